/*
 * loft.h: loft documents (docs/API.md, "Lofts") to pde_loft: solids through sections of the user's
 * own, with the paper's Fourier route (section II, after eq. 8).
 *
 * USAGE
 *
 *   api_error err;
 *   api_loft *l = api_loft_parse(cjson_of_the_loft_object, "/loft", &err);
 *   if (!l) { fprintf(stderr, "%s: %s\n", err.pointer, err.message); ... }
 *   pde_solve_loft(api_loft_get(l), NULL, &sol, &diag);
 *   api_loft_free(l);
 *
 * A section is a profile (N >= 3 points [x, y, z] of a closed curve at v = j/N, with optional
 * tangents and centre), a sampled surface (a grid fitted by cosine series in u and v, DCT-I), or
 * separable terms already in closed form. A profile's points are
 * interpolated by their trigonometric polynomial, computed with FFTW's real DFT, and the section is
 * x(u, v) = C + u (P(v) - C): terms u^0 (C), u^1 (the mean minus C), u cos(2 pi m v), u sin(2 pi m v).
 * Harmonics below tol (default API_LOFT_TOL) of the section's size are dropped. Errors follow
 * error.h's convention: a JSON pointer, a sentence, API_ERR_DOCUMENT (API_ERR_LIMIT over a limit).
 *
 * Every call is reentrant: FFTW's plans are made once per size under a lock, and executed on new
 * arrays from any thread.
 */
#ifndef API_LOFT_H
#define API_LOFT_H

#include <cJSON.h>

#include "model.h"
#include "pde.h"

#define API_LOFT_MAX_POINTS 4096   /* points of one profile */
#define API_LOFT_MAX_GRID 65536    /* points of one grid section */
#define API_LOFT_TOL 1e-12         /* harmonics below this of the section's size are dropped */

typedef struct api_loft api_loft;

/* The loft object (the value of "loft"); ptr is its JSON pointer, for errors. NULL with err filled. */
api_loft *api_loft_parse(const cJSON *j, const char *ptr, api_error *err);
void api_loft_free(api_loft *l);
const pde_loft *api_loft_get(const api_loft *l);

/* pde_solve_loft() with the core's diagnosis turned into a pointer under ptr; 0 or the status. */
int api_loft_solve(const api_loft *l, const char *ptr, const pde_cancel *cancel, pde_solution **out,
                   api_error *err);

/* The gallery's lofts (loft_presets.c): vase, tower, blade, bottle. The name of the i-th (and its
 * caption into *caption, unless NULL), or NULL past the last. */
size_t api_loft_preset_count(void);
const char *api_loft_preset_name(size_t i, const char **caption);
/* The document {"loft": {...}} of the loft preset name (cJSON_Delete it), or NULL if none has it. */
cJSON *api_loft_preset_tree(const char *name);

#endif
