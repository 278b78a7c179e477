# sph_kernel.h - build the tests, examples, docs and the installable header.
#   make test       all tests: gcc/clang x double/float, sanitizers, OpenMP,
#                   C++/nvcc/CMake compile checks; ends with "N passed, N failed"
#   make demo       builds and runs the main example
#   make plots      redraws the PNG plots in docs/ (needs gnuplot)
#   make install PREFIX=/usr/local   header + pkg-config file
#   make bench      operator and neighbour-search timings (examples/benchmark.c)
CC      ?= cc
CFLAGS  ?= -O2 -std=c99 -Wall -Wextra -pedantic -Werror
LDLIBS  ?= -lm
PREFIX  ?= /usr/local
VERSION := $(shell sed -n 's/^\#define SPH_KERNEL_VERSION_STRING "\(.*\)"/\1/p' sph_kernel.h)
BUILD   := build

.PHONY: all test demo plots install uninstall clean bench tiny-size

all: $(BUILD)/kernel_table $(BUILD)/kernel_plots $(BUILD)/quickstart

test:
	@bash tests/run.sh

$(BUILD)/%: examples/%.c sph_kernel.h
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) -I. $< -o $@ $(LDLIBS)

demo: $(BUILD)/kernel_table
	./$(BUILD)/kernel_table

# Data from examples/kernel_plots.c into build/plots, PNGs into docs/plots.
plots: $(BUILD)/kernel_plots
	@command -v gnuplot > /dev/null 2>&1 || { \
	    echo "make plots: gnuplot is not installed (Debian/Ubuntu: apt-get install gnuplot-nox);"; \
	    echo "            the PNGs in docs/plots were left as they are."; exit 1; }
	@mkdir -p $(BUILD)/plots
	./$(BUILD)/kernel_plots $(BUILD)/plots
	gnuplot -e "datadir='$(BUILD)/plots'; outdir='docs/plots'" docs/plots/kernels.gp
	@ls docs/plots/*.png

install:
	install -d $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/lib/pkgconfig
	install -m 644 sph_kernel.h $(DESTDIR)$(PREFIX)/include/sph_kernel.h
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' sph_kernel.pc.in \
	    > $(DESTDIR)$(PREFIX)/lib/pkgconfig/sph_kernel.pc

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/include/sph_kernel.h $(DESTDIR)$(PREFIX)/lib/pkgconfig/sph_kernel.pc

clean:
	rm -rf $(BUILD)

# ---- bench, tiny-size: timings (examples/benchmark.c) and the size of a
# program pinned to 2-D cubic density (examples/tiny_density.c) ----
BENCH_FLAGS := -O3 -march=native -fopenmp -std=c99 -Wall -Wextra -pedantic -Werror -I.
BENCH_PIN   := -DSPH_DIM=3 -DSPH_KERNEL=SPH_KERNEL_CUBIC

$(BUILD)/bench/%_double.o: examples/benchmark.c sph_kernel.h
	@mkdir -p $(BUILD)/bench
	$(CC) $(BENCH_FLAGS) $(BENCH_$*) -c $< -o $@

$(BUILD)/bench/%_float.o: examples/benchmark.c sph_kernel.h
	@mkdir -p $(BUILD)/bench
	$(CC) $(BENCH_FLAGS) -DSPH_REAL=float $(BENCH_$*) -c $< -o $@

.PRECIOUS: $(BUILD)/bench/%.o
BENCH_main   := -DBENCH_LINK_PARTS
BENCH_pinned := -DBENCH_PART=bench_pinned $(BENCH_PIN)
BENCH_spec0  := -DBENCH_PART=bench_spec0 -DSPH_OP_SPECIALISE=0

$(BUILD)/bench/benchmark_%: $(BUILD)/bench/main_%.o $(BUILD)/bench/pinned_%.o $(BUILD)/bench/spec0_%.o
	$(CC) -fopenmp $^ -o $@ -lm

bench: $(BUILD)/bench/benchmark_double $(BUILD)/bench/benchmark_float tiny-size
	./$(BUILD)/bench/benchmark_double
	@echo
	./$(BUILD)/bench/benchmark_float

tiny-size:
	@mkdir -p $(BUILD)/bench
	$(CC) -O2 -std=c99 -Wall -Wextra -pedantic -Werror -I. -c examples/tiny_density.c -o $(BUILD)/bench/tiny_density.o
	@echo "examples/tiny_density.c (SPH_DIM 2, SPH_KERNEL cubic, sph_density), gcc -O2:"
	@size $(BUILD)/bench/tiny_density.o
