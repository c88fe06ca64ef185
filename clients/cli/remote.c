/*
 * remote.c: pdesolid --server (remote.h), with libcurl.
 */
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cJSON.h>
#include <curl/curl.h>

#include "describe.h"
#include "id.h"
#include "output.h"
#include "remote.h"

typedef struct {
    char *data;
    size_t len;
    char id[64];        /* X-Solid-Id */
    long status;
} reply;

static size_t on_data(char *p, size_t size, size_t n, void *cls)
{
    reply *r = cls;
    size_t k = size * n;
    char *d = realloc(r->data, r->len + k + 1);
    if (!d)
        return 0;
    r->data = d;
    memcpy(r->data + r->len, p, k);
    r->len += k;
    r->data[r->len] = '\0';
    return k;
}

static size_t on_header(char *p, size_t size, size_t n, void *cls)
{
    reply *r = cls;
    size_t k = size * n;
    if (k > 12 && !strncasecmp(p, "X-Solid-Id:", 11)) {
        const char *v = p + 11;
        while (*v == ' ')
            v++;
        snprintf(r->id, sizeof r->id, "%.*s", (int)strcspn(v, "\r\n"), v);
    }
    return k;
}

/* POST body to url (GET when body is NULL); 0 with the reply, or 1 after printing why the server could not be
 * reached. */
static int post(const char *url, const char *body, size_t len, reply *r)
{
    memset(r, 0, sizeof *r);
    CURL *c = curl_easy_init();
    if (!c) {
        fprintf(stderr, "pdesolid: libcurl failed to start\n");
        return 1;
    }
    struct curl_slist *h = curl_slist_append(NULL, "Content-Type: application/json");
    h = curl_slist_append(h, "Expect:");
    curl_easy_setopt(c, CURLOPT_URL, url);
    curl_easy_setopt(c, CURLOPT_PROTOCOLS_STR, "http,https");
    if (body) {
        curl_easy_setopt(c, CURLOPT_POST, 1L);
        curl_easy_setopt(c, CURLOPT_POSTFIELDS, body);
        curl_easy_setopt(c, CURLOPT_POSTFIELDSIZE_LARGE, (curl_off_t)len);
    }
    curl_easy_setopt(c, CURLOPT_HTTPHEADER, h);
    curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, on_data);
    curl_easy_setopt(c, CURLOPT_WRITEDATA, r);
    curl_easy_setopt(c, CURLOPT_HEADERFUNCTION, on_header);
    curl_easy_setopt(c, CURLOPT_HEADERDATA, r);
    CURLcode rc = curl_easy_perform(c);
    if (rc == CURLE_OK)
        curl_easy_getinfo(c, CURLINFO_RESPONSE_CODE, &r->status);
    curl_slist_free_all(h);
    curl_easy_cleanup(c);
    if (rc != CURLE_OK) {
        fprintf(stderr, "pdesolid: %s: %s\n", url, curl_easy_strerror(rc));
        return 1;
    }
    return 0;
}

/* server followed by fmt's text, malloc'd at its whole length (a long --server is never cut short); NULL after
 * a message. */
static char *url_of(const char *server, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    size_t n = strlen(server);
    char *url = k >= 0 ? malloc(n + (size_t)k + 1) : NULL;
    if (!url) {
        fprintf(stderr, "pdesolid: out of memory\n");
        return NULL;
    }
    memcpy(url, server, n);
    va_start(ap, fmt);
    vsnprintf(url + n, (size_t)k + 1, fmt, ap);
    va_end(ap);
    return url;
}

/* A problem answer, printed as offline errors are; returns the exit status. */
static int problem(const char *server, const reply *r)
{
    cJSON *p = r->data ? cJSON_Parse(r->data) : NULL;
    const cJSON *detail = cJSON_GetObjectItemCaseSensitive(p, "detail");
    fprintf(stderr, "pdesolid: %s: %ld: %s\n", server, r->status,
            cJSON_IsString(detail) ? detail->valuestring : "the server gave no reason");
    cJSON_Delete(p);
    return r->status >= 400 && r->status < 500 ? 2 : 1;
}

/* The text of `pdesolid solve` from the json format's document. */
static int print_solve(const char *json, FILE *out)
{
    cJSON *d = cJSON_Parse(json);
    const cJSON *text = cJSON_GetObjectItemCaseSensitive(d, "closed_form");
    const cJSON *props = cJSON_GetObjectItemCaseSensitive(d, "properties");
    const cJSON *id = cJSON_GetObjectItemCaseSensitive(d, "id");
    if (!cJSON_IsString(text) || !cJSON_IsObject(props)) {
        cJSON_Delete(d);
        fprintf(stderr, "pdesolid: the server's answer is not a solution\n");
        return 1;
    }
    pde_props p;
    api_props_from_tree(props, &p);
    fprintf(out, "solid %s\n%s", cJSON_IsString(id) ? id->valuestring : "", text->valuestring);
    api_describe_props(out, &p);
    cJSON_Delete(d);
    return 0;
}

int remote_solve(const char *server, const char *body, size_t len, const char *format, const char *res,
                 const char *compress)
{
    char *url = url_of(server, "/solve?format=%s%s%s%s%s", format ? format : "json", res ? "&res=" : "",
                       res ? res : "", compress ? "&compress=" : "", compress ? compress : "");
    reply r;
    int rc = !url || post(url, body, len, &r);
    free(url);
    if (rc)
        return 1;
    rc = r.status != 200 ? problem(server, &r) : 0;
    if (!rc && !format)
        rc = print_solve(r.data ? r.data : "", stdout);
    else if (!rc && r.len)
        fwrite(r.data, 1, r.len, stdout);   /* a write error stays in stdout's error flag: the caller's to name */
    free(r.data);
    return rc;
}

int remote_base(const char *url, char *base, size_t n)
{
    size_t k = strlen(url);
    const char *why = strncasecmp(url, "http://", 7) && strncasecmp(url, "https://", 8)
                          ? "pdesolidd speaks http:// or https:// only"
                      : strchr(url, '?') ? "a query (?...) has no place in it"
                      : strchr(url, '#') ? "a fragment (#...) has no place in it"
                      : k >= n           ? "too long"
                                         : NULL;
    if (!why) {   /* the rest as libcurl reads URLs: a host, a port that is a number, ... */
        CURLU *u = curl_url();
        CURLUcode rc = u ? curl_url_set(u, CURLUPART_URL, url, 0) : CURLUE_OUT_OF_MEMORY;
        curl_url_cleanup(u);
        if (rc != CURLUE_OK)
            why = curl_url_strerror(rc);
    }
    if (why) {
        fprintf(stderr, "pdesolid: --server %s: %s; give a pdesolidd's base URL, e.g. http://127.0.0.1:8080\n", url, why);
        return 2;
    }
    while (k > 0 && url[k - 1] == '/')   /* joined with "/solve" and the like */
        k--;
    memcpy(base, url, k);
    base[k] = '\0';
    return 0;
}

/* A batch's point refused by the server (a problem whose pointer is /points/i...): named as offline, by its
 * index in the points file, and 1; 0 for any other problem. */
static int point_problem(const reply *r, size_t start, const char *points_name)
{
    cJSON *p = r->data ? cJSON_Parse(r->data) : NULL;
    const cJSON *ptr = cJSON_GetObjectItemCaseSensitive(p, "pointer");
    const cJSON *detail = cJSON_GetObjectItemCaseSensitive(p, "detail");
    int named = 0;
    if (cJSON_IsString(ptr) && cJSON_IsString(detail) && !strncmp(ptr->valuestring, "/points/", 8)) {
        size_t k = strlen(ptr->valuestring);
        char *end;
        unsigned long i = strtoul(ptr->valuestring + 8, &end, 10);
        if (end != ptr->valuestring + 8 && !strncmp(detail->valuestring, ptr->valuestring, k) &&
            !strncmp(detail->valuestring + k, ": ", 2)) {
            fprintf(stderr, "pdesolid: %s: /%zu%s: %s\n", points_name, start + i, end, detail->valuestring + k + 2);
            named = 1;
        }
    }
    cJSON_Delete(p);
    return named;
}

/* The values of one batch's answer into pts (NAN for null); 0, or 1 after a message. */
static int batch_values(const char *server, const reply *e, double *pts, size_t n)
{
    cJSON *d = cJSON_Parse(e->data ? e->data : "");
    const cJSON *vals = cJSON_GetObjectItemCaseSensitive(d, "values");
    int ok = cJSON_IsArray(vals) && (size_t)cJSON_GetArraySize(vals) == n;
    size_t i = 0;
    for (const cJSON *v = ok ? vals->child : NULL; v && ok; v = v->next, i++)
        for (int c = 0; c < 3 && ok; c++) {
            const cJSON *x = cJSON_GetArrayItem(v, c);
            ok = cJSON_IsNumber(x) || cJSON_IsNull(x);   /* a server writes null for a value that is not finite */
            pts[3 * i + c] = cJSON_IsNumber(x) ? x->valuedouble : NAN;
        }
    cJSON_Delete(d);
    if (!ok)
        fprintf(stderr, "pdesolid: %s: the server's answer does not have %zu values\n", server, n);
    return !ok;
}

/* Points a batch starts with: 10,000 points of at most 77 bytes (%.17g) are under 1 MiB, the default
 * --max-body, and under the default --max-points. */
enum { BATCH_POINTS = 10000 };

/*
 * Makes the solid on the server: POST /solve, whose X-Solid-Id (into id) names it. The server solves and
 * caches the solid before it checks the output it was asked for, and says its id in a refusal of that
 * output too; so the cheapest output, f32 at 2 x 2 x 2 (8 points, no properties), makes any solid the server
 * can solve, even one beyond float32, which f32 then refuses (json has no float32 check, but it computes the
 * properties, and refuses a solid whose properties overflow a double). 0, or the exit status after the
 * server's problem: one with no id is about the model (or the budget of its solve), and is the answer.
 */
static int make_solid(const char *server, const char *body, size_t len, char id[64])
{
    char *url = url_of(server, "/solve?format=f32&res=2");
    reply r;
    int rc = !url || post(url, body, len, &r);
    free(url);
    if (rc)
        return 1;
    if (api_id_valid(r.id)) {   /* an id, and nothing else, goes into the eval's URL */
        memcpy(id, r.id, sizeof r.id);
    } else if (r.status != 200) {
        rc = problem(server, &r);
    } else {
        fprintf(stderr, "pdesolid: %s: the server's answer names no solid (X-Solid-Id)\n", server);
        rc = 1;
    }
    free(r.data);
    return rc;
}

/* 1 if the problem is a budget of the server (--max-work, --max-mem-mb), which a smaller batch may meet. */
static int over_budget(const reply *r)
{
    return r->status == 422 && r->data &&
           (strstr(r->data, "(--max-work)") || strstr(r->data, "(--max-mem-mb)")) && !strstr(r->data, "\"pointer\"");
}

int remote_eval(const char *server, const char *body, size_t len, const char *local_id, double *pts, size_t n,
                const char *points_name)
{
    char id[64];
    snprintf(id, sizeof id, "%s", local_id ? local_id : "");
    int made = !id[0], rc = made ? make_solid(server, body, len, id) : 0;
    if (rc)
        return rc;
    size_t batch = BATCH_POINTS;
    char *req = malloc(32 + 80 * batch);
    if (!req) {
        fprintf(stderr, "pdesolid: out of memory\n");
        return 1;
    }
    for (size_t start = 0; start < n && !rc;) {
        size_t m = n - start < batch ? n - start : batch, k = (size_t)sprintf(req, "{\"points\":[");
        for (size_t i = start; i < start + m; i++)   /* 17 digits: the server reads the same doubles */
            k += (size_t)sprintf(req + k, "%s[%.17g,%.17g,%.17g]", i > start ? "," : "", pts[3 * i], pts[3 * i + 1],
                                 pts[3 * i + 2]);
        k += (size_t)sprintf(req + k, "]}");
        char *url = url_of(server, "/solids/%s/eval", id);
        reply e;
        if (!url || post(url, req, k, &e)) {
            free(url);
            rc = 1;
            break;
        }
        free(url);
        if (e.status == 404 && !made) {   /* not solved there yet (or evicted): make it, then ask again */
            rc = make_solid(server, body, len, id);
            made = 1;
        } else if ((e.status == 413 || over_budget(&e)) && batch > 1) {   /* --max-body, --max-points, --max-work */
            batch /= 2;
        } else if (e.status != 200) {
            rc = point_problem(&e, start, points_name) ? 2 : problem(server, &e);
        } else {
            rc = batch_values(server, &e, pts + 3 * start, m);
            start += m;
        }
        free(e.data);
    }
    free(req);
    return rc;
}

int remote_preset(const char *server, const char *name, char **json)
{
    char path[160];
    snprintf(path, sizeof path, "/presets/%s", name);
    char *url = url_of(server, path);
    reply r;
    int rc = !url || post(url, NULL, 0, &r);
    free(url);
    if (rc)
        return 1;
    if (r.status != 200) {
        rc = problem(server, &r);
        free(r.data);
        return rc;
    }
    *json = r.data;
    return 0;
}

int remote_presets(const char *server, void (*row)(const char *name, const char *template, const char *caption))
{
    char *url = url_of(server, "/presets");
    reply r;
    int rc = !url || post(url, NULL, 0, &r);
    free(url);
    if (rc)
        return 1;
    rc = r.status != 200 ? problem(server, &r) : 0;
    cJSON *d = rc ? NULL : cJSON_Parse(r.data ? r.data : "");
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(d, "presets"), *p;
    if (!rc && !cJSON_IsArray(list)) {
        fprintf(stderr, "pdesolid: %s: the server's answer has no presets\n", server);
        rc = 1;
    }
    const cJSON *items = rc ? NULL : list;
    cJSON_ArrayForEach(p, items) {
        const char *f[3] = { "name", "template", "caption" }, *v[3];
        for (int i = 0; i < 3; i++) {
            const cJSON *s = cJSON_GetObjectItemCaseSensitive(p, f[i]);
            v[i] = cJSON_IsString(s) ? s->valuestring : "";
        }
        row(v[0], v[1], v[2]);
    }
    cJSON_Delete(d);
    free(r.data);
    return rc;
}
