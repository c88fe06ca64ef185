/*
 * log.h: pdesolidd's access log: one line per request, escaped so that no
 * client can forge a line or send control sequences to a terminal, written
 * through a buffer so that logging costs little of the server's throughput.
 *
 * USAGE
 *
 *   srv_log *l = srv_log_create(2, SRV_LOG_TEXT);   // to stderr; NULL if out of memory
 *   srv_log_rec r = { .ip = "127.0.0.1", .method = "GET", .path = "/livez", .query = NULL,
 *                     .request_id = rid, .status = 200, .bytes = 3, .seconds = 52e-6 };
 *   srv_log_request(l, &r);                          // from any thread
 *   srv_log_destroy(l);                              // flushes, stops the flusher, frees
 *
 * Lines reach fd within about 200 ms (a background thread flushes), at once
 * when the 64 KiB buffer fills, and on srv_log_flush and srv_log_destroy.
 * Lines are never interleaved: every write(2) holds whole lines, and writes
 * are serialised. A line that cannot be written (fd closed, disk full) is
 * dropped: logging never fails a request.
 *
 * TEXT (SRV_LOG_TEXT), fields separated by one space:
 *
 *   2026-11-22T04:37:00.123Z 127.0.0.1 "GET /path?query" 200 1234 0.52ms id=<solid> rid=<request> aborted
 *
 * The time is RFC 3339 in UTC with milliseconds. "?query" is left out when
 * query is NULL or empty, "id=" when solid_id is NULL or empty, "rid=" when
 * request_id is NULL, "aborted" unless the client went away. Every string is
 * escaped: a byte below 0x20, 0x7f, or one that is not part of valid UTF-8,
 * and the C1 controls U+0080..U+009F (which some terminals obey), as \xNN;
 * '"' as \" and '\\' as \\; outside the quotes a space as \x20 too. So a line
 * holds no control byte, is valid UTF-8, and unescaping gives back the input.
 *
 * JSON (SRV_LOG_JSON), one object per line, always valid JSON in UTF-8:
 *
 *   {"time":"2026-11-22T04:37:00.123Z","ip":"127.0.0.1","method":"GET","path":"/path",
 *    "query":"a=1","status":200,"bytes":1234,"ms":0.520,"solid_id":null,"request_id":"...",
 *    "aborted":false}
 * Other lines (srv_log_note) are in the same format, with the same escaping:
 *   2026-11-22T04:37:00.123Z pdesolidd: listening on http://127.0.0.1:8080/
 *   {"time":"2026-11-22T04:37:00.123Z","source":"libmicrohttpd","message":"..."}
 *
 * query, solid_id and request_id are null when NULL (solid_id also when "").
 * Controls (and U+007F..U+009F) are written \u00XX, and every byte that is not
 * part of valid UTF-8 becomes U+FFFD.
 *
 * Request ids: srv_request_id_ok says whether a client's X-Request-Id may be
 * echoed; srv_request_id_make makes one otherwise. Both are thread-safe.
 */
#ifndef SRV_LOG_H
#define SRV_LOG_H

typedef struct srv_log srv_log;

typedef enum {
    SRV_LOG_TEXT,   /* one space-separated line per request */
    SRV_LOG_JSON    /* one JSON object per line */
} srv_log_format;

/* Writes to fd (2 for stderr) through a buffer; a background thread flushes every 200 ms, and a full
 * buffer (64 KiB) is flushed by the writer. NULL if out of memory (or no thread could be started).
 * The log does not own fd: it never closes it. */
srv_log *srv_log_create(int fd, srv_log_format fmt);
/* Flushes, stops the flusher and frees. NULL does nothing. No srv_log_request may run at the same time. */
void srv_log_destroy(srv_log *l);

typedef struct {
    const char *ip, *method, *path, *query;   /* untrusted: escaped on output; query may be NULL */
    const char *request_id, *solid_id;        /* solid_id may be NULL or "" */
    int status;
    long long bytes;
    double seconds;
    int aborted;                              /* the client went away before the end */
} srv_log_rec;

/* Thread-safe; one line, "\n"-terminated. A NULL ip, method or path is written as "-". Cannot fail
 * (a line that finds no memory is dropped). */
void srv_log_request(srv_log *l, const srv_log_rec *r);
/* A line that is not a request (the daemon starting and stopping, libmicrohttpd's own messages), in the
 * log's format: TEXT "TIME SOURCE: MESSAGE", JSON {"time":...,"source":...,"message":...}; both escaped as
 * a request's fields, a trailing newline of msg left out. Thread-safe; a line that finds no memory is dropped. */
void srv_log_note(srv_log *l, const char *source, const char *msg);
/* Writes out what is buffered, now. Thread-safe. */
void srv_log_flush(srv_log *l);

/* 1 if s is a sane request id to echo: 1..64 chars of [A-Za-z0-9._:-]; 0 otherwise (and for NULL). */
int srv_request_id_ok(const char *s);
/* A new unique request id (32 lowercase hex chars + NUL) in out: random (getrandom) per process + counter. */
void srv_request_id_make(char out[33]);

#endif
