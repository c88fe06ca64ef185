/*
 * bench_log: the access log's cost per line (server/log.c) against what the
 * daemon did before: an fprintf per request to unbuffered stderr, here to
 * /dev/null, so that only the writer is measured, and to a file (in $TMPDIR
 * or /tmp, emptied before each round), as stderr redirected to a log file
 * would be. Medians of rounds, in
 * lines per second and ns per line; with 2 threads, lines per second in all.
 * The last column is what one line costs of a polling thread that serves
 * 73,000 cached requests a second (docs/BENCHMARKS.md): ns x 73e3 / 1e9.
 */
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "log.h"

#define LINES 200000
#define ROUNDS 9
#define CACHED_RPS 73000.0

static const srv_log_rec rec = { .ip = "127.0.0.1", .method = "POST", .path = "/solve", .query = "format=json",
                                 .request_id = "8c1f2e3d4b5a69788796a5b4c3d2e1f0",
                                 .solid_id = "99268af08d93209af6cac24a6617fc90", .status = 200, .bytes = 3284,
                                 .seconds = 52e-6 };

typedef struct {
    srv_log *l;
    FILE *f;
    int n;
} job;

static void *run_log(void *p)
{
    job *j = p;
    for (int i = 0; i < j->n; i++)
        srv_log_request(j->l, &rec);
    return NULL;
}

/* The old access log line, as http.c wrote it. */
static void *run_fprintf(void *p)
{
    job *j = p;
    for (int i = 0; i < j->n; i++)
        fprintf(j->f, "%s \"%s %s?%s\" %d %lld %.2fms%s%s%s\n", rec.ip, rec.method, rec.path, rec.query, rec.status,
                rec.bytes, rec.seconds * 1e3, " id=", rec.solid_id, "");
    return NULL;
}

/* Seconds for LINES lines over threads threads. */
static double round_of(void *(*fn)(void *), srv_log *l, FILE *f, int threads)
{
    pthread_t t[2];
    job j[2];
    double t0 = now();
    for (int i = 0; i < threads; i++) {
        j[i] = (job){ l, f, LINES / threads };
        pthread_create(&t[i], NULL, fn, &j[i]);
    }
    for (int i = 0; i < threads; i++)
        pthread_join(t[i], NULL);
    if (l)
        srv_log_flush(l);
    else
        fflush(f);
    return now() - t0;
}

static void table(const char *target, int fd)
{
    FILE *f = fdopen(dup(fd), "w");
    if (!f)
        exit(1);
    setvbuf(f, NULL, _IONBF, 0);   /* as stderr is */
    static const struct {
        const char *name;
        int kind, threads;   /* kind: 0 fprintf, 1 text, 2 json */
    } rows[] = {
        { "fprintf to unbuffered FILE (before)", 0, 1 }, { "srv_log text", 1, 1 }, { "srv_log json", 2, 1 },
        { "fprintf to unbuffered FILE (before)", 0, 2 }, { "srv_log text", 1, 2 }, { "srv_log json", 2, 2 },
    };
    printf("\n| writer, %d lines to %s | threads | lines/s, median of %d | ns/line | of a thread at %.0f req/s |\n",
           LINES, target, ROUNDS, CACHED_RPS);
    printf("|---|---|---|---|---|\n");
    for (size_t r = 0; r < sizeof rows / sizeof *rows; r++) {
        srv_log *l = rows[r].kind ? srv_log_create(fd, rows[r].kind == 2 ? SRV_LOG_JSON : SRV_LOG_TEXT) : NULL;
        double s[ROUNDS];
        for (int i = 0; i < ROUNDS; i++) {
            if (ftruncate(fd, 0) == 0)
                lseek(fd, 0, SEEK_SET);
            s[i] = round_of(rows[r].kind ? run_log : run_fprintf, l, f, rows[r].threads);
        }
        double m = median(s, ROUNDS);
        /* ns of one thread's time per line: with 2 threads, each thread wrote half the lines in m. */
        double ns = m * 1e9 * rows[r].threads / LINES;
        printf("| %s | %d | %.0f | %.0f | %.1f%% |\n", rows[r].name, rows[r].threads, LINES / m, ns,
               100 * ns * CACHED_RPS / 1e9);
        srv_log_destroy(l);
    }
    fclose(f);
}

int main(void)
{
    int fd = open("/dev/null", O_WRONLY);
    if (fd < 0)
        return 1;
    table("/dev/null", fd);
    close(fd);
    char path[512];
    snprintf(path, sizeof path, "%s/bench_log.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    fd = mkstemp(path);
    if (fd < 0)
        return 1;
    unlink(path);
    table("a file", fd);
    close(fd);
    return 0;
}
