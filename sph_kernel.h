/* sph_kernel.h - Smoothed Particle Hydrodynamics in one C99 header: kernels,
 * operators over neighbour lists, neighbour search, solver terms and adaptive
 * smoothing length. MIT licence (see the end of this file and LICENSE).
 *
 * ==== USAGE ================================================================
 *
 *   #include "sph_kernel.h"            (every function is static inline)
 *
 *   sph_real W, F;
 *   sph_kernel_wf(SPH_KERNEL_CUBIC, 3, r, h, &W, &F);   W and F = (1/r) dW/dr
 *   grad_i W_ij = F * (x_i - x_j)                       (design sign convention)
 *
 * Conventions (docs/kernels.md, docs/operators.md): x_ij = x_i - x_j,
 * r = |x_ij|, q = r/h, W(r,h) = alpha_d h^-d w(q), w = 0 for q >= kappa,
 * grad_i W_ij = F x_ij with F = (1/r) dW/dr = alpha_d h^-(d+2) w'(q)/q, which
 * is finite at r = 0 for every kernel here: no division by r anywhere.
 *
 * Scalar kernel functions never fail loudly: for an unknown kernel, a
 * dimension the kernel is not defined in, r < 0, r or h not finite, h <= 0
 * (or h so small that some kernel's W or F in that dimension would overflow:
 * 64 h^-(d+2) beyond the largest sph_real) they return 0 (and write zeros).
 * Use sph_kernel_check(k, dim) and sph_check_h(h) to validate once, outside
 * hot loops.
 *
 * Periodic box: give it to the neighbour search once. sph_nsearch_list
 * copies it into the list, and the operators (sph_ctx) and section 9
 * (sph_hctx, sph_pairs) use ctx.box when set, else the list's; a ctx.box
 * that differs from the list's is SPH_EBOX (docs/neighbours.md). A list the
 * caller assembles (SPH_NEIGHBOURS_INIT) has no box of its own.
 *
 * Status codes (section 2) name what to fix: SPH_ECOUNT a count, SPH_ESIZE
 * an array or workspace too small, SPH_EOFFSET a list's offsets,
 * SPH_EOPTION an enum argument, SPH_ERANGE a parameter, SPH_ESTRIDE a
 * stride, SPH_EVALUE an input value, SPH_EBOXLEN / SPH_EBOX the box,
 * SPH_ENOTSYMMETRIC a list for pair-once loops, SPH_ENOGRID an unbuilt
 * grid; sph_strerror(status) says how.
 *
 * ==== CONFIGURATION (define before including) ==============================
 *
 *   SPH_REAL    floating type of every real number: double (default) or float.
 *   SPH_API     storage of every function; default `static inline`, plus
 *               `__host__ __device__` when compiled by nvcc.
 *   SPH_DIM     pin the dimension of the array operators (1, 2 or 3): only
 *               that dimension's loops are compiled; a context with another
 *               dim gets SPH_EDIM. Default: all three, chosen at run time.
 *   SPH_KERNEL  pin the kernel of the array operators (e.g. SPH_KERNEL_CUBIC):
 *               only its loops are compiled; another ctx.kernel gets
 *               SPH_EKERNEL. The scalar kernel functions take any kernel.
 *               Pinning changes code size and compile time, not speed: the
 *               run-time choice is made once per call, outside the pair loop
 *               (bench/benchmark.c measures both).
 *   SPH_OP_REFERENCE  compile only the plain reference loops of the array
 *               operators (one pair at a time through the section-5 pair
 *               terms): the smallest and simplest code, several times slower.
 *               Default: the fast loops (chunked, vectorised; AVX-512 one-pass
 *               density and gradient where the target has it), tested equal
 *               to the reference loops, which ctx.loops = SPH_LOOPS_REFERENCE
 *               also selects at run time.
 *   SPH_NO_DISPATCH  no run-time dispatch: the fast loops run at the level
 *               the build's flags give (-march), not at the CPU's. Default
 *               on x86-64 under gcc 8+ or clang 8+ (not clang with OpenMP):
 *               sections 5-9 are compiled once more for each level above
 *               the build's, AVX2 + FMA and AVX-512 (a target pragma, names
 *               suffixed _avx2 / _avx512), and the public functions with a
 *               hot loop run the level chosen once from the CPU (sph_isa;
 *               sph_isa_set forces one). Saves most of the compile time
 *               and code of a unit that calls the operators (README,
 *               "Build cost": about 5 times either with the passes); costs
 *               2-3x in speed on a CPU with AVX2 or AVX-512 in a build
 *               without -march (README, "Performance").
 *   SPH_NO_DISPATCH_AVX512  run-time dispatch without the AVX-512 pass:
 *               the AVX2 loops on every CPU that has AVX2 (or the build's
 *               level), about half the passes' compile time and code.
 *   SPH_SELF    the name under which the header includes itself for the
 *               run-time passes; default "sph_kernel.h" (define it when the
 *               file is renamed, or SPH_NO_DISPATCH).
 *   SPH_NO_INTRINSICS  use only portable C: no SSE/AVX square-root helper in
 *               the operator loops, no AVX-512 or AVX2 one-pass loop for the
 *               density and difference gradient, none for
 *               sph_h_solve's density sums (results within 1e-13 of the pair
 *               sum either way, tested; the order of the sum over j
 *               differs), no AVX2 or AVX-512 check of a block of sources in the
 *               neighbour search (same lists), no run-time dispatch; slower.
 *   SPH_NSEARCH_PLAIN  the plain neighbour search: cells of the given edge
 *               and, in symmetric mode, one radius kappa max(h_i, h_max) for
 *               every target. Default: cells refined to the sources' h and a
 *               reach bounded per target (docs/neighbours.md, "Varying h");
 *               the same lists, tested equal.
 *   SPH_BATCH   lanes of a pair batch (sph_batch_fill, section 9): a power of
 *               two, 4..64; default 16 (one AVX-512 register of floats, two of
 *               doubles). Changes speed, not results.
 *   SPH_FP_CONTRACT  leave the header's a * b + c to the unit's contraction
 *               setting. Default: under clang (and compilers built on it)
 *               the header's own code is compiled with contraction off
 *               (#pragma STDC FP_CONTRACT OFF, DEFAULT at its end), so
 *               that the fast loops equal the reference loops bit for bit
 *               as under gcc -std=c99; gcc cannot be told so per header
 *               without losing inlining (docs/testing.md, "Floating-point
 *               contraction": what holds in its GNU modes).
 *   SPH_ONLY_KERNELS   sections 1-3 only: the scalar kernel functions.
 *   SPH_ONLY_PAIRS     sections 1-5: kernels, views and pair terms, for a
 *               solver with its own neighbour loop (no operators, no search),
 *               and the pair terms of section 8.
 *   SPH_NO_OPERATORS   everything but section 6 (the array operators) and
 *               the array operators of section 8, which use it.
 *   SPH_NO_NSEARCH     everything but section 7 (the neighbour search).
 *   SPH_NO_SOLVER      everything but section 8 (the solver terms).
 *   SPH_NO_SMOOTHING_LENGTH  everything but section 9 (adaptive h, grad-h
 *               forces, pair-once loops).
 *               Each saves the compile time of what it leaves out
 *               (`make compile-cost`) and is compiled warning-free by make test.
 *
 * The version is SPH_KERNEL_VERSION (major*10000 + minor*100 + patch) and
 * SPH_KERNEL_VERSION_STRING.
 *
 * ==== SECTIONS =============================================================
 * Each needs only the sections before it that it names; a vendor may delete
 * a section that nothing after it needs (or leave it out with the switches
 * above):
 *   1. configuration        macros, sph_real, libm wrappers, instruction-set
 *                           levels: every section
 *   2. status codes         SPH_OK and the errors, the level the fast loops
 *      and instruction sets run at (sph_isa): every section
 *   3. kernels              1, 2: W, F and their derivatives, the kernel tables
 *   4. particle data        1, 2: views, CSR neighbour lists, periodic box
 *   5. pair terms           1-4: one neighbour's contribution to each operator
 *   6. array operators      1-5: the operators over a CSR list (deletable)
 *   7. neighbour search     1-4: builds the CSR lists (deletable)
 *   8. solver terms         1-6: artificial viscosity and its switches,
 *                           density diffusion, wall boundaries, viscosity,
 *                           time step (deletable; pair terms 1-5)
 *   9. smoothing length     1-5: adaptive h with grad-h terms, pair-once
 *      and pair-once loops  loops over a half list (deletable)
 *
 * ==== API AT A GLANCE (every public function; k kernel, dim 1..3) ==========
 * Names with a double underscore (sph__, SPH__) are internal.
 * 2. Status codes, instruction sets
 *   sph_strerror(status)                         a sentence for a status code
 *   sph_isa()                                    level the fast loops run at: SPH_ISA_PORTABLE, _AVX2, _AVX512
 *   sph_isa_has(isa), sph_isa_set(isa)           whether this unit and CPU have a level; force one (tests)
 *   sph_isa_name(isa), sph_isa_dispatch()        "portable", "avx2", "avx512"; 1 with run-time dispatch
 *   SPH_TARGET_AVX2, SPH_TARGET_AVX512           attributes compiling a caller's own loop for a level
 * 3. Kernels: scalar functions return 0 for invalid input
 *   sph_kernel_check(k, dim)                     SPH_OK, SPH_EKERNEL or SPH_EDIM
 *   sph_check_h(h)                               SPH_OK or SPH_EH
 *   sph_kernel_support(k)                        kappa: W = 0 for r >= kappa h
 *   sph_kernel_name(k)                           "cubic", "wendland_c4", ...
 *   sph_kernel_from_name(name)                   the kernel, or SPH_EKERNEL
 *   sph_kernel_alpha(k, dim)                     alpha_d (K1)
 *   sph_kernel_sigma(k, dim)                     standard deviation / h (K5)
 *   sph_kernel_neighbours(k, dim, h, V)          neighbours in the support (K6)
 *   sph_kernel_h_for_neighbours(k, dim, N, V)    h for N neighbours (K6)
 *   sph_kernel_w(k, dim, r, h)                   W (K1)
 *   sph_kernel_f(k, dim, r, h)                   F = (1/r) dW/dr (K2)
 *   sph_kernel_dwdr(k, dim, r, h)                dW/dr (K3)
 *   sph_kernel_d2wdr2(k, dim, r, h)              d2W/dr2 (K4)
 *   sph_kernel_dwdh(k, dim, r, h)                dW/dh (K7)
 *   sph_kernel_wf(k, dim, r, h, &W, &F)          W and F in one call
 *   sph_kernel_grad(k, dim, dx, h, grad)         grad_i W_ij = F dx (K8)
 * 4. Particle data
 *   sph_box_delta(box, a, dx)                    minimum image of one component (O0)
 *   SPH_NEIGHBOURS_INIT(nt, ns, offset, index)   a CSR list of the caller's arrays, box unknown
 *   sph_neighbours_check(list)                   validates a CSR list once
 *   sph_view_soa(x, y, z)                        read view of one array per component
 *   sph_view_aos(first, ncomp, stride_bytes)     read view into an array of structs
 *   sph_view_interleaved(x, ncomp)               read view of x[ncomp i + a]
 *   sph_out_soa(x, y, z)                         write view, as sph_view_soa
 *   sph_out_aos(first, ncomp, stride_bytes)      write view, as sph_view_aos
 *   sph_out_interleaved(x, ncomp)                write view, as sph_view_interleaved
 *   sph_share_init(&s, next, shares, n, chunk)   a parallel loop's particles in shares of chunks
 *   sph_share_next(&s, t, &u, &lo, &hi)          thread t's next chunk: its own share first
 * 5. Pair terms: neighbour j of target i, dx = x_i - x_j, F of the pair
 *   sph_pair_kernel(k, dim, dx, h)               r, q, W and F of the pair (O1)
 *   sph_pair_density(m_j, W)                     density term (O2)
 *   sph_pair_interpolate(V_j, f_j, W)            interpolation term (O3)
 *   sph_pair_grad_standard(dim, V_j, f_j, F, dx, acc)         acc += (O4)
 *   sph_pair_grad_difference(dim, V_j, f_i, f_j, F, dx, acc)  acc += (O5)
 *   sph_pair_grad_symmetric(dim, V_j, f_i, f_j, F, dx, acc)   acc += (O6)
 *   sph_pair_grad_pressure(dim, m_j, P_i, P_j, F, dx, acc)    acc += (O8)
 *   sph_pressure_factor(p, rho)                  P = p / rho^2 of (O8)
 *   sph_pair_div_standard(dim, V_j, v_j, F, dx)  divergence term (O9)
 *   sph_pair_div_difference(dim, V_j, v_i, v_j, F, dx)        (O10)
 *   sph_pair_curl(dim, V_j, u, F, dx, acc)       acc += (O11)
 *   sph_pair_laplacian(V_j, f_i, f_j, F)         Laplacian term (O12)
 *   sph_harmonic_k(k_i, k_j)                     pair coefficient k_ij (O13)
 *   sph_pair_diffusion(V_j, k_ij, f_i, f_j, F)   diffusion term (O14)
 *   sph_pair_correction(dim, V_j, F, dx, M)      M += (O15)
 *   sph_correction_invert(dim, M, rcond_min, B)  B = M^-1, or I if ill-conditioned (O16)
 * 6. Array operators over a neighbour list (return SPH_OK or a status code)
 *   sph_view_none()                              an absent view
 *   sph_ctx_init(k, dim, h, list, x)             a context; set further fields as needed
 *                                                (ctx.box NULL: the list's box; another: SPH_EBOX)
 *   sph_density(c, rho)                          (O2)
 *   sph_interpolate(c, f, out)                   (O3)
 *   sph_interpolate_shepard(c, f, out, &n_empty) (O3) normalised
 *   sph_gradient(c, scheme, f, f_t, grad, &n_fb) (O4)-(O8)
 *   sph_density_gradient(c, f, f_t, rho, grad)   (O2) and (O5) in one pass
 *   sph_gradient_vector(c, scheme, v, v_t, T, T_stride, &n_fb)  (O17)
 *   sph_divergence(c, scheme, v, v_t, div, &n_fb)               (O9), (O10), (O18)
 *   sph_curl(c, scheme, v, v_t, curl)            (O11)
 *   sph_laplacian(c, f, f_t, lap)                (O12)
 *   sph_diffusion(c, k, k_t, f, f_t, out)        (O13), (O14)
 *   sph_correction_matrix(c, B, B_stride, &n_fb) (O15), (O16)
 *   sph_check_field(f, ncomp, n, &first_bad)     first NaN or Inf of a field
 * 7. Neighbour search (caller-owned workspace; no allocation)
 *   sph_nsearch_workspace_size(dim, xs, n, hs, cell, box, &bytes)  bytes to build
 *   sph_nsearch_build(&g, dim, xs, n, hs, cell, box, work, bytes)  bins the sources (N4)
 *   sph_nsearch_count(&g, xt, n_t, ht, h, kappa, mode, offset)     list lengths (N1)/(N2)
 *   sph_nsearch_fill(&g, xt, n_t, ht, h, kappa, mode, offset, index, cap)  the lists
 *   sph_nsearch_lists(&g, ..., offset, index, cap, &pairs)  count and fill in one search
 *   sph_nsearch_stats(&g, ..., &pairs, &candidates, &fill)  pairs, checks, grid fill; no lists
 *   sph_nsearch_list(&g, n_t, offset, index)     the sph_neighbours view of the lists, with the box
 *   sph_nsearch_skin(&list, box, dim, x, x0, hl, kappa, h, h_keep, &n_stale)  whether a kept list serves h (N8)
 *   sph_nsearch_prune(&list, box, dim, x, h, kappa, mode, offset, index, cap, &pairs, &out)  its pairs within reach
 *   sph_nsearch_permutation(&g, perm)            sources in cell order (N5)
 *   sph_permutation_invert(perm, n, inv)         inverse permutation (N6)
 *   sph_permute(in, ncomp, n, perm, out)         out[k] = in[perm[k]] (N5)
 * 8. Solver terms: pair terms, then operators (return SPH_OK or a status code)
 *   sph_pair_av_monaghan(dim, alpha, beta, h, c_ij, rho_ij, dx, dv)  Pi_ij (S1)
 *   sph_pair_signal_velocity(dim, beta, c_i, c_j, dx, dv)            v_sig,ij (S2)
 *   sph_pair_av_signal(dim, alpha, beta, c_i, c_j, rho_ij, dx, dv)   Pi_ij (S3)
 *   sph_pair_av_apply(dim, m_j, Pi_ij, F, dx, dv, acc)   acc += (S4), returns du_i/dt's term
 *   sph_av_init(form, alpha, beta)               the viscosity of (S1) or (S3), no per-particle view
 *   sph_pair_av_alpha(alpha_i, alpha_j, B_i, B_j)        alpha_ij with the Balsara factors (S14)
 *   sph_pair_viscosity(dim, m_j, mu_i, mu_j, rho_i, rho_j, h, F, dx, dv, acc)  acc += (S5)
 *   sph_pair_density_diffusion(dim, V_j, rho_i, rho_j, g_i, g_j, F, dx)   (S6)
 *   sph_pair_wall(dim, W, p_f, rho_f, v_f, g_eff, dx, sum)    sums of a wall particle (S8)
 *   sph_wall_end(dim, slip, sum, v_wall, &p_w, v_w)          its pressure and velocity (S8)
 *   sph_dt_coef_default()                        C of the time-step limits (S9)-(S12)
 *   sph_dt_reason_name(reason)                   "cfl", "force", ...: the limit that holds
 *   sph_dt_limit(&coef, h, vsig, |a|, nu, D, &reason)        one particle's dt (S9)-(S12)
 *   sph_switch_default()                         the switches' parameters, SPHENIX's (S15)-(S17)
 *   sph_switch_balsara(div_v, curl_v, c, h)      Balsara factor B (S13)
 *   sph_switch_mm97(&s, alpha, div_v, c, h)      d alpha/dt of Morris & Monaghan (S15)
 *   sph_switch_sphenix(&s, alpha, div_v, ddiv_v_dt, c, H, dt)      new alpha, SPHENIX (S16)
 *   sph_switch_conductivity(&s, alpha_d, lap_u, u, v_sig, H, alpha_visc, dt)  new alpha_D (S17)
 *   sph_artificial_viscosity(c, &av, v, v_t, cs, cs_t, acc, dudt, vsig)   (S1)-(S4)
 *   sph_viscosity(c, kind, mu_or_nu, coef_t, v, v_t, acc)    (S5)
 *   sph_density_diffusion(c, delta, c0, grad_rho, grad_rho_t, out)        (S6), (S7)
 *   sph_wall_init(dim, g)                        a wall model at rest, no-slip
 *   sph_wall_adami(c, &wall, p, v, p_w, v_w, &n_empty)       (S8)
 *   sph_dt_input_init(h)                         inputs of sph_time_step
 *   sph_time_step(&in, dim, n, &dt, &reason, &which)         (S9)-(S12)
 *   sph_switch_input_init(kappa)                 inputs of sph_switch_update: SPHENIX, dt 0, no view
 *   sph_switch_update(&in, n, alpha, div_v_prev, B, alpha_d)  (S13), (S16), (S17) over the particles
 * 9. Smoothing length and pair-once loops (docs/smoothing_length.md)
 *   sph_hctx_init(k, dim, list, x, m, h_list_max)  a context; eta 1.2, tol 1e-6; box as sph_ctx
 *   sph_h_solve(c, h, rho, omega, iters, state, &report)  h, rho, Omega per particle (H1)-(H4)
 *   sph_gradh_factor(p, rho, omega)              A = p / (Omega rho^2) of (H5), (H6)
 *   sph_pair_gradh_pressure(dim, m_j, A_i, A_j, F_i, F_j, dx, acc)  acc += (H5)
 *   sph_pair_gradh_energy(dim, m_j, A_i, F_i, v_ij, dx)            (H6) term
 *   sph_gradh_forces(c, v, h, A, dvdt, dudt)     (H5), (H6), gather form
 *   sph_pairs_build(full, offset, index, cap, t_offset, t_slot, &pairs, &P)  half list + transpose (H8)
 *   sph_pairs_reduce(&P, ncomp, to_i, to_j, out) per-particle sums of per-pair terms (H8)
 *   sph_pairs_reduce_rows(&P, ncomp, to_j, out)  the same, out holding the rows' own sums on entry
 *   sph_pairs_reduce_rows_k(&P, ncomp, to_j, out)  the same, to_j at the pair index k (not the slot)
 *   sph_pairs_buffer_len(ncomp, pairs)           reals of the two per-pair buffers of sph_pairs_reduce
 *   sph_gradh_pairs_buffer_len(dim, pairs)       reals of the buffer of sph_gradh_forces_pairs
 *   sph_gradh_forces_pairs(c, &P, v, h, A, buf, buf_len, dvdt, dudt)  (H5), (H6), pair-once
 *   sph_batch_source(&S, k, dim, list, box, x, h)  checks a list once for the batch fills
 *   sph_batch_select(&S, what)                   SPH_BATCH_W, SPH_BATCH_F, both (default) or neither
 *   sph_batch_fill(&S, i, &next, &b)             next SPH_BATCH pairs of row i: j, k, dx, r, W, F at h_i, h_j
 *   sph_batch_sqrt(v)                            v[l] = sqrt(v[l]) over the lanes, in vector registers
 *
 * ==== EQUATION LABELS (comments cite docs/ by these) ========================
 *   (K1)-(K8)   kernel quantities, docs/kernels.md section 1: W, F, dW/dr,
 *               d2W/dr2, sigma, neighbour number, dW/dh, grad W
 *   (O0)-(O18)  pair terms and operators, docs/operators.md "Formulas":
 *               minimum image, pair kernel, density, interpolation, gradients
 *               (O4)-(O8), divergences (O9)-(O10), curl, Laplacian, k_ij,
 *               diffusion, correction matrix and inverse, velocity gradient,
 *               corrected divergence
 *   (N1)-(N8)   neighbour search, docs/neighbours.md: criteria (N1)-(N3),
 *               grid (N4), permutation and inverse (N5)-(N6), periodic
 *               image of a run of cells (N7), lists kept over steps (N8)
 *   (S1)-(S17)  solver terms, docs/solver.md: artificial viscosity
 *               (S1)-(S4), viscosity (S5), density diffusion (S6)-(S7),
 *               walls (S8), time-step limits (S9)-(S12), the Balsara factor
 *               and alpha per particle (S13)-(S14), viscosity and
 *               conductivity switches (S15)-(S17)
 *   (H1)-(H8)   smoothing length, grad-h equations, pair-once sums,
 *               docs/smoothing_length.md
 */
#ifndef SPH_KERNEL_H
#define SPH_KERNEL_H

/* ======================================================================== */
/* 1. Configuration                                                          */
/* ======================================================================== */

#define SPH_KERNEL_VERSION_MAJOR 0
#define SPH_KERNEL_VERSION_MINOR 1
#define SPH_KERNEL_VERSION_PATCH 0
#define SPH_KERNEL_VERSION \
    (SPH_KERNEL_VERSION_MAJOR * 10000 + SPH_KERNEL_VERSION_MINOR * 100 + SPH_KERNEL_VERSION_PATCH)
#define SPH_KERNEL_VERSION_STRING "0.1.0"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#ifdef _OPENMP
#include <omp.h> /* only when the program is built with OpenMP: thread count of sph_nsearch_lists */
#endif

#ifndef SPH_REAL
#define SPH_REAL double
#endif
typedef SPH_REAL sph_real;

#if defined(__CUDACC__)
#define SPH_HOSTDEV __host__ __device__
#else
#define SPH_HOSTDEV
#endif

#ifndef SPH_API
#define SPH_API static inline SPH_HOSTDEV
#endif

/* Force-inlined helpers (the kernel forms, the pair terms' loops): the
 * operator loops rely on them folding into one loop body per kernel and
 * dimension. */
#if defined(__CUDACC__)
#define SPH__INLINE static __forceinline__ SPH_HOSTDEV
#elif defined(__GNUC__) || defined(__clang__)
#define SPH__INLINE static inline __attribute__((always_inline))
#elif defined(_MSC_VER)
#define SPH__INLINE static __forceinline
#else
#define SPH__INLINE static inline
#endif
/* Kept out of line (a rarely taken path, or one instance per kernel shape that
 * the loops call), so that it does not weigh on its callers' code. */
#if defined(__CUDACC__)
#define SPH__NOINLINE static __noinline__ SPH_HOSTDEV
#elif defined(__GNUC__) || defined(__clang__)
/* inline: a unit that does not call it does not compile it, at -O0 too (a
 * plain static function is emitted there, every run-time pass's with it);
 * gcc's -Wattributes calls inline with noinline a contradiction: silenced
 * for the header's own code (SPH__DIAG_PUSHED, popped at its end). */
#define SPH__NOINLINE static inline __attribute__((noinline, unused))
#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wattributes"
#define SPH__DIAG_PUSHED 1
#endif
#else
#define SPH__NOINLINE static inline
#endif

/* Instruction sets. The fast loops of sections 5-9 are written once and
 * compiled for one level at a time: 0 the build's own target (portable C,
 * with SSE2 or AVX square roots where it has them), 1 AVX2 + FMA
 * (x86-64-v3), 2 AVX-512 F, VL, BW, DQ, CD (x86-64-v4). SPH__ISA_BUILD is
 * the level the unit's flags give; SPH__ISA the level of the code being
 * compiled: the build's, or that of a run-time pass (below, SPH__DISPATCH).
 * SPH__SQRT_SIMD: square roots in AVX (2) or SSE2 (1) registers, or none
 * (0: portable loop); it also picks the sign words of the symmetric lists'
 * completion (section 7). */
#if !defined(SPH_NO_INTRINSICS) && !defined(__CUDACC__) && (defined(__GNUC__) || defined(__clang__)) && \
    (defined(__AVX__) || defined(__SSE2__))
#include <immintrin.h>
#if defined(__AVX__)
#define SPH__SQRT_SIMD_BUILD 2
#else
#define SPH__SQRT_SIMD_BUILD 1
#endif
#else
#define SPH__SQRT_SIMD_BUILD 0
#endif
#if SPH__SQRT_SIMD_BUILD == 2 && defined(__AVX512F__) && defined(__AVX512VL__)
#define SPH__ISA_BUILD 2
#elif SPH__SQRT_SIMD_BUILD == 2 && defined(__AVX2__) && defined(__FMA__)
#define SPH__ISA_BUILD 1
#else
#define SPH__ISA_BUILD 0
#endif
#define SPH__ISA SPH__ISA_BUILD
#define SPH__SQRT_SIMD (SPH__ISA >= 1 ? 2 : SPH__SQRT_SIMD_BUILD)
/* AVX-512 in the operator loops (section 6: the density and the difference
 * gradient, 8 pairs per step in one pass; with SPH_REAL float the values are
 * read as float and the terms computed in double, the sums rounded to float
 * once), in sph_h_solve's density sums (section 9) and in the neighbour fill
 * (section 7: the rank sort of a cell's sources and the completion of the
 * symmetric lists). */
#define SPH__OP_AVX512 (SPH__ISA == 2)
#define SPH__NS_COMPRESS (SPH__ISA == 2)
/* The neighbour check of a block of 16 sources in vector registers, its
 * accepted indices compressed (AVX-512 compress, AVX2 permute), level 1 or 2. */
#define SPH__NS_VEC (SPH__ISA >= 1)
/* The same register loops in AVX2 + FMA, 4 pairs per step in double as
 * the AVX-512 ones' 8 (level 1): the density and difference gradient in one
 * pass, sph_h_solve's density sums. */
#define SPH__OP_AVX2 (SPH__ISA == 1)

/* Run-time dispatch (SPH_NO_DISPATCH compiles it out): on x86-64 under gcc
 * or clang, sections 5-9 are compiled once more for each level above the
 * build's (the header includes itself with SPH__LV set, under a target
 * pragma, its function names suffixed _avx2 or _avx512), and the public
 * functions with hot loops go to the level chosen once from the CPU's
 * features (sph_isa, section 2). Not with nvcc, MSVC or other targets,
 * which keep the build's loops; clang with OpenMP neither, as its outlined
 * parallel regions do not take a function's target (sph_isa_dispatch says
 * whether a unit has it). */
#if !defined(SPH_NO_DISPATCH) && SPH__SQRT_SIMD_BUILD != 0 && SPH__ISA_BUILD < 2 && defined(__x86_64__) && \
    ((defined(__clang__) && __clang_major__ >= 8 && !defined(_OPENMP)) || (!defined(__clang__) && __GNUC__ >= 8))
/* the passes: AVX-512 unless SPH_NO_DISPATCH_AVX512, AVX2 below an AVX2 build */
#if defined(SPH_NO_DISPATCH_AVX512)
#define SPH__PASS_AVX512 0
#else
#define SPH__PASS_AVX512 1
#endif
#define SPH__PASS_AVX2 (SPH__ISA_BUILD < 1)
#else
#define SPH__PASS_AVX512 0
#define SPH__PASS_AVX2 0
#endif
#if SPH__PASS_AVX512 || SPH__PASS_AVX2
#define SPH__DISPATCH 1
#else
#define SPH__DISPATCH 0
#endif
/* The target of each pass: the features sph__isa_cpu checks. A caller's
 * own hot loop (its pair arithmetic) can be compiled for a level the same
 * way: SPH_TARGET_AVX2 / SPH_TARGET_AVX512 are the function attributes,
 * defined where this unit has that pass (docs/testing.md, "Instruction
 * sets"; examples/sod_shock.c, sd_rows). */
#define SPH__TARGET_AVX2 "avx,avx2,fma,bmi,bmi2,popcnt"
#define SPH__TARGET_AVX512 "avx,avx2,fma,bmi,bmi2,popcnt,avx512f,avx512vl,avx512bw,avx512dq,avx512cd"
#define SPH__PRAGMA_(...) _Pragma(#__VA_ARGS__)
#define SPH__PRAGMA(...) SPH__PRAGMA_(__VA_ARGS__)
#if SPH__PASS_AVX512
#define SPH_TARGET_AVX512 __attribute__((target(SPH__TARGET_AVX512)))
#endif
#if SPH__PASS_AVX2
#define SPH_TARGET_AVX2 __attribute__((target(SPH__TARGET_AVX2)))
#endif


/* Every lane of 8. The AVX-512 code calls the maskz_ form, with SPH__ALL8,
 * of each intrinsic whose plain form passes a formally undefined vector as
 * the lanes to keep (sqrt, max, roundscale, the conversions and extracts):
 * g++ -O2 reports that vector as maybe-uninitialised wherever it is inlined. */
#define SPH__ALL8 ((__mmask8)0xFF)


/* Tables are read by host and device code alike: under nvcc the device pass
 * keeps its own copy in device memory. */
#if defined(__CUDACC__) && defined(__CUDA_ARCH__)
#define SPH__TABLE static __device__ const
#else
#define SPH__TABLE static const
#endif

/* An exact rational (or decimal) constant, rounded once to sph_real. */
#define SPH__Q(n, d) ((sph_real)((double)(n) / (double)(d)))
#define SPH__C(x) ((sph_real)(x))

/* Token pasting after expansion (the names of the run-time passes). */
#define SPH__CAT_(a, b) a##b
#define SPH__CAT(a, b) SPH__CAT_(a, b)

/* Largest finite sph_real, whatever SPH_REAL is. */
#define SPH__REAL_MAX (sizeof(sph_real) == sizeof(float) ? (sph_real)FLT_MAX : (sph_real)DBL_MAX)

#ifdef __cplusplus
extern "C" {
#endif

/* The header's arithmetic as written, a * b + c a rounded product and a
 * rounded sum (SPH_FP_CONTRACT above): clang decides contraction per source
 * expression, so this holds wherever its functions are inlined, unless the
 * unit asks -ffp-contract=fast (which disregards the pragma). At the end of
 * the header DEFAULT gives the code after it the unit's own setting again. */
#if !defined(SPH_FP_CONTRACT) && defined(__clang__) && !defined(__CUDACC__)
#pragma STDC FP_CONTRACT OFF
#define SPH__FP_PUSHED 1
#endif

/* libm in the precision of sph_real (the sizeof test folds at compile time). */
SPH_API sph_real sph__sqrt(sph_real x)
{
    return sizeof(sph_real) == sizeof(float) ? (sph_real)sqrtf((float)x) : (sph_real)sqrt((double)x);
}

SPH_API sph_real sph__floor(sph_real x)
{
    return sizeof(sph_real) == sizeof(float) ? (sph_real)floorf((float)x) : (sph_real)floor((double)x);
}

/* 1 when x is finite (neither NaN nor +-Inf), without isfinite's double promotion. */
SPH_API int sph__finite(sph_real x) { return x >= -SPH__REAL_MAX && x <= SPH__REAL_MAX; }

/* a * b rounded to sph_real before anything is added to it, whatever the
 * unit's contraction (gcc's GNU modes fuse a * b + c across statements):
 * the product passes through an empty asm the compiler cannot see into, or
 * a CUDA rounded multiply. For scalar code that decides on a rounded value
 * (the neighbour criterion, section 7); it keeps a loop from vectorising. */
SPH__INLINE sph_real sph__mul_rn(sph_real a, sph_real b)
{
#if defined(__CUDA_ARCH__)
    return sizeof(sph_real) == sizeof(float) ? (sph_real)__fmul_rn((float)a, (float)b)
                                             : (sph_real)__dmul_rn((double)a, (double)b);
#else
    sph_real p = a * b;
#if defined(__GNUC__) && (defined(__x86_64__) || (defined(__i386__) && defined(__SSE2__)))
    __asm__("" : "+x"(p));
#elif defined(__GNUC__) && defined(__aarch64__)
    __asm__("" : "+w"(p));
#elif defined(__GNUC__)
    __asm__("" : "+g"(p));
#endif
    return p;
#endif
}

/* ======================================================================== */
/* 2. Status codes                                                           */
/* ======================================================================== */

/* One list generates the status enum and the sentences of sph_strerror:
 * X(name, value, sentence). Every function that can fail returns SPH_OK or
 * one of the negative codes; the values never change between versions.
 * SPH_EINVAL is returned by no function of this header (it keeps its value;
 * a caller may use it for errors of its own). Which function returns which
 * code: the comment above each; tests/check_status_codes.sh holds the
 * documentation to the code. */
#define SPH_STATUS_LIST(X) \
    X(SPH_OK, 0, "success") \
    X(SPH_EKERNEL, -1, "unknown kernel") \
    X(SPH_EDIM, -2, "dimension outside 1..3 or not defined for this kernel") \
    X(SPH_EH, -3, "smoothing length not positive and finite, or so small that W or F would overflow") \
    X(SPH_ENULL, -4, "NULL pointer where data is required") \
    X(SPH_EINDEX, -5, "neighbour index out of range") \
    X(SPH_ESIZE, -6, \
      "array or workspace too small: query the size needed (or read the pairs counted) and pass a " \
      "larger one") \
    X(SPH_ENONFINITE, -7, "NaN or Inf in an input array") \
    X(SPH_EINVAL, -8, "invalid argument") \
    X(SPH_EGRID, -9, "neighbour grid too large: a source far from the others, or a cell size too small") \
    X(SPH_EPERIOD, -10, "periodic box shorter than twice the search radius kappa h") \
    X(SPH_EBOX, -11, \
      "periodic box differs from the one the neighbour list was built with: leave ctx.box NULL or pass " \
      "the search's box") \
    X(SPH_EBOXLEN, -12, \
      "periodic box unusable: a periodic axis needs a positive, finite length with finite 1/length " \
      "(and, to search, a finite lo)") \
    X(SPH_EOFFSET, -13, \
      "neighbour list offsets malformed: offset[0] must be 0, offsets non-decreasing and from " \
      "sph_nsearch_count with the same arguments") \
    X(SPH_ENOTSYMMETRIC, -14, \
      "list unusable for pair-once loops: a pair in one row only (search with SPH_NSEARCH_SYMMETRIC or " \
      "a uniform h) or a row not in ascending index") \
    X(SPH_EOPTION, -15, \
      "unknown option: a scheme, mode, loops, kind, form or slip value this function does not take") \
    X(SPH_ERANGE, -16, \
      "parameter out of range (eta, tol, max_iter, rcond_min, cell, kappa, a coefficient, ncomp): see " \
      "the function's comment") \
    X(SPH_ESTRIDE, -17, "stride too small: a view's stride must be positive, a tensor's at least dim * dim") \
    X(SPH_ECOUNT, -18, \
      "count negative or too large, or n_targets and n_sources not as the function needs (equal where " \
      "targets are the sources)") \
    X(SPH_EVALUE, -19, \
      "input value out of range: a density not positive, a coordinate beyond sqrt(REAL_MAX)/4, or a " \
      "time-step h or rate negative or not finite") \
    X(SPH_ENOGRID, -20, "neighbour grid not built: sph_nsearch_build must return SPH_OK first") \
    X(SPH_EISA, -21, \
      "instruction set not available: this unit has no loops for it (run-time dispatch compiled out, or a " \
      "build for a higher level) or the CPU lacks it")

enum {
#define SPH__STATUS_ENUM(name, value, sentence) name = value,
    SPH_STATUS_LIST(SPH__STATUS_ENUM)
#undef SPH__STATUS_ENUM
};

/* A sentence for a status code; never NULL. */
SPH_API const char *sph_strerror(int status)
{
    switch (status) {
#define SPH__STATUS_CASE(name, value, sentence) \
    case name: return sentence;
        SPH_STATUS_LIST(SPH__STATUS_CASE)
#undef SPH__STATUS_CASE
    default: return "unknown status code";
    }
}

/* ---- Instruction sets of the fast loops (section 1: levels, SPH__DISPATCH) ---- */
/* The levels sections 5-9 can run at: the build's own loops, or a run-time
 * pass compiled for AVX2 + FMA or AVX-512 (x86-64 under gcc or clang). */
#define SPH_ISA_LIST(X) \
    X(SPH_ISA_PORTABLE, 0, "portable") \
    X(SPH_ISA_AVX2, 1, "avx2") \
    X(SPH_ISA_AVX512, 2, "avx512")
enum {
    SPH_ISA_AUTO = -1, /* sph_isa_set: back to the CPU's best */
#define SPH__ISA_ENUM(name, value, id) name = value,
    SPH_ISA_LIST(SPH__ISA_ENUM)
#undef SPH__ISA_ENUM
};

/* "portable", "avx2", "avx512"; NULL for another value. */
SPH_API const char *sph_isa_name(int isa)
{
    switch (isa) {
#define SPH__ISA_CASE(name, value, id) \
    case name: return id;
        SPH_ISA_LIST(SPH__ISA_CASE)
#undef SPH__ISA_CASE
    default: return NULL;
    }
}

#if SPH__DISPATCH
/* The highest level this CPU runs, by the features each pass is compiled
 * for (the CPUID bits and the OS's saving of the registers, read by the
 * compiler's runtime). */
SPH_API int sph__isa_cpu(void)
{
    __builtin_cpu_init();
    if (!(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
          __builtin_cpu_supports("bmi2") && __builtin_cpu_supports("popcnt")))
        return SPH_ISA_PORTABLE;
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512cd"))
        return SPH_ISA_AVX512;
    return SPH_ISA_AVX2;
}

/* This unit's chosen level, -1 until the first sph_isa(). */
SPH_API int *sph__isa_slot(void)
{
    static int isa = -1;
    return &isa;
}
#endif

/* 1 when this unit can run its fast loops at level isa on this CPU: the
 * build's own level, or with run-time dispatch one above it the CPU has. */
SPH_API int sph_isa_has(int isa)
{
#if SPH__DISPATCH
    return isa >= SPH__ISA_BUILD && isa <= (SPH__PASS_AVX512 ? SPH_ISA_AVX512 : SPH_ISA_AVX2) && isa <= sph__isa_cpu();
#else
    return isa == SPH__ISA_BUILD;
#endif
}

/* The level the fast loops of sections 5-9 run at in this unit: chosen
 * once, the highest the CPU and the unit have, unless sph_isa_set forced one. */
SPH_API int sph_isa(void)
{
#if SPH__DISPATCH
    int *slot = sph__isa_slot(), isa = __atomic_load_n(slot, __ATOMIC_RELAXED);
    if (isa < 0) {
        isa = sph__isa_cpu();
        isa = SPH__PASS_AVX512 || isa < SPH_ISA_AVX512 ? isa : SPH_ISA_AVX2; /* the highest level compiled */
        isa = isa > SPH__ISA_BUILD ? isa : SPH__ISA_BUILD;
        __atomic_store_n(slot, isa, __ATOMIC_RELAXED);
    }
    return isa;
#else
    return SPH__ISA_BUILD;
#endif
}

/* Forces this unit's level (tests, comparisons; SPH_ISA_AUTO: the CPU's
 * best again): SPH_OK, SPH_EOPTION for an unknown level, SPH_EISA when
 * sph_isa_has(isa) is 0 (the level is left as it was). A grid built at
 * one level serves the search at every other (laid out for the widest). */
SPH_API int sph_isa_set(int isa)
{
    if (isa < SPH_ISA_AUTO || isa > SPH_ISA_AVX512) return SPH_EOPTION;
    if (isa != SPH_ISA_AUTO && !sph_isa_has(isa)) return SPH_EISA;
#if SPH__DISPATCH
    __atomic_store_n(sph__isa_slot(), isa, __ATOMIC_RELAXED);
#endif
    return SPH_OK;
}

/* 1 when this unit was compiled with run-time dispatch (section 1). */
SPH_API int sph_isa_dispatch(void) { return SPH__DISPATCH; }

/* ======================================================================== */
/* 3. Kernels                                                                */
/* ======================================================================== */

/* The kernels, in enum order: X(ID, name, description, C) each. It makes the
 * enum, sph_kernel_name, sph_kernel_from_name and the operators' dispatch, and
 * tools/gen_kernel_tables.py makes each kernel's tables from it: a new kernel
 * is one line here and its shape there. C reaches X unchanged (context for an
 * X that needs it, else empty). */
#define SPH_KERNEL_LIST(X, C)                                                           \
    X(CUBIC, cubic, "cubic B-spline M4 (Monaghan & Lattanzio 1985), kappa 2, C2", C)   \
    X(LUCY, lucy, "Lucy quartic (Lucy 1977), kappa 1, C2", C)                          \
    X(NEW_QUARTIC, new_quartic, "new quartic (Liu, Liu & Lam 2003), kappa 2, C1", C)   \
    X(QUINTIC, quintic, "quintic B-spline M6 (Morris 1996), kappa 3, C4", C)           \
    X(WENDLAND_C2, wendland_c2, "Wendland C2 (Wendland 1995), kappa 2", C)             \
    X(WENDLAND_C4, wendland_c4, "Wendland C4 (Wendland 1995), kappa 2", C)             \
    X(WENDLAND_C6, wendland_c6, "Wendland C6 (Wendland 1995), kappa 2", C)             \
    X(QUARTIC, quartic, "quartic B-spline M5 (Schoenberg 1946; Price 2012), kappa 2.5, C3", C)

#define SPH__KERNEL_ENUM(ID, name, description, C) SPH_KERNEL_##ID,
typedef enum { SPH_KERNEL_LIST(SPH__KERNEL_ENUM, ) SPH_KERNEL_COUNT } sph_kernel;
#undef SPH__KERNEL_ENUM

enum { SPH__PIECES = 3 }; /* natural pieces per shape, at most */

/* One polynomial in product form, (b - q)^m P(q - e), P of the given degree
 * with its coefficients lowest power first: next to the root b the value is a
 * product of small numbers, not the difference of large ones. */
typedef struct {
    sph_real b, e;
    int m, degree;
    sph_real c[6];
} sph__pform;

/* A shape w(q) over its natural pieces (at most 3): piece p holds q in
 * [lo[p], lo[p + 1]), and holds w, g and w2 = w''. g is w'(q)/q on the piece
 * holding 0 (finite at q = 0) and w'(q) on the others. */
typedef struct {
    int npiece;
    sph_real kappa; /* support in units of h: w = 0 for q >= kappa */
    sph_real lo[SPH__PIECES];
    struct {
        sph__pform w, g, w2;
    } piece[SPH__PIECES];
} sph__nshape;

/* A kernel in one dimension: which shape, its normalisation, its width. */
typedef struct {
    int shape;      /* index into sph__nshapes */
    sph_real alpha; /* alpha_d: W = alpha_d h^-d w(q) */
    sph_real sigma; /* standard deviation per coordinate, in units of h */
} sph__kdim;

/* ---- GENERATED by tools/gen_kernel_tables.py (make tables): do not edit by hand ---- */
/* Every shape over its natural pieces: pieces, kappa, left ends, then per
   piece the forms of w, g and w'': { b, e, m, degree, P } is
   (b - q)^m P(q - e), P's coefficients lowest power first. g is w'(q)/q on
   the piece holding 0 and w'(q) (divided by q at run time) on the others. */
SPH__TABLE sph__nshape sph__nshapes[] = {
    /* 0 cubic, kappa = 2 */
    { 2, SPH__Q(2, 1), { 0, SPH__Q(1, 1), 0 }, {
        /* [0, 1): w          = (3 q^3 - 6 q^2 + 4)/6
                   w'/q       = (3 q - 4)/2
                   w''        = 3 q - 2 */
        { { SPH__Q(1, 1), SPH__Q(1, 1), 0, 3, { SPH__Q(1, 6), SPH__Q(-1, 2), SPH__Q(1, 2), SPH__Q(1, 2), 0, 0 } },
          { SPH__Q(1, 1), SPH__Q(1, 1), 0, 1, { SPH__Q(-1, 2), SPH__Q(3, 2), 0, 0, 0, 0 } },
          { SPH__Q(1, 1), SPH__Q(1, 2), 0, 1, { SPH__Q(-1, 2), SPH__Q(3, 1), 0, 0, 0, 0 } } },
        /* [1, 2): w          = (2 - q)^3/6
                   w'         = -(2 - q)^2/2
                   w''        = (2 - q) */
        { { SPH__Q(2, 1), SPH__Q(1, 1), 3, 0, { SPH__Q(1, 6), 0, 0, 0, 0, 0 } },
          { SPH__Q(2, 1), SPH__Q(1, 1), 2, 0, { SPH__Q(-1, 2), 0, 0, 0, 0, 0 } },
          { SPH__Q(2, 1), SPH__Q(1, 1), 1, 0, { SPH__Q(1, 1), 0, 0, 0, 0, 0 } } }
    } },
    /* 1 lucy, kappa = 1 */
    { 1, SPH__Q(1, 1), { 0, 0, 0 }, {
        /* [0, 1): w          = (1 - q)^3 (3 q + 1)
                   w'/q       = -12 (1 - q)^2
                   w''        = 12 (1 - q) (3 q - 1) */
        { { SPH__Q(1, 1), 0, 3, 1, { SPH__Q(1, 1), SPH__Q(3, 1), 0, 0, 0, 0 } },
          { SPH__Q(1, 1), 0, 2, 0, { SPH__Q(-12, 1), 0, 0, 0, 0, 0 } },
          { SPH__Q(1, 1), SPH__Q(1, 2), 1, 1, { SPH__Q(6, 1), SPH__Q(36, 1), 0, 0, 0, 0 } } }
    } },
    /* 2 new_quartic, kappa = 2 */
    { 2, SPH__Q(2, 1), { 0, SPH__Q(1, 1), 0 }, {
        /* [0, 1): w          = -(2 - q)^2 (15 q^2 - 16 q - 16)/96
                   w'/q       = (2 - q) (5 q - 9)/8
                   w''        = -(15 q^2 - 38 q + 18)/8 */
        { { SPH__Q(2, 1), 0, 2, 2, { SPH__Q(1, 6), SPH__Q(1, 6), SPH__Q(-5, 32), 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 1, 1, { SPH__Q(-9, 8), SPH__Q(5, 8), 0, 0, 0, 0 } },
          { SPH__Q(2, 1), SPH__Q(1, 2), 0, 2, { SPH__Q(-11, 32), SPH__Q(23, 8), SPH__Q(-15, 8), 0, 0, 0 } } },
        /* [1, 2): w          = -(2 - q)^2 (15 q^2 - 16 q - 16)/96
                   w'         = (2 - q) q (5 q - 9)/8
                   w''        = -(15 q^2 - 38 q + 18)/8 */
        { { SPH__Q(2, 1), SPH__Q(3, 2), 2, 2, { SPH__Q(25, 384), SPH__Q(-29, 96), SPH__Q(-5, 32), 0, 0, 0 } },
          { SPH__Q(2, 1), SPH__Q(3, 2), 1, 2, { SPH__Q(-9, 32), SPH__Q(3, 4), SPH__Q(5, 8), 0, 0, 0 } },
          { SPH__Q(2, 1), SPH__Q(2, 1), 0, 2, { SPH__Q(-1, 4), SPH__Q(-11, 4), SPH__Q(-15, 8), 0, 0, 0 } } }
    } },
    /* 3 quintic, kappa = 3 */
    { 3, SPH__Q(3, 1), { 0, SPH__Q(1, 1), SPH__Q(2, 1) }, {
        /* [0, 1): w          = -2 (5 q^5 - 15 q^4 + 30 q^2 - 33)
                   w'/q       = -10 (5 q^3 - 12 q^2 + 12)
                   w''        = -40 (5 q^3 - 9 q^2 + 3) */
        { { SPH__Q(1, 1), 0, 0, 5, { SPH__Q(66, 1), 0, SPH__Q(-60, 1), 0, SPH__Q(30, 1), SPH__Q(-10, 1) } },
          { SPH__Q(1, 1), 0, 0, 3, { SPH__Q(-120, 1), 0, SPH__Q(120, 1), SPH__Q(-50, 1), 0, 0 } },
          { SPH__Q(1, 1), SPH__Q(1, 1), 0, 3, { SPH__Q(40, 1), SPH__Q(120, 1), SPH__Q(-240, 1), SPH__Q(-200, 1), 0, 0 } } },
        /* [1, 2): w          = 5 q^5 - 45 q^4 + 150 q^3 - 210 q^2 + 75 q + 51
                   w'         = 5 (5 q^4 - 36 q^3 + 90 q^2 - 84 q + 15)
                   w''        = 20 (5 q^3 - 27 q^2 + 45 q - 21) */
        { { SPH__Q(2, 1), SPH__Q(2, 1), 0, 5, { SPH__Q(1, 1), SPH__Q(-5, 1), SPH__Q(10, 1), SPH__Q(-10, 1), SPH__Q(5, 1), SPH__Q(5, 1) } },
          { SPH__Q(2, 1), SPH__Q(2, 1), 0, 4, { SPH__Q(-5, 1), SPH__Q(20, 1), SPH__Q(-30, 1), SPH__Q(20, 1), SPH__Q(25, 1), 0 } },
          { SPH__Q(2, 1), SPH__Q(3, 2), 0, 3, { SPH__Q(105, 2), SPH__Q(-45, 1), SPH__Q(-90, 1), SPH__Q(100, 1), 0, 0 } } },
        /* [2, 3): w          = (3 - q)^5
                   w'         = -5 (3 - q)^4
                   w''        = 20 (3 - q)^3 */
        { { SPH__Q(3, 1), SPH__Q(2, 1), 5, 0, { SPH__Q(1, 1), 0, 0, 0, 0, 0 } },
          { SPH__Q(3, 1), SPH__Q(2, 1), 4, 0, { SPH__Q(-5, 1), 0, 0, 0, 0, 0 } },
          { SPH__Q(3, 1), SPH__Q(2, 1), 3, 0, { SPH__Q(20, 1), 0, 0, 0, 0, 0 } } }
    } },
    /* 4 wendland_c2, kappa = 2 */
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, {
        /* [0, 2): w          = (2 - q)^4 (2 q + 1)/16
                   w'/q       = -5 (2 - q)^3/8
                   w''        = 5 (2 - q)^2 (2 q - 1)/4 */
        { { SPH__Q(2, 1), 0, 4, 1, { SPH__Q(1, 16), SPH__Q(1, 8), 0, 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 3, 0, { SPH__Q(-5, 8), 0, 0, 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 2, 1, { SPH__Q(-5, 4), SPH__Q(5, 2), 0, 0, 0, 0 } } }
    } },
    /* 5 wendland_c2_1d, kappa = 2 */
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, {
        /* [0, 2): w          = (2 - q)^3 (3 q + 2)/16
                   w'/q       = -3 (2 - q)^2/4
                   w''        = 3 (2 - q) (3 q - 2)/4 */
        { { SPH__Q(2, 1), 0, 3, 1, { SPH__Q(1, 8), SPH__Q(3, 16), 0, 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 2, 0, { SPH__Q(-3, 4), 0, 0, 0, 0, 0 } },
          { SPH__Q(2, 1), SPH__Q(1, 1), 1, 1, { SPH__Q(3, 4), SPH__Q(9, 4), 0, 0, 0, 0 } } }
    } },
    /* 6 wendland_c4, kappa = 2 */
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, {
        /* [0, 2): w          = (2 - q)^6 (35 q^2 + 36 q + 12)/768
                   w'/q       = -7 (2 - q)^5 (5 q + 2)/96
                   w''        = 7 (2 - q)^4 (35 q^2 - 8 q - 4)/96 */
        { { SPH__Q(2, 1), 0, 6, 2, { SPH__Q(1, 64), SPH__Q(3, 64), SPH__Q(35, 768), 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 5, 1, { SPH__Q(-7, 48), SPH__Q(-35, 96), 0, 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 4, 2, { SPH__Q(-7, 24), SPH__Q(-7, 12), SPH__Q(245, 96), 0, 0, 0 } } }
    } },
    /* 7 wendland_c4_1d, kappa = 2 */
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, {
        /* [0, 2): w          = (2 - q)^5 (4 q^2 + 5 q + 2)/64
                   w'/q       = -7 (2 - q)^4 (2 q + 1)/32
                   w''        = 7 (2 - q)^3 (12 q^2 - 3 q - 2)/32 */
        { { SPH__Q(2, 1), 0, 5, 2, { SPH__Q(1, 32), SPH__Q(5, 64), SPH__Q(1, 16), 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 4, 1, { SPH__Q(-7, 32), SPH__Q(-7, 16), 0, 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 3, 2, { SPH__Q(-7, 16), SPH__Q(-21, 32), SPH__Q(21, 8), 0, 0, 0 } } }
    } },
    /* 8 wendland_c6, kappa = 2 */
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, {
        /* [0, 2): w          = (2 - q)^8 (16 q^3 + 25 q^2 + 16 q + 4)/1024
                   w'/q       = -11 (2 - q)^7 (8 q^2 + 7 q + 2)/512
                   w''        = 11 (2 - q)^6 (80 q^3 + 15 q^2 - 12 q - 4)/512 */
        { { SPH__Q(2, 1), 0, 8, 3, { SPH__Q(1, 256), SPH__Q(1, 64), SPH__Q(25, 1024), SPH__Q(1, 64), 0, 0 } },
          { SPH__Q(2, 1), 0, 7, 2, { SPH__Q(-11, 256), SPH__Q(-77, 512), SPH__Q(-11, 64), 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 6, 3, { SPH__Q(-11, 128), SPH__Q(-33, 128), SPH__Q(165, 512), SPH__Q(55, 32), 0, 0 } } }
    } },
    /* 9 wendland_c6_1d, kappa = 2 */
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, {
        /* [0, 2): w          = (2 - q)^7 (3 q + 2) (7 q^2 + 8 q + 4)/1024
                   w'/q       = -3 (2 - q)^6 (35 q^2 + 36 q + 12)/512
                   w''        = 9 (2 - q)^5 (105 q^3 + 26 q^2 - 20 q - 8)/512 */
        { { SPH__Q(2, 1), 0, 7, 3, { SPH__Q(1, 128), SPH__Q(7, 256), SPH__Q(19, 512), SPH__Q(21, 1024), 0, 0 } },
          { SPH__Q(2, 1), 0, 6, 2, { SPH__Q(-9, 128), SPH__Q(-27, 128), SPH__Q(-105, 512), 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 5, 3, { SPH__Q(-9, 64), SPH__Q(-45, 128), SPH__Q(117, 256), SPH__Q(945, 512), 0, 0 } } }
    } },
    /* 10 quartic, kappa = 5/2 */
    { 3, SPH__Q(5, 2), { 0, SPH__Q(1, 2), SPH__Q(3, 2) }, {
        /* [0, 1/2): w          = (48 q^4 - 120 q^2 + 115)/8
                     w'/q       = 6 (4 q^2 - 5)
                     w''        = 6 (12 q^2 - 5) */
        { { SPH__Q(1, 2), 0, 0, 4, { SPH__Q(115, 8), 0, SPH__Q(-15, 1), 0, SPH__Q(6, 1), 0 } },
          { SPH__Q(1, 2), 0, 0, 2, { SPH__Q(-30, 1), 0, SPH__Q(24, 1), 0, 0, 0 } },
          { SPH__Q(1, 2), SPH__Q(1, 2), 0, 2, { SPH__Q(-12, 1), SPH__Q(72, 1), SPH__Q(72, 1), 0, 0, 0 } } },
        /* [1/2, 3/2): w          = -(16 q^4 - 80 q^3 + 120 q^2 - 20 q - 55)/4
                       w'         = -16 q^3 + 60 q^2 - 60 q + 5
                       w''        = -12 (4 q^2 - 10 q + 5) */
        { { SPH__Q(3, 2), SPH__Q(3, 2), 0, 4, { SPH__Q(1, 1), SPH__Q(-4, 1), SPH__Q(6, 1), SPH__Q(-4, 1), SPH__Q(-4, 1), 0 } },
          { SPH__Q(3, 2), SPH__Q(3, 2), 0, 3, { SPH__Q(-4, 1), SPH__Q(12, 1), SPH__Q(-12, 1), SPH__Q(-16, 1), 0, 0 } },
          { SPH__Q(3, 2), SPH__Q(1, 1), 0, 2, { SPH__Q(12, 1), SPH__Q(24, 1), SPH__Q(-48, 1), 0, 0, 0 } } },
        /* [3/2, 5/2): w          = (5/2 - q)^4
                       w'         = -4 (5/2 - q)^3
                       w''        = 12 (5/2 - q)^2 */
        { { SPH__Q(5, 2), SPH__Q(3, 2), 4, 0, { SPH__Q(1, 1), 0, 0, 0, 0, 0 } },
          { SPH__Q(5, 2), SPH__Q(3, 2), 3, 0, { SPH__Q(-4, 1), 0, 0, 0, 0, 0 } },
          { SPH__Q(5, 2), SPH__Q(3, 2), 2, 0, { SPH__Q(12, 1), 0, 0, 0, 0, 0 } } }
    } }
};
/* Every shape index: the pair loops of sections 6 and 9 are instantiated once
   per shape, and a case per shape selects the instance. */
#define SPH__SHAPE_IDS(X) X(0) X(1) X(2) X(3) X(4) X(5) X(6) X(7) X(8) X(9) X(10)

/* Per kernel (SPH_KERNEL_LIST order) and dimension 1..3: shape, alpha_d and
   sigma_d / h (exact integration, rounded once). */
SPH__TABLE sph__kdim sph__kdims[][3] = {
    { /* cubic: cubic B-spline M4 (Monaghan & Lattanzio 1985), kappa 2, C2 */
        { 0, SPH__C(1.00000000000000000000), SPH__C(0.577350269189625764509) }, /* 1D: alpha = 1, sigma/h = sqrt(3)/3 */
        { 0, SPH__C(0.682092613250980010438), SPH__C(0.562429133857986501406) }, /* 2D: alpha = 15/(7*pi), sigma/h = sqrt(62)/14 */
        { 0, SPH__C(0.477464829275686007307), SPH__C(0.547722557505166113457) }  /* 3D: alpha = 3/(2*pi), sigma/h = sqrt(30)/10 */
    },
    { /* lucy: Lucy quartic (Lucy 1977), kappa 1, C2 */
        { 1, SPH__C(1.25000000000000000000), SPH__C(0.308606699924183820522) }, /* 1D: alpha = 5/4, sigma/h = sqrt(42)/21 */
        { 1, SPH__C(1.59154943091895335769), SPH__C(0.298807152333598409992) }, /* 2D: alpha = 5/pi, sigma/h = sqrt(70)/28 */
        { 1, SPH__C(2.08890862808112628197), SPH__C(0.288675134594812882255) }  /* 3D: alpha = 105/(16*pi), sigma/h = sqrt(3)/6 */
    },
    { /* new_quartic: new quartic (Liu, Liu & Lam 2003), kappa 2, C1 */
        { 2, SPH__C(1.00000000000000000000), SPH__C(0.574594404914223089000) }, /* 1D: alpha = 1, sigma/h = 2*sqrt(910)/105 */
        { 2, SPH__C(0.682092613250980010438), SPH__C(0.553283335172488126454) }, /* 2D: alpha = 15/(7*pi), sigma/h = sqrt(15)/7 */
        { 2, SPH__C(0.482055837249490680454), SPH__C(0.531085004543794336722) }  /* 3D: alpha = 315/(208*pi), sigma/h = sqrt(429)/39 */
    },
    { /* quintic: quintic B-spline M6 (Morris 1996), kappa 3, C4 */
        { 3, SPH__C(0.00833333333333333333333), SPH__C(0.707106781186547524401) }, /* 1D: alpha = 1/120, sigma/h = sqrt(2)/2 */
        { 3, SPH__C(0.00466144184787977970871), SPH__C(0.695046229260274514650) }, /* 2D: alpha = 7/(478*pi), sigma/h = sqrt(3973614)/2868 */
        { 3, SPH__C(0.00265258238486492226281), SPH__C(0.683130051063973225548) }  /* 3D: alpha = 1/(120*pi), sigma/h = sqrt(105)/15 */
    },
    { /* wendland_c2: Wendland C2 (Wendland 1995), kappa 2 */
        { 5, SPH__C(0.625000000000000000000), SPH__C(0.617213399848367641044) }, /* 1D: alpha = 5/8, sigma/h = 2*sqrt(42)/21 */
        { 4, SPH__C(0.557042300821633675191), SPH__C(0.527046276694729888666) }, /* 2D: alpha = 7/(4*pi), sigma/h = sqrt(10)/6 */
        { 4, SPH__C(0.417781725616225256393), SPH__C(0.516397779494322251357) }  /* 3D: alpha = 21/(16*pi), sigma/h = 2*sqrt(15)/15 */
    },
    { /* wendland_c4: Wendland C4 (Wendland 1995), kappa 2 */
        { 7, SPH__C(0.750000000000000000000), SPH__C(0.516397779494322251357) }, /* 1D: alpha = 3/4, sigma/h = 2*sqrt(15)/15 */
        { 6, SPH__C(0.716197243913529010960), SPH__C(0.460566186471838291869) }, /* 2D: alpha = 9/(4*pi), sigma/h = sqrt(231)/33 */
        { 6, SPH__C(0.615482006488188993794), SPH__C(0.452910813657838300244) }  /* 3D: alpha = 495/(256*pi), sigma/h = 2*sqrt(78)/39 */
    },
    { /* wendland_c6: Wendland C6 (Wendland 1995), kappa 2 */
        { 9, SPH__C(0.859375000000000000000), SPH__C(0.452910813657838300244) }, /* 1D: alpha = 55/64, sigma/h = 2*sqrt(78)/39 */
        { 8, SPH__C(0.886720397226274013569), SPH__C(0.414039335605412530678) }, /* 2D: alpha = 39/(14*pi), sigma/h = sqrt(210)/35 */
        { 8, SPH__C(0.848619130157957552049), SPH__C(0.408248290463863016366) }  /* 3D: alpha = 1365/(512*pi), sigma/h = sqrt(6)/6 */
    },
    { /* quartic: quartic B-spline M5 (Schoenberg 1946; Price 2012), kappa 2.5, C3 */
        { 10, SPH__C(0.0416666666666666666667), SPH__C(0.645497224367902814197) }, /* 1D: alpha = 1/24, sigma/h = sqrt(15)/6 */
        { 10, SPH__C(0.0254860292524135983883), SPH__C(0.632215880892298243746) }, /* 2D: alpha = 96/(1199*pi), sigma/h = sqrt(14892234)/6104 */
        { 10, SPH__C(0.0159154943091895335769), SPH__C(0.619139187366890332366) }  /* 3D: alpha = 1/(20*pi), sigma/h = sqrt(345)/30 */
    }
};
/* ---- end of GENERATED tables ---- */

/* A kernel of SPH_KERNEL_LIST without its row (a stale block: run make tables)
 * does not compile. */
typedef char sph__kdims_cover_the_list[(int)(sizeof sph__kdims / sizeof sph__kdims[0]) == (int)SPH_KERNEL_COUNT ? 1 : -1];

/* Complete unrolling of the short constant-count loops of the product forms
 * (gcc's default limits leave the quintic's nest rolled, and unvectorised). */
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__) && !defined(__INTEL_COMPILER) && __GNUC__ >= 8
#define SPH__UNROLL _Pragma("GCC unroll 8")
#else
#define SPH__UNROLL
#endif

/* (b - q)^m P(q - e): one form of sph__nshapes, in the pair loops. */
SPH__INLINE sph_real sph__pform_eval(const sph__pform *f, sph_real q)
{
    const sph_real t = f->b - q, u = q - f->e;
    sph_real p = f->c[f->degree], tm = 1;
    int i;
    SPH__UNROLL
    for (i = f->degree - 1; i >= 0; --i) p = p * u + f->c[i];
    SPH__UNROLL
    for (i = 0; i < f->m; ++i) tm *= t;
    return tm * p;
}

/* Form G (0 w, 1 g, 2 w'') of piece p. */
SPH__INLINE const sph__pform *sph__nshape_form(const sph__nshape *s, int p, const int G)
{
    return G == 0 ? &s->piece[p].w : G == 1 ? &s->piece[p].g : &s->piece[p].w2;
}

/* For the pair loops, form G of the natural piece holding q >= 0: every piece
 * is evaluated and the one holding q selected by comparisons, so a loop over
 * pairs has no branch and no per-pair table gather (the forms are constants
 * of the kernel). */
SPH__INLINE sph_real sph__nshape_pick(const sph__nshape *s, const int G, sph_real q)
{
    sph_real v = sph__pform_eval(sph__nshape_form(s, 0, G), q);
    const int np = s->npiece < SPH__PIECES ? s->npiece : SPH__PIECES; /* no read past the table */
    int p;
    SPH__UNROLL
    for (p = 1; p < np; ++p) {
        const sph_real x = sph__pform_eval(sph__nshape_form(s, p, G), q);
        v = q >= s->lo[p] ? x : v;
    }
    return v;
}

/* docs/kernels.md eq. (K1), pair loops: w(q); 0 for q >= kappa and NaN. */
SPH__INLINE sph_real sph__nshape_w(const sph__nshape *s, sph_real q)
{
    const sph_real w = sph__nshape_pick(s, 0, q);
    return q < s->kappa ? w : 0;
}

/* (K2), pair loops: g(q) = w'(q)/q the same way; the piece holding 0 has q
 * divided out exactly (finite at q = 0), the others divide by q: one division
 * per pair. */
SPH__INLINE sph_real sph__nshape_g(const sph__nshape *s, sph_real q)
{
    sph_real g = sph__nshape_pick(s, 1, q);
    if (s->npiece > 1) g /= q >= s->lo[1] ? q : 1;
    return q < s->kappa ? g : 0;
}

/* Lanes of a pair batch (section 9, sph_batch): the pair loops evaluate the
 * kernel over SPH_BATCH pairs at once, each step of the arithmetic a loop
 * over the lanes, so that it compiles to SIMD (16 floats or 8 doubles fill
 * one AVX-512 register; bench/pair_once.c measured 16 faster than 8 and 32
 * in double as well). A power of two, 4..64. */
#ifndef SPH_BATCH
#define SPH_BATCH 16
#endif
/* Before a lane loop: gcc would otherwise unroll the short loop of constant
 * count completely before its loop vectoriser runs, and leave much of it
 * scalar (gcc 12, measured: twice the time of sph_batch_fill). */
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__) && !defined(__INTEL_COMPILER) && __GNUC__ >= 8
#define SPH__LANES _Pragma("GCC unroll 1")
#else
#define SPH__LANES
#endif
typedef char sph__batch_width_ok[SPH_BATCH >= 4 && SPH_BATCH <= 64 && (SPH_BATCH & (SPH_BATCH - 1)) == 0 ? 1 : -1];

/* sph__pform_eval over the lanes: v[l] = (b - q[l])^m P(q[l] - e), the same
 * operations in the same order, so each lane holds its bits. The loops over
 * the form's degree and power are outer and the lanes inner: one vector
 * operation per step whatever the kernel. */
SPH__INLINE void sph__pform_lanes(const sph__pform *f, const sph_real *q, sph_real *v)
{
    sph_real t[SPH_BATCH], u[SPH_BATCH], tm[SPH_BATCH];
    const sph_real b = f->b, e = f->e;
    int i, l;
    SPH__LANES
    for (l = 0; l < SPH_BATCH; ++l) {
        t[l] = b - q[l];
        u[l] = q[l] - e;
        v[l] = f->c[f->degree];
        tm[l] = 1;
    }
    for (i = f->degree - 1; i >= 0; --i) {
        const sph_real c = f->c[i];
        SPH__LANES
        for (l = 0; l < SPH_BATCH; ++l) v[l] = v[l] * u[l] + c;
    }
    for (i = 0; i < f->m; ++i) {
        SPH__LANES
        for (l = 0; l < SPH_BATCH; ++l) tm[l] *= t[l];
    }
    SPH__LANES
    for (l = 0; l < SPH_BATCH; ++l) v[l] = tm[l] * v[l];
}

/* (K1), (K2) over the lanes: w[l] = w(q[l]) and g[l] = w'(q[l]) / q[l] as
 * sph__nshape_w and sph__nshape_g give them, bit for bit: every piece
 * evaluated, the one holding q selected, 0 from kappa on; branch-free.
 * w or g NULL: that one is not evaluated. */
SPH__INLINE void sph__nshape_wg_lanes(const sph__nshape *s, const sph_real *q, sph_real *w, sph_real *g)
{
    sph_real x[SPH_BATCH];
    const int np = s->npiece < SPH__PIECES ? s->npiece : SPH__PIECES;
    const sph_real kappa = s->kappa;
    int G, p, l;
    for (G = 0; G < 2; ++G) {
        sph_real *v = G == 0 ? w : g;
        if (v == NULL) continue;
        sph__pform_lanes(sph__nshape_form(s, 0, G), q, v);
        for (p = 1; p < np; ++p) {
            const sph_real lo = s->lo[p];
            sph__pform_lanes(sph__nshape_form(s, p, G), q, x);
            SPH__LANES
            for (l = 0; l < SPH_BATCH; ++l) v[l] = q[l] >= lo ? x[l] : v[l];
        }
        if (G == 1 && np > 1) {
            const sph_real lo = s->lo[1];
            SPH__LANES
            for (l = 0; l < SPH_BATCH; ++l) x[l] = q[l] >= lo ? q[l] : 1;
            SPH__LANES /* apart: a division under a select stays scalar (gcc -O2) */
            for (l = 0; l < SPH_BATCH; ++l) v[l] /= x[l];
        }
        SPH__LANES
        for (l = 0; l < SPH_BATCH; ++l) v[l] = q[l] < kappa ? v[l] : 0;
    }
}

/* The same form for the scalar functions: in double whatever sph_real is, and
 * with the rounding error of t = b - q taken back (b - q = t + dt exactly,
 * Fast2Sum; (t + dt)^m = t^m + m t^(m-1) dt to first order), which (2 - q)^8
 * would otherwise raise to 4 eps next to q = 1. With SPH_REAL float a value
 * is then the form rounded once, so W is as monotone as w to the last bit. */
SPH_API double sph__pform_at(const sph__pform *f, double q)
{
    const double b = (double)f->b, t = b - q, u = q - (double)f->e;
    double p = (double)f->c[f->degree], tm = 1;
    int i;
    for (i = f->degree - 1; i >= 0; --i) p = p * u + (double)f->c[i];
    for (i = 1; i < f->m; ++i) tm *= t;
    if (f->m > 0) tm = tm * t + (double)f->m * tm * ((b - t) - q);
    return tm * p;
}

/* What the scalar functions take of the shape: w, g = w'/q, w'', w'. */
enum { SPH__SW, SPH__SG, SPH__SW2, SPH__SW1 };

/* w, g, w'' or w' at q >= 0 for the scalar functions, 0 for q >= kappa: the
 * piece holding q alone, by sph__pform_at. */
SPH_API double sph__shape_at(const sph__nshape *s, int what, sph_real q)
{
    int p = s->npiece - 1;
    double v;
    if (!(q < s->kappa)) return 0;
    while (p > 0 && q < s->lo[p]) --p;
    v = sph__pform_at(sph__nshape_form(s, p, what == SPH__SW1 ? SPH__SG : what), (double)q);
    if (what == SPH__SG && p > 0) v /= (double)q; /* g holds w' off the piece holding 0 */
    if (what == SPH__SW1 && p == 0) v *= (double)q; /* and w'/q on it */
    return v;
}

/* x * hinv^n, scaling last so intermediate values stay representable. */
SPH_API sph_real sph__hpow(sph_real x, sph_real hinv, int n)
{
    int i;
    for (i = 0; i < n; ++i) x *= hinv;
    return x;
}

/* SPH_OK when kernel k is defined in dimension dim, else SPH_EKERNEL/SPH_EDIM.
 * Every kernel here is defined in 1, 2 and 3 dimensions (1-D Wendland uses
 * Wendland's 1-D functions, see docs/kernels.md). */
SPH_API int sph_kernel_check(sph_kernel k, int dim)
{
    if ((int)k < 0 || (int)k >= (int)SPH_KERNEL_COUNT) return SPH_EKERNEL;
    if (dim < 1 || dim > 3) return SPH_EDIM;
    return SPH_OK;
}

/* A bound on alpha_d times |w|, |w'/q|, |w'|, |w''| and |d w + q w'| over
 * every kernel, dimension and q (the largest is Lucy's 3-D alpha_3 |w'/q| at
 * q = 0, 25.07), so that W, F, dW/dr, d2W/dr2 and dW/dh are all bounded by
 * SPH__SHAPE_MAX h^-(d+2) for h <= 1 and by SPH__SHAPE_MAX for h > 1. */
#define SPH__SHAPE_MAX 64

/* 1 when h is a usable smoothing length in dim dimensions: positive, finite,
 * and SPH__SHAPE_MAX h^-(dim+2) finite, so that every kernel quantity of
 * every kernel is finite in sph_real (the scalar functions and the pair
 * kernel take h in the caller's dim, the operators in ctx.dim). */
SPH_API int sph__h_ok(sph_real h, int dim)
{
    return h > 0 && h <= SPH__REAL_MAX && sph__hpow(SPH__SHAPE_MAX, 1 / h, dim + 2) <= SPH__REAL_MAX;
}

/* SPH_OK when h is a usable smoothing length in every dimension: positive,
 * finite and not so small that W, F or any other kernel quantity of any
 * kernel in 3-D overflows sph_real (64 h^-5 finite: h above about 5.1e-62
 * in double, 4.5e-8 in float); else SPH_EH. */
SPH_API int sph_check_h(sph_real h)
{
    return sph__h_ok(h, 3) ? SPH_OK : SPH_EH;
}

/* The per-dimension data of (k, dim), or NULL for invalid arguments. */
SPH_API const sph__kdim *sph__kd(sph_kernel k, int dim)
{
    return sph_kernel_check(k, dim) == SPH_OK ? &sph__kdims[k][dim - 1] : NULL;
}

/* Validates (k, dim, r, h) for the scalar API; on success sets the data,
 * 1/h and q = r/h. */
SPH_API const sph__kdim *sph__prep(sph_kernel k, int dim, sph_real r, sph_real h,
                                   sph_real *hinv, sph_real *q)
{
    const sph__kdim *kd = sph__kd(k, dim);
    if (kd == NULL || !sph__h_ok(h, dim) || !(r >= 0 && r <= SPH__REAL_MAX)) return NULL;
    *hinv = 1 / h;
    *q = r / h; /* one rounding: r = kappa h gives q = kappa exactly */
    /* beyond the support (r / h may even overflow to Inf): every form is 0
     * at q = kappa, and products with q stay finite */
    if (!(*q < sph__nshapes[kd->shape].kappa)) *q = sph__nshapes[kd->shape].kappa;
    return kd;
}

/* kappa: W(r, h) = 0 for r >= kappa h (0 for an unknown kernel). */
SPH_API sph_real sph_kernel_support(sph_kernel k)
{
    return sph_kernel_check(k, 1) == SPH_OK ? sph__nshapes[sph__kdims[k][0].shape].kappa : 0;
}

/* Short lower-case identifier ("cubic", "wendland_c4", ...); "invalid" otherwise. */
SPH_API const char *sph_kernel_name(sph_kernel k)
{
    switch (k) {
#define SPH__KERNEL_NAME(ID, name, description, C) case SPH_KERNEL_##ID: return #name;
    SPH_KERNEL_LIST(SPH__KERNEL_NAME, )
#undef SPH__KERNEL_NAME
    default: return "invalid";
    }
}

/* Inverse of sph_kernel_name; SPH_EKERNEL for an unknown name (or NULL). */
SPH_API int sph_kernel_from_name(const char *name)
{
    int k;
    for (k = 0; name != NULL && k < (int)SPH_KERNEL_COUNT; ++k) {
        const char *a = name, *b = sph_kernel_name((sph_kernel)k);
        while (*a != '\0' && *a == *b) ++a, ++b;
        if (*a == '\0' && *b == '\0') return k;
    }
    return SPH_EKERNEL;
}

/* alpha_d, the normalisation: W(r, h) = alpha_d h^-d w(r/h). 0 if invalid. */
SPH_API sph_real sph_kernel_alpha(sph_kernel k, int dim)
{
    const sph__kdim *kd = sph__kd(k, dim);
    return kd ? kd->alpha : 0;
}

/* Standard deviation of W per coordinate in units of h,
 * sigma^2 = (1/d) int |x|^2 W d^dx (docs/kernels.md eq. (K5)); kernels of equal
 * sigma h resolve equally (Dehnen & Aly 2012). 0 if invalid. */
SPH_API sph_real sph_kernel_sigma(sph_kernel k, int dim)
{
    const sph__kdim *kd = sph__kd(k, dim);
    return kd ? kd->sigma : 0;
}

/* Volume of the unit ball in dim dimensions (2, pi, 4 pi / 3). */
SPH_API sph_real sph__unit_ball(int dim)
{
    return dim == 1 ? (sph_real)2
         : dim == 2 ? SPH__C(3.14159265358979323846)
                    : SPH__C(4.18879020478639098462);
}

/* Expected number of neighbours inside the support (the particle itself
 * included) for particles of volume V = m / rho (docs/kernels.md eq. (K6)):
 * N = omega_d (kappa h)^d / V. 0 if invalid (V not positive and finite) and
 * where N overflows sph_real. */
SPH_API sph_real sph_kernel_neighbours(sph_kernel k, int dim, sph_real h, sph_real volume)
{
    const sph_real kh = sph_kernel_support(k) * h;
    sph_real n;
    if (sph_kernel_check(k, dim) != SPH_OK || !(volume > 0 && volume <= SPH__REAL_MAX) || !sph__h_ok(h, dim))
        return 0;
    n = sph__unit_ball(dim) * (dim == 1 ? kh : dim == 2 ? kh * kh : kh * kh * kh) / volume;
    return sph__finite(n) ? n : 0;
}

/* The h that puts n_neigh neighbours (self included) inside the support of a
 * particle of volume V = m / rho: the inverse of sph_kernel_neighbours. 0 if
 * invalid (n_neigh or V not positive and finite) and where n_neigh V
 * overflows sph_real. */
SPH_API sph_real sph_kernel_h_for_neighbours(sph_kernel k, int dim, sph_real n_neigh,
                                             sph_real volume)
{
    sph_real x;
    if (sph_kernel_check(k, dim) != SPH_OK || !(volume > 0 && volume <= SPH__REAL_MAX) ||
        !(n_neigh > 0 && n_neigh <= SPH__REAL_MAX))
        return 0;
    x = n_neigh * volume / sph__unit_ball(dim);
    x = dim == 1 ? x : dim == 2 ? sph__sqrt(x) : (sph_real)cbrt((double)x);
    x /= sph_kernel_support(k);
    return sph__finite(x) ? x : 0;
}

/* The scalar kernel quantities, each alpha_d h^-p times a shape value. */
enum { SPH__W, SPH__F, SPH__DWDR, SPH__D2WDR2, SPH__DWDH };

SPH_API sph_real sph__scalar(sph_kernel k, int dim, sph_real r, sph_real h, int what)
{
    sph_real hinv = 0, q = 0;
    const sph__kdim *kd = sph__prep(k, dim, r, h, &hinv, &q);
    const sph__nshape *s = kd ? &sph__nshapes[kd->shape] : NULL;
    if (kd == NULL) return 0;
    switch (what) {
    case SPH__W: return sph__hpow(kd->alpha * (sph_real)sph__shape_at(s, SPH__SW, q), hinv, dim);
    case SPH__F: return sph__hpow(kd->alpha * (sph_real)sph__shape_at(s, SPH__SG, q), hinv, dim + 2);
    case SPH__DWDR: return sph__hpow(kd->alpha * (sph_real)sph__shape_at(s, SPH__SW1, q), hinv, dim + 1);
    case SPH__D2WDR2: return sph__hpow(kd->alpha * (sph_real)sph__shape_at(s, SPH__SW2, q), hinv, dim + 2);
    default: /* (K7): d w + q w' */
        return -sph__hpow(kd->alpha * (sph_real)(dim * sph__shape_at(s, SPH__SW, q) + (double)q * sph__shape_at(s, SPH__SW1, q)),
                          hinv, dim + 1);
    }
}

/* docs/kernels.md eq. (K1): W(r, h) = alpha_d h^-d w(r/h). */
SPH_API sph_real sph_kernel_w(sph_kernel k, int dim, sph_real r, sph_real h)
{
    return sph__scalar(k, dim, r, h, SPH__W);
}

/* docs/kernels.md eq. (K2): F = (1/r) dW/dr = alpha_d h^-(d+2) w'(q)/q, finite at r = 0. */
SPH_API sph_real sph_kernel_f(sph_kernel k, int dim, sph_real r, sph_real h)
{
    return sph__scalar(k, dim, r, h, SPH__F);
}

/* docs/kernels.md eq. (K3): dW/dr = alpha_d h^-(d+1) w'(q). */
SPH_API sph_real sph_kernel_dwdr(sph_kernel k, int dim, sph_real r, sph_real h)
{
    return sph__scalar(k, dim, r, h, SPH__DWDR);
}

/* docs/kernels.md eq. (K4): d2W/dr2 = alpha_d h^-(d+2) w''(q). */
SPH_API sph_real sph_kernel_d2wdr2(sph_kernel k, int dim, sph_real r, sph_real h)
{
    return sph__scalar(k, dim, r, h, SPH__D2WDR2);
}

/* docs/kernels.md eq. (K7): dW/dh = -(d W + r dW/dr) / h = -alpha_d h^-(d+1) (d w + q w'). */
SPH_API sph_real sph_kernel_dwdh(sph_kernel k, int dim, sph_real r, sph_real h)
{
    return sph__scalar(k, dim, r, h, SPH__DWDH);
}

/* docs/kernels.md eq. (K1), (K2) together: W and F with one validation. */
SPH_API void sph_kernel_wf(sph_kernel k, int dim, sph_real r, sph_real h, sph_real *W,
                           sph_real *F)
{
    sph_real hinv = 0, q = 0;
    const sph__kdim *kd = sph__prep(k, dim, r, h, &hinv, &q);
    if (kd == NULL) {
        *W = 0;
        *F = 0;
        return;
    }
    *W = sph__hpow(kd->alpha * (sph_real)sph__shape_at(&sph__nshapes[kd->shape], SPH__SW, q), hinv, dim);
    *F = sph__hpow(kd->alpha * (sph_real)sph__shape_at(&sph__nshapes[kd->shape], SPH__SG, q), hinv, dim + 2);
}

/* docs/kernels.md eq. (K8): grad_i W_ij = F x_ij, dx = x_i - x_j (dim components).
 * Computed as alpha_d h^-(d+1) g(q) (dx / h) so that it stays representable
 * wherever the gradient is. Writes zeros for invalid input or non-finite dx. */
SPH_API void sph_kernel_grad(sph_kernel k, int dim, const sph_real *dx, sph_real h,
                             sph_real *grad)
{
    sph_real s[3] = {0, 0, 0}, q2 = 0, G;
    const sph__kdim *kd = sph__kd(k, dim);
    int a;
    if (kd == NULL || dx == NULL || grad == NULL || !sph__h_ok(h, dim)) {
        for (a = 0; grad != NULL && a < dim && a < 3; ++a) grad[a] = 0;
        return;
    }
    for (a = 0; a < dim; ++a) {
        s[a] = dx[a] / h;
        q2 += s[a] * s[a];
    }
    G = sph__hpow(kd->alpha * (sph_real)sph__shape_at(&sph__nshapes[kd->shape], SPH__SG, sph__sqrt(q2)), 1 / h, dim + 1);
    for (a = 0; a < dim; ++a) grad[a] = G != 0 ? G * s[a] : 0;
}

#if !defined(SPH_ONLY_KERNELS) /* section 4 */

/* ======================================================================== */
/* 4. Particle data: strided views, neighbour lists, periodic box            */
/* ======================================================================== */
/* Shared by the pair terms, operators and neighbour search (sections 5-7).
 * Every array belongs to the caller and is read in place, never copied. */

typedef int32_t sph_idx; /* particle index (targets and sources) */
typedef int64_t sph_off; /* position in a neighbour list */

/* A read-only field of ncomp (1..3) components per particle: component a of
 * particle i is p[a][i * stride]. One view reads structure-of-arrays
 * (p = {x, y, z}, stride 1), interleaved (p = {x, x+1, x+2}, stride 3) and
 * array-of-structs (p = {&s[0].x, &s[0].y, ...}, stride sizeof(s[0]) /
 * sizeof(sph_real)) alike. */
typedef struct {
    const sph_real *p[3];
    ptrdiff_t stride;
} sph_view;

/* The same for output fields. */
typedef struct {
    sph_real *p[3];
    ptrdiff_t stride;
} sph_out;

/* An axis-aligned box [lo, lo + length) with per-axis periodicity (minimum
 * image). Pass NULL where a function takes a box and there is none. */
typedef struct {
    sph_real lo[3];
    sph_real length[3];
    int periodic[3]; /* non-zero: axis a is periodic with period length[a] */
} sph_box;

/* box_known of a list whose box is the one it was built with. A tag, not 1:
 * a list assembled field by field, its flag never set, does not claim a box. */
#define SPH_BOX_KNOWN 0x53504842

/* Neighbour lists in CSR form: the sources of target i are
 * index[offset[i]] .. index[offset[i+1]-1], each in 0..n_sources-1. The
 * list carries the box of its search (a copy: it outlives the grid), so
 * that the operators and section 9 take the periodic axes from it when
 * ctx.box is NULL and refuse a different ctx.box (SPH_EBOX). */
typedef struct {
    sph_idx n_targets;
    sph_idx n_sources;
    const sph_off *offset; /* [n_targets + 1], offset[0] = 0, non-decreasing */
    const sph_idx *index;  /* [offset[n_targets]] */
    sph_box box;           /* the search's box (no periodic axis: an open search) when box_known */
    int box_known;         /* SPH_BOX_KNOWN (sph_nsearch_list sets it); any other value: box unknown */
} sph_neighbours;

/* A list of the caller's arrays with box unknown, as an initialiser (also of
 * a static list): sph_neighbours L = SPH_NEIGHBOURS_INIT(nt, ns, offset, index); */
#define SPH_NEIGHBOURS_INIT(n_targets, n_sources, offset, index) \
    { (n_targets), (n_sources), (offset), (index), { { 0, 0, 0 }, { 0, 0, 0 }, { 0, 0, 0 } }, 0 }

/* Minimum image of one component of x_i - x_j (docs/operators.md eq. (O0)):
 * along a periodic axis of length L, dx - L * round(dx / L), so |dx| <= L/2
 * whatever multiple of L the two positions are apart. Unchanged when box is
 * NULL, a is outside 0..2, the axis is not periodic or its length not
 * positive and finite, and where there is no image to take (dx NaN or
 * infinite, or dx / L beyond the largest sph_real). Every part of the
 * library (and the brute-force references of the tests) uses this one
 * function. */
SPH_API sph_real sph_box_delta(const sph_box *box, int a, sph_real dx)
{
    sph_real L, d;
    if (box == NULL || a < 0 || a > 2 || !box->periodic[a]) return dx;
    L = box->length[a];
    if (!(L > 0 && L <= SPH__REAL_MAX)) return dx;
    d = dx - sph__mul_rn(L, sph__floor(dx / L + (sph_real)0.5)); /* the product rounded: the same image in any unit */
    return sph__finite(d) ? d : dx;
}

/* SPH_OK when every periodic axis below dim of box (NULL: none) has a
 * length L > 0 with L and 1/L finite ((O0) takes 1/L); else SPH_EBOXLEN. */
SPH_API int sph__box_ok(const sph_box *box, int dim)
{
    int a;
    for (a = 0; box != NULL && a < dim && a < 3; ++a)
        if (box->periodic[a] &&
            !(box->length[a] > 0 && box->length[a] <= SPH__REAL_MAX && 1 / box->length[a] <= SPH__REAL_MAX))
            return SPH_EBOXLEN;
    return SPH_OK;
}

/* The box the minimum image (O0) uses over list in dim dimensions: box when
 * given, else the list's own (NULL when it has none). SPH_EBOX when both are
 * known and differ on an axis below dim (periodic or not, or the period,
 * compared exactly: lo plays no part in (O0)); SPH_EBOXLEN for an unusable
 * axis. */
SPH_API int sph__box_of(const sph_box *box, const sph_neighbours *list, int dim, const sph_box **out)
{
    const sph_box *own = list != NULL && list->box_known == SPH_BOX_KNOWN ? &list->box : NULL;
    int a, st;
    *out = box != NULL ? box : own;
    if ((st = sph__box_ok(*out, dim)) != SPH_OK) return st;
    for (a = 0; box != NULL && own != NULL && a < dim && a < 3; ++a)
        if ((box->periodic[a] != 0) != (own->periodic[a] != 0) ||
            (box->periodic[a] && box->length[a] != own->length[a]))
            return SPH_EBOX;
    return SPH_OK;
}

/* SPH_OK when list is a well-formed CSR list: counts >= 0 (else SPH_ECOUNT),
 * offset[0] = 0 and non-decreasing (else SPH_EOFFSET), every index in
 * 0..n_sources-1 (else SPH_EINDEX), arrays present (else SPH_ENULL).
 * Cost: one pass over offset and index. Run it once per list and set
 * ctx.validate = SPH_VALIDATE_ARGS to skip it in the operators. */
SPH_API int sph_neighbours_check(const sph_neighbours *list)
{
    const sph_off block = 4096; /* tested without a branch inside: the compiler vectorises each block */
    sph_off o, e, end;
    if (list == NULL || list->offset == NULL) return SPH_ENULL;
    if (list->n_targets < 0 || list->n_sources < 0) return SPH_ECOUNT;
    if (list->offset[0] != 0) return SPH_EOFFSET;
    for (o = 0; o < list->n_targets; o = e) {
        int bad = 0;
        sph_off t;
        e = list->n_targets - o > block ? o + block : list->n_targets;
        for (t = o; t < e; ++t) bad |= list->offset[t + 1] < list->offset[t];
        if (bad) return SPH_EOFFSET;
    }
    end = list->offset[list->n_targets];
    if (end > 0 && list->index == NULL) return SPH_ENULL;
    for (o = 0; o < end; o = e) {
        const uint32_t ns = (uint32_t)list->n_sources; /* one unsigned comparison: a negative index wraps above */
        int bad = 0;
        sph_off t;
        e = end - o > block ? o + block : end;
        for (t = o; t + 32 <= e; t += 32) { /* a fixed count: vectorised at -O2 too */
            int k;
            for (k = 0; k < 32; ++k) bad |= (uint32_t)list->index[t + k] >= ns;
        }
        for (; t < e; ++t) bad |= (uint32_t)list->index[t] >= ns;
        if (bad) return SPH_EINDEX;
    }
    return SPH_OK;
}

/* SPH_ENONFINITE or SPH_EH for the first particle (in index order) of n
 * whose position (dim components of x) is not finite or whose h (one
 * component) is not usable (sph__h_ok; h before x at each particle); else
 * SPH_OK. The views must be present. */
SPH_API int sph__hx_check(sph_view x, sph_view h, sph_idx n, int dim)
{
    sph_idx i;
    int a;
    for (i = 0; i < n; ++i) {
        if (!sph__h_ok(h.p[0][(ptrdiff_t)i * h.stride], dim)) return SPH_EH;
        for (a = 0; a < dim; ++a)
            if (!sph__finite(x.p[a][(ptrdiff_t)i * x.stride])) return SPH_ENONFINITE;
    }
    return SPH_OK;
}

/* View of a structure-of-arrays field (pass NULL for unused components). */
SPH_API sph_view sph_view_soa(const sph_real *x, const sph_real *y, const sph_real *z)
{
    sph_view v;
    v.p[0] = x;
    v.p[1] = y;
    v.p[2] = z;
    v.stride = 1;
    return v;
}

/* View of fields inside an array of structs: first points at component 0 of
 * particle 0, components are consecutive reals, stride_bytes = sizeof(struct)
 * (a multiple of sizeof(sph_real)). */
SPH_API sph_view sph_view_aos(const sph_real *first, int ncomp, size_t stride_bytes)
{
    sph_view v;
    int a;
    for (a = 0; a < 3; ++a) v.p[a] = (first != NULL && a < ncomp) ? first + a : NULL;
    v.stride = (ptrdiff_t)(stride_bytes / sizeof(sph_real));
    return v;
}

/* View of an interleaved field x[ncomp * i + a] (ncomp 1..3). */
SPH_API sph_view sph_view_interleaved(const sph_real *x, int ncomp)
{
    return sph_view_aos(x, ncomp, (size_t)ncomp * sizeof(sph_real));
}

/* Output counterparts of the three views: the same layouts on writable arrays
 * (the view is built first, then its pointers are taken back from the
 * caller's writable ones, so that no const is cast away). */
SPH_API sph_out sph_out_aos(sph_real *first, int ncomp, size_t stride_bytes)
{
    const sph_view v = sph_view_aos(first, ncomp, stride_bytes);
    sph_out o;
    int a;
    for (a = 0; a < 3; ++a) o.p[a] = v.p[a] != NULL ? first + a : NULL;
    o.stride = v.stride;
    return o;
}

SPH_API sph_out sph_out_soa(sph_real *x, sph_real *y, sph_real *z)
{
    sph_out o;
    o.p[0] = x;
    o.p[1] = y;
    o.p[2] = z;
    o.stride = 1;
    return o;
}

SPH_API sph_out sph_out_interleaved(sph_real *x, int ncomp)
{
    return sph_out_aos(x, ncomp, (size_t)ncomp * sizeof(sph_real));
}

/* Component a of particle i of a view or an output view (sections 6 and 9). */
#define SPH__AT(v, a, i) ((v).p[a][(ptrdiff_t)(i) * (v).stride])

/* Shares of a caller's parallel loop over particles 0..n-1: share p is
 * n p / shares .. n (p + 1) / shares - 1 (about the block that
 * schedule(static) gives thread p), handed out in chunks. A thread takes the chunks of its own share
 * first (particles whose fields the static loops before left in its core's
 * caches), then what is left of the others' (a slower core does not hold
 * the loop back); every particle once, whatever the thread count.
 * sph_share_next is safe to call from OpenMP threads at once. */
#define SPH_SHARE_PAD 8 /* entries of next per share: one 64-byte line, so the threads' counters never share one */
/* The shares of the library's own loops (their counters on the stack): one per thread, at most
 * SPH__SHARES_MAX (threads beyond it start in share t modulo that); this thread's number. Without
 * OpenMP, and in device code (a device thread runs the whole loop), one share. */
#if defined(_OPENMP) && !defined(__CUDA_ARCH__)
#define SPH__SHARES_MAX 64
#define SPH__SHARES (omp_get_max_threads() < SPH__SHARES_MAX ? omp_get_max_threads() : SPH__SHARES_MAX)
#define SPH__THREAD omp_get_thread_num()
#else
#define SPH__SHARES_MAX 1
#define SPH__SHARES 1
#define SPH__THREAD 0
#endif
typedef struct {
    sph_off *next; /* [shares * SPH_SHARE_PAD], the caller's: share p's next particle at next[p * SPH_SHARE_PAD] */
    sph_off n;
    sph_off chunk;
    int shares;
} sph_share;

/* Particles 0..n-1 in `shares` shares of chunks of `chunk` particles, the
 * counters in next (shares * SPH_SHARE_PAD entries); call it before each
 * loop (serially). SPH_ENULL (s or next NULL), SPH_ECOUNT (n < 0 or
 * shares < 1), SPH_ERANGE (chunk < 1); on error *s hands out nothing. */
SPH_API int sph_share_init(sph_share *s, sph_off *next, int shares, sph_idx n, sph_idx chunk)
{
    int p;
    if (s == NULL) return SPH_ENULL;
    s->next = NULL, s->n = 0, s->chunk = 1, s->shares = 0;
    if (next == NULL) return SPH_ENULL;
    if (n < 0 || shares < 1) return SPH_ECOUNT;
    if (chunk < 1) return SPH_ERANGE;
    for (p = 0; p < shares; ++p) next[(size_t)p * SPH_SHARE_PAD] = (sph_off)n * p / shares;
    s->next = next, s->n = n, s->chunk = chunk, s->shares = shares;
    return SPH_OK;
}

/* Thread t's next chunk, particles *lo .. *hi - 1: 1, or 0 when none is left
 * for it (also for t < 0 or an s that failed). *u starts at 0 in each
 * thread and counts the shares the thread has emptied (its own is share t
 * modulo shares, then the ones after it). */
SPH_API int sph_share_next(sph_share *s, int t, int *u, sph_idx *lo, sph_idx *hi)
{
    if (s == NULL || s->next == NULL || u == NULL || t < 0) return 0;
    while (*u >= 0 && *u < s->shares) {
        const int p = (int)(((sph_off)t + *u) % s->shares);
        const sph_off end = s->n * (p + 1) / s->shares;
        sph_off *c = s->next + (size_t)p * SPH_SHARE_PAD, a;
#ifdef _OPENMP
#pragma omp atomic capture
#endif
        {
            a = *c;
            *c += s->chunk;
        }
        if (a < end) { /* a counter passes its end once per thread at most: no overflow for n < 2^62 */
            *lo = (sph_idx)a, *hi = (sph_idx)(end - a > s->chunk ? a + s->chunk : end);
            return 1;
        }
        ++*u;
    }
    return 0;
}

#endif /* section 4 */

/* ---- Run-time dispatch (section 1, SPH__DISPATCH): sections 5-9 once per level above the build's ---- */
/* Each pass includes this file again with SPH__LV set: SPH__NAMES 1 first
 * maps every function name of sections 5-9 to name_avx512 or name_avx2
 * (SPH__SUFFIX; the list at the end of the file), a target pragma compiles
 * the pass for its level, and SPH__NAMES 2 removes the names again before
 * the build's own compile of sections 5-9. The types of sections 5-9 are
 * defined in the first of these compiles (SPH__FIRST). SPH_SELF: this
 * file's name as an #include finds it (default "sph_kernel.h"). */
#if SPH__DISPATCH && !defined(SPH_ONLY_KERNELS)
#ifndef SPH_SELF
#define SPH_SELF "sph_kernel.h"
#endif
#define SPH__LN(name) SPH__CAT(name, SPH__SUFFIX)
#define SPH__DISPATCH_TO(f, args)
#define SPH__DISPATCH_VOID(f, args)
#define SPH__NAMES 1
#include SPH_SELF
#undef SPH__NAMES
#if SPH__PASS_AVX512
#define SPH__LV 2 /* the pass itself: the start and end of sections 5-9 below */
#include SPH_SELF
#undef SPH__LV
#endif
#if SPH__PASS_AVX2
#define SPH__LV 1
#include SPH_SELF
#undef SPH__LV
#endif
#define SPH__NAMES 2
#include SPH_SELF
#undef SPH__NAMES
#define SPH__FIRST 0
#undef SPH__DISPATCH_TO
#undef SPH__DISPATCH_VOID
/* The build's public functions with a hot loop start by handing their
 * arguments to the level sph_isa() names, when that is not the build's. */
#define SPH__DISPATCH_TO(f, args) \
    switch (sph_isa()) { SPH__TO_AVX512(f, args) SPH__TO_AVX2(f, args) default: break; }
#define SPH__DISPATCH_VOID(f, args) \
    switch (sph_isa()) { SPH__TOV_AVX512(f, args) SPH__TOV_AVX2(f, args) default: break; }
#if SPH__PASS_AVX512
#define SPH__TO_AVX512(f, args) case SPH_ISA_AVX512: return f##_avx512 args;
#define SPH__TOV_AVX512(f, args) case SPH_ISA_AVX512: f##_avx512 args; return;
#else
#define SPH__TO_AVX512(f, args)
#define SPH__TOV_AVX512(f, args)
#endif
#if SPH__PASS_AVX2
#define SPH__TO_AVX2(f, args) case SPH_ISA_AVX2: return f##_avx2 args;
#define SPH__TOV_AVX2(f, args) case SPH_ISA_AVX2: f##_avx2 args; return;
#else
#define SPH__TO_AVX2(f, args)
#define SPH__TOV_AVX2(f, args)
#endif
#else
#define SPH__FIRST 1
#define SPH__DISPATCH_TO(f, args)
#define SPH__DISPATCH_VOID(f, args)
#endif

#endif /* SPH_KERNEL_H: sections 1-4 and the passes */

/* Sections 5-9: in each pass (SPH__LV) and in the build's own compile, once. */
#if !defined(SPH__NAMES) && (defined(SPH__LV) || !defined(SPH__BODY_DONE))
#if defined(SPH__LV) /* a pass: its level, names, target; the types if it is the first */
#undef SPH__ISA
#define SPH__ISA SPH__LV
#if SPH__LV == 2
#define SPH__SUFFIX _avx512
#define SPH__FIRST 1
#else
#define SPH__SUFFIX _avx2
#define SPH__FIRST (!SPH__PASS_AVX512)
#endif
#if defined(__clang__) && SPH__LV == 2
SPH__PRAGMA(clang attribute push(__attribute__((target(SPH__TARGET_AVX512))), apply_to = function))
#elif defined(__clang__)
SPH__PRAGMA(clang attribute push(__attribute__((target(SPH__TARGET_AVX2))), apply_to = function))
#else
#pragma GCC push_options
#if SPH__LV == 2
SPH__PRAGMA(GCC target(SPH__TARGET_AVX512))
#else
SPH__PRAGMA(GCC target(SPH__TARGET_AVX2))
#endif
#pragma GCC optimize("peel-loops")
#endif
#endif
#if !defined(SPH_ONLY_KERNELS) /* sections 5-9 */

/* ======================================================================== */
/* 5. Pair terms                                                             */
/* ======================================================================== */

/* ---- compiled once per instruction-set level (SPH__ISA) from here to the end of section 9 ---- */

/* 1 when this unit fuses the header's a * b + c into one rounding (gcc's
 * GNU modes or -ffp-contract=fast where the target has FMA; clang only
 * under -ffp-contract=fast or SPH_FP_CONTRACT): what the fast loops then
 * promise is agreement with the reference loops to round-off, not bit for
 * bit (docs/testing.md). (1 + 2^-27)^2 - 1 is 2^-26 rounded, 2^-26 + 2^-54
 * fused; the volatile keeps the compiler from folding it. */
SPH_API int sph__fp_contracted(void)
{
    SPH__DISPATCH_TO(sph__fp_contracted, ())
    volatile double v = 1 + 1.0 / 134217728;
    const double a = v;
    return a * a - 1 != 1.0 / 67108864;
}

/* r[0..n) = sqrt(r[0..n)), n a multiple of 8 (zero padded): IEEE square roots,
 * bit for bit those of sph__sqrt, without the errno test that keeps compilers
 * from vectorising sqrt() (the operators of section 6, sph_batch_fill).
 * With AVX-512 in 512-bit registers: a lane loop compiled for AVX-512 reads
 * the lanes with 512-bit loads, which the store buffer does not forward
 * from two 256-bit stores (they wait for the cache instead; docs/smoothing_length.md).
 * SPH_NO_INTRINSICS selects the portable loop. */
SPH__INLINE void sph__sqrt_chunk(sph_real *r, int n)
{
    int k = 0;
#if SPH__OP_AVX512
    if (sizeof(sph_real) == sizeof(double)) {
        for (; k + 8 <= n; k += 8)
            _mm512_storeu_pd((double *)r + k, _mm512_maskz_sqrt_pd(SPH__ALL8, _mm512_loadu_pd((const double *)r + k)));
    } else {
        for (; k + 16 <= n; k += 16)
            _mm512_storeu_ps((float *)r + k, _mm512_maskz_sqrt_ps((__mmask16)0xFFFF, _mm512_loadu_ps((const float *)r + k)));
    }
#endif
#if SPH__SQRT_SIMD == 2
    if (sizeof(sph_real) == sizeof(double)) {
        for (; k < n; k += 4)
            _mm256_storeu_pd((double *)r + k, _mm256_sqrt_pd(_mm256_loadu_pd((const double *)r + k)));
    } else {
        for (; k < n; k += 8)
            _mm256_storeu_ps((float *)r + k, _mm256_sqrt_ps(_mm256_loadu_ps((const float *)r + k)));
    }
#elif SPH__SQRT_SIMD == 1
    if (sizeof(sph_real) == sizeof(double)) {
        for (; k < n; k += 2)
            _mm_storeu_pd((double *)r + k, _mm_sqrt_pd(_mm_loadu_pd((const double *)r + k)));
    } else {
        for (; k < n; k += 4)
            _mm_storeu_ps((float *)r + k, _mm_sqrt_ps(_mm_loadu_ps((const float *)r + k)));
    }
#else
    for (; k < n; ++k) r[k] = sph__sqrt(r[k]);
#endif
}

/* e[0..n) -= L floor(e[0..n) / L + 1/2) with 1/L given: sph__pair's minimum
 * image, bit for bit, in vector registers (AVX-512 first, as sph__sqrt_chunk;
 * AVX: its vector floor; SSE2: by the int32 conversion) where the compilers
 * leave floor() in a loop scalar (the operators of section 6, sph_batch_fill). */
SPH__INLINE void sph__image_chunk(sph_real *e, int n, sph_real L, sph_real iL)
{
    int k = 0;
#if SPH__OP_AVX512
    if (sizeof(sph_real) == sizeof(double)) {
        const __m512d vL = _mm512_set1_pd((double)L), viL = _mm512_set1_pd((double)iL), h = _mm512_set1_pd(0.5);
        for (; k + 8 <= n; k += 8) {
            const __m512d v = _mm512_loadu_pd((const double *)e + k);
            const __m512d f = _mm512_maskz_roundscale_pd(SPH__ALL8, _mm512_add_pd(_mm512_mul_pd(v, viL), h),
                                                         _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
            _mm512_storeu_pd((double *)e + k, _mm512_sub_pd(v, _mm512_mul_pd(vL, f)));
        }
    } else {
        const __m512 vL = _mm512_set1_ps((float)L), viL = _mm512_set1_ps((float)iL), h = _mm512_set1_ps(0.5f);
        for (; k + 16 <= n; k += 16) {
            const __m512 v = _mm512_loadu_ps((const float *)e + k);
            const __m512 f = _mm512_maskz_roundscale_ps((__mmask16)0xFFFF, _mm512_add_ps(_mm512_mul_ps(v, viL), h),
                                                        _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
            _mm512_storeu_ps((float *)e + k, _mm512_sub_ps(v, _mm512_mul_ps(vL, f)));
        }
    }
#endif
#if SPH__SQRT_SIMD == 2
    if (sizeof(sph_real) == sizeof(double)) {
        const __m256d vL = _mm256_set1_pd((double)L), viL = _mm256_set1_pd((double)iL), h = _mm256_set1_pd(0.5);
        for (; k + 4 <= n; k += 4) {
            const __m256d v = _mm256_loadu_pd((const double *)e + k);
            const __m256d f = _mm256_floor_pd(_mm256_add_pd(_mm256_mul_pd(v, viL), h));
            _mm256_storeu_pd((double *)e + k, _mm256_sub_pd(v, _mm256_mul_pd(vL, f)));
        }
    } else {
        const __m256 vL = _mm256_set1_ps((float)L), viL = _mm256_set1_ps((float)iL), h = _mm256_set1_ps(0.5f);
        for (; k + 8 <= n; k += 8) {
            const __m256 v = _mm256_loadu_ps((const float *)e + k);
            const __m256 f = _mm256_floor_ps(_mm256_add_ps(_mm256_mul_ps(v, viL), h));
            _mm256_storeu_ps((float *)e + k, _mm256_sub_ps(v, _mm256_mul_ps(vL, f)));
        }
    }
#elif SPH__SQRT_SIMD == 1
    /* SSE2 has no vector floor: floor(t) = trunc(t) - (trunc(t) > t), trunc by
     * the conversion to int32, where |t| < 2^31 in every lane (t = -0 never
     * occurs: t = x + 1/2); otherwise the scalar loop below */
    if (sizeof(sph_real) == sizeof(double)) {
        const __m128d vL = _mm_set1_pd((double)L), viL = _mm_set1_pd((double)iL), h = _mm_set1_pd(0.5);
        const __m128d one = _mm_set1_pd(1.0), big = _mm_set1_pd(2147483648.0), sgn = _mm_set1_pd(-0.0);
        for (; k + 2 <= n; k += 2) {
            const __m128d v = _mm_loadu_pd((const double *)e + k), t = _mm_add_pd(_mm_mul_pd(v, viL), h);
            __m128d f;
            if (_mm_movemask_pd(_mm_cmpge_pd(_mm_andnot_pd(sgn, t), big)) != 0) break;
            f = _mm_cvtepi32_pd(_mm_cvttpd_epi32(t));
            f = _mm_sub_pd(f, _mm_and_pd(_mm_cmpgt_pd(f, t), one));
            _mm_storeu_pd((double *)e + k, _mm_sub_pd(v, _mm_mul_pd(vL, f)));
        }
    } else {
        const __m128 vL = _mm_set1_ps((float)L), viL = _mm_set1_ps((float)iL), h = _mm_set1_ps(0.5f);
        const __m128 one = _mm_set1_ps(1.0f), big = _mm_set1_ps(2147483648.0f), sgn = _mm_set1_ps(-0.0f);
        for (; k + 4 <= n; k += 4) {
            const __m128 v = _mm_loadu_ps((const float *)e + k), t = _mm_add_ps(_mm_mul_ps(v, viL), h);
            __m128 f;
            if (_mm_movemask_ps(_mm_cmpge_ps(_mm_andnot_ps(sgn, t), big)) != 0) break;
            f = _mm_cvtepi32_ps(_mm_cvttps_epi32(t));
            f = _mm_sub_ps(f, _mm_and_ps(_mm_cmpgt_ps(f, t), one));
            _mm_storeu_ps((float *)e + k, _mm_sub_ps(v, _mm_mul_ps(vL, f)));
        }
    }
#endif
    for (; k < n; ++k) e[k] -= L * sph__floor(e[k] * iL + (sph_real)0.5);
}

/* One neighbour's contribution to each operator of section 6, for solvers that
 * fuse several operators in their own neighbour loop (docs/operators.md,
 * "Pair terms"). Conventions: dx = x_ij = x_i - x_j (minimum image, (O0)),
 * F = F_ij = (1/r) dW/dr at the pair's h, grad_i W_ij = F dx (O1); V_j = m_j /
 * rho_j. The vector terms add into acc[0..dim-1]; nothing is divided by r.
 *
 * Bad input. These are the caller's inner loop and check nothing they need
 * not: the sums and products below are plain arithmetic, finite for finite
 * arguments whose products stay in range, and NaN or Inf in an argument
 * passes into the result (validate fields once with sph_check_field). Arrays
 * must hold dim (1..3) values; no component beyond the third is read or
 * written whatever dim is. The functions that divide or evaluate the kernel
 * return a documented finite fallback instead: sph_pair_kernel (zeros),
 * sph_pressure_factor (0), sph_harmonic_k (0) and sph_correction_invert
 * (identity). */

/* The kernel at one pair: r = |dx|, q = r / h, W = W(r, h), F = (1/r) dW/dr. */
#if SPH__FIRST
typedef struct {
    sph_real r, q, W, F;
} sph_pair;
#endif /* SPH__FIRST */

/* (O1) r, q, W and F of a pair from dx = x_i - x_j (dim components) and the
 * pair's h (the caller picks h_i, or (h_i + h_j) / 2 for symmetric terms).
 * All zero, as the scalar kernel functions give, for invalid kernel, dim or
 * h, and for a dx with a NaN or Inf component or so long that |dx|^2 or
 * |dx| / h overflows (far beyond the support, where W = F = 0 anyway). */
SPH_API sph_pair sph_pair_kernel(sph_kernel k, int dim, const sph_real *dx, sph_real h)
{
    sph_pair p;
    sph_real r2 = 0, hinv, r, q;
    const sph__kdim *kd = sph__kd(k, dim);
    int a;
    p.r = p.q = p.W = p.F = 0;
    if (kd == NULL || dx == NULL || !sph__h_ok(h, dim)) return p;
    for (a = 0; a < dim; ++a) r2 += dx[a] * dx[a];
    hinv = 1 / h;
    r = sph__sqrt(r2);
    q = r * hinv;
    if (!(q <= SPH__REAL_MAX)) return p; /* NaN (a NaN in dx) or Inf (Inf in dx, or overflow) */
    p.r = r;
    p.q = q;
    p.W = sph__hpow(kd->alpha * (sph_real)sph__shape_at(&sph__nshapes[kd->shape], SPH__SW, q), hinv, dim);
    p.F = sph__hpow(kd->alpha * (sph_real)sph__shape_at(&sph__nshapes[kd->shape], SPH__SG, q), hinv, dim + 2);
    return p;
}

/* (O2) density: m_j W_ij. */
SPH_API sph_real sph_pair_density(sph_real m_j, sph_real W) { return m_j * W; }

/* (O3) interpolation: V_j f_j W_ij (Shepard: also sum V_j W_ij). */
SPH_API sph_real sph_pair_interpolate(sph_real V_j, sph_real f_j, sph_real W) { return V_j * f_j * W; }

/* acc += c dx (the common shape of every gradient pair term, c = coefficient * F). */
SPH__INLINE void sph__axpy(int dim, sph_real c, const sph_real *dx, sph_real *acc)
{
    int a;
    for (a = 0; a < dim && a < 3; ++a) acc[a] += c * dx[a];
}

/* (O4) standard gradient: acc += V_j f_j F dx. */
SPH_API void sph_pair_grad_standard(int dim, sph_real V_j, sph_real f_j, sph_real F,
                                    const sph_real *dx, sph_real *acc)
{
    sph__axpy(dim, V_j * f_j * F, dx, acc);
}

/* (O5) difference gradient: acc += V_j (f_j - f_i) F dx (zero for constants). */
SPH_API void sph_pair_grad_difference(int dim, sph_real V_j, sph_real f_i, sph_real f_j,
                                      sph_real F, const sph_real *dx, sph_real *acc)
{
    sph__axpy(dim, V_j * (f_j - f_i) * F, dx, acc);
}

/* (O6) symmetric gradient: acc += V_j (f_j + f_i) F dx (antisymmetric in i, j). */
SPH_API void sph_pair_grad_symmetric(int dim, sph_real V_j, sph_real f_i, sph_real f_j,
                                     sph_real F, const sph_real *dx, sph_real *acc)
{
    sph__axpy(dim, V_j * (f_j + f_i) * F, dx, acc);
}

/* (O8) pressure form: acc += m_j (p_i / rho_i^2 + p_j / rho_j^2) F dx; then
 * grad p_i = rho_i acc and the acceleration is -acc. P = p / rho^2 is passed
 * precomputed (once per particle: no division in the pair loop). */
SPH_API void sph_pair_grad_pressure(int dim, sph_real m_j, sph_real P_i, sph_real P_j, sph_real F,
                                    const sph_real *dx, sph_real *acc)
{
    sph__axpy(dim, m_j * (P_i + P_j) * F, dx, acc);
}

/* P = p / rho^2, the per-particle factor of (O8). 0 where it is not a
 * finite number: rho not positive (no division by 0), p or rho NaN or
 * infinite, or rho^2 underflowing to 0; 0 also where rho^2 overflows (one
 * multiplication and one division per call, as the pair loops need). */
SPH_API sph_real sph_pressure_factor(sph_real p, sph_real rho)
{
    const sph_real P = rho > 0 ? p / (rho * rho) : 0;
    return sph__finite(P) ? P : 0;
}

/* (O9) standard divergence: V_j v_j . dx F. */
SPH_API sph_real sph_pair_div_standard(int dim, sph_real V_j, const sph_real *v_j, sph_real F,
                                       const sph_real *dx)
{
    sph_real s = 0;
    int a;
    for (a = 0; a < dim && a < 3; ++a) s += v_j[a] * dx[a];
    return V_j * F * s;
}

/* (O10) difference divergence: V_j (v_j - v_i) . dx F. */
SPH_API sph_real sph_pair_div_difference(int dim, sph_real V_j, const sph_real *v_i,
                                         const sph_real *v_j, sph_real F, const sph_real *dx)
{
    sph_real s = 0;
    int a;
    for (a = 0; a < dim && a < 3; ++a) s += (v_j[a] - v_i[a]) * dx[a];
    return V_j * F * s;
}

/* (O11) curl: acc += V_j F (dx x u), u = v_j (standard) or v_j - v_i
 * (difference); dim 2: acc[0] += V_j F (dx_x u_y - dx_y u_x); dim 3: vector. */
SPH_API void sph_pair_curl(int dim, sph_real V_j, const sph_real *u, sph_real F, const sph_real *dx,
                           sph_real *acc)
{
    const sph_real c = V_j * F;
    if (dim == 2) {
        acc[0] += c * (dx[0] * u[1] - dx[1] * u[0]);
    } else if (dim == 3) {
        acc[0] += c * (dx[1] * u[2] - dx[2] * u[1]);
        acc[1] += c * (dx[2] * u[0] - dx[0] * u[2]);
        acc[2] += c * (dx[0] * u[1] - dx[1] * u[0]);
    }
}

/* (O12) Laplacian (Brookshaw / Morris): 2 V_j (f_i - f_j) F (the factor 2
 * applied last: the same bits, and no 2 V_j overflowing on its own). */
SPH_API sph_real sph_pair_laplacian(sph_real V_j, sph_real f_i, sph_real f_j, sph_real F)
{
    return V_j * (f_i - f_j) * F * 2;
}

/* (O13) pair coefficient k_ij = 4 k_i k_j / (k_i + k_j) (twice the harmonic
 * mean; 2k for k_i = k_j = k). 0 when k_i and k_j do not have the same sign
 * (a zero or sign-changing coefficient blocks the flux), so k_i + k_j = 0
 * never divides, and 0 when either is NaN or infinite. Computed as
 * a (4 b / (a + b)), a the one of smaller magnitude, so that the factor lies
 * in [2, 4) and no intermediate overflows (a + b is scaled by 1/4 when b is
 * that large); where k_ij itself exceeds the largest sph_real it saturates
 * there, with a's sign. k_ij is symmetric in i, j bit for bit. */
SPH_API sph_real sph_harmonic_k(sph_real k_i, sph_real k_j)
{
    const int same = (k_i > 0 && k_j > 0) || (k_i < 0 && k_j < 0);
    const int swap = (k_i < 0 ? -k_i : k_i) > (k_j < 0 ? -k_j : k_j);
    const sph_real a = swap ? k_j : k_i, b = swap ? k_i : k_j;
    const sph_real big = (b < 0 ? -b : b) > SPH__REAL_MAX / 4 ? (sph_real)0.25 : 1; /* exact scaling of a + b */
    const sph_real k = a * (4 * ((b * big) / (a * big + b * big)));
    const sph_real sat = a > 0 ? SPH__REAL_MAX : -SPH__REAL_MAX;
    return same && sph__finite(b) ? (sph__finite(k) ? k : sat) : 0;
}

/* (O14) diffusion div(k grad f): V_j k_ij (f_i - f_j) F with k_ij from (O13). */
SPH_API sph_real sph_pair_diffusion(sph_real V_j, sph_real k_ij, sph_real f_i, sph_real f_j,
                                    sph_real F)
{
    return V_j * k_ij * (f_i - f_j) * F;
}

/* (O15) correction matrix: M[3a+b] += V_j (d_a W_ij) (x_j - x_i)_b = -V_j F dx_a dx_b
 * (M is 3x3 row-major, the dim x dim block used). */
SPH_API void sph_pair_correction(int dim, sph_real V_j, sph_real F, const sph_real *dx, sph_real *M)
{
    const sph_real c = -V_j * F;
    int a, b;
    for (a = 0; a < dim && a < 3; ++a)
        for (b = 0; b < dim && b < 3; ++b) M[3 * a + b] += c * dx[a] * dx[b];
}

/* Largest column sum of |A| over the dim x dim block (matrix 1-norm). */
SPH__INLINE sph_real sph__norm1(int dim, const sph_real *A)
{
    sph_real n = 0;
    int a, b;
    for (b = 0; b < dim; ++b) {
        sph_real s = 0;
        for (a = 0; a < dim; ++a) s += A[3 * a + b] < 0 ? -A[3 * a + b] : A[3 * a + b];
        n = s > n ? s : n;
    }
    return n;
}

/* (O16) B = M^-1 when M is well conditioned: reciprocal condition number in
 * the 1-norm, |det M| / (||M||_1 ||adj M||_1) >= rcond_min, tested without a
 * division (scale-free), and every entry of M^-1 finite. Otherwise
 * (degenerate neighbourhood, NaN or Inf in M, an inverse beyond the range of
 * sph_real, rcond_min NaN) B = identity and 0 is returned, else 1. M and B
 * are 3x3 row-major; the dim x dim block is used, the rest of B is set to
 * zero (dim outside 1..3, or M NULL: B = identity of the block that fits, 0
 * returned; B NULL: nothing written, 0). */
SPH_API int sph_correction_invert(int dim, const sph_real *M, sph_real rcond_min, sph_real *B)
{
    sph_real A[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, det = 0, ad, nm, na, inv;
    int a, ok;
    if (B == NULL) return 0;
    if (M == NULL || dim < 1 || dim > 3) {
        for (a = 0; a < 9; ++a) B[a] = a % 4 == 0 && a / 3 < dim ? 1 : 0;
        return 0;
    }
    if (dim == 1) {
        A[0] = 1;
        det = M[0];
    } else if (dim == 2) {
        A[0] = M[4];
        A[1] = -M[1];
        A[3] = -M[3];
        A[4] = M[0];
        det = M[0] * M[4] - M[1] * M[3];
    } else {
        A[0] = M[4] * M[8] - M[5] * M[7];
        A[1] = M[2] * M[7] - M[1] * M[8];
        A[2] = M[1] * M[5] - M[2] * M[4];
        A[3] = M[5] * M[6] - M[3] * M[8];
        A[4] = M[0] * M[8] - M[2] * M[6];
        A[5] = M[2] * M[3] - M[0] * M[5];
        A[6] = M[3] * M[7] - M[4] * M[6];
        A[7] = M[1] * M[6] - M[0] * M[7];
        A[8] = M[0] * M[4] - M[1] * M[3];
        det = M[0] * A[0] + M[1] * A[3] + M[2] * A[6];
    }
    ad = det < 0 ? -det : det;
    nm = sph__norm1(dim, M);
    na = sph__norm1(dim, A);
    /* In 3-D a rank-1 M (one neighbour, collinear neighbours) has an adjugate
     * of rounding noise, and noise / noise passes the rcond test: also require
     * ||adj M||_1 >= rcond_min ||M||_1^2 / 16, which every M passing the
     * exact rcond test meets (||adj M||_2 = s1 s2 with s2 / s1 >= rcond_min / 3;
     * 1- and 2-norms agree within sqrt 3: 9 sqrt 3 < 16). */
    ok = ad > 0 && ad <= SPH__REAL_MAX && ad >= rcond_min * nm * na &&
         (dim < 3 || 16 * na >= rcond_min * nm * nm);
    inv = ok ? 1 / det : 0;
    for (a = 0; a < 9; ++a) ok &= sph__finite(A[a] * inv); /* a denormal det can make 1/det or an entry overflow */
    for (a = 0; a < 9; ++a) B[a] = ok ? A[a] * inv : (a % 4 == 0 && a / 3 < dim ? 1 : 0);
    return ok;
}


#if !defined(SPH_ONLY_PAIRS) && !defined(SPH_NO_OPERATORS) /* section 6 */

/* ======================================================================== */
/* 6. Array operators                                                        */
/* ======================================================================== */

/* Loops over the targets of a CSR neighbour list (gather form: each target
 * sums its own list in order, so results are deterministic and, with OpenMP,
 * bitwise the same for any thread count). docs/operators.md describes the
 * context, the views, the schemes, the status codes and the fallbacks.
 *
 * Lists: the sources of target i are index[offset[i]] .. index[offset[i+1]-1].
 * When targets are the sources, a list contains i itself (r = 0): the density
 * and interpolation need the self term; the derivative terms vanish there.
 * Smoothing length: uniform (ctx.h), or per particle; then density and
 * interpolation use the target's h_i (gather) and every derivative operator
 * h_ij = (h_i + h_j) / 2, so that their pair terms stay antisymmetric. The
 * list must hold every source within kappa h of the target for the h used. */

/* How much input checking an operator does before it runs. */
#if SPH__FIRST
enum {
    SPH_VALIDATE_FULL = 0, /* default: arguments, one pass over the list (sph_neighbours_check)
                              and one over every per-particle input array */
    SPH_VALIDATE_ARGS = 1  /* arguments only (O(1)): the caller has checked list and data */
};
#endif /* SPH__FIRST */

/* Which loops an operator runs (the results agree to round-off, bitwise
 * without OpenMP and AVX-512; tests/test_op_reference.c). */
#if SPH__FIRST
enum {
    SPH_LOOPS_FAST = 0,     /* default: chunked vector loops (section 6, "Fast loops") */
    SPH_LOOPS_REFERENCE = 1 /* the plain reference loops, one pair at a time: to check a result */
};
#endif /* SPH__FIRST */

/* Gradient, divergence and curl schemes (docs/operators.md (O4)-(O11), (O17)). */
#if SPH__FIRST
typedef enum {
    SPH_SCHEME_STANDARD,   /* sum V_j f_j grad_i W_ij                       */
    SPH_SCHEME_DIFFERENCE, /* sum V_j (f_j - f_i) grad_i W_ij                */
    SPH_SCHEME_SYMMETRIC,  /* sum V_j (f_j + f_i) grad_i W_ij                */
    SPH_SCHEME_CORRECTED,  /* B_i sum V_j (f_j - f_i) grad_i W_ij            */
    SPH_SCHEME_PRESSURE    /* rho_i sum m_j (f_i/rho_i^2 + f_j/rho_j^2) grad_i W_ij (scalars) */
} sph_scheme;
#endif /* SPH__FIRST */

/* What every operator reads besides its field. Fill with sph_ctx_init, then
 * set what the scene uses. Sources are indexed 0..n_sources-1 and targets
 * 0..n_targets-1; a view with p[0] == NULL is absent. */
#if SPH__FIRST
typedef struct {
    sph_kernel kernel;
    int dim;                    /* 1..3 */
    sph_real h;                 /* uniform smoothing length (when h_source is absent) */
    const sph_neighbours *list; /* CSR list, targets -> sources */
    const sph_box *box;         /* periodic box, or NULL */
    sph_view x;                 /* source positions (dim components) */
    sph_view x_target;          /* target positions; absent: the targets are the sources */
    sph_view h_source;          /* per-particle h of sources; absent: uniform h */
    sph_view h_target;          /* per-particle h of targets (needed when x_target is given) */
    sph_view V;                 /* source volumes V_j = m_j / rho_j (all but density, pressure) */
    sph_view m;                 /* source masses (density, pressure form); a stride 0 is refused, unlike sph_hctx's */
    sph_view rho;               /* source densities (pressure form) */
    sph_view rho_target;        /* target densities (pressure form, when x_target is given) */
    sph_real rcond_min;         /* corrected schemes: fall back below this 1-norm rcond (1e-3) */
    int validate;               /* SPH_VALIDATE_FULL (default) or SPH_VALIDATE_ARGS */
    int loops;                  /* SPH_LOOPS_FAST (default) or SPH_LOOPS_REFERENCE */
} sph_ctx;
#endif /* SPH__FIRST */

/* An absent view (every pointer NULL). */
SPH_API sph_view sph_view_none(void) { return sph_view_soa(NULL, NULL, NULL); }

/* A context with uniform h, no box, targets = sources, rcond_min = 1e-3,
 * full validation, and every other view absent. */
SPH_API sph_ctx sph_ctx_init(sph_kernel kernel, int dim, sph_real h, const sph_neighbours *list,
                             sph_view x)
{
    sph_ctx c;
    c.kernel = kernel;
    c.dim = dim;
    c.h = h;
    c.list = list;
    c.box = NULL;
    c.x = x;
    c.x_target = c.h_source = c.h_target = c.V = c.m = c.rho = c.rho_target = sph_view_none();
    c.rcond_min = SPH__C(1e-3);
    c.validate = SPH_VALIDATE_FULL;
    c.loops = SPH_LOOPS_FAST;
    return c;
}

/* The operators and the family of loops that computes each: one list makes
 * the enum and the fast path's instances. */
#define SPH__OPS(X)                                                                        \
    X(DENSITY, sum) X(INTERP, sum) X(SHEPARD, sum)                                         \
    X(GRAD_STD, grad) X(GRAD_DIFF, grad) X(GRAD_SYM, grad) X(GRAD_CORR, grad)              \
    X(GRAD_PRES, grad) X(DENS_GRAD, grad)                                                  \
    X(GRADV_STD, tensor) X(GRADV_DIFF, tensor) X(GRADV_SYM, tensor) X(GRADV_CORR, tensor)  \
    X(DIV_CORR, tensor) X(CORRECTION, tensor)                                              \
    X(DIV_STD, divcurl) X(DIV_DIFF, divcurl) X(CURL_STD, divcurl) X(CURL_DIFF, divcurl)    \
    X(LAPLACIAN, lap) X(DIFFUSION, lap)

#define SPH__X(name, family) SPH__OP_##name,
#if SPH__FIRST
enum { SPH__OPS(SPH__X) SPH__OP_COUNT };
#endif /* SPH__FIRST */
#undef SPH__X

/* Everything an operator loop reads, resolved and checked. */
#if SPH__FIRST
typedef struct {
    sph_kernel kernel;
    int op, dim, hv;        /* operator, dimension, per-particle h */
    int reference;          /* run the reference loops (ctx.loops) */
    sph_real L[3], invL[3]; /* period and 1 / period per axis, 0 where not periodic */
    sph_idx nt;
    sph_real h, rcond_min;
    const sph_off *off;
    const sph_idx *idx;
    sph_view x, xt, hs, ht, V, m, rho, rhot, f, ft, k, kt;
    sph_out out, out2; /* out2: the density of SPH__OP_DENS_GRAD */
    sph_real *T;
    ptrdiff_t Ts;
} sph__args;
#endif /* SPH__FIRST */

/* The dimension and kernel of a loop: compile-time constants where SPH_DIM
 * and SPH_KERNEL pin them (the compiler then folds the kernel's pieces). The
 * run-time dimension, checked to be 1..3 before any loop, is masked so that
 * the compiler also knows the per-axis arrays of length 3 are not overrun. */
#if defined(SPH_DIM)
#define SPH__DIM(A) (SPH_DIM)
#else
#define SPH__DIM(A) ((A)->dim & 3)
#endif
#if defined(SPH_KERNEL)
#define SPH__KERN(A) ((int)(SPH_KERNEL))
#else
#define SPH__KERN(A) ((int)(A)->kernel)
#endif

/* What a loop evaluates per pair: W (at h_i) and/or F (at h_ij). */
#if SPH__FIRST
enum { SPH__WANT_W = 1, SPH__WANT_F = 2 };
#endif /* SPH__FIRST */

/* One target: position, h_i, 1/h_i, the kernel's shape and alpha_d, and the
 * factors alpha h_i^-d (W) and alpha h_i^-(d+2) (F). */
#if SPH__FIRST
typedef struct {
    const sph__nshape *sh;
    int shape;
    sph_real xi[3], hi, hinv, alpha, cW, cF;
} sph__tgt;
#endif /* SPH__FIRST */

SPH__INLINE void sph__tinit(const sph__args *A, sph_idx i, sph__tgt *t)
{
    const int D = SPH__DIM(A);
    const sph__kdim *kd = &sph__kdims[SPH__KERN(A)][D - 1];
    int a;
    for (a = 0; a < 3; ++a) t->xi[a] = a < D ? SPH__AT(A->xt, a, i) : 0;
    t->shape = kd->shape;
    t->sh = &sph__nshapes[kd->shape];
    t->alpha = kd->alpha;
    t->hi = A->hv ? SPH__AT(A->ht, 0, i) : A->h;
    t->hinv = 1 / t->hi;
    t->cW = sph__hpow(kd->alpha, t->hinv, D);
    t->cF = sph__hpow(kd->alpha, t->hinv, D + 2);
}

/* (O0), (O1) pair (i, j): dx = x_i - x_j with the minimum image on periodic
 * axes (sph_box_delta's image, with 1/L taken once per call so that no pair
 * divides), W at h_i and, with SPH__WANT_F, F at h_ij = (h_i + h_j) / 2
 * (per-particle h) or h. The arithmetic every loop below shares. */
SPH__INLINE void sph__pair(const sph__args *A, const sph__tgt *t, sph_idx j, int want, sph_real *dx,
                           sph_real *W, sph_real *F)
{
    const int D = SPH__DIM(A);
    sph_real r2 = 0, r, hinv = t->hinv, c = t->cF;
    int a;
    for (a = 0; a < 3; ++a) dx[a] = 0;
    for (a = 0; a < D; ++a) {
        sph_real d = t->xi[a] - SPH__AT(A->x, a, j);
        if (A->L[a] != 0) d -= A->L[a] * sph__floor(d * A->invL[a] + (sph_real)0.5);
        dx[a] = d;
        r2 += d * d;
    }
    r = sph__sqrt(r2);
    *W = (want & SPH__WANT_W) ? t->cW * sph__nshape_w(t->sh, r * t->hinv) : 0;
    if (!(want & SPH__WANT_F)) return;
    if (A->hv) {
        hinv = 2 / (t->hi + SPH__AT(A->hs, 0, j));
        c = sph__hpow(t->alpha, hinv, D + 2);
    }
    *F = c * sph__nshape_g(t->sh, r * hinv);
}

/* ---- the end of a target, shared by the reference and the fast loops ---- */

/* (O2), (O3): rho or <f>, or Shepard's s / sV; returns 1 for an empty Shepard target. */
SPH__INLINE int sph__end_sum(const sph__args *A, sph_idx i, sph_real s, sph_real sV)
{
    if (A->op != SPH__OP_SHEPARD) {
        SPH__AT(A->out, 0, i) = s;
        return 0;
    }
    SPH__AT(A->out, 0, i) = sV != 0 ? s / sV : 0;
    return sV == 0;
}

/* (O4)-(O8): rho_i g (pressure form; rho_i = 1 otherwise), B_i g (corrected,
 * (O7)) or g; the density of the fused pass. Returns 1 for a fallback. */
SPH__INLINE int sph__end_grad(const sph__args *A, sph_idx i, sph_real rhoi, const sph_real *g, int fb,
                              const sph_real *B, sph_real rho)
{
    const int D = SPH__DIM(A);
    int a, b;
    for (a = 0; a < D; ++a) {
        sph_real y = rhoi * g[a];
        if (A->op == SPH__OP_GRAD_CORR)
            for (y = 0, b = 0; b < D; ++b) y += B[3 * a + b] * g[b];
        SPH__AT(A->out, a, i) = y;
    }
    if (A->op == SPH__OP_DENS_GRAD) SPH__AT(A->out2, 0, i) = rho;
    return fb;
}

/* (O15)-(O18): the tensor S (velocity gradient), S B (corrected, (O17)),
 * its trace (corrected divergence, (O18)) or B itself. */
SPH__INLINE int sph__end_tensor(const sph__args *A, sph_idx i, const sph_real *S, const sph_real *M)
{
    const int D = SPH__DIM(A), op = A->op;
    const int corr = op == SPH__OP_GRADV_CORR || op == SPH__OP_DIV_CORR || op == SPH__OP_CORRECTION;
    sph_real B[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, div = 0;
    int fb = 0, a, b, e;
    if (corr) fb = !sph_correction_invert(D, M, A->rcond_min, B);
    for (a = 0; a < D; ++a)
        for (b = 0; b < D; ++b) {
            sph_real y = S[3 * a + b];
            if (op == SPH__OP_CORRECTION) y = B[3 * a + b];
            else if (corr)
                for (y = 0, e = 0; e < D; ++e) y += S[3 * a + e] * B[3 * e + b];
            if (op == SPH__OP_DIV_CORR) div += a == b ? y : 0;
            else A->T[(ptrdiff_t)i * A->Ts + a * D + b] = y;
        }
    if (op == SPH__OP_DIV_CORR) SPH__AT(A->out, 0, i) = div;
    return fb;
}

/* (O9)-(O11): the divergence, or the curl (a scalar in 2-D, a vector in 3-D). */
SPH__INLINE int sph__end_divcurl(const sph__args *A, sph_idx i, const sph_real *s)
{
    SPH__AT(A->out, 0, i) = s[0];
    if ((A->op == SPH__OP_CURL_STD || A->op == SPH__OP_CURL_DIFF) && SPH__DIM(A) == 3) {
        SPH__AT(A->out, 1, i) = s[1];
        SPH__AT(A->out, 2, i) = s[2];
    }
    return 0;
}

/* f_i (and, for the pressure form, rho_i and P_i = p_i / rho_i^2) of target i. */
SPH__INLINE sph_real sph__fi(const sph__args *A, sph_idx i)
{
    return A->op == SPH__OP_GRAD_STD ? 0 : SPH__AT(A->ft, 0, i);
}

/* ---- reference loops: one per family, one pair at a time ---- */
/* Each target sums its own list in order over the pair terms of section 5.
 * These loops define the results; the fast loops below are tested equal. */

/* (O2), (O3) density, interpolation, Shepard at target i. */
SPH_API int sph__ref_sum(const sph__args *A, sph_idx i)
{
    sph__tgt t;
    sph_real s = 0, sV = 0, dx[3], W, F;
    sph_off o;
    sph__tinit(A, i, &t);
    for (o = A->off[i]; o < A->off[i + 1]; ++o) {
        const sph_idx j = A->idx[o];
        sph__pair(A, &t, j, SPH__WANT_W, dx, &W, &F);
        if (A->op == SPH__OP_DENSITY) {
            s += sph_pair_density(SPH__AT(A->m, 0, j), W);
        } else {
            const sph_real Vj = SPH__AT(A->V, 0, j);
            s += sph_pair_interpolate(Vj, SPH__AT(A->f, 0, j), W);
            sV += Vj * W;
        }
    }
    return sph__end_sum(A, i, s, sV);
}

/* (O4)-(O8) gradient of a scalar, and (O2) + (O5) fused, at target i. */
SPH_API int sph__ref_grad(const sph__args *A, sph_idx i)
{
    const int D = SPH__DIM(A), op = A->op;
    const sph_real fi = sph__fi(A, i), rhoi = op == SPH__OP_GRAD_PRES ? SPH__AT(A->rhot, 0, i) : 1;
    const sph_real Pi = op == SPH__OP_GRAD_PRES ? sph_pressure_factor(fi, rhoi) : 0;
    sph_real g[3] = {0, 0, 0}, M[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, B[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    sph_real rho = 0, dx[3], W, F;
    sph__tgt t;
    sph_off o;
    sph__tinit(A, i, &t);
    for (o = A->off[i]; o < A->off[i + 1]; ++o) {
        const sph_idx j = A->idx[o];
        const sph_real fj = SPH__AT(A->f, 0, j);
        sph__pair(A, &t, j, op == SPH__OP_DENS_GRAD ? SPH__WANT_W | SPH__WANT_F : SPH__WANT_F, dx, &W, &F);
        if (op == SPH__OP_GRAD_PRES)
            sph_pair_grad_pressure(D, SPH__AT(A->m, 0, j), Pi, sph_pressure_factor(fj, SPH__AT(A->rho, 0, j)), F,
                                   dx, g);
        else if (op == SPH__OP_GRAD_STD)
            sph_pair_grad_standard(D, SPH__AT(A->V, 0, j), fj, F, dx, g);
        else if (op == SPH__OP_GRAD_SYM)
            sph_pair_grad_symmetric(D, SPH__AT(A->V, 0, j), fi, fj, F, dx, g);
        else
            sph_pair_grad_difference(D, SPH__AT(A->V, 0, j), fi, fj, F, dx, g);
        if (op == SPH__OP_DENS_GRAD) rho += sph_pair_density(SPH__AT(A->m, 0, j), W);
        if (op == SPH__OP_GRAD_CORR) sph_pair_correction(D, SPH__AT(A->V, 0, j), F, dx, M);
    }
    /* (O7) corrected: B_i g, or the difference scheme where M_i is ill-conditioned */
    return sph__end_grad(A, i, rhoi, g, op == SPH__OP_GRAD_CORR && !sph_correction_invert(D, M, A->rcond_min, B), B,
                         rho);
}

/* (O15)-(O18) velocity gradient, corrected divergence, correction matrix at target i. */
SPH_API int sph__ref_tensor(const sph__args *A, sph_idx i)
{
    const int D = SPH__DIM(A), op = A->op;
    sph_real vi[3] = {0, 0, 0}, S[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, M[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, dx[3], W, F;
    sph__tgt t;
    sph_off o;
    int a;
    sph__tinit(A, i, &t);
    for (a = 0; op != SPH__OP_GRADV_STD && op != SPH__OP_CORRECTION && a < D; ++a) vi[a] = SPH__AT(A->ft, a, i);
    for (o = A->off[i]; o < A->off[i + 1]; ++o) {
        const sph_idx j = A->idx[o];
        const sph_real Vj = SPH__AT(A->V, 0, j);
        sph__pair(A, &t, j, SPH__WANT_F, dx, &W, &F);
        for (a = 0; op != SPH__OP_CORRECTION && a < D; ++a) {
            const sph_real vj = SPH__AT(A->f, a, j);
            if (op == SPH__OP_GRADV_STD) sph_pair_grad_standard(D, Vj, vj, F, dx, S + 3 * a);
            else if (op == SPH__OP_GRADV_SYM) sph_pair_grad_symmetric(D, Vj, vi[a], vj, F, dx, S + 3 * a);
            else sph_pair_grad_difference(D, Vj, vi[a], vj, F, dx, S + 3 * a);
        }
        if (op == SPH__OP_GRADV_CORR || op == SPH__OP_DIV_CORR || op == SPH__OP_CORRECTION)
            sph_pair_correction(D, Vj, F, dx, M);
    }
    return sph__end_tensor(A, i, S, M);
}

/* (O9)-(O11) divergence and curl, standard (u = v_j) and difference (u = v_j - v_i), at target i. */
SPH_API int sph__ref_divcurl(const sph__args *A, sph_idx i)
{
    const int D = SPH__DIM(A), op = A->op;
    const int diff = op == SPH__OP_DIV_DIFF || op == SPH__OP_CURL_DIFF;
    sph_real vi[3] = {0, 0, 0}, s[3] = {0, 0, 0}, dx[3], W, F;
    sph__tgt t;
    sph_off o;
    int a;
    sph__tinit(A, i, &t);
    for (a = 0; diff && a < D; ++a) vi[a] = SPH__AT(A->ft, a, i);
    for (o = A->off[i]; o < A->off[i + 1]; ++o) {
        const sph_idx j = A->idx[o];
        sph_real u[3] = {0, 0, 0};
        sph__pair(A, &t, j, SPH__WANT_F, dx, &W, &F);
        for (a = 0; a < D; ++a) u[a] = SPH__AT(A->f, a, j) - vi[a];
        if (op == SPH__OP_CURL_STD || op == SPH__OP_CURL_DIFF) sph_pair_curl(D, SPH__AT(A->V, 0, j), u, F, dx, s);
        else s[0] += sph_pair_div_standard(D, SPH__AT(A->V, 0, j), u, F, dx);
    }
    return sph__end_divcurl(A, i, s);
}

/* (O12)-(O14) Laplacian and variable-coefficient diffusion at target i. */
SPH_API int sph__ref_lap(const sph__args *A, sph_idx i)
{
    const sph_real fi = SPH__AT(A->ft, 0, i), ki = A->op == SPH__OP_DIFFUSION ? SPH__AT(A->kt, 0, i) : 0;
    sph_real s = 0, dx[3], W, F;
    sph__tgt t;
    sph_off o;
    sph__tinit(A, i, &t);
    for (o = A->off[i]; o < A->off[i + 1]; ++o) {
        const sph_idx j = A->idx[o];
        const sph_real Vj = SPH__AT(A->V, 0, j), fj = SPH__AT(A->f, 0, j);
        sph__pair(A, &t, j, SPH__WANT_F, dx, &W, &F);
        if (A->op == SPH__OP_LAPLACIAN) s += sph_pair_laplacian(Vj, fi, fj, F);
        else s += sph_pair_diffusion(Vj, sph_harmonic_k(ki, SPH__AT(A->k, 0, j)), fi, fj, F);
    }
    SPH__AT(A->out, 0, i) = s;
    return 0;
}

#ifdef _OPENMP
#define SPH__OMP_FOR _Pragma("omp parallel for schedule(static) reduction(+ : n)")
#else
#define SPH__OMP_FOR
#endif

/* Every target through the reference loop of op's family; returns the
 * number of fallbacks (corrected schemes) or empty targets (Shepard). */
SPH_API sph_idx sph__run_reference(const sph__args *A)
{
    int (*target)(const sph__args *, sph_idx) = NULL;
    sph_idx i, n = 0;
    switch (A->op) {
#define SPH__X(name, family) case SPH__OP_##name: target = sph__ref_##family; break;
        SPH__OPS(SPH__X)
#undef SPH__X
    default: return 0;
    }
    SPH__OMP_FOR
    for (i = 0; i < A->nt; ++i) n += target(A, i);
    return n;
}

/* ======================================================================== */
/* Fast loops (compiled unless SPH_OP_REFERENCE is defined)                 */
/* ======================================================================== */
/* The reference loops' arithmetic, reorganised for the vector units: each
 * target's list is taken in chunks of up to SPH__CHUNK pairs, and each chunk
 * in simple loops the compiler vectorises (gather x_j axis by axis into dx
 * and r^2, square roots, the kernel over the chunk, one pass per pair term).
 * Every sum runs over j in list order, as in the reference loops, so without
 * OpenMP the results are bitwise theirs; with OpenMP the sums over a chunk
 * are SIMD reductions (the same for any thread count). The kernel is
 * evaluated by one function per shape (its pieces folded to constants there)
 * called once per chunk, so the operators need no copy per kernel. The
 * density and the difference gradient, the hot loops of most solvers, have
 * a loop per shape of their own instead: one pass in AVX-512 or AVX2 registers
 * (sph__dgv), or elsewhere two passes per chunk (sph__dgc). */
#if !defined(SPH_OP_REFERENCE)
/* the fast loops are compiled (sph_h_solve's density sums use them too) */
#define SPH__FAST_LOOPS 1

#ifndef SPH__CHUNK
#define SPH__CHUNK 32 /* a multiple of 8 */
#endif

/* omp simd (OpenMP 4.0 and later); nothing without OpenMP, so builds without
 * it see no unknown pragma. The SUM forms reduce into s0 and s1. */
#if defined(_OPENMP) && _OPENMP >= 201307
#define SPH__SIMD _Pragma("omp simd")
#define SPH__SIMD_SUM1 _Pragma("omp simd reduction(+ : s0)")
#define SPH__SIMD_SUM2 _Pragma("omp simd reduction(+ : s0, s1)")
#if defined(__clang__)
/* clang reports kernel loops it could not vectorise as errors under
 * -Werror (-Wpass-failed): there they go without the request. */
#define SPH__SIMD_KERNEL
#else
#define SPH__SIMD_KERNEL SPH__SIMD
#endif
#else
#define SPH__SIMD
#define SPH__SIMD_SUM1
#define SPH__SIMD_SUM2
#define SPH__SIMD_KERNEL
#endif

/* The pairs of one chunk (positions k = 0..n-1 of the target's list). */
#if SPH__FIRST
typedef struct {
    sph_real dx[3][SPH__CHUNK]; /* x_i - x_j, minimum image */
    sph_real r[SPH__CHUNK];     /* r^2, then r (zero padded to a multiple of 8) */
    sph_real q[SPH__CHUNK], W[SPH__CHUNK], F[SPH__CHUNK];
    sph_real c[SPH__CHUNK];     /* scratch: h_ij, then a pair term's coefficient */
    sph_real u[3][SPH__CHUNK];  /* scratch: v_j - v_i (divergence, curl) */
    sph_idx j[SPH__CHUNK];
} sph__chunk;
#endif /* SPH__FIRST */

/* One axis of a chunk: d[k] = x_i - x_j of the n sources j[k] (positions x,
 * stride s), with the minimum image where the axis has a period L, and
 * r[k] += d[k]^2 (the first axis: r[k] = d[k]^2, the same bits as 0 + d^2,
 * so that no chunk array is cleared first): sph__pair's arithmetic, bit for
 * bit. The image is tested once per axis, outside the pair loops: inside,
 * the vectoriser would evaluate both sides per pair. */
SPH__INLINE void sph__axis_chunk(const sph_real *x, ptrdiff_t s, const sph_idx *j, int n, sph_real xi, sph_real L,
                                 sph_real iL, sph_real *d, sph_real *r, int first)
{
    int k;
    if (L != 0) {
        SPH__SIMD
        for (k = 0; k < n; ++k) d[k] = xi - x[(ptrdiff_t)j[k] * s];
        sph__image_chunk(d, n, L, iL);
    } else {
        SPH__SIMD
        for (k = 0; k < n; ++k) d[k] = xi - x[(ptrdiff_t)j[k] * s];
    }
    if (first) {
        SPH__SIMD
        for (k = 0; k < n; ++k) r[k] = d[k] * d[k];
    } else {
        SPH__SIMD
        for (k = 0; k < n; ++k) r[k] += d[k] * d[k];
    }
}

/* r[k] = |x_ij| of the n sources j[k] of x_i in D >= 1 axes (x_ij on axis a
 * into d[a]; one scratch array may serve every axis), zero padded to a
 * multiple of 8 for the vector square roots. One instance for every loop
 * that calls it (inlined, it would be a copy per shape and use). */
SPH__NOINLINE void sph__r_chunk(sph_view x, int D, const sph_idx *j, int n, const sph_real *xi, const sph_real *L,
                                const sph_real *iL, sph_real *const *d, sph_real *r)
{
    int a, k;
    for (a = 0; a < D && a < 3; ++a) sph__axis_chunk(x.p[a], x.stride, j, n, xi[a], L[a], iL[a], d[a], r, a == 0);
    for (k = n; (k & 7) != 0; ++k) r[k] = 0;
    sph__sqrt_chunk(r, (n + 7) & ~7);
}

/* w(q) into w and g(q) = w'(q)/q into g (either may be NULL) for n values of
 * q: (K1), (K2) from the natural pieces, instantiated once per shape below. */
SPH__INLINE void sph__shape_run(const sph__nshape *s, const sph_real *q, sph_real *w, sph_real *g, int n)
{
    int k;
    if (w != NULL) {
        SPH__SIMD_KERNEL
        for (k = 0; k < n; ++k) w[k] = sph__nshape_w(s, q[k]);
    }
    if (g != NULL) {
        SPH__SIMD_KERNEL
        for (k = 0; k < n; ++k) g[k] = sph__nshape_g(s, q[k]);
    }
}

/* One instance per shape: SPH__SHAPE_IDS, beside the tables in section 3,
 * lists every shape's index (the generator writes both). */
#define SPH__X(S)                                                                          \
    SPH__NOINLINE void sph__shape_run##S(const sph_real *q, sph_real *w, sph_real *g, int n) \
    {                                                                                      \
        sph__shape_run(&sph__nshapes[S], q, w, g, n);                                      \
    }
SPH__SHAPE_IDS(SPH__X)
#undef SPH__X

SPH__INLINE void sph__shape_chunk(int shape, const sph_real *q, sph_real *w, sph_real *g, int n)
{
    switch (shape) {
#define SPH__X(S) case S: sph__shape_run##S(q, w, g, n); break;
        SPH__SHAPE_IDS(SPH__X)
#undef SPH__X
    default: break;
    }
}

/* (O0), (O1) the n pairs of list positions o..o+n-1 of target t: sph__pair's
 * arithmetic, axis by axis and pass by pass over the chunk. One instance for
 * every operator (a call per chunk costs nothing measurable; inlined into
 * each it was half the compile time of a pinned build's fast loops). */
SPH__NOINLINE void sph__chunk_eval(const sph__args *A, const sph__tgt *t, sph_off o, int n, int want, sph__chunk *P)
{
    const int D = SPH__DIM(A);
    int k, a;
    sph_real *const dx[3] = {P->dx[0], P->dx[1], P->dx[2]};
    for (k = 0; k < n; ++k) P->j[k] = A->idx[o + k];
    sph__r_chunk(A->x, D, P->j, n, t->xi, A->L, A->invL, dx, P->r);
    if ((want & SPH__WANT_W) || !A->hv)
        for (k = 0; k < n; ++k) P->q[k] = P->r[k] * t->hinv;
    if (want == (SPH__WANT_W | SPH__WANT_F) && !A->hv) {
        sph__shape_chunk(t->shape, P->q, P->W, P->F, n);
    } else {
        if (want & SPH__WANT_W) sph__shape_chunk(t->shape, P->q, P->W, NULL, n);
        if (want & SPH__WANT_F) {
            if (A->hv) {
                const sph_real *hs = A->hs.p[0];
                const ptrdiff_t sh = A->hs.stride;
                for (k = 0; k < n; ++k) {
                    P->c[k] = 2 / (t->hi + hs[(ptrdiff_t)P->j[k] * sh]);
                    P->q[k] = P->r[k] * P->c[k];
                }
            }
            sph__shape_chunk(t->shape, P->q, NULL, P->F, n);
        }
    }
    if (want & SPH__WANT_W)
        for (k = 0; k < n; ++k) P->W[k] = t->cW * P->W[k];
    if ((want & SPH__WANT_F) && A->hv) {
        /* alpha h_ij^-(d+2), multiplied as sph__hpow does */
        for (k = 0; k < n; ++k) P->q[k] = t->alpha;
        for (a = 0; a < D + 2; ++a)
            for (k = 0; k < n; ++k) P->q[k] *= P->c[k];
        for (k = 0; k < n; ++k) P->F[k] = P->q[k] * P->F[k];
    } else if (want & SPH__WANT_F) {
        for (k = 0; k < n; ++k) P->F[k] = t->cF * P->F[k];
    }
}

/* The next chunk of target i from list position o; returns its size. */
SPH__INLINE int sph__chunk_next(const sph__args *A, const sph__tgt *t, sph_idx i, sph_off o, int want,
                                sph__chunk *P)
{
    const int n = (A->off[i + 1] - o) < SPH__CHUNK ? (int)(A->off[i + 1] - o) : SPH__CHUNK;
    sph__chunk_eval(A, t, o, n, want, P);
    return n;
}

/* out[e] += sum_k c[k] dx[a][k] (dx[b][k]) in list order: the axis passes of
 * the vector pair terms (b < 0: one factor). */
SPH__INLINE void sph__chunk_axpy(const sph__chunk *P, int n, int a, int b, sph_real *out)
{
    sph_real s0 = *out;
    int k;
    if (b < 0) {
        SPH__SIMD_SUM1
        for (k = 0; k < n; ++k) s0 += P->c[k] * P->dx[a][k];
    } else {
        SPH__SIMD_SUM1
        for (k = 0; k < n; ++k) s0 += P->c[k] * P->dx[a][k] * P->dx[b][k];
    }
    *out = s0;
}

/* (O15) M += sum -V_j F dx_a dx_b over the chunk (c is overwritten). */
SPH__INLINE void sph__chunk_correction(const sph__args *A, const int D, sph__chunk *P, int n, sph_real *M)
{
    int k, a, b;
    for (k = 0; k < n; ++k) P->c[k] = -SPH__AT(A->V, 0, P->j[k]) * P->F[k];
    for (a = 0; a < D; ++a)
        for (b = 0; b < D; ++b) sph__chunk_axpy(P, n, a, b, M + 3 * a + b);
}

/* ---- vector registers: AVX-512 (8 doubles, SPH__OP_AVX512) or AVX2 + FMA (4, SPH__OP_AVX2) ---- */
#if SPH__OP_AVX512 || SPH__OP_AVX2
/* The operations the register loops take of each width: SPH__V(op) names the
 * intrinsic both spell alike (_mm512_op_pd, _mm256_op_pd); a lane mask is a
 * __mmask8, or with AVX2 a vector of all-ones and all-zeros lanes. */
#if SPH__OP_AVX512
#undef SPH__VW
#undef SPH__V
#define SPH__VW 8
#define SPH__V(op) _mm512_##op##_pd
typedef __m512d sph__vd;
typedef __mmask8 sph__vm;
SPH__INLINE sph__vd sph__vsqrt(sph__vd a) { return _mm512_maskz_sqrt_pd(SPH__ALL8, a); }
SPH__INLINE sph__vd sph__vfloor(sph__vd a)
{
    return _mm512_maskz_roundscale_pd(SPH__ALL8, a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
}
SPH__INLINE sph__vm sph__vge(sph__vd a, sph__vd b) { return _mm512_cmp_pd_mask(a, b, _CMP_GE_OQ); }
SPH__INLINE sph__vm sph__vlt(sph__vd a, sph__vd b) { return _mm512_cmp_pd_mask(a, b, _CMP_LT_OQ); }
SPH__INLINE sph__vm sph__vand(sph__vm a, sph__vm b) { return (sph__vm)(a & b); }
/* the first k lanes (none for k <= 0, all from SPH__VW on) */
SPH__INLINE sph__vm sph__vfirst(int k) { return (sph__vm)(k >= 8 ? 0xFF : k <= 0 ? 0 : (1u << k) - 1u); }
/* k ? a : b lane by lane */
SPH__INLINE sph__vd sph__vsel(sph__vm k, sph__vd a, sph__vd b) { return _mm512_mask_mov_pd(b, k, a); }
/* p[o[l]] for the lanes l in k, src elsewhere: scalar loads (the gather
 * instruction is slower on AMD Zen 4, docs/operators.md). */
SPH__INLINE sph__vd sph__vat(sph__vd src, sph__vm k, const sph_real *p, const ptrdiff_t *o)
{
    return _mm512_mask_mov_pd(src, k,
                              _mm512_set_pd((double)p[o[7]], (double)p[o[6]], (double)p[o[5]], (double)p[o[4]],
                                            (double)p[o[3]], (double)p[o[2]], (double)p[o[1]], (double)p[o[0]]));
}
/* The sum of the lanes in the order of _mm512_reduce_add_pd (halves, then
 * quarters, then the last two), through the maskz_ extract (SPH__ALL8). */
SPH__INLINE double sph__vsum(sph__vd v)
{
    const __m256d s4 = _mm256_add_pd(_mm512_maskz_extractf64x4_pd(SPH__ALL8, v, 1),
                                     _mm512_maskz_extractf64x4_pd(SPH__ALL8, v, 0));
    const __m128d s2 = _mm_add_pd(_mm256_extractf128_pd(s4, 1), _mm256_castpd256_pd128(s4));
    return _mm_cvtsd_f64(s2) + _mm_cvtsd_f64(_mm_unpackhi_pd(s2, s2));
}
/* The next lanes' sources j from the list (0 past its end, left entries
 * left) and the mask of the lanes in the list. */
SPH__INLINE sph__vm sph__vidx(const sph_idx *idx, sph_off left, sph_idx *j)
{
    const __mmask8 km = (__mmask8)(left >= 8 ? 0xff : (1u << left) - 1);
    _mm256_storeu_si256((__m256i *)j, _mm256_maskz_loadu_epi32(km, idx));
    return km;
}
#else
#undef SPH__VW
#undef SPH__V
#define SPH__VW 4
#define SPH__V(op) _mm256_##op##_pd
typedef __m256d sph__vd;
typedef __m256d sph__vm;
SPH__INLINE sph__vd sph__vsqrt(sph__vd a) { return _mm256_sqrt_pd(a); }
SPH__INLINE sph__vd sph__vfloor(sph__vd a) { return _mm256_floor_pd(a); }
SPH__INLINE sph__vm sph__vge(sph__vd a, sph__vd b) { return _mm256_cmp_pd(a, b, _CMP_GE_OQ); }
SPH__INLINE sph__vm sph__vlt(sph__vd a, sph__vd b) { return _mm256_cmp_pd(a, b, _CMP_LT_OQ); }
SPH__INLINE sph__vm sph__vand(sph__vm a, sph__vm b) { return _mm256_and_pd(a, b); }
SPH__INLINE sph__vm sph__vfirst(int k)
{
    return _mm256_castsi256_pd(_mm256_cvtepi32_epi64(_mm_cmpgt_epi32(_mm_set1_epi32(k), _mm_setr_epi32(0, 1, 2, 3))));
}
SPH__INLINE sph__vd sph__vsel(sph__vm k, sph__vd a, sph__vd b) { return _mm256_blendv_pd(b, a, k); }
SPH__INLINE sph__vd sph__vat(sph__vd src, sph__vm k, const sph_real *p, const ptrdiff_t *o)
{
    return _mm256_blendv_pd(src, _mm256_set_pd((double)p[o[3]], (double)p[o[2]], (double)p[o[1]], (double)p[o[0]]), k);
}
/* halves, then the last two, as the AVX-512 sum's last steps */
SPH__INLINE double sph__vsum(sph__vd v)
{
    const __m128d s2 = _mm_add_pd(_mm256_extractf128_pd(v, 1), _mm256_castpd256_pd128(v));
    return _mm_cvtsd_f64(s2) + _mm_cvtsd_f64(_mm_unpackhi_pd(s2, s2));
}
SPH__INLINE sph__vm sph__vidx(const sph_idx *idx, sph_off left, sph_idx *j)
{
    const __m128i km = _mm_cmpgt_epi32(_mm_set1_epi32(left >= 4 ? 4 : (int)left), _mm_setr_epi32(0, 1, 2, 3));
    _mm_storeu_si128((__m128i *)j, _mm_maskload_epi32(idx, km));
    return _mm256_castsi256_pd(_mm256_cvtepi32_epi64(km));
}
#endif

/* sph__pform_eval and sph__nshape_pick on the lanes' values of q: the
 * Horner steps as fused multiply-adds (FUSED), or multiplied and added as
 * the scalar forms are where contraction is off (bit for bit). */
SPH__INLINE sph__vd sph__pform_vec(const sph__pform *f, sph__vd q, const int FUSED)
{
    const sph__vd t = SPH__V(sub)(SPH__V(set1)((double)f->b), q), u = SPH__V(sub)(q, SPH__V(set1)((double)f->e));
    sph__vd p = SPH__V(set1)((double)f->c[f->degree]), tm = SPH__V(set1)(1);
    int i;
    SPH__UNROLL
    for (i = f->degree - 1; i >= 0; --i)
        p = FUSED ? SPH__V(fmadd)(p, u, SPH__V(set1)((double)f->c[i]))
                  : SPH__V(add)(SPH__V(mul)(p, u), SPH__V(set1)((double)f->c[i]));
    SPH__UNROLL
    for (i = 0; i < f->m; ++i) tm = SPH__V(mul)(tm, t);
    return SPH__V(mul)(tm, p);
}

SPH__INLINE sph__vd sph__nshape_vpick(const sph__nshape *s, const int G, sph__vd q, const int FUSED)
{
    sph__vd v = sph__pform_vec(sph__nshape_form(s, 0, G), q, FUSED);
    int p;
    SPH__UNROLL
    for (p = 1; p < s->npiece; ++p) {
        const sph__vd x = sph__pform_vec(sph__nshape_form(s, p, G), q, FUSED);
        v = sph__vsel(sph__vge(q, SPH__V(set1)((double)s->lo[p])), x, v);
    }
    return v;
}

/* x_i - x_j on one axis for the lanes (positions p, x_i in xi), minus L times
 * the image floor(x_ij / L + 1/2): with L = 1/L = 0 on an axis without a
 * period that is x_ij exactly, so the loop has no branch per axis. FUSED:
 * in multiply-adds, else multiplied and added as sph__image_chunk (bit for
 * bit). */
SPH__INLINE sph__vd sph__vdx(sph__vd xi, const sph_real *p, sph__vd L, sph__vd iL, sph__vm km, const ptrdiff_t *ox,
                             const int FUSED)
{
    const sph__vd d = SPH__V(sub)(xi, sph__vat(xi, km, p, ox)), h = SPH__V(set1)(0.5);
    if (FUSED) return SPH__V(fnmadd)(L, sph__vfloor(SPH__V(fmadd)(d, iL, h)), d);
    return SPH__V(sub)(d, SPH__V(mul)(L, sph__vfloor(SPH__V(add)(SPH__V(mul)(d, iL), h))));
}
#endif /* SPH__OP_AVX512 || SPH__OP_AVX2 */

/* ---- density and difference gradient in one pass, in registers (SPH__OP_AVX512 or SPH__OP_AVX2) ---- */
#if SPH__OP_AVX512 || SPH__OP_AVX2

/* (O2) rho = sum_j m_j W_ij (dens) and/or (O5) g = sum_j V_j (f_j - f_i) F_ij x_ij
 * (grad) of target t, SPH__VW pairs per step: the chunked loops' arithmetic
 * (IEEE square root, the natural pieces, the division of g by q) in
 * registers, in double for either sph_real; only the order of the sum over
 * j differs. Everything the loop reads of A and t is copied to locals first:
 * the store of the indices through a vector type may alias any memory, and
 * would otherwise reload them every step. */
SPH__INLINE void sph__dgv_body(const sph__args *A, const sph__nshape *sh, const sph__tgt *t, sph_idx i, const int D,
                               int dens, int grad, const int hv, const int one, sph_real fi, sph_real *g, sph_real *rho)
{
    const ptrdiff_t sx = A->x.stride, sm = A->m.stride, sV = A->V.stride, sf = A->f.stride, sh_ = A->hs.stride;
    const sph_real *const pm = A->m.p[0], *const pV = A->V.p[0], *const pf = A->f.p[0], *const ph = A->hs.p[0];
    const sph__vd hiv = SPH__V(set1)((double)t->hi), two = SPH__V(set1)(2), alpha = SPH__V(set1)((double)t->alpha);
    const sph_idx *const idx = A->idx;
    const sph_off end = A->off[i + 1];
    const sph__vd hinv = SPH__V(set1)((double)t->hinv), kap = SPH__V(set1)((double)sh->kappa);
    const sph__vd cW = SPH__V(set1)((double)t->cW), cF = SPH__V(set1)((double)t->cF);
    const sph__vd lo1 = SPH__V(set1)((double)sh->lo[sh->npiece > 1 ? 1 : 0]), onev = SPH__V(set1)(1);
    const sph__vd zero = SPH__V(setzero)(), vfi = SPH__V(set1)((double)fi);
    sph__vd xi[3], L[3], iL[3], s0 = zero, s1 = zero, s2 = zero, sr = zero;
    const sph_real *px[3];
    sph_off o;
    int k, a;
    for (a = 0; a < 3; ++a) {
        const int in = a < D;
        px[a] = in ? A->x.p[a] : NULL;
        xi[a] = SPH__V(set1)(in ? (double)t->xi[a] : 0);
        L[a] = SPH__V(set1)(in ? (double)A->L[a] : 0);
        iL[a] = SPH__V(set1)(in ? (double)A->invL[a] : 0);
    }
    for (o = A->off[i]; o < end; o += SPH__VW) {
        sph_idx j[SPH__VW];
        const sph__vm km = sph__vidx(idx + o, end - o, j);
        ptrdiff_t ox[SPH__VW], om[SPH__VW], oV[SPH__VW], of[SPH__VW], oh[SPH__VW];
        sph__vd d0, d1 = zero, d2 = zero, r2, r, q;
        sph__vm in;
        for (k = 0; k < SPH__VW; ++k) ox[k] = (ptrdiff_t)j[k] * sx;
        if (!one)
            for (k = 0; k < SPH__VW; ++k) om[k] = (ptrdiff_t)j[k] * sm, oV[k] = (ptrdiff_t)j[k] * sV, of[k] = (ptrdiff_t)j[k] * sf;
        if (!one && hv)
            for (k = 0; k < SPH__VW; ++k) oh[k] = (ptrdiff_t)j[k] * sh_;
        d0 = sph__vdx(xi[0], px[0], L[0], iL[0], km, ox, 1);
        r2 = SPH__V(mul)(d0, d0);
        if (D > 1) d1 = sph__vdx(xi[1], px[1], L[1], iL[1], km, ox, 1), r2 = SPH__V(fmadd)(d1, d1, r2);
        if (D > 2) d2 = sph__vdx(xi[2], px[2], L[2], iL[2], km, ox, 1), r2 = SPH__V(fmadd)(d2, d2, r2);
        r = sph__vsqrt(r2);
        q = SPH__V(mul)(r, hinv);
        in = sph__vand(sph__vlt(q, kap), km);
        if (dens) {
            const sph__vd W = sph__vsel(in, SPH__V(mul)(cW, sph__nshape_vpick(sh, 0, q, 1)), zero);
            sr = SPH__V(fmadd)(sph__vat(zero, in, pm, one ? ox : om), W, sr);
        }
        if (grad) {
            /* F at h_ij = (h_i + h_j) / 2 with per-particle h: 1/h_ij, q and
             * alpha h_ij^-(d+2) per lane, multiplied as sph__hpow does */
            sph__vd qF = q, cFj = cF, gq, c;
            sph__vm inF = in;
            if (hv) {
                const sph__vd hinvF = SPH__V(div)(two, SPH__V(add)(hiv, sph__vat(hiv, km, ph, one ? ox : oh)));
                qF = SPH__V(mul)(r, hinvF);
                inF = sph__vand(sph__vlt(qF, kap), km);
                cFj = alpha;
                SPH__UNROLL
                for (a = 0; a < D + 2; ++a) cFj = SPH__V(mul)(cFj, hinvF);
            }
            gq = sph__nshape_vpick(sh, 1, qF, 1);
            if (sh->npiece > 1) gq = SPH__V(div)(gq, sph__vsel(sph__vge(qF, lo1), qF, onev));
            c = SPH__V(mul)(sph__vat(zero, inF, pV, one ? ox : oV), SPH__V(sub)(sph__vat(vfi, inF, pf, one ? ox : of), vfi));
            c = SPH__V(mul)(c, sph__vsel(inF, SPH__V(mul)(cFj, gq), zero));
            s0 = SPH__V(fmadd)(c, d0, s0);
            if (D > 1) s1 = SPH__V(fmadd)(c, d1, s1);
            if (D > 2) s2 = SPH__V(fmadd)(c, d2, s2);
        }
    }
    if (grad) {
        g[0] = (sph_real)sph__vsum(s0);
        g[1] = D > 1 ? (sph_real)sph__vsum(s1) : 0;
        g[2] = D > 2 ? (sph_real)sph__vsum(s2) : 0;
    }
    if (dens) *rho = (sph_real)sph__vsum(sr);
}

/* One instance per shape, holding each use (density, gradient, both) in
 * each dimension as a loop of its own: a flag or a dimension tested per
 * step costs 15-25 % there. */
#define SPH__DGV_ONE(S, D, dn, gr, hv)                                                \
    one ? sph__dgv_body(A, &sph__nshapes[S], t, i, D, dn, gr, hv, 1, fi, g, rho)        \
        : sph__dgv_body(A, &sph__nshapes[S], t, i, D, dn, gr, hv, 0, fi, g, rho)
#define SPH__DGV_USES(S, D)                                                           \
    if (dens && grad && A->hv) /* one instance: each field at its own offsets */      \
        sph__dgv_body(A, &sph__nshapes[S], t, i, D, 1, 1, 1, 0, fi, g, rho);          \
    else if (dens && grad) SPH__DGV_ONE(S, D, 1, 1, 0);                               \
    else if (dens) SPH__DGV_ONE(S, D, 1, 0, 0);                                       \
    else SPH__DGV_ONE(S, D, 0, 1, 0);
#define SPH__X(S)                                                                                  \
    SPH__NOINLINE void sph__dgv_##S(const sph__args *A, const sph__tgt *t, sph_idx i, int dens, int grad, \
                                    sph_real fi, sph_real *g, sph_real *rho)                        \
    {                                                                                              \
        /* views sharing the stride of x (SoA, or one array of structs) share its offsets */       \
        const ptrdiff_t sx = A->x.stride;                                                          \
        const int one = (!dens || A->m.stride == sx) && (!grad || (A->V.stride == sx && A->f.stride == sx)); \
        switch (SPH__DIM(A)) {                                                                     \
        case 1: SPH__DGV_USES(S, 1) break;                                                         \
        case 2: SPH__DGV_USES(S, 2) break;                                                         \
        default: SPH__DGV_USES(S, 3) break;                                                        \
        }                                                                                          \
    }
SPH__SHAPE_IDS(SPH__X)
#undef SPH__X
#undef SPH__DGV_USES
#undef SPH__DGV_ONE

#endif /* SPH__OP_AVX512 || SPH__OP_AVX2 */

/* ---- sph_h_solve's density sums in registers (SPH__OP_AVX512 or SPH__OP_AVX2) ---- */
#if SPH__OP_AVX512 || SPH__OP_AVX2
/* (H2), (K7) the sums of sph_h_solve's density for one particle, SPH__VW
 * pairs per step as sph__dg8_body: sw = sum_j m_j w(q), sd = sum_j m_j (d w + q^2 g),
 * q = r_ij hinv, over list positions o..end-1 (positions x, masses m; L, iL
 * the periods and their inverses, 0 where not periodic). */
SPH__INLINE void sph__hsv_body(const sph__nshape *sh, const int D, sph_view x, sph_view m, const sph_idx *idx, sph_off o,
                               sph_off end, const sph_real *xi_, const sph_real *L_, const sph_real *iL_, sph_real hinv_,
                               sph_real *sw, sph_real *sd)
{
    const ptrdiff_t sx = x.stride, sm = m.stride;
    const sph_real *const pm = m.p[0];
    const sph__vd hinv = SPH__V(set1)((double)hinv_), kap = SPH__V(set1)((double)sh->kappa);
    const sph__vd lo1 = SPH__V(set1)((double)sh->lo[sh->npiece > 1 ? 1 : 0]), one = SPH__V(set1)(1);
    const sph__vd zero = SPH__V(setzero)(), dd = SPH__V(set1)((double)D);
    sph__vd xi[3], L[3], iL[3], s0 = zero, s1 = zero;
    const sph_real *px[3];
    int k, a;
    for (a = 0; a < 3; ++a) {
        const int in = a < D;
        px[a] = in ? x.p[a] : NULL;
        xi[a] = SPH__V(set1)(in ? (double)xi_[a] : 0);
        L[a] = SPH__V(set1)(in ? (double)L_[a] : 0);
        iL[a] = SPH__V(set1)(in ? (double)iL_[a] : 0);
    }
    for (; o < end; o += SPH__VW) {
        sph_idx j[SPH__VW];
        const sph__vm km = sph__vidx(idx + o, end - o, j);
        ptrdiff_t ox[SPH__VW], om[SPH__VW];
        sph__vd d, r2, q, w, g, mj;
        sph__vm in;
        for (k = 0; k < SPH__VW; ++k) ox[k] = (ptrdiff_t)j[k] * sx, om[k] = (ptrdiff_t)j[k] * sm;
        d = sph__vdx(xi[0], px[0], L[0], iL[0], km, ox, 1);
        r2 = SPH__V(mul)(d, d);
        if (D > 1) d = sph__vdx(xi[1], px[1], L[1], iL[1], km, ox, 1), r2 = SPH__V(fmadd)(d, d, r2);
        if (D > 2) d = sph__vdx(xi[2], px[2], L[2], iL[2], km, ox, 1), r2 = SPH__V(fmadd)(d, d, r2);
        q = SPH__V(mul)(sph__vsqrt(r2), hinv);
        in = sph__vand(sph__vlt(q, kap), km);
        w = sph__vsel(in, sph__nshape_vpick(sh, 0, q, 1), zero);
        g = sph__nshape_vpick(sh, 1, q, 1);
        if (sh->npiece > 1) g = SPH__V(div)(g, sph__vsel(sph__vge(q, lo1), q, one));
        g = sph__vsel(in, g, zero);
        mj = sph__vat(zero, in, pm, om);
        s0 = SPH__V(fmadd)(mj, w, s0);
        s1 = SPH__V(fmadd)(mj, SPH__V(fmadd)(dd, w, SPH__V(mul)(SPH__V(mul)(q, q), g)), s1);
    }
    *sw = (sph_real)sph__vsum(s0);
    *sd = (sph_real)sph__vsum(s1);
}

/* One instance per shape, a loop per dimension. */
#define SPH__X(S)                                                                                               \
    SPH__NOINLINE void sph__hsv_##S(int D, sph_view x, sph_view m, const sph_idx *idx, sph_off o, sph_off end,  \
                                    const sph_real *xi, const sph_real *L, const sph_real *iL, sph_real hinv,   \
                                    sph_real *sw, sph_real *sd)                                                 \
    {                                                                                                           \
        if (D == 1) sph__hsv_body(&sph__nshapes[S], 1, x, m, idx, o, end, xi, L, iL, hinv, sw, sd);             \
        else if (D == 2) sph__hsv_body(&sph__nshapes[S], 2, x, m, idx, o, end, xi, L, iL, hinv, sw, sd);        \
        else sph__hsv_body(&sph__nshapes[S], 3, x, m, idx, o, end, xi, L, iL, hinv, sw, sd);                    \
    }
SPH__SHAPE_IDS(SPH__X)
#undef SPH__X
#endif /* SPH__OP_AVX512 || SPH__OP_AVX2 */

/* ---- without AVX-512: density and difference gradient in two passes ---- */
#if !SPH__OP_AVX512 && !SPH__OP_AVX2
#if defined(_OPENMP) && _OPENMP >= 201307 && !defined(__clang__)
#define SPH__SIMD_SUM4 _Pragma("omp simd reduction(+ : s0, s1, s2, s3)")
#else
#define SPH__SIMD_SUM4 /* clang: as SPH__SIMD_KERNEL */
#endif
/* F at h_ij = (h_i + h_j) / 2 for a chunk of pairs with per-particle h: 1/h_ij,
 * q = r h_ij^-1 and alpha h_ij^-(d+2) (multiplied as sph__hpow does), in loops
 * the compilers vectorise (a gather and a division per pair). */
SPH__INLINE void sph__hij_chunk(sph_view hs, const sph_idx *j, int n, int D, sph_real hi, sph_real alpha,
                                const sph_real *r, sph_real *qF, sph_real *cFj)
{
    int k;
    SPH__SIMD
    for (k = 0; k < n; ++k) cFj[k] = 2 / (hi + SPH__AT(hs, 0, j[k]));
    SPH__SIMD
    for (k = 0; k < n; ++k) {
        const sph_real hF = cFj[k], c3 = alpha * hF * hF * hF, c4 = D > 1 ? c3 * hF : c3;
        qF[k] = r[k] * hF;
        cFj[k] = D > 2 ? c4 * hF : c4;
    }
}

/* (O2) rho = sum_j m_j W_ij (dens) and/or (O5) g = sum_j V_j (f_j - f_i) F_ij x_ij
 * (grad) of target t, a chunk at a time: x_ij and r (axis by axis, then the
 * square roots); with per-particle h, 1/h_ij = 2 / (h_i + h_j), q_ij and
 * alpha h_ij^-(d+2) in branch-free loops of their own (a gather and a
 * division per pair the compilers vectorise); then the kernel and every sum
 * in one loop, the shape's pieces constants of the instance. That loop
 * stays scalar where the compiler branches on the pieces (gcc 12: products
 * under a branch may trap, so it does not if-convert them), which is why
 * nothing per pair that can be done apart is left in it. The reference
 * loop's arithmetic pair by pair; without OpenMP its sums in list order too. */
SPH__INLINE void sph__dgc_body(const sph__args *A, const sph__nshape *sh, const sph__tgt *t, sph_idx i, int dens,
                               int grad, const int hv, sph_real fi, sph_real *g, sph_real *rho)
{
    const int D = SPH__DIM(A);
    const sph_real hinv = t->hinv, cW = t->cW, cF = t->cF;
    sph_real s0 = 0, s1 = 0, s2 = 0, s3 = 0, d[3][SPH__CHUNK], r[SPH__CHUNK], qF[SPH__CHUNK], cFj[SPH__CHUNK];
    sph_real *const dp[3] = {d[0], d[1], d[2]};
    sph_off o;
    int n, k, a;
    for (o = A->off[i]; o < A->off[i + 1]; o += n) {
        const sph_idx *j = A->idx + o;
        n = (A->off[i + 1] - o) < SPH__CHUNK ? (int)(A->off[i + 1] - o) : SPH__CHUNK;
        sph__r_chunk(A->x, D, j, n, t->xi, A->L, A->invL, dp, r);
        for (a = D; a < 3; ++a)
            for (k = 0; k < n; ++k) d[a][k] = 0;
        if (hv) sph__hij_chunk(A->hs, j, n, D, t->hi, t->alpha, r, qF, cFj);
        if (dens && !grad) {
            SPH__SIMD_SUM4
            for (k = 0; k < n; ++k) s3 += sph_pair_density(SPH__AT(A->m, 0, j[k]), cW * sph__nshape_w(sh, r[k] * hinv));
        } else {
            SPH__SIMD_SUM4
            for (k = 0; k < n; ++k) {
                const sph_real q = r[k] * hinv;
                const sph_real c = SPH__AT(A->V, 0, j[k]) * (SPH__AT(A->f, 0, j[k]) - fi) *
                                   ((hv ? cFj[k] : cF) * sph__nshape_g(sh, hv ? qF[k] : q));
                if (dens) s3 += sph_pair_density(SPH__AT(A->m, 0, j[k]), cW * sph__nshape_w(sh, q));
                s0 += c * d[0][k];
                s1 += c * d[1][k];
                s2 += c * d[2][k];
            }
        }
    }
    if (grad) {
        g[0] = s0;
        g[1] = D > 1 ? s1 : 0;
        g[2] = D > 2 ? s2 : 0;
    }
    if (dens) *rho = s3;
}
#undef SPH__SIMD_SUM4

#define SPH__X(S)                                                                                  \
    SPH__NOINLINE void sph__dgc_##S(const sph__args *A, const sph__tgt *t, sph_idx i, int dens, int grad, \
                                    sph_real fi, sph_real *g, sph_real *rho)                        \
    {                                                                                              \
        if (dens && grad && A->hv)                                                                 \
            sph__dgc_body(A, &sph__nshapes[S], t, i, 1, 1, 1, fi, g, rho);                         \
        else if (dens && grad)                                                                     \
            sph__dgc_body(A, &sph__nshapes[S], t, i, 1, 1, 0, fi, g, rho);                         \
        else if (dens)                                                                             \
            sph__dgc_body(A, &sph__nshapes[S], t, i, 1, 0, 0, fi, g, rho);                         \
        else                                                                                       \
            sph__dgc_body(A, &sph__nshapes[S], t, i, 0, 1, 0, fi, g, rho);                         \
    }
SPH__SHAPE_IDS(SPH__X)
#undef SPH__X
#endif /* !SPH__OP_AVX512 && !SPH__OP_AVX2 */

/* The one-pass loop for target i (W at h_i; F at h or, in the fused pass
 * with per-particle h, at h_ij per pair; the gradient alone with per-particle
 * h stays with the chunks, one instance fewer per shape to compile): returns
 * 1 with g and/or rho written, else 0. sph__dgv with AVX-512 or AVX2, sph__dgc
 * otherwise. */
#if SPH__OP_AVX512 || SPH__OP_AVX2
#define SPH__DG(S) sph__dgv_##S
#else
#define SPH__DG(S) sph__dgc_##S
#endif
SPH__INLINE int sph__dg(const sph__args *A, const sph__tgt *t, sph_idx i, int dens, int grad, sph_real fi,
                        sph_real *g, sph_real *rho)
{
    if (grad && !dens && A->hv) return 0;
    switch (t->shape) {
#define SPH__X(S) case S: SPH__DG(S)(A, t, i, dens, grad, fi, g, rho); return 1;
        SPH__SHAPE_IDS(SPH__X)
#undef SPH__X
    default: return 0;
    }
}
#undef SPH__DG

/* ---- the fast twin of each reference loop; OP is a constant of the instance ---- */

SPH__INLINE int sph__fast_sum(const sph__args *A, const int OP, sph_idx i)
{
    sph__tgt t;
    sph__chunk P;
    sph_real s0 = 0, s1 = 0;
    sph_off o;
    int n, k;
    sph__tinit(A, i, &t);
    /* the density always takes its shape's own loop (sph__dg serves it for
     * every shape, uniform or per-particle h) */
    if (OP == SPH__OP_DENSITY) {
        (void)sph__dg(A, &t, i, 1, 0, 0, NULL, &s0);
        return sph__end_sum(A, i, s0, 0);
    }
    for (o = A->off[i]; o < A->off[i + 1]; o += n) {
        n = sph__chunk_next(A, &t, i, o, SPH__WANT_W, &P);
        SPH__SIMD_SUM2
        for (k = 0; k < n; ++k) {
            const sph_real Vj = SPH__AT(A->V, 0, P.j[k]);
            s0 += sph_pair_interpolate(Vj, SPH__AT(A->f, 0, P.j[k]), P.W[k]);
            s1 += Vj * P.W[k];
        }
    }
    return sph__end_sum(A, i, s0, s1);
}

SPH__INLINE int sph__fast_grad(const sph__args *A, const int OP, sph_idx i)
{
    const int D = SPH__DIM(A);
    const sph_real fi = sph__fi(A, i), rhoi = OP == SPH__OP_GRAD_PRES ? SPH__AT(A->rhot, 0, i) : 1;
    const sph_real Pi = OP == SPH__OP_GRAD_PRES ? sph_pressure_factor(fi, rhoi) : 0;
    sph_real g[3] = {0, 0, 0}, M[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, B[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, s0 = 0;
    sph__tgt t;
    sph__chunk P;
    sph_off o;
    int n, k, a, fb = 0;
    sph__tinit(A, i, &t);
    if ((OP == SPH__OP_GRAD_DIFF || OP == SPH__OP_DENS_GRAD) && sph__dg(A, &t, i, OP == SPH__OP_DENS_GRAD, 1, fi, g, &s0))
        return sph__end_grad(A, i, rhoi, g, 0, B, s0);
    for (o = A->off[i]; o < A->off[i + 1]; o += n) {
        n = sph__chunk_next(A, &t, i, o, OP == SPH__OP_DENS_GRAD ? SPH__WANT_W | SPH__WANT_F : SPH__WANT_F, &P);
        /* (O4)-(O8) the coefficient c of each pair term c x_ij */
        SPH__SIMD
        for (k = 0; k < n; ++k) {
            const sph_idx j = P.j[k];
            const sph_real fj = SPH__AT(A->f, 0, j), F = P.F[k];
            if (OP == SPH__OP_GRAD_PRES)
                P.c[k] = SPH__AT(A->m, 0, j) * (Pi + sph_pressure_factor(fj, SPH__AT(A->rho, 0, j))) * F;
            else if (OP == SPH__OP_GRAD_STD)
                P.c[k] = SPH__AT(A->V, 0, j) * fj * F;
            else if (OP == SPH__OP_GRAD_SYM)
                P.c[k] = SPH__AT(A->V, 0, j) * (fj + fi) * F;
            else
                P.c[k] = SPH__AT(A->V, 0, j) * (fj - fi) * F;
        }
        for (a = 0; a < D; ++a) sph__chunk_axpy(&P, n, a, -1, g + a);
        if (OP == SPH__OP_DENS_GRAD) {
            SPH__SIMD_SUM1
            for (k = 0; k < n; ++k) s0 += sph_pair_density(SPH__AT(A->m, 0, P.j[k]), P.W[k]);
        }
        if (OP == SPH__OP_GRAD_CORR) sph__chunk_correction(A, D, &P, n, M);
    }
    if (OP == SPH__OP_GRAD_CORR) {
        fb = !sph_correction_invert(D, M, A->rcond_min, B);
        /* a fallback is the difference scheme bit for bit, one-pass loop included */
        if (fb) (void)sph__dg(A, &t, i, 0, 1, fi, g, NULL);
    }
    return sph__end_grad(A, i, rhoi, g, fb, B, s0);
}

SPH__INLINE int sph__fast_tensor(const sph__args *A, const int OP, sph_idx i)
{
    const int D = SPH__DIM(A);
    sph_real vi[3] = {0, 0, 0}, S[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, M[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    sph__tgt t;
    sph__chunk P;
    sph_off o;
    int n, k, a, b;
    sph__tinit(A, i, &t);
    for (a = 0; OP != SPH__OP_GRADV_STD && OP != SPH__OP_CORRECTION && a < D; ++a) vi[a] = SPH__AT(A->ft, a, i);
    for (o = A->off[i]; o < A->off[i + 1]; o += n) {
        n = sph__chunk_next(A, &t, i, o, SPH__WANT_F, &P);
        for (a = 0; OP != SPH__OP_CORRECTION && a < D; ++a) {
            /* (O17) row a: the gradient pair terms of v_a */
            SPH__SIMD
            for (k = 0; k < n; ++k) {
                const sph_idx j = P.j[k];
                const sph_real Vj = SPH__AT(A->V, 0, j), vj = SPH__AT(A->f, a, j);
                P.c[k] = OP == SPH__OP_GRADV_STD   ? Vj * vj * P.F[k]
                         : OP == SPH__OP_GRADV_SYM ? Vj * (vj + vi[a]) * P.F[k]
                                                   : Vj * (vj - vi[a]) * P.F[k];
            }
            for (b = 0; b < D; ++b) sph__chunk_axpy(&P, n, b, -1, S + 3 * a + b);
        }
        if (OP == SPH__OP_GRADV_CORR || OP == SPH__OP_DIV_CORR || OP == SPH__OP_CORRECTION)
            sph__chunk_correction(A, D, &P, n, M);
    }
    return sph__end_tensor(A, i, S, M);
}

SPH__INLINE int sph__fast_divcurl(const sph__args *A, const int OP, sph_idx i)
{
    const int D = SPH__DIM(A), diff = OP == SPH__OP_DIV_DIFF || OP == SPH__OP_CURL_DIFF;
    const int curl = OP == SPH__OP_CURL_STD || OP == SPH__OP_CURL_DIFF;
    sph_real vi[3] = {0, 0, 0}, s[3] = {0, 0, 0};
    sph__tgt t;
    sph__chunk P;
    sph_off o;
    int n, k, a;
    sph__tinit(A, i, &t);
    for (a = 0; diff && a < D; ++a) vi[a] = SPH__AT(A->ft, a, i);
    for (o = A->off[i]; o < A->off[i + 1]; o += n) {
        n = sph__chunk_next(A, &t, i, o, SPH__WANT_F, &P);
        for (a = 0; a < D; ++a)
            for (k = 0; k < n; ++k) P.u[a][k] = SPH__AT(A->f, a, P.j[k]) - vi[a];
        for (k = 0; k < n; ++k) P.c[k] = SPH__AT(A->V, 0, P.j[k]) * P.F[k];
        if (!curl) {
            /* (O9), (O10) V_j F (u . x_ij), the dot product summed axis by axis */
            sph_real s0 = s[0];
            for (k = 0; k < n; ++k) P.q[k] = 0;
            for (a = 0; a < D; ++a)
                for (k = 0; k < n; ++k) P.q[k] += P.u[a][k] * P.dx[a][k];
            SPH__SIMD_SUM1
            for (k = 0; k < n; ++k) s0 += P.c[k] * P.q[k];
            s[0] = s0;
        } else {
            /* (O11) V_j F (x_ij x u): component e takes axes (a, b) */
            int e;
            for (e = 0; e < (D == 3 ? 3 : 1); ++e) {
                const int x0 = D == 3 ? (e + 1) % 3 : 0, x1 = D == 3 ? (e + 2) % 3 : 1;
                sph_real s0 = s[e];
                SPH__SIMD_SUM1
                for (k = 0; k < n; ++k) s0 += P.c[k] * (P.dx[x0][k] * P.u[x1][k] - P.dx[x1][k] * P.u[x0][k]);
                s[e] = s0;
            }
        }
    }
    return sph__end_divcurl(A, i, s);
}

SPH__INLINE int sph__fast_lap(const sph__args *A, const int OP, sph_idx i)
{
    const sph_real fi = SPH__AT(A->ft, 0, i), ki = OP == SPH__OP_DIFFUSION ? SPH__AT(A->kt, 0, i) : 0;
    sph_real s0 = 0;
    sph__tgt t;
    sph__chunk P;
    sph_off o;
    int n, k;
    sph__tinit(A, i, &t);
    for (o = A->off[i]; o < A->off[i + 1]; o += n) {
        n = sph__chunk_next(A, &t, i, o, SPH__WANT_F, &P);
        SPH__SIMD_SUM1
        for (k = 0; k < n; ++k) {
            const sph_idx j = P.j[k];
            const sph_real Vj = SPH__AT(A->V, 0, j), fj = SPH__AT(A->f, 0, j);
            if (OP == SPH__OP_LAPLACIAN) s0 += sph_pair_laplacian(Vj, fi, fj, P.F[k]);
            else s0 += sph_pair_diffusion(Vj, sph_harmonic_k(ki, SPH__AT(A->k, 0, j)), fi, fj, P.F[k]);
        }
    }
    SPH__AT(A->out, 0, i) = s0;
    return 0;
}

/* One function per operator: every target through its family's fast loop. */
#define SPH__X(name, family)                                                       \
    SPH_API sph_idx sph__fast_##name(const sph__args *A)                           \
    {                                                                              \
        sph_idx i, n = 0;                                                          \
        SPH__OMP_FOR                                                               \
        for (i = 0; i < A->nt; ++i) n += sph__fast_##family(A, SPH__OP_##name, i); \
        return n;                                                                  \
    }
SPH__OPS(SPH__X)
#undef SPH__X

SPH_API sph_idx sph__run_fast(const sph__args *A)
{
    SPH__DISPATCH_TO(sph__run_fast, (A))
    switch (A->op) {
#define SPH__X(name, family) case SPH__OP_##name: return sph__fast_##name(A);
        SPH__OPS(SPH__X)
#undef SPH__X
    default: return 0;
    }
}

#undef SPH__SIMD
#undef SPH__SIMD_SUM1
#undef SPH__SIMD_SUM2
#undef SPH__SIMD_KERNEL
#endif /* !SPH_OP_REFERENCE */

/* Every target of the prepared operator A->op: the fast loops, or the
 * reference loops (ctx.loops, or SPH_OP_REFERENCE defined). */
SPH_API sph_idx sph__run(const sph__args *A)
{
#if defined(SPH_OP_REFERENCE)
    return sph__run_reference(A);
#else
    return A->reference ? sph__run_reference(A) : sph__run_fast(A);
#endif
}

/* ---- validation (everything is checked before any output is written) ---- */

/* SPH_OK when components 0..ncomp-1 are present (else SPH_ENULL) and the
 * stride positive (else SPH_ESTRIDE). */
SPH_API int sph__view_ok(sph_view v, int ncomp)
{
    int a;
    for (a = 0; a < ncomp; ++a)
        if (v.p[a] == NULL) return SPH_ENULL;
    return v.stride > 0 ? SPH_OK : SPH_ESTRIDE;
}

SPH_API int sph__out_ok(sph_out v, int ncomp)
{
    int a;
    for (a = 0; a < ncomp; ++a)
        if (v.p[a] == NULL) return SPH_ENULL;
    return v.stride > 0 ? SPH_OK : SPH_ESTRIDE;
}

/* SPH_OK when h is usable by the operators in dim dimensions (sph__h_ok: 64
 * h^-(dim+2) finite, so alpha h^-(dim+2) and every F_ij are;
 * docs/operators.md, "Extreme cases"); else SPH_EH. */
SPH_API int sph__op_h(sph_real h, int dim)
{
    return sph__h_ok(h, dim) ? SPH_OK : SPH_EH;
}

/* Largest |coordinate| the operators take: twice it squared, times 3, stays
 * finite, so no x_ij and no r^2 overflows (docs/operators.md, "Extreme cases"). */
#define SPH__XMAX (sph__sqrt(SPH__REAL_MAX) / 4)

/* Value checks of n entries, ncomp components: kind 0 finite (SPH_ENONFINITE),
 * 1 usable h in dim dimensions (SPH_EH), 2 positive (SPH_EVALUE; densities),
 * 3 positions: |x| <= SPH__XMAX (SPH_EVALUE), 4 not negative (SPH_EVALUE;
 * coefficients). NaN and Inf are SPH_ENONFINITE for every kind but h. */
SPH_API int sph__scan(sph_view v, int ncomp, sph_idx n, int kind, int dim)
{
    sph_idx i;
    int a;
    for (i = 0; i < n; ++i)
        for (a = 0; a < ncomp; ++a) {
            const sph_real y = SPH__AT(v, a, i);
            if (kind == 1 && sph__op_h(y, dim) != SPH_OK) return SPH_EH;
            if (!sph__finite(y)) return SPH_ENONFINITE;
            if (kind == 2 && !(y > 0)) return SPH_EVALUE;
            if (kind == 4 && y < 0) return SPH_EVALUE;
            if (kind == 3 && !(y <= SPH__XMAX && y >= -SPH__XMAX)) return SPH_EVALUE;
        }
    return SPH_OK;
}

/* Presence (and, with full validation, values) of a source view and its target
 * counterpart; an absent target view means "the source view" when the targets
 * are the sources. */
SPH_API int sph__field(const sph_ctx *c, sph_view src, sph_view tgt, int ncomp, int need_target,
                       int kind, sph_view *s_out, sph_view *t_out)
{
    const int same = c->x_target.p[0] == NULL;
    int st = sph__view_ok(src, ncomp);
    *s_out = src;
    *t_out = (same && tgt.p[0] == NULL) ? src : tgt;
    if (st == SPH_OK && need_target) st = sph__view_ok(*t_out, ncomp);
    if (st != SPH_OK || c->validate == SPH_VALIDATE_ARGS) return st;
    st = sph__scan(src, ncomp, c->list->n_sources, kind, c->dim);
    if (st == SPH_OK && need_target) st = sph__scan(*t_out, ncomp, c->list->n_targets, kind, c->dim);
    return st;
}

/* Needs of an operator. */
#if SPH__FIRST
enum { SPH__N_V = 1, SPH__N_M = 2, SPH__N_RHO = 4, SPH__N_FI = 8, SPH__N_K = 16 };
#endif /* SPH__FIRST */

/* Checks the context and the field(s) of one operator (fields f, k with ncomp
 * components) and fills A. */
SPH_API int sph__setup(const sph_ctx *c, int need, int ncomp, sph_view f, sph_view ft, sph_view k,
                       sph_view kt, sph__args *A)
{
    const int full = c != NULL && c->validate != SPH_VALIDATE_ARGS;
    sph_view none = sph_view_none(), unused;
    const sph_box *box;
    int st, a;
    if (c == NULL || c->list == NULL) return SPH_ENULL;
    if ((st = sph_kernel_check(c->kernel, c->dim)) != SPH_OK) return st;
#if defined(SPH_KERNEL)
    if ((int)c->kernel != (int)(SPH_KERNEL)) return SPH_EKERNEL;
#endif
#if defined(SPH_DIM)
    if (c->dim != (SPH_DIM)) return SPH_EDIM;
#endif
    /* the counts against each other first: nothing is read beyond what they allow */
    if (c->list->offset == NULL) return SPH_ENULL;
    if (c->list->n_targets < 0 || c->list->n_sources < 0) return SPH_ECOUNT;
    if (c->x_target.p[0] == NULL && c->list->n_targets > c->list->n_sources) return SPH_ECOUNT;
    if (full && (st = sph_neighbours_check(c->list)) != SPH_OK) return st;
    if (c->list->offset[c->list->n_targets] > 0 && c->list->index == NULL) return SPH_ENULL;
    if (!(c->rcond_min >= 0 && c->rcond_min < 1)) return SPH_ERANGE;
    if (c->loops != SPH_LOOPS_FAST && c->loops != SPH_LOOPS_REFERENCE) return SPH_EOPTION;
    if ((st = sph__box_of(c->box, c->list, c->dim, &box)) != SPH_OK) return st;
    A->kernel = c->kernel;
    A->op = -1;
    A->reference = c->loops == SPH_LOOPS_REFERENCE;
    A->dim = c->dim;
    A->hv = c->h_source.p[0] != NULL;
    for (a = 0; a < 3; ++a) {
        const int per = box != NULL && a < c->dim && box->periodic[a];
        A->L[a] = per ? box->length[a] : 0;
        A->invL[a] = per ? 1 / box->length[a] : 0;
    }
    A->nt = c->list->n_targets;
    A->h = c->h;
    A->rcond_min = c->rcond_min;
    A->off = c->list->offset;
    A->idx = c->list->index;
    A->V = A->m = A->rho = A->rhot = A->f = A->ft = A->k = A->kt = A->hs = A->ht = none;
    A->T = NULL;
    A->Ts = 0;
    if ((st = sph__field(c, c->x, c->x_target, c->dim, 1, 3, &A->x, &A->xt)) != SPH_OK) return st;
    if (A->hv) st = sph__field(c, c->h_source, c->h_target, 1, 1, 1, &A->hs, &A->ht);
    else st = sph__op_h(c->h, c->dim);
    if (st != SPH_OK) return st;
    if ((need & SPH__N_V) && (st = sph__field(c, c->V, none, 1, 0, 0, &A->V, &unused)) != SPH_OK)
        return st;
    if ((need & SPH__N_M) && (st = sph__field(c, c->m, none, 1, 0, 0, &A->m, &unused)) != SPH_OK)
        return st;
    if ((need & SPH__N_RHO) &&
        (st = sph__field(c, c->rho, c->rho_target, 1, 1, 2, &A->rho, &A->rhot)) != SPH_OK)
        return st;
    if ((need & SPH__N_K) && (st = sph__field(c, k, kt, 1, 1, 0, &A->k, &A->kt)) != SPH_OK) return st;
    if (ncomp > 0) st = sph__field(c, f, ft, ncomp, (need & SPH__N_FI) != 0, 0, &A->f, &A->ft);
    return st;
}

/* Runs operator op on the prepared A when the setup succeeded; stores the
 * count of fallbacks (or empty Shepard targets). */
SPH_API int sph__finish(int st, sph__args *A, int op, sph_idx *count)
{
    sph_idx n;
    if (st != SPH_OK) return st;
    A->op = op;
    n = sph__run(A);
    if (count != NULL) *count = n;
    return SPH_OK;
}

/* ---- public operators ---- */

/* (O2) rho_i = sum_j m_j W_ij(h_i) (needs ctx.m). */
SPH_API int sph_density(const sph_ctx *c, sph_out rho)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_M, 0, sph_view_none(), sph_view_none(), sph_view_none(),
                        sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(rho, 1);
    A.out = rho;
    return sph__finish(st, &A, SPH__OP_DENSITY, NULL);
}

/* (O3) <f>_i = sum_j V_j f_j W_ij(h_i) (needs ctx.V). */
SPH_API int sph_interpolate(const sph_ctx *c, sph_view f, sph_out out)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_V, 1, f, sph_view_none(), sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(out, 1);
    A.out = out;
    return sph__finish(st, &A, SPH__OP_INTERP, NULL);
}

/* (O3) Shepard: sum_j V_j f_j W_ij / sum_j V_j W_ij; 0 for a target whose
 * denominator is 0 (no sources in reach), counted in *n_empty (may be NULL). */
SPH_API int sph_interpolate_shepard(const sph_ctx *c, sph_view f, sph_out out, sph_idx *n_empty)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_V, 1, f, sph_view_none(), sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(out, 1);
    A.out = out;
    return sph__finish(st, &A, SPH__OP_SHEPARD, n_empty);
}

/* (O4)-(O8) gradient of the scalar f (f_target: target values, needed by all
 * schemes but the standard one when targets are not the sources). Corrected:
 * targets with an ill-conditioned M fall back to the difference scheme, counted
 * in *n_fallback (may be NULL). Pressure: f is p, needs ctx.m, rho, rho_target. */
SPH_API int sph_gradient(const sph_ctx *c, sph_scheme scheme, sph_view f, sph_view f_target,
                         sph_out grad, sph_idx *n_fallback)
{
    sph__args A;
    const int op =
        scheme == SPH_SCHEME_STANDARD ? SPH__OP_GRAD_STD
        : scheme == SPH_SCHEME_DIFFERENCE ? SPH__OP_GRAD_DIFF
        : scheme == SPH_SCHEME_SYMMETRIC ? SPH__OP_GRAD_SYM
        : scheme == SPH_SCHEME_CORRECTED ? SPH__OP_GRAD_CORR
        : scheme == SPH_SCHEME_PRESSURE ? SPH__OP_GRAD_PRES : -1;
    const int need = scheme == SPH_SCHEME_PRESSURE ? SPH__N_M | SPH__N_RHO | SPH__N_FI
                     : scheme == SPH_SCHEME_STANDARD ? SPH__N_V : SPH__N_V | SPH__N_FI;
    int st = op < 0 ? SPH_EOPTION : sph__setup(c, need, 1, f, f_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(grad, c->dim);
    A.out = grad;
    if (n_fallback != NULL && st == SPH_OK) *n_fallback = 0;
    return sph__finish(st, &A, op, scheme == SPH_SCHEME_CORRECTED ? n_fallback : NULL);
}

/* (O2) and (O5) in one pass over the list: rho_i = sum_j m_j W_ij(h_i) and
 * the difference gradient sum_j V_j (f_j - f_i) grad_i W_ij(h_ij) (needs
 * ctx.m and ctx.V; V_j from the previous densities, as a solver's step has
 * them). The same values as sph_density and sph_gradient(DIFFERENCE) to
 * round-off, in about the time of one of them. */
SPH_API int sph_density_gradient(const sph_ctx *c, sph_view f, sph_view f_target, sph_out rho,
                                 sph_out grad)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_M | SPH__N_V | SPH__N_FI, 1, f, f_target, sph_view_none(),
                        sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(rho, 1);
    if (st == SPH_OK) st = sph__out_ok(grad, c->dim);
    A.out = grad;
    A.out2 = rho;
    return sph__finish(st, &A, SPH__OP_DENS_GRAD, NULL);
}

/* (O17) velocity-gradient tensor of the vector v (dim components):
 * T[i * T_stride + a * dim + b] = d v_a / d x_b, schemes standard, difference,
 * symmetric, corrected (fallbacks as sph_gradient). T_stride >= dim * dim. */
SPH_API int sph_gradient_vector(const sph_ctx *c, sph_scheme scheme, sph_view v, sph_view v_target,
                                sph_real *T, ptrdiff_t T_stride, sph_idx *n_fallback)
{
    sph__args A;
    const int op =
        scheme == SPH_SCHEME_STANDARD ? SPH__OP_GRADV_STD
        : scheme == SPH_SCHEME_DIFFERENCE ? SPH__OP_GRADV_DIFF
        : scheme == SPH_SCHEME_SYMMETRIC ? SPH__OP_GRADV_SYM
        : scheme == SPH_SCHEME_CORRECTED ? SPH__OP_GRADV_CORR : -1;
    const int need = scheme == SPH_SCHEME_STANDARD ? SPH__N_V : SPH__N_V | SPH__N_FI;
    int st = op < 0 ? SPH_EOPTION
             : sph__setup(c, need, c != NULL ? c->dim : 1, v, v_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK && T == NULL) st = SPH_ENULL;
    if (st == SPH_OK && T_stride < (ptrdiff_t)c->dim * c->dim) st = SPH_ESTRIDE;
    A.T = T;
    A.Ts = T_stride;
    if (n_fallback != NULL && st == SPH_OK) *n_fallback = 0;
    return sph__finish(st, &A, op, scheme == SPH_SCHEME_CORRECTED ? n_fallback : NULL);
}

/* (O9), (O10), (O18) divergence of v: standard, difference or corrected
 * (trace of the corrected tensor; fallbacks as sph_gradient). */
SPH_API int sph_divergence(const sph_ctx *c, sph_scheme scheme, sph_view v, sph_view v_target,
                           sph_out div, sph_idx *n_fallback)
{
    sph__args A;
    const int op =
        scheme == SPH_SCHEME_STANDARD ? SPH__OP_DIV_STD
        : scheme == SPH_SCHEME_DIFFERENCE ? SPH__OP_DIV_DIFF
        : scheme == SPH_SCHEME_CORRECTED ? SPH__OP_DIV_CORR : -1;
    const int need = scheme == SPH_SCHEME_STANDARD ? SPH__N_V : SPH__N_V | SPH__N_FI;
    int st = op < 0 ? SPH_EOPTION
             : sph__setup(c, need, c != NULL ? c->dim : 1, v, v_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(div, 1);
    A.out = div;
    if (n_fallback != NULL && st == SPH_OK) *n_fallback = 0;
    return sph__finish(st, &A, op, scheme == SPH_SCHEME_CORRECTED ? n_fallback : NULL);
}

/* (O11) curl of v, standard or difference: dim 2 writes the scalar
 * d v_y/dx - d v_x/dy to component 0, dim 3 the vector; dim 1 is SPH_EDIM. */
SPH_API int sph_curl(const sph_ctx *c, sph_scheme scheme, sph_view v, sph_view v_target, sph_out curl)
{
    sph__args A;
    const int op =
        scheme == SPH_SCHEME_STANDARD ? SPH__OP_CURL_STD
        : scheme == SPH_SCHEME_DIFFERENCE ? SPH__OP_CURL_DIFF : -1;
    const int need = scheme == SPH_SCHEME_STANDARD ? SPH__N_V : SPH__N_V | SPH__N_FI;
    int st = op < 0 ? SPH_EOPTION
             : sph__setup(c, need, c != NULL ? c->dim : 1, v, v_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK && c->dim == 1) st = SPH_EDIM;
    if (st == SPH_OK) st = sph__out_ok(curl, c->dim == 2 ? 1 : 3);
    A.out = curl;
    return sph__finish(st, &A, op, NULL);
}

/* (O12) lap f_i = 2 sum_j V_j (f_i - f_j) F_ij. */
SPH_API int sph_laplacian(const sph_ctx *c, sph_view f, sph_view f_target, sph_out lap)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_V | SPH__N_FI, 1, f, f_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(lap, 1);
    A.out = lap;
    return sph__finish(st, &A, SPH__OP_LAPLACIAN, NULL);
}

/* (O14) div(k grad f)_i = sum_j V_j k_ij (f_i - f_j) F_ij, k_ij from (O13);
 * for a constant k it equals k times sph_laplacian. */
SPH_API int sph_diffusion(const sph_ctx *c, sph_view k, sph_view k_target, sph_view f,
                          sph_view f_target, sph_out out)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_V | SPH__N_FI | SPH__N_K, 1, f, f_target, k, k_target, &A);
    if (st == SPH_OK) st = sph__out_ok(out, 1);
    A.out = out;
    return sph__finish(st, &A, SPH__OP_DIFFUSION, NULL);
}

/* (O15), (O16) the correction matrix B_i = M_i^-1 of every target:
 * B[i * B_stride + a * dim + b]; identity where M_i is ill-conditioned
 * (counted in *n_fallback, may be NULL). B_stride >= dim * dim. */
SPH_API int sph_correction_matrix(const sph_ctx *c, sph_real *B, ptrdiff_t B_stride, sph_idx *n_fallback)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_V, 0, sph_view_none(), sph_view_none(), sph_view_none(),
                        sph_view_none(), &A);
    if (st == SPH_OK && B == NULL) st = SPH_ENULL;
    if (st == SPH_OK && B_stride < (ptrdiff_t)c->dim * c->dim) st = SPH_ESTRIDE;
    A.T = B;
    A.Ts = B_stride;
    return sph__finish(st, &A, SPH__OP_CORRECTION, n_fallback);
}

/* The validator behind SPH_ENONFINITE (docs/operators.md, "Extreme cases"):
 * scans components 0..ncomp-1 of particles 0..n-1 of f in particle order and
 * returns SPH_ENONFINITE at the first NaN or Inf, its particle in *first_bad
 * (may be NULL); SPH_OK and *first_bad = -1 when every value is finite.
 * SPH_ENULL for an absent component, SPH_ERANGE for ncomp outside 1..3,
 * SPH_ESTRIDE for a stride <= 0, SPH_ECOUNT for n < 0 (*first_bad untouched
 * on those). */
SPH_API int sph_check_field(sph_view f, int ncomp, sph_idx n, sph_idx *first_bad)
{
    sph_idx i;
    int a, st;
    if (ncomp < 1 || ncomp > 3) return SPH_ERANGE;
    if ((st = sph__view_ok(f, ncomp)) != SPH_OK) return st;
    if (n < 0) return SPH_ECOUNT;
    for (i = 0; i < n; ++i)
        for (a = 0; a < ncomp; ++a) {
            const sph_real y = SPH__AT(f, a, i);
            if (!sph__finite(y)) {
                if (first_bad != NULL) *first_bad = i;
                return SPH_ENONFINITE;
            }
        }
    if (first_bad != NULL) *first_bad = -1;
    return SPH_OK;
}


#endif /* section 6 */

#if !defined(SPH_ONLY_PAIRS) && !defined(SPH_NO_NSEARCH) /* section 7 */

/* ======================================================================== */
/* 7. Neighbour search                                                       */
/* ======================================================================== */
/* Cell-list neighbour search (docs/neighbours.md). Builds the CSR lists of
 * section 4 in O(N), in arrays the caller owns; nothing is allocated.
 *
 *   size_t bytes;                                             1. size query
 *   sph_nsearch_workspace_size(dim, xs, ns, hs, cell, box, &bytes);
 *   void *work = malloc(bytes);
 *   sph_nsearch g;                                            2. bin sources
 *   sph_nsearch_build(&g, dim, xs, ns, hs, cell, box, work, bytes);
 *   sph_off *offset = malloc((nt + 1) * sizeof *offset);       3. count
 *   sph_nsearch_count(&g, xt, nt, ht, h, kappa, SPH_NSEARCH_GATHER, offset);
 *   sph_idx *index = malloc(offset[nt] * sizeof *index);       4. fill
 *   sph_nsearch_fill(&g, xt, nt, ht, h, kappa, SPH_NSEARCH_GATHER, offset, index, offset[nt]);
 *
 * or steps 3 and 4 in one search per target, into an index with some slack
 * (SPH_ESIZE, offset complete, when it is too short: then fill as in 4):
 *   sph_nsearch_lists(&g, xt, nt, ht, h, kappa, SPH_NSEARCH_GATHER, offset, index, capacity, &pairs);
 *
 * Criterion (eq. (N1)-(N3)): source j is a neighbour of target i iff
 * r_ij^2 < R^2 with R = kappa h_i (SPH_NSEARCH_GATHER) or
 * R = kappa max(h_i, h_j) (SPH_NSEARCH_SYMMETRIC), r_ij^2 the sum over the
 * axes of sph_box_delta(box, a, x_i,a - x_j,a)^2 in axis order: exactly the
 * arithmetic of a brute-force double loop, so the lists are equal bit for bit.
 * Within each target the sources are in ascending index (deterministic, and
 * the same for any number of OpenMP threads).
 *
 * Sources (xs, ns, optional per-source h hs) are binned once by build into a
 * grid of cells of edge >= cell (recommended: kappa h / 2; with per-source
 * h, kappa h_max / 2, which the build refines to the h the sources have:
 * docs/neighbours.md, "Varying h"); targets (xt, nt,
 * optional per-target h ht) are any point set: the sources themselves,
 * probe points, ghosts. Per-particle h are views like every other field
 * (sph_view_soa(h, NULL, NULL), or sph_view_none() when absent); h is the
 * uniform smoothing length wherever the view is absent. Any cell size gives the same lists; it
 * only sets speed and workspace. Periodic axes of box tile the period with
 * n_a = max(1, floor(L_a / cell)) cells (eq. (N4)) and positions anywhere are
 * wrapped into it; the other axes span the bounding box of the sources (the
 * box's lo and length are not used there). The grid copies the source
 * positions (sorted by cell) into the workspace: the caller's arrays may
 * change after build, the workspace must not.
 *
 * Algorithm: a stable counting sort bins the sources (O(N + cells)); each
 * target scans only the cells whose nearest point lies within its radius, an
 * x row of cells at a time as one contiguous run of sorted sources (two where
 * a periodic axis wraps), then sorts its list. With cells of R/2 that is about
 * 2.5 candidate checks per neighbour in 3-D (docs/neighbours.md). A target
 * whose reach is at most 16 cells finds its rows from squared cell gaps
 * computed once per axis (clamped at open faces, wrapped round periodic
 * axes). In symmetric mode with per-source h a target reaches only as far
 * as the sources that may reach it (per-cell largest h, pushed over the
 * cells each reaches), and
 * of each row only the cells whose own reach covers it (SPH_NSEARCH_PLAIN:
 * one radius kappa max(h_i, h_max), cells of cell). When the targets are
 * the sources themselves (same count, positions and h) and kappa h_max is
 * within a quarter period, lists and fill build the symmetric lists from
 * one gather search instead: row i = gather row i + the sources j whose
 * kappa h_j reaches i from beyond kappa h_i, marked in gather row j and
 * transposed (O(pairs) more; same lists bit for bit; the workspace holds
 * 12 bytes per source more for it, and one such search runs on a grid at a
 * time); count, and lists with an index shorter than the gather pairs,
 * search directly. Each run carries its periodic image offset, so the checks need no
 * minimum image. Runs are checked in branch-free blocks of 8
 * sources (16, in vector registers, at AVX2 or AVX-512). Count, fill and lists run in
 * parallel over targets under OpenMP.
 *
 * Optional locality: sph_nsearch_permutation gives perm[new] = old (sources
 * by cell); sph_permute applies it to any field. Searching the sorted
 * particles is faster and their lists map back to the unsorted ones.
 *
 * Every function returns SPH_OK or a negative status: SPH_EDIM (dim outside
 * 1..3), SPH_ECOUNT (negative count or capacity, more than
 * SPH_NSEARCH_MAX_SOURCES sources), SPH_ESIZE (workspace or index too
 * small), SPH_EGRID (more than SPH_NSEARCH_MAX_CELLS cells: a source far
 * from the others, or a cell size too small for the cloud), SPH_ENULL,
 * SPH_EH (h not positive and finite), SPH_ENONFINITE (NaN or Inf position),
 * SPH_ERANGE (cell or kappa not positive and finite, ncomp outside 1..3),
 * SPH_EOPTION (mode neither GATHER nor SYMMETRIC), SPH_EBOXLEN (a periodic
 * axis with lo not finite or a length not positive and finite),
 * SPH_ENOGRID (grid not built, or its build failed), SPH_EOFFSET (offsets
 * malformed or not from a count with the same arguments), SPH_EPERIOD (a
 * search radius above half a period: the minimum image of eq. (N3) would
 * see one image of a source where two or more lie within reach),
 * SPH_EINDEX (not a permutation).
 *
 * sph_nsearch_list records the grid's box in the list (box_known): the
 * operators and section 9 then take the periodic axes from the list and
 * refuse a context whose box differs (SPH_EBOX).
 *
 * Limits, in one place (docs/neighbours.md, "Limits"): particle counts and
 * source indices are sph_idx (int32), so at most 2^31 - 1 targets and
 * SPH_NSEARCH_MAX_SOURCES = 2^31 - 17 sources; a grid has at most
 * SPH_NSEARCH_MAX_CELLS = 2^29 - 1 cells; list positions are sph_off (int64),
 * so the total list length is bounded by memory alone. */

#if SPH__FIRST
enum { SPH_NSEARCH_GATHER = 0, SPH_NSEARCH_SYMMETRIC = 1 };
enum { SPH__NS_MARK = 2 }; /* gather, the lists marked for the symmetric ones (sph__nsearch_sym_lists) */
#endif /* SPH__FIRST */

/* Hard limits (docs/neighbours.md, "Limits"): cells of a grid, per axis
 * and in all, so that every cell index stays in int (more: SPH_EGRID), and
 * sources of a grid, so that the padded arrays stay indexable by sph_idx
 * (more: SPH_ECOUNT). */
#define SPH_NSEARCH_MAX_CELLS 536870911    /* 2^29 - 1 */
#define SPH_NSEARCH_MAX_SOURCES 2147483631 /* 2^31 - 17 */

/* A cell grid over the sources. Filled by sph_nsearch_build; the arrays live
 * in the caller's workspace. */
#if SPH__FIRST
typedef struct {
    int dim;              /* 1..3 once built, 0 otherwise */
    int n[3];             /* cells per axis (1 for unused axes) */
    int n_cells;          /* n[0] n[1] n[2] */
    sph_idx n_sources;
    sph_real lo[3];       /* grid origin */
    sph_real w[3];        /* cell width per axis */
    sph_real inv_w[3];    /* 1 / w */
    sph_real quarter[3];  /* L / 4 on periodic axes, the largest real elsewhere */
    sph_real quarter2;    /* smallest quarter[a]^2 of the periodic axes, the largest real without */
    sph_real image_ok[3]; /* 0.49 L on periodic axes, the largest real elsewhere: an image offset that leaves |d_a|
                             below it gave the minimum image (eq. (N7)) */
    sph_real slack;       /* rounding allowance added to every search radius */
    sph_real h_max;       /* largest per-source h (0 without per-source h) */
    sph_box box;          /* copy of the caller's box (periodic axes) */
    sph_idx *cell_start;  /* [n_cells + 1]: sources of cell c are sorted positions cell_start[c].. */
    sph_idx *order;       /* [n_padded]: source index at each sorted position */
    sph_real *x;          /* [dim * n_padded]: source positions in sorted order, by axis: x[a n_padded + k] */
    sph_real *h;          /* [n_padded] per-source h in sorted order, or NULL */
    sph_idx n_padded;     /* n_sources + SPH__NS_PAD: the arrays' length (padding read by the blocked checks) */
    int n_occupied;       /* cells holding at least one source (fill ratio n_occupied / n_cells) */
    sph_real w_min;       /* smallest cell width of the used axes */
    sph_real cell_hint;   /* the cell edge given to build */
    sph_real h_min;       /* smallest per-source h (h_max without per-source h) */
    sph_real *hcell;      /* [n_cells] largest per-source h of each cell, or NULL (no per-source h, or plain) */
    sph_real *hreach;     /* [2 n_cells] per cell the largest hcell of the cells whose reach covers it
                             (sph__nsearch_hbuild), then a scratch table; or NULL */
    sph_real kappa_b;     /* hreach holds for every kappa up to this one (the given cell as kappa h_max / 2) */
    sph_real h_far;       /* largest hcell of the cells reaching beyond SPH__NS_PUSH cells (0: none) */
    int plain;            /* 1: the plain reference search (SPH_NSEARCH_PLAIN) */
    sph_idx *sym;         /* [2 n_padded] per source its gather row's length, then the marks in that row, and */
    sph_off *sym_at;      /* [n_padded] the sources reaching it from beyond it: their count, then the
                             next place for one (the symmetric lists from the gather ones,
                             sph__nsearch_sym_lists); both NULL without hcell */
    float *hf;            /* [n_padded] h rounded to float, for the own radius of the vector marked search in double
                             (half the bytes of h to load), NaN where h lies outside 1e-30..1e30 (decided from h
                             itself); NULL without hcell or a vector level (SPH__NS_HF), and in float */
} sph_nsearch;
#endif /* SPH__FIRST */

/* Candidates are checked in blocks of SPH__NS_BLOCK consecutive sorted
 * sources; the arrays of the grid are padded by one block. A target's runs
 * are collected SPH__NS_RUNS at a time before any is checked, so that the
 * cell arithmetic of one row does not wait on the checks of the last. */
/* The vector check of a block (SPH__NS_VEC: AVX2 + FMA or AVX-512): r^2 in
 * doubles, SPH__NSW lanes a register (sph__nsv), each lane test a bit of an
 * unsigned mask. The names of one level; the AVX-512 and AVX2 spellings of
 * the same operations. */
#undef SPH__NSW
#undef SPH__NSV
#if SPH__ISA == 2
#define SPH__NSW 8
#define SPH__NSV(op) _mm512_##op##_pd
typedef __m512d sph__nsv;
/* SPH__NSW floats as doubles (exact) */
SPH__INLINE sph__nsv sph__nsv_loadf(const float *p) { return _mm512_maskz_cvtps_pd(SPH__ALL8, _mm256_loadu_ps(p)); }
/* bit l of the result: a_l < b_l (ordered), a_l not >= b_l (NaN too), a_l > b_l, for the lanes of lv */
SPH__INLINE unsigned sph__nsv_lt(sph__nsv a, sph__nsv b, unsigned lv) { return _mm512_mask_cmp_pd_mask((__mmask8)lv, a, b, _CMP_LT_OQ); }
SPH__INLINE unsigned sph__nsv_nge(sph__nsv a, sph__nsv b, unsigned lv) { return _mm512_mask_cmp_pd_mask((__mmask8)lv, a, b, _CMP_NGE_UQ); }
SPH__INLINE unsigned sph__nsv_gt(sph__nsv a, sph__nsv b, unsigned lv) { return _mm512_mask_cmp_pd_mask((__mmask8)lv, a, b, _CMP_GT_OQ); }
SPH__INLINE sph__nsv sph__nsv_abs(sph__nsv a) { return _mm512_abs_pd(a); }
SPH__INLINE sph__nsv sph__nsv_max(sph__nsv a, sph__nsv b) { return _mm512_maskz_max_pd(SPH__ALL8, a, b); }
/* the lanes rounded to float (for SPH_REAL float) */
SPH__INLINE sph__nsv sph__nsv_round(sph__nsv v) { return _mm512_maskz_cvtps_pd(SPH__ALL8, _mm512_maskz_cvtpd_ps(SPH__ALL8, v)); }
#elif SPH__ISA == 1
#define SPH__NSW 4
#define SPH__NSV(op) _mm256_##op##_pd
typedef __m256d sph__nsv;
SPH__INLINE sph__nsv sph__nsv_loadf(const float *p) { return _mm256_cvtps_pd(_mm_loadu_ps(p)); }
SPH__INLINE unsigned sph__nsv_lt(sph__nsv a, sph__nsv b, unsigned lv) { return (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(a, b, _CMP_LT_OQ)) & lv; }
SPH__INLINE unsigned sph__nsv_nge(sph__nsv a, sph__nsv b, unsigned lv) { return (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(a, b, _CMP_NGE_UQ)) & lv; }
SPH__INLINE unsigned sph__nsv_gt(sph__nsv a, sph__nsv b, unsigned lv) { return (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(a, b, _CMP_GT_OQ)) & lv; }
SPH__INLINE sph__nsv sph__nsv_abs(sph__nsv a) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), a); }
SPH__INLINE sph__nsv sph__nsv_max(sph__nsv a, sph__nsv b) { return _mm256_max_pd(a, b); }
SPH__INLINE sph__nsv sph__nsv_round(sph__nsv v) { return _mm256_cvtps_pd(_mm256_cvtpd_ps(v)); }
#endif
#if SPH__NS_VEC
/* SPH__NSW consecutive sph_real as doubles (exact for float); the sizeof test folds */
SPH__INLINE sph__nsv sph__nsv_load(const sph_real *p)
{
    return sizeof(sph_real) == sizeof(double) ? SPH__NSV(loadu)((const double *)(const void *)p)
                                              : sph__nsv_loadf((const float *)(const void *)p);
}
#endif

#undef SPH__NS_BLOCK
#if SPH__NS_VEC
#define SPH__NS_BLOCK 16
#else
#define SPH__NS_BLOCK 8
#endif
/* The padding of the grid's arrays, and whether it keeps h in float (hf):
 * as the widest level of this unit needs, so that a grid built at one
 * level serves the others (sph_isa_set). */
#if SPH__ISA_BUILD >= 1 || SPH__PASS_AVX512 || SPH__PASS_AVX2
#define SPH__NS_PAD 16
#define SPH__NS_HF 1
#else
#define SPH__NS_PAD 8
#define SPH__NS_HF 0
#endif
#define SPH__NS_RUNS 32
/* The vector loops' r^2 (contracted or not, summed in another order) lies
 * within a few ulp of the criterion's: beyond this relative band around R^2
 * they decide, inside it sph__nsearch_in does. SPH__NS_BAND: whether the
 * portable block loop needs the band, i.e. whether the compiler may fuse its
 * d^2 + r^2: not on x86 without FMA (a plain -O2 build), where that loop is
 * the criterion's arithmetic bit for bit and the band cost 20-45 %. */
#define SPH__NS_EDGE (16 * (sizeof(sph_real) == sizeof(float) ? (sph_real)FLT_EPSILON : (sph_real)DBL_EPSILON))
#undef SPH__NS_BAND
#if (defined(__x86_64__) || defined(__i386__)) && SPH__ISA == 0 && !defined(__FMA__)
#define SPH__NS_BAND 0
#else
#define SPH__NS_BAND 1
#endif

/* SPH_NSEARCH_PLAIN: the plain reference search (docs/neighbours.md,
 * "Varying h"), tested equal to the default. */
#if defined(SPH_NSEARCH_PLAIN)
#define SPH__NS_PLAIN 1
#else
#define SPH__NS_PLAIN 0
#endif

/* Cells of one axis within reach of a target: up to two runs of cells
 * (wrapped index lo..hi, geometric position of cell k is k + shift), in
 * ascending cell order; full = the whole periodic axis (distance 0). */
#if SPH__FIRST
typedef struct {
    int lo[2], hi[2], shift[2];
    int count;
    int full;
} sph__span;
#endif /* SPH__FIRST */

SPH_API sph_real sph__nsearch_eps(void)
{
    return sizeof(sph_real) == sizeof(float) ? (sph_real)FLT_EPSILON : (sph_real)DBL_EPSILON;
}

/* Component a of particle i of a view. */
SPH_API sph_real sph__ns_at(sph_view v, int a, sph_idx i) { return v.p[a][(ptrdiff_t)i * v.stride]; }

/* The view from particle i0 on (ncomp components; an absent view stays absent). */
SPH_API sph_view sph__ns_tail(sph_view v, int ncomp, sph_idx i0)
{
    int a;
    for (a = 0; a < ncomp; ++a)
        if (v.p[a] != NULL) v.p[a] += (ptrdiff_t)i0 * v.stride;
    return v;
}

/* Largest |x_a| over n particles of a view (0 for none), or -1 when one of
 * them is NaN or infinite. One pass without a branch. */
SPH_API sph_real sph__ns_absmax(sph_view v, int a, sph_idx n)
{
    const sph_real *p = v.p[a];
    const ptrdiff_t st = v.stride;
    sph_real m = 0;
    int nan = 0;
    sph_idx i;
    for (i = 0; i < n; ++i) {
        const sph_real x = p[(ptrdiff_t)i * st], ax = x < 0 ? -x : x;
        m = ax > m ? ax : m;
        nan |= x != x;
    }
    return nan || !(m <= SPH__REAL_MAX) ? (sph_real)-1 : m;
}

/* Checks a position view of n particles: SPH_ENULL or SPH_ENONFINITE; the
 * largest |x_a| per axis into amax (when not NULL). */
SPH_API int sph__ns_scan_x(int dim, sph_view x, sph_idx n, sph_real *amax)
{
    int a;
    for (a = 0; a < dim && n > 0; ++a)
        if (x.p[a] == NULL) return SPH_ENULL;
    for (a = 0; a < dim; ++a) {
        const sph_real m = n > 0 ? sph__ns_absmax(x, a, n) : 0;
        if (m < 0) return SPH_ENONFINITE;
        if (amax != NULL) amax[a] = m;
    }
    return SPH_OK;
}

SPH_API int sph__ns_check_x(int dim, sph_view x, sph_idx n) { return sph__ns_scan_x(dim, x, n, NULL); }

/* Checks n per-particle smoothing lengths (absent view: none) in dim
 * dimensions (sph__h_ok, so that the lists serve the operators): SPH_EH if
 * any is bad; the largest into *hmax (0 for none). */
SPH_API int sph__ns_check_h(sph_view h, sph_idx n, int dim, sph_real *hmax)
{
    sph_idx i;
    *hmax = 0;
    for (i = 0; h.p[0] != NULL && i < n; ++i) {
        const sph_real hi = h.p[0][(ptrdiff_t)i * h.stride];
        if (!sph__h_ok(hi, dim)) return SPH_EH;
        *hmax = hi > *hmax ? hi : *hmax;
    }
    return SPH_OK;
}

/* Position of x along axis a relative to the grid origin; wrapped into
 * [0, L] on a periodic axis (eq. (N4)). */
SPH_API sph_real sph__nsearch_rel(const sph_nsearch *g, int a, sph_real x)
{
    sph_real t = x - g->lo[a], L = g->box.length[a];
    if (g->box.periodic[a]) t -= L * sph__floor(t / L);
    return t;
}

/* Cell of relative position t along axis a, clamped into 0..n-1. */
SPH_API int sph__nsearch_cell(const sph_nsearch *g, int a, sph_real t)
{
    sph_real u = sph__floor(t * g->inv_w[a]), top = (sph_real)(g->n[a] - 1);
    return u > 0 ? (int)(u < top ? u : top) : 0;
}

/* Linear cell of a source position (3 slots). */
SPH_API int sph__nsearch_source_cell(const sph_nsearch *g, const sph_real *x)
{
    int k[3] = {0, 0, 0}, a;
    for (a = 0; a < g->dim; ++a) k[a] = sph__nsearch_cell(g, a, sph__nsearch_rel(g, a, x[a]));
    return k[0] + g->n[0] * (k[1] + g->n[1] * k[2]);
}

/* Cells along axis a that meet [t - hw, t + hw]. */
SPH_API void sph__nsearch_span(const sph_nsearch *g, int a, sph_real t, sph_real hw, sph__span *s)
{
    const sph_real n = (sph_real)g->n[a];
    sph_real k0 = sph__floor((t - hw) * g->inv_w[a]), k1 = sph__floor((t + hw) * g->inv_w[a]);
    s->full = 0;
    s->count = 1;
    s->shift[0] = s->shift[1] = 0;
    if (g->box.periodic[a] && !(k1 - k0 + 1 < n)) {
        s->full = 1;
        s->lo[0] = 0;
        s->hi[0] = g->n[a] - 1;
    } else if (g->box.periodic[a]) { /* fewer than n cells: each at most once */
        int i0 = (int)k0, i1 = (int)k1, m = g->n[a];
        s->lo[0] = i0 < 0 ? 0 : i0;
        s->hi[0] = i1 < m ? i1 : m - 1;
        s->shift[0] = i1 < m ? 0 : m;
        if (i0 < 0 || i1 >= m) { /* wrapped: the run [0, ..] first, then [.., m-1] */
            s->count = 2;
            s->lo[0] = 0;
            s->hi[0] = i0 < 0 ? i1 : i1 - m;
            s->lo[1] = i0 < 0 ? i0 + m : i0;
            s->hi[1] = m - 1;
            s->shift[1] = i0 < 0 ? -m : 0;
        }
    } else {
        k0 = k0 > 0 ? (k0 < n ? k0 : n) : 0;
        k1 = k1 < n - 1 ? (k1 > -1 ? k1 : -1) : n - 1;
        s->lo[0] = (int)k0;
        s->hi[0] = (int)k1;
    }
}

/* Distance along axis a from t to cell k (geometric index), 0 inside. */
SPH_API sph_real sph__nsearch_gap(const sph_nsearch *g, int a, sph_real t, int k)
{
    sph_real below = (sph_real)k * g->w[a] - t, above = t - (sph_real)(k + 1) * g->w[a];
    sph_real d = below > above ? below : above;
    return d > 0 ? d : 0;
}

/* sph_box_delta(box, a, dx), skipping its division where its value is known:
 * for |dx| <= L/4 the rounded dx/L + 1/2 lies in [1/4, 3/4], its floor is 0
 * and sph_box_delta returns dx itself, bit for bit. */
SPH_API sph_real sph__nsearch_delta(const sph_nsearch *g, int a, sph_real dx)
{
    return (dx < 0 ? -dx : dx) <= g->quarter[a] ? dx : sph_box_delta(&g->box, a, dx);
}

/* Parameters of one target's search. */
#if SPH__FIRST
typedef struct {
    sph_real xt[3];   /* target position */
    sph_real t[3];    /* relative to the grid (eq. (N4)) */
    sph_real hi;      /* target h */
    sph_real hu;      /* uniform h (sources without per-source h) */
    sph_real kappa;
    sph_real R2;      /* R^2 when the same for every source (gather, or uniform h), else -1 */
    int symmetric;
    int mark;         /* 1: gather, each source i stored as -1 - i where r_ij^2 >= (kappa h_i)^2 (SPH__NS_MARK,
                         a target whose h is above the smallest) */
    sph_idx *seg;     /* fill: the target's part of index[], else NULL */
    sph_off cap;      /* its length */
    sph_off found;    /* neighbours found so far */
    sph_off checked;  /* candidates checked so far */
    sph_off redone;   /* blocks redone by sph__nsearch_in for the minimum image (tests read it) */
    sph_real Rm;      /* pruning radius of the rows (with the rounding allowance) */
    sph_real add;     /* the allowance's additive part */
    int hull;         /* 1: keep of each row only the cells that reach the target (sph__nsearch_keep) */
    int n_runs;       /* runs of sorted sources collected, not yet checked */
    sph_idx runs[2 * SPH__NS_RUNS];
    int image[SPH__NS_RUNS]; /* per run: the sources are seen at x_j + w L, eq. (N7): sph__ns_image */
} sph__probe;
#endif /* SPH__FIRST */

/* Image code of w = -1, 0, 1 periods along axis a: 2 bits per axis, 0 for
 * none, so that a run without any image has code 0. */
SPH_API int sph__ns_image(int w, int a) { return (w > 0 ? 1 : w < 0 ? 2 : 0) << (2 * a); }

/* The image offsets s_a = w_a L_a of eq. (N7) of an image code. */
SPH_API void sph__ns_offsets(const sph_nsearch *g, int code, sph_real *s)
{
    int a;
    for (a = 0; a < 3; ++a) {
        const int c = (code >> (2 * a)) & 3;
        s[a] = c == 0 ? 0 : c == 1 ? g->box.length[a] : -g->box.length[a];
    }
}

/* r_ij^2 of eq. (N3) from target position xt to sorted source k, summed in
 * axis order, every square rounded before it is added (sph__mul_rn: under
 * any contraction): the one distance every decision of the search rests on. */
SPH__INLINE sph_real sph__nsearch_r2(const sph_nsearch *g, const sph_real *xt, sph_idx k, const int dim)
{
    sph_real r2 = 0;
    int a;
    for (a = 0; a < dim; ++a) {
        const sph_real d = sph__nsearch_delta(g, a, xt[a] - g->x[(ptrdiff_t)a * g->n_padded + k]);
        r2 += sph__mul_rn(d, d);
    }
    return r2;
}

/* 1 when sorted source k meets criterion (N1)/(N2) for the target of p:
 * r_ij^2 of eq. (N3), summed in axis order, against R^2 = (kappa h)^2. */
SPH_API int sph__nsearch_in(const sph_nsearch *g, const sph__probe *p, sph_idx k, const int dim)
{
    const sph_real r2 = sph__nsearch_r2(g, p->xt, k, dim), hj = g->h != NULL ? g->h[k] : p->hu;
    const sph_real R = p->kappa * (p->symmetric && hj > p->hi ? hj : p->hi);
    return r2 < R * R;
}

/* 1 when sorted source k lies within its own radius, r^2 < (kappa h_k)^2,
 * r^2 as sph__nsearch_in takes it: the mark of the symmetric lists. */
SPH_API int sph__nsearch_in_own(const sph_nsearch *g, const sph__probe *p, sph_idx k, const int dim)
{
    const sph_real Ri = p->kappa * g->h[k];
    return sph__nsearch_r2(g, p->xt, k, dim) < Ri * Ri;
}

/* 1 when some source b + k of the block (k < SPH__NS_BLOCK, b + k < k1) has
 * |d_a| = |(x_t - x_j) - s_a| beyond image_ok_a on some axis: there the
 * run's image offset need not be the minimum image (eq. (N7)). Asked only
 * of blocks with some r^2 beyond the smallest squared quarter period. */
SPH__NOINLINE int sph__nsearch_far(const sph_nsearch *g, const sph__probe *p, sph_idx b, sph_idx k1, const sph_real *s,
                                 const int dim, const int IMG)
{
    const sph_real *x = g->x + b;
    const ptrdiff_t stride = g->n_padded;
    int k, a;
    for (k = 0; k < SPH__NS_BLOCK && b + k < k1; ++k)
        for (a = 0; a < dim; ++a) {
            const sph_real d = IMG ? (p->xt[a] - x[a * stride + k]) - s[a] : p->xt[a] - x[a * stride + k];
            if ((d < 0 ? -d : d) > g->image_ok[a]) return 1;
        }
    return 0;
}

/* Bit k set when sorted source b + k (k < SPH__NS_BLOCK, b + k < k1) meets
 * the criterion, as sph__nsearch_in decides it. One loop without a branch
 * over a whole block (the padding beyond k1 is masked). The run's image
 * offset s (eq. (N7); IMG: the run has one) gives d_a = (x_t - x_j) - s_a,
 * bit for bit the value sph__nsearch_delta returns whenever |d_a| is at
 * most image_ok_a = 0.49 L_a: then round((x_t - x_j) / L_a) is the run's
 * image w_a (or 0 without one) with a margin far above the rounding, so
 * sph_box_delta subtracts the same w_a L_a. A block with some |d_a| beyond
 * it (a wrong image, or a box not much larger than the radius) is redone
 * by sph__nsearch_in; the loop itself only tests r^2 against the smallest
 * squared quarter period (cheaper in it), and sph__nsearch_far looks at
 * the axes of the blocks that pass it. HV: R per source (symmetric with
 * per-source h); HV 2 also sets mw[k] to -1 where r^2 >= (kappa h_j)^2,
 * else 0 (the mark ~j = j ^ mw[k], stored without a branch); dim, HV, IMG
 * constants once inlined. The loop's r^2 is the compiler's to contract (it
 * may fuse d^2 + r^2 into FMAs): it decides the sources farther than
 * SPH__NS_EDGE from R^2 (relative), and sph__nsearch_in, the rest. */
SPH__INLINE unsigned sph__nsearch_mask(const sph_nsearch *g, sph__probe *p, sph_idx b, sph_idx k1,
                                       const sph_real *s, const int dim, const int HV, const int IMG, sph_idx *mw)
{
    const sph_real *x = g->x + b;
    const ptrdiff_t stride = g->n_padded;
    const sph_real lo = SPH__NS_BAND ? 1 - SPH__NS_EDGE : 1, hi = SPH__NS_BAND ? 1 + SPH__NS_EDGE : 1;
    unsigned mask = 0, edge = 0, edge_own = 0;
    int k, a, wide = 0;
    for (k = 0; k < SPH__NS_BLOCK; ++k) {
        sph_real r2 = 0, R2 = p->R2;
        const unsigned live = b + k < k1;
        for (a = 0; a < dim; ++a) {
            const sph_real d = IMG ? (p->xt[a] - x[a * stride + k]) - s[a] : p->xt[a] - x[a * stride + k];
            r2 += d * d;
        }
        wide |= (r2 > g->quarter2) & live;
        if (HV == 1) {
            const sph_real hj = g->h[b + k], R = p->kappa * (hj > p->hi ? hj : p->hi);
            R2 = R * R;
        }
        if (HV == 2) {
            const sph_real Ri = p->kappa * g->h[b + k], Ri2 = Ri * Ri;
            const unsigned own = r2 < Ri2 * lo;
            mw[k] = -(sph_idx)!own;
            if (SPH__NS_BAND) edge_own |= ((r2 < Ri2 * hi) & !own & live) << k;
        }
        {
            const unsigned in = r2 < R2 * lo;
            mask |= (in & live) << k;
            if (SPH__NS_BAND) edge |= ((r2 < R2 * hi) & !in & live) << k;
        }
    }
    if (wide) wide = sph__nsearch_far(g, p, b, k1, s, dim, IMG);
    if (!wide) { /* near R: the criterion's own r^2 decides (a wide block is redone whole below) */
        for (k = 0; edge != 0; ++k, edge >>= 1)
            if (edge & 1u) mask |= (unsigned)sph__nsearch_in(g, p, b + k, dim) << k;
        for (k = 0; edge_own != 0; ++k, edge_own >>= 1)
            if (edge_own & 1u) mw[k] = -(sph_idx)!sph__nsearch_in_own(g, p, b + k, dim);
    }
    if (wide) {
        ++p->redone;
        for (mask = 0, k = 0; k < SPH__NS_BLOCK && b + k < k1; ++k) {
            mask |= (unsigned)sph__nsearch_in(g, p, b + k, dim) << k;
            if (HV == 2) mw[k] = -(sph_idx)!sph__nsearch_in_own(g, p, b + k, dim);
        }
    }
    return mask;
}

#if SPH__NS_VEC
/* sph__nsearch_mask in vector registers: r^2 of the 16 sources of a block,
 * as vectors of SPH__NSW doubles. With double, d_a is the scalar value bit
 * for bit. With float, positions are widened exactly, and d_a = x_t - x_j is
 * exact, within half a float ulp of the scalar d_a; where an image offset
 * is subtracted, x_t - x_j is first rounded to float as the scalar one is
 * (unrounded, its error of half an ulp of the period would be many ulp of
 * d_a). The sum of squares may round otherwise than the scalar r^2
 * (contraction into fused multiply-adds is the compiler's choice; with
 * SPH_REAL float the scalar sum is rounded to float), so r^2 differs from
 * the scalar one by at most a few ulp of sph_real; a source within 16 ulp
 * of R^2 is therefore decided by sph__nsearch_in, and a block with some
 * |d_a| beyond image_ok_a is redone by the scalar mask, so the lists stay
 * those of the scalar criterion bit for bit. */
SPH__INLINE unsigned sph__nsearch_mask16(const sph_nsearch *g, sph__probe *p, sph_idx b, sph_idx k1,
                                         const sph_real *s, const int dim, const int HV, const int IMG, unsigned *mk)
{
    const double eps = (double)SPH__NS_EDGE;
    const ptrdiff_t stride = g->n_padded;
    const unsigned live = k1 - b >= 16 ? 0xFFFFu : (1u << (k1 - b)) - 1u, all = (1u << SPH__NSW) - 1u;
    unsigned in = 0, near_edge = 0, wide = 0, mask, own = 0, near_own = 0;
    int a, k, c;
    for (c = 0; c < 16; c += SPH__NSW) { /* the lanes c .. c + SPH__NSW - 1 of the block */
        const sph_real *x = g->x + b + c;
        const unsigned lv = (live >> c) & all;
        sph__nsv r2 = SPH__NSV(setzero)(), R2 = SPH__NSV(set1)((double)p->R2);
        unsigned inc;
        if (lv == 0) break; /* a short run: no live lane from here on */
        for (a = 0; a < dim; ++a) {
            sph__nsv d = SPH__NSV(sub)(SPH__NSV(set1)((double)p->xt[a]), sph__nsv_load(x + a * stride));
            if (IMG && sizeof(sph_real) == sizeof(float) && s[a] != 0) d = sph__nsv_round(d);
            if (IMG) d = SPH__NSV(sub)(d, SPH__NSV(set1)((double)s[a]));
            r2 = SPH__NSV(fmadd)(d, d, r2);
            wide |= sph__nsv_gt(sph__nsv_abs(d), SPH__NSV(set1)((double)g->image_ok[a]), lv);
        }
        if (HV == 2) { /* the source's own radius: r^2 < (kappa h_i)^2, decided as below; in double h_i from hf,
                          (kappa h_i)^2 then within 2^-22 of the double's: a band of 2^-20, a NaN in it */
            const int hf = sizeof(sph_real) == sizeof(double);
            const double band = hf ? 1.0 / 1048576 : eps;
            const sph__nsv Ri = SPH__NSV(mul)(SPH__NSV(set1)((double)p->kappa),
                                              hf ? sph__nsv_loadf(g->hf + b + c) : sph__nsv_load(g->h + b + c));
            const sph__nsv Ri2 = SPH__NSV(mul)(Ri, Ri);
            const unsigned ownc = sph__nsv_lt(r2, SPH__NSV(mul)(Ri2, SPH__NSV(set1)(1 - band)), lv);
            own |= ownc << c;
            near_own |= (sph__nsv_nge(r2, SPH__NSV(mul)(Ri2, SPH__NSV(set1)(1 + band)), lv) & ~ownc) << c;
        }
        if (HV == 1) {
            const sph__nsv R = SPH__NSV(mul)(SPH__NSV(set1)((double)p->kappa),
                                             sph__nsv_max(sph__nsv_load(g->h + b + c), SPH__NSV(set1)((double)p->hi)));
            R2 = SPH__NSV(mul)(R, R);
        }
        inc = sph__nsv_lt(r2, SPH__NSV(mul)(R2, SPH__NSV(set1)(1 - eps)), lv);
        in |= inc << c;
        near_edge |= (sph__nsv_lt(r2, SPH__NSV(mul)(R2, SPH__NSV(set1)(1 + eps)), lv) & ~inc) << c;
    }
    if (wide) {
        sph_idx mw[SPH__NS_BLOCK];
        mask = sph__nsearch_mask(g, p, b, k1, s, dim, HV, IMG, mw);
        if (HV == 2)
            for (*mk = 0, k = 0; k < SPH__NS_BLOCK; ++k) *mk |= (unsigned)(mw[k] & 1) << k & mask;
        return mask;
    }
    mask = in;
    for (k = 0; near_edge != 0; ++k, near_edge >>= 1)
        if (near_edge & 1u) mask |= (unsigned)sph__nsearch_in(g, p, b + k, dim) << k;
    if (HV == 2) {
        for (k = 0; near_own != 0; ++k, near_own >>= 1)
            if (near_own & 1u) own |= (unsigned)sph__nsearch_in_own(g, p, b + k, dim) << k;
        *mk = mask & ~own;
    }
    return mask;
}

#if SPH__ISA == 1
/* Per 4-bit mask, the lanes of its set bits in order, 2 bits each (lowest
 * first): the AVX2 compress of 4 indices, one permute. */
SPH__TABLE unsigned char sph__ns_pack4[16] = {0x00, 0x00, 0x01, 0x04, 0x02, 0x08, 0x09, 0x24,
                                              0x03, 0x0C, 0x0D, 0x34, 0x0E, 0x38, 0x39, 0xE4};
#endif

/* Stores the sources of block b that mask accepts at seg + m, those of mk
 * marked (~j): compressed into registers and stored whole (full: the
 * segment has room for SPH__NS_BLOCK), else just the accepted ones (an
 * exact segment, as fill gives each target, with room for them). */
SPH__INLINE void sph__nsearch_store(const sph_idx *order, unsigned mask, unsigned mk, sph_idx *seg, int full)
{
#if SPH__ISA == 2
    const __m512i o = _mm512_loadu_si512((const void *)order);
    const __m512i j = _mm512_maskz_compress_epi32((__mmask16)mask, _mm512_mask_xor_epi32(o, (__mmask16)mk, o, _mm512_set1_epi32(-1)));
    if (full)
        _mm512_storeu_si512((void *)seg, j);
    else
        _mm512_mask_storeu_epi32((void *)seg, (__mmask16)((1u << __builtin_popcount(mask)) - 1u), j);
#else
    const __m128i bit = _mm_setr_epi32(1, 2, 4, 8), shift = _mm_setr_epi32(0, 2, 4, 6);
    int c;
    for (c = 0; c < 16; c += 4) { /* 4 lanes at a time: the table's permute of the accepted to the front */
        const unsigned mc = (mask >> c) & 15u, kc = (mk >> c) & 15u;
        const __m128i o = _mm_loadu_si128((const __m128i *)(const void *)(order + c));
        const __m128i mark = _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32((int)kc), bit), bit);
        const __m128i perm = _mm_srlv_epi32(_mm_set1_epi32(sph__ns_pack4[mc]), shift);
        const __m128i j = _mm_castps_si128(_mm_permutevar_ps(_mm_castsi128_ps(_mm_xor_si128(o, mark)), perm));
        const int got = __builtin_popcount(mc);
        if (full)
            _mm_storeu_si128((__m128i *)(void *)seg, j);
        else
            _mm_maskstore_epi32((int *)(void *)seg, _mm_cmpgt_epi32(_mm_set1_epi32(got), _mm_setr_epi32(0, 1, 2, 3)), j);
        seg += got;
    }
#endif
}
#endif

/* Set bits of m. */
SPH_API int sph__ns_popcount(unsigned m)
{
#if defined(__GNUC__) && !defined(__CUDA_ARCH__) /* the builtin is host code under nvcc */
    return __builtin_popcount(m);
#else
    int k = 0;
    for (; m != 0; m &= m - 1) ++k;
    return k;
#endif
}

/* Lowest set bit of m != 0. */
SPH_API int sph__ns_ctz(unsigned m)
{
#if defined(__GNUC__) && !defined(__CUDA_ARCH__) /* the builtin is host code under nvcc */
    return __builtin_ctz(m);
#else
    int k = 0;
    if (!(m & 0xFFFFu)) k += 16, m >>= 16;
    if (!(m & 0xFFu)) k += 8, m >>= 8;
    if (!(m & 0xFu)) k += 4, m >>= 4;
    if (!(m & 3u)) k += 2, m >>= 2;
    return k + !(m & 1u);
#endif
}

/* Counts (p->seg NULL) or appends to the target's segment (never past its
 * end) the sorted sources k0..k1-1 that meet the criterion; returns the new
 * count. A block with room for all its sources in the segment stores them
 * all and keeps those inside, without a branch; at a vector level a block
 * whose accepted sources fit (the last of an exact segment) stores just those. */
SPH__INLINE sph_off sph__nsearch_run_blocks(const sph_nsearch *g, sph__probe *p, sph_idx k0, sph_idx k1,
                                            const sph_real *s, sph_off m, const int dim, const int HV,
                                            const int IMG)
{
    sph_idx b;
    int k;
    for (b = k0; b < k1; b += SPH__NS_BLOCK) {
#if SPH__NS_VEC
        unsigned mk = 0; /* HV 2: the accepted sources to store marked */
        const unsigned mask = sph__nsearch_mask16(g, p, b, k1, s, dim, HV, IMG, &mk);
#define SPH__NS_MARKED(k) (-(sph_idx)((mk >> (k)) & 1u))
        /* the accepted indices compressed into registers, stored whole where
           the segment has room for 16, else as many as were accepted */
        const int got = __builtin_popcount(mask);
        if (p->seg == NULL) {
            m += got;
            continue;
        }
        if (m + got <= p->cap) {
            sph__nsearch_store(g->order + b, mask, HV == 2 ? mk : 0, p->seg + m, m + SPH__NS_BLOCK <= p->cap);
            m += got;
            continue;
        }
#else
        sph_idx mw[SPH__NS_BLOCK]; /* HV 2: -1 where the source is stored marked (~j = j ^ -1), else 0 */
        const unsigned mask = sph__nsearch_mask(g, p, b, k1, s, dim, HV, IMG, mw);
#define SPH__NS_MARKED(k) (HV == 2 ? mw[k] : 0)
        if (p->seg == NULL) {
            for (k = 0; k < SPH__NS_BLOCK; ++k) m += (mask >> k) & 1u;
            continue;
        }
        if (m + SPH__NS_BLOCK <= p->cap) {
            for (k = 0; k < SPH__NS_BLOCK; ++k) {
                p->seg[m] = g->order[b + k] ^ SPH__NS_MARKED(k);
                m += (mask >> k) & 1u;
            }
            continue;
        }
#endif
        for (k = 0; k < SPH__NS_BLOCK; ++k) /* past the segment's end: count, store what fits */
            if ((mask >> k) & 1u) {
                if (m < p->cap) p->seg[m] = g->order[b + k] ^ SPH__NS_MARKED(k);
                ++m;
            }
    }
#undef SPH__NS_MARKED
    return m;
}

/* Checks the collected runs of sorted sources: counts them or appends them.
 * The count stays in a register across the runs; dim and HV are constants,
 * and runs without an image offset (most) skip its subtraction. */
SPH__INLINE void sph__nsearch_runs(const sph_nsearch *g, sph__probe *p, const int dim, const int HV)
{
    sph_off m = p->found, checked = 0;
    sph_real s[3] = {0, 0, 0};
    int r;
    for (r = 0; r < p->n_runs; ++r) {
        const sph_idx k0 = p->runs[2 * r], k1 = p->runs[2 * r + 1];
        if (p->image[r] == 0)
            m = sph__nsearch_run_blocks(g, p, k0, k1, s, m, dim, HV, 0);
        else {
            sph__ns_offsets(g, p->image[r], s);
            m = sph__nsearch_run_blocks(g, p, k0, k1, s, m, dim, HV, 1);
        }
        checked += k1 - k0;
    }
    p->found = m;
    p->checked += checked;
    p->n_runs = 0;
}

/* Checks the collected runs. */
SPH_API void sph__nsearch_flush(const sph_nsearch *g, sph__probe *p)
{
    const int hv = p->R2 < 0 ? 1 : p->mark && p->seg != NULL ? 2 : 0;
    if (hv == 2)
        g->dim == 3 ? sph__nsearch_runs(g, p, 3, 2) : g->dim == 2 ? sph__nsearch_runs(g, p, 2, 2) : sph__nsearch_runs(g, p, 1, 2);
    else if (g->dim == 3)
        hv ? sph__nsearch_runs(g, p, 3, 1) : sph__nsearch_runs(g, p, 3, 0);
    else if (g->dim == 2)
        hv ? sph__nsearch_runs(g, p, 2, 1) : sph__nsearch_runs(g, p, 2, 0);
    else
        hv ? sph__nsearch_runs(g, p, 1, 1) : sph__nsearch_runs(g, p, 1, 0);
}

/* nr runs collected in p->runs: checks them when fewer than room slots are
 * left for the next row; returns the runs still waiting. */
SPH_API int sph__nsearch_room(const sph_nsearch *g, sph__probe *p, int nr, int room)
{
    if (nr + room <= SPH__NS_RUNS) return nr;
    p->n_runs = nr;
    sph__nsearch_flush(g, p);
    return 0;
}

/* Run r of the probe: sorted sources k0..k1-1, seen at the image of code
 * img (sph__ns_image). */
SPH__INLINE void sph__nsearch_put(sph__probe *p, int r, sph_idx k0, sph_idx k1, int img)
{
    p->runs[2 * r] = k0;
    p->runs[2 * r + 1] = k1;
    p->image[r] = img;
}

/* Image code along axis a of the cells of run r of span s: w = shift / n,
 * the periods the cells' geometric position lies from their own (0 on a
 * full axis: every source is then taken at its own position and its block
 * left to the minimum image of sph__nsearch_in). */
SPH_API int sph__nsearch_image(int a, const sph__span *s, int r) { return sph__ns_image(s->shift[r], a); }

/* Squared distance along axis a from t to the k-th cell of run r of span s. */
SPH_API sph_real sph__nsearch_gap2(const sph_nsearch *g, int a, sph_real t, const sph__span *s, int r, int k)
{
    sph_real d = s->full ? 0 : sph__nsearch_gap(g, a, t, k + s->shift[r]);
    return d * d;
}

/* 1 when a cell whose sources have h at most hc, at squared distance gap2
 * from the target, may hold a neighbour under (N2): gap2 within the
 * pruning radius of R = kappa max(h_i, hc) (docs/neighbours.md, "Rounding
 * allowance"), never beyond the rows' radius. */
SPH__INLINE int sph__nsearch_keep(const sph__probe *p, sph_real hc, sph_real gap2)
{
    const sph_real R = p->kappa * (hc > p->hi ? hc : p->hi);
    sph_real Rm = R + R / 1024 + p->add;
    Rm = Rm < p->Rm ? Rm : p->Rm;
    return gap2 <= Rm * Rm;
}

/* One row of cells along axis 0 (cells ky, kz of axes 1, 2, image code
 * img of theirs), radius^2 rem left: its runs of sorted sources (one, or two
 * where a periodic axis wraps) into the probe from run nr on; returns how
 * many. */
SPH__INLINE int sph__nsearch_row(const sph_nsearch *g, sph__probe *p, int nr, int ky, int kz, int img,
                                 sph_real rem, sph_real yz2)
{
    sph__span s;
    const int row = g->n[0] * (ky + g->n[1] * kz);
    const sph_idx *cs = g->cell_start + row;
    const sph_real hw = sph__sqrt(rem), k0 = sph__floor((p->t[0] - hw) * g->inv_w[0]),
                   k1 = sph__floor((p->t[0] + hw) * g->inv_w[0]);
    int r, n = 0;
    if (!p->hull && k0 >= 0 && k1 < (sph_real)g->n[0]) { /* inside the grid: one run, as sph__nsearch_span finds */
        sph__nsearch_put(p, nr, cs[(int)k0], cs[(int)k1 + 1], img);
        return 1;
    }
    sph__nsearch_span(g, 0, p->t[0], hw, &s);
    for (r = 0; r < s.count; ++r) {
        int lo = s.lo[r], hi = s.hi[r];
        while (p->hull && lo <= hi && !sph__nsearch_keep(p, g->hcell[row + lo], sph__nsearch_gap2(g, 0, p->t[0], &s, r, lo) + yz2))
            ++lo;
        while (p->hull && lo <= hi && !sph__nsearch_keep(p, g->hcell[row + hi], sph__nsearch_gap2(g, 0, p->t[0], &s, r, hi) + yz2))
            --hi;
        if (lo <= hi) sph__nsearch_put(p, nr + n++, cs[lo], cs[hi + 1], img | sph__nsearch_image(0, &s, r));
    }
    return n;
}

/* A list entry with its mark -1 - s undone to s. */
SPH__INLINE sph_idx sph__ns_unmark(sph_idx v) { return v < 0 ? -1 - v : v; }

#if SPH__NS_COMPRESS
/* The first `left` lanes of 16 (none for left <= 0, all from 16 on). */
SPH__INLINE __mmask16 sph__ns_live16(sph_off left)
{
    return (__mmask16)(left >= 16 ? 0xFFFFu : left > 0 ? (1u << left) - 1u : 0u);
}

/* 16 indices with their marks -1 - s undone to s. */
SPH__INLINE __m512i sph__ns_unmark16(__m512i v)
{
    return _mm512_xor_si512(v, _mm512_maskz_srai_epi32((__mmask16)0xFFFF, v, 31));
}

/* Sorts n <= 16 NCH distinct indices ascending (NCH a constant: the list
 * stays in registers; MK 1: by source, a mark -1 - i as i): each entry
 * goes to its rank, the number of entries below it, counted for 16 entries
 * at a time against every entry in turn, without a branch on the data. */
SPH__INLINE void sph__ns_rank_sort(sph_idx *v, sph_off n, const int MK, const int NCH)
{
    __m512i val[8], key[8], rank[8];
    sph_off k;
    int t;
    for (t = 0; t < NCH; ++t) {
        val[t] = _mm512_maskz_loadu_epi32(sph__ns_live16(n - 16 * t), (const void *)(v + 16 * t));
        key[t] = MK ? sph__ns_unmark16(val[t]) : val[t];
        rank[t] = _mm512_setzero_si512();
    }
    for (k = 0; k < n; ++k) {
        const __m512i u = _mm512_set1_epi32(MK ? sph__ns_unmark(v[k]) : v[k]);
        for (t = 0; t < NCH; ++t)
            rank[t] = _mm512_mask_sub_epi32(rank[t], _mm512_cmplt_epi32_mask(u, key[t]), rank[t], _mm512_set1_epi32(-1));
    }
    for (t = 0; t < NCH; ++t) _mm512_mask_i32scatter_epi32((void *)v, sph__ns_live16(n - 16 * t), rank[t], val[t], 4);
}
#endif

/* Sorts n distinct indices ascending: nothing to do for a sorted run (the
 * usual case on cell-sorted particles); with AVX-512 up to 128 by rank
 * (sph__ns_rank_sort); else Shell sort with gaps g' = floor(2.25 g) + 1
 * (Tokuda 1992). */
SPH__INLINE void sph__ns_sort_as(sph_idx *v, sph_off n, const int MK)
{
#define SPH__NS_KEY(x) (MK && (x) < 0 ? -1 - (x) : (x))
    sph_off gaps[64], i, j, gap = 1;
    int ng = 0, unsorted = 0;
    for (i = 1; i < n; ++i) unsorted |= SPH__NS_KEY(v[i - 1]) >= SPH__NS_KEY(v[i]); /* no early exit: a vector loop */
    if (!unsorted) return;
#if SPH__NS_COMPRESS
    if (n <= 128) {
        n <= 32 ? sph__ns_rank_sort(v, n, MK, 2) : n <= 64 ? sph__ns_rank_sort(v, n, MK, 4) : sph__ns_rank_sort(v, n, MK, 8);
        return;
    }
#endif
    while (gap < n && ng < 64) {
        gaps[ng++] = gap;
        gap = (sph_off)(2.25 * (double)gap) + 1;
    }
    while (ng-- > 0) {
        gap = gaps[ng];
        for (i = gap; i < n; ++i) {
            const sph_idx x = v[i], kx = SPH__NS_KEY(x);
            for (j = i; j >= gap && SPH__NS_KEY(v[j - gap]) > kx; j -= gap) v[j] = v[j - gap];
            v[j] = x;
        }
    }
#undef SPH__NS_KEY
}

/* Sorts a target's list ascending (MK 1: by source, a mark -1 - i as i). */
SPH_API void sph__ns_sort(sph_idx *v, sph_off n, int MK)
{
    MK ? sph__ns_sort_as(v, n, 1) : sph__ns_sort_as(v, n, 0);
}


/* Cells a target reaches on each side along one axis, at most, for the
 * interior path of sph__nsearch_target (cells of R/2: 3; the varying-h
 * cells of the clump of bench/bench_search_h.c: up to 10). */
#define SPH__NS_REACH 16

/* The i-th of the 2 E + 1 offsets of an axis in ascending cell order: from
 * first (the offset of cell 0 where the axis wraps, else 0) round to first - 1. */
SPH_API int sph__ns_turn(int i, int first, int E) { return i + first - (i + first > 2 * E ? 2 * E + 1 : 0); }

/* The rows of a target whose reach spans E[a] cells either side of its
 * cell kc[a] (at most SPH__NS_REACH; a periodic axis needs at least
 * 2 E[a] + 1 cells, so that each comes once): for the geometric cells
 * kc + d, the squared gaps, their cells in the grid and their image offsets
 * (eq. (N7)) are computed once per axis; a cell beyond the grid on an axis
 * without a period gets an infinite gap. A row's x run is the cells whose
 * gap^2 fits in what is left of Rm^2, counted without a square root, a
 * floor or a branch (the gaps grow away from kc, so the count is a run).
 * The cells are those of the general path but for rounding in the last
 * place, which the allowance in Rm covers; every candidate is then checked
 * exactly. Rows come in ascending cell order (a wrapped axis starts at its
 * cell 0), so the lists of cell-sorted particles need no sort. EDGE (a
 * constant): some cell kc + d lies beyond the grid; without, the cells are
 * kc + d themselves (the usual case, kept free of the work of edges). */
SPH__INLINE void sph__nsearch_interior(const sph_nsearch *g, sph__probe *p, sph_real Rm, const int *kc, const int *E,
                                       const int EDGE, const int HULL)
{
    sph_real G[3][2 * SPH__NS_REACH + 1];
    int K[3][2 * SPH__NS_REACH + 1], C[3][2 * SPH__NS_REACH + 1], first[3] = {0, 0, 0}, a, i, d, iy, iz, nr = 0;
    for (a = 0; a < 3; ++a)
        for (i = 0; i <= 2 * E[a]; ++i) {
            const int k = kc[a] - E[a] + i, per = EDGE && g->box.periodic[a];
            const int w = per ? (k < 0 ? -1 : k >= g->n[a]) : 0, in = !EDGE || per || (k >= 0 && k < g->n[a]);
            const sph_real gap = sph__nsearch_gap(g, a, p->t[a], k);
            G[a][i] = in ? gap * gap : SPH__REAL_MAX;
            K[a][i] = in ? k - w * g->n[a] : 0;
            C[a][i] = sph__ns_image(w, a);
            if (EDGE) first[a] = in && K[a][i] == 0 ? i : first[a];
        }
    for (iz = 0; iz <= 2 * E[2]; ++iz) {
        const int dz = sph__ns_turn(iz, first[2], E[2]);
        const sph_real left_z = Rm * Rm - G[2][dz];
        if (left_z < 0) continue;
        for (iy = 0; iy <= 2 * E[1]; ++iy) {
            const int dy = sph__ns_turn(iy, first[1], E[1]);
            const sph_real left_y = left_z - G[1][dy];
            const sph_idx *cs = g->cell_start + g->n[0] * (K[1][dy] + g->n[1] * K[2][dz]);
            const int n0 = g->n[0];
            int k0 = kc[0], k1 = kc[0];
            if (left_y < 0) continue;
            for (d = 1; d <= E[0]; ++d) {
                k0 -= G[0][E[0] - d] <= left_y;
                k1 += G[0][E[0] + d] <= left_y;
            }
            if (HULL) { /* of those, the cells that reach the target (sph__nsearch_keep), first to last */
                const sph_real *hc = g->hcell + n0 * (K[1][dy] + g->n[1] * K[2][dz]), yz = G[1][dy] + G[2][dz];
                const int o = E[0] - kc[0];
                int lo = k1 + 1, hi = k0 - 1, k;
                for (k = k0; k <= k1; ++k) { /* no branch: the row's cells are few */
                    const int keep = sph__nsearch_keep(p, hc[K[0][k + o]], G[0][k + o] + yz);
                    lo = keep && k < lo ? k : lo;
                    hi = keep ? k : hi;
                }
                k0 = lo;
                k1 = hi;
                if (k0 > k1) continue;
            }
            if (!EDGE || (k0 >= 0 && k1 < n0))
                sph__nsearch_put(p, nr++, cs[k0], cs[k1 + 1], C[1][dy] | C[2][dz]);
            else if (HULL && (k1 < 0 || k0 >= n0)) { /* every kept cell beyond one face: one run at its image */
                const int w = k1 < 0 ? -1 : 1;
                sph__nsearch_put(p, nr++, cs[k0 - w * n0], cs[k1 - w * n0 + 1], sph__ns_image(w, 0) | C[1][dy] | C[2][dz]);
            } else { /* x wraps: the run from cell 0 first, then the one up to cell n0 - 1 */
                sph__nsearch_put(p, nr++, cs[0], cs[(k1 < n0 ? k1 : k1 - n0) + 1],
                                 sph__ns_image(k1 >= n0, 0) | C[1][dy] | C[2][dz]);
                sph__nsearch_put(p, nr++, cs[k0 < 0 ? k0 + n0 : k0], cs[n0],
                                 sph__ns_image(-(k0 < 0), 0) | C[1][dy] | C[2][dz]);
            }
            nr = sph__nsearch_room(g, p, nr, 2);
        }
    }
    p->n_runs = nr;
}

/* The rows of any target, search radius Rm: the cells along z, then y,
 * within reach, clamped to the grid or wrapped round a periodic axis. */
SPH_API void sph__nsearch_general(const sph_nsearch *g, sph__probe *p, sph_real Rm)
{
    sph__span sz, sy;
    int rz, ry, kz, ky, nr = 0;
    sph__nsearch_span(g, 2, p->t[2], Rm, &sz);
    for (rz = 0; rz < sz.count; ++rz)
        for (kz = sz.lo[rz]; kz <= sz.hi[rz]; ++kz) {
            const sph_real gz = sph__nsearch_gap2(g, 2, p->t[2], &sz, rz, kz), left_z = Rm * Rm - gz;
            if (left_z < 0) continue;
            sph__nsearch_span(g, 1, p->t[1], sph__sqrt(left_z), &sy);
            for (ry = 0; ry < sy.count; ++ry)
                for (ky = sy.lo[ry]; ky <= sy.hi[ry]; ++ky) {
                    const sph_real gy = sph__nsearch_gap2(g, 1, p->t[1], &sy, ry, ky), left_y = left_z - gy;
                    if (left_y < 0) continue;
                    nr += sph__nsearch_row(g, p, nr, ky, kz,
                                           sph__nsearch_image(1, &sy, ry) | sph__nsearch_image(2, &sz, rz), left_y,
                                           gz + gy);
                    nr = sph__nsearch_room(g, p, nr, 2);
                }
        }
    p->n_runs = nr;
}

/* A bound on h_j of every source j that may reach a target in cell kc
 * under (N2) by its own radius (docs/neighbours.md, "Varying h"): hreach of
 * the target's cell (each cell's h pushed over the cells its reach covers,
 * sph__nsearch_hbuild) or h_far, for any kappa up to the one the table was
 * built for and a target within the grid's rounding allowance (add, of
 * sph__nsearch_target); else h_max. */
SPH_API sph_real sph__nsearch_reach(const sph_nsearch *g, const int *kc, sph_real kappa, sph_real add)
{
    const ptrdiff_t c = kc[0] + (ptrdiff_t)g->n[0] * (kc[1] + (ptrdiff_t)g->n[1] * kc[2]);
    const sph_real hr = g->hreach[c] > g->h_far ? g->hreach[c] : g->h_far;
    return kappa <= g->kappa_b && add <= 2 * g->slack ? hr : g->h_max;
}

/* Searches one target (found, checked, and seg when filling): the cells
 * whose nearest point lies within the search radius, layer by layer (z, y),
 * each x row as one or two runs of sorted sources; the interior path where
 * the target's reach is at most SPH__NS_REACH cells on every axis and each
 * periodic axis has room for it, else the general path. */
SPH_API void sph__nsearch_target(const sph_nsearch *g, sph__probe *p)
{
    sph_real hmax = g->h != NULL ? g->h_max : p->hu;
    sph_real Rs, Rm, far = 0;
    int a, kc[3] = {0, 0, 0}, E[3] = {0, 0, 0}, inside = 1, edge = 0;
    for (a = 0; a < 3; ++a) {
        const sph_real ax = p->xt[a] < 0 ? -p->xt[a] : p->xt[a]; /* |x| in sph_real: no promotion to double */
        p->t[a] = a < g->dim ? sph__nsearch_rel(g, a, p->xt[a]) : (sph_real)0.5;
        if (a < g->dim) kc[a] = sph__nsearch_cell(g, a, p->t[a]);
        far = ax > far ? ax : far;
    }
    p->hull = 0;
    p->add = g->slack + 64 * sph__nsearch_eps() * far;
    if (p->symmetric && g->hcell != NULL) { /* reach of the sources that may reach the target (hreach) */
        const sph_real hr = sph__nsearch_reach(g, kc, p->kappa, p->add);
        p->hull = hr > p->hi;
        Rs = p->kappa * (p->hull ? hr : p->hi);
    } else
        Rs = p->kappa * (p->symmetric && hmax > p->hi ? hmax : p->hi);
    /* search radius with the rounding allowance of docs/neighbours.md: never misses a pair */
    Rm = Rs + Rs / 1024 + p->add;
    p->Rm = Rm;
    if (p->symmetric && g->h != NULL && (p->hull || g->hcell == NULL))
        p->R2 = -1;
    else if (p->symmetric && g->h != NULL) { /* no source of larger h reaches: (N2) decides as (N1), bit for bit */
        const sph_real R = p->kappa * p->hi;
        p->R2 = R * R;
    } else { /* R of sph__nsearch_in with h_j = the uniform h */
        const sph_real R = p->kappa * (p->symmetric && p->hu > p->hi ? p->hu : p->hi);
        p->R2 = R * R;
    }
    p->found = 0;
    p->checked = 0;
    p->redone = 0;
    p->n_runs = 0;
    for (a = 0; a < g->dim; ++a) { /* axes beyond dim: one cell, reach 0 */
        const sph_real reach = sph__floor(Rm * g->inv_w[a]) + 1;
        E[a] = reach <= SPH__NS_REACH ? (int)reach : -1;
        inside &= E[a] >= 0 && (!g->box.periodic[a] || 2 * E[a] + 1 <= g->n[a]);
        edge |= kc[a] - E[a] < 0 || kc[a] + E[a] >= g->n[a];
    }
    inside &= Rm * Rm <= SPH__REAL_MAX; /* the infinite gap of the interior path stays out of reach */
    if (inside && p->hull)
        edge ? sph__nsearch_interior(g, p, Rm, kc, E, 1, 1) : sph__nsearch_interior(g, p, Rm, kc, E, 0, 1);
    else if (inside && edge)
        sph__nsearch_interior(g, p, Rm, kc, E, 1, 0);
    else if (inside)
        sph__nsearch_interior(g, p, Rm, kc, E, 0, 0);
    else
        sph__nsearch_general(g, p, Rm);
    sph__nsearch_flush(g, p);
    if (p->seg != NULL && p->found <= p->cap) sph__ns_sort(p->seg, p->found, p->mark);
}

/* Cells per axis and their widths for a cell edge (eq. (N4)), from the
 * origin lo and span L of each axis (the period, or the sources' extent;
 * amax: the largest |x_a| of the sources); SPH_EGRID beyond
 * SPH_NSEARCH_MAX_CELLS. */
SPH_API int sph__nsearch_axes(sph_nsearch *g, int dim, const sph_real *L, const sph_real *amax, sph_real cell)
{
    double total = 1, extent = 0;
    int a;
    if (!(cell > 0 && 1 / cell <= SPH__REAL_MAX)) return SPH_EGRID; /* a denormal cell: cell widths of 1/0 */
    g->w_min = SPH__REAL_MAX;
    for (a = 0; a < 3; ++a) {
        const int per = g->box.periodic[a];
        double na = a < dim ? floor((double)L[a] / (double)cell) : 1;
        if (!(na <= (double)SPH_NSEARCH_MAX_CELLS)) return SPH_EGRID;
        na = na < 1 ? 1 : na;
        total *= na;
        g->n[a] = (int)na;
        g->w[a] = a >= dim ? 1 : per ? L[a] / (sph_real)na : (na > 1 ? L[a] / (sph_real)na : (L[a] > cell ? L[a] : cell));
        g->inv_w[a] = 1 / g->w[a];
        if (a < dim && g->w[a] < g->w_min) g->w_min = g->w[a];
        if (a < dim && fabs((double)g->lo[a]) + (double)L[a] + (double)g->w[a] > extent)
            extent = fabs((double)g->lo[a]) + (double)L[a] + (double)g->w[a];
        if (a < dim && (double)amax[a] > extent) extent = (double)amax[a]; /* sources outside a periodic box */
    }
    if (total > (double)SPH_NSEARCH_MAX_CELLS) return SPH_EGRID;
    g->n_cells = (int)total;
    g->slack = (sph_real)(64 * (double)sph__nsearch_eps() * extent);
    return SPH_OK;
}

/* Modelled cost of a target of radius x cell widths (docs/neighbours.md,
 * "Varying h"): rows of cells, weighted by the cost of a row against a
 * neighbour check (4 checks a row, ~60, 20, 5 neighbours in 3-, 2-, 1-D),
 * plus candidate checks per neighbour, (1 + 0.7 / x)^dim (2.41 at cells
 * of R/2 in 3-D; 2.45 measured). */
SPH_API double sph__nsearch_model(int dim, double x)
{
    const double rows = dim == 3 ? 3.14159265358979 * (x + 0.5) * (x + 0.5) : dim == 2 ? 2 * x + 1 : 1;
    const double c = 1 + 0.7 / x;
    return rows * (dim == 3 ? 4.0 / 60 : dim == 2 ? 4.0 / 20 : 4.0 / 5) + (dim == 3 ? c * c * c : dim == 2 ? c * c : c);
}

/* Quarter octaves j (h_ref = h_max 2^(-j/4)) below the largest source h at
 * which cells of (cell edge for h_max) * h_ref / h_max cost the least by
 * sph__nsearch_model, summed over a histogram of the sources' h in quarter
 * octaves (at most 32768 of them sampled, evenly); only j holding some
 * source are candidates, so equal h keep the given cell (j = 0). */
SPH_API int sph__nsearch_pick(sph_view hs, sph_idx ns, int dim, sph_real h_max)
{
    enum { BINS = 64 };
    double count[BINS], best = -1;
    const sph_idx step = ns / 32768 + 1;
    sph_idx i;
    int b, j, pick = 0;
    for (b = 0; b < BINS; ++b) count[b] = 0;
    for (i = 0; i < ns; i += step) {
        const double r = (double)(hs.p[0][(ptrdiff_t)i * hs.stride] / h_max), q = -4 * log2(r);
        count[q < BINS - 1 ? (int)q : BINS - 1] += 1;
    }
    for (j = 0; j < BINS; ++j) {
        double cost = 0;
        if (count[j] == 0) continue;
        for (b = 0; b < BINS; ++b) /* bin b's h, as its upper edge, in cells of R_ref / 2: x = 2 h_b / h_ref */
            if (count[b] > 0) cost += count[b] * sph__nsearch_model(dim, 2 * pow(2.0, 0.25 * (j - b)));
        if (best < 0 || cost < best) best = cost, pick = j;
    }
    return pick;
}

/* Grid geometry from the sources (eq. (N4)); no workspace needed yet. With
 * per-source h (PLAIN 0) the cells are refined below cell (the edge for the
 * largest h) to the h the sources have (sph__nsearch_pick), as long as the
 * cells stay at most max(those of cell, 4 n_sources + 64). */
SPH_API int sph__nsearch_geometry(sph_nsearch *g, int dim, sph_view xs, sph_idx ns, sph_view hs, sph_real cell,
                                  const sph_box *box, int plain)
{
    sph_real amax[3] = {0, 0, 0}, L[3] = {0, 0, 0};
    int a, st, j;
    sph_idx i;
    g->dim = 0;
    if (dim < 1 || dim > 3) return SPH_EDIM;
    if (ns < 0 || ns > SPH_NSEARCH_MAX_SOURCES) return SPH_ECOUNT;
    if (!(cell > 0 && cell <= SPH__REAL_MAX)) return SPH_ERANGE;
    if (!(1 / cell <= SPH__REAL_MAX)) return SPH_EGRID; /* a denormal cell: cell widths of 1/0 */
    if ((st = sph__ns_scan_x(dim, xs, ns, amax)) != SPH_OK) return st;
    if ((st = sph__ns_check_h(hs, ns, dim, &g->h_max)) != SPH_OK) return st;
    g->n_sources = ns;
    g->n_padded = ns + SPH__NS_PAD;
    g->plain = plain;
    g->cell_hint = cell;
    g->h_min = g->h_max;
    for (i = 0; hs.p[0] != NULL && i < ns; ++i)
        g->h_min = hs.p[0][(ptrdiff_t)i * hs.stride] < g->h_min ? hs.p[0][(ptrdiff_t)i * hs.stride] : g->h_min;
    for (a = 0; a < 3; ++a) {
        sph_real lo = 0;
        int per = a < dim && box != NULL && box->periodic[a];
        if (per) {
            lo = box->lo[a];
            L[a] = box->length[a];
            if (!sph__finite(lo) || sph__box_ok(box, dim) != SPH_OK) return SPH_EBOXLEN;
        } else if (a < dim && ns > 0) {
            sph_real hi = sph__ns_at(xs, a, 0);
            lo = hi;
            for (i = 1; i < ns; ++i) {
                sph_real x = sph__ns_at(xs, a, i);
                lo = x < lo ? x : lo;
                hi = x > hi ? x : hi;
            }
            L[a] = hi - lo;
        }
        g->lo[a] = lo;
        g->box.lo[a] = lo;
        g->box.length[a] = per ? L[a] : 0;
        g->box.periodic[a] = per;
        g->quarter[a] = per ? L[a] / 4 : SPH__REAL_MAX;
        g->image_ok[a] = per ? (sph_real)0.49 * L[a] : SPH__REAL_MAX;
    }
    g->quarter2 = SPH__REAL_MAX;
    for (a = 0; a < dim; ++a)
        if (g->box.periodic[a] && g->quarter[a] * g->quarter[a] < g->quarter2) g->quarter2 = g->quarter[a] * g->quarter[a];
    if ((st = sph__nsearch_axes(g, dim, L, amax, cell)) != SPH_OK) return st;
    if (hs.p[0] != NULL && ns > 0 && !plain) /* finer cells for the h the sources have */
        for (j = sph__nsearch_pick(hs, ns, dim, g->h_max); j > 0; --j) {
            sph_nsearch t = *g;
            const double cap = (double)g->n_cells > 4 * (double)ns + 64 ? (double)g->n_cells : 4 * (double)ns + 64;
            if (sph__nsearch_axes(&t, dim, L, amax, (sph_real)((double)cell * pow(2.0, -0.25 * j))) == SPH_OK &&
                t.n_cells <= cap) {
                *g = t;
                break;
            }
        }
    g->dim = dim;
    return SPH_OK;
}

/* Bytes of one workspace array padded to a 64-byte line. */
SPH_API double sph__nsearch_line(double bytes) { return ceil(bytes / 64) * 64; }

/* Workspace layout: returns the bytes needed (63 of them for alignment) and,
 * when base != NULL, points the grid's arrays into it, 64-byte aligned.
 * With per-source h also the per-cell largest h and the reach table hreach (PLAIN 0). */
SPH_API double sph__nsearch_layout(sph_nsearch *g, int with_h, char *base)
{
    const double cells = sph__nsearch_line((double)sizeof(sph_idx) * ((double)g->n_cells + 1));
    const double padded = (double)g->n_padded;
    const double order = sph__nsearch_line((double)sizeof(sph_idx) * padded);
    const double reals = sph__nsearch_line((double)sizeof(sph_real) * padded);
    const double xyz = sph__nsearch_line((double)sizeof(sph_real) * padded * g->dim);
    const int pyr = with_h && !g->plain && g->h_min < g->h_max; /* equal h: the uniform search */
    const double hcell = pyr ? sph__nsearch_line((double)sizeof(sph_real) * (double)g->n_cells) : 0;
    const double hreach = pyr ? sph__nsearch_line((double)sizeof(sph_real) * 2 * (double)g->n_cells) : 0;
    const double hs = (with_h != 0) * reals;
    const double sym = pyr ? 2 * order : 0, sym_at = pyr ? sph__nsearch_line((double)sizeof(sph_off) * padded) : 0;
    const double hf = pyr && SPH__NS_HF && sizeof(sph_real) == sizeof(double)
                          ? sph__nsearch_line((double)sizeof(float) * padded) : 0;
    if (base != NULL) {
        base += (64 - (size_t)((uintptr_t)base % 64)) % 64;
        g->cell_start = (sph_idx *)(void *)base;
        g->order = (sph_idx *)(void *)(base + (size_t)cells);
        g->x = (sph_real *)(void *)(base + (size_t)(cells + order));
        g->h = with_h ? (sph_real *)(void *)(base + (size_t)(cells + order + xyz)) : NULL;
        g->hcell = pyr ? (sph_real *)(void *)(base + (size_t)(cells + order + xyz + hs)) : NULL;
        g->hreach = pyr ? (sph_real *)(void *)(base + (size_t)(cells + order + xyz + hs + hcell)) : NULL;
        g->sym = pyr ? (sph_idx *)(void *)(base + (size_t)(cells + order + xyz + hs + hcell + hreach)) : NULL;
        g->sym_at = pyr ? (sph_off *)(void *)(base + (size_t)(cells + order + xyz + hs + hcell + hreach + sym)) : NULL;
        g->hf = hf > 0 ? (float *)(void *)(base + (size_t)(cells + order + xyz + hs + hcell + hreach + sym + sym_at)) : NULL;
    }
    return 63 + cells + order + xyz + hs + hcell + hreach + sym + sym_at + hf;
}

/* Steps of the reach push (sph__nsearch_hbuild): cells whose reach spans
 * more cells than this bound every target by h_far instead. */
#define SPH__NS_PUSH 64

/* out = in dilated by one cell along axis a: out[c] = max(in[c - 1], in[c],
 * in[c + 1]) along a, wrapped round a periodic axis, clamped at an open
 * one; acc: out[c] = max(out[c], in[c - 1], in[c + 1]) (a cross of axes). */
SPH_API void sph__nsearch_dilate(const sph_nsearch *g, int a, const sph_real *in, sph_real *out, int acc)
{
    const ptrdiff_t st = a == 0 ? 1 : a == 1 ? g->n[0] : (ptrdiff_t)g->n[0] * g->n[1], span = st * g->n[a];
    const int n = g->n[a], per = g->box.periodic[a];
    ptrdiff_t base, i;
    int k;
    for (base = 0; base < g->n_cells; base += span)
        for (k = 0; k < n; ++k) {
            const int km = k > 0 ? k - 1 : per ? n - 1 : 0, kp = k < n - 1 ? k + 1 : per ? 0 : n - 1;
            const sph_real *u = in + base + km * st, *w = in + base + kp * st, *v = acc ? out + base + k * st
                                                                                          : in + base + k * st;
            sph_real *z = out + base + k * st;
            for (i = 0; i < st; ++i) {
                const sph_real m = u[i] > v[i] ? u[i] : v[i];
                z[i] = w[i] > m ? w[i] : m;
            }
        }
}

/* Cells (reals, of the smallest width) that the push of sph__nsearch_hbuild
 * covers in every direction for a cell entered at step d: of the d steps
 * left, c = ceil(r d) dilate by a cube, o = d - c by a cross, so the offsets
 * y (in cells) it reaches are those with sum_a max(|y_a| - c, 0) <= o. Two
 * points less than u apart have offsets |y_a| <= ceil(|dx_a| / w); one
 * beyond needs integers k_a >= 1 on m axes, sum k_a = o + 1, with
 * |dx_a| / w > c - 1 + k_a, so every offset is reached while u^2 <=
 * sum_a (c - 1 + k_a)^2 for the most even split of o + 1 on m = 1..dim axes. */
SPH_API sph_real sph__nsearch_push_reach(int dim, int d)
{
    const double r = dim == 1 ? 1 : 0.4143;
    const int c = (int)ceil(r * d), o = d - c;
    double u2 = (double)d * d;
    int m;
    for (m = 1; m <= dim && m <= o + 1; ++m) {
        const int k = (o + 1) / m, extra = (o + 1) % m;
        const double s = (double)(m - extra) * (c - 1 + k) * (c - 1 + k) + (double)extra * (c + k) * (c + k);
        u2 = s < u2 ? s : u2;
    }
    return (sph_real)(sqrt(u2) * (1 - 1e-9)); /* rounded down */
}

/* The largest source h of every cell (hcell), and per cell the largest
 * hcell of the cells whose reach covers it (hreach; docs/neighbours.md,
 * "Varying h"): a cell of largest h hc reaches u = (kappa_b hc (1 + 2^-10)
 * + slack) / w_min cells. Pushed by a cascade from the widest reach down:
 * at step d the cells whose u lies in (U(d - 1), U(d)] (U of
 * sph__nsearch_push_reach) enter the table, then it is dilated by one cell
 * along each axis (a cube) or along the axes at once (a cross), so that a
 * cell entered at step d has spread over a near-sphere of radius U(d)
 * (wrapped round periodic axes, clamped at open ones). O(cells) per step,
 * at most SPH__NS_PUSH steps; cells of a wider reach go into h_far. */
SPH_API void sph__nsearch_hbuild(sph_nsearch *g)
{
    sph_real *F = g->hreach, *S = g->hreach + g->n_cells, *t, q;
    const double r = g->dim == 1 ? 1 : 0.4143;
    int c, d, a, top = 1;
    for (c = 0; c < g->n_cells; ++c) {
        sph_real m = 0;
        sph_idx i;
        for (i = g->cell_start[c]; i < g->cell_start[c + 1]; ++i) m = g->h[i] > m ? g->h[i] : m;
        g->hcell[c] = m;
        F[c] = 0;
    }
    g->kappa_b = 2 * g->cell_hint / g->h_max * (1 + (sph_real)1 / 1024);
    q = g->kappa_b * (1 + (sph_real)1 / 1024) / g->w_min; /* u = hc q + slack / w_min */
    while (top < SPH__NS_PUSH && sph__nsearch_push_reach(g->dim, top) < g->h_max * q + g->slack / g->w_min) ++top;
    g->h_far = 0;
    for (c = 0; c < g->n_cells; ++c)
        if (g->hcell[c] * q + g->slack / g->w_min > sph__nsearch_push_reach(g->dim, top) && g->hcell[c] > g->h_far)
            g->h_far = g->hcell[c];
    for (d = top; d >= 1; --d) {
        const sph_real lo = d > 1 ? sph__nsearch_push_reach(g->dim, d - 1) : -1, hi = sph__nsearch_push_reach(g->dim, d);
        for (c = 0; c < g->n_cells; ++c) {
            const sph_real u = g->hcell[c] * q + g->slack / g->w_min;
            F[c] = u > lo && u <= hi && g->hcell[c] > F[c] ? g->hcell[c] : F[c];
        }
        if (ceil(r * d) > ceil(r * (d - 1))) /* a cube: one axis after the other */
            for (a = 0; a < g->dim; ++a) {
                sph__nsearch_dilate(g, a, F, S, 0);
                t = F, F = S, S = t;
            }
        else { /* a cross: every axis from the same table */
            for (a = 0; a < g->dim; ++a) sph__nsearch_dilate(g, a, F, S, a > 0);
            t = F, F = S, S = t;
        }
    }
    if (F != g->hreach)
        for (c = 0; c < g->n_cells; ++c) g->hreach[c] = F[c];
}

/* Workspace bytes sph_nsearch_build needs for these sources (eq. (N4)
 * sizes the grid; scans the positions for their bounds). */
SPH_API int sph_nsearch_workspace_size(int dim, sph_view xs, sph_idx n_sources, sph_view hs,
                                       sph_real cell, const sph_box *box, size_t *bytes)
{
    sph_nsearch g;
    double need;
    int st;
    if (bytes == NULL) return SPH_ENULL;
    *bytes = 0;
    if ((st = sph__nsearch_geometry(&g, dim, xs, n_sources, hs, cell, box, SPH__NS_PLAIN)) != SPH_OK) return st;
    need = sph__nsearch_layout(&g, hs.p[0] != NULL, NULL);
    if (!(need <= (double)SIZE_MAX)) return SPH_EGRID;
    *bytes = (size_t)need;
    return SPH_OK;
}

/* sph_nsearch_build with the plain reference search (plain 1: cells of
 * cell, one radius kappa max(h_i, h_max) in symmetric mode) or the one for
 * varying h (0); SPH_NSEARCH_PLAIN picks the first for sph_nsearch_build. */
SPH_API int sph__nsearch_build_as(sph_nsearch *g, int dim, sph_view xs, sph_idx n_sources, sph_view hs,
                                  sph_real cell, const sph_box *box, void *work, size_t work_bytes, int plain)
{
    sph_real x[3] = {0, 0, 0};
    sph_idx i;
    int a, c, st;
    if (g == NULL) return SPH_ENULL;
    if ((st = sph__nsearch_geometry(g, dim, xs, n_sources, hs, cell, box, plain)) != SPH_OK) return st;
    if (work == NULL) {
        g->dim = 0;
        return SPH_ENULL;
    }
    if (!(sph__nsearch_layout(g, hs.p[0] != NULL, NULL) <= (double)work_bytes)) {
        g->dim = 0;
        return SPH_ESIZE;
    }
    sph__nsearch_layout(g, hs.p[0] != NULL, (char *)work);
    for (c = 0; c <= g->n_cells; ++c) g->cell_start[c] = 0;
    for (i = 0; i < n_sources; ++i) { /* count per cell, shifted by one */
        for (a = 0; a < dim; ++a) x[a] = sph__ns_at(xs, a, i);
        ++g->cell_start[sph__nsearch_source_cell(g, x) + 1];
    }
    g->n_occupied = 0;
    for (c = 0; c < g->n_cells; ++c) {
        g->n_occupied += g->cell_start[c + 1] > 0;
        g->cell_start[c + 1] += g->cell_start[c];
    }
    for (i = 0; i < n_sources; ++i) { /* scatter; cell_start[c] runs ahead to the next cell */
        sph_idx k;
        for (a = 0; a < dim; ++a) x[a] = sph__ns_at(xs, a, i);
        c = sph__nsearch_source_cell(g, x);
        k = g->cell_start[c]++;
        g->order[k] = i;
        for (a = 0; a < dim; ++a) g->x[(ptrdiff_t)a * g->n_padded + k] = x[a];
        if (hs.p[0] != NULL) g->h[k] = hs.p[0][(ptrdiff_t)i * hs.stride];
    }
    for (i = n_sources; i < g->n_padded; ++i) { /* padding: read by the blocked checks, never kept */
        g->order[i] = 0;
        for (a = 0; a < dim; ++a) g->x[(ptrdiff_t)a * g->n_padded + i] = 0;
        if (hs.p[0] != NULL) g->h[i] = 1;
    }
    for (c = g->n_cells; c > 0; --c) g->cell_start[c] = g->cell_start[c - 1];
    g->cell_start[0] = 0;
    if (g->hcell != NULL) sph__nsearch_hbuild(g);
    for (i = 0; g->hf != NULL && i < g->n_padded; ++i) /* (kappa h)^2 within float's normal range, else NaN */
        g->hf[i] = g->h[i] >= (sph_real)1e-30 && g->h[i] <= (sph_real)1e30 ? (float)g->h[i] : (float)NAN;
    return SPH_OK;
}

/* Bins the sources into cells (eq. (N4)) by a stable counting sort inside
 * work: cell starts, sorted order, sorted positions (and h, with the
 * per-cell largest h and the reach table hreach). O(N + cells). */
SPH_API int sph_nsearch_build(sph_nsearch *g, int dim, sph_view xs, sph_idx n_sources, sph_view hs, sph_real cell,
                              const sph_box *box, void *work, size_t work_bytes)
{
    SPH__DISPATCH_TO(sph_nsearch_build, (g, dim, xs, n_sources, hs, cell, box, work, work_bytes))
    return sph__nsearch_build_as(g, dim, xs, n_sources, hs, cell, box, work, work_bytes, SPH__NS_PLAIN);
}

/* Checks the arguments shared by count, fill, lists and stats. The largest
 * search radius R = kappa h_i (gather) or kappa max(h_i, h_j) (symmetric)
 * must fit the minimum image: R <= L/2 on every periodic axis, so that no
 * source has two images within reach (else SPH_EPERIOD). */
SPH_API int sph__nsearch_check(const sph_nsearch *g, sph_view xt, sph_idx nt, sph_view ht,
                               sph_real h, sph_real kappa, int mode)
{
    int uses_h = ht.p[0] == NULL || (mode == SPH_NSEARCH_SYMMETRIC && g != NULL && g->h == NULL);
    int st, a;
    sph_real hmax;
    if (g == NULL) return SPH_ENULL;
    if (g->dim < 1 || g->dim > 3) return SPH_ENOGRID;
    if (nt < 0) return SPH_ECOUNT;
    if (mode != SPH_NSEARCH_GATHER && mode != SPH_NSEARCH_SYMMETRIC) return SPH_EOPTION;
    if (!(kappa > 0 && kappa <= SPH__REAL_MAX)) return SPH_ERANGE;
    if (uses_h && !sph__h_ok(h, g->dim)) return SPH_EH;
    if ((st = sph__ns_check_x(g->dim, xt, nt)) != SPH_OK) return st;
    if ((st = sph__ns_check_h(ht, nt, g->dim, &hmax)) != SPH_OK) return st;
    if (ht.p[0] == NULL) hmax = h;
    if (mode == SPH_NSEARCH_SYMMETRIC) {
        const sph_real hs = g->h != NULL ? g->h_max : h;
        hmax = hs > hmax ? hs : hmax;
    }
    for (a = 0; a < g->dim; ++a)
        if (g->box.periodic[a] && !(kappa * hmax <= g->box.length[a] / 2)) return SPH_EPERIOD;
    return SPH_OK;
}

/* The search parameters of target i (position, h_i, criterion). */
SPH_API void sph__nsearch_probe(const sph_nsearch *g, sph_view xt, sph_view ht, sph_real h, sph_real kappa, int mode,
                                sph_idx i, sph__probe *p)
{
    int a;
    for (a = 0; a < 3; ++a) p->xt[a] = a < g->dim ? sph__ns_at(xt, a, i) : 0;
    p->hi = ht.p[0] != NULL ? ht.p[0][(ptrdiff_t)i * ht.stride] : h;
    p->hu = h;
    p->kappa = kappa;
    p->symmetric = mode == SPH_NSEARCH_SYMMETRIC;
    p->mark = mode == SPH__NS_MARK && p->hi > g->h_min; /* h_i >= h_min >= h_j: every source reaches i itself */
}

/* Runs the search for every target: counts into count[i + 1] (when count
 * != NULL), fills index (when index != NULL, segments given by offset),
 * sums into stats (when not NULL) the pairs, the candidates checked and the
 * blocks redone for the minimum image. Returns SPH_EOFFSET when a target's
 * count differs from its segment. Parallel over targets under OpenMP, same
 * result. */
SPH_API int sph__nsearch_run(const sph_nsearch *g, sph_view xt, sph_idx nt, sph_view ht,
                             sph_real h, sph_real kappa, int mode, sph_off *count,
                             const sph_off *offset, sph_idx *index, sph_off *stats)
{
    sph_off sum_pairs = 0, sum_checked = 0, sum_redone = 0;
    int bad = 0;
    sph_idx i;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 64) if (nt >= 512) reduction(+ : sum_pairs, sum_checked, sum_redone) \
    reduction(| : bad)
#endif
    for (i = 0; i < nt; ++i) {
        sph__probe p;
        sph__nsearch_probe(g, xt, ht, h, kappa, mode, i, &p);
        p.seg = index != NULL ? index + offset[i] : NULL;
        p.cap = index != NULL ? offset[i + 1] - offset[i] : 0;
        sph__nsearch_target(g, &p);
        if (count != NULL) count[i + 1] = p.found;
        if (index != NULL) bad |= p.found != p.cap;
        sum_pairs += p.found;
        sum_checked += p.checked;
        sum_redone += p.redone;
    }
    if (stats != NULL) {
        stats[0] = sum_pairs;
        stats[1] = sum_checked;
        stats[2] = sum_redone;
    }
    return bad ? SPH_EOFFSET : SPH_OK;
}

/* Counting pass: offset[0..nt] of the CSR lists of criterion (N1)/(N2);
 * offset[nt] is the number of pairs, the length index[] needs. */
SPH_API int sph_nsearch_count(const sph_nsearch *g, sph_view xt, sph_idx n_targets, sph_view ht,
                              sph_real h, sph_real kappa, int mode, sph_off *offset)
{
    SPH__DISPATCH_TO(sph_nsearch_count, (g, xt, n_targets, ht, h, kappa, mode, offset))
    sph_idx i;
    int st = sph__nsearch_check(g, xt, n_targets, ht, h, kappa, mode);
    if (st != SPH_OK) return st;
    if (offset == NULL) return SPH_ENULL;
    offset[0] = 0;
    sph__nsearch_run(g, xt, n_targets, ht, h, kappa, mode, offset, NULL, NULL, NULL);
    for (i = 0; i < n_targets; ++i) offset[i + 1] += offset[i];
    return SPH_OK;
}

/* ---- Symmetric lists from the gather ones (docs/neighbours.md, "Varying
 * h"). With r_ij^2 the same from either end, (N2) is the union of the two
 * gather criteria: j in row i iff j is in gather row i (r_ij < kappa h_i)
 * or i is in gather row j (r_ij < kappa h_j). So row i = G_i + E_i, G_i
 * its gather row and E_i = {j : i in G_j, j not in G_i}: the sources whose
 * larger h reaches i from beyond kappa h_i, found by transposing the
 * entries of the gather rows that fail the criterion seen from their
 * source. One gather search, O(pairs) more work, instead of searching
 * every target out to kappa h_max near the largest h. ---- */

/* 1 when the symmetric lists may be built from the gather ones: per-source
 * h that vary (the grid's scratch sym), not the plain search, per-target h,
 * the targets are the sources (same count, positions and h), and kappa h_max
 * within a quarter period of every periodic axis, so that every pair within
 * reach has |dx_a| <= L/4, where sph__nsearch_delta returns dx itself and
 * r_ij^2 = r_ji^2 bit for bit (beyond it, sph_box_delta's rounding need not
 * be odd in dx near L/2). O(N); the sources are compared in sorted order. */
SPH_API int sph__nsearch_sym_ok(const sph_nsearch *g, sph_view xt, sph_idx nt, sph_view ht, sph_real kappa, int mode)
{
    sph_idx k;
    int a, same = 1;
    if (mode != SPH_NSEARCH_SYMMETRIC || g->sym == NULL || g->plain || ht.p[0] == NULL || nt != g->n_sources)
        return 0;
    for (a = 0; a < g->dim; ++a)
        if (!(kappa * g->h_max <= g->quarter[a])) return 0;
    for (k = 0; k < nt; ++k) {
        const sph_idx i = g->order[k];
        same &= g->h[k] == ht.p[0][(ptrdiff_t)i * ht.stride];
        for (a = 0; a < g->dim; ++a) same &= g->x[(ptrdiff_t)a * g->n_padded + k] == sph__ns_at(xt, a, i);
    }
    return same;
}

/* Bit k set when v[k] < 0 (a mark), k < w <= 32: one word per 32 list
 * entries, so that the loops over marks branch per set bit of a word, not
 * per entry; a whole word from the sign bits of 16 or 4 entries per
 * instruction where the build has AVX-512 (a row's last word too, by masked
 * loads) or SSE2. */
SPH_API unsigned sph__ns_signs(const sph_idx *v, int w)
{
#if SPH__NS_COMPRESS
    const __m512i zero = _mm512_setzero_si512();
    return (unsigned)_mm512_cmplt_epi32_mask(_mm512_maskz_loadu_epi32(sph__ns_live16(w), (const void *)v), zero) |
           (unsigned)_mm512_cmplt_epi32_mask(_mm512_maskz_loadu_epi32(sph__ns_live16(w - 16), (const void *)(v + 16)), zero)
               << 16;
#else
    unsigned m = 0;
    int k;
#if SPH__SQRT_SIMD
    if (w == 32) {
        for (k = 0; k < 8; ++k)
            m |= (unsigned)_mm_movemask_ps(_mm_castsi128_ps(_mm_loadu_si128((const __m128i *)(const void *)(v + 4 * k))))
                 << (4 * k);
        return m;
    }
#endif
    if (w == 32)
        for (k = 0; k < 32; ++k) m |= ((unsigned)v[k] >> 31) << k;
    else
        for (k = 0; k < w; ++k) m |= ((unsigned)v[k] >> 31) << k;
    return m;
#endif
}

/* Counts into ext[i] the marks -1 - i of list entries row[0 .. n-1]
 * (atomically under OpenMP: chunks are counted in parallel); returns how
 * many. The marks of up to 512 entries are gathered first, then counted in
 * a loop of their own: its increments, scattered over ext, overlap one
 * another instead of each waiting behind a mispredicted branch of the scan. */
SPH_API sph_idx sph__nsearch_sym_count(const sph_idx *row, sph_off n, sph_off *ext)
{
    enum { C = 512 };
    sph_idx mark[C], marks = 0;
    sph_off e, k;
    for (e = 0; e < n; e += C) {
        const sph_off w = n - e < (sph_off)C ? n - e : (sph_off)C;
        int c = 0;
        for (k = 0; k < w; k += 32) {
            unsigned m = sph__ns_signs(row + e + k, w - k < 32 ? (int)(w - k) : 32);
            for (; m != 0; m &= m - 1) mark[c++] = row[e + k + sph__ns_ctz(m)];
        }
        marks += c;
        while (c > 0) {
#ifdef _OPENMP
#pragma omp atomic
#endif
            ++ext[-1 - mark[--c]];
        }
    }
    return marks;
}

/* The second run (n2 <= 64) merged in from buf: from its last value down,
 * the values of the first run above it moved up, then it. LOW 0 when every
 * value of buf is above a[0]: the scan of the first run then stops at a[0]
 * without testing its end (a constant once inlined). */
SPH__INLINE void sph__ns_merge_buf(sph_idx *a, const sph_idx *buf, sph_off n1, sph_off n2, const int LOW)
{
    sph_off w = n1 + n2, p = n1, q;
    for (q = n2 - 1; q >= 0; --q) {
        while ((!LOW || p > 0) && a[p - 1] > buf[q]) a[--w] = a[--p];
        a[--w] = buf[q];
    }
}

/* Merges the ascending runs a[0 .. n1-1] and a[n1 .. n1+n2-1] (no value in
 * both) in place: through a buffer of 64 when one run fits it, else by a
 * rotation at a cut point and the two halves merged alike (O(n log n)
 * moves, depth O(log n)). */
SPH_API void sph__ns_merge(sph_idx *a, sph_off n1, sph_off n2)
{
    enum { B = 64 };
    sph_idx buf[B];
    sph_off c1, c2, lo, hi, k;
    if (n1 == 0 || n2 == 0) return;
    if (n2 <= B) { /* the second run into buf, merged from the back */
        for (k = 0; k < n2; ++k) buf[k] = a[n1 + k];
        if (a[n1] > a[0]) /* the second run's lowest, buf[0] */
            sph__ns_merge_buf(a, buf, n1, n2, 0);
        else
            sph__ns_merge_buf(a, buf, n1, n2, 1);
        return;
    }
    if (n1 <= B) { /* the first run into buf, merged from the front */
        sph_off w = 0, p = 0, q = n1;
        for (k = 0; k < n1; ++k) buf[k] = a[k];
        while (p < n1) a[w++] = q < n1 + n2 && a[q] < buf[p] ? a[q++] : buf[p++];
        return;
    }
    if (n1 > n2) { /* cut the longer run in half, the other where its half's first value goes */
        const sph_idx v = a[c1 = n1 / 2];
        for (lo = n1, hi = n1 + n2; lo < hi;) {
            const sph_off m = lo + (hi - lo) / 2;
            if (a[m] < v) lo = m + 1; else hi = m;
        }
        c2 = lo - n1;
    } else {
        const sph_idx v = a[n1 + (c2 = n2 / 2)];
        for (lo = 0, hi = n1; lo < hi;) {
            const sph_off m = lo + (hi - lo) / 2;
            if (a[m] < v) lo = m + 1; else hi = m;
        }
        c1 = lo;
    }
    { /* rotate a[c1 .. n1 + c2 - 1] so that a[n1 .. n1 + c2 - 1] comes first: three reversals */
        sph_off r[3][2];
        int t;
        r[0][0] = c1, r[0][1] = n1, r[1][0] = n1, r[1][1] = n1 + c2, r[2][0] = c1, r[2][1] = n1 + c2;
        for (t = 0; t < 3; ++t)
            for (lo = r[t][0], hi = r[t][1] - 1; lo < hi; ++lo, --hi) {
                const sph_idx s = a[lo];
                a[lo] = a[hi], a[hi] = s;
            }
    }
    sph__ns_merge(a, c1, c2);
    sph__ns_merge(a + c1 + c2, n1 - c1, n2 - c2);
}

/* Completes the symmetric rows in place. Gather row i (len[i] entries,
 * marks[i] of them a source i marked -1 - i, in ascending source) is at the
 * front of its final segment offset[i] .. offset[i+1] - 1; at[i] =
 * offset[i+1]. Each mark is transposed into the back of its source's
 * segment (at[i] moves down to offset[i] + len[i]), rows taken in
 * descending order so that every E_i comes out ascending, found 32 entries
 * at a time from a word of their signs (sph__ns_signs), up to the row's
 * last mark, and undone; then each row merges its two runs (parallel under
 * OpenMP). */
SPH_API void sph__nsearch_sym_finish(sph_idx n, const sph_off *offset, const sph_idx *len, const sph_idx *marks,
                                     sph_off *at, sph_idx *index)
{
    sph_idx i, j;
    for (j = n - 1; j >= 0; --j) {
        sph_idx *row = index + offset[j], e, left = marks[j];
        for (e = 0; left > 0 && e < len[j]; e += 32) {
            unsigned m = sph__ns_signs(row + e, len[j] - e < 32 ? (int)(len[j] - e) : 32);
            for (; m != 0; m &= m - 1, --left) {
                const int k = sph__ns_ctz(m);
                const sph_idx src = -1 - row[e + k];
                row[e + k] = src;
                index[--at[src]] = j;
            }
        }
    }
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 256) if (n >= 4096)
#endif
    for (i = 0; i < n; ++i) sph__ns_merge(index + offset[i], len[i], offset[i + 1] - offset[i] - len[i]);
}

/* sph_nsearch_fill in symmetric mode from the gather search (sph__nsearch_sym_ok
 * holds; offset checked): each gather row searched into the front of its
 * segment, marked, completed. SPH_EOFFSET when a row's lengths disagree
 * with offset (index then unspecified). */
SPH_API int sph__nsearch_sym_fill(const sph_nsearch *g, sph_view xt, sph_idx n, sph_view ht, sph_real h,
                                  sph_real kappa, const sph_off *offset, sph_idx *index)
{
    sph_idx *len = g->sym, *marks = g->sym + g->n_padded, i;
    sph_off *ext = g->sym_at;
    int bad = 0;
    for (i = 0; i < n; ++i) ext[i] = 0;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 64) if (n >= 512) reduction(| : bad)
#endif
    for (i = 0; i < n; ++i) {
        sph__probe p;
        sph__nsearch_probe(g, xt, ht, h, kappa, SPH__NS_MARK, i, &p);
        p.seg = index + offset[i];
        p.cap = offset[i + 1] - offset[i];
        sph__nsearch_target(g, &p);
        bad |= p.found > p.cap;
        len[i] = (sph_idx)(p.found < p.cap ? p.found : p.cap);
    }
    if (bad) return SPH_EOFFSET;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 256) if (n >= 4096)
#endif
    for (i = 0; i < n; ++i) marks[i] = sph__nsearch_sym_count(index + offset[i], len[i], ext);
    for (i = 0; i < n; ++i)
        bad |= offset[i + 1] - offset[i] != len[i] + ext[i];
    if (bad) return SPH_EOFFSET;
    for (i = 0; i < n; ++i) ext[i] = offset[i + 1];
    sph__nsearch_sym_finish(n, offset, len, marks, ext, index);
    return SPH_OK;
}

/* Fill pass: index[offset[i] .. offset[i+1]-1] = the neighbours of target i
 * (criterion (N1)/(N2)) in ascending source index. offset must come from
 * sph_nsearch_count with the same arguments; index holds capacity entries
 * (SPH_ESIZE, nothing written, when offset[nt] > capacity; SPH_EOFFSET when
 * offset is malformed or a target's list does not have its length). */
SPH_API int sph_nsearch_fill(const sph_nsearch *g, sph_view xt, sph_idx n_targets, sph_view ht,
                             sph_real h, sph_real kappa, int mode, const sph_off *offset, sph_idx *index,
                             sph_off capacity)
{
    SPH__DISPATCH_TO(sph_nsearch_fill, (g, xt, n_targets, ht, h, kappa, mode, offset, index, capacity))
    sph_idx i;
    int st = sph__nsearch_check(g, xt, n_targets, ht, h, kappa, mode);
    if (st != SPH_OK) return st;
    if (offset == NULL) return SPH_ENULL;
    if (offset[0] != 0) return SPH_EOFFSET;
    for (i = 0; i < n_targets; ++i)
        if (offset[i + 1] < offset[i]) return SPH_EOFFSET;
    if (offset[n_targets] > capacity) return SPH_ESIZE;
    if (index == NULL && offset[n_targets] > 0) return SPH_ENULL;
    if (n_targets == 0 || index == NULL) return SPH_OK;
    if (sph__nsearch_sym_ok(g, xt, n_targets, ht, kappa, mode))
        return sph__nsearch_sym_fill(g, xt, n_targets, ht, h, kappa, offset, index);
    return sph__nsearch_run(g, xt, n_targets, ht, h, kappa, mode, NULL, offset, index, NULL);
}

/* Targets lo..hi-1 of sph_nsearch_lists into index[s0 .. s1-1] one after
 * another, each target's count into offset[i + 1]. Returns the first target
 * whose list did not fit (hi when all did); the targets after it are counted
 * only. */
SPH_API sph_idx sph__nsearch_block(const sph_nsearch *g, sph_view xt, sph_view ht, sph_real h, sph_real kappa,
                                   int mode, sph_idx lo, sph_idx hi, sph_off *offset, sph_idx *index, sph_off s0,
                                   sph_off s1)
{
    sph_idx i, bad = hi;
    for (i = lo; i < hi; ++i) {
        sph__probe p;
        sph__nsearch_probe(g, xt, ht, h, kappa, mode, i, &p);
        p.seg = bad == hi && index != NULL ? index + s0 : NULL;
        p.cap = bad == hi ? s1 - s0 : 0;
        sph__nsearch_target(g, &p);
        offset[i + 1] = p.found;
        if (bad == hi && p.found > p.cap) bad = i;
        if (bad == hi) s0 += p.found;
    }
    return bad;
}

/* Blocks of targets the one-pass search splits n_targets into: one without
 * OpenMP or with one thread, else up to four per thread of at least 1024
 * targets each, at most max_blocks. */
SPH_API int sph__nsearch_blocks(sph_idx n_targets, int max_blocks)
{
    int nb = 1;
#ifdef _OPENMP
    nb = omp_get_max_threads();
    nb = nb > 1 ? 4 * nb : 1; /* one thread: one block, nothing to move */
    nb = nb < max_blocks ? nb : max_blocks;
    nb = n_targets / 1024 < nb ? (int)(n_targets / 1024) : nb;
    nb = nb > 1 ? nb : 1;
#endif
    (void)n_targets, (void)max_blocks;
    return nb;
}

/* Count and fill in one search per target (eq. (N1)/(N2)): offset[0..nt]
 * and index[] exactly as sph_nsearch_count then sph_nsearch_fill give them;
 * index holds capacity entries, *pairs = offset[nt] (the entries needed).
 * SPH_ESIZE when more than capacity are needed: offset is then complete
 * (sph_nsearch_fill with it and a larger index finishes the job), index
 * unspecified. Under OpenMP the targets are split into up to four
 * contiguous blocks per thread (at least 1024 targets each), taken by the
 * threads as they come free (a core that runs slower takes fewer), each
 * searched into the share of index proportional to it, then moved down into
 * place; from the first block that outgrows its share on, a second pass
 * fills the lists (a capacity ~20 % above the expected pairs avoids it). The
 * result does not depend on the thread count. */
SPH_API int sph__nsearch_lists_ref(const sph_nsearch *g, sph_view xt, sph_idx n_targets, sph_view ht, sph_real h,
                                   sph_real kappa, int mode, sph_off *offset, sph_idx *index, sph_off capacity,
                                   sph_off *pairs)
{
    enum { MAX_BLOCKS = 64 };
    sph_idx lo[MAX_BLOCKS + 1], bad[MAX_BLOCKS];
    sph_off s0[MAX_BLOCKS + 1], k, end, next[SPH__SHARES_MAX * SPH_SHARE_PAD];
    sph_share sh;
    int nb, b, st = sph__nsearch_check(g, xt, n_targets, ht, h, kappa, mode == SPH__NS_MARK ? SPH_NSEARCH_GATHER : mode);
    sph_idx i;
    if (st != SPH_OK) return st;
    if (offset == NULL || pairs == NULL || (index == NULL && capacity > 0)) return SPH_ENULL;
    if (capacity < 0) return SPH_ECOUNT;
    nb = sph__nsearch_blocks(n_targets, MAX_BLOCKS);
    for (b = 0; b <= nb; ++b) { /* block b: targets lo[b].., index from s0[b] */
        lo[b] = (sph_idx)((double)n_targets * b / nb);
        s0[b] = (sph_off)((double)capacity * b / nb);
    }
    lo[nb] = n_targets;
    s0[nb] = capacity;
    sph_share_init(&sh, next, SPH__SHARES, nb, 1);
#ifdef _OPENMP
#pragma omp parallel if (nb > 1)
#endif
    { /* each thread its own blocks first (the targets of its static share), then the others' (sph_share_next) */
        sph_idx b0, b1, c;
        int u = 0;
        while (sph_share_next(&sh, SPH__THREAD, &u, &b0, &b1))
            for (c = b0; c < b1; ++c)
                bad[c] = sph__nsearch_block(g, xt, ht, h, kappa, mode, lo[c], lo[c + 1], offset, index, s0[c], s0[c + 1]);
    }
    offset[0] = 0;
    for (i = 0; i < n_targets; ++i) offset[i + 1] += offset[i];
    *pairs = offset[n_targets];
    if (offset[n_targets] > capacity) return SPH_ESIZE;
    for (b = 0; b < nb; ++b) { /* blocks that fitted move down to their offsets (never up: the blocks
                                  before them fitted too), in order */
        if (bad[b] != lo[b + 1]) break;
        end = offset[lo[b + 1]] - offset[lo[b]];
        for (k = 0; s0[b] != offset[lo[b]] && k < end; ++k) index[offset[lo[b]] + k] = index[s0[b] + k];
    }
    if (b < nb) { /* from the first block that outgrew its share: a fill pass over the rest */
        return sph__nsearch_run(g, sph__ns_tail(xt, g->dim, lo[b]), n_targets - lo[b], sph__ns_tail(ht, 1, lo[b]), h,
                                kappa, mode, NULL, offset + lo[b], index, NULL);
    }
    return SPH_OK;
}

/* Copies the c values below r to below w (w >= r: the ranges may overlap),
 * 16 at a time through a buffer, from the top, marks -1 - s undone to s;
 * returns w - c. */
SPH__INLINE sph_idx *sph__ns_up(sph_idx *w, const sph_idx *r, sph_off c)
{
    sph_idx buf[16];
    int k;
    for (; c >= 16; c -= 16) {
        for (k = 0; k < 16; ++k) buf[k] = sph__ns_unmark(r[k - 16]);
        for (k = 0; k < 16; ++k) w[k - 16] = buf[k];
        r -= 16, w -= 16;
    }
    while (c-- > 0) *--w = sph__ns_unmark(*--r);
    return w;
}

/* The b marks of buf counted into at and stored at (*P)[c ..], *P set to
 * NULL from the first that would pass room on; returns c + b. */
SPH__INLINE sph_off sph__ns_put_marks(const sph_idx *buf, int b, sph_off *at, sph_idx **P, sph_off c, sph_off room)
{
    int k;
    for (k = 0; k < b; ++k) ++at[-1 - buf[k]];
    *P = *P != NULL && c + b <= room ? *P : NULL;
    for (k = 0; *P != NULL && k < b; ++k) (*P)[c + k] = buf[k];
    return c + b;
}

/* One pass over the gather rows (row j len[j] entries, one after another
 * from index[0]): marks[j] = the marks in row j, at[s] += the marks -1 - s,
 * and the marks themselves in row order into P while room lasts (P may be
 * NULL). Returns how many. The marks of up to 512 entries are counted in a
 * loop of their own, where the increments scattered over at overlap one
 * another instead of each waiting behind a mispredicted branch. */
SPH_API sph_off sph__nsearch_sym_scan(sph_idx n, const sph_idx *len, const sph_idx *index, sph_idx *marks,
                                      sph_off *at, sph_idx *P, sph_off room)
{
    enum { C = 512 };
    sph_idx buf[C + 32], j, e;
    sph_off c = 0, src = 0;
    int b = 0;
    for (j = 0; j < n; src += len[j++]) {
        const sph_idx *row = index + src;
        const sph_off c0 = c + b;
#if SPH__NS_COMPRESS
        for (e = 0; e < len[j]; e += 16) { /* the marks of 16 entries compressed into buf, without a branch */
            const __m512i v = _mm512_maskz_loadu_epi32(sph__ns_live16(len[j] - e), (const void *)(row + e));
            const __mmask16 m = _mm512_cmplt_epi32_mask(v, _mm512_setzero_si512());
            _mm512_storeu_si512((void *)(buf + b), _mm512_maskz_compress_epi32(m, v));
            b += __builtin_popcount(m);
            if (b >= C) c = sph__ns_put_marks(buf, b, at, &P, c, room), b = 0;
        }
#else
        for (e = 0; e < len[j]; e += 32) {
            unsigned m = sph__ns_signs(row + e, len[j] - e < 32 ? (int)(len[j] - e) : 32);
            for (; m != 0; m &= m - 1) buf[b++] = row[e + sph__ns_ctz(m)];
            if (b >= C) c = sph__ns_put_marks(buf, b, at, &P, c, room), b = 0;
        }
#endif
        marks[j] = (sph_idx)(c + b - c0);
    }
    return sph__ns_put_marks(buf, b, at, &P, c, room); /* what the last rows left */
}

/* sph__nsearch_sym_scan on up to 64 contiguous blocks of rows, one per
 * thread at a time (under OpenMP): each block's marks counted per row, then,
 * from the block's place in P (a prefix over the blocks), stored there in
 * row order, at[s] counted atomically. The same marks, at and P. One
 * thread keeps sph__nsearch_sym_scan: one pass over the rows, not two
 * (0.136 against 0.139 s for the symmetric clump of bench/bench_search_h.c). */
SPH_API sph_off sph__nsearch_sym_scan_blocks(sph_idx n, const sph_off *offset, const sph_idx *index, sph_idx *marks,
                                             sph_off *at, sph_idx *P, sph_off room, int nb)
{
    enum { MAX_BLOCKS = 64 };
    sph_off c[MAX_BLOCKS + 1];
    int b;
    nb = nb < MAX_BLOCKS ? nb : MAX_BLOCKS;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) if (nb > 1)
#endif
    for (b = 0; b < nb; ++b) { /* each row's marks */
        const sph_idx lo = (sph_idx)((double)n * b / nb), hi = (sph_idx)((double)n * (b + 1) / nb);
        sph_idx j;
        sph_off e, sum = 0;
        for (j = lo; j < hi; ++j) {
            const sph_off len = offset[j + 1] - offset[j];
            int k = 0;
            for (e = 0; e < len; e += 32)
                k += sph__ns_popcount(sph__ns_signs(index + offset[j] + e, len - e < 32 ? (int)(len - e) : 32));
            marks[j] = k;
            sum += k;
        }
        c[b + 1] = sum;
    }
    for (c[0] = 0, b = 0; b < nb; ++b) c[b + 1] += c[b];
    P = c[nb] <= room ? P : NULL;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) if (nb > 1)
#endif
    for (b = 0; b < nb; ++b) { /* the marks into P from the block's place, and counted */
        const sph_idx lo = (sph_idx)((double)n * b / nb), hi = (sph_idx)((double)n * (b + 1) / nb);
        sph_idx j;
        sph_off e, w = c[b];
        for (j = lo; j < hi; ++j) {
            const sph_off len = offset[j + 1] - offset[j];
            const sph_idx *row = index + offset[j];
            for (e = 0; marks[j] > 0 && e < len; e += 32) {
                unsigned m = sph__ns_signs(row + e, len - e < 32 ? (int)(len - e) : 32);
                for (; m != 0; m &= m - 1) {
                    const sph_idx v = row[e + sph__ns_ctz(m)];
                    if (P != NULL) P[w++] = v;
#ifdef _OPENMP
#pragma omp atomic
#endif
                    ++at[-1 - v];
                }
            }
        }
    }
    return c[nb];
}

#if SPH__NS_COMPRESS
/* How many of row[0 .. t-1] (ascending once unmarked) lie below v, given
 * that none from t on does: 16 at a time down from t. */
SPH__INLINE sph_off sph__ns_below16(const sph_idx *row, sph_off t, sph_idx v)
{
    for (;;) {
        const sph_off lo = t >= 16 ? t - 16 : 0;
        const __mmask16 live = sph__ns_live16(t - lo);
        const __m512i x = sph__ns_unmark16(_mm512_maskz_loadu_epi32(live, (const void *)(row + lo)));
        const int above = __builtin_popcount(_mm512_mask_cmpgt_epi32_mask(live, x, _mm512_set1_epi32(v)));
        if (above < t - lo || lo == 0) return t - above;
        t = lo;
    }
}
#endif

#if SPH__NS_COMPRESS
/* The lanes of out's chunks of 16 (from out[0]) that come from ext, for a
 * row of at most 16 NCH entries (NCH a constant: the row stays in
 * registers): ext[c] goes to c + the row's entries below it. */
SPH__INLINE void sph__ns_ext_lanes(unsigned short *in_ext, const sph_idx *row, sph_off L, const sph_idx *ext,
                                   sph_off e, const int NCH)
{
    __m512i x[8];
    sph_off c;
    int t;
    for (t = 0; t < NCH; ++t) {
        x[t] = sph__ns_unmark16(
            _mm512_mask_loadu_epi32(_mm512_set1_epi32(INT32_MAX), sph__ns_live16(L - 16 * t), (const void *)(row + 16 * t)));
    }
    for (c = 0; c <= (L + e - 1) / 16; ++c) in_ext[c] = 0;
    for (c = 0; c < e; ++c) {
        const __m512i v = _mm512_set1_epi32(ext[c]);
        sph_off below = c;
        for (t = 0; t < NCH; ++t) below += __builtin_popcount(_mm512_cmplt_epi32_mask(x[t], v));
        in_ext[below / 16] = (unsigned short)(in_ext[below / 16] | 1u << (below % 16));
    }
}
#endif

/* out[0 .. L+e-1] = row[0 .. L-1] (marks undone) merged with ext[0 .. e-1],
 * both ascending, no value in both; out >= row (the two may overlap), ext
 * apart. Written from the top, never below what is still to be read: with
 * AVX-512 16 at a time, each chunk's entries from ext expanded into their
 * lanes and the row's into the others; else one entry at a time. */
SPH__INLINE void sph__ns_merge_row(sph_idx *out, const sph_idx *row, sph_off L, const sph_idx *ext, sph_off e)
{
#if SPH__NS_COMPRESS
    unsigned short in_ext[16];      /* per chunk of 16 of out, the lanes from ext: rows of up to 128 and ext of up to 128 */
    const int short_row = L <= 128 && e <= 128;
    sph_off o = L + e, r = L, k = e, q = e > 0 && !short_row ? sph__ns_below16(row, L, ext[e - 1]) + e - 1 : -1;
    if (L <= 64 && e <= 128)
        sph__ns_ext_lanes(in_ext, row, L, ext, e, 4);
    else if (short_row)
        sph__ns_ext_lanes(in_ext, row, L, ext, e, 8);
    while (o > 0) { /* out[lo .. o-1], lo a multiple of 16; q: where ext[k-1] goes */
        const sph_off lo = (o - 1) / 16 * 16;
        const __mmask16 live = sph__ns_live16(o - lo);
        unsigned m = 0;
        int from_ext, from_row;
        __m512i d;
        if (short_row)
            m = in_ext[lo / 16];
        else
            for (; q >= lo; q = k > 0 ? sph__ns_below16(row, r, ext[k - 1]) + k - 1 : -1) m |= 1u << (q - lo), --k;
        from_ext = __builtin_popcount(m);
        from_row = (int)(o - lo) - from_ext;
        k -= short_row ? from_ext : 0;
        d = _mm512_maskz_loadu_epi32((__mmask16)((1u << from_row) - 1u), (const void *)(row + r - from_row));
        d = sph__ns_unmark16(_mm512_maskz_expand_epi32((__mmask16)(live & ~m), d));
        d = _mm512_mask_expand_epi32(
            d, (__mmask16)m, _mm512_maskz_loadu_epi32((__mmask16)((1u << from_ext) - 1u), (const void *)(ext + k)));
        _mm512_mask_storeu_epi32((void *)(out + lo), live, d);
        r -= from_row, o = lo;
    }
#else
    sph_idx *w = out + L + e;
    const sph_idx *r = row + L;
    while (e > 0) { /* the row's entries above ext's last, then it */
        const sph_idx v = ext[--e];
        for (; r > row && sph__ns_unmark(r[-1]) > v; --r) *--w = sph__ns_unmark(r[-1]);
        *--w = v;
    }
    sph__ns_up(w, r, r - row);
#endif
}

/* Completes the symmetric rows from the scan (sph__nsearch_sym_scan) when
 * index has room for the marks twice past the gather lists: gather rows one
 * after another from index[0] (row i len[i] entries, marks[i] of them
 * marked, G entries in all; its final segment offset[i] .. offset[i+1] - 1),
 * the marks in row order right after them, at[i] where E_i starts past the
 * final lists (from offset[n]). Each E_i is laid out ascending there (a
 * counting sort of the marks); then each row, last first, is merged with its
 * E_i from the back into its final segment, marks undone on the way (a row
 * only moves up, over rows already done; the marks lie below the final end,
 * E past it). */
SPH_API void sph__nsearch_sym_past(sph_idx n, const sph_off *offset, const sph_idx *len, const sph_idx *marks,
                                   sph_off *at, sph_idx *index, sph_off G)
{
    const sph_idx *P = index + G;
    sph_idx *E = index + offset[n], i, j, e;
    sph_off src = G;
    for (j = 0; j < n; ++j)
        for (e = 0; e < marks[j]; ++e) E[at[-1 - *P++]++] = j;
    for (i = n - 1; i >= 0; --i) { /* at[i]: where E_i ends */
        const sph_off x = offset[i + 1] - offset[i] - len[i]; /* |E_i| */
        src -= len[i];
        if (offset[i] != src || x != 0 || marks[i] != 0)
            sph__ns_merge_row(index + offset[i], index + src, len[i], E + at[i] - x, x);
    }
}

/* sph_nsearch_lists in symmetric mode from the gather lists (sph__nsearch_sym_ok
 * holds): the gather lists into index, marked, their marks counted per
 * source and kept in row order past them (sph__nsearch_sym_scan), the final
 * offsets from the row lengths; with room for the marks past the final
 * lists, completed in one pass (sph__nsearch_sym_past), else the gather rows
 * moved up to their final segments (last row first: a row only moves up,
 * over rows already moved), then completed in place
 * (sph__nsearch_sym_finish).
 * SPH_ESIZE, offsets complete, when index cannot hold the symmetric lists; when
 * it cannot hold even the gather ones, the offsets come from the direct
 * search (sph__nsearch_lists_ref). */
SPH_API int sph__nsearch_sym_lists(const sph_nsearch *g, sph_view xt, sph_idx n, sph_view ht, sph_real h,
                                   sph_real kappa, sph_off *offset, sph_idx *index, sph_off capacity, sph_off *pairs)
{
    sph_idx *len = g->sym, *marks = g->sym + g->n_padded, i, k;
    sph_off src, M, G0, *at = g->sym_at;
    int st, nb;
    st = sph__nsearch_lists_ref(g, xt, n, ht, h, kappa, SPH__NS_MARK, offset, index, capacity, pairs);
    if (st == SPH_ESIZE)
        return sph__nsearch_lists_ref(g, xt, n, ht, h, kappa, SPH_NSEARCH_SYMMETRIC, offset, index, capacity, pairs);
    if (st != SPH_OK) return st;
    for (i = 0; i < n; ++i) at[i] = 0, len[i] = (sph_idx)(offset[i + 1] - offset[i]);
    src = offset[n];
    nb = sph__nsearch_blocks(n, 64);
    M = nb > 1 ? sph__nsearch_sym_scan_blocks(n, offset, index, marks, at, index + src, capacity - src, nb)
               : sph__nsearch_sym_scan(n, len, index, marks, at, index + src, capacity - src);
    for (G0 = 0, i = 0; i < n; ++i) { /* at[i] from the count of E_i to where it starts past the final lists */
        const sph_off e = at[i];
        at[i] = offset[i] - G0;
        G0 += len[i];
        offset[i + 1] = offset[i] + len[i] + e;
    }
    *pairs = offset[n];
    if (offset[n] > capacity) return SPH_ESIZE;
    if (capacity - offset[n] >= M) { /* P at the gather lists' end, E past the final ones */
        sph__nsearch_sym_past(n, offset, len, marks, at, index, src);
        return SPH_OK;
    }
    for (i = n - 1; i >= 0; --i) { /* up: last first */
        src -= len[i];
        for (k = len[i] - 1; k >= 0; --k) index[offset[i] + k] = index[src + k];
        at[i] = offset[i + 1];
    }
    sph__nsearch_sym_finish(n, offset, len, marks, at, index);
    return SPH_OK;
}

/* Count and fill in one search per target (eq. (N1)/(N2)), as
 * sph__nsearch_lists_ref describes; in symmetric mode with varying per-source
 * h over the sources themselves, from the gather lists (sph__nsearch_sym_lists),
 * the same lists. */
SPH_API int sph_nsearch_lists(const sph_nsearch *g, sph_view xt, sph_idx n_targets, sph_view ht, sph_real h,
                              sph_real kappa, int mode, sph_off *offset, sph_idx *index, sph_off capacity,
                              sph_off *pairs)
{
    SPH__DISPATCH_TO(sph_nsearch_lists, (g, xt, n_targets, ht, h, kappa, mode, offset, index, capacity, pairs))
    int st = sph__nsearch_check(g, xt, n_targets, ht, h, kappa, mode);
    if (st != SPH_OK) return st;
    if (offset == NULL || pairs == NULL || (index == NULL && capacity > 0)) return SPH_ENULL;
    if (capacity < 0) return SPH_ECOUNT;
    if (sph__nsearch_sym_ok(g, xt, n_targets, ht, kappa, mode))
        return sph__nsearch_sym_lists(g, xt, n_targets, ht, h, kappa, offset, index, capacity, pairs);
    return sph__nsearch_lists_ref(g, xt, n_targets, ht, h, kappa, mode, offset, index, capacity, pairs);
}

/* Statistics of one search without storing it (docs/neighbours.md,
 * "Measured"): pairs found by (N1)/(N2), candidate distance checks made and,
 * when fill != NULL, the grid's fill ratio: occupied cells / cells (1 for
 * one source per cell; a small value means a mostly empty grid, e.g. around
 * an escaped particle: docs/neighbours.md, "Limits"). */
SPH_API int sph_nsearch_stats(const sph_nsearch *g, sph_view xt, sph_idx n_targets, sph_view ht,
                              sph_real h, sph_real kappa, int mode, sph_off *pairs, sph_off *candidates,
                              sph_real *fill)
{
    SPH__DISPATCH_TO(sph_nsearch_stats, (g, xt, n_targets, ht, h, kappa, mode, pairs, candidates, fill))
    sph_off stats[3];
    int st = sph__nsearch_check(g, xt, n_targets, ht, h, kappa, mode);
    if (st != SPH_OK) return st;
    if (pairs == NULL || candidates == NULL) return SPH_ENULL;
    sph__nsearch_run(g, xt, n_targets, ht, h, kappa, mode, NULL, NULL, NULL, stats);
    *pairs = stats[0];
    *candidates = stats[1];
    if (fill != NULL) *fill = (sph_real)((double)g->n_occupied / (double)g->n_cells);
    return SPH_OK;
}

/* The sph_neighbours view (CSR, section 4) of arrays filled by sph_nsearch_count / _fill,
 * with a copy of the grid's box (box_known; an open search: no periodic axis) for the
 * operators' minimum image (O0). Box unknown when g is NULL or not built. */
SPH_API sph_neighbours sph_nsearch_list(const sph_nsearch *g, sph_idx n_targets, const sph_off *offset,
                                        const sph_idx *index)
{
    sph_neighbours l = SPH_NEIGHBOURS_INIT(n_targets, g != NULL ? g->n_sources : 0, offset, index);
    if (g != NULL && g->dim >= 1 && g->dim <= 3) {
        l.box = g->box;
        l.box_known = SPH_BOX_KNOWN;
    }
    return l;
}

/* (N8) Lists kept over steps (a Verlet skin). A list (targets = sources,
 * gather or symmetric) searched at radii kappa hl_i from positions x0
 * holds, at positions x, every j with r_ij < kappa h_i while
 * kappa h_i + d_i + d_max <= kappa hl_i, d_i = |x_i - x0_i| (minimum image)
 * and d_max the largest d_i: r_ij changed by at most d_i + d_j since the
 * search (in a symmetric list the larger of h_i, h_j decides, and the same
 * bound holds for it). Writes h_keep_i = hl_i (1 - 64 eps) - (d_i + d_max +
 * 64 eps X) / kappa, X the largest |coordinate| of x and x0 (the rounding
 * of r^2 and of the differences allowed for), the radii the list still
 * serves (ctx.h_list of sph_h_solve), and *n_stale, how many h_i exceed their
 * h_keep_i: 0, keep the list; else search again (docs/neighbours.md, "Lists
 * kept over steps"). h_list, h: one component (stride 0: one value for
 * all); box NULL takes the list's, a different one is SPH_EBOX. Returns
 * SPH_ENULL, SPH_EDIM, SPH_ECOUNT (n_sources != n_targets), SPH_ERANGE
 * (kappa not positive and finite), SPH_EBOX, SPH_EBOXLEN, SPH_EH (an h or
 * h_list not usable), SPH_ENONFINITE (a position NaN or Inf); else SPH_OK.
 * Parallel under OpenMP for n >= 4096; the same for any thread count. */
SPH_API int sph_nsearch_skin(const sph_neighbours *list, const sph_box *box, int dim, sph_view x, sph_view x0,
                             sph_view h_list, sph_real kappa, sph_view h, sph_out h_keep, sph_idx *n_stale)
{
    SPH__DISPATCH_TO(sph_nsearch_skin, (list, box, dim, x, x0, h_list, kappa, h, h_keep, n_stale))
    const sph_box *bx;
    const sph_real eps = 64 * sph__nsearch_eps();
    sph_real dmax = 0, X = 0;
    sph_idx i, n, stale = 0;
    int a, st;
    if (n_stale != NULL) *n_stale = 0;
    if (list == NULL || n_stale == NULL) return SPH_ENULL;
    if (dim < 1 || dim > 3) return SPH_EDIM;
    n = list->n_targets;
    if (n < 0 || list->n_sources != n) return SPH_ECOUNT;
    if (!(kappa > 0 && kappa <= SPH__REAL_MAX)) return SPH_ERANGE;
    if ((st = sph__box_of(box, list, dim, &bx)) != SPH_OK) return st;
    if (n == 0) return SPH_OK;
    if (h_list.p[0] == NULL || h.p[0] == NULL || h_keep.p[0] == NULL) return SPH_ENULL;
    for (a = 0; a < dim; ++a)
        if (x.p[a] == NULL || x0.p[a] == NULL) return SPH_ENULL;
    for (i = 0; i < n; ++i) {
        if (!sph__h_ok(sph__ns_at(h_list, 0, i), dim) || !sph__h_ok(sph__ns_at(h, 0, i), dim)) return SPH_EH;
        for (a = 0; a < dim; ++a)
            if (!sph__finite(sph__ns_at(x, a, i)) || !sph__finite(sph__ns_at(x0, a, i))) return SPH_ENONFINITE;
    }
#ifdef _OPENMP
#pragma omp parallel for schedule(static) reduction(max : dmax, X) if (n >= 4096)
#endif
    for (i = 0; i < n; ++i) { /* d_i into h_keep until d_max is known */
        sph_real d2 = 0, d;
        int b;
        for (b = 0; b < dim; ++b) {
            const sph_real xa = sph__ns_at(x, b, i), ya = sph__ns_at(x0, b, i);
            X = xa > X ? xa : -xa > X ? -xa : X;
            X = ya > X ? ya : -ya > X ? -ya : X;
            d = sph_box_delta(bx, b, xa - ya);
            d2 += d * d;
        }
        d = sph__sqrt(d2);
        h_keep.p[0][(ptrdiff_t)i * h_keep.stride] = d;
        dmax = d > dmax ? d : dmax;
    }
    dmax += eps * X;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) reduction(+ : stale) if (n >= 4096)
#endif
    for (i = 0; i < n; ++i) {
        sph_real *k = h_keep.p[0] + (ptrdiff_t)i * h_keep.stride;
        *k = sph__ns_at(h_list, 0, i) * (1 - eps) - (*k + dmax) / kappa;
        stale += sph__ns_at(h, 0, i) > *k;
    }
    *n_stale = stale;
    return SPH_OK;
}

/* Row i of sph_nsearch_prune: the j of the row with r_ij^2 < R^2 (as sph__nsearch_in decides: the minimum
 * image only where |dx_a| exceeds q_a = 0.49 L_a, below which it is dx_a itself), written to index[k..]
 * when index is not NULL; returns how many. */
SPH__INLINE sph_off sph__prune_row(const sph_neighbours *list, const sph_box *bx, const sph_real *q, int dim,
                                   sph_view x, sph_view h, sph_real kappa, int symmetric, sph_idx i, sph_idx *index)
{
    const sph_real hi = sph__ns_at(h, 0, i);
    sph_real xi[3] = {0, 0, 0};
    sph_off k = 0, p;
    int a;
    for (a = 0; a < dim; ++a) xi[a] = sph__ns_at(x, a, i);
    for (p = list->offset[i]; p < list->offset[i + 1]; ++p) {
        const sph_idx j = list->index[p];
        const sph_real hj = sph__ns_at(h, 0, j), R = kappa * (symmetric && hj > hi ? hj : hi);
        sph_real r2 = 0;
        for (a = 0; a < dim; ++a) {
            sph_real d = xi[a] - sph__ns_at(x, a, j);
            if ((d < 0 ? -d : d) > q[a]) d = sph_box_delta(bx, a, d);
            r2 += sph__mul_rn(d, d); /* the criterion's r^2 (sph__nsearch_r2) */
        }
        if (r2 < R * R) {
            if (index != NULL) index[k] = j;
            ++k;
        }
    }
    return k;
}

/* (N1)/(N2) on a kept list: row i of list keeps, in its order, the j with
 * r_ij^2 < R^2, R = kappa h_i (SPH_NSEARCH_GATHER) or kappa max(h_i, h_j)
 * (SPH_NSEARCH_SYMMETRIC), r_ij^2 and R^2 as sph_nsearch_fill computes them:
 * a list kept with sph_nsearch_skin comes out as a fresh search at h would
 * (a symmetric list stays symmetric and ascending). Writes offset [n + 1]
 * and, when cap is at least the *pairs kept, index [cap] (else SPH_ESIZE,
 * offset complete); *out (optional) is their sph_neighbours view with the
 * box. offset and index must not be the list's own arrays. box as
 * sph_nsearch_skin. Returns SPH_ENULL, SPH_EDIM, SPH_ECOUNT, SPH_ERANGE,
 * SPH_EOPTION (mode), SPH_EBOX, SPH_EBOXLEN, SPH_EOFFSET, SPH_EINDEX, SPH_EH,
 * SPH_ENONFINITE, SPH_ESIZE; else SPH_OK. With OpenMP and n >= 4096, one
 * pass over chunks of rows in parallel, each at its rows' own positions,
 * then moved down (when cap holds the whole list; else a counting and a
 * filling pass); on one thread one pass. The same for any thread count. */
SPH_API int sph_nsearch_prune(const sph_neighbours *list, const sph_box *box, int dim, sph_view x, sph_view h,
                              sph_real kappa, int mode, sph_off *offset, sph_idx *index, sph_off cap, sph_off *pairs,
                              sph_neighbours *out)
{
    SPH__DISPATCH_TO(sph_nsearch_prune, (list, box, dim, x, h, kappa, mode, offset, index, cap, pairs, out))
    const sph_box *bx;
    sph_real q[3];
    sph_idx i, n;
    int a, st, threads = 1;
    if (pairs != NULL) *pairs = 0;
    if (list == NULL || list->offset == NULL || offset == NULL) return SPH_ENULL;
    if (dim < 1 || dim > 3) return SPH_EDIM;
    n = list->n_targets;
    if (n < 0 || list->n_sources != n || cap < 0) return SPH_ECOUNT;
    if (!(kappa > 0 && kappa <= SPH__REAL_MAX)) return SPH_ERANGE;
    if (mode != SPH_NSEARCH_GATHER && mode != SPH_NSEARCH_SYMMETRIC) return SPH_EOPTION;
    if ((st = sph__box_of(box, list, dim, &bx)) != SPH_OK) return st;
    if ((st = sph_neighbours_check(list)) != SPH_OK) return st;
    if (n > 0 && h.p[0] == NULL) return SPH_ENULL;
    for (a = 0; a < dim; ++a)
        if (n > 0 && x.p[a] == NULL) return SPH_ENULL;
    if ((st = sph__hx_check(x, h, n, dim)) != SPH_OK) return st;
    for (a = 0; a < 3; ++a) q[a] = bx != NULL && bx->periodic[a] ? (sph_real)0.49 * bx->length[a] : SPH__REAL_MAX;
#ifdef _OPENMP
    threads = n >= 4096 ? omp_get_max_threads() : 1;
#endif
    offset[0] = 0;
    if (threads > 1 && index != NULL && cap >= list->offset[n]) { /* chunks of rows in parallel, each written at
        its rows' input positions (a pruned row is never longer), then moved down in order */
        const int C = 4 * threads;
        sph_off next[SPH__SHARES_MAX * SPH_SHARE_PAD];
        sph_share sh;
        int c;
        sph_share_init(&sh, next, SPH__SHARES, C, 1);
#ifdef _OPENMP
#pragma omp parallel
#endif
        { /* each thread its own chunks first (the rows of its static share), then the others' (sph_share_next) */
            sph_idx c0, c1, cc;
            int u = 0;
            while (sph_share_next(&sh, SPH__THREAD, &u, &c0, &c1))
                for (cc = c0; cc < c1; ++cc) {
                    const sph_idx lo = (sph_idx)((double)n * cc / C), hi = (sph_idx)((double)n * (cc + 1) / C);
                    sph_off k = list->offset[lo];
                    sph_idx r;
                    for (r = lo; r < hi; ++r) {
                        offset[r + 1] = sph__prune_row(list, bx, q, dim, x, h, kappa, mode, r, index + k);
                        k += offset[r + 1];
                    }
                }
        }
        for (i = 0; i < n; ++i) offset[i + 1] += offset[i];
        for (c = 1; c < C; ++c) { /* chunk 0 is in place; the others move down, front first (they may overlap) */
            const sph_idx lo = (sph_idx)((double)n * c / C), hi = (sph_idx)((double)n * (c + 1) / C);
            const sph_off from = list->offset[lo] - offset[lo];
            sph_off o;
            if (from > 0)
                for (o = offset[lo]; o < offset[hi]; ++o) index[o] = index[o + from];
        }
        if (pairs != NULL) *pairs = offset[n];
    } else if (threads == 1) { /* one pass: rows written while they fit */
        for (i = 0; i < n; ++i)
            offset[i + 1] = offset[i] + sph__prune_row(list, bx, q, dim, x, h, kappa, mode, i,
                                                      index != NULL && cap - offset[i] >= list->offset[i + 1] -
                                                      list->offset[i] ? index + offset[i] : NULL);
        if (pairs != NULL) *pairs = offset[n];
        if (cap < offset[n]) return SPH_ESIZE;
        if (offset[n] > 0 && index == NULL) return SPH_ENULL;
        for (i = 0; i < n; ++i) /* rows that might not have fitted were counted only: write them now */
            if (!(cap - offset[i] >= list->offset[i + 1] - list->offset[i]))
                sph__prune_row(list, bx, q, dim, x, h, kappa, mode, i, index + offset[i]);
    } else { /* threads, an index shorter than the list: a counting pass, then a filling pass */
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 256)
#endif
        for (i = 0; i < n; ++i) offset[i + 1] = sph__prune_row(list, bx, q, dim, x, h, kappa, mode, i, NULL);
        for (i = 0; i < n; ++i) offset[i + 1] += offset[i];
        if (pairs != NULL) *pairs = offset[n];
        if (cap < offset[n]) return SPH_ESIZE;
        if (offset[n] > 0 && index == NULL) return SPH_ENULL;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 256)
#endif
        for (i = 0; i < n; ++i) sph__prune_row(list, bx, q, dim, x, h, kappa, mode, i, index + offset[i]);
    }
    if (out != NULL) {
        sph_neighbours l = SPH_NEIGHBOURS_INIT(n, n, offset, index);
        if (bx != NULL) l.box = *bx, l.box_known = SPH_BOX_KNOWN;
        *out = l;
    }
    return SPH_OK;
}

/* Locality permutation of the sources, eq. (N5): perm[new] = old, sources
 * ordered by cell (and by index within a cell). */
SPH_API int sph_nsearch_permutation(const sph_nsearch *g, sph_idx *perm)
{
    sph_idx k;
    if (g == NULL || (perm == NULL && g->n_sources > 0)) return SPH_ENULL;
    if (g->dim < 1 || g->dim > 3) return SPH_ENOGRID;
    for (k = 0; k < g->n_sources; ++k) perm[k] = g->order[k];
    return SPH_OK;
}

/* Checks that perm[0..n-1] is a permutation of 0..n-1; mark[n] is scratch. */
SPH_API int sph__ns_check_perm(const sph_idx *perm, sph_idx n, sph_idx *mark)
{
    sph_idx k;
    for (k = 0; k < n; ++k) mark[k] = -1;
    for (k = 0; k < n; ++k) {
        if (perm[k] < 0 || perm[k] >= n || mark[perm[k]] >= 0) return SPH_EINDEX;
        mark[perm[k]] = k;
    }
    return SPH_OK;
}

/* Inverse permutation, eq. (N6): inv[perm[k]] = k. SPH_EINDEX (inv
 * unspecified) when perm is not a permutation of 0..n-1. */
SPH_API int sph_permutation_invert(const sph_idx *perm, sph_idx n, sph_idx *inv)
{
    if (n < 0) return SPH_ECOUNT;
    if (n > 0 && (perm == NULL || inv == NULL)) return SPH_ENULL;
    return sph__ns_check_perm(perm, n, inv);
}

/* Applies a permutation to a field, eq. (N5): component a of out[k] =
 * component a of in[perm[k]], for ncomp (1..3) components of n particles.
 * out must not overlap in. SPH_EINDEX (nothing written) for an index outside
 * 0..n-1. */
SPH_API int sph_permute(sph_view in, int ncomp, sph_idx n, const sph_idx *perm, sph_out out)
{
    SPH__DISPATCH_TO(sph_permute, (in, ncomp, n, perm, out))
    sph_idx k;
    int a;
    if (ncomp < 1 || ncomp > 3) return SPH_ERANGE;
    if (n < 0) return SPH_ECOUNT;
    if (n == 0) return SPH_OK;
    if (perm == NULL) return SPH_ENULL;
    for (a = 0; a < ncomp; ++a)
        if (in.p[a] == NULL || out.p[a] == NULL) return SPH_ENULL;
    for (k = 0; k < n; ++k)
        if (perm[k] < 0 || perm[k] >= n) return SPH_EINDEX;
    for (a = 0; a < ncomp; ++a)
        for (k = 0; k < n; ++k) out.p[a][(ptrdiff_t)k * out.stride] = sph__ns_at(in, a, perm[k]);
    return SPH_OK;
}


#endif /* section 7 */

#if !defined(SPH_NO_SOLVER) /* section 8 */

/* ======================================================================== */
/* 8. Solver terms                                                           */
/* ======================================================================== */

/* The dissipative terms, boundary and time-step rules that a weakly
 * compressible or compressible SPH solver adds to the operators of section 6
 * (docs/solver.md, equations (S1)-(S17)). As in section 5, pair terms come
 * first (usable under SPH_ONLY_PAIRS and in device code), then the array
 * operators over a CSR list and a context (section 6). Conventions as in
 * section 5: dx = x_ij = x_i - x_j, dv = v_ij = v_i - v_j, F = F_ij at the
 * pair's h, grad_i W_ij = F dx; rho_ij = (rho_i + rho_j) / 2. The pair terms
 * that divide return 0 instead of a division by zero (documented per term). */

/* Monaghan's regularisation of 1 / r^2: eta^2 = 0.01 h^2 (Monaghan 1992;
 * Morris, Fox & Zhu 1997). */
#define SPH__ETA2 SPH__C(0.01)

/* a . b over dim (1..3) components. */
SPH__INLINE sph_real sph__dot(int dim, const sph_real *a, const sph_real *b)
{
    sph_real s = 0;
    int k;
    for (k = 0; k < dim && k < 3; ++k) s += a[k] * b[k];
    return s;
}

/* (S1) Monaghan (1992) artificial viscosity Pi_ij = (-alpha c_ij mu_ij +
 * beta mu_ij^2) / rho_ij, mu_ij = h v_ij.x_ij / (r^2 + 0.01 h^2), for
 * approaching pairs (v_ij.x_ij < 0); 0 for receding ones, and 0 where
 * rho_ij <= 0 or r^2 + 0.01 h^2 is 0. h and c_ij: the pair's (means). */
SPH_API sph_real sph_pair_av_monaghan(int dim, sph_real alpha, sph_real beta, sph_real h, sph_real c_ij,
                                      sph_real rho_ij, const sph_real *dx, const sph_real *dv)
{
    const sph_real vr = sph__dot(dim, dv, dx), den = sph__dot(dim, dx, dx) + SPH__ETA2 * h * h;
    sph_real mu;
    if (!(vr < 0 && den > 0 && rho_ij > 0)) return 0;
    mu = h * vr / den;
    return (beta * mu - alpha * c_ij) * mu / rho_ij;
}

/* w_ij = v_ij . x_ij / r for an approaching pair, else 0 (no division when
 * the pair is not approaching or r^2 is 0). */
SPH__INLINE sph_real sph__w_approach(int dim, const sph_real *dx, const sph_real *dv)
{
    const sph_real vr = sph__dot(dim, dv, dx), r2 = sph__dot(dim, dx, dx);
    return vr < 0 && r2 > 0 ? vr / sph__sqrt(r2) : 0;
}

/* (S2) signal velocity v_sig,ij = c_i + c_j - beta w_ij, w_ij = min(0,
 * v_ij . x_ij / r) (Monaghan 1997; Price 2012): the speed of the
 * signal-velocity viscosity (S3), and of the CFL limit (S9) with C_cfl = 0.5
 * (it counts two sound speeds; see sph_dt_coef). */
SPH_API sph_real sph_pair_signal_velocity(int dim, sph_real beta, sph_real c_i, sph_real c_j, const sph_real *dx,
                                          const sph_real *dv)
{
    return c_i + c_j - beta * sph__w_approach(dim, dx, dv);
}

/* (S3) signal-velocity artificial viscosity Pi_ij = -(alpha / 2) v_sig,ij
 * w_ij / rho_ij (Monaghan 1997; Price 2012, eqs. 101-103; SWIFT's minimal SPH
 * with beta = 3); 0 for receding pairs and where rho_ij <= 0. */
SPH_API sph_real sph_pair_av_signal(int dim, sph_real alpha, sph_real beta, sph_real c_i, sph_real c_j,
                                    sph_real rho_ij, const sph_real *dx, const sph_real *dv)
{
    const sph_real w = sph__w_approach(dim, dx, dv);
    if (!(w < 0 && rho_ij > 0)) return 0;
    return -(alpha / 2) * (c_i + c_j - beta * w) * w / rho_ij;
}

/* The artificial viscosity of sph_artificial_viscosity: (S1) or (S3), and
 * its coefficients (usual values: Monaghan alpha = 1, beta = 2 for shocks,
 * alpha ~ 0.01-0.1, beta = 0 for weakly compressible flow; signal velocity
 * alpha = 1, beta = 3 as SWIFT, or beta = 2 as Price 2012). A switch gives
 * alpha per particle, and the Balsara factor (S13) limits it: the pair then
 * takes alpha_ij of (S14). Fill with sph_av_init, then set the views a scene
 * has. */
#if SPH__FIRST
typedef enum { SPH_AV_MONAGHAN = 0, SPH_AV_SIGNAL = 1 } sph_av_form;
typedef struct {
    sph_av_form form;
    sph_real alpha, beta;
    sph_view alpha_source;   /* per-particle alpha of the sources; absent: alpha for every particle */
    sph_view alpha_target;   /* of the targets, when they are not the sources */
    sph_view balsara_source; /* per-particle Balsara factor B (S13) of the sources; absent: B = 1 */
    sph_view balsara_target; /* of the targets, when they are not the sources */
} sph_av;
#endif /* SPH__FIRST */

/* The viscosity form with one alpha and beta for every particle (no view). */
SPH_API sph_av sph_av_init(sph_av_form form, sph_real alpha, sph_real beta)
{
    sph_av av;
    av.form = form;
    av.alpha = alpha;
    av.beta = beta;
    av.alpha_source = av.alpha_target = av.balsara_source = av.balsara_target = sph_view_soa(NULL, NULL, NULL);
    return av;
}

/* (S14) the pair's alpha_ij = (alpha_i + alpha_j) / 2 (B_i + B_j) / 2 (Borrow
 * et al. 2022, eq. 20): B = 1 without the Balsara limiter, and alpha_ij =
 * alpha bit for bit where alpha_i = alpha_j = alpha. */
SPH_API sph_real sph_pair_av_alpha(sph_real alpha_i, sph_real alpha_j, sph_real B_i, sph_real B_j)
{
    return (alpha_i + alpha_j) / 2 * ((B_i + B_j) / 2);
}

/* (S4) applies Pi_ij to target i: acc += -m_j Pi_ij F dx (momentum) and
 * returns du_i/dt's share (1/2) m_j Pi_ij F v_ij . x_ij (thermal energy):
 * together they conserve momentum and total energy pair by pair, and the
 * heating is >= 0 for Pi_ij >= 0 (F <= 0). */
SPH_API sph_real sph_pair_av_apply(int dim, sph_real m_j, sph_real Pi_ij, sph_real F, const sph_real *dx,
                                   const sph_real *dv, sph_real *acc)
{
    const sph_real c = m_j * Pi_ij * F;
    sph__axpy(dim, -c, dx, acc);
    return c * sph__dot(dim, dv, dx) / 2;
}

/* (S5) Morris, Fox & Zhu (1997) viscosity, (1/rho div(mu grad) v)_i: acc +=
 * m_j (mu_i + mu_j) / (rho_i rho_j) F r^2 / (r^2 + 0.01 h^2) v_ij (dynamic
 * viscosities mu, dv = v_ij). Nothing added where rho_i rho_j <= 0 or r^2 +
 * 0.01 h^2 is 0. */
SPH_API void sph_pair_viscosity(int dim, sph_real m_j, sph_real mu_i, sph_real mu_j, sph_real rho_i, sph_real rho_j,
                                sph_real h, sph_real F, const sph_real *dx, const sph_real *dv, sph_real *acc)
{
    const sph_real r2 = sph__dot(dim, dx, dx), den = r2 + SPH__ETA2 * h * h, rr = rho_i * rho_j;
    if (!(den > 0 && rr > 0)) return;
    sph__axpy(dim, m_j * (mu_i + mu_j) / rr * F * (r2 / den), dv, acc);
}

/* (S6) density diffusion (delta-SPH) of target i, without its factor
 * delta h c0: V_j F [2 (rho_i - rho_j) - (g_i + g_j) . x_ij], g the
 * renormalised density gradients (Antuono et al. 2010); g_i or g_j NULL:
 * 2 V_j (rho_i - rho_j) F (Molteni & Colagrossi 2009). */
SPH_API sph_real sph_pair_density_diffusion(int dim, sph_real V_j, sph_real rho_i, sph_real rho_j, const sph_real *g_i,
                                            const sph_real *g_j, sph_real F, const sph_real *dx)
{
    sph_real s = 2 * (rho_i - rho_j);
    int a;
    for (a = 0; g_i != NULL && g_j != NULL && a < dim && a < 3; ++a) s -= (g_i[a] + g_j[a]) * dx[a];
    return V_j * F * s;
}

/* (S8) one fluid source f of wall particle w (Adami, Hu & Adams 2012): adds
 * W_wf to sum[0], (p_f + rho_f g_eff . x_wf) W_wf to sum[1] and v_f W_wf to
 * sum[2..1+dim] (dx = x_wf = x_w - x_f, g_eff = g - a_w); sph_wall_end turns
 * the sums into the wall's pressure and velocity. */
SPH_API void sph_pair_wall(int dim, sph_real W, sph_real p_f, sph_real rho_f, const sph_real *v_f,
                           const sph_real *g_eff, const sph_real *dx, sph_real *sum)
{
    int a;
    sum[0] += W;
    sum[1] += (p_f + rho_f * sph__dot(dim, g_eff, dx)) * W;
    for (a = 0; a < dim && a < 3; ++a) sum[2 + a] += v_f[a] * W;
}

/* Wall velocity models of (S8): no-slip (the wall's velocity extrapolated
 * through the wall, 2 v_wall - v~) or free-slip (v~: no velocity jump for
 * the viscous term to act on). */
#if SPH__FIRST
typedef enum { SPH_WALL_NOSLIP = 0, SPH_WALL_FREESLIP = 1 } sph_wall_slip;
#endif /* SPH__FIRST */

/* (S8) wall pressure p_w = sum[1] / sum[0] and velocity v_w = 2 v_wall - v~
 * (no-slip) or v~ (free-slip), v~ = sum[2..] / sum[0]; returns 0, and p_w =
 * 0, v_w = v_wall (NULL: 0), for a wall with no fluid in reach (sum[0] <= 0,
 * or so small that 1 / sum[0] overflows), else 1. */
SPH_API int sph_wall_end(int dim, sph_wall_slip slip, const sph_real *sum, const sph_real *v_wall, sph_real *p_w,
                         sph_real *v_w)
{
    const sph_real inv = sum[0] > 0 ? 1 / sum[0] : 0;
    const int ok = inv > 0 && inv <= SPH__REAL_MAX; /* a denormal sum: as no fluid */
    int a;
    *p_w = ok ? sum[1] * inv : 0;
    for (a = 0; a < dim && a < 3; ++a) {
        const sph_real vwall = v_wall != NULL ? v_wall[a] : 0, vt = ok ? sum[2 + a] * inv : 0;
        v_w[a] = !ok ? vwall : slip == SPH_WALL_NOSLIP ? 2 * vwall - vt : vt;
    }
    return ok;
}

/* One list generates the reasons of the time-step limit (S9)-(S12), as
 * sph_dt_limit and sph_time_step return them, and their names
 * (sph_dt_reason_name): X(name, value, identifier, limit). */
#define SPH_DT_REASON_LIST(X) \
    X(SPH_DT_NONE, 0, "none", "no limit applied (every rate 0)") \
    X(SPH_DT_CFL, 1, "cfl", "(S9) C_cfl h / v_sig") \
    X(SPH_DT_FORCE, 2, "force", "(S10) C_force sqrt(h / |a|)") \
    X(SPH_DT_VISCOUS, 3, "viscous", "(S11) C_visc h^2 / nu") \
    X(SPH_DT_DIFFUSION, 4, "diffusion", "(S12) C_diff h^2 / D") \
    X(SPH_DT_INVALID, -1, "invalid", "h not positive and finite, or a rate negative or not finite")

#if SPH__FIRST
typedef enum {
#define SPH__DT_REASON_ENUM(name, value, id, limit) name = value,
    SPH_DT_REASON_LIST(SPH__DT_REASON_ENUM)
#undef SPH__DT_REASON_ENUM
} sph_dt_reason;
#endif /* SPH__FIRST */

/* The identifier of a time-step reason ("cfl", "force", ...) for a log
 * line; "unknown" for a value that is no reason; never NULL. */
SPH_API const char *sph_dt_reason_name(int reason)
{
    switch (reason) {
#define SPH__DT_REASON_CASE(name, value, id, limit) \
    case name: return id;
        SPH_DT_REASON_LIST(SPH__DT_REASON_CASE)
#undef SPH__DT_REASON_CASE
    default: return "unknown";
    }
}

/* Coefficients of (S9)-(S12). sph_dt_coef_default() gives C_force = 0.25
 * (Monaghan 1992), C_visc = 0.125 (Morris, Fox & Zhu 1997), C_diff = 0.125
 * (the same bound for any diffusivity) and C_cfl = 0.25 for a one-particle
 * speed, v_sig = c_i + |v_i|: dt = 0.25 h / (c + |v|) (Morris et al. 1997),
 * the examples' rule. The pair signal velocity (S2) that
 * sph_artificial_viscosity writes counts both sound speeds (2 c at rest):
 * give it C_cfl = 0.5 for the same step (0.25 would halve it).
 * docs/solver.md, "Time step". */
#if SPH__FIRST
typedef struct {
    sph_real cfl, force, viscous, diffusion;
} sph_dt_coef;
#endif /* SPH__FIRST */

SPH_API sph_dt_coef sph_dt_coef_default(void)
{
    sph_dt_coef k;
    k.cfl = SPH__C(0.25);
    k.force = SPH__C(0.25);
    k.viscous = SPH__C(0.125);
    k.diffusion = SPH__C(0.125);
    return k;
}

/* (S9)-(S12) the time step of one particle: the smallest of C_cfl h / vsig,
 * C_force sqrt(h / amag), C_visc h^2 / nu and C_diff h^2 / D over the rates
 * that are > 0, with the limiting one in *reason (may be NULL). SPH__REAL_MAX
 * and SPH_DT_NONE when every rate is 0; 0 and SPH_DT_INVALID for h not
 * positive and finite or a rate negative or not finite. */
SPH_API sph_real sph_dt_limit(const sph_dt_coef *k, sph_real h, sph_real vsig, sph_real amag, sph_real nu, sph_real D,
                              int *reason)
{
    const sph_real rate[4] = {vsig, amag, nu, D};
    sph_real dt = SPH__REAL_MAX;
    int why = SPH_DT_NONE, r;
    for (r = 0; r < 4; ++r)
        if (!(rate[r] >= 0 && rate[r] <= SPH__REAL_MAX)) why = SPH_DT_INVALID;
    if (k == NULL || !(h > 0 && h <= SPH__REAL_MAX)) why = SPH_DT_INVALID;
    for (r = 0; why != SPH_DT_INVALID && r < 4; ++r) {
        sph_real t;
        if (!(rate[r] > 0)) continue;
        t = r == 0 ? k->cfl * h / rate[0]
            : r == 1 ? k->force * sph__sqrt(h / rate[1])
            : (r == 2 ? k->viscous : k->diffusion) * h * (h / rate[r]);
        if (t < dt) dt = t, why = SPH_DT_CFL + r;
    }
    if (reason != NULL) *reason = why;
    return why == SPH_DT_INVALID ? 0 : dt;
}

/* ---- viscosity and conductivity switches (S13)-(S17), per particle ---- */
/* A solver calls them once per particle and step, after the sums of div v,
 * |curl v| and lap u (sph_divergence, sph_curl, sph_laplacian, or its own
 * loop), and gives the alphas to the next force loop (sph_av's views, or
 * sph_pair_av_alpha in its own loop). Plain arithmetic, as the pair terms:
 * no status; the fallbacks are documented per function. docs/solver.md,
 * "Viscosity and conductivity switches". */

/* The parameters of the switches (S15)-(S17). sph_switch_default() gives
 * SPHENIX's (Borrow et al. 2022; SWIFT's src/hydro/SPHENIX and its
 * documentation): alpha in [0, 2], ell = 0.25, alpha_D in [0, 1], beta_D =
 * 1. For (S15) examples/sod_shock.c takes ell = 0.1 (its first scheme: alpha
 * in [0.1, 1]). */
#if SPH__FIRST
typedef struct {
    sph_real alpha_min, alpha_max;  /* bounds of the viscosity's alpha */
    sph_real length;                /* ell: alpha decays at the rate ell c / H (S16), ell c / h (S15) */
    sph_real alpha_d_min, alpha_d_max; /* bounds of the conductivity's alpha_D (S17) */
    sph_real beta_d;                /* beta_D: the source coefficient of (S17) */
} sph_switch;
#endif /* SPH__FIRST */

SPH_API sph_switch sph_switch_default(void)
{
    sph_switch s;
    s.alpha_min = 0;
    s.alpha_max = 2;
    s.length = SPH__C(0.25);
    s.alpha_d_min = 0;
    s.alpha_d_max = 1;
    s.beta_d = 1;
    return s;
}

/* (S13) Balsara (1995) factor B = |div v| / (|div v| + |curl v| + 1e-4 c / h)
 * in [0, 1]: near 1 in compression, near 0 in shear; 0 for c < 0, h <= 0 and
 * where the denominator is not positive and finite (no flow and c = 0, a NaN). */
SPH_API sph_real sph_switch_balsara(sph_real div_v, sph_real curl_v, sph_real c, sph_real h)
{
    const sph_real d = div_v > 0 ? div_v : 0 - div_v, w = curl_v > 0 ? curl_v : 0 - curl_v;
    const sph_real den = d + w + SPH__C(1e-4) * c / h;
    return c >= 0 && h > 0 && den > 0 && den <= SPH__REAL_MAX ? d / den : 0;
}

/* (S15) Morris & Monaghan (1997) switch with the source of Rosswog et al.
 * (2000): d alpha / dt = -(alpha - alpha_min) ell c / h + max(-div v, 0)
 * (alpha_max - alpha), for the solver's integrator (then clamp alpha to
 * [alpha_min, alpha_max]). 0 for s NULL, h not positive and finite, or a
 * rate that is not finite (a NaN, an overflow). */
SPH_API sph_real sph_switch_mm97(const sph_switch *s, sph_real alpha, sph_real div_v, sph_real c, sph_real h)
{
    const sph_real src = div_v < 0 ? -div_v : 0;
    sph_real rate;
    if (s == NULL || !(h > 0 && h <= SPH__REAL_MAX)) return 0;
    rate = -(alpha - s->alpha_min) * s->length * c / h + src * (s->alpha_max - alpha);
    return sph__finite(rate) ? rate : 0;
}

/* (S16) SPHENIX viscosity switch (Borrow et al. 2022, eqs. 18, 19, 21; after
 * Cullen & Dehnen 2010): alpha_loc = alpha_max S / (c^2 + S), S = H^2
 * max(0, -d(div v)/dt) where div v < 0; the new alpha is alpha_loc where that
 * is larger, else (alpha + r alpha_loc) / (1 + r), r = ell dt c / H (the decay
 * to alpha_loc, implicit: stable at any dt); then clamped to [alpha_min,
 * alpha_max]. H = kappa h, the kernel's support radius; ddiv_v_dt, e.g.
 * (div v - div v of the last step) / dt. No source where S is 0, no decay for
 * dt or H not positive; s NULL returns alpha; a NaN alpha gives alpha_max. */
SPH_API sph_real sph_switch_sphenix(const sph_switch *s, sph_real alpha, sph_real div_v, sph_real ddiv_v_dt,
                                    sph_real c, sph_real H, sph_real dt)
{
    sph_real S, loc, r, a;
    if (s == NULL) return alpha;
    S = div_v < 0 && ddiv_v_dt < 0 ? -H * H * ddiv_v_dt : 0;
    loc = S > 0 ? s->alpha_max * S / (c * c + S) : 0;
    r = dt > 0 && H > 0 ? dt * s->length * c / H : 0;
    a = loc > alpha ? loc : (alpha + loc * r) / (1 + r);
    a = a < s->alpha_max ? a : s->alpha_max;
    return a > s->alpha_min ? a : s->alpha_min;
}

/* (S17) SPHENIX conductivity switch (Borrow et al. 2022, eqs. 28, 29): alpha_D
 * + dt (beta_D H lap u / sqrt(u) - (alpha_D - alpha_D,min) v_sig / H), at most
 * alpha_D,max (1 - alpha_visc / alpha_max) (none in viscous flow) and at least
 * alpha_D,min. v_sig: SPHENIX the largest signal velocity of the neighbours
 * (2 c at rest); alpha_visc: SWIFT the largest viscosity alpha of the
 * neighbours, or the particle's own. No source for u <= 0, no decay for H <= 0,
 * no change for dt <= 0 (but the bounds); s NULL returns alpha_d. */
SPH_API sph_real sph_switch_conductivity(const sph_switch *s, sph_real alpha_d, sph_real lap_u, sph_real u,
                                         sph_real v_sig, sph_real H, sph_real alpha_visc, sph_real dt)
{
    sph_real src, dec, lim, a;
    if (s == NULL) return alpha_d;
    src = u > 0 ? s->beta_d * H * lap_u / sph__sqrt(u) : 0;
    dec = H > 0 ? (alpha_d - s->alpha_d_min) * v_sig / H : 0;
    a = alpha_d + (dt > 0 ? dt : 0) * (src - dec);
    lim = s->alpha_max > 0 ? s->alpha_d_max * (1 - alpha_visc / s->alpha_max) : s->alpha_d_max;
    lim = lim < s->alpha_d_max ? lim : s->alpha_d_max;
    a = a < lim ? a : lim;
    return a > s->alpha_d_min ? a : s->alpha_d_min;
}

#if !defined(SPH_ONLY_PAIRS) && !defined(SPH_NO_OPERATORS) /* the operators of section 8 use section 6 */

/* SPH_OK for an absent output (p[0] NULL: not written) or a usable one. */
SPH_API int sph__out_opt(sph_out o, int ncomp) { return o.p[0] == NULL ? SPH_OK : sph__out_ok(o, ncomp); }

/* call (using i) for every target i of 0..nt-1, count = the sum of what it returns. */
#define SPH__EACH_TARGET(nt, count, call)                                                                         \
    do {                                                                                                          \
        sph_idx i, n = 0; /* n: the name SPH__OMP_FOR reduces; count must not be named n */                      \
        SPH__OMP_FOR                                                                                              \
        for (i = 0; i < (nt); ++i) n += (call);                                                                   \
        (count) = n;                                                                                              \
    } while (0)

/* Start of target i of a term of a vector field v (velocity, gradient): its
 * kernel data and v_i (A->ft; 0 where the field is absent). */
SPH__INLINE void sph__vtarget(const sph__args *A, sph_idx i, sph__tgt *t, sph_real *vi)
{
    int k;
    sph__tinit(A, i, t);
    for (k = 0; k < 3; ++k) vi[k] = k < SPH__DIM(A) && A->ft.p[0] != NULL ? SPH__AT(A->ft, k, i) : 0;
}

/* Pair (i, j) of such a term: dx, F at h_ij, dv = v_i - v_j (A->f, 0 where
 * absent); returns h_ij. */
SPH__INLINE sph_real sph__vpair(const sph__args *A, const sph__tgt *t, const sph_real *vi, sph_idx j, sph_real *dx,
                                sph_real *dv, sph_real *F)
{
    sph_real W;
    int k;
    sph__pair(A, t, j, SPH__WANT_F, dx, &W, F);
    for (k = 0; k < 3; ++k) dv[k] = k < SPH__DIM(A) && A->f.p[0] != NULL ? vi[k] - SPH__AT(A->f, k, j) : 0;
    return A->hv ? (t->hi + SPH__AT(A->hs, 0, j)) / 2 : A->h;
}

/* (S1)-(S4) at target i: acceleration, heating and the largest v_sig; p:
 * the views of alpha and B, sources and targets (absent: alpha, 1). */
SPH_API int sph__av_target(const sph__args *A, const sph_av *av, const sph_view *p, sph_idx i, sph_out acc,
                           sph_out dudt, sph_out vsig)
{
    const int D = SPH__DIM(A), each = p[0].p[0] != NULL || p[2].p[0] != NULL;
    const sph_real ci = SPH__AT(A->kt, 0, i), rhoi = SPH__AT(A->rhot, 0, i);
    const sph_real ali = p[0].p[0] != NULL ? SPH__AT(p[1], 0, i) : av->alpha, Bi = p[2].p[0] != NULL ? SPH__AT(p[3], 0, i) : 1;
    sph_real vi[3], a[3] = {0, 0, 0}, du = 0, vs = 0, dx[3], dv[3], F;
    sph__tgt t;
    sph_off o;
    int k;
    sph__vtarget(A, i, &t, vi);
    for (o = A->off[i]; o < A->off[i + 1]; ++o) {
        const sph_idx j = A->idx[o];
        const sph_real cj = SPH__AT(A->k, 0, j), rhoij = (rhoi + SPH__AT(A->rho, 0, j)) / 2;
        const sph_real hij = sph__vpair(A, &t, vi, j, dx, dv, &F);
        const sph_real al = !each ? av->alpha
                                  : sph_pair_av_alpha(ali, p[0].p[0] != NULL ? SPH__AT(p[0], 0, j) : av->alpha, Bi,
                                                      p[2].p[0] != NULL ? SPH__AT(p[2], 0, j) : 1);
        sph_real Pi, s;
        Pi = av->form == SPH_AV_MONAGHAN ? sph_pair_av_monaghan(D, al, av->beta, hij, (ci + cj) / 2, rhoij, dx, dv)
                                         : sph_pair_av_signal(D, al, av->beta, ci, cj, rhoij, dx, dv);
        du += sph_pair_av_apply(D, SPH__AT(A->m, 0, j), Pi, F, dx, dv, a);
        s = sph_pair_signal_velocity(D, av->beta, ci, cj, dx, dv);
        vs = s > vs ? s : vs;
    }
    for (k = 0; k < D; ++k) SPH__AT(acc, k, i) = a[k];
    if (dudt.p[0] != NULL) SPH__AT(dudt, 0, i) = du;
    if (vsig.p[0] != NULL) SPH__AT(vsig, 0, i) = vs;
    return 0;
}

/* (S1)-(S4) over the list: acc_i = -sum_j m_j Pi_ij grad_i W_ij (dim
 * components), du_i/dt = (1/2) sum_j m_j Pi_ij v_ij . grad_i W_ij and
 * vsig_i = max_j v_sig,ij (S2) with av's beta (0 for an empty list). v and c
 * are velocities (dim components) and sound speeds, with target views as in
 * sph_gradient; needs ctx.m and ctx.rho (and ctx.rho_target with targets of
 * their own); h_ij as the derivative operators. With av's per-particle alpha
 * or Balsara factor (sources, and targets of their own as v_target), Pi_ij
 * takes alpha_ij of (S14). dudt and vsig may be absent (not written).
 * SPH_EOPTION for an unknown form, SPH_ERANGE for an alpha or beta not finite
 * and >= 0, SPH_EVALUE for a per-particle alpha or B < 0. */
SPH_API int sph_artificial_viscosity(const sph_ctx *c, const sph_av *av, sph_view v, sph_view v_target, sph_view cs,
                                     sph_view cs_target, sph_out acc, sph_out dudt, sph_out vsig)
{
    SPH__DISPATCH_TO(sph_artificial_viscosity, (c, av, v, v_target, cs, cs_target, acc, dudt, vsig))
    sph__args A;
    sph_view p[4];
    int st, k;
    if (av == NULL) return SPH_ENULL;
    if (av->form != SPH_AV_MONAGHAN && av->form != SPH_AV_SIGNAL) return SPH_EOPTION;
    if (!(av->alpha >= 0 && sph__finite(av->alpha)) || !(av->beta >= 0 && sph__finite(av->beta))) return SPH_ERANGE;
    st = sph__setup(c, SPH__N_M | SPH__N_RHO | SPH__N_FI | SPH__N_K, c != NULL ? c->dim : 1, v, v_target, cs,
                    cs_target, &A);
    for (k = 0; k < 2; ++k) { /* alpha, then B: each absent, or sources and targets as v */
        const sph_view src = k == 0 ? av->alpha_source : av->balsara_source;
        p[2 * k] = p[2 * k + 1] = src;
        if (st == SPH_OK && src.p[0] != NULL)
            st = sph__field(c, src, k == 0 ? av->alpha_target : av->balsara_target, 1, 1, 4, &p[2 * k], &p[2 * k + 1]);
    }
    if (st == SPH_OK) st = sph__out_ok(acc, c->dim);
    if (st == SPH_OK) st = sph__out_opt(dudt, 1);
    if (st == SPH_OK) st = sph__out_opt(vsig, 1);
    if (st != SPH_OK) return st;
    SPH__EACH_TARGET(A.nt, st, sph__av_target(&A, av, p, i, acc, dudt, vsig));
    return SPH_OK;
}

/* Which coefficient sph_viscosity is given per particle. */
#if SPH__FIRST
typedef enum {
    SPH_VISC_DYNAMIC = 0,  /* mu (Pa s) */
    SPH_VISC_KINEMATIC = 1 /* nu = mu / rho (m^2/s): mu_i = rho_i nu_i */
} sph_visc_kind;
#endif /* SPH__FIRST */

/* (S5) at target i. */
SPH_API int sph__visc_target(const sph__args *A, int kinematic, sph_idx i, sph_out acc)
{
    const int D = SPH__DIM(A);
    const sph_real rhoi = SPH__AT(A->rhot, 0, i), mui = SPH__AT(A->kt, 0, i) * (kinematic ? rhoi : 1);
    sph_real vi[3], a[3] = {0, 0, 0}, dx[3], dv[3], F;
    sph__tgt t;
    sph_off o;
    int k;
    sph__vtarget(A, i, &t, vi);
    for (o = A->off[i]; o < A->off[i + 1]; ++o) {
        const sph_idx j = A->idx[o];
        const sph_real rhoj = SPH__AT(A->rho, 0, j), muj = SPH__AT(A->k, 0, j) * (kinematic ? rhoj : 1);
        const sph_real hij = sph__vpair(A, &t, vi, j, dx, dv, &F);
        sph_pair_viscosity(D, SPH__AT(A->m, 0, j), mui, muj, rhoi, rhoj, hij, F, dx, dv, a);
    }
    for (k = 0; k < D; ++k) SPH__AT(acc, k, i) = a[k];
    return 0;
}

/* (S5) viscous acceleration acc_i = (1/rho div(mu grad) v)_i of the velocity
 * v (dim components; for constant mu, nu lap v) with a dynamic (mu) or
 * kinematic (nu) coefficient per particle (coef, coef_target; target views
 * as in sph_gradient). Needs ctx.m and ctx.rho (rho_target with targets of
 * their own); h_ij as the derivative operators. SPH_EOPTION for another kind. */
SPH_API int sph_viscosity(const sph_ctx *c, sph_visc_kind kind, sph_view coef, sph_view coef_target, sph_view v,
                          sph_view v_target, sph_out acc)
{
    SPH__DISPATCH_TO(sph_viscosity, (c, kind, coef, coef_target, v, v_target, acc))
    sph__args A;
    int st = kind != SPH_VISC_DYNAMIC && kind != SPH_VISC_KINEMATIC
                 ? SPH_EOPTION
                 : sph__setup(c, SPH__N_M | SPH__N_RHO | SPH__N_FI | SPH__N_K, c != NULL ? c->dim : 1, v, v_target,
                              coef, coef_target, &A);
    if (st == SPH_OK) st = sph__out_ok(acc, c->dim);
    if (st != SPH_OK) return st;
    SPH__EACH_TARGET(A.nt, st, sph__visc_target(&A, kind == SPH_VISC_KINEMATIC, i, acc));
    return SPH_OK;
}

/* (S6), (S7) at target i: g in A->f / A->ft (absent: Molteni & Colagrossi). */
SPH_API int sph__ddiff_target(const sph__args *A, sph_real dc0, sph_idx i, sph_out out)
{
    const int renorm = A->f.p[0] != NULL;
    const sph_real rhoi = SPH__AT(A->rhot, 0, i);
    sph_real gi[3], gj[3], dg[3], s = 0, dx[3], F;
    sph__tgt t;
    sph_off o;
    int k;
    sph__vtarget(A, i, &t, gi);
    for (o = A->off[i]; o < A->off[i + 1]; ++o) {
        const sph_idx j = A->idx[o];
        const sph_real hij = sph__vpair(A, &t, gi, j, dx, dg, &F);
        for (k = 0; k < 3; ++k) gj[k] = renorm && k < SPH__DIM(A) ? SPH__AT(A->f, k, j) : 0; /* not gi - dg: exact */
        s += hij * sph_pair_density_diffusion(SPH__DIM(A), SPH__AT(A->V, 0, j), rhoi, SPH__AT(A->rho, 0, j),
                                              renorm ? gi : NULL, renorm ? gj : NULL, F, dx);
    }
    SPH__AT(out, 0, i) = dc0 * s;
    return 0;
}

/* (S7) density diffusion term of the continuity equation, drho_i/dt +=
 * delta c0 sum_j h_ij (S6): Antuono et al. (2010) with grad_rho the
 * renormalised density gradients (sph_gradient with SPH_SCHEME_CORRECTED of
 * ctx.rho; dim components, target view as in sph_gradient), or Molteni &
 * Colagrossi (2009) when grad_rho is absent. Density from ctx.rho (and
 * rho_target), volumes ctx.V; h_ij as the derivative operators. Writes out.
 * SPH_ERANGE for delta or c0 negative or not finite. */
SPH_API int sph_density_diffusion(const sph_ctx *c, sph_real delta, sph_real c0, sph_view grad_rho,
                                  sph_view grad_rho_target, sph_out out)
{
    SPH__DISPATCH_TO(sph_density_diffusion, (c, delta, c0, grad_rho, grad_rho_target, out))
    sph__args A;
    const int renorm = grad_rho.p[0] != NULL;
    int st = !(delta >= 0 && delta <= SPH__REAL_MAX && c0 >= 0 && c0 <= SPH__REAL_MAX)
                 ? SPH_ERANGE
                 : sph__setup(c, SPH__N_V | SPH__N_RHO | (renorm ? SPH__N_FI : 0), renorm && c != NULL ? c->dim : 0,
                              grad_rho, grad_rho_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(out, 1);
    if (st != SPH_OK) return st;
    SPH__EACH_TARGET(A.nt, st, sph__ddiff_target(&A, delta * c0, i, out));
    return SPH_OK;
}

/* The wall model of sph_wall_adami (S8). */
#if SPH__FIRST
typedef struct {
    sph_real g[3];      /* body force per unit mass on the fluid (gravity) */
    sph_wall_slip slip; /* SPH_WALL_NOSLIP or SPH_WALL_FREESLIP */
    sph_view v_wall;    /* prescribed velocity per wall particle (dim components); absent: at rest */
    sph_view a_wall;    /* prescribed acceleration per wall particle; absent: 0 */
} sph_wall;
#endif /* SPH__FIRST */

/* A wall model at rest with gravity g (dim components, NULL: none) and no-slip. */
SPH_API sph_wall sph_wall_init(int dim, const sph_real *g)
{
    sph_wall w;
    int a;
    for (a = 0; a < 3; ++a) w.g[a] = g != NULL && a < dim ? g[a] : 0;
    w.slip = SPH_WALL_NOSLIP;
    w.v_wall = w.a_wall = sph_view_none();
    return w;
}

/* (S8) at wall target i. */
SPH_API int sph__wall_target(const sph__args *A, const sph_wall *w, sph_view p, sph_idx i, sph_out p_w, sph_out v_w)
{
    const int D = SPH__DIM(A);
    sph_real sum[5] = {0, 0, 0, 0, 0}, g[3] = {0, 0, 0}, vwall[3] = {0, 0, 0}, vf[3] = {0, 0, 0}, pw, vw[3], dx[3],
             W, F;
    sph__tgt t;
    sph_off o;
    int k, ok;
    sph__tinit(A, i, &t);
    for (k = 0; k < D; ++k) {
        g[k] = w->g[k] - (w->a_wall.p[0] != NULL ? SPH__AT(w->a_wall, k, i) : 0);
        vwall[k] = w->v_wall.p[0] != NULL ? SPH__AT(w->v_wall, k, i) : 0;
    }
    for (o = A->off[i]; o < A->off[i + 1]; ++o) {
        const sph_idx j = A->idx[o];
        sph__pair(A, &t, j, SPH__WANT_W, dx, &W, &F);
        for (k = 0; k < D; ++k) vf[k] = SPH__AT(A->f, k, j);
        sph_pair_wall(D, W, SPH__AT(p, 0, j), SPH__AT(A->rho, 0, j), vf, g, dx, sum);
    }
    ok = sph_wall_end(D, w->slip, sum, vwall, &pw, vw);
    SPH__AT(p_w, 0, i) = pw;
    for (k = 0; v_w.p[0] != NULL && k < D; ++k) SPH__AT(v_w, k, i) = vw[k];
    return !ok;
}

/* SPH_OK when a view of the targets is absent or usable (values checked
 * with full validation). */
SPH_API int sph__target_opt(const sph_ctx *c, sph_view v, int ncomp)
{
    int st;
    if (v.p[0] == NULL) return SPH_OK;
    st = sph__view_ok(v, ncomp);
    return st != SPH_OK || c->validate == SPH_VALIDATE_ARGS ? st : sph__scan(v, ncomp, c->list->n_targets, 0, c->dim);
}

/* (S8) generalised wall boundary (Adami, Hu & Adams 2012): for every wall
 * particle (the targets: ctx.x_target, h_target with per-particle h) from its
 * fluid neighbours (the sources: ctx.x, ctx.rho, p, v), the pressure p_w =
 * [sum_f p_f W_wf + (g - a_w) . sum_f rho_f x_wf W_wf] / sum_f W_wf and the
 * velocity for the viscous terms v_w (no-slip 2 v_wall - v~, free-slip v~,
 * v~ = sum_f v_f W_wf / sum_f W_wf), W at the wall's h. A wall particle with
 * no fluid in reach gets p_w = 0 and v_w = v_wall, counted in *n_empty (may
 * be NULL). v_w may be absent (not written). The wall densities for the
 * momentum equation follow from p_w by the solver's equation of state.
 * SPH_EOPTION for an unknown slip, SPH_ERANGE for a g not finite. */
SPH_API int sph_wall_adami(const sph_ctx *c, const sph_wall *w, sph_view p, sph_view v, sph_out p_w, sph_out v_w,
                           sph_idx *n_empty)
{
    SPH__DISPATCH_TO(sph_wall_adami, (c, w, p, v, p_w, v_w, n_empty))
    sph__args A;
    sph_view unused;
    sph_idx empty = 0;
    int st, a;
    if (w == NULL) return SPH_ENULL;
    if (w->slip != SPH_WALL_NOSLIP && w->slip != SPH_WALL_FREESLIP) return SPH_EOPTION;
    for (a = 0; a < 3; ++a)
        if (!sph__finite(w->g[a])) return SPH_ERANGE;
    st = sph__setup(c, 0, c != NULL ? c->dim : 1, v, sph_view_none(), sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__field(c, c->rho, sph_view_none(), 1, 0, 2, &A.rho, &unused); /* fluid only */
    if (st == SPH_OK) st = sph__field(c, p, sph_view_none(), 1, 0, 0, &A.k, &unused);
    if (st == SPH_OK) st = sph__target_opt(c, w->v_wall, c->dim);
    if (st == SPH_OK) st = sph__target_opt(c, w->a_wall, c->dim);
    if (st == SPH_OK) st = sph__out_ok(p_w, 1);
    if (st == SPH_OK) st = sph__out_opt(v_w, c->dim);
    if (st != SPH_OK) return st;
    SPH__EACH_TARGET(A.nt, empty, sph__wall_target(&A, w, A.k, i, p_w, v_w));
    if (n_empty != NULL) *n_empty = empty;
    return SPH_OK;
}

/* Inputs of sph_time_step (S9)-(S12): per-particle views, each optional
 * (absent: the scalar next to it, 0 = no such limit). */
#if SPH__FIRST
typedef struct {
    sph_dt_coef coef;     /* the C of each limit */
    sph_real h;           /* uniform h (when h_particle is absent) */
    sph_view h_particle;  /* per-particle h */
    sph_view vsig;        /* speed of (S9): c + |v| (coef.cfl 0.25), or (S2) (coef.cfl 0.5) */
    sph_view acc;         /* acceleration (dim components): |a| */
    sph_real nu;          /* uniform kinematic viscosity */
    sph_view nu_particle; /* per-particle kinematic viscosity */
    sph_real D;           /* uniform diffusivity */
    sph_view D_particle;  /* per-particle diffusivity */
} sph_dt_input;
#endif /* SPH__FIRST */

/* Inputs with the default coefficients, uniform h and no rate. */
SPH_API sph_dt_input sph_dt_input_init(sph_real h)
{
    sph_dt_input in;
    in.coef = sph_dt_coef_default();
    in.h = h;
    in.nu = in.D = 0;
    in.h_particle = in.vsig = in.acc = in.nu_particle = in.D_particle = sph_view_none();
    return in;
}

/* (S9)-(S12) the global time step: min over particles 0..n-1 of
 * sph_dt_limit, with the limiting reason and particle (reason and which may
 * be NULL; SPH_DT_NONE, -1 and SPH__REAL_MAX when no rate is given or all
 * are 0). SPH_EVALUE (first such particle in *which) where sph_dt_limit is
 * SPH_DT_INVALID (h not positive and finite, a rate negative or not finite);
 * SPH_ENULL for in or dt NULL or a view without its components, SPH_EDIM,
 * SPH_ECOUNT for n < 0. */
SPH_API int sph_time_step(const sph_dt_input *in, int dim, sph_idx n, sph_real *dt, int *reason, sph_idx *which)
{
    sph_real best = SPH__REAL_MAX;
    int why = SPH_DT_NONE, a;
    sph_idx i, at = -1;
    if (in == NULL || dt == NULL) return SPH_ENULL;
    if (dim < 1 || dim > 3) return SPH_EDIM;
    if (n < 0) return SPH_ECOUNT;
    if ((in->h_particle.p[0] != NULL && sph__view_ok(in->h_particle, 1) != SPH_OK) ||
        (in->vsig.p[0] != NULL && sph__view_ok(in->vsig, 1) != SPH_OK) ||
        (in->acc.p[0] != NULL && sph__view_ok(in->acc, dim) != SPH_OK) ||
        (in->nu_particle.p[0] != NULL && sph__view_ok(in->nu_particle, 1) != SPH_OK) ||
        (in->D_particle.p[0] != NULL && sph__view_ok(in->D_particle, 1) != SPH_OK))
        return SPH_ENULL;
    for (i = 0; i < n; ++i) {
        sph_real h = in->h_particle.p[0] != NULL ? SPH__AT(in->h_particle, 0, i) : in->h, a2 = 0, t;
        int r;
        for (a = 0; in->acc.p[0] != NULL && a < dim; ++a) a2 += SPH__AT(in->acc, a, i) * SPH__AT(in->acc, a, i);
        t = sph_dt_limit(&in->coef, h, in->vsig.p[0] != NULL ? SPH__AT(in->vsig, 0, i) : 0, sph__sqrt(a2),
                         in->nu_particle.p[0] != NULL ? SPH__AT(in->nu_particle, 0, i) : in->nu,
                         in->D_particle.p[0] != NULL ? SPH__AT(in->D_particle, 0, i) : in->D, &r);
        if (r == SPH_DT_INVALID) {
            if (which != NULL) *which = i;
            return SPH_EVALUE;
        }
        if (r != SPH_DT_NONE && t < best) best = t, why = r, at = i;
    }
    *dt = best;
    if (reason != NULL) *reason = why;
    if (which != NULL) *which = at;
    return SPH_OK;
}

/* The viscosity switch of sph_switch_update: alpha left as it is (a caller
 * that integrates (S15) itself), or by (S16). */
#if SPH__FIRST
typedef enum { SPH_SWITCH_NONE = 0, SPH_SWITCH_SPHENIX = 1 } sph_switch_kind;

/* Inputs of sph_switch_update: per-particle views of one component (stride 0:
 * one value for all), absent where the switch they feed is not wanted. */
typedef struct {
    sph_switch par;            /* the parameters of (S15)-(S17) */
    sph_switch_kind viscosity; /* SPH_SWITCH_SPHENIX: alpha by (S16); SPH_SWITCH_NONE: alpha only read */
    sph_real dt;               /* the step since the last update; 0 at the first: no d(div v)/dt, no decay */
    sph_real kappa;            /* H = kappa h, the kernel's support radius (sph_kernel_support) */
    sph_view div_v;            /* div v of this evaluation */
    sph_view curl_v;           /* |curl v|, for the Balsara factor (S13) */
    sph_view c;                /* sound speed */
    sph_view h;                /* smoothing length */
    sph_view lap_u, u;         /* lap u and u, for the conductivity switch (S17) */
    sph_view v_sig;            /* speed of the decay of (S17); absent: 2 c */
    sph_view alpha_visc;       /* alpha of the limiter of (S17); absent: the particle's alpha after (S16) */
} sph_switch_input;
#endif /* SPH__FIRST */

/* Inputs with SPHENIX's parameters and switch, dt = 0, and every view absent. */
SPH_API sph_switch_input sph_switch_input_init(sph_real kappa)
{
    sph_switch_input in;
    in.par = sph_switch_default();
    in.viscosity = SPH_SWITCH_SPHENIX;
    in.dt = 0;
    in.kappa = kappa;
    in.div_v = in.curl_v = in.c = in.h = in.lap_u = in.u = in.v_sig = in.alpha_visc = sph_view_none();
    return in;
}

/* (S13), (S16), (S17) at particle i, in the order of SPHENIX: B from div v and
 * curl v, alpha, the div v kept for the next rate, then alpha_D. */
SPH_API int sph__switch_one(const sph_switch_input *in, sph_idx i, sph_out alpha, sph_out div_prev, sph_out B,
                            sph_out alpha_d)
{
    const sph_real dv = SPH__AT(in->div_v, 0, i), c = SPH__AT(in->c, 0, i), h = SPH__AT(in->h, 0, i);
    const sph_real H = in->kappa * h;
    sph_real a = SPH__AT(alpha, 0, i);
    if (B.p[0] != NULL) SPH__AT(B, 0, i) = sph_switch_balsara(dv, SPH__AT(in->curl_v, 0, i), c, h);
    if (in->viscosity == SPH_SWITCH_SPHENIX) {
        const sph_real rate = in->dt > 0 ? (dv - SPH__AT(div_prev, 0, i)) / in->dt : 0;
        SPH__AT(alpha, 0, i) = a = sph_switch_sphenix(&in->par, a, dv, rate, c, H, in->dt);
    }
    if (div_prev.p[0] != NULL) SPH__AT(div_prev, 0, i) = dv;
    if (alpha_d.p[0] != NULL)
        SPH__AT(alpha_d, 0, i) = sph_switch_conductivity(
            &in->par, SPH__AT(alpha_d, 0, i), SPH__AT(in->lap_u, 0, i), SPH__AT(in->u, 0, i),
            in->v_sig.p[0] != NULL ? SPH__AT(in->v_sig, 0, i) : 2 * c, H,
            in->alpha_visc.p[0] != NULL ? SPH__AT(in->alpha_visc, 0, i) : a, in->dt);
    return 0;
}

/* SPH_OK when the field p (one component, stride >= 0 for an input, > 0 for
 * an output) is absent and not needed, or present with usable values over n
 * particles: kind 0 finite, 4 also >= 0 (sph__scan), 5 h positive and finite
 * (SPH_EH). */
SPH_API int sph__switch_field(const sph_real *p, ptrdiff_t stride, int need, int out, int kind, sph_idx n)
{
    sph_view v = sph_view_soa(p, NULL, NULL);
    sph_idx i;
    if (p == NULL) return need ? SPH_ENULL : SPH_OK;
    if (stride < 0 || (out && stride == 0)) return SPH_ESTRIDE;
    v.stride = stride;
    if (kind != 5) return sph__scan(v, 1, n, kind, 1);
    for (i = 0; i < n; ++i)
        if (!(SPH__AT(v, 0, i) > 0 && SPH__AT(v, 0, i) <= SPH__REAL_MAX)) return SPH_EH;
    return SPH_OK;
}

/* (S13), (S16), (S17) over particles 0..n-1, each as sph__switch_one: alpha
 * (read; updated by (S16) with in.viscosity SPH_SWITCH_SPHENIX), div_v_prev
 * (div v of the last update, then this one's; needed by (S16), may be absent
 * otherwise), balsara (written where present, from in.curl_v), alpha_d
 * (updated by (S17) where present, from in.lap_u and in.u). Nothing is
 * written on an error: SPH_ENULL (in NULL, a view needed and absent),
 * SPH_ECOUNT (n < 0), SPH_EOPTION (in.viscosity), SPH_ERANGE (a parameter
 * not finite, negative or bounds out of order, dt < 0, kappa <= 0),
 * SPH_ESTRIDE (an input stride < 0, an output's <= 0), SPH_EH (h not positive
 * and finite), SPH_ENONFINITE, SPH_EVALUE (c, curl v, u, v_sig, alpha,
 * alpha_D negative). */
SPH_API int sph_switch_update(const sph_switch_input *in, sph_idx n_part, sph_out alpha, sph_out div_v_prev,
                              sph_out balsara, sph_out alpha_d)
{
    sph_real q[8];
    int st, k, visc, bal, cond;
    if (in == NULL) return SPH_ENULL;
    if (n_part < 0) return SPH_ECOUNT;
    if (in->viscosity != SPH_SWITCH_NONE && in->viscosity != SPH_SWITCH_SPHENIX) return SPH_EOPTION;
    q[0] = in->par.alpha_min, q[1] = in->par.alpha_max, q[2] = in->par.length, q[3] = in->par.alpha_d_min;
    q[4] = in->par.alpha_d_max, q[5] = in->par.beta_d, q[6] = in->dt, q[7] = in->kappa;
    for (k = 0; k < 8; ++k)
        if (!(q[k] >= 0 && q[k] <= SPH__REAL_MAX)) return SPH_ERANGE;
    if (!(q[7] > 0) || q[0] > q[1] || q[3] > q[4]) return SPH_ERANGE;
    visc = in->viscosity == SPH_SWITCH_SPHENIX, bal = balsara.p[0] != NULL, cond = alpha_d.p[0] != NULL;
    st = sph__switch_field(alpha.p[0], alpha.stride, 1, 1, 4, n_part);
    if (st == SPH_OK) st = sph__switch_field(div_v_prev.p[0], div_v_prev.stride, visc, 1, 0, n_part);
    if (st == SPH_OK) st = sph__switch_field(balsara.p[0], balsara.stride, 0, 1, 0, 0);
    if (st == SPH_OK) st = sph__switch_field(alpha_d.p[0], alpha_d.stride, 0, 1, 4, n_part);
    if (st == SPH_OK) st = sph__switch_field(in->div_v.p[0], in->div_v.stride, 1, 0, 0, n_part);
    if (st == SPH_OK) st = sph__switch_field(in->c.p[0], in->c.stride, 1, 0, 4, n_part);
    if (st == SPH_OK) st = sph__switch_field(in->h.p[0], in->h.stride, 1, 0, 5, n_part);
    if (st == SPH_OK) st = sph__switch_field(in->curl_v.p[0], in->curl_v.stride, bal, 0, 4, n_part);
    if (st == SPH_OK) st = sph__switch_field(in->lap_u.p[0], in->lap_u.stride, cond, 0, 0, n_part);
    if (st == SPH_OK) st = sph__switch_field(in->u.p[0], in->u.stride, cond, 0, 4, n_part);
    if (st == SPH_OK) st = sph__switch_field(in->v_sig.p[0], in->v_sig.stride, 0, 0, 4, n_part);
    if (st == SPH_OK) st = sph__switch_field(in->alpha_visc.p[0], in->alpha_visc.stride, 0, 0, 4, n_part);
    if (st != SPH_OK) return st;
    SPH__EACH_TARGET(n_part, st, sph__switch_one(in, i, alpha, div_v_prev, balsara, alpha_d));
    return SPH_OK;
}

#endif /* operators of section 8 */
#endif /* section 8 */

#if !defined(SPH_ONLY_PAIRS) && !defined(SPH_NO_SMOOTHING_LENGTH) /* section 9 */

/* ======================================================================== */
/* 9. Smoothing length and pair-once loops                                   */
/* ======================================================================== */
/* docs/smoothing_length.md. Needs sections 1-5 only (kernels, views, CSR
 * lists, pair terms); lists come from section 7 or the caller.
 *
 * Adaptive h (Springel & Hernquist 2002; Price 2012, J. Comput. Phys. 231,
 * 759, section 2.4): h_i = eta (m_i / rho_i)^(1/d) (H1) and rho_i =
 * sum_j m_j W(r_ij, h_i) (H2) solved together per particle by Newton-Raphson
 * on f(h) = rho(h) - m_i (eta / h)^d (H3), kept inside a bracket [lo, hi]
 * where f changes sign and bisected when a Newton step leaves it. h^d f(h) / m_i
 * = sum_j (m_j / m_i) alpha_d w(r_ij / h) - eta^d rises with h (w falls
 * with q), so the root is unique and f < 0 below it, provided eta^d exceeds
 * the self term alpha_d w(0) (else SPH_ERANGE). Omega_i (H4) and the grad-h
 * momentum and energy equations (H5), (H6) follow; they conserve momentum
 * and total energy pair by pair (H7).
 *
 * Lists that grow with h: the solver reads only the list it is given, built
 * with a search radius kappa h_list_i (per particle, ctx.h_list, or
 * ctx.h_list_max for all). A particle whose h would exceed it gets
 * SPH_H_BEYOND_LIST and, in h[i], the fixed-point estimate eta (m_i /
 * rho_i(h_list))^(1/d) > h_list_i: search again with a larger radius (e.g.
 * 1.2 times that) and call again.
 *
 * Pair-once loops: sph_pairs_build turns a symmetric full list (each pair in
 * both rows: SPH_NSEARCH_SYMMETRIC, or a uniform h) into a half list, row i
 * holding the sources j > i, and its transpose (for each j a range of slots,
 * one per pair (i, j), ascending in i). A pair loop over the half list writes
 * what pair k adds to i at k and what it adds to j at its slot, in two
 * per-pair buffers; sph_pairs_reduce sums each particle's entries in a fixed
 * order (its own row, then its slots), reading both buffers in sequence (H8): every pair evaluated once, no two threads
 * writing one particle, and the result bitwise the same for any number of
 * OpenMP threads.
 *
 * Data: per-particle fields are views, as sections 6-8 take them (section
 * 4: structure-of-arrays, interleaved or array-of-structs alike): sph_view
 * for what is read (x, m, h_list in the context; v, h, A), sph_out for what
 * is written (h, rho, Omega, dv/dt, du/dt). The per-pair buffers and the
 * output of sph_pairs_reduce (up to 16 components) are raw interleaved
 * arrays, sized by sph_pairs_buffer_len and sph_gradh_pairs_buffer_len.
 * One mass for every particle: m = sph_view_aos(&mass, 1, 0), a view of
 * stride 0 (the same bits as an array of that mass; the operators of
 * sections 6-8, sph_density and the others, refuse a stride 0 with
 * SPH_ESTRIDE). One step in order (kept lists, search, h solve, re-search,
 * prune, every pair term in one sph_batch_fill loop, time step), with the
 * kernel width each term takes: docs/step.md, examples/step_recipe.c. */

/* Per-particle outcome of sph_h_solve. */
#if SPH__FIRST
enum {
    SPH_H_CONVERGED = 0,     /* a Newton step within the list <= tol h, or a sign change of f bracketed to tol h */
    SPH_H_NOT_CONVERGED = 1, /* max_iter sums without meeting tol: h, rho, Omega of the last sum */
    SPH_H_BEYOND_LIST = 2    /* the solution lies beyond kappa h_list_i: h holds a larger estimate; search again */
};
#endif /* SPH__FIRST */

/* What the smoothing-length solver and the grad-h forces read. Fill with
 * sph_hctx_init. Targets are the sources: list->n_targets == n_sources = n. */
#if SPH__FIRST
typedef struct {
    sph_kernel kernel;
    int dim;                    /* 1..3 */
    const sph_neighbours *list; /* full CSR list; row i ascending (as the search gives) for sph_pairs_build */
    const sph_box *box;         /* periodic box, or NULL: the list's (SPH_EBOX when both are known and differ) */
    sph_view x;                 /* positions (dim components) */
    sph_view m;                 /* masses, positive; one for all: sph_view_aos(&m, 1, 0), stride 0 */
    sph_view h_list;            /* per particle: row i holds every j with r_ij < kappa h_list_i; absent: h_list_max */
    sph_real h_list_max;        /* the same for every particle (when h_list is absent) */
    sph_real eta;               /* (H1); default 1.2: the cubic spline's 58, 18, 4.8 neighbours in 3-D, 2-D, 1-D;
                                   sph_kernel_h_for_neighbours(k, dim, N, 1) gives the eta of N neighbours */
    sph_real tol;               /* relative change of h that ends the iteration; default 1e-6 (float: 64 eps) */
    int max_iter;               /* density sums per particle at most; default 50 */
    int check_list;             /* 1 (default): one pass checks the list (offsets, indices); 0: the caller did */
} sph_hctx;
#endif /* SPH__FIRST */

/* Totals of one sph_h_solve call. */
#if SPH__FIRST
typedef struct {
    sph_idx n_not_converged; /* particles with SPH_H_NOT_CONVERGED */
    sph_idx n_beyond_list;   /* particles with SPH_H_BEYOND_LIST */
    int max_iterations;      /* most density sums of any particle */
    sph_off iterations;      /* density sums of all particles */
} sph_hreport;
#endif /* SPH__FIRST */

/* A half list and its transpose (sph_pairs_build). Pair k = (i, j), i < j,
 * is position k of half.index (row i); its transposed slot t_slot[k] lies
 * in j's range t_offset[j] .. t_offset[j+1]-1, whose slots are ordered by
 * ascending i. A pair loop writes what pair k adds to i at k and what it
 * adds to j at t_slot[k]: the reduction then reads both in sequence. */
#if SPH__FIRST
typedef struct {
    sph_neighbours half;     /* row i: the sources j > i of the full list */
    const sph_off *t_offset; /* [n + 1]: particle j's slots */
    const sph_off *t_slot;   /* [pairs]: the transposed slot of pair k */
} sph_pairs;
#endif /* SPH__FIRST */

/* A context with eta = 1.2, tol = 1e-6 (64 eps in float), max_iter = 50,
 * the list checked, no box and no per-particle list radius. */
SPH_API sph_hctx sph_hctx_init(sph_kernel kernel, int dim, const sph_neighbours *list, sph_view x, sph_view m,
                               sph_real h_list_max)
{
    sph_hctx c;
    c.kernel = kernel;
    c.dim = dim;
    c.list = list;
    c.box = NULL;
    c.x = x;
    c.m = m;
    c.h_list = sph_view_soa(NULL, NULL, NULL);
    c.h_list_max = h_list_max;
    c.eta = SPH__C(1.2);
    c.tol = sizeof(sph_real) == sizeof(float) ? 64 * (sph_real)FLT_EPSILON : SPH__C(1e-6);
    c.max_iter = 50;
    c.check_list = 1;
    return c;
}

/* Periods and their inverses per axis (0 where not periodic) of the box
 * ctx.box or the list's (sph__box_of): the minimum image of (O0) without a
 * division per pair. */
#if SPH__FIRST
typedef struct {
    sph_real L[3], invL[3];
} sph__period;
#endif /* SPH__FIRST */

SPH_API sph__period sph__period_of(const sph_box *ctx_box, const sph_neighbours *list, int dim)
{
    sph__period P;
    const sph_box *box;
    int a;
    sph__box_of(ctx_box, list, dim, &box); /* checked by sph__hctx_check */
    for (a = 0; a < 3; ++a) {
        const int on = box != NULL && a < dim && box->periodic[a];
        P.L[a] = on ? box->length[a] : 0;
        P.invL[a] = on ? 1 / box->length[a] : 0;
    }
    return P;
}

/* (O0): dx = x_i - x_j (minimum image), returns r^2. */
SPH__INLINE sph_real sph__h_dx(const sph__period *P, int dim, const sph_real *xi, sph_view x, sph_idx j,
                               sph_real *dx)
{
    sph_real r2 = 0;
    int a;
    for (a = 0; a < 3; ++a) dx[a] = 0;
    for (a = 0; a < dim && a < 3; ++a) {
        sph_real d = xi[a] - x.p[a][(ptrdiff_t)j * x.stride];
        if (P->L[a] != 0) d -= P->L[a] * sph__floor(d * P->invL[a] + (sph_real)0.5);
        dx[a] = d;
        r2 += d * d;
    }
    return r2;
}

/* Position of particle i into xi[3]. */
SPH__INLINE void sph__h_xi(sph_view x, int dim, sph_idx i, sph_real *xi)
{
    int a;
    for (a = 0; a < 3; ++a) xi[a] = a < dim ? x.p[a][(ptrdiff_t)i * x.stride] : 0;
}

/* Checks what sph_h_solve and the forces share: kernel, dimension, list
 * (targets = sources; with check_list, offsets and indices), positions and
 * masses present, the box (ctx.box or the list's, equal when both are
 * known: sph__box_of) with usable periods. */
SPH_API int sph__hctx_check(const sph_hctx *c)
{
    const sph_box *box;
    sph_idx i, n;
    int a, st;
    if (c == NULL || c->list == NULL || c->list->offset == NULL) return SPH_ENULL;
    if (sph_kernel_check(c->kernel, c->dim) != SPH_OK) return sph_kernel_check(c->kernel, c->dim);
    n = c->list->n_targets;
    if (n < 0 || c->list->n_sources != n) return SPH_ECOUNT;
    if (n > 0 && c->m.p[0] == NULL) return SPH_ENULL;
    for (a = 0; a < c->dim; ++a)
        if (n > 0 && c->x.p[a] == NULL) return SPH_ENULL;
    if ((st = sph__box_of(c->box, c->list, c->dim, &box)) != SPH_OK) return st;
    if (c->list->offset[n] > 0 && c->list->index == NULL) return SPH_ENULL;
    if (c->check_list) {
        sph_off o;
        if (c->list->offset[0] != 0) return SPH_EOFFSET;
        for (i = 0; i < n; ++i)
            if (c->list->offset[i + 1] < c->list->offset[i]) return SPH_EOFFSET;
        for (o = 0; o < c->list->offset[n]; ++o)
            if (c->list->index[o] < 0 || c->list->index[o] >= n) return SPH_EINDEX;
    }
    return SPH_OK;
}

/* The sums of (H2) and (K7) at 1/h = hinv for particle i without the
 * factors of h: sw = sum_j m_j w(q), sd = sum_j m_j (d w + q^2 g(q)), q =
 * r_ij / h. The reference loop, one pair at a time, in list order. */
SPH_API void sph__h_sums_ref(const sph_hctx *c, const sph__nshape *s, const sph__period *P, sph_idx i, sph_real hinv,
                             sph_real *sw, sph_real *sd)
{
    const sph_real dd = (sph_real)c->dim;
    sph_real xi[3], dx[3], s0 = 0, s1 = 0;
    sph_off o;
    sph__h_xi(c->x, c->dim, i, xi);
    for (o = c->list->offset[i]; o < c->list->offset[i + 1]; ++o) {
        const sph_idx j = c->list->index[o];
        const sph_real q = sph__sqrt(sph__h_dx(P, c->dim, xi, c->x, j, dx)) * hinv;
        const sph_real mj = c->m.p[0][(ptrdiff_t)j * c->m.stride];
        const sph_real w = sph__nshape_w(s, q), g = sph__nshape_g(s, q);
        s0 += mj * w;
        s1 += mj * (dd * w + q * q * g);
    }
    *sw = s0;
    *sd = s1;
}

#if defined(SPH__FAST_LOOPS)
#if defined(_OPENMP) && _OPENMP >= 201307 && !defined(__clang__)
#define SPH__SIMD_HSUM _Pragma("omp simd reduction(+ : s0, s1)")
#else
#define SPH__SIMD_HSUM /* clang: as SPH__SIMD_KERNEL */
#endif
/* sph__h_sums_ref's sums with the operators' fast loops (section 6): one pass
 * in AVX-512 or AVX2 registers (sph__hsv_body) where the build has them, else
 * a chunk of the list at a time, x_ij and r axis by axis (sph__r_chunk: no chunk
 * array cleared), the vector square roots, then w, g, m_j and both sums in
 * one loop over the chunk's pairs alone, the shape's pieces constants of the
 * instance (a scalar loop where the compiler branches on the pieces, as in
 * sph__dgc_body). The reference arithmetic pair by pair; without OpenMP the
 * sums in list order too (bitwise), with it SIMD reductions where vectorised. */
SPH__INLINE void sph__h_sums_body(const sph_hctx *c, const sph__nshape *s, const sph__period *P, sph_idx i,
                                  sph_real hinv, sph_real *sw, sph_real *sd)
#if SPH__OP_AVX512 || SPH__OP_AVX2
{
    sph_real xi[3];
    sph__h_xi(c->x, c->dim, i, xi);
    switch ((int)(s - sph__nshapes)) { /* AVX-512 or AVX2: the one-pass loop of the shape */
#define SPH__X(S)                                                                                                \
    case S:                                                                                                      \
        sph__hsv_##S(c->dim, c->x, c->m, c->list->index, c->list->offset[i], c->list->offset[i + 1], xi, P->L, \
                     P->invL, hinv, sw, sd);                                                                     \
        break;
        SPH__SHAPE_IDS(SPH__X)
#undef SPH__X
    default: *sw = *sd = 0; break;
    }
}
#else
{
    const sph_real dd = (sph_real)c->dim, *const pm = c->m.p[0];
    const ptrdiff_t sm = c->m.stride;
    const sph_off end = c->list->offset[i + 1];
    sph_real xi[3], d[SPH__CHUNK], r[SPH__CHUNK], s0 = 0, s1 = 0;
    sph_real *const dp[3] = {d, d, d}; /* x_ij is not kept */
    sph_off o;
    int n, k;
    sph__h_xi(c->x, c->dim, i, xi);
    for (o = c->list->offset[i]; o < end; o += n) {
        const sph_idx *j = c->list->index + o;
        n = end - o < SPH__CHUNK ? (int)(end - o) : SPH__CHUNK;
        sph__r_chunk(c->x, c->dim, j, n, xi, P->L, P->invL, dp, r);
        SPH__SIMD_HSUM
        for (k = 0; k < n; ++k) {
            const sph_real q = r[k] * hinv, mj = pm[(ptrdiff_t)j[k] * sm];
            const sph_real w = sph__nshape_w(s, q), g = sph__nshape_g(s, q);
            s0 += mj * w;
            s1 += mj * (dd * w + q * q * g);
        }
    }
    *sw = s0;
    *sd = s1;
}
#endif
#undef SPH__SIMD_HSUM

#define SPH__X(S)                                                                                          \
    SPH__NOINLINE void sph__h_sums_##S(const sph_hctx *c, const sph__period *P, sph_idx i, sph_real hinv,  \
                                       sph_real *sw, sph_real *sd)                                        \
    {                                                                                                      \
        sph__h_sums_body(c, &sph__nshapes[S], P, i, hinv, sw, sd);                                         \
    }
SPH__SHAPE_IDS(SPH__X)
#undef SPH__X
#endif /* SPH__FAST_LOOPS */

/* (H2) and its h-derivative at h for particle i: rho = sum_j m_j W(r_ij, h),
 * drho = sum_j m_j dW/dh (K7), dW/dh = -alpha_d h^-(d+1) (d w + q w'); the
 * sums in the operators' fast loops where they are compiled. */
SPH_API void sph__h_sums(const sph_hctx *c, const sph__kdim *kd, const sph__period *P, sph_idx i, sph_real h,
                         sph_real *rho, sph_real *drho)
{
    const sph_real hinv = 1 / h;
    sph_real sw = 0, sd = 0;
#if defined(SPH__FAST_LOOPS)
    switch (kd->shape) {
#define SPH__X(S) case S: sph__h_sums_##S(c, P, i, hinv, &sw, &sd); break;
        SPH__SHAPE_IDS(SPH__X)
#undef SPH__X
    default: break; /* every shape has its instance (sph__shape_ids_cover_every_shape) */
    }
#else
    sph__h_sums_ref(c, &sph__nshapes[kd->shape], P, i, hinv, &sw, &sd);
#endif
    *rho = sph__hpow(kd->alpha * sw, hinv, c->dim);
    *drho = -sph__hpow(kd->alpha * sd, hinv, c->dim + 1);
}

/* (H1)-(H4) for particle i from the guess *h, bracketed Newton-Raphson:
 * returns its state, writes h, rho(h), Omega(h) of the last sum and the
 * number of sums. */
SPH_API int sph__h_particle(const sph_hctx *c, const sph__kdim *kd, const sph__period *P, sph_idx i, sph_real hl,
                            sph_real *h, sph_real *rho, sph_real *omega, int *iters)
{
    const sph_real mi = c->m.p[0][(ptrdiff_t)i * c->m.stride], dd = (sph_real)c->dim;
    sph_real lo = 0, hi = hl, x = *h < hl ? *h : hl;
    int hi_known = 0, it, state = SPH_H_NOT_CONVERGED;
    for (it = 1; it <= c->max_iter; ++it) {
        sph_real r, dr, rh, f, fp, xn;
        sph__h_sums(c, kd, P, i, x, &r, &dr);
        rh = sph__hpow(mi, c->eta / x, c->dim); /* m_i (eta / h)^d */
        f = r - rh;
        fp = dr + dd * rh / x;
        *h = x;
        *rho = r;
        *omega = r > 0 ? 1 + x * dr / (dd * r) : 1; /* (H4): dh/drho = -h / (d rho); r = 0 only without the self term */
        if (f < 0) lo = x;
        else hi = x, hi_known = 1;
        if (f < 0 && x >= hl) { /* the root lies beyond the list: the fixed point of (H1) beyond h_list */
            *h = r > 0 ? c->eta * (sph_real)pow((double)(mi / r), 1.0 / c->dim) : 2 * hl;
            state = SPH_H_BEYOND_LIST;
            break;
        }
        xn = fp > 0 ? x - f / fp : lo; /* (H3) Newton step; lo forces the bracket below */
        if (fp > 0 && xn <= hl && (xn > x ? xn - x : x - xn) <= c->tol * x) { /* also a step below the rounding of x */
            state = SPH_H_CONVERGED;
            break;
        }
        if (!(xn > lo && xn < hi)) xn = hi_known ? (lo + hi) / 2 : xn >= hi ? hl : (lo + hl) / 2;
        if ((xn > x ? xn - x : x - xn) <= c->tol * x) {
            if (hi_known) { /* a bracket of a sign change narrower than tol */
                state = SPH_H_CONVERGED;
                break;
            }
            xn = hl; /* f < 0 everywhere seen: only the sum at h_list tells whether the root lies in the list */
        }
        x = xn;
    }
    *iters = it <= c->max_iter ? it : c->max_iter;
    return state;
}

/* (H1)-(H4): solves h_i and rho_i together for every particle, from the
 * guesses in h (positive, finite; one above h_list_i starts at h_list_i),
 * and writes h, rho, Omega (one component each, any layout: h is read for
 * the guess and overwritten); iterations and state (optional, int [n]): the
 * density sums and SPH_H_* of each particle; report (optional): the
 * totals. Returns SPH_OK (check report or state for particles not
 * converged or beyond their list) or SPH_ENULL, SPH_EKERNEL, SPH_EDIM,
 * SPH_ECOUNT (n_sources != n_targets), SPH_EINDEX, SPH_EOFFSET, SPH_ERANGE
 * (eta^d <= alpha_d w(0): no solution; eta, tol not positive and finite,
 * max_iter < 1), SPH_EBOXLEN, SPH_EBOX (ctx.box differs from the list's),
 * SPH_EH (a guess or h_list not usable), SPH_ENONFINITE (a NaN or Inf
 * position or a mass not positive and finite), before anything is written.
 * Parallel over particles under OpenMP; the same result for any thread
 * count. */
SPH_API int sph_h_solve(const sph_hctx *c, sph_out h, sph_out rho, sph_out omega, int *iterations, int *state,
                        sph_hreport *report)
{
    SPH__DISPATCH_TO(sph_h_solve, (c, h, rho, omega, iterations, state, report))
    const sph__kdim *kd;
    sph__period P;
    sph_idx i, n, nnc = 0, nbl = 0;
    sph_off total = 0, next[SPH__SHARES_MAX * SPH_SHARE_PAD];
    sph_share sh;
    int st = sph__hctx_check(c), mx = 0, a;
    if (st != SPH_OK) return st;
    n = c->list->n_targets;
    if (n > 0 && (h.p[0] == NULL || rho.p[0] == NULL || omega.p[0] == NULL)) return SPH_ENULL;
    kd = sph__kd(c->kernel, c->dim);
    if (!(c->eta > 0 && c->eta <= SPH__REAL_MAX) || !(c->tol > 0 && c->tol <= SPH__REAL_MAX) || c->max_iter < 1 ||
        !(sph__hpow(1, c->eta, c->dim) > kd->alpha * (sph_real)sph__shape_at(&sph__nshapes[kd->shape], SPH__SW, 0)))
        return SPH_ERANGE;
    if (c->h_list.p[0] == NULL && !sph__h_ok(c->h_list_max, c->dim)) return SPH_EH;
    for (i = 0; i < n; ++i) {
        const sph_real mi = c->m.p[0][(ptrdiff_t)i * c->m.stride];
        if (!sph__h_ok(SPH__AT(h, 0, i), c->dim)) return SPH_EH;
        if (c->h_list.p[0] != NULL && !sph__h_ok(c->h_list.p[0][(ptrdiff_t)i * c->h_list.stride], c->dim))
            return SPH_EH;
        if (!(mi > 0 && mi <= SPH__REAL_MAX)) return SPH_ENONFINITE;
        for (a = 0; a < c->dim; ++a)
            if (!sph__finite(c->x.p[a][(ptrdiff_t)i * c->x.stride])) return SPH_ENONFINITE;
    }
    P = sph__period_of(c->box, c->list, c->dim);
    sph_share_init(&sh, next, SPH__SHARES, n, 64);
#ifdef _OPENMP
#pragma omp parallel if (n >= 512) reduction(+ : nnc, nbl, total) reduction(max : mx)
#endif
    { /* each thread its static share first (its core's caches), then the others' (sph_share_next) */
        sph_idx lo, end, j; /* j, not i: declared in the region, each thread's own */
        int u = 0;
        while (sph_share_next(&sh, SPH__THREAD, &u, &lo, &end))
            for (j = lo; j < end; ++j) {
                const sph_real hl = c->h_list.p[0] != NULL ? c->h_list.p[0][(ptrdiff_t)j * c->h_list.stride]
                                                           : c->h_list_max;
                sph_real hi = SPH__AT(h, 0, j), ri = 0, oi = 1;
                int it = 0;
                const int s = sph__h_particle(c, kd, &P, j, hl, &hi, &ri, &oi, &it);
                SPH__AT(h, 0, j) = hi;
                SPH__AT(rho, 0, j) = ri;
                SPH__AT(omega, 0, j) = oi;
                if (iterations != NULL) iterations[j] = it;
                if (state != NULL) state[j] = s;
                nnc += s == SPH_H_NOT_CONVERGED;
                nbl += s == SPH_H_BEYOND_LIST;
                total += it;
                mx = it > mx ? it : mx;
            }
    }
    if (report != NULL) {
        report->n_not_converged = nnc;
        report->n_beyond_list = nbl;
        report->max_iterations = mx;
        report->iterations = total;
    }
    return SPH_OK;
}

/* A_i = p_i / (Omega_i rho_i^2), the per-particle factor of (H5), (H6).
 * 0 where it is not a finite number (rho not positive, NaN or Inf input);
 * an Omega not positive and finite counts as 1 (the equations without the
 * grad-h term), so a degenerate neighbourhood cannot flip or blow up the
 * force. */
SPH_API sph_real sph_gradh_factor(sph_real p, sph_real rho, sph_real omega)
{
    const sph_real P = rho > 0 ? p / (rho * rho) : 0, A = omega > 0 && omega <= SPH__REAL_MAX ? P / omega : P;
    return sph__finite(A) ? A : 0;
}

/* (H5) pair term: acc += m_j (A_i F_i + A_j F_j) dx, F_i = F(r, h_i),
 * F_j = F(r, h_j); dv_i/dt = -acc. */
SPH_API void sph_pair_gradh_pressure(int dim, sph_real m_j, sph_real A_i, sph_real A_j, sph_real F_i, sph_real F_j,
                                     const sph_real *dx, sph_real *acc)
{
    sph__axpy(dim, m_j * (A_i * F_i + A_j * F_j), dx, acc);
}

/* (H6) pair term: m_j A_i F_i (v_i - v_j) . dx, summed into du_i/dt. */
SPH_API sph_real sph_pair_gradh_energy(int dim, sph_real m_j, sph_real A_i, sph_real F_i, const sph_real *v_ij,
                                       const sph_real *dx)
{
    sph_real s = 0;
    int a;
    for (a = 0; a < dim && a < 3; ++a) s += v_ij[a] * dx[a];
    return m_j * A_i * F_i * s;
}

/* Checks the arrays of the forces: h usable, A finite, dv/dt present, v
 * present when du/dt is asked for (dudt.p[0] not NULL). */
SPH_API int sph__gradh_check(const sph_hctx *c, sph_view v, sph_view h, sph_view A, sph_out dvdt, sph_out dudt)
{
    sph_idx i, n;
    int a, st = sph__hctx_check(c);
    if (st != SPH_OK) return st;
    n = c->list->n_targets;
    if (n > 0 && (h.p[0] == NULL || A.p[0] == NULL)) return SPH_ENULL;
    for (a = 0; n > 0 && a < c->dim; ++a)
        if (dvdt.p[a] == NULL || (dudt.p[0] != NULL && v.p[a] == NULL)) return SPH_ENULL;
    for (i = 0; i < n; ++i) {
        if (!sph__h_ok(SPH__AT(h, 0, i), c->dim)) return SPH_EH;
        if (!sph__finite(SPH__AT(A, 0, i))) return SPH_ENONFINITE;
    }
    return SPH_OK;
}

/* The common arithmetic of (H5), (H6) for pair (i, j), j != i: dx, the
 * factor c = A_i F_i + A_j F_j and e = F_i (v_i - v_j) . dx, F_i and F_j
 * at the particles' own h (1 / h_i given: one division per pair). */
SPH__INLINE void sph__gradh_pair(const sph_hctx *c, const sph__kdim *kd, const sph__period *P, const sph_real *xi,
                                 sph_real hiinv, sph_real Ai, const sph_real *vi, sph_idx j, sph_view v,
                                 sph_view h, sph_view A, int want_e, sph_real *dx, sph_real *cf, sph_real *Fi,
                                 sph_real *Fj)
{
    const sph__nshape *s = &sph__nshapes[kd->shape];
    const sph_real r = sph__sqrt(sph__h_dx(P, c->dim, xi, c->x, j, dx)), hjinv = 1 / SPH__AT(h, 0, j);
    int a;
    *Fi = sph__hpow(kd->alpha * sph__nshape_g(s, r * hiinv), hiinv, c->dim + 2);
    *Fj = sph__hpow(kd->alpha * sph__nshape_g(s, r * hjinv), hjinv, c->dim + 2);
    *cf = Ai * *Fi + SPH__AT(A, 0, j) * *Fj;
    if (want_e) {
        sph_real e = 0;
        for (a = 0; a < c->dim; ++a) e += (vi[a] - v.p[a][(ptrdiff_t)j * v.stride]) * dx[a];
        *Fi *= e; /* F_i (v_ij . dx) */
        *Fj *= e;
    }
}

/* (H5), (H6) in gather form: every pair visited from both rows.
 * dvdt component a of i = -sum_j m_j (A_i F_i + A_j F_j) x_ij,a and, when
 * dudt is present (dudt.p[0] not NULL), dudt_i = A_i sum_j m_j F_i v_ij .
 * x_ij, over a symmetric list (each pair in both rows, or the sums miss
 * what the other side sees) with A from sph_gradh_factor. h, A: one
 * component; v (dim components) read only for dudt; any layout, as the
 * views of section 6. Returns SPH_OK or a status of sph_h_solve's kinds,
 * nothing written then. */
SPH_API int sph_gradh_forces(const sph_hctx *c, sph_view v, sph_view h, sph_view A, sph_out dvdt, sph_out dudt)
{
    SPH__DISPATCH_TO(sph_gradh_forces, (c, v, h, A, dvdt, dudt))
    const sph__kdim *kd;
    const int want_u = dudt.p[0] != NULL;
    sph__period P;
    sph_idx i, n;
    int st = sph__gradh_check(c, v, h, A, dvdt, dudt);
    if (st != SPH_OK) return st;
    n = c->list->n_targets;
    kd = sph__kd(c->kernel, c->dim);
    P = sph__period_of(c->box, c->list, c->dim);
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 64) if (n >= 512)
#endif
    for (i = 0; i < n; ++i) {
        sph_real xi[3], vi[3] = {0, 0, 0}, acc[3] = {0, 0, 0}, du = 0, dx[3], cf, Fi, Fj;
        const sph_real hiinv = 1 / SPH__AT(h, 0, i), Ai = SPH__AT(A, 0, i);
        sph_off o;
        int a;
        sph__h_xi(c->x, c->dim, i, xi);
        if (want_u) sph__h_xi(v, c->dim, i, vi);
        for (o = c->list->offset[i]; o < c->list->offset[i + 1]; ++o) {
            const sph_idx j = c->list->index[o];
            const sph_real mj = c->m.p[0][(ptrdiff_t)j * c->m.stride];
            if (j == i) continue;
            sph__gradh_pair(c, kd, &P, xi, hiinv, Ai, vi, j, v, h, A, want_u, dx, &cf, &Fi, &Fj);
            sph__axpy(c->dim, mj * cf, dx, acc);
            du += mj * Fi;
        }
        for (a = 0; a < c->dim; ++a) SPH__AT(dvdt, a, i) = -acc[a];
        if (want_u) SPH__AT(dudt, 0, i) = Ai * du;
    }
    return SPH_OK;
}

/* (H8) The half list of a symmetric full list and its transpose. offset
 * [n + 1], index [cap], t_offset [n + 1], t_slot [cap]; pairs is set to the
 * number of pairs (j > i) whatever happens. Rows of the full list must be
 * in ascending index (the search's order). Returns SPH_OK and fills *P, or
 * SPH_ESIZE (cap < pairs; offset complete), SPH_ENOTSYMMETRIC when the list
 * is not symmetric (a pair in one row only, as a gather search with
 * per-particle h gives: the pair-once sums would differ from the gather
 * ones) or a row not strictly ascending, SPH_ECOUNT (n_sources != n_targets,
 * cap < 0), SPH_EOFFSET, SPH_ENULL, SPH_EINDEX. The half list carries the
 * full list's box. */
SPH_API int sph_pairs_build(const sph_neighbours *full, sph_off *offset, sph_idx *index, sph_off cap,
                            sph_off *t_offset, sph_off *t_slot, sph_off *pairs, sph_pairs *P)
{
    SPH__DISPATCH_TO(sph_pairs_build, (full, offset, index, cap, t_offset, t_slot, pairs, P))
    sph_idx i, n;
    sph_off o, k;
    int bad = 0;
    if (pairs != NULL) *pairs = 0;
    if (full == NULL || full->offset == NULL || offset == NULL || t_offset == NULL || P == NULL) return SPH_ENULL;
    n = full->n_targets;
    if (n < 0 || full->n_sources != n || cap < 0) return SPH_ECOUNT;
    if (full->offset[0] != 0) return SPH_EOFFSET;
    if (full->offset[n] > 0 && full->index == NULL) return SPH_ENULL;
    for (i = 0; i < n; ++i) {
        if (full->offset[i + 1] < full->offset[i]) return SPH_EOFFSET;
        for (o = full->offset[i]; o < full->offset[i + 1]; ++o) {
            if (full->index[o] < 0 || full->index[o] >= n) return SPH_EINDEX;
            if (o > full->offset[i] && full->index[o] <= full->index[o - 1]) return SPH_ENOTSYMMETRIC;
        }
    }
    offset[0] = 0;
    for (i = 0; i < n; ++i) { /* rows ascending: the sources j > i are the tail of row i */
        o = full->offset[i + 1];
        while (o > full->offset[i] && full->index[o - 1] > i) --o;
        offset[i + 1] = offset[i] + (full->offset[i + 1] - o);
    }
    if (pairs != NULL) *pairs = offset[n];
    if (cap < offset[n]) return SPH_ESIZE;
    if (offset[n] > 0 && (index == NULL || t_slot == NULL)) return SPH_ENULL;
    for (i = 0; i <= n; ++i) t_offset[i] = 0;
    for (i = 0; i < n; ++i) {
        const sph_off tail = full->offset[i + 1] - (offset[i + 1] - offset[i]);
        for (k = offset[i], o = tail; k < offset[i + 1]; ++k, ++o) {
            index[k] = full->index[o];
            ++t_offset[index[k] + 1];
        }
    }
    for (i = 0; i < n; ++i) t_offset[i + 1] += t_offset[i];
    /* transpose: t_offset[j] serves as the cursor of j (rows in ascending i), then is shifted back */
    for (i = 0; i < n; ++i)
        for (k = offset[i]; k < offset[i + 1]; ++k) t_slot[k] = t_offset[index[k]]++;
    for (i = n; i > 0; --i) t_offset[i] = t_offset[i - 1];
    t_offset[0] = 0;
    /* symmetry: the sources below j of full row j are, in order, the i whose half rows hold j */
    for (i = 0; i < n && !bad; ++i) {
        sph_off below = 0;
        for (o = full->offset[i]; o < full->offset[i + 1] && full->index[o] < i; ++o) ++below;
        bad = below != t_offset[i + 1] - t_offset[i];
    }
    for (i = 0; i < n && !bad; ++i)
        for (k = offset[i]; k < offset[i + 1] && !bad; ++k) {
            const sph_idx j = index[k];
            bad = full->index[full->offset[j] + (t_slot[k] - t_offset[j])] != i;
        }
    if (bad) return SPH_ENOTSYMMETRIC;
    P->half.n_targets = P->half.n_sources = n;
    P->half.offset = offset;
    P->half.index = index;
    P->half.box = full->box; /* the full list's box, known or not */
    P->half.box_known = full->box_known;
    P->t_offset = t_offset;
    P->t_slot = t_slot;
    return SPH_OK;
}

/* Reals of the two per-pair buffers of a pair loop with ncomp values per
 * pair (to_i and to_j of sph_pairs_reduce, ncomp pairs reals each): 2 ncomp
 * pairs. 0 for ncomp outside 1..16, pairs negative or the count beyond the
 * range of sph_off. */
SPH_API sph_off sph_pairs_buffer_len(int ncomp, sph_off pairs)
{
    return ncomp >= 1 && ncomp <= 16 && pairs >= 0 && pairs <= INT64_MAX / 32 ? 2 * (sph_off)ncomp * pairs : 0;
}

/* Reals of the buffer of sph_gradh_forces_pairs: dim + 1 values per pair
 * (dv/dt and du/dt), 2 (dim + 1) pairs; 0 for dim outside 1..3. */
SPH_API sph_off sph_gradh_pairs_buffer_len(int dim, sph_off pairs)
{
    return dim >= 1 && dim <= 3 ? sph_pairs_buffer_len(dim + 1, pairs) : 0;
}

/* (H8) for particle i: s[a] = the sum over the pairs k of row i of
 * to_i[ncomp k + a], then over the slots t of i of to_j[ncomp t + a]; with
 * to_i NULL, s[a] holds the row's sum on entry and the slots are added. */
SPH__INLINE void sph__pairs_sum(const sph_pairs *P, int ncomp, const sph_real *to_i, const sph_real *to_j, sph_idx i,
                                sph_real *s)
{
    sph_off k, t;
    int a;
    if (to_i != NULL)
        for (a = 0; a < ncomp; ++a) s[a] = 0;
    for (k = P->half.offset[i]; to_i != NULL && k < P->half.offset[i + 1]; ++k)
        for (a = 0; a < ncomp; ++a) s[a] += to_i[(ptrdiff_t)ncomp * k + a];
    for (t = P->t_offset[i]; t < P->t_offset[i + 1]; ++t)
        for (a = 0; a < ncomp; ++a) s[a] += to_j[(ptrdiff_t)ncomp * t + a];
}

/* sph_pairs_reduce (rows 0) and sph_pairs_reduce_rows (rows 1: to_i not
 * read, out holding the rows' sums on entry). */
SPH__INLINE int sph__pairs_reduce(const sph_pairs *P, int ncomp, int rows, const sph_real *to_i, const sph_real *to_j,
                                  sph_real *out)
{
    sph_idx i, n;
    if (P == NULL || P->half.offset == NULL || P->t_offset == NULL) return SPH_ENULL;
    if (ncomp < 1 || ncomp > 16) return SPH_ERANGE;
    n = P->half.n_targets;
    if (n > 0 && out == NULL) return SPH_ENULL;
    if (P->half.offset[n] > 0 && ((!rows && to_i == NULL) || to_j == NULL)) return SPH_ENULL;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) if (n >= 2048)
#endif
    for (i = 0; i < n; ++i) {
        sph_real s[16];
        int a;
        for (a = 0; a < ncomp; ++a) s[a] = rows ? out[(ptrdiff_t)ncomp * i + a] : 0;
        sph__pairs_sum(P, ncomp, rows ? NULL : to_i, to_j, i, s);
        for (a = 0; a < ncomp; ++a) out[(ptrdiff_t)ncomp * i + a] = s[a];
    }
    return SPH_OK;
}

/* (H8) out[ncomp i + a] = sum over the pairs k of row i of to_i[ncomp k + a]
 * + sum over the slots t of i of to_j[ncomp t + a], in that order: pair k =
 * (i, j) adds to_i[k] to i and to_j[t_slot[k]] to j. ncomp 1..16 (else
 * SPH_ERANGE); to_i and to_j hold ncomp pairs reals each
 * (sph_pairs_buffer_len for both). out is an interleaved array (ncomp reals
 * per particle), not a view: a view holds at most 3 components, a pair loop
 * often sums more (sod_shock.c: 5).
 * Parallel over particles; bitwise the same for any thread count. */
SPH_API int sph_pairs_reduce(const sph_pairs *P, int ncomp, const sph_real *to_i, const sph_real *to_j, sph_real *out)
{
    SPH__DISPATCH_TO(sph_pairs_reduce, (P, ncomp, to_i, to_j, out))
    return sph__pairs_reduce(P, ncomp, 0, to_i, to_j, out);
}

/* (H8) with the rows summed by the caller: out[ncomp i + a] holds on entry
 * particle i's own share, the terms a pair loop would store at to_i[k] for
 * the pairs k of row i added in row order from 0 (the loop adds them as it
 * goes, in registers); to_j's slots of i are then added in order, so that
 * out equals sph_pairs_reduce's bit for bit and the to_i buffer, half of a
 * pair-once loop's memory traffic, is never written. Checks and
 * parallelism as sph_pairs_reduce. */
SPH_API int sph_pairs_reduce_rows(const sph_pairs *P, int ncomp, const sph_real *to_j, sph_real *out)
{
    SPH__DISPATCH_TO(sph_pairs_reduce_rows, (P, ncomp, to_j, out))
    return sph__pairs_reduce(P, ncomp, 1, NULL, to_j, out);
}

/* The partners' shares of the rows i of P's half list with some j in
 * [j0, j1) added to out[ncomp j ..] (sph_pairs_reduce_rows_k): for each j
 * in ascending i, the order of j's slots. Rows ascending (sph_pairs_build). */
SPH__INLINE void sph__pairs_add_k(const sph_pairs *P, int ncomp, const sph_real *to_j, sph_real *out, sph_idx j0,
                                  sph_idx j1)
{
    const sph_off *off = P->half.offset;
    const sph_idx *idx = P->half.index;
    sph_idx i;
    for (i = 0; i + 1 < j1; ++i) { /* rows i >= j1 - 1 hold no j < j1 */
        sph_off k = off[i], k1 = off[i + 1];
        if (k1 <= k || idx[k1 - 1] < j0) continue; /* row ends below the range */
        for (; k < k1; ++k) {
            const sph_idx j = idx[k];
            const sph_real *s = to_j + (ptrdiff_t)ncomp * k;
            sph_real *o = out + (ptrdiff_t)ncomp * j;
            int a;
            if (j < j0) continue;
            if (j >= j1) break;
            if (ncomp == 5) { /* the common width in registers: the adds are those of the loop below */
                o[0] += s[0], o[1] += s[1], o[2] += s[2], o[3] += s[3], o[4] += s[4];
            } else {
                for (a = 0; a < ncomp; ++a) o[a] += s[a];
            }
        }
    }
}

/* (H8) with the rows summed by the caller and each partner's share stored at
 * its pair index: out[ncomp i + a] holds on entry i's own share (as for
 * sph_pairs_reduce_rows), to_j[ncomp k + a] what pair k = (i, j) adds to j,
 * at k rather than at t_slot[k], so that the pair loop's stores run in
 * sequence (scattered stores to the slots cost the shock tube's pair loop
 * more than its kernel evaluations, bench/pair_once.c); each j then gets its
 * pairs added in ascending i, the order of its slots, and out equals
 * sph_pairs_reduce_rows's bit for bit. t_offset and t_slot are not read.
 * Checks as sph_pairs_reduce_rows; the half list's rows ascending, as
 * sph_pairs_build gives them. With OpenMP each thread owns a range of j and
 * scans the rows that reach it: bitwise the same for any thread count. */
SPH_API int sph_pairs_reduce_rows_k(const sph_pairs *P, int ncomp, const sph_real *to_j, sph_real *out)
{
    SPH__DISPATCH_TO(sph_pairs_reduce_rows_k, (P, ncomp, to_j, out))
    sph_idx n;
    if (P == NULL || P->half.offset == NULL) return SPH_ENULL;
    if (ncomp < 1 || ncomp > 16) return SPH_ERANGE;
    n = P->half.n_targets;
    if (n > 0 && out == NULL) return SPH_ENULL;
    if (P->half.offset[n] > 0 && (to_j == NULL || P->half.index == NULL)) return SPH_ENULL;
#ifdef _OPENMP
#pragma omp parallel if (n >= 2048)
    {
        const int T = omp_get_num_threads(), t = omp_get_thread_num();
        sph__pairs_add_k(P, ncomp, to_j, out, (sph_idx)((double)n * t / T), (sph_idx)((double)n * (t + 1) / T));
    }
#else
    sph__pairs_add_k(P, ncomp, to_j, out, 0, n);
#endif
    return SPH_OK;
}

/* (H5), (H6) pair-once over the half list of sph_pairs_build (the views
 * and results of sph_gradh_forces, to round-off): each pair evaluated once
 * into buf, then summed per particle in the order of sph_pairs_reduce (H8).
 * buf: buf_len >= sph_gradh_pairs_buffer_len(dim, pairs) reals, pairs =
 * P->half.offset[n] (else SPH_ESIZE); scratch, raw like the buffers of
 * sph_pairs_reduce. c->list is not read. Bitwise the same for any thread
 * count. */
SPH_API int sph_gradh_forces_pairs(const sph_hctx *c, const sph_pairs *P, sph_view v, sph_view h, sph_view A,
                                   sph_real *buf, sph_off buf_len, sph_out dvdt, sph_out dudt)
{
    SPH__DISPATCH_TO(sph_gradh_forces_pairs, (c, P, v, h, A, buf, buf_len, dvdt, dudt))
    const sph__kdim *kd;
    const int want_u = dudt.p[0] != NULL;
    sph__period Pd;
    sph_hctx ch;
    sph_idx i, n;
    sph_off np;
    sph_real *vi_buf, *vj_buf, *ei_buf, *ej_buf;
    int st, D;
    if (c == NULL || P == NULL) return SPH_ENULL;
    ch = *c;
    ch.list = &P->half;
    ch.check_list = 0; /* sph_pairs_build checked it */
    if ((st = sph__gradh_check(&ch, v, h, A, dvdt, dudt)) != SPH_OK) return st;
    n = P->half.n_targets;
    np = P->half.offset[n];
    if (np > 0 && (buf == NULL || P->t_slot == NULL)) return SPH_ENULL;
    D = c->dim;
    if (np > 0 && buf_len < sph_gradh_pairs_buffer_len(D, np)) return SPH_ESIZE;
    kd = sph__kd(c->kernel, D);
    Pd = sph__period_of(c->box, &P->half, D);
    vi_buf = buf;
    vj_buf = buf + (ptrdiff_t)D * np;
    ei_buf = buf + (ptrdiff_t)2 * D * np;
    ej_buf = ei_buf + np;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 64) if (n >= 512)
#endif
    for (i = 0; i < n; ++i) {
        sph_real xi[3], vi[3] = {0, 0, 0}, dx[3], cf, Fi, Fj;
        const sph_real mi = c->m.p[0][(ptrdiff_t)i * c->m.stride], hiinv = 1 / SPH__AT(h, 0, i);
        const sph_real Ai = SPH__AT(A, 0, i);
        sph_off k;
        int a;
        sph__h_xi(c->x, D, i, xi);
        if (want_u) sph__h_xi(v, D, i, vi);
        for (k = P->half.offset[i]; k < P->half.offset[i + 1]; ++k) {
            const sph_idx j = P->half.index[k];
            const sph_real mj = c->m.p[0][(ptrdiff_t)j * c->m.stride];
            const sph_off t = P->t_slot[k];
            sph__gradh_pair(&ch, kd, &Pd, xi, hiinv, Ai, vi, j, v, h, A, want_u, dx, &cf, &Fi, &Fj);
            for (a = 0; a < D; ++a) {
                vi_buf[(ptrdiff_t)D * k + a] = -(mj * cf) * dx[a];
                vj_buf[(ptrdiff_t)D * t + a] = (mi * cf) * dx[a];
            }
            ei_buf[k] = Ai * (mj * Fi);
            ej_buf[t] = SPH__AT(A, 0, j) * (mi * Fj);
        }
    }
#ifdef _OPENMP
#pragma omp parallel for schedule(static) if (n >= 2048)
#endif
    for (i = 0; i < n; ++i) { /* (H8): the sums of sph_pairs_reduce, written into the views */
        sph_real s[16];
        int a;
        sph__pairs_sum(P, D, vi_buf, vj_buf, i, s);
        for (a = 0; a < D; ++a) SPH__AT(dvdt, a, i) = s[a];
        if (want_u) {
            sph__pairs_sum(P, 1, ei_buf, ej_buf, i, s);
            SPH__AT(dudt, 0, i) = s[0];
        }
    }
    return SPH_OK;
}

/* ---- Pair batches: what every pair needs, SPH_BATCH pairs at a time ----
 * For solvers that write their own pair equations: sph_batch_fill hands the
 * pairs of one row of a CSR list (a gather list, or the half list of
 * sph_pairs for a pair-once loop) in batches of SPH_BATCH lanes, a structure
 * of arrays, so that the caller's plain loop over the lanes compiles to SIMD
 * (docs/smoothing_length.md, "Pair batches"). Each lane holds x_ij (minimum
 * image), r, W and F at h_i and at h_j, the partner j and the list position
 * k of the pair (the pair index of the half list: the caller writes to_i[k]
 * and to_j[t_slot[k]]). W and F are those of the section-9 pair loops bit for
 * bit (sph__nshape_w, sph__nshape_g, scaled as sph__hpow), within a few eps
 * of sph_pair_kernel. */
#if SPH__FIRST
typedef struct {
    int n;                     /* pairs in the batch, 0..SPH_BATCH; lanes n.. are padding */
    sph_idx j[SPH_BATCH];      /* partner (padding: the target i) */
    sph_off k[SPH_BATCH];      /* position in the list: half list, the pair index (padding: -1) */
    sph_real dx[3][SPH_BATCH]; /* x_ij = x_i - x_j, minimum image (O0); 0 beyond dim and in padding */
    sph_real r[SPH_BATCH];     /* |x_ij| (padding: 0) */
    sph_real W_i[SPH_BATCH], F_i[SPH_BATCH]; /* W(r, h_i), F(r, h_i) = (1/r) dW/dr (padding: 0) */
    sph_real W_j[SPH_BATCH], F_j[SPH_BATCH]; /* the same at h_j */
} sph_batch;
#endif /* SPH__FIRST */

/* What sph_batch_fill reads: set by sph_batch_source. */
#if SPH__FIRST
typedef struct {
    const sph_neighbours *list;
    sph_view x, h;
    int dim;
    sph_real alpha;          /* alpha_d */
    const sph__nshape *shape;
    sph__period P;           /* the box of sph_batch_source or the list's */
    int what;                /* SPH_BATCH_W | SPH_BATCH_F: what the fills compute (sph_batch_select) */
} sph_batch_src;
#endif /* SPH__FIRST */

/* What sph_batch_fill computes besides j, k, x_ij and r (sph_batch_select). */
#if SPH__FIRST
enum { SPH_BATCH_W = 1, SPH_BATCH_F = 2 };
#endif /* SPH__FIRST */

/* The source of sph_batch_fill for kernel k in dim dimensions over list
 * (targets = sources), positions x (dim components) and smoothing lengths h
 * (one component), the periodic box box or, when NULL, the list's. Checks
 * once what the fills then take for granted: SPH_ENULL (b, list, offsets,
 * x or h absent, index absent for a non-empty list), SPH_EKERNEL, SPH_EDIM,
 * SPH_ECOUNT (n_sources != n_targets), SPH_EOFFSET, SPH_EINDEX, SPH_EBOX /
 * SPH_EBOXLEN (sph__box_of), SPH_EH (an h not usable), SPH_ENONFINITE (a
 * position NaN or Inf); else SPH_OK. On error *b is left unusable (its list
 * NULL: every fill then gives an empty batch). */
SPH_API int sph_batch_source(sph_batch_src *b, sph_kernel k, int dim, const sph_neighbours *list,
                             const sph_box *box, sph_view x, sph_view h)
{
    const sph_box *bx;
    sph_idx n;
    int a, st;
    if (b == NULL) return SPH_ENULL;
    b->list = NULL;
    if (list == NULL || list->offset == NULL) return SPH_ENULL;
    if ((st = sph_kernel_check(k, dim)) != SPH_OK) return st;
    n = list->n_targets;
    if (n < 0 || list->n_sources != n) return SPH_ECOUNT;
    if (n > 0 && h.p[0] == NULL) return SPH_ENULL;
    for (a = 0; a < dim; ++a)
        if (n > 0 && x.p[a] == NULL) return SPH_ENULL;
    if ((st = sph__box_of(box, list, dim, &bx)) != SPH_OK) return st;
    if ((st = sph_neighbours_check(list)) != SPH_OK) return st;
    if ((st = sph__hx_check(x, h, n, dim)) != SPH_OK) return st;
    b->x = x;
    b->h = h;
    b->dim = dim;
    b->alpha = sph__kdims[k][dim - 1].alpha;
    b->shape = &sph__nshapes[sph__kdims[k][dim - 1].shape];
    b->P = sph__period_of(box, list, dim);
    b->what = SPH_BATCH_W | SPH_BATCH_F;
    b->list = list;
    return SPH_OK;
}

/* Which kernel values the fills of S compute: what = SPH_BATCH_W (W_i, W_j),
 * SPH_BATCH_F (F_i, F_j), both (the default of sph_batch_source) or 0; the
 * arrays not asked for are zero. A pair loop that needs F alone (forces,
 * energy, div v) saves half the kernel evaluations. SPH_ENULL (S NULL),
 * SPH_ERANGE (other bits set: S unchanged); else SPH_OK. */
SPH_API int sph_batch_select(sph_batch_src *S, int what)
{
    if (S == NULL) return SPH_ENULL;
    if ((what & ~(SPH_BATCH_W | SPH_BATCH_F)) != 0) return SPH_ERANGE;
    S->what = what;
    return SPH_OK;
}

/* v[l] = sqrt(v[l]) over the SPH_BATCH lanes of a caller's pair loop: IEEE
 * square roots in vector registers, where sqrt() in a loop stays scalar
 * unless errno is off (-fno-math-errno). */
SPH_API void sph_batch_sqrt(sph_real *v)
{
    SPH__DISPATCH_VOID(sph_batch_sqrt, (v))
    int l;
    if (SPH_BATCH % 8 == 0) {
        sph__sqrt_chunk(v, SPH_BATCH);
    } else {
        for (l = 0; l < SPH_BATCH; ++l) v[l] = sph__sqrt(v[l]);
    }
}

/* v[l] = p[O[l]] over the lanes, O[l] = J[l] s the partners' offsets. With
 * AVX-512 (double) each 8 lanes are built in a register from scalar loads
 * and stored at once: the lane loops' 512-bit loads of v are then forwarded
 * from the store, which eight scalar stores are not (as in sph__sqrt_chunk). */
SPH__INLINE void sph__batch_gather(const sph_real *p, const ptrdiff_t *O, sph_real *v)
{
    int l;
#if SPH__OP_AVX512
    if (sizeof(sph_real) == sizeof(double) && SPH_BATCH % 8 == 0) {
        const double *q = (const double *)p;
        for (l = 0; l < SPH_BATCH; l += 8) {
            const ptrdiff_t *o = O + l;
            _mm512_storeu_pd((double *)v + l,
                             _mm512_set_pd(q[o[7]], q[o[6]], q[o[5]], q[o[4]], q[o[3]], q[o[2]], q[o[1]], q[o[0]]));
        }
        return;
    }
#endif
    for (l = 0; l < SPH_BATCH; ++l) v[l] = p[O[l]];
}

/* The partners of a batch (O0): J[l] = p[l] for the n <= SPH_BATCH listed
 * pairs, J[l] = i in the padding lanes. With AVX-512 one masked load per
 * 16 lanes, i in the lanes not loaded; else one select per lane: a plain
 * copy of n entries compiles to rep movs (gcc), slow to start for 64 bytes. */
SPH__INLINE void sph__batch_index(const sph_idx *p, int n, sph_idx i, sph_idx *J)
{
    int l;
#if SPH__OP_AVX512
    if (sizeof(sph_idx) == 4) {
        for (l = 0; l < SPH_BATCH; l += 16) {
            const int m = n - l < 0 ? 0 : n - l > 16 ? 16 : n - l, w = SPH_BATCH - l < 16 ? SPH_BATCH - l : 16;
            const __m512i v = _mm512_mask_loadu_epi32(_mm512_set1_epi32(i), (__mmask16)((1u << m) - 1), p + (m > 0 ? l : 0));
            _mm512_mask_storeu_epi32(J + l, (__mmask16)((1u << w) - 1), v);
        }
        return;
    }
#endif
    SPH__LANES
    for (l = 0; l < SPH_BATCH; ++l) J[l] = l < n ? p[l] : i;
}

/* sph__hpow over the lanes of a batch at h_i and h_j: vi[l] = alpha vi[l]
 * hiinv^n, vj[l] = alpha vj[l] hjinv[l]^n, multiplied in sph__hpow's order
 * (the same bits), one pass with the running products in registers. */
SPH__INLINE void sph__hpow_lanes(sph_real *vi, sph_real *vj, sph_real alpha, sph_real hiinv, const sph_real *hjinv,
                                 const int n)
{
    int l, d;
    SPH__LANES
    for (l = 0; l < SPH_BATCH; ++l) {
        sph_real pi = alpha * vi[l], pj = alpha * vj[l];
        for (d = 0; d < n; ++d) pi *= hiinv, pj *= hjinv[l];
        vi[l] = pi, vj[l] = pj;
    }
}

/* A hint to fetch the cache line at p (gcc, clang), nothing elsewhere. */
#if (defined(__GNUC__) || defined(__clang__)) && !defined(__CUDACC__)
#define SPH__PREFETCH(p) __builtin_prefetch(p)
#else
#define SPH__PREFETCH(p) ((void)(p))
#endif

/* The batch in vector registers (SPH__BATCH_VEC: AVX2 or AVX-512 where the
 * fast loops of section 6 are compiled, SPH_REAL double): SPH__VW lanes at a
 * time through every step of sph__batch_fill_dim, the same operations in the
 * same order (bit for bit; the minimum image as sph__image_chunk, the
 * Horner steps unfused as the scalar forms), x_j and h_j loaded straight
 * into registers, only the results stored. */
#undef SPH__BATCH_VEC
#if defined(SPH__FAST_LOOPS) && (SPH__OP_AVX512 || SPH__OP_AVX2) && SPH_BATCH >= 8
#define SPH__BATCH_VEC 1
#else
#define SPH__BATCH_VEC 0
#endif
#if SPH__BATCH_VEC
/* (K1) w(q) (G 0) or (K2) g(q) = w'(q) / q (G 1) on the lanes, as sph__nshape_wg_lanes */
SPH__INLINE sph__vd sph__batch_wg(const sph__nshape *s, const int G, sph__vd q)
{
    sph__vd v = sph__nshape_vpick(s, G, q, 0);
    if (G == 1 && s->npiece > 1)
        v = SPH__V(div)(v, sph__vsel(sph__vge(q, SPH__V(set1)((double)s->lo[1])), q, SPH__V(set1)(1)));
    return sph__vsel(sph__vlt(q, SPH__V(set1)((double)s->kappa)), v, SPH__V(setzero)());
}

/* x_ij, r, W and F at h_i and h_j of the n listed lanes (zeros past them)
 * into b; xi the target's position, hiinv 1 / h_i, Oh and Ox the partners'
 * offsets in h and x. */
SPH__INLINE void sph__batch_vec(const sph_batch_src *S, const sph_real *xi, sph_real hiinv, const ptrdiff_t *Oh,
                                const ptrdiff_t *Ox, int n, sph_batch *b, const int D)
{
    const sph__vd zero = SPH__V(setzero)(), vhi = SPH__V(set1)((double)hiinv), alpha = SPH__V(set1)((double)S->alpha);
    const sph__vm all = sph__vfirst(SPH__VW);
    const int want[2] = {(S->what & SPH_BATCH_W) != 0, (S->what & SPH_BATCH_F) != 0};
    int l, a, d, G;
    for (l = 0; l < SPH_BATCH; l += SPH__VW) {
        const sph__vm valid = sph__vfirst(n - l);
        const sph__vd hjinv = SPH__V(div)(SPH__V(set1)(1), sph__vat(zero, all, S->h.p[0], Oh + l));
        sph__vd r2 = zero, r, q[2];
        for (a = 0; a < 3; ++a) {
            double *dxa = (double *)(void *)(b->dx[a] + l);
            sph__vd e;
            if (a >= D) {
                SPH__V(storeu)(dxa, zero);
                continue;
            }
            e = sph__vdx(SPH__V(set1)((double)xi[a]), S->x.p[a], SPH__V(set1)((double)S->P.L[a]),
                         SPH__V(set1)((double)S->P.invL[a]), all, Ox + l, 0);
            r2 = a > 0 ? SPH__V(add)(r2, SPH__V(mul)(e, e)) : SPH__V(mul)(e, e);
            SPH__V(storeu)(dxa, e);
        }
        r = sph__vsqrt(r2);
        SPH__V(storeu)((double *)(void *)(b->r + l), r);
        q[0] = SPH__V(mul)(r, vhi), q[1] = SPH__V(mul)(r, hjinv);
        for (G = 0; G < 2; ++G) { /* W = alpha w h^-dim (G 0), F = alpha g h^-(dim + 2) (G 1), as sph__hpow_lanes */
            double *vi = (double *)(void *)((G ? b->F_i : b->W_i) + l), *vj = (double *)(void *)((G ? b->F_j : b->W_j) + l);
            sph__vd pi, pj;
            if (!want[G]) {
                SPH__V(storeu)(vi, zero), SPH__V(storeu)(vj, zero);
                continue;
            }
            pi = SPH__V(mul)(alpha, sph__batch_wg(S->shape, G, q[0]));
            pj = SPH__V(mul)(alpha, sph__batch_wg(S->shape, G, q[1]));
            for (d = 0; d < D + 2 * G; ++d) pi = SPH__V(mul)(pi, vhi), pj = SPH__V(mul)(pj, hjinv);
            SPH__V(storeu)(vi, sph__vsel(valid, pi, zero)), SPH__V(storeu)(vj, sph__vsel(valid, pj, zero));
        }
    }
}
#endif

/* sph_batch_fill's work in D dimensions, D a constant in each call of its
 * switch, so that the loops over the axes and sph__hpow's powers unroll:
 * the pairs from position o0 of row i, left of them in the row. */
SPH__INLINE int sph__batch_fill_dim(const sph_batch_src *S, sph_idx i, sph_off o0, sph_off left, sph_batch *b,
                                    const int D)
{
    sph_real xi[3], r[SPH_BATCH], qi[SPH_BATCH], qj[SPH_BATCH], hjinv[SPH_BATCH], hiinv, alpha;
    sph_real Wi[SPH_BATCH], Fi[SPH_BATCH], Wj[SPH_BATCH], Fj[SPH_BATCH];
    sph_real xj[3][SPH_BATCH], hj[SPH_BATCH]; /* x_j, h_j gathered into contiguous lanes */
    sph_idx J[SPH_BATCH];
    ptrdiff_t Ox[SPH_BATCH], Oh[SPH_BATCH]; /* J[l] times the strides of x and h */
    const sph_neighbours *L = S->list;
    const sph_real *hp;
    ptrdiff_t hs, xs;
    const int n = left < SPH_BATCH ? (int)left : SPH_BATCH;
    int l, a, wW, wF;
    wW = (S->what & SPH_BATCH_W) != 0, wF = (S->what & SPH_BATCH_F) != 0;
    hp = S->h.p[0], hs = S->h.stride, xs = S->x.stride;
    sph__batch_index(L->index + o0, n, i, J);
    SPH__LANES
    for (l = 0; l < SPH_BATCH; ++l) Ox[l] = (ptrdiff_t)J[l] * xs;
    if (hs != xs) {
        SPH__LANES
        for (l = 0; l < SPH_BATCH; ++l) Oh[l] = (ptrdiff_t)J[l] * hs;
    }
    if (left > n) { /* the next batch's partners, on their way while this one computes */
        const sph_idx *Jn = L->index + o0 + n;
        const int nn = left - n < SPH_BATCH ? (int)(left - n) : SPH_BATCH;
        for (l = 0; l < nn; ++l) {
            SPH__PREFETCH(S->x.p[0] + (ptrdiff_t)Jn[l] * xs);
            SPH__PREFETCH(hp + (ptrdiff_t)Jn[l] * hs);
        }
    }
    sph__h_xi(S->x, D, i, xi);
    hiinv = 1 / hp[(ptrdiff_t)i * hs];
#if SPH__BATCH_VEC
    if (sizeof(sph_real) == sizeof(double)) {
        sph__batch_vec(S, xi, hiinv, hs != xs ? Oh : Ox, Ox, n, b, D);
        SPH__LANES
        for (l = 0; l < SPH_BATCH; ++l) b->j[l] = J[l], b->k[l] = l < n ? o0 + l : -1;
        b->n = n;
        return n;
    }
#endif
    sph__batch_gather(hp, hs != xs ? Oh : Ox, hj); /* the gathers, on their own: the loops below read contiguous lanes */
    for (a = 0; a < D; ++a) sph__batch_gather(S->x.p[a], Ox, xj[a]);
    for (a = 0; a < 3; ++a) {
        const sph_real *xa = xj[a], xia = xi[a], La = S->P.L[a], iLa = S->P.invL[a];
        sph_real dx[SPH_BATCH]; /* local: the compiler need not fear that b overlaps x */
        if (a >= D) {
            SPH__LANES
            for (l = 0; l < SPH_BATCH; ++l) b->dx[a][l] = 0;
            continue;
        }
        SPH__LANES
        for (l = 0; l < SPH_BATCH; ++l) dx[l] = xia - xa[l];
        if (La != 0) sph__image_chunk(dx, SPH_BATCH, La, iLa); /* the image of sph__h_dx */
        SPH__LANES
        for (l = 0; l < SPH_BATCH; ++l) r[l] = (a > 0 ? r[l] : 0) + dx[l] * dx[l]; /* a constant select, no zero loop */
        SPH__LANES
        for (l = 0; l < SPH_BATCH; ++l) b->dx[a][l] = dx[l];
    }
    sph_batch_sqrt(r); /* r^2, then r */
    SPH__LANES
    for (l = 0; l < SPH_BATCH; ++l) {
        hjinv[l] = 1 / hj[l];
        qi[l] = r[l] * hiinv;
        qj[l] = r[l] * hjinv[l];
    }
    alpha = S->alpha;
    if (wW) { /* sph__hpow(alpha w, 1/h, dim) */
        sph__nshape_wg_lanes(S->shape, qi, Wi, NULL);
        sph__nshape_wg_lanes(S->shape, qj, Wj, NULL);
        sph__hpow_lanes(Wi, Wj, alpha, hiinv, hjinv, D);
    }
    if (wF) { /* sph__hpow(alpha g, 1/h, dim + 2) */
        sph__nshape_wg_lanes(S->shape, qi, NULL, Fi);
        sph__nshape_wg_lanes(S->shape, qj, NULL, Fj);
        sph__hpow_lanes(Fi, Fj, alpha, hiinv, hjinv, D + 2);
    }
    SPH__LANES
    for (l = 0; l < SPH_BATCH; ++l) { /* padding and what is not asked for: 0 by selects (zero loops: rep stos) */
        const int v = l < n, vW = v & wW, vF = v & wF;
        b->j[l] = J[l];
        b->k[l] = v ? o0 + l : -1;
        b->r[l] = r[l];
        b->W_i[l] = vW ? Wi[l] : 0, b->F_i[l] = vF ? Fi[l] : 0, b->W_j[l] = vW ? Wj[l] : 0, b->F_j[l] = vF ? Fj[l] : 0;
    }
    b->n = n;
    return n;
}

/* (O0), (O1), (K1), (K2) for the next pairs of row i: fills *b with the
 * pairs *next .. *next + SPH_BATCH - 1 of the row (counted from the row's
 * start; start with *next = 0), advances *next past them and returns their
 * number b->n, 0 once the row is done. i outside 0..n-1, *next negative or
 * a NULL argument give an empty batch (0). The self pair j = i, if listed,
 * is a lane like the others (r = 0, dx = 0, W and F at q = 0). Every lane
 * loop runs over all SPH_BATCH lanes; padding lanes hold j = i, k = -1 and
 * zeros, so a sum over all lanes of terms proportional to dx, W or F may
 * include them. */
SPH_API int sph_batch_fill(const sph_batch_src *S, sph_idx i, sph_off *next, sph_batch *b)
{
    SPH__DISPATCH_TO(sph_batch_fill, (S, i, next, b))
    sph_off o0, left;
    if (b == NULL) return 0;
    b->n = 0;
    if (S == NULL || S->list == NULL || next == NULL || *next < 0 || i < 0 || i >= S->list->n_targets) return 0;
    o0 = S->list->offset[i] + *next;
    left = S->list->offset[i + 1] - o0;
    if (left <= 0) return 0;
    *next += left < SPH_BATCH ? left : SPH_BATCH;
    switch (S->dim) {
    case 1: return sph__batch_fill_dim(S, i, o0, left, b, 1);
    case 2: return sph__batch_fill_dim(S, i, o0, left, b, 2);
    default: return sph__batch_fill_dim(S, i, o0, left, b, 3);
    }
}
#undef SPH__PREFETCH

#endif /* section 9 */
#endif /* sections 5-9 */
#if defined(SPH__LV) /* the end of a pass */
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#undef SPH__SUFFIX
#undef SPH__FIRST
#undef SPH__ISA
#define SPH__ISA SPH__ISA_BUILD
#endif

#if !defined(SPH__LV) /* the build's own compile: the end of the header */
#define SPH__BODY_DONE
#if defined(SPH__FP_PUSHED)
#pragma STDC FP_CONTRACT DEFAULT
#undef SPH__FP_PUSHED
#endif
#if defined(SPH__DIAG_PUSHED)
#pragma GCC diagnostic pop
#undef SPH__DIAG_PUSHED
#endif

#ifdef __cplusplus
}
#endif

#endif
#endif /* sections 5-9 of this compile */

/* ---- SPH__NAMES: the function names of sections 5-9, mapped for a pass (1) or back (2) ---- */
/* isa-names: the names below are written by support/isa_names.sh (make isa-names) */
#if defined(SPH__NAMES) && SPH__NAMES == 1
#define sph__av_target SPH__LN(sph__av_target)
#define sph__axis_chunk SPH__LN(sph__axis_chunk)
#define sph__axpy SPH__LN(sph__axpy)
#define sph__batch_fill_dim SPH__LN(sph__batch_fill_dim)
#define sph__batch_gather SPH__LN(sph__batch_gather)
#define sph__batch_index SPH__LN(sph__batch_index)
#define sph__batch_vec SPH__LN(sph__batch_vec)
#define sph__batch_wg SPH__LN(sph__batch_wg)
#define sph__chunk_axpy SPH__LN(sph__chunk_axpy)
#define sph__chunk_correction SPH__LN(sph__chunk_correction)
#define sph__chunk_eval SPH__LN(sph__chunk_eval)
#define sph__chunk_next SPH__LN(sph__chunk_next)
#define sph__ddiff_target SPH__LN(sph__ddiff_target)
#define sph__dg SPH__LN(sph__dg)
#define sph__dgc_0 SPH__LN(sph__dgc_0)
#define sph__dgc_1 SPH__LN(sph__dgc_1)
#define sph__dgc_10 SPH__LN(sph__dgc_10)
#define sph__dgc_2 SPH__LN(sph__dgc_2)
#define sph__dgc_3 SPH__LN(sph__dgc_3)
#define sph__dgc_4 SPH__LN(sph__dgc_4)
#define sph__dgc_5 SPH__LN(sph__dgc_5)
#define sph__dgc_6 SPH__LN(sph__dgc_6)
#define sph__dgc_7 SPH__LN(sph__dgc_7)
#define sph__dgc_8 SPH__LN(sph__dgc_8)
#define sph__dgc_9 SPH__LN(sph__dgc_9)
#define sph__dgc_body SPH__LN(sph__dgc_body)
#define sph__dgv_0 SPH__LN(sph__dgv_0)
#define sph__dgv_1 SPH__LN(sph__dgv_1)
#define sph__dgv_10 SPH__LN(sph__dgv_10)
#define sph__dgv_2 SPH__LN(sph__dgv_2)
#define sph__dgv_3 SPH__LN(sph__dgv_3)
#define sph__dgv_4 SPH__LN(sph__dgv_4)
#define sph__dgv_5 SPH__LN(sph__dgv_5)
#define sph__dgv_6 SPH__LN(sph__dgv_6)
#define sph__dgv_7 SPH__LN(sph__dgv_7)
#define sph__dgv_8 SPH__LN(sph__dgv_8)
#define sph__dgv_9 SPH__LN(sph__dgv_9)
#define sph__dgv_body SPH__LN(sph__dgv_body)
#define sph__dot SPH__LN(sph__dot)
#define sph__end_divcurl SPH__LN(sph__end_divcurl)
#define sph__end_grad SPH__LN(sph__end_grad)
#define sph__end_sum SPH__LN(sph__end_sum)
#define sph__end_tensor SPH__LN(sph__end_tensor)
#define sph__fast_CORRECTION SPH__LN(sph__fast_CORRECTION)
#define sph__fast_CURL_DIFF SPH__LN(sph__fast_CURL_DIFF)
#define sph__fast_CURL_STD SPH__LN(sph__fast_CURL_STD)
#define sph__fast_DENSITY SPH__LN(sph__fast_DENSITY)
#define sph__fast_DENS_GRAD SPH__LN(sph__fast_DENS_GRAD)
#define sph__fast_DIFFUSION SPH__LN(sph__fast_DIFFUSION)
#define sph__fast_DIV_CORR SPH__LN(sph__fast_DIV_CORR)
#define sph__fast_DIV_DIFF SPH__LN(sph__fast_DIV_DIFF)
#define sph__fast_DIV_STD SPH__LN(sph__fast_DIV_STD)
#define sph__fast_GRADV_CORR SPH__LN(sph__fast_GRADV_CORR)
#define sph__fast_GRADV_DIFF SPH__LN(sph__fast_GRADV_DIFF)
#define sph__fast_GRADV_STD SPH__LN(sph__fast_GRADV_STD)
#define sph__fast_GRADV_SYM SPH__LN(sph__fast_GRADV_SYM)
#define sph__fast_GRAD_CORR SPH__LN(sph__fast_GRAD_CORR)
#define sph__fast_GRAD_DIFF SPH__LN(sph__fast_GRAD_DIFF)
#define sph__fast_GRAD_PRES SPH__LN(sph__fast_GRAD_PRES)
#define sph__fast_GRAD_STD SPH__LN(sph__fast_GRAD_STD)
#define sph__fast_GRAD_SYM SPH__LN(sph__fast_GRAD_SYM)
#define sph__fast_INTERP SPH__LN(sph__fast_INTERP)
#define sph__fast_LAPLACIAN SPH__LN(sph__fast_LAPLACIAN)
#define sph__fast_SHEPARD SPH__LN(sph__fast_SHEPARD)
#define sph__fast_divcurl SPH__LN(sph__fast_divcurl)
#define sph__fast_grad SPH__LN(sph__fast_grad)
#define sph__fast_lap SPH__LN(sph__fast_lap)
#define sph__fast_sum SPH__LN(sph__fast_sum)
#define sph__fast_tensor SPH__LN(sph__fast_tensor)
#define sph__fi SPH__LN(sph__fi)
#define sph__field SPH__LN(sph__field)
#define sph__finish SPH__LN(sph__finish)
#define sph__fp_contracted SPH__LN(sph__fp_contracted)
#define sph__gradh_check SPH__LN(sph__gradh_check)
#define sph__gradh_pair SPH__LN(sph__gradh_pair)
#define sph__h_dx SPH__LN(sph__h_dx)
#define sph__h_particle SPH__LN(sph__h_particle)
#define sph__h_sums SPH__LN(sph__h_sums)
#define sph__h_sums_0 SPH__LN(sph__h_sums_0)
#define sph__h_sums_1 SPH__LN(sph__h_sums_1)
#define sph__h_sums_10 SPH__LN(sph__h_sums_10)
#define sph__h_sums_2 SPH__LN(sph__h_sums_2)
#define sph__h_sums_3 SPH__LN(sph__h_sums_3)
#define sph__h_sums_4 SPH__LN(sph__h_sums_4)
#define sph__h_sums_5 SPH__LN(sph__h_sums_5)
#define sph__h_sums_6 SPH__LN(sph__h_sums_6)
#define sph__h_sums_7 SPH__LN(sph__h_sums_7)
#define sph__h_sums_8 SPH__LN(sph__h_sums_8)
#define sph__h_sums_9 SPH__LN(sph__h_sums_9)
#define sph__h_sums_body SPH__LN(sph__h_sums_body)
#define sph__h_sums_ref SPH__LN(sph__h_sums_ref)
#define sph__h_xi SPH__LN(sph__h_xi)
#define sph__hctx_check SPH__LN(sph__hctx_check)
#define sph__hij_chunk SPH__LN(sph__hij_chunk)
#define sph__hpow_lanes SPH__LN(sph__hpow_lanes)
#define sph__hsv_0 SPH__LN(sph__hsv_0)
#define sph__hsv_1 SPH__LN(sph__hsv_1)
#define sph__hsv_10 SPH__LN(sph__hsv_10)
#define sph__hsv_2 SPH__LN(sph__hsv_2)
#define sph__hsv_3 SPH__LN(sph__hsv_3)
#define sph__hsv_4 SPH__LN(sph__hsv_4)
#define sph__hsv_5 SPH__LN(sph__hsv_5)
#define sph__hsv_6 SPH__LN(sph__hsv_6)
#define sph__hsv_7 SPH__LN(sph__hsv_7)
#define sph__hsv_8 SPH__LN(sph__hsv_8)
#define sph__hsv_9 SPH__LN(sph__hsv_9)
#define sph__hsv_body SPH__LN(sph__hsv_body)
#define sph__image_chunk SPH__LN(sph__image_chunk)
#define sph__norm1 SPH__LN(sph__norm1)
#define sph__ns_absmax SPH__LN(sph__ns_absmax)
#define sph__ns_at SPH__LN(sph__ns_at)
#define sph__ns_below16 SPH__LN(sph__ns_below16)
#define sph__ns_check_h SPH__LN(sph__ns_check_h)
#define sph__ns_check_perm SPH__LN(sph__ns_check_perm)
#define sph__ns_check_x SPH__LN(sph__ns_check_x)
#define sph__ns_ctz SPH__LN(sph__ns_ctz)
#define sph__ns_ext_lanes SPH__LN(sph__ns_ext_lanes)
#define sph__ns_image SPH__LN(sph__ns_image)
#define sph__ns_live16 SPH__LN(sph__ns_live16)
#define sph__ns_merge SPH__LN(sph__ns_merge)
#define sph__ns_merge_buf SPH__LN(sph__ns_merge_buf)
#define sph__ns_merge_row SPH__LN(sph__ns_merge_row)
#define sph__ns_offsets SPH__LN(sph__ns_offsets)
#define sph__ns_popcount SPH__LN(sph__ns_popcount)
#define sph__ns_put_marks SPH__LN(sph__ns_put_marks)
#define sph__ns_rank_sort SPH__LN(sph__ns_rank_sort)
#define sph__ns_scan_x SPH__LN(sph__ns_scan_x)
#define sph__ns_signs SPH__LN(sph__ns_signs)
#define sph__ns_sort SPH__LN(sph__ns_sort)
#define sph__ns_sort_as SPH__LN(sph__ns_sort_as)
#define sph__ns_tail SPH__LN(sph__ns_tail)
#define sph__ns_turn SPH__LN(sph__ns_turn)
#define sph__ns_unmark SPH__LN(sph__ns_unmark)
#define sph__ns_unmark16 SPH__LN(sph__ns_unmark16)
#define sph__ns_up SPH__LN(sph__ns_up)
#define sph__nsearch_axes SPH__LN(sph__nsearch_axes)
#define sph__nsearch_block SPH__LN(sph__nsearch_block)
#define sph__nsearch_blocks SPH__LN(sph__nsearch_blocks)
#define sph__nsearch_build_as SPH__LN(sph__nsearch_build_as)
#define sph__nsearch_cell SPH__LN(sph__nsearch_cell)
#define sph__nsearch_check SPH__LN(sph__nsearch_check)
#define sph__nsearch_delta SPH__LN(sph__nsearch_delta)
#define sph__nsearch_dilate SPH__LN(sph__nsearch_dilate)
#define sph__nsearch_eps SPH__LN(sph__nsearch_eps)
#define sph__nsearch_far SPH__LN(sph__nsearch_far)
#define sph__nsearch_flush SPH__LN(sph__nsearch_flush)
#define sph__nsearch_gap SPH__LN(sph__nsearch_gap)
#define sph__nsearch_gap2 SPH__LN(sph__nsearch_gap2)
#define sph__nsearch_general SPH__LN(sph__nsearch_general)
#define sph__nsearch_geometry SPH__LN(sph__nsearch_geometry)
#define sph__nsearch_hbuild SPH__LN(sph__nsearch_hbuild)
#define sph__nsearch_image SPH__LN(sph__nsearch_image)
#define sph__nsearch_in SPH__LN(sph__nsearch_in)
#define sph__nsearch_in_own SPH__LN(sph__nsearch_in_own)
#define sph__nsearch_interior SPH__LN(sph__nsearch_interior)
#define sph__nsearch_keep SPH__LN(sph__nsearch_keep)
#define sph__nsearch_layout SPH__LN(sph__nsearch_layout)
#define sph__nsearch_line SPH__LN(sph__nsearch_line)
#define sph__nsearch_lists_ref SPH__LN(sph__nsearch_lists_ref)
#define sph__nsearch_mask SPH__LN(sph__nsearch_mask)
#define sph__nsearch_mask16 SPH__LN(sph__nsearch_mask16)
#define sph__nsearch_model SPH__LN(sph__nsearch_model)
#define sph__nsearch_pick SPH__LN(sph__nsearch_pick)
#define sph__nsearch_probe SPH__LN(sph__nsearch_probe)
#define sph__nsearch_push_reach SPH__LN(sph__nsearch_push_reach)
#define sph__nsearch_put SPH__LN(sph__nsearch_put)
#define sph__nsearch_r2 SPH__LN(sph__nsearch_r2)
#define sph__nsearch_reach SPH__LN(sph__nsearch_reach)
#define sph__nsearch_rel SPH__LN(sph__nsearch_rel)
#define sph__nsearch_room SPH__LN(sph__nsearch_room)
#define sph__nsearch_row SPH__LN(sph__nsearch_row)
#define sph__nsearch_run SPH__LN(sph__nsearch_run)
#define sph__nsearch_run_blocks SPH__LN(sph__nsearch_run_blocks)
#define sph__nsearch_runs SPH__LN(sph__nsearch_runs)
#define sph__nsearch_source_cell SPH__LN(sph__nsearch_source_cell)
#define sph__nsearch_span SPH__LN(sph__nsearch_span)
#define sph__nsearch_store SPH__LN(sph__nsearch_store)
#define sph__nsearch_sym_count SPH__LN(sph__nsearch_sym_count)
#define sph__nsearch_sym_fill SPH__LN(sph__nsearch_sym_fill)
#define sph__nsearch_sym_finish SPH__LN(sph__nsearch_sym_finish)
#define sph__nsearch_sym_lists SPH__LN(sph__nsearch_sym_lists)
#define sph__nsearch_sym_ok SPH__LN(sph__nsearch_sym_ok)
#define sph__nsearch_sym_past SPH__LN(sph__nsearch_sym_past)
#define sph__nsearch_sym_scan SPH__LN(sph__nsearch_sym_scan)
#define sph__nsearch_sym_scan_blocks SPH__LN(sph__nsearch_sym_scan_blocks)
#define sph__nsearch_target SPH__LN(sph__nsearch_target)
#define sph__nshape_vpick SPH__LN(sph__nshape_vpick)
#define sph__nsv SPH__LN(sph__nsv)
#define sph__nsv_abs SPH__LN(sph__nsv_abs)
#define sph__nsv_gt SPH__LN(sph__nsv_gt)
#define sph__nsv_load SPH__LN(sph__nsv_load)
#define sph__nsv_loadf SPH__LN(sph__nsv_loadf)
#define sph__nsv_lt SPH__LN(sph__nsv_lt)
#define sph__nsv_max SPH__LN(sph__nsv_max)
#define sph__nsv_nge SPH__LN(sph__nsv_nge)
#define sph__nsv_round SPH__LN(sph__nsv_round)
#define sph__op_h SPH__LN(sph__op_h)
#define sph__out_ok SPH__LN(sph__out_ok)
#define sph__out_opt SPH__LN(sph__out_opt)
#define sph__pair SPH__LN(sph__pair)
#define sph__pairs_add_k SPH__LN(sph__pairs_add_k)
#define sph__pairs_reduce SPH__LN(sph__pairs_reduce)
#define sph__pairs_sum SPH__LN(sph__pairs_sum)
#define sph__period_of SPH__LN(sph__period_of)
#define sph__pform_vec SPH__LN(sph__pform_vec)
#define sph__prune_row SPH__LN(sph__prune_row)
#define sph__r_chunk SPH__LN(sph__r_chunk)
#define sph__ref_divcurl SPH__LN(sph__ref_divcurl)
#define sph__ref_grad SPH__LN(sph__ref_grad)
#define sph__ref_lap SPH__LN(sph__ref_lap)
#define sph__ref_sum SPH__LN(sph__ref_sum)
#define sph__ref_tensor SPH__LN(sph__ref_tensor)
#define sph__run SPH__LN(sph__run)
#define sph__run_fast SPH__LN(sph__run_fast)
#define sph__run_reference SPH__LN(sph__run_reference)
#define sph__scan SPH__LN(sph__scan)
#define sph__setup SPH__LN(sph__setup)
#define sph__shape_chunk SPH__LN(sph__shape_chunk)
#define sph__shape_run SPH__LN(sph__shape_run)
#define sph__shape_run0 SPH__LN(sph__shape_run0)
#define sph__shape_run1 SPH__LN(sph__shape_run1)
#define sph__shape_run10 SPH__LN(sph__shape_run10)
#define sph__shape_run2 SPH__LN(sph__shape_run2)
#define sph__shape_run3 SPH__LN(sph__shape_run3)
#define sph__shape_run4 SPH__LN(sph__shape_run4)
#define sph__shape_run5 SPH__LN(sph__shape_run5)
#define sph__shape_run6 SPH__LN(sph__shape_run6)
#define sph__shape_run7 SPH__LN(sph__shape_run7)
#define sph__shape_run8 SPH__LN(sph__shape_run8)
#define sph__shape_run9 SPH__LN(sph__shape_run9)
#define sph__sqrt_chunk SPH__LN(sph__sqrt_chunk)
#define sph__switch_field SPH__LN(sph__switch_field)
#define sph__switch_one SPH__LN(sph__switch_one)
#define sph__target_opt SPH__LN(sph__target_opt)
#define sph__tinit SPH__LN(sph__tinit)
#define sph__vand SPH__LN(sph__vand)
#define sph__vat SPH__LN(sph__vat)
#define sph__vd SPH__LN(sph__vd)
#define sph__vdx SPH__LN(sph__vdx)
#define sph__vfirst SPH__LN(sph__vfirst)
#define sph__vfloor SPH__LN(sph__vfloor)
#define sph__vge SPH__LN(sph__vge)
#define sph__vidx SPH__LN(sph__vidx)
#define sph__view_ok SPH__LN(sph__view_ok)
#define sph__visc_target SPH__LN(sph__visc_target)
#define sph__vlt SPH__LN(sph__vlt)
#define sph__vm SPH__LN(sph__vm)
#define sph__vpair SPH__LN(sph__vpair)
#define sph__vsel SPH__LN(sph__vsel)
#define sph__vsqrt SPH__LN(sph__vsqrt)
#define sph__vsum SPH__LN(sph__vsum)
#define sph__vtarget SPH__LN(sph__vtarget)
#define sph__w_approach SPH__LN(sph__w_approach)
#define sph__wall_target SPH__LN(sph__wall_target)
#define sph_artificial_viscosity SPH__LN(sph_artificial_viscosity)
#define sph_av_init SPH__LN(sph_av_init)
#define sph_batch_fill SPH__LN(sph_batch_fill)
#define sph_batch_select SPH__LN(sph_batch_select)
#define sph_batch_source SPH__LN(sph_batch_source)
#define sph_batch_sqrt SPH__LN(sph_batch_sqrt)
#define sph_check_field SPH__LN(sph_check_field)
#define sph_correction_invert SPH__LN(sph_correction_invert)
#define sph_correction_matrix SPH__LN(sph_correction_matrix)
#define sph_ctx_init SPH__LN(sph_ctx_init)
#define sph_curl SPH__LN(sph_curl)
#define sph_density SPH__LN(sph_density)
#define sph_density_diffusion SPH__LN(sph_density_diffusion)
#define sph_density_gradient SPH__LN(sph_density_gradient)
#define sph_diffusion SPH__LN(sph_diffusion)
#define sph_divergence SPH__LN(sph_divergence)
#define sph_dt_coef_default SPH__LN(sph_dt_coef_default)
#define sph_dt_input_init SPH__LN(sph_dt_input_init)
#define sph_dt_limit SPH__LN(sph_dt_limit)
#define sph_dt_reason_name SPH__LN(sph_dt_reason_name)
#define sph_gradh_factor SPH__LN(sph_gradh_factor)
#define sph_gradh_forces SPH__LN(sph_gradh_forces)
#define sph_gradh_forces_pairs SPH__LN(sph_gradh_forces_pairs)
#define sph_gradh_pairs_buffer_len SPH__LN(sph_gradh_pairs_buffer_len)
#define sph_gradient SPH__LN(sph_gradient)
#define sph_gradient_vector SPH__LN(sph_gradient_vector)
#define sph_h_solve SPH__LN(sph_h_solve)
#define sph_harmonic_k SPH__LN(sph_harmonic_k)
#define sph_hctx_init SPH__LN(sph_hctx_init)
#define sph_interpolate SPH__LN(sph_interpolate)
#define sph_interpolate_shepard SPH__LN(sph_interpolate_shepard)
#define sph_laplacian SPH__LN(sph_laplacian)
#define sph_nsearch_build SPH__LN(sph_nsearch_build)
#define sph_nsearch_count SPH__LN(sph_nsearch_count)
#define sph_nsearch_fill SPH__LN(sph_nsearch_fill)
#define sph_nsearch_list SPH__LN(sph_nsearch_list)
#define sph_nsearch_lists SPH__LN(sph_nsearch_lists)
#define sph_nsearch_permutation SPH__LN(sph_nsearch_permutation)
#define sph_nsearch_prune SPH__LN(sph_nsearch_prune)
#define sph_nsearch_skin SPH__LN(sph_nsearch_skin)
#define sph_nsearch_stats SPH__LN(sph_nsearch_stats)
#define sph_nsearch_workspace_size SPH__LN(sph_nsearch_workspace_size)
#define sph_pair_av_alpha SPH__LN(sph_pair_av_alpha)
#define sph_pair_av_apply SPH__LN(sph_pair_av_apply)
#define sph_pair_av_monaghan SPH__LN(sph_pair_av_monaghan)
#define sph_pair_av_signal SPH__LN(sph_pair_av_signal)
#define sph_pair_correction SPH__LN(sph_pair_correction)
#define sph_pair_curl SPH__LN(sph_pair_curl)
#define sph_pair_density SPH__LN(sph_pair_density)
#define sph_pair_density_diffusion SPH__LN(sph_pair_density_diffusion)
#define sph_pair_diffusion SPH__LN(sph_pair_diffusion)
#define sph_pair_div_difference SPH__LN(sph_pair_div_difference)
#define sph_pair_div_standard SPH__LN(sph_pair_div_standard)
#define sph_pair_grad_difference SPH__LN(sph_pair_grad_difference)
#define sph_pair_grad_pressure SPH__LN(sph_pair_grad_pressure)
#define sph_pair_grad_standard SPH__LN(sph_pair_grad_standard)
#define sph_pair_grad_symmetric SPH__LN(sph_pair_grad_symmetric)
#define sph_pair_gradh_energy SPH__LN(sph_pair_gradh_energy)
#define sph_pair_gradh_pressure SPH__LN(sph_pair_gradh_pressure)
#define sph_pair_interpolate SPH__LN(sph_pair_interpolate)
#define sph_pair_kernel SPH__LN(sph_pair_kernel)
#define sph_pair_laplacian SPH__LN(sph_pair_laplacian)
#define sph_pair_signal_velocity SPH__LN(sph_pair_signal_velocity)
#define sph_pair_viscosity SPH__LN(sph_pair_viscosity)
#define sph_pair_wall SPH__LN(sph_pair_wall)
#define sph_pairs_buffer_len SPH__LN(sph_pairs_buffer_len)
#define sph_pairs_build SPH__LN(sph_pairs_build)
#define sph_pairs_reduce SPH__LN(sph_pairs_reduce)
#define sph_pairs_reduce_rows SPH__LN(sph_pairs_reduce_rows)
#define sph_pairs_reduce_rows_k SPH__LN(sph_pairs_reduce_rows_k)
#define sph_permutation_invert SPH__LN(sph_permutation_invert)
#define sph_permute SPH__LN(sph_permute)
#define sph_pressure_factor SPH__LN(sph_pressure_factor)
#define sph_switch_balsara SPH__LN(sph_switch_balsara)
#define sph_switch_conductivity SPH__LN(sph_switch_conductivity)
#define sph_switch_default SPH__LN(sph_switch_default)
#define sph_switch_input_init SPH__LN(sph_switch_input_init)
#define sph_switch_mm97 SPH__LN(sph_switch_mm97)
#define sph_switch_sphenix SPH__LN(sph_switch_sphenix)
#define sph_switch_update SPH__LN(sph_switch_update)
#define sph_time_step SPH__LN(sph_time_step)
#define sph_view_none SPH__LN(sph_view_none)
#define sph_viscosity SPH__LN(sph_viscosity)
#define sph_wall_adami SPH__LN(sph_wall_adami)
#define sph_wall_end SPH__LN(sph_wall_end)
#define sph_wall_init SPH__LN(sph_wall_init)
#elif defined(SPH__NAMES) && SPH__NAMES == 2
#undef sph__av_target
#undef sph__axis_chunk
#undef sph__axpy
#undef sph__batch_fill_dim
#undef sph__batch_gather
#undef sph__batch_index
#undef sph__batch_vec
#undef sph__batch_wg
#undef sph__chunk_axpy
#undef sph__chunk_correction
#undef sph__chunk_eval
#undef sph__chunk_next
#undef sph__ddiff_target
#undef sph__dg
#undef sph__dgc_0
#undef sph__dgc_1
#undef sph__dgc_10
#undef sph__dgc_2
#undef sph__dgc_3
#undef sph__dgc_4
#undef sph__dgc_5
#undef sph__dgc_6
#undef sph__dgc_7
#undef sph__dgc_8
#undef sph__dgc_9
#undef sph__dgc_body
#undef sph__dgv_0
#undef sph__dgv_1
#undef sph__dgv_10
#undef sph__dgv_2
#undef sph__dgv_3
#undef sph__dgv_4
#undef sph__dgv_5
#undef sph__dgv_6
#undef sph__dgv_7
#undef sph__dgv_8
#undef sph__dgv_9
#undef sph__dgv_body
#undef sph__dot
#undef sph__end_divcurl
#undef sph__end_grad
#undef sph__end_sum
#undef sph__end_tensor
#undef sph__fast_CORRECTION
#undef sph__fast_CURL_DIFF
#undef sph__fast_CURL_STD
#undef sph__fast_DENSITY
#undef sph__fast_DENS_GRAD
#undef sph__fast_DIFFUSION
#undef sph__fast_DIV_CORR
#undef sph__fast_DIV_DIFF
#undef sph__fast_DIV_STD
#undef sph__fast_GRADV_CORR
#undef sph__fast_GRADV_DIFF
#undef sph__fast_GRADV_STD
#undef sph__fast_GRADV_SYM
#undef sph__fast_GRAD_CORR
#undef sph__fast_GRAD_DIFF
#undef sph__fast_GRAD_PRES
#undef sph__fast_GRAD_STD
#undef sph__fast_GRAD_SYM
#undef sph__fast_INTERP
#undef sph__fast_LAPLACIAN
#undef sph__fast_SHEPARD
#undef sph__fast_divcurl
#undef sph__fast_grad
#undef sph__fast_lap
#undef sph__fast_sum
#undef sph__fast_tensor
#undef sph__fi
#undef sph__field
#undef sph__finish
#undef sph__fp_contracted
#undef sph__gradh_check
#undef sph__gradh_pair
#undef sph__h_dx
#undef sph__h_particle
#undef sph__h_sums
#undef sph__h_sums_0
#undef sph__h_sums_1
#undef sph__h_sums_10
#undef sph__h_sums_2
#undef sph__h_sums_3
#undef sph__h_sums_4
#undef sph__h_sums_5
#undef sph__h_sums_6
#undef sph__h_sums_7
#undef sph__h_sums_8
#undef sph__h_sums_9
#undef sph__h_sums_body
#undef sph__h_sums_ref
#undef sph__h_xi
#undef sph__hctx_check
#undef sph__hij_chunk
#undef sph__hpow_lanes
#undef sph__hsv_0
#undef sph__hsv_1
#undef sph__hsv_10
#undef sph__hsv_2
#undef sph__hsv_3
#undef sph__hsv_4
#undef sph__hsv_5
#undef sph__hsv_6
#undef sph__hsv_7
#undef sph__hsv_8
#undef sph__hsv_9
#undef sph__hsv_body
#undef sph__image_chunk
#undef sph__norm1
#undef sph__ns_absmax
#undef sph__ns_at
#undef sph__ns_below16
#undef sph__ns_check_h
#undef sph__ns_check_perm
#undef sph__ns_check_x
#undef sph__ns_ctz
#undef sph__ns_ext_lanes
#undef sph__ns_image
#undef sph__ns_live16
#undef sph__ns_merge
#undef sph__ns_merge_buf
#undef sph__ns_merge_row
#undef sph__ns_offsets
#undef sph__ns_popcount
#undef sph__ns_put_marks
#undef sph__ns_rank_sort
#undef sph__ns_scan_x
#undef sph__ns_signs
#undef sph__ns_sort
#undef sph__ns_sort_as
#undef sph__ns_tail
#undef sph__ns_turn
#undef sph__ns_unmark
#undef sph__ns_unmark16
#undef sph__ns_up
#undef sph__nsearch_axes
#undef sph__nsearch_block
#undef sph__nsearch_blocks
#undef sph__nsearch_build_as
#undef sph__nsearch_cell
#undef sph__nsearch_check
#undef sph__nsearch_delta
#undef sph__nsearch_dilate
#undef sph__nsearch_eps
#undef sph__nsearch_far
#undef sph__nsearch_flush
#undef sph__nsearch_gap
#undef sph__nsearch_gap2
#undef sph__nsearch_general
#undef sph__nsearch_geometry
#undef sph__nsearch_hbuild
#undef sph__nsearch_image
#undef sph__nsearch_in
#undef sph__nsearch_in_own
#undef sph__nsearch_interior
#undef sph__nsearch_keep
#undef sph__nsearch_layout
#undef sph__nsearch_line
#undef sph__nsearch_lists_ref
#undef sph__nsearch_mask
#undef sph__nsearch_mask16
#undef sph__nsearch_model
#undef sph__nsearch_pick
#undef sph__nsearch_probe
#undef sph__nsearch_push_reach
#undef sph__nsearch_put
#undef sph__nsearch_r2
#undef sph__nsearch_reach
#undef sph__nsearch_rel
#undef sph__nsearch_room
#undef sph__nsearch_row
#undef sph__nsearch_run
#undef sph__nsearch_run_blocks
#undef sph__nsearch_runs
#undef sph__nsearch_source_cell
#undef sph__nsearch_span
#undef sph__nsearch_store
#undef sph__nsearch_sym_count
#undef sph__nsearch_sym_fill
#undef sph__nsearch_sym_finish
#undef sph__nsearch_sym_lists
#undef sph__nsearch_sym_ok
#undef sph__nsearch_sym_past
#undef sph__nsearch_sym_scan
#undef sph__nsearch_sym_scan_blocks
#undef sph__nsearch_target
#undef sph__nshape_vpick
#undef sph__nsv
#undef sph__nsv_abs
#undef sph__nsv_gt
#undef sph__nsv_load
#undef sph__nsv_loadf
#undef sph__nsv_lt
#undef sph__nsv_max
#undef sph__nsv_nge
#undef sph__nsv_round
#undef sph__op_h
#undef sph__out_ok
#undef sph__out_opt
#undef sph__pair
#undef sph__pairs_add_k
#undef sph__pairs_reduce
#undef sph__pairs_sum
#undef sph__period_of
#undef sph__pform_vec
#undef sph__prune_row
#undef sph__r_chunk
#undef sph__ref_divcurl
#undef sph__ref_grad
#undef sph__ref_lap
#undef sph__ref_sum
#undef sph__ref_tensor
#undef sph__run
#undef sph__run_fast
#undef sph__run_reference
#undef sph__scan
#undef sph__setup
#undef sph__shape_chunk
#undef sph__shape_run
#undef sph__shape_run0
#undef sph__shape_run1
#undef sph__shape_run10
#undef sph__shape_run2
#undef sph__shape_run3
#undef sph__shape_run4
#undef sph__shape_run5
#undef sph__shape_run6
#undef sph__shape_run7
#undef sph__shape_run8
#undef sph__shape_run9
#undef sph__sqrt_chunk
#undef sph__switch_field
#undef sph__switch_one
#undef sph__target_opt
#undef sph__tinit
#undef sph__vand
#undef sph__vat
#undef sph__vd
#undef sph__vdx
#undef sph__vfirst
#undef sph__vfloor
#undef sph__vge
#undef sph__vidx
#undef sph__view_ok
#undef sph__visc_target
#undef sph__vlt
#undef sph__vm
#undef sph__vpair
#undef sph__vsel
#undef sph__vsqrt
#undef sph__vsum
#undef sph__vtarget
#undef sph__w_approach
#undef sph__wall_target
#undef sph_artificial_viscosity
#undef sph_av_init
#undef sph_batch_fill
#undef sph_batch_select
#undef sph_batch_source
#undef sph_batch_sqrt
#undef sph_check_field
#undef sph_correction_invert
#undef sph_correction_matrix
#undef sph_ctx_init
#undef sph_curl
#undef sph_density
#undef sph_density_diffusion
#undef sph_density_gradient
#undef sph_diffusion
#undef sph_divergence
#undef sph_dt_coef_default
#undef sph_dt_input_init
#undef sph_dt_limit
#undef sph_dt_reason_name
#undef sph_gradh_factor
#undef sph_gradh_forces
#undef sph_gradh_forces_pairs
#undef sph_gradh_pairs_buffer_len
#undef sph_gradient
#undef sph_gradient_vector
#undef sph_h_solve
#undef sph_harmonic_k
#undef sph_hctx_init
#undef sph_interpolate
#undef sph_interpolate_shepard
#undef sph_laplacian
#undef sph_nsearch_build
#undef sph_nsearch_count
#undef sph_nsearch_fill
#undef sph_nsearch_list
#undef sph_nsearch_lists
#undef sph_nsearch_permutation
#undef sph_nsearch_prune
#undef sph_nsearch_skin
#undef sph_nsearch_stats
#undef sph_nsearch_workspace_size
#undef sph_pair_av_alpha
#undef sph_pair_av_apply
#undef sph_pair_av_monaghan
#undef sph_pair_av_signal
#undef sph_pair_correction
#undef sph_pair_curl
#undef sph_pair_density
#undef sph_pair_density_diffusion
#undef sph_pair_diffusion
#undef sph_pair_div_difference
#undef sph_pair_div_standard
#undef sph_pair_grad_difference
#undef sph_pair_grad_pressure
#undef sph_pair_grad_standard
#undef sph_pair_grad_symmetric
#undef sph_pair_gradh_energy
#undef sph_pair_gradh_pressure
#undef sph_pair_interpolate
#undef sph_pair_kernel
#undef sph_pair_laplacian
#undef sph_pair_signal_velocity
#undef sph_pair_viscosity
#undef sph_pair_wall
#undef sph_pairs_buffer_len
#undef sph_pairs_build
#undef sph_pairs_reduce
#undef sph_pairs_reduce_rows
#undef sph_pairs_reduce_rows_k
#undef sph_permutation_invert
#undef sph_permute
#undef sph_pressure_factor
#undef sph_switch_balsara
#undef sph_switch_conductivity
#undef sph_switch_default
#undef sph_switch_input_init
#undef sph_switch_mm97
#undef sph_switch_sphenix
#undef sph_switch_update
#undef sph_time_step
#undef sph_view_none
#undef sph_viscosity
#undef sph_wall_adami
#undef sph_wall_end
#undef sph_wall_init
#endif
/* isa-names end */

/*
 * MIT License. Copyright (c) 2026 The sph_kernel.h authors. Permission is hereby
 * granted, free of charge, to any person obtaining a copy of this software, to
 * deal in it without restriction, subject to including this notice; THE
 * SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND. Full text: LICENSE.
 */
