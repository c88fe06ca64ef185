/*
 * model.h: JSON model documents to pde_model, with errors that point at the
 * offending field.
 *
 * USAGE
 *
 *   api_error err;
 *   api_model *m = api_model_parse(text, len, &err);
 *   if (!m) { fprintf(stderr, "%s: %s\n", err.pointer, err.message); ... }
 *   pde_solution *sol;
 *   if (api_solve(m, &sol, &err) != 0) ...      // core errors become pointers too
 *   api_model_free(m);
 *
 * The format (docs/API.md):
 *   {"pde": {"a": [ax, ay, az], "b": [..], "c": [..]},
 *    "boundary": {"x": [{"u": F, "v": F, "w0": n, "dw0": n, "w1": n, "dw1": n}, ..], "y": .., "z": ..},
 *    "force":    {"x": [{"coef": n, "u": F, "v": F, "w": F}, ..], ..}}
 * where a factor F is one of {"pow": n}, {"sin": k}, {"cos": k}, {"exp": a},
 * {"sinh": a}, {"cosh": a}. An omitted factor is 1, an omitted number 0,
 * "boundary", "force" and each component in them are optional; "pde" and its
 * three arrays are required. Unknown and duplicate keys are errors whose
 * pointer is the key itself ("/boundry"). Every parser here first runs
 * api_json_check() (strict.h), so text with NUL, invalid UTF-8 or leading
 * zeros is API_ERR_NOT_JSON before cJSON reads it.
 *
 * Parsing uses cJSON, which records its last error in a global: callers that
 * parse on several threads must serialise api_model_parse() and
 * api_points_parse(). Everything else here is reentrant.
 */
#ifndef API_MODEL_H
#define API_MODEL_H

#include <stddef.h>

#include "error.h"
#include "pde.h"


#define API_MAX_TERMS 4096    /* terms in one component's boundary or force list */
#define API_MAX_POINTS 1000000
#define API_MAX_DEPTH 64      /* nesting of arrays and objects; the format needs 6 */

typedef struct api_model api_model;

/*
 * Parses a request of len bytes (no NUL needed): a model, a loft document
 * {"loft": {...}} (loft.h), or {"preset": NAME, "params": {...}} or
 * {"template": NAME, "params": {...}},
 * where params override the preset's or the template's values (template.h).
 * Returns NULL and fills err on failure.
 */
api_model *api_model_parse(const char *text, size_t len, api_error *err);

/*
 * A model owning a deep copy of m's terms (not validated: pde_solve does
 * that). from_params: m was expanded from a template's parameters, so errors
 * of api_solve() point into /params. NULL if out of memory.
 */
api_model *api_model_build(const pde_model *m, int from_params, api_error *err);
void api_model_free(api_model *m);
/* The model; for a loft document ({"loft": ...}, loft.h) an empty one: see api_model_loft(). */
const pde_model *api_model_get(const api_model *m);
/* The loft of a loft document, or NULL for a model. */
const pde_loft *api_model_loft(const api_model *m);

/* The api_status of a core status: NOMEM, LIMIT and CANCELLED as themselves, the rest a bad document. */
api_status api_status_of(pde_status st);

/* pde_solve() with the core's diagnosis turned into a JSON pointer. Returns 0 or the pde_status. */
int api_solve(const api_model *m, pde_solution **out, api_error *err);
/* The same, polling cancel (NULL: never) between modes; stopped: API_ERR_CANCELLED. */
int api_solve_ex(const api_model *m, const pde_cancel *cancel, pde_solution **out, api_error *err);

/*
 * Parses [[u, v, w], ...] into a new array of 3 n doubles, stored in *out
 * (free() it). Returns 0, or -1 with err filled.
 */
int api_points_parse(const char *text, size_t len, double **out, size_t *n, api_error *err);

/*
 * Parses an eval request {"points": [[u, v, w], ...], "derivatives": false}
 * with at most max_points points (over it: API_ERR_LIMIT). Returns 0, or -1.
 */
int api_eval_parse(const char *text, size_t len, size_t max_points, double **out, size_t *n, int *derivatives,
                   api_error *err);

/* The model in the general JSON format (malloc'd, unformatted); NULL if out of memory. */
char *api_model_json(const pde_model *m);
/* The same as a cJSON tree (cJSON_Delete it), to put inside a larger document without a parse. */
struct cJSON *api_model_tree(const pde_model *m);
/* One factor as {"sin": k} and so on, a cJSON tree. */
struct cJSON *api_factor_tree(pde_factor f);


#endif
