/* examples/taylor_green.c - 2-D periodic Taylor-Green vortex at Re = 100 with
 * weakly compressible SPH built on sph_kernel.h (docs/examples.md,
 * "Taylor-Green vortex").
 *
 * Flow in the periodic unit square (L = 1, U = 1, k = 2 pi / L, nu = U L / Re):
 *   u = -U cos(k x) sin(k y) e^{-2 nu k^2 t},   v = U sin(k x) cos(k y) e^{-2 nu k^2 t},
 *   p = -(rho0 U^2 / 4) (cos 2kx + cos 2ky) e^{-4 nu k^2 t},
 * so the kinetic energy decays as E(t) = E(0) exp(-4 nu k^2 t) = E(0) exp(-16 pi^2 nu t / L^2).
 *
 * Equations (operators of docs/operators.md):
 *   drho_i/dt = -rho_i div v_i              (O10) difference, or (O18) corrected
 *   dv_i/dt   = -grad p_i / rho_i + nu lap v_i
 *               grad p: (O8) pressure form, (O5) difference or (O7) corrected;
 *               lap v: (O12) per component (Brookshaw / Morris)
 *   p_i = c0^2 (rho_i - rho0) + p_b         linear equation of state, c0 = 10 U
 * Default: the particles stay on their start positions (an Eulerian frame),
 * the convective terms -v.grad v and -v.grad rho come from the gradient
 * operators (O17 / O5 / O7). --lagrangian moves the particles with the
 * transport-velocity formulation of Adami, Hu & Adams (2013, J. Comput.
 * Phys. 241, 292-307): density by summation (O2), particles advected with
 * v~ = v + (dt/2) b, b the background-pressure term, and the extra momentum
 * term of A = rho v (v~ - v) (tg_tvf_pairs); h = 2 dx by default there.
 * --lagrangian --plain is standard WCSPH on moving particles (continuity,
 * particle shifting --shift): the hyperbolic stagnation points of this flow
 * squeeze a lattice into lines within t ~ 0.2, and the table in docs shows
 * what that does.
 * Symplectic kick-drift-kick (Adami et al. 2013 ordering): v by dt/2, x by dt,
 * rho by dt with the mid-step velocity, forces, v by dt/2;
 * dt = min(cfl h / (c0 + U), 0.125 h^2 / nu), cfl = 0.25. Neighbour lists from the
 * library's cell-list search in the periodic box (rebuilt every step when the
 * particles move).
 *
 *   ./taylor_green                    default run: 40 x 40, Wendland C2, pressure form, fixed particles
 *   ./taylor_green --lagrangian       moving particles (transport velocity)
 *   ./taylor_green --check            short coarse runs (fixed, moving) with validation bounds (make test)
 *   ./taylor_green --study docs/results
 *                                     resolution / kernel / scheme table into docs/results/
 */
#include "example_io.h"

#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define PI 3.14159265358979323846
/* Bounds every run stays within, else it stops with exit 1: the flow decays,
 * so its kinetic energy may exceed E(0) only by round-off and start-up
 * transients (0.14 % at most in the --check and study runs), and a relative
 * L2 velocity error of 1 means the error is as large as the flow itself. */
#define TG_ENERGY_TOL 0.01
#define TG_L2_MAX 1.0
#define TG_BOUNDS "a run stops with exit 1 when its kinetic energy exceeds 1.01 E(0) or its relative L2 velocity error exceeds 1"

typedef struct {
    int n;             /* particles per side */
    const char *kernel;
    const char *scheme; /* pressure | difference | corrected */
    double hdx;        /* h / dx */
    double t_end, re, c0, pb, pt, perturb, shift;
    int frames;        /* VTK frames (0: none) */
    int lagrangian;    /* 1: particles move with the flow; 0: fixed particles, convection by operators */
    int plain;         /* moving particles without the transport velocity (standard WCSPH + shifting) */
    double cfl;        /* dt = cfl h / (c0 + U) (acoustic limit) */
} tg_param;

typedef struct {
    double rate_exact, rate_fit, rate_err, l2, e_ratio, seconds;
    long steps;
} tg_result;

/* The analytic velocity at (x, y, t). */
static void tg_exact(double x, double y, double t, double nu, double *u, double *v)
{
    const double k = 2 * PI, d = exp(-2 * nu * k * k * t);
    *u = -cos(k * x) * sin(k * y) * d;
    *v = sin(k * x) * cos(k * y) * d;
}

/* Simulation state (structure of arrays). */
typedef struct {
    sph_idx n;
    sph_real *x, *y, *u, *v, *rho, *p, *V, *m, *du, *dv, *drho, *gp, *lu, *lv, *div, *one, *T;
    sph_real *bu, *bv; /* transport-velocity formulation: the background-pressure acceleration */
} tg_state;

static sph_real *tg_alloc(sph_idx n) { return (sph_real *)ex_calloc((size_t)n * 2, sizeof(sph_real), NULL); }

/* The rates of the two halves of a step (Adami et al. 2013 ordering):
 * phase 0 rebuilds the lists (moving particles) and writes drho/dt,
 * phase 1 writes the accelerations dv/dt from the current rho. */
static int tg_rates(tg_state *S, ex_neighbours *L, const tg_param *P, sph_kernel k, double h, double nu,
                    const sph_box *box, int phase, sph_idx *n_fallback)
{
    const double rho0 = 1, kappa = sph_kernel_support(k);
    const int corr = strcmp(P->scheme, "corrected") == 0, pres = strcmp(P->scheme, "pressure") == 0;
    const sph_scheme gs = corr ? SPH_SCHEME_CORRECTED : pres ? SPH_SCHEME_PRESSURE : SPH_SCHEME_DIFFERENCE;
    const sph_scheme ds = corr ? SPH_SCHEME_CORRECTED : SPH_SCHEME_DIFFERENCE;
    sph_view X = sph_view_soa(S->x, S->y, NULL), vel = sph_view_soa(S->u, S->v, NULL);
    sph_ctx c;
    sph_idx i, nf = 0;
    int st;
    for (i = 0; i < S->n; ++i) {
        S->p[i] = P->c0 * P->c0 * (S->rho[i] - rho0) + P->pb;
        S->V[i] = S->m[i] / S->rho[i];
    }
    if (phase == 0 && (P->lagrangian || L->list.offset == NULL) &&
        (st = ex_neighbours_update(L, 2, X, S->n, S->n, h, kappa, box)) != SPH_OK)
        return st;
    c = sph_ctx_init(k, 2, h, &L->list, X);
    c.box = box;
    c.V = sph_view_soa(S->V, NULL, NULL);
    c.m = sph_view_soa(S->m, NULL, NULL);
    c.rho = sph_view_soa(S->rho, NULL, NULL);
    c.validate = SPH_VALIDATE_ARGS; /* the search's lists are well formed by construction */
    if (phase == 0) { /* drho/dt = -rho div v (O10 / O18), fixed particles also - v.grad rho (O5 / O7) */
        if ((st = sph_divergence(&c, ds, vel, sph_view_none(), sph_out_soa(S->div, NULL, NULL), &nf)) != SPH_OK)
            return st;
        for (i = 0; i < S->n; ++i) S->drho[i] = -S->rho[i] * S->div[i];
        if (!P->lagrangian) {
            if ((st = sph_gradient(&c, ds, sph_view_soa(S->rho, NULL, NULL), sph_view_none(),
                                   sph_out_interleaved(S->gp, 2), NULL)) != SPH_OK)
                return st;
            for (i = 0; i < S->n; ++i) S->drho[i] -= S->gp[2 * i] * S->u[i] + S->gp[2 * i + 1] * S->v[i];
        }
        if (n_fallback != NULL) *n_fallback += nf;
        return SPH_OK;
    }
    /* dv/dt = -grad p / rho (O8 / O5 / O7) + nu lap v (O12), fixed particles also - v.grad v (O17) */
    if ((st = sph_gradient(&c, gs, sph_view_soa(S->p, NULL, NULL), sph_view_none(),
                           sph_out_interleaved(S->gp, 2), NULL)) != SPH_OK ||
        (st = sph_laplacian(&c, sph_view_soa(S->u, NULL, NULL), sph_view_none(), sph_out_soa(S->lu, NULL, NULL))) !=
            SPH_OK ||
        (st = sph_laplacian(&c, sph_view_soa(S->v, NULL, NULL), sph_view_none(), sph_out_soa(S->lv, NULL, NULL))) !=
            SPH_OK)
        return st;
    for (i = 0; i < S->n; ++i) {
        S->du[i] = -S->gp[2 * i] / S->rho[i] + nu * S->lu[i];
        S->dv[i] = -S->gp[2 * i + 1] / S->rho[i] + nu * S->lv[i];
    }
    if (!P->lagrangian) {
        if ((st = sph_gradient_vector(&c, ds, vel, sph_view_none(), S->T, 4, NULL)) != SPH_OK) return st;
        for (i = 0; i < S->n; ++i) {
            const sph_real *T = S->T + 4 * i;
            S->du[i] -= T[0] * S->u[i] + T[1] * S->v[i];
            S->dv[i] -= T[2] * S->u[i] + T[3] * S->v[i];
        }
    }
    return SPH_OK;
}

/* The pair sums of the transport-velocity formulation (Adami, Hu & Adams
 * 2013, J. Comput. Phys. 241, 292-307, eqs. (8), (10) and (12)) with w_ij = V_i^2 + V_j^2:
 *   m_i dv_i/dt = sum_j w_ij [ -p_ij grad_i W_ij + (A_i + A_j)/2 . grad_i W_ij + eta (v_i - v_j) F_ij ],
 *   p_ij = (rho_j p_i + rho_i p_j) / (rho_i + rho_j),  A = rho v (v~ - v) (a 2 x 2 tensor in T),
 *   m_i b_i    = -p_t sum_j w_ij grad_i W_ij   (background pressure p_t: v~ = v + dt b),
 * built from the pair terms of docs/operators.md: (O1) kernel, (O4) for the
 * w_ij-weighted gradients, (O9) for each row of A . grad W and (O12) for
 * the viscous term (F_ij = (1/r) dW/dr, so no division by r). With
 * pressure = 0 the pressure term is left out (the caller adds -grad p / rho
 * from the operators instead). */
static void tg_tvf_pairs(const tg_state *S, const sph_neighbours *list, sph_kernel k, double h, double eta,
                         double p_t, int pressure, const sph_box *box)
{
    sph_idx i;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) /* a gather: each target its own sums, any thread count gives the same bits */
#endif
    for (i = 0; i < S->n; ++i) {
        const double Vi = S->m[i] / S->rho[i];
        sph_real acc[2] = {0, 0}, b[2] = {0, 0};
        sph_off o;
        for (o = list->offset[i]; o < list->offset[i + 1]; ++o) {
            const sph_idx j = list->index[o];
            const double Vj = S->m[j] / S->rho[j], w = Vi * Vi + Vj * Vj;
            sph_real dx[2], Ar[2];
            sph_pair pk;
            int a;
            if (j == i) continue;
            dx[0] = sph_box_delta(box, 0, S->x[i] - S->x[j]), dx[1] = sph_box_delta(box, 1, S->y[i] - S->y[j]);
            pk = sph_pair_kernel(k, 2, dx, h); /* (O1) */
            if (pressure) /* (O4) with weight w_ij and f = -p_ij */
                sph_pair_grad_standard(2, w, -(S->rho[j] * S->p[i] + S->rho[i] * S->p[j]) / (S->rho[i] + S->rho[j]),
                                       pk.F, dx, acc);
            for (a = 0; a < 2; ++a) { /* (O9): row a of (A_i + A_j)/2 . grad W */
                Ar[0] = S->T[4 * i + 2 * a] + S->T[4 * j + 2 * a], Ar[1] = S->T[4 * i + 2 * a + 1] + S->T[4 * j + 2 * a + 1];
                acc[a] += sph_pair_div_standard(2, 0.5 * w, Ar, pk.F, dx);
            }
            acc[0] += eta * sph_pair_laplacian(0.5 * w, S->u[i], S->u[j], pk.F); /* (O12) */
            acc[1] += eta * sph_pair_laplacian(0.5 * w, S->v[i], S->v[j], pk.F);
            sph_pair_grad_standard(2, w, 1, pk.F, dx, b); /* (O4), f = 1 */
        }
        S->du[i] = acc[0] / S->m[i], S->dv[i] = acc[1] / S->m[i];
        S->bu[i] = -p_t * b[0] / S->m[i], S->bv[i] = -p_t * b[1] / S->m[i];
    }
}

/* The rates of the transport-velocity formulation at the positions of step
 * n+1: lists, density by summation (O2), p from the equation of state, the
 * tensor A = rho v (v~ - v) from the half-step transport velocity v~ - v =
 * (dt/2) b of the previous evaluation, then the pair sums of tg_tvf_pairs.
 * The pressure gradient: Adami's pair form (scheme pressure) or -grad p / rho
 * from (O5) difference / (O7) corrected. */
static int tg_tvf_rates(tg_state *S, ex_neighbours *L, const tg_param *P, sph_kernel k, double h, double nu,
                        double dt, const sph_box *box, sph_idx *n_fallback)
{
    const double rho0 = 1, p_t = P->pt >= 0 ? P->pt : rho0 * P->c0 * P->c0;
    const int pres = strcmp(P->scheme, "pressure") == 0;
    sph_view X = sph_view_soa(S->x, S->y, NULL);
    sph_ctx c;
    sph_idx i, nf = 0;
    int st;
    if ((st = ex_neighbours_update(L, 2, X, S->n, S->n, h, sph_kernel_support(k), box)) != SPH_OK) return st;
    c = sph_ctx_init(k, 2, h, &L->list, X);
    c.box = box;
    c.m = sph_view_soa(S->m, NULL, NULL);
    c.V = sph_view_soa(S->V, NULL, NULL);
    c.validate = SPH_VALIDATE_ARGS;
    if ((st = sph_density(&c, sph_out_soa(S->rho, NULL, NULL))) != SPH_OK) return st; /* (O2) */
    for (i = 0; i < S->n; ++i) {
        const double tu = 0.5 * dt * S->bu[i], tv = 0.5 * dt * S->bv[i];
        sph_real *T = S->T + 4 * i;
        S->p[i] = P->c0 * P->c0 * (S->rho[i] - rho0) + P->pb;
        S->V[i] = S->m[i] / S->rho[i];
        T[0] = S->rho[i] * S->u[i] * tu, T[1] = S->rho[i] * S->u[i] * tv;
        T[2] = S->rho[i] * S->v[i] * tu, T[3] = S->rho[i] * S->v[i] * tv;
    }
    if (!pres && (st = sph_gradient(&c, strcmp(P->scheme, "corrected") == 0 ? SPH_SCHEME_CORRECTED
                                                                             : SPH_SCHEME_DIFFERENCE,
                                    sph_view_soa(S->p, NULL, NULL), sph_view_none(), sph_out_interleaved(S->gp, 2),
                                    &nf)) != SPH_OK)
        return st;
    tg_tvf_pairs(S, &L->list, k, h, rho0 * nu, p_t, pres, box);
    if (!pres)
        for (i = 0; i < S->n; ++i) S->du[i] -= S->gp[2 * i] / S->rho[i], S->dv[i] -= S->gp[2 * i + 1] / S->rho[i];
    if (n_fallback != NULL) *n_fallback += nf;
    return SPH_OK;
}

/* Particle shifting (Xu et al. 2009, Lind et al. 2012): move each particle
 * down the gradient of its kernel sum C_i = sum_j V_j W_ij (O4 with f = 1),
 * dr_i = -D h^2 grad C_i (at most 0.2 dx), and carry u, v, rho with it by one
 * Taylor term, f += dr . grad f (O7, corrected: exact for linear fields).
 * Uses the lists of the last rate evaluation (positions unchanged since). */
static int tg_shift(tg_state *S, const ex_neighbours *L, sph_kernel k, double h, double dx, double D,
                    const sph_box *box)
{
    sph_real *f[3];
    sph_view X = sph_view_soa(S->x, S->y, NULL);
    sph_ctx c = sph_ctx_init(k, 2, h, &L->list, X);
    sph_idx i;
    int st, q;
    c.box = box;
    c.V = sph_view_soa(S->V, NULL, NULL);
    c.validate = SPH_VALIDATE_ARGS;
    f[0] = S->u, f[1] = S->v, f[2] = S->rho;
    if ((st = sph_gradient(&c, SPH_SCHEME_STANDARD, sph_view_soa(S->one, NULL, NULL), sph_view_none(),
                           sph_out_soa(S->lu, S->lv, NULL), NULL)) != SPH_OK)
        return st;
    for (i = 0; i < S->n; ++i) { /* dr into (lu, lv), limited to 0.2 dx */
        double ax = -D * h * h * S->lu[i], ay = -D * h * h * S->lv[i], a = sqrt(ax * ax + ay * ay);
        if (a > 0.2 * dx) ax *= 0.2 * dx / a, ay *= 0.2 * dx / a;
        S->lu[i] = ax, S->lv[i] = ay;
    }
    for (q = 0; q < 3; ++q) {
        if ((st = sph_gradient(&c, SPH_SCHEME_CORRECTED, sph_view_soa(f[q], NULL, NULL), sph_view_none(),
                               sph_out_interleaved(S->gp, 2), NULL)) != SPH_OK)
            return st;
        for (i = 0; i < S->n; ++i) f[q][i] += S->gp[2 * i] * S->lu[i] + S->gp[2 * i + 1] * S->lv[i];
    }
    for (i = 0; i < S->n; ++i) {
        S->x[i] += S->lu[i], S->y[i] += S->lv[i];
        S->x[i] -= floor(S->x[i]), S->y[i] -= floor(S->y[i]);
    }
    return SPH_OK;
}

/* Kinetic energy and the L2 velocity error against the analytic field,
 * relative: sqrt(sum |v - v_a|^2 / sum |v_a|^2). */
static double tg_energy(const tg_state *S, double t, double nu, double *l2)
{
    double e = 0, num = 0, den = 0, ua, va;
    sph_idx i;
    for (i = 0; i < S->n; ++i) {
        e += 0.5 * S->m[i] * (S->u[i] * S->u[i] + S->v[i] * S->v[i]);
        tg_exact(S->x[i], S->y[i], t, nu, &ua, &va);
        num += (S->u[i] - ua) * (S->u[i] - ua) + (S->v[i] - va) * (S->v[i] - va);
        den += ua * ua + va * va;
    }
    *l2 = sqrt(num / den);
    return e;
}

/* The fields of a frame, also the ones checked for NaN and Inf every step. */
static void tg_fields(const tg_state *S, ex_field f[3])
{
    f[0].name = "velocity", f[0].v = sph_view_soa(S->u, S->v, NULL), f[0].ncomp = 2;
    f[1].name = "pressure", f[1].v = sph_view_soa(S->p, NULL, NULL), f[1].ncomp = 1;
    f[2].name = "density", f[2].v = sph_view_soa(S->rho, NULL, NULL), f[2].ncomp = 1;
}

/* One run. csv (may be NULL): time series t, E/E0, exact E/E0, L2 error.
 * frames (may be NULL): the VTK series. Returns 0 or a negative status;
 * a field turning NaN or Inf stops the run (SPH_ENONFINITE, no further frames). */
static int tg_run(const tg_param *P, tg_result *R, FILE *csv, ex_series *frames, const char *label)
{
    const int n = P->n, kid = sph_kernel_from_name(P->kernel);
    const double L = 1, U = 1, rho0 = 1, dx = L / n, h = P->hdx * dx, nu = U * L / P->re;
    const double dt0 = fmin(P->cfl * h / (P->c0 + U), 0.125 * h * h / nu);
    const double steps_d = ceil(P->t_end / dt0 - 1e-9);
    const long steps = steps_d > 0 && steps_d < 1e9 ? (long)steps_d : 1;
    const double dt = P->t_end / (double)steps;
    const sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 0}};
    const int tvf = P->lagrangian && !P->plain;
    double e0 = 0, l2 = 0, st_t = 0, st_y = 0, st_tt = 0, st_ty = 0, cnt = 0, t0 = ex_now();
    ex_neighbours NL;
    ex_progress prog = ex_progress_start();
    tg_state S;
    sph_idx i, nfb = 0;
    long s;
    int st = SPH_OK, frame = 0;
    uint64_t seed = 12345;
    ex_growth energy = {"kinetic energy", "the time step is too large for the resolution: lower --cfl", 0, 1 + TG_ENERGY_TOL, 0};
    ex_growth error = {"relative L2 velocity error", "the weakly compressible pressure cannot follow a decay this fast: "
                       "Re too low for c0 and the resolution, raise --re, --c0 or --n", 0, 1, TG_L2_MAX};
    if (kid < 0) return SPH_EKERNEL;
    if (strcmp(P->scheme, "pressure") != 0 && strcmp(P->scheme, "difference") != 0 &&
        strcmp(P->scheme, "corrected") != 0)
        return SPH_EINVAL;
    if (n < 4 || !(P->t_end > 0) || !(P->hdx > 0)) return SPH_EINVAL;
    if (!(steps_d < 1e9)) {
        fprintf(stderr, "taylor_green: %.3g time steps (dt = %.3g) is more than this example runs (1e9)\n", steps_d, dt0);
        return SPH_ESIZE;
    }
    memset(&NL, 0, sizeof NL);
    memset(&S, 0, sizeof S);
    if ((st = ex_particle_count((double)n * n, "particles (--n)", &S.n)) != SPH_OK) return st;
    S.x = tg_alloc(S.n), S.y = tg_alloc(S.n), S.u = tg_alloc(S.n), S.v = tg_alloc(S.n);
    S.rho = tg_alloc(S.n), S.p = tg_alloc(S.n), S.V = tg_alloc(S.n), S.m = tg_alloc(S.n);
    S.du = tg_alloc(S.n), S.dv = tg_alloc(S.n), S.drho = tg_alloc(S.n), S.gp = tg_alloc(S.n);
    S.lu = tg_alloc(S.n), S.lv = tg_alloc(S.n), S.div = tg_alloc(S.n), S.one = tg_alloc(S.n);
    S.T = (sph_real *)ex_calloc((size_t)S.n * 4, sizeof(sph_real), NULL);
    S.bu = tg_alloc(S.n), S.bv = tg_alloc(S.n);
    if (!S.x || !S.y || !S.u || !S.v || !S.rho || !S.p || !S.V || !S.m || !S.du || !S.dv || !S.drho || !S.gp ||
        !S.lu || !S.lv || !S.div || !S.one || !S.T || !S.bu || !S.bv) {
        fprintf(stderr, "taylor_green: cannot allocate the fields of %ld particles (%.4g MB)\n", (long)S.n,
                (double)S.n * 40 * sizeof(sph_real) / 1e6);
        st = EX_ENOMEM;
        goto done;
    }
    for (i = 0; i < S.n; ++i) S.one[i] = 1;
    for (i = 0; i < S.n; ++i) { /* cell-centred lattice, optionally perturbed (seeded) */
        double px = ((double)(i % n) + 0.5) * dx, py = ((double)(i / n) + 0.5) * dx, pa;
        int a;
        for (a = 0; a < 2 && P->perturb > 0; ++a) {
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            pa = P->perturb * dx * (2.0 * (double)(seed >> 11) / 9007199254740992.0 - 1);
            if (a == 0) px += pa; else py += pa;
        }
        S.x[i] = px, S.y[i] = py;
        tg_exact(px, py, 0, nu, &pa, &st_t);
        S.u[i] = pa, S.v[i] = st_t;
        S.rho[i] = rho0 - rho0 * U * U / 4 * (cos(4 * PI * px) + cos(4 * PI * py)) / (P->c0 * P->c0);
        S.m[i] = rho0 * dx * dx;
    }
    st_t = 0;
    if (tvf) { /* density by summation: masses so that it starts at the analytic rho (one fixed-point pass) */
        for (i = 0; i < S.n; ++i) S.div[i] = S.rho[i];
        st = tg_tvf_rates(&S, &NL, P, (sph_kernel)kid, h, nu, dt, &box, &nfb);
        for (i = 0; i < S.n && st == SPH_OK; ++i) S.m[i] *= S.div[i] / S.rho[i], S.bu[i] = S.bv[i] = 0;
        if (st == SPH_OK) st = tg_tvf_rates(&S, &NL, P, (sph_kernel)kid, h, nu, dt, &box, &nfb);
    } else {
        st = tg_rates(&S, &NL, P, (sph_kernel)kid, h, nu, &box, 0, &nfb);
        if (st == SPH_OK) st = tg_rates(&S, &NL, P, (sph_kernel)kid, h, nu, &box, 1, &nfb);
    }
    for (s = 0; st == SPH_OK && s <= steps; ++s) {
        const double t = (double)s * dt;
        const double e = tg_energy(&S, t, nu, &l2);
        ex_field f[3];
        tg_fields(&S, f);
        if (s == 0) e0 = energy.start = e;
        if ((st = ex_fields_finite("taylor_green", f, 3, S.n, t)) != SPH_OK ||
            (st = ex_growth_check(&energy, e, t)) != SPH_OK || (st = ex_growth_check(&error, l2, t)) != SPH_OK)
            break;
        if (!(e > 0)) {
            fprintf(stderr, "taylor_green: kinetic energy %g at t = %.6g: run stopped\n", e, t);
            st = SPH_ENONFINITE;
            break;
        }
        st_t += t, st_y += log(e / e0), st_tt += t * t, st_ty += t * log(e / e0), cnt += 1;
        if (csv != NULL && (s % (steps / 200 + 1) == 0 || s == steps))
            fprintf(csv, "%.6g,%.9g,%.9g,%.6g\n", t, e / e0, exp(-16 * PI * PI * nu * t), l2);
        if (frames != NULL && P->frames > 0 && (s * P->frames) / steps >= frame) {
            if (ex_series_write(frames, t, S.n, 2, sph_view_soa(S.x, S.y, NULL), f, 3) != 0) {
                st = EX_EWRITE;
                break;
            }
            ++frame;
        }
        if (s == steps) break;
        for (i = 0; i < S.n; ++i) { /* kick v by dt/2, drift x by dt with v~ = v + (dt/2) b (tvf) or v */
            S.u[i] += 0.5 * dt * S.du[i], S.v[i] += 0.5 * dt * S.dv[i];
            if (!P->lagrangian) continue;
            S.x[i] += dt * (S.u[i] + (tvf ? 0.5 * dt * S.bu[i] : 0));
            S.y[i] += dt * (S.v[i] + (tvf ? 0.5 * dt * S.bv[i] : 0));
            S.x[i] -= floor(S.x[i]), S.y[i] -= floor(S.y[i]);
        }
        if (tvf) {
            st = tg_tvf_rates(&S, &NL, P, (sph_kernel)kid, h, nu, dt, &box, &nfb);
        } else {
            st = tg_rates(&S, &NL, P, (sph_kernel)kid, h, nu, &box, 0, &nfb);
            for (i = 0; i < S.n; ++i) S.rho[i] += dt * S.drho[i]; /* rho by dt with the mid-step velocity */
            if (st == SPH_OK) st = tg_rates(&S, &NL, P, (sph_kernel)kid, h, nu, &box, 1, &nfb);
        }
        for (i = 0; i < S.n; ++i) S.u[i] += 0.5 * dt * S.du[i], S.v[i] += 0.5 * dt * S.dv[i]; /* kick v by dt/2 */
        if (st == SPH_OK && P->lagrangian && P->plain && P->shift > 0) st = tg_shift(&S, &NL, (sph_kernel)kid, h, dx, P->shift, &box);
        if (label != NULL) ex_progress_update(&prog, label, (double)(s + 1) / (double)steps);
    }
    if (label != NULL) ex_progress_done(&prog, label);
done:
    R->steps = steps;
    R->rate_exact = 16 * PI * PI * nu;
    R->rate_fit = -(cnt * st_ty - st_t * st_y) / (cnt * st_tt - st_t * st_t); /* least squares of ln E(t) */
    R->rate_err = (R->rate_fit - R->rate_exact) / R->rate_exact;
    R->l2 = l2;
    R->e_ratio = st == SPH_OK ? tg_energy(&S, P->t_end, nu, &l2) / e0 : NAN;
    R->seconds = ex_now() - t0;
    if (nfb > 0) fprintf(stderr, "note: %ld corrected-scheme fallbacks\n", (long)nfb);
    ex_neighbours_free(&NL);
    free(S.x), free(S.y), free(S.u), free(S.v), free(S.rho), free(S.p), free(S.V), free(S.m);
    free(S.du), free(S.dv), free(S.drho), free(S.gp), free(S.lu), free(S.lv), free(S.div), free(S.one), free(S.T);
    free(S.bu), free(S.bv);
    return st;
}

static void tg_print(const tg_param *P, const tg_result *R)
{
    printf("n %3d  %-12s %-10s perturb %.2f  steps %5ld  E(t)/E0 %.5f (exact %.5f)  decay rate %.4f "
           "(exact %.4f, error %+.2f %%)  L2 velocity error %.4f  %.1f s\n",
           P->n, P->kernel, P->scheme, P->perturb, R->steps, R->e_ratio, exp(-R->rate_exact * P->t_end), R->rate_fit,
           R->rate_exact, 100 * R->rate_err, R->l2, R->seconds);
    fflush(stdout);
}

/* One row of the study: resolution, kernel, pressure gradient, start
 * perturbation, particle motion (0 fixed, 1 transport velocity, 2 plain). */
typedef struct {
    int n;
    const char *kernel, *scheme;
    double perturb;
    int motion;
} tg_row;

static const char *tg_motion_name(int motion)
{
    return motion == 0 ? "fixed" : motion == 1 ? "moving, transport velocity" : "moving, plain + shifting";
}

/* The resolution / kernel / scheme / start table (docs/taylor_green_results.md)
 * and the energy series of the plots (outdir/tg_<n>_<kernel>_... .csv). */
static int tg_study(const tg_param *base, const char *docdir, const char *outdir)
{
    static const tg_row rows[] = {
        {24, "wendland_c2", "pressure", 0, 1},    {32, "wendland_c2", "pressure", 0, 1},
        {48, "wendland_c2", "pressure", 0, 1},    {32, "cubic", "pressure", 0, 1},
        {32, "wendland_c4", "pressure", 0, 1},    {32, "quintic", "pressure", 0, 1},
        {32, "wendland_c2", "difference", 0, 1},  {32, "wendland_c2", "corrected", 0, 1},
        {32, "wendland_c2", "pressure", 0.2, 1},  {32, "wendland_c2", "corrected", 0.2, 1},
        {32, "wendland_c2", "pressure", 0, 2},    {24, "wendland_c2", "pressure", 0, 0},
        {32, "wendland_c2", "pressure", 0, 0},    {48, "wendland_c2", "pressure", 0, 0},
        {32, "cubic", "pressure", 0, 0},          {32, "wendland_c2", "corrected", 0, 0},
        {32, "wendland_c2", "pressure", 0.2, 0},  {32, "wendland_c2", "corrected", 0.2, 0}};
    char path[1100];
    FILE *md, *csv;
    size_t q;
    int a, s, bad = 0;
    snprintf(path, sizeof path, "%s/taylor_green_results.md", docdir);
    if ((md = fopen(path, "w")) == NULL) return fprintf(stderr, "taylor_green: cannot write %s\n", path), -1;
    fprintf(md, "Written by `taylor_green --study` (Re = %g, c0 = %g U, t = %g, linear EOS with p_b = %g; "
                "h = 2 dx for moving particles, 1.3 dx for fixed ones; transport velocity with background "
                "pressure rho0 c0^2). Decay-rate error: least-squares slope of ln E(t) over [0, t] against "
                "16 pi^2 nu; L2 error: relative L2 norm of v - v_exact at the particles at t.\n\n",
            base->re, base->c0, base->t_end, base->pb);
    fprintf(md, "| particles | kernel | pressure gradient | particles | start | h / dx | E(t)/E(0) (exact %.4f) | "
                "decay-rate error | L2 velocity error | steps | run time |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
            exp(-16 * PI * PI * base->t_end / base->re));
    for (q = 0; q < sizeof rows / sizeof rows[0]; ++q) {
        tg_param P = *base;
        tg_result R;
        char label[96];
        P.frames = 0, P.n = rows[q].n, P.kernel = rows[q].kernel, P.scheme = rows[q].scheme;
        P.perturb = rows[q].perturb, P.lagrangian = rows[q].motion > 0, P.plain = rows[q].motion == 2;
        P.hdx = rows[q].motion == 1 ? 2.0 : 1.3;
        snprintf(path, sizeof path, "%s/tg_%d_%s_%s_%s%s.csv", outdir, P.n, P.kernel, P.scheme,
                 P.perturb > 0 ? "perturbed" : "lattice", rows[q].motion == 1 ? "_tvf" : rows[q].motion == 2 ? "_plain" : "");
        csv = fopen(path, "w");
        if (csv != NULL) fprintf(csv, "t,E/E0,exact E/E0,L2 velocity error\n");
        snprintf(label, sizeof label, "taylor_green %d %s %s %s", P.n, P.kernel, P.scheme, rows[q].motion ? "moving" : "fixed");
        a = tg_run(&P, &R, csv, NULL, label);
        if (csv != NULL) fclose(csv);
        fprintf(md, "| %d^2 | %s | %s | %s | %s | %.1f | ", P.n, P.kernel, P.scheme, tg_motion_name(rows[q].motion),
                P.perturb > 0 ? "perturbed 0.2 dx" : "lattice", P.hdx);
        if (a != SPH_OK) {
            fprintf(md, "diverged (%s) | | | | |\n", ex_strerror(a));
            bad += q < 3; /* the moving resolution rows must run */
            continue;
        }
        tg_print(&P, &R);
        fprintf(md, "%.4f | %+.2f %% | %.4f | %ld | %.1f s |\n", R.e_ratio, 100 * R.rate_err, R.l2, R.steps, R.seconds);
    }
    s = fclose(md);
    return bad || s != 0 ? -1 : 0;
}

int main(int argc, char **argv)
{
    tg_param P;
    tg_result R;
    const char *out = "build/taylor_green", *study = NULL;
    int threads = 1, check = 0, ascii = 0, st;
    char path[1100];
    FILE *csv;
    ex_series frames;
    /* Ranges: n to 4000 (16 million particles, several GB); Re from 0.1 (the
     * viscous step 0.125 h^2 Re keeps runs below millions of steps); c0 above
     * U; cfl to 1 (the acoustic limit of the kick-drift-kick step). */
    const ex_arg opt[] = {
        {"n", "particles per side of the unit square", NULL, &P.n, NULL, NULL, 8, 4000, 0, NULL},
        {"kernel", "smoothing kernel", NULL, NULL, &P.kernel, NULL, 0, 0, 0, ex_kernel_choices()},
        {"scheme", "pressure gradient: pressure (O8), difference (O5), corrected (O7)", NULL, NULL, &P.scheme, NULL,
         0, 0, 0, "pressure|difference|corrected"},
        {"hdx", "smoothing length h / dx (0: 2 moving, 1.3 fixed)", &P.hdx, NULL, NULL, NULL, 1, 4, EX_OR_ZERO, NULL},
        {"t-end", "end time (L / U)", &P.t_end, NULL, NULL, NULL, 0, 100, EX_OPEN_LO, NULL},
        {"re", "Reynolds number U L / nu", &P.re, NULL, NULL, NULL, 0.1, 1e5, 0, NULL},
        {"c0", "speed of sound (U)", &P.c0, NULL, NULL, NULL, 1, 1000, EX_OPEN_LO, NULL},
        {"pb", "background pressure of the equation of state", &P.pb, NULL, NULL, NULL, 0, 1e6, 0, NULL},
        {"perturb", "start: lattice moved by up to this fraction of dx", &P.perturb, NULL, NULL, NULL, 0, 0.5, 0, NULL},
        {"out", "output directory (VTK frames, energy.csv)", NULL, NULL, &out, NULL, 0, 0, 0, NULL},
        {"frames", "VTK frames: the start and this many more to the end (0: none)", NULL, &P.frames, NULL, NULL, 0,
         10000, 0, NULL},
        {"ascii", "VTK frames in ASCII (default: binary)", NULL, NULL, NULL, &ascii, 0, 0, 0, NULL},
        {"threads", "OpenMP threads (0: the runtime's default; 1 by default: runs this small lose more to thread synchronisation on a busy machine than they gain)",
         NULL, &threads, NULL, NULL, 0, 1024, 0, NULL},
        {"check", "short coarse run; exit 1 if it misses its validation bounds", NULL, NULL, NULL, &check, 0, 0, 0,
         NULL},
        {"study", "write the error table into this directory (docs/results)", NULL, NULL, &study, NULL, 0, 0, 0, NULL},
        {"lagrangian", "particles move with the flow, transport-velocity formulation (default: fixed particles)",
         NULL, NULL, NULL, &P.lagrangian, 0, 0, 0, NULL},
        {"pt", "background pressure of the transport velocity (negative: rho0 c0^2)", &P.pt, NULL, NULL, NULL, -1,
         1e6, 0, NULL},
        {"plain", "with --lagrangian: standard WCSPH (continuity, no transport velocity)", NULL, NULL, NULL, &P.plain,
         0, 0, 0, NULL},
        {"shift", "with --plain: particle shifting D, dr = -D h^2 grad C (0: off)", &P.shift, NULL, NULL, NULL, 0, 1,
         0, NULL},
        {"cfl", "time step dt = cfl h / (c0 + U)", &P.cfl, NULL, NULL, NULL, 0, 1, EX_OPEN_LO, NULL},
    };
    P.n = 40, P.kernel = "wendland_c2", P.scheme = "pressure", P.hdx = 0, P.t_end = 1, P.re = 100, P.c0 = 10;
    P.pb = 0, P.pt = -1, P.perturb = 0, P.frames = 10, P.shift = 0.05, P.lagrangian = 0, P.plain = 0, P.cfl = 0.25;
    st = ex_parse_args(argc, argv, "2-D Taylor-Green vortex, weakly compressible SPH, against the analytic decay; " TG_BOUNDS,
                       opt, (int)(sizeof opt / sizeof opt[0]));
    if (st != 0) return st > 0 ? 0 : 2;
    if (!(P.hdx > 0)) P.hdx = P.lagrangian && !P.plain ? 2.0 : 1.3;
#ifdef _OPENMP
    if (threads > 0) omp_set_num_threads(threads);
#else
    (void)threads;
#endif
    if (check) { /* coarse, 24^2: fixed particles to t = 0.5, then moving (transport velocity) to t = 1 */
        static const double rate_bound[2] = {0.10, 0.10}, l2_bound[2] = {0.05, 0.15};
        int ok = 1, mv;
        for (mv = 0; mv < 2; ++mv) {
            tg_param C = P;
            int pass;
            C.n = 24, C.t_end = mv ? 1 : 0.5, C.frames = 0, C.lagrangian = mv, C.plain = 0, C.hdx = mv ? 2.0 : 1.3;
            st = tg_run(&C, &R, NULL, NULL, NULL);
            if (st != SPH_OK) {
                printf("taylor_green --check: %s run failed: %s\n", mv ? "moving" : "fixed", ex_strerror(st));
                return 1;
            }
            tg_print(&C, &R);
            pass = fabs(R.rate_err) < rate_bound[mv] && R.l2 < l2_bound[mv];
            printf("taylor_green --check %s: decay-rate error %+.2f %% (bound %g %%), L2 velocity error %.4f "
                   "(bound %g): %s\n", mv ? "moving" : "fixed", 100 * R.rate_err, 100 * rate_bound[mv], R.l2,
                   l2_bound[mv], pass ? "pass" : "FAIL");
            ok = ok && pass;
        }
        return ok ? 0 : 1;
    }
    if (ex_mkdir_p(out) != 0) {
        fprintf(stderr, "taylor_green: cannot create %s\n", out);
        return 2;
    }
    if (study != NULL) return tg_study(&P, study, out) == 0 ? 0 : 1;
    snprintf(path, sizeof path, "%s/energy.csv", out);
    if ((csv = fopen(path, "w")) == NULL) {
        fprintf(stderr, "taylor_green: cannot write %s\n", path);
        return 2;
    }
    if (ex_series_open(&frames, out, "taylor_green", ascii) != 0) return 2;
    fprintf(csv, "t,E/E0,exact E/E0,L2 velocity error\n");
    st = tg_run(&P, &R, csv, &frames, "taylor_green");
    if (fclose(csv) != 0 && st == SPH_OK) st = EX_EWRITE;
    if (st == SPH_OK) tg_print(&P, &R);
    else fprintf(stderr, "taylor_green: run failed: %s\n", ex_strerror(st));
    printf("wrote %s (t, E/E0, exact E/E0, L2 velocity error)%s\n", path, st == SPH_OK ? "" : " up to the failure");
    ex_series_report(&frames);
    ex_series_close(&frames);
    return st == SPH_OK ? 0 : 1;
}
