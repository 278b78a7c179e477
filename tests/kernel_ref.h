/* tests/kernel_ref.h - independent reference kernels for the kernel tests.
 *
 * Nothing here reads the generated tables of sph_kernel.h: the shapes are the
 * textbook formulas, evaluated in long double, and the normalisations are the
 * closed forms of /work/shared/design.md section 2 (checked there by exact
 * integration; the 1-D Wendland constants 5/8, 3/4, 55/64 are Wendland 1995
 * for support 2h, i.e. Dehnen & Aly 2012 table 1's 5/4, 3/2, 55/32 for support
 * 1 halved). The quartic M5's 1/24, 96/(1199 pi), 1/(20 pi) are Price 2012's,
 * and Dehnen & Aly 2012 table 1's 3125/768, 46875/(2398 pi),
 * 15625/(512 pi) for support 1 divided by (5/2)^(d+4) (the support 5/2 and
 * the 4th-power scale of w with it).
 *
 * Sources of the shapes:
 *   cubic M4       Monaghan & Lattanzio 1985: [(2-q)^3 - 4 (1-q)_+^3] / 6
 *   Lucy           Lucy 1977: (1+3q)(1-q)^3
 *   new quartic    Liu & Liu 2003: 2/3 - 9/8 q^2 + 19/24 q^3 - 5/32 q^4,
 *                  evaluated factored, (2-q)^2 (1/6 + q/6 - 5/32 q^2)
 *                  (design.md), as the expanded form cancels near q = 2
 *   quintic M6     Morris 1996: (3-q)^5 - 6 (2-q)_+^5 + 15 (1-q)_+^5
 *   quartic M5     Schoenberg 1946, Price 2012:
 *                  (5/2-q)^4 - 5 (3/2-q)_+^4 + 10 (1/2-q)_+^4, and its
 *                  derivatives term by term, but w' = 6 q (4 q^2 - 5) on
 *                  [0, 1/2), where the terms' sum would cancel to O(q)
 *   Wendland       Wendland 1995 (support 2): 2-/3-D
 *                  C2 (1-q/2)^4 (1+2q), C4 (1-q/2)^6 (1+3q+35/12 q^2),
 *                  C6 (1-q/2)^8 (1+4q+25/4 q^2+4q^3); 1-D
 *                  C2 (1-q/2)^3 (1+3q/2), C4 (1-q/2)^5 (1+5q/2+2q^2),
 *                  C6 (1-q/2)^7 (1+7q/2+19q^2/4+21q^3/8).
 * The first and second derivatives are the factored closed forms obtained by
 * differentiating these by hand (and re-checked symbolically); the factored
 * forms keep the roots (q = 0 for w') exact, so long double evaluates them to
 * far better than double precision.
 *
 * Also: Gauss-Legendre nodes computed here (Newton on P_n), and a quadrature
 * over [0, kappa] split at every multiple of 1/2 (a refinement of every knot:
 * the quartic's 1/2, 3/2, 5/2 and the others' integers), exact for the
 * piecewise polynomials up to degree 2 n - 1.
 */
#ifndef SPH_TEST_KERNEL_REF_H
#define SPH_TEST_KERNEL_REF_H

#include "harness.h"

typedef long double ref_real;

/* Each test uses a part of this file: no unused-function warnings. */
#if defined(__GNUC__)
#define REF_FN static __attribute__((unused))
#define REF_DATA static const __attribute__((unused))
#else
#define REF_FN static
#define REF_DATA static const
#endif

#define REF_PI 3.141592653589793238462643383279502884L

/* support kappa of kernel k (units of h). */
REF_FN ref_real ref_kappa(sph_kernel k)
{
    return k == SPH_KERNEL_LUCY ? 1.0L : k == SPH_KERNEL_QUINTIC ? 3.0L : k == SPH_KERNEL_QUARTIC ? 2.5L : 2.0L;
}

/* alpha_d per kernel (enum order) and dimension: design.md section 2, and the
 * quartic's from the sources above. A kernel without its row does not compile. */
REF_DATA ref_real ref_alpha_table[][3] = {
    {1.0L, 15.0L / (7.0L * REF_PI), 3.0L / (2.0L * REF_PI)},
    {5.0L / 4.0L, 5.0L / REF_PI, 105.0L / (16.0L * REF_PI)},
    {1.0L, 15.0L / (7.0L * REF_PI), 315.0L / (208.0L * REF_PI)},
    {1.0L / 120.0L, 7.0L / (478.0L * REF_PI), 1.0L / (120.0L * REF_PI)},
    {5.0L / 8.0L, 7.0L / (4.0L * REF_PI), 21.0L / (16.0L * REF_PI)},
    {3.0L / 4.0L, 9.0L / (4.0L * REF_PI), 495.0L / (256.0L * REF_PI)},
    {55.0L / 64.0L, 39.0L / (14.0L * REF_PI), 1365.0L / (512.0L * REF_PI)},
    {1.0L / 24.0L, 96.0L / (1199.0L * REF_PI), 1.0L / (20.0L * REF_PI)},
};
typedef char ref_alpha_table_covers_every_kernel[sizeof ref_alpha_table / sizeof ref_alpha_table[0] == SPH_KERNEL_COUNT ? 1 : -1];

REF_FN ref_real ref_alpha(sph_kernel k, int dim)
{
    return ref_alpha_table[k][dim - 1];
}

REF_FN ref_real ref_pow(ref_real x, int n)
{
    ref_real p = 1;
    while (n-- > 0) p *= x;
    return p;
}

/* (x)_+^n: the truncated power of the B-splines, 0 where x <= 0. */
REF_FN ref_real ref_tpow(ref_real x, int n)
{
    return x > 0 ? ref_pow(x, n) : 0;
}

/* Dimensionless shape w(q), w'(q), w''(q) for 0 <= q (zero at q >= kappa). */
REF_FN void ref_shape(sph_kernel k, int dim, ref_real q, ref_real *w, ref_real *w1, ref_real *w2)
{
    const ref_real t = 2 - q; /* (q - 2) = -t */
    *w = *w1 = *w2 = 0;
    if (q >= ref_kappa(k)) return;
    switch (k) {
    case SPH_KERNEL_CUBIC:
        if (q < 1) {
            *w = (ref_pow(t, 3) - 4 * ref_pow(1 - q, 3)) / 6;
            *w1 = q * (3 * q - 4) / 2;
            *w2 = 3 * q - 2;
        } else {
            *w = ref_pow(t, 3) / 6;
            *w1 = -t * t / 2;
            *w2 = t;
        }
        break;
    case SPH_KERNEL_LUCY:
        *w = (1 + 3 * q) * ref_pow(1 - q, 3);
        *w1 = -12 * q * ref_pow(1 - q, 2);
        *w2 = -12 * (q - 1) * (3 * q - 1);
        break;
    case SPH_KERNEL_NEW_QUARTIC:
        *w = t * t * (1.0L / 6 + q / 6 - 5.0L / 32 * q * q);
        *w1 = q * t * (5 * q - 9) / 8;
        *w2 = -(15 * q * q - 38 * q + 18) / 8;
        break;
    case SPH_KERNEL_QUINTIC:
        if (q < 1) {
            *w = ref_pow(3 - q, 5) - 6 * ref_pow(2 - q, 5) + 15 * ref_pow(1 - q, 5);
            *w1 = -10 * q * (5 * ref_pow(q, 3) - 12 * q * q + 12);
            *w2 = -40 * (5 * ref_pow(q, 3) - 9 * q * q + 3);
        } else if (q < 2) {
            *w = ref_pow(3 - q, 5) - 6 * ref_pow(2 - q, 5);
            *w1 = 5 * (5 * ref_pow(q, 4) - 36 * ref_pow(q, 3) + 90 * q * q - 84 * q + 15);
            *w2 = 20 * (5 * ref_pow(q, 3) - 27 * q * q + 45 * q - 21);
        } else {
            *w = ref_pow(3 - q, 5);
            *w1 = -5 * ref_pow(3 - q, 4);
            *w2 = 20 * ref_pow(3 - q, 3);
        }
        break;
    case SPH_KERNEL_QUARTIC: { /* knots 1/2, 3/2, 5/2: u_n = n/2 - q */
        const ref_real u5 = 2.5L - q, u3 = 1.5L - q, u1 = 0.5L - q;
        *w = ref_pow(u5, 4) - 5 * ref_tpow(u3, 4) + 10 * ref_tpow(u1, 4);
        *w1 = q < 0.5L ? 6 * q * (4 * q * q - 5) : -4 * (ref_pow(u5, 3) - 5 * ref_tpow(u3, 3));
        *w2 = 12 * (u5 * u5 - 5 * ref_tpow(u3, 2) + 10 * ref_tpow(u1, 2));
        break;
    }
    case SPH_KERNEL_WENDLAND_C2:
        if (dim == 1) {
            *w = ref_pow(1 - q / 2, 3) * (1 + 1.5L * q);
            *w1 = -3 * q * t * t / 4;
            *w2 = 3 * t * (3 * q - 2) / 4;
        } else {
            *w = ref_pow(1 - q / 2, 4) * (1 + 2 * q);
            *w1 = -5 * q * ref_pow(t, 3) / 8;
            *w2 = 5 * t * t * (2 * q - 1) / 4;
        }
        break;
    case SPH_KERNEL_WENDLAND_C4:
        if (dim == 1) {
            *w = ref_pow(1 - q / 2, 5) * (1 + 2.5L * q + 2 * q * q);
            *w1 = -7 * q * ref_pow(t, 4) * (2 * q + 1) / 32;
            *w2 = 7 * ref_pow(t, 3) * (12 * q * q - 3 * q - 2) / 32;
        } else {
            *w = ref_pow(1 - q / 2, 6) * (1 + 3 * q + 35.0L / 12 * q * q);
            *w1 = -7 * q * ref_pow(t, 5) * (5 * q + 2) / 96;
            *w2 = 7 * ref_pow(t, 4) * (35 * q * q - 8 * q - 4) / 96;
        }
        break;
    case SPH_KERNEL_WENDLAND_C6:
        if (dim == 1) {
            *w = ref_pow(1 - q / 2, 7) * (1 + 3.5L * q + 4.75L * q * q + 2.625L * ref_pow(q, 3));
            *w1 = -3 * q * ref_pow(t, 6) * (35 * q * q + 36 * q + 12) / 512;
            *w2 = 9 * ref_pow(t, 5) * (105 * ref_pow(q, 3) + 26 * q * q - 20 * q - 8) / 512;
        } else {
            *w = ref_pow(1 - q / 2, 8) * (1 + 4 * q + 6.25L * q * q + 4 * ref_pow(q, 3));
            *w1 = -11 * q * ref_pow(t, 7) * (8 * q * q + 7 * q + 2) / 512;
            *w2 = 11 * ref_pow(t, 6) * (80 * ref_pow(q, 3) + 15 * q * q - 12 * q - 4) / 512;
        }
        break;
    default: break;
    }
}

/* g(q) = w'(q)/q, with its limit w''(0) at q = 0. */
REF_FN ref_real ref_g(sph_kernel k, int dim, ref_real q)
{
    ref_real w, w1, w2;
    ref_shape(k, dim, q, &w, &w1, &w2);
    return q > 0 ? w1 / q : w2;
}

/* ---- Gauss-Legendre quadrature ---------------------------------------- */

#define REF_GL_MAX 32

/* Nodes x[] and weights c[] of the n-point rule on [-1, 1] (n <= REF_GL_MAX):
 * Newton on P_n from Chebyshev-like starting points, P_n and P_n' by the
 * three-term recurrence, c = 2 / ((1 - x^2) P_n'(x)^2). */
REF_FN void ref_gauss_legendre(int n, ref_real *x, ref_real *c)
{
    int i, j, it;
    for (i = 0; i < n; ++i) {
        ref_real z = cosl(REF_PI * (i + 0.75L) / (n + 0.5L)), dp = 1;
        for (it = 0; it < 100; ++it) {
            ref_real p0 = 1, p1 = z, dz;
            for (j = 2; j <= n; ++j) {
                const ref_real p2 = ((2 * j - 1) * z * p1 - (j - 1) * p0) / j;
                p0 = p1;
                p1 = p2;
            }
            if (n == 1) p0 = 1, p1 = z;
            dp = n * (z * p1 - p0) / (z * z - 1);
            dz = p1 / dp;
            z -= dz;
            if (fabsl(dz) <= 1e-19L * fabsl(z) || dz == 0) break;
        }
        x[i] = z;
        c[i] = 2 / ((1 - z * z) * dp * dp);
    }
}

/* int_a^b f(r) dr, the interval cut into pieces of width 1/2 starting at 0
 * (every knot of every kernel is a multiple of 1/2), n-point rule on each. */
typedef ref_real (*ref_fn)(ref_real r, void *ctx);

REF_FN ref_real ref_integrate(ref_fn f, void *ctx, ref_real a, ref_real b, int n)
{
    ref_real x[REF_GL_MAX], c[REF_GL_MAX], sum = 0, lo = a;
    int i;
    ref_gauss_legendre(n, x, c);
    while (lo < b) {
        ref_real hi = (floorl(lo * 2) + 1) / 2, mid, half;
        if (hi > b) hi = b;
        mid = (lo + hi) / 2;
        half = (hi - lo) / 2;
        for (i = 0; i < n; ++i) sum += half * c[i] * f(mid + half * x[i], ctx);
        lo = hi;
    }
    return sum;
}

/* Surface of the unit sphere in d dimensions: the radial measure s_d r^(d-1). */
REF_FN ref_real ref_sphere(int dim)
{
    return dim == 1 ? 2.0L : dim == 2 ? 2 * REF_PI : 4 * REF_PI;
}

/* The neighbouring sph_real of x in the direction of dir. */
REF_FN sph_real ref_next(sph_real x, double dir)
{
    return TH_IS_FLOAT ? (sph_real)nextafterf((float)x, (float)dir) : (sph_real)nextafter((double)x, dir);
}

/* A small deterministic generator: uniform in [-1, 1). */
REF_FN double ref_rand(uint64_t *state)
{
    *state = *state * 6364136223846793005u + 1442695040888963407u;
    return (double)(*state >> 12) / 2251799813685248.0 - 1.0;
}

/* Kernel list, in enum order, for loops; one missing does not compile. */
static const sph_kernel ref_kernels[] = {
    SPH_KERNEL_CUBIC,       SPH_KERNEL_LUCY,        SPH_KERNEL_NEW_QUARTIC, SPH_KERNEL_QUINTIC,
    SPH_KERNEL_WENDLAND_C2, SPH_KERNEL_WENDLAND_C4, SPH_KERNEL_WENDLAND_C6, SPH_KERNEL_QUARTIC};
typedef char ref_kernels_cover_every_kernel[sizeof ref_kernels / sizeof ref_kernels[0] == SPH_KERNEL_COUNT ? 1 : -1];

/* Largest relative error seen, per quantity, for the informative summary. */
REF_FN double ref_worst[8];

REF_FN void ref_track(int slot, double got, double ref)
{
    if (ref != 0) {
        const double e = fabs(got - ref) / fabs(ref);
        if (e > ref_worst[slot]) ref_worst[slot] = e;
    }
}

#endif
