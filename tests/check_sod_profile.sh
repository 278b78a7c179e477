#!/bin/sh
# tests/check_sod_profile.sh - examples/sod_shock.c --profile and the step
# benchmark built on it: a run with --profile writes the profile CSV of the
# run without it byte for byte; its table counts what the step handles
# consistently (the kept list's entries at least 2 pairs + the particle
# itself, search candidates at least the list entries, its steps those of the
# run); lists kept over steps give the run of fresh lists; bench/bench_step.sh turns the runs into its table. nx = 8 to
# t = 0.03: a few seconds. Exit 1 naming the first failed check.
cd "$(dirname "$0")/.." || exit 2
CC=${CC:-gcc}
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
OPENMP=$(printf 'int main(void){return 0;}\n' | $CC -fopenmp -x c - -o /dev/null > /dev/null 2>&1 && echo -fopenmp)
fail() {
    echo "FAILED: $*"
    exit 1
}
# built as bench/bench_step.sh builds its O2 program, where that script then finds it (the same command in
# sod_shock_O2.cmd beside it): one build of the example's several
bin="$tmp/build/bench_step/sod_shock_O2"
cmd="$CC -O2 -std=c99 -Wall -Wextra -pedantic -Werror $OPENMP -I. examples/sod_shock.c -o $bin -lm"
mkdir -p "$tmp/build/bench_step" || exit 2
# shellcheck disable=SC2086
$cmd || fail "examples/sod_shock.c does not build"
echo "$cmd" > "$bin.cmd"
mkdir -p "$tmp/plain" "$tmp/prof"
OMP_NUM_THREADS=2 "$bin" --nx 8 --t-end 0.03 --out "$tmp/plain" > "$tmp/plain.txt" 2>&1 ||
    fail "sod_shock --nx 8 --t-end 0.03: $(cat "$tmp/plain.txt")"
OMP_NUM_THREADS=2 "$bin" --nx 8 --t-end 0.03 --out "$tmp/prof" --profile > "$tmp/prof.txt" 2>&1 ||
    fail "sod_shock --nx 8 --t-end 0.03 --profile: $(cat "$tmp/prof.txt")"
cmp -s "$tmp/plain/sod_nx8.csv" "$tmp/prof/sod_nx8.csv" || fail "--profile changed the run: sod_nx8.csv differs"
if [ -n "$OPENMP" ]; then # the same run on one thread: every loop of the step is the same for any thread count
    mkdir -p "$tmp/one"
    "$bin" --nx 8 --t-end 0.03 --threads 1 --out "$tmp/one" > "$tmp/one.txt" 2>&1 ||
        fail "sod_shock --threads 1: $(cat "$tmp/one.txt")"
    cmp -s "$tmp/plain/sod_nx8.csv" "$tmp/one/sod_nx8.csv" || fail "1 and 2 threads differ: sod_nx8.csv"
fi
awk '
    /^nx / { steps = $6 }
    /^profile: / { psteps = $2 }
    $1 == "search" || $1 == "density/h" || $1 == "forces" || $1 == "rest" { ++phases; sum += $2 }
    $1 == "total" { total = $2 }
    /^  list entries per particle/ { e = $5 }
    /^  pairs per particle/ { p = $4 }
    /^  candidates per particle/ { c = $4 }
    /^  bytes per particle/ { b = $4 }
    END {
        if (phases != 4 || total <= 0 || sum < total - 0.01 || sum > total + 0.01) { print "phases", phases, "sum", sum, "total", total; exit 1 }
        if (psteps == "" || psteps != steps) { print "profile steps", psteps, "run steps", steps; exit 1 }
        if (p <= 0 || e < 2 * p + 1 - 0.011) { print "list entries", e, "pairs", p, "(the kept list holds every pair and the particle itself)"; exit 1 }
        if (c < e) { print "candidates", c, "below list entries", e; exit 1 }
        if (b <= 0) { print "bytes per particle", b; exit 1 }
    }' "$tmp/prof.txt" > "$tmp/why" || fail "sod_shock --profile table: $(cat "$tmp/why")"
# the kept lists serve every h: runs at two skins that need no re-search are the same bit for bit (nx 8 to t = 0.2,
# 35 steps; the particles move beyond the smaller skin, so its lists are searched again on the way)
for s in 0.3 0.6; do
    mkdir -p "$tmp/skin$s"
    "$bin" --nx 8 --t-end 0.2 --skin $s --out "$tmp/skin$s" --profile > "$tmp/skin$s.txt" 2>&1 ||
        fail "sod_shock --nx 8 --t-end 0.2 --skin $s: $(cat "$tmp/skin$s.txt")"
done
cmp -s "$tmp/skin0.3/sod_nx8.csv" "$tmp/skin0.6/sod_nx8.csv" ||
    fail "--skin 0.3 and --skin 0.6 differ: the kept lists missed pairs within kappa h"
awk '/^  searches/ { s = $2 } /^profile: / { n = $2 } END { if (!(s > 1 && s < n)) { print "searches", s, "steps", n; exit 1 } }' \
    "$tmp/skin0.3.txt" > "$tmp/why" || fail "--skin 0.3: the lists were not kept and searched again: $(cat "$tmp/why")"
# rows of (build, nx 8, threads): the level of the loops named, total, search, density/h, forces, entries, pairs,
# candidates and bytes all > 0; with OpenMP, taskset and two CPUs also the 1-thread runs of O2 and native pinned to
# each and the speed-up the cores allow; on a CPU with AVX2 the rows of the O2 build at its AVX2 loops and of the
# -march=x86-64-v3 build, both at avx2
avx2=0
grep -qw avx2 /proc/cpuinfo 2> /dev/null && avx2=1
for cores in 1 0; do
    CC="$CC" BUILD="$tmp/build" BENCH_STEP_NX=8 BENCH_STEP_REPEATS=1 BENCH_STEP_T_END=0.01 BENCH_STEP_OUT="$tmp/step.md" \
        BENCH_STEP_CORES=$cores sh bench/bench_step.sh > "$tmp/bench.txt" 2>&1 ||
        fail "bench/bench_step.sh: $(tail -n 5 "$tmp/bench.txt")"
    rows=$(awk -F'|' '$4 == " 8 " && $3 ~ /[a-z]/ && $8 + 0 > 0 && $9 + 0 > 0 && $10 + 0 > 0 && $11 + 0 > 0 &&
        $14 + 0 > 0 && $15 + 0 > 0 && $16 + 0 > 0 && $17 + 0 > 0 { ++n } END { print n + 0 }' "$tmp/step.md")
    at_avx2=$(awk -F'|' '$4 == " 8 " && ($2 == " O2-avx2 " || $2 == " avx2 ") && $3 == " avx2 " { ++n } END { print n + 0 }' "$tmp/step.md")
    pinned=0
    [ -n "$OPENMP" ] && [ "$cores" = 1 ] && ! grep -q 'no per-core runs' "$tmp/bench.txt" && pinned=1
    per=$([ -n "$OPENMP" ] && echo 2 || echo 1) # thread counts per build
    want=$((per * (avx2 ? 4 : 2) + (pinned ? 4 : 0)))
    [ "$rows" = "$want" ] || fail "bench/bench_step.sh (BENCH_STEP_CORES=$cores): $rows complete table rows instead of $want: $(cat "$tmp/step.md")"
    [ "$at_avx2" = $((avx2 * per * 2)) ] || fail "bench/bench_step.sh: $at_avx2 AVX2 rows at avx2 instead of $((avx2 * per * 2)): $(cat "$tmp/step.md")"
    if [ "$pinned" = 1 ]; then # nx 8 in the ratio table: speed-ups, allowed (1..2), efficiencies and the ratios, all > 0
        awk -F'|' -v avx2=$avx2 '$2 == " 8 " && NF == 13 && $4 + 0 >= 1 && $4 + 0 <= 2 && $7 + 0 >= 1 && $7 + 0 <= 2 &&
            $3 + 0 > 0 && $5 + 0 > 0 && $6 + 0 > 0 && $8 + 0 > 0 && $9 + 0 > 0 && (!avx2 || ($11 + 0 > 0 && $12 + 0 > 0)) { ok = 1 }
            END { exit !ok }' "$tmp/step.md" ||
            fail "bench/bench_step.sh: no ratio row with allowed, efficiency and the ratios: $(cat "$tmp/step.md")"
    fi
done
echo "tests/check_sod_profile.sh: --profile and the thread count leave the run unchanged, its counts agree, --skin 0.3 = --skin 0.6, bench/bench_step.sh writes its rows, with and without the per-core runs"
