/*
 * test_hostile.c: pdesolidd as a hostile client meets it, over raw sockets on
 * loopback (issue 8). Each test starts the sanitised daemon ($PDESOLIDD_SAN)
 * and stops it with SIGTERM, which must end in exit status 0. Every wait is
 * bounded by poll() timeouts: no test waits more than about 10 s, but for a heavy stream to end.
 *
 * These tests pin the behaviour the daemon must reach: the slow-body deadline,
 * a per-address limit that does not lock an address out, a 413 that clients
 * can read, bounded shutdown, budgets, strict input, a response cache keyed
 * by the whole request, an access log that cannot be forged, request ids,
 * honest Server-Timing, CORS refused before work, and a Host header that
 * names neither this machine nor a name allowed (DNS rebinding) refused.
 */
#define _GNU_SOURCE   /* strcasestr */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>
#include <cmocka.h>

#include "support.h"

static char dir[] = "/tmp/pdesolid-hostile-XXXXXX";

/* The daemon a test runs, so that a failed test does not leave it running. */
static daemon_t slot;
static int live;

static void start(daemon_t *d, const char *args)
{
    memset(&slot, 0, sizeof slot);
    live = 1;
    daemon_start(&slot, dir, args);
    *d = slot;
}

static void stop(daemon_t *d)
{
    live = 0;
    daemon_stop(d);
}

static int kill_leftover(void **state)
{
    (void)state;
    if (live && slot.pid > 0 && waitpid(slot.pid, NULL, WNOHANG) == 0) {
        kill(slot.pid, SIGKILL);
        waitpid(slot.pid, NULL, 0);
    }
    live = 0;
    return 0;
}

/* ---- helpers ---- */

/* A request to host (the Host header's value) with Connection: close, extra headers (each ending in CRLF) and a
 * body or NULL. */
static raw_reply ask_host(const daemon_t *d, const char *host, const char *method, const char *target,
                          const char *headers, const char *body, size_t blen, int timeout_ms)
{
    size_t cap = strlen(host) + strlen(target) + (headers ? strlen(headers) : 0) + blen + 256;
    char *req = malloc(cap);
    int n = snprintf(req, cap, "%s %s HTTP/1.1\r\nHost: %s\r\nConnection: close\r\n%s", method, target, host,
                     headers ? headers : "");
    if (body)
        n += snprintf(req + n, cap - (size_t)n, "Content-Length: %zu\r\n", blen);
    n += snprintf(req + n, cap - (size_t)n, "\r\n");
    if (body) {
        memcpy(req + n, body, blen);
        n += (int)blen;
    }
    raw_reply r = raw_request(d->port, req, (size_t)n, timeout_ms);
    free(req);
    return r;
}

static raw_reply ask(const daemon_t *d, const char *method, const char *target, const char *headers, const char *body,
                     size_t blen, int timeout_ms)
{
    return ask_host(d, "127.0.0.1", method, target, headers, body, blen, timeout_ms);
}

static raw_reply get(const daemon_t *d, const char *target)
{
    return ask(d, "GET", target, NULL, NULL, 0, 5000);
}

static raw_reply post(const daemon_t *d, const char *target, const char *body)
{
    return ask(d, "POST", target, NULL, body, strlen(body), 8000);
}

/* s with bytes outside printable ASCII as \xHH, for messages; two calls may share a message (slot 0, 1). */
static const char *shown(const char *s, int which)
{
    static char outs[2][600];
    char *out = outs[which];
    size_t n = 0, cap = sizeof outs[0];
    for (; *s && n + 5 < cap; s++) {
        unsigned char c = (unsigned char)*s;
        n += (size_t)(c >= 0x20 && c < 0x7f ? snprintf(out + n, cap - n, "%c", c)
                                              : snprintf(out + n, cap - n, "\\x%02x", c));
    }
    out[n] = '\0';
    return out;
}

/* A request id is 1-64 characters of [A-Za-z0-9._:-]. */
static int sane_id(const char *s)
{
    size_t n = strlen(s);
    return n >= 1 && n <= 64 && strspn(s, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._:-") == n;
}

#define ANY_POINTER "*"

/*
 * The problem contract: status, problem+json, a strict JSON body with type,
 * title, status, detail and request_id (equal to X-Request-Id); pointer as
 * given, absent when pointer is NULL, either with ANY_POINTER. words, if not NULL, is in the detail.
 */
static void expect_problem(const raw_reply *r, int status, const char *pointer, const char *words)
{
    if (r->status != status)
        fail_msg("status %d, expected %d (closed %d, timed out %d): %s", r->status, status, r->closed, r->timed_out,
                 r->body);
    if (r->responses != 1)
        fail_msg("%d responses on one request", r->responses);
    char ct[128], rid[128];
    assert_true(raw_header(r, "Content-Type", ct, sizeof ct));
    assert_string_equal(ct, "application/problem+json");
    if (!json_strict_valid(r->body, r->body_len))
        fail_msg("the problem is not strict JSON: %s", r->body);
    cJSON *p = cJSON_Parse(r->body);
    assert_non_null(p);
    cJSON *type = cJSON_GetObjectItem(p, "type"), *title = cJSON_GetObjectItem(p, "title"),
          *st = cJSON_GetObjectItem(p, "status"), *detail = cJSON_GetObjectItem(p, "detail"),
          *id = cJSON_GetObjectItem(p, "request_id");
    assert_true(cJSON_IsString(type) && !strcmp(type->valuestring, "about:blank"));
    assert_true(cJSON_IsString(title));
    assert_true(cJSON_IsNumber(st));
    assert_int_equal(st->valueint, status);
    assert_true(cJSON_IsString(detail));
    if (!cJSON_IsString(id))
        fail_msg("no request_id in %s", r->body);
    if (!raw_header(r, "X-Request-Id", rid, sizeof rid))
        fail_msg("no X-Request-Id header");
    assert_string_equal(id->valuestring, rid);
    if (words && !strstr(detail->valuestring, words))
        fail_msg("detail \"%s\" lacks \"%s\"", detail->valuestring, words);
    /* ANY_POINTER: a syntax error may point at the value that holds it, or at nothing */
    if (!pointer || strcmp(pointer, ANY_POINTER))
        expect_problem_pointer(p, pointer, r->body);
    cJSON_Delete(p);
}

static void expect_livez(const daemon_t *d)
{
    raw_reply r = get(d, "/livez");
    if (r.status != 200)
        fail_msg("/livez: status %d", r.status);
    raw_reply_free(&r);
}

/* A metric's value, or -1 if /metrics does not answer or lacks it (never fails the test). */
static long metric_or_none(const daemon_t *d, const char *name)
{
    raw_reply r = get(d, "/metrics");
    char key[128];
    snprintf(key, sizeof key, "\n%s ", name);
    const char *p = r.status == 200 ? strstr(r.body, key) : NULL;
    long v = p ? atol(p + strlen(key)) : -1;
    raw_reply_free(&r);
    return v;
}

static long metric(const daemon_t *d, const char *name)
{
    raw_reply r = get(d, "/metrics");
    assert_int_equal(r.status, 200);
    char key[128];
    snprintf(key, sizeof key, "\n%s ", name);
    const char *p = strstr(r.body, key);
    long v = p ? atol(p + strlen(key)) : -1;
    raw_reply_free(&r);
    return v;
}

/* The id of a solved preset, from X-Solid-Id. */
static void solve_id(const daemon_t *d, const char *preset, char *id, size_t n)
{
    char body[64];
    snprintf(body, sizeof body, "{\"preset\":\"%s\"}", preset);
    raw_reply r = post(d, "/solve?format=f32&res=2", body);
    assert_int_equal(r.status, 200);
    assert_true(raw_header(&r, "X-Solid-Id", id, n));
    raw_reply_free(&r);
}

/*
 * fig4a's boundary with `terms` force terms per component, each its own (u, v)
 * mode cos(a pi u) cos(b pi v) sin(pi w): a valid solid, costly to solve and
 * mesh (512 terms: glb at res 512 takes about 23 s without sanitisers).
 * seed makes it a new solid.
 */
static char *heavy_model(int terms, int seed)
{
    size_t cap = (size_t)terms * 3 * 96 + 512;
    char *b = malloc(cap);
    int n = snprintf(b, cap, "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-9.5,-9.5,-10]},\"boundary\":{"
                             "\"x\":[{\"u\":{\"pow\":1},\"v\":{\"sin\":2},\"w0\":0.5,\"w1\":0.5}],"
                             "\"y\":[{\"u\":{\"pow\":1},\"v\":{\"cos\":2},\"w0\":0.5,\"w1\":0.5}],"
                             "\"z\":[{\"w1\":3}]},\"force\":{");
    for (int c = 0; c < 3; c++) {
        n += snprintf(b + n, cap - (size_t)n, "%s\"%c\":[", c ? "," : "", "xyz"[c]);
        for (int k = 0; k < terms; k++)
            n += snprintf(b + n, cap - (size_t)n, "%s{\"coef\":%d,\"u\":{\"cos\":%d},\"v\":{\"cos\":%d},\"w\":{\"sin\":1}}",
                          k ? "," : "", 10 + seed, 1 + k % 64, 1 + k / 64);
        n += snprintf(b + n, cap - (size_t)n, "]");
    }
    snprintf(b + n, cap - (size_t)n, "}}");
    return b;
}

/* n force terms per component, each a (u, v) mode of its own, cos(k pi u) cos(pi v) sin(pi w), so that
 * no two share a u-factor and a sampled point costs n multiply-adds per component. */
static char *distinct_modes_model(int n)
{
    size_t cap = (size_t)n * 3 * 80 + 256;
    char *b = malloc(cap);
    int k = snprintf(b, cap, "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-9.5,-9.5,-10]},\"force\":{");
    for (int c = 0; c < 3; c++) {
        k += snprintf(b + k, cap - (size_t)k, "%s\"%c\":[", c ? "," : "", "xyz"[c]);
        for (int i = 0; i < n; i++)
            k += snprintf(b + k, cap - (size_t)k, "%s{\"coef\":%d,\"u\":{\"cos\":%d},\"v\":{\"cos\":1},\"w\":{\"sin\":1}}",
                          i ? "," : "", 10 + c, i + 1);
        k += snprintf(b + k, cap - (size_t)k, "]");
    }
    snprintf(b + k, cap - (size_t)k, "}}");
    return b;
}

/* Sends everything with a deadline; 0 if all went out, -1 on an error or the deadline. */
static int send_all(int fd, const char *p, size_t len, double seconds)
{
    double end = mono_now() + seconds;
    size_t sent = 0;
    while (sent < len) {
        double left = end - mono_now();
        if (left <= 0)
            return -1;
        struct pollfd pf = { fd, POLLOUT, 0 };
        if (poll(&pf, 1, (int)(left * 1000) + 1) <= 0)
            continue;
        ssize_t k = send(fd, p + sent, len - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (k < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
            continue;
        if (k <= 0)
            return -1;
        sent += (size_t)k;
    }
    return 0;
}

/* 1 if the peer has closed fd (or said something, which *said is set to), polling up to ms. */
static int peer_done(int fd, int ms, int *said)
{
    struct pollfd pf = { fd, POLLIN, 0 };
    if (poll(&pf, 1, ms) <= 0)
        return 0;
    char buf[4096];
    ssize_t k = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
    if (k > 0) {
        if (said)
            *said = 1;
        return 1;
    }
    return k == 0 || (errno != EAGAIN && errno != EWOULDBLOCK);
}

static int setup(void **state)
{
    (void)state;
    signal(SIGPIPE, SIG_IGN);
    srand((unsigned)time(NULL) ^ (unsigned)getpid());
    return tmpdir_make(dir);
}

static int teardown(void **state)
{
    (void)state;
    return tmpdir_remove(dir);
}

/* ---- the polling thread only copies ---- */

typedef struct {
    const daemon_t *d;
    const char *body;
    long long bytes;
    int status;
    volatile int done;
} stream_arg;

/* The stream takes some 11 s under ASan, and 100 s under TSan (make tsan) on a loaded 2-core machine: the client
 * waits up to 240 s for it to end. */
static void *stream_client(void *arg)
{
    stream_arg *a = arg;
    raw_reply r = ask(a->d, "POST", "/solve?format=f32&res=64,64,16", NULL, a->body, strlen(a->body), 240000);
    a->status = r.status;
    a->bytes = (long long)r.body_len;
    raw_reply_free(&r);
    __atomic_store_n(&a->done, 1, __ATOMIC_SEQ_CST);
    return NULL;
}

/*
 * Finding 1: grid bodies were made in libmicrohttpd's content reader, on the
 * polling thread, so one client's stream stalled every other request. With a
 * single polling thread (--http-threads 1) and a stream of 64x64x16 points
 * of a solid of 4000 distinct modes per component being made and read (each
 * 128 KiB of it is some 10^8 multiply-adds), /livez must never stall (the
 * benchmark measures its p99 against the 10 ms goal).
 */
static void livez_should_answer_while_the_only_polling_thread_sends_a_heavy_stream(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--http-threads 1 --threads 1 --max-work 1e13 --max-mem-mb 1024 --job-timeout 120");
    char *body = distinct_modes_model(4000);
    stream_arg a = { &d, body, 0, 0, 0 };
    pthread_t t;
    pthread_create(&t, NULL, stream_client, &a);
    double took[512];
    int asked = 0;
    /* Once the stream's connection is open (this request's own is the other), and while it runs. */
    for (int i = 0; i < 200 && metric(&d, "pdesolid_connections") < 2; i++)
        usleep(10000);
    for (double end = mono_now() + 60; mono_now() < end && !__atomic_load_n(&a.done, __ATOMIC_SEQ_CST) && asked < 512;
         asked++) {
        raw_reply r = ask(&d, "GET", "/livez", NULL, NULL, 0, 3000);
        assert_int_equal(r.status, 200);
        took[asked] = r.seconds;
        raw_reply_free(&r);
        usleep(50000);
    }
    pthread_join(t, NULL);
    free(body);
    assert_int_equal(a.status, 200);
    assert_int_equal(a.bytes, 64LL * 64 * 16 * 12);
    if (asked < 5)
        fail_msg("the stream ended before /livez was asked 5 times (%d): make it heavier", asked);
    qsort(took, (size_t)asked, sizeof *took, ref_cmp_double);
    print_message("  /livez asked %d times during the stream: median %.1f ms, slowest %.1f ms\n", asked,
                  took[asked / 2] * 1e3, took[asked - 1] * 1e3);
    /* A stall, not a latency goal (bench/bench_livez.sh measures p99 <= 10 ms): the finding's polling
     * thread stalled /livez for 16 s; refills made on it here stall it about a second each. */
    if (took[asked - 1] > 2.0)
        fail_msg("/livez took %.2f s while a stream was sent", took[asked - 1]);
    stop(&d);
}

/* ---- connections ---- */

static void a_body_sent_one_byte_each_half_second_should_be_cut_off_at_the_request_timeout(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--request-timeout 2");
    int fd = raw_dial(d.port);
    assert_true(fd >= 0);
    const char *head = "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: 100\r\n\r\n";
    double t0 = mono_now();
    assert_int_equal(send_all(fd, head, strlen(head), 1), 0);
    int cut = 0;
    while (!cut && mono_now() - t0 < 6) {
        if (send(fd, " ", 1, MSG_NOSIGNAL | MSG_DONTWAIT) < 0 && errno != EAGAIN)
            cut = 1;
        else
            cut = peer_done(fd, 500, NULL);
    }
    double took = mono_now() - t0;
    close(fd);
    if (!cut)
        fail_msg("the slow body still held the connection after %.1f s", took);
    if (took > 3.5)
        fail_msg("cut off after %.1f s, not within about 3 s", took);
    expect_livez(&d);
    stop(&d);
}

/* --max-conns-per-ip connections each sending head (and then a byte every 250 ms, never idle) lock their
 * address out for --request-timeout at most. */
static void slow_clients_at_the_limit(const char *head)
{
    daemon_t d;
    start(&d, "--request-timeout 2 --max-conns-per-ip 8");
    enum { N = 8 };
    int fd[N];
    for (int i = 0; i < N; i++) {
        fd[i] = raw_dial(d.port);
        assert_true(fd[i] >= 0);
        send(fd[i], head, strlen(head), MSG_NOSIGNAL);
    }
    double t0 = mono_now(), ok_at = -1;
    int tries = 0;
    while (ok_at < 0 && mono_now() - t0 < 6) {
        for (int i = 0; i < N; i++)
            send(fd[i], " ", 1, MSG_NOSIGNAL | MSG_DONTWAIT);   /* never idle */
        raw_reply r = get(&d, "/livez");
        tries++;
        if (r.status == 200)
            ok_at = mono_now() - t0;
        raw_reply_free(&r);
        if (ok_at < 0)
            usleep(250000);
    }
    for (int i = 0; i < N; i++)
        close(fd[i]);
    if (ok_at < 0)
        fail_msg("/livez from the same address failed %d times in 6 s", tries);
    if (ok_at > 3.5)
        fail_msg("/livez first succeeded after %.1f s, over the request timeout + 1 s", ok_at);
    stop(&d);
}

static void slow_bodies_at_the_per_address_limit_should_not_lock_the_address_out(void **state)
{
    (void)state;
    slow_clients_at_the_limit("POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: 1000\r\n\r\n");
}

/* The same with heads that never end (slowloris): libmicrohttpd's --timeout is an idle timeout, and the
 * handler that keeps --request-timeout is called only once a head is whole, so 128 of them locked
 * localhost out for as long as they trickled (QA: with --timeout 3 --request-timeout 3, still open at 12 s). */
static void slow_heads_at_the_per_address_limit_should_not_lock_the_address_out(void **state)
{
    (void)state;
    slow_clients_at_the_limit("GET /livez HTTP/1.1\r\nHost: localhost\r\nX-Slow: ");
}

/* At --max-conns, one more connection is answered at once, a 503 problem with Retry-After, and closed;
 * the connections already open are served as before, and once one closes a new one is served. (It used to
 * wait in the listen queue unanswered: libmicrohttpd, with the inter-thread channel that suspending needs,
 * stops accepting at its connection limit rather than closing what is over it.) */
static void a_connection_over_max_conns_should_get_a_prompt_503_while_the_others_are_served(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--max-conns 4 --max-conns-per-ip 200 --http-threads 2");
    enum { N = 4 };
    const char *keep = "GET /livez HTTP/1.1\r\nHost: localhost\r\n\r\n";
    int fd[N];
    for (int i = 0; i < N; i++) {   /* each open and accepted: it has had an answer, and stays */
        fd[i] = raw_dial(d.port);
        assert_true(fd[i] >= 0);
        raw_reply r = raw_exchange(fd[i], keep, strlen(keep), 3000);
        if (r.status != 200 || r.closed)
            fail_msg("keep-alive connection %d: status %d, closed %d", i, r.status, r.closed);
        raw_reply_free(&r);
    }
    for (int round = 0; round < 3; round++) {
        int over = raw_dial(d.port);
        assert_true(over >= 0);
        raw_reply r = raw_exchange(over, keep, strlen(keep), 3000);
        close(over);
        if (r.timed_out || r.status == 0)
            fail_msg("over --max-conns: no answer in %.1f s (timed out %d, closed %d)", r.seconds, r.timed_out,
                     r.closed);
        expect_problem(&r, 503, NULL, "--max-conns");
        char retry[32];
        if (!raw_header(&r, "Retry-After", retry, sizeof retry))
            fail_msg("a 503 over --max-conns without Retry-After");
        if (r.first_response > 1.0)
            fail_msg("the 503 came after %.2f s", r.first_response);
        raw_reply_free(&r);
    }
    /* Idle connections past the limit take the 64 spare places that are answered 503; one more is closed at once
     * (or, if the daemon has not seen them all yet, answered 503): never left waiting. */
    enum { SPARE = 64 };
    int idle[SPARE];
    for (int i = 0; i < SPARE; i++) {
        idle[i] = raw_dial(d.port);
        assert_true(idle[i] >= 0);
    }
    usleep(300000);
    raw_reply r0 = get(&d, "/livez");
    if (r0.timed_out || !(r0.status == 503 || (r0.status == 0 && r0.closed)) || r0.seconds > 1.0)
        fail_msg("past the spare places: status %d, closed %d, timed out %d, after %.2f s", r0.status, r0.closed,
                 r0.timed_out, r0.seconds);
    raw_reply_free(&r0);
    for (int i = 0; i < SPARE; i++)
        close(idle[i]);
    for (int i = 0; i < N; i++) {   /* the others carry on */
        raw_reply r = raw_exchange(fd[i], keep, strlen(keep), 3000);
        if (r.status != 200)
            fail_msg("keep-alive connection %d after the refusals: status %d", i, r.status);
        raw_reply_free(&r);
    }
    close(fd[0]);
    double t0 = mono_now();
    raw_reply r = get(&d, "/livez");   /* a place is free again (its close may take a moment to be seen) */
    while (r.status != 200 && mono_now() - t0 < 2) {
        raw_reply_free(&r);
        usleep(50000);
        r = get(&d, "/livez");
    }
    if (r.status != 200)
        fail_msg("with a connection closed, a new one still got %d", r.status);
    raw_reply_free(&r);
    for (int i = 1; i < N; i++)
        close(fd[i]);
    stop(&d);
}

/* ---- 413 ---- */

static void an_oversized_body_with_expect_100_continue_should_get_413_before_any_byte_of_it(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--max-body 1MiB");
    const char *req = "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Type: application/json\r\n"
                      "Content-Length: 2097152\r\nExpect: 100-continue\r\n\r\n";
    raw_reply r = raw_request(d.port, req, strlen(req), 3000);
    expect_problem(&r, 413, NULL, NULL);   /* with no body sent: a daemon waiting for one times out */
    raw_reply_free(&r);
    expect_livez(&d);
    stop(&d);
}

static void a_client_that_writes_all_its_body_before_reading_should_read_the_413_20_of_20_times(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--max-body 1MiB");
    size_t big = 2u << 20;
    char head[160];
    int hl = snprintf(head, sizeof head, "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Type: application/json\r\n"
                                         "Content-Length: %zu\r\n\r\n", big);
    char *req = malloc((size_t)hl + big);
    memcpy(req, head, (size_t)hl);
    memset(req + hl, ' ', big);
    int read_413 = 0;
    char why[256] = "";
    for (int i = 0; i < 20; i++) {
        int fd = raw_dial(d.port);
        assert_true(fd >= 0);
        /* As urllib does: every byte out first, only then read. Odd tries send the head, wait for the
         * daemon to see it, then the body, as a streaming client does; the race is then lost every time. */
        int fail = i % 2 ? send_all(fd, req, (size_t)hl, 5) != 0 || (usleep(100000), 0) ||
                               send_all(fd, req + hl, big, 5) != 0
                         : send_all(fd, req, (size_t)hl + big, 5) != 0;
        if (fail) {
            snprintf(why, sizeof why, "try %d: the write failed (%s)", i, strerror(errno));
            close(fd);
            continue;
        }
        raw_reply r = raw_exchange(fd, "", 0, 5000);
        close(fd);
        char conn[64] = "";
        raw_header(&r, "Connection", conn, sizeof conn);
        if (r.status == 413 && r.responses == 1 && !strcasecmp(conn, "close") &&
            json_strict_valid(r.body, r.body_len))
            read_413++;
        else
            snprintf(why, sizeof why, "try %d: status %d, Connection \"%s\", body %.80s", i, r.status, conn, r.body);
        raw_reply_free(&r);
    }
    free(req);
    if (read_413 != 20)
        fail_msg("413 read %d of 20; last failure: %s", read_413, why);
    expect_livez(&d);
    stop(&d);
}

static void a_chunked_body_growing_over_the_limit_should_get_a_readable_413(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--max-body 1MiB");
    size_t chunk = 65536, chunks = 32, cap = 256 + chunks * (chunk + 16);
    char *req = malloc(cap);
    size_t n = (size_t)snprintf(req, cap, "POST /solve HTTP/1.1\r\nHost: localhost\r\nTransfer-Encoding: chunked\r\n\r\n");
    for (size_t i = 0; i < chunks; i++) {
        n += (size_t)snprintf(req + n, cap - n, "%zx\r\n", chunk);
        memset(req + n, ' ', chunk);
        n += chunk;
        n += (size_t)snprintf(req + n, cap - n, "\r\n");
    }
    n += (size_t)snprintf(req + n, cap - n, "0\r\n\r\n");
    raw_reply r = raw_request(d.port, req, n, 5000);
    free(req);
    expect_problem(&r, 413, NULL, NULL);
    raw_reply_free(&r);
    expect_livez(&d);
    stop(&d);
}

/* ---- shutdown and budgets ---- */

typedef struct {
    int port;
    char *body;
    raw_reply r;
} job_arg;

static void *heavy_client(void *arg)
{
    job_arg *a = arg;
    size_t blen = strlen(a->body), cap = blen + 256;
    char *req = malloc(cap);
    int n = snprintf(req, cap, "POST /solve?format=glb&res=512 HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n"
                               "Content-Length: %zu\r\n\r\n%s", blen, a->body);
    a->r = raw_request(a->port, req, (size_t)n, 9000);
    free(req);
    return NULL;
}

static void sigterm_should_answer_queued_jobs_503_cancel_the_running_one_and_exit_within_grace_plus_one(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--grace 2 --threads 1 --queue 64 --job-timeout 60 --max-work 1e15 --max-mem-mb 4096");
    enum { N = 12 };
    pthread_t t[N];
    job_arg a[N];
    for (int i = 0; i < N; i++)
        a[i] = (job_arg){ d.port, heavy_model(512, i), { 0 } };
    threads_start(t, N, heavy_client, a, sizeof *a);
    /* Until every job is in: one running, the rest queued. */
    for (int i = 0; i < 100 && metric_or_none(&d, "pdesolid_queue_depth") < N - 1; i++)
        usleep(50000);
    double t0 = mono_now();
    kill(d.pid, SIGTERM);
    int st = -1, exited = 0;
    while (!exited && mono_now() - t0 < 6) {
        exited = waitpid(d.pid, &st, WNOHANG) == d.pid;
        if (!exited)
            usleep(20000);
    }
    double took = mono_now() - t0;
    if (!exited) {
        kill(d.pid, SIGKILL);
        waitpid(d.pid, &st, 0);
    }
    live = 0;
    threads_join(t, N);
    int answered_503 = 0, unanswered = 0;
    for (int i = 0; i < N; i++) {
        char ct[64] = "";
        raw_header(&a[i].r, "Content-Type", ct, sizeof ct);
        if (a[i].r.status == 503 && !strcmp(ct, "application/problem+json") &&
            json_strict_valid(a[i].r.body, a[i].r.body_len))
            answered_503++;
        else if (a[i].r.status == 0)
            unanswered++;
        raw_reply_free(&a[i].r);
        free(a[i].body);
    }
    if (!exited)
        fail_msg("pdesolidd had not exited 6 s after SIGTERM with --grace 2");
    if (took > 3.5)
        fail_msg("exit %.1f s after SIGTERM, over grace + 1 s", took);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
    /* The queued ones get a 503 problem; the running one may be cut off instead. */
    if (answered_503 < N - 1)
        fail_msg("%d of %d heavy requests answered 503 problem+json (%d not answered)", answered_503, N, unanswered);
}

/* A job past --job-timeout is cancelled. With the CPU to itself (75 % of the time or more) it is more work than
 * the server takes: a 422 that says so (it was a 503 with Retry-After, which a client retried forever: QA);
 * starved of CPU by other work, a 503 "busy" with Retry-After. Which one depends on the machine's load, so
 * the status must agree with the CPU share the detail reports. */
static void a_job_over_its_deadline_should_be_cancelled_with_a_problem_that_says_why(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--threads 1 --job-timeout 1 --max-work 1e15 --max-mem-mb 4096");
    char *body = heavy_model(512, 77);
    raw_reply r = ask(&d, "POST", "/solve?format=glb&res=512", NULL, body, strlen(body), 6000);
    free(body);
    double cpu = -1, wall = -1;
    const char *in = r.body ? strstr(r.body, "s of CPU in ") : NULL;
    if (in) {
        const char *b = in - 1;   /* "0.98 s of CPU in 1.1 s" */
        while (b > r.body && (b[-1] == '.' || (b[-1] >= '0' && b[-1] <= '9') || b[-1] == 'e' || b[-1] == '-'))
            b--;
        cpu = strtod(b, NULL), wall = strtod(in + strlen("s of CPU in "), NULL);
    }
    if (!(cpu >= 0 && wall >= 1))
        fail_msg("no CPU share in the answer (%d): %.300s", r.status, r.body ? r.body : "");
    print_message("%d: %.2g s of CPU in %.2g s\n", r.status, cpu, wall);
    if (cpu >= 0.75 * wall)
        expect_problem(&r, 422, NULL, "on a CPU of its own");
    else
        expect_problem(&r, 503, NULL, "the server is busy");
    if (r.first_response > 3)
        fail_msg("the cancelled job answered after %.1f s with --job-timeout 1", r.first_response);
    raw_reply_free(&r);
    /* The thread is free again at once. */
    r = post(&d, "/solve?format=f32&res=2", "{\"preset\":\"fig4a\"}");
    assert_int_equal(r.status, 200);
    assert_int_equal(r.body_len, 8 * 12);
    raw_reply_free(&r);
    stop(&d);
}

/* Opens a connection, sends a heavy /solve on it (keep-alive) and returns the socket once the job runs. */
static int heavy_job_running(const daemon_t *d, int seed)
{
    char *body = heavy_model(512, seed);
    size_t blen = strlen(body);
    char head[160];
    int hn = snprintf(head, sizeof head, "POST /solve?format=glb&res=512 HTTP/1.1\r\nHost: localhost\r\n"
                                         "Content-Length: %zu\r\n\r\n", blen);
    int fd = raw_dial(d->port);
    assert_true(fd >= 0);
    raw_send_all(fd, head, (size_t)hn);
    raw_send_all(fd, body, blen);
    free(body);
    for (int i = 0; i < 200 && metric_or_none(d, "pdesolid_queue_depth") < 1; i++)
        usleep(50000);
    usleep(300000);   /* well into its work, which takes some 23 s without sanitisers */
    return fd;
}

/* A client that closes its connection while its job runs (nginx's 499, "client closed request"): the job
 * stops at its next poll rather than at --job-timeout, its thread serves the next request, and it is counted
 * and logged as 499 with the reason. Before, it ran on to the deadline and was logged 503 aborted. */
static void a_client_gone_while_its_job_runs_should_stop_the_job_and_be_logged_499(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--threads 1 --job-timeout 60 --max-work 1e15 --max-mem-mb 4096");
    int fd = heavy_job_running(&d, 41);
    double t0 = mono_now();
    close(fd);
    static const char counted[] = "pdesolid_requests_total{route=\"solve\",status=\"499\"} 1\n";
    int seen = 0;
    while (!seen && mono_now() - t0 < 10) {
        raw_reply m = get(&d, "/metrics");
        seen = m.status == 200 && strstr(m.body, counted);
        raw_reply_free(&m);
        if (!seen)
            usleep(50000);
    }
    double took = mono_now() - t0;
    if (!seen)
        fail_msg("the job of a client gone 10 s ago still runs (or was not counted 499); --job-timeout is 60 s");
    /* The only solver thread is free: a new solve is answered at once (its post waits 8 s at most). */
    raw_reply r = post(&d, "/solve?format=f32&res=2", "{\"preset\":\"fig4a\"}");
    assert_int_equal(r.status, 200);
    raw_reply_free(&r);
    expect_livez(&d);
    stop(&d);
    char *log = read_file(d.log, NULL);
    assert_non_null(log);
    const char *line = strstr(log, "\"POST /solve?format=glb&res=512\" 499 ");
    if (!line || !strstr(line, "aborted"))
        fail_msg("no access-log line of the gone client's request as 499 aborted:\n%s", log);
    if (!strstr(log, "closed its connection"))
        fail_msg("the log does not say why the job stopped:\n%s", log);
    if (strstr(log, "internal error"))   /* libmicrohttpd's words for the handler's refusal to answer */
        fail_msg("the log calls a client gone an internal error:\n%s", log);
    print_message("  the job stopped %.2f s after its client closed\n", took);
    free(log);
}

/* Bytes that come while a job runs, a request pipelined on the same keep-alive connection, are no close: the job
 * runs to its end (here its deadline: a 422, or a 503 where it was starved of CPU) and both requests are
 * answered, in order. */
static void a_request_pipelined_while_a_job_runs_should_not_cancel_it(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--threads 1 --job-timeout 3 --max-work 1e15 --max-mem-mb 4096");
    int fd = heavy_job_running(&d, 43);
    static const char next[] = "GET /livez HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n";
    raw_send_all(fd, next, sizeof next - 1);
    static char buf[1 << 16];
    long n = raw_read_to_close(fd, buf, sizeof buf, 8);
    close(fd);
    const char *first = strstr(buf, "HTTP/1.1 "), *second = first ? strstr(first + 9, "HTTP/1.1 ") : NULL;
    const int deadline = first && (!strncmp(first, "HTTP/1.1 422", 12) || !strncmp(first, "HTTP/1.1 503", 12)) &&
                         strstr(first, "ran past its deadline");
    if (n < 0 || !first || !second || !deadline || strncmp(second, "HTTP/1.1 200", 12))
        fail_msg("expected the job's deadline (422, or 503 on a busy machine) and the pipelined request's 200, got "
                 "(%ld bytes): %s", n, shown(buf, 0));
    stop(&d);
    char *log = read_file(d.log, NULL);
    if (log && strstr(log, "closed its connection"))
        fail_msg("a pipelined request was taken for a close:\n%s", log);
    free(log);
}

/* Each budget alone: the other one is set out of the way. */
static void requests_over_the_work_or_memory_budget_should_be_422_naming_the_flag(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--max-work 1000000 --max-mem-mb 4096");
    char *body = heavy_model(512, 5);
    raw_reply r = ask(&d, "POST", "/solve?format=glb&res=512", NULL, body, strlen(body), 5000);
    expect_problem(&r, 422, NULL, "--max-work");
    raw_reply_free(&r);
    stop(&d);
    /* A glb at res 512 needs tens of MB of mesh: over 1 MB of scratch. */
    start(&d, "--max-work 1e15 --max-mem-mb 1");
    r = ask(&d, "POST", "/solve?format=glb&res=512", NULL, body, strlen(body), 5000);
    expect_problem(&r, 422, NULL, "--max-mem-mb");
    raw_reply_free(&r);
    free(body);
    expect_livez(&d);
    stop(&d);
}

/* ---- flags ---- */

/* Runs pdesolidd with args for up to 5 s; its exit status (-1 if it was still running), its stderr into err. */
static int run_daemon(const char *args, char **err)
{
    const char *bin = getenv("PDESOLIDD_SAN") ? getenv("PDESOLIDD_SAN") : "build/san/pdesolidd";
    char log[160], cmd[1024];
    snprintf(log, sizeof log, "%s/run.log", dir);
    snprintf(cmd, sizeof cmd, "exec %s %s 2>%s", bin, args, log);
    pid_t pid = fork();
    if (pid == 0) {
        child_dies_with_parent();
        execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
        _exit(127);
    }
    int st = 0, done = 0;
    for (double t0 = mono_now(); !done && mono_now() - t0 < 5;) {
        done = waitpid(pid, &st, WNOHANG) == pid;
        if (!done)
            usleep(20000);
    }
    if (!done) {
        kill(pid, SIGTERM);
        waitpid(pid, &st, 0);
    }
    *err = read_file(log, NULL);
    return done && WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void every_flag_should_take_the_equals_form_and_unknown_arguments_should_exit_2_naming_them(void **state)
{
    (void)state;
    daemon_t d;
    daemon_start(&d, dir,
                 "--threads=1 --request-timeout=5 --job-timeout=2 --max-work=1000000000 --max-mem-mb=64 "
                 "--http-threads=2 --log-format=text --grace=3 --timeout=10 --max-body=1MiB");
    expect_livez(&d);
    stop(&d);
    static const struct {
        const char *args, *named;
    } bad[] = {
        { "--port 0 extra", "extra" },
        { "--port 0 --bogus-flag=1", "--bogus-flag" },
        { "--port 0 --log-format yaml", "--log-format" },
        { "--port 0 --web /nonexistent", "/nonexistent" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        char *err;
        int rc = run_daemon(bad[i].args, &err);
        if (rc != 2)
            fail_msg("pdesolidd %s: exit %d, expected 2 (-1: it started): %s", bad[i].args, rc, err ? err : "");
        if (!err || !strstr(err, bad[i].named) || strstr(err, "needs a value"))
            fail_msg("pdesolidd %s: the message does not name %s: %s", bad[i].args, bad[i].named, err ? err : "");
        free(err);
    }
}

/* ---- strict input and output ---- */

static void eval_far_outside_the_cube_should_be_422_naming_the_point_and_never_write_nan(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    char id[64], path[128];
    solve_id(&d, "fig4a", id, sizeof id);
    snprintf(path, sizeof path, "/solids/%s/eval", id);
    static const struct {
        const char *body, *pointer;
    } rows[] = {
        { "{\"points\":[[1e300,1e300,1e300]]}", "/points/0" },
        { "{\"points\":[[0.5,0.5,0.5],[0.5,0.5,1e300]]}", "/points/1" },
        { "{\"points\":[[0.5,0.5,1e300]],\"derivatives\":true}", "/points/0" },
        { "{\"points\":[[0.5,0.5,800]]}", "/points/0" },   /* x, y are nan there today */
    };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        raw_reply r = post(&d, path, rows[i].body);
        if (!json_strict_valid(r.body, r.body_len))
            fail_msg("%s: the answer is not JSON: %.200s", rows[i].body, r.body);
        expect_problem(&r, 422, rows[i].pointer, NULL);
        raw_reply_free(&r);
    }
    /* A finite point still answers, with finite numbers. */
    raw_reply r = post(&d, path, "{\"points\":[[0.5,0.25,0.5]],\"derivatives\":true}");
    assert_int_equal(r.status, 200);
    assert_true(json_strict_valid(r.body, r.body_len));
    raw_reply_free(&r);
    expect_livez(&d);
    stop(&d);
}

static void the_response_cache_should_key_on_the_whole_query(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    char target[256];
    static const struct {
        char last;
        size_t bytes;
    } rows[] = { { '3', 3 * 3 * 3 * 12 }, { '5', 5 * 5 * 5 * 12 }, { '3', 3 * 3 * 3 * 12 } };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        snprintf(target, sizeof target, "/solve?format=f32&res=%0100d%c", 0, rows[i].last);
        raw_reply r = post(&d, target, "{\"preset\":\"fig4a\"}");
        assert_int_equal(r.status, 200);
        if (r.body_len != rows[i].bytes)
            fail_msg("res=<100 zeros>%c: %zu bytes, expected %zu", rows[i].last, r.body_len, rows[i].bytes);
        raw_reply_free(&r);
    }
    stop(&d);
}

static void nul_in_a_path_query_or_body_should_be_400(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    char id[64], path[128];
    solve_id(&d, "fig4a", id, sizeof id);
    snprintf(path, sizeof path, "/solids/%s%%00", id);
    raw_reply r = get(&d, path);
    if (r.status != 400 && r.status != 404)
        fail_msg("%s: status %d, expected 400 or 404", path, r.status);
    expect_problem(&r, r.status, ANY_POINTER, NULL);
    raw_reply_free(&r);
    snprintf(path, sizeof path, "/solids/%s?format=json%%00xyz", id);
    r = get(&d, path);
    expect_problem(&r, 400, NULL, "format");
    raw_reply_free(&r);
    char *model = read_file("examples/fig4a.json", NULL);
    assert_non_null(model);
    char *key = strstr(model, "\"pde\"");
    assert_non_null(key);
    size_t ml = strlen(model), kpos = (size_t)(key - model);
    char *nulkey = malloc(ml + 32);
    snprintf(nulkey, ml + 32, "%.*s\"pde\\u0000junk\"%s", (int)kpos, model, key + 5);
    static const char raw_nul[] = "{\"preset\":\0\"fig4a\"}";
    static const struct {
        const char *body;
        size_t len;
    } rows[] = {
        { NULL, 0 },   /* the model with the key "pde\u0000junk" */
        { "{\"preset\":\"fig4a\\u0000x\"}", 0 },
        { raw_nul, sizeof raw_nul - 1 },
        { "{\"preset\":\"fig4a\",\"params\":{\"p0\":0001}}", 0 },
        { "{\"preset\":\"fig4a\",\"params\":{\"p0\":-01}}", 0 },
    };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        const char *b = rows[i].body ? rows[i].body : nulkey;
        size_t bl = rows[i].len ? rows[i].len : strlen(b);
        r = ask(&d, "POST", "/solve", NULL, b, bl, 8000);
        if (r.status != 400)
            fail_msg("body %zu (%.60s): status %d, expected 400", i, b, r.status);
        expect_problem(&r, 400, ANY_POINTER, NULL);
        raw_reply_free(&r);
    }
    free(nulkey);
    free(model);
    expect_livez(&d);
    stop(&d);
}

static void invalid_utf8_anywhere_should_give_a_problem_in_valid_json_and_utf8(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    static const struct {
        const char *method, *target, *body;
    } rows[] = {
        { "POST", "/solve", "{\"preset\":\"fig\xff\xfe\"}" },
        { "POST", "/solve", "{\"pr\xc3\x28set\":\"fig4a\"}" },
        { "POST", "/solve", "{\"template\":\"ex\xed\xa0\x80mple4\"}" },
        { "POST", "/solve", "{\"preset\":\"fig4a\",\"params\":{\"p\xc0\xaf\":1}}" },
        { "POST", "/solve", "{\"preset\":\"\xf4\x90\x80\x80\"}" },
        { "POST", "/solve", "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-1,-1,-1]},\"boundary\":{\"x\":[{\"u\":{\"t\xe2\x82\":1}}]}}" },
        { "POST", "/solve?format=\xff\xfe", "{\"preset\":\"fig4a\"}" },
        { "POST", "/solve?format=%ff%fe", "{\"preset\":\"fig4a\"}" },
        { "POST", "/solve?%c3%28=1", "{\"preset\":\"fig4a\"}" },
        { "POST", "/solve?format=grid&res=%e2%82", "{\"preset\":\"fig4a\"}" },
        { "GET", "/presets/fig%ff", NULL },
        { "GET", "/presets/fig\xc3\x28", NULL },
        { "GET", "/solids/%ed%a0%80", NULL },
        { "GET", "/nowhere/%c0%af", NULL },
    };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        raw_reply r = ask(&d, rows[i].method, rows[i].target, NULL, rows[i].body, rows[i].body ? strlen(rows[i].body) : 0,
                          5000);
        if (r.status < 400 || r.status > 499)
            fail_msg("row %zu (%s %s): status %d, expected 4xx", i, rows[i].method, shown(rows[i].target, 0), r.status);
        if (!utf8_valid(r.body, r.body_len) || !json_strict_valid(r.body, r.body_len))
            fail_msg("row %zu (%s %s): the problem is not valid UTF-8 JSON: %s", i, rows[i].method,
                     shown(rows[i].target, 0), shown(r.body, 1));
        expect_problem(&r, r.status, ANY_POINTER, NULL);
        raw_reply_free(&r);
    }
    expect_livez(&d);
    stop(&d);
}

static void an_unknown_query_parameter_should_be_400_naming_it_and_the_known_ones(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    raw_reply r = post(&d, "/solve?fromat=glb", "{\"preset\":\"fig4a\"}");
    expect_problem(&r, 400, NULL, "fromat");
    cJSON *p = cJSON_Parse(r.body);
    const char *detail = cJSON_GetObjectItem(p, "detail")->valuestring;
    if (!strstr(detail, "format") || !strstr(detail, "res"))
        fail_msg("the detail does not list format and res: %s", detail);
    cJSON_Delete(p);
    raw_reply_free(&r);
    stop(&d);
}

/* A compressed body is a 415 naming the coding (a gzip body was read as JSON: 400 "not the control character
 * 0x1F": QA); identity, or a route without a body, is served as before. */
static void a_content_encoded_body_should_be_415_naming_the_coding(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    static const char gz[] = "\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03\xab\x56\x2a\x28\x4a\x2d";
    raw_reply r = ask(&d, "POST", "/solve", "Content-Encoding: gzip\r\n", gz, sizeof gz - 1, 8000);
    expect_problem(&r, 415, NULL, "Content-Encoding is gzip");
    raw_reply_free(&r);
    const char *body = "{\"preset\":\"fig1a\"}";
    r = ask(&d, "POST", "/solve", "Content-Encoding: identity\r\n", body, strlen(body), 8000);
    assert_int_equal(r.status, 200);
    raw_reply_free(&r);
    r = ask(&d, "GET", "/livez", "Content-Encoding: br\r\n", NULL, 0, 5000);
    assert_int_equal(r.status, 200);
    raw_reply_free(&r);
    /* a list, or two lines, is one list (RFC 9110 5.3): the second line was not read (review) */
    r = ask(&d, "POST", "/solve", "Content-Encoding: identity\r\nContent-Encoding: gzip\r\n", gz, sizeof gz - 1, 8000);
    expect_problem(&r, 415, NULL, "Content-Encoding is gzip");
    raw_reply_free(&r);
    r = ask(&d, "POST", "/solve", "Content-Encoding: identity, br\r\n", gz, sizeof gz - 1, 8000);
    expect_problem(&r, 415, NULL, "Content-Encoding is br");
    raw_reply_free(&r);
    r = ask(&d, "POST", "/solve", "Content-Encoding:\r\n", body, strlen(body), 8000);
    assert_int_equal(r.status, 200);
    raw_reply_free(&r);
    stop(&d);
}

/* A keep-alive connection idle for longer than --request-timeout but within --timeout is served: the head's
 * deadline on a connection answered before is the longer of the two (the watcher closed it at
 * --request-timeout, so --timeout above it did nothing: review). */
static void a_keep_alive_connection_should_stay_open_for_its_timeout(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--request-timeout 1 --timeout 6");
    int fd = raw_dial(d.port);
    assert_true(fd >= 0);
    static const char one[] = "GET /livez HTTP/1.1\r\nHost: localhost\r\n\r\n",
                      two[] = "GET /livez HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n";
    raw_send_all(fd, one, sizeof one - 1);
    char buf[4096];
    struct pollfd pf = { fd, POLLIN, 0 };
    assert_true(poll(&pf, 1, 5000) == 1);
    assert_true(recv(fd, buf, sizeof buf, 0) > 0);
    usleep(2500000);   /* idle: past --request-timeout, within --timeout */
    raw_send_all(fd, two, sizeof two - 1);
    long n = raw_read_to_close(fd, buf, sizeof buf - 1, 5);
    close(fd);
    if (n < 12 || strncmp(buf, "HTTP/1.1 200", 12))
        fail_msg("the second request on an idle keep-alive connection got %ld bytes: %s", n, n > 0 ? shown(buf, 0) : "");
    stop(&d);
}

/* ---- framing ---- */

static void bad_framing_should_get_one_error_response_or_a_close_within_2_s(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
#define BODY18 "{\"preset\":\"fig4a\"}"
    /*
     * mhd: libmicrohttpd 0.9.75 answers these itself before pdesolidd sees the request (its answer to a
     * malformed Content-Length sends the status line twice; a chunk size of 2^64 - 1 waits for the idle
     * timeout). They are what deploy/nginx.conf is for (tests/test_nginx.c); here only the daemon's
     * survival is checked.
     */
    static const struct {
        const char *name, *req;
        int mhd;
    } rows[] = {
        { "Content-Length: -1", "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: -1\r\n\r\n" BODY18, 1 },
        { "Content-Length: abc", "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: abc\r\n\r\n" BODY18, 1 },
        { "Content-Length: 18, 18", "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: 18, 18\r\n\r\n" BODY18, 1 },
        { "Content-Length: 2^64",
          "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: 18446744073709551616\r\n\r\n" BODY18, 1 },
        { "two Content-Lengths",
          "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: 18\r\nContent-Length: 5\r\n\r\n" BODY18, 0 },
        { "Transfer-Encoding with Content-Length",
          "POST /solve HTTP/1.1\r\nHost: localhost\r\nContent-Length: 18\r\nTransfer-Encoding: chunked\r\n\r\n"
          "12\r\n" BODY18 "\r\n0\r\n\r\n", 0 },
        { "Transfer-Encoding: gzip, chunked",
          "POST /solve HTTP/1.1\r\nHost: localhost\r\nTransfer-Encoding: gzip, chunked\r\n\r\n12\r\n" BODY18 "\r\n0\r\n\r\n", 0 },
        { "chunk size ffffffffffffffff",
          "POST /solve HTTP/1.1\r\nHost: localhost\r\nTransfer-Encoding: chunked\r\n\r\nffffffffffffffff\r\n" BODY18 "\r\n", 1 },
    };
#undef BODY18
    int failed = 0;
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        raw_reply r = raw_request(d.port, rows[i].req, strlen(rows[i].req), 2000);
        int one_error = r.responses == 1 && r.status >= 400 && r.status <= 599;
        int closed = r.responses == 0 && r.closed;
        if (!rows[i].mhd && (!(one_error || closed) || r.seconds > 2.1)) {
            print_message("  %s: %d responses, status %d, closed %d, %.2f s\n", rows[i].name, r.responses, r.status,
                          r.closed, r.seconds);
            failed++;
        }
        raw_reply_free(&r);
        expect_livez(&d);
    }
    if (failed)
        fail_msg("%d of %zu framing attacks were answered wrongly", failed, sizeof rows / sizeof *rows);
    stop(&d);
}

/* ---- logs and request ids ---- */

/* An RFC 3339 date-time somewhere in line. */
static int has_rfc3339(const char *line)
{
    for (const char *p = line; *p; p++) {
        int y, mo, da, h, mi, s, k = 0;
        if (sscanf(p, "%4d-%2d-%2dT%2d:%2d:%2d%n", &y, &mo, &da, &h, &mi, &s, &k) == 6 && k == 19) {
            const char *q = p + 19;
            if (*q == '.')
                for (q++; *q >= '0' && *q <= '9'; q++)
                    ;
            if (*q == 'Z' || ((*q == '+' || *q == '-') && q[1] >= '0' && q[1] <= '9' && q[3] == ':'))
                return 1;
        }
    }
    return 0;
}

static void the_access_log_should_escape_control_characters_and_carry_the_request_id(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    raw_reply r = ask(&d, "GET", "/%0aFORGED%20LINE?x=%0d%0aFORGED2", "X-Request-Id: hostile-log-1\r\n", NULL, 0, 5000);
    if (r.status != 400 && r.status != 404)
        fail_msg("status %d, expected 400 or 404", r.status);
    raw_reply_free(&r);
    stop(&d);
    char *log = read_file(d.log, NULL);
    assert_non_null(log);
    const char *line = NULL;
    for (char *p = log; *p; p += strcspn(p, "\n") + (p[strcspn(p, "\n")] != 0)) {
        if (!strncmp(p, "FORGED", 6))
            fail_msg("a forged line in the log:\n%s", log);
        if (!line && strstr(p, "hostile-log-1") && strstr(p, "hostile-log-1") < p + strcspn(p, "\n"))
            line = p;
    }
    if (!line)
        fail_msg("no access-log line carries the request id hostile-log-1:\n%s", log);
    if (!strstr(log, "\\nFORGED") && !strstr(log, "\\x0aFORGED") && !strstr(log, "\\x0AFORGED") &&
        !strstr(log, "\\u000aFORGED") && !strstr(log, "%0aFORGED") && !strstr(log, "%0AFORGED"))
        fail_msg("the newline before FORGED is not escaped:\n%s", log);
    char one[1024];
    snprintf(one, sizeof one, "%.*s", (int)strcspn(line, "\n"), line);
    if (!has_rfc3339(one))
        fail_msg("no RFC 3339 timestamp in the access-log line: %s", one);
    free(log);
}

static void the_json_log_format_should_write_one_json_object_per_line(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--log-format json");
    raw_reply r = ask(&d, "GET", "/%0aFORGED%22%7d", "X-Request-Id: hostile-json-1\r\n", NULL, 0, 5000);
    raw_reply_free(&r);
    r = ask(&d, "GET", "/livez", "X-Request-Id: hostile-json-2\r\n", NULL, 0, 5000);
    raw_reply_free(&r);
    stop(&d);
    char *log = read_file(d.log, NULL);
    assert_non_null(log);
    int found = 0;
    for (char *p = log; *p; p += strcspn(p, "\n") + (p[strcspn(p, "\n")] != 0)) {
        size_t n = strcspn(p, "\n");
        if (!strncmp(p, "FORGED", 6))
            fail_msg("a forged line in the log:\n%s", log);
        char *hit1 = strstr(p, "hostile-json-1"), *hit2 = strstr(p, "hostile-json-2");
        if ((hit1 && hit1 < p + n) || (hit2 && hit2 < p + n)) {
            if (!json_strict_valid(p, n))
                fail_msg("an access-log line is not one JSON object: %.*s", (int)n, p);
            char one[1024];
            snprintf(one, sizeof one, "%.*s", (int)n, p);
            if (!has_rfc3339(one))
                fail_msg("no RFC 3339 timestamp: %s", one);
            found++;
        }
    }
    if (found != 2)
        fail_msg("%d JSON access-log lines with the two request ids, expected 2:\n%s", found, log);
    free(log);
}

static void request_ids_should_be_echoed_when_sane_and_replaced_otherwise(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    static const struct {
        const char *sent;
        int echoed;
    } rows[] = {
        { "abc-DEF_1.2:3", 1 },
        { "0123456789012345678901234567890123456789012345678901234567890123", 1 },   /* 64 */
        { "01234567890123456789012345678901234567890123456789012345678901234", 0 },  /* 65 */
        { "has space", 0 },
        { "<script>", 0 },
        { "a\"b", 0 },
        { "caf\xc3\xa9", 0 },
        { "", 0 },
    };
    char seen[2][128] = { "", "" };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        char h[160], rid[128];
        snprintf(h, sizeof h, "X-Request-Id: %s\r\n", rows[i].sent);
        raw_reply r = ask(&d, "GET", "/nowhere", h, NULL, 0, 5000);
        expect_problem(&r, 404, NULL, NULL);
        assert_true(raw_header(&r, "X-Request-Id", rid, sizeof rid));
        if (rows[i].echoed && strcmp(rid, rows[i].sent))
            fail_msg("sane id \"%s\" came back as \"%s\"", rows[i].sent, rid);
        if (!rows[i].echoed && (!strcmp(rid, rows[i].sent) || !sane_id(rid)))
            fail_msg("id \"%s\" was not replaced by a sane one: \"%s\"", rows[i].sent, rid);
        raw_reply_free(&r);
    }
    /* Without one, every response has its own. */
    for (int i = 0; i < 2; i++) {
        raw_reply r = get(&d, "/livez");
        assert_int_equal(r.status, 200);
        if (!raw_header(&r, "X-Request-Id", seen[i], sizeof seen[i]) || !sane_id(seen[i]))
            fail_msg("/livez: no sane X-Request-Id (\"%s\")", seen[i]);
        raw_reply_free(&r);
    }
    assert_string_not_equal(seen[0], seen[1]);
    stop(&d);
}

/* ---- Server-Timing, CORS, openapi ---- */

/* The sum of the dur= of the named entries; -1 if one is missing. */
static double timing_sum(const char *st, const char *const *names, size_t n)
{
    double sum = 0;
    for (size_t i = 0; i < n; i++) {
        size_t l = strlen(names[i]);
        const char *p = st, *hit = NULL;
        while ((p = strstr(p, names[i]))) {
            if ((p == st || p[-1] == ' ' || p[-1] == ',') && p[l] == ';') {
                hit = p;
                break;
            }
            p += l;
        }
        if (!hit)
            return -1;
        const char *dur = strstr(hit, "dur=");
        const char *comma = strchr(hit, ',');
        if (!dur || (comma && dur > comma))
            return -1;
        sum += strtod(dur + 4, NULL);
    }
    return sum;
}

/* Every request's Server-Timing fits in its wall time; the best of N covers at least half of it. (A stall of the
 * test or the loopback on a loaded machine may make one request's wall time many times its sum; a Server-Timing
 * that leaves most of the server's time out does so in every request.) */
static void server_timing_should_add_up_to_most_of_the_wall_time_of_a_new_solve(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    static const char *const names[] = { "queue", "parse", "solve", "props", "output" };
    enum { N = 5 };
    double best = 0;
    char best_st[640] = "";
    for (int k = 0; k < N; k++) {
        char body[128], st[512];
        snprintf(body, sizeof body, "{\"preset\":\"fig4a\",\"params\":{\"p0\":%d.%d}}", 20000 + rand() % 20000, k);
        raw_reply r = post(&d, "/solve", body);
        assert_int_equal(r.status, 200);
        if (!raw_header(&r, "Server-Timing", st, sizeof st))
            fail_msg("no Server-Timing");
        double sum = timing_sum(st, names, sizeof names / sizeof *names), wall = r.first_response * 1e3;
        if (sum < 0)
            fail_msg("Server-Timing \"%s\" lacks one of queue, parse, solve, props, output with dur=", st);
        if (sum > wall)
            fail_msg("Server-Timing sums to %.3f ms, more than the %.3f ms of the request: %s", sum, wall, st);
        if (sum / wall > best) {
            best = sum / wall;
            snprintf(best_st, sizeof best_st, "%.3f ms of %.3f ms: %s", sum, wall, st);
        }
        raw_reply_free(&r);
    }
    if (best < 0.5)
        fail_msg("Server-Timing sums to at most %.0f%% of a request's wall time in %d requests (best %s)", 100 * best,
                 N, best_st);
    stop(&d);
}

static void a_post_from_a_disallowed_origin_should_get_403_and_solve_nothing(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--cors-origin http://a.example");
    long before = metric(&d, "pdesolid_solve_seconds_count");
    assert_true(before >= 0);
    raw_reply r = ask(&d, "POST", "/solve", "Origin: http://evil.example\r\n", "{\"preset\":\"fig4b\"}", 18, 5000);
    expect_problem(&r, 403, NULL, NULL);
    raw_reply_free(&r);
    assert_int_equal(metric(&d, "pdesolid_solve_seconds_count"), before);
    /* The allowed origin solves, and the count moves. */
    r = ask(&d, "POST", "/solve", "Origin: http://a.example\r\n", "{\"preset\":\"fig4b\"}", 18, 8000);
    assert_int_equal(r.status, 200);
    raw_reply_free(&r);
    assert_int_equal(metric(&d, "pdesolid_solve_seconds_count"), before + 1);
    stop(&d);
}

/* ---- Host: DNS rebinding ---- */

/* The status of GET target with Host: host (formatted with the daemon's port, if host has a %d). */
static int status_as(const daemon_t *d, const char *host, const char *target)
{
    char h[128];
    snprintf(h, sizeof h, host, d->port);
    raw_reply r = ask_host(d, h, "GET", target, NULL, NULL, 0, 5000);
    int status = r.status;
    raw_reply_free(&r);
    return status;
}

static void expect_hosts(const daemon_t *d, const char *const *hosts, size_t n, int status)
{
    for (size_t i = 0; i < n; i++) {
        int got = status_as(d, hosts[i], "/livez");
        if (got != status)
            fail_msg("Host: %s: %d, expected %d", hosts[i], got, status);
    }
}

/* A page at evil.example that rebinds its name to 127.0.0.1 sends Host: evil.example:PORT, and an Origin to match,
 * so that the same-origin check passes: every route refuses it, the front-end's files too, before any work. */
static void a_host_name_not_allowed_should_get_403_naming_the_header_the_value_and_the_flag(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    long before = metric(&d, "pdesolid_solve_seconds_count");
    assert_true(before >= 0);
    char host[64], origin[128];
    snprintf(host, sizeof host, "evil.example:%d", d.port);
    snprintf(origin, sizeof origin, "Origin: http://%s\r\n", host);
    static const struct {
        const char *method, *target;
    } routes[] = {
        { "GET", "/" },         { "GET", "/app.js" },   { "GET", "/livez" },    { "GET", "/readyz" },
        { "GET", "/metrics" },  { "GET", "/presets" },  { "POST", "/solve" },   { "OPTIONS", "/solve" },
        { "GET", "/nowhere" },
    };
    for (size_t i = 0; i < sizeof routes / sizeof *routes; i++) {
        int post = !strcmp(routes[i].method, "POST");
        raw_reply r = ask_host(&d, host, routes[i].method, routes[i].target, origin,
                               post ? "{\"preset\":\"fig4b\"}" : NULL, post ? 18 : 0, 5000);
        expect_problem(&r, 403, NULL, host);
        cJSON *p = cJSON_Parse(r.body);
        const char *detail = cJSON_GetObjectItem(p, "detail")->valuestring;
        if (!strstr(detail, "Host") || !strstr(detail, "--allow-host evil.example"))
            fail_msg("%s %s: the detail \"%s\" does not name the Host header and --allow-host evil.example",
                     routes[i].method, routes[i].target, detail);
        cJSON_Delete(p);
        raw_reply_free(&r);
    }
    assert_int_equal(metric(&d, "pdesolid_solve_seconds_count"), before);
    /* Other spellings of names, and names that only start or end like an allowed one. */
    static const char *const refused[] = {
        "EVIL.Example.",  "x",        "localhost:80x", "127.0.0.1:80:80", "localhost.evil.example", "evillocalhost",
        "localhost.example", "127.0.0.1.evil.example", "[evil.example]", "[::1", "[::1]x", "::1",
        "a..localhost", ".localhost", "evil.example/.localhost",
    };
    expect_hosts(&d, refused, sizeof refused / sizeof *refused, 403);
    expect_livez(&d);   /* the daemon still answers */
    stop(&d);
}

/* Rebinding needs a DNS name: an IP literal, or localhost (which browsers never ask DNS for), is this machine. */
static void ip_literals_and_localhost_should_be_allowed_by_default(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    static const char *const allowed[] = {
        "127.0.0.1:%d", "127.0.0.1",      "localhost", "localhost:%d", "LocalHost.", "foo.localhost",
        "a.b.localhost:%d", "[::1]:%d",   "[::1]",     "192.0.2.7:80", "[2001:db8::1]", "localhost:",
    };
    expect_hosts(&d, allowed, sizeof allowed / sizeof *allowed, 200);
    assert_int_equal(status_as(&d, "localhost:%d", "/"), 200);   /* the front-end */
    /* HTTP/1.0 without Host (no browser sends that). */
    const char *req = "GET /livez HTTP/1.0\r\n\r\n";
    raw_reply r = raw_request(d.port, req, strlen(req), 5000);
    assert_int_equal(r.status, 200);
    raw_reply_free(&r);
    stop(&d);
}

static void allow_host_should_allow_the_names_listed_and_subdomains_of_a_leading_dot(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--allow-host example.com,.example.org");
    static const char *const allowed[] = {
        "example.com", "EXAMPLE.com.", "example.com:8080", "example.org", "a.example.org", "b.a.Example.Org.:443",
        "localhost",   "127.0.0.1:%d",
    };
    static const char *const refused[] = {
        "evil.example", "a.example.com", "example.com.evil.example", "badexample.org", "example.co", "example.orgx",
    };
    expect_hosts(&d, allowed, sizeof allowed / sizeof *allowed, 200);
    expect_hosts(&d, refused, sizeof refused / sizeof *refused, 403);
    stop(&d);
    start(&d, "--allow-host '*'");
    static const char *const any[] = { "evil.example:8080", "x", "EVIL.example.", "[evil.example]" };
    expect_hosts(&d, any, sizeof any / sizeof *any, 200);
    stop(&d);
}

/* An empty Host names no server: a malformed request (RFC 9110 7.2 asks for the authority of an http URI), 400,
 * not the 403 of a name not allowed. */
static void an_empty_host_header_should_get_400_naming_it(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    static const char *const empty[] = { "", " " };
    for (size_t i = 0; i < sizeof empty / sizeof *empty; i++) {
        raw_reply r = ask_host(&d, empty[i], "GET", "/livez", NULL, NULL, 0, 5000);
        expect_problem(&r, 400, NULL, "Host header is empty");
        raw_reply_free(&r);
    }
    expect_livez(&d);
    stop(&d);
}

/* RFC 9112 3.2.2: a server must accept a target in absolute form (http://host/path), and take its host from the
 * target, not from the Host header: the path is routed as in origin form, and the rebinding check applies to the
 * target's host. */
static void an_absolute_form_target_should_be_routed_and_its_host_checked(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    char target[128];
    snprintf(target, sizeof target, "http://127.0.0.1:%d/livez", d.port);
    assert_int_equal(status_as(&d, "localhost", target), 200);
    assert_int_equal(status_as(&d, "localhost", "HTTPS://localhost/presets"), 200);
    assert_int_equal(status_as(&d, "localhost", "http://localhost"), 200);   /* the front-end's page */
    assert_int_equal(status_as(&d, "localhost", "http://localhost/nowhere"), 404);
    /* The target's host decides, whatever Host says. */
    snprintf(target, sizeof target, "http://evil.example:%d/livez", d.port);
    raw_reply r = ask_host(&d, "localhost", "GET", target, NULL, NULL, 0, 5000);
    expect_problem(&r, 403, NULL, "evil.example");
    raw_reply_free(&r);
    assert_int_equal(status_as(&d, "evil.example", "http://localhost/livez"), 200);
    /* Not a URI of this server's schemes: a path like any other. */
    assert_int_equal(status_as(&d, "localhost", "ftp://localhost/livez"), 404);
    /* An authority with userinfo or %-escapes, or too long to hold whole, is refused, not cut or decoded into
     * another host (review: 117 a's + ".localhost.evil.com" was cut to a name under .localhost, and
     * localhost%2f@evil.com decoded to localhost). */
    char longhost[300];
    memset(longhost, 'a', 117);
    snprintf(longhost + 117, sizeof longhost - 117, ".localhost.evil.com");
    char lt[400];
    snprintf(lt, sizeof lt, "http://%s/livez", longhost);
    static const char *const bad[] = { "http://localhost%2f@evil.example/livez", "http://user@localhost/livez",
                                       "http://local%68ost/livez", NULL };
    for (int i = 0; i < 4; i++) {
        raw_reply b = ask_host(&d, "localhost", "GET", i < 3 ? bad[i] : lt, NULL, NULL, 0, 5000);
        expect_problem(&b, 400, NULL, "request target's host");
        raw_reply_free(&b);
    }
    /* A missing Host beside an absolute target is named as such, not as an empty target host. */
    char req[256];
    snprintf(req, sizeof req, "GET http://localhost:%d/livez HTTP/1.1\r\nConnection: close\r\n\r\n", d.port);
    r = raw_request(d.port, req, strlen(req), 5000);
    expect_problem(&r, 400, NULL, "exactly one Host header");
    raw_reply_free(&r);
    stop(&d);
}

static void the_openapi_document_should_be_served(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "");
    raw_reply r = get(&d, "/openapi.yaml");
    assert_int_equal(r.status, 200);
    if (strncmp(r.body, "openapi: 3.1", 12))
        fail_msg("/openapi.yaml starts with %.40s", r.body);
    assert_non_null(strstr(r.body, "/solve"));
    raw_reply_free(&r);
    stop(&d);
}

/* ~40 bytes bought 2 s of a solver thread (QA): fig. 4a with p0 = 1e300 ran its properties to --job-timeout
 * (503), and a glb of p0 = 3e299 computed them for 0.9 s before its float32 refusal, which takes no work. Both
 * are 422 now, the properties refused from their first sample and the glb before them (props;dur=0.000). */
static void a_solid_beyond_a_double_should_be_refused_422_without_its_properties_work(void **state)
{
    (void)state;
    daemon_t d;
    start(&d, "--job-timeout 2");
    for (int k = 0; k < 2; k++) {   /* a refusal is not cached: the second costs as little */
        raw_reply r = post(&d, "/solve", "{\"preset\":\"fig4a\",\"params\":{\"p0\":1e300}}");
        expect_problem(&r, 422, ANY_POINTER, "too large");
        if (r.first_response > 0.5)
            fail_msg("the refusal took %.2f s", r.first_response);
        raw_reply_free(&r);
    }
    raw_reply r = post(&d, "/solve?format=glb", "{\"preset\":\"fig4a\",\"params\":{\"p0\":3e299}}");
    expect_problem(&r, 422, ANY_POINTER, "float32");
    char st[512];
    if (!raw_header(&r, "Server-Timing", st, sizeof st))
        fail_msg("no Server-Timing");
    if (!strstr(st, "props;dur=0.000"))
        fail_msg("the glb refused for float32 computed the properties first: %s", st);
    raw_reply_free(&r);
    /* A solid near the limit does its properties' work before their refusal: once. The failure is kept with
     * the cached solid, so a repeat (and a glb, which computed them again after their NULL) costs nothing. */
    static const char near[] = "{\"preset\":\"fig4a\",\"params\":{\"p0\":1e85}}";
    static const char *const again[] = { "/solve", "/solve?format=vts&res=4" };
    double first = 0.0;   /* the first request's properties, ms: the work (3 ms optimised, more sanitised) */
    for (int k = 0; k < 3; k++) {
        r = post(&d, k ? again[k - 1] : "/solve", near);
        expect_problem(&r, 422, ANY_POINTER, "too large");
        if (!raw_header(&r, "Server-Timing", st, sizeof st))
            fail_msg("no Server-Timing");
        const char *pd = strstr(st, "props;dur="), *od = strstr(st, "output;dur=");
        assert_true(pd && od);
        const double props = strtod(pd + strlen("props;dur="), NULL), output = strtod(od + strlen("output;dur="), NULL);
        raw_reply_free(&r);
        if (!k)
            first = props;
        else if (!(props + output < first / 20))   /* a repeat ran them again, in props or in the output */
            fail_msg("request %d of a solid whose properties fail: props %g ms, output %g ms, the first's %g ms", k,
                     props, output, first);
    }
    assert_true(first > 0.0);
    stop(&d);
}

/* Each test, then the daemon it left running if it failed. */
#define T(test) cmocka_unit_test_teardown(test, kill_leftover)

int main(void)
{
    const struct CMUnitTest tests[] = {
        T(livez_should_answer_while_the_only_polling_thread_sends_a_heavy_stream),
        T(a_body_sent_one_byte_each_half_second_should_be_cut_off_at_the_request_timeout),
        T(slow_bodies_at_the_per_address_limit_should_not_lock_the_address_out),
        T(slow_heads_at_the_per_address_limit_should_not_lock_the_address_out),
        T(a_connection_over_max_conns_should_get_a_prompt_503_while_the_others_are_served),
        T(an_oversized_body_with_expect_100_continue_should_get_413_before_any_byte_of_it),
        T(a_client_that_writes_all_its_body_before_reading_should_read_the_413_20_of_20_times),
        T(a_chunked_body_growing_over_the_limit_should_get_a_readable_413),
        T(sigterm_should_answer_queued_jobs_503_cancel_the_running_one_and_exit_within_grace_plus_one),
        T(a_job_over_its_deadline_should_be_cancelled_with_a_problem_that_says_why),
        T(a_client_gone_while_its_job_runs_should_stop_the_job_and_be_logged_499),
        T(a_request_pipelined_while_a_job_runs_should_not_cancel_it),
        T(requests_over_the_work_or_memory_budget_should_be_422_naming_the_flag),
        T(every_flag_should_take_the_equals_form_and_unknown_arguments_should_exit_2_naming_them),
        T(eval_far_outside_the_cube_should_be_422_naming_the_point_and_never_write_nan),
        T(the_response_cache_should_key_on_the_whole_query),
        T(nul_in_a_path_query_or_body_should_be_400),
        T(a_content_encoded_body_should_be_415_naming_the_coding),
        T(a_keep_alive_connection_should_stay_open_for_its_timeout),
        T(invalid_utf8_anywhere_should_give_a_problem_in_valid_json_and_utf8),
        T(an_unknown_query_parameter_should_be_400_naming_it_and_the_known_ones),
        T(bad_framing_should_get_one_error_response_or_a_close_within_2_s),
        T(the_access_log_should_escape_control_characters_and_carry_the_request_id),
        T(the_json_log_format_should_write_one_json_object_per_line),
        T(request_ids_should_be_echoed_when_sane_and_replaced_otherwise),
        T(server_timing_should_add_up_to_most_of_the_wall_time_of_a_new_solve),
        T(a_post_from_a_disallowed_origin_should_get_403_and_solve_nothing),
        T(an_empty_host_header_should_get_400_naming_it),
    T(an_absolute_form_target_should_be_routed_and_its_host_checked),
    T(the_openapi_document_should_be_served),
        T(a_host_name_not_allowed_should_get_403_naming_the_header_the_value_and_the_flag),
        T(ip_literals_and_localhost_should_be_allowed_by_default),
        T(allow_host_should_allow_the_names_listed_and_subdomains_of_a_leading_dot),
        T(a_solid_beyond_a_double_should_be_refused_422_without_its_properties_work),
    };
    test_filter_from_env();
    return cmocka_run_group_tests(tests, setup, teardown);
}
