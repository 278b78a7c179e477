/* Solver terms: the viscosity and conductivity switches (S13)-(S17),
 * docs/solver.md.
 *
 * Reference values: each formula written out in double from its source -
 * Balsara (1995) for (S13); Borrow et al. (2022, SPHENIX, eq. 20) for (S14),
 * eqs. 18, 19, 21 for (S16), eqs. 28, 29 for (S17); Morris & Monaghan (1997)
 * with the source of Rosswog et al. (2000) for (S15) - and the closed forms
 * they imply: the fixed point of (S15), the geometric decay (1 + r)^-n of
 * (S16) and its limit exp(-ell c t / H). div v and curl v come from linear
 * fields v = A x, for which the corrected velocity gradient (O17) is exact
 * (div v = trace A, curl v = A_yx - A_xy to round-off), on a jittered lattice.
 */
#include "op_scene.h"

/* (S13) in double. */
static double ref_balsara(double d, double w, double c, double h)
{
    return fabs(d) / (fabs(d) + fabs(w) + 1e-4 * c / h);
}

/* (S16) in double: the new alpha from alpha, div v, d(div v)/dt, c, H, dt. */
static double ref_sphenix(const sph_switch *s, double alpha, double dv, double rate, double c, double H, double dt)
{
    const double S = dv < 0 ? H * H * fmax(0, -rate) : 0, loc = (double)s->alpha_max * S / (c * c + S);
    const double r = (double)s->length * dt * c / H;
    const double a = loc > alpha ? loc : (alpha + loc * r) / (1 + r);
    return fmin(fmax(a, (double)s->alpha_min), (double)s->alpha_max);
}

/* div v and |curl v| (2-D) of v = A x on a jittered 12 x 12 lattice (no box: the corrected gradient is exact at
 * the edges too), from the corrected velocity gradient (O17) of particle k. */
static void lattice_divcurl(const double A[2][2], double *div, double *curl, int k)
{
    ts_scene s;
    sph_real *v, *T;
    sph_idx nfb = 0;
    int i, st;
    ts_lattice(&s, SPH_KERNEL_QUINTIC, 2, 12, 1.0 / 12, 1.3, 0.2, 41, NULL);
    v = ts_vec(3 * s.n), T = ts_vec(4 * s.n);
    for (i = 0; i < s.n; ++i) {
        v[3 * i] = (sph_real)(A[0][0] * s.x[3 * i] + A[0][1] * s.x[3 * i + 1]);
        v[3 * i + 1] = (sph_real)(A[1][0] * s.x[3 * i] + A[1][1] * s.x[3 * i + 1]);
    }
    st = sph_gradient_vector(&s.c, SPH_SCHEME_CORRECTED, sph_view_interleaved(v, 3), sph_view_none(), T, 4, &nfb);
    TH_CHECK(st == SPH_OK && nfb == 0, "corrected gradient: status %d, %d fallbacks", st, (int)nfb);
    *div = (double)T[4 * k] + T[4 * k + 3];        /* dv_x/dx + dv_y/dy */
    *curl = fabs((double)T[4 * k + 2] - T[4 * k + 1]); /* dv_y/dx - dv_x/dy */
    free(v), free(T);
    ts_free(&s);
}

static void test_balsara(void)
{
    /* (a) pure shear v = (s y, 0): div v = 0, |curl v| = s; (b) compression with shear v = (a x + s y, a y); (c)
       pure compression v = -g x: B near 1 */
    const double shear[2][2] = {{0, 2.5}, {0, 0}}, mixed[2][2] = {{-0.7, 1.9}, {0, -0.7}}, conv[2][2] = {{-3, 0}, {0, -3}};
    const double c = 1.5, h = 0.1;
    double d, w, B;
    int k, i;
    th_begin("(S13) Balsara factor: 0 in pure shear, the formula in a sheared compression, near 1 in compression "
             "(div v and curl v of linear fields)");
    for (k = 0; k < 3; ++k) {
        const int p = k == 0 ? 0 : k == 1 ? 77 : 143; /* a corner, an inner particle, the last corner */
        lattice_divcurl(shear, &d, &w, p);
        TH_CLOSE(d, 0, 200 * TH_EPS);
        TH_NEAR(w, 2.5, 200 * TH_EPS);
        B = (double)sph_switch_balsara((sph_real)d, (sph_real)w, (sph_real)c, (sph_real)h);
        TH_CHECK(B <= 200 * TH_EPS, "shear: B = %g at particle %d", B, p);
        lattice_divcurl(mixed, &d, &w, p);
        TH_NEAR(d, -1.4, 200 * TH_EPS);
        TH_NEAR(w, 1.9, 200 * TH_EPS);
        B = (double)sph_switch_balsara((sph_real)d, (sph_real)w, (sph_real)c, (sph_real)h);
        TH_NEAR(B, ref_balsara(-1.4, 1.9, c, h), 1e3 * TH_EPS);
        lattice_divcurl(conv, &d, &w, p);
        B = (double)sph_switch_balsara((sph_real)d, (sph_real)w, (sph_real)c, (sph_real)h);
        TH_NEAR(B, 6 / (6 + 1.5e-3), 1e3 * TH_EPS);
        TH_CHECK(B > 0.999 && B < 1, "compression: B = %.17g", B);
    }
    /* the documented fallbacks: no flow and c = 0, an h <= 0 or a NaN give 0; curl given with either sign */
    TH_CHECK(sph_switch_balsara(0, 0, 0, 1) == 0 && sph_switch_balsara(1, 0, 1, 0) == 0 &&
                 sph_switch_balsara(1, 0, 1, -1) == 0 && sph_switch_balsara(1, 0, -1, 1) == 0 &&
                 sph_switch_balsara((sph_real)NAN, 0, 1, 1) == 0,
             "fallbacks");
    for (i = 0; i < 20; ++i) {
        const double dv = -3 + 0.3 * i, cv = 0.1 * i - 1;
        TH_NEAR(sph_switch_balsara((sph_real)dv, (sph_real)cv, (sph_real)c, (sph_real)h), ref_balsara(dv, cv, c, h),
                8 * TH_EPS);
    }
    th_end();
}

static void test_pair_alpha(void)
{
    int i, j;
    th_begin("(S14) alpha_ij = (alpha_i + alpha_j) / 2 (B_i + B_j) / 2, alpha itself for equal alphas and B = 1");
    for (i = 0; i < 9; ++i)
        for (j = 0; j < 9; ++j) {
            const double ai = 0.25 * i, aj = 0.3 * j, bi = 0.125 * i, bj = 1 - 0.1 * j;
            const sph_real a = (sph_real)ai;
            TH_NEAR(sph_pair_av_alpha((sph_real)ai, (sph_real)aj, (sph_real)bi, (sph_real)bj),
                    (ai + aj) / 2 * (bi + bj) / 2, 4 * TH_EPS);
            TH_CHECK(sph_pair_av_alpha(a, a, 1, 1) == a, "alpha %g not returned bit for bit", ai);
            TH_CHECK(sph_pair_av_alpha((sph_real)ai, (sph_real)aj, (sph_real)bi, (sph_real)bj) ==
                         sph_pair_av_alpha((sph_real)aj, (sph_real)ai, (sph_real)bj, (sph_real)bi),
                     "not symmetric in i, j");
        }
    th_end();
}

static void test_sphenix_rise(void)
{
    /* converging flow, steepening: div v = -g t, d(div v)/dt = -g. S = H^2 g; alpha jumps to alpha_loc and rises
       toward alpha_max as the compression rate grows against c^2 / H^2 */
    const sph_switch s = sph_switch_default();
    const double c = 2, H = 0.2, dt = 1e-3;
    double alpha = 0, g;
    int k;
    th_begin("(S16) SPHENIX: alpha rises to alpha_max S / (c^2 + S) in a converging flow, toward alpha_max as S grows");
    for (k = 0, g = 1; k < 7; ++k, g *= 10) {
        const double want = 2 * H * H * g / (c * c + H * H * g), prev = -g * k * dt, now = -g * (k + 1) * dt;
        const double a = (double)sph_switch_sphenix(&s, (sph_real)alpha, (sph_real)now, (sph_real)((now - prev) / dt),
                                                    (sph_real)c, (sph_real)H, (sph_real)dt);
        TH_NEAR(a, want, 64 * TH_EPS);
        TH_NEAR(a, ref_sphenix(&s, alpha, now, (now - prev) / dt, c, H, dt), 64 * TH_EPS);
        TH_CHECK(a > alpha, "g = %g: alpha %g did not rise from %g", g, a, alpha);
        alpha = a;
    }
    TH_CHECK(alpha > 0.999 * 2 && alpha <= 2, "alpha %.17g not near alpha_max 2", alpha);
    /* no source where the flow diverges, nor where the compression weakens */
    TH_CHECK(sph_switch_sphenix(&s, 0, (sph_real)0.5, -100, (sph_real)c, (sph_real)H, 0) == 0, "div v > 0: a source");
    TH_CHECK(sph_switch_sphenix(&s, 0, (sph_real)-0.5, 100, (sph_real)c, (sph_real)H, 0) == 0,
             "weakening compression: a source");
    th_end();
}

static void test_sphenix_decay(void)
{
    /* no source: alpha_n = alpha_0 (1 + r)^-n, r = ell dt c / H, -> alpha_0 exp(-ell c t / H); with alpha_min > 0
       it stops there */
    sph_switch s = sph_switch_default();
    const double c = 3, H = 0.15, dt = 2e-4, r = 0.25 * dt * c / H;
    double alpha = 1.7, t = 0;
    int n;
    th_begin("(S16) SPHENIX: alpha decays as (1 + ell dt c / H)^-n, at the rate ell c / H, and stops at alpha_min");
    for (n = 1; n <= 2000; ++n) {
        alpha = (double)sph_switch_sphenix(&s, (sph_real)alpha, 0, 0, (sph_real)c, (sph_real)H, (sph_real)dt);
        t += dt;
    }
    TH_REL(alpha, 1.7 * pow(1 + r, -2000), 4000 * TH_EPS);
    TH_REL(log(alpha / 1.7) / t, -0.25 * c / H, 2 * r + 4000 * TH_EPS / (0.25 * c / H * t));
    s.alpha_min = (sph_real)0.1;
    for (n = 0; n < 4000; ++n)
        alpha = (double)sph_switch_sphenix(&s, (sph_real)alpha, 0, 0, (sph_real)c, (sph_real)H, (sph_real)dt);
    TH_CHECK(alpha == (double)(sph_real)0.1, "alpha %.17g, want alpha_min 0.1", alpha);
    /* clamped into [alpha_min, alpha_max]; dt = 0: no decay; a NaN alpha gives alpha_max */
    TH_CHECK(sph_switch_sphenix(&s, 5, 0, 0, 1, 1, 0) == 2 && sph_switch_sphenix(&s, 0, 0, 0, 1, 1, 0) == s.alpha_min,
             "bounds");
    TH_CHECK(sph_switch_sphenix(&s, (sph_real)0.7, 0, 0, 1, 1, 0) == (sph_real)0.7, "dt 0 changed alpha");
    TH_CHECK(sph_switch_sphenix(&s, (sph_real)NAN, 0, 0, 1, 1, 1) == 2, "NaN alpha");
    th_end();
}

static void test_mm97(void)
{
    /* d alpha / dt = -(alpha - alpha_min) k + D (alpha_max - alpha), k = ell c / h, D = max(-div v, 0): its value,
       the decay at rate k, and the fixed point (alpha_min k + D alpha_max) / (k + D) that integration reaches */
    sph_switch s = sph_switch_default();
    const double c = 2, h = 0.05;
    int i, n;
    s.alpha_min = (sph_real)0.1, s.alpha_max = 1, s.length = (sph_real)0.1;
    th_begin("(S15) Morris & Monaghan with Rosswog's source: the rate, the decay at ell c / h, the fixed point "
             "rising to alpha_max with the compression");
    for (i = 0; i < 10; ++i) {
        const double a = 0.1 * i, dv = 1.5 - 0.4 * i, k = 0.1 * c / h;
        const double want = -(a - 0.1) * k + (dv < 0 ? -dv : 0) * (1 - a);
        TH_NEAR(sph_switch_mm97(&s, (sph_real)a, (sph_real)dv, (sph_real)c, (sph_real)h), want, 16 * TH_EPS);
    }
    for (i = 0; i < 4; ++i) {
        const double D = i == 0 ? 0 : pow(10, i), k = 0.1 * c / h, fix = (0.1 * k + D) / (k + D);
        const double dt = 0.5 / (k + D);
        double a = 0.5;
        for (n = 0; n < 400; ++n) a += dt * (double)sph_switch_mm97(&s, (sph_real)a, (sph_real)-D, (sph_real)c,
                                                                    (sph_real)h);
        TH_NEAR(a, fix, 64 * TH_EPS);
        if (i == 3) TH_CHECK(a > 0.99, "D = %g: fixed point %g not near alpha_max 1", D, a);
    }
    TH_CHECK(sph_switch_mm97(NULL, 1, -1, 1, 1) == 0 && sph_switch_mm97(&s, 1, -1, 1, 0) == 0, "fallbacks");
    th_end();
}

static void test_conductivity(void)
{
    /* 1-D lattice with a step of u at x = 0.5 (u = 0.5 on the left, 2 on the right): lap u (O12) > 0 on the cold
       side of the step, < 0 on the hot side, 0 away from it. One update from alpha_D = 0 gives dt beta_D H lap u /
       sqrt(u) on the cold side, 0 elsewhere; the limiter takes it to alpha_D,max (1 - alpha / alpha_max) = 0.1 at
       alpha = 1.8, 0 at alpha = alpha_max */
    const sph_switch s = sph_switch_default();
    ts_scene sc;
    sph_real *u, *lap;
    const double dt = 1e-3, vsig = 2;
    int i, rising = 0, flat = 0;
    th_begin("(S17) SPHENIX conductivity: alpha_D rises on the cold side of a jump of u, stays 0 elsewhere, is "
             "limited in viscous flow and decays at v_sig / H");
    ts_lattice(&sc, SPH_KERNEL_CUBIC, 1, 40, 1.0 / 40, 1.2, 0, 1, NULL);
    u = ts_vec(sc.n), lap = ts_vec(sc.n);
    for (i = 0; i < sc.n; ++i) u[i] = (sph_real)(sc.x[3 * i] < 0.5 ? 0.5 : 2);
    TH_CHECK(sph_laplacian(&sc.c, sph_view_soa(u, NULL, NULL), sph_view_none(), sph_out_soa(lap, NULL, NULL)) == SPH_OK,
             "laplacian");
    for (i = 2; i < sc.n - 2; ++i) { /* away from the lattice's ends */
        const double H = 2 * sc.h, L = (double)lap[i], want = L > 0 ? fmin(dt * H * L / sqrt((double)u[i]), 1) : 0;
        const double a = (double)sph_switch_conductivity(&s, 0, lap[i], u[i], (sph_real)vsig, (sph_real)H, 0,
                                                         (sph_real)dt);
        const double lim = (double)sph_switch_conductivity(&s, 0, lap[i], u[i], (sph_real)vsig, (sph_real)H,
                                                           (sph_real)1.8, (sph_real)dt);
        TH_NEAR(a, want, 64 * TH_EPS);
        TH_NEAR(lim, fmin(want, 1 - (double)(sph_real)1.8 / 2), 64 * TH_EPS);
        TH_CHECK(sph_switch_conductivity(&s, 0, lap[i], u[i], (sph_real)vsig, (sph_real)H, 2, (sph_real)dt) == 0,
                 "alpha = alpha_max: alpha_D not 0");
        rising += a > 0;
        flat += a == 0 && fabs(sc.x[3 * i] - 0.5) > 3 * H;
        TH_CHECK(a == 0 || (sc.x[3 * i] < 0.5 && fabs(sc.x[3 * i] - 0.5) < H), "alpha_D %g at x = %g", a,
                 (double)sc.x[3 * i]);
    }
    TH_CHECK(rising >= 2 && flat > 15, "%d particles with alpha_D > 0, %d far from the jump at 0", rising, flat);
    /* decay: lap u = 0, alpha_D = 0.6 -> 0.6 - dt 0.6 v_sig / H, explicit */
    TH_NEAR(sph_switch_conductivity(&s, (sph_real)0.6, 0, 1, (sph_real)vsig, (sph_real)0.2, 0, (sph_real)dt),
            0.6 - dt * 0.6 * vsig / 0.2, 16 * TH_EPS);
    /* fallbacks: u <= 0 no source, dt 0 no change, NaN alpha_D clamped into the bounds */
    TH_CHECK(sph_switch_conductivity(&s, 0, 5, 0, 1, 1, 0, 1) == 0 &&
                 sph_switch_conductivity(&s, (sph_real)0.3, 5, 1, 1, 1, 0, 0) == (sph_real)0.3 &&
                 sph_switch_conductivity(&s, (sph_real)NAN, 0, 1, 1, 1, 0, 1) == 1,
             "fallbacks");
    free(u), free(lap);
    ts_free(&sc);
    th_end();
}

/* The array update against the per-particle functions, bit for bit, over views of every layout. */
static void test_update(void)
{
    enum { N = 37 };
    sph_switch_input in = sph_switch_input_init((sph_real)2.5);
    sph_real sw[3 * N], c[N], hh = (sph_real)0.04, u[N], al[N], prev[N], B[N], ad[N], al0[N], prev0[N], ad0[N];
    sph_real vsig[N], avis[N];
    const sph_out none = sph_out_soa(NULL, NULL, NULL);
    tp_rng g;
    int i, k, st, bad = 0;
    g.s = 99;
    th_begin("sph_switch_update: the per-particle functions bit for bit, interleaved and stride-0 views, optional "
             "parts; status codes with nothing written");
    for (i = 0; i < N; ++i) {
        sw[3 * i] = (sph_real)tp_range(&g, -5, 3), sw[3 * i + 1] = (sph_real)tp_range(&g, 0, 4);
        sw[3 * i + 2] = (sph_real)tp_range(&g, -20, 20);
        c[i] = (sph_real)tp_range(&g, 0.5, 2), u[i] = (sph_real)tp_range(&g, 0.1, 3);
        al0[i] = (sph_real)tp_range(&g, 0, 2), prev0[i] = (sph_real)tp_range(&g, -5, 3);
        ad0[i] = (sph_real)tp_range(&g, 0, 1), vsig[i] = (sph_real)tp_range(&g, 1, 5);
        avis[i] = (sph_real)tp_range(&g, 0, 2);
    }
    in.dt = (sph_real)0.01;
    in.div_v = sph_view_aos(sw, 1, 3 * sizeof(sph_real)), in.curl_v = sph_view_aos(sw + 1, 1, 3 * sizeof(sph_real));
    in.lap_u = sph_view_aos(sw + 2, 1, 3 * sizeof(sph_real));
    in.c = sph_view_soa(c, NULL, NULL), in.u = sph_view_soa(u, NULL, NULL);
    in.h = sph_view_aos(&hh, 1, 0); /* one h for all */
    for (k = 0; k < 4; ++k) { /* SPHENIX / none, with and without v_sig and alpha_visc */
        in.viscosity = k % 2 ? SPH_SWITCH_NONE : SPH_SWITCH_SPHENIX;
        in.v_sig = k >= 2 ? sph_view_soa(vsig, NULL, NULL) : sph_view_none();
        in.alpha_visc = k >= 2 ? sph_view_soa(avis, NULL, NULL) : sph_view_none();
        memcpy(al, al0, sizeof al), memcpy(prev, prev0, sizeof prev), memcpy(ad, ad0, sizeof ad);
        st = sph_switch_update(&in, N, sph_out_soa(al, NULL, NULL), sph_out_soa(prev, NULL, NULL),
                               sph_out_soa(B, NULL, NULL), sph_out_soa(ad, NULL, NULL));
        TH_CHECK(st == SPH_OK, "status %d", st);
        for (i = 0; i < N; ++i) {
            const sph_real H = in.kappa * hh, dv = sw[3 * i];
            const sph_real a = in.viscosity == SPH_SWITCH_NONE
                                   ? al0[i]
                                   : sph_switch_sphenix(&in.par, al0[i], dv, (dv - prev0[i]) / in.dt, c[i], H, in.dt);
            const sph_real d = sph_switch_conductivity(&in.par, ad0[i], sw[3 * i + 2], u[i], k >= 2 ? vsig[i] : 2 * c[i],
                                                       H, k >= 2 ? avis[i] : a, in.dt);
            bad += al[i] != a || prev[i] != dv || ad[i] != d || B[i] != sph_switch_balsara(dv, sw[3 * i + 1], c[i], hh);
        }
    }
    TH_CHECK(bad == 0, "%d particles differ from the per-particle functions", bad);
    /* optional parts: no Balsara output, no conductivity, no div_v_prev without the viscosity switch */
    memcpy(al, al0, sizeof al), memcpy(ad, ad0, sizeof ad);
    in.viscosity = SPH_SWITCH_NONE;
    st = sph_switch_update(&in, N, sph_out_soa(al, NULL, NULL), none, none, none);
    TH_CHECK(st == SPH_OK && memcmp(al, al0, sizeof al) == 0, "alpha only read: status %d", st);
    /* errors: nothing written */
    memcpy(al, al0, sizeof al);
    {
        sph_switch_input e = in;
        const sph_out ao = sph_out_soa(al, NULL, NULL), po = sph_out_soa(prev, NULL, NULL);
        e.viscosity = SPH_SWITCH_SPHENIX;
        TH_CHECK(sph_switch_update(NULL, N, ao, po, none, none) == SPH_ENULL, "in NULL");
        TH_CHECK(sph_switch_update(&e, -1, ao, po, none, none) == SPH_ECOUNT, "n < 0");
        TH_CHECK(sph_switch_update(&e, N, ao, none, none, none) == SPH_ENULL, "no div_v_prev for (S16)");
        TH_CHECK(sph_switch_update(&e, N, none, po, none, none) == SPH_ENULL, "no alpha");
        TH_CHECK(sph_switch_update(&e, N, ao, po, none, sph_out_soa(ad, NULL, NULL)) == SPH_OK, "with alpha_D");
        memcpy(al, al0, sizeof al);
        e.lap_u = sph_view_none();
        TH_CHECK(sph_switch_update(&e, N, ao, po, none, sph_out_soa(ad, NULL, NULL)) == SPH_ENULL, "alpha_D, no lap u");
        e = in, e.viscosity = (sph_switch_kind)7;
        TH_CHECK(sph_switch_update(&e, N, ao, po, none, none) == SPH_EOPTION, "viscosity 7");
        e = in, e.par.alpha_min = 3;
        TH_CHECK(sph_switch_update(&e, N, ao, po, none, none) == SPH_ERANGE, "alpha_min > alpha_max");
        e = in, e.dt = -1;
        TH_CHECK(sph_switch_update(&e, N, ao, po, none, none) == SPH_ERANGE, "dt < 0");
        e = in, e.kappa = 0;
        TH_CHECK(sph_switch_update(&e, N, ao, po, none, none) == SPH_ERANGE, "kappa 0");
        e = in, e.par.beta_d = (sph_real)NAN;
        TH_CHECK(sph_switch_update(&e, N, ao, po, none, none) == SPH_ERANGE, "beta_D NaN");
        e = in, e.h.stride = -1;
        TH_CHECK(sph_switch_update(&e, N, ao, po, none, none) == SPH_ESTRIDE, "h stride -1");
        TH_CHECK(sph_switch_update(&in, N, sph_out_aos(al, 1, 0), po, none, none) == SPH_ESTRIDE, "alpha stride 0");
        hh = 0;
        TH_CHECK(sph_switch_update(&in, N, ao, po, none, none) == SPH_EH, "h = 0");
        hh = (sph_real)0.04, c[5] = -1;
        TH_CHECK(sph_switch_update(&in, N, ao, po, none, none) == SPH_EVALUE, "c < 0");
        c[5] = (sph_real)INFINITY;
        TH_CHECK(sph_switch_update(&in, N, ao, po, none, none) == SPH_ENONFINITE, "c Inf");
        c[5] = 1, al[N - 1] = -1;
        TH_CHECK(sph_switch_update(&in, N, ao, po, none, none) == SPH_EVALUE, "alpha < 0");
        al[N - 1] = al0[N - 1];
        TH_CHECK(memcmp(al, al0, sizeof al) == 0, "alpha written on a refused call");
    }
    th_end();
}

int main(void)
{
    test_balsara();
    test_pair_alpha();
    test_sphenix_rise();
    test_sphenix_decay();
    test_mm97();
    test_conductivity();
    test_update();
    return th_summary();
}
