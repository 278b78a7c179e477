/* tests/test_kernel_convergence.c - the kernel estimate converges to the
 * delta function at second order: <f>(x0) = int f(x) W(x0 - x, h) d^dx ->
 * f(x0) as h -> 0, with error (sigma^2 h^2 / 2) lap f(x0) + O(h^4)
 * (expand f to second order; odd moments vanish, the second moment is
 * sigma^2 h^2 per coordinate).
 *
 * f(x) = exp(a . x) with |a| = 1, so lap f = f and the integral reduces to a
 * radial one with the exact mean of f over the sphere of radius r around x0:
 * f(x0) cosh(r) (1-D), f(x0) I0(r) (2-D), f(x0) sinh(r)/r (3-D). Hence
 *   E(h) = <f>(x0)/f(x0) - 1 = int_0^{kappa h} W(r, h) M(r) s_d r^(d-1) dr - 1,
 * computed by Gauss-Legendre (tests/kernel_ref.h) on the header's W. Asserted:
 * the observed order log2(E(h)/E(h/2)) for h = 0.2, 0.1, 0.05 lies in
 * [1.9, 2.1], and E(0.05) / (sigma^2 h^2 / 2) = 1 within 0.5 % (the O(h^4)
 * term is ~h^2 of it).
 */
#include "kernel_ref.h"

/* the mean of exp(a . y) over the sphere |y| = r, |a| = 1 */
static ref_real sphere_mean(int dim, ref_real r)
{
    if (dim == 1) return coshl(r);
    if (dim == 3) return r > 0 ? sinhl(r) / r : 1;
    {
        /* I0(r) = sum (r^2/4)^k / (k!)^2 */
        ref_real term = 1, sum = 1, x = r * r / 4;
        int k;
        for (k = 1; k < 60; ++k) {
            term *= x / ((ref_real)k * k);
            sum += term;
        }
        return sum;
    }
}

typedef struct {
    sph_kernel k;
    int dim;
    sph_real h;
} conv_ctx;

static ref_real conv_integrand(ref_real q, void *p)
{
    const conv_ctx *c = (const conv_ctx *)p;
    const ref_real r = q * c->h;
    /* int over r = h int over q: W(r,h) h^d w-scaled, times h for dr */
    return (ref_real)sph_kernel_w(c->k, c->dim, (sph_real)r, c->h) * sphere_mean(c->dim, r) * ref_sphere(c->dim) *
           ref_pow(r, c->dim - 1) * c->h;
}

static double error_at(sph_kernel k, int dim, double h)
{
    conv_ctx c;
    c.k = k;
    c.dim = dim;
    c.h = (sph_real)h;
    return (double)(ref_integrate(conv_integrand, &c, 0, ref_kappa(k), 12) - 1);
}

static void test_convergence(sph_kernel k, int dim)
{
    const double hs[3] = {0.2, 0.1, 0.05};
    double E[3], p1, p2, lead;
    const double s = (double)sph_kernel_sigma(k, dim);
    int i;
    for (i = 0; i < 3; ++i) E[i] = error_at(k, dim, (double)(sph_real)hs[i]);
    p1 = log(E[0] / E[1]) / log(2.0);
    p2 = log(E[1] / E[2]) / log(2.0);
    lead = s * s * (double)(sph_real)hs[2] * (double)(sph_real)hs[2] / 2;
    th_begin("convergence to the delta function at order 2, %s %dD", sph_kernel_name(k), dim);
    TH_CHECK(p1 >= 1.9 && p1 <= 2.1, "order from h = 0.2, 0.1: %.4f", p1);
    TH_CHECK(p2 >= 1.9 && p2 <= 2.1, "order from h = 0.1, 0.05: %.4f", p2);
    TH_REL(E[2], lead, 5e-3);
    th_end();
    printf("info [%s]: %s %dD observed orders %.4f %.4f, E(0.05) / (sigma^2 h^2 / 2) = %.5f\n", TH_PRECISION,
           sph_kernel_name(k), dim, p1, p2, E[2] / lead);
}

int main(void)
{
    int ik, dim;
    for (ik = 0; ik < SPH_KERNEL_COUNT; ++ik)
        for (dim = 1; dim <= 3; ++dim) test_convergence(ref_kernels[ik], dim);
    return th_summary();
}
