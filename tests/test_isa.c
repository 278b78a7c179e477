/* tests/test_isa.c - the instruction-set levels of the fast loops (section 2,
 * sph_isa; section 1, run-time dispatch).
 *
 * The names and the status codes of sph_isa_set: an unknown level is
 * SPH_EOPTION, a level this unit or CPU lacks SPH_EISA, and neither changes
 * the level; a level sph_isa_has names is what sph_isa reports after
 * sph_isa_set, and SPH_ISA_AUTO gives back the highest level the unit has.
 * A grid is laid out alike at every level (sph_isa_set says to force the level
 * before a search, but a grid built at one level must not be misread by
 * another): a 3-D cloud with per-particle h (0.02..0.12), the grid built at each level and
 * the symmetric lists searched at each other, equal entry for entry to the
 * lists of a grid built and searched at the portable level (or the build's,
 * where it has no portable one). The operators at every level against the
 * reference loops: tests/test_op_reference.c run at each level by make test
 * (SPH_TEST_ISA).
 */
#include <stdlib.h>

#include "harness.h"
#include "support/particles.h"

#define TI_N 700

static void names_case(void)
{
    th_begin("sph_isa_name: portable, avx2, avx512; NULL beyond");
    TH_CHECK(strcmp(sph_isa_name(SPH_ISA_PORTABLE), "portable") == 0, "%s", sph_isa_name(SPH_ISA_PORTABLE));
    TH_CHECK(strcmp(sph_isa_name(SPH_ISA_AVX2), "avx2") == 0, "%s", sph_isa_name(SPH_ISA_AVX2));
    TH_CHECK(strcmp(sph_isa_name(SPH_ISA_AVX512), "avx512") == 0, "%s", sph_isa_name(SPH_ISA_AVX512));
    TH_CHECK(sph_isa_name(-1) == NULL && sph_isa_name(3) == NULL, "names beyond the levels");
    TH_CHECK(strcmp(sph_strerror(SPH_EISA), "unknown status code") != 0, "SPH_EISA has a sentence");
    th_end();
}

static void set_case(void)
{
    const int start = sph_isa();
    int isa, best = -1, st;
    th_begin("sph_isa_set: refusals leave the level, forced levels are reported, AUTO the best");
    TH_CHECK(sph_isa_has(start), "the running level %d is one the unit has", start);
    TH_CHECK(sph_isa_set(-2) == SPH_EOPTION && sph_isa_set(3) == SPH_EOPTION, "unknown levels");
    TH_CHECK(sph_isa() == start, "level after refusals %d, was %d", sph_isa(), start);
    for (isa = SPH_ISA_PORTABLE; isa <= SPH_ISA_AVX512; ++isa) {
        st = sph_isa_set(isa);
        if (sph_isa_has(isa)) {
            best = isa;
            TH_CHECK(st == SPH_OK && sph_isa() == isa, "level %s: status %d, running %d", sph_isa_name(isa), st, sph_isa());
        } else {
            const int before = sph_isa();
            TH_CHECK(st == SPH_EISA && sph_isa() == before, "level %s refused: status %d, running %d (was %d)",
                     sph_isa_name(isa), st, sph_isa(), before);
        }
    }
    TH_CHECK(best >= 0, "no level at all");
    TH_CHECK(sph_isa_set(SPH_ISA_AUTO) == SPH_OK && sph_isa() == best, "AUTO: %d, the best the unit has: %d", sph_isa(),
             best);
    if (!sph_isa_dispatch()) TH_CHECK(best == sph_isa() && sph_isa_has(best), "without dispatch: the build's level only");
    TH_CHECK(sph_isa_set(start) == SPH_OK, "back to %d", start);
    th_end();
}

/* Symmetric lists of the cloud with per-particle h: grid built at level bl, searched at level sl. */
static int ti_lists(int bl, int sl, const sph_real *x, const sph_real *h, sph_off *off, sph_idx *idx, sph_off cap)
{
    const sph_real kappa = 2;
    const sph_view xv = sph_view_interleaved((sph_real *)(uintptr_t)x, 3), hv = sph_view_soa((sph_real *)(uintptr_t)h, NULL, NULL);
    sph_nsearch g;
    size_t bytes;
    void *work;
    sph_off pairs;
    int st = sph_isa_set(bl);
    if (st == SPH_OK) st = sph_nsearch_workspace_size(3, xv, TI_N, hv, (sph_real)0.12, NULL, &bytes);
    if (st != SPH_OK || (work = malloc(bytes)) == NULL) return st != SPH_OK ? st : SPH_ESIZE;
    st = sph_nsearch_build(&g, 3, xv, TI_N, hv, (sph_real)0.12, NULL, work, bytes);
    if (st == SPH_OK) st = sph_isa_set(sl);
    if (st == SPH_OK) st = sph_nsearch_lists(&g, xv, TI_N, hv, (sph_real)0.12, kappa, SPH_NSEARCH_SYMMETRIC, off, idx, cap, &pairs);
    free(work);
    return st;
}

static void grid_case(void)
{
    const sph_off cap = 200 * TI_N;
    sph_real *x = malloc(sizeof(sph_real) * 3 * TI_N), *h = malloc(sizeof(sph_real) * TI_N);
    sph_off *off0 = calloc(TI_N + 1, sizeof(sph_off)), *off = malloc(sizeof(sph_off) * (TI_N + 1));
    sph_idx *idx0 = malloc(sizeof(sph_idx) * (size_t)cap), *idx = malloc(sizeof(sph_idx) * (size_t)cap);
    const int start = sph_isa();
    int base = SPH_ISA_PORTABLE, bl, sl, i;
    tp_rng r = {2024u};
    th_begin("a grid built at one level serves the search at every other: the same symmetric lists");
    if (!x || !h || !off0 || !off || !idx0 || !idx) {
        TH_CHECK(0, "out of memory");
        th_end();
        return;
    }
    tp_uniform_cloud(3, TI_N, 1.0, &r, x);
    for (i = 0; i < TI_N; ++i) h[i] = (sph_real)tp_range(&r, 0.02, 0.12);
    while (!sph_isa_has(base)) ++base;
    TH_CHECK(ti_lists(base, base, x, h, off0, idx0, cap) == SPH_OK, "lists at level %d", base);
    for (bl = base; bl <= SPH_ISA_AVX512; ++bl)
        for (sl = base; sl <= SPH_ISA_AVX512; ++sl) {
            int st, same = 1;
            if (!sph_isa_has(bl) || !sph_isa_has(sl)) continue;
            st = ti_lists(bl, sl, x, h, off, idx, cap);
            for (i = 0; st == SPH_OK && same && i <= TI_N; ++i) same = off[i] == off0[i];
            for (i = 0; st == SPH_OK && same && i < off0[TI_N]; ++i) same = idx[i] == idx0[i];
            TH_CHECK(st == SPH_OK && same, "grid at %s, lists at %s: status %d, same lists %d", sph_isa_name(bl),
                     sph_isa_name(sl), st, same);
        }
    sph_isa_set(start);
    th_end();
    free(x), free(h), free(off0), free(off), free(idx0), free(idx);
}

int main(void)
{
    names_case();
    set_case();
    grid_case();
    return th_summary();
}
