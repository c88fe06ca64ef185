/*
 * error.h: the one error type of api/: a status, the JSON pointer (RFC 6901)
 * of the field at fault ("" for the whole document) and a sentence.
 *
 * USAGE
 *
 *   api_error err;
 *   api_model *m = api_model_parse(text, len, &err);
 *   if (!m) { fprintf(stderr, "%s: %s: %s\n", api_strerror(err.status), err.pointer, err.message); ... }
 *
 * THE CONVENTION, for every function of api/ that can fail:
 *   - a function returning a pointer returns NULL and fills err;
 *   - a function returning int returns 0, or -1 and fills err (the solves, api_solve() and
 *     api_loft_solve(), return the pde_status instead of -1; err is filled the same way);
 *   - err may be NULL wherever it is taken; a function without an err (api_model_json(),
 *     api_model_tree(), ...) fails only for want of memory and returns NULL.
 * err carries no transport's status: the server maps api_status to HTTP in one function
 * (srv_http_status(), server/reply.c), the CLI to its exit status.
 */
#ifndef API_ERROR_H
#define API_ERROR_H

typedef enum {
    API_OK = 0,
    API_ERR_NOMEM,      /* out of memory */
    API_ERR_LIMIT,      /* a size limit exceeded (points, terms, nesting, res) */
    API_ERR_DOCUMENT,   /* a document (or a query's value) that is JSON but wrong */
    API_ERR_NOT_JSON,   /* text that is not (strict) JSON */
    API_ERR_CANCELLED,  /* a call given a pde_cancel was asked to stop */
    API_ERR_NOT_FOUND,  /* an unknown name (a preset, a template) */
} api_status;

/* A short English phrase for s ("out of memory"); never NULL. */
const char *api_strerror(api_status s);

typedef struct {
    api_status status;
    char pointer[160];
    char message[320];
} api_error;

/*
 * Sets err (when not NULL) to status, pointer and a printf message, and
 * returns -1, for one-line error returns. The pointer and the message pass
 * through api_text_clean(): valid UTF-8, no control characters, whatever they quote.
 */
int api_fail(api_error *err, api_status status, const char *pointer, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Sets err to the "cancelled" problem (API_ERR_CANCELLED) and returns PDE_ERR_CANCELLED (pde.h). */
int api_fail_cancelled(api_error *err);

/* Sets err to "out of memory" (API_ERR_NOMEM) and returns -1. */
int api_fail_nomem(api_error *err);

#endif
