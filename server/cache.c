/*
 * cache.c: the solution cache (cache.h).
 *
 * DESIGN
 * One mutex guards a chained hash of entries and an LRU list. A miss inserts
 * a SOLVING entry at once, so that requests for the same id that arrive
 * meanwhile wait on its condition variable instead of solving again; the
 * solve itself runs outside the lock. Eviction unlinks entries from the hash
 * and the list; an unlinked entry is freed when its last reference goes.
 * A solve cancelled for its own request (its deadline, its client gone) is
 * no answer for the others waiting on it: when one of them can solve (a
 * srv_cache_get), the entry is ORPHANED and that one takes the solve over,
 * while those that cannot (srv_cache_find, a GET by id) wait on; with no
 * such waiter it fails, and is not cached.
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "cache.h"
#include "output.h"

enum { SOLVING, ORPHANED, READY, FAILED };   /* ORPHANED: cancelled, for a waiter to solve again */

struct srv_entry {
    char id[API_ID_LEN + 1];
    pde_solution *sol;
    size_t bytes;
    int state, refs, linked;
    int solvers;                   /* waiters that can solve (srv_cache_get): one takes over an ORPHANED solve */
    api_error err;                 /* FAILED: why */
    pthread_cond_t done;           /* SOLVING -> READY, FAILED or ORPHANED; ORPHANED -> SOLVING */
    srv_entry *hnext, *prev, *next;
    pthread_mutex_t props_lock;   /* one computes the properties; the others wait for them */
    pde_props props;
    int props_ok;                 /* 1: props; -1: they failed (props_err), which every later call answers */
    api_error props_err;
    _Atomic unsigned long long shown[8];   /* representations opened once (srv_entry_shown), a ring */
    atomic_uint shown_next;
};

#define BUCKETS 4096

struct srv_cache {
    pthread_mutex_t lock;
    size_t max_bytes, bytes, entries;
    unsigned long long hits, misses, evictions;
    srv_entry *bucket[BUCKETS];
    srv_entry *head, *tail;        /* most recently used first */
};

/* FNV-1a: ids' buckets, and representations' names (srv_entry_shown) */
static unsigned long long fnv1a(const char *s)
{
    unsigned long long h = 14695981039346656037ull;
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 1099511628211ull;
    return h;
}

static size_t bucket_of(const char *id)
{
    return (size_t)(fnv1a(id) % BUCKETS);
}

srv_cache *srv_cache_create(size_t max_bytes)
{
    srv_cache *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    if (pthread_mutex_init(&c->lock, NULL)) {
        free(c);
        return NULL;
    }
    c->max_bytes = max_bytes;
    return c;
}

static void entry_free(srv_entry *e)
{
    pde_solution_free(e->sol);
    pthread_cond_destroy(&e->done);
    pthread_mutex_destroy(&e->props_lock);
    free(e);
}

static void lru_unlink(srv_cache *c, srv_entry *e)
{
    if (e->prev)
        e->prev->next = e->next;
    else
        c->head = e->next;
    if (e->next)
        e->next->prev = e->prev;
    else
        c->tail = e->prev;
    e->prev = e->next = NULL;
}

static void lru_front(srv_cache *c, srv_entry *e)
{
    e->prev = NULL;
    e->next = c->head;
    if (c->head)
        c->head->prev = e;
    c->head = e;
    if (!c->tail)
        c->tail = e;
}

/* Takes e out of the hash and the list; frees it if no one holds it. */
static void unlink_entry(srv_cache *c, srv_entry *e)
{
    srv_entry **p = &c->bucket[bucket_of(e->id)];
    while (*p && *p != e)
        p = &(*p)->hnext;
    if (*p)
        *p = e->hnext;
    if (e->state == READY) {
        lru_unlink(c, e);
        c->bytes -= e->bytes;
    }
    c->entries--;
    e->linked = 0;
    if (e->refs == 0)
        entry_free(e);
}

void srv_cache_destroy(srv_cache *c)
{
    if (!c)
        return;
    for (size_t b = 0; b < BUCKETS; b++)
        while (c->bucket[b])
            unlink_entry(c, c->bucket[b]);    /* every request has ended: no references are left */
    pthread_mutex_destroy(&c->lock);
    free(c);
}

static srv_entry *lookup(srv_cache *c, const char *id)
{
    for (srv_entry *e = c->bucket[bucket_of(id)]; e; e = e->hnext)
        if (strcmp(e->id, id) == 0)
            return e;
    return NULL;
}

/* Waits while e is being solved, referencing it. READY: e; FAILED: NULL with err, the reference dropped.
 * ORPHANED, which only a waiter that can solve (can_solve) returns at: e, for the caller to solve. */
static srv_entry *await(srv_cache *c, srv_entry *e, int can_solve, api_error *err)
{
    e->refs++;
    e->solvers += can_solve;
    while (e->state == SOLVING || (e->state == ORPHANED && !can_solve))
        pthread_cond_wait(&e->done, &c->lock);
    e->solvers -= can_solve;
    if (e->state == READY && e->linked) {
        lru_unlink(c, e);
        lru_front(c, e);
    }
    if (e->state != FAILED)
        return e;
    if (err)
        *err = e->err;
    if (--e->refs == 0 && !e->linked)
        entry_free(e);
    return NULL;
}

/* A new entry of id, SOLVING and referenced once, in the hash; NULL if out of memory. */
static srv_entry *entry_new(srv_cache *c, const char *id)
{
    srv_entry *e = calloc(1, sizeof *e);
    if (!e || pthread_cond_init(&e->done, NULL)) {
        free(e);
        return NULL;
    }
    if (pthread_mutex_init(&e->props_lock, NULL)) {
        pthread_cond_destroy(&e->done);
        free(e);
        return NULL;
    }
    memcpy(e->id, id, sizeof e->id);
    e->id[API_ID_LEN] = '\0';
    e->state = SOLVING;
    e->refs = 1;
    e->linked = 1;
    size_t b = bucket_of(e->id);
    e->hnext = c->bucket[b];
    c->bucket[b] = e;
    c->entries++;
    return e;
}

srv_entry *srv_cache_get(srv_cache *c, const char *id, srv_solve_fn solve, void *arg, int *hit, api_error *err)
{
    pthread_mutex_lock(&c->lock);
    srv_entry *e = lookup(c, id);
    *hit = e != NULL;
    if (e) {
        c->hits++;
        e = await(c, e, 1, err);
        if (!e || e->state == READY) {
            pthread_mutex_unlock(&c->lock);
            return e;
        }
        /* Its solve was stopped for its own request: this one solves, under its own cancel. */
        c->hits--;
        *hit = 0;
        e->state = SOLVING;
    } else if (!(e = entry_new(c, id))) {
        pthread_mutex_unlock(&c->lock);
        api_fail_nomem(err);
        return NULL;
    }
    c->misses++;
    pthread_mutex_unlock(&c->lock);

    pde_solution *sol = NULL;
    int rc = solve(arg, &sol, &e->err);

    pthread_mutex_lock(&c->lock);
    if (rc) {
        if (err)
            *err = e->err;
        e->refs--;
        if (e->err.status == API_ERR_CANCELLED && e->solvers) {
            e->state = ORPHANED;    /* a waiter that can solve takes it over (await) */
            pthread_cond_broadcast(&e->done);
        } else {
            e->state = FAILED;
            pthread_cond_broadcast(&e->done);
            unlink_entry(c, e);     /* failures are not cached: the next request tries again */
        }
        pthread_mutex_unlock(&c->lock);
        return NULL;
    }
    e->sol = sol;
    e->bytes = pde_solution_bytes(sol) + sizeof *e;
    e->state = READY;
    c->bytes += e->bytes;
    lru_front(c, e);
    pthread_cond_broadcast(&e->done);
    while (c->bytes > c->max_bytes && c->tail) {
        c->evictions++;
        unlink_entry(c, c->tail);   /* may be e itself, when it alone exceeds the bound: it lives on its reference */
    }
    pthread_mutex_unlock(&c->lock);
    return e;
}

srv_entry *srv_cache_find(srv_cache *c, const char *id, api_error *err)
{
    pthread_mutex_lock(&c->lock);
    srv_entry *e = lookup(c, id);
    if (e) {
        c->hits++;
        e = await(c, e, 0, err);
    } else {
        api_fail(err, API_ERR_NOT_FOUND, "", "no solid %s in the cache", id);
    }
    pthread_mutex_unlock(&c->lock);
    return e;
}

void srv_cache_release(srv_cache *c, srv_entry *e)
{
    if (!e)
        return;
    pthread_mutex_lock(&c->lock);
    if (--e->refs == 0 && !e->linked)
        entry_free(e);
    pthread_mutex_unlock(&c->lock);
}

const pde_solution *srv_entry_solution(const srv_entry *e)
{
    return e->sol;
}

const char *srv_entry_id(const srv_entry *e)
{
    return e->id;
}

const pde_props *srv_entry_props(srv_entry *e, const pde_cancel *cancel, api_error *err)
{
    pthread_mutex_lock(&e->props_lock);
    if (!e->props_ok) {
        pde_status st = api_properties(e->sol, cancel, &e->props, &e->props_err);
        /* A cancelled computation leaves them for the next request; any other failure is the solid's. */
        e->props_ok = st == PDE_OK ? 1 : st == PDE_ERR_CANCELLED ? 0 : -1;
        if (st == PDE_ERR_CANCELLED)
            *err = e->props_err;
    }
    if (e->props_ok < 0)
        *err = e->props_err;
    const pde_props *p = e->props_ok > 0 ? &e->props : NULL;
    pthread_mutex_unlock(&e->props_lock);
    return p;
}

int srv_entry_shown(srv_entry *e, const char *rep, int mark)
{
    const unsigned long long h = fnv1a(rep) | 1;   /* never 0, an empty slot */
    for (size_t i = 0; i < sizeof e->shown / sizeof *e->shown; i++)
        if (atomic_load_explicit(&e->shown[i], memory_order_relaxed) == h)
            return 1;
    if (mark)
        atomic_store_explicit(&e->shown[atomic_fetch_add(&e->shown_next, 1) % (sizeof e->shown / sizeof *e->shown)], h,
                              memory_order_relaxed);
    return 0;
}

/* Whether the properties are there already, or failed for good (then they cost nothing). */
int srv_entry_has_props(srv_entry *e)
{
    pthread_mutex_lock(&e->props_lock);
    int ok = e->props_ok != 0;
    pthread_mutex_unlock(&e->props_lock);
    return ok;
}

void srv_cache_stats_get(srv_cache *c, srv_cache_stats *out)
{
    pthread_mutex_lock(&c->lock);
    out->hits = c->hits;
    out->misses = c->misses;
    out->evictions = c->evictions;
    out->bytes = c->bytes;
    out->entries = c->entries;
    pthread_mutex_unlock(&c->lock);
}
