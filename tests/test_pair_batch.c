/* tests/test_pair_batch.c - pair batches (docs/smoothing_length.md, "Pair
 * batches": sph_batch_source, sph_batch_fill).
 *
 * Contents. On a random periodic cloud with per-particle h and a CSR list of
 * ragged rows (lengths 0 .. 3 SPH_BATCH + 3: empty rows, rows a multiple of
 * the batch width and rows with a tail; the self pair and partners up to
 * and beyond the support included), for every kernel and dimension, each
 * lane must hold: the list's j and position k in order, every pair of the
 * row exactly once; x_ij bit for bit sph__h_dx's minimum image (and
 * |x_ij,a| <= L/2, x_i - x_j - x_ij a multiple of L); r bit for bit
 * sph_pair_kernel's r; W and F at h_i and at h_j bit for bit the pair
 * loops' arithmetic (sph__nshape_w, sph__nshape_g scaled by sph__hpow, the
 * forms sph_gradh_forces_pairs uses) where the unit does not fuse the
 * header's a * b + c (sph__fp_contracted; else r within 4 eps and W, F
 * within the bound below), and within 16 eps |ref| + 8 eps S of
 * sph_pair_kernel's W and F (ref; S = |ref at q = 0|, the allowance for the
 * interior roots of the new quartic and values below the normal range; the
 * pair loops' product form is held to 8 eps of the closed forms by
 * test_kernel_pieces.c, the scalar functions to about 1 eps). Padding lanes
 * hold j = i, k = -1 and zeros.
 *
 * Forces. The grad-h momentum and energy equations (H5), (H6) written as a
 * caller's loop over batches of the half list (the loop the page shows)
 * equal sph_gradh_forces_pairs to 4 eps of the largest value.
 *
 * Selection: with sph_batch_select (W alone, F alone, neither) every lane
 * holds the default fill's values bit for bit and zeros in the arrays not
 * asked for. sph_batch_sqrt: bit for bit sph__sqrt in every lane. Far
 * positions: x_ij bit for bit sph__h_dx where x / L exceeds 2^31 (the vector
 * image's fallback), in lanes beside near ones.
 *
 * Bad input: sph_batch_source refuses a NULL list or source, an unknown
 * kernel or dimension, an index outside the particles, an h not usable and
 * a NaN position; sph_batch_select a NULL source and unknown bits;
 * sph_batch_fill gives an empty batch for a target outside
 * the list, a negative cursor and a source that failed.
 */
#include "harness.h"
#include "support/particles.h"

#define NP 97
#define MAXROW (3 * SPH_BATCH + 3)

typedef struct {
    sph_real x[3 * NP], h[NP];
    sph_off off[NP + 1];
    sph_idx idx[NP * MAXROW];
    sph_box box;
    sph_neighbours L;
} pb_cloud;

/* Random positions in a box of sides 1, 0.8, 0.6 (periodic in every axis
 * but the second), h in [0.05, 0.12], row i of length i % (MAXROW + 1)
 * (row 0 empty) with random partners, the first one i itself. */
static void pb_make_cloud(pb_cloud *c, int dim, tp_rng *g)
{
    int i, a, t;
    memset(&c->box, 0, sizeof c->box);
    for (a = 0; a < 3; ++a) c->box.length[a] = (sph_real)(1 - 0.2 * a), c->box.periodic[a] = a != 1;
    for (i = 0; i < NP; ++i) {
        for (a = 0; a < 3; ++a) c->x[3 * i + a] = a < dim ? (sph_real)tp_range(g, 0, 1 - 0.2 * a) : 0;
        c->h[i] = (sph_real)tp_range(g, 0.05, 0.12);
    }
    c->off[0] = 0;
    for (i = 0; i < NP; ++i) {
        const int len = i % (MAXROW + 1);
        for (t = 0; t < len; ++t) c->idx[c->off[i] + t] = t == 0 ? i : (sph_idx)(tp_next(g) % NP);
        c->off[i + 1] = c->off[i] + len;
    }
    c->L = (sph_neighbours)SPH_NEIGHBOURS_INIT(NP, NP, c->off, c->idx);
}

/* ulp-scale bound between the batch and sph_pair_kernel (see the top). */
static int pb_near(sph_real got, sph_real ref, sph_real at0)
{
    return fabs((double)got - (double)ref) <= 16 * TH_EPS * fabs((double)ref) + 8 * TH_EPS * fabs((double)at0);
}

static void pb_check_contents(sph_kernel k, int dim)
{
    pb_cloud c;
    tp_rng g = {(uint64_t)(11 + 7 * k + dim)};
    sph_batch_src S;
    const sph__kdim *kd = &sph__kdims[k][dim - 1];
    const sph__nshape *s = &sph__nshapes[kd->shape];
    sph__period P;
    int i, st, seen_tail = 0, seen_full = 0, seen_empty = 0;
    const int bitwise = !sph__fp_contracted();
    th_begin("batch contents %s %dD %s%s", sph_kernel_name(k), dim, TH_PRECISION, bitwise ? "" : " (contracted)");
    pb_make_cloud(&c, dim, &g);
    P = sph__period_of(&c.box, &c.L, dim);
    st = sph_batch_source(&S, k, dim, &c.L, &c.box, sph_view_interleaved(c.x, 3), sph_view_soa(c.h, NULL, NULL));
    TH_CHECK(st == SPH_OK, "sph_batch_source: %s", sph_strerror(st));
    for (i = 0; i < NP && st == SPH_OK; ++i) {
        sph_batch b;
        sph_off next = 0, o = c.off[i], nb = 0;
        const sph_real hi = c.h[i];
        sph_real xi[3];
        int a, l;
        sph__h_xi(sph_view_interleaved(c.x, 3), dim, i, xi);
        while (sph_batch_fill(&S, i, &next, &b) > 0) {
            ++nb;
            TH_CHECK(b.n == (c.off[i + 1] - o < SPH_BATCH ? c.off[i + 1] - o : SPH_BATCH), "row %d: n = %d", i, b.n);
            seen_tail |= b.n < SPH_BATCH;
            seen_full |= b.n == SPH_BATCH;
            for (l = 0; l < SPH_BATCH; ++l) {
                sph_real dx[3], sum0 = 0;
                if (l >= b.n) {
                    for (a = 0; a < 3; ++a) sum0 += b.dx[a][l] != 0;
                    TH_CHECK(b.j[l] == i && b.k[l] == -1 && sum0 == 0 && b.r[l] == 0 && b.W_i[l] == 0 &&
                                 b.F_i[l] == 0 && b.W_j[l] == 0 && b.F_j[l] == 0,
                             "row %d lane %d: padding j %d k %ld", i, l, (int)b.j[l], (long)b.k[l]);
                    continue;
                }
                {
                    const sph_idx j = c.idx[o];
                    const sph_real hj = c.h[j], r2 = sph__h_dx(&P, dim, xi, sph_view_interleaved(c.x, 3), j, dx);
                    const sph_pair pi = sph_pair_kernel(k, dim, dx, hi), pj = sph_pair_kernel(k, dim, dx, hj);
                    const sph_pair p0i = sph_pair_kernel(k, dim, (const sph_real[3]){0, 0, 0}, hi);
                    const sph_pair p0j = sph_pair_kernel(k, dim, (const sph_real[3]){0, 0, 0}, hj);
                    const sph_real Wi = sph__hpow(kd->alpha * sph__nshape_w(s, sph__sqrt(r2) * (1 / hi)), 1 / hi, dim);
                    const sph_real Fi = sph__hpow(kd->alpha * sph__nshape_g(s, sph__sqrt(r2) * (1 / hi)), 1 / hi, dim + 2);
                    const sph_real Wj = sph__hpow(kd->alpha * sph__nshape_w(s, sph__sqrt(r2) * (1 / hj)), 1 / hj, dim);
                    const sph_real Fj = sph__hpow(kd->alpha * sph__nshape_g(s, sph__sqrt(r2) * (1 / hj)), 1 / hj, dim + 2);
                    TH_CHECK(b.j[l] == j && b.k[l] == o, "row %d lane %d: j %d k %ld, list %d at %ld", i, l, (int)b.j[l],
                             (long)b.k[l], (int)j, (long)o);
                    for (a = 0; a < 3; ++a) {
                        const double L = (double)c.box.length[a], d = (double)b.dx[a][l];
                        const double wrap = ((double)c.x[3 * i + a] - (double)c.x[3 * j + a] - d) / L;
                        TH_CHECK(b.dx[a][l] == dx[a], "row %d lane %d: dx[%d] %.17g, sph__h_dx %.17g", i, l, a, d,
                                 (double)dx[a]);
                        if (a < dim && c.box.periodic[a])
                            TH_CHECK(fabs(d) <= L / 2 * (1 + 4 * TH_EPS) && fabs(wrap - floor(wrap + 0.5)) <= 4 * TH_EPS,
                                     "row %d lane %d: dx[%d] = %.17g not the minimum image", i, l, a, d);
                    }
                    TH_CHECK(bitwise ? b.r[l] == pi.r : fabs((double)b.r[l] - (double)pi.r) <= 4 * TH_EPS * (double)pi.r,
                             "row %d lane %d: r %.17g, sph_pair_kernel %.17g", i, l, (double)b.r[l], (double)pi.r);
                    TH_CHECK(bitwise ? b.W_i[l] == Wi && b.F_i[l] == Fi && b.W_j[l] == Wj && b.F_j[l] == Fj
                                     : pb_near(b.W_i[l], Wi, p0i.W) && pb_near(b.F_i[l], Fi, p0i.F) &&
                                           pb_near(b.W_j[l], Wj, p0j.W) && pb_near(b.F_j[l], Fj, p0j.F),
                             "row %d lane %d: W_i %.17g F_i %.17g W_j %.17g F_j %.17g, pair loops %.17g %.17g %.17g %.17g",
                             i, l, (double)b.W_i[l], (double)b.F_i[l], (double)b.W_j[l], (double)b.F_j[l], (double)Wi,
                             (double)Fi, (double)Wj, (double)Fj);
                    TH_CHECK(pb_near(b.W_i[l], pi.W, p0i.W) && pb_near(b.F_i[l], pi.F, p0i.F) && pb_near(b.W_j[l], pj.W, p0j.W) &&
                                 pb_near(b.F_j[l], pj.F, p0j.F),
                             "row %d lane %d (q_i %.17g): W_i %.17g F_i %.17g W_j %.17g F_j %.17g, sph_pair_kernel %.17g "
                             "%.17g %.17g %.17g",
                             i, l, (double)pi.q, (double)b.W_i[l], (double)b.F_i[l], (double)b.W_j[l],
                             (double)b.F_j[l], (double)pi.W, (double)pi.F, (double)pj.W, (double)pj.F);
                    ++o;
                }
            }
        }
        TH_CHECK(o == c.off[i + 1] && next == c.off[i + 1] - c.off[i], "row %d: %ld of %ld pairs", i, (long)(o - c.off[i]),
                 (long)(c.off[i + 1] - c.off[i]));
        TH_CHECK(b.n == 0 && sph_batch_fill(&S, i, &next, &b) == 0, "row %d: a fill after the end gives %d", i, b.n);
        seen_empty |= c.off[i + 1] == c.off[i] && nb == 0;
    }
    TH_CHECK(seen_tail && seen_full && seen_empty, "rows: tail %d full %d empty %d", seen_tail, seen_full, seen_empty);
    th_end();
}

/* The (H5), (H6) terms of the lanes of batch b of row i: pair (i, j) gives
 * i -m_j (A_i F_i + A_j F_j) x_ij (ci times x_ij) and m_j A_i F_i v_ij .
 * x_ij (ei), j m_i (A_i F_i + A_j F_j) x_ij (cj) and m_i A_j F_j v_ij . x_ij
 * (ej). 3-D. restrict: the outputs overlap neither b nor each other, so
 * the compiler need not reload b->n or the lanes after each store. */
/* snippet: pair_batch_terms */
static void pb_gradh_terms(sph_idx i, const sph_batch *restrict b, const sph_real *v, const sph_real *m,
                           const sph_real *A, sph_real *restrict ci, sph_real *restrict cj, sph_real *restrict ei,
                           sph_real *restrict ej)
{
    int l;
    for (l = 0; l < b->n; ++l) { /* one plain loop over the lanes, it vectorises */
        const sph_idx j = b->j[l];
        const sph_real e = (v[3 * i] - v[3 * j]) * b->dx[0][l] + (v[3 * i + 1] - v[3 * j + 1]) * b->dx[1][l] +
                           (v[3 * i + 2] - v[3 * j + 2]) * b->dx[2][l]; /* v_ij . x_ij */
        const sph_real cf = A[i] * b->F_i[l] + A[j] * b->F_j[l];
        ci[l] = -m[j] * cf, cj[l] = m[i] * cf;
        ei[l] = m[j] * A[i] * b->F_i[l] * e, ej[l] = m[i] * A[j] * b->F_j[l] * e;
    }
}
/* end snippet */

/* (H5), (H6) over batches of the half list, as a caller writes them: pair k
 * = (i, j) puts i's terms into to_i[4 k ..], j's into to_j[4 t_slot[k] ..];
 * sph_pairs_reduce then sums them. */
static int pb_gradh_batches(const sph_pairs *pr, const sph_batch_src *S, const sph_real *v, const sph_real *m,
                         const sph_real *A, sph_real *to_i, sph_real *to_j, sph_real *out)
{
    sph_idx i;
    for (i = 0; i < pr->half.n_targets; ++i) {
        /* snippet: pair_batch */
        sph_batch b;
        sph_off next = 0;
        while (sph_batch_fill(S, i, &next, &b) > 0) {
            sph_real ci[SPH_BATCH], cj[SPH_BATCH], ei[SPH_BATCH], ej[SPH_BATCH];
            int l, a;
            pb_gradh_terms(i, &b, v, m, A, ci, cj, ei, ej); /* the arithmetic */
            for (l = 0; l < b.n; ++l) { /* the stores: i's share at k, j's at its slot */
                sph_real *ti = to_i + 4 * b.k[l], *tj = to_j + 4 * pr->t_slot[b.k[l]];
                for (a = 0; a < 3; ++a) ti[a] = ci[l] * b.dx[a][l], tj[a] = cj[l] * b.dx[a][l];
                ti[3] = ei[l], tj[3] = ej[l];
            }
        }
        /* end snippet */
    }
    return sph_pairs_reduce(pr, 4, to_i, to_j, out);
}

/* The same equations on one thread with no buffers: j's share added to
 * out[4 j ..] as the pair is met, i's to out[4 i ..] after its row (out
 * zeroed first): the terms of pb_gradh_terms, as pb_gradh_batches stores
 * them, summed in another order. */
static void pb_gradh_direct(const sph_pairs *pr, const sph_batch_src *S, const sph_real *v, const sph_real *m,
                            const sph_real *A, sph_real *out)
{
    sph_idx i;
    memset(out, 0, sizeof(sph_real) * 4 * (size_t)pr->half.n_targets);
    for (i = 0; i < pr->half.n_targets; ++i) {
        /* snippet: pair_batch_direct */
        sph_batch b;
        sph_off next = 0;
        sph_real si[4] = {0, 0, 0, 0};
        int a;
        while (sph_batch_fill(S, i, &next, &b) > 0) {
            sph_real ci[SPH_BATCH], cj[SPH_BATCH], ei[SPH_BATCH], ej[SPH_BATCH];
            int l;
            pb_gradh_terms(i, &b, v, m, A, ci, cj, ei, ej); /* the arithmetic */
            for (l = 0; l < b.n; ++l) { /* j's share added to its row now, i's kept */
                sph_real *oj = out + 4 * b.j[l];
                for (a = 0; a < 3; ++a) oj[a] += cj[l] * b.dx[a][l], si[a] += ci[l] * b.dx[a][l];
                oj[3] += ej[l], si[3] += ei[l];
            }
        }
        for (a = 0; a < 4; ++a) out[4 * i + a] += si[a]; /* row i has had its share from the rows before */
        /* end snippet */
    }
}

#define NF 400

static void pb_check_forces(void)
{
    static sph_real x[3 * NF], v[3 * NF], m[NF], h[NF], hl[NF], rho[NF], om[NF], A[NF], dv[3 * NF], du[NF];
    static sph_real out[4 * NF], outd[4 * NF];
    sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}};
    tp_rng g = {2027};
    tp_list L;
    sph_hctx c;
    sph_hreport rep;
    sph_pairs pr;
    sph_batch_src S;
    sph_off *mem = NULL, pairs = 0, cap;
    sph_real *buf = NULL, *to = NULL;
    double worst = 0, worstd = 0, big = 0;
    int i, a, st;
    th_begin("grad-h forces on batches (buffers, and j added in the loop) vs sph_gradh_forces_pairs %s", TH_PRECISION);
    tp_uniform_cloud(3, NF, 1, &g, x);
    for (i = 0; i < NF; ++i) {
        m[i] = (sph_real)(tp_range(&g, 0.5, 1.5) / NF);
        for (a = 0; a < 3; ++a) v[3 * i + a] = (sph_real)tp_range(&g, -1, 1);
        h[i] = (sph_real)(1.2 * pow(1.0 / NF, 1.0 / 3)), hl[i] = (sph_real)0.3;
    }
    st = tp_brute_list(3, x, NF, x, NF, 0, hl, NULL, 2, TP_GATHER, &box, &L) != 0 ? SPH_ESIZE : SPH_OK;
    c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &L.list, sph_view_interleaved(x, 3), sph_view_soa(m, NULL, NULL), 0);
    c.h_list = sph_view_soa(hl, NULL, NULL);
    c.box = &box;
    if (st == SPH_OK)
        st = sph_h_solve(&c, sph_out_soa(h, NULL, NULL), sph_out_soa(rho, NULL, NULL), sph_out_soa(om, NULL, NULL),
                         NULL, NULL, &rep);
    if (st == SPH_OK) tp_free_list(&L);
    for (i = 0; i < NF; ++i) {
        hl[i] = (sph_real)1.1 * h[i];
        A[i] = sph_gradh_factor((sph_real)(2.0 / 3.0) * rho[i] * (sph_real)tp_range(&g, 1, 2), rho[i], om[i]);
    }
    if (st == SPH_OK) st = tp_brute_list(3, x, NF, x, NF, 0, hl, hl, 2, TP_SYMMETRIC, &box, &L) != 0 ? SPH_ESIZE : SPH_OK;
    c.list = &L.list;
    cap = st == SPH_OK ? L.list.offset[NF] : 0;
    mem = (sph_off *)malloc(sizeof(sph_off) * (size_t)(2 * (NF + 1) + cap) + sizeof(sph_idx) * (size_t)cap + 1);
    buf = (sph_real *)malloc(sizeof(sph_real) * (size_t)(sph_gradh_pairs_buffer_len(3, cap) + 1));
    to = (sph_real *)malloc(sizeof(sph_real) * (size_t)(sph_pairs_buffer_len(4, cap) + 1));
    if (st == SPH_OK && (mem == NULL || buf == NULL || to == NULL)) st = SPH_ESIZE;
    if (st == SPH_OK)
        st = sph_pairs_build(&L.list, mem, (sph_idx *)(void *)(mem + 2 * (NF + 1) + cap), cap, mem + NF + 1,
                             mem + 2 * (NF + 1), &pairs, &pr);
    if (st == SPH_OK)
        st = sph_gradh_forces_pairs(&c, &pr, sph_view_interleaved(v, 3), sph_view_soa(h, NULL, NULL),
                                    sph_view_soa(A, NULL, NULL), buf, sph_gradh_pairs_buffer_len(3, pairs),
                                    sph_out_interleaved(dv, 3), sph_out_soa(du, NULL, NULL));
    if (st == SPH_OK)
        st = sph_batch_source(&S, SPH_KERNEL_CUBIC, 3, &pr.half, &box, sph_view_interleaved(x, 3),
                              sph_view_soa(h, NULL, NULL));
    if (st == SPH_OK) st = pb_gradh_batches(&pr, &S, v, m, A, to, to + 4 * pairs, out);
    if (st == SPH_OK) pb_gradh_direct(&pr, &S, v, m, A, outd);
    TH_CHECK(st == SPH_OK && pairs > 20 * NF, "setup: %s, %ld pairs", sph_strerror(st), (long)pairs);
    for (i = 0; st == SPH_OK && i < NF; ++i)
        for (a = 0; a < 4; ++a) {
            const double ref = a < 3 ? (double)dv[3 * i + a] : (double)du[i];
            big = fabs(ref) > big ? fabs(ref) : big;
        }
    for (i = 0; st == SPH_OK && i < NF; ++i)
        for (a = 0; a < 4; ++a) {
            const double ref = a < 3 ? (double)dv[3 * i + a] : (double)du[i], e = fabs((double)out[4 * i + a] - ref);
            /* the same N terms in two orders: each sum within gamma_(N-1) sum |t| of the exact one (Higham,
               Accuracy and Stability of Numerical Algorithms, 2nd ed., eq. 4.4), N eps sum |t| apart at most */
            const sph_off *ko = pr.half.offset, *to_off = pr.t_offset;
            const double nt = (double)(ko[i + 1] - ko[i] + to_off[i + 1] - to_off[i]);
            double sum_abs = 0, bound, ed = fabs((double)outd[4 * i + a] - (double)out[4 * i + a]);
            sph_off k;
            for (k = ko[i]; k < ko[i + 1]; ++k) sum_abs += fabs((double)to[4 * k + a]);
            for (k = to_off[i]; k < to_off[i + 1]; ++k) sum_abs += fabs((double)to[4 * (pairs + k) + a]);
            TH_CHECK(e <= 4 * TH_EPS * big, "particle %d component %d: batches %.17g, sph_gradh_forces_pairs %.17g", i,
                     a, (double)out[4 * i + a], ref);
            bound = nt * TH_EPS * sum_abs;
            TH_CHECK(ed <= bound, "particle %d component %d: added in the loop %.17g, buffers %.17g", i, a,
                     (double)outd[4 * i + a], (double)out[4 * i + a]);
            worst = e > worst ? e : worst;
            if (bound > 0) worstd = ed / bound > worstd ? ed / bound : worstd;
        }
    printf("    largest |batches - sph_gradh_forces_pairs| = %.2f eps of the largest value; added in the loop against\n"
           "    the buffers: at most %.3f of the bound N eps sum |t|\n", worst / (TH_EPS * big), worstd);
    tp_free_list(&L);
    free(mem), free(buf), free(to);
    th_end();
}

/* sph_batch_select: with W alone, F alone or neither, every lane holds what
 * the default fill (both) holds, bit for bit, and zeros in the arrays not
 * asked for. */
static void pb_check_select(sph_kernel k, int dim)
{
    static const int what[3] = {SPH_BATCH_W, SPH_BATCH_F, 0};
    pb_cloud c;
    tp_rng g = {(uint64_t)(5 + 3 * k + dim)};
    sph_batch_src S, T;
    int i, w, st;
    th_begin("batch select %s %dD %s", sph_kernel_name(k), dim, TH_PRECISION);
    pb_make_cloud(&c, dim, &g);
    st = sph_batch_source(&S, k, dim, &c.L, &c.box, sph_view_interleaved(c.x, 3), sph_view_soa(c.h, NULL, NULL));
    TH_CHECK(st == SPH_OK, "sph_batch_source: %s", sph_strerror(st));
    for (w = 0; w < 3 && st == SPH_OK; ++w) {
        T = S;
        TH_CHECK(sph_batch_select(&T, what[w]) == SPH_OK, "select %d refused", what[w]);
        for (i = 0; i < NP; ++i) {
            sph_batch a, b;
            sph_off na = 0, nb = 0;
            while (sph_batch_fill(&S, i, &na, &a) > 0) {
                const int wW = (what[w] & SPH_BATCH_W) != 0, wF = (what[w] & SPH_BATCH_F) != 0;
                int l, bad = 0;
                TH_CHECK(sph_batch_fill(&T, i, &nb, &b) == a.n && nb == na, "row %d: %d pairs, default %d", i, b.n, a.n);
                for (l = 0; l < SPH_BATCH; ++l) {
                    bad += a.j[l] != b.j[l] || a.k[l] != b.k[l] || a.r[l] != b.r[l] || a.dx[0][l] != b.dx[0][l] ||
                           a.dx[1][l] != b.dx[1][l] || a.dx[2][l] != b.dx[2][l];
                    bad += b.W_i[l] != (wW ? a.W_i[l] : 0) || b.W_j[l] != (wW ? a.W_j[l] : 0);
                    bad += b.F_i[l] != (wF ? a.F_i[l] : 0) || b.F_j[l] != (wF ? a.F_j[l] : 0);
                }
                TH_CHECK(bad == 0, "row %d, what %d: %d lanes differ from the default fill", i, what[w], bad);
            }
        }
    }
    th_end();
}

/* sph_batch_sqrt: each lane the square root of sph__sqrt, bit for bit
 * (0, subnormal, exact squares, the largest finite value, random). */
static void pb_check_sqrt(void)
{
    sph_real v[SPH_BATCH], ref[SPH_BATCH];
    tp_rng g = {23};
    int l, t, bad = 0;
    th_begin("batch sqrt %s", TH_PRECISION);
    for (t = 0; t < 50; ++t) {
        for (l = 0; l < SPH_BATCH; ++l) v[l] = (sph_real)(tp_range(&g, 0, 10) * pow(10.0, (double)(l % 7) - 3));
        if (t == 0) v[0] = 0, v[1] = SPH__REAL_MAX, v[2] = (sph_real)4, v[3] = (sph_real)(SPH__REAL_MAX * 0) + 1;
        if (t == 1) v[0] = (sph_real)(sizeof(sph_real) == sizeof(float) ? 1e-42 : 1e-310);
        for (l = 0; l < SPH_BATCH; ++l) ref[l] = sph__sqrt(v[l]);
        sph_batch_sqrt(v);
        for (l = 0; l < SPH_BATCH; ++l) bad += v[l] != ref[l];
    }
    TH_CHECK(bad == 0, "%d lanes differ from sph__sqrt", bad);
    th_end();
}

/* Minimum image of positions far outside the box (x L^-1 beyond 2^31, where
 * the vector image falls back to floor()), in lanes beside near ones: x_ij
 * bit for bit sph__h_dx. */
static void pb_check_far_image(void)
{
    sph_real x[3 * 3] = {(sph_real)0.3, (sph_real)0.2, (sph_real)0.1, (sph_real)0.35, (sph_real)0.25, (sph_real)0.05,
                         (sph_real)3e10, (sph_real)-7e9, (sph_real)0.12};
    sph_real h[3] = {(sph_real)0.2, (sph_real)0.2, (sph_real)0.2}, xi[3], dx[3];
    sph_off off[4] = {0, SPH_BATCH, SPH_BATCH, SPH_BATCH};
    sph_idx idx[SPH_BATCH];
    sph_neighbours L = SPH_NEIGHBOURS_INIT(3, 3, off, idx);
    sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}};
    const sph_view xv = sph_view_interleaved(x, 3);
    sph__period P;
    sph_batch_src S;
    sph_batch b;
    sph_off next = 0;
    int l, a, bad = 0;
    th_begin("batch image of far positions %s", TH_PRECISION);
    for (l = 0; l < SPH_BATCH; ++l) idx[l] = (sph_idx)(1 + (l / 3) % 2);
    TH_CHECK(sph_batch_source(&S, SPH_KERNEL_CUBIC, 3, &L, &box, xv, sph_view_soa(h, NULL, NULL)) == SPH_OK, "source");
    P = sph__period_of(&box, &L, 3);
    sph__h_xi(xv, 3, 0, xi);
    TH_CHECK(sph_batch_fill(&S, 0, &next, &b) == SPH_BATCH, "%d pairs", b.n);
    for (l = 0; l < SPH_BATCH; ++l) {
        sph__h_dx(&P, 3, xi, xv, idx[l], dx);
        for (a = 0; a < 3; ++a) bad += b.dx[a][l] != dx[a];
    }
    TH_CHECK(bad == 0, "%d components differ from sph__h_dx", bad);
    th_end();
}

static void pb_check_bad_input(void)
{
    sph_real x[6] = {0, 0, 0, (sph_real)0.1, 0, 0}, h[2] = {(sph_real)0.2, (sph_real)0.2};
    sph_off off[3] = {0, 2, 3};
    sph_idx idx[3] = {0, 1, 0};
    sph_neighbours L = SPH_NEIGHBOURS_INIT(2, 2, off, idx);
    const sph_view xv = sph_view_interleaved(x, 3), hv = sph_view_soa(h, NULL, NULL);
    sph_batch_src S;
    sph_batch b;
    sph_off next = 0;
    th_begin("pair batches: bad input %s", TH_PRECISION);
    TH_CHECK(sph_batch_source(NULL, SPH_KERNEL_CUBIC, 3, &L, NULL, xv, hv) == SPH_ENULL, "NULL source");
    TH_CHECK(sph_batch_source(&S, SPH_KERNEL_CUBIC, 3, NULL, NULL, xv, hv) == SPH_ENULL, "NULL list");
    TH_CHECK(sph_batch_source(&S, (sph_kernel)99, 3, &L, NULL, xv, hv) == SPH_EKERNEL, "unknown kernel");
    TH_CHECK(sph_batch_source(&S, SPH_KERNEL_CUBIC, 4, &L, NULL, xv, hv) == SPH_EDIM, "dim 4");
    TH_CHECK(sph_batch_source(&S, SPH_KERNEL_CUBIC, 3, &L, NULL, xv, sph_view_none()) == SPH_ENULL, "no h");
    idx[2] = 2;
    TH_CHECK(sph_batch_source(&S, SPH_KERNEL_CUBIC, 3, &L, NULL, xv, hv) == SPH_EINDEX, "index 2 of 2 particles");
    idx[2] = 0, h[1] = 0;
    TH_CHECK(sph_batch_source(&S, SPH_KERNEL_CUBIC, 3, &L, NULL, xv, hv) == SPH_EH, "h = 0");
    h[1] = (sph_real)0.2, x[4] = (sph_real)NAN;
    TH_CHECK(sph_batch_source(&S, SPH_KERNEL_CUBIC, 3, &L, NULL, xv, hv) == SPH_ENONFINITE, "NaN position");
    TH_CHECK(sph_batch_fill(&S, 0, &next, &b) == 0 && b.n == 0, "a failed source gives a batch");
    x[4] = 0;
    TH_CHECK(sph_batch_source(&S, SPH_KERNEL_CUBIC, 3, &L, NULL, xv, hv) == SPH_OK, "good input refused");
    TH_CHECK(sph_batch_fill(&S, 2, &next, &b) == 0 && sph_batch_fill(&S, -1, &next, &b) == 0, "target outside");
    next = -1;
    TH_CHECK(sph_batch_fill(&S, 0, &next, &b) == 0, "negative cursor");
    next = 0;
    TH_CHECK(sph_batch_fill(&S, 0, &next, &b) == 2 && next == 2 && b.j[1] == 1 && b.r[1] == (sph_real)0.1,
             "row 0: %d pairs", b.n);
    TH_CHECK(sph_batch_select(NULL, SPH_BATCH_F) == SPH_ENULL, "select: NULL source");
    TH_CHECK(sph_batch_select(&S, 4) == SPH_ERANGE && S.what == (SPH_BATCH_W | SPH_BATCH_F), "select: bit 4 accepted");
    th_end();
}

int main(void)
{
    int k, dim;
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim) pb_check_contents((sph_kernel)k, dim), pb_check_select((sph_kernel)k, dim);
    pb_check_sqrt();
    pb_check_far_image();
    pb_check_forces();
    pb_check_bad_input();
    return th_summary();
}
