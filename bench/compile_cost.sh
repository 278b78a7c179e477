#!/bin/sh
# bench/compile_cost.sh - what including sph_kernel.h costs to compile: CPU
# seconds (user + system), peak memory and .text bytes of the units of
# bench/compile_units.c and of examples/cloud_quickstart.c, under the build
# options a user would choose. Run by hand (`make compile-cost`); CPU time
# moves little with the machine's load, wall time would.
#   CC=clang sh bench/compile_cost.sh      another compiler
cd "$(dirname "$0")/.." || exit 2
CC=${CC:-cc}
OUT=${BUILD:-build}/compile_cost
mkdir -p "$OUT"
if ! command -v /usr/bin/time > /dev/null 2>&1; then
    echo "bench/compile_cost.sh: /usr/bin/time is missing (Debian: apt-get install time)"
    exit 1
fi
FLAGS="-O2 -std=c99 -Wall -Wextra -pedantic -Werror -I."
PIN="-DSPH_DIM=3 -DSPH_KERNEL=SPH_KERNEL_CUBIC"
echo "$($CC --version | head -n 1), $FLAGS; CPU: $(grep -m1 'model name' /proc/cpuinfo 2> /dev/null | sed 's/.*: //')"
echo
echo "| unit | options | CPU s | peak MB | .text KB |"
echo "|---|---|---:|---:|---:|"
row() { # row "label" "options" source...
    label=$1 opts=$2
    shift 2
    if ! /usr/bin/time -f '%U %S %M' -o "$OUT/time" $CC $FLAGS $opts -c "$@" -o "$OUT/unit.o" > "$OUT/log" 2>&1; then
        echo "| $label | $opts | build failed | | |"
        sed 's/^/    /' "$OUT/log" | head -n 20
        return
    fi
    awk -v l="$label" -v o="${opts:-default}" -v t="$(size "$OUT/unit.o" | awk 'NR == 2 {print $1}')" \
        '{printf "| %s | %s | %.1f | %.0f | %.0f |\n", l, o, $1 + $2, $3 / 1024, t / 1024}' "$OUT/time"
}
row "scalar kernels only" "-DCOST_UNIT=1" bench/compile_units.c
row "scalar kernels only" "-DCOST_UNIT=1 -DSPH_ONLY_KERNELS" bench/compile_units.c
row "pair terms only (own loop)" "-DCOST_UNIT=2" bench/compile_units.c
row "pair terms only (own loop)" "-DCOST_UNIT=2 -DSPH_ONLY_PAIRS" bench/compile_units.c
row "3-D solver step: search + 3 operators" "-DCOST_UNIT=3" bench/compile_units.c
row "3-D solver step: search + 3 operators" "-DCOST_UNIT=3 -march=native" bench/compile_units.c
row "3-D solver step: search + 3 operators" "-DCOST_UNIT=3 -DSPH_NO_DISPATCH" bench/compile_units.c
row "3-D solver step: search + 3 operators" "-DCOST_UNIT=3 $PIN" bench/compile_units.c
row "examples/cloud_quickstart.c" "" examples/cloud_quickstart.c
row "every operator + search, run-time kernel and dim" "-DCOST_UNIT=4" bench/compile_units.c
row "every operator + search, run-time kernel and dim" "-DCOST_UNIT=4 -march=native" bench/compile_units.c
row "every operator + search, run-time kernel and dim" "-DCOST_UNIT=4 -DSPH_NO_DISPATCH" bench/compile_units.c
row "every operator + search, run-time kernel and dim" "-DCOST_UNIT=4 -DSPH_NO_DISPATCH_AVX512" bench/compile_units.c
row "every operator + search, run-time kernel and dim" "-DCOST_UNIT=4 -march=x86-64-v3" bench/compile_units.c
row "every operator + search, run-time kernel and dim" "-DCOST_UNIT=4 -DSPH_OP_REFERENCE" bench/compile_units.c
row "every operator + search, pinned" "-DCOST_UNIT=4 $PIN" bench/compile_units.c
row "every operator + search, pinned" "-DCOST_UNIT=4 $PIN -march=native" bench/compile_units.c
row "every operator + search, run-time kernel and dim" "-DCOST_UNIT=4 -DSPH_NO_SOLVER" bench/compile_units.c
row "solver terms (section 8) + h solve, grad-h, pair-once (9)" "-DCOST_UNIT=5" bench/compile_units.c
row "solver terms (section 8) + h solve, grad-h, pair-once (9)" "-DCOST_UNIT=5 -march=native" bench/compile_units.c
