/*
 * pool.h: the solver threads. A bounded queue (a mutex and a condition
 * variable, as Redis's bio.c) feeds N threads. A job's slot is reserved
 * before the job exists, so that the HTTP layer can answer 503 while it still
 * can, and only then suspend the connection and hand the job over.
 *
 * Heavy parts wait apart: a job that finds its remaining work heavy (its
 * estimate, known only once it has parsed its request) defers it
 * (srv_pool_defer_heavy), and at most threads - 1 threads run deferred parts
 * at once: the last is kept for the rest, even while it idles, so a light
 * request never waits for heavy work (with 2 threads, heavy parts run one at
 * a time). With one thread, a heavy part runs when no light job waits, or
 * once 8 light jobs have gone before it.
 */
#ifndef SRV_POOL_H
#define SRV_POOL_H

#include <stddef.h>

typedef struct srv_pool srv_pool;
typedef void (*srv_job_fn)(void *arg);

/*
 * queue: jobs that may wait (srv_pool_reserve); extra: places kept for
 * continuations (srv_pool_push), at most one per connection. NULL if out of
 * memory or a thread cannot start.
 */
srv_pool *srv_pool_create(int threads, size_t queue, size_t extra);
/* Takes a place in the queue; 0, or -1 when the queue is full or the pool is stopping. */
int srv_pool_reserve(srv_pool *p);
/* Queues a job in a reserved place. Cannot fail. */
void srv_pool_submit(srv_pool *p, srv_job_fn fn, void *arg);
/* Queues a continuation of work already admitted (the next piece of a stream), outside the
 * reserved places; 0, or -1 when all extra places are taken. */
int srv_pool_push(srv_pool *p, srv_job_fn fn, void *arg);
/* Queues fn(arg), the heavy remainder of a job that has ended, apart from the queue (above); at most
 * limit wait. 0, or -1 when limit wait already or every thread is past its last job (a job that defers
 * runs on a thread, so while stopping its part is still taken, and sees the server stopping). Call it as
 * the job's last act: fn may run at once on another thread. */
int srv_pool_defer_heavy(srv_pool *p, srv_job_fn fn, void *arg, size_t limit);
/* Jobs waiting or running now. */
size_t srv_pool_depth(srv_pool *p);
/* Refuses new jobs, runs every queued and reserved one to the end (a job sees the server
 * stopping and ends at once) and stops the threads. The pool stays valid: reserve and push
 * answer -1 from now on. */
void srv_pool_stop(srv_pool *p);
/* srv_pool_stop(), then frees the pool. NULL does nothing. */
void srv_pool_destroy(srv_pool *p);

#endif
