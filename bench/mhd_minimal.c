/*
 * mhd_minimal: the baseline of the server benchmark. A minimal libmicrohttpd
 * server, configured like pdesolidd (epoll polling threads: THREADS of them in
 * libmicrohttpd's thread pool, MHD_OPTION_THREAD_POOL_SIZE, as pdesolidd's
 * --http-threads), that answers every request with the bytes of one file,
 * from memory.
 *
 *   mhd_minimal PORT FILE [THREADS]      (THREADS: 1 by default)
 */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <microhttpd.h>

static char *body;
static size_t body_len;

static enum MHD_Result answer(void *cls, struct MHD_Connection *c, const char *url, const char *method,
                              const char *version, const char *upload, size_t *upload_size, void **state)
{
    (void)cls, (void)url, (void)method, (void)version, (void)upload;
    if (!*state) {          /* first call: headers only */
        *state = (void *)1;
        return MHD_YES;
    }
    if (*upload_size) {     /* discard the request body */
        *upload_size = 0;
        return MHD_YES;
    }
    struct MHD_Response *r = MHD_create_response_from_buffer(body_len, body, MHD_RESPMEM_PERSISTENT);
    MHD_add_response_header(r, "Content-Type", "application/json");
    enum MHD_Result ok = MHD_queue_response(c, 200, r);
    MHD_destroy_response(r);
    return ok;
}

int main(int argc, char **argv)
{
    int threads = argc == 4 ? atoi(argv[3]) : 1;
    if ((argc != 3 && argc != 4) || threads < 1 || threads > 256) {
        fprintf(stderr, "usage: mhd_minimal PORT FILE [THREADS]\n");
        return 2;
    }
    FILE *f = fopen(argv[2], "rb");
    if (!f)
        return 1;
    body = malloc(1 << 24);
    body_len = fread(body, 1, 1 << 24, f);
    fclose(f);
    struct MHD_Daemon *d = MHD_start_daemon(MHD_USE_EPOLL_INTERNAL_THREAD | MHD_USE_ERROR_LOG, (uint16_t)atoi(argv[1]),
                                            NULL, NULL, answer, NULL, MHD_OPTION_CONNECTION_TIMEOUT, 30u,
                                            MHD_OPTION_THREAD_POOL_SIZE, (unsigned)(threads > 1 ? threads : 0),
                                            MHD_OPTION_END);
    if (!d)
        return 1;
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGINT);
    pthread_sigmask(SIG_BLOCK, &set, NULL);
    int sig;
    sigwait(&set, &sig);
    MHD_stop_daemon(d);
    free(body);
    return 0;
}
