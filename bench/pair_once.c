/* bench/pair_once.c - the grad-h pressure force (docs/smoothing_length.md
 * (H5), (H6)) in gather form (sph_gradh_forces: each pair evaluated from
 * both of its rows) against the pair-once form (sph_gradh_forces_pairs:
 * each pair once into a buffer, then the fixed-order reduction (H8)), with
 * the section-6 pressure gradient (O8) as the gather operator of reference.
 * Run by hand (not part of make test: timings never are):
 *
 *   gcc -O2 -std=c99 -I. bench/pair_once.c -o build/pair_once -lm
 *   gcc -O2 -std=c99 -fopenmp -I. bench/pair_once.c -o build/pair_once_omp -lm
 *   gcc -O3 -march=native -fno-math-errno -std=c99 -I. bench/pair_once.c -o build/pair_once_native -lm
 *   ./build/pair_once [side] [repeats]     (default 40: 40^3 particles, 9 repeats)
 *
 * Then the shock tube's first pair loop (as examples/sod_shock.c had it
 * before its SPHENIX switches and gather loop: grad-h momentum and energy
 * (H5), (H6), signal-velocity viscosity (S3), (S4), Price's thermal
 * conductivity, div v and the largest signal velocity), pair-once, in two
 * forms: one pair at a time with the scalar pair terms (sph_kernel_f,
 * sph_pair_gradh_*, sph_pair_av_signal, sph_pair_av_apply: scalar_pair),
 * and as a caller's loop over the lanes of sph_batch_fill
 * (docs/smoothing_length.md, "Pair batches"; F alone, sph_batch_select;
 * the loop's fields packed per particle, two cache lines, the fills reading
 * x and h from there too); both then reduced by sph_pairs_reduce, and the
 * largest difference of the two results printed; the batch form again with
 * i's share summed in the loop (sph_pairs_reduce_rows: no to_i buffer),
 * and with j's share stored at the pair index k instead of its slot
 * (sph_pairs_reduce_rows_k), both of which must equal the first bit for
 * bit; with j's share added to its row in the loop (one thread: no
 * buffer, no reduction; the same terms in another order, its largest
 * difference from the scalar form printed); the gather form on the full
 * list for comparison (each pair evaluated from both rows, no stores: its
 * time per unordered pair); then
 * the fill alone, F alone and W and F. Build also with -O3 -march=native
 * (the lane loops then use the widest vectors).
 *
 * 3-D perturbed lattice in a periodic unit box, h solved by sph_h_solve
 * (eta 1.2, cubic spline: about 58 neighbours), one symmetric list at
 * 1.1 h. The forms run one after another in each repeat; prints the
 * median over the repeats in ns per pair (pairs = unordered pairs i < j of
 * the list), the median of the per-repeat gather / pair-once ratios, and the
 * one-time cost of sph_pairs_build.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
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

/* Per-particle fields of the shock-tube pair loop (interleaved x, v). */
typedef struct {
    const sph_real *x, *v, *m, *h, *rho, *A, *u, *p, *cs, *alpha;
    const sph_box *box;
    sph_real beta, alpha_u;
} fields;

/* The shock tube's first pair terms for pair k = (i, j), one pair at a time
 * with the scalar pair terms; masses m_j into i's terms, m_i into j's: to
 * t_i[0..4] (dv/dt, du/dt, m div v) and t_j[0..4]. */
static void scalar_pair(const fields *f, sph_idx i, sph_idx j, sph_real *ti, sph_real *tj, sph_real *vs)
{
    sph_real dx[3], dv[3], xji[3], vji[3], r2 = 0, e = 0, Fi, Fj, Fb, rhob, Pi, vu, cond, s, r;
    const sph_real mi = f->m[i], mj = f->m[j];
    int a;
    for (a = 0; a < 3; ++a) {
        dx[a] = sph_box_delta(f->box, a, f->x[3 * i + a] - f->x[3 * j + a]);
        dv[a] = f->v[3 * i + a] - f->v[3 * j + a];
        xji[a] = -dx[a], vji[a] = -dv[a];
        r2 += dx[a] * dx[a];
        e += dv[a] * dx[a];
    }
    r = sqrt(r2);
    Fi = sph_kernel_f(SPH_KERNEL_CUBIC, 3, r, f->h[i]);
    Fj = sph_kernel_f(SPH_KERNEL_CUBIC, 3, r, f->h[j]);
    for (a = 0; a < 5; ++a) ti[a] = tj[a] = 0;
    sph_pair_gradh_pressure(3, mj, f->A[i], f->A[j], Fi, Fj, dx, ti);
    sph_pair_gradh_pressure(3, mi, f->A[j], f->A[i], Fj, Fi, xji, tj);
    for (a = 0; a < 3; ++a) ti[a] = -ti[a], tj[a] = -tj[a]; /* dv/dt = -acc */
    ti[3] = sph_pair_gradh_energy(3, mj, f->A[i], Fi, dv, dx);
    tj[3] = sph_pair_gradh_energy(3, mi, f->A[j], Fj, vji, xji);
    Fb = (Fi + Fj) / 2;
    rhob = (f->rho[i] + f->rho[j]) / 2;
    Pi = sph_pair_av_signal(3, (f->alpha[i] + f->alpha[j]) / 2, f->beta, f->cs[i], f->cs[j], rhob, dx, dv);
    ti[3] += sph_pair_av_apply(3, mj, Pi, Fb, dx, dv, ti);
    tj[3] += sph_pair_av_apply(3, mi, Pi, Fb, xji, vji, tj);
    vu = sqrt(fabs(f->p[i] - f->p[j]) / rhob);
    cond = f->alpha_u * vu * (f->u[i] - f->u[j]) * Fb * r / rhob;
    ti[3] += mj * cond;
    tj[3] -= mi * cond;
    ti[4] = mj * e * Fi;
    tj[4] = mi * e * Fj;
    s = sph_pair_signal_velocity(3, f->beta, f->cs[i], f->cs[j], dx, dv);
    *vs = s > *vs ? s : *vs;
}

/* What the batch loop reads of a particle, side by side: the partner's
 * fields then cost two cache lines (ten separate arrays: ten lines), and the
 * fills read x and h from here too (sph_view_aos). */
typedef struct {
    sph_real x[3], h, v[3], m, A, rho, cs, u, p, alpha, pad[2];
} part;

/* The fields of the batch loop side by side, once per step (after h, rho,
 * A and c_s). */
static void pack(part *P, int n, const sph_real *x, const sph_real *v, const sph_real *h, const sph_real *m,
                 const sph_real *A, const sph_real *rho, const sph_real *cs, const sph_real *u, const sph_real *p,
                 const sph_real *al)
{
    int i, a;
    for (i = 0; i < n; ++i) {
        part *q = P + i;
        for (a = 0; a < 3; ++a) q->x[a] = x[3 * i + a], q->v[a] = v[3 * i + a];
        q->h = h[i], q->m = m[i], q->A = A[i], q->rho = rho[i], q->cs = cs[i], q->u = u[i], q->p = p[i], q->alpha = al[i];
        q->pad[0] = q->pad[1] = 0;
    }
}

/* The ways the batch loop stores its results (see batch_rows). */
enum { TO_I_SLOTS, ROWS_SLOTS, ROWS_AT_K, ROWS_DIRECT, GATHER };

/* The same equations on batches, in three plain loops over all SPH_BATCH
 * lanes (padding lanes compute harmless zeros): the partner's fields
 * gathered into lane arrays, then the arithmetic (it vectorises: no
 * gathers, branches or scalar sqrt inside; two divisions per lane, 1/rho_ij
 * and 1/r, multiplied where needed), then the stores. form: TO_I_SLOTS
 * i's share to to_i[k] (contiguous) and j's scattered to to_j[t_slot[k]]
 * (sph_pairs_reduce then); ROWS_SLOTS i's share added up in row order into
 * rows[5 i ..] (sph_pairs_reduce_rows then; to_i unused); ROWS_AT_K the
 * same with j's share at k, in sequence (sph_pairs_reduce_rows_k then);
 * ROWS_DIRECT j's share added to rows[5 j ..] in the loop and i's summed
 * in lane arrays (one thread: rows zeroed before, no buffer, no reduction);
 * GATHER over a full list (each pair in both rows): i's share into rows,
 * nothing stored for j. */
static sph_real batch_rows(const part *P, sph_real beta, sph_real alpha_u, const sph_batch_src *S,
                           const sph_pairs *pr, int form, sph_real *to_i, sph_real *to_j, sph_real *rows)
{
    const sph_idx n = S->list->n_targets;
    sph_real vmax = 0;
    sph_idx i;
    for (i = 0; i < n; ++i) {
        const part *Pi_ = P + i;
        const sph_real mi = Pi_->m, Ai = Pi_->A, rhoi = Pi_->rho, ci = Pi_->cs, ui = Pi_->u, pi = Pi_->p;
        const sph_real ai = Pi_->alpha, vi0 = Pi_->v[0], vi1 = Pi_->v[1], vi2 = Pi_->v[2];
        int c, l;
        sph_real si[5] = {0, 0, 0, 0, 0}, sl[5][SPH_BATCH] = {{0}};
        sph_batch b;
        sph_off next = 0;
        while (sph_batch_fill(S, i, &next, &b) > 0) {
            sph_real mj[SPH_BATCH], Aj[SPH_BATCH], rhoj[SPH_BATCH], cj[SPH_BATCH], uj[SPH_BATCH], pj[SPH_BATCH];
            sph_real aj[SPH_BATCH], vj[3][SPH_BATCH], vu[SPH_BATCH], irb[SPH_BATCH], ir[SPH_BATCH];
            sph_real gi[SPH_BATCH], gj[SPH_BATCH], ei[SPH_BATCH], ej[SPH_BATCH], di[SPH_BATCH], dj[SPH_BATCH], vs[SPH_BATCH];
            for (l = 0; l < SPH_BATCH; ++l) { /* the partner's fields: two cache lines */
                const part *Pj = P + b.j[l];
                mj[l] = Pj->m, Aj[l] = Pj->A, rhoj[l] = Pj->rho, cj[l] = Pj->cs, uj[l] = Pj->u, pj[l] = Pj->p;
                aj[l] = Pj->alpha, vj[0][l] = Pj->v[0], vj[1][l] = Pj->v[1], vj[2][l] = Pj->v[2];
            }
            for (l = 0; l < SPH_BATCH; ++l) {
                irb[l] = 2 / (rhoi + rhoj[l]);          /* 1 / rho_ij */
                ir[l] = 1 / (b.r[l] > 0 ? b.r[l] : 1); /* here: a division by a select stays scalar (gcc -O2) */
            }
            for (l = 0; l < SPH_BATCH; ++l) vu[l] = fabs(pi - pj[l]) * irb[l];
            sph_batch_sqrt(vu); /* sqrt(|p_i - p_j| / rho_ij) */
            for (l = 0; l < SPH_BATCH; ++l) {
                const sph_real dx0 = b.dx[0][l], dx1 = b.dx[1][l], dx2 = b.dx[2][l], r = b.r[l];
                const sph_real e = (vi0 - vj[0][l]) * dx0 + (vi1 - vj[1][l]) * dx1 + (vi2 - vj[2][l]) * dx2;
                const sph_real Fi = b.F_i[l], Fj = b.F_j[l], Fb = (Fi + Fj) / 2;
                const sph_real w = (e < 0 ? e : 0) * ir[l]; /* no division under a condition: */
                const sph_real vsig = ci + cj[l] - beta * w;
                const sph_real Pi = -((ai + aj[l]) / 4) * vsig * w * irb[l]; /* the vectoriser would need masks */
                const sph_real cf = Ai * Fi + Aj[l] * Fj + Pi * Fb;
                const sph_real cond = alpha_u * vu[l] * (ui - uj[l]) * Fb * r * irb[l];
                gi[l] = mj[l] * cf, gj[l] = mi * cf; /* dv_i/dt = -g_i x_ij, dv_j/dt = g_j x_ij */
                ei[l] = mj[l] * (Ai * Fi * e + Pi * Fb * e / 2 + cond);
                ej[l] = mi * (Aj[l] * Fj * e + Pi * Fb * e / 2 - cond);
                di[l] = mj[l] * e * Fi, dj[l] = mi * e * Fj;
                vs[l] = b.j[l] != i ? vsig : 0; /* (a gather list's self pair: not a pair) the largest after the
                                                   loop: a max reduction here stops the vectoriser */
            }
            if (form == TO_I_SLOTS) { /* to_i[k]: the batch's pairs are consecutive in the half list */
                sph_real *ti = to_i + 5 * b.k[0];
                for (l = 0; l < b.n; ++l) {
                    for (c = 0; c < 3; ++c) ti[5 * l + c] = -gi[l] * b.dx[c][l];
                    ti[5 * l + 3] = ei[l], ti[5 * l + 4] = di[l];
                }
            } else if (form == ROWS_DIRECT) { /* any order will do: the lanes add up i's share in vectors */
                for (l = 0; l < SPH_BATCH; ++l) {
                    for (c = 0; c < 3; ++c) sl[c][l] -= gi[l] * b.dx[c][l];
                    sl[3][l] += ei[l], sl[4][l] += di[l];
                }
            } else { /* i's share in registers, in the order sph_pairs_reduce adds to_i */
                for (l = 0; l < b.n; ++l) {
                    for (c = 0; c < 3; ++c) si[c] += -gi[l] * b.dx[c][l];
                    si[3] += ei[l], si[4] += di[l];
                }
            }
            if (form == ROWS_AT_K) { /* j's share at k: in sequence, like to_i */
                sph_real *tk = to_j + 5 * b.k[0];
                for (l = 0; l < b.n; ++l) {
                    for (c = 0; c < 3; ++c) tk[5 * l + c] = gj[l] * b.dx[c][l];
                    tk[5 * l + 3] = ej[l], tk[5 * l + 4] = dj[l];
                }
            } else if (form == ROWS_DIRECT) { /* j's share added to its row now: one thread owns them all */
                for (l = 0; l < b.n; ++l) {
                    sph_real *tj = rows + 5 * b.j[l];
                    for (c = 0; c < 3; ++c) tj[c] += gj[l] * b.dx[c][l];
                    tj[3] += ej[l], tj[4] += dj[l];
                }
            } else if (form != GATHER) { /* at its slot: 40 or so places per row */
                for (l = 0; l < b.n; ++l) {
                    sph_real *tj = to_j + 5 * pr->t_slot[b.k[l]];
                    for (c = 0; c < 3; ++c) tj[c] = gj[l] * b.dx[c][l];
                    tj[3] = ej[l], tj[4] = dj[l];
                }
            }
            for (l = 0; l < b.n; ++l) vmax = vs[l] > vmax ? vs[l] : vmax;
        }
        if (form == ROWS_DIRECT) { /* row i has had its share from rows before it */
            for (c = 0; c < 5; ++c)
                for (l = 0; l < SPH_BATCH; ++l) si[c] += sl[c][l];
            for (c = 0; c < 5; ++c) rows[5 * i + c] += si[c];
        } else if (form != TO_I_SLOTS)
            for (c = 0; c < 5; ++c) rows[5 * i + c] = si[c];
    }
    return vmax;
}

/* The memory traffic of the batch loop at k alone, for the floor of its
 * time: each pair's partner fields read (the two cache lines of part), 5
 * reals stored at k and 5 added to the row, no kernel and no pair
 * arithmetic; sph_pairs_reduce_rows_k after it. */
static sph_real traffic_only(const part *P, const sph_pairs *pr, sph_real *to_j, sph_real *rows)
{
    const sph_idx n = pr->half.n_targets;
    sph_idx i;
    sph_real s = 0;
    for (i = 0; i < n; ++i) {
        sph_real si[5] = {0, 0, 0, 0, 0};
        sph_off k;
        int c;
        for (k = pr->half.offset[i]; k < pr->half.offset[i + 1]; ++k) {
            const part *q = P + pr->half.index[k];
            sph_real *t = to_j + 5 * k;
            t[0] = q->x[0] + q->v[0], t[1] = q->x[1] + q->v[1], t[2] = q->x[2] + q->v[2];
            t[3] = q->m + q->A + q->rho + q->h, t[4] = q->cs + q->u + q->p + q->alpha;
            for (c = 0; c < 5; ++c) si[c] += t[c];
        }
        for (c = 0; c < 5; ++c) rows[5 * i + c] = si[c];
        s += si[0];
    }
    return s;
}

int main(int argc, char **argv)
{
    const int side = argc > 1 ? atoi(argv[1]) : 40, reps = argc > 2 ? atoi(argv[2]) : 9;
    const int n = side * side * side;
    const double dx = 1.0 / side;
    sph_real *x, *v, *m, *h, *hl, *rho, *om, *p, *A, *P, *dv, *du, *buf, *V, *u, *cs, *al, *t5, *f5[6];
    sph_off *off = NULL, *hoff, *toff, *tpair, pairs;
    sph_idx *idx = NULL, *hidx;
    sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}};
    sph_neighbours full = SPH_NEIGHBOURS_INIT(0, 0, NULL, NULL); /* box unknown: c.box gives it */
    sph_pairs pr;
    sph_hctx c;
    sph_hreport rep;
    tp_rng g = {7};
    double *t[14], med[14], tb, diff = 0, diffg = 0, diffd = 0, diff2 = 0, fmax = 0, sink = 0;
    sph_real vs[6] = {0, 0, 0, 0, 0, 0};
    sph_batch_src bs, bw, bg;
    sph_view xv, hv5;
    part *pk, *P5;
    fields fl;
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
    u = malloc(sizeof(sph_real) * (size_t)n), cs = malloc(sizeof(sph_real) * (size_t)n);
    al = malloc(sizeof(sph_real) * (size_t)n);
    f5[0] = malloc(sizeof(sph_real) * 5 * (size_t)n), f5[1] = malloc(sizeof(sph_real) * 5 * (size_t)n);
    f5[2] = malloc(sizeof(sph_real) * 5 * (size_t)n), f5[3] = malloc(sizeof(sph_real) * 5 * (size_t)n);
    f5[4] = malloc(sizeof(sph_real) * 5 * (size_t)n), f5[5] = malloc(sizeof(sph_real) * 5 * (size_t)n);
    for (i = 0; i < 14; ++i) t[i] = malloc(sizeof(double) * (size_t)reps);
    if (!u || !cs || !al || !f5[0] || !f5[1] || !f5[2] || !f5[3] || !f5[4] || !f5[5]) return 1;
    if (!x || !v || !m || !h || !hl || !rho || !om || !p || !A || !P || !V || !dv || !du) return 1;
    for (i = 0; i < 14; ++i)
        if (!t[i]) return 1;
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
        u[i] = (sph_real)tp_range(&g, 1, 2);
        al[i] = (sph_real)tp_range(&g, 0.1, 1);
        p[i] = (sph_real)(2.0 / 3.0) * rho[i] * u[i]; /* gamma 5/3 */
        cs[i] = sqrt((sph_real)(5.0 / 3.0) * p[i] / rho[i]);
        A[i] = sph_gradh_factor(p[i], rho[i], om[i]);
        P[i] = sph_pressure_factor(p[i], rho[i]);
        V[i] = m[i] / rho[i];
    }
    hoff = malloc(sizeof(sph_off) * (size_t)(n + 1)), toff = malloc(sizeof(sph_off) * (size_t)(n + 1));
    hidx = malloc(sizeof(sph_idx) * (size_t)off[n]), tpair = malloc(sizeof(sph_off) * (size_t)off[n]);
    buf = malloc(sizeof(sph_real) * (size_t)sph_gradh_pairs_buffer_len(3, off[n]));
    t5 = malloc(sizeof(sph_real) * (size_t)sph_pairs_buffer_len(5, off[n]));
    if (!hoff || !toff || !hidx || !tpair || !buf || !t5) return 1;
    tb = tm_now();
    st = sph_pairs_build(&full, hoff, hidx, off[n], toff, tpair, &pairs, &pr);
    tb = tm_now() - tb;
    if (st != SPH_OK) return fprintf(stderr, "pairs: %s\n", sph_strerror(st)), 1;
    pk = malloc(sizeof(part) * (size_t)n + 64); /* aligned to 64 bytes: a particle is two cache lines */
    if (!pk) return 1;
    P5 = (part *)(void *)((char *)pk + (64 - (size_t)((uintptr_t)pk % 64)) % 64);
    pack(P5, n, x, v, h, m, A, rho, cs, u, p, al);
    xv = sph_view_aos(P5[0].x, 3, sizeof(part)), hv5 = sph_view_aos(&P5[0].h, 1, sizeof(part));
    st = sph_batch_source(&bs, SPH_KERNEL_CUBIC, 3, &pr.half, &box, xv, hv5);
    if (st == SPH_OK) /* W and F (the default), for the time of the fill alone */
        st = sph_batch_source(&bw, SPH_KERNEL_CUBIC, 3, &pr.half, &box, xv, hv5);
    if (st == SPH_OK) st = sph_batch_source(&bg, SPH_KERNEL_CUBIC, 3, &full, &box, xv, hv5); /* the gather form */
    if (st == SPH_OK) st = sph_batch_select(&bs, SPH_BATCH_F); /* the pair loop reads F only */
    if (st == SPH_OK) st = sph_batch_select(&bg, SPH_BATCH_F);
    if (st != SPH_OK) return fprintf(stderr, "batch source: %s\n", sph_strerror(st)), 1;
    fl.x = x, fl.v = v, fl.m = m, fl.h = h, fl.rho = rho, fl.A = A, fl.u = u, fl.p = p, fl.cs = cs, fl.alpha = al;
    fl.box = &box, fl.beta = 3, fl.alpha_u = 1;
    for (r = 0; r < reps; ++r) {
        const sph_view vv = sph_view_interleaved(v, 3), hv = sph_view_soa(h, NULL, NULL);
        const sph_view Av = sph_view_soa(A, NULL, NULL);
        const sph_out dvo = sph_out_interleaved(dv, 3), duo = sph_out_soa(du, NULL, NULL);
        double t0 = tm_now(), t1, t2, t3, t4, t5s;
        sph_idx ii;
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
        vs[0] = 0;
        for (ii = 0; ii < n; ++ii) {
            sph_off k;
            for (k = pr.half.offset[ii]; k < pr.half.offset[ii + 1]; ++k)
                scalar_pair(&fl, ii, pr.half.index[k], t5 + 5 * k, t5 + 5 * (pairs + pr.t_slot[k]), &vs[0]);
        }
        st |= sph_pairs_reduce(&pr, 5, t5, t5 + 5 * pairs, f5[0]);
        t4 = tm_now();
        pack(P5, n, x, v, h, m, A, rho, cs, u, p, al);
        t[11][r] = tm_now() - t4;
        t4 = tm_now();
        vs[1] = batch_rows(P5, fl.beta, fl.alpha_u, &bs, &pr, TO_I_SLOTS, t5, t5 + 5 * pairs, NULL);
        st |= sph_pairs_reduce(&pr, 5, t5, t5 + 5 * pairs, f5[1]);
        t5s = tm_now();
        t[5][r] = t5s - t4;
        vs[2] = batch_rows(P5, fl.beta, fl.alpha_u, &bs, &pr, ROWS_SLOTS, NULL, t5 + 5 * pairs, f5[2]);
        st |= sph_pairs_reduce_rows(&pr, 5, t5 + 5 * pairs, f5[2]);
        t[8][r] = tm_now() - t5s;
        t5s = tm_now();
        vs[3] = batch_rows(P5, fl.beta, fl.alpha_u, &bs, &pr, ROWS_AT_K, NULL, t5 + 5 * pairs, f5[3]);
        st |= sph_pairs_reduce_rows_k(&pr, 5, t5 + 5 * pairs, f5[3]);
        t[9][r] = tm_now() - t5s;
        t5s = tm_now();
        memset(f5[5], 0, sizeof(sph_real) * 5 * (size_t)n);
        vs[5] = batch_rows(P5, fl.beta, fl.alpha_u, &bs, &pr, ROWS_DIRECT, NULL, NULL, f5[5]);
        t[13][r] = tm_now() - t5s;
        t5s = tm_now();
        vs[4] = batch_rows(P5, fl.beta, fl.alpha_u, &bg, &pr, GATHER, NULL, NULL, f5[4]);
        t[10][r] = tm_now() - t5s;
        t5s = tm_now();
        sink += (double)traffic_only(P5, &pr, t5 + 5 * pairs, t5);
        st |= sph_pairs_reduce_rows_k(&pr, 5, t5 + 5 * pairs, t5);
        t[12][r] = tm_now() - t5s;
        t5s = tm_now();
        if (st != SPH_OK) return fprintf(stderr, "forces: %s\n", sph_strerror(st)), 1;
        t[0][r] = t1 - t0, t[1][r] = t2 - t1, t[2][r] = t3 - t2, t[3][r] = (t1 - t0) / (t2 - t1);
        t[4][r] = t4 - t3;
        for (ii = 0; ii < n; ++ii) { /* sph_batch_fill alone: what every batch loop pays for its pairs */
            sph_batch bb;
            sph_off nx = 0;
            while (sph_batch_fill(&bs, ii, &nx, &bb) > 0) sink += (double)bb.F_i[0] + (double)bb.F_j[bb.n - 1];
        }
        t[6][r] = tm_now() - t5s;
        t5s = tm_now();
        for (ii = 0; ii < n; ++ii) {
            sph_batch bb;
            sph_off nx = 0;
            while (sph_batch_fill(&bw, ii, &nx, &bb) > 0) sink += (double)bb.W_i[0] + (double)bb.F_j[bb.n - 1];
        }
        t[7][r] = tm_now() - t5s;
    }
    for (i = 0; i < 14; ++i) med[i] = tm_median(t[i], reps);
    for (i = 0; i < 5 * n; ++i) fmax = fabs(f5[0][i]) > fmax ? fabs(f5[0][i]) : fmax;
    for (i = 0; i < 5 * n; ++i) diff = fabs(f5[1][i] - f5[0][i]) > diff ? fabs(f5[1][i] - f5[0][i]) : diff;
    for (i = 0; i < 5 * n; ++i) diff2 += (f5[2][i] != f5[1][i]) + (f5[3][i] != f5[1][i]); /* the reductions: bit for bit */
    printf("%d particles, %ld pairs (i < j), %.1f neighbours per particle, %s, median of %d\n", n, (long)pairs,
           (double)off[n] / n, sizeof(sph_real) == sizeof(float) ? "float" : "double", reps);
    printf("  grad-h force + du/dt, gather    (sph_gradh_forces)        %7.2f ns/pair\n", 1e9 * med[0] / (double)pairs);
    printf("  grad-h force + du/dt, pair-once (sph_gradh_forces_pairs)  %7.2f ns/pair (speed-up %.2f)\n",
           1e9 * med[1] / (double)pairs, med[3]);
    printf("  pressure gradient (O8), gather  (sph_gradient PRESSURE)   %7.2f ns/pair\n", 1e9 * med[2] / (double)pairs);
    printf("  shock-tube pair loop (H5, H6, S3, S4, conduction, div v), pair-once + sph_pairs_reduce:\n");
    printf("    one pair at a time, scalar pair terms (scalar_pair)  %7.2f ns/pair\n", 1e9 * med[4] / (double)pairs);
    printf("    lanes of sph_batch_fill, SPH_BATCH %2d                         %7.2f ns/pair (speed-up %.2f)\n", SPH_BATCH,
           1e9 * med[5] / (double)pairs, med[4] / med[5]);
    printf("    the same, i's share summed in the loop (sph_pairs_reduce_rows) %7.2f ns/pair (speed-up %.2f)\n",
           1e9 * med[8] / (double)pairs, med[4] / med[8]);
    printf("    the same, j's share stored at k (sph_pairs_reduce_rows_k)      %7.2f ns/pair (speed-up %.2f)\n",
           1e9 * med[9] / (double)pairs, med[4] / med[9]);
    printf("    the same, j's share added to its row in the loop (one thread, no reduction) %7.2f ns/pair (speed-up %.2f)\n",
           1e9 * med[13] / (double)pairs, med[4] / med[13]);
    printf("    gather form: each pair from both rows of the full list, no stores   %7.2f ns/pair (speed-up %.2f)\n",
           1e9 * med[10] / (double)pairs, med[4] / med[10]);
    printf("    of which sph_batch_fill alone (x_ij, r, F at h_i, h_j)      %7.2f ns/pair\n", 1e9 * med[6] / (double)pairs);
    printf("    sph_batch_fill alone with W too (x_ij, r, W, F)              %7.2f ns/pair (checksum %.3g)\n",
           1e9 * med[7] / (double)pairs, sink);
    printf("    the floor of the form at k: its memory traffic alone (partner's fields, to_j at k,\n"
           "      sph_pairs_reduce_rows_k; no kernel, no arithmetic)          %7.2f ns/pair; + the fill alone %.2f\n",
           1e9 * med[12] / (double)pairs, 1e9 * (med[12] + med[6]) / (double)pairs);
    printf("    largest |batch - scalar| / largest |value| %.2g, signal velocity %.17g vs %.17g\n", diff / fmax,
           (double)vs[1], (double)vs[0]);
    for (i = 0; i < 5 * n; ++i) diffg = fabs(f5[4][i] - f5[0][i]) > diffg ? fabs(f5[4][i] - f5[0][i]) : diffg;
    for (i = 0; i < 5 * n; ++i) diffd = fabs(f5[5][i] - f5[0][i]) > diffd ? fabs(f5[5][i] - f5[0][i]) : diffd;
    printf("    added in the loop: largest |direct - scalar| / largest |value| %.2g, signal velocity %.17g\n",
           diffd / fmax, (double)vs[5]);
    printf("    gather form: largest |gather - scalar| / largest |value| %.2g, signal velocity %.17g\n", diffg / fmax, (double)vs[4]);
    printf("    values where the other two batch forms differ from the first: %.0f of %d (signal velocity %.17g, %.17g)\n",
           diff2, 2 * 5 * n, (double)vs[2], (double)vs[3]);
    printf("  the batch loop's fields packed per particle, once per step  %7.2f ns/pair\n", 1e9 * med[11] / (double)pairs);
    printf("  sph_pairs_build once per list                             %7.2f ns/pair\n", 1e9 * tb / (double)pairs);
    free(x), free(v), free(m), free(h), free(hl), free(rho), free(om), free(p), free(A), free(P), free(V), free(dv);
    free(du), free(off), free(idx), free(hoff), free(toff), free(hidx), free(tpair), free(buf);
    free(u), free(cs), free(al), free(f5[0]), free(f5[1]), free(f5[2]), free(f5[3]), free(f5[4]), free(f5[5]), free(t5), free(pk);
    for (i = 0; i < 14; ++i) free(t[i]);
    return 0;
}
