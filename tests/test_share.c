/* tests/test_share.c - shares of a parallel loop (section 4: sph_share_init,
 * sph_share_next).
 *
 * Threads taken in turn (one program thread calls sph_share_next for each
 * of T threads, round after round, and in a shuffled order): every
 * particle 0..n-1 is handed out exactly once; each chunk lies within one
 * share (share p is n p / shares .. n (p + 1) / shares - 1, the static
 * schedule's block) and holds at most `chunk` particles; the first chunk of
 * thread t < shares is from its own share unless others took all of it
 * before (taken in turn from 0: always the share's first); once a thread is told
 * nothing is left, nothing is. Sizes: n 0, 1, 5, 64, 1000, 4099; shares 1,
 * 2, 3, 5; threads 1, 2, 3, 7 (more threads than shares and fewer); chunks
 * 1, 7, 64. With OpenMP (the +omp configurations, OMP_NUM_THREADS=2) the
 * same loop over 100003 particles from a real team, counts added with
 * atomics: every particle once, for 2 and 3 shares.
 *
 * Bad input: sph_share_init refuses a NULL share or counters (SPH_ENULL),
 * n < 0 and shares < 1 (SPH_ECOUNT), chunk < 1 (SPH_ERANGE), and a share it
 * refused hands out nothing; sph_share_next gives 0 for t < 0 and a NULL
 * share or counter of emptied shares.
 */
#include "harness.h"
#include "support/particles.h"

#define MAXN 4099
#define MAXT 7

/* 1 when thread t's first chunk (lo) is from its own share, or that share was
 * already taken in full by others (seen), or t has no share of its own. */
static int sh_own_first(int t, int shares, sph_idx n, sph_idx lo, const int *seen)
{
    const sph_idx start = (sph_idx)((long)n * t / shares), end = (sph_idx)((long)n * (t + 1) / shares);
    sph_idx i;
    int taken = 1;
    for (i = start; t < shares && i < end; ++i) taken &= seen[i] > 0;
    return t >= shares || (lo >= start && lo < end) || taken;
}

/* One configuration, threads taken in turn (shuffled when rng is not NULL). */
static void sh_check(sph_idx n, int shares, int T, sph_idx chunk, tp_rng *rng)
{
    static int seen[MAXN];
    sph_off next[5 * SPH_SHARE_PAD];
    sph_share s;
    int u[MAXT], done[MAXT], first[MAXT], order[MAXT], t, k, left = T, bad = 0, twice = 0, outside = 0, late = 0;
    sph_idx i, lo, hi;
    memset(seen, 0, sizeof seen);
    for (t = 0; t < T; ++t) u[t] = 0, done[t] = 0, first[t] = 1, order[t] = t;
    TH_CHECK(sph_share_init(&s, next, shares, n, chunk) == SPH_OK, "init n %ld shares %d chunk %ld", (long)n, shares,
             (long)chunk);
    while (left > 0) {
        if (rng != NULL)
            for (t = T - 1; t > 0; --t) { /* a new order of the threads each round */
                const int j = (int)(tp_uniform(rng) * (t + 1)), x = order[t];
                order[t] = order[j], order[j] = x;
            }
        for (k = 0; k < T; ++k) {
            t = order[k];
            if (!sph_share_next(&s, t, &u[t], &lo, &hi)) {
                left -= !done[t], done[t] = 1;
                continue;
            }
            late += done[t];
            if (first[t] && !sh_own_first(t, shares, n, lo, seen)) ++bad;
            first[t] = 0;
            {
                int q, in = 0;
                for (q = 0; q < shares; ++q) /* the share holding lo holds the chunk */
                    in |= lo >= (long)n * q / shares && lo < (long)n * (q + 1) / shares && hi <= (long)n * (q + 1) / shares;
                outside += !in || hi <= lo || hi - lo > chunk;
            }
            for (i = lo; i < hi && i < n && i >= 0; ++i) twice += seen[i]++ > 0;
        }
    }
    for (i = 0; i < n; ++i) bad += seen[i] != 1;
    TH_CHECK(bad == 0 && twice == 0 && outside == 0 && late == 0,
             "n %ld shares %d threads %d chunk %ld%s: %d missed or not first in own share, %d twice, %d chunks "
             "outside a share or too long, %d after done",
             (long)n, shares, T, (long)chunk, rng ? " shuffled" : "", bad, twice, outside, late);
}

static void sh_turns(void)
{
    static const sph_idx ns[] = {0, 1, 5, 64, 1000, 4099}, chunks[] = {1, 7, 64};
    static const int shares[] = {1, 2, 3, 5}, threads[] = {1, 2, 3, 7};
    tp_rng g = {11};
    int a, b, c, d;
    th_begin("every particle once, in chunks within shares, each thread its own share first");
    for (a = 0; a < 6; ++a)
        for (b = 0; b < 4; ++b)
            for (c = 0; c < 4; ++c)
                for (d = 0; d < 3; ++d) {
                    sh_check(ns[a], shares[b], threads[c], chunks[d], NULL);
                    sh_check(ns[a], shares[b], threads[c], chunks[d], &g);
                }
    th_end();
}

static void sh_team(void)
{
    enum { N = 100003 };
    static int count[N];
    sph_off next[3 * SPH_SHARE_PAD];
    int shares, threads = 1;
    th_begin("an OpenMP team: every particle once");
    for (shares = 2; shares <= 3; ++shares) {
        sph_share s;
        long bad = 0;
        int i;
        memset(count, 0, sizeof count);
        TH_CHECK(sph_share_init(&s, next, shares, N, 64) == SPH_OK, "init");
#ifdef _OPENMP
#pragma omp parallel
#endif
        {
            sph_idx lo, hi, j;
            int u = 0, t = 0;
#ifdef _OPENMP
            t = omp_get_thread_num();
#pragma omp single
            threads = omp_get_num_threads();
#endif
            while (sph_share_next(&s, t, &u, &lo, &hi))
                for (j = lo; j < hi; ++j) {
#ifdef _OPENMP
#pragma omp atomic
#endif
                    count[j]++;
                }
        }
        for (i = 0; i < N; ++i) bad += count[i] != 1;
        TH_CHECK(bad == 0, "%d shares, %d threads: %ld particles not taken once", shares, threads, bad);
    }
    printf("    %d threads\n", threads);
    th_end();
}

static void sh_bad_input(void)
{
    sph_off next[2 * SPH_SHARE_PAD];
    sph_share s;
    sph_idx lo = -1, hi = -1;
    int u = 0;
    th_begin("bad input");
    TH_CHECK(sph_share_init(NULL, next, 2, 10, 4) == SPH_ENULL, "NULL share");
    TH_CHECK(sph_share_init(&s, NULL, 2, 10, 4) == SPH_ENULL, "NULL counters");
    TH_CHECK(!sph_share_next(&s, 0, &u, &lo, &hi), "a share refused hands out nothing");
    TH_CHECK(sph_share_init(&s, next, 2, -1, 4) == SPH_ECOUNT, "n < 0");
    TH_CHECK(sph_share_init(&s, next, 0, 10, 4) == SPH_ECOUNT, "no shares");
    TH_CHECK(sph_share_init(&s, next, -3, 10, 4) == SPH_ECOUNT, "shares < 0");
    TH_CHECK(sph_share_init(&s, next, 2, 10, 0) == SPH_ERANGE, "chunk 0");
    TH_CHECK(!sph_share_next(&s, 0, &u, &lo, &hi), "after a refused chunk: nothing");
    TH_CHECK(sph_share_init(&s, next, 2, 10, 4) == SPH_OK, "valid");
    TH_CHECK(!sph_share_next(&s, -1, &u, &lo, &hi), "thread -1");
    TH_CHECK(!sph_share_next(NULL, 0, &u, &lo, &hi), "NULL share");
    TH_CHECK(!sph_share_next(&s, 0, NULL, &lo, &hi), "NULL counter of emptied shares");
    TH_CHECK(lo == -1 && hi == -1, "nothing written: %ld %ld", (long)lo, (long)hi);
    TH_CHECK(sph_share_next(&s, 1, &u, &lo, &hi) && lo == 5 && hi == 9, "thread 1's first chunk: %ld..%ld", (long)lo,
             (long)hi - 1);
    th_end();
}

int main(void)
{
    sh_turns();
    sh_team();
    sh_bad_input();
    return th_summary();
}
