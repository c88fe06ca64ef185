/*
 * pool.c: a fixed set of threads over a bounded FIFO of jobs (pool.h).
 * The lock is released while a job runs.
 */
#include <pthread.h>
#include <stdlib.h>

#include "pool.h"

typedef struct {
    srv_job_fn fn;
    void *arg;
} job;

struct srv_pool {
    pthread_mutex_t lock;
    pthread_cond_t work;
    job *ring;
    size_t cap, limit, head, count, reserved, running;   /* limit: places for reserve; cap adds extra */
    job *heavy;                                          /* deferred heavy parts, a ring of cap places */
    size_t hhead, hcount, hrunning;
    size_t lanes;        /* threads that may run heavy parts at once: all but one */
    size_t passed;       /* with one thread: light jobs taken while a heavy part waited */
    int stopping, nthreads, alive;   /* alive: workers not yet past their last job */
    pthread_t *threads;
};

/* With one thread, a heavy part goes first once this many light jobs went before it. */
#define HEAVY_PASSED 8

/* A heavy part runs while fewer than threads - 1 do: one thread is kept for the rest, even while it idles, so
 * that a light job never waits for heavy work. With one thread, a heavy part runs when no light job waits, or
 * once HEAVY_PASSED have gone before it. */
static int heavy_next(const srv_pool *p)
{
    if (!p->hcount)
        return 0;
    if (p->lanes)
        return p->hrunning < p->lanes;
    return p->count == 0 || p->passed >= HEAVY_PASSED;
}

static void *worker(void *arg)
{
    srv_pool *p = arg;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        /* A heavy part waiting for a lane is not work for this thread; the lane's thread signals when it is free. */
        while (p->count == 0 && !heavy_next(p) && (!p->stopping || p->reserved || p->hcount))
            pthread_cond_wait(&p->work, &p->lock);
        if (p->count == 0 && !heavy_next(p)) {
            p->alive--;   /* stopping and drained: a push from now on is refused, not lost */
            pthread_cond_broadcast(&p->work);   /* a thread that waited for a heavy part's lane sees it drained */
            break;
        }
        const int heavy = heavy_next(p);
        job j;
        if (heavy) {
            j = p->heavy[p->hhead];
            p->hhead = (p->hhead + 1) % p->cap;
            p->hcount--;
            p->hrunning++;
            p->passed = 0;
        } else {
            p->passed += p->hcount > 0;
            j = p->ring[p->head];
            p->head = (p->head + 1) % p->cap;
            p->count--;
        }
        p->running++;
        pthread_mutex_unlock(&p->lock);
        j.fn(j.arg);
        pthread_mutex_lock(&p->lock);
        p->running--;
        p->hrunning -= heavy;
        if (heavy && p->hcount)
            pthread_cond_signal(&p->work);   /* a lane is free for a waiting heavy part */
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

srv_pool *srv_pool_create(int threads, size_t queue, size_t extra)
{
    srv_pool *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->limit = queue ? queue : 1;
    p->cap = p->limit + extra;
    p->ring = malloc(p->cap * sizeof *p->ring);
    p->heavy = malloc(p->cap * sizeof *p->heavy);
    p->threads = malloc((size_t)threads * sizeof *p->threads);
    if (!p->ring || !p->heavy || !p->threads || pthread_mutex_init(&p->lock, NULL) || pthread_cond_init(&p->work, NULL)) {
        free(p->ring);
        free(p->heavy);
        free(p->threads);
        free(p);
        return NULL;
    }
    p->alive = threads;
    p->lanes = threads > 1 ? (size_t)threads - 1 : 0;
    for (p->nthreads = 0; p->nthreads < threads; p->nthreads++)
        if (pthread_create(&p->threads[p->nthreads], NULL, worker, p)) {
            p->alive = p->nthreads;
            srv_pool_destroy(p);
            return NULL;
        }
    return p;
}

int srv_pool_reserve(srv_pool *p)
{
    pthread_mutex_lock(&p->lock);
    int ok = !p->stopping && p->count + p->reserved < p->limit;
    if (ok)
        p->reserved++;
    pthread_mutex_unlock(&p->lock);
    return ok ? 0 : -1;
}

void srv_pool_submit(srv_pool *p, srv_job_fn fn, void *arg)
{
    pthread_mutex_lock(&p->lock);
    p->reserved--;
    p->ring[(p->head + p->count) % p->cap] = (job){ fn, arg };
    p->count++;
    pthread_cond_signal(&p->work);
    pthread_mutex_unlock(&p->lock);
}

int srv_pool_push(srv_pool *p, srv_job_fn fn, void *arg)
{
    pthread_mutex_lock(&p->lock);
    int ok = p->alive > 0 && p->count + p->reserved < p->cap;
    if (ok) {
        p->ring[(p->head + p->count) % p->cap] = (job){ fn, arg };
        p->count++;
        pthread_cond_signal(&p->work);
    }
    pthread_mutex_unlock(&p->lock);
    return ok ? 0 : -1;
}

int srv_pool_defer_heavy(srv_pool *p, srv_job_fn fn, void *arg, size_t limit)
{
    pthread_mutex_lock(&p->lock);
    int ok = p->alive > 0 && p->hcount < limit && p->hcount < p->cap;
    if (ok) {
        p->heavy[(p->hhead + p->hcount) % p->cap] = (job){ fn, arg };
        p->hcount++;
        pthread_cond_signal(&p->work);
    }
    pthread_mutex_unlock(&p->lock);
    return ok ? 0 : -1;
}

size_t srv_pool_depth(srv_pool *p)
{
    pthread_mutex_lock(&p->lock);
    size_t d = p->count + p->hcount + p->running;
    pthread_mutex_unlock(&p->lock);
    return d;
}

void srv_pool_stop(srv_pool *p)
{
    pthread_mutex_lock(&p->lock);
    int joined = p->stopping == 2;
    if (!joined)
        p->stopping = 1;
    pthread_cond_broadcast(&p->work);
    pthread_mutex_unlock(&p->lock);
    if (joined)
        return;
    for (int i = 0; i < p->nthreads; i++)
        pthread_join(p->threads[i], NULL);
    pthread_mutex_lock(&p->lock);
    p->stopping = 2;
    pthread_mutex_unlock(&p->lock);
}

void srv_pool_destroy(srv_pool *p)
{
    if (!p)
        return;
    srv_pool_stop(p);
    pthread_cond_destroy(&p->work);
    pthread_mutex_destroy(&p->lock);
    free(p->ring);
    free(p->heavy);
    free(p->threads);
    free(p);
}
