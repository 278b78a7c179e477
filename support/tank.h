/* support/tank.h - a weakly compressible 2-D hydrostatic tank built from the
 * library's solver terms, shared by tests/test_solver_wall.c (a short run
 * under the sanitizers) and studies/hydrostatic_tank.c (long runs).
 *
 * nx x ny fluid particles of spacing dx at rest with the hydrostatic density
 * of the linear equation of state p = c0^2 (rho - rho0), c0 = 10 sqrt(g H);
 * three wall layers under the fluid and beside it (two rows above the
 * surface); cubic kernel, h = 1.3 dx. One step (tank_step) is the
 * kick-drift-kick recipe of docs/solver.md: continuity (O10) with the walls at
 * rest, the wall pressure and no-slip velocity (S8), the pressure force (O8)
 * and Monaghan's viscosity (S1) (alpha = 0.02, beta = 0) over fluid and
 * walls, gravity, the time step (S9)-(S10) with v_sig of (S2), and with
 * t->delta > 0 the density diffusion (S7) (Antuono et al. 2010). Lists:
 * O(N^2) reference lists (support/particles.h) with a skin of 0.2 kappa h,
 * rebuilt when a particle has moved half of it.
 */
#ifndef SPH_SUPPORT_TANK_H
#define SPH_SUPPORT_TANK_H

#include <math.h>
#include <stdlib.h>

#include "particles.h"

enum { TANK_LAYERS = 3 };

typedef struct {
    int nx, ny, nf, nw, n;
    double rho0, g, c0, h, dx, H, L, alpha, delta; /* delta: density diffusion (S7), 0 = none */
    sph_real *x, *x0, *v, *vh, *vav, *rho, *p, *m, *V, *c, *a, *drho, *gp, *vs, *aav, *du, *grho, *dd;
    tp_list Lf, Lw; /* fluid targets -> every particle; wall targets -> fluid */
    int rebuilds;
} tank;

/* Frees what tank_make allocated (safe on a partly made tank). */
static inline void tank_free(tank *t)
{
    free(t->x), free(t->x0), free(t->v), free(t->vh), free(t->vav), free(t->rho), free(t->p), free(t->m), free(t->V);
    free(t->c), free(t->a), free(t->drho), free(t->gp), free(t->vs), free(t->aav), free(t->du), free(t->grho);
    free(t->dd);
    tp_free_list(&t->Lf), tp_free_list(&t->Lw);
}

/* The lists with a skin of 0.2 kappa h; the positions they were built at. -1 when malloc fails. */
static inline int tank_lists(tank *t)
{
    const double kappa = 2 * 1.2;
    int i;
    tp_free_list(&t->Lf), tp_free_list(&t->Lw);
    if (tp_brute_list(2, t->x, t->nf, t->x, t->n, (sph_real)t->h, NULL, NULL, (sph_real)kappa, TP_GATHER, NULL,
                      &t->Lf) != 0 ||
        tp_brute_list(2, t->x + 3 * t->nf, t->nw, t->x, t->nf, (sph_real)t->h, NULL, NULL, (sph_real)kappa, TP_GATHER,
                      NULL, &t->Lw) != 0)
        return -1;
    for (i = 0; i < 3 * t->n; ++i) t->x0[i] = t->x[i];
    ++t->rebuilds;
    return 0;
}

static inline sph_real *tank_vec(int n) { return (sph_real *)calloc((size_t)n, sizeof(sph_real)); }

/* The tank of nx x ny fluid particles at rest (nx, ny >= 1, small enough
 * for int counts: the caller range-checks). 0, or -1 when malloc fails. */
static inline int tank_make(tank *t, int nx, int ny)
{
    int i, k, nw = 0;
    *t = (tank){0};
    t->nx = nx, t->ny = ny;
    t->dx = 0.025, t->rho0 = 1000, t->g = 9.81, t->alpha = 0.02;
    t->H = ny * t->dx, t->L = nx * t->dx, t->h = 1.3 * t->dx, t->c0 = 10 * sqrt(t->g * t->H);
    t->nf = nx * ny;
    t->nw = TANK_LAYERS * (nx + 2 * TANK_LAYERS) + 2 * TANK_LAYERS * (ny + 2);
    t->n = t->nf + t->nw;
    t->x = tank_vec(3 * t->n), t->x0 = tank_vec(3 * t->n), t->v = tank_vec(2 * t->n), t->vh = tank_vec(2 * t->n);
    t->vav = tank_vec(2 * t->n), t->rho = tank_vec(t->n), t->p = tank_vec(t->n), t->m = tank_vec(t->n);
    t->V = tank_vec(t->n), t->c = tank_vec(t->n), t->a = tank_vec(2 * t->nf), t->drho = tank_vec(t->nf);
    t->gp = tank_vec(2 * t->nf), t->vs = tank_vec(t->nf), t->aav = tank_vec(2 * t->nf), t->du = tank_vec(t->nf);
    t->grho = tank_vec(2 * t->n), t->dd = tank_vec(t->nf);
    if (!t->x || !t->x0 || !t->v || !t->vh || !t->vav || !t->rho || !t->p || !t->m || !t->V || !t->c || !t->a ||
        !t->drho || !t->gp || !t->vs || !t->aav || !t->du || !t->grho || !t->dd)
        return -1;
    for (i = 0; i < t->nf; ++i) {
        t->x[3 * i] = (sph_real)((i % nx + 0.5) * t->dx);
        t->x[3 * i + 1] = (sph_real)((i / nx + 0.5) * t->dx);
    }
    for (k = 0; k < TANK_LAYERS; ++k) {
        for (i = -TANK_LAYERS; i < nx + TANK_LAYERS; ++i, ++nw) { /* floor, under the fluid and the side walls */
            t->x[3 * (t->nf + nw)] = (sph_real)((i + 0.5) * t->dx);
            t->x[3 * (t->nf + nw) + 1] = (sph_real)(-(k + 0.5) * t->dx);
        }
        for (i = 0; i < ny + 2; ++i, nw += 2) { /* side walls, two rows above the surface */
            t->x[3 * (t->nf + nw)] = (sph_real)(-(k + 0.5) * t->dx);
            t->x[3 * (t->nf + nw + 1)] = (sph_real)(t->L + (k + 0.5) * t->dx);
            t->x[3 * (t->nf + nw) + 1] = t->x[3 * (t->nf + nw + 1) + 1] = (sph_real)((i + 0.5) * t->dx);
        }
    }
    for (i = 0; i < t->n; ++i) {
        const double y = i < t->nf ? t->x[3 * i + 1] : t->H; /* walls: set by (S8) before use */
        t->rho[i] = (sph_real)(t->rho0 * (1 + t->g * (t->H - y) / (t->c0 * t->c0)));
        t->p[i] = (sph_real)(t->c0 * t->c0 * (t->rho[i] - t->rho0));
        t->m[i] = (sph_real)(i < t->nf ? t->rho[i] * t->dx * t->dx : t->rho0 * t->dx * t->dx);
        t->c[i] = (sph_real)t->c0;
    }
    return tank_lists(t);
}

/* drho/dt of the fluid at velocities vel (O10), walls at rest: drho_i/dt =
 * -rho_i sum_j V_j (v_j - v_i) . grad_i W_ij; with delta > 0 plus the
 * Antuono density diffusion (S7) over fluid and walls (wall densities from
 * (S8)), its renormalised gradients (O7) at fluid and wall particles. */
static inline int tank_continuity(tank *t, const sph_real *vel)
{
    sph_ctx cf = sph_ctx_init(SPH_KERNEL_CUBIC, 2, (sph_real)t->h, &t->Lf.list, sph_view_interleaved(t->x, 3));
    sph_neighbours lw = t->Lw.list; /* walls -> fluid, indexed among every particle */
    sph_ctx cw = sph_ctx_init(SPH_KERNEL_CUBIC, 2, (sph_real)t->h, &lw, sph_view_interleaved(t->x, 3));
    const sph_view rho = sph_view_soa(t->rho, NULL, NULL), grho = sph_view_interleaved(t->grho, 2);
    int i, st;
    for (i = 0; i < 2 * t->n; ++i) t->vav[i] = i < 2 * t->nf ? vel[i] : 0;
    for (i = 0; i < t->n; ++i) t->V[i] = t->m[i] / t->rho[i];
    cf.V = sph_view_soa(t->V, NULL, NULL);
    cf.rho = rho;
    st = sph_divergence(&cf, SPH_SCHEME_DIFFERENCE, sph_view_interleaved(t->vav, 2), sph_view_none(),
                        sph_out_soa(t->drho, NULL, NULL), NULL);
    for (i = 0; i < t->nf; ++i) t->drho[i] *= -t->rho[i];
    if (st != SPH_OK || !(t->delta > 0)) return st;
    lw.n_sources = t->n;
    cw.x_target = sph_view_interleaved(t->x + 3 * t->nf, 3);
    cw.V = cf.V;
    st = sph_gradient(&cf, SPH_SCHEME_CORRECTED, rho, sph_view_none(), sph_out_interleaved(t->grho, 2), NULL);
    if (st == SPH_OK)
        st = sph_gradient(&cw, SPH_SCHEME_CORRECTED, rho, sph_view_soa(t->rho + t->nf, NULL, NULL),
                          sph_out_interleaved(t->grho + 2 * t->nf, 2), NULL);
    if (st == SPH_OK)
        st = sph_density_diffusion(&cf, (sph_real)t->delta, (sph_real)t->c0, grho, sph_view_none(),
                                   sph_out_soa(t->dd, NULL, NULL));
    for (i = 0; i < t->nf; ++i) t->drho[i] += t->dd[i];
    return st;
}

/* Walls (S8) from the fluid's p, rho and velocities vel, then the fluid's
 * acceleration: pressure (O8) and Monaghan's viscosity (S1) over fluid and
 * walls (the walls with their no-slip velocity), gravity. */
static inline int tank_momentum(tank *t, const sph_real *vel)
{
    const sph_real grav[2] = {0, (sph_real)-t->g};
    const sph_av av = sph_av_init(SPH_AV_MONAGHAN, (sph_real)t->alpha, 0);
    sph_wall w = sph_wall_init(2, grav);
    sph_ctx cw = sph_ctx_init(SPH_KERNEL_CUBIC, 2, (sph_real)t->h, &t->Lw.list, sph_view_interleaved(t->x, 3));
    sph_ctx cf = sph_ctx_init(SPH_KERNEL_CUBIC, 2, (sph_real)t->h, &t->Lf.list, sph_view_interleaved(t->x, 3));
    int i, st;
    cw.x_target = sph_view_interleaved(t->x + 3 * t->nf, 3);
    cw.rho = sph_view_soa(t->rho, NULL, NULL);
    st = sph_wall_adami(&cw, &w, sph_view_soa(t->p, NULL, NULL), sph_view_interleaved(vel, 2),
                        sph_out_soa(t->p + t->nf, NULL, NULL), sph_out_interleaved(t->vav + 2 * t->nf, 2), NULL);
    for (i = t->nf; i < t->n; ++i) t->rho[i] = (sph_real)(t->rho0 + t->p[i] / (t->c0 * t->c0));
    for (i = 0; i < 2 * t->nf; ++i) t->vav[i] = vel[i];
    cf.m = sph_view_soa(t->m, NULL, NULL);
    cf.rho = sph_view_soa(t->rho, NULL, NULL);
    if (st == SPH_OK)
        st = sph_gradient(&cf, SPH_SCHEME_PRESSURE, sph_view_soa(t->p, NULL, NULL), sph_view_none(),
                          sph_out_interleaved(t->gp, 2), NULL);
    if (st == SPH_OK)
        st = sph_artificial_viscosity(&cf, &av, sph_view_interleaved(t->vav, 2), sph_view_none(),
                                      sph_view_soa(t->c, NULL, NULL), sph_view_none(), sph_out_interleaved(t->aav, 2),
                                      sph_out_soa(t->du, NULL, NULL), sph_out_soa(t->vs, NULL, NULL));
    for (i = 0; i < t->nf; ++i) {
        t->a[2 * i] = -t->gp[2 * i] / t->rho[i] + t->aav[2 * i];
        t->a[2 * i + 1] = -t->gp[2 * i + 1] / t->rho[i] + t->aav[2 * i + 1] - (sph_real)t->g;
    }
    return st;
}

/* One kick-drift-kick step: v(n+1/2) = v + dt/2 a(n); x += dt v(n+1/2);
 * rho += dt drho/dt(x(n+1), v(n+1/2)); a(n+1); v(n+1) = v(n+1/2) + dt/2
 * a(n+1); dt from (S9), (S10) of step n. tank_momentum(t, t->v) must have
 * run once before the first step. Returns a status (SPH_ESIZE when a list
 * rebuild runs out of memory). */
static inline int tank_step(tank *t, double *dt_out)
{
    sph_dt_input in = sph_dt_input_init((sph_real)t->h);
    sph_real dt = 0;
    int i, st, why;
    double d2 = 0;
    in.vsig = sph_view_soa(t->vs, NULL, NULL); /* (S2): two sound speeds, so C_cfl 0.5 (docs/solver.md) */
    in.coef.cfl = (sph_real)0.5;
    in.acc = sph_view_interleaved(t->a, 2);
    st = sph_time_step(&in, 2, t->nf, &dt, &why, NULL);
    if (st != SPH_OK) return st;
    for (i = 0; i < 2 * t->nf; ++i) t->vh[i] = t->v[i] + dt / 2 * t->a[i];
    for (i = 0; i < t->nf; ++i) {
        double d = 0;
        int a;
        for (a = 0; a < 2; ++a) {
            t->x[3 * i + a] += dt * t->vh[2 * i + a];
            d += ((double)t->x[3 * i + a] - t->x0[3 * i + a]) * ((double)t->x[3 * i + a] - t->x0[3 * i + a]);
        }
        d2 = fmax(d2, d);
    }
    if (sqrt(d2) > 0.2 * t->h && tank_lists(t) != 0) return SPH_ESIZE; /* half the skin (0.2 kappa h) */
    st = tank_continuity(t, t->vh);
    for (i = 0; i < t->nf; ++i) {
        t->rho[i] += dt * t->drho[i];
        t->p[i] = (sph_real)(t->c0 * t->c0 * (t->rho[i] - t->rho0));
    }
    if (st == SPH_OK) st = tank_momentum(t, t->vh);
    for (i = 0; i < 2 * t->nf; ++i) t->v[i] = t->vh[i] + dt / 2 * t->a[i];
    *dt_out = dt;
    return st;
}

/* Errors against the hydrostatic state, relative to rho0 g H: the largest
 * over the fluid (*pf) and over the floor's wall particles within the
 * fluid's reach (*pw); the largest fluid speed (returned). */
static inline double tank_errors(const tank *t, double *pf, double *pw)
{
    const double P = t->rho0 * t->g * t->H;
    double vmax = 0;
    int i;
    *pf = *pw = 0;
    for (i = 0; i < t->nf; ++i) {
        *pf = fmax(*pf, fabs((double)t->p[i] - t->rho0 * t->g * (t->H - t->x[3 * i + 1])) / P);
        vmax = fmax(vmax, hypot(t->v[2 * i], t->v[2 * i + 1]));
    }
    for (i = t->nf; i < t->n; ++i)
        if (t->x[3 * i + 1] > 0.5 * t->dx - 2 * t->h && t->x[3 * i] > 0 && t->x[3 * i] < t->L)
            *pw = fmax(*pw, fabs((double)t->p[i] - t->rho0 * t->g * (t->H - t->x[3 * i + 1])) / P);
    return vmax;
}

#endif
