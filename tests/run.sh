#!/bin/bash
# tests/run.sh - `make test`: builds every tests/test_*.c in every configuration
# (gcc and clang x double and float, sanitizers where the compiler has them,
# plus OpenMP builds), runs them, runs the compile checks (C++, nvcc, CMake)
# and prints one closing line "N passed, N failed" with the sum of all cases.
# A configuration whose compiler is missing is skipped with a printed reason.
set -u
cd "$(dirname "$0")/.." || exit 2
OUT=build/test
mkdir -p "$OUT"
WARN="-std=c99 -Wall -Wextra -pedantic -Werror -I."
OPT="-O1 -g"
TOTAL_PASS=0
TOTAL_FAIL=0
LOG="$OUT/run.log"
: > "$LOG"

count() { # count "label" exit-status output-file
    line=$(grep -E '^[0-9]+ passed, [0-9]+ failed$' "$3" | tail -n 1)
    if [ -z "$line" ]; then
        echo "  $1: no summary line (exit $2) - counted as 1 failed"
        sed 's/^/    | /' "$3" | tail -n 20
        TOTAL_FAIL=$((TOTAL_FAIL + 1))
        return
    fi
    p=${line%% passed*}
    f=${line#*passed, }
    f=${f%% failed*}
    if [ "$2" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
    TOTAL_PASS=$((TOTAL_PASS + p))
    TOTAL_FAIL=$((TOTAL_FAIL + f))
    grep -E '^(FAIL|    )' "$3" | head -n 40
    echo "  $1: $p passed, $f failed"
}

check() { # check "label" command...: a compile check counted as one case
    label=$1
    shift
    if "$@" > "$OUT/check.out" 2>&1; then
        TOTAL_PASS=$((TOTAL_PASS + 1))
        echo "  $label: ok"
    else
        TOTAL_FAIL=$((TOTAL_FAIL + 1))
        echo "  $label: FAILED"
        sed 's/^/    | /' "$OUT/check.out" | head -n 30
    fi
}

has_flag() { # has_flag cc flag: the compiler accepts flag and the program runs
    printf 'int main(void){return 0;}\n' > "$OUT/flag.c"
    "$1" "$2" "$OUT/flag.c" -o "$OUT/flag" > /dev/null 2>&1 && "$OUT/flag" > /dev/null 2>&1
}

has_openmp() {
    printf '#include <omp.h>\nint main(void){return omp_get_max_threads() > 0 ? 0 : 1;}\n' > "$OUT/omp.c"
    "$1" -fopenmp "$OUT/omp.c" -o "$OUT/omp" > /dev/null 2>&1 && "$OUT/omp" > /dev/null 2>&1
}

run_config() { # run_config cc precision extra-flags label [sources]
    cc=$1 prec=$2 extra=$3 label=$4 sources=${5:-tests/test_*.c}
    dir="$OUT/$label"
    mkdir -p "$dir"
    for src in $sources; do
        [ -e "$src" ] || continue
        name=$(basename "$src" .c)
        if ! $cc $WARN $OPT $extra -DSPH_REAL=$prec "$src" -o "$dir/$name" -lm > "$dir/$name.build" 2>&1; then
            echo "  $label $name: BUILD FAILED"
            sed 's/^/    | /' "$dir/$name.build" | head -n 30
            TOTAL_FAIL=$((TOTAL_FAIL + 1))
            continue
        fi
        "$dir/$name" > "$dir/$name.out" 2>&1
        count "$label $name" $? "$dir/$name.out"
    done
}

# The configurations are independent: run them JOBS at a time (default: the
# number of cores), each into its own log, and print the logs in order.
JOBS=${JOBS:-$(nproc 2> /dev/null || echo 2)}
CONFIGS=""
for cc in gcc clang; do
    if ! command -v $cc > /dev/null 2>&1; then
        echo "SKIPPED: $cc configurations ($cc is not installed)"
        continue
    fi
    san=""
    if has_flag $cc -fsanitize=address,undefined; then
        san="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
    else
        echo "note: $cc has no address/undefined sanitizers here; $cc builds run without them"
    fi
    for prec in double float; do
        CONFIGS="$CONFIGS $cc-$prec"
        # clang double builds for the host CPU (-march=native where it
        # works): the AVX square-root path and AVX vector loops get tested
        arch=""
        if [ $cc-$prec = clang-double ] && has_flag $cc -march=native; then arch="-march=native"; fi
        eval "CFG_$(echo $cc-$prec | tr - _)=\"\$cc|\$prec|\$san \$arch|== \$cc \$prec\${san:+ +asan,ubsan}\${arch:+ \$arch}|\""
    done
done
if has_openmp gcc; then
    # also the portable path: SPH_NO_INTRINSICS (no SSE/AVX helper)
    CONFIGS="$CONFIGS gcc-double-omp"
    CFG_gcc_double_omp="gcc|double|-fopenmp -DSPH_NO_INTRINSICS|== gcc double -fopenmp -DSPH_NO_INTRINSICS (2 threads, portable path)|OMP_NUM_THREADS=2"
else
    echo "SKIPPED: OpenMP configuration (gcc -fopenmp does not build here)"
fi
if has_flag gcc -march=native; then
    # gcc for the host CPU at -O2, as make bench builds: the AVX-512 one-pass
    # pair loops (where the CPU has AVX-512) under the compiler that times them
    CONFIGS="$CONFIGS gcc-double-native"
    CFG_gcc_double_native="gcc|double|-march=native -O2 -g0|== gcc double -march=native -O2 (operator tests)||tests/test_op_*.c"
    # the same for float: there the AVX-512 loops read float and compute in
    # double, and the neighbour check widens float positions
    CONFIGS="$CONFIGS gcc-float-native"
    CFG_gcc_float_native="gcc|float|-march=native -O2 -g0|== gcc float -march=native -O2 (operator and neighbour tests)||tests/test_op_*.c tests/test_neighbours.c"
fi
if command -v clang > /dev/null 2>&1 && has_openmp clang; then
    # clang -fopenmp at -O2 without -g: the build where clang reports omp simd
    # loops it could not vectorise (-Wpass-failed, an error under -Werror)
    CONFIGS="$CONFIGS clang-double-omp"
    CFG_clang_double_omp="clang|double|-fopenmp -O2 -g0|== clang double -fopenmp -O2 (operator tests, 2 threads)|OMP_NUM_THREADS=2|tests/test_op_*.c"
else
    echo "SKIPPED: clang OpenMP configuration (clang -fopenmp does not build here)"
fi

run_one() { # run_one label: one configuration, output and counts into its own files
    spec=$(eval echo "\"\$CFG_$(echo $1 | tr - _)\"")
    IFS='|' read -r c p f title envs srcs <<EOS
$spec
EOS
    TOTAL_PASS=0
    TOTAL_FAIL=0
    {
        echo "$title"
        if [ -n "$envs" ]; then export $envs; fi
        run_config "$c" "$p" "$f" "$1" "$srcs"
        echo "$TOTAL_PASS $TOTAL_FAIL" > "$OUT/$1.counts"
    } > "$OUT/$1.log" 2>&1
}

running=0
for cfg in $CONFIGS; do
    run_one "$cfg" &
    running=$((running + 1))
    if [ "$running" -ge "$JOBS" ]; then
        wait -n 2> /dev/null || wait
        running=$((running - 1))
    fi
done
wait
for cfg in $CONFIGS; do
    cat "$OUT/$cfg.log"
    if [ -f "$OUT/$cfg.counts" ]; then
        read -r p f < "$OUT/$cfg.counts"
        TOTAL_PASS=$((TOTAL_PASS + p))
        TOTAL_FAIL=$((TOTAL_FAIL + f))
    else
        echo "  $cfg: did not finish - counted as 1 failed"
        TOTAL_FAIL=$((TOTAL_FAIL + 1))
    fi
done

# Examples with a --check mode: a short coarse run of a real simulation that
# exits non-zero when it misses its own validation bounds (one case each).
echo "== examples (--check)"
mkdir -p "$OUT/examples"
omp=""
if has_openmp gcc; then omp="-fopenmp"; fi
for src in examples/*.c studies/*.c; do
    [ -e "$src" ] || continue
    grep -q -- '--check' "$src" || continue
    name=$(basename "$src" .c)
    if ! gcc -O2 -std=c99 -Wall -Wextra -pedantic -Werror $omp -I. "$src" -o "$OUT/examples/$name" -lm \
        > "$OUT/examples/$name.build" 2>&1; then
        echo "  example $name: BUILD FAILED"
        sed 's/^/    | /' "$OUT/examples/$name.build" | head -n 30
        TOTAL_FAIL=$((TOTAL_FAIL + 1))
        continue
    fi
    check "example $name --check" timeout 300 "$OUT/examples/$name" --check
done

echo "== compile checks"
if command -v g++ > /dev/null 2>&1; then
    check "C++11 (g++ -std=c++11 -Wall -Wextra -pedantic -Werror)" \
        g++ -std=c++11 -Wall -Wextra -pedantic -Werror -I. tests/compile_check.cpp -o "$OUT/cpp_check"
    check "C++ float build" \
        g++ -std=c++11 -Wall -Wextra -pedantic -Werror -DSPH_REAL=float -I. tests/compile_check.cpp -o "$OUT/cpp_check_f"
else
    echo "SKIPPED: C++ compile check (g++ is not installed)"
fi
for cc in gcc clang; do
    command -v $cc > /dev/null 2>&1 || continue
    check "C11 ($cc -std=c11, double and float)" sh -c "$cc -std=c11 -Wall -Wextra -pedantic -Werror -I. tests/compile_check.c -o $OUT/c11_check -lm && $OUT/c11_check && $cc -std=c11 -Wall -Wextra -pedantic -Werror -DSPH_REAL=float -I. tests/compile_check.c -o $OUT/c11_check_f -lm && $OUT/c11_check_f"
done
if command -v nvcc > /dev/null 2>&1; then
    check "CUDA (nvcc, host and device code)" \
        nvcc -std=c++11 -Werror all-warnings -I. -c tests/compile_check.cu -o "$OUT/cu_check.o"
else
    echo "SKIPPED: nvcc compile check (nvcc is not on the PATH)"
fi
if command -v cmake > /dev/null 2>&1; then
    check "CMake target sph_kernel::sph_kernel (add_subdirectory and installed find_package)" sh tests/cmake_check.sh
else
    echo "SKIPPED: CMake check (cmake is not installed)"
fi

echo "$TOTAL_PASS passed, $TOTAL_FAIL failed"
[ "$TOTAL_FAIL" -eq 0 ]
