/* studies/error_vs_runtime.c - error against run time of every operator of
 * sph_kernel.h: interpolation/density, the five gradient schemes, two
 * divergence schemes and the Laplacian, for every kernel in 2-D and 3-D,
 * on a lattice, on lattices perturbed by 10 % and 30 % of dx and at a free
 * surface, for a sine, a linear and a quadratic field with analytic
 * derivatives. Writes docs/results/report.md and the CSV files of docs/results/report/
 * (`make report`; the PNGs are drawn from the CSVs by studies/report.gp).
 *
 * Sweeps (Quinlan, Basa & Lastiwka 2006, Int. J. Numer. Meth. Engng 66:2064):
 *   A  h -> 0 at fixed dx/h: the smoothing error O(h^2) and, on disorder,
 *      the discretisation error that does not shrink with h;
 *   B  dx/h -> 0 at fixed h: the discretisation error vanishes and the error
 *      levels off at the smoothing error of that h;
 *   P  fixed dx, a ladder of h per kernel: the choices a solver has at a
 *      given particle count, from which the Pareto fronts (least error for a
 *      time budget) are taken.
 * Kernels are compared at equal h and at equal resolution (equal standard
 * deviation sigma h, sph_kernel_sigma; the cubic's h is the reference).
 *
 * Every neighbour list comes from sph_nsearch_*, every estimate from
 * sph_density, sph_interpolate, sph_gradient, sph_divergence and
 * sph_laplacian. Times: median over repeats of the operator call alone (the
 * list is checked once and the operators run with SPH_VALIDATE_ARGS).
 *
 *   error_vs_runtime [--full] [--out DIR] [--repeats R]   report into DIR (default docs/results);
 *                    R timing repeats everywhere (default 5 in the Pareto scan, 3 in the sweeps)
 *   error_vs_runtime --check      short coarse run, asserts known properties, writes nothing
 */
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

#define PI 3.14159265358979323846
#define NK SPH_KERNEL_COUNT
#define NOP 10
#define NFIELD 3
#define NARR 4

/* ---------------------------------------------------------------- setup */

enum { ARR_LATTICE, ARR_PERT10, ARR_PERT30, ARR_SURFACE };
static const char *arr_name[NARR] = {"lattice", "perturbed10", "perturbed30", "surface"};
static const double arr_amp[NARR] = {0, 0.1, 0.3, 0};

enum { FIELD_SINE, FIELD_LINEAR, FIELD_QUADRATIC };
static const char *field_name[NFIELD] = {"sine", "linear", "quadratic"};

/* operator rows: what is called and which group (plot, Pareto front) it belongs to */
enum { OP_DENSITY, OP_INTERP, OP_GRAD_STD, OP_GRAD_DIFF, OP_GRAD_SYM, OP_GRAD_CORR, OP_GRAD_PRES,
       OP_DIV_DIFF, OP_DIV_CORR, OP_LAPLACIAN };
static const char *op_group[NOP] = {"density", "interpolation", "gradient", "gradient", "gradient",
                                    "gradient", "gradient", "divergence", "divergence", "laplacian"};
static const char *op_scheme[NOP] = {"-", "-", "standard", "difference", "symmetric", "corrected",
                                     "pressure", "difference", "corrected", "-"};
#define NGROUP 5
static const char *group_name[NGROUP] = {"density", "interpolation", "gradient", "divergence", "laplacian"};
static int op_group_id(int op) { return op == 0 ? 0 : op == 1 ? 1 : op <= 6 ? 2 : op <= 8 ? 3 : 4; }

/* divergence test field: v_a = c_a f, div v = c . grad f */
static const double div_c[3] = {1.0, -0.5, 0.25};

typedef struct {
    int full, check;
    int repeats;       /* timing repeats in the Pareto scan */
    int repeats_sweep; /* timing repeats in sweeps A and B */
    const char *out;
} options;

/* one row of the report */
typedef struct {
    char sweep;       /* 'A', 'B', 'P' */
    int equal_sigma;  /* 0: equal h, 1: equal sigma h */
    int dim, arr, N, op, field, n_measured;
    sph_kernel k;
    double dx, h, L2, Lmax, order, neigh, t_ns, pairs_s;
    int absolute;     /* exact answer is 0: errors are absolute */
    long fallback;    /* corrected schemes: targets that fell back */
} row;

typedef struct {
    row *r;
    size_t n, cap;
} table;

static void push(table *t, const row *r)
{
    if (t->n == t->cap) {
        t->cap = t->cap ? 2 * t->cap : 1024;
        t->r = (row *)realloc(t->r, t->cap * sizeof(row));
        if (t->r == NULL) {
            fprintf(stderr, "out of memory\n");
            exit(2);
        }
    }
    t->r[t->n++] = *r;
}

/* ------------------------------------------------------------- fields */

/* value, gradient and Laplacian of field fid at x (dim components) */
static double field_eval(int fid, int dim, const double *x, double *g, double *lap)
{
    int a;
    if (fid == FIELD_SINE) {
        double s[3], c[3], f = 1;
        const double k = 2 * PI;
        for (a = 0; a < dim; ++a) s[a] = sin(k * x[a]), c[a] = cos(k * x[a]), f *= s[a];
        for (a = 0; a < dim; ++a) {
            int b;
            g[a] = k * c[a];
            for (b = 0; b < dim; ++b)
                if (b != a) g[a] *= s[b];
        }
        *lap = -dim * k * k * f;
        return f;
    }
    if (fid == FIELD_LINEAR) { /* 0.7 + 1.3 x - 0.8 y + 0.4 z */
        static const double c[3] = {1.3, -0.8, 0.4};
        double f = 0.7;
        for (a = 0; a < dim; ++a) g[a] = c[a], f += c[a] * x[a];
        *lap = 0;
        return f;
    }
    { /* 0.5 + x^2 - x y + 0.5 y^2 + z^2 */
        const double X = x[0], Y = x[1], Z = dim == 3 ? x[2] : 0;
        g[0] = 2 * X - Y;
        g[1] = -X + Y;
        if (dim == 3) g[2] = 2 * Z;
        *lap = dim == 3 ? 5 : 3;
        return 0.5 + X * X - X * Y + 0.5 * Y * Y + Z * Z;
    }
}

/* -------------------------------------------------------------- scene */

typedef struct {
    int dim, arr, N, n;
    double dx, h, margin;
    sph_kernel k;
    sph_box box;
    sph_real *x, *V, *m, *rho, *out, *f[NFIELD], *v[NFIELD][3];
    double *fe[NFIELD], *ge[NFIELD], *le[NFIELD]; /* exact value, gradient, Laplacian */
    unsigned char *surf, *inner;                  /* measured targets: all/surface, interior */
    sph_off *offset;
    sph_idx *index;
    sph_neighbours list;
    void *work;
    sph_ctx c;
} scene;

/* splitmix64: the same perturbation on every machine */
static double uniform(unsigned long long *s)
{
    unsigned long long z = (*s += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

static void *xmalloc(size_t bytes)
{
    void *p = malloc(bytes > 0 ? bytes : 1);
    if (p == NULL) {
        fprintf(stderr, "out of memory (%lu bytes)\n", (unsigned long)bytes);
        exit(2);
    }
    return p;
}

static void scene_free(scene *s)
{
    int fi, a;
    free(s->x), free(s->V), free(s->m), free(s->rho), free(s->out), free(s->surf), free(s->inner);
    free(s->offset), free(s->index), free(s->work);
    for (fi = 0; fi < NFIELD; ++fi) {
        free(s->f[fi]), free(s->fe[fi]), free(s->ge[fi]), free(s->le[fi]);
        for (a = 0; a < 3; ++a) free(s->v[fi][a]);
    }
    memset(s, 0, sizeof *s);
}

static int fail(const char *what, int st)
{
    fprintf(stderr, "%s: %s\n", what, sph_strerror(st));
    exit(1);
}

/* Unit box [0,1)^dim with N particles per side (cell-centred lattice), the
 * perturbation of the arrangement, periodic on every axis but x for the free
 * surface; neighbour list for kernel k and h; exact fields; summation density. */
static void scene_make(scene *s, int dim, int arr, int N, sph_kernel k, double h)
{
    const double dx = 1.0 / N, R = sph_kernel_support(k) * h;
    unsigned long long seed = 0x5eedULL + 977ULL * (unsigned long long)N + 31ULL * (unsigned long long)dim + (unsigned long long)arr;
    size_t bytes;
    sph_nsearch g;
    sph_view xv;
    int i, a, fi, st;
    memset(s, 0, sizeof *s);
    s->dim = dim, s->arr = arr, s->N = N, s->k = k, s->dx = dx, s->h = h;
    s->n = dim == 2 ? N * N : N * N * N;
    s->margin = R + arr_amp[arr] * dx; /* no target this far from a face has a wrapped neighbour */
    for (a = 0; a < 3; ++a) s->box.lo[a] = 0, s->box.length[a] = 1, s->box.periodic[a] = a < dim;
    if (arr == ARR_SURFACE) s->box.periodic[0] = 0;
    s->x = (sph_real *)xmalloc(sizeof(sph_real) * 3 * (size_t)s->n);
    s->V = (sph_real *)xmalloc(sizeof(sph_real) * (size_t)s->n);
    s->m = (sph_real *)xmalloc(sizeof(sph_real) * (size_t)s->n);
    s->rho = (sph_real *)xmalloc(sizeof(sph_real) * (size_t)s->n);
    s->out = (sph_real *)xmalloc(sizeof(sph_real) * 3 * (size_t)s->n);
    s->surf = (unsigned char *)xmalloc((size_t)s->n);
    s->inner = (unsigned char *)xmalloc((size_t)s->n);
    for (i = 0; i < s->n; ++i) {
        int rest = i;
        for (a = 0; a < 3; ++a) {
            double p = 0;
            if (a < dim) {
                p = ((double)(rest % N) + 0.5) * dx;
                rest /= N;
                if (arr_amp[arr] > 0) p += arr_amp[arr] * dx * (2 * uniform(&seed) - 1);
            }
            s->x[3 * i + a] = (sph_real)p;
        }
        s->V[i] = s->m[i] = (sph_real)pow(dx, dim); /* rho_0 = 1 */
    }
    for (i = 0; i < s->n; ++i) {
        int in = 1;
        for (a = 0; a < dim; ++a) {
            const double p = s->x[3 * i + a];
            if (arr == ARR_SURFACE && a == 0) continue;
            in &= p >= s->margin && p <= 1 - s->margin;
        }
        s->surf[i] = arr != ARR_SURFACE || s->x[3 * i] < dx;
        s->inner[i] = (unsigned char)(in && s->surf[i]);
    }
    for (fi = 0; fi < NFIELD; ++fi) {
        s->f[fi] = (sph_real *)xmalloc(sizeof(sph_real) * (size_t)s->n);
        s->fe[fi] = (double *)xmalloc(sizeof(double) * (size_t)s->n);
        s->ge[fi] = (double *)xmalloc(sizeof(double) * 3 * (size_t)s->n);
        s->le[fi] = (double *)xmalloc(sizeof(double) * (size_t)s->n);
        for (a = 0; a < 3; ++a) s->v[fi][a] = (sph_real *)xmalloc(sizeof(sph_real) * (size_t)s->n);
        for (i = 0; i < s->n; ++i) {
            double p[3];
            for (a = 0; a < 3; ++a) p[a] = s->x[3 * i + a];
            s->fe[fi][i] = field_eval(fi, dim, p, s->ge[fi] + 3 * i, s->le[fi] + i);
            s->f[fi][i] = (sph_real)s->fe[fi][i];
            for (a = 0; a < 3; ++a) s->v[fi][a][i] = (sph_real)(div_c[a] * s->fe[fi][i]);
        }
    }
    /* neighbour search: cells of kappa h / 2, gather radius kappa h */
    xv = sph_view_interleaved(s->x, 3);
    if ((st = sph_nsearch_workspace_size(dim, xv, s->n, sph_view_none(), (sph_real)(R / 2), &s->box, &bytes)))
        fail("sph_nsearch_workspace_size", st);
    s->work = xmalloc(bytes);
    if ((st = sph_nsearch_build(&g, dim, xv, s->n, sph_view_none(), (sph_real)(R / 2), &s->box, s->work, bytes)))
        fail("sph_nsearch_build", st);
    s->offset = (sph_off *)xmalloc(sizeof(sph_off) * ((size_t)s->n + 1));
    if ((st = sph_nsearch_count(&g, xv, s->n, sph_view_none(), (sph_real)h, sph_kernel_support(k), SPH_NSEARCH_GATHER,
                                s->offset)))
        fail("sph_nsearch_count", st);
    s->index = (sph_idx *)xmalloc(sizeof(sph_idx) * (size_t)s->offset[s->n]);
    if ((st = sph_nsearch_fill(&g, xv, s->n, sph_view_none(), (sph_real)h, sph_kernel_support(k), SPH_NSEARCH_GATHER,
                               s->offset, s->index, s->offset[s->n])))
        fail("sph_nsearch_fill", st);
    s->list = sph_nsearch_list(&g, s->n, s->offset, s->index);
    if ((st = sph_neighbours_check(&s->list))) fail("sph_neighbours_check", st);
    s->c = sph_ctx_init(k, dim, (sph_real)h, &s->list, xv);
    s->c.box = &s->box;
    s->c.V = sph_view_soa(s->V, NULL, NULL);
    s->c.m = sph_view_soa(s->m, NULL, NULL);
    s->c.validate = SPH_VALIDATE_ARGS; /* checked once above */
    if ((st = sph_density(&s->c, sph_out_soa(s->rho, NULL, NULL)))) fail("sph_density", st);
    s->c.rho = sph_view_soa(s->rho, NULL, NULL); /* the pressure form reads the summation density */
}

/* one operator call on field fi; writes s->out (interleaved, 3 per particle) */
static int op_call(scene *s, int op, int fi, sph_idx *fallback)
{
    const sph_view f = sph_view_soa(s->f[fi], NULL, NULL);
    const sph_view v = sph_view_soa(s->v[fi][0], s->v[fi][1], s->v[fi][2]);
    const sph_out o = sph_out_interleaved(s->out, 3);
    *fallback = 0;
    switch (op) {
    case OP_DENSITY: return sph_density(&s->c, o);
    case OP_INTERP: return sph_interpolate(&s->c, f, o);
    case OP_GRAD_STD: return sph_gradient(&s->c, SPH_SCHEME_STANDARD, f, sph_view_none(), o, NULL);
    case OP_GRAD_DIFF: return sph_gradient(&s->c, SPH_SCHEME_DIFFERENCE, f, sph_view_none(), o, NULL);
    case OP_GRAD_SYM: return sph_gradient(&s->c, SPH_SCHEME_SYMMETRIC, f, sph_view_none(), o, NULL);
    case OP_GRAD_CORR: return sph_gradient(&s->c, SPH_SCHEME_CORRECTED, f, sph_view_none(), o, fallback);
    case OP_GRAD_PRES: return sph_gradient(&s->c, SPH_SCHEME_PRESSURE, f, sph_view_none(), o, NULL);
    case OP_DIV_DIFF: return sph_divergence(&s->c, SPH_SCHEME_DIFFERENCE, v, sph_view_none(), o, NULL);
    case OP_DIV_CORR: return sph_divergence(&s->c, SPH_SCHEME_CORRECTED, v, sph_view_none(), o, fallback);
    default: return sph_laplacian(&s->c, f, sph_view_none(), o);
    }
}

/* L2 and max error of the last call against the analytic answer, over the
 * measured targets (all or the surface layer for the sine field; the
 * interior of those for the linear and quadratic fields, which are not periodic). */
static int op_error(const scene *s, int op, int fi, row *r)
{
    double se = 0, sx = 0, me = 0, mx = 0;
    const unsigned char *use = fi == FIELD_SINE ? s->surf : s->inner;
    int i, a, count = 0;
    for (i = 0; i < s->n; ++i) {
        double e2 = 0, x2 = 0;
        if (!use[i]) continue;
        ++count;
        if (op >= OP_GRAD_STD && op <= OP_GRAD_PRES) {
            for (a = 0; a < s->dim; ++a) {
                const double ex = s->ge[fi][3 * i + a], d = s->out[3 * i + a] - ex;
                e2 += d * d, x2 += ex * ex;
            }
        } else {
            double ex = op == OP_DENSITY ? 1 : op == OP_INTERP ? s->fe[fi][i] : op == OP_LAPLACIAN ? s->le[fi][i] : 0;
            if (op == OP_DIV_DIFF || op == OP_DIV_CORR)
                for (a = 0; a < s->dim; ++a) ex += div_c[a] * s->ge[fi][3 * i + a];
            e2 = (s->out[3 * i] - ex) * (s->out[3 * i] - ex), x2 = ex * ex;
        }
        se += e2, sx += x2;
        if (sqrt(e2) > me) me = sqrt(e2);
        if (sqrt(x2) > mx) mx = sqrt(x2);
    }
    r->n_measured = count;
    if (count == 0) return 0;
    r->absolute = !(sx > 1e-24 * count);
    r->L2 = r->absolute ? sqrt(se / count) : sqrt(se / sx);
    r->Lmax = r->absolute ? me : me / mx;
    return 1;
}

/* median time of one call (sine field) over `repeats` batches; a batch
 * repeats the call until it has done at least 2e4 pairs, so short calls are
 * timed reliably. The output of the last call stays in s->out. */
static double op_time(scene *s, int op, int repeats, sph_idx *fallback)
{
    const double pairs = (double)s->offset[s->n];
    const int batch = pairs >= 2e4 ? 1 : (int)ceil(2e4 / (pairs > 1 ? pairs : 1));
    double t[64];
    int r, b, st;
    if (repeats > 64) repeats = 64;
    for (r = 0; r < repeats; ++r) {
        const double t0 = tm_now();
        for (b = 0; b < batch; ++b)
            if ((st = op_call(s, op, FIELD_SINE, fallback))) fail("operator", st);
        t[r] = (tm_now() - t0) / batch;
    }
    return tm_median(t, repeats);
}

/* Every operator and field on one scene; rows appended to t. prev holds the
 * L2 errors of the previous resolution of the same series (for the order),
 * res is the resolution parameter of the sweep (h in A, dx/h in B). */
static void run_scene(table *t, const options *o, char sweep, int equal_sigma, int dim, int arr, int N,
                      sph_kernel k, double h, double res, double prev[NOP][NFIELD][2])
{
    scene s;
    int op, fi;
    const int nfield = dim == 3 && !o->full ? 1 : NFIELD; /* 3-D: the sine field only, unless --full */
    scene_make(&s, dim, arr, N, k, h);
    for (op = 0; op < NOP; ++op) {
        sph_idx fb = 0;
        const double tcall = op_time(&s, op, sweep == 'P' ? o->repeats : o->repeats_sweep, &fb);
        for (fi = 0; fi < nfield; ++fi) {
            row r;
            int st;
            if (op == OP_DENSITY && fi != FIELD_SINE) continue; /* density does not read a field */
            if (fi != FIELD_SINE && (st = op_call(&s, op, fi, &fb))) fail("operator", st); /* sine: the timed call */
            memset(&r, 0, sizeof r);
            r.sweep = sweep, r.equal_sigma = equal_sigma, r.dim = dim, r.arr = arr, r.N = N, r.op = op;
            r.field = op == OP_DENSITY ? -1 : fi, r.k = k, r.dx = s.dx, r.h = h;
            r.fallback = fb;
            r.neigh = (double)s.offset[s.n] / s.n;
            r.t_ns = 1e9 * tcall / s.n;
            r.pairs_s = (double)s.offset[s.n] / tcall;
            r.order = NAN;
            if (!op_error(&s, op, fi, &r)) continue;
            if (prev != NULL) {
                if (prev[op][fi][0] > 0 && r.L2 > 0) r.order = log(prev[op][fi][0] / r.L2) / log(prev[op][fi][1] / res);
                prev[op][fi][0] = r.L2, prev[op][fi][1] = res;
            }
            push(t, &r);
        }
    }
    scene_free(&s);
}

/* ------------------------------------------------------------- sweeps */

/* h of kernel k for a cubic-equivalent h_ref: equal h, or equal sigma h */
static double kernel_h(sph_kernel k, int dim, double h_ref, int equal_sigma)
{
    return equal_sigma ? h_ref * sph_kernel_sigma(SPH_KERNEL_CUBIC, dim) / sph_kernel_sigma(k, dim) : h_ref;
}

static void progress(const char *what, int dim, sph_kernel k, double t0)
{
    fprintf(stderr, "  %-8s %d-D %-12s %6.1f s (cpu %6.1f s)\n", what, dim, sph_kernel_name(k), tm_now() - t0, (double)clock() / CLOCKS_PER_SEC);
}

static int arr_in(unsigned set, int arr) { return (set >> arr) & 1u; }

/* The two sweeps over N in the list, for every kernel (at equal h and, from
 * es0, at equal sigma) and arrangement in arrs:
 *   'A': h = hval dx for the cubic (h -> 0 at fixed dx/h);
 *   'B': h = hval for the cubic (dx/h -> 0 at fixed h). */
static void sweep_n(table *t, const options *o, char which, int dim, const int *Ns, int nN, double hval,
                    int es0, unsigned arrs, double t0)
{
    int es, k, arr, i;
    for (k = 0; k < NK; ++k) {
        for (es = k == SPH_KERNEL_CUBIC ? 0 : es0; es < 2; ++es) {
            if (es == 1 && k == SPH_KERNEL_CUBIC) continue; /* equal sigma = equal h for the reference */
            for (arr = 0; arr < NARR; ++arr) {
                double prev[NOP][NFIELD][2];
                memset(prev, 0, sizeof prev);
                for (i = 0; arr_in(arrs, arr) && i < nN; ++i) {
                    const double h = kernel_h((sph_kernel)k, dim, which == 'A' ? hval / Ns[i] : hval, es);
                    run_scene(t, o, which, es, dim, arr, Ns[i], (sph_kernel)k, h,
                              which == 'A' ? h : (1.0 / Ns[i]) / h, prev);
                }
            }
        }
        progress(which == 'A' ? "sweep A" : "sweep B", dim, (sph_kernel)k, t0);
    }
}

/* Pareto scan: fixed N, h = c dx sigma_cubic / sigma_k for c in the ladder */
static void sweep_p(table *t, const options *o, int dim, int N, const double *ladder, int nl, unsigned arrs,
                    double t0)
{
    int k, arr, i;
    for (k = 0; k < NK; ++k) {
        for (arr = 0; arr < NARR; ++arr)
            for (i = 0; arr_in(arrs, arr) && i < nl; ++i)
                run_scene(t, o, 'P', 1, dim, arr, N, (sph_kernel)k, kernel_h((sph_kernel)k, dim, ladder[i] / N, 1), 0, NULL);
        progress("pareto", dim, (sph_kernel)k, t0);
    }
}

/* ------------------------------------------------------------- Pareto */

static const table *cmp_tab; /* the table qsort's comparison reads */
static int cmp_row_time(const void *a, const void *b)
{
    const row *x = &cmp_tab->r[*(const size_t *)a], *y = &cmp_tab->r[*(const size_t *)b];
    if (x->t_ns != y->t_ns) return x->t_ns < y->t_ns ? -1 : 1;
    return x->L2 < y->L2 ? -1 : x->L2 > y->L2;
}

/* rows of the Pareto scan for (group, dim, arr, sine field), sorted by time */
static size_t pareto_select(const table *t, int group, int dim, int arr, size_t *idx)
{
    size_t i, n = 0;
    for (i = 0; i < t->n; ++i) {
        const row *r = &t->r[i];
        if (r->sweep == 'P' && op_group_id(r->op) == group && r->dim == dim && r->arr == arr &&
            (r->field == FIELD_SINE || r->field == -1))
            idx[n++] = i;
    }
    cmp_tab = t;
    qsort(idx, n, sizeof(size_t), cmp_row_time);
    return n;
}

/* Marks in front[] the rows of idx[0..n-1] (sorted by time) that no faster
 * row beats in L2 error; returns the count. */
static size_t pareto_front(const table *t, const size_t *idx, size_t n, unsigned char *front)
{
    double best = INFINITY;
    size_t i, count = 0;
    for (i = 0; i < n; ++i) {
        front[i] = t->r[idx[i]].L2 < best;
        if (front[i]) best = t->r[idx[i]].L2, ++count;
    }
    return count;
}

/* -------------------------------------------------------------- output */

static FILE *open_out(const char *dir, const char *name)
{
    char path[1024];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "w");
    if (f == NULL) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    return f;
}

static const char *row_field(const row *r) { return r->field < 0 ? "-" : field_name[r->field]; }

static void fmt_order(char *buf, size_t n, double order)
{
    if (order != order) snprintf(buf, n, "-");
    else snprintf(buf, n, "%.2f", order);
}

static void write_rows_csv(const table *t, const char *dir)
{
    FILE *f = open_out(dir, "rows.csv");
    size_t i;
    fprintf(f, "sweep,kernels_at,dim,arrangement,kernel,N,dx,h,h_over_dx,sigma_h_over_dx,operator,scheme,field,"
               "n_measured,L2,max,errors,order,neighbours,time_ns_per_particle,pairs_per_s,fallbacks\n");
    for (i = 0; i < t->n; ++i) {
        const row *r = &t->r[i];
        char ord[32];
        fmt_order(ord, sizeof ord, r->order);
        fprintf(f, "%c,%s,%d,%s,%s,%d,%.6g,%.6g,%.4f,%.4f,%s,%s,%s,%d,%.4e,%.4e,%s,%s,%.2f,%.2f,%.4e,%ld\n",
                r->sweep, r->equal_sigma ? "equal_sigma" : "equal_h", r->dim, arr_name[r->arr], sph_kernel_name(r->k),
                r->N, r->dx, r->h, r->h / r->dx, sph_kernel_sigma(r->k, r->dim) * r->h / r->dx, op_group[r->op],
                op_scheme[r->op], row_field(r), r->n_measured, r->L2, r->Lmax, r->absolute ? "absolute" : "relative", ord,
                r->neigh, r->t_ns, r->pairs_s, r->fallback);
    }
    fclose(f);
}

static void choice(const row *r, char *buf, size_t n)
{
    if (strcmp(op_scheme[r->op], "-") == 0)
        snprintf(buf, n, "%s, h = %.2f dx", sph_kernel_name(r->k), r->h / r->dx);
    else
        snprintf(buf, n, "%s, h = %.2f dx, %s", sph_kernel_name(r->k), r->h / r->dx, op_scheme[r->op]);
}

/* pareto_<group>.csv: every point of the scan (dim, arrangement); the front
 * flagged. The markdown gets the front as a table per dim for arrangement
 * `headline` and a one-line list for the others. */
static void write_pareto(const table *t, const char *dir, FILE *md, int headline)
{
    size_t *idx = (size_t *)xmalloc(sizeof(size_t) * (t->n + 1));
    unsigned char *front = (unsigned char *)xmalloc(t->n + 1);
    int g, dim, arr;
    for (g = 0; g < NGROUP; ++g) {
        char name[64];
        FILE *f, *ff;
        snprintf(name, sizeof name, "pareto_%s.csv", group_name[g]);
        f = open_out(dir, name);
        fprintf(f, "dim,arrangement,kernel,kernel_id,h_over_dx,scheme,scheme_id,time_ns_per_particle,L2,max,front\n");
        snprintf(name, sizeof name, "pareto_front_%s.csv", group_name[g]);
        ff = open_out(dir, name);
        fprintf(ff, "# the front of pareto_%s.csv, one block per (dim, arrangement): gnuplot index (dim-2)*4 + arrangement\n",
                group_name[g]);
        fprintf(md, "\n### %s\n\n", group_name[g]);
        fprintf(md, "![%s: L2 error against time per particle](report/pareto_%s.png)\n\n", group_name[g], group_name[g]);
        for (dim = 2; dim <= 3; ++dim)
            for (arr = 0; arr < NARR; ++arr) {
                const size_t n = pareto_select(t, g, dim, arr, idx);
                size_t i;
                pareto_front(t, idx, n, front);
                for (i = 0; i < n; ++i) {
                    const row *r = &t->r[idx[i]];
                    fprintf(f, "%d,%s,%s,%d,%.3f,%s,%d,%.3f,%.4e,%.4e,%d\n", dim, arr_name[arr], sph_kernel_name(r->k),
                            (int)r->k, r->h / r->dx, op_scheme[r->op], r->op, r->t_ns, r->L2, r->Lmax, front[i]);
                    if (front[i])
                        fprintf(ff, "%d,%s,%s,%d,%.3f,%s,%d,%.3f,%.4e,%.4e,1\n", dim, arr_name[arr],
                                sph_kernel_name(r->k), (int)r->k, r->h / r->dx, op_scheme[r->op], r->op, r->t_ns, r->L2,
                                r->Lmax);
                }
                if (n == 0) /* gnuplot merges empty blocks: keep every index with one invalid point */
                    fprintf(ff, "%d,%s,-,-1,nan,-,-1,nan,nan,nan,0\n", dim, arr_name[arr]);
                fprintf(ff, "\n\n");
                if (arr == headline) {
                    fprintf(md, "%d-D, %s, sine field, N = %d per side:\n\n", dim, arr_name[arr], t->r[idx[0]].N);
                    fprintf(md, "| time budget (ns / particle) | least-error choice | L2 | max | neighbours |\n|---|---|---|---|---|\n");
                    for (i = 0; i < n; ++i)
                        if (front[i]) {
                            const row *r = &t->r[idx[i]];
                            char c[128];
                            choice(r, c, sizeof c);
                            fprintf(md, "| %.1f | %s | %.2e | %.2e | %.1f |\n", r->t_ns, c, r->L2, r->Lmax, r->neigh);
                        }
                    fprintf(md, "\n");
                }
            }
        fprintf(md, "Fronts of the other arrangements (from the fastest to the most accurate choice; time in ns / particle, L2 error):\n\n");
        for (dim = 2; dim <= 3; ++dim)
            for (arr = 0; arr < NARR; ++arr) {
                const size_t n = pareto_select(t, g, dim, arr, idx);
                size_t i;
                if (arr == headline || n == 0) continue;
                pareto_front(t, idx, n, front);
                fprintf(md, "- %d-D %s:", dim, arr_name[arr]);
                for (i = 0; i < n; ++i)
                    if (front[i]) {
                        const row *r = &t->r[idx[i]];
                        char c[128];
                        choice(r, c, sizeof c);
                        fprintf(md, " %s (%.0f ns, %.1e);", c, r->t_ns, r->L2);
                    }
                fprintf(md, "\n");
            }
        fclose(f), fclose(ff);
    }
    free(idx), free(front);
}

/* A row lookup: the row of (sweep, es, dim, arr, kernel, N, op, field) */
static const row *find(const table *t, char sweep, int es, int dim, int arr, sph_kernel k, int N, int op, int field)
{
    size_t i;
    for (i = 0; i < t->n; ++i) {
        const row *r = &t->r[i];
        if (r->sweep == sweep && r->equal_sigma == es && r->dim == dim && r->arr == arr && r->k == k && r->N == N &&
            r->op == op && r->field == (op == OP_DENSITY ? -1 : field))
            return r;
    }
    return NULL;
}

/* sweep tables: per dim and arrangement, kernel rows, operator columns,
 * entries "L2 at the finest resolution (order against the previous one)" */
static void md_sweep_tables(FILE *md, const table *t, char sweep, int dim, int Nlast, int field, int es)
{
    int arr, k, op;
    for (arr = 0; arr < NARR; ++arr) {
        if (find(t, sweep, 0, dim, arr, SPH_KERNEL_CUBIC, Nlast, OP_INTERP, field) == NULL) continue;
        fprintf(md, "\n%d-D, %s, %s field, kernels at %s, N = %d per side: L2 error (observed order)\n\n", dim,
                arr_name[arr], field_name[field], es ? "equal sigma h" : "equal h", Nlast);
        fprintf(md, "| kernel | h/dx |");
        for (op = 0; op < NOP; ++op) fprintf(md, " %s%s%s |", op_group[op], op_scheme[op][0] == '-' ? "" : " ", op_scheme[op][0] == '-' ? "" : op_scheme[op]);
        fprintf(md, "\n|---|---|");
        for (op = 0; op < NOP; ++op) fprintf(md, "---|");
        fprintf(md, "\n");
        for (k = 0; k < NK; ++k) {
            const int e = k == SPH_KERNEL_CUBIC ? 0 : es;
            const row *r0 = find(t, sweep, e, dim, arr, (sph_kernel)k, Nlast, OP_INTERP, field);
            if (r0 == NULL) continue;
            fprintf(md, "| %s | %.2f |", sph_kernel_name((sph_kernel)k), r0->h / r0->dx);
            for (op = 0; op < NOP; ++op) {
                const row *r = find(t, sweep, e, dim, arr, (sph_kernel)k, Nlast, op, field);
                char ord[32];
                if (r == NULL) {
                    fprintf(md, " - |");
                    continue;
                }
                fmt_order(ord, sizeof ord, r->order);
                fprintf(md, " %.2e (%s) |", r->L2, ord);
            }
            fprintf(md, "\n");
        }
    }
}

/* sweep_<A|B>.csv for the plots: difference and corrected gradient and the
 * Laplacian, sine field, every kernel at equal sigma h; one block per
 * (dim, arrangement, operator, kernel) in resolution order, blocks separated
 * by two blank lines (gnuplot index ((dim-2)*4 + arrangement)*3*NK + operator*NK + kernel) */
static void write_sweep_csv(const table *t, const char *dir, char sweep)
{
    static const int ops[3] = {OP_GRAD_DIFF, OP_GRAD_CORR, OP_LAPLACIAN};
    char name[32];
    FILE *f;
    int dim, arr, o, k;
    size_t i;
    snprintf(name, sizeof name, "sweep_%c.csv", sweep);
    f = open_out(dir, name);
    fprintf(f, "# dim,arrangement,kernel,kernel_id,operator,scheme,N,h,dx_over_h,L2\n");
    for (dim = 2; dim <= 3; ++dim)
        for (arr = 0; arr < NARR; ++arr)
            for (o = 0; o < 3; ++o)
                for (k = 0; k < NK; ++k) {
                    int written = 0;
                    for (i = 0; i < t->n; ++i) {
                        const row *r = &t->r[i];
                        if (r->sweep != sweep || r->field != FIELD_SINE || r->dim != dim || r->arr != arr ||
                            r->op != ops[o] || (int)r->k != k || r->equal_sigma != (k != SPH_KERNEL_CUBIC))
                            continue;
                        fprintf(f, "%d,%s,%s,%d,%s,%s,%d,%.6g,%.6g,%.4e\n", r->dim, arr_name[r->arr],
                                sph_kernel_name(r->k), (int)r->k, op_group[r->op], op_scheme[r->op], r->N, r->h,
                                r->dx / r->h, r->L2);
                        ++written;
                    }
                    if (!written) /* gnuplot merges empty blocks: keep every index with one invalid point */
                        fprintf(f, "%d,%s,-,%d,-,-,0,nan,nan,nan\n", dim, arr_name[arr], k);
                    fprintf(f, "\n\n");
                }
    fclose(f);
}

/* ----------------------------------------------------------- --check */

static int expect(int ok, const char *what, double value)
{
    printf("%s %s (%.3g)\n", ok ? "ok  " : "FAIL", what, value);
    return ok ? 0 : 1;
}

/* A short run: 2-D, cubic and Wendland C2, sweep A at N = 16, 32, 64 and a
 * Pareto scan at N = 24; asserts properties known from the analysis of
 * docs/operators.md. */
static int run_check(const options *o)
{
    static const int Ns[3] = {16, 32, 64};
    static const double ladder[3] = {1.0, 1.3, 1.8};
    table t = {NULL, 0, 0};
    const row *r;
    int bad = 0, k, i;
    size_t *idx, n, nf;
    unsigned char *front;
    for (k = 0; k < 2; ++k) {
        const sph_kernel kk = k ? SPH_KERNEL_WENDLAND_C2 : SPH_KERNEL_CUBIC;
        int arr;
        for (arr = 0; arr < NARR; arr += 2) { /* lattice and perturbed 30 % */
            double prev[NOP][NFIELD][2];
            memset(prev, 0, sizeof prev);
            for (i = 0; i < 3; ++i) run_scene(&t, o, 'A', 0, 2, arr, Ns[i], kk, 1.3 / Ns[i], 1.3 / Ns[i], prev);
        }
        for (i = 0; i < 3; ++i) run_scene(&t, o, 'P', 1, 2, ARR_PERT10, 24, kk, ladder[i] / 24, 0, NULL);
    }
    /* sine on the periodic lattice: second order in h (the lattice cancels odd terms) */
    /* sine on the periodic lattice: the corrected gradient and interpolation
     * converge at order 2 in h; the uncorrected derivatives carry the lattice
     * factor mu - 1, constant at fixed dx/h (docs/operators.md) */
    r = find(&t, 'A', 0, 2, ARR_LATTICE, SPH_KERNEL_CUBIC, 64, OP_GRAD_CORR, FIELD_SINE);
    bad += expect(r && r->order > 1.7 && r->order < 2.3, "cubic lattice sine corrected gradient: order in (1.7, 2.3)", r ? r->order : 0);
    r = find(&t, 'A', 0, 2, ARR_LATTICE, SPH_KERNEL_CUBIC, 64, OP_INTERP, FIELD_SINE);
    bad += expect(r && r->order > 1.7 && r->order < 2.3, "cubic lattice sine interpolation: order in (1.7, 2.3)", r ? r->order : 0);
    r = find(&t, 'A', 0, 2, ARR_LATTICE, SPH_KERNEL_CUBIC, 64, OP_GRAD_DIFF, FIELD_SINE);
    bad += expect(r && r->L2 > 2e-3 && r->L2 < 2e-2, "cubic lattice sine difference gradient: L2 near |mu - 1| = 1.05e-2 less h^2 term", r ? r->L2 : 0);
    r = find(&t, 'A', 0, 2, ARR_LATTICE, SPH_KERNEL_CUBIC, 64, OP_DENSITY, -1);
    bad += expect(r && r->L2 < 2e-2, "cubic lattice density within 2 % of rho_0", r ? r->L2 : 0);
    /* corrected schemes are exact for linear fields on any cloud */
    r = find(&t, 'A', 0, 2, ARR_PERT30, SPH_KERNEL_CUBIC, 32, OP_GRAD_CORR, FIELD_LINEAR);
    bad += expect(r && r->L2 < 1e-10, "corrected gradient of a linear field on 30 % disorder: L2 < 1e-10", r ? r->L2 : 1);
    r = find(&t, 'A', 0, 2, ARR_PERT30, SPH_KERNEL_WENDLAND_C2, 32, OP_DIV_CORR, FIELD_LINEAR);
    bad += expect(r && r->L2 < 1e-10, "corrected divergence of a linear field on 30 % disorder: L2 < 1e-10", r ? r->L2 : 1);
    /* the standard gradient does not converge on disorder at fixed dx/h */
    r = find(&t, 'A', 0, 2, ARR_PERT30, SPH_KERNEL_CUBIC, 64, OP_GRAD_STD, FIELD_SINE);
    bad += expect(r && r->L2 > 0.1 && r->order < 0.5, "standard gradient on 30 % disorder: L2 > 0.1, order < 0.5", r ? r->L2 : 0);
    /* the Pareto front is non-empty, sorted, and no point beats a front point on both axes */
    idx = (size_t *)xmalloc(sizeof(size_t) * t.n);
    front = (unsigned char *)xmalloc(t.n);
    n = pareto_select(&t, 2, 2, ARR_PERT10, idx);
    nf = pareto_front(&t, idx, n, front);
    {
        size_t a, b;
        int dominated = 0;
        for (a = 0; a < n; ++a)
            for (b = 0; b < n; ++b)
                if (front[a] && t.r[idx[b]].t_ns < t.r[idx[a]].t_ns && t.r[idx[b]].L2 < t.r[idx[a]].L2) dominated = 1;
        bad += expect(n == 30 && nf >= 1 && !dominated, "gradient Pareto front: 30 points, front non-empty and non-dominated",
                      (double)nf);
    }
    nf = 0;
    for (i = 0; i < (int)t.n; ++i) nf += t.r[i].t_ns > 0 && t.r[i].L2 == t.r[i].L2 ? 0 : 1;
    bad += expect(nf == 0, "every row has a positive time and a finite error (rows)", (double)t.n);
    free(idx), free(front), free(t.r);
    printf("%s\n", bad ? "error_vs_runtime --check: FAILED" : "error_vs_runtime --check: all passed");
    return bad ? 1 : 0;
}

/* ------------------------------------------------------------ report */

static void list_int(char *buf, size_t n, const int *v, int count)
{
    int i;
    size_t used = 0;
    buf[0] = 0;
    for (i = 0; i < count && used < n; ++i) used += (size_t)snprintf(buf + used, n - used, i ? ", %d" : "%d", v[i]);
}

static void list_real(char *buf, size_t n, const double *v, int count)
{
    int i;
    size_t used = 0;
    buf[0] = 0;
    for (i = 0; i < count && used < n; ++i) used += (size_t)snprintf(buf + used, n - used, i ? ", %g" : "%g", v[i]);
}

static void md_guide(FILE *md, const options *o, int threads)
{
    char machine[512];
    tm_machine(machine, sizeof machine);
    fprintf(md,
            "# Error against run time\n\n"
            "Generated by `studies/error_vs_runtime.c` (`make report`%s); every number below comes from that run. "
            "All rows are in [report/rows.csv](report/rows.csv). Times measured on: %s.\n\n"
            "The same question for whole solvers, the Gresho-Chan vortex and the Sod shock tube (the error of the "
            "flow against the CPU time of the run): [flows.md](flows.md) (`make report-flows`).\n\n",
            o->full ? " with `--full`" : "", machine);
    fprintf(md,
            "## Reading guide\n\n"
            "Each row is one operator of `sph_kernel.h` applied to one field on one particle arrangement, compared "
            "with the analytic answer:\n\n"
            "- **operators**: density `sum m_j W_ij` (exact answer rho_0 = 1), interpolation `sum V_j f_j W_ij`, the "
            "gradient in the standard, difference, symmetric, corrected and pressure forms, the divergence of "
            "`v = (1, -0.5, 0.25) f` in the difference and corrected forms, the Laplacian (Brookshaw/Morris); "
            "formulas in [operators.md](../operators.md). The pressure form reads the summation density; every other "
            "operator reads `V_j = dx^d`.\n"
            "- **fields**: `sin(2 pi x) sin(2 pi y)` (3-D: times `sin(2 pi z)`) in the periodic unit box; the "
            "linear `0.7 + 1.3x - 0.8y + 0.4z` and the quadratic `0.5 + x^2 - xy + y^2/2 + z^2`, which are not "
            "periodic, are measured only at targets farther than `kappa h` (plus the perturbation) from a box face, "
            "so that no neighbour is a periodic image.\n"
            "- **arrangements**: `lattice` (cell-centred, N per side, dx = 1/N); `perturbed10`/`perturbed30`: every "
            "coordinate moved by a uniform random amount in +-10 %% / +-30 %% of dx (fixed seed); `surface`: the "
            "lattice with a free surface at x = 0 (x not periodic), errors measured on the outermost layer x < dx.\n"
            "- **L2** = sqrt(sum |e_i|^2 / sum |exact_i|^2) and **max** = max |e_i| / max |exact_i| over the measured "
            "targets (|.| the Euclidean norm for gradients). Where the exact answer is 0 (Laplacian of the linear "
            "field) the errors are absolute (column `errors` of the CSV).\n"
            "- **order**: observed convergence order between successive resolutions of a sweep, "
            "log(e_prev / e) / log(res_prev / res), res = h in sweep A and dx/h in sweep B.\n"
            "- **neighbours**: list entries per particle (self included); **time**: median over %d (Pareto scan) / "
            "%d (sweeps) repeats of one "
            "operator call (list prebuilt, validated once, `SPH_VALIDATE_ARGS`), divided by the particle count; "
            "**pairs/s**: list entries per second of that call. %d OpenMP thread%s, `sph_real` = %s.\n\n"
            "How the sweeps relate to the error (Quinlan, Basa & Lastiwka 2006, *Truncation error in mesh-free "
            "particle methods*, Int. J. Numer. Meth. Engng 66:2064-2085). The error of an SPH estimate is the "
            "**smoothing error** of the continuous kernel integral, `sigma^2 h^2 / 2 lap f` for interpolation and "
            "O(h^2) for every derivative (sigma = `sph_kernel_sigma`, the kernel's standard deviation in units of h), "
            "plus the **discretisation error** of replacing the integral by a sum over particles, which depends on "
            "dx/h and on the disorder, and for derivatives grows like 1/h at fixed dx/h on a disordered cloud:\n\n"
            "- **sweep A** (h -> 0 at fixed dx/h): on a lattice the sum is nearly exact and the error falls as h^2 "
            "(order 2); on disorder the discretisation error does not fall with h, so the uncorrected gradients level "
            "off or grow (order <= 0) - refining at fixed h/dx does not converge.\n"
            "- **sweep B** (dx/h -> 0 at fixed h): the discretisation error vanishes (fast on lattices, slowly on "
            "disorder) and the error levels off at the smoothing error of that h - the floor the kernel's width "
            "sets.\n"
            "- kernels are compared at **equal h** (same h for every kernel: wide kernels like the quintic look "
            "expensive and smooth, Lucy cheap and noisy) and at **equal resolution**, equal sigma h, the cubic's h "
            "being the reference (the fair comparison: equal smoothing error to leading order).\n"
            "- **Pareto front**: at a fixed particle count (the Pareto scan, sweep P: every kernel at "
            "sigma_k h = c sigma_cubic dx for a ladder of c) each (kernel, h, scheme) is a point (time per particle, "
            "L2 error). A point is on the front when no faster point has a smaller error; read a front table as "
            "*for this time budget, this choice gives the least error*. Points off the front are never worth "
            "their time for that problem.\n\n",
            o->repeats, o->repeats_sweep, threads, threads == 1 ? "" : "s",
            sizeof(sph_real) == sizeof(float) ? "float" : "double");
}

int main(int argc, char **argv)
{
    options o;
    table t = {NULL, 0, 0};
    int i, threads = 1;
    double t0 = tm_now();
    char dir[1024];
    FILE *md;
    o.full = 0, o.check = 0, o.repeats = 5, o.repeats_sweep = 3, o.out = "docs/results";
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--full") == 0) o.full = 1;
        else if (strcmp(argv[i], "--check") == 0) o.check = 1;
        else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) o.out = argv[++i];
        else if (strcmp(argv[i], "--repeats") == 0 && i + 1 < argc) o.repeats = o.repeats_sweep = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: %s [--full] [--out DIR] [--repeats R] | --check\n", argv[0]);
            return 2;
        }
    }
    if (o.repeats < 1) o.repeats = 1;
    if (o.repeats_sweep < 1) o.repeats_sweep = 1;
#ifdef _OPENMP
    threads = omp_get_max_threads();
#endif
    if (o.check) {
        o.repeats = o.repeats_sweep = 3;
        return run_check(&o);
    }
    {
        /* the sweeps: particle counts per side, h (cubic), kernel comparisons */
        static const int A2[] = {12, 24, 48, 96, 192}, A3[] = {8, 12, 16, 24, 32}, A3d[] = {8, 10, 12};
        static const int B2[] = {12, 18, 24, 30, 36, 48, 72}, B2f[] = {12, 18, 24, 36, 48, 72};
        static const int B3[] = {8, 10, 12}, B3f[] = {8, 12, 16, 24};
        static const double L2d[] = {1.0, 1.3, 1.6, 2.0}, L3d[] = {1.0, 1.3, 1.6};
        static const double Lf[] = {0.9, 1.0, 1.15, 1.3, 1.5, 1.75, 2.0, 2.5, 3.0};
        const int *a3 = o.full ? A3 : A3d, *b2 = o.full ? B2f : B2, *b3 = o.full ? B3f : B3;
        const int na2 = o.full ? 5 : 3, na3 = o.full ? 5 : 3, nb2 = o.full ? 6 : 4, nb3 = o.full ? 4 : 3;
        const int es_a3 = o.full ? 0 : 1, es_b = o.full ? 0 : 1; /* 1: equal sigma h only (and the cubic) */
        const int np2 = o.full ? 32 : 24, np3 = o.full ? 12 : 10;
        const double *l2 = o.full ? Lf : L2d, *l3 = o.full ? Lf : L3d;
        const int nl2 = o.full ? 9 : 4, nl3 = o.full ? 6 : 3;
        const unsigned p3arrs = o.full ? 15u : (1u << ARR_PERT10) | (1u << ARR_SURFACE);
        const unsigned s3arrs = o.full ? 15u : 15u & ~(1u << ARR_PERT30);
        char la2[64], la3[64], lb2[64], lb3[64], lp2[96], lp3[96];
        fprintf(stderr, "error_vs_runtime: %s run, %d thread(s), %d / %d repeats\n", o.full ? "full" : "default", threads,
                o.repeats, o.repeats_sweep);
        sweep_n(&t, &o, 'A', 2, A2, na2, 1.3, 0, 15u, t0);
        sweep_n(&t, &o, 'A', 3, a3, na3, 1.3, es_a3, s3arrs, t0);
        sweep_n(&t, &o, 'B', 2, b2, nb2, 1.0 / 12, es_b, 15u, t0);
        sweep_n(&t, &o, 'B', 3, b3, nb3, 1.0 / 8, es_b, s3arrs, t0);
        sweep_p(&t, &o, 2, np2, l2, nl2, 15u, t0);
        sweep_p(&t, &o, 3, np3, l3, nl3, p3arrs, t0);
        list_int(la2, sizeof la2, A2, na2), list_int(la3, sizeof la3, a3, na3);
        list_int(lb2, sizeof lb2, b2, nb2), list_int(lb3, sizeof lb3, b3, nb3);
        list_real(lp2, sizeof lp2, l2, nl2), list_real(lp3, sizeof lp3, l3, nl3);
        snprintf(dir, sizeof dir, "%s/report", o.out);
        write_rows_csv(&t, dir);
        write_sweep_csv(&t, dir, 'A');
        write_sweep_csv(&t, dir, 'B');
        snprintf(dir, sizeof dir, "%s/report.md", o.out);
        md = fopen(dir, "w");
        if (md == NULL) {
            fprintf(stderr, "cannot write %s\n", dir);
            return 1;
        }
        md_guide(md, &o, threads);
        fprintf(md, "## What was run\n\n"
                    "| set | 2-D | 3-D | kernels at |\n|---|---|---|---|\n"
                    "| sweep A (h = 1.3 dx for the cubic) | N = %s, every arrangement | N = %s, %s | 2-D: equal h and equal sigma h; 3-D: %s |\n"
                    "| sweep B (h = 1/12 (2-D), 1/8 (3-D) for the cubic) | N = %s, every arrangement | N = %s, %s | %s |\n"
                    "| Pareto scan (sigma_k h = c sigma_cubic dx) | N = %d, c = %s, every arrangement | N = %d, c = %s, %s | equal sigma h ladder |\n\n"
                    "Fields: sine, linear and quadratic in 2-D; %s in 3-D. N is the number of particles per side of "
                    "the unit box; `make report-full` (`--full`) runs longer sweeps with every comparison.\n\n",
                la2, la3, o.full ? "every arrangement" : "lattice, perturbed10, surface",
                es_a3 ? "equal sigma h" : "equal h and equal sigma h", lb2, lb3,
                o.full ? "every arrangement" : "lattice, perturbed10, surface",
                es_b ? "equal sigma h" : "equal h and equal sigma h", np2, lp2, np3, lp3,
                o.full ? "every arrangement" : "perturbed10 and surface", o.full ? "all three" : "the sine field only");
        fprintf(md, "## Pareto fronts: least error for a time budget\n\n"
                    "Points: every kernel x h x scheme of the Pareto scan, sine field; colours are kernels, "
                    "symbols schemes (circle: difference or the only form, square: standard, triangle: symmetric, "
                    "diamond: corrected, inverted triangle: pressure), the black staircase is the front. Tables: the "
                    "front for the perturbed 10 %% lattice; lists: the fronts of the other arrangements.\n");
        snprintf(dir, sizeof dir, "%s/report", o.out);
        write_pareto(&t, dir, md, ARR_PERT10);
        fprintf(md, "\n## Sweep A: h -> 0 at fixed dx/h\n\n"
                    "h = 1.3 dx for the cubic (and for every kernel at equal h; at equal sigma h the other kernels "
                    "scale h by sigma_cubic / sigma_k). N = %s per side in 2-D, %s in 3-D.\n\n"
                    "![sweep A, 2-D](report/sweep_A_2d.png)\n![sweep A, 3-D](report/sweep_A_3d.png)\n",
                la2, la3);
        md_sweep_tables(md, &t, 'A', 2, A2[na2 - 1], FIELD_SINE, 1);
        md_sweep_tables(md, &t, 'A', 3, a3[na3 - 1], FIELD_SINE, 1);
        fprintf(md, "\nAt equal h, 2-D, and the quadratic field:\n");
        md_sweep_tables(md, &t, 'A', 2, A2[na2 - 1], FIELD_QUADRATIC, 0);
        fprintf(md, "\nThe linear field, 2-D at equal h (the corrected schemes are exact on every arrangement):\n");
        md_sweep_tables(md, &t, 'A', 2, A2[na2 - 1], FIELD_LINEAR, 0);
        fprintf(md, "\n## Sweep B: dx/h -> 0 at fixed h\n\n"
                    "h = 1/12 (2-D) and 1/8 (3-D) for the cubic, the other kernels at equal sigma h; N = %s (2-D), "
                    "%s (3-D), so h/dx runs from 1 to %.1f (2-D) and %.1f (3-D) for the cubic.\n\n"
                    "![sweep B, 2-D](report/sweep_B_2d.png)\n![sweep B, 3-D](report/sweep_B_3d.png)\n",
                lb2, lb3, b2[nb2 - 1] / 12.0, b3[nb3 - 1] / 8.0);
        md_sweep_tables(md, &t, 'B', 2, b2[nb2 - 1], FIELD_SINE, 1);
        md_sweep_tables(md, &t, 'B', 3, b3[nb3 - 1], FIELD_SINE, 1);
        fprintf(md, "\n## Files\n\n"
                    "- `report/rows.csv`: every row (%lu): sweep (A, B, P), kernels_at (equal_h, equal_sigma), dim, "
                    "arrangement, kernel, N, dx, h, h/dx, sigma h/dx, operator, scheme, field, targets measured, L2, max, "
                    "errors (relative/absolute), order, neighbours per particle, time per particle (ns), pairs per second, "
                    "corrected-scheme fallbacks.\n"
                    "- `report/pareto_<operator>.csv`: the Pareto scan per operator with the front flagged "
                    "(`pareto_front_<operator>.csv`: the front alone); `report/sweep_A.csv`, `report/sweep_B.csv`: the "
                    "data of the sweep plots.\n"
                    "- Plots: `gnuplot -e \"dir='docs/results/report'\" studies/report.gp` (run by `make report` when gnuplot "
                    "is installed).\n\n"
                    "Run time of this report: %.0f s wall clock, %.0f s processor time.\n",
                (unsigned long)t.n, tm_now() - t0, (double)clock() / CLOCKS_PER_SEC);
        fclose(md);
        fprintf(stderr, "error_vs_runtime: %lu rows, %.1f s\n", (unsigned long)t.n, tm_now() - t0);
    }
    free(t.r);
    return 0;
}
