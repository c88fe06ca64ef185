/*
 * rcache.c: the response cache (rcache.h): a chained hash and an LRU list
 * under one mutex, bounded in bytes.
 */
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stdatomic.h>

#include "rcache.h"

/* The kept bytes, shared by the cache and the responses that send them. */
struct srv_rbody {
    atomic_int refs;
    size_t len;
    char bytes[];
};

typedef struct item item;
struct item {
    char *key;
    size_t klen;
    uint64_t hash;
    srv_rbody *body;
    size_t len;
    char id[40], etag[96];
    const char *ctype;
    item *hnext, *prev, *next;
};

#define BUCKETS 1024

struct srv_rcache {
    pthread_mutex_t lock;
    size_t max_bytes, bytes;
    unsigned long long hits;
    item *bucket[BUCKETS];
    item *head, *tail;
};

static uint64_t hash_of(const char *k, size_t n)
{
    uint64_t h = 14695981039346656037ull;
    for (size_t i = 0; i < n; i++)
        h = (h ^ (unsigned char)k[i]) * 1099511628211ull;
    return h;
}

srv_rcache *srv_rcache_create(size_t max_bytes)
{
    srv_rcache *c = calloc(1, sizeof *c);
    if (c && pthread_mutex_init(&c->lock, NULL)) {
        free(c);
        c = NULL;
    }
    if (c)
        c->max_bytes = max_bytes;
    return c;
}

static void unlink_item(srv_rcache *c, item *it)
{
    item **p = &c->bucket[it->hash % BUCKETS];
    while (*p != it)
        p = &(*p)->hnext;
    *p = it->hnext;
    if (it->prev)
        it->prev->next = it->next;
    else
        c->head = it->next;
    if (it->next)
        it->next->prev = it->prev;
    else
        c->tail = it->prev;
    c->bytes -= it->len + it->klen;
    srv_rcache_unpin(it->body);
    free(it->key);
    free(it);
}

void srv_rcache_destroy(srv_rcache *c)
{
    if (!c)
        return;
    while (c->head)
        unlink_item(c, c->head);
    pthread_mutex_destroy(&c->lock);
    free(c);
}

static item *find(srv_rcache *c, const char *key, size_t klen, uint64_t h)
{
    for (item *it = c->bucket[h % BUCKETS]; it; it = it->hnext)
        if (it->hash == h && it->klen == klen && !memcmp(it->key, key, klen))
            return it;
    return NULL;
}

/* The item of key, moved to the front, with h filled; NULL if none. Under the lock. */
static item *hit(srv_rcache *c, const char *key, size_t klen, srv_rhit *h)
{
    item *it = find(c, key, klen, hash_of(key, klen));
    if (!it)
        return NULL;
    c->hits++;
    if (it != c->head) {
        it->prev->next = it->next;
        if (it->next)
            it->next->prev = it->prev;
        else
            c->tail = it->prev;
        it->prev = NULL;
        it->next = c->head;
        c->head->prev = it;
        c->head = it;
    }
    atomic_fetch_add(&it->body->refs, 1);
    h->body = it->body;
    h->bytes = it->body->bytes;
    h->len = it->len;
    memcpy(h->id, it->id, sizeof h->id);
    memcpy(h->etag, it->etag, sizeof h->etag);
    h->ctype = it->ctype;
    return it;
}

int srv_rcache_get(srv_rcache *c, const char *key, size_t klen, srv_rhit *h)
{
    pthread_mutex_lock(&c->lock);
    item *it = hit(c, key, klen, h);
    pthread_mutex_unlock(&c->lock);
    return it != NULL;
}

void srv_rcache_unpin(void *body)
{
    srv_rbody *b = body;
    if (b && atomic_fetch_sub(&b->refs, 1) == 1)
        free(b);
}

void srv_rcache_put(srv_rcache *c, const char *key, size_t klen, const char *bytes, size_t len, const char *ctype,
                    const char *id, const char *etag)
{
    if (len > SRV_RCACHE_MAX_ITEM || klen > SRV_RCACHE_MAX_KEY || len + klen > c->max_bytes)
        return;
    item *it = calloc(1, sizeof *it);
    srv_rbody *b = malloc(sizeof *b + (len ? len : 1));
    char *k = malloc(klen ? klen : 1);
    if (!it || !k || !b) {
        free(b);
        free(k);
        free(it);
        return;
    }
    atomic_init(&b->refs, 1);
    b->len = len;
    memcpy(b->bytes, bytes, len);
    memcpy(k, key, klen);
    it->key = k;
    it->klen = klen;
    it->hash = hash_of(key, klen);
    it->body = b;
    it->len = len;
    it->ctype = ctype;
    snprintf(it->id, sizeof it->id, "%s", id);
    snprintf(it->etag, sizeof it->etag, "%s", etag);
    pthread_mutex_lock(&c->lock);
    item *old = find(c, key, klen, it->hash);
    if (old)
        unlink_item(c, old);
    it->hnext = c->bucket[it->hash % BUCKETS];
    c->bucket[it->hash % BUCKETS] = it;
    it->next = c->head;
    if (c->head)
        c->head->prev = it;
    c->head = it;
    if (!c->tail)
        c->tail = it;
    c->bytes += len + klen;
    while (c->bytes > c->max_bytes && c->tail && c->tail != it)
        unlink_item(c, c->tail);
    pthread_mutex_unlock(&c->lock);
}

unsigned long long srv_rcache_hits(srv_rcache *c)
{
    pthread_mutex_lock(&c->lock);
    unsigned long long h = c->hits;
    pthread_mutex_unlock(&c->lock);
    return h;
}
