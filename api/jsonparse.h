/*
 * jsonparse.h: the pieces of api/'s JSON that its files share (internal to api/): strict reading, and
 * writing numbers exactly. Each check fills err with a JSON pointer and a sentence (api_fail, API_ERR_DOCUMENT) and returns
 * -1 on failure, 0 on success.
 */
#ifndef API_JSONPARSE_H
#define API_JSONPARSE_H

#include <stddef.h>

#include <cJSON.h>

#include "model.h"

/* ptr + "/" + key as RFC 6901 writes a key: ~ as ~0 and / as ~1. */
void api_json_child(char *out, size_t n, const char *ptr, const char *key);
/* "a number", "an array", ... for messages. */
const char *api_json_type(const cJSON *j);
/* obj is an object whose keys are all in keys[] (NULL-ended), each once; found[i] gets keys[i]'s child or NULL. */
int api_json_object(const cJSON *obj, const char *ptr, const char *const *keys, const cJSON **found, api_error *err);
/* A finite number into *out, or 0 when j is NULL. */
int api_json_number(const cJSON *j, const char *ptr, double *out, api_error *err);
/* A factor {"pow": n}, {"sin": k}, ... into *f, or the constant 1 when j is NULL. */
int api_json_factor(const cJSON *j, const char *ptr, pde_factor *f, api_error *err);
/* An array of three finite numbers (required). */
int api_json_vector3(const cJSON *j, const char *ptr, double out[3], api_error *err);

/* v as a JSON number that reads back as v exactly (api_fmt_f64), null when not finite; NULL only
 * for want of memory. cJSON_CreateNumber would settle for 15 digits. */
cJSON *api_json_exact(double v);
/* The same, n of them as an array. */
cJSON *api_json_exact_array(const double *v, int n);
/* api_json_exact(v) as obj's key: the item, or NULL for want of memory (as cJSON_AddNumberToObject). */
cJSON *api_json_add_exact(cJSON *obj, const char *key, double v);

#endif
