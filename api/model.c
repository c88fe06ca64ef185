/*
 * model.c: the JSON model format (model.h) read with cJSON into a pde_model.
 *
 * Every object is checked against the keys it may hold, so a typo is an
 * error that names the key, not a silently ignored field. cJSON keeps
 * duplicate keys as separate children, which are caught the same way.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "model.h"
#include "jsonparse.h"
#include "numfmt.h"
#include "loft.h"
#include "strict.h"
#include "template.h"

struct api_model {
    pde_model m;
    api_loft *loft;     /* a loft document (loft.h): m is then empty */
    pde_bterm *b[3];
    pde_fterm *f[3];
    int from_params;    /* expanded from a preset or template: errors point into /params */
};

static const char *const comp_key[3] = { "x", "y", "z" };

/*
 * Both strings go through api_text_clean(), so that whatever a message quotes
 * (a key, a preset's name, a truncated %.60s) and however it is cut, the error
 * is valid UTF-8 with no control characters, fit for a JSON body or a terminal.
 */
static const char *const status_text[] = {
    [API_OK] = "no error",
    [API_ERR_NOMEM] = "out of memory",
    [API_ERR_LIMIT] = "over a size limit",
    [API_ERR_DOCUMENT] = "a bad document",
    [API_ERR_NOT_JSON] = "not JSON",
    [API_ERR_CANCELLED] = "cancelled",
    [API_ERR_NOT_FOUND] = "not found",
};

const char *api_strerror(api_status s)
{
    return (unsigned)s < sizeof status_text / sizeof *status_text && status_text[s] ? status_text[s] : "unknown error";
}

int api_fail(api_error *err, api_status status, const char *pointer, const char *fmt, ...)
{
    if (!err)
        return -1;
    err->status = status;
    char text[1024];
    api_text_clean(err->pointer, sizeof err->pointer, pointer, strlen(pointer));
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    api_text_clean(err->message, sizeof err->message, text, strlen(text));
    return -1;
}

int api_fail_cancelled(api_error *err)
{
    api_fail(err, API_ERR_CANCELLED, "", "cancelled");
    return (int)PDE_ERR_CANCELLED;
}

api_status api_status_of(pde_status st)
{
    return st == PDE_OK ? API_OK : st == PDE_ERR_NOMEM ? API_ERR_NOMEM : st == PDE_ERR_LIMIT ? API_ERR_LIMIT
         : st == PDE_ERR_CANCELLED ? API_ERR_CANCELLED : API_ERR_DOCUMENT;
}

int api_fail_nomem(api_error *err)
{
    return api_fail(err, API_ERR_NOMEM, "", "out of memory");
}

/* ptr + "/" + key as RFC 6901 writes a key: ~ as ~0 and / as ~1. */
void api_json_child(char *out, size_t n, const char *ptr, const char *key)
{
    size_t w = (size_t)snprintf(out, n, "%s/", ptr);
    for (; *key && w + 2 < n; key++) {
        if (*key == '~' || *key == '/') {
            out[w++] = '~';
            out[w++] = *key == '~' ? '0' : '1';
        } else {
            out[w++] = *key;
        }
    }
    if (w < n)
        out[w] = '\0';
}

/* A name for a message: at most 63 bytes, cut at a character boundary, controls as U+FFFD. */
static const char *quoted(char out[64], const char *s)
{
    api_text_clean(out, 64, s, strlen(s));
    return out;
}

const char *api_json_type(const cJSON *j)
{
    if (cJSON_IsNumber(j)) return "a number";
    if (cJSON_IsString(j)) return "a string";
    if (cJSON_IsBool(j)) return "a boolean";
    if (cJSON_IsNull(j)) return "null";
    if (cJSON_IsArray(j)) return "an array";
    if (cJSON_IsObject(j)) return "an object";
    return "invalid";
}

/*
 * Checks that obj is an object whose keys are all in keys[] (NULL-ended) and
 * appear once; found[i] gets the child for keys[i] or NULL.
 */
int api_json_object(const cJSON *obj, const char *ptr, const char *const *keys,
                        const cJSON **found, api_error *err)
{
    if (!cJSON_IsObject(obj))
        return api_fail(err, API_ERR_DOCUMENT, ptr, "must be an object, not %s", api_json_type(obj));
    size_t nk = 0;
    while (keys[nk])
        found[nk++] = NULL;
    for (const cJSON *c = obj->child; c; c = c->next) {
        size_t i = 0;
        while (i < nk && strcmp(keys[i], c->string) != 0)
            i++;
        char at[200], q[64];
        if (i == nk) {
            char allowed[160] = "";
            for (size_t k = 0; k < nk; k++)
                snprintf(allowed + strlen(allowed), sizeof allowed - strlen(allowed), "%s\"%s\"",
                         k ? ", " : "", keys[k]);
            api_json_child(at, sizeof at, ptr, c->string);
            return api_fail(err, API_ERR_DOCUMENT, at, "unknown key \"%s\"; the keys here are %s", quoted(q, c->string), allowed);
        }
        if (found[i]) {
            api_json_child(at, sizeof at, ptr, keys[i]);
            return api_fail(err, API_ERR_DOCUMENT, at, "the key \"%s\" appears twice", keys[i]);
        }
        found[i] = c;
    }
    return 0;
}

/* A finite number, or 0 when absent. */
int api_json_number(const cJSON *j, const char *ptr, double *out, api_error *err)
{
    if (!j) {
        *out = 0.0;
        return 0;
    }
    if (!cJSON_IsNumber(j))
        return api_fail(err, API_ERR_DOCUMENT, ptr, "must be a number, not %s", api_json_type(j));
    if (!isfinite(j->valuedouble))
        return api_fail(err, API_ERR_DOCUMENT, ptr, "must be a finite number; this one overflows a double");
    *out = j->valuedouble;
    return 0;
}

int api_json_factor(const cJSON *j, const char *ptr, pde_factor *f, api_error *err)
{
    static const char *const kinds[] = { "pow", "sin", "cos", "exp", "sinh", "cosh", NULL };
    f->kind = PDE_POW;
    f->p = 0.0;
    if (!j)
        return 0;
    const cJSON *found[6];
    if (api_json_object(j, ptr, kinds, found, err))
        return -1;
    int which = -1;
    for (int k = 0; k < 6; k++)
        if (found[k]) {
            if (which >= 0)
                return api_fail(err, API_ERR_DOCUMENT, ptr, "a factor has one key, not both \"%s\" and \"%s\"",
                                kinds[which], kinds[k]);
            which = k;
        }
    if (which < 0)
        return api_fail(err, API_ERR_DOCUMENT, ptr, "a factor needs one of \"pow\", \"sin\", \"cos\", \"exp\", \"sinh\", \"cosh\"");
    char p[200];
    api_json_child(p, sizeof p, ptr, kinds[which]);
    if (api_json_number(found[which], p, &f->p, err))
        return -1;
    f->kind = (pde_factor_kind)which;
    if (which == PDE_POW && (f->p != floor(f->p) || f->p < 0 || f->p > PDE_MAX_POW))
        return api_fail(err, API_ERR_DOCUMENT, p, "the power must be a whole number from 0 to %d, not %.17g", PDE_MAX_POW, f->p);
    if ((which == PDE_SIN || which == PDE_COS) && fabs(f->p) > 1e6)
        return api_fail(err, API_ERR_DOCUMENT, p, "k must be at most 1e6 in size (the factor is %s(k*pi*t))", kinds[which]);
    if (which >= PDE_EXP && fabs(f->p) > PDE_MAX_ARG)
        return api_fail(err, API_ERR_DOCUMENT, p, "alpha must be at most %g in size, or %s(alpha*t) overflows a double",
                        PDE_MAX_ARG, kinds[which]);
    return 0;
}

int api_json_vector3(const cJSON *j, const char *ptr, double out[3], api_error *err)
{
    if (!j)
        return api_fail(err, API_ERR_DOCUMENT, ptr, "is required: an array of three numbers, one for each of x, y, z");
    if (!cJSON_IsArray(j) || cJSON_GetArraySize(j) != 3)
        return api_fail(err, API_ERR_DOCUMENT, ptr, "must be an array of three numbers, one for each of x, y, z");
    int i = 0;
    for (const cJSON *c = j->child; c; c = c->next, i++) {
        char p[200];
        snprintf(p, sizeof p, "%s/%d", ptr, i);
        if (!c || api_json_number(c, p, &out[i], err))
            return -1;
    }
    return 0;
}

/* An array of terms; returns its length via *n and the array itself via *items. */
static int term_array(const cJSON *j, const char *ptr, size_t *n, api_error *err)
{
    if (!cJSON_IsArray(j))
        return api_fail(err, API_ERR_DOCUMENT, ptr, "must be an array of terms, not %s", api_json_type(j));
    size_t k = 0;
    for (const cJSON *c = j->child; c; c = c->next)
        if (++k > API_MAX_TERMS) {
            return api_fail(err, API_ERR_LIMIT, ptr, "has more than %d terms, the limit", API_MAX_TERMS);
        }
    *n = k;
    return 0;
}

static int parse_bterms(const cJSON *j, const char *ptr, api_model *m, int ci, api_error *err)
{
    static const char *const keys[] = { "u", "v", "w0", "dw0", "w1", "dw1", NULL };
    size_t n = 0;
    if (term_array(j, ptr, &n, err))
        return -1;
    m->b[ci] = calloc(n ? n : 1, sizeof *m->b[ci]);
    if (!m->b[ci])
        return api_fail(err, API_ERR_NOMEM, ptr, "out of memory");
    size_t i = 0;
    for (const cJSON *c = j->child; c; c = c->next, i++) {
        char p[200], q[220];
        snprintf(p, sizeof p, "%s/%zu", ptr, i);
        const cJSON *f[6];
        pde_bterm *t = &m->b[ci][i];
        if (api_json_object(c, p, keys, f, err))
            return -1;
        double *num[4] = { &t->w0, &t->dw0, &t->w1, &t->dw1 };
        for (int k = 0; k < 2; k++) {
            api_json_child(q, sizeof q, p, keys[k]);
            if (api_json_factor(f[k], q, k ? &t->v : &t->u, err))
                return -1;
        }
        for (int k = 0; k < 4; k++) {
            api_json_child(q, sizeof q, p, keys[k + 2]);
            if (api_json_number(f[k + 2], q, num[k], err))
                return -1;
        }
    }
    m->m.comp[ci].bterms = m->b[ci];
    m->m.comp[ci].nbterms = n;
    return 0;
}

static int parse_fterms(const cJSON *j, const char *ptr, api_model *m, int ci, api_error *err)
{
    static const char *const keys[] = { "coef", "u", "v", "w", NULL };
    size_t n = 0;
    if (term_array(j, ptr, &n, err))
        return -1;
    m->f[ci] = calloc(n ? n : 1, sizeof *m->f[ci]);
    if (!m->f[ci])
        return api_fail(err, API_ERR_NOMEM, ptr, "out of memory");
    size_t i = 0;
    for (const cJSON *c = j->child; c; c = c->next, i++) {
        char p[200], q[220];
        snprintf(p, sizeof p, "%s/%zu", ptr, i);
        const cJSON *f[4];
        pde_fterm *t = &m->f[ci][i];
        if (api_json_object(c, p, keys, f, err))
            return -1;
        api_json_child(q, sizeof q, p, "coef");
        if (api_json_number(f[0], q, &t->coef, err))
            return -1;
        pde_factor *fac[3] = { &t->u, &t->v, &t->w };
        for (int k = 0; k < 3; k++) {
            api_json_child(q, sizeof q, p, keys[k + 1]);
            if (api_json_factor(f[k + 1], q, fac[k], err))
                return -1;
        }
    }
    m->m.comp[ci].fterms = m->f[ci];
    m->m.comp[ci].nfterms = n;
    return 0;
}

static int parse_model(const cJSON *root, api_model *m, api_error *err)
{
    static const char *const top[] = { "pde", "boundary", "force", NULL };
    static const char *const abc[] = { "a", "b", "c", NULL };
    static const char *const xyz[] = { "x", "y", "z", NULL };
    const cJSON *t[3], *p[3], *comps[3];
    if (api_json_object(root, "", top, t, err))
        return -1;
    if (!t[0])
        return api_fail(err, API_ERR_DOCUMENT, "/pde", "is required: {\"a\": [..], \"b\": [..], \"c\": [..]}, the PDE's coefficients");
    if (api_json_object(t[0], "/pde", abc, p, err))
        return -1;
    double v[3][3];
    for (int k = 0; k < 3; k++) {
        char q[32];
        snprintf(q, sizeof q, "/pde/%s", abc[k]);
        if (api_json_vector3(p[k], q, v[k], err))
            return -1;
    }
    for (int ci = 0; ci < 3; ci++) {
        m->m.comp[ci].a = v[0][ci];
        m->m.comp[ci].b = v[1][ci];
        m->m.comp[ci].c = v[2][ci];
    }
    for (int sect = 1; sect <= 2; sect++) {
        if (!t[sect])
            continue;
        const char *name = top[sect];
        char q[32];
        snprintf(q, sizeof q, "/%s", name);
        if (api_json_object(t[sect], q, xyz, comps, err))
            return -1;
        for (int ci = 0; ci < 3; ci++) {
            if (!comps[ci])
                continue;
            char r[40];
            snprintf(r, sizeof r, "/%s/%s", name, comp_key[ci]);
            if ((sect == 1 ? parse_bterms : parse_fterms)(comps[ci], r, m, ci, err))
                return -1;
        }
    }
    return 0;
}

/* {"preset": NAME, "params": {...}} or {"template": NAME, "params": {...}}. */
static api_model *parse_request(const cJSON *root, api_error *err)
{
    static const char *const keys[] = { "preset", "template", "params", NULL };
    const cJSON *k[3];
    if (api_json_object(root, "", keys, k, err))
        return NULL;
    if (k[0] && k[1]) {
        api_fail(err, API_ERR_DOCUMENT, "", "give either \"preset\" or \"template\", not both");
        return NULL;
    }
    const cJSON *name = k[0] ? k[0] : k[1];
    const char *ptr = k[0] ? "/preset" : "/template";
    if (!cJSON_IsString(name)) {
        api_fail(err, API_ERR_DOCUMENT, ptr, "must be a string, not %s", api_json_type(name));
        return NULL;
    }
    const api_template *t;
    api_params p;
    char q0[64];
    if (k[0] && !api_preset_find(name->valuestring)) {
        cJSON *doc = api_loft_preset_tree(name->valuestring);   /* a loft of the gallery */
        if (doc) {
            api_model *m = NULL;
            if (k[2])
                api_fail(err, API_ERR_DOCUMENT, "/params", "the loft preset \"%s\" takes no params; change its document (GET /presets/%s, "
                         "or pdesolid presets --preset %s) and give that", name->valuestring, name->valuestring,
                         name->valuestring);
            else if (!(m = calloc(1, sizeof *m)))
                api_fail(err, API_ERR_NOMEM, "", "out of memory");
            else if (!(m->loft = api_loft_parse(cJSON_GetObjectItemCaseSensitive(doc, "loft"), "/loft", err))) {
                free(m);
                m = NULL;
            }
            cJSON_Delete(doc);
            return m;
        }
    }
    if (k[0]) {
        const api_preset *ps = api_preset_find(name->valuestring);
        if (!ps) {
            api_fail(err, API_ERR_DOCUMENT, ptr, "no preset \"%s\"; GET /presets (or `pdesolid presets`) lists them",
                     quoted(q0, name->valuestring));
            return NULL;
        }
        t = api_preset_template(ps);
        api_preset_params(ps, &p);
    } else {
        if (!(t = api_template_find(name->valuestring))) {
            api_fail(err, API_ERR_DOCUMENT, ptr, "no template \"%s\"; the templates are example1, example2, example3, example4",
                     quoted(q0, name->valuestring));
            return NULL;
        }
        api_template_defaults(t, &p);
    }
    if (k[2]) {
        if (!cJSON_IsObject(k[2])) {
            api_fail(err, API_ERR_DOCUMENT, "/params", "must be an object of parameter values, not %s", api_json_type(k[2]));
            return NULL;
        }
        for (const cJSON *c = k[2]->child; c; c = c->next) {
            char q[200];
            api_json_child(q, sizeof q, "/params", c->string);
            for (const cJSON *d = k[2]->child; d != c; d = d->next)
                if (strcmp(d->string, c->string) == 0) {
                    api_fail(err, API_ERR_DOCUMENT, q, "the key \"%s\" appears twice", quoted(q0, c->string));
                    return NULL;
                }
            double v[3];
            int n = 0;
            if (cJSON_IsNumber(c)) {
                v[n++] = c->valuedouble;
            } else if (cJSON_IsArray(c) && cJSON_GetArraySize(c) == 3) {
                for (const cJSON *x = c->child; x; x = x->next) {
                    char qi[220];
                    snprintf(qi, sizeof qi, "%s/%d", q, n);
                    if (api_json_number(x, qi, &v[n++], err))
                        return NULL;
                }
            } else {
                if (cJSON_IsArray(c))
                    api_fail(err, API_ERR_DOCUMENT, q, "must be a number, or an array of three for a, b and c; not an "
                             "array of %d", cJSON_GetArraySize(c));
                else
                    api_fail(err, API_ERR_DOCUMENT, q, "must be a number, or an array of three for a, b and c; not %s",
                             api_json_type(c));
                return NULL;
            }
            if (n == 1 && api_json_number(c, q, &v[0], err))
                return NULL;
            if (api_params_set(t, &p, c->string, v, n, err)) {
                /* template.c writes the key as it is; a pointer escapes ~ and / */
                api_text_clean(err->pointer, sizeof err->pointer, q, strlen(q));
                return NULL;
            }
        }
    }
    return api_template_expand(t, &p, err);
}

/*
 * cJSON over a private NUL-terminated copy (1.7.15 may read past a buffer
 * without one), after api_json_check(): cJSON never sees NUL, invalid UTF-8,
 * leading zeros or nesting over the limit.
 */
static cJSON *parse_json(const char *text, size_t len, api_error *err)
{
    if (api_json_check(text, len, err))
        return NULL;
    char *copy = malloc(len + 1);
    if (!copy) {
        api_fail(err, API_ERR_NOMEM, "", "out of memory");
        return NULL;
    }
    memcpy(copy, text, len);
    copy[len] = '\0';
    cJSON *root = cJSON_ParseWithLength(copy, len + 1);
    if (!root)   /* checked JSON that cJSON still refuses: it ran out of memory */
        api_fail(err, API_ERR_NOMEM, "", "out of memory");
    free(copy);
    return root;
}

api_model *api_model_parse(const char *text, size_t len, api_error *err)
{
    cJSON *root = parse_json(text, len, err);
    if (!root)
        return NULL;
    api_model *m = NULL;
    if (cJSON_IsObject(root) && (cJSON_GetObjectItemCaseSensitive(root, "preset") ||
                                 cJSON_GetObjectItemCaseSensitive(root, "template"))) {
        m = parse_request(root, err);
    } else if (cJSON_IsObject(root) && cJSON_GetObjectItemCaseSensitive(root, "loft")) {
        static const char *const keys[] = { "loft", NULL };
        const cJSON *f[1];
        if (!api_json_object(root, "", keys, f, err) && (m = calloc(1, sizeof *m)) == NULL)
            api_fail(err, API_ERR_NOMEM, "", "out of memory");
        if (m && !(m->loft = api_loft_parse(f[0], "/loft", err))) {
            api_model_free(m);
            m = NULL;
        }
    } else if (!(m = calloc(1, sizeof *m))) {
        api_fail(err, API_ERR_NOMEM, "", "out of memory");
    } else if (parse_model(root, m, err)) {
        api_model_free(m);
        m = NULL;
    }
    cJSON_Delete(root);
    return m;
}

api_model *api_model_build(const pde_model *src, int from_params, api_error *err)
{
    api_model *m = calloc(1, sizeof *m);
    if (!m) {
        api_fail(err, API_ERR_NOMEM, "", "out of memory");
        return NULL;
    }
    m->m = *src;
    m->from_params = from_params;
    for (int c = 0; c < 3; c++) {
        size_t nb = src->comp[c].nbterms, nf = src->comp[c].nfterms;
        m->b[c] = malloc((nb ? nb : 1) * sizeof *m->b[c]);
        m->f[c] = malloc((nf ? nf : 1) * sizeof *m->f[c]);
        if (!m->b[c] || !m->f[c]) {
            api_model_free(m);
            api_fail(err, API_ERR_NOMEM, "", "out of memory");
            return NULL;
        }
        if (nb)
            memcpy(m->b[c], src->comp[c].bterms, nb * sizeof *m->b[c]);
        if (nf)
            memcpy(m->f[c], src->comp[c].fterms, nf * sizeof *m->f[c]);
        m->m.comp[c].bterms = m->b[c];
        m->m.comp[c].fterms = m->f[c];
    }
    return m;
}

void api_model_free(api_model *m)
{
    if (!m)
        return;
    for (int i = 0; i < 3; i++) {
        free(m->b[i]);
        free(m->f[i]);
    }
    api_loft_free(m->loft);
    free(m);
}

const pde_model *api_model_get(const api_model *m)
{
    return &m->m;
}

const pde_loft *api_model_loft(const api_model *m)
{
    return m->loft ? api_loft_get(m->loft) : NULL;
}

int api_solve(const api_model *m, pde_solution **out, api_error *err)
{
    return api_solve_ex(m, NULL, out, err);
}

int api_solve_ex(const api_model *m, const pde_cancel *cancel, pde_solution **out, api_error *err)
{
    if (m->loft)
        return api_loft_solve(m->loft, "/loft", cancel, out, err);
    pde_diag d;
    pde_solve_opts o = { .cancel = cancel };
    pde_status st = pde_solve_ex(&m->m, &o, out, &d);
    if (st == PDE_OK)
        return 0;
    if (st == PDE_ERR_CANCELLED)
        return api_fail_cancelled(err);
    char ptr[160] = "";
    if (m->from_params)
        snprintf(ptr, sizeof ptr, d.term < 0 && d.field[0] ? "/params/%s/%d" : "/params", d.field, d.component);
    else if (d.component >= 0 && d.term < 0 && d.field[0])
        snprintf(ptr, sizeof ptr, "/pde/%s/%d", d.field, d.component);
    else if (d.component >= 0 && d.term >= 0)
        snprintf(ptr, sizeof ptr, "/%s/%s/%ld%s%s", d.in_force ? "force" : "boundary",
                 comp_key[d.component], d.term, d.field[0] ? "/" : "", d.field);
    api_fail(err, api_status_of(st), ptr, "%s", d.message[0] ? d.message : pde_strerror(st));
    return (int)st;
}

/* Reads an array of [u, v, w] at ptr into a new array; at most max points (over it: 413). */
static int points_from(const cJSON *arr, const char *ptr, size_t max, double **out, size_t *count, api_error *err)
{
    if (!cJSON_IsArray(arr))
        return api_fail(err, API_ERR_DOCUMENT, ptr, "must be an array of [u, v, w] points, not %s", api_json_type(arr));
    size_t k = 0;
    for (const cJSON *c = arr->child; c; c = c->next)
        if (++k > max) {
            return api_fail(err, API_ERR_LIMIT, ptr, "has more than %zu points, the limit", max);
        }
    double *pts = malloc((k ? k : 1) * 3 * sizeof *pts);
    if (!pts)
        return api_fail(err, API_ERR_NOMEM, ptr, "out of memory");
    size_t i = 0;
    for (const cJSON *c = arr->child; c; c = c->next, i++) {
        char p[64];
        snprintf(p, sizeof p, "%.40s/%zu", ptr, i);
        if (!cJSON_IsArray(c) || cJSON_GetArraySize(c) != 3) {
            free(pts);
            return api_fail(err, API_ERR_DOCUMENT, p, "must be a point [u, v, w] of three numbers");
        }
        int q = 0;
        for (const cJSON *x = c->child; x; x = x->next, q++) {
            char pq[80];
            snprintf(pq, sizeof pq, "%s/%d", p, q);
            if (api_json_number(x, pq, &pts[3 * i + q], err)) {
                free(pts);
                return -1;
            }
        }
    }
    *out = pts;
    *count = k;
    return 0;
}

int api_points_parse(const char *text, size_t len, double **out, size_t *n, api_error *err)
{
    cJSON *root = parse_json(text, len, err);
    if (!root)
        return -1;
    int rc = points_from(root, "", API_MAX_POINTS, out, n, err);
    cJSON_Delete(root);
    return rc;
}

int api_eval_parse(const char *text, size_t len, size_t max_points, double **out, size_t *n, int *derivatives,
                   api_error *err)
{
    static const char *const keys[] = { "points", "derivatives", NULL };
    cJSON *root = parse_json(text, len, err);
    if (!root)
        return -1;
    const cJSON *k[2];
    int rc = api_json_object(root, "", keys, k, err);
    if (!rc && !k[0])
        rc = api_fail(err, API_ERR_DOCUMENT, "/points", "is required: an array of [u, v, w] points");
    if (!rc && k[1] && !cJSON_IsBool(k[1]))
        rc = api_fail(err, API_ERR_DOCUMENT, "/derivatives", "must be true or false, not %s", api_json_type(k[1]));
    if (!rc)
        rc = points_from(k[0], "/points", max_points, out, n, err);
    if (!rc)
        *derivatives = k[1] && cJSON_IsTrue(k[1]);
    cJSON_Delete(root);
    return rc;
}

cJSON *api_json_exact(double v)
{
    char s[API_F64_MAX];
    if (!isfinite(v))
        return cJSON_CreateNull();
    api_fmt_f64(s, v);
    return cJSON_CreateRaw(s);
}

cJSON *api_json_exact_array(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < n; i++) {
        cJSON *x = api_json_exact(v[i]);
        if (!x || !cJSON_AddItemToArray(a, x)) {
            cJSON_Delete(x);
            cJSON_Delete(a);
            return NULL;
        }
    }
    return a;
}

cJSON *api_json_add_exact(cJSON *obj, const char *key, double v)
{
    cJSON *x = api_json_exact(v);
    if (!x || !cJSON_AddItemToObject(obj, key, x)) {
        cJSON_Delete(x);
        return NULL;
    }
    return x;
}

cJSON *api_factor_tree(pde_factor f)
{
    static const char *const kinds[] = { "pow", "sin", "cos", "exp", "sinh", "cosh" };
    cJSON *o = cJSON_CreateObject();
    if (o && !api_json_add_exact(o, kinds[f.kind], f.p)) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

/* 1 when done (or nothing to do), 0 out of memory. */
static int add_factor(cJSON *o, const char *key, pde_factor f)
{
    if (f.kind == PDE_POW && f.p == 0)   /* 1, the default, is left out */
        return 1;
    cJSON *t = api_factor_tree(f);
    if (t && cJSON_AddItemToObject(o, key, t))
        return 1;
    cJSON_Delete(t);
    return 0;
}

/* Every allocation is checked: out of memory anywhere gives NULL, never a partial tree. */
cJSON *api_model_tree(const pde_model *m)
{
    cJSON *root = cJSON_CreateObject(), *pde = cJSON_AddObjectToObject(root, "pde");
    cJSON *bd = cJSON_AddObjectToObject(root, "boundary"), *fo = cJSON_AddObjectToObject(root, "force");
    int ok = pde && bd && fo;
    double abc[3][3];
    for (int c = 0; c < 3; c++) {
        abc[0][c] = m->comp[c].a;
        abc[1][c] = m->comp[c].b;
        abc[2][c] = m->comp[c].c;
    }
    static const char *const names[3] = { "a", "b", "c" };
    for (int k = 0; ok && k < 3; k++) {
        cJSON *arr = api_json_exact_array(abc[k], 3);
        ok = arr && cJSON_AddItemToObject(pde, names[k], arr);
        if (!ok)
            cJSON_Delete(arr);
    }
    for (int c = 0; ok && c < 3; c++) {
        const pde_component *k = &m->comp[c];
        if (k->nbterms) {
            cJSON *list = cJSON_AddArrayToObject(bd, comp_key[c]);
            ok = list != NULL;
            for (size_t j = 0; ok && j < k->nbterms; j++) {
                const pde_bterm *t = &k->bterms[j];
                cJSON *o = cJSON_CreateObject();
                ok = o && cJSON_AddItemToArray(list, o);
                if (!ok) {
                    cJSON_Delete(o);
                    break;
                }
                ok = add_factor(o, "u", t->u) && add_factor(o, "v", t->v) && api_json_add_exact(o, "w0", t->w0) &&
                     api_json_add_exact(o, "dw0", t->dw0) && api_json_add_exact(o, "w1", t->w1) &&
                     api_json_add_exact(o, "dw1", t->dw1);
            }
        }
        if (ok && k->nfterms) {
            cJSON *list = cJSON_AddArrayToObject(fo, comp_key[c]);
            ok = list != NULL;
            for (size_t j = 0; ok && j < k->nfterms; j++) {
                const pde_fterm *t = &k->fterms[j];
                cJSON *o = cJSON_CreateObject();
                ok = o && cJSON_AddItemToArray(list, o);
                if (!ok) {
                    cJSON_Delete(o);
                    break;
                }
                ok = api_json_add_exact(o, "coef", t->coef) && add_factor(o, "u", t->u) &&
                     add_factor(o, "v", t->v) && add_factor(o, "w", t->w);
            }
        }
    }
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

char *api_model_json(const pde_model *m)
{
    cJSON *root = api_model_tree(m);
    char *s = root ? cJSON_PrintUnformatted(root) : NULL;
    cJSON_Delete(root);
    return s;
}
