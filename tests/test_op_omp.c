/* Operators: results are bitwise the same for 1 and 2 OpenMP threads (each
 * target sums its own list sequentially; only the targets are shared out).
 * Meaningful in the -fopenmp build of tests/run.sh; without OpenMP the two
 * runs are serial and the test checks plain run-to-run determinism.
 */
#include "op_scene.h"

/* density, corrected gradient, Laplacian, corrected tensor, Shepard, with counts */
static void run(sph_ctx *c, int n, const sph_real *f, sph_real *v, sph_real *res, sph_idx *counts)
{
    sph_real *T = res + 6 * (size_t)n;
    int st;
    st = sph_density(c, sph_out_soa(res, NULL, NULL));
    st |= sph_gradient(c, SPH_SCHEME_CORRECTED, sph_view_soa(f, NULL, NULL), sph_view_none(),
                       sph_out_soa(res + n, res + 2 * n, res + 3 * n), &counts[0]);
    st |= sph_laplacian(c, sph_view_soa(f, NULL, NULL), sph_view_none(), sph_out_soa(res + 4 * n, NULL, NULL));
    st |= sph_interpolate_shepard(c, sph_view_soa(f, NULL, NULL), sph_out_soa(res + 5 * n, NULL, NULL), &counts[1]);
    st |= sph_gradient_vector(c, SPH_SCHEME_CORRECTED, sph_view_interleaved(v, 3), sph_view_none(), T, 9, &counts[2]);
    TH_CHECK(st == SPH_OK, "status %d", st);
}

int main(void)
{
    ts_scene s;
    sph_real *f, *r1, *r2;
    sph_idx c1[3], c2[3];
    int i;
    th_begin("1 and 2 threads give bitwise identical operator results (3D random cloud)");
    ts_random(&s, SPH_KERNEL_WENDLAND_C4, 3, 1500, 1.0, 1.3, 77);
    f = ts_vec(s.n), r1 = ts_vec(15 * s.n), r2 = ts_vec(15 * s.n);
    for (i = 0; i < s.n; ++i) f[i] = (sph_real)ts_sine(3, s.x + 3 * i, NULL);
    s.c.m = s.c.V;
    s.c.rcond_min = (sph_real)0.3; /* strict: some targets fall back, so the counts are exercised */
    th_set_threads(1);
    run(&s.c, s.n, f, s.x, r1, c1);
    th_set_threads(2);
    run(&s.c, s.n, f, s.x, r2, c2);
    TH_CHECK(memcmp(r1, r2, sizeof(sph_real) * 15 * (size_t)s.n) == 0, "results differ between thread counts");
    TH_CHECK(c1[0] == c2[0] && c1[1] == c2[1] && c1[2] == c2[2], "fallback counts differ: %d/%d", (int)c1[0], (int)c2[0]);
    TH_CHECK(c1[0] > 0, "the scene should exercise the fallback path (got %d)", (int)c1[0]);
    free(f), free(r1), free(r2);
    ts_free(&s);
    th_end();
    return th_summary();
}
