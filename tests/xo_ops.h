/* tests/xo_ops.h - runs every array operator of section 6 on one context, for
 * the extreme-case test and the fuzz harness.
 *
 * Each operator writes into its own buffer of 9 reals per target (scalars at
 * [i], vectors interleaved at [3 i + a], tensors at [9 i + 3 a + b]), so one
 * pass checks every output for finiteness and compares layouts bitwise.
 */
#ifndef SPH_TEST_XO_OPS_H
#define SPH_TEST_XO_OPS_H

#include <stdlib.h>
#include <string.h>

#include "sph_kernel.h"

/* The operators, in the order of xo_run. */
enum {
    XO_DENSITY, XO_INTERP, XO_SHEPARD,
    XO_GRAD_STD, XO_GRAD_DIFF, XO_GRAD_SYM, XO_GRAD_CORR, XO_GRAD_PRES,
    XO_GV_STD, XO_GV_DIFF, XO_GV_SYM, XO_GV_CORR,
    XO_DIV_STD, XO_DIV_DIFF, XO_DIV_CORR,
    XO_CURL_STD, XO_CURL_DIFF,
    XO_LAP, XO_DIFFUSION, XO_CORRECTION,
    XO_N
};

static const char *const xo_names[XO_N] = {
    "density", "interpolate", "shepard",
    "gradient standard", "gradient difference", "gradient symmetric", "gradient corrected", "gradient pressure",
    "velocity gradient standard", "velocity gradient difference", "velocity gradient symmetric",
    "velocity gradient corrected",
    "divergence standard", "divergence difference", "divergence corrected",
    "curl standard", "curl difference",
    "laplacian", "diffusion", "correction matrix"};

/* Inputs besides the context (which carries x, h, V, m, rho): scalar f, its
 * target values ft (absent view: the sources'), vector v (dim components)
 * and vt, conductivity k and kt. */
typedef struct {
    sph_view f, ft, v, vt, k, kt;
} xo_in;

/* Outputs: o[op][9 * nt], status, count (fallbacks / empty Shepard targets). */
typedef struct {
    int nt;
    sph_real *o[XO_N];
    int status[XO_N];
    sph_idx count[XO_N];
} xo_res;

static inline void xo_alloc(xo_res *R, int nt, sph_real fill)
{
    int op, i;
    R->nt = nt;
    for (op = 0; op < XO_N; ++op) {
        R->o[op] = (sph_real *)malloc(sizeof(sph_real) * (size_t)(9 * (nt > 0 ? nt : 1)));
        for (i = 0; i < 9 * (nt > 0 ? nt : 1); ++i) R->o[op][i] = fill;
        R->status[op] = 1;
        R->count[op] = -7;
    }
}

static inline void xo_free(xo_res *R)
{
    int op;
    for (op = 0; op < XO_N; ++op) free(R->o[op]);
}

static inline sph_out xo_s(sph_real *o) { return sph_out_soa(o, NULL, NULL); }
static inline sph_out xo_v(sph_real *o) { return sph_out_interleaved(o, 3); }

/* Runs all operators (curl only for dim >= 2 is still called: 1-D must give SPH_EDIM). */
static inline void xo_run(const sph_ctx *c, const xo_in *in, xo_res *R)
{
    const sph_scheme gs[5] = {SPH_SCHEME_STANDARD, SPH_SCHEME_DIFFERENCE, SPH_SCHEME_SYMMETRIC,
                              SPH_SCHEME_CORRECTED, SPH_SCHEME_PRESSURE};
    const sph_scheme ds[3] = {SPH_SCHEME_STANDARD, SPH_SCHEME_DIFFERENCE, SPH_SCHEME_CORRECTED};
    int s;
    R->status[XO_DENSITY] = sph_density(c, xo_s(R->o[XO_DENSITY]));
    R->status[XO_INTERP] = sph_interpolate(c, in->f, xo_s(R->o[XO_INTERP]));
    R->status[XO_SHEPARD] = sph_interpolate_shepard(c, in->f, xo_s(R->o[XO_SHEPARD]), &R->count[XO_SHEPARD]);
    for (s = 0; s < 5; ++s)
        R->status[XO_GRAD_STD + s] = sph_gradient(c, gs[s], in->f, in->ft, xo_v(R->o[XO_GRAD_STD + s]),
                                                  &R->count[XO_GRAD_STD + s]);
    for (s = 0; s < 4; ++s)
        R->status[XO_GV_STD + s] = sph_gradient_vector(c, gs[s], in->v, in->vt, R->o[XO_GV_STD + s], 9,
                                                       &R->count[XO_GV_STD + s]);
    for (s = 0; s < 3; ++s)
        R->status[XO_DIV_STD + s] = sph_divergence(c, ds[s], in->v, in->vt, xo_s(R->o[XO_DIV_STD + s]),
                                                   &R->count[XO_DIV_STD + s]);
    for (s = 0; s < 2; ++s)
        R->status[XO_CURL_STD + s] = sph_curl(c, ds[s], in->v, in->vt, xo_v(R->o[XO_CURL_STD + s]));
    R->status[XO_LAP] = sph_laplacian(c, in->f, in->ft, xo_s(R->o[XO_LAP]));
    R->status[XO_DIFFUSION] = sph_diffusion(c, in->k, in->kt, in->f, in->ft, xo_s(R->o[XO_DIFFUSION]));
    R->status[XO_CORRECTION] = sph_correction_matrix(c, R->o[XO_CORRECTION], 9, &R->count[XO_CORRECTION]);
}

/* Is operator op expected to run for this dimension (curl needs dim >= 2)? */
static inline int xo_defined(int op, int dim) { return !((op == XO_CURL_STD || op == XO_CURL_DIFF) && dim == 1); }

/* First non-finite entry of operator op's buffer, or -1. */
static inline int xo_first_nonfinite(const xo_res *R, int op)
{
    int i;
    for (i = 0; i < 9 * R->nt; ++i)
        if (!(R->o[op][i] - R->o[op][i] == 0)) return i;
    return -1;
}

#endif
