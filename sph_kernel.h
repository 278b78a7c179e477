/* sph_kernel.h - Smoothed Particle Hydrodynamics kernels and kernel-sum operators
 * in one C99 header. MIT licence (see the end of this file and LICENSE).
 *
 * ==== USAGE ================================================================
 *
 *   #include "sph_kernel.h"            (every function is static inline)
 *
 *   sph_real W, F;
 *   sph_kernel_wf(SPH_KERNEL_CUBIC, 3, r, h, &W, &F);   W and F = (1/r) dW/dr
 *   grad_i W_ij = F * (x_i - x_j)                       (design sign convention)
 *
 * Conventions (docs/kernels.md, docs/operators.md): x_ij = x_i - x_j,
 * r = |x_ij|, q = r/h, W(r,h) = alpha_d h^-d w(q), w = 0 for q >= kappa,
 * grad_i W_ij = F x_ij with F = (1/r) dW/dr = alpha_d h^-(d+2) w'(q)/q, which
 * is finite at r = 0 for every kernel here: no division by r anywhere.
 *
 * Scalar kernel functions never fail loudly: for an unknown kernel, a
 * dimension the kernel is not defined in, r < 0, r or h not finite, h <= 0
 * (or h so small that some kernel's W or F in that dimension would overflow:
 * 64 h^-(d+2) beyond the largest sph_real) they return 0 (and write zeros).
 * Use sph_kernel_check(k, dim) and sph_check_h(h) to validate once, outside
 * hot loops.
 *
 * ==== CONFIGURATION (define before including) ==============================
 *
 *   SPH_REAL    floating type of every real number: double (default) or float.
 *   SPH_API     storage of every function; default `static inline`, plus
 *               `__host__ __device__` when compiled by nvcc.
 *   SPH_DIM     pin the dimension of the array operators (1, 2 or 3): only
 *               that dimension's loops are compiled; a context with another
 *               dim gets SPH_EDIM. Default: all three, chosen at run time.
 *   SPH_KERNEL  pin the kernel of the array operators (e.g. SPH_KERNEL_CUBIC):
 *               only its loops are compiled; another ctx.kernel gets
 *               SPH_EKERNEL. The scalar kernel functions take any kernel.
 *               Pinning changes code size and compile time, not speed: the
 *               run-time choice is made once per call, outside the pair loop
 *               (examples/benchmark.c measures both).
 *   SPH_OP_SPECIALISE  1 (default): one operator loop per kernel x dimension,
 *               the kernel's natural pieces and their coefficients folded at
 *               compile time, so the pair loop vectorises. 0: one loop per
 *               dimension, the kernel read at run time (scalar pair loop).
 *               On the 2-core Intel Xeon (AVX-512) of docs/benchmark.md, 0
 *               compiled a unit calling sph_gradient 3.7x faster into an
 *               object 3.1x smaller (`make tiny-size`), and the fused density
 *               + gradient pass took 1.19x the time in double, 1.25x in float
 *               (`make bench`; docs/benchmark.md has the current figures). 1
 *               for production builds, 0 while developing. Pinning SPH_KERNEL
 *               makes the choice moot: one kernel, one loop either way.
 *   SPH_NO_INTRINSICS  use only portable C: no SSE/AVX square-root helper in
 *               the operator loops, no AVX-512 one-pass loop for the density
 *               and difference gradient (results within 1e-13 of the pair
 *               sum either way, tested; the order of the sum over j
 *               differs) and no AVX-512 compress in the neighbour fill
 *               (same lists); slower.
 *
 * The version is SPH_KERNEL_VERSION (major*10000 + minor*100 + patch) and
 * SPH_KERNEL_VERSION_STRING.
 *
 * ==== SECTIONS =============================================================
 *   1. configuration   2. status codes   3. kernels   4. particle data (views,
 *   neighbour lists, box)   5. pair terms   6. array operators   7. neighbour search
 */
#ifndef SPH_KERNEL_H
#define SPH_KERNEL_H

/* ======================================================================== */
/* 1. Configuration                                                          */
/* ======================================================================== */

#define SPH_KERNEL_VERSION_MAJOR 0
#define SPH_KERNEL_VERSION_MINOR 1
#define SPH_KERNEL_VERSION_PATCH 0
#define SPH_KERNEL_VERSION \
    (SPH_KERNEL_VERSION_MAJOR * 10000 + SPH_KERNEL_VERSION_MINOR * 100 + SPH_KERNEL_VERSION_PATCH)
#define SPH_KERNEL_VERSION_STRING "0.1.0"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#ifdef _OPENMP
#include <omp.h> /* only when the program is built with OpenMP: thread count of sph_nsearch_lists */
#endif

#ifndef SPH_REAL
#define SPH_REAL double
#endif
typedef SPH_REAL sph_real;

#if defined(__CUDACC__)
#define SPH_HOSTDEV __host__ __device__
#else
#define SPH_HOSTDEV
#endif

#ifndef SPH_API
#define SPH_API static inline SPH_HOSTDEV
#endif

/* Vector square roots for the operator loops (section 6): AVX (2), SSE2 (1),
 * none (0: portable loop). */
#if !defined(SPH_NO_INTRINSICS) && !defined(__CUDACC__) && (defined(__GNUC__) || defined(__clang__)) && \
    (defined(__AVX__) || defined(__SSE2__))
#include <immintrin.h>
#if defined(__AVX__)
#define SPH__SQRT_SIMD 2
#else
#define SPH__SQRT_SIMD 1
#endif
#else
#define SPH__SQRT_SIMD 0
#endif

/* Neighbour fill (section 7): AVX-512 VL compress of a block's accepted
 * source indices (1), or the portable store-all-and-advance loop (0). */
#if SPH__SQRT_SIMD == 2 && defined(__AVX512VL__) && defined(__AVX512F__)
#define SPH__NS_COMPRESS 1
#else
#define SPH__NS_COMPRESS 0
#endif

/* Operator pair loops (section 6): the density and the difference gradient
 * in AVX-512 registers, 8 pairs per step in one pass (1), or the portable
 * chunked loops only (0). Both precisions: with SPH_REAL float the values
 * are read as float and the pair terms computed in double (8 lanes), then
 * the sums rounded to float once. */
#if SPH__SQRT_SIMD == 2 && defined(__AVX512F__) && defined(__AVX512VL__)
#define SPH__OP_AVX512 1
#else
#define SPH__OP_AVX512 0
#endif

#ifndef SPH_OP_SPECIALISE
#define SPH_OP_SPECIALISE 1
#endif

/* Tables are read by host and device code alike: under nvcc the device pass
 * keeps its own copy in device memory. */
#if defined(__CUDACC__) && defined(__CUDA_ARCH__)
#define SPH__TABLE static __device__ const
#else
#define SPH__TABLE static const
#endif

/* An exact rational (or decimal) constant, rounded once to sph_real. */
#define SPH__Q(n, d) ((sph_real)((double)(n) / (double)(d)))
#define SPH__C(x) ((sph_real)(x))

/* Largest finite sph_real, whatever SPH_REAL is. */
#define SPH__REAL_MAX (sizeof(sph_real) == sizeof(float) ? (sph_real)FLT_MAX : (sph_real)DBL_MAX)

#ifdef __cplusplus
extern "C" {
#endif

/* libm in the precision of sph_real (the sizeof test folds at compile time). */
SPH_API sph_real sph__sqrt(sph_real x)
{
    return sizeof(sph_real) == sizeof(float) ? (sph_real)sqrtf((float)x) : (sph_real)sqrt((double)x);
}

SPH_API sph_real sph__floor(sph_real x)
{
    return sizeof(sph_real) == sizeof(float) ? (sph_real)floorf((float)x) : (sph_real)floor((double)x);
}

/* 1 when x is finite (neither NaN nor +-Inf), without isfinite's double promotion. */
SPH_API int sph__finite(sph_real x) { return x >= -SPH__REAL_MAX && x <= SPH__REAL_MAX; }


/* ======================================================================== */
/* 2. Status codes                                                           */
/* ======================================================================== */

/* One list generates the status enum and the sentences of sph_strerror:
 * X(name, value, sentence). Every function that can fail returns SPH_OK or
 * one of the negative codes; the values never change between versions. */
#define SPH_STATUS_LIST(X) \
    X(SPH_OK, 0, "success") \
    X(SPH_EKERNEL, -1, "unknown kernel") \
    X(SPH_EDIM, -2, "dimension outside 1..3 or not defined for this kernel") \
    X(SPH_EH, -3, "smoothing length not positive and finite, or so small that W or F would overflow") \
    X(SPH_ENULL, -4, "NULL pointer where data is required") \
    X(SPH_EINDEX, -5, "neighbour index out of range") \
    X(SPH_ESIZE, -6, "negative or too large count, or an array or workspace too small") \
    X(SPH_ENONFINITE, -7, "NaN or Inf in an input array") \
    X(SPH_EINVAL, -8, "invalid argument") \
    X(SPH_EGRID, -9, "neighbour grid too large: a source far from the others, or a cell size too small") \
    X(SPH_EPERIOD, -10, "periodic box shorter than twice the search radius kappa h")

enum {
#define SPH__STATUS_ENUM(name, value, sentence) name = value,
    SPH_STATUS_LIST(SPH__STATUS_ENUM)
#undef SPH__STATUS_ENUM
};

/* A sentence for a status code; never NULL. */
SPH_API const char *sph_strerror(int status)
{
    switch (status) {
#define SPH__STATUS_CASE(name, value, sentence) \
    case name: return sentence;
        SPH_STATUS_LIST(SPH__STATUS_CASE)
#undef SPH__STATUS_CASE
    default: return "unknown status code";
    }
}

/* ======================================================================== */
/* 3. Kernels                                                                */
/* ======================================================================== */

typedef enum {
    SPH_KERNEL_CUBIC,       /* cubic B-spline M4, kappa = 2, C2          */
    SPH_KERNEL_LUCY,        /* Lucy quartic, kappa = 1, C2               */
    SPH_KERNEL_NEW_QUARTIC, /* Liu & Liu new quartic, kappa = 2, C1       */
    SPH_KERNEL_QUINTIC,     /* quintic B-spline M6, kappa = 3, C4        */
    SPH_KERNEL_WENDLAND_C2, /* Wendland C2, kappa = 2                    */
    SPH_KERNEL_WENDLAND_C4, /* Wendland C4, kappa = 2                    */
    SPH_KERNEL_WENDLAND_C6, /* Wendland C6, kappa = 2                    */
    SPH_KERNEL_COUNT
} sph_kernel;

/* One dimensionless shape w(q), cut into pieces of equal width. */
typedef struct {
    sph_real kappa;     /* support in units of h */
    sph_real inv_width; /* 1 / piece width: the piece of q is (int)(q * inv_width) */
    int npiece;         /* pieces before the zero row */
    int degree;         /* polynomial degree of every piece (zero-padded) */
    int offset;         /* first coefficient in sph__coef */
} sph__shape;

/* A kernel in one dimension: which shape, its normalisation, its width. */
typedef struct {
    int shape;      /* index into sph__shapes */
    sph_real alpha; /* alpha_d: W = alpha_d h^-d w(q) */
    sph_real sigma; /* standard deviation per coordinate, in units of h */
} sph__kdim;

/* One product form (b - q)^m P(q - e), P of the given degree, lowest power first. */
typedef struct {
    sph_real b, e;
    int m, degree;
    sph_real c[6];
} sph__pform;

/* A shape over its natural pieces (at most 3), each in product form, for
 * evaluation without a per-pair table row: w, and g = w'(q)/q on the piece
 * holding 0, w'(q) on the others (divided by q at run time). */
typedef struct {
    int npiece;
    sph_real kappa;
    sph_real lo[3]; /* piece p holds q in [lo[p], lo[p + 1]) */
    struct {
        sph__pform w, g;
    } piece[3];
} sph__nshape;

enum { SPH__SHAPE_COUNT = 10 };

/* ---- GENERATED by tools/gen_kernel_tables.py: do not edit by hand ---- */
/* Per piece [a, b): c, den0, den1, then w, g, w2 as deg+1 coefficients each
   (lowest power first) in u = q - c; F = alpha h^-(d+2) g(u) / (den0 + den1 q),
   W = alpha h^-d w(u), d2W/dr2 = alpha h^-(d+2) w2(u). The last row of each
   shape is the zero row used for q >= kappa (and for NaN q).            */
SPH__TABLE sph_real sph__coef[] = {
    /* cubic spline (M4), Monaghan & Lattanzio 1985, kappa = 2, degree 3 */
    /*   w = (3*q**3 - 6*q**2 + 4)/6  on [0, 1) */
    /*   w = -(q - 2)**3/6  on [1, 2) */
    /* [0, 1/2) c = 0 */ 0, 1, 0,
        /* w   */ SPH__Q(2, 3), 0, SPH__Q(-1, 1), SPH__Q(1, 2),
        /* g   */ SPH__Q(-2, 1), SPH__Q(3, 2), 0, 0,
        /* w2  */ SPH__Q(-2, 1), SPH__Q(3, 1), 0, 0,
    /* [1/2, 1) c = 1 */ SPH__Q(1, 1), 0, 1,
        /* w   */ SPH__Q(1, 6), SPH__Q(-1, 2), SPH__Q(1, 2), SPH__Q(1, 2),
        /* g   */ SPH__Q(-1, 2), SPH__Q(1, 1), SPH__Q(3, 2), 0,
        /* w2  */ SPH__Q(1, 1), SPH__Q(3, 1), 0, 0,
    /* [1, 3/2) c = 3/2 */ SPH__Q(3, 2), 0, 1,
        /* w   */ SPH__Q(1, 48), SPH__Q(-1, 8), SPH__Q(1, 4), SPH__Q(-1, 6),
        /* g   */ SPH__Q(-1, 8), SPH__Q(1, 2), SPH__Q(-1, 2), 0,
        /* w2  */ SPH__Q(1, 2), SPH__Q(-1, 1), 0, 0,
    /* [3/2, 2) c = 2 */ SPH__Q(2, 1), 0, 1,
        /* w   */ 0, 0, 0, SPH__Q(-1, 6),
        /* g   */ 0, 0, SPH__Q(-1, 2), 0,
        /* w2  */ 0, SPH__Q(-1, 1), 0, 0,
    /* zero row */ 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    /* Lucy quartic, Lucy 1977, kappa = 1, degree 4 */
    /*   w = -(q - 1)**3*(3*q + 1)  on [0, 1) */
    /* [0, 1/2) c = 0 */ 0, 1, 0,
        /* w   */ SPH__Q(1, 1), 0, SPH__Q(-6, 1), SPH__Q(8, 1), SPH__Q(-3, 1),
        /* g   */ SPH__Q(-12, 1), SPH__Q(24, 1), SPH__Q(-12, 1), 0, 0,
        /* w2  */ SPH__Q(-12, 1), SPH__Q(48, 1), SPH__Q(-36, 1), 0, 0,
    /* [1/2, 1) c = 1 */ SPH__Q(1, 1), 0, 1,
        /* w   */ 0, 0, 0, SPH__Q(-4, 1), SPH__Q(-3, 1),
        /* g   */ 0, 0, SPH__Q(-12, 1), SPH__Q(-12, 1), 0,
        /* w2  */ 0, SPH__Q(-24, 1), SPH__Q(-36, 1), 0, 0,
    /* zero row */ 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    /* new quartic, Liu & Liu 2003, kappa = 2, degree 4 */
    /*   w = -(q - 2)**2*(15*q**2 - 16*q - 16)/96  on [0, 2) */
    /* [0, 1/2) c = 0 */ 0, 1, 0,
        /* w   */ SPH__Q(2, 3), 0, SPH__Q(-9, 8), SPH__Q(19, 24), SPH__Q(-5, 32),
        /* g   */ SPH__Q(-9, 4), SPH__Q(19, 8), SPH__Q(-5, 8), 0, 0,
        /* w2  */ SPH__Q(-9, 4), SPH__Q(19, 4), SPH__Q(-15, 8), 0, 0,
    /* [1/2, 1) c = 1 */ SPH__Q(1, 1), 0, 1,
        /* w   */ SPH__Q(17, 96), SPH__Q(-1, 2), SPH__Q(5, 16), SPH__Q(1, 6), SPH__Q(-5, 32),
        /* g   */ SPH__Q(-1, 2), SPH__Q(5, 8), SPH__Q(1, 2), SPH__Q(-5, 8), 0,
        /* w2  */ SPH__Q(5, 8), SPH__Q(1, 1), SPH__Q(-15, 8), 0, 0,
    /* [1, 3/2) c = 3/2 */ SPH__Q(3, 2), 0, 1,
        /* w   */ SPH__Q(25, 1536), SPH__Q(-9, 64), SPH__Q(21, 64), SPH__Q(-7, 48), SPH__Q(-5, 32),
        /* g   */ SPH__Q(-9, 64), SPH__Q(21, 32), SPH__Q(-7, 16), SPH__Q(-5, 8), 0,
        /* w2  */ SPH__Q(21, 32), SPH__Q(-7, 8), SPH__Q(-15, 8), 0, 0,
    /* [3/2, 2) c = 2 */ SPH__Q(2, 1), 0, 1,
        /* w   */ 0, 0, SPH__Q(-1, 8), SPH__Q(-11, 24), SPH__Q(-5, 32),
        /* g   */ 0, SPH__Q(-1, 4), SPH__Q(-11, 8), SPH__Q(-5, 8), 0,
        /* w2  */ SPH__Q(-1, 4), SPH__Q(-11, 4), SPH__Q(-15, 8), 0, 0,
    /* zero row */ 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    /* quintic spline (M6), Morris 1996, kappa = 3, degree 5 */
    /*   w = -2*(5*q**5 - 15*q**4 + 30*q**2 - 33)  on [0, 1) */
    /*   w = 5*q**5 - 45*q**4 + 150*q**3 - 210*q**2 + 75*q + 51  on [1, 2) */
    /*   w = -(q - 3)**5  on [2, 3) */
    /* [0, 1/2) c = 0 */ 0, 1, 0,
        /* w   */ SPH__Q(66, 1), 0, SPH__Q(-60, 1), 0, SPH__Q(30, 1), SPH__Q(-10, 1),
        /* g   */ SPH__Q(-120, 1), 0, SPH__Q(120, 1), SPH__Q(-50, 1), 0, 0,
        /* w2  */ SPH__Q(-120, 1), 0, SPH__Q(360, 1), SPH__Q(-200, 1), 0, 0,
    /* [1/2, 1) c = 1 */ SPH__Q(1, 1), 0, 1,
        /* w   */ SPH__Q(26, 1), SPH__Q(-50, 1), SPH__Q(20, 1), SPH__Q(20, 1), SPH__Q(-20, 1), SPH__Q(-10, 1),
        /* g   */ SPH__Q(-50, 1), SPH__Q(40, 1), SPH__Q(60, 1), SPH__Q(-80, 1), SPH__Q(-50, 1), 0,
        /* w2  */ SPH__Q(40, 1), SPH__Q(120, 1), SPH__Q(-240, 1), SPH__Q(-200, 1), 0, 0,
    /* [1, 3/2) c = 3/2 */ SPH__Q(3, 2), 0, 1,
        /* w   */ SPH__Q(237, 32), SPH__Q(-375, 16), SPH__Q(105, 4), SPH__Q(-15, 2), SPH__Q(-15, 2), SPH__Q(5, 1),
        /* g   */ SPH__Q(-375, 16), SPH__Q(105, 2), SPH__Q(-45, 2), SPH__Q(-30, 1), SPH__Q(25, 1), 0,
        /* w2  */ SPH__Q(105, 2), SPH__Q(-45, 1), SPH__Q(-90, 1), SPH__Q(100, 1), 0, 0,
    /* [3/2, 2) c = 2 */ SPH__Q(2, 1), 0, 1,
        /* w   */ SPH__Q(1, 1), SPH__Q(-5, 1), SPH__Q(10, 1), SPH__Q(-10, 1), SPH__Q(5, 1), SPH__Q(5, 1),
        /* g   */ SPH__Q(-5, 1), SPH__Q(20, 1), SPH__Q(-30, 1), SPH__Q(20, 1), SPH__Q(25, 1), 0,
        /* w2  */ SPH__Q(20, 1), SPH__Q(-60, 1), SPH__Q(60, 1), SPH__Q(100, 1), 0, 0,
    /* [2, 5/2) c = 5/2 */ SPH__Q(5, 2), 0, 1,
        /* w   */ SPH__Q(1, 32), SPH__Q(-5, 16), SPH__Q(5, 4), SPH__Q(-5, 2), SPH__Q(5, 2), SPH__Q(-1, 1),
        /* g   */ SPH__Q(-5, 16), SPH__Q(5, 2), SPH__Q(-15, 2), SPH__Q(10, 1), SPH__Q(-5, 1), 0,
        /* w2  */ SPH__Q(5, 2), SPH__Q(-15, 1), SPH__Q(30, 1), SPH__Q(-20, 1), 0, 0,
    /* [5/2, 3) c = 3 */ SPH__Q(3, 1), 0, 1,
        /* w   */ 0, 0, 0, 0, 0, SPH__Q(-1, 1),
        /* g   */ 0, 0, 0, 0, SPH__Q(-5, 1), 0,
        /* w2  */ 0, 0, 0, SPH__Q(-20, 1), 0, 0,
    /* zero row */ 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    /* Wendland C2 (2-D/3-D), Wendland 1995, kappa = 2, degree 5 */
    /*   w = (q - 2)**4*(2*q + 1)/16  on [0, 2) */
    /* [0, 1/2) c = 0 */ 0, 1, 0,
        /* w   */ SPH__Q(1, 1), 0, SPH__Q(-5, 2), SPH__Q(5, 2), SPH__Q(-15, 16), SPH__Q(1, 8),
        /* g   */ SPH__Q(-5, 1), SPH__Q(15, 2), SPH__Q(-15, 4), SPH__Q(5, 8), 0, 0,
        /* w2  */ SPH__Q(-5, 1), SPH__Q(15, 1), SPH__Q(-45, 4), SPH__Q(5, 2), 0, 0,
    /* [1/2, 1) c = 1 */ SPH__Q(1, 1), 0, 1,
        /* w   */ SPH__Q(3, 16), SPH__Q(-5, 8), SPH__Q(5, 8), 0, SPH__Q(-5, 16), SPH__Q(1, 8),
        /* g   */ SPH__Q(-5, 8), SPH__Q(5, 4), 0, SPH__Q(-5, 4), SPH__Q(5, 8), 0,
        /* w2  */ SPH__Q(5, 4), 0, SPH__Q(-15, 4), SPH__Q(5, 2), 0, 0,
    /* [1, 3/2) c = 3/2 */ SPH__Q(3, 2), 0, 1,
        /* w   */ SPH__Q(1, 64), SPH__Q(-15, 128), SPH__Q(5, 16), SPH__Q(-5, 16), 0, SPH__Q(1, 8),
        /* g   */ SPH__Q(-15, 128), SPH__Q(5, 8), SPH__Q(-15, 16), 0, SPH__Q(5, 8), 0,
        /* w2  */ SPH__Q(5, 8), SPH__Q(-15, 8), 0, SPH__Q(5, 2), 0, 0,
    /* [3/2, 2) c = 2 */ SPH__Q(2, 1), 0, 1,
        /* w   */ 0, 0, 0, 0, SPH__Q(5, 16), SPH__Q(1, 8),
        /* g   */ 0, 0, 0, SPH__Q(5, 4), SPH__Q(5, 8), 0,
        /* w2  */ 0, 0, SPH__Q(15, 4), SPH__Q(5, 2), 0, 0,
    /* zero row */ 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    /* Wendland C4 (2-D/3-D), Wendland 1995, kappa = 2, degree 8 */
    /*   w = (q - 2)**6*(35*q**2 + 36*q + 12)/768  on [0, 2) */
    /* [0, 1/2) c = 0 */ 0, 1, 0,
        /* w   */ SPH__Q(1, 1), 0, SPH__Q(-7, 3), 0, SPH__Q(35, 8), SPH__Q(-14, 3), SPH__Q(35, 16), SPH__Q(-1, 2), SPH__Q(35, 768),
        /* g   */ SPH__Q(-14, 3), 0, SPH__Q(35, 2), SPH__Q(-70, 3), SPH__Q(105, 8), SPH__Q(-7, 2), SPH__Q(35, 96), 0, 0,
        /* w2  */ SPH__Q(-14, 3), 0, SPH__Q(105, 2), SPH__Q(-280, 3), SPH__Q(525, 8), SPH__Q(-21, 1), SPH__Q(245, 96), 0, 0,
    /* [1/2, 1) c = 1 */ SPH__Q(1, 1), 0, 1,
        /* w   */ SPH__Q(83, 768), SPH__Q(-49, 96), SPH__Q(161, 192), SPH__Q(-35, 96), SPH__Q(-175, 384), SPH__Q(49, 96), SPH__Q(-7, 192), SPH__Q(-13, 96), SPH__Q(35, 768),
        /* g   */ SPH__Q(-49, 96), SPH__Q(161, 96), SPH__Q(-35, 32), SPH__Q(-175, 96), SPH__Q(245, 96), SPH__Q(-7, 32), SPH__Q(-91, 96), SPH__Q(35, 96), 0,
        /* w2  */ SPH__Q(161, 96), SPH__Q(-35, 16), SPH__Q(-175, 32), SPH__Q(245, 24), SPH__Q(-35, 32), SPH__Q(-91, 16), SPH__Q(245, 96), 0, 0,
    /* [1, 3/2) c = 3/2 */ SPH__Q(3, 2), 0, 1,
        /* w   */ SPH__Q(193, 65536), SPH__Q(-133, 4096), SPH__Q(1757, 12288), SPH__Q(-315, 1024), SPH__Q(595, 2048), SPH__Q(7, 768), SPH__Q(-49, 256), SPH__Q(3, 64), SPH__Q(35, 768),
        /* g   */ SPH__Q(-133, 4096), SPH__Q(1757, 6144), SPH__Q(-945, 1024), SPH__Q(595, 512), SPH__Q(35, 768), SPH__Q(-147, 128), SPH__Q(21, 64), SPH__Q(35, 96), 0,
        /* w2  */ SPH__Q(1757, 6144), SPH__Q(-945, 512), SPH__Q(1785, 512), SPH__Q(35, 192), SPH__Q(-735, 128), SPH__Q(63, 32), SPH__Q(245, 96), 0, 0,
    /* [3/2, 2) c = 2 */ SPH__Q(2, 1), 0, 1,
        /* w   */ 0, 0, 0, 0, 0, 0, SPH__Q(7, 24), SPH__Q(11, 48), SPH__Q(35, 768),
        /* g   */ 0, 0, 0, 0, 0, SPH__Q(7, 4), SPH__Q(77, 48), SPH__Q(35, 96), 0,
        /* w2  */ 0, 0, 0, 0, SPH__Q(35, 4), SPH__Q(77, 8), SPH__Q(245, 96), 0, 0,
    /* zero row */ 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    /* Wendland C6 (2-D/3-D), Wendland 1995, kappa = 2, degree 11 */
    /*   w = (q - 2)**8*(16*q**3 + 25*q**2 + 16*q + 4)/1024  on [0, 2) */
    /* [0, 1/2) c = 0 */ 0, 1, 0,
        /* w   */ SPH__Q(1, 1), 0, SPH__Q(-11, 4), 0, SPH__Q(33, 8), 0, SPH__Q(-231, 32), SPH__Q(33, 4), SPH__Q(-1155, 256), SPH__Q(11, 8), SPH__Q(-231, 1024), SPH__Q(1, 64),
        /* g   */ SPH__Q(-11, 2), 0, SPH__Q(33, 2), 0, SPH__Q(-693, 16), SPH__Q(231, 4), SPH__Q(-1155, 32), SPH__Q(99, 8), SPH__Q(-1155, 512), SPH__Q(11, 64), 0, 0,
        /* w2  */ SPH__Q(-11, 2), 0, SPH__Q(99, 2), 0, SPH__Q(-3465, 16), SPH__Q(693, 2), SPH__Q(-8085, 32), SPH__Q(99, 1), SPH__Q(-10395, 512), SPH__Q(55, 32), 0, 0,
    /* [1/2, 1) c = 1 */ SPH__Q(1, 1), 0, 1,
        /* w   */ SPH__Q(61, 1024), SPH__Q(-187, 512), SPH__Q(869, 1024), SPH__Q(-99, 128), SPH__Q(-99, 512), SPH__Q(231, 256), SPH__Q(-231, 512), SPH__Q(-33, 128), SPH__Q(297, 1024), SPH__Q(-11, 512), SPH__Q(-55, 1024), SPH__Q(1, 64),
        /* g   */ SPH__Q(-187, 512), SPH__Q(869, 512), SPH__Q(-297, 128), SPH__Q(-99, 128), SPH__Q(1155, 256), SPH__Q(-693, 256), SPH__Q(-231, 128), SPH__Q(297, 128), SPH__Q(-99, 512), SPH__Q(-275, 512), SPH__Q(11, 64), 0,
        /* w2  */ SPH__Q(869, 512), SPH__Q(-297, 64), SPH__Q(-297, 128), SPH__Q(1155, 64), SPH__Q(-3465, 256), SPH__Q(-693, 64), SPH__Q(2079, 128), SPH__Q(-99, 64), SPH__Q(-2475, 512), SPH__Q(55, 32), 0, 0,
    /* [1, 3/2) c = 3/2 */ SPH__Q(3, 2), 0, 1,
        /* w   */ SPH__Q(553, 1048576), SPH__Q(-2013, 262144), SPH__Q(12397, 262144), SPH__Q(-1287, 8192), SPH__Q(9537, 32768), SPH__Q(-2079, 8192), SPH__Q(-231, 8192), SPH__Q(231, 1024), SPH__Q(-363, 4096), SPH__Q(-77, 1024), SPH__Q(33, 1024), SPH__Q(1, 64),
        /* g   */ SPH__Q(-2013, 262144), SPH__Q(12397, 131072), SPH__Q(-3861, 8192), SPH__Q(9537, 8192), SPH__Q(-10395, 8192), SPH__Q(-693, 4096), SPH__Q(1617, 1024), SPH__Q(-363, 512), SPH__Q(-693, 1024), SPH__Q(165, 512), SPH__Q(11, 64), 0,
        /* w2  */ SPH__Q(12397, 131072), SPH__Q(-3861, 4096), SPH__Q(28611, 8192), SPH__Q(-10395, 2048), SPH__Q(-3465, 4096), SPH__Q(4851, 512), SPH__Q(-2541, 512), SPH__Q(-693, 128), SPH__Q(1485, 512), SPH__Q(55, 32), 0, 0,
    /* [3/2, 2) c = 2 */ SPH__Q(2, 1), 0, 1,
        /* w   */ 0, 0, 0, 0, 0, 0, 0, 0, SPH__Q(33, 128), SPH__Q(77, 256), SPH__Q(121, 1024), SPH__Q(1, 64),
        /* g   */ 0, 0, 0, 0, 0, 0, 0, SPH__Q(33, 16), SPH__Q(693, 256), SPH__Q(605, 512), SPH__Q(11, 64), 0,
        /* w2  */ 0, 0, 0, 0, 0, 0, SPH__Q(231, 16), SPH__Q(693, 32), SPH__Q(5445, 512), SPH__Q(55, 32), 0, 0,
    /* zero row */ 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    /* Wendland C2 (1-D), Wendland 1995, kappa = 2, degree 4 */
    /*   w = -(q - 2)**3*(3*q + 2)/16  on [0, 2) */
    /* [0, 1/2) c = 0 */ 0, 1, 0,
        /* w   */ SPH__Q(1, 1), 0, SPH__Q(-3, 2), SPH__Q(1, 1), SPH__Q(-3, 16),
        /* g   */ SPH__Q(-3, 1), SPH__Q(3, 1), SPH__Q(-3, 4), 0, 0,
        /* w2  */ SPH__Q(-3, 1), SPH__Q(6, 1), SPH__Q(-9, 4), 0, 0,
    /* [1/2, 1) c = 1 */ SPH__Q(1, 1), 0, 1,
        /* w   */ SPH__Q(5, 16), SPH__Q(-3, 4), SPH__Q(3, 8), SPH__Q(1, 4), SPH__Q(-3, 16),
        /* g   */ SPH__Q(-3, 4), SPH__Q(3, 4), SPH__Q(3, 4), SPH__Q(-3, 4), 0,
        /* w2  */ SPH__Q(3, 4), SPH__Q(3, 2), SPH__Q(-9, 4), 0, 0,
    /* [1, 3/2) c = 3/2 */ SPH__Q(3, 2), 0, 1,
        /* w   */ SPH__Q(13, 256), SPH__Q(-9, 32), SPH__Q(15, 32), SPH__Q(-1, 8), SPH__Q(-3, 16),
        /* g   */ SPH__Q(-9, 32), SPH__Q(15, 16), SPH__Q(-3, 8), SPH__Q(-3, 4), 0,
        /* w2  */ SPH__Q(15, 16), SPH__Q(-3, 4), SPH__Q(-9, 4), 0, 0,
    /* [3/2, 2) c = 2 */ SPH__Q(2, 1), 0, 1,
        /* w   */ 0, 0, 0, SPH__Q(-1, 2), SPH__Q(-3, 16),
        /* g   */ 0, 0, SPH__Q(-3, 2), SPH__Q(-3, 4), 0,
        /* w2  */ 0, SPH__Q(-3, 1), SPH__Q(-9, 4), 0, 0,
    /* zero row */ 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    /* Wendland C4 (1-D), Wendland 1995, kappa = 2, degree 7 */
    /*   w = -(q - 2)**5*(4*q**2 + 5*q + 2)/64  on [0, 2) */
    /* [0, 1/2) c = 0 */ 0, 1, 0,
        /* w   */ SPH__Q(1, 1), 0, SPH__Q(-7, 4), 0, SPH__Q(35, 16), SPH__Q(-7, 4), SPH__Q(35, 64), SPH__Q(-1, 16),
        /* g   */ SPH__Q(-7, 2), 0, SPH__Q(35, 4), SPH__Q(-35, 4), SPH__Q(105, 32), SPH__Q(-7, 16), 0, 0,
        /* w2  */ SPH__Q(-7, 2), 0, SPH__Q(105, 4), SPH__Q(-35, 1), SPH__Q(525, 32), SPH__Q(-21, 8), 0, 0,
    /* [1/2, 1) c = 1 */ SPH__Q(1, 1), 0, 1,
        /* w   */ SPH__Q(11, 64), SPH__Q(-21, 32), SPH__Q(49, 64), 0, SPH__Q(-35, 64), SPH__Q(7, 32), SPH__Q(7, 64), SPH__Q(-1, 16),
        /* g   */ SPH__Q(-21, 32), SPH__Q(49, 32), 0, SPH__Q(-35, 16), SPH__Q(35, 32), SPH__Q(21, 32), SPH__Q(-7, 16), 0,
        /* w2  */ SPH__Q(49, 32), 0, SPH__Q(-105, 16), SPH__Q(35, 8), SPH__Q(105, 32), SPH__Q(-21, 8), 0, 0,
    /* [1, 3/2) c = 3/2 */ SPH__Q(3, 2), 0, 1,
        /* w   */ SPH__Q(37, 4096), SPH__Q(-21, 256), SPH__Q(287, 1024), SPH__Q(-105, 256), SPH__Q(35, 256), SPH__Q(7, 32), SPH__Q(-7, 64), SPH__Q(-1, 16),
        /* g   */ SPH__Q(-21, 256), SPH__Q(287, 512), SPH__Q(-315, 256), SPH__Q(35, 64), SPH__Q(35, 32), SPH__Q(-21, 32), SPH__Q(-7, 16), 0,
        /* w2  */ SPH__Q(287, 512), SPH__Q(-315, 128), SPH__Q(105, 64), SPH__Q(35, 8), SPH__Q(-105, 32), SPH__Q(-21, 8), 0, 0,
    /* [3/2, 2) c = 2 */ SPH__Q(2, 1), 0, 1,
        /* w   */ 0, 0, 0, 0, 0, SPH__Q(-7, 16), SPH__Q(-21, 64), SPH__Q(-1, 16),
        /* g   */ 0, 0, 0, 0, SPH__Q(-35, 16), SPH__Q(-63, 32), SPH__Q(-7, 16), 0,
        /* w2  */ 0, 0, 0, SPH__Q(-35, 4), SPH__Q(-315, 32), SPH__Q(-21, 8), 0, 0,
    /* zero row */ 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    /* Wendland C6 (1-D), Wendland 1995, kappa = 2, degree 10 */
    /*   w = -(q - 2)**7*(3*q + 2)*(7*q**2 + 8*q + 4)/1024  on [0, 2) */
    /* [0, 1/2) c = 0 */ 0, 1, 0,
        /* w   */ SPH__Q(1, 1), 0, SPH__Q(-9, 4), 0, SPH__Q(21, 8), 0, SPH__Q(-105, 32), SPH__Q(3, 1), SPH__Q(-315, 256), SPH__Q(1, 4), SPH__Q(-21, 1024),
        /* g   */ SPH__Q(-9, 2), 0, SPH__Q(21, 2), 0, SPH__Q(-315, 16), SPH__Q(21, 1), SPH__Q(-315, 32), SPH__Q(9, 4), SPH__Q(-105, 512), 0, 0,
        /* w2  */ SPH__Q(-9, 2), 0, SPH__Q(63, 2), 0, SPH__Q(-1575, 16), SPH__Q(126, 1), SPH__Q(-2205, 32), SPH__Q(18, 1), SPH__Q(-945, 512), 0, 0,
    /* [1/2, 1) c = 1 */ SPH__Q(1, 1), 0, 1,
        /* w   */ SPH__Q(95, 1024), SPH__Q(-249, 512), SPH__Q(927, 1024), SPH__Q(-63, 128), SPH__Q(-273, 512), SPH__Q(189, 256), SPH__Q(-21, 512), SPH__Q(-39, 128), SPH__Q(99, 1024), SPH__Q(23, 512), SPH__Q(-21, 1024),
        /* g   */ SPH__Q(-249, 512), SPH__Q(927, 512), SPH__Q(-189, 128), SPH__Q(-273, 128), SPH__Q(945, 256), SPH__Q(-63, 256), SPH__Q(-273, 128), SPH__Q(99, 128), SPH__Q(207, 512), SPH__Q(-105, 512), 0,
        /* w2  */ SPH__Q(927, 512), SPH__Q(-189, 64), SPH__Q(-819, 128), SPH__Q(945, 64), SPH__Q(-315, 256), SPH__Q(-819, 64), SPH__Q(693, 128), SPH__Q(207, 64), SPH__Q(-945, 512), 0, 0,
    /* [1, 3/2) c = 3/2 */ SPH__Q(3, 2), 0, 1,
        /* w   */ SPH__Q(1651, 1048576), SPH__Q(-5211, 262144), SPH__Q(26991, 262144), SPH__Q(-4473, 16384), SPH__Q(11739, 32768), SPH__Q(-945, 8192), SPH__Q(-1869, 8192), SPH__Q(183, 1024), SPH__Q(279, 4096), SPH__Q(-59, 1024), SPH__Q(-21, 1024),
        /* g   */ SPH__Q(-5211, 262144), SPH__Q(26991, 131072), SPH__Q(-13419, 16384), SPH__Q(11739, 8192), SPH__Q(-4725, 8192), SPH__Q(-5607, 4096), SPH__Q(1281, 1024), SPH__Q(279, 512), SPH__Q(-531, 1024), SPH__Q(-105, 512), 0,
        /* w2  */ SPH__Q(26991, 131072), SPH__Q(-13419, 8192), SPH__Q(35217, 8192), SPH__Q(-4725, 2048), SPH__Q(-28035, 4096), SPH__Q(3843, 512), SPH__Q(1953, 512), SPH__Q(-531, 128), SPH__Q(-945, 512), 0, 0,
    /* [3/2, 2) c = 2 */ SPH__Q(2, 1), 0, 1,
        /* w   */ 0, 0, 0, 0, 0, 0, 0, SPH__Q(-3, 8), SPH__Q(-27, 64), SPH__Q(-41, 256), SPH__Q(-21, 1024),
        /* g   */ 0, 0, 0, 0, 0, 0, SPH__Q(-21, 8), SPH__Q(-27, 8), SPH__Q(-369, 256), SPH__Q(-105, 512), 0,
        /* w2  */ 0, 0, 0, 0, 0, SPH__Q(-63, 4), SPH__Q(-189, 8), SPH__Q(-369, 32), SPH__Q(-945, 512), 0, 0,
    /* zero row */ 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0
};

SPH__TABLE sph__shape sph__shapes[] = {
    /* kappa, 1/width, pieces, degree, offset into sph__coef */
    { SPH__Q(2, 1), SPH__Q(2, 1), 4, 3, 0 }, /* 0 cubic */
    { SPH__Q(1, 1), SPH__Q(2, 1), 2, 4, 75 }, /* 1 lucy */
    { SPH__Q(2, 1), SPH__Q(2, 1), 4, 4, 129 }, /* 2 new_quartic */
    { SPH__Q(3, 1), SPH__Q(2, 1), 6, 5, 219 }, /* 3 quintic */
    { SPH__Q(2, 1), SPH__Q(2, 1), 4, 5, 366 }, /* 4 wendland_c2 */
    { SPH__Q(2, 1), SPH__Q(2, 1), 4, 8, 471 }, /* 5 wendland_c4 */
    { SPH__Q(2, 1), SPH__Q(2, 1), 4, 11, 621 }, /* 6 wendland_c6 */
    { SPH__Q(2, 1), SPH__Q(2, 1), 4, 4, 816 }, /* 7 wendland_c2_1d */
    { SPH__Q(2, 1), SPH__Q(2, 1), 4, 7, 906 }, /* 8 wendland_c4_1d */
    { SPH__Q(2, 1), SPH__Q(2, 1), 4, 10, 1041 }  /* 9 wendland_c6_1d */
};

/* Per kernel and dimension 1..3: shape index, alpha_d (exact integration of
   the shape, correctly rounded) and sigma_d / h, sigma_d^2 = int |x|^2 W d^dx / d. */
SPH__TABLE sph__kdim sph__kdims[SPH_KERNEL_COUNT][3] = {
    { /* cubic */
        { 0, SPH__C(1.00000000000000000000), SPH__C(0.577350269189625764509) }, /* 1D: alpha = 1, sigma/h = sqrt(3)/3 */
        { 0, SPH__C(0.682092613250980010438), SPH__C(0.562429133857986501406) }, /* 2D: alpha = 15/(7*pi), sigma/h = sqrt(62)/14 */
        { 0, SPH__C(0.477464829275686007307), SPH__C(0.547722557505166113457) }  /* 3D: alpha = 3/(2*pi), sigma/h = sqrt(30)/10 */
    },
    { /* lucy */
        { 1, SPH__C(1.25000000000000000000), SPH__C(0.308606699924183820522) }, /* 1D: alpha = 5/4, sigma/h = sqrt(42)/21 */
        { 1, SPH__C(1.59154943091895335769), SPH__C(0.298807152333598409992) }, /* 2D: alpha = 5/pi, sigma/h = sqrt(70)/28 */
        { 1, SPH__C(2.08890862808112628197), SPH__C(0.288675134594812882255) }  /* 3D: alpha = 105/(16*pi), sigma/h = sqrt(3)/6 */
    },
    { /* new_quartic */
        { 2, SPH__C(1.00000000000000000000), SPH__C(0.574594404914223089000) }, /* 1D: alpha = 1, sigma/h = 2*sqrt(910)/105 */
        { 2, SPH__C(0.682092613250980010438), SPH__C(0.553283335172488126454) }, /* 2D: alpha = 15/(7*pi), sigma/h = sqrt(15)/7 */
        { 2, SPH__C(0.482055837249490680454), SPH__C(0.531085004543794336722) }  /* 3D: alpha = 315/(208*pi), sigma/h = sqrt(429)/39 */
    },
    { /* quintic */
        { 3, SPH__C(0.00833333333333333333333), SPH__C(0.707106781186547524401) }, /* 1D: alpha = 1/120, sigma/h = sqrt(2)/2 */
        { 3, SPH__C(0.00466144184787977970871), SPH__C(0.695046229260274514650) }, /* 2D: alpha = 7/(478*pi), sigma/h = sqrt(3973614)/2868 */
        { 3, SPH__C(0.00265258238486492226281), SPH__C(0.683130051063973225548) }  /* 3D: alpha = 1/(120*pi), sigma/h = sqrt(105)/15 */
    },
    { /* wendland_c2 */
        { 7, SPH__C(0.625000000000000000000), SPH__C(0.617213399848367641044) }, /* 1D: alpha = 5/8, sigma/h = 2*sqrt(42)/21 */
        { 4, SPH__C(0.557042300821633675191), SPH__C(0.527046276694729888666) }, /* 2D: alpha = 7/(4*pi), sigma/h = sqrt(10)/6 */
        { 4, SPH__C(0.417781725616225256393), SPH__C(0.516397779494322251357) }  /* 3D: alpha = 21/(16*pi), sigma/h = 2*sqrt(15)/15 */
    },
    { /* wendland_c4 */
        { 8, SPH__C(0.750000000000000000000), SPH__C(0.516397779494322251357) }, /* 1D: alpha = 3/4, sigma/h = 2*sqrt(15)/15 */
        { 5, SPH__C(0.716197243913529010960), SPH__C(0.460566186471838291869) }, /* 2D: alpha = 9/(4*pi), sigma/h = sqrt(231)/33 */
        { 5, SPH__C(0.615482006488188993794), SPH__C(0.452910813657838300244) }  /* 3D: alpha = 495/(256*pi), sigma/h = 2*sqrt(78)/39 */
    },
    { /* wendland_c6 */
        { 9, SPH__C(0.859375000000000000000), SPH__C(0.452910813657838300244) }, /* 1D: alpha = 55/64, sigma/h = 2*sqrt(78)/39 */
        { 6, SPH__C(0.886720397226274013569), SPH__C(0.414039335605412530678) }, /* 2D: alpha = 39/(14*pi), sigma/h = sqrt(210)/35 */
        { 6, SPH__C(0.848619130157957552049), SPH__C(0.408248290463863016366) }  /* 3D: alpha = 1365/(512*pi), sigma/h = sqrt(6)/6 */
    }
};

/* The natural pieces in product form, per shape (same order as sph__shapes):
   pieces, kappa, left ends, then per piece the forms of w and g,
   { b, e, m, degree, P } means (b - q)^m P(q - e); W = w, F from g, where g
   is w'(q)/q on the piece holding 0 and w'(q) (to divide by q) elsewhere. */
SPH__TABLE sph__nshape sph__nshapes[] = {
    { 2, SPH__Q(2, 1), { 0, SPH__Q(1, 1), 0 }, { /* cubic */
        { { SPH__Q(1, 1), SPH__Q(1, 1), 0, 3, { SPH__Q(1, 6), SPH__Q(-1, 2), SPH__Q(1, 2), SPH__Q(1, 2), 0, 0 } },
          { SPH__Q(1, 1), SPH__Q(1, 1), 0, 1, { SPH__Q(-1, 2), SPH__Q(3, 2), 0, 0, 0, 0 } } },
        { { SPH__Q(2, 1), SPH__Q(1, 1), 3, 0, { SPH__Q(1, 6), 0, 0, 0, 0, 0 } },
          { SPH__Q(2, 1), SPH__Q(1, 1), 2, 0, { SPH__Q(-1, 2), 0, 0, 0, 0, 0 } } }
    } },
    { 1, SPH__Q(1, 1), { 0, 0, 0 }, { /* lucy */
        { { SPH__Q(1, 1), 0, 3, 1, { SPH__Q(1, 1), SPH__Q(3, 1), 0, 0, 0, 0 } },
          { SPH__Q(1, 1), 0, 2, 0, { SPH__Q(-12, 1), 0, 0, 0, 0, 0 } } }
    } },
    { 2, SPH__Q(2, 1), { 0, SPH__Q(1, 1), 0 }, { /* new_quartic */
        { { SPH__Q(2, 1), 0, 2, 2, { SPH__Q(1, 6), SPH__Q(1, 6), SPH__Q(-5, 32), 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 1, 1, { SPH__Q(-9, 8), SPH__Q(5, 8), 0, 0, 0, 0 } } },
        { { SPH__Q(2, 1), SPH__Q(3, 2), 2, 2, { SPH__Q(25, 384), SPH__Q(-29, 96), SPH__Q(-5, 32), 0, 0, 0 } },
          { SPH__Q(2, 1), SPH__Q(2, 1), 1, 2, { SPH__Q(1, 4), SPH__Q(11, 8), SPH__Q(5, 8), 0, 0, 0 } } }
    } },
    { 3, SPH__Q(3, 1), { 0, SPH__Q(1, 1), SPH__Q(2, 1) }, { /* quintic */
        { { SPH__Q(1, 1), 0, 0, 5, { SPH__Q(66, 1), 0, SPH__Q(-60, 1), 0, SPH__Q(30, 1), SPH__Q(-10, 1) } },
          { SPH__Q(1, 1), 0, 0, 3, { SPH__Q(-120, 1), 0, SPH__Q(120, 1), SPH__Q(-50, 1), 0, 0 } } },
        { { SPH__Q(2, 1), SPH__Q(2, 1), 0, 5, { SPH__Q(1, 1), SPH__Q(-5, 1), SPH__Q(10, 1), SPH__Q(-10, 1), SPH__Q(5, 1), SPH__Q(5, 1) } },
          { SPH__Q(2, 1), SPH__Q(2, 1), 0, 4, { SPH__Q(-5, 1), SPH__Q(20, 1), SPH__Q(-30, 1), SPH__Q(20, 1), SPH__Q(25, 1), 0 } } },
        { { SPH__Q(3, 1), SPH__Q(2, 1), 5, 0, { SPH__Q(1, 1), 0, 0, 0, 0, 0 } },
          { SPH__Q(3, 1), SPH__Q(2, 1), 4, 0, { SPH__Q(-5, 1), 0, 0, 0, 0, 0 } } }
    } },
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, { /* wendland_c2 */
        { { SPH__Q(2, 1), 0, 4, 1, { SPH__Q(1, 16), SPH__Q(1, 8), 0, 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 3, 0, { SPH__Q(-5, 8), 0, 0, 0, 0, 0 } } }
    } },
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, { /* wendland_c4 */
        { { SPH__Q(2, 1), 0, 6, 2, { SPH__Q(1, 64), SPH__Q(3, 64), SPH__Q(35, 768), 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 5, 1, { SPH__Q(-7, 48), SPH__Q(-35, 96), 0, 0, 0, 0 } } }
    } },
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, { /* wendland_c6 */
        { { SPH__Q(2, 1), 0, 8, 3, { SPH__Q(1, 256), SPH__Q(1, 64), SPH__Q(25, 1024), SPH__Q(1, 64), 0, 0 } },
          { SPH__Q(2, 1), 0, 7, 2, { SPH__Q(-11, 256), SPH__Q(-77, 512), SPH__Q(-11, 64), 0, 0, 0 } } }
    } },
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, { /* wendland_c2_1d */
        { { SPH__Q(2, 1), 0, 3, 1, { SPH__Q(1, 8), SPH__Q(3, 16), 0, 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 2, 0, { SPH__Q(-3, 4), 0, 0, 0, 0, 0 } } }
    } },
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, { /* wendland_c4_1d */
        { { SPH__Q(2, 1), 0, 5, 2, { SPH__Q(1, 32), SPH__Q(5, 64), SPH__Q(1, 16), 0, 0, 0 } },
          { SPH__Q(2, 1), 0, 4, 1, { SPH__Q(-7, 32), SPH__Q(-7, 16), 0, 0, 0, 0 } } }
    } },
    { 1, SPH__Q(2, 1), { 0, 0, 0 }, { /* wendland_c6_1d */
        { { SPH__Q(2, 1), 0, 7, 3, { SPH__Q(1, 128), SPH__Q(7, 256), SPH__Q(19, 512), SPH__Q(21, 1024), 0, 0 } },
          { SPH__Q(2, 1), 0, 6, 2, { SPH__Q(-9, 128), SPH__Q(-27, 128), SPH__Q(-105, 512), 0, 0, 0 } } }
    } }
};
/* ---- end of GENERATED tables ---- */

/* Horner's rule, lowest power first: c[0] + u (c[1] + u (c[2] + ...)). */
SPH_API sph_real sph__horner(const sph_real *c, int degree, sph_real u)
{
    sph_real p = c[degree];
    int i;
    for (i = degree - 1; i >= 0; --i) p = p * u + c[i];
    return p;
}

/* The table row of the piece holding q: picked by one conversion, no chain of
 * ifs. q outside [0, kappa) (and NaN) selects the zero row. */
SPH_API const sph_real *sph__row(const sph__shape *s, sph_real q)
{
    const int i = (q >= 0 && q < s->kappa) ? (int)(q * s->inv_width) : s->npiece;
    return sph__coef + s->offset + i * (3 + 3 * (s->degree + 1));
}

/* docs/kernels.md eq. (K1), (K2): the dimensionless shape w(q) and
 * g(q) = w'(q)/q at q >= 0, both from one table row. */
SPH_API void sph__shape_wg(const sph__shape *s, sph_real q, sph_real *w, sph_real *g)
{
    const sph_real *row = sph__row(s, q);
    const sph_real u = q - row[0];
    *w = sph__horner(row + 3, s->degree, u);
    *g = sph__horner(row + 4 + s->degree, s->degree, u) / (row[1] + row[2] * q);
}

/* w, g = w'/q, w' and w'' at q >= 0 from one table row (scalar API). */
SPH_API void sph__shape_all(const sph__shape *s, sph_real q, sph_real d[4])
{
    const sph_real *row = sph__row(s, q);
    const sph_real u = q - row[0];
    const int n = s->degree + 1;
    const sph_real num = sph__horner(row + 3 + n, s->degree, u);
    d[0] = sph__horner(row + 3, s->degree, u);
    d[1] = num / (row[1] + row[2] * q);
    d[2] = row[1] > 0 ? num * q : num; /* inner piece stores w'/q, the others w' */
    d[3] = sph__horner(row + 3 + 2 * n, s->degree, u);
}

/* x * hinv^n, scaling last so intermediate values stay representable. */
SPH_API sph_real sph__hpow(sph_real x, sph_real hinv, int n)
{
    int i;
    for (i = 0; i < n; ++i) x *= hinv;
    return x;
}

/* SPH_OK when kernel k is defined in dimension dim, else SPH_EKERNEL/SPH_EDIM.
 * Every kernel here is defined in 1, 2 and 3 dimensions (1-D Wendland uses
 * Wendland's 1-D functions, see docs/kernels.md). */
SPH_API int sph_kernel_check(sph_kernel k, int dim)
{
    if ((int)k < 0 || (int)k >= (int)SPH_KERNEL_COUNT) return SPH_EKERNEL;
    if (dim < 1 || dim > 3) return SPH_EDIM;
    return SPH_OK;
}

/* A bound on alpha_d times |w|, |w'/q|, |w'|, |w''| and |d w + q w'| over
 * every kernel, dimension and q (the largest is Lucy's 3-D alpha_3 |w'/q| at
 * q = 0, 25.07), so that W, F, dW/dr, d2W/dr2 and dW/dh are all bounded by
 * SPH__SHAPE_MAX h^-(d+2) for h <= 1 and by SPH__SHAPE_MAX for h > 1. */
#define SPH__SHAPE_MAX 64

/* 1 when h is a usable smoothing length in dim dimensions: positive, finite,
 * and SPH__SHAPE_MAX h^-(dim+2) finite, so that every kernel quantity of
 * every kernel is finite in sph_real (the scalar functions and the pair
 * kernel take h in the caller's dim, the operators in ctx.dim). */
SPH_API int sph__h_ok(sph_real h, int dim)
{
    return h > 0 && h <= SPH__REAL_MAX && sph__hpow(SPH__SHAPE_MAX, 1 / h, dim + 2) <= SPH__REAL_MAX;
}

/* SPH_OK when h is a usable smoothing length in every dimension: positive,
 * finite and not so small that W, F or any other kernel quantity of any
 * kernel in 3-D overflows sph_real (64 h^-5 finite: h above about 5.1e-62
 * in double, 4.5e-8 in float); else SPH_EH. */
SPH_API int sph_check_h(sph_real h)
{
    return sph__h_ok(h, 3) ? SPH_OK : SPH_EH;
}

/* The per-dimension data of (k, dim), or NULL for invalid arguments. */
SPH_API const sph__kdim *sph__kd(sph_kernel k, int dim)
{
    return sph_kernel_check(k, dim) == SPH_OK ? &sph__kdims[k][dim - 1] : NULL;
}

/* Validates (k, dim, r, h) for the scalar API; on success sets the data,
 * 1/h and q = r/h. */
SPH_API const sph__kdim *sph__prep(sph_kernel k, int dim, sph_real r, sph_real h,
                                   sph_real *hinv, sph_real *q)
{
    const sph__kdim *kd = sph__kd(k, dim);
    if (kd == NULL || !sph__h_ok(h, dim) || !(r >= 0 && r <= SPH__REAL_MAX)) return NULL;
    *hinv = 1 / h;
    *q = r / h; /* one rounding: r = kappa h gives q = kappa exactly */
    /* beyond the support (r / h may even overflow to Inf): q = kappa selects
     * the zero row and keeps every product with q finite */
    if (!(*q < sph__shapes[kd->shape].kappa)) *q = sph__shapes[kd->shape].kappa;
    return kd;
}

/* kappa: W(r, h) = 0 for r >= kappa h (0 for an unknown kernel). */
SPH_API sph_real sph_kernel_support(sph_kernel k)
{
    return sph_kernel_check(k, 1) == SPH_OK ? sph__shapes[sph__kdims[k][0].shape].kappa : 0;
}

/* Short lower-case identifier ("cubic", "wendland_c4", ...); "invalid" otherwise. */
SPH_API const char *sph_kernel_name(sph_kernel k)
{
    switch (k) {
    case SPH_KERNEL_CUBIC: return "cubic";
    case SPH_KERNEL_LUCY: return "lucy";
    case SPH_KERNEL_NEW_QUARTIC: return "new_quartic";
    case SPH_KERNEL_QUINTIC: return "quintic";
    case SPH_KERNEL_WENDLAND_C2: return "wendland_c2";
    case SPH_KERNEL_WENDLAND_C4: return "wendland_c4";
    case SPH_KERNEL_WENDLAND_C6: return "wendland_c6";
    default: return "invalid";
    }
}

/* Inverse of sph_kernel_name; SPH_EKERNEL for an unknown name (or NULL). */
SPH_API int sph_kernel_from_name(const char *name)
{
    int k;
    for (k = 0; name != NULL && k < (int)SPH_KERNEL_COUNT; ++k) {
        const char *a = name, *b = sph_kernel_name((sph_kernel)k);
        while (*a != '\0' && *a == *b) ++a, ++b;
        if (*a == '\0' && *b == '\0') return k;
    }
    return SPH_EKERNEL;
}

/* alpha_d, the normalisation: W(r, h) = alpha_d h^-d w(r/h). 0 if invalid. */
SPH_API sph_real sph_kernel_alpha(sph_kernel k, int dim)
{
    const sph__kdim *kd = sph__kd(k, dim);
    return kd ? kd->alpha : 0;
}

/* Standard deviation of W per coordinate in units of h,
 * sigma^2 = (1/d) int |x|^2 W d^dx (docs/kernels.md eq. (K5)); kernels of equal
 * sigma h resolve equally (Dehnen & Aly 2012). 0 if invalid. */
SPH_API sph_real sph_kernel_sigma(sph_kernel k, int dim)
{
    const sph__kdim *kd = sph__kd(k, dim);
    return kd ? kd->sigma : 0;
}

/* Volume of the unit ball in dim dimensions (2, pi, 4 pi / 3). */
SPH_API sph_real sph__unit_ball(int dim)
{
    return dim == 1 ? (sph_real)2
         : dim == 2 ? SPH__C(3.14159265358979323846)
                    : SPH__C(4.18879020478639098462);
}

/* Expected number of neighbours inside the support (the particle itself
 * included) for particles of volume V = m / rho (docs/kernels.md eq. (K6)):
 * N = omega_d (kappa h)^d / V. 0 if invalid (V not positive and finite) and
 * where N overflows sph_real. */
SPH_API sph_real sph_kernel_neighbours(sph_kernel k, int dim, sph_real h, sph_real volume)
{
    const sph_real kh = sph_kernel_support(k) * h;
    sph_real n;
    if (sph_kernel_check(k, dim) != SPH_OK || !(volume > 0 && volume <= SPH__REAL_MAX) || !sph__h_ok(h, dim))
        return 0;
    n = sph__unit_ball(dim) * (dim == 1 ? kh : dim == 2 ? kh * kh : kh * kh * kh) / volume;
    return sph__finite(n) ? n : 0;
}

/* The h that puts n_neigh neighbours (self included) inside the support of a
 * particle of volume V = m / rho: the inverse of sph_kernel_neighbours. 0 if
 * invalid (n_neigh or V not positive and finite) and where n_neigh V
 * overflows sph_real. */
SPH_API sph_real sph_kernel_h_for_neighbours(sph_kernel k, int dim, sph_real n_neigh,
                                             sph_real volume)
{
    sph_real x;
    if (sph_kernel_check(k, dim) != SPH_OK || !(volume > 0 && volume <= SPH__REAL_MAX) ||
        !(n_neigh > 0 && n_neigh <= SPH__REAL_MAX))
        return 0;
    x = n_neigh * volume / sph__unit_ball(dim);
    x = dim == 1 ? x : dim == 2 ? sph__sqrt(x) : (sph_real)cbrt((double)x);
    x /= sph_kernel_support(k);
    return sph__finite(x) ? x : 0;
}

/* The scalar kernel quantities, each alpha_d h^-p times a shape value. */
enum { SPH__W, SPH__F, SPH__DWDR, SPH__D2WDR2, SPH__DWDH };

SPH_API sph_real sph__scalar(sph_kernel k, int dim, sph_real r, sph_real h, int what)
{
    sph_real hinv = 0, q = 0, d[4];
    const sph__kdim *kd = sph__prep(k, dim, r, h, &hinv, &q);
    if (kd == NULL) return 0;
    sph__shape_all(&sph__shapes[kd->shape], q, d);
    switch (what) {
    case SPH__W: return sph__hpow(kd->alpha * d[0], hinv, dim);
    case SPH__F: return sph__hpow(kd->alpha * d[1], hinv, dim + 2);
    case SPH__DWDR: return sph__hpow(kd->alpha * d[2], hinv, dim + 1);
    case SPH__D2WDR2: return sph__hpow(kd->alpha * d[3], hinv, dim + 2);
    default: return -sph__hpow(kd->alpha * ((sph_real)dim * d[0] + q * d[2]), hinv, dim + 1);
    }
}

/* docs/kernels.md eq. (K1): W(r, h) = alpha_d h^-d w(r/h). */
SPH_API sph_real sph_kernel_w(sph_kernel k, int dim, sph_real r, sph_real h)
{
    return sph__scalar(k, dim, r, h, SPH__W);
}

/* docs/kernels.md eq. (K2): F = (1/r) dW/dr = alpha_d h^-(d+2) w'(q)/q, finite at r = 0. */
SPH_API sph_real sph_kernel_f(sph_kernel k, int dim, sph_real r, sph_real h)
{
    return sph__scalar(k, dim, r, h, SPH__F);
}

/* docs/kernels.md eq. (K3): dW/dr = alpha_d h^-(d+1) w'(q). */
SPH_API sph_real sph_kernel_dwdr(sph_kernel k, int dim, sph_real r, sph_real h)
{
    return sph__scalar(k, dim, r, h, SPH__DWDR);
}

/* docs/kernels.md eq. (K4): d2W/dr2 = alpha_d h^-(d+2) w''(q). */
SPH_API sph_real sph_kernel_d2wdr2(sph_kernel k, int dim, sph_real r, sph_real h)
{
    return sph__scalar(k, dim, r, h, SPH__D2WDR2);
}

/* docs/kernels.md eq. (K7): dW/dh = -(d W + r dW/dr) / h = -alpha_d h^-(d+1) (d w + q w'). */
SPH_API sph_real sph_kernel_dwdh(sph_kernel k, int dim, sph_real r, sph_real h)
{
    return sph__scalar(k, dim, r, h, SPH__DWDH);
}

/* docs/kernels.md eq. (K1), (K2) fused: W and F from one table row (hot loops). */
SPH_API void sph_kernel_wf(sph_kernel k, int dim, sph_real r, sph_real h, sph_real *W,
                           sph_real *F)
{
    sph_real hinv = 0, q = 0, w, g;
    const sph__kdim *kd = sph__prep(k, dim, r, h, &hinv, &q);
    if (kd == NULL) {
        *W = 0;
        *F = 0;
        return;
    }
    sph__shape_wg(&sph__shapes[kd->shape], q, &w, &g);
    *W = sph__hpow(kd->alpha * w, hinv, dim);
    *F = sph__hpow(kd->alpha * g, hinv, dim + 2);
}

/* docs/kernels.md eq. (K8): grad_i W_ij = F x_ij, dx = x_i - x_j (dim components).
 * Computed as alpha_d h^-(d+1) g(q) (dx / h) so that it stays representable
 * wherever the gradient is. Writes zeros for invalid input or non-finite dx. */
SPH_API void sph_kernel_grad(sph_kernel k, int dim, const sph_real *dx, sph_real h,
                             sph_real *grad)
{
    sph_real s[3] = {0, 0, 0}, q2 = 0, q, w, g, G;
    const sph__kdim *kd = sph__kd(k, dim);
    int a;
    if (kd == NULL || dx == NULL || grad == NULL || !sph__h_ok(h, dim)) {
        for (a = 0; grad != NULL && a < dim && a < 3; ++a) grad[a] = 0;
        return;
    }
    for (a = 0; a < dim; ++a) {
        s[a] = dx[a] / h;
        q2 += s[a] * s[a];
    }
    q = sph__sqrt(q2);
    sph__shape_wg(&sph__shapes[kd->shape], q, &w, &g);
    G = (q < sph__shapes[kd->shape].kappa) ? sph__hpow(kd->alpha * g, 1 / h, dim + 1) : 0;
    for (a = 0; a < dim; ++a) grad[a] = G != 0 ? G * s[a] : 0;
}

/* ======================================================================== */
/* 4. Particle data: strided views, neighbour lists, periodic box            */
/* ======================================================================== */
/* Shared by the pair terms, operators and neighbour search (sections 5-7).
 * Every array belongs to the caller and is read in place, never copied. */

typedef int32_t sph_idx; /* particle index (targets and sources) */
typedef int64_t sph_off; /* position in a neighbour list */

/* A read-only field of ncomp (1..3) components per particle: component a of
 * particle i is p[a][i * stride]. One view reads structure-of-arrays
 * (p = {x, y, z}, stride 1), interleaved (p = {x, x+1, x+2}, stride 3) and
 * array-of-structs (p = {&s[0].x, &s[0].y, ...}, stride sizeof(s[0]) /
 * sizeof(sph_real)) alike. */
typedef struct {
    const sph_real *p[3];
    ptrdiff_t stride;
} sph_view;

/* The same for output fields. */
typedef struct {
    sph_real *p[3];
    ptrdiff_t stride;
} sph_out;

/* Neighbour lists in CSR form: the sources of target i are
 * index[offset[i]] .. index[offset[i+1]-1], each in 0..n_sources-1. */
typedef struct {
    sph_idx n_targets;
    sph_idx n_sources;
    const sph_off *offset; /* [n_targets + 1], offset[0] = 0, non-decreasing */
    const sph_idx *index;  /* [offset[n_targets]] */
} sph_neighbours;

/* An axis-aligned box [lo, lo + length) with per-axis periodicity (minimum
 * image). Pass NULL where a function takes a box and there is none. */
typedef struct {
    sph_real lo[3];
    sph_real length[3];
    int periodic[3]; /* non-zero: axis a is periodic with period length[a] */
} sph_box;

/* Minimum image of one component of x_i - x_j (docs/operators.md eq. (O0)):
 * along a periodic axis of length L, dx - L * round(dx / L), so |dx| <= L/2
 * whatever multiple of L the two positions are apart. Unchanged when box is
 * NULL, a is outside 0..2, the axis is not periodic or its length not
 * positive and finite, and where there is no image to take (dx NaN or
 * infinite, or dx / L beyond the largest sph_real). Every part of the
 * library (and the brute-force references of the tests) uses this one
 * function. */
SPH_API sph_real sph_box_delta(const sph_box *box, int a, sph_real dx)
{
    sph_real L, d;
    if (box == NULL || a < 0 || a > 2 || !box->periodic[a]) return dx;
    L = box->length[a];
    if (!(L > 0 && L <= SPH__REAL_MAX)) return dx;
    d = dx - L * sph__floor(dx / L + (sph_real)0.5);
    return sph__finite(d) ? d : dx;
}

/* View of a structure-of-arrays field (pass NULL for unused components). */
SPH_API sph_view sph_view_soa(const sph_real *x, const sph_real *y, const sph_real *z)
{
    sph_view v;
    v.p[0] = x;
    v.p[1] = y;
    v.p[2] = z;
    v.stride = 1;
    return v;
}

/* View of fields inside an array of structs: first points at component 0 of
 * particle 0, components are consecutive reals, stride_bytes = sizeof(struct)
 * (a multiple of sizeof(sph_real)). */
SPH_API sph_view sph_view_aos(const sph_real *first, int ncomp, size_t stride_bytes)
{
    sph_view v;
    int a;
    for (a = 0; a < 3; ++a) v.p[a] = (first != NULL && a < ncomp) ? first + a : NULL;
    v.stride = (ptrdiff_t)(stride_bytes / sizeof(sph_real));
    return v;
}

/* View of an interleaved field x[ncomp * i + a] (ncomp 1..3). */
SPH_API sph_view sph_view_interleaved(const sph_real *x, int ncomp)
{
    return sph_view_aos(x, ncomp, (size_t)ncomp * sizeof(sph_real));
}

/* The writable twin of a view built on the caller's writable arrays. */
SPH_API sph_out sph__out_of(sph_view v)
{
    sph_out o;
    int a;
    for (a = 0; a < 3; ++a) o.p[a] = (sph_real *)v.p[a]; /* the caller passed writable arrays */
    o.stride = v.stride;
    return o;
}

/* Output counterparts of the three views. */
SPH_API sph_out sph_out_soa(sph_real *x, sph_real *y, sph_real *z)
{
    return sph__out_of(sph_view_soa(x, y, z));
}

SPH_API sph_out sph_out_interleaved(sph_real *x, int ncomp)
{
    return sph__out_of(sph_view_interleaved(x, ncomp));
}

SPH_API sph_out sph_out_aos(sph_real *first, int ncomp, size_t stride_bytes)
{
    return sph__out_of(sph_view_aos(first, ncomp, stride_bytes));
}

/* ======================================================================== */
/* 5. Pair terms                                                             */
/* ======================================================================== */

/* One neighbour's contribution to each operator of section 6, for solvers that
 * fuse several operators in their own neighbour loop (docs/operators.md,
 * "Pair terms"). Conventions: dx = x_ij = x_i - x_j (minimum image, (O0)),
 * F = F_ij = (1/r) dW/dr at the pair's h, grad_i W_ij = F dx (O1); V_j = m_j /
 * rho_j. The vector terms add into acc[0..dim-1]; nothing is divided by r.
 *
 * Bad input. These are the caller's inner loop and check nothing they need
 * not: the sums and products below are plain arithmetic, finite for finite
 * arguments whose products stay in range, and NaN or Inf in an argument
 * passes into the result (validate fields once with sph_check_field). Arrays
 * must hold dim (1..3) values; no component beyond the third is read or
 * written whatever dim is. The functions that divide or evaluate the kernel
 * return a documented finite fallback instead: sph_pair_kernel (zeros),
 * sph_pressure_factor (0), sph_harmonic_k (0) and sph_correction_invert
 * (identity). */

/* Force-inlined helpers: the operator loops rely on them folding into one
 * loop body per kernel and dimension. */
#if defined(__CUDACC__)
#define SPH__INLINE static __forceinline__ SPH_HOSTDEV
#elif defined(__GNUC__) || defined(__clang__)
#define SPH__INLINE static inline __attribute__((always_inline))
#elif defined(_MSC_VER)
#define SPH__INLINE static __forceinline
#else
#define SPH__INLINE static inline
#endif

/* The kernel at one pair: r = |dx|, q = r / h, W = W(r, h), F = (1/r) dW/dr. */
typedef struct {
    sph_real r, q, W, F;
} sph_pair;

/* (O1) r, q, W and F of a pair from dx = x_i - x_j (dim components) and the
 * pair's h (the caller picks h_i, or (h_i + h_j) / 2 for symmetric terms).
 * All zero, as the scalar kernel functions give, for invalid kernel, dim or
 * h, and for a dx with a NaN or Inf component or so long that |dx|^2 or
 * |dx| / h overflows (far beyond the support, where W = F = 0 anyway). */
SPH_API sph_pair sph_pair_kernel(sph_kernel k, int dim, const sph_real *dx, sph_real h)
{
    sph_pair p;
    sph_real r2 = 0, w, g, hinv, r, q;
    const sph__kdim *kd = sph__kd(k, dim);
    int a;
    p.r = p.q = p.W = p.F = 0;
    if (kd == NULL || dx == NULL || !sph__h_ok(h, dim)) return p;
    for (a = 0; a < dim; ++a) r2 += dx[a] * dx[a];
    hinv = 1 / h;
    r = sph__sqrt(r2);
    q = r * hinv;
    if (!(q <= SPH__REAL_MAX)) return p; /* NaN (a NaN in dx) or Inf (Inf in dx, or overflow) */
    p.r = r;
    p.q = q;
    sph__shape_wg(&sph__shapes[kd->shape], p.q, &w, &g);
    p.W = sph__hpow(kd->alpha * w, hinv, dim);
    p.F = sph__hpow(kd->alpha * g, hinv, dim + 2);
    return p;
}

/* (O2) density: m_j W_ij. */
SPH_API sph_real sph_pair_density(sph_real m_j, sph_real W) { return m_j * W; }

/* (O3) interpolation: V_j f_j W_ij (Shepard: also sum V_j W_ij). */
SPH_API sph_real sph_pair_interpolate(sph_real V_j, sph_real f_j, sph_real W) { return V_j * f_j * W; }

/* acc += c dx (the common shape of every gradient pair term, c = coefficient * F). */
SPH__INLINE void sph__axpy(int dim, sph_real c, const sph_real *dx, sph_real *acc)
{
    int a;
    for (a = 0; a < dim && a < 3; ++a) acc[a] += c * dx[a];
}

/* (O4) standard gradient: acc += V_j f_j F dx. */
SPH_API void sph_pair_grad_standard(int dim, sph_real V_j, sph_real f_j, sph_real F,
                                    const sph_real *dx, sph_real *acc)
{
    sph__axpy(dim, V_j * f_j * F, dx, acc);
}

/* (O5) difference gradient: acc += V_j (f_j - f_i) F dx (zero for constants). */
SPH_API void sph_pair_grad_difference(int dim, sph_real V_j, sph_real f_i, sph_real f_j,
                                      sph_real F, const sph_real *dx, sph_real *acc)
{
    sph__axpy(dim, V_j * (f_j - f_i) * F, dx, acc);
}

/* (O6) symmetric gradient: acc += V_j (f_j + f_i) F dx (antisymmetric in i, j). */
SPH_API void sph_pair_grad_symmetric(int dim, sph_real V_j, sph_real f_i, sph_real f_j,
                                     sph_real F, const sph_real *dx, sph_real *acc)
{
    sph__axpy(dim, V_j * (f_j + f_i) * F, dx, acc);
}

/* (O8) pressure form: acc += m_j (p_i / rho_i^2 + p_j / rho_j^2) F dx; then
 * grad p_i = rho_i acc and the acceleration is -acc. P = p / rho^2 is passed
 * precomputed (once per particle: no division in the pair loop). */
SPH_API void sph_pair_grad_pressure(int dim, sph_real m_j, sph_real P_i, sph_real P_j, sph_real F,
                                    const sph_real *dx, sph_real *acc)
{
    sph__axpy(dim, m_j * (P_i + P_j) * F, dx, acc);
}

/* P = p / rho^2, the per-particle factor of (O8). 0 where it is not a
 * finite number: rho not positive (no division by 0), p or rho NaN or
 * infinite, or rho^2 underflowing to 0; 0 also where rho^2 overflows (one
 * multiplication and one division per call, as the pair loops need). */
SPH_API sph_real sph_pressure_factor(sph_real p, sph_real rho)
{
    const sph_real P = rho > 0 ? p / (rho * rho) : 0;
    return sph__finite(P) ? P : 0;
}

/* (O9) standard divergence: V_j v_j . dx F. */
SPH_API sph_real sph_pair_div_standard(int dim, sph_real V_j, const sph_real *v_j, sph_real F,
                                       const sph_real *dx)
{
    sph_real s = 0;
    int a;
    for (a = 0; a < dim && a < 3; ++a) s += v_j[a] * dx[a];
    return V_j * F * s;
}

/* (O10) difference divergence: V_j (v_j - v_i) . dx F. */
SPH_API sph_real sph_pair_div_difference(int dim, sph_real V_j, const sph_real *v_i,
                                         const sph_real *v_j, sph_real F, const sph_real *dx)
{
    sph_real s = 0;
    int a;
    for (a = 0; a < dim && a < 3; ++a) s += (v_j[a] - v_i[a]) * dx[a];
    return V_j * F * s;
}

/* (O11) curl: acc += V_j F (dx x u), u = v_j (standard) or v_j - v_i
 * (difference); dim 2: acc[0] += V_j F (dx_x u_y - dx_y u_x); dim 3: vector. */
SPH_API void sph_pair_curl(int dim, sph_real V_j, const sph_real *u, sph_real F, const sph_real *dx,
                           sph_real *acc)
{
    const sph_real c = V_j * F;
    if (dim == 2) {
        acc[0] += c * (dx[0] * u[1] - dx[1] * u[0]);
    } else if (dim == 3) {
        acc[0] += c * (dx[1] * u[2] - dx[2] * u[1]);
        acc[1] += c * (dx[2] * u[0] - dx[0] * u[2]);
        acc[2] += c * (dx[0] * u[1] - dx[1] * u[0]);
    }
}

/* (O12) Laplacian (Brookshaw / Morris): 2 V_j (f_i - f_j) F (the factor 2
 * applied last: the same bits, and no 2 V_j overflowing on its own). */
SPH_API sph_real sph_pair_laplacian(sph_real V_j, sph_real f_i, sph_real f_j, sph_real F)
{
    return V_j * (f_i - f_j) * F * 2;
}

/* (O13) pair coefficient k_ij = 4 k_i k_j / (k_i + k_j) (twice the harmonic
 * mean; 2k for k_i = k_j = k). 0 when k_i and k_j do not have the same sign
 * (a zero or sign-changing coefficient blocks the flux), so k_i + k_j = 0
 * never divides, and 0 when either is NaN or infinite. Computed as
 * a (4 b / (a + b)), a the one of smaller magnitude, so that the factor lies
 * in [2, 4) and no intermediate overflows (a + b is scaled by 1/4 when b is
 * that large); where k_ij itself exceeds the largest sph_real it saturates
 * there, with a's sign. k_ij is symmetric in i, j bit for bit. */
SPH_API sph_real sph_harmonic_k(sph_real k_i, sph_real k_j)
{
    const int same = (k_i > 0 && k_j > 0) || (k_i < 0 && k_j < 0);
    const int swap = (k_i < 0 ? -k_i : k_i) > (k_j < 0 ? -k_j : k_j);
    const sph_real a = swap ? k_j : k_i, b = swap ? k_i : k_j;
    const sph_real big = (b < 0 ? -b : b) > SPH__REAL_MAX / 4 ? (sph_real)0.25 : 1; /* exact scaling of a + b */
    const sph_real k = a * (4 * ((b * big) / (a * big + b * big)));
    const sph_real sat = a > 0 ? SPH__REAL_MAX : -SPH__REAL_MAX;
    return same && sph__finite(b) ? (sph__finite(k) ? k : sat) : 0;
}

/* (O14) diffusion div(k grad f): V_j k_ij (f_i - f_j) F with k_ij from (O13). */
SPH_API sph_real sph_pair_diffusion(sph_real V_j, sph_real k_ij, sph_real f_i, sph_real f_j,
                                    sph_real F)
{
    return V_j * k_ij * (f_i - f_j) * F;
}

/* (O15) correction matrix: M[3a+b] += V_j (d_a W_ij) (x_j - x_i)_b = -V_j F dx_a dx_b
 * (M is 3x3 row-major, the dim x dim block used). */
SPH_API void sph_pair_correction(int dim, sph_real V_j, sph_real F, const sph_real *dx, sph_real *M)
{
    const sph_real c = -V_j * F;
    int a, b;
    for (a = 0; a < dim && a < 3; ++a)
        for (b = 0; b < dim && b < 3; ++b) M[3 * a + b] += c * dx[a] * dx[b];
}

/* Largest column sum of |A| over the dim x dim block (matrix 1-norm). */
SPH__INLINE sph_real sph__norm1(int dim, const sph_real *A)
{
    sph_real n = 0;
    int a, b;
    for (b = 0; b < dim; ++b) {
        sph_real s = 0;
        for (a = 0; a < dim; ++a) s += A[3 * a + b] < 0 ? -A[3 * a + b] : A[3 * a + b];
        n = s > n ? s : n;
    }
    return n;
}

/* (O16) B = M^-1 when M is well conditioned: reciprocal condition number in
 * the 1-norm, |det M| / (||M||_1 ||adj M||_1) >= rcond_min, tested without a
 * division (scale-free), and every entry of M^-1 finite. Otherwise
 * (degenerate neighbourhood, NaN or Inf in M, an inverse beyond the range of
 * sph_real, rcond_min NaN) B = identity and 0 is returned, else 1. M and B
 * are 3x3 row-major; the dim x dim block is used, the rest of B is set to
 * zero (dim outside 1..3, or M NULL: B = identity of the block that fits, 0
 * returned; B NULL: nothing written, 0). */
SPH_API int sph_correction_invert(int dim, const sph_real *M, sph_real rcond_min, sph_real *B)
{
    sph_real A[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, det = 0, ad, nm, na, inv;
    int a, ok;
    if (B == NULL) return 0;
    if (M == NULL || dim < 1 || dim > 3) {
        for (a = 0; a < 9; ++a) B[a] = a % 4 == 0 && a / 3 < dim ? 1 : 0;
        return 0;
    }
    if (dim == 1) {
        A[0] = 1;
        det = M[0];
    } else if (dim == 2) {
        A[0] = M[4];
        A[1] = -M[1];
        A[3] = -M[3];
        A[4] = M[0];
        det = M[0] * M[4] - M[1] * M[3];
    } else {
        A[0] = M[4] * M[8] - M[5] * M[7];
        A[1] = M[2] * M[7] - M[1] * M[8];
        A[2] = M[1] * M[5] - M[2] * M[4];
        A[3] = M[5] * M[6] - M[3] * M[8];
        A[4] = M[0] * M[8] - M[2] * M[6];
        A[5] = M[2] * M[3] - M[0] * M[5];
        A[6] = M[3] * M[7] - M[4] * M[6];
        A[7] = M[1] * M[6] - M[0] * M[7];
        A[8] = M[0] * M[4] - M[1] * M[3];
        det = M[0] * A[0] + M[1] * A[3] + M[2] * A[6];
    }
    ad = det < 0 ? -det : det;
    nm = sph__norm1(dim, M);
    na = sph__norm1(dim, A);
    /* In 3-D a rank-1 M (one neighbour, collinear neighbours) has an adjugate
     * of rounding noise, and noise / noise passes the rcond test: also require
     * ||adj M||_1 >= rcond_min ||M||_1^2 / 16, which every M passing the
     * exact rcond test meets (||adj M||_2 = s1 s2 with s2 / s1 >= rcond_min / 3;
     * 1- and 2-norms agree within sqrt 3: 9 sqrt 3 < 16). */
    ok = ad > 0 && ad <= SPH__REAL_MAX && ad >= rcond_min * nm * na &&
         (dim < 3 || 16 * na >= rcond_min * nm * nm);
    inv = ok ? 1 / det : 0;
    for (a = 0; a < 9; ++a) ok &= sph__finite(A[a] * inv); /* a denormal det can make 1/det or an entry overflow */
    for (a = 0; a < 9; ++a) B[a] = ok ? A[a] * inv : (a % 4 == 0 && a / 3 < dim ? 1 : 0);
    return ok;
}


/* ======================================================================== */
/* 6. Array operators                                                        */
/* ======================================================================== */

/* Loops over the targets of a CSR neighbour list (gather form: each target
 * sums its own list in order, so results are deterministic and, with OpenMP,
 * bitwise the same for any thread count). docs/operators.md describes the
 * context, the views, the schemes, the status codes and the fallbacks.
 *
 * Lists: the sources of target i are index[offset[i]] .. index[offset[i+1]-1].
 * When targets are the sources, a list contains i itself (r = 0): the density
 * and interpolation need the self term; the derivative terms vanish there.
 * Smoothing length: uniform (ctx.h), or per particle; then density and
 * interpolation use the target's h_i (gather) and every derivative operator
 * h_ij = (h_i + h_j) / 2, so that their pair terms stay antisymmetric. The
 * list must hold every source within kappa h of the target for the h used. */

/* How much input checking an operator does before it runs. */
enum {
    SPH_VALIDATE_FULL = 0, /* default: arguments, one pass over the list (sph_neighbours_check)
                              and one over every per-particle input array */
    SPH_VALIDATE_ARGS = 1  /* arguments only (O(1)): the caller has checked list and data */
};

/* Gradient, divergence and curl schemes (docs/operators.md (O4)-(O11), (O17)). */
typedef enum {
    SPH_SCHEME_STANDARD,   /* sum V_j f_j grad_i W_ij                       */
    SPH_SCHEME_DIFFERENCE, /* sum V_j (f_j - f_i) grad_i W_ij                */
    SPH_SCHEME_SYMMETRIC,  /* sum V_j (f_j + f_i) grad_i W_ij                */
    SPH_SCHEME_CORRECTED,  /* B_i sum V_j (f_j - f_i) grad_i W_ij            */
    SPH_SCHEME_PRESSURE    /* rho_i sum m_j (f_i/rho_i^2 + f_j/rho_j^2) grad_i W_ij (scalars) */
} sph_scheme;

/* What every operator reads besides its field. Fill with sph_ctx_init, then
 * set what the scene uses. Sources are indexed 0..n_sources-1 and targets
 * 0..n_targets-1; a view with p[0] == NULL is absent. */
typedef struct {
    sph_kernel kernel;
    int dim;                    /* 1..3 */
    sph_real h;                 /* uniform smoothing length (when h_source is absent) */
    const sph_neighbours *list; /* CSR list, targets -> sources */
    const sph_box *box;         /* periodic box, or NULL */
    sph_view x;                 /* source positions (dim components) */
    sph_view x_target;          /* target positions; absent: the targets are the sources */
    sph_view h_source;          /* per-particle h of sources; absent: uniform h */
    sph_view h_target;          /* per-particle h of targets (needed when x_target is given) */
    sph_view V;                 /* source volumes V_j = m_j / rho_j (all but density, pressure) */
    sph_view m;                 /* source masses (density, pressure form) */
    sph_view rho;               /* source densities (pressure form) */
    sph_view rho_target;        /* target densities (pressure form, when x_target is given) */
    sph_real rcond_min;         /* corrected schemes: fall back below this 1-norm rcond (1e-3) */
    int validate;               /* SPH_VALIDATE_FULL (default) or SPH_VALIDATE_ARGS */
} sph_ctx;

/* An absent view (every pointer NULL). */
SPH_API sph_view sph_view_none(void) { return sph_view_soa(NULL, NULL, NULL); }

/* A context with uniform h, no box, targets = sources, rcond_min = 1e-3,
 * full validation, and every other view absent. */
SPH_API sph_ctx sph_ctx_init(sph_kernel kernel, int dim, sph_real h, const sph_neighbours *list,
                             sph_view x)
{
    sph_ctx c;
    c.kernel = kernel;
    c.dim = dim;
    c.h = h;
    c.list = list;
    c.box = NULL;
    c.x = x;
    c.x_target = c.h_source = c.h_target = c.V = c.m = c.rho = c.rho_target = sph_view_none();
    c.rcond_min = SPH__C(1e-3);
    c.validate = SPH_VALIDATE_FULL;
    return c;
}

/* SPH_OK when list is a well-formed CSR list: counts >= 0 (else SPH_ESIZE),
 * offset[0] = 0 and non-decreasing (else SPH_EINVAL), every index in
 * 0..n_sources-1 (else SPH_EINDEX), arrays present (else SPH_ENULL).
 * Cost: one pass over offset and index. Run it once per list and set
 * ctx.validate = SPH_VALIDATE_ARGS to skip it in the operators. */
SPH_API int sph_neighbours_check(const sph_neighbours *list)
{
    sph_idx i;
    sph_off o;
    if (list == NULL || list->offset == NULL) return SPH_ENULL;
    if (list->n_targets < 0 || list->n_sources < 0) return SPH_ESIZE;
    if (list->offset[0] != 0) return SPH_EINVAL;
    for (i = 0; i < list->n_targets; ++i)
        if (list->offset[i + 1] < list->offset[i]) return SPH_EINVAL;
    if (list->offset[list->n_targets] > 0 && list->index == NULL) return SPH_ENULL;
    for (o = 0; o < list->offset[list->n_targets]; ++o)
        if (list->index[o] < 0 || list->index[o] >= list->n_sources) return SPH_EINDEX;
    return SPH_OK;
}

#define SPH__AT(v, a, i) ((v).p[a][(ptrdiff_t)(i) * (v).stride])

/* Operators of the loop body (compile-time constants of its instances). */
enum {
    SPH__OP_DENSITY, SPH__OP_INTERP, SPH__OP_SHEPARD, /* gather h: W only */
    SPH__OP_GRAD_STD, SPH__OP_GRAD_DIFF, SPH__OP_GRAD_SYM, SPH__OP_GRAD_CORR, SPH__OP_GRAD_PRES,
    SPH__OP_GRADV_STD, SPH__OP_GRADV_DIFF, SPH__OP_GRADV_SYM, SPH__OP_GRADV_CORR,
    SPH__OP_DIV_STD, SPH__OP_DIV_DIFF, SPH__OP_DIV_CORR, SPH__OP_CURL_STD, SPH__OP_CURL_DIFF,
    SPH__OP_LAPLACIAN, SPH__OP_DIFFUSION, SPH__OP_CORRECTION, SPH__OP_DENS_GRAD
};

/* Everything an operator loop reads, resolved and checked. */
typedef struct {
    sph_kernel kernel;
    int dim, hv, pb; /* per-particle h; periodic box */
    sph_real L[3], invL[3]; /* period and 1 / period per axis, 0 where not periodic */
    sph_idx nt;
    sph_real h, rcond_min;
    const sph_box *box;
    const sph_off *off;
    const sph_idx *idx;
    sph_view x, xt, hs, ht, V, m, rho, rhot, f, ft, k, kt;
    sph_out out, out2; /* out2: the density of SPH__OP_DENS_GRAD */
    sph_real *T;
    ptrdiff_t Ts;
} sph__args;

/* The pair loop instances. K is a kernel (compile-time constant) or -1 (the
 * kernel read once per target from A: SPH_OP_SPECIALISE 0); D the dimension;
 * GEN 0 is the uniform-h, no-box instance (no trace of those options in it),
 * GEN 1 handles per-particle h and periodic boxes.
 *
 * Each target's list is walked in chunks of SPH__CHUNK sources, and each
 * chunk in three simple loops the compiler vectorises: gather the sources'
 * positions into dx and r^2 (and per-pair h), take the square roots, evaluate
 * the kernel (all natural pieces, selected by comparisons: no branch); the operator then sums the
 * chunk. The arithmetic of every pair term is that of the pair-term functions
 * of section 5; only the order of the sum over j may differ (a SIMD reduction
 * under OpenMP, the same for any thread count). */
#ifndef SPH__CHUNK
#define SPH__CHUNK 32 /* a multiple of 8 */
#endif

/* omp simd (OpenMP 4.0 and later); nothing without OpenMP, so builds without
 * it see no unknown pragma. The SUM forms reduce into s0.., m0... */
#if defined(_OPENMP) && _OPENMP >= 201307
#define SPH__SIMD _Pragma("omp simd")
#define SPH__SIMD_SUM1 _Pragma("omp simd reduction(+ : s0)")
#define SPH__SIMD_SUM2 _Pragma("omp simd reduction(+ : s0, s1)")
#define SPH__SIMD_SUM3 _Pragma("omp simd reduction(+ : s0, s1, s2)")
#define SPH__SIMD_SUM4 _Pragma("omp simd reduction(+ : s0, s1, s2, s3)")
#if defined(__clang__)
/* clang does not vectorise a kernel loop over a run-time piece table and
 * then warns that the requested transformation failed (-Wpass-failed, an
 * error under -Werror): there, kernel loops go without the request. */
#define SPH__SIMD_KERNEL
#else
#define SPH__SIMD_KERNEL SPH__SIMD
#endif
#else
#define SPH__SIMD_KERNEL
#define SPH__SIMD
#define SPH__SIMD_SUM1
#define SPH__SIMD_SUM2
#define SPH__SIMD_SUM3
#define SPH__SIMD_SUM4
#endif

/* What to evaluate per pair: W (gather h_i) and/or F (h_ij). */
enum { SPH__WANT_W = 1, SPH__WANT_F = 2 };

/* One target: position, h_i, 1/h_i and the factors alpha h^-D (W), alpha h^-(D+2) (F). */
typedef struct {
    sph_real xi[3], hi, hinv, cW, cF;
} sph__tgt;

/* Pair data of one chunk of a target's list (positions k = 0..n-1). */
typedef struct {
    sph_real dx[3][SPH__CHUNK]; /* x_i - x_j, minimum image */
    sph_real r[SPH__CHUNK];     /* r^2, then r (padded with zeros to a multiple of 8) */
    sph_real W[SPH__CHUNK], F[SPH__CHUNK];
    sph_idx j[SPH__CHUNK];
} sph__chunk;

/* r[0..n) = sqrt(r[0..n)), n a multiple of 8 (zero padded): IEEE square roots,
 * bit for bit those of sph__sqrt, without the errno test that keeps compilers
 * from vectorising sqrt(). SPH_NO_INTRINSICS selects the portable loop. */
SPH__INLINE void sph__sqrt_chunk(sph_real *r, int n)
{
    int k;
#if SPH__SQRT_SIMD == 2
    if (sizeof(sph_real) == sizeof(double)) {
        for (k = 0; k < n; k += 4)
            _mm256_storeu_pd((double *)r + k, _mm256_sqrt_pd(_mm256_loadu_pd((const double *)r + k)));
    } else {
        for (k = 0; k < n; k += 8)
            _mm256_storeu_ps((float *)r + k, _mm256_sqrt_ps(_mm256_loadu_ps((const float *)r + k)));
    }
#elif SPH__SQRT_SIMD == 1
    if (sizeof(sph_real) == sizeof(double)) {
        for (k = 0; k < n; k += 2)
            _mm_storeu_pd((double *)r + k, _mm_sqrt_pd(_mm_loadu_pd((const double *)r + k)));
    } else {
        for (k = 0; k < n; k += 4)
            _mm_storeu_ps((float *)r + k, _mm_sqrt_ps(_mm_loadu_ps((const float *)r + k)));
    }
#else
    for (k = 0; k < n; ++k) r[k] = sph__sqrt(r[k]);
#endif
}

/* Kernel data of the instance. */
SPH__INLINE const sph__kdim *sph__kdk(const sph__args *A, const int K, const int D)
{
    return &sph__kdims[K < 0 ? (int)A->kernel : K][D - 1];
}

/* Target i: position, h_i (the target's h, or the uniform h), 1/h_i and the
 * factors alpha h_i^-D (W) and alpha h_i^-(D+2) (F). */
SPH__INLINE void sph__tinit(const sph__args *A, const sph__kdim *kd, const int D, const int GEN,
                            const sph_idx i, sph__tgt *t)
{
    int a;
    for (a = 0; a < 3; ++a) t->xi[a] = a < D ? SPH__AT(A->xt, a, i) : 0;
    t->hi = (GEN && A->hv) ? SPH__AT(A->ht, 0, i) : A->h;
    t->hinv = 1 / t->hi;
    t->cW = sph__hpow(kd->alpha, t->hinv, D);
    t->cF = sph__hpow(kd->alpha, t->hinv, D + 2);
}

/* Complete unrolling of the short constant-count loops of the kernel forms
 * (gcc's default limits leave the quintic's nest rolled, and unvectorised). */
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__) && !defined(__INTEL_COMPILER) && __GNUC__ >= 8
#define SPH__UNROLL _Pragma("GCC unroll 8")
#else
#define SPH__UNROLL
#endif

/* (b - q)^m P(q - e): one product form of sph__nshapes. */
SPH__INLINE sph_real sph__pform_eval(const sph__pform *f, sph_real q)
{
    const sph_real t = f->b - q, u = q - f->e;
    sph_real p = f->c[f->degree], tm = 1;
    int i;
    SPH__UNROLL
    for (i = f->degree - 1; i >= 0; --i) p = p * u + f->c[i];
    SPH__UNROLL
    for (i = 0; i < f->m; ++i) tm *= t;
    return tm * p;
}

/* The form of w (G = 0) or g (G = 1) of the natural piece holding q >= 0:
 * every piece is evaluated and the one holding q selected by comparisons, so
 * a loop over pairs has no branch and no per-pair table gather (the forms are
 * constants of the kernel). */
SPH__INLINE sph_real sph__nshape_pick(const sph__nshape *s, const int G, sph_real q)
{
    sph_real v = sph__pform_eval(G ? &s->piece[0].g : &s->piece[0].w, q);
    int p;
    SPH__UNROLL
    for (p = 1; p < s->npiece; ++p) {
        const sph_real x = sph__pform_eval(G ? &s->piece[p].g : &s->piece[p].w, q);
        v = q >= s->lo[p] ? x : v;
    }
    return v;
}

/* docs/kernels.md eq. (K1): w(q) from the natural pieces; 0 for q >= kappa and NaN. */
SPH__INLINE sph_real sph__nshape_w(const sph__nshape *s, sph_real q)
{
    const sph_real w = sph__nshape_pick(s, 0, q);
    return q < s->kappa ? w : 0;
}

/* (K2): g(q) = w'(q)/q the same way; the piece holding 0 has q divided out
 * exactly (finite at q = 0), the others divide by q: one division per pair. */
SPH__INLINE sph_real sph__nshape_g(const sph__nshape *s, sph_real q)
{
    sph_real g = sph__nshape_pick(s, 1, q);
    if (s->npiece > 1) g /= q >= s->lo[1] ? q : 1;
    return q < s->kappa ? g : 0;
}

/* (O0) dx = x_i - x_j of the n pairs of list positions o0..o0+n-1, with the
 * minimum image when PB (a constant: one loop per value), r^2 and j. */
SPH__INLINE void sph__chunk_gather(const sph__args *A, const int D, const int PB, const sph__tgt *t, sph_off o0,
                                   int n, sph__chunk *P)
{
    int k, a;
    SPH__SIMD
    for (k = 0; k < n; ++k) {
        const sph_idx j = A->idx[o0 + k];
        sph_real r2 = 0;
        for (a = 0; a < D; ++a) {
            sph_real d = t->xi[a] - SPH__AT(A->x, a, j);
            if (PB) d -= A->L[a] * sph__floor(d * A->invL[a] + (sph_real)0.5);
            P->dx[a][k] = d;
            r2 += d * d;
        }
        P->j[k] = j;
        P->r[k] = r2;
    }
}

/* (O0), (O1) the n pairs of list positions o0..o0+n-1: dx = x_i - x_j
 * (minimum image: sph_box_delta with 1/L taken once per call, so no division
 * per pair; d * (1/L) and d / L round to the same integer, and the image is
 * the same bit for bit, unless |image| is within an ulp of L/2, where both
 * images are equally near and beyond the support of any list pair), r, and W (at h_i) and/or F (at h_ij = (h_i + h_j) / 2 with
 * per-particle h, else h), each from the natural pieces (sph__nshape_w/_g). */
SPH__INLINE void sph__chunk_eval(const sph__args *A, const sph__kdim *kd, const int D, const int GEN,
                                 const int WANT, const sph__tgt *t, sph_off o0, int n, sph__chunk *P)
{
    const sph__nshape *sh = &sph__nshapes[kd->shape];
    const int hv = GEN && A->hv && (WANT & SPH__WANT_F), pb = GEN && A->pb;
    int k;
    /* the options are tested once per chunk, outside the pair loops: inside,
     * the vectoriser would evaluate both sides of every option per pair */
    if (pb)
        sph__chunk_gather(A, D, 1, t, o0, n, P);
    else
        sph__chunk_gather(A, D, 0, t, o0, n, P);
    for (k = n; (k & 7) != 0; ++k) P->r[k] = 0;
    sph__sqrt_chunk(P->r, k);
    if (WANT & SPH__WANT_W) {
        SPH__SIMD_KERNEL
        for (k = 0; k < n; ++k) P->W[k] = t->cW * sph__nshape_w(sh, P->r[k] * t->hinv);
    }
    if ((WANT & SPH__WANT_F) && hv) {
        SPH__SIMD_KERNEL
        for (k = 0; k < n; ++k) {
            const sph_real hinv = 2 / (t->hi + SPH__AT(A->hs, 0, P->j[k]));
            P->F[k] = sph__hpow(kd->alpha, hinv, D + 2) * sph__nshape_g(sh, P->r[k] * hinv);
        }
    } else if (WANT & SPH__WANT_F) {
        SPH__SIMD_KERNEL
        for (k = 0; k < n; ++k) P->F[k] = t->cF * sph__nshape_g(sh, P->r[k] * t->hinv);
    }
}

/* dx of chunk position k as a vector (zeros beyond D). */
SPH__INLINE void sph__chunk_dx(const sph__chunk *P, const int D, int k, sph_real *dx)
{
    int a;
    for (a = 0; a < 3; ++a) dx[a] = a < D ? P->dx[a][k] : 0;
}

/* The loop head shared by the families: declarations, target setup; the
 * chunk loop is `for (o = A->off[i]; o < A->off[i + 1]; o += n)`. */
#define SPH__TARGET_HEAD(WANT)                                                     \
    const sph__kdim *kd = sph__kdk(A, K, D);                                       \
    sph__tgt t;                                                                    \
    sph__chunk P;                                                                  \
    sph_off o;                                                                     \
    int n, k, a;                                                                   \
    sph__tinit(A, kd, D, GEN, i, &t)

/* The next chunk: n sources from list position o, evaluated. */
#define SPH__NEXT_CHUNK(WANT)                                                      \
    n = (A->off[i + 1] - o) < SPH__CHUNK ? (int)(A->off[i + 1] - o) : SPH__CHUNK; \
    sph__chunk_eval(A, kd, D, GEN, WANT, &t, o, n, &P)

#if SPH__OP_AVX512 || SPH__NS_COMPRESS
/* 8 consecutive sph_real as doubles (exact for float), for the AVX-512 loops
 * here and in the neighbour check (section 7); the sizeof test folds. */
SPH__INLINE __m512d sph__load8(const sph_real *p)
{
    return sizeof(sph_real) == sizeof(double) ? _mm512_loadu_pd((const void *)p)
                                              : _mm512_cvtps_pd(_mm256_loadu_ps((const float *)(const void *)p));
}
#endif

#if SPH__OP_AVX512
/* sph__pform_eval and sph__nshape_pick on 8 values of q. */
SPH__INLINE __m512d sph__pform_eval8(const sph__pform *f, __m512d q)
{
    const __m512d t = _mm512_sub_pd(_mm512_set1_pd((double)f->b), q), u = _mm512_sub_pd(q, _mm512_set1_pd((double)f->e));
    __m512d p = _mm512_set1_pd((double)f->c[f->degree]), tm = _mm512_set1_pd(1);
    int i;
    SPH__UNROLL
    for (i = f->degree - 1; i >= 0; --i) p = _mm512_fmadd_pd(p, u, _mm512_set1_pd((double)f->c[i]));
    SPH__UNROLL
    for (i = 0; i < f->m; ++i) tm = _mm512_mul_pd(tm, t);
    return _mm512_mul_pd(tm, p);
}

SPH__INLINE __m512d sph__nshape_pick8(const sph__nshape *s, const int G, __m512d q)
{
    __m512d v = sph__pform_eval8(G ? &s->piece[0].g : &s->piece[0].w, q);
    int p;
    SPH__UNROLL
    for (p = 1; p < s->npiece; ++p) {
        const __m512d x = sph__pform_eval8(G ? &s->piece[p].g : &s->piece[p].w, q);
        v = _mm512_mask_mov_pd(v, _mm512_cmp_pd_mask(q, _mm512_set1_pd((double)s->lo[p]), _CMP_GE_OQ), x);
    }
    return v;
}

/* Can sph__t_dg8 serve this call: F at the uniform h (GRAD with
 * per-particle h stays with the chunked loops)? Every layout of the views
 * takes the same arithmetic (a shared stride changes only the index
 * products), so SoA, interleaved and AoS stay bitwise equal. */
SPH__INLINE int sph__dg8_ok(const sph__args *A, const int GRAD, const int GEN)
{
    return !(GRAD && GEN && A->hv);
}

/* v.p[a][j * st] for the 8 list entries j, lanes outside km from src, st
 * the view's stride. Eight scalar loads, not the gather instruction, which
 * is slower on AMD Zen 4 (see docs/operators.md). A lane outside km has
 * j = 0, a valid source whenever the list holds any pair. */
SPH__INLINE __m512d sph__at8(__m512d src, __mmask8 km, const sph_idx *j, sph_view v, int a, ptrdiff_t st)
{
    const sph_real *p = v.p[a];
    return _mm512_mask_mov_pd(src, km,
                              _mm512_set_pd((double)p[j[7] * st], (double)p[j[6] * st], (double)p[j[5] * st],
                                            (double)p[j[4] * st], (double)p[j[3] * st], (double)p[j[2] * st],
                                            (double)p[j[1] * st], (double)p[j[0] * st]));
}

/* (O2) rho = sum_j m_j W_ij (DENS) and/or (O5) g = sum_j V_j (f_j - f_i) F_ij x_ij
 * (GRAD) of target t, PB: minimum image; ONE_STRIDE: the views read have
 * the stride of x (SoA, or one array of structs), so each j * stride serves
 * every field (with a stride per view the integer multiplies cost 10-20 %
 * of the loop). The same pair arithmetic as the
 * chunked loops (IEEE square root, W and F from the natural pieces, the
 * division of g by q), done for 8 pairs at a time in registers in one pass
 * over the list; only the order of the sum over j differs, and with SPH_REAL
 * float the precision: the pair terms and sums are double, rounded to float
 * once at the end. */
SPH__INLINE void sph__t_dg8(const sph__args *A, const sph__kdim *kd, const int D, const int PB, const int ONE_STRIDE,
                            const int DENS, const int GRAD, const sph__tgt *t, sph_idx i, sph_real fi, sph_real *g,
                            sph_real *rho)
{
    const ptrdiff_t sx = A->x.stride, sm = ONE_STRIDE ? sx : A->m.stride, sV = ONE_STRIDE ? sx : A->V.stride,
                    sf = ONE_STRIDE ? sx : A->f.stride;
    const sph__nshape *sh = &sph__nshapes[kd->shape];
    const __m512d hinv = _mm512_set1_pd((double)t->hinv), kap = _mm512_set1_pd((double)sh->kappa), zero = _mm512_setzero_pd();
    const __m512d vfi = _mm512_set1_pd((double)fi), half = _mm512_set1_pd(0.5);
    __m512d s[3] = {zero, zero, zero}, s3 = zero;
    sph_off o;
    int a;
    for (o = A->off[i]; o < A->off[i + 1]; o += 8) {
        const sph_off left = A->off[i + 1] - o;
        const __mmask8 km = (__mmask8)(left >= 8 ? 0xff : (1u << left) - 1);
        sph_idx j[8];
        __m512d d[3], r2 = zero, q;
        __mmask8 in;
        _mm256_storeu_si256((__m256i *)j, _mm256_maskz_loadu_epi32(km, A->idx + o));
        for (a = 0; a < D; ++a) {
            const __m512d xi = _mm512_set1_pd((double)t->xi[a]);
            d[a] = _mm512_sub_pd(xi, sph__at8(xi, km, j, A->x, a, sx));
            if (PB) {
                const __m512d img = _mm512_roundscale_pd(
                    _mm512_fmadd_pd(d[a], _mm512_set1_pd((double)A->invL[a]), half), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
                d[a] = _mm512_fnmadd_pd(_mm512_set1_pd((double)A->L[a]), img, d[a]);
            }
            r2 = _mm512_fmadd_pd(d[a], d[a], r2);
        }
        q = _mm512_mul_pd(_mm512_sqrt_pd(r2), hinv);
        in = _mm512_cmp_pd_mask(q, kap, _CMP_LT_OQ) & km;
        if (DENS) {
            const __m512d W = _mm512_maskz_mul_pd(in, _mm512_set1_pd((double)t->cW), sph__nshape_pick8(sh, 0, q));
            s3 = _mm512_fmadd_pd(sph__at8(zero, in, j, A->m, 0, sm), W, s3);
        }
        if (GRAD) {
            __m512d gq = sph__nshape_pick8(sh, 1, q), c;
            if (sh->npiece > 1)
                gq = _mm512_div_pd(gq, _mm512_mask_mov_pd(_mm512_set1_pd(1), _mm512_cmp_pd_mask(q, _mm512_set1_pd((double)sh->lo[1]), _CMP_GE_OQ), q));
            c = _mm512_mul_pd(sph__at8(zero, in, j, A->V, 0, sV),
                              _mm512_sub_pd(sph__at8(vfi, in, j, A->f, 0, sf), vfi));
            c = _mm512_mul_pd(c, _mm512_maskz_mul_pd(in, _mm512_set1_pd((double)t->cF), gq));
            for (a = 0; a < D; ++a) s[a] = _mm512_fmadd_pd(c, d[a], s[a]);
        }
    }
    for (a = 0; GRAD && a < 3; ++a) g[a] = a < D ? (sph_real)_mm512_reduce_add_pd(s[a]) : 0;
    if (DENS) *rho = (sph_real)_mm512_reduce_add_pd(s3);
}
#endif

/* The one-pass AVX-512 loop for target i where it can serve (returns 1 with
 * g and/or rho written), else 0: the caller runs the chunked loops. */
SPH__INLINE int sph__dg8_try(const sph__args *A, const sph__kdim *kd, const int D, const int GEN, const int DENS,
                             const int GRAD, const sph__tgt *t, sph_idx i, sph_real fi, sph_real *g, sph_real *rho)
{
#if SPH__OP_AVX512
    const ptrdiff_t sx = A->x.stride;
    int one;
    if (!sph__dg8_ok(A, GRAD, GEN)) return 0;
    one = (!DENS || A->m.stride == sx) && (!GRAD || (A->V.stride == sx && A->f.stride == sx));
    /* GEN: the minimum image always (L = 1/L = 0 on axes without a period
     * leave x_ij as it is, bit for bit), so that each instance of the
     * caller holds two copies of the loop, not four: compile time */
    one ? sph__t_dg8(A, kd, D, GEN, 1, DENS, GRAD, t, i, fi, g, rho)
        : sph__t_dg8(A, kd, D, GEN, 0, DENS, GRAD, t, i, fi, g, rho);
    return 1;
#else
    (void)A, (void)kd, (void)D, (void)GEN, (void)DENS, (void)GRAD, (void)t, (void)i, (void)fi, (void)g, (void)rho;
    return 0;
#endif
}

/* (O2), (O3) density, interpolation, Shepard; returns 1 for an empty Shepard target. */
SPH__INLINE int sph__t_sum(const sph__args *A, const int OP, const int K, const int D,
                           const int GEN, const sph_idx i)
{
    sph_real s0 = 0, s1 = 0;
    SPH__TARGET_HEAD(SPH__WANT_W);
    (void)a;
    if (OP == SPH__OP_DENSITY && sph__dg8_try(A, kd, D, GEN, 1, 0, &t, i, 0, NULL, &s0)) {
        SPH__AT(A->out, 0, i) = s0;
        return 0;
    }
    for (o = A->off[i]; o < A->off[i + 1]; o += n) {
        SPH__NEXT_CHUNK(SPH__WANT_W);
        if (OP == SPH__OP_DENSITY) {
            SPH__SIMD_SUM1
            for (k = 0; k < n; ++k) s0 += sph_pair_density(SPH__AT(A->m, 0, P.j[k]), P.W[k]);
        } else {
            SPH__SIMD_SUM2
            for (k = 0; k < n; ++k) {
                const sph_real Vj = SPH__AT(A->V, 0, P.j[k]);
                s0 += sph_pair_interpolate(Vj, SPH__AT(A->f, 0, P.j[k]), P.W[k]);
                s1 += Vj * P.W[k];
            }
        }
    }
    if (OP == SPH__OP_SHEPARD) {
        SPH__AT(A->out, 0, i) = s1 != 0 ? s0 / s1 : 0;
        return s1 == 0;
    }
    SPH__AT(A->out, 0, i) = s0;
    return 0;
}

/* (O4)-(O8) scalar gradient, and the density with the difference gradient in
 * one pass (O2)+(O5); returns 1 when the corrected scheme fell back. */
SPH__INLINE int sph__t_grad(const sph__args *A, const int OP, const int K, const int D,
                            const int GEN, const sph_idx i)
{
    const int corr = OP == SPH__OP_GRAD_CORR, dens = OP == SPH__OP_DENS_GRAD;
    const int want = dens ? SPH__WANT_W | SPH__WANT_F : SPH__WANT_F;
    const sph_real fi = OP == SPH__OP_GRAD_STD ? 0 : SPH__AT(A->ft, 0, i);
    const sph_real rhoi = OP == SPH__OP_GRAD_PRES ? SPH__AT(A->rhot, 0, i) : 1;
    const sph_real Pi = OP == SPH__OP_GRAD_PRES ? sph_pressure_factor(fi, rhoi) : 0;
    sph_real g[3] = {0, 0, 0}, M[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, B[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    sph_real s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    int fb = 0, b;
    SPH__TARGET_HEAD(want);
    /* the one-pass loop leaves the sums in g and s3, and nothing to the chunks */
    o = (OP == SPH__OP_GRAD_DIFF || dens) && sph__dg8_try(A, kd, D, GEN, dens, 1, &t, i, fi, g, &s3) ? A->off[i + 1]
                                                                                                   : A->off[i];
    for (; o < A->off[i + 1]; o += n) {
        SPH__NEXT_CHUNK(want);
        SPH__SIMD_SUM4
        for (k = 0; k < n; ++k) {
            const sph_idx j = P.j[k];
            const sph_real fj = SPH__AT(A->f, 0, j), F = P.F[k];
            sph_real dx[3], acc[3] = {0, 0, 0};
            sph__chunk_dx(&P, D, k, dx);
            if (OP == SPH__OP_GRAD_PRES)
                sph_pair_grad_pressure(D, SPH__AT(A->m, 0, j), Pi,
                                       sph_pressure_factor(fj, SPH__AT(A->rho, 0, j)), F, dx, acc);
            if (OP == SPH__OP_GRAD_STD) sph_pair_grad_standard(D, SPH__AT(A->V, 0, j), fj, F, dx, acc);
            if (OP == SPH__OP_GRAD_DIFF || corr || dens)
                sph_pair_grad_difference(D, SPH__AT(A->V, 0, j), fi, fj, F, dx, acc);
            if (OP == SPH__OP_GRAD_SYM) sph_pair_grad_symmetric(D, SPH__AT(A->V, 0, j), fi, fj, F, dx, acc);
            if (dens) s3 += sph_pair_density(SPH__AT(A->m, 0, j), P.W[k]);
            s0 += acc[0];
            s1 += acc[1];
            s2 += acc[2];
        }
        for (k = 0; corr && k < n; ++k) {
            sph_real dx[3];
            sph__chunk_dx(&P, D, k, dx);
            sph_pair_correction(D, SPH__AT(A->V, 0, P.j[k]), P.F[k], dx, M);
        }
    }
    g[0] += s0;
    g[1] += s1;
    g[2] += s2;
    if (corr) fb = !sph_correction_invert(D, M, A->rcond_min, B);
    /* a fallback is the difference scheme bit for bit: where that scheme
     * takes the one-pass loop, the fallback's sums come from it too */
    if (fb) (void)sph__dg8_try(A, kd, D, GEN, 0, 1, &t, i, fi, g, NULL);
    for (a = 0; a < D; ++a) {
        sph_real y = rhoi * g[a];
        if (corr) /* (O7) */
            for (y = 0, b = 0; b < D; ++b) y += B[3 * a + b] * g[b];
        SPH__AT(A->out, a, i) = y;
    }
    if (dens) SPH__AT(A->out2, 0, i) = s3;
    return fb;
}

/* (O15)-(O18) tensors: velocity gradient S[a][b] = d v_a / d x_b, the
 * corrected divergence trace(S B) and the correction matrix B itself. */
SPH__INLINE int sph__t_tensor(const sph__args *A, const int OP, const int K, const int D,
                              const int GEN, const sph_idx i)
{
    const int corr = OP == SPH__OP_GRADV_CORR || OP == SPH__OP_DIV_CORR || OP == SPH__OP_CORRECTION;
    sph_real vi[3] = {0, 0, 0}, S[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, M[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    sph_real B[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, div = 0;
    int fb = 0, b, e;
    SPH__TARGET_HEAD(SPH__WANT_F);
    for (a = 0; OP != SPH__OP_GRADV_STD && OP != SPH__OP_CORRECTION && a < D; ++a)
        vi[a] = SPH__AT(A->ft, a, i);
    for (o = A->off[i]; o < A->off[i + 1]; o += n) {
        SPH__NEXT_CHUNK(SPH__WANT_F);
        for (k = 0; k < n; ++k) {
            const sph_idx j = P.j[k];
            const sph_real F = P.F[k], Vj = SPH__AT(A->V, 0, j);
            sph_real dx[3];
            sph__chunk_dx(&P, D, k, dx);
            for (a = 0; OP != SPH__OP_CORRECTION && a < D; ++a) {
                const sph_real vj = SPH__AT(A->f, a, j);
                if (OP == SPH__OP_GRADV_STD) sph_pair_grad_standard(D, Vj, vj, F, dx, S + 3 * a);
                else if (OP == SPH__OP_GRADV_SYM) sph_pair_grad_symmetric(D, Vj, vi[a], vj, F, dx, S + 3 * a);
                else sph_pair_grad_difference(D, Vj, vi[a], vj, F, dx, S + 3 * a);
            }
            if (corr) sph_pair_correction(D, Vj, F, dx, M);
        }
    }
    if (corr) fb = !sph_correction_invert(D, M, A->rcond_min, B);
    for (a = 0; a < D; ++a)
        for (b = 0; b < D; ++b) {
            sph_real y = S[3 * a + b];
            if (OP == SPH__OP_CORRECTION) y = B[3 * a + b];
            else if (corr) /* (O17) T = S B */
                for (y = 0, e = 0; e < D; ++e) y += S[3 * a + e] * B[3 * e + b];
            if (OP == SPH__OP_DIV_CORR) div += a == b ? y : 0; /* (O18) */
            else A->T[(ptrdiff_t)i * A->Ts + a * D + b] = y;
        }
    if (OP == SPH__OP_DIV_CORR) SPH__AT(A->out, 0, i) = div;
    return fb;
}

/* (O9)-(O11) divergence and curl, standard and difference forms. */
SPH__INLINE int sph__t_divcurl(const sph__args *A, const int OP, const int K, const int D,
                               const int GEN, const sph_idx i)
{
    const int diff = OP == SPH__OP_DIV_DIFF || OP == SPH__OP_CURL_DIFF;
    const int curl = OP == SPH__OP_CURL_STD || OP == SPH__OP_CURL_DIFF;
    sph_real vi[3] = {0, 0, 0}, s0 = 0, s1 = 0, s2 = 0;
    SPH__TARGET_HEAD(SPH__WANT_F);
    for (a = 0; diff && a < D; ++a) vi[a] = SPH__AT(A->ft, a, i);
    for (o = A->off[i]; o < A->off[i + 1]; o += n) {
        SPH__NEXT_CHUNK(SPH__WANT_F);
        SPH__SIMD_SUM3
        for (k = 0; k < n; ++k) {
            const sph_idx j = P.j[k];
            sph_real u[3] = {0, 0, 0}, dx[3], acc[3] = {0, 0, 0};
            int c;
            sph__chunk_dx(&P, D, k, dx);
            for (c = 0; c < D; ++c) u[c] = SPH__AT(A->f, c, j) - vi[c];
            if (curl) sph_pair_curl(D, SPH__AT(A->V, 0, j), u, P.F[k], dx, acc);
            else acc[0] = sph_pair_div_standard(D, SPH__AT(A->V, 0, j), u, P.F[k], dx);
            s0 += acc[0];
            s1 += acc[1];
            s2 += acc[2];
        }
    }
    SPH__AT(A->out, 0, i) = s0;
    if (curl && D == 3) {
        SPH__AT(A->out, 1, i) = s1;
        SPH__AT(A->out, 2, i) = s2;
    }
    return 0;
}

/* (O12)-(O14) Laplacian and variable-coefficient diffusion. */
SPH__INLINE int sph__t_lap(const sph__args *A, const int OP, const int K, const int D,
                           const int GEN, const sph_idx i)
{
    const sph_real fi = SPH__AT(A->ft, 0, i);
    const sph_real ki = OP == SPH__OP_DIFFUSION ? SPH__AT(A->kt, 0, i) : 0;
    sph_real s0 = 0;
    SPH__TARGET_HEAD(SPH__WANT_F);
    (void)a;
    for (o = A->off[i]; o < A->off[i + 1]; o += n) {
        SPH__NEXT_CHUNK(SPH__WANT_F);
        SPH__SIMD_SUM1
        for (k = 0; k < n; ++k) {
            const sph_idx j = P.j[k];
            const sph_real Vj = SPH__AT(A->V, 0, j), fj = SPH__AT(A->f, 0, j);
            if (OP == SPH__OP_LAPLACIAN) s0 += sph_pair_laplacian(Vj, fi, fj, P.F[k]);
            else s0 += sph_pair_diffusion(Vj, sph_harmonic_k(ki, SPH__AT(A->k, 0, j)), fi, fj, P.F[k]);
        }
    }
    SPH__AT(A->out, 0, i) = s0;
    return 0;
}

/* Kernel specialisation: SPH_OP_SPECIALISE (section 1) 1 gives one loop
 * instance per kernel, dimension and GEN, so table rows and Horner degrees
 * fold; 0 one instance per dimension and GEN with the kernel read at run time
 * (7 times less code to compile; the kernel data is still hoisted out of the
 * loop); SPH_KERNEL one instance for the pinned kernel. */

#ifdef _OPENMP
#define SPH__OMP_FOR _Pragma("omp parallel for schedule(static) reduction(+ : n_)")
#else
#define SPH__OMP_FOR
#endif

/* Every target of one instance; n_ counts fallbacks. */
#define SPH__LOOP(A, FAM, OP, K, D, GEN)                                           \
    do {                                                                           \
        sph_idx i_;                                                                \
        SPH__OMP_FOR                                                               \
        for (i_ = 0; i_ < (A)->nt; ++i_) n_ += FAM(A, OP, K, D, GEN, i_);          \
    } while (0)

#define SPH__LOOP_G(A, FAM, OP, K, D)                                              \
    do {                                                                           \
        if ((A)->hv || (A)->pb) SPH__LOOP(A, FAM, OP, K, D, 1);                    \
        else SPH__LOOP(A, FAM, OP, K, D, 0);                                       \
    } while (0)

#if defined(SPH_KERNEL)
#define SPH__LOOP_K(A, FAM, OP, D) SPH__LOOP_G(A, FAM, OP, (int)(SPH_KERNEL), D)
#elif SPH_OP_SPECIALISE
#define SPH__LOOP_K(A, FAM, OP, D)                                                 \
    switch ((A)->kernel) {                                                         \
    case SPH_KERNEL_CUBIC: SPH__LOOP_G(A, FAM, OP, SPH_KERNEL_CUBIC, D); break;    \
    case SPH_KERNEL_LUCY: SPH__LOOP_G(A, FAM, OP, SPH_KERNEL_LUCY, D); break;      \
    case SPH_KERNEL_NEW_QUARTIC: SPH__LOOP_G(A, FAM, OP, SPH_KERNEL_NEW_QUARTIC, D); break; \
    case SPH_KERNEL_QUINTIC: SPH__LOOP_G(A, FAM, OP, SPH_KERNEL_QUINTIC, D); break; \
    case SPH_KERNEL_WENDLAND_C2: SPH__LOOP_G(A, FAM, OP, SPH_KERNEL_WENDLAND_C2, D); break; \
    case SPH_KERNEL_WENDLAND_C4: SPH__LOOP_G(A, FAM, OP, SPH_KERNEL_WENDLAND_C4, D); break; \
    default: SPH__LOOP_G(A, FAM, OP, SPH_KERNEL_WENDLAND_C6, D); break;            \
    }
#else
#define SPH__LOOP_K(A, FAM, OP, D) SPH__LOOP_G(A, FAM, OP, -1, D)
#endif

/* name(A): runs operator OP of family FAM; one function per dimension keeps
 * each compiled function small. Returns the number of fallbacks. */
#if defined(SPH_DIM)
#define SPH__RUNNER(name, FAM, OP)                                                 \
    SPH_API sph_idx name(const sph__args *A) { sph_idx n_ = 0; SPH__LOOP_K(A, FAM, OP, SPH_DIM); return n_; }
#else
#define SPH__RUNNER(name, FAM, OP)                                                 \
    SPH_API sph_idx name##_d1(const sph__args *A) { sph_idx n_ = 0; SPH__LOOP_K(A, FAM, OP, 1); return n_; } \
    SPH_API sph_idx name##_d2(const sph__args *A) { sph_idx n_ = 0; SPH__LOOP_K(A, FAM, OP, 2); return n_; } \
    SPH_API sph_idx name##_d3(const sph__args *A) { sph_idx n_ = 0; SPH__LOOP_K(A, FAM, OP, 3); return n_; } \
    SPH_API sph_idx name(const sph__args *A)                                       \
    {                                                                              \
        return A->dim == 1 ? name##_d1(A) : A->dim == 2 ? name##_d2(A) : name##_d3(A); \
    }
#endif

SPH__RUNNER(sph__run_density, sph__t_sum, SPH__OP_DENSITY)
SPH__RUNNER(sph__run_interp, sph__t_sum, SPH__OP_INTERP)
SPH__RUNNER(sph__run_shepard, sph__t_sum, SPH__OP_SHEPARD)
SPH__RUNNER(sph__run_grad_std, sph__t_grad, SPH__OP_GRAD_STD)
SPH__RUNNER(sph__run_grad_diff, sph__t_grad, SPH__OP_GRAD_DIFF)
SPH__RUNNER(sph__run_grad_sym, sph__t_grad, SPH__OP_GRAD_SYM)
SPH__RUNNER(sph__run_grad_corr, sph__t_grad, SPH__OP_GRAD_CORR)
SPH__RUNNER(sph__run_grad_pres, sph__t_grad, SPH__OP_GRAD_PRES)
SPH__RUNNER(sph__run_gradv_std, sph__t_tensor, SPH__OP_GRADV_STD)
SPH__RUNNER(sph__run_gradv_diff, sph__t_tensor, SPH__OP_GRADV_DIFF)
SPH__RUNNER(sph__run_gradv_sym, sph__t_tensor, SPH__OP_GRADV_SYM)
SPH__RUNNER(sph__run_gradv_corr, sph__t_tensor, SPH__OP_GRADV_CORR)
SPH__RUNNER(sph__run_div_corr, sph__t_tensor, SPH__OP_DIV_CORR)
SPH__RUNNER(sph__run_correction, sph__t_tensor, SPH__OP_CORRECTION)
SPH__RUNNER(sph__run_div_std, sph__t_divcurl, SPH__OP_DIV_STD)
SPH__RUNNER(sph__run_div_diff, sph__t_divcurl, SPH__OP_DIV_DIFF)
SPH__RUNNER(sph__run_curl_std, sph__t_divcurl, SPH__OP_CURL_STD)
SPH__RUNNER(sph__run_curl_diff, sph__t_divcurl, SPH__OP_CURL_DIFF)
SPH__RUNNER(sph__run_laplacian, sph__t_lap, SPH__OP_LAPLACIAN)
SPH__RUNNER(sph__run_diffusion, sph__t_lap, SPH__OP_DIFFUSION)
SPH__RUNNER(sph__run_dens_grad, sph__t_grad, SPH__OP_DENS_GRAD)

/* ---- validation (everything is checked before any output is written) ---- */

/* SPH_OK when components 0..ncomp-1 are present and the stride positive. */
SPH_API int sph__view_ok(sph_view v, int ncomp)
{
    int a;
    for (a = 0; a < ncomp; ++a)
        if (v.p[a] == NULL) return SPH_ENULL;
    return v.stride > 0 ? SPH_OK : SPH_EINVAL;
}

SPH_API int sph__out_ok(sph_out v, int ncomp)
{
    int a;
    for (a = 0; a < ncomp; ++a)
        if (v.p[a] == NULL) return SPH_ENULL;
    return v.stride > 0 ? SPH_OK : SPH_EINVAL;
}

/* SPH_OK when h is usable by the operators in dim dimensions (sph__h_ok: 64
 * h^-(dim+2) finite, so alpha h^-(dim+2) and every F_ij are;
 * docs/operators.md, "Extreme cases"); else SPH_EH. */
SPH_API int sph__op_h(sph_real h, int dim)
{
    return sph__h_ok(h, dim) ? SPH_OK : SPH_EH;
}

/* Largest |coordinate| the operators take: twice it squared, times 3, stays
 * finite, so no x_ij and no r^2 overflows (docs/operators.md, "Extreme cases"). */
#define SPH__XMAX (sph__sqrt(SPH__REAL_MAX) / 4)

/* Value checks of n entries, ncomp components: kind 0 finite (SPH_ENONFINITE),
 * 1 usable h in dim dimensions (SPH_EH), 2 positive (SPH_EINVAL; densities),
 * 3 positions: |x| <= SPH__XMAX (SPH_EINVAL). NaN and Inf are SPH_ENONFINITE
 * for every kind but h. */
SPH_API int sph__scan(sph_view v, int ncomp, sph_idx n, int kind, int dim)
{
    sph_idx i;
    int a;
    for (i = 0; i < n; ++i)
        for (a = 0; a < ncomp; ++a) {
            const sph_real y = SPH__AT(v, a, i);
            if (kind == 1 && sph__op_h(y, dim) != SPH_OK) return SPH_EH;
            if (!sph__finite(y)) return SPH_ENONFINITE;
            if (kind == 2 && !(y > 0)) return SPH_EINVAL;
            if (kind == 3 && !(y <= SPH__XMAX && y >= -SPH__XMAX)) return SPH_EINVAL;
        }
    return SPH_OK;
}

/* Presence (and, with full validation, values) of a source view and its target
 * counterpart; an absent target view means "the source view" when the targets
 * are the sources. */
SPH_API int sph__field(const sph_ctx *c, sph_view src, sph_view tgt, int ncomp, int need_target,
                       int kind, sph_view *s_out, sph_view *t_out)
{
    const int same = c->x_target.p[0] == NULL;
    int st = sph__view_ok(src, ncomp);
    *s_out = src;
    *t_out = (same && tgt.p[0] == NULL) ? src : tgt;
    if (st == SPH_OK && need_target) st = sph__view_ok(*t_out, ncomp);
    if (st != SPH_OK || c->validate == SPH_VALIDATE_ARGS) return st;
    st = sph__scan(src, ncomp, c->list->n_sources, kind, c->dim);
    if (st == SPH_OK && need_target) st = sph__scan(*t_out, ncomp, c->list->n_targets, kind, c->dim);
    return st;
}

/* Needs of an operator. */
enum { SPH__N_V = 1, SPH__N_M = 2, SPH__N_RHO = 4, SPH__N_FI = 8, SPH__N_K = 16 };

/* Checks the context and the field(s) of one operator (fields f, k with ncomp
 * components) and fills A. */
SPH_API int sph__setup(const sph_ctx *c, int need, int ncomp, sph_view f, sph_view ft, sph_view k,
                       sph_view kt, sph__args *A)
{
    const int full = c != NULL && c->validate != SPH_VALIDATE_ARGS;
    sph_view none = sph_view_none(), unused;
    int st, a;
    if (c == NULL || c->list == NULL) return SPH_ENULL;
    if ((st = sph_kernel_check(c->kernel, c->dim)) != SPH_OK) return st;
#if defined(SPH_KERNEL)
    if ((int)c->kernel != (int)(SPH_KERNEL)) return SPH_EKERNEL;
#endif
#if defined(SPH_DIM)
    if (c->dim != (SPH_DIM)) return SPH_EDIM;
#endif
    /* the counts against each other first: nothing is read beyond what they allow */
    if (c->list->offset == NULL) return SPH_ENULL;
    if (c->list->n_targets < 0 || c->list->n_sources < 0) return SPH_ESIZE;
    if (c->x_target.p[0] == NULL && c->list->n_targets > c->list->n_sources) return SPH_ESIZE;
    if (full && (st = sph_neighbours_check(c->list)) != SPH_OK) return st;
    if (c->list->offset[c->list->n_targets] > 0 && c->list->index == NULL) return SPH_ENULL;
    if (!(c->rcond_min >= 0 && c->rcond_min < 1)) return SPH_EINVAL;
    for (a = 0; c->box != NULL && a < c->dim; ++a)
        if (c->box->periodic[a] && !(c->box->length[a] > 0 && c->box->length[a] <= SPH__REAL_MAX &&
                                     1 / c->box->length[a] <= SPH__REAL_MAX)) /* (O0) takes 1/L */
            return SPH_EINVAL;
    A->kernel = c->kernel;
    A->dim = c->dim;
    A->hv = c->h_source.p[0] != NULL;
    A->pb = 0;
    for (a = 0; a < 3; ++a) {
        const int per = c->box != NULL && a < c->dim && c->box->periodic[a];
        A->L[a] = per ? c->box->length[a] : 0;
        A->invL[a] = per ? 1 / c->box->length[a] : 0;
        A->pb |= per;
    }
    A->nt = c->list->n_targets;
    A->h = c->h;
    A->rcond_min = c->rcond_min;
    A->box = c->box;
    A->off = c->list->offset;
    A->idx = c->list->index;
    A->V = A->m = A->rho = A->rhot = A->f = A->ft = A->k = A->kt = A->hs = A->ht = none;
    A->T = NULL;
    A->Ts = 0;
    if ((st = sph__field(c, c->x, c->x_target, c->dim, 1, 3, &A->x, &A->xt)) != SPH_OK) return st;
    if (A->hv) st = sph__field(c, c->h_source, c->h_target, 1, 1, 1, &A->hs, &A->ht);
    else st = sph__op_h(c->h, c->dim);
    if (st != SPH_OK) return st;
    if ((need & SPH__N_V) && (st = sph__field(c, c->V, none, 1, 0, 0, &A->V, &unused)) != SPH_OK)
        return st;
    if ((need & SPH__N_M) && (st = sph__field(c, c->m, none, 1, 0, 0, &A->m, &unused)) != SPH_OK)
        return st;
    if ((need & SPH__N_RHO) &&
        (st = sph__field(c, c->rho, c->rho_target, 1, 1, 2, &A->rho, &A->rhot)) != SPH_OK)
        return st;
    if ((need & SPH__N_K) && (st = sph__field(c, k, kt, 1, 1, 0, &A->k, &A->kt)) != SPH_OK) return st;
    if (ncomp > 0) st = sph__field(c, f, ft, ncomp, (need & SPH__N_FI) != 0, 0, &A->f, &A->ft);
    return st;
}

/* Runs a prepared operator when the setup succeeded; stores the fallback count. */
SPH_API int sph__finish(int st, const sph__args *A, sph_idx (*run)(const sph__args *),
                        sph_idx *count)
{
    sph_idx n;
    if (st != SPH_OK) return st;
    n = run(A);
    if (count != NULL) *count = n;
    return SPH_OK;
}

/* ---- public operators ---- */

/* (O2) rho_i = sum_j m_j W_ij(h_i) (needs ctx.m). */
SPH_API int sph_density(const sph_ctx *c, sph_out rho)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_M, 0, sph_view_none(), sph_view_none(), sph_view_none(),
                        sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(rho, 1);
    A.out = rho;
    return sph__finish(st, &A, sph__run_density, NULL);
}

/* (O3) <f>_i = sum_j V_j f_j W_ij(h_i) (needs ctx.V). */
SPH_API int sph_interpolate(const sph_ctx *c, sph_view f, sph_out out)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_V, 1, f, sph_view_none(), sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(out, 1);
    A.out = out;
    return sph__finish(st, &A, sph__run_interp, NULL);
}

/* (O3) Shepard: sum_j V_j f_j W_ij / sum_j V_j W_ij; 0 for a target whose
 * denominator is 0 (no sources in reach), counted in *n_empty (may be NULL). */
SPH_API int sph_interpolate_shepard(const sph_ctx *c, sph_view f, sph_out out, sph_idx *n_empty)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_V, 1, f, sph_view_none(), sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(out, 1);
    A.out = out;
    return sph__finish(st, &A, sph__run_shepard, n_empty);
}

/* (O4)-(O8) gradient of the scalar f (f_target: target values, needed by all
 * schemes but the standard one when targets are not the sources). Corrected:
 * targets with an ill-conditioned M fall back to the difference scheme, counted
 * in *n_fallback (may be NULL). Pressure: f is p, needs ctx.m, rho, rho_target. */
SPH_API int sph_gradient(const sph_ctx *c, sph_scheme scheme, sph_view f, sph_view f_target,
                         sph_out grad, sph_idx *n_fallback)
{
    sph__args A;
    sph_idx (*run)(const sph__args *) =
        scheme == SPH_SCHEME_STANDARD ? sph__run_grad_std
        : scheme == SPH_SCHEME_DIFFERENCE ? sph__run_grad_diff
        : scheme == SPH_SCHEME_SYMMETRIC ? sph__run_grad_sym
        : scheme == SPH_SCHEME_CORRECTED ? sph__run_grad_corr
        : scheme == SPH_SCHEME_PRESSURE ? sph__run_grad_pres : NULL;
    const int need = scheme == SPH_SCHEME_PRESSURE ? SPH__N_M | SPH__N_RHO | SPH__N_FI
                     : scheme == SPH_SCHEME_STANDARD ? SPH__N_V : SPH__N_V | SPH__N_FI;
    int st = run == NULL ? SPH_EINVAL : sph__setup(c, need, 1, f, f_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(grad, c->dim);
    A.out = grad;
    if (n_fallback != NULL && st == SPH_OK) *n_fallback = 0;
    return sph__finish(st, &A, run, scheme == SPH_SCHEME_CORRECTED ? n_fallback : NULL);
}

/* (O2) and (O5) in one pass over the list: rho_i = sum_j m_j W_ij(h_i) and
 * the difference gradient sum_j V_j (f_j - f_i) grad_i W_ij(h_ij) (needs
 * ctx.m and ctx.V; V_j from the previous densities, as a solver's step has
 * them). The same values as sph_density and sph_gradient(DIFFERENCE) to
 * round-off, in about the time of one of them. */
SPH_API int sph_density_gradient(const sph_ctx *c, sph_view f, sph_view f_target, sph_out rho,
                                 sph_out grad)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_M | SPH__N_V | SPH__N_FI, 1, f, f_target, sph_view_none(),
                        sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(rho, 1);
    if (st == SPH_OK) st = sph__out_ok(grad, c->dim);
    A.out = grad;
    A.out2 = rho;
    return sph__finish(st, &A, sph__run_dens_grad, NULL);
}

/* (O17) velocity-gradient tensor of the vector v (dim components):
 * T[i * T_stride + a * dim + b] = d v_a / d x_b, schemes standard, difference,
 * symmetric, corrected (fallbacks as sph_gradient). T_stride >= dim * dim. */
SPH_API int sph_gradient_vector(const sph_ctx *c, sph_scheme scheme, sph_view v, sph_view v_target,
                                sph_real *T, ptrdiff_t T_stride, sph_idx *n_fallback)
{
    sph__args A;
    sph_idx (*run)(const sph__args *) =
        scheme == SPH_SCHEME_STANDARD ? sph__run_gradv_std
        : scheme == SPH_SCHEME_DIFFERENCE ? sph__run_gradv_diff
        : scheme == SPH_SCHEME_SYMMETRIC ? sph__run_gradv_sym
        : scheme == SPH_SCHEME_CORRECTED ? sph__run_gradv_corr : NULL;
    const int need = scheme == SPH_SCHEME_STANDARD ? SPH__N_V : SPH__N_V | SPH__N_FI;
    int st = run == NULL ? SPH_EINVAL
             : sph__setup(c, need, c != NULL ? c->dim : 1, v, v_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK && T == NULL) st = SPH_ENULL;
    if (st == SPH_OK && T_stride < (ptrdiff_t)c->dim * c->dim) st = SPH_EINVAL;
    A.T = T;
    A.Ts = T_stride;
    if (n_fallback != NULL && st == SPH_OK) *n_fallback = 0;
    return sph__finish(st, &A, run, scheme == SPH_SCHEME_CORRECTED ? n_fallback : NULL);
}

/* (O9), (O10), (O18) divergence of v: standard, difference or corrected
 * (trace of the corrected tensor; fallbacks as sph_gradient). */
SPH_API int sph_divergence(const sph_ctx *c, sph_scheme scheme, sph_view v, sph_view v_target,
                           sph_out div, sph_idx *n_fallback)
{
    sph__args A;
    sph_idx (*run)(const sph__args *) =
        scheme == SPH_SCHEME_STANDARD ? sph__run_div_std
        : scheme == SPH_SCHEME_DIFFERENCE ? sph__run_div_diff
        : scheme == SPH_SCHEME_CORRECTED ? sph__run_div_corr : NULL;
    const int need = scheme == SPH_SCHEME_STANDARD ? SPH__N_V : SPH__N_V | SPH__N_FI;
    int st = run == NULL ? SPH_EINVAL
             : sph__setup(c, need, c != NULL ? c->dim : 1, v, v_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(div, 1);
    A.out = div;
    if (n_fallback != NULL && st == SPH_OK) *n_fallback = 0;
    return sph__finish(st, &A, run, scheme == SPH_SCHEME_CORRECTED ? n_fallback : NULL);
}

/* (O11) curl of v, standard or difference: dim 2 writes the scalar
 * d v_y/dx - d v_x/dy to component 0, dim 3 the vector; dim 1 is SPH_EDIM. */
SPH_API int sph_curl(const sph_ctx *c, sph_scheme scheme, sph_view v, sph_view v_target, sph_out curl)
{
    sph__args A;
    sph_idx (*run)(const sph__args *) =
        scheme == SPH_SCHEME_STANDARD ? sph__run_curl_std
        : scheme == SPH_SCHEME_DIFFERENCE ? sph__run_curl_diff : NULL;
    const int need = scheme == SPH_SCHEME_STANDARD ? SPH__N_V : SPH__N_V | SPH__N_FI;
    int st = run == NULL ? SPH_EINVAL
             : sph__setup(c, need, c != NULL ? c->dim : 1, v, v_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK && c->dim == 1) st = SPH_EDIM;
    if (st == SPH_OK) st = sph__out_ok(curl, c->dim == 2 ? 1 : 3);
    A.out = curl;
    return sph__finish(st, &A, run, NULL);
}

/* (O12) lap f_i = 2 sum_j V_j (f_i - f_j) F_ij. */
SPH_API int sph_laplacian(const sph_ctx *c, sph_view f, sph_view f_target, sph_out lap)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_V | SPH__N_FI, 1, f, f_target, sph_view_none(), sph_view_none(), &A);
    if (st == SPH_OK) st = sph__out_ok(lap, 1);
    A.out = lap;
    return sph__finish(st, &A, sph__run_laplacian, NULL);
}

/* (O14) div(k grad f)_i = sum_j V_j k_ij (f_i - f_j) F_ij, k_ij from (O13);
 * for a constant k it equals k times sph_laplacian. */
SPH_API int sph_diffusion(const sph_ctx *c, sph_view k, sph_view k_target, sph_view f,
                          sph_view f_target, sph_out out)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_V | SPH__N_FI | SPH__N_K, 1, f, f_target, k, k_target, &A);
    if (st == SPH_OK) st = sph__out_ok(out, 1);
    A.out = out;
    return sph__finish(st, &A, sph__run_diffusion, NULL);
}

/* (O15), (O16) the correction matrix B_i = M_i^-1 of every target:
 * B[i * B_stride + a * dim + b]; identity where M_i is ill-conditioned
 * (counted in *n_fallback, may be NULL). B_stride >= dim * dim. */
SPH_API int sph_correction_matrix(const sph_ctx *c, sph_real *B, ptrdiff_t B_stride, sph_idx *n_fallback)
{
    sph__args A;
    int st = sph__setup(c, SPH__N_V, 0, sph_view_none(), sph_view_none(), sph_view_none(),
                        sph_view_none(), &A);
    if (st == SPH_OK && B == NULL) st = SPH_ENULL;
    if (st == SPH_OK && B_stride < (ptrdiff_t)c->dim * c->dim) st = SPH_EINVAL;
    A.T = B;
    A.Ts = B_stride;
    return sph__finish(st, &A, sph__run_correction, n_fallback);
}

/* The validator behind SPH_ENONFINITE (docs/operators.md, "Extreme cases"):
 * scans components 0..ncomp-1 of particles 0..n-1 of f in particle order and
 * returns SPH_ENONFINITE at the first NaN or Inf, its particle in *first_bad
 * (may be NULL); SPH_OK and *first_bad = -1 when every value is finite.
 * SPH_ENULL for an absent component, SPH_EINVAL for ncomp outside 1..3 or a
 * stride <= 0, SPH_ESIZE for n < 0 (*first_bad untouched on those). */
SPH_API int sph_check_field(sph_view f, int ncomp, sph_idx n, sph_idx *first_bad)
{
    sph_idx i;
    int a, st;
    if (ncomp < 1 || ncomp > 3) return SPH_EINVAL;
    if ((st = sph__view_ok(f, ncomp)) != SPH_OK) return st;
    if (n < 0) return SPH_ESIZE;
    for (i = 0; i < n; ++i)
        for (a = 0; a < ncomp; ++a) {
            const sph_real y = SPH__AT(f, a, i);
            if (!sph__finite(y)) {
                if (first_bad != NULL) *first_bad = i;
                return SPH_ENONFINITE;
            }
        }
    if (first_bad != NULL) *first_bad = -1;
    return SPH_OK;
}


/* ======================================================================== */
/* 7. Neighbour search                                                       */
/* ======================================================================== */
/* Cell-list neighbour search (docs/neighbours.md). Builds the CSR lists of
 * section 4 in O(N), in arrays the caller owns; nothing is allocated.
 *
 *   size_t bytes;                                             1. size query
 *   sph_nsearch_workspace_size(dim, xs, ns, hs, cell, box, &bytes);
 *   void *work = malloc(bytes);
 *   sph_nsearch g;                                            2. bin sources
 *   sph_nsearch_build(&g, dim, xs, ns, hs, cell, box, work, bytes);
 *   sph_off *offset = malloc((nt + 1) * sizeof *offset);       3. count
 *   sph_nsearch_count(&g, xt, nt, ht, h, kappa, SPH_NSEARCH_GATHER, offset);
 *   sph_idx *index = malloc(offset[nt] * sizeof *index);       4. fill
 *   sph_nsearch_fill(&g, xt, nt, ht, h, kappa, SPH_NSEARCH_GATHER, offset, index, offset[nt]);
 *
 * or steps 3 and 4 in one search per target, into an index with some slack
 * (SPH_ESIZE, offset complete, when it is too short: then fill as in 4):
 *   sph_nsearch_lists(&g, xt, nt, ht, h, kappa, SPH_NSEARCH_GATHER, offset, index, capacity, &pairs);
 *
 * Criterion (eq. (N1)-(N3)): source j is a neighbour of target i iff
 * r_ij^2 < R^2 with R = kappa h_i (SPH_NSEARCH_GATHER) or
 * R = kappa max(h_i, h_j) (SPH_NSEARCH_SYMMETRIC), r_ij^2 the sum over the
 * axes of sph_box_delta(box, a, x_i,a - x_j,a)^2 in axis order: exactly the
 * arithmetic of a brute-force double loop, so the lists are equal bit for bit.
 * Within each target the sources are in ascending index (deterministic, and
 * the same for any number of OpenMP threads).
 *
 * Sources (xs, ns, optional per-source h hs) are binned once by build into a
 * grid of cells of edge >= cell (recommended: kappa h / 2); targets (xt, nt,
 * optional per-target h ht) are any point set: the sources themselves,
 * probe points, ghosts. Per-particle h are views like every other field
 * (sph_view_soa(h, NULL, NULL), or sph_view_none() when absent); h is the
 * uniform smoothing length wherever the view is absent. Any cell size gives the same lists; it
 * only sets speed and workspace. Periodic axes of box tile the period with
 * n_a = max(1, floor(L_a / cell)) cells (eq. (N4)) and positions anywhere are
 * wrapped into it; the other axes span the bounding box of the sources (the
 * box's lo and length are not used there). The grid copies the source
 * positions (sorted by cell) into the workspace: the caller's arrays may
 * change after build, the workspace must not.
 *
 * Algorithm: a stable counting sort bins the sources (O(N + cells)); each
 * target scans only the cells whose nearest point lies within its radius, an
 * x row of cells at a time as one contiguous run of sorted sources (two where
 * a periodic axis wraps), then sorts its list. With cells of R/2 that is about
 * 2.5 candidate checks per neighbour in 3-D (docs/neighbours.md). A target
 * whose reach is at most 4 cells finds its rows from squared cell gaps
 * computed once per axis (clamped at open faces, wrapped round periodic
 * axes); each run carries its periodic image offset, so the checks need no
 * minimum image. Runs are checked in branch-free blocks of 8
 * sources (16, two vectors, with AVX-512). Count, fill and lists run in
 * parallel over targets under OpenMP.
 *
 * Optional locality: sph_nsearch_permutation gives perm[new] = old (sources
 * by cell); sph_permute applies it to any field. Searching the sorted
 * particles is faster and their lists map back to the unsorted ones.
 *
 * Every function returns SPH_OK or a negative status: SPH_EDIM (dim outside
 * 1..3), SPH_ESIZE (negative count, more than SPH_NSEARCH_MAX_SOURCES
 * sources, workspace or index too small), SPH_EGRID (more than
 * SPH_NSEARCH_MAX_CELLS cells: a source far from the others, or a cell size
 * too small for the cloud), SPH_ENULL, SPH_EH (h not positive and finite),
 * SPH_ENONFINITE (NaN or Inf position), SPH_EINVAL (cell or kappa not
 * positive and finite, bad mode or box, grid not built, offsets inconsistent
 * with the targets), SPH_EPERIOD (a search radius above half a period: the
 * minimum image of eq. (N3) would see one image of a source where two or
 * more lie within reach), SPH_EINDEX (not a permutation).
 *
 * Limits, in one place (docs/neighbours.md, "Limits"): particle counts and
 * source indices are sph_idx (int32), so at most 2^31 - 1 targets and
 * SPH_NSEARCH_MAX_SOURCES = 2^31 - 17 sources; a grid has at most
 * SPH_NSEARCH_MAX_CELLS = 2^29 - 1 cells; list positions are sph_off (int64),
 * so the total list length is bounded by memory alone. */

enum { SPH_NSEARCH_GATHER = 0, SPH_NSEARCH_SYMMETRIC = 1 };

/* Hard limits (docs/neighbours.md, "Limits"): cells of a grid, per axis
 * and in all, so that every cell index stays in int (more: SPH_EGRID), and
 * sources of a grid, so that the padded arrays stay indexable by sph_idx
 * (more: SPH_ESIZE). */
#define SPH_NSEARCH_MAX_CELLS 536870911    /* 2^29 - 1 */
#define SPH_NSEARCH_MAX_SOURCES 2147483631 /* 2^31 - 17 */

/* A cell grid over the sources. Filled by sph_nsearch_build; the arrays live
 * in the caller's workspace. */
typedef struct {
    int dim;              /* 1..3 once built, 0 otherwise */
    int n[3];             /* cells per axis (1 for unused axes) */
    int n_cells;          /* n[0] n[1] n[2] */
    sph_idx n_sources;
    sph_real lo[3];       /* grid origin */
    sph_real w[3];        /* cell width per axis */
    sph_real inv_w[3];    /* 1 / w */
    sph_real quarter[3];  /* L / 4 on periodic axes, the largest real elsewhere */
    sph_real quarter2;    /* smallest quarter[a]^2 of the periodic axes, the largest real without */
    sph_real slack;       /* rounding allowance added to every search radius */
    sph_real h_max;       /* largest per-source h (0 without per-source h) */
    sph_box box;          /* copy of the caller's box (periodic axes) */
    sph_idx *cell_start;  /* [n_cells + 1]: sources of cell c are sorted positions cell_start[c].. */
    sph_idx *order;       /* [n_padded]: source index at each sorted position */
    sph_real *x;          /* [dim * n_padded]: source positions in sorted order, by axis: x[a n_padded + k] */
    sph_real *h;          /* [n_padded] per-source h in sorted order, or NULL */
    sph_idx n_padded;     /* n_sources + SPH__NS_BLOCK: the arrays' length (padding read by the blocked checks) */
    int n_occupied;       /* cells holding at least one source (fill ratio n_occupied / n_cells) */
} sph_nsearch;

/* Candidates are checked in blocks of SPH__NS_BLOCK consecutive sorted
 * sources; the arrays of the grid are padded by one block. A target's runs
 * are collected SPH__NS_RUNS at a time before any is checked, so that the
 * cell arithmetic of one row does not wait on the checks of the last. */
#if SPH__NS_COMPRESS
#define SPH__NS_BLOCK 16
#else
#define SPH__NS_BLOCK 8
#endif
#define SPH__NS_RUNS 32

/* Cells of one axis within reach of a target: up to two runs of cells
 * (wrapped index lo..hi, geometric position of cell k is k + shift), in
 * ascending cell order; full = the whole periodic axis (distance 0). */
typedef struct {
    int lo[2], hi[2], shift[2];
    int count;
    int full;
} sph__span;

SPH_API sph_real sph__nsearch_eps(void)
{
    return sizeof(sph_real) == sizeof(float) ? (sph_real)FLT_EPSILON : (sph_real)DBL_EPSILON;
}

/* Component a of particle i of a view. */
SPH_API sph_real sph__ns_at(sph_view v, int a, sph_idx i) { return v.p[a][(ptrdiff_t)i * v.stride]; }

/* The view from particle i0 on (ncomp components; an absent view stays absent). */
SPH_API sph_view sph__ns_tail(sph_view v, int ncomp, sph_idx i0)
{
    int a;
    for (a = 0; a < ncomp; ++a)
        if (v.p[a] != NULL) v.p[a] += (ptrdiff_t)i0 * v.stride;
    return v;
}

/* Largest |x_a| over n particles of a view (0 for none), or -1 when one of
 * them is NaN or infinite. One pass without a branch. */
SPH_API sph_real sph__ns_absmax(sph_view v, int a, sph_idx n)
{
    const sph_real *p = v.p[a];
    const ptrdiff_t st = v.stride;
    sph_real m = 0;
    int nan = 0;
    sph_idx i;
    for (i = 0; i < n; ++i) {
        const sph_real x = p[(ptrdiff_t)i * st], ax = x < 0 ? -x : x;
        m = ax > m ? ax : m;
        nan |= x != x;
    }
    return nan || !(m <= SPH__REAL_MAX) ? (sph_real)-1 : m;
}

/* Checks a position view of n particles: SPH_ENULL or SPH_ENONFINITE; the
 * largest |x_a| per axis into amax (when not NULL). */
SPH_API int sph__ns_scan_x(int dim, sph_view x, sph_idx n, sph_real *amax)
{
    int a;
    for (a = 0; a < dim && n > 0; ++a)
        if (x.p[a] == NULL) return SPH_ENULL;
    for (a = 0; a < dim; ++a) {
        const sph_real m = n > 0 ? sph__ns_absmax(x, a, n) : 0;
        if (m < 0) return SPH_ENONFINITE;
        if (amax != NULL) amax[a] = m;
    }
    return SPH_OK;
}

SPH_API int sph__ns_check_x(int dim, sph_view x, sph_idx n) { return sph__ns_scan_x(dim, x, n, NULL); }

/* Checks n per-particle smoothing lengths (absent view: none) in dim
 * dimensions (sph__h_ok, so that the lists serve the operators): SPH_EH if
 * any is bad; the largest into *hmax (0 for none). */
SPH_API int sph__ns_check_h(sph_view h, sph_idx n, int dim, sph_real *hmax)
{
    sph_idx i;
    *hmax = 0;
    for (i = 0; h.p[0] != NULL && i < n; ++i) {
        const sph_real hi = h.p[0][(ptrdiff_t)i * h.stride];
        if (!sph__h_ok(hi, dim)) return SPH_EH;
        *hmax = hi > *hmax ? hi : *hmax;
    }
    return SPH_OK;
}

/* Position of x along axis a relative to the grid origin; wrapped into
 * [0, L] on a periodic axis (eq. (N4)). */
SPH_API sph_real sph__nsearch_rel(const sph_nsearch *g, int a, sph_real x)
{
    sph_real t = x - g->lo[a], L = g->box.length[a];
    if (g->box.periodic[a]) t -= L * sph__floor(t / L);
    return t;
}

/* Cell of relative position t along axis a, clamped into 0..n-1. */
SPH_API int sph__nsearch_cell(const sph_nsearch *g, int a, sph_real t)
{
    sph_real u = sph__floor(t * g->inv_w[a]), top = (sph_real)(g->n[a] - 1);
    return u > 0 ? (int)(u < top ? u : top) : 0;
}

/* Linear cell of a source position (3 slots). */
SPH_API int sph__nsearch_source_cell(const sph_nsearch *g, const sph_real *x)
{
    int k[3] = {0, 0, 0}, a;
    for (a = 0; a < g->dim; ++a) k[a] = sph__nsearch_cell(g, a, sph__nsearch_rel(g, a, x[a]));
    return k[0] + g->n[0] * (k[1] + g->n[1] * k[2]);
}

/* Cells along axis a that meet [t - hw, t + hw]. */
SPH_API void sph__nsearch_span(const sph_nsearch *g, int a, sph_real t, sph_real hw, sph__span *s)
{
    const sph_real n = (sph_real)g->n[a];
    sph_real k0 = sph__floor((t - hw) * g->inv_w[a]), k1 = sph__floor((t + hw) * g->inv_w[a]);
    s->full = 0;
    s->count = 1;
    s->shift[0] = s->shift[1] = 0;
    if (g->box.periodic[a] && !(k1 - k0 + 1 < n)) {
        s->full = 1;
        s->lo[0] = 0;
        s->hi[0] = g->n[a] - 1;
    } else if (g->box.periodic[a]) { /* fewer than n cells: each at most once */
        int i0 = (int)k0, i1 = (int)k1, m = g->n[a];
        s->lo[0] = i0 < 0 ? 0 : i0;
        s->hi[0] = i1 < m ? i1 : m - 1;
        s->shift[0] = i1 < m ? 0 : m;
        if (i0 < 0 || i1 >= m) { /* wrapped: the run [0, ..] first, then [.., m-1] */
            s->count = 2;
            s->lo[0] = 0;
            s->hi[0] = i0 < 0 ? i1 : i1 - m;
            s->lo[1] = i0 < 0 ? i0 + m : i0;
            s->hi[1] = m - 1;
            s->shift[1] = i0 < 0 ? -m : 0;
        }
    } else {
        k0 = k0 > 0 ? (k0 < n ? k0 : n) : 0;
        k1 = k1 < n - 1 ? (k1 > -1 ? k1 : -1) : n - 1;
        s->lo[0] = (int)k0;
        s->hi[0] = (int)k1;
    }
}

/* Distance along axis a from t to cell k (geometric index), 0 inside. */
SPH_API sph_real sph__nsearch_gap(const sph_nsearch *g, int a, sph_real t, int k)
{
    sph_real below = (sph_real)k * g->w[a] - t, above = t - (sph_real)(k + 1) * g->w[a];
    sph_real d = below > above ? below : above;
    return d > 0 ? d : 0;
}

/* sph_box_delta(box, a, dx), skipping its division where its value is known:
 * for |dx| <= L/4 the rounded dx/L + 1/2 lies in [1/4, 3/4], its floor is 0
 * and sph_box_delta returns dx itself, bit for bit. */
SPH_API sph_real sph__nsearch_delta(const sph_nsearch *g, int a, sph_real dx)
{
    return (dx < 0 ? -dx : dx) <= g->quarter[a] ? dx : sph_box_delta(&g->box, a, dx);
}

/* Parameters of one target's search. */
typedef struct {
    sph_real xt[3];   /* target position */
    sph_real t[3];    /* relative to the grid (eq. (N4)) */
    sph_real hi;      /* target h */
    sph_real hu;      /* uniform h (sources without per-source h) */
    sph_real kappa;
    sph_real R2;      /* R^2 when the same for every source (gather, or uniform h), else -1 */
    int symmetric;
    sph_idx *seg;     /* fill: the target's part of index[], else NULL */
    sph_off cap;      /* its length */
    sph_off found;    /* neighbours found so far */
    sph_off checked;  /* candidates checked so far */
    sph_off redone;   /* blocks redone by sph__nsearch_in for the minimum image (tests read it) */
    int n_runs;       /* runs of sorted sources collected, not yet checked */
    sph_idx runs[2 * SPH__NS_RUNS];
    int image[SPH__NS_RUNS]; /* per run: the sources are seen at x_j + w L, eq. (N7): sph__ns_image */
} sph__probe;

/* Image code of w = -1, 0, 1 periods along axis a: 2 bits per axis, 0 for
 * none, so that a run without any image has code 0. */
SPH_API int sph__ns_image(int w, int a) { return (w > 0 ? 1 : w < 0 ? 2 : 0) << (2 * a); }

/* The image offsets s_a = w_a L_a of eq. (N7) of an image code. */
SPH_API void sph__ns_offsets(const sph_nsearch *g, int code, sph_real *s)
{
    int a;
    for (a = 0; a < 3; ++a) {
        const int c = (code >> (2 * a)) & 3;
        s[a] = c == 0 ? 0 : c == 1 ? g->box.length[a] : -g->box.length[a];
    }
}

/* 1 when sorted source k meets criterion (N1)/(N2) for the target of p:
 * r_ij^2 of eq. (N3), summed in axis order, against R^2 = (kappa h)^2. */
SPH_API int sph__nsearch_in(const sph_nsearch *g, const sph__probe *p, sph_idx k, const int dim)
{
    sph_real r2 = 0, hj = g->h != NULL ? g->h[k] : p->hu, R;
    int a;
    for (a = 0; a < dim; ++a) {
        sph_real d = sph__nsearch_delta(g, a, p->xt[a] - g->x[(ptrdiff_t)a * g->n_padded + k]);
        r2 += d * d;
    }
    R = p->kappa * (p->symmetric && hj > p->hi ? hj : p->hi);
    return r2 < R * R;
}

/* Bit k set when sorted source b + k (k < SPH__NS_BLOCK, b + k < k1) meets
 * the criterion, as sph__nsearch_in decides it. One loop without a branch
 * over a whole block (the padding beyond k1 is masked). The run's image
 * offset s (eq. (N7); IMG: the run has one) gives d_a = (x_t - x_j) - s_a,
 * bit for bit the value sph__nsearch_delta returns whenever |d_a| is at
 * most the quarter period. Where r^2 exceeds the smallest squared quarter
 * period that may not hold (a wrong image, or a box not much larger than
 * the radius): such a block is redone by sph__nsearch_in. HV: R per source
 * (symmetric with per-source h); dim, HV, IMG constants once inlined. */
SPH__INLINE unsigned sph__nsearch_mask(const sph_nsearch *g, sph__probe *p, sph_idx b, sph_idx k1,
                                       const sph_real *s, const int dim, const int HV, const int IMG)
{
    const sph_real *x = g->x + b;
    const ptrdiff_t stride = g->n_padded;
    unsigned mask = 0;
    int k, a, wide = 0;
    for (k = 0; k < SPH__NS_BLOCK; ++k) {
        sph_real r2 = 0, R2 = p->R2;
        for (a = 0; a < dim; ++a) {
            const sph_real d = IMG ? (p->xt[a] - x[a * stride + k]) - s[a] : p->xt[a] - x[a * stride + k];
            r2 += d * d;
        }
        wide |= (r2 > g->quarter2) & (b + k < k1);
        if (HV) {
            const sph_real hj = g->h[b + k], R = p->kappa * (hj > p->hi ? hj : p->hi);
            R2 = R * R;
        }
        mask |= (unsigned)((r2 < R2) & (b + k < k1)) << k;
    }
    if (wide) {
        ++p->redone;
        for (mask = 0, k = 0; k < SPH__NS_BLOCK && b + k < k1; ++k)
            mask |= (unsigned)sph__nsearch_in(g, p, b + k, dim) << k;
    }
    return mask;
}

#if SPH__NS_COMPRESS
/* 8 doubles rounded to float (for SPH_REAL float). */
SPH__INLINE __m512d sph__nsearch_round8(__m512d v)
{
    return _mm512_cvtps_pd(_mm512_cvtpd_ps(v));
}

/* sph__nsearch_mask in AVX-512 registers: r^2 of the 16 sources of a block,
 * as two vectors of 8 doubles. With double, d_a is the scalar value bit for
 * bit. With float, positions are widened exactly, and d_a = x_t - x_j is
 * exact, within half a float ulp of the scalar d_a; where an image offset
 * is subtracted, x_t - x_j is first rounded to float as the scalar one is
 * (unrounded, its error of half an ulp of the period would be many ulp of
 * d_a). The sum of squares may round otherwise than the scalar r^2
 * (contraction into fused multiply-adds is the compiler's choice; with
 * SPH_REAL float the scalar sum is rounded to float), so r^2 differs from
 * the scalar one by at most a few ulp of sph_real; a source within 16 ulp
 * of R^2 is therefore decided by sph__nsearch_in, and a block beyond the
 * smallest squared quarter period is redone by the scalar mask, so the
 * lists stay those of the scalar criterion bit for bit. */
SPH__INLINE unsigned sph__nsearch_mask16(const sph_nsearch *g, sph__probe *p, sph_idx b, sph_idx k1,
                                         const sph_real *s, const int dim, const int HV, const int IMG)
{
    const double eps = 16 * (sizeof(sph_real) == sizeof(float) ? (double)FLT_EPSILON : DBL_EPSILON);
    const ptrdiff_t stride = g->n_padded;
    const unsigned live = k1 - b >= 16 ? 0xFFFFu : (1u << (k1 - b)) - 1u;
    unsigned in = 0, near_edge = 0, wide = 0, mask;
    int a, k, half;
    for (half = 0; half < 2; ++half) {
        const sph_real *x = g->x + b + 8 * half;
        const __mmask8 lv = (__mmask8)(live >> (8 * half));
        if (lv == 0) break; /* a run of 8 or fewer: no live lane in the second vector */
        __m512d r2 = _mm512_setzero_pd(), R2 = _mm512_set1_pd((double)p->R2);
        __mmask8 in8;
        for (a = 0; a < dim; ++a) {
            __m512d d = _mm512_sub_pd(_mm512_set1_pd((double)p->xt[a]), sph__load8(x + a * stride));
            if (IMG && sizeof(sph_real) == sizeof(float) && s[a] != 0) d = sph__nsearch_round8(d);
            if (IMG) d = _mm512_sub_pd(d, _mm512_set1_pd((double)s[a]));
            r2 = _mm512_fmadd_pd(d, d, r2);
        }
        wide |= _mm512_mask_cmp_pd_mask(lv, r2, _mm512_set1_pd((double)g->quarter2), _CMP_GT_OQ);
        if (HV) {
            const __m512d R = _mm512_mul_pd(_mm512_set1_pd((double)p->kappa),
                                            _mm512_max_pd(sph__load8(g->h + b + 8 * half),
                                                          _mm512_set1_pd((double)p->hi)));
            R2 = _mm512_mul_pd(R, R);
        }
        in8 = _mm512_mask_cmp_pd_mask(lv, r2, _mm512_mul_pd(R2, _mm512_set1_pd(1 - eps)), _CMP_LT_OQ);
        in |= (unsigned)in8 << (8 * half);
        near_edge |= (unsigned)(_mm512_mask_cmp_pd_mask(lv, r2, _mm512_mul_pd(R2, _mm512_set1_pd(1 + eps)), _CMP_LT_OQ) &
                                (__mmask8)~in8) << (8 * half);
    }
    if (wide) return sph__nsearch_mask(g, p, b, k1, s, dim, HV, IMG);
    mask = in;
    for (k = 0; near_edge != 0; ++k, near_edge >>= 1)
        if (near_edge & 1u) mask |= (unsigned)sph__nsearch_in(g, p, b + k, dim) << k;
    return mask;
}
#define SPH__NSEARCH_MASK(g, p, b, k1, s, dim, HV, IMG) sph__nsearch_mask16(g, p, b, k1, s, dim, HV, IMG)
#else
#define SPH__NSEARCH_MASK(g, p, b, k1, s, dim, HV, IMG) sph__nsearch_mask(g, p, b, k1, s, dim, HV, IMG)
#endif

/* Counts (p->seg NULL) or appends to the target's segment (never past its
 * end) the sorted sources k0..k1-1 that meet the criterion; returns the new
 * count. A block with room for all its sources in the segment stores them
 * all and keeps those inside, without a branch; with AVX-512 a block whose
 * accepted sources fit (the last of an exact segment) stores just those. */
SPH__INLINE sph_off sph__nsearch_run_blocks(const sph_nsearch *g, sph__probe *p, sph_idx k0, sph_idx k1,
                                            const sph_real *s, sph_off m, const int dim, const int HV,
                                            const int IMG)
{
    sph_idx b;
    int k;
    for (b = k0; b < k1; b += SPH__NS_BLOCK) {
        const unsigned mask = SPH__NSEARCH_MASK(g, p, b, k1, s, dim, HV, IMG);
#if SPH__NS_COMPRESS
        /* the accepted indices compressed into one register, stored whole
           where the segment has room for 16, else as many as were accepted
           (a masked store: an exact segment, as fill gives each target) */
        const int got = __builtin_popcount(mask);
        if (p->seg == NULL) {
            m += got;
            continue;
        }
        if (m + got <= p->cap) {
            const __m512i j = _mm512_maskz_compress_epi32((__mmask16)mask,
                                                          _mm512_loadu_si512((const void *)(g->order + b)));
            if (m + SPH__NS_BLOCK <= p->cap)
                _mm512_storeu_si512((void *)(p->seg + m), j);
            else
                _mm512_mask_storeu_epi32((void *)(p->seg + m), (__mmask16)((1u << got) - 1u), j);
            m += got;
            continue;
        }
#else
        if (p->seg == NULL) {
            for (k = 0; k < SPH__NS_BLOCK; ++k) m += (mask >> k) & 1u;
            continue;
        }
        if (m + SPH__NS_BLOCK <= p->cap) {
            for (k = 0; k < SPH__NS_BLOCK; ++k) {
                p->seg[m] = g->order[b + k];
                m += (mask >> k) & 1u;
            }
            continue;
        }
#endif
        for (k = 0; k < SPH__NS_BLOCK; ++k) /* past the segment's end: count, store what fits */
            if ((mask >> k) & 1u) {
                if (m < p->cap) p->seg[m] = g->order[b + k];
                ++m;
            }
    }
    return m;
}

/* Checks the collected runs of sorted sources: counts them or appends them.
 * The count stays in a register across the runs; dim and HV are constants,
 * and runs without an image offset (most) skip its subtraction. */
SPH__INLINE void sph__nsearch_runs(const sph_nsearch *g, sph__probe *p, const int dim, const int HV)
{
    sph_off m = p->found, checked = 0;
    sph_real s[3] = {0, 0, 0};
    int r;
    for (r = 0; r < p->n_runs; ++r) {
        const sph_idx k0 = p->runs[2 * r], k1 = p->runs[2 * r + 1];
        if (p->image[r] == 0)
            m = sph__nsearch_run_blocks(g, p, k0, k1, s, m, dim, HV, 0);
        else {
            sph__ns_offsets(g, p->image[r], s);
            m = sph__nsearch_run_blocks(g, p, k0, k1, s, m, dim, HV, 1);
        }
        checked += k1 - k0;
    }
    p->found = m;
    p->checked += checked;
    p->n_runs = 0;
}

/* Checks the collected runs. */
SPH_API void sph__nsearch_flush(const sph_nsearch *g, sph__probe *p)
{
    const int hv = p->R2 < 0;
    if (g->dim == 3)
        hv ? sph__nsearch_runs(g, p, 3, 1) : sph__nsearch_runs(g, p, 3, 0);
    else if (g->dim == 2)
        hv ? sph__nsearch_runs(g, p, 2, 1) : sph__nsearch_runs(g, p, 2, 0);
    else
        hv ? sph__nsearch_runs(g, p, 1, 1) : sph__nsearch_runs(g, p, 1, 0);
}

/* nr runs collected in p->runs: checks them when fewer than room slots are
 * left for the next row; returns the runs still waiting. */
SPH_API int sph__nsearch_room(const sph_nsearch *g, sph__probe *p, int nr, int room)
{
    if (nr + room <= SPH__NS_RUNS) return nr;
    p->n_runs = nr;
    sph__nsearch_flush(g, p);
    return 0;
}

/* Run r of the probe: sorted sources k0..k1-1, seen at the image of code
 * img (sph__ns_image). */
SPH__INLINE void sph__nsearch_put(sph__probe *p, int r, sph_idx k0, sph_idx k1, int img)
{
    p->runs[2 * r] = k0;
    p->runs[2 * r + 1] = k1;
    p->image[r] = img;
}

/* Image code along axis a of the cells of run r of span s: w = shift / n,
 * the periods the cells' geometric position lies from their own (0 on a
 * full axis: every source is then taken at its own position and its block
 * left to the minimum image of sph__nsearch_in). */
SPH_API int sph__nsearch_image(int a, const sph__span *s, int r) { return sph__ns_image(s->shift[r], a); }

/* One row of cells along axis 0 (cells ky, kz of axes 1, 2, image code
 * img of theirs), radius^2 rem left: its runs of sorted sources (one, or two
 * where a periodic axis wraps) into the probe from run nr on; returns how
 * many. */
SPH__INLINE int sph__nsearch_row(const sph_nsearch *g, sph__probe *p, int nr, int ky, int kz, int img,
                                 sph_real rem)
{
    sph__span s;
    const sph_idx *cs = g->cell_start + g->n[0] * (ky + g->n[1] * kz);
    const sph_real hw = sph__sqrt(rem), k0 = sph__floor((p->t[0] - hw) * g->inv_w[0]),
                   k1 = sph__floor((p->t[0] + hw) * g->inv_w[0]);
    int r, n = 0;
    if (k0 >= 0 && k1 < (sph_real)g->n[0]) { /* inside the grid: one run, as sph__nsearch_span finds */
        sph__nsearch_put(p, nr, cs[(int)k0], cs[(int)k1 + 1], img);
        return 1;
    }
    sph__nsearch_span(g, 0, p->t[0], hw, &s);
    for (r = 0; r < s.count; ++r)
        if (s.lo[r] <= s.hi[r])
            sph__nsearch_put(p, nr + n++, cs[s.lo[r]], cs[s.hi[r] + 1], img | sph__nsearch_image(0, &s, r));
    return n;
}

/* Sorts n distinct indices ascending: nothing to do for a sorted run (the
 * usual case on cell-sorted particles), else Shell sort with gaps
 * g' = floor(2.25 g) + 1 (Tokuda 1992). */
SPH_API void sph__ns_sort(sph_idx *v, sph_off n)
{
    sph_off gaps[64], i, j, gap = 1;
    int ng = 0, unsorted = 0;
    for (i = 1; i < n; ++i) unsorted |= v[i - 1] >= v[i]; /* no early exit: a vector loop */
    if (!unsorted) return;
    while (gap < n && ng < 64) {
        gaps[ng++] = gap;
        gap = (sph_off)(2.25 * (double)gap) + 1;
    }
    while (ng-- > 0) {
        gap = gaps[ng];
        for (i = gap; i < n; ++i) {
            sph_idx x = v[i];
            for (j = i; j >= gap && v[j - gap] > x; j -= gap) v[j] = v[j - gap];
            v[j] = x;
        }
    }
}

/* Squared distance along axis a from t to the k-th cell of run r of span s. */
SPH_API sph_real sph__nsearch_gap2(const sph_nsearch *g, int a, sph_real t, const sph__span *s, int r, int k)
{
    sph_real d = s->full ? 0 : sph__nsearch_gap(g, a, t, k + s->shift[r]);
    return d * d;
}

/* Cells a target reaches on each side along one axis, at most, for the
 * interior path of sph__nsearch_target (cells of R/2: 3). */
#define SPH__NS_REACH 4

/* The i-th of the 2 E + 1 offsets of an axis in ascending cell order: from
 * first (the offset of cell 0 where the axis wraps, else 0) round to first - 1. */
SPH_API int sph__ns_turn(int i, int first, int E) { return i + first - (i + first > 2 * E ? 2 * E + 1 : 0); }

/* The rows of a target whose reach spans E[a] cells either side of its
 * cell kc[a] (at most SPH__NS_REACH; a periodic axis needs at least
 * 2 E[a] + 1 cells, so that each comes once): for the geometric cells
 * kc + d, the squared gaps, their cells in the grid and their image offsets
 * (eq. (N7)) are computed once per axis; a cell beyond the grid on an axis
 * without a period gets an infinite gap. A row's x run is the cells whose
 * gap^2 fits in what is left of Rm^2, counted without a square root, a
 * floor or a branch (the gaps grow away from kc, so the count is a run).
 * The cells are those of the general path but for rounding in the last
 * place, which the allowance in Rm covers; every candidate is then checked
 * exactly. Rows come in ascending cell order (a wrapped axis starts at its
 * cell 0), so the lists of cell-sorted particles need no sort. EDGE (a
 * constant): some cell kc + d lies beyond the grid; without, the cells are
 * kc + d themselves (the usual case, kept free of the work of edges). */
SPH__INLINE void sph__nsearch_interior(const sph_nsearch *g, sph__probe *p, sph_real Rm, const int *kc, const int *E,
                                       const int EDGE)
{
    sph_real G[3][2 * SPH__NS_REACH + 1];
    int K[3][2 * SPH__NS_REACH + 1], C[3][2 * SPH__NS_REACH + 1], first[3] = {0, 0, 0}, a, i, d, iy, iz, nr = 0;
    for (a = 0; a < 3; ++a)
        for (i = 0; i <= 2 * E[a]; ++i) {
            const int k = kc[a] - E[a] + i, per = EDGE && g->box.periodic[a];
            const int w = per ? (k < 0 ? -1 : k >= g->n[a]) : 0, in = !EDGE || per || (k >= 0 && k < g->n[a]);
            const sph_real gap = sph__nsearch_gap(g, a, p->t[a], k);
            G[a][i] = in ? gap * gap : SPH__REAL_MAX;
            K[a][i] = in ? k - w * g->n[a] : 0;
            C[a][i] = sph__ns_image(w, a);
            if (EDGE) first[a] = in && K[a][i] == 0 ? i : first[a];
        }
    for (iz = 0; iz <= 2 * E[2]; ++iz) {
        const int dz = sph__ns_turn(iz, first[2], E[2]);
        const sph_real left_z = Rm * Rm - G[2][dz];
        if (left_z < 0) continue;
        for (iy = 0; iy <= 2 * E[1]; ++iy) {
            const int dy = sph__ns_turn(iy, first[1], E[1]);
            const sph_real left_y = left_z - G[1][dy];
            const sph_idx *cs = g->cell_start + g->n[0] * (K[1][dy] + g->n[1] * K[2][dz]);
            const int n0 = g->n[0];
            int k0 = kc[0], k1 = kc[0];
            if (left_y < 0) continue;
            for (d = 1; d <= E[0]; ++d) {
                k0 -= G[0][E[0] - d] <= left_y;
                k1 += G[0][E[0] + d] <= left_y;
            }
            if (!EDGE || (k0 >= 0 && k1 < n0))
                sph__nsearch_put(p, nr++, cs[k0], cs[k1 + 1], C[1][dy] | C[2][dz]);
            else { /* x wraps: the run from cell 0 first, then the one up to cell n0 - 1 */
                sph__nsearch_put(p, nr++, cs[0], cs[(k1 < n0 ? k1 : k1 - n0) + 1],
                                 sph__ns_image(k1 >= n0, 0) | C[1][dy] | C[2][dz]);
                sph__nsearch_put(p, nr++, cs[k0 < 0 ? k0 + n0 : k0], cs[n0],
                                 sph__ns_image(-(k0 < 0), 0) | C[1][dy] | C[2][dz]);
            }
            nr = sph__nsearch_room(g, p, nr, 2);
        }
    }
    p->n_runs = nr;
}

/* The rows of any target, search radius Rm: the cells along z, then y,
 * within reach, clamped to the grid or wrapped round a periodic axis. */
SPH_API void sph__nsearch_general(const sph_nsearch *g, sph__probe *p, sph_real Rm)
{
    sph__span sz, sy;
    int rz, ry, kz, ky, nr = 0;
    sph__nsearch_span(g, 2, p->t[2], Rm, &sz);
    for (rz = 0; rz < sz.count; ++rz)
        for (kz = sz.lo[rz]; kz <= sz.hi[rz]; ++kz) {
            sph_real left_z = Rm * Rm - sph__nsearch_gap2(g, 2, p->t[2], &sz, rz, kz);
            if (left_z < 0) continue;
            sph__nsearch_span(g, 1, p->t[1], sph__sqrt(left_z), &sy);
            for (ry = 0; ry < sy.count; ++ry)
                for (ky = sy.lo[ry]; ky <= sy.hi[ry]; ++ky) {
                    sph_real left_y = left_z - sph__nsearch_gap2(g, 1, p->t[1], &sy, ry, ky);
                    if (left_y < 0) continue;
                    nr += sph__nsearch_row(g, p, nr, ky, kz,
                                           sph__nsearch_image(1, &sy, ry) | sph__nsearch_image(2, &sz, rz), left_y);
                    nr = sph__nsearch_room(g, p, nr, 2);
                }
        }
    p->n_runs = nr;
}

/* Searches one target (found, checked, and seg when filling): the cells
 * whose nearest point lies within the search radius, layer by layer (z, y),
 * each x row as one or two runs of sorted sources; the interior path where
 * the target's reach is at most SPH__NS_REACH cells on every axis and each
 * periodic axis has room for it, else the general path. */
SPH_API void sph__nsearch_target(const sph_nsearch *g, sph__probe *p)
{
    sph_real hmax = g->h != NULL ? g->h_max : p->hu;
    sph_real Rs = p->kappa * (p->symmetric && hmax > p->hi ? hmax : p->hi);
    sph_real Rm, far = 0;
    int a, kc[3] = {0, 0, 0}, E[3] = {0, 0, 0}, inside = 1, edge = 0;
    for (a = 0; a < 3; ++a) {
        const sph_real ax = p->xt[a] < 0 ? -p->xt[a] : p->xt[a]; /* |x| in sph_real: no promotion to double */
        p->t[a] = a < g->dim ? sph__nsearch_rel(g, a, p->xt[a]) : (sph_real)0.5;
        far = ax > far ? ax : far;
    }
    /* search radius with the rounding allowance of docs/neighbours.md: never misses a pair */
    Rm = Rs + Rs / 1024 + g->slack + 64 * sph__nsearch_eps() * far;
    if (p->symmetric && g->h != NULL)
        p->R2 = -1;
    else { /* R of sph__nsearch_in with h_j = the uniform h */
        const sph_real R = p->kappa * (p->symmetric && p->hu > p->hi ? p->hu : p->hi);
        p->R2 = R * R;
    }
    p->found = 0;
    p->checked = 0;
    p->redone = 0;
    p->n_runs = 0;
    for (a = 0; a < g->dim; ++a) { /* axes beyond dim: one cell, reach 0 */
        const sph_real reach = sph__floor(Rm * g->inv_w[a]) + 1;
        kc[a] = sph__nsearch_cell(g, a, p->t[a]);
        E[a] = reach <= SPH__NS_REACH ? (int)reach : -1;
        inside &= E[a] >= 0 && (!g->box.periodic[a] || 2 * E[a] + 1 <= g->n[a]);
        edge |= kc[a] - E[a] < 0 || kc[a] + E[a] >= g->n[a];
    }
    inside &= Rm * Rm <= SPH__REAL_MAX; /* the infinite gap of the interior path stays out of reach */
    if (inside && edge)
        sph__nsearch_interior(g, p, Rm, kc, E, 1);
    else if (inside)
        sph__nsearch_interior(g, p, Rm, kc, E, 0);
    else
        sph__nsearch_general(g, p, Rm);
    sph__nsearch_flush(g, p);
    if (p->seg != NULL && p->found <= p->cap) sph__ns_sort(p->seg, p->found);
}

/* Grid geometry from the sources (eq. (N4)); no workspace needed yet. */
SPH_API int sph__nsearch_geometry(sph_nsearch *g, int dim, sph_view xs, sph_idx ns,
                                  sph_view hs, sph_real cell, const sph_box *box)
{
    double total = 1, extent = 0;
    sph_real amax[3] = {0, 0, 0};
    int a, st;
    sph_idx i;
    g->dim = 0;
    if (dim < 1 || dim > 3) return SPH_EDIM;
    if (ns < 0 || ns > SPH_NSEARCH_MAX_SOURCES) return SPH_ESIZE;
    if (!(cell > 0 && cell <= SPH__REAL_MAX)) return SPH_EINVAL;
    if (!(1 / cell <= SPH__REAL_MAX)) return SPH_EGRID; /* a denormal cell: cell widths of 1/0 */
    if ((st = sph__ns_scan_x(dim, xs, ns, amax)) != SPH_OK) return st;
    if ((st = sph__ns_check_h(hs, ns, dim, &g->h_max)) != SPH_OK) return st;
    g->n_sources = ns;
    g->n_padded = ns + SPH__NS_BLOCK;
    for (a = 0; a < 3; ++a) {
        sph_real lo = 0, L = 0;
        double na = 1;
        int per = a < dim && box != NULL && box->periodic[a];
        if (per) {
            lo = box->lo[a];
            L = box->length[a];
            if (!sph__finite(lo) || !(L > 0 && L <= SPH__REAL_MAX && 1 / L <= SPH__REAL_MAX)) return SPH_EINVAL;
        } else if (a < dim && ns > 0) {
            sph_real hi = sph__ns_at(xs, a, 0);
            lo = hi;
            for (i = 1; i < ns; ++i) {
                sph_real x = sph__ns_at(xs, a, i);
                lo = x < lo ? x : lo;
                hi = x > hi ? x : hi;
            }
            L = hi - lo;
        }
        if (a < dim) na = floor((double)L / (double)cell);
        if (!(na <= (double)SPH_NSEARCH_MAX_CELLS)) return SPH_EGRID;
        na = na < 1 ? 1 : na;
        total *= na;
        g->n[a] = (int)na;
        g->lo[a] = lo;
        g->w[a] = a >= dim ? 1 : per ? L / (sph_real)na : (na > 1 ? L / (sph_real)na : (L > cell ? L : cell));
        g->inv_w[a] = 1 / g->w[a];
        g->box.lo[a] = lo;
        g->box.length[a] = per ? L : 0;
        g->box.periodic[a] = per;
        g->quarter[a] = per ? L / 4 : SPH__REAL_MAX;
        if (a < dim && fabs((double)lo) + (double)L + (double)g->w[a] > extent)
            extent = fabs((double)lo) + (double)L + (double)g->w[a];
        if (a < dim && (double)amax[a] > extent) extent = (double)amax[a]; /* sources outside a periodic box */
    }
    if (total > (double)SPH_NSEARCH_MAX_CELLS) return SPH_EGRID;
    g->quarter2 = SPH__REAL_MAX;
    for (a = 0; a < dim; ++a)
        if (g->box.periodic[a] && g->quarter[a] * g->quarter[a] < g->quarter2) g->quarter2 = g->quarter[a] * g->quarter[a];
    g->n_cells = (int)total;
    g->slack = (sph_real)(64 * (double)sph__nsearch_eps() * extent);
    g->dim = dim;
    return SPH_OK;
}

/* Bytes of one workspace array padded to a 64-byte line. */
SPH_API double sph__nsearch_line(double bytes) { return ceil(bytes / 64) * 64; }

/* Workspace layout: returns the bytes needed (63 of them for alignment) and,
 * when base != NULL, points the grid's arrays into it, 64-byte aligned. */
SPH_API double sph__nsearch_layout(sph_nsearch *g, int with_h, char *base)
{
    const double cells = sph__nsearch_line((double)sizeof(sph_idx) * ((double)g->n_cells + 1));
    const double padded = (double)g->n_padded;
    const double order = sph__nsearch_line((double)sizeof(sph_idx) * padded);
    const double reals = sph__nsearch_line((double)sizeof(sph_real) * padded);
    const double xyz = sph__nsearch_line((double)sizeof(sph_real) * padded * g->dim);
    if (base != NULL) {
        base += (64 - (size_t)((uintptr_t)base % 64)) % 64;
        g->cell_start = (sph_idx *)(void *)base;
        g->order = (sph_idx *)(void *)(base + (size_t)cells);
        g->x = (sph_real *)(void *)(base + (size_t)(cells + order));
        g->h = with_h ? (sph_real *)(void *)(base + (size_t)(cells + order + xyz)) : NULL;
    }
    return 63 + cells + order + xyz + (with_h != 0) * reals;
}

/* Workspace bytes sph_nsearch_build needs for these sources (eq. (N4)
 * sizes the grid; scans the positions for their bounds). */
SPH_API int sph_nsearch_workspace_size(int dim, sph_view xs, sph_idx n_sources, sph_view hs,
                                       sph_real cell, const sph_box *box, size_t *bytes)
{
    sph_nsearch g;
    double need;
    int st;
    if (bytes == NULL) return SPH_ENULL;
    *bytes = 0;
    if ((st = sph__nsearch_geometry(&g, dim, xs, n_sources, hs, cell, box)) != SPH_OK) return st;
    need = sph__nsearch_layout(&g, hs.p[0] != NULL, NULL);
    if (!(need <= (double)SIZE_MAX)) return SPH_EGRID;
    *bytes = (size_t)need;
    return SPH_OK;
}

/* Bins the sources into cells (eq. (N4)) by a stable counting sort inside
 * work: cell starts, sorted order, sorted positions (and h). O(N + cells). */
SPH_API int sph_nsearch_build(sph_nsearch *g, int dim, sph_view xs, sph_idx n_sources,
                              sph_view hs, sph_real cell, const sph_box *box, void *work,
                              size_t work_bytes)
{
    sph_real x[3] = {0, 0, 0};
    sph_idx i;
    int a, c, st;
    if (g == NULL) return SPH_ENULL;
    if ((st = sph__nsearch_geometry(g, dim, xs, n_sources, hs, cell, box)) != SPH_OK) return st;
    if (work == NULL) {
        g->dim = 0;
        return SPH_ENULL;
    }
    if (!(sph__nsearch_layout(g, hs.p[0] != NULL, NULL) <= (double)work_bytes)) {
        g->dim = 0;
        return SPH_ESIZE;
    }
    sph__nsearch_layout(g, hs.p[0] != NULL, (char *)work);
    for (c = 0; c <= g->n_cells; ++c) g->cell_start[c] = 0;
    for (i = 0; i < n_sources; ++i) { /* count per cell, shifted by one */
        for (a = 0; a < dim; ++a) x[a] = sph__ns_at(xs, a, i);
        ++g->cell_start[sph__nsearch_source_cell(g, x) + 1];
    }
    g->n_occupied = 0;
    for (c = 0; c < g->n_cells; ++c) {
        g->n_occupied += g->cell_start[c + 1] > 0;
        g->cell_start[c + 1] += g->cell_start[c];
    }
    for (i = 0; i < n_sources; ++i) { /* scatter; cell_start[c] runs ahead to the next cell */
        sph_idx k;
        for (a = 0; a < dim; ++a) x[a] = sph__ns_at(xs, a, i);
        c = sph__nsearch_source_cell(g, x);
        k = g->cell_start[c]++;
        g->order[k] = i;
        for (a = 0; a < dim; ++a) g->x[(ptrdiff_t)a * g->n_padded + k] = x[a];
        if (hs.p[0] != NULL) g->h[k] = hs.p[0][(ptrdiff_t)i * hs.stride];
    }
    for (i = n_sources; i < g->n_padded; ++i) { /* padding: read by the blocked checks, never kept */
        g->order[i] = 0;
        for (a = 0; a < dim; ++a) g->x[(ptrdiff_t)a * g->n_padded + i] = 0;
        if (hs.p[0] != NULL) g->h[i] = 1;
    }
    for (c = g->n_cells; c > 0; --c) g->cell_start[c] = g->cell_start[c - 1];
    g->cell_start[0] = 0;
    return SPH_OK;
}

/* Checks the arguments shared by count, fill, lists and stats. The largest
 * search radius R = kappa h_i (gather) or kappa max(h_i, h_j) (symmetric)
 * must fit the minimum image: R <= L/2 on every periodic axis, so that no
 * source has two images within reach (else SPH_EPERIOD). */
SPH_API int sph__nsearch_check(const sph_nsearch *g, sph_view xt, sph_idx nt, sph_view ht,
                               sph_real h, sph_real kappa, int mode)
{
    int uses_h = ht.p[0] == NULL || (mode == SPH_NSEARCH_SYMMETRIC && g != NULL && g->h == NULL);
    int st, a;
    sph_real hmax;
    if (g == NULL) return SPH_ENULL;
    if (g->dim < 1 || g->dim > 3) return SPH_EINVAL;
    if (nt < 0) return SPH_ESIZE;
    if (mode != SPH_NSEARCH_GATHER && mode != SPH_NSEARCH_SYMMETRIC) return SPH_EINVAL;
    if (!(kappa > 0 && kappa <= SPH__REAL_MAX)) return SPH_EINVAL;
    if (uses_h && !sph__h_ok(h, g->dim)) return SPH_EH;
    if ((st = sph__ns_check_x(g->dim, xt, nt)) != SPH_OK) return st;
    if ((st = sph__ns_check_h(ht, nt, g->dim, &hmax)) != SPH_OK) return st;
    if (ht.p[0] == NULL) hmax = h;
    if (mode == SPH_NSEARCH_SYMMETRIC) {
        const sph_real hs = g->h != NULL ? g->h_max : h;
        hmax = hs > hmax ? hs : hmax;
    }
    for (a = 0; a < g->dim; ++a)
        if (g->box.periodic[a] && !(kappa * hmax <= g->box.length[a] / 2)) return SPH_EPERIOD;
    return SPH_OK;
}

/* The search parameters of target i (position, h_i, criterion). */
SPH_API void sph__nsearch_probe(const sph_nsearch *g, sph_view xt, sph_view ht, sph_real h, sph_real kappa, int mode,
                                sph_idx i, sph__probe *p)
{
    int a;
    for (a = 0; a < 3; ++a) p->xt[a] = a < g->dim ? sph__ns_at(xt, a, i) : 0;
    p->hi = ht.p[0] != NULL ? ht.p[0][(ptrdiff_t)i * ht.stride] : h;
    p->hu = h;
    p->kappa = kappa;
    p->symmetric = mode == SPH_NSEARCH_SYMMETRIC;
}

/* Runs the search for every target: counts into count[i + 1] (when count
 * != NULL), fills index (when index != NULL, segments given by offset),
 * sums into stats (when not NULL) the pairs, the candidates checked and the
 * blocks redone for the minimum image. Returns SPH_EINVAL when a target's
 * count differs from its segment. Parallel over targets under OpenMP, same
 * result. */
SPH_API int sph__nsearch_run(const sph_nsearch *g, sph_view xt, sph_idx nt, sph_view ht,
                             sph_real h, sph_real kappa, int mode, sph_off *count,
                             const sph_off *offset, sph_idx *index, sph_off *stats)
{
    sph_off sum_pairs = 0, sum_checked = 0, sum_redone = 0;
    int bad = 0;
    sph_idx i;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 64) if (nt >= 512) reduction(+ : sum_pairs, sum_checked, sum_redone) \
    reduction(| : bad)
#endif
    for (i = 0; i < nt; ++i) {
        sph__probe p;
        sph__nsearch_probe(g, xt, ht, h, kappa, mode, i, &p);
        p.seg = index != NULL ? index + offset[i] : NULL;
        p.cap = index != NULL ? offset[i + 1] - offset[i] : 0;
        sph__nsearch_target(g, &p);
        if (count != NULL) count[i + 1] = p.found;
        if (index != NULL) bad |= p.found != p.cap;
        sum_pairs += p.found;
        sum_checked += p.checked;
        sum_redone += p.redone;
    }
    if (stats != NULL) {
        stats[0] = sum_pairs;
        stats[1] = sum_checked;
        stats[2] = sum_redone;
    }
    return bad ? SPH_EINVAL : SPH_OK;
}

/* Counting pass: offset[0..nt] of the CSR lists of criterion (N1)/(N2);
 * offset[nt] is the number of pairs, the length index[] needs. */
SPH_API int sph_nsearch_count(const sph_nsearch *g, sph_view xt, sph_idx n_targets, sph_view ht,
                              sph_real h, sph_real kappa, int mode, sph_off *offset)
{
    sph_idx i;
    int st = sph__nsearch_check(g, xt, n_targets, ht, h, kappa, mode);
    if (st != SPH_OK) return st;
    if (offset == NULL) return SPH_ENULL;
    offset[0] = 0;
    sph__nsearch_run(g, xt, n_targets, ht, h, kappa, mode, offset, NULL, NULL, NULL);
    for (i = 0; i < n_targets; ++i) offset[i + 1] += offset[i];
    return SPH_OK;
}

/* Fill pass: index[offset[i] .. offset[i+1]-1] = the neighbours of target i
 * (criterion (N1)/(N2)) in ascending source index. offset must come from
 * sph_nsearch_count with the same arguments; index holds capacity entries
 * (SPH_ESIZE, nothing written, when offset[nt] > capacity). */
SPH_API int sph_nsearch_fill(const sph_nsearch *g, sph_view xt, sph_idx n_targets, sph_view ht,
                             sph_real h, sph_real kappa, int mode, const sph_off *offset, sph_idx *index,
                             sph_off capacity)
{
    sph_idx i;
    int st = sph__nsearch_check(g, xt, n_targets, ht, h, kappa, mode);
    if (st != SPH_OK) return st;
    if (offset == NULL) return SPH_ENULL;
    if (offset[0] != 0) return SPH_EINVAL;
    for (i = 0; i < n_targets; ++i)
        if (offset[i + 1] < offset[i]) return SPH_EINVAL;
    if (offset[n_targets] > capacity) return SPH_ESIZE;
    if (index == NULL && offset[n_targets] > 0) return SPH_ENULL;
    if (n_targets == 0 || index == NULL) return SPH_OK;
    return sph__nsearch_run(g, xt, n_targets, ht, h, kappa, mode, NULL, offset, index, NULL);
}

/* Targets lo..hi-1 of sph_nsearch_lists into index[s0 .. s1-1] one after
 * another, each target's count into offset[i + 1]. Returns the first target
 * whose list did not fit (hi when all did); the targets after it are counted
 * only. */
SPH_API sph_idx sph__nsearch_block(const sph_nsearch *g, sph_view xt, sph_view ht, sph_real h, sph_real kappa,
                                   int mode, sph_idx lo, sph_idx hi, sph_off *offset, sph_idx *index, sph_off s0,
                                   sph_off s1)
{
    sph_idx i, bad = hi;
    for (i = lo; i < hi; ++i) {
        sph__probe p;
        sph__nsearch_probe(g, xt, ht, h, kappa, mode, i, &p);
        p.seg = bad == hi && index != NULL ? index + s0 : NULL;
        p.cap = bad == hi ? s1 - s0 : 0;
        sph__nsearch_target(g, &p);
        offset[i + 1] = p.found;
        if (bad == hi && p.found > p.cap) bad = i;
        if (bad == hi) s0 += p.found;
    }
    return bad;
}

/* Count and fill in one search per target (eq. (N1)/(N2)): offset[0..nt]
 * and index[] exactly as sph_nsearch_count then sph_nsearch_fill give them;
 * index holds capacity entries, *pairs = offset[nt] (the entries needed).
 * SPH_ESIZE when more than capacity are needed: offset is then complete
 * (sph_nsearch_fill with it and a larger index finishes the job), index
 * unspecified. Under OpenMP the targets are split into one contiguous block
 * per thread (at least 1024 targets each), each searched into the share of
 * index proportional to it, then moved down into place; from the first
 * block that outgrows its share on, a second pass fills the lists (a
 * capacity ~20 % above the expected pairs avoids it). The result does not
 * depend on the thread count. */
SPH_API int sph_nsearch_lists(const sph_nsearch *g, sph_view xt, sph_idx n_targets, sph_view ht, sph_real h,
                              sph_real kappa, int mode, sph_off *offset, sph_idx *index, sph_off capacity,
                              sph_off *pairs)
{
    enum { MAX_BLOCKS = 64 };
    sph_idx lo[MAX_BLOCKS + 1], bad[MAX_BLOCKS];
    sph_off s0[MAX_BLOCKS + 1], k, end;
    int nb, b, st = sph__nsearch_check(g, xt, n_targets, ht, h, kappa, mode);
    sph_idx i;
    if (st != SPH_OK) return st;
    if (offset == NULL || pairs == NULL || (index == NULL && capacity > 0)) return SPH_ENULL;
    if (capacity < 0) return SPH_ESIZE;
    nb = 1;
#ifdef _OPENMP
    nb = omp_get_max_threads();
    nb = nb < MAX_BLOCKS ? nb : MAX_BLOCKS;
    nb = n_targets / 1024 < nb ? (int)(n_targets / 1024) : nb;
    nb = nb > 1 ? nb : 1;
#endif
    for (b = 0; b <= nb; ++b) { /* block b: targets lo[b].., index from s0[b] */
        lo[b] = (sph_idx)((double)n_targets * b / nb);
        s0[b] = (sph_off)((double)capacity * b / nb);
    }
    lo[nb] = n_targets;
    s0[nb] = capacity;
#ifdef _OPENMP
#pragma omp parallel for schedule(static, 1) if (nb > 1)
#endif
    for (b = 0; b < nb; ++b)
        bad[b] = sph__nsearch_block(g, xt, ht, h, kappa, mode, lo[b], lo[b + 1], offset, index, s0[b], s0[b + 1]);
    offset[0] = 0;
    for (i = 0; i < n_targets; ++i) offset[i + 1] += offset[i];
    *pairs = offset[n_targets];
    if (offset[n_targets] > capacity) return SPH_ESIZE;
    for (b = 0; b < nb; ++b) { /* blocks that fitted move down to their offsets (never up: the blocks
                                  before them fitted too), in order */
        if (bad[b] != lo[b + 1]) break;
        end = offset[lo[b + 1]] - offset[lo[b]];
        for (k = 0; s0[b] != offset[lo[b]] && k < end; ++k) index[offset[lo[b]] + k] = index[s0[b] + k];
    }
    if (b < nb) /* from the first block that outgrew its share: a fill pass over the rest */
        return sph__nsearch_run(g, sph__ns_tail(xt, g->dim, lo[b]), n_targets - lo[b], sph__ns_tail(ht, 1, lo[b]),
                                h, kappa, mode, NULL, offset + lo[b], index, NULL);
    return SPH_OK;
}

/* Statistics of one search without storing it (docs/neighbours.md,
 * "Measured"): pairs found by (N1)/(N2), candidate distance checks made and,
 * when fill != NULL, the grid's fill ratio: occupied cells / cells (1 for
 * one source per cell; a small value means a mostly empty grid, e.g. around
 * an escaped particle: docs/neighbours.md, "Limits"). */
SPH_API int sph_nsearch_stats(const sph_nsearch *g, sph_view xt, sph_idx n_targets, sph_view ht,
                              sph_real h, sph_real kappa, int mode, sph_off *pairs, sph_off *candidates,
                              sph_real *fill)
{
    sph_off stats[3];
    int st = sph__nsearch_check(g, xt, n_targets, ht, h, kappa, mode);
    if (st != SPH_OK) return st;
    if (pairs == NULL || candidates == NULL) return SPH_ENULL;
    sph__nsearch_run(g, xt, n_targets, ht, h, kappa, mode, NULL, NULL, NULL, stats);
    *pairs = stats[0];
    *candidates = stats[1];
    if (fill != NULL) *fill = (sph_real)((double)g->n_occupied / (double)g->n_cells);
    return SPH_OK;
}

/* The sph_neighbours view (CSR, section 4) of arrays filled by sph_nsearch_count / _fill. */
SPH_API sph_neighbours sph_nsearch_list(const sph_nsearch *g, sph_idx n_targets, const sph_off *offset,
                                        const sph_idx *index)
{
    sph_neighbours l;
    l.n_targets = n_targets;
    l.n_sources = g != NULL ? g->n_sources : 0;
    l.offset = offset;
    l.index = index;
    return l;
}

/* Locality permutation of the sources, eq. (N5): perm[new] = old, sources
 * ordered by cell (and by index within a cell). */
SPH_API int sph_nsearch_permutation(const sph_nsearch *g, sph_idx *perm)
{
    sph_idx k;
    if (g == NULL || (perm == NULL && g->n_sources > 0)) return SPH_ENULL;
    if (g->dim < 1 || g->dim > 3) return SPH_EINVAL;
    for (k = 0; k < g->n_sources; ++k) perm[k] = g->order[k];
    return SPH_OK;
}

/* Checks that perm[0..n-1] is a permutation of 0..n-1; mark[n] is scratch. */
SPH_API int sph__ns_check_perm(const sph_idx *perm, sph_idx n, sph_idx *mark)
{
    sph_idx k;
    for (k = 0; k < n; ++k) mark[k] = -1;
    for (k = 0; k < n; ++k) {
        if (perm[k] < 0 || perm[k] >= n || mark[perm[k]] >= 0) return SPH_EINDEX;
        mark[perm[k]] = k;
    }
    return SPH_OK;
}

/* Inverse permutation, eq. (N6): inv[perm[k]] = k. SPH_EINDEX (inv
 * unspecified) when perm is not a permutation of 0..n-1. */
SPH_API int sph_permutation_invert(const sph_idx *perm, sph_idx n, sph_idx *inv)
{
    if (n < 0) return SPH_ESIZE;
    if (n > 0 && (perm == NULL || inv == NULL)) return SPH_ENULL;
    return sph__ns_check_perm(perm, n, inv);
}

/* Applies a permutation to a field, eq. (N5): component a of out[k] =
 * component a of in[perm[k]], for ncomp (1..3) components of n particles.
 * out must not overlap in. SPH_EINDEX (nothing written) for an index outside
 * 0..n-1. */
SPH_API int sph_permute(sph_view in, int ncomp, sph_idx n, const sph_idx *perm, sph_out out)
{
    sph_idx k;
    int a;
    if (ncomp < 1 || ncomp > 3) return SPH_EINVAL;
    if (n < 0) return SPH_ESIZE;
    if (n == 0) return SPH_OK;
    if (perm == NULL) return SPH_ENULL;
    for (a = 0; a < ncomp; ++a)
        if (in.p[a] == NULL || out.p[a] == NULL) return SPH_ENULL;
    for (k = 0; k < n; ++k)
        if (perm[k] < 0 || perm[k] >= n) return SPH_EINDEX;
    for (a = 0; a < ncomp; ++a)
        for (k = 0; k < n; ++k) out.p[a][(ptrdiff_t)k * out.stride] = sph__ns_at(in, a, perm[k]);
    return SPH_OK;
}


#ifdef __cplusplus
}
#endif

#endif /* SPH_KERNEL_H */

/*
 * MIT License. Copyright (c) 2026 The sph_kernel.h authors. Permission is hereby
 * granted, free of charge, to any person obtaining a copy of this software, to
 * deal in it without restriction, subject to including this notice; THE
 * SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND. Full text: LICENSE.
 */
