/* The fuzz invariants of tests/fuzz_body.h on seeded random inputs (the same
 * on every machine): `make test` runs a short fixed pass; with an argument
 * `test_fuzz_seeded SECONDS` it keeps drawing new inputs for that long (what
 * `make fuzz` does without libFuzzer); `--replay FILE` runs one saved input.
 * Each batch of cases is one harness case. */
#include <time.h>

/* The kernel read at run time keeps this build quick (tests/test_op_dispatch.c
 * proves the kernel-specialised loops give the same bits). */
#include "harness.h"
#include "fuzz_body.h"

#define FZ_BYTES 48

static int run_seed(uint64_t seed)
{
    uint8_t buf[FZ_BYTES];
    tp_rng g;
    int i;
    g.s = seed;
    for (i = 0; i < FZ_BYTES; ++i) buf[i] = (uint8_t)(tp_next(&g) >> 56);
    return fz_case(buf, FZ_BYTES);
}

static int replay(const char *path)
{
    static uint8_t buf[1 << 16];
    FILE *fp = fopen(path, "rb");
    size_t n;
    if (fp == NULL) {
        printf("cannot open %s\n", path);
        return 2;
    }
    n = fread(buf, 1, sizeof buf, fp);
    fclose(fp);
    th_begin("replay %s", path);
    TH_CHECK(fz_case(buf, n) == 0, "%s", fz_msg);
    return th_summary();
}

int main(int argc, char **argv)
{
    const int batches = 8, per_batch = 40;
    uint64_t seed = 1;
    int b, i;
    if (argc > 2 && strcmp(argv[1], "--replay") == 0) return replay(argv[2]);
    if (argc > 1) { /* timed mode */
        const double seconds = atof(argv[1]);
        const clock_t t0 = clock();
        long n = 0;
        seed = (uint64_t)time(NULL) * 1000003u;
        printf("seeded fuzzing for %g s from seed %llu\n", seconds, (unsigned long long)seed);
        while ((double)(clock() - t0) / CLOCKS_PER_SEC < seconds) {
            th_begin("fuzz seed %llu", (unsigned long long)seed);
            TH_CHECK(run_seed(seed) == 0, "%s", fz_msg);
            th_end();
            ++seed, ++n;
        }
        printf("%ld inputs\n", n);
        return th_summary();
    }
    for (b = 0; b < batches; ++b) {
        th_begin("fuzz invariants, seeds %llu..%llu", (unsigned long long)seed,
                 (unsigned long long)(seed + per_batch - 1));
        for (i = 0; i < per_batch; ++i, ++seed) TH_CHECK(run_seed(seed) == 0, "seed %llu: %s", (unsigned long long)seed, fz_msg);
        th_end();
    }
    return th_summary();
}
