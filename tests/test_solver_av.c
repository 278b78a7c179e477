/* Solver terms: artificial viscosity (S1)-(S4), docs/solver.md, with alpha
 * per particle and the Balsara factor (S14).
 *
 * Reference values: (S1) and (S3) written out in double from their sources
 * (Monaghan 1992, as restated by Monaghan 2005; Price
 * 2012, eqs. 101-103; alpha_ij = (alpha_i + alpha_j) / 2 (B_i + B_j) / 2,
 * Borrow et al. 2022, eq. 20), evaluated here independently of the library's
 * pair terms; the conservation laws are exact identities of the pair sum:
 * Pi_ij = Pi_ji and F_ij = F_ji (symmetric h_ij) with x_ji = -x_ij make the
 * momentum term antisymmetric and m_i v_i . a_i + m_i du_i/dt sum to zero
 * over every pair, so in a closed (periodic) system
 *   sum_i m_i a_i = 0  and  sum_i m_i (v_i . a_i + du_i/dt) = 0
 * up to the rounding of the sums (bound: 64 eps times the sum of magnitudes,
 * as tests/test_op_conservation.c). Entropy: F <= 0 and Pi_ij >= 0 make every
 * heating term >= 0, so du_i/dt >= 0 for every particle.
 */
#include "solver_scene.h"

static sph_av AV_M, AV_S; /* sph_av_init(SPH_AV_MONAGHAN, 1, 2), sph_av_init(SPH_AV_SIGNAL, 1, 3): set by main */

/* (S1) and (S3) in double, from the papers' formulas, with av's alpha or alpha_ij >= 0. */
static double ref_pi_alpha(const sph_av *av, double alpha_ij, int dim, double h, double ci, double cj, double rho_ij,
                           const double *dx, const double *dv)
{
    double vr = 0, r2 = 0;
    int a;
    for (a = 0; a < dim; ++a) vr += dv[a] * dx[a], r2 += dx[a] * dx[a];
    if (vr >= 0) return 0;
    if (alpha_ij < 0) alpha_ij = (double)av->alpha;
    if (av->form == SPH_AV_MONAGHAN) {
        const double mu = h * vr / (r2 + 0.01 * h * h);
        return (-alpha_ij * 0.5 * (ci + cj) * mu + (double)av->beta * mu * mu) / rho_ij;
    } else {
        const double w = vr / sqrt(r2);
        return -0.5 * alpha_ij * (ci + cj - (double)av->beta * w) * w / rho_ij;
    }
}

static double ref_pi(const sph_av *av, int dim, double h, double ci, double cj, double rho_ij, const double *dx,
                     const double *dv)
{
    return ref_pi_alpha(av, -1, dim, h, ci, cj, rho_ij, dx, dv);
}

static void test_pair_values(void)
{
    const sph_real dx[3] = {3, 4, 0}, toward[3] = {-3, -1, 0}, away[3] = {1, 2, 0}, shear[3] = {4, -3, 0};
    const double dxd[3] = {3, 4, 0}, td[3] = {-3, -1, 0};
    th_begin("(S1), (S3): values of approaching pairs, zero for receding and sheared pairs");
    {
        const double m = (double)sph_pair_av_monaghan(2, 1, 2, (sph_real)1.5, 7, 950, dx, toward);
        const double s = (double)sph_pair_av_signal(2, 1, 3, 6, 8, 950, dx, toward);
        /* by hand: v.x = -13, r = 5; mu = 1.5 (-13) / (25 + 0.0225); w = -13 / 5 */
        const double mu = -19.5 / 25.0225, w = -2.6;
        TH_NEAR(m, (-7 * mu + 2 * mu * mu) / 950, 8 * TH_EPS);
        TH_NEAR(s, -0.5 * (14 - 3 * w) * w / 950, 8 * TH_EPS);
        TH_NEAR(m, ref_pi(&AV_M, 2, 1.5, 7, 7, 950, dxd, td), 8 * TH_EPS);
        TH_CHECK(m > 0 && s > 0, "Pi = %g, %g", m, s);
        TH_NEAR(sph_pair_signal_velocity(2, 3, 6, 8, dx, toward), 14 - 3 * w, 8 * TH_EPS);
    }
    TH_CHECK(sph_pair_av_monaghan(2, 1, 2, 1, 7, 950, dx, away) == 0, "receding (S1) not 0");
    TH_CHECK(sph_pair_av_signal(2, 1, 3, 6, 8, 950, dx, away) == 0, "receding (S3) not 0");
    TH_CHECK(sph_pair_av_monaghan(2, 1, 2, 1, 7, 950, dx, shear) == 0, "shear (S1) not 0");
    TH_CHECK(sph_pair_av_signal(2, 1, 3, 6, 8, 950, dx, shear) == 0, "shear (S3) not 0");
    TH_CHECK(sph_pair_signal_velocity(2, 3, 6, 8, dx, away) == 14, "receding v_sig = c_i + c_j");
    /* the documented fallbacks: no division by 0 */
    TH_CHECK(sph_pair_av_monaghan(2, 1, 2, 1, 7, 0, dx, toward) == 0, "rho_ij = 0");
    TH_CHECK(sph_pair_av_signal(2, 1, 3, 6, 8, -1, dx, toward) == 0, "rho_ij < 0");
    {
        const sph_real zero[3] = {0, 0, 0};
        TH_CHECK(sph_pair_av_monaghan(2, 1, 2, 0, 7, 950, zero, toward) == 0, "r = h = 0");
        TH_CHECK(sph_pair_av_signal(2, 1, 3, 6, 8, 950, zero, toward) == 0, "r = 0");
    }
    th_end();
}

static void test_random_pairs(void)
{
    /* 10^4 random pairs: Pi = 0 exactly when receding, > 0 when approaching,
     * and the heating share of (S4) >= 0. */
    tp_rng g;
    int k, a, bad = 0;
    g.s = 77;
    th_begin("(S1)-(S4) on random pairs: zero when receding, heating >= 0");
    for (k = 0; k < 10000; ++k) {
        sph_real dx[3], dv[3], acc[3] = {0, 0, 0}, Pm, Ps, F;
        double vr = 0;
        for (a = 0; a < 3; ++a) dx[a] = (sph_real)tp_range(&g, -1, 1), dv[a] = (sph_real)tp_range(&g, -5, 5);
        for (a = 0; a < 3; ++a) vr += (double)dv[a] * dx[a];
        Pm = sph_pair_av_monaghan(3, 1, 2, (sph_real)0.7, 10, 1000, dx, dv);
        Ps = sph_pair_av_signal(3, 1, 3, 9, 11, 1000, dx, dv);
        F = sph_kernel_f(SPH_KERNEL_CUBIC, 3, (sph_real)sqrt((double)(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2])),
                         1);
        if (vr >= 0 && (Pm != 0 || Ps != 0)) ++bad;
        if (vr < 0 && (double)(dv[0] * dx[0] + dv[1] * dx[1] + dv[2] * dx[2]) < 0 && !(Pm > 0 && Ps > 0)) ++bad;
        if (sph_pair_av_apply(3, 2, Pm, F, dx, dv, acc) < 0 || sph_pair_av_apply(3, 2, Ps, F, dx, dv, acc) < 0) ++bad;
    }
    TH_CHECK(bad == 0, "%d pairs wrong", bad);
    th_end();
}

/* The operator against the pair sum written out in double; al, B: alpha and the Balsara factor per particle (NULL:
 * av's alpha, B = 1). */
static void check_against_reference_ab(ss_cloud *s, const sph_av *av, const sph_real *al, const sph_real *B)
{
    int i, a;
    double err = 0, scale = 0, derr = 0, dscale = 0;
    for (i = 0; i < s->n; ++i) {
        double acc[3] = {0, 0, 0}, du = 0;
        sph_off o;
        for (o = s->L.offset[i]; o < s->L.offset[i + 1]; ++o) {
            const int j = s->L.index[o];
            double dx[3], dv[3] = {0, 0, 0}, F, Pi, vr = 0;
            F = ss_pair(s, i, j, dx);
            for (a = 0; a < s->dim; ++a) dv[a] = (double)s->v[3 * i + a] - s->v[3 * j + a], vr += dv[a] * dx[a];
            Pi = ref_pi_alpha(av,
                              al == NULL && B == NULL ? -1
                              : (al != NULL ? 0.5 * ((double)al[i] + al[j]) : (double)av->alpha) *
                                    (B != NULL ? 0.5 * ((double)B[i] + B[j]) : 1),
                              s->dim, 0.5 * ((double)s->h[i] + s->h[j]), s->c[i], s->c[j],
                              0.5 * ((double)s->rho[i] + s->rho[j]), dx, dv);
            for (a = 0; a < s->dim; ++a) acc[a] -= (double)s->m[j] * Pi * F * dx[a];
            du += 0.5 * (double)s->m[j] * Pi * F * vr;
        }
        for (a = 0; a < s->dim; ++a) {
            err = fmax(err, fabs((double)s->a[3 * i + a] - acc[a]));
            scale = fmax(scale, fabs(acc[a]));
        }
        derr = fmax(derr, fabs((double)s->du[i] - du));
        dscale = fmax(dscale, fabs(du));
    }
    TH_CHECK(scale > 0 && err <= 1e3 * TH_EPS * scale, "acceleration off by %.3g of %.3g", err, scale);
    TH_CHECK(dscale > 0 && derr <= 1e3 * TH_EPS * dscale, "du/dt off by %.3g of %.3g", derr, dscale);
}

static void check_against_reference(ss_cloud *s, const sph_av *av) { check_against_reference_ab(s, av, NULL, NULL); }

static void test_operator_conservation(void)
{
    int dim, f;
    for (f = 0; f < 2; ++f)
        for (dim = 1; dim <= 3; ++dim) {
            const sph_av *av = f ? &AV_S : &AV_M;
            ss_cloud s;
            int i, a, st, negative = 0;
            double P[3] = {0, 0, 0}, Pm[3] = {0, 0, 0}, E = 0, Em = 0, K = 0;
            th_begin("%s viscosity, %dD periodic random cloud: reference sum, momentum and energy conserved, "
                     "du/dt >= 0",
                     f ? "signal-velocity" : "Monaghan", dim);
            ss_make(&s, dim, dim == 1 ? 100 : dim == 2 ? 300 : 500, 3, 11 + dim + 5 * f);
            st = sph_artificial_viscosity(&s.ctx, av, sph_view_interleaved(s.v, 3), sph_view_none(),
                                          sph_view_soa(s.c, NULL, NULL), sph_view_none(),
                                          sph_out_interleaved(s.a, 3), sph_out_soa(s.du, NULL, NULL),
                                          sph_out_soa(s.vs, NULL, NULL));
            TH_CHECK(st == SPH_OK, "status %d", st);
            check_against_reference(&s, av);
            for (i = 0; i < s.n; ++i) {
                double e = (double)s.m[i] * s.du[i];
                for (a = 0; a < dim; ++a) {
                    const double p = (double)s.m[i] * s.a[3 * i + a];
                    P[a] += p, Pm[a] += fabs(p);
                    e += p * s.v[3 * i + a];
                    Em += fabs(p * s.v[3 * i + a]);
                    K += p * s.v[3 * i + a];
                }
                E += e, Em += fabs((double)s.m[i] * s.du[i]);
                negative += s.du[i] < 0;
                TH_CHECK(s.vs[i] >= 2 * fmin(5, (double)s.c[i]) - 1e-3, "v_sig %g below the sound speeds", s.vs[i]);
            }
            for (a = 0; a < dim; ++a)
                TH_CHECK(Pm[a] > 0 && fabs(P[a]) <= 64 * TH_EPS * Pm[a], "momentum axis %d: %.3g of %.3g", a, P[a],
                         Pm[a]);
            TH_CHECK(Em > 0 && fabs(E) <= 64 * TH_EPS * Em, "total energy rate %.3g of %.3g", E, Em);
            TH_CHECK(K < 0, "kinetic energy rate %.3g not negative", K);
            TH_CHECK(negative == 0, "%d particles with du/dt < 0", negative);
            ss_free(&s);
            th_end();
        }
}

static void test_galilean(void)
{
    /* A uniform velocity added to every particle changes no v_ij: the same results. */
    ss_cloud s;
    sph_real *a2, *du2;
    int i, st, diff = 0;
    th_begin("Galilean invariance: a uniform drift leaves acceleration and heating unchanged");
    ss_make(&s, 2, 200, 2, 5);
    a2 = ts_vec(3 * s.n), du2 = ts_vec(s.n);
    st = sph_artificial_viscosity(&s.ctx, &AV_M, sph_view_interleaved(s.v, 3), sph_view_none(),
                                  sph_view_soa(s.c, NULL, NULL), sph_view_none(), sph_out_interleaved(s.a, 3),
                                  sph_out_soa(s.du, NULL, NULL), sph_out_soa(NULL, NULL, NULL));
    for (i = 0; i < s.n; ++i) s.v[3 * i] += 8, s.v[3 * i + 1] -= 4; /* exact in binary: the same v_ij bits */
    st |= sph_artificial_viscosity(&s.ctx, &AV_M, sph_view_interleaved(s.v, 3), sph_view_none(),
                                   sph_view_soa(s.c, NULL, NULL), sph_view_none(), sph_out_interleaved(a2, 3),
                                   sph_out_soa(du2, NULL, NULL), sph_out_soa(NULL, NULL, NULL));
    TH_CHECK(st == SPH_OK, "status %d", st);
    for (i = 0; i < 3 * s.n; ++i) diff += fabs((double)a2[i] - s.a[i]) > 1e3 * TH_EPS * (1 + fabs((double)s.a[i]));
    for (i = 0; i < s.n; ++i) diff += fabs((double)du2[i] - s.du[i]) > 1e3 * TH_EPS * (1 + fabs((double)s.du[i]));
    TH_CHECK(diff == 0, "%d values changed", diff);
    free(a2), free(du2);
    ss_free(&s);
    th_end();
}

static void test_av_errors(void)
{
    ss_cloud s;
    sph_av bad = AV_M;
    sph_view v, c;
    sph_out a, none = sph_out_soa(NULL, NULL, NULL);
    th_begin("sph_artificial_viscosity: bad arguments get status codes, nothing written");
    ss_make(&s, 2, 50, 1, 3);
    v = sph_view_interleaved(s.v, 3), c = sph_view_soa(s.c, NULL, NULL), a = sph_out_interleaved(s.a, 3);
    s.a[0] = 12345;
    TH_CHECK(sph_artificial_viscosity(&s.ctx, NULL, v, sph_view_none(), c, sph_view_none(), a, none, none) == SPH_ENULL,
             "av NULL");
    bad.alpha = -1;
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &bad, v, sph_view_none(), c, sph_view_none(), a, none, none) ==
                 SPH_ERANGE, "alpha < 0");
    bad = AV_M, bad.beta = (sph_real)NAN;
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &bad, v, sph_view_none(), c, sph_view_none(), a, none, none) ==
                 SPH_ERANGE, "beta NaN");
    bad = AV_M, bad.form = (sph_av_form)7;
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &bad, v, sph_view_none(), c, sph_view_none(), a, none, none) ==
                 SPH_EOPTION, "form 7");
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &AV_M, v, sph_view_none(), sph_view_none(), sph_view_none(), a, none,
                                      none) == SPH_ENULL, "no sound speeds");
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &AV_M, v, sph_view_none(), c, sph_view_none(), none, none, none) ==
                 SPH_ENULL, "no acceleration output");
    s.ctx.rho = sph_view_none();
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &AV_M, v, sph_view_none(), c, sph_view_none(), a, none, none) ==
                 SPH_ENULL, "no densities");
    s.ctx.rho = sph_view_soa(s.rho, NULL, NULL);
    s.c[3] = (sph_real)INFINITY;
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &AV_M, v, sph_view_none(), c, sph_view_none(), a, none, none) ==
                 SPH_ENONFINITE, "Inf sound speed");
    TH_CHECK(s.a[0] == 12345, "output written on failure");
    ss_free(&s);
    th_end();
}

static void test_empty_targets(void)
{
    /* a target whose list is empty gets zeros; no target at all writes nothing */
    const sph_off off[3] = {0, 0, 2};
    const sph_idx idx[2] = {0, 1};
    sph_neighbours list = SPH_NEIGHBOURS_INIT(2, 2, off, idx);
    sph_real x[6] = {0, 0, 0, (sph_real)0.5, 0, 0}, v[6] = {1, 0, 0, -1, 0, 0}, m[2] = {1, 1}, rho[2] = {1, 1};
    sph_real c[2] = {1, 1}, a[6] = {7, 7, 7, 7, 7, 7}, du[2] = {7, 7}, vs[2] = {7, 7};
    sph_ctx ctx = sph_ctx_init(SPH_KERNEL_CUBIC, 3, 1, &list, sph_view_interleaved(x, 3));
    int st;
    th_begin("sph_artificial_viscosity: an empty list gives zeros, no targets write nothing");
    ctx.m = sph_view_soa(m, NULL, NULL), ctx.rho = sph_view_soa(rho, NULL, NULL);
    st = sph_artificial_viscosity(&ctx, &AV_S, sph_view_interleaved(v, 3), sph_view_none(), sph_view_soa(c, NULL, NULL),
                                  sph_view_none(), sph_out_interleaved(a, 3), sph_out_soa(du, NULL, NULL),
                                  sph_out_soa(vs, NULL, NULL));
    TH_CHECK(st == SPH_OK, "status %d", st);
    TH_CHECK(a[0] == 0 && a[1] == 0 && a[2] == 0 && du[0] == 0 && vs[0] == 0, "empty target: %g %g %g", a[0], du[0],
             vs[0]);
    TH_CHECK(a[3] > 0 && du[1] > 0 && vs[1] > 2, "approaching pair: a %g, du %g, v_sig %g", a[3], du[1], vs[1]);
    list.n_targets = 0;
    a[0] = 7;
    st = sph_artificial_viscosity(&ctx, &AV_S, sph_view_interleaved(v, 3), sph_view_none(), sph_view_soa(c, NULL, NULL),
                                  sph_view_none(), sph_out_interleaved(a, 3), sph_out_soa(du, NULL, NULL),
                                  sph_out_soa(vs, NULL, NULL));
    TH_CHECK(st == SPH_OK && a[0] == 7, "no targets: status %d, a %g", st, a[0]);
    th_end();
}

/* Per-particle alpha and Balsara factor (S14): all alphas equal and B = 1 give the scalar result bit for bit;
 * different ones the pair sum with alpha_ij, momentum and energy still conserved (alpha_ij is symmetric). */
static void test_alpha_per_particle(void)
{
    int f, dim, i, a;
    for (f = 0; f < 2; ++f)
        for (dim = 1; dim <= 3; ++dim) {
            ss_cloud s;
            sph_av av = f ? AV_S : AV_M;
            const sph_view none = sph_view_none();
            sph_view v;
            sph_real *a0, *du0, *vs0, *al, *B;
            tp_rng g;
            int st, diff = 0;
            double P[3] = {0, 0, 0}, Pm[3] = {0, 0, 0}, E = 0, Em = 0;
            th_begin("%s viscosity, %dD: per-particle alpha all equal = the scalar alpha bit for bit; alpha_i, B_i "
                     "random: the pair sum with alpha_ij, momentum and energy conserved",
                     f ? "signal-velocity" : "Monaghan", dim);
            ss_make(&s, dim, dim == 1 ? 80 : dim == 2 ? 200 : 343, 3, 31 + dim + 7 * f);
            g.s = 5 + (uint64_t)dim;
            v = sph_view_interleaved(s.v, 3);
            a0 = ts_vec(3 * s.n), du0 = ts_vec(s.n), vs0 = ts_vec(s.n), al = ts_vec(s.n), B = ts_vec(s.n);
            av.alpha = (sph_real)0.7;
            st = sph_artificial_viscosity(&s.ctx, &av, v, none, sph_view_soa(s.c, NULL, NULL), none,
                                          sph_out_interleaved(a0, 3), sph_out_soa(du0, NULL, NULL),
                                          sph_out_soa(vs0, NULL, NULL));
            for (i = 0; i < s.n; ++i) al[i] = (sph_real)0.7, B[i] = 1;
            av.alpha = 3; /* unused where the views are given */
            av.alpha_source = sph_view_soa(al, NULL, NULL), av.balsara_source = sph_view_soa(B, NULL, NULL);
            st |= sph_artificial_viscosity(&s.ctx, &av, v, none, sph_view_soa(s.c, NULL, NULL), none,
                                           sph_out_interleaved(s.a, 3), sph_out_soa(s.du, NULL, NULL),
                                           sph_out_soa(s.vs, NULL, NULL));
            TH_CHECK(st == SPH_OK, "status %d", st);
            for (i = 0; i < s.n; ++i) {
                diff += s.du[i] != du0[i] || s.vs[i] != vs0[i];
                for (a = 0; a < dim; ++a) diff += s.a[3 * i + a] != a0[3 * i + a];
            }
            TH_CHECK(diff == 0, "%d values differ from the scalar alpha's", diff);
            for (i = 0; i < s.n; ++i) al[i] = (sph_real)tp_range(&g, 0, 2), B[i] = (sph_real)tp_range(&g, 0, 1);
            st = sph_artificial_viscosity(&s.ctx, &av, v, none, sph_view_soa(s.c, NULL, NULL), none,
                                          sph_out_interleaved(s.a, 3), sph_out_soa(s.du, NULL, NULL),
                                          sph_out_soa(s.vs, NULL, NULL));
            TH_CHECK(st == SPH_OK, "status %d", st);
            check_against_reference_ab(&s, &av, al, B);
            for (i = 0; i < s.n; ++i) {
                double e = (double)s.m[i] * s.du[i];
                for (a = 0; a < dim; ++a) {
                    const double p = (double)s.m[i] * s.a[3 * i + a];
                    P[a] += p, Pm[a] += fabs(p), e += p * s.v[3 * i + a], Em += fabs(p * s.v[3 * i + a]);
                }
                E += e, Em += fabs((double)s.m[i] * s.du[i]);
            }
            for (a = 0; a < dim; ++a)
                TH_CHECK(fabs(P[a]) <= 64 * TH_EPS * Pm[a], "momentum axis %d: %.3g of %.3g", a, P[a], Pm[a]);
            TH_CHECK(fabs(E) <= 64 * TH_EPS * Em, "total energy rate %.3g of %.3g", E, Em);
            av.balsara_source = none; /* alpha alone: B = 1 */
            st = sph_artificial_viscosity(&s.ctx, &av, v, none, sph_view_soa(s.c, NULL, NULL), none,
                                          sph_out_interleaved(s.a, 3), sph_out_soa(s.du, NULL, NULL),
                                          sph_out_soa(NULL, NULL, NULL));
            TH_CHECK(st == SPH_OK, "status %d", st);
            check_against_reference_ab(&s, &av, al, NULL);
            av.alpha_source = none, av.balsara_source = sph_view_soa(B, NULL, NULL); /* B alone: the scalar alpha */
            st = sph_artificial_viscosity(&s.ctx, &av, v, none, sph_view_soa(s.c, NULL, NULL), none,
                                          sph_out_interleaved(s.a, 3), sph_out_soa(s.du, NULL, NULL),
                                          sph_out_soa(NULL, NULL, NULL));
            TH_CHECK(st == SPH_OK, "status %d", st);
            check_against_reference_ab(&s, &av, NULL, B);
            free(a0), free(du0), free(vs0), free(al), free(B);
            ss_free(&s);
            th_end();
        }
}

static void test_alpha_errors(void)
{
    ss_cloud s;
    sph_av av = AV_S;
    sph_real *al, *xt;
    sph_view v, c;
    sph_out a, none = sph_out_soa(NULL, NULL, NULL);
    int i;
    th_begin("sph_artificial_viscosity: a per-particle alpha or B negative, NaN, or without the targets' view, gets "
             "a status code, nothing written");
    ss_make(&s, 2, 50, 1, 3);
    al = ts_vec(s.n), xt = ts_vec(3 * s.n);
    for (i = 0; i < s.n; ++i) al[i] = 1;
    v = sph_view_interleaved(s.v, 3), c = sph_view_soa(s.c, NULL, NULL), a = sph_out_interleaved(s.a, 3);
    s.a[0] = 12345;
    av.alpha_source = sph_view_soa(al, NULL, NULL);
    al[7] = -1;
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &av, v, sph_view_none(), c, sph_view_none(), a, none, none) ==
                 SPH_EVALUE, "alpha < 0");
    al[7] = (sph_real)NAN;
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &av, v, sph_view_none(), c, sph_view_none(), a, none, none) ==
                 SPH_ENONFINITE, "alpha NaN");
    al[7] = 1;
    av.alpha_source = sph_view_none(), av.balsara_source = sph_view_soa(al, NULL, NULL);
    al[3] = -2;
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &av, v, sph_view_none(), c, sph_view_none(), a, none, none) ==
                 SPH_EVALUE, "B < 0");
    al[3] = 1;
    av.alpha_source = av.balsara_source = sph_view_soa(al, NULL, NULL);
    memcpy(xt, s.x, sizeof(sph_real) * 3 * (size_t)s.n);
    s.ctx.x_target = sph_view_interleaved(xt, 3), s.ctx.h_target = sph_view_soa(s.h, NULL, NULL);
    s.ctx.rho_target = sph_view_soa(s.rho, NULL, NULL);
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &av, v, v, c, c, a, none, none) == SPH_ENULL,
             "targets of their own, no alpha_target");
    av.alpha_target = sph_view_soa(al, NULL, NULL);
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &av, v, v, c, c, a, none, none) == SPH_ENULL,
             "targets of their own, no balsara_target");
    TH_CHECK(s.a[0] == 12345, "output written on failure");
    av.balsara_target = sph_view_soa(al, NULL, NULL);
    TH_CHECK(sph_artificial_viscosity(&s.ctx, &av, v, v, c, c, a, none, none) == SPH_OK, "targets' views given");
    free(al), free(xt);
    ss_free(&s);
    th_end();
}

int main(void)
{
    AV_M = sph_av_init(SPH_AV_MONAGHAN, 1, 2);
    AV_S = sph_av_init(SPH_AV_SIGNAL, 1, 3);
    test_empty_targets();
    test_pair_values();
    test_random_pairs();
    test_operator_conservation();
    test_galilean();
    test_av_errors();
    test_alpha_per_particle();
    test_alpha_errors();
    return th_summary();
}
