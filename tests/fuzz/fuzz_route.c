/*
 * fuzz_route.c: the request router on raw request lines. The input is
 * "METHOD TARGET" (up to the first NUL, CR or LF); the target splits at its
 * first '?' into path and query. The path is %-decoded as libmicrohttpd does
 * with pdesolidd's unescape callback (%00 stays literal, server/http.c) and
 * cut to the server's 511 bytes; the query is split as libmicrohttpd 0.9.75
 * splits it (on '&', then on the first '=', '+' to space, then %-decoding).
 * Then srv_route_find, and srv_query_init/arg/done, as http.c's admit()
 * calls them. Invariants: a found row takes the method (or OPTIONS, or HEAD
 * for GET) and its {} segment is what the path holds; a miss is 400, 404 or
 * 405, and a 405 lists what the path allows, ending in OPTIONS; every
 * message is a NUL-terminated, non-empty sentence in valid UTF-8 with no
 * control characters; an accepted query names a format and a resolution
 * within the limits.
 */
#include "fuzz.h"
#include "output.h"
#include "route.h"

static int hexval(int c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

/* %XY to its byte in place, except %00; returns the new length. */
static size_t decode(char *s)
{
    char *w = s;
    for (const char *p = s; *p;) {
        int hi = p[0] == '%' ? hexval(p[1]) : -1, lo = hi >= 0 ? hexval(p[2]) : -1;
        if (lo >= 0 && (hi | lo)) {
            *w++ = (char)(hi << 4 | lo);
            p += 3;
        } else {
            *w++ = *p++;
        }
    }
    *w = '\0';
    return (size_t)(w - s);
}

static size_t decode_plus(char *s)
{
    for (char *p = s; *p; p++)
        if (*p == '+')
            *p = ' ';
    return decode(s);
}

/* One argument as libmicrohttpd hands it over: key and value NUL-terminated, value NULL for "key". */
static int query_arg(const srv_route *rt, srv_query *q, char *key, char *value)
{
    size_t klen = decode_plus(key), vlen = value ? decode_plus(value) : 0;
    char msg[200];
    memset(msg, 'X', sizeof msg);
    int rc = srv_query_arg(rt, q, key, klen, value, vlen, msg, sizeof msg);
    FUZZ_CHECK(rc == 0 || rc == -1, "srv_query_arg gave %d", rc);
    if (rc)
        fuzz_check_text(msg, sizeof msg, 0);
    return rc;
}

static void check_row(int i, const char *method, const char *path, const char *arg, size_t argn)
{
    FUZZ_CHECK(i < srv_nroutes, "row %d of %d", i, srv_nroutes);
    const srv_route *rt = &srv_routes[i];
    FUZZ_CHECK(!strcmp(method, rt->method) || !strcmp(method, "OPTIONS") ||
                   (!strcmp(method, "HEAD") && !strcmp(rt->method, "GET")),
               "%s %s found the row %s %s", method, path, rt->method, rt->path);
    const char *brace = strstr(rt->path, "{}");
    if (brace) {
        FUZZ_CHECK(memchr(arg, '\0', argn), "arg not NUL-terminated");
        size_t pre = (size_t)(brace - rt->path), alen = strlen(arg), plen = strlen(path);
        FUZZ_CHECK(alen > 0 && !strchr(arg, '/'), "the segment \"%s\" of %s", arg, path);
        FUZZ_CHECK(plen == strlen(rt->path) - 2 + alen && !strncmp(path, rt->path, pre) &&
                       !memcmp(path + pre, arg, alen) && !strcmp(path + pre + alen, brace + 2),
                   "%s is not %s with \"%s\"", path, rt->path, arg);
    } else if (strcmp(rt->path, "*")) {
        FUZZ_CHECK(!strcmp(path, rt->path), "%s found the row %s", path, rt->path);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096)
        return 0;
    char line[4097];
    size_t n = 0;
    while (n < size && data[n] && data[n] != '\r' && data[n] != '\n')
        n++;
    memcpy(line, data, n);
    line[n] = '\0';
    char *method = line, *target = strchr(line, ' ');
    if (!target)
        return 0;
    *target++ = '\0';
    char *query = strchr(target, '?');
    if (query)
        *query++ = '\0';
    decode(target);
    char path[512];
    snprintf(path, sizeof path, "%s", target);

    char arg[96], allow[64];
    int status = 0;
    memset(arg, 'X', sizeof arg);
    memset(allow, 'X', sizeof allow);
    int i = srv_route_find(method, path, arg, sizeof arg, allow, sizeof allow, &status);
    FUZZ_CHECK(memchr(allow, '\0', sizeof allow), "allow not NUL-terminated");
    if (i < 0) {
        FUZZ_CHECK(i == -1, "srv_route_find gave %d", i);
        FUZZ_CHECK(status == 400 || status == 404 || status == 405, "status %d for %s %s", status, method, path);
        if (status == 405) {
            size_t alen = strlen(allow);
            FUZZ_CHECK(alen >= 7 && !strcmp(allow + alen - 7, "OPTIONS"), "405 with Allow \"%s\"", allow);
            fuzz_check_text(allow, sizeof allow, 0);
        }
        return 0;
    }
    check_row(i, method, path, arg, sizeof arg);

    const srv_route *rt = &srv_routes[i];
    srv_query q;
    srv_query_init(&q);
    int bad = 0;
    /* libmicrohttpd 0.9.75's MHD_parse_arguments_: "k=v&k&=v&&", in order, stopping at the end. */
    for (char *a = query; a && *a && !bad;) {
        char *amp = strchr(a, '&'), *eq = strchr(a, '=');
        if (amp)
            *amp++ = '\0';
        if (eq && (!amp || eq < amp)) {
            *eq++ = '\0';
            bad = query_arg(rt, &q, a, eq);
        } else {
            bad = query_arg(rt, &q, a, NULL);
        }
        a = amp;
    }
    if (bad)
        return 0;
    char msg[200];
    memset(msg, 'X', sizeof msg);
    if (srv_query_done(rt, &q, msg, sizeof msg)) {
        fuzz_check_text(msg, sizeof msg, 0);
        FUZZ_CHECK(rt->flags & SRV_RT_OUTPUT, "a route without a query refused an empty one: %s", msg);
        return 0;
    }
    if (rt->flags & SRV_RT_OUTPUT) {
        const api_format_info *fi = api_format_info_of(q.fmt);
        FUZZ_CHECK((unsigned)q.fmt < API_FMT_COUNT && fi, "format %d", (int)q.fmt);
        FUZZ_CHECK(!strcmp(fi->name, q.format[0] ? q.format : "json"), "format \"%s\" read as %s", q.format,
                   fi->name);
        unsigned max = fi->mesh ? API_RES_MESH_MAX : API_RES_GRID_MAX;
        unsigned long long total = 1;
        for (int k = 0; k < 3; k++) {
            FUZZ_CHECK(q.res3[k] >= 2 && q.res3[k] <= max, "res %u for %s (\"%s\")", q.res3[k], fi->name, q.res);
            total *= q.res3[k];
        }
        FUZZ_CHECK(fi->mesh || total <= API_RES_GRID_POINTS, "%llu grid points", total);
        FUZZ_CHECK(q.comp == API_COMPRESS_NONE || (q.comp == API_COMPRESS_MESHOPT && fi->compress &&
                                                   !strcmp(q.compress, "meshopt")),
                   "compress %d (\"%s\") for %s", (int)q.comp, q.compress, fi->name);
    } else {
        FUZZ_CHECK(!q.seen, "a route without a query took one");
    }
    return 0;
}
