/* bench/tiny_density.c - a program that only needs the 2-D cubic-spline
 * density: with the dimension and the kernel pinned, only that loop is
 * compiled (`make tiny-size` prints the object's size). */
#define SPH_DIM 2
#define SPH_KERNEL SPH_KERNEL_CUBIC
#include "sph_kernel.h"

/* rho_i = sum_j m_j W_ij for n particles at (x, y) with uniform h and the
 * caller's neighbour list; returns a status code of sph_kernel.h. */
int tiny_density(const sph_real *x, const sph_real *y, const sph_real *m, sph_real h,
                 const sph_neighbours *list, sph_real *rho);
int tiny_density(const sph_real *x, const sph_real *y, const sph_real *m, sph_real h,
                 const sph_neighbours *list, sph_real *rho)
{
    sph_ctx c = sph_ctx_init(SPH_KERNEL_CUBIC, 2, h, list, sph_view_soa(x, y, NULL));
    c.m = sph_view_soa(m, NULL, NULL);
    return sph_density(&c, sph_out_soa(rho, NULL, NULL));
}
