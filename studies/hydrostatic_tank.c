/* studies/hydrostatic_tank.c - the hydrostatic tank of support/tank.h run
 * for long times: does a weakly compressible tank built from the solver
 * terms of sph_kernel.h (walls (S8), viscosity (S1), time step (S9)-(S10),
 * kick-drift-kick; docs/solver.md) keep p = rho0 g depth and stay at rest?
 *
 * Usage:  hydrostatic_tank [--nx N] [--ny N] [--time T] [--every T]
 *         hydrostatic_tank --check        (the test's tank, 10 x 12 for 2
 *                                          sqrt(H/g), asserting its bounds)
 *   --nx, --ny  fluid particles across and deep (4..200; default 20 x 30)
 *   --time      duration in units of sqrt(H/g) (0 < T <= 1000; default 10)
 *   --every     interval of the printed rows, same unit (default T / 10)
 *   --delta     density diffusion (S7), Antuono form (0..1; default 0: none)
 * Prints one row per interval: time, steps, largest pressure error of the
 * fluid and of the floor walls (relative to rho0 g H), largest speed over
 * the interval and at its end (relative to sqrt(g H)). Exit status 0, or 1
 * for a failed check, 2 for bad arguments or a failure of the run.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/tank.h"

/* The value of option name at argv[*k + 1] in [lo, hi] (an integer when whole is set), or exit(2) naming the
 * option and its range. */
static double option(int argc, char **argv, int *k, const char *name, double lo, double hi, int whole)
{
    char *end = NULL;
    double x;
    if (*k + 1 >= argc) {
        fprintf(stderr, "hydrostatic_tank: %s needs a value in [%g, %g]\n", name, lo, hi);
        exit(2);
    }
    x = strtod(argv[++*k], &end);
    if (end == argv[*k] || *end != '\0' || !(x >= lo && x <= hi) || (whole && x != floor(x))) {
        fprintf(stderr, "hydrostatic_tank: %s = '%s' is not %s in [%g, %g]\n", name, argv[*k],
                whole ? "an integer" : "a number", lo, hi);
        exit(2);
    }
    return x;
}

int main(int argc, char **argv)
{
    int nx = 20, ny = 30, check = 0, k, st, steps = 0;
    double T = 10, every = -1, delta = 0, time = 0, next, dt = 0, vmax = 0, pf = 0, pw = 0, v = 0, tunit, vunit;
    tank t;
    for (k = 1; k < argc; ++k) {
        if (strcmp(argv[k], "--nx") == 0) nx = (int)option(argc, argv, &k, "--nx", 4, 200, 1);
        else if (strcmp(argv[k], "--ny") == 0) ny = (int)option(argc, argv, &k, "--ny", 4, 200, 1);
        else if (strcmp(argv[k], "--time") == 0) T = option(argc, argv, &k, "--time", 1e-6, 1000, 0);
        else if (strcmp(argv[k], "--every") == 0) every = option(argc, argv, &k, "--every", 1e-6, 1000, 0);
        else if (strcmp(argv[k], "--delta") == 0) delta = option(argc, argv, &k, "--delta", 0, 1, 0);
        else if (strcmp(argv[k], "--check") == 0) check = 1;
        else {
            fprintf(stderr, "hydrostatic_tank: unknown option '%s' (--nx, --ny, --time, --every, --delta, --check)\n",
                    argv[k]);
            return 2;
        }
    }
    if (check) nx = 10, ny = 12, T = 2, every = 2, delta = 0;
    if (every <= 0) every = T / 10;
    if (tank_make(&t, nx, ny) != 0) {
        fprintf(stderr, "hydrostatic_tank: out of memory for %d x %d particles\n", nx, ny);
        tank_free(&t);
        return 2;
    }
    t.delta = delta;
    tunit = sqrt(t.H / t.g), vunit = sqrt(t.g * t.H);
    printf("# %d x %d fluid particles, dx = %g m, H = %g m, c0 = %.4g m/s, h = 1.3 dx, cubic, alpha = %g, delta = %g\n",
           nx, ny, t.dx, t.H, t.c0, t.alpha, t.delta);
    printf("# t/sqrt(H/g)  steps  p_err_fluid  p_err_floor  vmax_interval  v_end"
           "   (p_err / (rho0 g H), v / sqrt(g H))\n");
    st = tank_momentum(&t, t.v);
    for (next = every; st == SPH_OK && time < T * tunit;) {
        st = tank_step(&t, &dt);
        time += dt, ++steps;
        vmax = fmax(vmax, v = tank_errors(&t, &pf, &pw));
        if (time >= next * tunit || time >= T * tunit) {
            printf("%12.3f %7d %12.5f %12.5f %14.5f %8.5f\n", time / tunit, steps, pf, pw, vmax / vunit, v / vunit);
            if (check && !(pf < 0.05 && pw < 0.05 && vmax < 0.02 * vunit)) st = -100;
            vmax = 0;
            next += every;
        }
    }
    tank_free(&t);
    if (st == -100) {
        fprintf(stderr, "hydrostatic_tank: check failed (bounds: p_err < 0.05, vmax < 0.02)\n");
        return 1;
    }
    if (st != SPH_OK) {
        fprintf(stderr, "hydrostatic_tank: step %d: %s\n", steps, sph_strerror(st));
        return 2;
    }
    return 0;
}
