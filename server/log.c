/*
 * log.c: the access log (log.h).
 *
 * DESIGN. A line is formatted on the caller's thread into its own memory
 * (on the stack unless it is long), then copied into the shared 64 KiB buffer
 * under a mutex held only for the copy. Writing to the fd is serialised by a
 * second mutex, io, which owns a spare buffer: a flush swaps the two buffers
 * under the first mutex and writes the full one under io alone, so writers
 * keep appending while the write(2) runs. Lock order: io, then lock. A line
 * longer than the buffer is written directly, after what is buffered, under io.
 */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>
#include <unistd.h>

#include "log.h"
#include "strict.h"

#define CAP (64u << 10)
#define PERIOD_NS 200000000L
#define STACK_LINE 4096

struct srv_log {
    int fd;
    srv_log_format fmt;
    pthread_mutex_t lock;   /* buf, len, stop */
    pthread_cond_t wake;    /* the flusher's sleep; signalled at stop */
    pthread_mutex_t io;     /* spare and every write(2) */
    char *buf, *spare;
    size_t len;
    int stop;
    pthread_t flusher;
};

/* ---- escaping ---- */

/* The length of the valid UTF-8 sequence at s (1 to 4), or 0 if s does not start one:
 * overlong forms, surrogates and code points over U+10FFFF are invalid (RFC 3629). */
/* The length of the valid UTF-8 character at s, NUL-terminated, or 0. */
static size_t utf8_seq(const unsigned char *s)
{
    size_t part;
    return api_utf8_char(s, strnlen((const char *)s, 4), &part);
}

static const char hexd[] = "0123456789abcdef";

static char *put_hex(char *o, const char *pre, unsigned c)
{
    while (*pre)
        *o++ = *pre++;
    *o++ = hexd[c >> 4];
    *o++ = hexd[c & 15];
    return o;
}

/* A C1 control (U+0080 to U+009F) or a bidirectional control (U+061C, U+200E, U+200F, U+202A to U+202E,
 * U+2066 to U+2069: a viewer shows the rest of a line after U+202E reversed) or a line or paragraph
 * separator (U+2028, U+2029: some viewers break the line there), the valid UTF-8 sequence
 * at p of n bytes: escaped, as C0 controls are. */
static int unseen(const unsigned char *p, size_t n)
{
    if (n == 2)
        return (p[0] == 0xc2 && p[1] < 0xa0) || (p[0] == 0xd8 && p[1] == 0x9c);
    return n == 3 && p[0] == 0xe2 &&
           ((p[1] == 0x80 && (p[2] == 0x8e || p[2] == 0x8f || (p[2] >= 0xa8 && p[2] <= 0xae))) ||
            (p[1] == 0x81 && p[2] >= 0xa6 && p[2] <= 0xa9));
}

/* At most 4 bytes out per byte in. With space, ' ' is escaped too (for fields outside quotes). */
static char *esc_text(char *o, const char *s, int space)
{
    const unsigned char *p = (const unsigned char *)s;
    while (*p) {
        unsigned c = *p;
        if (c > 0x20 && c < 0x7f) {
            if (c == '"' || c == '\\')
                *o++ = '\\';
            *o++ = (char)c;
            p++;
        } else if (c == ' ' && !space) {
            *o++ = ' ';
            p++;
        } else {
            size_t n = c >= 0x80 ? utf8_seq(p) : 0;
            if (unseen(p, n)) {
                for (size_t i = 0; i < n; i++)
                    o = put_hex(o, "\\x", p[i]);
            } else if (n == 0) {
                o = put_hex(o, "\\x", c);
                n = 1;
            } else {
                memcpy(o, p, n);
                o += n;
            }
            p += n;
        }
    }
    return o;
}

/* A JSON string with its quotes; at most 6 bytes out per byte in, plus 2. NULL is written null. */
static char *esc_json(char *o, const char *s)
{
    if (!s) {
        memcpy(o, "null", 4);
        return o + 4;
    }
    const unsigned char *p = (const unsigned char *)s;
    *o++ = '"';
    while (*p) {
        unsigned c = *p;
        if (c >= 0x20 && c < 0x7f) {
            if (c == '"' || c == '\\')
                *o++ = '\\';
            *o++ = (char)c;
            p++;
        } else if (c < 0x80) {
            o = put_hex(o, "\\u00", c);
            p++;
        } else {
            size_t n = utf8_seq(p);
            if (unseen(p, n)) {   /* as \\u: U+0080 to U+009F, U+061C, U+20xx */
                const unsigned cp = n == 2 ? ((c & 0x1fu) << 6) | (p[1] & 0x3fu)
                                           : ((c & 0x0fu) << 12) | ((p[1] & 0x3fu) << 6) | (p[2] & 0x3fu);
                o = put_hex(put_hex(o, "\\u", cp >> 8), "", cp & 0xff);
            } else if (n == 0) {
                memcpy(o, "\xef\xbf\xbd", 3);   /* U+FFFD */
                o += 3;
                n = 1;
            } else {
                memcpy(o, p, n);
                o += n;
            }
            p += n;
        }
    }
    *o++ = '"';
    return o;
}

static char *put_str(char *o, const char *s)
{
    size_t n = strlen(s);
    memcpy(o, s, n);
    return o + n;
}

/* RFC 3339, UTC, milliseconds: 24 bytes. The date and time of day are formatted once a second per thread. */
static char *put_time(char *o)
{
    static _Thread_local time_t last = (time_t)-1;
    static _Thread_local char sec[32];
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    if (ts.tv_sec != last) {
        struct tm tm;
        gmtime_r(&ts.tv_sec, &tm);
        strftime(sec, sizeof sec, "%Y-%m-%dT%H:%M:%S", &tm);
        last = ts.tv_sec;
    }
    o = put_str(o, sec);
    int ms = (int)(ts.tv_nsec / 1000000);
    *o++ = '.';
    *o++ = (char)('0' + ms / 100);
    *o++ = (char)('0' + ms / 10 % 10);
    *o++ = (char)('0' + ms % 10);
    *o++ = 'Z';
    return o;
}

static char *put_ll(char *o, long long v)
{
    char t[24];
    int n = 0;
    unsigned long long u = v < 0 ? 0ull - (unsigned long long)v : (unsigned long long)v;
    do
        t[n++] = (char)('0' + u % 10);
    while (u /= 10);
    if (v < 0)
        *o++ = '-';
    while (n)
        *o++ = t[--n];
    return o;
}

/* ms with the given decimals (2 or 3); negative, NaN and absurd values are written 0. */
static char *put_ms(char *o, double seconds, int decimals)
{
    double ms = seconds * 1e3;
    if (!(ms >= 0 && ms < 1e15))
        ms = 0;
    long long scale = decimals == 3 ? 1000 : 100;
    long long v = (long long)(ms * (double)scale + 0.5);
    o = put_ll(o, v / scale);
    *o++ = '.';
    for (long long d = scale / 10; d; d /= 10)
        *o++ = (char)('0' + v / d % 10);
    return o;
}

static size_t slen(const char *s)
{
    return s ? strlen(s) : 0;
}

/* An upper bound of the line's length. */
static size_t line_bound(const srv_log_rec *r)
{
    return 512 + 6 * (slen(r->ip) + slen(r->method) + slen(r->path) + slen(r->query) + slen(r->request_id) +
                      slen(r->solid_id));
}

static const char *or_dash(const char *s)
{
    return s ? s : "-";
}

static char *format_text(char *o, const srv_log_rec *r)
{
    o = put_time(o);
    *o++ = ' ';
    o = esc_text(o, or_dash(r->ip), 1);
    o = put_str(o, " \"");
    o = esc_text(o, or_dash(r->method), 0);
    *o++ = ' ';
    o = esc_text(o, or_dash(r->path), 0);
    if (r->query && r->query[0]) {
        *o++ = '?';
        o = esc_text(o, r->query, 0);
    }
    o = put_str(o, "\" ");
    o = put_ll(o, r->status);
    *o++ = ' ';
    o = put_ll(o, r->bytes);
    *o++ = ' ';
    o = put_ms(o, r->seconds, 2);
    o = put_str(o, "ms");
    if (r->solid_id && r->solid_id[0]) {
        o = put_str(o, " id=");
        o = esc_text(o, r->solid_id, 1);
    }
    if (r->request_id) {
        o = put_str(o, " rid=");
        o = esc_text(o, r->request_id, 1);
    }
    if (r->aborted)
        o = put_str(o, " aborted");
    *o++ = '\n';
    return o;
}

static char *format_json(char *o, const srv_log_rec *r)
{
    o = put_str(o, "{\"time\":\"");
    o = put_time(o);
    o = put_str(o, "\",\"ip\":");
    o = esc_json(o, or_dash(r->ip));
    o = put_str(o, ",\"method\":");
    o = esc_json(o, or_dash(r->method));
    o = put_str(o, ",\"path\":");
    o = esc_json(o, or_dash(r->path));
    o = put_str(o, ",\"query\":");
    o = esc_json(o, r->query);
    o = put_str(o, ",\"status\":");
    o = put_ll(o, r->status);
    o = put_str(o, ",\"bytes\":");
    o = put_ll(o, r->bytes);
    o = put_str(o, ",\"ms\":");
    o = put_ms(o, r->seconds, 3);
    o = put_str(o, ",\"solid_id\":");
    o = esc_json(o, r->solid_id && r->solid_id[0] ? r->solid_id : NULL);
    o = put_str(o, ",\"request_id\":");
    o = esc_json(o, r->request_id);
    o = put_str(o, r->aborted ? ",\"aborted\":true}\n" : ",\"aborted\":false}\n");
    return o;
}

static char *format_note(char *o, srv_log_format fmt, const char *source, const char *msg)
{
    if (fmt == SRV_LOG_JSON) {
        o = put_str(o, "{\"time\":\"");
        o = put_time(o);
        o = put_str(o, "\",\"source\":");
        o = esc_json(o, source);
        o = put_str(o, ",\"message\":");
        o = esc_json(o, msg);
        return put_str(o, "}\n");
    }
    o = put_time(o);
    *o++ = ' ';
    o = esc_text(o, source, 1);
    o = put_str(o, ": ");
    o = esc_text(o, msg, 0);
    *o++ = '\n';
    return o;
}

/* ---- the buffer ---- */

static void write_all(int fd, const char *p, size_t n)
{
    while (n) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return;   /* dropped: logging never fails a request */
        p += w;
        n -= (size_t)w;
    }
}

/* Writes out the buffer; the caller holds io. */
static void flush_io(srv_log *l)
{
    pthread_mutex_lock(&l->lock);
    char *full = l->buf;
    size_t n = l->len;
    l->buf = l->spare;
    l->spare = full;
    l->len = 0;
    pthread_mutex_unlock(&l->lock);
    write_all(l->fd, full, n);
}

void srv_log_flush(srv_log *l)
{
    if (!l)
        return;
    pthread_mutex_lock(&l->io);
    flush_io(l);
    pthread_mutex_unlock(&l->io);
}

static void append(srv_log *l, const char *line, size_t n)
{
    if (n > CAP) {
        pthread_mutex_lock(&l->io);
        flush_io(l);
        write_all(l->fd, line, n);
        pthread_mutex_unlock(&l->io);
        return;
    }
    for (;;) {
        pthread_mutex_lock(&l->lock);
        if (l->len + n <= CAP) {
            memcpy(l->buf + l->len, line, n);
            l->len += n;
            pthread_mutex_unlock(&l->lock);
            return;
        }
        pthread_mutex_unlock(&l->lock);
        srv_log_flush(l);
    }
}

void srv_log_request(srv_log *l, const srv_log_rec *r)
{
    if (!l || !r)
        return;
    char stack[STACK_LINE];
    size_t bound = line_bound(r);
    char *b = bound <= sizeof stack ? stack : malloc(bound);
    if (!b)
        return;
    char *end = l->fmt == SRV_LOG_JSON ? format_json(b, r) : format_text(b, r);
    append(l, b, (size_t)(end - b));
    if (b != stack)
        free(b);
}

void srv_log_note(srv_log *l, const char *source, const char *msg)
{
    if (!l || !source || !msg)
        return;
    size_t n = strlen(msg);
    char *m = malloc(n + 1), *b = malloc(128 + 6 * (strlen(source) + n));
    if (m && b) {
        memcpy(m, msg, n + 1);
        while (n && (m[n - 1] == '\n' || m[n - 1] == '\r'))
            m[--n] = '\0';
        char *end = format_note(b, l->fmt, source, m);
        append(l, b, (size_t)(end - b));
    }
    free(m);
    free(b);
}

static void *flusher(void *arg)
{
    srv_log *l = arg;
    pthread_mutex_lock(&l->lock);
    while (!l->stop) {
        struct timespec t;
        clock_gettime(CLOCK_MONOTONIC, &t);
        t.tv_nsec += PERIOD_NS;
        if (t.tv_nsec >= 1000000000L) {
            t.tv_sec++;
            t.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&l->wake, &l->lock, &t);
        if (l->len && !l->stop) {
            pthread_mutex_unlock(&l->lock);
            srv_log_flush(l);
            pthread_mutex_lock(&l->lock);
        }
    }
    pthread_mutex_unlock(&l->lock);
    return NULL;
}

srv_log *srv_log_create(int fd, srv_log_format fmt)
{
    srv_log *l = calloc(1, sizeof *l);
    if (!l)
        return NULL;
    l->fd = fd;
    l->fmt = fmt;
    l->buf = malloc(CAP);
    l->spare = malloc(CAP);
    pthread_condattr_t ca;
    int ok = l->buf && l->spare && !pthread_condattr_init(&ca);
    if (ok) {
        pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
        ok = !pthread_cond_init(&l->wake, &ca);
        pthread_condattr_destroy(&ca);
    }
    if (!ok) {
        free(l->buf);
        free(l->spare);
        free(l);
        return NULL;
    }
    pthread_mutex_init(&l->lock, NULL);
    pthread_mutex_init(&l->io, NULL);
    /* The flusher takes no signals: they belong to the daemon's main thread. */
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
    int err = pthread_create(&l->flusher, NULL, flusher, l);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (err) {
        pthread_cond_destroy(&l->wake);
        pthread_mutex_destroy(&l->lock);
        pthread_mutex_destroy(&l->io);
        free(l->buf);
        free(l->spare);
        free(l);
        return NULL;
    }
    return l;
}

void srv_log_destroy(srv_log *l)
{
    if (!l)
        return;
    pthread_mutex_lock(&l->lock);
    l->stop = 1;
    pthread_cond_signal(&l->wake);
    pthread_mutex_unlock(&l->lock);
    pthread_join(l->flusher, NULL);
    srv_log_flush(l);
    pthread_cond_destroy(&l->wake);
    pthread_mutex_destroy(&l->lock);
    pthread_mutex_destroy(&l->io);
    free(l->buf);
    free(l->spare);
    free(l);
}

/* ---- request ids ---- */

int srv_request_id_ok(const char *s)
{
    if (!s)
        return 0;
    size_t n = 0;
    for (; s[n]; n++) {
        unsigned char c = (unsigned char)s[n];
        int ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                 c == '_' || c == ':' || c == '-';
        if (!ok || n >= 64)
            return 0;
    }
    return n >= 1;
}

static pthread_once_t id_once = PTHREAD_ONCE_INIT;
static uint64_t id_process;
static _Atomic uint64_t id_counter;

static void id_seed(void)
{
    uint64_t r[2];
    if (getrandom(r, sizeof r, 0) != (ssize_t)sizeof r) {
        /* No entropy source: the time and pid still tell processes apart. */
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        r[0] = ((uint64_t)ts.tv_sec << 32) ^ (uint64_t)ts.tv_nsec ^ ((uint64_t)getpid() << 48);
        r[1] = (uint64_t)ts.tv_nsec * 0x9e3779b97f4a7c15ull;
    }
    id_process = r[0];
    atomic_store(&id_counter, r[1]);
}

static void put_hex64(char *o, uint64_t v)
{
    for (int i = 15; i >= 0; i--, v >>= 4)
        o[i] = hexd[v & 15];
}

void srv_request_id_make(char out[33])
{
    pthread_once(&id_once, id_seed);
    uint64_t n = atomic_fetch_add(&id_counter, 1);
    put_hex64(out, id_process);
    put_hex64(out + 16, n);
    out[32] = '\0';
}
