/* examples/mpi_taylor_green.c - the Taylor-Green vortex of
 * examples/taylor_green.c (same equations, integrator, equation of state,
 * viscosity, defaults) decomposed over MPI ranks (docs/mpi.md).
 *
 * Decomposition: the periodic unit square is cut into P slabs along x, rank
 * r owns the particles with x in [r/P, (r+1)/P). Every step (docs/mpi.md,
 * "One step"):
 *   1. migrate: particles that drifted out of the slab go to their owner
 *      (moving particles only), locals kept in ascending global id;
 *   2. halo: each rank sends the particles within R = kappa h (+ margin) of
 *      another slab to that rank, at their own positions (the periodic box
 *      of the search and the operators takes the minimum image, so the wrap
 *      x = 1 -> 0 needs nothing else); halos kept in ascending global id;
 *   3. compute with the library: sources = locals then halos, targets = the
 *      first n_local sources (sph_nsearch_* with n_targets < n_sources,
 *      operators on the same list); fields that change inside a step
 *      (continuity or summation density, the kicked velocity before
 *      shifting) are refreshed in the halo from the same send lists;
 *   4. reductions (kinetic energy, L2 error, the CFL number of the step)
 *      with MPI_Allreduce; a rank that fails stops the job (MPI_Abort).
 * Identical answers: the search returns each target's sources in ascending
 * index; here the lists are reordered by global id (a merge of the local and
 * the halo run), which is the order of the single-process run (index =
 * global id). Each target then sums the same terms in the same order, so the
 * fields are bitwise those of one process for any number of ranks and
 * threads; only the energy sums, added rank by rank, differ in the last bits.
 * --compare and --check run the single-process reference (the same code on
 * MPI_COMM_SELF) on rank 0 and print the differences.
 *
 *   mpirun -n 2 ./mpi_taylor_green                 default run (as ./taylor_green)
 *   mpirun -n 2 ./mpi_taylor_green --lagrangian    moving particles (transport velocity)
 *   mpirun -n 2 ./mpi_taylor_green --check         fixed, moving and plain runs against one process
 *   mpirun -n 2 ./mpi_taylor_green --lagrangian --steps 50 --compare
 *   tools/mpi_scaling.sh                           strong and weak scaling, exchange against compute
 */
#include "example_io.h"

#include <fcntl.h>
#include <math.h>
#include <mpi.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define PI 3.14159265358979323846
/* taylor_green.c's bounds: a run stops with exit 1 when its kinetic energy
 * exceeds 1.01 E(0) or its relative L2 velocity error exceeds 1. */
#define TG_ENERGY_TOL 0.01
#define TG_L2_MAX 1.0
#define MTG_BOUNDS "a run stops with exit 1 when its kinetic energy exceeds 1.01 E(0) or its relative L2 velocity error exceeds 1"

typedef struct {
    int n;              /* particles per side */
    const char *kernel;
    const char *scheme; /* pressure | difference | corrected */
    double hdx;         /* h / dx */
    double t_end, re, c0, pb, pt, perturb, shift, cfl;
    int frames;         /* VTK frames (0: none) */
    int lagrangian;     /* 1: particles move (transport velocity); 0: fixed particles */
    int plain;          /* moving particles without the transport velocity (+ shifting) */
    int steps;          /* stop after this many steps of the t_end's dt (0: run to t_end) */
    int unordered;      /* keep the search's order (locals, then halos): round-off equality only */
} mtg_param;

/* What a run measured: the physics (as taylor_green.c prints it) and the
 * decomposition (counts and times; seconds are the largest over the ranks). */
typedef struct {
    double e_ratio, rate_fit, rate_exact, l2, cfl_max;
    double t_total, t_exchange, t_compute, bytes_sent; /* bytes: all ranks, all steps */
    double local_max, halo_sum, halo_max, local_sum;   /* particle counts at the last step */
    long steps, migrated, fallbacks;
    int frames; /* VTK frames written */
} mtg_result;

/* Particle fields. The first MTG_NX are what a particle carries to another
 * rank (migration, halo); the rest are computed per step. */
enum { F_X, F_Y, F_U, F_V, F_RHO, F_M, F_BU, F_BV, MTG_NX, /* exchanged */
       F_P = MTG_NX, F_VOL, F_DU, F_DV, F_DRHO, F_DIV, F_LU, F_LV, F_ONE, MTG_NF };
#define MTG_ALL ((1u << MTG_NX) - 1u)

/* One rank's particles: locals 0..nl-1 then halos nl..nl+nh-1, each run in
 * ascending global id; the halo send lists and receive slots of the last
 * selection; the neighbour lists. */
typedef struct {
    MPI_Comm comm;
    int rank, size;
    sph_idx nl, nh, cap;
    int64_t *gid;
    sph_real *f[MTG_NF];
    sph_real *gp, *T; /* 2 and 4 per particle */
    /* halo exchange plan: send_idx grouped by destination, recv slot of each received record */
    int *scnt, *sdsp, *rcnt, *rdsp, *near, n_near;
    sph_idx *send_idx, *slot, send_cap, slot_cap;
    double *sbuf, *rbuf;
    size_t sbuf_cap, rbuf_cap;
    ex_neighbours NL;
    sph_idx *merge; /* scratch of the list reordering */
    sph_off merge_cap;
    double t_exchange, bytes_sent;
    long migrated;
    int unordered; /* mtg_param.unordered */
} mtg_state;

#define FIELD(S, k) ((S)->f[k])

/* The analytic velocity at (x, y, t) (taylor_green.c's tg_exact). */
static void mtg_exact(double x, double y, double t, double nu, double *u, double *v)
{
    const double k = 2 * PI, d = exp(-2 * nu * k * k * t);
    *u = -cos(k * x) * sin(k * y) * d;
    *v = sin(k * x) * cos(k * y) * d;
}

/* ---- storage ---------------------------------------------------------------- */

/* p grown to hold n elements of size bytes (contents kept, *cap updated),
 * or NULL when out of memory (p then unchanged and still valid). */
static void *mtg_grow(void *p, size_t *cap, size_t n, size_t size)
{
    void *q;
    if (n <= *cap) return p;
    if (n > ((size_t)-1) / 2 / size) return NULL;
    n += n / 2 + 16;
    if ((q = realloc(p, n * size)) == NULL) return NULL;
    *cap = n;
    return q;
}

/* A message buffer of at least n doubles. 0 on success. */
static int mtg_room(double **buf, size_t *cap, size_t n)
{
    double *b = (double *)mtg_grow(*buf, cap, n, sizeof(double));
    if (b == NULL) return -1;
    *buf = b;
    return 0;
}

/* Room for n particles (locals + halos) in every field. SPH_OK or SPH_ESIZE. */
static int mtg_reserve(mtg_state *S, sph_idx n)
{
    size_t cap = (size_t)S->cap, c;
    int k;
    if (n <= S->cap) return SPH_OK;
    c = cap;
    {
        int64_t *g = (int64_t *)mtg_grow(S->gid, &c, (size_t)n, sizeof *S->gid);
        if (g == NULL) return SPH_ESIZE;
        S->gid = g;
    }
    if (c > (size_t)INT32_MAX / 4) return SPH_ESIZE;
    for (k = 0; k < MTG_NF; ++k) {
        sph_real *q = (sph_real *)realloc(S->f[k], c * sizeof(sph_real));
        if (q == NULL) return SPH_ESIZE;
        S->f[k] = q;
    }
    {
        sph_real *g = (sph_real *)realloc(S->gp, 2 * c * sizeof(sph_real)), *t;
        if (g == NULL) return SPH_ESIZE;
        S->gp = g;
        if ((t = (sph_real *)realloc(S->T, 4 * c * sizeof(sph_real))) == NULL) return SPH_ESIZE;
        S->T = t;
    }
    S->cap = (sph_idx)c;
    return SPH_OK;
}

/* Releases everything a rank's state holds. */
static void mtg_free(mtg_state *S)
{
    int k;
    for (k = 0; k < MTG_NF; ++k) free(S->f[k]);
    free(S->gid), free(S->gp), free(S->T), free(S->scnt), free(S->sdsp), free(S->rcnt), free(S->rdsp);
    free(S->near), free(S->send_idx), free(S->slot), free(S->sbuf), free(S->rbuf), free(S->merge);
    ex_neighbours_free(&S->NL);
    memset(S, 0, sizeof *S);
}

/* ---- decomposition ---------------------------------------------------------- */

/* The rank owning position x of the unit period: floor(x P), clamped. */
static int mtg_owner(double x, int P)
{
    int o = (int)floor(x * P);
    return o < 0 ? 0 : o >= P ? P - 1 : o;
}

/* Distance from x to slab q = [q/P, (q+1)/P) along the periodic unit axis. */
static double mtg_slab_distance(double x, int q, int P)
{
    double a = (double)q / P - x, b = x - (double)(q + 1) / P;
    a -= floor(a), b -= floor(b); /* going right to the slab's start, left to its end */
    return fmin(a, b);
}

/* A particle's global id and its position before sorting. */
typedef struct {
    int64_t g;
    sph_idx i;
} mtg_key;

/* qsort order of mtg_key: ascending global id. */
static int mtg_key_cmp(const void *a, const void *b)
{
    const int64_t x = ((const mtg_key *)a)->g, y = ((const mtg_key *)b)->g;
    return (x > y) - (x < y);
}

/* Permutes the exchanged fields and gid of particles [lo, lo + n) into the
 * order of keys (sorted). Uses the work fields F_P.. as scratch. */
static void mtg_apply_order(mtg_state *S, sph_idx lo, const mtg_key *key, sph_idx n)
{
    sph_real *tmp = FIELD(S, F_P);
    int64_t *gt = (int64_t *)(void *)S->T; /* 4 reals per particle: room for an int64 each */
    sph_idx i;
    int k;
    for (k = 0; k < MTG_NX; ++k) {
        for (i = 0; i < n; ++i) tmp[i] = FIELD(S, k)[lo + key[i].i];
        memcpy(FIELD(S, k) + lo, tmp, (size_t)n * sizeof(sph_real));
    }
    for (i = 0; i < n; ++i) gt[i] = S->gid[lo + key[i].i];
    memcpy(S->gid + lo, gt, (size_t)n * sizeof(int64_t));
}

/* Sorts particles [lo, lo + n) by global id; when slot is not NULL,
 * slot[k] = the sorted position (from lo) of the particle that was at lo + k. */
static int mtg_sort_by_gid(mtg_state *S, sph_idx lo, sph_idx n, sph_idx *slot)
{
    mtg_key *key = (mtg_key *)malloc((size_t)(n > 0 ? n : 1) * sizeof *key);
    sph_idx i;
    if (key == NULL) return SPH_ESIZE;
    for (i = 0; i < n; ++i) key[i].g = S->gid[lo + i], key[i].i = i;
    qsort(key, (size_t)n, sizeof *key, mtg_key_cmp);
    mtg_apply_order(S, lo, key, n);
    if (slot != NULL)
        for (i = 0; i < n; ++i) slot[key[i].i] = i;
    free(key);
    return SPH_OK;
}

/* Packs fields of mask (plus the gid when with_gid) of particles idx[0..n-1]
 * into buf as doubles, one record after another. */
static void mtg_pack(const mtg_state *S, const sph_idx *idx, sph_idx n, unsigned mask, int with_gid, double *buf)
{
    sph_idx i;
    int k;
    for (i = 0; i < n; ++i) {
        if (with_gid) *buf++ = (double)S->gid[idx[i]];
        for (k = 0; k < MTG_NX; ++k)
            if (mask & (1u << k)) *buf++ = (double)FIELD(S, k)[idx[i]];
    }
}

/* Unpacks record r of buf into particle i (the layout of mtg_pack). */
static void mtg_unpack(mtg_state *S, const double *buf, sph_idx r, int nrec, unsigned mask, int with_gid, sph_idx i)
{
    const double *p = buf + (size_t)r * (size_t)nrec;
    int k;
    if (with_gid) S->gid[i] = (int64_t)*p++;
    for (k = 0; k < MTG_NX; ++k)
        if (mask & (1u << k)) FIELD(S, k)[i] = (sph_real)*p++;
}

/* The number of fields in mask. */
static int mtg_bits(unsigned mask)
{
    int c = 0;
    for (; mask; mask >>= 1) c += (int)(mask & 1u);
    return c;
}

/* MPI_Alltoallv of records of nrec doubles: scnt[q] records to rank q from
 * sbuf; receives into S->rbuf, rcnt/rdsp in records. SPH_OK or SPH_ESIZE. */
static int mtg_alltoall(mtg_state *S, const int *scnt, int nrec, sph_idx *n_recv)
{
    int q, *sc = S->sdsp + S->size, *sd = sc + S->size, *rc = S->rdsp + S->size, *rd = rc + S->size;
    long long tot = 0, stot = 0;
    MPI_Alltoall((void *)scnt, 1, MPI_INT, S->rcnt, 1, MPI_INT, S->comm);
    for (q = 0; q < S->size; ++q) {
        S->rdsp[q] = (int)tot;
        if ((long long)S->rcnt[q] * nrec > INT32_MAX || (long long)scnt[q] * nrec > INT32_MAX) return SPH_ESIZE;
        sc[q] = scnt[q] * nrec, sd[q] = (int)(stot * nrec);
        rc[q] = S->rcnt[q] * nrec, rd[q] = (int)(tot * nrec);
        tot += S->rcnt[q], stot += scnt[q];
        if (tot * nrec > INT32_MAX || stot * nrec > INT32_MAX) return SPH_ESIZE;
    }
    if (mtg_room(&S->rbuf, &S->rbuf_cap, (size_t)(tot * nrec + 1)) != 0) return SPH_ESIZE;
    MPI_Alltoallv(S->sbuf, sc, sd, MPI_DOUBLE, S->rbuf, rc, rd, MPI_DOUBLE, S->comm);
    S->bytes_sent += (double)stot * nrec * sizeof(double);
    *n_recv = (sph_idx)tot;
    return SPH_OK;
}

/* Step 1: particles whose position left the slab go to their owner; the
 * remaining and arriving locals are put in ascending global id. */
static int mtg_migrate(mtg_state *S)
{
    const int P = S->size, nrec = 1 + MTG_NX;
    sph_idx i, keep = 0, ns = 0, nr;
    int q, st;
    int *cnt = S->scnt;
    for (q = 0; q < P; ++q) cnt[q] = 0;
    for (i = 0; i < S->nl; ++i)
        if (mtg_owner(FIELD(S, F_X)[i], P) != S->rank) ++cnt[mtg_owner(FIELD(S, F_X)[i], P)], ++ns;
    if (mtg_room(&S->sbuf, &S->sbuf_cap, (size_t)ns * nrec + 1) != 0) return SPH_ESIZE;
    { /* records grouped by destination: positions from a running offset per rank */
        int *at = S->sdsp;
        sph_idx one;
        at[0] = 0;
        for (q = 1; q < P; ++q) at[q] = at[q - 1] + cnt[q - 1];
        for (i = 0; i < S->nl; ++i) {
            const int o = mtg_owner(FIELD(S, F_X)[i], P);
            if (o == S->rank) continue;
            one = i;
            mtg_pack(S, &one, 1, MTG_ALL, 1, S->sbuf + (size_t)at[o]++ * nrec);
        }
    }
    if ((st = mtg_alltoall(S, cnt, nrec, &nr)) != SPH_OK) return st;
    for (i = 0; i < S->nl; ++i) { /* compact the kept locals, order unchanged */
        int k;
        if (mtg_owner(FIELD(S, F_X)[i], P) != S->rank) continue;
        if (keep != i) {
            for (k = 0; k < MTG_NX; ++k) FIELD(S, k)[keep] = FIELD(S, k)[i];
            S->gid[keep] = S->gid[i];
        }
        ++keep;
    }
    if ((st = mtg_reserve(S, keep + nr)) != SPH_OK) return st;
    for (i = 0; i < nr; ++i) mtg_unpack(S, S->rbuf, i, nrec, MTG_ALL, 1, keep + i);
    S->nl = keep + nr;
    S->migrated += (long)ns;
    return nr > 0 ? mtg_sort_by_gid(S, 0, S->nl, NULL) : SPH_OK;
}

/* Step 2, selection: the locals within reach of another slab, grouped by
 * destination (ascending local index, i.e. global id, within a group). */
static int mtg_select_halo(mtg_state *S, double reach)
{
    const int P = S->size;
    sph_idx i, n = 0;
    int a, q;
    for (q = 0; q < P; ++q) S->scnt[q] = 0;
    for (a = 0; a < S->n_near; ++a) {
        q = S->near[a];
        for (i = 0; i < S->nl; ++i)
            if (mtg_slab_distance(FIELD(S, F_X)[i], q, P) < reach) ++S->scnt[q];
    }
    for (q = 0; q < P; ++q) n += S->scnt[q];
    if (n > S->send_cap) {
        sph_idx *p = (sph_idx *)realloc(S->send_idx, (size_t)n * sizeof *p);
        if (p == NULL) return SPH_ESIZE;
        S->send_idx = p, S->send_cap = n;
    }
    S->sdsp[0] = 0;
    for (q = 1; q < P; ++q) S->sdsp[q] = S->sdsp[q - 1] + S->scnt[q - 1];
    for (q = 0; q < P; ++q) {
        sph_idx at = S->sdsp[q];
        int near = 0;
        for (a = 0; a < S->n_near; ++a) near |= S->near[a] == q;
        if (!near) continue;
        for (i = 0; i < S->nl; ++i)
            if (mtg_slab_distance(FIELD(S, F_X)[i], q, P) < reach) S->send_idx[at++] = i;
    }
    return SPH_OK;
}

/* Step 2 and 3, transfer: sends the fields of mask of the selected locals;
 * with with_gid a new halo (received, then sorted by global id: slot[]), else
 * a refresh of the same halo in place. */
static int mtg_send_halo(mtg_state *S, unsigned mask, int with_gid)
{
    const int nrec = mtg_bits(mask) + (with_gid != 0);
    const sph_idx nsend = S->sdsp[S->size - 1] + S->scnt[S->size - 1];
    const double t0 = MPI_Wtime();
    sph_idx nr, k;
    int st;
    if (mtg_room(&S->sbuf, &S->sbuf_cap, (size_t)nsend * nrec + 1) != 0) return SPH_ESIZE;
    mtg_pack(S, S->send_idx, nsend, mask, with_gid, S->sbuf);
    if ((st = mtg_alltoall(S, S->scnt, nrec, &nr)) != SPH_OK) return st;
    if (with_gid) {
        if ((st = mtg_reserve(S, S->nl + nr)) != SPH_OK) return st;
        if (nr > S->slot_cap) {
            sph_idx *p = (sph_idx *)realloc(S->slot, (size_t)nr * sizeof *p);
            if (p == NULL) return SPH_ESIZE;
            S->slot = p, S->slot_cap = nr;
        }
        for (k = 0; k < nr; ++k) mtg_unpack(S, S->rbuf, k, nrec, mask, 1, S->nl + k);
        S->nh = nr;
        st = mtg_sort_by_gid(S, S->nl, nr, S->slot);
    } else {
        if (nr != S->nh) return SPH_EINVAL; /* a refresh brings exactly the halo */
        for (k = 0; k < nr; ++k) mtg_unpack(S, S->rbuf, k, nrec, mask, 0, S->nl + S->slot[k]);
    }
    S->t_exchange += MPI_Wtime() - t0;
    return st;
}

/* Steps 1 and 2 at the start of a step (and before the first rates):
 * migrate and select anew when the particles move (or no halo exists yet),
 * then send every carried field. */
static int mtg_exchange(mtg_state *S, double reach, int reselect)
{
    const double t0 = MPI_Wtime();
    int st = SPH_OK;
    if (reselect) {
        if ((st = mtg_migrate(S)) == SPH_OK) st = mtg_select_halo(S, reach);
    }
    S->t_exchange += MPI_Wtime() - t0;
    return st == SPH_OK ? mtg_send_halo(S, MTG_ALL, reselect) : st;
}

/* ---- neighbour lists: the library's search, reordered by global id ------------ */

/* Lists of the nl local targets over the nl + nh sources (ex_neighbours_update:
 * targets = the first nl sources), each reordered into ascending global id:
 * the search gives ascending index (locals, then halos, each by global id),
 * one merge of the two runs gives the single-process order. */
static int mtg_lists(mtg_state *S, double h, double kappa, const sph_box *box)
{
    const sph_view X = sph_view_soa(FIELD(S, F_X), FIELD(S, F_Y), NULL);
    sph_idx i;
    int st = ex_neighbours_update(&S->NL, 2, X, S->nl + S->nh, S->nl, h, kappa, box);
    sph_off o, longest = 0;
    if (st != SPH_OK || S->unordered) return st;
    for (i = 0; i < S->nl; ++i)
        if (S->NL.offset[i + 1] - S->NL.offset[i] > longest) longest = S->NL.offset[i + 1] - S->NL.offset[i];
    if (longest > S->merge_cap) {
        sph_idx *p = (sph_idx *)realloc(S->merge, (size_t)longest * sizeof *p);
        if (p == NULL) return SPH_ESIZE;
        S->merge = p, S->merge_cap = longest;
    }
    for (i = 0; i < S->nl; ++i) {
        sph_idx *idx = S->NL.index;
        const sph_off o0 = S->NL.offset[i], o1 = S->NL.offset[i + 1];
        sph_off a = o0, b = o0, m = 0;
        while (b < o1 && idx[b] < S->nl) ++b; /* [o0, b): locals, [b, o1): halos */
        {
            const sph_off mid = b;
            while (a < mid || b < o1)
                S->merge[m++] = (b >= o1 || (a < mid && S->gid[idx[a]] < S->gid[idx[b]])) ? idx[a++] : idx[b++];
        }
        for (o = 0; o < m; ++o) idx[o0 + o] = S->merge[o];
    }
    return SPH_OK;
}

/* ---- the physics of taylor_green.c on local targets, local + halo sources ----- */

/* p = c0^2 (rho - rho0) + p_b and V = m / rho on every particle, halos included. */
static void mtg_eos(mtg_state *S, const mtg_param *P)
{
    const double rho0 = 1;
    sph_idx i;
    for (i = 0; i < S->nl + S->nh; ++i) {
        FIELD(S, F_P)[i] = P->c0 * P->c0 * (FIELD(S, F_RHO)[i] - rho0) + P->pb;
        FIELD(S, F_VOL)[i] = FIELD(S, F_M)[i] / FIELD(S, F_RHO)[i];
    }
}

/* A context over the sources (locals + halos) for the local targets. */
static sph_ctx mtg_ctx(const mtg_state *S, sph_kernel k, double h, const sph_box *box)
{
    sph_ctx c = sph_ctx_init(k, 2, h, &S->NL.list, sph_view_soa(FIELD(S, F_X), FIELD(S, F_Y), NULL));
    c.box = box;
    c.V = sph_view_soa(FIELD(S, F_VOL), NULL, NULL);
    c.m = sph_view_soa(FIELD(S, F_M), NULL, NULL);
    c.rho = sph_view_soa(FIELD(S, F_RHO), NULL, NULL);
    c.validate = SPH_VALIDATE_ARGS; /* the search's lists are well formed by construction */
    return c;
}

/* taylor_green.c's tg_rates: phase 0 writes drho/dt (O10 / O18, fixed
 * particles also - v.grad rho by O5 / O7), phase 1 dv/dt (O8 / O5 / O7 and
 * O12, fixed particles also - v.grad v by O17). */
static int mtg_rates(mtg_state *S, const mtg_param *P, sph_kernel k, double h, double nu, const sph_box *box,
                     int phase, long *n_fallback)
{
    const int corr = strcmp(P->scheme, "corrected") == 0, pres = strcmp(P->scheme, "pressure") == 0;
    const sph_scheme gs = corr ? SPH_SCHEME_CORRECTED : pres ? SPH_SCHEME_PRESSURE : SPH_SCHEME_DIFFERENCE;
    const sph_scheme ds = corr ? SPH_SCHEME_CORRECTED : SPH_SCHEME_DIFFERENCE;
    sph_real *u = FIELD(S, F_U), *v = FIELD(S, F_V), *rho = FIELD(S, F_RHO), *du = FIELD(S, F_DU), *dv = FIELD(S, F_DV);
    const sph_view vel = sph_view_soa(u, v, NULL);
    sph_ctx c;
    sph_idx i, nf = 0;
    int st;
    mtg_eos(S, P);
    if (phase == 0 && (P->lagrangian || S->NL.list.offset == NULL) &&
        (st = mtg_lists(S, h, sph_kernel_support(k), box)) != SPH_OK)
        return st;
    c = mtg_ctx(S, k, h, box);
    if (phase == 0) {
        sph_real *drho = FIELD(S, F_DRHO);
        if ((st = sph_divergence(&c, ds, vel, sph_view_none(), sph_out_soa(FIELD(S, F_DIV), NULL, NULL), &nf)) != SPH_OK)
            return st;
        for (i = 0; i < S->nl; ++i) drho[i] = -rho[i] * FIELD(S, F_DIV)[i];
        if (!P->lagrangian) {
            if ((st = sph_gradient(&c, ds, sph_view_soa(rho, NULL, NULL), sph_view_none(),
                                   sph_out_interleaved(S->gp, 2), NULL)) != SPH_OK)
                return st;
            for (i = 0; i < S->nl; ++i) drho[i] -= S->gp[2 * i] * u[i] + S->gp[2 * i + 1] * v[i];
        }
        *n_fallback += nf;
        return SPH_OK;
    }
    if ((st = sph_gradient(&c, gs, sph_view_soa(FIELD(S, F_P), NULL, NULL), sph_view_none(),
                           sph_out_interleaved(S->gp, 2), NULL)) != SPH_OK ||
        (st = sph_laplacian(&c, sph_view_soa(u, NULL, NULL), sph_view_none(), sph_out_soa(FIELD(S, F_LU), NULL, NULL))) !=
            SPH_OK ||
        (st = sph_laplacian(&c, sph_view_soa(v, NULL, NULL), sph_view_none(), sph_out_soa(FIELD(S, F_LV), NULL, NULL))) !=
            SPH_OK)
        return st;
    for (i = 0; i < S->nl; ++i) {
        du[i] = -S->gp[2 * i] / rho[i] + nu * FIELD(S, F_LU)[i];
        dv[i] = -S->gp[2 * i + 1] / rho[i] + nu * FIELD(S, F_LV)[i];
    }
    if (!P->lagrangian) {
        if ((st = sph_gradient_vector(&c, ds, vel, sph_view_none(), S->T, 4, NULL)) != SPH_OK) return st;
        for (i = 0; i < S->nl; ++i) {
            const sph_real *T = S->T + 4 * i;
            du[i] -= T[0] * u[i] + T[1] * v[i];
            dv[i] -= T[2] * u[i] + T[3] * v[i];
        }
    }
    return SPH_OK;
}

/* The pair sums of the transport-velocity formulation (Adami, Hu & Adams
 * 2013, J. Comput. Phys. 241, 292-307, eqs. (8), (10), (12)), w_ij = V_i^2 + V_j^2:
 *   m_i dv_i/dt = sum_j w_ij [ -p_ij grad_i W_ij + (A_i + A_j)/2 . grad_i W_ij + eta (v_i - v_j) F_ij ],
 *   m_i b_i     = -p_t sum_j w_ij grad_i W_ij,
 * from the pair terms (O1), (O4), (O9), (O12), as taylor_green.c's
 * tg_tvf_pairs, for the local targets over local + halo sources. */
static void mtg_tvf_pairs(mtg_state *S, sph_kernel k, double h, double eta, double p_t, int pressure,
                          const sph_box *box)
{
    const sph_neighbours *list = &S->NL.list;
    const sph_real *x = FIELD(S, F_X), *y = FIELD(S, F_Y), *u = FIELD(S, F_U), *v = FIELD(S, F_V), *m = FIELD(S, F_M);
    const sph_real *rho = FIELD(S, F_RHO), *p = FIELD(S, F_P), *T = S->T;
    sph_idx i;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) /* a gather: each target its own sums, any thread count gives the same bits */
#endif
    for (i = 0; i < S->nl; ++i) {
        const double Vi = m[i] / rho[i];
        sph_real acc[2] = {0, 0}, b[2] = {0, 0};
        sph_off o;
        for (o = list->offset[i]; o < list->offset[i + 1]; ++o) {
            const sph_idx j = list->index[o];
            const double Vj = m[j] / rho[j], w = Vi * Vi + Vj * Vj;
            sph_real dx[2], Ar[2];
            sph_pair pk;
            int a;
            if (j == i) continue;
            dx[0] = sph_box_delta(box, 0, x[i] - x[j]), dx[1] = sph_box_delta(box, 1, y[i] - y[j]);
            pk = sph_pair_kernel(k, 2, dx, h); /* (O1) */
            if (pressure) /* (O4) with weight w_ij and f = -p_ij */
                sph_pair_grad_standard(2, w, -(rho[j] * p[i] + rho[i] * p[j]) / (rho[i] + rho[j]), pk.F, dx, acc);
            for (a = 0; a < 2; ++a) { /* (O9): row a of (A_i + A_j)/2 . grad W */
                Ar[0] = T[4 * i + 2 * a] + T[4 * j + 2 * a], Ar[1] = T[4 * i + 2 * a + 1] + T[4 * j + 2 * a + 1];
                acc[a] += sph_pair_div_standard(2, 0.5 * w, Ar, pk.F, dx);
            }
            acc[0] += eta * sph_pair_laplacian(0.5 * w, u[i], u[j], pk.F); /* (O12) */
            acc[1] += eta * sph_pair_laplacian(0.5 * w, v[i], v[j], pk.F);
            sph_pair_grad_standard(2, w, 1, pk.F, dx, b); /* (O4), f = 1 */
        }
        FIELD(S, F_DU)[i] = acc[0] / m[i], FIELD(S, F_DV)[i] = acc[1] / m[i];
        FIELD(S, F_BU)[i] = -p_t * b[0] / m[i], FIELD(S, F_BV)[i] = -p_t * b[1] / m[i];
    }
}

/* taylor_green.c's tg_tvf_rates: lists, density by summation (O2) on the
 * locals and refreshed in the halo, p, V and A = rho v (v~ - v) on every
 * particle, then the pressure gradient (O5 / O7) and the pair sums. */
static int mtg_tvf_rates(mtg_state *S, const mtg_param *P, sph_kernel k, double h, double nu, double dt,
                         const sph_box *box, long *n_fallback)
{
    const double rho0 = 1, p_t = P->pt >= 0 ? P->pt : rho0 * P->c0 * P->c0;
    const int pres = strcmp(P->scheme, "pressure") == 0;
    sph_real *rho = FIELD(S, F_RHO), *u = FIELD(S, F_U), *v = FIELD(S, F_V);
    sph_ctx c;
    sph_idx i, nf = 0;
    int st;
    if ((st = mtg_lists(S, h, sph_kernel_support(k), box)) != SPH_OK) return st;
    c = mtg_ctx(S, k, h, box);
    if ((st = sph_density(&c, sph_out_soa(rho, NULL, NULL))) != SPH_OK) return st; /* (O2) */
    if ((st = mtg_send_halo(S, 1u << F_RHO, 0)) != SPH_OK) return st;
    mtg_eos(S, P);
    for (i = 0; i < S->nl + S->nh; ++i) {
        const double tu = 0.5 * dt * FIELD(S, F_BU)[i], tv = 0.5 * dt * FIELD(S, F_BV)[i];
        sph_real *T = S->T + 4 * i;
        T[0] = rho[i] * u[i] * tu, T[1] = rho[i] * u[i] * tv;
        T[2] = rho[i] * v[i] * tu, T[3] = rho[i] * v[i] * tv;
    }
    if (!pres && (st = sph_gradient(&c, strcmp(P->scheme, "corrected") == 0 ? SPH_SCHEME_CORRECTED
                                                                             : SPH_SCHEME_DIFFERENCE,
                                    sph_view_soa(FIELD(S, F_P), NULL, NULL), sph_view_none(),
                                    sph_out_interleaved(S->gp, 2), &nf)) != SPH_OK)
        return st;
    mtg_tvf_pairs(S, k, h, rho0 * nu, p_t, pres, box);
    if (!pres)
        for (i = 0; i < S->nl; ++i)
            FIELD(S, F_DU)[i] -= S->gp[2 * i] / rho[i], FIELD(S, F_DV)[i] -= S->gp[2 * i + 1] / rho[i];
    *n_fallback += nf;
    return SPH_OK;
}

/* taylor_green.c's tg_shift (Xu et al. 2009, Lind et al. 2012): dr_i =
 * -D h^2 grad C_i (O4, f = 1), at most 0.2 dx, and u, v, rho carried by one
 * Taylor term (O7). The halo's u, v, rho are refreshed first (kicked since
 * the last exchange). */
static int mtg_shift(mtg_state *S, sph_kernel k, double h, double dx, double D, const sph_box *box)
{
    sph_real *f[3], *lu = FIELD(S, F_LU), *lv = FIELD(S, F_LV);
    sph_ctx c;
    sph_idx i;
    int st, q;
    if ((st = mtg_send_halo(S, (1u << F_U) | (1u << F_V) | (1u << F_RHO), 0)) != SPH_OK) return st;
    for (i = 0; i < S->nl + S->nh; ++i) FIELD(S, F_ONE)[i] = 1;
    c = mtg_ctx(S, k, h, box);
    f[0] = FIELD(S, F_U), f[1] = FIELD(S, F_V), f[2] = FIELD(S, F_RHO);
    if ((st = sph_gradient(&c, SPH_SCHEME_STANDARD, sph_view_soa(FIELD(S, F_ONE), NULL, NULL), sph_view_none(),
                           sph_out_soa(lu, lv, NULL), NULL)) != SPH_OK)
        return st;
    for (i = 0; i < S->nl; ++i) {
        double ax = -D * h * h * lu[i], ay = -D * h * h * lv[i], a = sqrt(ax * ax + ay * ay);
        if (a > 0.2 * dx) ax *= 0.2 * dx / a, ay *= 0.2 * dx / a;
        lu[i] = ax, lv[i] = ay;
    }
    for (q = 0; q < 3; ++q) {
        if ((st = sph_gradient(&c, SPH_SCHEME_CORRECTED, sph_view_soa(f[q], NULL, NULL), sph_view_none(),
                               sph_out_interleaved(S->gp, 2), NULL)) != SPH_OK)
            return st;
        for (i = 0; i < S->nl; ++i) f[q][i] += S->gp[2 * i] * lu[i] + S->gp[2 * i + 1] * lv[i];
    }
    for (i = 0; i < S->nl; ++i) {
        FIELD(S, F_X)[i] += lu[i], FIELD(S, F_Y)[i] += lv[i];
        FIELD(S, F_X)[i] -= floor(FIELD(S, F_X)[i]), FIELD(S, F_Y)[i] -= floor(FIELD(S, F_Y)[i]);
    }
    return SPH_OK;
}

/* ---- reductions and output ---------------------------------------------------- */

/* Kinetic energy and the L2 velocity error over all ranks (MPI_SUM of the
 * local sums, in local order as taylor_green.c's tg_energy). */
static double mtg_energy(const mtg_state *S, double t, double nu, double *l2)
{
    double s[3] = {0, 0, 0}, g[3], ua, va;
    sph_idx i;
    for (i = 0; i < S->nl; ++i) {
        const double u = FIELD(S, F_U)[i], v = FIELD(S, F_V)[i];
        s[0] += 0.5 * FIELD(S, F_M)[i] * (u * u + v * v);
        mtg_exact(FIELD(S, F_X)[i], FIELD(S, F_Y)[i], t, nu, &ua, &va);
        s[1] += (u - ua) * (u - ua) + (v - va) * (v - va);
        s[2] += ua * ua + va * va;
    }
    MPI_Allreduce(s, g, 3, MPI_DOUBLE, MPI_SUM, S->comm);
    *l2 = sqrt(g[1] / g[2]);
    return g[0];
}

/* A rank whose allocation, search or operator failed stops the job
 * (MPI_Abort: the other ranks would wait in the next exchange for ever),
 * naming the rank, the stage and the status. */
static void mtg_ok(const mtg_state *S, int st, const char *what)
{
    if (st == SPH_OK) return;
    fprintf(stderr, "mpi_taylor_green: rank %d: %s: %s\n", S->rank, what, sph_strerror(st));
    fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, 1);
}

/* Gathers fields (F_X, F_Y, F_U, F_V, F_RHO, F_P) of every particle into
 * out[6][N] on rank 0, indexed by global id (out unused elsewhere). */
enum { MTG_NOUT = 6 };
static void mtg_gather(mtg_state *S, sph_idx N, double *out)
{
    static const int fk[MTG_NOUT] = {F_X, F_Y, F_U, F_V, F_RHO, F_P};
    const int nrec = 1 + MTG_NOUT;
    int *cnt = NULL, *dsp = NULL, q, n = (int)S->nl * nrec, st = SPH_OK;
    double *buf = (double *)malloc((size_t)(n + 1) * sizeof(double)), *all = NULL;
    sph_idx i;
    if (S->rank == 0) {
        cnt = (int *)malloc((size_t)S->size * sizeof(int)), dsp = (int *)malloc((size_t)S->size * sizeof(int));
        all = (double *)malloc(((size_t)N * nrec + 1) * sizeof(double));
        if (cnt == NULL || dsp == NULL || all == NULL || out == NULL) st = SPH_ESIZE;
    }
    if (buf == NULL || (long long)N * nrec > INT32_MAX) st = SPH_ESIZE;
    mtg_ok(S, st, "gathering the particles on rank 0");
    for (i = 0; i < S->nl; ++i) {
        buf[(size_t)i * nrec] = (double)S->gid[i];
        for (q = 0; q < MTG_NOUT; ++q) buf[(size_t)i * nrec + 1 + q] = (double)FIELD(S, fk[q])[i];
    }
    MPI_Gather(&n, 1, MPI_INT, cnt, 1, MPI_INT, 0, S->comm);
    if (S->rank == 0)
        for (q = 0; q < S->size; ++q) dsp[q] = q == 0 ? 0 : dsp[q - 1] + cnt[q - 1];
    MPI_Gatherv(buf, n, MPI_DOUBLE, all, cnt, dsp, MPI_DOUBLE, 0, S->comm);
    if (S->rank == 0)
        for (i = 0; i < N; ++i) {
            const double *r = all + (size_t)i * nrec;
            const int64_t g = (int64_t)r[0];
            for (q = 0; q < MTG_NOUT; ++q) out[(size_t)q * N + g] = r[1 + q];
        }
    free(buf), free(cnt), free(dsp), free(all);
}

/* One VTK frame on rank 0, particles in global-id order: the file
 * taylor_green.c writes for the same state. A file that cannot be written
 * is reported and the run goes on (as in taylor_green.c). */
static void mtg_vtk(mtg_state *S, sph_idx N, double *G, ex_series *frames, double t, int frame)
{
    sph_real *R = NULL;
    ex_field f[3];
    size_t i;
    mtg_gather(S, N, G);
    if (S->rank != 0) return;
    if ((R = (sph_real *)malloc((size_t)N * MTG_NOUT * sizeof(sph_real))) == NULL) {
        fprintf(stderr, "mpi_taylor_green: no memory for VTK frame %d\n", frame);
        return;
    }
    for (i = 0; i < (size_t)N * MTG_NOUT; ++i) R[i] = (sph_real)G[i]; /* x, y, u, v, rho, p */
    f[0].name = "velocity", f[0].v = sph_view_soa(R + 2 * (size_t)N, R + 3 * (size_t)N, NULL), f[0].ncomp = 2;
    f[1].name = "pressure", f[1].v = sph_view_soa(R + 5 * (size_t)N, NULL, NULL), f[1].ncomp = 1;
    f[2].name = "density", f[2].v = sph_view_soa(R + 4 * (size_t)N, NULL, NULL), f[2].ncomp = 1;
    if (ex_series_write(frames, t, N, 2, sph_view_soa(R, R + N, NULL), f, 3) != 0)
        fprintf(stderr, "mpi_taylor_green: cannot write VTK frame %d into %s\n", frame, frames->dir);
    free(R);
}

/* ---- one run ---------------------------------------------------------------------- */

/* One run on the ranks of comm. csv (rank 0, may be NULL): t, E/E0, exact
 * E/E0, L2 error as taylor_green.c writes it; frames (may be NULL; opened on rank 0): VTK series;
 * with gather_final, final (rank 0) receives the fields of mtg_gather at the
 * end. Returns SPH_OK, or SPH_ENONFINITE (on every rank) when the energy
 * stops being finite, EX_EGROWTH (on every rank, rank 0 says why) when it or
 * the L2 error grows past taylor_green.c's bounds; a failed allocation or search stops the job (mtg_ok). */
static int mtg_run(MPI_Comm comm, const mtg_param *P, mtg_result *R, FILE *csv, ex_series *frames, int gather_final,
                   double *final)
{
    const int n = P->n, kid = sph_kernel_from_name(P->kernel);
    const sph_kernel k = (sph_kernel)kid;
    const double L = 1, U = 1, rho0 = 1, dx = L / n, h = P->hdx * dx, nu = U * L / P->re;
    const double dt0 = fmin(P->cfl * h / (P->c0 + U), 0.125 * h * h / nu);
    const long steps = (long)ceil(P->t_end / dt0 - 1e-9);
    const double dt = P->t_end / (double)steps;
    const long last = P->steps > 0 && P->steps < steps ? P->steps : steps;
    const sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 0}};
    const int tvf = P->lagrangian && !P->plain;
    const sph_idx N = (sph_idx)n * n;
    const double reach = sph_kernel_support(k) * h * (1 + 1e-9) + 1e-12; /* the search radius, and a rounding margin */
    double e0 = 0, l2 = 0, st_t = 0, st_y = 0, st_tt = 0, st_ty = 0, cnt = 0, t0, t_start, ex0, *G = NULL;
    mtg_state S;
    sph_idx i;
    long s, nfb = 0;
    int st = SPH_OK, frame = 0, d, q;
    uint64_t seed = 12345;
    ex_growth energy = {"kinetic energy", "the time step is too large for the resolution: lower --cfl", 0, 1 + TG_ENERGY_TOL, 0};
    ex_growth error = {"relative L2 velocity error", "the weakly compressible pressure cannot follow a decay this fast: "
                       "Re too low for c0 and the resolution, raise --re, --c0 or --n", 0, 1, TG_L2_MAX};
    memset(&S, 0, sizeof S);
    memset(R, 0, sizeof *R);
    S.comm = comm;
    S.unordered = P->unordered;
    MPI_Comm_rank(comm, &S.rank);
    MPI_Comm_size(comm, &S.size);
    S.scnt = (int *)calloc((size_t)S.size, sizeof(int)), S.rcnt = (int *)calloc((size_t)S.size, sizeof(int));
    S.sdsp = (int *)calloc((size_t)S.size * 3, sizeof(int)), S.rdsp = (int *)calloc((size_t)S.size * 3, sizeof(int));
    S.near = (int *)calloc((size_t)S.size, sizeof(int));
    if (S.scnt == NULL || S.rcnt == NULL || S.sdsp == NULL || S.rdsp == NULL || S.near == NULL) st = SPH_ESIZE;
    if (st == SPH_OK && (frames != NULL || gather_final) && S.rank == 0 &&
        (G = (double *)malloc((size_t)N * MTG_NOUT * sizeof(double))) == NULL)
        st = SPH_ESIZE;
    mtg_ok(&S, st, "allocating the decomposition");
    /* ranks whose slab may lie within reach: up to ceil(reach P) slabs either side */
    for (d = 1; d <= S.size - 1 && d <= (int)ceil(reach * S.size); ++d)
        for (q = 0; q < 2; ++q) {
            const int r = ((q ? S.rank - d : S.rank + d) % S.size + S.size) % S.size;
            int a, seen = r == S.rank;
            for (a = 0; a < S.n_near; ++a) seen |= S.near[a] == r;
            if (!seen) S.near[S.n_near++] = r;
        }
    /* the particles of this slab, in global-id order, as taylor_green.c places them (seeded perturbation) */
    for (i = 0; i < N; ++i) {
        double px = ((double)(i % n) + 0.5) * dx, py = ((double)(i / n) + 0.5) * dx, pa, pb;
        int a;
        for (a = 0; a < 2 && P->perturb > 0; ++a) {
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            pa = P->perturb * dx * (2.0 * (double)(seed >> 11) / 9007199254740992.0 - 1);
            if (a == 0) px += pa; else py += pa;
        }
        if (mtg_owner(px - floor(px), S.size) != S.rank) continue;
        mtg_ok(&S, mtg_reserve(&S, S.nl + 1), "allocating the particles");
        mtg_exact(px, py, 0, nu, &pa, &pb);
        S.gid[S.nl] = i;
        FIELD(&S, F_X)[S.nl] = px, FIELD(&S, F_Y)[S.nl] = py, FIELD(&S, F_U)[S.nl] = pa, FIELD(&S, F_V)[S.nl] = pb;
        FIELD(&S, F_RHO)[S.nl] = rho0 - rho0 * U * U / 4 * (cos(4 * PI * px) + cos(4 * PI * py)) / (P->c0 * P->c0);
        FIELD(&S, F_M)[S.nl] = rho0 * dx * dx;
        FIELD(&S, F_BU)[S.nl] = FIELD(&S, F_BV)[S.nl] = 0;
        ++S.nl;
    }
    MPI_Barrier(comm);
    t_start = MPI_Wtime();
    mtg_ok(&S, mtg_exchange(&S, reach, 1), "the first halo exchange");
    if (tvf) { /* the rates of the start, in taylor_green.c's order; masses so that the summation density starts at the analytic rho */
        for (i = 0; i < S.nl; ++i) FIELD(&S, F_DIV)[i] = FIELD(&S, F_RHO)[i];
        mtg_ok(&S, mtg_tvf_rates(&S, P, k, h, nu, dt, &box, &nfb), "the rates");
        for (i = 0; i < S.nl; ++i)
            FIELD(&S, F_M)[i] *= FIELD(&S, F_DIV)[i] / FIELD(&S, F_RHO)[i], FIELD(&S, F_BU)[i] = FIELD(&S, F_BV)[i] = 0;
        mtg_ok(&S, mtg_exchange(&S, reach, 0), "the halo exchange");
        mtg_ok(&S, mtg_tvf_rates(&S, P, k, h, nu, dt, &box, &nfb), "the rates");
    } else {
        mtg_ok(&S, mtg_rates(&S, P, k, h, nu, &box, 0, &nfb), "the rates");
        mtg_ok(&S, mtg_rates(&S, P, k, h, nu, &box, 1, &nfb), "the rates");
    }
    ex0 = S.t_exchange;
    for (s = 0; s <= last; ++s) {
        const double t = (double)s * dt;
        const double e = mtg_energy(&S, t, nu, &l2);
        double vmax = 0, vg = 0;
        if (s == 0) e0 = energy.start = e;
        if (!(e > 0) || !isfinite(e)) { /* the same e on every rank */
            st = SPH_ENONFINITE;
            break;
        }
        if (!(e <= ex_growth_bound(&energy)) || !(l2 <= ex_growth_bound(&error))) { /* reduced: every rank decides alike */
            if (S.rank == 0 && ex_growth_check(&energy, e, t) == SPH_OK) ex_growth_check(&error, l2, t);
            st = EX_EGROWTH;
            break;
        }
        for (i = 0; i < S.nl; ++i) /* CFL number of the step: dt (c0 + max |v|) / h, MPI_MAX */
            vmax = fmax(vmax, sqrt(FIELD(&S, F_U)[i] * FIELD(&S, F_U)[i] + FIELD(&S, F_V)[i] * FIELD(&S, F_V)[i]));
        MPI_Allreduce(&vmax, &vg, 1, MPI_DOUBLE, MPI_MAX, comm);
        R->cfl_max = fmax(R->cfl_max, dt * (P->c0 + vg) / h);
        st_t += t, st_y += log(e / e0), st_tt += t * t, st_ty += t * log(e / e0), cnt += 1;
        if (csv != NULL && S.rank == 0 && (s % (steps / 200 + 1) == 0 || s == steps))
            fprintf(csv, "%.6g,%.9g,%.9g,%.6g\n", t, e / e0, exp(-16 * PI * PI * nu * t), l2);
        if (frames != NULL && P->frames > 0 && (s * P->frames) / steps >= frame) {
            mtg_vtk(&S, N, G, frames, t, frame);
            ++frame;
        }
        if (s == last) break;
        t0 = MPI_Wtime();
        for (i = 0; i < S.nl; ++i) { /* kick v by dt/2, drift x by dt with v~ = v + (dt/2) b (tvf) or v */
            FIELD(&S, F_U)[i] += 0.5 * dt * FIELD(&S, F_DU)[i], FIELD(&S, F_V)[i] += 0.5 * dt * FIELD(&S, F_DV)[i];
            if (!P->lagrangian) continue;
            FIELD(&S, F_X)[i] += dt * (FIELD(&S, F_U)[i] + (tvf ? 0.5 * dt * FIELD(&S, F_BU)[i] : 0));
            FIELD(&S, F_Y)[i] += dt * (FIELD(&S, F_V)[i] + (tvf ? 0.5 * dt * FIELD(&S, F_BV)[i] : 0));
            FIELD(&S, F_X)[i] -= floor(FIELD(&S, F_X)[i]), FIELD(&S, F_Y)[i] -= floor(FIELD(&S, F_Y)[i]);
        }
        mtg_ok(&S, mtg_exchange(&S, reach, P->lagrangian), "the halo exchange");
        if (tvf) {
            mtg_ok(&S, mtg_tvf_rates(&S, P, k, h, nu, dt, &box, &nfb), "the rates");
        } else {
            mtg_ok(&S, mtg_rates(&S, P, k, h, nu, &box, 0, &nfb), "the rates");
            for (i = 0; i < S.nl; ++i) FIELD(&S, F_RHO)[i] += dt * FIELD(&S, F_DRHO)[i]; /* rho by dt, mid-step velocity */
            mtg_ok(&S, mtg_send_halo(&S, 1u << F_RHO, 0), "the density refresh");
            mtg_ok(&S, mtg_rates(&S, P, k, h, nu, &box, 1, &nfb), "the rates");
        }
        for (i = 0; i < S.nl; ++i) /* kick v by dt/2 */
            FIELD(&S, F_U)[i] += 0.5 * dt * FIELD(&S, F_DU)[i], FIELD(&S, F_V)[i] += 0.5 * dt * FIELD(&S, F_DV)[i];
        if (P->lagrangian && P->plain && P->shift > 0) mtg_ok(&S, mtg_shift(&S, k, h, dx, P->shift, &box), "shifting");
        R->t_compute += MPI_Wtime() - t0;
    }
    R->t_total = MPI_Wtime() - t_start;
    R->t_compute -= S.t_exchange - ex0; /* the steps' wall time less their exchanges */
    R->steps = s;
    R->frames = frame;
    R->rate_exact = 16 * PI * PI * nu;
    R->rate_fit = -(cnt * st_ty - st_t * st_y) / (cnt * st_tt - st_t * st_t);
    R->e_ratio = st == SPH_OK ? mtg_energy(&S, (double)s * dt, nu, &l2) / e0 : NAN;
    R->l2 = l2;
    { /* counts and times over the ranks */
        double loc[4] = {(double)S.nl, (double)S.nh, S.bytes_sent, (double)S.migrated}, sum[4], mx[5], my[5];
        long long f = nfb, fs = 0;
        my[0] = (double)S.nl, my[1] = (double)S.nh, my[2] = R->t_total, my[3] = S.t_exchange, my[4] = R->t_compute;
        MPI_Allreduce(loc, sum, 4, MPI_DOUBLE, MPI_SUM, comm);
        MPI_Allreduce(my, mx, 5, MPI_DOUBLE, MPI_MAX, comm);
        MPI_Allreduce(&f, &fs, 1, MPI_LONG_LONG, MPI_SUM, comm);
        R->local_sum = sum[0], R->halo_sum = sum[1], R->bytes_sent = sum[2], R->migrated = (long)sum[3];
        R->local_max = mx[0], R->halo_max = mx[1], R->t_total = mx[2], R->t_exchange = mx[3], R->t_compute = mx[4];
        R->fallbacks = (long)fs;
    }
    if (st == SPH_OK && gather_final) {
        mtg_gather(&S, N, G);
        if (S.rank == 0) memcpy(final, G, (size_t)N * MTG_NOUT * sizeof(double));
    }
    free(G);
    mtg_free(&S);
    return st;
}

/* ---- driver ---------------------------------------------------------------------- */

/* Largest absolute and relative (to the field's largest magnitude) difference
 * of the first five gathered fields (x, y, u, v, rho) between two runs. */
static void mtg_diff(const double *a, const double *b, sph_idx N, double *abs_d, double *rel_d)
{
    int q;
    sph_idx i;
    for (q = 0; q < 5; ++q) {
        double d = 0, m = 0;
        for (i = 0; i < N; ++i) {
            const double x = a[(size_t)q * N + i], y = b[(size_t)q * N + i];
            double e = fabs(x - y);
            if (q < 2) e = fmin(e, 1 - e); /* positions: distance on the periodic unit axis */
            if (!(e <= d)) d = e;          /* NaN stays NaN */
            m = fmax(m, fabs(y));
        }
        abs_d[q] = d, rel_d[q] = m > 0 ? d / m : d;
    }
}

/* The run on every rank, then (rank 0) the same run on one process
 * (MPI_COMM_SELF) and the differences of the fields. 1 when they differ
 * beyond bound (0: bitwise), -1 when a run failed, 0 otherwise. */
static int mtg_compare(const mtg_param *P, const char *label, double bound, int need_migration)
{
    const sph_idx N = (sph_idx)P->n * P->n;
    mtg_result R, R1;
    double *A = NULL, *B = NULL, ad[5], rd[5], worst = 0;
    int rank, size, st, bad = 0, q;
    static const char *name[5] = {"x", "y", "u", "v", "rho"};
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (rank == 0) {
        A = (double *)malloc((size_t)N * MTG_NOUT * sizeof(double));
        B = (double *)malloc((size_t)N * MTG_NOUT * sizeof(double));
        if (A == NULL || B == NULL) bad = -1;
    }
    MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (bad) return free(A), free(B), -1;
    st = mtg_run(MPI_COMM_WORLD, P, &R, NULL, NULL, 1, A);
    if (st != SPH_OK) {
        if (rank == 0) printf("mpi_taylor_green %s: the run on %d ranks failed: %s\n", label, size, sph_strerror(st));
        return free(A), free(B), -1;
    }
    if (rank == 0) {
        st = mtg_run(MPI_COMM_SELF, P, &R1, NULL, NULL, 1, B);
        if (st != SPH_OK) {
            printf("mpi_taylor_green %s: the one-process run failed: %s\n", label, sph_strerror(st));
            bad = -1;
        } else {
            mtg_diff(A, B, N, ad, rd);
            printf("mpi_taylor_green %s: %d ranks against 1 process, %ld steps, %ld particles, halo %.0f "
                   "(%.1f %% of the locals), %ld migrations\n",
                   label, size, R.steps, (long)N, R.halo_sum, 100 * R.halo_sum / R.local_sum, R.migrated);
            printf("  max |difference| (relative to the field's max):");
            for (q = 0; q < 5; ++q) {
                printf(" %s %.3g (%.3g)", name[q], ad[q], rd[q]);
                worst = fmax(worst, rd[q]);
            }
            printf("\n  E(t)/E0 %.17g against %.17g (relative difference %.3g)\n", R.e_ratio, R1.e_ratio,
                   fabs(R.e_ratio - R1.e_ratio) / R1.e_ratio);
            bad = !(worst <= bound) || !(fabs(R.e_ratio - R1.e_ratio) <= 1e-12 * R1.e_ratio);
            if (need_migration && size > 1 && R.migrated == 0) {
                printf("  no particle crossed a rank boundary: the run did not test migration\n");
                bad = 1;
            }
            printf("  %s (fields: %s; E(t)/E0 within 1e-12)\n", bad ? "FAIL" : "pass",
                   bound == 0 ? "bitwise equal" : "within the bound");
        }
    }
    MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
    free(A), free(B);
    return bad;
}

/* Refuses a value outside [lo, hi] (naming the option). 0 when it is inside. */
int main(int argc, char **argv)
{
    mtg_param P;
    mtg_result R;
    const char *out = "build/mpi_taylor_green";
    int threads = 0, check = 0, compare = 0, rank, size, st, bad = 0;
    double bound = 0;
    const ex_arg opt[] = {
        {"n", "particles per side of the unit square", NULL, &P.n, NULL, NULL, 4, 46340, 0, NULL},
        {"kernel", "smoothing kernel", NULL, NULL, &P.kernel, NULL, 0, 0, 0, ex_kernel_choices()},
        {"scheme", "pressure gradient: pressure (O8), difference (O5), corrected (O7)", NULL, NULL, &P.scheme, NULL,
         0, 0, 0, "pressure|difference|corrected"},
        {"hdx", "smoothing length h / dx (0: 2 moving, 1.3 fixed)", &P.hdx, NULL, NULL, NULL, 1e-3, 10, EX_OR_ZERO, NULL},
        {"t-end", "end time (L / U)", &P.t_end, NULL, NULL, NULL, 0, 100, EX_OPEN_LO, NULL},
        {"re", "Reynolds number U L / nu", &P.re, NULL, NULL, NULL, 1e-3, 1e6, 0, NULL},
        {"c0", "speed of sound (U)", &P.c0, NULL, NULL, NULL, 1, 1000, 0, NULL},
        {"pb", "background pressure of the equation of state", &P.pb, NULL, NULL, NULL, -1e6, 1e6, 0, NULL},
        {"perturb", "start: lattice moved by up to this fraction of dx", &P.perturb, NULL, NULL, NULL, 0, 0.5, 0, NULL},
        {"out", "output directory (VTK frames, energy.csv; rank 0 writes)", NULL, NULL, &out, NULL, 0, 0, 0, NULL},
        {"frames", "VTK frames: the start and this many more to the end (0: none)", NULL, &P.frames, NULL, NULL, 0,
         10000, 0, NULL},
        {"threads", "OpenMP threads per rank (0: the runtime's default)", NULL, &threads, NULL, NULL, 0, 4096, 0, NULL},
        {"check", "fixed, moving and plain runs on these ranks against one process; exit 1 unless bitwise equal", NULL,
         NULL, NULL, &check, 0, 0, 0, NULL},
        {"lagrangian", "particles move with the flow, transport-velocity formulation", NULL, NULL, NULL, &P.lagrangian, 0,
         0, 0, NULL},
        {"pt", "background pressure of the transport velocity (-1: rho0 c0^2)", &P.pt, NULL, NULL, NULL, -1, 1e9, 0,
         NULL},
        {"plain", "with --lagrangian: standard WCSPH (continuity, no transport velocity)", NULL, NULL, NULL, &P.plain, 0,
         0, 0, NULL},
        {"shift", "with --plain: particle shifting D (0: off)", &P.shift, NULL, NULL, NULL, 0, 1, 0, NULL},
        {"cfl", "time step dt = cfl h / (c0 + U)", &P.cfl, NULL, NULL, NULL, 0, 1, EX_OPEN_LO, NULL},
        {"steps", "stop after this many steps of the t-end's dt (0: run to t-end)", NULL, &P.steps, NULL, NULL, 0, 1e9,
         0, NULL},
        {"compare", "also run on one process (rank 0) and print the differences", NULL, NULL, NULL, &compare, 0, 0, 0,
         NULL},
        {"bound", "--compare: largest relative difference accepted (0: bitwise)", &bound, NULL, NULL, NULL, 0, 1, 0, NULL},
        {"unordered", "sum each target's neighbours in the search's order (locals, then halos): equal to one process to "
                      "round-off only", NULL, NULL, NULL, &P.unordered, 0, 0, 0, NULL},
    };
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    P.n = 40, P.kernel = "wendland_c2", P.scheme = "pressure", P.hdx = 0, P.t_end = 1, P.re = 100, P.c0 = 10;
    P.pb = 0, P.pt = -1, P.perturb = 0, P.frames = 10, P.shift = 0.05, P.lagrangian = 0, P.plain = 0, P.cfl = 0.25;
    P.steps = 0, P.unordered = 0;
    { /* every rank parses; only rank 0 prints the help or a refusal */
        int saved_out = -1, saved_err = -1, nul = rank != 0 ? open("/dev/null", O_WRONLY) : -1;
        if (nul >= 0) {
            fflush(stdout), fflush(stderr);
            saved_out = dup(1), saved_err = dup(2);
            dup2(nul, 1), dup2(nul, 2), close(nul);
        }
        st = ex_parse_args(argc, argv, "2-D Taylor-Green vortex (taylor_green.c) over MPI ranks, slab decomposition; "
                           MTG_BOUNDS, opt, (int)(sizeof opt / sizeof opt[0]));
        if (saved_out >= 0) fflush(stdout), dup2(saved_out, 1), close(saved_out);
        if (saved_err >= 0) fflush(stderr), dup2(saved_err, 2), close(saved_err);
    }
    if (st != 0) {
        MPI_Finalize();
        return st > 0 ? 0 : 2;
    }
    if (P.hdx == 0) P.hdx = P.lagrangian && !P.plain ? 2.0 : 1.3;
    if (sph_kernel_support((sph_kernel)sph_kernel_from_name(P.kernel)) * P.hdx / P.n >= 0.5) {
        if (rank == 0)
            fprintf(stderr, "mpi_taylor_green: the support kappa h = %g exceeds half the box: raise --n or lower --hdx\n",
                    sph_kernel_support((sph_kernel)sph_kernel_from_name(P.kernel)) * P.hdx / P.n);
        bad = 1;
    }
    if (!bad && (long)P.n < (long)size) {
        if (rank == 0) fprintf(stderr, "mpi_taylor_green: %d ranks need --n of at least %d\n", size, size);
        bad = 1;
    }
    if (bad) {
        MPI_Finalize();
        return 2;
    }
#ifdef _OPENMP
    if (threads > 0) omp_set_num_threads(threads);
#else
    (void)threads;
#endif
    if (check) { /* 24^2: fixed, moving (transport velocity), moving plain + shifting; 60 steps each */
        static const int motion[3] = {0, 1, 2};
        int m;
        for (m = 0; m < 3; ++m) {
            mtg_param C = P;
            C.n = 24, C.frames = 0, C.steps = 60, C.t_end = 1, C.perturb = m == 0 ? 0.2 : 0;
            C.lagrangian = motion[m] > 0, C.plain = motion[m] == 2, C.hdx = motion[m] == 1 ? 2.0 : 1.3;
            C.scheme = m == 0 ? "corrected" : "pressure";
            st = mtg_compare(&C, m == 0 ? "--check fixed (perturbed, corrected)"
                                 : m == 1 ? "--check moving (transport velocity)"
                                          : "--check moving (plain + shifting)",
                             0, motion[m] > 0);
            bad |= st != 0;
        }
        if (rank == 0) printf("mpi_taylor_green --check on %d ranks: %s\n", size, bad ? "FAIL" : "pass");
        MPI_Finalize();
        return bad ? 1 : 0;
    }
    if (compare) {
        st = mtg_compare(&P, "--compare", bound, 0);
        MPI_Finalize();
        return st == 0 ? 0 : 1;
    }
    {
        char path[1100];
        FILE *csv = NULL;
        ex_series frames;
        int ok = rank != 0 || ex_series_open(&frames, out, "taylor_green", 0) == 0;
        MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
        if (!ok) {
            if (rank == 0) fprintf(stderr, "mpi_taylor_green: cannot create %s\n", out);
            MPI_Finalize();
            return 2;
        }
        if (rank == 0) {
            snprintf(path, sizeof path, "%s/energy.csv", out);
            if ((csv = fopen(path, "w")) != NULL) fprintf(csv, "t,E/E0,exact E/E0,L2 velocity error\n");
        }
        st = mtg_run(MPI_COMM_WORLD, &P, &R, csv, &frames, 0, NULL);
        if (csv != NULL) fclose(csv);
        if (rank == 0) {
            if (st == SPH_OK) ex_series_report(&frames);
            ex_series_close(&frames);
        }
    }
    if (rank == 0) {
        if (st != SPH_OK) {
            fprintf(stderr, "mpi_taylor_green: run failed: %s\n", ex_strerror(st));
        } else {
            const int nth =
#ifdef _OPENMP
                omp_get_max_threads();
#else
                1;
#endif
            printf("n %3d  %-12s %-10s %s  steps %5ld  E(t)/E0 %.5f  decay rate %.4f (exact %.4f, error %+.2f %%)  "
                   "L2 velocity error %.4f  largest CFL number %.3f\n",
                   P.n, P.kernel, P.scheme, P.lagrangian ? (P.plain ? "moving plain" : "moving tvf") : "fixed",
                   R.steps, R.e_ratio, R.rate_fit, R.rate_exact, 100 * (R.rate_fit - R.rate_exact) / R.rate_exact,
                   R.l2, R.cfl_max);
            printf("ranks %d  threads %d  particles %.0f  per rank max %.0f  halo %.0f (%.1f %% of the locals, max %.0f "
                   "per rank)  migrations %ld  sent %.3g MB/step\n",
                   size, nth, R.local_sum, R.local_max, R.halo_sum, 100 * R.halo_sum / R.local_sum, R.halo_max,
                   R.migrated, R.bytes_sent / 1e6 / (double)(R.steps > 0 ? R.steps : 1));
            printf("time %.3f s  exchange %.3f s (%.1f %%)  compute %.3f s  per step %.3g ms\n", R.t_total, R.t_exchange,
                   100 * R.t_exchange / R.t_total, R.t_compute, 1e3 * R.t_total / (double)(R.steps > 0 ? R.steps : 1));
            printf("scaling: ranks %d threads %d particles %.0f halo %.0f steps %ld total %.6f exchange %.6f compute %.6f\n",
                   size, nth, R.local_sum, R.halo_sum, R.steps, R.t_total, R.t_exchange, R.t_compute);
            if (R.fallbacks > 0) printf("note: %ld corrected-scheme fallbacks\n", R.fallbacks);
            printf("wrote %s/energy.csv\n", out);
        }
    }
    MPI_Finalize();
    return st == SPH_OK ? 0 : 1;
}
