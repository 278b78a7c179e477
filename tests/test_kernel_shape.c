/* tests/test_kernel_shape.c - qualitative shape of every kernel in 1-, 2- and
 * 3-D: positivity and monotone decay, the new quartic's negative lobe and
 * rising tail, symmetry of W and antisymmetry of grad W, compact support with
 * the sign right up to the last representable r, and continuity at every knot
 * and every piece boundary (the header's tables are cut at multiples of 1/2).
 *
 * Reference facts, from the closed forms (tests/kernel_ref.h):
 *  - every kernel except the new quartic: w > 0 and w' < 0 on (0, kappa);
 *  - new quartic (design.md): w = (2-q)^2 (1/6 + q/6 - 5/32 q^2) is negative
 *    exactly on ((8 + 2 sqrt 76)/15, 2) and w' = q (2-q)(5q-9)/8 is positive
 *    exactly on (9/5, 2);
 *  - smoothness: cubic M4 and Lucy are C2 on the whole line (w'' -> 0 at the
 *    support edge: 2 - q and -12 (q-1)(3q-1)); quintic M6 is C4 (20 (3-q)^3
 *    -> 0); quartic M5 is C3 (12 (5/2-q)^2 -> 0; its knots are at 1/2 and
 *    3/2); every Wendland function here has w'' with a factor (2-q)^k, k >= 1,
 *    so it is at least C2; the new quartic is one polynomial inside its
 *    support but w''(2) = -1/4 != 0: d2W/dr2 jumps at the support edge only.
 *    So W and dW/dr are continuous at every knot and piece boundary (edge
 *    included) for all kernels, d2W/dr2 everywhere except the new quartic's
 *    edge, where the test asserts the jump instead.
 */
#include "kernel_ref.h"

static const double test_h[] = {1, 0.25, 4, 0.3, 0.7, 1.1, 3.7, 1e-3, 123.456};
#define NH (sizeof test_h / sizeof test_h[0])

static int is_power_of_two(double h)
{
    int e;
    return frexp(h, &e) == 0.5;
}

/* W > 0 and non-increasing, dW/dr < 0, on a fine grid of (0, kappa) (near
 * q = 0 the decrease is below one ulp, so non-strict); for the new quartic
 * the signs flip where the closed form says they do (points within 4 eps of
 * a root are not judged). */
static int side(ref_real x, ref_real root)
{
    return x < root * (1 - 4 * TH_EPS) ? -1 : x > root * (1 + 4 * TH_EPS) ? 1 : 0;
}

static void test_monotone(sph_kernel k, int dim)
{
    const double kap = (double)sph_kernel_support(k);
    const ref_real root_w = (8 + 2 * sqrtl(76.0L)) / 15, root_w1 = 1.8L;
    sph_real prev = sph_kernel_w(k, dim, 0, 1), rprev = 0;
    int i;
    const int n = 20000;
    th_begin("positivity and monotone decay on a grid, %s %dD", sph_kernel_name(k), dim);
    TH_CHECK(prev > 0, "W(0) = %g", (double)prev);
    for (i = 1; i < n; ++i) {
        const sph_real r = (sph_real)(kap * i / n);
        const sph_real W = sph_kernel_w(k, dim, r, 1), dW = sph_kernel_dwdr(k, dim, r, 1);
        const sph_real F = sph_kernel_f(k, dim, r, 1);
        if (k == SPH_KERNEL_NEW_QUARTIC) {
            const int sw = side(r, root_w), sd = side(r, root_w1), sp = side(rprev, root_w1);
            TH_CHECK(sw == 0 || (sw < 0 ? W > 0 : W < 0), "W(%.9g) = %g", (double)r, (double)W);
            TH_CHECK(sd == 0 || (sd < 0 ? dW < 0 : dW > 0), "dW/dr(%.9g) = %g", (double)r, (double)dW);
            TH_CHECK(sd != sp || (sd < 0 ? W <= prev : W >= prev), "W not monotone at %.9g", (double)r);
        } else {
            TH_CHECK(W > 0, "W(%.9g) = %g", (double)r, (double)W);
            TH_CHECK(dW < 0, "dW/dr(%.9g) = %g", (double)r, (double)dW);
            TH_CHECK(W <= prev, "W(%.9g) = %.17g above the previous %.17g", (double)r, (double)W,
                     (double)prev);
        }
        TH_CHECK((F < 0) == (dW < 0) && (F > 0) == (dW > 0), "sign of F(%.9g) = %g", (double)r, (double)F);
        prev = W;
        rprev = r;
    }
    th_end();
}

/* The sign change of the header's f on [a, b] by bisection (f(a), f(b) of
 * opposite signs). */
static sph_real bisect(sph_real (*f)(sph_kernel, int, sph_real, sph_real), int dim, sph_real a, sph_real b)
{
    const int sa = f(SPH_KERNEL_NEW_QUARTIC, dim, a, 1) > 0;
    int it;
    for (it = 0; it < 200; ++it) {
        const sph_real m = a + (b - a) / 2;
        if (m <= a || m >= b) break;
        if ((f(SPH_KERNEL_NEW_QUARTIC, dim, m, 1) > 0) == sa) a = m;
        else b = m;
    }
    return b;
}

/* New quartic: negative exactly beyond (8 + 2 sqrt 76)/15, rising exactly on
 * (9/5, 2). Roots located to 8 eps by bisection on the header's W and dW/dr
 * (both are simple roots of well-conditioned factors). */
static void test_new_quartic_lobe(int dim)
{
    const double root_w = (double)((8 + 2 * sqrtl(76.0L)) / 15), root_w1 = 1.8;
    const sph_kernel k = SPH_KERNEL_NEW_QUARTIC;
    const sph_real rw = bisect(sph_kernel_w, dim, (sph_real)1.5, (sph_real)1.9);
    const sph_real rw1 = bisect(sph_kernel_dwdr, dim, (sph_real)1.7, (sph_real)1.9);
    th_begin("new quartic %dD: negative on ((8+2 sqrt 76)/15, 2), rising on (1.8, 2)", dim);
    TH_REL(rw, root_w, 8 * TH_EPS);
    TH_REL(rw1, root_w1, 8 * TH_EPS);
    TH_CHECK(sph_kernel_w(k, dim, (sph_real)(root_w * (1 + 16 * TH_EPS)), 1) < 0, "W just above the root");
    TH_CHECK(sph_kernel_w(k, dim, (sph_real)(root_w * (1 - 16 * TH_EPS)), 1) >= 0, "W just below the root");
    TH_CHECK(sph_kernel_dwdr(k, dim, (sph_real)(root_w1 * (1 + 16 * TH_EPS)), 1) > 0, "dW/dr just above 1.8");
    TH_CHECK(sph_kernel_dwdr(k, dim, (sph_real)(root_w1 * (1 - 16 * TH_EPS)), 1) < 0, "dW/dr just below 1.8");
    th_end();
}

/* W takes r = |x| only, so W(x) = W(-x) by construction; what can break is
 * the gradient: grad W(-dx) = -grad W(dx) bitwise, and grad W = F dx against
 * the closed form F(q) at the exact q = |dx|/h (long double). Tolerance per
 * component: 16 eps (|F| + q |dF/dq|) |dx_a| (the header rounds q itself, so
 * the sensitivity of F to q enters), dF/dq = alpha h^-(d+2) (w'' - g)/q. */
static void test_symmetry(sph_kernel k, int dim)
{
    uint64_t seed = 12345u + (uint64_t)k * 7u + (uint64_t)dim;
    const double kap = (double)sph_kernel_support(k);
    int i, a;
    th_begin("antisymmetry of grad W and grad W = F dx (random directions), %s %dD", sph_kernel_name(k), dim);
    for (i = 0; i < 2000; ++i) {
        sph_real dx[3], mdx[3], g[3] = {9, 9, 9}, mg[3] = {9, 9, 9};
        const sph_real h = (sph_real)(0.5 + 0.4 * ref_rand(&seed));
        ref_real r2 = 0, q, w, w1, w2, gq, dg, scale;
        for (a = 0; a < dim; ++a) {
            dx[a] = (sph_real)(0.7 * kap * (double)h * ref_rand(&seed));
            mdx[a] = -dx[a];
            r2 += (ref_real)dx[a] * dx[a];
        }
        q = sqrtl(r2) / h;
        ref_shape(k, dim, q, &w, &w1, &w2);
        gq = ref_g(k, dim, q);
        dg = q > 0 ? (w2 - gq) / q : 0;
        scale = ref_alpha(k, dim) / ref_pow(h, dim + 2);
        sph_kernel_grad(k, dim, dx, h, g);
        sph_kernel_grad(k, dim, mdx, h, mg);
        for (a = 0; a < dim; ++a) {
            const ref_real ref = scale * gq * dx[a];
            const ref_real tol = 16 * TH_EPS * scale * (fabsl(gq) + q * fabsl(dg)) * fabsl((ref_real)dx[a]);
            TH_CHECK(mg[a] == -g[a], "grad(-dx)[%d] = %.17g, -grad(dx) = %.17g", a, (double)mg[a], (double)-g[a]);
            TH_CHECK(fabsl(g[a] - ref) <= tol, "grad[%d] = %.17g, F dx = %.17Lg (tol %.3Lg) at q = %.17Lg", a,
                     (double)g[a], ref, tol, q);
        }
    }
    th_end();
}

/* One ulp inside the support the sign must be right (sgn W = sw, dW/dr and F
 * of the opposite sign) wherever the true value is a normal number (from the
 * closed form); where it underflows (Wendland C6 in float: (2^-22)^8) it may
 * be 0 but never of the wrong sign. */
static void sign_inside(sph_kernel k, int dim, sph_real r, sph_real h, int sw)
{
    const double tiny = TH_IS_FLOAT ? FLT_MIN : DBL_MIN;
    const ref_real q = (ref_real)r / h, a = ref_alpha(k, dim);
    ref_real w, w1, w2;
    const double got[3] = {(double)sph_kernel_w(k, dim, r, h), (double)sph_kernel_dwdr(k, dim, r, h),
                           (double)sph_kernel_f(k, dim, r, h)};
    const int want[3] = {sw, -sw, -sw};
    ref_real ref[3];
    int i;
    ref_shape(k, dim, q, &w, &w1, &w2);
    ref[0] = a * w / ref_pow(h, dim);
    ref[1] = a * w1 / ref_pow(h, dim + 1);
    ref[2] = a * w1 / q / ref_pow(h, dim + 2);
    for (i = 0; i < 3; ++i) {
        if (fabsl(ref[i]) >= tiny) TH_CHECK(got[i] * want[i] > 0, "h = %g, r = %.17g: %s = %g", (double)h,
                                            (double)r, i == 0 ? "W" : i == 1 ? "dW/dr" : "F", got[i]);
        else TH_CHECK(got[i] * want[i] >= 0, "h = %g, r = %.17g: %s = %g (underflows)", (double)h, (double)r,
                      i == 0 ? "W" : i == 1 ? "dW/dr" : "F", got[i]);
    }
}

/* Exactly zero at r = kappa h and beyond; inside, one ulp below the edge, the
 * sign is right (W > 0, dW/dr < 0; new quartic: W < 0, dW/dr > 0). Checked for
 * h a power of two, where r = kappa h and r/h are exact. */
static void test_support(sph_kernel k, int dim)
{
    const sph_real kap = sph_kernel_support(k);
    size_t ih;
    th_begin("compact support: zero at and beyond kappa h, right sign one ulp inside, %s %dD",
             sph_kernel_name(k), dim);
    for (ih = 0; ih < NH; ++ih) {
        const sph_real h = (sph_real)test_h[ih], edge = kap * h;
        const sph_real out[4] = {edge, ref_next(edge, 1e300), edge * (sph_real)1.5, edge * (sph_real)1e6};
        const sph_real in = ref_next(edge, 0);
        const int nq = k == SPH_KERNEL_NEW_QUARTIC;
        int j, a;
        if (!is_power_of_two((double)h)) continue;
        for (j = 0; j < 4; ++j) {
            sph_real dx[3] = {0, 0, 0}, g[3] = {9, 9, 9};
            TH_CHECK(sph_kernel_w(k, dim, out[j], h) == 0 && sph_kernel_dwdr(k, dim, out[j], h) == 0 &&
                         sph_kernel_f(k, dim, out[j], h) == 0 && sph_kernel_d2wdr2(k, dim, out[j], h) == 0 &&
                         sph_kernel_dwdh(k, dim, out[j], h) == 0,
                     "h = %g, r = %.17g (kappa h = %.17g): W %g dW/dr %g F %g d2W %g dW/dh %g", (double)h,
                     (double)out[j], (double)edge, (double)sph_kernel_w(k, dim, out[j], h),
                     (double)sph_kernel_dwdr(k, dim, out[j], h), (double)sph_kernel_f(k, dim, out[j], h),
                     (double)sph_kernel_d2wdr2(k, dim, out[j], h), (double)sph_kernel_dwdh(k, dim, out[j], h));
            dx[dim - 1] = out[j];
            sph_kernel_grad(k, dim, dx, h, g);
            for (a = 0; a < dim; ++a) TH_CHECK(g[a] == 0, "grad[%d] = %g at r = %.17g", a, (double)g[a], (double)out[j]);
        }
        sign_inside(k, dim, in, h, nq ? -1 : 1);
    }
    th_end();
}

/* The same for any h, with "r >= kappa h" decided exactly (long double holds
 * the product of a sph_real and kappa exactly). Guards q = r / h in the
 * header: q = r * (1/h) put q one ulp below kappa for r = kappa h exactly
 * with about one h in nine (h = 4.7020975303859682, r = 2 h gave W = 3.9e-49
 * instead of 0). (The sign one ulp inside is not asked for arbitrary h: for
 * kappa = 3, r/h can round up to kappa whatever the method.) */
static void test_support_any_h(sph_kernel k, int dim)
{
    const sph_real kap = sph_kernel_support(k);
    uint64_t seed = 99u + (uint64_t)k;
    int i;
    th_begin("compact support for arbitrary h (exact r >= kappa h), %s %dD", sph_kernel_name(k), dim);
    for (i = 0; i < 20000; ++i) {
        const sph_real h = (sph_real)(5.05 + 4.95 * ref_rand(&seed));
        const ref_real edge = (ref_real)kap * (ref_real)h;
        sph_real out = kap * h, in;
        if ((ref_real)out < edge) out = ref_next(out, 1e300);
        in = ref_next(out, 0);
        TH_CHECK(sph_kernel_w(k, dim, out, h) == 0 && sph_kernel_dwdr(k, dim, out, h) == 0 &&
                     sph_kernel_f(k, dim, out, h) == 0 && sph_kernel_d2wdr2(k, dim, out, h) == 0 &&
                     sph_kernel_dwdh(k, dim, out, h) == 0,
                 "h = %.17g, r = %.17g >= kappa h: W = %g, dW/dr = %g", (double)h, (double)out,
                 (double)sph_kernel_w(k, dim, out, h), (double)sph_kernel_dwdr(k, dim, out, h));
        TH_CHECK(in < out, "r one ulp inside");
    }
    th_end();
}

/* Left and right limits at every multiple of 1/2 in (0, kappa]: the left
 * value is taken one ulp below m, the right one at m (the header picks the
 * right piece there; at m = kappa the right value is the exact 0). Allowed
 * difference: 4 eps of the local magnitude, plus the change of the function
 * over one ulp of q (|next derivative| * ulp(m)), plus 4 eps of the peak
 * magnitude where the value itself is near 0. The next derivative is bounded
 * by the peak of the one after it (2 max|dW/dr| for W, 2 max|d2W/dr2| for
 * dW/dr) and, for d2W/dr2, by 32 max|d2W/dr2| (a bound on |w'''| / max|w''|
 * for these polynomials; the highest is Wendland C6's, about 10). */
static double peak_abs(sph_real (*f)(sph_kernel, int, sph_real, sph_real), sph_kernel k, int dim)
{
    double m = 0;
    int i;
    for (i = 0; i <= 2000; ++i) {
        const double v = fabs((double)f(k, dim, (sph_real)(sph_kernel_support(k) * i / 2000.0), 1));
        if (v > m) m = v;
    }
    return m;
}

static void test_continuity(sph_kernel k, int dim)
{
    const double kap = (double)sph_kernel_support(k);
    const double pw = peak_abs(sph_kernel_w, k, dim), pd = peak_abs(sph_kernel_dwdr, k, dim);
    const double p2 = peak_abs(sph_kernel_d2wdr2, k, dim);
    double m;
    th_begin("continuity of W, dW/dr, d2W/dr2 at every knot and piece boundary, %s %dD", sph_kernel_name(k), dim);
    for (m = 0.5; m <= kap; m += 0.5) {
        const sph_real qr = (sph_real)m, ql = ref_next(qr, 0);
        const double ulp = (double)(qr - ql);
        const double Wl = (double)sph_kernel_w(k, dim, ql, 1), Wr = (double)sph_kernel_w(k, dim, qr, 1);
        const double Dl = (double)sph_kernel_dwdr(k, dim, ql, 1), Dr = (double)sph_kernel_dwdr(k, dim, qr, 1);
        const double Sl = (double)sph_kernel_d2wdr2(k, dim, ql, 1), Sr = (double)sph_kernel_d2wdr2(k, dim, qr, 1);
        TH_CHECK(fabs(Wl - Wr) <= 4 * TH_EPS * (fabs(Wr) + pw) + 2 * pd * ulp, "W at q = %g: %.17g | %.17g", m, Wl, Wr);
        TH_CHECK(fabs(Dl - Dr) <= 4 * TH_EPS * (fabs(Dr) + pd) + 2 * p2 * ulp, "dW/dr at q = %g: %.17g | %.17g", m, Dl,
                 Dr);
        if (k == SPH_KERNEL_NEW_QUARTIC && m == kap) {
            /* w''(2-) = -1/4: a jump of alpha/4 at the edge */
            TH_REL(Sl, -0.25 * (double)sph_kernel_alpha(k, dim), 1e-3);
            TH_CHECK(Sr == 0, "d2W/dr2 at the edge = %g", Sr);
        } else {
            TH_CHECK(fabs(Sl - Sr) <= 4 * TH_EPS * (fabs(Sr) + p2) + 32 * p2 * ulp,
                     "d2W/dr2 at q = %g: %.17g | %.17g", m, Sl, Sr);
        }
    }
    th_end();
}

int main(void)
{
    int ik, dim;
    for (ik = 0; ik < SPH_KERNEL_COUNT; ++ik) {
        for (dim = 1; dim <= 3; ++dim) {
            test_monotone(ref_kernels[ik], dim);
            test_symmetry(ref_kernels[ik], dim);
            test_support(ref_kernels[ik], dim);
            test_support_any_h(ref_kernels[ik], dim);
            test_continuity(ref_kernels[ik], dim);
        }
    }
    for (dim = 1; dim <= 3; ++dim) test_new_quartic_lobe(dim);
    return th_summary();
}
