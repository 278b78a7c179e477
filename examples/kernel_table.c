/* kernel_table.c - `make demo`: the kernels of sph_kernel.h at a glance.
 *
 * Section 1 lists, for every kernel and dimension, the support kappa, the
 * normalisation alpha_d, the standard deviation sigma/h from the header, and
 * three numbers this program computes itself by Gauss-Legendre quadrature of
 * sph_kernel_w over each piece of width h/2 (exact for these polynomials up to
 * rounding): the normalisation integral int W d^dx (docs/kernels.md eq. (K1),
 * should be 1), sigma/h from eq. (K5), and the neighbour count N of eq. (K6)
 * for particles on a lattice of spacing dx, at h = 1.2 dx and at the h of equal
 * resolution (the same sigma as the cubic spline at h = 1.2 dx).
 * Section 2 prints W and dW/dr at h = 1 and a few q = r/h. Section 3 (alone
 * with --eta: the tables of docs/smoothing_length.md, "Choosing eta") gives
 * the eta of (H1), h = eta (m / rho)^(1/d), that puts N neighbours inside the
 * support, sph_kernel_h_for_neighbours(k, dim, N, 1) (h in units of the
 * particle spacing (m / rho)^(1/d)), for the usual N of each dimension, and
 * the N of sph_hctx_init's default eta 1.2.
 *
 * Build and run: make demo   (or: cc -std=c99 -I. examples/kernel_table.c -lm)
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sph_kernel.h"

#define GL_N 8 /* Gauss-Legendre points per piece: exact for degree <= 15 */

static double gl_x[GL_N], gl_w[GL_N]; /* nodes and weights on [-1, 1] */

/* Gauss-Legendre nodes and weights by Newton's method on P_n. */
static void gauss_legendre_init(void)
{
    const double pi = 3.14159265358979323846;
    int i, j, it;
    for (i = 0; i < GL_N; ++i) {
        double x = cos(pi * (i + 0.75) / (GL_N + 0.5)), p0 = 1, p1 = 0, dp = 1;
        for (it = 0; it < 100; ++it) {
            double dx;
            p0 = 1;
            p1 = 0;
            for (j = 1; j <= GL_N; ++j) { /* P_j by the three-term recurrence */
                double p2 = p1;
                p1 = p0;
                p0 = ((2.0 * j - 1) * x * p1 - (j - 1.0) * p2) / j;
            }
            dp = GL_N * (x * p0 - p1) / (x * x - 1);
            dx = p0 / dp;
            x -= dx;
            if (fabs(dx) < 1e-16) break;
        }
        gl_x[i] = x;
        gl_w[i] = 2 / ((1 - x * x) * dp * dp);
    }
}

/* Surface of the unit sphere in dim dimensions: 2, 2 pi, 4 pi. */
static double sphere_surface(int dim)
{
    const double pi = 3.14159265358979323846;
    return dim == 1 ? 2 : dim == 2 ? 2 * pi : 4 * pi;
}

/* int |x|^p W(|x|, h=1) d^dx by quadrature over the pieces [q, q + 1/2). */
static double kernel_moment(sph_kernel k, int dim, int p)
{
    const double kappa = (double)sph_kernel_support(k);
    double sum = 0, a;
    int i;
    for (a = 0; a < kappa; a += 0.5) {
        for (i = 0; i < GL_N; ++i) {
            const double r = a + 0.25 * (1 + gl_x[i]);
            const double W = (double)sph_kernel_w(k, dim, (sph_real)r, 1);
            sum += 0.25 * gl_w[i] * W * pow(r, dim - 1 + p);
        }
    }
    return sphere_surface(dim) * sum;
}

static void print_rule(int width)
{
    while (width-- > 0) putchar('-');
    putchar('\n');
}

/* One table entry; -0 (dW/dr at q = 0) is printed as 0. */
static void print_value(double x)
{
    printf(" %17.10e", x + 0.0);
}

/* Section 1: constants of every kernel and dimension, with checks. */
static void table_constants(void)
{
    const double h_over_dx = 1.2;
    int k, dim;
    printf("1. Constants (h = 1). alpha_d and sigma/h: the header's tables;\n"
           "   int W dV, sigma/h (quad): this program's quadrature, eq. (K1), (K5);\n"
           "   N: neighbours inside the support (self included), eq. (K6), at\n"
           "      h = %.1f dx and at equal sigma (h = %.1f dx sigma_cubic / sigma)\n\n",
           h_over_dx, h_over_dx);
    printf("%-12s %1s %5s %19s %19s %19s %19s %9s %7s %7s\n", "kernel", "d", "kappa", "alpha_d",
           "sigma/h", "sigma/h (quad)", "int W dV", "minus 1", "N", "N(sig)");
    print_rule(125);
    for (k = 0; k < SPH_KERNEL_COUNT; ++k) {
        const sph_kernel kk = (sph_kernel)k;
        for (dim = 1; dim <= 3; ++dim) {
            const double norm = kernel_moment(kk, dim, 0);
            const double sig = sqrt(kernel_moment(kk, dim, 2) / dim);
            const double N = (double)sph_kernel_neighbours(kk, dim, (sph_real)h_over_dx, 1);
            const double h_sig = h_over_dx * (double)sph_kernel_sigma(SPH_KERNEL_CUBIC, dim) /
                                 (double)sph_kernel_sigma(kk, dim);
            const double Ns = (double)sph_kernel_neighbours(kk, dim, (sph_real)h_sig, 1);
            printf("%-12s %1d %5g %19.16f %19.16f %19.16f %19.16f %+9.1e %7.2f %7.2f\n",
                   dim == 1 ? sph_kernel_name(kk) : "", dim, (double)sph_kernel_support(kk),
                   (double)sph_kernel_alpha(kk, dim), (double)sph_kernel_sigma(kk, dim), sig,
                   norm, norm - 1, N, Ns);
        }
    }
    printf("\n");
}

/* Section 2: W and dW/dr at h = 1 and a few q. */
static void table_values(void)
{
    static const double qs[] = {0, 0.5, 1, 1.5, 2.5};
    const int nq = (int)(sizeof qs / sizeof qs[0]);
    int k, dim, i;
    printf("2. W(q) and dW/dr(q) at h = 1, eq. (K1), (K3)\n\n%-12s %1s %5s", "kernel", "d", "");
    for (i = 0; i < nq; ++i) {
        char head[32];
        sprintf(head, "q = %g", qs[i]);
        printf(" %17s", head);
    }
    printf("\n");
    print_rule(20 + 18 * nq);
    for (k = 0; k < SPH_KERNEL_COUNT; ++k) {
        const sph_kernel kk = (sph_kernel)k;
        for (dim = 1; dim <= 3; ++dim) {
            printf("%-12s %1d %5s", dim == 1 ? sph_kernel_name(kk) : "", dim, "W");
            for (i = 0; i < nq; ++i)
                print_value((double)sph_kernel_w(kk, dim, (sph_real)qs[i], 1));
            printf("\n%-12s %1s %5s", "", "", "dW/dr");
            for (i = 0; i < nq; ++i)
                print_value((double)sph_kernel_dwdr(kk, dim, (sph_real)qs[i], 1));
            printf("\n");
        }
    }
    printf("\n");
}

/* Section 3: eta for N neighbours, one Markdown table per dimension. */
static void table_eta(void)
{
    static const double N[4][5] = {{0}, {3, 4, 5, 6, 8}, {12, 18, 24, 32, 48}, {32, 58, 100, 200, 400}};
    int k, dim, c;
    for (dim = 1; dim <= 3; ++dim) {
        printf("%d-D: eta for N neighbours in the support\n\n| kernel | kappa |", dim);
        for (c = 0; c < 5; ++c) printf(" N = %g |", N[dim][c]);
        printf(" N at eta 1.2 |\n|---|---:|");
        for (c = 0; c <= 5; ++c) printf("---:|");
        printf("\n");
        for (k = 0; k < SPH_KERNEL_COUNT; ++k) {
            const sph_kernel kk = (sph_kernel)k;
            printf("| %s | %g |", sph_kernel_name(kk), (double)sph_kernel_support(kk));
            for (c = 0; c < 5; ++c)
                printf(" %.3f |", (double)sph_kernel_h_for_neighbours(kk, dim, (sph_real)N[dim][c], 1));
            printf(" %.1f |\n", (double)sph_kernel_neighbours(kk, dim, (sph_real)1.2, 1));
        }
        if (dim < 3) printf("\n");
    }
}

int main(int argc, char **argv)
{
    const int eta = argc == 2 && strcmp(argv[1], "--eta") == 0;
    if (argc > 1 && !eta) { /* --eta or nothing: say so rather than ignore a typo */
        const int help = strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0;
        fprintf(help ? stdout : stderr, "%s: %s; takes no arguments but --eta (section 3 alone)%s%s%s\n", argv[0],
                "the constants of every kernel, checked by quadrature, W and dW/dr at a few q, eta for N neighbours",
                help ? "" : " (got '", help ? "" : argv[1], help ? "" : "')");
        return help ? 0 : 2;
    }
    if (eta) {
        table_eta();
        return 0;
    }
    gauss_legendre_init();
    printf("sph_kernel.h %s, sph_real = %s\n\n", SPH_KERNEL_VERSION_STRING,
           sizeof(sph_real) == sizeof(float) ? "float" : "double");
    table_constants();
    table_values();
    printf("3. eta of (H1), h = eta (m / rho)^(1/d), for N neighbours inside the support (self included),\n"
           "   sph_kernel_h_for_neighbours(k, dim, N, 1), eq. (K6); N at the default eta 1.2 of sph_hctx_init\n\n");
    table_eta();
    return 0;
}
