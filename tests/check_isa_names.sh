#!/bin/sh
# tests/check_isa_names.sh - the list of function names at the end of
# sph_kernel.h (the run-time passes, section 1) names every function of
# sections 5-9: a function added without `make isa-names` fails here (exit 1,
# with the lines that differ). Needs gcc (its -aux-info prototypes).
cd "$(dirname "$0")/.." || exit 2
if ! command -v gcc > /dev/null 2>&1; then
    echo "SKIPPED: tests/check_isa_names.sh (gcc is not installed)"
    exit 0
fi
CC=gcc sh support/isa_names.sh --check
