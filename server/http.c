/*
 * http.c: routes and request handling of pdesolidd (http.h).
 *
 * DESIGN
 * libmicrohttpd's internal polling thread (epoll) accepts connections and
 * parses requests. The handler follows post_example.c: the first call makes
 * the request's state, further calls take the body in against a byte cap,
 * and the last call acts. Cheap routes answer at once on the polling thread.
 * Solve, solids and eval work goes to the solver threads: the handler
 * reserves a place in the queue (or answers 503), suspends the connection,
 * and submits the job; the job stores its result and resumes the connection
 * as its last act, and the handler, called again, queues the response.
 * Large outputs stream from a content-reader callback in bounded memory;
 * the stream owns its output and a reference to the cached solution.
 * cJSON's parser writes a global, so parses are serialised by json_lock.
 */
#include <arpa/inet.h>
#include <netdb.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>
#include <microhttpd.h>

#include "cache.h"
#include "http.h"
#include "id.h"
#include "metrics.h"
#include "model.h"
#include "output.h"
#include "catalog.h"
#include "pool.h"
#include "rcache.h"
#include "template.h"

enum route_id {
    R_SOLVE, R_SOLID, R_EVAL, R_PRESETS, R_PRESET, R_LIVEZ, R_READYZ, R_VERSION, R_METRICS, R_STATIC, R_NONE,
    R_COUNT
};
static const char *const route_names[R_COUNT] = { "solve", "solids", "eval", "presets", "preset", "livez",
                                                  "readyz", "version", "metrics", "static", "none" };

/* The front-end's files: a fixed set, never a path taken from the URL. */
static const struct {
    const char *url, *file, *type;
} static_files[] = {
    { "/", "index.html", "text/html; charset=utf-8" },
    { "/index.html", "index.html", "text/html; charset=utf-8" },
    { "/app.js", "app.js", "text/javascript; charset=utf-8" },
    { "/style.css", "style.css", "text/css; charset=utf-8" },
    { "/vendor/three/three.module.js", "node_modules/three/build/three.module.js", "text/javascript; charset=utf-8" },
    { "/vendor/three/three.core.js", "node_modules/three/build/three.core.js", "text/javascript; charset=utf-8" },
    { "/vendor/three/addons/loaders/GLTFLoader.js", "node_modules/three/examples/jsm/loaders/GLTFLoader.js",
      "text/javascript; charset=utf-8" },
    { "/vendor/three/addons/utils/BufferGeometryUtils.js", "node_modules/three/examples/jsm/utils/BufferGeometryUtils.js",
      "text/javascript; charset=utf-8" },
    { "/vendor/three/addons/utils/SkeletonUtils.js", "node_modules/three/examples/jsm/utils/SkeletonUtils.js",
      "text/javascript; charset=utf-8" },
    { "/vendor/three/addons/controls/OrbitControls.js", "node_modules/three/examples/jsm/controls/OrbitControls.js",
      "text/javascript; charset=utf-8" },
    { "/vendor/lil-gui/lil-gui.esm.js", "node_modules/lil-gui/dist/lil-gui.esm.js", "text/javascript; charset=utf-8" },
};
#define NSTATIC (sizeof static_files / sizeof *static_files)

struct srv_server {
    srv_config cfg;
    struct MHD_Daemon *d;
    srv_pool *pool;
    srv_cache *cache;
    srv_metrics *metrics;
    srv_rcache *rcache;
    pthread_mutex_t json_lock;   /* cJSON_Parse writes a global */
    pthread_mutex_t lock;        /* in_flight, stopping */
    pthread_cond_t idle;
    size_t in_flight;
    int stopping;
    uint16_t port;
    char *files[NSTATIC];
    size_t file_len[NSTATIC];
};

enum phase { NEW, BODY, QUEUED, DONE };

typedef struct stream stream;

typedef struct {
    srv_server *s;
    struct MHD_Connection *conn;
    enum route_id route;
    int phase;
    double t0;
    char method[8], url[256];
    char arg[96];                /* the id of /solids/{id}, the name of /presets/{name}, the static index */
    char *body;
    size_t len, cap;
    int early;                   /* a status decided before the body was read */
    char early_msg[200];
    /* The result. */
    int status;
    const char *ctype;
    char *text;                  /* a whole body, or NULL */
    size_t text_len;
    api_output *out;             /* or a stream */
    srv_entry *entry;            /* referenced while the stream lives */
    char id[API_ID_LEN + 1];
    char etag[96];
    const char *allow;           /* for 405 */
    int retry_after;
    long long sent;
    stream *live;                /* the stream sending this response, if any */
    char *key;                   /* the response cache's key of this request, or NULL */
    size_t klen;
    char timing[128];            /* Server-Timing: solve (or cache) and output */
} request;

struct stream {
    srv_server *s;
    api_output *out;
    srv_entry *entry;
    request *r;                  /* NULL once the request has completed */
    double seconds;
    long long bytes;
};

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static const char *title_of(int status)
{
    switch (status) {
    case 400: return "Bad Request";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 413: return "Content Too Large";
    case 422: return "Unprocessable Content";
    case 503: return "Service Unavailable";
    default: return "Internal Server Error";
    }
}

/* An RFC 9457 problem body as the request's result. */
static void set_problem(request *r, int status, const char *pointer, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static void set_problem(request *r, int status, const char *pointer, const char *fmt, ...)
{
    char detail[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof detail, fmt, ap);
    va_end(ap);
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", "about:blank");
    cJSON_AddStringToObject(o, "title", title_of(status));
    cJSON_AddNumberToObject(o, "status", status);
    cJSON_AddStringToObject(o, "detail", detail);
    if (pointer)
        cJSON_AddStringToObject(o, "pointer", pointer);
    free(r->text);
    r->text = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    r->text_len = r->text ? strlen(r->text) : 0;
    r->status = status;
    r->ctype = "application/problem+json";
}

/* detail reads as a sentence on its own: the pointer, then what is wrong there. */
static void set_api_error(request *r, const api_error *e)
{
    set_problem(r, e->status ? e->status : 422, e->pointer, "%s%s%s", e->pointer, e->pointer[0] ? ": " : "",
                e->message);
}

/* The response cache's key: route, format, res, and the body or the id. NULL if too large to keep. */
static void make_key(request *r)
{
    const char *fs = MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, "format");
    const char *rs = MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, "res");
    const char *tail = r->route == R_SOLVE ? (r->body ? r->body : "") : r->arg;
    size_t tl = r->route == R_SOLVE ? r->len : strlen(r->arg);
    if (tl > SRV_RCACHE_MAX_KEY)
        return;
    size_t cap = tl + 256;
    if (!(r->key = malloc(cap)))
        return;
    int n = snprintf(r->key, cap, "%c\n%.100s\n%.100s\n", r->route == R_SOLVE ? 'S' : 'G', fs ? fs : "", rs ? rs : "");
    memcpy(r->key + n, tail, tl);
    r->klen = (size_t)n + tl;
}

static void set_text(request *r, int status, const char *ctype, char *text)
{
    free(r->text);
    r->text = text;
    r->text_len = text ? strlen(text) : 0;
    r->status = text ? status : 500;
    r->ctype = ctype;
    if (!text)
        set_problem(r, 500, NULL, "out of memory");
}

/* ---- routing ---- */

static int valid_id(const char *s)
{
    size_t n = 0;
    for (; s[n]; n++)
        if (!((s[n] >= '0' && s[n] <= '9') || (s[n] >= 'a' && s[n] <= 'f')))
            return 0;
    return n == API_ID_LEN;
}

/* The route of a path, with its argument; the methods it allows in *allow. */
static enum route_id route_of(const char *url, char *arg, size_t argn, const char **allow)
{
    static const struct {
        const char *path;
        enum route_id id;
        const char *allow;
    } exact[] = {
        { "/solve", R_SOLVE, "POST, OPTIONS" },       { "/presets", R_PRESETS, "GET, OPTIONS" },
        { "/livez", R_LIVEZ, "GET, OPTIONS" },        { "/readyz", R_READYZ, "GET, OPTIONS" },
        { "/version", R_VERSION, "GET, OPTIONS" },    { "/metrics", R_METRICS, "GET, OPTIONS" },
    };
    for (size_t i = 0; i < sizeof exact / sizeof *exact; i++)
        if (!strcmp(url, exact[i].path)) {
            *allow = exact[i].allow;
            return exact[i].id;
        }
    for (size_t i = 0; i < NSTATIC; i++)
        if (!strcmp(url, static_files[i].url)) {
            snprintf(arg, argn, "%zu", i);
            *allow = "GET, OPTIONS";
            return R_STATIC;
        }
    if (!strncmp(url, "/solids/", 8)) {
        const char *id = url + 8, *slash = strchr(id, '/');
        size_t n = slash ? (size_t)(slash - id) : strlen(id);
        if (n < argn) {
            snprintf(arg, argn, "%.*s", (int)n, id);
            if (!slash) {
                *allow = "GET, OPTIONS";
                return R_SOLID;
            }
            if (!strcmp(slash, "/eval")) {
                *allow = "POST, OPTIONS";
                return R_EVAL;
            }
        }
    }
    if (!strncmp(url, "/presets/", 9) && strlen(url + 9) < argn && !strchr(url + 9, '/')) {
        snprintf(arg, argn, "%s", url + 9);
        *allow = "GET, OPTIONS";
        return R_PRESET;
    }
    *allow = NULL;
    return R_NONE;
}

static int wants_body(enum route_id r)
{
    return r == R_SOLVE || r == R_EVAL;
}

/* ---- headers ---- */

static void add_cors(srv_server *s, struct MHD_Connection *c, struct MHD_Response *resp)
{
    const char *origin = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Origin");
    if (!origin || !s->cfg.cors[0])
        return;
    int ok = !strcmp(s->cfg.cors, "*");
    size_t n = strlen(origin);
    for (const char *p = s->cfg.cors; !ok && *p;) {
        const char *e = strchr(p, ',');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        while (len && *p == ' ')
            p++, len--;
        ok = len == n && !strncmp(p, origin, n);
        p = e ? e + 1 : p + len;
    }
    if (!ok)
        return;
    MHD_add_response_header(resp, "Access-Control-Allow-Origin", !strcmp(s->cfg.cors, "*") ? "*" : origin);
    MHD_add_response_header(resp, "Vary", "Origin");
    MHD_add_response_header(resp, "Access-Control-Expose-Headers", "X-Solid-Id, ETag, Content-Length, Retry-After");
}

static enum MHD_Result queue(request *r, struct MHD_Response *resp)
{
    if (!resp)
        return MHD_NO;
    srv_server *s = r->s;
    add_cors(s, r->conn, resp);
    if (r->ctype)
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, r->ctype);
    if (r->id[0])
        MHD_add_response_header(resp, "X-Solid-Id", r->id);
    if (r->etag[0]) {
        MHD_add_response_header(resp, MHD_HTTP_HEADER_ETAG, r->etag);
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
    }
    if (r->status == 405)
        MHD_add_response_header(resp, MHD_HTTP_HEADER_ALLOW, r->allow);
    if (r->timing[0])
        MHD_add_response_header(resp, "Server-Timing", r->timing);
    if (r->retry_after) {
        char v[16];
        snprintf(v, sizeof v, "%d", r->retry_after);
        MHD_add_response_header(resp, MHD_HTTP_HEADER_RETRY_AFTER, v);
    }
    if (r->status >= 400 || r->early)
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CONNECTION, r->early ? "close" : "keep-alive");
    enum MHD_Result ok = MHD_queue_response(r->conn, (unsigned)r->status, resp);
    MHD_destroy_response(resp);
    r->phase = DONE;
    return ok;
}

/* Queues r's text (or an empty body). */
static enum MHD_Result respond_text(request *r)
{
    struct MHD_Response *resp = MHD_create_response_from_buffer(r->text_len, r->text ? r->text : (char *)"",
                                                                r->text ? MHD_RESPMEM_MUST_FREE : MHD_RESPMEM_PERSISTENT);
    if (resp)
        r->text = NULL;     /* the response owns it now */
    r->sent = (long long)r->text_len;
    return queue(r, resp);
}

static ssize_t stream_read(void *cls, uint64_t pos, char *buf, size_t max)
{
    (void)pos;
    stream *st = cls;
    double t0 = now();
    long n = api_output_read(st->out, buf, max);
    st->seconds += now() - t0;
    if (n < 0)
        return MHD_CONTENT_READER_END_WITH_ERROR;
    if (n == 0)
        return MHD_CONTENT_READER_END_OF_STREAM;
    st->bytes += n;
    if (st->r)
        st->r->sent = st->bytes;
    return n;
}

static void stream_free(void *cls)
{
    stream *st = cls;
    srv_metrics_output(st->s->metrics, st->seconds, (size_t)st->bytes);
    if (st->r)
        st->r->live = NULL;
    api_output_free(st->out);
    srv_cache_release(st->s->cache, st->entry);
    free(st);
}

static enum MHD_Result respond_stream(request *r)
{
    stream *st = calloc(1, sizeof *st);
    if (!st) {
        set_problem(r, 500, NULL, "out of memory");
        return respond_text(r);
    }
    st->s = r->s;
    st->out = r->out;
    st->entry = r->entry;
    st->r = r;
    r->out = NULL;
    r->entry = NULL;
    long long size = api_output_size(st->out);
    struct MHD_Response *resp = MHD_create_response_from_callback(size >= 0 ? (uint64_t)size : MHD_SIZE_UNKNOWN,
                                                                  256 * 1024, stream_read, st, stream_free);
    if (!resp) {
        stream_free(st);
        return MHD_NO;
    }
    r->live = st;
    return queue(r, resp);
}

/* ---- the cheap routes, on the polling thread ---- */

static enum MHD_Result quick(request *r)
{
    srv_server *s = r->s;
    char *text;
    switch (r->route) {
    case R_LIVEZ:
        set_text(r, 200, "text/plain; charset=utf-8", strdup("ok\n"));
        break;
    case R_READYZ: {
        pthread_mutex_lock(&s->lock);
        int stopping = s->stopping;
        pthread_mutex_unlock(&s->lock);
        if (stopping)
            set_problem(r, 503, NULL, "shutting down");
        else
            set_text(r, 200, "text/plain; charset=utf-8", strdup("ready\n"));
        break;
    }
    case R_VERSION: {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", "pdesolidd");
        cJSON_AddStringToObject(o, "version", SRV_VERSION);
        cJSON_AddStringToObject(o, "libmicrohttpd", MHD_get_version());
        cJSON_AddStringToObject(o, "cjson", cJSON_Version());
        text = cJSON_PrintUnformatted(o);
        cJSON_Delete(o);
        set_text(r, 200, "application/json", text);
        break;
    }
    case R_METRICS: {
        srv_cache_stats cs;
        srv_cache_stats_get(s->cache, &cs);
        pthread_mutex_lock(&s->lock);
        size_t in_flight = s->in_flight;
        pthread_mutex_unlock(&s->lock);
        set_text(r, 200, "text/plain; version=0.0.4; charset=utf-8",
                 srv_metrics_render(s->metrics, &cs, srv_pool_depth(s->pool), in_flight, srv_rcache_hits(s->rcache)));
        break;
    }
    case R_PRESETS:
        set_text(r, 200, "application/json", api_presets_json());
        break;
    case R_PRESET: {
        const api_preset *ps = api_preset_find(r->arg);
        if (!ps)
            set_problem(r, 404, NULL, "no preset \"%.60s\"; GET /presets lists them", r->arg);
        else
            set_text(r, 200, "application/json", api_preset_json(ps));
        break;
    }
    case R_STATIC: {
        size_t i = (size_t)atoi(r->arg);
        if (!s->files[i]) {
            set_problem(r, 404, NULL, "%s is not installed in %s; run `make run`", static_files[i].file, s->cfg.web);
            break;
        }
        struct MHD_Response *resp =
            MHD_create_response_from_buffer(s->file_len[i], s->files[i], MHD_RESPMEM_PERSISTENT);
        r->status = 200;
        r->ctype = static_files[i].type;
        r->sent = (long long)s->file_len[i];
        if (resp)
            MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
        return queue(r, resp);
    }
    default:
        set_problem(r, 404, NULL, "no such resource: %s; the API is described in docs/API.md", r->url);
        break;
    }
    return respond_text(r);
}

/* ---- the solver threads' jobs ---- */

typedef struct {
    api_model *model;
} solve_arg;

static int solve_model(void *arg, pde_solution **out, api_error *err)
{
    return api_solve(((solve_arg *)arg)->model, out, err);
}

/* format and res from the query; 0, or -1 with the problem set. */
static int output_args(request *r, api_format *f, unsigned res[3])
{
    const char *fs = MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, "format");
    const char *rs = MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, "res");
    api_error err;
    if (api_format_parse(fs ? fs : "json", f, &err) || api_res_parse(rs, *f, res, &err)) {
        set_problem(r, 422, NULL, "%s", err.message);
        return -1;
    }
    return 0;
}

/* The response of a solved entry: 304, or an output stream. Takes over the reference. */
static void answer_entry(request *r, srv_entry *e, api_format f, const unsigned res[3])
{
    srv_server *s = r->s;
    snprintf(r->id, sizeof r->id, "%s", srv_entry_id(e));
    snprintf(r->etag, sizeof r->etag, "\"%s.%s.%ux%ux%u\"", r->id, api_format_info_of(f)->name, res[0], res[1], res[2]);
    const char *inm = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_IF_NONE_MATCH);
    if (inm && (strstr(inm, r->etag) || !strcmp(inm, "*"))) {
        r->status = 304;
        r->ctype = NULL;
        srv_cache_release(s->cache, e);
        return;
    }
    const pde_props *props = NULL;
    if (f == API_FMT_JSON || f == API_FMT_GLTF || f == API_FMT_GLB)
        props = srv_entry_props(e);
    api_error err;
    double t0 = now();
    api_output *o = api_output_open(srv_entry_solution(e), r->id, props, f, res, NULL, &err);
    size_t tl = strlen(r->timing);
    if (!o) {
        srv_cache_release(s->cache, e);
        set_problem(r, err.status == 422 ? 422 : 500, NULL, "%s", err.message);
        return;
    }
    r->status = 200;
    r->ctype = api_format_info_of(f)->mime;
    long long size = api_output_size(o);
    if (r->key && size >= 0 && size <= (long long)SRV_RCACHE_MAX_ITEM) {
        /* Small and of known size: render it here, and keep it for the next identical request. */
        char *bytes = malloc((size_t)size + 1);
        long n = bytes ? 0 : -1;
        for (long k = 1; n >= 0 && n < size && k > 0; n = k < 0 ? -1 : n + k)
            k = api_output_read(o, bytes + n, (size_t)(size - n));   /* bounded work per call */
        api_output_free(o);
        srv_cache_release(s->cache, e);
        srv_metrics_output(s->metrics, now() - t0, n > 0 ? (size_t)n : 0);
        snprintf(r->timing + tl, sizeof r->timing - tl, "%soutput;dur=%.3f", tl ? ", " : "", (now() - t0) * 1e3);
        if (n != size) {
            free(bytes);
            set_problem(r, 500, NULL, "out of memory");
            return;
        }
        bytes[n] = '\0';
        srv_rcache_put(s->rcache, r->key, r->klen, bytes, (size_t)n, r->ctype, r->id, r->etag);
        r->text = bytes;
        r->text_len = (size_t)n;
        return;
    }
    srv_metrics_output(s->metrics, now() - t0, 0);
    snprintf(r->timing + tl, sizeof r->timing - tl, "%soutput;desc=\"streamed\";dur=%.3f", tl ? ", " : "",
             (now() - t0) * 1e3);
    r->out = o;
    r->entry = e;
}

static void job_solve(request *r)
{
    srv_server *s = r->s;
    api_format f;
    unsigned res[3];
    if (output_args(r, &f, res))
        return;
    api_error err;
    pthread_mutex_lock(&s->json_lock);
    api_model *m = api_model_parse(r->body ? r->body : "", r->len, &err);
    pthread_mutex_unlock(&s->json_lock);
    if (!m) {
        set_api_error(r, &err);
        return;
    }
    char id[API_ID_LEN + 1];
    pde_diag d;
    if (api_model_id(api_model_get(m), id, &d) != PDE_OK) {
        /* Invalid in a way the solve reports with a pointer. */
        pde_solution *sol = NULL;
        api_solve(m, &sol, &err);
        pde_solution_free(sol);
        api_model_free(m);
        set_api_error(r, &err);
        return;
    }
    solve_arg sa = { m };
    int hit;
    double t0 = now();
    srv_entry *e = srv_cache_get(s->cache, id, solve_model, &sa, &hit, &err);
    double dt = now() - t0;
    if (!hit)
        srv_metrics_solve(s->metrics, dt);
    if (hit)
        snprintf(r->timing, sizeof r->timing, "solve;desc=\"cached\";dur=%.3f", dt * 1e3);
    else
        snprintf(r->timing, sizeof r->timing, "solve;dur=%.3f", dt * 1e3);
    api_model_free(m);
    if (!e) {
        set_api_error(r, &err);
        return;
    }
    answer_entry(r, e, f, res);
}

static void job_solid(request *r)
{
    api_format f;
    unsigned res[3];
    if (output_args(r, &f, res))
        return;
    srv_entry *e = valid_id(r->arg) ? srv_cache_find(r->s->cache, r->arg) : NULL;
    if (!e) {
        set_problem(r, 404, NULL,
                    "no solid %.40s in the cache: it was never solved here, or was evicted; POST its model to /solve",
                    r->arg);
        return;
    }
    answer_entry(r, e, f, res);
}

static void job_eval(request *r)
{
    srv_server *s = r->s;
    srv_entry *e = valid_id(r->arg) ? srv_cache_find(s->cache, r->arg) : NULL;
    if (!e) {
        set_problem(r, 404, NULL, "no solid %.40s in the cache: POST its model to /solve first", r->arg);
        return;
    }
    api_error err;
    double *pts = NULL;
    size_t n = 0;
    int derivs = 0;
    pthread_mutex_lock(&s->json_lock);
    int rc = api_eval_parse(r->body ? r->body : "", r->len, s->cfg.max_points, &pts, &n, &derivs, &err);
    pthread_mutex_unlock(&s->json_lock);
    if (rc) {
        srv_cache_release(s->cache, e);
        set_api_error(r, &err);
        return;
    }
    const pde_solution *sol = srv_entry_solution(e);
    double *v = malloc((n ? n : 1) * 12 * sizeof *v);
    if (!v) {
        free(pts);
        srv_cache_release(s->cache, e);
        set_problem(r, 500, NULL, "out of memory");
        return;
    }
    double *du = v + 3 * n, *dv = v + 6 * n, *dw = v + 9 * n;
    for (size_t i = 0; i < n; i++)
        pde_eval_d(sol, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], v + 3 * i, derivs ? du + 3 * i : NULL,
                   derivs ? dv + 3 * i : NULL, derivs ? dw + 3 * i : NULL);
    snprintf(r->id, sizeof r->id, "%s", srv_entry_id(e));
    srv_cache_release(s->cache, e);
    char *json = api_eval_json(r->id, v, derivs ? du : NULL, derivs ? dv : NULL, derivs ? dw : NULL, n);
    free(pts);
    free(v);
    set_text(r, 200, "application/json", json);
}

static void run_job(void *arg)
{
    request *r = arg;
    switch (r->route) {
    case R_SOLVE: job_solve(r); break;
    case R_SOLID: job_solid(r); break;
    case R_EVAL: job_eval(r); break;
    default: set_problem(r, 500, NULL, "no job for this route"); break;
    }
    r->phase = DONE;
    MHD_resume_connection(r->conn);   /* the last act: the polling thread may free r from here on */
}

/* ---- the handler ---- */

static enum MHD_Result count_length(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    (void)kind;
    (void)value;
    if (!strcasecmp(key, MHD_HTTP_HEADER_CONTENT_LENGTH))
        (*(int *)cls)++;
    return MHD_YES;
}

/* Appends the query's arguments to the URL kept for the access log. */
static enum MHD_Result add_arg(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    (void)kind;
    request *r = cls;
    size_t n = strlen(r->url);
    snprintf(r->url + n, sizeof r->url - n, "%c%s%s%s", strchr(r->url, '?') ? '&' : '?', key, value ? "=" : "",
             value ? value : "");
    return MHD_YES;
}

static request *begin(srv_server *s, struct MHD_Connection *conn, const char *url, const char *method)
{
    request *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    r->s = s;
    r->conn = conn;
    r->t0 = now();
    snprintf(r->method, sizeof r->method, "%s", method);
    snprintf(r->url, sizeof r->url, "%s", url);
    r->route = route_of(url, r->arg, sizeof r->arg, &r->allow);
    MHD_get_connection_values(conn, MHD_GET_ARGUMENT_KIND, add_arg, r);
    pthread_mutex_lock(&s->lock);
    s->in_flight++;
    int stopping = s->stopping;
    pthread_mutex_unlock(&s->lock);
    int lengths = 0;
    MHD_get_connection_values(conn, MHD_HEADER_KIND, count_length, &lengths);
    const char *cl = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
    if (lengths > 1) {
        r->early = 400;
        snprintf(r->early_msg, sizeof r->early_msg, "the request has %d Content-Length headers; it may have one",
                 lengths);
    } else if (cl && strtoull(cl, NULL, 10) > s->cfg.max_body) {
        r->early = 413;
        snprintf(r->early_msg, sizeof r->early_msg, "the body of %s bytes is more than the limit of %zu bytes (--max-body)",
                 cl, s->cfg.max_body);
    } else if (stopping) {
        r->early = 503;
        snprintf(r->early_msg, sizeof r->early_msg, "the server is shutting down");
    }
    return r;
}

static enum MHD_Result handler(void *cls, struct MHD_Connection *conn, const char *url, const char *method,
                               const char *version, const char *upload, size_t *upload_size, void **con_cls)
{
    (void)version;
    srv_server *s = cls;
    request *r = *con_cls;
    if (!r) {
        if (!(r = begin(s, conn, url, method)))
            return MHD_NO;
        *con_cls = r;
        r->phase = BODY;
        /* An early answer needs no body: give it now, and the connection closes. */
        if (r->early == 413 || r->early == 400) {
            set_problem(r, r->early, NULL, "%s", r->early_msg);
            return respond_text(r);
        }
        return MHD_YES;
    }
    if (*upload_size) {
        if (!r->early && wants_body(r->route)) {
            if (r->len + *upload_size > s->cfg.max_body) {
                r->early = 413;
                snprintf(r->early_msg, sizeof r->early_msg, "the body is more than the limit of %zu bytes (--max-body)",
                         s->cfg.max_body);
            } else {
                if (r->len + *upload_size + 1 > r->cap) {
                    size_t cap = r->cap ? r->cap : 4096;
                    while (cap < r->len + *upload_size + 1)
                        cap *= 2;
                    char *b = realloc(r->body, cap);
                    if (!b)
                        return MHD_NO;
                    r->body = b;
                    r->cap = cap;
                }
                memcpy(r->body + r->len, upload, *upload_size);
                r->len += *upload_size;
                r->body[r->len] = '\0';
            }
        }
        *upload_size = 0;
        return MHD_YES;
    }
    if (r->phase == DONE)      /* resumed: the job's result is ready */
        return r->out ? respond_stream(r) : respond_text(r);

    if (r->early) {
        set_problem(r, r->early, NULL, "%s", r->early_msg);
        if (r->early == 503)
            r->retry_after = 1;
        return respond_text(r);
    }
    if (!strcmp(method, MHD_HTTP_METHOD_OPTIONS) && r->route != R_NONE) {
        r->status = 204;
        struct MHD_Response *resp = MHD_create_response_from_buffer(0, (void *)"", MHD_RESPMEM_PERSISTENT);
        if (resp) {
            MHD_add_response_header(resp, "Access-Control-Allow-Methods", r->allow);
            MHD_add_response_header(resp, "Access-Control-Allow-Headers", "Content-Type, If-None-Match");
            MHD_add_response_header(resp, "Access-Control-Max-Age", "600");
        }
        return queue(r, resp);
    }
    if (r->route != R_NONE) {
        int get = !strcmp(method, MHD_HTTP_METHOD_GET) || !strcmp(method, MHD_HTTP_METHOD_HEAD);
        int post = !strcmp(method, MHD_HTTP_METHOD_POST);
        if ((wants_body(r->route) && !post) || (!wants_body(r->route) && !get)) {
            set_problem(r, 405, NULL, "%s is not allowed on %s; use %s", method, url, r->allow);
            return respond_text(r);
        }
    }
    if (r->route != R_SOLVE && r->route != R_SOLID && r->route != R_EVAL)
        return quick(r);
    if (r->route != R_EVAL) {
        /* A request answered before: its response is kept, no solver thread needed. */
        make_key(r);
        const char *inm = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_IF_NONE_MATCH);
        int cors = s->cfg.cors[0] && MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Origin");
        srv_rhit h;
        if (r->key && !inm && !cors && srv_rcache_queue(s->rcache, r->key, r->klen, conn, &h)) {
            r->status = 200;
            r->sent = (long long)h.len;
            snprintf(r->id, sizeof r->id, "%.32s", h.id);
            r->phase = DONE;
            return MHD_YES;
        }
        if (r->key && (inm || cors) && srv_rcache_copy(s->rcache, r->key, r->klen, &h)) {
            snprintf(r->id, sizeof r->id, "%.32s", h.id);
            snprintf(r->etag, sizeof r->etag, "%s", h.etag);
            if (inm && (strstr(inm, h.etag) || !strcmp(inm, "*"))) {
                free(h.copy);
                r->status = 304;
                return respond_text(r);
            }
            set_text(r, 200, h.ctype, h.copy);
            r->text_len = h.len;
            return respond_text(r);
        }
    }
    if (srv_pool_reserve(s->pool)) {
        r->retry_after = 1;
        set_problem(r, 503, NULL, "all %d solver threads are busy and %zu jobs are waiting (--queue); try again",
                    s->cfg.threads, s->cfg.queue);
        return respond_text(r);
    }
    r->phase = QUEUED;
    MHD_suspend_connection(conn);      /* before the job exists, so that its resume finds it suspended */
    srv_pool_submit(s->pool, run_job, r);
    return MHD_YES;
}

static void completed(void *cls, struct MHD_Connection *conn, void **con_cls, enum MHD_RequestTerminationCode toe)
{
    srv_server *s = cls;
    request *r = *con_cls;
    if (!r)
        return;
    *con_cls = NULL;
    double dt = now() - r->t0;
    int status = r->status ? r->status : 500;
    srv_metrics_request(s->metrics, r->route, status, dt);
    if (!s->cfg.quiet) {
        char ip[INET6_ADDRSTRLEN] = "-";
        const union MHD_ConnectionInfo *ci = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
        if (ci && ci->client_addr) {
            const struct sockaddr *sa = ci->client_addr;
            if (sa->sa_family == AF_INET)
                inet_ntop(AF_INET, &((const struct sockaddr_in *)sa)->sin_addr, ip, sizeof ip);
            else if (sa->sa_family == AF_INET6)
                inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)sa)->sin6_addr, ip, sizeof ip);
        }
        fprintf(stderr, "%s \"%s %s\" %d %lld %.2fms%s%s%s\n", ip, r->method, r->url, status, r->sent, dt * 1e3,
                r->id[0] ? " id=" : "", r->id, toe == MHD_REQUEST_TERMINATED_COMPLETED_OK ? "" : " (aborted)");
    }
    if (r->live)
        r->live->r = NULL;
    api_output_free(r->out);
    srv_cache_release(s->cache, r->entry);
    free(r->body);
    free(r->text);
    free(r->key);
    free(r);
    pthread_mutex_lock(&s->lock);
    if (--s->in_flight == 0)
        pthread_cond_broadcast(&s->idle);
    pthread_mutex_unlock(&s->lock);
}

static void connection_event(void *cls, struct MHD_Connection *conn, void **socket_context,
                             enum MHD_ConnectionNotificationCode toe)
{
    (void)conn;
    (void)socket_context;
    srv_server *s = cls;
    srv_metrics_connection(s->metrics, toe == MHD_CONNECTION_NOTIFY_STARTED ? 1 : -1);
}

/* ---- start and stop ---- */

static void load_static(srv_server *s)
{
    for (size_t i = 0; i < NSTATIC; i++) {
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", s->cfg.web, static_files[i].file);
        FILE *f = fopen(path, "rb");
        if (!f)
            continue;
        if (fseek(f, 0, SEEK_END) == 0) {
            long n = ftell(f);
            if (n >= 0 && fseek(f, 0, SEEK_SET) == 0 && (s->files[i] = malloc((size_t)n + 1))) {
                s->file_len[i] = fread(s->files[i], 1, (size_t)n, f);
            }
        }
        fclose(f);
    }
}

static void free_server(srv_server *s)
{
    if (s->pool)
        srv_pool_destroy(s->pool);
    srv_cache_destroy(s->cache);
    srv_rcache_destroy(s->rcache);
    srv_metrics_destroy(s->metrics);
    for (size_t i = 0; i < NSTATIC; i++)
        free(s->files[i]);
    pthread_mutex_destroy(&s->json_lock);
    pthread_mutex_destroy(&s->lock);
    pthread_cond_destroy(&s->idle);
    free(s);
}

srv_server *srv_start(const srv_config *c, char *err, size_t errlen)
{
    srv_server *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    s->cfg = *c;
    pthread_mutex_init(&s->json_lock, NULL);
    pthread_mutex_init(&s->lock, NULL);
    pthread_cond_init(&s->idle, NULL);
    s->cache = srv_cache_create(c->cache_bytes);
    /* Finished responses: an eighth of the solution cache's bound, at least 4 MiB. */
    s->rcache = srv_rcache_create(c->cache_bytes / 8 > (4u << 20) ? c->cache_bytes / 8 : 4u << 20);
    s->metrics = srv_metrics_create(route_names, R_COUNT);
    s->pool = srv_pool_create(c->threads, c->queue);
    if (!s->cache || !s->rcache || !s->metrics || !s->pool) {
        snprintf(err, errlen, "out of memory, or a solver thread could not start");
        free_server(s);
        return NULL;
    }
    load_static(s);
    struct addrinfo hints = { .ai_flags = AI_PASSIVE | AI_NUMERICHOST, .ai_socktype = SOCK_STREAM }, *ai;
    char port[8];
    snprintf(port, sizeof port, "%u", c->port);
    int gai = getaddrinfo(c->bind, port, &hints, &ai);
    if (gai) {
        snprintf(err, errlen, "--bind %s: %s (give a numeric IPv4 or IPv6 address)", c->bind, gai_strerror(gai));
        free_server(s);
        return NULL;
    }
    unsigned flags = MHD_USE_EPOLL_INTERNAL_THREAD | MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ERROR_LOG;
    if (ai->ai_family == AF_INET6)
        flags |= MHD_USE_IPv6;
    s->d = MHD_start_daemon(flags, (uint16_t)c->port, NULL, NULL, handler, s, MHD_OPTION_SOCK_ADDR, ai->ai_addr,
                            MHD_OPTION_CONNECTION_TIMEOUT, c->timeout, MHD_OPTION_PER_IP_CONNECTION_LIMIT, c->per_ip,
                            MHD_OPTION_CONNECTION_LIMIT, c->max_conns, MHD_OPTION_NOTIFY_COMPLETED, completed, s,
                            MHD_OPTION_NOTIFY_CONNECTION, connection_event, s, MHD_OPTION_END);
    freeaddrinfo(ai);
    if (!s->d) {
        snprintf(err, errlen, "cannot listen on %s port %u (in use, or not an address of this machine)", c->bind,
                 c->port);
        free_server(s);
        return NULL;
    }
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(s->d, MHD_DAEMON_INFO_BIND_PORT);
    s->port = info ? info->port : (uint16_t)c->port;
    return s;
}

uint16_t srv_port(const srv_server *s)
{
    return s->port;
}

void srv_stop(srv_server *s)
{
    pthread_mutex_lock(&s->lock);
    s->stopping = 1;
    pthread_mutex_unlock(&s->lock);
    int fd = MHD_quiesce_daemon(s->d);     /* no new connections */
    if (fd >= 0)
        close(fd);
    /* Requests in flight finish: the solver threads resume theirs, streams run out. */
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_sec += s->cfg.grace;
    pthread_mutex_lock(&s->lock);
    while (s->in_flight > 0)
        if (pthread_cond_timedwait(&s->idle, &s->lock, &until))
            break;
    pthread_mutex_unlock(&s->lock);
    /* Every queued job resumes its connection before the pool stops, so none stays suspended. */
    srv_pool_destroy(s->pool);
    s->pool = NULL;
    MHD_stop_daemon(s->d);
    free_server(s);
}
