/*
 * config.c: flags (config.h).
 */
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "config.h"

static const char usage[] =
    "usage: pdesolidd [OPTIONS]\n"
    "\n"
    "The pdesolid solve server: an HTTP daemon that solves fourth-order PDE solids\n"
    "in closed form and returns closed forms, grids and meshes (docs/API.md).\n"
    "\n"
    "options (defaults in brackets):\n"
    "  --bind ADDR            address to listen on [127.0.0.1]\n"
    "  --port N               port; 0 picks a free one [8080]\n"
    "  --threads N            solver threads [one per core]\n"
    "  --queue N              jobs that may wait for a thread before 503 [64]\n"
    "  --cache-mb N           bound of the solution cache, MiB [256]\n"
    "  --max-body SIZE        largest request body, e.g. 1MiB, 512KiB [1MiB]\n"
    "  --max-points N         points in one eval request [100000]\n"
    "  --cors-origin LIST     origins allowed cross-origin calls, comma-separated,\n"
    "                         or * for any [none: same origin only]\n"
    "  --timeout S            seconds before an idle connection is closed [30]\n"
    "  --max-conns-per-ip N   connections from one address [128]\n"
    "  --max-conns N          connections in all [1024]\n"
    "  --grace S              seconds to finish requests on SIGTERM or SIGINT [30]\n"
    "  --web DIR              the browser front-end's files [clients/web beside build/]\n"
    "  --quiet                no access log on stderr\n"
    "  -h, --help             this text\n"
    "  --version              the version\n";

/* SIZE: bytes, or with KiB, MiB, GiB (or K, M, G, KB, MB, GB as powers of 1024). */
static int parse_size(const char *s, size_t *out)
{
    char *end;
    unsigned long long v = strtoull(s, &end, 10);
    if (end == s || *s == '-')
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

static int parse_uint(const char *s, unsigned long long lo, unsigned long long hi, unsigned long long *out)
{
    char *end;
    if (*s < '0' || *s > '9')
        return -1;
    unsigned long long v = strtoull(s, &end, 10);
    if (*end || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

/* The web directory beside the binary: build/pdesolidd -> clients/web. */
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
    *slash = '\0';
    slash = strrchr(exe, '/');
    if (slash)
        *slash = '\0';
    snprintf(out, n, "%.900s/clients/web", exe);
}

int srv_config_parse(int argc, char **argv, srv_config *c, FILE *out, FILE *err)
{
    memset(c, 0, sizeof *c);
    snprintf(c->bind, sizeof c->bind, "127.0.0.1");
    c->port = 8080;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    c->threads = cores > 0 ? (int)cores : 2;
    c->queue = 64;
    c->cache_bytes = 256u << 20;
    c->max_body = 1u << 20;
    c->max_points = 100000;
    c->timeout = 30;
    c->per_ip = 128;
    c->max_conns = 1024;
    c->grace = 30;
    default_web(c->web, sizeof c->web);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        unsigned long long n;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage, out);
            return 1;
        }
        if (!strcmp(a, "--version")) {
            fprintf(out, "pdesolidd %s\n", SRV_VERSION);
            return 1;
        }
        if (!strcmp(a, "--quiet")) {
            c->quiet = 1;
            continue;
        }
        if (!v) {
            fprintf(err, "pdesolidd: %s needs a value (see --help)\n", a);
            return 2;
        }
        int bad = 0;
        if (!strcmp(a, "--bind"))
            bad = snprintf(c->bind, sizeof c->bind, "%s", v) >= (int)sizeof c->bind;
        else if (!strcmp(a, "--port"))
            bad = parse_uint(v, 0, 65535, &n) || (c->port = (unsigned)n, 0);
        else if (!strcmp(a, "--threads"))
            bad = parse_uint(v, 1, 256, &n) || (c->threads = (int)n, 0);
        else if (!strcmp(a, "--queue"))
            bad = parse_uint(v, 1, 1u << 20, &n) || (c->queue = (size_t)n, 0);
        else if (!strcmp(a, "--cache-mb"))
            bad = parse_uint(v, 0, 1u << 20, &n) || (c->cache_bytes = (size_t)n << 20, 0);
        else if (!strcmp(a, "--max-body"))
            bad = parse_size(v, &c->max_body) || c->max_body < 1024;
        else if (!strcmp(a, "--max-points"))
            bad = parse_uint(v, 1, 10000000, &n) || (c->max_points = (size_t)n, 0);
        else if (!strcmp(a, "--cors-origin"))
            bad = snprintf(c->cors, sizeof c->cors, "%s", v) >= (int)sizeof c->cors;
        else if (!strcmp(a, "--timeout"))
            bad = parse_uint(v, 1, 86400, &n) || (c->timeout = (unsigned)n, 0);
        else if (!strcmp(a, "--max-conns-per-ip"))
            bad = parse_uint(v, 1, 65535, &n) || (c->per_ip = (unsigned)n, 0);
        else if (!strcmp(a, "--max-conns"))
            bad = parse_uint(v, 1, 65535, &n) || (c->max_conns = (unsigned)n, 0);
        else if (!strcmp(a, "--grace"))
            bad = parse_uint(v, 0, 3600, &n) || (c->grace = (unsigned)n, 0);
        else if (!strcmp(a, "--web"))
            bad = snprintf(c->web, sizeof c->web, "%s", v) >= (int)sizeof c->web;
        else {
            fprintf(err, "pdesolidd: unknown option %s\n\n%s", a, usage);
            return 2;
        }
        if (bad) {
            fprintf(err, "pdesolidd: %s %s: not a valid value (see --help)\n", a, v);
            return 2;
        }
        i++;
    }
    return 0;
}

void srv_config_print(const srv_config *c, FILE *f)
{
    fprintf(f,
            "pdesolidd %s: --bind %s --port %u --threads %d --queue %zu --cache-mb %zu --max-body %zu "
            "--max-points %zu --cors-origin '%s' --timeout %u --max-conns-per-ip %u --max-conns %u --grace %u "
            "--web %s%s\n",
            SRV_VERSION, c->bind, c->port, c->threads, c->queue, c->cache_bytes >> 20, c->max_body, c->max_points,
            c->cors, c->timeout, c->per_ip, c->max_conns, c->grace, c->web, c->quiet ? " --quiet" : "");
}
