/*
 * http.h: pdesolidd's HTTP side: the libmicrohttpd daemon, its routes, and
 * the hand-off of solve work to the solver threads.
 *
 * USAGE
 *
 *   srv_server *s = srv_start(&config, err, sizeof err);   // listening once it returns
 *   ... wait for SIGTERM ...
 *   srv_stop(s);   // stop accepting, finish requests in flight, free
 */
#ifndef SRV_HTTP_H
#define SRV_HTTP_H

#include <stddef.h>
#include <stdint.h>

#include "config.h"

typedef struct srv_server srv_server;

srv_server *srv_start(const srv_config *c, char *err, size_t errlen);
uint16_t srv_port(const srv_server *s);
/* Stops accepting, lets requests in flight finish (up to the grace period), stops, says "stopped", frees. */
void srv_stop(srv_server *s);
/* A line of the daemon's own into the access log, in its format (srv_log_note, source "pdesolidd"); to stderr
 * as "pdesolidd: ..." under --quiet. Thread-safe. */
void srv_say(srv_server *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
