/*
 * test_cluster.c: the cluster of `make cluster` (deploy/cluster.sh): Redis,
 * three sanitised replicas ($PDESOLIDD_SAN, as the other tests' daemons) and
 * nginx with deploy/nginx.conf, started once for all the cases in a directory
 * and on ports of the test's own (CLUSTER_DIR, CLUSTER_PORT), so that it
 * meets neither a developer's cluster nor another test. The cases run in
 * order on the same cluster:
 *  - a solve through nginx is found on every replica directly;
 *  - one replica SIGKILLed in the middle of 2,000 requests through nginx
 *    costs none of them, and `make cluster` brings it back, also while the
 *    killed process is still a zombie (the test is the cluster's subreaper);
 *  - with Redis stopped, the replicas answer the ids they hold and say
 *    "degraded" on /readyz; with Redis started again, they recover;
 *  - after `make cluster-stop` and `make cluster`, every id resolves.
 * A case run alone (make check T=test_cluster F=...) makes the first case's
 * id itself. The group's teardown runs `make cluster-stop` whatever happened (and so
 * does SIGINT or SIGTERM), then fails the run if a replica's log holds a
 * sanitiser's report. Skipped when nginx or redis-server is absent
 * (.ci/deps installs both).
 */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <pthread.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>
#include <cmocka.h>
#include <curl/curl.h>

#include "support.h"

#define REPLICAS 3
#define LOAD 2000           /* requests through nginx while a replica is killed */
#define LOAD_THREADS 8
#define KILL_AT 600         /* the request at which the replica dies */
#define VICTIM 2            /* pdesolidd-2 */

static char dir[] = "/tmp/pdesolid-cluster-XXXXXX";
static int absent;                  /* nginx or redis-server is not installed */
static int port;                    /* nginx; Redis on port + 1, replica k on port + 1 + k */
static char front[64], replica[REPLICAS + 1][64];
static char make_env[512];          /* the make command's variables */
static char *stop_argv[8];          /* `make cluster-stop ...`, ready for a signal handler */

/* Every id solved so far, and what GET /solids/ID answered for the first. */
static char ids[LOAD + 16][33];
static atomic_int nids;
static char *first_doc, first_id[33];

static void add_id(const char *id)
{
    int i = atomic_fetch_add(&nids, 1);
    snprintf(ids[i], sizeof ids[i], "%s", id);
}

/* ---- the cluster through make ---- */

/* `make TARGET` with the cluster's variables, its output in dir/make.log: make's exit status. */
static int make(const char *target)
{
    char cmd[1024];
    /* Not make's jobserver of a surrounding `make test`: this make is no part of it. */
    snprintf(cmd, sizeof cmd, "exec env -u MAKEFLAGS -u MFLAGS make -s --no-print-directory %s %s >>%s/make.log 2>&1",
             target, make_env, dir);
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void print_file(const char *path)
{
    char *text = read_file(path, NULL);
    print_message("---- %s\n%s\n", path, text ? text : "(absent)");
    free(text);
}

static void make_or_fail(const char *target)
{
    if (make(target) != 0) {
        char path[128];
        snprintf(path, sizeof path, "%s/make.log", dir);
        print_file(path);
        for (int k = 1; k <= REPLICAS; k++) {
            snprintf(path, sizeof path, "%s/pdesolidd-%d.log", dir, k);
            print_file(path);
        }
        fail_msg("make %s failed", target);
    }
}

/* Stops the cluster on SIGINT, SIGTERM and SIGHUP too (fork and exec are async-signal-safe). */
static void stop_on_signal(int sig)
{
    pid_t pid = fork();
    if (pid == 0) {
        execvp(stop_argv[0], stop_argv);
        _exit(127);
    }
    if (pid > 0)
        waitpid(pid, NULL, 0);
    signal(sig, SIG_DFL);
    raise(sig);
}

/* 1 when all of port .. port + n - 1 on loopback are free now. */
static int ports_free(int p, int n)
{
    for (int i = 0; i < n; i++) {
        int fd = socket(AF_INET, SOCK_STREAM, 0);
        struct sockaddr_in a = { .sin_family = AF_INET, .sin_port = htons((uint16_t)(p + i)),
                                 .sin_addr.s_addr = htonl(INADDR_LOOPBACK) };
        int ok = bind(fd, (struct sockaddr *)&a, sizeof a) == 0;
        close(fd);
        if (!ok)
            return 0;
    }
    return 1;
}

/* n consecutive free ports below the kernel's ephemeral range (32768 on Linux), where no other test's
 * port 0 lands: the cluster's ports are fixed offsets from CLUSTER_PORT. */
static int pick_ports(int n)
{
    srand((unsigned)getpid() ^ (unsigned)time(NULL));
    for (int attempt = 0; attempt < 100; attempt++) {
        int p = 20000 + rand() % 12000;
        if (ports_free(p, n))
            return p;
    }
    return 0;
}

/* ---- HTTP ---- */

static http_reply get(const char *base, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static http_reply get(const char *base, const char *fmt, ...)
{
    char path[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(path, sizeof path, fmt, ap);
    va_end(ap);
    return http_request(NULL, base, "GET", path, NULL, 0, NULL, NULL);
}

static void expect_status(http_reply r, long status, const char *what)
{
    if (r.status != status)
        fail_msg("%s: status %ld, expected %ld: %s", what, r.status, status, r.body);
    free(r.body);
}

/* POST /solve of body to base: its document, and its id in id. */
static char *solve(const char *base, const char *body, char id[33])
{
    http_reply r = http_request(NULL, base, "POST", "/solve", body, strlen(body), NULL, NULL);
    if (r.status != 200)
        fail_msg("POST /solve %s: %ld %s", body, r.status, r.body);
    cJSON *j = cJSON_Parse(r.body);
    assert_non_null(j);
    snprintf(id, 33, "%s", cJSON_GetStringValue(cJSON_GetObjectItem(j, "id")));
    cJSON_Delete(j);
    return r.body;
}

/* GET /solids/ID from base answers 200 with doc (when doc is not NULL); when says what was going on. */
static void expect_doc(const char *base, const char *id, const char *doc, const char *when)
{
    http_reply r = get(base, "/solids/%s", id);
    if (r.status != 200)
        fail_msg("%s, %s: GET /solids/%s: %ld %s", base, when, id, r.status, r.body);
    if (doc)
        assert_string_equal(r.body, doc);
    free(r.body);
}

/* The pid in dir/name.pid, or 0. */
static int pid_of(const char *name)
{
    char path[128];
    snprintf(path, sizeof path, "%s/%s.pid", dir, name);
    char *text = read_file(path, NULL);
    int pid = text ? atoi(text) : 0;
    free(text);
    return pid;
}

/* 1 when pid is a zombie: dead, not yet reaped. */
static int zombie(int pid)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/%d/stat", pid);
    char *text = read_file(path, NULL);
    const char *end = text ? strrchr(text, ')') : NULL;
    int z = end && end[1] == ' ' && end[2] == 'Z';
    free(text);
    return z;
}

/* Reaps the cluster's processes that have ended (this process is their subreaper). */
static void reap(void)
{
    while (waitpid(-1, NULL, WNOHANG) > 0)
        ;
}

/* Waits up to seconds for GET /readyz on base to answer 200 with a body starting with want. */
static void wait_readyz(const char *base, const char *want, double seconds)
{
    double end = mono_now() + seconds;
    for (;;) {
        http_reply r = get(base, "/readyz");
        int ok = r.status == 200 && !strncmp(r.body, want, strlen(want));
        if (ok || mono_now() > end) {
            if (!ok)
                fail_msg("%s/readyz: %ld %s after %.0f s; expected 200 \"%s...\"", base, r.status, r.body, seconds,
                         want);
            free(r.body);
            return;
        }
        free(r.body);
        usleep(100000);
    }
}

static void need_cluster(void)
{
    if (absent) {
        print_message("skipped: /usr/sbin/nginx or /usr/bin/redis-server is not installed (make deps)\n");
        skip();
    }
}

/* ---- the cases ---- */

/* The first case: a solve through nginx, then its id from every replica (which then holds it). The
 * other cases use that id, and make it themselves when run alone (make check F=...). */
static void solve_first(void)
{
    const char *request = "{\"preset\":\"fig4a\",\"params\":{\"p0\":41000}}";
    first_doc = solve(front, request, first_id);
    add_id(first_id);
    for (int k = 1; k <= REPLICAS; k++) {
        expect_doc(replica[k], first_id, first_doc, "solved through nginx");
        http_reply r = get(replica[k], "/solids/%s/request", first_id);
        assert_int_equal(r.status, 200);
        assert_string_equal(r.body, request);
        free(r.body);
    }
}

static void a_solve_through_nginx_should_be_found_on_every_replica(void **state)
{
    (void)state;
    need_cluster();
    solve_first();
}

typedef struct {
    atomic_int next, failed, victim;
    char first_failure[512];
    pthread_mutex_t lock;
} load_state;

typedef struct {
    load_state *L;
} load_arg;

/*
 * Requests through nginx until LOAD have been sent: a new solve (p0 differs each time), an eval of the
 * first id, or a GET of an id solved a moment before (a miss of nginx's cache, by the query). Solves and
 * GETs ask for f32 at a few points: the json's properties take 0.2 s a solid, the solve 0.1 ms. The
 * thread that sends request KILL_AT SIGKILLs the victim first.
 */
static void *load(void *arg)
{
    load_state *L = ((load_arg *)arg)->L;
    CURL *c = curl_easy_init();
    char body[160], path[160], id[33] = "";
    for (int i; (i = atomic_fetch_add(&L->next, 1)) < LOAD;) {
        if (i == KILL_AT)
            kill(atomic_load(&L->victim), SIGKILL);
        http_reply r;
        if (i % 3 == 0 || !id[0]) {
            snprintf(body, sizeof body, "{\"preset\":\"fig4a\",\"params\":{\"p0\":%d}}", 30000 + i);
            r = http_request(c, front, "POST", "/solve?format=f32&res=2", body, strlen(body), NULL, NULL);
            if (r.status == 200 && http_header(r.headers, "X-Solid-Id", id, sizeof id))
                add_id(id);
        } else if (i % 3 == 1) {
            snprintf(path, sizeof path, "/solids/%s/eval", first_id);
            snprintf(body, sizeof body, "{\"points\":[[0.5,0.25,%.4f]]}", (i % 1000) / 1000.0);
            r = http_request(c, front, "POST", path, body, strlen(body), NULL, NULL);
        } else {
            snprintf(path, sizeof path, "/solids/%s?format=f32&res=%d", id, 2 + i % 7);
            r = http_request(c, front, "GET", path, NULL, 0, NULL, NULL);
        }
        if (r.status != 200 && atomic_fetch_add(&L->failed, 1) == 0) {
            pthread_mutex_lock(&L->lock);
            snprintf(L->first_failure, sizeof L->first_failure, "request %d: %ld %.400s", i, r.status, r.body);
            pthread_mutex_unlock(&L->lock);
        }
        free(r.body);
    }
    curl_easy_cleanup(c);
    return NULL;
}

static void a_replica_killed_under_load_should_cost_no_request(void **state)
{
    (void)state;
    need_cluster();
    if (!first_doc)
        solve_first();
    char name[32];
    snprintf(name, sizeof name, "pdesolidd-%d", VICTIM);
    int victim = pid_of(name);
    assert_true(victim > 0);
    load_state L = { .lock = PTHREAD_MUTEX_INITIALIZER };
    atomic_init(&L.next, 0);
    atomic_init(&L.failed, 0);
    atomic_init(&L.victim, victim);
    pthread_t t[LOAD_THREADS];
    load_arg args[LOAD_THREADS];
    for (int i = 0; i < LOAD_THREADS; i++)
        args[i].L = &L;
    double t0 = mono_now();
    threads_start(t, LOAD_THREADS, load, args, sizeof *args);
    threads_join(t, LOAD_THREADS);
    print_message("%d requests through nginx in %.1f s, pdesolidd-%d SIGKILLed at request %d\n", LOAD,
                  mono_now() - t0, VICTIM, KILL_AT);
    if (atomic_load(&L.failed))
        fail_msg("%d of %d requests failed; the first: %s", atomic_load(&L.failed), LOAD, L.first_failure);
    /* The kill was felt: nginx logged the victim's refused or cut connections, and went on to the next. */
    char path[128], victim_addr[32];
    snprintf(path, sizeof path, "%s/nginx/error.log", dir);
    snprintf(victim_addr, sizeof victim_addr, "127.0.0.1:%d", port + 1 + VICTIM);
    char *errors = read_file(path, NULL);
    int felt = 0;
    for (const char *at = errors; at && (at = strstr(at, victim_addr)); at++)
        felt++;
    print_message("nginx's error log names pdesolidd-%d %d times\n", VICTIM, felt);
    if (!felt)
        print_file(path);
    free(errors);
    assert_true(felt);

    /* `make cluster` again brings back only the dead replica, which serves at once and stays up. */
    int others[REPLICAS + 1];
    for (int k = 1; k <= REPLICAS; k++) {
        snprintf(name, sizeof name, "pdesolidd-%d", k);
        others[k] = pid_of(name);
    }
    make_or_fail("cluster");
    for (int k = 1; k <= REPLICAS; k++) {
        snprintf(name, sizeof name, "pdesolidd-%d", k);
        if (k == VICTIM)
            assert_int_not_equal(pid_of(name), victim);
        else
            assert_int_equal(pid_of(name), others[k]);
    }
    snprintf(name, sizeof name, "pdesolidd-%d", VICTIM);
    int back = pid_of(name);
    for (int i = 0; i < 10; i++) {
        expect_doc(replica[VICTIM], first_id, first_doc, "restarted");
        usleep(100000);
    }
    assert_int_equal(kill(back, 0), 0);
    assert_int_equal(pid_of(name), back);

    /* Killed and restarted while the killed process is a zombie: this process is the cluster's
     * subreaper (setup) and does not reap it yet, as a slow init would not. cluster.sh once took a
     * zombie for a live replica (kill -0 succeeds on one) and left it dead. */
    snprintf(name, sizeof name, "pdesolidd-%d", REPLICAS);
    int last = pid_of(name);
    assert_int_equal(kill(last, SIGKILL), 0);
    for (int i = 0; i < 100 && !zombie(last); i++)
        usleep(20000);
    assert_true(zombie(last));
    make_or_fail("cluster");
    assert_int_not_equal(pid_of(name), last);
    expect_doc(replica[REPLICAS], first_id, first_doc, "killed and restarted, its zombie still there");
    reap();
}

static void replicas_should_serve_what_they_hold_while_redis_is_down_and_recover(void **state)
{
    (void)state;
    need_cluster();
    if (!first_doc)
        solve_first();
    char id[33], late[33];
    char *doc = solve(front, "{\"preset\":\"fig4b\"}", id);   /* in Redis, and in one replica's memory */
    add_id(id);
    for (int k = 1; k <= REPLICAS; k++)
        wait_readyz(replica[k], "ready\n", 5);

    int redis = pid_of("redis");
    assert_true(redis > 0);
    assert_int_equal(kill(redis, SIGTERM), 0);
    for (int i = 0; i < 100 && kill(redis, 0) == 0; i++) {
        int fd = raw_dial(port + 1);
        if (fd < 0)
            break;
        close(fd);
        usleep(50000);
    }
    int fd = raw_dial(port + 1);
    if (fd >= 0)
        close(fd);
    assert_true(fd < 0);

    for (int k = 1; k <= REPLICAS; k++) {
        /* Every replica fetched the first id in the first case: it answers from memory. */
        expect_doc(replica[k], first_id, first_doc, "Redis down, the id in memory");
        wait_readyz(replica[k], "degraded", 5);
        /* An id nobody solved: the store cannot say, so 503 (not 404), and at once. */
        double t0 = mono_now();
        expect_status(get(replica[k], "/solids/%032x", 0xdeadu + (unsigned)k), 503, "an unknown id, Redis down");
        assert_true(mono_now() - t0 < 1.0);
    }
    wait_readyz(front, "degraded", 5);
    /* New solves are still served (but not kept: nothing retries the put). */
    free(solve(front, "{\"preset\":\"fig4c\"}", late));

    make_or_fail("cluster");   /* starts Redis again, from its AOF */
    for (int k = 1; k <= REPLICAS; k++)
        wait_readyz(replica[k], "ready\n", 5);
    /* Two replicas of three never held this id: they find it in Redis again. */
    for (int k = 1; k <= REPLICAS; k++)
        expect_doc(replica[k], id, doc, "Redis back");
    assert_int_equal(pid_of("redis") != redis, 1);
    free(doc);
}

static void every_id_should_resolve_after_cluster_stop_and_start(void **state)
{
    (void)state;
    need_cluster();
    if (!first_doc)
        solve_first();
    make_or_fail("cluster-stop");
    for (int i = 0; i <= REPLICAS + 1; i++) {
        int fd = raw_dial(port + i);
        if (fd >= 0)
            close(fd);
        assert_true(fd < 0);
    }
    make_or_fail("cluster");
    int n = atomic_load(&nids);
    assert_true(n >= 1);   /* the load's solves and the cases' (only the first when run alone) */
    /* The replicas start empty: each id comes from Redis's AOF. The first on every replica, the others
     * spread over them (as f32: a re-solve without the properties), and every tenth through nginx too. */
    for (int k = 1; k <= REPLICAS; k++)
        expect_doc(replica[k], first_id, first_doc, "after make cluster-stop and make cluster");
    CURL *c = curl_easy_init();
    for (int i = 0; i < n; i++) {
        char path[80];
        snprintf(path, sizeof path, "/solids/%s?format=f32&res=2", ids[i]);
        http_reply r = http_request(c, replica[1 + i % REPLICAS], "GET", path, NULL, 0, NULL, NULL);
        if (r.status != 200)
            fail_msg("id %d of %d, %s, on pdesolidd-%d after a restart: %ld %s", i, n, ids[i], 1 + i % REPLICAS,
                     r.status, r.body);
        free(r.body);
        if (i % 10 == 0)
            expect_status(http_request(c, front, "GET", path, NULL, 0, NULL, NULL), 200, "through nginx");
    }
    curl_easy_cleanup(c);
    print_message("%d ids resolved after make cluster-stop and make cluster\n", n);
}

/* ---- the group ---- */

static int teardown(void **state);

static int setup(void **state)
{
    (void)state;
    curl_global_init(CURL_GLOBAL_ALL);
    signal(SIGPIPE, SIG_IGN);
    if (tmpdir_make(dir))
        return -1;
    if (access("/usr/sbin/nginx", X_OK) || access("/usr/bin/redis-server", X_OK)) {
        absent = 1;
        return 0;
    }
    port = pick_ports(REPLICAS + 2);
    if (!port) {
        print_error("no %d consecutive free ports below 32768\n", REPLICAS + 2);
        return -1;
    }
    const char *daemon = getenv("PDESOLIDD_SAN") ? getenv("PDESOLIDD_SAN") : "build/san/pdesolidd";
    snprintf(make_env, sizeof make_env, "CLUSTER_PORT=%d CLUSTER_DIR=%s CLUSTER_DAEMON=%s", port, dir, daemon);
    static char a_port[32], a_dir[80], a_daemon[256];
    snprintf(a_port, sizeof a_port, "CLUSTER_PORT=%d", port);
    snprintf(a_dir, sizeof a_dir, "CLUSTER_DIR=%s", dir);
    snprintf(a_daemon, sizeof a_daemon, "CLUSTER_DAEMON=%s", daemon);
    char *argv[] = { "make", "-s", "cluster-stop", a_port, a_dir, a_daemon, NULL };
    memcpy(stop_argv, argv, sizeof argv);
    signal(SIGINT, stop_on_signal);
    signal(SIGTERM, stop_on_signal);
    signal(SIGHUP, stop_on_signal);
    /* The cluster's processes outlive the make that starts them: as their subreaper, this process
     * inherits them instead of init, and reaps them when it chooses (the zombie case above). */
    if (prctl(PR_SET_CHILD_SUBREAPER, 1) != 0) {
        print_error("prctl(PR_SET_CHILD_SUBREAPER) failed\n");
        return -1;
    }
    snprintf(front, sizeof front, "http://127.0.0.1:%d", port);
    for (int k = 1; k <= REPLICAS; k++)
        snprintf(replica[k], sizeof replica[k], "http://127.0.0.1:%d", port + 1 + k);
    double t0 = mono_now();
    if (make("cluster") != 0) {
        char path[128];
        snprintf(path, sizeof path, "%s/make.log", dir);
        print_file(path);
        teardown(state);
        return -1;
    }
    print_message("make cluster %s: %.1f s\n", make_env, mono_now() - t0);
    return 0;
}

/* 1 when the file holds a sanitiser's report. */
static int sanitiser_report(const char *path)
{
    char *text = read_file(path, NULL);
    int found = text && (strstr(text, "Sanitizer") || strstr(text, "runtime error:"));
    if (found)
        print_error("---- %s\n%s\n", path, text);
    free(text);
    return found;
}

static int teardown(void **state)
{
    (void)state;
    static int done;
    if (done++)
        return 0;
    int rc = 0;
    if (!absent && port) {
        if (make("cluster-stop") != 0)
            rc = -1;
        reap();
        for (int k = 1; k <= REPLICAS; k++) {
            char path[128];
            snprintf(path, sizeof path, "%s/pdesolidd-%d.log", dir, k);
            if (sanitiser_report(path))
                rc = -1;
        }
    }
    free(first_doc);
    first_doc = NULL;
    curl_global_cleanup();
    if (rc == 0)
        tmpdir_remove(dir);
    else
        print_error("the cluster's logs are kept in %s\n", dir);
    return rc;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_solve_through_nginx_should_be_found_on_every_replica),
        cmocka_unit_test(a_replica_killed_under_load_should_cost_no_request),
        cmocka_unit_test(replicas_should_serve_what_they_hold_while_redis_is_down_and_recover),
        cmocka_unit_test(every_id_should_resolve_after_cluster_stop_and_start),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("cluster", tests, setup, teardown);
}
