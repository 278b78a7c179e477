/* Operators on particles sorted by cell (sph_nsearch_permutation +
 * sph_permute, the locality optimisation of docs/neighbours.md) give the
 * results of the original order once un-permuted.
 *
 * Not bitwise: sorting changes the order in which each target's sum meets
 * its neighbours. A sum of n terms t_j reordered differs by at most
 * 2 (n - 1) eps sum_j |t_j| (the standard bound for recursive summation,
 * Higham, "Accuracy and Stability of Numerical Algorithms", eq. (4.3)); the
 * test computes sum_j |t_j| of every target from the pair terms and asserts
 * that bound, for the density (O2) and the difference gradient (O5).
 */
#include "harness.h"
#include "support/particles.h"

#include <stdlib.h>

typedef struct {
    sph_nsearch g;
    void *work;
    sph_off *off;
    sph_idx *idx;
    sph_neighbours list;
} nl;

/* Neighbour list of the points x (interleaved, 3 slots) on themselves. */
static int build(nl *L, int dim, const sph_real *x, int n, sph_real h, const sph_box *box)
{
    const sph_view v = sph_view_interleaved(x, 3);
    const sph_real kappa = sph_kernel_support(SPH_KERNEL_CUBIC);
    size_t bytes = 0;
    int st = sph_nsearch_workspace_size(dim, v, n, sph_view_none(), kappa * h / 2, box, &bytes);
    L->work = malloc(bytes > 0 ? bytes : 1);
    L->off = (sph_off *)malloc(sizeof(sph_off) * (size_t)(n + 1));
    if (st != SPH_OK || L->work == NULL || L->off == NULL) return SPH_ESIZE;
    st = sph_nsearch_build(&L->g, dim, v, n, sph_view_none(), kappa * h / 2, box, L->work, bytes);
    if (st == SPH_OK) st = sph_nsearch_count(&L->g, v, n, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, L->off);
    if (st != SPH_OK) return st;
    L->idx = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)(L->off[n] > 0 ? L->off[n] : 1));
    if (L->idx == NULL) return SPH_ESIZE;
    st = sph_nsearch_fill(&L->g, v, n, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, L->off, L->idx, L->off[n]);
    L->list = sph_nsearch_list(&L->g, n, L->off, L->idx);
    return st;
}

static void nl_free(nl *L)
{
    free(L->work), free(L->off), free(L->idx);
}

/* Density and difference gradient of f into rho[n] and grad[3 n]. */
static int run_ops(const nl *L, int dim, const sph_real *x, const sph_real *V, const sph_real *f, sph_real h,
                   const sph_box *box, sph_real *rho, sph_real *grad)
{
    sph_ctx c = sph_ctx_init(SPH_KERNEL_CUBIC, dim, h, &L->list, sph_view_interleaved(x, 3));
    c.box = box;
    c.m = c.V = sph_view_soa(V, NULL, NULL);
    return sph_density(&c, sph_out_soa(rho, NULL, NULL)) |
           sph_gradient(&c, SPH_SCHEME_DIFFERENCE, sph_view_soa(f, NULL, NULL), sph_view_none(),
                        sph_out_interleaved(grad, 3), NULL);
}

static void test_sorted(int dim, int periodic)
{
    const int n = dim == 2 ? 600 : 1200;
    const double L = 1, dx = dim == 2 ? sqrt(1.0 / n) : cbrt(1.0 / n);
    const sph_real h = (sph_real)(1.3 * dx);
    const double eps = TH_EPS;
    sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}};
    const sph_box *bp = periodic ? &box : NULL;
    sph_real *x = (sph_real *)calloc((size_t)(3 * n), sizeof(sph_real));
    sph_real *V = (sph_real *)calloc((size_t)n, sizeof(sph_real)), *f = (sph_real *)calloc((size_t)n, sizeof(sph_real));
    sph_real *xs = (sph_real *)calloc((size_t)(3 * n), sizeof(sph_real));
    sph_real *Vs = (sph_real *)calloc((size_t)n, sizeof(sph_real)), *fs = (sph_real *)calloc((size_t)n, sizeof(sph_real));
    sph_real *rho = (sph_real *)calloc((size_t)n, sizeof(sph_real)), *rhos = (sph_real *)calloc((size_t)n, sizeof(sph_real));
    sph_real *g = (sph_real *)calloc((size_t)(3 * n), sizeof(sph_real)), *gs = (sph_real *)calloc((size_t)(3 * n), sizeof(sph_real));
    sph_idx *perm = (sph_idx *)calloc((size_t)n, sizeof(sph_idx));
    tp_rng rng = {42u + (uint64_t)dim};
    nl A, B;
    int i, a, st, moved = 0;
    double worst = 0;
    th_begin("cell-sorted particles give the unsorted results after un-permuting (%dD%s, cubic)", dim,
             periodic ? ", periodic" : "");
    tp_uniform_cloud(dim, n, L, &rng, x);
    for (i = 0; i < n; ++i) {
        V[i] = (sph_real)(1.0 / n);
        f[i] = (sph_real)(sin(2 * 3.141592653589793 * (double)x[3 * i]) * cos(2 * 3.141592653589793 * (double)x[3 * i + 1]) + 0.5);
    }
    st = build(&A, dim, x, n, h, bp);
    TH_CHECK(st == SPH_OK, "unsorted list: %s", sph_strerror(st));
    st = run_ops(&A, dim, x, V, f, h, bp, rho, g);
    TH_CHECK(st == SPH_OK, "unsorted operators: %s", sph_strerror(st));
    /* sort by cell: perm[new] = old */
    st = sph_nsearch_permutation(&A.g, perm);
    st |= sph_permute(sph_view_interleaved(x, 3), 3, n, perm, sph_out_interleaved(xs, 3));
    st |= sph_permute(sph_view_soa(V, NULL, NULL), 1, n, perm, sph_out_soa(Vs, NULL, NULL));
    st |= sph_permute(sph_view_soa(f, NULL, NULL), 1, n, perm, sph_out_soa(fs, NULL, NULL));
    TH_CHECK(st == SPH_OK, "permutation: %s", sph_strerror(st));
    for (i = 0; i < n; ++i) moved += perm[i] != i;
    TH_CHECK(moved > n / 2, "sorting moved only %d of %d particles: the test would not test", moved, n);
    st = build(&B, dim, xs, n, h, bp);
    st |= run_ops(&B, dim, xs, Vs, fs, h, bp, rhos, gs);
    TH_CHECK(st == SPH_OK, "sorted list and operators: %s", sph_strerror(st));
    for (i = 0; i < n && st == SPH_OK; ++i) {
        const int o = perm[i]; /* sorted particle i is original particle o */
        const double nn = (double)(A.off[o + 1] - A.off[o]);
        double sabs = 0;
        sph_off e;
        TH_CHECK(B.off[i + 1] - B.off[i] == A.off[o + 1] - A.off[o], "particle %d: neighbour count differs", o);
        /* sum_j |t_j| of the difference gradient, component-wise bound by |.|_1 */
        for (e = A.off[o]; e < A.off[o + 1]; ++e) {
            const int j = A.idx[e];
            sph_real d[3];
            sph_pair p;
            for (a = 0; a < dim; ++a) d[a] = sph_box_delta(bp, a, x[3 * o + a] - x[3 * j + a]);
            p = sph_pair_kernel(SPH_KERNEL_CUBIC, dim, d, h);
            for (a = 0; a < dim; ++a) sabs += fabs((double)(V[j] * (f[j] - f[o]) * p.F * d[a]));
        }
        /* density: positive terms, sum |t_j| = rho */
        TH_CHECK(fabs((double)rhos[i] - (double)rho[o]) <= 2 * nn * eps * (double)rho[o],
                 "density of %d: %.17g sorted vs %.17g", o, (double)rhos[i], (double)rho[o]);
        for (a = 0; a < dim; ++a) {
            const double dif = fabs((double)gs[3 * i + a] - (double)g[3 * o + a]);
            TH_CHECK(dif <= 2 * nn * eps * sabs, "gradient_%d of %d: %.17g sorted vs %.17g (bound %.3g)", a, o,
                     (double)gs[3 * i + a], (double)g[3 * o + a], 2 * nn * eps * sabs);
            if (sabs > 0 && dif / (nn * eps * sabs) > worst) worst = dif / (nn * eps * sabs);
        }
    }
    printf("  sorted vs unsorted %dD%s: worst gradient difference %.3f n eps sum|t| (bound 2)\n", dim,
           periodic ? " periodic" : "", worst);
    th_end();
    nl_free(&A), nl_free(&B);
    free(x), free(V), free(f), free(xs), free(Vs), free(fs), free(rho), free(rhos), free(g), free(gs), free(perm);
}

int main(void)
{
    test_sorted(2, 0);
    test_sorted(2, 1);
    test_sorted(3, 1);
    return th_summary();
}
