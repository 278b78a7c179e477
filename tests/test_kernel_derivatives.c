/* tests/test_kernel_derivatives.c - dW/dr, every component of grad W,
 * d2W/dr2 and dW/dh of every kernel in 1-, 2- and 3-D against numerical
 * derivatives of the header's own W (and dW/dr for d2W/dr2): central
 * differences at steps d and d/2, Richardson-extrapolated,
 * D = (4 D(d/2) - D(d)) / 3 (error O(d^4) plus rounding eps |W| / d). Each
 * stencil stays inside one piece of width 1/2 in q (points closer to a
 * piece boundary than the stencil are skipped), where W is one polynomial.
 *
 * Steps (d in units of h; for dW/dh a relative step d in h) and bounds:
 * double d = 1e-3, |error| <= 1e-8 of max(|value|, 1e-2 * peak |value|);
 * float d = 2e-2, |error| <= 3e-4 of max(|value|, 1e-1 * peak |value|)
 * (rounding, eps |W| / d ~ 1e-5 of the peak, dominates). Also the identities
 * dW/dh = -(d W + r dW/dr) / h and F = (1/r) dW/dr (8 eps of the sum of the
 * magnitudes of their terms), and F(0) finite and the limit of dW/dr / r.
 */
#include "kernel_ref.h"

#define STEP (TH_IS_FLOAT ? 2e-2 : 1e-3)
#define FLOOR (TH_IS_FLOAT ? 1e-1 : 1e-2)
#define TOL (TH_IS_FLOAT ? 3e-4 : 1e-8)

enum { D_DWDR, D_GRAD, D_D2W, D_DWDH, D_COUNT };
static const char *const dname[D_COUNT] = {"dW/dr", "grad W", "d2W/dr2", "dW/dh"};

/* A scalar function of one variable t around a fixed configuration. */
typedef struct {
    sph_kernel k;
    int dim;
    int what; /* D_DWDR: W(r=t), D_D2W: dW/dr(r=t), D_DWDH: W(h=t), D_GRAD: W(x + t e_a) */
    sph_real r, h, x[3];
    int axis;
} fn1;

static double eval(const fn1 *f, sph_real t)
{
    switch (f->what) {
    case D_DWDR: return (double)sph_kernel_w(f->k, f->dim, t, f->h);
    case D_D2W: return (double)sph_kernel_dwdr(f->k, f->dim, t, f->h);
    case D_DWDH: return (double)sph_kernel_w(f->k, f->dim, f->r, t);
    default: {
        double r2 = 0;
        int a;
        for (a = 0; a < f->dim; ++a) {
            const double c = a == f->axis ? (double)t : (double)f->x[a];
            r2 += c * c;
        }
        return (double)sph_kernel_w(f->k, f->dim, (sph_real)sqrt(r2), f->h);
    }
    }
}

/* q of the configuration at t, to keep the stencil inside one piece. */
static double q_at(const fn1 *f, double t)
{
    double r2 = 0;
    int a;
    switch (f->what) {
    case D_DWDR:
    case D_D2W: return t / (double)f->h;
    case D_DWDH: return (double)f->r / t;
    default:
        for (a = 0; a < f->dim; ++a) {
            const double c = a == f->axis ? t : (double)f->x[a];
            r2 += c * c;
        }
        return sqrt(r2) / (double)f->h;
    }
}

/* Richardson-extrapolated central difference at t0 with step d; returns 0 and
 * leaves *out alone when the stencil leaves the piece of t0. */
static int numdiff(const fn1 *f, sph_real t0, double d, double *out)
{
    const int piece = (int)floor(q_at(f, (double)t0) * 2);
    double D[2];
    int i;
    for (i = -2; i <= 2; ++i)
        if ((int)floor(q_at(f, (double)t0 + i * d / 2) * 2) != piece) return 0;
    /* along an axis q(t) has its minimum at t = 0, where W(|x|) of a shape
     * with odd powers of q (Lucy, cubic, ...) is only C2 when x -> 0: skip */
    if (f->what == D_GRAD && fabs((double)t0) <= 1.01 * d) return 0;
    for (i = 0; i < 2; ++i) {
        const double s = d / (1 << i);
        const sph_real tp = (sph_real)((double)t0 + s), tm = (sph_real)((double)t0 - s);
        D[i] = (eval(f, tp) - eval(f, tm)) / ((double)tp - (double)tm);
    }
    *out = (4 * D[1] - D[0]) / 3;
    return 1;
}

static double kd_worst[D_COUNT];

static void compare(int which, double got, double num, double peak, double where)
{
    const double scale = fabs(got) > FLOOR * peak ? fabs(got) : FLOOR * peak;
    const double e = fabs(got - num) / scale;
    TH_CHECK(e <= TOL, "%s at %g: header %.17g, numerical %.17g, err %.3g of scale %.3g", dname[which], where, got,
             num, e, scale);
    if (e > kd_worst[which]) kd_worst[which] = e;
}

static double peak_of(sph_real (*g)(sph_kernel, int, sph_real, sph_real), sph_kernel k, int dim, sph_real h)
{
    double m = 0;
    int i;
    for (i = 0; i <= 1000; ++i) {
        const double v = fabs((double)g(k, dim, (sph_real)((double)sph_kernel_support(k) * (double)h * i / 1000), h));
        if (v > m) m = v;
    }
    return m;
}

static void test_radial(sph_kernel k, int dim)
{
    static const double hs[] = {1, 0.37};
    const double kap = (double)sph_kernel_support(k);
    size_t ih;
    int i, n = 0;
    th_begin("dW/dr, d2W/dr2, dW/dh vs Richardson differences, %s %dD", sph_kernel_name(k), dim);
    for (ih = 0; ih < 2; ++ih) {
        const sph_real h = (sph_real)hs[ih];
        const double p1 = peak_of(sph_kernel_dwdr, k, dim, h), p2 = peak_of(sph_kernel_d2wdr2, k, dim, h);
        const double ph = peak_of(sph_kernel_dwdh, k, dim, h);
        for (i = 1; i < 300; ++i) {
            const sph_real r = (sph_real)(kap * (double)h * i / 300);
            fn1 f;
            double num;
            f.k = k;
            f.dim = dim;
            f.h = h;
            f.r = r;
            f.what = D_DWDR;
            if (numdiff(&f, r, STEP * (double)h, &num)) {
                compare(D_DWDR, (double)sph_kernel_dwdr(k, dim, r, h), num, p1, (double)r);
                ++n;
            }
            f.what = D_D2W;
            if (numdiff(&f, r, STEP * (double)h, &num))
                compare(D_D2W, (double)sph_kernel_d2wdr2(k, dim, r, h), num, p2, (double)r);
            f.what = D_DWDH;
            if (numdiff(&f, h, STEP * (double)h, &num))
                compare(D_DWDH, (double)sph_kernel_dwdh(k, dim, r, h), num, ph, (double)r);
        }
    }
    TH_CHECK(n > 300, "only %d points judged", n);
    th_end();
}

static void test_grad(sph_kernel k, int dim)
{
    uint64_t seed = 777u + (uint64_t)k * 3u + (uint64_t)dim;
    const double kap = (double)sph_kernel_support(k);
    const sph_real h = (sph_real)0.8;
    const double peak = peak_of(sph_kernel_dwdr, k, dim, h);
    int i, a, n = 0;
    th_begin("grad W components vs Richardson differences of W, %s %dD", sph_kernel_name(k), dim);
    for (i = 0; i < 500; ++i) {
        fn1 f;
        sph_real g[3];
        f.k = k;
        f.dim = dim;
        f.h = h;
        f.what = D_GRAD;
        for (a = 0; a < 3; ++a) f.x[a] = (sph_real)(0.6 * kap * (double)h * ref_rand(&seed));
        sph_kernel_grad(k, dim, f.x, h, g);
        for (a = 0; a < dim; ++a) {
            double num;
            f.axis = a;
            if (numdiff(&f, f.x[a], STEP * (double)h, &num)) {
                compare(D_GRAD, (double)g[a], num, peak, (double)f.x[a]);
                ++n;
            }
        }
    }
    TH_CHECK(n > 200 * dim, "only %d components judged", n);
    th_end();
}

/* dW/dh = -(d W + r dW/dr)/h and F = dW/dr / r from the header's own values;
 * F(0) finite and the limit of dW/dr / r. */
static void test_identities(sph_kernel k, int dim)
{
    const double kap = (double)sph_kernel_support(k);
    const sph_real h = (sph_real)1.3;
    const double small = TH_IS_FLOAT ? 1e-3 : 1e-6;
    double F0, lim;
    int i;
    th_begin("identities dW/dh = -(d W + r dW/dr)/h, F = (1/r) dW/dr, F(0) = lim, %s %dD", sph_kernel_name(k), dim);
    for (i = 1; i < 400; ++i) {
        const sph_real r = (sph_real)(kap * (double)h * i / 400);
        const double W = (double)sph_kernel_w(k, dim, r, h), D = (double)sph_kernel_dwdr(k, dim, r, h);
        const double ident = -(dim * W + (double)r * D) / (double)h;
        TH_CLOSE(sph_kernel_dwdh(k, dim, r, h), ident, 8 * TH_EPS * (dim * fabs(W) + fabs((double)r * D)) / (double)h);
        TH_CLOSE(sph_kernel_f(k, dim, r, h), D / (double)r, 8 * TH_EPS * fabs(D / (double)r));
    }
    F0 = (double)sph_kernel_f(k, dim, 0, h);
    lim = (double)sph_kernel_dwdr(k, dim, (sph_real)(small * (double)h), h) / (small * (double)h);
    TH_CHECK(isfinite(F0) && F0 != 0, "F(0) = %g", F0);
    TH_REL(F0, lim, 10 * small);
    th_end();
}

int main(void)
{
    int ik, dim, i;
    for (ik = 0; ik < SPH_KERNEL_COUNT; ++ik) {
        for (dim = 1; dim <= 3; ++dim) {
            test_radial(ref_kernels[ik], dim);
            test_grad(ref_kernels[ik], dim);
            test_identities(ref_kernels[ik], dim);
        }
    }
    for (i = 0; i < D_COUNT; ++i)
        printf("info [%s]: kd_worst relative error of %s vs Richardson difference: %.3g (bound %.0e)\n", TH_PRECISION,
               dname[i], kd_worst[i], TOL);
    return th_summary();
}
