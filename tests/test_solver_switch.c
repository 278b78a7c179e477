/* Solver terms: the Balsara factor (S13) and the pair alpha (S14) of the
 * viscosity switches, docs/solver.md.
 *
 * Reference values: each formula written out in double from its source -
 * Balsara (1995) for (S13); Borrow et al. (2022, SPHENIX, eq. 20) for (S14).
 * div v and curl v come from linear fields v = A x, for which the corrected
 * velocity gradient (O17) is exact (div v = trace A, curl v = A_yx - A_xy to
 * round-off), on a jittered lattice.
 */
#include "op_scene.h"

/* (S13) in double. */
static double ref_balsara(double d, double w, double c, double h)
{
    return fabs(d) / (fabs(d) + fabs(w) + 1e-4 * c / h);
}

/* div v and |curl v| (2-D) of v = A x on a jittered 12 x 12 lattice (no box: the corrected gradient is exact at
 * the edges too), from the corrected velocity gradient (O17) of particle k. */
static void lattice_divcurl(const double A[2][2], double *div, double *curl, int k)
{
    ts_scene s;
    sph_real *v, *T;
    sph_idx nfb = 0;
    int i, st;
    ts_lattice(&s, SPH_KERNEL_QUINTIC, 2, 12, 1.0 / 12, 1.3, 0.2, 41, NULL);
    v = ts_vec(3 * s.n), T = ts_vec(4 * s.n);
    for (i = 0; i < s.n; ++i) {
        v[3 * i] = (sph_real)(A[0][0] * s.x[3 * i] + A[0][1] * s.x[3 * i + 1]);
        v[3 * i + 1] = (sph_real)(A[1][0] * s.x[3 * i] + A[1][1] * s.x[3 * i + 1]);
    }
    st = sph_gradient_vector(&s.c, SPH_SCHEME_CORRECTED, sph_view_interleaved(v, 3), sph_view_none(), T, 4, &nfb);
    TH_CHECK(st == SPH_OK && nfb == 0, "corrected gradient: status %d, %d fallbacks", st, (int)nfb);
    *div = (double)T[4 * k] + T[4 * k + 3];        /* dv_x/dx + dv_y/dy */
    *curl = fabs((double)T[4 * k + 2] - T[4 * k + 1]); /* dv_y/dx - dv_x/dy */
    free(v), free(T);
    ts_free(&s);
}

static void test_balsara(void)
{
    /* (a) pure shear v = (s y, 0): div v = 0, |curl v| = s; (b) compression with shear v = (a x + s y, a y); (c)
       pure compression v = -g x: B near 1 */
    const double shear[2][2] = {{0, 2.5}, {0, 0}}, mixed[2][2] = {{-0.7, 1.9}, {0, -0.7}}, conv[2][2] = {{-3, 0}, {0, -3}};
    const double c = 1.5, h = 0.1;
    double d, w, B;
    int k, i;
    th_begin("(S13) Balsara factor: 0 in pure shear, the formula in a sheared compression, near 1 in compression "
             "(div v and curl v of linear fields)");
    for (k = 0; k < 3; ++k) {
        const int p = k == 0 ? 0 : k == 1 ? 77 : 143; /* a corner, an inner particle, the last corner */
        lattice_divcurl(shear, &d, &w, p);
        TH_CLOSE(d, 0, 200 * TH_EPS);
        TH_NEAR(w, 2.5, 200 * TH_EPS);
        B = (double)sph_switch_balsara((sph_real)d, (sph_real)w, (sph_real)c, (sph_real)h);
        TH_CHECK(B <= 200 * TH_EPS, "shear: B = %g at particle %d", B, p);
        lattice_divcurl(mixed, &d, &w, p);
        TH_NEAR(d, -1.4, 200 * TH_EPS);
        TH_NEAR(w, 1.9, 200 * TH_EPS);
        B = (double)sph_switch_balsara((sph_real)d, (sph_real)w, (sph_real)c, (sph_real)h);
        TH_NEAR(B, ref_balsara(-1.4, 1.9, c, h), 1e3 * TH_EPS);
        lattice_divcurl(conv, &d, &w, p);
        B = (double)sph_switch_balsara((sph_real)d, (sph_real)w, (sph_real)c, (sph_real)h);
        TH_NEAR(B, 6 / (6 + 1.5e-3), 1e3 * TH_EPS);
        TH_CHECK(B > 0.999 && B < 1, "compression: B = %.17g", B);
    }
    /* the documented fallbacks: no flow and c = 0, an h <= 0 or a NaN give 0; curl given with either sign */
    TH_CHECK(sph_switch_balsara(0, 0, 0, 1) == 0 && sph_switch_balsara(1, 0, 1, 0) == 0 &&
                 sph_switch_balsara(1, 0, 1, -1) == 0 && sph_switch_balsara(1, 0, -1, 1) == 0 &&
                 sph_switch_balsara((sph_real)NAN, 0, 1, 1) == 0,
             "fallbacks");
    for (i = 0; i < 20; ++i) {
        const double dv = -3 + 0.3 * i, cv = 0.1 * i - 1;
        TH_NEAR(sph_switch_balsara((sph_real)dv, (sph_real)cv, (sph_real)c, (sph_real)h), ref_balsara(dv, cv, c, h),
                8 * TH_EPS);
    }
    th_end();
}

static void test_pair_alpha(void)
{
    int i, j;
    th_begin("(S14) alpha_ij = (alpha_i + alpha_j) / 2 (B_i + B_j) / 2, alpha itself for equal alphas and B = 1");
    for (i = 0; i < 9; ++i)
        for (j = 0; j < 9; ++j) {
            const double ai = 0.25 * i, aj = 0.3 * j, bi = 0.125 * i, bj = 1 - 0.1 * j;
            const sph_real a = (sph_real)ai;
            TH_NEAR(sph_pair_av_alpha((sph_real)ai, (sph_real)aj, (sph_real)bi, (sph_real)bj),
                    (ai + aj) / 2 * (bi + bj) / 2, 4 * TH_EPS);
            TH_CHECK(sph_pair_av_alpha(a, a, 1, 1) == a, "alpha %g not returned bit for bit", ai);
            TH_CHECK(sph_pair_av_alpha((sph_real)ai, (sph_real)aj, (sph_real)bi, (sph_real)bj) ==
                         sph_pair_av_alpha((sph_real)aj, (sph_real)ai, (sph_real)bj, (sph_real)bi),
                     "not symmetric in i, j");
        }
    th_end();
}

int main(void)
{
    test_balsara();
    test_pair_alpha();
    return th_summary();
}
