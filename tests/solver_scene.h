/* tests/solver_scene.h - a closed particle system for the solver-term tests
 * (test_solver_*.c): a random cloud in a periodic unit box with random masses,
 * densities, sound speeds, per-particle h and velocities, and the symmetric
 * neighbour list (h_ij symmetric, so every pair term is antisymmetric and the
 * totals vanish to round-off). */
#ifndef SPH_TEST_SOLVER_SCENE_H
#define SPH_TEST_SOLVER_SCENE_H

#include "op_scene.h"

typedef struct {
    int n, dim;
    sph_real *x, *m, *rho, *V, *h, *c, *v, *a, *du, *vs;
    tp_list L;
    sph_box box;
    sph_ctx ctx;
} ss_cloud;

/* n particles of a perturbed lattice (random cloud for n not a power of the
 * lattice side) filling the periodic unit box, and random fields. */
static inline void ss_make(ss_cloud *s, int dim, int n, double vmax, uint64_t seed)
{
    tp_rng g;
    int i, a, side = (int)floor(pow((double)n, 1.0 / dim) + 0.5);
    const double dx = pow(1.0 / n, 1.0 / dim);
    g.s = seed;
    *s = (ss_cloud){0};
    s->n = n, s->dim = dim;
    s->x = ts_vec(3 * n), s->m = ts_vec(n), s->rho = ts_vec(n), s->V = ts_vec(n), s->h = ts_vec(n);
    s->c = ts_vec(n), s->v = ts_vec(3 * n), s->a = ts_vec(3 * n), s->du = ts_vec(n), s->vs = ts_vec(n);
    for (a = 0; a < 3; ++a) s->box.length[a] = 1, s->box.periodic[a] = 1;
    if (tp_lattice_count(dim, side) == n) {
        tp_lattice(dim, side, 1.0 / side, s->x);
        tp_perturb(dim, n, 0.3 / side, &g, s->x);
    } else {
        tp_uniform_cloud(dim, n, 1.0, &g, s->x);
    }
    for (i = 0; i < n; ++i) {
        s->rho[i] = (sph_real)tp_range(&g, 900, 1100);
        s->m[i] = (sph_real)(tp_range(&g, 0.8, 1.2) * 1000 * pow(dx, dim));
        s->V[i] = s->m[i] / s->rho[i];
        s->h[i] = (sph_real)(tp_range(&g, 1.2, 1.8) * dx);
        s->c[i] = (sph_real)tp_range(&g, 5, 15);
        for (a = 0; a < dim; ++a) s->v[3 * i + a] = (sph_real)tp_range(&g, -vmax, vmax);
    }
    tp_brute_list(dim, s->x, n, s->x, n, 0, s->h, s->h, sph_kernel_support(SPH_KERNEL_WENDLAND_C2), TP_SYMMETRIC,
                  &s->box, &s->L);
    s->ctx = sph_ctx_init(SPH_KERNEL_WENDLAND_C2, dim, 0, &s->L.list, sph_view_interleaved(s->x, 3));
    s->ctx.h_source = sph_view_soa(s->h, NULL, NULL);
    s->ctx.m = sph_view_soa(s->m, NULL, NULL);
    s->ctx.rho = sph_view_soa(s->rho, NULL, NULL);
    s->ctx.V = sph_view_soa(s->V, NULL, NULL);
    s->ctx.box = &s->box;
}

static inline void ss_free(ss_cloud *s)
{
    free(s->x), free(s->m), free(s->rho), free(s->V), free(s->h);
    free(s->c), free(s->v), free(s->a), free(s->du), free(s->vs);
    tp_free_list(&s->L);
}

/* dx = x_i - x_j (minimum image) and F_ij at h_ij = (h_i + h_j) / 2, from the
 * scalar kernel function: the tests' own pair geometry. */
static inline double ss_pair(const ss_cloud *s, int i, int j, double *dx)
{
    double r2 = 0;
    int a;
    for (a = 0; a < 3; ++a) dx[a] = 0;
    for (a = 0; a < s->dim; ++a) {
        dx[a] = (double)sph_box_delta(&s->box, a, s->x[3 * i + a] - s->x[3 * j + a]);
        r2 += dx[a] * dx[a];
    }
    return (double)sph_kernel_f(SPH_KERNEL_WENDLAND_C2, s->dim, (sph_real)sqrt(r2), (s->h[i] + s->h[j]) / 2);
}

#endif
