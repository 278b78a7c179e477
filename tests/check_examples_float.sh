#!/bin/sh
# tests/check_examples_float.sh - the examples a user copies build in float
# too (-DSPH_REAL=float, warnings as errors, compiled only): every
# examples/*.c but the MPI one, which needs mpicc. Exit 1 on the first that
# does not build, with the compiler's messages. Without the run-time passes
# (SPH_NO_DISPATCH: they compile the header's same text again, and the float
# test builds compile them).
cd "$(dirname "$0")/.." || exit 2
CC=${CC:-gcc}
n=0
for f in examples/*.c; do
    case $f in *mpi_*) continue ;; esac
    if ! $CC -O2 -std=c99 -Wall -Wextra -pedantic -Werror -DSPH_NO_DISPATCH -DSPH_REAL=float -I. -c "$f" -o /dev/null; then
        echo "FAILED: $f does not build with -DSPH_REAL=float"
        exit 1
    fi
    n=$((n + 1))
done
echo "tests/check_examples_float.sh: $n examples build in float"
