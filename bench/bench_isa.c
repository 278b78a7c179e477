/* bench/bench_isa.c - the fast loops at every instruction-set level this
 * build and CPU have (sph_isa_set: portable, avx2, avx512), timed in one
 * run, and the ratio of each level's time to the widest's. Run by hand:
 *
 *   make bench-isa       (-O2 without -march: double and float; the levels
 *                         of the run-time dispatch, section 1 of the header)
 *   build/bench/isa_double [side] [repetitions]
 *
 * Scene: 3-D, side^3 particles (default 48^3) on a lattice perturbed by
 * +-10 % dx in the periodic unit box, sorted by cell, h such that the cubic
 * spline has ~60 neighbours (the other kernels: the same kappa h, the same
 * list). One thread. Operations, each per list entry (pair, self included):
 *   search     sph_nsearch_build + sph_nsearch_lists (gather, uniform h)
 *   fused K    sph_density_gradient (density and difference gradient in one
 *              pass) with kernel K, uniform h
 *   batch      sph_batch_fill over every row, W and F at h_i and h_j
 *              (per-particle h 0.9..1 h), the lanes summed
 *   h solve    sph_h_solve from h_i = h at eta 1.1, per pair of its sums
 * and, for what the CPU itself allows, "multiply-add peak": 8 independent
 * chains of a * b + c in the level's registers (SSE2 mul and add, AVX2 FMA,
 * AVX-512 FMA), the same number of double operations at every level, per
 * 64 of them: a loop bound by arithmetic alone can gain at most this ratio
 * from the wider level (about 2 where 512-bit vectors run at full width, 1
 * where they run as two 256-bit halves).
 * Each repetition runs every operation at every level in turn; a time is the
 * median over the repetitions and a ratio the median of the ratios within a
 * repetition (load that comes and goes lands on all levels alike). */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sph_kernel.h"
#include "support/particles.h"
#if !defined(__SSE2__) || !defined(__x86_64__)
#error "bench/bench_isa.c: the levels are those of x86-64 (SSE2, AVX2, AVX-512)"
#endif
#include <immintrin.h>
#include "support/timing.h"

enum { BI_PEAK, BI_SEARCH, BI_BATCH, BI_HSOLVE, BI_FUSED0, BI_OPS = BI_FUSED0 + SPH_KERNEL_COUNT };
enum { BI_LEVELS = SPH_ISA_AVX512 + 1, BI_MAX_REPS = 64 };

typedef struct {
    int n;
    sph_real h, *x, *m, *f, *hv, *rho, *g, *om, *hs, *lanes;
    sph_box box;
    sph_off *off, cap;
    sph_idx *idx;
    size_t ws_bytes;
    void *work;
    sph_neighbours list;
} bi_scene;

static int bi_status = SPH_OK;
static void bi_chk(int st)
{
    if (st != SPH_OK && bi_status == SPH_OK) bi_status = st;
}

static sph_view bi_x(const bi_scene *s) { return sph_view_interleaved(s->x, 3); }

/* The neighbour lists of the scene at kappa h (cells kappa h / 2). */
static void bi_search(bi_scene *s)
{
    const sph_real kappa = sph_kernel_support(SPH_KERNEL_CUBIC);
    sph_nsearch g;
    sph_off pairs;
    bi_chk(sph_nsearch_build(&g, 3, bi_x(s), s->n, sph_view_none(), kappa * s->h / 2, &s->box, s->work, s->ws_bytes));
    bi_chk(sph_nsearch_lists(&g, bi_x(s), s->n, sph_view_none(), s->h, kappa, SPH_NSEARCH_GATHER, s->off, s->idx, s->cap,
                             &pairs));
    s->list = sph_nsearch_list(&g, s->n, s->off, s->idx);
}

static void bi_scene_init(bi_scene *s, int side)
{
    const sph_real kappa = sph_kernel_support(SPH_KERNEL_CUBIC);
    const double dx = 1.0 / side;
    sph_real *tmp;
    sph_idx *perm;
    sph_nsearch g;
    tp_rng r = {12345u};
    int i;
    s->n = side * side * side;
    s->h = sph_kernel_h_for_neighbours(SPH_KERNEL_CUBIC, 3, 60, (sph_real)(dx * dx * dx));
    for (i = 0; i < 3; ++i) s->box.lo[i] = 0, s->box.length[i] = 1, s->box.periodic[i] = 1;
    tmp = (sph_real *)malloc(sizeof(sph_real) * 3 * (size_t)s->n);
    s->x = (sph_real *)malloc(sizeof(sph_real) * 3 * (size_t)s->n);
    s->g = (sph_real *)malloc(sizeof(sph_real) * 3 * (size_t)s->n);
    s->m = (sph_real *)malloc(sizeof(sph_real) * (size_t)s->n);
    s->f = (sph_real *)malloc(sizeof(sph_real) * (size_t)s->n);
    s->hv = (sph_real *)malloc(sizeof(sph_real) * (size_t)s->n);
    s->rho = (sph_real *)malloc(sizeof(sph_real) * (size_t)s->n);
    s->om = (sph_real *)malloc(sizeof(sph_real) * (size_t)s->n);
    s->hs = (sph_real *)malloc(sizeof(sph_real) * (size_t)s->n);
    s->lanes = (sph_real *)calloc(SPH_BATCH, sizeof(sph_real));
    s->off = (sph_off *)malloc(sizeof(sph_off) * ((size_t)s->n + 1));
    perm = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)s->n);
    s->cap = (sph_off)s->n * 80; /* ~20 % above the ~66 entries per particle */
    s->idx = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)s->cap);
    if (!tmp || !s->x || !s->g || !s->m || !s->f || !s->hv || !s->rho || !s->om || !s->hs || !s->lanes || !s->off ||
        !perm || !s->idx) {
        fprintf(stderr, "bench_isa: out of memory for %d particles\n", s->n);
        exit(1);
    }
    tp_lattice(3, side, dx, tmp);
    tp_perturb(3, s->n, 0.1 * dx, &r, tmp);
    bi_chk(sph_nsearch_workspace_size(3, sph_view_interleaved(tmp, 3), s->n, sph_view_none(), kappa * s->h / 2, &s->box,
                                      &s->ws_bytes));
    s->work = malloc(s->ws_bytes);
    if (s->work == NULL) exit(1);
    bi_chk(sph_nsearch_build(&g, 3, sph_view_interleaved(tmp, 3), s->n, sph_view_none(), kappa * s->h / 2, &s->box,
                             s->work, s->ws_bytes));
    bi_chk(sph_nsearch_permutation(&g, perm));
    bi_chk(sph_permute(sph_view_interleaved(tmp, 3), 3, s->n, perm, sph_out_interleaved(s->x, 3)));
    for (i = 0; i < s->n; ++i) {
        s->m[i] = (sph_real)(dx * dx * dx);
        s->f[i] = (sph_real)tp_range(&r, -1, 1);
        s->hv[i] = s->h * (sph_real)tp_range(&r, 0.9, 1.0);
    }
    free(tmp);
    free(perm);
    bi_search(s);
}

/* ---- multiply-add peak: 8 chains of v = v * a + b, BI_FLOPS double multiply-adds in all ---- */
#define BI_FLOPS (1L << 27)
static double bi_sink;
static double bi_peak_sse2(void)
{
    __m128d v[8], a = _mm_set1_pd(0.999999), b = _mm_set1_pd(1e-7);
    long i;
    int k;
    for (k = 0; k < 8; ++k) v[k] = _mm_set1_pd(1 + k);
    for (i = 0; i < BI_FLOPS / 16; ++i)
        for (k = 0; k < 8; ++k) v[k] = _mm_add_pd(_mm_mul_pd(v[k], a), b);
    for (k = 1; k < 8; ++k) v[0] = _mm_add_pd(v[0], v[k]);
    return _mm_cvtsd_f64(v[0]);
}
/* One peak loop per width: type, intrinsic prefix, doubles per register. */
#define BI_PEAK_FMA(name, target, T, P, W)                                          \
    target static double name(void)                                                 \
    {                                                                               \
        T v[8], a = P##_set1_pd(0.999999), b = P##_set1_pd(1e-7);                   \
        double out[W];                                                              \
        long i;                                                                     \
        int k;                                                                      \
        for (k = 0; k < 8; ++k) v[k] = P##_set1_pd(1 + k);                          \
        for (i = 0; i < BI_FLOPS / (8 * W); ++i)                                    \
            for (k = 0; k < 8; ++k) v[k] = P##_fmadd_pd(v[k], a, b);                \
        for (k = 1; k < 8; ++k) v[0] = P##_add_pd(v[0], v[k]);                      \
        P##_storeu_pd(out, v[0]);                                                   \
        return out[0];                                                              \
    }
#ifdef SPH_TARGET_AVX2
BI_PEAK_FMA(bi_peak_avx2, SPH_TARGET_AVX2, __m256d, _mm256, 4)
#endif
#ifdef SPH_TARGET_AVX512
BI_PEAK_FMA(bi_peak_avx512, SPH_TARGET_AVX512, __m512d, _mm512, 8)
#endif
/* The peak loop of the running level (sph_isa), where this build has one. */
static void bi_peak(void)
{
    switch (sph_isa()) {
#ifdef SPH_TARGET_AVX512
    case SPH_ISA_AVX512: bi_sink += bi_peak_avx512(); break;
#endif
#ifdef SPH_TARGET_AVX2
    case SPH_ISA_AVX2: bi_sink += bi_peak_avx2(); break;
#endif
    case SPH_ISA_PORTABLE: bi_sink += bi_peak_sse2(); break;
    default: break;
    }
}

/* Pairs summed by the last sph_h_solve: its time is per pair of these sums. */
static double bi_hsolve_pairs;

static void bi_run(bi_scene *s, int op)
{
    if (op == BI_PEAK) {
        bi_peak();
    } else if (op == BI_SEARCH) {
        bi_search(s);
    } else if (op == BI_BATCH) {
        sph_batch_src B;
        sph_batch b;
        sph_idx i;
        int l;
        bi_chk(sph_batch_source(&B, SPH_KERNEL_CUBIC, 3, &s->list, NULL, bi_x(s), sph_view_soa(s->hv, NULL, NULL)));
        for (i = 0; i < s->n; ++i) {
            sph_off next = 0;
            while (sph_batch_fill(&B, i, &next, &b) > 0)
                for (l = 0; l < SPH_BATCH; ++l) s->lanes[l] += b.W_i[l] + b.F_j[l];
        }
    } else if (op == BI_HSOLVE) {
        sph_hctx c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &s->list, bi_x(s), sph_view_soa(s->m, NULL, NULL), s->h);
        sph_hreport rep;
        sph_idx i;
        c.eta = (sph_real)1.1;
        c.check_list = 0;
        for (i = 0; i < s->n; ++i) s->hs[i] = s->h;
        bi_chk(sph_h_solve(&c, sph_out_soa(s->hs, NULL, NULL), sph_out_soa(s->rho, NULL, NULL),
                           sph_out_soa(s->om, NULL, NULL), NULL, NULL, &rep));
        bi_hsolve_pairs = (double)rep.iterations * (double)s->off[s->n] / s->n; /* sums x mean list length */
    } else {
        const sph_kernel k = (sph_kernel)(op - BI_FUSED0);
        sph_ctx c = sph_ctx_init(k, 3, s->h * sph_kernel_support(SPH_KERNEL_CUBIC) / sph_kernel_support(k), &s->list,
                                 bi_x(s));
        c.m = sph_view_soa(s->m, NULL, NULL);
        c.V = c.m; /* rho = 1 */
        c.validate = SPH_VALIDATE_ARGS;
        bi_chk(sph_density_gradient(&c, sph_view_soa(s->f, NULL, NULL), sph_view_none(), sph_out_soa(s->rho, NULL, NULL),
                                    sph_out_interleaved(s->g, 3)));
    }
}

static void bi_name(int op, char *buf, size_t size)
{
    if (op == BI_PEAK) snprintf(buf, size, "multiply-add peak (per 64 flops)");
    else if (op == BI_SEARCH) snprintf(buf, size, "search (build + lists)");
    else if (op == BI_BATCH) snprintf(buf, size, "sph_batch_fill (W, F at h_i, h_j)");
    else if (op == BI_HSOLVE) snprintf(buf, size, "sph_h_solve density sums");
    else snprintf(buf, size, "fused density + gradient, %s", sph_kernel_name((sph_kernel)(op - BI_FUSED0)));
}

int main(int argc, char **argv)
{
    const int side = argc > 1 ? atoi(argv[1]) : 48, reps = argc > 2 ? atoi(argv[2]) : 7;
    static double t[BI_OPS][BI_LEVELS][BI_MAX_REPS];
    int lv[BI_LEVELS], nl = 0, op, r, i, top;
    double pairs;
    bi_scene s;
    if (side < 8 || side > 200 || reps < 1 || reps > BI_MAX_REPS) {
        fprintf(stderr, "usage: %s [side 8..200] [repetitions 1..%d]\n", argv[0], BI_MAX_REPS);
        return 2;
    }
    for (i = SPH_ISA_PORTABLE; i <= SPH_ISA_AVX512; ++i)
        if (sph_isa_has(i)) lv[nl++] = i;
    top = nl - 1;
    bi_scene_init(&s, side);
    pairs = (double)s.off[s.n];
    printf("bench_isa: %s, %d particles, %.1f list entries per particle, %d repetitions, one thread\n",
           sizeof(sph_real) == sizeof(float) ? "float" : "double", s.n, pairs / s.n, reps);
    printf("levels this build and CPU have:");
    for (i = 0; i < nl; ++i) printf(" %s", sph_isa_name(lv[i]));
    printf(" (run-time dispatch %s)\n", sph_isa_dispatch() ? "on" : "off");
    for (r = -1; r < reps; ++r) /* r = -1: warm-up */
        for (op = 0; op < BI_OPS; ++op)
            for (i = 0; i < nl; ++i) {
                double t0;
                bi_chk(sph_isa_set(lv[i]));
                t0 = tm_now();
                bi_run(&s, op);
                t0 = tm_now() - t0;
                if (op == BI_HSOLVE && bi_hsolve_pairs > 0) t0 *= pairs / bi_hsolve_pairs;
                if (r >= 0) t[op][i][r] = t0;
            }
    bi_chk(sph_isa_set(SPH_ISA_AUTO));
    printf("\n| operation |");
    for (i = 0; i < nl; ++i) printf(" %s ns/pair |", sph_isa_name(lv[i]));
    for (i = 0; i < top; ++i) printf(" %s / %s |", sph_isa_name(lv[i]), sph_isa_name(lv[top]));
    printf("\n|---|");
    for (i = 0; i < 2 * nl - 1; ++i) printf("---:|");
    printf("\n");
    for (op = 0; op < BI_OPS; ++op) {
        char name[96];
        double v[BI_MAX_REPS];
        bi_name(op, name, sizeof name);
        printf("| %s |", name);
        for (i = 0; i < nl; ++i) {
            memcpy(v, t[op][i], sizeof(double) * (size_t)reps);
            printf(" %.2f |", 1e9 * tm_median(v, reps) / (op == BI_PEAK ? (double)BI_FLOPS / 64 : pairs));
        }
        for (i = 0; i < top; ++i) {
            for (r = 0; r < reps; ++r) v[r] = t[op][i][r] / t[op][top][r];
            printf(" %.2f |", tm_median(v, reps));
        }
        printf("\n");
    }
    if (bi_status != SPH_OK) printf("\nERROR: a call returned %d (%s)\n", bi_status, sph_strerror(bi_status));
    return bi_status == SPH_OK ? 0 : 1;
}
