/* Section 9 of sph_kernel.h in one program (docs/smoothing_length.md shows
 * its parts, and tests/check_doc_snippets.sh checks that the page shows
 * them as they are here): adaptive h with lists that grow with h, the grad-h
 * forces in gather form, and the pair-once form, with a pair term of the
 * caller's own summed by sph_pairs_reduce.
 *
 * 12^3 particles of equal mass in a periodic unit cube, squeezed along x
 * (x -> x + 0.4 sin(2 pi x) / (2 pi): density from 0.71 to 1.67 times the
 * mean), random velocities, p = rho^(5/3). The first guess of h is 20 %
 * short everywhere and the first lists only reach 1.1 times it, so the
 * particles in the thin part outgrow their lists and are searched again.
 *
 * With --check it exits 1 unless (H1) holds to the tolerance for every
 * particle (m (eta / h)^3 = rho, the neighbour mass of eta), the pair-once
 * forces conserve momentum and energy to round-off (H7), they equal the
 * gather forces to round-off, and the density summed by the program's own
 * pair-once loop equals the solver's; any other argument is refused (exit 2).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sph_kernel.h"

enum { SIDE = 12, N = SIDE * SIDE * SIDE };

static int fail(const char *what, int st)
{
    fprintf(stderr, "smoothing_length_quickstart: %s: %s\n", what, sph_strerror(st));
    return 1;
}

/* A failure that is no status of the library's: what went wrong, in words. */
static int stop(const char *what)
{
    fprintf(stderr, "smoothing_length_quickstart: %s\n", what);
    return 1;
}

/* snippet: search */
/* Symmetric lists (N2) at the per-particle radius kappa hl_i: the solver
 * needs row i to hold every j within kappa hl_i, the forces each pair in
 * both rows. offset [N + 1]; *index is (re)allocated to fit. */
static int search(sph_view x, const sph_real *hl, const sph_box *box, sph_off *offset, sph_idx **index)
{
    const sph_view hv = sph_view_soa(hl, NULL, NULL);
    const sph_real kappa = sph_kernel_support(SPH_KERNEL_CUBIC);
    sph_real hmax = 0;
    sph_nsearch g;
    size_t bytes = 0;
    void *work;
    int i, st;
    for (i = 0; i < N; ++i) hmax = hl[i] > hmax ? hl[i] : hmax;
    if ((st = sph_nsearch_workspace_size(3, x, N, hv, kappa * hmax / 2, box, &bytes)) != SPH_OK) return st;
    if ((work = malloc(bytes)) == NULL) return SPH_ESIZE;
    st = sph_nsearch_build(&g, 3, x, N, hv, kappa * hmax / 2, box, work, bytes);
    if (st == SPH_OK) st = sph_nsearch_count(&g, x, N, hv, 0, kappa, SPH_NSEARCH_SYMMETRIC, offset);
    free(*index);
    *index = st == SPH_OK ? (sph_idx *)malloc(sizeof(sph_idx) * (size_t)(offset[N] + 1)) : NULL;
    if (st == SPH_OK && *index == NULL) st = SPH_ESIZE;
    if (st == SPH_OK) st = sph_nsearch_fill(&g, x, N, hv, 0, kappa, SPH_NSEARCH_SYMMETRIC, offset, *index, offset[N]);
    free(work);
    return st;
}
/* end snippet */

int main(int argc, char **argv)
{
    const double pi = 3.14159265358979323846, eps = sizeof(sph_real) == sizeof(float) ? 1.2e-7 : 2.3e-16;
    const sph_real dx = (sph_real)1 / SIDE, eta = (sph_real)1.2;
    static sph_real x[3 * N], v[3 * N], m[N], h[N], hl[N], rho[N], omega[N], A[N];
    static sph_real dvdt[3 * N], dudt[N], dvdt2[3 * N], dudt2[N], rho2[N];
    static sph_off offset[N + 1], half_offset[N + 1], t_offset[N + 1];
    static int state[N];
    const sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}};
    const sph_view xv = sph_view_interleaved(x, 3), mv = sph_view_soa(m, NULL, NULL);
    sph_idx *index = NULL, *half_index = NULL;
    sph_off *t_slot = NULL, pairs = 0, nbuf;
    sph_real *buf = NULL, *to_i = NULL, *to_j, hmin, hmax;
    sph_neighbours list;
    sph_hctx c;
    sph_hreport rep;
    sph_pairs P;
    double res = 0, mom[3] = {0, 0, 0}, mom_abs = 0, en = 0, en_abs = 0, diff = 0, amax = 0, drho = 0;
    unsigned rng = 12345u;
    int i, a, round, st, check = argc == 2 && strcmp(argv[1], "--check") == 0;
    if (argc > 1 && !check) {
        fprintf(stderr, "%s: unknown argument '%s'; usage: %s [--check]\n", argv[0], argv[1], argv[0]);
        return 2;
    }
    for (i = 0; i < N; ++i) {
        const double x0 = ((i % SIDE) + 0.5) / SIDE;
        x[3 * i] = (sph_real)(x0 + 0.4 * sin(2 * pi * x0) / (2 * pi));
        x[3 * i + 1] = dx * (sph_real)((i / SIDE) % SIDE + 0.5);
        x[3 * i + 2] = dx * (sph_real)(i / (SIDE * SIDE) + 0.5);
        for (a = 0; a < 3; ++a) {
            rng = rng * 1103515245u + 12345u;
            v[3 * i + a] = (sph_real)((rng >> 8) % 2001) / 1000 - 1; /* -1 .. 1 */
        }
        m[i] = dx * dx * dx;
        h[i] = (sph_real)0.8 * eta * dx; /* the first guess: 20 % short */
        hl[i] = (sph_real)1.1 * h[i];    /* the first lists reach kappa 1.1 h */
    }

    /* 1. Adaptive h: search at kappa h_list_i, solve, search again where h outgrew the list. */
    /* snippet: adaptive_h */
    for (round = 1; round <= 5; ++round) {
        if ((st = search(xv, hl, &box, offset, &index)) != SPH_OK) return fail("search", st);
        list.n_targets = list.n_sources = N;
        list.offset = offset;
        list.index = index;
        c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &list, xv, mv, 0); /* eta 1.2, tol 1e-6 (float: 64 eps) */
        c.box = &box;                                             /* the periodic box the lists were built in */
        c.h_list = sph_view_soa(hl, NULL, NULL);                  /* row i: every j within kappa hl_i */
        c.eta = eta;
        st = sph_h_solve(&c, sph_out_soa(h, NULL, NULL), sph_out_soa(rho, NULL, NULL),
                         sph_out_soa(omega, NULL, NULL), NULL, state, &rep);
        if (st != SPH_OK) return fail("sph_h_solve", st);
        printf("search %d: %ld list entries; %ld density sums (at most %d per particle), %ld not converged, "
               "%ld beyond their list\n", round, (long)offset[N], (long)rep.iterations, rep.max_iterations,
               (long)rep.n_not_converged, (long)rep.n_beyond_list);
        if (rep.n_not_converged > 0) return stop("sph_h_solve: particles not converged (max_iter sums)");
        if (rep.n_beyond_list == 0) break;
        for (i = 0; i < N; ++i) /* h[i] holds the solver's estimate beyond the list: reach 1.2 times that */
            if (state[i] == SPH_H_BEYOND_LIST) hl[i] = (sph_real)1.2 * h[i];
    }
    if (rep.n_beyond_list > 0) return stop("particles still beyond their lists after 5 searches");
    /* end snippet */
    for (i = 0; i < N; ++i) { /* (H1): the neighbour mass of eta, m (eta / h)^3, is the density */
        const double target = (double)m[i] * pow((double)eta / (double)h[i], 3);
        const sph_real p = rho[i] * (sph_real)pow((double)rho[i], 2.0 / 3.0); /* p = rho^(5/3) */
        const double r = fabs(target - (double)rho[i]) / (double)rho[i];
        res = r > res ? r : res;
        A[i] = sph_gradh_factor(p, rho[i], omega[i]); /* A = p / (Omega rho^2) */
    }

    /* 2. Grad-h forces (H5), (H6), gather form: every pair seen from both of its rows. */
    /* snippet: gather */
    st = sph_gradh_forces(&c, sph_view_interleaved(v, 3), sph_view_soa(h, NULL, NULL), sph_view_soa(A, NULL, NULL),
                          sph_out_interleaved(dvdt, 3), sph_out_soa(dudt, NULL, NULL));
    if (st != SPH_OK) return fail("sph_gradh_forces", st);
    /* end snippet */

    /* 3. Pair-once: the half list and its transpose, then each pair evaluated once. */
    /* snippet: pair_once */
    half_index = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)offset[N]); /* pairs <= list entries: room for all */
    t_slot = (sph_off *)malloc(sizeof(sph_off) * (size_t)offset[N]);
    if (half_index == NULL || t_slot == NULL) return fail("pair arrays", SPH_ESIZE);
    st = sph_pairs_build(&list, half_offset, half_index, offset[N], t_offset, t_slot, &pairs, &P);
    if (st != SPH_OK) return fail("sph_pairs_build", st);
    nbuf = sph_gradh_pairs_buffer_len(3, pairs); /* 2 (dim + 1) reals per pair */
    if ((buf = (sph_real *)malloc(sizeof(sph_real) * (size_t)nbuf)) == NULL) return fail("buffer", SPH_ESIZE);
    st = sph_gradh_forces_pairs(&c, &P, sph_view_interleaved(v, 3), sph_view_soa(h, NULL, NULL),
                                sph_view_soa(A, NULL, NULL), buf, nbuf, sph_out_interleaved(dvdt2, 3),
                                sph_out_soa(dudt2, NULL, NULL));
    if (st != SPH_OK) return fail("sph_gradh_forces_pairs", st);
    /* A pair term of one's own, here the density (H2) at each particle's h: pair k = (i, j) writes what it adds
       to i at k of to_i and what it adds to j at t_slot[k] of to_j; sph_pairs_reduce sums both in a fixed order. */
    to_i = (sph_real *)malloc(sizeof(sph_real) * (size_t)sph_pairs_buffer_len(1, pairs)); /* 1 real per pair, twice */
    if (to_i == NULL) return fail("own buffer", SPH_ESIZE);
    to_j = to_i + pairs;
    for (i = 0; i < N; ++i) {
        sph_off k;
        for (k = P.half.offset[i]; k < P.half.offset[i + 1]; ++k) {
            const sph_idx j = P.half.index[k];
            sph_real r2 = 0, r;
            for (a = 0; a < 3; ++a) {
                const sph_real d = sph_box_delta(&box, a, x[3 * i + a] - x[3 * j + a]);
                r2 += d * d;
            }
            r = (sph_real)sqrt((double)r2);
            to_i[k] = m[j] * sph_kernel_w(SPH_KERNEL_CUBIC, 3, r, h[i]);
            to_j[P.t_slot[k]] = m[i] * sph_kernel_w(SPH_KERNEL_CUBIC, 3, r, h[j]);
        }
    }
    if ((st = sph_pairs_reduce(&P, 1, to_i, to_j, rho2)) != SPH_OK) return fail("sph_pairs_reduce", st);
    for (i = 0; i < N; ++i) rho2[i] += m[i] * sph_kernel_w(SPH_KERNEL_CUBIC, 3, 0, h[i]); /* the self term */
    /* end snippet */

    hmin = hmax = h[0];
    for (i = 0; i < N; ++i) {
        const double d = fabs((double)rho2[i] - (double)rho[i]) / (double)rho[i];
        hmin = h[i] < hmin ? h[i] : hmin;
        hmax = h[i] > hmax ? h[i] : hmax;
        drho = d > drho ? d : drho;
        en += (double)m[i] * (double)dudt2[i];
        en_abs += fabs((double)m[i] * (double)dudt2[i]);
        diff = fabs((double)dudt2[i] - (double)dudt[i]) > diff ? fabs((double)dudt2[i] - (double)dudt[i]) : diff;
        for (a = 0; a < 3; ++a) {
            const double f = (double)m[i] * (double)dvdt2[3 * i + a];
            const double e = fabs((double)dvdt2[3 * i + a] - (double)dvdt[3 * i + a]);
            mom[a] += f;
            mom_abs += fabs(f);
            en += f * (double)v[3 * i + a];
            en_abs += fabs(f * (double)v[3 * i + a]);
            diff = e > diff ? e : diff;
            amax = fabs((double)dvdt[3 * i + a]) > amax ? fabs((double)dvdt[3 * i + a]) : amax;
        }
    }
    printf("%d particles, %ld pairs; h / dx from %.3f to %.3f (first guess %.3f)\n", N, (long)pairs,
           (double)(hmin / dx), (double)(hmax / dx), 0.8 * (double)eta);
    printf("(H1) |m (eta/h)^3 - rho| / rho at most %.2e (tol %.0e)\n", res, (double)c.tol);
    printf("pair-once: momentum %.1e, energy %.1e of the sums of magnitudes; against gather %.1e of %.2e; "
           "own density sum against the solver's %.1e\n",
           sqrt(mom[0] * mom[0] + mom[1] * mom[1] + mom[2] * mom[2]) / mom_abs, fabs(en) / en_abs, diff, amax, drho);
    free(index), free(half_index), free(t_slot), free(buf), free(to_i);
    if (check) {
        /* (H1) to 4 d tol: the Newton step that stopped the solver was below tol h, |f| <= tol h f' = d Omega rho tol;
           the sums below differ from each other only in the order of their terms */
        const int ok = res <= 12 * (double)c.tol && fabs(mom[0]) <= 100 * eps * mom_abs &&
                       fabs(mom[1]) <= 100 * eps * mom_abs && fabs(mom[2]) <= 100 * eps * mom_abs &&
                       fabs(en) <= 100 * eps * en_abs && diff <= 100 * eps * amax && drho <= 100 * eps;
        printf("smoothing_length_quickstart --check: %s\n", ok ? "pass" : "FAIL");
        return ok ? 0 : 1;
    }
    return 0;
}
