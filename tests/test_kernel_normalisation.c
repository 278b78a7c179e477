/* tests/test_kernel_normalisation.c - int W d^dx = 1 and the second moment
 * sigma^2 = (1/d) int |x|^2 W d^dx of every kernel in 1-, 2- and 3-D, by our
 * own Gauss-Legendre quadrature (tests/kernel_ref.h: nodes by Newton on P_n,
 * 12 nodes on every interval of width 1/2, exact for the piecewise
 * polynomials here up to degree 23) of the header's W with the radial measure
 * s_d r^(d-1), s_d = 2, 2 pi, 4 pi; the neighbour-count helpers against
 * N = omega_d (kappa h)^d / V.
 *
 * Bounds: |int W - 1| <= 1e-12 (double) and <= 2e-6 (float: each sample of W
 * carries a few float eps, ~1e-7, and the nodes are rounded to float). The
 * same bounds hold, relative, for sigma. The quadrature itself is checked
 * first on the long-double closed forms (|err| <= 1e-16).
 *
 * Published cross-check: Dehnen & Aly 2012 (MNRAS 425, 1068), table 1, give
 * H/(2 sigma) (H = kappa h, the support radius) to 6 decimals; those used
 * here: cubic M4 1-D 1.732051 (= sqrt 3), 3-D 1.825742; quintic M6 3-D
 * 2.195775; Wendland 3-D C2 1.936492, C4 2.207940, C6 2.449490; quartic M5
 * 1-D 1.936492, 2-D 1.977173, 3-D 2.018932 (also SWIFT's kernel_gamma of
 * its quartic spline, src/kernel_hydro.h).
 */
#include "kernel_ref.h"

#define NGAUSS 12
#define TOL_INT (TH_IS_FLOAT ? 2e-6 : 1e-12)

typedef struct {
    sph_kernel k;
    int dim;
    int moment; /* 0: int W, 2: int |x|^2 W */
    int use_ref;
} integrand;

/* s_d r^(d-1+moment) W(r, h = 1), from the header or from the closed form. */
static ref_real radial(ref_real r, void *ctx)
{
    const integrand *p = (const integrand *)ctx;
    ref_real W, w, w1, w2;
    if (p->use_ref) {
        ref_shape(p->k, p->dim, r, &w, &w1, &w2);
        W = ref_alpha(p->k, p->dim) * w;
    } else {
        const sph_real rr = (sph_real)r;
        W = (ref_real)sph_kernel_w(p->k, p->dim, rr, 1);
    }
    return ref_sphere(p->dim) * ref_pow(r, p->dim - 1 + p->moment) * W;
}

static ref_real moment(sph_kernel k, int dim, int m, int use_ref)
{
    integrand p;
    p.k = k;
    p.dim = dim;
    p.moment = m;
    p.use_ref = use_ref;
    return ref_integrate(radial, &p, 0, ref_kappa(k), NGAUSS);
}

static double worst_norm, worst_sigma;

static void test_quadrature(sph_kernel k, int dim)
{
    th_begin("quadrature self-check: closed form %s %dD integrates to 1", sph_kernel_name(k), dim);
    TH_CLOSE((double)moment(k, dim, 0, 1), 1.0, 1e-16);
    th_end();
}

static void test_normalisation(sph_kernel k, int dim)
{
    const double I = (double)moment(k, dim, 0, 0);
    th_begin("normalisation int W d^%dx = 1, %s %dD", dim, sph_kernel_name(k), dim);
    TH_CLOSE(I, 1.0, TOL_INT);
    if (fabs(I - 1) > worst_norm) worst_norm = fabs(I - 1);
    th_end();
}

static void test_sigma(sph_kernel k, int dim)
{
    const double s_quad = sqrt((double)(moment(k, dim, 2, 0) / dim));
    const double s_ref = sqrt((double)(moment(k, dim, 2, 1) / dim));
    const double s = (double)sph_kernel_sigma(k, dim);
    th_begin("sigma^2 = (1/d) int |x|^2 W, %s %dD", sph_kernel_name(k), dim);
    TH_REL(s, s_quad, TOL_INT);
    TH_REL(s, s_ref, 4 * TH_EPS); /* closed form in long double: only the rounding of sigma */
    if (fabs(s - s_quad) / s_quad > worst_sigma) worst_sigma = fabs(s - s_quad) / s_quad;
    th_end();
}

static void test_published(void)
{
    static const struct {
        sph_kernel k;
        int dim;
        double ratio;
    } da[] = {{SPH_KERNEL_CUBIC, 1, 1.732051},       {SPH_KERNEL_CUBIC, 3, 1.825742},
              {SPH_KERNEL_QUINTIC, 3, 2.195775},     {SPH_KERNEL_WENDLAND_C2, 3, 1.936492},
              {SPH_KERNEL_WENDLAND_C4, 3, 2.207940}, {SPH_KERNEL_WENDLAND_C6, 3, 2.449490},
              {SPH_KERNEL_QUARTIC, 1, 1.936492},     {SPH_KERNEL_QUARTIC, 2, 1.977173},
              {SPH_KERNEL_QUARTIC, 3, 2.018932}};
    size_t i;
    for (i = 0; i < sizeof da / sizeof da[0]; ++i) {
        const double ratio = (double)sph_kernel_support(da[i].k) / (2 * (double)sph_kernel_sigma(da[i].k, da[i].dim));
        th_begin("Dehnen & Aly 2012 H/(2 sigma) %s %dD = %.6f", sph_kernel_name(da[i].k), da[i].dim, da[i].ratio);
        TH_CLOSE(ratio, da[i].ratio, 6e-7); /* 6 published decimals */
        th_end();
    }
}

/* N = omega_d (kappa h)^d / V, and h_for_neighbours its inverse. */
static void test_neighbours(sph_kernel k, int dim)
{
    static const double hs[] = {0.01, 0.3, 1, 2.5, 70};
    static const double Vs[] = {1e-6, 0.02, 1, 3};
    const ref_real omega = dim == 1 ? 2.0L : dim == 2 ? REF_PI : 4.0L / 3 * REF_PI;
    size_t i, j;
    th_begin("neighbours N = omega_d (kappa h)^d / V and its inverse, %s %dD", sph_kernel_name(k), dim);
    for (i = 0; i < sizeof hs / sizeof hs[0]; ++i) {
        for (j = 0; j < sizeof Vs / sizeof Vs[0]; ++j) {
            const sph_real h = (sph_real)hs[i], V = (sph_real)Vs[j];
            const ref_real N_ref = omega * ref_pow(ref_kappa(k) * h, dim) / V;
            const sph_real N = sph_kernel_neighbours(k, dim, h, V);
            TH_REL(N, (double)N_ref, 8 * TH_EPS);
            TH_REL(sph_kernel_h_for_neighbours(k, dim, N, V), h, 8 * TH_EPS);
            TH_REL(sph_kernel_neighbours(k, dim, sph_kernel_h_for_neighbours(k, dim, (sph_real)50, V), V),
                   50.0, 8 * TH_EPS);
        }
    }
    th_end();
}

int main(void)
{
    int ik, dim;
    for (ik = 0; ik < SPH_KERNEL_COUNT; ++ik) {
        for (dim = 1; dim <= 3; ++dim) {
            test_quadrature(ref_kernels[ik], dim);
            test_normalisation(ref_kernels[ik], dim);
            test_sigma(ref_kernels[ik], dim);
            test_neighbours(ref_kernels[ik], dim);
        }
    }
    test_published();
    printf("info [%s]: worst |int W - 1| = %.3g, worst relative error of sigma = %.3g\n", TH_PRECISION,
           worst_norm, worst_sigma);
    return th_summary();
}
