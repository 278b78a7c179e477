/* examples/sod_shock.c - the Sod (1978) shock tube in 3-D with adaptive
 * smoothing lengths, grad-h forces, a switched artificial viscosity and
 * artificial conductivity, against the exact Riemann solution
 * (docs/smoothing_length.md, "Shock tube").
 *
 * States as in Phantom's "Sod shock" set-up and SWIFT's Sod initial conditions (periodic x in [-1, 1]):
 * gamma = 5/3, left state rho = 1, P = 1, right state rho = 0.125, P = 0.1,
 * v = 0, end time t = 0.2, equal-mass particles on two face-centred cubic
 * (close-packed, as the default lattice of Phantom's set-up) lattices of cell a (left) and 2 a
 * (right: density ratio 8 in 3-D); --lattice cubic takes simple cubic
 * lattices instead, which are not a minimum-energy arrangement: the
 * particles re-mesh behind the waves and the left plateau ends up 20 %
 * above the exact pressure (0.35 instead of 0.294 at 32 and 64 cells per
 * unit length; docs/smoothing_length.md). The tube
 * x in [-1, 1) is periodic along every axis, with the left state on
 * [-1, 0) and the right state on [0, 1): the interface at x = 0 is the Sod
 * problem, the one at x = +-1 its mirror image, and until t = 0.25 the waves
 * of the two stay apart; errors are measured over |x| <= 0.5, where only the
 * x = 0 problem has arrived.
 *
 * Each step (kick-drift-kick leapfrog, dt = C h_min / v_sig,max, v_sig,max
 * over the pairs within kappa max(h_i, h_j)):
 *   - neighbour lists (section 7, symmetric criterion (N2)) at a search
 *     radius kappa h_list_i, h_list_i = (1 + skin) h_i (--skin, 0.1; at
 *     most the half-period of the cross-section), kept over the following
 *     steps while they still hold every pair within kappa max(h_i, h_j)
 *     (a Verlet skin: sph_nsearch_skin gives the radii they still serve);
 *     a run is the same bit for bit at any skin that needs no re-search
 *     (tests/check_sod_profile.sh);
 *   - sph_h_solve (section 9, (H1)-(H4)): h_i and rho_i together, Omega_i,
 *     from the guess h_i (1 + dt div v_i / 3) (the drift of h that (H1)
 *     implies); particles whose h outgrew their list get a new radius and
 *     are solved again; then sph_nsearch_prune keeps the pairs within
 *     kappa max(h_i, h_j);
 *   - one loop over the particles, each summing its own row in batches of
 *     SPH_BATCH pairs (sph_batch_fill: x_ij, r, F at h_i and h_j; the
 *     equations in a plain loop over the lanes, sd_batch; each pair is
 *     evaluated from both ends, its terms antisymmetric): the grad-h
 *     momentum and energy equations
 *     (H5), (H6), the signal-velocity artificial viscosity (section 8,
 *     (S3), (S4), SWIFT's beta = 3) with alpha_ij = (alpha_i + alpha_j) / 2
 *     (B_i + B_j) / 2, the artificial conductivity of SPHENIX (Borrow,
 *     Schaller, Bower & Schaye 2022, MNRAS 511, 2367), du_i/dt += sum_j m_j
 *     alpha_D,ij (v_u + |v_ij . x_ij| / r) / 2 (u_i - u_j) (F_i / (Omega_i
 *     rho_i) + F_j / (Omega_j rho_j)) r with v_u = sqrt(|P_i - P_j| /
 *     rho_ij), and the sums of div v_i = -(1 / (Omega_i rho_i)) sum_j m_j
 *     v_ij . grad_i W_ij(h_i) (Price 2012), curl v_i and lap u_i;
 *   - after the sums, SPHENIX's switches per particle (section 8,
 *     sph_switch_update, docs/solver.md (S13)-(S17)): the Balsara (1995)
 *     factor B_i = |div v| / (|div v| + |curl v| + 1e-4 c / h) (S13); alpha_i =
 *     alpha_max S / (c^2 + S), S = H^2 max(0, -d(div v)/dt) (H = kappa h,
 *     d(div v)/dt over the last step) where that is larger, else a decay
 *     to it at the rate 0.25 c / H, alpha in [0, 2] (S16); d alpha_D / dt =
 *     H lap u / sqrt(u) - alpha_D 2 c / H, alpha_D <= 1 - alpha_i / 2 (S17).
 *     The example's first scheme stays behind options: --switch mm97 (Morris &
 *     Monaghan 1997 with the source of Rosswog et al. 2000, (S15): d alpha_i
 *     / dt = -(alpha_i - alpha_min) 0.1 c_i / h_i + max(-div v_i, 0)
 *     (alpha_max - alpha_i)), --conductivity price08 (Price 2008: du_i/dt +=
 *     sum_j m_j alpha_u v_u (u_i - u_j) F_ij r / rho_ij), --balsara 0,
 *     --alpha-min 0.1 --alpha-max 1.
 *
 * The exact solution is the program's own iterative Riemann solver (Toro
 * 2009, chapter 4: Newton-Raphson on the pressure function, then the
 * sampling of section 4.5), checked against Toro's Table 4.3 (test 1,
 * gamma = 1.4: p* = 0.30313, u* = 0.92745) on every --check run.
 *
 *   ./sod_shock                     one run, nx = 32 (fcc cells per unit length, left)
 *   ./sod_shock --check             nx = 16 run with validation bounds (make test)
 *   ./sod_shock --study docs/results  nx = 16, 24, 32, 48: L1 errors and orders into
 *                                   docs/results/sod_shock.md, profiles into --out
 *   ./sod_shock --profile           also the step's wall time per particle by phase (search,
 *                                   density / h, forces, rest), pairs and bytes per particle
 *                                   (make bench-step: bench/bench_step.sh)
 */
#include "example_io.h"

#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* Bounds every run stays within, else it stops with exit 1: the scheme
 * conserves the total energy to round-off and time-integration error (below
 * 1e-3 in the --check run), and the strongest compression of a gamma >= 1
 * shock is (gamma + 1) / (gamma - 1) (4 at 5/3), so a density above 10 times
 * the largest start density has blown up. */
#define SD_ENERGY_TOL 0.01
#define SD_RHO_FACTOR 10.0
#define SD_BOUNDS "a run stops with exit 1 when its total energy drifts by more than 1 % or a density exceeds 10 times the largest start density"
#define SD_EREFUSED 200 /* status of a run refused by its memory estimate (the message printed) */
#define SD_EHSOLVE 201  /* smoothing lengths that did not converge */
#define SD_EEXACT 202   /* no exact Riemann solution for the states */
#define SD_NT 9 /* pair terms per particle: dv/dt (3), du/dt, the sums of div v, curl v (3) and lap u */
#define SD_NX_MAX 256 /* 73728 particles at the fewest ny, 0.9 GB, about 1300 steps: hours of one core (--help prints the memory) */
/* The force loop's pair arithmetic is this file's own code: inlined into each instruction-set instance of sd_rows. */
#if defined(__GNUC__) || defined(__clang__)
#define SD_INLINE static inline __attribute__((always_inline))
#else
#define SD_INLINE static inline
#endif

typedef struct {
    int nx, ny;          /* left lattice: cells per unit length, and across the tube (0: the fewest allowed) */
    const char *kernel, *lattice; /* lattice: fcc (4 particles per cell) or cubic (1) */
    double gamma, t_end, eta, cfl, alpha_min, alpha_max, beta, alpha_u;
    double skin; /* lists at kappa (1 + skin) h, kept while every pair within kappa h is still listed */
    const char *av_switch, *cond; /* viscosity switch: sphenix or mm97; conductivity: sphenix or price08 */
    double av_length, beta_u;     /* SPHENIX: decay length of the viscosity, source coefficient of the conductivity */
    int balsara;                  /* the Balsara (1995) limiter on the viscosity */
    int profile; /* --profile: time the phases of the step (sd_prof) */
} sd_param;

/* --profile: wall time of the step loop per phase, and what the step handles. */
enum { SD_SEARCH, SD_H, SD_FORCES, SD_REST, SD_PHASES };
typedef struct {
    double t[SD_PHASES], last;  /* seconds per phase; the clock at the last mark */
    double entries, pairs;      /* sums over the steps: kept list entries, pairs within kappa max(h_i, h_j) */
    double candidates, sampled; /* sums over the sampled steps: search candidates, list entries */
    long steps, samples, researches, searches;
    double bytes[3];            /* held at the end: fields, lists, search workspace */
    int threads;
} sd_prof;

typedef struct {
    double l1_rho, l1_v, l1_p;  /* L1 errors over |x| <= 0.5 at t_end */
    double energy_drift;        /* |E(t_end) - E(0)| / E(0) */
    double momentum;            /* |sum m v_x| / sum m |v| at t_end */
    double seconds;
    long steps, solves, sums, researches;
    int max_sums;
    sph_idx n;
    sd_prof prof; /* --profile */
} sd_result;

/* ---- the exact Riemann solution (Toro 2009, chapter 4) ---- */

typedef struct {
    double rho, u, p;
} sd_state;

/* f_K(p) and its derivative (Toro eqs. 4.6, 4.7, 4.37): shock for p > p_K, rarefaction otherwise. */
static void sd_pressure_function(double p, sd_state K, double g, double *f, double *df)
{
    const double c = sqrt(g * K.p / K.rho);
    if (p > K.p) {
        const double A = 2 / ((g + 1) * K.rho), B = (g - 1) / (g + 1) * K.p, s = sqrt(A / (B + p));
        *f = (p - K.p) * s;
        *df = s * (1 - (p - K.p) / (2 * (B + p)));
    } else {
        *f = 2 * c / (g - 1) * (pow(p / K.p, (g - 1) / (2 * g)) - 1);
        *df = pow(p / K.p, -(g + 1) / (2 * g)) / (K.rho * c);
    }
}

/* p* and u* by Newton-Raphson from the two-rarefaction guess (Toro eqs. 4.5, 4.9, 4.46). */
static int sd_star(sd_state L, sd_state R, double g, double *ps, double *us)
{
    const double cL = sqrt(g * L.p / L.rho), cR = sqrt(g * R.p / R.rho), z = (g - 1) / (2 * g);
    double p = pow((cL + cR - (g - 1) / 2 * (R.u - L.u)) / (cL / pow(L.p, z) + cR / pow(R.p, z)), 1 / z);
    int it;
    for (it = 0; it < 50; ++it) {
        double fL, dL, fR, dR, pn;
        sd_pressure_function(p, L, g, &fL, &dL);
        sd_pressure_function(p, R, g, &fR, &dR);
        pn = p - (fL + fR + R.u - L.u) / (dL + dR);
        if (pn < 1e-12) pn = 1e-12;
        if (fabs(pn - p) <= 1e-14 * (pn + p)) {
            p = pn;
            sd_pressure_function(p, L, g, &fL, &dL);
            sd_pressure_function(p, R, g, &fR, &dR);
            *ps = p;
            *us = (L.u + R.u) / 2 + (fR - fL) / 2;
            return 0;
        }
        p = pn;
    }
    return -1;
}

/* The solution at S = x / t (Toro section 4.5): left or right of the contact, shock or fan. */
static sd_state sd_sample(sd_state L, sd_state R, double g, double ps, double us, double S)
{
    const int left = S <= us;
    const sd_state K = left ? L : R;
    const double sg = left ? 1 : -1; /* mirror the right side onto the left formulas */
    const double c = sqrt(g * K.p / K.rho), G6 = (g - 1) / (g + 1), q = ps / K.p;
    sd_state W = K;
    if (ps > K.p) { /* shock */
        const double SK = K.u - sg * c * sqrt((g + 1) / (2 * g) * q + (g - 1) / (2 * g));
        if (sg * (S - SK) > 0) W.rho = K.rho * (q + G6) / (G6 * q + 1), W.u = us, W.p = ps;
    } else { /* rarefaction: head, tail, fan */
        const double cs = c * pow(q, (g - 1) / (2 * g)), head = K.u - sg * c, tail = us - sg * cs;
        if (sg * (S - tail) > 0) {
            W.rho = K.rho * pow(q, 1 / g), W.u = us, W.p = ps;
        } else if (sg * (S - head) > 0) {
            const double u = 2 / (g + 1) * (sg * c + (g - 1) / 2 * K.u + S);
            const double cf = 2 / (g + 1) * (c + sg * (g - 1) / 2 * (K.u - S));
            W.rho = K.rho * pow(cf / c, 2 / (g - 1)), W.u = u, W.p = K.p * pow(cf / c, 2 * g / (g - 1));
        }
    }
    return W;
}

/* ---- the simulation ---- */

typedef struct {
    sd_param P;
    sph_kernel k;
    sph_real kappa, dx, W, h_cap, m; /* m: the mass of every particle */
    sph_idx n;
    sph_box box;
    sph_real *x, *v, *vp, *a, *u, *up, *du, *h, *rho, *om, *hl, *hle, *x0, *A, *cs, *alpha, *dalpha;
    sph_real *B, *alpha_d, *divv; /* Balsara factor, conductivity alpha_D, div v of the last force evaluation */
    sph_real *sw;                 /* div v, |curl v|, lap u of this evaluation: the switches' input */
    sph_switch mm97;              /* --switch mm97: its parameters (S15), ell = 0.1 */
    double dt;                    /* the step since the last force evaluation (0 before the first) */
    int sphenix_av, sphenix_cond; /* P's switches as flags */
    int *state;
    /* lists: kept, the symmetric list at kappa hl searched at x0 (cap entries); pairs, its pairs within
       kappa max(h_i, h_j) at x (sph_nsearch_prune, cap entries) */
    void *work;
    size_t work_bytes;
    sph_off *offset, *p_off, cap;
    sph_idx *index, *p_idx;
    sph_neighbours kept, pairs;
    int listed; /* 1 once a search has filled the kept list */
    double vsig_max;
    long solves, sums, researches, searches;
    int max_sums;
    sph_nsearch grid; /* the last search's cells (sph_nsearch_stats of --profile) */
    sph_off *share_next; /* the force loop's shares (sph_share): one per thread, shares * SPH_SHARE_PAD */
    int shares;
    sd_prof *prof; /* inside the step loop with --profile, NULL otherwise */
} sd_sim;

static void sd_free(sd_sim *S)
{
    free(S->x), free(S->v), free(S->vp), free(S->a), free(S->u), free(S->up), free(S->du), free(S->h);
    free(S->rho), free(S->om), free(S->hl), free(S->hle), free(S->x0), free(S->A), free(S->cs), free(S->alpha);
    free(S->dalpha), free(S->B), free(S->alpha_d), free(S->divv), free(S->sw);
    free(S->state), free(S->work), free(S->offset), free(S->p_off), free(S->index), free(S->p_idx);
    free(S->share_next);
}

/* Particles per lattice cell: 4 (fcc) or 1 (cubic). */
static int sd_per_cell(const sd_param *P) { return strcmp(P->lattice, "cubic") == 0 ? 1 : 4; }

/* The fewest (even) cells across the tube for which the search radius kappa 1.15 h of the right lattice
 * (h = eta 2 a ppc^(-1/3)) stays within half the cross-section. */
static double sd_ny_min(const sd_param *P, double kappa)
{
    return 2 * kappa * 1.15 * P->eta * 2 / cbrt((double)sd_per_cell(P)) / 0.999;
}

/* Particles of the two lattices. */
static double sd_particles(const sd_param *P)
{
    return (double)sd_per_cell(P) * ((double)P->nx * P->ny * P->ny + (double)(P->nx / 2) * (P->ny / 2) * (P->ny / 2));
}

/* Bytes a run allocates per particle: 33 reals, the state and two list
 * offsets, the search's workspace (about 40 bytes), and per list entry two
 * indices (the kept list and its pruned copy), for 1.25 times (the growth
 * slack of sd_search) 1.1 times the neighbours in the sphere of radius
 * kappa (1 + skin) eta (m / rho)^(1/3), i.e. 1.1 (4/3) pi (kappa (1 + skin)
 * eta)^3 (at the defaults: 81 entries measured, 77 in the sphere). */
static double sd_bytes_per_particle(const sd_param *P)
{
    const double kappa = sph_kernel_support((sph_kernel)sph_kernel_from_name(P->kernel));
    const double r = (1 + P->skin) * kappa * P->eta, entries = 1.25 * 1.1 * 4.18879020478639 * r * r * r;
    return 33.0 * sizeof(sph_real) + sizeof(int) + 2.0 * sizeof(sph_off) + 40 + entries * 2.0 * sizeof(sph_idx);
}

/* Time steps to t_end: about 5 per left cell at t = 0.2 and CFL 0.3 (80 at nx = 16, 120 at 24). */
static double sd_steps(const sd_param *P) { return 7.5 * P->nx * P->t_end / P->cfl; }

/* The fewest even ny of P's kernel, eta and lattice (at least 4). */
static int sd_ny_auto(const sd_param *P)
{
    const int ny = 2 * (int)ceil(sd_ny_min(P, (double)sph_kernel_support((sph_kernel)sph_kernel_from_name(P->kernel))) / 2);
    return ny < 4 ? 4 : ny;
}

/* Whether the run's memory estimate fits what the process may allocate;
 * if not, a message naming --nx (and --ny), the estimate and the largest
 * --nx that fits. Prints the banner (particles, memory, steps) when it fits. */
static int sd_fits(const sd_param *P)
{
    const char *why = NULL;
    const double n = sd_particles(P), per = sd_bytes_per_particle(P), need = n * per;
    const double avail = ex_memory_available(&why);
    char b_need[32], b_per[32], b_avail[32];
    ex_bytes_text(need, b_need, sizeof b_need), ex_bytes_text(per, b_per, sizeof b_per);
    if (avail >= 0 && need > avail) {
        sd_param Q = *P;
        ex_bytes_text(avail, b_avail, sizeof b_avail);
        while (Q.nx > 8 && sd_particles(&Q) * per > avail) Q.nx -= 2;
        if (sd_particles(&Q) * per > avail)
            fprintf(stderr, "%s: --nx %d --ny %d needs %s (%.0f particles x %s); not even --nx 8 fits in the %s of the %s: "
                    "lower --ny\n", ex_prog(), P->nx, P->ny, b_need, n, b_per, b_avail, why);
        else
            fprintf(stderr, "%s: --nx %d needs %s (%.0f particles x %s at --ny %d); at most --nx %d fits in the %s of "
                    "the %s\n", ex_prog(), P->nx, b_need, n, b_per, P->ny, Q.nx, b_avail, why);
        return 0;
    }
    printf("%s: nx %d, ny %d, %s lattices: %.0f particles, about %s, about %.0f steps to t = %g\n", ex_prog(), P->nx,
           P->ny, P->lattice, n, b_need, sd_steps(P), P->t_end);
    fflush(stdout);
    return 1;
}

/* malloc of count elements of size bytes, NULL on overflow or failure. */
static void *sd_alloc(size_t count, size_t size) { return count > ((size_t)-1) / size ? NULL : malloc(count * size); }

/* The two lattices; returns 0 or -1 (out of memory). */
static int sd_setup(sd_sim *S)
{
    const sd_param *P = &S->P;
    /* cell bases: fcc shifted by a / 4 (the two lattices then meet 3a/4 apart at x = 0 and x = +-1), cubic cell-centred */
    static const double fcc[4][3] = {{0.25, 0.25, 0.25}, {0.75, 0.75, 0.25}, {0.75, 0.25, 0.75}, {0.25, 0.75, 0.75}};
    static const double cub[1][3] = {{0.5, 0.5, 0.5}};
    const int ppc = sd_per_cell(P), nxr = P->nx / 2, nyr = P->ny / 2;
    const double(*basis)[3] = ppc == 4 ? fcc : cub;
    const double dx = 1.0 / P->nx, dxr = 2 * dx, g1 = P->gamma - 1;
    const size_t n = (size_t)ppc * ((size_t)P->nx * (size_t)P->ny * (size_t)P->ny + (size_t)nxr * (size_t)nyr * (size_t)nyr);
    sph_idx p = 0;
    int i, j, l, b;
    S->n = (sph_idx)n;
    S->dx = (sph_real)dx;
    S->W = (sph_real)(P->ny * dx);
    S->h_cap = (sph_real)(0.999 * S->W / (2 * S->kappa)); /* search radius at most half the cross-section */
    S->box.lo[0] = -1, S->box.lo[1] = S->box.lo[2] = 0;
    S->box.length[0] = 2, S->box.length[1] = S->box.length[2] = S->W;
    S->box.periodic[0] = S->box.periodic[1] = S->box.periodic[2] = 1;
#define SD_A(f, c) ((S->f = (sph_real *)sd_alloc(n * (c), sizeof(sph_real))) == NULL)
    if (SD_A(x, 3) || SD_A(v, 3) || SD_A(vp, 3) || SD_A(a, 3) || SD_A(u, 1) || SD_A(up, 1) || SD_A(du, 1) ||
        SD_A(h, 1) || SD_A(rho, 1) || SD_A(om, 1) || SD_A(hl, 1) || SD_A(hle, 1) || SD_A(x0, 3) || SD_A(A, 1) ||
        SD_A(cs, 1) || SD_A(alpha, 1) || SD_A(dalpha, 1) || SD_A(B, 1) || SD_A(alpha_d, 1) || SD_A(divv, 1) ||
        SD_A(sw, 3))
        return -1;
#undef SD_A
#ifdef _OPENMP
    S->shares = omp_get_max_threads();
#else
    S->shares = 1;
#endif
    if ((S->share_next = (sph_off *)sd_alloc((size_t)S->shares * SPH_SHARE_PAD, sizeof(sph_off))) == NULL ||
        (S->state = (int *)sd_alloc(n, sizeof(int))) == NULL ||
        (S->offset = (sph_off *)sd_alloc(n + 1, sizeof(sph_off))) == NULL ||
        (S->p_off = (sph_off *)sd_alloc(n + 1, sizeof(sph_off))) == NULL)
        return -1;
    for (l = 0; l < 2; ++l) { /* l = 0: left lattice on [-1, 0), l = 1: right lattice on [0, 1) */
        const int mx = l ? nxr : P->nx, my = l ? nyr : P->ny;
        const double d = l ? dxr : dx, x0 = l ? 0 : -1, rho = l ? 0.125 : 1, pr = l ? 0.1 : 1;
        for (i = 0; i < mx; ++i)
            for (j = 0; j < my * my * ppc; ++j, ++p) {
                b = j % ppc;
                S->x[3 * p] = (sph_real)(x0 + (i + basis[b][0]) * d);
                S->x[3 * p + 1] = (sph_real)((j / ppc % my + basis[b][1]) * d);
                S->x[3 * p + 2] = (sph_real)((j / ppc / my + basis[b][2]) * d);
                S->v[3 * p] = S->v[3 * p + 1] = S->v[3 * p + 2] = 0;
                S->u[p] = (sph_real)(pr / (g1 * rho));
                S->h[p] = (sph_real)(P->eta * d / cbrt((double)ppc));
                S->alpha[p] = (sph_real)P->alpha_min;
                S->B[p] = 1, S->alpha_d[p] = S->sphenix_cond ? 0 : (sph_real)P->alpha_u, S->divv[p] = 0;
            }
    }
    return 0;
}

/* The grid of sph_nsearch_build for the radii kappa h_v (cells of kappa h_max / 2: the symmetric criterion reaches
 * that far) in S->grid, the workspace grown when it is short. */
static int sd_grid(sd_sim *S, const sph_real *hr)
{
    const sph_view xv = sph_view_interleaved(S->x, 3), hv = sph_view_soa(hr, NULL, NULL);
    sph_real hmax = hr[0];
    size_t bytes;
    sph_idx i;
    int st;
    for (i = 1; i < S->n; ++i) hmax = hr[i] > hmax ? hr[i] : hmax;
    st = sph_nsearch_workspace_size(3, xv, S->n, hv, S->kappa * hmax / 2, &S->box, &bytes);
    if (st != SPH_OK) return st;
    if (bytes > S->work_bytes) {
        free(S->work);
        S->work = malloc(bytes);
        S->work_bytes = S->work != NULL ? bytes : 0;
        if (S->work == NULL) return EX_ENOMEM;
    }
    return sph_nsearch_build(&S->grid, 3, xv, S->n, hv, S->kappa * hmax / 2, &S->box, S->work, S->work_bytes);
}

/* The particles in the cell order of a grid for kappa h (sph_nsearch_permutation, (N5)), once after the set-up:
 * neighbours then lie close in memory for the whole run (the particles of a shock tube move little against each
 * other), whatever the skin. x0 and hle, not used before the first search, serve as scratch. */
static int sd_cell_order(sd_sim *S)
{
    sph_real *f1[3] = {S->u, S->h, S->alpha};
    sph_idx *perm = (sph_idx *)sd_alloc((size_t)S->n, sizeof(sph_idx));
    int st, k;
    if (perm == NULL) return EX_ENOMEM;
    if ((st = sd_grid(S, S->h)) != SPH_OK || (st = sph_nsearch_permutation(&S->grid, perm)) != SPH_OK) {
        free(perm);
        return st;
    }
    for (k = 0; k < 2 && st == SPH_OK; ++k) { /* x, v: three components */
        sph_real *f = k == 0 ? S->x : S->v;
        st = sph_permute(sph_view_interleaved(f, 3), 3, S->n, perm, sph_out_interleaved(S->x0, 3));
        memcpy(f, S->x0, sizeof(sph_real) * 3 * (size_t)S->n);
    }
    for (k = 0; k < 3 && st == SPH_OK; ++k) { /* the fields set per particle; B, alpha_D, div v start uniform */
        st = sph_permute(sph_view_soa(f1[k], NULL, NULL), 1, S->n, perm, sph_out_soa(S->hle, NULL, NULL));
        memcpy(f1[k], S->hle, sizeof(sph_real) * (size_t)S->n);
    }
    free(perm);
    return st;
}

/* Symmetric lists (N2) at radius kappa hl_i into S->offset/index (S->kept); the positions are kept in x0 and every
 * radius is usable (hle = hl) until the particles move. */
static int sd_search(sd_sim *S)
{
    const sph_view xv = sph_view_interleaved(S->x, 3), hv = sph_view_soa(S->hl, NULL, NULL);
    sph_off pairs = 0;
    int st;
    if ((st = sd_grid(S, S->hl)) != SPH_OK) return st;
    S->listed = 0;
    st = sph_nsearch_lists(&S->grid, xv, S->n, hv, 0, S->kappa, SPH_NSEARCH_SYMMETRIC, S->offset, S->index, S->cap, &pairs);
    if (st == SPH_ESIZE) { /* grow the index arrays with slack, then fill */
        free(S->index), free(S->p_idx);
        S->cap = S->offset[S->n] + S->offset[S->n] / 4 + 1;
        S->index = (sph_idx *)sd_alloc((size_t)S->cap, sizeof(sph_idx));
        S->p_idx = (sph_idx *)sd_alloc((size_t)S->cap, sizeof(sph_idx));
        if (S->index == NULL || S->p_idx == NULL) return S->cap = 0, EX_ENOMEM;
        st = sph_nsearch_fill(&S->grid, xv, S->n, hv, 0, S->kappa, SPH_NSEARCH_SYMMETRIC, S->offset, S->index, S->cap);
    }
    if (st != SPH_OK) return st;
    S->kept = sph_nsearch_list(&S->grid, S->n, S->offset, S->index);
    memcpy(S->x0, S->x, sizeof(sph_real) * 3 * (size_t)S->n);
    memcpy(S->hle, S->hl, sizeof(sph_real) * (size_t)S->n);
    S->listed = 1;
    S->searches++;
    return SPH_OK;
}

/* --profile: the wall time since the last mark goes to phase p; without --profile nothing happens. */
static void sd_mark(sd_sim *S, int p)
{
    if (S->prof != NULL) {
        const double now = ex_now();
        S->prof->t[p] += now - S->prof->last;
        S->prof->last = now;
    }
}

/* Lists and h together: the kept list while it serves every h (sph_nsearch_skin: the radii hle it still serves),
 * else a search at (1 + skin) h; then the h solve on the radii hle; particles beyond them get (1 + skin) times the
 * solver's estimate and the search is repeated. Last, the pairs within kappa max(h_i, h_j) (sph_nsearch_prune). */
static int sd_density(sd_sim *S)
{
    const sph_real grow = (sph_real)(1 + S->P.skin);
    const sph_view xv = sph_view_interleaved(S->x, 3);
    sph_hctx c;
    sph_hreport rep;
    sph_idx i, stale = 1;
    sph_off pairs;
    int round, st;
    if (S->listed) {
        st = sph_nsearch_skin(&S->kept, NULL, 3, xv, sph_view_interleaved(S->x0, 3), sph_view_soa(S->hl, NULL, NULL),
                              S->kappa, sph_view_soa(S->h, NULL, NULL), sph_out_soa(S->hle, NULL, NULL), &stale);
        if (st != SPH_OK) return st;
    }
    if (stale > 0) {
        for (i = 0; i < S->n; ++i) S->hl[i] = grow * S->h[i] < S->h_cap ? grow * S->h[i] : S->h_cap;
        if ((st = sd_search(S)) != SPH_OK) return st;
    }
    sd_mark(S, SD_SEARCH);
    for (round = 0; round < 6; ++round) {
        c = sph_hctx_init(S->k, 3, &S->kept, xv, sph_view_aos(&S->m, 1, 0), 0); /* stride 0: one mass; the list's box */
        c.eta = (sph_real)S->P.eta;
        c.h_list = sph_view_soa(S->hle, NULL, NULL);
        c.check_list = 0; /* the search's lists */
        st = sph_h_solve(&c, sph_out_soa(S->h, NULL, NULL), sph_out_soa(S->rho, NULL, NULL), sph_out_soa(S->om, NULL, NULL),
                         NULL, S->state, &rep);
        if (st != SPH_OK) return st;
        sd_mark(S, SD_H);
        S->solves++;
        S->sums += (long)rep.iterations;
        S->max_sums = rep.max_iterations > S->max_sums ? rep.max_iterations : S->max_sums;
        if (rep.n_not_converged > 0) return SD_EHSOLVE;
        if (rep.n_beyond_list == 0) {
            st = sph_nsearch_prune(&S->kept, NULL, 3, xv, sph_view_soa(S->h, NULL, NULL), S->kappa, SPH_NSEARCH_SYMMETRIC,
                                   S->p_off, S->p_idx, S->cap, &pairs, &S->pairs);
            sd_mark(S, SD_H);
            return st;
        }
        S->researches++;
        for (i = 0; i < S->n; ++i)
            if (S->state[i] == SPH_H_BEYOND_LIST) {
                if (S->hle[i] >= S->h_cap) return SPH_EPERIOD; /* h beyond half the cross-section: a wider tube is needed */
                S->hl[i] = grow * S->h[i] < S->h_cap ? grow * S->h[i] : S->h_cap;
            }
        if ((st = sd_search(S)) != SPH_OK) return st;
        sd_mark(S, SD_H); /* a re-search counts to the h solve that asked for it */
    }
    return SD_EHSOLVE;
}

/* (H5), (H6), (S3), (S4), conductivity, and the sums of div v, curl v and lap u of particle i from the pairs of
 * batch b of its row, added to acc[SD_NT] (dv/dt, du/dt, sum m_j v_ij . x_ij F_i, sum m_j (v_ij x x_ij) F_i,
 * lap u); the largest signal velocity of the pairs other than (i, i) into vs. SPHENIX: Borrow, Schaller, Bower &
 * Schaye (2022, MNRAS 511, 2367). */
SD_INLINE void sd_batch(const sd_sim *S, sph_idx i, const sph_batch *b, sph_real *vs, sph_real *acc)
{
    const sd_param *P = &S->P;
    const sph_real m = S->m, g1 = (sph_real)(P->gamma - 1), beta = (sph_real)P->beta, au = (sph_real)P->alpha_u;
    const sph_real Ai = S->A[i], rhoi = S->rho[i], ci = S->cs[i], ui = S->up[i], pi = g1 * rhoi * ui;
    const sph_real ali = S->alpha[i], Bi = S->B[i], adi = S->alpha_d[i], Gi_rho = 1 / (S->om[i] * rhoi);
    const sph_real *vi = S->vp + 3 * i;
    const int sphenix = S->sphenix_cond;
    sph_real t[SD_NT][SPH_BATCH], vsig[SPH_BATCH], vu[SPH_BATCH], vmax = *vs;
    sph_real vj[3][SPH_BATCH], Aj[SPH_BATCH], rhoj[SPH_BATCH], cj[SPH_BATCH], uj[SPH_BATCH], alj[SPH_BATCH];
    sph_real Bj[SPH_BATCH], adj[SPH_BATCH], omj[SPH_BATCH];
    int l, a;
    for (l = 0; l < SPH_BATCH; ++l) { /* the partners' fields into lanes */
        const sph_idx j = b->j[l];
        for (a = 0; a < 3; ++a) vj[a][l] = S->vp[3 * j + a];
        Aj[l] = S->A[j], rhoj[l] = S->rho[j], cj[l] = S->cs[j], uj[l] = S->up[j], alj[l] = S->alpha[j];
        Bj[l] = S->B[j], adj[l] = S->alpha_d[j], omj[l] = S->om[j];
    }
    for (l = 0; l < SPH_BATCH; ++l) { /* the square root's argument on its own: the loop below then has no call */
        const sph_real pj = g1 * rhoj[l] * uj[l], rhob = (rhoi + rhoj[l]) / 2;
        vu[l] = fabs(pi - pj) / rhob;
    }
    sph_batch_sqrt(vu); /* v_u = sqrt(|P_i - P_j| / rho_ij), in vector registers */
    for (l = 0; l < SPH_BATCH; ++l) {
        const sph_real dx = b->dx[0][l], dy = b->dx[1][l], dz = b->dx[2][l], r = b->r[l], Fi = b->F_i[l], Fj = b->F_j[l];
        const sph_real dvx = vi[0] - vj[0][l], dvy = vi[1] - vj[1][l], dvz = vi[2] - vj[2][l];
        const sph_real e = dvx * dx + dvy * dy + dvz * dz, rinv = 1 / (r > 0 ? r : 1); /* e = v_ij . x_ij */
        const sph_real Fb = (Fi + Fj) / 2, rhob = (rhoi + rhoj[l]) / 2, pj = g1 * rhoj[l] * uj[l];
        const sph_real w = (e < 0 ? e : 0) * rinv;                    /* (S2) w_ij, no division by 0 */
        const sph_real v_sig = ci + cj[l] - beta * w;                 /* (S2) */
        /* (S3) with alpha_ij of (S14) = (alpha_i + alpha_j) / 2 (B_i + B_j) / 2 (B = 1 without Balsara) */
        const sph_real Pi = -(sph_pair_av_alpha(ali, alj[l], Bi, Bj[l]) / 2) * v_sig * w / rhob;
        const sph_real cav = m * Pi * Fb;                             /* (S4) */
        const sph_real cp = m * (Ai * Fi + Aj[l] * Fj) + cav;         /* (H5) + (S4): dv_i/dt = -cp x_ij */
        /* SPHENIX eqs. 24-26: m_j alpha_D,ij v_D (u_i - u_j) (F_i / (Omega_i rho_i) + F_j / (Omega_j rho_j)) r,
           alpha_D,ij = (P_i alpha_D,i + P_j alpha_D,j) / (P_i + P_j), v_D = (v_u + |e| / r) / 2; else Price (2008):
           m_j alpha_u v_u (u_i - u_j) F_ij r / rho_ij */
        const sph_real cond_s = m * (pi * adi + pj * adj[l]) / (pi + pj) * (vu[l] + fabs(e) * rinv) / 2 * (ui - uj[l]) *
                                (Fi * Gi_rho + Fj / (omj[l] * rhoj[l])) * r;
        const sph_real cond_p = au * m * vu[l] * (ui - uj[l]) * Fb * r / rhob;
        const sph_real cond = sphenix ? cond_s : cond_p; /* both computed: a select, not a branch, in the lanes */
        t[0][l] = -cp * dx, t[1][l] = -cp * dy, t[2][l] = -cp * dz;
        t[3][l] = m * Ai * Fi * e + cav * e / 2 + cond;               /* (H6) + (S4) */
        t[4][l] = m * e * Fi;                                         /* div v before the factor -1 / (Omega rho) */
        t[5][l] = m * (dvy * dz - dvz * dy) * Fi;                     /* curl v before the factor 1 / (Omega rho) */
        t[6][l] = m * (dvz * dx - dvx * dz) * Fi;
        t[7][l] = m * (dvx * dy - dvy * dx) * Fi;
        t[8][l] = 2 * m * (ui - uj[l]) * Fi / rhoj[l];                /* lap u (Brookshaw 1985; SPHENIX eq. 27) */
        vsig[l] = b->j[l] != i ? v_sig : 0;                           /* padding lanes hold j = i */
    }
    for (a = 0; a < SD_NT; ++a) {
        sph_real sum = 0;
        for (l = 0; l < SPH_BATCH; ++l) sum += t[a][l];
        acc[a] += sum;
    }
    for (l = 0; l < SPH_BATCH; ++l) vmax = vsig[l] > vmax ? vsig[l] : vmax;
    *vs = vmax;
}

/* This thread's number in an OpenMP team, 0 without OpenMP. */
static int sd_thread(void)
{
#ifdef _OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

/* Particle i's pair sums (sd_batch over the batches of its row) and what follows from them: dv/dt, du/dt, d alpha /
 * dt and the switches' input; returns the largest signal velocity of its pairs. */
SD_INLINE sph_real sd_force_row(sd_sim *S, const sph_batch_src *B, sph_idx i)
{
    sph_real vs = 0, acc[SD_NT] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    const sph_real orho = S->om[i] * S->rho[i];
    sph_real divv, curl;
    sph_off next = 0;
    sph_batch b;
    int a;
    while (sph_batch_fill(B, i, &next, &b) > 0) sd_batch(S, i, &b, &vs, acc);
    for (a = 0; a < 3; ++a) S->a[3 * i + a] = acc[a];
    S->du[i] = acc[3];
    divv = -acc[4] / orho; /* div v_i (Price 2012) */
    curl = sqrt(acc[5] * acc[5] + acc[6] * acc[6] + acc[7] * acc[7]) / orho;
    /* (S15) Morris & Monaghan (1997) with the source of Rosswog et al. (2000); SPHENIX's switch replaces it */
    S->dalpha[i] = S->sphenix_av ? 0 : sph_switch_mm97(&S->mm97, S->alpha[i], divv, S->cs[i], S->h[i]);
    S->sw[3 * i] = divv, S->sw[3 * i + 1] = curl, S->sw[3 * i + 2] = acc[8];
    return vs;
}

/* The rows of thread t's shares (sd_force_row); returns their largest signal velocity. One body, compiled for the
 * build's target (sd_rows) and, where the header has run-time dispatch, for AVX2 and AVX-512 (SPH_TARGET_AVX2,
 * SPH_TARGET_AVX512): sd_forces calls the instance of the level the header's loops run at (sph_isa), so that a
 * build without -march runs this arithmetic in the CPU's widest registers too. */
/* snippet: share */
SD_INLINE double sd_rows_body(sd_sim *S, const sph_batch_src *B, sph_share *share, int t)
{
    sph_idx lo, hi, j;
    double vmax = 0;
    int u = 0;
    while (sph_share_next(share, t, &u, &lo, &hi))
        for (j = lo; j < hi; ++j) {
            const sph_real vs = sd_force_row(S, B, j);
            vmax = vs > vmax ? vs : vmax;
        }
    return vmax;
}
/* end snippet */
static double sd_rows(sd_sim *S, const sph_batch_src *B, sph_share *share, int t) { return sd_rows_body(S, B, share, t); }
#ifdef SPH_TARGET_AVX2
SPH_TARGET_AVX2 static double sd_rows_avx2(sd_sim *S, const sph_batch_src *B, sph_share *share, int t)
{
    return sd_rows_body(S, B, share, t);
}
#endif
#ifdef SPH_TARGET_AVX512
SPH_TARGET_AVX512 static double sd_rows_avx512(sd_sim *S, const sph_batch_src *B, sph_share *share, int t)
{
    return sd_rows_body(S, B, share, t);
}
#endif
static double sd_rows_at(int isa, sd_sim *S, const sph_batch_src *B, sph_share *share, int t)
{
    switch (isa) {
#ifdef SPH_TARGET_AVX512
    case SPH_ISA_AVX512: return sd_rows_avx512(S, B, share, t);
#endif
#ifdef SPH_TARGET_AVX2
    case SPH_ISA_AVX2: return sd_rows_avx2(S, B, share, t);
#endif
    default: return sd_rows(S, B, share, t);
    }
}

/* SPHENIX's switches of every particle (sph_switch_update) from div v, |curl v| and lap u of this evaluation (sw) and
 * div v of the last (divv), dt the step between: the Balsara factor B (S13) with --balsara 1, alpha (S16) with
 * --switch sphenix (else only read: the conductivity's limit), alpha_D (S17) with --conductivity sphenix, its decay
 * at 2 c / H and its limit from the particle's own alpha (SWIFT: the neighbours' largest signal velocity and alpha).
 * Borrow, Schaller, Bower & Schaye (2022, MNRAS 511, 2367), sections 2.4 and 2.5. */
static int sd_switches(sd_sim *S)
{
    const sd_param *P = &S->P;
    const size_t row = 3 * sizeof(sph_real); /* sw: three values per particle */
    const sph_out none = sph_out_soa(NULL, NULL, NULL);
    sph_switch_input in = sph_switch_input_init(S->kappa);
    in.par.alpha_min = (sph_real)P->alpha_min, in.par.alpha_max = (sph_real)P->alpha_max;
    in.par.length = (sph_real)P->av_length;
    in.par.alpha_d_min = 0, in.par.alpha_d_max = (sph_real)P->alpha_u, in.par.beta_d = (sph_real)P->beta_u;
    in.viscosity = S->sphenix_av ? SPH_SWITCH_SPHENIX : SPH_SWITCH_NONE;
    in.dt = (sph_real)S->dt;
    in.div_v = sph_view_aos(S->sw, 1, row), in.curl_v = sph_view_aos(S->sw + 1, 1, row);
    in.lap_u = sph_view_aos(S->sw + 2, 1, row);
    in.c = sph_view_soa(S->cs, NULL, NULL), in.h = sph_view_soa(S->h, NULL, NULL), in.u = sph_view_soa(S->up, NULL, NULL);
    return sph_switch_update(&in, S->n, sph_out_soa(S->alpha, NULL, NULL), sph_out_soa(S->divv, NULL, NULL),
                             P->balsara ? sph_out_soa(S->B, NULL, NULL) : none,
                             S->sphenix_cond ? sph_out_soa(S->alpha_d, NULL, NULL) : none);
}

/* Accelerations, du/dt, d alpha/dt and the largest signal velocity at the positions x, velocities vp and energies
 * up: each particle sums over its row of the pruned list (each pair is evaluated from both ends: no scatter, no
 * reduction, no per-pair buffers; the pair terms are antisymmetric, so momentum is conserved to round-off). */
static int sd_forces(sd_sim *S)
{
    const sd_param *P = &S->P;
    sph_share share;
    sph_batch_src B;
    sph_idx i;
    double vmax = 0;
    const int isa = sph_isa();
    int st;
    if ((st = sd_density(S)) != SPH_OK) return st;
#ifdef _OPENMP
#pragma omp parallel for schedule(static)
#endif
    for (i = 0; i < S->n; ++i) {
        const sph_real p = (sph_real)(P->gamma - 1) * S->rho[i] * S->up[i];
        S->cs[i] = sqrt((sph_real)P->gamma * p / S->rho[i]);
        S->A[i] = sph_gradh_factor(p, S->rho[i], S->om[i]);
    }
    st = sph_batch_source(&B, S->k, 3, &S->pairs, NULL, sph_view_interleaved(S->x, 3), sph_view_soa(S->h, NULL, NULL));
    if (st != SPH_OK || (st = sph_batch_select(&B, SPH_BATCH_F)) != SPH_OK) return st; /* the loop needs F alone */
    if ((st = sph_share_init(&share, S->share_next, S->shares, S->n, 64)) != SPH_OK) return st;
#ifdef _OPENMP
#pragma omp parallel reduction(max : vmax)
#endif
    { /* each thread takes its own share first (the particles of the static loops: in its core's caches) */
        const double vs = sd_rows_at(isa, S, &B, &share, sd_thread());
        vmax = vs > vmax ? vs : vmax;
    }
    S->vsig_max = vmax;
    return sd_switches(S); /* after the loop: it read alpha, B and alpha_D of the neighbours */
}

/* --profile: the step loop's timing starts (the first forces before it and the densities after it are not timed). */
static void sd_profile_start(sd_sim *S, sd_prof *Q)
{
#ifdef _OPENMP
    Q->threads = omp_get_max_threads();
#else
    Q->threads = 1;
#endif
    Q->researches = S->researches;
    Q->searches = S->searches;
    S->prof = Q;
    Q->last = ex_now();
}

/* --profile, after each step's forces: the list entries (symmetric, self included) and half-list pairs it used, and
 * every SD_SAMPLE-th step the candidates its last search checked (sph_nsearch_stats runs that search again without
 * writing lists; its time goes to no phase). */
enum { SD_SAMPLE = 10 };
static void sd_profile_count(sd_sim *S)
{
    sd_prof *Q = S->prof;
    Q->entries += (double)S->offset[S->n];
    Q->pairs += (double)(S->p_off[S->n] - S->n) / 2;
    if (Q->steps++ % SD_SAMPLE == 0) {
        sph_off pairs = 0, cand = 0;
        if (sph_nsearch_stats(&S->grid, sph_view_interleaved(S->x0, 3), S->n, sph_view_soa(S->hl, NULL, NULL), 0, S->kappa,
                              SPH_NSEARCH_SYMMETRIC, &pairs, &cand, NULL) == SPH_OK)
            Q->candidates += (double)cand, Q->sampled += (double)pairs, Q->samples++;
        Q->last = ex_now();
    }
}

/* --profile, after the step loop: the last rest, the searches and re-searches, and the bytes per particle the step
 * holds, from the sizes sd_setup and sd_search allocated: fields (x, v, vp, a, x0, sw: 3 reals; u, up, du, h, rho, om,
 * hl, hle, A, cs, alpha, dalpha, B, alpha_d, divv: 1; state; offset, p_off: n + 1 each), lists (index, p_idx: cap entries
 * each) and the search workspace. */
static void sd_profile_end(sd_sim *S)
{
    sd_prof *Q = S->prof;
    const double n = (double)S->n, cap = (double)S->cap;
    sd_mark(S, SD_REST);
    Q->researches = S->researches - Q->researches;
    Q->searches = S->searches - Q->searches;
    Q->bytes[0] = (double)((6 * 3 + 15) * sizeof(sph_real) + sizeof(int)) + 2 * (n + 1) / n * (double)sizeof(sph_off);
    Q->bytes[1] = 2 * cap / n * (double)sizeof(sph_idx);
    Q->bytes[2] = (double)S->work_bytes / n;
    S->prof = NULL;
}

static double sd_energy(const sd_sim *S, double m)
{
    double E = 0;
    sph_idx i;
    for (i = 0; i < S->n; ++i)
        E += m * (0.5 * ((double)S->v[3 * i] * S->v[3 * i] + (double)S->v[3 * i + 1] * S->v[3 * i + 1] +
                         (double)S->v[3 * i + 2] * S->v[3 * i + 2]) + (double)S->u[i]);
    return E;
}

/* One run to t_end; profile (optional) gets x, rho, v, P, u, alpha and the exact rho, v, P over |x| <= 0.5. */
static int sd_run(const sd_param *P, sd_result *R, FILE *profile, const char *label)
{
    const sd_state L = {1, 0, 1}, Rs = {0.125, 0, 0.1};
    sd_sim S;
    double m, t = 0, E0, ps, us, pabs = 0, px = 0;
    ex_progress prog = ex_progress_start();
    double t0 = ex_now();
    ex_growth energy = {"relative total energy error |E - E0| / E0", "the time step is too large: lower --cfl", 0, 0, 0};
    ex_growth density = {"largest density", "the time step is too large or the viscosity too weak: lower --cfl, raise "
                         "--alpha-max", 0, 0, 0};
    sph_idx i, nsel = 0;
    int st = SPH_OK, a;
    memset(&S, 0, sizeof S);
    memset(R, 0, sizeof *R);
    S.P = *P;
    S.sphenix_av = strcmp(P->av_switch, "sphenix") == 0;
    S.sphenix_cond = strcmp(P->cond, "sphenix") == 0;
    S.mm97 = sph_switch_default();
    S.mm97.alpha_min = (sph_real)P->alpha_min, S.mm97.alpha_max = (sph_real)P->alpha_max, S.mm97.length = (sph_real)0.1;
    S.k = (sph_kernel)sph_kernel_from_name(P->kernel);
    S.kappa = sph_kernel_support(S.k);
    if (!sd_fits(P)) return SD_EREFUSED;
    if (sd_setup(&S) != 0) {
        sd_free(&S);
        return EX_ENOMEM;
    }
    if ((st = sd_cell_order(&S)) != SPH_OK) {
        sd_free(&S);
        return st;
    }
    m = 1.0 / ((double)sd_per_cell(P) * P->nx * P->nx * P->nx); /* rho_L a^3 / ppc = rho_R (2 a)^3 / ppc */
    S.m = (sph_real)m;
    E0 = sd_energy(&S, m);
    memcpy(S.vp, S.v, sizeof(sph_real) * 3 * (size_t)S.n);
    memcpy(S.up, S.u, sizeof(sph_real) * (size_t)S.n);
    energy.start = 0, energy.factor = 1, energy.margin = SD_ENERGY_TOL;
    density.start = 1, density.factor = SD_RHO_FACTOR, density.margin = 0; /* the left state's density is the largest */
    st = sd_forces(&S);
    if (P->profile) sd_profile_start(&S, &R->prof);
    while (st == SPH_OK && t < P->t_end * (1 - 1e-12)) {
        sph_real hmin = S.h[0];
        double dt;
        for (i = 1; i < S.n; ++i) hmin = S.h[i] < hmin ? S.h[i] : hmin;
        dt = P->cfl * hmin / S.vsig_max;
        if (t + dt > P->t_end) dt = P->t_end - t;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) private(a)
#endif
        for (i = 0; i < S.n; ++i) { /* kick, drift, predict */
            for (a = 0; a < 3; ++a) {
                S.v[3 * i + a] += (sph_real)(dt / 2) * S.a[3 * i + a];
                S.x[3 * i + a] += (sph_real)dt * S.v[3 * i + a];
                S.x[3 * i + a] -= S.box.length[a] * floor((S.x[3 * i + a] - S.box.lo[a]) / S.box.length[a]);
                S.vp[3 * i + a] = S.v[3 * i + a] + (sph_real)(dt / 2) * S.a[3 * i + a];
            }
            S.u[i] += (sph_real)(dt / 2) * S.du[i];
            S.up[i] = S.u[i] + (sph_real)(dt / 2) * S.du[i];
            S.alpha[i] += (sph_real)(dt / 2) * S.dalpha[i];
            S.h[i] *= 1 + (sph_real)(dt / 3) * S.sw[3 * i]; /* the h solve's guess: dh/dt = (h / 3) div v (from (H1)) */
        }
        sd_mark(&S, SD_REST);
        S.dt = dt;
        if ((st = sd_forces(&S)) != SPH_OK) break;
        sd_mark(&S, SD_FORCES); /* sd_density marked its search and h solve: the rest of sd_forces */
        if (S.prof != NULL) sd_profile_count(&S);
#ifdef _OPENMP
#pragma omp parallel for schedule(static) private(a)
#endif
        for (i = 0; i < S.n; ++i) { /* kick */
            for (a = 0; a < 3; ++a) S.v[3 * i + a] += (sph_real)(dt / 2) * S.a[3 * i + a];
            S.u[i] += (sph_real)(dt / 2) * S.du[i];
            S.alpha[i] += (sph_real)(dt / 2) * S.dalpha[i];
            S.alpha[i] = S.alpha[i] < P->alpha_min ? (sph_real)P->alpha_min
                       : S.alpha[i] > P->alpha_max ? (sph_real)P->alpha_max : S.alpha[i];
        }
        t += dt;
        R->steps++;
        {
            sph_real rho_max = S.rho[0];
            for (i = 1; i < S.n; ++i) rho_max = S.rho[i] > rho_max ? S.rho[i] : rho_max;
            if ((st = ex_growth_check(&energy, fabs(sd_energy(&S, m) - E0) / E0, t)) != SPH_OK ||
                (st = ex_growth_check(&density, (double)rho_max, t)) != SPH_OK)
                break;
        }
        if (label != NULL) ex_progress_update(&prog, label, t / P->t_end);
    }
    if (S.prof != NULL) sd_profile_end(&S);
    if (label != NULL) ex_progress_done(&prog, label);
    if (st == SPH_OK && sd_star(L, Rs, P->gamma, &ps, &us) != 0) st = SD_EEXACT;
    if (st == SPH_OK) { /* densities at the final positions for the errors */
        memcpy(S.vp, S.v, sizeof(sph_real) * 3 * (size_t)S.n);
        memcpy(S.up, S.u, sizeof(sph_real) * (size_t)S.n);
        st = sd_density(&S);
    }
    if (st == SPH_OK) {
        for (i = 0; i < S.n; ++i) {
            const double x = S.x[3 * i], p = (P->gamma - 1) * S.rho[i] * S.u[i];
            px += m * S.v[3 * i];
            pabs += m * (fabs(S.v[3 * i]) + fabs(S.v[3 * i + 1]) + fabs(S.v[3 * i + 2]));
            if (fabs(x) <= 0.5) {
                const sd_state ex = sd_sample(L, Rs, P->gamma, ps, us, x / P->t_end);
                R->l1_rho += fabs(S.rho[i] - ex.rho);
                R->l1_v += fabs(S.v[3 * i] - ex.u);
                R->l1_p += fabs(p - ex.p);
                ++nsel;
                if (profile != NULL)
                    fprintf(profile, "%.6f,%.6f,%.6f,%.6f,%.6f,%.4f,%.6f,%.6f,%.6f\n", ex_csv_fixed(x, 6),
                            ex_csv_fixed(S.rho[i], 6), ex_csv_fixed(S.v[3 * i], 6), ex_csv_fixed(p, 6),
                            ex_csv_fixed(S.u[i], 6), ex_csv_fixed(S.alpha[i], 4), ex_csv_fixed(ex.rho, 6),
                            ex_csv_fixed(ex.u, 6), ex_csv_fixed(ex.p, 6));
            }
        }
        R->l1_rho /= nsel, R->l1_v /= nsel, R->l1_p /= nsel;
        R->energy_drift = fabs(sd_energy(&S, m) - E0) / E0;
        R->momentum = fabs(px) / pabs;
    }
    R->n = S.n;
    R->solves = S.solves, R->sums = S.sums, R->researches = S.researches, R->max_sums = S.max_sums;
    R->seconds = ex_now() - t0;
    sd_free(&S);
    return st;
}

/* --profile: the step's phases in microseconds of wall time per particle and step, what it handles and holds. */
static void sd_print_profile(const sd_result *R)
{
    static const char *name[SD_PHASES] = {"search", "density/h", "forces", "rest"};
    static const char *what[SD_PHASES] = {"sph_nsearch_skin; stale lists: radii, sph_nsearch_build, _lists (_fill)",
                                          "sph_h_solve and the re-searches it asked for, sph_nsearch_prune",
                                          "c_s and A, sph_batch_source, the pair loop, the switches",
                                          "h_min and dt, kicks, drift, progress line"};
    const sd_prof *Q = &R->prof;
    const double n = (double)R->n, ps = n * (double)Q->steps;
    double total = 0;
    int p;
    if (Q->steps == 0) return;
    for (p = 0; p < SD_PHASES; ++p) total += Q->t[p];
    printf("profile: %ld steps of %ld particles, %d thread%s, fast loops at %s; wall time per particle and step:\n",
           Q->steps, (long)R->n, Q->threads, Q->threads == 1 ? "" : "s", sph_isa_name(sph_isa()));
    for (p = 0; p < SD_PHASES; ++p)
        printf("  %-28s %10.3f us %5.1f %%  %s\n", name[p], 1e6 * Q->t[p] / ps, 100 * Q->t[p] / total, what[p]);
    printf("  %-28s %10.3f us 100.0 %%  %.3f s in the step loop\n", "total", 1e6 * total / ps, total);
    printf("  %-28s %10.2f     (the kept symmetric list at kappa (1 + skin) h, self included: the sums of the h solve)\n",
           "list entries per particle", Q->entries / ps);
    printf("  %-28s %10.2f     (within kappa max(h_i, h_j): the force loop visits each from both ends)\n",
           "pairs per particle", Q->pairs / ps);
    if (Q->samples > 0)
        printf("  %-28s %10.2f     (%.2f per list entry; sph_nsearch_stats on %ld of the steps, untimed)\n",
               "candidates per particle", Q->candidates / (n * (double)Q->samples), Q->candidates / Q->sampled, Q->samples);
    printf("  %-28s %10.0f     (fields %.0f, lists %.0f, search workspace %.0f)\n", "bytes per particle",
           Q->bytes[0] + Q->bytes[1] + Q->bytes[2], Q->bytes[0], Q->bytes[1], Q->bytes[2]);
    printf("  %-28s %10ld     (%.2f steps per search; the lists are kept while they serve every h)\n", "searches",
           Q->searches, (double)Q->steps / (double)(Q->searches > 0 ? Q->searches : 1));
    printf("  %-28s %10ld     (their time counts to density/h)\n", "re-searches", Q->researches);
}

static void sd_print(const sd_param *P, const sd_result *R)
{
    printf("nx %4d  N %7ld  steps %5ld  L1 rho %.4e  v %.4e  P %.4e  h: %.2f density sums per particle and solve "
           "(max %d), %ld re-searches  |dE|/E %.1e  |P_x|/sum m|v| %.1e  %.1f s\n",
           P->nx, (long)R->n, R->steps, R->l1_rho, R->l1_v, R->l1_p, (double)R->sums / ((double)R->solves * R->n),
           R->max_sums, R->researches, R->energy_drift, R->momentum, R->seconds);
    if (P->profile) sd_print_profile(R);
}

/* Toro (2009) Table 4.3, test 1 (Sod's problem with gamma = 1.4): p* = 0.30313, u* = 0.92745,
 * rho*_L = 0.42632, rho*_R = 0.26557 (five figures as published). */
static int sd_check_riemann(void)
{
    const sd_state L = {1, 0, 1}, R = {0.125, 0, 0.1};
    double ps = 0, us = 0;
    sd_state wl, wr;
    int ok = sd_star(L, R, 1.4, &ps, &us) == 0;
    wl = sd_sample(L, R, 1.4, ps, us, us - 1e-9);
    wr = sd_sample(L, R, 1.4, ps, us, us + 1e-9);
    ok = ok && fabs(ps - 0.30313) < 1e-5 && fabs(us - 0.92745) < 1e-5 && fabs(wl.rho - 0.42632) < 1e-5 &&
         fabs(wr.rho - 0.26557) < 1e-5;
    printf("Riemann solver, gamma 1.4: p* %.5f u* %.5f rho*L %.5f rho*R %.5f (Toro Table 4.3: 0.30313 0.92745 "
           "0.42632 0.26557): %s\n",
           ps, us, wl.rho, wr.rho, ok ? "pass" : "FAIL");
    return ok;
}

/* Writes the exact profile at t_end over |x| <= 0.5 (1001 points). */
static int sd_write_exact(const sd_param *P, const char *path)
{
    const sd_state L = {1, 0, 1}, R = {0.125, 0, 0.1};
    double ps, us;
    FILE *f = fopen(path, "w");
    int i;
    if (f == NULL || sd_star(L, R, P->gamma, &ps, &us) != 0) {
        if (f != NULL) fclose(f);
        return -1;
    }
    fprintf(f, "x,rho,v,P\n");
    for (i = 0; i <= 1000; ++i) {
        const double x = -0.5 + i / 1000.0;
        const sd_state w = sd_sample(L, R, P->gamma, ps, us, x / P->t_end);
        fprintf(f, "%.5f,%.6f,%.6f,%.6f\n", ex_csv_fixed(x, 5), ex_csv_fixed(w.rho, 6), ex_csv_fixed(w.u, 6),
                ex_csv_fixed(w.p, 6));
    }
    return fclose(f) == 0 ? 0 : -1;
}

/* The checks that join two options (each option's own range is ex_parse_args'):
 * the refusal names the option and what it accepts. */
static int sd_validate(const sd_param *P)
{
    const double ny_min = sd_ny_min(P, (double)sph_kernel_support((sph_kernel)sph_kernel_from_name(P->kernel)));
    if (P->alpha_min > P->alpha_max) {
        fprintf(stderr, "%s: --alpha-min %g refused: accepted 0 <= alpha-min <= alpha-max = %g\n", ex_prog(), P->alpha_min,
                P->alpha_max);
        return -1;
    }
    if (P->ny < ny_min) { /* the search radius kappa 1.15 h of the right lattice (h = eta 2 dx) within half the cross-section */
        fprintf(stderr, "%s: --ny %d refused: accepted ny >= %.1f, the cross-section must exceed 2 kappa 1.15 h of the "
                "right lattice for --kernel %s, --eta %g, --lattice %s (0: the fewest)\n", ex_prog(), P->ny, ny_min,
                P->kernel, P->eta, P->lattice);
        return -1;
    }
    return 0;
}

/* A failed run's status as the option that caused it. */
static void sd_explain(const sd_param *P, int st)
{
    if (st == EX_ENOMEM)
        fprintf(stderr, "%s: out of memory for --nx %d --ny %d (%.0f particles): lower --nx\n", ex_prog(), P->nx, P->ny,
                sd_particles(P));
    else if (st == SPH_EPERIOD)
        fprintf(stderr, "%s: a smoothing length grew beyond half the cross-section of --ny %d: raise --ny\n", ex_prog(),
                P->ny);
    else if (st == SD_EHSOLVE)
        fprintf(stderr, "%s: the smoothing lengths did not converge with --eta %g, --kernel %s\n", ex_prog(), P->eta,
                P->kernel);
    else if (st == SD_EEXACT)
        fprintf(stderr, "%s: no exact Riemann solution for these states (--gamma %g)\n", ex_prog(), P->gamma);
    else if (st != EX_EGROWTH && st != EX_EWRITE && st != SD_EREFUSED) /* those printed theirs where they arose */
        fprintf(stderr, "%s: nx %d: %s\n", ex_prog(), P->nx, ex_strerror(st));
}

/* One run into out/sod_nx<nx>.csv; 0 or a status. */
static int sd_run_to(const sd_param *P, const char *out, sd_result *R)
{
    char path[1100], label[64];
    FILE *f;
    int st;
    snprintf(path, sizeof path, "%s/sod_nx%d.csv", out, P->nx);
    f = fopen(path, "w");
    if (f == NULL) {
        fprintf(stderr, "sod_shock: cannot write %s\n", path);
        return EX_EWRITE;
    }
    fprintf(f, "x,rho,v,P,u,alpha,exact rho,exact v,exact P\n");
    snprintf(label, sizeof label, "sod nx %d", P->nx);
    st = sd_run(P, R, f, label);
    if (fclose(f) != 0) st = st == SPH_OK ? EX_EWRITE : st;
    if (st == SPH_OK) sd_print(P, R);
    return st;
}

/* nx = 16, 24, 32, 48: table with orders into dir/sod_shock.md. */
static int sd_study(const sd_param *P0, const char *dir, const char *out)
{
    enum { NRES = 4 };
    const int nxs[NRES] = {16, 24, 32, 48};
    sd_result R[NRES];
    char path[1100];
    FILE *md;
    int r, st;
    for (r = 0; r < NRES; ++r) {
        sd_param P = *P0;
        P.nx = nxs[r];
        if ((st = sd_run_to(&P, out, &R[r])) != SPH_OK) {
            sd_explain(&P, st);
            return -1;
        }
    }
    snprintf(path, sizeof path, "%s/sod_shock.md", dir);
    if ((md = fopen(path, "w")) == NULL) return -1;
    fprintf(md, "# Sod shock tube in 3-D (examples/sod_shock.c)\n\n"
                "Written by `make plots-sod` (`build/sod_shock --study %s`). gamma = %g, t = %g, %s kernel, eta = %g, "
                "%s lattices, %d x %d cells across the tube on the left, CFL %g, viscosity switch %s (av-length %g, "
                "Balsara %s), alpha in [%g, %g], beta = %g, conductivity %s, alpha_u = %g (beta_u %g). L1 = mean over the particles with |x| <= 0.5 of "
                "|q_i - q_exact(x_i)|; order = log(L1 ratio) / log(nx ratio) of successive rows.\n\n"
                "| nx | particles | steps | L1 rho | order | L1 v_x | order | L1 P | order | density sums per "
                "particle and solve (max) | re-searches | abs(dE)/E | run time (s) |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
            dir, P0->gamma, P0->t_end, P0->kernel, P0->eta, P0->lattice, P0->ny, P0->ny, P0->cfl, P0->av_switch, P0->av_length,
            P0->balsara ? "on" : "off", P0->alpha_min, P0->alpha_max, P0->beta, P0->cond, P0->alpha_u, P0->beta_u);
    for (r = 0; r < NRES; ++r) {
        char o[3][16] = {"-", "-", "-"};
        if (r > 0) {
            const double q = log((double)nxs[r] / nxs[r - 1]);
            snprintf(o[0], sizeof o[0], "%.2f", log(R[r - 1].l1_rho / R[r].l1_rho) / q);
            snprintf(o[1], sizeof o[1], "%.2f", log(R[r - 1].l1_v / R[r].l1_v) / q);
            snprintf(o[2], sizeof o[2], "%.2f", log(R[r - 1].l1_p / R[r].l1_p) / q);
        }
        fprintf(md, "| %d | %ld | %ld | %.4f | %s | %.4f | %s | %.4f | %s | %.2f (%d) | %ld | %.1e | %.0f |\n", nxs[r],
                (long)R[r].n, R[r].steps, R[r].l1_rho, o[0], R[r].l1_v, o[1], R[r].l1_p, o[2],
                (double)R[r].sums / ((double)R[r].solves * R[r].n), R[r].max_sums, R[r].researches,
                R[r].energy_drift, R[r].seconds);
    }
    fprintf(md, "\nProfiles: `%s/sod_nx*.csv`; plot: `plots/sod_shock.png`.\n", out);
    return fclose(md) == 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    sd_param P;
    sd_result R;
    const char *out = "build/sod_shock_out", *study = NULL, *isa = "auto";
    int threads = 0, check = 0, st;
    char nx_help[200];
    const ex_arg opt[] = {
        {"nx", nx_help, NULL, &P.nx, NULL, NULL, 8, SD_NX_MAX, EX_EVEN, NULL},
        {"ny", "left lattice: cells across the tube (right: ny / 2; 0: the fewest allowed)", NULL, &P.ny, NULL, NULL, 4,
         64, EX_EVEN | EX_OR_ZERO, NULL},
        {"lattice", "fcc (close packed, 4 per cell) or cubic", NULL, NULL, &P.lattice, NULL, 0, 0, 0, "fcc|cubic"},
        {"kernel", "smoothing kernel", NULL, NULL, &P.kernel, NULL, 0, 0, 0, ex_kernel_choices()},
        {"gamma", "adiabatic index (SWIFT and Phantom: 5/3; Sod 1978: 1.4)", &P.gamma, NULL, NULL, NULL, 1, 3,
         EX_OPEN_LO, NULL},
        {"t-end", "end time (the waves of x = 0 and x = +-1 meet after 0.25)", &P.t_end, NULL, NULL, NULL, 0, 0.25,
         EX_OPEN_LO, NULL},
        {"eta", "h = eta (m / rho)^(1/3)", &P.eta, NULL, NULL, NULL, 0.9, 4, 0, NULL},
        {"cfl", "dt = cfl h_min / v_sig,max", &P.cfl, NULL, NULL, NULL, 0, 0.5, EX_OPEN_LO, NULL},
        {"alpha-min", "viscosity switch: alpha far from shocks (at most alpha-max)", &P.alpha_min, NULL, NULL, NULL, 0,
         4, 0, NULL},
        {"alpha-max", "viscosity switch: alpha in shocks", &P.alpha_max, NULL, NULL, NULL, 0, 4, 0, NULL},
        {"beta", "signal-velocity viscosity beta", &P.beta, NULL, NULL, NULL, 0, 8, 0, NULL},
        {"alpha-u", "artificial conductivity: alpha_D,max of the SPHENIX switch, or price08's constant alpha_u (0: none)",
         &P.alpha_u, NULL, NULL, NULL, 0, 4, 0, NULL},
        {"switch", "viscosity switch: sphenix (Borrow et al. 2022) or mm97 (Morris & Monaghan 1997)", NULL, NULL,
         &P.av_switch, NULL, 0, 0, 0, "sphenix|mm97"},
        {"av-length", "sphenix switch: alpha decays at the rate av-length c / H (H: kernel support)", &P.av_length, NULL,
         NULL, NULL, 0, 1, EX_OPEN_LO, NULL},
        {"balsara", "1: Balsara limiter B_i on alpha, 0: none", NULL, &P.balsara, NULL, NULL, 0, 1, 0, NULL},
        {"conductivity", "sphenix (switched alpha_D, Borrow et al. 2022) or price08 (constant alpha-u, Price 2008)", NULL,
         NULL, &P.cond, NULL, 0, 0, 0, "sphenix|price08"},
        {"beta-u", "sphenix conductivity: source coefficient beta_D of d alpha_D / dt", &P.beta_u, NULL, NULL, NULL, 0, 8,
         0, NULL},
        {"skin", "lists searched at kappa (1 + skin) h and kept over steps while they serve every h", &P.skin, NULL,
         NULL, NULL, 0, 1, 0, NULL},
        {"out", "output directory (profiles, exact solution)", NULL, NULL, &out, NULL, 0, 0, 0, NULL},
        {"threads", "OpenMP threads (0: the runtime's default)", NULL, &threads, NULL, NULL, 0, 1024, 0, NULL},
        {"isa", "instruction set of the fast loops: auto (the CPU's best this build has), portable, avx2 or avx512",
         NULL, NULL, &isa, NULL, 0, 0, 0, "auto|portable|avx2|avx512"},
        {"check", "nx = 16 run; exit 1 if it misses its validation bounds", NULL, NULL, NULL, &check, 0, 0, 0, NULL},
        {"study", "nx = 16, 24, 32, 48: the error table into this directory", NULL, NULL, &study, NULL, 0, 0, 0, NULL},
        {"profile", "print the step's time per phase, pairs and bytes per particle", NULL, NULL, NULL, &P.profile, 0, 0,
         0, NULL},
    };
    P.nx = 32, P.ny = 0, P.kernel = "cubic", P.lattice = "fcc", P.gamma = 5.0 / 3.0, P.t_end = 0.2, P.eta = 1.2, P.cfl = 0.3;
    P.alpha_min = 0, P.alpha_max = 2, P.beta = 3, P.alpha_u = 1, P.skin = 0.1, P.profile = 0;
    P.av_switch = "sphenix", P.cond = "sphenix", P.av_length = 0.25, P.balsara = 1, P.beta_u = 1;
    { /* what the top of --nx needs at the defaults: memory grows as nx ny^2 */
        sd_param Q = P;
        char b[32];
        Q.nx = SD_NX_MAX, Q.ny = sd_ny_auto(&Q);
        ex_bytes_text(sd_particles(&Q) * sd_bytes_per_particle(&Q), b, sizeof b);
        snprintf(nx_help, sizeof nx_help, "left lattice: cells per unit length (right: nx / 2); memory grows as nx ny^2: "
                 "--nx %d needs %s at ny %d", SD_NX_MAX, b, Q.ny);
    }
    st = ex_parse_args(argc, argv, "3-D Sod shock tube with adaptive h and grad-h terms against the exact Riemann "
                       "solution; " SD_BOUNDS, opt, (int)(sizeof opt / sizeof opt[0]));
    if (st != 0) return st > 0 ? 0 : 2;
    if (check) P.nx = 16;
    if (P.ny == 0) P.ny = sd_ny_auto(&P);
    if (sd_validate(&P) != 0) return 2;
    if (strcmp(isa, "auto") != 0) { /* the level the header's loops and sd_rows run at (sph_isa) */
        int l;
        for (l = SPH_ISA_PORTABLE; l <= SPH_ISA_AVX512 && strcmp(isa, sph_isa_name(l)) != 0; ++l) {}
        if ((st = sph_isa_set(l)) != SPH_OK) {
            fprintf(stderr, "%s: --isa %s refused: %s\n", ex_prog(), isa, sph_strerror(st));
            return 2;
        }
    }
#ifdef _OPENMP
    if (threads > 0) omp_set_num_threads(threads);
#endif
    if (check) {
        int ok = sd_check_riemann();
        st = sd_run(&P, &R, NULL, NULL);
        if (st != SPH_OK) {
            sd_explain(&P, st);
            printf("sod_shock --check: run failed (status %d, explained above)\n", st);
            return 1;
        }
        sd_print(&P, &R);
        /* L1 bounds: 1.5 times the figures of the nx = 16 run (0.0174, 0.0363, 0.0192), a regression guard; the
           conservation and iteration bounds are properties of the scheme */
        ok = ok && R.l1_rho < 0.026 && R.l1_v < 0.055 && R.l1_p < 0.029 && R.energy_drift < 1e-3 && R.momentum < 1e-10 &&
             R.max_sums <= 10;
        printf("sod_shock --check: L1 rho %.4f (bound 0.026), v %.4f (0.055), P %.4f (0.029), energy drift %.1e (1e-3), "
               "momentum %.1e (1e-10), most density sums %d (10): %s\n",
               R.l1_rho, R.l1_v, R.l1_p, R.energy_drift, R.momentum, R.max_sums, ok ? "pass" : "FAIL");
        return ok ? 0 : 1;
    }
    if (ex_mkdir_p(out) != 0) {
        fprintf(stderr, "sod_shock: cannot create %s\n", out);
        return 2;
    }
    {
        char path[1100];
        snprintf(path, sizeof path, "%s/sod_exact.csv", out);
        if (sd_write_exact(&P, path) != 0) {
            fprintf(stderr, "sod_shock: cannot write %s\n", path);
            return 1;
        }
    }
    if (study != NULL) return sd_study(&P, study, out) == 0 ? 0 : 1;
    st = sd_run_to(&P, out, &R);
    if (st != SPH_OK) {
        sd_explain(&P, st);
        return 1;
    }
    printf("wrote %s/sod_nx%d.csv and %s/sod_exact.csv\n", out, P.nx, out);
    return 0;
}
