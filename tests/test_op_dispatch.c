/* Operators in the default build (the fast loops: the kernel evaluated by
 * its shape's function, dimension and box read at run time) agree with a
 * reference written directly from the pair helper sph_pair_kernel and the
 * formulas (O2) and (O12), for every kernel in 1, 2 and 3 D, with uniform h,
 * per-particle h (h_i for the density, (h_i + h_j)/2 for the Laplacian) and a
 * periodic box, and a periodic box whose particles sit up to 3 periods outside
 * it (the operators' minimum image, a multiplication by 1/L, must pick the
 * image sph_box_delta picks; a wrong one changes a term by O(1)). Tolerance: 1e-12 (double) / 1e-4 (float) relative to the sum
 * of the magnitudes of the terms (the two evaluate W and F by different
 * operation orders, so agreement is to round-off, not bitwise).
 */
#include "op_scene.h"

static void check_case(sph_kernel k, int dim, int mode)
{
    ts_scene s;
    sph_box box;
    sph_real *f, *hh, *rho, *lap;
    int i, a, st;
    sph_off o;
    const double tol = TH_IS_FLOAT ? 1e-4 : 1e-12;
    for (a = 0; a < 3; ++a) box.lo[a] = 0, box.length[a] = 1, box.periodic[a] = 1;
    th_begin("dispatch %s %dD %s", sph_kernel_name(k), dim,
             mode == 0 ? "uniform h" : mode == 1 ? "per-particle h" : mode == 2 ? "periodic box" : "periodic, shifted");
    ts_lattice(&s, k, dim, dim == 1 ? 20 : dim == 2 ? 8 : 5, dim == 1 ? 0.05 : dim == 2 ? 0.125 : 0.2, 1.3, 0.3, 3,
               mode >= 2 ? &box : NULL);
    for (i = 0; mode == 3 && i < s.n; ++i) /* the list stays valid: it holds minimum images */
        for (a = 0; a < dim; ++a) s.x[3 * i + a] += (sph_real)((i * 5 + a) % 7 - 3);
    f = ts_vec(s.n), hh = ts_vec(s.n), rho = ts_vec(s.n), lap = ts_vec(s.n);
    for (i = 0; i < s.n; ++i) {
        f[i] = (sph_real)(ts_linear(s.x + 3 * i) + s.x[3 * i] * s.x[3 * i]);
        hh[i] = (sph_real)(s.h * (1 + 0.1 * ((i * 7) % 3 - 1))); /* 0.9 h, h, 1.1 h: within the list's reach */
    }
    if (mode == 1) {
        /* per-particle h needs the symmetric list (max(h_i, h_j)); h_i <= 1.1 h */
        tp_free_list(&s.L);
        tp_brute_list(dim, s.x, s.n, s.x, s.n, 0, hh, hh, sph_kernel_support(k), TP_SYMMETRIC, NULL, &s.L);
        s.c.list = &s.L.list;
        s.c.h_source = sph_view_soa(hh, NULL, NULL);
    }
    s.c.m = s.c.V;
    st = sph_density(&s.c, sph_out_soa(rho, NULL, NULL));
    st |= sph_laplacian(&s.c, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_soa(lap, NULL, NULL));
    TH_CHECK(st == SPH_OK, "status %d", st);
    for (i = 0; i < s.n; ++i) {
        double rr = 0, lr = 0, rm = 0, lm = 0;
        for (o = s.L.list.offset[i]; o < s.L.list.offset[i + 1]; ++o) {
            const int j = s.L.list.index[o];
            sph_real dx[3];
            sph_pair pi, pij;
            for (a = 0; a < dim; ++a) dx[a] = sph_box_delta(s.c.box, a, s.x[3 * i + a] - s.x[3 * j + a]);
            pi = sph_pair_kernel(k, dim, dx, mode == 1 ? hh[i] : (sph_real)s.h);
            pij = sph_pair_kernel(k, dim, dx, mode == 1 ? (hh[i] + hh[j]) / 2 : (sph_real)s.h);
            rr += (double)s.V[j] * pi.W, rm += fabs((double)s.V[j] * pi.W);
            lr += 2.0 * s.V[j] * (f[i] - f[j]) * pij.F, lm += fabs(2.0 * s.V[j] * (f[i] - f[j]) * pij.F);
        }
        TH_CLOSE(rho[i], rr, tol * rm);
        TH_CLOSE(lap[i], lr, tol * lm);
    }
    free(f), free(hh), free(rho), free(lap);
    ts_free(&s);
    th_end();
}

int main(void)
{
    int k, dim, mode;
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim)
            for (mode = 0; mode < 4; ++mode) check_case((sph_kernel)k, dim, mode);
    return th_summary();
}
