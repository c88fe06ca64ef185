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

/* POSTs body to URL/solve?format=..&res=..&compress=.. (each only when given) and writes the answer to the file
 * path, made only when the server answers 200, or to standard output when path is NULL (format NULL: the text
 * of `pdesolid solve`). Returns the exit status: 0, 2 for a request the server refused, 1 otherwise. */
int remote_solve(const char *server, const char *body, size_t len, const char *format, const char *res,
                 const char *compress, const char *path);

/* Solves body, then evaluates the n points [u, v, w] there, in batches that fit the server's body limit
 * (halved after a 413), into pts in place: [x, y, z], NAN where the server answers null. A point the server
 * refuses is named as points_name's /i. Returns the exit status as remote_solve(). */
int remote_eval(const char *server, const char *body, size_t len, double *pts, size_t n, const char *points_name);

/* GET URL/presets, each row through row(name, template, caption). Returns the exit status as remote_solve(). */
int remote_presets(const char *server, void (*row)(const char *name, const char *template, const char *caption));

#endif
