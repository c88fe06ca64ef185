/*
 * test_server.c: pdesolidd over HTTP on loopback, with libcurl. Each test
 * starts the sanitised daemon on a free port ($PDESOLIDD_SAN, build/san/pdesolidd)
 * and stops it with SIGTERM, which must end in exit status 0 (so a leak the
 * sanitiser finds at exit fails the test too).
 */
#include <arpa/inet.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>
#include <cmocka.h>
#include <curl/curl.h>

#include "cache.h"
#include "id.h"
#include "loft.h"
#include "output.h"
#include "support.h"
#include "template.h"

static char dir[] = "/tmp/pdesolid-srv-XXXXXX";

static void start(daemon_t *d, const char *args)
{
    daemon_start(d, dir, args);
}

static void stop(daemon_t *d)
{
    daemon_stop(d);
}

typedef http_reply reply;

/* method, path (with query), body or NULL, one extra header or NULL. */
static reply http(const daemon_t *d, const char *method, const char *path, const char *body, size_t blen,
                  const char *header)
{
    return http_request(NULL, d->base, method, path, body, blen, header, NULL);
}

static reply post(const daemon_t *d, const char *path, const char *body)
{
    return http(d, "POST", path, body, strlen(body), NULL);
}

/* The value of a response header, into out. */
static int header_value(const reply *r, const char *name, char *out, size_t n)
{
    return http_header(r->headers, name, out, n);
}

static void expect_problem(const reply *r, long status, const char *pointer, const char *words)
{
    if (r->status != status)
        fail_msg("status %ld, expected %ld: %s", r->status, status, r->body);
    char ct[128];
    assert_true(header_value(r, "Content-Type", ct, sizeof ct));
    assert_string_equal(ct, "application/problem+json");
    cJSON *p = cJSON_Parse(r->body);
    assert_non_null(p);
    assert_int_equal(cJSON_GetObjectItem(p, "status")->valueint, status);
    if (!strstr(cJSON_GetObjectItem(p, "detail")->valuestring, words))
        fail_msg("detail \"%s\" lacks \"%s\"", cJSON_GetObjectItem(p, "detail")->valuestring, words);
    expect_problem_pointer(p, pointer, r->body);
    cJSON_Delete(p);
}

static pde_solution *local_solve(const char *preset, char *id)
{
    api_model *m = preset_model(preset);
    api_error err;
    pde_solution *s;
    assert_int_equal(api_solve(m, &s, &err), 0);
    if (id)
        api_model_id(api_model_get(m), id, NULL);
    api_model_free(m);
    return s;
}

static long metric(const daemon_t *d, const char *name)
{
    reply r = http(d, "GET", "/metrics", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    char key[128];
    snprintf(key, sizeof key, "\n%s ", name);
    const char *p = strstr(r.body, key);
    long v = p ? atol(p + strlen(key)) : -1;
    free(r.body);
    return v;
}

static int setup(void **state)
{
    (void)state;
    curl_global_init(CURL_GLOBAL_ALL);
    signal(SIGPIPE, SIG_IGN);
    return tmpdir_make(dir);
}

static int teardown(void **state)
{
    (void)state;
    curl_global_cleanup();
    return tmpdir_remove(dir);
}

/* ---- every format, against the core ---- */

static void solve_should_give_every_format_as_the_core_computes_it(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    char id[API_ID_LEN + 1], hid[64];
    pde_solution *sol = local_solve("fig3c", id);
    const char *req = "{\"preset\":\"fig3c\"}";
    /* f32 against pde_eval. */
    reply r = post(&d, "/solve?format=f32&res=5,6,7", req);
    assert_int_equal(r.status, 200);
    assert_true(header_value(&r, "X-Solid-Id", hid, sizeof hid));
    assert_string_equal(hid, id);
    assert_int_equal(r.len, 12 * 5 * 6 * 7);
    float *f = malloc(r.len);
    memcpy(f, r.body, r.len);
    for (int k = 0; k < 7; k++)
        for (int j = 0; j < 6; j++)
            for (int i = 0; i < 5; i++) {
                double x[3];
                pde_eval(sol, i / 4.0, j / 5.0, k / 6.0, x);
                for (int c = 0; c < 3; c++)
                    assert_rel(f[3 * ((k * 6 + j) * 5 + i) + c], x[c], 1e-6, 1);
            }
    /* grid JSON equals the f32. */
    reply g = post(&d, "/solve?format=grid&res=5,6,7", req);
    assert_int_equal(g.status, 200);
    cJSON *gj = cJSON_Parse(g.body);
    assert_non_null(gj);
    const char *comp[3] = { "x", "y", "z" };
    for (int c = 0; c < 3; c++) {
        int i = 0;
        for (cJSON *e = cJSON_GetObjectItem(gj, comp[c])->child; e; e = e->next, i++)
            assert_true((float)e->valuedouble == f[3 * i + c]);
        assert_int_equal(i, 5 * 6 * 7);
    }
    cJSON_Delete(gj);
    free(g.body);
    free(r.body);
    /* json: the id and the closed form. */
    r = post(&d, "/solve", req);
    assert_int_equal(r.status, 200);
    cJSON *j = cJSON_Parse(r.body);
    assert_string_equal(cJSON_GetObjectItem(j, "id")->valuestring, id);
    assert_non_null(cJSON_GetObjectItem(j, "properties"));
    cJSON_Delete(j);
    free(r.body);
    /* glb and gltf through the validator; vts and stl by their size. */
    char cmd[512];
    int n = snprintf(cmd, sizeof cmd, "node tests/node/validate_gltf.mjs");
    const char *mesh[2] = { "glb", "gltf" };
    for (int m = 0; m < 2; m++) {
        char path[160], q[64];
        snprintf(q, sizeof q, "/solve?format=%s&res=20", mesh[m]);
        r = post(&d, q, req);
        assert_int_equal(r.status, 200);
        snprintf(path, sizeof path, "%s/srv.%s", dir, mesh[m]);
        FILE *o = fopen(path, "wb");
        fwrite(r.body, 1, r.len, o);
        fclose(o);
        free(r.body);
        n += snprintf(cmd + n, sizeof cmd - (size_t)n, " %s", path);
    }
    snprintf(cmd + n, sizeof cmd - (size_t)n, " >/dev/null");
    assert_int_equal(system(cmd), 0);
    r = post(&d, "/solve?format=vts&res=4", req);
    assert_int_equal(r.status, 200);
    assert_non_null(strstr(r.body, "<VTKFile type=\"StructuredGrid\""));
    free(r.body);
    r = post(&d, "/solve?format=stl&res=10", req);
    assert_int_equal(r.status, 200);
    uint32_t nt;
    memcpy(&nt, r.body + 80, 4);
    assert_int_equal(r.len, 84 + 50 * (size_t)nt);
    free(r.body);
    /* GET /solids/{id} samples the cached solution again. */
    char path[96];
    snprintf(path, sizeof path, "/solids/%s?format=f32&res=5,6,7", id);
    r = http(&d, "GET", path, NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    assert_memory_equal(r.body, f, 12 * 5 * 6 * 7);
    free(r.body);
    free(f);
    pde_solution_free(sol);
    stop(&d);
}

/* A solid beyond float32's range is a 422 in every format, as the skins have always refused it: fig. 4a with
 * p0 = 1e308 overflows the coordinates themselves (grid wrote nulls, f32 and msh inf and nan, with a 200);
 * with p0 = 1e30 its coordinates (about 1e25) fit, but the products of its derivatives (the skin's normals,
 * det J) do not, so every format that writes those refuses it (obj wrote "vn 0 0 null", msh and vts an inf
 * det J), while grid, f32 and json (doubles) still answer, every number finite. */
static void a_solid_beyond_float32_should_be_a_422_in_every_format_that_would_overflow(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    for (int f = 0; f < API_FMT_COUNT; f++) {
        const char *name = api_format_info_of((api_format)f)->name;
        char path[96];
        snprintf(path, sizeof path, "/solve?format=%s&res=9", name);
        reply r = post(&d, path, "{\"preset\":\"fig4a\",\"params\":{\"p0\":1e308}}");
        if (r.status != 422)
            fail_msg("%s at p0 = 1e308: %ld, not 422", name, r.status);
        expect_problem(&r, 422, NULL, "too large");
        if (f != API_FMT_JSON && !strstr(r.body, "float32"))
            fail_msg("%s at p0 = 1e308: the detail does not name float32: %s", name, r.body);
        free(r.body);
        r = post(&d, path, "{\"preset\":\"fig4a\",\"params\":{\"p0\":1e30}}");
        int answers = f == API_FMT_JSON || f == API_FMT_GRID || f == API_FMT_F32;
        if (!answers) {
            if (r.status != 422)
                fail_msg("%s at p0 = 1e30: %ld, not 422", name, r.status);
            expect_problem(&r, 422, NULL, "float32");
        } else {
            if (r.status != 200)
                fail_msg("%s at p0 = 1e30: %ld, not 200: %s", name, r.status, r.body);
            if (f == API_FMT_F32) {
                assert_int_equal(r.len, 12 * 9 * 9 * 9);
                for (size_t i = 0; i < r.len / 4; i++) {
                    float v;
                    memcpy(&v, r.body + 4 * i, 4);
                    if (!isfinite(v))
                        fail_msg("f32 at p0 = 1e30: value %zu is %g", i, (double)v);
                }
            } else if (strstr(r.body, "null") || !json_strict_valid(r.body, r.len)) {
                fail_msg("%s at p0 = 1e30: not finite JSON: %.300s", name, r.body);
            }
        }
        free(r.body);
    }
    reply r = http(&d, "GET", "/livez", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    free(r.body);
    stop(&d);
}

/* The lines of text that hold what, each checked: it must hold want and not refuse; returns how many there are. */
static int lines_with(const char *text, const char *what, const char *want, const char *refuse)
{
    int n = 0;
    for (const char *at = strstr(text, what); at; at = strstr(at + 1, what), n++) {
        const char *start = at, *end = at + strcspn(at, "\n");
        while (start > text && start[-1] != '\n')
            start--;
        char line[1024];
        snprintf(line, sizeof line, "%.*s", (int)(end - start), start);
        if (!strstr(line, want) || strstr(line, refuse))
            fail_msg("a line on %s says %s or not %s: %s", what, refuse, want, line);
    }
    return n;
}

/* A volume mesh over 2^22 cells is a 413 (api/volmesh.c's API_ERR_LIMIT), once the budgets let the request get so
 * far; docs/API.md said 422, and openapi.yaml's 413 did not list it. */
static void a_volume_mesh_over_its_cell_limit_should_be_the_413_the_docs_say(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--max-work 1e13 --max-mem-mb 100000");
    const char *formats[] = { "msh", "vtu" };
    for (int i = 0; i < 2; i++) {
        char path[64];
        snprintf(path, sizeof path, "/solve?format=%s&res=200", formats[i]);
        reply r = post(&d, path, "{\"preset\":\"fig4a\"}");
        expect_problem(&r, 413, NULL, "over 4194304 cells");
        free(r.body);
    }
    stop(&d);
    char *api = read_file("docs/API.md", NULL);
    assert_non_null(api);
    assert_true(lines_with(api, "2^22 cells", "413", "422") >= 2);   /* Resolution, and Volume meshes */
    free(api);
    char *yaml = read_file("docs/openapi.yaml", NULL), why[400] = "";
    assert_non_null(yaml);
    const char *p413 = strstr(yaml, "413 (a body over --max-body,");
    if (p413)
        snprintf(why, sizeof why, "%.*s", (int)strcspn(p413, ")"), p413);
    free(yaml);
    if (!strstr(why, "cells"))
        fail_msg("openapi.yaml's Problem does not list the volume mesh's cells under 413: %s", why);
}

static void eval_should_agree_with_the_cli(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    reply r = post(&d, "/solve", "{\"preset\":\"fig4a\",\"params\":{\"p0\":41000}}");
    char id[64];
    assert_true(header_value(&r, "X-Solid-Id", id, sizeof id));
    free(r.body);
    const char *pts = "[[0.5,0.25,0.5],[1,0.125,0.75],[0.3,0.7,0.4],[0,0,0],[1,1,1]]";
    char body[256], path[96];
    snprintf(body, sizeof body, "{\"points\":%s,\"derivatives\":true}", pts);
    snprintf(path, sizeof path, "/solids/%s/eval", id);
    r = post(&d, path, body);
    assert_int_equal(r.status, 200);
    char ppath[160], cmd[512];
    snprintf(ppath, sizeof ppath, "%s/pts.json", dir);
    FILE *o = fopen(ppath, "w");
    fputs(pts, o);
    fclose(o);
    snprintf(cmd, sizeof cmd, "%s eval --preset fig4a --param p0=41000 %s > %s/cli.json",
             getenv("PDESOLID") ? getenv("PDESOLID") : "build/pdesolid", ppath, dir);
    assert_int_equal(system(cmd), 0);
    snprintf(ppath, sizeof ppath, "%s/cli.json", dir);
    char *cli = read_file(ppath, NULL);
    cJSON *a = cJSON_Parse(r.body), *b = cJSON_Parse(cli);
    cJSON *vals = cJSON_GetObjectItem(a, "values");
    assert_int_equal(cJSON_GetArraySize(vals), 5);
    for (int i = 0; i < 5; i++)
        for (int c = 0; c < 3; c++)
            assert_true(cJSON_GetArrayItem(cJSON_GetArrayItem(vals, i), c)->valuedouble ==
                        cJSON_GetArrayItem(cJSON_GetArrayItem(b, i), c)->valuedouble);
    assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(a, "dw")), 5);
    cJSON_Delete(a);
    cJSON_Delete(b);
    free(cli);
    free(r.body);
    stop(&d);
}

/* ---- the cache ---- */

static void cache_hits_misses_and_evictions_should_show_in_metrics(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--cache-mb 1");
    char first[64] = "", body[128];
    int n = 0;
    /* Distinct solids until the 1 MiB bound evicts one (a few hundred). */
    while (metric(&d, "pdesolid_cache_evictions_total") == 0) {
        assert_true(n < 5000);
        for (int k = 0; k < 50; k++, n++) {
            snprintf(body, sizeof body, "{\"preset\":\"fig3d\",\"params\":{\"r0\":%d}}", n + 1);
            reply r = post(&d, "/solve?format=f32&res=2", body);
            assert_int_equal(r.status, 200);
            if (n == 0)
                header_value(&r, "X-Solid-Id", first, sizeof first);
            free(r.body);
        }
    }
    assert_int_equal(metric(&d, "pdesolid_cache_misses_total"), n);
    assert_true(metric(&d, "pdesolid_cache_bytes") <= 1 << 20);
    /* The first was evicted: 404 for its id, and a miss when it is solved again. */
    char path[96];
    snprintf(path, sizeof path, "/solids/%s", first);
    reply r = http(&d, "GET", path, NULL, 0, NULL);
    expect_problem(&r, 404, NULL, "evicted");
    free(r.body);
    /* The last one again: answered from the kept response; at another res, from the cached solution. */
    long hits = metric(&d, "pdesolid_cache_hits_total"), rhits = metric(&d, "pdesolid_response_cache_hits_total");
    r = post(&d, "/solve?format=f32&res=2", body);
    assert_int_equal(r.status, 200);
    free(r.body);
    assert_int_equal(metric(&d, "pdesolid_response_cache_hits_total"), rhits + 1);
    assert_int_equal(metric(&d, "pdesolid_cache_hits_total"), hits);
    r = post(&d, "/solve?format=f32&res=3", body);
    assert_int_equal(r.status, 200);
    assert_int_equal(r.len, 12 * 27);
    free(r.body);
    assert_int_equal(metric(&d, "pdesolid_cache_hits_total"), hits + 1);
    stop(&d);
}

typedef struct {
    const daemon_t *d;
    long status;
} same_arg;

static void *same_request(void *arg)
{
    same_arg *a = arg;
    reply r = post(a->d, "/solve?format=glb&res=200", "{\"preset\":\"fig3b\",\"params\":{\"r0\":0.77}}");
    a->status = r.status;
    free(r.body);
    return NULL;
}

/* A solve that blocks until released, then reports itself cancelled (its request's deadline, or its client
 * gone): what a request waiting on the same id must not take for its own answer. */
typedef struct {
    pthread_mutex_t m;
    pthread_cond_t c;
    int entered, released, calls;
    srv_cache *cache;
    srv_entry *e;
    api_error err;
    int hit;
} cancel_gate;

static int solve_then_cancelled(void *arg, pde_solution **out, api_error *err)
{
    (void)out;
    cancel_gate *g = arg;
    pthread_mutex_lock(&g->m);
    g->entered = 1;
    pthread_cond_broadcast(&g->c);
    while (!g->released)
        pthread_cond_wait(&g->c, &g->m);
    pthread_mutex_unlock(&g->m);
    return api_fail_cancelled(err);
}

static int solve_fig4a(void *arg, pde_solution **out, api_error *err)
{
    (void)err;
    ((cancel_gate *)arg)->calls++;
    *out = preset_solution("fig4a");
    return 0;
}

static void *get_cancelled(void *arg)
{
    cancel_gate *g = arg;
    g->e = srv_cache_get(g->cache, "0123456789abcdef0123456789abcdef", solve_then_cancelled, g, &g->hit, &g->err);
    return NULL;
}

static void *solve_waiting(void *arg)
{
    cancel_gate *g = arg;
    g->e = srv_cache_get(g->cache, "0123456789abcdef0123456789abcdef", solve_fig4a, g, &g->hit, &g->err);
    return NULL;
}

/* A GET /solids/{id}: it cannot solve, only wait. */
static void *find_waiting(void *arg)
{
    cancel_gate *g = arg;
    g->e = srv_cache_find(g->cache, "0123456789abcdef0123456789abcdef", &g->err);
    return NULL;
}

/* Starts a's solve of the id (through the cache), which blocks until cancel_gate_release(a). */
static void cancel_gate_start(cancel_gate *a, pthread_t *t)
{
    *a = (cancel_gate){ .m = PTHREAD_MUTEX_INITIALIZER, .c = PTHREAD_COND_INITIALIZER };
    a->cache = srv_cache_create(64u << 20);
    assert_non_null(a->cache);
    assert_int_equal(pthread_create(t, NULL, get_cancelled, a), 0);
    pthread_mutex_lock(&a->m);
    while (!a->entered)
        pthread_cond_wait(&a->c, &a->m);
    pthread_mutex_unlock(&a->m);
}

/* Until the cache has counted hits: each request that finds the entry being solved counts its hit under the
 * lock, as it starts to wait. */
static void wait_for_hits(srv_cache *c, unsigned long long hits)
{
    srv_cache_stats cs = { 0 };
    for (int i = 0; i < 5000 && cs.hits < hits; i++) {
        srv_cache_stats_get(c, &cs);
        if (cs.hits < hits)
            usleep(1000);
    }
    assert_int_equal(cs.hits, hits);
}

/* Starts w's request (fn: solve_waiting or find_waiting) on a's entry, and waits until it waits there: until
 * the cache counts the hits it then has. */
static void waiter_start(const cancel_gate *a, cancel_gate *w, void *(*fn)(void *), pthread_t *t,
                         unsigned long long hits)
{
    *w = (cancel_gate){ .cache = a->cache };
    assert_int_equal(pthread_create(t, NULL, fn, w), 0);
    wait_for_hits(a->cache, hits);
}

static void expect_cache_stats(srv_cache *c, unsigned long long hits, unsigned long long misses, size_t entries)
{
    srv_cache_stats cs;
    srv_cache_stats_get(c, &cs);
    assert_int_equal(cs.hits, hits);
    assert_int_equal(cs.misses, misses);
    assert_int_equal(cs.entries, entries);
}

static void cancel_gate_release(cancel_gate *a, pthread_t t)
{
    pthread_mutex_lock(&a->m);
    a->released = 1;
    pthread_cond_broadcast(&a->c);
    pthread_mutex_unlock(&a->m);
    pthread_join(t, NULL);
    assert_null(a->e);
    assert_int_equal(a->err.status, API_ERR_CANCELLED);
}

/* A request that waits for another's solve of the same id, which is then cancelled for that request alone,
 * solves for itself: before, it got the cancellation, and answered 503 "ran past its deadline" with no time
 * spent, so that one client closing its connection could fail the others' identical requests. */
static void a_request_waiting_on_a_cancelled_solve_should_solve_for_itself(void **state)
{
    (void)state;
    cancel_gate a, b;
    pthread_t t, tb;
    cancel_gate_start(&a, &t);
    waiter_start(&a, &b, solve_waiting, &tb, 1);   /* b finds a's entry being solved and waits on it */
    cancel_gate_release(&a, t);
    pthread_join(tb, NULL);
    if (!b.e)
        fail_msg("the waiting request failed with a's cancellation: %s", b.err.message);
    assert_int_equal(b.calls, 1);
    assert_int_equal(b.hit, 0);
    expect_cache_stats(a.cache, 0, 2, 1);
    srv_cache_release(a.cache, b.e);
    srv_cache_destroy(a.cache);
}

/* A GET /solids/{id} (or an eval) that waits for a /solve of the id, which is then cancelled for its own
 * request, while another /solve of the same model waits too: that one takes the solve over, and the GET gets
 * its solid. Before, the GET answered 404 "never solved here" for an id that was being solved. */
static void a_get_waiting_on_a_cancelled_solve_should_get_the_solve_that_takes_it_over(void **state)
{
    (void)state;
    cancel_gate a, b, c;
    pthread_t t, tb, tc;
    cancel_gate_start(&a, &t);
    waiter_start(&a, &b, find_waiting, &tb, 1);
    waiter_start(&a, &c, solve_waiting, &tc, 2);
    cancel_gate_release(&a, t);
    pthread_join(tb, NULL);
    pthread_join(tc, NULL);
    if (!b.e)
        fail_msg("the GET waiting on a cancelled solve found nothing (a 404), while another request re-solved it");
    assert_ptr_equal(b.e, c.e);
    assert_int_equal(c.calls, 1);
    assert_int_equal(c.hit, 0);
    expect_cache_stats(a.cache, 1, 2, 1);
    srv_cache_release(a.cache, b.e);
    srv_cache_release(a.cache, c.e);
    srv_cache_destroy(a.cache);
}

/* The same with no request there that can solve: the GET learns why (a 503 "stopped before it ended"), not a
 * 404 "never solved here"; and the failure is not cached. */
static void a_get_waiting_on_a_cancelled_solve_no_one_takes_over_should_learn_it_was_cancelled(void **state)
{
    (void)state;
    cancel_gate a, b;
    pthread_t t, tb;
    cancel_gate_start(&a, &t);
    waiter_start(&a, &b, find_waiting, &tb, 1);
    cancel_gate_release(&a, t);
    pthread_join(tb, NULL);
    assert_null(b.e);
    assert_int_equal(b.err.status, API_ERR_CANCELLED);
    expect_cache_stats(a.cache, 1, 1, 0);
    api_error err;
    assert_null(srv_cache_find(a.cache, "0123456789abcdef0123456789abcdef", &err));
    assert_int_equal(err.status, API_ERR_NOT_FOUND);
    srv_cache_destroy(a.cache);
}

static void concurrent_identical_requests_should_solve_once(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--threads 4");
    enum { N = 16 };
    pthread_t t[N];
    same_arg a[N];
    for (int i = 0; i < N; i++)
        a[i] = (same_arg){ &d, 0 };
    threads_start(t, N, same_request, a, sizeof *a);
    threads_join(t, N);
    for (int i = 0; i < N; i++)
        assert_int_equal(a[i].status, 200);
    /* One solve; every other request found the solution, or the whole response, already made. */
    assert_int_equal(metric(&d, "pdesolid_cache_misses_total"), 1);
    assert_int_equal(metric(&d, "pdesolid_cache_hits_total") + metric(&d, "pdesolid_response_cache_hits_total"), N - 1);
    stop(&d);
}

/* Server-Timing's solve says "cached" whenever the cache gave the solution: a POST /solve of a solid solved
 * before and a GET /solids/{id} alike (the GET never said so: review); not a new solve, nor an eval, whose
 * solve is the evaluation. Each request is a new one for the response cache, so a job answers it. */
static void server_timing_should_say_cached_wherever_the_cache_gave_the_solution(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    static const char body[] = "{\"preset\":\"fig2a\"}";
    char id[API_ID_LEN + 1], path[128], timing[512];
    reply r = post(&d, "/solve", body);
    assert_int_equal(r.status, 200);
    assert_true(header_value(&r, "X-Solid-Id", id, sizeof id));
    free(r.body);
    const struct {
        const char *method, *path, *body;   /* %s: the id */
        int cached;
    } cases[] = {
        { "POST", "/solve?format=grid&res=3", body, 1 },
        { "GET", "/solids/%s", NULL, 1 },
        { "GET", "/solids/%s?format=glb&res=5", NULL, 1 },
        { "POST", "/solids/%s/eval", "{\"points\":[[0.5,0.5,0.5]]}", 0 },
        { "POST", "/solve", "{\"preset\":\"fig2b\"}", 0 },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        snprintf(path, sizeof path, cases[i].path, id);
        const char *b = cases[i].body;
        r = http(&d, cases[i].method, path, b, b ? strlen(b) : 0, NULL);
        if (r.status != 200)
            fail_msg("%s %s: %ld %s", cases[i].method, path, r.status, r.body);
        if (!header_value(&r, "Server-Timing", timing, sizeof timing))
            fail_msg("%s %s: no Server-Timing", cases[i].method, path);
        const char *solve = strstr(timing, "solve;dur="), *next = solve ? strchr(solve, ',') : NULL;
        assert_non_null(next);
        const char *desc = strstr(solve, ";desc=\"cached\"");
        const int said = desc && desc < next;
        if (said != cases[i].cached)
            fail_msg("%s %s: Server-Timing %s, want the solve %s", cases[i].method, path, timing,
                     cases[i].cached ? "cached" : "not cached");
        free(r.body);
    }
    stop(&d);
}

/* A gltf or glb at res 3 along v, around which a loft closes into a loop, is refused before its properties
 * (8 ms for the vase, optimised), by the skin's own test of the loop (api_mesh_check_loops): they were computed
 * first, to be thrown away (QA). 4 along v is a skin, its properties computed then. */
static void a_skin_around_a_loop_at_res_3_should_be_refused_before_the_properties(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    static const char *const refused[] = { "/solve?format=glb&res=3", "/solve?format=gltf&res=16,3,16" };
    char timing[512];
    for (size_t i = 0; i < sizeof refused / sizeof *refused; i++) {
        reply r = post(&d, refused[i], "{\"preset\":\"vase\"}");
        expect_problem(&r, 422, NULL, "take at least 4 along v");
        assert_true(header_value(&r, "Server-Timing", timing, sizeof timing));
        if (!strstr(timing, "props;dur=0.000"))
            fail_msg("%s: the properties were computed before the refusal: %s", refused[i], timing);
        free(r.body);
    }
    reply r = post(&d, "/solve?format=glb&res=3,4,3", "{\"preset\":\"vase\"}");
    assert_int_equal(r.status, 200);
    assert_true(header_value(&r, "Server-Timing", timing, sizeof timing));
    if (strstr(timing, "props;dur=0.000"))
        fail_msg("the glb's properties took no time: %s", timing);
    free(r.body);
    stop(&d);
}

static void etag_with_if_none_match_should_give_304(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    reply r = post(&d, "/solve?format=glb&res=8", "{\"preset\":\"fig2a\"}");
    assert_int_equal(r.status, 200);
    char etag[128], inm[160];
    assert_true(header_value(&r, "ETag", etag, sizeof etag));
    assert_true(etag[0] == '"');
    free(r.body);
    snprintf(inm, sizeof inm, "If-None-Match: %s", etag);
    const char *body = "{\"preset\":\"fig2a\"}";
    r = http(&d, "POST", "/solve?format=glb&res=8", body, strlen(body), inm);
    assert_int_equal(r.status, 304);
    assert_int_equal(r.len, 0);
    free(r.body);
    r = http(&d, "POST", "/solve?format=glb&res=9", body, strlen(body), inm);
    assert_int_equal(r.status, 200);
    free(r.body);
    /* A representation served before is not built again to say so: a glb too large for the response cache
     * (2.4 MB) revalidates without its output (it cost a whole build before: QA). */
    r = post(&d, "/solve?format=glb&res=128", "{\"preset\":\"fig4a\"}");
    assert_int_equal(r.status, 200);
    assert_true(r.len > (1u << 20));
    char big[128], bigm[160], timing[256];
    assert_true(header_value(&r, "ETag", big, sizeof big));
    free(r.body);
    snprintf(bigm, sizeof bigm, "If-None-Match: %s", big);
    r = http(&d, "POST", "/solve?format=glb&res=128", "{\"preset\":\"fig4a\"}", 18, bigm);
    assert_int_equal(r.status, 304);
    assert_true(header_value(&r, "Server-Timing", timing, sizeof timing));
    if (!strstr(timing, "output;dur=0.000"))
        fail_msg("the 304 built its output: %s", timing);
    free(r.body);
    /* Only a representation the request would get is "not modified": the checks come first (a QA probe got
     * 304s for outputs that are 422s, with the ETag they would carry or with *). */
    const struct {
        const char *path, *body;
    } refused[] = {
        { "/solve?format=stl&res=2", "{\"preset\":\"fig4a\"}" },                           /* no triangle */
        { "/solve?format=glb&res=512", "{\"preset\":\"fig4a\"}" },                         /* a limit */
    };
    for (size_t i = 0; i < sizeof refused / sizeof *refused; i++) {
        r = post(&d, refused[i].path, refused[i].body);
        long want = r.status;
        assert_true(want >= 400);
        free(r.body);
        const char *path = refused[i].path;
        const char *fmt = strstr(path, "format=") + 7;
        const char *res = strstr(path, "res=") + 4;
        char e[200];
        /* the ETag it would carry: its id from a 200 of the same model in json */
        r = post(&d, "/solve", refused[i].body);
        assert_int_equal(r.status, 200);
        char jt[128];
        assert_true(header_value(&r, "ETag", jt, sizeof jt));
        free(r.body);
        int n = atoi(res);
        snprintf(e, sizeof e, "If-None-Match: \"%.*s.%.*s.%dx%dx%d\"", API_ID_LEN, jt + 1, (int)(strchr(fmt, '&') - fmt), fmt,
                 n, n, n);
        const char *conds[] = { e, "If-None-Match: *" };
        for (int k = 0; k < 2; k++) {
            r = http(&d, "POST", path, refused[i].body, strlen(refused[i].body), conds[k]);
            if (r.status != want)
                fail_msg("%s with %s: %ld, want %ld", path, conds[k], r.status, want);
            free(r.body);
        }
    }
    stop(&d);
}

/* ---- load ---- */

typedef struct {
    const daemon_t *d;
    int k, ok;
} client_arg;

static void *client(void *arg)
{
    client_arg *a = arg;
    char body[128], id[API_ID_LEN + 1];
    snprintf(body, sizeof body, "{\"preset\":\"fig4%c\"}", 'a' + a->k % 24);
    reply r = post(a->d, "/solve?format=f32&res=3", body);
    char name[8];
    snprintf(name, sizeof name, "fig4%c", 'a' + a->k % 24);
    const api_preset *ps = api_preset_find(name);
    api_params p;
    api_error err;
    api_preset_params(ps, &p);
    api_model *m = api_template_expand(api_preset_template(ps), &p, &err);
    pde_solution *sol;
    api_solve(m, &sol, &err);
    api_model_id(api_model_get(m), id, NULL);
    api_model_free(m);
    a->ok = r.status == 200 && r.len == 12 * 27;
    for (int i = 0; a->ok && i < 27; i++) {
        double x[3];
        pde_eval(sol, (i % 3) / 2.0, (i / 3 % 3) / 2.0, (i / 9) / 2.0, x);
        for (int c = 0; c < 3; c++)
            a->ok &= close_rel(((float *)r.body)[3 * i + c], x[c], 1e-6, 1);
    }
    char hid[64] = "";
    header_value(&r, "X-Solid-Id", hid, sizeof hid);
    a->ok &= !strcmp(hid, id);
    pde_solution_free(sol);
    free(r.body);
    return NULL;
}

static void sixty_four_concurrent_clients_should_all_get_correct_answers(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    enum { N = 64 };
    pthread_t t[N];
    client_arg a[N];
    for (int i = 0; i < N; i++)
        a[i] = (client_arg){ &d, i, 0 };
    threads_start(t, N, client, a, sizeof *a);
    threads_join(t, N);
    for (int i = 0; i < N; i++)
        if (!a[i].ok)
            fail_msg("client %d got a wrong answer", i);
    stop(&d);
}

typedef struct {
    const daemon_t *d;
    int k;
    long status;
    char retry[16];
} heavy_arg;

static void *heavy(void *arg)
{
    heavy_arg *a = arg;
    char body[128];
    snprintf(body, sizeof body, "{\"preset\":\"fig3b\",\"params\":{\"r0\":%d}}", a->k + 2);
    reply r = post(a->d, "/solve?format=glb&res=400", body);
    a->status = r.status;
    header_value(&r, "Retry-After", a->retry, sizeof a->retry);
    if (r.status == 503)
        expect_problem(&r, 503, NULL, "busy");
    free(r.body);
    return NULL;
}

static void a_full_queue_should_give_503_with_retry_after(void **state)
{
    (void)state;
    daemon_t d;
    /* glb res 400 of fig3b is over the default budgets: lift them, for jobs that take a while. */
    start(&d, "--threads 1 --queue 1 --max-work 1e12 --max-mem-mb 4096 --job-timeout 60");
    enum { N = 8 };
    pthread_t t[N];
    heavy_arg a[N];
    for (int i = 0; i < N; i++)
        a[i] = (heavy_arg){ &d, i, 0, "" };
    threads_start(t, N, heavy, a, sizeof *a);
    threads_join(t, N);
    int busy = 0, ok = 0;
    for (int i = 0; i < N; i++) {
        if (a[i].status == 503) {
            busy++;
            assert_string_equal(a[i].retry, "1");
        } else if (a[i].status == 200) {
            ok++;
        } else {
            fail_msg("status %ld", a[i].status);
        }
    }
    assert_true(busy > 0);
    assert_true(ok > 0);
    reply r = http(&d, "GET", "/livez", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    free(r.body);
    stop(&d);
}

/* A row of heavy requests must not hold up a light one (a QA probe: 20 distinct heavy solves, and an f32 of
 * res 2 waited 16.6 s behind them). The light request finishes before the third of four heavy ones, as no
 * queue in front of all threads would let it; and past --heavy-queue, heavy ones get a prompt 503. */
typedef struct {
    const daemon_t *d;
    int k;
    long status;
    atomic_int *done;
    int order;
    char retry[16];
} lane_arg;

static void *lane_client(void *arg)
{
    lane_arg *a = arg;
    char body[128];
    if (a->k < 0)
        snprintf(body, sizeof body, "{\"preset\":\"fig1a\"}");
    else
        snprintf(body, sizeof body, "{\"preset\":\"fig3c\",\"params\":{\"h0\":%d}}", a->k + 3);
    reply r = post(a->d, a->k < 0 ? "/solve?format=f32&res=2" : "/solve", body);
    a->order = atomic_fetch_add(a->done, 1);
    a->status = r.status;
    header_value(&r, "Retry-After", a->retry, sizeof a->retry);
    if (r.status == 503)
        expect_problem(&r, 503, NULL, "--heavy-queue");
    free(r.body);
    return NULL;
}

static void a_light_request_should_not_wait_behind_heavy_ones(void **state)
{
    (void)state;
    for (int round = 0; round < 2; round++) {
        daemon_t d;
        /* fig3c's json is some 1e8 units: heavy at 1e7; round 1 lets one heavy request wait */
        start(&d, round ? "--threads 2 --heavy-work 1e7 --heavy-queue 1" : "--threads 2 --heavy-work 1e7");
        enum { N = 6 };
        const int heavies = round ? N : 4;
        pthread_t t[N + 1];
        lane_arg a[N + 1];
        atomic_int done = 0;
        for (int i = 0; i < heavies; i++)
            a[i] = (lane_arg){ &d, i, 0, &done, -1, "" };
        threads_start(t, heavies, lane_client, a, sizeof *a);
        usleep(150000);   /* all of them in */
        a[heavies] = (lane_arg){ &d, -1, 0, &done, -1, "" };
        threads_start(t + heavies, 1, lane_client, a + heavies, sizeof *a);
        threads_join(t, heavies + 1);
        assert_int_equal(a[heavies].status, 200);
        int busy = 0;
        for (int i = 0; i < heavies; i++) {
            if (a[i].status == 503) {
                busy++;
                assert_string_equal(a[i].retry, "1");
            } else if (a[i].status != 200)
                fail_msg("heavy %d: status %ld", i, a[i].status);
        }
        if (round == 0) {
            assert_int_equal(busy, 0);
            if (a[heavies].order > 2)
                fail_msg("the light request finished after %d of %d heavy ones", a[heavies].order, heavies);
        } else if (busy == 0 || busy > heavies - 2)
            fail_msg("%d of %d heavy requests were refused (--heavy-queue 1, 2 threads)", busy, heavies);
        stop(&d);
    }
}

/* An eval estimated at --heavy-work or more, and a /solve body big enough to be a big loft (its parse and
 * fit are heavy before any estimate of them is known), run apart like /solve's heavy outputs (QA 13: two
 * clients evaluating 12k points, or posting 1 MB lofts, held up a light request for 1.2 s in the queue).
 * Counted in pdesolid_heavy_total, not timed. A light eval and a small body do not go there. */
static void heavy_evals_and_big_bodies_should_run_apart(void **state)
{
    (void)state;
    daemon_t d;
    /* 3e6: below the estimate of 5000 points, and of the padded body's parse (1.2e6 by api_cost_parse) */
    start(&d, "--heavy-work 3e6");
    reply r = post(&d, "/solve?format=f32&res=2", "{\"preset\":\"fig1a\"}");
    assert_int_equal(r.status, 200);
    char id[64], path[96];
    assert_true(header_value(&r, "X-Solid-Id", id, sizeof id));
    free(r.body);
    snprintf(path, sizeof path, "/solids/%s/eval", id);
    long h = metric(&d, "pdesolid_heavy_total");
    assert_true(h >= 0);
    r = post(&d, path, "{\"points\":[[0.5,0.5,0.5]]}");
    assert_int_equal(r.status, 200);
    free(r.body);
    assert_int_equal(metric(&d, "pdesolid_heavy_total"), h);
    enum { N = 5000 };
    size_t cap = 64 + N * 40, len = 0;
    char *body = malloc(cap);
    len += (size_t)snprintf(body + len, cap - len, "{\"derivatives\":true,\"points\":[");
    for (int i = 0; i < N; i++)
        len += (size_t)snprintf(body + len, cap - len, "%s[%.6f,0.25,0.75]", i ? "," : "", (double)i / N);
    len += (size_t)snprintf(body + len, cap - len, "]}");
    r = http(&d, "POST", path, body, len, NULL);
    assert_int_equal(r.status, 200);
    cJSON *a = cJSON_Parse(r.body);
    assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(a, "values")), N);
    cJSON_Delete(a);
    free(r.body);
    free(body);
    assert_int_equal(metric(&d, "pdesolid_heavy_total"), h + 1);
    /* fig1a padded to 100 KB: 9.2e6 units of parse and fit at 90 a byte; answered as the plain one is */
    size_t big = 100 << 10;
    body = malloc(big);
    memset(body, ' ', big);
    memcpy(body, "{\"preset\":\"fig1a\"}", 18);
    r = http(&d, "POST", "/solve?format=f32&res=2", body, big, NULL);
    assert_int_equal(r.status, 200);
    char id2[64];
    assert_true(header_value(&r, "X-Solid-Id", id2, sizeof id2));
    assert_string_equal(id2, id);
    free(r.body);
    free(body);
    assert_int_equal(metric(&d, "pdesolid_heavy_total"), h + 2);
    stop(&d);
}

/* ---- bad input ---- */

static void bad_requests_should_get_problems_and_the_daemon_should_keep_serving(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--max-points 10");
    size_t big = 2 << 20;
    char *huge = malloc(big);
    memset(huge, ' ', big);
    reply r = http(&d, "POST", "/solve", huge, big, NULL);
    expect_problem(&r, 413, NULL, "limit of 1048576 bytes");
    assert_non_null(strstr(r.body, "if this is a loft"));
    free(r.body);
    /* The loft hint is /solve's: an eval's body is points (QA 13) */
    r = http(&d, "POST", "/solids/0123456789abcdef0123456789abcdef/eval", huge, big, NULL);
    expect_problem(&r, 413, NULL, "limit of 1048576 bytes");
    assert_null(strstr(r.body, "loft"));
    free(r.body);
    free(huge);
    r = post(&d, "/solve", "{\"pde\": [1, 2");
    expect_problem(&r, 400, "/pde", "not valid JSON");
    free(r.body);
    r = post(&d, "/solve", "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-1,-1,-1]},\"boundary\":{\"x\":[{\"u\":{\"tan\":1}}]}}");
    expect_problem(&r, 422, "/boundary/x/0/u/tan", "unknown key \"tan\"");
    free(r.body);
    r = post(&d, "/solve", "{\"preset\":\"fig4a\",\"params\":{\"c\":[-1,-1,0]}}");
    expect_problem(&r, 422, "/params/c/2", "not fourth order");
    free(r.body);
    r = post(&d, "/solve?format=grid&res=100000", "{\"preset\":\"fig4a\"}");   /* json takes any res */
    expect_problem(&r, 422, NULL, "limit of 4096");
    free(r.body);
    r = post(&d, "/solve?format=dae", "{\"preset\":\"fig4a\"}");
    expect_problem(&r, 422, NULL, "is not a format");
    free(r.body);
    char *deep = malloc(5001);
    memset(deep, '[', 5000);
    deep[5000] = '\0';
    r = post(&d, "/solve", deep);
    expect_problem(&r, 413, NULL, "deeper than 64");
    free(r.body);
    free(deep);
    r = post(&d, "/solve", "{\"preset\":\"fig4a\"}");
    char id[64], path[96];
    header_value(&r, "X-Solid-Id", id, sizeof id);
    free(r.body);
    snprintf(path, sizeof path, "/solids/%s/eval", id);
    r = post(&d, path, "{\"points\":[[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0]]}");
    expect_problem(&r, 413, "/points", "more than 10 points");
    free(r.body);
    r = post(&d, path, "{\"points\":[[0,0]]}");
    expect_problem(&r, 422, "/points/0", "three numbers");
    free(r.body);
    r = http(&d, "GET", "/nowhere", NULL, 0, NULL);
    expect_problem(&r, 404, NULL, "no such resource");
    free(r.body);
    r = http(&d, "DELETE", "/solve", NULL, 0, NULL);
    expect_problem(&r, 405, NULL, "DELETE is not allowed");
    char allow[64];
    assert_true(header_value(&r, "Allow", allow, sizeof allow));
    free(r.body);
    r = http(&d, "DELETE", "/livez", NULL, 0, NULL);   /* a GET route takes HEAD too, and says so */
    expect_problem(&r, 405, NULL, "use GET, HEAD, OPTIONS");
    assert_true(header_value(&r, "Allow", allow, sizeof allow));
    assert_string_equal(allow, "GET, HEAD, OPTIONS");
    free(r.body);
    r = http(&d, "GET", "/solids/xyz", NULL, 0, NULL);
    expect_problem(&r, 404, NULL, "no solid");
    free(r.body);
    r = http(&d, "GET", "/presets/fig9q", NULL, 0, NULL);
    expect_problem(&r, 404, NULL, "no preset");
    free(r.body);
    r = http(&d, "GET", "/livez", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    free(r.body);
    stop(&d);
}

static int dial(int port)
{
    int fd = raw_dial(port);
    assert_true(fd >= 0);
    return fd;
}

/* A loft document through POST /solve: solved, cached under its id, outputs; a bad one named. */
static void a_loft_should_solve_and_a_bad_one_get_its_pointer(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    const char *loft = "{\"loft\": {\"pde\": {\"a\": [1, 1, 1], \"b\": [1, 1, 1], \"c\": [2, 2, 2]}, \"sections\": ["
                       "{\"w\": 0, \"profile\": [[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]]},"
                       "{\"w\": 0.5, \"profile\": [[1.5, 0, 1], [0, 0.8, 1], [-1.5, 0, 1], [0, -0.8, 1]]},"
                       "{\"w\": 1, \"profile\": [[1, 0, 2], [0, 1, 2], [-1, 0, 2], [0, -1, 2]]}]}}";
    reply r = post(&d, "/solve", loft);
    assert_int_equal(r.status, 200);
    cJSON *j = cJSON_Parse(r.body);
    assert_non_null(j);
    const char *id = cJSON_GetStringValue(cJSON_GetObjectItem(j, "id"));
    assert_non_null(id);
    /* The section at w = 0.5 through the server's eval: u = 1, v = 1/4 is the point (0, 0.8, 1). */
    char path[128];
    snprintf(path, sizeof path, "/solids/%s/eval", id);
    reply e = post(&d, path, "{\"points\": [[1, 0.25, 0.5]]}");
    assert_int_equal(e.status, 200);
    cJSON *ej = cJSON_Parse(e.body), *p0 = cJSON_GetArrayItem(cJSON_GetObjectItem(ej, "values"), 0);
    assert_non_null(p0);
    assert_true(fabs(cJSON_GetArrayItem(p0, 1)->valuedouble - 0.8) < 1e-12);
    assert_true(fabs(cJSON_GetArrayItem(p0, 2)->valuedouble - 1) < 1e-12);
    snprintf(path, sizeof path, "/solids/%s?format=glb", id);
    reply g = http(&d, "GET", path, NULL, 0, NULL);
    assert_int_equal(g.status, 200);
    cJSON_Delete(j);
    cJSON_Delete(ej);
    free(r.body);
    free(e.body);
    free(g.body);
    r = post(&d, "/solve", "{\"loft\": {\"pde\": {\"a\": [1, 1, 1], \"b\": [1, 1, 1], \"c\": [2, 2, 2]}, \"sections\": ["
                           "{\"w\": 0, \"profile\": [[1, 0, 0], [0, 1, 0]]}, {\"w\": 1, \"profile\": [[1, 0, 1], [0, 1, 1], [0, 0, 1]]}]}}");
    expect_problem(&r, 422, "/loft/sections/0/profile", "at least 3");
    free(r.body);
    r = http(&d, "GET", "/livez", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    free(r.body);
    stop(&d);
}

static void two_content_lengths_and_stalled_clients_should_be_refused(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--timeout 1");
    char buf[8192];
    int fd = dial(d.port);
    const char *req = "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: 18\r\nContent-Length: 5\r\n\r\n"
                      "{\"preset\":\"fig4a\"}";
    send(fd, req, strlen(req), 0);
    long n = raw_read_to_close(fd, buf, sizeof buf, 10);
    close(fd);
    assert_true(n > 0);
    assert_true(strstr(buf, " 400 ") != NULL);
    /* Half the headers, then silence: closed after the one-second timeout. */
    fd = dial(d.port);
    const char *half = "GET /livez HTTP/1.1\r\nHost: localhost\r\n";
    send(fd, half, strlen(half), 0);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    n = raw_read_to_close(fd, buf, sizeof buf, 10);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    close(fd);
    assert_int_equal(n, 0);
    double waited = (t1.tv_sec - t0.tv_sec) + (t1.tv_nsec - t0.tv_nsec) * 1e-9;
    assert_true(waited >= 0.5 && waited < 8);
    reply r = http(&d, "GET", "/livez", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    free(r.body);
    stop(&d);
}

/* ---- shutdown ---- */

static void sigterm_should_let_a_request_in_flight_complete_and_answer_new_ones_503(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--max-work 1e12 --max-mem-mb 4096 --job-timeout 60");
    heavy_arg a = { &d, 99, 0, "" };
    pthread_t t;
    pthread_create(&t, NULL, heavy, &a);
    /* Wait until the job is on a solver thread, then SIGTERM. */
    for (int i = 0; i < 400 && metric(&d, "pdesolid_queue_depth") < 1; i++)
        usleep(5000);
    kill(d.pid, SIGTERM);
    /* While the job finishes, a new connection is answered, not refused: 503 with Retry-After, which a
     * balancer retries on another replica (libmicrohttpd's quiesce, which refused it, races its own polling
     * threads and can abort the daemon). */
    for (int i = 0; i < 400; i++) {
        char *text = read_file(d.log, NULL);
        int seen = text && strstr(text, "SIGTERM: finishing the requests in flight");
        free(text);
        if (seen)
            break;
        usleep(5000);
    }
    reply late = http(&d, "GET", "/livez", NULL, 0, NULL);
    expect_problem(&late, 503, NULL, "shutting down");
    char retry[16] = "";
    assert_true(header_value(&late, "Retry-After", retry, sizeof retry));
    assert_string_equal(retry, "1");
    free(late.body);
    /* A new request whose body is slow to come gets its 503 at once, not after the body (up to 5 s of draining
     * that held the exit back). */
    static const char slow[] = "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: 5\r\n\r\n";
    raw_reply rr = raw_request(d.port, slow, sizeof slow - 1, 2000);
    assert_int_equal(rr.status, 503);
    assert_false(rr.timed_out);
    raw_reply_free(&rr);
    pthread_join(t, NULL);
    assert_int_equal(a.status, 200);
    int st;
    waitpid(d.pid, &st, 0);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
    char *log = read_file(d.log, NULL);
    assert_non_null(strstr(log, "SIGTERM: finishing the requests in flight"));
    assert_non_null(strstr(log, "\"POST /solve?format=glb&res=400\" 200"));   /* the access log */
    free(log);
}

/* With --log-format json every line of stderr is JSON: the daemon's start and stop, libmicrohttpd's own
 * messages (a 505 it sent itself, a client gone mid-body: raw text before, QA); and a request whose client went
 * away before its body ended is logged and counted as 499, not 500 (any client could raise the error rate). */
static void a_json_log_should_be_all_json_and_a_client_gone_mid_body_499(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--log-format json");
    static const char v2[] = "GET /livez HTTP/2.0\r\nHost: localhost\r\n\r\n";
    raw_reply rr = raw_request(d.port, v2, sizeof v2 - 1, 2000);
    assert_int_equal(rr.status, 505);
    raw_reply_free(&rr);
    int fd = raw_dial(d.port);
    static const char part[] = "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: 100\r\n\r\n{\"pre";
    raw_send_all(fd, part, sizeof part - 1);
    usleep(200 * 1000);
    close(fd);
    usleep(200 * 1000);
    reply r = http(&d, "GET", "/metrics", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    assert_non_null(strstr(r.body, "pdesolid_requests_total{route=\"solve\",status=\"499\"} 1"));
    if (strstr(r.body, "status=\"500\"") || strstr(r.body, "status=\"other\""))
        fail_msg("a client that went away counted as an error of the server:\n%s", r.body);
    free(r.body);
    stop(&d);
    char *log = read_file(d.log, NULL);
    assert_non_null(log);
    int lines = 0, mhd = 0, aborted = 0, said = 0;
    for (char *line = log, *end; *line; line = end + 1) {
        end = strchr(line, '\n');
        assert_non_null(end);
        *end = '\0';
        if (!json_strict_valid(line, strlen(line)))
            fail_msg("a line of the json log is not JSON: %s", line);
        lines++;
        mhd += strstr(line, "\"source\":\"libmicrohttpd\"") != NULL;
        said += strstr(line, "\"source\":\"pdesolidd\",\"message\":\"listening on http://127.0.0.1:") != NULL ||
                strstr(line, "\"message\":\"stopped\"") != NULL;
        aborted += strstr(line, "\"path\":\"/solve\"") && strstr(line, "\"status\":499") &&
                   strstr(line, "\"aborted\":true");
    }
    assert_true(mhd >= 1);
    assert_int_equal(said, 2);
    assert_int_equal(aborted, 1);
    assert_true(lines >= 6);
    free(log);
}

/* One polling thread starts without libmicrohttpd's "Warning: ... thread pool size, is ignored" (a pool size of
 * 0 was passed for it). */
static void one_polling_thread_should_start_without_warnings(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--http-threads 1");
    reply r = http(&d, "GET", "/livez", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    free(r.body);
    stop(&d);
    char *log = read_file(d.log, NULL);
    assert_non_null(log);
    if (strstr(log, "Warning"))
        fail_msg("the log warns:\n%s", log);
    free(log);
}

/* ---- the small routes ---- */

/* GET /formats lists output.h's table, and each row is true: POST /solve?format=NAME answers with its media
 * type, its body is binary exactly when the row says so, and default_res is api_res_parse's default. */
static void formats_should_list_the_table_and_each_row_should_hold(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    reply r = http(&d, "GET", "/formats", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    cJSON *j = cJSON_Parse(r.body);
    assert_true(cJSON_IsArray(j));
    assert_int_equal(cJSON_GetArraySize(j), API_FMT_COUNT);
    for (int i = 0; i < API_FMT_COUNT; i++) {
        const api_format_info *f = api_format_info_of((api_format)i);
        const cJSON *row = cJSON_GetArrayItem(j, i);
        assert_string_equal(cJSON_GetObjectItem(row, "name")->valuestring, f->name);
        assert_string_equal(cJSON_GetObjectItem(row, "media_type")->valuestring, f->mime);
        assert_string_equal(cJSON_GetObjectItem(row, "extension")->valuestring, f->ext);
        assert_int_equal(cJSON_IsTrue(cJSON_GetObjectItem(row, "mesh")), f->mesh);
        assert_int_equal(cJSON_IsTrue(cJSON_GetObjectItem(row, "properties")), f->props);
        assert_true(cJSON_IsBool(cJSON_GetObjectItem(row, "binary")));
        unsigned res[3];
        assert_int_equal(api_res_parse(NULL, (api_format)i, res, NULL), 0);
        assert_int_equal(cJSON_GetObjectItem(row, "default_res")->valueint, (int)res[0]);
        char path[96], ctype[96];
        snprintf(path, sizeof path, "/solve?format=%s&res=4", f->name);
        reply s = post(&d, path, "{\"preset\":\"fig3d\"}");
        assert_int_equal(s.status, 200);
        assert_true(header_value(&s, "Content-Type", ctype, sizeof ctype));
        if (strncmp(ctype, f->mime, strlen(f->mime)) != 0)
            fail_msg("%s: Content-Type %s, GET /formats says %s", f->name, ctype, f->mime);
        /* binary: the body has a byte no text format writes (a NUL or a byte over 0x7f), at res 4 of fig3d */
        int high = 0;
        for (size_t k = 0; k < s.len; k++)
            high |= s.body[k] == 0 || (unsigned char)s.body[k] > 0x7f;
        if (high != cJSON_IsTrue(cJSON_GetObjectItem(row, "binary")))
            fail_msg("%s: binary %d, but its body %s", f->name, cJSON_IsTrue(cJSON_GetObjectItem(row, "binary")),
                     high ? "has bytes outside printable ASCII" : "is text");
        free(s.body);
    }
    cJSON_Delete(j);
    free(r.body);
    stop(&d);
}

/* An unknown query parameter names the route as a client writes it (it read "/presets/{} takes none": QA), and an
 * empty item is nothing asked wherever it stands ("?format=f32&" was taken, "?&format=f32" refused). */
static void query_messages_should_name_the_route_and_empty_items_be_skipped(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    reply r = http(&d, "GET", "/presets/fig4a?x", NULL, 0, NULL);
    expect_problem(&r, 400, NULL, "unknown query parameter \"x\"; /presets/{name} takes none");
    free(r.body);
    r = http(&d, "GET", "/solids/0123456789abcdef0123456789abcdef?y=1", NULL, 0, NULL);
    expect_problem(&r, 400, NULL, "/solids/{id} takes format, res, compress");
    free(r.body);
    static const char *const ok[] = { "/solve?&format=f32&res=2", "/solve?format=f32&res=2&", "/solve?format=f32&&res=2" };
    for (size_t i = 0; i < sizeof ok / sizeof *ok; i++) {
        r = post(&d, ok[i], "{\"preset\":\"fig1a\"}");
        if (r.status != 200)
            fail_msg("%s: %ld %s", ok[i], r.status, r.body);
        free(r.body);
    }
    r = post(&d, "/solve?=glb", "{\"preset\":\"fig1a\"}");   /* a value without its name is still refused */
    expect_problem(&r, 400, NULL, "unknown query parameter \"\"");
    free(r.body);
    stop(&d);
}

/* compress=meshopt on the formats whose row takes it (GET /formats' "compress"); any other value, or on a
 * format that does not take it, is a 422 that names compress. */
static void compress_should_be_checked_like_every_query_parameter(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    reply r = http(&d, "GET", "/formats", NULL, 0, NULL);
    cJSON *j = cJSON_Parse(r.body);
    for (int i = 0; i < API_FMT_COUNT; i++) {
        const api_format_info *f = api_format_info_of((api_format)i);
        const cJSON *c = cJSON_GetObjectItem(cJSON_GetArrayItem(j, i), "compress");
        assert_int_equal(cJSON_GetArraySize(c), 1 + f->compress);
        char path[96];
        snprintf(path, sizeof path, "/solve?format=%s&res=8&compress=meshopt", f->name);
        reply s = post(&d, path, "{\"preset\":\"fig4a\"}");
        if (s.status != (f->compress ? 200 : 422) || (!f->compress && !strstr(s.body, "compress")))
            fail_msg("%s: %d %.300s", f->name, s.status, s.body);
        free(s.body);
    }
    cJSON_Delete(j);
    free(r.body);
    reply plain = post(&d, "/solve?format=glb&res=32", "{\"preset\":\"fig4a\"}");
    reply small = post(&d, "/solve?format=glb&res=32&compress=meshopt", "{\"preset\":\"fig4a\"}");
    assert_int_equal(plain.status, 200);
    assert_int_equal(small.status, 200);
    assert_true(small.len * 4 <= plain.len);
    assert_non_null(strstr(small.body + 20, "EXT_meshopt_compression"));   /* in the JSON chunk, before any NUL */
    char e1[128], e2[128];
    assert_true(header_value(&plain, "ETag", e1, sizeof e1) && header_value(&small, "ETag", e2, sizeof e2));
    assert_string_not_equal(e1, e2);
    free(plain.body);
    free(small.body);
    reply bad = post(&d, "/solve?format=glb&compress=zip", "{\"preset\":\"fig4a\"}");
    assert_int_equal(bad.status, 422);
    assert_non_null(strstr(bad.body, "compress"));
    free(bad.body);
    reply twice = post(&d, "/solve?format=glb&compress=meshopt&compress=meshopt", "{\"preset\":\"fig4a\"}");
    assert_int_equal(twice.status, 400);
    free(twice.body);
    stop(&d);
}

static void presets_version_health_metrics_and_cors_should_answer(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--cors-origin http://a.example,http://b.example");
    reply r = http(&d, "GET", "/presets", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    cJSON *j = cJSON_Parse(r.body);
    /* The paper's 35 figures, then the gallery's lofts. */
    assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(j, "presets")), 35 + (int)api_loft_preset_count());
    assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(j, "templates")), 4);
    cJSON_Delete(j);
    free(r.body);
    r = http(&d, "GET", "/presets/fig4c", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    j = cJSON_Parse(r.body);
    assert_true(cJSON_GetObjectItem(cJSON_GetObjectItem(j, "params"), "p0")->valuedouble == 1.8e6);
    /* Its model, posted as a model, is the same solid. */
    char *model = cJSON_PrintUnformatted(cJSON_GetObjectItem(j, "model"));
    reply s = post(&d, "/solve?format=f32&res=2", model);
    char id[64];
    assert_true(header_value(&s, "X-Solid-Id", id, sizeof id));
    assert_string_equal(id, cJSON_GetObjectItem(j, "id")->valuestring);
    free(s.body);
    free(model);
    cJSON_Delete(j);
    free(r.body);
    r = http(&d, "GET", "/version", NULL, 0, NULL);
    assert_non_null(strstr(r.body, "\"libmicrohttpd\":\"0.9."));
    free(r.body);
    r = http(&d, "GET", "/readyz", NULL, 0, NULL);
    assert_int_equal(r.status, 200);
    free(r.body);
    r = http(&d, "GET", "/metrics", NULL, 0, NULL);
    assert_non_null(strstr(r.body, "pdesolid_request_duration_seconds_bucket{le=\"+Inf\"}"));
    assert_non_null(strstr(r.body, "pdesolid_requests_total{route=\"presets\",status=\"200\"} 1"));
    free(r.body);
    r = http(&d, "OPTIONS", "/solve", NULL, 0, "Origin: http://b.example");
    assert_int_equal(r.status, 204);
    char v[128];
    assert_true(header_value(&r, "Access-Control-Allow-Origin", v, sizeof v));
    assert_string_equal(v, "http://b.example");
    assert_true(header_value(&r, "Access-Control-Allow-Methods", v, sizeof v));
    assert_string_equal(v, "POST, OPTIONS");
    free(r.body);
    r = http(&d, "GET", "/livez", NULL, 0, "Origin: http://evil.example");
    assert_false(header_value(&r, "Access-Control-Allow-Origin", v, sizeof v));
    assert_true(header_value(&r, "Vary", v, sizeof v));
    free(r.body);
    /* With a list of origins, every answer varies by Origin, one without it too: a shared cache must not
     * give a.example's answer (with its Allow-Origin) to b.example, nor one without to a.example. */
    r = http(&d, "GET", "/presets/fig4c", NULL, 0, NULL);
    assert_true(header_value(&r, "Vary", v, sizeof v));
    assert_string_equal(v, "Origin");
    free(r.body);
    stop(&d);
}

/* A share link (/?solid=ID, README "In the browser") is the page with a query of its own: the page's script
 * reads it, so the server serves the page whatever the names; control characters are still refused. */
static void the_page_should_take_a_query_of_its_own(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    const char *ok[] = { "/?solid=99268af08d93209af6cac24a6617fc90", "/?preset=fig4c", "/index.html?solid=x&y" };
    for (size_t i = 0; i < sizeof ok / sizeof *ok; i++) {
        reply r = http(&d, "GET", ok[i], NULL, 0, NULL);
        char type[64] = "";
        header_value(&r, "Content-Type", type, sizeof type);
        if (r.status != 200 || !strstr(type, "text/html"))
            fail_msg("GET %s: %ld %s", ok[i], r.status, type);
        free(r.body);
    }
    reply r = http(&d, "GET", "/?solid=a%01b", NULL, 0, NULL);
    expect_problem(&r, 400, NULL, "control character");
    free(r.body);
    /* C1 controls (U+0080..U+009F, in UTF-8 C2 80..C2 9F) as C0 ones, in a value or a name, escaped or raw;
     * the characters after them (U+00A0, é) pass. */
    const char *c1[] = { "/?solid=a%C2%85b", "/?solid=%c2%80", "/?solid=a%C2%9F", "/?x%C2%8Ay=1", "/?solid=a\xc2\x85" "b" };
    for (size_t i = 0; i < sizeof c1 / sizeof *c1; i++) {
        r = http(&d, "GET", c1[i], NULL, 0, NULL);
        if (r.status != 400)
            fail_msg("GET %s: %ld, not 400", c1[i], r.status);
        expect_problem(&r, 400, NULL, "control character");
        free(r.body);
    }
    const char *fine[] = { "/?solid=a%C2%A0b", "/?solid=caf%C3%A9", "/?solid=%C2%BF" };
    for (size_t i = 0; i < sizeof fine / sizeof *fine; i++) {
        r = http(&d, "GET", fine[i], NULL, 0, NULL);
        if (r.status != 200)
            fail_msg("GET %s: %ld, not 200", fine[i], r.status);
        free(r.body);
    }
    /* The API's routes still refuse what they do not know. */
    r = http(&d, "GET", "/presets?solid=1", NULL, 0, NULL);
    expect_problem(&r, 400, NULL, "solid");
    free(r.body);
    stop(&d);
}

static void openapi_should_be_valid_and_name_every_route(void **state)
{
    (void)state;
    char cmd[256];
    snprintf(cmd, sizeof cmd, "node tests/node/validate_openapi.mjs docs/openapi.yaml > %s/paths.txt", dir);
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd, "%s/paths.txt", dir);
    char *paths = read_file(cmd, NULL);
    /* The routes of server/http.c, in the document, and nothing else. */
    const char *routes[] = { "/solve", "/solids/{id}", "/solids/{id}/eval", "/solids/{id}/request", "/presets",
                             "/presets/{name}", "/livez", "/readyz", "/version", "/metrics", "/", "/openapi.yaml",
                             "/formats" };
    size_t listed = 0;
    for (const char *p = paths; *p; p += strcspn(p, "\n") + (p[strcspn(p, "\n")] != 0))
        listed++;
    assert_int_equal(listed, sizeof routes / sizeof *routes);
    for (size_t i = 0; i < sizeof routes / sizeof *routes; i++) {
        char line[64];
        snprintf(line, sizeof line, "\n%s\n", routes[i]);
        char *framed = malloc(strlen(paths) + 3);
        sprintf(framed, "\n%s", paths);
        if (!strstr(framed, line))
            fail_msg("docs/openapi.yaml lacks %s", routes[i]);
        free(framed);
    }
    free(paths);
}

/* Runs a shell command; returns its exit status and stdout (free it). */
static int sh(const char *cmd, char **out)
{
    char full[2048], path[160];
    snprintf(path, sizeof path, "%s/sh.out", dir);
    snprintf(full, sizeof full, "%s > %s 2>&1", cmd, path);
    int st = system(full);
    *out = read_file(path, NULL);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void the_cli_should_give_the_same_answers_through_the_server(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    const char *cli = getenv("PDESOLID_SAN") ? getenv("PDESOLID_SAN") : "build/san/pdesolid";
    char cmd[1024], *a, *b;
    const char *forms[] = { "solve --preset fig4b --param p0=12345 --param c=-11,-11,-10",
                            "solve --preset fig3d --format grid --res 3,4,5",
                            "solve examples/fig4a.json --format json" };
    for (int i = 0; i < 3; i++) {
        snprintf(cmd, sizeof cmd, "%s %s --server %s", cli, forms[i], d.base);
        assert_int_equal(sh(cmd, &a), 0);
        snprintf(cmd, sizeof cmd, "%s %s", cli, forms[i]);
        assert_int_equal(sh(cmd, &b), 0);
        if (i < 2)
            assert_string_equal(a, b);   /* the json document differs only in key order, not here */
        else
            assert_non_null(strstr(a, "\"closed_form\""));
        free(a);
        free(b);
    }
    char pts[160];
    snprintf(pts, sizeof pts, "%s/p.json", dir);
    FILE *f = fopen(pts, "w");
    fputs("[[0.5,0.25,0.5],[1,0.1,0.9],[0,0,0]]", f);
    fclose(f);
    snprintf(cmd, sizeof cmd, "%s eval examples/fig4a.json %s --server %s", cli, pts, d.base);
    assert_int_equal(sh(cmd, &a), 0);
    snprintf(cmd, sizeof cmd, "%s eval examples/fig4a.json %s", cli, pts);
    assert_int_equal(sh(cmd, &b), 0);
    assert_string_equal(a, b);
    free(a);
    free(b);
    snprintf(cmd, sizeof cmd, "%s solve --preset fig4a --param c=-1,-1,0 --server %s", cli, d.base);
    assert_int_equal(sh(cmd, &a), 2);
    assert_non_null(strstr(a, "422: /params/c/2: c of component z is 0"));
    free(a);
    stop(&d);
    snprintf(cmd, sizeof cmd, "%s solve examples/fig4a.json --server %s", cli, d.base);
    assert_int_equal(sh(cmd, &a), 1);
    assert_non_null(strstr(a, "connect"));
    free(a);
}

/* ---- the harness itself ---- */

/* Running, and not a zombie (where no init reaps orphans, as in some containers, one stays listed). */
static int process_alive(int pid)
{
    char path[64], buf[256];
    snprintf(path, sizeof path, "/proc/%d/stat", pid);
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    const char *p = strrchr(buf, ')');   /* the state follows the command, which may hold spaces */
    return p && p[1] == ' ' && p[2] != 'Z' && p[2] != 'X';
}

/* A failed assertion leaves a test without reaching daemon_stop: the daemon must still not outlive the test
 * binary (it held a port and CPU after a failed CI run). A child starts one and exits without stopping it. */
static void a_daemon_should_not_outlive_the_test_that_started_it(void **state)
{
    (void)state;
    int fd[2];
    assert_int_equal(pipe(fd), 0);
    pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0) {
        daemon_t d;
        daemon_start(&d, dir, "");
        if (write(fd[1], &d.pid, sizeof d.pid) != (ssize_t)sizeof d.pid)
            _exit(1);
        _exit(0);   /* as a failed test's binary ends: no daemon_stop */
    }
    close(fd[1]);
    int pid = 0, st;
    assert_int_equal(read(fd[0], &pid, sizeof pid), (ssize_t)sizeof pid);
    close(fd[0]);
    waitpid(child, &st, 0);
    assert_true(pid > 0);
    int gone = 0;
    for (int i = 0; i < 200 && !gone; i++) {
        gone = !process_alive(pid);
        if (!gone)
            usleep(10000);
    }
    if (!gone) {
        kill(pid, SIGKILL);
        fail_msg("pdesolidd %d outlived the process that started it", pid);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_cli_should_give_the_same_answers_through_the_server),
        cmocka_unit_test(the_page_should_take_a_query_of_its_own),
        cmocka_unit_test(openapi_should_be_valid_and_name_every_route),
        cmocka_unit_test(solve_should_give_every_format_as_the_core_computes_it),
        cmocka_unit_test(a_solid_beyond_float32_should_be_a_422_in_every_format_that_would_overflow),
        cmocka_unit_test(a_volume_mesh_over_its_cell_limit_should_be_the_413_the_docs_say),
        cmocka_unit_test(eval_should_agree_with_the_cli),
        cmocka_unit_test(cache_hits_misses_and_evictions_should_show_in_metrics),
        cmocka_unit_test(concurrent_identical_requests_should_solve_once),
        cmocka_unit_test(a_request_waiting_on_a_cancelled_solve_should_solve_for_itself),
        cmocka_unit_test(a_get_waiting_on_a_cancelled_solve_should_get_the_solve_that_takes_it_over),
        cmocka_unit_test(a_get_waiting_on_a_cancelled_solve_no_one_takes_over_should_learn_it_was_cancelled),
        cmocka_unit_test(server_timing_should_say_cached_wherever_the_cache_gave_the_solution),
        cmocka_unit_test(a_skin_around_a_loop_at_res_3_should_be_refused_before_the_properties),
        cmocka_unit_test(etag_with_if_none_match_should_give_304),
        cmocka_unit_test(sixty_four_concurrent_clients_should_all_get_correct_answers),
        cmocka_unit_test(a_full_queue_should_give_503_with_retry_after),
        cmocka_unit_test(a_light_request_should_not_wait_behind_heavy_ones),
        cmocka_unit_test(heavy_evals_and_big_bodies_should_run_apart),
        cmocka_unit_test(bad_requests_should_get_problems_and_the_daemon_should_keep_serving),
        cmocka_unit_test(a_loft_should_solve_and_a_bad_one_get_its_pointer),
        cmocka_unit_test(two_content_lengths_and_stalled_clients_should_be_refused),
        cmocka_unit_test(sigterm_should_let_a_request_in_flight_complete_and_answer_new_ones_503),
        cmocka_unit_test(one_polling_thread_should_start_without_warnings),
        cmocka_unit_test(a_json_log_should_be_all_json_and_a_client_gone_mid_body_499),
        cmocka_unit_test(presets_version_health_metrics_and_cors_should_answer),
        cmocka_unit_test(formats_should_list_the_table_and_each_row_should_hold),
        cmocka_unit_test(compress_should_be_checked_like_every_query_parameter),
        cmocka_unit_test(query_messages_should_name_the_route_and_empty_items_be_skipped),
        cmocka_unit_test(a_daemon_should_not_outlive_the_test_that_started_it),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("server", tests, setup, teardown);
}
