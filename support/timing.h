/* support/timing.h - wall-clock time, medians and the machine's name for the
 * programs that time the library (bench/, studies/error_vs_runtime.c,
 * studies/flows_vs_runtime.c): every quoted time is a median of repeats or
 * a CPU time, and every table names the machine. clock_gettime needs
 * _POSIX_C_SOURCE 199309L (or later) defined before the first system header
 * of the including file.
 */
#ifndef SPH_SUPPORT_TIMING_H
#define SPH_SUPPORT_TIMING_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Seconds on the monotonic clock. */
static inline double tm_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* qsort order of doubles, ascending. */
static inline int tm_cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of t[0 .. n-1], n >= 1 (sorts t in place). */
static inline double tm_median(double *t, int n)
{
    qsort(t, (size_t)n, sizeof(double), tm_cmp_double);
    return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

/* The machine the times come from, as make bench names it: the CPU model and
 * vendor from /proc/cpuinfo (where there is one), AVX-512 or not, and the
 * number of logical CPUs. */
static inline void tm_machine(char *buf, size_t n)
{
    char line[4096], model[256] = "unknown CPU", vendor[64] = "unknown vendor";
    int avx512 = 0, cpus = 0;
    FILE *f = fopen("/proc/cpuinfo", "r");
    while (f != NULL && fgets(line, sizeof line, f) != NULL) {
        char *v = strchr(line, ':');
        if (v == NULL) continue;
        v += v[1] == ' ' ? 2 : 1;
        v[strcspn(v, "\n")] = '\0';
        if (strncmp(line, "model name", 10) == 0 && cpus <= 1) snprintf(model, sizeof model, "%s", v);
        if (strncmp(line, "vendor_id", 9) == 0) snprintf(vendor, sizeof vendor, "%s", v);
        if (strncmp(line, "processor", 9) == 0) ++cpus;
        if (strncmp(line, "flags", 5) == 0 && strstr(v, "avx512f") != NULL) avx512 = 1;
    }
    if (f != NULL) fclose(f);
    snprintf(buf, n, "%s (%s, %s), %d logical CPUs", model, vendor, avx512 ? "AVX-512" : "no AVX-512", cpus);
}

#endif
