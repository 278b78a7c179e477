/* Operators: data layouts, separate targets, per-particle h, periodic boxes,
 * density and interpolation.
 *
 * The operators read every array in place through strided views, so SoA,
 * interleaved and AoS data must give bitwise the same results; a target is
 * summed over its own list in order, so probe points equal to particles
 * reproduce the particles' results bitwise; h_i = h_j = h gives h_ij = 2/(2h)
 * = 1/h exactly, so per-particle h equal to the uniform h is bitwise the
 * uniform result; a periodic box equals explicit ghost copies up to the
 * rounding of the shifted coordinates.
 */
#include "op_scene.h"

typedef struct {
    sph_real x, y, z, V, f, out[3];
} particle; /* an array-of-structs layout */

/* Runs density, interpolation, corrected gradient, Laplacian and the
 * corrected velocity gradient into res (n * 16 reals). */
static int run_all(sph_ctx *c, int n, sph_view f, sph_view ft, sph_view v, sph_view vt, sph_real *res)
{
    sph_real *T = ts_vec(9 * n);
    int st, i, a;
    sph_idx nfb;
    const sph_out r0 = sph_out_interleaved(res, 16);
    st = sph_density(c, r0);
    st |= sph_interpolate(c, f, sph_out_interleaved(res + 1, 16));
    st |= sph_gradient(c, SPH_SCHEME_CORRECTED, f, ft, sph_out_interleaved(res + 2, 16), &nfb);
    st |= sph_laplacian(c, f, ft, sph_out_interleaved(res + 5, 16));
    st |= sph_gradient_vector(c, SPH_SCHEME_CORRECTED, v, vt, T, 9, &nfb);
    for (i = 0; i < n; ++i)
        for (a = 0; a < 9; ++a) res[16 * i + 6 + a] = T[9 * i + a];
    free(T);
    return st;
}

static void test_layouts(void)
{
    ts_scene s;
    particle *P;
    sph_real *xs[3], *f, *r1, *r2, *r3;
    int i, a, st;
    th_begin("SoA, interleaved and AoS views give bitwise identical results (3D perturbed lattice)");
    ts_lattice(&s, SPH_KERNEL_WENDLAND_C2, 3, 6, 1.0 / 6, 1.3, 0.3, 2, NULL);
    P = (particle *)calloc((size_t)s.n, sizeof(particle));
    f = ts_vec(s.n), r1 = ts_vec(16 * s.n), r2 = ts_vec(16 * s.n), r3 = ts_vec(16 * s.n);
    for (a = 0; a < 3; ++a) xs[a] = ts_vec(s.n);
    for (i = 0; i < s.n; ++i) {
        for (a = 0; a < 3; ++a) xs[a][i] = s.x[3 * i + a];
        P[i].x = s.x[3 * i], P[i].y = s.x[3 * i + 1], P[i].z = s.x[3 * i + 2];
        P[i].V = s.V[i];
        P[i].f = f[i] = (sph_real)(ts_sine(3, s.x + 3 * i, NULL) + ts_linear(s.x + 3 * i));
    }
    s.c.m = s.c.V;
    st = run_all(&s.c, s.n, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_view_interleaved(s.x, 3), sph_view_none(), r1);
    s.c.x = sph_view_soa(xs[0], xs[1], xs[2]);
    st |= run_all(&s.c, s.n, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_view_soa(xs[0], xs[1], xs[2]), sph_view_none(), r2);
    s.c.x = sph_view_aos(&P[0].x, 3, sizeof(particle));
    s.c.V = s.c.m = sph_view_aos(&P[0].V, 1, sizeof(particle));
    st |= run_all(&s.c, s.n, sph_view_aos(&P[0].f, 1, sizeof(particle)), sph_view_none(),
                  sph_view_aos(&P[0].x, 3, sizeof(particle)), sph_view_none(), r3);
    TH_CHECK(st == SPH_OK, "status %d", st);
    TH_CHECK(memcmp(r1, r2, sizeof(sph_real) * 16 * (size_t)s.n) == 0, "SoA differs from interleaved");
    TH_CHECK(memcmp(r1, r3, sizeof(sph_real) * 16 * (size_t)s.n) == 0, "AoS differs from interleaved");
    /* AoS output view too */
    st = sph_gradient(&s.c, SPH_SCHEME_CORRECTED, sph_view_aos(&P[0].f, 1, sizeof(particle)), sph_view_none(),
                      sph_out_aos(P[0].out, 3, sizeof(particle)), NULL);
    for (i = 0; i < s.n; ++i)
        for (a = 0; a < 3; ++a) TH_CHECK(P[i].out[a] == r1[16 * i + 2 + a], "AoS output %d %d", i, a);
    for (a = 0; a < 3; ++a) free(xs[a]);
    free(P), free(f), free(r1), free(r2), free(r3);
    ts_free(&s);
    th_end();
}

static void test_probes(void)
{
    /* Probe points at the positions of every 7th particle, with their own
     * list (tp_brute_list over the particles) and their own target views. */
    ts_scene s;
    sph_real *f, *xp, *fp, *vp, *ra, *rp;
    tp_list Lp;
    sph_ctx cp;
    int i, a, np = 0, st;
    th_begin("probe points (targets != sources) reproduce the particles' results bitwise (2D)");
    ts_lattice(&s, SPH_KERNEL_QUINTIC, 2, 12, 1.0 / 12, 1.3, 0.3, 8, NULL);
    f = ts_vec(s.n), xp = ts_vec(3 * s.n), fp = ts_vec(s.n), vp = ts_vec(3 * s.n);
    ra = ts_vec(16 * s.n), rp = ts_vec(16 * s.n);
    for (i = 0; i < s.n; ++i) f[i] = (sph_real)ts_sine(2, s.x + 3 * i, NULL);
    for (i = 0; i < s.n; i += 7, ++np) {
        for (a = 0; a < 3; ++a) xp[3 * np + a] = vp[3 * np + a] = s.x[3 * i + a];
        fp[np] = f[i];
    }
    s.c.m = s.c.V;
    st = run_all(&s.c, s.n, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_view_interleaved(s.x, 3), sph_view_none(), ra);
    tp_brute_list(2, xp, np, s.x, s.n, (sph_real)s.h, NULL, NULL, sph_kernel_support(SPH_KERNEL_QUINTIC), TP_GATHER,
                  NULL, &Lp);
    cp = s.c;
    cp.list = &Lp.list;
    cp.x_target = sph_view_interleaved(xp, 3);
    st |= run_all(&cp, np, sph_view_soa(f, NULL, NULL), sph_view_soa(fp, NULL, NULL), sph_view_interleaved(s.x, 3), sph_view_interleaved(vp, 3), rp);
    TH_CHECK(st == SPH_OK, "status %d", st);
    for (i = 0; i < np; ++i)
        for (a = 0; a < 15; ++a) /* density, interpolation, gradient, Laplacian, velocity gradient */
            TH_CHECK(rp[16 * i + a] == ra[16 * (7 * i) + a], "probe %d quantity %d: %.17g vs %.17g", i, a,
                     (double)rp[16 * i + a], (double)ra[16 * 7 * i + a]);
    /* a target-side field is required once targets are separate */
    st = sph_laplacian(&cp, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_interleaved(rp, 16));
    TH_CHECK(st == SPH_ENULL, "missing f_target: status %d", st);
    free(f), free(xp), free(fp), free(vp), free(ra), free(rp);
    tp_free_list(&Lp);
    ts_free(&s);
    th_end();
}

static void test_per_particle_h(void)
{
    ts_scene s;
    sph_real *f, *hh, *r1, *r2;
    int i, st;
    th_begin("per-particle h equal to the uniform h gives bitwise the uniform result (2D)");
    ts_lattice(&s, SPH_KERNEL_CUBIC, 2, 10, 0.1, 1.3, 0.3, 3, NULL);
    f = ts_vec(s.n), hh = ts_vec(s.n), r1 = ts_vec(16 * s.n), r2 = ts_vec(16 * s.n);
    for (i = 0; i < s.n; ++i) {
        f[i] = (sph_real)ts_sine(2, s.x + 3 * i, NULL);
        hh[i] = (sph_real)s.h;
    }
    s.c.m = s.c.V;
    st = run_all(&s.c, s.n, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_view_interleaved(s.x, 3), sph_view_none(), r1);
    s.c.h_source = sph_view_soa(hh, NULL, NULL);
    s.c.h = -1; /* ignored when h_source is given */
    st |= run_all(&s.c, s.n, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_view_interleaved(s.x, 3), sph_view_none(), r2);
    TH_CHECK(st == SPH_OK, "status %d", st);
    TH_CHECK(memcmp(r1, r2, sizeof(sph_real) * 16 * (size_t)s.n) == 0, "per-particle h differs");
    free(f), free(hh), free(r1), free(r2);
    ts_free(&s);
    th_end();
}

static void test_ghosts(void)
{
    /* [0,1)^2 periodic vs the same particles plus ghost copies shifted by
     * +-1 (every copy within kappa h + 0.01 of the box) and no box. */
    ts_scene s;
    sph_box box;
    sph_real *f, *xg, *fg, *Vg, *r1, *r2;
    tp_list Lg;
    sph_ctx cg;
    int i, a, sx, sy, ng = 0, st;
    double R;
    th_begin("periodic box equals explicit ghost copies (2D perturbed lattice)");
    for (a = 0; a < 3; ++a) {
        box.lo[a] = 0;
        box.length[a] = 1;
        box.periodic[a] = 1;
    }
    ts_lattice(&s, SPH_KERNEL_WENDLAND_C4, 2, 12, 1.0 / 12, 1.3, 0.2, 6, &box);
    R = sph_kernel_support(SPH_KERNEL_WENDLAND_C4) * s.h + 0.2 / 12;
    f = ts_vec(s.n), xg = ts_vec(27 * s.n), fg = ts_vec(9 * s.n), Vg = ts_vec(9 * s.n);
    r1 = ts_vec(16 * s.n), r2 = ts_vec(16 * s.n);
    for (i = 0; i < s.n; ++i) f[i] = (sph_real)ts_sine(2, s.x + 3 * i, NULL);
    for (sx = 0; sx < 3; ++sx) /* the originals first: ghost i (shift 0,0) is particle i */
        for (sy = 0; sy < 3; ++sy)
            for (i = 0; i < s.n; ++i) {
                const double X = s.x[3 * i] + (sx == 2 ? -1 : sx), Y = s.x[3 * i + 1] + (sy == 2 ? -1 : sy);
                if (X < -R || X > 1 + R || Y < -R || Y > 1 + R) continue;
                xg[3 * ng] = (sph_real)X, xg[3 * ng + 1] = (sph_real)Y, xg[3 * ng + 2] = 0;
                fg[ng] = f[i], Vg[ng] = s.V[i];
                ++ng;
            }
    s.c.m = s.c.V;
    st = run_all(&s.c, s.n, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_view_interleaved(s.x, 3), sph_view_none(), r1);
    tp_brute_list(2, s.x, s.n, xg, ng, (sph_real)s.h, NULL, NULL, sph_kernel_support(SPH_KERNEL_WENDLAND_C4), TP_GATHER,
                  NULL, &Lg);
    cg = sph_ctx_init(SPH_KERNEL_WENDLAND_C4, 2, (sph_real)s.h, &Lg.list, sph_view_interleaved(xg, 3));
    cg.x_target = sph_view_interleaved(s.x, 3);
    cg.V = cg.m = sph_view_soa(Vg, NULL, NULL);
    st |= run_all(&cg, s.n, sph_view_soa(fg, NULL, NULL), sph_view_soa(f, NULL, NULL), sph_view_interleaved(xg, 3), sph_view_interleaved(s.x, 3), r2);
    TH_CHECK(st == SPH_OK, "status %d", st);
    TH_CHECK(Lg.list.offset[s.n] == s.L.list.offset[s.n], "ghost list has %ld pairs, periodic list %ld",
             (long)Lg.list.offset[s.n], (long)s.L.list.offset[s.n]);
    for (i = 0; i < s.n; ++i)
        for (a = 0; a < 6; ++a) { /* (the tensor of v = x is skipped: x is not periodic) */
            /* rounding of x +- 1 is eps relative to 1, i.e. eps / h relative to a gradient term */
            const double scale = a < 2 ? 1 : a < 5 ? 2 * TS_PI : 8 * TS_PI * TS_PI;
            TH_CLOSE(r2[16 * i + a], r1[16 * i + a], 200 * TH_EPS / s.h * scale);
        }
    free(f), free(xg), free(fg), free(Vg), free(r1), free(r2);
    tp_free_list(&Lg);
    ts_free(&s);
    th_end();
}

static void test_density_shepard(void)
{
    /* Density: m_j = rho0 V_j, so rho_i = rho0 sum_j V_j W_ij: at the centre of
     * a lattice within the zeroth lattice moment of 1 (1 % for h/dx = 1.3);
     * Shepard reproduces a constant at every target (surface included) to
     * round-off; a probe with no source in reach gets 0 and is counted. */
    ts_scene s;
    sph_real *m, *rho, *c, *sh, xp[6] = {0.5, 0.5, 0, 7, 7, 0}, cp[2], fp[2] = {0, 0};
    tp_list Lp;
    sph_ctx ctx;
    int i, st, centre = -1;
    double best = 1;
    sph_idx nempty = -1;
    th_begin("density, Shepard interpolation and the empty-target fallback (2D lattice)");
    ts_lattice(&s, SPH_KERNEL_CUBIC, 2, 16, 1.0 / 16, 1.3, 0, 1, NULL);
    m = ts_vec(s.n), rho = ts_vec(s.n), c = ts_vec(s.n), sh = ts_vec(s.n);
    for (i = 0; i < s.n; ++i) {
        const double d = fabs(s.x[3 * i] - 0.5) + fabs(s.x[3 * i + 1] - 0.5);
        m[i] = (sph_real)1000 * s.V[i];
        c[i] = (sph_real)1000;
        if (d < best) best = d, centre = i;
    }
    s.c.m = sph_view_soa(m, NULL, NULL);
    st = sph_density(&s.c, sph_out_soa(rho, NULL, NULL));
    st |= sph_interpolate_shepard(&s.c, sph_view_soa(c, NULL, NULL), sph_out_soa(sh, NULL, NULL), &nempty);
    TH_CHECK(st == SPH_OK && nempty == 0, "status %d, empty %d", st, (int)nempty);
    TH_NEAR(rho[centre], 1000, 0.01);
    for (i = 0; i < s.n; ++i) TH_NEAR(sh[i], 1000, 8 * TH_EPS);
    tp_brute_list(2, xp, 2, s.x, s.n, (sph_real)s.h, NULL, NULL, 2, TP_GATHER, NULL, &Lp);
    ctx = s.c;
    ctx.list = &Lp.list;
    ctx.x_target = sph_view_interleaved(xp, 3);
    st = sph_interpolate_shepard(&ctx, sph_view_soa(c, NULL, NULL), sph_out_soa(cp, NULL, NULL), &nempty);
    TH_CHECK(st == SPH_OK && nempty == 1, "status %d, empty %d", st, (int)nempty);
    TH_NEAR(cp[0], 1000, 8 * TH_EPS);
    TH_CHECK(cp[1] == 0, "empty target: %g", (double)cp[1]);
    (void)fp;
    free(m), free(rho), free(c), free(sh);
    tp_free_list(&Lp);
    ts_free(&s);
    th_end();
}

int main(void)
{
    test_layouts();
    test_probes();
    test_per_particle_h();
    test_ghosts();
    test_density_shepard();
    return th_summary();
}
