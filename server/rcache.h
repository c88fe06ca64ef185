/*
 * rcache.h: finished responses of repeated requests, answered on the polling
 * thread without a solver thread, a parse or a solve.
 *
 * A request's key is its exact bytes (route, format, res, body or id); a hit
 * compares the whole key, so no two requests share an entry by accident.
 * Entries hold a libmicrohttpd response, which is reference-counted and may be
 * queued on any number of connections; evicting an entry drops the cache's
 * reference, and the bytes go when the last send that holds them ends.
 * Thread-safe.
 */
#ifndef SRV_RCACHE_H
#define SRV_RCACHE_H

#include <stddef.h>

#include <microhttpd.h>

#define SRV_RCACHE_MAX_ITEM (1u << 20)     /* the largest response kept */
#define SRV_RCACHE_MAX_KEY (16u << 10)     /* requests with bodies larger than this are not kept */

typedef struct srv_rcache srv_rcache;

typedef struct {
    char *copy;                   /* the bytes, malloc'd (srv_rcache_copy only) */
    size_t len;
    char id[40];
    char etag[96];
    const char *ctype;
} srv_rhit;

srv_rcache *srv_rcache_create(size_t max_bytes);
void srv_rcache_destroy(srv_rcache *c);

/*
 * On a hit, queues the kept response (status 200) on conn, fills h and
 * returns 1; else 0. The response is queued under the cache's lock, which
 * takes libmicrohttpd's reference before an eviction could drop the last.
 * Call from the access handler only.
 */
int srv_rcache_queue(srv_rcache *c, const char *key, size_t klen, struct MHD_Connection *conn, srv_rhit *h);
/* On a hit, fills h with a copy of the bytes (free h->copy) and returns 1; else 0. */
int srv_rcache_copy(srv_rcache *c, const char *key, size_t klen, srv_rhit *h);
/* Keeps a response of len bytes (copied) under key. */
void srv_rcache_put(srv_rcache *c, const char *key, size_t klen, const char *bytes, size_t len, const char *ctype,
                    const char *id, const char *etag);

/* Hits served, for /metrics. */
unsigned long long srv_rcache_hits(srv_rcache *c);

#endif
