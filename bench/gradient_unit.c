/* bench/gradient_unit.c - one translation unit that calls sph_gradient
 * with the kernel and the dimension chosen at run time: `make tiny-size`
 * compiles it with the fast loops and with SPH_OP_REFERENCE and prints
 * compile time and object size (what the fast loops cost to build). */
#include "sph_kernel.h"

/* grad f at every target of the caller's list (difference scheme). */
int gradient_unit(sph_kernel k, int dim, const sph_real *x, const sph_real *V, const sph_real *f, sph_real h,
                  const sph_neighbours *list, sph_real *g);
int gradient_unit(sph_kernel k, int dim, const sph_real *x, const sph_real *V, const sph_real *f, sph_real h,
                  const sph_neighbours *list, sph_real *g)
{
    sph_ctx c = sph_ctx_init(k, dim, h, list, sph_view_interleaved(x, 3));
    c.V = sph_view_soa(V, NULL, NULL);
    return sph_gradient(&c, SPH_SCHEME_DIFFERENCE, sph_view_soa(f, NULL, NULL), sph_view_none(),
                        sph_out_interleaved(g, 3), NULL);
}
