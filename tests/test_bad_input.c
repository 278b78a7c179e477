/* tests/test_bad_input.c - every public function over bad arguments.
 *
 * Walks every public function of sph_kernel.h (`grep '^SPH_API'`, names
 * without `sph__`) over NaN, +Inf, -Inf, 0, -0, -1, a denormal and its
 * negative, 0.5, 2, a value whose square overflows and +-the largest
 * sph_real (integers over negative, zero, one past the range, INT_MIN and
 * INT_MAX), and asserts what the header documents for each: a status code
 * with the outputs untouched, or a finite result (zeros, 0, identity or the
 * unchanged argument where a fallback is documented). The documented
 * exceptions are the plain arithmetic pair terms of section 5, which pass
 * NaN and Inf through and overflow where their products do: for them the
 * test asserts that finite arguments with products in range give finite
 * results and that no fourth component is touched; and the operators, which
 * check that their inputs are finite but not that sums of products of
 * overflow-sized field values stay in range.
 *
 * Built with -fsanitize=address,undefined: an argument check that reads
 * past a caller's array (offset[] beyond the counts, periodic[] beyond
 * axis 2) stops the program there.
 */
#include <limits.h>

#include "op_scene.h"
#include "xo_ops.h"

#define REAL_MAX (TH_IS_FLOAT ? (double)FLT_MAX : DBL_MAX)
#define REAL_MIN (TH_IS_FLOAT ? (double)FLT_MIN : DBL_MIN)
#define SENT ((sph_real)-12345)

enum { V_NAN, V_PINF, V_NINF, V_ZERO, V_NZERO, V_M1, V_DEN, V_NDEN, V_HALF, V_TWO, V_BIG, V_MAX, V_NMAX, NV };
static const char *const vname[NV] = {"NaN", "+Inf", "-Inf", "0", "-0", "-1", "denormal", "-denormal",
                                      "0.5", "2", "big (its square overflows)", "+max", "-max"};
static sph_real val[NV];

static void vals_init(void)
{
    val[V_NAN] = (sph_real)NAN;
    val[V_PINF] = (sph_real)HUGE_VAL;
    val[V_NINF] = (sph_real)-HUGE_VAL;
    val[V_ZERO] = 0;
    val[V_NZERO] = (sph_real)-0.0;
    val[V_M1] = -1;
    val[V_DEN] = (sph_real)(REAL_MIN / 64);
    val[V_NDEN] = (sph_real)(-REAL_MIN / 64);
    val[V_HALF] = (sph_real)0.5;
    val[V_TWO] = 2;
    val[V_BIG] = (sph_real)(sqrt(REAL_MAX) * 4);
    val[V_MAX] = (sph_real)REAL_MAX;
    val[V_NMAX] = (sph_real)-REAL_MAX;
}

static int fin(sph_real x) { return isfinite((double)x); }
static int finite_arg(int v) { return v >= V_ZERO; }

static const int bad_int[5] = {INT_MIN, -1, 0, 4, INT_MAX};
static const int bad_kernel[4] = {-1, SPH_KERNEL_COUNT, 1000, INT_MAX};

/* ---- section 2 ---- */

static void test_strerror(void)
{
    static const int code[] = {
#define TB_CODE(name, value, sentence) name,
        SPH_STATUS_LIST(TB_CODE)
#undef TB_CODE
    };
    static const char *const text[] = {
#define TB_TEXT(name, value, sentence) sentence,
        SPH_STATUS_LIST(TB_TEXT)
#undef TB_TEXT
    };
    const int n = (int)(sizeof code / sizeof code[0]), other[6] = {INT_MIN, -22, 1, 2, 100, INT_MAX};
    int i, j;
    th_begin("sph_strerror: every listed code its own sentence, values 0, -1, -2, ...; any other int a sentence");
    for (i = 0; i < n; ++i) {
        TH_CHECK(code[i] == -i, "code %d has value %d", i, code[i]);
        TH_CHECK(strcmp(sph_strerror(code[i]), text[i]) == 0, "code %d: '%s'", code[i], sph_strerror(code[i]));
        for (j = 0; j < i; ++j) TH_CHECK(strcmp(text[i], text[j]) != 0, "codes %d and %d share a sentence", i, j);
    }
    TH_CHECK(n == 22, "%d codes (SPH_EISA, the last, included)", n);
    for (i = 0; i < 6; ++i)
        TH_CHECK(sph_strerror(other[i]) != NULL && strcmp(sph_strerror(other[i]), "unknown status code") == 0,
                 "strerror(%d)", other[i]);
    th_end();
}

/* ---- section 3 ---- */

static void test_kernel_args(void)
{
    static const char *const names[6] = {"", "CUBIC", "cubic ", "wendland", "invalid", "cubic\tx"};
    char longname[1000];
    int i, j, k, v;
    th_begin("kernel and dimension checks, constants and names over bad kernels and dimensions");
    for (i = 0; i < 4; ++i) {
        const sph_kernel bk = (sph_kernel)bad_kernel[i];
        TH_CHECK(sph_kernel_check(bk, 2) == SPH_EKERNEL, "kernel %d", bad_kernel[i]);
        TH_CHECK(sph_kernel_support(bk) == 0 && sph_kernel_alpha(bk, 2) == 0 && sph_kernel_sigma(bk, 2) == 0,
                 "constants of kernel %d", bad_kernel[i]);
        TH_CHECK(strcmp(sph_kernel_name(bk), "invalid") == 0, "name of kernel %d", bad_kernel[i]);
    }
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (j = 0; j < 5; ++j) {
            TH_CHECK(sph_kernel_check((sph_kernel)k, bad_int[j]) == SPH_EDIM, "dim %d", bad_int[j]);
            TH_CHECK(sph_kernel_alpha((sph_kernel)k, bad_int[j]) == 0 && sph_kernel_sigma((sph_kernel)k, bad_int[j]) == 0,
                     "constants in dim %d", bad_int[j]);
        }
    memset(longname, 'a', sizeof longname - 1);
    longname[sizeof longname - 1] = '\0';
    TH_CHECK(sph_kernel_from_name(NULL) == SPH_EKERNEL && sph_kernel_from_name(longname) == SPH_EKERNEL, "NULL, long");
    for (i = 0; i < 6; ++i) TH_CHECK(sph_kernel_from_name(names[i]) == SPH_EKERNEL, "name '%s'", names[i]);
    th_end();

    th_begin("sph_check_h over every value: SPH_OK only for positive, finite, not tiny h");
    for (v = 0; v < NV; ++v) {
        const int want = (v == V_HALF || v == V_TWO || v == V_BIG || v == V_MAX) ? SPH_OK : SPH_EH;
        TH_CHECK(sph_check_h(val[v]) == want, "h %s: %d", vname[v], sph_check_h(val[v]));
    }
    th_end();
}

static sph_real scalar_of(int which, sph_kernel k, int dim, sph_real r, sph_real h)
{
    switch (which) {
    case 0: return sph_kernel_w(k, dim, r, h);
    case 1: return sph_kernel_f(k, dim, r, h);
    case 2: return sph_kernel_dwdr(k, dim, r, h);
    case 3: return sph_kernel_d2wdr2(k, dim, r, h);
    default: return sph_kernel_dwdh(k, dim, r, h);
    }
}

static void test_scalar_kernels(void)
{
    static const char *const fname[5] = {"w", "f", "dwdr", "d2wdr2", "dwdh"};
    int k, dim, vr, vh, i;
    for (k = -1; k <= SPH_KERNEL_COUNT; ++k) {
        th_begin("scalar kernels %s over r x h x dim -1..4: finite; 0 for negative or non-finite r, refused h",
                 sph_kernel_name((sph_kernel)k));
        for (dim = -1; dim <= 4; ++dim)
            for (vr = 0; vr < NV; ++vr)
                for (vh = 0; vh < NV; ++vh) {
                    const sph_real r = val[vr], h = val[vh];
                    const int zero = !(r >= 0 && fin(r)) || sph_check_h(h) != SPH_OK || dim < 1 || dim > 3 ||
                                     k < 0 || k >= SPH_KERNEL_COUNT;
                    sph_real W = SENT, F = SENT;
                    for (i = 0; i < 5; ++i) {
                        const sph_real y = scalar_of(i, (sph_kernel)k, dim, r, h);
                        TH_CHECK(fin(y) && (!zero || y == 0), "%dD %s(r %s, h %s) = %g", dim, fname[i], vname[vr],
                                 vname[vh], (double)y);
                    }
                    sph_kernel_wf((sph_kernel)k, dim, r, h, &W, &F);
                    TH_CHECK(fin(W) && fin(F) && (!zero || (W == 0 && F == 0)), "%dD wf(r %s, h %s) = %g, %g", dim,
                             vname[vr], vname[vh], (double)W, (double)F);
                }
        th_end();
    }
    th_begin("sph_kernel_grad: each component of dx and h over every value, dims -1..4: finite, no write past "
             "min(dim, 3); NULL arrays");
    for (dim = -1; dim <= 4; ++dim)
        for (i = 0; i < 3; ++i)
            for (vr = 0; vr < NV; ++vr)
                for (vh = 0; vh < NV; ++vh) {
                    sph_real dx[3] = {(sph_real)0.3, (sph_real)-0.2, (sph_real)0.1}, g[5] = {SENT, SENT, SENT, SENT, SENT};
                    int a;
                    dx[i] = val[vr];
                    sph_kernel_grad(SPH_KERNEL_QUINTIC, dim, dx, val[vh], g);
                    for (a = 0; a < 5; ++a)
                        TH_CHECK(a < dim && a < 3 ? fin(g[a]) : g[a] == SENT, "%dD dx[%d] %s h %s: g[%d] = %g", dim, i,
                                 vname[vr], vname[vh], a, (double)g[a]);
                    if (!fin(val[vr]) && i < dim)
                        for (a = 0; a < dim && a < 3; ++a) TH_CHECK(g[a] == 0, "non-finite dx: g[%d] = %g", a, (double)g[a]);
                }
    {
        sph_real g[3] = {SENT, SENT, SENT}, dx[3] = {0, 0, 0};
        sph_kernel_grad(SPH_KERNEL_CUBIC, 3, NULL, 1, g);
        TH_CHECK(g[0] == 0 && g[1] == 0 && g[2] == 0, "NULL dx: zeros");
        sph_kernel_grad(SPH_KERNEL_CUBIC, 3, dx, 1, NULL); /* nothing to write, no crash */
    }
    th_end();

    th_begin("neighbour counts and h for a count over every value pair: finite and >= 0");
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim)
            for (vr = 0; vr < NV; ++vr)
                for (vh = 0; vh < NV; ++vh) {
                    const sph_real n = sph_kernel_neighbours((sph_kernel)k, dim, val[vr], val[vh]);
                    const sph_real hh = sph_kernel_h_for_neighbours((sph_kernel)k, dim, val[vr], val[vh]);
                    TH_CHECK(fin(n) && n >= 0, "%s %dD neighbours(h %s, V %s) = %g", sph_kernel_name((sph_kernel)k),
                             dim, vname[vr], vname[vh], (double)n);
                    TH_CHECK(fin(hh) && hh >= 0, "%s %dD h_for_neighbours(N %s, V %s) = %g",
                             sph_kernel_name((sph_kernel)k), dim, vname[vr], vname[vh], (double)hh);
                }
    th_end();
}

/* ---- section 4 ---- */

static void test_box_and_views(void)
{
    static const int axes[6] = {INT_MIN, -1, 0, 2, 3, INT_MAX};
    sph_real x[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    int vl, vd, ia, j, per;
    th_begin("sph_box_delta: period and dx over every value, axis index out of range: finite, or dx unchanged "
             "where it is not finite");
    for (per = 0; per < 2; ++per)
        for (vl = 0; vl < NV; ++vl)
            for (ia = 0; ia < 6; ++ia)
                for (vd = 0; vd < NV; ++vd) {
                    sph_box box;
                    sph_real d;
                    for (j = 0; j < 3; ++j) box.lo[j] = 0, box.length[j] = val[vl], box.periodic[j] = per;
                    d = sph_box_delta(&box, axes[ia], val[vd]);
                    if (fin(val[vd])) {
                        TH_CHECK(fin(d), "L %s axis %d dx %s: %g", vname[vl], axes[ia], vname[vd], (double)d);
                        if (per && axes[ia] >= 0 && axes[ia] <= 2 && val[vl] > 0 && fin(val[vl]) &&
                            fin(val[vd] / val[vl]))
                            TH_CHECK(fabs((double)d) <= 0.5 * (double)val[vl] * (1 + 4 * TH_EPS),
                                     "L %s dx %s: |image| %g > L/2", vname[vl], vname[vd], (double)d);
                    } else {
                        TH_CHECK(d == val[vd] || (d != d && val[vd] != val[vd]), "dx %s changed to %g", vname[vd],
                                 (double)d);
                    }
                }
    TH_CHECK(sph_box_delta(NULL, 5, (sph_real)0.7) == (sph_real)0.7, "NULL box");
    th_end();

    th_begin("views: ncomp and stride over bad values set no component beyond min(ncomp, 3)");
    for (j = 0; j < 5; ++j) {
        const int nc = bad_int[j] == 4 ? 4 : bad_int[j];
        const sph_view v = sph_view_aos(x, nc, 3 * sizeof(sph_real)), w = sph_view_interleaved(x, nc);
        const sph_out o = sph_out_aos(x, nc, 0), p = sph_out_interleaved(x, nc);
        int a;
        for (a = 0; a < 3; ++a) {
            const int set = a < nc;
            TH_CHECK((v.p[a] != NULL) == set && (w.p[a] != NULL) == set && (o.p[a] != NULL) == set &&
                         (p.p[a] != NULL) == set,
                     "ncomp %d: component %d", nc, a);
        }
    }
    {
        const sph_view n = sph_view_none(), s = sph_view_soa(NULL, NULL, NULL), a0 = sph_view_aos(NULL, 3, 24);
        const sph_out os = sph_out_soa(NULL, x, NULL);
        TH_CHECK(n.p[0] == NULL && n.p[1] == NULL && n.p[2] == NULL && s.p[0] == NULL && a0.p[0] == NULL &&
                     a0.p[2] == NULL && os.p[0] == NULL && os.p[1] == x,
                 "NULL arrays stay NULL");
    }
    th_end();
}

/* ---- section 5 ---- */

static void test_pair_kernel(void)
{
    int k, dim, i, vd, vh;
    th_begin("sph_pair_kernel: each component of dx and h over every value: r, q, W, F finite; all zero for a "
             "non-finite dx");
    for (k = -1; k <= SPH_KERNEL_COUNT; ++k)
        for (dim = -1; dim <= 4; ++dim)
            for (i = 0; i < 3; ++i)
                for (vd = 0; vd < NV; ++vd)
                    for (vh = 0; vh < NV; ++vh) {
                        sph_real dx[3] = {(sph_real)0.3, (sph_real)-0.2, (sph_real)0.1};
                        sph_pair p;
                        dx[i] = val[vd];
                        p = sph_pair_kernel((sph_kernel)k, dim, dx, val[vh]);
                        TH_CHECK(fin(p.r) && fin(p.q) && fin(p.W) && fin(p.F), "k %d %dD dx[%d] %s h %s: %g %g %g %g",
                                 k, dim, i, vname[vd], vname[vh], (double)p.r, (double)p.q, (double)p.W, (double)p.F);
                        if (!fin(val[vd]) && i < dim)
                            TH_CHECK(p.r == 0 && p.q == 0 && p.W == 0 && p.F == 0, "dx[%d] %s: not all zero", i,
                                     vname[vd]);
                    }
    TH_CHECK(sph_pair_kernel(SPH_KERNEL_CUBIC, 3, NULL, 1).W == 0, "NULL dx");
    th_end();
}

/* The plain arithmetic pair terms with one argument at a time over every
 * value (the others 0.5, vectors (0.5, -0.5, 0.25)): finite for every finite
 * value (the products of one overflow-sized value and factors <= 1 stay in
 * range); and no component past min(dim, 3) touched, dim -1..4. */
enum { PT_DENSITY, PT_INTERP, PT_GSTD, PT_GDIFF, PT_GSYM, PT_GPRES, PT_DSTD, PT_DDIFF, PT_CURL, PT_LAP, PT_DIFF,
       PT_CORR, PT_N };
static const char *const ptname[PT_N] = {"density", "interpolate", "grad_standard", "grad_difference",
                                         "grad_symmetric", "grad_pressure", "div_standard", "div_difference",
                                         "curl", "laplacian", "diffusion", "correction"};
static const int ptargs[PT_N] = {2, 3, 3, 4, 4, 4, 2, 2, 2, 4, 5, 2}; /* scalar arguments */
static const int ptvecs[PT_N] = {0, 0, 1, 1, 1, 1, 2, 3, 2, 0, 0, 1}; /* vector arguments read */

/* Runs term t with scalars s[], vectors u[3][3]; the result into out[12]
 * (scalar at out[0]; acc or M pre-filled by the caller). */
static void pt_run(int t, int dim, const sph_real *s, sph_real u[3][3], sph_real *out)
{
    switch (t) {
    case PT_DENSITY: out[0] = sph_pair_density(s[0], s[1]); break;
    case PT_INTERP: out[0] = sph_pair_interpolate(s[0], s[1], s[2]); break;
    case PT_GSTD: sph_pair_grad_standard(dim, s[0], s[1], s[2], u[0], out); break;
    case PT_GDIFF: sph_pair_grad_difference(dim, s[0], s[1], s[2], s[3], u[0], out); break;
    case PT_GSYM: sph_pair_grad_symmetric(dim, s[0], s[1], s[2], s[3], u[0], out); break;
    case PT_GPRES: sph_pair_grad_pressure(dim, s[0], s[1], s[2], s[3], u[0], out); break;
    case PT_DSTD: out[0] = sph_pair_div_standard(dim, s[0], u[0], s[1], u[1]); break;
    case PT_DDIFF: out[0] = sph_pair_div_difference(dim, s[0], u[0], u[1], s[1], u[2]); break;
    case PT_CURL: sph_pair_curl(dim, s[0], u[0], s[1], u[1], out); break;
    case PT_LAP: out[0] = sph_pair_laplacian(s[0], s[1], s[2], s[3]); break;
    case PT_DIFF: out[0] = sph_pair_diffusion(s[0], s[1], s[2], s[3], s[4]); break;
    default: sph_pair_correction(dim, s[0], s[1], u[0], out); break;
    }
}

static void test_pair_terms(void)
{
    int t, dim, arg, v, a, c;
    for (t = 0; t < PT_N; ++t) {
        th_begin("pair term %s: one argument at a time over every value, dim -1..4: finite for finite values, "
                 "nothing past the third component", ptname[t]);
        for (dim = -1; dim <= 4; ++dim)
            for (arg = 0; arg < ptargs[t] + 3 * ptvecs[t]; ++arg)
                for (v = 0; v < NV; ++v) {
                    sph_real s[5] = {(sph_real)0.5, (sph_real)0.5, (sph_real)0.5, (sph_real)0.5, (sph_real)0.5};
                    sph_real u[3][3], out[12];
                    const int reads = t == PT_CORR ? 9 : 3; /* entries the term may write */
                    for (c = 0; c < 3; ++c) u[c][0] = (sph_real)0.5, u[c][1] = (sph_real)-0.5, u[c][2] = (sph_real)0.25;
                    if (arg < ptargs[t]) s[arg] = val[v];
                    else u[(arg - ptargs[t]) / 3][(arg - ptargs[t]) % 3] = val[v];
                    for (a = 0; a < 12; ++a) out[a] = a < reads ? 0 : SENT;
                    pt_run(t, dim, s, u, out);
                    /* the correction term has dx squared: an overflow-sized component overflows */
                    const int squared = t == PT_CORR && arg >= ptargs[t] && (v == V_BIG || v == V_MAX || v == V_NMAX);
                    for (a = 0; a < reads; ++a)
                        TH_CHECK(!finite_arg(v) || squared || fin(out[a]), "%dD argument %d = %s: out[%d] = %g", dim,
                                 arg, vname[v], a, (double)out[a]);
                    for (a = reads; a < 12; ++a) TH_CHECK(out[a] == SENT, "%dD: wrote out[%d]", dim, a);
                    if (t != PT_CORR && t != PT_DENSITY && t != PT_INTERP && t != PT_LAP && t != PT_DIFF &&
                        t != PT_DSTD && t != PT_DDIFF)
                        for (a = 0; a < 3; ++a)
                            TH_CHECK(a < dim || out[a] == 0, "%dD: acc[%d] = %g written", dim, a, (double)out[a]);
                }
        th_end();
    }
}

static void test_pressure_harmonic(void)
{
    int vi, vj;
    th_begin("sph_pressure_factor over every (p, rho): finite; 0 for rho <= 0, non-finite or with rho^2 "
             "overflowing; p / rho^2 elsewhere");
    for (vi = 0; vi < NV; ++vi)
        for (vj = 0; vj < NV; ++vj) {
            const sph_real p = val[vi], rho = val[vj], P = sph_pressure_factor(p, rho);
            const long double ref = (long double)p / ((long double)rho * (long double)rho);
            TH_CHECK(fin(P), "p %s rho %s: %g", vname[vi], vname[vj], (double)P);
            if (!(rho > 0) || !fin(rho) || !fin(p) || !fin(rho * rho))
                TH_CHECK(P == 0, "p %s rho %s: %g, want 0", vname[vi], vname[vj], (double)P);
            else if (fabsl(ref) >= (long double)REAL_MIN && fabsl(ref) <= (long double)REAL_MAX / 2)
                TH_CHECK(fabsl((long double)P - ref) <= 2 * TH_EPS * fabsl(ref), "p %s rho %s: %g, want %Lg", vname[vi],
                         vname[vj], (double)P, ref);
        }
    th_end();

    th_begin("sph_harmonic_k over every (k_i, k_j): finite, symmetric bit for bit, 0 unless finite and of one "
             "sign, 4 k_i k_j / (k_i + k_j) (long double) within 4 eps, saturated beyond the range");
    for (vi = 0; vi < NV; ++vi)
        for (vj = 0; vj < NV; ++vj) {
            const sph_real a = val[vi], b = val[vj], k = sph_harmonic_k(a, b);
            const int same = (a > 0 && b > 0) || (a < 0 && b < 0);
            const long double ref = 4.0L * (long double)a * (long double)b / ((long double)a + (long double)b);
            TH_CHECK(fin(k), "k(%s, %s) = %g", vname[vi], vname[vj], (double)k);
            TH_CHECK(k == sph_harmonic_k(b, a), "k(%s, %s) not symmetric", vname[vi], vname[vj]);
            if (!same || !fin(a) || !fin(b)) TH_CHECK(k == 0, "k(%s, %s) = %g, want 0", vname[vi], vname[vj], (double)k);
            else if (fabsl(ref) > (long double)REAL_MAX)
                TH_CHECK(fabs((double)k) == REAL_MAX && (k > 0) == (ref > 0), "k(%s, %s) = %g, want +-max", vname[vi],
                         vname[vj], (double)k);
            else if (fabsl(ref) >= (long double)REAL_MIN)
                TH_CHECK(fabsl((long double)k - ref) <= 4 * TH_EPS * fabsl(ref), "k(%s, %s) = %g, want %Lg",
                         vname[vi], vname[vj], (double)k, ref);
        }
    th_end();
}

static void test_correction_invert(void)
{
    static const int dims[7] = {INT_MIN, -1, 0, 1, 2, 3, 4};
    int id, v, vr, full, a, b, c;
    th_begin("sph_correction_invert: M = diag(v) or all v, rcond over every value, bad dims: B finite; where "
             "it inverts, M B = I");
    for (id = 0; id < 7; ++id)
        for (full = 0; full < 2; ++full)
            for (v = 0; v < NV; ++v)
                for (vr = 0; vr < NV; ++vr) {
                    const int dim = dims[id];
                    sph_real M[9], B[10];
                    int ok;
                    for (a = 0; a < 9; ++a) M[a] = full || a % 4 == 0 ? val[v] : 0;
                    if (full) M[4] = (sph_real)0.5, M[8] = (sph_real)0.25; /* keep the full one invertible */
                    for (a = 0; a < 10; ++a) B[a] = SENT;
                    ok = sph_correction_invert(dim, M, val[vr], B);
                    for (a = 0; a < 9; ++a) TH_CHECK(fin(B[a]), "dim %d M %s rcond %s: B[%d] = %g", dim, vname[v],
                                                     vname[vr], a, (double)B[a]);
                    TH_CHECK(B[9] == SENT && (ok == 0 || ok == 1), "dim %d: B[9] written or status %d", dim, ok);
                    if (ok)
                        for (a = 0; a < dim; ++a)
                            for (b = 0; b < dim; ++b) {
                                long double s = 0;
                                for (c = 0; c < dim; ++c) s += (long double)M[3 * a + c] * (long double)B[3 * c + b];
                                TH_CHECK(fabsl(s - (a == b)) <= 1e3L * TH_EPS, "dim %d M %s: (M B)[%d][%d] = %Lg", dim,
                                         vname[v], a, b, s);
                            }
                    else
                        for (a = 0; a < 9; ++a)
                            TH_CHECK(B[a] == (a % 4 == 0 && a / 3 < dim ? 1 : 0), "fallback B[%d] = %g", a, (double)B[a]);
                }
    {
        sph_real B[9], M[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        TH_CHECK(sph_correction_invert(3, NULL, 0, B) == 0 && B[0] == 1 && B[4] == 1 && B[8] == 1 && B[1] == 0,
                 "NULL M: identity");
        TH_CHECK(sph_correction_invert(3, M, 0, NULL) == 0, "NULL B");
    }
    th_end();
}

/* ---- section 6 ---- */

typedef struct {
    ts_scene s;
    sph_real *f, *v, *k, *m, *rho, *hh;
    xo_in in;
} tb_scene;

static void tb_make(tb_scene *t)
{
    int i, a;
    ts_lattice(&t->s, SPH_KERNEL_CUBIC, 2, 6, 1.0 / 6, 1.3, 0.2, 5, NULL);
    t->f = ts_vec(t->s.n), t->v = ts_vec(3 * t->s.n), t->k = ts_vec(t->s.n);
    t->m = ts_vec(t->s.n), t->rho = ts_vec(t->s.n), t->hh = ts_vec(t->s.n);
    for (i = 0; i < t->s.n; ++i) {
        t->f[i] = (sph_real)ts_linear(t->s.x + 3 * i);
        for (a = 0; a < 3; ++a) t->v[3 * i + a] = (sph_real)ts_vlinear(t->s.x + 3 * i, a);
        t->k[i] = 1 + (sph_real)(i % 3);
        t->m[i] = t->s.V[i];
        t->rho[i] = 1;
        t->hh[i] = (sph_real)t->s.h;
    }
    t->s.c.m = sph_view_soa(t->m, NULL, NULL);
    t->s.c.rho = sph_view_soa(t->rho, NULL, NULL);
    t->in.f = sph_view_soa(t->f, NULL, NULL);
    t->in.ft = sph_view_none();
    t->in.v = sph_view_interleaved(t->v, 3);
    t->in.vt = sph_view_none();
    t->in.k = sph_view_soa(t->k, NULL, NULL);
    t->in.kt = sph_view_none();
}

static void tb_free(tb_scene *t)
{
    free(t->f), free(t->v), free(t->k), free(t->m), free(t->rho), free(t->hh);
    ts_free(&t->s);
}

/* Every operator on c: each either returns SPH_OK with finite outputs (when
 * finite_out) or an error with its output and count untouched. Returns the
 * number of operators that ran. */
static int tb_run(const tb_scene *t, const sph_ctx *c, int finite_out, const char *what)
{
    xo_res R;
    sph_real *rg = ts_vec(4 * t->s.n); /* sph_density_gradient, which xo_run leaves out: rho, then grad */
    int op, i, ran = 0, st;
    xo_alloc(&R, t->s.n, SENT);
    xo_run(c, &t->in, &R);
    for (i = 0; i < 4 * t->s.n; ++i) rg[i] = SENT;
    st = sph_density_gradient(c, t->in.f, t->in.ft, sph_out_soa(rg, NULL, NULL),
                              sph_out_interleaved(rg + t->s.n, 3));
    for (i = 0; i < 4 * t->s.n; ++i)
        if (st == SPH_OK ? finite_out && !fin(rg[i]) && (i < t->s.n || (i - t->s.n) % 3 < 2) : rg[i] != SENT) break;
    TH_CHECK(i == 4 * t->s.n, "%s: density_gradient (status %d) wrote rg[%d]", what, st, i);
    ran += st == SPH_OK;
    free(rg);
    for (op = 0; op < XO_N; ++op) {
        if (R.status[op] == SPH_OK) {
            ++ran;
            if (finite_out)
                TH_CHECK(xo_first_nonfinite(&R, op) < 0, "%s: %s wrote a non-finite value", what, xo_names[op]);
        } else {
            for (i = 0; i < 9 * t->s.n; ++i)
                if (R.o[op][i] != SENT) break;
            TH_CHECK(i == 9 * t->s.n && (R.count[op] == -7 || op == XO_DENSITY), "%s: %s (status %d) wrote output",
                     what, xo_names[op], R.status[op]);
        }
    }
    xo_free(&R);
    return ran;
}

static void test_operators(void)
{
    tb_scene t;
    sph_ctx c;
    sph_box box;
    int v, j, a, ran;
    tb_make(&t);
    th_begin("operators: h, rcond_min, a periodic length over every value, bad kernel and dim: a status, or "
             "finite outputs");
    for (v = 0; v < NV; ++v) {
        c = t.s.c;
        c.h = val[v];
        ran = tb_run(&t, &c, 1, "h");
        TH_CHECK((ran > 0) == (sph_check_h(val[v]) == SPH_OK), "h %s: %d operators ran", vname[v], ran);
        c = t.s.c;
        c.rcond_min = val[v];
        ran = tb_run(&t, &c, 1, "rcond_min");
        TH_CHECK((ran > 0) == (val[v] >= 0 && val[v] < 1), "rcond_min %s: %d ran", vname[v], ran);
        for (a = 0; a < 3; ++a) box.lo[a] = 0, box.length[a] = val[v], box.periodic[a] = 1;
        c = t.s.c;
        c.box = &box;
        ran = tb_run(&t, &c, 1, "period");
        TH_CHECK((ran > 0) == (val[v] > 0 && fin(val[v]) && fin(1 / val[v])), "period %s: %d ran", vname[v], ran);
    }
    for (j = 0; j < 5; ++j) {
        c = t.s.c;
        c.dim = bad_int[j];
        TH_CHECK(tb_run(&t, &c, 1, "dim") == 0, "dim %d ran", bad_int[j]);
        c = t.s.c;
        c.kernel = (sph_kernel)bad_kernel[j < 4 ? j : 0];
        TH_CHECK(tb_run(&t, &c, 1, "kernel") == 0, "kernel %d ran", bad_kernel[j < 4 ? j : 0]);
    }
    th_end();

    th_begin("operators: one value of each input array over every value: SPH_ENONFINITE / SPH_EH / SPH_EVALUE, "
             "or finite outputs (up to overflow-sized field values, whose sums may overflow)");
    for (v = 0; v < NV; ++v) {
        const int moderate = finite_arg(v) && v != V_MAX && v != V_NMAX;
        sph_real *arr[6] = {t.f, t.v, t.k, t.m, t.rho, t.s.V};
        const char *an[6] = {"f", "v", "k", "m", "rho", "V"};
        sph_real keep;
        for (j = 0; j < 6; ++j) {
            keep = arr[j][7];
            arr[j][7] = val[v];
            c = t.s.c;
            ran = tb_run(&t, &c, moderate, an[j]);
            TH_CHECK(finite_arg(v) || ran < XO_N + 1, "%s %s: every operator ran", an[j], vname[v]);
            arr[j][7] = keep;
        }
        keep = t.s.x[3 * 4 + 1];
        t.s.x[3 * 4 + 1] = val[v];
        ran = tb_run(&t, &t.s.c, 1, "x");
        TH_CHECK((ran > 0) == (finite_arg(v) && fabs((double)val[v]) <= sqrt(REAL_MAX) / 4), "x %s: %d ran",
                 vname[v], ran);
        t.s.x[3 * 4 + 1] = keep;
        t.hh[9] = val[v];
        c = t.s.c;
        c.h_source = sph_view_soa(t.hh, NULL, NULL);
        ran = tb_run(&t, &c, 1, "per-particle h");
        TH_CHECK((ran > 0) == (sph_check_h(val[v]) == SPH_OK), "per-particle h %s: %d ran", vname[v], ran);
        t.hh[9] = (sph_real)t.s.h;
    }
    th_end();

    th_begin("operators: unknown schemes (SPH_EOPTION), tensor strides (SPH_ESTRIDE), NULL outputs; n_targets beyond "
             "an offset array of n_sources + 1 entries is SPH_ECOUNT before offset[n_targets] is read");
    {
        const sph_scheme bad_s[3] = {(sph_scheme)-1, (sph_scheme)5, (sph_scheme)99};
        const sph_view f = t.in.f, vv = t.in.v;
        sph_real *T = ts_vec(9 * t.s.n), *o = ts_vec(3 * t.s.n);
        sph_off *off = (sph_off *)malloc(sizeof(sph_off) * (size_t)(t.s.n + 1));
        sph_neighbours L = t.s.L.list;
        sph_idx nfb = -7;
        int s, vs;
        for (s = 0; s < 3; ++s) {
            TH_CHECK(sph_gradient(&t.s.c, bad_s[s], f, sph_view_none(), sph_out_interleaved(o, 3), &nfb) == SPH_EOPTION,
                     "gradient scheme %d", (int)bad_s[s]);
            TH_CHECK(sph_gradient_vector(&t.s.c, bad_s[s], vv, sph_view_none(), T, 9, &nfb) == SPH_EOPTION, "tensor");
            TH_CHECK(sph_divergence(&t.s.c, bad_s[s], vv, sph_view_none(), sph_out_soa(o, NULL, NULL), &nfb) ==
                         SPH_EOPTION, "divergence");
            TH_CHECK(sph_curl(&t.s.c, bad_s[s], vv, sph_view_none(), sph_out_interleaved(o, 3)) == SPH_EOPTION, "curl");
        }
        TH_CHECK(sph_gradient_vector(&t.s.c, SPH_SCHEME_PRESSURE, vv, sph_view_none(), T, 9, &nfb) == SPH_EOPTION &&
                     sph_divergence(&t.s.c, SPH_SCHEME_SYMMETRIC, vv, sph_view_none(), sph_out_soa(o, NULL, NULL),
                                    &nfb) == SPH_EOPTION,
                 "schemes an operator does not have");
        for (vs = -2; vs <= 3; ++vs) {
            TH_CHECK(sph_gradient_vector(&t.s.c, SPH_SCHEME_STANDARD, vv, sph_view_none(), T, vs, &nfb) == SPH_ESTRIDE,
                     "T_stride %d", vs);
            TH_CHECK(sph_correction_matrix(&t.s.c, T, vs, &nfb) == SPH_ESTRIDE, "B_stride %d", vs);
        }
        TH_CHECK(sph_gradient_vector(&t.s.c, SPH_SCHEME_STANDARD, vv, sph_view_none(), NULL, 9, &nfb) == SPH_ENULL &&
                     sph_correction_matrix(&t.s.c, NULL, 9, &nfb) == SPH_ENULL &&
                     sph_density(&t.s.c, sph_out_soa(NULL, NULL, NULL)) == SPH_ENULL &&
                     sph_density(NULL, sph_out_soa(o, NULL, NULL)) == SPH_ENULL,
                 "NULL outputs or context");
        TH_CHECK(nfb == -7, "a refused call wrote its count");
        /* an offset array of exactly n + 1 entries: n_targets = n + 5 must be refused on the counts */
        memcpy(off, L.offset, sizeof(sph_off) * (size_t)(t.s.n + 1));
        L.offset = off;
        L.n_targets = (sph_idx)t.s.n + 5;
        for (vs = 0; vs < 2; ++vs) {
            c = t.s.c;
            c.list = &L;
            c.validate = vs ? SPH_VALIDATE_ARGS : SPH_VALIDATE_FULL;
            TH_CHECK(sph_density(&c, sph_out_soa(o, NULL, NULL)) == SPH_ECOUNT, "n_targets > n_sources (validate %d)", vs);
        }
        L.n_targets = INT_MAX;
        c.validate = SPH_VALIDATE_ARGS;
        TH_CHECK(sph_density(&c, sph_out_soa(o, NULL, NULL)) == SPH_ECOUNT, "n_targets INT_MAX");
        free(T), free(o), free(off);
    }
    th_end();

    th_begin("sph_neighbours_check and sph_check_field over bad lists, counts and values");
    {
        sph_neighbours L = t.s.L.list;
        sph_off off[3] = {0, 2, 1};
        sph_idx idx[2] = {0, 0}, first = -7;
        sph_real y[4] = {1, 2, 3, 4};
        TH_CHECK(sph_neighbours_check(NULL) == SPH_ENULL, "NULL list");
        L.n_targets = -1;
        TH_CHECK(sph_neighbours_check(&L) == SPH_ECOUNT, "n_targets < 0");
        L.n_targets = INT_MIN;
        TH_CHECK(sph_neighbours_check(&L) == SPH_ECOUNT, "n_targets INT_MIN");
        L.n_targets = 2, L.n_sources = 1, L.offset = off, L.index = idx;
        TH_CHECK(sph_neighbours_check(&L) == SPH_EOFFSET, "decreasing offsets");
        off[2] = 2, idx[1] = 1;
        TH_CHECK(sph_neighbours_check(&L) == SPH_EINDEX, "index = n_sources");
        idx[1] = -1;
        TH_CHECK(sph_neighbours_check(&L) == SPH_EINDEX, "index -1");
        L.index = NULL;
        TH_CHECK(sph_neighbours_check(&L) == SPH_ENULL, "index NULL with pairs");
        L.offset = NULL;
        TH_CHECK(sph_neighbours_check(&L) == SPH_ENULL, "offset NULL");
        for (v = 0; v < NV; ++v) {
            int st;
            y[2] = val[v];
            first = -7;
            st = sph_check_field(sph_view_soa(y, NULL, NULL), 1, 4, &first);
            TH_CHECK(finite_arg(v) ? st == SPH_OK && first == -1 : st == SPH_ENONFINITE && first == 2,
                     "value %s: status %d, first %d", vname[v], st, (int)first);
        }
        first = -7;
        for (j = 0; j < 5; ++j) {
            TH_CHECK(sph_check_field(sph_view_soa(y, NULL, NULL), bad_int[j], 4, &first) == SPH_ERANGE, "ncomp %d",
                     bad_int[j]);
            if (bad_int[j] < 0)
                TH_CHECK(sph_check_field(sph_view_soa(y, NULL, NULL), 1, bad_int[j], &first) == SPH_ECOUNT, "n %d",
                         bad_int[j]);
        }
        TH_CHECK(first == -7, "first_bad written on a refused call");
        TH_CHECK(sph_check_field(sph_view_soa(NULL, NULL, NULL), 1, 4, NULL) == SPH_ENULL, "NULL component");
        {
            sph_ctx cc = sph_ctx_init((sph_kernel)-1, INT_MIN, val[V_NAN], NULL, sph_view_none());
            TH_CHECK(sph_density(&cc, sph_out_soa(y, NULL, NULL)) == SPH_ENULL && y[0] == 1, "context of bad values");
        }
    }
    {   /* the check runs in blocks (of 4096 rows or entries, the entries 32 at a time, then a tail): one bad
           offset or index anywhere, in a block's body, at its edges or in the tail, is found */
        enum { NR = 5000, NE = 9011 };
        static sph_off off[NR + 1];
        static sph_idx idx[NE];
        static const long at_e[] = {0, 1, 31, 32, 33, 4095, 4096, 4097, 8191, 8192, 8991, 8992, 9010};
        static const long at_r[] = {0, 1, 31, 32, 4094, 4095, 4096, 4999};
        const sph_idx bad_idx[] = {-1, 997, 998, INT_MIN, INT_MAX}; /* the sources are 0..996 */
        sph_neighbours L = t.s.L.list;
        long e, r;
        int b;
        for (r = 0; r <= NR; ++r) off[r] = (sph_off)(r * (long)NE / NR);
        for (e = 0; e < NE; ++e) idx[e] = (sph_idx)(e % 997);
        L.n_targets = NR, L.n_sources = 997, L.offset = off, L.index = idx;
        TH_CHECK(sph_neighbours_check(&L) == SPH_OK, "valid list of %d rows, %d entries", NR, NE);
        for (e = 0; e < (long)(sizeof at_e / sizeof at_e[0]); ++e)
            for (b = 0; b < 5; ++b) {
                const sph_idx keep = idx[at_e[e]];
                idx[at_e[e]] = bad_idx[b];
                TH_CHECK(sph_neighbours_check(&L) == SPH_EINDEX, "index %ld = %ld", at_e[e], (long)bad_idx[b]);
                idx[at_e[e]] = keep;
            }
        for (r = 0; r < (long)(sizeof at_r / sizeof at_r[0]); ++r) {
            const sph_off keep = off[at_r[r] + 1];
            off[at_r[r] + 1] = off[at_r[r]] - 1; /* row at_r[r] of negative length */
            TH_CHECK(sph_neighbours_check(&L) == SPH_EOFFSET, "offset %ld below the one before", at_r[r] + 1);
            off[at_r[r] + 1] = keep;
        }
        TH_CHECK(sph_neighbours_check(&L) == SPH_OK, "the list restored");
    }
    th_end();
    tb_free(&t);
}

/* ---- section 7 ---- */

static void test_search(void)
{
    enum { N = 40 };
    sph_real x[3 * N] = {0}, h[N];
    sph_view xv = sph_view_interleaved(x, 3);
    sph_box box;
    sph_nsearch g;
    sph_off off[N + 1], pairs = -7, cand = -7;
    sph_idx idx[N * N], perm[N], inv[N];
    sph_real fill = -7, out[3 * N];
    static char work[1 << 18];
    size_t bytes = 0;
    tp_rng rng = {77};
    int v, j, st, a, i;
    tp_uniform_cloud(3, N, 1.0, &rng, x);
    for (i = 0; i < N; ++i) h[i] = (sph_real)0.1;
    for (a = 0; a < 3; ++a) box.lo[a] = 0, box.length[a] = 1, box.periodic[a] = 1;

    th_begin("search set-up: cell, one position, one per-source h, the period over every value; bad dims and "
             "counts: documented statuses, a failed build unusable");
    for (v = 0; v < NV; ++v) {
        const sph_real c = val[v];
        st = sph_nsearch_workspace_size(3, xv, N, sph_view_none(), c, NULL, &bytes);
        TH_CHECK(st == (v == V_HALF || v == V_TWO || v == V_BIG || v == V_MAX ? SPH_OK
                        : v == V_DEN                                         ? SPH_EGRID
                                                                             : SPH_ERANGE),
                 "cell %s: %d", vname[v], st);
        x[3 * 5 + 1] = val[v];
        st = sph_nsearch_workspace_size(3, xv, N, sph_view_none(), (sph_real)0.1, NULL, &bytes);
        TH_CHECK(st == (!finite_arg(v) ? SPH_ENONFINITE : v == V_BIG || v == V_MAX || v == V_NMAX ? SPH_EGRID : SPH_OK),
                 "x %s: %d", vname[v], st);
        st = sph_nsearch_workspace_size(3, xv, N, sph_view_none(), (sph_real)0.1, &box, &bytes);
        TH_CHECK(st == (finite_arg(v) ? SPH_OK : SPH_ENONFINITE), "x %s in a periodic box (wrapped): %d", vname[v], st);
        x[3 * 5 + 1] = (sph_real)0.5;
        h[3] = val[v];
        st = sph_nsearch_workspace_size(3, xv, N, sph_view_soa(h, NULL, NULL), (sph_real)0.1, NULL, &bytes);
        TH_CHECK(st == (sph_check_h(val[v]) == SPH_OK ? SPH_OK : SPH_EH), "h %s: %d", vname[v], st);
        h[3] = (sph_real)0.1;
        box.length[1] = val[v];
        st = sph_nsearch_workspace_size(3, xv, N, sph_view_none(), (sph_real)0.1, &box, &bytes);
        TH_CHECK(st == (!(val[v] > 0 && fin(val[v]) && fin(1 / val[v])) ? SPH_EBOXLEN
                        : val[v] / (sph_real)0.1 > (sph_real)SPH_NSEARCH_MAX_CELLS ? SPH_EGRID : SPH_OK),
                 "period %s: %d", vname[v], st);
        box.length[1] = 1;
        box.lo[2] = val[v];
        st = sph_nsearch_workspace_size(3, xv, N, sph_view_none(), (sph_real)0.1, &box, &bytes);
        TH_CHECK(st == (finite_arg(v) ? SPH_OK : SPH_EBOXLEN), "box lo %s: %d", vname[v], st);
        box.lo[2] = 0;
    }
    for (j = 0; j < 5; ++j) {
        const int n = bad_int[j] == 0 ? SPH_NSEARCH_MAX_SOURCES + 1 : bad_int[j] == 4 ? -7 : bad_int[j];
        TH_CHECK(sph_nsearch_workspace_size(bad_int[j], xv, N, sph_view_none(), 1, NULL, &bytes) == SPH_EDIM, "dim %d",
                 bad_int[j]);
        TH_CHECK(sph_nsearch_workspace_size(3, xv, n, sph_view_none(), 1, NULL, &bytes) == SPH_ECOUNT, "n %d", n);
    }
    TH_CHECK(sph_nsearch_workspace_size(3, xv, N, sph_view_none(), 1, NULL, NULL) == SPH_ENULL, "NULL bytes");
    TH_CHECK(sph_nsearch_workspace_size(3, xv, 1, sph_view_none(), val[V_DEN], NULL, &bytes) == SPH_EGRID,
             "a denormal cell over a single source (no extent, yet cells of width 1/0)");
    st = sph_nsearch_workspace_size(3, xv, N, sph_view_none(), (sph_real)0.1, &box, &bytes);
    TH_CHECK(st == SPH_OK && bytes <= sizeof work, "%d, %lu bytes", st, (unsigned long)bytes);
    TH_CHECK(sph_nsearch_build(NULL, 3, xv, N, sph_view_none(), (sph_real)0.1, &box, work, bytes) == SPH_ENULL &&
                 sph_nsearch_build(&g, 3, xv, N, sph_view_none(), (sph_real)0.1, &box, NULL, bytes) == SPH_ENULL &&
                 sph_nsearch_build(&g, 3, xv, N, sph_view_none(), (sph_real)0.1, &box, work, 0) == SPH_ESIZE,
             "NULL grid or work, no bytes");
    TH_CHECK(sph_nsearch_count(&g, xv, N, sph_view_none(), (sph_real)0.1, 2, 0, off) == SPH_ENOGRID &&
                 sph_nsearch_permutation(&g, perm) == SPH_ENOGRID,
             "a failed build is unusable");
    th_end();

    st = sph_nsearch_build(&g, 3, xv, N, sph_view_soa(h, NULL, NULL), (sph_real)0.1, &box, work, sizeof work);
    th_begin("search passes: h, kappa, one target coordinate and one target h over every value, bad modes and "
             "counts: a status with nothing written, or consistent lists");
    TH_CHECK(st == SPH_OK, "build %d", st);
    for (v = 0; v < NV; ++v) {
        int w;
        for (w = 0; w < 4; ++w) { /* uniform h, kappa, a target coordinate, a per-target h */
            sph_real hu = (sph_real)0.1, kap = 2;
            sph_view ht = sph_view_none();
            int want;
            if (w == 0) hu = val[v];
            if (w == 1) kap = val[v];
            if (w == 2) x[3 * 6] = val[v];
            if (w == 3) h[8] = val[v], ht = sph_view_soa(h, NULL, NULL);
            /* the unit periodic box takes R = kappa h <= 1/2 */
            want = w == 0 ? (sph_check_h(val[v]) != SPH_OK ? SPH_EH : 2 * val[v] > (sph_real)0.5 ? SPH_EPERIOD : SPH_OK)
                 : w == 1 ? (!(val[v] > 0 && fin(val[v])) ? SPH_ERANGE : val[v] * (sph_real)0.1 > (sph_real)0.5
                                                                        ? SPH_EPERIOD : SPH_OK)
                 : w == 2 ? (finite_arg(v) ? SPH_OK : SPH_ENONFINITE)
                          : (sph_check_h(val[v]) != SPH_OK ? SPH_EH : 2 * val[v] > (sph_real)0.5 ? SPH_EPERIOD : SPH_OK);
            for (i = 0; i <= N; ++i) off[i] = -7;
            st = sph_nsearch_count(&g, xv, N, ht, hu, kap, SPH_NSEARCH_GATHER, off);
            TH_CHECK(st == want, "pass %d value %s: count %d, want %d", w, vname[v], st, want);
            if (st == SPH_OK) {
                for (i = 0; i < N; ++i) TH_CHECK(off[i + 1] >= off[i] && off[i + 1] - off[i] <= N, "offsets");
                TH_CHECK(sph_nsearch_fill(&g, xv, N, ht, hu, kap, 0, off, idx, N * N) == SPH_OK, "fill");
                TH_CHECK(sph_nsearch_lists(&g, xv, N, ht, hu, kap, 0, off, idx, N * N, &pairs) == SPH_OK &&
                             pairs == off[N],
                         "lists");
                TH_CHECK(sph_nsearch_stats(&g, xv, N, ht, hu, kap, 0, &pairs, &cand, &fill) == SPH_OK && fin(fill) &&
                             fill > 0 && fill <= 1,
                         "stats, fill %g", (double)fill);
            } else {
                for (i = 0; i <= N && off[i] == -7; ++i) continue;
                TH_CHECK(i > N, "a refused count wrote offset[%d]", i);
                pairs = cand = -7, fill = -7;
                TH_CHECK(sph_nsearch_fill(&g, xv, N, ht, hu, kap, 0, off, idx, N * N) == st &&
                             sph_nsearch_lists(&g, xv, N, ht, hu, kap, 0, off, idx, N * N, &pairs) == st &&
                             sph_nsearch_stats(&g, xv, N, ht, hu, kap, 0, &pairs, &cand, &fill) == st && pairs == -7 &&
                             cand == -7 && fill == -7,
                         "fill, lists, stats agree with count (%d) and write nothing", st);
            }
            x[3 * 6] = (sph_real)0.5, h[8] = (sph_real)0.1;
        }
    }
    for (j = 0; j < 5; ++j) {
        TH_CHECK(sph_nsearch_count(&g, xv, N, sph_view_none(), (sph_real)0.1, 2, bad_int[j] == 0 ? 2 : bad_int[j],
                                   off) == SPH_EOPTION,
                 "mode %d", bad_int[j]);
        if (bad_int[j] < 0)
            TH_CHECK(sph_nsearch_count(&g, xv, bad_int[j], sph_view_none(), (sph_real)0.1, 2, 0, off) == SPH_ECOUNT &&
                         sph_nsearch_lists(&g, xv, bad_int[j], sph_view_none(), (sph_real)0.1, 2, 0, off, idx, N * N,
                                           &pairs) == SPH_ECOUNT,
                     "n_targets %d", bad_int[j]);
    }
    TH_CHECK(sph_nsearch_lists(&g, xv, N, sph_view_none(), (sph_real)0.1, 2, 0, off, idx, INT_MIN, &pairs) ==
                 SPH_ECOUNT,
             "capacity INT_MIN");
    TH_CHECK(sph_nsearch_list(NULL, 3, off, idx).n_sources == 0, "list of a NULL grid");
    th_end();

    th_begin("permutations over bad counts, NULL arrays and non-permutations: statuses, nothing written");
    TH_CHECK(sph_nsearch_permutation(NULL, perm) == SPH_ENULL && sph_nsearch_permutation(&g, NULL) == SPH_ENULL,
             "NULL grid or perm");
    TH_CHECK(sph_nsearch_permutation(&g, perm) == SPH_OK, "grid permutation");
    for (j = 0; j < 5; ++j)
        if (bad_int[j] < 0) {
            TH_CHECK(sph_permutation_invert(perm, bad_int[j], inv) == SPH_ECOUNT, "invert n %d", bad_int[j]);
            TH_CHECK(sph_permute(xv, 3, bad_int[j], perm, sph_out_interleaved(out, 3)) == SPH_ECOUNT, "permute n %d",
                     bad_int[j]);
        } else {
            TH_CHECK(sph_permute(xv, bad_int[j], N, perm, sph_out_interleaved(out, 3)) == SPH_ERANGE, "ncomp %d",
                     bad_int[j]);
        }
    for (i = 0; i < 3 * N; ++i) out[i] = SENT;
    perm[4] = N;
    TH_CHECK(sph_permutation_invert(perm, N, inv) == SPH_EINDEX, "entry n");
    TH_CHECK(sph_permute(xv, 3, N, perm, sph_out_interleaved(out, 3)) == SPH_EINDEX, "permute entry n");
    perm[4] = INT_MIN;
    TH_CHECK(sph_permute(xv, 3, N, perm, sph_out_interleaved(out, 3)) == SPH_EINDEX, "permute entry INT_MIN");
    for (i = 0; i < 3 * N && out[i] == SENT; ++i) continue;
    TH_CHECK(i == 3 * N, "a refused permute wrote out[%d]", i);
    TH_CHECK(sph_permutation_invert(NULL, N, inv) == SPH_ENULL &&
                 sph_permute(xv, 3, N, NULL, sph_out_interleaved(out, 3)) == SPH_ENULL,
             "NULL perm");
    th_end();
}

/* ---- section 8 ---- */

/* The switches (S13)-(S17) with one argument at a time over every value (the others moderate): (S13) in [0, 1]
 * for every combination, (S16) and (S17) within their bounds, (S15) finite, (S14) finite for finite arguments up
 * to half the largest sph_real; sph_switch_update's parameters over every value: SPH_ERANGE or SPH_OK. */
static void test_switches(void)
{
    const sph_switch s = sph_switch_default();
    int v, w, x, y, arg;
    th_begin("switches (S13)-(S17): every value of every argument gives a finite result within the bounds");
    for (v = 0; v < NV; ++v)
        for (w = 0; w < NV; ++w)
            for (x = 0; x < NV; ++x)
                for (y = 0; y < NV; ++y) {
                    const sph_real B = sph_switch_balsara(val[v], val[w], val[x], val[y]);
                    TH_CHECK(B >= 0 && B <= 1, "balsara(%s, %s, %s, %s) = %g", vname[v], vname[w], vname[x], vname[y],
                             (double)B);
                }
    for (arg = 0; arg < 8; ++arg)
        for (v = 0; v < NV; ++v) {
            sph_real q[8] = {(sph_real)0.5, (sph_real)-0.5, (sph_real)0.5, (sph_real)0.5,
                             (sph_real)0.5, (sph_real)0.5, (sph_real)0.5, (sph_real)0.5};
            sph_real a, d, r, p;
            q[arg] = val[v];
            a = sph_switch_sphenix(&s, q[0], q[1], q[2], q[3], q[4], q[5]);
            d = sph_switch_conductivity(&s, q[0], q[1], q[2], q[3], q[4], q[5], q[6]);
            r = sph_switch_mm97(&s, q[0], q[1], q[2], q[3]);
            p = sph_pair_av_alpha(q[0], q[1], q[2], q[3]);
            TH_CHECK(a >= s.alpha_min && a <= s.alpha_max, "sphenix argument %d = %s: %g", arg, vname[v], (double)a);
            TH_CHECK(d >= s.alpha_d_min && d <= s.alpha_d_max, "conductivity argument %d = %s: %g", arg, vname[v],
                     (double)d);
            TH_CHECK(fin(r), "mm97 argument %d = %s: %g", arg, vname[v], (double)r);
            TH_CHECK(!finite_arg(v) || v == V_MAX || v == V_NMAX || fin(p), "pair alpha argument %d = %s: %g", arg,
                     vname[v], (double)p);
        }
    TH_CHECK(sph_switch_sphenix(NULL, (sph_real)0.3, -1, -1, 1, 1, 1) == (sph_real)0.3 &&
                 sph_switch_conductivity(NULL, (sph_real)0.3, 1, 1, 1, 1, 0, 1) == (sph_real)0.3 &&
                 sph_switch_mm97(NULL, 1, -1, 1, 1) == 0,
             "NULL parameters");
    th_end();

    th_begin("sph_switch_update: each parameter, dt and kappa over every value, bad counts: SPH_ERANGE / SPH_ECOUNT "
             "with nothing written, or SPH_OK");
    {
        sph_real dv[3] = {-1, 0, 2}, cc = 1, hh = (sph_real)0.1, al[3] = {1, 1, 1}, prev[3] = {0, 0, 0};
        sph_switch_input in = sph_switch_input_init(2);
        const sph_out ao = sph_out_soa(al, NULL, NULL), po = sph_out_soa(prev, NULL, NULL);
        in.dt = (sph_real)0.01;
        in.div_v = sph_view_soa(dv, NULL, NULL), in.c = sph_view_aos(&cc, 1, 0), in.h = sph_view_aos(&hh, 1, 0);
        for (arg = 0; arg < 8; ++arg)
            for (v = 0; v < NV; ++v) {
                sph_switch_input e = in;
                sph_real *f[8] = {&e.par.alpha_min, &e.par.alpha_max, &e.par.length, &e.par.alpha_d_min,
                                  &e.par.alpha_d_max, &e.par.beta_d, &e.dt, &e.kappa};
                int st, ok;
                *f[arg] = val[v];
                ok = val[v] >= 0 && fin(val[v]) && (arg != 7 || val[v] > 0) && e.par.alpha_min <= e.par.alpha_max &&
                     e.par.alpha_d_min <= e.par.alpha_d_max;
                al[0] = al[1] = al[2] = 1, prev[0] = prev[1] = prev[2] = 7;
                st = sph_switch_update(&e, 3, ao, po, sph_out_soa(NULL, NULL, NULL), sph_out_soa(NULL, NULL, NULL));
                TH_CHECK(ok ? st == SPH_OK : st == SPH_ERANGE && prev[0] == 7, "parameter %d = %s: status %d", arg,
                         vname[v], st);
                TH_CHECK(fin(al[0]) && fin(al[1]) && fin(al[2]), "parameter %d = %s: alpha not finite", arg, vname[v]);
            }
        for (v = 0; v < 3; ++v) /* INT_MIN, -1, 0 (the arrays hold 3) */
            TH_CHECK(sph_switch_update(&in, bad_int[v], ao, po, sph_out_soa(NULL, NULL, NULL),
                                       sph_out_soa(NULL, NULL, NULL)) == (bad_int[v] < 0 ? SPH_ECOUNT : SPH_OK),
                     "n %d", bad_int[v]);
    }
    th_end();
}

int main(void)
{
    vals_init();
    test_strerror();
    test_kernel_args();
    test_scalar_kernels();
    test_box_and_views();
    test_pair_kernel();
    test_pair_terms();
    test_pressure_harmonic();
    test_correction_invert();
    test_operators();
    test_search();
    test_switches();
    return th_summary();
}
