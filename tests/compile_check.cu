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
             sph_kernel_dwdr(k, 1, r, 1) + sph_kernel_support(k) + sph_kernel_w(k, 3, r, 1) + sph_kernel_f(k, 3, r, 1) +
             sph_kernel_alpha(k, 3) + sph_kernel_sigma(k, 2) + sph_kernel_neighbours(k, 3, 1, 1) +
             sph_kernel_h_for_neighbours(k, 3, 50, 1) + sph_kernel_check(k, 3) + sph_check_h(1);
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
    // the switches of the viscosity and conductivity, per particle
    sph_switch s = sph_switch_default();
    out[i] += sph_pair_av_alpha(1, 2, sph_switch_balsara(-1, 1, 1, 1), 1) + sph_switch_mm97(&s, 1, -1, 1, 1) +
              sph_switch_sphenix(&s, 1, -1, -1, 1, 1, 1) + sph_switch_conductivity(&s, 0, 1, 1, 2, 1, 1, 1);
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

// The device example of README.md ("CUDA"), verbatim: the section-5 pair
// terms over a CSR list built on the host, one thread per target.
__global__ void density(const sph_real *x, const sph_real *m, const sph_off *offset, const sph_idx *index,
                        sph_idx n, sph_real h, sph_real *rho)
{
    const sph_idx i = blockIdx.x * blockDim.x + threadIdx.x;
    sph_real s = 0;
    if (i >= n) return;
    for (sph_off k = offset[i]; k < offset[i + 1]; ++k) {
        const sph_idx j = index[k];
        const sph_real dx[3] = {x[3 * i] - x[3 * j], x[3 * i + 1] - x[3 * j + 1], x[3 * i + 2] - x[3 * j + 2]};
        const sph_pair p = sph_pair_kernel(SPH_KERNEL_WENDLAND_C2, 3, dx, h);
        s += sph_pair_density(m[j], p.W);
    }
    rho[i] = s;
}

// The rest of sections 4 and 5 in device code: minimum image, views, pair terms.
__global__ void eval_pair_terms(sph_real *out, int n)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 0, 0}};
    sph_real dx[3] = {sph_box_delta(&box, 0, sph_real(0.01) * i - sph_real(0.9)), sph_real(0.1), 0};
    sph_real f[3] = {1, 2, 3}, acc[3] = {0, 0, 0}, M[9] = {0}, B[9];
    const sph_view v = sph_view_soa(f, f + 1, f + 2), vi = sph_view_interleaved(f, 3), va = sph_view_aos(f, 3, sizeof f);
    const sph_out o = sph_out_soa(out, NULL, NULL), oi = sph_out_interleaved(out, 1), oa = sph_out_aos(out, 1, sizeof *out);
    const sph_pair p = sph_pair_kernel(SPH_KERNEL_CUBIC, 3, dx, 1);
    sph_pair_grad_standard(3, 1, 1, p.F, dx, acc);
    sph_pair_grad_difference(3, 1, 1, 2, p.F, dx, acc);
    sph_pair_grad_symmetric(3, 1, 1, 2, p.F, dx, acc);
    sph_pair_grad_pressure(3, 1, sph_pressure_factor(1, 1), sph_pressure_factor(2, 1), p.F, dx, acc);
    sph_pair_curl(3, 1, f, p.F, dx, acc);
    sph_pair_correction(3, 1, p.F, dx, M);
    sph_correction_invert(3, M, sph_real(1e-3), B);
    o.p[0][0] = oi.p[0][0] + oa.p[0][0];
    out[i] = acc[0] + B[0] + v.p[1][0] + vi.p[2][0] + va.p[0][0] + sph_pair_interpolate(1, 2, p.W) + sph_pair_div_standard(3, 1, f, p.F, dx) +
             sph_pair_div_difference(3, 1, f, f, p.F, dx) + sph_pair_laplacian(1, 1, 2, p.F) +
             sph_pair_diffusion(1, sph_harmonic_k(1, 2), 1, 2, p.F);
}

int host_side(void) { return sph_kernel_w(SPH_KERNEL_CUBIC, 3, 0.5, 1) > 0 ? 0 : 1; }

// Host code of a CUDA translation unit builds neighbour lists and runs an
// operator through the same header.
int host_operators(void) { return cc_host_density(); }
