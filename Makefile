# sph_kernel.h - build the tests, examples, docs and the installable header.
#   make test       all tests: gcc/clang x double/float, sanitizers, OpenMP,
#                   -march=native, C11/C++/nvcc/CMake compile checks, the examples'
#                   --check runs; ends with "N passed, N failed" (tests/run.sh)
#   make check      the quick tier: the sanitised clang -march=native build of the
#                   tests, the gcc -march=native -O2 fused-pass test, the header checks
#   make demo       builds and runs the main example
#   make plots      redraws the PNG plots in docs/results/ (needs gnuplot)
#   make report     error against run time of every operator: docs/results/report.md, docs/results/report/
#   make report-flows  error against run time of two flows (Gresho vortex, Sod tube): docs/results/flows.md
#   make install PREFIX=/usr/local   header, pkg-config file, CMake package
#   make bench      operator and neighbour-search timings (bench/benchmark.c)
#   make bench-step the Sod shock tube's step per particle and phase (bench/bench_step.sh)
#   make bench-isa  the fast loops at each instruction set this CPU runs, one -O2 build (bench/bench_isa.c)
#   make isa-names  rewrites the function names of the run-time passes at the end of sph_kernel.h
#   make run-mpi    the Taylor-Green vortex over MPI ranks (mpicc, mpirun; docs/mpi.md)
#
# Tree: examples/ what a user copies (quickstarts, solvers); bench/ timings and
# size probes; studies/ the programs and gnuplot scripts that write the results
# in docs/results/; support/ particle clouds shared by tests, bench and studies,
# the clock and median of the timing programs, and the generator of the header's
# list of run-time pass names (isa_names.sh); docs/ the reference pages.
# Every program includes "sph_kernel.h" with -I.
CC      ?= cc
CFLAGS  ?= -O2 -std=c99 -Wall -Wextra -pedantic -Wshadow -Werror
LDLIBS  ?= -lm
PREFIX  ?= /usr/local
VERSION := $(shell sed -n 's/^\#define SPH_KERNEL_VERSION_STRING "\(.*\)"/\1/p' sph_kernel.h)
BUILD   := build
# generated results (report, benchmark, study tables, plots); docs/ keeps the reference pages
RESULTS := docs/results
# -fopenmp where the compiler has it (examples run multi-threaded; results do
# not depend on the thread count)
OPENMP  := $(shell printf 'int main(void){return 0;}\n' | $(CC) -fopenmp -x c - -o /dev/null > /dev/null 2>&1 && echo -fopenmp)

.PHONY: all test check print-check-examples demo plots install uninstall clean fuzz stability report report-full plots-report report-plots-if-gnuplot report-flows plots-report-flows report-flows-plots-if-gnuplot bench bench-step bench-search bench-isa tiny-size compile-cost isa-names

all: $(BUILD)/kernel_table $(BUILD)/kernel_plots $(BUILD)/quickstart

test:
	@bash tests/run.sh test

check:
	@bash tests/run.sh check

# Programs with a --check mode: a short coarse run of a real simulation or
# study that exits non-zero when it misses its own validation bounds. make test
# builds each (gcc -O2, OpenMP where gcc has it) and runs it with its
# arguments, CHECK_ARGS_<name> (default --check); one case each.
CHECK_EXAMPLES := examples/cloud_quickstart examples/dam_break examples/taylor_green \
                  examples/heat_conduction examples/sod_shock examples/smoothing_length_quickstart \
                  examples/step_recipe examples/gresho \
                  studies/error_vs_runtime studies/stability studies/hydrostatic_tank
CHECK_ARGS     := --check

print-check-examples:
	@$(foreach p,$(CHECK_EXAMPLES),echo "$(p).c $(or $(CHECK_ARGS_$(notdir $(p))),$(CHECK_ARGS))";)

$(BUILD)/%: examples/%.c sph_kernel.h
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) -I. $< -o $@ $(LDLIBS)

$(BUILD)/%: studies/%.c sph_kernel.h support/particles.h support/tank.h support/timing.h
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) -I. $< -o $@ $(LDLIBS)

$(BUILD)/%: bench/%.c sph_kernel.h support/particles.h support/timing.h
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) -I. $< -o $@ $(LDLIBS)

demo: $(BUILD)/kernel_table
	./$(BUILD)/kernel_table

# Data from studies/kernel_plots.c into build/plots, PNGs into docs/results/plots.
plots: $(BUILD)/kernel_plots plots-dambreak plots-report plots-report-flows plots-flows
	@command -v gnuplot > /dev/null 2>&1 || { \
	    echo "make plots: gnuplot is not installed (Debian/Ubuntu: apt-get install gnuplot-nox);"; \
	    echo "            the PNGs in $(RESULTS)/plots were left as they are."; exit 1; }
	@mkdir -p $(BUILD)/plots
	./$(BUILD)/kernel_plots $(BUILD)/plots
	gnuplot -e "datadir='$(BUILD)/plots'; outdir='$(RESULTS)/plots'" studies/kernels.gp
	@ls $(RESULTS)/plots/*.png

# Dam break example (examples/dam_break.c): run-dam-break, plots-dambreak.
# Built with OpenMP when the compiler has it; the measurements are read from
# data/dam_break (DAM_BREAK_DATA=dir overrides).
DAM_BREAK_DATA ?=
# plots-dambreak runs on one thread: the run times it reports stay comparable on a
# shared machine (results are the same for any thread count).
DAM_BREAK_THREADS ?= 1
# Threads that wait at a barrier sleep instead of spinning: on a machine whose
# cores are busy with other work, spinning made a 2-thread run 5-6 times slower
# than one thread (the thread being waited for had lost its core).
DAM_BREAK_WAIT ?= $(or $(OMP_WAIT_POLICY),passive)
DAM_BREAK_ARGS := $(if $(DAM_BREAK_DATA),--data $(DAM_BREAK_DATA))
.PHONY: run-dam-break plots-dambreak

$(BUILD)/dam_break: examples/dam_break.c examples/example_io.h sph_kernel.h
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) $(OPENMP) -I. $< -o $@ $(LDLIBS)

run-dam-break: $(BUILD)/dam_break
	OMP_WAIT_POLICY=$(DAM_BREAK_WAIT) ./$(BUILD)/dam_break --out $(BUILD)/dam_break_out $(DAM_BREAK_ARGS)

# The validation protocol at 30 (default) and 60 (a x 2a only) particles across
# the column, each with and without the wall-friction model
# ($(RESULTS)/dam_break_results.md: protocol table and comparison tables), the
# protocol figures also at 20 and 40 and for variants of the model at 30 (a x 2a
# only: no-slip walls, c0, alpha, h) ($(RESULTS)/dam_break_resolution.md), the
# wall-pressure probe of Buchner (2002) ($(RESULTS)/dam_break_probe.md), and the
# front, height and pressure plots ($(RESULTS)/plots/dam_break_*.png). About 6
# minutes of one core.
DAM_BREAK_RUN = ./$(BUILD)/dam_break $(DAM_BREAK_ARGS) --threads $(DAM_BREAK_THREADS) --vtk-every 0
plots-dambreak: $(BUILD)/dam_break
	@command -v gnuplot > /dev/null 2>&1 || { echo "make plots-dambreak: gnuplot is not installed"; exit 1; }
	rm -f $(RESULTS)/dam_break_resolution.md
	$(DAM_BREAK_RUN) --res 30 --side-by-side --refine --out $(BUILD)/dam_break_out --summary $(RESULTS)/dam_break_resolution.md --report $(RESULTS)/dam_break_results.md
	$(DAM_BREAK_RUN) --res 20 --out $(BUILD)/dam_break_out --summary $(RESULTS)/dam_break_resolution.md
	$(DAM_BREAK_RUN) --res 40 --out $(BUILD)/dam_break_out --summary $(RESULTS)/dam_break_resolution.md
	for v in "--stokes 0 --noslip 1" "--c0 20" "--alpha 0.05" "--hfac 1.6"; do \
	    $(DAM_BREAK_RUN) --res 30 --column 2 $$v --out $(BUILD)/dam_break_out/variants --summary $(RESULTS)/dam_break_resolution.md || exit 1; \
	done
	$(DAM_BREAK_RUN) --probe --out $(BUILD)/dam_break_out --report $(RESULTS)/dam_break_probe.md || [ $$? -eq 1 ] # 1: targets missed, reported
	gnuplot -e "datadir='$(or $(DAM_BREAK_DATA),$(firstword $(wildcard data/dam_break)))'; simdir='$(BUILD)/dam_break_out'; outdir='$(RESULTS)/plots'; res1=30; res2=60; probe='buchner_res40'" studies/dam_break.gp

# Accuracy/cost report (report, report-full, plots-report): studies/error_vs_runtime.c
# writes $(RESULTS)/report.md and the CSVs of $(RESULTS)/report/ (one OpenMP thread,
# so times are per core); gnuplot draws the PNGs from the CSVs where it exists.
$(BUILD)/error_vs_runtime: studies/error_vs_runtime.c sph_kernel.h
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) $(OPENMP) -I. $< -o $@ $(LDLIBS)

report: $(BUILD)/error_vs_runtime
	@mkdir -p $(RESULTS)/report
	OMP_NUM_THREADS=1 ./$(BUILD)/error_vs_runtime --out $(RESULTS)
	@$(MAKE) --no-print-directory report-plots-if-gnuplot

report-full: $(BUILD)/error_vs_runtime
	@mkdir -p $(RESULTS)/report
	OMP_NUM_THREADS=1 ./$(BUILD)/error_vs_runtime --full --out $(RESULTS)
	@$(MAKE) --no-print-directory report-plots-if-gnuplot
	@$(MAKE) --no-print-directory report-flows

report-plots-if-gnuplot:
	@if command -v gnuplot > /dev/null 2>&1; then $(MAKE) --no-print-directory plots-report; else \
	    echo "make report: gnuplot is not installed (Debian/Ubuntu: apt-get install gnuplot-nox);"; \
	    echo "             $(RESULTS)/report.md and the CSVs are new, the PNGs in $(RESULTS)/report were NOT redrawn."; fi

plots-report:
	@command -v gnuplot > /dev/null 2>&1 || { \
	    echo "make plots-report: gnuplot is not installed (Debian/Ubuntu: apt-get install gnuplot-nox);"; \
	    echo "                   the PNGs in $(RESULTS)/report were left as they are."; exit 1; }
	gnuplot -e "dir='$(RESULTS)/report'" studies/report.gp
	@ls $(RESULTS)/report/*.png

# Error against run time on flows (report-flows, plots-report-flows): studies/flows_vs_runtime.c
# runs examples/gresho.c (n = 32, 64, 128) and examples/sod_shock.c (nx = 16, 24, 32) for every
# kernel at two or three neighbour numbers, each run one process on one thread, the programs
# built with -march=native as a user tuning for the machine builds them; it writes
# $(RESULTS)/flows.md and $(RESULTS)/flows/*.csv, gnuplot the PNGs beside the CSVs. About 15
# minutes of one core (860 s for the table in docs/results), so not part of make report (under a
# minute) nor of make test; make report-full runs it after the long sweeps.
FLOWS_BUILD  := $(BUILD)/native
FLOWS_CFLAGS := $(CFLAGS) -march=native
report-flows: $(BUILD)/flows_vs_runtime
	@$(MAKE) --no-print-directory BUILD=$(FLOWS_BUILD) CFLAGS='$(FLOWS_CFLAGS)' \
	    $(FLOWS_BUILD)/flows/gresho $(FLOWS_BUILD)/flows/sod_shock
	./$(BUILD)/flows_vs_runtime --bin $(FLOWS_BUILD)/flows --out $(RESULTS) \
	    --build "$(CC) $(FLOWS_CFLAGS) $(OPENMP), $$($(CC) --version | head -n 1)"
	@$(MAKE) --no-print-directory report-flows-plots-if-gnuplot

report-flows-plots-if-gnuplot:
	@if command -v gnuplot > /dev/null 2>&1; then $(MAKE) --no-print-directory plots-report-flows; else \
	    echo "make report-flows: gnuplot is not installed (Debian/Ubuntu: apt-get install gnuplot-nox);"; \
	    echo "                   $(RESULTS)/flows.md and the CSVs are new, the PNGs in $(RESULTS)/flows were NOT redrawn."; fi

plots-report-flows:
	@command -v gnuplot > /dev/null 2>&1 || { \
	    echo "make plots-report-flows: gnuplot is not installed (Debian/Ubuntu: apt-get install gnuplot-nox);"; \
	    echo "                         the PNGs in $(RESULTS)/flows were left as they are."; exit 1; }
	gnuplot -e "dir='$(RESULTS)/flows'" studies/flows_pareto.gp
	@ls $(RESULTS)/flows/*.png

# stability: builds studies/stability.c twice (double, and float for table 9) and
# rewrites $(RESULTS)/stability.md with its measurements (about five minutes,
# one core: its scenes are small, threads would not pay; `./build/stability
# --quick out.md` is a fast pass, `--check` the short assertion run that `make
# test` does).
stability: $(BUILD)/stability $(BUILD)/stability_float
	./$(BUILD)/stability_float --float-values > $(BUILD)/stability_float.txt
	./$(BUILD)/stability --float-results $(BUILD)/stability_float.txt $(RESULTS)/stability.md

# the same study program in float: writes the float column of its table 9
$(BUILD)/stability_float: studies/stability.c sph_kernel.h
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) -DSPH_REAL=float -I. $< -o $@ $(LDLIBS)

# make tables: rewrites the GENERATED block of sph_kernel.h (the kernels'
# natural pieces, alpha_d, sigma_d) from tools/gen_kernel_tables.py, which
# needs python3 with sympy; tests/check_tables.sh checks the two agree.
.PHONY: tables
tables:
	@python3 -c 'import sympy' > /dev/null 2>&1 || { \
	    echo "make tables: needs python3 with sympy (Debian/Ubuntu: apt-get install python3-sympy)"; exit 1; }
	python3 tools/gen_kernel_tables.py --write sph_kernel.h

# The header, the pkg-config file and the CMake package (cmake/: the same
# files cmake --install installs), so find_package(sph_kernel 0.1) works
CMAKEDIR = $(PREFIX)/lib/cmake/sph_kernel
install:
	install -d $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/lib/pkgconfig $(DESTDIR)$(CMAKEDIR)
	install -m 644 sph_kernel.h $(DESTDIR)$(PREFIX)/include/sph_kernel.h
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' sph_kernel.pc.in \
	    > $(DESTDIR)$(PREFIX)/lib/pkgconfig/sph_kernel.pc
	install -m 644 cmake/sph_kernelConfig.cmake $(DESTDIR)$(CMAKEDIR)/sph_kernelConfig.cmake
	sed -e 's|@VERSION@|$(VERSION)|' cmake/sph_kernelConfigVersion.cmake.in \
	    > $(DESTDIR)$(CMAKEDIR)/sph_kernelConfigVersion.cmake

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/include/sph_kernel.h $(DESTDIR)$(PREFIX)/lib/pkgconfig/sph_kernel.pc \
	    $(DESTDIR)$(CMAKEDIR)/sph_kernelConfig.cmake $(DESTDIR)$(CMAKEDIR)/sph_kernelConfigVersion.cmake
	rmdir $(DESTDIR)$(CMAKEDIR) 2> /dev/null || true

clean:
	rm -rf $(BUILD)

# Flow examples: run-taylor-green, run-heat-conduction, run-gresho, plots-flows
# (examples/taylor_green.c, examples/heat_conduction.c, examples/gresho.c; docs/examples.md).
.PHONY: run-taylor-green run-heat-conduction run-gresho plots-flows run-sod plots-sod

$(BUILD)/flows/%: examples/%.c examples/example_io.h sph_kernel.h
	@mkdir -p $(BUILD)/flows
	$(CC) $(CFLAGS) $(OPENMP) -I. $< -o $@ $(LDLIBS)

run-taylor-green: $(BUILD)/flows/taylor_green
	./$(BUILD)/flows/taylor_green --out $(BUILD)/taylor_green

run-heat-conduction: $(BUILD)/flows/heat_conduction
	./$(BUILD)/flows/heat_conduction --out $(BUILD)/heat_conduction

run-gresho: $(BUILD)/flows/gresho
	./$(BUILD)/flows/gresho --out $(BUILD)/gresho

# The --study runs write $(RESULTS)/*_results.md and the CSVs the plots read (a few minutes).
plots-flows: $(BUILD)/flows/taylor_green $(BUILD)/flows/heat_conduction
	@command -v gnuplot > /dev/null 2>&1 || { echo "make plots-flows: gnuplot is not installed"; exit 1; }
	./$(BUILD)/flows/taylor_green --study $(RESULTS) --out $(BUILD)/flows/data
	./$(BUILD)/flows/heat_conduction --study $(RESULTS) --out $(BUILD)/flows/data
	gnuplot -e "datadir='$(BUILD)/flows/data'; outdir='$(RESULTS)/plots'" studies/flows.gp

# Shock tube (examples/sod_shock.c, docs/smoothing_length.md): one run at
# nx = 32 (fcc cells per unit length), or the study at nx = 16, 24, 32, 48 with
# its table ($(RESULTS)/sod_shock.md) and plot ($(RESULTS)/plots/sod_shock.png).
run-sod: $(BUILD)/flows/sod_shock
	./$(BUILD)/flows/sod_shock --out $(BUILD)/sod_shock

plots-sod: $(BUILD)/flows/sod_shock
	@command -v gnuplot > /dev/null 2>&1 || { echo "make plots-sod: gnuplot is not installed"; exit 1; }
	./$(BUILD)/flows/sod_shock --study $(RESULTS) --out $(BUILD)/flows/sod
	gnuplot -e "datadir='$(BUILD)/flows/sod'; outdir='$(RESULTS)/plots'" studies/sod_shock.gp

# MPI example (examples/mpi_taylor_green.c, docs/mpi.md): run-mpi builds it
# with mpicc (OpenMP inside the ranks where the compiler has it) and runs
# MPI_RANKS ranks with MPI_ARGS (default: moving particles, so that they
# migrate between the ranks; add --compare to check the run against one
# process); scaling-mpi prints strong and weak scaling (tools/mpi_scaling.sh).
# As root, Open MPI needs OMPI_ALLOW_RUN_AS_ROOT(_CONFIRM)=1: set here then.
MPICC      ?= mpicc
MPIRUN     ?= mpirun
MPI_RANKS  ?= 2
MPI_ARGS   ?= --lagrangian
MPI_ROOT   := $(if $(filter 0,$(shell id -u 2> /dev/null)),OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1)
MPI_OPENMP  = $(shell printf 'int main(void){return 0;}\n' | $(MPICC) -fopenmp -x c - -o /dev/null > /dev/null 2>&1 && echo -fopenmp)
.PHONY: run-mpi scaling-mpi

$(BUILD)/mpi/mpi_taylor_green: examples/mpi_taylor_green.c examples/example_io.h sph_kernel.h
	@command -v $(MPICC) > /dev/null 2>&1 || { \
	    echo "$(MPICC) is not installed (Debian/Ubuntu: apt-get install openmpi-bin libopenmpi-dev)"; exit 1; }
	@mkdir -p $(BUILD)/mpi
	$(MPICC) $(CFLAGS) $(MPI_OPENMP) -I. $< -o $@ $(LDLIBS)

run-mpi: $(BUILD)/mpi/mpi_taylor_green
	$(MPI_ROOT) $(MPIRUN) -n $(MPI_RANKS) ./$(BUILD)/mpi/mpi_taylor_green --out $(BUILD)/mpi_taylor_green $(MPI_ARGS)

scaling-mpi:
	@sh tools/mpi_scaling.sh

# ---- fuzz: operator and neighbour-search invariants (tests/fuzz_body.h) ----
# make fuzz [FUZZ_SECONDS=60]: libFuzzer (clang -fsanitize=fuzzer,address,
# undefined) when clang has it, otherwise the seeded random driver
# tests/test_fuzz_seeded.c under ASan/UBSan, for FUZZ_SECONDS.
FUZZ_SECONDS ?= 60
fuzz:
	@mkdir -p $(BUILD)/fuzz/corpus
	@printf 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n){(void)d;(void)n;return 0;}\n' > $(BUILD)/fuzz/probe.c
	@if command -v clang > /dev/null 2>&1 && \
	    clang -fsanitize=fuzzer $(BUILD)/fuzz/probe.c -o $(BUILD)/fuzz/probe > /dev/null 2>&1; then \
	    echo "make fuzz: libFuzzer (clang -fsanitize=fuzzer,address,undefined), $(FUZZ_SECONDS) s"; \
	    clang -std=c99 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. \
	        tests/fuzz_operators.c -o $(BUILD)/fuzz/fuzz_operators -lm && \
	    ./$(BUILD)/fuzz/fuzz_operators -max_total_time=$(FUZZ_SECONDS) -max_len=256 \
	        -artifact_prefix=$(BUILD)/fuzz/ $(BUILD)/fuzz/corpus; \
	else \
	    echo "make fuzz: libFuzzer not available; seeded random driver (ASan/UBSan), $(FUZZ_SECONDS) s"; \
	    $(CC) -std=c99 -O1 -g -fsanitize=address,undefined -fno-sanitize-recover=all -I. \
	        tests/test_fuzz_seeded.c -o $(BUILD)/fuzz/test_fuzz_seeded -lm && \
	    ./$(BUILD)/fuzz/test_fuzz_seeded $(FUZZ_SECONDS); \
	fi

# ---- bench-search: cost per listed pair of the neighbour search with
# varying h (bench/bench_search_h.c, docs/neighbours.md "Varying h"): the
# one-pass lists and, beside them, sph_nsearch_count alone (the direct
# search), built -O3 -march=native and -O2 generic; BEFORE=path/to/sph_kernel.h also builds
# and runs it against that header (before/after figures in one run). ----
BEFORE ?=
bench-search: bench/bench_search_h.c sph_kernel.h support/particles.h support/timing.h
	@mkdir -p $(BUILD)/bench
	$(CC) -O3 -march=native -std=c99 -I. bench/bench_search_h.c -o $(BUILD)/bench/search_h_native -lm
	$(CC) -O2 -std=c99 -I. bench/bench_search_h.c -o $(BUILD)/bench/search_h_generic -lm
	@if [ -n "$(BEFORE)" ]; then \
	    $(CC) -O3 -march=native -std=c99 -DSPH_HEADER='"$(abspath $(BEFORE))"' -I. bench/bench_search_h.c -o $(BUILD)/bench/search_h_native_before -lm && \
	    $(CC) -O2 -std=c99 -DSPH_HEADER='"$(abspath $(BEFORE))"' -I. bench/bench_search_h.c -o $(BUILD)/bench/search_h_generic_before -lm || exit 1; \
	    echo "== before ($(BEFORE)), -O3 -march=native"; ./$(BUILD)/bench/search_h_native_before $(BENCH_REPEATS) || exit 1; \
	    echo "== before ($(BEFORE)), -O2"; ./$(BUILD)/bench/search_h_generic_before $(BENCH_REPEATS) || exit 1; fi
	@echo "== -O3 -march=native"; ./$(BUILD)/bench/search_h_native $(BENCH_REPEATS)
	@echo "== -O2"; ./$(BUILD)/bench/search_h_generic $(BENCH_REPEATS)
BENCH_REPEATS ?= 5

# ---- bench, tiny-size: timings (bench/benchmark.c) and the size of a
# program pinned to 2-D cubic density (bench/tiny_density.c) ----
# BENCH_ARCH: the -march of the timed build (make bench also times x86-64-v3,
# AVX2 without AVX-512, the vector width most users' CPUs have)
BENCH_ARCH  ?= native
BENCH_DEFS  ?=
BENCH_FLAGS := -O3 -march=$(BENCH_ARCH) $(BENCH_DEFS) -fopenmp -std=c99 -Wall -Wextra -pedantic -Werror -I.
BENCH_PIN   := -DSPH_DIM=3 -DSPH_KERNEL=SPH_KERNEL_CUBIC

$(BUILD)/bench/%_double.o: bench/benchmark.c sph_kernel.h support/timing.h
	@mkdir -p $(BUILD)/bench
	$(CC) $(BENCH_FLAGS) $(BENCH_$*) -c $< -o $@

$(BUILD)/bench/%_float.o: bench/benchmark.c sph_kernel.h support/timing.h
	@mkdir -p $(BUILD)/bench
	$(CC) $(BENCH_FLAGS) -DSPH_REAL=float $(BENCH_$*) -c $< -o $@

.PRECIOUS: $(BUILD)/bench/%.o
BENCH_main   := -DBENCH_LINK_PARTS
BENCH_pinned := -DBENCH_PART=bench_pinned $(BENCH_PIN)
BENCH_reference := -DBENCH_PART=bench_reference -DSPH_OP_REFERENCE

$(BUILD)/bench/benchmark_%: $(BUILD)/bench/main_%.o $(BUILD)/bench/pinned_%.o $(BUILD)/bench/reference_%.o
	$(CC) -fopenmp $^ -o $@ -lm

# make bench prints the tables and writes them to $(RESULTS)/benchmark.md (with the
# machine's CPU model and load average: these are shared-machine timings).
bench: $(BUILD)/bench/benchmark_double $(BUILD)/bench/benchmark_float tiny-size
	@{ echo "# Benchmark (written by make bench, bench/benchmark.c)"; echo; \
	   echo "$(CC) -O3 -march=native -fopenmp; CPU: $$(grep -m1 'model name' /proc/cpuinfo 2> /dev/null | sed 's/.*: //')"; \
	   echo "($$(grep -m1 vendor_id /proc/cpuinfo 2> /dev/null | sed 's/.*: //'), $$(grep -qw avx512f /proc/cpuinfo 2> /dev/null || echo 'no ')AVX-512),"; \
	   echo "$$(nproc 2> /dev/null) cores; load average at the start: $$(cut -d' ' -f1-3 /proc/loadavg 2> /dev/null)."; \
	   echo "Ratios within one run are the numbers to read: absolute times move with other jobs on the machine."; \
	 } > $(RESULTS)/benchmark.md
	./$(BUILD)/bench/benchmark_double 64 7 $(RESULTS)/benchmark.md
	@echo
	./$(BUILD)/bench/benchmark_float 64 7 $(RESULTS)/benchmark.md
	@$(MAKE) --no-print-directory BUILD=$(BUILD)/avx2 BENCH_ARCH=x86-64-v3 BENCH_DEFS=-DSPH_NO_DISPATCH \
	    $(BUILD)/avx2/bench/benchmark_double $(BUILD)/avx2/bench/benchmark_float
	@{ echo; echo "# AVX2 build: $(CC) -O3 -march=x86-64-v3 -DSPH_NO_DISPATCH -fopenmp (no AVX-512: the AVX2 loops)"; } >> $(RESULTS)/benchmark.md
	./$(BUILD)/avx2/bench/benchmark_double 64 7 $(RESULTS)/benchmark.md
	@echo
	./$(BUILD)/avx2/bench/benchmark_float 64 7 $(RESULTS)/benchmark.md
	@$(MAKE) --no-print-directory bench-isa BENCH_REPEATS=7 | tee $(BUILD)/bench/isa.txt
	@{ echo; echo "# Every instruction set in one build (make bench-isa, bench/bench_isa.c, $(CC) -O2, no -march)"; echo; \
	   grep -v '^\./\|^$(CC) ' $(BUILD)/bench/isa.txt; } >> $(RESULTS)/benchmark.md

# bench-step: the step of examples/sod_shock.c per particle (search, density / h,
# forces, the rest; pairs, candidates, bytes) at nx = 16, 32, 48 on 1 and 2
# threads and on 1 thread pinned to each of two CPUs (the speed-up the cores
# allow), built with CFLAGS and with -O3 -march=native, medians of 3 repeats
# (bench/bench_step.sh; a few minutes): $(RESULTS)/step.md. Shorter:
# make bench-step BENCH_STEP_NX=16 BENCH_STEP_REPEATS=3
bench-step:
	@CC="$(CC)" CFLAGS="$(CFLAGS)" OPENMP="$(OPENMP)" LDLIBS="$(LDLIBS)" BUILD="$(BUILD)" \
	    BENCH_STEP_OUT="$(RESULTS)/step.md" sh bench/bench_step.sh

# bench-isa: the fast loops at portable, AVX2 and AVX-512 (those this CPU
# runs), one build without -march (run-time dispatch), double and float.
bench-isa:
	@mkdir -p $(BUILD)/bench
	$(CC) -O2 -std=c99 -Wall -Wextra -pedantic -Werror -I. bench/bench_isa.c -o $(BUILD)/bench/isa_double -lm
	$(CC) -O2 -std=c99 -Wall -Wextra -pedantic -Werror -DSPH_REAL=float -I. bench/bench_isa.c -o $(BUILD)/bench/isa_float -lm
	@echo "CPU: $$(grep -m1 'model name' /proc/cpuinfo 2> /dev/null | sed 's/.*: //'); $$($(CC) --version | head -n 1)"
	./$(BUILD)/bench/isa_double $(BENCH_ISA_SIDE) $(BENCH_REPEATS)
	./$(BUILD)/bench/isa_float $(BENCH_ISA_SIDE) $(BENCH_REPEATS)
BENCH_ISA_SIDE ?= 48

# isa-names: the names the run-time passes map (support/isa_names.sh; make
# test checks them with tests/check_isa_names.sh).
isa-names:
	@sh support/isa_names.sh

# compile-cost: CPU time, peak memory and code size of typical units
# (bench/compile_cost.sh; README "Build cost").
compile-cost:
	@sh bench/compile_cost.sh

tiny-size:
	@mkdir -p $(BUILD)/bench
	$(CC) -O2 -std=c99 -Wall -Wextra -pedantic -Werror -I. -c bench/tiny_density.c -o $(BUILD)/bench/tiny_density.o
	@echo "bench/tiny_density.c (SPH_DIM 2, SPH_KERNEL cubic, sph_density), $(CC) -O2:"
	@size $(BUILD)/bench/tiny_density.o
	@echo "bench/gradient_unit.c (sph_gradient, kernel and dimension at run time), $(CC) -O2:"
	@for s in "" -DSPH_OP_REFERENCE; do \
	    t0=$$(date +%s.%N); \
	    $(CC) -O2 -std=c99 -Wall -Wextra -pedantic -Werror -I. $$s \
	        -c bench/gradient_unit.c -o $(BUILD)/bench/gradient_unit.o || exit 1; \
	    t1=$$(date +%s.%N); \
	    printf '  %-20s compile %.2f s, text %s bytes\n' "$${s:-fast loops}" \
	        $$(awk "BEGIN {print $$t1 - $$t0}") $$(size $(BUILD)/bench/gradient_unit.o | awk 'NR == 2 {print $$1}'); \
	done
