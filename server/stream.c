/*
 * stream.c: bodies that the solver threads produce and the polling threads
 * send (internal.h).
 *
 * DESIGN
 * A stream is a ring of SRV_STREAM_RING bytes between one producer, a fill
 * job on a solver thread that reads the api_output into the ring's free
 * space, and one consumer, libmicrohttpd's content reader on a polling
 * thread, which only copies bytes out. The two touch disjoint parts of the
 * ring, so the lock guards only the counters. When the ring is half empty
 * the reader queues a fill job (at most one at a time); when it is empty
 * the reader suspends the connection and returns 0, and the fill job
 * resumes it. So no solver thread ever waits for a client, no polling
 * thread ever computes, and a request holds at most one ring of body.
 * A fill job stops at the job deadline (--job-timeout counts the solver
 * time of all of a request's jobs) and when the server aborts; the reader
 * then ends the response with an error, since its headers are gone.
 * The ring is shared by the response (freed by libmicrohttpd) and a fill
 * job in flight: a reference count frees it after both.
 */
#include <stdlib.h>
#include <string.h>

#include "internal.h"

struct srv_stream {
    srv_server *s;
    struct MHD_Connection *conn;
    api_output *out;
    srv_entry *entry;
    pthread_mutex_t lock;
    char *ring;
    size_t cap;             /* SRV_STREAM_RING, or a whole body's size + 1 */
    size_t head, len;       /* the bytes [head, head + len) mod cap are ready */
    int filling;            /* a fill job is queued or running */
    int waiting;            /* the reader suspended the connection for want of bytes */
    int done, failed, closed;
    int refs;
    double work, limit;     /* solver seconds spent on the request, and --job-timeout */
    double fill_seconds;
    long long bytes;
    srv_req *r;             /* NULL once the request has completed */
};

static void stream_unref(srv_stream *st)
{
    pthread_mutex_lock(&st->lock);
    int last = --st->refs == 0;
    pthread_mutex_unlock(&st->lock);
    if (!last)
        return;
    srv_metrics_output(st->s->metrics, st->fill_seconds, (size_t)st->bytes);
    api_output_free(st->out);
    srv_cache_release(st->s->cache, st->entry);
    pthread_mutex_destroy(&st->lock);
    free(st->ring);
    free(st);
}

/* Reads the output into the ring until it is full or ends; on a solver thread. */
static void fill(srv_stream *st)
{
    double t0 = srv_now();
    pthread_mutex_lock(&st->lock);
    while (!st->done && !st->failed && !st->closed && st->len < st->cap) {
        size_t tail = (st->head + st->len) % st->cap;
        size_t room = st->cap - st->len;
        if (room > st->cap - tail)
            room = st->cap - tail;
        pthread_mutex_unlock(&st->lock);
        /* The reader copies only [head, head + len): this part of the ring is ours. */
        long n = api_output_read(st->out, st->ring + tail, room);
        int late = atomic_load(&st->s->aborting) || st->work + (srv_now() - t0) > st->limit;
        pthread_mutex_lock(&st->lock);
        if (n < 0 || (late && n != 0))
            st->failed = 1;
        else if (n == 0)
            st->done = 1;
        else
            st->len += (size_t)n;
    }
    st->work += srv_now() - t0;
    st->fill_seconds += srv_now() - t0;
    pthread_mutex_unlock(&st->lock);
}

static void fill_job(void *arg)
{
    srv_stream *st = arg;
    fill(st);
    pthread_mutex_lock(&st->lock);
    st->filling = 0;
    int resume = st->waiting;
    st->waiting = 0;
    pthread_mutex_unlock(&st->lock);
    if (resume)
        MHD_resume_connection(st->conn);   /* it stays suspended until this: the connection is alive */
    stream_unref(st);
}

srv_stream *srv_stream_start(srv_req *r, api_output *o, srv_entry *e, int *whole)
{
    /* A body the response cache may keep is made whole here; any other streams through the ring. */
    long long size = api_output_size(o);
    size_t cap = r->key && size >= 0 && size <= (long long)SRV_RCACHE_MAX_ITEM ? (size_t)size + 1 : SRV_STREAM_RING;
    srv_stream *st = calloc(1, sizeof *st);
    if (!st || !(st->ring = malloc(cap)) || pthread_mutex_init(&st->lock, NULL)) {
        if (st)
            free(st->ring);
        free(st);
        api_output_free(o);
        srv_cache_release(r->s->cache, e);
        srv_problem(r, 500, NULL, "out of memory");
        return NULL;
    }
    st->s = r->s;
    st->cap = cap;
    st->conn = r->conn;
    st->out = o;
    st->entry = e;
    st->refs = 1;
    st->limit = r->s->cfg.job_timeout;
    st->work = r->work + (srv_now() - r->run_start);
    double t0 = srv_now();
    fill(st);
    r->tm.output += srv_now() - t0;
    if (st->failed) {
        int late = st->work > st->limit || atomic_load(&r->s->aborting);
        stream_unref(st);
        if (late)
            srv_problem(r, 503, NULL, "the request ran past its deadline of %g s of solver time (--job-timeout)",
                        r->s->cfg.job_timeout);
        else
            srv_problem(r, 500, NULL, "out of memory while writing the output");
        return NULL;
    }
    *whole = st->done;
    if (st->done) {
        /* The whole body is here: hand it over as text (the response cache may keep it). */
        char *text = malloc(st->len + 1);
        if (text) {
            memcpy(text, st->ring, st->len);
            text[st->len] = '\0';
        }
        size_t n = st->len;
        st->bytes = (long long)n;
        stream_unref(st);
        srv_set_text(r, 200, r->ctype, text);
        r->text_len = n;
        return NULL;
    }
    return st;
}

static ssize_t reader(void *cls, uint64_t pos, char *buf, size_t max)
{
    (void)pos;
    srv_stream *st = cls;
    int submit = 0;
    ssize_t n;
    pthread_mutex_lock(&st->lock);
    if (st->len) {
        n = (ssize_t)(st->len < max ? st->len : max);
        size_t first = st->cap - st->head;
        if (first > (size_t)n)
            first = (size_t)n;
        memcpy(buf, st->ring + st->head, first);
        memcpy(buf + first, st->ring, (size_t)n - first);
        st->head = (st->head + (size_t)n) % st->cap;
        st->len -= (size_t)n;
        st->bytes += n;
        if (st->r)
            st->r->sent = st->bytes;
        if (!st->filling && !st->done && !st->failed && st->len < st->cap / 2)
            submit = st->filling = 1;
    } else if (st->failed || atomic_load(&st->s->aborting)) {
        n = MHD_CONTENT_READER_END_WITH_ERROR;
    } else if (st->done) {
        n = MHD_CONTENT_READER_END_OF_STREAM;
    } else {
        /* Nothing to send: wait for the fill job, which resumes the connection. */
        n = 0;
        st->waiting = 1;
        MHD_suspend_connection(st->conn);
        if (!st->filling)
            submit = st->filling = 1;
    }
    if (submit)
        st->refs++;
    pthread_mutex_unlock(&st->lock);
    if (submit && srv_pool_push(st->s->pool, fill_job, st)) {
        /* The pool is gone (shutting down): end here. */
        pthread_mutex_lock(&st->lock);
        st->filling = 0;
        st->failed = 1;
        int resume = st->waiting;
        st->waiting = 0;
        st->refs--;
        pthread_mutex_unlock(&st->lock);
        if (resume)
            MHD_resume_connection(st->conn);
    }
    return n;
}

static void reader_free(void *cls)
{
    srv_stream *st = cls;
    pthread_mutex_lock(&st->lock);
    st->closed = 1;
    if (st->r)
        st->r->stream = NULL;
    st->r = NULL;
    pthread_mutex_unlock(&st->lock);
    stream_unref(st);
}

void srv_stream_release(srv_req *r)
{
    srv_stream *st = r->stream;
    if (!st)
        return;
    r->stream = NULL;
    pthread_mutex_lock(&st->lock);
    int sent = st->r != NULL;   /* the response owns it; else the request still does */
    st->r = NULL;
    pthread_mutex_unlock(&st->lock);
    if (!sent)
        stream_unref(st);
}

enum MHD_Result srv_stream_respond(srv_req *r)
{
    srv_stream *st = r->stream;
    long long size = api_output_size(st->out);
    struct MHD_Response *resp = MHD_create_response_from_callback(size >= 0 ? (uint64_t)size : MHD_SIZE_UNKNOWN,
                                                                  64 * 1024, reader, st, reader_free);
    if (!resp) {
        r->stream = NULL;
        stream_unref(st);
        return MHD_NO;
    }
    st->r = r;
    return srv_queue(r, resp);
}
