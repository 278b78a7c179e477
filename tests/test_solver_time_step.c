/* Solver terms: time-step limits (S9)-(S12), docs/solver.md.
 *
 * Values worked by hand from the definitions: dt = min(C_cfl h / v_sig,
 * C_force sqrt(h / |a|), C_visc h^2 / nu, C_diff h^2 / D) with the default
 * coefficients 0.25, 0.25, 0.125, 0.125 (Morris, Fox & Zhu 1997; Monaghan
 * 1992), the limiting reason and particle, and the refusals.
 */
#include "harness.h"
#include <stdlib.h>

static void test_particle(void)
{
    const sph_dt_coef k = sph_dt_coef_default();
    sph_dt_coef k2 = k;
    int why = -9;
    th_begin("(S9)-(S12) one particle: each limit and its reason");
    /* h = 0.1: CFL 0.25 0.1 / 10 = 2.5e-3; force 0.25 sqrt(0.1 / 1e4) = 7.9e-4; viscous 0.125 0.01 / 1 = 1.25e-3;
       diffusion 0.125 0.01 / 5 = 2.5e-4 */
    TH_NEAR(sph_dt_limit(&k, (sph_real)0.1, 10, 0, 0, 0, &why), 2.5e-3, 8 * TH_EPS);
    TH_CHECK(why == SPH_DT_CFL, "reason %d", why);
    TH_NEAR(sph_dt_limit(&k, (sph_real)0.1, 10, 1e4, 0, 0, &why), 0.25 * sqrt(1e-5), 8 * TH_EPS);
    TH_CHECK(why == SPH_DT_FORCE, "reason %d", why);
    TH_NEAR(sph_dt_limit(&k, (sph_real)0.1, 10, 10, 1, 0, &why), 1.25e-3, 8 * TH_EPS);
    TH_CHECK(why == SPH_DT_VISCOUS, "reason %d", why);
    TH_NEAR(sph_dt_limit(&k, (sph_real)0.1, 10, 1e4, 1, 5, &why), 2.5e-4, 8 * TH_EPS);
    TH_CHECK(why == SPH_DT_DIFFUSION, "reason %d", why);
    k2.diffusion = (sph_real)0.1; /* each coefficient applies to its own limit */
    TH_NEAR(sph_dt_limit(&k2, (sph_real)0.1, 10, 1e4, 1, 5, &why), 2e-4, 8 * TH_EPS);
    k2.viscous = (sph_real)0.01;
    TH_NEAR(sph_dt_limit(&k2, (sph_real)0.1, 10, 1e4, 1, 5, &why), 1e-4, 8 * TH_EPS);
    TH_CHECK(why == SPH_DT_VISCOUS, "reason %d", why);
    TH_CHECK(sph_dt_limit(&k, (sph_real)0.1, 0, 0, 0, 0, &why) > 1e30 && why == SPH_DT_NONE, "no rate: reason %d", why);
    TH_CHECK(sph_dt_limit(&k, 0, 10, 0, 0, 0, &why) == 0 && why == SPH_DT_INVALID, "h = 0: reason %d", why);
    TH_CHECK(sph_dt_limit(&k, 1, -1, 0, 0, 0, &why) == 0 && why == SPH_DT_INVALID, "v_sig < 0: reason %d", why);
    TH_CHECK(sph_dt_limit(&k, 1, 1, (sph_real)NAN, 0, 0, &why) == 0 && why == SPH_DT_INVALID, "NaN: reason %d", why);
    TH_CHECK(sph_dt_limit(NULL, 1, 1, 0, 0, 0, &why) == 0 && why == SPH_DT_INVALID, "coef NULL: reason %d", why);
    th_end();
}

static void test_array(void)
{
    sph_real h[4] = {(sph_real)0.1, (sph_real)0.05, (sph_real)0.1, (sph_real)0.1};
    sph_real vs[4] = {10, 10, 10, 10}, acc[8] = {0, 0, 0, 0, 300, 400, 0, 0}, nu[4] = {0, 0, 0, 0}, dt = 0;
    sph_dt_input in = sph_dt_input_init((sph_real)0.1);
    int why = -9, st;
    sph_idx which = -9;
    th_begin("sph_time_step: the minimum over particles, its reason and particle; refusals");
    in.h_particle = sph_view_soa(h, NULL, NULL);
    in.vsig = sph_view_soa(vs, NULL, NULL);
    st = sph_time_step(&in, 2, 4, &dt, &why, &which);
    /* particle 1: 0.25 0.05 / 10 = 1.25e-3 */
    TH_CHECK(st == SPH_OK && why == SPH_DT_CFL && which == 1, "status %d reason %d particle %d", st, why, (int)which);
    TH_NEAR(dt, 1.25e-3, 8 * TH_EPS);
    in.acc = sph_view_interleaved(acc, 2); /* particle 2: |a| = 500, 0.25 sqrt(0.1 / 500) = 3.5e-3: not limiting */
    in.nu = (sph_real)2;                   /* uniform: 0.125 0.05^2 / 2 = 1.5625e-4 at particle 1 */
    st = sph_time_step(&in, 2, 4, &dt, &why, &which);
    TH_CHECK(st == SPH_OK && why == SPH_DT_VISCOUS && which == 1, "status %d reason %d particle %d", st, why,
             (int)which);
    TH_NEAR(dt, 1.5625e-4, 8 * TH_EPS);
    in.nu = 0;
    in.nu_particle = sph_view_soa(nu, NULL, NULL);
    in.coef.force = 10; /* force limit off the table: CFL again */
    acc[4] = (sph_real)3e7, acc[5] = (sph_real)4e7; /* |a| = 5e7: 10 sqrt(0.1 / 5e7) = 4.47e-4 at particle 2 */
    st = sph_time_step(&in, 2, 4, &dt, &why, &which);
    TH_CHECK(st == SPH_OK && why == SPH_DT_FORCE && which == 2, "status %d reason %d particle %d", st, why, (int)which);
    TH_NEAR(dt, 10 * sqrt(0.1 / 5e7), 16 * TH_EPS);
    nu[3] = -1;
    TH_CHECK(sph_time_step(&in, 2, 4, &dt, &why, &which) == SPH_EVALUE && which == 3, "negative nu: particle %d",
             (int)which);
    nu[3] = 0;
    in.vsig.p[0] = NULL;
    in.acc.p[0] = NULL;
    st = sph_time_step(&in, 2, 4, &dt, &why, &which);
    TH_CHECK(st == SPH_OK && why == SPH_DT_NONE && which == -1, "no rates: reason %d particle %d", why, (int)which);
    st = sph_time_step(&in, 2, 0, &dt, &why, &which);
    TH_CHECK(st == SPH_OK && why == SPH_DT_NONE && which == -1 && dt > 1e30, "no particles: reason %d", why);
    TH_CHECK(sph_time_step(NULL, 2, 4, &dt, &why, &which) == SPH_ENULL, "in NULL");
    TH_CHECK(sph_time_step(&in, 4, 4, &dt, &why, &which) == SPH_EDIM, "dim 4");
    TH_CHECK(sph_time_step(&in, 2, -1, &dt, &why, &which) == SPH_ECOUNT, "n < 0");
    in.acc = sph_view_soa(acc, NULL, NULL);
    TH_CHECK(sph_time_step(&in, 2, 4, &dt, &why, &which) == SPH_ENULL, "acceleration view without its y");
    th_end();
}

int main(void)
{
    test_particle();
    test_array();
    return th_summary();
}
