/* tests/test_kernel_pieces.c - the kernel evaluation of the operator pair
 * loops (sph__nshape_w, sph__nshape_g: every natural piece in product form
 * (b - q)^m P(q - e) evaluated in sph_real and the one holding q selected by
 * comparisons) against the textbook closed forms of tests/kernel_ref.h in long
 * double, for every kernel in 1-, 2- and 3-D. The scalar functions evaluate
 * the same forms (sph__shape_at, in double and with the rounding of b - q
 * taken back); test_kernel_values.c holds those to the closed forms.
 *
 * Points: a grid of 24001 q on [0, kappa], and the 100 floating-point numbers
 * either side of every multiple of 1/2 (every knot and the support edge; the
 * last ulps before kappa included).
 *
 * Tolerance: |loop - exact| <= 8 eps |exact| (eps = TH_EPS). The largest part
 * of the error is (b - q)^m for the Wendland functions on [0, 1): b - q =
 * 2 - q rounds (relative error up to eps/2, times m = 8 for C6 in 2-/3-D:
 * 4 eps). Where the value changes sign within 1/16 (the interior roots of the
 * new quartic: w at (8 + 2 sqrt 76)/15, w'/q at 9/5) relative error is
 * unbounded; there |loop - exact| <= 8 eps max|exact| over the support.
 * At and beyond kappa the loops' values must be exactly 0, NaN q must give 0,
 * the sign must be that of the closed form everywhere, and at q = 0 (the self
 * term) w and g must be those of the scalar functions bit for bit.
 * Subnormal values (float, Wendland C6 within 2e-5 of the edge: (2 - q)^8
 * underflows) have an absolute resolution of one denormal; there 4 of them
 * are allowed on top.
 */
#include "kernel_ref.h"

#define TOL 8.0
#define TINY (4 * (TH_IS_FLOAT ? (double)FLT_MIN * FLT_EPSILON : DBL_MIN * DBL_EPSILON)) /* 4 denormals */

static sph_real bump(sph_real x, int n)
{
    for (; n > 0; --n) x = ref_next(x, 10.0);
    for (; n < 0; ++n) x = ref_next(x, -1.0);
    return x;
}

/* The closed form of w (which 0) or g = w'/q (which 1) at q >= 0. */
static ref_real exact(sph_kernel k, int dim, int which, ref_real q)
{
    ref_real w, w1, w2;
    if (q >= ref_kappa(k)) return 0;
    if (which == 1) return ref_g(k, dim, q);
    ref_shape(k, dim, q, &w, &w1, &w2);
    return w;
}

static void check(sph_kernel k, int dim)
{
    const sph__nshape *ns = &sph__nshapes[sph__kdims[k][dim - 1].shape];
    const sph_real kappa = sph_kernel_support(k);
    const int ngrid = 24000, nknot = (int)(2 * kappa) + 1;
    double worst[2] = {0, 0};
    ref_real big[2] = {0, 0};
    int i, which;
    th_begin("pair-loop pieces vs closed forms %s %dD", sph_kernel_name(k), dim);
    for (i = 0; i <= ngrid; ++i)
        for (which = 0; which < 2; ++which) {
            const ref_real v = fabsl(exact(k, dim, which, (ref_real)kappa * i / ngrid));
            big[which] = v > big[which] ? v : big[which];
        }
    for (i = 0; i <= ngrid + nknot * 201; ++i) {
        sph_real q;
        if (i <= ngrid) q = (sph_real)(kappa * i / ngrid);
        else q = bump((sph_real)(0.5 * ((i - ngrid - 1) / 201)), (i - ngrid - 1) % 201 - 100);
        if (q < 0) continue;
        for (which = 0; which < 2; ++which) {
            const ref_real x = exact(k, dim, which, (ref_real)q);
            const double n = which == 0 ? (double)sph__nshape_w(ns, q) : (double)sph__nshape_g(ns, q);
            const ref_real lo = exact(k, dim, which, (ref_real)q - 0.0625L);
            const ref_real hi = exact(k, dim, which, (ref_real)q + 0.0625L < kappa ? (ref_real)q + 0.0625L : (ref_real)q);
            const int root = (lo > 0 && hi < 0) || (lo < 0 && hi > 0) || x == 0;
            const double err = (double)fabsl(n - x), scale = (double)(root ? big[which] : fabsl(x));
            if (q >= kappa) {
                TH_CHECK(n == 0, "%s(q = %.17g >= kappa) = %.17g", which ? "g" : "w", (double)q, n);
                continue;
            }
            TH_CHECK(fabs(n) <= TINY || ((n > 0) == (x > 0) && (n < 0) == (x < 0)), "%s(%.17g): sign %.17g vs exact %.17Lg",
                     which ? "g" : "w", (double)q, n, x);
            TH_CHECK(err <= TOL * TH_EPS * scale + TINY, "%s(%.17g) = %.17g, exact %.17Lg (%.2f eps)", which ? "g" : "w",
                     (double)q, n, x, err / (TH_EPS * scale));
            if (!root && scale > TINY / TH_EPS && err / (TH_EPS * scale) > worst[which]) worst[which] = err / (TH_EPS * scale);
        }
    }
    /* the self term: bit for bit that of the scalar functions */
    TH_CHECK(sph__nshape_w(ns, 0) == (sph_real)sph__shape_at(ns, SPH__SW, 0) &&
                 sph__nshape_g(ns, 0) == (sph_real)sph__shape_at(ns, SPH__SG, 0),
             "q = 0: w %.17g vs %.17g, g %.17g vs %.17g", (double)sph__nshape_w(ns, 0), sph__shape_at(ns, SPH__SW, 0),
             (double)sph__nshape_g(ns, 0), sph__shape_at(ns, SPH__SG, 0));
    TH_CHECK(sph__nshape_w(ns, (sph_real)NAN) == 0 && sph__nshape_g(ns, (sph_real)NAN) == 0, "NaN q gives non-zero");
    printf("    %s %dD: worst |loop - exact| / |exact| = %.2f eps (w), %.2f eps (g)\n", sph_kernel_name(k), dim, worst[0],
           worst[1]);
    th_end();
}

int main(void)
{
    int k, dim;
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim) check(ref_kernels[k], dim);
    return th_summary();
}
