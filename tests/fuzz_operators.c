/* libFuzzer entry point for the operator and neighbour-search invariants of
 * tests/fuzz_body.h. Built and run by `make fuzz` (clang -fsanitize=fuzzer,
 * address,undefined); a violated invariant aborts with its description, and
 * libFuzzer saves the input (replay it with build/fuzz/fuzz_operators FILE or
 * build/test_fuzz_seeded --replay FILE). */
#include "fuzz_body.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (fz_case(data, size)) {
        fprintf(stderr, "invariant violated: %s\n", fz_msg);
        abort();
    }
    return 0;
}
