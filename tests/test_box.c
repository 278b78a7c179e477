/* tests/test_box.c - a neighbour list carries the box it was searched in.
 *
 * On a periodic cubic lattice (8^3 particles, spacing dx, the unit box) the
 * operators and section 9 take the periodic axes from the list when the
 * context's box is left NULL: the density of the corner particle (at the
 * origin, whose neighbours lie across three faces) is the lattice sum
 * m sum_k W(|k| dx, h) over the integer offsets k, summed here without any
 * box, and every particle's equals it; sph_h_solve gives every particle the
 * same h as with the box set, and the grad-h forces (gather and pair-once)
 * are bitwise those with the box set. A box that differs from the list's
 * (another period, an axis not periodic, or a periodic box over an open
 * search) is SPH_EBOX for the operators, sph_h_solve, sph_gradh_forces and
 * sph_gradh_forces_pairs; a list whose box is unknown (assembled by the
 * caller) keeps the context's box as before. sph_pairs_build's half list
 * inherits the full list's box, and a gather list with per-particle h is
 * SPH_ENOTSYMMETRIC there.
 */
#include <stdlib.h>

#include "harness.h"

#define NS 8 /* particles per side */
#define N (NS * NS * NS)

typedef struct {
    sph_real x[3 * N], m[N], h[N], rho[N], om[N], A[N], dvdt[3 * N], dudt[N];
    sph_box box;
    sph_nsearch g;
    void *work;
    sph_off off[N + 1];
    sph_idx *idx;
    sph_neighbours list;
} lattice;

static const double bx_dx = 1.0 / NS, bx_rho0 = 1000;

/* The lattice in [0, 1)^3, periodic on every axis, and its gather list of
 * radius kappa hl (uniform; per particle from hv when hv is given),
 * searched in search_box. */
static int lattice_make(lattice *s, const sph_box *search_box, sph_real hl, sph_view hv)
{
    const sph_view xv = sph_view_interleaved(s->x, 3);
    const sph_real cell = (sph_real)0.125; /* any cell gives the same lists */
    size_t bytes;
    int i, a, st;
    for (i = 0; i < N; ++i) {
        s->x[3 * i] = (sph_real)(bx_dx * (i % NS));
        s->x[3 * i + 1] = (sph_real)(bx_dx * (i / NS % NS));
        s->x[3 * i + 2] = (sph_real)(bx_dx * (i / (NS * NS)));
        s->m[i] = (sph_real)(bx_rho0 * bx_dx * bx_dx * bx_dx);
    }
    for (a = 0; a < 3; ++a) s->box.lo[a] = 0, s->box.length[a] = 1, s->box.periodic[a] = 1;
    if ((st = sph_nsearch_workspace_size(3, xv, N, hv, cell, search_box, &bytes)) != SPH_OK) return st;
    s->work = malloc(bytes);
    s->idx = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)N * N);
    if (s->work == NULL || s->idx == NULL) return SPH_ENULL;
    if ((st = sph_nsearch_build(&s->g, 3, xv, N, hv, cell, search_box, s->work, bytes)) != SPH_OK) return st;
    st = sph_nsearch_count(&s->g, xv, N, hv, hl, 2, SPH_NSEARCH_GATHER, s->off);
    if (st == SPH_OK) st = sph_nsearch_fill(&s->g, xv, N, hv, hl, 2, SPH_NSEARCH_GATHER, s->off, s->idx, N * N);
    s->list = sph_nsearch_list(&s->g, N, s->off, s->idx);
    return st;
}

static void lattice_free(lattice *s)
{
    free(s->work);
    free(s->idx);
}

/* m sum over integer offsets k of W(|k| dx, h): the density of every particle
 * of the infinite lattice, computed without a box or a list. */
static double lattice_density(sph_real h)
{
    const int K = (int)ceil(2 * (double)h / bx_dx);
    double s = 0;
    int i, j, k;
    for (i = -K; i <= K; ++i)
        for (j = -K; j <= K; ++j)
            for (k = -K; k <= K; ++k)
                s += (double)sph_kernel_w(SPH_KERNEL_CUBIC, 3, (sph_real)(bx_dx * sqrt((double)(i * i + j * j + k * k))), h);
    return bx_rho0 * bx_dx * bx_dx * bx_dx * s;
}

static void operators_case(void)
{
    const sph_real h = (sph_real)(1.3 * bx_dx);
    lattice s;
    sph_box other;
    sph_neighbours own;
    sph_ctx c;
    sph_real rho_set[N], grad[3 * N];
    const double ref = lattice_density(h);
    double worst = 0;
    int i, st;
    th_begin("operators: ctx.box NULL takes the list's periodic box; a different box is SPH_EBOX");
    st = lattice_make(&s, &s.box, h, sph_view_none());
    TH_CHECK(st == SPH_OK && s.list.box_known == SPH_BOX_KNOWN, "search %d, box_known %d", st, s.list.box_known);
    c = sph_ctx_init(SPH_KERNEL_CUBIC, 3, h, &s.list, sph_view_interleaved(s.x, 3));
    c.m = c.V = sph_view_soa(s.m, NULL, NULL); /* volumes unused by the density; present for the gradient */
    st = sph_density(&c, sph_out_soa(s.rho, NULL, NULL)); /* c.box forgotten */
    TH_CHECK(st == SPH_OK, "density without ctx.box: %d", st);
    TH_REL(s.rho[0], ref, 64 * TH_EPS); /* the corner particle */
    for (i = 0; i < N; ++i) worst = fabs((double)s.rho[i] - ref) > worst ? fabs((double)s.rho[i] - ref) : worst;
    TH_CHECK(worst <= 64 * TH_EPS * ref, "largest |rho - lattice sum| %g of %g", worst, ref);
    c.box = &s.box;
    st = sph_density(&c, sph_out_soa(rho_set, NULL, NULL));
    for (i = 0; i < N && rho_set[i] == s.rho[i]; ++i) continue;
    TH_CHECK(st == SPH_OK && i == N, "the search's box given: %d, particle %d differs", st, i);
    other = s.box, other.length[1] = (sph_real)1.5; /* R = 0.325 fits either period */
    c.box = &other;
    for (i = 0; i < N; ++i) rho_set[i] = -7;
    TH_CHECK((st = sph_density(&c, sph_out_soa(rho_set, NULL, NULL))) == SPH_EBOX, "period 1.5 on y: %d", st);
    TH_CHECK(rho_set[0] == -7, "refused call wrote rho");
    TH_CHECK((st = sph_gradient(&c, SPH_SCHEME_DIFFERENCE, sph_view_soa(s.m, NULL, NULL), sph_view_none(),
                                sph_out_interleaved(grad, 3), NULL)) == SPH_EBOX,
             "gradient, period 1.5: %d", st);
    other = s.box, other.periodic[2] = 0;
    TH_CHECK((st = sph_density(&c, sph_out_soa(rho_set, NULL, NULL))) == SPH_EBOX, "z not periodic: %d", st);
    other = s.box, other.lo[0] = (sph_real)-0.5; /* lo plays no part in the minimum image */
    TH_CHECK((st = sph_density(&c, sph_out_soa(rho_set, NULL, NULL))) == SPH_OK, "another lo: %d", st);
    other.length[0] = 0;
    TH_CHECK((st = sph_density(&c, sph_out_soa(rho_set, NULL, NULL))) == SPH_EBOXLEN, "period 0: %d", st);
    /* a list of the same arrays whose box is unknown: the context's box alone, as before */
    own = (sph_neighbours)SPH_NEIGHBOURS_INIT(N, N, s.off, s.idx);
    c.list = &own;
    c.box = &s.box;
    st = sph_density(&c, sph_out_soa(rho_set, NULL, NULL));
    TH_CHECK(st == SPH_OK && rho_set[0] == s.rho[0], "box unknown, ctx.box set: %d, %g", st, (double)rho_set[0]);
    c.box = NULL;
    st = sph_density(&c, sph_out_soa(rho_set, NULL, NULL));
    TH_CHECK(st == SPH_OK && rho_set[0] < (sph_real)(0.6 * ref), "box unknown, no ctx.box: open faces, rho %g",
             (double)rho_set[0]);
    lattice_free(&s);
    /* an open search: known, no periodic axis; a periodic ctx.box over it is refused */
    st = lattice_make(&s, NULL, h, sph_view_none());
    c = sph_ctx_init(SPH_KERNEL_CUBIC, 3, h, &s.list, sph_view_interleaved(s.x, 3));
    c.m = sph_view_soa(s.m, NULL, NULL);
    c.box = &s.box;
    TH_CHECK(st == SPH_OK && s.list.box_known == SPH_BOX_KNOWN, "open search %d", st);
    TH_CHECK((st = sph_density(&c, sph_out_soa(rho_set, NULL, NULL))) == SPH_EBOX, "periodic ctx.box, open list: %d",
             st);
    lattice_free(&s);
    th_end();
}


/* sph_h_solve, then A_i = p_i / (Omega_i rho_i^2) with p = rho (any positive p will do). */
static int solve(const sph_hctx *c, lattice *s)
{
    sph_hreport rep;
    int i, st;
    for (i = 0; i < N; ++i) s->h[i] = (sph_real)(1.2 * bx_dx);
    st = sph_h_solve(c, th_out1(s->h), th_out1(s->rho), th_out1(s->om), NULL, NULL, &rep);
    if (st == SPH_OK && rep.n_not_converged + rep.n_beyond_list > 0) return SPH_EH;
    for (i = 0; i < N; ++i) s->A[i] = sph_gradh_factor(s->rho[i], s->rho[i], s->om[i]);
    return st;
}

static void hctx_case(void)
{
    const sph_real hl = (sph_real)0.2; /* kappa hl = 0.4 < 1/2 */
    lattice s;
    sph_hctx c;
    sph_box other;
    sph_pairs P;
    sph_off hoff[N + 1], toff[N + 1], *tslot, pairs, blen;
    sph_idx *hidx;
    sph_real h_set[N], dv_set[3 * N], *buf, dv[3 * N];
    sph_view v;
    int i, st;
    th_begin("sph_hctx and the pair-once list: box NULL takes the list's; a different box is SPH_EBOX");
    st = lattice_make(&s, &s.box, hl, sph_view_none());
    TH_CHECK(st == SPH_OK, "search %d", st);
    v = sph_view_interleaved(s.x, 3); /* any velocity field */
    c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &s.list, sph_view_interleaved(s.x, 3), sph_view_soa(s.m, NULL, NULL), hl);
    c.box = &s.box;
    TH_CHECK((st = solve(&c, &s)) == SPH_OK, "h solve with the box: %d", st);
    for (i = 0; i < N; ++i) h_set[i] = s.h[i];
    TH_CHECK((st = sph_gradh_forces(&c, v, th_in1(s.h), th_in1(s.A), th_out3(dv_set), th_out1(s.dudt))) == SPH_OK,
             "forces with the box: %d", st);
    c.box = NULL; /* forgotten */
    TH_CHECK((st = solve(&c, &s)) == SPH_OK, "h solve without hctx.box: %d", st);
    for (i = 0; i < N && s.h[i] == h_set[i] && fabs((double)(s.h[i] - h_set[0])) <= 4 * c.tol * h_set[0]; ++i)
        continue; /* every particle's h within the solver's tolerance of the corner's, and that as with the box */
    TH_CHECK(i == N, "particle %d: h %.17g, with the box %.17g, corner %.17g", i, (double)s.h[i < N ? i : 0],
             (double)h_set[i < N ? i : 0], (double)h_set[0]);
    TH_CHECK((st = sph_gradh_forces(&c, v, th_in1(s.h), th_in1(s.A), th_out3(s.dvdt), th_out1(s.dudt))) == SPH_OK,
             "forces without hctx.box: %d", st);
    for (i = 0; i < 3 * N && s.dvdt[i] == dv_set[i]; ++i) continue;
    TH_CHECK(i == 3 * N, "gather forces differ at %d", i);
    other = s.box, other.length[0] = 2;
    c.box = &other;
    TH_CHECK((st = sph_h_solve(&c, th_out1(s.h), th_out1(s.rho), th_out1(s.om), NULL, NULL, NULL)) == SPH_EBOX,
             "h solve, period 2: %d", st);
    TH_CHECK((st = sph_gradh_forces(&c, v, th_in1(s.h), th_in1(s.A), th_out3(s.dvdt), th_out1(s.dudt))) == SPH_EBOX,
             "forces, period 2: %d", st);
    /* pair-once: the half list inherits the box */
    hidx = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)s.off[N]);
    tslot = (sph_off *)malloc(sizeof(sph_off) * (size_t)s.off[N]);
    blen = sph_gradh_pairs_buffer_len(3, s.off[N]); /* more than the half list needs */
    buf = (sph_real *)malloc(sizeof(sph_real) * (size_t)blen);
    TH_CHECK(hidx != NULL && tslot != NULL && buf != NULL, "memory");
    if (hidx != NULL && tslot != NULL && buf != NULL) {
        st = sph_pairs_build(&s.list, hoff, hidx, s.off[N], toff, tslot, &pairs, &P);
        TH_CHECK(st == SPH_OK && P.half.box_known == SPH_BOX_KNOWN && P.half.box.periodic[2] &&
                     P.half.box.length[2] == 1,
                 "half list: %d, box_known %d", st, P.half.box_known);
        c.box = NULL;
        TH_CHECK((st = sph_gradh_forces_pairs(&c, &P, v, th_in1(s.h), th_in1(s.A), buf, blen, th_out3(s.dvdt), th_out1(s.dudt))) ==
                     SPH_OK,
                 "pair-once without hctx.box: %d", st);
        c.box = &s.box;
        TH_CHECK((st = sph_gradh_forces_pairs(&c, &P, v, th_in1(s.h), th_in1(s.A), buf, blen, th_out3(dv), th_out1(s.dudt))) ==
                     SPH_OK,
                 "pair-once with the box: %d", st);
        for (i = 0; i < 3 * N && s.dvdt[i] == dv[i]; ++i) continue;
        TH_CHECK(i == 3 * N, "pair-once forces differ at %d", i);
        c.box = &other;
        TH_CHECK((st = sph_gradh_forces_pairs(&c, &P, v, th_in1(s.h), th_in1(s.A), buf, blen, th_out3(dv), th_out1(s.dudt))) ==
                     SPH_EBOX,
                 "pair-once, period 2: %d", st);
    }
    free(hidx), free(tslot), free(buf);
    lattice_free(&s);
    th_end();
}

static void gather_pairs_case(void)
{
    lattice s;
    sph_real hv[N];
    sph_pairs P;
    sph_off hoff[N + 1], toff[N + 1], *tslot, pairs;
    sph_idx *hidx;
    int i, st;
    th_begin("sph_pairs_build: a gather list with per-particle h is SPH_ENOTSYMMETRIC");
    for (i = 0; i < N; ++i) hv[i] = (sph_real)(bx_dx * (1.1 + 0.3 * (i % 3)));
    st = lattice_make(&s, &s.box, 0, sph_view_soa(hv, NULL, NULL));
    hidx = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)s.off[N]);
    tslot = (sph_off *)malloc(sizeof(sph_off) * (size_t)s.off[N]);
    TH_CHECK(st == SPH_OK && hidx != NULL && tslot != NULL, "search %d", st);
    if (hidx != NULL && tslot != NULL) {
        st = sph_pairs_build(&s.list, hoff, hidx, s.off[N], toff, tslot, &pairs, &P);
        TH_CHECK(st == SPH_ENOTSYMMETRIC, "gather list, h per particle: %d (%s)", st, sph_strerror(st));
    }
    free(hidx), free(tslot);
    lattice_free(&s);
    th_end();
}

int main(void)
{
    operators_case();
    hctx_case();
    gather_pairs_case();
    return th_summary();
}
