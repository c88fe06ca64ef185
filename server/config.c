/*
 * config.c: flags (config.h). One table row per flag: parsing, defaults, the
 * usage text and srv_config_print all read the table, so that a new flag is
 * one row (and its field in srv_config).
 */
#include <arpa/inet.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "config.h"
#include "host.h"
#include "store.h"

typedef enum {
    K_STR,       /* char array; lo is the least length */
    K_HOSTS,     /* ... host names, comma-separated, or * (host.h) */
    K_ADDR,      /* ... a numeric IP address */
    K_STORE,     /* ... a store's spec (store.h) */
    K_UNSIGNED,  /* unsigned, a whole number in [lo, hi] */
    K_INT,       /* int, a whole number in [lo, hi] */
    K_COUNT,     /* size_t, a whole number in [lo, hi] */
    K_MB,        /* size_t bytes, given in MiB in [lo, hi] */
    K_BYTES,     /* size_t bytes, given as SIZE (parse_size), at least lo */
    K_REAL,      /* double over 0, in [lo, hi]: 2.5, 2e9, 2000000000 */
    K_LOGFMT,    /* srv_log_format: text or json */
    K_SWITCH,    /* int set to 1; takes no value */
    K_HELP,
    K_VERSION
} kind;

static const size_t kind_size[] = { [K_UNSIGNED] = sizeof(unsigned), [K_INT] = sizeof(int),
                                    [K_COUNT] = sizeof(size_t),      [K_MB] = sizeof(size_t),
                                    [K_BYTES] = sizeof(size_t),      [K_REAL] = sizeof(double),
                                    [K_LOGFMT] = sizeof(srv_log_format), [K_SWITCH] = sizeof(int) };

typedef struct {
    const char *name, *arg;  /* "--port", "N" (NULL for a switch) */
    kind k;
    size_t off, size;        /* the field in srv_config */
    double lo, hi;
    const char *def;         /* the default, parsed as a value would be; NULL: set in code */
    const char *shown;       /* the default as the usage shows it, when def is NULL or not plain */
    const char *help;        /* "\n" continues on the next line, indented */
} flag;

#define AT(f) offsetof(srv_config, f), sizeof(((srv_config *)0)->f)
#define NONE 0, 0

/* --bind's address: numeric, as srv_start's getaddrinfo takes it (AI_NUMERICHOST). */
static int address_check(const char *v)
{
    unsigned char a[16];
    return inet_pton(AF_INET, v, a) == 1 || inet_pton(AF_INET6, v, a) == 1 ? 0 : -1;
}

/* The string kinds: what checks a value beyond its length (NULL: nothing), and what a valid one is. */
#define IS_STR(k) ((k) <= K_STORE)
static const struct {
    int (*check)(const char *v);
    const char *what;
} str_kind[] = {
    [K_STR] = { NULL, "" },
    [K_HOSTS] = { srv_host_list_check, "host names separated by commas (.NAME: NAME and the names under it), or *; " },
    [K_ADDR] = { address_check, "a numeric IPv4 or IPv6 address, such as 127.0.0.1, 0.0.0.0 or ::1; " },
    [K_STORE] = { srv_store_spec_check, "DIR, lmdb:DIR, redis://HOST:PORT[/DB] or none; " },
};

static const flag flags[] = {
    { "--bind", "ADDR", K_ADDR, AT(bind), 1, 0, "127.0.0.1", NULL, "address to listen on" },
    { "--port", "N", K_UNSIGNED, AT(port), 0, 65535, "8080", NULL, "port; 0 picks a free one" },
    { "--threads", "N", K_INT, AT(threads), 1, 256, NULL, "one per core", "solver threads" },
    { "--http-threads", "N", K_INT, AT(http_threads), 1, 256, NULL, "one per core",
      "libmicrohttpd's polling threads, each serving\nconnections" },
    { "--queue", "N", K_COUNT, AT(queue), 1, 1 << 20, "64", NULL, "jobs that may wait for a thread before 503" },
    { "--cache-mb", "N", K_MB, AT(cache_bytes), 0, 1 << 20, "256", NULL, "bound of the solution cache, MiB" },
    { "--max-body", "SIZE", K_BYTES, AT(max_body), 1024, 0, "1MiB", NULL,
      "largest request body, e.g. 1MiB, 512KiB, 65536" },
    { "--max-points", "N", K_COUNT, AT(max_points), 1, 10000000, "100000", NULL, "points in one eval request" },
    { "--max-work", "N", K_REAL, AT(max_work), 0, 1e18, "1e9", NULL,
      "refuse with a 422 a request whose estimated cost\n"
      "is over N units (about 1 ns of one core each);\n"
      "2e9 or 2000000000" },
    { "--max-mem-mb", "N", K_MB, AT(max_mem), 1, 1 << 20, "64", NULL,
      "scratch memory one request may use beyond\nthe caches, MiB" },
    { "--heavy-work", "N", K_REAL, AT(heavy_work), 0, 1e18, "5e7", NULL,
      "a request estimated at N units or more runs its\n"
      "properties and output (an eval, its points; a\n"
      "/solve body of N/90 bytes or more, all of it)\n"
      "apart, on at most all threads but one: light\n"
      "requests wait for no heavy work, only for\n"
      "parses and for solves estimated light (docs/API.md;\n"
      "with one thread, a heavy request waits for at\n"
      "most 8 light ones)" },
    { "--heavy-queue", "N", K_COUNT, AT(heavy_queue), 1, 1 << 20, "8", NULL,
      "heavy requests that may wait before 503" },
    { "--job-timeout", "S", K_REAL, AT(job_timeout), 0, 86400, "2", NULL,
      "wall-clock seconds of solver time one request's\njobs may take in all; past it they are cancelled" },
    { "--request-timeout", "S", K_REAL, AT(request_timeout), 1, 86400, "30", NULL,
      "seconds for a request's head (from the opening\nof its connection or its previous answer) and\n"
      "again for its body (from the end of its head);\npast either the connection is closed.\n"
      "At least 1, and never off: it bounds how long\na slow client holds a connection" },
    { "--timeout", "S", K_UNSIGNED, AT(timeout), 1, 86400, "30", NULL,
      "seconds before an idle connection is closed" },
    { "--max-conns-per-ip", "N", K_UNSIGNED, AT(per_ip), 1, 65535, "128", NULL,
      "connections open at once from one address; a\n"
      "new one over the limit is closed at once, the\n"
      "others stay. No address is locked out longer\n"
      "than --request-timeout (a request in progress)\n"
      "or --timeout (an idle keep-alive connection)" },
    { "--max-conns", "N", K_UNSIGNED, AT(max_conns), 1, 65535, "1024", NULL,
      "connections in all; 64 more are answered 503\n"
      "with Retry-After and closed, and past those a\n"
      "new one is closed at once" },
    { "--grace", "S", K_UNSIGNED, AT(grace), 0, 3600, "30", NULL,
      "seconds to finish requests on SIGTERM or SIGINT" },
    { "--cors-origin", "LIST", K_STR, AT(cors), 0, 0, "", "none: same origin only",
      "origins allowed cross-origin calls, comma-separated,\nor * for any" },
    { "--allow-host", "LIST", K_HOSTS, AT(allow_host), 0, 0, "", "none",
      "host names served besides IP addresses and\n"
      "localhost (others get 403: DNS rebinding),\n"
      "comma-separated; .NAME: NAME and the names\n"
      "under it; * for any" },
    { "--web", "DIR", K_STR, AT(web), 1, 0, NULL, "clients/web by the binary",
      "the browser front-end's files; DIR/index.html\nmust be readable; installed: found in\nPREFIX/share/pdesolid/web" },
    { "--log-format", "F", K_LOGFMT, AT(log_format), 0, 0, "text", NULL,
      "access log lines: text, or json (one object\na line)" },
    { "--store", "SPEC", K_STORE, AT(store), 1, 0, "var/store", NULL,
      "durable ids: DIR or lmdb:DIR (LMDB),\nredis://HOST:PORT[/DB], or none; installed:\n/var/lib/pdesolid" },
    { "--store-mb", "N", K_COUNT, AT(store_mb), 1, 1 << 20, "256", NULL,
      "bound of the LMDB store, MiB: least recently used ids\ngo first" },
    { "--store-prefix", "S", K_STR, AT(store_prefix), 0, 0, "pdesolid:", NULL, "key prefix in Redis" },
    { "--store-ttl", "S", K_UNSIGNED, AT(store_ttl), 0, 4000000000u, "0", NULL,
      "seconds a Redis entry lives after its last use;\n0: forever" },
    { "--quiet", NULL, K_SWITCH, AT(quiet), 0, 0, NULL, NULL, "no access log on stderr" },
    { "-h", NULL, K_HELP, NONE, 0, 0, NULL, NULL, "this text" },
    { "--help", NULL, K_HELP, NONE, 0, 0, NULL, NULL, "this text" },
    { "--version", NULL, K_VERSION, NONE, 0, 0, NULL, NULL, "the version" },
};
#define NFLAGS (sizeof flags / sizeof *flags)

static const char intro[] =
    "usage: pdesolidd [OPTIONS]\n"
    "\n"
    "The pdesolid solve server: an HTTP daemon that solves fourth-order PDE solids\n"
    "in closed form and returns closed forms, grids and meshes (docs/API.md).\n"
    "Every option that takes a value takes it as --opt VALUE or --opt=VALUE.\n"
    "\n"
    "options (defaults in brackets):\n";

static void print_usage(FILE *f)
{
    fputs(intro, f);
    for (size_t i = 0; i < NFLAGS; i++) {
        const flag *r = &flags[i];
        if (!strcmp(r->name, "-h"))
            continue;   /* shown with --help */
        char left[64];
        snprintf(left, sizeof left, "%s%s%s%s", !strcmp(r->name, "--help") ? "-h, " : "", r->name,
                 r->arg ? " " : "", r->arg ? r->arg : "");
        fprintf(f, "  %-22s ", left);
        for (const char *h = r->help; *h; h++) {
            fputc(*h, f);
            if (*h == '\n')
                fprintf(f, "%25s", "");
        }
        const char *d = r->shown ? r->shown : r->def;
        if (d)
            fprintf(f, " [%s]", d);
        fputc('\n', f);
    }
}

/* SIZE: bytes, or with KiB, MiB, GiB (or K, M, G, KB, MB, GB as powers of 1024). */
static int parse_size(const char *s, size_t *out)
{
    char *end;
    if (*s < '0' || *s > '9')
        return -1;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno)
        return -1;
    unsigned long long mul = 1;
    if (!strcmp(end, "") || !strcmp(end, "B"))
        mul = 1;
    else if (!strcmp(end, "K") || !strcmp(end, "KB") || !strcmp(end, "KiB"))
        mul = 1ull << 10;
    else if (!strcmp(end, "M") || !strcmp(end, "MB") || !strcmp(end, "MiB"))
        mul = 1ull << 20;
    else if (!strcmp(end, "G") || !strcmp(end, "GB") || !strcmp(end, "GiB"))
        mul = 1ull << 30;
    else
        return -1;
    if (v > (unsigned long long)SIZE_MAX / mul)
        return -1;
    *out = (size_t)(v * mul);
    return 0;
}

static int parse_whole(const char *s, double lo, double hi, unsigned long long *out)
{
    char *end;
    if (*s < '0' || *s > '9')
        return -1;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || *end || (double)v < lo || (double)v > hi)
        return -1;
    *out = v;
    return 0;
}

/* A plain decimal number (digits, '.', an exponent) over 0 in [lo, hi]: no hex, inf, nan or spaces, which strtod
 * would take. */
static int parse_real(const char *s, double lo, double hi, double *out)
{
    if (!((*s >= '0' && *s <= '9') || *s == '.') || strspn(s, "0123456789.eE+-") != strlen(s))
        return -1;
    char *end;
    double v = strtod(s, &end);
    if (*end || !isfinite(v) || !(v > 0) || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

/* Sets the row's field from v; -1 if v is not a valid value. */
static int set(const flag *r, const char *v, srv_config *c)
{
    void *p = (char *)c + r->off;
    unsigned long long n;
    size_t z;
    double d;
    if (!IS_STR(r->k) && r->size != kind_size[r->k])
        return -1;   /* a row whose kind does not fit its field: the defaults test fails */
    if (IS_STR(r->k)) {
        if (strlen(v) < (size_t)r->lo || strlen(v) >= r->size || (str_kind[r->k].check && str_kind[r->k].check(v)))
            return -1;
        memcpy(p, v, strlen(v) + 1);
        return 0;
    }
    switch (r->k) {
    case K_UNSIGNED:
        if (parse_whole(v, r->lo, r->hi, &n))
            return -1;
        *(unsigned *)p = (unsigned)n;
        return 0;
    case K_INT:
        if (parse_whole(v, r->lo, r->hi, &n))
            return -1;
        *(int *)p = (int)n;
        return 0;
    case K_COUNT:
        if (parse_whole(v, r->lo, r->hi, &n))
            return -1;
        *(size_t *)p = (size_t)n;
        return 0;
    case K_MB:
        if (parse_whole(v, r->lo, r->hi, &n))
            return -1;
        *(size_t *)p = (size_t)n << 20;
        return 0;
    case K_BYTES:
        if (parse_size(v, &z) || (double)z < r->lo)
            return -1;
        *(size_t *)p = z;
        return 0;
    case K_REAL:
        if (parse_real(v, r->lo, r->hi, &d))
            return -1;
        *(double *)p = d;
        return 0;
    case K_LOGFMT:
        if (strcmp(v, "text") && strcmp(v, "json"))
            return -1;
        *(srv_log_format *)p = strcmp(v, "json") ? SRV_LOG_TEXT : SRV_LOG_JSON;
        return 0;
    case K_STR:   /* above */
    case K_HOSTS:
    case K_ADDR:
    case K_STORE:
    case K_SWITCH:
    case K_HELP:
    case K_VERSION:
        break;
    }
    return -1;
}

/* What a valid value of the row is, for the error message. */
static void describe(const flag *r, char *out, size_t n)
{
    if (IS_STR(r->k)) {
        snprintf(out, n, "%s%sat most %zu characters", str_kind[r->k].what, r->lo ? "not empty, " : "", r->size - 1);
        return;
    }
    switch (r->k) {
    case K_UNSIGNED:
    case K_INT:
    case K_COUNT:
    case K_MB:
        snprintf(out, n, "a whole number from %.0f to %.0f", r->lo, r->hi);
        break;
    case K_BYTES:
        snprintf(out, n, "a size such as 1MiB, 512KiB or 65536, at least %.0f bytes", r->lo);
        break;
    case K_REAL:
        if (r->lo > 0)
            snprintf(out, n, "a number from %g to %g, such as %s", r->lo, r->hi, r->def ? r->def : "1");
        else
            snprintf(out, n, "a number over 0 and at most %g, such as %s", r->hi, r->def ? r->def : "1");
        break;
    case K_LOGFMT:
        snprintf(out, n, "text or json");
        break;
    default:
        snprintf(out, n, "no value");
        break;
    }
}

/* Candidates for the web directory: clients/web beside the binary's directory and up to two levels
 * further up (build/pdesolidd and build/san/pdesolidd both find the source tree's), then
 * share/pdesolid/web beside it (an installed PREFIX/sbin/pdesolidd: `make install`). The first whose
 * index.html is readable, else the first candidate. */
static void default_web(char *out, size_t n)
{
    char exe[PATH_MAX];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    snprintf(out, n, "clients/web");
    if (len <= 0)
        return;
    exe[len] = '\0';
    char *slash = strrchr(exe, '/');
    if (!slash)
        return;
    *slash = '\0';   /* the binary's directory */
    char prefix[PATH_MAX];
    snprintf(prefix, sizeof prefix, "%s", exe);
    for (int up = 0; up < 4; up++) {
        char dir[PATH_MAX + 32], index[PATH_MAX + 48];
        if (up < 3) {
            slash = strrchr(exe, '/');
            if (!slash)
                continue;
            *slash = '\0';
            snprintf(dir, sizeof dir, "%s/clients/web", exe);
        } else {
            slash = strrchr(prefix, '/');
            if (!slash)
                return;
            *slash = '\0';
            snprintf(dir, sizeof dir, "%s/share/pdesolid/web", prefix);
        }
        snprintf(index, sizeof index, "%s/index.html", dir);
        if (up == 0 || !access(index, R_OK))
            snprintf(out, n, "%.1000s", dir);
        if (!access(index, R_OK))
            return;
    }
}

static const flag *find(const char *a, size_t len)
{
    for (size_t i = 0; i < NFLAGS; i++)
        if (strlen(flags[i].name) == len && !strncmp(flags[i].name, a, len))
            return &flags[i];
    return NULL;
}

int srv_config_parse(int argc, char **argv, srv_config *c, FILE *out, FILE *err)
{
    memset(c, 0, sizeof *c);
    for (size_t i = 0; i < NFLAGS; i++)
        if (flags[i].def && set(&flags[i], flags[i].def, c)) {
            fprintf(err, "pdesolidd: the default of %s, %s, is not valid (a bug)\n", flags[i].name, flags[i].def);
            return 2;
        }
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    c->threads = c->http_threads = cores > 0 ? (cores < 256 ? (int)cores : 256) : 2;
    default_web(c->web, sizeof c->web);
    int web_given = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (a[0] != '-') {
            fprintf(err, "pdesolidd: unexpected argument %s: pdesolidd takes options only (see --help)\n", a);
            return 2;
        }
        const char *eq = strncmp(a, "--", 2) ? NULL : strchr(a, '=');
        const flag *r = find(a, eq ? (size_t)(eq - a) : strlen(a));
        if (!r) {
            fprintf(err, "pdesolidd: unknown option %s (see --help)\n", a);
            return 2;
        }
        if (!r->arg) {
            if (eq) {
                fprintf(err, "pdesolidd: %s: %s takes no value (see --help)\n", a, r->name);
                return 2;
            }
            if (r->k == K_HELP) {
                print_usage(out);
                return 1;
            }
            if (r->k == K_VERSION) {
                fprintf(out, "pdesolidd %s\n", PDESOLID_VERSION);
                return 1;
            }
            *(int *)((char *)c + r->off) = 1;
            continue;
        }
        const char *v = eq ? eq + 1 : NULL;
        if (!eq && i + 1 < argc && strncmp(argv[i + 1], "--", 2))
            v = argv[++i];
        if (!v) {
            fprintf(err, "pdesolidd: %s needs a value: %s %s or %s=%s (see --help)\n", a, r->name, r->arg, r->name,
                    r->arg);
            return 2;
        }
        if (set(r, v, c)) {
            char what[128];
            describe(r, what, sizeof what);
            fprintf(err, "pdesolidd: %s%s%s: not a valid value; give %s (see --help)\n", a, eq ? "" : " ",
                    eq ? "" : v, what);
            return 2;
        }
        web_given |= r->off == offsetof(srv_config, web);
    }
    char index[sizeof c->web + 16];
    snprintf(index, sizeof index, "%s/index.html", c->web);
    if (access(index, R_OK)) {
        if (web_given) {
            fprintf(err, "pdesolidd: --web %s: cannot read %s (%s); give the directory of the front-end, "
                         "clients/web\n", c->web, index, strerror(errno));
            return 2;
        }
        fprintf(err, "pdesolidd: warning: no front-end in %s (%s), so / answers 404; give --web DIR\n", c->web,
                strerror(errno));
    }
    return 0;
}

size_t srv_config_item(const char *p, const char **item, const char **next)
{
    const char *comma = strchr(p, ',');
    size_t n = comma ? (size_t)(comma - p) : strlen(p);
    while (n && *p == ' ')
        p++, n--;
    while (n && p[n - 1] == ' ')
        n--;
    *item = p;
    *next = comma ? comma + 1 : NULL;
    return n;
}

void srv_config_print(const srv_config *c, FILE *f)
{
    fprintf(f, "pdesolidd %s:", PDESOLID_VERSION);
    for (size_t i = 0; i < NFLAGS; i++) {
        const flag *r = &flags[i];
        const void *p = (const char *)c + r->off;
        if (IS_STR(r->k)) {
            fprintf(f, *(const char *)p ? " %s %s" : " %s ''", r->name, (const char *)p);
            continue;
        }
        switch (r->k) {
        case K_UNSIGNED:
            fprintf(f, " %s %u", r->name, *(const unsigned *)p);
            break;
        case K_INT:
            fprintf(f, " %s %d", r->name, *(const int *)p);
            break;
        case K_COUNT:
        case K_BYTES:
            fprintf(f, " %s %zu", r->name, *(const size_t *)p);
            break;
        case K_MB:
            fprintf(f, " %s %zu", r->name, *(const size_t *)p >> 20);
            break;
        case K_REAL:
            fprintf(f, " %s %g", r->name, *(const double *)p);
            break;
        case K_LOGFMT:
            fprintf(f, " %s %s", r->name, *(const srv_log_format *)p == SRV_LOG_JSON ? "json" : "text");
            break;
        case K_SWITCH:
            if (*(const int *)p)
                fprintf(f, " %s", r->name);
            break;
        case K_STR:   /* above */
        case K_HOSTS:
        case K_ADDR:
        case K_STORE:
        case K_HELP:
        case K_VERSION:
            break;
        }
    }
    fputc('\n', f);
}
