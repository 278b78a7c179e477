#!/bin/sh
# tools/mpi_scaling.sh - strong and weak scaling of examples/mpi_taylor_green.c
# (docs/mpi.md, "Scaling on one machine"): moving particles (transport
# velocity), a fixed number of steps, every combination of MPI ranks and
# OpenMP threads per rank up to the cores of this machine; prints the time
# per step, the share of it spent in the halo exchange and migration, the
# halo size, and the speed-up and efficiency against one rank, one thread.
#
#   tools/mpi_scaling.sh                    n 200 (40 000 particles), 40 steps
#   N=400 STEPS=20 tools/mpi_scaling.sh     a larger run
#   RANKS="1 2 4" THREADS="1 2" tools/mpi_scaling.sh   other combinations (also oversubscribed ones)
#
# Strong scaling: the same N particles on every combination. Weak scaling:
# N per rank fixed (n grows as sqrt(ranks)), one thread per rank. Timings
# are wall-clock seconds of the slowest rank; take them on an otherwise idle
# machine (other jobs on the cores change them far more than the code does).
set -e
cd "$(dirname "$0")/.."
N=${N:-200}
STEPS=${STEPS:-40}
CORES=$(nproc 2> /dev/null || echo 2)
RANKS=${RANKS:-$(seq 1 "$CORES" | tr '\n' ' ')}
THREADS=${THREADS:-$(seq 1 "$CORES" | tr '\n' ' ')}
BIN=build/mpi/mpi_taylor_green
if ! command -v mpicc > /dev/null 2>&1 || ! command -v mpirun > /dev/null 2>&1; then
    echo "tools/mpi_scaling.sh: needs mpicc and mpirun (Debian/Ubuntu: apt-get install openmpi-bin libopenmpi-dev)"
    exit 1
fi
make -s --no-print-directory "$BIN"
RUN=mpirun
if mpirun --version 2>&1 | grep -q "Open MPI"; then
    RUN="mpirun --oversubscribe --bind-to none"
    if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
fi
OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
export OMP_WAIT_POLICY
OUT=build/mpi_scaling
mkdir -p "$OUT"

# row kind n ranks threads: runs one combination, prints its row; the first
# row of a kind sets the base time (BASE) of its speed-up and efficiency
row() {
    # shellcheck disable=SC2086 # RUN is words
    line=$($RUN -n "$3" "$BIN" --n "$2" --lagrangian --steps "$STEPS" --frames 0 --threads "$4" --out "$OUT" | grep '^scaling:')
    # the line: scaling: ranks R threads T particles P halo H steps S total X exchange E compute C
    echo "$line" | awk -v kind="$1" -v base="${BASE:-0}" '{
        r = $3; t = $5; p = $7; h = $9; s = $11; x = $13; e = $15; c = $17; ms = 1e3 * x / s
        if (base == 0) base = ms
        up = base / ms; eff = kind == "weak" ? up : up / (r * t)
        printf "%-6s %5d %7d %9d %7.1f %11.3f %10.1f %9.1f %8s %9.0f%%\n", kind, r, t, p, 100 * h / p, ms,
            100 * e / x, 100 * c / x, kind == "weak" ? "-" : sprintf("%.2f", up), 100 * eff
        printf "%s\n", base > "'"$OUT/base"'" }'
    BASE=$(cat "$OUT/base")
}

echo "mpi_taylor_green --lagrangian --steps $STEPS; $CORES cores ($(grep -m1 'model name' /proc/cpuinfo 2> /dev/null | sed 's/.*: //')); load average $(cut -d' ' -f1-3 /proc/loadavg 2> /dev/null)"
printf '%-6s %5s %7s %9s %7s %11s %10s %9s %8s %10s\n' scaling ranks threads particles "halo %" "ms / step" "exchange %" "compute %" speed-up efficiency
BASE=""
for r in $RANKS; do
    for t in $THREADS; do
        [ $((r * t)) -le "$CORES" ] || [ -n "${ALL:-}" ] || continue
        row strong "$N" "$r" "$t"
    done
done
BASE=""
for r in $RANKS; do
    [ "$r" -le "$CORES" ] || [ -n "${ALL:-}" ] || continue
    row weak "$(awk -v n="$N" -v r="$r" 'BEGIN {printf "%d", n * sqrt(r) + 0.5}')" "$r" 1
done
echo "exchange: migration, halo selection, packing and MPI_Alltoallv (waiting for a slower rank included);"
echo "compute: the rest of the steps (search, operators, integration, reductions). Efficiency: weak = t(1) / t(P)."
