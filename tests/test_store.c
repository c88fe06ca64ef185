/*
 * test_store.c: durable ids (server/store.h). The LMDB store directly: round
 * trips, durability across close and open, the bound's LRU eviction, two
 * processes on one directory. Then pdesolidd with a store: ids that outlive
 * SIGKILL, and (when /usr/bin/redis-server exists) two daemons sharing a
 * Redis store through its outage.
 */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <pthread.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cJSON.h>
#include <cmocka.h>
#include <curl/curl.h>

#include "sbuf.h"
#include "store.h"
#include "support.h"

static char dir[] = "/tmp/pdesolid-store-XXXXXX";

/* A fresh LMDB store in dir/name, of max_mb. */
static srv_store *open_lmdb(const char *name, size_t max_mb)
{
    char spec[256], why[256];
    snprintf(spec, sizeof spec, "lmdb:%s/%s", dir, name);
    srv_store *s = srv_store_open(&(srv_store_config){ .spec = spec, .max_mb = max_mb }, why, sizeof why);
    if (!s)
        fail_msg("%s: %s", spec, why);
    return s;
}

/* The id of the number i: 32 hex digits. */
static const char *id_of(unsigned i, char out[33])
{
    snprintf(out, 33, "%032x", i);
    return out;
}

static void expect_entry(srv_store *s, const char *id, const char *model, const char *request)
{
    char *m = NULL, *r = NULL;
    srv_store_status st = srv_store_get(s, id, &m, &r);
    if (st != SRV_STORE_OK)
        fail_msg("get %s: status %d", id, st);
    assert_string_equal(m, model);
    if (request)
        assert_string_equal(r, request);
    else
        assert_null(r);
    free(m);
    free(r);
}

static void expect_missing(srv_store *s, const char *id)
{
    char *m = NULL, *r = NULL;
    assert_int_equal(srv_store_get(s, id, &m, &r), SRV_STORE_MISSING);
    assert_null(m);
    assert_null(r);
}

/* ---- LMDB ---- */

static void a_put_should_come_back_and_an_unknown_id_be_missing(void **state)
{
    (void)state;
    srv_store *s = open_lmdb("roundtrip", 8);
    char a[33], b[33], c[33];
    assert_int_equal(srv_store_put(s, id_of(1, a), "{\"model\":1}", "{\"preset\":\"fig4a\"}"), SRV_STORE_OK);
    assert_int_equal(srv_store_put(s, id_of(2, b), "{\"model\":2}", NULL), SRV_STORE_OK);
    expect_entry(s, a, "{\"model\":1}", "{\"preset\":\"fig4a\"}");
    expect_entry(s, b, "{\"model\":2}", NULL);
    expect_missing(s, id_of(3, c));
    /* Immutable: a second put of an id keeps the first model. */
    assert_int_equal(srv_store_put(s, a, "{\"other\":1}", NULL), SRV_STORE_OK);
    expect_entry(s, a, "{\"model\":1}", "{\"preset\":\"fig4a\"}");
    assert_int_equal(srv_store_put(s, "not an id", "{}", NULL), SRV_STORE_ERROR);
    srv_store_stats st;
    srv_store_stats_get(s, &st);
    assert_int_equal(st.entries, 2);
    /* The bytes are the keys and values: 32 + 4 + model + request each. */
    assert_int_equal(st.bytes, (32 + 4 + 11 + 18) + (32 + 4 + 11));
    assert_int_equal(st.misses, 1);
    assert_int_equal(st.up, 1);
    srv_store_close(s);
}

static void a_put_should_survive_close_and_open(void **state)
{
    (void)state;
    char a[33];
    srv_store *s = open_lmdb("durable", 8);
    assert_int_equal(srv_store_put(s, id_of(7, a), "{\"m\":7}", "{\"r\":7}"), SRV_STORE_OK);
    srv_store_close(s);
    s = open_lmdb("durable", 8);
    expect_entry(s, a, "{\"m\":7}", "{\"r\":7}");
    srv_store_close(s);
}

/* A model of n bytes, its first character c. */
static char *big(size_t n, char c)
{
    char *m = malloc(n + 1);
    memset(m, 'x', n);
    m[0] = c;
    m[n] = '\0';
    return m;
}

static void the_bound_should_evict_the_least_recently_used_first(void **state)
{
    (void)state;
    /* 4 MiB: a budget of 2 MiB of entries; five of 400000 bytes fit (2000180 B), a sixth does not. */
    srv_store *s = open_lmdb("lru", 4);
    char id[6][33], extra[33];
    char *m[6];
    for (unsigned i = 0; i < 5; i++) {
        m[i] = big(400000 - 36, (char)('A' + i));
        assert_int_equal(srv_store_put(s, id_of(100 + i, id[i]), m[i], NULL), SRV_STORE_OK);
    }
    srv_store_stats st;
    srv_store_stats_get(s, &st);
    assert_int_equal(st.entries, 5);
    assert_int_equal(st.evictions, 0);
    /* A read of the oldest (A) refreshes it: B becomes the least recently used. */
    expect_entry(s, id[0], m[0], NULL);
    m[5] = big(400000 - 36, 'F');
    assert_int_equal(srv_store_put(s, id_of(105, id[5]), m[5], NULL), SRV_STORE_OK);
    srv_store_stats_get(s, &st);
    assert_int_equal(st.evictions, 1);
    assert_int_equal(st.entries, 5);
    assert_int_equal(st.bytes, 5 * 400000);
    expect_missing(s, id[1]);
    expect_entry(s, id[0], m[0], NULL);
    for (int i = 2; i < 6; i++)
        expect_entry(s, id[i], m[i], NULL);
    /* Those reads refreshed C, D, E and F (each in the older half of the order when read), not A, read
     * last of all just before: A is now the least recently used, and goes next. */
    char *g = big(400000 - 36, 'G');
    assert_int_equal(srv_store_put(s, id_of(106, extra), g, NULL), SRV_STORE_OK);
    expect_missing(s, id[0]);
    for (int i = 2; i < 6; i++)
        expect_entry(s, id[i], m[i], NULL);
    srv_store_stats_get(s, &st);
    assert_int_equal(st.evictions, 2);
    /* An entry over the whole budget is refused, and evicts nothing. */
    char *huge = big(3 << 20, 'H');
    assert_int_equal(srv_store_put(s, id_of(107, extra), huge, NULL), SRV_STORE_ERROR);
    srv_store_stats_get(s, &st);
    assert_int_equal(st.evictions, 2);
    assert_int_equal(st.entries, 5);
    free(huge);
    free(g);
    for (int i = 0; i < 6; i++)
        free(m[i]);
    srv_store_close(s);
}

static unsigned long long commits_of(srv_store *s)
{
    srv_store_stats st;
    srv_store_stats_get(s, &st);
    return st.commits;
}

static void a_get_should_never_commit_and_its_refresh_be_written_later_in_one(void **state)
{
    (void)state;
    srv_store *s = open_lmdb("stamps", 8);
    char id[5][33];
    for (unsigned i = 0; i < 4; i++)
        assert_int_equal(srv_store_put(s, id_of(0x200 + i, id[i]), "{\"m\":1}", NULL), SRV_STORE_OK);
    assert_int_equal(commits_of(s), 4);   /* one synchronous commit a new id */
    /* The two oldest are in the older half: their reads ask for a refresh, and write nothing. */
    expect_entry(s, id[0], "{\"m\":1}", NULL);
    expect_entry(s, id[1], "{\"m\":1}", NULL);
    assert_int_equal(commits_of(s), 4);
    /* The next put writes them in its own commit. */
    assert_int_equal(srv_store_put(s, id_of(0x204, id[4]), "{\"m\":1}", NULL), SRV_STORE_OK);
    assert_int_equal(commits_of(s), 5);
    /* With no put, the store's thread writes a refresh within about a second, in one commit. */
    expect_entry(s, id[2], "{\"m\":1}", NULL);
    expect_entry(s, id[3], "{\"m\":1}", NULL);
    assert_int_equal(commits_of(s), 5);
    for (int i = 0; i < 40 && commits_of(s) == 5; i++)
        usleep(50000);
    assert_int_equal(commits_of(s), 6);
    srv_store_close(s);
}

/* 50 new ids put by one of eight threads at once. */
typedef struct {
    srv_store *s;
    unsigned base;
    int failed;
} putter;

static void *put_fifty(void *arg)
{
    putter *p = arg;
    char id[33], model[32];
    for (unsigned i = 0; i < 50; i++) {
        snprintf(model, sizeof model, "{\"m\":%u}", p->base + i);
        p->failed |= srv_store_put(p->s, id_of(p->base + i, id), model, NULL) != SRV_STORE_OK;
    }
    return NULL;
}

static void puts_at_once_should_share_commits_and_each_be_kept(void **state)
{
    (void)state;
    srv_store *s = open_lmdb("group", 8);
    pthread_t th[8];
    putter p[8];
    for (unsigned i = 0; i < 8; i++) {
        p[i] = (putter){ s, 0x3000 + 100 * i, 0 };
        assert_int_equal(pthread_create(&th[i], NULL, put_fifty, &p[i]), 0);
    }
    for (int i = 0; i < 8; i++) {
        pthread_join(th[i], NULL);
        assert_false(p[i].failed);
    }
    /* Each put returned after its commit; puts that waited for one went together in the next. */
    assert_true(commits_of(s) < 400);
    srv_store_close(s);
    s = open_lmdb("group", 8);
    char id[33], model[32];
    for (unsigned i = 0; i < 8; i++)
        for (unsigned j = 0; j < 50; j++) {
            snprintf(model, sizeof model, "{\"m\":%u}", p[i].base + j);
            expect_entry(s, id_of(p[i].base + j, id), model, NULL);
        }
    srv_store_stats st;
    srv_store_stats_get(s, &st);
    assert_int_equal(st.entries, 400);
    srv_store_close(s);
}

/* Writes one byte to fd, then waits for one on the other. */
static void signal_and_wait(int out, int in)
{
    char c = 1;
    if (write(out, &c, 1) != 1 || read(in, &c, 1) != 1)
        _exit(3);
}

static void two_processes_on_one_directory_should_see_each_others_puts(void **state)
{
    (void)state;
    int to_child[2], to_parent[2];
    assert_int_equal(pipe(to_child), 0);
    assert_int_equal(pipe(to_parent), 0);
    char a[33], b[33];
    id_of(0xa, a);
    id_of(0xb, b);
    pid_t pid = fork();
    if (pid == 0) {
        char spec[256], why[256], *m = NULL, *r = NULL;
        snprintf(spec, sizeof spec, "%s/shared", dir);
        srv_store *s = srv_store_open(&(srv_store_config){ .spec = spec, .max_mb = 8 }, why, sizeof why);
        if (!s || srv_store_put(s, a, "{\"from\":\"child\"}", NULL) != SRV_STORE_OK)
            _exit(1);
        signal_and_wait(to_parent[1], to_child[0]);   /* the parent puts b */
        int ok = srv_store_get(s, b, &m, &r) == SRV_STORE_OK && !strcmp(m, "{\"from\":\"parent\"}");
        free(m);
        free(r);
        srv_store_close(s);
        _exit(ok ? 0 : 2);
    }
    srv_store *s = open_lmdb("shared", 8);
    char c;
    assert_int_equal(read(to_parent[0], &c, 1), 1);
    expect_entry(s, a, "{\"from\":\"child\"}", NULL);
    assert_int_equal(srv_store_put(s, b, "{\"from\":\"parent\"}", NULL), SRV_STORE_OK);
    assert_int_equal(write(to_child[1], &c, 1), 1);
    int st;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
    srv_store_close(s);
    for (int i = 0; i < 2; i++) {
        close(to_child[i]);
        close(to_parent[i]);
    }
}

static void a_bad_spec_should_be_refused_and_none_give_no_store(void **state)
{
    (void)state;
    char why[256];
    assert_null(srv_store_open(&(srv_store_config){ .spec = "none" }, why, sizeof why));
    assert_string_equal(why, "");
    assert_null(srv_store_open(&(srv_store_config){ .spec = "redis://nohost" }, why, sizeof why));
    assert_non_null(strstr(why, "redis://HOST:PORT"));
    assert_null(srv_store_open(&(srv_store_config){ .spec = "lmdb:/proc/no/such/place" }, why, sizeof why));
    assert_non_null(strstr(why, "/proc/no/such/place"));
}

/* ---- the daemon ---- */

static char *solve(const daemon_t *d, const char *body, char id[33])
{
    http_reply r = http_request(NULL, d->base, "POST", "/solve", body, strlen(body), NULL, NULL);
    if (r.status != 200)
        fail_msg("POST /solve: %ld %s", r.status, r.body);
    cJSON *j = cJSON_Parse(r.body);
    assert_non_null(j);
    snprintf(id, 33, "%s", cJSON_GetStringValue(cJSON_GetObjectItem(j, "id")));
    cJSON_Delete(j);
    return r.body;
}

static http_reply get(const daemon_t *d, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static http_reply get(const daemon_t *d, const char *fmt, ...)
{
    char path[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(path, sizeof path, fmt, ap);
    va_end(ap);
    return http_request(NULL, d->base, "GET", path, NULL, 0, NULL, NULL);
}

static void expect_status(http_reply r, long status)
{
    if (r.status != status)
        fail_msg("status %ld, expected %ld: %s", r.status, status, r.body);
    free(r.body);
}

static void hard_kill(daemon_t *d)
{
    kill(d->pid, SIGKILL);
    int st;
    waitpid(d->pid, &st, 0);
}

static void ids_should_survive_sigkill_of_the_daemon(void **state)
{
    (void)state;
    char args[512], id[33], lid[33];
    snprintf(args, sizeof args, "--store %s/daemon-store --store-mb 16", dir);
    daemon_t d;
    daemon_start(&d, dir, args);
    const char *request = "{\"preset\":\"fig4a\",\"params\":{\"p0\":41000}}";
    char *first = solve(&d, request, id);
    char *loft = solve(&d, "{\"preset\":\"vase\"}", lid);
    hard_kill(&d);
    daemon_start(&d, dir, args);
    http_reply r = get(&d, "/solids/%s", id);
    assert_int_equal(r.status, 200);
    assert_string_equal(r.body, first);   /* re-solved from the stored model: the same document */
    free(r.body);
    r = get(&d, "/solids/%s/request", id);
    assert_int_equal(r.status, 200);
    assert_string_equal(r.body, request);
    free(r.body);
    r = get(&d, "/solids/%s", lid);
    assert_int_equal(r.status, 200);
    assert_string_equal(r.body, loft);
    free(r.body);
    expect_status(get(&d, "/solids/%032x", 12345u), 404);
    expect_status(get(&d, "/solids/%032x/request", 12345u), 404);
    daemon_stop(&d);
    free(first);
    free(loft);
}

/* ---- Redis ---- */

static int free_port(void)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = { .sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK) };
    socklen_t n = sizeof a;
    assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof a), 0);
    assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &n), 0);
    close(fd);
    return ntohs(a.sin_port);
}

static pid_t redis_start(int port)
{
    char p[16];
    snprintf(p, sizeof p, "%d", port);
    pid_t pid = fork();
    if (pid == 0) {
        child_dies_with_parent();
        execl("/usr/bin/redis-server", "redis-server", "--port", p, "--bind", "127.0.0.1", "--save", "",
              "--appendonly", "no", "--dir", dir, "--logfile", "redis.log", "--loglevel", "warning", (char *)NULL);
        _exit(127);
    }
    for (int i = 0; i < 200; i++) {
        int fd = raw_dial(port);
        if (fd >= 0) {
            close(fd);
            return pid;
        }
        usleep(25000);
    }
    fail_msg("redis-server did not start on port %d", port);
    return -1;
}

static void redis_stop(pid_t pid)
{
    kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
}

static void daemons_should_share_ids_through_redis_and_ride_out_its_outage(void **state)
{
    (void)state;
    if (access("/usr/bin/redis-server", X_OK)) {
        skip();
        return;
    }
    int port = free_port();
    pid_t redis = redis_start(port);
    char args[256], id[33], id2[33];
    snprintf(args, sizeof args, "--store redis://127.0.0.1:%d/3 --store-prefix test: --store-ttl 600", port);
    daemon_t a, b;
    daemon_start(&a, dir, args);
    daemon_start(&b, dir, args);
    char *first = solve(&a, "{\"preset\":\"fig4a\"}", id);
    http_reply r = get(&b, "/solids/%s", id);   /* b never solved it: from Redis */
    assert_int_equal(r.status, 200);
    assert_string_equal(r.body, first);
    free(r.body);
    r = get(&b, "/solids/%s/request", id);
    assert_int_equal(r.status, 200);
    assert_string_equal(r.body, "{\"preset\":\"fig4a\"}");
    free(r.body);

    redis_stop(redis);
    expect_status(get(&a, "/solids/%s", id), 200);   /* in a's memory */
    for (int i = 0; i < 3; i++) {                      /* never stalls: each answer well within a second */
        double t0 = mono_now();
        expect_status(get(&a, "/solids/%032x", 999u + i), 503);
        assert_true(mono_now() - t0 < 1.0);
    }
    r = get(&a, "/readyz");
    assert_int_equal(r.status, 200);
    assert_non_null(strstr(r.body, "degraded"));
    free(r.body);
    r = get(&a, "/metrics");
    assert_non_null(strstr(r.body, "\npdesolid_store_up 0\n"));
    free(r.body);

    redis = redis_start(port);   /* empty: no persistence in this test */
    usleep(1200000);              /* past the second between reconnections */
    char *second = solve(&a, "{\"preset\":\"fig4b\"}", id2);
    r = get(&b, "/solids/%s", id2);
    assert_int_equal(r.status, 200);
    assert_string_equal(r.body, second);
    free(r.body);
    r = get(&a, "/readyz");
    assert_string_equal(r.body, "ready\n");
    free(r.body);
    daemon_stop(&a);
    daemon_stop(&b);
    redis_stop(redis);
    free(first);
    free(second);
}

/* A Redis store on port (up or not), its puts kept within pending_kb while it is down. */
static srv_store *open_redis(int port, size_t pending_kb)
{
    char spec[64], why[256];
    snprintf(spec, sizeof spec, "redis://127.0.0.1:%d/4", port);
    srv_store *s = srv_store_open(&(srv_store_config){ .spec = spec, .prefix = "kept:", .pending_kb = pending_kb }, why,
                                  sizeof why);
    if (!s)
        fail_msg("%s: %s", spec, why);
    return s;
}

/* Waits up to 5 s for the store's kept puts to be written. */
static void wait_until_nothing_pending(srv_store *s)
{
    srv_store_stats st;
    for (int i = 0; i < 100; i++) {
        srv_store_stats_get(s, &st);
        if (!st.pending)
            return;
        usleep(50000);
    }
    fail_msg("%llu puts still pending after 5 s", st.pending);
}

static void puts_while_redis_is_down_should_be_kept_within_their_bound_and_written_when_it_returns(void **state)
{
    (void)state;
    if (access("/usr/bin/redis-server", X_OK)) {
        skip();
        return;
    }
    int port = free_port();   /* nothing listens there yet */
    srv_store *s = open_redis(port, 1);
    /* Ten puts of 200 bytes (id, model and request) while Redis is down; 1 KiB keeps the last five. */
    char id[10][33], model[10][180];
    for (unsigned i = 0; i < 10; i++) {
        snprintf(model[i], sizeof model[i], "{\"m\":%u,\"pad\":\"%0145u\"}", i, i);
        assert_int_equal(32 + strlen(model[i]) + strlen("{\"r\":1}"), 200);
        assert_int_equal(srv_store_put(s, id_of(0x1000 + i, id[i]), model[i], "{\"r\":1}"), SRV_STORE_DOWN);
    }
    srv_store_stats st;
    srv_store_stats_get(s, &st);
    assert_int_equal(st.pending, 5);
    assert_int_equal(st.dropped, 5);
    /* Meanwhile a kept put answers from memory; a dropped one cannot be answered. */
    expect_entry(s, id[9], model[9], "{\"r\":1}");
    char *m = NULL, *r = NULL;
    assert_int_equal(srv_store_get(s, id[0], &m, &r), SRV_STORE_DOWN);
    srv_sbuf b = { 0 };
    srv_store_metrics(s, &b);
    assert_non_null(strstr(b.s, "\npdesolid_store_pending 5\n"));
    assert_non_null(strstr(b.s, "\npdesolid_store_pending_dropped_total 5\n"));
    free(b.s);

    pid_t redis = redis_start(port);
    wait_until_nothing_pending(s);   /* with no call of ours: the store's thread writes them */
    srv_store_stats_get(s, &st);
    assert_int_equal(st.late, 5);
    srv_store_close(s);
    s = open_redis(port, 1);         /* nothing in memory: what Redis holds */
    for (unsigned i = 0; i < 10; i++) {
        if (i < 5)
            expect_missing(s, id[i]);
        else
            expect_entry(s, id[i], model[i], "{\"r\":1}");
    }
    srv_store_close(s);
    redis_stop(redis);
}

static void an_id_solved_while_redis_is_down_should_reach_the_other_daemons_when_it_returns(void **state)
{
    (void)state;
    if (access("/usr/bin/redis-server", X_OK)) {
        skip();
        return;
    }
    int port = free_port();
    pid_t redis = redis_start(port);
    char args[256], id[33];
    snprintf(args, sizeof args, "--store redis://127.0.0.1:%d/5", port);
    daemon_t a, b;
    daemon_start(&a, dir, args);
    daemon_start(&b, dir, args);
    redis_stop(redis);
    char *doc = solve(&a, "{\"preset\":\"fig4c\"}", id);   /* a answers; its put cannot reach Redis */
    expect_status(get(&b, "/solids/%s", id), 503);
    http_reply r = get(&a, "/metrics");
    assert_non_null(strstr(r.body, "\npdesolid_store_pending 1\n"));
    free(r.body);

    redis = redis_start(port);   /* empty: the id is only in a's memory */
    r = (http_reply){ 0 };
    for (int i = 0; i < 50; i++) {   /* a writes it within about a second of Redis's return */
        free(r.body);
        r = get(&b, "/solids/%s", id);
        if (r.status == 200)
            break;
        usleep(100000);
    }
    if (r.status != 200)
        fail_msg("b: GET /solids/%s: %ld %s", id, r.status, r.body);
    assert_string_equal(r.body, doc);
    free(r.body);
    r = get(&a, "/metrics");
    assert_non_null(strstr(r.body, "\npdesolid_store_pending 0\n"));
    assert_non_null(strstr(r.body, "\npdesolid_store_late_puts_total 1\n"));
    free(r.body);
    daemon_stop(&a);
    daemon_stop(&b);
    redis_stop(redis);
    free(doc);
}

static int setup(void **state)
{
    (void)state;
    curl_global_init(CURL_GLOBAL_ALL);
    signal(SIGPIPE, SIG_IGN);
    return tmpdir_make(dir);
}

static int teardown(void **state)
{
    (void)state;
    curl_global_cleanup();
    return tmpdir_remove(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_put_should_come_back_and_an_unknown_id_be_missing),
        cmocka_unit_test(a_put_should_survive_close_and_open),
        cmocka_unit_test(the_bound_should_evict_the_least_recently_used_first),
        cmocka_unit_test(a_get_should_never_commit_and_its_refresh_be_written_later_in_one),
        cmocka_unit_test(puts_at_once_should_share_commits_and_each_be_kept),
        cmocka_unit_test(two_processes_on_one_directory_should_see_each_others_puts),
        cmocka_unit_test(a_bad_spec_should_be_refused_and_none_give_no_store),
        cmocka_unit_test(ids_should_survive_sigkill_of_the_daemon),
        cmocka_unit_test(daemons_should_share_ids_through_redis_and_ride_out_its_outage),
        cmocka_unit_test(puts_while_redis_is_down_should_be_kept_within_their_bound_and_written_when_it_returns),
        cmocka_unit_test(an_id_solved_while_redis_is_down_should_reach_the_other_daemons_when_it_returns),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("store", tests, setup, teardown);
}
