/* C11 compile check: the header included from a C11 translation unit, and
 * each section switch (SPH_ONLY_KERNELS, SPH_ONLY_PAIRS, SPH_NO_OPERATORS,
 * SPH_NO_NSEARCH, SPH_NO_SOLVER, SPH_NO_SMOOTHING_LENGTH) still provides the
 * sections it promises. */
#include <stdio.h>
#include "sph_kernel.h"

int main(void)
{
    sph_real W, F;
    int ok;
    sph_kernel_wf(SPH_KERNEL_WENDLAND_C4, 2, (sph_real)0.3, 1, &W, &F);
    printf("%s %s\n", sph_kernel_name(SPH_KERNEL_WENDLAND_C4), SPH_KERNEL_VERSION_STRING);
    ok = W > 0 && F < 0;
#if !defined(SPH_ONLY_KERNELS)
    { /* sections 4, 5 */
        const sph_real dx[2] = {(sph_real)0.3, 0};
        ok = ok && sph_pair_kernel(SPH_KERNEL_WENDLAND_C4, 2, dx, 1).W == W;
    }
#if !defined(SPH_ONLY_PAIRS) && !defined(SPH_NO_OPERATORS)
    ok = ok && sph_density(NULL, sph_out_soa(NULL, NULL, NULL)) == SPH_ENULL; /* section 6 */
#endif
#if !defined(SPH_NO_SOLVER)
    { /* section 8: pair terms (also under SPH_ONLY_PAIRS), then operators */
        const sph_real dx[2] = {1, 0}, dv[2] = {-1, 0};
        ok = ok && sph_pair_av_monaghan(2, 1, 2, 1, 1, 1, dx, dv) > 0 && sph_switch_balsara(-1, 0, 1, 1) > 0;
#if !defined(SPH_ONLY_PAIRS) && !defined(SPH_NO_OPERATORS)
        ok = ok && sph_artificial_viscosity(NULL, NULL, sph_view_none(), sph_view_none(), sph_view_none(),
                                            sph_view_none(), sph_out_soa(NULL, NULL, NULL),
                                            sph_out_soa(NULL, NULL, NULL), sph_out_soa(NULL, NULL, NULL)) == SPH_ENULL;
        ok = ok && sph_switch_update(NULL, 0, sph_out_soa(NULL, NULL, NULL), sph_out_soa(NULL, NULL, NULL),
                                     sph_out_soa(NULL, NULL, NULL), sph_out_soa(NULL, NULL, NULL)) == SPH_ENULL;
#endif
    }
#endif
#if !defined(SPH_ONLY_PAIRS) && !defined(SPH_NO_SMOOTHING_LENGTH)
    ok = ok && sph_pairs_reduce(NULL, 1, NULL, NULL, NULL) == SPH_ENULL; /* section 9 */
    ok = ok && sph_pairs_reduce_rows_k(NULL, 1, NULL, NULL) == SPH_ENULL;
#endif
#if !defined(SPH_ONLY_PAIRS) && !defined(SPH_NO_NSEARCH)
    { /* section 7 */
        size_t bytes = 0;
        ok = ok && sph_nsearch_workspace_size(2, sph_view_soa(NULL, NULL, NULL), 0, sph_view_soa(NULL, NULL, NULL),
                                              1, NULL, &bytes) == SPH_OK;
    }
#endif
#endif
    return ok ? 0 : 1;
}
