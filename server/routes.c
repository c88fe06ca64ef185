/*
 * routes.c: the route table (route.h), the handlers, and the jobs that run
 * on the solver threads.
 *
 * A row's handler runs on the polling thread unless the row has SRV_RT_JOB;
 * then http.c queues it and srv_run_job() calls it on a solver thread,
 * times it, and resumes the connection. Handlers only set the request's
 * result (srv_set_text, srv_problem, r->stream); http.c sends it.
 * Every job checks its cost before the work (--max-work, --max-mem-mb) and
 * polls srv_job_stop() in its long loops (--job-timeout, shutdown, the
 * client's close: then no answer, and the request is logged 499).
 */
#include <errno.h>
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>

#include <cJSON.h>

#include "catalog.h"
#include "cost.h"
#include "internal.h"
#include "mesh.h"
#include "model.h"
#include "sbuf.h"
#include "strict.h"
#include "template.h"

double srv_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* ---- the cheap routes, on the polling thread ---- */

static void get_livez(srv_req *r)
{
    srv_set_text(r, 200, "text/plain; charset=utf-8", strdup("ok\n"));
}

static void get_readyz(srv_req *r)
{
    srv_server *s = r->s;
    /* While the server stops, admit() answers every request, this one too. */
    if (s->store && !srv_store_ready(s->store)) {
        /* Still ready: ids in memory and new solves are served; only ids known elsewhere answer 503. */
        char *text = malloc(1200);
        if (text)
            snprintf(text, 1200, "degraded: the store %s is unreachable\n", srv_store_name(s->store));
        srv_set_text(r, 200, "text/plain; charset=utf-8", text);
    } else {
        srv_set_text(r, 200, "text/plain; charset=utf-8", strdup("ready\n"));
    }
}

static void get_version(srv_req *r)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "name", "pdesolidd");
    cJSON_AddStringToObject(o, "version", SRV_VERSION);
    cJSON_AddStringToObject(o, "libmicrohttpd", MHD_get_version());
    cJSON_AddStringToObject(o, "cjson", cJSON_Version());
    char *text = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    srv_set_text(r, 200, "application/json", text);
}

static void get_metrics(srv_req *r)
{
    srv_server *s = r->s;
    srv_cache_stats cs;
    srv_cache_stats_get(s->cache, &cs);
    size_t in_flight = atomic_load(&s->in_flight);
    char *text = srv_metrics_render(s->metrics, &cs, srv_pool_depth(s->pool), in_flight, srv_rcache_hits(s->rcache));
    if (text && s->store) {
        srv_sbuf b = { text, strlen(text), strlen(text) + 1, 0 };
        srv_store_metrics(s->store, &b);
        text = b.oom ? (free(b.s), NULL) : b.s;
    }
    srv_set_text(r, 200, "text/plain; version=0.0.4; charset=utf-8", text);
}

static void get_formats(srv_req *r)
{
    srv_set_text(r, 200, "application/json", api_formats_json());
}

static void get_presets(srv_req *r)
{
    srv_set_text(r, 200, "application/json", api_presets_json());
}

static void get_preset(srv_req *r)
{
    const api_preset *ps = api_preset_find(r->arg);
    char *loft = ps ? NULL : api_loft_preset_json(r->arg);
    if (ps)
        srv_set_text(r, 200, "application/json", api_preset_json(ps));
    else if (loft)
        srv_set_text(r, 200, "application/json", loft);
    else
        srv_problem(r, 404, NULL, "no preset \"%s\"; GET /presets lists them", r->arg);
}

/* ---- the solver threads' jobs ---- */

/* How often a job looks at its client's socket, in seconds of the job: a recv(2) of about a microsecond
 * each, so the look costs some 0.01 % of the job, and a job whose client left stops within this. */
#define CLIENT_CHECK 0.01

/* 1 (and r->gone) once r's client has closed its connection or reset it: the socket reads as EOF or an
 * error. Bytes waiting are no close (a client may pipeline its next request on a keep-alive connection);
 * a half-close (shutdown(SHUT_WR)) is one, as for nginx (ngx_http_test_reading) and libmicrohttpd. The
 * socket stays open while the connection is suspended: libmicrohttpd closes it only after the resume. */
static int client_gone(srv_req *r, double now)
{
    char c;
    r->checked = now;
    if (!r->gone && r->fd >= 0) {
        ssize_t n = recv(r->fd, &c, 1, MSG_PEEK | MSG_DONTWAIT);
        r->gone = n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR);
    }
    return r->gone;
}

int srv_job_stop(void *arg)
{
    srv_req *r = arg;
    const double now = srv_now();
    if (now - r->checked >= CLIENT_CHECK)
        client_gone(r, now);
    return r->gone || atomic_load(&r->s->aborting) || r->work + (now - r->run_start) > r->s->cfg.job_timeout;
}

/* The calling thread's CPU clock, in seconds. */
static double thread_cpu(void)
{
    struct timespec t;
    return clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t) ? 0.0 : t.tv_sec + t.tv_nsec * 1e-9;
}

/* A job past --job-timeout that had the CPU to itself most of that time is too much work for this server
 * (422: the same request would only run out of time again; its estimate was within --max-work); one that
 * did not got too little of it, the server being busy (503, Retry-After). */
#define CPU_SHARE 0.75

/* The problem of a job that stopped: shutdown, the deadline, or no problem at all for a client gone (499,
 * nginx's "client closed request": http.c closes the connection without an answer). */
static void stopped(srv_req *r)
{
    srv_server *s = r->s;
    if (atomic_load(&s->aborting)) {
        srv_problem(r, 503, NULL, "the server is shutting down");
    } else if (r->gone) {
        free(r->text);
        r->text = NULL;
        r->status = 499;
        if (s->log) {
            char msg[200];
            snprintf(msg, sizeof msg, "rid=%s: the client closed its connection; its job stopped after %.3f s of "
                     "solver time", r->rid, r->work + (srv_now() - r->run_start));
            srv_log_note(s->log, "pdesolidd", msg);
        }
    } else {
        const double wall = r->work + (srv_now() - r->run_start), cpu = r->cpu + (thread_cpu() - r->cpu_start);
        if (cpu >= CPU_SHARE * wall)
            srv_problem(r, 422, NULL, "the request ran past its deadline of %g s of solver time (--job-timeout), "
                        "on a CPU of its own (%.2g s of CPU in %.2g s): it is more work than this server takes, "
                        "though its estimate (%.3g units) was within --max-work; ask for a lower res, or a smaller "
                        "model (fewer terms, or a loft with fewer sections or grid points)",
                        s->cfg.job_timeout, cpu, wall, r->cost.work);
        else
            srv_problem(r, 503, NULL, "the server is busy: the request ran past its deadline of %g s of solver "
                        "time (--job-timeout) with %.2g s of CPU in %.2g s; try again shortly", s->cfg.job_timeout,
                        cpu, wall);
    }
}

/* Adds part to the request's estimate; 1 (with the problem set) when the whole is over a budget. */
static int over_budget(srv_req *r, const api_cost *part)
{
    const srv_config *c = &r->s->cfg;
    api_cost_add(&r->cost, part);
    if (r->cost.work > c->max_work) {
        srv_problem(r, 422, NULL,
                    "this request is estimated at %.3g units of work (about %.2g CPU-seconds), over the limit of %.3g "
                    "(--max-work); ask for a lower res, fewer points, or a smaller model (fewer terms, or a loft with "
                    "fewer sections or grid points)",
                    r->cost.work, r->cost.work * 1e-9, c->max_work);
        return 1;
    }
    if (r->cost.bytes > (double)c->max_mem) {
        srv_problem(r, 422, NULL,
                    "this request would use about %.0f MiB of memory, over the limit of %zu MiB (--max-mem-mb); "
                    "ask for a lower res, or a smaller model (fewer terms, or a loft with fewer sections or grid points)",
                    r->cost.bytes / 1048576, c->max_mem >> 20);
        return 1;
    }
    return 0;
}

/* An api/ error, or the problem of a job that was stopped. */
static void failed(srv_req *r, const api_error *err)
{
    if (err->status == API_ERR_CANCELLED)
        stopped(r);
    else
        srv_problem_api(r, err);
}

typedef struct {
    api_model *model;
    const pde_cancel *cancel;
} solve_arg;

static int solve_model(void *arg, pde_solution **out, api_error *err)
{
    solve_arg *a = arg;
    return api_solve_ex(a->model, a->cancel, out, err);
}

static void answer_heavy(srv_req *r, srv_entry *e);
static void answer_later(srv_req *r);

/* Whether the rest of a request, estimated at r->cost so far, runs apart from light requests: then
 * srv_run_job defers later (with what it needs in r) as its last act. A remainder already apart runs now. */
static int defer(srv_req *r, void (*later)(srv_req *r))
{
    if (r->apart || r->cost.work < r->s->cfg.heavy_work)
        return 0;
    r->later = later;
    return 1;
}

/* 304 Not Modified, releasing e, when If-None-Match names this request's representation (or is *) and the
 * output is known to exist: opened by this request (opened), or by one before. An ETag (or *) of an output
 * that is refused (a limit, float32, no skin) names no representation, and the refusal is the answer. */
static int revalidated(srv_req *r, srv_entry *e, int opened)
{
    const int shown = srv_entry_shown(e, r->etag, opened);
    const char *inm = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_IF_NONE_MATCH);
    if (!inm || !(opened || shown) || !(strstr(inm, r->etag) || !strcmp(inm, "*")))
        return 0;
    srv_cache_release(r->s->cache, e);
    r->status = 304;
    r->ctype = NULL;
    return 1;
}

/* The response of a solved entry: its ETag and the budget's checks, then answer_heavy() now or, when the
 * estimate is --heavy-work or more, apart from lighter requests (pool.h). Takes over the reference. */
static void answer_entry(srv_req *r, srv_entry *e)
{
    srv_server *s = r->s;
    api_format f = r->q.fmt;
    const unsigned *res = r->q.res3;
    snprintf(r->id, sizeof r->id, "%s", srv_entry_id(e));
    api_output_opts opts = { .compress = r->q.comp };
    snprintf(r->etag, sizeof r->etag, "\"%s.%s%s%s.%ux%ux%u\"", r->id, api_format_info_of(f)->name,
             opts.compress ? "." : "", opts.compress ? api_compress_name(opts.compress) : "", res[0], res[1], res[2]);
    if (revalidated(r, e, 0))
        return;
    const pde_solution *sol = srv_entry_solution(e);
    int with_props = api_format_info_of(f)->props;
    api_cost part;
    api_cost_output_ex(sol, f, res, &opts, &part);
    int over = over_budget(r, &part);
    if (!over && with_props && !srv_entry_has_props(e)) {
        api_cost_props(sol, &part);
        over = over_budget(r, &part);
    }
    if (over) {
        srv_cache_release(s->cache, e);
        return;
    }
    r->heavy = e;
    if (!defer(r, answer_later))
        answer_later(r);
}

static void answer_later(srv_req *r)
{
    srv_entry *e = r->heavy;
    r->heavy = NULL;
    answer_heavy(r, e);
}

/* The properties and the output of an entry the budget admitted: 304, a whole body, or a stream. */
static void answer_heavy(srv_req *r, srv_entry *e)
{
    srv_server *s = r->s;
    api_format f = r->q.fmt;
    const unsigned *res = r->q.res3;
    api_output_opts opts = { .compress = r->q.comp };
    const pde_solution *sol = srv_entry_solution(e);
    const int with_props = api_format_info_of(f)->props;
    const pde_props *props = NULL;
    api_error err;
    /* The output's own refusals first (float32's range: a glb of a solid beyond it), which cost nothing,
     * where the properties of the same solid would take their whole budget; and a skin's of res 3 around a
     * loop (mesh.h), which costs a sampling of its faces, only at res 3 and only before properties to come. */
    double t0 = srv_now();
    if (api_output_check(sol, f, &opts, &err) ||
        (with_props && api_format_info_of(f)->mesh && !srv_entry_has_props(e) &&
         api_mesh_check_loops(sol, res, &r->cancel, &err))) {
        r->tm.output = srv_now() - t0;
        srv_cache_release(s->cache, e);
        failed(r, &err);
        return;
    }
    t0 = srv_now();
    if (with_props && !(props = srv_entry_props(e, &r->cancel, &err))) {
        r->tm.props = srv_now() - t0;
        srv_cache_release(s->cache, e);
        failed(r, &err);   /* cancelled: stopped(); the solid's own failure, kept with it */
        return;
    }
    r->tm.props = srv_now() - t0;
    if (srv_job_stop(r)) {
        srv_cache_release(s->cache, e);
        stopped(r);
        return;
    }
    t0 = srv_now();
    api_output *o = api_output_open_ex(sol, r->id, props, f, res, &opts, &r->cancel, &err);
    r->tm.output = srv_now() - t0;
    if (!o) {
        srv_cache_release(s->cache, e);
        failed(r, &err);
        return;
    }
    if (revalidated(r, e, 1)) {
        api_output_free(o);
        return;
    }
    r->status = 200;
    r->ctype = api_format_info_of(f)->mime;
    int whole = 0;
    r->stream = srv_stream_start(r, o, e, &whole);
    if (whole && r->status == 200 && r->key && r->text_len <= SRV_RCACHE_MAX_ITEM)
        srv_rcache_put(s->rcache, r->key, r->klen, r->text, r->text_len, r->ctype, r->id, r->etag);
}

/* A large body's parse tree (some 40 bytes a byte) is freed by now; give it back to the system
 * before the next step allocates its own, so that the two peaks do not add up (--max-mem-mb). */
static void trim_after_parse(const srv_req *r)
{
    if (r->len > (256u << 10))
        malloc_trim(0);
}

/* Puts a newly solved id in the store (--store): its canonical model (a loft's, its request: a loft
 * has no other document) and the request as given. A failure is only counted (/metrics). */
static void keep(srv_req *r, const char *id, const api_model *m)
{
    if (!r->s->store)
        return;
    char *request = malloc(r->len + 1);
    char *model = api_model_loft(m) ? NULL : api_model_json(api_model_get(m));
    if (request) {
        memcpy(request, r->body ? r->body : "", r->len);
        request[r->len] = '\0';
    }
    const char *doc = api_model_loft(m) ? request : model;
    if (doc && request)
        srv_store_put(r->s->store, id, doc, request);
    free(model);
    free(request);
}

/* Model m's entry (id), solved through the cache (concurrent requests solve once) if its estimate is within
 * budget; a new one is kept in the store when keep_new. Frees m. NULL with the problem set. */
static srv_entry *solve_cached(srv_req *r, api_model *m, const char *id, int keep_new)
{
    api_cost part;
    api_cost_model(m, &part);
    if (over_budget(r, &part)) {
        api_model_free(m);
        return NULL;
    }
    api_error err;
    solve_arg sa = { m, &r->cancel };
    int hit;
    double t0 = srv_now();
    srv_entry *e = srv_cache_get(r->s->cache, id, solve_model, &sa, &hit, &err);
    r->tm.solve = srv_now() - t0;
    r->tm.cached = hit;
    if (!hit)
        srv_metrics_solve(r->s->metrics, r->tm.solve);
    if (e && !hit && keep_new)
        keep(r, id, m);
    api_model_free(m);
    if (!e)
        failed(r, &err);
    return e;
}

/* What parsing and fitting a loft costs a byte of its body, in work units: measured at about 0.09
 * CPU-seconds for 1 MB (/tmp/qa13, QA round 13), some 8 times api_cost_parse's estimate. Only where
 * the request runs depends on it (a body of 556 kB or more, at the default --heavy-work), not the budget. */
#define BODY_WORK_BYTE 90.0

static void solve_body(srv_req *r);

static void post_solve(srv_req *r)
{
    api_cost part;
    api_cost_parse(r->len, &part);
    if (over_budget(r, &part))
        return;
    /* A big body is a big loft: its parse and fit are heavy work before any estimate knows it. */
    if (!r->apart && (double)r->len * BODY_WORK_BYTE >= r->s->cfg.heavy_work) {
        r->later = solve_body;
        return;
    }
    solve_body(r);
}

/* A /solve body parsed, solved and answered. */
static void solve_body(srv_req *r)
{
    srv_server *s = r->s;
    api_error err;
    double t0 = srv_now();
    pthread_mutex_lock(&s->json_lock);
    api_model *m = api_model_parse(r->body ? r->body : "", r->len, &err);
    pthread_mutex_unlock(&s->json_lock);
    trim_after_parse(r);
    r->tm.parse = srv_now() - t0;
    if (!m) {
        srv_problem_api(r, &err);
        return;
    }
    char id[API_ID_LEN + 1];
    pde_diag d;
    if (api_request_id(m, id, &d) != PDE_OK) {
        /* Invalid in a way the solve reports with a pointer. */
        pde_solution *sol = NULL;
        api_solve(m, &sol, &err);
        pde_solution_free(sol);
        api_model_free(m);
        srv_problem_api(r, &err);
        return;
    }
    srv_entry *e = solve_cached(r, m, id, 1);
    if (e)
        answer_entry(r, e);
}

/* The problem of a store that cannot answer now (--store). */
static void store_down(srv_req *r)
{
    srv_problem(r, 503, NULL, "the store %s cannot be reached now, and the solid %s is not in this server's memory; "
                "try again later", srv_store_name(r->s->store), r->arg);
}

/* The entry of an id missing from the cache, re-solved from its model in the store (through the cache:
 * concurrent requests solve once). NULL with the problem set, or with *missing when the store has no such id. */
static srv_entry *restore(srv_req *r, int *missing)
{
    srv_server *s = r->s;
    char *doc = NULL, *request = NULL;
    srv_store_status st = srv_store_get(s->store, r->arg, &doc, &request);
    free(request);
    *missing = st == SRV_STORE_MISSING;
    if (st != SRV_STORE_OK) {
        if (!*missing)
            store_down(r);
        return NULL;
    }
    api_error err;
    pthread_mutex_lock(&s->json_lock);
    api_model *m = api_model_parse(doc, strlen(doc), &err);
    pthread_mutex_unlock(&s->json_lock);
    free(doc);
    char id[API_ID_LEN + 1];
    pde_diag d;
    if (!m || api_request_id(m, id, &d) != PDE_OK || strcmp(id, r->arg)) {
        api_model_free(m);
        srv_problem(r, 500, NULL, "the store's model of %s does not give that id back", r->arg);
        return NULL;
    }
    return solve_cached(r, m, id, 0);
}

/* The entry of the id in the path: cached, being solved (waited for), or re-solved from the store. NULL with
 * the problem set: 404 for an id not known here; 503 for one whose solve, for another request, stopped for that
 * request alone (its deadline, its client gone) with no /solve of the model there to take it over. */
static srv_entry *find_solid(srv_req *r)
{
    api_error err = { .status = API_ERR_NOT_FOUND };
    int valid = api_id_valid(r->arg), missing = 1;
    double t0 = srv_now();
    srv_entry *e = valid ? srv_cache_find(r->s->cache, r->arg, &err) : NULL;
    r->tm.solve = srv_now() - t0;   /* as solve_cached's: the solve is the cache's, a wait at most */
    r->tm.cached = e != NULL;
    if (!e && valid && r->s->store && (err.status == API_ERR_NOT_FOUND || err.status == API_ERR_CANCELLED))
        e = restore(r, &missing);
    if (e || !missing)
        return e;
    if (err.status == API_ERR_CANCELLED)
        srv_problem(r, 503, NULL,
                    "the solid %s was being solved for another request, which stopped before the solve ended (its "
                    "--job-timeout, or its client gone); this server has no model to solve it again: try again, or "
                    "POST its model to /solve", r->arg);
    else if (err.status != API_ERR_NOT_FOUND)   /* that solve's own failure; its pointer is into another body */
        srv_problem(r, srv_http_status(err.status), NULL, "the solve of %s, for another request, failed: %s", r->arg,
                    err.message);
    else
        srv_problem(r, 404, NULL,
                    "no solid %s: it was never solved here, or was evicted; POST its model to /solve",
                    valid ? r->arg : "with that id (an id is 32 lowercase hex digits)");
    return NULL;
}

/* The request an id came from, as the store kept it (--store): for share links. */
static void get_solid_request(srv_req *r)
{
    char *doc = NULL, *request = NULL;
    srv_store_status st = SRV_STORE_MISSING;
    if (r->s->store && api_id_valid(r->arg))
        st = srv_store_get(r->s->store, r->arg, &doc, &request);
    free(doc);
    if (st == SRV_STORE_OK && request)
        srv_set_text(r, 200, "application/json", request);
    else if (st == SRV_STORE_OK || st == SRV_STORE_MISSING)
        srv_problem(r, 404, NULL, "no request kept for %s: the store (--store) has no such id",
                    api_id_valid(r->arg) ? r->arg : "that id (an id is 32 lowercase hex digits)");
    else
        store_down(r);
}

static void get_solid(srv_req *r)
{
    srv_entry *e = find_solid(r);
    if (e)
        answer_entry(r, e);
}

static void eval_points(srv_req *r);

static void post_eval(srv_req *r)
{
    srv_server *s = r->s;
    srv_entry *e = find_solid(r);
    if (!e)
        return;
    api_error err;
    api_cost part;
    api_cost_parse(r->len, &part);
    if (over_budget(r, &part)) {
        srv_cache_release(s->cache, e);
        return;
    }
    double *pts = NULL;
    size_t n = 0;
    int derivs = 0;
    double t0 = srv_now();
    pthread_mutex_lock(&s->json_lock);
    int rc = api_eval_parse(r->body ? r->body : "", r->len, s->cfg.max_points, &pts, &n, &derivs, &err);
    pthread_mutex_unlock(&s->json_lock);
    trim_after_parse(r);
    r->tm.parse = srv_now() - t0;
    if (rc) {
        srv_cache_release(s->cache, e);
        srv_problem_api(r, &err);
        return;
    }
    api_cost_eval(srv_entry_solution(e), n, derivs, &part);
    if (over_budget(r, &part)) {
        free(pts);
        srv_cache_release(s->cache, e);
        return;
    }
    r->heavy = e;
    r->pts = pts;
    r->npts = n;
    r->derivs = derivs;
    if (!defer(r, eval_points))
        eval_points(r);
}

/* An eval's points, parsed and admitted (post_eval), evaluated and answered. */
static void eval_points(srv_req *r)
{
    srv_server *s = r->s;
    srv_entry *e = r->heavy;
    double *pts = r->pts;
    const size_t n = r->npts;
    const int derivs = r->derivs;
    r->heavy = NULL;
    r->pts = NULL;
    api_error err;
    double t0;
    const pde_solution *sol = srv_entry_solution(e);
    double *v = malloc((n ? n : 1) * 12 * sizeof *v);
    if (!v) {
        free(pts);
        srv_cache_release(s->cache, e);
        srv_problem(r, 500, NULL, "out of memory");
        return;
    }
    double *du = v + 3 * n, *dv = v + 6 * n, *dw = v + 9 * n;
    t0 = srv_now();
    size_t i = 0;
    for (; i < n; i++) {
        if (i % 256 == 0 && srv_job_stop(r))
            break;
        pde_eval_d(sol, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], v + 3 * i, derivs ? du + 3 * i : NULL,
                   derivs ? dv + 3 * i : NULL, derivs ? dw + 3 * i : NULL);
    }
    r->tm.solve = srv_now() - t0;
    r->tm.cached = 0;   /* the slot is the evaluation's now (docs/API.md), which no cache answered */
    snprintf(r->id, sizeof r->id, "%s", srv_entry_id(e));
    srv_cache_release(s->cache, e);
    free(pts);
    if (i < n) {
        free(v);
        stopped(r);
        return;
    }
    if (api_eval_check(v, derivs ? du : NULL, derivs ? dv : NULL, derivs ? dw : NULL, n, &err)) {
        free(v);
        srv_problem_api(r, &err);
        return;
    }
    t0 = srv_now();
    char *json = api_eval_json(r->id, v, derivs ? du : NULL, derivs ? dv : NULL, derivs ? dw : NULL, n);
    r->tm.output = srv_now() - t0;
    free(v);
    srv_set_text(r, 200, "application/json", json);
}

static void job_end(srv_req *r);

/* What a remainder that will not run holds (job_end, run_heavy), given back. */
static void drop_later(srv_req *r)
{
    if (r->heavy)
        srv_cache_release(r->s->cache, r->heavy);
    free(r->pts);
    r->heavy = NULL;
    r->pts = NULL;
    r->later = NULL;
}

/* The heavy remainder of a request (--heavy-work), on the thread that took it from the pool. */
static void run_heavy(void *arg)
{
    srv_req *r = arg;
    void (*later)(srv_req *r) = r->later;
    r->later = NULL;
    r->apart = 1;
    srv_metrics_heavy(r->s->metrics);
    r->run_start = srv_now();
    r->cpu_start = thread_cpu();
    r->tm.queue += r->run_start - r->queued_at;
    if (atomic_load(&r->s->aborting) || client_gone(r, r->run_start)) {
        drop_later(r);
        stopped(r);
    } else
        later(r);
    job_end(r);
}

void srv_run_job(void *arg)
{
    srv_req *r = arg;
    r->run_start = srv_now();
    r->cpu_start = thread_cpu();
    r->tm.queue = r->run_start - r->queued_at;
    r->cancel = (pde_cancel){ srv_job_stop, r };
    if (atomic_load(&r->s->aborting) || client_gone(r, r->run_start))   /* a client that left while its job was queued */
        stopped(r);
    else
        srv_routes[r->route].handler(r);
    job_end(r);
}

/* A job's end: its heavy part deferred (the last act: it may run at once elsewhere), or the answer. */
static void job_end(srv_req *r)
{
    srv_server *s = r->s;
    if (r->later && client_gone(r, srv_now())) {
        drop_later(r);
        stopped(r);
    }
    r->work += srv_now() - r->run_start;
    r->cpu += thread_cpu() - r->cpu_start;
    if (r->later) {
        r->queued_at = srv_now();
        if (srv_pool_defer_heavy(s->pool, run_heavy, r, s->cfg.heavy_queue) == 0)
            return;
        drop_later(r);
        srv_problem(r, 503, NULL,
                    "the server is busy: %zu requests estimated at over %.3g units of work (--heavy-work) wait "
                    "already (--heavy-queue); try again shortly, or ask for a lower res",
                    s->cfg.heavy_queue, s->cfg.heavy_work);
    }
    /* A job that took much memory gives it back to the system, rather than keeping the peak. */
    if (r->cost.bytes > 16e6)
        malloc_trim(0);
    r->phase = SRV_DONE;
    MHD_resume_connection(r->conn);   /* the last act: the polling thread may free r from here on */
}

/* ---- the table ---- */

const srv_route srv_routes[] = {
    { "solve", "POST", "/solve", post_solve, SRV_RT_BODY | SRV_RT_JOB | SRV_RT_CACHE | SRV_RT_OUTPUT },
    { "solids", "GET", "/solids/{}", get_solid, SRV_RT_JOB | SRV_RT_CACHE | SRV_RT_OUTPUT },
    { "eval", "POST", "/solids/{}/eval", post_eval, SRV_RT_BODY | SRV_RT_JOB },
    { "request", "GET", "/solids/{}/request", get_solid_request, SRV_RT_JOB },
    { "presets", "GET", "/presets", get_presets, 0 },
    { "preset", "GET", "/presets/{}", get_preset, 0 },
    { "formats", "GET", "/formats", get_formats, 0 },
    { "livez", "GET", "/livez", get_livez, 0 },
    { "readyz", "GET", "/readyz", get_readyz, 0 },
    { "version", "GET", "/version", get_version, 0 },
    { "metrics", "GET", "/metrics", get_metrics, 0 },
    { "static", "GET", "*", srv_static_get, SRV_RT_PAGE },
};
const int srv_nroutes = (int)(sizeof srv_routes / sizeof *srv_routes);

/* 1 if path matches pattern, with the {} segment in arg; -1 if that segment is longer than argn. */
static int match(const char *pattern, const char *path, char *arg, size_t argn)
{
    if (pattern[0] == '*')
        return srv_static_find(path) >= 0;
    if (pattern[1] != path[1])   /* every pattern and path starts with '/': most rows differ next */
        return 0;
    const char *brace = strstr(pattern, "{}");
    if (!brace)
        return !strcmp(pattern, path);
    size_t pre = (size_t)(brace - pattern);
    if (strncmp(pattern, path, pre))
        return 0;
    const char *seg = path + pre, *end = strchr(seg, '/');
    size_t n = end ? (size_t)(end - seg) : strlen(seg);
    if (n == 0 || strcmp(brace + 2, seg + n))
        return 0;
    if (n >= argn)
        return -1;
    memcpy(arg, seg, n);
    arg[n] = '\0';
    return 1;
}

int srv_route_find(const char *method, const char *path, char *arg, size_t argn, char *allow, size_t allown,
                   int *status)
{
    int any = 0;
    size_t used = 0;
    allow[0] = '\0';
    for (int i = 0; i < srv_nroutes; i++) {
        if (any && srv_routes[i].path[0] == '*')
            break;   /* no static file shares a path with the API */
        int m = match(srv_routes[i].path, path, arg, argn);
        if (m < 0) {
            *status = 400;
            return -1;
        }
        if (!m)
            continue;
        any = 1;
        const char *rm = srv_routes[i].method;
        if (!strcmp(method, rm) || !strcmp(method, "OPTIONS") || (!strcmp(rm, "GET") && !strcmp(method, "HEAD")))
            return i;
    }
    *status = any ? 405 : 404;
    if (!any)
        return -1;
    /* 405: the methods the path takes. */
    for (int i = 0; i < srv_nroutes && !(used && srv_routes[i].path[0] == '*'); i++) {
        char tmp[96];
        if (match(srv_routes[i].path, path, tmp, sizeof tmp) != 1)
            continue;
        used += (size_t)snprintf(allow + used, used < allown ? allown - used : 0, "%s%s%s", used ? ", " : "",
                                 srv_routes[i].method, strcmp(srv_routes[i].method, "GET") ? "" : ", HEAD");
        if (used >= allown)
            used = allown - 1;
    }
    snprintf(allow + used, used < allown ? allown - used : 0, "%sOPTIONS", used ? ", " : "");
    return -1;
}

/* ---- the query ---- */

static const struct {
    const char *name;
    unsigned bit;
    size_t off, size;
} params[] = {
    { "format", 1, offsetof(srv_query, format), sizeof ((srv_query *)0)->format },
    { "res", 2, offsetof(srv_query, res), sizeof ((srv_query *)0)->res },
    { "compress", 4, offsetof(srv_query, compress), sizeof ((srv_query *)0)->compress },
};
#define NPARAMS (sizeof params / sizeof *params)

void srv_query_init(srv_query *q)
{
    memset(q, 0, sizeof *q);
}

/* A control character: C0, DEL, or C1 (U+0080..U+009F, in UTF-8 C2 80..C2 9F). */
static int bad_text(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c < 0x20 || c == 0x7f || (c == 0xc2 && i + 1 < n && (unsigned char)s[i + 1] >= 0x80 &&
                                      (unsigned char)s[i + 1] <= 0x9f))
            return 1;
    }
    return 0;
}

int srv_query_arg(const srv_route *rt, srv_query *q, const char *key, size_t klen, const char *value, size_t vlen,
                  char *msg, size_t n)
{
    size_t i = 0;
    if (!klen && (!value || !vlen))
        return 0;   /* an empty item, as "?&format=glb" or "?format=glb&" hold: nothing asked */
    if (rt->flags & SRV_RT_PAGE) {
        if (bad_text(key, klen) || (value && (bad_text(value, vlen) || strlen(value) != vlen))) {
            snprintf(msg, n, "the query holds a control character or a NUL");
            return -1;
        }
        return 0;
    }
    if (rt->flags & SRV_RT_OUTPUT)
        for (; i < NPARAMS; i++)
            if (strlen(params[i].name) == klen && !memcmp(params[i].name, key, klen))
                break;
    if (!(rt->flags & SRV_RT_OUTPUT) || i == NPARAMS) {
        char shown[64];
        api_text_clean(shown, sizeof shown, key, klen);
        char known[64] = "none";
        for (size_t k = 0, used = 0; (rt->flags & SRV_RT_OUTPUT) && k < NPARAMS; k++)   /* from the table */
            used += (size_t)snprintf(known + used, sizeof known - used, "%s%s", k ? ", " : "", params[k].name);
        char path[64];   /* the route's {} named, for the message */
        const char *brace = strstr(rt->path, "{}");
        if (brace)
            snprintf(path, sizeof path, "%.*s{%s}%s", (int)(brace - rt->path), rt->path,
                     strcmp(rt->name, "preset") ? "id" : "name", brace + 2);
        else
            snprintf(path, sizeof path, "%s", rt->path);
        snprintf(msg, n, "unknown query parameter \"%s\"; %s takes %s", shown, path, known);
        return -1;
    }
    if (q->seen & params[i].bit) {
        snprintf(msg, n, "the query parameter %s is given twice", params[i].name);
        return -1;
    }
    q->seen |= params[i].bit;
    if (!value || !vlen) {
        snprintf(msg, n, "the query parameter %s needs a value", params[i].name);
        return -1;
    }
    if (bad_text(value, vlen) || strlen(value) != vlen) {
        snprintf(msg, n, "the query parameter %s holds a control character or a NUL", params[i].name);
        return -1;
    }
    if (vlen >= params[i].size) {
        snprintf(msg, n, "the query parameter %s is longer than %zu characters", params[i].name, params[i].size - 1);
        return -1;
    }
    memcpy((char *)q + params[i].off, value, vlen + 1);
    return 0;
}

int srv_query_done(const srv_route *rt, srv_query *q, char *msg, size_t n)
{
    if (!(rt->flags & SRV_RT_OUTPUT))
        return 0;
    api_error err;
    if (api_format_parse(q->format[0] ? q->format : "json", &q->fmt, &err) ||
        api_res_parse(q->res[0] ? q->res : NULL, q->fmt, q->res3, &err) ||
        api_compress_parse(q->compress, q->fmt, &q->comp, &err)) {
        snprintf(msg, n, "%s", err.message);
        return -1;
    }
    return 0;
}
