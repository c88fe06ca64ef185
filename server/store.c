/*
 * store.c: the store interface (store.h) over its backends, one row each.
 *
 * DESIGN. A put that meets SRV_STORE_DOWN (the backend is unreachable) is
 * kept in a FIFO in memory, within pending_kb (the id, model and request
 * bytes), the oldest dropped first when a new one would go over. The store's
 * thread (one per store, bio.c's shape: a mutex and a condition variable)
 * wakes every second, or at once when a call succeeds, and writes the kept
 * puts oldest first, stopping at the first that meets DOWN again. The put
 * being written stays findable (the flying entry), so a get never misses an
 * id this process answered. The same thread calls the backend's tick (LMDB:
 * its batched LRU stamps).
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "id.h"
#include "sbuf.h"
#include "store_impl.h"

/* The first row whose scheme starts the spec; a spec with no scheme is an LMDB directory. */
static const srv_store_backend *const backends[] = { &srv_store_lmdb, &srv_store_redis };

/* A put kept while the store is down. */
typedef struct kept {
    struct kept *next;
    char id[API_ID_LEN + 1];
    char *model, *request;   /* request may be NULL */
    size_t size;             /* id, model and request bytes: what pending_kb bounds */
} kept;

struct srv_store {
    const srv_store_backend *b;
    void *impl;
    char name[1024];
    atomic_ullong puts, gets, misses, errors;
    pthread_mutex_t lock;    /* the kept puts and the thread's state */
    pthread_cond_t wake;
    pthread_t thread;
    int closing;
    kept *head, *tail;       /* the oldest first */
    kept *flying;            /* taken from head, being written by the thread */
    size_t pending, pending_bytes, pending_max;
    atomic_int any;          /* pending or flying: a get looks there (read without the lock) */
    unsigned long long late, dropped;
};

static void kept_free(kept *k)
{
    if (k) {
        free(k->model);
        free(k->request);
        free(k);
    }
}

/* Unlinks the oldest kept put (there is one). Lock held. */
static kept *take_oldest(srv_store *s)
{
    kept *k = s->head;
    s->head = k->next;
    if (!s->head)
        s->tail = NULL;
    s->pending--;
    s->pending_bytes -= k->size;
    atomic_store(&s->any, s->pending || s->flying);
    return k;
}

/* Drops the oldest kept puts until extra more bytes fit. Lock held. */
static void make_room(srv_store *s, size_t extra)
{
    while (s->head && s->pending_bytes + extra > s->pending_max) {
        kept_free(take_oldest(s));
        s->dropped++;
    }
}

/* Keeps a put that met DOWN, newest last (or, again = 1, the flying one back at the head). Lock held. */
static void keep(srv_store *s, kept *k, int again)
{
    if (k->size > s->pending_max) {
        s->dropped++;
        kept_free(k);
        return;
    }
    if (again) {
        /* The oldest: room is made by dropping it last of all. */
        k->next = s->head;
        s->head = k;
        if (!s->tail)
            s->tail = k;
        s->pending++;
        s->pending_bytes += k->size;
        make_room(s, 0);
        atomic_store(&s->any, s->pending || s->flying);
        return;
    }
    make_room(s, k->size);
    k->next = NULL;
    if (s->tail)
        s->tail->next = k;
    else
        s->head = k;
    s->tail = k;
    s->pending++;
    s->pending_bytes += k->size;
    atomic_store(&s->any, 1);
}

/* The kept put of id, or NULL. Lock held. */
static const kept *find_kept(const srv_store *s, const char *id)
{
    if (s->flying && !strcmp(s->flying->id, id))
        return s->flying;
    for (const kept *k = s->head; k; k = k->next)
        if (!strcmp(k->id, id))
            return k;
    return NULL;
}

/* Writes the kept puts, the oldest first, until one meets DOWN. Lock held; released while writing. */
static void write_kept(srv_store *s)
{
    while (s->head) {
        kept *k = s->flying = take_oldest(s);
        atomic_store(&s->any, 1);
        pthread_mutex_unlock(&s->lock);
        srv_store_status st = s->b->put(s->impl, k->id, k->model, k->request);
        pthread_mutex_lock(&s->lock);
        s->flying = NULL;
        atomic_store(&s->any, s->pending > 0);
        if (st == SRV_STORE_DOWN) {
            keep(s, k, 1);
            return;
        }
        if (st == SRV_STORE_OK)
            s->late++;
        else
            atomic_fetch_add(&s->errors, 1);   /* refused for good (too large, full): not kept */
        kept_free(k);
    }
}

static void *store_thread(void *arg)
{
    srv_store *s = arg;
    pthread_mutex_lock(&s->lock);
    while (!s->closing) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_sec += 1;
        pthread_cond_timedwait(&s->wake, &s->lock, &until);
        if (s->closing)
            break;
        write_kept(s);
        if (s->b->tick) {
            pthread_mutex_unlock(&s->lock);
            s->b->tick(s->impl);
            pthread_mutex_lock(&s->lock);
        }
    }
    pthread_mutex_unlock(&s->lock);
    return NULL;
}

/* A call answered: the kept puts may go now. */
static void answered(srv_store *s)
{
    if (!atomic_load(&s->any))
        return;
    pthread_mutex_lock(&s->lock);
    if (s->pending)
        pthread_cond_signal(&s->wake);
    pthread_mutex_unlock(&s->lock);
}

/* The backend of spec (LMDB for a directory without a scheme), *where what its open() gets; NULL for a
 * spec that starts like a URL of no backend (ftp://x, REDIS://x, redis:/x), a mistake more likely than a
 * directory of that name (./ftp:/x is one). */
static const srv_store_backend *backend_of(const char *spec, const char **where)
{
    *where = spec;
    for (size_t i = 0; i < sizeof backends / sizeof *backends; i++) {
        size_t n = strlen(backends[i]->scheme);
        if (!strncmp(spec, backends[i]->scheme, n)) {
            *where = backends[i]->keep_scheme ? spec : spec + n;
            return backends[i];
        }
    }
    size_t k = strspn(spec, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789+.-");
    return k && spec[k] == ':' && !(spec[0] >= '0' && spec[0] <= '9') ? NULL : &srv_store_lmdb;
}

int srv_store_spec_check(const char *spec)
{
    const char *where;
    const srv_store_backend *b = strcmp(spec, "none") ? backend_of(spec, &where) : NULL;
    return !strcmp(spec, "none") ? 0 : b ? b->check(where) : -1;
}

srv_store *srv_store_open(const srv_store_config *cfg, char *why, size_t whylen)
{
    const char *spec = cfg->spec && *cfg->spec ? cfg->spec : "none";
    snprintf(why, whylen, "%s", "");
    if (!strcmp(spec, "none"))
        return NULL;
    const char *where;
    const srv_store_backend *b = backend_of(spec, &where);
    if (!b || b->check(where)) {
        snprintf(why, whylen, "--store %s: not a store; give DIR, lmdb:DIR, redis://HOST:PORT[/DB] or none", spec);
        return NULL;
    }
    srv_store *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(why, whylen, "out of memory");
        return NULL;
    }
    s->b = b;
    if (b == &srv_store_lmdb)
        snprintf(s->name, sizeof s->name, "lmdb:%s", where);
    else
        snprintf(s->name, sizeof s->name, "%s", spec);
    s->pending_max = (cfg->pending_kb ? cfg->pending_kb : 16384) << 10;
    s->impl = b->open(where, cfg, why, whylen);
    if (!s->impl) {
        free(s);
        return NULL;
    }
    pthread_mutex_init(&s->lock, NULL);
    pthread_cond_init(&s->wake, NULL);
    int rc = pthread_create(&s->thread, NULL, store_thread, s);
    if (rc) {
        snprintf(why, whylen, "--store %s: its thread: %s", spec, strerror(rc));
        pthread_cond_destroy(&s->wake);
        pthread_mutex_destroy(&s->lock);
        b->close(s->impl);
        free(s);
        return NULL;
    }
    return s;
}

srv_store_status srv_store_get(srv_store *s, const char *id, char **model, char **request)
{
    *model = NULL;
    if (request)
        *request = NULL;
    atomic_fetch_add(&s->gets, 1);
    if (!api_id_valid(id)) {
        atomic_fetch_add(&s->misses, 1);
        return SRV_STORE_MISSING;
    }
    char *req = NULL;
    srv_store_status st = SRV_STORE_MISSING;
    const kept *k = NULL;
    if (atomic_load(&s->any)) {
        pthread_mutex_lock(&s->lock);
        if ((k = find_kept(s, id))) {   /* answered by this process, not in the store yet */
            *model = strdup(k->model);
            req = k->request ? strdup(k->request) : NULL;
            st = *model && (req || !k->request) ? SRV_STORE_OK : SRV_STORE_NOMEM;
        }
        pthread_mutex_unlock(&s->lock);
    }
    if (!k)
        st = s->b->get(s->impl, id, model, &req);
    else if (st != SRV_STORE_OK) {
        free(*model);
        free(req);
        *model = req = NULL;
    }
    if (request)
        *request = req;
    else
        free(req);
    if (st == SRV_STORE_MISSING)
        atomic_fetch_add(&s->misses, 1);
    else if (st != SRV_STORE_OK)
        atomic_fetch_add(&s->errors, 1);
    if (!k && (st == SRV_STORE_OK || st == SRV_STORE_MISSING))
        answered(s);
    return st;
}

srv_store_status srv_store_put(srv_store *s, const char *id, const char *model, const char *request)
{
    atomic_fetch_add(&s->puts, 1);
    srv_store_status st = api_id_valid(id) && model ? s->b->put(s->impl, id, model, request) : SRV_STORE_ERROR;
    if (st != SRV_STORE_OK)
        atomic_fetch_add(&s->errors, 1);
    if (st == SRV_STORE_OK) {
        answered(s);
    } else if (st == SRV_STORE_DOWN) {
        kept *k = calloc(1, sizeof *k);
        if (k) {
            memcpy(k->id, id, API_ID_LEN);
            k->model = strdup(model);
            k->request = request ? strdup(request) : NULL;
            k->size = API_ID_LEN + strlen(model) + (request ? strlen(request) : 0);
        }
        pthread_mutex_lock(&s->lock);
        if (k && k->model && (k->request || !request))
            keep(s, k, 0);
        else {
            s->dropped++;
            kept_free(k);
        }
        pthread_mutex_unlock(&s->lock);
    }
    return st;
}

void srv_store_stats_get(srv_store *s, srv_store_stats *out)
{
    memset(out, 0, sizeof *out);
    s->b->stats(s->impl, out);
    out->puts = atomic_load(&s->puts);
    out->gets = atomic_load(&s->gets);
    out->misses = atomic_load(&s->misses);
    out->errors = atomic_load(&s->errors);
    pthread_mutex_lock(&s->lock);
    out->pending = s->pending + (s->flying != NULL);
    out->late = s->late;
    out->dropped = s->dropped;
    pthread_mutex_unlock(&s->lock);
}

void srv_store_metrics(srv_store *s, void *sbuf)
{
    srv_sbuf *b = sbuf;
    srv_store_stats st;
    srv_store_stats_get(s, &st);
    static const struct {
        const char *name, *type, *help;
        size_t off;
    } rows[] = {
        { "store_bytes", "gauge", "Bytes the store holds (LMDB: the entries; Redis: its used_memory).",
          offsetof(srv_store_stats, bytes) },
        { "store_entries", "gauge", "Ids in the store (Redis: keys of its database).", offsetof(srv_store_stats, entries) },
        { "store_evictions_total", "counter", "Ids this process evicted to keep the store within --store-mb.",
          offsetof(srv_store_stats, evictions) },
        { "store_puts_total", "counter", "New ids put in the store.", offsetof(srv_store_stats, puts) },
        { "store_gets_total", "counter", "Lookups of ids missing from the solution cache.", offsetof(srv_store_stats, gets) },
        { "store_misses_total", "counter", "Lookups of ids the store did not have.", offsetof(srv_store_stats, misses) },
        { "store_errors_total", "counter", "Store calls that failed (unreachable, full, out of memory).",
          offsetof(srv_store_stats, errors) },
        { "store_commits_total", "counter",
          "LMDB: write transactions this process committed, each a synchronous write (puts, batched LRU refreshes).",
          offsetof(srv_store_stats, commits) },
        { "store_pending", "gauge", "Puts kept in memory while the store is unreachable, to be written when it answers.",
          offsetof(srv_store_stats, pending) },
        { "store_late_puts_total", "counter", "Kept puts written once the store answered again.",
          offsetof(srv_store_stats, late) },
        { "store_pending_dropped_total", "counter",
          "Kept puts dropped, the oldest first, to stay within the bound (16 MiB): those ids are lost at exit.",
          offsetof(srv_store_stats, dropped) },
    };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++)
        srv_sbuf_printf(b, "# HELP pdesolid_%s %s\n# TYPE pdesolid_%s %s\npdesolid_%s %llu\n", rows[i].name, rows[i].help,
                        rows[i].name, rows[i].type, rows[i].name,
                        *(const unsigned long long *)((const char *)&st + rows[i].off));
    srv_sbuf_printf(b, "# HELP pdesolid_store_up 1 if the store answered its last call.\n# TYPE pdesolid_store_up gauge\n"
                    "pdesolid_store_up %d\n", st.up);
}

int srv_store_ready(srv_store *s)
{
    return s->b->ready(s->impl);
}

const char *srv_store_name(const srv_store *s)
{
    return s->name;
}

void srv_store_close(srv_store *s)
{
    if (!s)
        return;
    pthread_mutex_lock(&s->lock);
    s->closing = 1;
    pthread_cond_signal(&s->wake);
    pthread_mutex_unlock(&s->lock);
    pthread_join(s->thread, NULL);
    pthread_mutex_lock(&s->lock);
    write_kept(s);   /* a last try: what is still kept now dies with the process */
    if (s->b->tick)
        s->b->tick(s->impl);
    for (kept *k = s->head, *next; k; k = next) {
        next = k->next;
        kept_free(k);
    }
    pthread_mutex_unlock(&s->lock);
    pthread_cond_destroy(&s->wake);
    pthread_mutex_destroy(&s->lock);
    s->b->close(s->impl);
    free(s);
}
