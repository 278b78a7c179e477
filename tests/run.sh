#!/bin/bash
# tests/run.sh - `make test` (tier "test", the default) and `make check` (tier
# "check", the developer's quick run). Builds every tests/test_*.c in every
# configuration of the table below, runs them, runs the examples' --check
# modes (listed in the Makefile), the compile checks (C11, C++, nvcc, CMake,
# float warnings), the MPI example on 2 ranks (where mpicc and mpirun exist)
# and tests/check_tables.sh where it exists, and ends with one line
# "N passed, N failed" summing the cases of every program.
#
# Every (configuration, program) pair is one job: build, then run. The jobs
# go through one queue, longest first (the times of the previous run in
# build/test/times.tsv, or an estimate on a fresh tree), JOBS at a time
# (default: the number of cores). Before the closing line the script prints
# where the time went: per configuration, and the slowest builds and runs.
#
# Restrict a run (checking this script, or one change):
#   CONFIGS="gcc-double clang-float"   only these configurations ("none": no test builds)
#   TESTS="test_op_fused dam_break"    only these programs (tests in each configuration, examples)
#   EXTRAS=0                           no examples, compile checks or scripts
#   LIST=1                             print the jobs in queue order, run nothing
# A configuration whose compiler or feature is missing is skipped with a
# printed reason.
set -u
cd "$(dirname "$0")/.." || exit 2
TIER=${1:-test}
case $TIER in
test | check) ;;
*) echo "usage: tests/run.sh [test|check]" >&2; exit 2 ;;
esac
OUT=build/test
RES=$OUT/results
rm -rf "$RES" "$OUT/units"
mkdir -p "$OUT" "$RES" "$OUT/units"
JOBS=${JOBS:-$(nproc 2> /dev/null || echo 2)}
# the test build's warnings; the language mode comes from the configuration
# (-std=c99 unless its flags say +gnu)
WARN="-Wall -Wextra -pedantic -Wshadow -Werror -I."
# threads that wait sleep instead of spinning: the jobs share the cores
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}

# ---- configurations -------------------------------------------------------
# One line each. flags: words starting with + are the named sets of
# expand_flags below, the others go to the compiler as written (after
# -std=c99 -Wall -Wextra -pedantic -Werror). environment: NAME=value words for
# the runs. make test / make check: the programs, as globs of tests/*.c
# ("-": none); !name leaves a program out, name:flag adds a flag for it.
CONFIG_TABLE='
# name           | cc    | real   | flags                        | environment       | make test                  | make check
gcc-double       | gcc   | double | -O1 +san -DSPH_NO_DISPATCH   |                   | test_*                     | -
gcc-native       | gcc   | double | -O2 +native                  |                   | test_op_*                  | test_op_fused
gcc-float        | gcc   | float  | -O1 +san -DSPH_NO_DISPATCH   |                   | test_*                     | -
gcc-float-native | gcc   | float  | -O2 +native                  |                   | test_op_* test_neighbours  | -
gcc-avx2         | gcc   | double | -O2 +avx2 +omp -DSPH_NO_DISPATCH | OMP_NUM_THREADS=2 | test_op_* test_smoothing_length | -
gcc-float-avx2   | gcc   | float  | -O2 +avx2 -DSPH_NO_DISPATCH  |                   | test_op_* test_smoothing_length | -
gcc-omp          | gcc   | double | -O1 +omp -DSPH_NO_INTRINSICS | OMP_NUM_THREADS=2 | test_*                     | -
clang-double     | clang | double | -O0 +san +native             |                   | test_* test_neighbours:-O1 | test_* !test_op_fused test_neighbours:-O1
clang-float      | clang | float  | -O0 +san -DSPH_NO_DISPATCH   |                   | test_* !test_neighbours    | -
clang-omp        | clang | double | -O2 +omp                     | OMP_NUM_THREADS=2 | test_extremes test_op_dispatch test_op_fused test_op_omp test_op_reference test_pair_once | -
gcc-reference    | gcc   | double | -O1 -DSPH_OP_REFERENCE -DSPH_NO_DISPATCH |       | test_op_* !test_op_reference | -
gcc-nsearch-plain| gcc   | double | -O2 +native -DSPH_NSEARCH_PLAIN -DSPH_NO_DISPATCH | | test_neighbours test_box | -
gcc-gnu-native   | gcc   | double | -O2 +gnu +native +omp        | OMP_NUM_THREADS=2 | test_*                     | -
gcc-gnu-znver3   | gcc   | float  | -O2 +gnu -march=znver3 -DSPH_NO_DISPATCH |       | test_op_* test_pair_batch test_neighbours test_smoothing_length | -
clang-avx2       | clang | double | -O2 +avx2                    | SPH_TEST_ISA=avx2,avx512 | test_*                     | -
clang-float-avx2 | clang | float  | -O2 +avx2 -DSPH_NO_DISPATCH  |                   | test_op_* test_pair_batch test_smoothing_length | -
gcc-dispatch     | gcc   | double | -O2                          | SPH_TEST_ISA=portable,avx2,avx512 | test_* !test_neighbours | -
gcc-float-dispatch | gcc | float  | -O2                          | SPH_TEST_ISA=portable,avx2,avx512 | test_op_* test_pair_batch test_pair_once test_smoothing_length | -
gcc-gnu-dispatch | gcc   | double | -O2 +gnu +omp                | OMP_NUM_THREADS=2 SPH_TEST_ISA=avx2,avx512 | test_op_* test_pair_batch test_pair_once test_neighbours test_smoothing_length | -
clang-dispatch   | clang | double | -O2                          | SPH_TEST_ISA=portable,avx2,avx512 | test_op_* test_pair_batch test_pair_once test_neighbours test_smoothing_length | -
aarch64-gcc      | aarch64-linux-gnu-gcc | double | -O2 +gnu +aarch64 | | test_* !test_neighbours    | -
aarch64-clang    | clang | float  | -O2 +aarch64                 |                   | test_* !test_neighbours    | -
'
# make check: every test, sanitised, for the host CPU, but the fused pass
# (built by gcc -O2 instead: 39 s of CPU against 106 s); the header checks.
# What each is for:
#   gcc-double        the reference build, AddressSanitizer + UBSan; gcc -O1 for the
#                     warnings that need its flow analysis (-Wmaybe-uninitialized)
#   gcc-native        -march=native -O2 as make bench builds: the AVX-512 one-pass
#                     pair loops (on a CPU that has AVX-512) under the compiler that times them
#   gcc-float         float under the sanitizers
#   gcc-float-native  float's AVX-512 loops (float read, double arithmetic) and the
#                     neighbour check widening float positions
#   gcc-avx2          -march=x86-64-v3 (AVX2, what most users' CPUs have; make bench
#                     times it too): the chunked density and difference gradient, the
#                     AVX2 register loop of the h-solve density sums and the vector
#                     minimum image, with OpenMP's simd reductions, 2 threads
#   gcc-float-avx2    the same paths in float, without OpenMP (the chunked sums in
#                     list order)
#   gcc-omp           OpenMP with 2 threads, and the portable path (SPH_NO_INTRINSICS)
#   clang-double      the second compiler, sanitised, for the host CPU: the AVX-512
#                     paths under the sanitizers
#   clang-float       float under clang's sanitizers (the neighbour search in float
#                     under sanitizers: gcc-float)
#   clang-omp         clang -fopenmp -O2, where clang reports omp simd loops it could
#                     not vectorise (-Wpass-failed, an error under -Werror): the units
#                     that instantiate every operator loop (test_extremes,
#                     test_op_dispatch, test_op_fused, test_op_reference), and
#                     the OpenMP tests (operators, pair-once loops)
#   gcc-reference     the operator tests on the reference loops alone (SPH_OP_REFERENCE)
#   gcc-nsearch-plain the neighbour tests on the plain search alone (SPH_NSEARCH_PLAIN:
#                     one cell size, one radius kappa max(h_i, h_max)), at the host
#                     CPU's level
#   The builds users make (no -std, the compilers' default contraction of a * b + c
#   into FMA: docs/testing.md, "Floating-point contraction"):
#   gcc-gnu-native    gcc's GNU mode (-ffp-contract=fast) for the host CPU, OpenMP on 2 threads
#   gcc-gnu-znver3    the same on the AVX2 paths, in float, tuned as a Zen 3 user's
#                     -march=native (znver tuning fuses other sums than generic's)
#   clang-avx2        clang's default (-ffp-contract=on) with AVX2 and FMA, every test
#   clang-float-avx2  the same in float, the loops that promise bitwise equality
#   aarch64-gcc       aarch64-linux-gnu-gcc in GNU mode, run under qemu-aarch64 (every
#                     test but test_neighbours: 3 minutes of CPU under emulation)
#   aarch64-clang     clang --target=aarch64-linux-gnu (what Apple-silicon Macs compile
#                     with), float, under qemu-aarch64
# Where the time goes: the operator tests are minutes of compiling and seconds
# of running, and the sanitizers' instrumentation of the always-inlined
# operator loops is most of it (gcc -O1, tests/test_op_dispatch.c, CPU seconds:
# 3.0 plain, 6.1 ASan, 13.0 UBSan, 25.9 both). Hence: the programs of one
# header configuration compiled as one unit (see "units" below: make check's
# clang-double, ASan/UBSan -O0, 21 CPU s for its 29 programs instead of 205 s
# one by one); ASan checks through calls
# (the same checks, 15 % less for gcc, 30 % less for clang); clang's sanitised
# builds at -O0, where the sanitizers check the same accesses and the
# intrinsics paths are the same code (at -O1 they cost 4-5 times as much:
# test_op_dispatch 58 s against 13 s, test_op_fused 431 s against 106 s);
# test_neighbours is the opposite (a second to build, its O(N^2) reference
# lists run 4 times longer at -O0), hence its -O1; no -g (28 % of a gcc
# sanitised build; a failing job prints its command line, to rebuild with -g).

# Compile checks (one case each; C11 and the float-warning builds run for each
# compiler): the header alone, as C11 and C++11, under nvcc and as a CMake
# package. The float warnings -Wdouble-promotion -Wfloat-conversion are set
# here, on a unit with nothing but the header: the C front end checks every
# function body of the header whether or not it is called, and the tests
# compute their references in double from float values on purpose.
# (The variants that leave out or pin parts of the header build without the
# run-time passes, SPH_NO_DISPATCH: the passes compile the same text again,
# and the default variant compiles them.)
HEADER_VARIANTS=("" -march=native -DSPH_NO_INTRINSICS -DSPH_NO_DISPATCH_AVX512 "-DSPH_NO_DISPATCH -DSPH_OP_REFERENCE"
                 "-DSPH_NO_DISPATCH -DSPH_DIM=3 -DSPH_KERNEL=SPH_KERNEL_CUBIC" -DSPH_ONLY_KERNELS
                 "-DSPH_NO_DISPATCH -DSPH_ONLY_PAIRS" "-DSPH_NO_DISPATCH -DSPH_NO_OPERATORS"
                 "-DSPH_NO_DISPATCH -DSPH_NO_NSEARCH" "-DSPH_NO_DISPATCH -DSPH_NO_SOLVER"
                 "-DSPH_NO_DISPATCH -DSPH_NO_SMOOTHING_LENGTH")
FLOAT_WARN="-Wdouble-promotion -Wfloat-conversion"
# The C++ check, unoptimised and as users build for their own CPU: g++
# reports at -O2 and -O3 (-Wmaybe-uninitialized) what it finds in the
# intrinsics the AVX-512 loops inline; -O3 in make test only.
CXX_WARN="$FLOAT_WARN -Wcast-qual"
CXX_OPTS=("" "-O2 -march=native")

trim() { # trim "text": without leading and trailing blanks
    local s=$1
    s=${s#"${s%%[![:space:]]*}"}
    printf '%s' "${s%"${s##*[![:space:]]}"}"
}

declare -A PROBED
probe() { # probe key command...: 0 when the command succeeds (cached per key)
    local key=$1
    shift
    if [ -z "${PROBED[$key]:-}" ]; then
        if "$@" > /dev/null 2>&1; then PROBED[$key]=yes; else PROBED[$key]=no; fi
    fi
    [ "${PROBED[$key]}" = yes ]
}

builds_and_runs() { # builds_and_runs cc flags...: a trivial program builds and runs (under $PROBE_RUNNER)
    local cc=$1 tag
    shift
    tag=$(printf '%s' "$cc $*" | tr -c 'A-Za-z0-9' _)
    printf '#include <stdio.h>\nint main(void){return 0;}\n' > "$OUT/probe_$tag.c"
    # shellcheck disable=SC2086 # the runner is words
    "$cc" "$@" "$OUT/probe_$tag.c" -o "$OUT/probe_$tag" && ${PROBE_RUNNER:-} "$OUT/probe_$tag"
}

openmp_runs() { # openmp_runs cc
    printf '#include <omp.h>\nint main(void){return omp_get_max_threads() > 0 ? 0 : 1;}\n' > "$OUT/probe_omp_$1.c"
    "$1" -fopenmp "$OUT/probe_omp_$1.c" -o "$OUT/probe_omp_$1" && "$OUT/probe_omp_$1"
}

# The cross sysroot and emulator of the aarch64 configurations (Debian's
# gcc-aarch64-linux-gnu and qemu-user, which .ci/run installs).
AARCH64_RUNNER="qemu-aarch64 -L /usr/aarch64-linux-gnu"

# expand_flags cc words...: EXPANDED = the compiler flags of the flags column
# (-std=c99 first, unless +gnu), RUNNER = what runs the programs (empty:
# natively); returns 1 with REASON set when the configuration cannot be built
# here, and adds to NOTES what is built without
expand_flags() {
    local cc=$1 w std=-std=c99
    shift
    EXPANDED="" REASON="" NOTES="" RUNNER=""
    for w in "$@"; do
        case $w in
        +gnu) std="" ;; # the compiler's default mode (gnu17): gcc contracts a*b + c into FMA across statements
        +aarch64)
            # cross-compiled for aarch64 (clang: --target), run under qemu-aarch64
            command -v qemu-aarch64 > /dev/null 2>&1 || { REASON="qemu-aarch64 is not installed (Debian: qemu-user)"; return 1; }
            case $cc in clang*) EXPANDED="$EXPANDED --target=aarch64-linux-gnu" ;; esac
            # shellcheck disable=SC2086 # the target flag is words
            PROBE_RUNNER=$AARCH64_RUNNER probe "$cc aarch64" builds_and_runs "$cc" $EXPANDED ||
                { REASON="$cc does not build for aarch64 here, or qemu-aarch64 does not run it (Debian: gcc-aarch64-linux-gnu)"; return 1; }
            RUNNER=$AARCH64_RUNNER
            ;;
        esac
    done
    for w in "$@"; do
        case $w in
        +gnu | +aarch64) ;;
        +san)
            # ASan checks through calls rather than inline code: the same
            # checks, a third less to compile in the operator loops
            case $cc in
            clang*) w="-mllvm -asan-instrumentation-with-call-threshold=0" ;;
            *) w="--param asan-instrumentation-with-call-threshold=0" ;;
            esac
            # shellcheck disable=SC2086 # w is words
            if probe "$cc san" builds_and_runs "$cc" -fsanitize=address,undefined $w; then
                EXPANDED="$EXPANDED -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer $w"
            elif probe "$cc san0" builds_and_runs "$cc" -fsanitize=address,undefined; then
                EXPANDED="$EXPANDED -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
            else
                NOTES="$NOTES; $cc has no address/undefined sanitizers here, built without them"
            fi
            ;;
        +native)
            probe "$cc native" builds_and_runs "$cc" -march=native || { REASON="$cc -march=native does not build here"; return 1; }
            EXPANDED="$EXPANDED -march=native"
            ;;
        +avx2)
            probe "$cc avx2" builds_and_runs "$cc" -march=x86-64-v3 || { REASON="$cc -march=x86-64-v3 does not build or run here"; return 1; }
            EXPANDED="$EXPANDED -march=x86-64-v3"
            ;;
        -march=*)
            probe "$cc $w" builds_and_runs "$cc" "$w" || { REASON="$cc $w does not build or run here"; return 1; }
            EXPANDED="$EXPANDED $w"
            ;;
        +omp)
            probe "$cc omp" openmp_runs "$cc" || { REASON="$cc -fopenmp does not build here"; return 1; }
            EXPANDED="$EXPANDED -fopenmp"
            ;;
        +*) REASON="unknown flag set $w"; return 1 ;;
        *) EXPANDED="$EXPANDED $w" ;;
        esac
    done
    EXPANDED=$(trim "$std $EXPANDED")
}

# ---- the jobs ----------------------------------------------------------------
# Each job writes RES/<id>.res: group|label|passed|failed|build "wall cpu"|run "wall cpu"
# (seconds; cpu = user + system of the job and its children), and RES/<id>.txt:
# the lines to print under its group.

now() { printf '%s' "${EPOCHREALTIME/,/.}"; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.1f", b - a}'; }

# timed out command...: runs the command, its output into the file out and
# "wall cpu" seconds into out.time; returns the command's status
timed() {
    local out=$1 status TIMEFORMAT='%R %U %S'
    shift
    { time "$@" > "$out" 2>&1; } 2> "$out.time"
    status=$?
    awk 'END {printf "%.1f %.1f\n", $1, $2 + $3}' "$out.time" > "$out.t" && mv "$out.t" "$out.time"
    return $status
}

# summary out: "passed failed" from the program's closing line, or nothing
summary() {
    local line
    line=$(grep -E '^[0-9]+ passed, [0-9]+ failed$' "$1" | tail -n 1)
    [ -n "$line" ] && echo "${line%% passed*} $(echo "${line#*passed, }" | cut -d' ' -f1)"
}

# build bin "command": compiles (output into bin.build, seconds into
# bin.build.time, the command into bin.cmd); returns the compiler's status
build() {
    echo "$2" > "$1.cmd"
    # shellcheck disable=SC2086 # the command is words
    timed "$1.build" $2
}

# build_failed id group label bin: report a failed build (one failed case)
build_failed() {
    {
        echo "  $3: BUILD FAILED"
        sed 's/^/    | /' "$4.build" | head -n 30
        echo "    built by: $(cat "$4.cmd")"
    } > "$RES/$1.txt"
    echo "$2|$3|0|1|$(cat "$4.build.time")|0 0" > "$RES/$1.res"
}

# run_report id group label how bin "build seconds" "env words" args...: run a
# built program with the environment and arguments (its output into
# RES/<id>.out) and report it. how: "cases" (the program's closing line N
# passed, N failed) or "one" (one case, its exit status)
run_report() {
    local id=$1 group=$2 label=$3 how=$4 bin=$5 btime=$6 envs=$7 status p f out=$RES/$1.out
    shift 7
    # shellcheck disable=SC2086 # envs are NAME=value words, the runner is words
    timed "$out" env $envs timeout 900 ${RUNNERS[$group]:-} "$bin" "$@"
    status=$?
    {
        if [ "$how" = one ]; then
            p=$((status == 0)) f=$((status != 0))
            if [ "$f" -eq 0 ]; then echo "  $label: ok"; else echo "  $label: FAILED (exit $status)"; fi
            [ "$f" -eq 0 ] || sed 's/^/    | /' "$out" | tail -n 30
        elif read -r p f < <(summary "$out"); then
            if [ "$status" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
            grep -E '^(FAIL|    )' "$out" | head -n 40
            echo "  $label: $p passed, $f failed"
        else
            p=0 f=1
            echo "  $label: no summary line (exit $status) - counted as 1 failed"
            sed 's/^/    | /' "$out" | tail -n 20
        fi
        # a failure says how to rebuild and rerun it (add -g for the sanitizers' line numbers)
        [ "$f" -eq 0 ] || echo "    built by: $(cat "$bin.cmd"); run: ${envs:+$envs }${RUNNERS[$group]:+${RUNNERS[$group]} }$bin $*"
        echo "$group|$label|$p|$f|$btime|$(cat "$out.time")" > "$RES/$id.res"
    } > "$RES/$id.txt"
}

# The instruction-set levels of the fast loops this CPU runs (sph_isa_set's
# names; /proc/cpuinfo's flags for the features each run-time pass needs).
CPU_ISAS=portable
if grep -qw avx2 /proc/cpuinfo 2> /dev/null && grep -qw fma /proc/cpuinfo && grep -qw bmi2 /proc/cpuinfo; then
    CPU_ISAS="$CPU_ISAS avx2"
    for f in avx512f avx512vl avx512bw avx512dq avx512cd; do grep -qw $f /proc/cpuinfo || f=; [ -n "$f" ] || break; done
    [ -n "$f" ] && CPU_ISAS="$CPU_ISAS avx512"
fi
# isa_runs "env words": the levels to run each program at, from the
# configuration's SPH_TEST_ISA=a,b,... (those this CPU has), else "-": one
# run at the level the program chooses
isa_runs() {
    local w l out=""
    for w in $1; do
        case $w in SPH_TEST_ISA=*)
            for l in $(echo "${w#SPH_TEST_ISA=}" | tr , ' '); do
                case " $CPU_ISAS " in *" $l "*) out="$out $l" ;; esac
            done
            echo "${out:- none}"
            return ;;
        esac
    done
    echo -
}
# run_isas id cfg label bin "build seconds" "env words" args...: run_report once
# per level of isa_runs (ids id@level, SPH_TEST_ISA=level), or once
run_isas() {
    local id=$1 cfg=$2 label=$3 bin=$4 btime=$5 envs=$6 l plain="" w
    shift 6
    for w in $envs; do case $w in SPH_TEST_ISA=*) ;; *) plain="$plain $w" ;; esac; done
    for l in $(isa_runs "$envs"); do
        if [ "$l" = - ]; then
            run_report "$id" "$cfg" "$label" cases "$bin" "$btime" "$envs" "$@"
        elif [ "$l" != none ]; then
            run_report "$id@$l" "$cfg" "$label @$l" cases "$bin" "$btime" "${plain# } SPH_TEST_ISA=$l" "$@"
        fi
    done
}
# ids id "env words": the result ids of one program (one per level of isa_runs)
ids() {
    local l
    for l in $(isa_runs "$2"); do
        case $l in -) echo "$1" ;; none) ;; *) echo "$1@$l" ;; esac
    done
}

# test_job id config cc real "flags" "env" source: one test program
test_job() {
    local id=$1 cfg=$2 cc=$3 real=$4 flags=$5 envs=$6 src=$7 bin name
    name=$(basename "$src" .c)
    mkdir -p "$OUT/$cfg"
    bin=$OUT/$cfg/$name
    if build "$bin" "$cc $WARN $flags -DSPH_REAL=$real $src -o $bin -lm"; then
        run_isas "$id" "$cfg" "$cfg $name" "$bin" "$(cat "$bin.build.time")" "$envs"
    else
        build_failed "$id" "$cfg" "$cfg $name" "$bin"
    fi
}

# unit_job id config cc real "flags" "env" unit-source programs...: the test
# programs of one unit (see "Units" below) built once and run one by one. A
# failed build of the unit is one failed case with the compiler's error, and
# each of its programs is reported as not run (one failed case each).
unit_job() {
    local id=$1 cfg=$2 cc=$3 real=$4 flags=$5 envs=$6 src=$7 bin t
    shift 7
    mkdir -p "$OUT/$cfg"
    bin=$OUT/$cfg/$(basename "$src" .c)
    if build "$bin" "$cc $WARN $flags -DSPH_REAL=$real $src -o $bin -lm"; then
        : > "$RES/$id.txt"
        echo "$cfg|$cfg $*|0|0|$(cat "$bin.build.time")|0 0" > "$RES/$id.res"
        for t in "$@"; do
            run_isas "${cfg}_$t" "$cfg" "$cfg $t" "$bin" "0 0" "$envs" "$t"
        done
    else
        build_failed "$id" "$cfg" "$cfg $(basename "$src" .c) (one build of $*)" "$bin"
        for t in "$@"; do
            for i in $(ids "${cfg}_$t" "$envs"); do
                echo "  $cfg $t: NOT RUN (the unit's build failed)" > "$RES/$i.txt"
                echo "$cfg|$cfg $t|0|1|0 0|0 0" > "$RES/$i.res"
            done
        done
    fi
}

# example_job id source args...: an example or study in its --check mode, built
# as the Makefile builds it (gcc -O2, OpenMP where gcc has it); one case. All
# but examples/sod_shock.c (whose own force loop is compiled per instruction
# set, sd_rows) build without the run-time passes (SPH_NO_DISPATCH): the
# --check runs validate the physics, the test programs run every level, and
# the passes would double the examples' build time
example_job() {
    local id=$1 src=$2 bin omp="" nd=-DSPH_NO_DISPATCH
    shift 2
    mkdir -p "$OUT/examples"
    bin=$OUT/examples/$(basename "$src" .c)
    if probe "gcc omp" openmp_runs gcc; then omp=-fopenmp; fi
    case $src in *sod_shock.c) nd= ;; esac
    if build "$bin" "gcc -O2 -std=c99 -Wall -Wextra -pedantic -Wshadow -Werror $omp $nd -I. $src -o $bin -lm"; then
        run_report "$id" examples "$src $*" one "$bin" "$(cat "$bin.build.time")" "" "$@"
    else
        build_failed "$id" examples "$src $*" "$bin"
    fi
}

# check_job id label command...: a compile check or a script, one case
check_job() {
    local id=$1 label=$2
    shift 2
    if timed "$RES/$id.log" "$@"; then
        echo "  $label: ok" > "$RES/$id.txt"
        echo "checks|$label|1|0|$(cat "$RES/$id.log.time")|0 0" > "$RES/$id.res"
    else
        {
            echo "  $label: FAILED"
            sed 's/^/    | /' "$RES/$id.log" | head -n 30
        } > "$RES/$id.txt"
        echo "checks|$label|0|1|$(cat "$RES/$id.log.time")|0 0" > "$RES/$id.res"
    fi
}

# header_check cc: the header alone (tests/compile_check.c) as C11, double
# and float, in every variant of HEADER_VARIANTS, with the float warnings;
# built and run. In float not the variants that only leave text out (a
# section, the AVX-512 pass): the float warnings concern the text, which the
# full header's float build compiles.
header_check() {
    local cc=$1 real i bin
    for real in double float; do
        for i in "${!HEADER_VARIANTS[@]}"; do
            case $real:${HEADER_VARIANTS[$i]} in
            *-march=native) probe "$cc native" builds_and_runs "$cc" -march=native || continue ;;
            float:*ONLY_KERNELS* | float:*ONLY_PAIRS* | float:*NO_NSEARCH* | float:*NO_SOLVER* | \
                float:*NO_SMOOTHING_LENGTH* | float:*NO_DISPATCH_AVX512*) continue ;;
            esac
            bin=$OUT/c11_check_${cc}_${real}_$i
            echo "== $cc -std=c11 -DSPH_REAL=$real ${HEADER_VARIANTS[$i]}"
            # shellcheck disable=SC2086 # the variant's flags are words
            $cc -std=c11 -Wall -Wextra -pedantic -Wshadow -Werror $FLOAT_WARN ${HEADER_VARIANTS[$i]} -DSPH_REAL="$real" -I. \
                tests/compile_check.c -o "$bin" -lm && "$bin" || return 1
        done
    done
}

# shellcheck disable=SC2086 # FLOAT_WARN and the options are words
cxx_check() { # cxx_check real [options]: tests/compile_check.cpp (the operators' loops) with g++ -std=c++11
    local opts=${2:-} bin
    bin=$OUT/cpp_check_$1$(printf '%s' "$opts" | tr -c 'A-Za-z0-9' _)
    g++ -std=c++11 $opts -Wall -Wextra -pedantic -Wshadow -Werror $CXX_WARN -DSPH_REAL="$1" -I. tests/compile_check.cpp \
        -o "$bin" && "$bin"
}

# ---- the queue -----------------------------------------------------------------
# QUEUE lines: estimate, id, group, kind, args..., separated by SEP (not a
# blank: read keeps the empty fields)
QUEUE=$OUT/queue
IDS=$OUT/ids # group and id of every result, in the order they are printed
: > "$QUEUE"
: > "$IDS"
GROUPS_ORDER=""
SEP=$'\x1f'
declare -A PREV
if [ -f "$OUT/times.tsv" ]; then
    while IFS=$'\t' read -r id _ b _ r; do PREV[$id]=$(awk -v b="$b" -v r="$r" 'BEGIN {printf "%d", (b + r) * 10}'); done < "$OUT/times.tsv"
fi

# estimate id guess: tenths of a CPU second the job took last time, else the guess
estimate() { echo "${PREV[$1]:-$2}"; }

# guess for a test program on a fresh tree: programs that run the array
# operators compile for minutes, the neighbour tests run long under the
# sanitizers, the kernel tests take seconds
test_guess() { # test_guess source flags
    local g=30
    if grep -qE '#include "(op_scene|xo_ops|fuzz_body)\.h"|sph_(density|interpolate|shepard|gradient|density_gradient|velocity_gradient|divergence|curl|laplacian|diffusion|correction_matrix)\(' "$1"; then g=1000
    elif grep -q 'sph_nsearch' "$1"; then g=400; fi
    case " $2 " in *" -fsanitize="*) g=$((g * 2)) ;; esac
    echo "$g"
}

enqueue() { # enqueue estimate id group kind args...: one job with one result
    local est=$1 id=$2 group=$3 kind=$4 args=""
    shift 4
    local a
    for a in "$@"; do args="$args$SEP$a"; done
    printf '%s\n' "$est$SEP$id$SEP$group$SEP$kind$args" >> "$QUEUE"
    case $kind in
    unit) ;;
    test) for a in $(ids "$id" "$5"); do printf '%s\n' "$group$SEP$a" >> "$IDS"; done ;;
    *) printf '%s\n' "$group$SEP$id" >> "$IDS" ;;
    esac
    case " $GROUPS_ORDER " in *" $group "*) ;; *) GROUPS_ORDER="$GROUPS_ORDER $group" ;; esac
}

# ---- units ------------------------------------------------------------------------
# The test programs of a configuration that configure the header alike (the
# same #define lines before their first #include "...") are compiled as one
# unit: the header's operators, most of a build, are compiled once instead
# of once per program. Each program's main becomes <program>_main, each of
# its macros is #undef'd after it, and the unit runs one program per process,
# by name. File-scope names must therefore differ between the test programs,
# and a program that needs a feature macro (_POSIX_C_SOURCE) defines it
# itself before its first #include: that makes its signature differ, so it is
# built in a unit of its own whose system headers all see the macro. (Moving
# every program's feature macros to the top of a shared unit would instead
# change what the other programs see of the system headers.) A unit that
# does not build fails the run (see unit_job).

signature() { # signature source: the #define lines before the first #include "..."
    awk '/^[ \t]*#[ \t]*include[ \t]*"/ {exit} /^[ \t]*#[ \t]*define/ {sub(/\/\*.*$/, ""); gsub(/[ \t]+/, " "); sub(/ $/, ""); print}' "$1"
}

# write_unit file programs...: the source of a unit of test programs
write_unit() {
    local file=$1 t
    shift
    {
        echo "/* Written by tests/run.sh: the test programs $* in one unit."
        echo " * Run as: <unit> <program> [arguments]. */"
        for t in "$@"; do
            echo "#define main ${t}_main"
            echo "#include \"tests/$t.c\""
            echo "#undef main"
            sed -n 's/^[ \t]*#[ \t]*define[ \t]\{1,\}\([A-Za-z_][A-Za-z0-9_]*\).*/#undef \1/p' "tests/$t.c" | sort -u
        done
        echo "#include <stdio.h>"
        echo "#include <string.h>"
        echo "int main(int argc, char **argv)"
        echo "{"
        for t in "$@"; do
            if grep -qE 'int main\((void)?\)' "tests/$t.c"; then
                echo "    if (argc == 2 && strcmp(argv[1], \"$t\") == 0) return ${t}_main();"
            else
                echo "    if (argc >= 2 && strcmp(argv[1], \"$t\") == 0) return ${t}_main(argc - 1, argv + 1);"
            fi
        done
        printf '    fprintf(stderr, "usage: %%s program [arguments]: %s\\n", argv[0]);\n' "$*"
        echo "    return 2;"
        echo "}"
    } > "$file"
}

# enqueue_programs config cc real flags envs programs...: the jobs of one
# configuration; programs are source[:extra flags] (extra flags: built alone)
enqueue_programs() {
    local cfg=$1 cc=$2 real=$3 flags=$4 envs=$5 p t src slug key est guess
    shift 5
    local -A members=()
    local order=""
    for p in "$@"; do
        src=${p%%:*}
        t=$(basename "$src" .c)
        if [ "$p" != "$src" ]; then
            enqueue "$(estimate "$cfg/$t" "$(test_guess "$src" "$flags")")" "$cfg/$t" "$cfg" test \
                "$cfg" "$cc" "$real" "$flags ${p#*:}" "$envs" "$src"
            continue
        fi
        key=k$(signature "$src" | sed 's/^#define //' | tr -c 'A-Za-z0-9\n' _ | tr '\n' _)
        [ -n "${members[$key]:-}" ] || order="$order $key"
        members[$key]="${members[$key]:-} $t"
    done
    for key in $order; do
        # shellcheck disable=SC2086 # the member list is words
        set -- ${members[$key]}
        key=${key#k}
        if [ $# -eq 1 ]; then
            enqueue "$(estimate "$cfg/$1" "$(test_guess "tests/$1.c" "$flags")")" "$cfg/$1" "$cfg" test \
                "$cfg" "$cc" "$real" "$flags" "$envs" "tests/$1.c"
            continue
        fi
        slug=unit_${key%_}
        [ -n "$key" ] || slug=unit_default
        # one file per configuration: configurations list different programs
        mkdir -p "$OUT/units/$cfg" && write_unit "$OUT/units/$cfg/$slug.c" "$@"
        # estimate: the last run's build and runs, else the largest program's guess
        est=$(estimate "$cfg/$slug" 0) guess=0
        for t in "$@"; do
            est=$((est + $(estimate "$cfg/$t" 0)))
            g=$(test_guess "tests/$t.c" "$flags")
            [ "$g" -gt "$guess" ] && guess=$g
        done
        [ "$est" -gt 0 ] || est=$((guess * 3 / 2))
        printf '%s\n' "$cfg$SEP$cfg/$slug" >> "$IDS"
        for t in "$@"; do ids "$cfg/$t" "$envs" | sed "s|^|$cfg$SEP|" >> "$IDS"; done
        enqueue "$est" "$cfg/$slug" "$cfg" unit "$cfg" "$cc" "$real" "$flags" "$envs" "$OUT/units/$cfg/$slug.c" "$@"
    done
}

declare -A TITLE RUNNERS
wanted() { # wanted name list: name is in the space-separated list (empty list: all)
    [ -z "$2" ] && return 0
    case " $2 " in *" $1 "*) return 0 ;; esac
    return 1
}

while IFS='|' read -r name cc real flags envs test_progs check_progs; do
    name=$(trim "$name")
    case $name in '' | '#'*) continue ;; esac
    cc=$(trim "$cc") real=$(trim "$real") flags=$(trim "$flags") envs=$(trim "$envs")
    if [ "$TIER" = test ]; then progs=$(trim "$test_progs"); else progs=$(trim "$check_progs"); fi
    [ "$progs" = - ] && continue
    [ "${CONFIGS:-}" = none ] && continue
    wanted "$name" "${CONFIGS:-}" || continue
    if ! command -v "$cc" > /dev/null 2>&1; then
        echo "SKIPPED: $name ($cc is not installed)"
        continue
    fi
    # shellcheck disable=SC2086 # flags are words
    if ! expand_flags "$cc" $flags; then
        echo "SKIPPED: $name ($REASON)"
        continue
    fi
    [ -n "$NOTES" ] && echo "note: $name$NOTES"
    RUNNERS[$name]=$RUNNER
    TITLE[$name]="== $name: $cc $real $EXPANDED${envs:+ ($envs)}${RUNNER:+, run by $RUNNER}"
    # the programs: globs, then !name (left out) and name:flag (added flag)
    declare -A extra=()
    skip=" "
    for w in $progs; do
        case $w in
        !*) skip="$skip${w#!} " ;;
        *:*) extra[${w%%:*}]="${extra[${w%%:*}]:-} ${w#*:}" ;;
        esac
    done
    list=()
    for w in $progs; do
        case $w in !* | *:*) continue ;; esac
        for src in tests/$w.c; do
            [ -e "$src" ] || continue
            t=$(basename "$src" .c)
            case $skip in *" $t "*) continue ;; esac
            skip="$skip$t " # once, however many globs match it
            wanted "$t" "${TESTS:-}" || continue
            list+=("$src${extra[$t]:+:${extra[$t]# }}")
        done
    done
    unset extra
    [ ${#list[@]} -gt 0 ] && enqueue_programs "$name" "$cc" "$real" "$EXPANDED" "$envs" "${list[@]}"
done <<< "$CONFIG_TABLE"

if [ "${EXTRAS:-1}" != 0 ]; then
    TITLE[examples]="== examples and studies (--check: a short coarse run that fails when it misses its validation bounds)"
    TITLE[checks]="== compile checks and scripts"
    if [ "$TIER" = test ]; then
        # the Makefile lists the programs with a --check mode and their arguments
        while read -r src args; do
            [ -n "$src" ] || continue
            n=$(basename "$src" .c)
            wanted "$n" "${TESTS:-}" || continue
            # shellcheck disable=SC2086 # args are words
            enqueue "$(estimate "examples/$n" 600)" "examples/$n" examples example "$src" $args
        done < <(make -s --no-print-directory print-check-examples)
    fi
    for cc in gcc clang; do
        if command -v $cc > /dev/null 2>&1; then
            enqueue "$(estimate "checks/c11-$cc" 100)" "checks/c11-$cc" checks check \
                "C11 ($cc -std=c11; double and float; generic, -march=native, SPH_NO_INTRINSICS, pinned; $FLOAT_WARN)" \
                header_check $cc
        else
            echo "SKIPPED: C11 check with $cc ($cc is not installed)"
        fi
    done
    if command -v g++ > /dev/null 2>&1; then
        [ "$TIER" = test ] && CXX_OPTS+=("-O3 -march=native")
        for real in double float; do
            for opts in "${CXX_OPTS[@]}"; do
                case $opts in *-march=native*) probe "g++ native" builds_and_runs g++ -march=native -x c++ || continue ;; esac
                n=cxx-$real$(printf '%s' "${opts:+ $opts}" | tr -d - | tr -c 'A-Za-z0-9' -)
                enqueue "$(estimate "checks/$n" 100)" "checks/$n" checks check \
                    "C++11 $real (g++ -std=c++11${opts:+ $opts} -Wall -Wextra -pedantic -Wshadow -Werror $CXX_WARN)" \
                    cxx_check $real "$opts"
            done
        done
    else
        echo "SKIPPED: C++ compile check (g++ is not installed)"
    fi
    if [ "$TIER" = test ]; then
        if command -v nvcc > /dev/null 2>&1; then
            enqueue "$(estimate checks/nvcc 300)" checks/nvcc checks check "CUDA (nvcc, host and device code)" \
                nvcc -std=c++11 -Werror all-warnings -I. -c tests/compile_check.cu -o "$OUT/cu_check.o"
        else
            echo "SKIPPED: nvcc compile check (nvcc is not on the PATH)"
        fi
        # the timed build of make bench (-O3, where gcc's flow warnings differ from -O2's)
        if probe "gcc omp" openmp_runs gcc; then
            enqueue "$(estimate checks/bench 200)" checks/bench checks check \
                "make bench's build (gcc -O3 -march=native -fopenmp -std=c99 $WARN bench/benchmark.c)" \
                gcc -O3 -march=native -fopenmp -std=c99 $WARN -DBENCH_LINK_PARTS -c bench/benchmark.c -o "$OUT/bench_check.o"
        else
            echo "SKIPPED: make bench's build (gcc -fopenmp does not build here)"
        fi
        if command -v cmake > /dev/null 2>&1; then
            enqueue "$(estimate checks/cmake 200)" checks/cmake checks check \
                "CMake target sph_kernel::sph_kernel (add_subdirectory and installed find_package)" sh tests/cmake_check.sh
        else
            echo "SKIPPED: CMake check (cmake is not installed)"
        fi
        # the MPI example on 2 ranks: bitwise the single-process run and taylor_green.c's frames
        if command -v mpicc > /dev/null 2>&1 && command -v mpirun > /dev/null 2>&1; then
            enqueue "$(estimate checks/mpi 300)" checks/mpi checks check \
                "MPI: examples/mpi_taylor_green.c on 2 ranks, bitwise equal to one process and to taylor_green.c (tests/mpi_check.sh)" \
                sh tests/mpi_check.sh
        else
            echo "SKIPPED: MPI check (mpicc or mpirun is not on the PATH; Debian/Ubuntu: apt-get install openmpi-bin libopenmpi-dev)"
        fi
    fi
    # other checks that are scripts: one case each (they print their own SKIPPED)
    for s in tests/check_*.sh; do
        [ -e "$s" ] || continue
        n=$(basename "$s" .sh)
        enqueue "$(estimate "checks/$n" 100)" "checks/$n" checks check "$s" bash "$s"
    done
fi

run_job() { # run_job id kind args...
    local id=$1 kind=$2
    shift 2
    case $kind in
    test) test_job "$id" "$@" ;;
    unit) unit_job "$id" "$@" ;;
    example) example_job "$id" "$@" ;;
    check) check_job "$id" "$@" ;;
    esac
}

if [ "${LIST:-0}" != 0 ]; then
    sort -t "$SEP" -k1,1nr "$QUEUE" | tr "$SEP" '|'
    exit 0
fi

START=$(now)
LOAD0=$(cut -d' ' -f1-3 /proc/loadavg 2> /dev/null)
echo "running $(wc -l < "$QUEUE") jobs, $JOBS at a time, longest first (tier $TIER; load average $LOAD0)"
running=0
while IFS=$SEP read -r -a job; do
    if [ "$running" -ge "$JOBS" ]; then
        wait -n
        running=$((running - 1))
    fi
    id=${job[1]}
    run_job "${id//\//_}" "${job[@]:3}" < /dev/null &
    running=$((running + 1))
done < <(sort -t "$SEP" -k1,1nr "$QUEUE")
wait
END=$(now)

# ---- results, in table order -----------------------------------------------------
TOTAL_PASS=0
TOTAL_FAIL=0
: > "$OUT/times.new"
for group in $GROUPS_ORDER; do
    echo "${TITLE[$group]}"
    while IFS=$SEP read -r g id; do
        [ "$g" = "$group" ] || continue
        f=$RES/${id//\//_}
        if [ ! -f "$f.res" ]; then
            echo "  $id: did not finish - counted as 1 failed"
            TOTAL_FAIL=$((TOTAL_FAIL + 1))
            continue
        fi
        cat "$f.txt"
        IFS='|' read -r _ _ p fl b r < "$f.res"
        TOTAL_PASS=$((TOTAL_PASS + p))
        TOTAL_FAIL=$((TOTAL_FAIL + fl))
        printf '%s\t%s\t%s\t%s\t%s\n' "$id" "${b% *}" "${b#* }" "${r% *}" "${r#* }" >> "$OUT/times.new"
    done < "$IDS"
done
mv "$OUT/times.new" "$OUT/times.tsv"

# ---- where the time went ------------------------------------------------------------
# times.tsv: id, build wall, build cpu, run wall, run cpu (seconds). CPU seconds
# (user + system) hardly move with other load on the machine; wall seconds do.
echo "== time: $(secs "$START" "$END") s wall, $JOBS jobs at a time; load average $LOAD0 at the start, $(cut -d' ' -f1-3 /proc/loadavg 2> /dev/null) at the end"
awk -F'\t' '
    { split($1, k, "/"); g = k[1]; n[g] += (k[2] !~ /^unit_/); bw[g] += $2; bc[g] += $3; rw[g] += $4; rc[g] += $5
      if (!(g in seen)) { seen[g] = 1; order[++m] = g } }
    END {
        printf "  %-18s %4s %11s %9s %12s %10s\n", "configuration", "runs", "build cpu s", "run cpu s", "build wall s", "run wall s"
        for (i = 1; i <= m; ++i) {
            g = order[i]
            printf "  %-18s %4d %11.1f %9.1f %12.1f %10.1f\n", g, n[g], bc[g], rc[g], bw[g], rw[g]
            N += n[g]; BC += bc[g]; RC += rc[g]; BW += bw[g]; RW += rw[g]
        }
        printf "  %-18s %4d %11.1f %9.1f %12.1f %10.1f\n", "all", N, BC, RC, BW, RW
    }' "$OUT/times.tsv"
echo "  slowest builds (cpu s, wall s):"
sort -t "$(printf '\t')" -k3,3nr "$OUT/times.tsv" | head -n 10 | awk -F'\t' '{printf "  %8.1f %8.1f  %s\n", $3, $2, $1}'
echo "  slowest runs (cpu s, wall s):"
sort -t "$(printf '\t')" -k5,5nr "$OUT/times.tsv" | head -n 5 | awk -F'\t' '{printf "  %8.1f %8.1f  %s\n", $5, $4, $1}'

echo "$TOTAL_PASS passed, $TOTAL_FAIL failed"
[ "$TOTAL_FAIL" -eq 0 ]
