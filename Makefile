# sph_kernel.h - build the tests, examples, docs and the installable header.
#   make test       all tests: gcc/clang x double/float, sanitizers, OpenMP,
#                   C++/nvcc/CMake compile checks; ends with "N passed, N failed"
#   make demo       builds and runs the main example
#   make plots      redraws the PNG plots in docs/ (needs gnuplot)
#   make report     error against run time of every operator: docs/report.md, docs/report/
#   make install PREFIX=/usr/local   header + pkg-config file
CC      ?= cc
CFLAGS  ?= -O2 -std=c99 -Wall -Wextra -pedantic -Werror
LDLIBS  ?= -lm
PREFIX  ?= /usr/local
VERSION := $(shell sed -n 's/^\#define SPH_KERNEL_VERSION_STRING "\(.*\)"/\1/p' sph_kernel.h)
BUILD   := build

.PHONY: all test demo plots install uninstall clean report report-full plots-report report-plots-if-gnuplot

all: $(BUILD)/kernel_table $(BUILD)/kernel_plots $(BUILD)/quickstart

test:
	@bash tests/run.sh

$(BUILD)/%: examples/%.c sph_kernel.h
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) -I. $< -o $@ $(LDLIBS)

demo: $(BUILD)/kernel_table
	./$(BUILD)/kernel_table

# Data from examples/kernel_plots.c into build/plots, PNGs into docs/plots.
plots: $(BUILD)/kernel_plots plots-report
	@command -v gnuplot > /dev/null 2>&1 || { \
	    echo "make plots: gnuplot is not installed (Debian/Ubuntu: apt-get install gnuplot-nox);"; \
	    echo "            the PNGs in docs/plots were left as they are."; exit 1; }
	@mkdir -p $(BUILD)/plots
	./$(BUILD)/kernel_plots $(BUILD)/plots
	gnuplot -e "datadir='$(BUILD)/plots'; outdir='docs/plots'" docs/plots/kernels.gp
	@ls docs/plots/*.png

# Accuracy/cost report (report, report-full, plots-report): examples/error_vs_runtime.c
# writes docs/report.md and the CSVs of docs/report/ (one OpenMP thread, so
# times are per core); gnuplot draws the PNGs from the CSVs where it exists.
REPORT_OMP := $(shell printf 'int main(void){return 0;}\n' | $(CC) -fopenmp -x c - -o /dev/null > /dev/null 2>&1 && echo -fopenmp)

$(BUILD)/error_vs_runtime: examples/error_vs_runtime.c sph_kernel.h
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) $(REPORT_OMP) -I. $< -o $@ $(LDLIBS)

report: $(BUILD)/error_vs_runtime
	@mkdir -p docs/report
	OMP_NUM_THREADS=1 ./$(BUILD)/error_vs_runtime --out docs
	@$(MAKE) --no-print-directory report-plots-if-gnuplot

report-full: $(BUILD)/error_vs_runtime
	@mkdir -p docs/report
	OMP_NUM_THREADS=1 ./$(BUILD)/error_vs_runtime --full --out docs
	@$(MAKE) --no-print-directory report-plots-if-gnuplot

report-plots-if-gnuplot:
	@if command -v gnuplot > /dev/null 2>&1; then $(MAKE) --no-print-directory plots-report; else \
	    echo "make report: gnuplot is not installed (Debian/Ubuntu: apt-get install gnuplot-nox);"; \
	    echo "             docs/report.md and the CSVs are new, the PNGs in docs/report were NOT redrawn."; fi

plots-report:
	@command -v gnuplot > /dev/null 2>&1 || { \
	    echo "make plots-report: gnuplot is not installed (Debian/Ubuntu: apt-get install gnuplot-nox);"; \
	    echo "                   the PNGs in docs/report were left as they are."; exit 1; }
	gnuplot -e "dir='docs/report'" docs/report/report.gp
	@ls docs/report/*.png

install:
	install -d $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/lib/pkgconfig
	install -m 644 sph_kernel.h $(DESTDIR)$(PREFIX)/include/sph_kernel.h
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' sph_kernel.pc.in \
	    > $(DESTDIR)$(PREFIX)/lib/pkgconfig/sph_kernel.pc

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/include/sph_kernel.h $(DESTDIR)$(PREFIX)/lib/pkgconfig/sph_kernel.pc

clean:
	rm -rf $(BUILD)
