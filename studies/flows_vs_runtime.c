/* studies/flows_vs_runtime.c - error against run time on two flows, whole
 * solvers rather than single operators (docs/results/report.md has those):
 *   - the Gresho-Chan vortex in 2-D (examples/gresho.c): L1 of v_phi at
 *     t = 1, n = 32, 64, 128 particles per side;
 *   - the Sod shock tube in 3-D (examples/sod_shock.c): L1 of rho, v_x and P
 *     at t = 0.2 against the exact Riemann solution, nx = 16, 24, 32 fcc
 *     cells per unit length;
 * every kernel of sph_kernel.h (SPH_KERNEL_COUNT: a new kernel joins by
 * itself) at neighbour numbers of equal resolution: kernel k gets the h at
 * which its standard deviation sigma_k h equals c times the cubic's at
 * h = 1.2 dx (18.1 neighbours in 2-D, 57.9 in 3-D), c = 1, 1.3, 1.6 for the
 * vortex and c = 1, 1.3 for the tube (whose 3-D runs cost more per
 * neighbour). Each point is (CPU seconds of the run, L1); the Pareto front
 * (the points no other point beats in both) is the table "for this budget,
 * this kernel at this neighbour number".
 *
 * The runs are child processes on one thread (--threads 1, OMP_NUM_THREADS=1);
 * the CPU time is the child's user + system time (getrusage), which other jobs
 * on a shared machine disturb far less than the wall time.
 *
 *   flows_vs_runtime [--bin DIR] [--out DIR] [--build TEXT] [--quick]
 *     --bin    the gresho and sod_shock programs (default build/flows)
 *     --out    writes OUT/flows.md and OUT/flows/{points.csv, front_*.csv}
 *              (default docs/results)
 *     --build  how the programs were built, for the report (the Makefile passes it)
 *     --quick  c = 1 at the smallest resolution only: the pipeline in seconds
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#define SPH_ONLY_KERNELS
#include "sph_kernel.h"
#include "support/timing.h"

enum { GRESHO, SOD, NFLOW };
static const char *flow_name[NFLOW] = {"gresho", "sod"};
static const int flow_dim[NFLOW] = {2, 3};
static const int res[NFLOW][3] = {{32, 64, 128}, {16, 24, 32}};
static const double ladder[NFLOW][3] = {{1, 1.3, 1.6}, {1, 1.3, 0}}; /* 0: unused */
/* the quantities whose fronts are tabled: gresho v_phi; sod rho, v_x, P */
static const char *qty_name[NFLOW][3] = {{"v_phi", NULL, NULL}, {"rho", "v_x", "P"}};

typedef struct {
    int flow, res, ok;
    sph_kernel k;
    double c, neighbours, eta, particles, steps, cpu, l1[3];
} point;

/* eta = h / (m / rho)^(1/d) of kernel k at rung c: sigma_k h = c sigma_cubic 1.2 (m / rho)^(1/d). */
static double rung_eta(sph_kernel k, int dim, double c)
{
    return c * 1.2 * sph_kernel_sigma(SPH_KERNEL_CUBIC, dim) / sph_kernel_sigma(k, dim);
}

/* Neighbours in the support at that eta: omega_d (kappa eta)^d (K6). */
static double rung_neighbours(sph_kernel k, int dim, double eta)
{
    return sph_kernel_neighbours(k, dim, eta, 1);
}

static double children_cpu(void)
{
    struct rusage u;
    getrusage(RUSAGE_CHILDREN, &u);
    return (double)u.ru_utime.tv_sec + 1e-6 * u.ru_utime.tv_usec + (double)u.ru_stime.tv_sec + 1e-6 * u.ru_stime.tv_usec;
}

/* Runs one point; ok = 1 when the program exited 0 and printed its result line. */
static void run_point(const char *bin, const char *tmp, point *p)
{
    char cmd[2048], line[4096];
    const char *name = sph_kernel_name(p->k);
    FILE *f;
    double c0;
    int status;
    p->ok = 0;
    if (p->flow == GRESHO)
        snprintf(cmd, sizeof cmd, "%s/gresho --threads 1 --n %d --kernel %s --neighbours %.4f 2> /dev/null", bin, p->res,
                 name, p->neighbours);
    else
        snprintf(cmd, sizeof cmd, "%s/sod_shock --threads 1 --nx %d --kernel %s --eta %.6f --out %s 2> /dev/null", bin,
                 p->res, name, p->eta, tmp);
    c0 = children_cpu();
    if ((f = popen(cmd, "r")) == NULL) return;
    while (fgets(line, sizeof line, f) != NULL) {
        const char *s;
        long n = 0;
        if (p->flow == GRESHO && (s = strstr(line, "steps ")) != NULL &&
            sscanf(s, "steps %lf  L1 v_phi %lf", &p->steps, &p->l1[0]) == 2)
            p->ok = 1, p->particles = (double)p->res * p->res;
        if (p->flow == SOD && strncmp(line, "nx ", 3) == 0 && (s = strstr(line, "N ")) != NULL &&
            sscanf(s, "N %ld  steps %lf  L1 rho %lf  v %lf  P %lf", &n, &p->steps, &p->l1[0], &p->l1[1], &p->l1[2]) == 5)
            p->ok = 1, p->particles = (double)n;
    }
    status = pclose(f);
    p->cpu = children_cpu() - c0;
    if (status != 0) p->ok = 0;
    fprintf(stderr, "%-6s %-12s c %.1f N_H %6.1f res %3d: %s L1 %.4e, %.2f s CPU\n", flow_name[p->flow], name, p->c,
            p->neighbours, p->res, p->ok ? "" : "FAILED", p->l1[0], p->cpu);
}

/* qsort order: CPU time ascending, then error. */
static int qty; /* the quantity compare_cpu breaks ties on */
static int compare_cpu(const void *a, const void *b)
{
    const point *x = *(const point *const *)a, *y = *(const point *const *)b;
    return x->cpu < y->cpu ? -1 : x->cpu > y->cpu ? 1 : (x->l1[qty] > y->l1[qty]) - (x->l1[qty] < y->l1[qty]);
}

/* The Pareto front of quantity q of one flow into front[] (ascending CPU, descending error); returns its length.
 * A point is on it when every point at most as fast has a larger error. */
static int pareto(point *pts, int n, int flow, int q, point **front)
{
    point **by = (point **)malloc(sizeof(point *) * (size_t)(n > 0 ? n : 1));
    double best = HUGE_VAL;
    int i, m = 0, nf = 0;
    if (by == NULL) return 0;
    for (i = 0; i < n; ++i)
        if (pts[i].flow == flow && pts[i].ok) by[m++] = &pts[i];
    qty = q;
    qsort(by, (size_t)m, sizeof *by, compare_cpu);
    for (i = 0; i < m; ++i)
        if (by[i]->l1[q] < best) best = by[i]->l1[q], front[nf++] = by[i];
    free(by);
    return nf;
}

static const char *res_name(int flow) { return flow == GRESHO ? "n" : "nx"; }

/* The front of quantity q as a table, and as front_<flow>[_<q>].csv for the plot. */
static int write_front(FILE *md, const char *dir, point *pts, int n, int flow, int q)
{
    point *front[512];
    char path[1200];
    FILE *csv;
    const int nf = pareto(pts, n, flow, q, front);
    int i;
    snprintf(path, sizeof path, "%s/flows/front_%s%s%s.csv", dir, flow_name[flow], flow == SOD ? "_" : "",
             flow == SOD ? qty_name[flow][q] : "");
    if ((csv = fopen(path, "w")) == NULL) return -1;
    fprintf(csv, "cpu_s,L1,kernel,neighbours,%s\n", res_name(flow));
    fprintf(md, "| CPU budget (s) | least error: kernel | neighbours | %s | L1 %s |\n|---|---|---|---|---|\n",
            res_name(flow), qty_name[flow][q]);
    for (i = 0; i < nf; ++i) {
        const point *p = front[i];
        fprintf(md, "| %.2f | %s | %.0f | %d | %.4f |\n", p->cpu, sph_kernel_name(p->k), p->neighbours, p->res, p->l1[q]);
        fprintf(csv, "%.3f,%.6e,%s,%.1f,%d\n", p->cpu, p->l1[q], sph_kernel_name(p->k), p->neighbours, p->res);
    }
    fprintf(md, "\n");
    return fclose(csv);
}

/* Every point of one flow as a matrix: a row per kernel and rung, a column per resolution, "L1 (CPU s)". */
static void write_matrix(FILE *md, const point *pts, int n, int flow)
{
    const int nq = flow == SOD ? 3 : 1;
    int i, r;
    fprintf(md, "| kernel | c | neighbours |");
    for (r = 0; r < 3; ++r)
        fprintf(md, " %s = %d: L1 %s (CPU s) |", res_name(flow), res[flow][r], nq == 3 ? "rho, v_x, P" : "v_phi");
    fprintf(md, "\n|---|---|---|---|---|---|\n");
    for (i = 0; i < n; ++i) {
        const point *p = &pts[i];
        if (p->flow != flow || p->res != res[flow][0]) continue;
        fprintf(md, "| %s | %.1f | %.1f |", sph_kernel_name(p->k), p->c, p->neighbours);
        for (r = 0; r < 3; ++r) {
            int j;
            for (j = 0; j < n; ++j) {
                const point *o = &pts[j];
                if (o->flow != flow || o->k != p->k || o->c != p->c || o->res != res[flow][r]) continue;
                if (!o->ok) fprintf(md, " failed (%.1f) |", o->cpu);
                else if (nq == 1) fprintf(md, " %.4f (%.2f) |", o->l1[0], o->cpu);
                else fprintf(md, " %.4f, %.4f, %.4f (%.2f) |", o->l1[0], o->l1[1], o->l1[2], o->cpu);
            }
        }
        fprintf(md, "\n");
    }
    fprintf(md, "\n");
}

/* The load average of the last minute (/proc/loadavg), -1 where there is none: how busy the shared machine was. */
static double load_average(void)
{
    double l = -1;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f != NULL && fscanf(f, "%lf", &l) != 1) l = -1;
    if (f != NULL) fclose(f);
    return l;
}

static int write_report(const char *dir, const char *build, const double load[2], point *pts, int n, int quick)
{
    char path[1200], machine[512];
    FILE *md, *csv;
    double total = 0;
    int i, f, q;
    snprintf(path, sizeof path, "%s/flows/points.csv", dir);
    if ((csv = fopen(path, "w")) == NULL) return -1;
    fprintf(csv, "flow,kernel,c,neighbours,eta,res,particles,steps,cpu_s,L1,L1_v,L1_P,ok\n");
    for (i = 0; i < n; ++i) {
        const point *p = &pts[i];
        total += p->cpu;
        fprintf(csv, "%s,%s,%.1f,%.2f,%.5f,%d,%.0f,%.0f,%.3f,%.6e,%.6e,%.6e,%d\n", flow_name[p->flow],
                sph_kernel_name(p->k), p->c, p->neighbours, p->eta, p->res, p->particles, p->steps, p->cpu, p->l1[0],
                p->l1[1], p->l1[2], p->ok);
    }
    if (fclose(csv) != 0) return -1;
    snprintf(path, sizeof path, "%s/flows.md", dir);
    if ((md = fopen(path, "w")) == NULL) return -1;
    tm_machine(machine, sizeof machine);
    fprintf(md,
            "# Error against run time on flows\n\n"
            "Generated by `studies/flows_vs_runtime.c` (`make report-flows`)%s; every number below comes from that run. "
            "Every point is in [flows/points.csv](flows/points.csv), the fronts in `flows/front_*.csv`.\n\n"
            "Machine: %s; load average %.2f at the start, %.2f at the end (a shared machine: the CPU time of a "
            "run moves less with other jobs than its wall time, but it moves). Build: %s. Each run is one "
            "process on one thread; its CPU time (user + system, from the set-up to the error) is the cost. The "
            "whole study took %.0f s of CPU (%.1f min).\n\n"
            "**What is run.** Two whole solvers of `examples/`, every kernel at neighbour numbers of equal "
            "resolution: kernel k at the h where its standard deviation sigma_k h equals c times the cubic "
            "spline's at h = 1.2 dx (`sph_kernel_sigma`; c = 1 is the cubic's 18.1 neighbours in 2-D and 57.9 in "
            "3-D), the neighbours in its support following from h (`sph_kernel_neighbours`).\n\n"
            "- **Gresho-Chan vortex** ([examples/gresho.c](../../examples/gresho.c), "
            "[docs/examples.md](../examples.md#gresho-chan-vortex), and what was found of published figures): 2-D, n x n "
            "particles on a square lattice in the periodic unit box, the step of [docs/step.md](../step.md) "
            "(adaptive h, grad-h forces, signal-velocity viscosity) with the Balsara factor and SPHENIX's switch, "
            "to t = 1; L1 = mean over all particles of |v_phi - v_phi,exact(r)|. c = 1, 1.3, 1.6; n = 32, 64, 128; "
            "dt from `sph_time_step` ((S9), C_cfl = 0.5 on h_i / v_sig,i, and (S10)).\n"
            "- **Sod shock tube** ([examples/sod_shock.c](../../examples/sod_shock.c), "
            "[docs/smoothing_length.md](../smoothing_length.md#shock-tube-examplessod_shockc)): 3-D, two fcc lattices, "
            "the same step with SPHENIX's conductivity, to t = 0.2; L1 of rho, v_x and P over |x| <= 0.5 against the "
            "exact Riemann solution. c = 1, 1.3 (a 3-D neighbour costs more); nx = 16, 24, 32 fcc cells per unit "
            "length, the fewest cells across the tube that the kernel's reach allows (so a wider kernel runs a wider "
            "tube: more particles); dt = 0.3 h_min / v_sig,max, the example's default.\n\n"
            "Both time steps are in units of h as each kernel defines it, and a kernel's support is kappa h with "
            "kappa = 1 (Lucy), 2.5 (quartic), 3 (quintic) or 2: at equal resolution a kernel of small kappa has the "
            "larger h and takes the longer steps, and its CPU time includes that (the Lucy kernel's runs are the "
            "cheapest for this reason). The errors of one point move by a few per cent with small changes of h "
            "(docs/examples.md gives one case), so read neighbouring points on a front as ties.\n\n"
            "**Pareto front.** A point (CPU seconds, L1) is on the front when no point that cost at most as much has "
            "a smaller error: read a front table as *for this budget, this kernel at this neighbour number and "
            "resolution gives the least error*. Points off the front are never worth their time for that flow.\n\n",
            quick ? " with `--quick` (one resolution: a test of the pipeline, not the report)" : "", machine, load[0],
            load[1], build, total, total / 60);
    for (f = 0; f < NFLOW; ++f) {
        fprintf(md, "## %s\n\n", f == GRESHO ? "Gresho-Chan vortex (2-D, L1 of v_phi at t = 1)"
                                             : "Sod shock tube (3-D, L1 at t = 0.2)");
        fprintf(md, "![%s: L1 against CPU seconds](flows/pareto_%s.png)\n\n", flow_name[f], flow_name[f]);
        for (q = 0; q < (f == SOD ? 3 : 1); ++q) {
            if (f == SOD) fprintf(md, "Front of L1 %s:\n\n", qty_name[f][q]);
            if (write_front(md, dir, pts, n, f, q) != 0) return fclose(md), -1;
        }
        fprintf(md, "Every point, L1 (CPU seconds):\n\n");
        write_matrix(md, pts, n, f);
    }
    return fclose(md);
}

int main(int argc, char **argv)
{
    const char *bin = "build/flows", *out = "docs/results", *build = "(not given)";
    char dir[1100], tmp[1100];
    double load[2];
    point *pts;
    int quick = 0, n = 0, i, f, r, ci, k;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) quick = 1;
        else if (i + 1 < argc && strcmp(argv[i], "--bin") == 0) bin = argv[++i];
        else if (i + 1 < argc && strcmp(argv[i], "--out") == 0) out = argv[++i];
        else if (i + 1 < argc && strcmp(argv[i], "--build") == 0) build = argv[++i];
        else {
            fprintf(stderr, "flows_vs_runtime: unknown or incomplete option '%s'\n"
                    "usage: flows_vs_runtime [--bin DIR] [--out DIR] [--build TEXT] [--quick]\n", argv[i]);
            return 2;
        }
    }
    snprintf(dir, sizeof dir, "%s/flows", out);
    snprintf(tmp, sizeof tmp, "%s/sod_profiles", bin);
    if ((mkdir(out, 0777) != 0 && errno != EEXIST) || (mkdir(dir, 0777) != 0 && errno != EEXIST)) {
        fprintf(stderr, "flows_vs_runtime: cannot create %s\n", dir);
        return 1;
    }
    setenv("OMP_NUM_THREADS", "1", 1);
    pts = (point *)calloc((size_t)NFLOW * SPH_KERNEL_COUNT * 3 * 3, sizeof(point));
    if (pts == NULL) {
        fprintf(stderr, "flows_vs_runtime: out of memory\n");
        return 1;
    }
    load[0] = load_average();
    for (f = 0; f < NFLOW; ++f)
        for (k = 0; k < SPH_KERNEL_COUNT; ++k)
            for (ci = 0; ci < 3 && ladder[f][ci] > 0 && !(quick && ci > 0); ++ci)
                for (r = 0; r < 3 && !(quick && r > 0); ++r) {
                    point *p = &pts[n++];
                    p->flow = f, p->k = (sph_kernel)k, p->c = ladder[f][ci], p->res = res[f][r];
                    p->eta = rung_eta(p->k, flow_dim[f], p->c);
                    p->neighbours = rung_neighbours(p->k, flow_dim[f], p->eta);
                    run_point(bin, tmp, p);
                }
    load[1] = load_average();
    if (write_report(out, build, load, pts, n, quick) != 0) {
        fprintf(stderr, "flows_vs_runtime: cannot write into %s\n", out);
        free(pts);
        return 1;
    }
    for (i = 0, k = 0; i < n; ++i) k += !pts[i].ok;
    printf("wrote %s/flows.md, %s/points.csv and the fronts (%d points, %d failed)\n", out, dir, n, k);
    free(pts);
    return 0;
}
