/* tests/op_scene.h - particle scenes for the operator tests (test_op_*.c).
 *
 * A scene: interleaved positions x[3*i+a] (support/particles.h), uniform
 * volumes, a reference neighbour list from tp_brute_list and a context for
 * the operators. Fields are evaluated analytically here; every reference
 * value of the operator tests is an analytic derivative of these fields.
 */
#ifndef SPH_TEST_OP_SCENE_H
#define SPH_TEST_OP_SCENE_H

#include <math.h>
#include <stdlib.h>

#include "harness.h"
#include "support/particles.h"

#define TS_PI 3.14159265358979323846

typedef struct {
    int dim, n;   /* dimension, particle count */
    double dx, h; /* spacing, smoothing length */
    sph_real *x;  /* [3 n] interleaved positions */
    sph_real *V;  /* [n] volumes */
    tp_list L;
    sph_ctx c;
} ts_scene;

static inline sph_real *ts_vec(int n) { return (sph_real *)calloc((size_t)(n > 0 ? n : 1), sizeof(sph_real)); }

/* An n^dim lattice block of spacing dx in [0, n dx)^dim, perturbed by
 * amp * dx (uniform in [-amp dx, amp dx) per axis), volumes dx^dim,
 * h = hdx * dx * 2 / kappa (the same support radius for every kernel),
 * list for kernel k (targets = sources, self included), optional box. */
static inline void ts_lattice(ts_scene *s, sph_kernel k, int dim, int n, double dx, double hdx, double amp,
                       uint64_t seed, const sph_box *box)
{
    tp_rng g;
    int i;
    g.s = seed;
    s->dim = dim;
    s->n = tp_lattice_count(dim, n);
    s->dx = dx;
    s->h = hdx * dx * 2 / sph_kernel_support(k);
    s->x = ts_vec(3 * s->n);
    s->V = ts_vec(s->n);
    tp_lattice(dim, n, dx, s->x);
    if (amp > 0) tp_perturb(dim, s->n, amp * dx, &g, s->x);
    for (i = 0; i < s->n; ++i) s->V[i] = (sph_real)pow(dx, dim);
    tp_brute_list(dim, s->x, s->n, s->x, s->n, (sph_real)s->h, NULL, NULL, sph_kernel_support(k),
                  TP_GATHER, box, &s->L);
    s->c = sph_ctx_init(k, dim, (sph_real)s->h, &s->L.list, sph_view_interleaved(s->x, 3));
    s->c.V = sph_view_soa(s->V, NULL, NULL);
    s->c.box = box;
}

/* count points uniform in [0, L)^dim with the mean volume L^dim / count and
 * h = hdx * (mean spacing) * 2 / kappa. */
static inline void ts_random(ts_scene *s, sph_kernel k, int dim, int count, double L, double hdx, uint64_t seed)
{
    tp_rng g;
    int i;
    g.s = seed;
    s->dim = dim;
    s->n = count;
    s->dx = pow(pow(L, dim) / count, 1.0 / dim);
    s->h = hdx * s->dx * 2 / sph_kernel_support(k);
    s->x = ts_vec(3 * count);
    s->V = ts_vec(count);
    tp_uniform_cloud(dim, count, L, &g, s->x);
    for (i = 0; i < count; ++i) s->V[i] = (sph_real)pow(s->dx, dim);
    tp_brute_list(dim, s->x, count, s->x, count, (sph_real)s->h, NULL, NULL, sph_kernel_support(k),
                  TP_GATHER, NULL, &s->L);
    s->c = sph_ctx_init(k, dim, (sph_real)s->h, &s->L.list, sph_view_interleaved(s->x, 3));
    s->c.V = sph_view_soa(s->V, NULL, NULL);
}

static inline void ts_free(ts_scene *s)
{
    free(s->x);
    free(s->V);
    tp_free_list(&s->L);
}

/* The linear field f = 0.7 + sum_a ga[a] x_a and its gradient ga; with
 * ts_x_only set, ga = (1.3, 0, 0) (a field periodic along y and z). */
static int ts_x_only;
static inline double ts_ga(int a) { return a == 0 ? 1.3 : ts_x_only ? 0 : a == 1 ? -0.8 : 0.45; }
static inline double ts_linear(const sph_real *x) { return 0.7 + ts_ga(0) * x[0] + ts_ga(1) * x[1] + ts_ga(2) * x[2]; }

/* The linear vector field v_a = c_a + sum_b A[a][b] x_b, grad v = A, div v = trace A. */
static inline double ts_A(int a, int b)
{
    static const double A[3][3] = {{0.9, -0.4, 0.3}, {0.25, -1.1, 0.6}, {-0.35, 0.2, 0.5}};
    return A[a][b];
}
static inline double ts_vlinear(const sph_real *x, int a)
{
    return 0.1 * (a + 1) + ts_A(a, 0) * x[0] + ts_A(a, 1) * x[1] + ts_A(a, 2) * x[2];
}

/* Periodic test field on [0,1)^dim: f = prod_a sin(2 pi x_a) (dim 2, 3), its
 * gradient and Laplacian (-dim (2 pi)^2 f). */
static inline double ts_sine(int dim, const sph_real *x, double *grad)
{
    double s[3], c[3], f = 1;
    int a, b;
    for (a = 0; a < dim; ++a) {
        s[a] = sin(2 * TS_PI * x[a]);
        c[a] = cos(2 * TS_PI * x[a]);
        f *= s[a];
    }
    for (a = 0; grad != NULL && a < dim; ++a) {
        grad[a] = 2 * TS_PI * c[a];
        for (b = 0; b < dim; ++b)
            if (b != a) grad[a] *= s[b];
    }
    return f;
}

#endif
