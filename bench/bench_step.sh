#!/bin/sh
# bench/bench_step.sh - the step of examples/sod_shock.c per particle: wall
# time of search, density / h solve, forces and the rest (sod_shock
# --profile), list entries, half-list pairs, search candidates and bytes held
# per particle, for nx = 16, 32, 48 on 1 and 2 threads and on 1 thread pinned
# to each of the first two CPUs (what speed-up the two cores allow), built
# with the Makefile's flags (O2: no -march, the header's run-time dispatch
# picks the CPU's widest loops) and with -O3 -march=native; on a CPU with
# AVX2, also the O2 build forced to its AVX2 loops (O2-avx2: sod_shock --isa
# avx2) and an -O3 -march=x86-64-v3 build at AVX2 (avx2: what a CPU without
# AVX-512 runs with -march=native), 1 and 2 threads. Run by `make
# bench-step`; prints the table and writes it to docs/results/step.md.
#   BENCH_STEP_NX="16"        resolutions (fcc cells per unit length, left)
#   BENCH_STEP_REPEATS=3      repeats of every run (a time is their median)
#   BENCH_STEP_T_END=0.05     simulated time of each run
#   BENCH_STEP_OUT=file       where the table goes
#   BENCH_STEP_CORES=1        0: skip the one-thread runs pinned to each of the
#                             first two CPUs (taskset), which tell how fast each
#                             core runs and so what speed-up the two allow
# Each repeat runs every (nx, build, threads) once, the 1- and 2-thread runs of a
# build back to back, so that a ratio (speed-up, -O3 against -O2, a phase's
# share) is taken within one repeat or one run and load that comes and goes
# between repeats cancels; the table gives the median over the repeats.
cd "$(dirname "$0")/.." || exit 2
CC=${CC:-cc}
CFLAGS=${CFLAGS:--O2 -std=c99 -Wall -Wextra -pedantic -Werror}
OPENMP=${OPENMP-$(printf 'int main(void){return 0;}\n' | $CC -fopenmp -x c - -o /dev/null > /dev/null 2>&1 && echo -fopenmp)}
LDLIBS=${LDLIBS:--lm}
NX=${BENCH_STEP_NX:-16 32 48}
REPEATS=${BENCH_STEP_REPEATS:-3}
T_END=${BENCH_STEP_T_END:-0.05}
OUT=${BENCH_STEP_OUT:-docs/results/step.md}
DIR=${BUILD:-build}/bench_step
case $DIR in /*) ;; *) DIR=./$DIR ;; esac
NATIVE="-O3 -march=native -std=c99 -Wall -Wextra -pedantic -Werror"
AVX2="-O3 -march=x86-64-v3 -std=c99 -Wall -Wextra -pedantic -Werror"
BUILDS="O2 native"
grep -qw avx2 /proc/cpuinfo 2> /dev/null && BUILDS="$BUILDS O2-avx2 avx2"
THREADS="1 2"
CORES=${BENCH_STEP_CORES:-1}
case $CORES in 0 | 1) ;; *) echo "bench/bench_step.sh: BENCH_STEP_CORES=$CORES is neither 0 nor 1"; exit 2 ;; esac
if [ -z "$OPENMP" ]; then
    echo "bench/bench_step.sh: $CC has no -fopenmp: 1 thread only"
    THREADS=1
fi
# The first two CPUs this process may run on ("0,1" from "0-63" or "0,2,4").
CPUS=$(taskset -pc $$ 2> /dev/null | sed 's/.*: //' | tr ',' '\n' |
    awk -F- '{ for (c = $1; c <= ($2 == "" ? $1 : $2) && k < 2; ++c) printf "%s%d", (k++ ? "," : ""), c }')
if [ "$THREADS" = "1" ] || [ "$CORES" = 0 ]; then
    CPUS=
elif [ "${CPUS#*,}" = "$CPUS" ]; then
    echo "bench/bench_step.sh: no taskset or fewer than two CPUs to pin to: no per-core runs"
    CPUS=
fi
# The runs of each build and nx: 1 and 2 threads, then 1@c, one thread pinned to CPU c
RUNS=$THREADS
for c in $(echo "$CPUS" | tr ',' ' '); do RUNS="$RUNS 1@$c"; done
case $REPEATS in '' | *[!0-9]* | 0) echo "bench/bench_step.sh: BENCH_STEP_REPEATS=$REPEATS is not a positive integer"; exit 2 ;; esac
mkdir -p "$DIR/out" || exit 1
START=$(date -u '+%Y-%m-%d %H:%M UTC')
LOAD0=$(cut -d' ' -f1-3 /proc/loadavg 2> /dev/null)
T0=$(date +%s)
# build name "flags": examples/sod_shock.c into $DIR/sod_shock_name, unless that program is newer than the
# sources and was built with the same command
build() {
    cmd="$CC $2 $OPENMP -I. examples/sod_shock.c -o $DIR/sod_shock_$1 $LDLIBS"
    if [ "$DIR/sod_shock_$1" -nt sph_kernel.h ] && [ "$DIR/sod_shock_$1" -nt examples/sod_shock.c ] &&
        [ "$DIR/sod_shock_$1" -nt examples/example_io.h ] &&
        [ "$(cat "$DIR/sod_shock_$1.cmd" 2> /dev/null)" = "$cmd" ]; then
        return 0
    fi
    # shellcheck disable=SC2086
    $cmd || exit 1
    echo "$cmd" > "$DIR/sod_shock_$1.cmd"
}
build O2 "$CFLAGS"
build native "$NATIVE"
case $BUILDS in *avx2*) build avx2 "$AVX2" ;; esac
: > "$DIR/runs.txt"
r=1
while [ "$r" -le "$REPEATS" ]; do
    for nx in $NX; do
        for b in $BUILDS; do
            runs=$RUNS bin=$b isa=auto
            case $b in *avx2) runs=$THREADS isa=avx2 ;; esac
            case $b in O2-avx2) bin=O2 ;; esac
            for th in $runs; do
                echo "repeat $r/$REPEATS  nx $nx  $b  $th thread(s)" >&2
                pin=
                case $th in 1@*) pin="taskset -c ${th#1@}" ;; esac
                # shellcheck disable=SC2086
                if ! OMP_NUM_THREADS=${th%@*} $pin "$DIR/sod_shock_$bin" --isa $isa --nx "$nx" --t-end "$T_END" \
                    --threads "${th%@*}" --profile --out "$DIR/out" > "$DIR/run.txt" 2>&1; then
                    cat "$DIR/run.txt"
                    echo "bench/bench_step.sh: sod_shock --nx $nx ($b, $th threads) failed"
                    exit 1
                fi
                # one line per run: repeat build nx threads n steps, us of total search density/h forces rest, list
                # entries, pairs, candidates, bytes (per particle)
                awk -v r="$r" -v b="$b" -v nx="$nx" -v th="$th" '
                    /^profile: / { steps = $2; n = $5; isa = $0; sub(/.*fast loops at /, "", isa); sub(/;.*/, "", isa) }
                    $1 == "search" || $1 == "density/h" || $1 == "forces" || $1 == "rest" || $1 == "total" { us[$1] = $2 }
                    /^  list entries per particle/ { e = $5 }
                    /^  pairs per particle/ { hp = $4 }
                    /^  candidates per particle/ { c = $4 }
                    /^  bytes per particle/ { by = $4 }
                    END {
                        if (steps == "") exit 1
                        print r, b, nx, th, n, steps, us["total"], us["search"], us["density/h"], us["forces"], us["rest"], e, hp, c, by, isa
                    }' "$DIR/run.txt" >> "$DIR/runs.txt" || { cat "$DIR/run.txt"; echo "bench/bench_step.sh: no --profile table"; exit 1; }
            done
        done
    done
    r=$((r + 1))
done
LOAD1=$(cut -d' ' -f1-3 /proc/loadavg 2> /dev/null)
T1=$(date +%s)
{
    echo "# Step benchmark: examples/sod_shock.c"
    echo
    echo "Written by \`make bench-step\` (bench/bench_step.sh) on $START, $((T1 - T0)) s of wall time."
    echo
    echo "- CPU: $(grep -m1 'model name' /proc/cpuinfo 2> /dev/null | sed 's/.*: //'), $(nproc 2> /dev/null) cores online ($(grep -c '^processor' /proc/cpuinfo 2> /dev/null) logical CPUs)"
    echo "- compiler: $($CC --version 2> /dev/null | head -n 1)"
    echo "- builds: O2 = \`$CC $CFLAGS $OPENMP\` (the Makefile's flags; the header's loops at the CPU's widest level, run-time dispatch), native = \`$CC $NATIVE $OPENMP\`"
    case $BUILDS in *avx2*) echo "- AVX2 rows: O2-avx2 = the O2 build run with \`--isa avx2\` (its AVX2 loops, as on a CPU without AVX-512), avx2 = \`$CC $AVX2 $OPENMP\` run with \`--isa avx2\` (a -march=native build on such a CPU)" ;; esac
    echo "- instruction sets: $(grep -qw avx512f /proc/cpuinfo && echo 'AVX-512, ')$(grep -qw avx2 /proc/cpuinfo && echo 'AVX2 + FMA, ')SSE2; the level each build ran at is in \`${DIR#./}/runs.txt\`'s profile lines"
    echo "- load average (1, 5, 15 min): $LOAD0 at the start, $LOAD1 at the end"
    echo "- commit: $(git rev-parse --short HEAD 2> /dev/null || echo unknown)$(git diff --quiet HEAD -- examples/sod_shock.c sph_kernel.h 2> /dev/null || echo ' with local changes')"
    echo "- runs: \`sod_shock --nx NX --t-end $T_END --threads T --profile\`, $REPEATS repeats each"
    echo
    echo "Microseconds of wall time per particle and step (monotonic clock), medians over the"
    echo "repeats; in brackets the median share of the step within a run. search: the skin rule,"
    echo "and on the steps whose kept lists are stale the list radii, cells and symmetric lists;"
    echo "density/h: sph_h_solve, any re-search it asks for, and the pruning of the kept list to"
    echo "the pairs within reach; forces: sound speeds and the pair loop; rest: time step, kicks,"
    echo "drift. The first forces before the step loop and the final densities are not timed."
    echo "Entries: entries of the kept symmetric list (self included, the h solve's sums); pairs:"
    echo "pairs within kappa max(h_i, h_j), which the force loop visits from both ends;"
    echo "candidates: positions the search checked (sph_nsearch_stats every 10th step, outside"
    echo "the timed phases); bytes: held by the step (fields, lists, search workspace). spread:"
    echo "the slowest and fastest total."
    if [ -n "$CPUS" ]; then
        echo "Threads \"1, CPU c\": one thread pinned to CPU c (taskset), run after the unpinned"
        echo "1- and 2-thread runs of the same build: how fast each core of the machine runs the step."
    fi
    echo
    awk -v cpus="$CPUS" '
        function median(s,    a, m, i, j, t) { # of the space-separated numbers in s
            m = split(s, a, " ")
            for (i = 2; i <= m; ++i) for (j = i; j > 1 && a[j - 1] + 0 > a[j] + 0; --j) { t = a[j]; a[j] = a[j - 1]; a[j - 1] = t }
            return m % 2 ? a[(m + 1) / 2] : (a[m / 2] + a[m / 2 + 1]) / 2
        }
        function lo(s,    a, m, i, v) { m = split(s, a, " "); v = a[1]; for (i = 2; i <= m; ++i) if (a[i] + 0 < v + 0) v = a[i]; return v }
        function hi(s,    a, m, i, v) { m = split(s, a, " "); v = a[1]; for (i = 2; i <= m; ++i) if (a[i] + 0 > v + 0) v = a[i]; return v }
        {
            k = $2 " " $3 " " $4
            if (!(k in n)) { order[++nk] = k; n[k] = $5; steps[k] = $6; isa[k] = $16 }
            for (c = 7; c <= 15; ++c) v[k, c] = v[k, c] " " $c
            for (c = 8; c <= 11; ++c) share[k, c] = share[k, c] " " 100 * $c / $7
            tot[$1, k] = $7
            builds[$2] = 1; nxs[$3] = 1; ths[$4] = 1
        }
        END {
            print "| build | loops | nx | particles | steps | threads | total | search | density/h | forces | rest | spread of total | entries | pairs | candidates | bytes |"
            print "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
            for (i = 1; i <= nk; ++i) {
                k = order[i]; split(k, f, " ")
                th = f[3]; sub(/^1@/, "1, CPU ", th)
                printf "| %s | %s | %s | %s | %s | %s | %.2f |", f[1], isa[k], f[2], n[k], steps[k], th, median(v[k, 7])
                for (c = 8; c <= 11; ++c) printf " %.2f (%.0f %%) |", median(v[k, c]), median(share[k, c])
                printf " %.2f-%.2f | %.1f | %.1f | %.0f | %.0f |\n", lo(v[k, 7]), hi(v[k, 7]), median(v[k, 12]), median(v[k, 13]), median(v[k, 14]), median(v[k, 15])
            }
            if (!(2 in ths)) exit
            print ""
            print "Ratios of the total, each the median over the repeats of the ratio within one repeat:"
            print "the 2-thread speed-up (1-thread time / 2-thread time) and native against O2 (O2 time /"
            print "native time, same threads); with AVX2 rows, O2-avx2 / avx2 (the same for the AVX2 loops)"
            print "and avx2 / native (the AVX2 build against the AVX-512 one), 1 thread."
            if (cpus != "") {
                split(cpus, cpu, ",")
                print "Allowed: the largest 2-thread speed-up the two cores allow over the faster of them,"
                print "1 + t_fast / t_slow, with t_a, t_b the 1-thread times pinned to CPU " cpu[1] " and CPU " cpu[2] ": below 2"
                print "when one core runs slower than the other, as on a virtual machine whose host shares"
                print "its second core. Efficiency: the 2-thread time the two cores would take with the work"
                print "shared in proportion to their speeds, 1 / (1 / t_a + 1 / t_b), over the measured one."
            }
            print ""
            if (cpus != "") {
                print "| nx | 2-thread speed-up, O2 | allowed, O2 | efficiency, O2 | 2-thread speed-up, native | allowed, native | efficiency, native | O2 / native, 1 thread | O2 / native, 2 threads | O2-avx2 / avx2, 1 thread | avx2 / native, 1 thread |"
                print "|---|---|---|---|---|---|---|---|---|---|---|"
            } else {
                print "| nx | 2-thread speed-up, O2 | 2-thread speed-up, native | O2 / native, 1 thread | O2 / native, 2 threads | O2-avx2 / avx2, 1 thread | avx2 / native, 1 thread |"
                print "|---|---|---|---|---|---|---|"
            }
            for (i = 1; i <= nk; ++i) {
                k = order[i]; split(k, f, " ")
                if (f[1] != "O2" || f[3] != 1 || done[f[2]]++) continue
                s2 = sn = r1 = r2 = a2 = an = e2 = en = va = vn = ""
                for (rr = 1; ((rr, "O2 " f[2] " 1") in tot); ++rr) {
                    s2 = s2 " " tot[rr, "O2 " f[2] " 1"] / tot[rr, "O2 " f[2] " 2"]
                    sn = sn " " tot[rr, "native " f[2] " 1"] / tot[rr, "native " f[2] " 2"]
                    r1 = r1 " " tot[rr, "O2 " f[2] " 1"] / tot[rr, "native " f[2] " 1"]
                    r2 = r2 " " tot[rr, "O2 " f[2] " 2"] / tot[rr, "native " f[2] " 2"]
                    if ((rr, "avx2 " f[2] " 1") in tot) {
                        va = va " " tot[rr, "O2-avx2 " f[2] " 1"] / tot[rr, "avx2 " f[2] " 1"]
                        vn = vn " " tot[rr, "avx2 " f[2] " 1"] / tot[rr, "native " f[2] " 1"]
                    }
                    if (cpus == "") continue
                    for (bb = 1; bb <= 2; ++bb) {
                        b = bb == 1 ? "O2 " f[2] : "native " f[2]
                        ta = tot[rr, b " 1@" cpu[1]]; tb = tot[rr, b " 1@" cpu[2]]
                        al = ta < tb ? 1 + ta / tb : 1 + tb / ta
                        ef = 1 / (tot[rr, b " 2"] * (1 / ta + 1 / tb))
                        if (bb == 1) { a2 = a2 " " al; e2 = e2 " " ef } else { an = an " " al; en = en " " ef }
                    }
                }
                if (cpus != "")
                    printf "| %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %s | %s |\n", f[2], median(s2), median(a2), median(e2), median(sn), median(an), median(en), median(r1), median(r2), va == "" ? "-" : sprintf("%.2f", median(va)), vn == "" ? "-" : sprintf("%.2f", median(vn))
                else
                    printf "| %s | %.2f | %.2f | %.2f | %.2f | %s | %s |\n", f[2], median(s2), median(sn), median(r1), median(r2), va == "" ? "-" : sprintf("%.2f", median(va)), vn == "" ? "-" : sprintf("%.2f", median(vn))
            }
        }' "$DIR/runs.txt"
    echo
    echo "One line per run (repeat, build, nx, threads (1@c: pinned to CPU c), particles, steps, total, search, density/h,"
    echo "forces, rest, entries, pairs, candidates, bytes, level of the loops): \`${DIR#./}/runs.txt\`."
} > "$DIR/step.md" || exit 1
cat "$DIR/step.md"
cp "$DIR/step.md" "$OUT" && echo "wrote $OUT"
