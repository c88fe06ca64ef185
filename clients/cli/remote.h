/*
 * remote.h: the command-line tool as a client of a pdesolidd (--server URL):
 * the same solve and eval, done by the server, printed as offline.
 */
#ifndef CLI_REMOTE_H
#define CLI_REMOTE_H

#include <stddef.h>
#include <stdio.h>

/* POSTs body to URL/solve?format=..&res=..&compress=.. (each only when given) and writes the answer to out (format NULL: the text of
 * `pdesolid solve`). Returns the exit status: 0, 2 for a request the server refused, 1 otherwise. */
int remote_solve(const char *server, const char *body, size_t len, const char *format, const char *res,
                 const char *compress, FILE *out);

/* Solves body, then evaluates the points (a JSON array) there; prints [[x,y,z], ...] as offline. */
int remote_eval(const char *server, const char *body, size_t len, const char *points, size_t plen, FILE *out);

#endif
