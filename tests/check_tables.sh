#!/bin/sh
# tests/check_tables.sh - the GENERATED block of sph_kernel.h is what
# tools/gen_kernel_tables.py writes: regenerates a copy of the header and
# fails (exit 1, printing the diff) where the two differ; `make tables`
# rewrites the block. Where python3 or sympy is missing it prints a line
# "SKIPPED: ..." with the reason and exits 0.
cd "$(dirname "$0")/.." || exit 2
if ! command -v python3 > /dev/null 2>&1; then
    echo "SKIPPED: tests/check_tables.sh (python3/sympy missing): no python3 on PATH"
    exit 0
fi
if ! python3 -c 'import sympy' > /dev/null 2>&1; then
    echo "SKIPPED: tests/check_tables.sh (python3/sympy missing): python3 cannot import sympy"
    exit 0
fi
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
cp sph_kernel.h "$tmp/sph_kernel.h" || exit 2
if ! python3 tools/gen_kernel_tables.py --write "$tmp/sph_kernel.h"; then
    echo "FAILED: tools/gen_kernel_tables.py did not write the tables"
    exit 1
fi
if diff -u sph_kernel.h "$tmp/sph_kernel.h" > "$tmp/diff"; then
    echo "ok: the GENERATED block of sph_kernel.h is what tools/gen_kernel_tables.py writes"
    exit 0
fi
echo "FAILED: the GENERATED block of sph_kernel.h differs from tools/gen_kernel_tables.py (make tables rewrites it):"
cat "$tmp/diff"
exit 1
