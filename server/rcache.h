/*
 * rcache.h: finished responses of repeated requests, answered on the polling
 * threads without a solver thread, a parse or a solve.
 *
 * A request's key is its exact bytes (route, format, res, body or id); a hit
 * compares the whole key, so no two requests share an entry by accident.
 * Entries hold reference-counted bytes, which any number of responses may
 * send at once, each with its own headers (the request id, CORS); evicting
 * an entry drops the cache's reference, and the bytes go when the last send
 * that holds them ends.
 * Thread-safe.
 */
#ifndef SRV_RCACHE_H
#define SRV_RCACHE_H

#include <stddef.h>

#include <microhttpd.h>

#define SRV_RCACHE_MAX_ITEM (1u << 20)     /* the largest response kept */
#define SRV_RCACHE_MAX_KEY (16u << 10)     /* requests with bodies larger than this are not kept */

typedef struct srv_rcache srv_rcache;
typedef struct srv_rbody srv_rbody;

typedef struct {
    srv_rbody *body;              /* pinned: srv_rcache_unpin() it, or let the response do it */
    const char *bytes;            /* the body's bytes, valid while it is pinned */
    size_t len;
    char id[40];
    char etag[96];
    const char *ctype;
} srv_rhit;

srv_rcache *srv_rcache_create(size_t max_bytes);
void srv_rcache_destroy(srv_rcache *c);

/*
 * On a hit, fills h with the kept bytes, pinned so that an eviction cannot
 * free them, and returns 1; else 0. Hand them to libmicrohttpd with
 * MHD_create_response_from_buffer_with_free_callback_cls(h.len, h.bytes,
 * srv_rcache_unpin, h.body), which unpins when the response is done.
 */
int srv_rcache_get(srv_rcache *c, const char *key, size_t klen, srv_rhit *h);
/* Drops a pin (a srv_rbody *); NULL does nothing. */
void srv_rcache_unpin(void *body);
/* Keeps a response of len bytes (copied) under key. */
void srv_rcache_put(srv_rcache *c, const char *key, size_t klen, const char *bytes, size_t len, const char *ctype,
                    const char *id, const char *etag);

/* Hits served, for /metrics. */
unsigned long long srv_rcache_hits(srv_rcache *c);

#endif
