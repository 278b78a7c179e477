/* bench/benchmark.c - speed of the neighbour search and the operators,
 * against two loops written here: a floor (gather the neighbours' positions,
 * minimum image, sum r^2: the memory system's limit for this access pattern)
 * and a textbook loop (if/else on q, pow(), division by r). Run by hand:
 *
 *   make bench          (double and float builds, 1 and 2 threads)
 *   build/bench/benchmark_double [side] [repetitions]
 *   BENCH_ONLY=fused build/bench/benchmark_double 64 7   (density, fused passes, sph_h_solve)
 *
 * Scene: 3-D, side^3 particles (default 64^3) on a lattice perturbed by
 * +-10 % dx in the periodic unit box, sorted by cell (sph_nsearch_permutation
 * + sph_permute), h such that the cubic spline has ~60 neighbours; the other
 * kernels use the same support radius kappa h (equal neighbours: the same
 * list). Each repetition runs every operation once, in turn, with 1 and
 * then 2 threads; a time is the median over the repetitions, printed as ns
 * per pair (pairs = list entries, self included), and a ratio of two times
 * the median of their ratios within each repetition.
 *
 * The same source compiled with -DBENCH_PART=name yields one wrapper around
 * sph_density_gradient built with other configuration macros (SPH_DIM and
 * SPH_KERNEL pinned, or SPH_OP_REFERENCE); the Makefile links those into
 * the program, so pinned and run-time selected loops are timed in one run. */
#if defined(BENCH_PART)
#include "sph_kernel.h"
int BENCH_PART(const sph_ctx *c, sph_view f, sph_out rho, sph_out grad);
int BENCH_PART(const sph_ctx *c, sph_view f, sph_out rho, sph_out grad)
{
    return sph_density_gradient(c, f, sph_view_none(), rho, grad);
}
#else
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "sph_kernel.h"
#include "support/timing.h"

typedef int (*dens_grad_fn)(const sph_ctx *, sph_view, sph_out, sph_out);
#if defined(BENCH_LINK_PARTS)
int bench_pinned(const sph_ctx *c, sph_view f, sph_out rho, sph_out grad);
int bench_reference(const sph_ctx *c, sph_view f, sph_out rho, sph_out grad);
#endif

/* ---- the scene ---- */
typedef struct {
    int n, side;
    sph_real dx, h, L;
    sph_real *x[3], *m, *V, *f, *v[3], *rho, *g[3], *out;
    sph_box box;
    sph_off *off;
    sph_idx *idx;
    size_t idx_cap, ws_bytes;
    void *work;
    sph_neighbours list;
} scene;

static sph_real *alloc_real(int n) { return (sph_real *)calloc((size_t)n, sizeof(sph_real)); }

static unsigned long long rng_state = 0x9E3779B97F4A7C15ull;
static double uniform(void) /* in [0, 1) */
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

static sph_view xview(const scene *s) { return sph_view_soa(s->x[0], s->x[1], s->x[2]); }

/* Neighbour list of the (sorted) scene: workspace size, build, then the
 * lists in one pass (sph_nsearch_lists) or by count + fill (two passes). */
static int build_list(scene *s, sph_real h, sph_real kappa, int one_pass)
{
    sph_nsearch g;
    const sph_real cell = kappa * h / 2;
    size_t bytes;
    int st = sph_nsearch_workspace_size(3, xview(s), s->n, sph_view_none(), cell, &s->box, &bytes);
    if (st != SPH_OK || bytes > s->ws_bytes) return st != SPH_OK ? st : SPH_ESIZE;
    st = sph_nsearch_build(&g, 3, xview(s), s->n, sph_view_none(), cell, &s->box, s->work, bytes);
    if (st == SPH_OK && one_pass) {
        sph_off pairs;
        st = sph_nsearch_lists(&g, xview(s), s->n, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, s->off, s->idx,
                               (sph_off)s->idx_cap, &pairs);
        s->list = sph_nsearch_list(&g, s->n, s->off, s->idx);
        return st;
    }
    if (st == SPH_OK) st = sph_nsearch_count(&g, xview(s), s->n, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, s->off);
    if (st == SPH_OK && (size_t)s->off[s->n] > s->idx_cap) return SPH_ESIZE;
    if (st == SPH_OK)
        st = sph_nsearch_fill(&g, xview(s), s->n, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, s->off, s->idx,
                              (sph_off)s->idx_cap);
    s->list = sph_nsearch_list(&g, s->n, s->off, s->idx);
    return st;
}

static void scene_init(scene *s, int side)
{
    const sph_real kappa = sph_kernel_support(SPH_KERNEL_CUBIC);
    sph_real *tmp[3];
    sph_idx *perm;
    sph_nsearch g;
    int i, a;
    s->side = side;
    s->n = side * side * side;
    s->L = 1;
    s->dx = s->L / side;
    s->h = sph_kernel_h_for_neighbours(SPH_KERNEL_CUBIC, 3, 60, s->dx * s->dx * s->dx);
    for (a = 0; a < 3; ++a) {
        s->x[a] = alloc_real(s->n);
        s->v[a] = alloc_real(s->n);
        s->g[a] = alloc_real(s->n);
        tmp[a] = alloc_real(s->n);
        s->box.lo[a] = 0;
        s->box.length[a] = s->L;
        s->box.periodic[a] = 1;
    }
    s->m = alloc_real(s->n);
    s->V = alloc_real(s->n);
    s->f = alloc_real(s->n);
    s->rho = alloc_real(s->n);
    s->out = alloc_real(s->n);
    for (i = 0; i < s->n; ++i) {
        const int c[3] = {i % side, (i / side) % side, i / (side * side)};
        for (a = 0; a < 3; ++a) {
            sph_real y = ((sph_real)c[a] + (sph_real)0.5 + (sph_real)(0.2 * uniform() - 0.1)) * s->dx;
            tmp[a][i] = y;
        }
    }
    /* shuffle, so that the sort below does real work, then sort by cell */
    for (i = s->n - 1; i > 0; --i) {
        const int k = (int)(uniform() * (i + 1));
        for (a = 0; a < 3; ++a) {
            const sph_real t = tmp[a][i];
            tmp[a][i] = tmp[a][k];
            tmp[a][k] = t;
        }
    }
    s->off = (sph_off *)malloc(sizeof(sph_off) * (size_t)(s->n + 1));
    sph_nsearch_workspace_size(3, sph_view_soa(tmp[0], tmp[1], tmp[2]), s->n, sph_view_none(), kappa * s->h / 2,
                               &s->box, &s->ws_bytes);
    s->work = malloc(s->ws_bytes);
    perm = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)s->n);
    sph_nsearch_build(&g, 3, sph_view_soa(tmp[0], tmp[1], tmp[2]), s->n, sph_view_none(), kappa * s->h / 2, &s->box,
                      s->work, s->ws_bytes);
    sph_nsearch_permutation(&g, perm);
    sph_permute(sph_view_soa(tmp[0], tmp[1], tmp[2]), 3, s->n, perm, sph_out_soa(s->x[0], s->x[1], s->x[2]));
    free(perm);
    for (a = 0; a < 3; ++a) free(tmp[a]);
    s->idx_cap = (size_t)s->n * 80; /* ~20 % above the 66 pairs per particle of the scene */
    s->idx = (sph_idx *)malloc(sizeof(sph_idx) * s->idx_cap);
    for (i = 0; i < s->n; ++i) {
        const double tp = 6.283185307179586;
        s->m[i] = s->dx * s->dx * s->dx; /* rho0 = 1 */
        s->V[i] = s->m[i];
        s->f[i] = (sph_real)(sin(tp * s->x[0][i]) * sin(tp * s->x[1][i]));
        for (a = 0; a < 3; ++a) s->v[a][i] = (sph_real)sin(tp * s->x[(a + 1) % 3][i]);
    }
}

/* ---- reference loops ---- */

/* The floor: gather x_j, minimum image, sum r^2 (what any pair loop must do).
 * With FIELDS (a constant: the two loops are separate instances) it also
 * reads m_j, V_j and f_j and sums them: the loads a density + difference
 * gradient cannot do without (it needs m_j for rho, V_j and f_j for the
 * gradient), and none of its arithmetic. Its time is a lower bound for that
 * operation over the scene's arrays, measured on this machine. */
static inline void floor_pass(const scene *s, const int FIELDS)
{
    const sph_real L = s->L, Linv = 1 / s->L;
    int i;
#pragma omp parallel for schedule(static)
    for (i = 0; i < s->n; ++i) {
        const sph_real xi = s->x[0][i], yi = s->x[1][i], zi = s->x[2][i];
        sph_real acc = 0, sum = 0;
        sph_off o;
#pragma omp simd reduction(+ : acc, sum)
        for (o = s->off[i]; o < s->off[i + 1]; ++o) {
            const sph_idx j = s->idx[o];
            sph_real dx = xi - s->x[0][j], dy = yi - s->x[1][j], dz = zi - s->x[2][j];
            dx -= L * (sph_real)floor((double)(dx * Linv + (sph_real)0.5));
            dy -= L * (sph_real)floor((double)(dy * Linv + (sph_real)0.5));
            dz -= L * (sph_real)floor((double)(dz * Linv + (sph_real)0.5));
            acc += dx * dx + dy * dy + dz * dz;
            if (FIELDS) sum += s->m[j] + s->V[j] + s->f[j];
        }
        s->out[i] = acc + sum;
    }
}

static void floor_loop(const scene *s) { floor_pass(s, 0); }
static void floor_fields_loop(const scene *s) { floor_pass(s, 1); }

/* The textbook loop: cubic spline (Monaghan 1992 form), if/else on q, pow(),
 * division by r, if/else minimum image; density and difference gradient. */
static void textbook_loop(scene *s)
{
    const double pi = 3.14159265358979323846, h = (double)s->h, L = (double)s->L;
    int i;
#pragma omp parallel for schedule(static)
    for (i = 0; i < s->n; ++i) {
        double rho = 0, g[3] = {0, 0, 0};
        sph_off o;
        for (o = s->off[i]; o < s->off[i + 1]; ++o) {
            const sph_idx j = s->idx[o];
            double d[3], r, q, W, dW;
            int a;
            for (a = 0; a < 3; ++a) {
                d[a] = (double)s->x[a][i] - (double)s->x[a][j];
                if (d[a] > 0.5 * L) d[a] -= L;
                else if (d[a] < -0.5 * L) d[a] += L;
            }
            r = sqrt(pow(d[0], 2) + pow(d[1], 2) + pow(d[2], 2));
            q = r / h;
            if (q < 1) {
                W = 1 / (pi * pow(h, 3)) * (1 - 1.5 * pow(q, 2) + 0.75 * pow(q, 3));
                dW = 1 / (pi * pow(h, 4)) * (-3 * q + 2.25 * pow(q, 2));
            } else if (q < 2) {
                W = 1 / (pi * pow(h, 3)) * 0.25 * pow(2 - q, 3);
                dW = 1 / (pi * pow(h, 4)) * (-0.75 * pow(2 - q, 2));
            } else {
                W = 0;
                dW = 0;
            }
            rho += (double)s->m[j] * W;
            if (r > 0)
                for (a = 0; a < 3; ++a) g[a] += (double)s->V[j] * ((double)s->f[j] - (double)s->f[i]) * dW * d[a] / r;
        }
        s->rho[i] = (sph_real)rho;
        s->g[0][i] = (sph_real)g[0];
        s->g[1][i] = (sph_real)g[1];
        s->g[2][i] = (sph_real)g[2];
    }
}

/* A hand-written cubic density + difference gradient for a scene with a
 * uniform h and no box (what a solver without those options would write):
 * branch-free B-spline form w = ((2-q)+^3 - 4 (1-q)+^3) / 6, the same chunked
 * structure as the library, errno-free sqrt via the same helper. */
static void hand_loop(scene *s)
{
    const sph_real hinv = 1 / s->h, cW = (sph_real)(3.0 / (2.0 * 3.14159265358979323846)) * hinv * hinv * hinv;
    const sph_real cF = cW * hinv * hinv;
    int i;
#pragma omp parallel for schedule(static)
    for (i = 0; i < s->n; ++i) {
        const sph_real xi[3] = {s->x[0][i], s->x[1][i], s->x[2][i]}, fi = s->f[i];
        sph_real s0 = 0, s1 = 0, s2 = 0, s3 = 0;
        sph_off o;
        for (o = s->off[i]; o < s->off[i + 1]; o += SPH__CHUNK) {
            const int n = (int)((s->off[i + 1] - o) < SPH__CHUNK ? s->off[i + 1] - o : SPH__CHUNK);
            sph_real d[3][SPH__CHUNK], r[SPH__CHUNK];
            int k;
#pragma omp simd
            for (k = 0; k < n; ++k) {
                const sph_idx j = s->idx[o + k];
                d[0][k] = xi[0] - s->x[0][j];
                d[1][k] = xi[1] - s->x[1][j];
                d[2][k] = xi[2] - s->x[2][j];
                r[k] = d[0][k] * d[0][k] + d[1][k] * d[1][k] + d[2][k] * d[2][k];
            }
            for (k = n; (k & 7) != 0; ++k) r[k] = 0;
            sph__sqrt_chunk(r, k);
#pragma omp simd reduction(+ : s0, s1, s2, s3)
            for (k = 0; k < n; ++k) {
                const sph_idx j = s->idx[o + k];
                const sph_real q = r[k] * hinv, a = 2 - q > 0 ? 2 - q : 0, b = 1 - q > 0 ? 1 - q : 0;
                const sph_real w = (a * a * a - 4 * b * b * b) * (sph_real)(1.0 / 6.0);
                /* w'/q = (-(2-q)+^2 / 2 + 2 (1-q)+^2) / q, finite limit -2 at q = 0 */
                const sph_real g = q > 0 ? (2 * b * b - (sph_real)0.5 * a * a) / q : -2;
                const sph_real c = s->V[j] * (s->f[j] - fi) * cF * g;
                s3 += s->m[j] * cW * w;
                s0 += c * d[0][k];
                s1 += c * d[1][k];
                s2 += c * d[2][k];
            }
        }
        s->rho[i] = s3;
        s->g[0][i] = s0;
        s->g[1][i] = s1;
        s->g[2][i] = s2;
    }
}

/* ---- timing ---- */
enum {
    T_FLOOR, T_FLOOR_FIELDS, T_TEXT, T_BUILD, T_BUILD2, T_DENS, T_GRAD, T_DENS_THEN_GRAD, T_FUSED, T_CORR, T_DIV, T_LAP,
    T_FUSED_HV, T_FUSED_HVAR, T_HSOLVE, T_FUSED_NOBOX, T_HAND_NOBOX, T_PINNED, T_REFERENCE, T_KERNEL0, T_COUNT = T_KERNEL0 + SPH_KERNEL_COUNT
};

static const char *const t_name[T_COUNT] = {
    "floor: gather x_j, min. image, r^2", "floor + reads of m_j, V_j, f_j", "textbook density + gradient", "neighbour list (size+build+lists, 1 pass)",
    "neighbour list (size+build+count+fill)",
    "density", "gradient (difference)", "density, then gradient (2 calls)", "density + gradient (fused, 1 pass)",
    "corrected gradient incl. B_i", "divergence (difference)", "Laplacian",
    "fused, per-particle h (all equal)", "fused, per-particle h (0.9..1 h)", "sph_h_solve density sums (eta 1.1)",
    "fused, no box (scene unwrapped)", "hand-written loop, no box, uniform h",
    "fused, SPH_DIM 3 + SPH_KERNEL pinned", "fused, reference loops (SPH_OP_REFERENCE)", "k", "k", "k", "k", "k", "k", "k"};

static sph_ctx ctx_of(scene *s, sph_kernel k)
{
    sph_ctx c = sph_ctx_init(k, 3, s->h * sph_kernel_support(SPH_KERNEL_CUBIC) / sph_kernel_support(k), &s->list,
                             xview(s));
    c.box = &s->box;
    c.m = sph_view_soa(s->m, NULL, NULL);
    c.V = sph_view_soa(s->V, NULL, NULL);
    c.validate = SPH_VALIDATE_ARGS;
    return c;
}

static int g_status = SPH_OK;
static void chk(int st)
{
    if (st != SPH_OK && g_status == SPH_OK) g_status = st;
}

/* Pairs summed by the last sph_h_solve run (its iterations times the list
 * lengths): T_HSOLVE's time is per pair of these sums. */
static double g_hsolve_pairs = 0;

/* sph_h_solve from the guesses h_i = h (above the root of eta 1.1, inside
 * the list of kappa h): a few density sums per particle. */
static void run_hsolve(scene *s, sph_real *hwork, int *iters)
{
    sph_hctx c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &s->list, xview(s), sph_view_soa(s->m, NULL, NULL), s->h);
    sph_real *rho = s->rho, *om = s->out;
    double np = 0;
    int i;
    c.box = &s->box;
    c.eta = (sph_real)1.1;
    c.check_list = 0;
    for (i = 0; i < s->n; ++i) hwork[i] = s->h;
    chk(sph_h_solve(&c, sph_out_soa(hwork, NULL, NULL), sph_out_soa(rho, NULL, NULL), sph_out_soa(om, NULL, NULL),
                    iters, NULL, NULL));
    for (i = 0; i < s->n; ++i) np += (double)iters[i] * (double)(s->off[i + 1] - s->off[i]);
    g_hsolve_pairs = np;
}

/* One timed run of operation op (hbuf: h_i = h, then h_i in 0.9..1 h, then
 * scratch for sph_h_solve). */
static void run_op(scene *s, int op, sph_real *hbuf)
{
    sph_ctx c = ctx_of(s, SPH_KERNEL_CUBIC);
    const sph_view f = sph_view_soa(s->f, NULL, NULL), v = sph_view_soa(s->v[0], s->v[1], s->v[2]);
    const sph_out rho = sph_out_soa(s->rho, NULL, NULL), g = sph_out_soa(s->g[0], s->g[1], s->g[2]);
    const sph_out out = sph_out_soa(s->out, NULL, NULL);
    sph_idx nfb;
    switch (op) {
    case T_FLOOR: floor_loop(s); break;
    case T_FLOOR_FIELDS: floor_fields_loop(s); break;
    case T_TEXT: textbook_loop(s); break;
    case T_BUILD: chk(build_list(s, s->h, sph_kernel_support(SPH_KERNEL_CUBIC), 1)); break;
    case T_BUILD2: chk(build_list(s, s->h, sph_kernel_support(SPH_KERNEL_CUBIC), 0)); break;
    case T_DENS: chk(sph_density(&c, rho)); break;
    case T_GRAD: chk(sph_gradient(&c, SPH_SCHEME_DIFFERENCE, f, sph_view_none(), g, NULL)); break;
    case T_DENS_THEN_GRAD:
        chk(sph_density(&c, rho));
        chk(sph_gradient(&c, SPH_SCHEME_DIFFERENCE, f, sph_view_none(), g, NULL));
        break;
    case T_FUSED: chk(sph_density_gradient(&c, f, sph_view_none(), rho, g)); break;
    case T_CORR: chk(sph_gradient(&c, SPH_SCHEME_CORRECTED, f, sph_view_none(), g, &nfb)); break;
    case T_DIV: chk(sph_divergence(&c, SPH_SCHEME_DIFFERENCE, v, sph_view_none(), out, NULL)); break;
    case T_LAP: chk(sph_laplacian(&c, f, sph_view_none(), out)); break;
    case T_FUSED_HV:
        c.h_source = sph_view_soa(hbuf, NULL, NULL);
        chk(sph_density_gradient(&c, f, sph_view_none(), rho, g));
        break;
    case T_FUSED_HVAR:
        c.h_source = sph_view_soa(hbuf + s->n, NULL, NULL);
        chk(sph_density_gradient(&c, f, sph_view_none(), rho, g));
        break;
    case T_HSOLVE: run_hsolve(s, hbuf + 2 * s->n, (int *)(void *)(hbuf + 3 * s->n)); break;
    case T_FUSED_NOBOX: { /* the list without its periodic box: the open loops' time */
        sph_neighbours open = s->list;
        open.box_known = 0;
        c.list = &open;
        c.box = NULL;
        chk(sph_density_gradient(&c, f, sph_view_none(), rho, g));
        break;
    }
    case T_HAND_NOBOX: hand_loop(s); break;
#if defined(BENCH_LINK_PARTS)
    case T_PINNED: chk(bench_pinned(&c, f, rho, g)); break;
    case T_REFERENCE: chk(bench_reference(&c, f, rho, g)); break;
#endif
    default:
        if (op >= T_KERNEL0) {
            c = ctx_of(s, (sph_kernel)(op - T_KERNEL0));
            chk(sph_density_gradient(&c, f, sph_view_none(), rho, g));
        }
        break;
    }
}

/* The samples: time of operation op with thread setting ti (0: 1 thread,
 * 1: 2 threads) in repetition r is s[(ti * T_COUNT + op) * reps + r]; 0 for
 * an operation not timed. */
typedef struct {
    int reps;
    double *s;
} timings;

static const double *samples(const timings *T, int ti, int op) { return T->s + ((size_t)ti * T_COUNT + (size_t)op) * (size_t)T->reps; }

/* Median time of (ti, op). */
static double med_time(const timings *T, int ti, int op)
{
    double v[64];
    const int n = T->reps < 64 ? T->reps : 64;
    memcpy(v, samples(T, ti, op), (size_t)n * sizeof(double));
    return tm_median(v, n);
}

/* Median over the repetitions of time(ti_a, a) / time(ti_b, b): the two were
 * timed in the same repetition, seconds apart, so load from other jobs that
 * comes and goes between repetitions cancels in each ratio. 0 if either was
 * not timed. */
static double med_ratio(const timings *T, int ti_a, int a, int ti_b, int b)
{
    const double *x = samples(T, ti_a, a), *y = samples(T, ti_b, b);
    double v[64];
    const int n = T->reps < 64 ? T->reps : 64;
    int r;
    for (r = 0; r < n; ++r) {
        if (x[r] <= 0 || y[r] <= 0) return 0;
        v[r] = x[r] / y[r];
    }
    return tm_median(v, n);
}

/* One row of the ratio list: label, value, printf format, goal ("" if none). */
static void put_ratio(FILE *f, int md, const char *label, double v, const char *fmt, const char *goal)
{
    char num[32];
    snprintf(num, sizeof num, fmt, v);
    if (md)
        fprintf(f, "| %s | %s | %s |\n", label, num, goal);
    else
        fprintf(f, "  %-48s %s%s%s%s\n", label, num, *goal ? "  (target " : "", goal, *goal ? ")" : "");
}

/* The timing table and the ratios against the targets: as text for the
 * terminal (md 0) or as a markdown section (md 1; make bench appends both
 * precisions to docs/results/benchmark.md). Times are medians over the repetitions,
 * every ratio the median of the per-repetition ratios (med_ratio). */
static void put_tables(FILE *f, int md, const timings *T, double pairs, int n, int side, double cand, double h_dx)
{
    char label[80];
    int op;
#define R1(a, b) med_ratio(T, 0, a, 0, b)
    if (md)
        fprintf(f, "\n## %s\n\n%d^3 = %d particles, lattice perturbed by +-10 %% dx, periodic unit box, sorted by "
                   "cell; cubic h = %.4g dx, %.1f pairs per particle (self included), the other kernels with the same "
                   "kappa h; %d repetitions, each running every operation once in turn, with 1 and then 2 threads; "
                   "times are medians, ratios medians of the ratios within a repetition; %.2f candidate distance "
                   "checks per neighbour found.\n\n"
                   "| operation (cubic unless named) | ns/pair | x floor | x textbook | 2 threads ns/pair | speed-up |\n"
                   "|---|---:|---:|---:|---:|---:|\n",
                sizeof(sph_real) == sizeof(float) ? "float" : "double", side, n, h_dx, pairs / n, T->reps, cand);
    else
        fprintf(f, "%-42s %9s %8s %8s %9s %8s\n", "operation (cubic unless named)", "ns/pair", "x floor", "x text.",
                "2 thr ns", "speedup");
    for (op = 0; op < T_COUNT; ++op) {
        const double ns = 1e9 * med_time(T, 0, op) / pairs, ns2 = 1e9 * med_time(T, 1, op) / pairs;
        const double up = med_ratio(T, 0, op, 1, op);
        if (ns == 0) continue;
        if (op >= T_KERNEL0)
            snprintf(label, sizeof label, md ? "fused, %s" : "  %s", sph_kernel_name((sph_kernel)(op - T_KERNEL0)));
        else
            snprintf(label, sizeof label, "%s", t_name[op]);
        if (md) {
            fprintf(f, "| %s | %.2f | %.2f | %.3f | %.2f | %.2f |\n", label, ns, R1(op, T_FLOOR), R1(op, T_TEXT), ns2,
                    up);
        } else {
            if (op == T_KERNEL0) fprintf(f, "fused density + gradient, per kernel (equal neighbours):\n");
            fprintf(f, "%-42s %9.3f %8.2f %8.3f %9.3f %8.2f\n", label, ns, R1(op, T_FLOOR), R1(op, T_TEXT), ns2, up);
        }
    }
    fprintf(f, md ? "\n| measure | value | target |\n|---|---:|---|\n" : "\ntargets (1 thread unless named):\n");
    put_ratio(f, md, "fused density + gradient / floor, cubic", R1(T_FUSED, T_FLOOR), "%.2f", "<= 1.3");
    for (op = T_KERNEL0; op < T_COUNT; ++op)
        if (op != T_KERNEL0 + SPH_KERNEL_CUBIC) {
            snprintf(label, sizeof label, "fused density + gradient / floor, %s",
                     sph_kernel_name((sph_kernel)(op - T_KERNEL0)));
            put_ratio(f, md, label, R1(op, T_FLOOR), "%.2f", "<= 1.6");
        }
    put_ratio(f, md, "floor + reads of m_j, V_j, f_j / floor (bound for the two above)", R1(T_FLOOR_FIELDS, T_FLOOR),
              "%.2f", "");
    put_ratio(f, md, "fused density + gradient / (floor + reads), cubic", R1(T_FUSED, T_FLOOR_FIELDS), "%.2f", "");
    put_ratio(f, md, "textbook / fused density + gradient", R1(T_TEXT, T_FUSED), "%.1f", ">= 10");
    put_ratio(f, md, "textbook / (density, then gradient)", R1(T_TEXT, T_DENS_THEN_GRAD), "%.1f", "");
    if (med_time(T, 1, T_FUSED) > 0)
        put_ratio(f, md, "fused: 1 thread / 2 threads", med_ratio(T, 0, T_FUSED, 1, T_FUSED), "%.2f", ">= 1.8");
    put_ratio(f, md, "candidate checks per neighbour", cand, "%.2f", "<= 3");
    put_ratio(f, md, "neighbour list / fused density + gradient", R1(T_BUILD, T_FUSED), "%.2f", "<= 2");
    if (med_time(T, 0, T_PINNED) > 0)
        put_ratio(f, md, "run-time selected / pinned (SPH_DIM, SPH_KERNEL)", R1(T_FUSED, T_PINNED), "%.3f", "<= 1.05");
    put_ratio(f, md, "library without box / hand-written, no box", R1(T_FUSED_NOBOX, T_HAND_NOBOX), "%.3f", "<= 1.03");
    put_ratio(f, md, "per-particle h (all equal) / uniform h", R1(T_FUSED_HV, T_FUSED), "%.3f", "<= 1.3");
    put_ratio(f, md, "per-particle h (0.9..1 h) / uniform h", R1(T_FUSED_HVAR, T_FUSED), "%.3f", "<= 1.3");
    put_ratio(f, md, "sph_h_solve density sums / density, per pair", R1(T_HSOLVE, T_DENS), "%.3f", "<= 1.3");
    put_ratio(f, md, "periodic box / no box", R1(T_FUSED, T_FUSED_NOBOX), "%.3f", "");
    if (med_time(T, 0, T_REFERENCE) > 0) put_ratio(f, md, "reference loops / fast loops", R1(T_REFERENCE, T_FUSED), "%.3f", "");
#undef R1
}

int main(int argc, char **argv)
{
    const int side = argc > 1 ? atoi(argv[1]) : 64, reps = argc > 2 ? atoi(argv[2]) : 5;
    FILE *md = argc > 3 ? fopen(argv[3], "a") : NULL;
    const int nthreads[2] = {1, 2};
    /* BENCH_ONLY=fused: the density, the fused passes and sph_h_solve only */
    const int only_fused = getenv("BENCH_ONLY") != NULL && strcmp(getenv("BENCH_ONLY"), "fused") == 0;
    /* zeros for operations not timed: their median 0 leaves them out of the tables */
    timings T;
    double pairs;
    sph_off npairs = 0, ncand = 0;
    sph_real *hbuf;
    scene s;
    int op, r, ti, i;
    if (side < 4 || reps < 1 || reps > 64) {
        fprintf(stderr, "usage: %s [side >= 4] [repetitions 1..64] [markdown file to append the tables to]\n",
                argv[0]);
        return 2;
    }
    T.reps = reps;
    T.s = (double *)calloc(2 * T_COUNT * (size_t)reps, sizeof(double));
    if (T.s == NULL) return 2;
    scene_init(&s, side);
    hbuf = alloc_real(4 * s.n); /* h, varying h, sph_h_solve's h and its int iterations */
    if (hbuf == NULL) return 2;
    for (i = 0; i < s.n; ++i) hbuf[i] = s.h;
    for (i = 0; i < s.n; ++i) hbuf[s.n + i] = s.h * (sph_real)(0.9 + 0.1 * uniform());
    chk(build_list(&s, s.h, sph_kernel_support(SPH_KERNEL_CUBIC), 1));
    {
        sph_nsearch g;
        const sph_real kappa = sph_kernel_support(SPH_KERNEL_CUBIC);
        chk(sph_nsearch_build(&g, 3, xview(&s), s.n, sph_view_none(), kappa * s.h / 2, &s.box, s.work, s.ws_bytes));
        chk(sph_nsearch_stats(&g, xview(&s), s.n, sph_view_none(), s.h, kappa, SPH_NSEARCH_GATHER, &npairs, &ncand, NULL));
    }
    pairs = (double)s.off[s.n];
    printf("benchmark: %s, %d^3 = %d particles, perturbed lattice (+-10%% dx), periodic unit box, sorted by cell\n",
           sizeof(sph_real) == sizeof(float) ? "float" : "double", side, s.n);
    printf("cubic h = %.4g dx, %.1f pairs per particle (self included); other kernels: same kappa h (equal "
           "neighbours, same list)\n",
           (double)(s.h / s.dx), pairs / s.n);
    printf("neighbour search: %.3f candidate distance checks per neighbour found (cells of kappa h / 2)\n",
           (double)ncand / (double)npairs);
    printf("%d repetitions, each every operation once in turn with 1, then 2 threads; times: medians, ratios: "
           "medians of the ratios within a repetition; ns per pair = time / %.0f pairs\n\n",
           reps, pairs);
    /* repetition r of every operation, with 1 and with 2 threads, then r + 1:
     * a burst of load from other jobs lands on all rows alike, not on the few
     * timed in it, and each ratio compares times taken seconds apart */
    for (r = -1; r < reps; ++r) /* r = -1: warm-up */
        for (ti = 0; ti < 2; ++ti) {
#ifdef _OPENMP
            omp_set_num_threads(nthreads[ti]);
#else
            if (nthreads[ti] > 1) break;
#endif
            for (op = 0; op < T_COUNT; ++op) {
                double t0;
#if !defined(BENCH_LINK_PARTS)
                if (op == T_PINNED || op == T_REFERENCE) continue;
#endif
                if (only_fused && op != T_DENS && op != T_FUSED && op != T_FUSED_HV && op != T_FUSED_HVAR &&
                    op != T_HSOLVE)
                    continue;
                t0 = tm_now();
                run_op(&s, op, hbuf);
                t0 = tm_now() - t0;
                /* sph_h_solve: per pair of its density sums, as ns/pair divides by the list's pairs */
                if (op == T_HSOLVE && g_hsolve_pairs > 0) t0 *= pairs / g_hsolve_pairs;
                if (r >= 0) T.s[((size_t)ti * T_COUNT + (size_t)op) * (size_t)reps + (size_t)r] = t0;
            }
        }
    put_tables(stdout, 0, &T, pairs, s.n, side, (double)ncand / (double)npairs, (double)(s.h / s.dx));
    if (argc > 3 && md == NULL) fprintf(stderr, "benchmark: cannot open %s\n", argv[3]);
    if (md != NULL) {
        put_tables(md, 1, &T, pairs, s.n, side, (double)ncand / (double)npairs, (double)(s.h / s.dx));
        fclose(md);
    }
    if (g_status != SPH_OK) printf("\nERROR: a call returned %d (%s)\n", g_status, sph_strerror(g_status));
    free(T.s);
    return g_status == SPH_OK ? 0 : 1;
}
#endif
