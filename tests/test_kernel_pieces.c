/* tests/test_kernel_pieces.c - the kernel evaluation of the operator pair
 * loops (sph__nshape_w, sph__nshape_g: every natural piece in product form
 * (b - q)^m P(q - e), selected by comparisons) against the evaluation of the
 * scalar functions (sph__shape_wg, the table rows behind sph_kernel_W,
 * sph_kernel_F, ...; those are tested against the long-double textbook forms
 * in test_kernel_values.c), for all 7 kernels in 1-, 2- and 3-D.
 *
 * Points: a grid of 24001 q on [0, kappa], and the 100 floating-point numbers
 * either side of every multiple of 1/2 (every knot, every table-piece boundary
 * and the support edge; the last ulps before kappa included).
 *
 * Tolerance: |new - old| <= 8 eps |old| (eps = TH_EPS). Both are within a few
 * eps of the exact value; the largest part of the new error is (b - q)^m for
 * the Wendland functions on [0, 1): b - q = 2 - q rounds (relative error up to
 * eps/2, times m = 8 for C6 in 2-/3-D: 4 eps), the old rows expand about a
 * nearer point. Measured worst |new - old| / |old|: 6.1 eps (Wendland C6 near
 * q = 1, double and float), 2.6 eps for the cubic and the quintic, 4.6 eps
 * for the new quartic. Where the value changes sign within 1/16 (the interior
 * roots of the new quartic: w at (8 + 2 sqrt 76)/15, w'/q at 9/5) relative
 * error is unbounded; there |new - old| <= 8 eps max|old| over the support.
 * (The new quartic, one polynomial (2 - q)^2 P(q), is stored as two pieces,
 * P about 0 on [0, 1), so that w(0) is exact, and about 3/2 on [1, 2): P about
 * 0 alone loses 17 eps relative in the small negative lobe near q = 1.8.)
 * At and beyond kappa both must be exactly 0, at q = 0 (the self term) both must agree bit for bit, and the
 * new form must keep the sign of the old one everywhere.
 * Subnormal values (float, Wendland C6 within 2e-5 of the edge: (2 - q)^8
 * underflows) have an absolute resolution of one denormal; there 4 of them
 * are allowed on top (measured: 1).
 */
#include "harness.h"

#define TOL 8.0
#define TINY (4 * (TH_IS_FLOAT ? (double)FLT_MIN * FLT_EPSILON : DBL_MIN * DBL_EPSILON)) /* 4 denormals */

static sph_real bump(sph_real x, int n)
{
    for (; n > 0; --n) x = TH_IS_FLOAT ? (sph_real)nextafterf((float)x, 10.0f) : (sph_real)nextafter((double)x, 10.0);
    for (; n < 0; ++n) x = TH_IS_FLOAT ? (sph_real)nextafterf((float)x, -1.0f) : (sph_real)nextafter((double)x, -1.0);
    return x;
}

/* old (table row) w or g at q, 0 outside [0, kappa). */
static double old_value(int si, int which, sph_real q)
{
    sph_real w, g;
    if (q < 0) return 0;
    sph__shape_wg(&sph__shapes[si], q, &w, &g);
    return which == 0 ? (double)w : (double)g;
}

static void check(sph_kernel k, int dim)
{
    const int si = sph__kdims[k][dim - 1].shape;
    const sph__nshape *ns = &sph__nshapes[si];
    const sph_real kappa = sph__shapes[si].kappa;
    const int ngrid = 24000, nknot = (int)(2 * kappa) + 1;
    double worst[2] = {0, 0}, big[2] = {0, 0};
    int i, which;
    th_begin("natural pieces vs table rows %s %dD", sph_kernel_name(k), dim);
    for (i = 0; i <= ngrid; ++i)
        for (which = 0; which < 2; ++which) {
            const double v = fabs(old_value(si, which, (sph_real)(kappa * i / ngrid)));
            big[which] = v > big[which] ? v : big[which];
        }
    for (i = 0; i <= ngrid + nknot * 201; ++i) {
        sph_real q;
        if (i <= ngrid) q = (sph_real)(kappa * i / ngrid);
        else q = bump((sph_real)(0.5 * ((i - ngrid - 1) / 201)), (i - ngrid - 1) % 201 - 100);
        if (q < 0) continue;
        for (which = 0; which < 2; ++which) {
            const double o = old_value(si, which, q);
            const double n = which == 0 ? (double)sph__nshape_w(ns, q) : (double)sph__nshape_g(ns, q);
            const double lo = old_value(si, which, q - (sph_real)0.0625);
            const double hi = old_value(si, which, q + (sph_real)0.0625 < kappa ? q + (sph_real)0.0625 : q);
            const int root = (lo > 0 && hi < 0) || (lo < 0 && hi > 0) || o == 0;
            const double err = fabs(n - o), scale = root ? big[which] : fabs(o);
            if (q >= kappa) {
                TH_CHECK(n == 0 && o == 0, "%s(q = %.17g >= kappa) = %.17g, old %.17g", which ? "g" : "w",
                         (double)q, n, o);
                continue;
            }
            TH_CHECK(fabs(n) <= TINY || ((n > 0) == (o > 0) && (n < 0) == (o < 0)), "%s(%.17g): sign %.17g vs old %.17g",
                     which ? "g" : "w", (double)q, n, o);
            TH_CHECK(err <= TOL * TH_EPS * scale + TINY, "%s(%.17g) = %.17g, old %.17g (%.2f eps)", which ? "g" : "w",
                     (double)q, n, o, err / (TH_EPS * scale));
            if (!root && scale > TINY / TH_EPS && err / (TH_EPS * scale) > worst[which]) worst[which] = err / (TH_EPS * scale);
        }
    }
    { /* the self term: bit for bit that of the scalar functions */
        sph_real w0, g0;
        sph__shape_wg(&sph__shapes[si], 0, &w0, &g0);
        TH_CHECK(sph__nshape_w(ns, 0) == w0 && sph__nshape_g(ns, 0) == g0, "q = 0: w %.17g vs %.17g, g %.17g vs %.17g",
                 (double)sph__nshape_w(ns, 0), (double)w0, (double)sph__nshape_g(ns, 0), (double)g0);
    }
    TH_CHECK(sph__nshape_w(ns, (sph_real)NAN) == 0 && sph__nshape_g(ns, (sph_real)NAN) == 0, "NaN q gives non-zero");
    printf("    %s %dD: worst |new - old| / |old| = %.2f eps (w), %.2f eps (g)\n", sph_kernel_name(k), dim,
           worst[0], worst[1]);
    th_end();
}

int main(void)
{
    int k, dim;
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim) check((sph_kernel)k, dim);
    return th_summary();
}
