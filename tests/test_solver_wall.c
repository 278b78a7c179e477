/* Solver terms: the generalised wall boundary (S8) (Adami, Hu & Adams 2012),
 * docs/solver.md.
 *
 * Extrapolation: for a hydrostatic fluid of constant density rho0 under
 * gravity g = (0, -g), p_f = rho0 g (H - y_f), every fluid neighbour gives
 * p_f + rho0 g . (x_w - x_f) = rho0 g (H - y_w), so the Shepard average
 * (S8) is the exact hydrostatic pressure at the wall particle, wherever its
 * neighbours are (to round-off); with a wall acceleration a_w the
 * effective gravity is g - a_w. A uniform fluid velocity U gives the wall
 * 2 v_wall - U (no-slip) or U (free-slip), a wall without fluid neighbours
 * p = 0 and v_wall.
 *
 * Hydrostatic tank (support/tank.h): a weakly compressible 2-D tank (linear
 * equation of state p = c0^2 (rho - rho0), c0 = 10 sqrt(g H)) whose fluid
 * starts at rest with the hydrostatic density, walls of three particle
 * layers on both sides and below, stepped by kick-drift-kick with
 * continuity (O10), the pressure force (O8) over fluid and wall particles,
 * Monaghan's viscosity (S1) (alpha = 0.02), gravity, the wall pressure and
 * velocity of (S8) each step and the time step (S9)-(S10). It must hold the
 * hydrostatic pressure and stay at rest; the figures and bounds are printed
 * and stated in docs/solver.md (studies/hydrostatic_tank.c runs it longer).
 */
#include "solver_scene.h"
#include "support/tank.h"

static void test_extrapolation(void)
{
    /* a 2-D fluid block above a row of wall particles, some fluid neighbours only on one side */
    enum { NXF = 12, NYF = 6, NW = 16 };
    const double rho0 = 1000, g = 9.81, dx = 0.1, H = NYF * dx, h = 1.3 * dx;
    const int nf = NXF * NYF;
    sph_real xf[3 * NXF * NYF], xw[3 * NW], p[NXF * NYF], rho[NXF * NYF], v[2 * NXF * NYF], pw[NW], vw[2 * NW],
        vwall[2 * NW], aw[2 * NW];
    const sph_real grav[2] = {0, (sph_real)-g};
    tp_list L;
    sph_ctx c;
    sph_wall w = sph_wall_init(2, grav);
    sph_idx empty = -1;
    double err = 0;
    int i, st;
    th_begin("(S8) hydrostatic extrapolation exact at wall particles; no-slip and free-slip velocities");
    for (i = 0; i < nf; ++i) {
        xf[3 * i] = (sph_real)((i % NXF + 0.5) * dx), xf[3 * i + 1] = (sph_real)((i / NXF + 0.5) * dx);
        xf[3 * i + 2] = 0;
        rho[i] = (sph_real)rho0;
        p[i] = (sph_real)(rho0 * g * (H - xf[3 * i + 1]));
        v[2 * i] = (sph_real)0.75, v[2 * i + 1] = (sph_real)-0.5;
    }
    for (i = 0; i < NW; ++i) /* the row below the fluid, and two beyond its right end (no fluid in reach: last) */
        xw[3 * i] = (sph_real)((i - 1.5) * dx + (i == NW - 1 ? 1.0 : 0)), xw[3 * i + 1] = (sph_real)(-0.5 * dx),
                xw[3 * i + 2] = 0;
    tp_brute_list(2, xw, NW, xf, nf, (sph_real)h, NULL, NULL, 2, TP_GATHER, NULL, &L);
    c = sph_ctx_init(SPH_KERNEL_CUBIC, 2, (sph_real)h, &L.list, sph_view_interleaved(xf, 3));
    c.x_target = sph_view_interleaved(xw, 3);
    c.rho = sph_view_soa(rho, NULL, NULL);
    st = sph_wall_adami(&c, &w, sph_view_soa(p, NULL, NULL), sph_view_interleaved(v, 2), sph_out_soa(pw, NULL, NULL),
                        sph_out_interleaved(vw, 2), &empty);
    TH_CHECK(st == SPH_OK && empty == 1, "status %d, %d empty", st, (int)empty);
    for (i = 0; i < NW - 1; ++i) {
        err = fmax(err, fabs((double)pw[i] - rho0 * g * (H - xw[3 * i + 1])) / (rho0 * g * H));
        TH_CHECK(fabs((double)vw[2 * i] + 0.75) <= 8 * TH_EPS && fabs((double)vw[2 * i + 1] - 0.5) <= 8 * TH_EPS,
                 "no-slip wall %d: v = (%g, %g)", i, vw[2 * i], vw[2 * i + 1]);
    }
    TH_CHECK(err <= 64 * TH_EPS, "pressure off by %.3g of rho0 g H", err);
    TH_CHECK(pw[NW - 1] == 0 && vw[2 * (NW - 1)] == 0, "empty wall: p = %g, v = %g", pw[NW - 1], vw[2 * (NW - 1)]);
    /* moving, accelerating wall: v_wall = (2, 1), a_w = (0, 3): g_eff = (0, -g - 3); free-slip then no-slip */
    for (i = 0; i < NW; ++i) vwall[2 * i] = 2, vwall[2 * i + 1] = 1, aw[2 * i] = 0, aw[2 * i + 1] = 3;
    w.v_wall = sph_view_interleaved(vwall, 2), w.a_wall = sph_view_interleaved(aw, 2), w.slip = SPH_WALL_FREESLIP;
    st = sph_wall_adami(&c, &w, sph_view_soa(p, NULL, NULL), sph_view_interleaved(v, 2), sph_out_soa(pw, NULL, NULL),
                        sph_out_interleaved(vw, 2), NULL);
    TH_CHECK(st == SPH_OK, "status %d", st);
    for (err = 0, i = 0; i < NW - 1; ++i) {
        /* each neighbour: p_f + rho0 (-(g + 3)) (y_w - y_f) = rho0 g (H - y_w) - 3 rho0 (y_w - y_f): not uniform,
           so compare with the Shepard average written out */
        double sw = 0, sp = 0;
        sph_off o;
        for (o = L.offset[i]; o < L.offset[i + 1]; ++o) {
            const int f = L.index[o];
            const double W = (double)sph_kernel_w(SPH_KERNEL_CUBIC, 2, (sph_real)sqrt(tp_r2(2, xw + 3 * i, xf + 3 * f,
                                                                                           NULL)), (sph_real)h);
            sw += W;
            sp += W * ((double)p[f] - rho0 * (g + 3) * ((double)xw[3 * i + 1] - xf[3 * f + 1]));
        }
        err = fmax(err, fabs((double)pw[i] - sp / sw) / (rho0 * g * H));
        TH_CHECK(fabs((double)vw[2 * i] - 0.75) <= 8 * TH_EPS && fabs((double)vw[2 * i + 1] + 0.5) <= 8 * TH_EPS,
                 "free-slip wall %d: v = (%g, %g)", i, vw[2 * i], vw[2 * i + 1]);
    }
    TH_CHECK(err <= 64 * TH_EPS, "accelerating wall: pressure off by %.3g", err);
    TH_CHECK(vw[2 * (NW - 1)] == 2 && vw[2 * (NW - 1) + 1] == 1, "empty moving wall: v = v_wall");
    w.slip = SPH_WALL_NOSLIP;
    st = sph_wall_adami(&c, &w, sph_view_soa(p, NULL, NULL), sph_view_interleaved(v, 2), sph_out_soa(pw, NULL, NULL),
                        sph_out_interleaved(vw, 2), NULL);
    TH_CHECK(st == SPH_OK && fabs((double)vw[0] - 3.25) <= 8 * TH_EPS && fabs((double)vw[1] - 2.5) <= 8 * TH_EPS,
             "no-slip moving wall: v = (%g, %g), expected 2 v_wall - U = (3.25, 2.5)", vw[0], vw[1]);
    { /* the pair form's fallback: a Shepard sum whose inverse overflows counts as no fluid */
        const sph_real tiny = (sph_real)(TH_IS_FLOAT ? 1e-45 : 4.9e-324), sum[5] = {tiny, 1, 1, 1, 0};
        const sph_real vwl[2] = {2, 1};
        sph_real pp = -1, vv[2] = {-1, -1};
        TH_CHECK(sph_wall_end(2, SPH_WALL_NOSLIP, sum, vwl, &pp, vv) == 0 && pp == 0 && vv[0] == 2 && vv[1] == 1,
                 "denormal sum: p %g, v (%g, %g)", pp, vv[0], vv[1]);
    }
    /* refusals */
    TH_CHECK(sph_wall_adami(&c, NULL, sph_view_soa(p, NULL, NULL), sph_view_interleaved(v, 2),
                            sph_out_soa(pw, NULL, NULL), sph_out_interleaved(vw, 2), NULL) == SPH_ENULL, "w NULL");
    w.slip = (sph_wall_slip)5;
    TH_CHECK(sph_wall_adami(&c, &w, sph_view_soa(p, NULL, NULL), sph_view_interleaved(v, 2),
                            sph_out_soa(pw, NULL, NULL), sph_out_interleaved(vw, 2), NULL) == SPH_EOPTION, "slip 5");
    w.slip = SPH_WALL_NOSLIP, w.g[1] = (sph_real)NAN;
    TH_CHECK(sph_wall_adami(&c, &w, sph_view_soa(p, NULL, NULL), sph_view_interleaved(v, 2),
                            sph_out_soa(pw, NULL, NULL), sph_out_interleaved(vw, 2), NULL) == SPH_ERANGE, "g NaN");
    w.g[1] = grav[1], aw[5] = (sph_real)INFINITY;
    TH_CHECK(sph_wall_adami(&c, &w, sph_view_soa(p, NULL, NULL), sph_view_interleaved(v, 2),
                            sph_out_soa(pw, NULL, NULL), sph_out_interleaved(vw, 2), NULL) == SPH_ENONFINITE,
             "a_w Inf");
    aw[5] = 3;
    TH_CHECK(sph_wall_adami(&c, &w, sph_view_none(), sph_view_interleaved(v, 2), sph_out_soa(pw, NULL, NULL),
                            sph_out_interleaved(vw, 2), NULL) == SPH_ENULL, "no pressures");
    tp_free_list(&L);
    th_end();
}

/* ---- the hydrostatic tank (support/tank.h) ---- */

static void test_tank(void)
{
    tank t;
    int step, st;
    double time = 0, dt = 0, vmax = 0, perr = 0, pwerr = 0, vend = 0;
    const int nx = 10, ny = 12, steps = 750;
    th_begin("(S8) hydrostatic 2D tank, %dx%d fluid particles, %d kick-drift-kick steps: p = rho0 g depth, at rest", nx,
             ny, steps);
    st = tank_make(&t, nx, ny) == 0 ? tank_momentum(&t, t.v) : SPH_ESIZE;
    for (step = 0; step < steps && st == SPH_OK; ++step) {
        st = tank_step(&t, &dt);
        time += dt;
        vmax = fmax(vmax, tank_errors(&t, &perr, &pwerr));
    }
    TH_CHECK(st == SPH_OK, "status %d at step %d", st, step);
    vend = tank_errors(&t, &perr, &pwerr);
    printf("    t = %.3f s = %.2f sqrt(H/g) (%d steps, last dt %.3g s, %d list builds): max |p - rho0 g (H - y)| / "
           "(rho0 g H) fluid %.4f, floor walls %.4f; max |v| / sqrt(g H) over the run %.4f, at the end %.4f\n",
           time, time / sqrt(t.H / t.g), steps, dt, t.rebuilds, perr, pwerr, vmax / sqrt(t.g * t.H),
           vend / sqrt(t.g * t.H));
    TH_CHECK(perr < 0.05, "fluid pressure off by %.3g of rho0 g H", perr);
    TH_CHECK(pwerr < 0.05, "floor wall pressure off by %.3g of rho0 g H", pwerr);
    TH_CHECK(vmax < 0.02 * sqrt(t.g * t.H), "fluid moved at %.3g sqrt(g H)", vmax / sqrt(t.g * t.H));
    tank_free(&t);
    th_end();
}

int main(void)
{
    test_extrapolation();
    test_tank();
    return th_summary();
}
