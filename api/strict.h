/*
 * strict.h: untrusted text checked before anything else reads it, cleaned
 * before a message quotes it, and eval results checked before they are
 * written as JSON.
 *
 * USAGE
 *
 *   api_error err;
 *   if (api_json_check(body, len, &err) != 0)     // API_ERR_NOT_JSON (API_ERR_LIMIT for nesting), before any cJSON_Parse
 *       return problem(&err);
 *   char name[64];
 *   api_text_clean(name, sizeof name, user_text, user_len);   // valid UTF-8, no control characters
 *   if (api_eval_check(values, du, dv, dw, n, &err) != 0)     // API_ERR_DOCUMENT at /points/i
 *       return problem(&err);
 *
 * cJSON 1.7.15 stops a string at NUL ("pde\u0000junk" reads as "pde"), takes
 * a raw NUL for white space, accepts 0001, and copies invalid UTF-8 into its
 * strings; api_json_check() refuses all of these first, so that the parsers
 * in model.h only ever see RFC 8259 JSON with no NUL in it. Every function
 * here is reentrant, allocates nothing and takes time linear in its input.
 */
#ifndef API_STRICT_H
#define API_STRICT_H

#include <stddef.h>

#include "model.h"

/* Checks that text is one RFC 8259 JSON value, strictly: valid UTF-8 (no overlongs, surrogates or bytes
 * past U+10FFFF), no NUL raw or as \u0000 (nor escaped surrogate halves unpaired), no leading zeros, no
 * control characters in strings, nesting at most API_MAX_DEPTH, nothing but whitespace after the value.
 * Returns 0, or -1 with err: API_ERR_NOT_JSON, pointer "" (or the JSON pointer of the string/number at fault
 * when you can give it cheaply), a message naming the byte offset and what is wrong, never echoing the
 * input's bytes. Linear time, no allocation.
 *
 * Here the pointer names the innermost value whose text holds the fault: "/pde/a/1" for
 * {"pde":{"a":[1,01]}}, "/pde" for {"pde":}, "" for a fault at the top level, in a key or after
 * the value. Nesting deeper than API_MAX_DEPTH is API_ERR_LIMIT (413, a size limit, as docs/API.md says). */
int api_json_check(const char *text, size_t len, api_error *err);

/* The length of the UTF-8 character at s (n > 0 bytes), or 0 if no valid one starts there; then
 * *part gets the length of the longest valid start of one (at least 1), the bytes that one U+FFFD
 * replaces. Cannot fail. */
size_t api_utf8_char(const unsigned char *s, size_t n, size_t *part);

/* Copies s (n bytes) into out (outn > 0, always NUL-terminated, truncated at a character boundary),
 * replacing each invalid UTF-8 sequence by U+FFFD and each control character (< 0x20, 0x7f) by U+FFFD;
 * returns the bytes written. For putting untrusted text into messages.
 *
 * An invalid sequence is replaced one maximal subpart at a time (Unicode 15, section 3.9, U+FFFD
 * substitution), so "\xE2\x82" is one U+FFFD and "\xC0\x80" two. Cannot fail. */
size_t api_text_clean(char *out, size_t outn, const char *s, size_t n);

/* 0 if all 3n values (and the derivative arrays when non-NULL) are finite, else -1 with err: API_ERR_DOCUMENT,
 * pointer "/points/i" of the first point whose value is not finite, and a sentence. */
int api_eval_check(const double *values, const double *du, const double *dv, const double *dw, size_t n,
                   api_error *err);

#endif
