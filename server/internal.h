/*
 * internal.h: the server's state and a request's state, shared by the HTTP
 * edge (http.c), the routes and jobs (routes.c), replies (reply.c), static
 * files (static.c) and streamed bodies (stream.c). Not a public interface.
 *
 * Threads: the polling threads (libmicrohttpd's, --http-threads) run the
 * access handler, the content readers and the completion callback; the
 * solver threads (--threads) run jobs. A request belongs to one side at a
 * time: the handler suspends its connection before a job is queued, and the
 * job's last act is to resume it.
 */
#ifndef SRV_INTERNAL_H
#define SRV_INTERNAL_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include <microhttpd.h>

#include "cache.h"
#include "config.h"
#include "cost.h"
#include "http.h"
#include "id.h"
#include "log.h"
#include "metrics.h"
#include "output.h"
#include "pool.h"
#include "rcache.h"
#include "store.h"
#include "route.h"
#include "watch.h"

typedef struct srv_static srv_static;
typedef struct srv_stream srv_stream;

struct srv_server {
    srv_config cfg;
    struct MHD_Daemon *d;
    srv_pool *pool;
    srv_cache *cache;
    srv_metrics *metrics;
    srv_rcache *rcache;
    srv_store *store;            /* durable ids (--store), or NULL for none */
    srv_static *web;
    srv_log *log;                /* the access log, or NULL (--quiet) */
    srv_watch *watch;            /* closes connections whose request head is late (--request-timeout) */
    pthread_mutex_t json_lock;   /* cJSON_Parse writes a global */
    pthread_mutex_t lock;        /* with idle: srv_stop waits for in_flight to reach 0 */
    pthread_cond_t idle;
    atomic_size_t in_flight;     /* requests begun and not completed */
    atomic_uint conns;           /* connections open (--max-conns, and SRV_CONN_SPARE more to refuse on) */
    atomic_int stopping;         /* no new work: quiescing */
    atomic_int aborting;         /* grace is over: jobs end at once, queued ones answer 503 */
    uint16_t port;
};

enum srv_phase { SRV_BODY, SRV_QUEUED, SRV_DONE };

typedef struct srv_req {
    srv_server *s;
    struct MHD_Connection *conn;
    int route;                   /* index of srv_routes, or srv_nroutes when none matched */
    enum srv_phase phase;
    double t0;                   /* the first call of the handler */
    char method[8];
    char version[12];            /* HTTP/1.1 */
    char arg[96];                /* the path's {} segment */
    char rid[65];                /* the request id */
    char *body;
    size_t len, cap;
    int decided;                 /* the answer was set before the body was read: the body is discarded */
    int close;                   /* answer with Connection: close (the body was not read whole) */
    size_t drained;              /* bytes of body discarded */
    /* The result. */
    int status;
    const char *ctype;
    char *text;                  /* a whole body, or NULL */
    size_t text_len;
    const char *ref;             /* or a body that outlives the request (static files) */
    size_t ref_len;
    srv_stream *stream;          /* or a body that the solver threads produce */
    char id[API_ID_LEN + 1];
    char etag[96];
    char allow[64];              /* for 405 */
    const char *host;            /* what stands for Host: the header, or an absolute-form target's authority */
    char target_host[128];       /* that authority (http://HOST/path), where the target had one */
    int retry_after;
    long long sent;
    char *key;                   /* the response cache's key of this request, or NULL */
    size_t klen;
    /* Cost, timing and cancellation. */
    api_cost cost;               /* the estimate so far (--max-work, --max-mem-mb) */
    pde_cancel cancel;           /* polls srv_job_stop(r) */
    int fd;                      /* the connection's socket, which the jobs watch for the client's close */
    int gone;                    /* the client closed its connection while its job waited or ran: 499, no answer */
    double checked;              /* when a job last looked at fd (srv_now) */
    double queued_at, run_start;
    double work;                 /* seconds the solver threads spent on it before this run */
    double cpu, cpu_start;       /* the CPU seconds of those runs, and the thread's CPU clock at this run's start */
    srv_entry *heavy;            /* the solid whose output waits apart (--heavy-work), or NULL */
    void (*later)(struct srv_req *r);   /* the heavy remainder, run apart (--heavy-work), or NULL */
    int apart;                   /* running that remainder now: it runs to the end, not deferred again */
    double *pts;                 /* an eval's points (3 a point), kept for its remainder */
    size_t npts;
    int derivs;
    struct {
        double queue, parse, solve, props, output;
        int cached;
    } tm;
    /* Not zeroed by begin(): NUL-terminated when filled; q set by srv_query_init in admit(). */
    srv_query q;
    char path[512];              /* decoded, as libmicrohttpd gives it (escaped only in the log) */
    char query[512];             /* key=value&..., decoded, for the log */
} srv_req;

double srv_now(void);

/* reply.c: problems, headers, CORS. */
void srv_problem(srv_req *r, int status, const char *pointer, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
void srv_problem_api(srv_req *r, const api_error *e);
/* An api_status as HTTP: NOMEM 500, LIMIT 413, DOCUMENT 422, NOT_JSON 400, CANCELLED 503, NOT_FOUND 404. */
int srv_http_status(api_status s);
/* Takes text (malloc'd; NULL means out of memory, which becomes a 500). */
void srv_set_text(srv_req *r, int status, const char *ctype, char *text);
/* 1 if the request's Origin may call: no Origin, the same origin, or --cors-origin lists it. */
int srv_origin_allowed(srv_req *r);
/* Queues resp with r's status and headers, then destroys the handle. */
enum MHD_Result srv_queue(srv_req *r, struct MHD_Response *resp);
/* Queues r's text, or its ref, or an empty body. */
enum MHD_Result srv_respond_text(srv_req *r);

/* static.c: the front-end's files and the OpenAPI document, from a fixed table. */
srv_static *srv_static_load(const char *web_dir, char *err, size_t errlen);
/* The index of a static file's URL, or -1. */
int srv_static_find(const char *path);
void srv_static_free(srv_static *w);
/* The handler of the static row: r->ref points at the file's bytes. */
void srv_static_get(srv_req *r);

/* stream.c: a body produced by the solver threads into a bounded ring (takes o and e). */
#define SRV_STREAM_RING (256u << 10)
/* Fills the first ring on this (solver) thread; a body of known size that the response cache may
 * keep (r->key, at most SRV_RCACHE_MAX_ITEM) is made whole. Returns the stream, or NULL with r's
 * problem set, or NULL with *whole set: the output ended, its bytes are in r->text. */
srv_stream *srv_stream_start(srv_req *r, api_output *o, srv_entry *e, int *whole);
enum MHD_Result srv_stream_respond(srv_req *r);
/* When the request completes: drops its hold on its stream, if any. */
void srv_stream_release(srv_req *r);

/* routes.c: the jobs' entry, and the cancellation test every long loop polls: the deadline (--job-timeout),
 * shutdown, and the client's close (r->gone; at most every 10 ms of a job, a recv(2) that peeks). */
void srv_run_job(void *arg);
int srv_job_stop(void *arg);

#endif
