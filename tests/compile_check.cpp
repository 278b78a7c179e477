// C++ compile check: the header must build warning-free as C++11 and its
// functions must be callable from C++ code (extern "C", no C-only syntax).
#include <cstdio>
#include "sph_kernel.h"

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
    sph_real x[6] = {0, 0, 0, sph_real(0.5), 0, 0}, m[2] = {1, 1}, rho[2] = {0, 0};
    sph_view xv = sph_view_interleaved(x, 3);
    size_t bytes = 0;
    static unsigned char work[1 << 16];
    sph_nsearch grid;
    sph_off off[3];
    sph_idx idx[4];
    if (sph_nsearch_workspace_size(3, xv, 2, sph_view_none(), 1, NULL, &bytes) != SPH_OK ||
        bytes > sizeof work ||
        sph_nsearch_build(&grid, 3, xv, 2, sph_view_none(), 1, NULL, work, bytes) != SPH_OK ||
        sph_nsearch_count(&grid, xv, 2, sph_view_none(), 1, 2, SPH_NSEARCH_GATHER, off) != SPH_OK ||
        sph_nsearch_fill(&grid, xv, 2, sph_view_none(), 1, 2, SPH_NSEARCH_GATHER, off, idx, 4) != SPH_OK)
        bad = 1;
    sph_neighbours list = sph_nsearch_list(&grid, 2, off, idx);
    sph_ctx c = sph_ctx_init(SPH_KERNEL_CUBIC, 3, 1, &list, xv);
    c.m = sph_view_soa(m, NULL, NULL);
    if (sph_density(&c, sph_out_soa(rho, NULL, NULL)) != SPH_OK || !(rho[0] > 0)) bad = 1;
    std::printf("%s\n", bad ? "C++ check failed" : sph_strerror(SPH_OK));
    return bad;
}
