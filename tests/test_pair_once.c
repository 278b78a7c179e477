/* Grad-h forces and pair-once loops (docs/smoothing_length.md (H5)-(H8)):
 * on a random closed periodic cloud with unequal masses and h from
 * sph_h_solve, the momentum equation (H5) sums to zero momentum change and
 * (H5) with (H6) to zero change of the total energy, to round-off (H7);
 * both equal a reference summed here over every pair with the scalar kernel;
 * the pair-once form equals the gather form to round-off and is bitwise the
 * same for 1 and 2 OpenMP threads; sph_pairs_build refuses a list that is
 * not symmetric and reports the pair count when the arrays are short;
 * sph_pairs_reduce_rows on rows summed by the caller equals sph_pairs_reduce
 * bit for bit, and sph_pairs_reduce_rows_k (the partners' shares at the
 * pair index) equals sph_pairs_reduce_rows bit for bit for any thread
 * count; a
 * buffer shorter than sph_gradh_pairs_buffer_len is refused; both forms give
 * the same bits through structure-of-arrays, interleaved and array-of-structs
 * views.
 */
#include "harness.h"
#include "support/particles.h"

#define N 600


typedef struct {
    sph_real x[3 * N], v[3 * N], m[N], h[N], rho[N], om[N], u[N], p[N], A[N];
    sph_box box;
    tp_list L; /* symmetric list at 1.25 h */
    sph_hctx c;
} pscene;

/* A random periodic cloud in the unit cube, h solved, u and v random; p = (gamma - 1) rho u. */
static int make_scene(pscene *s, int dim)
{
    tp_rng g = {2026};
    sph_real hl[N];
    sph_hreport rep;
    int i, a, st;
    memset(&s->box, 0, sizeof s->box);
    for (a = 0; a < dim; ++a) s->box.length[a] = 1, s->box.periodic[a] = 1;
    tp_uniform_cloud(dim, N, 1, &g, s->x);
    for (i = 0; i < N; ++i) {
        s->m[i] = (sph_real)(tp_range(&g, 0.5, 1.5) / N);
        s->u[i] = (sph_real)tp_range(&g, 1, 2);
        for (a = 0; a < 3; ++a) s->v[3 * i + a] = a < dim ? (sph_real)tp_range(&g, -1, 1) : 0;
        s->h[i] = (sph_real)(1.2 * pow(1.0 / N, 1.0 / dim));
        hl[i] = (sph_real)(dim == 3 ? 0.24 : 0.2);
    }
    if (tp_brute_list(dim, s->x, N, s->x, N, 0, hl, NULL, 2, TP_GATHER, &s->box, &s->L) != 0) return SPH_ESIZE;
    s->c = sph_hctx_init(SPH_KERNEL_CUBIC, dim, &s->L.list, sph_view_interleaved(s->x, 3),
                         sph_view_soa(s->m, NULL, NULL), 0);
    s->c.h_list = sph_view_soa(hl, NULL, NULL);
    s->c.box = &s->box;
    st = sph_h_solve(&s->c, th_out1(s->h), th_out1(s->rho), th_out1(s->om), NULL, NULL, &rep);
    if (st != SPH_OK || rep.n_beyond_list > 0 || rep.n_not_converged > 0) return st != SPH_OK ? st : SPH_EINVAL;
    tp_free_list(&s->L);
    for (i = 0; i < N; ++i) hl[i] = (sph_real)1.25 * s->h[i]; /* the force list: symmetric, at 1.25 h */
    if (tp_brute_list(dim, s->x, N, s->x, N, 0, hl, hl, 2, TP_SYMMETRIC, &s->box, &s->L) != 0) return SPH_ESIZE;
    s->c.list = &s->L.list;
    for (i = 0; i < N; ++i) {
        s->p[i] = (sph_real)(2.0 / 3.0) * s->rho[i] * s->u[i];
        s->A[i] = sph_gradh_factor(s->p[i], s->rho[i], s->om[i]);
    }
    return SPH_OK;
}

/* (H5), (H6) summed here over every pair (i, j != i) in double with sph_kernel_f. */
static void reference(const pscene *s, int dim, int i, double *acc, double *du)
{
    int j, a;
    for (a = 0; a < 3; ++a) acc[a] = 0;
    *du = 0;
    for (j = 0; j < N; ++j) {
        double dx[3] = {0, 0, 0}, r2 = 0, Fi, Fj, vdx = 0, A_i, A_j;
        if (j == i) continue;
        for (a = 0; a < dim; ++a) {
            dx[a] = (double)sph_box_delta(&s->box, a, s->x[3 * i + a] - s->x[3 * j + a]);
            r2 += dx[a] * dx[a];
            vdx += ((double)s->v[3 * i + a] - (double)s->v[3 * j + a]) * dx[a];
        }
        Fi = (double)sph_kernel_f(SPH_KERNEL_CUBIC, dim, (sph_real)sqrt(r2), s->h[i]);
        Fj = (double)sph_kernel_f(SPH_KERNEL_CUBIC, dim, (sph_real)sqrt(r2), s->h[j]);
        A_i = (double)s->p[i] / ((double)s->om[i] * (double)s->rho[i] * (double)s->rho[i]);
        A_j = (double)s->p[j] / ((double)s->om[j] * (double)s->rho[j] * (double)s->rho[j]);
        for (a = 0; a < dim; ++a) acc[a] -= (double)s->m[j] * (A_i * Fi + A_j * Fj) * dx[a];
        *du += (double)s->m[j] * A_i * Fi * vdx;
    }
}

static int pairs_of(const pscene *s, sph_off **mem, sph_pairs *P)
{
    const sph_off cap = s->L.list.offset[N];
    sph_off pairs = 0;
    *mem = malloc(sizeof(sph_off) * (size_t)(2 * (N + 1) + cap) + sizeof(sph_idx) * (size_t)cap);
    if (*mem == NULL) return SPH_ESIZE;
    return sph_pairs_build(&s->L.list, *mem, (sph_idx *)(void *)(*mem + 2 * (N + 1) + cap), cap, *mem + N + 1,
                           *mem + 2 * (N + 1), &pairs, P);
}

#define BUF_LEN (8 * 4 * N * 60)

static void conservation_case(int dim)
{
    static pscene s;
    static sph_real dv[3 * N], du[N], dv2[3 * N], du2[N], dv3[3 * N], du3[N], buf[BUF_LEN];
    double P[3] = {0, 0, 0}, Pabs = 0, E = 0, Eabs = 0, err_ref = 0, err_pairs = 0, scale = 0, dscale = 0, e;
    sph_off *mem = NULL;
    sph_pairs pr;
    int i, a, st, same;
    th_begin("grad-h forces %dD: momentum and energy conserved, reference, pair-once, threads", dim);
    st = make_scene(&s, dim);
    TH_CHECK(st == SPH_OK, "pscene: %s", sph_strerror(st));
    if (st != SPH_OK) {
        th_end();
        return;
    }
    st = sph_gradh_forces(&s.c, sph_view_interleaved(s.v, 3), th_in1(s.h), th_in1(s.A), sph_out_interleaved(dv, dim),
                          th_out1(du));
    TH_CHECK(st == SPH_OK, "gather: %s", sph_strerror(st));
    for (i = 0; i < N; ++i) {
        double ref[3], dref;
        reference(&s, dim, i, ref, &dref);
        for (a = 0; a < dim; ++a) {
            P[a] += (double)s.m[i] * (double)dv[dim * i + a];
            Pabs += fabs((double)s.m[i] * (double)dv[dim * i + a]);
            E += (double)s.m[i] * (double)s.v[3 * i + a] * (double)dv[dim * i + a];
            Eabs += fabs((double)s.m[i] * (double)s.v[3 * i + a] * (double)dv[dim * i + a]);
            e = fabs((double)dv[dim * i + a] - ref[a]);
            err_ref = e > err_ref ? e : err_ref;
            scale = fabs(ref[a]) > scale ? fabs(ref[a]) : scale;
        }
        E += (double)s.m[i] * (double)du[i];
        Eabs += fabs((double)s.m[i] * (double)du[i]);
        e = fabs((double)du[i] - dref);
        err_ref = e / 1 > err_ref ? e : err_ref;
        dscale = fabs(dref) > dscale ? fabs(dref) : dscale;
    }
    for (a = 0; a < dim; ++a) TH_CHECK(fabs(P[a]) <= 50 * TH_EPS * Pabs, "momentum change %.3g of %.3g", P[a], Pabs);
    TH_CHECK(fabs(E) <= 50 * TH_EPS * Eabs, "energy change %.3g of %.3g", E, Eabs);
    TH_CHECK(err_ref <= 1e3 * TH_EPS * (scale > dscale ? scale : dscale), "against the reference: %.3g (scale %.3g)",
             err_ref, scale);
    /* pair-once */
    st = pairs_of(&s, &mem, &pr);
    TH_CHECK(st == SPH_OK, "pairs: %s", sph_strerror(st));
    TH_CHECK(2 * pr.half.offset[N] + N == s.L.list.offset[N], "half list %ld pairs, full %ld", (long)pr.half.offset[N],
             (long)s.L.list.offset[N]);
    TH_CHECK((size_t)(2 * (dim + 1)) * (size_t)pr.half.offset[N] <= sizeof buf / sizeof buf[0], "buffer");
    TH_CHECK(sph_gradh_pairs_buffer_len(dim, pr.half.offset[N]) == 2 * (dim + 1) * pr.half.offset[N], "buffer length");
    th_set_threads(1);
    st = sph_gradh_forces_pairs(&s.c, &pr, sph_view_interleaved(s.v, 3), th_in1(s.h), th_in1(s.A), buf, BUF_LEN,
                                sph_out_interleaved(dv2, dim), th_out1(du2));
    TH_CHECK(st == SPH_OK, "pair-once: %s", sph_strerror(st));
    for (i = 0; i < dim * N; ++i) {
        e = fabs((double)dv2[i] - (double)dv[i]);
        err_pairs = e > err_pairs ? e : err_pairs;
    }
    for (i = 0; i < N; ++i) {
        e = fabs((double)du2[i] - (double)du[i]);
        err_pairs = e > err_pairs ? e : err_pairs;
    }
    TH_CHECK(err_pairs <= 100 * TH_EPS * (scale > dscale ? scale : dscale), "pair-once against gather: %.3g", err_pairs);
    th_set_threads(2);
    st = sph_gradh_forces_pairs(&s.c, &pr, sph_view_interleaved(s.v, 3), th_in1(s.h), th_in1(s.A), buf, BUF_LEN,
                                sph_out_interleaved(dv3, dim), th_out1(du3));
    same = memcmp(dv2, dv3, sizeof(sph_real) * (size_t)(dim * N)) == 0 && memcmp(du2, du3, sizeof du2) == 0;
    TH_CHECK(st == SPH_OK && same, "pair-once with 1 and 2 threads differ");
    st = sph_gradh_forces(&s.c, sph_view_interleaved(s.v, 3), th_in1(s.h), th_in1(s.A), sph_out_interleaved(dv3, dim),
                          th_out1(du3));
    same = memcmp(dv, dv3, sizeof(sph_real) * (size_t)(dim * N)) == 0 && memcmp(du, du3, sizeof du) == 0;
    TH_CHECK(st == SPH_OK && same, "gather with 1 and 2 threads differ");
    th_set_threads(1);
    printf("    %dD: momentum %.1e, energy %.1e of the sums of magnitudes; reference %.1e, pair-once %.1e of %.2e\n", dim,
           fabs(P[0]) / Pabs, fabs(E) / Eabs, err_ref, err_pairs, scale);
    free(mem);
    tp_free_list(&s.L);
    th_end();
}

/* What a solver keeps per particle, side by side. */
typedef struct {
    sph_real h, A, dv[3], du;
} po_particle;

/* Both forms through other layouts: v as three arrays, h, A, dv/dt, du/dt in
 * an array of structs; the same bits as interleaved arrays. A buffer one
 * real short and a missing component of dv/dt are refused, nothing written. */
static void po_layout_case(void)
{
    static pscene s;
    static sph_real vx[N], vy[N], vz[N], dv[3 * N], du[N], buf[BUF_LEN];
    static po_particle P[N];
    const size_t S = sizeof(po_particle);
    const sph_view h_aos = sph_view_aos(&P[0].h, 1, S), A_aos = sph_view_aos(&P[0].A, 1, S);
    const sph_out dv_aos = sph_out_aos(P[0].dv, 3, S), du_aos = sph_out_aos(&P[0].du, 1, S);
    sph_off *mem = NULL, need;
    sph_pairs pr;
    int i, a, st, st2, same = 1, untouched = 1;
    th_begin("grad-h forces 3D: SoA, interleaved and array-of-structs views give the same bits; short buffer refused");
    st = make_scene(&s, 3);
    TH_CHECK(st == SPH_OK, "pscene: %s", sph_strerror(st));
    if (st != SPH_OK || (st = pairs_of(&s, &mem, &pr)) != SPH_OK) {
        free(mem);
        th_end();
        return;
    }
    for (i = 0; i < N; ++i) {
        vx[i] = s.v[3 * i], vy[i] = s.v[3 * i + 1], vz[i] = s.v[3 * i + 2];
        P[i].h = s.h[i], P[i].A = s.A[i];
    }
    st = sph_gradh_forces(&s.c, sph_view_interleaved(s.v, 3), th_in1(s.h), th_in1(s.A), sph_out_interleaved(dv, 3), th_out1(du));
    st2 = sph_gradh_forces(&s.c, sph_view_soa(vx, vy, vz), h_aos, A_aos, dv_aos, du_aos);
    for (i = 0; i < N; ++i)
        for (a = 0; a < 3; ++a) same &= P[i].dv[a] == dv[3 * i + a] && P[i].du == du[i];
    TH_CHECK(st == SPH_OK && st2 == SPH_OK && same, "gather: %d %d, layouts differ", st, st2);
    st = sph_gradh_forces_pairs(&s.c, &pr, sph_view_interleaved(s.v, 3), th_in1(s.h), th_in1(s.A), buf, BUF_LEN,
                                sph_out_interleaved(dv, 3), th_out1(du));
    st2 = sph_gradh_forces_pairs(&s.c, &pr, sph_view_soa(vx, vy, vz), h_aos, A_aos, buf, BUF_LEN, dv_aos, du_aos);
    for (i = 0, same = 1; i < N; ++i)
        for (a = 0; a < 3; ++a) same &= P[i].dv[a] == dv[3 * i + a] && P[i].du == du[i];
    TH_CHECK(st == SPH_OK && st2 == SPH_OK && same, "pair-once: %d %d, layouts differ", st, st2);
    need = sph_gradh_pairs_buffer_len(3, pr.half.offset[N]);
    for (i = 0; i < N; ++i) du[i] = -7;
    st = sph_gradh_forces_pairs(&s.c, &pr, sph_view_soa(vx, vy, vz), h_aos, A_aos, buf, need - 1,
                                sph_out_interleaved(dv, 3), th_out1(du));
    st2 = sph_gradh_forces(&s.c, sph_view_soa(vx, vy, vz), h_aos, A_aos, sph_out_soa(dv, dv + N, NULL), th_out1(du));
    for (i = 0; i < N; ++i) untouched &= du[i] == -7;
    TH_CHECK(st == SPH_ESIZE && st2 == SPH_ENULL && untouched, "buffer one short: %d, dv/dt without z: %d", st, st2);
    TH_CHECK(sph_gradh_pairs_buffer_len(0, 10) == 0 && sph_pairs_buffer_len(17, 10) == 0 &&
                 sph_pairs_buffer_len(5, -1) == 0 && sph_pairs_buffer_len(5, 10) == 100,
             "buffer lengths of bad arguments");
    free(mem);
    tp_free_list(&s.L);
    th_end();
}

/* A list with pair (0, 1) in row 0 only: not symmetric. */
static void build_errors_case(void)
{
    const sph_off off[4] = {0, 3, 5, 7};
    const sph_idx idx[7] = {0, 1, 2, 1, 2, 1, 2}; /* row 2 lacks 0: (0, 2) in row 0 only */
    const sph_idx sym[9] = {0, 1, 2, 0, 1, 2, 0, 1, 2};
    const sph_off soff[4] = {0, 3, 6, 9};
    sph_neighbours full = SPH_NEIGHBOURS_INIT(3, 3, off, idx);
    sph_off offset[4], t_offset[4], t_slot[9], pairs = -1;
    sph_idx index[9];
    sph_pairs P;
    sph_real to_i[3] = {1, 2, 4}, to_j[3] = {8, 16, 32}, out[3] = {0, 0, 0};
    int st;
    th_begin("pairs: non-symmetric list refused, short arrays report the count, reduce order");
    st = sph_pairs_build(&full, offset, index, 9, t_offset, t_slot, &pairs, &P);
    TH_CHECK(st == SPH_ENOTSYMMETRIC, "non-symmetric: %d", st);
    full.index = sym;
    full.offset = soff;
    full.n_sources = 4;
    TH_CHECK((st = sph_pairs_build(&full, offset, index, 9, t_offset, t_slot, &pairs, &P)) == SPH_ECOUNT,
             "n_sources 4 of 3 targets: %d", st);
    full.n_sources = 3;
    TH_CHECK((st = sph_pairs_build(&full, offset, index, -1, t_offset, t_slot, &pairs, &P)) == SPH_ECOUNT,
             "cap -1: %d", st);
    {
        const sph_idx unsorted[9] = {0, 1, 2, 1, 0, 2, 0, 1, 2}; /* row 1 not ascending */
        const sph_off dec[4] = {0, 3, 2, 9};
        full.index = unsorted;
        TH_CHECK((st = sph_pairs_build(&full, offset, index, 9, t_offset, t_slot, &pairs, &P)) == SPH_ENOTSYMMETRIC,
                 "row not ascending: %d", st);
        full.index = sym;
        full.offset = dec;
        TH_CHECK((st = sph_pairs_build(&full, offset, index, 9, t_offset, t_slot, &pairs, &P)) == SPH_EOFFSET,
                 "decreasing offsets: %d", st);
    }
    full.offset = soff;
    full.index = sym;
    st = sph_pairs_build(&full, offset, index, 2, t_offset, t_slot, &pairs, &P);
    TH_CHECK(st == SPH_ESIZE && pairs == 3, "cap 2: %d, pairs %ld", st, (long)pairs);
    st = sph_pairs_build(&full, offset, index, 3, t_offset, t_slot, &pairs, &P);
    TH_CHECK(st == SPH_OK && pairs == 3, "cap 3: %d", st);
    /* pairs k: 0 = (0,1), 1 = (0,2), 2 = (1,2) */
    TH_CHECK(index[0] == 1 && index[1] == 2 && index[2] == 2, "half list %d %d %d", index[0], index[1], index[2]);
    st = sph_pairs_reduce(&P, 1, to_i, to_j, out);
    TH_CHECK(st == SPH_OK && out[0] == 1 + 2 && out[1] == 4 + 8 && out[2] == 16 + 32, "reduce %g %g %g", (double)out[0],
             (double)out[1], (double)out[2]);
    TH_CHECK(sph_pairs_reduce(&P, 0, to_i, to_j, out) == SPH_ERANGE, "ncomp 0");
    out[0] = 1 + 2, out[1] = 4, out[2] = 0; /* the rows' own sums; then the slots: 0 none, 1 [0], 2 [1, 2] */
    st = sph_pairs_reduce_rows(&P, 1, to_j, out);
    TH_CHECK(st == SPH_OK && out[0] == 1 + 2 && out[1] == 4 + 8 && out[2] == 16 + 32, "reduce_rows %g %g %g",
             (double)out[0], (double)out[1], (double)out[2]);
    TH_CHECK(sph_pairs_reduce_rows(&P, 17, to_j, out) == SPH_ERANGE && sph_pairs_reduce_rows(&P, 1, NULL, out) == SPH_ENULL &&
                 sph_pairs_reduce_rows(NULL, 1, to_j, out) == SPH_ENULL,
             "reduce_rows: ncomp 17, NULL to_j or pairs accepted");
    { /* 4 particles, every pair: k = (0,1) (0,2) (0,3) (1,2) (1,3) (2,3); slots of 1: [0], of 2: [1, 2] for
         i = 0, 1, of 3: [3, 4, 5] for i = 0, 1, 2 */
        const sph_off o4[5] = {0, 4, 8, 12, 16};
        const sph_idx i4[16] = {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3};
        const sph_off expect[6] = {0, 1, 3, 2, 4, 5};
        sph_neighbours f4 = SPH_NEIGHBOURS_INIT(4, 4, o4, i4);
        sph_off ho[5], to[5], ts[16];
        sph_idx hi[16];
        int k, ok = 1;
        st = sph_pairs_build(&f4, ho, hi, 16, to, ts, &pairs, &P);
        for (k = 0; k < 6; ++k) ok &= ts[k] == expect[k];
        TH_CHECK(st == SPH_OK && pairs == 6 && ok && to[4] == 6, "4 particles: slots %ld %ld %ld %ld %ld %ld",
                 (long)ts[0], (long)ts[1], (long)ts[2], (long)ts[3], (long)ts[4], (long)ts[5]);
        { /* the rows summed by hand in row order, then sph_pairs_reduce_rows: sph_pairs_reduce bit for bit
             (values of mixed magnitude, so that another order would round differently) */
            sph_real ti[18], tj[18], o1[12], o2[12];
            tp_rng g = {99};
            int a, i, bad = 0;
            for (k = 0; k < 18; ++k)
                ti[k] = (sph_real)(tp_range(&g, -1, 1) * pow(10.0, (double)(k % 5) * 4 - 8)),
                tj[k] = (sph_real)(tp_range(&g, -1, 1) * pow(10.0, (double)(k % 3) * 5 - 5));
            tj[9] = 1, tj[12] = tj[15] = (sph_real)(0.4 * TH_EPS); /* particle 3's slots 3, 4, 5: 1 first absorbs both */
            for (i = 0; i < 4; ++i)
                for (a = 0; a < 3; ++a) {
                    o2[3 * i + a] = 0;
                    for (k = (int)ho[i]; k < (int)ho[i + 1]; ++k) o2[3 * i + a] += ti[3 * k + a];
                }
            st = sph_pairs_reduce(&P, 3, ti, tj, o1);
            st |= sph_pairs_reduce_rows(&P, 3, tj, o2);
            for (k = 0; k < 12; ++k) bad += o1[k] != o2[k];
            TH_CHECK(st == SPH_OK && bad == 0, "reduce_rows: %d of 12 sums differ from sph_pairs_reduce", bad);
        }
    }
    TH_CHECK(sph_pairs_build(NULL, offset, index, 3, t_offset, t_slot, &pairs, &P) == SPH_ENULL, "NULL list");
    th_end();
}

static void factor_case(void)
{
    th_begin("sph_gradh_factor: p / (Omega rho^2), Omega <= 0 or NaN counts as 1, rho <= 0 gives 0");
    TH_NEAR(sph_gradh_factor(2, 2, (sph_real)0.5), 1, 4 * TH_EPS);
    TH_NEAR(sph_gradh_factor(2, 2, -1), (sph_real)0.5, 4 * TH_EPS);
    TH_NEAR(sph_gradh_factor(2, 2, (sph_real)NAN), (sph_real)0.5, 4 * TH_EPS);
    TH_CHECK(sph_gradh_factor(2, 0, 1) == 0 && sph_gradh_factor((sph_real)NAN, 1, 1) == 0, "fallback 0");
    th_end();
}

/* sph_pairs_reduce_rows_k: j's share stored at the pair index k, not at its
 * slot: on the 3-D pscene's 600-particle list, with values of mixed magnitude
 * (another order of a sum would round differently), 3 and 5 components (5:
 * its unrolled adds), bit for bit sph_pairs_reduce_rows on the same shares
 * at the slots, with 1 and 2 threads, and the partner ranges of its threads
 * (sph__pairs_add_k over 1, 2, 7 and 600 ranges of j: the threads split
 * only from 2048 particles on) add the same bits; bad input refused. */
static void reduce_k_case(void)
{
    static pscene s;
    static sph_real o1[5 * N], o2[5 * N], o3[5 * N], rows[5 * N];
    sph_off *mem = NULL, k, pairs;
    sph_pairs pr;
    sph_real *tj = NULL, *tk = NULL;
    tp_rng g = {5};
    int i, st, nc;
    th_begin("sph_pairs_reduce_rows_k: partners' shares at k equal sph_pairs_reduce_rows bit for bit, any ranges");
    st = make_scene(&s, 3);
    if (st == SPH_OK) st = pairs_of(&s, &mem, &pr);
    TH_CHECK(st == SPH_OK, "pscene and pairs: %s", sph_strerror(st));
    if (st != SPH_OK) {
        free(mem);
        th_end();
        return;
    }
    pairs = pr.half.offset[N];
    tj = malloc(sizeof(sph_real) * 5 * (size_t)pairs), tk = malloc(sizeof(sph_real) * 5 * (size_t)pairs);
    TH_CHECK(tj != NULL && tk != NULL && pairs > 10 * N, "buffers, %ld pairs", (long)pairs);
    for (nc = 3; nc <= 5 && tj != NULL && tk != NULL; nc += 2) {
        int parts, bad = 0;
        for (i = 0; i < nc * N; ++i) rows[i] = (sph_real)(tp_range(&g, -1, 1) * pow(10.0, (double)(i % 4) * 3 - 6));
        for (k = 0; k < nc * pairs; ++k) tk[k] = (sph_real)(tp_range(&g, -1, 1) * pow(10.0, (double)(k % 7) * 2 - 7));
        for (k = 0; k < pairs; ++k)
            for (i = 0; i < nc; ++i) tj[nc * pr.t_slot[k] + i] = tk[nc * k + i];
        memcpy(o1, rows, sizeof o1), memcpy(o2, rows, sizeof o2);
        th_set_threads(1);
        st = sph_pairs_reduce_rows(&pr, nc, tj, o1);
        st |= sph_pairs_reduce_rows_k(&pr, nc, tk, o2);
        for (i = 0; i < nc * N; ++i) bad += o1[i] != o2[i];
        TH_CHECK(st == SPH_OK && bad == 0, "%d components, 1 thread: %d of %d sums differ from sph_pairs_reduce_rows", nc,
                 bad, nc * N);
        memcpy(o3, rows, sizeof o3);
        th_set_threads(2);
        st = sph_pairs_reduce_rows_k(&pr, nc, tk, o3);
        th_set_threads(1);
        TH_CHECK(st == SPH_OK && memcmp(o2, o3, sizeof o2) == 0, "%d components: 1 and 2 threads differ", nc);
        for (parts = 1; parts <= N; parts = parts == 1 ? 2 : parts == 2 ? 7 : parts == 7 ? N : N + 1) {
            int q;
            memcpy(o3, rows, sizeof o3);
            for (q = 0; q < parts; ++q)
                sph__pairs_add_k(&pr, nc, tk, o3, (sph_idx)(N * q / parts), (sph_idx)(N * (q + 1) / parts));
            TH_CHECK(memcmp(o2, o3, sizeof o2) == 0, "%d components: %d ranges of j differ from one", nc, parts);
        }
    }
    TH_CHECK(sph_pairs_reduce_rows_k(&pr, 17, tk, o3) == SPH_ERANGE && sph_pairs_reduce_rows_k(&pr, 0, tk, o3) == SPH_ERANGE &&
                 sph_pairs_reduce_rows_k(&pr, 3, NULL, o3) == SPH_ENULL &&
                 sph_pairs_reduce_rows_k(&pr, 3, tk, NULL) == SPH_ENULL && sph_pairs_reduce_rows_k(NULL, 3, tk, o3) == SPH_ENULL,
             "ncomp 0 or 17, NULL to_j, out or pairs accepted");
    free(tj), free(tk), free(mem);
    tp_free_list(&s.L);
    th_end();
}

int main(void)
{
    conservation_case(3);
    conservation_case(2);
    po_layout_case();
    build_errors_case();
    reduce_k_case();
    factor_case();
    return th_summary();
}
