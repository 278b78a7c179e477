#!/bin/sh
# tests/check_examples_blowup.sh - a run that goes wrong while its values stay
# finite stops with exit 1 and says why: taylor_green at Re = 0.1 on 20 x 20
# particles (the weakly compressible pressure cannot follow the viscous decay;
# before the bound, it wrote a relative L2 velocity error of 2.5e14 and
# exited 0) must exit 1 naming the quantity, its bound and a hint, and the
# same run at Re = 100 must still pass. Builds as the Makefile does; about a
# second.
cd "$(dirname "$0")/.." || exit 2
CC=${CC:-gcc}
dir=build/test/blowup
mkdir -p "$dir" || exit 2
if ! $CC -O2 -std=c99 -Wall -Wextra -pedantic -Werror -I. examples/taylor_green.c -o "$dir/taylor_green" -lm; then
    echo "FAILED: examples/taylor_green.c does not build"
    exit 1
fi
"$dir/taylor_green" --n 20 --t-end 0.05 --frames 0 --re 0.1 --out "$dir/out" > "$dir/low_re.out" 2> "$dir/low_re.err"
rc=$?
if [ $rc -ne 1 ]; then
    echo "FAILED: taylor_green --re 0.1 exited $rc, not 1"
    cat "$dir/low_re.out" "$dir/low_re.err"
    exit 1
fi
if ! grep -q '^taylor_green: relative L2 velocity error = .* at t = .* exceeds its bound 1: run stopped (.*--re' "$dir/low_re.err"; then
    echo "FAILED: taylor_green --re 0.1 did not name the quantity, bound and hint:"
    cat "$dir/low_re.err"
    exit 1
fi
if ! "$dir/taylor_green" --n 20 --t-end 0.05 --frames 0 --re 100 --out "$dir/out" > "$dir/re100.out" 2>&1; then
    echo "FAILED: the same run at --re 100 did not pass:"
    cat "$dir/re100.out"
    exit 1
fi
echo "tests/check_examples_blowup.sh: taylor_green --re 0.1 stops with exit 1 at its error bound; --re 100 runs"
