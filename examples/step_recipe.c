/* examples/step_recipe.c - the adaptive-h step of docs/step.md, in order, on
 * a small periodic gas in 1-D, 2-D or 3-D: kept lists while they serve,
 * search, h solve, re-search of the particles beyond their lists, prune,
 * then one loop over each particle's pairs in batches with the grad-h
 * pressure terms (H5), (H6), the signal-velocity artificial viscosity (S3),
 * (S4) and div v, then the time step (S9), (S10) and the kick-drift-kick
 * update. Every particle has the same mass: one real, read through a view
 * of stride 0.
 *
 * The scene: particles on a lattice of n1 per unit length in the periodic
 * unit box, squeezed along x (density 0.77 to 1.43 of the mean) and jittered
 * by 5 % of the spacing, a converging velocity v_x = -0.2 c sin(2 pi x), an
 * ideal gas with gamma = 5/3 and u = 1.
 *
 *   ./step_recipe                       3-D, 10^3 particles, 20 steps
 *   ./step_recipe --dim 2 --n1 64       2-D, 64^2 particles
 *   ./step_recipe --forces library      (H5), (H6) by sph_gradh_forces, the viscosity in a second loop
 *   ./step_recipe --check               1-D, 2-D and 3-D runs with the bounds below; exit 1 when one is missed
 *   ./step_recipe --profile             the wall time of each part of the step per particle
 *
 * --check asserts, at every force evaluation, that (H1) holds for every
 * particle to 4 d tol, that the pair terms conserve momentum and total
 * energy to round-off (sum m a and sum m (v . a + du/dt) against the sums of
 * their magnitudes) and, at the first, that the batch loop equals
 * sph_gradh_forces with the viscosity added; over the run, that the total
 * momentum stays at round-off and the total energy within the
 * time-stepping error.
 */
#include "example_io.h"

#include <math.h>

#if defined(__GNUC__) || defined(__clang__)
#define SR_INLINE static inline __attribute__((always_inline))
#else
#define SR_INLINE static inline
#endif
#define SR_NT 5 /* sums per particle of the force loop: dv/dt (3), du/dt, div v before its factor */

typedef struct {
    int dim, n1, steps, library, profile;
    double neighbours, alpha, beta, cfl, skin;
    const char *kernel;
} sr_param;

typedef struct {
    sr_param P;
    sph_kernel k;
    sph_real kappa, eta, m, gamma; /* m: the mass of every particle */
    sph_idx n;
    sph_box box;
    sph_real *x, *v, *vp, *a, *u, *up, *du, *h, *rho, *om, *A, *cs, *vsig, *divv, *hl, *hkeep, *x0;
    int *state;
    void *work; /* the search's workspace */
    size_t work_bytes;
    sph_off *offset, *p_off, cap; /* kept list (searched at kappa hl from x0) and its pruned copy: cap entries each */
    sph_idx *index, *p_idx;
    sph_neighbours kept, pairs;
    sph_nsearch grid;
    long searches, researches;
    double t_part[4]; /* --profile: steps 1-5, 6-7, the whole steps, sph_gradh_forces in 6-7 (--forces library) */
} sr_sim;

static void sr_free(sr_sim *S)
{
    free(S->x), free(S->v), free(S->vp), free(S->a), free(S->u), free(S->up), free(S->du), free(S->h);
    free(S->rho), free(S->om), free(S->A), free(S->cs), free(S->vsig), free(S->divv), free(S->hl), free(S->hkeep);
    free(S->x0), free(S->state), free(S->work), free(S->offset), free(S->p_off), free(S->index), free(S->p_idx);
}

/* A number in [0, 1) from an integer (a hash: the same scene on every machine). */
static double sr_hash(unsigned long i)
{
    i = (i ^ 61) ^ (i >> 16), i *= 9, i ^= i >> 4, i *= 0x27d4eb2dUL, i ^= i >> 15;
    return (double)(i & 0xffffffUL) / 16777216.0;
}

/* The scene of the top comment; 0, or -1 when out of memory. */
static int sr_setup(sr_sim *S)
{
    const double pi = 3.14159265358979323846, dx = 1.0 / S->P.n1;
    sph_idx i, n = 1;
    int a;
    for (a = 0; a < S->P.dim; ++a) n *= S->P.n1;
    S->n = n;
    S->m = (sph_real)(1.0 / (double)n); /* mean density 1 */
    S->gamma = (sph_real)(5.0 / 3.0);
    for (a = 0; a < 3; ++a) S->box.lo[a] = 0, S->box.length[a] = 1, S->box.periodic[a] = a < S->P.dim;
#define SR_A(f, c) ((S->f = (sph_real *)ex_calloc((size_t)n * (c), sizeof(sph_real), #f)) == NULL)
    if (SR_A(x, 3) || SR_A(v, 3) || SR_A(vp, 3) || SR_A(a, 3) || SR_A(u, 1) || SR_A(up, 1) || SR_A(du, 1) ||
        SR_A(h, 1) || SR_A(rho, 1) || SR_A(om, 1) || SR_A(A, 1) || SR_A(cs, 1) || SR_A(vsig, 1) || SR_A(divv, 1) ||
        SR_A(hl, 1) || SR_A(hkeep, 1) || SR_A(x0, 3))
        return -1;
#undef SR_A
    if ((S->state = (int *)ex_calloc((size_t)n, sizeof(int), "state")) == NULL ||
        (S->offset = (sph_off *)ex_calloc((size_t)n + 1, sizeof(sph_off), "offset")) == NULL ||
        (S->p_off = (sph_off *)ex_calloc((size_t)n + 1, sizeof(sph_off), "p_off")) == NULL)
        return -1;
    for (i = 0; i < n; ++i) {
        sph_idx c = i;
        for (a = 0; a < S->P.dim; ++a, c /= S->P.n1) {
            double q = ((double)(c % S->P.n1) + 0.5 + 0.1 * (sr_hash(3 * (unsigned long)i + (unsigned long)a) - 0.5)) * dx;
            if (a == 0) q += 0.3 * sin(2 * pi * q) / (2 * pi); /* squeezed along x: rho = 1 / (1 + 0.3 cos 2 pi x) */
            S->x[3 * i + a] = (sph_real)(q - floor(q));
        }
        S->u[i] = 1;
        S->v[3 * i] = (sph_real)(-0.2 * sqrt((5.0 / 3.0) * (2.0 / 3.0)) * sin(2 * pi * (double)S->x[3 * i]));
        S->h[i] = S->eta * (sph_real)pow((double)S->m, 1.0 / S->P.dim); /* the guess: the mean density */
    }
    memcpy(S->vp, S->v, sizeof(sph_real) * 3 * (size_t)n);
    memcpy(S->up, S->u, sizeof(sph_real) * (size_t)n);
    return 0;
}

/* 2. Search: symmetric lists (N2) at radii kappa hl_i into S->kept, from the positions x0 = x; until the particles
 * move, the radii the lists serve (hkeep) are hl. Arrays too short are grown, with a quarter to spare. */
static int sr_search(sr_sim *S)
{
    const sph_view xv = sph_view_interleaved(S->x, 3), hv = sph_view_soa(S->hl, NULL, NULL);
    sph_real cell = 0;
    sph_off pairs = 0;
    size_t bytes;
    sph_idx i;
    int st;
    memcpy(S->x0, S->x, sizeof(sph_real) * 3 * (size_t)S->n);
    memcpy(S->hkeep, S->hl, sizeof(sph_real) * (size_t)S->n);
    for (i = 0; i < S->n; ++i) cell = S->kappa * S->hl[i] / 2 > cell ? S->kappa * S->hl[i] / 2 : cell;
    if ((st = sph_nsearch_workspace_size(S->P.dim, xv, S->n, hv, cell, &S->box, &bytes)) != SPH_OK) return st;
    if (bytes > S->work_bytes) {
        free(S->work);
        S->work_bytes = (S->work = ex_calloc(bytes, 1, "search workspace")) != NULL ? bytes : 0;
        if (S->work == NULL) return EX_ENOMEM;
    }
    st = sph_nsearch_build(&S->grid, S->P.dim, xv, S->n, hv, cell, &S->box, S->work, S->work_bytes);
    while (st == SPH_OK && (st = sph_nsearch_lists(&S->grid, xv, S->n, hv, 0, S->kappa, SPH_NSEARCH_SYMMETRIC,
                                                   S->offset, S->index, S->cap, &pairs)) == SPH_ESIZE) {
        free(S->index), free(S->p_idx); /* pairs: what the lists need */
        S->cap = pairs + pairs / 4 + 1;
        S->index = (sph_idx *)ex_calloc((size_t)S->cap, sizeof(sph_idx), "index");
        S->p_idx = (sph_idx *)ex_calloc((size_t)S->cap, sizeof(sph_idx), "p_idx");
        st = S->index != NULL && S->p_idx != NULL ? SPH_OK : (S->cap = 0, EX_ENOMEM);
    }
    S->kept = sph_nsearch_list(&S->grid, S->n, S->offset, S->index);
    S->searches++;
    return st;
}

/* snippet: density */
/* Steps 1-5: h, rho and Omega of every particle from the guess in S->h, and S->pairs, the pairs within
 * kappa max(h_i, h_j) that the force loop visits. */
static int sr_density(sr_sim *S)
{
    const sph_real grow = (sph_real)(1 + S->P.skin);
    const sph_view xv = sph_view_interleaved(S->x, 3);
    sph_idx i, stale = 1;
    sph_hreport rep;
    sph_hctx c;
    sph_off pairs;
    int round, st;
    if (S->searches > 0) { /* 1. does the kept list still hold every pair within kappa h? (N8) */
        st = sph_nsearch_skin(&S->kept, NULL, S->P.dim, xv, sph_view_interleaved(S->x0, 3),
                              sph_view_soa(S->hl, NULL, NULL), S->kappa, sph_view_soa(S->h, NULL, NULL),
                              sph_out_soa(S->hkeep, NULL, NULL), &stale);
        if (st != SPH_OK) return st;
    }
    if (stale > 0) { /* 2. no: search at (1 + skin) h */
        for (i = 0; i < S->n; ++i) S->hl[i] = grow * S->h[i];
        if ((st = sr_search(S)) != SPH_OK) return st;
    }
    for (round = 0; round < 5; ++round) {
        /* 3. h and rho together (H1)-(H4) over the kept list, within the radii it still serves */
        c = sph_hctx_init(S->k, S->P.dim, &S->kept, xv, sph_view_aos(&S->m, 1, 0), 0); /* stride 0: one mass */
        c.eta = S->eta;
        c.h_list = sph_view_soa(S->hkeep, NULL, NULL);
        c.check_list = 0; /* the search's lists */
        st = sph_h_solve(&c, sph_out_soa(S->h, NULL, NULL), sph_out_soa(S->rho, NULL, NULL),
                         sph_out_soa(S->om, NULL, NULL), NULL, S->state, &rep);
        if (st != SPH_OK) return st;
        if (rep.n_not_converged > 0) return SPH_ERANGE;
        if (rep.n_beyond_list == 0) /* 5. prune: the pairs within kappa max(h_i, h_j), as a fresh search */
            return sph_nsearch_prune(&S->kept, NULL, S->P.dim, xv, sph_view_soa(S->h, NULL, NULL), S->kappa,
                                     SPH_NSEARCH_SYMMETRIC, S->p_off, S->p_idx, S->cap, &pairs, &S->pairs);
        /* 4. h of some particle lies beyond its list: h holds its estimate; search again, wider there */
        for (i = 0; i < S->n; ++i)
            if (S->state[i] == SPH_H_BEYOND_LIST) S->hl[i] = grow * S->h[i];
        if ((st = sr_search(S)) != SPH_OK) return st;
        S->researches++;
    }
    return SPH_ERANGE;
}
/* end snippet */

/* snippet: batch */
/* Step 7, the pair terms of particle i from batch b of its row, added to acc[SR_NT]: dv/dt, du/dt and
 * sum_j m_j v_ij . x_ij F_i (div v); the largest signal velocity of the pairs into *vs. F_i = F(r, h_i) and
 * F_j = F(r, h_j): the pressure terms take each side's own width, the viscosity their mean. pressure 0
 * leaves out (H5), (H6) (--forces library: sph_gradh_forces has them). */
SR_INLINE void sr_batch(const sr_sim *S, sph_idx i, const sph_batch *b, int pressure, sph_real *vs, sph_real *acc)
{
    const sph_real m = S->m, alpha = (sph_real)S->P.alpha, beta = (sph_real)S->P.beta, kp = pressure ? 1 : 0;
    const sph_real Ai = S->A[i], ci = S->cs[i], rhoi = S->rho[i], *vi = S->vp + 3 * i;
    sph_real vj[3][SPH_BATCH], Aj[SPH_BATCH], cj[SPH_BATCH], rhoj[SPH_BATCH]; /* the partners' fields, in lanes */
    sph_real t[SR_NT][SPH_BATCH], vsig[SPH_BATCH], vmax = *vs;
    int l, a;
    for (l = 0; l < SPH_BATCH; ++l) { /* padding lanes: j = i, x_ij = 0, F = 0: every term 0 */
        const sph_idx j = b->j[l];
        for (a = 0; a < 3; ++a) vj[a][l] = S->vp[3 * j + a];
        Aj[l] = S->A[j], cj[l] = S->cs[j], rhoj[l] = S->rho[j];
    }
    for (l = 0; l < SPH_BATCH; ++l) { /* the arithmetic alone: the compiler vectorises it */
        const sph_real dx = b->dx[0][l], dy = b->dx[1][l], dz = b->dx[2][l], r = b->r[l], Fi = b->F_i[l], Fj = b->F_j[l];
        const sph_real e = (vi[0] - vj[0][l]) * dx + (vi[1] - vj[1][l]) * dy + (vi[2] - vj[2][l]) * dz; /* v_ij . x_ij */
        const sph_real w = (e < 0 ? e : 0) / (r > 0 ? r : 1);         /* (S2) w_ij */
        const sph_real v_sig = ci + cj[l] - beta * w;                 /* (S2) */
        const sph_real Pi = -alpha / 2 * v_sig * w / ((rhoi + rhoj[l]) / 2); /* (S3) */
        const sph_real cav = m * Pi * (Fi + Fj) / 2;                  /* (S4) at the mean of F_i, F_j */
        const sph_real cp = kp * m * (Ai * Fi + Aj[l] * Fj) + cav;    /* (H5) + (S4): dv_i/dt = -cp x_ij */
        t[0][l] = -cp * dx, t[1][l] = -cp * dy, t[2][l] = -cp * dz;
        t[3][l] = kp * m * Ai * Fi * e + cav * e / 2;                 /* (H6) at F_i + (S4) */
        t[4][l] = m * e * Fi;                                         /* div v_i = -t[4] / (Omega_i rho_i) */
        vsig[l] = b->j[l] != i ? v_sig : 0;
    }
    for (a = 0; a < SR_NT; ++a) {
        sph_real sum = 0;
        for (l = 0; l < SPH_BATCH; ++l) sum += t[a][l];
        acc[a] += sum;
    }
    for (l = 0; l < SPH_BATCH; ++l) vmax = vsig[l] > vmax ? vsig[l] : vmax;
    *vs = vmax;
}
/* end snippet */

/* (H5), (H6) into a and du by the library's gather loop (--forces library), timed for --profile. */
static int sr_gradh_library(sr_sim *S)
{
    sph_hctx c = sph_hctx_init(S->k, S->P.dim, &S->pairs, sph_view_interleaved(S->x, 3), sph_view_aos(&S->m, 1, 0), 0);
    const double t0 = ex_now();
    int st;
    c.check_list = 0;
    st = sph_gradh_forces(&c, sph_view_interleaved(S->vp, 3), sph_view_soa(S->h, NULL, NULL), sph_view_soa(S->A, NULL, NULL),
                          sph_out_interleaved(S->a, 3), sph_out_soa(S->du, NULL, NULL));
    S->t_part[3] += ex_now() - t0;
    return st;
}

/* snippet: forces */
/* Steps 6-7: dv/dt, du/dt, div v and the signal velocity of every particle at the positions x, velocities vp and
 * energies up, from h, rho and Omega of sr_density. Each particle sums its own row of the pruned list: every pair
 * is evaluated from both ends, its terms antisymmetric, so momentum and energy are conserved to round-off.
 * library 1: the slower way, (H5) and (H6) by sph_gradh_forces and the viscosity in the loop. */
static int sr_pair_forces(sr_sim *S, int library)
{
    sph_batch_src B;
    sph_idx i;
    int st;
    for (i = 0; i < S->n; ++i) { /* 6. pressure, sound speed, A = P / (Omega rho^2) of (H5) */
        const sph_real p = (S->gamma - 1) * S->rho[i] * S->up[i];
        S->cs[i] = (sph_real)sqrt((double)(S->gamma * p / S->rho[i]));
        S->A[i] = sph_gradh_factor(p, S->rho[i], S->om[i]);
    }
    if (library && (st = sr_gradh_library(S)) != SPH_OK) return st;
    st = sph_batch_source(&B, S->k, S->P.dim, &S->pairs, NULL, sph_view_interleaved(S->x, 3), sph_view_soa(S->h, NULL, NULL));
    if (st != SPH_OK || (st = sph_batch_select(&B, SPH_BATCH_F)) != SPH_OK) return st; /* F alone: no W */
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 64)
#endif
    for (i = 0; i < S->n; ++i) { /* 7. one loop: each particle its row, SPH_BATCH pairs at a time */
        sph_real acc[SR_NT] = {0, 0, 0, 0, 0}, vs = 0;
        sph_off next = 0;
        sph_batch b;
        int a;
        while (sph_batch_fill(&B, i, &next, &b) > 0) sr_batch(S, i, &b, !library, &vs, acc);
        for (a = 0; a < 3; ++a) S->a[3 * i + a] = library ? S->a[3 * i + a] + acc[a] : acc[a];
        S->du[i] = library ? S->du[i] + acc[3] : acc[3];
        S->divv[i] = -acc[4] / (S->om[i] * S->rho[i]); /* Price (2012) */
        S->vsig[i] = vs;
    }
    return SPH_OK;
}
/* end snippet */

/* Steps 1-7, timed for --profile. */
static int sr_forces(sr_sim *S)
{
    double t0 = ex_now();
    int st = sr_density(S);
    S->t_part[0] += ex_now() - t0, t0 = ex_now();
    if (st == SPH_OK) st = sr_pair_forces(S, S->P.library);
    S->t_part[1] += ex_now() - t0;
    return st;
}

/* snippet: step */
/* Steps 8-9: the time step from the rates of the last evaluation, then kick, drift, forces, kick. */
static int sr_step(sr_sim *S, double *dt_out)
{
    sph_dt_input in = sph_dt_input_init(0);
    sph_real dt;
    sph_idx i;
    int a, st;
    in.h_particle = sph_view_soa(S->h, NULL, NULL);
    in.vsig = sph_view_soa(S->vsig, NULL, NULL); /* the pair signal velocity (S2): C_cfl 0.5 */
    in.coef.cfl = (sph_real)S->P.cfl;
    in.acc = sph_view_interleaved(S->a, 3);
    if ((st = sph_time_step(&in, S->P.dim, S->n, &dt, NULL, NULL)) != SPH_OK) return st;
    for (i = 0; i < S->n; ++i) { /* kick, drift (wrapped into the box), and the state the forces see */
        for (a = 0; a < S->P.dim; ++a) {
            S->v[3 * i + a] += dt / 2 * S->a[3 * i + a];
            S->x[3 * i + a] += dt * S->v[3 * i + a];
            S->x[3 * i + a] -= floor(S->x[3 * i + a]);
            S->vp[3 * i + a] = S->v[3 * i + a] + dt / 2 * S->a[3 * i + a];
        }
        S->u[i] += dt / 2 * S->du[i];
        S->up[i] = S->u[i] + dt / 2 * S->du[i];
        S->h[i] *= 1 + dt / (sph_real)S->P.dim * S->divv[i]; /* the h solve's guess: dh/dt = (h / d) div v, from (H1) */
    }
    if ((st = sr_forces(S)) != SPH_OK) return st;
    for (i = 0; i < S->n; ++i) { /* kick */
        for (a = 0; a < S->P.dim; ++a) S->v[3 * i + a] += dt / 2 * S->a[3 * i + a];
        S->u[i] += dt / 2 * S->du[i];
    }
    *dt_out = (double)dt;
    return SPH_OK;
}
/* end snippet */

/* --check's measures of the last evaluation: the largest (H1) residual |m (eta / h)^d - rho| / rho, and the
 * momentum and energy rates against the sums of their magnitudes. */
static void sr_rates(const sr_sim *S, double *h1, double *mom, double *en)
{
    double p[3] = {0, 0, 0}, pabs = 0, e = 0, eabs = 0;
    sph_idx i;
    int a;
    *h1 = 0;
    for (i = 0; i < S->n; ++i) {
        const double r = fabs((double)S->m * pow((double)S->eta / (double)S->h[i], S->P.dim) - (double)S->rho[i]) / (double)S->rho[i];
        *h1 = r > *h1 ? r : *h1;
        for (a = 0; a < 3; ++a) {
            const double ma = (double)S->m * (double)S->a[3 * i + a], w = ma * (double)S->vp[3 * i + a];
            p[a] += ma, pabs += fabs(ma), e += w, eabs += fabs(w);
        }
        e += (double)S->m * (double)S->du[i], eabs += fabs((double)S->m * (double)S->du[i]);
    }
    *mom = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) / pabs;
    *en = fabs(e) / eabs;
}

/* Total momentum p[3], the sum of m |v| and the total energy. */
static void sr_totals(const sr_sim *S, double *p, double *mabs, double *E)
{
    sph_idx i;
    int a;
    p[0] = p[1] = p[2] = *mabs = *E = 0;
    for (i = 0; i < S->n; ++i) {
        double v2 = 0;
        for (a = 0; a < 3; ++a) {
            const double v = (double)S->v[3 * i + a];
            p[a] += (double)S->m * v, *mabs += (double)S->m * fabs(v), v2 += v * v;
        }
        *E += (double)S->m * (v2 / 2 + (double)S->u[i]);
    }
}

typedef struct {
    double h1, mom_rate, en_rate, route, mom, energy; /* --check's measures: the largest over the run */
    double eta, t, seconds, part[4];
    long steps, searches, researches;
    sph_idx n;
} sr_result;

/* Largest |a - b| over n values, against the largest |a|. */
static double sr_rel_diff(const sph_real *a, const sph_real *b, sph_idx n)
{
    double d = 0, top = 0;
    sph_idx k;
    for (k = 0; k < n; ++k) {
        d = fmax(d, fabs((double)a[k] - (double)b[k]));
        top = fmax(top, fabs((double)a[k]));
    }
    return top > 0 ? d / top : d;
}

/* One run of P; the measures of --check into R. */
static int sr_run(const sr_param *P, sr_result *R)
{
    sr_sim S;
    double p0[3], p[3], mabs, E0, E, dt;
    sph_real *a0 = NULL, *du0 = NULL;
    int st, k;
    memset(&S, 0, sizeof S);
    memset(R, 0, sizeof *R);
    S.P = *P;
    S.k = (sph_kernel)sph_kernel_from_name(P->kernel);
    S.kappa = sph_kernel_support(S.k);
    S.eta = sph_kernel_h_for_neighbours(S.k, P->dim, (sph_real)P->neighbours, 1); /* h in units of (m / rho)^(1/d) */
    R->seconds = ex_now();
    if (sr_setup(&S) != 0) return sr_free(&S), EX_ENOMEM;
    R->n = S.n, R->eta = (double)S.eta;
    st = sr_forces(&S);
    if (st == SPH_OK) { /* the other route to the same forces */
        a0 = (sph_real *)ex_calloc((size_t)S.n * 3, sizeof(sph_real), "a0");
        du0 = (sph_real *)ex_calloc((size_t)S.n, sizeof(sph_real), "du0");
        if (a0 == NULL || du0 == NULL) st = EX_ENOMEM;
    }
    if (st == SPH_OK) {
        memcpy(a0, S.a, sizeof(sph_real) * 3 * (size_t)S.n), memcpy(du0, S.du, sizeof(sph_real) * (size_t)S.n);
        st = sr_pair_forces(&S, !P->library);
        R->route = fmax(sr_rel_diff(a0, S.a, 3 * S.n), sr_rel_diff(du0, S.du, S.n));
        memcpy(S.a, a0, sizeof(sph_real) * 3 * (size_t)S.n), memcpy(S.du, du0, sizeof(sph_real) * (size_t)S.n);
    }
    free(a0), free(du0);
    sr_totals(&S, p0, &mabs, &E0);
    memset(S.t_part, 0, sizeof S.t_part); /* --profile times the steps, not the start */
    for (k = 0; st == SPH_OK && k <= P->steps; ++k) {
        double h1, mom, en, t0;
        sr_rates(&S, &h1, &mom, &en);
        R->h1 = fmax(R->h1, h1), R->mom_rate = fmax(R->mom_rate, mom), R->en_rate = fmax(R->en_rate, en);
        t0 = ex_now();
        if (k < P->steps && (st = sr_step(&S, &dt)) == SPH_OK) R->t += dt, R->steps++;
        S.t_part[2] += ex_now() - t0;
    }
    sr_totals(&S, p, &mabs, &E);
    R->mom = sqrt((p[0] - p0[0]) * (p[0] - p0[0]) + (p[1] - p0[1]) * (p[1] - p0[1]) + (p[2] - p0[2]) * (p[2] - p0[2])) / mabs;
    R->energy = fabs(E - E0) / E0;
    R->searches = S.searches, R->researches = S.researches;
    for (k = 0; k < 4; ++k) R->part[k] = S.t_part[k];
    R->seconds = ex_now() - R->seconds;
    sr_free(&S);
    return st;
}

/* A failed run's status as the option that caused it. */
static void sr_explain(const sr_param *P, int st)
{
    if (st == SPH_EPERIOD)
        fprintf(stderr, "%s: --n1 %d is too small for --neighbours %g in %d-D: the search radius exceeds half the box; "
                "raise --n1\n", ex_prog(), P->n1, P->neighbours, P->dim);
    else if (st == SPH_ERANGE)
        fprintf(stderr, "%s: --neighbours %g: no smoothing length solves (H1) for --kernel %s in %d-D (too few "
                "neighbours: the particle's own term exceeds the density), or it did not converge\n", ex_prog(),
                P->neighbours, P->kernel, P->dim);
    else if (st != EX_ENOMEM)
        fprintf(stderr, "%s: %s\n", ex_prog(), ex_strerror(st));
}

static void sr_print(const sr_param *P, const sr_result *R)
{
    printf("%d-D, %ld particles, %s, eta %.4f (%g neighbours), forces: %s; %ld steps to t = %.4f, %ld searches "
           "(%ld re-searches), %.2f s\n", P->dim, (long)R->n, P->kernel, R->eta, P->neighbours,
           P->library ? "sph_gradh_forces + viscosity loop" : "one batch loop", R->steps, R->t, R->searches,
           R->researches, R->seconds);
    if (P->profile && R->steps > 0) {
        const double ps = 1e6 / ((double)R->n * (double)R->steps);
        printf("  per particle and step: lists and h (steps 1-5) %.3f us, forces (6-7) %.3f us",
               R->part[0] * ps, R->part[1] * ps);
        if (P->library) printf(" (sph_gradh_forces %.3f us of it)", R->part[3] * ps);
        printf(", time step and update (8-9) %.3f us\n", (R->part[2] - R->part[0] - R->part[1]) * ps);
    }
}

int main(int argc, char **argv)
{
    static const double usual[4] = {0, 5, 18, 58}; /* neighbours: the cubic spline's eta 1.2 in 1-D, 2-D, 3-D */
    static const int n1_default[4] = {0, 100, 32, 10}, n1_check[4] = {0, 64, 24, 9};
    sr_param P;
    sr_result R;
    const char *forces = "batch";
    int check = 0, st, d;
    const ex_arg opt[] = {
        {"dim", "dimension", NULL, &P.dim, NULL, NULL, 1, 3, 0, NULL},
        {"n1", "particles per unit length (0: 100, 32, 10 in 1-D, 2-D, 3-D); n1^dim particles", NULL, &P.n1, NULL,
         NULL, 8, 4096, EX_OR_ZERO, NULL},
        {"steps", "time steps", NULL, &P.steps, NULL, NULL, 0, 100000, 0, NULL},
        {"kernel", "smoothing kernel", NULL, NULL, &P.kernel, NULL, 0, 0, 0, ex_kernel_choices()},
        {"neighbours", "neighbours in the support, eta = sph_kernel_h_for_neighbours(k, dim, N, 1) (0: 5, 18, 58 in "
         "1-D, 2-D, 3-D)", &P.neighbours, NULL, NULL, NULL, 2, 1000, EX_OR_ZERO, NULL},
        {"alpha", "artificial viscosity alpha of (S3)", &P.alpha, NULL, NULL, NULL, 0, 4, 0, NULL},
        {"beta", "artificial viscosity beta of (S2), (S3)", &P.beta, NULL, NULL, NULL, 0, 8, 0, NULL},
        {"cfl", "C_cfl of (S9) on the pair signal velocity (S2)", &P.cfl, NULL, NULL, NULL, 0, 1, EX_OPEN_LO, NULL},
        {"skin", "lists at kappa (1 + skin) h, kept while they serve every h", &P.skin, NULL, NULL, NULL, 0, 1, 0, NULL},
        {"forces", "batch: one loop of every pair term; library: (H5), (H6) by sph_gradh_forces, then a loop for "
         "the viscosity", NULL, NULL, &forces, NULL, 0, 0, 0, "batch|library"},
        {"profile", "print the time per particle of the step's parts", NULL, NULL, NULL, &P.profile, 0, 0, 0, NULL},
        {"check", "1-D, 2-D and 3-D runs of 10 steps; exit 1 when a bound is missed", NULL, NULL, NULL, &check, 0, 0, 0,
         NULL},
    };
    P.dim = 3, P.n1 = 0, P.steps = 20, P.kernel = "cubic", P.neighbours = 0, P.alpha = 1, P.beta = 3, P.cfl = 0.5;
    P.skin = 0.1, P.profile = 0;
    st = ex_parse_args(argc, argv, "the adaptive-h step of docs/step.md on a small periodic gas", opt,
                       (int)(sizeof opt / sizeof opt[0]));
    if (st != 0) return st > 0 ? 0 : 2;
    P.library = strcmp(forces, "library") == 0;
    if (!check) {
        if (P.n1 == 0) P.n1 = n1_default[P.dim];
        if (P.neighbours == 0) P.neighbours = usual[P.dim];
        if (pow(P.n1, P.dim) > 16777216) {
            fprintf(stderr, "%s: --n1 %d refused: accepted n1^dim <= 16777216 particles (--dim %d)\n", ex_prog(), P.n1,
                    P.dim);
            return 2;
        }
        if ((st = sr_run(&P, &R)) != SPH_OK) {
            sr_explain(&P, st);
            return 1;
        }
        sr_print(&P, &R);
        printf("  batch loop against the other route at the start %.1e; momentum %.1e of sum m |v|, energy drift %.1e\n",
               R.route, R.mom, R.energy);
        return 0;
    }
    {
        /* the bounds: (H1) to 4 d tol (the solver stops at a Newton step below tol h); rates and routes to
           round-off; energy to the time-stepping error of 10 steps */
        const double eps = sizeof(sph_real) == sizeof(float) ? FLT_EPSILON : DBL_EPSILON;
        const double tol = sizeof(sph_real) == sizeof(float) ? 64 * eps : 1e-6, rate = 1e3 * eps, energy = 1e-4;
        long researches = 0;
        int ok = 1;
        for (d = 1; d <= 3; ++d) {
            sr_param Q = P;
            int pass;
            Q.dim = d, Q.n1 = n1_check[d], Q.neighbours = usual[d], Q.steps = 10;
            if ((st = sr_run(&Q, &R)) != SPH_OK) {
                sr_explain(&Q, st);
                printf("step_recipe --check: %d-D run failed\n", d);
                return 1;
            }
            sr_print(&Q, &R);
            pass = R.h1 <= 4 * d * tol && R.mom_rate <= rate && R.en_rate <= rate && R.route <= rate &&
                   R.mom <= rate && R.energy <= energy && R.searches <= R.steps; /* a list kept at least once */
            researches += R.researches;
            printf("  (H1) residual %.1e (bound %.1e); rates of momentum %.1e, energy %.1e; batch loop against "
                   "sph_gradh_forces + viscosity %.1e; momentum %.1e (bounds %.0e); energy drift %.1e (%.0e): %s\n",
                   R.h1, 4 * d * tol, R.mom_rate, R.en_rate, R.route, R.mom, rate, R.energy, energy,
                   pass ? "pass" : "FAIL");
            ok &= pass;
        }
        if (researches == 0) printf("  no run searched again for a particle beyond its list (step 4): FAIL\n");
        ok &= researches > 0;
        printf("step_recipe --check: %s\n", ok ? "pass" : "FAIL");
        return ok ? 0 : 1;
    }
}
