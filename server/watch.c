/*
 * watch.c: one thread and a list of the open connections under a lock. The thread shuts a late
 * connection's socket down (shutdown(2), not close: the socket stays libmicrohttpd's, which reads the
 * end of it and closes the connection as if the client had). srv_watch_close takes the lock, and
 * libmicrohttpd closes the socket only after it returns, so a descriptor the thread shuts down is never
 * another connection's.
 */
#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <time.h>

#include "watch.h"

struct srv_watch {
    pthread_mutex_t lock;
    pthread_cond_t wake;
    pthread_t thread;
    srv_watched head;   /* a ring: head.next is the oldest opened */
    double limit, idle, period;
    int stop;
};

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

static void *watcher(void *arg)
{
    srv_watch *w = arg;
    pthread_mutex_lock(&w->lock);
    while (!w->stop) {
        struct timespec until;
        clock_gettime(CLOCK_MONOTONIC, &until);
        const double end = until.tv_sec + until.tv_nsec * 1e-9 + w->period;
        until.tv_sec = (time_t)end;
        until.tv_nsec = (long)((end - (double)until.tv_sec) * 1e9);
        while (!w->stop && pthread_cond_timedwait(&w->wake, &w->lock, &until) != ETIMEDOUT)
            ;
        const double t = now();
        for (srv_watched *c = w->head.next; c != &w->head; c = c->next)
            if (!c->busy && c->fd >= 0 && t - c->since > (c->answered ? w->idle : w->limit)) {
                shutdown(c->fd, SHUT_RDWR);
                c->fd = -1;   /* once */
            }
    }
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

srv_watch *srv_watch_start(double limit, double idle, double period)
{
    srv_watch *w = calloc(1, sizeof *w);
    pthread_condattr_t ca;
    if (!w || pthread_condattr_init(&ca)) {
        free(w);
        return NULL;
    }
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    int bad = pthread_mutex_init(&w->lock, NULL) || pthread_cond_init(&w->wake, &ca);
    pthread_condattr_destroy(&ca);
    w->head.next = w->head.prev = &w->head;
    w->limit = limit, w->idle = idle, w->period = period;
    if (bad || pthread_create(&w->thread, NULL, watcher, w)) {
        free(w);
        return NULL;
    }
    return w;
}

void srv_watch_stop(srv_watch *w)
{
    if (!w)
        return;
    pthread_mutex_lock(&w->lock);
    w->stop = 1;
    pthread_cond_signal(&w->wake);
    pthread_mutex_unlock(&w->lock);
    pthread_join(w->thread, NULL);
    pthread_cond_destroy(&w->wake);
    pthread_mutex_destroy(&w->lock);
    free(w);
}

void srv_watch_open(srv_watch *w, srv_watched *c, int fd)
{
    pthread_mutex_lock(&w->lock);
    c->fd = fd, c->busy = c->answered = 0, c->since = now();
    c->prev = w->head.prev, c->next = &w->head;
    w->head.prev->next = c, w->head.prev = c;
    pthread_mutex_unlock(&w->lock);
}

/* Both read c->prev under the lock: closing a neighbour writes it. */
void srv_watch_close(srv_watch *w, srv_watched *c)
{
    pthread_mutex_lock(&w->lock);
    if (c->prev) {
        c->prev->next = c->next, c->next->prev = c->prev;
        c->prev = c->next = NULL;
    }
    pthread_mutex_unlock(&w->lock);
}

void srv_watch_busy(srv_watch *w, srv_watched *c, int busy)
{
    pthread_mutex_lock(&w->lock);
    if (c->prev)
        c->busy = busy, c->answered |= !busy, c->since = now();
    pthread_mutex_unlock(&w->lock);
}
