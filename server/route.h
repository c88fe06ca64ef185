/*
 * route.h: pdesolidd's routes as one table, as Redis's command table: each
 * row has the method, the path, the handler, its flags and the query
 * parameters it takes. The dispatch, the Allow header and 405s, the query
 * checks, /metrics' route labels and the response cache all read the table,
 * so an endpoint is one row and its handler.
 *
 * USAGE
 *
 *   char arg[96], allow[64];
 *   int status;
 *   int i = srv_route_find("GET", "/solids/abc", arg, sizeof arg, allow, sizeof allow, &status);
 *   if (i < 0) ... answer status (404, or 405 with allow) ...
 *   srv_query q;
 *   srv_query_init(&q);
 *   for each decoded argument: if (srv_query_arg(&srv_routes[i], &q, k, klen, v, vlen, msg, sizeof msg)) 400;
 *   if (srv_query_done(&srv_routes[i], &q, msg, sizeof msg)) 400;
 *
 * Everything here is reentrant and needs no libmicrohttpd connection, so a
 * fuzzer can drive it with raw strings.
 */
#ifndef SRV_ROUTE_H
#define SRV_ROUTE_H

#include <stddef.h>

#include "output.h"

struct srv_req;

enum {
    SRV_RT_BODY = 1 << 0,    /* takes a request body (POST) */
    SRV_RT_JOB = 1 << 1,     /* runs on a solver thread; else answers on the polling thread */
    SRV_RT_CACHE = 1 << 2,   /* its 200s may be kept in the response cache */
    SRV_RT_OUTPUT = 1 << 3,  /* takes ?format=, ?res= and ?compress= */
    SRV_RT_PAGE = 1 << 4,    /* a page whose query is its script's own (/?solid=ID): any names, no control characters */
};

typedef struct {
    const char *name;        /* the route's label in /metrics */
    const char *method;      /* "GET" (HEAD too) or "POST" */
    const char *path;        /* exact; "{}" stands for one segment, the argument; "*" is a static file */
    void (*handler)(struct srv_req *r);
    unsigned flags;
} srv_route;

extern const srv_route srv_routes[];
extern const int srv_nroutes;

/*
 * The row of method and path, with the path's {} segment copied into arg.
 * Returns its index, or -1 with *status 404 (no such path), 405 (the path
 * takes other methods, listed in allow as "GET, OPTIONS") or 400 (a segment
 * longer than argn). OPTIONS matches every row of the path (CORS preflight).
 */
int srv_route_find(const char *method, const char *path, char *arg, size_t argn, char *allow, size_t allown,
                   int *status);

/* A request's query, checked against its row. */
typedef struct {
    char format[32], res[256], compress[16];  /* as given, "" when absent */
    int seen;                   /* bits: 1 format, 2 res, 4 compress */
    api_format fmt;             /* after srv_query_done */
    api_compress comp;          /* after srv_query_done */
    unsigned res3[3];
} srv_query;

void srv_query_init(srv_query *q);
/*
 * Takes one decoded argument of klen and vlen bytes (value NULL for "?key");
 * 0, or -1 with a sentence in msg: an unknown parameter (naming the known
 * ones), one given twice, a NUL or a control character, a value too long.
 */
int srv_query_arg(const srv_route *rt, srv_query *q, const char *key, size_t klen, const char *value, size_t vlen,
                  char *msg, size_t n);
/* Parses format, res and compress (with the format's defaults); 0, or -1 with msg (a value the format does not
 * take: 422; the message names the parameter). */
int srv_query_done(const srv_route *rt, srv_query *q, char *msg, size_t n);

#endif
