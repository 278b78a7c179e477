/* tests/harness.h - the project's assertion harness.
 *
 * A test program is a list of cases. A case passes when none of its checks
 * fails; the program ends with one line "N passed, N failed" (cases) and exits
 * non-zero when any case failed. tests/run.sh adds the lines of every program
 * and every build configuration into the final count.
 *
 *   th_begin("normalisation %s %dD", name, dim);
 *   TH_CHECK(x > 0, "x = %g", x);
 *   TH_NEAR(value, reference, rel_tol);   relative, with |reference| floor 1
 *   TH_CLOSE(value, reference, abs_tol);  absolute
 *   th_end();
 *   return th_summary();
 *
 * TH_EPS is the machine epsilon of sph_real (the precision under test).
 *
 * SPH_TEST_ISA=portable|avx2|avx512 in the environment runs the program's
 * fast loops at that level (sph_isa_set, before the first case); a level
 * the unit or the CPU does not have is a failed case, not a quiet fallback.
 */
#ifndef SPH_TEST_HARNESS_H
#define SPH_TEST_HARNESS_H

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "sph_kernel.h"

#define TH_IS_FLOAT (sizeof(sph_real) == sizeof(float))
#define TH_EPS (TH_IS_FLOAT ? (double)FLT_EPSILON : (double)DBL_EPSILON)
#define TH_PRECISION (TH_IS_FLOAT ? "float" : "double")

static int th_passed, th_failed, th_case_bad, th_case_open, th_quiet_fails, th_isa_read;
static char th_case_name[256];

/* SPH_TEST_ISA: the level every case runs at (see above). */
static inline void th_isa_from_env(void)
{
    const char *want = getenv("SPH_TEST_ISA");
    int isa, st = SPH_EOPTION;
    th_isa_read = 1;
    if (want == NULL || *want == 0) return;
    for (isa = SPH_ISA_PORTABLE; isa <= SPH_ISA_AVX512; ++isa)
        if (strcmp(want, sph_isa_name(isa)) == 0) st = sph_isa_set(isa);
    if (st != SPH_OK) {
        printf("FAIL SPH_TEST_ISA=%s: %s\n", want, sph_strerror(st));
        ++th_failed;
    }
}

static inline void th_begin(const char *fmt, ...)
{
    va_list ap;
    if (!th_isa_read) th_isa_from_env();
    va_start(ap, fmt);
    vsnprintf(th_case_name, sizeof th_case_name, fmt, ap);
    va_end(ap);
    th_case_bad = 0;
    th_case_open = 1;
    th_quiet_fails = 0;
}

static inline void th_end(void)
{
    if (!th_case_open) return;
    if (th_case_bad) {
        ++th_failed;
        if (th_quiet_fails) printf("    (%d more failed checks in this case)\n", th_quiet_fails);
    } else {
        ++th_passed;
    }
    th_case_open = 0;
}

/* Records a failed check; prints the first five of a case. */
static inline void th_fail(const char *file, int line, const char *fmt, ...)
{
    va_list ap;
    if (th_case_bad >= 5) {
        ++th_quiet_fails;
        ++th_case_bad;
        return;
    }
    if (th_case_bad == 0) printf("FAIL [%s] %s\n", TH_PRECISION, th_case_name);
    ++th_case_bad;
    printf("    %s:%d: ", file, line);
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    printf("\n");
}

#define TH_CHECK(cond, ...)                                                    \
    do {                                                                       \
        if (!(cond)) th_fail(__FILE__, __LINE__, __VA_ARGS__);                 \
    } while (0)

/* |a - b| <= tol * max(1, |b|) ... relative with a floor: use TH_REL for pure relative. */
#define TH_NEAR(a, b, tol)                                                     \
    do {                                                                       \
        double th_a_ = (double)(a), th_b_ = (double)(b), th_t_ = (double)(tol); \
        double th_s_ = fabs(th_b_) > 1 ? fabs(th_b_) : 1;                       \
        if (!(fabs(th_a_ - th_b_) <= th_t_ * th_s_))                           \
            th_fail(__FILE__, __LINE__, "%s = %.17g, expected %.17g (tol %.3g)", #a, th_a_, \
                    th_b_, th_t_);                                             \
    } while (0)

/* |a - b| <= tol * |b| (pure relative). */
#define TH_REL(a, b, tol)                                                      \
    do {                                                                       \
        double th_a_ = (double)(a), th_b_ = (double)(b), th_t_ = (double)(tol); \
        if (!(fabs(th_a_ - th_b_) <= th_t_ * fabs(th_b_)))                     \
            th_fail(__FILE__, __LINE__, "%s = %.17g, expected %.17g (rel tol %.3g, rel err %.3g)", \
                    #a, th_a_, th_b_, th_t_, fabs(th_a_ - th_b_) / fabs(th_b_)); \
    } while (0)

/* |a - b| <= tol. */
#define TH_CLOSE(a, b, tol)                                                    \
    do {                                                                       \
        double th_a_ = (double)(a), th_b_ = (double)(b), th_t_ = (double)(tol); \
        if (!(fabs(th_a_ - th_b_) <= th_t_))                                   \
            th_fail(__FILE__, __LINE__, "%s = %.17g, expected %.17g (abs tol %.3g)", #a, th_a_, \
                    th_b_, th_t_);                                             \
    } while (0)

/* The OpenMP thread count of the next parallel region (nothing without OpenMP). */
static inline void th_set_threads(int n)
{
#ifdef _OPENMP
    omp_set_num_threads(n);
#else
    (void)n;
#endif
}

#if !defined(SPH_ONLY_KERNELS)
/* Views of one array: one component per particle (th_in1, th_out1) or three interleaved (th_out3). */
static inline sph_view th_in1(const sph_real *p) { return sph_view_soa(p, NULL, NULL); }
static inline sph_out th_out1(sph_real *p) { return sph_out_soa(p, NULL, NULL); }
static inline sph_out th_out3(sph_real *p) { return sph_out_interleaved(p, 3); }
#endif

/* Prints the closing line; exit status for main. */
static inline int th_summary(void)
{
    th_end();
    printf("fast loops at %s (run-time dispatch %s)\n", sph_isa_name(sph_isa()), sph_isa_dispatch() ? "on" : "off");
    printf("%d passed, %d failed\n", th_passed, th_failed);
    return th_failed == 0 ? 0 : 1;
}

#endif
