# sph_kernel.h - build the tests, examples, docs and the installable header.
#   make test       all tests: gcc/clang x double/float, sanitizers, OpenMP,
#                   C++/nvcc/CMake compile checks; ends with "N passed, N failed"
#   make demo       builds and runs the main example
#   make plots      redraws the PNG plots in docs/ (needs gnuplot)
#   make install PREFIX=/usr/local   header + pkg-config file
CC      ?= cc
CFLAGS  ?= -O2 -std=c99 -Wall -Wextra -pedantic -Werror
LDLIBS  ?= -lm
PREFIX  ?= /usr/local
VERSION := $(shell sed -n 's/^\#define SPH_KERNEL_VERSION_STRING "\(.*\)"/\1/p' sph_kernel.h)
BUILD   := build

.PHONY: all test demo plots install uninstall clean stability

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

# stability: builds examples/stability.c and rewrites docs/stability.md with
# its measurements (a few minutes, one core: its scenes are small, threads would
# not pay; `./build/stability --quick out.md` is a fast pass, `--check` the
# short assertion run that `make test` does).
stability: $(BUILD)/stability
	./$(BUILD)/stability docs/stability.md

install:
	install -d $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/lib/pkgconfig
	install -m 644 sph_kernel.h $(DESTDIR)$(PREFIX)/include/sph_kernel.h
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' sph_kernel.pc.in \
	    > $(DESTDIR)$(PREFIX)/lib/pkgconfig/sph_kernel.pc

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/include/sph_kernel.h $(DESTDIR)$(PREFIX)/lib/pkgconfig/sph_kernel.pc

clean:
	rm -rf $(BUILD)
