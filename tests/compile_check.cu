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

// The solver pair terms (section 8) in device code.
__global__ void eval_solver_terms(sph_real *out, int n)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    sph_real dx[3] = {sph_real(0.01) * i + 1, 0, 0}, dv[3] = {-1, 0, 0}, acc[3] = {0, 0, 0};
    sph_real Pi = sph_pair_av_monaghan(3, 1, 2, 1, 1, 1, dx, dv) + sph_pair_av_signal(3, 1, 3, 1, 1, 1, dx, dv);
    sph_real sum[5] = {0, 0, 0, 0, 0}, pw, vw[3];
    sph_dt_coef k = sph_dt_coef_default();
    int why;
    out[i] = sph_pair_av_apply(3, 1, Pi, -1, dx, dv, acc) + acc[0] + sph_pair_signal_velocity(3, 3, 1, 1, dx, dv);
    sph_pair_viscosity(3, 1, 1, 1, 1, 1, 1, -1, dx, dv, acc);
    sph_pair_wall(3, 1, 1, 1, dv, dv, dx, sum);
    out[i] += acc[0] + sph_pair_density_diffusion(3, 1, 1, 2, dx, dv, -1, dx) + sph_wall_end(3, SPH_WALL_NOSLIP, sum, dv, &pw, vw) +
              pw + sph_dt_limit(&k, 1, 1, 1, 1, 1, &why);
}

// The grad-h pair terms (section 9) in device code.
__global__ void eval_gradh_terms(sph_real *out, int n)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    sph_real dx[3] = {sph_real(0.01) * i + 1, 0, 0}, dv[3] = {-1, 0, 0}, acc[3] = {0, 0, 0};
    const sph_real A = sph_gradh_factor(1, 1, sph_real(0.9));
    sph_pair_gradh_pressure(3, 1, A, A, -1, -1, dx, acc);
    out[i] = acc[0] + sph_pair_gradh_energy(3, 1, A, -1, dv, dx);
}

int host_side(void) { return sph_kernel_w(SPH_KERNEL_CUBIC, 3, 0.5, 1) > 0 ? 0 : 1; }

// Host code of a CUDA translation unit builds neighbour lists and runs an
// operator through the same header.
int host_operators(void) { return cc_host_density(); }
