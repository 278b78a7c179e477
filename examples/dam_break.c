/* examples/dam_break.c - 2-D weakly-compressible SPH dam break: a water
 * column of width a and height n^2 a collapses onto the dry floor of a tank;
 * the surge front and the residual height at the back wall are compared with
 * the measurements of Martin & Moyce (1952), Phil. Trans. R. Soc. A 244, 312.
 *
 * Physics and numerics (docs/examples.md, "Dam break"):
 *   continuity     drho_i/dt = -sum_j m_j (v_j - v_i) . grad_i W_ij              (O10) with m_j
 *                              + delta h c0 lap(rho)_i      (Molteni & Colagrossi 2009, (O12))
 *   momentum       dv_i/dt  = -sum_j m_j (p_i/rho_i^2 + p_j/rho_j^2 + Pi_ij) grad_i W_ij + g   (O8)
 *                              + nu lap(v)_i        (Morris, Fox & Zhu 1997, (O12)) + f_wall
 *                  Pi_ij: artificial viscosity of Monaghan (1992), fluid-fluid pairs;
 *                  nu = 1e-6 m^2/s (water) at the experiment's scale a = 2.25 in
 *   state          p = rho0 c0^2 / gamma ((rho/rho0)^gamma - 1), gamma = 7 (Tait)
 *   walls          several layers of fixed wall particles whose pressure is
 *                  extrapolated from the fluid with the hydrostatic term
 *                  (Adami, Hu & Adams 2012, J. Comput. Phys. 231, 7057);
 *                  the particle viscous terms see free-slip walls (--noslip 1:
 *                  no-slip through the wall velocity of Adami et al.), and
 *                  f_wall is the shear stress of the laminar wall layer, far
 *                  thinner than dx, from Stokes' first problem (wall_friction)
 *   front          furthest fluid particle on the floor that has >= 4 fluid
 *                  neighbours (a connected layer, not a drop), + dx/2
 *   time stepping  kick-drift-kick (velocity Verlet) with the CFL, force and
 *                  viscous limits on dt
 * Kernel sums: the library's pair terms over lists from its neighbour search.
 * The lists are Verlet lists with a skin of 0.25 h, rebuilt when a particle
 * has moved 0.125 h: the search costs more than the three pair loops together
 * (measured: 55 % of the run time when searching every step), the skin adds
 * about 25 % pairs, and the particles move at most 0.05 h per step (CFL with
 * c0 >= 5 |v|), so the lists last a few steps. --skin 0 searches every step.
 *
 * OpenMP: on a machine whose cores are busy with other work, run with
 * OMP_WAIT_POLICY=passive (make run-dam-break does): threads spinning at the
 * barriers of the pair loops made a 2-thread run 5-6 times slower than one
 * thread there (measured; passive: faster than one thread).
 *
 * Validation (docs/examples.md, "Validation protocol"): the front against
 * Martin & Moyce after one least-squares delay (the release of the real
 * column is not instantaneous), its speed, the residual height, and the
 * square column's delay against the a x 2a one; --probe: the wall pressure of
 * the dam break of Buchner (2002) against the measured one.
 *
 * Usage: dam_break [--res 30] [--end 3.5] [--out build/dam_break_out] ...;
 * --help lists every option (each is range-checked before anything runs).
 * --check runs the protocol at the default resolution and exits 1 when a
 * target is missed; without the measurements (data/dam_break) nothing runs
 * and the exit status is 1; a state that stops being finite ends the run
 * (no further frame) with exit status 1. */
#include "example_io.h"

#include <math.h>
#include <stddef.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define GRAV 9.81
#define RHO0 1000.0
#define GAMMA 7.0
/* The fluid only loses mechanical energy (viscosity, wall friction, impact):
 * E_k + E_p may exceed the E_p of the column at rest by the elastic energy of
 * its hydrostatic compression (below 0.5 % at c0 = 10 sqrt(g H)) and little
 * more; a run past 1.05 E_p(0) has created energy and stops with exit 1. */
#define DB_ENERGY_FACTOR 1.05
#define DB_BOUNDS "a run stops with exit 1 when the fluid's mechanical energy E_k + E_p exceeds 1.05 E_p at the release"

/* ---- measurements ---- */

/* One measured series of Martin & Moyce: times in units of sqrt(a/g) (tau),
 * values Z = x/a (front) or H = eta / (n^2 a) (height). */
typedef struct {
    int n;
    double tau[64], val[64];
} series;

/* Reads columns (ct, cv) of a CSV (# comments, one header line) into s;
 * time_scale converts the file's time column to tau = t sqrt(g/a).
 * Rows before the first measurement (the added initial condition t = 0) are skipped. */
static int read_series(const char *dir, const char *file, int ct, int cv, double time_scale, series *s)
{
    char path[1200], line[512];
    FILE *f;
    int header = 0;
    snprintf(path, sizeof path, "%s/%s", dir, file);
    s->n = 0;
    if ((f = fopen(path, "r")) == NULL) {
        fprintf(stderr, "dam_break: cannot open %s\n", path);
        return -1;
    }
    while (fgets(line, sizeof line, f) != NULL && s->n < 64) {
        double col[8];
        int nc = 0;
        char *p = line;
        if (line[0] == '#') continue;
        if (!header) {
            header = 1;
            continue;
        }
        while (nc < 8) {
            char *end;
            col[nc] = strtod(p, &end);
            if (end == p) col[nc] = NAN;
            ++nc;
            p = strchr(end, ',');
            if (p == NULL) break;
            ++p;
        }
        if (nc <= ct || nc <= cv || !(col[ct] > 0) || col[cv] != col[cv]) continue;
        s->tau[s->n] = col[ct] * time_scale;
        s->val[s->n] = col[cv];
        ++s->n;
    }
    fclose(f);
    if (s->n == 0) fprintf(stderr, "dam_break: no measurements in %s\n", path);
    return s->n > 0 ? 0 : -1;
}

/* Linear interpolation of (t[k], y[k]), k < n, at time x; NAN outside. */
static double interp(const double *t, const double *y, int n, double x)
{
    int k;
    for (k = 1; k < n; ++k)
        if (x >= t[k - 1] && x <= t[k])
            return t[k] > t[k - 1] ? y[k - 1] + (y[k] - y[k - 1]) * (x - t[k - 1]) / (t[k] - t[k - 1]) : y[k];
    return NAN;
}

/* ---- the particle system ---- */

typedef struct {
    int n, nf;          /* particles, of which fluid 0..nf-1, walls nf..n-1 */
    double a, n2;       /* column width a, height n2 a */
    double dx, h, c0, mass0;
    sph_real *x, *v, *rho, *p, *P, *m, *acc, *drho, *vh;
    sph_kernel k;
    double kappa, alpha, delta;
    double nu;     /* laminar kinematic viscosity (m^2/s), 0: none */
    int noslip;    /* walls: 1 no-slip (viscous term with the extrapolated wall velocity), 0 free slip */
    int front_k;   /* front: fluid neighbours a floor particle needs to count (measure) */
    sph_real *vw;    /* wall velocity for the viscous term (Adami et al. 2012) */
    int stokes;    /* 1: friction of the unresolved laminar layer on the floor and back wall (wall_friction) */
    double xwall;  /* face of the far wall (the tank length) */
    int ncell;     /* floor cells of width dx ... */
    double *wet;   /* ... and the time each got wet (-1: still dry) */
    /* neighbour search */
    sph_nsearch g;
    void *work;
    size_t work_bytes;
    sph_off *offset;
    sph_idx *index;
    sph_off capacity;
    sph_neighbours list;
    sph_real *W, *F; /* kernel of each listed pair, computed once per step (O1) */
    double skin;   /* lists hold pairs within (kappa + skin) h ... */
    sph_real *x0;    /* ... and are rebuilt when a particle has moved skin h / 2 from x0 */
    long searches;
} sim;

/* ex_calloc (count x size, overflow checked); a failure ends the program
 * (exit 1) after ex_calloc's message naming what. */
static void *xalloc(size_t count, size_t size, const char *what)
{
    void *p = ex_calloc(count, size, what);
    if (p == NULL) exit(1);
    return p;
}

/* Tait equation of state and its inverse. */
static double tait_p(const sim *s, double rho) { return RHO0 * s->c0 * s->c0 / GAMMA * (pow(rho / RHO0, GAMMA) - 1); }
static double tait_rho(const sim *s, double p) { return RHO0 * pow(1 + GAMMA * p / (RHO0 * s->c0 * s->c0), 1 / GAMMA); }

/* Lays out the column (nx x ny fluid particles, hydrostatic density) and the
 * tank walls of height wall_h (layers thick enough to fill the kernel support kappa h of the
 * fluid next to them, under the floor and outside both side walls). */
static void setup(sim *s, int res, double a, double n2, double tank_len, double wall_h, double hfac, double c0fac)
{
    const int layers = (int)ceil(s->kappa * hfac - 1e-9);
    const double dx = a / res, H = n2 * a;
    const int nx = res, ny = (int)floor(n2 * res + 0.5);
    const int nfloor = (int)ceil(tank_len / dx), nside = (int)ceil(wall_h / dx);
    int i, j, l, c = 0;
    s->a = a;
    s->n2 = n2;
    s->dx = dx;
    s->h = hfac * dx;
    s->c0 = c0fac * sqrt(GRAV * H);
    sph_idx count;
    if (ex_particle_count((double)nx * ny + (double)layers * (nfloor + 2 * layers) + 2.0 * layers * nside,
                          "particles (--res, --tank)", &count) != SPH_OK)
        exit(1);
    s->nf = nx * ny;
    s->n = count;
    s->x = (sph_real *)xalloc(2 * (size_t)s->n, sizeof(sph_real), "particle vectors");
    s->v = (sph_real *)xalloc(2 * (size_t)s->n, sizeof(sph_real), "particle vectors");
    s->vh = (sph_real *)xalloc(2 * (size_t)s->n, sizeof(sph_real), "particle vectors");
    s->acc = (sph_real *)xalloc(2 * (size_t)s->n, sizeof(sph_real), "particle vectors");
    s->rho = (sph_real *)xalloc((size_t)s->n, sizeof(sph_real), "particle scalars");
    s->p = (sph_real *)xalloc((size_t)s->n, sizeof(sph_real), "particle scalars");
    s->P = (sph_real *)xalloc((size_t)s->n, sizeof(sph_real), "particle scalars");
    s->m = (sph_real *)xalloc((size_t)s->n, sizeof(sph_real), "particle scalars");
    s->drho = (sph_real *)xalloc((size_t)s->n, sizeof(sph_real), "particle scalars");
    s->vw = (sph_real *)xalloc(2 * (size_t)s->n, sizeof(sph_real), "particle vectors");
    s->ncell = nfloor;
    s->xwall = nfloor * dx;
    s->wet = (double *)xalloc((size_t)nfloor, sizeof(double), "floor cells");
    for (i = 0; i < nfloor; ++i) s->wet[i] = i < nx ? 0 : -1; /* under the column: wet from the start */
    s->offset = (sph_off *)xalloc((size_t)s->n + 1, sizeof(sph_off), "neighbour-list offsets");
    s->x0 = (sph_real *)xalloc(2 * (size_t)s->n, sizeof(sph_real), "particle vectors");
    for (j = 0; j < ny; ++j)
        for (i = 0; i < nx; ++i, ++c) {
            s->x[2 * c] = (i + 0.5) * dx;
            s->x[2 * c + 1] = (j + 0.5) * dx;
        }
    for (l = 0; l < layers; ++l) {
        const double off = (l + 0.5) * dx;
        for (i = -layers; i < nfloor + layers; ++i, ++c) { /* floor, corners included */
            s->x[2 * c] = (i + 0.5) * dx;
            s->x[2 * c + 1] = -off;
        }
        for (j = 0; j < nside; ++j, c += 2) { /* back wall (x < 0) and far wall (x > L) */
            s->x[2 * c] = -off;
            s->x[2 * c + 1] = (j + 0.5) * dx;
            s->x[2 * c + 2] = nfloor * dx + off;
            s->x[2 * c + 3] = (j + 0.5) * dx;
        }
    }
    for (i = 0; i < s->n; ++i) { /* hydrostatic start: p = rho0 g (H - y), mass = rho dx^2 */
        const double y = s->x[2 * i + 1];
        s->p[i] = i < s->nf ? RHO0 * GRAV * (H - y) : 0;
        s->rho[i] = i < s->nf ? tait_rho(s, s->p[i]) : RHO0;
        s->m[i] = s->rho[i] * dx * dx;
    }
}

/* Neighbour lists of every particle (targets = sources = all, gather form)
 * within (kappa + skin) h: a Verlet list, valid until some particle has moved
 * skin h / 2 (two particles then approach by at most skin h). Pairs beyond
 * kappa h in the list have W = F = 0 (O1) and add nothing. */
static void search(sim *s)
{
    const sph_view xs = sph_view_interleaved(s->x, 2);
    const double kappa = s->kappa + s->skin, cell = kappa * s->h / 2;
    sph_idx i;
    double moved = 0;
    if (s->searches > 0) {
        for (i = 0; i < s->nf; ++i) {
            const double d0 = s->x[2 * i] - s->x0[2 * i], d1 = s->x[2 * i + 1] - s->x0[2 * i + 1];
            if (d0 * d0 + d1 * d1 > moved) moved = d0 * d0 + d1 * d1;
        }
        if (sqrt(moved) < 0.5 * s->skin * s->h) return;
    }
    ++s->searches;
    memcpy(s->x0, s->x, 2 * sizeof(sph_real) * (size_t)s->n);
    size_t bytes;
    int st = sph_nsearch_workspace_size(2, xs, s->n, sph_view_none(), cell, NULL, &bytes);
    if (st == SPH_OK && bytes > s->work_bytes) {
        free(s->work);
        s->work_bytes = bytes + bytes / 4;
        s->work = xalloc(s->work_bytes, 1, "the neighbour-search workspace");
    }
    if (st == SPH_OK) st = sph_nsearch_build(&s->g, 2, xs, s->n, sph_view_none(), cell, NULL, s->work, s->work_bytes);
    /* one search into the index of the last step; where it has become too
     * short, offset is complete: grow the arrays and fill at those offsets */
    sph_off pairs = 0;
    if (st == SPH_OK)
        st = sph_nsearch_lists(&s->g, xs, s->n, sph_view_none(), s->h, kappa, SPH_NSEARCH_GATHER, s->offset, s->index,
                               s->capacity, &pairs);
    if (st == SPH_ESIZE) {
        free(s->index);
        s->capacity = pairs + pairs / 4;
        s->index = (sph_idx *)xalloc((size_t)s->capacity, sizeof(sph_idx), "neighbour lists");
        free(s->W), free(s->F);
        s->W = (sph_real *)xalloc((size_t)s->capacity, sizeof(sph_real), "pair kernels");
        s->F = (sph_real *)xalloc((size_t)s->capacity, sizeof(sph_real), "pair kernels");
        st = sph_nsearch_fill(&s->g, xs, s->n, sph_view_none(), s->h, kappa, SPH_NSEARCH_GATHER, s->offset, s->index,
                              s->capacity);
    }
    if (st != SPH_OK) {
        fprintf(stderr, "dam_break: neighbour search failed: %s\n", sph_strerror(st));
        exit(2);
    }
    s->list = sph_nsearch_list(&s->g, s->n, s->offset, s->index);
}

/* dx = x_i - x_j (O0, no periodic box). */
static void delta(const sim *s, sph_idx i, sph_idx j, sph_real *dx)
{
    dx[0] = s->x[2 * i] - s->x[2 * j];
    dx[1] = s->x[2 * i + 1] - s->x[2 * j + 1];
}

/* W and F of every listed pair (O1), once per step for the three pair loops.
 * Wall-wall pairs are never used and pairs in the skin (beyond kappa h) have
 * W = F = 0: both are set to 0 without evaluating the kernel (most of the
 * listed pairs are one or the other). */
static void pair_kernels(sim *s)
{
    const double rmax2 = s->kappa * s->h * s->kappa * s->h;
    sph_idx i;
#ifdef _OPENMP
#pragma omp parallel for schedule(static)
#endif
    for (i = 0; i < s->n; ++i) {
        sph_off o;
        for (o = s->list.offset[i]; o < s->list.offset[i + 1]; ++o) {
            const sph_idx j = s->list.index[o];
            sph_real dx[2];
            sph_pair pr;
            delta(s, i, j, dx);
            if ((i >= s->nf && j >= s->nf) || dx[0] * dx[0] + dx[1] * dx[1] >= rmax2) {
                s->W[o] = s->F[o] = 0;
                continue;
            }
            pr = sph_pair_kernel(s->k, 2, dx, s->h);
            s->W[o] = pr.W;
            s->F[o] = pr.F;
        }
    }
}

/* Continuity with density diffusion for the fluid, velocities vel:
 * drho_i = -sum_j m_j (v_j - v_i) . x_ij F_ij          (O10, m_j for V_j)
 *          + delta h c0 * 2 sum_j V_j (rho_i - rho_j) F_ij   (O12, fluid pairs).
 * Wall particles take part with their velocity (zero). */
static void continuity(sim *s, const sph_real *vel)
{
    sph_idx i;
#ifdef _OPENMP
#pragma omp parallel for schedule(static)
#endif
    for (i = 0; i < s->nf; ++i) {
        double d = 0, lap = 0;
        sph_off o;
        for (o = s->list.offset[i]; o < s->list.offset[i + 1]; ++o) {
            const sph_idx j = s->list.index[o];
            sph_real dx[2];
            if (j == i) continue;
            delta(s, i, j, dx);
            d -= sph_pair_div_difference(2, s->m[j], vel + 2 * i, vel + 2 * j, s->F[o], dx);
            if (j < s->nf) lap += sph_pair_laplacian(s->m[j] / s->rho[j], s->rho[i], s->rho[j], s->F[o]);
        }
        s->drho[i] = d + s->delta * s->h * s->c0 * lap;
    }
}

/* Wall pressure (Adami, Hu & Adams 2012, stationary wall, gravity (0, -g)):
 * p_w = (sum_f p_f W_wf + g . sum_f rho_f (x_w - x_f) W_wf) / sum_f W_wf,
 * each sum a Shepard interpolation (O3, V = 1) over the fluid neighbours;
 * clamped at 0 (no suction) and turned into a density by the inverse EOS.
 * Wall velocity for the viscous term (same paper, no-slip at a wall at rest):
 * v_w = -sum_f v_f W_wf / sum_f W_wf (fluid velocities vel). */
static void wall_pressure(sim *s, const sph_real *vel)
{
    sph_idx w;
#ifdef _OPENMP
#pragma omp parallel for schedule(static)
#endif
    for (w = s->nf; w < s->n; ++w) {
        double sw = 0, sp = 0, su = 0, sv = 0;
        sph_off o;
        for (o = s->list.offset[w]; o < s->list.offset[w + 1]; ++o) {
            const sph_idx f = s->list.index[o];
            sph_real dx[2];
            if (f >= s->nf) continue;
            delta(s, w, f, dx);
            sw += sph_pair_interpolate(1, 1, s->W[o]);
            sp += sph_pair_interpolate(1, s->p[f] - GRAV * s->rho[f] * dx[1], s->W[o]);
            su += sph_pair_interpolate(1, vel[2 * f], s->W[o]);
            sv += sph_pair_interpolate(1, vel[2 * f + 1], s->W[o]);
        }
        s->p[w] = sw > 0 && sp > 0 ? sp / sw : 0;
        s->vw[2 * w] = sw > 0 ? -su / sw : 0;
        s->vw[2 * w + 1] = sw > 0 ? -sv / sw : 0;
        s->rho[w] = tait_rho(s, s->p[w]);
        s->P[w] = sph_pressure_factor(s->p[w], s->rho[w]);
    }
}

/* Accelerations of the fluid: pressure (O8), Monaghan's artificial viscosity
 * Pi_ij = -alpha c0 h mu_ij / rho_ij, mu_ij = v_ij . x_ij / (r^2 + 0.01 h^2)
 * for approaching fluid pairs (also in the pressure form of (O8): it adds
 * m_j Pi_ij grad_i W_ij), laminar viscosity nu lap v (Morris, Fox & Zhu 1997:
 * (O12) per component, V_j = m_j / rho_j; with no-slip walls also over the
 * wall particles with their velocity v_w), gravity. Returns max |a|. */
static double momentum(sim *s, const sph_real *vel)
{
    double amax = 0;
    sph_idx i;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) reduction(max : amax)
#endif
    for (i = 0; i < s->nf; ++i) {
        sph_real acc[2] = {0, 0};
        double visc[2] = {0, 0}, an;
        sph_off o;
        for (o = s->list.offset[i]; o < s->list.offset[i + 1]; ++o) {
            const sph_idx j = s->list.index[o];
            sph_real dx[2];
            double Pi = 0;
            if (j == i) continue;
            delta(s, i, j, dx);
            if (s->nu > 0 && (j < s->nf || s->noslip)) {
                const sph_real *vj = j < s->nf ? vel + 2 * j : s->vw + 2 * j;
                const double Vj = s->m[j] / s->rho[j];
                visc[0] += sph_pair_laplacian(Vj, vel[2 * i], vj[0], s->F[o]); /* (O12) */
                visc[1] += sph_pair_laplacian(Vj, vel[2 * i + 1], vj[1], s->F[o]);
            }
            if (j < s->nf) {
                const double vr = (vel[2 * i] - vel[2 * j]) * dx[0] + (vel[2 * i + 1] - vel[2 * j + 1]) * dx[1];
                if (vr < 0) {
                    const double mu = s->h * vr / (dx[0] * dx[0] + dx[1] * dx[1] + 0.01 * s->h * s->h);
                    Pi = -s->alpha * s->c0 * mu / (0.5 * (s->rho[i] + s->rho[j]));
                }
            }
            sph_pair_grad_pressure(2, s->m[j], s->P[i] + 0.5 * Pi, s->P[j] + 0.5 * Pi, s->F[o], dx, acc);
        }
        s->acc[2 * i] = -acc[0] + s->nu * visc[0];
        s->acc[2 * i + 1] = -acc[1] + s->nu * visc[1] - GRAV;
        an = sqrt(s->acc[2 * i] * s->acc[2 * i] + s->acc[2 * i + 1] * s->acc[2 * i + 1]);
        if (an > amax) amax = an;
    }
    return amax;
}

/* Wall friction of the laminar boundary layer the particles do not resolve
 * (its thickness sqrt(pi nu t) stays below dx / 2 up to tau = 3.5 at the
 * default resolution, and far below near the front, where the floor has just
 * got wet; the model assumes it is thinner than dx): Stokes'
 * first problem (Schlichting, Boundary-Layer Theory, ch. 5) gives the wall
 * shear stress tau_w = rho u sqrt(nu / (pi t_w)) of a layer that started
 * t_w ago at slip velocity u. Each fluid particle whose centre lies within dx
 * of the floor (back wall) takes its share tau_w dx / m of the stress on its
 * strip, against its velocity along the wall; t_w is the time since the
 * fluid reached the particle's floor cell (since the release for the back
 * wall and the floor under the column), at least one time step. Only
 * physical constants: nu (water) and the real scale a. */
static void wall_friction(sim *s, const sph_real *vel, double t, double dt)
{
    sph_idx i;
    for (i = 0; i < s->nf; ++i) { /* floor cells reached by the fluid */
        const int cell = (int)floor(s->x[2 * i] / s->dx);
        if (s->x[2 * i + 1] < s->dx && cell >= 0 && cell < s->ncell && s->wet[cell] < 0) s->wet[cell] = t;
    }
    for (i = 0; i < s->nf; ++i) {
        const double share = RHO0 * s->dx / s->m[i] * sqrt(s->nu / 3.14159265358979323846);
        if (s->x[2 * i + 1] < s->dx) {
            const int cell = (int)floor(s->x[2 * i] / s->dx);
            const double age = cell >= 0 && cell < s->ncell && s->wet[cell] >= 0 ? t - s->wet[cell] : 0;
            s->acc[2 * i] -= share * vel[2 * i] / sqrt(age > dt ? age : dt);
        }
        if (s->x[2 * i] < s->dx) s->acc[2 * i + 1] -= share * vel[2 * i + 1] / sqrt(t > dt ? t : dt);
    }
}

static void fluid_pressure(sim *s)
{
    sph_idx i;
    for (i = 0; i < s->nf; ++i) {
        s->p[i] = tait_p(s, s->rho[i]);
        s->P[i] = sph_pressure_factor(s->p[i], s->rho[i]);
    }
}

/* Fluid neighbours of fluid particle i inside the kernel support (W > 0). */
static int fluid_neighbours(const sim *s, sph_idx i)
{
    int c = 0;
    sph_off o;
    for (o = s->list.offset[i]; o < s->list.offset[i + 1]; ++o)
        c += s->list.index[o] != i && s->list.index[o] < s->nf && s->W[o] > 0;
    return c;
}

/* Surge front x/a: the furthest fluid particle lying on the floor (centre
 * within 2 spacings of it) with at least front_k fluid neighbours in its
 * kernel support, plus half a spacing; drops and thin spray that have left the
 * layer do not count. Zraw: the furthest fluid particle plus half a spacing.
 * Residual height at the back wall eta / (n^2 a): highest fluid particle
 * within two spacings of the wall plus half a spacing. */
static void measure(const sim *s, double *Z, double *Zraw, double *H)
{
    double xf = 0, xr = 0, yh = 0;
    sph_idx i;
    for (i = 0; i < s->nf; ++i) {
        if (s->x[2 * i] > xr) xr = s->x[2 * i];
        if (s->x[2 * i] > xf && s->x[2 * i + 1] < 2 * s->dx && fluid_neighbours(s, i) >= s->front_k) xf = s->x[2 * i];
        if (s->x[2 * i] < 2 * s->dx && s->x[2 * i + 1] > yh) yh = s->x[2 * i + 1];
    }
    *Z = (xf + 0.5 * s->dx) / s->a;
    *Zraw = (xr + 0.5 * s->dx) / s->a;
    *H = (yh + 0.5 * s->dx) / (s->n2 * s->a);
}

/* Wall-pressure probe: the fluid pressure interpolated at PROBE_POINTS points
 * of the far wall's face x = xwall, y0 <= y <= y1 (the sensor's face), by
 * the Shepard sum p(x) = sum_f p_f W(x - x_f) / sum_f W(x - x_f) over the
 * fluid particles (O3 with V = 1), and averaged over the points; 0 where no
 * fluid is within reach (dry wall). */
#define PROBE_POINTS 10
static double probe_pressure(const sim *s, double y0, double y1)
{
    const double reach = s->kappa * s->h;
    double sum = 0;
    int q;
    for (q = 0; q < PROBE_POINTS; ++q) {
        const double y = y0 + (y1 - y0) * (q + 0.5) / PROBE_POINTS;
        double sw = 0, sp = 0;
        sph_idx i;
        for (i = 0; i < s->nf; ++i) {
            sph_real dx[2];
            sph_pair pr;
            dx[0] = s->xwall - s->x[2 * i];
            dx[1] = y - s->x[2 * i + 1];
            if (fabs(dx[0]) >= reach || fabs(dx[1]) >= reach) continue;
            pr = sph_pair_kernel(s->k, 2, dx, s->h);
            sw += sph_pair_interpolate(1, 1, pr.W);
            sp += sph_pair_interpolate(1, s->p[i], pr.W);
        }
        sum += sw > 0 ? sp / sw : 0;
    }
    return sum / PROBE_POINTS;
}

/* Position, velocity, pressure and density of every particle as VTK fields
 * (f[0] the positions, which ex_series_write takes apart). */
static void particle_fields(const sim *s, ex_field f[4])
{
    f[0].name = "position", f[0].v = sph_view_interleaved(s->x, 2), f[0].ncomp = 2;
    f[1].name = "velocity", f[1].v = sph_view_interleaved(s->v, 2), f[1].ncomp = 2;
    f[2].name = "pressure", f[2].v = sph_view_soa(s->p, NULL, NULL), f[2].ncomp = 1;
    f[3].name = "density", f[3].v = sph_view_soa(s->rho, NULL, NULL), f[3].ncomp = 1;
}

/* One particle frame (time t) of the run's series; exits when it cannot be written. */
static void write_frame(const sim *s, ex_series *ser, double t)
{
    ex_field f[4];
    particle_fields(s, f);
    if (ex_series_write(ser, t, s->n, 2, f[0].v, f + 1, 3) != 0) exit(1);
}

/* ---- one simulation ---- */

typedef struct {
    int res, vtk_every, noslip, front_k, stokes, ascii;
    double end_tau, tank, hfac, alpha, delta, a, skin, nu, c0fac;
    double wall_h;           /* side walls: height / column height */
    double probe_y0, probe_y1; /* far-wall pressure probe between these heights (m); none when equal */
    const char *kernel, *out;
} params;

/* Per step: tau, front (layer and furthest particle), height, probe pressure. */
#define HIST_SERIES 5
typedef struct {
    int n, cap;
    double *tau, *Z, *Zraw, *H, *P1;
    int particles, fluid;
    long steps, searches;
    double seconds;
    double wall; /* the far wall's face, x / a */
} history;

static void history_push(history *h, const double *row)
{
    double **col[HIST_SERIES];
    int c;
    col[0] = &h->tau, col[1] = &h->Z, col[2] = &h->Zraw, col[3] = &h->H, col[4] = &h->P1;
    if (h->n == h->cap) {
        if (h->cap > (1 << 28)) {
            fprintf(stderr, "dam_break: history longer than %d steps\n", h->cap);
            exit(2);
        }
        h->cap = h->cap ? 2 * h->cap : 1024;
        for (c = 0; c < HIST_SERIES; ++c) {
            double *grown = (double *)realloc(*col[c], sizeof(double) * (size_t)h->cap);
            if (grown == NULL) {
                fprintf(stderr, "dam_break: out of memory (history of %d steps)\n", h->cap);
                exit(2);
            }
            *col[c] = grown;
        }
    }
    for (c = 0; c < HIST_SERIES; ++c) (*col[c])[h->n] = row[c];
    ++h->n;
}

static void history_free(history *h)
{
    free(h->tau), free(h->Z), free(h->Zraw), free(h->H), free(h->P1);
    memset(h, 0, sizeof *h);
}

/* One step's row of the history: tau, front, height, probe pressure. */
static void record(const sim *s, const params *pm, double tau, history *hist)
{
    double row[HIST_SERIES];
    row[0] = tau;
    measure(s, &row[1], &row[2], &row[3]);
    row[4] = pm->probe_y1 > pm->probe_y0 ? probe_pressure(s, pm->probe_y0, pm->probe_y1) : NAN;
    history_push(hist, row);
}

/* Kinetic plus potential energy of the fluid, E_p = m g y above the floor. */
static double mechanical_energy(const sim *s)
{
    double e = 0;
    sph_idx i;
    for (i = 0; i < s->nf; ++i)
        e += s->m[i] * (0.5 * (s->v[2 * i] * s->v[2 * i] + s->v[2 * i + 1] * s->v[2 * i + 1]) + GRAV * s->x[2 * i + 1]);
    return e;
}

/* Runs the column a x n2 a to tau = end_tau, recording front, height and
 * probe every step. Stops the program (exit 1, no further frames) when the
 * state stops being finite or its mechanical energy grows past
 * DB_ENERGY_FACTOR times that at the release. */
static void run(const params *pm, double n2, history *hist, int quiet)
{
    sim s;
    const double tscale = sqrt(pm->a / GRAV); /* tau = t / tscale */
    double t = 0, amax, dt;
    long step = 0;
    char label[64];
    ex_series ser;
    const int frames = pm->out && pm->vtk_every > 0;
    ex_field fields[4];
    ex_progress prog = ex_progress_start();
    ex_growth energy = {"mechanical energy E_k + E_p of the fluid (J/m)",
                        "the scheme created energy: raise --c0 or --res, or check --hfac and --alpha", 0,
                        DB_ENERGY_FACTOR, 0};
    sph_idx i;
    memset(&s, 0, sizeof s);
    s.k = (sph_kernel)sph_kernel_from_name(pm->kernel);
    s.kappa = sph_kernel_support(s.k);
    s.alpha = pm->alpha;
    s.nu = pm->nu;
    s.noslip = pm->noslip;
    s.front_k = pm->front_k;
    s.stokes = pm->stokes;
    s.delta = pm->delta;
    s.skin = pm->skin;
    setup(&s, pm->res, pm->a, n2, pm->tank * pm->a, pm->wall_h * n2 * pm->a, pm->hfac, pm->c0fac);
    hist->particles = s.n;
    hist->wall = s.xwall / s.a;
    hist->fluid = s.nf;
    snprintf(label, sizeof label, "dam_break n^2=%g res %d", n2, pm->res);
    search(&s);
    pair_kernels(&s);
    fluid_pressure(&s);
    wall_pressure(&s, s.v);
    amax = momentum(&s, s.v);
    record(&s, pm, 0, hist);
    if (frames) {
        char name[64];
        snprintf(name, sizeof name, "dam_break_n2-%g", n2);
        if (ex_series_open(&ser, pm->out, name, pm->ascii) != 0) exit(1);
        write_frame(&s, &ser, 0);
    }
    particle_fields(&s, fields);
    energy.start = mechanical_energy(&s);
    while (t < pm->end_tau * tscale) {
        double vmax = 0;
        for (i = 0; i < s.nf; ++i) {
            const double vn = sqrt(s.v[2 * i] * s.v[2 * i] + s.v[2 * i + 1] * s.v[2 * i + 1]);
            if (vn > vmax) vmax = vn;
        }
        dt = 0.25 * s.h / (s.c0 + vmax);                                   /* CFL */
        if (amax > 0 && 0.25 * sqrt(s.h / amax) < dt) dt = 0.25 * sqrt(s.h / amax); /* force */
        if (s.alpha > 0 && 0.125 * 8 * s.h / (s.alpha * s.c0) < dt)            /* viscous: nu = alpha h c0 / 8 */
            dt = 0.125 * 8 * s.h / (s.alpha * s.c0);
        if (s.nu > 0 && 0.125 * s.h * s.h / s.nu < dt) dt = 0.125 * s.h * s.h / s.nu; /* laminar viscous */
        for (i = 0; i < s.nf; ++i) { /* kick, drift */
            s.vh[2 * i] = s.v[2 * i] + 0.5 * dt * s.acc[2 * i];
            s.vh[2 * i + 1] = s.v[2 * i + 1] + 0.5 * dt * s.acc[2 * i + 1];
            s.x[2 * i] += dt * s.vh[2 * i];
            s.x[2 * i + 1] += dt * s.vh[2 * i + 1];
        }
        search(&s);
        pair_kernels(&s);
        continuity(&s, s.vh); /* density at the new positions with the mid-step velocity */
        for (i = 0; i < s.nf; ++i) s.rho[i] += dt * s.drho[i];
        fluid_pressure(&s);
        wall_pressure(&s, s.vh);
        amax = momentum(&s, s.vh);
        if (s.stokes) wall_friction(&s, s.vh, t + dt, dt);
        for (i = 0; i < s.nf; ++i) { /* kick */
            s.v[2 * i] = s.vh[2 * i] + 0.5 * dt * s.acc[2 * i];
            s.v[2 * i + 1] = s.vh[2 * i + 1] + 0.5 * dt * s.acc[2 * i + 1];
        }
        t += dt;
        ++step;
        if (ex_fields_finite("dam_break", fields, 4, s.nf, t) != SPH_OK ||
            ex_growth_check(&energy, mechanical_energy(&s), t) != SPH_OK) {
            if (frames) ex_series_report(&ser), ex_series_close(&ser);
            exit(1);
        }
        record(&s, pm, t / tscale, hist);
        if (frames && step % pm->vtk_every == 0) write_frame(&s, &ser, t);
        if (!quiet) ex_progress_update(&prog, label, t / (pm->end_tau * tscale));
    }
    if (!quiet) ex_progress_done(&prog, label);
    if (frames) ex_series_report(&ser), ex_series_close(&ser);
    hist->steps = step;
    hist->searches = s.searches;
    hist->seconds = ex_now() - prog.start;
    free(s.x), free(s.v), free(s.vh), free(s.acc), free(s.rho), free(s.p), free(s.P), free(s.m), free(s.drho), free(s.vw), free(s.wet);
    free(s.offset), free(s.index), free(s.work), free(s.W), free(s.F), free(s.x0);
}

/* ---- comparison with the measurements ---- */

/* One column of Martin & Moyce: its measured front and height. */
typedef struct {
    double n2;
    series front, height;
    int have;
} experiment;

/* Reads the two series of column n^2 = n2. The front files give T = n tau,
 * the height files tau (data README). 0 when both were read. */
static int load_experiment(const char *dir, double n2, experiment *e)
{
    const double n = sqrt(n2);
    int st;
    e->n2 = n2;
    if (n2 == 2) {
        st = read_series(dir, "mm1952_n2-2_a2.25in_front_table2.csv", 0, 1, 1 / n, &e->front);
        st |= read_series(dir, "mm1952_n2-2_a2.25in_height_table6.csv", 0, 1, 1, &e->height);
    } else {
        st = read_series(dir, "mm1952_n2-1_a2.25in_front.csv", 0, 1, 1 / n, &e->front);
        st |= read_series(dir, "mm1952_n2-1_a2.25in_height.csv", 0, 1, 1, &e->height);
    }
    e->have = st == 0;
    return st;
}

/* Largest relative deviation |sim - exp| / exp of the simulated series
 * (tau[], val[], n entries) over the measured points inside the simulated
 * time; *lo, *hi: the tau range compared, *count: points compared. */
static double deviation(const series *m, const double *tau, const double *val, int n, double *lo, double *hi,
                        int *count)
{
    double worst = 0;
    int k;
    *lo = *hi = NAN;
    *count = 0;
    for (k = 0; k < m->n; ++k) {
        double d;
        if (m->tau[k] > tau[n - 1]) continue;
        d = fabs(interp(tau, val, n, m->tau[k]) - m->val[k]) / m->val[k];
        if (d > worst) worst = d;
        if (*count == 0) *lo = m->tau[k];
        *hi = m->tau[k];
        ++*count;
    }
    return worst;
}

/* First time at which the simulated front reaches Z (NAN if it never does). */
static double reach_time(const history *h, const double *val, double Z)
{
    int k;
    for (k = 1; k < h->n; ++k)
        if (val[k] >= Z) return h->tau[k - 1] + (h->tau[k] - h->tau[k - 1]) * (Z - val[k - 1]) / (val[k] - val[k - 1]);
    return NAN;
}

/* Least-squares slope dZ/dT over the measured times k = ka..kb of m (T = n
 * tau): of m's own values when htau is NULL, else of the series (htau, z,
 * hn) interpolated at those times. */
static double slope(const series *m, int ka, int kb, double n, const double *z, const double *htau, int hn)
{
    double st = 0, sz = 0, stt = 0, stz = 0;
    int k, c = 0;
    for (k = ka; k <= kb; ++k, ++c) {
        const double T = n * m->tau[k], Z = htau ? interp(htau, z, hn, m->tau[k]) : z[k];
        st += T, sz += Z, stt += T * T, stz += T * Z;
    }
    return (c * stz - st * sz) / (c * stt - st * st);
}

/* Median of x[0..n-1] (n <= 64; x is reordered). */
static double median(double *x, int n)
{
    int i, j;
    for (i = 1; i < n; ++i)
        for (j = i; j > 0 && x[j] < x[j - 1]; --j) {
            const double t = x[j];
            x[j] = x[j - 1];
            x[j - 1] = t;
        }
    return n == 0 ? NAN : n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

/* Prints (and writes to md, when not NULL, as a markdown table) simulated
 * against measured values at the measured times; returns the largest
 * deviation. For the front also: the median lag (measured time minus the
 * time the simulated front reached the same Z, in T and in milliseconds for
 * the column width a), the mean front speed dZ/dT (least-squares slope of Z
 * against T over the measured points from the second on), measured and
 * simulated at the same times (independent of the time origin; *speed_dev:
 * relative deviation), and the largest deviation of the front taken as the
 * furthest particle (no layer condition). */
static double compare(FILE *md, const char *what, double n, double a, const series *m, const history *h,
                      const double *val, double *lag_ms, double *speed_dev)
{
    double lags[64];
    int nlag = 0;
    double lo, hi, worst;
    int k, count;
    const int front = val != h->H;
    worst = deviation(m, h->tau, val, h->n, &lo, &hi, &count);
    printf("  %s (%d points, tau = %.3g .. %.3g):\n", what, count, lo, hi);
    printf("    %8s %8s %10s %10s %8s %s\n", "tau", "T", "measured", "simulated", "dev %", front ? "  lag T" : "");
    if (md) fprintf(md, "\n%s, %d points, tau = %.3g .. %.3g%s:\n\n| tau | T = n tau | measured | simulated | deviation |%s\n|---:|---:|---:|---:|---:|%s\n",
                    what, count, lo, hi, front ? " (lag: measured T minus the T at which the simulated front got there)" : "",
                    front ? " lag in T |" : "", front ? "---:|" : "");
    for (k = 0; k < m->n; ++k) {
        double simulated;
        if (m->tau[k] > h->tau[h->n - 1]) continue;
        simulated = interp(h->tau, val, h->n, m->tau[k]);
        printf("    %8.3f %8.3f %10.3f %10.3f %8.1f", m->tau[k], n * m->tau[k], m->val[k], simulated,
               100 * (simulated - m->val[k]) / m->val[k]);
        if (front) {
            lags[nlag] = n * (m->tau[k] - reach_time(h, val, m->val[k]));
            printf(" %8.3f", lags[nlag]);
            nlag += lags[nlag] == lags[nlag];
        }
        printf("\n");
        if (md) {
            fprintf(md, "| %.3f | %.3f | %.3f | %.3f | %+.1f %% |", m->tau[k], n * m->tau[k], m->val[k], simulated,
                    100 * (simulated - m->val[k]) / m->val[k]);
            if (front) fprintf(md, " %.3f |", n * (m->tau[k] - reach_time(h, val, m->val[k])));
            fprintf(md, "\n");
        }
    }
    printf("    largest deviation %.1f %%\n", 100 * worst);
    if (front) {
        double lo2, hi2, lag, um = NAN, us = NAN;
        int count2, ka = -1, kb = -1, seen = 0;
        const double raw = deviation(m, h->tau, h->Zraw, h->n, &lo2, &hi2, &count2);
        lag = median(lags, nlag);
        *lag_ms = 1e3 * lag / n * sqrt(a / GRAV);
        for (k = 0; k < m->n; ++k) { /* second and last compared points */
            if (m->tau[k] > h->tau[h->n - 1]) continue;
            if (++seen == 2) ka = k;
            kb = k;
        }
        if (ka >= 0 && kb > ka) {
            um = slope(m, ka, kb, n, m->val, NULL, 0);
            us = slope(m, ka, kb, n, val, h->tau, h->n);
            printf("    front speed dZ/dT, T = %.2f .. %.2f: measured %.3f, simulated %.3f (%+.1f %%)\n", n * m->tau[ka],
                   n * m->tau[kb], um, us, 100 * (us - um) / um);
            if (md)
                fprintf(md, "\nMean front speed dZ/dT (least-squares slope over T = %.2f .. %.2f, independent of the time "
                            "origin): measured %.3f, simulated %.3f (%+.1f %%).\n",
                        n * m->tau[ka], n * m->tau[kb], um, us, 100 * (us - um) / um);
        }
        *speed_dev = (us - um) / um;
        printf("    median lag %.3f in T = %.1f ms; front as the furthest particle: largest deviation %.1f %%\n", lag,
               1e3 * lag / n * sqrt(a / GRAV), 100 * raw);
        if (md)
            fprintf(md, "\nLargest deviation %.1f %%. Median lag %.3f in T (%.1f ms). The front taken as the furthest "
                        "particle (no layer condition): largest deviation %.1f %%.\n",
                    100 * worst, lag, 1e3 * lag / n * sqrt(a / GRAV), 100 * raw);
    } else if (md)
        fprintf(md, "\nLargest deviation %.1f %%.\n", 100 * worst);
    return count > 0 ? worst : NAN;
}

/* Time series CSV of one column: tau, T, simulated Z and H, the
 * measurements interpolated at tau (empty outside their range), the front of
 * the furthest particle and T of the simulation delayed by the protocol's
 * fitted delay shift (in tau). */
static void write_csv(const char *dir, const experiment *e, const history *h, double shift)
{
    char path[1200];
    FILE *f;
    int k;
    double next = 0;
    snprintf(path, sizeof path, "%s/dam_break_n2-%g.csv", dir, e->n2);
    if ((f = fopen(path, "w")) == NULL) {
        fprintf(stderr, "dam_break: cannot write %s\n", path);
        return;
    }
    fprintf(f, "# dam break n^2 = %g: tau = t sqrt(g/a), T = n tau, Z = front/a, H = height/(n^2 a); *_exp: "
               "Martin & Moyce 1952 interpolated; Z_sim_furthest: furthest particle; T_delayed: T of the simulation "
               "delayed by the fitted %.4f in T\ntau,T,Z_sim,H_sim,Z_exp,H_exp,Z_sim_furthest,T_delayed\n",
            e->n2, sqrt(e->n2) * shift);
    for (k = 0; k < h->n; ++k) {
        double ze, he;
        if (h->tau[k] < next && k != h->n - 1) continue;
        next = h->tau[k] + 0.01;
        ze = e->have ? interp(e->front.tau, e->front.val, e->front.n, h->tau[k]) : NAN;
        he = e->have ? interp(e->height.tau, e->height.val, e->height.n, h->tau[k]) : NAN;
        fprintf(f, "%.5f,%.5f,%.5f,%.5f,", h->tau[k], sqrt(e->n2) * h->tau[k], h->Z[k], h->H[k]);
        if (ze == ze) fprintf(f, "%.5f", ze);
        fputc(',', f);
        if (he == he) fprintf(f, "%.5f", he);
        fprintf(f, ",%.5f,%.5f\n", h->Zraw[k], sqrt(e->n2) * (h->tau[k] + shift));
    }
    fclose(f);
    printf("wrote %s\n", path);
}

/* The model options of pm that differ from the defaults def, as text
 * ("default" when none do): the resolution table's model column. */
static void describe_variant(const params *pm, const params *def, char *out, size_t size)
{
    size_t len = 0;
    out[0] = '\0';
#define DB_VARIANT(cond, ...)                                                                   \
    do {                                                                                       \
        if ((cond) && len < size) {                                                            \
            len += (size_t)snprintf(out + len, size - len, "%s", len ? ", " : "");             \
            if (len < size) len += (size_t)snprintf(out + len, size - len, __VA_ARGS__);       \
        }                                                                                      \
    } while (0)
    DB_VARIANT(pm->stokes != def->stokes, "%s", pm->stokes ? "wall-layer friction" : "no wall-layer friction");
    DB_VARIANT(pm->noslip != def->noslip, "%s", pm->noslip ? "no-slip walls" : "free-slip walls");
    DB_VARIANT(pm->nu != def->nu, "nu = %g m^2/s", pm->nu);
    DB_VARIANT(pm->c0fac != def->c0fac, "c0 = %g sqrt(g n^2 a)", pm->c0fac);
    DB_VARIANT(pm->alpha != def->alpha, "alpha = %g", pm->alpha);
    DB_VARIANT(pm->delta != def->delta, "delta = %g", pm->delta);
    DB_VARIANT(pm->hfac != def->hfac, "h = %g dx", pm->hfac);
    DB_VARIANT(strcmp(pm->kernel, def->kernel) != 0, "kernel %s", pm->kernel);
    DB_VARIANT(pm->front_k != def->front_k, "front: >= %d neighbours", pm->front_k);
#undef DB_VARIANT
    if (len == 0) snprintf(out, size, "default");
}

static const char *find_data(const char *given)
{
    /* the repository's data/dam_break, from the top of the tree or one or two levels below */
    static const char *candidates[] = {"data/dam_break", "../data/dam_break", "../../data/dam_break"};
    char path[1200];
    size_t k;
    if (given != NULL) return given;
    for (k = 0; k < sizeof candidates / sizeof candidates[0]; ++k) {
        FILE *f;
        snprintf(path, sizeof path, "%s/README.md", candidates[k]);
        if ((f = fopen(path, "r")) != NULL) {
            fclose(f);
            return candidates[k];
        }
    }
    return NULL;
}

/* ---- the validation protocol (docs/examples.md, "Validation protocol") ---- */

/* Targets of the protocol. Martin & Moyce's first point (T = 0.41) and the
 * early surge are dominated by the removal of the board that held the column
 * (docs/examples.md): the front is compared from T = 0.84 on, the same
 * physical time t = 0.594 sqrt(a/g) for the square column. */
#define PR_T_FROM 0.84   /* a x 2a: first compared point, T */
#define PR_T_LATE 1.83   /* a x 2a: start of the late front-speed window, T */
#define PR_TAU_REL 2.45  /* height: relative deviation gated up to this tau */

/* Protocol figures of one run (NAN: not computed). Deviations are relative,
 * (simulated - measured) / measured, except h_abs (in H). */
typedef struct {
    double speed_late, speed_all; /* front speed dZ/dT, T 1.83-3.33 and 0.84-3.33 */
    double shift_T, shift_ms;     /* least-squares delay of the simulated front, T >= 0.84 */
    double worst, rms;            /* largest |deviation| and rms after the delay, T >= 0.84 */
    double worst_raw;             /* largest |deviation| without it, T >= 0.84 */
    double first_raw, first_sh;   /* the point T = 0.41: without and with the delay */
    double h_abs, h_rel;          /* height: largest |H - H_m|; largest |relative| for tau <= 2.45 */
    double sq_shift_ms, sq_gap_ms, sq_worst; /* square: its delay, minus the a x 2a one, largest |dev| after it */
} protocol;

/* The simulated series delayed by shift (in tau) at time tau: the value at
 * tau - shift, the initial value before the start, NAN after the end. */
static double delayed(const history *h, const double *val, double tau, double shift)
{
    return tau - shift <= 0 ? val[0] : interp(h->tau, val, h->n, tau - shift);
}

/* Indices [*ka, *kb] of the measured points with tau_from <= tau <= tau_to
 * that the run covers; 0 when there are at least two. */
static int window(const series *m, const history *h, double tau_from, double tau_to, int *ka, int *kb)
{
    int k;
    *ka = *kb = -1;
    for (k = 0; k < m->n; ++k) {
        if (m->tau[k] < tau_from - 1e-9 || m->tau[k] > tau_to + 1e-9 || m->tau[k] > h->tau[h->n - 1]) continue;
        if (*ka < 0) *ka = k;
        *kb = k;
    }
    return *ka >= 0 && *kb > *ka ? 0 : -1;
}

/* Relative deviation of the delayed simulation at measured point k. */
static double dev_at(const series *m, int k, const history *h, const double *val, double shift)
{
    return (delayed(h, val, m->tau[k], shift) - m->val[k]) / m->val[k];
}

/* Sum of squared relative deviations over points ka..kb for a delay shift
 * (tau); HUGE_VAL when the delayed run does not cover them all. */
static double shift_cost(const series *m, int ka, int kb, const history *h, const double *val, double shift)
{
    double sum = 0;
    int k;
    for (k = ka; k <= kb; ++k) {
        const double d = dev_at(m, k, h, val, shift);
        if (!(d == d)) return HUGE_VAL;
        sum += d * d;
    }
    return sum;
}

/* Least-squares delay (tau) of the simulated front against points ka..kb:
 * a scan over -0.5 .. 1 in steps of 0.002, then golden-section search
 * around the best step (the cost is piecewise smooth in the delay). */
static double fit_shift(const series *m, int ka, int kb, const history *h, const double *val)
{
    const double g = 0.5 * (sqrt(5.0) - 1);
    double best = 0, cbest = HUGE_VAL, lo, hi, s;
    int it;
    for (s = -0.5; s <= 1.0; s += 0.002) {
        const double c = shift_cost(m, ka, kb, h, val, s);
        if (c < cbest) cbest = c, best = s;
    }
    lo = best - 0.002, hi = best + 0.002;
    for (it = 0; it < 40; ++it) {
        const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
        if (shift_cost(m, ka, kb, h, val, x1) < shift_cost(m, ka, kb, h, val, x2)) hi = x2;
        else lo = x1;
    }
    return 0.5 * (lo + hi);
}

/* Largest |relative deviation| (and, when rms is not NULL, the rms) of the
 * delayed simulation over points ka..kb. */
static double worst_dev(const series *m, int ka, int kb, const history *h, const double *val, double shift,
                        double *rms)
{
    double worst = 0, sum = 0;
    int k;
    for (k = ka; k <= kb; ++k) {
        const double d = fabs(dev_at(m, k, h, val, shift));
        if (d > worst) worst = d;
        sum += d * d;
    }
    if (rms) *rms = sqrt(sum / (kb - ka + 1));
    return worst;
}

/* Relative deviation of the simulated front speed: least-squares slopes of
 * Z against T over the measured points of T from .. to. */
static double speed_dev(const series *m, const history *h, double n, double T_from, double T_to)
{
    int ka, kb;
    double um, us;
    if (window(m, h, T_from / n, T_to / n, &ka, &kb) != 0) return NAN;
    um = slope(m, ka, kb, n, m->val, NULL, 0);
    us = slope(m, ka, kb, n, h->Z, h->tau, h->n);
    return (us - um) / um;
}

/* The protocol figures of the a x 2a column (e2, h2) and, when hs->n > 0,
 * the square column (es, hs); a: the column width in metres. */
static protocol evaluate(const experiment *e2, const history *h2, const experiment *es, const history *hs, double a)
{
    const double n = sqrt(2.0), ms = 1e3 * sqrt(a / GRAV); /* ms per unit of tau */
    protocol pr;
    int ka, kb, k;
    pr.speed_late = pr.speed_all = pr.shift_T = pr.shift_ms = pr.worst = pr.rms = pr.worst_raw = NAN;
    pr.first_raw = pr.first_sh = pr.h_abs = pr.h_rel = pr.sq_shift_ms = pr.sq_gap_ms = pr.sq_worst = NAN;
    if (h2->n > 0 && e2->have) {
        const series *m = &e2->front;
        double sh;
        pr.speed_late = speed_dev(m, h2, n, PR_T_LATE, 1e9);
        pr.speed_all = speed_dev(m, h2, n, PR_T_FROM, 1e9);
        if (window(m, h2, PR_T_FROM / n, 1e9, &ka, &kb) == 0) {
            sh = fit_shift(m, ka, kb, h2, h2->Z);
            pr.shift_T = n * sh;
            pr.shift_ms = ms * sh;
            pr.worst = worst_dev(m, ka, kb, h2, h2->Z, sh, &pr.rms);
            pr.worst_raw = worst_dev(m, ka, kb, h2, h2->Z, 0, NULL);
            for (k = 0; k < ka; ++k) /* the last point before the window: T = 0.41 */
                pr.first_raw = dev_at(m, k, h2, h2->Z, 0), pr.first_sh = dev_at(m, k, h2, h2->Z, sh);
        }
        pr.h_abs = pr.h_rel = 0;
        for (k = 0; k < e2->height.n; ++k) {
            const double tau = e2->height.tau[k], d = interp(h2->tau, h2->H, h2->n, tau) - e2->height.val[k];
            if (!(d == d)) continue;
            if (fabs(d) > pr.h_abs) pr.h_abs = fabs(d);
            if (tau <= PR_TAU_REL + 1e-9 && fabs(d) / e2->height.val[k] > pr.h_rel) pr.h_rel = fabs(d) / e2->height.val[k];
        }
    }
    if (hs->n > 0 && es->have && window(&es->front, hs, PR_T_FROM / n, 1e9, &ka, &kb) == 0) {
        const double sh = fit_shift(&es->front, ka, kb, hs, hs->Z);
        pr.sq_shift_ms = ms * sh;
        pr.sq_gap_ms = pr.sq_shift_ms - pr.shift_ms;
        pr.sq_worst = worst_dev(&es->front, ka, kb, hs, hs->Z, sh, NULL);
    }
    return pr;
}

/* One row of the protocol table: a field of protocol, its scale for
 * printing (100: per cent), the accepted range [lo, hi] (gated rows) or
 * NAN (reported only). */
typedef struct {
    const char *what;
    size_t field;
    double scale, lo, hi;
    const char *unit, *target;
    int sign; /* printed with its sign (a signed deviation, not a magnitude) */
} protocol_row;

static const protocol_row protocol_rows[] = {
    {"front speed dZ/dT, T 1.83-3.33", offsetof(protocol, speed_late), 100, -0.03, 0.03, "%", "within 3 %", 1},
    {"front speed dZ/dT, T 0.84-3.33", offsetof(protocol, speed_all), 100, -0.05, 0.05, "%", "within 5 %", 1},
    {"fitted delay of the front (T >= 0.84), in T", offsetof(protocol, shift_T), 1, 0, 0.3, "", "0 .. 0.3", 1},
    {"fitted delay, ms", offsetof(protocol, shift_ms), 1, NAN, NAN, "ms", "reported", 1},
    {"front after the delay: largest abs. deviation", offsetof(protocol, worst), 100, 0, 0.05, "%", "within 5 %", 0},
    {"front after the delay: rms deviation", offsetof(protocol, rms), 100, 0, 0.03, "%", "within 3 %", 0},
    {"front without delay: largest abs. deviation, T >= 0.84", offsetof(protocol, worst_raw), 100, NAN, NAN, "%",
     "reported", 0},
    {"point T = 0.41 without delay", offsetof(protocol, first_raw), 100, NAN, NAN, "%", "reported", 1},
    {"point T = 0.41 after the delay", offsetof(protocol, first_sh), 100, NAN, NAN, "%", "reported", 1},
    {"height (Table 6): largest abs. H - H_measured", offsetof(protocol, h_abs), 1, 0, 0.03, "", "within 0.03", 0},
    {"height: largest abs. deviation, tau <= 2.45", offsetof(protocol, h_rel), 100, 0, 0.04, "%", "within 4 %", 0},
    {"square column: fitted delay, ms", offsetof(protocol, sq_shift_ms), 1, NAN, NAN, "ms", "reported", 1},
    {"square column: delay minus the a x 2a delay, ms", offsetof(protocol, sq_gap_ms), 1, -2, 2, "ms", "within 2 ms", 1},
    {"square column after its delay: largest abs. deviation", offsetof(protocol, sq_worst), 100, 0, 0.06, "%",
     "within 6 %", 0},
};
#define PROTOCOL_ROWS ((int)(sizeof protocol_rows / sizeof protocol_rows[0]))

static double row_value(const protocol *pr, int r) { return *(const double *)((const char *)pr + protocol_rows[r].field); }

/* 1: gated row met (or not gated / not computed), 0: missed. */
static int row_ok(const protocol *pr, int r)
{
    const double v = row_value(pr, r);
    return !(protocol_rows[r].lo == protocol_rows[r].lo) || !(v == v) ||
           (v >= protocol_rows[r].lo - 1e-12 && v <= protocol_rows[r].hi + 1e-12);
}

/* Prints the protocol table, one column per run (label[c], pr[c]), to f:
 * plain text, or a markdown table when markdown is set. Returns the number
 * of gated rows missed in column 0. */
static int print_protocol(FILE *f, int markdown, const protocol *pr, char label[][64], int nrun)
{
    int r, c, missed = 0;
    if (markdown) {
        fprintf(f, "| protocol | target |");
        for (c = 0; c < nrun; ++c) fprintf(f, " %s |", label[c]);
        fprintf(f, "\n|:---|:---|");
        for (c = 0; c < nrun; ++c) fprintf(f, "---:|");
        fprintf(f, "\n");
    } else {
        fprintf(f, "\nprotocol (Martin & Moyce 1952)                          %-12s", "target");
        for (c = 0; c < nrun; ++c) fprintf(f, " %22s", label[c]);
        fprintf(f, "\n");
    }
    for (r = 0; r < PROTOCOL_ROWS; ++r) {
        const protocol_row *w = &protocol_rows[r];
        fprintf(f, markdown ? "| %s | %s |" : "  %-53s %-12s", w->what, w->target);
        for (c = 0; c < nrun; ++c) {
            const double v = row_value(&pr[c], r);
            char cell[48];
            if (!(v == v)) snprintf(cell, sizeof cell, "-");
            else snprintf(cell, sizeof cell, w->scale == 100 ? (w->sign ? "%+.1f %s%s" : "%.1f %s%s")
                                             : w->unit[0] ? (w->sign ? "%+.1f %s%s" : "%.1f %s%s") : "%.3f%s%s",
                          w->scale * v, w->unit, !(w->lo == w->lo) ? "" : row_ok(&pr[c], r) ? " ok" : " MISSED");
            fprintf(f, markdown ? " %s |" : " %22s", cell);
        }
        fprintf(f, "\n");
        missed += !row_ok(&pr[0], r);
    }
    return missed;
}

/* ---- wall-pressure probe: Buchner (2002) ---- */

/* The MARIN experiment (data/dam_break/README.md): a column 2H wide and H
 * high, H = 0.6 m, in a tank 5.366 H long; sensor P1 on the far wall, 9 mm
 * high with its top edge 160 mm above the floor (the set-up of the
 * TrixiParticles.jl validation case, validation/dam_break_2d). Times
 * t sqrt(g/H), pressures p / (rho g H). */
#define BUCHNER_H 0.6
#define BUCHNER_TANK 5.366
#define BUCHNER_WALL 3.0      /* side walls 3 H high: the run-up on the far wall stays below */
#define BUCHNER_P1_TOP 0.160
#define BUCHNER_P1_SIZE 0.009
#define BUCHNER_END 7.0
#define PROBE_RISE 0.2        /* impact: first p/(rho g H) >= 0.2, above the +-0.16 scatter of the digitised zero line */
#define PROBE_BIN 0.02        /* the simulated pressure is averaged over bins of this width in t sqrt(g/H) */
#define PROBE_SERIES 3
#define PROBE_POINTS_MAX 400

/* One pressure series: name, n points (T = t sqrt(g/H), p / (rho g H)), sorted in T. */
typedef struct {
    char name[32];
    int n;
    double T[PROBE_POINTS_MAX], p[PROBE_POINTS_MAX];
} pseries;

/* Figures of a pressure series: impact (first rise to PROBE_RISE), first
 * peak (largest p within 0.5 after the impact) and its time, mean p over
 * T = 3.5 .. 4.5 (of the piecewise-linear series), time of the largest p
 * over T = 4.5 .. 7 (the second peak: the plunging wave falling back). */
enum { FIG_RISE, FIG_PEAK1, FIG_PEAK1_T, FIG_MEAN, FIG_PEAK2_T, FIGURES };
typedef struct {
    double v[FIGURES];
} probe_figures;

static void pseries_sort(pseries *s)
{
    int i, j;
    for (i = 1; i < s->n; ++i)
        for (j = i; j > 0 && s->T[j] < s->T[j - 1]; --j) {
            double t = s->T[j];
            s->T[j] = s->T[j - 1], s->T[j - 1] = t;
            t = s->p[j], s->p[j] = s->p[j - 1], s->p[j - 1] = t;
        }
}

/* Reads the digitised series of buchner2002_P1_pressure_digitised.csv
 * (source,T,p; # comments, one header line) into out[], one per source.
 * Returns the number of series (0: file missing or empty). */
static int read_buchner(const char *path, pseries *out)
{
    char line[256];
    int ns = 0, header = 0, k;
    FILE *f = fopen(path, "r");
    if (f == NULL) return 0;
    while (fgets(line, sizeof line, f) != NULL) {
        char *c1, *c2, *end;
        double T, p;
        if (line[0] == '#') continue;
        if (!header) {
            header = 1;
            continue;
        }
        if ((c1 = strchr(line, ',')) == NULL || (c2 = strchr(c1 + 1, ',')) == NULL) continue;
        *c1 = '\0';
        T = strtod(c1 + 1, &end);
        if (end == c1 + 1) continue;
        p = strtod(c2 + 1, &end);
        if (end == c2 + 1) continue;
        for (k = 0; k < ns && strcmp(out[k].name, line) != 0; ++k) continue;
        if (k == ns) {
            if (ns == PROBE_SERIES) continue;
            strncpy(out[ns].name, line, sizeof out[ns].name - 1);
            out[ns].name[sizeof out[ns].name - 1] = '\0';
            out[ns++].n = 0;
        }
        if (out[k].n < PROBE_POINTS_MAX) out[k].T[out[k].n] = T, out[k].p[out[k].n++] = p;
    }
    fclose(f);
    for (k = 0; k < ns; ++k) pseries_sort(&out[k]);
    return ns;
}

static probe_figures figures(const pseries *s)
{
    probe_figures fg;
    int k, q;
    for (q = 0; q < FIGURES; ++q) fg.v[q] = NAN;
    for (k = 1; k < s->n; ++k)
        if (s->p[k] >= PROBE_RISE && s->p[k - 1] < PROBE_RISE) {
            fg.v[FIG_RISE] = s->T[k - 1] + (s->T[k] - s->T[k - 1]) * (PROBE_RISE - s->p[k - 1]) / (s->p[k] - s->p[k - 1]);
            break;
        }
    fg.v[FIG_PEAK1] = -HUGE_VAL;
    for (k = 0; k < s->n; ++k)
        if (s->T[k] >= fg.v[FIG_RISE] && s->T[k] <= fg.v[FIG_RISE] + 0.5 && s->p[k] > fg.v[FIG_PEAK1]) fg.v[FIG_PEAK1] = s->p[k], fg.v[FIG_PEAK1_T] = s->T[k];
    if (!(fg.v[FIG_PEAK1_T] == fg.v[FIG_PEAK1_T])) fg.v[FIG_PEAK1] = NAN;
    if (s->n > 1 && s->T[0] <= 3.5 && s->T[s->n - 1] >= 4.5) {
        fg.v[FIG_MEAN] = 0;
        for (q = 0; q <= 1000; ++q) fg.v[FIG_MEAN] += interp(s->T, s->p, s->n, 3.5 + 1e-3 * q) / 1001;
    }
    {
        double best = -HUGE_VAL;
        for (k = 0; k < s->n; ++k)
            if (s->T[k] >= 4.5 && s->T[k] <= 7.0 && s->p[k] > best) best = s->p[k], fg.v[FIG_PEAK2_T] = s->T[k];
    }
    return fg;
}

/* The simulated probe pressure as a series of bin averages (width PROBE_BIN
 * in T = t sqrt(g/H)); tau of the history is t sqrt(g/a), a = 2H. */
static void probe_series(const history *h, pseries *s)
{
    const double Tscale = sqrt(2.0), pscale = 1 / (RHO0 * GRAV * BUCHNER_H);
    int k = 0;
    snprintf(s->name, sizeof s->name, "SPH");
    s->n = 0;
    while (k < h->n && s->n < PROBE_POINTS_MAX) {
        const double bin = floor(Tscale * h->tau[k] / PROBE_BIN);
        double sum = 0;
        int c = 0;
        for (; k < h->n && floor(Tscale * h->tau[k] / PROBE_BIN) == bin; ++k, ++c) sum += h->P1[k];
        s->T[s->n] = (bin + 0.5) * PROBE_BIN;
        s->p[s->n++] = pscale * sum / c;
    }
}

/* Distance of x from the interval [lo, hi] (0 inside). */
static double outside(double x, double lo, double hi) { return x < lo ? lo - x : x > hi ? x - hi : 0; }

/* Prints the figures of the measured series and of the simulation, with the
 * targets against the range of the measured ones; writes the simulated
 * series to csv (when not NULL). Returns the number of targets missed. */
static int probe_report(FILE *md, const pseries *meas, int nm, const pseries *simulated)
{
    probe_figures fm[PROBE_SERIES], fs = figures(simulated);
    double lo[FIGURES], hi[FIGURES];
    int k, q, missed = 0;
    static const char *what[FIGURES] = {"impact: first p >= 0.2 rho g H, t sqrt(g/H)", "first peak p / (rho g H)",
                                  "first peak, t sqrt(g/H)", "mean p / (rho g H), t sqrt(g/H) 3.5-4.5",
                                  "second peak (largest p, 4.5-7), t sqrt(g/H)"};
    for (q = 0; q < FIGURES; ++q) lo[q] = HUGE_VAL, hi[q] = -HUGE_VAL;
    for (k = 0; k < nm; ++k) {
        const double *v = fm[k].v;
        fm[k] = figures(&meas[k]);
        for (q = 0; q < FIGURES; ++q) {
            if (v[q] < lo[q]) lo[q] = v[q];
            if (v[q] > hi[q]) hi[q] = v[q];
        }
    }
    printf("\nwall pressure at P1 against Buchner (2002), three digitisations of the measured curve:\n");
    printf("  %-46s", "");
    for (k = 0; k < nm; ++k) printf(" %9s", meas[k].name);
    printf(" %9s  target\n", "SPH");
    if (md) {
        fprintf(md, "\n| P1 (Buchner 2002) |");
        for (k = 0; k < nm; ++k) fprintf(md, " %s |", meas[k].name);
        fprintf(md, " SPH | target |\n|:---|");
        for (k = 0; k <= nm; ++k) fprintf(md, "---:|");
        fprintf(md, ":---|\n");
    }
    for (q = 0; q < FIGURES; ++q) {
        const double v = fs.v[q];
        char target[96];
        int ok = 1;
        if (q == FIG_RISE) ok = outside(v, lo[q], hi[q]) <= 0.1, snprintf(target, sizeof target, "within 0.1 of %.3f .. %.3f", lo[q], hi[q]);
        else if (q == FIG_MEAN)
            ok = outside(v, lo[q], hi[q]) <= 0.15 * (v < lo[q] ? lo[q] : hi[q]),
            snprintf(target, sizeof target, "within 15 %% of %.3f .. %.3f", lo[q], hi[q]);
        else if (q == FIG_PEAK2_T) ok = outside(v, lo[q], hi[q]) <= 0.3, snprintf(target, sizeof target, "within 0.3 of %.3f .. %.3f", lo[q], hi[q]);
        else snprintf(target, sizeof target, "reported");
        ok = ok && v == v;
        missed += !ok;
        printf("  %-46s", what[q]);
        for (k = 0; k < nm; ++k) printf(" %9.3f", fm[k].v[q]);
        printf(" %9.3f  %s%s\n", v, target, q == FIG_PEAK1 || q == FIG_PEAK1_T ? "" : ok ? " ok" : " MISSED");
        if (md) {
            fprintf(md, "| %s |", what[q]);
            for (k = 0; k < nm; ++k) fprintf(md, " %.3f |", fm[k].v[q]);
            fprintf(md, " %.3f | %s%s |\n", v, target, q == FIG_PEAK1 || q == FIG_PEAK1_T ? "" : ok ? " ok" : " MISSED");
        }
    }
    return missed;
}

static void probe_csv(const char *dir, const params *pm, const pseries *simulated)
{
    char path[1200];
    FILE *f;
    int k;
    snprintf(path, sizeof path, "%s/buchner_P1.csv", dir);
    if ((f = fopen(path, "w")) == NULL) {
        fprintf(stderr, "dam_break: cannot write %s\n", path);
        exit(2);
    }
    fprintf(f, "# dam break of Buchner (2002), column 2H x H, H = %g m, tank %g H; pressure at P1 (far wall, %g .. %g m), "
               "averaged over bins of %g\nT_t_sqrt_g_over_H,p_over_rhogH\n",
            BUCHNER_H, BUCHNER_TANK, pm->probe_y0, pm->probe_y1, PROBE_BIN);
    for (k = 0; k < simulated->n; ++k) fprintf(f, "%.4f,%.5f\n", simulated->T[k], simulated->p[k]);
    fclose(f);
    printf("wrote %s\n", path);
}

/* Output directory of one run: <out>/<tag>, created; exits on failure. */
static void run_dir(const char *out, const char *tag, char *dir, size_t size)
{
    snprintf(dir, size, "%s/%s", out, tag);
    if (ex_mkdir_p(dir) != 0) {
        fprintf(stderr, "dam_break: cannot create the output directory %s\n", dir);
        exit(2);
    }
}

/* One Martin & Moyce run: resolution, wall model, both columns' histories. */
typedef struct {
    params pm;
    history hist[2];
    protocol pr;
    char tag[64], dir[1200];
} mm_run;

int main(int argc, char **argv)
{
    params pm, def;
    char variant[256], label[4][64], path[1200];
    int check = 0, columns = 0, c, r, fail = 0, side = 0, refine = 0, probe = 0, nrun = 0, threads = 0, probe_res = 40;
    double probe_top = BUCHNER_P1_TOP;
    const char *data = NULL, *report = NULL, *summary = NULL, *walls;
    mm_run runs[4];
    protocol pr[4];
    experiment ex[2];
    FILE *md = NULL;
    /* every option with what it accepts: refused before anything runs (ex_parse_args) */
    const ex_arg opt[] = {
        {"res", "particles across the column width a", NULL, &pm.res, NULL, NULL, 4, 400, 0, NULL},
        {"end", "end time tau = t sqrt(g/a)", &pm.end_tau, NULL, NULL, NULL, 0.01, 20, 0, NULL},
        {"column", "n^2 of the column a x n^2 a: 2, 1, or 0 for both", NULL, &columns, NULL, NULL, 0, 2, 0, NULL},
        {"kernel", "kernel name", NULL, NULL, &pm.kernel, NULL, 0, 0, 0, ex_kernel_choices()},
        {"hfac", "smoothing length h / particle spacing", &pm.hfac, NULL, NULL, NULL, 0.75, 3, 0, NULL},
        {"alpha", "artificial viscosity coefficient (Monaghan 1992)", &pm.alpha, NULL, NULL, NULL, 0, 1, 0, NULL},
        {"delta", "density diffusion coefficient (Molteni & Colagrossi 2009)", &pm.delta, NULL, NULL, NULL, 0, 1, 0,
         NULL},
        {"tank", "tank length / a", &pm.tank, NULL, NULL, NULL, 2, 100, 0, NULL},
        {"skin", "neighbour-list skin / h (0: search every step)", &pm.skin, NULL, NULL, NULL, 0, 2, 0, NULL},
        {"a", "column width a in metres (Martin & Moyce: 2.25 in)", &pm.a, NULL, NULL, NULL, 1e-3, 100, 0, NULL},
        {"out", "output directory: one folder per run in it (VTK frames, .pvd series, time-series CSVs)", NULL, NULL,
         &pm.out, NULL, 0, 0, 0, NULL},
        {"vtk-every", "write particles every N steps (0: never)", NULL, &pm.vtk_every, NULL, NULL, 0, 1e9, 0, NULL},
        {"ascii", "VTK frames as text instead of binary", NULL, NULL, NULL, &pm.ascii, 0, 0, 0, NULL},
        {"threads", "OpenMP threads (0: the OpenMP default)", NULL, &threads, NULL, NULL, 0, 1024, 0, NULL},
        {"data", "directory of the measurements (tries data/dam_break, ../data/dam_break, ../../data/dam_break)",
         NULL, NULL, &data, NULL, 0, 0, 0, NULL},
        {"report", "write the protocol and comparison tables as markdown to this file", NULL, NULL, &report, NULL, 0,
         0, 0, NULL},
        {"summary", "append one row of protocol figures per run (markdown table rows) to this file", NULL, NULL,
         &summary, NULL, 0, 0, 0, NULL},
        {"nu", "laminar kinematic viscosity in m^2/s (water 1e-6; 0: none)", &pm.nu, NULL, NULL, NULL, 0, 1e-2, 0,
         NULL},
        {"noslip", "walls: 1 no-slip (viscous term over wall particles), 0 free slip", NULL, &pm.noslip, NULL, NULL,
         0, 1, 0, NULL},
        {"front-k", "fluid neighbours a floor particle needs to count as the front (0: furthest particle)", NULL,
         &pm.front_k, NULL, NULL, 0, 50, 0, NULL},
        {"stokes", "1: friction of the unresolved laminar wall layer (Stokes' first problem, needs --nu)", NULL,
         &pm.stokes, NULL, NULL, 0, 1, 0, NULL},
        {"c0", "speed of sound / sqrt(g n^2 a)", &pm.c0fac, NULL, NULL, NULL, 2, 100, 0, NULL},
        {"side-by-side", "also run without the wall-friction model and print both in the protocol table", NULL, NULL,
         NULL, &side, 0, 0, 0, NULL},
        {"refine", "also run the a x 2a column at twice --res (the fitted delay's change)", NULL, NULL, NULL, &refine,
         0, 0, 0, NULL},
        {"probe", "instead: the wall-pressure probe of Buchner (2002), column 2H x H in a 5.366 H tank", NULL, NULL,
         NULL, &probe, 0, 0, 0, NULL},
        {"probe-res", "--probe: particles across the column height H", NULL, &probe_res, NULL, NULL, 10, 400, 0, NULL},
        {"probe-top", "--probe: top edge of the 9 mm sensor on the far wall, m (Buchner's P1: 0.16)", &probe_top, NULL,
         NULL, NULL, BUCHNER_P1_SIZE, BUCHNER_WALL * BUCHNER_H, 0, NULL},
        {"check", "the protocol at the default resolution, a x 2a to tau 2.5, a x a to 3.35; exit 1 on a miss", NULL,
         NULL, NULL, &check, 0, 0, 0, NULL},
    };
    pm.res = 30;
    pm.vtk_every = 500;
    pm.noslip = 0;
    pm.front_k = 4;
    pm.stokes = 1;
    pm.ascii = 0;
    pm.end_tau = 3.5;
    pm.kernel = "wendland_c2";
    pm.hfac = 1.3;
    pm.alpha = 0.02;
    pm.delta = 0.1;
    pm.tank = 10;
    pm.skin = 0.25;
    pm.a = 0.05715;
    pm.out = "build/dam_break_out";
    pm.nu = 1e-6;
    pm.c0fac = 10;
    pm.wall_h = 1.5;
    pm.probe_y0 = pm.probe_y1 = 0;
    def = pm; /* the defaults: describe_variant lists what a run changes */
    def.res = 30, def.noslip = 0, def.front_k = 4, def.stokes = 1;
    c = ex_parse_args(argc, argv, "2-D SPH dam break against Martin & Moyce (1952) and Buchner (2002); " DB_BOUNDS, opt,
                      (int)(sizeof opt / sizeof opt[0]));
    if (c != 0) return c > 0 ? 0 : 2;
    if ((pm.noslip && pm.stokes) || (side && !pm.stokes) || (pm.stokes && !(pm.nu > 0)) ||
        (check && (side || refine || probe))) {
        fprintf(stderr, "dam_break: %s\n",
                pm.noslip && pm.stokes ? "--noslip 1 needs --stokes 0 (the wall-layer friction replaces the no-slip walls)"
                : side && !pm.stokes ? "--side-by-side runs with and without the wall friction: leave --stokes at 1"
                : pm.stokes && !(pm.nu > 0) ? "--stokes 1 needs --nu > 0 (the wall-layer friction is that of nu)"
                : "--check runs the protocol on its own: no --side-by-side, --refine or --probe with it");
        return 2;
    }
    if (check) {
        pm.res = 30; /* the protocol is asserted at the default resolution */
        pm.vtk_every = 0;
        pm.out = NULL;
        if (threads == 0) threads = 1; /* the run time stays that of one core; a loaded machine slows OpenMP barriers */
    }
#ifdef _OPENMP
    if (threads > 0) omp_set_num_threads(threads);
    threads = omp_get_max_threads();
#else
    threads = 1;
#endif
    /* the measurements first: nothing runs without them */
    data = find_data(data);
    if (data == NULL) {
        fprintf(stderr, "dam_break: the measurements were not found: no data/dam_break/README.md in ., .. or ../.. "
                        "(give the directory with --data DIR)\n");
        return 1;
    }
    if (probe) {
        pseries meas[PROBE_SERIES], simulated;
        history h;
        const int moved = probe_top != BUCHNER_P1_TOP; /* the sensor off Buchner's P1 */
        char top_arg[64];
        double arrival;
        int nm;
        snprintf(path, sizeof path, "%s/buchner2002_P1_pressure_digitised.csv", data);
        if ((nm = read_buchner(path, meas)) < PROBE_SERIES) {
            fprintf(stderr, "dam_break: %s: the %d digitised series of Buchner (2002) were not found (%d read)\n", path,
                    PROBE_SERIES, nm);
            return 1;
        }
        pm.res = 2 * probe_res; /* across the column width 2H */
        pm.a = 2 * BUCHNER_H;
        pm.tank = BUCHNER_TANK / 2;
        pm.wall_h = BUCHNER_WALL;
        pm.end_tau = BUCHNER_END / sqrt(2.0);
        pm.probe_y0 = probe_top - BUCHNER_P1_SIZE, pm.probe_y1 = probe_top;
        top_arg[0] = '\0';
        if (moved) snprintf(top_arg, sizeof top_arg, " --probe-top %g", probe_top);
        if (pm.out) {
            snprintf(variant, sizeof variant, "buchner_res%d%s%s", probe_res, pm.stokes ? "" : "_nofriction",
                     moved ? "_top" : "");
            run_dir(pm.out, variant, path, sizeof path);
            pm.out = path;
        }
        printf("dam break of Buchner (2002): column 2H x H, H = %g m, tank %g H, %d particles across H, kernel %s, "
               "h = %g dx, c0 = %g sqrt(g H), alpha = %g, delta = %g, nu = %g m^2/s, wall-layer friction %s; probe: "
               "Shepard-interpolated fluid pressure at %d points of the far wall's face, %g .. %g m, averaged; %d "
               "thread(s)\n",
               BUCHNER_H, BUCHNER_TANK, probe_res, pm.kernel, pm.hfac, pm.c0fac, pm.alpha, pm.delta, pm.nu,
               pm.stokes ? "on" : "off", PROBE_POINTS, pm.probe_y0, pm.probe_y1, threads);
        memset(&h, 0, sizeof h);
        run(&pm, 0.5, &h, 0);
        printf("%d particles (%d fluid), %ld steps, %.1f s\n", h.particles, h.fluid, h.steps, h.seconds);
        probe_series(&h, &simulated);
        if (report && (md = fopen(report, "w")) == NULL) {
            fprintf(stderr, "dam_break: cannot write %s\n", report);
            return 2;
        }
        if (md)
            fprintf(md, "Written by `dam_break --probe --probe-res %d%s%s`: %d particles across H, %ld steps, %.1f s on %d "
                        "thread(s).\n",
                    probe_res, pm.stokes ? "" : " --stokes 0", top_arg, probe_res, h.steps, h.seconds, threads);
        fail = probe_report(md, meas, nm, &simulated);
        /* the surge front (measure) within one spacing (a / res) of the far wall's face */
        arrival = sqrt(2.0) * reach_time(&h, h.Z, h.wall - 1.0 / pm.res);
        printf("surge front within one spacing of the far wall at t sqrt(g/H) = %.3f\n", arrival);
        if (md) fprintf(md, "\nThe surge front (the layer's furthest particle on the floor) comes within one particle spacing "
                            "of the far wall at t sqrt(g/H) = %.3f.\n", arrival);
        if (md) fclose(md);
        if (pm.out) probe_csv(pm.out, &pm, &simulated);
        history_free(&h);
        return fail ? 1 : 0;
    }
    for (c = 0; c < 2; ++c) {
        if (load_experiment(data, c == 0 ? 2 : 1, &ex[c]) != 0) {
            fprintf(stderr, "dam_break: the measurements of Martin & Moyce (n^2 = %d) are missing from %s; nothing "
                            "run (--data DIR)\n", c == 0 ? 2 : 1, data);
            return 1;
        }
    }
    /* the runs: the model asked for, without the wall friction (--side-by-side), each at twice --res (--refine) */
    for (r = 0; r < 1 + refine; ++r)
        for (c = 0; c < 1 + side; ++c) {
            mm_run *u = &runs[nrun++];
            memset(u, 0, sizeof *u);
            u->pm = pm;
            u->pm.res = pm.res << r;
            u->pm.stokes = c ? 0 : pm.stokes;
            snprintf(u->tag, sizeof u->tag, "res%d%s", u->pm.res, u->pm.stokes ? "" : "_nofriction");
            if (u->pm.out) { /* the output folders before the banner: a refused --out stops before anything is printed */
                run_dir(pm.out, u->tag, u->dir, sizeof u->dir);
                u->pm.out = u->dir;
            }
        }
    if (summary) { /* appended to after each run: writable before the first */
        FILE *f = fopen(summary, "a");
        if (f == NULL || fclose(f) != 0) {
            fprintf(stderr, "dam_break: cannot write %s\n", summary);
            return 2;
        }
    }
    if (report && (md = fopen(report, "w")) == NULL) {
        fprintf(stderr, "dam_break: cannot write %s\n", report);
        return 2;
    }
    walls = pm.stokes ? "free slip + laminar wall-layer friction" : pm.noslip ? "no-slip" : "free slip";
    printf("dam break: column a x n^2 a, a = %g m, %d particles across a, kernel %s, h = %g dx, c0 = %g sqrt(g n^2 a), "
           "alpha = %g, delta = %g, nu = %g m^2/s, walls: %s, front: >= %d neighbours, tank %g a, end tau = %g, "
           "%d thread(s)\n",
           pm.a, pm.res, pm.kernel, pm.hfac, pm.c0fac, pm.alpha, pm.delta, pm.nu, walls, pm.front_k, pm.tank,
           check ? 2.5 : pm.end_tau, threads);
    if (md)
        fprintf(md, "# Dam break: simulated against measured\n\nWritten by `examples/dam_break.c` (`make plots-dambreak`): "
                    "%d particles across the column width a, kernel %s, h = %g dx, c0 = %g sqrt(g n^2 a), "
                    "alpha = %g, delta = %g, nu = %g m^2/s, walls: %s, tank %g a, end tau = %g. Measurements: Martin & Moyce (1952), "
                    "a = 2.25 in. Front: the furthest fluid particle on the floor with at least %d fluid "
                    "neighbours, plus dx/2. Deviation = (simulated - measured) / measured; the tables below are "
                    "not shifted in time (the protocol's delay is fitted separately).\n",
                pm.res, pm.kernel, pm.hfac, pm.c0fac, pm.alpha, pm.delta, pm.nu, walls, pm.tank, pm.end_tau, pm.front_k);
    for (r = 0; r < nrun; ++r) {
        mm_run *u = &runs[r];
        double lag = NAN, speed = NAN, seconds = 0;
        for (c = 0; c < 2; ++c) {
            const double n2 = c == 0 ? 2 : 1;
            if ((columns != 0 && columns != (int)n2) || (u->pm.res != pm.res && c == 1)) continue;
            u->pm.end_tau = check ? (c == 0 ? 2.5 : 3.35) : pm.end_tau;
            run(&u->pm, n2, &u->hist[c], check);
            seconds += u->hist[c].seconds;
            printf("\n%s, column a x %ga: %d particles (%d fluid), %ld steps, %ld neighbour searches, %.1f s\n", u->tag,
                   n2, u->hist[c].particles, u->hist[c].fluid, u->hist[c].steps, u->hist[c].searches, u->hist[c].seconds);
            if (r > 0 && !check) continue; /* the tables of the first run; the protocol of every run */
            if (md) fprintf(md, "\n## Column a x %ga (n^2 = %g): %d particles (%d fluid), %ld steps, %.1f s on %d thread(s)\n",
                            n2, n2, u->hist[c].particles, u->hist[c].fluid, u->hist[c].steps, u->hist[c].seconds, threads);
            compare(md, "surge front Z = z/a", sqrt(n2), pm.a, &ex[c].front, &u->hist[c], u->hist[c].Z, &lag, &speed);
            compare(md, "residual height H = eta/(n^2 a)", sqrt(n2), pm.a, &ex[c].height, &u->hist[c], u->hist[c].H,
                    &lag, &speed);
        }
        u->pr = evaluate(&ex[0], &u->hist[0], &ex[1], &u->hist[1], pm.a);
        pr[r] = u->pr;
        for (c = 0; c < 2 && u->pm.out; ++c) /* delays in tau: a x 2a from T, a x a from ms */
            if (u->hist[c].n > 0)
                write_csv(u->pm.out, &ex[c], &u->hist[c],
                          c == 0 ? u->pr.shift_T / sqrt(2.0) : u->pr.sq_shift_ms / (1e3 * sqrt(pm.a / GRAV)));
        snprintf(label[r], sizeof label[r], "%d across a%s", u->pm.res, u->pm.stokes ? "" : ", no friction");
        if (summary) {
            FILE *f = fopen(summary, "a");
            int fresh;
            if (f == NULL || fseek(f, 0, SEEK_END) != 0) {
                fprintf(stderr, "dam_break: cannot write %s\n", summary);
                return 2;
            }
            fresh = ftell(f) == 0; /* the header first in a new or empty file */
            describe_variant(&u->pm, &def, variant, sizeof variant);
            if (fresh)
                fprintf(f, "| particles across a | model (default unless listed) | particles (a x 2a) | delay (T) | delay "
                           "(ms) | front after it: largest, rms | front unshifted (T >= 0.84) | front speed T 1.83-3.33, "
                           "0.84-3.33 | height: largest abs, rel (tau <= 2.45) | a x a: delay (ms), front after it | "
                           "run time (s), threads |\n"
                           "|---:|:---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
            fprintf(f, "| %d | %s | %d | %.3f | %.1f | %.1f %%, %.1f %% | %.1f %% | %+.1f %%, %+.1f %% | %.3f, %.1f %% | ",
                    u->pm.res, variant, u->hist[0].particles, u->pr.shift_T, u->pr.shift_ms, 100 * u->pr.worst,
                    100 * u->pr.rms, 100 * u->pr.worst_raw, 100 * u->pr.speed_late, 100 * u->pr.speed_all, u->pr.h_abs,
                    100 * u->pr.h_rel);
            if (u->pr.sq_shift_ms == u->pr.sq_shift_ms)
                fprintf(f, "%.1f, %.1f %% |", u->pr.sq_shift_ms, 100 * u->pr.sq_worst);
            else
                fprintf(f, "- |");
            fprintf(f, " %.1f, %d |\n", seconds, threads);
            fclose(f);
        }
    }
    if (md) fprintf(md, "\n## Validation protocol\n\n");
    fail = print_protocol(stdout, 0, pr, label, nrun);
    if (md) print_protocol(md, 1, pr, label, nrun);
    for (c = 0; refine && c < 1 + side; ++c) {
        const double d = pr[1 + side + c].shift_T - pr[c].shift_T;
        printf("  fitted delay, %s: %d -> %d across a changes it by %+.3f in T (target: at most 0.03) %s\n",
               runs[c].pm.stokes ? "with the wall friction" : "without it", runs[c].pm.res, runs[1 + side + c].pm.res, d,
               fabs(d) <= 0.03 ? "ok" : "MISSED");
        if (md)
            fprintf(md, "\nFitted delay, %s: from %d to %d particles across a it changes by %+.3f in T (target: at "
                        "most 0.03): %s.\n",
                    runs[c].pm.stokes ? "with the wall friction" : "without it", runs[c].pm.res,
                    runs[1 + side + c].pm.res, d, fabs(d) <= 0.03 ? "met" : "missed");
    }
    if (md) fclose(md);
    for (r = 0; r < nrun; ++r)
        for (c = 0; c < 2; ++c) history_free(&runs[r].hist[c]);
    if (check) {
        printf("dam_break --check: %s (%d protocol target(s) missed at %d particles across a)\n",
               fail ? "FAILED" : "passed", fail, pm.res);
        return fail ? 1 : 0;
    }
    return 0;
}
