/*
 * id.h: the canonical id of a model, a hash of its canonical form
 * (pde_model_canonical: terms merged and sorted, factors and numbers
 * normalised), so that equal models get the same id however their JSON is
 * spelled. It keys the server's cache and ETags.
 */
#ifndef API_ID_H
#define API_ID_H

#include "pde.h"

#define API_ID_LEN 32    /* hex digits: the first 128 bits of a SHA-256 */

/* Writes the id and a NUL into id[API_ID_LEN + 1]. Returns PDE_OK or the model's error. */
pde_status api_model_id(const pde_model *m, char id[API_ID_LEN + 1], pde_diag *diag);
/* A loft's id (its terms as api/loft.c builds them: merged, sorted, no -0). */
pde_status api_loft_id(const pde_loft *l, char id[API_ID_LEN + 1]);
/* The id of what api_model_parse() read: a model's, or a loft's. */
struct api_model;
pde_status api_request_id(const struct api_model *m, char id[API_ID_LEN + 1], pde_diag *diag);
/* 1 if s is the form of an id: API_ID_LEN lowercase hex digits and nothing else. */
int api_id_valid(const char *s);

#endif
