/* Solver terms: time-step limits (S9)-(S12), docs/solver.md.
 *
 * Values worked by hand from the definitions: dt = min(C_cfl h / v_sig,
 * C_force sqrt(h / |a|), C_visc h^2 / nu, C_diff h^2 / D) with the default
 * coefficients 0.25, 0.25, 0.125, 0.125 (Morris, Fox & Zhu 1997; Monaghan
 * 1992), the limiting reason and particle, and the refusals; the names of
 * the reasons; and the rule of docs/solver.md that the pair signal velocity
 * (S2) of sph_artificial_viscosity, 2 c0 at rest, with C_cfl = 0.5 gives the
 * examples' step dt = 0.25 h / (c0 + max |v|).
 */
#include "harness.h"
#include <stdlib.h>
#include <string.h>

static void test_particle(void)
{
    const sph_dt_coef k = sph_dt_coef_default();
    sph_dt_coef k2 = k;
    int why = -9;
    th_begin("(S9)-(S12) one particle: each limit and its reason");
    /* h = 0.1: CFL 0.25 0.1 / 10 = 2.5e-3; force 0.25 sqrt(0.1 / 1e4) = 7.9e-4; viscous 0.125 0.01 / 1 = 1.25e-3;
       diffusion 0.125 0.01 / 5 = 2.5e-4 */
    TH_NEAR(sph_dt_limit(&k, (sph_real)0.1, 10, 0, 0, 0, &why), 2.5e-3, 8 * TH_EPS);
    TH_CHECK(why == SPH_DT_CFL, "reason %s", sph_dt_reason_name(why));
    TH_NEAR(sph_dt_limit(&k, (sph_real)0.1, 10, 1e4, 0, 0, &why), 0.25 * sqrt(1e-5), 8 * TH_EPS);
    TH_CHECK(why == SPH_DT_FORCE, "reason %s", sph_dt_reason_name(why));
    TH_NEAR(sph_dt_limit(&k, (sph_real)0.1, 10, 10, 1, 0, &why), 1.25e-3, 8 * TH_EPS);
    TH_CHECK(why == SPH_DT_VISCOUS, "reason %s", sph_dt_reason_name(why));
    TH_NEAR(sph_dt_limit(&k, (sph_real)0.1, 10, 1e4, 1, 5, &why), 2.5e-4, 8 * TH_EPS);
    TH_CHECK(why == SPH_DT_DIFFUSION, "reason %s", sph_dt_reason_name(why));
    k2.diffusion = (sph_real)0.1; /* each coefficient applies to its own limit */
    TH_NEAR(sph_dt_limit(&k2, (sph_real)0.1, 10, 1e4, 1, 5, &why), 2e-4, 8 * TH_EPS);
    k2.viscous = (sph_real)0.01;
    TH_NEAR(sph_dt_limit(&k2, (sph_real)0.1, 10, 1e4, 1, 5, &why), 1e-4, 8 * TH_EPS);
    TH_CHECK(why == SPH_DT_VISCOUS, "reason %s", sph_dt_reason_name(why));
    TH_CHECK(sph_dt_limit(&k, (sph_real)0.1, 0, 0, 0, 0, &why) > 1e30 && why == SPH_DT_NONE, "no rate: reason %s", sph_dt_reason_name(why));
    TH_CHECK(sph_dt_limit(&k, 0, 10, 0, 0, 0, &why) == 0 && why == SPH_DT_INVALID, "h = 0: reason %s", sph_dt_reason_name(why));
    TH_CHECK(sph_dt_limit(&k, 1, -1, 0, 0, 0, &why) == 0 && why == SPH_DT_INVALID, "v_sig < 0: reason %s", sph_dt_reason_name(why));
    TH_CHECK(sph_dt_limit(&k, 1, 1, (sph_real)NAN, 0, 0, &why) == 0 && why == SPH_DT_INVALID, "NaN: reason %s", sph_dt_reason_name(why));
    TH_CHECK(sph_dt_limit(NULL, 1, 1, 0, 0, 0, &why) == 0 && why == SPH_DT_INVALID, "coef NULL: reason %s", sph_dt_reason_name(why));
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
    TH_CHECK(st == SPH_OK && why == SPH_DT_CFL && which == 1, "status %d reason %s particle %d", st, sph_dt_reason_name(why), (int)which);
    TH_NEAR(dt, 1.25e-3, 8 * TH_EPS);
    in.acc = sph_view_interleaved(acc, 2); /* particle 2: |a| = 500, 0.25 sqrt(0.1 / 500) = 3.5e-3: not limiting */
    in.nu = (sph_real)2;                   /* uniform: 0.125 0.05^2 / 2 = 1.5625e-4 at particle 1 */
    st = sph_time_step(&in, 2, 4, &dt, &why, &which);
    TH_CHECK(st == SPH_OK && why == SPH_DT_VISCOUS && which == 1, "status %d reason %s particle %d", st, sph_dt_reason_name(why),
             (int)which);
    TH_NEAR(dt, 1.5625e-4, 8 * TH_EPS);
    in.nu = 0;
    in.nu_particle = sph_view_soa(nu, NULL, NULL);
    in.coef.force = 10; /* force limit off the table: CFL again */
    acc[4] = (sph_real)3e7, acc[5] = (sph_real)4e7; /* |a| = 5e7: 10 sqrt(0.1 / 5e7) = 4.47e-4 at particle 2 */
    st = sph_time_step(&in, 2, 4, &dt, &why, &which);
    TH_CHECK(st == SPH_OK && why == SPH_DT_FORCE && which == 2, "status %d reason %s particle %d", st, sph_dt_reason_name(why), (int)which);
    TH_NEAR(dt, 10 * sqrt(0.1 / 5e7), 16 * TH_EPS);
    nu[3] = -1;
    TH_CHECK(sph_time_step(&in, 2, 4, &dt, &why, &which) == SPH_EVALUE && which == 3, "negative nu: particle %d",
             (int)which);
    nu[3] = 0;
    in.vsig.p[0] = NULL;
    in.acc.p[0] = NULL;
    st = sph_time_step(&in, 2, 4, &dt, &why, &which);
    TH_CHECK(st == SPH_OK && why == SPH_DT_NONE && which == -1, "no rates: reason %s particle %d", sph_dt_reason_name(why), (int)which);
    st = sph_time_step(&in, 2, 0, &dt, &why, &which);
    TH_CHECK(st == SPH_OK && why == SPH_DT_NONE && which == -1 && dt > 1e30, "no particles: reason %s", sph_dt_reason_name(why));
    TH_CHECK(sph_time_step(NULL, 2, 4, &dt, &why, &which) == SPH_ENULL, "in NULL");
    TH_CHECK(sph_time_step(&in, 4, 4, &dt, &why, &which) == SPH_EDIM, "dim 4");
    TH_CHECK(sph_time_step(&in, 2, -1, &dt, &why, &which) == SPH_ECOUNT, "n < 0");
    in.acc = sph_view_soa(acc, NULL, NULL);
    TH_CHECK(sph_time_step(&in, 2, 4, &dt, &why, &which) == SPH_ENULL, "acceleration view without its y");
    th_end();
}

static void test_reason_names(void)
{
    static const int reasons[] = {SPH_DT_NONE, SPH_DT_CFL, SPH_DT_FORCE, SPH_DT_VISCOUS, SPH_DT_DIFFUSION,
                                  SPH_DT_INVALID};
    const int nr = (int)(sizeof reasons / sizeof reasons[0]);
    int a, b;
    th_begin("sph_dt_reason_name: a distinct non-empty name per reason, \"unknown\" for any other value");
    for (a = 0; a < nr; ++a) {
        const char *na = sph_dt_reason_name(reasons[a]);
        TH_CHECK(na != NULL && na[0] != '\0' && strcmp(na, "unknown") != 0, "reason %d: name '%s'", reasons[a],
                 na != NULL ? na : "(null)");
        for (b = 0; na != NULL && b < a; ++b)
            TH_CHECK(strcmp(na, sph_dt_reason_name(reasons[b])) != 0, "reasons %d and %d share the name '%s'",
                     reasons[a], reasons[b], na);
    }
    TH_CHECK(strcmp(sph_dt_reason_name(SPH_DT_CFL), "cfl") == 0 && strcmp(sph_dt_reason_name(SPH_DT_FORCE), "force") == 0,
             "cfl and force names: '%s', '%s'", sph_dt_reason_name(SPH_DT_CFL), sph_dt_reason_name(SPH_DT_FORCE));
    TH_CHECK(strcmp(sph_dt_reason_name(5), "unknown") == 0 && strcmp(sph_dt_reason_name(-2), "unknown") == 0 &&
                 strcmp(sph_dt_reason_name(1 << 30), "unknown") == 0,
             "values 5, -2, 2^30: '%s', '%s', '%s'", sph_dt_reason_name(5), sph_dt_reason_name(-2),
             sph_dt_reason_name(1 << 30));
    th_end();
}

/* docs/solver.md, "Time step": one rule, a coefficient per input. At rest the
 * largest pair signal velocity (S2) is c_i + c_j = 2 c0 (w_ij = 0), so
 * C_cfl = 0.5 on it gives 0.5 h / (2 c0) = 0.25 h / c0, the examples' step
 * 0.25 h / (c0 + max |v|) with max |v| = 0; the default 0.25 on it gives half.
 * The one-particle speed c0 + |v| with the default 0.25 gives the examples'
 * step for a moving fluid. */
static void test_cfl_rule(void)
{
    enum { N = 5 };
    const sph_real dx = (sph_real)0.1, h = (sph_real)0.13, c0 = 20, U = 3;
    sph_real x[N], m[N], rho[N], v[N], cs[N], acc[N], vs[N], speed[N], dt = 0;
    sph_off off[N + 1];
    sph_idx idx[N * N], which = -9;
    sph_neighbours list = SPH_NEIGHBOURS_INIT(N, N, NULL, NULL); /* box_known 0: no box of its own */
    sph_ctx c;
    sph_dt_input in = sph_dt_input_init(h);
    const sph_av av = sph_av_init(SPH_AV_SIGNAL, 1, 3);
    int i, j, st, why = -9;
    th_begin("(S9) the pair signal velocity of sph_artificial_viscosity at rest (2 c0) with C_cfl = 0.5: "
             "dt = 0.25 h / c0");
    for (i = 0; i < N; ++i) {
        x[i] = dx * (sph_real)i, m[i] = dx, rho[i] = 1, v[i] = 0, cs[i] = c0;
        off[i] = (sph_off)i * N;
        for (j = 0; j < N; ++j) idx[i * N + j] = (sph_idx)j;
    }
    off[N] = (sph_off)N * N;
    list.offset = off, list.index = idx;
    c = sph_ctx_init(SPH_KERNEL_CUBIC, 1, h, &list, sph_view_soa(x, NULL, NULL));
    c.m = sph_view_soa(m, NULL, NULL);
    c.rho = sph_view_soa(rho, NULL, NULL);
    st = sph_artificial_viscosity(&c, &av, sph_view_soa(v, NULL, NULL), sph_view_none(), sph_view_soa(cs, NULL, NULL),
                                  sph_view_none(), sph_out_soa(acc, NULL, NULL), sph_out_soa(NULL, NULL, NULL),
                                  sph_out_soa(vs, NULL, NULL));
    TH_CHECK(st == SPH_OK, "sph_artificial_viscosity: %s", sph_strerror(st));
    for (i = 0; i < N; ++i) TH_NEAR(vs[i], 2 * c0, 4 * TH_EPS * c0);
    in.vsig = sph_view_soa(vs, NULL, NULL);
    in.coef.cfl = (sph_real)0.5;
    st = sph_time_step(&in, 1, N, &dt, &why, &which);
    TH_CHECK(st == SPH_OK && why == SPH_DT_CFL, "status %d reason %s", st, sph_dt_reason_name(why));
    TH_NEAR(dt, 0.25 * h / c0, 8 * TH_EPS * h / c0);
    in.coef = sph_dt_coef_default(); /* the default on (S2): half the examples' step */
    st = sph_time_step(&in, 1, N, &dt, &why, &which);
    TH_NEAR(dt, 0.125 * h / c0, 8 * TH_EPS * h / c0);
    for (i = 0; i < N; ++i) speed[i] = c0 + (i == 2 ? U : 0); /* c + |v|, one particle moving at U */
    in.vsig = sph_view_soa(speed, NULL, NULL);
    st = sph_time_step(&in, 1, N, &dt, &why, &which);
    TH_CHECK(st == SPH_OK && why == SPH_DT_CFL && which == 2, "status %d reason %s particle %d", st,
             sph_dt_reason_name(why), (int)which);
    TH_NEAR(dt, 0.25 * h / (c0 + U), 8 * TH_EPS * h / c0);
    th_end();
}

int main(void)
{
    test_particle();
    test_array();
    test_reason_names();
    test_cfl_rule();
    return th_summary();
}
