/* tests/test_op_fused.c - sph_density_gradient (docs/operators.md (O2) and
 * (O5) in one pass) and the vector square root of the operator loops.
 *
 * References: the fused operator must give what sph_density and
 * sph_gradient(SPH_SCHEME_DIFFERENCE) give separately (the same pair
 * arithmetic; only the order of the sum over j may differ, so agreement is to
 * round-off), with uniform and per-particle h, with and without a periodic
 * box; and, independently of the library's own operators, the density of an
 * unperturbed periodic lattice equals the lattice sum of W, which for the
 * quintic spline at h = 1.3 dx equals 1 / dx^dim to better than 1e-3 (the
 * discretisation error of a smooth kernel on a lattice, Quinlan et al. 2006),
 * and the difference gradient of a constant field is exactly 0. The square
 * roots are compared bit for bit with sqrt(). Per-particle h varying by a
 * factor 2: the fused fast loops equal the reference loops (bitwise where
 * the fast loops promise it). */
#include "harness.h"
#include "op_scene.h"

static const double TOL = sizeof(sph_real) == sizeof(float) ? 2e-5 : 1e-12;

/* Fused against separate calls on one scene; hv: per-particle h. */
static void check_scene(sph_kernel k, int dim, int hv, int periodic)
{
    sph_box box;
    ts_scene s;
    sph_real *m, *f, *hs, *rho1, *rho2, *g1[3], *g2[3];
    int i, a, st;
    for (a = 0; a < 3; ++a) {
        box.lo[a] = 0;
        box.length[a] = (sph_real)(8 * 0.125);
        box.periodic[a] = periodic;
    }
    th_begin("fused = separate, %s %dD, %s h, %s", sph_kernel_name(k), dim, hv ? "per-particle" : "uniform",
             periodic ? "periodic" : "no box");
    ts_lattice(&s, k, dim, 8, 0.125, 1.3, 0.2, 7u + (uint64_t)dim, periodic ? &box : NULL);
    m = ts_vec(s.n);
    f = ts_vec(s.n);
    hs = ts_vec(s.n);
    rho1 = ts_vec(s.n);
    rho2 = ts_vec(s.n);
    for (a = 0; a < 3; ++a) {
        g1[a] = ts_vec(s.n);
        g2[a] = ts_vec(s.n);
    }
    for (i = 0; i < s.n; ++i) {
        m[i] = (sph_real)(s.V[i] * (1 + 0.1 * sin(3.0 * i)));
        f[i] = (sph_real)ts_sine(dim, s.x + 3 * i, NULL);
        hs[i] = (sph_real)(s.h * (0.8 + 0.2 * cos(1.7 * i))); /* <= h: the list holds every pair */
    }
    s.c.m = sph_view_soa(m, NULL, NULL);
    if (hv) s.c.h_source = sph_view_soa(hs, NULL, NULL);
    st = sph_density(&s.c, sph_out_soa(rho1, NULL, NULL));
    st |= sph_gradient(&s.c, SPH_SCHEME_DIFFERENCE, sph_view_soa(f, NULL, NULL), sph_view_none(),
                       sph_out_soa(g1[0], g1[1], g1[2]), NULL);
    TH_CHECK(st == SPH_OK, "separate calls: status %d", st);
    st = sph_density_gradient(&s.c, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_soa(rho2, NULL, NULL),
                              sph_out_soa(g2[0], g2[1], g2[2]));
    TH_CHECK(st == SPH_OK, "fused: status %d", st);
    for (i = 0; i < s.n; ++i) {
        double gn = 0;
        TH_REL(rho2[i], rho1[i], TOL);
        for (a = 0; a < dim; ++a) gn += (double)g1[a][i] * g1[a][i];
        gn = sqrt(gn) + 1e-300;
        for (a = 0; a < dim; ++a) TH_CLOSE(g2[a][i], g1[a][i], 10 * TOL * gn);
    }
    free(m);
    free(f);
    free(hs);
    free(rho1);
    free(rho2);
    for (a = 0; a < 3; ++a) {
        free(g1[a]);
        free(g2[a]);
    }
    ts_free(&s);
    th_end();
}

/* Density, difference gradient and the fused pass against the sum of the
 * pair terms written out here: sph_pair_kernel (the kernel tables, not the
 * natural pieces the pair loops evaluate), sph_box_delta, m_j W and
 * V_j (f_j - f_i) F x_ij summed in order. Any implementation of the loops
 * (the chunked portable one, or the one-pass AVX-512 one where the build has
 * it) must agree to round-off: |op - sum| <= PTOL * sum_j |term| per target.
 * soa: positions as three arrays (stride 1) instead of interleaved (stride 3). */
static const double PTOL = sizeof(sph_real) == sizeof(float) ? 1e-5 : 1e-13;

/* Masses m_j = V_j (1 + 0.1 sin 3j), the field f = ts_sine, SoA copies of
 * the positions and two sets of outputs (rho, gradient) for scene s. */
typedef struct {
    sph_real *m, *f, *xs[3], *rho[2], *g[2][3];
} fz_data;

static void fz_alloc(fz_data *d, const ts_scene *s, int dim)
{
    int i, a, v;
    d->m = ts_vec(s->n);
    d->f = ts_vec(s->n);
    for (a = 0; a < 3; ++a) d->xs[a] = ts_vec(s->n);
    for (v = 0; v < 2; ++v) {
        d->rho[v] = ts_vec(s->n);
        for (a = 0; a < 3; ++a) d->g[v][a] = ts_vec(s->n);
    }
    for (i = 0; i < s->n; ++i) {
        d->m[i] = (sph_real)(s->V[i] * (1 + 0.1 * sin(3.0 * i)));
        d->f[i] = (sph_real)ts_sine(dim, s->x + 3 * i, NULL);
        for (a = 0; a < 3; ++a) d->xs[a][i] = s->x[3 * i + a];
    }
}

static void fz_free(fz_data *d)
{
    int a, v;
    free(d->m);
    free(d->f);
    for (a = 0; a < 3; ++a) free(d->xs[a]);
    for (v = 0; v < 2; ++v) {
        free(d->rho[v]);
        for (a = 0; a < 3; ++a) free(d->g[v][a]);
    }
}

static void check_pair_sums(sph_kernel k, int dim, int periodic, int soa)
{
    sph_box box;
    ts_scene s;
    fz_data d;
    const sph_off *off;
    const sph_idx *idx;
    int i, a, v, st;
    double worst = 0;
    for (a = 0; a < 3; ++a) {
        box.lo[a] = 0;
        box.length[a] = 1;
        box.periodic[a] = periodic;
    }
    th_begin("density, gradient, fused = sum of pair terms, %s %dD, %s, %s positions", sph_kernel_name(k), dim,
             periodic ? "periodic" : "no box", soa ? "SoA" : "interleaved");
    ts_lattice(&s, k, dim, 8, 0.125, 1.3, 0.2, 11u + (uint64_t)dim, periodic ? &box : NULL);
    fz_alloc(&d, &s, dim);
    if (soa) s.c.x = sph_view_soa(d.xs[0], dim > 1 ? d.xs[1] : NULL, dim > 2 ? d.xs[2] : NULL);
    s.c.m = sph_view_soa(d.m, NULL, NULL);
    st = sph_density(&s.c, sph_out_soa(d.rho[0], NULL, NULL));
    st |= sph_gradient(&s.c, SPH_SCHEME_DIFFERENCE, sph_view_soa(d.f, NULL, NULL), sph_view_none(),
                       sph_out_soa(d.g[0][0], d.g[0][1], d.g[0][2]), NULL);
    st |= sph_density_gradient(&s.c, sph_view_soa(d.f, NULL, NULL), sph_view_none(), sph_out_soa(d.rho[1], NULL, NULL),
                               sph_out_soa(d.g[1][0], d.g[1][1], d.g[1][2]));
    TH_CHECK(st == SPH_OK, "status %d", st);
    off = s.L.list.offset;
    idx = s.L.list.index;
    for (i = 0; i < s.n; ++i) {
        double r = 0, rabs = 0, gs[3] = {0, 0, 0}, gabs[3] = {0, 0, 0};
        sph_off o;
        for (o = off[i]; o < off[i + 1]; ++o) {
            const sph_idx j = idx[o];
            sph_real dx[3] = {0, 0, 0};
            sph_pair p;
            double c;
            for (a = 0; a < dim; ++a) dx[a] = sph_box_delta(s.c.box, a, s.x[3 * i + a] - s.x[3 * j + a]);
            p = sph_pair_kernel(k, dim, dx, (sph_real)s.h);
            r += (double)d.m[j] * p.W;
            rabs += fabs((double)d.m[j] * p.W);
            c = (double)s.V[j] * ((double)d.f[j] - d.f[i]) * p.F;
            for (a = 0; a < dim; ++a) {
                gs[a] += c * dx[a];
                gabs[a] += fabs(c * dx[a]);
            }
        }
        for (v = 0; v < 2; ++v) {
            const double e = fabs(d.rho[v][i] - r) / rabs;
            worst = e > worst ? e : worst;
            TH_CHECK(e <= PTOL, "%s rho at %d: %.17g, pair sum %.17g", v ? "fused" : "density", i, (double)d.rho[v][i], r);
            for (a = 0; a < dim; ++a) {
                const double eg = fabs(d.g[v][a][i] - gs[a]) / (gabs[a] + 1e-300);
                worst = eg > worst ? eg : worst;
                TH_CHECK(eg <= PTOL, "%s gradient %d at %d: %.17g, pair sum %.17g", v ? "fused" : "gradient", a, i,
                         (double)d.g[v][a][i], gs[a]);
            }
        }
    }
    if (dim == 3 && k == SPH_KERNEL_QUINTIC)
        printf("info [%s]: worst |operator - pair sum| / sum |terms|, quintic 3D %s %s: %.3g\n",
               sizeof(sph_real) == sizeof(float) ? "float" : "double", periodic ? "periodic" : "no box",
               soa ? "SoA" : "interleaved", worst);
    fz_free(&d);
    ts_free(&s);
    th_end();
}

/* Per-particle h varying from 0.5 h to h (W at h_i, F at h_ij per pair):
 * the fused pass of the fast loops against the reference loops
 * (ctx.loops = SPH_LOOPS_REFERENCE), every view SoA so that the one-pass
 * loop reads them all at the offsets of x, and once with h interleaved with
 * another stride. Bitwise where the fast loops promise it (no OpenMP, the
 * portable level, no contraction: sph__fp_contracted), else within HTOL of the
 * largest |value|. */
#if defined(_OPENMP)
#define HV_BITWISE 0
#elif defined(SPH_OP_REFERENCE)
#define HV_BITWISE 1
#else
#define HV_BITWISE (sph_isa() == SPH_ISA_PORTABLE)
#endif
static const double HTOL = sizeof(sph_real) == sizeof(float) ? 1e-5 : 1e-13;

static void check_hv_twins(sph_kernel k, int dim, int periodic, int h_strided)
{
    sph_box box;
    ts_scene s;
    fz_data d;
    sph_real *hs, *h2;
    double big[4] = {0, 0, 0, 0};
    int i, a, v, st = SPH_OK;
    const int bitwise = HV_BITWISE && !sph__fp_contracted();
    for (a = 0; a < 3; ++a) box.lo[a] = 0, box.length[a] = 1, box.periodic[a] = periodic;
    th_begin("fused, h varying 0.5..1 h: fast = reference loops%s, %s %dD, %s, h %s", bitwise ? " (bitwise)" : "",
             sph_kernel_name(k), dim, periodic ? "periodic" : "no box", h_strided ? "strided" : "SoA");
    ts_lattice(&s, k, dim, 8, 0.125, 1.3, 0.2, 5u + (uint64_t)dim, periodic ? &box : NULL);
    fz_alloc(&d, &s, dim);
    hs = ts_vec(s.n), h2 = ts_vec(2 * s.n);
    for (i = 0; i < s.n; ++i) /* <= h: the list holds every pair */
        hs[i] = h2[2 * i] = (sph_real)(s.h * (0.75 + 0.25 * cos(2.3 * i)));
    s.c.x = sph_view_soa(d.xs[0], dim > 1 ? d.xs[1] : NULL, dim > 2 ? d.xs[2] : NULL);
    s.c.m = sph_view_soa(d.m, NULL, NULL);
    s.c.h_source = h_strided ? sph_view_interleaved(h2, 2) : sph_view_soa(hs, NULL, NULL);
    for (v = 0; v < 2; ++v) {
        s.c.loops = v ? SPH_LOOPS_REFERENCE : SPH_LOOPS_FAST;
        st |= sph_density_gradient(&s.c, sph_view_soa(d.f, NULL, NULL), sph_view_none(), sph_out_soa(d.rho[v], NULL, NULL),
                                   sph_out_soa(d.g[v][0], d.g[v][1], d.g[v][2]));
    }
    TH_CHECK(st == SPH_OK, "status %d", st);
    for (i = 0; i < s.n; ++i) {
        big[0] = fmax(big[0], fabs((double)d.rho[1][i]));
        for (a = 0; a < dim; ++a) big[1 + a] = fmax(big[1 + a], fabs((double)d.g[1][a][i]));
    }
    for (i = 0; i < s.n; ++i) {
        TH_CLOSE(d.rho[0][i], d.rho[1][i], bitwise ? 0 : HTOL * big[0]);
        for (a = 0; a < dim; ++a) TH_CLOSE(d.g[0][a][i], d.g[1][a][i], bitwise ? 0 : HTOL * big[1 + a]);
    }
    fz_free(&d);
    free(hs), free(h2);
    ts_free(&s);
    th_end();
}

/* Unperturbed periodic lattice, quintic, h = 1.3 dx: rho = 1 / dx^dim... with
 * m = 1 the lattice sum of W; f constant: gradient exactly 0. */
static void check_lattice(int dim)
{
    const int side = 8;
    const double dx = 1.0 / side;
    sph_box box;
    ts_scene s;
    sph_real *m, *f, *rho, *g[3];
    int i, a, st;
    th_begin("fused on a periodic lattice, quintic %dD", dim);
    for (a = 0; a < 3; ++a) {
        box.lo[a] = 0;
        box.length[a] = 1;
        box.periodic[a] = 1;
    }
    ts_lattice(&s, SPH_KERNEL_QUINTIC, dim, side, dx, 1.3 * 3 / 2, 0, 3u, &box); /* h = 1.3 dx */
    m = ts_vec(s.n);
    f = ts_vec(s.n);
    rho = ts_vec(s.n);
    for (a = 0; a < 3; ++a) g[a] = ts_vec(s.n);
    for (i = 0; i < s.n; ++i) {
        m[i] = (sph_real)pow(dx, dim); /* rho0 = 1 */
        f[i] = (sph_real)2.5;
    }
    s.c.m = sph_view_soa(m, NULL, NULL);
    st = sph_density_gradient(&s.c, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_soa(rho, NULL, NULL),
                              sph_out_soa(g[0], g[1], g[2]));
    TH_CHECK(st == SPH_OK, "status %d", st);
    for (i = 0; i < s.n; ++i) {
        TH_REL(rho[i], 1.0, 1e-3);
        for (a = 0; a < dim; ++a) TH_CHECK(g[a][i] == 0, "gradient of a constant: %g at %d", (double)g[a][i], i);
    }
    free(m);
    free(f);
    free(rho);
    for (a = 0; a < 3; ++a) free(g[a]);
    ts_free(&s);
    th_end();
}

/* Errors: nothing is written. */
static void check_errors(void)
{
    ts_scene s;
    sph_real f[64], rho[64], g[3][64];
    const sph_real SENT = (sph_real)-123.5;
    int i, st;
    th_begin("fused: errors");
    ts_lattice(&s, SPH_KERNEL_CUBIC, 2, 4, 0.25, 1.3, 0, 1u, NULL);
    for (i = 0; i < 64; ++i) f[i] = rho[i] = g[0][i] = g[1][i] = g[2][i] = SENT;
    st = sph_density_gradient(&s.c, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_soa(rho, NULL, NULL),
                              sph_out_soa(g[0], g[1], NULL));
    TH_CHECK(st == SPH_ENULL, "without masses: %d", st);
    s.c.m = s.c.V;
    st = sph_density_gradient(&s.c, sph_view_none(), sph_view_none(), sph_out_soa(rho, NULL, NULL),
                              sph_out_soa(g[0], g[1], NULL));
    TH_CHECK(st == SPH_ENULL, "without f: %d", st);
    st = sph_density_gradient(&s.c, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_soa(NULL, NULL, NULL),
                              sph_out_soa(g[0], g[1], NULL));
    TH_CHECK(st == SPH_ENULL, "without rho: %d", st);
    st = sph_density_gradient(&s.c, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_soa(rho, NULL, NULL),
                              sph_out_soa(g[0], NULL, NULL));
    TH_CHECK(st == SPH_ENULL, "gradient with one of two components: %d", st);
    st = sph_density_gradient(NULL, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_soa(rho, NULL, NULL),
                              sph_out_soa(g[0], g[1], NULL));
    TH_CHECK(st == SPH_ENULL, "NULL context: %d", st);
    f[3] = (sph_real)NAN;
    st = sph_density_gradient(&s.c, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_soa(rho, NULL, NULL),
                              sph_out_soa(g[0], g[1], NULL));
    TH_CHECK(st == SPH_ENONFINITE, "NaN in f: %d", st);
    for (i = 0; i < 64; ++i) TH_CHECK(rho[i] == SENT && g[0][i] == SENT && g[1][i] == SENT, "written at %d", i);
    ts_free(&s);
    th_end();
}

/* The chunk square root equals sqrt() bit for bit (vector and portable paths). */
#if !defined(SPH_OP_REFERENCE)
static void check_sqrt(void)
{
    sph_real r[SPH__CHUNK], want[SPH__CHUNK];
    tp_rng g;
    int k, rep;
    th_begin("chunk square root = sqrt()");
    g.s = 99;
    for (rep = 0; rep < 200; ++rep) {
        for (k = 0; k < SPH__CHUNK; ++k) {
            const double e = 60 * (tp_uniform(&g) - 0.5);
            r[k] = (sph_real)(tp_uniform(&g) * pow(10.0, sizeof(sph_real) == sizeof(float) ? e / 2 : e));
        }
        r[0] = 0;
        r[1] = sizeof(sph_real) == sizeof(float) ? (sph_real)FLT_MIN / 4 : (sph_real)DBL_MIN / 4;
        r[2] = 1;
        for (k = 0; k < SPH__CHUNK; ++k) want[k] = sph__sqrt(r[k]);
        sph__sqrt_chunk(r, SPH__CHUNK);
        for (k = 0; k < SPH__CHUNK; ++k)
            TH_CHECK(r[k] == want[k], "sqrt at %d: %.17g, expected %.17g", k, (double)r[k], (double)want[k]);
    }
    th_end();
}
#endif

int main(void)
{
    const sph_kernel ks[2] = {SPH_KERNEL_CUBIC, SPH_KERNEL_QUINTIC};
    int dim, ki, hv, per, soa;
    for (dim = 1; dim <= 3; ++dim)
        for (ki = 0; ki < 2; ++ki)
            for (hv = 0; hv < 2; ++hv)
                for (per = 0; per < 2; ++per) check_scene(ks[ki], dim, hv, per);
    for (dim = 1; dim <= 3; ++dim)
        for (ki = 0; ki < SPH_KERNEL_COUNT; ++ki)
            for (per = 0; per < 2; ++per)
                for (soa = 0; soa < 2; ++soa) check_pair_sums((sph_kernel)ki, dim, per, soa);
    for (dim = 1; dim <= 3; ++dim)
        for (ki = 0; ki < SPH_KERNEL_COUNT; ++ki)
            for (per = 0; per < 2; ++per) check_hv_twins((sph_kernel)ki, dim, per, per);
    check_lattice(2);
    check_lattice(3);
    check_errors();
#if !defined(SPH_OP_REFERENCE)
    check_sqrt();
#endif
    return th_summary();
}
