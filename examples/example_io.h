/* examples/example_io.h - the small I/O every example solver needs, kept out
 * of the solvers so they read as physics: command-line options with --help,
 * a one-line progress indicator (elapsed time and ETA on stderr), VTK
 * particle files that ParaView opens, and output directories.
 * Not part of the library: sph_kernel.h does no I/O. POSIX (clock_gettime,
 * mkdir, opendir); define _POSIX_C_SOURCE before any system header, as below.
 *
 * What a solver uses:
 *   ex_arg, ex_parse_args      options with their accepted range (numbers) or
 *                              words (text): a value outside is refused before
 *                              anything runs, naming the option and the range
 *   ex_kernel_choices()        the kernel names of sph_kernel.h as choices
 *   ex_calloc(n, size, what)   calloc with the size checked for overflow; a
 *                              failure prints what could not be allocated
 *   ex_prog()                  the program's name (set by ex_parse_args): every
 *                              message on stderr starts with it
 *   ex_fields_finite(...)      stops a run at the first NaN or Inf of its
 *                              fields (sph_check_field), naming field, particle, t
 *   ex_growth, ex_growth_check a quantity of a run (energy, error, max |T|)
 *                              against the bound it must stay within: a run
 *                              that grows past it stops (EX_EGROWTH, exit 1)
 *                              with quantity, value, bound, time and a hint
 *   ex_memory_available()      bytes a run may still allocate (address-space
 *                              limit, available memory), for estimates made
 *                              before the set-up
 *   ex_csv_fixed(v, decimals)  v for "%.*f" in a CSV, -0.000 printed as 0.000
 *   ex_series_open/_write/_report/_close
 *                              a run's frames: XML VTK (.vtu, appended raw
 *                              binary by default, ASCII on request) carrying
 *                              their time (FieldData TIME), the .pvd series
 *                              file ParaView plays in physical time, and the
 *                              frames of an earlier run of the same name removed
 *                              first, so one folder never mixes two runs
 * Kept for programs written against the first version: ex_option / ex_parse
 * (options without ranges; integers now refused outside int and when not
 * whole) and ex_write_vtk (one legacy ASCII frame).
 */
#ifndef SPH_EXAMPLE_IO_H
#define SPH_EXAMPLE_IO_H

#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>

#include "sph_kernel.h"

/* ---- the program's name ---- */

/* The slot of the name every message starts with ("example" until
 * ex_parse_args stores argv[0]'s last path component). */
static inline const char **ex__prog_slot(void)
{
    static const char *name = "example";
    return &name;
}

static inline const char *ex_prog(void) { return *ex__prog_slot(); }

/* Stores the program's name from argv[0] (its part after the last '/'). */
static inline void ex_set_prog(const char *argv0)
{
    const char *slash = argv0 != NULL ? strrchr(argv0, '/') : NULL;
    if (argv0 != NULL && *argv0) *ex__prog_slot() = slash != NULL && slash[1] ? slash + 1 : argv0;
}

/* ---- command-line options: --name value, --flag ---- */

/* One option of an example: its name (without "--"), a one-line help, and
 * where its value goes (exactly one of real/integer/text/flag is set). */
typedef struct {
    const char *name, *help;
    double *real;
    int *integer;
    const char **text;
    int *flag;
} ex_option;

/* An option with what it accepts: numbers (real, integer) within lo..hi,
 * the ends themselves refused when open has EX_OPEN_LO / EX_OPEN_HI, and 0
 * accepted besides the range with EX_OR_ZERO (0 meaning "automatic"),
 * integers only even with EX_EVEN; text
 * one of the words of choices ("a|b|c"; NULL: any). An integer must also be
 * whole. Unset (zero) lo and hi accept every finite number. */
typedef struct {
    const char *name, *help;
    double *real;
    int *integer;
    const char **text;
    int *flag;
    double lo, hi;
    int open;
    const char *choices;
} ex_arg;

enum { EX_OPEN_LO = 1, EX_OPEN_HI = 2, EX_OR_ZERO = 4, EX_EVEN = 8 };

/* The accepted range of a numeric option as text: "0 < cfl <= 1". */
static inline void ex_range_text(const ex_arg *o, char *buf, size_t size)
{
    if (o->lo == 0 && o->hi == 0)
        snprintf(buf, size, "any finite number");
    else
        snprintf(buf, size, "%s%s%.15g %s %s %s %.15g", (o->open & EX_EVEN) ? "even, " : "",
                 (o->open & EX_OR_ZERO) ? "0 or " : "", o->lo, (o->open & EX_OPEN_LO) ? "<" : "<=", o->name,
                 (o->open & EX_OPEN_HI) ? "<" : "<=", o->hi);
}

static inline void ex_usage_args(const char *prog, const char *about, const ex_arg *opt, int n)
{
    int i;
    printf("%s - %s\n\nusage: %s [options]\n\n", ex_prog(), about, prog);
    for (i = 0; i < n; ++i) {
        char def[64] = "", range[128] = "";
        if (opt[i].real) snprintf(def, sizeof def, " (default %g", *opt[i].real);
        if (opt[i].integer) snprintf(def, sizeof def, " (default %d", *opt[i].integer);
        if (opt[i].text) snprintf(def, sizeof def, " (default %s", *opt[i].text ? *opt[i].text : "none");
        if ((opt[i].real || opt[i].integer) && !(opt[i].lo == 0 && opt[i].hi == 0)) {
            char r[100];
            ex_range_text(&opt[i], r, sizeof r);
            snprintf(range, sizeof range, "; %s", r);
        }
        if (opt[i].text && opt[i].choices) snprintf(range, sizeof range, "; %s", opt[i].choices);
        printf("  --%-14s %s%s%s%s\n", opt[i].name, opt[i].help, def, range, def[0] ? ")" : "");
    }
    printf("  --%-14s %s\n", "help", "this text");
}

/* Whether word is one of the '|'-separated choices. */
static inline int ex_is_choice(const char *word, const char *choices)
{
    const size_t n = strlen(word);
    const char *c = choices;
    while (n > 0 && c != NULL && *c) {
        const char *e = strchr(c, '|');
        const size_t len = e ? (size_t)(e - c) : strlen(c);
        if (len == n && strncmp(c, word, n) == 0) return 1;
        c = e ? e + 1 : NULL;
    }
    return 0;
}

/* Parses argv into the options, checking each value against what its
 * option accepts. Returns 0 to run, 1 after --help (exit 0), -1 on an
 * unknown option, a missing value or a refused one (a message on stderr
 * that names the option and what it accepts). */
static inline int ex_parse_args(int argc, char **argv, const char *about, const ex_arg *opt, int n)
{
    int a, i;
    ex_set_prog(argv[0]);
    for (a = 1; a < argc; ++a) {
        const char *s = argv[a];
        const ex_arg *o;
        if (strcmp(s, "--help") == 0 || strcmp(s, "-h") == 0) {
            ex_usage_args(argv[0], about, opt, n);
            return 1;
        }
        for (i = 0; i < n; ++i)
            if (strncmp(s, "--", 2) == 0 && strcmp(s + 2, opt[i].name) == 0) break;
        if (i == n) {
            fprintf(stderr, "%s: unknown option '%s' (try --help)\n", ex_prog(), s);
            return -1;
        }
        o = &opt[i];
        if (o->flag) {
            *o->flag = 1;
            continue;
        }
        if (a + 1 >= argc || strncmp(argv[a + 1], "--", 2) == 0) { /* "--n --t-end 1": --n has none */
            fprintf(stderr, "%s: option '%s' needs a value (try --help)\n", ex_prog(), s);
            return -1;
        }
        ++a;
        if (o->text) {
            if (o->choices != NULL && !ex_is_choice(argv[a], o->choices)) {
                fprintf(stderr, "%s: --%s '%s' refused: accepted %s\n", ex_prog(), o->name, argv[a], o->choices);
                return -1;
            }
            *o->text = argv[a];
        } else {
            char *end = NULL, range[128];
            const double v = strtod(argv[a], &end);
            const int ranged = !(o->lo == 0 && o->hi == 0);
            int bad = end == argv[a] || *end != '\0' || !isfinite(v);
            if (!bad && o->integer && (v != floor(v) || v < INT_MIN || v > INT_MAX)) bad = 1;
            if (!bad && (o->open & EX_EVEN) && fmod(v, 2) != 0) bad = 1;
            if (!bad && ranged && !(v == 0 && (o->open & EX_OR_ZERO)))
                bad = (o->open & EX_OPEN_LO ? !(v > o->lo) : !(v >= o->lo)) ||
                      (o->open & EX_OPEN_HI ? !(v < o->hi) : !(v <= o->hi));
            if (bad) {
                if (ranged) ex_range_text(o, range, sizeof range);
                else snprintf(range, sizeof range, "%s", o->integer ? "a number in int" : "any finite number");
                fprintf(stderr, "%s: --%s %s refused: accepted %s%s\n", ex_prog(), o->name, argv[a],
                        o->integer && ranged ? "a whole number, " : o->integer ? "a whole " : "", range);
                return -1;
            }
            if (o->real) *o->real = v;
            if (o->integer) *o->integer = (int)v;
        }
    }
    return 0;
}

static inline void ex_usage(const char *prog, const char *about, const ex_option *opt, int n)
{
    int i;
    printf("%s - %s\n\nusage: %s [options]\n\n", ex_prog(), about, prog);
    for (i = 0; i < n; ++i) {
        char def[64] = "";
        if (opt[i].real) snprintf(def, sizeof def, " (default %g)", *opt[i].real);
        if (opt[i].integer) snprintf(def, sizeof def, " (default %d)", *opt[i].integer);
        if (opt[i].text && *opt[i].text) snprintf(def, sizeof def, " (default %s)", *opt[i].text);
        printf("  --%-14s %s%s\n", opt[i].name, opt[i].help, def);
    }
    printf("  --%-14s %s\n", "help", "this text");
}

/* ex_parse_args for options without ranges (every finite number; integers
 * whole and within int). Same returns. */
static inline int ex_parse(int argc, char **argv, const char *about, const ex_option *opt, int n)
{
    ex_arg *all;
    int i, st;
    ex_set_prog(argv[0]);
    for (i = 1; i < argc; ++i)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            ex_usage(argv[0], about, opt, n);
            return 1;
        }
    all = (ex_arg *)calloc(n > 0 ? (size_t)n : 1, sizeof *all);
    if (all == NULL) {
        fprintf(stderr, "%s: out of memory reading the options\n", ex_prog());
        return -1;
    }
    for (i = 0; i < n; ++i) {
        all[i].name = opt[i].name, all[i].help = opt[i].help, all[i].real = opt[i].real;
        all[i].integer = opt[i].integer, all[i].text = opt[i].text, all[i].flag = opt[i].flag;
    }
    st = ex_parse_args(argc, argv, about, all, n);
    free(all);
    return st;
}

/* The kernel names of sph_kernel.h as a choices list "cubic|lucy|...". */
static inline const char *ex_kernel_choices(void)
{
    static char buf[512];
    int k;
    if (buf[0] == '\0')
        for (k = 0; k < SPH_KERNEL_COUNT; ++k) {
            const size_t used = strlen(buf);
            snprintf(buf + used, sizeof buf - used, "%s%s", k ? "|" : "", sph_kernel_name((sph_kernel)k));
        }
    return buf;
}

/* ---- status ---- */

/* Statuses of the examples beside the library's (section 2 of sph_kernel.h):
 * an output file could not be written, memory ran out, a quantity of the
 * run grew past its bound (a message on stderr names the file, what could
 * not be allocated, or the quantity). */
#define EX_EWRITE 100
#define EX_ENOMEM 101
#define EX_EGROWTH 102

static inline const char *ex_strerror(int st)
{
    return st == EX_EWRITE ? "an output file could not be written"
           : st == EX_ENOMEM        ? "out of memory"
           : st == EX_EGROWTH       ? "a quantity of the run grew past its bound"
           : st == SPH_ENONFINITE   ? "NaN or Inf in the solution"
                                    : sph_strerror(st);
}

/* ---- bounds a run must stay within ---- */

/* A quantity of a run that must stay at or below start * factor + margin:
 * kinetic energy of a decaying flow (factor 1 + tol), an error against the
 * exact solution (start 0, margin), max |T| under the maximum principle. The
 * hint says what to change when it is exceeded. */
typedef struct {
    const char *quantity, *hint;
    double start, factor, margin;
} ex_growth;

static inline double ex_growth_bound(const ex_growth *g) { return g->start * g->factor + g->margin; }

/* The bound as text for a banner or --help: "kinetic energy <= 1.01 x its start value 0.25". */
static inline void ex_growth_text(const ex_growth *g, char *buf, size_t size)
{
    if (g->start == 0) snprintf(buf, size, "%s <= %.6g", g->quantity, g->margin);
    else if (g->margin == 0) snprintf(buf, size, "%s <= %.6g x its start value %.6g", g->quantity, g->factor, g->start);
    else snprintf(buf, size, "%s <= %.6g x its start value %.6g + %.6g", g->quantity, g->factor, g->start, g->margin);
}

/* SPH_OK while value <= the bound; otherwise (also for NaN) EX_EGROWTH and
 * one line on stderr: program, quantity, value, bound, time t and the hint,
 * so the run stops there and the program exits 1. */
static inline int ex_growth_check(const ex_growth *g, double value, double t)
{
    const double bound = ex_growth_bound(g);
    if (value <= bound) return SPH_OK;
    fprintf(stderr, "%s: %s = %.6g at t = %.6g exceeds its bound %.6g: run stopped (%s)\n", ex_prog(), g->quantity,
            value, t, bound, g->hint);
    return EX_EGROWTH;
}

/* ---- memory ---- */

/* calloc of count elements of size bytes; NULL when count * size overflows
 * size_t or memory runs out, with a message on stderr naming what (none
 * when what is NULL: the caller reports). */
static inline void *ex_calloc(size_t count, size_t size, const char *what)
{
    void *p = NULL;
    if (size != 0 && count > (size_t)-1 / size) {
        if (what) fprintf(stderr, "%s: cannot allocate %s: %.4g x %lu bytes overflow the address space\n", ex_prog(),
                          what, (double)count, (unsigned long)size);
    } else if ((p = calloc(count ? count : 1, size ? size : 1)) == NULL && what) {
        fprintf(stderr, "%s: cannot allocate %s: %.4g MB (out of memory)\n", ex_prog(), what,
                (double)count * (double)size / 1e6);
    }
    return p;
}

/* The value of "Key:  N kB" in a /proc file, in bytes; -1 when absent. */
static inline double ex__proc_kb(const char *path, const char *key)
{
    char line[256];
    const size_t n = strlen(key);
    double v = -1;
    FILE *f = fopen(path, "r");
    if (f == NULL) return -1;
    while (fgets(line, sizeof line, f) != NULL)
        if (strncmp(line, key, n) == 0 && line[n] == ':') {
            v = 1024 * strtod(line + n + 1, NULL);
            break;
        }
    fclose(f);
    return v;
}

/* Bytes this process may still allocate: the smaller of the address-space
 * limit (ulimit -v) less what the process maps now, and the memory the
 * system reports available (Linux: /proc/meminfo MemAvailable); -1 when
 * neither is known. *why (may be NULL) names the one that limits. */
static inline double ex_memory_available(const char **why)
{
    struct rlimit rl;
    double avail = ex__proc_kb("/proc/meminfo", "MemAvailable"), limit = -1;
    if (why != NULL) *why = "available memory";
    if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
        const double mapped = ex__proc_kb("/proc/self/status", "VmSize");
        limit = (double)rl.rlim_cur - (mapped > 0 ? mapped : 0);
        if (limit < 0) limit = 0;
    }
    if (limit >= 0 && (avail < 0 || limit < avail)) {
        if (why != NULL) *why = "address-space limit (ulimit -v)";
        return limit;
    }
    return avail;
}

/* A byte count as text: "23.4 GB", "512 MB", "64 kB". */
static inline void ex_bytes_text(double bytes, char *buf, size_t size)
{
    if (bytes >= 1e9) snprintf(buf, size, "%.3g GB", bytes / 1e9);
    else if (bytes >= 1e6) snprintf(buf, size, "%.3g MB", bytes / 1e6);
    else snprintf(buf, size, "%.3g kB", bytes / 1e3);
}

/* v for a "%.*f" field of a CSV with this many decimals: 0 where the value
 * would print as -0.000... (a negative value, or -0.0, that rounds to zero),
 * v otherwise. */
static inline double ex_csv_fixed(double v, int decimals)
{
    char buf[64];
    const char *c;
    snprintf(buf, sizeof buf, "%.*f", decimals, v);
    if (buf[0] != '-') return v;
    for (c = buf + 1; *c; ++c)
        if (*c != '0' && *c != '.') return v;
    return 0.0;
}

/* A particle count from its factors, checked to fit sph_idx (int32_t):
 * SPH_OK and *n, or SPH_ESIZE (and a message naming what is counted, e.g.
 * "particles of --n 4000") when too many. */
static inline int ex_particle_count(double count, const char *what, sph_idx *n)
{
    if (!(count >= 0) || count > (double)INT32_MAX) {
        fprintf(stderr, "%s: %.4g %s exceed what sph_idx counts (%ld)\n", ex_prog(), count, what, (long)INT32_MAX);
        return SPH_ESIZE;
    }
    *n = (sph_idx)count;
    return SPH_OK;
}

/* ---- wall clock and progress ---- */

static inline double ex_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* One progress line on stderr, rewritten in place at most every 0.5 s:
 * "label  43.0 %  elapsed 12.1 s  ETA 16.0 s". Call ex_progress_done at the end. */
typedef struct {
    double start, last;
    int shown;
} ex_progress;

static inline ex_progress ex_progress_start(void)
{
    ex_progress p;
    p.start = ex_now();
    p.last = 0;
    p.shown = 0;
    return p;
}

static inline void ex_progress_update(ex_progress *p, const char *label, double fraction)
{
    double now = ex_now(), el = now - p->start;
    if (now - p->last < 0.5 || el < 2.0) return; /* short runs stay silent */
    p->last = now;
    p->shown = 1;
    if (fraction > 1e-6)
        fprintf(stderr, "\r%s %5.1f %%  elapsed %6.1f s  ETA %6.1f s   ", label, 100 * fraction, el,
                el * (1 - fraction) / fraction);
    else
        fprintf(stderr, "\r%s %5.1f %%  elapsed %6.1f s   ", label, 100 * fraction, el);
    fflush(stderr);
}

static inline void ex_progress_done(ex_progress *p, const char *label)
{
    if (p->shown) fprintf(stderr, "\r%s 100.0 %%  elapsed %6.1f s              \n", label,
                          ex_now() - p->start);
}

/* ---- files ---- */

/* Creates a directory and its parents (like mkdir -p). 0 on success. */
static inline int ex_mkdir_p(const char *path)
{
    char buf[1024];
    size_t i, n = strlen(path);
    if (n == 0 || n >= sizeof buf) return -1;
    memcpy(buf, path, n + 1);
    for (i = 1; i <= n; ++i) {
        if (buf[i] == '/' || buf[i] == '\0') {
            char c = buf[i];
            buf[i] = '\0';
            if (mkdir(buf, 0755) != 0 && errno != EEXIST) return -1;
            buf[i] = c;
        }
    }
    { /* an existing file of that name is not a directory */
        struct stat st;
        return stat(path, &st) == 0 && S_ISDIR(st.st_mode) ? 0 : -1;
    }
}

/* One particle field for ex_write_vtk: a name and a view of ncomp (1..3)
 * components per particle (vectors are written with 3 components). */
typedef struct {
    const char *name;
    sph_view v;
    int ncomp;
} ex_field;

/* Writes n particles (positions x, dim components) and their fields as a
 * legacy ASCII VTK POLYDATA file of vertices, which ParaView reads.
 * Returns 0 on success. */
static inline int ex_write_vtk(const char *path, sph_idx n, int dim, sph_view x, const ex_field *f,
                               int nfields)
{
    FILE *out = fopen(path, "w");
    sph_idx i;
    int k, a;
    if (out == NULL) return -1;
    fprintf(out, "# vtk DataFile Version 3.0\nsph_kernel.h particles\nASCII\nDATASET POLYDATA\n");
    fprintf(out, "POINTS %ld double\n", (long)n);
    for (i = 0; i < n; ++i) {
        for (a = 0; a < 3; ++a)
            fprintf(out, "%.9g%c", a < dim ? (double)x.p[a][(ptrdiff_t)i * x.stride] : 0.0,
                    a == 2 ? '\n' : ' ');
    }
    fprintf(out, "VERTICES %ld %ld\n", (long)n, 2L * (long)n);
    for (i = 0; i < n; ++i) fprintf(out, "1 %ld\n", (long)i);
    if (nfields > 0) fprintf(out, "POINT_DATA %ld\n", (long)n);
    for (k = 0; k < nfields; ++k) {
        if (f[k].ncomp == 1)
            fprintf(out, "SCALARS %s double 1\nLOOKUP_TABLE default\n", f[k].name);
        else
            fprintf(out, "VECTORS %s double\n", f[k].name);
        for (i = 0; i < n; ++i) {
            if (f[k].ncomp == 1) {
                fprintf(out, "%.9g\n", (double)f[k].v.p[0][(ptrdiff_t)i * f[k].v.stride]);
                continue;
            }
            for (a = 0; a < 3; ++a)
                fprintf(out, "%.9g%c",
                        a < f[k].ncomp ? (double)f[k].v.p[a][(ptrdiff_t)i * f[k].v.stride] : 0.0,
                        a == 2 ? '\n' : ' ');
        }
    }
    return fclose(out) == 0 ? 0 : -1;
}

/* ---- a run's frames: XML VTK with their time, and the series file ---- */

/* SPH_OK when every component of the first n particles of each field is
 * finite (sph_check_field); otherwise SPH_ENONFINITE and a message on stderr
 * naming the program, field, particle and time, so the run stops there. */
static inline int ex_fields_finite(const char *prog, const ex_field *f, int nfields, sph_idx n, double t)
{
    int k;
    for (k = 0; k < nfields; ++k) {
        sph_idx bad = -1;
        const int st = sph_check_field(f[k].v, f[k].ncomp, n, &bad);
        if (st == SPH_ENONFINITE) {
            fprintf(stderr, "%s: %s of particle %ld is not finite at t = %.6g: run stopped, no further frames\n",
                    prog, f[k].name, (long)bad, t);
            return st;
        }
        if (st != SPH_OK) return st;
    }
    return SPH_OK;
}

/* One data array of a .vtu file: Float32 values of ncomp components per
 * particle (kind 0; components vcomp.. of view v padded with 0, so 2-D
 * vectors and positions get 3), or the Int32 / UInt8 vertex cells (kind 1:
 * the connectivity i, 2: the offsets i + 1, 3: the types, 1 = VTK_VERTEX).
 * Float32 and Int32: what a viewer needs, half the bytes of 64-bit values
 * (sph_idx is 32-bit, so are the indices). ASCII: the values inside the
 * element; binary: the 8-byte byte count and the raw values appended. */
typedef struct {
    FILE *out;
    int ascii;
} ex__vtu;

static inline int ex__vtu_values(ex__vtu *w, sph_view v, int vcomp, int ncomp, int kind, sph_idx n)
{
    float buf[3 * 256];
    int32_t ibuf[256];
    unsigned char tbuf[256];
    const size_t esize = kind == 3 ? 1 : 4;
    const uint64_t bytes = (uint64_t)n * (uint64_t)(kind == 0 ? ncomp : 1) * esize;
    sph_idx i0, i;
    int a;
    if (!w->ascii && fwrite(&bytes, sizeof bytes, 1, w->out) != 1) return -1;
    for (i0 = 0; i0 < n; i0 += 256) {
        const sph_idx m = n - i0 < 256 ? n - i0 : 256;
        size_t cnt = 0;
        for (i = 0; i < m; ++i) {
            const sph_idx p = i0 + i;
            if (kind == 0)
                for (a = 0; a < ncomp; ++a)
                    buf[cnt++] = a < vcomp ? (float)v.p[a][(ptrdiff_t)p * v.stride] : 0.0f;
            else if (kind == 3)
                tbuf[cnt++] = 1;
            else
                ibuf[cnt++] = (int32_t)p + (kind == 2);
        }
        if (w->ascii) {
            size_t q;
            for (q = 0; q < cnt; ++q) {
                if (kind == 0) fprintf(w->out, "%.9g ", (double)buf[q]);
                else fprintf(w->out, "%ld ", kind == 3 ? 1L : (long)ibuf[q]);
            }
            fputc('\n', w->out);
        } else if (fwrite(kind == 0 ? (void *)buf : kind == 3 ? (void *)tbuf : (void *)ibuf, esize, cnt, w->out) !=
                   cnt) {
            return -1;
        }
    }
    return 0;
}

/* The <DataArray> element of one array; binary: its offset into the
 * appended block, advanced past it. */
static inline void ex__vtu_array(ex__vtu *w, const char *type, const char *name, int ncomp, sph_view v, int vcomp,
                                 int kind, sph_idx n, uint64_t *offset)
{
    fprintf(w->out, "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"%s\"", type, name,
            ncomp, w->ascii ? "ascii" : "appended");
    if (w->ascii) {
        fprintf(w->out, ">\n");
        ex__vtu_values(w, v, vcomp, ncomp, kind, n);
        fprintf(w->out, "        </DataArray>\n");
    } else {
        fprintf(w->out, " offset=\"%lu\"/>\n", (unsigned long)*offset);
        *offset += 8 + (uint64_t)n * (uint64_t)ncomp * (kind == 3 ? 1u : 4u);
    }
}

/* Writes n particles (positions x, dim components) and their fields at time
 * t as an XML VTK UnstructuredGrid of vertices (.vtu; VTK 6 and later,
 * ParaView), values in single precision, the time (double) in FieldData
 * TIME; appended raw binary in the host's byte order (named in the header),
 * or ASCII (ascii = 1). 0 on success. */
static inline int ex_write_vtu(const char *path, double t, sph_idx n, int dim, sph_view x, const ex_field *f,
                               int nfields, int ascii)
{
    const uint16_t one = 1;
    uint64_t offset = 0;
    ex__vtu w;
    int k, pass, err = 0;
    if (n < 0 || dim < 1 || dim > 3 || (w.out = fopen(path, ascii ? "w" : "wb")) == NULL) return -1;
    w.ascii = ascii;
    fprintf(w.out, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"%s\" "
                   "header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <FieldData>\n      <DataArray type=\"Float64\" "
                   "Name=\"TIME\" NumberOfTuples=\"1\" format=\"ascii\">%.17g</DataArray>\n    </FieldData>\n"
                   "    <Piece NumberOfPoints=\"%ld\" NumberOfCells=\"%ld\">\n",
            *(const unsigned char *)&one ? "LittleEndian" : "BigEndian", t, (long)n, (long)n);
    /* pass 0: the elements (ASCII: with their values); pass 1 (binary): the appended values in the same order */
    for (pass = 0; pass < (ascii ? 1 : 2); ++pass) {
        if (pass == 1) fprintf(w.out, "  <AppendedData encoding=\"raw\">\n   _");
        if (pass == 0) fprintf(w.out, "      <PointData>\n");
        for (k = 0; k < nfields; ++k) {
            const int nc = f[k].ncomp == 1 ? 1 : 3;
            if (pass == 0) ex__vtu_array(&w, "Float32", f[k].name, nc, f[k].v, f[k].ncomp, 0, n, &offset);
            else err |= ex__vtu_values(&w, f[k].v, f[k].ncomp, nc, 0, n);
        }
        if (pass == 0) {
            fprintf(w.out, "      </PointData>\n      <Points>\n");
            ex__vtu_array(&w, "Float32", "Points", 3, x, dim, 0, n, &offset);
            fprintf(w.out, "      </Points>\n      <Cells>\n");
            ex__vtu_array(&w, "Int32", "connectivity", 1, x, 0, 1, n, &offset);
            ex__vtu_array(&w, "Int32", "offsets", 1, x, 0, 2, n, &offset);
            ex__vtu_array(&w, "UInt8", "types", 1, x, 0, 3, n, &offset);
            fprintf(w.out, "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n");
        } else {
            err |= ex__vtu_values(&w, x, dim, 3, 0, n);
            for (k = 1; k <= 3; ++k) err |= ex__vtu_values(&w, x, 0, 1, k, n);
            fprintf(w.out, "\n  </AppendedData>\n");
        }
    }
    fprintf(w.out, "</VTKFile>\n");
    err |= ferror(w.out);
    return fclose(w.out) != 0 || err ? -1 : 0;
}

/* The frames of one run: dir/name_0000.vtu, ... and dir/name.pvd, the
 * series file that lists them with their times (ParaView: open the .pvd). */
typedef struct {
    char dir[1024], name[128], last[1200];
    int ascii, count, removed;
    double t_first, t_last;
    double *time;
    int cap;
} ex_series;

/* Whether file is name_<digits>.vtu / .vtk or name.pvd: a frame or series
 * file of a run called name. */
static inline int ex__series_file(const char *file, const char *name)
{
    const size_t n = strlen(name);
    const char *p = file + n;
    if (strncmp(file, name, n) != 0) return 0;
    if (strcmp(p, ".pvd") == 0) return 1;
    if (*p++ != '_' || !(*p >= '0' && *p <= '9')) return 0;
    while (*p >= '0' && *p <= '9') ++p;
    return strcmp(p, ".vtu") == 0 || strcmp(p, ".vtk") == 0;
}

/* Starts a series in dir (created, like mkdir -p) and removes the frames and
 * series file of an earlier run of the same name there (s->removed counts
 * them; other files are left alone). 0 on success, -1 (with a message) when
 * dir cannot be created, read or cleaned. */
static inline int ex_series_open(ex_series *s, const char *dir, const char *name, int ascii)
{
    DIR *d;
    struct dirent *e;
    memset(s, 0, sizeof *s);
    if (strlen(dir) >= sizeof s->dir || strlen(name) >= sizeof s->name) {
        fprintf(stderr, "%s: output path too long: %s/%s\n", ex_prog(), dir, name);
        return -1;
    }
    strcpy(s->dir, dir), strcpy(s->name, name);
    s->ascii = ascii;
    if (ex_mkdir_p(dir) != 0 || (d = opendir(dir)) == NULL) {
        fprintf(stderr, "%s: cannot create or read the output directory %s\n", ex_prog(), dir);
        return -1;
    }
    while ((e = readdir(d)) != NULL) {
        char path[1200];
        if (!ex__series_file(e->d_name, name)) continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (remove(path) != 0) {
            fprintf(stderr, "%s: cannot remove %s of an earlier run\n", ex_prog(), path);
            closedir(d);
            return -1;
        }
        ++s->removed;
    }
    closedir(d);
    return 0;
}

/* Writes the next frame (time t) and rewrites the .pvd to list every frame
 * so far, so a run stopped early still leaves a series ParaView opens.
 * 0 on success, -1 with a message naming the file. */
static inline int ex_series_write(ex_series *s, double t, sph_idx n, int dim, sph_view x, const ex_field *f,
                                  int nfields)
{
    char path[1200];
    FILE *pvd;
    int i, err;
    if (s->count == s->cap) {
        const int cap = s->cap ? 2 * s->cap : 64;
        double *grown = (double *)realloc(s->time, (size_t)cap * sizeof *grown);
        if (grown == NULL) {
            fprintf(stderr, "%s: cannot allocate the frame list of %s\n", ex_prog(), s->name);
            return -1;
        }
        s->time = grown, s->cap = cap;
    }
    snprintf(s->last, sizeof s->last, "%s/%s_%04d.vtu", s->dir, s->name, s->count);
    if (ex_write_vtu(s->last, t, n, dim, x, f, nfields, s->ascii) != 0) {
        fprintf(stderr, "%s: cannot write %s\n", ex_prog(), s->last);
        return -1;
    }
    s->time[s->count++] = t;
    s->t_last = t;
    if (s->count == 1) s->t_first = t;
    snprintf(path, sizeof path, "%s/%s.pvd", s->dir, s->name);
    if ((pvd = fopen(path, "w")) == NULL) {
        fprintf(stderr, "%s: cannot write %s\n", ex_prog(), path);
        return -1;
    }
    fprintf(pvd, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n");
    for (i = 0; i < s->count; ++i)
        fprintf(pvd, "    <DataSet timestep=\"%.17g\" part=\"0\" file=\"%s_%04d.vtu\"/>\n", s->time[i], s->name, i);
    fprintf(pvd, "  </Collection>\n</VTKFile>\n");
    err = ferror(pvd);
    if (fclose(pvd) != 0 || err) {
        fprintf(stderr, "%s: cannot write %s\n", ex_prog(), path);
        return -1;
    }
    return 0;
}

/* One line on stdout: what the series wrote (and removed of an earlier run). */
static inline void ex_series_report(const ex_series *s)
{
    char times[64];
    if (s->count == 0) {
        printf("wrote no VTK frames of %s", s->name);
    } else {
        if (s->count > 1) snprintf(times, sizeof times, "t = %.4g .. %.4g", s->t_first, s->t_last);
        else snprintf(times, sizeof times, "t = %.4g", s->t_first);
        printf("wrote %d VTK frame%s %s/%s_0000.vtu%s%s (%s, %s) and the series %s/%s.pvd (ParaView)", s->count,
               s->count > 1 ? "s" : "", s->dir, s->name, s->count > 1 ? " .. " : "",
               s->count > 1 ? strrchr(s->last, '/') + 1 : "", s->ascii ? "ASCII" : "binary", times, s->dir, s->name);
    }
    if (s->removed > 0) printf("; removed %d file%s of an earlier run", s->removed, s->removed > 1 ? "s" : "");
    printf("\n");
}

static inline void ex_series_close(ex_series *s)
{
    free(s->time);
    s->time = NULL, s->cap = 0;
}

/* ---- neighbour lists that follow moving particles ---- */

/* The grid, its workspace and the CSR arrays of sph_nsearch (section 7 of
 * sph_kernel.h), kept between steps and grown when a step needs more. */
typedef struct {
    sph_nsearch g;
    void *work;
    size_t work_bytes;
    sph_off *offset;
    sph_idx *index;
    sph_idx n_targets_cap;
    sph_off index_cap;
    sph_neighbours list;
} ex_neighbours;

/* Rebuilds the gather lists (R = kappa h) of targets 0..nt-1 = the first nt
 * of the ns sources at positions x (dim components), cells of kappa h / 2.
 * Returns SPH_OK or the search's status (or SPH_ESIZE when out of memory). */
static inline int ex_neighbours_update(ex_neighbours *L, int dim, sph_view x, sph_idx ns, sph_idx nt,
                                       sph_real h, sph_real kappa, const sph_box *box)
{
    const sph_real cell = kappa * h / 2;
    size_t bytes;
    int st = sph_nsearch_workspace_size(dim, x, ns, sph_view_none(), cell, box, &bytes);
    if (st != SPH_OK) return st;
    if (bytes > L->work_bytes) {
        free(L->work);
        L->work = malloc(bytes);
        L->work_bytes = L->work != NULL ? bytes : 0;
        if (L->work == NULL) return SPH_ESIZE;
    }
    if (nt + 1 > L->n_targets_cap) {
        free(L->offset);
        L->offset = (sph_off *)malloc(sizeof(sph_off) * (size_t)(nt + 1));
        L->n_targets_cap = L->offset != NULL ? nt + 1 : 0;
        if (L->offset == NULL) return SPH_ESIZE;
    }
    if ((st = sph_nsearch_build(&L->g, dim, x, ns, sph_view_none(), cell, box, L->work, L->work_bytes)) != SPH_OK ||
        (st = sph_nsearch_count(&L->g, x, nt, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, L->offset)) != SPH_OK)
        return st;
    if (L->offset[nt] > L->index_cap) {
        free(L->index);
        L->index_cap = L->offset[nt] + L->offset[nt] / 4 + 1;
        L->index = (sph_idx *)malloc(sizeof(sph_idx) * (size_t)L->index_cap);
        if (L->index == NULL) return L->index_cap = 0, SPH_ESIZE;
    }
    st = sph_nsearch_fill(&L->g, x, nt, sph_view_none(), h, kappa, SPH_NSEARCH_GATHER, L->offset, L->index,
                          L->index_cap);
    L->list = sph_nsearch_list(&L->g, nt, L->offset, L->index);
    return st;
}

static inline void ex_neighbours_free(ex_neighbours *L)
{
    free(L->work);
    free(L->offset);
    free(L->index);
    memset(L, 0, sizeof *L);
}

#endif
