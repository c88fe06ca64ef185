/*
 * watch.h: the deadline of a request's head. libmicrohttpd's --timeout is an idle timeout, which a
 * client sending a byte a second never reaches, and the handler (which keeps --request-timeout for the
 * body) is called only once the head is whole; so a connection holding a slot with a head that never
 * ends, slowloris, would hold it forever, and --max-conns-per-ip of them lock an address out. The watch
 * closes a connection whose head is not whole within its limit of opening, or of its last answer.
 */
#ifndef SRV_WATCH_H
#define SRV_WATCH_H

typedef struct srv_watch srv_watch;

/* A connection, as the watch keeps it (in the connection's own state: no allocation). */
typedef struct srv_watched {
    struct srv_watched *prev, *next;
    int fd;
    int busy;       /* between its head and its answer: the request's own deadlines hold */
    int answered;   /* a request was answered on it: what comes now is keep-alive idleness first */
    double since;   /* opened, or answered last */
} srv_watched;

/* Checks every `period` seconds for heads older than `limit`, or than `idle` on a connection answered
before (an idle keep-alive connection: --timeout may be longer); NULL when out of memory or threads. */
srv_watch *srv_watch_start(double limit, double idle, double period);
void srv_watch_stop(srv_watch *w);

/* Connection opened on fd (its head's clock starts), closed (before libmicrohttpd closes fd), its head
 * whole (busy), its answer done (the next head's clock starts). c zeroed and never opened: close and
 * busy do nothing. */
void srv_watch_open(srv_watch *w, srv_watched *c, int fd);
void srv_watch_close(srv_watch *w, srv_watched *c);
void srv_watch_busy(srv_watch *w, srv_watched *c, int busy);

#endif
