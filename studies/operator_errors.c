/* studies/operator_errors.c - the error of every gradient scheme of
 * sph_kernel.h on three particle configurations (docs/operators.md, table
 * "Measured errors"). 2-D, cubic spline, h = 1.3 dx, 32 x 32 particles of
 * volume dx^2 (pressure form with rho = 1, m = V).
 *
 *   lattice       cell-centred lattice in [0,1)^2
 *   perturbed     the lattice moved by up to 30 % of dx per axis (seeded)
 *   free surface  the lattice, periodic along y only; errors at the layer x < dx
 *
 * linear: f = 0.7 + 1.3 x - 0.8 y (0.7 + 1.3 x at the free surface), errors
 * over targets at least 2 h from a non-periodic edge (all of the surface
 * layer in the free-surface case); sine: f = sin(2 pi x) sin(2 pi y) with a
 * periodic box in the lattice and perturbed cases. Error: max_i |g_i - g(x_i)|
 * / max_i |g(x_i)|.   Build and run: make build/operator_errors && ./build/operator_errors
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "sph_kernel.h"
#include "support/particles.h"

#define N 32
#define PI 3.14159265358979323846

static double field(int sine, int surface, const sph_real *x, double *g)
{
    if (sine) {
        const double sx = sin(2 * PI * x[0]), sy = sin(2 * PI * x[1]);
        g[0] = 2 * PI * cos(2 * PI * x[0]) * sy;
        g[1] = 2 * PI * sx * cos(2 * PI * x[1]);
        return sx * sy;
    }
    g[0] = 1.3;
    g[1] = surface ? 0 : -0.8;
    return 0.7 + g[0] * x[0] + g[1] * x[1];
}

int main(void)
{
    static const char *scheme[5] = {"standard", "difference", "symmetric", "corrected", "pressure"};
    static const char *config[3] = {"lattice", "perturbed 30%", "free surface"};
    const int n = N * N;
    const double dx = 1.0 / N, h = 1.3 * dx;
    sph_real *x = (sph_real *)malloc(sizeof(sph_real) * 3 * n), *V = (sph_real *)malloc(sizeof(sph_real) * n);
    sph_real *f = (sph_real *)malloc(sizeof(sph_real) * n), *one = (sph_real *)malloc(sizeof(sph_real) * n);
    sph_real *g[2] = {(sph_real *)malloc(sizeof(sph_real) * n), (sph_real *)malloc(sizeof(sph_real) * n)};
    double *ge = (double *)malloc(sizeof(double) * 2 * n), err[3][2][5];
    int cf, sine, sc, i;
    for (cf = 0; cf < 3; ++cf)
        for (sine = 0; sine < 2; ++sine) {
            tp_rng rng = {2024};
            sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}};
            tp_list L;
            sph_ctx c;
            const sph_box *bp = NULL;
            if (cf == 2) box.periodic[0] = 0, bp = &box;
            else if (sine) bp = &box;
            tp_lattice(2, N, dx, x);
            if (cf == 1) tp_perturb(2, n, 0.3 * dx, &rng, x);
            for (i = 0; i < n; ++i) {
                V[i] = (sph_real)(dx * dx), one[i] = 1;
                f[i] = (sph_real)field(sine, cf == 2, x + 3 * i, ge + 2 * i);
            }
            if (tp_brute_list(2, x, n, x, n, (sph_real)h, NULL, NULL, 2, TP_GATHER, bp, &L) != 0) return 1;
            c = sph_ctx_init(SPH_KERNEL_CUBIC, 2, (sph_real)h, &L.list, sph_view_interleaved(x, 3));
            c.box = bp;
            c.V = c.m = sph_view_soa(V, NULL, NULL);
            c.rho = sph_view_soa(one, NULL, NULL);
            for (sc = 0; sc < 5; ++sc) {
                double num = 0, den = 0;
                if (sph_gradient(&c, (sph_scheme)sc, sph_view_soa(f, NULL, NULL), sph_view_none(),
                                 sph_out_soa(g[0], g[1], NULL), NULL) != SPH_OK)
                    return 1;
                for (i = 0; i < n; ++i) {
                    int a, use = 1;
                    if (cf == 2) use = x[3 * i] < dx;
                    else if (!sine)
                        for (a = 0; a < 2; ++a) use &= x[3 * i + a] > 2 * h + 0.3 * dx && x[3 * i + a] < 1 - 2 * h - 0.3 * dx;
                    if (!use) continue;
                    for (a = 0; a < 2; ++a) {
                        const double d = fabs(g[a][i] - ge[2 * i + a]);
                        if (d > num) num = d;
                        if (fabs(ge[2 * i + a]) > den) den = fabs(ge[2 * i + a]);
                    }
                }
                err[cf][sine][sc] = num / den;
            }
            tp_free_list(&L);
        }
    printf("max relative gradient error, 2-D cubic spline, h = 1.3 dx, %d x %d particles (%s)\n", N, N,
           sizeof(sph_real) == sizeof(float) ? "float" : "double");
    printf("%-12s", "scheme");
    for (cf = 0; cf < 3; ++cf) printf(" | %-13s lin   sine   ", config[cf]);
    printf("\n");
    for (sc = 0; sc < 5; ++sc) {
        printf("%-12s", scheme[sc]);
        for (cf = 0; cf < 3; ++cf) printf(" | %9.2e %9.2e      ", err[cf][0][sc], err[cf][1][sc]);
        printf("\n");
    }
    printf("\nlattice second moment mu at h = 1.3 dx (1 for the continuous kernel)\n%-12s %9s %9s\n",
           "kernel", "2-D", "3-D");
    for (sc = 0; sc < SPH_KERNEL_COUNT; ++sc)
        printf("%-12s %9.4f %9.4f\n", sph_kernel_name((sph_kernel)sc),
               tp_lattice_moment((sph_kernel)sc, 2, 1, 1.3), tp_lattice_moment((sph_kernel)sc, 3, 1, 1.3));
    free(x), free(V), free(f), free(one), free(g[0]), free(g[1]), free(ge);
    return 0;
}
