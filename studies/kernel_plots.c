/* studies/kernel_plots.c - data for the kernel plots of docs/kernels.md (`make plots`).
 *
 * Usage: kernel_plots [directory]   (default build/plots; it must exist)
 *
 * Writes, for d = 2 and 3, two tables of W, dW/dr and d2W/dr2 against r
 * (docs/kernels.md eq. (K1), (K3), (K4)) for every kernel:
 *   kernels_<d>d_equal_h.dat      all kernels at h = 1;
 *   kernels_<d>d_equal_sigma.dat  kernel k at h_k = sigma_ref / sigma_k, with
 *                                 sigma_ref = the cubic spline's sigma/h, so
 *                                 every kernel has the standard deviation of
 *                                 the cubic at h = 1 (eq. (K5)).
 * Columns: r, then W, dW/dr, d2W/dr2 of each kernel in enum order.
 * Also new_quartic_tail.dat: q, w(q), w'(q) of the new quartic on [1.5, 2]
 * (its negative dip near the support edge).
 */
#include <stdio.h>

#include "sph_kernel.h"

#define R_MAX 3.0 /* the largest support at h = 1 (quintic, kappa = 3) */
#define N_ROWS 600

/* One table of W, dW/dr, d2W/dr2 against r for all kernels; h[k] per kernel. */
static int write_table(const char *dir, const char *name, int dim, const double *h)
{
    char path[1024];
    FILE *f;
    int i, k;
    sprintf(path, "%.900s/%s", dir, name);
    f = fopen(path, "w");
    if (f == NULL) {
        fprintf(stderr, "kernel_plots: cannot write %s\n", path);
        return 1;
    }
    fprintf(f, "# %d-D: r, then W dW/dr d2W/dr2 for each kernel; h per kernel:", dim);
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        fprintf(f, " %s %.6f", sph_kernel_name((sph_kernel)k), h[k]);
    fprintf(f, "\n");
    for (i = 0; i <= N_ROWS; ++i) {
        const double r = R_MAX * i / N_ROWS;
        fprintf(f, "%.6f", r);
        for (k = 0; k < SPH_KERNEL_COUNT; ++k) {
            const sph_kernel kk = (sph_kernel)k;
            const sph_real rr = (sph_real)r, hh = (sph_real)h[k];
            fprintf(f, " %.9e %.9e %.9e", (double)sph_kernel_w(kk, dim, rr, hh),
                    (double)sph_kernel_dwdr(kk, dim, rr, hh),
                    (double)sph_kernel_d2wdr2(kk, dim, rr, hh));
        }
        fprintf(f, "\n");
    }
    fclose(f);
    printf("wrote %s\n", path);
    return 0;
}

/* The new quartic's dimensionless w(q) = W(q, 1) / alpha_d and w'(q) near q = 2. */
static int write_quartic_tail(const char *dir)
{
    const sph_kernel k = SPH_KERNEL_NEW_QUARTIC;
    const double alpha = (double)sph_kernel_alpha(k, 1);
    char path[1024];
    FILE *f;
    int i;
    sprintf(path, "%.900s/new_quartic_tail.dat", dir);
    f = fopen(path, "w");
    if (f == NULL) {
        fprintf(stderr, "kernel_plots: cannot write %s\n", path);
        return 1;
    }
    fprintf(f, "# new quartic: q, w(q), w'(q)\n");
    for (i = 0; i <= 500; ++i) {
        const double q = 1.5 + 0.5 * i / 500;
        fprintf(f, "%.6f %.9e %.9e\n", q, (double)sph_kernel_w(k, 1, (sph_real)q, 1) / alpha,
                (double)sph_kernel_dwdr(k, 1, (sph_real)q, 1) / alpha);
    }
    fclose(f);
    printf("wrote %s\n", path);
    return 0;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "build/plots";
    double h_equal[SPH_KERNEL_COUNT], h_sigma[SPH_KERNEL_COUNT];
    char name[64];
    int dim, k, err = 0;
    for (dim = 2; dim <= 3; ++dim) {
        const double sigma_ref = (double)sph_kernel_sigma(SPH_KERNEL_CUBIC, dim);
        for (k = 0; k < SPH_KERNEL_COUNT; ++k) {
            h_equal[k] = 1;
            h_sigma[k] = sigma_ref / (double)sph_kernel_sigma((sph_kernel)k, dim);
        }
        sprintf(name, "kernels_%dd_equal_h.dat", dim);
        err |= write_table(dir, name, dim, h_equal);
        sprintf(name, "kernels_%dd_equal_sigma.dat", dim);
        err |= write_table(dir, name, dim, h_sigma);
    }
    err |= write_quartic_tail(dir);
    return err;
}
