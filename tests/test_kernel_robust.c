/* tests/test_kernel_robust.c - invalid input and extreme scales.
 *
 * Invalid input (documented fallback of section 3): every scalar kernel
 * function returns 0, sph_kernel_wf and sph_kernel_grad write zeros, for an
 * unknown kernel, a dimension outside 1..3, r < 0 / NaN / Inf, h <= 0 / NaN /
 * Inf / so small that 64 h^-(d+2) overflows (float 1e-30 among them);
 * sph_kernel_check and sph_check_h report SPH_EKERNEL, SPH_EDIM, SPH_EH;
 * names round-trip through sph_kernel_from_name (NULL and unknown names give
 * SPH_EKERNEL); sph_strerror is never NULL.
 *
 * The smallest usable h (64 h^-(d+2) = the largest sph_real, found here in
 * long double): just above it every quantity of every kernel is finite, just
 * below it h is refused (SPH_EH, zeros) in that dimension and still usable in
 * lower ones; 0.8 times it the true 3-D Lucy F(0) = 25.07 h^-5 overflows,
 * so the refusal is needed, not merely cautious.
 *
 * Scale: W(r, h) = h^-d W(r/h, 1), dW/dr and dW/dh scale with h^-(d+1),
 * F and d2W/dr2 with h^-(d+2), grad W with h^-(d+1); where h is refused in
 * dimension d (float 3-D below 4.5e-8) every value is 0 instead.
 *  - h = 2^k (double |k| <= 99, float |k| <= 29): r = q h and 1/h are exact,
 *    so the scaled values must be bitwise those of h = 1 times 2^(-k p)
 *    wherever that is a normal number (for grad W, at least 4 times the
 *    smallest normal: its intermediate alpha h^-(d+1) g(q) is up to kappa
 *    times smaller than the result);
 *  - h = 10^k (double 1e-30..1e30, float 1e-9..1e9): at q = 0 (no rounding
 *    of q) the relative error is <= 8 eps, and at q = 0, 0.3 kappa, 0.7 kappa
 *    every value is finite wherever the true value is a normal number.
 */
#include "kernel_ref.h"

#define REAL_MAX (TH_IS_FLOAT ? (double)FLT_MAX : DBL_MAX)
#define REAL_MIN (TH_IS_FLOAT ? (double)FLT_MIN : DBL_MIN)

enum { S_W, S_DWDR, S_F, S_D2W, S_DWDH, S_COUNT };
static const char *const sname[S_COUNT] = {"W", "dW/dr", "F", "d2W/dr2", "dW/dh"};
static const int spow[S_COUNT] = {0, 1, 2, 2, 1}; /* extra power of 1/h beyond d */

/* The documented rule of sph_check_h in dimension dim: h refused where
 * 64 h^-(dim+2) exceeds the largest sph_real (long double, no sph_real rounding). */
static int h_refused(long double h, int dim) { return 64.0L / powl(h, dim + 2) > (long double)REAL_MAX; }

static sph_real scalar(int which, sph_kernel k, int dim, sph_real r, sph_real h)
{
    switch (which) {
    case S_W: return sph_kernel_w(k, dim, r, h);
    case S_DWDR: return sph_kernel_dwdr(k, dim, r, h);
    case S_F: return sph_kernel_f(k, dim, r, h);
    case S_D2W: return sph_kernel_d2wdr2(k, dim, r, h);
    default: return sph_kernel_dwdh(k, dim, r, h);
    }
}

/* Every entry point gives its fallback (0, zeros) for (k, dim, r, h). */
static void expect_fallback(sph_kernel k, int dim, sph_real r, sph_real h, const char *what)
{
    sph_real W = 7, F = 7, g[3] = {7, 7, 7}, dx[3];
    int i;
    for (i = 0; i < S_COUNT; ++i)
        TH_CHECK(scalar(i, k, dim, r, h) == 0, "%s: %s = %g", what, sname[i], (double)scalar(i, k, dim, r, h));
    sph_kernel_wf(k, dim, r, h, &W, &F);
    TH_CHECK(W == 0 && F == 0, "%s: wf wrote W = %g, F = %g", what, (double)W, (double)F);
    if (r < 0 && r > -(sph_real)REAL_MAX) return; /* a negative component is a valid separation for grad */
    dx[0] = r;
    dx[1] = dx[2] = 0;
    sph_kernel_grad(k, dim, dx, h, g);
    for (i = 0; i < 3 && i < dim; ++i) TH_CHECK(g[i] == 0, "%s: grad[%d] = %g", what, i, (double)g[i]);
}

static void test_invalid(void)
{
    const sph_real inf = (sph_real)HUGE_VAL, nan = (sph_real)NAN;
    const sph_real sub = TH_IS_FLOAT ? (sph_real)1e-40f : (sph_real)1e-310;
    const sph_kernel bad_k[3] = {(sph_kernel)-1, SPH_KERNEL_COUNT, (sph_kernel)100};
    const int bad_dim[3] = {0, 4, -1};
    const sph_real bad_r[4] = {-1, -(sph_real)1e-30, nan, inf};
    const sph_real tiny = TH_IS_FLOAT ? (sph_real)1e-30f : (sph_real)1e-110; /* 1/h finite, 64 h^-3 not */
    const sph_real bad_h[8] = {0, -1, -0.0, nan, inf, -inf, sub, tiny};
    int i, ik, dim;
    th_begin("invalid kernel: zeros, SPH_EKERNEL, alpha/sigma/support/neighbours 0");
    for (i = 0; i < 3; ++i) {
        expect_fallback(bad_k[i], 3, (sph_real)0.5, 1, "bad kernel");
        TH_CHECK(sph_kernel_check(bad_k[i], 3) == SPH_EKERNEL, "check = %d", sph_kernel_check(bad_k[i], 3));
        TH_CHECK(sph_kernel_alpha(bad_k[i], 3) == 0 && sph_kernel_sigma(bad_k[i], 3) == 0 &&
                     sph_kernel_support(bad_k[i]) == 0,
                 "constants of a bad kernel");
        TH_CHECK(sph_kernel_neighbours(bad_k[i], 3, 1, 1) == 0 && sph_kernel_h_for_neighbours(bad_k[i], 3, 50, 1) == 0,
                 "neighbours of a bad kernel");
        TH_CHECK(strcmp(sph_kernel_name(bad_k[i]), "invalid") == 0, "name %s", sph_kernel_name(bad_k[i]));
    }
    th_end();
    for (ik = 0; ik < SPH_KERNEL_COUNT; ++ik) {
        const sph_kernel k = ref_kernels[ik];
        th_begin("invalid dim, r, h: zeros and status codes, %s", sph_kernel_name(k));
        for (i = 0; i < 3; ++i) {
            expect_fallback(k, bad_dim[i], (sph_real)0.5, 1, "bad dim");
            TH_CHECK(sph_kernel_check(k, bad_dim[i]) == SPH_EDIM, "check(dim %d)", bad_dim[i]);
            TH_CHECK(sph_kernel_alpha(k, bad_dim[i]) == 0 && sph_kernel_sigma(k, bad_dim[i]) == 0, "dim %d",
                     bad_dim[i]);
        }
        for (dim = 1; dim <= 3; ++dim) {
            TH_CHECK(sph_kernel_check(k, dim) == SPH_OK, "check(%d)", dim);
            for (i = 0; i < 4; ++i) expect_fallback(k, dim, bad_r[i], 1, "bad r");
            /* valid r and h whose quotient overflows: q = +Inf is outside the
             * support, every value is 0 (it was NaN: 0 * Inf in the zero row) */
            expect_fallback(k, dim, (sph_real)(TH_IS_FLOAT ? FLT_MAX / 2 : DBL_MAX / 2), (sph_real)1e-3,
                            "r / h overflows");
            for (i = 0; i < 8; ++i) {
                expect_fallback(k, dim, (sph_real)0.5 * (sph_real)1e-30, bad_h[i], "bad h");
                TH_CHECK(sph_check_h(bad_h[i]) == SPH_EH, "sph_check_h(%g) = %d", (double)bad_h[i],
                         sph_check_h(bad_h[i]));
                TH_CHECK(sph_kernel_neighbours(k, dim, bad_h[i], 1) == 0, "neighbours(h = %g)", (double)bad_h[i]);
            }
            TH_CHECK(sph_kernel_neighbours(k, dim, 1, 0) == 0 && sph_kernel_neighbours(k, dim, 1, -1) == 0 &&
                         sph_kernel_neighbours(k, dim, 1, nan) == 0,
                     "neighbours with V <= 0 or NaN");
            TH_CHECK(sph_kernel_h_for_neighbours(k, dim, 0, 1) == 0 && sph_kernel_h_for_neighbours(k, dim, nan, 1) == 0 &&
                         sph_kernel_h_for_neighbours(k, dim, 50, 0) == 0,
                     "h_for_neighbours with N or V invalid");
            {
                /* non-finite separation: grad writes zeros */
                sph_real dx[3] = {nan, 0, 0}, g[3] = {7, 7, 7};
                int a;
                sph_kernel_grad(k, dim, dx, 1, g);
                for (a = 0; a < dim; ++a) TH_CHECK(g[a] == 0, "grad(NaN dx)[%d] = %g", a, (double)g[a]);
                dx[0] = inf;
                sph_kernel_grad(k, dim, dx, 1, g);
                for (a = 0; a < dim; ++a) TH_CHECK(g[a] == 0, "grad(Inf dx)[%d] = %g", a, (double)g[a]);
            }
        }
        th_end();
    }
    th_begin("sph_check_h accepts usable h");
    TH_CHECK(sph_check_h(1) == SPH_OK && sph_check_h((sph_real)(TH_IS_FLOAT ? 1e-7 : 1e-60)) == SPH_OK &&
                 sph_check_h((sph_real)REAL_MAX) == SPH_OK,
             "usable h rejected");
    th_end();
}

/* The boundary of sph_check_h and of the per-dimension rule of the scalar functions. */
static void test_h_boundary(void)
{
    static const double qf[4] = {0, 0.3, 0.7, 0.95};
    int ik, dim, i, j, a;
    for (dim = 1; dim <= 3; ++dim) {
        const long double hb = powl(64.0L / (long double)REAL_MAX, 1.0L / (dim + 2));
        const sph_real h_in = (sph_real)(hb * 1.0001L), h_out = (sph_real)(hb * 0.9999L);
        th_begin("smallest usable h in %dD (%.4Lg): above it every quantity finite, below it zeros", dim, hb);
        TH_CHECK(!h_refused(h_in, dim) && h_refused(h_out, dim), "the test's own h straddle the bound");
        if (dim == 3) {
            const long double F_true = (long double)sph_kernel_f(SPH_KERNEL_LUCY, 3, 0, 1) / powl(hb * 0.8L, 5);
            TH_CHECK(sph_check_h(h_in) == SPH_OK && sph_check_h(h_out) == SPH_EH, "sph_check_h(%g) = %d, (%g) = %d",
                     (double)h_in, sph_check_h(h_in), (double)h_out, sph_check_h(h_out));
            TH_CHECK(fabsl(F_true) > (long double)REAL_MAX, "at 0.8 of the bound Lucy 3-D F(0) = %Lg fits: the bound is loose",
                     F_true);
        }
        for (ik = 0; ik < SPH_KERNEL_COUNT; ++ik) {
            const sph_kernel k = ref_kernels[ik];
            for (j = 0; j < 4; ++j) {
                const sph_real q = (sph_real)(qf[j] * (double)sph_kernel_support(k));
                sph_real dx[3] = {0, 0, 0}, g[3] = {7, 7, 7}, W = 7, F = 7;
                for (i = 0; i < S_COUNT; ++i) {
                    const double in = (double)scalar(i, k, dim, q * h_in, h_in);
                    const double out = (double)scalar(i, k, dim, q * h_out, h_out);
                    TH_CHECK(isfinite(in) && (j > 0 || i == S_DWDR || in != 0), "%s q %g: %s = %g at h just usable",
                             sph_kernel_name(k), (double)q, sname[i], in);
                    TH_CHECK(out == 0, "%s: %s = %g at h just refused", sph_kernel_name(k), sname[i], out);
                }
                sph_kernel_wf(k, dim, q * h_in, h_in, &W, &F);
                TH_CHECK(isfinite((double)W) && isfinite((double)F), "wf: %g %g", (double)W, (double)F);
                dx[0] = q * h_in;
                sph_kernel_grad(k, dim, dx, h_in, g);
                for (a = 0; a < dim; ++a) TH_CHECK(isfinite((double)g[a]), "grad[%d] = %g", a, (double)g[a]);
                if (dim > 1) /* refused in dim is still usable in dim - 1 (a bound per dimension) */
                    TH_CHECK(sph_kernel_w(k, dim - 1, 0, h_out) > 0, "%s: W in %dD = 0 at an h usable there",
                             sph_kernel_name(k), dim - 1);
            }
        }
        th_end();
    }
}

static void test_names(void)
{
    int ik, s;
    th_begin("kernel names round-trip; NULL and unknown names give SPH_EKERNEL; sph_strerror never NULL");
    for (ik = 0; ik < SPH_KERNEL_COUNT; ++ik)
        TH_CHECK(sph_kernel_from_name(sph_kernel_name(ref_kernels[ik])) == (int)ref_kernels[ik], "%s",
                 sph_kernel_name(ref_kernels[ik]));
    TH_CHECK(sph_kernel_from_name(NULL) == SPH_EKERNEL, "NULL");
    TH_CHECK(sph_kernel_from_name("") == SPH_EKERNEL, "empty");
    TH_CHECK(sph_kernel_from_name("cubi") == SPH_EKERNEL && sph_kernel_from_name("cubic ") == SPH_EKERNEL &&
                 sph_kernel_from_name("invalid") == SPH_EKERNEL && sph_kernel_from_name("wendland") == SPH_EKERNEL,
             "prefix/suffix/unknown names");
    for (s = -100; s <= 100; ++s) TH_CHECK(sph_strerror(s) != NULL && sph_strerror(s)[0] != '\0', "strerror(%d)", s);
    TH_CHECK(strcmp(sph_strerror(SPH_OK), sph_strerror(SPH_EH)) != 0, "distinct sentences");
    th_end();
}

/* h = 2^k: bitwise h^-p scaling wherever the result is a normal number. */
static void test_scale_pow2(sph_kernel k, int dim)
{
    static const double qs[] = {0, 0.13, 0.3, 0.55, 0.7, 0.95};
    const int kmax = TH_IS_FLOAT ? 29 : 99;
    const double kap = (double)sph_kernel_support(k);
    int e, i, j, a;
    th_begin("scale invariance h = 2^k, |k| <= %d, bitwise, %s %dD", kmax, sph_kernel_name(k), dim);
    for (e = -kmax; e <= kmax; ++e) {
        const sph_real h = (sph_real)ldexp(1.0, e);
        for (j = 0; j < 6; ++j) {
            const sph_real q = (sph_real)(qs[j] * kap), r = q * h;
            sph_real dx[3] = {0, 0, 0}, dx1[3] = {0, 0, 0}, g[3], g1[3];
            if (h_refused(h, dim)) { /* refused in this dimension: every value 0 */
                for (i = 0; i < S_COUNT; ++i)
                    TH_CHECK(scalar(i, k, dim, r, h) == 0, "h = 2^%d refused: %s = %g", e, sname[i],
                             (double)scalar(i, k, dim, r, h));
                continue;
            }
            for (i = 0; i < S_COUNT; ++i) {
                const long double want = ldexpl((long double)scalar(i, k, dim, q, 1), -e * (dim + spow[i]));
                const double got = (double)scalar(i, k, dim, r, h);
                if (want == 0 || (fabsl(want) >= REAL_MIN && fabsl(want) <= REAL_MAX))
                    TH_CHECK(got == (double)want, "h = 2^%d, q = %g: %s = %.17g, want %.17Lg", e, (double)q, sname[i],
                             got, want);
            }
            for (a = 0; a < dim; ++a) {
                dx1[a] = q * (sph_real)(a == 0 ? 0.6 : a == 1 ? -0.8 : 0.0);
                dx[a] = dx1[a] * h;
            }
            sph_kernel_grad(k, dim, dx, h, g);
            sph_kernel_grad(k, dim, dx1, 1, g1);
            for (a = 0; a < dim; ++a) {
                const long double want = ldexpl((long double)g1[a], -e * (dim + 1));
                /* grad forms alpha h^-(d+1) g(q) before the factor dx/h <= kappa:
                 * keep a margin of 4 above the smallest normal for it */
                if (want == 0 || (fabsl(want) >= 4 * REAL_MIN && fabsl(want) <= REAL_MAX))
                    TH_CHECK((double)g[a] == (double)want, "h = 2^%d: grad[%d] = %.17g, want %.17Lg", e, a,
                             (double)g[a], want);
            }
        }
    }
    th_end();
}

/* h = 10^k: finite wherever representable, 8 eps at q = 0. */
static double worst_scale;

static void test_scale_pow10(sph_kernel k, int dim)
{
    const int kmax = TH_IS_FLOAT ? 9 : 30;
    const double kap = (double)sph_kernel_support(k);
    int e, i, j, a;
    th_begin("scale h = 1e-%d..1e%d: finite where representable, 8 eps at r = 0, %s %dD", kmax, kmax,
             sph_kernel_name(k), dim);
    for (e = -kmax; e <= kmax; ++e) {
        const long double hl = powl(10.0L, e);
        const sph_real h = (sph_real)hl;
        for (j = 0; j < 3; ++j) {
            const sph_real q = (sph_real)(j == 0 ? 0 : j == 1 ? 0.3 * kap : 0.7 * kap);
            const sph_real r = q * h;
            sph_real dx[3] = {0, 0, 0}, g[3];
            if (h_refused(h, dim)) { /* refused in this dimension: every value 0 */
                for (i = 0; i < S_COUNT; ++i)
                    TH_CHECK(scalar(i, k, dim, r, h) == 0, "h = 1e%d refused: %s = %g", e, sname[i],
                             (double)scalar(i, k, dim, r, h));
                continue;
            }
            for (i = 0; i < S_COUNT; ++i) {
                const long double want = (long double)scalar(i, k, dim, q, 1) / powl((long double)h, dim + spow[i]);
                const double got = (double)scalar(i, k, dim, r, h);
                if (fabsl(want) >= REAL_MIN && fabsl(want) <= REAL_MAX) {
                    TH_CHECK(isfinite(got) && got != 0, "h = 1e%d, q = %g: %s = %g, true %Lg", e, (double)q,
                             sname[i], got, want);
                    if (j == 0) {
                        TH_CHECK(fabsl(got - want) <= 8 * TH_EPS * fabsl(want), "h = 1e%d, r = 0: %s = %.17g, want %.17Lg",
                                 e, sname[i], got, want);
                        if ((double)(fabsl(got - want) / fabsl(want)) > worst_scale)
                            worst_scale = (double)(fabsl(got - want) / fabsl(want));
                    }
                }
            }
            dx[dim - 1] = r;
            sph_kernel_grad(k, dim, dx, h, g);
            {
                const long double want = (long double)sph_kernel_dwdr(k, dim, q, 1) / powl((long double)h, dim + 1);
                for (a = 0; a < dim; ++a) TH_CHECK(isfinite((double)g[a]), "grad[%d] = %g", a, (double)g[a]);
                if (fabsl(want) >= REAL_MIN && fabsl(want) <= REAL_MAX)
                    TH_CHECK(g[dim - 1] != 0, "h = 1e%d, q = %g: grad = 0, true %Lg", e, (double)q, want);
            }
        }
    }
    th_end();
}

int main(void)
{
    int ik, dim;
    test_invalid();
    test_h_boundary();
    test_names();
    for (ik = 0; ik < SPH_KERNEL_COUNT; ++ik) {
        for (dim = 1; dim <= 3; ++dim) {
            test_scale_pow2(ref_kernels[ik], dim);
            test_scale_pow10(ref_kernels[ik], dim);
        }
    }
    printf("info [%s]: worst relative error of the h^-p scaling at r = 0, h = 10^k: %.3g (%.2f eps)\n", TH_PRECISION,
           worst_scale, worst_scale / TH_EPS);
    return th_summary();
}
