/* tests/test_kernel_rounding.c - the scalar kernel functions take back the
 * rounding of b - q in the product forms (b - q)^m P(q - e) of section 3.
 *
 * Below q = 1 the Wendland forms hold (2 - q)^m with m up to 8, and 2 - q
 * rounds by up to eps/2 there: raised to the m-th power that alone would be
 * up to m/2 eps (4 eps for C6 in 2-/3-D), on top of the rest. The scalar
 * functions add m t^(m-1) dt, dt the exact rounding error of t = 2 - q, and
 * evaluate in double (with SPH_REAL float, in double throughout).
 * Mutation: without the added term (double) the 6 cases of C4 and C6 fail
 * (worst 6.6, 7.0 and 7.3 eps). (Evaluating in float with SPH_REAL float
 * passes here, at 3.6 eps; test_kernel_shape's monotony then fails 4 cases.)
 *
 * Points: 100001 q on [0, 1) for each Wendland kernel in 1-, 2- and 3-D, at
 * h = 1. Reference: the textbook closed forms of tests/kernel_ref.h in long
 * double. W, F and dW/dr must be within 4 eps of them (relative; none of the
 * three changes sign on (0, 1), and dW/dr = 0 at q = 0 is judged by F).
 */
#include "kernel_ref.h"

#define TOL 4.0

int main(void)
{
    static const sph_kernel ks[3] = {SPH_KERNEL_WENDLAND_C2, SPH_KERNEL_WENDLAND_C4, SPH_KERNEL_WENDLAND_C6};
    static const char *const qname[3] = {"W", "F", "dW/dr"};
    double worst[3] = {0, 0, 0};
    int ik, dim, i, iq;
    for (ik = 0; ik < 3; ++ik)
        for (dim = 1; dim <= 3; ++dim) {
            const sph_kernel k = ks[ik];
            const ref_real a = ref_alpha(k, dim);
            th_begin("W, F, dW/dr on [0, 1) within %g eps: %s %dD", TOL, sph_kernel_name(k), dim);
            for (i = 0; i <= 100000; ++i) {
                const sph_real q = (sph_real)(i / 100001.0);
                ref_real w, w1, w2, ref[3];
                sph_real got[3];
                ref_shape(k, dim, (ref_real)q, &w, &w1, &w2);
                ref[0] = a * w;
                ref[1] = a * ref_g(k, dim, (ref_real)q);
                ref[2] = a * w1;
                got[0] = sph_kernel_w(k, dim, q, 1);
                got[1] = sph_kernel_f(k, dim, q, 1);
                got[2] = sph_kernel_dwdr(k, dim, q, 1);
                for (iq = 0; iq < 3; ++iq) {
                    double e;
                    if (ref[iq] == 0) continue;
                    e = (double)(fabsl((ref_real)got[iq] - ref[iq]) / fabsl(ref[iq])) / TH_EPS;
                    TH_CHECK(e <= TOL, "%s(%.17g) = %.17g, exact %.17Lg (%.2f eps)", qname[iq], (double)q,
                             (double)got[iq], ref[iq], e);
                    if (e > worst[iq]) worst[iq] = e;
                }
            }
            th_end();
        }
    printf("info [%s]: worst relative error on [0, 1): W %.2f eps, F %.2f eps, dW/dr %.2f eps\n", TH_PRECISION,
           worst[0], worst[1], worst[2]);
    return th_summary();
}
