#!/bin/sh
# The MPI example (examples/mpi_taylor_green.c, docs/mpi.md) on 2 ranks:
#  1. its --check: fixed, moving (transport velocity) and moving plain runs
#     on 2 ranks against the same code on one process, fields bitwise equal
#     and particles migrating between the ranks;
#  2. against examples/taylor_green.c itself: both built with VTK frames
#     printed to 17 significant digits (a copy of example_io.h), the frames
#     of the 2-rank run are byte for byte those of taylor_green (fixed,
#     moving and moving plain particles).
# Built with mpicc as the Makefile builds it, but without the run-time
# passes (SPH_NO_DISPATCH: the ranks and the
# single process run the same loops either way); run with mpirun (Open MPI:
# --oversubscribe, and its allow-run-as-root settings when run as root).
set -e
dir=build/test/mpi
rm -rf "$dir"
mkdir -p "$dir/src"
FLAGS="-O2 -std=c99 -Wall -Wextra -pedantic -Werror -DSPH_NO_DISPATCH"
OMP=""
if printf 'int main(void){return 0;}\n' | mpicc -fopenmp -x c - -o "$dir/omp_probe" > /dev/null 2>&1; then OMP=-fopenmp; fi
RUN="mpirun -n 2"
if mpirun --version 2>&1 | grep -q "Open MPI"; then
    RUN="$RUN --oversubscribe"
    export OMPI_MCA_mpi_yield_when_idle=1 # ranks that wait give the core away (the tests share the machine)
    if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
fi
export OMP_NUM_THREADS=1
echo "== mpicc $FLAGS $OMP examples/mpi_taylor_green.c; $RUN ... --check"
# shellcheck disable=SC2086 # flags are words
mpicc $FLAGS $OMP -I. examples/mpi_taylor_green.c -o "$dir/mpi_taylor_green" -lm
# shellcheck disable=SC2086
timeout 600 $RUN "$dir/mpi_taylor_green" --check

echo "== against taylor_green.c: binary VTK frames, their series and energy.csv byte for byte"
cp examples/taylor_green.c examples/mpi_taylor_green.c "$dir/src/"
cp examples/example_io.h "$dir/src/"
# shellcheck disable=SC2086
mpicc $FLAGS $OMP -I. "$dir/src/mpi_taylor_green.c" -o "$dir/mpi17" -lm
# shellcheck disable=SC2086
cc $FLAGS $OMP -I. "$dir/src/taylor_green.c" -o "$dir/tg17" -lm
for mode in fixed lagrangian plain; do
    case $mode in
    fixed) args="" ;;
    lagrangian) args="--lagrangian" ;;
    plain) args="--lagrangian --plain" ;;
    esac
    # shellcheck disable=SC2086 # args are words
    "$dir/tg17" --n 24 --t-end 0.1 --frames 2 $args --out "$dir/tg_$mode" > /dev/null
    # shellcheck disable=SC2086
    timeout 600 $RUN "$dir/mpi17" --n 24 --t-end 0.1 --frames 2 $args --out "$dir/mpi_$mode" > /dev/null
    k=0
    for f in "$dir/tg_$mode"/*.vtu "$dir/tg_$mode"/taylor_green.pvd "$dir/tg_$mode"/energy.csv; do
        cmp "$f" "$dir/mpi_$mode/$(basename "$f")"
        k=$((k + 1))
    done
    echo "$mode: $k files byte for byte equal"
done
