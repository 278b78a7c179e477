/* quickstart.c - the README's first program: one pair, then a density sum.
 * Build: cc -std=c99 -I. examples/quickstart.c -lm   (or: make build/quickstart) */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "sph_kernel.h"

#define N 25 /* a 5 x 5 lattice of spacing dx: unit density, m = dx^2 */

int main(int argc, char **argv)
{
    const sph_kernel k = SPH_KERNEL_WENDLAND_C2;
    const sph_real dx = 0.1, m = dx * dx, h = 1.2 * dx;
    sph_real x[N][2], W, F, grad[2], rho = 0;
    int i, j;
    if (argc > 1) { /* it takes none: say so rather than ignore a typo */
        const int help = strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0;
        fprintf(help ? stdout : stderr, "%s: %s; takes no arguments%s%s%s\n", argv[0], "one kernel pair and a density sum on a 5 x 5 lattice",
                help ? "" : " (got '", help ? "" : argv[1], help ? "" : "')");
        return help ? 0 : 2;
    }
    for (i = 0; i < N; ++i) x[i][0] = dx * (i % 5), x[i][1] = dx * (i / 5);

    /* one pair i = 12 (the centre), j = 18 (diagonal): W, F = (1/r) dW/dr, grad_i W_ij */
    const sph_real xij[2] = {x[12][0] - x[18][0], x[12][1] - x[18][1]};
    sph_kernel_wf(k, 2, sqrt(xij[0] * xij[0] + xij[1] * xij[1]), h, &W, &F);
    /* x_ij = x_i - x_j points from j to i; F < 0 inside the support, so
     * grad_i W_ij = F x_ij points from i towards j (W grows as i nears j) */
    sph_kernel_grad(k, 2, xij, h, grad);
    printf("W = %.6f  grad_i W = (%.4f, %.4f)  F x_ij = (%.4f, %.4f)\n",
           W, grad[0], grad[1], F * xij[0], F * xij[1]);

    /* density of the centre particle: rho_i = sum_j m_j W_ij, self included */
    for (j = 0; j < N; ++j) {
        const sph_real r = hypot(x[12][0] - x[j][0], x[12][1] - x[j][1]);
        rho += m * sph_kernel_w(k, 2, r, h);
    }
    printf("rho_12 = %.6f  (neighbours expected: %.2f)\n", rho,
           sph_kernel_neighbours(k, 2, h, dx * dx));
    return 0;
}
