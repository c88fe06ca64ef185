/*
 * bench_cost: api/cost.h's estimates against measured CPU time (and the peak
 * resident memory a job adds, in a forked child), for every preset at its
 * default resolution in every format, their properties, eval of 1e3 to 1e5
 * points, and heavy synthetic models: many modes, many force terms, high
 * powers. Prints a markdown table: estimate, median measured thread CPU time
 * over several runs, and their ratio (goal: within 0.5 to 2); then the
 * estimated peak scratch memory against the heap's measured peak, counted
 * in a forked child by wrapping malloc (the Makefile links this program with
 * -Wl,--wrap=malloc,...) and through cJSON's hooks.
 *
 *   bench_cost            the table for docs/BENCHMARKS.md
 *   bench_cost --quick    one run per case, presets fig1a and fig4a only
 *   bench_cost --heavy    the synthetic models only
 *   bench_cost --lofts    the loft presets only
 *   bench_cost --example3 the properties of fig. 3a's solid (example3) at n_xy = 10, 15, .., 100
 */
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cJSON.h>

#include "bench.h"
#include "cost.h"
#include "loft.h"
#include "model.h"
#include "output.h"
#include "pde.h"
#include "template.h"

static int runs = 3;

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* ---- the jobs ---- */

typedef enum { JOB_SOLVE, JOB_PROPS, JOB_OUTPUT, JOB_EVAL } job_kind;

typedef struct {
    job_kind kind;
    const api_model *model;
    const pde_solution *sol;
    const pde_props *props;
    api_format fmt;
    unsigned res[3];
    size_t npoints;
    int derivs;
} job;

static volatile double sink;

static void run(const job *j)
{
    switch (j->kind) {
    case JOB_SOLVE: {
        pde_solution *s = NULL;
        if (api_solve(j->model, &s, NULL) == 0)
            sink += (double)pde_solution_bytes(s);
        pde_solution_free(s);
        return;
    }
    case JOB_PROPS: {
        pde_props p;
        pde_properties(j->sol, NULL, &p);
        sink += p.volume;
        return;
    }
    case JOB_OUTPUT: {
        api_error err;
        api_output *o = api_output_open(j->sol, "bench", j->props, j->fmt, j->res, NULL, &err);
        static char buf[1 << 16];
        long n;
        while (o && (n = api_output_read(o, buf, sizeof buf)) > 0)
            sink += (double)n;
        api_output_free(o);
        return;
    }
    case JOB_EVAL: {
        size_t n = j->npoints;
        double *v = malloc(12 * n * sizeof *v);
        if (!v)
            return;
        double *du = v + 3 * n, *dv = v + 6 * n, *dw = v + 9 * n;
        for (size_t i = 0; i < n; i++) {
            double u = (i % 97) / 96.0, vv = (i % 89) / 88.0, w = (i % 83) / 82.0;
            pde_eval_d(j->sol, u, vv, w, v + 3 * i, j->derivs ? du + 3 * i : NULL, j->derivs ? dv + 3 * i : NULL,
                       j->derivs ? dw + 3 * i : NULL);
        }
        char *s = api_eval_json("bench", v, j->derivs ? du : NULL, j->derivs ? dv : NULL, j->derivs ? dw : NULL, n);
        sink += s ? (double)strlen(s) : 0.0;
        free(s);
        free(v);
        return;
    }
    }
}

static api_cost estimate(const job *j)
{
    api_cost c = { 0, 0 };
    switch (j->kind) {
    case JOB_SOLVE: api_cost_model(j->model, &c); break;
    case JOB_PROPS: api_cost_props(j->sol, &c); break;
    case JOB_OUTPUT: api_cost_output(j->sol, j->fmt, j->res, &c); break;
    case JOB_EVAL: api_cost_eval(j->sol, j->npoints, j->derivs, &c); break;
    }
    return c;
}

/* ---- the heap's peak: malloc wrapped at link time, counted only while tracking ---- */

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t k);
void *__real_realloc(void *p, size_t n);
void __real_free(void *p);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t k);
void *__wrap_realloc(void *p, size_t n);
void __wrap_free(void *p);

static int tracking;
static long long heap_now, heap_peak;

static void *noted(void *p)
{
    if (p && tracking) {
        heap_now += (long long)malloc_usable_size(p);
        if (heap_now > heap_peak)
            heap_peak = heap_now;
    }
    return p;
}

void *__wrap_malloc(size_t n)
{
    return noted(__real_malloc(n));
}

void *__wrap_calloc(size_t n, size_t k)
{
    return noted(__real_calloc(n, k));
}

void *__wrap_realloc(void *p, size_t n)
{
    long long old = p && tracking ? (long long)malloc_usable_size(p) : 0;
    void *q = __real_realloc(p, n);
    if (q) {
        heap_now -= old;
        noted(q);
    }
    return q;
}

void __wrap_free(void *p)
{
    if (p && tracking)
        heap_now -= (long long)malloc_usable_size(p);
    __real_free(p);
}

static void *hook_malloc(size_t n)
{
    return __wrap_malloc(n);
}

static void hook_free(void *p)
{
    __wrap_free(p);
}

/* The heap's peak growth during the job, in a forked child (MB). */
static double peak_mb(const job *j)
{
    int fd[2];
    if (pipe(fd))
        return -1;
    pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        cJSON_Hooks hooks = { hook_malloc, hook_free };
        cJSON_InitHooks(&hooks);
        tracking = 1;
        run(j);
        tracking = 0;
        double mb = (double)heap_peak / 1e6;
        if (write(fd[1], &mb, sizeof mb) != sizeof mb)
            _exit(1);
        _exit(0);
    }
    close(fd[1]);
    double mb = -1;
    if (pid < 0 || read(fd[0], &mb, sizeof mb) != sizeof mb)
        mb = -1;
    close(fd[0]);
    if (pid > 0)
        waitpid(pid, NULL, 0);
    return mb;
}

static double worst_lo = 1e9, worst_hi = 0;

static void report(const char *name, const job *j)
{
    api_cost c = estimate(j);
    double t[16];
    int n = runs;
    for (int r = 0; r < n; r++) {
        double t0 = cpu_now();
        run(j);
        t[r] = cpu_now() - t0;
        if (r == 0 && t[0] > 1.0)   /* a long case: one run is enough */
            n = 1;
    }
    double m = median(t, n), est = c.work * 1e-9, ratio = est / m;
    double mb = peak_mb(j);
    if (m > 2e-4) {                 /* below 0.2 ms the clock's and the caches' noise dominates */
        worst_lo = ratio < worst_lo ? ratio : worst_lo;
        worst_hi = ratio > worst_hi ? ratio : worst_hi;
    }
    printf("| %-34s | %10.2f | %10.2f | %5.2f | %8.1f | %7.1f |\n", name, est * 1e3, m * 1e3, ratio,
           c.bytes / 1e6, mb);
    fflush(stdout);
}

/* ---- models ---- */

/* A preset's model, as a client's {"preset": name} gives it: a paper figure's or a loft's */
static api_model *preset(const char *name)
{
    char doc[200];
    snprintf(doc, sizeof doc, "{\"preset\": \"%s\"}", name);
    api_error err;
    api_model *m = api_model_parse(doc, strlen(doc), &err);
    if (!m)
        fprintf(stderr, "%s: %s\n", name, err.message);
    return m;
}

/* A solid x = u, y = v, z = w-ish, to which the heavy terms are added. */
static pde_bterm base_b[3][1] = {
    { { { PDE_POW, 1 }, { PDE_POW, 0 }, 1, 0, 1, 0 } },
    { { { PDE_POW, 0 }, { PDE_POW, 1 }, 1, 0, 1, 0 } },
    { { { PDE_POW, 0 }, { PDE_POW, 0 }, 0, 1, 1, 1 } },
};

typedef struct {
    pde_model m;
    pde_bterm *b[3];
    pde_fterm *f[3];
} heavy;

/* kind 0: n force terms sin(a u) sin(b v) w^100 per component, all (u, v) distinct (the case);
 * kind 1: n distinct modes sin(i pi u) sin(i pi v) in the boundary data;
 * kind 2: n boundary terms u^p v^q, p, q near 100, whose chains make about 676 n modes. */
static void heavy_make(heavy *h, int kind, size_t n)
{
    memset(h, 0, sizeof *h);
    for (int c = 0; c < 3; c++) {
        h->b[c] = calloc(n + 1, sizeof *h->b[c]);
        h->f[c] = calloc(n + 1, sizeof *h->f[c]);
        h->b[c][0] = base_b[c][0];
        size_t nb = 1, nf = 0;
        for (size_t i = 0; i < n; i++) {
            double a = (double)(30 + i), b = (double)(30 + (i * 7) % n);   /* |e| > (30 pi)^4: w^100 stays well conditioned */
            if (kind == 0)
                h->f[c][nf++] = (pde_fterm){ 1e-3, { PDE_SIN, a }, { PDE_SIN, b }, { PDE_POW, 100 } };
            else if (kind == 1)
                h->b[c][nb++] = (pde_bterm){ { PDE_SIN, a }, { PDE_SIN, b }, 1e-3, 0, 1e-3, 0 };
            else
                h->b[c][nb++] = (pde_bterm){ { PDE_POW, 100 - (double)(i % 4) }, { PDE_POW, 100 - (double)(i / 4 % 4) },
                                             1e-3, 0, 1e-3, 0 };
        }
        h->m.comp[c] = (pde_component){ 1, 1, 1, h->b[c], nb, h->f[c], nf };
    }
}

static void heavy_free(heavy *h)
{
    for (int c = 0; c < 3; c++) {
        free(h->b[c]);
        free(h->f[c]);
    }
}

/* Every case of one solution: its solve, properties, the formats at res, eval. */
static void cases(const char *name, const api_model *m, const unsigned *res_grid, const unsigned *res_mesh,
                  const size_t *npts, int neval, int do_props, int do_json)
{
    char label[96];
    job j = { .kind = JOB_SOLVE, .model = m };
    snprintf(label, sizeof label, "%s solve", name);
    report(label, &j);
    pde_solution *sol;
    if (api_solve(m, &sol, NULL) != 0) {
        printf("| %s does not solve |\n", name);
        return;
    }
    pde_props props;
    pde_properties(sol, NULL, &props);
    j = (job){ .kind = JOB_PROPS, .sol = sol };
    if (do_props) {
        snprintf(label, sizeof label, "%s props", name);
        report(label, &j);
    }
    for (int f = 0; f < API_FMT_COUNT; f++) {
        if (f == API_FMT_JSON && !do_json)
            continue;
        const api_format_info *fi = api_format_info_of((api_format)f);
        const unsigned *r = fi->mesh ? res_mesh : res_grid;
        if (!r)
            continue;
        j = (job){ .kind = JOB_OUTPUT, .sol = sol, .props = &props, .fmt = (api_format)f };
        memcpy(j.res, r, sizeof j.res);
        if (f == API_FMT_JSON)
            snprintf(label, sizeof label, "%s json", name);
        else
            snprintf(label, sizeof label, "%s %s %u,%u,%u", name, fi->name, r[0], r[1], r[2]);
        report(label, &j);
    }
    for (int e = 0; e < neval; e++)
        for (int d = 0; d < 2; d++) {
            j = (job){ .kind = JOB_EVAL, .sol = sol, .npoints = npts[e], .derivs = d };
            snprintf(label, sizeof label, "%s eval %zu%s", name, npts[e], d ? " +d" : "");
            report(label, &j);
        }
    pde_solution_free(sol);
}

/* The properties of example3 (fig. 3a) at n_xy = 10 .. 100: separable and folding, with a rotation
 * along v at even n_xy (core/quad.c's face_rows). */
static void example3_sweep(void)
{
    const api_preset *ps = api_preset_find("fig3a");
    for (int n = 10; n <= 100; n += 5) {
        api_params prm;
        api_error err;
        api_preset_params(ps, &prm);
        const double nxy = n;
        if (api_params_set(api_preset_template(ps), &prm, "n_xy", &nxy, 1, &err))
            return;
        api_model *m = api_template_expand(api_preset_template(ps), &prm, &err);
        pde_solution *sol;
        if (!m || pde_solve(api_model_get(m), &sol, NULL) != PDE_OK) {
            api_model_free(m);
            return;
        }
        char label[64];
        snprintf(label, sizeof label, "example3 n_xy %d props", n);
        job j = { .kind = JOB_PROPS, .sol = sol };
        report(label, &j);
        pde_solution_free(sol);
        api_model_free(m);
    }
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--example3")) {
        printf("| case | estimate ms | measured ms | ratio | est. MB | heap peak MB |\n");
        printf("|---|---:|---:|---:|---:|---:|\n");
        example3_sweep();
        printf("\nratio estimate/measured: %.2f to %.2f\n", worst_lo, worst_hi);
        return 0;
    }
    int quick = argc > 1 && !strcmp(argv[1], "--quick"), heavy_only = argc > 1 && !strcmp(argv[1], "--heavy"),
        lofts_only = argc > 1 && !strcmp(argv[1], "--lofts");
    if (quick)
        runs = 1;
    printf("| case | estimate ms | measured ms | ratio | est. MB | heap peak MB |\n");
    printf("|---|---:|---:|---:|---:|---:|\n");
    static const unsigned g33[3] = { 33, 33, 33 }, m64[3] = { 64, 64, 64 };
    static const size_t pts[3] = { 1000, 10000, 100000 };
    for (size_t i = 0; i < api_preset_count() && !heavy_only && !lofts_only; i++) {
        const char *name = api_preset_at(i)->name;
        if (quick && strcmp(name, "fig1a") && strcmp(name, "fig4a"))
            continue;
        api_model *m = preset(name);
        int eval = !strcmp(name, "fig4a") || !strcmp(name, "fig3a");
        cases(name, m, g33, m64, pts, eval ? 3 : 0, 1, 1);
        api_model_free(m);
    }
    /* The gallery's lofts (api/loft_presets.c): sections of many harmonics, their own paths */
    for (size_t i = 0; i < api_loft_preset_count() && !heavy_only && !quick; i++) {
        api_model *m = preset(api_loft_preset_name(i, NULL));
        if (m)
            cases(api_loft_preset_name(i, NULL), m, g33, m64, pts, 0, 1, 1);
        api_model_free(m);
    }
    /* Heavy synthetic models, scaled so that each case takes seconds, not minutes. */
    static const struct {
        const char *name;
        int kind;
        size_t n;
        unsigned grid[3], mesh[3];
        size_t npts;
    } heavies[] = {
        { "force256", 0, 256, { 64, 64, 64 }, { 64, 64, 64 }, 1000 },
        { "force1024", 0, 1024, { 32, 32, 32 }, { 32, 32, 32 }, 100 },
        { "modes512", 1, 512, { 128, 128, 16 }, { 96, 96, 96 }, 1000 },
        { "modes4095", 1, 4095, { 32, 32, 8 }, { 16, 16, 16 }, 100 },
        { "pow4", 2, 4, { 64, 64, 64 }, { 64, 64, 64 }, 1000 },
    };
    for (size_t i = 0; i < sizeof heavies / sizeof *heavies; i++) {
        if ((quick && i > 0) || lofts_only)
            break;
        heavy h;
        heavy_make(&h, heavies[i].kind, heavies[i].n);
        api_model *m = api_model_build(&h.m, 0, NULL);
        if (m)
            cases(heavies[i].name, m, heavies[i].grid, heavies[i].mesh, &heavies[i].npts, 1, 1, 1);
        api_model_free(m);
        heavy_free(&h);
    }
    printf("\nratio estimate/measured over the cases above 0.2 ms: %.2f to %.2f\n", worst_lo, worst_hi);
    return 0;
}
