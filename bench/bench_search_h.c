/* bench/bench_search_h.c - cost of the neighbour search per listed pair when
 * h varies from particle to particle, against a uniform-h lattice searched
 * in the same run (docs/neighbours.md, "Varying h"). `make bench-search`
 * builds and runs it with -O3 -march=native and with -O2 for a generic
 * x86-64; BEFORE=path/to/other/sph_kernel.h also builds it against that
 * header (the SPH_HEADER macro below), for before/after figures.
 *
 *   ./build/bench_search_h [repeats] [scale]   (default 7 repeats, scale 1)
 *
 * Scenes, 3-D, cubic spline (kappa 2), h = 1.2 (m / rho)^(1/3):
 *   uniform  fcc lattice of cell a in a periodic box, one h (the baseline);
 *   sod      the lattices of examples/sod_shock.c: fcc of cell a on [-1, 0),
 *            of cell 2 a on [0, 1) (rho 1 and 0.125, h ratio 2), periodic;
 *   clump    a Gaussian clump truncated at density contrast 1000 (h
 *            contrast 10), open box (tp_clump of support/particles.h).
 * Each scene is searched in gather and in symmetric mode with per-particle
 * h views (the baseline with the one uniform h), on particles sorted by the
 * grid's locality permutation (N5), as a solver would keep them. The grid
 * is built with cells of kappa h_max / 2, as examples/sod_shock.c does.
 * Printed per line: pairs, the median over the repeats of the one-pass
 * sph_nsearch_lists (index 20 % longer than the pairs), the median of
 * sph_nsearch_count alone (the list lengths of the direct search, which in
 * symmetric mode with varying h searches each target out to the reach of
 * its sources, where the lists complete the gather ones), ns per pair of
 * the lists, candidate distance checks per pair (sph_nsearch_stats), and ns
 * per pair over the baseline's in this run: the figure the search must keep
 * <= 1.5; then the grid's cells, the median time of sph_nsearch_build and
 * its workspace in MB.
 */
#define _POSIX_C_SOURCE 199309L
#ifdef SPH_HEADER
#include SPH_HEADER
#endif
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/particles.h"
#include "support/timing.h"

typedef struct {
    const char *name;
    int n;
    sph_real *x, *h; /* interleaved positions, per-particle h */
    sph_box box, *pbox;
    int uniform;     /* 1: search with the one h, no per-particle h */
} bs_scene;

/* fcc lattice of cell a over [x0, x0 + mx a) x [0, my a)^2, shifted a / 4 as examples/sod_shock.c; h = eta a / 4^(1/3). */
static int bs_fcc(sph_real *x, sph_real *h, int p, double x0, double a, int mx, int my)
{
    static const double fcc[4][3] = {{0.25, 0.25, 0.25}, {0.75, 0.75, 0.25}, {0.75, 0.25, 0.75}, {0.25, 0.75, 0.75}};
    int i, j, k, b;
    for (i = 0; i < mx; ++i)
        for (j = 0; j < my; ++j)
            for (k = 0; k < my; ++k)
                for (b = 0; b < 4; ++b, ++p) {
                    x[3 * p] = (sph_real)(x0 + (i + fcc[b][0]) * a);
                    x[3 * p + 1] = (sph_real)((j + fcc[b][1]) * a);
                    x[3 * p + 2] = (sph_real)((k + fcc[b][2]) * a);
                    h[p] = (sph_real)(1.2 * a / cbrt(4.0));
                }
    return p;
}

static void bs_alloc(bs_scene *s, int n)
{
    s->n = n;
    s->x = (sph_real *)malloc(sizeof(sph_real) * 3 * (size_t)n);
    s->h = (sph_real *)malloc(sizeof(sph_real) * (size_t)n);
    if (s->x == NULL || s->h == NULL) {
        fprintf(stderr, "bench_search_h: out of memory for %d particles\n", n);
        exit(1);
    }
}

static void bs_periodic(bs_scene *s, double lo0, double L0, double L1)
{
    int a;
    for (a = 0; a < 3; ++a) {
        s->box.lo[a] = (sph_real)(a == 0 ? lo0 : 0);
        s->box.length[a] = (sph_real)(a == 0 ? L0 : L1);
        s->box.periodic[a] = 1;
    }
    s->pbox = &s->box;
}

/* Sorts the scene's particles by the cells of the grid that will search them (N5). */
static int bs_sort(bs_scene *s, sph_real kappa)
{
    sph_view xv = sph_view_interleaved(s->x, 3), hv = s->uniform ? sph_view_none() : sph_view_soa(s->h, NULL, NULL);
    sph_real hmax = 0, cell, *x2 = (sph_real *)malloc(sizeof(sph_real) * 3 * (size_t)s->n),
             *h2 = (sph_real *)malloc(sizeof(sph_real) * (size_t)s->n);
    sph_idx *perm = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)s->n);
    size_t bytes = 0;
    void *work;
    sph_nsearch g;
    int i, st;
    for (i = 0; i < s->n; ++i) hmax = s->h[i] > hmax ? s->h[i] : hmax;
    cell = kappa * hmax / 2;
    st = sph_nsearch_workspace_size(3, xv, s->n, hv, cell, s->pbox, &bytes);
    work = malloc(bytes);
    if (st != SPH_OK || work == NULL || x2 == NULL || h2 == NULL || perm == NULL) return -1;
    st = sph_nsearch_build(&g, 3, xv, s->n, hv, cell, s->pbox, work, bytes);
    st |= sph_nsearch_permutation(&g, perm);
    st |= sph_permute(xv, 3, s->n, perm, sph_out_interleaved(x2, 3));
    st |= sph_permute(sph_view_soa(s->h, NULL, NULL), 1, s->n, perm, sph_out_soa(h2, NULL, NULL));
    memcpy(s->x, x2, sizeof(sph_real) * 3 * (size_t)s->n);
    memcpy(s->h, h2, sizeof(sph_real) * (size_t)s->n);
    free(x2), free(h2), free(perm), free(work);
    return st;
}

/* Times the one-pass lists of one scene and mode; returns ns per pair (or -1). */
static double bs_run(const bs_scene *s, int mode, int repeats, sph_real kappa, double base)
{
    sph_view xv = sph_view_interleaved(s->x, 3), hv = s->uniform ? sph_view_none() : sph_view_soa(s->h, NULL, NULL);
    sph_real hmax = 0, cell;
    sph_off *off = (sph_off *)malloc(sizeof(sph_off) * (size_t)(s->n + 1)), pairs = 0, cand = 0, cap;
    sph_idx *idx;
    double *t = (double *)malloc(sizeof(double) * (size_t)repeats), med, ns, build, count;
    size_t bytes = 0;
    void *work;
    sph_nsearch g;
    int i, r, st;
    for (i = 0; i < s->n; ++i) hmax = s->h[i] > hmax ? s->h[i] : hmax;
    cell = kappa * hmax / 2;
    st = sph_nsearch_workspace_size(3, xv, s->n, hv, cell, s->pbox, &bytes);
    work = malloc(bytes);
    if (st != SPH_OK || work == NULL || off == NULL || t == NULL) return -1;
    for (r = 0; r < repeats; ++r) {
        double t0 = tm_now();
        st |= sph_nsearch_build(&g, 3, xv, s->n, hv, cell, s->pbox, work, bytes);
        t[r] = tm_now() - t0;
    }
    build = tm_median(t, repeats);
    st |= sph_nsearch_stats(&g, xv, s->n, hv, s->h[0], kappa, mode, &pairs, &cand, NULL);
    cap = (sph_off)(1.2 * (double)pairs) + 16;
    idx = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)cap);
    if (st != SPH_OK || idx == NULL) return -1;
    for (r = 0; r < repeats; ++r) {
        double t0 = tm_now();
        st |= sph_nsearch_lists(&g, xv, s->n, hv, s->h[0], kappa, mode, off, idx, cap, &pairs);
        t[r] = tm_now() - t0;
    }
    med = tm_median(t, repeats);
    for (r = 0; r < repeats; ++r) {
        double t0 = tm_now();
        st |= sph_nsearch_count(&g, xv, s->n, hv, s->h[0], kappa, mode, off);
        t[r] = tm_now() - t0;
    }
    count = tm_median(t, repeats);
    if (off[s->n] != pairs) st = SPH_EOFFSET; /* the direct search lists the same pairs */
    ns = 1e9 * med / (double)pairs;
    printf("%-8s %-9s %8d %10ld %9.4f s %8.4f s %8.2f %8.2f %7.2f %9d %8.4f s %6.1f%s\n", s->name,
           mode == SPH_NSEARCH_GATHER ? "gather" : "symmetric", s->n, (long)pairs, med, count, ns,
           (double)cand / (double)pairs, base > 0 ? ns / base : 1.0, g.n_cells, build, (double)bytes / 1e6,
           st == SPH_OK ? "" : "  ERROR");
    free(off), free(idx), free(t), free(work);
    return st == SPH_OK ? ns : -1;
}

int main(int argc, char **argv)
{
    const int repeats = argc > 1 ? atoi(argv[1]) : 7;
    const double scale = argc > 2 ? atof(argv[2]) : 1;
    const sph_real kappa = 2;
    bs_scene sc[3];
    double base;
    int k, mode;
    if (repeats < 1 || repeats > 1000) {
        fprintf(stderr, "bench_search_h: repeats %d outside 1..1000\n", repeats);
        return 1;
    }
    if (!(scale >= 0.1 && scale <= 4)) {
        fprintf(stderr, "bench_search_h: scale %g outside 0.1..4\n", scale);
        return 1;
    }
    memset(sc, 0, sizeof sc);
    { /* uniform: fcc, 40^3 cells of a in a periodic cube */
        const int m = (int)(40 * cbrt(scale));
        sc[0].name = "uniform";
        sc[0].uniform = 1;
        bs_alloc(&sc[0], 4 * m * m * m);
        bs_fcc(sc[0].x, sc[0].h, 0, 0, 1.0 / m, m, m);
        bs_periodic(&sc[0], 0, 1, 1);
    }
    { /* sod: left fcc cell a = 1/nx on [-1, 0), right 2a on [0, 1), ny cells across */
        const int nx = 2 * (int)(48 * cbrt(scale)), ny = 16;
        const double a = 1.0 / nx;
        int p;
        sc[1].name = "sod";
        bs_alloc(&sc[1], 4 * (nx * ny * ny + nx / 2 * (ny / 2) * (ny / 2)));
        p = bs_fcc(sc[1].x, sc[1].h, 0, -1, a, nx, ny);
        bs_fcc(sc[1].x, sc[1].h, p, 0, 2 * a, nx / 2, ny / 2);
        bs_periodic(&sc[1], -1, 2, ny * a);
    }
    { /* clump: Gaussian, contrast 1000 */
        tp_rng rng = {2024};
        sc[2].name = "clump";
        bs_alloc(&sc[2], (int)(200000 * scale));
        tp_clump(3, sc[2].n, 0.1, 1000, 0.5, 1.2, &rng, sc[2].x, sc[2].h);
        sc[2].pbox = NULL;
    }
    for (k = 0; k < 3; ++k)
        if (bs_sort(&sc[k], kappa) != SPH_OK) {
            fprintf(stderr, "bench_search_h: sorting scene %s failed\n", sc[k].name);
            return 1;
        }
    printf("neighbour search per listed pair, %s, %d repeats (medians), load %s", sizeof(sph_real) == 4 ? "float" : "double",
           repeats, "");
    {
        FILE *f = fopen("/proc/loadavg", "r");
        char line[128] = "?\n";
        if (f != NULL) {
            if (fgets(line, sizeof line, f) == NULL) strcpy(line, "?\n");
            fclose(f);
        }
        printf("%s", line);
    }
    printf("%-8s %-9s %8s %10s %11s %10s %8s %8s %7s %9s %10s %6s\n", "scene", "mode", "N", "pairs", "lists", "count", "ns/pair",
           "cand/pr", "ratio", "cells", "build", "MB");
    base = bs_run(&sc[0], SPH_NSEARCH_GATHER, repeats, kappa, 0);
    if (base <= 0) return 1;
    bs_run(&sc[0], SPH_NSEARCH_SYMMETRIC, repeats, kappa, base);
    for (k = 1; k < 3; ++k)
        for (mode = 0; mode < 2; ++mode)
            if (bs_run(&sc[k], mode, repeats, kappa, base) < 0) return 1;
    for (k = 0; k < 3; ++k) free(sc[k].x), free(sc[k].h);
    return 0;
}
