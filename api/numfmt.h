/*
 * numfmt.h: api/'s number writers. A float32 value in at most API_F32_MAX
 * characters that parse back to the same float32, JSON syntax, about ten
 * times faster than snprintf("%.9g") (the grid JSON); and a double in the
 * fewest digits that parse back to the same double (models, properties).
 */
#ifndef API_NUMFMT_H
#define API_NUMFMT_H

#include <stddef.h>

#define API_F32_MAX 16

/* Writes v (no NUL) and returns the length. Non-finite values are written as null. */
size_t api_fmt_f32(char *out, float v);

#define API_F64_MAX 32

/* Writes finite v with a NUL in the fewest of 15 to 17 significant digits that strtod reads back as v
 * exactly (cJSON's writer settles for 15 within an epsilon: 0.5609999999999999 came back as 0.561), and
 * returns the length. */
size_t api_fmt_f64(char out[API_F64_MAX], double v);

#endif
