/*
 * fuzz.h: what the libFuzzer harnesses share (tests/fuzz/fuzz_*.c).
 *
 * USAGE
 *
 *   int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
 *   {
 *       ...
 *       FUZZ_CHECK(n <= limit, "%zu points, over the limit of %zu", n, limit);
 *       fuzz_check_error(&err);      // a sane api_error: status, pointer, sentence
 *       return 0;
 *   }
 *
 * Each harness is built twice: with clang's -fsanitize=fuzzer into
 * build/fuzz/<name> (`make fuzz`), and with the project's compiler and
 * sanitisers against tests/fuzz/replay.c into build/san/fuzz/<name>, which
 * `make test` runs over the seed corpus tests/fuzz/corpus/<name>/. A broken
 * invariant prints what broke and aborts, which both drivers report as a
 * crash. The harnesses also link tests/support.c for its independent
 * checkers of UTF-8 and JSON (support.h).
 */
#ifndef FUZZ_H
#define FUZZ_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model.h"
#include "support.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
/* Optional, called once before the first input. */
int LLVMFuzzerInitialize(int *argc, char ***argv);

#define FUZZ_CHECK(cond, ...)                                                        \
    do {                                                                             \
        if (!(cond)) {                                                               \
            fprintf(stderr, "%s:%d: invariant broken: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                            \
            fputc('\n', stderr);                                                     \
            abort();                                                                 \
        }                                                                            \
    } while (0)

/* A message fit for a problem body: NUL-terminated within n bytes, not empty, valid UTF-8, no control
 * characters. */
static inline void fuzz_check_text(const char *s, size_t n, int may_be_empty)
{
    const char *end = memchr(s, '\0', n);
    FUZZ_CHECK(end, "text not NUL-terminated within %zu bytes", n);
    size_t len = (size_t)(end - s);
    FUZZ_CHECK(may_be_empty || len > 0, "empty text");
    FUZZ_CHECK(utf8_valid(s, len), "text is not valid UTF-8: %s", s);
    for (size_t i = 0; i < len; i++)
        FUZZ_CHECK((unsigned char)s[i] >= 0x20 && s[i] != 0x7f, "control character 0x%02x in \"%s\"",
                   (unsigned char)s[i], s);
}

/* An api_error as a parser or the solver left it: the client's fault (not JSON, over a limit, a bad document),
 * a JSON pointer ("" or "/..."), a sentence. */
static inline void fuzz_check_error(const api_error *err)
{
    FUZZ_CHECK(err->status == API_ERR_NOT_JSON || err->status == API_ERR_LIMIT || err->status == API_ERR_DOCUMENT,
               "status %d", (int)err->status);
    fuzz_check_text(err->pointer, sizeof err->pointer, 1);
    FUZZ_CHECK(err->pointer[0] == '\0' || err->pointer[0] == '/', "pointer \"%s\"", err->pointer);
    fuzz_check_text(err->message, sizeof err->message, 0);
}

#endif
