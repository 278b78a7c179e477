/* Density and gradient on a particle cloud: neighbour search, then two
 * operators (README "Quickstart: a particle cloud"). With --check it exits
 * non-zero unless the corrected gradient of a linear field is exact; --help
 * lists the options, any other argument is refused (exit 2). No time steps,
 * so no growth bound. */
#include "example_io.h"

static int fail(int st)
{
    fprintf(stderr, "%s: %s\n", ex_prog(), sph_strerror(st));
    return 1;
}

int main(int argc, char **argv)
{
    enum { N = 20 * 20 };                       /* 2-D, 20 x 20 particles */
    const sph_real dx = (sph_real)0.05, h = (sph_real)1.3 * dx, kappa = sph_kernel_support(SPH_KERNEL_CUBIC);
    static sph_real x[2 * N], m[N], rho[N], V[N], f[N], grad[2 * N];
    sph_view xv = sph_view_interleaved(x, 2);   /* x[2 i + a] */
    sph_nsearch grid;
    size_t bytes = 0;
    void *work;
    sph_off *offset;
    sph_idx *index, n_fallback = 0;
    sph_real rho_lo = 0, rho_hi = 0;
    int i, st, check = 0;
    const ex_arg opt[] = {
        {"check", "exit 1 unless the corrected gradient of a linear field is exact", NULL, NULL, NULL, &check, 0, 0, 0,
         NULL},
    };
    st = ex_parse_args(argc, argv, "density and corrected gradient on a 20 x 20 particle cloud", opt, 1);
    if (st != 0) return st > 0 ? 0 : 2;
    /* A lattice of spacing dx, each particle moved by up to 0.2 dx, with the
     * mass m = 1000 dx^2 of density 1000 on the lattice. The summation density
     * of the jittered cloud is not 1000 everywhere: a particle whose
     * neighbours moved away gets less, one whose neighbours crowded in more
     * (-4 % to +5 % here: the range printed below; without the jitter the sum
     * is 1000 to within the lattice error of the cubic at h = 1.3 dx). */
    for (i = 0; i < N; ++i) {
        x[2 * i] = dx * ((sph_real)(i % 20) + (sph_real)0.2 * (sph_real)((i * 7919) % 11) / 11);
        x[2 * i + 1] = dx * ((sph_real)(i / 20) + (sph_real)0.2 * (sph_real)((i * 104729) % 13) / 13);
        m[i] = 1000 * dx * dx;
        f[i] = 3 * x[2 * i] - 2 * x[2 * i + 1]; /* grad f = (3, -2) */
    }
    /* 1. neighbour lists: size query, build, count, allocate, fill */
    st = sph_nsearch_workspace_size(2, xv, N, sph_view_none(), kappa * h / 2, NULL, &bytes);
    work = malloc(bytes);
    offset = (sph_off *)malloc((N + 1) * sizeof(sph_off));
    if (work == NULL || offset == NULL) return fprintf(stderr, "%s: out of memory\n", ex_prog()), 1;
    if (st == SPH_OK) st = sph_nsearch_build(&grid, 2, xv, N, sph_view_none(), kappa * h / 2, NULL, work, bytes);
    if (st == SPH_OK) st = sph_nsearch_count(&grid, xv, N, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, offset);
    if (st != SPH_OK) return fail(st);
    index = (sph_idx *)malloc((size_t)offset[N] * sizeof(sph_idx));
    if (index == NULL) return fprintf(stderr, "%s: out of memory\n", ex_prog()), 1;
    st = sph_nsearch_fill(&grid, xv, N, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, offset, index, offset[N]);
    if (st != SPH_OK) return fail(st);
    sph_neighbours list = sph_nsearch_list(&grid, N, offset, index);
    /* 2. density rho_i = sum_j m_j W_ij, volumes V = m / rho, corrected gradient */
    sph_ctx c = sph_ctx_init(SPH_KERNEL_CUBIC, 2, h, &list, xv);
    c.m = sph_view_soa(m, NULL, NULL);
    if ((st = sph_density(&c, sph_out_soa(rho, NULL, NULL))) != SPH_OK) return fail(st);
    for (i = 0; i < N; ++i) V[i] = m[i] / rho[i];
    c.V = sph_view_soa(V, NULL, NULL);
    st = sph_gradient(&c, SPH_SCHEME_CORRECTED, sph_view_soa(f, NULL, NULL), sph_view_none(),
                      sph_out_interleaved(grad, 2), &n_fallback);
    if (st != SPH_OK) return fail(st);
    for (i = 0; i < N; ++i) { /* the particles 3 dx or more from the edges: kappa h = 2.6 dx of full support */
        const int col = i % 20, row = i / 20;
        if (col < 3 || col > 16 || row < 3 || row > 16) continue;
        rho_lo = rho_lo == 0 || rho[i] < rho_lo ? rho[i] : rho_lo;
        rho_hi = rho[i] > rho_hi ? rho[i] : rho_hi;
    }
    i = N / 2 + 10;                             /* an interior particle */
    printf("%ld pairs; rho = %.2f (interior %.1f .. %.1f); grad f = (%.12f, %.12f); %ld fallbacks\n",
           (long)offset[N], (double)rho[i], (double)rho_lo, (double)rho_hi, (double)grad[2 * i],
           (double)grad[2 * i + 1], (long)n_fallback);
    free(work), free(offset), free(index);
    if (check) { /* exact for a linear field, to round-off */
        const double tol = 1000 * (sizeof(sph_real) == sizeof(float) ? FLT_EPSILON : DBL_EPSILON);
        return fabs((double)grad[2 * i] - 3) < 3 * tol && fabs((double)grad[2 * i + 1] + 2) < 2 * tol ? 0 : 1;
    }
    return 0;
}
