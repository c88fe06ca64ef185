/*
 * metrics.c: request, latency, solve and output counters (metrics.h).
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "metrics.h"
#include "sbuf.h"

static const int statuses[] = { 200, 204, 304, 400, 403, 404, 405, 408, 413, 422, 499, 500, 501, 503 };
#define NSTATUS (int)(sizeof statuses / sizeof *statuses)
static const double buckets[] = { 0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10 };
#define NBUCKET (int)(sizeof buckets / sizeof *buckets)

/* What every request counts is atomic, so that the polling threads never wait for one another here;
 * the rest is under the lock. */
struct srv_metrics {
    pthread_mutex_t lock;
    const char *const *routes;
    int nroutes;
    atomic_ullong *requests;                /* nroutes x (NSTATUS + 1 for others) */
    atomic_ullong hist[NBUCKET + 1];
    atomic_ullong latency_ns, latency_count;
    double solve_sum, output_sum;
    unsigned long long solve_count, output_count, output_bytes;
    atomic_llong connections;
    atomic_ullong heavy;                    /* parts run apart (--heavy-work) */
};

srv_metrics *srv_metrics_create(const char *const *routes, int nroutes)
{
    srv_metrics *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->requests = calloc((size_t)nroutes * (NSTATUS + 1), sizeof *m->requests);
    if (!m->requests || pthread_mutex_init(&m->lock, NULL)) {
        free(m->requests);
        free(m);
        return NULL;
    }
    m->routes = routes;
    m->nroutes = nroutes;
    return m;
}

void srv_metrics_destroy(srv_metrics *m)
{
    if (!m)
        return;
    pthread_mutex_destroy(&m->lock);
    free(m->requests);
    free(m);
}

void srv_metrics_request(srv_metrics *m, int route, int status, double seconds)
{
    int s = 0;
    while (s < NSTATUS && statuses[s] != status)
        s++;
    int b = 0;
    while (b < NBUCKET && seconds > buckets[b])
        b++;
    if (route >= 0 && route < m->nroutes)
        atomic_fetch_add_explicit(&m->requests[route * (NSTATUS + 1) + s], 1, memory_order_relaxed);
    atomic_fetch_add_explicit(&m->hist[b], 1, memory_order_relaxed);
    atomic_fetch_add_explicit(&m->latency_ns, (unsigned long long)(seconds * 1e9), memory_order_relaxed);
    atomic_fetch_add_explicit(&m->latency_count, 1, memory_order_relaxed);
}

void srv_metrics_solve(srv_metrics *m, double seconds)
{
    pthread_mutex_lock(&m->lock);
    m->solve_sum += seconds;
    m->solve_count++;
    pthread_mutex_unlock(&m->lock);
}

void srv_metrics_output(srv_metrics *m, double seconds, size_t bytes)
{
    pthread_mutex_lock(&m->lock);
    m->output_sum += seconds;
    m->output_count++;
    m->output_bytes += bytes;
    pthread_mutex_unlock(&m->lock);
}

void srv_metrics_heavy(srv_metrics *m)
{
    atomic_fetch_add_explicit(&m->heavy, 1, memory_order_relaxed);
}

void srv_metrics_connection(srv_metrics *m, int delta)
{
    atomic_fetch_add_explicit(&m->connections, delta, memory_order_relaxed);
}

char *srv_metrics_render(srv_metrics *m, const srv_cache_stats *c, size_t queue_depth, size_t in_flight,
                         unsigned long long response_hits)
{
    srv_sbuf b = { 0 };
    pthread_mutex_lock(&m->lock);
    srv_sbuf_printf(&b, "# HELP pdesolid_requests_total HTTP requests answered, by route and status.\n"
            "# TYPE pdesolid_requests_total counter\n");
    for (int r = 0; r < m->nroutes; r++)
        for (int s = 0; s <= NSTATUS; s++) {
            unsigned long long n = atomic_load(&m->requests[r * (NSTATUS + 1) + s]);
            if (n) {
                if (s < NSTATUS)
                    srv_sbuf_printf(&b, "pdesolid_requests_total{route=\"%s\",status=\"%d\"} %llu\n", m->routes[r], statuses[s], n);
                else
                    srv_sbuf_printf(&b, "pdesolid_requests_total{route=\"%s\",status=\"other\"} %llu\n", m->routes[r], n);
            }
        }
    srv_sbuf_printf(&b, "# HELP pdesolid_request_duration_seconds Time from a request's first byte to its last byte sent.\n"
            "# TYPE pdesolid_request_duration_seconds histogram\n");
    unsigned long long cum = 0;
    for (int i = 0; i < NBUCKET; i++) {
        cum += atomic_load(&m->hist[i]);
        srv_sbuf_printf(&b, "pdesolid_request_duration_seconds_bucket{le=\"%g\"} %llu\n", buckets[i], cum);
    }
    cum += atomic_load(&m->hist[NBUCKET]);
    srv_sbuf_printf(&b, "pdesolid_request_duration_seconds_bucket{le=\"+Inf\"} %llu\n", cum);
    srv_sbuf_printf(&b, "pdesolid_request_duration_seconds_sum %.9g\npdesolid_request_duration_seconds_count %llu\n",
        (double)atomic_load(&m->latency_ns) * 1e-9, atomic_load(&m->latency_count));
    srv_sbuf_printf(&b, "# HELP pdesolid_solve_seconds Time spent solving models (cache misses).\n"
            "# TYPE pdesolid_solve_seconds summary\n"
            "pdesolid_solve_seconds_sum %.9g\npdesolid_solve_seconds_count %llu\n",
        m->solve_sum, m->solve_count);
    srv_sbuf_printf(&b, "# HELP pdesolid_output_seconds Time spent sampling solutions and writing outputs.\n"
            "# TYPE pdesolid_output_seconds summary\n"
            "pdesolid_output_seconds_sum %.9g\npdesolid_output_seconds_count %llu\n",
        m->output_sum, m->output_count);
    srv_sbuf_printf(&b, "# HELP pdesolid_output_bytes_total Bytes of outputs written.\n"
            "# TYPE pdesolid_output_bytes_total counter\npdesolid_output_bytes_total %llu\n", m->output_bytes);
    srv_sbuf_printf(&b, "# HELP pdesolid_heavy_total Requests whose rest ran apart from light ones (--heavy-work).\n"
            "# TYPE pdesolid_heavy_total counter\npdesolid_heavy_total %llu\n", atomic_load(&m->heavy));
    srv_sbuf_printf(&b, "# HELP pdesolid_connections Open HTTP connections.\n# TYPE pdesolid_connections gauge\n"
            "pdesolid_connections %lld\n", (long long)atomic_load(&m->connections));
    pthread_mutex_unlock(&m->lock);
    srv_sbuf_printf(&b, "# HELP pdesolid_cache_hits_total Requests whose solution was cached (or being solved).\n"
            "# TYPE pdesolid_cache_hits_total counter\npdesolid_cache_hits_total %llu\n", c->hits);
    srv_sbuf_printf(&b, "# HELP pdesolid_cache_misses_total Requests that solved their model.\n"
            "# TYPE pdesolid_cache_misses_total counter\npdesolid_cache_misses_total %llu\n", c->misses);
    srv_sbuf_printf(&b, "# HELP pdesolid_cache_evictions_total Solutions evicted to keep the cache within its bound.\n"
            "# TYPE pdesolid_cache_evictions_total counter\npdesolid_cache_evictions_total %llu\n", c->evictions);
    srv_sbuf_printf(&b, "# HELP pdesolid_cache_bytes Bytes of cached solutions.\n# TYPE pdesolid_cache_bytes gauge\n"
            "pdesolid_cache_bytes %zu\n", c->bytes);
    srv_sbuf_printf(&b, "# HELP pdesolid_cache_entries Cached solutions.\n# TYPE pdesolid_cache_entries gauge\n"
            "pdesolid_cache_entries %zu\n", c->entries);
    srv_sbuf_printf(&b, "# HELP pdesolid_response_cache_hits_total Requests answered from a kept response, without a solver thread.\n"
            "# TYPE pdesolid_response_cache_hits_total counter\npdesolid_response_cache_hits_total %llu\n", response_hits);
    srv_sbuf_printf(&b, "# HELP pdesolid_queue_depth Jobs queued or running on the solver threads.\n"
            "# TYPE pdesolid_queue_depth gauge\npdesolid_queue_depth %zu\n", queue_depth);
    srv_sbuf_printf(&b, "# HELP pdesolid_requests_in_flight Requests begun and not yet finished.\n"
            "# TYPE pdesolid_requests_in_flight gauge\npdesolid_requests_in_flight %zu\n", in_flight);
    if (b.oom) {
        free(b.s);
        return NULL;
    }
    return b.s;
}
