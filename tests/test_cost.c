/*
 * test_cost.c: cooperative cancellation of the long calls (pde_solve_ex,
 * pde_properties, api_mesh_build, api_output_open), the bounded work of
 * api_output_read, and api/cost.h's estimates: they scale as the code does,
 * put the heavy requests of issue 8 over 2 CPU-seconds and 64 MB, and every
 * preset in every format at its default resolution well under.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#if defined(__SANITIZE_ADDRESS__)
size_t __sanitizer_get_current_allocated_bytes(void);   /* the ASan runtime's (sanitizer/allocator_interface.h) */
#else
#include <malloc.h>
#endif

#include "cost.h"
#include "loft.h"
#include "mesh.h"
#include "output.h"
#include "support.h"
#include "template.h"

/* ---- a stop() that counts its calls and stops from the Nth on ---- */

typedef struct {
    long calls, stop_at;   /* stop_at 0: never */
} counter;

static int count_stop(void *arg)
{
    counter *c = arg;
    c->calls++;
    return c->stop_at > 0 && c->calls >= c->stop_at;
}

/* ---- models ---- */

/* The heavy models of issue 8, with n terms per component (the issue's have 4096):
 * FORCE: force terms sin(a pi u) sin(b pi v) w^100, every (a, b) and every a distinct;
 * (4095 of them and the base term make the limit of 4096 modes)
 * MODES: boundary terms sin(a pi u) sin(b pi v), n distinct modes and u-factors. */
enum { FORCE, MODES };

typedef struct {
    pde_model m;
    pde_bterm *b[3];
    pde_fterm *f[3];
} heavy;

static void heavy_make(heavy *h, int kind, size_t n)
{
    static const pde_bterm base[3] = {
        { { PDE_POW, 1 }, { PDE_POW, 0 }, 1, 0, 1, 0 },
        { { PDE_POW, 0 }, { PDE_POW, 1 }, 1, 0, 1, 0 },
        { { PDE_POW, 0 }, { PDE_POW, 0 }, 0, 1, 1, 1 },
    };
    memset(h, 0, sizeof *h);
    for (int c = 0; c < 3; c++) {
        h->b[c] = calloc(n + 1, sizeof *h->b[c]);
        h->f[c] = calloc(n + 1, sizeof *h->f[c]);
        assert_true(h->b[c] && h->f[c]);
        h->b[c][0] = base[c];
        size_t nb = 1, nf = 0;
        for (size_t i = 0; i < n; i++) {
            double a = (double)(30 + i), b = (double)(30 + (i * 7) % n);   /* |e| > (30 pi)^4: w^100 stays well conditioned */
            if (kind == FORCE)
                h->f[c][nf++] = (pde_fterm){ 1e-3, { PDE_SIN, a }, { PDE_SIN, b }, { PDE_POW, 100 } };
            else
                h->b[c][nb++] = (pde_bterm){ { PDE_SIN, a }, { PDE_SIN, b }, 1e-3, 0, 1e-3, 0 };
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

/* ---- cancellation ---- */

/* Runs call with a counter stopping at stop_at; returns its result. */
typedef int (*cancellable)(const void *arg, const pde_cancel *cancel);

/* Counts the polls of a full run, then stops at the first, a middle and the last poll: each run must
 * fail as cancelled right at that poll (no poll after it), and a run allowed one poll more succeeds. */
static void check_cancellation(cancellable call, const void *arg, int ok, int cancelled, long min_polls)
{
    counter all = { 0, 0 };
    pde_cancel cancel = { count_stop, &all };
    assert_int_equal(call(arg, &cancel), ok);
    assert_true(all.calls >= min_polls);
    const long at[] = { 1, 2, all.calls / 2, all.calls };
    for (size_t i = 0; i < sizeof at / sizeof *at; i++) {
        counter c = { 0, at[i] };
        pde_cancel k = { count_stop, &c };
        assert_int_equal(call(arg, &k), cancelled);
        assert_int_equal(c.calls, at[i]);
    }
    counter last = { 0, all.calls + 1 };
    pde_cancel k = { count_stop, &last };
    assert_int_equal(call(arg, &k), ok);
}

static int call_solve(const void *arg, const pde_cancel *cancel)
{
    pde_solve_opts opts = { cancel };
    pde_solution *sol = (pde_solution *)(uintptr_t)0x1;   /* must stay untouched on failure */
    pde_diag d;
    pde_status st = pde_solve_ex(arg, &opts, &sol, &d);
    if (st == PDE_OK) {
        pde_solution_free(sol);
    } else {
        assert_ptr_equal(sol, (pde_solution *)(uintptr_t)0x1);
        if (st == PDE_ERR_CANCELLED)
            assert_string_equal(d.message, "cancelled");
    }
    return st;
}

static void solve_ex_should_stop_at_the_poll_that_asks_and_free_everything(void **state)
{
    (void)state;
    heavy h;
    heavy_make(&h, FORCE, 64);
    check_cancellation(call_solve, &h.m, PDE_OK, PDE_ERR_CANCELLED, 3 * 64);
    heavy_free(&h);
}

static void solve_ex_should_match_solve_without_options(void **state)
{
    (void)state;
    api_model *m = preset_model("fig4a");
    pde_solution *a, *b;
    pde_solve_opts none = { NULL };
    pde_cancel never = { NULL, NULL };
    pde_solve_opts nullstop = { &never };
    assert_int_equal(pde_solve(api_model_get(m), &a, NULL), PDE_OK);
    assert_int_equal(pde_solve_ex(api_model_get(m), &none, &b, NULL), PDE_OK);
    double xa[3], xb[3];
    pde_eval(a, 0.3, 0.6, 0.7, xa);
    pde_eval(b, 0.3, 0.6, 0.7, xb);
    for (int c = 0; c < 3; c++)
        assert_true(xa[c] == xb[c]);
    pde_solution_free(b);
    assert_int_equal(pde_solve_ex(api_model_get(m), &nullstop, &b, NULL), PDE_OK);
    pde_solution_free(b);
    assert_int_equal(pde_solve_ex(api_model_get(m), NULL, &b, NULL), PDE_OK);
    pde_solution_free(b);
    pde_solution_free(a);
    api_model_free(m);
    assert_string_equal(pde_strerror(PDE_ERR_CANCELLED), "cancelled");
}

static int call_props(const void *arg, const pde_cancel *cancel)
{
    pde_props_opts opts = { .cancel = cancel };
    pde_props p, before;
    memset(&p, 0x5a, sizeof p);
    before = p;
    pde_status st = pde_properties(arg, &opts, &p);
    if (st != PDE_OK)
        assert_memory_equal(&p, &before, sizeof p);   /* left untouched */
    else
        assert_true(p.volume > 0);
    return st;
}

static void properties_should_stop_at_the_poll_that_asks_and_leave_out_untouched(void **state)
{
    (void)state;
    /* Polled about every millisecond of work: fig. 3a's properties take tens of polls (fig. 4a's took 12 until
     * they got cheaper, and take 4). */
    pde_solution *sol = preset_solution("fig3a");
    check_cancellation(call_props, sol, PDE_OK, PDE_ERR_CANCELLED, 10);
    pde_solution_free(sol);
}

typedef struct {
    const pde_solution *sol;
    unsigned res[3];
    api_format fmt;
} out_arg;

static int call_mesh(const void *arg, const pde_cancel *cancel)
{
    const out_arg *a = arg;
    api_mesh m;
    api_error err = { .status = API_OK };
    int rc = api_mesh_build(a->sol, a->res, cancel, &m, &err);
    if (rc == 0) {
        assert_true(m.ntris > 0);
        api_mesh_free(&m);
    } else {
        assert_int_equal(err.status, API_ERR_CANCELLED);
        assert_string_equal(err.message, "cancelled");
        assert_null(m.pos);
        assert_null(m.tri);
    }
    return rc;
}

static void mesh_build_should_stop_at_the_poll_that_asks_and_free_everything(void **state)
{
    (void)state;
    pde_solution *sol = preset_solution("fig4a");
    /* Faces are polled per row or plane (6 x 48), welding per 8192 samples (6 x 48^2 of them). */
    out_arg a = { sol, { 48, 48, 48 }, API_FMT_GLB };
    check_cancellation(call_mesh, &a, 0, -1, 6 * 48 + 6 * 48 * 48 / 8192);
    pde_solution_free(sol);
}

static int call_output(const void *arg, const pde_cancel *cancel)
{
    const out_arg *a = arg;
    api_error err = { .status = API_OK };
    api_output *o = api_output_open(a->sol, "id", NULL, a->fmt, a->res, cancel, &err);
    if (!o) {
        assert_int_equal(err.status, API_ERR_CANCELLED);
        assert_string_equal(err.message, "cancelled");
        return -1;
    }
    char buf[4096];
    long n, total = 0;
    while ((n = api_output_read(o, buf, sizeof buf)) > 0)
        total += n;
    assert_int_equal(n, 0);
    assert_true(total > 0);
    api_output_free(o);
    return 0;
}

static void output_open_should_stop_in_the_properties_and_the_mesh_it_computes(void **state)
{
    (void)state;
    pde_solution *sol = preset_solution("fig3a");
    /* json and vts: the properties; glb: the mesh, then the properties; stl: the mesh alone. */
    static const api_format fmts[] = { API_FMT_JSON, API_FMT_VTS, API_FMT_GLB, API_FMT_STL };
    for (size_t i = 0; i < sizeof fmts / sizeof *fmts; i++) {
        out_arg a = { sol, { 16, 16, 16 }, fmts[i] };
        check_cancellation(call_output, &a, 0, -1, 10);
    }
    pde_solution_free(sol);
}

static void output_read_should_sample_a_bounded_number_of_rows_per_call(void **state)
{
    (void)state;
    heavy h;
    heavy_make(&h, MODES, 256);
    pde_solution *sol;
    assert_int_equal(pde_solve(&h.m, &sol, NULL), PDE_OK);
    size_t nm = 0;
    for (int c = 0; c < 3; c++) {
        size_t k;
        pde_solution_modes(sol, c, &k);
        nm += k;
    }
    const unsigned res[3] = { 64, 64, 4 };
    api_error err;
    api_output *o = api_output_open(sol, NULL, NULL, API_FMT_F32, res, NULL, &err);
    assert_non_null(o);
    /* A row of 64 points costs about nm (3 + 64) multiply-adds; a call does about 2^21 of them. */
    size_t rows = (size_t)((1u << 21) / ((double)nm * (3 + 64)));
    static char buf[1 << 20];
    long n, total = 0, calls = 0;
    while ((n = api_output_read(o, buf, sizeof buf)) > 0) {
        assert_true((size_t)n <= 12 * 64 * (rows > 0 ? rows : 1));
        total += n;
        calls++;
    }
    assert_int_equal(n, 0);
    assert_int_equal(total, 12 * 64 * 64 * 4);
    assert_true(calls >= (long)(64 * 4 / (rows > 0 ? rows : 1)));
    api_output_free(o);
    pde_solution_free(sol);
    heavy_free(&h);
}

/* ---- the estimates ---- */

/* The volume meshes at res 80 (512000 points), against their measured CPU time (pdesolid solve --preset P
 * --res 80 -o a.msh, user time, docs/BENCHMARKS.md): the estimate not below it, nor over 2.5 times it. */
static void volume_mesh_estimates_should_not_be_below_their_measured_time(void **state)
{
    (void)state;
    const struct {
        const char *preset;
        api_format f;
        double measured_ns;
    } cases[] = {
        { "fig4a", API_FMT_MSH, 0.97e9 }, { "fig4a", API_FMT_VTU, 0.06e9 },
        { "fig1a", API_FMT_MSH, 0.93e9 }, { "fig1a", API_FMT_VTU, 0.08e9 },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        pde_solution *sol = preset_solution(cases[i].preset);
        api_cost c;
        api_cost_output(sol, cases[i].f, (const unsigned[3]){ 80, 80, 80 }, &c);
        double r = c.work / cases[i].measured_ns;
        print_message("%s %s: estimate %.3g, measured %.3g ns, ratio %.2f\n", cases[i].preset,
                      api_format_info_of(cases[i].f)->name, c.work, cases[i].measured_ns, r);
        assert_true(r >= 1.0 && r <= 2.5);
        pde_solution_free(sol);
    }
}

static void f32_work_should_grow_eightfold_when_the_resolution_doubles(void **state)
{
    (void)state;
    heavy h;
    heavy_make(&h, MODES, 64);
    pde_solution *sol;
    assert_int_equal(pde_solve(&h.m, &sol, NULL), PDE_OK);
    api_cost a, b;
    api_cost_output(sol, API_FMT_F32, (const unsigned[3]){ 128, 128, 128 }, &a);
    api_cost_output(sol, API_FMT_F32, (const unsigned[3]){ 256, 256, 256 }, &b);
    assert_true(b.work / a.work > 7.0 && b.work / a.work < 8.5);
    /* Planes alone: linear in nw. */
    api_cost_output(sol, API_FMT_F32, (const unsigned[3]){ 128, 128, 256 }, &b);
    assert_true(b.work / a.work > 1.8 && b.work / a.work < 2.05);
    pde_solution_free(sol);
    heavy_free(&h);
}

static void grid_memory_should_grow_with_the_modes(void **state)
{
    (void)state;
    api_cost c[2];
    const size_t n[2] = { 256, 1024 };
    for (int i = 0; i < 2; i++) {
        heavy h;
        heavy_make(&h, MODES, n[i]);
        pde_solution *sol;
        assert_int_equal(pde_solve(&h.m, &sol, NULL), PDE_OK);
        api_cost_output(sol, API_FMT_F32, (const unsigned[3]){ 512, 512, 2 }, &c[i]);
        /* The tables alone: f_u and f_u' per distinct u-factor and u, f_v and f_v' per mode and v. */
        double tables = 3.0 * 16.0 * (double)(n[i] + 1) * (512 + 512);
        assert_true(c[i].bytes > tables && c[i].bytes < 1.5 * tables);
        pde_solution_free(sol);
        heavy_free(&h);
    }
    assert_true(c[1].bytes / c[0].bytes > 3.5 && c[1].bytes / c[0].bytes < 4.1);
}

/* Bytes the heap holds now: ASan's allocator under the sanitizers (the tests' build), else glibc's. */
static double heap_in_use(void)
{
#if defined(__SANITIZE_ADDRESS__)
    return (double)__sanitizer_get_current_allocated_bytes();
#else
    struct mallinfo2 mi = mallinfo2();
    return (double)mi.uordblks + (double)mi.hblkhd;
#endif
}

/* The mesh's two blocks stay allocated (kept for the next build) after api_mesh_free, so the heap's growth
 * over a build is what it allocated; the estimate adds the sampling grids, a few percent here. */
static void mesh_memory_estimate_should_match_the_blocks_a_build_allocates(void **state)
{
    (void)state;
    const char *presets[] = { "fig4a", "fig1a" };
    const unsigned res[][3] = { { 256, 256, 256 }, { 64, 32, 16 } };
    for (size_t i = 0; i < 2; i++)
        for (size_t r = 0; r < 2; r++) {
            pde_solution *sol = preset_solution(presets[i]);
            api_mesh_release_spares();
            const double before = heap_in_use();
            api_mesh m;
            api_error err;
            assert_int_equal(api_mesh_build(sol, res[r], NULL, &m, &err), 0);
            api_mesh_free(&m);
            const double blocks = heap_in_use() - before;
            api_mesh_release_spares();
            api_cost c;
            api_cost_skin(sol, res[r], 0.0, 0.0, 0.0, 0.0, &c);
            print_message("%s at %u x %u x %u: blocks %.0f bytes, estimate %.0f\n", presets[i], res[r][0], res[r][1],
                          res[r][2], blocks, c.bytes);
            assert_true(c.bytes >= blocks);
            if (r == 0)   /* at 64 x 32 x 16 the skin's 2 MB read buffer is the estimate's larger term */
                assert_true(c.bytes <= 1.1 * blocks);
            pde_solution_free(sol);
        }
}

static void eval_work_should_be_linear_in_the_points(void **state)
{
    (void)state;
    pde_solution *sol = preset_solution("fig4a");
    api_cost a, b, d;
    api_cost_eval(sol, 10000, 0, &a);
    api_cost_eval(sol, 100000, 0, &b);
    api_cost_eval(sol, 100000, 1, &d);
    assert_true(fabs(b.work / a.work - 10.0) < 0.1);
    assert_true(fabs(b.bytes / a.bytes - 10.0) < 0.5);
    assert_true(d.work > b.work && d.bytes > b.bytes);   /* three more arrays of numbers to print */
    pde_solution_free(sol);
}

#define BUDGET 2e9          /* about 2 CPU-seconds */
#define MEMORY 64e6

static void heavy_requests_of_the_issue_should_exceed_the_budget(void **state)
{
    (void)state;
    heavy f, m;
    heavy_make(&f, FORCE, 4095);
    heavy_make(&m, MODES, 4095);
    pde_solution *fs, *ms;
    api_cost solve, props, out;
    api_cost_solve(&f.m, &solve);
    assert_int_equal(pde_solve(&f.m, &fs, NULL), PDE_OK);
    assert_int_equal(pde_solve(&m.m, &ms, NULL), PDE_OK);

    /* glb res 512 of 4096 force terms per component: 309 CPU-s, and 86 s of properties. */
    api_cost_props(fs, &props);
    api_cost_output(fs, API_FMT_GLB, (const unsigned[3]){ 512, 512, 512 }, &out);
    assert_true(props.work > 10 * BUDGET);
    assert_true(out.work > 30 * BUDGET);
    assert_true(out.bytes > MEMORY);

    /* eval of 100,000 points with derivatives on a 4096-mode model: 155 CPU-s. */
    api_cost_eval(ms, 100000, 1, &out);
    assert_true(out.work > 20 * BUDGET);

    /* The same model's json: 86 CPU-s and 341 MB, mostly the properties. */
    api_cost_props(ms, &props);
    api_cost_output(ms, API_FMT_JSON, (const unsigned[3]){ 33, 33, 33 }, &out);
    assert_true(props.work + out.work > 5 * BUDGET);

    /* f32 res 4096,4096,2 of 4096 distinct modes: 1.5 GB of sampling tables. */
    api_cost_output(ms, API_FMT_F32, (const unsigned[3]){ 4096, 4096, 2 }, &out);
    assert_true(out.bytes > 1.2e9 && out.bytes < 2.4e9);
    assert_true(out.work > BUDGET);

    pde_solution_free(fs);
    pde_solution_free(ms);
    heavy_free(&f);
    heavy_free(&m);
}

static void every_preset_in_every_format_should_stay_well_under_the_budget(void **state)
{
    (void)state;
    for (size_t i = 0; i < api_preset_count(); i++) {
        api_model *m = preset_model(api_preset_at(i)->name);
        api_cost total = { 0, 0 }, part;
        api_cost_solve(api_model_get(m), &part);
        api_cost_add(&total, &part);
        pde_solution *sol;
        assert_int_equal(pde_solve(api_model_get(m), &sol, NULL), PDE_OK);
        api_cost_props(sol, &part);
        api_cost_add(&total, &part);
        for (int f = 0; f < API_FMT_COUNT; f++) {
            unsigned res[3];
            assert_int_equal(api_res_parse(NULL, (api_format)f, res, NULL), 0);
            api_cost c = total;
            api_cost_output(sol, (api_format)f, res, &part);
            api_cost_add(&c, &part);
            /* fig. 3b's properties (sin 30 pi v: its face u = 1 refined in full, det J's box budget grown to
             * 32000) take about 1 s of an idle core: estimated at 0.7e9, with its msh 0.8e9, under the
             * default budget by 1.25x. */
            if (!(c.work < 0.85e9 && c.bytes < MEMORY))
                fail_msg("%s %s: %.3g units, %.3g bytes", api_preset_at(i)->name,
                         api_format_info_of((api_format)f)->name, c.work, c.bytes);
            assert_true(c.work > 1e4);   /* and not nothing */
        }
        pde_solution_free(sol);
        api_model_free(m);
    }
}

/*
 * The gallery's lofts (tower, blade: sections of 64 points, many modes) must load in the browser:
 * their solve, properties and what the page asks for (the json, the preview's f32, the glb) under
 * the default budget of 1e9 units (pdesolidd's --max-work). The estimate once went past it when the
 * properties' plan took the exact rules of a polynomial axis, which only a solid whose det J keeps
 * its sign gets (core/quad.c). (Their volume meshes at the default res are over it: 422, lower res.)
 */
static void every_loft_preset_should_load_in_the_browser_within_the_default_budget(void **state)
{
    (void)state;
    static const char *const page_formats[] = { "json", "f32", "glb" };
    for (size_t i = 0; i < api_loft_preset_count(); i++) {
        const char *name = api_loft_preset_name(i, NULL);
        api_model *m = preset_model(name);
        assert_non_null(api_model_loft(m));
        api_error err;
        api_cost total = { 0, 0 }, part;
        api_cost_loft(api_model_loft(m), &part);
        api_cost_add(&total, &part);
        pde_solution *sol = NULL;
        assert_int_equal(api_solve(m, &sol, &err), 0);
        api_cost_props(sol, &part);
        api_cost_add(&total, &part);
        for (size_t k = 0; k < sizeof page_formats / sizeof *page_formats; k++) {
            api_format f;
            unsigned res[3];
            assert_int_equal(api_format_parse(page_formats[k], &f, &err), 0);
            assert_int_equal(api_res_parse(NULL, f, res, NULL), 0);
            api_cost c = total;
            api_cost_output(sol, f, res, &part);
            api_cost_add(&c, &part);
            if (!(c.work < 1e9 && c.bytes < MEMORY))
                fail_msg("%s %s: %.3g units, %.3g bytes", name, page_formats[k], c.work, c.bytes);
        }
        pde_solution_free(sol);
        api_model_free(m);
    }
}

/*
 * A loft of two 160-point sections of every harmonic (319 modes, more than core/bound.c's memo serves):
 * its properties took 1.5 to 4.8 s of CPU on the reference machine against an estimate of 0.71 s, so
 * pdesolidd took it and cancelled it at --job-timeout (503, and again on every retry). Its estimate must
 * now be over the default budget (1e9), a 422 before any work.
 */
static void a_loft_of_more_modes_than_the_memo_should_be_over_the_default_budget(void **state)
{
    (void)state;
    enum { N = 160 };
    size_t cap = 64 * 2 * N + 256, len = 0;
    char *doc = malloc(cap);
    assert_non_null(doc);
    len += (size_t)snprintf(doc + len, cap - len, "{\"loft\": {\"pde\": {\"a\": [1, 1, 1], \"b\": [1, 1, 1], "
                                                   "\"c\": [4, 4, 4]}, \"sections\": [");
    for (int k = 0; k < 2; k++) {
        len += (size_t)snprintf(doc + len, cap - len, "%s{\"w\": %d, \"profile\": [", k ? ", " : "", k);
        for (int j = 0; j < N; j++) {
            const double t = 2.0 * M_PI * j / N;
            double r = 1.0;
            for (int m = 2; m < N / 2; m++)   /* every harmonic up to 79, a rough section */
                r += 0.02 / m * cos(m * t + 0.7 * m * m + k);
            len += (size_t)snprintf(doc + len, cap - len, "%s[%.17g, %.17g, %d]", j ? ", " : "", r * cos(t), r * sin(t), k);
        }
        len += (size_t)snprintf(doc + len, cap - len, "]}");
    }
    len += (size_t)snprintf(doc + len, cap - len, "]}}");
    assert_true(len < cap);
    api_error err;
    api_model *m = api_model_parse(doc, len, &err);
    if (!m)
        fail_msg("%s: %s", err.pointer, err.message);
    pde_solution *sol = NULL;
    assert_int_equal(api_solve(m, &sol, &err), 0);
    size_t modes = 0;
    for (int c = 0; c < 3; c++) {
        size_t nm;
        pde_solution_modes(sol, c, &nm);
        modes += nm;
    }
    assert_true(modes > 256);
    api_cost props;
    api_cost_props(sol, &props);
    if (!(props.work >= 1e9))
        fail_msg("%zu modes: properties estimated at %.3g units, under the default budget of 1e9", modes, props.work);
    pde_solution_free(sol);
    api_model_free(m);
    free(doc);
}

/*
 * A model a designer might write: 16 cosine modes in u per component, a solid that folds. Its
 * properties took 6.7 s and pdesolidd refused every request for it (1.06e10 units); they are now
 * bounded by PDE_PROPS_WORK (about 0.5 s here) and fit the default budget of 1e9 with json.
 */
static void a_model_of_sixteen_modes_per_component_should_fit_the_default_budget(void **state)
{
    (void)state;
    pde_bterm b[3][16];
    pde_model m;
    sixteen_mode_model(b, &m);
    api_cost total = { 0, 0 }, part;
    api_cost_solve(&m, &part);
    api_cost_add(&total, &part);
    pde_solution *sol;
    assert_int_equal(pde_solve(&m, &sol, NULL), PDE_OK);
    api_cost_props(sol, &part);
    api_cost_add(&total, &part);
    unsigned res[3];
    assert_int_equal(api_res_parse(NULL, API_FMT_JSON, res, NULL), 0);
    api_cost_output(sol, API_FMT_JSON, res, &part);
    api_cost_add(&total, &part);
    if (!(total.work < 1e9))
        fail_msg("16 modes per component: %.3g units, over the default --max-work of 1e9", total.work);
    pde_solution_free(sol);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(solve_ex_should_stop_at_the_poll_that_asks_and_free_everything),
        cmocka_unit_test(solve_ex_should_match_solve_without_options),
        cmocka_unit_test(properties_should_stop_at_the_poll_that_asks_and_leave_out_untouched),
        cmocka_unit_test(mesh_build_should_stop_at_the_poll_that_asks_and_free_everything),
        cmocka_unit_test(output_open_should_stop_in_the_properties_and_the_mesh_it_computes),
        cmocka_unit_test(output_read_should_sample_a_bounded_number_of_rows_per_call),
        cmocka_unit_test(f32_work_should_grow_eightfold_when_the_resolution_doubles),
        cmocka_unit_test(volume_mesh_estimates_should_not_be_below_their_measured_time),
        cmocka_unit_test(grid_memory_should_grow_with_the_modes),
        cmocka_unit_test(mesh_memory_estimate_should_match_the_blocks_a_build_allocates),
        cmocka_unit_test(eval_work_should_be_linear_in_the_points),
        cmocka_unit_test(heavy_requests_of_the_issue_should_exceed_the_budget),
        cmocka_unit_test(every_preset_in_every_format_should_stay_well_under_the_budget),
        cmocka_unit_test(every_loft_preset_should_load_in_the_browser_within_the_default_budget),
        cmocka_unit_test(a_model_of_sixteen_modes_per_component_should_fit_the_default_budget),
        cmocka_unit_test(a_loft_of_more_modes_than_the_memo_should_be_over_the_default_budget),
    };
    test_filter_from_env();
    return cmocka_run_group_tests(tests, NULL, NULL);
}
