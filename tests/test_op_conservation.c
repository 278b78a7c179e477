/* Operators: conservation and the Laplacian/diffusion pair coefficients.
 *
 * The pair terms of the pressure form (O8), the symmetric gradient (O6), the
 * Laplacian (O12) and diffusion (O14) are antisymmetric in i <-> j when h_ij
 * is symmetric: dx_ji = -dx_ij exactly and F_ij = F_ji bit for bit (same r^2,
 * same h_i + h_j). So the total force sum_i m_i a_i (a_i = -grad p_i / rho_i)
 * and the total heat change sum_i V_i div(k grad f)_i vanish up to the
 * rounding of the accumulation: the bound used is 64 eps times the sum of
 * the magnitudes |m_i a_i| (each target adds ~50 terms; the errors of the
 * sums of different targets do not cancel).
 */
#include "op_scene.h"

/* A random cloud in a (optionally periodic) unit box with random masses,
 * densities, pressures and per-particle h; list by the symmetric criterion. */
typedef struct {
    int n, dim;
    sph_real *x, *m, *rho, *V, *p, *h, *gx[3];
    tp_list L;
    sph_box box;
    sph_ctx c;
} oc_cloud;

static void cloud_make(oc_cloud *s, int dim, int n, int periodic, uint64_t seed)
{
    tp_rng g;
    int i, a;
    const double dx = pow(1.0 / n, 1.0 / dim);
    g.s = seed;
    s->n = n;
    s->dim = dim;
    s->x = ts_vec(3 * n), s->m = ts_vec(n), s->rho = ts_vec(n), s->V = ts_vec(n), s->p = ts_vec(n), s->h = ts_vec(n);
    for (a = 0; a < 3; ++a) {
        s->gx[a] = ts_vec(n);
        s->box.lo[a] = 0;
        s->box.length[a] = 1;
        s->box.periodic[a] = periodic;
    }
    tp_uniform_cloud(dim, n, 1.0, &g, s->x);
    for (i = 0; i < n; ++i) {
        s->rho[i] = (sph_real)tp_range(&g, 900, 1100);
        s->m[i] = (sph_real)(tp_range(&g, 0.8, 1.2) * 1000 * pow(dx, dim));
        s->V[i] = s->m[i] / s->rho[i];
        s->p[i] = (sph_real)tp_range(&g, -50, 150);
        s->h[i] = (sph_real)(tp_range(&g, 1.2, 1.8) * dx);
    }
    tp_brute_list(dim, s->x, n, s->x, n, 0, s->h, s->h, sph_kernel_support(SPH_KERNEL_WENDLAND_C2), TP_SYMMETRIC,
                  periodic ? &s->box : NULL, &s->L);
    s->c = sph_ctx_init(SPH_KERNEL_WENDLAND_C2, dim, 0, &s->L.list, sph_view_interleaved(s->x, 3));
    s->c.h_source = sph_view_soa(s->h, NULL, NULL);
    s->c.m = sph_view_soa(s->m, NULL, NULL);
    s->c.rho = sph_view_soa(s->rho, NULL, NULL);
    s->c.V = sph_view_soa(s->V, NULL, NULL);
    s->c.box = periodic ? &s->box : NULL;
}

static void cloud_free(oc_cloud *s)
{
    int a;
    free(s->x), free(s->m), free(s->rho), free(s->V), free(s->p), free(s->h);
    for (a = 0; a < 3; ++a) free(s->gx[a]);
    tp_free_list(&s->L);
}

/* sum_i w_i g_i against sum_i |w_i g_i| (w = m_i / rho_i = V_i for both forms). */
static void check_total(oc_cloud *s, const char *what)
{
    int i, a;
    for (a = 0; a < s->dim; ++a) {
        double tot = 0, mag = 0;
        for (i = 0; i < s->n; ++i) {
            const double t = (double)s->m[i] * (-(double)s->gx[a][i] / (double)s->rho[i]);
            tot += t;
            mag += fabs(t);
        }
        TH_CHECK(mag > 0 && fabs(tot) <= 64 * TH_EPS * mag, "%s axis %d: total %.3g of magnitude %.3g", what, a, tot, mag);
    }
}

static void test_momentum(void)
{
    int dim, periodic, sc;
    for (dim = 2; dim <= 3; ++dim)
        for (periodic = 0; periodic <= 1; ++periodic)
            for (sc = 0; sc < 2; ++sc) {
                oc_cloud s;
                int st;
                const sph_scheme scheme = sc ? SPH_SCHEME_SYMMETRIC : SPH_SCHEME_PRESSURE;
                th_begin("total force of the %s form vanishes: %dD random cloud, per-particle h, %s",
                         sc ? "symmetric" : "pressure", dim, periodic ? "periodic box" : "free");
                cloud_make(&s, dim, dim == 2 ? 300 : 500, periodic, 21 + dim + 2 * periodic);
                st = sph_gradient(&s.c, scheme, sph_view_soa(s.p, NULL, NULL), sph_view_none(),
                                  sph_out_soa(s.gx[0], s.gx[1], s.gx[2]), NULL);
                TH_CHECK(st == SPH_OK, "status %d", st);
                check_total(&s, sc ? "symmetric" : "pressure");
                cloud_free(&s);
                th_end();
            }
}

static void test_heat(void)
{
    /* sum_i V_i lap f_i = 0 and sum_i V_i div(k grad f)_i = 0 (antisymmetric pairs). */
    oc_cloud s;
    sph_real *k = NULL, *L1 = NULL, *L2 = NULL;
    double t1 = 0, t2 = 0, m1 = 0, m2 = 0;
    int i, st;
    th_begin("Laplacian and diffusion conserve sum V f (3D random cloud, per-particle h, periodic)");
    cloud_make(&s, 3, 400, 1, 5);
    k = ts_vec(s.n), L1 = ts_vec(s.n), L2 = ts_vec(s.n);
    for (i = 0; i < s.n; ++i) k[i] = (sph_real)(i % 3 == 0 ? 0.1 : 5.0); /* jumps by 50 */
    st = sph_laplacian(&s.c, sph_view_soa(s.p, NULL, NULL), sph_view_none(), sph_out_soa(L1, NULL, NULL));
    st |= sph_diffusion(&s.c, sph_view_soa(k, NULL, NULL), sph_view_none(), sph_view_soa(s.p, NULL, NULL),
                        sph_view_none(), sph_out_soa(L2, NULL, NULL));
    TH_CHECK(st == SPH_OK, "status %d", st);
    for (i = 0; i < s.n; ++i) {
        t1 += (double)s.V[i] * L1[i], m1 += fabs((double)s.V[i] * L1[i]);
        t2 += (double)s.V[i] * L2[i], m2 += fabs((double)s.V[i] * L2[i]);
    }
    TH_CHECK(m1 > 0 && fabs(t1) <= 64 * TH_EPS * m1, "Laplacian total %.3g of %.3g", t1, m1);
    TH_CHECK(m2 > 0 && fabs(t2) <= 64 * TH_EPS * m2, "diffusion total %.3g of %.3g", t2, m2);
    free(k), free(L1), free(L2);
    cloud_free(&s);
    th_end();
}

static void test_diffusion_constant_k(void)
{
    /* (O13): k_ij = 4 k k / (2 k) = 2 k, so (O14) = k * (O12) for constant k. */
    ts_scene s;
    sph_real *f = NULL, *k = NULL, *L1 = NULL, *L2 = NULL;
    int i, st;
    th_begin("diffusion with constant k equals k times the Laplacian (2D perturbed lattice)");
    ts_lattice(&s, SPH_KERNEL_CUBIC, 2, 12, 1.0 / 12, 1.3, 0.2, 4, NULL);
    f = ts_vec(s.n), k = ts_vec(s.n), L1 = ts_vec(s.n), L2 = ts_vec(s.n);
    for (i = 0; i < s.n; ++i) {
        f[i] = (sph_real)ts_sine(2, s.x + 3 * i, NULL);
        k[i] = (sph_real)2.5;
    }
    st = sph_laplacian(&s.c, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_soa(L1, NULL, NULL));
    st |= sph_diffusion(&s.c, sph_view_soa(k, NULL, NULL), sph_view_none(), sph_view_soa(f, NULL, NULL),
                        sph_view_none(), sph_out_soa(L2, NULL, NULL));
    TH_CHECK(st == SPH_OK, "status %d", st);
    for (i = 0; i < s.n; ++i) TH_NEAR(L2[i], 2.5 * L1[i], 64 * TH_EPS * (1 + fabs(2.5 * L1[i])));
    free(f), free(k), free(L1), free(L2);
    ts_free(&s);
    th_end();
}

static void test_harmonic(void)
{
    th_begin("pair coefficient k_ij = 4 k_i k_j / (k_i + k_j), 0 when k_i k_j <= 0");
    TH_CLOSE(sph_harmonic_k(2, 2), 4, 0);        /* 2k for equal k */
    TH_CLOSE(sph_harmonic_k(1, 3), 3, 0);        /* 12 / 4 */
    TH_CLOSE(sph_harmonic_k(-2, -2), -4, 0);     /* same formula for negative pairs */
    TH_CLOSE(sph_harmonic_k(0, 0), 0, 0);        /* k_i + k_j = 0: no division */
    TH_CLOSE(sph_harmonic_k(1, -1), 0, 0);       /* k_i + k_j = 0 again */
    TH_CLOSE(sph_harmonic_k(0, 7), 0, 0);        /* a zero coefficient blocks the flux */
    TH_NEAR(sph_harmonic_k(1, 1e6), 4 * 1e6 / (1 + 1e6), 4 * TH_EPS); /* ~4 x the small one */
    th_end();
}

int main(void)
{
    test_momentum();
    test_heat();
    test_diffusion_constant_k();
    test_harmonic();
    return th_summary();
}
