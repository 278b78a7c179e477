// tests/compile_check_host.h - host code shared by the C++ and nvcc compile
// checks: build a neighbour list and run the operators as a C++ caller would.
// Returns 0 on success.
#ifndef SPH_COMPILE_CHECK_HOST_H
#define SPH_COMPILE_CHECK_HOST_H
#include "sph_kernel.h"

static int cc_host_density(void)
{
    sph_real x[6] = {0, 0, 0, sph_real(0.5), 0, 0}, m[2] = {1, 1}, rho[2] = {0, 0};
    sph_view xv = sph_view_interleaved(x, 3);
    static unsigned char work[1 << 16];
    size_t bytes = 0;
    sph_nsearch grid;
    sph_off off[3];
    sph_idx idx[4];
    if (sph_nsearch_workspace_size(3, xv, 2, sph_view_none(), 1, NULL, &bytes) != SPH_OK ||
        bytes > sizeof work ||
        sph_nsearch_build(&grid, 3, xv, 2, sph_view_none(), 1, NULL, work, bytes) != SPH_OK ||
        sph_nsearch_count(&grid, xv, 2, sph_view_none(), 1, 2, SPH_NSEARCH_GATHER, off) != SPH_OK ||
        sph_nsearch_fill(&grid, xv, 2, sph_view_none(), 1, 2, SPH_NSEARCH_GATHER, off, idx, 4) != SPH_OK)
        return 1;
    sph_neighbours list = sph_nsearch_list(&grid, 2, off, idx);
    sph_ctx c = sph_ctx_init(SPH_KERNEL_CUBIC, 3, 1, &list, xv);
    c.m = sph_view_soa(m, NULL, NULL);
    if (sph_density(&c, sph_out_soa(rho, NULL, NULL)) != SPH_OK || !(rho[0] > 0)) return 1;
    /* the one-pass density and gradient, a gradient and a Laplacian: the
     * operator loops a caller instantiates (f = x, so grad f_x > 0 at both) */
    sph_real V[2] = {1 / rho[0], 1 / rho[1]}, f[2] = {0, sph_real(0.5)}, g[6] = {0}, lap[2] = {0};
    c.V = sph_view_soa(V, NULL, NULL);
    const sph_view fv = sph_view_soa(f, NULL, NULL);
    if (sph_density_gradient(&c, fv, sph_view_none(), sph_out_soa(rho, NULL, NULL),
                             sph_out_interleaved(g, 3)) != SPH_OK || !(g[0] > 0))
        return 1;
    if (sph_gradient(&c, SPH_SCHEME_DIFFERENCE, fv, sph_view_none(), sph_out_aos(g, 3, 3 * sizeof(sph_real)),
                     NULL) != SPH_OK || !(g[3] > 0))
        return 1;
    if (sph_laplacian(&c, fv, sph_view_none(), sph_out_soa(lap, NULL, NULL)) != SPH_OK) return 1;
    /* per-particle h: the one-pass loops with h_j, and the density sums of sph_h_solve */
    sph_real h[2] = {1, 1}, om[2] = {0, 0};
    c.h_source = sph_view_soa(h, NULL, NULL);
    if (sph_density_gradient(&c, fv, sph_view_none(), sph_out_soa(rho, NULL, NULL),
                             sph_out_interleaved(g, 3)) != SPH_OK || !(g[0] > 0))
        return 1;
    sph_hctx hc = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &list, xv, sph_view_soa(m, NULL, NULL), 1);
    if (sph_h_solve(&hc, sph_out_soa(h, NULL, NULL), sph_out_soa(rho, NULL, NULL), sph_out_soa(om, NULL, NULL), NULL,
                    NULL, NULL) != SPH_OK || !(rho[0] > 0))
        return 1;
    /* a pair batch with F alone and a lane square root: the lane loops a caller instantiates */
    sph_batch_src bs;
    sph_batch b;
    sph_off next = 0;
    if (sph_batch_source(&bs, SPH_KERNEL_CUBIC, 3, &list, NULL, xv, sph_view_soa(h, NULL, NULL)) != SPH_OK ||
        sph_batch_select(&bs, SPH_BATCH_F) != SPH_OK || sph_batch_fill(&bs, 0, &next, &b) != 2)
        return 1;
    sph_batch_sqrt(b.r);
    return b.r[0] + b.r[1] > 0 ? 0 : 1;
}
#endif
