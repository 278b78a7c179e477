/* support/particles.h - particle clouds and reference neighbour lists, shared by
 * the tests, the benchmarks (bench/) and the studies (studies/operator_errors.c).
 *
 * Positions are interleaved with three slots per particle, x[3*i + a]
 * (unused components are 0), so sph_view_interleaved(x, 3) reads them.
 * Everything here is deliberately simple (O(N^2) reference search), written
 * for checking the library against it and for building test scenes. Arrays
 * come from malloc; free them with free() / tp_free_list().
 */
#ifndef SPH_SUPPORT_PARTICLES_H
#define SPH_SUPPORT_PARTICLES_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "sph_kernel.h"

/* ---- a seeded random generator (splitmix64), the same on every machine ---- */
typedef struct {
    uint64_t s;
} tp_rng;

static inline uint64_t tp_next(tp_rng *g)
{
    uint64_t z = (g->s += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1). */
static inline double tp_uniform(tp_rng *g) { return (double)(tp_next(g) >> 11) * (1.0 / 9007199254740992.0); }

/* Uniform in [lo, hi). */
static inline double tp_range(tp_rng *g, double lo, double hi) { return lo + (hi - lo) * tp_uniform(g); }

/* ---- clouds ---- */

/* Number of particles of an n^dim lattice. */
static inline int tp_lattice_count(int dim, int n) { return dim == 1 ? n : dim == 2 ? n * n : n * n * n; }

/* Lattice of n points per side, spacing dx, cell-centred in [0, n dx)^dim:
 * x = (k + 1/2) dx. Returns the particle count; x must hold 3 * count. */
static inline int tp_lattice(int dim, int n, double dx, sph_real *x)
{
    int count = tp_lattice_count(dim, n), i, a;
    for (i = 0; i < count; ++i) {
        int rest = i;
        for (a = 0; a < 3; ++a) {
            x[3 * i + a] = 0;
            if (a < dim) {
                x[3 * i + a] = (sph_real)(((double)(rest % n) + 0.5) * dx);
                rest /= n;
            }
        }
    }
    return count;
}

/* Moves every particle by a uniform random amount in [-amp, amp) per axis. */
static inline void tp_perturb(int dim, int count, double amp, tp_rng *g, sph_real *x)
{
    int i, a;
    for (i = 0; i < count; ++i)
        for (a = 0; a < dim; ++a) x[3 * i + a] += (sph_real)tp_range(g, -amp, amp);
}

/* count points uniform in [0, L)^dim. */
static inline void tp_uniform_cloud(int dim, int count, double L, tp_rng *g, sph_real *x)
{
    int i, a;
    for (i = 0; i < count; ++i)
        for (a = 0; a < 3; ++a) x[3 * i + a] = a < dim ? (sph_real)tp_range(g, 0, L) : 0;
}

/* count points in nclusters tight clusters (Gaussian-like, width w, sum of
 * three uniforms) whose centres are uniform in [0, L)^dim, plus a uniform
 * background of one point in ten: a strongly inhomogeneous cloud. */
static inline void tp_clustered_cloud(int dim, int count, int nclusters, double L, double w, tp_rng *g,
                               sph_real *x)
{
    double c[16][3];
    int i, a, k;
    if (nclusters > 16) nclusters = 16;
    for (k = 0; k < nclusters; ++k)
        for (a = 0; a < 3; ++a) c[k][a] = tp_range(g, 0.2 * L, 0.8 * L);
    for (i = 0; i < count; ++i) {
        k = (int)(tp_uniform(g) * nclusters);
        for (a = 0; a < 3; ++a) {
            double v;
            if (a >= dim) {
                x[3 * i + a] = 0;
                continue;
            }
            if (i % 10 == 9) v = tp_range(g, 0, L);
            else v = c[k][a] + w * (tp_uniform(g) + tp_uniform(g) + tp_uniform(g) - 1.5);
            x[3 * i + a] = (sph_real)v;
        }
    }
}

/* ---- clouds with strongly varying h (the search of section 7 must cost per
 * pair, not per largest h; tests/test_neighbours.c, bench/bench_search_h.c) ---- */

/* One particle from the standard normal distribution (Box-Muller). */
static inline double tp_normal(tp_rng *g)
{
    double u = tp_uniform(g), v = tp_uniform(g);
    return sqrt(-2 * log(1 - u)) * cos(6.283185307179586 * v);
}

/* A Gaussian clump of n particles of mass 1/n in dim dimensions, width s,
 * truncated where the density has fallen by the factor contrast
 * (r^2 <= 2 s^2 ln contrast), centred at c in every used axis; h from the
 * analytic density, h = eta (m / rho)^(1/dim), so the h contrast is
 * contrast^(1/dim). x: 3 slots per particle, h: n values. */
static inline void tp_clump(int dim, int n, double s, double contrast, double c, double eta, tp_rng *g,
                            sph_real *x, sph_real *h)
{
    const double r2max = 2 * s * s * log(contrast), m = 1.0 / n;
    const double rho0 = n * m / pow(6.283185307179586 * s * s, 0.5 * dim); /* untruncated peak: the truncation drops < 0.5 % */
    int i, a;
    for (i = 0; i < n; ++i) {
        double y[3] = {0, 0, 0}, r2;
        do {
            r2 = 0;
            for (a = 0; a < dim; ++a) {
                y[a] = s * tp_normal(g);
                r2 += y[a] * y[a];
            }
        } while (r2 > r2max);
        for (a = 0; a < 3; ++a) x[3 * i + a] = a < dim ? (sph_real)(c + y[a]) : 0;
        h[i] = (sph_real)(eta * pow(m / (rho0 * exp(-r2 / (2 * s * s))), 1.0 / dim));
    }
}

/* The two states of a shock tube on [-1, 1) along x (periodic in x and, for
 * dim > 1, across the tube of width W): a lattice of spacing d on the left
 * and 2 d on the right (density ratio 2^dim), each cell-centred in its
 * half, h = eta times the local spacing. Returns the particle count; x (3
 * slots each) and h must hold tp_tube_count(dim, d, W) particles. */
static inline int tp_tube_count(int dim, double d, double W)
{
    const int nl = (int)(1 / d + 0.5), nr = nl / 2, ml = dim > 1 ? (int)(W / d + 0.5) : 1, mr = dim > 1 ? ml / 2 : 1;
    return nl * ml * (dim > 2 ? ml : 1) + nr * mr * (dim > 2 ? mr : 1);
}

static inline int tp_tube(int dim, double d, double W, double eta, sph_real *x, sph_real *h)
{
    const int nl = (int)(1 / d + 0.5), ml = dim > 1 ? (int)(W / d + 0.5) : 1;
    int side, i, j, k, p = 0;
    for (side = 0; side < 2; ++side) {
        const double e = side ? 2 * d : d, x0 = side ? 0 : -1;
        const int mx = side ? nl / 2 : nl, my = dim > 1 ? (side ? ml / 2 : ml) : 1, mz = dim > 2 ? my : 1;
        for (i = 0; i < mx; ++i)
            for (j = 0; j < my; ++j)
                for (k = 0; k < mz; ++k, ++p) {
                    x[3 * p] = (sph_real)(x0 + (i + 0.5) * e);
                    x[3 * p + 1] = dim > 1 ? (sph_real)((j + 0.5) * e) : 0;
                    x[3 * p + 2] = dim > 2 ? (sph_real)((k + 0.5) * e) : 0;
                    h[p] = (sph_real)(eta * e);
                }
    }
    return p;
}

/* ---- reference neighbour lists ---- */

/* Who counts as a neighbour (the library's criterion): source j is a
 * neighbour of target i when r_ij^2 < R^2 with R = kappa * h_i ("gather") or
 * R = kappa * max(h_i, h_j) ("symmetric"); x_ij by sph_box_delta per axis. */
enum { TP_GATHER = 0, TP_SYMMETRIC = 1 };

typedef struct {
    sph_off *offset; /* [nt + 1] */
    sph_idx *index;  /* [offset[nt]], ascending source index within a target */
    sph_neighbours list;
} tp_list;

static inline void tp_free_list(tp_list *l)
{
    free(l->offset);
    free(l->index);
    l->offset = NULL;
    l->index = NULL;
}

/* r^2 between target position xt (3 slots) and source position xs, summed
 * in axis order with every square rounded before it is added, whatever the
 * unit's floating-point contraction (the volatile keeps the compiler from
 * fusing d^2 + r^2): the search's criterion (N3), which its lists must meet
 * exactly, for pairs on the radius too. */
static inline sph_real tp_r2(int dim, const sph_real *xt, const sph_real *xs, const sph_box *box)
{
    sph_real r2 = 0;
    int a;
    for (a = 0; a < dim; ++a) {
        const sph_real d = sph_box_delta(box, a, xt[a] - xs[a]);
        volatile sph_real d2 = d * d;
        r2 += d2;
    }
    return r2;
}

/* O(nt * ns) reference list, one pass over the pairs (the index array grows
 * by doubling). ht / hs: per-particle h, or NULL for uniform h.
 * Returns 0 on success, -1 when malloc fails. */
static inline int tp_brute_list(int dim, const sph_real *xt, int nt, const sph_real *xs, int ns,
                         sph_real h, const sph_real *ht, const sph_real *hs, sph_real kappa,
                         int mode, const sph_box *box, tp_list *out)
{
    int i, j;
    sph_off n = 0;
    size_t cap = 1024;
    out->offset = (sph_off *)malloc(sizeof(sph_off) * (size_t)(nt + 1));
    out->index = (sph_idx *)malloc(sizeof(sph_idx) * cap);
    if (out->offset == NULL || out->index == NULL) return -1;
    for (i = 0; i < nt; ++i) {
        out->offset[i] = n;
        for (j = 0; j < ns; ++j) {
            sph_real hi = ht ? ht[i] : h, hj = hs ? hs[j] : h;
            sph_real R = kappa * (mode == TP_SYMMETRIC && hj > hi ? hj : hi);
            if (tp_r2(dim, xt + 3 * i, xs + 3 * j, box) < R * R) {
                if ((size_t)n == cap) {
                    sph_idx *grown = (sph_idx *)realloc(out->index, sizeof(sph_idx) * 2 * cap);
                    if (grown == NULL) return -1;
                    out->index = grown;
                    cap *= 2;
                }
                out->index[n++] = (sph_idx)j;
            }
        }
    }
    out->offset[nt] = n;
    out->list.n_targets = (sph_idx)nt;
    out->list.n_sources = (sph_idx)ns;
    out->list.offset = out->offset;
    out->list.index = out->index;
    out->list.box_known = 0; /* the brute-force list does not record its box */
    return 0;
}

/* Lattice second moment mu = -sum over offsets k != 0 of dx^d F(|k| dx, h)
 * (k_x dx)^2 on a lattice of spacing dx: the factor by which every
 * uncorrected operator differs from the exact derivative on a lattice (1 for
 * the continuous kernel; docs/operators.md, "Consistency and truncation
 * error"). From the scalar kernel function sph_kernel_f over integer offsets,
 * independent of lists and operators. */
static inline double tp_lattice_moment(sph_kernel k, int dim, double dx, double h)
{
    const int R = (int)(sph_kernel_support(k) * h / dx) + 1;
    double m = 0;
    int i, j, l;
    for (i = -R; i <= R; ++i)
        for (j = (dim > 1 ? -R : 0); j <= (dim > 1 ? R : 0); ++j)
            for (l = (dim > 2 ? -R : 0); l <= (dim > 2 ? R : 0); ++l) {
                const double r = dx * sqrt((double)(i * i + j * j + l * l));
                m -= pow(dx, dim) * (double)sph_kernel_f(k, dim, (sph_real)r, (sph_real)h) * (i * dx) * (i * dx);
            }
    return m;
}

#endif
