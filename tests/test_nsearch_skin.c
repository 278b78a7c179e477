/* tests/test_nsearch_skin.c - lists kept over steps (section 7, (N8)):
 * sph_nsearch_skin says when a list searched at radii kappa hl from
 * positions x0 still holds every pair within kappa h at positions x, and
 * sph_nsearch_prune cuts such a list down to those pairs. Reference: a fresh
 * search at h (itself equal to a brute-force double loop, test_neighbours.c);
 * the radii against the displacements worked by hand. */
#include "harness.h"

#include <stdlib.h>

enum { SK_N = 500 };
static const sph_real sk_kappa = 2;

typedef struct {
    sph_off *offset;
    sph_idx *index;
    sph_neighbours list;
} sk_list;

static unsigned sk_seed = 12345u;
static double sk_uniform(void) /* a small linear congruential generator: the same cloud everywhere */
{
    sk_seed = sk_seed * 1664525u + 1013904223u;
    return (sk_seed >> 8) / 16777216.0;
}

/* Lists of x with per-particle radii kappa h (mode) in box: 0 or a status. */
static int sk_search_n(const sph_real *x, const sph_real *h, int n, const sph_box *box, int mode, sk_list *L)
{
    const sph_view xv = sph_view_interleaved(x, 3), hv = th_in1(h);
    sph_real hmax = 0;
    size_t bytes;
    sph_off pairs;
    sph_nsearch g;
    void *work;
    int i, st;
    for (i = 0; i < n; ++i) hmax = h[i] > hmax ? h[i] : hmax;
    L->offset = (sph_off *)malloc((n + 1) * sizeof(sph_off));
    L->index = NULL;
    if ((st = sph_nsearch_workspace_size(3, xv, n, hv, sk_kappa * hmax / 2, box, &bytes)) != SPH_OK) return st;
    if ((work = malloc(bytes)) == NULL || L->offset == NULL) return free(work), SPH_ESIZE;
    if ((st = sph_nsearch_build(&g, 3, xv, n, hv, sk_kappa * hmax / 2, box, work, bytes)) == SPH_OK &&
        (st = sph_nsearch_count(&g, xv, n, hv, 0, sk_kappa, mode, L->offset)) == SPH_OK) {
        L->index = (sph_idx *)malloc((size_t)(L->offset[n] + 1) * sizeof(sph_idx));
        st = L->index == NULL ? SPH_ESIZE
                              : sph_nsearch_lists(&g, xv, n, hv, 0, sk_kappa, mode, L->offset, L->index,
                                                  L->offset[n], &pairs);
        L->list = sph_nsearch_list(&g, n, L->offset, L->index);
    }
    free(work);
    return st;
}

static int sk_search(const sph_real *x, const sph_real *h, const sph_box *box, int mode, sk_list *L)
{
    return sk_search_n(x, h, SK_N, box, mode, L);
}

static void sk_free(sk_list *L) { free(L->offset), free(L->index); }

/* First row where two lists differ, SK_N when equal. */
static int sk_differ(const sk_list *a, const sph_off *offset, const sph_idx *index)
{
    int i;
    sph_off o;
    for (i = 0; i < SK_N; ++i) {
        if (a->offset[i + 1] != offset[i + 1]) return i;
        for (o = a->offset[i]; o < a->offset[i + 1]; ++o)
            if (a->index[o] != index[o]) return i;
    }
    return SK_N;
}

/* A periodic cloud, h varying by a factor 2, lists at 1.25 h; then steps of random moves (some particles moving
 * towards each other) and h changes: while sph_nsearch_skin reports no stale particle, the kept list pruned at h is
 * the fresh search at h, pair for pair, in both modes; large moves are reported stale. W: the period across (1, or
 * 0.45: a tube whose cross-section is just over twice the largest radius, pairs up to 0.47 periods apart). */
static void sk_kept_case(int mode, double W)
{
    static sph_real x0[3 * SK_N], x[3 * SK_N], hl[SK_N], h[SK_N], keep[SK_N];
    static sph_idx index[60 * SK_N];
    static sph_off offset[SK_N + 1];
    sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}};
    sk_list kept, fresh;
    box.length[1] = box.length[2] = (sph_real)W;
    const sph_real h0 = (sph_real)0.06;
    int i, a, step, kept_steps = 0, stale_seen = 0;
    th_begin("sph_nsearch_skin + prune = fresh search, %s, period %g across, %s", mode ? "symmetric" : "gather", W,
             TH_PRECISION);
    for (i = 0; i < SK_N; ++i) {
        for (a = 0; a < 3; ++a) x0[3 * i + a] = x[3 * i + a] = (sph_real)(sk_uniform() * (a ? W : 1));
        h[i] = h0 * (sph_real)(0.7 + 0.7 * sk_uniform());
        hl[i] = (sph_real)1.25 * h[i];
    }
    TH_CHECK(sk_search(x0, hl, &box, mode, &kept) == SPH_OK, "search at hl");
    for (step = 1; step <= 12; ++step) {
        const double move = 0.004 * step; /* grows until the skin no longer covers it */
        sph_idx stale = -1;
        sph_off pairs = -1;
        sph_neighbours out;
        int st;
        for (i = 0; i < SK_N; ++i) {
            for (a = 0; a < 3; ++a) { /* even particles move along +x, odd ones along -x: pairs close at 2 d */
                const double d = a == 0 ? (i % 2 ? -move : move) : move * (sk_uniform() - 0.5) * 0.2;
                x[3 * i + a] = (sph_real)(x0[3 * i + a] + d);
                x[3 * i + a] -= (sph_real)((a ? W : 1) * floor((double)x[3 * i + a] / (a ? W : 1))); /* wrapped */
            }
            h[i] *= (sph_real)(1 + 0.01 * (sk_uniform() - 0.3));
        }
        st = sph_nsearch_skin(&kept.list, NULL, 3, sph_view_interleaved(x, 3), sph_view_interleaved(x0, 3), th_in1(hl),
                              sk_kappa, th_in1(h), th_out1(keep), &stale);
        TH_CHECK(st == SPH_OK && stale >= 0 && stale <= SK_N, "skin step %d: %d, stale %ld", step, st, (long)stale);
        if (stale > 0) {
            ++stale_seen;
            continue;
        }
        ++kept_steps;
        TH_CHECK(sk_search(x, h, &box, mode, &fresh) == SPH_OK, "fresh search step %d", step);
        st = sph_nsearch_prune(&kept.list, NULL, 3, sph_view_interleaved(x, 3), th_in1(h), sk_kappa, mode, offset, index,
                               60 * SK_N, &pairs, &out);
        TH_CHECK(st == SPH_OK && pairs == fresh.offset[SK_N], "prune step %d: %d, %ld pairs, fresh %ld", step, st,
                 (long)pairs, (long)fresh.offset[SK_N]);
        if (st == SPH_OK) {
            i = sk_differ(&fresh, offset, index);
            TH_CHECK(i == SK_N, "step %d (move %g): row %d differs from the fresh search", step, move, i);
            TH_CHECK(out.offset == offset && out.index == index && out.box_known == SPH_BOX_KNOWN &&
                         out.box.length[0] == 1 && out.n_targets == SK_N,
                     "the pruned view carries the arrays and the list's box");
        }
        sk_free(&fresh);
    }
    /* moves 0.004 .. 0.048 against a skin of 0.25 h kappa = 0.021 .. 0.042: the first steps are kept, later ones not */
    TH_CHECK(kept_steps >= 2 && stale_seen >= 2, "%d steps kept, %d stale", kept_steps, stale_seen);
    sk_free(&kept);
    th_end();
}

/* The radii worked by hand: particle 0 moved by 0.3 along x, particle 1 by 0.1 along y (through the periodic face),
 * particle 2 stayed: d = 0.3, 0.1, 0, d_max = 0.3, h_keep_i = hl_i - (d_i + 0.3) / kappa = 1.7, 1.8, 1.85 (to the
 * rounding allowance); h_0 = 1.71 is stale; with y open particle 1 moved by 9.9 and all three are stale. */
static void sk_radii_case(void)
{
    const sph_real x0[9] = {1, 1, 1, 2, (sph_real)9.95, 1, 3, 3, 3};
    const sph_real x[9] = {(sph_real)1.3, 1, 1, 2, (sph_real)0.05, 1, 3, 3, 3};
    const sph_real hl[3] = {2, 2, 2};
    sph_real h[3] = {1, 1, 1}, keep[3];
    const sph_off offset[4] = {0, 0, 0, 0};
    sph_neighbours L = SPH_NEIGHBOURS_INIT(3, 3, offset, NULL);
    sph_box box = {{0, 0, 0}, {10, 10, 10}, {0, 1, 0}};
    sph_idx stale = -1;
    int st;
    th_begin("sph_nsearch_skin radii by hand, %s", TH_PRECISION);
    st = sph_nsearch_skin(&L, &box, 3, sph_view_interleaved(x, 3), sph_view_interleaved(x0, 3), th_in1(hl), sk_kappa,
                          th_in1(h), th_out1(keep), &stale);
    TH_CHECK(st == SPH_OK && stale == 0, "status %d, stale %ld", st, (long)stale);
    TH_NEAR(keep[0], 2 - 0.6 / 2, 1e3 * TH_EPS);
    TH_NEAR(keep[1], 2 - 0.4 / 2, 1e3 * TH_EPS);
    TH_NEAR(keep[2], 2 - 0.3 / 2, 1e3 * TH_EPS);
    h[0] = (sph_real)1.71; /* beyond 1.7 */
    st = sph_nsearch_skin(&L, &box, 3, sph_view_interleaved(x, 3), sph_view_interleaved(x0, 3), th_in1(hl), sk_kappa,
                          th_in1(h), th_out1(keep), &stale);
    TH_CHECK(st == SPH_OK && stale == 1, "h_0 = 1.71: status %d, stale %ld", st, (long)stale);
    box.periodic[1] = 0; /* open y: particle 1 moved by 9.9 */
    st = sph_nsearch_skin(&L, &box, 3, sph_view_interleaved(x, 3), sph_view_interleaved(x0, 3), th_in1(hl), sk_kappa,
                          th_in1(h), th_out1(keep), &stale);
    TH_CHECK(st == SPH_OK && stale == 3, "open y: status %d, stale %ld", st, (long)stale);
    th_end();
}

/* Every refusal of the two functions, and SPH_ESIZE with the pairs counted. */
static void sk_errors_case(void)
{
    static sph_real x[3 * SK_N], h[SK_N], hl[SK_N], keep[SK_N];
    static sph_idx index[60 * SK_N];
    static sph_off offset[SK_N + 1];
    sph_box box = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}}, other = box;
    const sph_view xv = sph_view_interleaved(x, 3);
    sk_list L;
    sph_off pairs = -1, bad_off;
    sph_idx stale, bad_idx;
    sph_real x5;
    int i, a, st;
    th_begin("sph_nsearch_skin / prune refusals, %s", TH_PRECISION);
    for (i = 0; i < SK_N; ++i) {
        for (a = 0; a < 3; ++a) x[3 * i + a] = (sph_real)sk_uniform();
        h[i] = (sph_real)0.05;
        hl[i] = (sph_real)0.06;
    }
    TH_CHECK(sk_search(x, h, &box, SPH_NSEARCH_SYMMETRIC, &L) == SPH_OK, "search");
    other.length[2] = 2;
#define SK_SKIN(list, bx, dim, kap, hv, outv, ns) \
    sph_nsearch_skin(list, bx, dim, xv, xv, th_in1(hl), kap, hv, outv, ns)
#define SK_PRUNE(list, bx, kap, hv, mode, off, cap) \
    sph_nsearch_prune(list, bx, 3, xv, hv, kap, mode, off, index, cap, &pairs, NULL)
    TH_CHECK((st = SK_SKIN(&L.list, NULL, 3, sk_kappa, th_in1(h), th_out1(keep), &stale)) == SPH_OK && stale == 0,
             "unmoved: %d, stale %ld", st, (long)stale);
    TH_CHECK(SK_SKIN(NULL, NULL, 3, sk_kappa, th_in1(h), th_out1(keep), &stale) == SPH_ENULL, "no list");
    TH_CHECK(SK_SKIN(&L.list, NULL, 3, sk_kappa, th_in1(h), th_out1(keep), NULL) == SPH_ENULL, "no n_stale");
    TH_CHECK(SK_SKIN(&L.list, NULL, 3, sk_kappa, th_in1(h), th_out1(NULL), &stale) == SPH_ENULL, "no h_keep");
    TH_CHECK(SK_SKIN(&L.list, NULL, 4, sk_kappa, th_in1(h), th_out1(keep), &stale) == SPH_EDIM, "dim 4");
    TH_CHECK(SK_SKIN(&L.list, NULL, 3, 0, th_in1(h), th_out1(keep), &stale) == SPH_ERANGE, "kappa 0");
    TH_CHECK(SK_SKIN(&L.list, &other, 3, sk_kappa, th_in1(h), th_out1(keep), &stale) == SPH_EBOX, "another box");
    h[7] = -1;
    TH_CHECK(SK_SKIN(&L.list, NULL, 3, sk_kappa, th_in1(h), th_out1(keep), &stale) == SPH_EH, "h -1");
    TH_CHECK(SK_PRUNE(&L.list, NULL, sk_kappa, th_in1(h), SPH_NSEARCH_GATHER, offset, 60 * SK_N) == SPH_EH, "prune h -1");
    h[7] = (sph_real)0.05;
    x5 = x[5], x[5] = (sph_real)NAN;
    TH_CHECK(SK_SKIN(&L.list, NULL, 3, sk_kappa, th_in1(h), th_out1(keep), &stale) == SPH_ENONFINITE, "x NaN");
    TH_CHECK(SK_PRUNE(&L.list, NULL, sk_kappa, th_in1(h), SPH_NSEARCH_GATHER, offset, 60 * SK_N) == SPH_ENONFINITE,
             "prune x NaN");
    x[5] = x5; /* the searched position again */
    TH_CHECK(SK_PRUNE(&L.list, NULL, sk_kappa, th_in1(h), 7, offset, 60 * SK_N) == SPH_EOPTION, "mode 7");
    TH_CHECK(SK_PRUNE(&L.list, NULL, -1, th_in1(h), SPH_NSEARCH_GATHER, offset, 60 * SK_N) == SPH_ERANGE, "kappa -1");
    TH_CHECK(SK_PRUNE(&L.list, &other, sk_kappa, th_in1(h), SPH_NSEARCH_GATHER, offset, 60 * SK_N) == SPH_EBOX,
             "prune, another box");
    TH_CHECK(SK_PRUNE(&L.list, NULL, sk_kappa, th_in1(h), SPH_NSEARCH_GATHER, NULL, 60 * SK_N) == SPH_ENULL,
             "no offset");
    TH_CHECK(SK_PRUNE(&L.list, NULL, sk_kappa, th_in1(h), SPH_NSEARCH_GATHER, offset, -1) == SPH_ECOUNT, "cap -1");
    st = SK_PRUNE(&L.list, NULL, sk_kappa, th_in1(h), SPH_NSEARCH_GATHER, offset, 10);
    TH_CHECK(st == SPH_ESIZE && pairs == L.offset[SK_N] && offset[SK_N] == pairs,
             "cap 10: %d, %ld pairs counted, list %ld (nothing dropped at the search's own h)", st, (long)pairs,
             (long)L.offset[SK_N]);
    bad_off = L.offset[3], L.offset[3] = L.offset[2] - 1;
    TH_CHECK(SK_PRUNE(&L.list, NULL, sk_kappa, th_in1(h), SPH_NSEARCH_GATHER, offset, 60 * SK_N) == SPH_EOFFSET,
             "offsets falling");
    L.offset[3] = bad_off;
    bad_idx = L.index[4], L.index[4] = SK_N;
    TH_CHECK(SK_PRUNE(&L.list, NULL, sk_kappa, th_in1(h), SPH_NSEARCH_GATHER, offset, 60 * SK_N) == SPH_EINDEX,
             "index n");
    L.index[4] = bad_idx;
    L.list.n_sources = SK_N - 1;
    TH_CHECK(SK_PRUNE(&L.list, NULL, sk_kappa, th_in1(h), SPH_NSEARCH_GATHER, offset, 60 * SK_N) == SPH_ECOUNT,
             "n_sources != n_targets");
    TH_CHECK(SK_SKIN(&L.list, NULL, 3, sk_kappa, th_in1(h), th_out1(keep), &stale) == SPH_ECOUNT, "skin: counts");
#undef SK_SKIN
#undef SK_PRUNE
    sk_free(&L);
    th_end();
}

/* The prune and the skin radii are the same for 1 and 2 threads: 5000 particles, so that 2 threads take their
 * parallel forms. */
static void sk_threads_case(void)
{
    enum { NT = 5000 };
    sph_real *x = (sph_real *)malloc(3 * NT * sizeof(sph_real)), *h = (sph_real *)malloc(NT * sizeof(sph_real));
    sph_real *hs = (sph_real *)malloc(NT * sizeof(sph_real));
    sph_idx *i1 = (sph_idx *)malloc(60 * NT * sizeof(sph_idx)), *i2 = (sph_idx *)malloc(60 * NT * sizeof(sph_idx));
    sph_off *o1 = (sph_off *)malloc((NT + 1) * sizeof(sph_off)), *o2 = (sph_off *)malloc((NT + 1) * sizeof(sph_off));
    sk_list L = {NULL, NULL, SPH_NEIGHBOURS_INIT(0, 0, NULL, NULL)};
    sph_off p1 = 0, p2 = 0;
    int i, a, st1 = -99, st2 = -99;
    th_begin("sph_nsearch_prune, 1 and 2 threads, %s", TH_PRECISION);
    if (x != NULL && h != NULL && hs != NULL && i1 != NULL && i2 != NULL && o1 != NULL && o2 != NULL) {
        for (i = 0; i < NT; ++i) {
            for (a = 0; a < 3; ++a) x[3 * i + a] = (sph_real)sk_uniform();
            h[i] = (sph_real)(0.025 + 0.015 * sk_uniform());
            hs[i] = h[i] * (sph_real)0.8;
        }
        TH_CHECK(sk_search_n(x, h, NT, NULL, SPH_NSEARCH_SYMMETRIC, &L) == SPH_OK, "open search");
        th_set_threads(1);
        st1 = sph_nsearch_prune(&L.list, NULL, 3, sph_view_interleaved(x, 3), th_in1(hs), sk_kappa,
                                SPH_NSEARCH_SYMMETRIC, o1, i1, 60 * NT, &p1, NULL);
        th_set_threads(2);
        st2 = sph_nsearch_prune(&L.list, NULL, 3, sph_view_interleaved(x, 3), th_in1(hs), sk_kappa,
                                SPH_NSEARCH_SYMMETRIC, o2, i2, 60 * NT, &p2, NULL);
        TH_CHECK(st1 == SPH_OK && st2 == SPH_OK && p1 == p2 && p1 > 0 && p1 < L.offset[NT],
                 "%d %d, pairs %ld %ld of %ld", st1, st2, (long)p1, (long)p2, (long)L.offset[NT]);
        TH_CHECK(memcmp(o1, o2, (NT + 1) * sizeof(sph_off)) == 0 && memcmp(i1, i2, (size_t)p1 * sizeof(sph_idx)) == 0,
                 "lists differ");
        /* an index of exactly the pairs kept, shorter than the list: 2 threads take the counting and filling passes */
        memset(i2, 0, (size_t)p1 * sizeof(sph_idx));
        st2 = sph_nsearch_prune(&L.list, NULL, 3, sph_view_interleaved(x, 3), th_in1(hs), sk_kappa,
                                SPH_NSEARCH_SYMMETRIC, o2, i2, p1, &p2, NULL);
        TH_CHECK(st2 == SPH_OK && p2 == p1 && memcmp(i1, i2, (size_t)p1 * sizeof(sph_idx)) == 0,
                 "cap = pairs: %d, %ld pairs, lists differ", st2, (long)p2);
        { /* the skin radii: x moved (x0 = x + a wave), hs the h, h the list's radii; h_keep into the spare index */
            sph_real *x0 = (sph_real *)(void *)i1, *k1 = (sph_real *)(void *)i2, *k2 = k1 + NT;
            sph_idx n1 = -1, n2 = -2;
            for (i = 0; i < 3 * NT; ++i) x0[i] = x[i] + (sph_real)(0.004 * sin(0.37 * i));
            th_set_threads(1);
            st1 = sph_nsearch_skin(&L.list, NULL, 3, sph_view_interleaved(x, 3), sph_view_interleaved(x0, 3), th_in1(h),
                                   sk_kappa, th_in1(hs), th_out1(k1), &n1);
            th_set_threads(2);
            st2 = sph_nsearch_skin(&L.list, NULL, 3, sph_view_interleaved(x, 3), sph_view_interleaved(x0, 3), th_in1(h),
                                   sk_kappa, th_in1(hs), th_out1(k2), &n2);
            TH_CHECK(st1 == SPH_OK && st2 == SPH_OK && n1 == n2 && n1 > 0 && n1 < NT, "skin %d %d, stale %ld %ld", st1,
                     st2, (long)n1, (long)n2);
            TH_CHECK(memcmp(k1, k2, NT * sizeof(sph_real)) == 0, "skin radii differ between 1 and 2 threads");
        }
    } else
        TH_CHECK(0, "out of memory");
    sk_free(&L);
    free(x), free(h), free(hs), free(i1), free(i2), free(o1), free(o2);
    th_end();
}

int main(void)
{
    sk_kept_case(SPH_NSEARCH_GATHER, 1);
    sk_kept_case(SPH_NSEARCH_SYMMETRIC, 1);
    sk_kept_case(SPH_NSEARCH_GATHER, 0.45);
    sk_kept_case(SPH_NSEARCH_SYMMETRIC, 0.45);
    sk_radii_case();
    sk_errors_case();
    sk_threads_case();
    return th_summary();
}
