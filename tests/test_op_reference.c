/* The fast loops (default, ctx.loops = SPH_LOOPS_FAST) against the plain
 * reference loops (SPH_LOOPS_REFERENCE), every operator and scheme, every
 * kernel in 1, 2 and 3 D, with uniform h, per-particle h and a periodic box
 * whose particles sit up to 3 periods outside it.
 *
 * Both evaluate the same pair arithmetic (sph__pair) and sum over j in list
 * order, so where nothing reorders the sums (no OpenMP, no AVX-512 or AVX2
 * one-pass loop: sph_isa) and the unit does not fuse the header's a * b + c (sph__fp_contracted:
 * gcc's GNU modes on an FMA target) they must agree bit for bit; with OpenMP
 * SIMD reductions, the one-pass loops (FMA, a different order) or contraction
 * they agree to round-off: 1e-12 (double) / 1e-4 (float) of the largest
 * |value| of the operator's output.
 */
#include "op_scene.h"

#if defined(_OPENMP)
#define TR_BITWISE 0
#else
#define TR_BITWISE 1
#endif

enum { TR_OUT = 34 }; /* output values per particle (the 3x3 tensors go to T) */

static sph_real (*tr_out)[TR_OUT];

/* Components off..off+ncomp-1 of every particle's row of tr_out. */
static sph_out tr_o(int off, int ncomp) { return sph_out_aos(&tr_out[0][0] + off, ncomp, sizeof tr_out[0]); }

/* Every vector and scalar operator with ctx.loops = loops into out. */
static int run_every_operator(sph_ctx *c, int dim, int loops, const sph_real *f, const sph_real *v, const sph_real *kk,
                   sph_real (*out)[TR_OUT])
{
    const sph_view fv = sph_view_soa(f, NULL, NULL), vv = sph_view_interleaved(v, 3), kv = sph_view_soa(kk, NULL, NULL);
    const sph_view none = sph_view_none();
    int st = 0;
    tr_out = out;
    c->loops = loops;
    st |= sph_density(c, tr_o(0, 1));
    st |= sph_interpolate(c, fv, tr_o(1, 1));
    st |= sph_interpolate_shepard(c, fv, tr_o(2, 1), NULL);
    st |= sph_gradient(c, SPH_SCHEME_STANDARD, fv, none, tr_o(3, dim), NULL);
    st |= sph_gradient(c, SPH_SCHEME_DIFFERENCE, fv, none, tr_o(6, dim), NULL);
    st |= sph_gradient(c, SPH_SCHEME_SYMMETRIC, fv, none, tr_o(9, dim), NULL);
    st |= sph_gradient(c, SPH_SCHEME_CORRECTED, fv, none, tr_o(12, dim), NULL);
    st |= sph_gradient(c, SPH_SCHEME_PRESSURE, fv, none, tr_o(15, dim), NULL);
    st |= sph_density_gradient(c, fv, none, tr_o(18, 1), tr_o(19, dim));
    st |= sph_divergence(c, SPH_SCHEME_STANDARD, vv, none, tr_o(22, 1), NULL);
    st |= sph_divergence(c, SPH_SCHEME_DIFFERENCE, vv, none, tr_o(23, 1), NULL);
    st |= sph_divergence(c, SPH_SCHEME_CORRECTED, vv, none, tr_o(24, 1), NULL);
    if (dim > 1) {
        st |= sph_curl(c, SPH_SCHEME_STANDARD, vv, none, tr_o(25, dim == 2 ? 1 : 3));
        st |= sph_curl(c, SPH_SCHEME_DIFFERENCE, vv, none, tr_o(28, dim == 2 ? 1 : 3));
    }
    st |= sph_laplacian(c, fv, none, tr_o(31, 1));
    st |= sph_diffusion(c, kv, none, fv, none, tr_o(32, 1));
    return st;
}

/* The tensor operators into T[9 * i ..] (four schemes and B). */
static int run_tensors(sph_ctx *c, int loops, const sph_real *v, sph_real *T)
{
    const sph_view vv = sph_view_interleaved(v, 3);
    const ptrdiff_t s = 5 * 9;
    int st = 0;
    c->loops = loops;
    st |= sph_gradient_vector(c, SPH_SCHEME_STANDARD, vv, sph_view_none(), T, s, NULL);
    st |= sph_gradient_vector(c, SPH_SCHEME_DIFFERENCE, vv, sph_view_none(), T + 9, s, NULL);
    st |= sph_gradient_vector(c, SPH_SCHEME_SYMMETRIC, vv, sph_view_none(), T + 18, s, NULL);
    st |= sph_gradient_vector(c, SPH_SCHEME_CORRECTED, vv, sph_view_none(), T + 27, s, NULL);
    st |= sph_correction_matrix(c, T + 36, s, NULL);
    return st;
}

static void check_twins(sph_kernel k, int dim, int mode)
{
    ts_scene s;
    sph_box box;
    sph_real *f, *v, *kk, *hh, *rho, *T1, *T2, (*o1)[TR_OUT], (*o2)[TR_OUT];
    int i, a, e, st;
    const int bitwise = TR_BITWISE && sph_isa() == SPH_ISA_PORTABLE && !sph__fp_contracted();
    const double tol = bitwise ? 0 : TH_IS_FLOAT ? 1e-4 : 1e-12;
    double big[TR_OUT], bigT = 0;
    for (a = 0; a < 3; ++a) box.lo[a] = 0, box.length[a] = 1, box.periodic[a] = 1;
    th_begin("fast = reference loops%s: %s %dD %s", bitwise ? " (bitwise)" : "", sph_kernel_name(k), dim,
             mode == 0 ? "uniform h" : mode == 1 ? "per-particle h" : "periodic, shifted");
    ts_lattice(&s, k, dim, dim == 1 ? 24 : dim == 2 ? 9 : 5, dim == 1 ? 1.0 / 24 : dim == 2 ? 1.0 / 9 : 0.2, 1.4,
               0.3, 11 + (uint64_t)mode, mode == 2 ? &box : NULL);
    for (i = 0; mode == 2 && i < s.n; ++i) /* the list holds minimum images: it stays valid */
        for (a = 0; a < dim; ++a) s.x[3 * i + a] += (sph_real)((i * 5 + a) % 7 - 3);
    f = ts_vec(s.n), v = ts_vec(3 * s.n), kk = ts_vec(s.n), hh = ts_vec(s.n), rho = ts_vec(s.n);
    o1 = (sph_real(*)[TR_OUT])calloc((size_t)s.n, sizeof *o1), o2 = (sph_real(*)[TR_OUT])calloc((size_t)s.n, sizeof *o2);
    T1 = ts_vec(45 * s.n), T2 = ts_vec(45 * s.n);
    for (i = 0; i < s.n; ++i) {
        const sph_real *x = s.x + 3 * i;
        f[i] = (sph_real)(sin(2 * TS_PI * x[0]) + 0.5 * x[dim - 1] * x[0]);
        for (a = 0; a < 3; ++a) v[3 * i + a] = (sph_real)(ts_vlinear(x, a) + 0.3 * sin(3.0 * x[a] + a));
        kk[i] = (sph_real)(1 + 0.5 * sin(4.0 * x[0]));
        hh[i] = (sph_real)(s.h * (1 + 0.1 * ((i * 7) % 3 - 1)));
        rho[i] = (sph_real)(1000 * (1 + 0.05 * cos(5.0 * x[0])));
    }
    if (mode == 1) { /* per-particle h: the symmetric list (max(h_i, h_j)) */
        tp_free_list(&s.L);
        tp_brute_list(dim, s.x, s.n, s.x, s.n, 0, hh, hh, sph_kernel_support(k), TP_SYMMETRIC, NULL, &s.L);
        s.c.list = &s.L.list;
        s.c.h_source = sph_view_soa(hh, NULL, NULL);
    }
    s.c.m = s.c.V;
    s.c.rho = sph_view_soa(rho, NULL, NULL);
    st = run_every_operator(&s.c, dim, SPH_LOOPS_FAST, f, v, kk, o1);
    st |= run_every_operator(&s.c, dim, SPH_LOOPS_REFERENCE, f, v, kk, o2);
    st |= run_tensors(&s.c, SPH_LOOPS_FAST, v, T1);
    st |= run_tensors(&s.c, SPH_LOOPS_REFERENCE, v, T2);
    TH_CHECK(st == SPH_OK, "status %d", st);
    for (e = 0; e < TR_OUT; ++e)
        for (big[e] = 0, i = 0; i < s.n; ++i) big[e] = fabs((double)o2[i][e]) > big[e] ? fabs((double)o2[i][e]) : big[e];
    for (i = 0; i < 45 * s.n; ++i) bigT = fabs((double)T2[i]) > bigT ? fabs((double)T2[i]) : bigT;
    for (i = 0; i < s.n; ++i) {
        for (e = 0; e < TR_OUT; ++e) TH_CLOSE(o1[i][e], o2[i][e], tol * big[e]);
        for (e = 0; e < 45; ++e) TH_CLOSE(T1[45 * i + e], T2[45 * i + e], tol * bigT);
    }
    free(f), free(v), free(kk), free(hh), free(rho), free(o1), free(o2), free(T1), free(T2);
    ts_free(&s);
    th_end();
}

/* Where the header promises its arithmetic uncontracted (docs/testing.md,
 * "Floating-point contraction"), sph__fp_contracted() must say so, so that
 * the cases above assert bit for bit: under clang unless SPH_FP_CONTRACT
 * (the header's #pragma STDC FP_CONTRACT OFF), and under gcc in an ISO mode
 * (-std=c99 and later imply -ffp-contract=off). */
static void check_contraction_promise(void)
{
#if defined(__clang__) && !defined(SPH_FP_CONTRACT)
    const char *why = "clang: the header's pragma";
    const int promised = 1;
#elif defined(__GNUC__) && !defined(__clang__) && defined(__STRICT_ANSI__)
    const char *why = "gcc -std=c..";
    const int promised = 1;
#else
    const char *why = "no promise in this build";
    const int promised = 0;
#endif
    th_begin("the header's a * b + c uncontracted where promised (%s): %s", why,
             sph__fp_contracted() ? "contracted" : "not contracted");
    TH_CHECK(!promised || !sph__fp_contracted(), "%s promises no contraction, and the probe found one", why);
    th_end();
}

int main(void)
{
    int k, dim, mode;
    check_contraction_promise();
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim)
            for (mode = 0; mode < 3; ++mode) check_twins((sph_kernel)k, dim, mode);
    th_begin("an unknown ctx.loops is SPH_EOPTION");
    {
        ts_scene s;
        sph_real rho[64];
        ts_lattice(&s, SPH_KERNEL_CUBIC, 2, 4, 0.25, 1.3, 0, 1, NULL);
        s.c.m = s.c.V;
        s.c.loops = 2;
        TH_CHECK(sph_density(&s.c, sph_out_soa(rho, NULL, NULL)) == SPH_EOPTION, "loops = 2 accepted");
        ts_free(&s);
    }
    return th_summary();
}
