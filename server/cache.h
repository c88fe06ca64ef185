/*
 * cache.h: solved solutions keyed by their model's id, shared by all
 * threads: LRU, bounded in bytes. Solutions are immutable; entries are
 * reference-counted, so an evicted entry stays alive while a request still
 * samples it. Concurrent requests for one id solve it once: the first solves,
 * the others wait for it.
 */
#ifndef SRV_CACHE_H
#define SRV_CACHE_H

#include <stddef.h>

#include "id.h"
#include "model.h"
#include "pde.h"

typedef struct srv_cache srv_cache;
typedef struct srv_entry srv_entry;

/* Solves the model behind an id: 0 and *out, or non-zero with err. */
typedef int (*srv_solve_fn)(void *arg, pde_solution **out, api_error *err);

typedef struct {
    unsigned long long hits, misses, evictions;
    size_t bytes, entries;
} srv_cache_stats;

srv_cache *srv_cache_create(size_t max_bytes);
void srv_cache_destroy(srv_cache *c);

/*
 * The entry of id, solving it with solve(arg) if no one has. Returns a
 * reference (release it), or NULL with err when the solve failed. *hit tells
 * whether the solution was there (or being solved by another request).
 * When the solve it waited for is cancelled (API_ERR_CANCELLED: that request's
 * deadline, or its client gone), it takes the solve over rather than fail.
 */
srv_entry *srv_cache_get(srv_cache *c, const char *id, srv_solve_fn solve, void *arg, int *hit, api_error *err);
/*
 * The entry of id if it is cached, waiting for a solve under way (a hit), and
 * for the one that takes it over if that is cancelled. NULL with err: not
 * cached (API_ERR_NOT_FOUND); the solve failed; or it was cancelled for its
 * own request and no request that can solve waited (API_ERR_CANCELLED).
 */
srv_entry *srv_cache_find(srv_cache *c, const char *id, api_error *err);
void srv_cache_release(srv_cache *c, srv_entry *e);

const pde_solution *srv_entry_solution(const srv_entry *e);
const char *srv_entry_id(const srv_entry *e);
/*
 * The properties, computed on first use, once: concurrent callers wait for
 * the first. NULL with *err when they failed: cancelled (API_ERR_CANCELLED;
 * the next call computes them again), or a failure of the solid's own (too
 * large for a double), which is kept: every later call gets it at once.
 */
const pde_props *srv_entry_props(srv_entry *e, const pde_cancel *cancel, api_error *err);
/* 1 if the properties are computed already, or failed for good: they cost nothing now. */
int srv_entry_has_props(srv_entry *e);
/* 1 if the representation rep (its ETag) of the entry was opened before: the last 8 are kept, by a 64-bit
 * hash. With mark, a rep not seen is recorded. So a revalidation (If-None-Match) of an output known to open
 * answers 304 without building it again. */
int srv_entry_shown(srv_entry *e, const char *rep, int mark);

void srv_cache_stats_get(srv_cache *c, srv_cache_stats *out);

#endif
