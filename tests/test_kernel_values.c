/* tests/test_kernel_values.c - W, dW/dr, F = (1/r) dW/dr, d2W/dr2 and dW/dh
 * of every kernel in 1-, 2- and 3-D at chosen q (q = 0, points inside every
 * piece, next to every knot and every piece boundary, next to the support
 * edge), against the textbook closed forms of tests/kernel_ref.h evaluated in
 * long double with the normalisations of design.md (never the header's tables).
 *
 * Tolerances (eps = TH_EPS of the precision under test), at h = 1 so r = q:
 *  - relative error <= 16 eps wherever the reference quantity keeps its sign
 *    on [q - 1/16, q + 1/16] (no root nearby; the support edge is not a root
 *    here: the header writes the outer piece in kappa - q, so W and its
 *    derivatives keep full relative accuracy up to the edge);
 *  - next to an interior root the relative error is unbounded, so there the
 *    absolute error must be <= 16 eps times the largest magnitude M of that
 *    quantity over the support;
 *  - a reference that is exactly 0 at q = 0 (dW/dr: q is factored out of
 *    w') must come out exactly 0. An interior root that falls on a sampled q
 *    (dW/dh of the 3-D cubic at q = 1) is a root like the others: absolute
 *    error <= 16 eps M. It comes out exactly 0 when the compiler does not
 *    contract a*b + c into a fused multiply-add, not with contraction (clang
 *    -march=native on a CPU with FMA: 1.3e-17 = 0.06 eps M).
 * alpha_d: correctly rounded, so relative error <= eps/2 (asserted <= 1 eps).
 */
#include "kernel_ref.h"

#define TOL_REL 16.0
#define TOL_ABS 16.0

enum { Q_W, Q_DWDR, Q_F, Q_D2W, Q_DWDH, Q_COUNT };
static const char *const qname[Q_COUNT] = {"W", "dW/dr", "F", "d2W/dr2", "dW/dh"};

/* The reference value of quantity iq at q (h = 1). */
static ref_real ref_quantity(sph_kernel k, int dim, int iq, ref_real q)
{
    ref_real w, w1, w2;
    const ref_real a = ref_alpha(k, dim);
    ref_shape(k, dim, q, &w, &w1, &w2);
    switch (iq) {
    case Q_W: return a * w;
    case Q_DWDR: return a * w1;
    case Q_F: return a * ref_g(k, dim, q);
    case Q_D2W: return a * w2;
    default: return -a * (dim * w + q * w1);
    }
}

static sph_real header_quantity(sph_kernel k, int dim, int iq, sph_real q)
{
    switch (iq) {
    case Q_W: return sph_kernel_w(k, dim, q, 1);
    case Q_DWDR: return sph_kernel_dwdr(k, dim, q, 1);
    case Q_F: return sph_kernel_f(k, dim, q, 1);
    case Q_D2W: return sph_kernel_d2wdr2(k, dim, q, 1);
    default: return sph_kernel_dwdh(k, dim, q, 1);
    }
}

/* Largest |quantity| over the support (fine grid). */
static ref_real ref_peak(sph_kernel k, int dim, int iq)
{
    ref_real m = 0;
    int i;
    for (i = 0; i <= 4096; ++i) {
        const ref_real v = fabsl(ref_quantity(k, dim, iq, ref_kappa(k) * i / 4096));
        if (v > m) m = v;
    }
    return m;
}

/* Does the reference change sign within 1/16 of q (an interior root)? */
static int near_root(sph_kernel k, int dim, int iq, ref_real q)
{
    const ref_real kap = ref_kappa(k);
    ref_real lo = q - 1.0L / 16, hi = q + 1.0L / 16;
    int i, neg = 0, pos = 0;
    if (lo < 0) lo = 0;
    if (hi > kap) hi = kap;
    for (i = 0; i <= 64; ++i) {
        const ref_real x = lo + (hi - lo) * i / 64;
        const ref_real v = x < kap ? ref_quantity(k, dim, iq, x) : 0;
        neg |= v < 0;
        pos |= v > 0;
    }
    return neg && pos;
}

static void check_point(sph_kernel k, int dim, sph_real q, const ref_real *peak)
{
    int iq;
    for (iq = 0; iq < Q_COUNT; ++iq) {
        const double got = (double)header_quantity(k, dim, iq, q);
        const ref_real ref = ref_quantity(k, dim, iq, (ref_real)q);
        const double err = fabs(got - (double)ref);
        if (ref == 0 && q == 0) {
            TH_CHECK(got == 0, "%s at q = %.17g: %.17g, expected exactly 0", qname[iq], (double)q, got);
        } else if (near_root(k, dim, iq, (ref_real)q)) {
            TH_CHECK(err <= TOL_ABS * TH_EPS * (double)peak[iq],
                     "%s at q = %.17g (near a root): %.17g, expected %.17Lg, |err| = %.3g peak %.3Lg",
                     qname[iq], (double)q, got, ref, err, peak[iq]);
        } else {
            TH_CHECK(err <= TOL_REL * TH_EPS * fabsl(ref),
                     "%s at q = %.17g: %.17g, expected %.17Lg, rel err %.3g eps", qname[iq],
                     (double)q, got, ref, err / (double)fabsl(ref) / TH_EPS);
            ref_track(iq, got, (double)ref);
        }
    }
}

static void test_values(sph_kernel k, int dim)
{
    static const double base[] = {0,    1e-6, 1e-3, 0.1, 0.25, 0.3, 0.49, 0.6,  0.7,  0.75,
                                  0.9,  1.1,  1.25, 1.4, 1.6,  1.7, 1.75, 1.85, 1.95, 2.1,
                                  2.25, 2.4,  2.6,  2.75, 2.9, 2.99};
    static const double near[] = {-0x1p-12, -0x1p-24, -0x1p-40, 0, 0x1p-40, 0x1p-24, 0x1p-12};
    const double kap = (double)ref_kappa(k);
    ref_real peak[Q_COUNT];
    double m;
    size_t i, j;
    int iq, npoints = 0;
    for (iq = 0; iq < Q_COUNT; ++iq) peak[iq] = ref_peak(k, dim, iq);
    th_begin("values %s %dD (W, dW/dr, F, d2W/dr2, dW/dh vs closed forms)", sph_kernel_name(k), dim);
    for (i = 0; i < sizeof base / sizeof base[0]; ++i) {
        if (base[i] >= kap) continue;
        check_point(k, dim, (sph_real)base[i], peak);
        ++npoints;
    }
    /* next to every multiple of 1/2 (knots, piece boundaries, the edge) */
    for (m = 0.5; m <= kap; m += 0.5) {
        for (j = 0; j < sizeof near / sizeof near[0]; ++j) {
            const sph_real q = (sph_real)(m + near[j]);
            if (!(q < (sph_real)kap)) continue;
            check_point(k, dim, q, peak);
            ++npoints;
        }
    }
    TH_CHECK(npoints >= 20, "only %d points", npoints);
    th_end();
}

/* the fused call returns exactly what the separate calls return */
static void test_fused(sph_kernel k, int dim)
{
    int i;
    th_begin("fused sph_kernel_wf == (sph_kernel_w, sph_kernel_f) %s %dD", sph_kernel_name(k), dim);
    for (i = 0; i <= 400; ++i) {
        const sph_real r = (sph_real)(i * 0.0079), h = (sph_real)0.7;
        sph_real W = -1, F = -1;
        sph_kernel_wf(k, dim, r, h, &W, &F);
        TH_CHECK(W == sph_kernel_w(k, dim, r, h) && F == sph_kernel_f(k, dim, r, h),
                 "r = %g: W %.17g vs %.17g, F %.17g vs %.17g", (double)r, (double)W,
                 (double)sph_kernel_w(k, dim, r, h), (double)F, (double)sph_kernel_f(k, dim, r, h));
    }
    th_end();
}

static void test_constants(sph_kernel k, int dim)
{
    th_begin("alpha and kappa %s %dD vs design.md table", sph_kernel_name(k), dim);
    TH_REL(sph_kernel_alpha(k, dim), (double)ref_alpha(k, dim), TH_EPS);
    TH_CHECK(sph_kernel_support(k) == (sph_real)ref_kappa(k), "kappa = %g", (double)sph_kernel_support(k));
    th_end();
}

int main(void)
{
    int ik, dim, iq;
    for (ik = 0; ik < SPH_KERNEL_COUNT; ++ik) {
        for (dim = 1; dim <= 3; ++dim) {
            test_constants(ref_kernels[ik], dim);
            test_values(ref_kernels[ik], dim);
            test_fused(ref_kernels[ik], dim);
        }
    }
    for (iq = 0; iq < Q_COUNT; ++iq)
        printf("info [%s]: worst relative error of %s vs closed form (away from roots): %.3g (%.2f eps)\n",
               TH_PRECISION, qname[iq], ref_worst[iq], ref_worst[iq] / TH_EPS);
    return th_summary();
}
