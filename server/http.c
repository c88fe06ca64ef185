/*
 * http.c: pdesolidd's HTTP edge (http.h): the libmicrohttpd daemon, a
 * request's lifecycle, and start and stop.
 *
 * DESIGN
 * libmicrohttpd's polling threads (--http-threads, epoll) accept
 * connections and parse requests; they never compute. The handler follows
 * post_example.c: the first call makes the request's state and decides
 * what it can from the headers alone (framing, size, route, query, origin);
 * further calls take the body in against a byte cap and the request's total
 * deadline; the last call answers. Rows of the route table without
 * SRV_RT_JOB answer at once. Job rows first look in the response cache;
 * else the handler reserves a place in the solver queue (or answers 503),
 * suspends the connection and submits the job, whose last act is to resume
 * it, and the handler, called again, sends the result: a whole body, or a
 * stream that the solver threads fill (stream.c); or, when the job saw its
 * client close the connection, closes it too, without an answer (499).
 * A request refused before its body was read still has its body read and
 * discarded, bounded in bytes and time as nginx's lingering close, so that
 * the client, which is still writing, can read the answer.
 */
#include <arpa/inet.h>
#include <stdarg.h>
#include <math.h>
#include <netdb.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "host.h"
#include "http.h"
#include "internal.h"
#include "strict.h"

/* Discarding a refused body: at most this many bytes, and this long. */
#define DRAIN_BYTES (16u << 20)
#define DRAIN_SECONDS 5.0

/* Connections beyond --max-conns that are accepted only to be answered 503 (each for at most --timeout idle, or
 * one request); past these, a new connection is closed at once. libmicrohttpd's own limit is never reached: at it,
 * with the inter-thread channel that suspending needs, it stops accepting, and new clients wait in the listen
 * queue unanswered. */
#define SPARE_CONNS 64u

/* The longest request target (path and query) and the most bytes of header lines pdesolidd takes: past them a 414
 * or a 431 problem. libmicrohttpd answers with its own HTML page (no hook changes it in 0.9.75) when the request line
 * and headers do not fit a connection's memory, so that is set well above both (it is committed only as used). */
#define MAX_TARGET (32u << 10)
#define MAX_HEADERS (32u << 10)
#define CONN_MEMORY (128u << 10)

/* ---- the request's key for the response cache ---- */

/* Route, format, res, compress, then the body or the path's argument: the whole request, nothing cut. */
static void make_key(srv_req *r)
{
    const char *tail = r->body ? r->body : r->arg;
    size_t tl = r->body ? r->len : strlen(r->arg);
    if (tl > SRV_RCACHE_MAX_KEY)
        return;
    size_t cap = tl + sizeof r->q.format + sizeof r->q.res + sizeof r->q.compress + 16;
    if (!(r->key = malloc(cap)))
        return;
    char *k = r->key;
    *k++ = (char)('A' + r->route);   /* a letter per row of the table */
    *k++ = '\n';
    size_t fl = strlen(r->q.format), rl = strlen(r->q.res);
    memcpy(k, r->q.format, fl);
    k += fl;
    *k++ = '\n';
    memcpy(k, r->q.res, rl);
    k += rl;
    *k++ = '\n';
    const char *cn = api_compress_name(r->q.comp);   /* as parsed: "" and "none" are one answer */
    memcpy(k, cn, strlen(cn));
    k += strlen(cn);
    *k++ = '\n';
    memcpy(k, tail, tl);
    r->klen = (size_t)(k - r->key) + tl;
}

/* What a 413 suggests: a loft's profiles are the usual large bodies, and keep harmonics below half their
 * points. Only /solve takes a loft; another route's body (eval's points) gets the limit alone. A
 * Content-Length over the limit is refused before the route is found: then the path tells. */
static const char *body_hint(const srv_req *r)
{
    const int solve = r->route < srv_nroutes ? !strcmp(srv_routes[r->route].name, "solve")
                                             : !strcmp(r->path, "/solve");
    if (!solve)
        return "";
    return "; if this is a loft, its profiles need no more points than twice the highest harmonic they should "
           "keep (see docs/API.md), or run the CLI offline, which has no such limit";
}

/* ---- the first call: what the headers decide ---- */

/* What a connection carries from request to request. */
typedef struct {
    int nul;         /* the request's path or query held %00 */
    int authority;   /* the target, in absolute form, has an authority with userinfo (@) or %-escapes */
    int over;        /* opened beyond --max-conns: its requests are answered 503 */
    size_t target;   /* the current request's target, in bytes as sent */
    srv_watched w;   /* its head's deadline (watch.h) */
} conn_state;


typedef struct {
    int lengths, encodings, hosts;
    size_t bytes;      /* of the header lines: name, ": ", value, CRLF */
    srv_req *r;
    const char *bad;   /* what is wrong with a header, or NULL */
} header_scan;

/* RFC 9110's token characters, which a header's name is made of. */
static int token(const char *s, size_t n)
{
    static const char extra[] = "!#$%&'*+-.^_`|~";
    for (size_t i = 0; i < n; i++)
        if (!((s[i] >= 'a' && s[i] <= 'z') || (s[i] >= 'A' && s[i] <= 'Z') || (s[i] >= '0' && s[i] <= '9') ||
              (s[i] && strchr(extra, s[i]))))
            return 0;
    return n > 0;
}

static enum MHD_Result scan_header(void *cls, enum MHD_ValueKind kind, const char *key, size_t klen,
                                   const char *value, size_t vlen)
{
    (void)kind;
    header_scan *h = cls;
    h->bytes += klen + vlen + 4;
    if (!h->bad && !token(key, klen))
        h->bad = "a header's name is not a token (RFC 9110: letters, digits and !#$%&'*+-.^_`|~)";
    for (size_t i = 0; value && i < vlen && !h->bad; i++)
        if (((unsigned char)value[i] < 0x20 && value[i] != '\t') || value[i] == 0x7f)
            h->bad = "a header's value holds a control character";
    if (!strcasecmp(key, MHD_HTTP_HEADER_HOST))
        h->hosts++;
    if (!strcasecmp(key, MHD_HTTP_HEADER_CONTENT_LENGTH))
        h->lengths++;
    if (!strcasecmp(key, MHD_HTTP_HEADER_TRANSFER_ENCODING))
        h->encodings++;
    if (!strcasecmp(key, "X-Request-Id") && srv_request_id_ok(value))
        snprintf(h->r->rid, sizeof h->r->rid, "%s", value);
    return MHD_YES;
}

typedef struct {
    srv_req *r;
    int bad;
    char msg[200];
    size_t used;
} query_scan;

static enum MHD_Result scan_arg(void *cls, enum MHD_ValueKind kind, const char *key, size_t klen, const char *value,
                                size_t vlen)
{
    (void)kind;
    query_scan *qs = cls;
    srv_req *r = qs->r;
    int n = snprintf(r->query + qs->used, sizeof r->query - qs->used, "%s%.*s%s%.*s", qs->used ? "&" : "", (int)klen,
                     key, value ? "=" : "", value ? (int)vlen : 0, value ? value : "");
    qs->used = n < 0 ? qs->used : qs->used + (size_t)n < sizeof r->query ? qs->used + (size_t)n : sizeof r->query - 1;
    if (!qs->bad && r->route < srv_nroutes &&
        srv_query_arg(&srv_routes[r->route], &r->q, key, klen, value, vlen, qs->msg, sizeof qs->msg))
        qs->bad = 1;
    return MHD_YES;
}

/* Names the first query argument holding a literal %00. */
static enum MHD_Result find_nul(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    (void)kind;
    if (!strstr(key, "%00") && !(value && strstr(value, "%00")))
        return MHD_YES;
    char k[32];
    api_text_clean(k, sizeof k, key, strlen(key));
    snprintf(cls, 64, "the query parameter %s", k);
    return MHD_NO;
}

/* The first content coding other than identity in any Content-Encoding line (a list: "identity, gzip", or
 * two lines), into cls (64 bytes, cleaned for the message); an empty value is no coding. */
static enum MHD_Result find_coding(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    (void)kind;
    if (strcasecmp(key, MHD_HTTP_HEADER_CONTENT_ENCODING) || !value)
        return MHD_YES;
    for (const char *p = value; *p;) {
        p += strspn(p, " \t,");
        const size_t n = strcspn(p, " \t,");
        if (n && !(n == 8 && !strncasecmp(p, "identity", 8))) {
            api_text_clean(cls, 64, p, n);
            return MHD_NO;
        }
        p += n;
    }
    return MHD_YES;
}

/* Content-Length as digits only, within uint64; -1 if absent, -2 if malformed. */
static long long content_length(struct MHD_Connection *c)
{
    const char *cl = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
    if (!cl)
        return -1;
    unsigned long long v = 0;
    if (!*cl)
        return -2;
    for (const char *p = cl; *p; p++) {
        if (*p < '0' || *p > '9' || v > (1ull << 62) / 10)
            return -2;
        v = v * 10 + (unsigned)(*p - '0');
    }
    return (long long)v;
}

/* Decides what the headers alone decide; r->decided when the answer is set. Returns 1 to answer now. */
static int admit(srv_req *r, const char *method)
{
    srv_server *s = r->s;
    header_scan h = { .r = r };
    MHD_get_connection_values_n(r->conn, MHD_HEADER_KIND, scan_header, &h);
    if (!r->rid[0])
        srv_request_id_make(r->rid);
    long long cl = content_length(r->conn);
    /* Framing that cannot be trusted: answer and close without reading a byte of body. */
    const char *te = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_TRANSFER_ENCODING);
    if (h.lengths > 1 || cl == -2 || (h.encodings && h.lengths) || h.encodings > 1 ||
        (te && strcasecmp(te, "chunked"))) {
        r->close = r->decided = 1;
        int coding = te && strcasecmp(te, "chunked") && !h.lengths && h.encodings == 1;
        srv_problem(r, coding ? 501 : 400, NULL, "%s",
                    h.lengths > 1  ? "the request has more than one Content-Length header"
                    : cl == -2     ? "the Content-Length header is not a number of bytes"
                    : h.lengths    ? "the request has both Transfer-Encoding and Content-Length; it may have one"
                    : coding       ? "the only Transfer-Encoding taken is chunked"
                                   : "the request has more than one Transfer-Encoding header");
        return 1;
    }
    /* An absolute-form target's authority stands for Host (RFC 9112 3.2.2; begin() kept it). */
    if (!r->host)
        r->host = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_HOST);
    /* libmicrohttpd's strict mode refuses these with an HTML page; pdesolidd refuses them with a problem. */
    const union MHD_ConnectionInfo *ci = MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    conn_state *cs = ci ? ci->socket_context : NULL;
    const int target = r->host == r->target_host, hosts = h.hosts != 1 && !strcmp(r->version, MHD_HTTP_VERSION_1_1);
    const char *bad = h.bad  ? h.bad
                      : hosts ? "an HTTP/1.1 request needs exactly one Host header"
                      : target && ((cs && cs->authority) || strlen(r->host) >= sizeof r->target_host - 1)
                          ? "the request target's host holds userinfo (@) or %-escapes, or is too long; send the host alone"
                      : target && !*r->host ? "the request target's host is empty"
                      : r->host && !*r->host ? "the Host header is empty; it names the server the request is for (RFC 9110 7.2)"
                                             : NULL;
    if (bad) {
        r->close = r->decided = 1;
        srv_problem(r, 400, NULL, "%s", bad);
        return 1;
    }
    if ((cs && cs->target > MAX_TARGET) || h.bytes > MAX_HEADERS) {
        r->decided = 1;
        if (h.bytes > MAX_HEADERS)
            srv_problem(r, 431, NULL, "the request's header lines are %zu bytes, more than the limit of %u", h.bytes,
                        MAX_HEADERS);
        else
            srv_problem(r, 414, NULL, "the request target (path and query) is %zu bytes, more than the limit of %u",
                        cs->target, MAX_TARGET);
        return 0;
    }
    int stopping = atomic_load(&s->stopping);
    if (cl > (long long)s->cfg.max_body) {
        const char *expect = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_EXPECT);
        r->decided = r->close = 1;
        srv_problem(r, 413, NULL, "the body of %lld bytes is more than the limit of %zu bytes (--max-body)%s", cl,
                    s->cfg.max_body, body_hint(r));
        /* Expect: 100-continue: the client waits, and sends nothing. Too large to discard: close. */
        return (expect && !strcasecmp(expect, "100-continue")) || cl > (long long)DRAIN_BYTES;
    }
    if (cs && cs->nul) {
        /* unescape() kept the %00 literal: find where, to name it. */
        cs->nul = 0;
        r->decided = 1;
        char where[64] = "the path";
        if (!strstr(r->path, "%00"))
            MHD_get_connection_values(r->conn, MHD_GET_ARGUMENT_KIND, find_nul, where);
        srv_problem(r, 400, NULL, "%s holds a NUL (%%00), which no part of a request may", where);
        return 0;
    }
    /* Before the route, so that a rebound name learns nothing, not even which paths exist (host.h). */
    const char *host = r->host;
    if (!srv_host_allowed(s->cfg.allow_host, host)) {
        r->decided = 1;
        int name = (int)srv_host_name(host);
        srv_problem(r, 403, NULL, "the %s %.200s names neither an IP address, localhost nor a host allowed "
                    "here (a guard against DNS rebinding)%s%.*s", r->host == r->target_host ? "request target's host" : "Host header", host,
                    name ? "; if it is this server's name, start pdesolidd with --allow-host " : "; see --allow-host",
                    name, host);
        return 0;
    }
    if (stopping) {   /* at once, body or not: waiting for a body would hold the exit back */
        r->decided = r->close = 1;
        srv_problem(r, 503, NULL, "the server is shutting down");
        return 1;
    }
    if (cs && cs->over) {
        r->decided = r->close = 1;
        srv_problem(r, 503, NULL, "the server has its limit of %u connections open (--max-conns); try again",
                    s->cfg.max_conns);
        return 0;
    }
    int status = 0;
    r->route = srv_route_find(method, r->path, r->arg, sizeof r->arg, r->allow, sizeof r->allow, &status);
    query_scan qs = { .r = r };
    if (r->route < 0)
        r->route = srv_nroutes;
    srv_query_init(&r->q);
    MHD_get_connection_values_n(r->conn, MHD_GET_ARGUMENT_KIND, scan_arg, &qs);
    if (r->route == srv_nroutes) {
        r->decided = 1;
        if (status == 405)
            srv_problem(r, 405, NULL, "%s is not allowed on %s; use %s", method, r->path, r->allow);
        else if (status == 400)
            srv_problem(r, 400, NULL, "a segment of the path is too long");
        else
            srv_problem(r, 404, NULL, "no such resource: %s; the API is described in docs/API.md and /openapi.yaml",
                        r->path);
        return 0;
    }
    if (qs.bad || srv_query_done(&srv_routes[r->route], &r->q, qs.msg, sizeof qs.msg)) {
        r->decided = 1;   /* a malformed query is a bad request; a well-formed value out of range is not */
        srv_problem(r, qs.bad ? 400 : 422, NULL, "%s", qs.msg);
        return 0;
    }
    char coding[64] = "";
    if (srv_routes[r->route].flags & SRV_RT_BODY)
        MHD_get_connection_values(r->conn, MHD_HEADER_KIND, find_coding, coding);
    if (*coding) {
        r->decided = 1;   /* RFC 9110 15.5.16: 415 for a content coding not taken (a gzip body read as JSON: 0x1F) */
        srv_problem(r, 415, NULL, "the body's Content-Encoding is %s; pdesolidd takes bodies uncompressed "
                    "(identity): send it without the header", coding);
        return 0;
    }
    if (!srv_origin_allowed(r)) {
        r->decided = 1;
        srv_problem(r, 403, NULL, "cross-origin requests from %s are not allowed here (--cors-origin)",
                    MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, "Origin"));
        return 0;
    }
    return 0;
}

/* strlcpy: src cut to fit n bytes, NUL-terminated. */
static void copy(char *dst, size_t n, const char *src)
{
    size_t k = strnlen(src, n - 1);
    memcpy(dst, src, k);
    dst[k] = '\0';
}

static srv_req *begin(srv_server *s, struct MHD_Connection *conn, const char *url, const char *method,
                      const char *version)
{
    /* Zeroed up to its text buffers, which are NUL-terminated as they are filled. */
    srv_req *r = malloc(sizeof *r);
    if (!r)
        return NULL;
    memset(r, 0, offsetof(srv_req, path));
    r->s = s;
    r->conn = conn;
    r->t0 = srv_now();
    r->route = srv_nroutes;
    r->phase = SRV_BODY;
    r->fd = -1;
    copy(r->method, sizeof r->method, method);
    copy(r->version, sizeof r->version, version);
    /* RFC 9112 3.2.2: a target in absolute form is routed by its path, and its authority stands for Host. Any
     * other scheme stays a path, which no route has. */
    size_t k = !strncasecmp(url, "http://", 7) ? 7 : !strncasecmp(url, "https://", 8) ? 8 : 0;
    if (k) {
        size_t n = strcspn(url + k, "/");
        /* one too long is kept as its first sizeof - 1 bytes and refused in admit(), never compared cut */
        snprintf(r->target_host, sizeof r->target_host, "%.*s", (int)(n < sizeof r->target_host ? n : sizeof r->target_host), url + k);
        r->host = r->target_host;
        url = url[k + n] ? url + k + n : "/";
    }
    copy(r->path, sizeof r->path, url);
    r->query[0] = '\0';
    atomic_fetch_add(&s->in_flight, 1);
    return r;
}

/* ---- the last call: the answer ---- */

static enum MHD_Result preflight(srv_req *r)
{
    r->status = 204;
    struct MHD_Response *resp = MHD_create_response_from_buffer(0, (void *)"", MHD_RESPMEM_PERSISTENT);
    if (resp) {
        char allow[80];
        snprintf(allow, sizeof allow, "%s, OPTIONS", srv_routes[r->route].method);
        MHD_add_response_header(resp, "Access-Control-Allow-Methods", allow);
        MHD_add_response_header(resp, "Access-Control-Allow-Headers", "Content-Type, If-None-Match, X-Request-Id");
        MHD_add_response_header(resp, "Access-Control-Max-Age", "600");
    }
    return srv_queue(r, resp);
}

/* A job row: from the response cache, or queued for a solver thread. */
static enum MHD_Result dispatch_job(srv_req *r)
{
    srv_server *s = r->s;
    const srv_route *rt = &srv_routes[r->route];
    if (rt->flags & SRV_RT_CACHE) {
        make_key(r);
        srv_rhit h;
        if (r->key && srv_rcache_get(s->rcache, r->key, r->klen, &h)) {
            /* A request answered before: its kept bytes, with this request's own headers. */
            copy(r->id, sizeof r->id, h.id);
            copy(r->etag, sizeof r->etag, h.etag);
            r->ctype = h.ctype;
            const char *inm = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_IF_NONE_MATCH);
            if (inm && (strstr(inm, h.etag) || !strcmp(inm, "*"))) {
                srv_rcache_unpin(h.body);
                r->status = 304;
                r->ctype = NULL;
                return srv_respond_text(r);
            }
            r->status = 200;
            r->sent = (long long)h.len;
            struct MHD_Response *resp = MHD_create_response_from_buffer_with_free_callback_cls(
                h.len, (void *)h.bytes, srv_rcache_unpin, h.body);
            if (!resp)
                srv_rcache_unpin(h.body);
            return srv_queue(r, resp);
        }
    }
    if (srv_pool_reserve(s->pool)) {
        if (atomic_load(&s->stopping))
            srv_problem(r, 503, NULL, "the server is shutting down");
        else
            srv_problem(r, 503, NULL, "all %d solver threads are busy and %zu jobs are waiting (--queue); try again",
                        s->cfg.threads, s->cfg.queue);
        return srv_respond_text(r);
    }
    r->phase = SRV_QUEUED;
    r->queued_at = srv_now();
    const union MHD_ConnectionInfo *ci = MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_CONNECTION_FD);
    r->fd = ci ? ci->connect_fd : -1;   /* the jobs watch it for the client's close (srv_job_stop) */
    MHD_suspend_connection(r->conn);   /* before the job exists, so that its resume finds it suspended */
    srv_pool_submit(s->pool, srv_run_job, r);
    return MHD_YES;
}

static enum MHD_Result answer(srv_req *r, const char *method)
{
    if (r->decided)
        return srv_respond_text(r);
    if (!strcmp(method, MHD_HTTP_METHOD_OPTIONS))
        return preflight(r);
    const srv_route *rt = &srv_routes[r->route];
    if (rt->flags & SRV_RT_JOB)
        return dispatch_job(r);
    rt->handler(r);
    return srv_respond_text(r);
}

/* Takes a piece of body; MHD_NO closes the connection. */
static enum MHD_Result take_body(srv_req *r, const char *upload, size_t n)
{
    srv_server *s = r->s;
    double age = srv_now() - r->t0;
    if (r->decided) {
        /* Discarding the body of a refused request, so that its answer can be read. */
        r->drained += n;
        return r->drained <= DRAIN_BYTES && age <= DRAIN_SECONDS ? MHD_YES : MHD_NO;
    }
    if (age > s->cfg.request_timeout) {
        r->status = 408;   /* logged so; closed without an answer */
        return MHD_NO;   /* the whole request, headers and body, has a deadline (--request-timeout) */
    }
    if (!(srv_routes[r->route].flags & SRV_RT_BODY) || strcmp(r->method, srv_routes[r->route].method)) {
        r->drained += n;
        return r->drained <= DRAIN_BYTES ? MHD_YES : MHD_NO;
    }
    if (r->len + n > s->cfg.max_body) {
        r->decided = r->close = 1;
        free(r->body);
        r->body = NULL;
        srv_problem(r, 413, NULL, "the body is more than the limit of %zu bytes (--max-body)%s", s->cfg.max_body,
                    body_hint(r));
        r->drained = r->len + n;
        r->len = r->cap = 0;
        return MHD_YES;
    }
    if (r->len + n + 1 > r->cap) {
        size_t cap = r->cap ? r->cap : 4096;
        while (cap < r->len + n + 1)
            cap *= 2;
        char *b = realloc(r->body, cap);
        if (!b)
            return MHD_NO;
        r->body = b;
        r->cap = cap;
    }
    memcpy(r->body + r->len, upload, n);
    r->len += n;
    r->body[r->len] = '\0';
    return MHD_YES;
}

/* Set on a polling thread as its handler closes the connection of a client gone (MHD_NO): libmicrohttpd then
 * logs, on the same thread at once, "Application reported internal error", which it is not; mhd_logger drops
 * that one line (the job's own line says why, and the access log has the 499). */
static _Thread_local int closing_gone;

/* Between a request's head and its answer (busy), the request's deadlines hold, not the head's (watch.h). */
static void watch_busy(srv_server *s, struct MHD_Connection *conn, int busy)
{
    const union MHD_ConnectionInfo *ci = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    conn_state *cs = ci ? ci->socket_context : NULL;
    if (cs)
        srv_watch_busy(s->watch, &cs->w, busy);
}

static enum MHD_Result handler(void *cls, struct MHD_Connection *conn, const char *url, const char *method,
                               const char *version, const char *upload, size_t *upload_size, void **con_cls)
{
    srv_server *s = cls;
    srv_req *r = *con_cls;
    closing_gone = 0;
    if (!r) {
        if (!(r = begin(s, conn, url, method, version)))
            return MHD_NO;
        *con_cls = r;
        watch_busy(s, conn, 1);
        if (admit(r, method))
            return srv_respond_text(r);
        return MHD_YES;
    }
    if (*upload_size) {
        size_t n = *upload_size;
        *upload_size = 0;
        return take_body(r, upload, n);
    }
    if (r->phase == SRV_DONE && r->gone) {   /* resumed after the job saw its client close: no one to answer */
        closing_gone = 1;
        return MHD_NO;
    }
    if (r->phase == SRV_DONE)   /* resumed: the job's result is ready */
        return r->stream ? srv_stream_respond(r) : srv_respond_text(r);
    return answer(r, method);
}

static int hexval(char c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

/* libmicrohttpd's %-decoding, except that %00 stays as it is, so that a NUL never hides the rest of a path
 * or a value, and the request is refused (admit). */
static size_t unescape(void *cls, struct MHD_Connection *c, char *s)
{
    (void)cls;
    char *w = s;
    for (const char *p = s; *p;) {
        int hi = p[0] == '%' ? hexval(p[1]) : -1, lo = hi >= 0 ? hexval(p[2]) : -1;
        if (lo >= 0 && (hi | lo)) {
            *w++ = (char)(hi << 4 | lo);
            p += 3;
            continue;
        }
        if (lo >= 0) {
            const union MHD_ConnectionInfo *ci = MHD_get_connection_info(c, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
            if (ci && ci->socket_context)
                ((conn_state *)ci->socket_context)->nul = 1;
        }
        *w++ = *p++;
    }
    *w = '\0';
    return (size_t)(w - s);
}

static void completed(void *cls, struct MHD_Connection *conn, void **con_cls, enum MHD_RequestTerminationCode toe)
{
    srv_server *s = cls;
    srv_req *r = *con_cls;
    if (!r)
        return;
    *con_cls = NULL;
    watch_busy(s, conn, 0);
    double dt = srv_now() - r->t0;
    /* No answer: the client went away (499, as nginx logs it), or its request ran past --timeout or
     * --request-timeout (408); a request that completed without one would be a bug (500). */
    int status = r->status                                    ? r->status
                 : toe == MHD_REQUEST_TERMINATED_TIMEOUT_REACHED ? 408
                 : toe != MHD_REQUEST_TERMINATED_COMPLETED_OK    ? 499
                                                                 : 500;
    srv_metrics_request(s->metrics, r->route, status, dt);
    if (s->log) {
        char ip[INET6_ADDRSTRLEN] = "-";
        const union MHD_ConnectionInfo *ci = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
        if (ci && ci->client_addr) {
            const struct sockaddr *sa = ci->client_addr;
            if (sa->sa_family == AF_INET)
                inet_ntop(AF_INET, &((const struct sockaddr_in *)sa)->sin_addr, ip, sizeof ip);
            else if (sa->sa_family == AF_INET6)
                inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)sa)->sin6_addr, ip, sizeof ip);
        }
        srv_log_rec rec = { .ip = ip, .method = r->method, .path = r->path, .query = r->query[0] ? r->query : NULL,
                            .request_id = r->rid, .solid_id = r->id, .status = status, .bytes = r->sent,
                            .seconds = dt, .aborted = toe != MHD_REQUEST_TERMINATED_COMPLETED_OK };
        srv_log_request(s->log, &rec);
    }
    srv_stream_release(r);
    free(r->body);
    free(r->text);
    free(r->key);
    free(r);
    if (atomic_fetch_sub(&s->in_flight, 1) == 1 && atomic_load(&s->stopping)) {
        pthread_mutex_lock(&s->lock);   /* srv_stop waits for this */
        pthread_cond_broadcast(&s->idle);
        pthread_mutex_unlock(&s->lock);
    }
}

static void connection_event(void *cls, struct MHD_Connection *conn, void **socket_context,
                             enum MHD_ConnectionNotificationCode toe)
{
    srv_server *s = cls;
    srv_metrics_connection(s->metrics, toe == MHD_CONNECTION_NOTIFY_STARTED ? 1 : -1);
    if (toe == MHD_CONNECTION_NOTIFY_STARTED) {
        unsigned n = atomic_fetch_add(&s->conns, 1) + 1;
        conn_state *cs = calloc(1, sizeof *cs);   /* NULL: %00 goes unnoticed (still kept literal), as may --max-conns */
        const union MHD_ConnectionInfo *ci = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
        if (cs)
            cs->over = n > s->cfg.max_conns;
        if (cs && ci)
            srv_watch_open(s->watch, &cs->w, ci->connect_fd);
        *socket_context = cs;
    } else {
        atomic_fetch_sub(&s->conns, 1);
        conn_state *cs = *socket_context;
        if (cs)
            srv_watch_close(s->watch, &cs->w);
        free(cs);
        *socket_context = NULL;
    }
}

/* Notes the length of the request target as sent (the handler sees the path and the query apart, decoded). */
static void *target_seen(void *cls, const char *uri, struct MHD_Connection *conn)
{
    (void)cls;
    const union MHD_ConnectionInfo *ci = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    if (ci && ci->socket_context) {
        conn_state *cs = ci->socket_context;
        cs->target = strlen(uri);
        /* As sent, before decoding: an absolute-form target's authority holding @ or % (begin() sees it decoded,
         * where localhost%2f@evil.example reads as the host localhost) is refused in admit(). */
        size_t k = !strncasecmp(uri, "http://", 7) ? 7 : !strncasecmp(uri, "https://", 8) ? 8 : 0;
        size_t n = k ? strcspn(uri + k, "/?#") : 0;
        cs->authority = k && (memchr(uri + k, '@', n) || memchr(uri + k, '%', n));
    }
    return NULL;   /* the request's state is made by the handler's first call */
}

/* Past --max-conns and its spares, a new connection is closed at once. */
static enum MHD_Result accept_policy(void *cls, const struct sockaddr *addr, socklen_t addrlen)
{
    (void)addr;
    (void)addrlen;
    srv_server *s = cls;
    return atomic_load(&s->conns) < s->cfg.max_conns + SPARE_CONNS ? MHD_YES : MHD_NO;
}

/* ---- start and stop ---- */

static void say(srv_log *log, const char *source, const char *fmt, va_list ap)
{
    char msg[1024];
    vsnprintf(msg, sizeof msg, fmt, ap);
    if (log)
        srv_log_note(log, source, msg);
    else
        fprintf(stderr, "pdesolidd: %s%s%s%s", strcmp(source, "pdesolidd") ? source : "",
                strcmp(source, "pdesolidd") ? ": " : "", msg, strchr(msg, '\n') ? "" : "\n");
}

void srv_say(srv_server *s, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    say(s->log, "pdesolidd", fmt, ap);
    va_end(ap);
}

/* libmicrohttpd's own messages (a request it refused itself, a client gone mid-body) into the log, in its
 * format: with --log-format json, every line on stderr is JSON. */
static void mhd_logger(void *cls, const char *fmt, va_list ap)
{
    srv_server *s = cls;
    if (closing_gone) {
        closing_gone = 0;
        va_list aq;
        va_copy(aq, ap);
        char msg[128];
        vsnprintf(msg, sizeof msg, fmt, aq);
        va_end(aq);
        if (!strncmp(msg, "Application reported internal error", 35))
            return;
    }
    say(s->log, "libmicrohttpd", fmt, ap);
}

static void free_server(srv_server *s)
{
    srv_watch_stop(s->watch);
    srv_pool_destroy(s->pool);
    srv_cache_destroy(s->cache);
    srv_rcache_destroy(s->rcache);
    srv_store_close(s->store);
    srv_metrics_destroy(s->metrics);
    srv_static_free(s->web);
    srv_log_destroy(s->log);
    pthread_mutex_destroy(&s->json_lock);
    pthread_mutex_destroy(&s->lock);
    pthread_cond_destroy(&s->idle);
    free(s);
}

srv_server *srv_start(const srv_config *c, char *err, size_t errlen)
{
    static const char *names[64];
    srv_server *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    s->cfg = *c;
    pthread_mutex_init(&s->json_lock, NULL);
    pthread_mutex_init(&s->lock, NULL);
    pthread_cond_init(&s->idle, NULL);
    for (int i = 0; i < srv_nroutes; i++)
        names[i] = srv_routes[i].name;
    names[srv_nroutes] = "none";
    s->cache = srv_cache_create(c->cache_bytes);
    /* Finished responses: an eighth of the solution cache's bound, at least 4 MiB. */
    s->rcache = srv_rcache_create(c->cache_bytes / 8 > (4u << 20) ? c->cache_bytes / 8 : 4u << 20);
    s->metrics = srv_metrics_create(names, srv_nroutes + 1);
    /* Continuations of streams: at most one per connection. */
    s->pool = srv_pool_create(c->threads, c->queue, c->max_conns);
    s->log = c->quiet ? NULL : srv_log_create(2, c->log_format);
    s->web = srv_static_load(c->web, err, errlen);
    /* a head (request line and headers) has --request-timeout, as the whole request, and a keep-alive connection's
     * next head the longer of that and --timeout (libmicrohttpd's idle timeout); checked 4 times as often */
    s->watch = srv_watch_start(c->request_timeout, fmax(c->request_timeout, (double)c->timeout),
                               fmin(fmax(c->request_timeout / 4, 0.05), 1.0));
    srv_store_config sc = { .spec = c->store, .max_mb = c->store_mb, .prefix = c->store_prefix, .ttl_s = c->store_ttl };
    if (s->web && !(s->store = srv_store_open(&sc, err, errlen)) && *err) {   /* "" for --store none */
        free_server(s);
        return NULL;
    }
    if (!s->cache || !s->rcache || !s->metrics || !s->pool || (!c->quiet && !s->log) || !s->web || !s->watch) {
        snprintf(err, errlen, "out of memory, or a solver thread could not start");
        free_server(s);
        return NULL;
    }
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
    /* libmicrohttpd splits its limit evenly between the polling threads, which may accept unevenly: so that no
     * thread reaches its share (and stops accepting), each may hold all; accept_policy keeps the real limit. */
    unsigned workers = (unsigned)(c->http_threads > 1 ? c->http_threads : 1);
    /* One polling thread is no pool: libmicrohttpd warns at a pool size of 0 or 1, so the option is left out. */
    struct MHD_OptionItem pool[] = { { MHD_OPTION_THREAD_POOL_SIZE, workers, NULL }, { MHD_OPTION_END, 0, NULL } };
    if (workers == 1)
        pool[0] = pool[1];
    s->d = MHD_start_daemon(flags, (uint16_t)c->port, accept_policy, s, handler, s,
                            MHD_OPTION_EXTERNAL_LOGGER, mhd_logger, s,   /* first: it takes the other options' messages */
                            MHD_OPTION_SOCK_ADDR, ai->ai_addr,
                            MHD_OPTION_ARRAY, pool,
                            MHD_OPTION_CONNECTION_TIMEOUT, c->timeout, MHD_OPTION_PER_IP_CONNECTION_LIMIT, c->per_ip,
                            MHD_OPTION_CONNECTION_LIMIT, (c->max_conns + SPARE_CONNS + 1) * workers,
                            MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)CONN_MEMORY, MHD_OPTION_URI_LOG_CALLBACK,
                            target_seen, NULL, MHD_OPTION_STRICT_FOR_CLIENT, (int)0,
                            MHD_OPTION_UNESCAPE_CALLBACK, unescape, NULL, MHD_OPTION_NOTIFY_COMPLETED, completed, s,
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

/* Waits up to seconds for every request to complete; 1 if they did. */
static int await_idle(srv_server *s, double seconds)
{
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    double end = until.tv_sec + until.tv_nsec * 1e-9 + seconds;
    until.tv_sec = (time_t)end;
    until.tv_nsec = (long)((end - (double)until.tv_sec) * 1e9);
    pthread_mutex_lock(&s->lock);
    while (atomic_load(&s->in_flight) > 0)
        if (pthread_cond_timedwait(&s->idle, &s->lock, &until))
            break;
    int idle = atomic_load(&s->in_flight) == 0;
    pthread_mutex_unlock(&s->lock);
    return idle;
}

void srv_stop(srv_server *s)
{
    /* From now on every new request, on a connection open or new, answers 503 "shutting down" with
     * Retry-After (handler()), which a balancer retries on another replica. The listening socket stays
     * open until MHD_stop_daemon: libmicrohttpd 0.9.75-0.9.77's MHD_quiesce_daemon removes it from each
     * polling thread's epoll set while that thread may be removing it too, and aborts the process when
     * it loses that race (epoll_ctl's ENOENT). */
    atomic_store(&s->stopping, 1);
    /* Requests in flight may finish within the grace period. */
    if (!await_idle(s, s->cfg.grace)) {
        /* Then the rest ends: running jobs stop at their next poll, queued ones answer 503, streams end.
         * Every queued job resumes its connection before the pool stops, so none stays suspended, and
         * the polling threads get a moment to send those answers before the daemon closes everything. */
        atomic_store(&s->aborting, 1);
        srv_pool_stop(s->pool);
        await_idle(s, 0.5);
    }
    srv_pool_stop(s->pool);
    MHD_stop_daemon(s->d);
    srv_say(s, "stopped");
    free_server(s);
}
