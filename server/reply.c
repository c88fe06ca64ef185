/*
 * reply.c: what every answer shares (internal.h): RFC 9457 problems, the
 * headers (request id, CORS, ETag, Server-Timing, Allow, Retry-After), and
 * the check of a request's Origin.
 *
 * A problem's detail is made from a format and may quote what the client
 * sent, so it is cleaned (invalid UTF-8 and control characters replaced)
 * before it goes into the JSON: no answer carries bytes that are not UTF-8.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cJSON.h>

#include "internal.h"
#include "strict.h"

static const struct {
    int status;
    const char *title;
} titles[] = {
    { 400, "Bad Request" },          { 403, "Forbidden" },
    { 404, "Not Found" },            { 405, "Method Not Allowed" },
    { 408, "Request Timeout" },      { 413, "Content Too Large" },
    { 414, "URI Too Long" },         { 422, "Unprocessable Content" },
    { 431, "Request Header Fields Too Large" },
    { 500, "Internal Server Error" },
    { 501, "Not Implemented" },       { 503, "Service Unavailable" },
};

static const char *title_of(int status)
{
    for (size_t i = 0; i < sizeof titles / sizeof *titles; i++)
        if (titles[i].status == status)
            return titles[i].title;
    return "Error";
}

void srv_problem(srv_req *r, int status, const char *pointer, const char *fmt, ...)
{
    char raw[600], detail[700];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(raw, sizeof raw, fmt, ap);
    va_end(ap);
    api_text_clean(detail, sizeof detail, raw, n < 0 ? 0 : (size_t)n < sizeof raw ? (size_t)n : sizeof raw - 1);
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "type", "about:blank");
    cJSON_AddStringToObject(o, "title", title_of(status));
    cJSON_AddNumberToObject(o, "status", status);
    cJSON_AddStringToObject(o, "detail", detail);
    if (pointer && pointer[0])
        cJSON_AddStringToObject(o, "pointer", pointer);
    cJSON_AddStringToObject(o, "request_id", r->rid);
    free(r->text);
    r->text = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    r->text_len = r->text ? strlen(r->text) : 0;
    r->status = status;
    r->retry_after = status == 503;   /* every 503 is for now: docs/API.md promises Retry-After: 1 */
    r->ctype = "application/problem+json";
    r->etag[0] = '\0';   /* a problem is not the representation the ETag would name */
}

/* The one place an api_status becomes an HTTP status. */
int srv_http_status(api_status s)
{
    switch (s) {
    case API_ERR_NOMEM:
        return 500;
    case API_ERR_LIMIT:
        return 413;
    case API_ERR_NOT_JSON:
        return 400;
    case API_ERR_CANCELLED:
        return 503;
    case API_ERR_NOT_FOUND:
        return 404;
    case API_OK:   /* an error without a status is a bug; call it a bad document, as api_fail's callers meant */
    case API_ERR_DOCUMENT:
        break;
    }
    return 422;
}

/* detail reads as a sentence on its own: the pointer, then what is wrong there. */
void srv_problem_api(srv_req *r, const api_error *e)
{
    srv_problem(r, srv_http_status(e->status), e->pointer, "%s%s%s", e->pointer, e->pointer[0] ? ": " : "",
                e->message);
}

void srv_set_text(srv_req *r, int status, const char *ctype, char *text)
{
    free(r->text);
    r->text = text;
    r->text_len = text ? strlen(text) : 0;
    r->status = status;
    r->ctype = ctype;
    if (!text)
        srv_problem(r, 500, NULL, "out of memory");
}

/* Whether origin is in the comma-separated list. */
static int listed(const char *list, const char *origin)
{
    size_t n = strlen(origin);
    const char *item;
    for (const char *p = list; p;) {
        size_t len = srv_config_item(p, &item, &p);
        if (len == n && !strncmp(item, origin, n))
            return 1;
    }
    return 0;
}

/* 1 for cross-origin requests that --cors-origin allows; 0 for the same origin or none. */
static int cors_granted(srv_server *s, const char *origin)
{
    return origin && s->cfg.cors[0] && (!strcmp(s->cfg.cors, "*") || listed(s->cfg.cors, origin));
}

int srv_origin_allowed(srv_req *r)
{
    const char *origin = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, "Origin");
    if (!origin || cors_granted(r->s, origin))
        return 1;
    /* The same origin: the page this daemon (or the proxy in front) served. Browsers send Origin
     * on same-origin POSTs too, so compare its host with the Host the request was sent to. */
    const char *host = r->host;
    const char *sep = strstr(origin, "://");
    return host && sep && !strcasecmp(sep + 3, host);
}

static void add_timing(srv_req *r, struct MHD_Response *resp)
{
    if (r->route >= srv_nroutes || !(srv_routes[r->route].flags & SRV_RT_JOB) || !r->run_start)
        return;
    char v[256];
    snprintf(v, sizeof v,
             "queue;dur=%.3f, parse;dur=%.3f, solve;dur=%.3f%s, props;dur=%.3f, output;dur=%.3f%s",
             r->tm.queue * 1e3, r->tm.parse * 1e3, r->tm.solve * 1e3, r->tm.cached ? ";desc=\"cached\"" : "",
             r->tm.props * 1e3, r->tm.output * 1e3, r->stream ? ";desc=\"first part; the rest streams\"" : "");
    MHD_add_response_header(resp, "Server-Timing", v);
}

enum MHD_Result srv_queue(srv_req *r, struct MHD_Response *resp)
{
    if (!resp)
        return MHD_NO;
    srv_server *s = r->s;
    const char *origin = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, "Origin");
    /* A list of origins makes every answer depend on Origin (granted or not, or none): say so to caches. */
    if (s->cfg.cors[0] && strcmp(s->cfg.cors, "*"))
        MHD_add_response_header(resp, "Vary", "Origin");
    if (cors_granted(s, origin)) {
        MHD_add_response_header(resp, "Access-Control-Allow-Origin", !strcmp(s->cfg.cors, "*") ? "*" : origin);
        MHD_add_response_header(resp, "Access-Control-Expose-Headers",
                                "X-Solid-Id, X-Request-Id, ETag, Content-Length, Retry-After, Server-Timing");
    }
    MHD_add_response_header(resp, "X-Request-Id", r->rid);
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
    add_timing(r, resp);
    if (r->retry_after) {
        char v[16];
        snprintf(v, sizeof v, "%d", r->retry_after);
        MHD_add_response_header(resp, MHD_HTTP_HEADER_RETRY_AFTER, v);
    }
    if (r->close)
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CONNECTION, "close");
    enum MHD_Result ok = MHD_queue_response(r->conn, (unsigned)r->status, resp);
    MHD_destroy_response(resp);
    r->phase = SRV_DONE;
    return ok;
}

enum MHD_Result srv_respond_text(srv_req *r)
{
    if (r->ref && !r->text) {
        struct MHD_Response *resp = MHD_create_response_from_buffer(r->ref_len, (void *)r->ref, MHD_RESPMEM_PERSISTENT);
        if (resp)
            MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
        r->sent = (long long)r->ref_len;
        return srv_queue(r, resp);
    }
    struct MHD_Response *resp = MHD_create_response_from_buffer(r->text_len, r->text ? r->text : (char *)"",
                                                                r->text ? MHD_RESPMEM_MUST_FREE : MHD_RESPMEM_PERSISTENT);
    if (resp)
        r->text = NULL;   /* the response owns it now */
    r->sent = (long long)r->text_len;
    return srv_queue(r, resp);
}
