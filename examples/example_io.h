/* examples/example_io.h - the small I/O every example solver needs, kept out
 * of the solvers so they read as physics: command-line options with --help,
 * a one-line progress indicator (elapsed time and ETA on stderr), legacy VTK
 * particle files that ParaView opens, and output directories.
 * Not part of the library: sph_kernel.h does no I/O. POSIX (clock_gettime,
 * mkdir); define _POSIX_C_SOURCE before any system header, as below. */
#ifndef SPH_EXAMPLE_IO_H
#define SPH_EXAMPLE_IO_H

#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "sph_kernel.h"

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

static inline void ex_usage(const char *prog, const char *about, const ex_option *opt, int n)
{
    int i;
    printf("%s - %s\n\nusage: %s [options]\n\n", prog, about, prog);
    for (i = 0; i < n; ++i) {
        char def[64] = "";
        if (opt[i].real) snprintf(def, sizeof def, " (default %g)", *opt[i].real);
        if (opt[i].integer) snprintf(def, sizeof def, " (default %d)", *opt[i].integer);
        if (opt[i].text && *opt[i].text) snprintf(def, sizeof def, " (default %s)", *opt[i].text);
        printf("  --%-14s %s%s\n", opt[i].name, opt[i].help, def);
    }
    printf("  --%-14s %s\n", "help", "this text");
}

/* Parses argv into the options. Returns 0 to run, 1 after --help (exit 0),
 * -1 on an unknown option or a missing/bad value (a message on stderr). */
static inline int ex_parse(int argc, char **argv, const char *about, const ex_option *opt, int n)
{
    int a, i;
    for (a = 1; a < argc; ++a) {
        const char *s = argv[a];
        if (strcmp(s, "--help") == 0 || strcmp(s, "-h") == 0) {
            ex_usage(argv[0], about, opt, n);
            return 1;
        }
        for (i = 0; i < n; ++i)
            if (strncmp(s, "--", 2) == 0 && strcmp(s + 2, opt[i].name) == 0) break;
        if (i == n) {
            fprintf(stderr, "%s: unknown option '%s' (try --help)\n", argv[0], s);
            return -1;
        }
        if (opt[i].flag) {
            *opt[i].flag = 1;
            continue;
        }
        if (a + 1 >= argc) {
            fprintf(stderr, "%s: option '%s' needs a value\n", argv[0], s);
            return -1;
        }
        ++a;
        if (opt[i].text) {
            *opt[i].text = argv[a];
        } else {
            char *end = NULL;
            double v = strtod(argv[a], &end);
            if (end == argv[a] || *end != '\0') {
                fprintf(stderr, "%s: bad value '%s' for '%s'\n", argv[0], argv[a], s);
                return -1;
            }
            if (opt[i].real) *opt[i].real = v;
            if (opt[i].integer) *opt[i].integer = (int)v;
        }
    }
    return 0;
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
    return 0;
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
