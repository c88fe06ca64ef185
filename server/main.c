/*
 * pdesolidd: the pdesolid solve server. Parses flags, starts the daemon,
 * and waits for SIGTERM or SIGINT, on which it answers new requests 503,
 * finishes the requests in flight and exits 0.
 */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "http.h"

int main(int argc, char **argv)
{
    srv_config c;
    int rc = srv_config_parse(argc, argv, &c, stdout, stderr);
    if (rc)
        return rc == 1 ? 0 : 2;
    /* Every thread inherits this mask: the signals arrive only at sigwait below. */
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGINT);
    pthread_sigmask(SIG_BLOCK, &set, NULL);
    signal(SIGPIPE, SIG_IGN);
    char err[256];
    srv_server *s = srv_start(&c, err, sizeof err);
    if (!s) {
        fprintf(stderr, "pdesolidd: %s\n", err);
        return 1;
    }
    /* Into the log, in its format (--log-format json: every line on stderr is JSON). */
    char *flags = NULL;
    size_t n = 0;
    FILE *m = open_memstream(&flags, &n);
    if (m) {
        srv_config_print(&c, m);
        fclose(m);
        srv_say(s, "%s", strncmp(flags, "pdesolidd ", 10) ? flags : flags + 10);   /* "0.4.0: --bind ..." */
        free(flags);
    }
    srv_say(s, "listening on http://%s%s%s:%u/", strchr(c.bind, ':') ? "[" : "", c.bind, strchr(c.bind, ':') ? "]" : "",
            srv_port(s));
    int sig;
    sigwait(&set, &sig);
    srv_say(s, "%s: finishing the requests in flight", sig == SIGTERM ? "SIGTERM" : "SIGINT");
    srv_stop(s);
    return 0;
}
