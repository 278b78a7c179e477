/* Operators: bad input gets its status code before any output is written;
 * degenerate neighbourhoods fall back to B = I (the difference scheme),
 * are counted, and never produce NaN.
 */
#include "op_scene.h"

#define SENTINEL ((sph_real)12345)

/* A small valid 2-D scene with a scalar field and a sentinel-filled output. */
typedef struct {
    ts_scene s;
    sph_real *f, *g[3], *rho;
} base;

static void base_make(base *b)
{
    int i, a;
    ts_lattice(&b->s, SPH_KERNEL_CUBIC, 2, 6, 1.0 / 6, 1.3, 0.2, 1, NULL);
    b->f = ts_vec(b->s.n), b->rho = ts_vec(b->s.n);
    for (a = 0; a < 3; ++a) b->g[a] = ts_vec(b->s.n);
    for (i = 0; i < b->s.n; ++i) {
        b->f[i] = (sph_real)ts_linear(b->s.x + 3 * i);
        b->rho[i] = 1;
        for (a = 0; a < 3; ++a) b->g[a][i] = SENTINEL;
    }
    b->s.c.m = b->s.c.V;
    b->s.c.rho = sph_view_soa(b->rho, NULL, NULL);
}

static void base_free(base *b)
{
    int a;
    free(b->f), free(b->rho);
    for (a = 0; a < 3; ++a) free(b->g[a]);
    ts_free(&b->s);
}

/* Runs the corrected gradient with context c; checks the status and that
 * the output and the fallback count were not touched on error. */
static void expect(base *b, const sph_ctx *c, sph_scheme sc, int want, const char *what)
{
    sph_idx nfb = -7;
    int i, a;
    const int st = sph_gradient(c, sc, sph_view_soa(b->f, NULL, NULL), sph_view_none(),
                                sph_out_soa(b->g[0], b->g[1], b->g[2]), &nfb);
    TH_CHECK(st == want, "%s: status %d (%s), expected %d", what, st, sph_strerror(st), want);
    if (want == SPH_OK) return;
    TH_CHECK(nfb == -7, "%s: count written on error", what);
    for (i = 0; i < b->s.n; ++i)
        for (a = 0; a < 3; ++a) TH_CHECK(b->g[a][i] == SENTINEL, "%s: output written on error", what);
}

static void test_status_codes(void)
{
    base b;
    sph_ctx c;
    sph_neighbours L;
    sph_off *off;
    sph_idx *idx;
    sph_box box;
    sph_real *hh, keep;
    int i, a;
    th_begin("every bad input gets its status code and leaves the outputs alone");
    base_make(&b);
    off = (sph_off *)malloc(sizeof(sph_off) * (size_t)(b.s.n + 1));
    idx = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)b.s.L.list.offset[b.s.n]);
    memcpy(off, b.s.L.list.offset, sizeof(sph_off) * (size_t)(b.s.n + 1));
    memcpy(idx, b.s.L.list.index, sizeof(sph_idx) * (size_t)off[b.s.n]);
    L = b.s.L.list;
    L.offset = off;
    L.index = idx;
    c = b.s.c;
    c.list = &L;
    expect(&b, NULL, SPH_SCHEME_CORRECTED, SPH_ENULL, "NULL context");
    c.list = NULL, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_ENULL, "NULL list"), c.list = &L;
    c.kernel = (sph_kernel)99, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EKERNEL, "kernel 99"), c.kernel = SPH_KERNEL_CUBIC;
    c.dim = 0, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EDIM, "dim 0");
    c.dim = 4, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EDIM, "dim 4"), c.dim = 2;
    c.h = 0, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EH, "h = 0");
    c.h = -1, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EH, "h < 0");
    c.h = (sph_real)NAN, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EH, "h NaN");
    c.h = (sph_real)INFINITY, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EH, "h inf"), c.h = (sph_real)b.s.h;
    hh = ts_vec(b.s.n);
    for (i = 0; i < b.s.n; ++i) hh[i] = (sph_real)b.s.h;
    hh[5] = 0;
    c.h_source = sph_view_soa(hh, NULL, NULL);
    expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EH, "one per-particle h = 0");
    c.h_source = sph_view_none();
    idx[3] = (sph_idx)b.s.n, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EINDEX, "index = n_sources");
    idx[3] = -1, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EINDEX, "index = -1");
    idx[3] = b.s.L.list.index[3];
    off[4] = off[3] - 1, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EOFFSET, "decreasing offsets");
    off[4] = b.s.L.list.offset[4];
    off[0] = 1, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EOFFSET, "offset[0] != 0"), off[0] = 0;
    L.n_targets = -1, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_ECOUNT, "n_targets < 0"), L.n_targets = (sph_idx)b.s.n;
    /* targets are the sources: n_sources below n_targets is refused on the counts alone, before
       the list is read (tests/test_bad_input.c checks that no offset beyond them is read) */
    L.n_sources = (sph_idx)b.s.n - 1;
    expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_ECOUNT, "n_sources below n_targets without x_target");
    L.n_sources = (sph_idx)b.s.n;
    L.index = NULL, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_ENULL, "index NULL"), L.index = idx;
    c.x.p[1] = NULL, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_ENULL, "y positions NULL"), c.x = b.s.c.x;
    c.x.stride = 0, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_ESTRIDE, "stride 0"), c.x = b.s.c.x;
    c.V = sph_view_none(), expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_ENULL, "no volumes"), c.V = b.s.c.V;
    keep = b.s.x[3 * 7 + 1];
    b.s.x[3 * 7 + 1] = (sph_real)NAN, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_ENONFINITE, "NaN position");
    b.s.x[3 * 7 + 1] = keep;
    keep = b.f[9];
    b.f[9] = (sph_real)INFINITY, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_ENONFINITE, "Inf in the field");
    b.f[9] = keep;
    b.rho[2] = 0, expect(&b, &c, SPH_SCHEME_PRESSURE, SPH_EVALUE, "density 0 in the pressure form"), b.rho[2] = 1;
    expect(&b, &c, (sph_scheme)17, SPH_EOPTION, "unknown scheme");
    c.rcond_min = 2, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_ERANGE, "rcond_min 2"), c.rcond_min = (sph_real)1e-3;
    for (a = 0; a < 3; ++a) box.lo[a] = 0, box.length[a] = 0, box.periodic[a] = 1;
    c.box = &box, expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_EBOXLEN, "periodic axis of length 0"), c.box = NULL;
    /* other operators' own checks */
    TH_CHECK(sph_curl(&c, SPH_SCHEME_CORRECTED, sph_view_interleaved(b.s.x, 3), sph_view_none(),
                      sph_out_soa(b.g[0], NULL, NULL)) == SPH_EOPTION, "curl has no corrected form");
    TH_CHECK(sph_gradient_vector(&c, SPH_SCHEME_STANDARD, sph_view_interleaved(b.s.x, 3), sph_view_none(), b.g[0], 3,
                                 NULL) == SPH_ESTRIDE, "tensor stride < dim^2");
    TH_CHECK(sph_density(&c, sph_out_soa(NULL, NULL, NULL)) == SPH_ENULL, "density output NULL");
    c.m = sph_view_none();
    TH_CHECK(sph_density(&c, sph_out_soa(b.g[0], NULL, NULL)) == SPH_ENULL, "density without masses");
    for (i = 0; i < b.s.n; ++i) TH_CHECK(b.g[0][i] == SENTINEL, "output written on error");
    /* the list check alone, and the skipped re-validation on a checked list */
    TH_CHECK(sph_neighbours_check(&L) == SPH_OK, "valid list");
    TH_CHECK(sph_neighbours_check(NULL) == SPH_ENULL, "NULL list");
    c = b.s.c;
    c.validate = SPH_VALIDATE_ARGS;
    expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_OK, "validated list, arguments only");
    expect(&b, &c, SPH_SCHEME_CORRECTED, SPH_OK, "validated list, arguments only");
    for (i = 0; i < 9; ++i) TH_CHECK(sph_strerror(-i)[0] != '\0', "strerror %d", -i);
    free(hh), free(off), free(idx);
    base_free(&b);
    th_end();
}

/* Corrected gradient of the linear field on cloud x (count n, dim d, h), all
 * targets; returns the fallback count, checks NaN-freedom and that fallen
 * back targets carry the difference-scheme value bitwise. */
static sph_idx fallback_run(int d, int n, sph_real *x, double h, sph_real rcond)
{
    sph_real *f = ts_vec(n), *V = ts_vec(n), *dv = ts_vec(n), *g[3], *gd[3];
    tp_list L;
    sph_ctx c;
    sph_idx nfb = -1, nfb_div = -1;
    int i, a, st;
    for (a = 0; a < 3; ++a) g[a] = ts_vec(n), gd[a] = ts_vec(n);
    for (i = 0; i < n; ++i) f[i] = (sph_real)ts_linear(x + 3 * i), V[i] = (sph_real)pow(h / 1.3, d);
    tp_brute_list(d, x, n, x, n, (sph_real)h, NULL, NULL, 2, TP_GATHER, NULL, &L);
    c = sph_ctx_init(SPH_KERNEL_CUBIC, d, (sph_real)h, &L.list, sph_view_interleaved(x, 3));
    c.V = sph_view_soa(V, NULL, NULL);
    c.rcond_min = rcond;
    st = sph_gradient(&c, SPH_SCHEME_CORRECTED, sph_view_soa(f, NULL, NULL), sph_view_none(),
                      sph_out_soa(g[0], g[1], g[2]), &nfb);
    st |= sph_gradient(&c, SPH_SCHEME_DIFFERENCE, sph_view_soa(f, NULL, NULL), sph_view_none(),
                       sph_out_soa(gd[0], gd[1], gd[2]), NULL);
    st |= sph_divergence(&c, SPH_SCHEME_CORRECTED, sph_view_interleaved(x, 3), sph_view_none(),
                         sph_out_soa(dv, NULL, NULL), &nfb_div);
    TH_CHECK(st == SPH_OK && nfb == nfb_div, "status %d, fallbacks %d / %d", st, (int)nfb, (int)nfb_div);
    for (i = 0; i < n; ++i) {
        for (a = 0; a < d; ++a) TH_CHECK(g[a][i] - g[a][i] == 0, "non-finite gradient at %d", i);
        TH_CHECK(dv[i] - dv[i] == 0, "non-finite divergence at %d", i);
    }
    if (nfb == n)
        for (i = 0; i < n; ++i)
            for (a = 0; a < d; ++a) TH_CHECK(g[a][i] == gd[a][i], "fallback is not the difference scheme at %d", i);
    free(f), free(V), free(dv);
    for (a = 0; a < 3; ++a) free(g[a]), free(gd[a]);
    tp_free_list(&L);
    return nfb;
}

static void test_fallbacks(void)
{
    sph_real x[3 * 64];
    int i, j;
    sph_idx n;
    th_begin("correction-matrix fallbacks: collinear 2D, coplanar 3D, too few neighbours");
    for (i = 0; i < 10; ++i) x[3 * i] = (sph_real)(0.1 * i), x[3 * i + 1] = (sph_real)(0.03 * i), x[3 * i + 2] = 0;
    n = fallback_run(2, 10, x, 0.13, (sph_real)1e-3);
    TH_CHECK(n == 10, "collinear 2D: %d of 10 fell back", (int)n);
    for (i = 0; i < 8; ++i)
        for (j = 0; j < 8; ++j) {
            const int k = 8 * i + j;
            x[3 * k] = (sph_real)(0.1 * i), x[3 * k + 1] = (sph_real)(0.1 * j), x[3 * k + 2] = (sph_real)(0.02 * i - 0.01 * j);
        }
    n = fallback_run(3, 64, x, 0.13, (sph_real)1e-3);
    TH_CHECK(n == 64, "coplanar 3D: %d of 64 fell back", (int)n);
    x[0] = 0, x[1] = 0, x[2] = 0, x[3] = (sph_real)0.1, x[4] = (sph_real)0.05, x[5] = (sph_real)0.02;
    n = fallback_run(3, 2, x, 0.13, (sph_real)1e-3);
    TH_CHECK(n == 2, "two particles in 3D (one neighbour each): %d of 2 fell back", (int)n);
    x[0] = 0, x[3] = 5; /* 1-D: two particles out of each other's reach: only the self term */
    n = fallback_run(1, 2, x, 0.13, (sph_real)1e-3);
    TH_CHECK(n == 2, "isolated 1D particles: %d of 2 fell back", (int)n);
    th_end();

    th_begin("free-surface corner of a lattice block is well conditioned (no fallback, exact)");
    {
        ts_scene s;
        sph_real *f, *g[3];
        sph_idx nfb = -1;
        int a, st;
        ts_lattice(&s, SPH_KERNEL_CUBIC, 2, 8, 0.1, 1.3, 0, 1, NULL);
        f = ts_vec(s.n);
        for (a = 0; a < 3; ++a) g[a] = ts_vec(s.n);
        for (i = 0; i < s.n; ++i) f[i] = (sph_real)ts_linear(s.x + 3 * i);
        st = sph_gradient(&s.c, SPH_SCHEME_CORRECTED, sph_view_soa(f, NULL, NULL), sph_view_none(),
                          sph_out_soa(g[0], g[1], g[2]), &nfb);
        TH_CHECK(st == SPH_OK && nfb == 0, "status %d, %d fallbacks", st, (int)nfb);
        TH_NEAR(g[0][0], ts_ga(0), TH_IS_FLOAT ? 1e-4 : 1e-12); /* particle 0 is the corner */
        TH_NEAR(g[1][0], ts_ga(1), TH_IS_FLOAT ? 1e-4 : 1e-12);
        /* the threshold is settable: demanding rcond >= 0.9 rejects the corner */
        n = fallback_run(2, s.n, s.x, s.h, (sph_real)0.9);
        TH_CHECK(n > 0 && n < s.n, "rcond_min 0.9: %d of %d fell back", (int)n, s.n);
        free(f);
        for (a = 0; a < 3; ++a) free(g[a]);
        ts_free(&s);
    }
    th_end();

    th_begin("sph_correction_invert: scale-free test, identity fallback, no division by ~0");
    {
        sph_real M[9] = {0}, B[9];
        M[0] = M[4] = M[8] = (sph_real)1e8; /* well conditioned at any scale */
        TH_CHECK(sph_correction_invert(3, M, (sph_real)1e-3, B) == 1, "diag 1e8");
        TH_REL(B[0], 1e-8, 4 * TH_EPS);
        M[0] = M[4] = M[8] = (sph_real)1e-8;
        TH_CHECK(sph_correction_invert(3, M, (sph_real)1e-3, B) == 1, "diag 1e-8");
        M[4] = (sph_real)1e-20; /* rcond 1e-12 */
        TH_CHECK(sph_correction_invert(3, M, (sph_real)1e-3, B) == 0 && B[0] == 1 && B[4] == 1 && B[8] == 1 && B[1] == 0,
                 "near-singular -> identity");
        M[4] = (sph_real)NAN;
        TH_CHECK(sph_correction_invert(3, M, (sph_real)1e-3, B) == 0 && B[4] == 1, "NaN -> identity");
        for (i = 0; i < 9; ++i) M[i] = 0;
        TH_CHECK(sph_correction_invert(2, M, 0, B) == 0 && B[0] == 1 && B[8] == 0, "zero matrix, rcond_min 0");
        M[0] = 2, M[1] = 1, M[3] = 1, M[4] = 2; /* 2-D inverse: (1/3) [2 -1; -1 2] */
        TH_CHECK(sph_correction_invert(2, M, (sph_real)1e-3, B) == 1, "2x2");
        TH_NEAR(B[0], 2.0 / 3, 4 * TH_EPS);
        TH_NEAR(B[1], -1.0 / 3, 4 * TH_EPS);
    }
    th_end();
}

int main(void)
{
    test_status_codes();
    test_fallbacks();
    return th_summary();
}
