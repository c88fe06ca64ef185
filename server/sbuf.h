/*
 * sbuf.h: a growing string for response bodies. Out of memory is sticky:
 * later calls do nothing and oom stays set, so a writer checks once at the end.
 */
#ifndef SRV_SBUF_H
#define SRV_SBUF_H

#include <stddef.h>

typedef struct {
    char *s;        /* NUL-terminated once anything is written; the caller frees it */
    size_t len, cap;
    int oom;
} srv_sbuf;

void srv_sbuf_put(srv_sbuf *b, const char *p, size_t n);
void srv_sbuf_printf(srv_sbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
