// nvcc compile check: every kernel function is callable from device code.
#include "sph_kernel.h"
#include "compile_check_host.h"

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
int host_operators(void) { return cc_host_density(); }
