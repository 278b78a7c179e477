/* tests/fuzz_body.h - one fuzz case: bytes -> a random scene thrown at every
 * operator and at the neighbour search, with the invariants that must hold
 * for any input:
 *   - valid input: every operator returns SPH_OK (curl in 1-D: SPH_EDIM) and
 *     writes only finite values; SoA, interleaved and array-of-structs views
 *     of the same data give bitwise the same results; the cell-list search
 *     gives exactly the brute-force lists (support/particles.h), gather and
 *     symmetric;
 *   - one bad input (NaN/Inf in a field, index out of range, negative index,
 *     decreasing offsets, offset[0] != 0, h not usable, unknown kernel,
 *     periodic axis of length 0, density <= 0): every operator that reads it
 *     returns its documented status code and leaves outputs and counts alone.
 * Used by tests/fuzz_operators.c (libFuzzer) and tests/test_fuzz_seeded.c.
 * A violated invariant is described in fz_msg and fz_case returns 1.
 */
#ifndef SPH_TEST_FUZZ_BODY_H
#define SPH_TEST_FUZZ_BODY_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/particles.h"
#include "xo_ops.h"

static char fz_msg[512];

/* The byte reader: zeros once the input is exhausted. */
typedef struct {
    const uint8_t *d;
    size_t n, at;
} fz_in;

static inline unsigned fz_u8(fz_in *r) { return r->at < r->n ? r->d[r->at++] : 0u; }
static inline unsigned fz_u16(fz_in *r) { unsigned a = fz_u8(r); return a | (fz_u8(r) << 8); }
static inline double fz_unit(fz_in *r) { return fz_u16(r) / 65536.0; } /* [0, 1) */

/* Corruptions: at most one per case. */
enum {
    FZ_NONE, FZ_NAN_X, FZ_INF_F, FZ_NAN_V, FZ_NAN_VEC, FZ_INF_K, FZ_NAN_H, FZ_RHO0, FZ_IDX_HIGH, FZ_IDX_NEG,
    FZ_OFF_DEC, FZ_OFF0, FZ_H_BAD, FZ_H_TINY, FZ_KERNEL, FZ_BOX0, FZ_COUNT
};

#define FZ_MAXN 200
#define FZ_SENT ((sph_real)-31.25)

typedef struct {
    int dim, ns, nt, probes, hv, layout_mask;
    sph_kernel kernel;
    sph_real h, kappa;
    sph_real xs[3 * FZ_MAXN], xt[3 * FZ_MAXN], hs[FZ_MAXN], ht[FZ_MAXN];
    sph_real V[FZ_MAXN], rho[FZ_MAXN], rhot[FZ_MAXN], f[FZ_MAXN], ft[FZ_MAXN], v[3 * FZ_MAXN], vt[3 * FZ_MAXN];
    sph_real k[FZ_MAXN], kt[FZ_MAXN];
    sph_box box;
    int use_box;
    sph_off *off;
    sph_idx *idx;
    sph_neighbours L;
} fz_scene;

/* A particle struct for the array-of-structs layout. */
typedef struct {
    sph_real x[3], V, rho, f, v[3], k, h;
} fz_particle;

/* Does operator op read the input that corruption c spoils? */
static inline int fz_reads(int op, int c)
{
    switch (c) {
    case FZ_INF_F: return op != XO_DENSITY && op <= XO_GRAD_PRES ? 1 : op == XO_LAP || op == XO_DIFFUSION;
    case FZ_NAN_VEC: return op >= XO_GV_STD && op <= XO_CURL_DIFF;
    case FZ_INF_K: return op == XO_DIFFUSION;
    case FZ_RHO0: return op == XO_GRAD_PRES;
    default: return 1; /* positions, volumes = masses, h, list, kernel, box: everyone */
    }
}

static inline int fz_expected(int c)
{
    switch (c) {
    case FZ_NAN_X: case FZ_INF_F: case FZ_NAN_V: case FZ_NAN_VEC: case FZ_INF_K: return SPH_ENONFINITE;
    case FZ_NAN_H: case FZ_H_BAD: case FZ_H_TINY: return SPH_EH;
    case FZ_RHO0: return SPH_EVALUE;
    case FZ_OFF_DEC: case FZ_OFF0: return SPH_EOFFSET;
    case FZ_BOX0: return SPH_EBOXLEN;
    case FZ_IDX_HIGH: case FZ_IDX_NEG: return SPH_EINDEX;
    case FZ_KERNEL: return SPH_EKERNEL;
    default: return SPH_OK;
    }
}

/* Builds the operator context over the scene in one of three layouts:
 * 0 interleaved (positions x[3i+a], scalars plain), 1 structure of arrays
 * (copies into per-component arrays), 2 array of structs. */
typedef struct {
    sph_real *soa;         /* [14 * n] copies for layout 1 */
    fz_particle *ps, *pt;  /* layout 2 */
    xo_in in;
    sph_ctx c;
} fz_views;

static inline sph_view fz_col(const sph_real *base, int ncomp, int layout, sph_real *soa_dst, int n)
{ /* base holds ncomp interleaved components; layout 1 splits them into soa_dst */
    int i, a;
    if (layout != 1) return ncomp == 1 ? sph_view_soa(base, NULL, NULL) : sph_view_interleaved(base, ncomp);
    for (i = 0; i < n; ++i)
        for (a = 0; a < ncomp; ++a) soa_dst[a * n + i] = base[ncomp * i + a];
    return sph_view_soa(soa_dst, ncomp > 1 ? soa_dst + n : NULL, ncomp > 2 ? soa_dst + 2 * n : NULL);
}

static inline void fz_make_views(fz_scene *s, int layout, fz_views *w)
{
    const int n = FZ_MAXN, ns = s->ns, nt = s->nt;
    const size_t st = sizeof(fz_particle);
    int i, a;
    w->soa = (sph_real *)calloc((size_t)(26 * n), sizeof(sph_real));
    w->ps = (fz_particle *)calloc((size_t)n, st);
    w->pt = (fz_particle *)calloc((size_t)n, st);
    if (layout == 2) {
        for (i = 0; i < ns; ++i) {
            for (a = 0; a < 3; ++a) w->ps[i].x[a] = s->xs[3 * i + a], w->ps[i].v[a] = s->v[3 * i + a];
            w->ps[i].V = s->V[i], w->ps[i].rho = s->rho[i], w->ps[i].f = s->f[i], w->ps[i].k = s->k[i];
            w->ps[i].h = s->hs[i];
        }
        for (i = 0; i < nt; ++i) {
            for (a = 0; a < 3; ++a) w->pt[i].x[a] = s->xt[3 * i + a], w->pt[i].v[a] = s->vt[3 * i + a];
            w->pt[i].rho = s->rhot[i], w->pt[i].f = s->ft[i], w->pt[i].k = s->kt[i], w->pt[i].h = s->ht[i];
        }
        w->c = sph_ctx_init(s->kernel, s->dim, s->h, &s->L, sph_view_aos(w->ps[0].x, 3, st));
        w->c.V = w->c.m = sph_view_aos(&w->ps[0].V, 1, st);
        w->c.rho = sph_view_aos(&w->ps[0].rho, 1, st);
        w->in.f = sph_view_aos(&w->ps[0].f, 1, st), w->in.v = sph_view_aos(w->ps[0].v, 3, st);
        w->in.k = sph_view_aos(&w->ps[0].k, 1, st);
        if (s->hv) w->c.h_source = sph_view_aos(&w->ps[0].h, 1, st);
        w->in.ft = w->in.vt = w->in.kt = sph_view_none();
        if (s->probes) {
            w->c.x_target = sph_view_aos(w->pt[0].x, 3, st);
            w->c.rho_target = sph_view_aos(&w->pt[0].rho, 1, st);
            w->in.ft = sph_view_aos(&w->pt[0].f, 1, st), w->in.vt = sph_view_aos(w->pt[0].v, 3, st);
            w->in.kt = sph_view_aos(&w->pt[0].k, 1, st);
            if (s->hv) w->c.h_target = sph_view_aos(&w->pt[0].h, 1, st);
        }
    } else {
        sph_real *q = w->soa;
        w->c = sph_ctx_init(s->kernel, s->dim, s->h, &s->L, fz_col(s->xs, 3, layout, q, n));
        w->c.V = w->c.m = fz_col(s->V, 1, layout, q + 3 * n, n);
        w->c.rho = fz_col(s->rho, 1, layout, q + 4 * n, n);
        w->in.f = fz_col(s->f, 1, layout, q + 5 * n, n);
        w->in.v = fz_col(s->v, 3, layout, q + 6 * n, n);
        w->in.k = fz_col(s->k, 1, layout, q + 9 * n, n);
        if (s->hv) w->c.h_source = fz_col(s->hs, 1, layout, q + 10 * n, n);
        w->in.ft = w->in.vt = w->in.kt = sph_view_none();
        if (s->probes) {
            w->c.x_target = fz_col(s->xt, 3, layout, q + 11 * n, n);
            w->c.rho_target = fz_col(s->rhot, 1, layout, q + 14 * n, n);
            w->in.ft = fz_col(s->ft, 1, layout, q + 15 * n, n);
            w->in.vt = fz_col(s->vt, 3, layout, q + 16 * n, n);
            w->in.kt = fz_col(s->kt, 1, layout, q + 19 * n, n);
            if (s->hv) w->c.h_target = fz_col(s->ht, 1, layout, q + 20 * n, n);
        }
    }
    w->c.box = s->use_box ? &s->box : NULL;
}

static inline void fz_free_views(fz_views *w)
{
    free(w->soa), free(w->ps), free(w->pt);
}

/* The cell-list search against the brute-force reference (valid input only). */
static inline int fz_check_search(fz_scene *s)
{
    int mode;
    for (mode = 0; mode < 2; ++mode) {
        const sph_view xs = sph_view_interleaved(s->xs, 3);
        const sph_view xt = s->probes ? sph_view_interleaved(s->xt, 3) : xs;
        const sph_view hs = s->hv ? sph_view_soa(s->hs, NULL, NULL) : sph_view_none();
        const sph_view ht = s->hv ? sph_view_soa(s->probes ? s->ht : s->hs, NULL, NULL) : sph_view_none();
        const sph_box *box = s->use_box ? &s->box : NULL;
        sph_real hmax = s->h, hmt = s->hv ? 0 : s->h, hms = s->hv ? 0 : s->h, cell, R;
        sph_nsearch g;
        size_t bytes = 0;
        void *work;
        sph_off *off;
        sph_idx *idx;
        tp_list ref;
        int i, a, st, want = SPH_OK, bad = 0;
        for (i = 0; s->hv && i < s->ns; ++i) hms = s->hs[i] > hms ? s->hs[i] : hms;
        for (i = 0; s->hv && i < s->nt; ++i) hmt = (s->probes ? s->ht : s->hs)[i] > hmt ? (s->probes ? s->ht : s->hs)[i] : hmt;
        hmax = hms > hmax ? hms : hmax;
        hmax = hmt > hmax ? hmt : hmax;
        cell = s->kappa * hmax / 2;
        /* the largest search radius (N1)/(N2) must fit the minimum image: R <= L/2 */
        R = s->kappa * (mode && hms > hmt ? hms : hmt);
        for (a = 0; box != NULL && a < s->dim; ++a)
            if (box->periodic[a] && R > box->length[a] / 2) want = SPH_EPERIOD;
        st = sph_nsearch_workspace_size(s->dim, xs, s->ns, hs, cell, box, &bytes);
        if (st != SPH_OK) {
            snprintf(fz_msg, sizeof fz_msg, "nsearch workspace size: status %d on valid input", st);
            return 1;
        }
        work = malloc(bytes > 0 ? bytes : 1);
        off = (sph_off *)malloc(sizeof(sph_off) * (size_t)(s->nt + 1));
        st = sph_nsearch_build(&g, s->dim, xs, s->ns, hs, cell, box, work, bytes);
        if (st == SPH_OK) st = sph_nsearch_count(&g, xt, s->nt, ht, s->h, s->kappa, mode, off);
        idx = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)(st == SPH_OK && off[s->nt] > 0 ? off[s->nt] : 1));
        if (st == SPH_OK) st = sph_nsearch_fill(&g, xt, s->nt, ht, s->h, s->kappa, mode, off, idx, off[s->nt]);
        tp_brute_list(s->dim, s->probes ? s->xt : s->xs, s->nt, s->xs, s->ns, s->h,
                      s->hv ? (s->probes ? s->ht : s->hs) : NULL, s->hv ? s->hs : NULL, s->kappa,
                      mode ? TP_SYMMETRIC : TP_GATHER, box, &ref);
        if (st != want) {
            snprintf(fz_msg, sizeof fz_msg, "nsearch mode %d: status %d on valid input, want %d", mode, st, want);
            bad = 1;
        } else if (st == SPH_OK && (memcmp(off, ref.offset, sizeof(sph_off) * (size_t)(s->nt + 1)) != 0 ||
                                    memcmp(idx, ref.index, sizeof(sph_idx) * (size_t)off[s->nt]) != 0)) {
            snprintf(fz_msg, sizeof fz_msg, "nsearch mode %d: lists differ from brute force (%ld vs %ld entries)",
                     mode, (long)off[s->nt], (long)ref.offset[s->nt]);
            bad = 1;
        }
        tp_free_list(&ref);
        free(work), free(off), free(idx);
        if (bad) return 1;
    }
    return 0;
}

/* One case. Returns 0 when every invariant held, 1 otherwise (fz_msg says which). */
static inline int fz_case(const uint8_t *data, size_t size)
{
    fz_in r;
    fz_scene *s = (fz_scene *)calloc(1, sizeof(fz_scene));
    xo_res R[3];
    int corrupt, i, a, op, layout, listkind, fail = 0, nl = 0, target;
    double L, e;
    tp_rng g;
    r.d = data, r.n = size, r.at = 0;
    fz_msg[0] = '\0';
    s->dim = 1 + (int)(fz_u8(&r) % 3);
    s->kernel = (sph_kernel)(fz_u8(&r) % SPH_KERNEL_COUNT);
    s->kappa = sph_kernel_support(s->kernel);
    s->ns = (int)(fz_u16(&r) % (FZ_MAXN + 1));
    s->probes = fz_u8(&r) % 4 == 0;
    s->nt = s->probes ? (int)(fz_u8(&r) % 60) : s->ns;
    s->hv = fz_u8(&r) % 3 == 0;
    corrupt = (int)(fz_u8(&r) % (2 * FZ_COUNT));
    if (corrupt >= FZ_COUNT) corrupt = FZ_NONE; /* half the cases are valid */
    /* h = 10^e, e in [-6, 6] (float [-3, 3]), and the length of the cloud */
    e = (fz_unit(&r) * 2 - 1) * (sizeof(sph_real) == sizeof(float) ? 3 : 6);
    s->h = (sph_real)pow(10, e);
    L = (double)s->h * (0.3 + 8 * fz_unit(&r)) * pow(s->ns > 0 ? s->ns : 1, 1.0 / s->dim);
    g.s = (uint64_t)fz_u16(&r) * 2654435761u + fz_u8(&r);
    {
        const double offset = fz_u8(&r) % 4 == 0 ? 1e3 * L : 0; /* far from the origin */
        const int clustered = fz_u8(&r) % 3 == 0;
        if (clustered) tp_clustered_cloud(s->dim, s->ns, 3, L, (double)s->h, &g, s->xs);
        else tp_uniform_cloud(s->dim, s->ns, L, &g, s->xs);
        if (s->probes) tp_uniform_cloud(s->dim, s->nt, L * 1.2, &g, s->xt);
        for (i = 0; offset > 0 && i < s->ns; ++i)
            for (a = 0; a < s->dim; ++a) s->xs[3 * i + a] += (sph_real)offset;
        for (i = 0; offset > 0 && s->probes && i < s->nt; ++i)
            for (a = 0; a < s->dim; ++a) s->xt[3 * i + a] += (sph_real)offset;
        if (fz_u8(&r) % 5 == 0 && s->ns > 1) /* coincident pair */
            for (a = 0; a < 3; ++a) s->xs[3 + a] = s->xs[a];
        s->use_box = fz_u8(&r) % 3 == 0 && offset == 0;
        for (a = 0; a < 3; ++a) {
            s->box.lo[a] = 0;
            s->box.length[a] = (sph_real)L;
            s->box.periodic[a] = s->use_box && (fz_u8(&r) & 1);
        }
    }
    for (i = 0; i < FZ_MAXN; ++i) {
        const double vol = pow(L, s->dim) / (s->ns > 0 ? s->ns : 1);
        s->hs[i] = (sph_real)((double)s->h * (0.5 + tp_uniform(&g)));
        s->ht[i] = (sph_real)((double)s->h * (0.5 + tp_uniform(&g)));
        s->V[i] = (sph_real)(vol * (0.5 + tp_uniform(&g)));
        s->rho[i] = (sph_real)(0.5 + 1.5 * tp_uniform(&g)), s->rhot[i] = (sph_real)(0.5 + 1.5 * tp_uniform(&g));
        s->f[i] = (sph_real)tp_range(&g, -100, 100), s->ft[i] = (sph_real)tp_range(&g, -100, 100);
        s->k[i] = (sph_real)pow(10, tp_range(&g, -3, 3)), s->kt[i] = (sph_real)pow(10, tp_range(&g, -3, 3));
        for (a = 0; a < 3; ++a) s->v[3 * i + a] = (sph_real)tp_range(&g, -10, 10), s->vt[3 * i + a] = (sph_real)tp_range(&g, -10, 10);
    }
    if (!s->probes) /* targets are the sources: target arrays mirror them */
        for (i = 0; i < FZ_MAXN; ++i) {
            s->ht[i] = s->hs[i], s->rhot[i] = s->rho[i], s->ft[i] = s->f[i], s->kt[i] = s->k[i];
            for (a = 0; a < 3; ++a) s->xt[3 * i + a] = s->xs[3 * i + a], s->vt[3 * i + a] = s->v[3 * i + a];
        }
    /* the list: brute force (gather at kappa max h), or random valid indices */
    listkind = (int)(fz_u8(&r) % 3);
    if (listkind < 2) {
        tp_list t;
        tp_brute_list(s->dim, s->probes ? s->xt : s->xs, s->nt, s->xs, s->ns, s->h, s->hv ? s->ht : NULL,
                      s->hv ? s->hs : NULL, s->kappa, listkind ? TP_SYMMETRIC : TP_GATHER, s->use_box ? &s->box : NULL, &t);
        s->off = t.offset, s->idx = t.index;
    } else {
        s->off = (sph_off *)malloc(sizeof(sph_off) * (size_t)(s->nt + 1));
        s->off[0] = 0;
        for (i = 0; i < s->nt; ++i) s->off[i + 1] = s->off[i] + (s->ns > 0 ? (sph_off)(tp_next(&g) % 12) : 0);
        s->idx = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)(s->off[s->nt] > 0 ? s->off[s->nt] : 1));
        for (i = 0; i < (int)s->off[s->nt]; ++i) s->idx[i] = (sph_idx)(tp_next(&g) % (uint64_t)s->ns);
    }
    nl = (int)s->off[s->nt];
    s->L.n_targets = s->nt, s->L.n_sources = s->ns, s->L.offset = s->off, s->L.index = s->idx;

    /* one corruption; those that need data that is not there fall back to none */
    target = (int)(fz_u8(&r) % (s->ns > 0 ? s->ns : 1));
    switch (corrupt) {
    case FZ_NAN_X: if (s->ns > 0) s->xs[3 * target + s->dim - 1] = (sph_real)NAN; else corrupt = FZ_NONE; break;
    case FZ_INF_F: if (s->ns > 0) s->f[target] = (sph_real)-INFINITY; else corrupt = FZ_NONE; break;
    case FZ_NAN_V: if (s->ns > 0) s->V[target] = (sph_real)NAN; else corrupt = FZ_NONE; break;
    case FZ_NAN_VEC: if (s->ns > 0) s->v[3 * target] = (sph_real)NAN; else corrupt = FZ_NONE; break;
    case FZ_INF_K: if (s->ns > 0) s->k[target] = (sph_real)INFINITY; else corrupt = FZ_NONE; break;
    case FZ_NAN_H: if (s->ns > 0) s->hv = 1, s->hs[target] = (sph_real)NAN; else corrupt = FZ_NONE; break;
    case FZ_RHO0: if (s->ns > 0) s->rho[target] = 0; else corrupt = FZ_NONE; break;
    case FZ_IDX_HIGH: if (nl > 0) s->idx[fz_u8(&r) % (unsigned)nl] = (sph_idx)s->ns; else corrupt = FZ_NONE; break;
    case FZ_IDX_NEG: if (nl > 0) s->idx[fz_u8(&r) % (unsigned)nl] = -1 - (sph_idx)fz_u8(&r); else corrupt = FZ_NONE; break;
    case FZ_OFF_DEC: if (nl > 0 && s->nt > 1) s->off[s->nt - 1] = s->off[s->nt] + 1; else corrupt = FZ_NONE; break;
    case FZ_OFF0: if (s->nt > 0) s->off[0] = 1; else corrupt = FZ_NONE; break;
    case FZ_H_BAD: {
        const double bad[4] = {0, -1, NAN, INFINITY};
        s->h = (sph_real)bad[fz_u8(&r) % 4], s->hv = 0;
        break;
    }
    case FZ_H_TINY: /* usable for the scalar kernel, but 64 h^-(d+2) overflows */
        s->h = (sph_real)(sizeof(sph_real) == sizeof(float) ? (s->dim == 3 ? 1e-8 : s->dim == 2 ? 1e-10 : 1e-13)
                          : (s->dim == 3 ? 1e-70 : s->dim == 2 ? 1e-85 : 1e-110)), s->hv = 0;
        break;
    case FZ_KERNEL: s->kernel = (sph_kernel)(SPH_KERNEL_COUNT + (int)fz_u8(&r)); break;
    case FZ_BOX0: s->use_box = 1, s->box.periodic[0] = 1, s->box.length[0] = 0; break;
    default: break;
    }

    /* run every layout */
    for (layout = 0; layout < 3; ++layout) {
        fz_views w;
        fz_make_views(s, layout, &w);
        xo_alloc(&R[layout], s->nt, FZ_SENT);
        xo_run(&w.c, &w.in, &R[layout]);
        fz_free_views(&w);
    }
    for (op = 0; op < XO_N && !fail; ++op) {
        const int spoiled = corrupt != FZ_NONE && fz_reads(op, corrupt);
        const int want = spoiled ? fz_expected(corrupt) : xo_defined(op, s->dim) ? SPH_OK : SPH_EDIM;
        for (layout = 0; layout < 3 && !fail; ++layout) {
            const int got = R[layout].status[op];
            if (got != want) {
                snprintf(fz_msg, sizeof fz_msg, "%s (dim %d, kernel %d, ns %d, nt %d, corruption %d, layout %d): "
                         "status %d, expected %d", xo_names[op], s->dim, (int)s->kernel, s->ns, s->nt, corrupt, layout, got, want);
                fail = 1;
            } else if (got != SPH_OK) {
                for (i = 0; i < 9 * (s->nt > 0 ? s->nt : 1); ++i)
                    if (R[layout].o[op][i] != FZ_SENT) {
                        snprintf(fz_msg, sizeof fz_msg, "%s: output written on error %d", xo_names[op], got);
                        fail = 1;
                        break;
                    }
                if (!fail && R[layout].count[op] != -7) {
                    snprintf(fz_msg, sizeof fz_msg, "%s: count written on error %d", xo_names[op], got);
                    fail = 1;
                }
            } else {
                for (i = 0; i < 9 * s->nt; ++i)
                    if (!(R[layout].o[op][i] - R[layout].o[op][i] == 0)) {
                        snprintf(fz_msg, sizeof fz_msg, "%s (dim %d, kernel %d, ns %d, nt %d, h %g, layout %d): "
                                 "non-finite output %g at entry %d", xo_names[op], s->dim, (int)s->kernel, s->ns, s->nt,
                                 (double)s->h, layout, (double)R[layout].o[op][i], i);
                        fail = 1;
                        break;
                    }
                if (!fail && layout > 0 &&
                    (memcmp(R[layout].o[op], R[0].o[op], sizeof(sph_real) * (size_t)(9 * s->nt)) != 0 ||
                     R[layout].count[op] != R[0].count[op])) {
                    snprintf(fz_msg, sizeof fz_msg, "%s: layout %d differs from layout 0", xo_names[op], layout);
                    fail = 1;
                }
            }
        }
    }
    if (!fail && corrupt == FZ_NONE && listkind < 2) fail = fz_check_search(s);
    for (layout = 0; layout < 3; ++layout) xo_free(&R[layout]);
    free(s->off), free(s->idx), free(s);
    return fail;
}

#endif
