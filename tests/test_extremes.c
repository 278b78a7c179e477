/* Extreme and degenerate cases: each case states the outcome the library
 * promises (docs/operators.md, "Extreme cases") - a finite, correct value, or
 * a documented status code or fallback - and asserts it. Never NaN, never a
 * crash (run under the sanitizers in the sanitised builds of tests/run.sh).
 *
 * Reference values are analytic: w(0) and w''(0) of each kernel from the
 * polynomials of docs/kernels.md (derived by hand in the comments below),
 * scale covariance, translation invariance with a rounding bound, exact
 * two-particle sums, and the piecewise-linear steady profile of a two-layer
 * slab.
 */
#include "op_scene.h"
#include "xo_ops.h"

#define SENT ((sph_real)12345)

static sph_kernel K(int k) { return (sph_kernel)k; }
static double kap(int k) { return (double)sph_kernel_support(K(k)); }
static double ulp_of(double x) /* spacing of sph_real at |x| */
{
    const sph_real y = (sph_real)fabs(x);
    return TH_IS_FLOAT ? (double)(nextafterf((float)y, FLT_MAX) - (float)y) : nextafter((double)y, DBL_MAX) - (double)y;
}

/* w(0) and w''(0) of the dimensionless shapes (docs/kernels.md; Taylor
 * expansions about q = 0 worked by hand):
 *   cubic 2/3 - q^2 ...              w0 2/3, w'' -2
 *   Lucy (1+3q)(1-q)^3 = 1 - 6q^2 ... w0 1,   w'' -12
 *   new quartic 2/3 - 9/8 q^2 ...    w0 2/3, w'' -9/4
 *   quintic (3-q)^5 - 6(2-q)^5 + 15(1-q)^5: w0 243-192+15 = 66,
 *       w'' = 20 (27 - 6*8 + 15) = -120
 *   Wendland 2-D/3-D: C2 (1-2q+3/2q^2)(1+2q) -> -5/2 q^2: w'' -5;
 *       C4 (1-3q+15/4q^2)(1+3q+35/12q^2) -> -7/3 q^2: w'' -14/3;
 *       C6 (1-4q+7q^2)(1+4q+25/4q^2) -> -11/4 q^2: w'' -11/2; w0 1
 *   Wendland 1-D in s = q/2: C2 (1-s)^3(1+3s) -> -6 s^2: w'' -3;
 *       C4 (1-s)^5(1+5s+8s^2) -> -7 s^2: w'' -7/2;
 *       C6 (1-s)^7(1+7s+19s^2+21s^3) -> -9 s^2: w'' -9/2; w0 1
 *   quartic (5/2-q)^4 - 5(3/2-q)^4 + 10(1/2-q)^4: w0 (625 - 405 + 10)/16
 *       = 115/8, w'' = 12 (25/4 - 5*9/4 + 10/4) = -30
 * One entry per kernel in enum order: a kernel without one does not compile. */
static const double w0_k[] = {2.0 / 3, 1, 2.0 / 3, 66, 1, 1, 1, 115.0 / 8};
static const double w2_k[] = {-2, -12, -9.0 / 4, -120, -5, -14.0 / 3, -11.0 / 2, -30};
typedef char w0_w2_cover_every_kernel[sizeof w0_k / sizeof w0_k[0] == SPH_KERNEL_COUNT &&
                                              sizeof w2_k / sizeof w2_k[0] == SPH_KERNEL_COUNT
                                          ? 1
                                          : -1];
static double w0_of(int k) { return w0_k[k]; }
static double w2_of(int k, int dim)
{
    static const double w2_1d[3] = {-3, -7.0 / 2, -9.0 / 2}; /* Wendland C2, C4, C6 */
    return k >= SPH_KERNEL_WENDLAND_C2 && k <= SPH_KERNEL_WENDLAND_C6 && dim == 1 ? w2_1d[k - SPH_KERNEL_WENDLAND_C2]
                                                                                   : w2_k[k];
}

/* ---- a small scene from given positions: V = m = vol, rho = 1, linear fields ---- */
typedef struct {
    int dim, n;
    sph_real *x, *V, *rho, *f, *v, *kc;
    tp_list L;
    sph_ctx c;
    xo_in in;
} xs_scene;

/* Two particles that see each other whatever their distance (the reference
 * search would leave out a pair at r >= kappa h): the full 2 x 2 list. */
static const sph_off xs_pair_off[3] = {0, 2, 4};
static const sph_idx xs_pair_idx[4] = {0, 1, 0, 1};
static const sph_neighbours xs_pair_list = SPH_NEIGHBOURS_INIT(2, 2, xs_pair_off, xs_pair_idx);

static void xs_make(xs_scene *s, sph_kernel k, int dim, int n, const sph_real *x, double h, double vol)
{
    int i, a;
    s->dim = dim, s->n = n;
    s->x = ts_vec(3 * n), s->V = ts_vec(n), s->rho = ts_vec(n), s->f = ts_vec(n), s->v = ts_vec(3 * n);
    s->kc = ts_vec(n);
    if (n > 0) memcpy(s->x, x, sizeof(sph_real) * 3 * (size_t)n);
    for (i = 0; i < n; ++i) {
        s->V[i] = (sph_real)vol, s->rho[i] = 1, s->kc[i] = 1;
        s->f[i] = (sph_real)ts_linear(s->x + 3 * i);
        for (a = 0; a < 3; ++a) s->v[3 * i + a] = (sph_real)ts_vlinear(s->x + 3 * i, a);
    }
    tp_brute_list(dim, s->x, n, s->x, n, (sph_real)h, NULL, NULL, sph_kernel_support(k), TP_GATHER, NULL, &s->L);
    s->c = sph_ctx_init(k, dim, (sph_real)h, &s->L.list, sph_view_interleaved(s->x, 3));
    s->c.V = s->c.m = sph_view_soa(s->V, NULL, NULL);
    s->c.rho = sph_view_soa(s->rho, NULL, NULL);
    s->in.f = sph_view_soa(s->f, NULL, NULL), s->in.ft = sph_view_none();
    s->in.v = sph_view_interleaved(s->v, 3), s->in.vt = sph_view_none();
    s->in.k = sph_view_soa(s->kc, NULL, NULL), s->in.kt = sph_view_none();
}

static void xs_free(xs_scene *s)
{
    free(s->x), free(s->V), free(s->rho), free(s->f), free(s->v), free(s->kc);
    tp_free_list(&s->L);
}

/* Every operator returned SPH_OK (SPH_EDIM for curl in 1-D) and wrote only finite values. */
static void check_all_finite(const xo_res *R, int dim, const char *what)
{
    int op;
    for (op = 0; op < XO_N; ++op) {
        const int want = xo_defined(op, dim) ? SPH_OK : SPH_EDIM;
        TH_CHECK(R->status[op] == want, "%s: %s status %d", what, xo_names[op], R->status[op]);
        TH_CHECK(xo_first_nonfinite(R, op) < 0, "%s: %s non-finite at entry %d", what, xo_names[op],
                 xo_first_nonfinite(R, op));
    }
}

/* ======================================================================== */
/* 1. coincident particles: r = 0 in every kernel function and operator      */
/* ======================================================================== */
static void test_r0_kernels(void)
{
    int k, dim;
    const double h = 0.7;
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim) {
            const double a = (double)sph_kernel_alpha(K(k), dim);
            const double W0 = a * w0_of(k) / pow(h, dim), F0 = a * w2_of(k, dim) / pow(h, dim + 2);
            const sph_real dx[3] = {0, 0, 0};
            sph_real g[3] = {9, 9, 9}, W = 9, F = 9;
            sph_pair p;
            th_begin("r = 0: %s %dD: W, F, d2W/dr2, dW/dh from w(0), w''(0); dW/dr = grad W = 0",
                     sph_kernel_name(K(k)), dim);
            TH_REL(sph_kernel_w(K(k), dim, 0, (sph_real)h), W0, 8 * TH_EPS);
            TH_REL(sph_kernel_f(K(k), dim, 0, (sph_real)h), F0, 8 * TH_EPS);
            TH_REL(sph_kernel_d2wdr2(K(k), dim, 0, (sph_real)h), F0, 8 * TH_EPS);
            TH_REL(sph_kernel_dwdh(K(k), dim, 0, (sph_real)h), -dim * W0 / h, 8 * TH_EPS);
            TH_CHECK(sph_kernel_dwdr(K(k), dim, 0, (sph_real)h) == 0, "dW/dr(0) != 0");
            sph_kernel_wf(K(k), dim, 0, (sph_real)h, &W, &F);
            TH_REL(W, W0, 8 * TH_EPS);
            TH_REL(F, F0, 8 * TH_EPS);
            sph_kernel_grad(K(k), dim, dx, (sph_real)h, g);
            TH_CHECK(g[0] == 0 && (dim < 2 || g[1] == 0) && (dim < 3 || g[2] == 0), "grad W(0) != 0");
            p = sph_pair_kernel(K(k), dim, dx, (sph_real)h);
            TH_REL(p.W, W0, 8 * TH_EPS);
            TH_REL(p.F, F0, 8 * TH_EPS);
            th_end();
        }
}

/* Two particles on the same spot (plus the self terms): every operator is
 * finite and equals its exact two-term sum. x_ij = 0, so every gradient,
 * divergence and curl term vanishes; the Laplacian pair term is
 * 2 V (f_i - f_j) F(0), the diffusion one V k_ij (f_i - f_j) F(0); M = 0, so
 * every corrected operator falls back (count 2) and B = I. */
static void test_r0_operators(void)
{
    int k, dim, i, a, op;
    const double h = 0.6, V = 0.3;
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim) {
            sph_real x[6] = {(sph_real)0.25, (sph_real)-0.5, (sph_real)0.125, 0, 0, 0};
            const double a0 = (double)sph_kernel_alpha(K(k), dim);
            const double W0 = a0 * w0_of(k) / pow(h, dim), F0 = a0 * w2_of(k, dim) / pow(h, dim + 2);
            xs_scene s;
            xo_res R;
            for (a = 0; a < 3; ++a) x[3 + a] = a < dim ? x[a] : 0;
            th_begin("coincident particles: %s %dD, every operator exact and finite", sph_kernel_name(K(k)), dim);
            xs_make(&s, K(k), dim, 2, x, h, V);
            s.f[0] = 1, s.f[1] = 3; /* different values on the same spot */
            s.kc[0] = 1, s.kc[1] = 1000;
            xo_alloc(&R, 2, 0);
            xo_run(&s.c, &s.in, &R);
            check_all_finite(&R, dim, "coincident");
            for (i = 0; i < 2; ++i) {
                const double fi = s.f[i], fj = s.f[1 - i];
                TH_REL(R.o[XO_DENSITY][i], 2 * V * W0, 8 * TH_EPS);
                TH_REL(R.o[XO_INTERP][i], V * W0 * 4, 8 * TH_EPS);
                TH_REL(R.o[XO_SHEPARD][i], 2, 8 * TH_EPS);
                TH_REL(R.o[XO_LAP][i], 2 * V * (fi - fj) * F0, 16 * TH_EPS);
                TH_REL(R.o[XO_DIFFUSION][i], V * (4.0 * 1000 / 1001) * (fi - fj) * F0, 16 * TH_EPS);
                for (op = XO_GRAD_STD; op <= XO_CURL_DIFF; ++op)
                    for (a = 0; a < 9; ++a) TH_CHECK(R.o[op][9 * i + a] == 0, "%s != 0", xo_names[op]);
                for (a = 0; a < dim * dim; ++a)
                    TH_CHECK(R.o[XO_CORRECTION][9 * i + a] == (a % (dim + 1) == 0), "B != I");
            }
            TH_CHECK(R.count[XO_GRAD_CORR] == 2 && R.count[XO_GV_CORR] == 2 && R.count[XO_DIV_CORR] == 2 &&
                         R.count[XO_CORRECTION] == 2, "fallback counts %d %d %d %d (expected 2)",
                     (int)R.count[XO_GRAD_CORR], (int)R.count[XO_GV_CORR], (int)R.count[XO_DIV_CORR],
                     (int)R.count[XO_CORRECTION]);
            xo_free(&R);
            xs_free(&s);
            th_end();
        }
}

/* A duplicated particle inside a perturbed lattice: still finite, and the
 * corrected gradient of a linear field (linear in the stored positions, so
 * equal on the two copies) stays exact; no fallback. */
static void test_r0_in_cloud(void)
{
    int dim;
    for (dim = 2; dim <= 3; ++dim) {
        ts_scene t;
        xs_scene s;
        xo_res R;
        sph_real *x;
        int n, i, a;
        th_begin("duplicate particle in a %dD cloud: finite everywhere, corrected gradient exact", dim);
        ts_lattice(&t, SPH_KERNEL_WENDLAND_C4, dim, dim == 2 ? 8 : 5, 0.1, 1.3, 0.2, 3, NULL);
        n = t.n + 1;
        x = ts_vec(3 * n);
        memcpy(x, t.x, sizeof(sph_real) * 3 * (size_t)t.n);
        for (a = 0; a < 3; ++a) x[3 * t.n + a] = t.x[3 * (t.n / 2) + a];
        xs_make(&s, SPH_KERNEL_WENDLAND_C4, dim, n, x, t.h, pow(0.1, dim));
        xo_alloc(&R, n, 0);
        xo_run(&s.c, &s.in, &R);
        check_all_finite(&R, dim, "duplicate");
        TH_CHECK(R.count[XO_GRAD_CORR] == 0, "fallbacks %d", (int)R.count[XO_GRAD_CORR]);
        for (i = 0; i < n; ++i)
            for (a = 0; a < dim; ++a) TH_NEAR(R.o[XO_GRAD_CORR][3 * i + a], ts_ga(a), 1e3 * TH_EPS);
        xo_free(&R);
        xs_free(&s);
        ts_free(&t);
        free(x);
        th_end();
    }
}

/* ======================================================================== */
/* 2. r at, one ulp inside and one ulp outside the support                   */
/* ======================================================================== */
static void test_support_edge(void)
{
    int k, dim, ih;
    const double hs[3] = {0.5, 0.7, 3e-3};
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim) {
            th_begin("support edge: %s %dD: 0 at r = kappa h and one ulp out; one ulp in: tiny, right sign",
                     sph_kernel_name(K(k)), dim);
            for (ih = 0; ih < 3; ++ih) {
                const sph_real h = (sph_real)hs[ih];
                sph_real R = sph_kernel_support(K(k)) * h, out, in;
                /* "at the support": an r whose q = r / h (one rounding, as
                 * the library forms it) is kappa; fl(kappa h) may sit one ulp
                 * below (then W there is the one-ulp-inside value). "One ulp
                 * in": the largest r whose q is below kappa, which for kappa
                 * h not exact (2.5 x 0.7) can be more than one ulp of r below
                 * R, as r / h rounds to kappa over more than one r */
                while ((sph_real)(R / h) < sph_kernel_support(K(k)))
                    R = TH_IS_FLOAT ? nextafterf((float)R, FLT_MAX) : nextafter((double)R, DBL_MAX);
                out = TH_IS_FLOAT ? nextafterf((float)R, FLT_MAX) : nextafter((double)R, DBL_MAX);
                in = R;
                do
                    in = TH_IS_FLOAT ? nextafterf((float)in, 0) : nextafter((double)in, 0);
                while (!((sph_real)(in / h) < sph_kernel_support(K(k))));
                const double scale = (double)sph_kernel_alpha(K(k), dim) / pow((double)h, dim);
                /* the new quartic is (2-q)^2 (1/6 + q/6 - 5q^2/32): negative and
                 * rising near q = 2; every other kernel positive and falling */
                const double sgn = k == SPH_KERNEL_NEW_QUARTIC ? -1 : 1;
                sph_real r;
                int e;
                for (e = 0; e < 2; ++e) {
                    r = e == 0 ? R : out;
                    TH_CHECK(sph_kernel_w(K(k), dim, r, h) == 0 && sph_kernel_f(K(k), dim, r, h) == 0 &&
                                 sph_kernel_dwdr(K(k), dim, r, h) == 0 && sph_kernel_dwdh(K(k), dim, r, h) == 0,
                             "h %g, r %s support: W %g F %g not exactly 0", (double)h, e ? "beyond" : "at",
                             (double)sph_kernel_w(K(k), dim, r, h), (double)sph_kernel_f(K(k), dim, r, h));
                }
                TH_CHECK(sph_kernel_d2wdr2(K(k), dim, out, h) == 0, "d2W/dr2 beyond support != 0");
                {
                    const double W = (double)sph_kernel_w(K(k), dim, in, h);
                    const double D = (double)sph_kernel_dwdr(K(k), dim, in, h);
                    /* w ~ c t^p, t = kappa - q ~ one ulp: |W| <= scale (8 eps)^2 (p >= 2) */
                    TH_CHECK(sgn * W >= 0 && fabs(W) <= scale * 64 * TH_EPS * TH_EPS,
                             "h %g one ulp inside: W = %g (scale %g)", (double)h, W, scale);
                    TH_CHECK(sgn * D <= 0, "h %g one ulp inside: dW/dr = %g has the wrong sign", (double)h, D);
                    if (!TH_IS_FLOAT) TH_CHECK(W != 0, "h %g one ulp inside: W = 0 (continuity lost)", (double)h);
                }
            }
            th_end();
        }
    /* in an operator: a neighbour exactly at kappa h adds exactly nothing */
    for (k = 0; k < SPH_KERNEL_COUNT; ++k) {
        const sph_real h = (sph_real)0.5;
        sph_real x[6] = {0, 0, 0, 0, 0, 0};
        xs_scene s;
        xo_res R;
        th_begin("operators: neighbour at exactly kappa h contributes 0 (%s 1D)", sph_kernel_name(K(k)));
        x[3] = sph_kernel_support(K(k)) * h; /* exact: kappa h is a dyadic number */
        xs_make(&s, K(k), 1, 2, x, h, 1);
        /* the reference list leaves it out (r < kappa h fails): put it in by hand */
        {
            s.c.list = &xs_pair_list;
            xo_alloc(&R, 2, 0);
            xo_run(&s.c, &s.in, &R);
            check_all_finite(&R, 1, "edge");
            TH_CHECK((double)R.o[XO_DENSITY][0] == (double)sph_kernel_w(K(k), 1, 0, h), "density %g, W(0) %g",
                     (double)R.o[XO_DENSITY][0], (double)sph_kernel_w(K(k), 1, 0, h));
            TH_CHECK(R.o[XO_GRAD_STD][0] == 0 && R.o[XO_LAP][0] == 0, "gradient %g laplacian %g",
                     (double)R.o[XO_GRAD_STD][0], (double)R.o[XO_LAP][0]);
            TH_CHECK(R.count[XO_GRAD_CORR] == 2, "isolated in effect: %d fallbacks", (int)R.count[XO_GRAD_CORR]);
            xo_free(&R);
        }
        xs_free(&s);
        th_end();
    }
}

/* ======================================================================== */
/* 3. h from 1e-30 to 1e30 (float 1e-9 .. 1e9): scale covariance             */
/* ======================================================================== */
/* v = value at (r, h), ref = the unit-h value times h^-p (in double): 0 where
 * h is refused in dim dimensions (64 h^-(dim+2) beyond the largest sph_real:
 * sph_check_h's rule, which every value that would overflow falls under),
 * else equal to 64 eps relative where ref is a normal sph_real, within the
 * smallest normal where it underflows. */
static void check_scaled(double v, double ref, const char *what, double h, int dim, double q)
{
    const double big = TH_IS_FLOAT ? FLT_MAX : DBL_MAX, tiny = TH_IS_FLOAT ? FLT_MIN : DBL_MIN;
    if (64 / pow((double)(sph_real)h, dim + 2) > big)
        TH_CHECK(v == 0, "%s h %g q %g: %g, h refused (true value %g)", what, h, q, v, ref);
    else if (fabs(ref) < tiny / TH_EPS)
        TH_CHECK(fabs(v - ref) <= 2 * tiny, "%s h %g q %g: %g vs %g", what, h, q, v, ref);
    else
        TH_CHECK(fabs(v - ref) <= 64 * TH_EPS * fabs(ref), "%s h %g q %g: %.17g vs %.17g", what, h, q, v, ref);
}

static void test_h_range_kernels(void)
{
    const int emax = TH_IS_FLOAT ? 9 : 30;
    const double qf[4] = {0, 0.1, 0.35, 0.6};
    int k, dim, e, iq;
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim) {
            th_begin("h = 1e-%d .. 1e%d: W(r,h) = W(r/h,1)/h^d, F, dW/dr likewise: %s %dD", emax, emax,
                     sph_kernel_name(K(k)), dim);
            for (e = -emax; e <= emax; ++e) {
                const double h = pow(10, e);
                for (iq = 0; iq < 4; ++iq) {
                    const sph_real q = (sph_real)(qf[iq] * kap(k)), r = q * (sph_real)h;
                    const double qq = (double)r / (double)(sph_real)h; /* the q the library sees */
                    const sph_real q1 = (sph_real)qq;
                    check_scaled((double)sph_kernel_w(K(k), dim, r, (sph_real)h),
                                 (double)sph_kernel_w(K(k), dim, q1, 1) / pow((double)(sph_real)h, dim), "W", h, dim, qq);
                    check_scaled((double)sph_kernel_f(K(k), dim, r, (sph_real)h),
                                 (double)sph_kernel_f(K(k), dim, q1, 1) / pow((double)(sph_real)h, dim + 2), "F", h, dim, qq);
                    check_scaled((double)sph_kernel_dwdr(K(k), dim, r, (sph_real)h),
                                 (double)sph_kernel_dwdr(K(k), dim, q1, 1) / pow((double)(sph_real)h, dim + 1), "dW/dr",
                                 h, dim, qq);
                }
            }
            th_end();
        }
}

/* Density and gradients of a cloud scaled by s (positions and h times s,
 * volumes times s^d, masses and fields unchanged): rho / s^d and grad / s. */
static void test_h_range_operators(void)
{
    const double sc[2] = {TH_IS_FLOAT ? 1e-5 : 1e-20, TH_IS_FLOAT ? 1e5 : 1e20};
    int dim, is, i, a;
    for (dim = 1; dim <= 3; ++dim) {
        ts_scene t;
        xs_scene s0;
        xo_res R0;
        const int n1 = dim == 1 ? 30 : dim == 2 ? 9 : 5;
        ts_lattice(&t, SPH_KERNEL_CUBIC, dim, n1, 0.1, 1.3, 0.25, 11, NULL);
        xs_make(&s0, SPH_KERNEL_CUBIC, dim, t.n, t.x, t.h, pow(0.1, dim));
        xo_alloc(&R0, t.n, 0);
        xo_run(&s0.c, &s0.in, &R0);
        for (is = 0; is < 2; ++is) {
            const double s = sc[is];
            sph_real *x = ts_vec(3 * t.n);
            xs_scene s1;
            xo_res R1;
            th_begin("scaled cloud %dD by %g: rho/s^d, every gradient scheme /s, Laplacian /s^2", dim, s);
            for (i = 0; i < 3 * t.n; ++i) x[i] = (sph_real)(s * (double)t.x[i]);
            xs_make(&s1, SPH_KERNEL_CUBIC, dim, t.n, x, t.h * s, pow(0.1 * s, dim));
            s1.c.m = s0.c.m; /* the same masses and field values */
            memcpy(s1.f, s0.f, sizeof(sph_real) * (size_t)t.n);
            memcpy(s1.v, s0.v, sizeof(sph_real) * 3 * (size_t)t.n);
            TH_CHECK(s1.L.list.offset[t.n] == s0.L.list.offset[t.n], "lists differ: %ld vs %ld",
                     (long)s1.L.list.offset[t.n], (long)s0.L.list.offset[t.n]);
            xo_alloc(&R1, t.n, 0);
            xo_run(&s1.c, &s1.in, &R1);
            check_all_finite(&R1, dim, "scaled");
            /* rounding: positions and h each carry eps/2; q moves by ~2 eps and
             * each term by |d ln W/d ln q| 2 eps; terms of one sign (density;
             * the difference gradient of a linear field): 1e3 eps is generous */
            for (i = 0; i < t.n; ++i) {
                TH_REL((double)R1.o[XO_DENSITY][i] * pow(s, dim), R0.o[XO_DENSITY][i], 1e3 * TH_EPS);
                for (a = 0; a < dim; ++a) {
                    TH_NEAR((double)R1.o[XO_GRAD_DIFF][3 * i + a] * s, R0.o[XO_GRAD_DIFF][3 * i + a], 1e3 * TH_EPS);
                    TH_NEAR((double)R1.o[XO_GRAD_CORR][3 * i + a] * s, R0.o[XO_GRAD_CORR][3 * i + a], 1e3 * TH_EPS);
                }
                TH_NEAR((double)R1.o[XO_DIV_CORR][i] * s, R0.o[XO_DIV_CORR][i], 1e3 * TH_EPS);
            }
            xo_free(&R1);
            xs_free(&s1);
            free(x);
            th_end();
        }
        xo_free(&R0);
        xs_free(&s0);
        ts_free(&t);
    }
}

/* Every operator on scene s refuses with status st and leaves its output (2
 * targets, pre-filled with SENT) untouched; what/v name the bad input. */
static void check_refused(xs_scene *s, int st, const char *what, double v)
{
    xo_res R;
    int op, i;
    xo_alloc(&R, 2, SENT);
    xo_run(&s->c, &s->in, &R);
    for (op = 0; op < XO_N; ++op) {
        TH_CHECK(R.status[op] == st, "%s %g: %s status %d", what, v, xo_names[op], R.status[op]);
        for (i = 0; i < 18; ++i) TH_CHECK(R.o[op][i] == SENT, "%s: output written on error", xo_names[op]);
    }
    xo_free(&R);
}

/* Where h^-(d+2) or x_ij^2 would overflow, the operators refuse (SPH_EH,
 * SPH_EVALUE) instead of computing Inf - Inf; just inside the limits they
 * give finite results. */
static void test_range_limits(void)
{
    const double h_bad = TH_IS_FLOAT ? 1e-8 : 1e-70, h_ok = TH_IS_FLOAT ? 1e-7 : 1e-60;
    const double x_bad = TH_IS_FLOAT ? 1e19 : 1e154, x_ok = TH_IS_FLOAT ? 1e18 : 1e153;
    sph_real x[6] = {0, 0, 0, 0, 0, 0};
    xs_scene s;
    xo_res R;
    th_begin("range limits: h with 64 h^-5 overflowing is SPH_EH, |x| > sqrt(REAL_MAX)/4 SPH_EVALUE (3D)");
    x[3] = (sph_real)(0.5 * h_ok);
    xs_make(&s, SPH_KERNEL_CUBIC, 3, 2, x, h_ok, pow(h_ok, 3));
    xo_alloc(&R, 2, SENT);
    xo_run(&s.c, &s.in, &R);
    check_all_finite(&R, 3, "h just usable");
    xo_free(&R);
    s.c.h = (sph_real)h_bad;
    check_refused(&s, SPH_EH, "h", h_bad);
    xs_free(&s);
    /* two particles far apart (both in the list): the pair adds 0, nothing overflows */
    x[0] = (sph_real)-x_ok, x[3] = (sph_real)x_ok;
    xs_make(&s, SPH_KERNEL_CUBIC, 3, 2, x, 1, 1);
    {
        s.c.list = &xs_pair_list;
        xo_alloc(&R, 2, 0);
        xo_run(&s.c, &s.in, &R);
        check_all_finite(&R, 3, "x far apart");
        /* the self term alone, alpha_3 w(0) = 1/pi for the cubic, within one rounding of sph_real (the
           scalar W(0) and the AVX-512 float loop, which sums in double and rounds once, may differ by an ulp) */
        TH_CLOSE(R.o[XO_DENSITY][0], 1 / 3.14159265358979323846, TH_EPS / 3.14159265358979323846);
        xo_free(&R);
        s.x[3] = (sph_real)x_bad;
        check_refused(&s, SPH_EVALUE, "x", x_bad);
    }
    xs_free(&s);
    th_end();
}

/* ======================================================================== */
/* 4. coordinates far from the origin                                        */
/* ======================================================================== */
/* A lattice of spacing dx around X (double: X = 1e8, dx = 1e-3; float:
 * X = 10, dx = 1e-3). The stored positions are the lattice points rounded to
 * the spacing u = ulp(X) of sph_real there; differences of nearby stored
 * positions are exact (Sterbenz), so the operators see a lattice perturbed by
 * at most u/2 per coordinate: r_ij moves by at most sqrt(d) u, and
 *   |rho_X - rho_0| <= sqrt(d) u sum_j m |dW/dr(r_ij)|  (+ rounding of sums):
 * relative error ~ eps X / dx (double 2e-16 * 1e11 ~ 1e-5). A field linear in
 * the stored positions, measured from a local origin, keeps its corrected
 * gradient exact: what survives is set by the positions, not the operators. */
static void test_far_from_origin(void)
{
    const double X = TH_IS_FLOAT ? 10 : 1e8, dx = 1e-3;
    int dim, i, j, a;
    for (dim = 2; dim <= 3; ++dim) {
        ts_scene t;
        xs_scene s0, s1;
        xo_res R0, R1;
        sph_real *x;
        double u = ulp_of(2 * X), worst = 0, worst_bound = 0, worst_g = 0;
        const int n1 = dim == 2 ? 10 : 6;
        th_begin("far from the origin %dD: X = %g, dx = %g: density within the rounding bound, "
                 "corrected gradient exact", dim, X, dx);
        ts_lattice(&t, SPH_KERNEL_QUINTIC, dim, n1, dx, 1.3, 0, 1, NULL);
        x = ts_vec(3 * t.n);
        for (i = 0; i < t.n; ++i)
            for (a = 0; a < dim; ++a) x[3 * i + a] = (sph_real)(X + (double)t.x[3 * i + a]);
        xs_make(&s0, SPH_KERNEL_QUINTIC, dim, t.n, t.x, t.h, pow(dx, dim));
        xs_make(&s1, SPH_KERNEL_QUINTIC, dim, t.n, x, t.h, pow(dx, dim));
        for (i = 0; i < t.n; ++i) { /* the field from a local origin X (x - X exact) */
            sph_real loc[3] = {0, 0, 0};
            for (a = 0; a < dim; ++a) loc[a] = x[3 * i + a] - (sph_real)X;
            s1.f[i] = (sph_real)ts_linear(loc);
        }
        xo_alloc(&R0, t.n, 0), xo_alloc(&R1, t.n, 0);
        xo_run(&s0.c, &s0.in, &R0);
        xo_run(&s1.c, &s1.in, &R1);
        check_all_finite(&R1, dim, "far");
        for (i = 0; i < t.n; ++i) {
            double S = 0, err, bound;
            for (j = 0; j < t.n; ++j) {
                const double r = sqrt((double)tp_r2(dim, t.x + 3 * i, t.x + 3 * j, NULL));
                S += (double)s0.V[j] * fabs((double)sph_kernel_dwdr(SPH_KERNEL_QUINTIC, dim, (sph_real)r, (sph_real)t.h));
            }
            err = fabs((double)R1.o[XO_DENSITY][i] - (double)R0.o[XO_DENSITY][i]);
            bound = sqrt((double)dim) * u * S * 1.01 + 64 * TH_EPS * (double)R0.o[XO_DENSITY][i];
            TH_CHECK(err <= bound, "particle %d: |rho_X - rho_0| = %g > bound %g", i, err, bound);
            if (err / R0.o[XO_DENSITY][i] > worst) worst = err / R0.o[XO_DENSITY][i];
            if (bound / R0.o[XO_DENSITY][i] > worst_bound) worst_bound = bound / R0.o[XO_DENSITY][i];
            for (a = 0; a < dim; ++a) {
                TH_NEAR(R1.o[XO_GRAD_CORR][3 * i + a], ts_ga(a), 1e3 * TH_EPS);
                if (fabs(R1.o[XO_GRAD_CORR][3 * i + a] - ts_ga(a)) > worst_g)
                    worst_g = fabs(R1.o[XO_GRAD_CORR][3 * i + a] - ts_ga(a));
            }
        }
        printf("    far %dD [%s]: ulp(X) %.3g, dx %.3g: max relative density change %.3g (bound %.3g); "
               "corrected gradient max error %.3g\n", dim, TH_PRECISION, u, dx, worst, worst_bound, worst_g);
        xo_free(&R0), xo_free(&R1);
        xs_free(&s0), xs_free(&s1);
        ts_free(&t);
        free(x);
        th_end();
    }
}

/* ======================================================================== */
/* 5. one particle, two particles, empty lists, a target with no sources     */
/* ======================================================================== */
static void test_tiny_clouds(void)
{
    int k, dim, i, a;
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim) {
            const double h = 0.4, V = 0.05;
            sph_real x[6] = {(sph_real)0.1, (sph_real)0.2, (sph_real)0.3, 0, 0, 0};
            xs_scene s;
            xo_res R;
            th_begin("single particle %s %dD: rho = m W(0), derivatives 0, corrected falls back (1), B = I",
                     sph_kernel_name(K(k)), dim);
            xs_make(&s, K(k), dim, 1, x, h, V);
            xo_alloc(&R, 1, 0);
            xo_run(&s.c, &s.in, &R);
            check_all_finite(&R, dim, "single");
            TH_REL(R.o[XO_DENSITY][0], V * (double)sph_kernel_alpha(K(k), dim) * w0_of(k) / pow(h, dim), 8 * TH_EPS);
            TH_REL(R.o[XO_SHEPARD][0], s.f[0], 4 * TH_EPS);
            for (a = 0; a < 9; ++a)
                TH_CHECK(R.o[XO_GRAD_CORR][a] == 0 && R.o[XO_LAP][a] == 0 && R.o[XO_DIV_CORR][a] == 0,
                         "derivative of one particle != 0");
            TH_CHECK(R.count[XO_GRAD_CORR] == 1 && R.count[XO_CORRECTION] == 1 && R.count[XO_SHEPARD] == 0,
                     "counts %d %d %d", (int)R.count[XO_GRAD_CORR], (int)R.count[XO_CORRECTION], (int)R.count[XO_SHEPARD]);
            xo_free(&R);
            xs_free(&s);
            th_end();

            /* two particles at distance r = 0.3 h kappa along a direction */
            th_begin("two particles %s %dD: each operator equals its two-term sum; 1-D corrected = slope",
                     sph_kernel_name(K(k)), dim);
            {
                const double r = 0.3 * h * kap(k), dir[3] = {0.6, 0.8, 0};
                const double dir3[3] = {0.48, 0.64, 0.6};
                double d[3] = {0, 0, 0}, W0, Wr, Fr;
                for (a = 0; a < dim; ++a) {
                    d[a] = r * (dim == 1 ? 1 : dim == 2 ? dir[a] : dir3[a]);
                    x[3 + a] = (sph_real)((double)x[a] + d[a]);
                }
                xs_make(&s, K(k), dim, 2, x, h, V);
                xo_alloc(&R, 2, 0);
                xo_run(&s.c, &s.in, &R);
                check_all_finite(&R, dim, "two");
                W0 = (double)sph_kernel_w(K(k), dim, 0, (sph_real)h);
                Wr = (double)sph_kernel_w(K(k), dim, (sph_real)r, (sph_real)h);
                Fr = (double)sph_kernel_f(K(k), dim, (sph_real)r, (sph_real)h);
                for (i = 0; i < 2; ++i) {
                    const double fi = s.f[i], fj = s.f[1 - i], sg = i == 0 ? -1 : 1; /* x_ij = sg d */
                    TH_REL(R.o[XO_DENSITY][i], V * (W0 + Wr), 64 * TH_EPS);
                    TH_REL(R.o[XO_LAP][i], 2 * V * (fi - fj) * Fr, 1e3 * TH_EPS);
                    for (a = 0; a < dim; ++a) {
                        TH_NEAR(R.o[XO_GRAD_STD][3 * i + a], V * fj * Fr * sg * d[a], 1e3 * TH_EPS * fabs(V * Fr * r));
                        TH_NEAR(R.o[XO_GRAD_DIFF][3 * i + a], V * (fj - fi) * Fr * sg * d[a], 1e3 * TH_EPS);
                        TH_NEAR(R.o[XO_GRAD_SYM][3 * i + a], V * (fj + fi) * Fr * sg * d[a], 1e3 * TH_EPS * fabs(V * Fr * r));
                    }
                    if (dim == 1) /* M = -V F dx^2 is invertible: B (f_j - f_i) ... = the slope */
                        TH_NEAR(R.o[XO_GRAD_CORR][3 * i], (fj - fi) / (double)(s.x[3 * (1 - i)] - s.x[3 * i]),
                                1e3 * TH_EPS);
                }
                TH_CHECK(R.count[XO_GRAD_CORR] == (dim == 1 ? 0 : 2), "two particles %dD: %d fallbacks", dim,
                         (int)R.count[XO_GRAD_CORR]);
                xo_free(&R);
                xs_free(&s);
            }
            th_end();
        }

    /* empty list: n_targets = 4, every offset 0, index NULL */
    for (dim = 1; dim <= 3; ++dim) {
        sph_real x[12] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0};
        sph_off off[5] = {0, 0, 0, 0, 0};
        sph_neighbours L = SPH_NEIGHBOURS_INIT(4, 4, off, NULL);
        xs_scene s;
        xo_res R;
        th_begin("empty neighbour lists %dD: sums are 0, Shepard 0 counted (4), corrected falls back (4)", dim);
        xs_make(&s, SPH_KERNEL_WENDLAND_C2, dim, 4, x, 0.3, 1);
        s.c.list = &L;
        xo_alloc(&R, 4, SENT);
        xo_run(&s.c, &s.in, &R);
        for (i = 0; i < 4; ++i) {
            TH_CHECK(R.o[XO_DENSITY][i] == 0 && R.o[XO_SHEPARD][i] == 0 && R.o[XO_LAP][i] == 0 &&
                         R.o[XO_GRAD_CORR][3 * i] == 0 && R.o[XO_CORRECTION][9 * i] == 1,
                     "target %d: density %g shepard %g", i, (double)R.o[XO_DENSITY][i], (double)R.o[XO_SHEPARD][i]);
        }
        for (i = 0; i < XO_N; ++i)
            TH_CHECK(R.status[i] == (xo_defined(i, dim) ? SPH_OK : SPH_EDIM), "%s status %d", xo_names[i], R.status[i]);
        TH_CHECK(R.count[XO_SHEPARD] == 4 && R.count[XO_GRAD_CORR] == 4 && R.count[XO_CORRECTION] == 4,
                 "counts %d %d %d", (int)R.count[XO_SHEPARD], (int)R.count[XO_GRAD_CORR], (int)R.count[XO_CORRECTION]);
        xo_free(&R);
        /* no particles at all */
        L.n_targets = L.n_sources = 0;
        xo_alloc(&R, 0, SENT);
        xo_run(&s.c, &s.in, &R);
        for (i = 0; i < XO_N; ++i) {
            TH_CHECK(R.status[i] == (xo_defined(i, dim) ? SPH_OK : SPH_EDIM), "empty cloud: %s status %d",
                     xo_names[i], R.status[i]);
            TH_CHECK(R.o[i][0] == SENT, "empty cloud: %s wrote", xo_names[i]);
        }
        xo_free(&R);
        xs_free(&s);
        th_end();
    }

    /* probe targets, one of them far from every source */
    th_begin("probe target with no sources (2D): 0 with a Shepard count of 1, the others exact");
    {
        ts_scene t;
        sph_real xt[6] = {(sph_real)0.45, (sph_real)0.42, 0, 50, 50, 0}, ht[2], ft[2], gt[6], sh[2];
        sph_idx nempty = -1, nfb = -1;
        tp_list L;
        sph_ctx c;
        sph_real *f;
        int st;
        ts_lattice(&t, SPH_KERNEL_CUBIC, 2, 9, 0.1, 1.3, 0.1, 5, NULL);
        f = ts_vec(t.n);
        for (i = 0; i < t.n; ++i) f[i] = (sph_real)ts_linear(t.x + 3 * i);
        tp_brute_list(2, xt, 2, t.x, t.n, (sph_real)t.h, NULL, NULL, 2, TP_GATHER, NULL, &L);
        TH_CHECK(L.list.offset[2] == L.list.offset[1] && L.list.offset[1] > 0, "probe lists %ld %ld",
                 (long)L.list.offset[1], (long)L.list.offset[2]);
        c = t.c;
        c.list = &L.list;
        c.x_target = sph_view_interleaved(xt, 3);
        for (i = 0; i < 2; ++i) ht[i] = (sph_real)t.h, ft[i] = (sph_real)ts_linear(xt + 3 * i);
        c.h_target = sph_view_soa(ht, NULL, NULL);
        st = sph_interpolate_shepard(&c, sph_view_soa(f, NULL, NULL), sph_out_soa(sh, NULL, NULL), &nempty);
        st |= sph_gradient(&c, SPH_SCHEME_CORRECTED, sph_view_soa(f, NULL, NULL), sph_view_soa(ft, NULL, NULL),
                           sph_out_interleaved(gt, 3), &nfb);
        TH_CHECK(st == SPH_OK && nempty == 1 && nfb == 1, "status %d, empty %d, fallbacks %d", st, (int)nempty, (int)nfb);
        TH_CHECK(sh[1] == 0 && gt[3] == 0 && gt[4] == 0, "lonely probe: %g %g %g", (double)sh[1], (double)gt[3], (double)gt[4]);
        TH_NEAR(gt[0], ts_ga(0), 1e3 * TH_EPS);
        TH_NEAR(gt[1], ts_ga(1), 1e3 * TH_EPS);
        free(f);
        tp_free_list(&L);
        ts_free(&t);
    }
    th_end();
}

/* ======================================================================== */
/* 6. degenerate neighbourhoods: the correction matrix falls back, counted   */
/* ======================================================================== */
/* Runs everything on the cloud; every corrected operator reports want
 * fallbacks, and where all targets fell back the corrected gradient is the
 * difference gradient bitwise. */
static void degenerate(sph_kernel k, int dim, int n, const sph_real *x, double h, int want, const char *what)
{
    xs_scene s;
    xo_res R;
    int i, a;
    xs_make(&s, k, dim, n, x, h, pow(h / 1.3, dim));
    xo_alloc(&R, n, 0);
    xo_run(&s.c, &s.in, &R);
    check_all_finite(&R, dim, what);
    TH_CHECK(R.count[XO_GRAD_CORR] == want && R.count[XO_GV_CORR] == want && R.count[XO_DIV_CORR] == want &&
                 R.count[XO_CORRECTION] == want,
             "%s %s: fallbacks %d %d %d %d, expected %d", what, sph_kernel_name(k), (int)R.count[XO_GRAD_CORR],
             (int)R.count[XO_GV_CORR], (int)R.count[XO_DIV_CORR], (int)R.count[XO_CORRECTION], want);
    if (want == n)
        for (i = 0; i < n; ++i)
            for (a = 0; a < dim; ++a)
                TH_CHECK(R.o[XO_GRAD_CORR][3 * i + a] == R.o[XO_GRAD_DIFF][3 * i + a], "%s: not the difference scheme", what);
    if (want == 0)
        for (i = 0; i < n; ++i)
            for (a = 0; a < dim; ++a) TH_NEAR(R.o[XO_GRAD_CORR][3 * i + a], ts_ga(a), 1e4 * TH_EPS);
    xo_free(&R);
    xs_free(&s);
}

static void test_degenerate(void)
{
    sph_real x[3 * 125];
    int k, i, j, l;
    for (k = 0; k < SPH_KERNEL_COUNT; ++k) {
        const double h = 0.1 * 1.3 * 2 / kap(k); /* support radius 0.26: about 2.6 spacings */
        th_begin("correction fallbacks, %s: collinear 2D/3D, coplanar 3D, 3 points in 3D, 1-D isolated: "
                 "all fall back; lattice corners: none", sph_kernel_name(K(k)));
        for (i = 0; i < 12; ++i) /* a tilted line */
            x[3 * i] = (sph_real)(0.08 * i), x[3 * i + 1] = (sph_real)(0.06 * i), x[3 * i + 2] = (sph_real)(-0.02 * i);
        degenerate(K(k), 2, 12, x, h, 12, "collinear 2D");
        degenerate(K(k), 3, 12, x, h, 12, "collinear 3D");
        for (i = 0; i < 5; ++i) /* a tilted plane z = 0.3 x - 0.2 y */
            for (j = 0; j < 5; ++j) {
                l = 5 * i + j;
                x[3 * l] = (sph_real)(0.1 * i), x[3 * l + 1] = (sph_real)(0.1 * j);
                x[3 * l + 2] = (sph_real)(0.03 * i - 0.02 * j);
            }
        degenerate(K(k), 3, 25, x, h, 25, "coplanar 3D");
        x[0] = 0, x[1] = 0, x[2] = 0, x[3] = (sph_real)0.1, x[4] = 0, x[5] = 0;
        x[6] = 0, x[7] = (sph_real)0.1, x[8] = (sph_real)0.05; /* fewer neighbours than dimensions */
        degenerate(K(k), 3, 3, x, h, 3, "three points 3D");
        degenerate(K(k), 2, 2, x, h, 2, "two points 2D");
        x[0] = 0, x[3] = 1; /* out of reach */
        degenerate(K(k), 1, 2, x, h, 2, "isolated 1D");
        /* a square and a cube block: corners, edges and faces are free
         * surfaces but span the space: no fallback, exact */
        for (i = 0; i < 5; ++i)
            for (j = 0; j < 5; ++j)
                for (l = 0; l < 5; ++l) {
                    const int m = 25 * i + 5 * j + l;
                    x[3 * m] = (sph_real)(0.1 * l), x[3 * m + 1] = (sph_real)(0.1 * j), x[3 * m + 2] = (sph_real)(0.1 * i);
                }
        degenerate(K(k), 2, 25, x, h, 0, "square block 2D");
        degenerate(K(k), 3, 125, x, h, 0, "cube block 3D");
        th_end();
    }
}

/* ======================================================================== */
/* 7. 1:1000 density and conductivity jump: the two-layer slab               */
/* ======================================================================== */
/* 1-D slab on [0, 1], interface at x = 1/2: layer 1 (x < 1/2) rho = 1000,
 * k = 1; layer 2 rho = 1, k = 1000 (masses m = rho dx, so V = dx). Fixed
 * T = 0 at x <= 0 and T = 1 at x >= 1 (three rows of fixed particles beyond
 * each end). Steady state: the flux q = 1 / (1/2 / k1 + 1/2 / k2) is the
 * same in both layers, T = q x / k1 in layer 1 and T_I + q (x - 1/2) / k2 in
 * layer 2, T_I = q / (2 k1) (piecewise linear, continuous flux). The
 * discrete steady state of sph_diffusion is solved by Jacobi-preconditioned
 * conjugate gradients on the unknowns (the operator is symmetric here: equal
 * V, symmetric k_ij, F_ij). Harmonic k_ij (the library) against the
 * arithmetic mean (k_i + k_j), fed through the same operator by the trick
 * k_ij = sph_harmonic_k(k', k') = 2 k' for a pair-constant k': not
 * available per pair, so the arithmetic run uses its own pair loop. */
#define SLAB_N 200 /* largest number of free particles */
#define SLAB_G 3
typedef struct {
    int n;              /* particles including fixed ones */
    sph_real x[3 * (SLAB_N + 2 * SLAB_G)], V[SLAB_N + 2 * SLAB_G], k[SLAB_N + 2 * SLAB_G];
    sph_real m[SLAB_N + 2 * SLAB_G], rho[SLAB_N + 2 * SLAB_G];
    int fixed[SLAB_N + 2 * SLAB_G];
    tp_list L;
    sph_ctx c;
    int arith;
} slab;

/* out = -div(k grad T) on the unknowns, 0 on fixed particles. */
static void slab_apply(slab *s, const sph_real *T, sph_real *out)
{
    int i;
    if (!s->arith) {
        sph_diffusion(&s->c, sph_view_soa(s->k, NULL, NULL), sph_view_none(), sph_view_soa(T, NULL, NULL),
                      sph_view_none(), sph_out_soa(out, NULL, NULL));
    } else {
        for (i = 0; i < s->n; ++i) { /* the same (O14) sum with k_ij = k_i + k_j */
            sph_off o;
            double acc = 0;
            for (o = s->L.list.offset[i]; o < s->L.list.offset[i + 1]; ++o) {
                const int j = s->L.list.index[o];
                const sph_real dx = s->x[3 * i] - s->x[3 * j];
                const sph_pair p = sph_pair_kernel(s->c.kernel, 1, &dx, s->c.h);
                acc += (double)sph_pair_diffusion(s->V[j], s->k[i] + s->k[j], T[i], T[j], p.F);
            }
            out[i] = (sph_real)acc;
        }
    }
    for (i = 0; i < s->n; ++i) out[i] = s->fixed[i] ? 0 : -out[i];
}

/* Solves the steady state; returns the max deviation from the analytic profile. */
static double slab_solve(slab *s, int *iters)
{
    static sph_real T[SLAB_N + 2 * SLAB_G], r[SLAB_N + 2 * SLAB_G], p[SLAB_N + 2 * SLAB_G], Ap[SLAB_N + 2 * SLAB_G];
    static sph_real z[SLAB_N + 2 * SLAB_G], D[SLAB_N + 2 * SLAB_G], e[SLAB_N + 2 * SLAB_G];
    const double q = 1 / (0.5 / 1 + 0.5 / 1000), TI = q * 0.5;
    double rz, rz0, err = 0;
    int i, it;
    for (i = 0; i < s->n; ++i) {
        const double xi = s->x[3 * i];
        T[i] = !s->fixed[i] ? 0 : (sph_real)(xi < 0.5 ? q * xi : 1 + q * (xi - 1) / 1000);
    }
    /* the diagonal: the operator on unit vectors would cost n calls; instead
     * D_i = sum_j V k_ij (-F_ij) over j != i from the same operator with the
     * target field 1 and the source field 0 */
    for (i = 0; i < s->n; ++i) e[i] = 0, z[i] = 1;
    if (!s->arith) {
        sph_diffusion(&s->c, sph_view_soa(s->k, NULL, NULL), sph_view_none(), sph_view_soa(e, NULL, NULL),
                      sph_view_soa(z, NULL, NULL), sph_out_soa(D, NULL, NULL));
        for (i = 0; i < s->n; ++i) { /* remove the self term V k_ii F(0) (1 - 0) */
            D[i] -= s->V[i] * sph_harmonic_k(s->k[i], s->k[i]) * sph_kernel_f(s->c.kernel, 1, 0, s->c.h);
            D[i] = -D[i];
        }
    } else {
        for (i = 0; i < s->n; ++i) {
            sph_off o;
            double acc = 0;
            for (o = s->L.list.offset[i]; o < s->L.list.offset[i + 1]; ++o) {
                const int j = s->L.list.index[o];
                const sph_real dx = s->x[3 * i] - s->x[3 * j];
                if (j != i) acc -= (double)(s->V[j] * (s->k[i] + s->k[j]) * sph_pair_kernel(s->c.kernel, 1, &dx, s->c.h).F);
            }
            D[i] = (sph_real)acc;
        }
    }
    /* r = b - A T with T holding the boundary values: r = -A T */
    slab_apply(s, T, r);
    for (i = 0; i < s->n; ++i) r[i] = -r[i], z[i] = s->fixed[i] ? 0 : r[i] / D[i], p[i] = z[i];
    rz = 0;
    for (i = 0; i < s->n; ++i) rz += (double)r[i] * z[i];
    rz0 = rz;
    for (it = 0; it < 20 * s->n && rz > rz0 * (TH_IS_FLOAT ? 1e-12 : 1e-28); ++it) {
        double pAp = 0, alpha, rz1 = 0;
        slab_apply(s, p, Ap);
        for (i = 0; i < s->n; ++i) pAp += (double)p[i] * Ap[i];
        alpha = rz / pAp;
        for (i = 0; i < s->n; ++i) T[i] += (sph_real)(alpha * p[i]), r[i] -= (sph_real)(alpha * Ap[i]);
        for (i = 0; i < s->n; ++i) z[i] = s->fixed[i] ? 0 : r[i] / D[i], rz1 += (double)r[i] * z[i];
        for (i = 0; i < s->n; ++i) p[i] = z[i] + (sph_real)(rz1 / rz) * p[i];
        rz = rz1;
    }
    *iters = it;
    for (i = 0; i < s->n; ++i) {
        const double xi = s->x[3 * i], Te = xi < 0.5 ? q * xi : TI + q * (xi - 0.5) / 1000;
        if (!s->fixed[i] && fabs(T[i] - Te) > err) err = fabs(T[i] - Te);
    }
    return err;
}

/* The slab with nfree free particles (dx = 1/nfree); returns the max error. */
static double slab_run(slab *s, int nfree, int arith, int *its)
{
    const double dx = 1.0 / nfree;
    double err;
    int i;
    s->n = nfree + 2 * SLAB_G;
    for (i = 0; i < s->n; ++i) {
        const double xi = (i - SLAB_G + 0.5) * dx;
        s->x[3 * i] = (sph_real)xi, s->x[3 * i + 1] = s->x[3 * i + 2] = 0;
        s->rho[i] = xi < 0.5 ? 1000 : 1;
        s->m[i] = (sph_real)(s->rho[i] * dx);
        s->V[i] = s->m[i] / s->rho[i];
        s->k[i] = xi < 0.5 ? 1 : 1000;
        s->fixed[i] = xi < 0 || xi > 1;
    }
    /* fixed particles carry the exact profile continued beyond the ends
     * (Dirichlet data by extrapolation), so the only error left is the
     * interface treatment */
    tp_brute_list(1, s->x, s->n, s->x, s->n, (sph_real)(1.3 * dx), NULL, NULL, 2, TP_GATHER, NULL, &s->L);
    s->c = sph_ctx_init(SPH_KERNEL_CUBIC, 1, (sph_real)(1.3 * dx), &s->L.list, sph_view_interleaved(s->x, 3));
    s->c.V = sph_view_soa(s->V, NULL, NULL);
    s->c.m = sph_view_soa(s->m, NULL, NULL);
    s->arith = arith;
    err = slab_solve(s, its);
    return err;
}

static void test_two_layer_slab(void)
{
    static slab s;
    double eh[3], ea[3];
    int i, l, it_h, it_a;
    th_begin("1:1000 density and conductivity jump: harmonic-mean diffusion keeps the flux continuous "
             "(two-layer slab, steady profile)");
    for (l = 0; l < 3; ++l) {
        const int nfree = 50 << l;
        ea[l] = slab_run(&s, nfree, 1, &it_a);
        tp_free_list(&s.L);
        eh[l] = slab_run(&s, nfree, 0, &it_h);
        printf("    slab [%s]: dx 1/%d, h 1.3 dx, k and rho 1:1000: max |T - T_exact| harmonic %.3g (%d CG its), "
               "arithmetic %.3g (%d its)\n", TH_PRECISION, nfree, eh[l], it_h, ea[l], it_a);
        if (l == 1) { /* the density operator across the jump: exact away from it, never NaN */
            sph_real rho[SLAB_N + 2 * SLAB_G];
            TH_CHECK(sph_density(&s.c, sph_out_soa(rho, NULL, NULL)) == SPH_OK, "density");
            for (i = SLAB_G + 3; i < s.n - SLAB_G - 3; ++i) {
                /* 1-D cubic lattice sum at h = 1.3 dx: within 1 % (measured 0.35 %) */
                TH_CHECK(rho[i] >= (sph_real)0.99 && rho[i] <= (sph_real)1010, "rho %g at %d", (double)rho[i], i);
                if (fabs((double)s.x[3 * i] - 0.5) > 3.0 / nfree) TH_REL(rho[i], s.rho[i], 0.01);
            }
        }
        tp_free_list(&s.L);
        /* a priori: the interface lies dx/2 from its nearest particles; an
         * error in its effective position of a quarter spacing moves T by
         * q dx / 4 (q = 1/0.5005, the flux): the harmonic mean must stay
         * below that, the arithmetic mean (interface pairs conducting ~250
         * times too well) must be at least 5 times worse */
        TH_CHECK(eh[l] <= 0.25 / 0.5005 / nfree + 1e4 * TH_EPS, "harmonic mean dx 1/%d: max error %g", nfree, eh[l]);
        TH_CHECK(ea[l] >= 5 * eh[l], "arithmetic mean not worse at dx 1/%d: %g vs %g", nfree, ea[l], eh[l]);
    }
    /* and it converges at first order (the interface is a kink of T) */
    TH_CHECK(eh[1] <= 0.6 * eh[0] && eh[2] <= 0.6 * eh[1], "harmonic error does not converge: %g %g %g", eh[0],
                 eh[1], eh[2]);
    th_end();
}

/* ======================================================================== */
/* 8. h/dx from 0.5 to 5                                                     */
/* ======================================================================== */
/* Does the neighbourhood (offsets x_j - x_i, j != i, inside the support)
 * span dim dimensions? Independent of M: rank from cross products. */
static int spans(int dim, const sph_real *x, const tp_list *L, int i)
{
    sph_off o, p, r;
    for (o = L->offset[i]; o < L->offset[i + 1]; ++o) {
        const sph_real *a = x + 3 * L->index[o], *xi = x + 3 * i;
        double u[3], v[3], w[3];
        int c;
        if (L->index[o] == i) continue;
        for (c = 0; c < 3; ++c) u[c] = a[c] - xi[c];
        if (dim == 1) return 1;
        for (p = L->offset[i]; p < L->offset[i + 1]; ++p) {
            double cr[3];
            if (L->index[p] == i) continue;
            for (c = 0; c < 3; ++c) v[c] = x[3 * L->index[p] + c] - xi[c];
            cr[0] = u[1] * v[2] - u[2] * v[1], cr[1] = u[2] * v[0] - u[0] * v[2], cr[2] = u[0] * v[1] - u[1] * v[0];
            if (dim == 2 && fabs(cr[2]) > 1e-9) return 1;
            if (dim == 3)
                for (r = L->offset[i]; r < L->offset[i + 1]; ++r) {
                    if (L->index[r] == i) continue;
                    for (c = 0; c < 3; ++c) w[c] = x[3 * L->index[r] + c] - xi[c];
                    if (fabs(cr[0] * w[0] + cr[1] * w[1] + cr[2] * w[2]) > 1e-12) return 1;
                }
        }
    }
    return 0;
}

static void test_hdx_range(void)
{
    const double hdx[6] = {0.5, 0.8, 1.3, 2, 3, 5};
    int dim, ih, i, a;
    for (dim = 2; dim <= 3; ++dim)
        for (ih = 0; ih < 6; ++ih) {
            ts_scene t;
            xs_scene s;
            xo_res R;
            int nospan = 0, bad = 0;
            double mean;
            if (dim == 3 && hdx[ih] > 3) continue; /* 3-D at h/dx 5: 4000 neighbours, too slow under sanitizers */
            ts_lattice(&t, SPH_KERNEL_CUBIC, dim, dim == 2 ? (hdx[ih] > 2 ? 26 : 12) : (hdx[ih] > 2 ? 10 : 7), 0.1,
                       hdx[ih], 0.2, 17, NULL);
            xs_make(&s, SPH_KERNEL_CUBIC, dim, t.n, t.x, t.h, pow(0.1, dim));
            mean = (double)s.L.list.offset[t.n] / t.n;
            th_begin("h/dx = %g %dD (cubic, lattice perturbed 20%%): finite; every corrected target exact or "
                     "the difference scheme", hdx[ih], dim);
            xo_alloc(&R, t.n, 0);
            xo_run(&s.c, &s.in, &R);
            check_all_finite(&R, dim, "h/dx");
            for (i = 0; i < t.n; ++i) {
                int exact = 1, same = 1;
                nospan += !spans(dim, t.x, &s.L, i);
                for (a = 0; a < dim; ++a) {
                    exact &= fabs(R.o[XO_GRAD_CORR][3 * i + a] - ts_ga(a)) <= 1e4 * TH_EPS;
                    same &= R.o[XO_GRAD_CORR][3 * i + a] == R.o[XO_GRAD_DIFF][3 * i + a];
                }
                bad += !exact && !same;
            }
            TH_CHECK(bad == 0, "%d targets neither exact nor the difference scheme", bad);
            TH_CHECK(R.count[XO_GRAD_CORR] >= nospan && R.count[XO_GRAD_CORR] <= t.n,
                     "fallbacks %d < %d non-spanning neighbourhoods", (int)R.count[XO_GRAD_CORR], nospan);
            if (hdx[ih] >= 1.3) TH_CHECK(R.count[XO_GRAD_CORR] == 0, "fallbacks %d at h/dx %g", (int)R.count[XO_GRAD_CORR], hdx[ih]);
            printf("    h/dx %.1f %dD [%s]: %d particles, %.1f neighbours each, %d non-spanning, %d corrected "
                   "fallbacks\n", hdx[ih], dim, TH_PRECISION, t.n, mean, nospan, (int)R.count[XO_GRAD_CORR]);
            xo_free(&R);
            xs_free(&s);
            ts_free(&t);
            th_end();
        }
}

/* ======================================================================== */
/* 9. NaN or Inf in an input field                                           */
/* ======================================================================== */
static void test_nonfinite(void)
{
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    int ib, which, op, i;
    ts_scene t;
    xs_scene s;
    th_begin("NaN/Inf in any input: every operator returns SPH_ENONFINITE (SPH_EH for h), writes nothing; "
             "sph_check_field names the particle");
    ts_lattice(&t, SPH_KERNEL_WENDLAND_C2, 2, 6, 0.1, 1.3, 0.2, 9, NULL);
    xs_make(&s, SPH_KERNEL_WENDLAND_C2, 2, t.n, t.x, t.h, 0.01);
    for (ib = 0; ib < 3; ++ib)
        for (which = 0; which < 7; ++which) {
            /* 0 x, 1 V (= m), 2 rho, 3 f, 4 v, 5 k, 6 per-particle h */
            sph_real hh[64], *arr, keep;
            const int at = 17;
            int comp = 0, want = SPH_ENONFINITE, ncomp = 1;
            sph_idx first = -9;
            sph_view view;
            xo_res R;
            for (i = 0; i < t.n; ++i) hh[i] = (sph_real)t.h;
            arr = which == 0 ? s.x : which == 1 ? s.V : which == 2 ? s.rho : which == 3 ? s.f : which == 4 ? s.v
                  : which == 5 ? s.kc : hh;
            if (which == 0 || which == 4) comp = 1, ncomp = 3;
            if (which == 6) s.c.h_source = sph_view_soa(hh, NULL, NULL), want = SPH_EH;
            keep = arr[ncomp * at + comp];
            arr[ncomp * at + comp] = (sph_real)bad[ib];
            view = ncomp == 3 ? sph_view_interleaved(arr, 3) : sph_view_soa(arr, NULL, NULL);
            TH_CHECK(sph_check_field(view, ncomp == 3 ? 2 : 1, t.n, &first) == SPH_ENONFINITE && first == at,
                     "sph_check_field: first bad %d, expected %d", (int)first, at);
            xo_alloc(&R, t.n, SENT);
            xo_run(&s.c, &s.in, &R);
            for (op = 0; op < XO_N; ++op) {
                /* an operator that does not read the array is unaffected */
                const int reads = which == 0 || which == 6 ||
                    (which == 1 && op != XO_GRAD_PRES) ||
                    (which == 2 && op == XO_GRAD_PRES) ||
                    (which == 3 && (op <= XO_GRAD_PRES || op == XO_LAP || op == XO_DIFFUSION) && op != XO_DENSITY) ||
                    (which == 4 && op >= XO_GV_STD && op <= XO_CURL_DIFF) ||
                    (which == 5 && op == XO_DIFFUSION);
                const int m_read = which == 1 && (op == XO_DENSITY || op == XO_GRAD_PRES); /* m = V here */
                if (!reads && !m_read) {
                    TH_CHECK(R.status[op] == SPH_OK, "input %d: %s status %d", which, xo_names[op], R.status[op]);
                    continue;
                }
                TH_CHECK(R.status[op] == want, "input %d value %g: %s status %d, expected %d", which, bad[ib],
                         xo_names[op], R.status[op], want);
                for (i = 0; i < 9 * t.n; ++i)
                    if (R.o[op][i] != SENT) {
                        TH_CHECK(0, "input %d: %s wrote on error", which, xo_names[op]);
                        break;
                    }
            }
            xo_free(&R);
            arr[ncomp * at + comp] = keep;
            s.c.h_source = sph_view_none();
        }
    /* the validator's own status codes */
    {
        sph_idx first = -9;
        TH_CHECK(sph_check_field(sph_view_soa(s.f, NULL, NULL), 1, t.n, &first) == SPH_OK && first == -1, "clean field");
        TH_CHECK(sph_check_field(sph_view_soa(s.f, NULL, NULL), 2, t.n, &first) == SPH_ENULL, "missing component");
        TH_CHECK(sph_check_field(sph_view_soa(s.f, NULL, NULL), 0, t.n, &first) == SPH_ERANGE, "ncomp 0");
        TH_CHECK(sph_check_field(sph_view_soa(s.f, NULL, NULL), 1, -1, &first) == SPH_ECOUNT, "n < 0");
        TH_CHECK(sph_check_field(sph_view_soa(s.f, NULL, NULL), 1, 0, NULL) == SPH_OK, "n = 0, first NULL");
    }
    xs_free(&s);
    ts_free(&t);
    th_end();
}

int main(void)
{
    test_r0_kernels();
    test_r0_operators();
    test_r0_in_cloud();
    test_support_edge();
    test_h_range_kernels();
    test_h_range_operators();
    test_range_limits();
    test_far_from_origin();
    test_tiny_clouds();
    test_degenerate();
    test_two_layer_slab();
    test_hdx_range();
    test_nonfinite();
    return th_summary();
}
