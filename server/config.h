/*
 * config.h: pdesolidd's command-line flags, their defaults and limits.
 */
#ifndef SRV_CONFIG_H
#define SRV_CONFIG_H

#include <stddef.h>
#include <stdio.h>

typedef struct {
    char bind[64];          /* --bind: address to listen on */
    unsigned port;          /* --port: 0 picks a free port */
    int threads;            /* --threads: solver threads, one per core by default */
    size_t queue;           /* --queue: jobs waiting before 503 */
    size_t cache_bytes;     /* --cache-mb */
    size_t max_body;        /* --max-body */
    size_t max_points;      /* --max-points: per eval request */
    char cors[1024];        /* --cors-origin: comma-separated origins, or * */
    unsigned timeout;       /* --timeout: seconds a connection may idle */
    unsigned per_ip;        /* --max-conns-per-ip */
    unsigned max_conns;     /* --max-conns */
    unsigned grace;         /* --grace: seconds to finish requests on SIGTERM */
    char web[1024];         /* --web: the front-end's directory */
    int quiet;              /* --quiet: no access log */
} srv_config;

/* Defaults, then flags. Returns 0 to run, 1 after printing help or the version, 2 on a bad flag. */
int srv_config_parse(int argc, char **argv, srv_config *c, FILE *out, FILE *err);
void srv_config_print(const srv_config *c, FILE *f);

#define SRV_VERSION "0.3.0"

#endif
