// nvcc compile check: every kernel function is callable from device code.
#include "sph_kernel.h"

__global__ void eval_kernels(sph_real *out, int n)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    sph_kernel k = static_cast<sph_kernel>(i % SPH_KERNEL_COUNT);
    sph_real r = sph_real(0.01) * i, W, F, dx[3] = {r, 0, 0}, g[3];
    sph_kernel_wf(k, 3, r, 1, &W, &F);
    sph_kernel_grad(k, 3, dx, 1, g);
    out[i] = W + F + g[0] + sph_kernel_d2wdr2(k, 2, r, 1) + sph_kernel_dwdh(k, 2, r, 1) +
             sph_kernel_dwdr(k, 1, r, 1) + sph_kernel_support(k);
}

int host_side(void) { return sph_kernel_w(SPH_KERNEL_CUBIC, 3, 0.5, 1) > 0 ? 0 : 1; }

// Host code of a CUDA translation unit builds neighbour lists and runs an
// operator through the same header.
int host_operators(void)
{
    sph_real x[6] = {0, 0, 0, 0.5, 0, 0}, m[2] = {1, 1}, rho[2] = {0, 0};
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
    return sph_density(&c, sph_out_soa(rho, NULL, NULL)) == SPH_OK && rho[0] > 0 ? 0 : 1;
}
