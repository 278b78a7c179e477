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

.PHONY: all test demo plots install uninstall clean fuzz

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
	    $(CC) -std=c99 -O1 -g -fsanitize=address,undefined -fno-sanitize-recover=all \
	        tests/test_fuzz_seeded.c -o $(BUILD)/fuzz/test_fuzz_seeded -lm && \
	    ./$(BUILD)/fuzz/test_fuzz_seeded $(FUZZ_SECONDS); \
	fi
