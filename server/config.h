/*
 * config.h: pdesolidd's command-line flags, their defaults and limits.
 *
 * USAGE
 *
 *   srv_config c;
 *   int rc = srv_config_parse(argc, argv, &c, stdout, stderr);
 *   if (rc) return rc == 1 ? 0 : 2;    // 1: --help or --version printed; 2: a bad argument, named on err
 *   srv_config_print(&c, stderr);      // one line: the version and every flag's value
 *
 * Every flag that takes a value takes it as `--flag VALUE` or `--flag=VALUE`.
 * In the first form a VALUE may not start with "--" (so that `--port --quiet`
 * says that --port needs a value); the second form takes anything. An unknown
 * flag, a flag without its value, a bad value or a stray argument makes
 * srv_config_parse return 2 after one message on err that names exactly that
 * argument. `--web DIR` given explicitly must hold a readable DIR/index.html
 * (2 otherwise); the default web directory, when missing, only warns on err.
 * One table in config.c holds every flag: its name, field, range, default and
 * help; the usage text and srv_config_print are written from it.
 */
#ifndef SRV_CONFIG_H
#define SRV_CONFIG_H

#include <stddef.h>
#include <stdio.h>

#include "log.h"
#include "version.h"

typedef struct {
    char bind[64];          /* --bind: address to listen on */
    unsigned port;          /* --port: 0 picks a free port */
    int threads;            /* --threads: solver threads, one per core by default */
    size_t queue;           /* --queue: jobs waiting before 503 */
    size_t cache_bytes;     /* --cache-mb, in bytes */
    size_t max_body;        /* --max-body */
    size_t max_points;      /* --max-points: per eval request */
    char cors[1024];        /* --cors-origin: comma-separated origins, or * */
    char allow_host[1024];  /* --allow-host: host names answered besides IP addresses and localhost, or * (host.h) */
    unsigned timeout;       /* --timeout: seconds a connection may idle */
    unsigned per_ip;        /* --max-conns-per-ip */
    unsigned max_conns;     /* --max-conns */
    unsigned grace;         /* --grace: seconds to finish requests on SIGTERM */
    char web[1024];         /* --web: the front-end's directory */
    int quiet;              /* --quiet: no access log */
    double request_timeout; /* --request-timeout: seconds to receive a whole request (headers and body) */
    double job_timeout;     /* --job-timeout: wall-clock seconds one job may run before it is cancelled */
    double max_work;        /* --max-work: largest estimated cost of a request, in units of about 1 ns of a core */
    size_t max_mem;         /* --max-mem-mb, in bytes: scratch memory of one request beyond the caches */
    double heavy_work;      /* --heavy-work: an estimate from which a request's solid output waits apart (pool.h) */
    size_t heavy_queue;     /* --heavy-queue: heavy requests that may wait before 503 */
    int http_threads;       /* --http-threads: libmicrohttpd's polling threads, one per core by default */
    srv_log_format log_format; /* --log-format text|json */
    char store[1024];       /* --store: DIR, lmdb:DIR, redis://HOST:PORT[/DB] or none (store.h) */
    size_t store_mb;        /* --store-mb: the LMDB store's bound, MiB */
    char store_prefix[128]; /* --store-prefix: Redis key prefix */
    unsigned store_ttl;     /* --store-ttl: Redis entries' lifetime after their last use, s; 0: forever */
} srv_config;

/* Defaults, then flags. Returns 0 to run, 1 after printing help or the version on out, 2 on a bad
 * argument (one message on err). c is filled in every case (with defaults where no flag was read). */
int srv_config_parse(int argc, char **argv, srv_config *c, FILE *out, FILE *err);
/* One line: "pdesolidd VERSION: --bind ... --port ..." with every flag's value. */
void srv_config_print(const srv_config *c, FILE *f);

/* The item that starts at p of a flag's comma-separated list (--cors-origin, --allow-host), spaces around it
 * trimmed: its length, with *item its start and *next the next item's, or NULL after the last. */
size_t srv_config_item(const char *p, const char **item, const char **next);

/* The daemon's version is the project's (api/version.h); http.c says SRV_VERSION. */
#define SRV_VERSION PDESOLID_VERSION

#endif
