/*
 * store_impl.h: what a store backend (store_lmdb.c, store_redis.c) gives
 * store.c: one srv_store_backend, a row of store.c's table. store.c counts
 * puts, gets, misses and errors; a backend fills bytes, entries, evictions
 * and up.
 */
#ifndef SRV_STORE_IMPL_H
#define SRV_STORE_IMPL_H

#include "store.h"

typedef struct {
    const char *scheme;   /* "lmdb:", "redis://": the spec's start that selects the backend */
    int keep_scheme;      /* 1: open() gets the whole spec; 0: the spec after the scheme */
    int (*check)(const char *where);   /* 0 if where is a valid spec (its syntax alone: at start-up), else -1 */
    void *(*open)(const char *where, const srv_store_config *cfg, char *why, size_t whylen);
    srv_store_status (*get)(void *b, const char *id, char **model, char **request);
    srv_store_status (*put)(void *b, const char *id, const char *model, const char *request);
    void (*stats)(void *b, srv_store_stats *out);
    int (*ready)(void *b);
    void (*close)(void *b);
    void (*tick)(void *b);   /* NULL, or work the backend defers: called by store.c's thread about once a second */
} srv_store_backend;

extern const srv_store_backend srv_store_lmdb, srv_store_redis;

#endif
