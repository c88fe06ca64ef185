/*
 * remote.c: pdesolid --server (remote.h), with libcurl.
 */
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>
#include <curl/curl.h>

#include "describe.h"
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

/* POST body to url; 0 with the reply, or 1 after printing why the server could not be reached. */
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
    curl_easy_setopt(c, CURLOPT_POST, 1L);
    curl_easy_setopt(c, CURLOPT_POSTFIELDS, body);
    curl_easy_setopt(c, CURLOPT_POSTFIELDSIZE_LARGE, (curl_off_t)len);
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
                 const char *compress, FILE *out)
{
    char url[2048];
    snprintf(url, sizeof url, "%s/solve?format=%s%s%s%s%s", server, format ? format : "json", res ? "&res=" : "",
             res ? res : "", compress ? "&compress=" : "", compress ? compress : "");
    reply r;
    if (post(url, body, len, &r))
        return 1;
    int rc;
    if (r.status != 200)
        rc = problem(server, &r);
    else if (!format)
        rc = print_solve(r.data ? r.data : "", out);
    else
        rc = fwrite(r.data, 1, r.len, out) == r.len ? 0 : 1;
    free(r.data);
    return rc;
}

int remote_eval(const char *server, const char *body, size_t len, const char *points, size_t plen, FILE *out)
{
    char url[2048];
    snprintf(url, sizeof url, "%s/solve?format=f32&res=2", server);
    reply r;
    if (post(url, body, len, &r))
        return 1;
    if (r.status != 200) {
        int rc = problem(server, &r);
        free(r.data);
        return rc;
    }
    free(r.data);
    char *req = malloc(plen + 32);
    if (!req)
        return 1;
    int n = snprintf(req, plen + 32, "{\"points\":%.*s}", (int)plen, points);
    snprintf(url, sizeof url, "%s/solids/%s/eval", server, r.id);
    reply e;
    int rc = post(url, req, (size_t)n, &e);
    free(req);
    if (rc)
        return rc;
    if (e.status != 200) {
        rc = problem(server, &e);
        free(e.data);
        return rc;
    }
    cJSON *d = cJSON_Parse(e.data ? e.data : "");
    const cJSON *vals = cJSON_GetObjectItemCaseSensitive(d, "values");
    /* Every value a number, checked before anything is printed: a server writes null, never nan, for a
     * value that is not finite, and that is an error here as it is offline. */
    int i = 0;
    for (const cJSON *v = vals ? vals->child : NULL; v && !rc; v = v->next, i++)
        for (int c = 0; c < 3 && !rc; c++)
            if (!cJSON_IsNumber(cJSON_GetArrayItem(v, c))) {
                fprintf(stderr, "pdesolid: %s: /%d: x(u, v, w) is not a finite number at this point\n", server, i);
                rc = 2;
            }
    if (!rc && !cJSON_IsArray(vals)) {
        fprintf(stderr, "pdesolid: %s: the server's answer has no values\n", server);
        rc = 1;
    }
    if (!rc) {
        fputc('[', out);
        i = 0;
        for (const cJSON *v = vals->child; v; v = v->next, i++)
            fprintf(out, "%s[%.17g,%.17g,%.17g]", i ? ",\n" : "", cJSON_GetArrayItem(v, 0)->valuedouble,
                    cJSON_GetArrayItem(v, 1)->valuedouble, cJSON_GetArrayItem(v, 2)->valuedouble);
        fputs("]\n", out);
    }
    cJSON_Delete(d);
    free(e.data);
    return rc;
}
