/*
 * store_lmdb.c: the LMDB store (store.h), the default. One environment per
 * directory (created 0700 if missing), opened with MDB_NOTLS so that any
 * solver thread may read; several processes may share it (LMDB's locks).
 * A put commits with a synchronous write (no MDB_NOSYNC): once it returns,
 * the id survives SIGKILL and power loss. Group commit: puts that arrive
 * while a commit is under way wait, and the first of them writes them all in
 * the next commit (lmdb_put), so concurrent new ids share one fsync.
 *
 * Four databases:
 *   ids   id -> u32 model length, model, request (the request may be empty)
 *   age   id -> u64 stamp of its last use
 *   lru   u64 stamp, big-endian -> id: the least recently used first
 *   meta  "clock" -> u64 (the last stamp given), "bytes" -> u64 (the sum of
 *         the ids' keys and values)
 * A stamp is a counter bumped by each write transaction, which LMDB runs one
 * at a time across processes, so stamps are unique.
 *
 * Bound: the map is --store-mb; the entries' bytes are kept under half of it
 * (the rest is B-tree pages and copy-on-write room). A put that would go over
 * evicts the least recently used entries first; a put that still meets
 * MDB_MAP_FULL evicts an eighth of the entries and tries again.
 * A get never writes. It asks for its entry's stamp to be refreshed only
 * when the entry is in the older half of the LRU order (its stamp is below
 * clock + asked - entries / 2, asked counting the refreshes not yet written);
 * the refreshes asked for wait in memory (up to TOUCH_MAX ids, more are not
 * kept) and are written by this process's next put, in its transaction, or
 * else within about a second by store.c's thread (tick), in one commit for
 * all. So hot entries cost nothing, an entry read since it reached the older
 * half is not the next evicted by this process, and a crash loses at most
 * the last second's refreshes (the order, never an entry).
 */
#include <errno.h>
#include <lmdb.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "id.h"
#include "store_impl.h"

#define TOUCH_MAX 4096   /* refreshes waiting to be written */

/* A put waiting for its commit (lmdb_put). */
typedef struct put_req {
    struct put_req *next;
    const char *id, *model, *request;
    size_t mlen, rlen;
    int done, rc;
} put_req;

typedef struct {
    MDB_env *env;
    MDB_dbi ids, age, lru, meta;
    uint64_t budget;
    atomic_ullong evictions, commits;
    pthread_mutex_t lock;                 /* the refreshes asked for */
    char touches[TOUCH_MAX][API_ID_LEN];  /* in the order asked */
    atomic_size_t ntouch;                 /* written under the lock, read without it */
    uint16_t slot[2 * TOUCH_MAX];         /* open addressing over touches: index + 1, 0 free */
    pthread_mutex_t glock;                /* group commit: the puts waiting, and who writes */
    pthread_cond_t gdone;
    put_req *queue, **qtail;
    int writing;
} lmdb_store;

/* mkdir -p, the last component 0700. */
static int make_dirs(const char *dir)
{
    char path[1024];
    if (snprintf(path, sizeof path, "%s", dir) >= (int)sizeof path)
        return ENAMETOOLONG;
    for (char *p = path + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = '\0';
        if (mkdir(path, 0755) && errno != EEXIST)
            return errno;
        *p = '/';
    }
    if (mkdir(path, 0700) && errno != EEXIST)
        return errno;
    return 0;
}

static uint64_t get_u64(MDB_txn *t, MDB_dbi dbi, const char *key)
{
    MDB_val k = { strlen(key), (void *)key }, v;
    uint64_t x = 0;
    if (!mdb_get(t, dbi, &k, &v) && v.mv_size == sizeof x)
        memcpy(&x, v.mv_data, sizeof x);
    return x;
}

static int put_u64(MDB_txn *t, MDB_dbi dbi, const char *key, uint64_t x)
{
    MDB_val k = { strlen(key), (void *)key }, v = { sizeof x, &x };
    return mdb_put(t, dbi, &k, &v, 0);
}

static void stamp_key(uint64_t stamp, unsigned char out[8])
{
    for (int i = 7; i >= 0; i--, stamp >>= 8)
        out[i] = (unsigned char)stamp;
}

/* Gives id a new stamp (the next of the clock). */
static int touch(lmdb_store *L, MDB_txn *t, const char *id)
{
    MDB_val k = { API_ID_LEN, (void *)id }, v;
    int rc;
    if (!mdb_get(t, L->age, &k, &v) && v.mv_size == 8) {
        uint64_t old;
        memcpy(&old, v.mv_data, 8);
        unsigned char ok[8];
        stamp_key(old, ok);
        MDB_val lk = { 8, ok };
        rc = mdb_del(t, L->lru, &lk, NULL);
        if (rc && rc != MDB_NOTFOUND)
            return rc;
    }
    uint64_t now = get_u64(t, L->meta, "clock") + 1;
    if ((rc = put_u64(t, L->meta, "clock", now)))
        return rc;
    MDB_val sv = { 8, &now };
    if ((rc = mdb_put(t, L->age, &k, &sv, 0)))
        return rc;
    unsigned char nk[8];
    stamp_key(now, nk);
    MDB_val lk = { 8, nk };
    return mdb_put(t, L->lru, &lk, &k, 0);
}

/* Writes the refreshes asked for (of the entries still there) in t; they are gone from memory
 * whether t commits or not: a refresh lost costs LRU order, never an entry. */
static int apply_touches(lmdb_store *L, MDB_txn *t)
{
    pthread_mutex_lock(&L->lock);
    size_t n = L->ntouch;
    char(*ids)[API_ID_LEN] = n ? malloc(n * API_ID_LEN) : NULL;
    if (ids)
        memcpy(ids, L->touches, n * API_ID_LEN);
    L->ntouch = 0;
    memset(L->slot, 0, sizeof L->slot);
    pthread_mutex_unlock(&L->lock);
    int rc = 0;
    for (size_t i = 0; ids && !rc && i < n; i++) {
        MDB_val k = { API_ID_LEN, ids[i] }, v;
        if (!mdb_get(t, L->ids, &k, &v))
            rc = touch(L, t, ids[i]);
    }
    free(ids);
    return rc;
}

/* Asks for id's stamp to be refreshed (apply_touches); nothing if it is asked already or too many are. */
static void ask_touch(lmdb_store *L, const char *id)
{
    uint32_t h = 2166136261u;   /* FNV-1a */
    for (int i = 0; i < API_ID_LEN; i++)
        h = (h ^ (unsigned char)id[i]) * 16777619u;
    pthread_mutex_lock(&L->lock);
    size_t i = h % (2 * TOUCH_MAX);
    while (L->slot[i] && memcmp(L->touches[L->slot[i] - 1], id, API_ID_LEN))
        i = (i + 1) % (2 * TOUCH_MAX);
    size_t n = L->ntouch;
    if (!L->slot[i] && n < TOUCH_MAX) {
        memcpy(L->touches[n], id, API_ID_LEN);
        L->slot[i] = (uint16_t)(n + 1);
        L->ntouch = n + 1;
    }
    pthread_mutex_unlock(&L->lock);
}

static size_t asked(lmdb_store *L)
{
    return atomic_load_explicit(&L->ntouch, memory_order_relaxed);
}

static int commit(lmdb_store *L, MDB_txn *t)
{
    int rc = mdb_txn_commit(t);
    if (!rc)
        atomic_fetch_add(&L->commits, 1);
    return rc;
}

/* Evicts the least recently used entry; MDB_NOTFOUND when there is none. */
static int evict_one(lmdb_store *L, MDB_txn *t)
{
    MDB_cursor *c;
    int rc = mdb_cursor_open(t, L->lru, &c);
    if (rc)
        return rc;
    MDB_val lk, idv;
    rc = mdb_cursor_get(c, &lk, &idv, MDB_FIRST);
    if (!rc) {
        char id[API_ID_LEN];
        memcpy(id, idv.mv_data, idv.mv_size < API_ID_LEN ? idv.mv_size : API_ID_LEN);
        MDB_val k = { idv.mv_size < API_ID_LEN ? idv.mv_size : API_ID_LEN, id }, v;
        rc = mdb_cursor_del(c, 0);
        if (!rc && !mdb_get(t, L->ids, &k, &v)) {
            uint64_t bytes = get_u64(t, L->meta, "bytes"), size = k.mv_size + v.mv_size;
            rc = put_u64(t, L->meta, "bytes", bytes > size ? bytes - size : 0);
            if (!rc)
                rc = mdb_del(t, L->ids, &k, NULL);
        }
        if (!rc) {
            rc = mdb_del(t, L->age, &k, NULL);
            if (rc == MDB_NOTFOUND)
                rc = 0;
        }
        if (!rc)
            atomic_fetch_add(&L->evictions, 1);
    }
    mdb_cursor_close(c);
    return rc;
}

static srv_store_status status_of(int rc)
{
    return rc == 0 ? SRV_STORE_OK : rc == MDB_NOTFOUND ? SRV_STORE_MISSING : rc == ENOMEM ? SRV_STORE_NOMEM
                                                                                          : SRV_STORE_ERROR;
}

/* A directory: any path but the empty one. */
static int lmdb_check(const char *dir)
{
    return *dir ? 0 : -1;
}

static void *lmdb_open(const char *dir, const srv_store_config *cfg, char *why, size_t whylen)
{
    lmdb_store *L = calloc(1, sizeof *L);
    if (!L) {
        snprintf(why, whylen, "out of memory");
        return NULL;
    }
    size_t mb = cfg->max_mb ? cfg->max_mb : 256;
    L->budget = (uint64_t)mb << 19;   /* half the map */
    MDB_txn *t = NULL;
    int rc = make_dirs(dir);
    const char *step = "mkdir";
    if (!rc && !(rc = mdb_env_create(&L->env))) {
        step = "mdb_env_open";
        if (!(rc = mdb_env_set_maxdbs(L->env, 4)) && !(rc = mdb_env_set_mapsize(L->env, mb << 20)) &&
            !(rc = mdb_env_set_maxreaders(L->env, 510)))
            rc = mdb_env_open(L->env, dir, MDB_NOTLS, 0600);
    }
    if (!rc) {
        int dead;
        mdb_reader_check(L->env, &dead);   /* readers of processes that died */
        step = "creating its databases";
        rc = mdb_txn_begin(L->env, NULL, 0, &t);
    }
    if (!rc && !(rc = mdb_dbi_open(t, "ids", MDB_CREATE, &L->ids)) && !(rc = mdb_dbi_open(t, "age", MDB_CREATE, &L->age)) &&
        !(rc = mdb_dbi_open(t, "lru", MDB_CREATE, &L->lru)) && !(rc = mdb_dbi_open(t, "meta", MDB_CREATE, &L->meta)))
        rc = mdb_txn_commit(t);
    else if (t)
        mdb_txn_abort(t);
    if (!rc) {
        pthread_mutex_init(&L->lock, NULL);
        pthread_mutex_init(&L->glock, NULL);
        pthread_cond_init(&L->gdone, NULL);
        L->qtail = &L->queue;
    }
    if (rc) {
        snprintf(why, whylen, "--store %s: %s: %s", dir, step, rc > 0 ? strerror(rc) : mdb_strerror(rc));
        if (L->env)
            mdb_env_close(L->env);
        free(L);
        return NULL;
    }
    return L;
}

static char *dup_n(const void *p, size_t n)
{
    char *s = malloc(n + 1);
    if (s) {
        memcpy(s, p, n);
        s[n] = '\0';
    }
    return s;
}

static srv_store_status lmdb_get(void *b, const char *id, char **model, char **request)
{
    lmdb_store *L = b;
    MDB_txn *t;
    int rc = mdb_txn_begin(L->env, NULL, MDB_RDONLY, &t);
    if (rc == MDB_MAP_RESIZED) {   /* another process grew the map */
        mdb_env_set_mapsize(L->env, 0);
        rc = mdb_txn_begin(L->env, NULL, MDB_RDONLY, &t);
    }
    if (rc)
        return status_of(rc);
    MDB_val k = { API_ID_LEN, (void *)id }, v;
    int refresh = 0;
    rc = mdb_get(t, L->ids, &k, &v);
    if (!rc) {
        uint32_t mlen = 0;
        if (v.mv_size < 4 || (memcpy(&mlen, v.mv_data, 4), mlen > v.mv_size - 4)) {
            rc = MDB_CORRUPTED;
        } else {
            const char *p = (const char *)v.mv_data + 4;
            size_t rlen = v.mv_size - 4 - mlen;
            *model = dup_n(p, mlen);
            *request = rlen ? dup_n(p + mlen, rlen) : NULL;
            if (!*model || (rlen && !*request)) {
                free(*model);
                free(*request);
                *model = *request = NULL;
                rc = ENOMEM;
            }
        }
        MDB_val sv;
        MDB_stat st;
        if (!rc && !mdb_get(t, L->age, &k, &sv) && sv.mv_size == 8 && !mdb_stat(t, L->ids, &st)) {
            uint64_t stamp, clock = get_u64(t, L->meta, "clock") + asked(L);
            memcpy(&stamp, sv.mv_data, 8);
            refresh = stamp + st.ms_entries / 2 < clock;
        }
    }
    mdb_txn_abort(t);
    if (!rc && refresh)
        ask_touch(L, id);
    return status_of(rc);
}

/* Puts p in t: a known id only gets a new stamp (entries are immutable). */
static int put_one(lmdb_store *L, MDB_txn *t, const put_req *p)
{
    uint64_t size = API_ID_LEN + 4 + p->mlen + p->rlen;
    MDB_val k = { API_ID_LEN, (void *)p->id }, v;
    if (!mdb_get(t, L->ids, &k, &v))
        return touch(L, t, p->id);
    int rc = 0;
    uint64_t bytes = get_u64(t, L->meta, "bytes");
    while (!rc && bytes + size > L->budget) {
        rc = evict_one(L, t);
        bytes = get_u64(t, L->meta, "bytes");
    }
    if (rc == MDB_NOTFOUND)
        rc = 0;
    v.mv_size = size - API_ID_LEN;
    if (!rc && !(rc = mdb_put(t, L->ids, &k, &v, MDB_RESERVE))) {
        uint32_t m32 = (uint32_t)p->mlen;
        memcpy(v.mv_data, &m32, 4);
        memcpy((char *)v.mv_data + 4, p->model, p->mlen);
        memcpy((char *)v.mv_data + 4 + p->mlen, p->request ? p->request : "", p->rlen);
        rc = put_u64(t, L->meta, "bytes", bytes + size);
    }
    return rc ? rc : touch(L, t, p->id);
}

/* Writes the puts of batch in one synchronous commit (with the refreshes asked for); 0 or the error,
 * the same for all. */
static int write_batch(lmdb_store *L, const put_req *batch)
{
    int rc = 0;
    for (int attempt = 0; attempt < 4; attempt++) {
        MDB_txn *t;
        rc = mdb_txn_begin(L->env, NULL, 0, &t);
        if (rc == MDB_MAP_RESIZED) {
            mdb_env_set_mapsize(L->env, 0);
            rc = mdb_txn_begin(L->env, NULL, 0, &t);
        }
        if (rc)
            return rc;
        rc = apply_touches(L, t);   /* on an error the refreshes are lost */
        for (const put_req *p = batch; !rc && p; p = p->next)
            rc = put_one(L, t, p);
        if (!rc)
            return commit(L, t);
        mdb_txn_abort(t);
        if (rc != MDB_MAP_FULL)
            break;
        /* Full before the budget (pages, not bytes): evict an eighth and try again. */
        if (mdb_txn_begin(L->env, NULL, 0, &t))
            break;
        MDB_stat st;
        int e = mdb_stat(t, L->ids, &st);
        for (size_t i = 0; !e && i < st.ms_entries / 8 + 1; i++)
            e = evict_one(L, t);
        if (e && e != MDB_NOTFOUND) {
            mdb_txn_abort(t);
            break;
        }
        if (commit(L, t))
            break;
    }
    return rc;
}

/* Group commit: the puts that arrive while a commit is under way wait for it, and the first of them
 * then writes them all in the next commit. Each returns once its own commit is on disk. */
static srv_store_status lmdb_put(void *b, const char *id, const char *model, const char *request)
{
    lmdb_store *L = b;
    put_req me = { NULL, id, model, request, strlen(model), request ? strlen(request) : 0, 0, 0 };
    if (me.mlen > UINT32_MAX || API_ID_LEN + 4 + me.mlen + me.rlen > L->budget)
        return SRV_STORE_ERROR;
    pthread_mutex_lock(&L->glock);
    *L->qtail = &me;
    L->qtail = &me.next;
    while (!me.done) {
        if (L->writing) {
            pthread_cond_wait(&L->gdone, &L->glock);
            continue;
        }
        put_req *batch = L->queue;
        L->queue = NULL;
        L->qtail = &L->queue;
        L->writing = 1;
        pthread_mutex_unlock(&L->glock);
        int rc = write_batch(L, batch);
        pthread_mutex_lock(&L->glock);
        for (put_req *p = batch, *next; p; p = next) {
            next = p->next;   /* p is its caller's, gone once done */
            p->rc = rc;
            p->done = 1;
        }
        L->writing = 0;
        pthread_cond_broadcast(&L->gdone);
    }
    pthread_mutex_unlock(&L->glock);
    return status_of(me.rc);
}

static void lmdb_stats(void *b, srv_store_stats *out)
{
    lmdb_store *L = b;
    MDB_txn *t;
    out->up = 1;
    out->evictions = atomic_load(&L->evictions);
    out->commits = atomic_load(&L->commits);
    if (mdb_txn_begin(L->env, NULL, MDB_RDONLY, &t))
        return;
    MDB_stat st;
    if (!mdb_stat(t, L->ids, &st))
        out->entries = st.ms_entries;
    out->bytes = get_u64(t, L->meta, "bytes");
    mdb_txn_abort(t);
}

static int lmdb_ready(void *b)
{
    (void)b;
    return 1;
}

/* Writes the refreshes asked for, in one commit (store.c's thread, about once a second). */
static void lmdb_tick(void *b)
{
    lmdb_store *L = b;
    MDB_txn *t;
    if (!asked(L) || mdb_txn_begin(L->env, NULL, 0, &t))
        return;
    if (!apply_touches(L, t))
        commit(L, t);
    else
        mdb_txn_abort(t);
}

static void lmdb_close(void *b)
{
    lmdb_store *L = b;
    mdb_env_close(L->env);
    pthread_mutex_destroy(&L->lock);
    pthread_mutex_destroy(&L->glock);
    pthread_cond_destroy(&L->gdone);
    free(L);
}

const srv_store_backend srv_store_lmdb = { "lmdb:", 0, lmdb_check, lmdb_open, lmdb_get, lmdb_put, lmdb_stats, lmdb_ready, lmdb_close, lmdb_tick };
