/* tests/test_example_io.c - the I/O of the example programs
 * (examples/example_io.h): options refused outside their accepted range,
 * checked allocations and particle counts, the NaN/Inf stop, the bound a
 * growing quantity stops a run at (its message read back from stderr), the
 * program name that starts every message, CSV values never printed as
 * -0.000, an output directory that is a file refused, and the VTK
 * series: a binary .vtu frame read back value by value with a reader written
 * here from the VTK XML file format (appended raw data: an 8-byte byte count
 * per array, then the values, at the array's offset after the '_' mark;
 * single-precision values, so each must equal the float of the input), its
 * TIME field, the .pvd listing, the ASCII variant, and the removal of an
 * earlier run's frames. */
/* example_io.h needs POSIX (clock_gettime, mkdtemp): the feature macro must
 * precede every system header of the unit, so this file states it first */
#define _POSIX_C_SOURCE 200809L
#include "examples/example_io.h"

#include <unistd.h>

#include "harness.h"

#define NP 7

static char *slurp(const char *path, long *size)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    if (f == NULL) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (*size = ftell(f)) > 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (buf = (char *)malloc((size_t)*size + 1)) != NULL) {
        if (fread(buf, 1, (size_t)*size, f) != (size_t)*size) {
            free(buf);
            buf = NULL;
        } else {
            buf[*size] = '\0';
        }
    }
    fclose(f);
    return buf;
}

/* The appended bytes of array name: its byte count in *bytes, NULL when absent. */
static const unsigned char *appended(const char *file, long size, const char *name, uint64_t *bytes)
{
    char key[96];
    const char *e, *o, *data;
    unsigned long offset;
    snprintf(key, sizeof key, "Name=\"%s\"", name);
    if ((e = strstr(file, key)) == NULL || (o = strstr(e, "offset=\"")) == NULL || o > strchr(e, '>')) return NULL;
    offset = strtoul(o + 8, NULL, 10);
    if ((data = strstr(file, "<AppendedData encoding=\"raw\">")) == NULL || (data = strchr(data, '_')) == NULL)
        return NULL;
    data += 1 + offset;
    if (data + 8 > file + size) return NULL;
    memcpy(bytes, data, 8);
    if (data + 8 + *bytes > file + size) return NULL;
    return (const unsigned char *)data + 8;
}

/* Compares the Float32 array name (ncomp per particle) with v (vcomp used). */
static void check_floats(const char *file, long size, const char *name, int ncomp, sph_view v, int vcomp)
{
    uint64_t bytes = 0;
    const unsigned char *d = appended(file, size, name, &bytes);
    int i, a, bad = 0;
    TH_CHECK(d != NULL, "array %s not found", name);
    if (d == NULL) return;
    TH_CHECK(bytes == (uint64_t)NP * ncomp * 4, "%s: %lu bytes", name, (unsigned long)bytes);
    for (i = 0; i < NP; ++i)
        for (a = 0; a < ncomp; ++a) {
            float got;
            const float want = a < vcomp ? (float)v.p[a][i * v.stride] : 0.0f;
            memcpy(&got, d + 4 * (i * ncomp + a), 4);
            bad += got != want;
        }
    TH_CHECK(bad == 0, "%s: %d values differ", name, bad);
}

static int parse(int argc, const char **argv, const ex_arg *opt, int n)
{
    return ex_parse_args(argc, (char **)(void *)argv, "test", opt, n);
}

static void test_options(void)
{
    double cfl = 0.25, hdx = 0;
    int n = 40, nx = 16;
    const char *kernel = "cubic", *out = "build";
    const ex_arg opt[] = {
        {"n", "", NULL, &n, NULL, NULL, 8, 4000, 0, NULL},
        {"cfl", "", &cfl, NULL, NULL, NULL, 0, 1, EX_OPEN_LO, NULL},
        {"hdx", "", &hdx, NULL, NULL, NULL, 1, 4, EX_OR_ZERO, NULL},
        {"kernel", "", NULL, NULL, &kernel, NULL, 0, 0, 0, ex_kernel_choices()},
        {"nx", "", NULL, &nx, NULL, NULL, 8, 64, EX_EVEN, NULL},
        {"out", "", NULL, NULL, &out, NULL, 0, 0, 0, NULL},
    };
    const int no = (int)(sizeof opt / sizeof opt[0]);
    static const char *refused[][3] = {
        {"p", "--n", "100000"}, {"p", "--n", "7"},      {"p", "--n", "12.5"},   {"p", "--n", "1e12"},
        {"p", "--cfl", "-1"},   {"p", "--cfl", "0"},    {"p", "--cfl", "1.5"},  {"p", "--cfl", "nan"},
        {"p", "--cfl", "inf"},  {"p", "--cfl", "0.2x"}, {"p", "--hdx", "-1"},   {"p", "--hdx", "0.5"},
        {"p", "--kernel", "foo"}, {"p", "--kernel", ""}, {"p", "--bogus", "1"}, {"p", "--kernel", "cubicx"},
        {"p", "--nx", "17"},    {"p", "--nx", "66"},    {"p", "--nx", "6"}};
    size_t q;
    th_begin("options: values outside the range refused");
    for (q = 0; q < sizeof refused / sizeof refused[0]; ++q)
        TH_CHECK(parse(3, refused[q], opt, no) == -1, "%s %s accepted", refused[q][1], refused[q][2]);
    TH_CHECK(n == 40 && cfl == 0.25 && hdx == 0 && nx == 16 && strcmp(kernel, "cubic") == 0,
             "a refused value was stored");
    {
        const char *missing[] = {"p", "--n"}, *followed[] = {"p", "--out", "--n", "10"};
        TH_CHECK(parse(2, missing, opt, no) == -1, "missing value accepted");
        TH_CHECK(parse(4, followed, opt, no) == -1 && strcmp(out, "build") == 0, "the next option taken as value");
    }
    th_end();
    th_begin("options: values inside the range stored");
    {
        const char *ok[] = {"p", "--n", "4000", "--cfl", "1", "--hdx", "0", "--kernel", "wendland_c4"};
        TH_CHECK(parse(9, ok, opt, no) == 0, "refused");
        TH_CHECK(n == 4000 && cfl == 1 && hdx == 0 && strcmp(kernel, "wendland_c4") == 0, "n %d cfl %g hdx %g %s", n,
                 cfl, hdx, kernel);
    }
    {
        const char *ok[] = {"p", "--n", "8", "--hdx", "4", "--cfl", "1e-9", "--nx", "64"};
        TH_CHECK(parse(9, ok, opt, no) == 0 && n == 8 && hdx == 4 && cfl == 1e-9 && nx == 64, "ends of the ranges");
    }
    th_end();
    th_begin("options: the program name is argv[0] without its directory");
    {
        const char *args[] = {"./build/flows/sod_shock", "--nx", "18"};
        TH_CHECK(ex_parse_args(3, (char **)(void *)args, "test", opt, no) == 0 && nx == 18, "refused");
        TH_CHECK(strcmp(ex_prog(), "sod_shock") == 0, "program name '%s'", ex_prog());
    }
    th_end();
}

static void test_sizes(void)
{
    sph_idx n = 0;
    th_begin("allocation and particle counts checked");
    TH_CHECK(ex_calloc((size_t)-1 / 4, 8, NULL) == NULL, "overflowing size allocated");
    TH_CHECK(ex_particle_count(1e10, "test", &n) == SPH_ESIZE && n == 0, "1e10 particles accepted");
    TH_CHECK(ex_particle_count(2147483647.0, "test", &n) == SPH_OK && n == 2147483647, "INT32_MAX refused");
    th_end();
}

static void test_finite(void)
{
    sph_real a[NP] = {1, 2, 3, 4, 5, 6, 7}, b[2 * NP] = {0};
    ex_field f[2];
    f[0].name = "a", f[0].v = sph_view_soa(a, NULL, NULL), f[0].ncomp = 1;
    f[1].name = "b", f[1].v = sph_view_interleaved(b, 2), f[1].ncomp = 2;
    th_begin("NaN and Inf stop a run");
    TH_CHECK(ex_fields_finite("test", f, 2, NP, 0) == SPH_OK, "finite fields refused");
    b[2 * 3 + 1] = (sph_real)HUGE_VAL;
    TH_CHECK(ex_fields_finite("test", f, 2, NP, 0.5) == SPH_ENONFINITE, "Inf accepted");
    b[2 * 3 + 1] = 0, a[5] = (sph_real)NAN;
    TH_CHECK(ex_fields_finite("test", f, 2, NP, 0.5) == SPH_ENONFINITE, "NaN accepted");
    th_end();
}

/* What fn wrote on stderr (at most size - 1 characters), read back from a temporary file. */
static void capture_stderr(void (*fn)(void *), void *arg, char *out, size_t size)
{
    FILE *tmp = tmpfile();
    int saved;
    size_t got = 0;
    out[0] = '\0';
    if (tmp == NULL) return;
    fflush(stderr);
    saved = dup(2);
    dup2(fileno(tmp), 2);
    fn(arg);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    rewind(tmp);
    got = fread(out, 1, size - 1, tmp);
    out[got] = '\0';
    fclose(tmp);
}

typedef struct {
    ex_growth g;
    double value, t;
    int st;
} growth_case;

static void run_growth(void *arg)
{
    growth_case *c = (growth_case *)arg;
    c->st = ex_growth_check(&c->g, c->value, c->t);
}

static void test_growth(void)
{
    growth_case c;
    char msg[512], text[128];
    th_begin("a quantity past its bound stops the run, the message names it");
    c.g.quantity = "kinetic energy", c.g.hint = "time step too large";
    c.g.start = 0.25, c.g.factor = 1.01, c.g.margin = 0;
    TH_CHECK(ex_growth_bound(&c.g) == 0.25 * 1.01, "bound %.17g", ex_growth_bound(&c.g));
    c.value = 0.25 * 1.01, c.t = 0.5;
    capture_stderr(run_growth, &c, msg, sizeof msg);
    TH_CHECK(c.st == SPH_OK && msg[0] == '\0', "the bound itself refused: %d '%s'", c.st, msg);
    c.value = 0.2526, c.t = 0.125;
    capture_stderr(run_growth, &c, msg, sizeof msg);
    TH_CHECK(c.st == EX_EGROWTH, "0.2526 > 0.2525 accepted");
    TH_CHECK(strncmp(msg, ex_prog(), strlen(ex_prog())) == 0 && strstr(msg, "kinetic energy = 0.2526") != NULL &&
                 strstr(msg, "t = 0.125") != NULL && strstr(msg, "bound 0.2525") != NULL &&
                 strstr(msg, "time step too large") != NULL,
             "message: '%s'", msg);
    c.value = NAN;
    capture_stderr(run_growth, &c, msg, sizeof msg);
    TH_CHECK(c.st == EX_EGROWTH, "NaN accepted");
    c.g.start = 0, c.g.factor = 1, c.g.margin = 1, c.value = 1.5;
    capture_stderr(run_growth, &c, msg, sizeof msg);
    TH_CHECK(c.st == EX_EGROWTH && strstr(msg, "bound 1:") != NULL, "error bound: %d '%s'", c.st, msg);
    ex_growth_text(&c.g, text, sizeof text);
    TH_CHECK(strcmp(text, "kinetic energy <= 1") == 0, "text '%s'", text);
    c.g.start = 2, c.g.factor = 1.01;
    ex_growth_text(&c.g, text, sizeof text);
    TH_CHECK(strcmp(text, "kinetic energy <= 1.01 x its start value 2 + 1") == 0, "text '%s'", text);
    TH_CHECK(strcmp(ex_strerror(EX_EGROWTH), ex_strerror(SPH_ENONFINITE)) != 0, "no message of its own");
    th_end();
}

static void test_csv_and_dirs(void)
{
    char dir[] = "/tmp/sph_example_dir_XXXXXX", path[256];
    FILE *f;
    th_begin("CSV values: no -0.000");
    TH_CHECK(!signbit(ex_csv_fixed(-0.0, 6)) && !signbit(ex_csv_fixed(-4e-7, 6)), "negative zero kept");
    TH_CHECK(ex_csv_fixed(-6e-7, 6) == -6e-7 && ex_csv_fixed(-4e-7, 7) == -4e-7 && ex_csv_fixed(3e-7, 6) == 3e-7,
             "a value that prints as a non-zero changed");
    th_end();
    th_begin("an output directory that exists as a file is refused");
    TH_CHECK(mkdtemp(dir) != NULL, "no temporary directory");
    TH_CHECK(ex_mkdir_p(dir) == 0, "an existing directory refused");
    snprintf(path, sizeof path, "%s/file", dir);
    if ((f = fopen(path, "w")) != NULL) fclose(f);
    TH_CHECK(ex_mkdir_p(path) != 0, "a file accepted as directory");
    remove(path);
    snprintf(path, sizeof path, "%s/a/b", dir);
    TH_CHECK(ex_mkdir_p(path) == 0, "nested directories not created");
    remove(path);
    snprintf(path, sizeof path, "%s/a", dir);
    remove(path);
    TH_CHECK(remove(dir) == 0, "temporary directory not empty");
    th_end();
}

static void test_series(void)
{
    char dir[] = "/tmp/sph_example_io_XXXXXX", path[256], *file;
    sph_real x[2 * NP], u[NP], v[NP], p[NP];
    ex_field f[2];
    ex_series s;
    long size = 0;
    int i, frame;
    FILE *keep;
    th_begin("VTK series: binary frame read back");
    TH_CHECK(mkdtemp(dir) != NULL, "no temporary directory");
    for (i = 0; i < NP; ++i) {
        x[2 * i] = (sph_real)(0.1 * i + 1.0 / 3), x[2 * i + 1] = (sph_real)(-0.7 * i);
        u[i] = (sph_real)(i * i) / 7, v[i] = -(sph_real)i / 3, p[i] = (sph_real)(1e5 + i);
    }
    f[0].name = "velocity", f[0].v = sph_view_soa(u, v, NULL), f[0].ncomp = 2;
    f[1].name = "pressure", f[1].v = sph_view_soa(p, NULL, NULL), f[1].ncomp = 1;
    TH_CHECK(ex_series_open(&s, dir, "run", 0) == 0 && s.removed == 0, "open");
    for (frame = 0; frame < 3; ++frame)
        TH_CHECK(ex_series_write(&s, 0.25 * frame, NP, 2, sph_view_interleaved(x, 2), f, 2) == 0, "frame %d", frame);
    TH_CHECK(s.count == 3, "%d frames counted", s.count);
    snprintf(path, sizeof path, "%s/run_0002.vtu", dir);
    file = slurp(path, &size);
    TH_CHECK(file != NULL, "%s not read", path);
    if (file != NULL) {
        const uint16_t one = 1;
        const char *t = strstr(file, "Name=\"TIME\"");
        uint64_t bytes = 0;
        const unsigned char *d;
        int bad = 0;
        TH_CHECK(strstr(file, *(const unsigned char *)&one ? "byte_order=\"LittleEndian\"" : "byte_order=\"BigEndian\"")
                     != NULL, "byte order not the host's");
        TH_CHECK(t != NULL && strtod(strchr(t, '>') + 1, NULL) == 0.5, "TIME of frame 2 not 0.5");
        check_floats(file, size, "Points", 3, sph_view_interleaved(x, 2), 2);
        check_floats(file, size, "velocity", 3, sph_view_soa(u, v, NULL), 2);
        check_floats(file, size, "pressure", 1, sph_view_soa(p, NULL, NULL), 1);
        d = appended(file, size, "offsets", &bytes);
        for (i = 0; d != NULL && i < NP; ++i) {
            int32_t o;
            memcpy(&o, d + 4 * i, 4);
            bad += o != i + 1;
        }
        TH_CHECK(d != NULL && bytes == 4 * NP && bad == 0, "vertex offsets");
        d = appended(file, size, "types", &bytes);
        for (i = 0, bad = 0; d != NULL && i < NP; ++i) bad += d[i] != 1;
        TH_CHECK(d != NULL && bytes == NP && bad == 0, "cell types not VTK_VERTEX");
        free(file);
    }
    snprintf(path, sizeof path, "%s/run.pvd", dir);
    file = slurp(path, &size);
    TH_CHECK(file != NULL && strstr(file, "timestep=\"0.25\" part=\"0\" file=\"run_0001.vtu\"") != NULL &&
                 strstr(file, "file=\"run_0002.vtu\"") != NULL && strstr(file, "run_0003") == NULL,
             "series file:\n%s", file ? file : "(none)");
    free(file);
    ex_series_close(&s);
    th_end();

    th_begin("VTK series: ASCII frame, earlier run removed, other files kept");
    snprintf(path, sizeof path, "%s/run_notes.txt", dir);
    keep = fopen(path, "w");
    if (keep != NULL) fclose(keep);
    TH_CHECK(ex_series_open(&s, dir, "run", 1) == 0 && s.removed == 4, "removed %d files, not 3 frames and the .pvd",
             s.removed);
    TH_CHECK(ex_series_write(&s, 1.5, NP, 2, sph_view_interleaved(x, 2), f, 2) == 0, "ASCII frame");
    snprintf(path, sizeof path, "%s/run_0001.vtu", dir);
    TH_CHECK(fopen(path, "r") == NULL, "frame 1 of the earlier run left");
    snprintf(path, sizeof path, "%s/run_notes.txt", dir);
    TH_CHECK((keep = fopen(path, "r")) != NULL, "a file not of the series removed");
    if (keep != NULL) fclose(keep), remove(path);
    snprintf(path, sizeof path, "%s/run_0000.vtu", dir);
    file = slurp(path, &size);
    if (file != NULL) {
        const char *a = strstr(file, "Name=\"pressure\"");
        char *end = NULL;
        int bad = 0;
        a = a ? strchr(a, '>') + 1 : NULL;
        for (i = 0; a != NULL && i < NP; ++i, a = end) bad += (float)strtod(a, &end) != (float)p[i];
        TH_CHECK(a != NULL && bad == 0, "ASCII pressure differs");
        TH_CHECK(strstr(file, "AppendedData") == NULL, "ASCII frame has appended data");
        free(file);
    }
    TH_CHECK(file != NULL, "ASCII frame not read");
    ex_series_close(&s);
    TH_CHECK(ex_series_open(&s, dir, "run", 0) == 0 && s.removed == 2, "clean-up");
    ex_series_close(&s);
    TH_CHECK(remove(dir) == 0, "temporary directory not empty");
    th_end();
}

int main(void)
{
    test_options();
    test_sizes();
    test_finite();
    test_growth();
    test_csv_and_dirs();
    test_series();
    return th_summary();
}
