/* examples/heat_conduction.c - 2-D transient heat conduction through a slab
 * 0 <= x <= 1 (periodic in y) with the variable-coefficient diffusion
 * operator of sph_kernel.h (docs/examples.md, "Heat conduction through two
 * layers").
 *
 *   dT_i/dt = div(k grad T)_i = sum_j V_j k_ij (T_i - T_j) F_ij     (O14)
 *   k_ij = 4 k_i k_j / (k_i + k_j)                                   (O13)
 * (rho c = 1). T(0) = 0 and T(1) = 1 are held by layers of fixed boundary
 * particles beyond each end: "mirror" walls take T_w = 2 T_b - T_f of the
 * fluid particle f they mirror (the linear continuation of the profile),
 * "fixed" walls hold T_w = T_b. Forward Euler with dt = 0.9 / max_i D_i,
 * D_i = sum_j V_j k_ij |F_ij| (Gershgorin: the operator's eigenvalues lie in
 * [-2 D_max, 0], so dt < 1 / D_max is stable).
 *
 * Two cases, both from T = 0:
 *   single     uniform k = 1; against the Fourier series of the heat equation
 *              T(x, t) = x + sum_m 2 (-1)^m / (m pi) sin(m pi x) exp(-m^2 pi^2 t)
 *   two-layer  k = 1 for x < 1/2, k = 100 for x > 1/2, to steady state; against
 *              the piecewise linear profile with flux continuity:
 *              T_i = k2 / (k1 + k2) at x = 1/2.
 *
 *   ./heat_conduction                 default: 30 particles across, Wendland C2, mirror walls
 *   ./heat_conduction --check         coarse run with validation bounds (make test)
 *   ./heat_conduction --study docs/results
 *                                     resolution / kernel / wall table into docs/results/
 */
#include "example_io.h"

#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define PI 3.14159265358979323846
/* The maximum principle: T starts at 0 and the walls hold 0 and 1, so max |T|
 * over the fluid stays at most 1; a run whose max |T| exceeds 1 + 0.05 has
 * gone unstable and stops with exit 1. */
#define HC_T_MARGIN 0.05
#define HC_BOUNDS "a run stops with exit 1 when max |T| exceeds the wall temperature 1 by more than 0.05 (maximum principle)"

typedef struct {
    int n;             /* particles across the slab */
    const char *kernel;
    const char *wall;  /* mirror | fixed */
    double hdx, k_ratio, t_single, t_end;
    int frames;
} hc_param;

typedef struct {
    double l2, max;    /* errors of the case at its end time */
    double seconds;
    long steps;
    double t_interface, t_interface_exact; /* two-layer: mean T of the two particle columns next to x = 1/2 */
} hc_result;

/* Single layer: the Fourier series of x on [0, 1] decaying mode by mode. */
static double hc_single_exact(double x, double t)
{
    double T = x;
    int m;
    for (m = 1; m <= 400; ++m) {
        const double e = exp(-(double)m * m * PI * PI * t);
        if (e < 1e-17) break;
        T += 2 * ((m & 1) ? -1.0 : 1.0) / (m * PI) * sin(m * PI * x) * e;
    }
    return T;
}

/* Two layers, steady: linear in each layer, k1 T' = k2 T' across x = 1/2. */
static double hc_two_layer_exact(double x, double k1, double k2)
{
    const double Ti = k2 / (k1 + k2);
    return x < 0.5 ? 2 * Ti * x : Ti + 2 * (1 - Ti) * (x - 0.5);
}

/* One case (two_layer 0 or 1). csv (may be NULL) receives the time series
 * t, L2 error, max error (single) or t, T at the interface (two-layer) and,
 * at the end, the profile x, T, exact T into profile (may be NULL); frames
 * (may be NULL) the VTK series. A temperature turning NaN or Inf stops the
 * run (SPH_ENONFINITE, no further frames). */
static int hc_run(const hc_param *P, int two_layer, hc_result *R, FILE *csv, FILE *profile, ex_series *frames,
                  const char *label)
{
    const int kid = sph_kernel_from_name(P->kernel), n = P->n;
    const double dx = 1.0 / n, h = P->hdx * dx, k1 = 1, k2 = two_layer ? P->k_ratio : 1;
    const double t_end = two_layer ? P->t_end : P->t_single;
    const int mirror = strcmp(P->wall, "mirror") == 0;
    double kappa, dmax = 0, dt, t0 = ex_now();
    int nl, ny, i, j, l, st = SPH_OK, frame = 0;
    sph_idx nf, ns, q;
    sph_real *x = NULL, *y = NULL, *T = NULL, *k = NULL, *V = NULL, *dT = NULL;
    sph_idx *img = NULL;
    double steps_d;
    ex_neighbours NL;
    ex_progress prog = ex_progress_start();
    sph_box box;
    sph_ctx c;
    long s, steps;
    ex_growth tmax = {"max |T|", "the explicit step exceeds the diffusion limit of this resolution and conductivity", 1, 1,
                      HC_T_MARGIN};
    if (kid < 0) return SPH_EKERNEL;
    if (!mirror && strcmp(P->wall, "fixed") != 0) return SPH_EINVAL;
    kappa = sph_kernel_support((sph_kernel)kid);
    nl = (int)ceil(kappa * P->hdx);          /* wall layers: the support reaches nl dx */
    ny = (int)ceil(2 * kappa * P->hdx) + 1;  /* periodic rows: the period exceeds 2 kappa h */
    if (n < 2 * nl || !(P->hdx > 0) || !(t_end > 0)) return SPH_EINVAL;
    memset(&NL, 0, sizeof NL);
    if ((st = ex_particle_count((double)(n + 2 * nl) * ny, "particles (--n)", &ns)) != SPH_OK) return st;
    nf = (sph_idx)n * ny;
    x = (sph_real *)ex_calloc((size_t)ns, sizeof *x, NULL), y = (sph_real *)ex_calloc((size_t)ns, sizeof *y, NULL);
    T = (sph_real *)ex_calloc((size_t)ns, sizeof *T, NULL), k = (sph_real *)ex_calloc((size_t)ns, sizeof *k, NULL);
    V = (sph_real *)ex_calloc((size_t)ns, sizeof *V, NULL), dT = (sph_real *)ex_calloc((size_t)ns, sizeof *dT, NULL);
    img = (sph_idx *)ex_calloc((size_t)ns, sizeof *img, NULL);
    if (!x || !y || !T || !k || !V || !dT || !img) {
        fprintf(stderr, "heat_conduction: cannot allocate the fields of %ld particles\n", (long)ns);
        st = EX_ENOMEM;
        goto done;
    }
    for (j = 0; j < ny; ++j)
        for (i = 0; i < n; ++i) { /* fluid: cell-centred lattice, T = 0 */
            q = (sph_idx)j * n + i;
            x[q] = (i + 0.5) * dx, y[q] = (j + 0.5) * dx;
            k[q] = x[q] < 0.5 ? k1 : k2;
        }
    for (j = 0; j < ny; ++j)
        for (l = 0; l < nl; ++l) { /* walls: left at -(l+1/2) dx, right at 1 + (l+1/2) dx, and their mirrors */
            q = nf + ((sph_idx)j * nl + l) * 2;
            x[q] = -(l + 0.5) * dx, y[q] = (j + 0.5) * dx, k[q] = k1, img[q] = (sph_idx)j * n + l;
            x[q + 1] = 1 + (l + 0.5) * dx, y[q + 1] = (j + 0.5) * dx, k[q + 1] = k2;
            img[q + 1] = (sph_idx)j * n + (n - 1 - l);
        }
    for (q = 0; q < ns; ++q) V[q] = dx * dx;
    box.lo[0] = box.lo[1] = box.lo[2] = 0;
    box.length[0] = 1, box.length[1] = ny * dx, box.length[2] = 1;
    box.periodic[0] = 0, box.periodic[1] = 1, box.periodic[2] = 0;
    st = ex_neighbours_update(&NL, 2, sph_view_soa(x, y, NULL), ns, nf, h, kappa, &box);
    for (q = 0; st == SPH_OK && q < nf; ++q) { /* Gershgorin bound of the operator, from the pair terms */
        double d = 0;
        sph_off o;
        for (o = NL.list.offset[q]; o < NL.list.offset[q + 1]; ++o) {
            const sph_idx p = NL.list.index[o];
            sph_real dxy[2];
            dxy[0] = x[q] - x[p], dxy[1] = sph_box_delta(&box, 1, y[q] - y[p]);
            d += sph_pair_diffusion(V[p], sph_harmonic_k(k[q], k[p]), 1, 0,
                                    fabs(sph_pair_kernel((sph_kernel)kid, 2, dxy, h).F));
        }
        dmax = d > dmax ? d : dmax;
    }
    steps_d = ceil(t_end / (0.9 / dmax));
    if (st == SPH_OK && !(steps_d < 1e9)) {
        fprintf(stderr, "heat_conduction: %.3g time steps is more than this example runs (1e9)\n", steps_d);
        st = SPH_ESIZE;
    }
    steps = st == SPH_OK ? (long)steps_d : 1;
    dt = t_end / (double)steps;
    c = sph_ctx_init((sph_kernel)kid, 2, h, &NL.list, sph_view_soa(x, y, NULL));
    c.box = &box;
    c.V = sph_view_soa(V, NULL, NULL);
    for (s = 0; st == SPH_OK; ++s) {
        const double t = (double)s * dt;
        double T_abs = 0;
        ex_field f[2];
        f[0].name = "temperature", f[0].v = sph_view_soa(T, NULL, NULL), f[0].ncomp = 1;
        f[1].name = "conductivity", f[1].v = sph_view_soa(k, NULL, NULL), f[1].ncomp = 1;
        for (q = 0; q < nf; ++q) T_abs = fabs(T[q]) > T_abs ? fabs(T[q]) : T_abs;
        if ((st = ex_fields_finite("heat_conduction", f, 1, nf, t)) != SPH_OK ||
            (st = ex_growth_check(&tmax, T_abs, t)) != SPH_OK)
            break;
        for (q = nf; q < ns; ++q) { /* wall temperatures */
            const double Tb = x[q] < 0 ? 0 : 1;
            T[q] = (sph_real)(mirror ? 2 * Tb - T[img[q]] : Tb);
        }
        if (csv != NULL && (s % (steps / 400 + 1) == 0 || s == steps)) {
            double e2 = 0, em = 0, ti = 0;
            for (q = 0; q < nf; ++q) {
                const double e = fabs(T[q] - hc_single_exact(x[q], t));
                e2 += e * e, em = e > em ? e : em;
                if (fabs(x[q] - 0.5) < dx) ti += T[q] / (2.0 * ny);
            }
            if (two_layer) fprintf(csv, "%.6g,%.9g\n", t, ti);
            else if (s > 0) fprintf(csv, "%.6g,%.6g,%.6g\n", t, sqrt(e2 / nf), em);
        }
        if (frames != NULL && P->frames > 0 && (s * P->frames) / steps >= frame) {
            if (ex_series_write(frames, t, ns, 2, sph_view_soa(x, y, NULL), f, 2) != 0) {
                st = EX_EWRITE;
                break;
            }
            ++frame;
        }
        if (s == steps) break;
        st = sph_diffusion(&c, sph_view_soa(k, NULL, NULL), sph_view_none(), sph_view_soa(T, NULL, NULL),
                           sph_view_none(), sph_out_soa(dT, NULL, NULL)); /* (O13), (O14) */
        c.validate = SPH_VALIDATE_ARGS; /* list and k checked once by the first call */
        for (q = 0; q < nf; ++q) T[q] += dt * dT[q];
        if (label != NULL) ex_progress_update(&prog, label, (double)(s + 1) / (double)steps);
    }
    if (label != NULL) ex_progress_done(&prog, label);
    R->l2 = R->max = R->t_interface = R->t_interface_exact = 0;
    for (q = 0; st == SPH_OK && q < nf; ++q) {
        const double Te = two_layer ? hc_two_layer_exact(x[q], k1, k2) : hc_single_exact(x[q], t_end);
        const double e = fabs(T[q] - Te);
        R->l2 += e * e / nf, R->max = e > R->max ? e : R->max;
        if (fabs(x[q] - 0.5) < dx) R->t_interface += T[q] / (2.0 * ny), R->t_interface_exact += Te / (2.0 * ny);
        if (profile != NULL && q < n) fprintf(profile, "%.6g,%.9g,%.9g\n", x[q], T[q], Te);
    }
    R->l2 = sqrt(R->l2);
    R->steps = steps;
    R->seconds = ex_now() - t0;
    if (st == SPH_OK && !(R->l2 < 1e30)) st = SPH_ENONFINITE;
done:
    ex_neighbours_free(&NL);
    free(x), free(y), free(T), free(k), free(V), free(dT), free(img);
    return st;
}

static void hc_print(const hc_param *P, int two_layer, const hc_result *R)
{
    printf("%-9s n %3d  %-12s %-6s walls  t %.3g  steps %7ld  L2 error %.3e  max error %.3e", two_layer ? "two-layer" : "single",
           P->n, P->kernel, P->wall, two_layer ? P->t_end : P->t_single, R->steps, R->l2, R->max);
    if (two_layer) printf("  T next to x = 1/2 %.5f (exact %.5f)", R->t_interface, R->t_interface_exact);
    printf("  %.1f s\n", R->seconds);
    fflush(stdout);
}

/* docs/heat_results.md and the profiles of the plots (outdir/heat_*.csv). */
static int hc_study(const hc_param *base, const char *docdir, const char *outdir)
{
    static const int res[3] = {20, 30, 40};
    static const char *kern[5] = {"cubic", "wendland_c2", "wendland_c4", "quintic", "lucy"};
    char path[1100];
    FILE *md;
    int q, two, bad = 0;
    snprintf(path, sizeof path, "%s/heat_results.md", docdir);
    if ((md = fopen(path, "w")) == NULL) return fprintf(stderr, "heat_conduction: cannot write %s\n", path), -1;
    fprintf(md, "Written by `heat_conduction --study` (h = %g dx, rho c = 1, T = 0 at t = 0). Errors are "
                "absolute (T runs from 0 to 1): L2 = root mean square over the particles, max = largest. Single "
                "layer: k = 1, against the Fourier series at t = %g. Two layers: k = 1 | %g, against the steady "
                "piecewise linear profile at t = %g (slowest mode decayed by exp(-4 pi^2 t)).\n\n",
            base->hdx, base->t_single, base->k_ratio, base->t_end);
    fprintf(md, "| particles across | kernel | walls | single: L2 | single: max | two layers: L2 | two layers: max | "
                "T next to x = 1/2: SPH / exact | steps (two layers) | run time |\n|---|---|---|---|---|---|---|---|---|---|\n");
    for (q = 0; q < 3 + 5 + 3; ++q) { /* resolutions; kernels; fixed walls at each resolution */
        hc_param P = *base;
        hc_result R[2];
        int a = SPH_OK;
        P.frames = 0;
        P.n = q < 3 ? res[q] : q < 8 ? res[1] : res[q - 8];
        if (q >= 3 && q < 8) P.kernel = kern[q - 3];
        if (q >= 8) P.wall = "fixed";
        if (q >= 3 && q < 8 && strcmp(P.kernel, base->kernel) == 0) continue;
        for (two = 0; two < 2 && a == SPH_OK; ++two) {
            FILE *prof;
            char label[80];
            snprintf(path, sizeof path, "%s/heat_%s_%d_%s_%s.csv", outdir, two ? "two_layer" : "single", P.n,
                     P.kernel, P.wall);
            prof = fopen(path, "w");
            if (prof != NULL) fprintf(prof, "x,T,exact T\n");
            snprintf(label, sizeof label, "heat %s %d %s %s", two ? "two-layer" : "single", P.n, P.kernel, P.wall);
            a = hc_run(&P, two, &R[two], NULL, prof, NULL, label);
            if (prof != NULL) fclose(prof);
            if (a == SPH_OK) hc_print(&P, two, &R[two]);
        }
        if (a != SPH_OK) {
            fprintf(md, "| %d | %s | %s | failed: %s | | | | | | |\n", P.n, P.kernel, P.wall, ex_strerror(a));
            bad = 1;
            continue;
        }
        fprintf(md, "| %d | %s | %s | %.2e | %.2e | %.2e | %.2e | %.5f / %.5f | %ld | %.1f s |\n", P.n, P.kernel, P.wall,
                R[0].l2, R[0].max, R[1].l2, R[1].max, R[1].t_interface, R[1].t_interface_exact, R[1].steps, R[0].seconds + R[1].seconds);
    }
    return fclose(md) != 0 || bad ? -1 : 0;
}

int main(int argc, char **argv)
{
    hc_param P;
    hc_result R[2];
    const char *out = "build/heat_conduction", *study = NULL;
    int threads = 1, check = 0, ascii = 0, st, two, nl;
    ex_series frames[2];
    /* Ranges: n to 1000 (the two-layer steps grow as n^2 k-ratio); h from dx
     * (below, a particle has hardly any neighbours) to 3 dx; k-ratio within
     * 1e-3 .. 1e3 (the step is set by the larger k, the run time by the ratio). */
    const ex_arg opt[] = {
        {"n", "particles across the slab (dx = 1/n)", NULL, &P.n, NULL, NULL, 8, 1000, 0, NULL},
        {"kernel", "smoothing kernel", NULL, NULL, &P.kernel, NULL, 0, 0, 0, ex_kernel_choices()},
        {"wall", "boundary particles: mirror (T_w = 2 T_b - T_f) or fixed (T_w = T_b)", NULL, NULL, &P.wall, NULL, 0,
         0, 0, "mirror|fixed"},
        {"hdx", "smoothing length h / dx", &P.hdx, NULL, NULL, NULL, 1, 3, 0, NULL},
        {"k-ratio", "conductivity of the right layer (left: 1)", &P.k_ratio, NULL, NULL, NULL, 1e-3, 1e3, 0, NULL},
        {"t-single", "end time of the single-layer transient", &P.t_single, NULL, NULL, NULL, 0, 10, EX_OPEN_LO, NULL},
        {"t-end", "end time of the two-layer run (steady by then)", &P.t_end, NULL, NULL, NULL, 0, 10, EX_OPEN_LO,
         NULL},
        {"out", "output directory (VTK frames, CSV series and profiles)", NULL, NULL, &out, NULL, 0, 0, 0, NULL},
        {"frames", "VTK frames per case: the start and this many more to the end (0: none)", NULL, &P.frames, NULL,
         NULL, 0, 10000, 0, NULL},
        {"ascii", "VTK frames in ASCII (default: binary)", NULL, NULL, NULL, &ascii, 0, 0, 0, NULL},
        {"threads", "OpenMP threads (0: the runtime's default; 1 by default: a few hundred particles lose more to thread synchronisation than they gain)",
         NULL, &threads, NULL, NULL, 0, 1024, 0, NULL},
        {"check", "coarse run; exit 1 if it misses its validation bounds", NULL, NULL, NULL, &check, 0, 0, 0, NULL},
        {"study", "write the error table into this directory (docs/results)", NULL, NULL, &study, NULL, 0, 0, 0, NULL},
    };
    P.n = 30, P.kernel = "wendland_c2", P.wall = "mirror", P.hdx = 1.3, P.k_ratio = 100, P.t_single = 0.1;
    P.t_end = 0.3, P.frames = 10;
    st = ex_parse_args(argc, argv, "2-D heat conduction through two layers (k 1:100) and one, against analytic solutions; " HC_BOUNDS,
                       opt, (int)(sizeof opt / sizeof opt[0]));
    if (st != 0) return st > 0 ? 0 : 2;
    nl = (int)ceil(sph_kernel_support((sph_kernel)sph_kernel_from_name(P.kernel)) * P.hdx);
    if (P.n < 2 * nl) { /* the wall layers mirror the first nl fluid columns on each side */
        fprintf(stderr, "%s: --n %d refused: with --kernel %s and --hdx %g the walls need n >= 2 ceil(kappa h / dx) = %d\n",
                argv[0], P.n, P.kernel, P.hdx, 2 * nl);
        return 2;
    }
#ifdef _OPENMP
    if (threads > 0) omp_set_num_threads(threads);
#else
    (void)threads;
#endif
    if (check) { /* coarse: 20 particles across */
        hc_param C = P;
        int ok = 1;
        C.n = 20, C.frames = 0;
        for (two = 0; two < 2; ++two) {
            st = hc_run(&C, two, &R[two], NULL, NULL, NULL, NULL);
            if (st != SPH_OK) {
                printf("heat_conduction --check: run failed: %s\n", ex_strerror(st));
                return 1;
            }
            hc_print(&C, two, &R[two]);
        }
        ok = R[0].max < 0.02 && R[1].max < 0.01 && fabs(R[1].t_interface - R[1].t_interface_exact) < 0.005;
        printf("heat_conduction --check: single-layer max error %.2e (bound 2e-2), two-layer max error %.2e (bound "
               "1e-2), error of T next to the interface %.2e (bound 5e-3): %s\n",
               R[0].max, R[1].max, fabs(R[1].t_interface - R[1].t_interface_exact), ok ? "pass" : "FAIL");
        return ok ? 0 : 1;
    }
    if (ex_mkdir_p(out) != 0) {
        fprintf(stderr, "heat_conduction: cannot create %s\n", out);
        return 2;
    }
    if (study != NULL) return hc_study(&P, study, out) == 0 ? 0 : 1;
    if (ex_series_open(&frames[0], out, "heat_single", ascii) != 0 ||
        ex_series_open(&frames[1], out, "heat_two_layer", ascii) != 0)
        return 2;
    for (two = 0; two < 2; ++two) {
        char path[2][1100];
        FILE *csv, *prof;
        snprintf(path[0], sizeof path[0], "%s/%s_series.csv", out, two ? "two_layer" : "single");
        snprintf(path[1], sizeof path[1], "%s/%s_profile.csv", out, two ? "two_layer" : "single");
        if ((csv = fopen(path[0], "w")) == NULL || (prof = fopen(path[1], "w")) == NULL) {
            fprintf(stderr, "heat_conduction: cannot write %s\n", csv == NULL ? path[0] : path[1]);
            if (csv != NULL) fclose(csv);
            return 2;
        }
        fprintf(csv, two ? "t,T at x = 1/2\n" : "t,L2 error,max error\n");
        fprintf(prof, "x,T,exact T\n");
        st = hc_run(&P, two, &R[two], csv, prof, &frames[two], two ? "heat two-layer" : "heat single");
        if ((fclose(csv) != 0 || fclose(prof) != 0) && st == SPH_OK) st = EX_EWRITE;
        if (st != SPH_OK) {
            fprintf(stderr, "heat_conduction: %s case failed: %s\n", two ? "two-layer" : "single", ex_strerror(st));
            ex_series_report(&frames[two]);
            break;
        }
        hc_print(&P, two, &R[two]);
        printf("wrote %s (%s) and %s (x, T, exact T at the end)\n", path[0],
               two ? "t, T next to x = 1/2" : "t, L2 error, max error", path[1]);
        ex_series_report(&frames[two]);
    }
    ex_series_close(&frames[0]), ex_series_close(&frames[1]);
    return st == SPH_OK ? 0 : 1;
}
