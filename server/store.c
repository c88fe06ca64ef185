/*
 * store.c: the store interface (store.h) over its backends, one row each.
 */
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "id.h"
#include "sbuf.h"
#include "store_impl.h"

/* The first row whose scheme starts the spec; a spec with no scheme is an LMDB directory. */
static const srv_store_backend *const backends[] = { &srv_store_lmdb, &srv_store_redis };

struct srv_store {
    const srv_store_backend *b;
    void *impl;
    char name[1024];
    atomic_ullong puts, gets, misses, errors;
};

srv_store *srv_store_open(const srv_store_config *cfg, char *why, size_t whylen)
{
    const char *spec = cfg->spec && *cfg->spec ? cfg->spec : "none";
    snprintf(why, whylen, "%s", "");
    if (!strcmp(spec, "none"))
        return NULL;
    const srv_store_backend *b = &srv_store_lmdb;
    const char *where = spec;
    for (size_t i = 0; i < sizeof backends / sizeof *backends; i++) {
        size_t n = strlen(backends[i]->scheme);
        if (!strncmp(spec, backends[i]->scheme, n)) {
            b = backends[i];
            where = backends[i]->keep_scheme ? spec : spec + n;
            break;
        }
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
    s->impl = b->open(where, cfg, why, whylen);
    if (!s->impl) {
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
    srv_store_status st = s->b->get(s->impl, id, model, &req);
    if (request)
        *request = req;
    else
        free(req);
    if (st == SRV_STORE_MISSING)
        atomic_fetch_add(&s->misses, 1);
    else if (st != SRV_STORE_OK)
        atomic_fetch_add(&s->errors, 1);
    return st;
}

srv_store_status srv_store_put(srv_store *s, const char *id, const char *model, const char *request)
{
    atomic_fetch_add(&s->puts, 1);
    srv_store_status st = api_id_valid(id) && model ? s->b->put(s->impl, id, model, request) : SRV_STORE_ERROR;
    if (st != SRV_STORE_OK)
        atomic_fetch_add(&s->errors, 1);
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
    s->b->close(s->impl);
    free(s);
}
