/*
 * template.h: the paper's four example families as templates with its own
 * parameter names, and every solid of its figures as a preset: a template
 * with values.
 *
 * USAGE
 *
 *   const api_template *t = api_template_find("example4");
 *   api_params p;
 *   api_template_defaults(t, &p);                 // the family's first figure
 *   api_params_set(t, &p, "p0", (double[]){5e4}, 1, &err);
 *   api_model *m = api_template_expand(t, &p, &err);
 *
 *   const api_preset *ps = api_preset_find("fig4a");
 *   api_preset_params(ps, &p);                    // its template's values for the figure
 *
 * A tangent x' of the paper is spelled x0p: "r0p" is r'_0. Each template also
 * takes the PDE's vectors "a", "b" and "c" (three numbers each). Everything
 * here is reentrant and uses no cJSON.
 */
#ifndef API_TEMPLATE_H
#define API_TEMPLATE_H

#include <stddef.h>

#include "model.h"

#define API_MAX_SLOTS 40

typedef struct {
    const char *name;     /* "r0", "r0p", "a" ... */
    int slots;            /* 1, or 3 for the vectors a, b, c */
    const char *help;     /* what it is, in the paper's words */
} api_param_info;

typedef struct api_template api_template;

typedef struct {
    double v[API_MAX_SLOTS];
} api_params;

typedef struct {
    const char *name;       /* "fig4a" */
    const char *template;   /* "example4" */
    const char *caption;    /* the figure's caption and parameters, from the paper */
    const char *values;     /* "name=v name=v1,v2,v3 ..." over the template's defaults */
} api_preset;

size_t api_template_count(void);
const api_template *api_template_at(size_t i);
const api_template *api_template_find(const char *name);   /* NULL if none */
const char *api_template_name(const api_template *t);
const char *api_template_title(const api_template *t);
/* The parameters, in order; their slots follow one another in api_params.v. */
const api_param_info *api_template_params(const api_template *t, size_t *n);

void api_template_defaults(const api_template *t, api_params *p);
/* Sets one parameter (n values: 1, or 3 for a vector). Returns 0, or -1 with err naming it. */
int api_params_set(const api_template *t, api_params *p, const char *name, const double *vals, int n,
                   api_error *err);
/* Reads the value of one parameter into vals (1 or 3 values); returns its slot count or 0. */
int api_params_get(const api_template *t, const api_params *p, const char *name, double *vals);

/* The general model of the template with these values; NULL and err on failure. */
api_model *api_template_expand(const api_template *t, const api_params *p, api_error *err);

size_t api_preset_count(void);
const api_preset *api_preset_at(size_t i);
const api_preset *api_preset_find(const char *name);        /* NULL if none */
const api_template *api_preset_template(const api_preset *p);
/* The preset's parameter values: its template's defaults, then its own values. */
void api_preset_params(const api_preset *ps, api_params *p);

#endif
