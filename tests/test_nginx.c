/*
 * test_nginx.c: deploy/nginx.conf in front of pdesolidd on loopback, under the
 * attacks that libmicrohttpd 0.9.75 cannot hold by itself: slowloris on the
 * headers, stalled and trickled bodies, request smuggling (Transfer-Encoding
 * with Content-Length, two Content-Lengths, bad lengths), oversize bodies and
 * bursts. Each test starts the sanitised daemon (tests/support.c) and Debian's
 * nginx, unprivileged in a temporary prefix, with a copy of the shipped file in
 * which only the ports and, for speed, the two client timeouts (10 s to 2 s)
 * are rewritten. A test that must see exactly what reaches the daemon puts a
 * recording upstream of its own in the daemon's place. Skipped when
 * /usr/sbin/nginx is absent (.ci/deps installs Debian's nginx).
 */
#define _GNU_SOURCE   /* strcasestr */
#include <arpa/inet.h>
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
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>
#include <cmocka.h>
#include <curl/curl.h>

#include "support.h"

#ifndef NGINX
#define NGINX "/usr/sbin/nginx"
#endif
#define SHIPPED "deploy/nginx.conf"
/* The test copy's client_header_timeout and client_body_timeout, in seconds. */
#define HEADER_TIMEOUT 2.0
#define BODY_TIMEOUT 2.0

static char dir[] = "/tmp/pdesolid-nginx-XXXXXX";

/* ---- nginx in a temporary prefix ---- */

enum { KEEP, FRONT_PORT, UPSTREAM_PORT };

/* What the test copy changes; each shipped line must be there `times` times (every one is changed). */
static const struct {
    const char *shipped;
    const char *test;
    int port;
    int times;
} rewrites[] = {
    { "listen 80;", "listen 127.0.0.1:%d;", FRONT_PORT, 1 },
    { "listen [::]:80;", "", KEEP, 1 },
    { "server 127.0.0.1:8080;", "server 127.0.0.1:%d;", UPSTREAM_PORT, 2 },   /* both upstreams */
    { "client_header_timeout 10s;", "client_header_timeout 2s;", KEEP, 1 },
    { "client_body_timeout 10s;", "client_body_timeout 2s;", KEEP, 1 },
    { "proxy_cache_path /var/cache/nginx/pdesolid ", "proxy_cache_path cache ", KEEP, 1 },   /* in the prefix */
};

/* What the tests below rely on and the copy keeps as shipped. */
static const char *const shipped_directives[] = {
    "upstream pdesolidd {",
    "client_max_body_size 1m;",
    "limit_req zone=pdesolid_req burst=40 nodelay;",
    "limit_req_status 429;",
    "limit_conn pdesolid_conn 32;",
    "reset_timedout_connection on;",
    "proxy_request_buffering on;",
    "proxy_buffering on;",
    "proxy_intercept_errors off;",
    "proxy_connect_timeout",
    "proxy_read_timeout",
    "proxy_send_timeout",
    "proxy_set_header X-Request-Id $pdesolid_request_id;",
    "proxy_set_header X-Forwarded-For $remote_addr;",
    "proxy_set_header X-Forwarded-Proto $scheme;",
    "proxy_set_header Host $http_host;",
    "gzip on;",
    "gzip_types application/json application/problem+json",
    "error_page 400 494 /_problem/400;",
    "error_page 413 /_problem/413;",
    "error_page 429 /_problem/429;",
    "error_page 502 /_problem/502;",
    "hash $pdesolid_id consistent;",
    "proxy_next_upstream error timeout http_502 http_503 http_504 non_idempotent;",
    "proxy_cache pdesolid_cache;",
};

typedef struct {
    int pid;
    int port;
    char base[64];
    char log[192];   /* nginx's error log */
} front_t;

/* What the running test started, so that a failed test, which cmocka leaves by longjmp, still stops it. */
static struct {
    front_t *front;
    daemon_t *daemon;
    void *recorder;
} live;

static int count(const char *text, const char *what)
{
    int n = 0;
    for (const char *p = text; (p = strstr(p, what)); p += strlen(what))
        n++;
    return n;
}

/* A socket bound to a loopback port of the kernel's choice, and that port. */
static int bind_loopback(int *port)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = { .sin_family = AF_INET };
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof a), 0);
    socklen_t len = sizeof a;
    getsockname(fd, (struct sockaddr *)&a, &len);
    *port = ntohs(a.sin_port);
    return fd;
}

/* A loopback port nothing listens on now (the kernel's choice, then closed). */
static int free_port(void)
{
    int port;
    close(bind_loopback(&port));
    return port;
}

/* 1 when something listens on 127.0.0.1:port. */
static int listening(int port)
{
    int fd = raw_dial(port);
    if (fd >= 0)
        close(fd);
    return fd >= 0;
}

static int dial(int port)
{
    int fd = raw_dial(port);
    assert_true(fd >= 0);
    return fd;
}

/* The shipped file with the rewrites for these ports, or a failed test if a line is missing. */
static char *test_copy(int front_port, int upstream_port)
{
    char *text = read_file(SHIPPED, NULL);
    if (!text)
        fail_msg("cannot read %s (run the tests from the repository's root)", SHIPPED);
    for (size_t i = 0; i < sizeof rewrites / sizeof *rewrites; i++) {
        if (count(text, rewrites[i].shipped) != rewrites[i].times)
            fail_msg("%s has \"%s\" %d times, not %d", SHIPPED, rewrites[i].shipped,
                     count(text, rewrites[i].shipped), rewrites[i].times);
        char to[96];
        int port = rewrites[i].port == FRONT_PORT ? front_port : upstream_port;
        snprintf(to, sizeof to, rewrites[i].test, port);
        for (int k = 0; k < rewrites[i].times; k++) {
            char *at = strstr(text, rewrites[i].shipped);
            size_t head = (size_t)(at - text), from = strlen(rewrites[i].shipped), tail = strlen(at + from);
            char *out = malloc(head + strlen(to) + tail + 1);
            memcpy(out, text, head);
            memcpy(out + head, to, strlen(to));
            memcpy(out + head + strlen(to), at + from, tail + 1);
            free(text);
            text = out;
        }
    }
    return text;
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

/*
 * The main file that Debian's /etc/nginx/nginx.conf stands for, with its http
 * settings (sendfile, mime types, gzip) and every path in the test prefix.
 */
static void write_main(const char *conf, const char *site, const char *log, int k)
{
    char text[1024];
    snprintf(text, sizeof text,
             "worker_processes 1;\n"
             "error_log %s info;\n"
             "events { worker_connections 512; }\n"
             "http {\n"
             "    sendfile on;\n"
             "    tcp_nopush on;\n"
             "    include /etc/nginx/mime.types;\n"
             "    default_type application/octet-stream;\n"
             "    gzip on;\n"
             "    access_log %s/access%d.log;\n"
             "    client_body_temp_path %s/body;\n"
             "    proxy_temp_path %s/proxy;\n"
             "    fastcgi_temp_path %s/fastcgi;\n"
             "    uwsgi_temp_path %s/uwsgi;\n"
             "    scgi_temp_path %s/scgi;\n"
             "    include %s;\n"
             "}\n",
             log, dir, k, dir, dir, dir, dir, dir, site);
    write_text(conf, text);
}

static void need_nginx(void)
{
    if (access(NGINX, X_OK) != 0) {
        print_message("skipped: " NGINX " is not installed (apt-get install nginx, or make deps)\n");
        skip();
    }
}

/*
 * nginx with the test copy in front of 127.0.0.1:upstream_port. As root, the
 * workers run as nginx's default user (nobody), so the prefix must let them in.
 */
static void front_start(front_t *f, int upstream_port)
{
    static int n;
    for (int attempt = 0; attempt < 3; attempt++) {
        int k = n++;
        f->port = free_port();
        char site[160], conf[160], err[160], cmd[1024];
        snprintf(site, sizeof site, "%s/site%d.conf", dir, k);
        snprintf(conf, sizeof conf, "%s/nginx%d.conf", dir, k);
        snprintf(err, sizeof err, "%s/nginx%d.stderr", dir, k);
        snprintf(f->log, sizeof f->log, "%s/nginx%d.log", dir, k);
        char *text = test_copy(f->port, upstream_port);
        write_text(site, text);
        free(text);
        write_main(conf, site, f->log, k);
        snprintf(cmd, sizeof cmd, "exec %s -p %s -c %s -e %s -g 'daemon off; pid %s/nginx%d.pid;' >/dev/null 2>%s", NGINX,
                 dir, conf, f->log, dir, k, err);
        pid_t pid = fork();
        if (pid == 0) {
            child_dies_with_parent();
            execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
            _exit(127);
        }
        f->pid = (int)pid;
        int st;
        for (int i = 0; i < 200; i++) {
            if (listening(f->port)) {
                snprintf(f->base, sizeof f->base, "http://127.0.0.1:%d", f->port);
                live.front = f;
                return;
            }
            if (waitpid(pid, &st, WNOHANG) == pid)
                break;
            usleep(25000);
        }
        char *log = read_file(f->log, NULL);
        int in_use = log && strstr(log, "Address already in use");
        if (!in_use) {
            kill(pid, SIGKILL);
            waitpid(pid, &st, 0);
            char *e = read_file(err, NULL);
            fail_msg("nginx did not start:\n%s%s", log ? log : "", e ? e : "");
        }
        free(log);
        waitpid(pid, &st, WNOHANG);
    }
    fail_msg("nginx found no free port in 3 tries");
}

/* SIGTERM, a bounded wait, and an error log without alerts or emergencies. */
static void front_stop(front_t *f)
{
    live.front = NULL;
    kill(f->pid, SIGTERM);
    int st = 0, done = 0;
    for (int i = 0; i < 200 && !done; i++) {
        done = waitpid(f->pid, &st, WNOHANG) == f->pid;
        if (!done)
            usleep(25000);
    }
    if (!done) {
        kill(f->pid, SIGKILL);
        waitpid(f->pid, &st, 0);
        fail_msg("nginx did not stop within 5 s of SIGTERM");
    }
    char *log = read_file(f->log, NULL);
    assert_non_null(log);
    if (strstr(log, "[alert]") || strstr(log, "[emerg]") || strstr(log, "[crit]"))
        fail_msg("nginx's error log has alerts:\n%s", log);
    free(log);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
}

/* ---- HTTP through libcurl (tests/support.c) ---- */

#define FIG4A "{\"preset\":\"fig4a\"}"

/* POST FIG4A to base and path, with Accept-Encoding (curl then decodes the body) or NULL. */
static http_reply solve(const char *base, const char *path, const char *encoding)
{
    return http_request(NULL, base, "POST", path, FIG4A, strlen(FIG4A), NULL, encoding);
}

static http_reply get(void *c, const char *base, const char *path)
{
    return http_request(c, base, "GET", path, NULL, 0, NULL, NULL);
}

static int is_hex32(const char *s)
{
    return strlen(s) == 32 && strspn(s, "0123456789abcdef") == 32;
}

/*
 * An RFC 9457 problem from nginx: the status, application/problem+json, a
 * body that is JSON with that status, a title and a detail, and the request id
 * of the X-Request-Id header.
 */
static void expect_problem(long status_got, const char *headers, const char *body, long status)
{
    if (status_got != status)
        fail_msg("status %ld, expected %ld:\n%s%s", status_got, status, headers, body);
    char ct[128], rid[128];
    assert_true(http_header(headers, "Content-Type", ct, sizeof ct));
    assert_string_equal(ct, "application/problem+json");
    cJSON *p = cJSON_Parse(body);
    if (!p)
        fail_msg("not JSON: %s", body);
    assert_true(cJSON_IsNumber(cJSON_GetObjectItem(p, "status")));
    assert_int_equal(cJSON_GetObjectItem(p, "status")->valueint, status);
    assert_true(cJSON_IsString(cJSON_GetObjectItem(p, "title")));
    assert_true(strlen(cJSON_GetObjectItem(p, "detail")->valuestring) > 10);
    assert_true(http_header(headers, "X-Request-Id", rid, sizeof rid));
    assert_string_equal(cJSON_GetObjectItem(p, "request_id")->valuestring, rid);
    cJSON_Delete(p);
}

/* ---- raw sockets ---- */

/* One request on a new connection, and the whole answer up to the close. */
static void raw(int port, const char *req, char *buf, size_t cap)
{
    int fd = dial(port);
    raw_send_all(fd, req, strlen(req));
    long n = raw_read_to_close(fd, buf, cap, 10);
    close(fd);
    if (n <= 0)
        fail_msg("no answer (%ld) to %s", n, req);
}

static long raw_status(const char *resp)
{
    return strncmp(resp, "HTTP/1.1 ", 9) ? -1 : strtol(resp + 9, NULL, 10);
}

static const char *raw_body(const char *resp)
{
    const char *p = strstr(resp, "\r\n\r\n");
    return p ? p + 4 : "";
}

/* ---- a recording upstream, in the daemon's place ---- */

typedef struct {
    int fd;                  /* listening */
    int port;
    volatile int stop;
    int accepted;            /* connections */
    double first_at;         /* when the first was accepted, on mono_now()'s clock */
    char request[8192];      /* the last request, headers and body */
    pthread_mutex_t lock;
    pthread_t thread;
} recorder_t;

/* Answers each request with {} and a stray X-Request-Id, then closes; until stop, at most 30 s. */
static void *recorder_run(void *arg)
{
    recorder_t *r = arg;
    double end = mono_now() + 30;
    while (!r->stop && mono_now() < end) {
        struct pollfd p = { r->fd, POLLIN, 0 };
        if (poll(&p, 1, 50) <= 0)
            continue;
        int c = accept(r->fd, NULL, NULL);
        if (c < 0)
            continue;
        pthread_mutex_lock(&r->lock);
        if (r->accepted++ == 0)
            r->first_at = mono_now();
        pthread_mutex_unlock(&r->lock);
        char buf[8192];
        size_t n = 0;
        const char *hend = NULL;
        long want = -1;
        while (n < sizeof buf - 1) {
            struct pollfd q = { c, POLLIN, 0 };
            if (poll(&q, 1, 5000) <= 0)
                break;
            ssize_t k = recv(c, buf + n, sizeof buf - 1 - n, 0);
            if (k <= 0)
                break;
            n += (size_t)k;
            buf[n] = '\0';
            if (!hend && (hend = strstr(buf, "\r\n\r\n"))) {
                char cl[32];
                want = http_header(buf, "Content-Length", cl, sizeof cl) ? atol(cl) : 0;
            }
            if (hend && (long)(n - (size_t)(hend + 4 - buf)) >= want)
                break;
        }
        buf[n] = '\0';
        pthread_mutex_lock(&r->lock);
        memcpy(r->request, buf, n + 1);
        pthread_mutex_unlock(&r->lock);
        const char *answer = "HTTP/1.1 200 OK\r\nContent-Type: application/json\r\nContent-Length: 2\r\n"
                             "X-Request-Id: from-the-upstream\r\nConnection: close\r\n\r\n{}";
        raw_send_all(c, answer, strlen(answer));
        close(c);
    }
    return NULL;
}

static void recorder_start(recorder_t *r)
{
    memset(r, 0, sizeof *r);
    pthread_mutex_init(&r->lock, NULL);
    r->fd = bind_loopback(&r->port);
    assert_int_equal(listen(r->fd, 16), 0);
    pthread_create(&r->thread, NULL, recorder_run, r);
    live.recorder = r;
}

static void recorder_stop(recorder_t *r)
{
    live.recorder = NULL;
    r->stop = 1;
    pthread_join(r->thread, NULL);
    close(r->fd);
    pthread_mutex_destroy(&r->lock);
}

static int recorder_accepted(recorder_t *r)
{
    pthread_mutex_lock(&r->lock);
    int n = r->accepted;
    pthread_mutex_unlock(&r->lock);
    return n;
}

/* ---- the tests ---- */

static int setup(void **state)
{
    (void)state;
    curl_global_init(CURL_GLOBAL_ALL);
    signal(SIGPIPE, SIG_IGN);
    if (tmpdir_make(dir))
        return -1;
    /* As root, nginx's workers are nobody: they must reach the temporary paths. */
    return geteuid() == 0 ? chmod(dir, 0711) : 0;
}

static int teardown(void **state)
{
    (void)state;
    curl_global_cleanup();
    return tmpdir_remove(dir);
}

/* nginx in front of the daemon started with args (static storage: stop_leftovers reaches them after a failure). */
static void pair_start_with(daemon_t *d, front_t *f, const char *args)
{
    need_nginx();
    daemon_start(d, dir, args);
    live.daemon = d;
    front_start(f, d->port);
}

static void pair_start(daemon_t *d, front_t *f)
{
    pair_start_with(d, f, "");
}

static void pair_stop(daemon_t *d, front_t *f)
{
    front_stop(f);
    live.daemon = NULL;
    daemon_stop(d);
}

/* After what a test threw at it, a solve through nginx still answers 200; then both stop. */
static void pair_stop_serving(daemon_t *d, front_t *f)
{
    http_reply r = solve(f->base, "/solve", NULL);
    assert_int_equal(r.status, 200);
    free(r.body);
    pair_stop(d, f);
}

/* nginx in front of a recording upstream. */
static void recorded_start(recorder_t *up, front_t *f)
{
    need_nginx();
    recorder_start(up);
    front_start(f, up->port);
}

static void recorded_stop(recorder_t *up, front_t *f)
{
    front_stop(f);
    recorder_stop(up);
}

/* After each test: whatever a failed test left running. */
static int stop_leftovers(void **state)
{
    (void)state;
    int st;
    if (live.front) {
        kill(live.front->pid, SIGTERM);   /* the master stops its workers */
        for (int i = 0; i < 200 && waitpid(live.front->pid, &st, WNOHANG) != live.front->pid; i++)
            usleep(25000);
        kill(live.front->pid, SIGKILL);
        waitpid(live.front->pid, &st, WNOHANG);
    }
    if (live.daemon) {
        kill(live.daemon->pid, SIGKILL);
        waitpid(live.daemon->pid, &st, 0);
    }
    if (live.recorder)
        recorder_stop(live.recorder);
    memset(&live, 0, sizeof live);
    return 0;
}

static void the_shipped_conf_should_have_every_directive_the_tests_rely_on(void **state)
{
    (void)state;
    need_nginx();
    char *text = read_file(SHIPPED, NULL);
    assert_non_null(text);
    for (size_t i = 0; i < sizeof shipped_directives / sizeof *shipped_directives; i++)
        if (!strstr(text, shipped_directives[i]))
            fail_msg("%s lacks \"%s\"", SHIPPED, shipped_directives[i]);
    free(text);
    /* And nginx -t takes the test copy. */
    char *copy = test_copy(free_port(), 8080);
    char site[160], conf[160], cmd[1024];
    snprintf(site, sizeof site, "%s/site-t.conf", dir);
    snprintf(conf, sizeof conf, "%s/nginx-t.conf", dir);
    write_text(site, copy);
    free(copy);
    char log[160];
    snprintf(log, sizeof log, "%s/t.log", dir);
    write_main(conf, site, log, 99);
    snprintf(cmd, sizeof cmd, "%s -q -t -p %s -c %s -e %s -g 'pid %s/t.pid;' 2>&1", NGINX, dir, conf, log, dir);
    assert_int_equal(system(cmd), 0);
}

static void a_solve_through_nginx_should_be_byte_identical_to_direct(void **state)
{
    (void)state;
    static daemon_t d;
    static front_t f;
    pair_start(&d, &f);
    static const char *const paths[] = { "/solve", "/solve?format=f32&res=64", "/solve?format=glb&res=16" };
    for (size_t i = 0; i < sizeof paths / sizeof *paths; i++) {
        http_reply a = solve(d.base, paths[i], NULL);
        http_reply b = solve(f.base, paths[i], NULL);
        assert_int_equal(a.status, 200);
        assert_int_equal(b.status, 200);
        assert_int_equal(a.len, b.len);
        assert_memory_equal(a.body, b.body, a.len);
        char ea[128], eb[128], ia[64], ib[64];
        assert_true(http_header(a.headers, "ETag", ea, sizeof ea) && http_header(b.headers, "ETag", eb, sizeof eb));
        assert_string_equal(ea, eb);
        assert_true(http_header(a.headers, "X-Solid-Id", ia, sizeof ia));
        assert_true(http_header(b.headers, "X-Solid-Id", ib, sizeof ib));
        assert_string_equal(ia, ib);
        /* nginx's request id, once. */
        assert_int_equal(count(b.headers, "X-Request-Id:"), 1);
        char rid[64];
        assert_true(http_header(b.headers, "X-Request-Id", rid, sizeof rid));
        assert_true(is_hex32(rid));
        free(a.body);
        free(b.body);
    }
    /* The 64^3 f32 streamed through whole: 12 bytes a point. */
    http_reply g = solve(f.base, "/solve?format=f32&res=64", NULL);
    assert_int_equal(g.len, 12u * 64 * 64 * 64);
    free(g.body);
    pair_stop(&d, &f);
}

/* GET /solids/ID?...: immutable per id and query, so the second is nginx's (HIT) and the same bytes;
 * another query is another entry; the eval POST is never cached. */
static void an_ids_answers_should_be_cached_by_nginx_and_answer_if_none_match(void **state)
{
    (void)state;
    static daemon_t d;
    static front_t f;
    pair_start(&d, &f);
    http_reply a = solve(f.base, "/solve", NULL);
    assert_int_equal(a.status, 200);
    char id[64], path[128], st[32];
    assert_true(http_header(a.headers, "X-Solid-Id", id, sizeof id));
    free(a.body);
    snprintf(path, sizeof path, "/solids/%s?format=glb&res=12", id);
    http_reply first = get(NULL, f.base, path), second = get(NULL, f.base, path);
    assert_int_equal(first.status, 200);
    assert_int_equal(second.status, 200);
    assert_true(http_header(first.headers, "X-Cache-Status", st, sizeof st));
    assert_string_equal(st, "MISS");
    assert_true(http_header(second.headers, "X-Cache-Status", st, sizeof st));
    assert_string_equal(st, "HIT");
    assert_int_equal(first.len, second.len);
    assert_memory_equal(first.body, second.body, first.len);
    /* A client that has it: 304 from the cache, by the daemon's ETag. */
    char etag[128], inm[160];
    assert_true(http_header(first.headers, "ETag", etag, sizeof etag));
    snprintf(inm, sizeof inm, "If-None-Match: %s", etag);
    http_reply cond = http_request(NULL, f.base, "GET", path, NULL, 0, inm, NULL);
    assert_int_equal(cond.status, 304);
    assert_int_equal(cond.len, 0);
    free(cond.body);
    free(first.body);
    free(second.body);
    snprintf(path, sizeof path, "/solids/%s?format=glb&res=13", id);
    http_reply other = get(NULL, f.base, path);
    assert_true(http_header(other.headers, "X-Cache-Status", st, sizeof st));
    assert_string_equal(st, "MISS");
    free(other.body);
    snprintf(path, sizeof path, "/solids/%s/eval", id);
    for (int i = 0; i < 2; i++) {
        static const char pts[] = "{\"points\": [[0.5, 0.5, 0.5]]}";
        http_reply e = http_request(NULL, f.base, "POST", path, pts, strlen(pts), NULL, NULL);
        assert_int_equal(e.status, 200);
        assert_true(!http_header(e.headers, "X-Cache-Status", st, sizeof st) || strcmp(st, "HIT") != 0);
        free(e.body);
    }
    pair_stop(&d, &f);
}

static void json_should_be_gzipped_when_asked_and_binary_outputs_never(void **state)
{
    (void)state;
    static daemon_t d;
    static front_t f;
    pair_start(&d, &f);
    static const struct {
        const char *path;
        const char *encoding;   /* Accept-Encoding, or NULL for none */
        int gzipped;
    } rows[] = {
        { "/solve", "gzip", 1 },
        { "/solve?format=grid&res=8", "gzip", 1 },
        { "/solve", NULL, 0 },
        { "/solve?format=f32&res=16", "gzip", 0 },
        { "/solve?format=glb&res=16", "gzip", 0 },
    };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        http_reply a = solve(d.base, rows[i].path, NULL);
        http_reply b = solve(f.base, rows[i].path, rows[i].encoding);
        assert_int_equal(b.status, 200);
        char ce[64] = "";
        http_header(b.headers, "Content-Encoding", ce, sizeof ce);
        if (strcmp(ce, rows[i].gzipped ? "gzip" : ""))
            fail_msg("%s with Accept-Encoding %s: Content-Encoding \"%s\"", rows[i].path,
                     rows[i].encoding ? rows[i].encoding : "(none)", ce);
        /* curl decoded it: the same bytes as the daemon's. */
        assert_int_equal(a.len, b.len);
        assert_memory_equal(a.body, b.body, a.len);
        free(a.body);
        free(b.body);
    }
    pair_stop(&d, &f);
}

#define SLOW_CONNS 16

static void slowloris_on_the_headers_should_be_cut_within_client_header_timeout(void **state)
{
    (void)state;
    static daemon_t d;
    static front_t f;
    pair_start(&d, &f);
    const char *req = "GET /livez HTTP/1.1\r\nHost: x\r\n\r\n";
    int fd[SLOW_CONNS];
    size_t sent[SLOW_CONNS] = { 0 };
    double opened[SLOW_CONNS], closed[SLOW_CONNS];
    for (int i = 0; i < SLOW_CONNS; i++) {
        fd[i] = dial(f.port);
        opened[i] = mono_now();
        closed[i] = -1;
    }
    double t0 = mono_now(), next_byte = t0;
    int open = SLOW_CONNS, answered = 0, normal = 0;
    /* One byte a second on each, until nginx has closed them all or four timeouts pass. */
    while (open > 0 && mono_now() - t0 < 4 * HEADER_TIMEOUT) {
        if (mono_now() >= next_byte) {
            for (int i = 0; i < SLOW_CONNS; i++)
                if (closed[i] < 0 && sent[i] < strlen(req) && send(fd[i], req + sent[i], 1, MSG_NOSIGNAL) == 1)
                    sent[i]++;
            next_byte += 1;
        }
        if (!normal && mono_now() - t0 > 1) {
            /* Meanwhile a normal client is served. */
            http_reply r = get(NULL, f.base, "/livez");
            normal = r.status == 200;
            free(r.body);
        }
        struct pollfd p[SLOW_CONNS];
        for (int i = 0; i < SLOW_CONNS; i++)
            p[i] = (struct pollfd){ closed[i] < 0 ? fd[i] : -1, POLLIN, 0 };
        if (poll(p, SLOW_CONNS, 100) <= 0)
            continue;
        for (int i = 0; i < SLOW_CONNS; i++) {
            if (!p[i].revents)
                continue;
            char buf[512];
            ssize_t k = recv(fd[i], buf, sizeof buf, 0);
            if (k > 0) {
                answered++;
                continue;
            }
            closed[i] = mono_now();
            close(fd[i]);
            open--;
        }
    }
    assert_true(normal);
    assert_int_equal(answered, 0);
    for (int i = 0; i < SLOW_CONNS; i++) {
        if (closed[i] < 0)
            fail_msg("connection %d still open after %.1f s, %zu bytes sent", i, mono_now() - opened[i], sent[i]);
        double held = closed[i] - opened[i];
        if (held < HEADER_TIMEOUT - 0.5 || held > HEADER_TIMEOUT + 1)
            fail_msg("connection %d held %.2f s, client_header_timeout is %.0f s", i, held, HEADER_TIMEOUT);
        assert_true(sent[i] < strlen(req));
    }
    pair_stop(&d, &f);
}

static void a_trickled_body_should_be_held_by_nginx_and_a_stalled_one_cut_within_client_body_timeout(void **state)
{
    (void)state;
    static recorder_t up;
    static front_t f;
    recorded_start(&up, &f);
    const char *body = FIG4A;
    char head[128];
    snprintf(head, sizeof head, "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: %zu\r\nConnection: close\r\n\r\n",
             strlen(body));
    int fd = dial(f.port);
    raw_send_all(fd, head, strlen(head));
    /*
     * One byte a second for longer than the timeout: client_body_timeout is the
     * longest silence between two reads, so nginx keeps reading, and the
     * upstream sees nothing of it.
     */
    double first = mono_now(), last = first;
    size_t sent = 0;
    for (; sent < 4; sent++) {
        raw_send_all(fd, body + sent, 1);
        last = mono_now();
        struct pollfd p = { fd, POLLIN, 0 };
        assert_int_equal(poll(&p, 1, 1000), 0);
    }
    assert_true(mono_now() - first > BODY_TIMEOUT);
    assert_int_equal(recorder_accepted(&up), 0);
    /* Then silence: cut within client_body_timeout (+1 s) of the last byte. */
    char buf[4096];
    long n = raw_read_to_close(fd, buf, sizeof buf, BODY_TIMEOUT + 3);
    double held = mono_now() - last;
    close(fd);
    if (n < 0 || held > BODY_TIMEOUT + 1 || held < BODY_TIMEOUT - 0.5)
        fail_msg("a stalled body was held %.2f s (read %ld), client_body_timeout is %.0f s", held, n, BODY_TIMEOUT);
    assert_int_equal(recorder_accepted(&up), 0);
    /* The same body in two halves a second apart reaches the upstream whole, once, after the last byte. */
    fd = dial(f.port);
    raw_send_all(fd, head, strlen(head));
    raw_send_all(fd, body, 9);
    struct pollfd p = { fd, POLLIN, 0 };
    assert_int_equal(poll(&p, 1, 1000), 0);
    assert_int_equal(recorder_accepted(&up), 0);
    double whole = mono_now();
    raw_send_all(fd, body + 9, strlen(body) - 9);
    n = raw_read_to_close(fd, buf, sizeof buf, 10);
    close(fd);
    assert_true(n > 0);
    assert_int_equal(raw_status(buf), 200);
    assert_int_equal(recorder_accepted(&up), 1);
    pthread_mutex_lock(&up.lock);
    assert_true(up.first_at >= whole);
    assert_string_equal(raw_body(up.request), body);
    pthread_mutex_unlock(&up.lock);
    recorded_stop(&up, &f);
}

static void trickled_bodies_from_one_address_should_be_capped_by_limit_conn(void **state)
{
    (void)state;
    static daemon_t d;
    static front_t f;
    pair_start(&d, &f);
    /* 32 requests whose bodies have not arrived are in progress; the 33rd from the address is refused. */
    const char *head = "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: 18\r\n\r\n{";
    int fd[32];
    for (int i = 0; i < 32; i++) {
        fd[i] = dial(f.port);
        raw_send_all(fd[i], head, strlen(head));
    }
    http_reply r = { 0 };
    for (int i = 0; i < 40; i++) {   /* until nginx has read all 32 headers */
        free(r.body);
        r = solve(f.base, "/solve", NULL);
        if (r.status == 429)
            break;
        usleep(25000);
    }
    expect_problem(r.status, r.headers, r.body, 429);
    char retry[16];
    assert_true(http_header(r.headers, "Retry-After", retry, sizeof retry));
    free(r.body);
    for (int i = 0; i < 32; i++)
        close(fd[i]);
    /* Once they are gone, the address is served again. */
    r.status = 0;
    for (int i = 0; i < 40 && r.status != 200; i++) {
        usleep(25000);
        r = solve(f.base, "/solve", NULL);
        if (r.status != 200)
            free(r.body);
    }
    assert_int_equal(r.status, 200);
    assert_non_null(strstr(r.body, "99268af08d93209af6cac24a6617fc90"));
    free(r.body);
    pair_stop(&d, &f);
}

/* Framing that libmicrohttpd 0.9.75 gets wrong or lets through, and what nginx answers. */
static const struct {
    const char *what;
    const char *request;
    long status;
} malformed[] = {
    { "Transfer-Encoding with Content-Length (smuggling)",
      "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: 18\r\nTransfer-Encoding: chunked\r\n\r\n"
      FIG4A,
      400 },
    { "Content-Length with Transfer-Encoding after it",
      "POST /solve HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: chunked\r\nContent-Length: 5\r\n\r\n"
      "0\r\n\r\n",
      400 },
    { "two equal Content-Lengths",
      "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: 18\r\nContent-Length: 18\r\n\r\n{\"preset\":\"fig4a\"}",
      400 },
    { "two different Content-Lengths",
      "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: 18\r\nContent-Length: 5\r\n\r\n{\"preset\":\"fig4a\"}",
      400 },
    { "a list as Content-Length", "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: 18, 18\r\n\r\n{}", 400 },
    { "a negative Content-Length", "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: -1\r\n\r\n{}", 400 },
    { "a word as Content-Length", "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: abc\r\n\r\n{}", 400 },
    { "2^64 as Content-Length",
      "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: 18446744073709551616\r\n\r\n{}", 400 },
    { "Transfer-Encoding gzip, chunked", "POST /solve HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: gzip, chunked\r\n\r\n",
      501 },
    { "a chunk size of 2^64 - 1",
      "POST /solve HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: chunked\r\n\r\nffffffffffffffff\r\n", 400 },
    { "no Host in HTTP/1.1", "GET /livez HTTP/1.1\r\n\r\n", 400 },
    { "two Hosts", "GET /livez HTTP/1.1\r\nHost: x\r\nHost: y\r\n\r\n", 400 },
    { "garbage for a request line", "garbage\r\n\r\n", 400 },
    { "HTTP/2.0 in plain text", "GET /livez HTTP/2.0\r\nHost: x\r\n\r\n", 505 },
};

static void malformed_framing_should_get_one_problem_and_never_reach_the_daemon(void **state)
{
    (void)state;
    static recorder_t up;
    static front_t f;
    recorded_start(&up, &f);
    static char buf[65536];
    for (size_t i = 0; i < sizeof malformed / sizeof *malformed; i++) {
        raw(f.port, malformed[i].request, buf, sizeof buf);
        if (raw_status(buf) != malformed[i].status)
            fail_msg("%s: expected %ld, got\n%s", malformed[i].what, malformed[i].status, buf);
        /* One status line (libmicrohttpd 0.9.75 sends two for a bad Content-Length). */
        if (strncmp(buf, "HTTP/", 5) || count(buf, "\nHTTP/") != 0)
            fail_msg("%s: not one answer:\n%s", malformed[i].what, buf);
        expect_problem(raw_status(buf), buf, raw_body(buf), malformed[i].status);
    }
    assert_int_equal(recorder_accepted(&up), 0);
    recorded_stop(&up, &f);
}

static void malformed_framing_should_leave_the_daemon_serving(void **state)
{
    (void)state;
    static daemon_t d;
    static front_t f;
    pair_start(&d, &f);
    static char buf[65536];
    for (size_t i = 0; i < sizeof malformed / sizeof *malformed; i++) {
        raw(f.port, malformed[i].request, buf, sizeof buf);
        assert_int_equal(raw_status(buf), malformed[i].status);
    }
    pair_stop_serving(&d, &f);
}

static void an_oversize_body_should_get_a_413_problem_that_the_client_can_read(void **state)
{
    (void)state;
    static daemon_t d;
    static front_t f;
    pair_start(&d, &f);
    size_t big = 2u << 20;
    char *body = malloc(big + 1);
    memset(body, ' ', big);
    body[big] = '\0';
    /* As a naive client does: the whole body first, then read the answer. */
    char head[128];
    snprintf(head, sizeof head, "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: %zu\r\n\r\n", big);
    static char buf[65536];
    for (int i = 0; i < 5; i++) {
        int fd = dial(f.port);
        struct timeval tv = { 5, 0 };
        setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
        raw_send_all(fd, head, strlen(head));
        raw_send_all(fd, body, big);
        long n = raw_read_to_close(fd, buf, sizeof buf, 10);
        close(fd);
        assert_true(n > 0);
        expect_problem(raw_status(buf), buf, raw_body(buf), 413);
    }
    /* With Expect: 100-continue, the 413 comes before the body. */
    const char *expect = "POST /solve HTTP/1.1\r\nHost: x\r\nContent-Length: 2097152\r\nExpect: 100-continue\r\n\r\n";
    raw(f.port, expect, buf, sizeof buf);
    expect_problem(raw_status(buf), buf, raw_body(buf), 413);
    /* And through libcurl. */
    http_reply r = http_request(NULL, f.base, "POST", "/solve", body, big, NULL, NULL);
    expect_problem(r.status, r.headers, r.body, 413);
    free(r.body);
    free(body);
    pair_stop_serving(&d, &f);
}

static void a_burst_above_limit_req_should_get_429_problems_and_health_checks_none(void **state)
{
    (void)state;
    static daemon_t d;
    static front_t f;
    pair_start(&d, &f);
    CURL *c = curl_easy_init();
    int ok = 0, limited = 0;
    double t0 = mono_now();
    /* Until ten are refused, in at most 400 requests (bounded even on a loaded machine). */
    for (int i = 0; i < 400 && limited < 10; i++) {
        http_reply r = get(c, f.base, "/version");
        if (r.status == 200) {
            ok++;
        } else {
            expect_problem(r.status, r.headers, r.body, 429);
            char retry[16];
            assert_true(http_header(r.headers, "Retry-After", retry, sizeof retry));
            limited++;
        }
        free(r.body);
    }
    double took = mono_now() - t0;
    /* rate=20r/s burst=40 nodelay: 41 at once, then 20 a second. */
    if (limited < 10 || ok < 41 || ok > 41 + (int)(20 * took) + 1)
        fail_msg("%d answered and %d refused in %.2f s", ok, limited, took);
    /* /livez is not limited, even now. */
    for (int i = 0; i < 60; i++) {
        http_reply r = get(c, f.base, "/livez");
        assert_int_equal(r.status, 200);
        free(r.body);
    }
    curl_easy_cleanup(c);
    pair_stop(&d, &f);
}

static void the_daemon_should_get_a_sane_request_id_and_forwarded_headers(void **state)
{
    (void)state;
    static recorder_t up;
    static front_t f;
    recorded_start(&up, &f);
    static const struct {
        const char *header;   /* the client's X-Request-Id, or NULL */
        const char *id;       /* the id sent on, or NULL for one of nginx's */
    } rows[] = {
        { "X-Request-Id: build-7.42:a_b", "build-7.42:a_b" },
        { NULL, NULL },
        { "X-Request-Id: two words", NULL },
        { "X-Request-Id: {\"json\":1}", NULL },
        { "X-Request-Id: 01234567890123456789012345678901234567890123456789012345678901234", NULL },
    };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        int before = recorder_accepted(&up);
        char headers[256];
        snprintf(headers, sizeof headers, "X-Forwarded-For: 203.0.113.9\n%s",
                 rows[i].header ? rows[i].header : "X-Other: 1");
        http_reply r = http_request(NULL, f.base, "GET", "/version", NULL, 0, headers, NULL);
        if (r.status < 0)
            fail_msg("curl: %s", curl_easy_strerror((CURLcode)-r.status));
        assert_int_equal(r.status, 200);
        assert_int_equal(recorder_accepted(&up), before + 1);
        char sent_id[128], got_id[128], xff[128], proto[32];
        pthread_mutex_lock(&up.lock);
        assert_true(http_header(up.request, "X-Request-Id", sent_id, sizeof sent_id));
        assert_int_equal(count(up.request, "X-Forwarded-For:"), 1);
        assert_true(http_header(up.request, "X-Forwarded-For", xff, sizeof xff));
        assert_true(http_header(up.request, "X-Forwarded-Proto", proto, sizeof proto));
        pthread_mutex_unlock(&up.lock);
        /* nginx is the first hop: the client's X-Forwarded-For is replaced, not appended to. */
        assert_string_equal(xff, "127.0.0.1");
        assert_string_equal(proto, "http");
        if (rows[i].id)
            assert_string_equal(sent_id, rows[i].id);
        else
            assert_true(is_hex32(sent_id));
        /* The client gets the id the daemon got, once: the daemon's own echo is replaced. */
        assert_int_equal(count(r.headers, "X-Request-Id:"), 1);
        assert_true(http_header(r.headers, "X-Request-Id", got_id, sizeof got_id));
        assert_string_equal(got_id, sent_id);
        free(r.body);
    }
    recorded_stop(&up, &f);
}

/* nginx passes the client's Host on: the daemon, started as a deployment starts it (--allow-host with nginx's
 * server_name), answers that name and refuses another with its own 403 problem, passed through (DNS rebinding). */
static void the_daemon_should_answer_its_allowed_name_through_nginx_and_refuse_others(void **state)
{
    (void)state;
    static daemon_t d;
    static front_t f;
    pair_start_with(&d, &f, "--allow-host solids.example.org");
    http_reply r = http_request(NULL, f.base, "GET", "/", NULL, 0, "Host: Solids.Example.org", NULL);
    assert_int_equal(r.status, 200);
    free(r.body);
    r = http_request(NULL, f.base, "POST", "/solve", FIG4A, strlen(FIG4A),
                     "Host: evil.example\nOrigin: http://evil.example", NULL);
    expect_problem(r.status, r.headers, r.body, 403);
    if (!strstr(r.body, "--allow-host evil.example"))
        fail_msg("the 403 does not say how to allow the name: %s", r.body);
    free(r.body);
    pair_stop_serving(&d, &f);   /* through 127.0.0.1:PORT, an address */
}

static void an_unreachable_daemon_should_give_a_502_problem(void **state)
{
    (void)state;
    need_nginx();
    static front_t f;
    front_start(&f, free_port());
    http_reply r = solve(f.base, "/solve", NULL);
    expect_problem(r.status, r.headers, r.body, 502);
    free(r.body);
    /* The error log says why (connect() failed); front_stop only rejects alerts. */
    front_stop(&f);
}

/* Each test, then whatever it left running if it failed. */
#define T(test) cmocka_unit_test_teardown(test, stop_leftovers)

int main(void)
{
    const struct CMUnitTest tests[] = {
        T(the_shipped_conf_should_have_every_directive_the_tests_rely_on),
        T(a_solve_through_nginx_should_be_byte_identical_to_direct),
        T(an_ids_answers_should_be_cached_by_nginx_and_answer_if_none_match),
        T(json_should_be_gzipped_when_asked_and_binary_outputs_never),
        T(slowloris_on_the_headers_should_be_cut_within_client_header_timeout),
        T(a_trickled_body_should_be_held_by_nginx_and_a_stalled_one_cut_within_client_body_timeout),
        T(trickled_bodies_from_one_address_should_be_capped_by_limit_conn),
        T(malformed_framing_should_get_one_problem_and_never_reach_the_daemon),
        T(malformed_framing_should_leave_the_daemon_serving),
        T(an_oversize_body_should_get_a_413_problem_that_the_client_can_read),
        T(a_burst_above_limit_req_should_get_429_problems_and_health_checks_none),
        T(the_daemon_should_get_a_sane_request_id_and_forwarded_headers),
        T(the_daemon_should_answer_its_allowed_name_through_nginx_and_refuse_others),
        T(an_unreachable_daemon_should_give_a_502_problem),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("nginx", tests, setup, teardown);
}
