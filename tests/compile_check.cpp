// C++ compile check: the header must build warning-free as C++11 and its
// functions must be callable from C++ code (extern "C", no C-only syntax).
#include <cstdio>
#include "sph_kernel.h"
#include "compile_check_host.h"

int main()
{
    sph_real W = 0, F = 0, g[3] = {0, 0, 0};
    const sph_real dx[3] = {sph_real(0.1), sph_real(0.2), sph_real(0.3)};
    int bad = 0;
    for (int k = 0; k < SPH_KERNEL_COUNT; ++k) {
        sph_kernel kk = static_cast<sph_kernel>(k);
        sph_kernel_wf(kk, 3, sph_real(0.5), sph_real(1), &W, &F);
        sph_kernel_grad(kk, 3, dx, sph_real(1), g);
        if (!(W > 0) || sph_kernel_from_name(sph_kernel_name(kk)) != k) bad = 1;
    }
    // one operator and the neighbour search, as a C++ caller would use them
    if (cc_host_density() != 0) bad = 1;
    std::printf("%s\n", bad ? "C++ check failed" : sph_strerror(SPH_OK));
    return bad;
}
