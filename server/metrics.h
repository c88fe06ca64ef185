/*
 * metrics.h: counters for GET /metrics, in the Prometheus text format.
 * Every call is thread-safe.
 */
#ifndef SRV_METRICS_H
#define SRV_METRICS_H

#include <stddef.h>

#include "cache.h"

typedef struct srv_metrics srv_metrics;

srv_metrics *srv_metrics_create(const char *const *routes, int nroutes);
void srv_metrics_destroy(srv_metrics *m);

void srv_metrics_request(srv_metrics *m, int route, int status, double seconds);
void srv_metrics_solve(srv_metrics *m, double seconds);
void srv_metrics_output(srv_metrics *m, double seconds, size_t bytes);
/* A request's rest deferred to the heavy lane (pool.h) and run. */
void srv_metrics_heavy(srv_metrics *m);
void srv_metrics_connection(srv_metrics *m, int delta);

/* The exposition text (malloc'd), with the caches' figures and the queue depth. */
char *srv_metrics_render(srv_metrics *m, const srv_cache_stats *cache, size_t queue_depth, size_t in_flight,
                         unsigned long long response_hits);

#endif
