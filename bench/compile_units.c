/* bench/compile_units.c - the translation units whose compile cost
 * bench/compile_cost.sh prints (CPU seconds, peak memory, .text bytes).
 * COST_UNIT selects one:
 *   1  scalar kernels only: W, F and grad W of a run-time kernel
 *   2  pair terms only: a solver's own loop over sph_pair_kernel and the
 *      section-5 terms (density, pressure force, Laplacian)
 *   3  a small 3-D WCSPH step: neighbour search, density, pressure-form
 *      gradient, viscous Laplacian (three array operators)
 *   4  every array operator once, and the neighbour search
 *   5  the solver level: section 8's artificial viscosity, viscosity,
 *      density diffusion, Adami walls and time step, and section 9's
 *      h solve, grad-h forces in gather and pair-once form
 * Kernel and dimension are run-time arguments unless the build pins them
 * with SPH_KERNEL / SPH_DIM. Nothing here is run. */
#include "sph_kernel.h"

#if COST_UNIT == 1
sph_real cost_unit(sph_kernel k, int dim, sph_real r, sph_real h, const sph_real *dx, sph_real *g);
sph_real cost_unit(sph_kernel k, int dim, sph_real r, sph_real h, const sph_real *dx, sph_real *g)
{
    sph_real W, F;
    sph_kernel_wf(k, dim, r, h, &W, &F);
    sph_kernel_grad(k, dim, dx, h, g);
    return W + F + sph_kernel_dwdh(k, dim, r, h);
}
#elif COST_UNIT == 2
/* rho_i, the pressure acceleration and the Laplacian of f, written by the caller */
void cost_unit(sph_kernel k, int dim, sph_real h, sph_idx n, const sph_real *x, const sph_real *m, const sph_real *rho,
               const sph_real *p, const sph_real *f, const sph_off *off, const sph_idx *idx, sph_real *rho_out,
               sph_real *acc, sph_real *lap);
void cost_unit(sph_kernel k, int dim, sph_real h, sph_idx n, const sph_real *x, const sph_real *m, const sph_real *rho,
               const sph_real *p, const sph_real *f, const sph_off *off, const sph_idx *idx, sph_real *rho_out,
               sph_real *acc, sph_real *lap)
{
    sph_idx i;
    for (i = 0; i < n; ++i) {
        const sph_real Pi = sph_pressure_factor(p[i], rho[i]);
        sph_real r = 0, a[3] = {0, 0, 0}, l = 0;
        sph_off o;
        for (o = off[i]; o < off[i + 1]; ++o) {
            const sph_idx j = idx[o];
            sph_real dx[3] = {0, 0, 0};
            sph_pair P;
            int c;
            for (c = 0; c < dim; ++c) dx[c] = x[3 * i + c] - x[3 * j + c];
            P = sph_pair_kernel(k, dim, dx, h);
            r += sph_pair_density(m[j], P.W);
            sph_pair_grad_pressure(dim, m[j], Pi, sph_pressure_factor(p[j], rho[j]), P.F, dx, a);
            l += sph_pair_laplacian(m[j] / rho[j], f[i], f[j], P.F);
        }
        rho_out[i] = r;
        acc[3 * i] = -a[0], acc[3 * i + 1] = -a[1], acc[3 * i + 2] = -a[2];
        lap[i] = l;
    }
}
#elif COST_UNIT == 3
/* One step's right-hand side of a 3-D weakly compressible solver. */
int cost_unit(sph_kernel k, sph_real h, sph_idx n, const sph_real *x, const sph_real *m, const sph_real *v,
              sph_real *rho, sph_real *p, sph_real *acc, sph_real *lap, void *work, size_t work_bytes, sph_off *off,
              sph_idx *idx, sph_off capacity);
int cost_unit(sph_kernel k, sph_real h, sph_idx n, const sph_real *x, const sph_real *m, const sph_real *v,
              sph_real *rho, sph_real *p, sph_real *acc, sph_real *lap, void *work, size_t work_bytes, sph_off *off,
              sph_idx *idx, sph_off capacity)
{
    const sph_view xv = sph_view_interleaved(x, 3);
    const sph_real kappa = sph_kernel_support(k);
    sph_nsearch g;
    sph_neighbours L;
    sph_ctx c;
    sph_idx i;
    int st = sph_nsearch_build(&g, 3, xv, n, sph_view_none(), kappa * h, NULL, work, work_bytes);
    if (st == SPH_OK) st = sph_nsearch_lists(&g, xv, n, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, off, idx, capacity, NULL);
    if (st != SPH_OK) return st;
    L = sph_nsearch_list(&g, n, off, idx);
    c = sph_ctx_init(k, 3, h, &L, xv);
    c.m = sph_view_soa(m, NULL, NULL);
    if ((st = sph_density(&c, sph_out_soa(rho, NULL, NULL))) != SPH_OK) return st;
    for (i = 0; i < n; ++i) p[i] = 100 * (rho[i] - 1000); /* linear equation of state */
    c.rho = sph_view_soa(rho, NULL, NULL);
    st = sph_gradient(&c, SPH_SCHEME_PRESSURE, sph_view_soa(p, NULL, NULL), sph_view_none(), sph_out_interleaved(acc, 3), NULL);
    c.V = c.m; /* volumes m / rho would be set here */
    if (st == SPH_OK) st = sph_laplacian(&c, sph_view_soa(v, NULL, NULL), sph_view_none(), sph_out_soa(lap, NULL, NULL));
    return st;
}
#elif COST_UNIT == 4
int cost_unit(sph_kernel k, int dim, sph_real h, sph_idx n, const sph_real *x, const sph_real *m, const sph_real *V,
              const sph_real *f, sph_real *out, sph_real *T, void *work, size_t work_bytes, sph_off *off, sph_idx *idx,
              sph_off capacity);
int cost_unit(sph_kernel k, int dim, sph_real h, sph_idx n, const sph_real *x, const sph_real *m, const sph_real *V,
              const sph_real *f, sph_real *out, sph_real *T, void *work, size_t work_bytes, sph_off *off, sph_idx *idx,
              sph_off capacity)
{
    const sph_view xv = sph_view_interleaved(x, dim), fv = sph_view_soa(f, NULL, NULL), none = sph_view_none();
    const sph_out o1 = sph_out_soa(out, NULL, NULL), o3 = sph_out_interleaved(out, dim);
    const sph_real kappa = sph_kernel_support(k);
    sph_nsearch g;
    sph_neighbours L;
    sph_ctx c;
    sph_idx nf = 0;
    int st = sph_nsearch_build(&g, dim, xv, n, none, kappa * h, NULL, work, work_bytes);
    if (st == SPH_OK) st = sph_nsearch_lists(&g, xv, n, none, h, kappa, SPH_NSEARCH_GATHER, off, idx, capacity, NULL);
    if (st != SPH_OK) return st;
    L = sph_nsearch_list(&g, n, off, idx);
    c = sph_ctx_init(k, dim, h, &L, xv);
    c.m = sph_view_soa(m, NULL, NULL);
    c.V = sph_view_soa(V, NULL, NULL);
    st |= sph_density(&c, o1);
    st |= sph_interpolate(&c, fv, o1);
    st |= sph_interpolate_shepard(&c, fv, o1, &nf);
    st |= sph_gradient(&c, SPH_SCHEME_DIFFERENCE, fv, none, o3, &nf);
    st |= sph_gradient(&c, SPH_SCHEME_CORRECTED, fv, none, o3, &nf);
    st |= sph_density_gradient(&c, fv, none, o1, o3);
    st |= sph_gradient_vector(&c, SPH_SCHEME_DIFFERENCE, xv, none, T, dim * dim, &nf);
    st |= sph_divergence(&c, SPH_SCHEME_DIFFERENCE, xv, none, o1, &nf);
    st |= sph_curl(&c, SPH_SCHEME_DIFFERENCE, xv, none, o3);
    st |= sph_laplacian(&c, fv, none, o1);
    st |= sph_diffusion(&c, fv, none, fv, none, o1);
    st |= sph_correction_matrix(&c, T, dim * dim, &nf);
    return st;
}
#elif COST_UNIT == 5
int cost_unit(sph_kernel k, int dim, const sph_neighbours *L, const sph_real *x, const sph_real *m, sph_real *rho,
              sph_real *h, sph_real *om, const sph_real *v, const sph_real *cs, const sph_real *A, sph_real *acc,
              sph_real *out, sph_real *buf, sph_off *off, sph_idx *idx, sph_off cap, sph_off *t_off, sph_off *t_slot);
int cost_unit(sph_kernel k, int dim, const sph_neighbours *L, const sph_real *x, const sph_real *m, sph_real *rho,
              sph_real *h, sph_real *om, const sph_real *v, const sph_real *cs, const sph_real *A, sph_real *acc,
              sph_real *out, sph_real *buf, sph_off *off, sph_idx *idx, sph_off cap, sph_off *t_off, sph_off *t_slot)
{
    const sph_view xv = sph_view_interleaved(x, dim), vv = sph_view_interleaved(v, dim), none = sph_view_none();
    const sph_view sv = sph_view_soa(cs, NULL, NULL);
    const sph_out o1 = sph_out_soa(out, NULL, NULL), o3 = sph_out_interleaved(acc, dim);
    const sph_real g[3] = {0, -9.81, 0};
    const sph_av av = sph_av_init(SPH_AV_SIGNAL, 1, 3);
    const sph_wall w = sph_wall_init(dim, g);
    sph_hctx hc = sph_hctx_init(k, dim, L, xv, sph_view_soa(m, NULL, NULL), 0);
    sph_ctx c = sph_ctx_init(k, dim, h[0], L, xv);
    sph_dt_input in = sph_dt_input_init(h[0]);
    sph_hreport rep;
    sph_pairs P;
    sph_off pairs;
    sph_real dt;
    sph_idx empty, which;
    int reason, st;
    c.m = sph_view_soa(m, NULL, NULL);
    c.rho = sph_view_soa(rho, NULL, NULL);
    st = sph_h_solve(&hc, sph_out_soa(h, NULL, NULL), sph_out_soa(rho, NULL, NULL), sph_out_soa(om, NULL, NULL), NULL,
                     NULL, &rep);
    st |= sph_gradh_forces(&hc, vv, sph_view_soa(h, NULL, NULL), sph_view_soa(A, NULL, NULL), o3, o1);
    st |= sph_pairs_build(L, off, idx, cap, t_off, t_slot, &pairs, &P);
    st |= sph_gradh_forces_pairs(&hc, &P, vv, sph_view_soa(h, NULL, NULL), sph_view_soa(A, NULL, NULL), buf,
                                 sph_gradh_pairs_buffer_len(dim, cap), o3, o1);
    st |= sph_artificial_viscosity(&c, &av, vv, none, sv, none, o3, o1, o1);
    st |= sph_viscosity(&c, SPH_VISC_KINEMATIC, sv, none, vv, none, o3);
    st |= sph_density_diffusion(&c, 0.1, 10, vv, none, o1);
    st |= sph_wall_adami(&c, &w, sv, vv, o1, o3, &empty);
    in.vsig = sv;
    st |= sph_time_step(&in, dim, L->n_targets, &dt, &reason, &which);
    return st;
}
#else
#error "COST_UNIT 1..5"
#endif
