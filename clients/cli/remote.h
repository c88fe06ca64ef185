/*
 * remote.h: the command-line tool as a client of a pdesolidd (--server URL):
 * the same solve and eval, done by the server, printed as offline.
 */
#ifndef CLI_REMOTE_H
#define CLI_REMOTE_H

#include <stddef.h>
#include <stdio.h>

/* url as a pdesolidd's base: http or https, with no query or fragment, into base without trailing slashes.
 * Returns 0, or 2 after a message naming --server. */
int remote_base(const char *url, char *base, size_t n);

/* POSTs body to URL/solve?format=..&res=..&compress=.. (each only when given) and writes the answer to standard
 * output (format NULL: the text of `pdesolid solve`); nothing on a refusal. Returns the exit status: 0, 2 for a
 * request the server refused, 1 otherwise (not for a write error: the caller checks standard output's error flag). */
int remote_solve(const char *server, const char *body, size_t len, const char *format, const char *res,
                 const char *compress);

/* Evaluates the n points [u, v, w] on the solid id (api_request_id()'s of body; NULL or "" when it has none)
 * into pts in place: [x, y, z], NAN where the server answers null. The solid is made from body (POST /solve)
 * only when the server does not have it; the points go in batches that fit the server's limits (halved after
 * a 413, or a 422 over --max-work or --max-mem-mb). A point the server refuses is named as points_name's /i.
 * Returns the exit status as remote_solve(). */
int remote_eval(const char *server, const char *body, size_t len, const char *id, double *pts, size_t n,
                const char *points_name);

/* GET URL/presets, each row through row(name, template, caption). Returns the exit status as remote_solve(). */
int remote_presets(const char *server, void (*row)(const char *name, const char *template, const char *caption));

/* GET URL/presets/NAME into *json (malloc'd). Returns the exit status as remote_solve(). */
int remote_preset(const char *server, const char *name, char **json);

#endif
