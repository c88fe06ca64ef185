/*
 * bench_store: the LMDB store's put and get (server/store_lmdb.c), against a
 * solve of the model they keep: a put is a synchronous commit (an fsync),
 * paid once per new id; a get is what a cache miss of a known id costs before
 * it re-solves; a get in the older half of the LRU order (scattered) asks
 * for its stamp to be refreshed, in memory, written later in one commit with
 * others; one of a recent id does not. Medians of single calls, on fig4a's canonical model (about
 * 400 bytes), in a store in $TMPDIR or /tmp. With redis-server on
 * 127.0.0.1:$REDIS_PORT (when set), the same for Redis.
 */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "model.h"
#include "bench.h"
#include "store.h"

#define N 401

static void measure(const char *spec, const char *model, double solve)
{
    char why[256];
    srv_store *s = srv_store_open(&(srv_store_config){ .spec = spec, .max_mb = 64 }, why, sizeof why);
    if (!s) {
        fprintf(stderr, "bench_store: %s\n", why);
        exit(1);
    }
    static double put[N], get[N];
    char id[33];
    for (int i = 0; i < N; i++) {
        snprintf(id, sizeof id, "%032x", 0x5eed0000u + (unsigned)i);
        double t0 = now();
        if (srv_store_put(s, id, model, "{\"preset\":\"fig4a\"}") != SRV_STORE_OK) {
            fprintf(stderr, "bench_store: %s: a put failed\n", spec);
            exit(1);
        }
        put[i] = now() - t0;
    }
    for (int i = 0; i < N; i++) {
        snprintf(id, sizeof id, "%032x", 0x5eed0000u + (unsigned)((i * 7) % N));
        char *m, *r;
        double t0 = now();
        srv_store_get(s, id, &m, &r);
        get[i] = now() - t0;
        free(m);
        free(r);
    }
    static double hot[N];
    for (int i = 0; i < N; i++) {   /* the newest id: a read that never refreshes its stamp */
        char *m, *r;
        double t0 = now();
        srv_store_get(s, id, &m, &r);
        hot[i] = now() - t0;
        free(m);
        free(r);
    }
    double p = median(put, N), g = median(get, N), h = median(hot, N);
    printf("%-28s put %7.1f us   get (scattered) %7.2f us   get (recent) %5.2f us = %.2f solves\n", spec, p * 1e6,
           g * 1e6, h * 1e6, h / solve);
    srv_store_close(s);
}

/* New ids put by several threads at once, as a daemon's solver threads do: puts a second. */
#define PAR_PUTS 200
typedef struct {
    srv_store *s;
    const char *model;
    unsigned base;
} par_arg;

static void *par_put(void *p)
{
    par_arg *a = p;
    char id[33];
    for (unsigned i = 0; i < PAR_PUTS; i++) {
        snprintf(id, sizeof id, "%032x", a->base + i);
        if (srv_store_put(a->s, id, a->model, "{\"preset\":\"fig4a\"}") != SRV_STORE_OK)
            exit(1);
    }
    return NULL;
}

static void measure_parallel(const char *dir, const char *model)
{
    char spec[600], why[256];
    snprintf(spec, sizeof spec, "%s-par", dir);
    srv_store *s = srv_store_open(&(srv_store_config){ .spec = spec, .max_mb = 64 }, why, sizeof why);
    if (!s) {
        fprintf(stderr, "bench_store: %s\n", why);
        exit(1);
    }
    static const int counts[] = { 1, 2, 8 };
    for (size_t c = 0; c < sizeof counts / sizeof *counts; c++) {
        pthread_t th[8];
        par_arg a[8];
        srv_store_stats s0, s1;
        srv_store_stats_get(s, &s0);
        double t0 = now();
        for (int i = 0; i < counts[c]; i++) {
            a[i] = (par_arg){ s, model, 0x7a000000u + (unsigned)(c * 8 + i) * 0x10000u };
            pthread_create(&th[i], NULL, par_put, &a[i]);
        }
        for (int i = 0; i < counts[c]; i++)
            pthread_join(th[i], NULL);
        double t = now() - t0;
        srv_store_stats_get(s, &s1);
        printf("%d thread(s) putting new ids: %6.0f puts/s, %.2f puts a commit\n", counts[c],
               counts[c] * PAR_PUTS / t, (double)counts[c] * PAR_PUTS / (double)(s1.commits - s0.commits));
    }
    srv_store_close(s);
}

int main(void)
{
    const char *tmp = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    char dir[512], cmd[1100];
    snprintf(dir, sizeof dir, "%s/bench-store-%d", tmp, (int)getpid());
    api_model *m = NULL;
    api_error err;
    const char *req = "{\"preset\":\"fig4a\"}";
    m = api_model_parse(req, strlen(req), &err);
    char *model = api_model_json(api_model_get(m));
    static double solve[N];
    for (int i = 0; i < N; i++) {
        pde_solution *sol;
        double t0 = now();
        api_solve(m, &sol, &err);
        solve[i] = now() - t0;
        pde_solution_free(sol);
    }
    double ts = median(solve, N);
    printf("fig4a: solve %.1f us, canonical model %zu bytes\n", ts * 1e6, strlen(model));
    measure(dir, model, ts);
    measure_parallel(dir, model);
    if (getenv("REDIS_PORT")) {
        char spec[64];
        snprintf(spec, sizeof spec, "redis://127.0.0.1:%s/9", getenv("REDIS_PORT"));
        measure(spec, model, ts);
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s-par'", dir, dir);
    if (system(cmd))
        fprintf(stderr, "bench_store: could not remove %s\n", dir);
    free(model);
    api_model_free(m);
    return 0;
}
