/* bench/bench_neighbours.c - timing of the cell-list neighbour search, run by
 * hand (not part of make test: timings never are):
 *
 *   gcc -O2 -std=c99 -I. bench/bench_neighbours.c -o build/bench_neighbours -lm
 *   gcc -O2 -std=c99 -fopenmp -I. bench/bench_neighbours.c -o build/bench_neighbours_omp -lm
 *   ./build/bench_neighbours [side]        (default side 64: 64^3 particles)
 *
 * 3-D perturbed lattice in a periodic unit box, ~60 neighbours per particle,
 * cells of R, R/2, R/3; particles in random index order ("shuffled") and
 * after the locality permutation ("cell-sorted"). Prints the seconds of
 * build, count, fill and the one-pass lists (index 20 % longer than the
 * pairs), the candidate checks per neighbour found, and the nanoseconds per
 * list entry of sph_neighbours_check on the lists (median of 5 calls: the
 * pass every function that takes a list runs over it).
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "support/particles.h"
#include "support/timing.h"

static void run(const char *label, const sph_real *x, int n, sph_real h, sph_real kappa, double cell_over_R,
                const sph_box *box, sph_idx *perm_out)
{
    sph_view v = sph_view_interleaved(x, 3);
    sph_real cell = (sph_real)(cell_over_R * (double)(kappa * h));
    sph_off *off = (sph_off *)malloc(sizeof(sph_off) * (size_t)(n + 1)), pairs = 0, cand = 0, cap;
    sph_idx *idx;
    sph_nsearch g;
    size_t bytes;
    void *work;
    double t0, t1, t2, t3, t4, tc[5];
    sph_neighbours L;
    int st, r;
    memset(&g, 0, sizeof g); /* printed even when the build fails */
    sph_nsearch_workspace_size(3, v, n, sph_view_none(), cell, box, &bytes);
    work = malloc(bytes);
    t0 = tm_now();
    st = sph_nsearch_build(&g, 3, v, n, sph_view_none(), cell, box, work, bytes);
    t1 = tm_now();
    st |= sph_nsearch_count(&g, v, n, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, off);
    t2 = tm_now();
    cap = (sph_off)(1.2 * (double)off[n]);
    idx = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)cap);
    st |= sph_nsearch_fill(&g, v, n, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, off, idx, off[n]);
    t3 = tm_now();
    st |= sph_nsearch_lists(&g, v, n, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, off, idx, cap,
                            &pairs);
    t4 = tm_now();
    L = sph_nsearch_list(&g, n, off, idx);
    for (r = 0; r < 5; ++r) {
        tc[r] = tm_now();
        st |= sph_neighbours_check(&L);
        tc[r] = tm_now() - tc[r];
    }
    st |= sph_nsearch_stats(&g, v, n, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, &pairs, &cand, NULL);
    printf("%-12s cell %.3f R  cells %7d  build %.4f s  count %.4f s  fill %.4f s  lists %.4f s  "
           "neighbours/particle %.1f  candidates/neighbour %.3f  workspace %.1f MB  check %.3f ns/entry%s\n",
           label, cell_over_R, g.n_cells, t1 - t0, t2 - t1, t3 - t2, t4 - t3, (double)pairs / n,
           (double)cand / (double)pairs, (double)bytes / 1e6, 1e9 * tm_median(tc, 5) / (double)off[n],
           st == SPH_OK ? "" : "  ERROR");
    if (perm_out != NULL) sph_nsearch_permutation(&g, perm_out);
    free(idx);
    free(off);
    free(work);
}

int main(int argc, char **argv)
{
    int side = argc > 1 ? atoi(argv[1]) : 64, n, i, a, c;
    double dx;
    sph_real *x, *xs, kappa = 2, h;
    sph_idx *perm[3];
    sph_box box;
    tp_rng rng = {1};
    static const double cells[3] = {1, 0.5, 1.0 / 3};
    if (side < 4 || side > 200) return 1;
    n = side * side * side;
    dx = 1.0 / side;
    h = (sph_real)(cbrt(60 * 3 / (4 * 3.14159265358979)) * dx / 2); /* 4/3 pi R^3 = 60 dx^3 */
    x = (sph_real *)malloc(sizeof(sph_real) * 3 * (size_t)n);
    xs = (sph_real *)malloc(sizeof(sph_real) * 3 * (size_t)n);
    for (c = 0; c < 3; ++c) perm[c] = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)n);
    for (a = 0; a < 3; ++a) {
        box.lo[a] = 0;
        box.length[a] = 1;
        box.periodic[a] = 1;
    }
    tp_lattice(3, side, dx, x);
    tp_perturb(3, n, 0.25 * dx, &rng, x);
    for (i = n - 1; i > 0; --i) { /* random index order */
        int j = (int)(tp_uniform(&rng) * (i + 1));
        for (a = 0; a < 3; ++a) {
            sph_real t = x[3 * i + a];
            x[3 * i + a] = x[3 * j + a];
            x[3 * j + a] = t;
        }
    }
    printf("%d particles (%d^3), periodic perturbed lattice, %s\n", n, side,
           sizeof(sph_real) == sizeof(float) ? "float" : "double");
    for (c = 0; c < 3; ++c) run("shuffled", x, n, h, kappa, cells[c], &box, perm[c]);
    for (c = 0; c < 3; ++c) { /* sorted by the cells of the grid that searches them */
        sph_permute(sph_view_interleaved(x, 3), 3, n, perm[c], sph_out_interleaved(xs, 3));
        run("cell-sorted", xs, n, h, kappa, cells[c], &box, NULL);
    }
    free(x);
    free(xs);
    for (c = 0; c < 3; ++c) free(perm[c]);
    return 0;
}
