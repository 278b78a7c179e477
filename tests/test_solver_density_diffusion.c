/* Solver terms: density diffusion (S6), (S7) (delta-SPH), docs/solver.md.
 *
 * Hydrostatic column: a 2-D block of fluid (free surface on every side, no
 * walls) with the hydrostatic density of the linear equation of state p =
 * c0^2 (rho - rho0), rho = rho0 + rho0 g (H - y) / c0^2 (linear in y to
 * first order in g H / c0^2, as Antuono et al. 2010 take it). For a linear
 * density the renormalised gradient (O7) is exact at every particle with an
 * invertible correction matrix, including the surface, so each Antuono pair
 * term 2 (rho_i - rho_j) - (g_i + g_j) . x_ij is 0 and the diffusion
 * vanishes to round-off; the Molteni & Colagrossi form is 2 sum_j V_j a .
 * x_ij F_ij, which cancels in the interior of a lattice but not where the
 * kernel support is cut by the surface: it must be nonzero there, far above
 * the round-off bound (below).
 *
 * Mass: every pair term of (S6) is antisymmetric in i, j (symmetric h_ij, V
 * of the pair), so with V_i the same volumes sum_i V_i drho_i/dt = 0: the
 * diffusion moves density between particles and creates none (closed
 * periodic cloud, random densities and gradients).
 */
#include "solver_scene.h"

enum { NX = 16, NY = 32 };

static void test_hydrostatic(void)
{
    const double rho0 = 1000, g = 9.81, dx = 0.025, H = NY * dx, c0 = 10 * sqrt(g * H), delta = 0.1;
    const int n = NX * NY;
    sph_real *x = ts_vec(3 * n), *rho = ts_vec(n), *m = ts_vec(n), *V = ts_vec(n), *grad = ts_vec(3 * n);
    sph_real *Da = ts_vec(n), *Dm = ts_vec(n), *lap = ts_vec(n);
    tp_list L;
    sph_ctx c;
    double amax = 0, mmax = 0, tol = 0, lapdiff = 0;
    const double h = 1.3 * dx;
    sph_idx nfb = -1;
    int i, st;
    th_begin("(S7) hydrostatic 2D column: Antuono form 0 to round-off, Molteni-Colagrossi form not");
    for (i = 0; i < n; ++i) {
        x[3 * i] = (sph_real)((i % NX + 0.5) * dx);
        x[3 * i + 1] = (sph_real)((i / NX + 0.5) * dx);
        rho[i] = (sph_real)(rho0 + rho0 * g * (H - x[3 * i + 1]) / (c0 * c0));
        m[i] = (sph_real)(rho0 * dx * dx);
        V[i] = m[i] / rho[i];
    }
    tp_brute_list(2, x, n, x, n, (sph_real)h, NULL, NULL, 2, TP_GATHER, NULL, &L);
    c = sph_ctx_init(SPH_KERNEL_CUBIC, 2, (sph_real)h, &L.list, sph_view_interleaved(x, 3));
    c.V = sph_view_soa(V, NULL, NULL);
    c.rho = sph_view_soa(rho, NULL, NULL);
    st = sph_gradient(&c, SPH_SCHEME_CORRECTED, sph_view_soa(rho, NULL, NULL), sph_view_none(),
                      sph_out_interleaved(grad, 3), &nfb);
    st |= sph_density_diffusion(&c, (sph_real)delta, (sph_real)c0, sph_view_interleaved(grad, 3), sph_view_none(),
                                sph_out_soa(Da, NULL, NULL));
    st |= sph_density_diffusion(&c, (sph_real)delta, (sph_real)c0, sph_view_none(), sph_view_none(),
                                sph_out_soa(Dm, NULL, NULL));
    st |= sph_laplacian(&c, sph_view_soa(rho, NULL, NULL), sph_view_none(), sph_out_soa(lap, NULL, NULL));
    TH_CHECK(st == SPH_OK && nfb == 0, "status %d, %d fallbacks", st, (int)nfb);
    for (i = 0; i < n; ++i) {
        /* round-off bound: delta c0 h sum_j |V_j F_ij| times 64 eps (2 |rho_i - rho_j| + |g_i + g_j| r_ij)
         * (the arithmetic) plus 2 eps (|rho_i| + |rho_j|) (the densities rounded to sph_real are linear
         * in y only to their last bit) */
        double b = 0;
        sph_off o;
        for (o = L.offset[i]; o < L.offset[i + 1]; ++o) {
            const int j = L.index[o];
            const double r = sqrt(tp_r2(2, x + 3 * i, x + 3 * j, NULL));
            const double F = (double)sph_kernel_f(SPH_KERNEL_CUBIC, 2, (sph_real)r, (sph_real)h);
            b += fabs((double)V[j] * F) * (64 * (2 * fabs((double)rho[i] - rho[j]) + 2 * rho0 * g / (c0 * c0) * 2 * r) +
                                           2 * ((double)rho[i] + rho[j]));
        }
        tol = fmax(tol, TH_EPS * delta * c0 * h * b);
        amax = fmax(amax, fabs((double)Da[i]));
        mmax = fmax(mmax, fabs((double)Dm[i]));
        lapdiff = fmax(lapdiff, fabs((double)Dm[i] - delta * c0 * h * lap[i]));
    }
    printf("    max |D| Antuono %.3g, Molteni-Colagrossi %.3g, round-off bound %.3g (rho0 = %g, c0 = %.3g)\n", amax,
           mmax, tol, rho0, c0);
    TH_CHECK(amax <= tol, "Antuono form %.3g above the round-off bound %.3g", amax, tol);
    TH_CHECK(mmax > 20 * tol, "Molteni-Colagrossi form %.3g not above the bound %.3g", mmax, tol);
    TH_CHECK(lapdiff <= tol, "Molteni-Colagrossi form differs from delta c0 h (O12) by %.3g", lapdiff);
    tp_free_list(&L);
    free(x), free(rho), free(m), free(V), free(grad), free(Da), free(Dm), free(lap);
    th_end();
}

static void test_mass(void)
{
    int dim, form;
    for (dim = 1; dim <= 3; ++dim)
        for (form = 0; form < 2; ++form) {
            ss_cloud s;
            tp_rng g;
            sph_real *gr = NULL, *D = NULL;
            double tot = 0, mag = 0;
            int i, st;
            th_begin("(S7) %dD periodic random cloud, %s form: sum_i V_i drho_i/dt = 0", dim,
                     form ? "Antuono" : "Molteni-Colagrossi");
            g.s = 99 + dim;
            ss_make(&s, dim, dim == 1 ? 100 : dim == 2 ? 300 : 500, 1, 60 + dim);
            gr = ts_vec(3 * s.n), D = ts_vec(s.n);
            for (i = 0; i < 3 * s.n; ++i) gr[i] = (sph_real)tp_range(&g, -3000, 3000);
            st = sph_density_diffusion(&s.ctx, (sph_real)0.1, 20, form ? sph_view_interleaved(gr, 3) : sph_view_none(),
                                       sph_view_none(), sph_out_soa(D, NULL, NULL));
            TH_CHECK(st == SPH_OK, "status %d", st);
            for (i = 0; i < s.n; ++i) tot += (double)s.V[i] * D[i], mag += fabs((double)s.V[i] * D[i]);
            TH_CHECK(mag > 0 && fabs(tot) <= 64 * TH_EPS * mag, "total %.3g of %.3g", tot, mag);
            free(gr), free(D);
            ss_free(&s);
            th_end();
        }
}

static void test_dd_pair_and_errors(void)
{
    const sph_real dx[2] = {(sph_real)0.5, -1}, gi[2] = {2, 4}, gj[2] = {6, -2};
    ss_cloud s;
    sph_out o;
    th_begin("(S6) pair value by hand; status codes of sph_density_diffusion");
    /* V F [2 (rho_i - rho_j) - (g_i + g_j) . x_ij] = 0.5 (-3) [2 (-1) - (8 0.5 + 2 (-1))] = 6 */
    TH_NEAR(sph_pair_density_diffusion(2, (sph_real)0.5, 10, 11, gi, gj, -3, dx), 6, 8 * TH_EPS);
    TH_NEAR(sph_pair_density_diffusion(2, (sph_real)0.5, 10, 11, NULL, gj, -3, dx), 3, 8 * TH_EPS);
    ss_make(&s, 2, 50, 1, 2);
    o = sph_out_soa(s.du, NULL, NULL);
    TH_CHECK(sph_density_diffusion(&s.ctx, -1, 1, sph_view_none(), sph_view_none(), o) == SPH_ERANGE, "delta < 0");
    TH_CHECK(sph_density_diffusion(&s.ctx, 1, (sph_real)INFINITY, sph_view_none(), sph_view_none(), o) == SPH_ERANGE,
             "c0 Inf");
    TH_CHECK(sph_density_diffusion(&s.ctx, 1, 1, sph_view_none(), sph_view_none(), sph_out_soa(NULL, NULL, NULL)) ==
                 SPH_ENULL, "no output");
    s.rho[4] = -1;
    TH_CHECK(sph_density_diffusion(&s.ctx, 1, 1, sph_view_none(), sph_view_none(), o) == SPH_EVALUE,
             "negative density");
    ss_free(&s);
    th_end();
}

int main(void)
{
    test_hydrostatic();
    test_mass();
    test_dd_pair_and_errors();
    return th_summary();
}
