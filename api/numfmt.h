/*
 * numfmt.h: the number writer behind the grid JSON. A float32 value in at
 * most API_F32_MAX characters that parse back to the same float32, JSON
 * syntax, about ten times faster than snprintf("%.9g").
 */
#ifndef API_NUMFMT_H
#define API_NUMFMT_H

#include <stddef.h>

#define API_F32_MAX 16

/* Writes v (no NUL) and returns the length. Non-finite values are written as null. */
size_t api_fmt_f32(char *out, float v);

#endif
