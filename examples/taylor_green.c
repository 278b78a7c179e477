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
 * operators (O17 / O5 / O7). --lagrangian moves the particles with the flow
 * instead (with particle shifting, --shift); the hyperbolic stagnation points
 * of this flow squeeze a lattice into lines within t ~ 0.2, and the table in
 * docs shows what that does to standard WCSPH.
 * Symplectic kick-drift-kick (Adami et al. 2013 ordering): v by dt/2, x by dt,
 * rho by dt with the mid-step velocity, forces, v by dt/2;
 * dt = min(0.25 h / (c0 + U), 0.125 h^2 / nu). Neighbour lists from the
 * library's cell-list search in the periodic box (rebuilt every step when the
 * particles move).
 *
 *   ./taylor_green                    default run: 40 x 40, Wendland C2, pressure form, fixed particles
 *   ./taylor_green --check            short coarse run with validation bounds (make test)
 *   ./taylor_green --study docs       resolution / kernel / scheme table into docs/
 */
#include "example_io.h"

#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define PI 3.14159265358979323846

typedef struct {
    int n;             /* particles per side */
    const char *kernel;
    const char *scheme; /* pressure | difference | corrected */
    double hdx;        /* h / dx */
    double t_end, re, c0, pb, perturb, shift;
    int frames;        /* VTK frames (0: none) */
    int lagrangian;    /* 1: particles move with the flow; 0: fixed particles, convection by operators */
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
} tg_state;

static sph_real *tg_alloc(sph_idx n) { return (sph_real *)calloc((size_t)(2 * n), sizeof(sph_real)); }

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

static int tg_vtk(const tg_state *S, const char *dir, int frame)
{
    char path[1100];
    ex_field f[3];
    f[0].name = "velocity", f[0].v = sph_view_soa(S->u, S->v, NULL), f[0].ncomp = 2;
    f[1].name = "pressure", f[1].v = sph_view_soa(S->p, NULL, NULL), f[1].ncomp = 1;
    f[2].name = "density", f[2].v = sph_view_soa(S->rho, NULL, NULL), f[2].ncomp = 1;
    snprintf(path, sizeof path, "%s/taylor_green_%04d.vtk", dir, frame);
    return ex_write_vtk(path, S->n, 2, sph_view_soa(S->x, S->y, NULL), f, 3);
}

/* One run. csv (may be NULL): time series t, E/E0, exact E/E0, L2 error.
 * vtkdir (may be NULL): frames. Returns 0 or a negative status. */
static int tg_run(const tg_param *P, tg_result *R, FILE *csv, const char *vtkdir, const char *label)
{
    const int n = P->n, kid = sph_kernel_from_name(P->kernel);
    const double L = 1, U = 1, rho0 = 1, dx = L / n, h = P->hdx * dx, nu = U * L / P->re;
    const double dt0 = fmin(0.25 * h / (P->c0 + U), 0.125 * h * h / nu);
    const long steps = (long)ceil(P->t_end / dt0 - 1e-9);
    const double dt = P->t_end / (double)steps;
    const sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 0}};
    double e0 = 0, l2 = 0, st_t = 0, st_y = 0, st_tt = 0, st_ty = 0, cnt = 0, t0 = ex_now();
    ex_neighbours NL;
    ex_progress prog = ex_progress_start();
    tg_state S;
    sph_idx i, nfb = 0;
    long s;
    int st = SPH_OK, frame = 0;
    uint64_t seed = 12345;
    if (kid < 0) return SPH_EKERNEL;
    if (strcmp(P->scheme, "pressure") != 0 && strcmp(P->scheme, "difference") != 0 &&
        strcmp(P->scheme, "corrected") != 0)
        return SPH_EINVAL;
    if (n < 4 || !(P->t_end > 0) || !(P->hdx > 0)) return SPH_EINVAL;
    memset(&NL, 0, sizeof NL);
    S.n = (sph_idx)n * n;
    S.x = tg_alloc(S.n), S.y = tg_alloc(S.n), S.u = tg_alloc(S.n), S.v = tg_alloc(S.n);
    S.rho = tg_alloc(S.n), S.p = tg_alloc(S.n), S.V = tg_alloc(S.n), S.m = tg_alloc(S.n);
    S.du = tg_alloc(S.n), S.dv = tg_alloc(S.n), S.drho = tg_alloc(S.n), S.gp = tg_alloc(S.n);
    S.lu = tg_alloc(S.n), S.lv = tg_alloc(S.n), S.div = tg_alloc(S.n), S.one = tg_alloc(S.n);
    S.T = (sph_real *)calloc((size_t)(4 * S.n), sizeof(sph_real));
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
    st = tg_rates(&S, &NL, P, (sph_kernel)kid, h, nu, &box, 0, &nfb);
    if (st == SPH_OK) st = tg_rates(&S, &NL, P, (sph_kernel)kid, h, nu, &box, 1, &nfb);
    for (s = 0; st == SPH_OK && s <= steps; ++s) {
        const double t = (double)s * dt;
        const double e = tg_energy(&S, t, nu, &l2);
        if (s == 0) e0 = e;
        if (!(e > 0) || !isfinite(e)) {
            st = SPH_ENONFINITE;
            break;
        }
        st_t += t, st_y += log(e / e0), st_tt += t * t, st_ty += t * log(e / e0), cnt += 1;
        if (csv != NULL && (s % (steps / 200 + 1) == 0 || s == steps))
            fprintf(csv, "%.6g,%.9g,%.9g,%.6g\n", t, e / e0, exp(-16 * PI * PI * nu * t), l2);
        if (vtkdir != NULL && P->frames > 0 && (s * P->frames) / steps >= frame) {
            if (tg_vtk(&S, vtkdir, frame) != 0) fprintf(stderr, "cannot write VTK into %s\n", vtkdir);
            ++frame;
        }
        if (s == steps) break;
        for (i = 0; i < S.n; ++i) { /* kick v by dt/2, drift x by dt (wrapped into the box) */
            S.u[i] += 0.5 * dt * S.du[i], S.v[i] += 0.5 * dt * S.dv[i];
            if (!P->lagrangian) continue;
            S.x[i] += dt * S.u[i], S.y[i] += dt * S.v[i];
            S.x[i] -= floor(S.x[i]), S.y[i] -= floor(S.y[i]);
        }
        st = tg_rates(&S, &NL, P, (sph_kernel)kid, h, nu, &box, 0, &nfb);
        for (i = 0; i < S.n; ++i) S.rho[i] += dt * S.drho[i]; /* rho by dt with the mid-step velocity */
        if (st == SPH_OK) st = tg_rates(&S, &NL, P, (sph_kernel)kid, h, nu, &box, 1, &nfb);
        for (i = 0; i < S.n; ++i) S.u[i] += 0.5 * dt * S.du[i], S.v[i] += 0.5 * dt * S.dv[i]; /* kick v by dt/2 */
        if (st == SPH_OK && P->lagrangian && P->shift > 0) st = tg_shift(&S, &NL, (sph_kernel)kid, h, dx, P->shift, &box);
        if (label != NULL) ex_progress_update(&prog, label, (double)(s + 1) / (double)steps);
    }
    if (label != NULL) ex_progress_done(&prog, label);
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

/* The resolution / kernel / scheme / start table (docs/taylor_green_results.md)
 * and the energy series of the plots (outdir/energy_<n>.csv ...). */
static int tg_study(const tg_param *base, const char *docdir, const char *outdir)
{
    static const int res[3] = {24, 32, 48};
    static const char *kern[4] = {"cubic", "wendland_c2", "wendland_c4", "quintic"};
    static const char *sch[3] = {"pressure", "difference", "corrected"};
    char path[1100];
    FILE *md, *csv;
    int r, q, s, a, bad = 0;
    snprintf(path, sizeof path, "%s/taylor_green_results.md", docdir);
    if ((md = fopen(path, "w")) == NULL) return -1;
    fprintf(md, "Written by `taylor_green --study` (Re = %g, c0 = %g U, h = %g dx, t = %g, linear EOS with "
                "p_b = %g). Decay-rate error: least-squares slope of ln E(t) over [0, t] against 16 pi^2 nu; "
                "L2 error: relative L2 norm of v - v_exact at the particles at t.\n\n",
            base->re, base->c0, base->hdx, base->t_end, base->pb);
    fprintf(md, "| particles | kernel | pressure gradient | particles / start | E(t)/E(0) (exact %.4f) | decay-rate error | "
                "L2 velocity error | steps | run time |\n|---|---|---|---|---|---|---|---|---|\n",
            exp(-16 * PI * PI * base->t_end / base->re));
    for (q = 0; q < 3 + 4 + 3 + 2 + 1; ++q) { /* resolutions; kernels; schemes; disordered start; moving */
        tg_param P = *base;
        tg_result R;
        char label[64];
        P.frames = 0;
        if (q < 3) P.n = res[q];
        else P.n = res[1];
        if (q >= 3 && q < 7) P.kernel = kern[q - 3];
        if (q >= 7 && q < 10) P.scheme = sch[q - 7];
        if (q == 10 || q == 11) P.perturb = 0.2, P.scheme = sch[q == 10 ? 0 : 2];
        if (q == 12) P.lagrangian = 1;
        if ((q >= 3 && q < 7 && strcmp(P.kernel, base->kernel) == 0) ||
            (q >= 7 && q < 10 && strcmp(P.scheme, base->scheme) == 0))
            continue; /* the same run as the resolution row */
        snprintf(path, sizeof path, "%s/tg_%d_%s_%s_%s%s.csv", outdir, P.n, P.kernel, P.scheme,
                 P.perturb > 0 ? "perturbed" : "lattice", P.lagrangian ? "_moving" : "");
        csv = fopen(path, "w");
        if (csv != NULL) fprintf(csv, "t,E/E0,exact E/E0,L2 velocity error\n");
        snprintf(label, sizeof label, "taylor_green %d %s %s", P.n, P.kernel, P.scheme);
        a = tg_run(&P, &R, csv, NULL, label);
        if (csv != NULL) fclose(csv);
        if (a != SPH_OK) {
            fprintf(md, "| %d^2 | %s | %s | %s%s | diverged (%s) | | | | |\n", P.n, P.kernel, P.scheme,
                    P.lagrangian ? "moving, " : "fixed, ", P.perturb > 0 ? "perturbed 0.2 dx" : "lattice",
                    sph_strerror(a));
            bad += q < 3; /* the resolution rows must run */
            continue;
        }
        tg_print(&P, &R);
        fprintf(md, "| %d^2 | %s | %s | %s%s | %.4f | %+.2f %% | %.4f | %ld | %.1f s |\n", P.n, P.kernel, P.scheme,
                P.lagrangian ? "moving + shifting, " : "fixed, ", P.perturb > 0 ? "perturbed 0.2 dx" : "lattice",
                R.e_ratio, 100 * R.rate_err, R.l2, R.steps,
                R.seconds);
    }
    s = fclose(md);
    (void)r;
    return bad || s != 0 ? -1 : 0;
}

int main(int argc, char **argv)
{
    tg_param P;
    tg_result R;
    const char *out = "build/taylor_green", *study = NULL;
    int threads = 0, check = 0, st;
    char path[1100];
    FILE *csv;
    ex_option opt[13];
    P.n = 40, P.kernel = "wendland_c2", P.scheme = "pressure", P.hdx = 1.3, P.t_end = 1, P.re = 100, P.c0 = 10;
    P.pb = 0, P.perturb = 0, P.frames = 10, P.shift = 0.05, P.lagrangian = 0;
    memset(opt, 0, sizeof opt);
    opt[0].name = "n", opt[0].help = "particles per side of the unit square", opt[0].integer = &P.n;
    opt[1].name = "kernel", opt[1].help = "cubic, lucy, new_quartic, quintic, wendland_c2/c4/c6", opt[1].text = &P.kernel;
    opt[2].name = "scheme", opt[2].help = "pressure gradient: pressure (O8), difference (O5), corrected (O7)",
    opt[2].text = &P.scheme;
    opt[3].name = "hdx", opt[3].help = "smoothing length h / dx", opt[3].real = &P.hdx;
    opt[4].name = "t-end", opt[4].help = "end time (L / U)", opt[4].real = &P.t_end;
    opt[5].name = "re", opt[5].help = "Reynolds number U L / nu", opt[5].real = &P.re;
    opt[6].name = "c0", opt[6].help = "speed of sound (U)", opt[6].real = &P.c0;
    opt[7].name = "pb", opt[7].help = "background pressure of the equation of state", opt[7].real = &P.pb;
    opt[8].name = "perturb", opt[8].help = "start: lattice moved by up to this fraction of dx", opt[8].real = &P.perturb;
    opt[9].name = "out", opt[9].help = "output directory (VTK frames, energy.csv)", opt[9].text = &out;
    opt[10].name = "frames", opt[10].help = "number of VTK frames (0: none)", opt[10].integer = &P.frames;
    opt[11].name = "threads", opt[11].help = "OpenMP threads (0: the runtime's default)", opt[11].integer = &threads;
    opt[12].name = "check", opt[12].help = "short coarse run; exit 1 if it misses its validation bounds",
    opt[12].flag = &check;
    {
        ex_option all[16];
        memcpy(all, opt, sizeof opt);
        memset(&all[13], 0, 3 * sizeof all[13]);
        all[15].name = "lagrangian", all[15].help = "particles move with the flow (default: fixed particles)";
        all[15].flag = &P.lagrangian;
        all[14].name = "shift", all[14].help = "particle shifting D: dr = -D h^2 grad C (0: off)", all[14].real = &P.shift;
        all[13].name = "study", all[13].help = "write the error table into this directory (docs)", all[13].text = &study;
        st = ex_parse(argc, argv, "2-D Taylor-Green vortex, weakly compressible SPH, against the analytic decay",
                      all, 16);
    }
    if (st != 0) return st > 0 ? 0 : 2;
#ifdef _OPENMP
    if (threads > 0) omp_set_num_threads(threads);
#else
    (void)threads;
#endif
    if (check) { /* coarse: 24^2 to t = 0.5, about 600 steps */
        tg_param C = P;
        int ok;
        C.n = 24, C.t_end = 0.5, C.frames = 0;
        st = tg_run(&C, &R, NULL, NULL, NULL);
        if (st != SPH_OK) {
            printf("taylor_green --check: run failed: %s\n", sph_strerror(st));
            return 1;
        }
        tg_print(&C, &R);
        ok = fabs(R.rate_err) < 0.10 && R.l2 < 0.05;
        printf("taylor_green --check: decay-rate error %+.2f %% (bound 10 %%), L2 velocity error %.4f (bound 0.05): %s\n",
               100 * R.rate_err, R.l2, ok ? "pass" : "FAIL");
        return ok ? 0 : 1;
    }
    if (ex_mkdir_p(out) != 0) {
        fprintf(stderr, "cannot create %s\n", out);
        return 2;
    }
    if (study != NULL) return tg_study(&P, study, out) == 0 ? 0 : 1;
    snprintf(path, sizeof path, "%s/energy.csv", out);
    csv = fopen(path, "w");
    if (csv != NULL) fprintf(csv, "t,E/E0,exact E/E0,L2 velocity error\n");
    st = tg_run(&P, &R, csv, out, "taylor_green");
    if (csv != NULL) fclose(csv);
    if (st != SPH_OK) {
        fprintf(stderr, "taylor_green: %s\n", sph_strerror(st));
        return 1;
    }
    tg_print(&P, &R);
    printf("wrote %s/energy.csv and %d VTK frames %s/taylor_green_*.vtk\n", out, P.frames + (P.frames > 0), out);
    return 0;
}
