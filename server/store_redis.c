/*
 * store_redis.c: the Redis store (store.h), for daemons on several machines.
 * An id is a hash PREFIXid with fields "model" and "request"; with a TTL,
 * each put and get sets the key to expire TTL seconds later.
 *
 * One connection, guarded by a mutex: a call takes well under a millisecond,
 * and the solver threads spend their time solving. Every command has the
 * command timeout. After a failure the connection is dropped and calls
 * answer SRV_STORE_DOWN at once until a second has passed; the next call
 * after that connects again (with the connect timeout), so the daemon
 * reconnects by itself and never stalls more than about one timeout.
 */
#include <hiredis/hiredis.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "id.h"
#include "store_impl.h"

typedef struct {
    pthread_mutex_t lock;
    redisContext *c;          /* NULL when down */
    char host[256];
    int port, db;
    char prefix[128];
    unsigned ttl;
    struct timeval connect_tv, command_tv;
    double retry_at;          /* no connect before this (monotonic seconds) */
    double last_ok;           /* the last command that succeeded */
    atomic_int up;
    atomic_ullong bytes, entries;
} redis_store;

static double mono(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static struct timeval ms_tv(unsigned ms)
{
    return (struct timeval){ ms / 1000, (ms % 1000) * 1000 };
}

/* Drops the connection after a failure: calls answer DOWN for a second. Lock held. */
static void down(redis_store *R)
{
    if (R->c)
        redisFree(R->c);
    R->c = NULL;
    R->retry_at = mono() + 1;
    atomic_store(&R->up, 0);
}

/* The connection, connecting if it is time to; NULL when down. Lock held. */
static redisContext *conn(redis_store *R)
{
    if (R->c)
        return R->c;
    if (mono() < R->retry_at)
        return NULL;
    R->c = redisConnectWithTimeout(R->host, R->port, R->connect_tv);
    if (!R->c || R->c->err || redisSetTimeout(R->c, R->command_tv) != REDIS_OK) {
        down(R);
        return NULL;
    }
    if (R->db) {
        redisReply *r = redisCommand(R->c, "SELECT %d", R->db);
        int ok = r && r->type == REDIS_REPLY_STATUS;
        if (r)
            freeReplyObject(r);
        if (!ok) {
            down(R);
            return NULL;
        }
    }
    atomic_store(&R->up, 1);
    return R->c;
}

/* redis://HOST:PORT[/DB] into R's host, port and db; -1 if url is not one. */
static int redis_parse(const char *url, redis_store *R)
{
    const char *h = url + strlen("redis://"), *colon = strrchr(h, ':');
    char *end = NULL;
    long port = colon ? strtol(colon + 1, &end, 10) : 0;
    long db = 0;
    if (end && *end == '/')
        db = strtol(end + 1, &end, 10);
    if (!colon || colon == h || (size_t)(colon - h) >= sizeof R->host || port < 1 || port > 65535 || !end || *end ||
        db < 0 || db > 1000)
        return -1;
    memcpy(R->host, h, (size_t)(colon - h));
    R->host[colon - h] = '\0';
    R->port = (int)port;
    R->db = (int)db;
    return 0;
}

static int redis_check(const char *url)
{
    redis_store R;
    return redis_parse(url, &R);
}

static void *redis_open(const char *url, const srv_store_config *cfg, char *why, size_t whylen)
{
    redis_store *R = calloc(1, sizeof *R);
    if (!R) {
        snprintf(why, whylen, "out of memory");
        return NULL;
    }
    if (redis_parse(url, R)) {
        snprintf(why, whylen, "--store %s: give redis://HOST:PORT or redis://HOST:PORT/DB", url);
        free(R);
        return NULL;
    }
    snprintf(R->prefix, sizeof R->prefix, "%s", cfg->prefix ? cfg->prefix : "pdesolid:");
    R->ttl = cfg->ttl_s;
    R->connect_tv = ms_tv(cfg->connect_timeout_ms ? cfg->connect_timeout_ms : 200);
    R->command_tv = ms_tv(cfg->command_timeout_ms ? cfg->command_timeout_ms : 500);
    pthread_mutex_init(&R->lock, NULL);
    pthread_mutex_lock(&R->lock);
    conn(R);   /* down now is no error: the daemon serves, and connects later */
    pthread_mutex_unlock(&R->lock);
    return R;
}

/* Runs a command; NULL (and the connection dropped) on an I/O error or an error reply. A connection
 * that was open before this call (it may have outlived a restart of Redis) gets one fresh try. Lock held. */
static redisReply *command(redis_store *R, int argc, const char **argv, const size_t *lens)
{
    for (int fresh = R->c == NULL; ; fresh = 1) {
        redisContext *c = conn(R);
        if (!c)
            return NULL;
        redisReply *r = redisCommandArgv(c, argc, argv, lens);
        if (r && r->type != REDIS_REPLY_ERROR) {
            R->last_ok = mono();
            return r;
        }
        int io = !r;
        if (r)
            freeReplyObject(r);
        down(R);
        if (fresh || !io)
            return NULL;
        R->retry_at = 0;
    }
}

static char *dup_n(const char *p, size_t n)
{
    char *s = malloc(n + 1);
    if (s) {
        memcpy(s, p, n);
        s[n] = '\0';
    }
    return s;
}

static srv_store_status redis_get(void *b, const char *id, char **model, char **request)
{
    redis_store *R = b;
    char key[256];
    snprintf(key, sizeof key, "%s%s", R->prefix, id);
    const char *argv[] = { "HMGET", key, "model", "request" };
    size_t lens[] = { 5, strlen(key), 5, 7 };
    srv_store_status st = SRV_STORE_DOWN;
    pthread_mutex_lock(&R->lock);
    redisReply *r = command(R, 4, argv, lens);
    if (r) {
        st = SRV_STORE_ERROR;
        if (r->type == REDIS_REPLY_ARRAY && r->elements == 2) {
            redisReply *m = r->element[0], *q = r->element[1];
            if (m->type != REDIS_REPLY_STRING) {
                st = SRV_STORE_MISSING;
            } else {
                *model = dup_n(m->str, m->len);
                *request = q->type == REDIS_REPLY_STRING && q->len ? dup_n(q->str, q->len) : NULL;
                st = *model ? SRV_STORE_OK : SRV_STORE_NOMEM;
            }
        }
        freeReplyObject(r);
    }
    if (st == SRV_STORE_OK && R->ttl) {
        char ttl[16];
        snprintf(ttl, sizeof ttl, "%u", R->ttl);
        const char *ev[] = { "EXPIRE", key, ttl };
        size_t el[] = { 6, strlen(key), strlen(ttl) };
        if ((r = command(R, 3, ev, el)))
            freeReplyObject(r);
    }
    pthread_mutex_unlock(&R->lock);
    return st;
}

static srv_store_status redis_put(void *b, const char *id, const char *model, const char *request)
{
    redis_store *R = b;
    char key[256], ttl[16];
    snprintf(key, sizeof key, "%s%s", R->prefix, id);
    snprintf(ttl, sizeof ttl, "%u", R->ttl);
    const char *argv[] = { "HSET", key, "model", model, "request", request ? request : "" };
    size_t lens[] = { 4, strlen(key), 5, strlen(model), 7, request ? strlen(request) : 0 };
    const char *ev[] = { "EXPIRE", key, ttl };
    size_t el[] = { 6, strlen(key), strlen(ttl) };
    pthread_mutex_lock(&R->lock);
    redisReply *r = command(R, 6, argv, lens);
    if (r) {
        freeReplyObject(r);
        if (R->ttl && (r = command(R, 3, ev, el)))
            freeReplyObject(r);
    }
    srv_store_status st = R->c ? SRV_STORE_OK : SRV_STORE_DOWN;
    pthread_mutex_unlock(&R->lock);
    return st;
}

/* bytes: Redis's used_memory; entries: the keys of the database (DBSIZE). Not waiting for the lock:
 * when another thread holds it, the last numbers. */
static void redis_stats(void *b, srv_store_stats *out)
{
    redis_store *R = b;
    if (!pthread_mutex_trylock(&R->lock)) {
        redisContext *c = R->c;   /* no connecting from here */
        redisReply *r = c ? redisCommand(c, "DBSIZE") : NULL;
        if (r && r->type == REDIS_REPLY_INTEGER)
            atomic_store(&R->entries, (unsigned long long)r->integer);
        if (r)
            freeReplyObject(r);
        else if (c)
            down(R);
        r = R->c ? redisCommand(R->c, "INFO memory") : NULL;
        const char *u = r && r->type == REDIS_REPLY_STRING ? strstr(r->str, "used_memory:") : NULL;
        if (u)
            atomic_store(&R->bytes, strtoull(u + strlen("used_memory:"), NULL, 10));
        if (r)
            freeReplyObject(r);
        else if (R->c)
            down(R);
        pthread_mutex_unlock(&R->lock);
    }
    out->bytes = atomic_load(&R->bytes);
    out->entries = atomic_load(&R->entries);
    out->up = atomic_load(&R->up);
}

/* Connected now: when the last success is over a second old, a PING (or a connect, when down and it is
 * time to retry) by a caller that finds the lock free; one that does not, answers from the last call. */
static int redis_ready(void *b)
{
    redis_store *R = b;
    if (!pthread_mutex_trylock(&R->lock)) {
        if (!R->c || mono() - R->last_ok > 1) {
            const char *argv[] = { "PING" };
            size_t lens[] = { 4 };
            redisReply *r = command(R, 1, argv, lens);
            if (r)
                freeReplyObject(r);
        }
        pthread_mutex_unlock(&R->lock);
    }
    return atomic_load(&R->up);
}

static void redis_close(void *b)
{
    redis_store *R = b;
    if (R->c)
        redisFree(R->c);
    pthread_mutex_destroy(&R->lock);
    free(R);
}

const srv_store_backend srv_store_redis = { "redis://", 1, redis_check, redis_open, redis_get, redis_put, redis_stats, redis_ready,
                                            redis_close, NULL };
