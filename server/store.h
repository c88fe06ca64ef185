/*
 * store.h: durable ids. The canonical model behind each id (and the request
 * it came from), kept outside the process so that an id outlives a restart
 * and can be shared between daemons. Separate from the solution cache
 * (cache.h): on a cache miss the daemon gets the model here and re-solves.
 *
 * USAGE
 *
 *   srv_store_config sc = { .spec = "var/store", .max_mb = 256 };
 *   char why[256];
 *   srv_store *s = srv_store_open(&sc, why, sizeof why);   // NULL: why says why; "none": NULL, why ""
 *   srv_store_put(s, id, model_json, request_json);         // request may be NULL
 *   char *model, *request;
 *   if (srv_store_get(s, id, &model, &request) == SRV_STORE_OK) { ...; free(model); free(request); }
 *   srv_store_close(s);
 *
 * Backends, one file and one row of store.c's table each:
 *   "DIR" or "lmdb:DIR"         LMDB (store_lmdb.c), the default: durable, bounded, LRU eviction.
 *   "redis://HOST:PORT[/DB]"    Redis (store_redis.c): shared between machines; key prefix, TTL.
 *   "none"                      no store: srv_store_open returns NULL with why "".
 * Every function is thread-safe. Entries are immutable: putting an existing id only refreshes it.
 *
 * A put the store cannot take now (SRV_STORE_DOWN: Redis unreachable) is kept in memory, within
 * pending_kb, and written by the store's own thread as soon as the store answers again (it retries
 * every second); a get of such an id answers it from memory meanwhile. Over the bound, the oldest
 * kept puts are dropped (counted: dropped). Kept puts that are still unwritten when the process
 * ends are lost; srv_store_close tries them once more first.
 */
#ifndef SRV_STORE_H
#define SRV_STORE_H

#include <stddef.h>

typedef struct srv_store srv_store;

typedef enum { SRV_STORE_OK = 0, SRV_STORE_MISSING, SRV_STORE_DOWN, SRV_STORE_NOMEM, SRV_STORE_ERROR } srv_store_status;

typedef struct {
    const char *spec;            /* see above */
    size_t max_mb;               /* LMDB: map size and bound, MiB */
    const char *prefix;          /* Redis: key prefix; NULL: "pdesolid:" */
    unsigned ttl_s;              /* Redis: seconds an entry lives after its last put or get; 0: forever */
    unsigned connect_timeout_ms; /* Redis; 0: 200 */
    unsigned command_timeout_ms; /* Redis; 0: 500 */
    size_t pending_kb;           /* puts kept while the store is down (models and requests), KiB; 0: 16384 */
} srv_store_config;

typedef struct {
    unsigned long long bytes, entries, evictions, puts, gets, misses, errors;
    unsigned long long pending;  /* puts kept in memory, waiting for the store */
    unsigned long long late;     /* kept puts written since, once the store answered again */
    unsigned long long dropped;  /* kept puts dropped, the oldest first, to stay within pending_kb */
    unsigned long long commits;  /* LMDB: write transactions this process committed (each a synchronous write) */
    int up;                      /* 1 if the store answered its last call */
} srv_store_stats;

/* 0 if spec is a valid --store value by its syntax (a directory, lmdb:DIR, redis://HOST:PORT[/DB], none),
 * else -1: what start-up checks before it opens anything. */
int srv_store_spec_check(const char *spec);
/* The store of cfg->spec, or NULL with why (why is "" for "none"). */
srv_store *srv_store_open(const srv_store_config *cfg, char *why, size_t whylen);
/* The canonical model document of id and the request it came from (both malloc'd, NUL-terminated;
 * *request is NULL if none was kept). MISSING, DOWN (unreachable now), NOMEM or ERROR otherwise. */
srv_store_status srv_store_get(srv_store *s, const char *id, char **model, char **request);
srv_store_status srv_store_put(srv_store *s, const char *id, const char *model, const char *request);
void srv_store_stats_get(srv_store *s, srv_store_stats *out);
/* 1 if usable now (Redis: connected); cheap, never waits for another thread's call. */
int srv_store_ready(srv_store *s);
/* Appends the store's lines of /metrics (Prometheus text) to b, a srv_sbuf (sbuf.h). */
void srv_store_metrics(srv_store *s, void *sbuf);
/* The spec, for messages: "lmdb:var/store", "redis://127.0.0.1:6379/0". */
const char *srv_store_name(const srv_store *s);
void srv_store_close(srv_store *s);

#endif
