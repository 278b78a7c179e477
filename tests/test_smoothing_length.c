/* Adaptive smoothing length (sph_h_solve, docs/smoothing_length.md (H1)-(H4)):
 * h_i = eta (m_i / rho_i)^(1/d) with rho_i = sum_j m_j W(r_ij, h_i) met to
 * 1e-6 relative (double) in a few density sums on lattices and on a Gaussian
 * clump, against densities and Omega summed independently here over every
 * particle with the scalar kernel functions; the beyond-the-list status and
 * its re-search, and that status (never a converged h) from any guess near
 * the list's radius when the solution lies beyond it; non-convergence
 * reported; bad input refused; h, rho and Omega written through an
 * array-of-structs view are bitwise those of separate arrays; one mass for
 * all through a view of stride 0 gives the bits of an array of that mass
 * (h solve, gather and pair-once grad-h forces), and the operators refuse it.
 */
#include "harness.h"
#include "support/particles.h"


/* Reference (H2) and (H4) for particle i at h: sums over all n particles. */
static void ref_sums(sph_kernel k, int dim, const sph_real *x, const sph_real *m, int n, const sph_box *box, int i,
                     double h, double *rho, double *omega)
{
    double s = 0, sd = 0;
    int j;
    for (j = 0; j < n; ++j) {
        const double r = sqrt((double)tp_r2(dim, x + 3 * i, x + 3 * j, box));
        s += (double)m[j] * (double)sph_kernel_w(k, dim, (sph_real)r, (sph_real)h);
        sd += (double)m[j] * (double)sph_kernel_dwdh(k, dim, (sph_real)r, (sph_real)h);
    }
    *rho = s;
    *omega = 1 + h / (dim * s) * sd;
}

/* Largest relative residual |h - eta (m / rho_ref(h))^(1/d)| / h and Omega error over the particles. */
static void residuals(sph_kernel k, int dim, const sph_real *x, const sph_real *m, int n, const sph_box *box,
                      double eta, const sph_real *h, const sph_real *rho, const sph_real *om, double *res_h,
                      double *err_rho, double *err_om)
{
    int i;
    *res_h = *err_rho = *err_om = 0;
    for (i = 0; i < n; ++i) {
        double r, o, e;
        ref_sums(k, dim, x, m, n, box, i, (double)h[i], &r, &o);
        e = fabs((double)h[i] - eta * pow((double)m[i] / r, 1.0 / dim)) / (double)h[i];
        *res_h = e > *res_h ? e : *res_h;
        e = fabs((double)rho[i] - r) / r;
        *err_rho = e > *err_rho ? e : *err_rho;
        e = fabs((double)om[i] - o);
        *err_om = e > *err_om ? e : *err_om;
    }
}

/* Tolerance asked of the solver and bound on the residual checked. */
#define TOL (TH_IS_FLOAT ? 64 * (double)FLT_EPSILON : 1e-7)
#define RES (TH_IS_FLOAT ? 3e-5 : 1e-6)

static void lattice_case(sph_kernel k, int dim, int n1)
{
    const double dx = 1, eta = 1.2, h0 = 0.8 * eta * dx; /* the guess 20 % short */
    const double kappa = (double)sph_kernel_support(k);
    const int n = tp_lattice_count(dim, n1);
    sph_real *x = malloc(sizeof(sph_real) * 3 * (size_t)n), *m = malloc(sizeof(sph_real) * (size_t)n);
    sph_real *h = malloc(sizeof(sph_real) * (size_t)n), *rho = malloc(sizeof(sph_real) * (size_t)n);
    sph_real *om = malloc(sizeof(sph_real) * (size_t)n);
    int *it = malloc(sizeof(int) * (size_t)n), *state = malloc(sizeof(int) * (size_t)n), i, st;
    sph_box box = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    tp_list L;
    sph_hctx c;
    sph_hreport rep;
    double res, erho, eom;
    th_begin("h solve: %dD %s lattice %d^%d, guess 0.8 eta dx", dim, sph_kernel_name(k), n1, dim);
    for (i = 0; i < dim; ++i) box.length[i] = (sph_real)(n1 * dx), box.periodic[i] = 1;
    tp_lattice(dim, n1, dx, x);
    for (i = 0; i < n; ++i) m[i] = 1, h[i] = (sph_real)h0;
    TH_CHECK(tp_brute_list(dim, x, n, x, n, (sph_real)(1.5 * eta * dx), NULL, NULL, (sph_real)kappa, TP_GATHER, &box,
                           &L) == 0, "out of memory");
    c = sph_hctx_init(k, dim, &L.list, sph_view_interleaved(x, 3), sph_view_soa(m, NULL, NULL),
                      (sph_real)(1.5 * eta * dx));
    c.box = &box;
    c.tol = (sph_real)TOL;
    st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, state, &rep);
    TH_CHECK(st == SPH_OK, "status %s", sph_strerror(st));
    TH_CHECK(rep.n_not_converged == 0 && rep.n_beyond_list == 0, "%d not converged, %d beyond", (int)rep.n_not_converged,
             (int)rep.n_beyond_list);
    /* Newton from 20 % off converges quadratically: a handful of sums */
    TH_CHECK(rep.max_iterations <= 6, "max iterations %d", rep.max_iterations);
    for (i = 0; i < n; ++i) TH_CHECK(state[i] == SPH_H_CONVERGED && it[i] >= 2, "particle %d state %d it %d", i, state[i], it[i]);
    residuals(k, dim, x, m, n, &box, eta, h, rho, om, &res, &erho, &eom);
    TH_CHECK(res < RES, "residual of (H1) %.3g", res);
    TH_CHECK(erho < 100 * TH_EPS, "rho against the reference sum: %.3g", erho);
    TH_CHECK(eom < 100 * TH_EPS, "Omega against the reference sum: %.3g", eom);
    /* a lattice is uniform: every particle gets the same h */
    for (i = 1; i < n; ++i) TH_CHECK(fabs((double)h[i] - (double)h[0]) <= 1e-5 * (double)h[0], "h[%d] %g h[0] %g", i, (double)h[i], (double)h[0]);
    printf("    %dD %s lattice: max %d, mean %.2f density sums; residual %.2e; h / dx %.6f, Omega %.6f\n", dim,
           sph_kernel_name(k), rep.max_iterations, (double)rep.iterations / n, res, (double)h[0], (double)om[0]);
    tp_free_list(&L);
    free(x), free(m), free(h), free(rho), free(om), free(it), free(state);
    th_end();
}

/* Gaussian clump: densities over several decades; lists searched with a per-particle
 * radius of 1.3 h_guess, re-searched for the particles that report SPH_H_BEYOND_LIST. */
static void clump_case(void)
{
    const int n = 1500, dim = 3;
    const sph_kernel k = SPH_KERNEL_CUBIC;
    const double eta = 1.2;
    sph_real *x = malloc(sizeof(sph_real) * 3 * (size_t)n), *m = malloc(sizeof(sph_real) * (size_t)n);
    sph_real *h = malloc(sizeof(sph_real) * (size_t)n), *rho = malloc(sizeof(sph_real) * (size_t)n);
    sph_real *om = malloc(sizeof(sph_real) * (size_t)n), *hl = malloc(sizeof(sph_real) * (size_t)n);
    int *it = malloc(sizeof(int) * (size_t)n), i, a, round, st = SPH_OK, sums = 0, maxit = 0;
    tp_rng g = {12345};
    tp_list L;
    sph_hctx c;
    sph_hreport rep;
    double res, erho, eom, rmin = 1e300, rmax = 0;
    th_begin("h solve: 3D Gaussian clump of %d particles, lists regrown where h outgrows them", n);
    for (i = 0; i < n; ++i) {
        for (a = 0; a < 3; ++a) { /* Box-Muller: a unit normal per axis */
            const double u1 = 1 - tp_uniform(&g), u2 = tp_uniform(&g);
            x[3 * i + a] = (sph_real)(sqrt(-2 * log(u1)) * cos(2 * 3.14159265358979323846 * u2));
        }
        m[i] = (sph_real)(1.0 / n);
        h[i] = (sph_real)0.3; /* one guess for all: far off both in the core and in the halo */
    }
    rep.n_beyond_list = 1;
    for (round = 0; round < 8 && rep.n_beyond_list > 0; ++round) {
        for (i = 0; i < n; ++i) hl[i] = (sph_real)1.3 * h[i];
        TH_CHECK(tp_brute_list(dim, x, n, x, n, 0, hl, NULL, 2, TP_GATHER, NULL, &L) == 0, "out of memory");
        c = sph_hctx_init(k, dim, &L.list, sph_view_interleaved(x, 3), sph_view_soa(m, NULL, NULL), 0);
        c.h_list = sph_view_soa(hl, NULL, NULL);
        c.tol = (sph_real)TOL;
        st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, &rep);
        TH_CHECK(st == SPH_OK, "status %s", sph_strerror(st));
        tp_free_list(&L);
        sums += (int)rep.iterations;
        maxit = rep.max_iterations > maxit ? rep.max_iterations : maxit;
        if (st != SPH_OK) break;
    }
    TH_CHECK(rep.n_beyond_list == 0 && rep.n_not_converged == 0, "after %d rounds: %d beyond, %d not converged", round,
             (int)rep.n_beyond_list, (int)rep.n_not_converged);
    TH_CHECK(round <= 4, "%d searches", round);
    TH_CHECK(rep.max_iterations <= 8, "last round: max iterations %d", rep.max_iterations);
    residuals(k, dim, x, m, n, NULL, eta, h, rho, om, &res, &erho, &eom);
    TH_CHECK(res < RES, "residual of (H1) %.3g", res);
    TH_CHECK(erho < 100 * TH_EPS && eom < 100 * TH_EPS, "rho error %.3g, Omega error %.3g", erho, eom);
    for (i = 0; i < n; ++i) {
        rmin = rho[i] < rmin ? rho[i] : rmin;
        rmax = rho[i] > rmax ? rho[i] : rmax;
    }
    TH_CHECK(rmax / rmin > 100, "density contrast %.3g (the clump should span decades)", rmax / rmin);
    printf("    clump: %d searches, last solve max %d, mean %.2f sums; all solves %d sums (%.2f per particle); "
           "residual %.2e; density contrast %.0f\n",
           round, rep.max_iterations, (double)rep.iterations / n, sums, (double)sums / n, res, rmax / rmin);
    free(x), free(m), free(h), free(rho), free(om), free(hl), free(it);
    th_end();
}

/* A list radius below the solution: every particle reports it with a larger h; then converges. */
static void beyond_case(void)
{
    const int n1 = 8, n = n1 * n1 * n1;
    sph_real x[3 * 512], m[512], h[512], rho[512], om[512];
    int state[512], i, all = 1;
    sph_box box = {{0, 0, 0}, {8, 8, 8}, {1, 1, 1}};
    tp_list L;
    sph_hctx c;
    sph_hreport rep;
    th_begin("h solve: list radius below the solution gives SPH_H_BEYOND_LIST and a larger h");
    tp_lattice(3, n1, 1, x);
    for (i = 0; i < n; ++i) m[i] = 1, h[i] = 1;
    TH_CHECK(tp_brute_list(3, x, n, x, n, 1, NULL, NULL, 2, TP_GATHER, &box, &L) == 0, "out of memory");
    c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &L.list, sph_view_interleaved(x, 3), sph_view_soa(m, NULL, NULL), 1);
    c.box = &box;
    TH_CHECK(sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), NULL, state, &rep) == SPH_OK, "status");
    TH_CHECK(rep.n_beyond_list == n, "%d beyond of %d", (int)rep.n_beyond_list, n);
    for (i = 0; i < n; ++i) all &= state[i] == SPH_H_BEYOND_LIST && h[i] > 1 && h[i] < 2;
    TH_CHECK(all, "state %d, h %g (expected beyond, 1 < h < 2)", state[0], (double)h[0]);
    tp_free_list(&L);
    TH_CHECK(tp_brute_list(3, x, n, x, n, (sph_real)1.3 * h[0], NULL, NULL, 2, TP_GATHER, &box, &L) == 0, "oom");
    c.list = &L.list;
    c.h_list_max = (sph_real)1.3 * h[0];
    TH_CHECK(sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), NULL, state, &rep) == SPH_OK && rep.n_beyond_list == 0 &&
             rep.n_not_converged == 0 && rep.max_iterations <= 4,
             "after the re-search: %d beyond, %d not converged, max %d sums", (int)rep.n_beyond_list,
             (int)rep.n_not_converged, rep.max_iterations);
    tp_free_list(&L);
    th_end();
}

/* A guess within tol below h_list while the solution lies beyond the list
 * (docs/smoothing_length.md, "Lists that grow with h"): the first sum gives
 * f < 0 and the step is clamped to h_list; the state must be
 * SPH_H_BEYOND_LIST, not a converged h. 1-D lattice of spacing 1, m = 1,
 * cubic, h_list = 1: the B-spline's partition of unity gives rho(h_list) = 1
 * exactly, so the estimate eta (m / rho)^(1/d) is eta = 1.2. */
static void beyond_guess_lattice_case(void)
{
    enum { N = 64 };
    const double eta = 1.2, tol = TOL;
    const double guess[] = {0.9, 1 - tol / 4, 1 - tol, 1, 1 + tol / 4, 1.1};
    sph_real x[3 * N], m[N], h[N], rho[N], om[N];
    sph_box box = {{0, 0, 0}, {N, 0, 0}, {1, 0, 0}};
    int state[N], i, g;
    tp_list L;
    sph_hctx c;
    sph_hreport rep;
    th_begin("h solve: 1D lattice, list to h 1, solution 1.2: beyond the list from every guess near h_list");
    tp_lattice(1, N, 1, x);
    for (i = 0; i < N; ++i) m[i] = 1;
    TH_CHECK(tp_brute_list(1, x, N, x, N, 1, NULL, NULL, 2, TP_GATHER, &box, &L) == 0, "out of memory");
    c = sph_hctx_init(SPH_KERNEL_CUBIC, 1, &L.list, sph_view_interleaved(x, 3), sph_view_soa(m, NULL, NULL), 1);
    c.box = &box;
    c.tol = (sph_real)tol;
    for (g = 0; g < (int)(sizeof guess / sizeof guess[0]); ++g) {
        int bad = 0;
        for (i = 0; i < N; ++i) h[i] = (sph_real)guess[g];
        TH_CHECK(sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), NULL, state, &rep) == SPH_OK, "status");
        for (i = 0; i < N; ++i)
            bad += !(state[i] == SPH_H_BEYOND_LIST && fabs((double)h[i] - eta) <= 8 * TH_EPS * eta &&
                     fabs((double)rho[i] - 1) <= 8 * TH_EPS);
        TH_CHECK(bad == 0 && rep.n_beyond_list == N,
                 "guess %.9g h_list: %d of %d wrong, particle 0 state %d h %.9g rho %.9g (expected beyond, h %g, rho 1)",
                 guess[g], bad, N, state[0], (double)h[0], (double)rho[0], eta);
    }
    tp_free_list(&L);
    th_end();
}

/* The same in 3-D on a random cloud, each particle's solution h* found
 * first on long lists with tol / 16: lists to 0.95 h* and guesses at, just
 * below and just above h_list, and lists to h* / (1 + tol / 2) (the root a
 * Newton step of 3/4 tol beyond the list) must all give SPH_H_BEYOND_LIST
 * with an h above h_list; lists to 1.05 h* and a guess just below h_list
 * converge to (H1). */
static void beyond_guess_cloud_case(void)
{
    enum { N = 1000 };
    const double tol = TOL, L0 = 10;
    const double list[] = {1.05, 0.95, 0.95, 0.95, 0.95, 1 / (1 + tol / 2)};
    const double guess[] = {1 - tol / 4, 1 - tol / 4, 1 - tol, 1, 1 + tol / 4, 1 - tol / 4};
    sph_real *x = malloc(sizeof(sph_real) * 3 * N), *m = malloc(sizeof(sph_real) * N);
    sph_real *h = malloc(sizeof(sph_real) * N), *hs = malloc(sizeof(sph_real) * N), *hl = malloc(sizeof(sph_real) * N);
    sph_real *rho = malloc(sizeof(sph_real) * N), *om = malloc(sizeof(sph_real) * N);
    int *state = malloc(sizeof(int) * N), i, g;
    sph_box box = {{0, 0, 0}, {(sph_real)L0, (sph_real)L0, (sph_real)L0}, {1, 1, 1}};
    tp_rng rng = {777};
    tp_list L;
    sph_hctx c;
    sph_hreport rep;
    double res, erho, eom;
    th_begin("h solve: 3D random cloud, lists short of the solution: beyond the list from guesses at, below and above h_list");
    tp_uniform_cloud(3, N, L0, &rng, x);
    for (i = 0; i < N; ++i) m[i] = 1, hs[i] = (sph_real)1.2;
    /* the solutions, on lists to h 2.4 (twice the mean h): every particle converged */
    TH_CHECK(tp_brute_list(3, x, N, x, N, (sph_real)2.4, NULL, NULL, 2, TP_GATHER, &box, &L) == 0, "out of memory");
    c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &L.list, sph_view_interleaved(x, 3), sph_view_soa(m, NULL, NULL),
                      (sph_real)2.4);
    c.box = &box;
    c.tol = (sph_real)(tol / 16);
    TH_CHECK(sph_h_solve(&c, th_out1(hs), th_out1(rho), th_out1(om), NULL, NULL, &rep) == SPH_OK &&
                 rep.n_not_converged == 0 && rep.n_beyond_list == 0,
             "long lists: %d not converged, %d beyond", (int)rep.n_not_converged, (int)rep.n_beyond_list);
    tp_free_list(&L);
    c.tol = (sph_real)tol;
    for (g = 0; g < (int)(sizeof guess / sizeof guess[0]); ++g) {
        int bad = 0;
        for (i = 0; i < N; ++i) hl[i] = (sph_real)(list[g] * (double)hs[i]);
        TH_CHECK(tp_brute_list(3, x, N, x, N, 0, hl, NULL, 2, TP_GATHER, &box, &L) == 0, "out of memory");
        c.list = &L.list;
        c.h_list = sph_view_soa(hl, NULL, NULL);
        for (i = 0; i < N; ++i) h[i] = (sph_real)(guess[g] * (double)hl[i]);
        TH_CHECK(sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), NULL, state, &rep) == SPH_OK, "status");
        if (list[g] > 1) {
            residuals(SPH_KERNEL_CUBIC, 3, x, m, N, &box, 1.2, h, rho, om, &res, &erho, &eom);
            TH_CHECK(rep.n_not_converged == 0 && rep.n_beyond_list == 0 && res < RES,
                     "lists 5 %% long: %d not converged, %d beyond, residual of (H1) %.3g", (int)rep.n_not_converged,
                     (int)rep.n_beyond_list, res);
        } else {
            for (i = 0; i < N; ++i) bad += !(state[i] == SPH_H_BEYOND_LIST && h[i] > hl[i]);
            TH_CHECK(bad == 0, "lists to %.9g h*, guess %.9g h_list: %d of %d particles not beyond their list with h > h_list",
                     list[g], guess[g], bad, N);
        }
        tp_free_list(&L);
    }
    free(x), free(m), free(h), free(hs), free(hl), free(rho), free(om), free(state);
    th_end();
}

static void bad_input_case(void)
{
    sph_real x[3 * 27], m[27], h[27], rho[27], om[27];
    int it[27], i, st;
    sph_box box = {{0, 0, 0}, {3, 3, 3}, {1, 1, 1}};
    tp_list L;
    sph_hctx c;
    sph_hreport rep;
    th_begin("h solve: bad input refused before anything is written; max_iter reached is reported");
    tp_lattice(3, 3, 1, x);
    for (i = 0; i < 27; ++i) m[i] = 1, h[i] = 1, rho[i] = -7;
    TH_CHECK(tp_brute_list(3, x, 27, x, 27, (sph_real)1.4, NULL, NULL, 2, TP_GATHER, &box, &L) == 0, "oom");
    c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &L.list, sph_view_interleaved(x, 3), sph_view_soa(m, NULL, NULL),
                      (sph_real)1.4);
    c.box = &box;
    c.eta = (sph_real)0.5; /* eta^3 = 0.125 < alpha_3 w(0) = 1/pi: the self term alone exceeds the target */
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_ERANGE, "small eta: %d", st);
    c.eta = (sph_real)1.2;
    c.tol = 0;
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_ERANGE, "tol 0: %d", st);
    c.tol = (sph_real)1e-6;
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(NULL), th_out1(om), it, NULL, NULL)) == SPH_ENULL, "rho NULL: %d",
             st);
    h[5] = 0;
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_EH, "h = 0: %d", st);
    h[5] = 1;
    m[3] = -1;
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_ENONFINITE, "m < 0: %d", st);
    m[3] = 1;
    x[7] = (sph_real)NAN;
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_ENONFINITE, "x NaN: %d", st);
    x[7] = (sph_real)0.5;
    c.h_list_max = -1;
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_EH, "h_list -1: %d", st);
    c.h_list_max = (sph_real)1.4;
    c.kernel = (sph_kernel)99;
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_EKERNEL, "kernel 99: %d", st);
    c.kernel = SPH_KERNEL_CUBIC;
    L.index[4] = 27;
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_EINDEX, "index 27: %d", st);
    L.index[4] = 0;
    {
        const sph_off keep = L.offset[3];
        L.offset[3] = L.offset[4] + 1;
        TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_EOFFSET, "decreasing offsets: %d", st);
        L.offset[3] = keep;
    }
    L.list.n_sources = 28;
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_ECOUNT, "28 sources, 27 targets: %d", st);
    L.list.n_sources = 27;
    box.length[1] = 0;
    TH_CHECK((st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, NULL)) == SPH_EBOXLEN, "period 0: %d", st);
    box.length[1] = 3;
    for (i = 0; i < 27; ++i) TH_CHECK(rho[i] == -7, "rho[%d] written", i);
    { /* a row without the particle itself and without neighbours: finite results, beyond the list */
        const sph_off o1[2] = {0, 0};
        sph_real x1[3] = {0, 0, 0}, m1 = 1, h1 = 1, r1 = -1, om1 = -1;
        sph_neighbours e = SPH_NEIGHBOURS_INIT(1, 1, o1, NULL);
        sph_hctx c1 = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &e, sph_view_interleaved(x1, 3), sph_view_soa(&m1, NULL, NULL),
                                    (sph_real)1.5);
        int s1 = -1;
        TH_CHECK(sph_h_solve(&c1, th_out1(&h1), th_out1(&r1), th_out1(&om1), NULL, &s1, NULL) == SPH_OK &&
                     s1 == SPH_H_BEYOND_LIST && h1 == 3 && r1 == 0 && om1 == 1,
                 "empty row: state %d h %g rho %g Omega %g", s1, (double)h1, (double)r1, (double)om1);
    }
    c.max_iter = 1;
    TH_CHECK(sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), it, NULL, &rep) == SPH_OK && rep.n_not_converged == 27 &&
             rep.max_iterations == 1, "max_iter 1: %d not converged", (int)rep.n_not_converged);
    tp_free_list(&L);
    th_end();
}

/* h, rho and Omega of one particle side by side, as a solver stores them. */
typedef struct {
    sph_real x[3], h, rho, om;
} sl_particle;

/* The same solve into separate arrays and into an array of structs: the views change where, not what. */
static void sl_layout_case(void)
{
    enum { n1 = 6, n = n1 * n1 * n1 };
    static sl_particle P[n];
    sph_real x[3 * n], m[n], h[n], rho[n], om[n];
    sph_box box = {{0, 0, 0}, {n1, n1, n1}, {1, 1, 1}};
    const size_t S = sizeof(sl_particle);
    tp_list L;
    sph_hctx c;
    int i, a, st, st2, same = 1;
    th_begin("h solve: h, rho, Omega through array-of-structs views equal separate arrays bitwise");
    tp_lattice(3, n1, 1, x);
    for (i = 0; i < n; ++i) {
        x[3 * i] += (sph_real)(0.05 * ((i * 7) % 5)); /* unequal neighbourhoods: every particle its own h */
        m[i] = 1, h[i] = 1;
        for (a = 0; a < 3; ++a) P[i].x[a] = x[3 * i + a];
        P[i].h = 1, P[i].rho = P[i].om = -1;
    }
    TH_CHECK(tp_brute_list(3, x, n, x, n, (sph_real)2.2, NULL, NULL, 2, TP_GATHER, &box, &L) == 0, "out of memory");
    c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &L.list, sph_view_interleaved(x, 3), sph_view_soa(m, NULL, NULL),
                      (sph_real)2.2);
    c.box = &box;
    st = sph_h_solve(&c, th_out1(h), th_out1(rho), th_out1(om), NULL, NULL, NULL);
    c.x = sph_view_aos(P[0].x, 3, S);
    st2 = sph_h_solve(&c, sph_out_aos(&P[0].h, 1, S), sph_out_aos(&P[0].rho, 1, S), sph_out_aos(&P[0].om, 1, S), NULL,
                      NULL, NULL);
    for (i = 0; i < n; ++i) same &= P[i].h == h[i] && P[i].rho == rho[i] && P[i].om == om[i];
    TH_CHECK(st == SPH_OK && st2 == SPH_OK && same, "status %d %d; particle 0: h %.17g %.17g", st, st2, (double)h[0],
             (double)P[0].h);
    TH_CHECK(h[0] != h[1] && h[0] != h[2], "the particles' h should differ: %g %g %g", (double)h[0], (double)h[1],
             (double)h[2]);
    tp_free_list(&L);
    th_end();
}

/* One mass for all through a view of stride 0 (sph_view_aos(&m, 1, 0), docs/smoothing_length.md "One mass for
 * all"): the h solve and the gather and pair-once grad-h forces give the bits of an array holding that mass for
 * every particle; the operators (sph_ctx) refuse the stride 0 with SPH_ESTRIDE. */
static void scalar_mass_case(void)
{
    enum { n1 = 6, n = n1 * n1 * n1 };
    sph_real x[3 * n], m[n], v[3 * n], A[n], h[2][n], rho[2][n], om[2][n], acc[2][3 * n], du[2][n], rho_op[n];
    sph_real accp[2][3 * n], dup[2][n];
    sph_real *buf;
    const sph_real m1 = (sph_real)0.7;
    sph_box box = {{0, 0, 0}, {n1, n1, n1}, {1, 1, 1}};
    sph_off half_off[n + 1], t_off[n + 1], *t_slot, pairs;
    sph_idx *half_idx;
    sph_pairs P;
    tp_list L;
    sph_hctx c;
    sph_ctx oc;
    int i, r, st[2], sf[2], sp[2], same = 1, nb;
    th_begin("h solve, grad-h forces: one mass through a view of stride 0 = an array of that mass, bitwise");
    tp_lattice(3, n1, 1, x);
    for (i = 0; i < n; ++i) {
        x[3 * i] += (sph_real)(0.05 * ((i * 7) % 5)), x[3 * i + 1] += (sph_real)(0.04 * ((i * 3) % 4));
        m[i] = m1, v[3 * i] = (sph_real)(0.1 * (i % 3)), v[3 * i + 1] = (sph_real)(0.05 * (i % 5)), v[3 * i + 2] = 0;
    }
    TH_CHECK(tp_brute_list(3, x, n, x, n, (sph_real)2.2, NULL, NULL, 2, TP_SYMMETRIC, &box, &L) == 0, "out of memory");
    t_slot = malloc(sizeof(sph_off) * (size_t)L.list.offset[n]);
    half_idx = malloc(sizeof(sph_idx) * (size_t)L.list.offset[n]);
    TH_CHECK(t_slot != NULL && half_idx != NULL, "out of memory");
    TH_CHECK(sph_pairs_build(&L.list, half_off, half_idx, L.list.offset[n], t_off, t_slot, &pairs, &P) == SPH_OK,
             "sph_pairs_build");
    nb = (int)sph_gradh_pairs_buffer_len(3, pairs);
    buf = malloc(sizeof(sph_real) * (size_t)nb);
    TH_CHECK(buf != NULL, "out of memory");
    for (r = 0; r < 2; ++r) { /* r = 0: an array of masses; r = 1: one mass, stride 0 */
        c = sph_hctx_init(SPH_KERNEL_CUBIC, 3, &L.list, sph_view_interleaved(x, 3),
                          r == 0 ? sph_view_soa(m, NULL, NULL) : sph_view_aos(&m1, 1, 0), (sph_real)2.2);
        c.box = &box;
        for (i = 0; i < n; ++i) h[r][i] = 1;
        st[r] = sph_h_solve(&c, th_out1(h[r]), th_out1(rho[r]), th_out1(om[r]), NULL, NULL, NULL);
        for (i = 0; i < n; ++i) A[i] = sph_gradh_factor(rho[0][i], rho[0][i], om[0][i]); /* p = rho: any A will do */
        sf[r] = sph_gradh_forces(&c, sph_view_interleaved(v, 3), th_in1(h[0]), th_in1(A), sph_out_interleaved(acc[r], 3),
                                 th_out1(du[r]));
        sp[r] = sph_gradh_forces_pairs(&c, &P, sph_view_interleaved(v, 3), th_in1(h[0]), th_in1(A), buf, nb,
                                       sph_out_interleaved(accp[r], 3), th_out1(dup[r]));
    }
    for (i = 0; i < n; ++i)
        same &= h[0][i] == h[1][i] && rho[0][i] == rho[1][i] && om[0][i] == om[1][i] && du[0][i] == du[1][i] &&
                dup[0][i] == dup[1][i];
    for (i = 0; i < 3 * n; ++i) same &= acc[0][i] == acc[1][i] && accp[0][i] == accp[1][i];
    TH_CHECK(st[0] == SPH_OK && st[1] == SPH_OK && sf[0] == SPH_OK && sf[1] == SPH_OK && sp[0] == SPH_OK &&
             sp[1] == SPH_OK, "status: solve %d %d, forces %d %d, pairs %d %d", st[0], st[1], sf[0], sf[1], sp[0], sp[1]);
    TH_CHECK(same, "the stride-0 mass changed a bit: particle 0 h %.17g %.17g", (double)h[0][0], (double)h[1][0]);
    TH_CHECK(rho[0][0] != rho[0][1], "the particles' densities should differ");
    oc = sph_ctx_init(SPH_KERNEL_CUBIC, 3, 2, &L.list, sph_view_interleaved(x, 3));
    oc.box = &box;
    oc.m = sph_view_aos(&m1, 1, 0);
    r = sph_density(&oc, th_out1(rho_op));
    TH_CHECK(r == SPH_ESTRIDE, "sph_density with a stride-0 mass: %s (SPH_ESTRIDE expected)", sph_strerror(r));
    tp_free_list(&L);
    free(t_slot), free(half_idx), free(buf);
    th_end();
}

/* The density sums of sph_h_solve in the fast loops (the operators' loops of
 * section 6, one pass in AVX-512 or AVX2 registers where the build has them)
 * against the reference loop, one pair at a time: every kernel in 1-3 D, a
 * perturbed periodic lattice, masses and h varying per particle (0.7 to 1.4
 * dx), a list longer than the support of most of them. Bitwise where the fast
 * loops promise it (no OpenMP, the chunked loop, no contraction:
 * sph__fp_contracted), else to round-off: rho relative, drho relative to its
 * scale d rho / h. */
#if defined(_OPENMP)
#define HS_BITWISE 0
#else
#define HS_BITWISE (sph_isa() == SPH_ISA_PORTABLE)
#endif
/* The fast sums of the level the unit runs at (sph_isa), chosen as the header's public functions choose. */
static void hs_sums(const sph_hctx *c, const sph__kdim *kd, const sph__period *P, sph_idx i, sph_real h, sph_real *rho,
                    sph_real *drho)
{
    SPH__DISPATCH_VOID(sph__h_sums, (c, kd, P, i, h, rho, drho))
    sph__h_sums(c, kd, P, i, h, rho, drho);
}
static void fast_sums_case(sph_kernel k, int dim)
{
    const int n1 = dim == 1 ? 40 : dim == 2 ? 12 : 7, n = tp_lattice_count(dim, n1);
    const double kappa = (double)sph_kernel_support(k), hmax = 1.4, tol = TH_IS_FLOAT ? 1e-5 : 1e-13;
    const int bitwise = HS_BITWISE && !sph__fp_contracted();
    sph_real *x = malloc(sizeof(sph_real) * 3 * (size_t)n), *m = malloc(sizeof(sph_real) * (size_t)n);
    sph_box box = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    const sph__kdim *kd = sph__kd(k, dim);
    tp_rng g = {99u + (uint64_t)dim};
    double worst = 0;
    tp_list L;
    sph_hctx c;
    sph__period P;
    int i, a;
    th_begin("h solve: density sums, fast loops = reference loop%s, %dD %s, h varying", bitwise ? " (bitwise)" : "",
             dim, sph_kernel_name(k));
    for (a = 0; a < dim; ++a) box.length[a] = (sph_real)n1, box.periodic[a] = 1;
    tp_lattice(dim, n1, 1, x);
    tp_perturb(dim, n, 0.3, &g, x);
    for (i = 0; i < n; ++i) m[i] = (sph_real)tp_range(&g, 0.8, 1.2);
    TH_CHECK(tp_brute_list(dim, x, n, x, n, (sph_real)hmax, NULL, NULL, (sph_real)kappa, TP_GATHER, &box, &L) == 0,
             "out of memory");
    c = sph_hctx_init(k, dim, &L.list, sph_view_interleaved(x, 3), sph_view_soa(m, NULL, NULL), (sph_real)hmax);
    c.box = &box;
    P = sph__period_of(&box, &L.list, dim);
    for (i = 0; i < n; ++i) {
        const sph_real h = (sph_real)tp_range(&g, 0.7, hmax), hinv = 1 / h;
        sph_real rho, drho, sw, sd, rr, dr;
        double e;
        hs_sums(&c, kd, &P, i, h, &rho, &drho);
        sph__h_sums_ref(&c, &sph__nshapes[kd->shape], &P, i, hinv, &sw, &sd);
        rr = sph__hpow(kd->alpha * sw, hinv, dim);
        dr = -sph__hpow(kd->alpha * sd, hinv, dim + 1);
        if (bitwise) {
            TH_CHECK(rho == rr && drho == dr, "particle %d: rho %.17g ref %.17g, drho %.17g ref %.17g", i, (double)rho,
                     (double)rr, (double)drho, (double)dr);
            continue;
        }
        e = fabs((double)rho - rr) / rr;
        e = fmax(e, fabs((double)drho - dr) / (fabs((double)dr) + dim * (double)rr / (double)h));
        worst = fmax(worst, e);
    }
    TH_CHECK(worst <= tol, "largest relative difference %.3g (tolerance %.1g)", worst, tol);
    tp_free_list(&L);
    free(x), free(m);
    th_end();
}

int main(void)
{
    int k, dim;
    lattice_case(SPH_KERNEL_CUBIC, 1, 40);
    lattice_case(SPH_KERNEL_CUBIC, 2, 16);
    lattice_case(SPH_KERNEL_CUBIC, 3, 10);
    lattice_case(SPH_KERNEL_WENDLAND_C4, 3, 10);
    lattice_case(SPH_KERNEL_QUINTIC, 3, 12);
    clump_case();
    beyond_case();
    beyond_guess_lattice_case();
    beyond_guess_cloud_case();
    bad_input_case();
    sl_layout_case();
    scalar_mass_case();
    for (k = 0; k < SPH_KERNEL_COUNT; ++k)
        for (dim = 1; dim <= 3; ++dim) fast_sums_case((sph_kernel)k, dim);
    return th_summary();
}
