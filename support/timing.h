/* support/timing.h - wall-clock time and medians for the programs that time
 * the library (bench/, studies/error_vs_runtime.c): every quoted time is a
 * median of repeats. clock_gettime needs _POSIX_C_SOURCE 199309L (or later)
 * defined before the first system header of the including file.
 */
#ifndef SPH_SUPPORT_TIMING_H
#define SPH_SUPPORT_TIMING_H

#include <stdlib.h>
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

#endif
