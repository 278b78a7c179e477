/* Solver terms: the viscosity operator (S5) (Morris, Fox & Zhu 1997),
 * docs/solver.md.
 *
 * Analytic field: v = (sin 2 pi y, 0) on a periodic 2-D lattice, rho = 1,
 * mu = 1, whose viscous acceleration is lap v = (-(2 pi)^2 sin 2 pi y, 0).
 * On a lattice the operator is exactly 2 sum_j V (1 - cos k y_ij) F_ij g_ij
 * sin k y_i (g = r^2 / (r^2 + 0.01 h^2), the sine part cancels by symmetry),
 * which tends to -k^2 mu_eta sin k y_i with error O((k h)^2) as the lattice
 * is refined at fixed h / dx: mu_eta = -sum over offsets of dx^2 F g
 * (n_y dx)^2 is the lattice's second moment with Morris' regularisation,
 * computed below from the scalar kernel function alone (no operator; 1 for
 * the continuous kernel without eta, tp_lattice_moment). So the test checks
 * the field against -k^2 mu_eta sin k y at three resolutions, an error
 * ratio of ~4 per halving (order 2), and mu_eta within 2 % of 1 (the
 * regularisation's own bias). Conservation: the pair term is symmetric in
 * i, j times v_ij, so sum_i m_i a_i = 0 and sum_i m_i v_i . a_i =
 * -(1/2) sum_ij (...) |v_ij|^2 F <= 0 (viscosity only dissipates).
 */
#include "solver_scene.h"

/* mu_eta of a 2-D lattice of spacing dx for kernel k at h (see above). */
static double lattice_moment_eta(sph_kernel k, double dx, double h)
{
    const int K = (int)ceil((double)sph_kernel_support(k) * h / dx) + 1;
    double s = 0;
    int a, b;
    for (a = -K; a <= K; ++a)
        for (b = -K; b <= K; ++b) {
            const double r2 = (a * a + b * b) * dx * dx;
            if (a == 0 && b == 0) continue;
            s -= dx * dx * (double)sph_kernel_f(k, 2, (sph_real)sqrt(r2), (sph_real)h) * (r2 / (r2 + 0.01 * h * h)) *
                 (b * dx) * (b * dx);
        }
    return s;
}

static void test_sine_field(void)
{
    const double k = 2 * TS_PI;
    double err[3] = {0, 0, 0}, mu = 0;
    int r;
    th_begin("(S5) on v = (sin 2 pi y, 0), 2D periodic lattice: -k^2 mu_eta sin k y, order 2");
    for (r = 0; r < 3; ++r) {
        const int N = 16 << r;
        sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}};
        ts_scene s;
        sph_real *v, *m, *rho, *mv, *a;
        int i, st;
        ts_lattice(&s, SPH_KERNEL_QUINTIC, 2, N, 1.0 / N, 1.6, 0, 1, &box);
        v = ts_vec(3 * s.n), m = ts_vec(s.n), rho = ts_vec(s.n), mv = ts_vec(s.n), a = ts_vec(3 * s.n);
        mu = lattice_moment_eta(SPH_KERNEL_QUINTIC, 1.0 / N, s.h);
        for (i = 0; i < s.n; ++i) {
            v[3 * i] = (sph_real)sin(k * s.x[3 * i + 1]);
            m[i] = s.V[i], rho[i] = 1, mv[i] = 1;
        }
        s.c.m = sph_view_soa(m, NULL, NULL), s.c.rho = sph_view_soa(rho, NULL, NULL);
        st = sph_viscosity(&s.c, SPH_VISC_DYNAMIC, sph_view_soa(mv, NULL, NULL), sph_view_none(),
                           sph_view_interleaved(v, 3), sph_view_none(), sph_out_interleaved(a, 3));
        TH_CHECK(st == SPH_OK, "status %d", st);
        for (i = 0; i < s.n; ++i) {
            err[r] = fmax(err[r], fabs((double)a[3 * i] + k * k * mu * sin(k * s.x[3 * i + 1])) / (k * k));
            err[r] = fmax(err[r], fabs((double)a[3 * i + 1]) / (k * k));
        }
        printf("    N = %3d  h = %.4f  mu_eta = %.6f  max |a - (-k^2 mu_eta sin ky)| / k^2 = %.3e\n", N, s.h, mu,
               err[r]);
        ts_free(&s);
        free(v), free(m), free(rho), free(mv), free(a);
    }
    TH_CHECK(err[0] / err[1] > 3.5 && err[1] / err[2] > 3.5, "errors %.3g %.3g %.3g: not order 2", err[0], err[1],
             err[2]);
    TH_CHECK(err[2] < 2e-3, "finest error %.3g", err[2]); /* 1.3e-3 = 0.12 (k h)^2 measured */
    TH_CHECK(fabs(mu - 1) < 0.02, "mu_eta = %.5f", mu);
    th_end();
}

static void test_conservation(void)
{
    int dim, kin;
    for (dim = 1; dim <= 3; ++dim)
        for (kin = 0; kin < 2; ++kin) {
            ss_cloud s;
            sph_real *mu = NULL, *a2 = NULL;
            double P[3] = {0, 0, 0}, Pm[3] = {0, 0, 0}, K = 0, Km = 0, diff = 0, mag = 0;
            int i, a, st;
            th_begin("(S5) %dD periodic random cloud, %s coefficient: momentum conserved, kinetic energy dissipated",
                     dim, kin ? "kinematic" : "dynamic");
            ss_make(&s, dim, dim == 1 ? 100 : dim == 2 ? 300 : 500, 2, 40 + dim);
            mu = ts_vec(s.n), a2 = ts_vec(3 * s.n);
            for (i = 0; i < s.n; ++i) mu[i] = (sph_real)(i % 4 == 0 ? 0.05 : 2.0); /* jumps by 40 */
            st = sph_viscosity(&s.ctx, SPH_VISC_DYNAMIC, sph_view_soa(mu, NULL, NULL), sph_view_none(),
                               sph_view_interleaved(s.v, 3), sph_view_none(), sph_out_interleaved(s.a, 3));
            if (kin) { /* the same viscosity given as nu = mu / rho */
                for (i = 0; i < s.n; ++i) mu[i] /= s.rho[i];
                st |= sph_viscosity(&s.ctx, SPH_VISC_KINEMATIC, sph_view_soa(mu, NULL, NULL), sph_view_none(),
                                    sph_view_interleaved(s.v, 3), sph_view_none(), sph_out_interleaved(a2, 3));
            }
            TH_CHECK(st == SPH_OK, "status %d", st);
            for (i = 0; i < s.n; ++i)
                for (a = 0; a < dim; ++a) {
                    const double p = (double)s.m[i] * s.a[3 * i + a];
                    P[a] += p, Pm[a] += fabs(p);
                    K += p * s.v[3 * i + a], Km += fabs(p * s.v[3 * i + a]);
                    if (kin) diff = fmax(diff, fabs((double)a2[3 * i + a] - s.a[3 * i + a]));
                    mag = fmax(mag, fabs((double)s.a[3 * i + a]));
                }
            for (a = 0; a < dim; ++a)
                TH_CHECK(Pm[a] > 0 && fabs(P[a]) <= 64 * TH_EPS * Pm[a], "momentum axis %d: %.3g of %.3g", a, P[a],
                         Pm[a]);
            TH_CHECK(K < 0 && Km > 0, "kinetic energy rate %.3g", K);
            TH_CHECK(diff <= 64 * TH_EPS * mag, "kinematic differs from dynamic by %.3g of %.3g", diff, mag);
            free(mu), free(a2);
            ss_free(&s);
            th_end();
        }
}

static void test_visc_pair_and_errors(void)
{
    const sph_real dx[3] = {(sph_real)0.3, (sph_real)0.4, 0}, dv[3] = {1, -2, 0};
    sph_real acc[3] = {0, 0, 0};
    ss_cloud s;
    sph_out a;
    sph_view v, mu;
    th_begin("(S5) pair value by hand; status codes of sph_viscosity");
    /* m_j (mu_i + mu_j) / (rho_i rho_j) F r^2 / (r^2 + 0.01 h^2) v_ij: 2 * 3 / 2 * (-5) * 0.25 / 0.26 */
    sph_pair_viscosity(2, 2, 1, 2, 1, 2, 1, -5, dx, dv, acc);
    TH_NEAR(acc[0], -15 * 0.25 / 0.26, 8 * TH_EPS);
    TH_NEAR(acc[1], 30 * 0.25 / 0.26, 8 * TH_EPS);
    acc[0] = 0;
    sph_pair_viscosity(2, 2, 1, 2, 0, 2, 1, -5, dx, dv, acc); /* rho_i = 0: nothing added */
    TH_CHECK(acc[0] == 0, "rho_i = 0 added %g", acc[0]);
    ss_make(&s, 2, 60, 1, 8);
    v = sph_view_interleaved(s.v, 3), mu = sph_view_soa(s.c, NULL, NULL), a = sph_out_interleaved(s.a, 3);
    TH_CHECK(sph_viscosity(&s.ctx, (sph_visc_kind)2, mu, sph_view_none(), v, sph_view_none(), a) == SPH_EOPTION,
             "kind 2");
    TH_CHECK(sph_viscosity(&s.ctx, SPH_VISC_DYNAMIC, sph_view_none(), sph_view_none(), v, sph_view_none(), a) ==
                 SPH_ENULL, "no coefficient");
    s.ctx.m = sph_view_none();
    TH_CHECK(sph_viscosity(&s.ctx, SPH_VISC_DYNAMIC, mu, sph_view_none(), v, sph_view_none(), a) == SPH_ENULL,
             "no masses");
    TH_CHECK(sph_viscosity(NULL, SPH_VISC_DYNAMIC, mu, sph_view_none(), v, sph_view_none(), a) == SPH_ENULL,
             "ctx NULL");
    ss_free(&s);
    th_end();
}

int main(void)
{
    test_sine_field();
    test_conservation();
    test_visc_pair_and_errors();
    return th_summary();
}
