/* bench/pair_once.c - the grad-h pressure force (docs/smoothing_length.md
 * (H5), (H6)) in gather form (sph_gradh_forces: each pair evaluated from
 * both of its rows) against the pair-once form (sph_gradh_forces_pairs:
 * each pair once into a buffer, then the fixed-order reduction (H8)), with
 * the section-6 pressure gradient (O8) as the gather operator of reference.
 * Run by hand (not part of make test: timings never are):
 *
 *   gcc -O2 -std=c99 -I. bench/pair_once.c -o build/pair_once -lm
 *   gcc -O2 -std=c99 -fopenmp -I. bench/pair_once.c -o build/pair_once_omp -lm
 *   ./build/pair_once [side] [repeats]     (default 40: 40^3 particles, 9 repeats)
 *
 * 3-D perturbed lattice in a periodic unit box, h solved by sph_h_solve
 * (eta 1.2, cubic spline: about 58 neighbours), one symmetric list at
 * 1.1 h. The three forms run one after another in each repeat; prints the
 * median over the repeats in ns per pair (pairs = unordered pairs i < j of
 * the list), the median of the per-repeat gather / pair-once ratios, and the
 * one-time cost of sph_pairs_build.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "support/particles.h"
#include "support/timing.h"

/* Symmetric list at radius kappa hl into *off / *idx (malloc'd). */
static int lists(const sph_real *x, int n, const sph_real *hl, const sph_box *box, sph_off **off, sph_idx **idx)
{
    const sph_view v = sph_view_interleaved(x, 3), hv = sph_view_soa(hl, NULL, NULL);
    sph_real hmax = 0;
    sph_nsearch g;
    size_t bytes;
    void *work;
    int i, st;
    for (i = 0; i < n; ++i) hmax = hl[i] > hmax ? hl[i] : hmax;
    if ((st = sph_nsearch_workspace_size(3, v, n, hv, hmax, box, &bytes)) != SPH_OK) return st;
    work = malloc(bytes);
    *off = (sph_off *)malloc(sizeof(sph_off) * (size_t)(n + 1));
    if (work == NULL || *off == NULL) return SPH_ESIZE;
    st = sph_nsearch_build(&g, 3, v, n, hv, hmax, box, work, bytes);
    if (st == SPH_OK) st = sph_nsearch_count(&g, v, n, hv, 0, 2, SPH_NSEARCH_SYMMETRIC, *off);
    *idx = st == SPH_OK ? (sph_idx *)malloc(sizeof(sph_idx) * (size_t)((*off)[n] + 1)) : NULL;
    if (st == SPH_OK && *idx == NULL) st = SPH_ESIZE;
    if (st == SPH_OK) st = sph_nsearch_fill(&g, v, n, hv, 0, 2, SPH_NSEARCH_SYMMETRIC, *off, *idx, (*off)[n]);
    free(work);
    return st;
}

int main(int argc, char **argv)
{
    const int side = argc > 1 ? atoi(argv[1]) : 40, reps = argc > 2 ? atoi(argv[2]) : 9;
    const int n = side * side * side;
    const double dx = 1.0 / side;
    sph_real *x, *v, *m, *h, *hl, *rho, *om, *p, *A, *P, *dv, *du, *buf, *V;
    sph_off *off = NULL, *hoff, *toff, *tpair, pairs;
    sph_idx *idx = NULL, *hidx;
    sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}};
    sph_neighbours full = SPH_NEIGHBOURS_INIT(0, 0, NULL, NULL); /* box unknown: c.box gives it */
    sph_pairs pr;
    sph_hctx c;
    sph_hreport rep;
    tp_rng g = {7};
    double *t[4], med[4], tb;
    int i, r, st;
    if (side < 8 || side > 400 || reps < 1 || reps > 1000) {
        fprintf(stderr, "usage: %s [side 8..400] [repeats 1..1000]\n", argv[0]);
        return 2;
    }
    x = malloc(sizeof(sph_real) * 3 * (size_t)n), v = malloc(sizeof(sph_real) * 3 * (size_t)n);
    m = malloc(sizeof(sph_real) * (size_t)n), h = malloc(sizeof(sph_real) * (size_t)n);
    hl = malloc(sizeof(sph_real) * (size_t)n), rho = malloc(sizeof(sph_real) * (size_t)n);
    om = malloc(sizeof(sph_real) * (size_t)n), p = malloc(sizeof(sph_real) * (size_t)n);
    A = malloc(sizeof(sph_real) * (size_t)n), P = malloc(sizeof(sph_real) * (size_t)n);
    V = malloc(sizeof(sph_real) * (size_t)n);
    dv = malloc(sizeof(sph_real) * 3 * (size_t)n), du = malloc(sizeof(sph_real) * (size_t)n);
    for (i = 0; i < 4; ++i) t[i] = malloc(sizeof(double) * (size_t)reps);
    if (!x || !v || !m || !h || !hl || !rho || !om || !p || !A || !P || !V || !dv || !du) return 1;
    if (!t[0] || !t[1] || !t[2] || !t[3]) return 1;
    tp_lattice(3, side, dx, x);
    tp_perturb(3, n, 0.2 * dx, &g, x);
    for (i = 0; i < n; ++i) {
        m[i] = (sph_real)(dx * dx * dx);
        h[i] = (sph_real)(1.2 * dx);
        hl[i] = (sph_real)(1.5 * dx);
        v[3 * i] = (sph_real)tp_range(&g, -1, 1), v[3 * i + 1] = (sph_real)tp_range(&g, -1, 1);
        v[3 * i + 2] = (sph_real)tp_range(&g, -1, 1);
    }
    /* h solved on a generous list, then the force list at 1.1 h */
    if ((st = lists(x, n, hl, &box, &off, &idx)) != SPH_OK) return fprintf(stderr, "search: %s\n", sph_strerror(st)), 1;
    full.n_targets = full.n_sources = n, full.offset = off, full.index = idx;
    c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &full, sph_view_interleaved(x, 3), sph_view_soa(m, NULL, NULL), 0);
    c.h_list = sph_view_soa(hl, NULL, NULL);
    c.box = &box;
    st = sph_h_solve(&c, sph_out_soa(h, NULL, NULL), sph_out_soa(rho, NULL, NULL), sph_out_soa(om, NULL, NULL), NULL,
                     NULL, &rep);
    if (st != SPH_OK || rep.n_beyond_list > 0) return fprintf(stderr, "h solve: %s\n", sph_strerror(st)), 1;
    free(off), free(idx);
    for (i = 0; i < n; ++i) hl[i] = (sph_real)1.1 * h[i];
    if ((st = lists(x, n, hl, &box, &off, &idx)) != SPH_OK) return 1;
    full.offset = off, full.index = idx;
    c.list = &full;
    c.check_list = 0;
    for (i = 0; i < n; ++i) {
        p[i] = rho[i]; /* any pressure field */
        A[i] = sph_gradh_factor(p[i], rho[i], om[i]);
        P[i] = sph_pressure_factor(p[i], rho[i]);
        V[i] = m[i] / rho[i];
    }
    hoff = malloc(sizeof(sph_off) * (size_t)(n + 1)), toff = malloc(sizeof(sph_off) * (size_t)(n + 1));
    hidx = malloc(sizeof(sph_idx) * (size_t)off[n]), tpair = malloc(sizeof(sph_off) * (size_t)off[n]);
    buf = malloc(sizeof(sph_real) * (size_t)sph_gradh_pairs_buffer_len(3, off[n]));
    if (!hoff || !toff || !hidx || !tpair || !buf) return 1;
    tb = tm_now();
    st = sph_pairs_build(&full, hoff, hidx, off[n], toff, tpair, &pairs, &pr);
    tb = tm_now() - tb;
    if (st != SPH_OK) return fprintf(stderr, "pairs: %s\n", sph_strerror(st)), 1;
    for (r = 0; r < reps; ++r) {
        const sph_view vv = sph_view_interleaved(v, 3), hv = sph_view_soa(h, NULL, NULL);
        const sph_view Av = sph_view_soa(A, NULL, NULL);
        const sph_out dvo = sph_out_interleaved(dv, 3), duo = sph_out_soa(du, NULL, NULL);
        double t0 = tm_now(), t1, t2, t3;
        sph_ctx oc = sph_ctx_init(SPH_KERNEL_CUBIC, 3, 0, &full, sph_view_interleaved(x, 3));
        st = sph_gradh_forces(&c, vv, hv, Av, dvo, duo);
        t1 = tm_now();
        st |= sph_gradh_forces_pairs(&c, &pr, vv, hv, Av, buf, sph_gradh_pairs_buffer_len(3, pairs), dvo, duo);
        t2 = tm_now();
        oc.box = &box;
        oc.h_source = sph_view_soa(h, NULL, NULL);
        oc.m = sph_view_soa(m, NULL, NULL);
        oc.rho = sph_view_soa(rho, NULL, NULL);
        oc.V = sph_view_soa(V, NULL, NULL);
        oc.validate = SPH_VALIDATE_ARGS;
        st |= sph_gradient(&oc, SPH_SCHEME_PRESSURE, sph_view_soa(p, NULL, NULL), sph_view_none(),
                           sph_out_interleaved(dv, 3), NULL);
        t3 = tm_now();
        if (st != SPH_OK) return fprintf(stderr, "forces: %s\n", sph_strerror(st)), 1;
        t[0][r] = t1 - t0, t[1][r] = t2 - t1, t[2][r] = t3 - t2, t[3][r] = (t1 - t0) / (t2 - t1);
    }
    for (i = 0; i < 4; ++i) med[i] = tm_median(t[i], reps);
    printf("%d particles, %ld pairs (i < j), %.1f neighbours per particle, %s, median of %d\n", n, (long)pairs,
           (double)off[n] / n, sizeof(sph_real) == sizeof(float) ? "float" : "double", reps);
    printf("  grad-h force + du/dt, gather    (sph_gradh_forces)        %7.2f ns/pair\n", 1e9 * med[0] / (double)pairs);
    printf("  grad-h force + du/dt, pair-once (sph_gradh_forces_pairs)  %7.2f ns/pair (speed-up %.2f)\n",
           1e9 * med[1] / (double)pairs, med[3]);
    printf("  pressure gradient (O8), gather  (sph_gradient PRESSURE)   %7.2f ns/pair\n", 1e9 * med[2] / (double)pairs);
    printf("  sph_pairs_build once per list                             %7.2f ns/pair\n", 1e9 * tb / (double)pairs);
    free(x), free(v), free(m), free(h), free(hl), free(rho), free(om), free(p), free(A), free(P), free(V), free(dv);
    free(du), free(off), free(idx), free(hoff), free(toff), free(hidx), free(tpair), free(buf);
    for (i = 0; i < 4; ++i) free(t[i]);
    return 0;
}
