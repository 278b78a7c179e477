/* C11 compile check: the header included from a C11 translation unit. */
#include <stdio.h>
#include "sph_kernel.h"

int main(void)
{
    sph_real W, F;
    sph_kernel_wf(SPH_KERNEL_WENDLAND_C4, 2, (sph_real)0.3, 1, &W, &F);
    printf("%s %s\n", sph_kernel_name(SPH_KERNEL_WENDLAND_C4), SPH_KERNEL_VERSION_STRING);
    return W > 0 && F < 0 ? 0 : 1;
}
