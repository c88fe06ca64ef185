/*
 * describe.h: a solution's closed form and properties as text for people,
 * as `pdesolid solve` prints them.
 */
#ifndef API_DESCRIBE_H
#define API_DESCRIBE_H

#include <stdio.h>

#include "pde.h"

/* Writes every component's modes and h(w), then the properties if props is not NULL. */
void api_describe(FILE *out, const pde_solution *sol, const pde_props *props);

/* The properties block alone, as api_describe() ends. */
void api_describe_props(FILE *out, const pde_props *props);

/* A factor as text, e.g. "sin(2*pi*u)", "u^3", "1". */
void api_factor_text(char *buf, size_t n, pde_factor f, char var);

#endif
