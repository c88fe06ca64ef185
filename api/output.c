/*
 * output.c: the formats of output.h, each as a little state machine that
 * refills a buffer with the next piece: a header, a chunk of rows, a run of
 * base64. Grids are sampled a few rows at a time, so a 256^3 f32 grid
 * (200 MB) streams through a buffer of about 1 MB; meshes are built whole
 * (their welding needs every face) and streamed from one binary blob.
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "describe.h"
#include "id.h"
#include "mesh.h"
#include "numfmt.h"
#include "output.h"

/* One call of api_output_read() samples at most CHUNK_POINTS points, or rows worth about CHUNK_WORK
 * multiply-adds (about 1 ms), whichever is fewer, but at least one row. */
#define CHUNK_POINTS 16384
#define CHUNK_WORK (1u << 21)

static const api_format_info formats[API_FMT_COUNT] = {
    { "json", "application/json", ".json", 0, 1, 0 },
    { "grid", "application/json", ".grid.json", 0, 0, 0 },
    { "f32", "application/octet-stream", ".f32", 0, 0, 1 },
    { "gltf", "model/gltf+json", ".gltf", 1, 1, 0 },
    { "glb", "model/gltf-binary", ".glb", 1, 1, 1 },
    { "vts", "application/xml", ".vts", 0, 1, 1 },   /* XML around raw appended float32 */
    { "stl", "model/stl", ".stl", 1, 0, 1 },
};

char *api_formats_json(void)
{
    cJSON *a = cJSON_CreateArray();
    int ok = a != NULL;
    for (int i = 0; ok && i < API_FMT_COUNT; i++) {
        const api_format_info *f = &formats[i];
        cJSON *o = cJSON_CreateObject();
        ok = o && cJSON_AddItemToArray(a, o) && cJSON_AddStringToObject(o, "name", f->name) &&
             cJSON_AddStringToObject(o, "media_type", f->mime) && cJSON_AddStringToObject(o, "extension", f->ext) &&
             cJSON_AddBoolToObject(o, "binary", f->binary) && cJSON_AddBoolToObject(o, "mesh", f->mesh) &&
             cJSON_AddBoolToObject(o, "properties", f->props) &&
             cJSON_AddNumberToObject(o, "default_res", f->mesh ? API_RES_MESH_DEFAULT : API_RES_GRID_DEFAULT);
        if (!o)
            break;
    }
    char *s = ok ? cJSON_PrintUnformatted(a) : NULL;
    cJSON_Delete(a);
    return s;
}

const api_format_info *api_format_info_of(api_format f)
{
    return (unsigned)f < API_FMT_COUNT ? &formats[f] : NULL;
}

int api_format_parse(const char *name, api_format *f, api_error *err)
{
    for (int i = 0; i < API_FMT_COUNT; i++)
        if (strcmp(formats[i].name, name) == 0) {
            *f = (api_format)i;
            return 0;
        }
    char list[256];
    size_t n = 0;
    for (int i = 0; i < API_FMT_COUNT && n < sizeof list; i++)   /* the list from the table */
        n += (size_t)snprintf(list + n, sizeof list - n, "%s%s", i ? ", " : "", formats[i].name);
    return api_fail(err, API_ERR_DOCUMENT, "", "format: \"%.40s\" is not a format; the formats are %s", name, list);
}

int api_res_parse(const char *text, api_format f, unsigned res[3], api_error *err)
{
    int mesh = formats[f].mesh;
    unsigned dflt = mesh ? API_RES_MESH_DEFAULT : API_RES_GRID_DEFAULT;
    unsigned max = mesh ? API_RES_MESH_MAX : API_RES_GRID_MAX;
    const char *what = mesh ? "samples per face edge" : "samples per axis";
    res[0] = res[1] = res[2] = dflt;
    if (!text || !*text)
        return 0;
    unsigned long long v[3];
    int n = 0;
    const char *s = text;
    while (n < 3) {
        if (*s < '0' || *s > '9')
            return api_fail(err, API_ERR_DOCUMENT, "", "res: \"%.40s\" is not N or NU,NV,NW (whole numbers)", text);
        char *end;
        v[n++] = strtoull(s, &end, 10);
        s = end;
        if (*s != ',' || n == 3)
            break;
        s++;
    }
    if (*s || (n != 1 && n != 3))
        return api_fail(err, API_ERR_DOCUMENT, "", "res: \"%.40s\" is not N or NU,NV,NW (whole numbers)", text);
    if (n == 1)
        v[1] = v[2] = v[0];
    unsigned long long total = 1;
    for (int i = 0; i < 3; i++) {
        if (v[i] < 2)
            return api_fail(err, API_ERR_DOCUMENT, "", "res: %llu is too few; at least 2 %s", v[i], what);
        if (v[i] > max)
            return api_fail(err, API_ERR_DOCUMENT, "", "res: %llu is more than the limit of %u %s for %s", v[i], max, what,
                            formats[f].name);
        total *= v[i];
    }
    if (!mesh && total > API_RES_GRID_POINTS)
        return api_fail(err, API_ERR_DOCUMENT, "", "res: %llu points in all is more than the limit of %u", total, API_RES_GRID_POINTS);
    for (int i = 0; i < 3; i++)
        res[i] = (unsigned)v[i];
    return 0;
}

struct api_output {
    api_format fmt;
    const pde_solution *sol;
    char id[API_ID_LEN + 1];
    unsigned res[3];
    long long size;
    char *buf;
    size_t len, pos, cap;
    int phase;
    size_t c, k, j, chunk;
    int first;
    pde_grid *grid;
    float *xyz, *xu, *xv, *xw;
    api_mesh mesh;
    unsigned char *blob;
    size_t blob_len, blob_pos;
    pde_props props;
    int have_props;
    char *text;           /* mesh formats: the JSON (glTF, GLB) */
    size_t text_len, split;   /* gltf: the base64 goes at text[split] */
};

static int reserve(api_output *o, size_t n)
{
    if (o->cap - o->len >= n)
        return 0;
    size_t cap = o->cap ? o->cap : 4096;
    while (cap - o->len < n)
        cap *= 2;
    char *b = realloc(o->buf, cap);
    if (!b)
        return -1;
    o->buf = b;
    o->cap = cap;
    return 0;
}

static int put(api_output *o, const void *p, size_t n)
{
    if (reserve(o, n))
        return -1;
    memcpy(o->buf + o->len, p, n);
    o->len += n;
    return 0;
}

static int puts_(api_output *o, const char *s)
{
    return put(o, s, strlen(s));
}

static void le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

static void le64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

/* n floats as little-endian bytes. */
static int put_f32(api_output *o, const float *f, size_t n)
{
    if (reserve(o, 4 * n))
        return -1;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    memcpy(o->buf + o->len, f, 4 * n);
#else
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, &f[i], 4);
        le32((unsigned char *)o->buf + o->len + 4 * i, u);
    }
#endif
    o->len += 4 * n;
    return 0;
}

static double axis(size_t i, size_t n)
{
    return n > 1 ? (double)i / (double)(n - 1) : 0.5;
}

/* ---- the properties, and the json format ---- */

/*
 * The properties, one row each: the object they sit in under "properties" (NULL: at its top), their
 * name there, where they are in pde_props, and their shape (rows x 3, or one number; folds is the one
 * int). The json format and glTF's extras (props_tree), the CLI's reading of a server's answer
 * (api_props_from_tree) and the vts field data (group_name) all read this table.
 */
typedef struct {
    const char *group, *name;
    size_t off;
    int rows, cols;     /* 1 x 1: a number; 1 x 3: [3]; 3 x 3: [[3],[3],[3]], row by row */
    int flag;           /* an int read as a JSON boolean */
} prop_row;

#define PROP(g, n, field, r, c) { g, n, offsetof(pde_props, field), r, c, 0 }
static const prop_row prop_rows[] = {
    PROP("bbox", "min", bbox_min, 1, 3),
    PROP("bbox", "max", bbox_max, 1, 3),
    PROP("bbox", "gap", bbox_gap, 1, 1),
    PROP(NULL, "volume", volume, 1, 1),
    PROP(NULL, "signed_volume", signed_volume, 1, 1),
    PROP("detJ", "min", detj_min, 1, 1),
    PROP("detJ", "max", detj_max, 1, 1),
    PROP("detJ", "min_found", detj_min_found, 1, 1),
    PROP("detJ", "max_found", detj_max_found, 1, 1),
    PROP("detJ", "min_at", detj_min_at, 1, 3),
    PROP("detJ", "max_at", detj_max_at, 1, 3),
    PROP("detJ", "gap", detj_gap, 1, 1),
    { NULL, "folds", offsetof(pde_props, folds), 1, 1, 1 },
    PROP(NULL, "centroid", centroid, 1, 3),
    PROP(NULL, "inertia", inertia, 3, 3),
    PROP("principal", "moments", principal_moments, 1, 3),
    PROP("principal", "axes", principal_axes, 3, 3),
    PROP(NULL, "surface_area", surface_area, 1, 1),
    PROP("residuals", "boundary", bc_residual, 1, 1),
    PROP("residuals", "pde", pde_residual, 1, 1),
    PROP("residuals", "integrals", integral_error, 1, 1),
    PROP("residuals", "fit", fit_error, 1, 1),
    PROP("conditioning", "condition", condition, 1, 1),
    PROP("conditioning", "harmonic", condition_harmonic, 1, 1),
};
#undef PROP
#define PROP_ROWS (sizeof prop_rows / sizeof prop_rows[0])

static const double *prop_at(const pde_props *p, const prop_row *r)
{
    return (const double *)(const void *)((const char *)p + r->off);
}

/* v in the fewest digits that read back as v exactly (cJSON_CreateNumber settles for 15 digits within an
 * epsilon, so the last bit of a certified bound could move); null when not finite. */
static cJSON *prop_number(double v)
{
    char s[32];
    if (!isfinite(v))
        return cJSON_CreateNull();
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(s, sizeof s, "%.*g", digits, v);
        if (strtod(s, NULL) == v)
            break;
    }
    return cJSON_CreateRaw(s);
}

static cJSON *prop_numbers(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < n; i++)
        cJSON_AddItemToArray(a, prop_number(v[i]));
    return a;
}

static cJSON *prop_value(const pde_props *p, const prop_row *r)
{
    const double *v = prop_at(p, r);
    if (r->flag)
        return cJSON_CreateBool(*(const int *)(const void *)v);
    if (r->cols == 1)
        return prop_number(*v);
    if (r->rows == 1)
        return prop_numbers(v, r->cols);
    cJSON *m = cJSON_CreateArray();
    for (int i = 0; m && i < r->rows; i++)
        cJSON_AddItemToArray(m, prop_numbers(v + i * r->cols, r->cols));
    return m;
}

/* The object a row goes in: o itself, or its group, made on first use. */
static cJSON *prop_parent(cJSON *o, const prop_row *r)
{
    if (!r->group)
        return o;
    cJSON *g = cJSON_GetObjectItemCaseSensitive(o, r->group);
    return g ? g : cJSON_AddObjectToObject(o, r->group);
}

static cJSON *props_tree(const pde_props *p)
{
    cJSON *o = cJSON_CreateObject();
    for (size_t i = 0; o && i < PROP_ROWS; i++) {
        cJSON *parent = prop_parent(o, &prop_rows[i]);
        if (parent)
            cJSON_AddItemToObject(parent, prop_rows[i].name, prop_value(p, &prop_rows[i]));
    }
    return o;
}

struct cJSON *api_props_tree(const pde_props *p)
{
    return props_tree(p);
}

void api_props_from_tree(const struct cJSON *t, pde_props *out)
{
    memset(out, 0, sizeof *out);
    for (size_t i = 0; i < PROP_ROWS; i++) {
        const prop_row *r = &prop_rows[i];
        const cJSON *parent = r->group ? cJSON_GetObjectItemCaseSensitive(t, r->group) : t;
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(parent, r->name);
        double *d = (double *)(void *)((char *)out + r->off);
        if (r->flag) {
            *(int *)(void *)d = cJSON_IsTrue(v);
            continue;
        }
        for (int k = 0; k < r->rows * r->cols; k++) {
            const cJSON *x = r->cols == 1 ? v
                             : r->rows == 1 ? cJSON_GetArrayItem(v, k)
                                            : cJSON_GetArrayItem(cJSON_GetArrayItem(v, k / r->cols), k % r->cols);
            d[k] = cJSON_IsNumber(x) ? x->valuedouble : cJSON_IsRaw(x) ? strtod(x->valuestring, NULL) : 0.0;
        }
    }
}

char *api_props_json(const pde_props *p)
{
    cJSON *t = props_tree(p);
    char *s = t ? cJSON_PrintUnformatted(t) : NULL;
    cJSON_Delete(t);
    return s;
}

/* One number at 17 digits, or null when it is not finite: nan and inf are not JSON (the callers
 * refuse such results first with api_eval_check(); this is the last resort). */
static size_t put_number(char *buf, double v)
{
    return isfinite(v) ? (size_t)sprintf(buf, "%.17g", v) : (size_t)sprintf(buf, "null");
}

/* ,"name":[[x,y,z],...] into buf at *len (the caller sized it). */
static void put_triples(char *buf, size_t *len, const char *name, const double *v, size_t n)
{
    *len += (size_t)sprintf(buf + *len, ",\"%s\":[", name);
    for (size_t i = 0; i < n; i++) {
        if (i)
            buf[(*len)++] = ',';
        for (int k = 0; k < 3; k++) {
            buf[(*len)++] = k ? ',' : '[';
            *len += put_number(buf + *len, v[3 * i + k]);
        }
        buf[(*len)++] = ']';
    }
    buf[(*len)++] = ']';
}

char *api_eval_json(const char *id, const double *values, const double *du, const double *dv, const double *dw,
                    size_t n)
{
    /* Each number takes at most 24 characters, each triple 3 of them and 4 more. */
    size_t arrays = 1 + (du != NULL) + (dv != NULL) + (dw != NULL);
    char *buf = malloc(64 + strlen(id) + arrays * (16 + n * (3 * 24 + 4)));
    if (!buf)
        return NULL;
    size_t len = (size_t)sprintf(buf, "{\"id\":\"%s\"", id);
    put_triples(buf, &len, "values", values, n);
    if (du)
        put_triples(buf, &len, "du", du, n);
    if (dv)
        put_triples(buf, &len, "dv", dv, n);
    if (dw)
        put_triples(buf, &len, "dw", dw, n);
    memcpy(buf + len, "}\n", 3);
    return buf;
}

static cJSON *numbers(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < n; i++)
        cJSON_AddItemToArray(a, cJSON_CreateNumber(v[i]));
    return a;
}

/* -1 with err set to the cancellation of api_error (model.h). */
static int cancelled(api_error *err)
{
    return api_fail(err, API_ERR_CANCELLED, "", "cancelled");
}

static int stopped(const pde_cancel *c)
{
    return c && c->stop && c->stop(c->arg);
}

/* The caller's properties, or computed now; NULL with err when cancelled, NULL alone otherwise. */
static const pde_props *props_of(api_output *o, const pde_cancel *cancel, api_error *err)
{
    pde_props_opts opts = { .cancel = cancel };
    if (!o->have_props) {
        pde_status st = pde_properties(o->sol, &opts, &o->props);
        if (st == PDE_ERR_CANCELLED)
            cancelled(err);
        if (st != PDE_OK)
            return NULL;
    }
    o->have_props = 1;
    return &o->props;
}

static int json_document(api_output *o, const pde_cancel *cancel, api_error *err)
{
    const pde_props *props = props_of(o, cancel, err);
    if (!props)
        return -1;
    cJSON *root = cJSON_CreateObject(), *comps = cJSON_AddObjectToObject(root, "components");
    if (o->id[0])
        cJSON_AddStringToObject(root, "id", o->id);
    static const char *const names[3] = { "x", "y", "z" };
    for (int c = 0; comps && c < 3; c++) {
        cJSON *comp = cJSON_AddObjectToObject(comps, names[c]), *modes = cJSON_AddArrayToObject(comp, "modes");
        size_t nm;
        const pde_mode *md = pde_solution_modes(o->sol, c, &nm);
        for (size_t m = 0; modes && m < nm; m++) {
            if (m % 64 == 63 && stopped(cancel)) {
                cJSON_Delete(root);
                return cancelled(err);
            }
            cJSON *mo = cJSON_CreateObject(), *terms;
            cJSON_AddItemToArray(modes, mo);
            cJSON_AddItemToObject(mo, "u", api_factor_tree(md[m].u));
            cJSON_AddItemToObject(mo, "v", api_factor_tree(md[m].v));
            cJSON_AddNumberToObject(mo, "e", md[m].e);
            /* A loft's mode is piecewise: "slabs": [{"w": [w0, w1], "h": [...]}] instead of "h". */
            cJSON *slabs = md[m].nslabs > 1 ? cJSON_AddArrayToObject(mo, "slabs") : NULL;
            for (size_t sl = 0; sl < (slabs ? md[m].nslabs : 1); sl++) {
                cJSON *holder = mo;
                if (slabs) {
                    holder = cJSON_CreateObject();
                    cJSON_AddItemToArray(slabs, holder);
                    cJSON_AddItemToObject(holder, "w", numbers(md[m].breaks + sl, 2));
                }
                if (!(terms = cJSON_AddArrayToObject(holder, "h")))
                    continue;
                size_t t0 = slabs ? md[m].first[sl] : 0, t1 = slabs ? md[m].first[sl + 1] : md[m].nterms;
                for (size_t t = t0; t < t1; t++) {
                    const pde_wterm *w = &md[m].terms[t];
                    cJSON *to = cJSON_CreateObject();
                    cJSON_AddItemToArray(terms, to);
                    cJSON_AddNumberToObject(to, "alpha", w->alpha);
                    cJSON_AddNumberToObject(to, "beta", w->beta);
                    cJSON_AddNumberToObject(to, "shift", w->shift);
                    cJSON_AddItemToObject(to, "A", numbers(w->A, w->deg + 1));
                    cJSON_AddItemToObject(to, "B", numbers(w->B, w->deg + 1));
                }
            }
        }
    }
    /* The closed form as text, as `pdesolid solve` prints it. */
    char *text = NULL;
    size_t tlen = 0;
    FILE *f = open_memstream(&text, &tlen);
    if (f) {
        api_describe(f, o->sol, NULL);
        fclose(f);
        cJSON_AddStringToObject(root, "closed_form", text ? text : "");
        free(text);
    }
    cJSON_AddItemToObject(root, "properties", props_tree(props));
    char *s = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    if (!s)
        return -1;
    int rc = puts_(o, s) || puts_(o, "\n");
    free(s);
    return rc ? -1 : 0;
}

/* ---- grids ---- */

static int grid_open(api_output *o)
{
    size_t nu = o->res[0], nv = o->res[1];
    double *us = malloc((nu + nv) * sizeof *us);
    if (!us)
        return -1;
    for (size_t i = 0; i < nu; i++)
        us[i] = axis(i, nu);
    for (size_t j = 0; j < nv; j++)
        us[nu + j] = axis(j, nv);
    pde_status st = pde_grid_create(o->sol, us, nu, us + nu, nv, &o->grid);
    free(us);
    if (st != PDE_OK)
        return -1;
    /* A row costs about (3 + nu) multiply-adds per mode and component (nu per distinct u-factor). */
    double row = 0.0;
    for (int c = 0; c < 3; c++) {
        size_t nm;
        pde_solution_modes(o->sol, c, &nm);
        row += (double)nm * (3.0 + (double)nu) * (o->fmt == API_FMT_VTS ? 4.0 : 1.0);
    }
    o->chunk = CHUNK_POINTS / nu;
    if (row > 0 && (double)o->chunk * row > CHUNK_WORK)
        o->chunk = (size_t)(CHUNK_WORK / row);
    if (o->chunk == 0)
        o->chunk = 1;
    size_t n = 3 * nu * o->chunk;
    o->xyz = malloc(n * sizeof(float));
    if (o->fmt == API_FMT_VTS) {
        o->xu = malloc(n * sizeof(float));
        o->xv = malloc(n * sizeof(float));
        o->xw = malloc(n * sizeof(float));
        if (!o->xu || !o->xv || !o->xw)
            return -1;
    }
    return o->xyz ? 0 : -1;
}

/* The next chunk of rows of plane k from row j; returns the number of points, advancing j and k. */
static size_t next_rows(api_output *o, int derivs)
{
    size_t nu = o->res[0], nv = o->res[1], j1 = o->j + o->chunk < nv ? o->j + o->chunk : nv;
    double w = axis(o->k, o->res[2]);
    pde_grid_rows(o->grid, w, o->j, j1, o->xyz, derivs ? o->xu : NULL, derivs ? o->xv : NULL,
                  derivs ? o->xw : NULL);
    size_t n = nu * (j1 - o->j);
    o->j = j1;
    if (o->j == nv) {
        o->j = 0;
        o->k++;
    }
    return n;
}

static int fill_grid_json(api_output *o)
{
    static const char *const open[3] = { "],\"x\":[", "],\"y\":[", "],\"z\":[" };
    if (o->phase == 0) {
        char head[96];
        snprintf(head, sizeof head, "{\"resolution\":[%u,%u,%u],\"x\":[", o->res[0], o->res[1], o->res[2]);
        o->phase = 1;
        o->first = 1;
        return puts_(o, head);
    }
    if (o->phase == 2)
        return 1;
    if (o->k == o->res[2]) {
        o->k = o->j = 0;
        o->first = 1;
        if (++o->c == 3) {
            o->phase = 2;
            return puts_(o, "]}\n");
        }
        return puts_(o, open[o->c]);
    }
    size_t n = next_rows(o, 0);
    if (reserve(o, n * (API_F32_MAX + 1)))
        return -1;
    char *p = o->buf + o->len;
    for (size_t i = 0; i < n; i++) {
        if (!o->first)
            *p++ = ',';
        o->first = 0;
        p += api_fmt_f32(p, o->xyz[3 * i + o->c]);
    }
    o->len = (size_t)(p - o->buf);
    return 0;
}

static int fill_f32(api_output *o)
{
    if (o->k == o->res[2])
        return 1;
    size_t n = next_rows(o, 0);
    return put_f32(o, o->xyz, 3 * n);
}

static long long points(const api_output *o)
{
    return (long long)o->res[0] * o->res[1] * o->res[2];
}

/* The properties as VTK field data, one array per row of prop_rows named group_name ("detJ_min_at"),
 * in ascii at 17 digits, so ParaView lists them with the dataset. */
static int vts_field_data(api_output *o)
{
    if (puts_(o, "    <FieldData>\n"))
        return -1;
    for (size_t i = 0; i < PROP_ROWS; i++) {
        const prop_row *r = &prop_rows[i];
        const double *v = prop_at(&o->props, r);
        int n = r->rows * r->cols;
        char line[1024], *p = line;
        p += sprintf(p, "      <DataArray type=\"%s\" Name=\"%s%s%s\" NumberOfComponents=\"%d\" NumberOfTuples=\"1\" "
                        "format=\"ascii\">",
                     r->flag ? "Int8" : "Float64", r->group ? r->group : "", r->group ? "_" : "", r->name, n);
        if (r->flag)
            p += sprintf(p, "%d", *(const int *)(const void *)v != 0);
        for (int k = 0; !r->flag && k < n; k++)
            p += sprintf(p, "%s%.17g", k ? " " : "", v[k]);
        p += sprintf(p, "</DataArray>\n");
        if (put(o, line, (size_t)(p - line)))
            return -1;
    }
    return puts_(o, "    </FieldData>\n");
}

static int vts_header(api_output *o)
{
    unsigned a = o->res[0] - 1, b = o->res[1] - 1, c = o->res[2] - 1;
    char h[1024];
    int n = snprintf(h, sizeof h,
                     "<?xml version=\"1.0\"?>\n"
                     "<!-- pdesolid: the solid %s, x(u,v,w) at u, v, w = i/(n-1); detJ = det d(x,y,z)/d(u,v,w); "
                     "the field data are its properties (docs/API.md) -->\n"
                     "<VTKFile type=\"StructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
                     "  <StructuredGrid WholeExtent=\"0 %u 0 %u 0 %u\">\n",
                     o->id[0] ? o->id : "(no id)", a, b, c);
    if (put(o, h, (size_t)n) || vts_field_data(o))
        return -1;
    n = snprintf(h, sizeof h,
                 "    <Piece Extent=\"0 %u 0 %u 0 %u\">\n"
                 "      <PointData Scalars=\"detJ\">\n"
                 "        <DataArray type=\"Float32\" Name=\"detJ\" NumberOfComponents=\"1\" format=\"appended\" offset=\"%lld\"/>\n"
                 "      </PointData>\n"
                 "      <Points>\n"
                 "        <DataArray type=\"Float32\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>\n"
                 "      </Points>\n"
                 "    </Piece>\n"
                 "  </StructuredGrid>\n"
                 "  <AppendedData encoding=\"raw\">\n   _",
                 a, b, c, 8 + 12 * points(o));
    return put(o, h, (size_t)n);
}

static const char vts_footer[] = "\n  </AppendedData>\n</VTKFile>\n";

static int fill_vts(api_output *o)
{
    unsigned char len8[8];
    switch (o->phase) {
    case 0:
        o->phase = 1;
        le64(len8, (uint64_t)(12 * points(o)));
        return vts_header(o) || put(o, len8, 8);
    case 1:
        if (o->k < o->res[2])
            return put_f32(o, o->xyz, 3 * next_rows(o, 0));
        o->k = o->j = 0;
        o->phase = 2;
        le64(len8, (uint64_t)(4 * points(o)));
        return put(o, len8, 8);
    case 2:
        if (o->k < o->res[2]) {
            size_t n = next_rows(o, 1);
            for (size_t i = 0; i < n; i++) {
                const float *a = o->xu + 3 * i, *b = o->xv + 3 * i, *c = o->xw + 3 * i;
                double d = (double)a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
                           (double)a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
                           (double)a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
                o->xyz[i] = (float)d;
            }
            return put_f32(o, o->xyz, n);
        }
        o->phase = 3;
        return puts_(o, vts_footer);
    }
    return 1;
}

/* ---- meshes ---- */

static int mesh_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    if (api_mesh_build(o->sol, o->res, cancel, &o->mesh, err))
        return -1;
    if (o->mesh.ntris == 0) {
        api_fail(err, API_ERR_DOCUMENT, "", "the solid has no skin: every face collapses to a line or a point");
        return -1;
    }
    size_t nv = o->mesh.nverts, nt = o->mesh.ntris;
    if (o->fmt == API_FMT_STL) {
        o->size = 84 + 50LL * (long long)nt;
        return 0;
    }
    /* The blob: positions, normals, det J, indices; each a multiple of 4 bytes. */
    o->blob_len = 28 * nv + 12 * nt;
    o->blob = malloc(o->blob_len);
    if (!o->blob)
        return -1;
    /* glTF is +Y up: (X, Y, Z) = (x, z, -y), a rotation (x and the solid's handedness kept); the paper's
     * height w, along z, stands along +Y. Negation is exact, so min and max stay the float32 values. */
    float *bp = (float *)o->blob, *bn = bp + 3 * nv;
    for (size_t i = 0; i < nv; i++) {
        const float *p = o->mesh.pos + 3 * i, *q = o->mesh.nrm + 3 * i;
        bp[3 * i] = p[0], bp[3 * i + 1] = p[2], bp[3 * i + 2] = -p[1];
        bn[3 * i] = q[0], bn[3 * i + 1] = q[2], bn[3 * i + 2] = -q[1];
    }
    memcpy(o->blob + 24 * nv, o->mesh.detj, 4 * nv);
    memcpy(o->blob + 28 * nv, o->mesh.tri, 12 * nt);
    const pde_props *props = props_of(o, cancel, err);
    if (!props)
        return -1;
    char *pj = api_props_json(props);
    if (!pj)
        return -1;
    /* min and max as the exact float32 values (17 digits of the double they widen to). */
    char mm[256];
    snprintf(mm, sizeof mm, "\"min\":[%.17g,%.17g,%.17g],\"max\":[%.17g,%.17g,%.17g]", o->mesh.min[0],
             o->mesh.min[2], -o->mesh.max[1], o->mesh.max[0], o->mesh.max[2], -o->mesh.min[1]);
    int gltf = o->fmt == API_FMT_GLTF;
    size_t cap = 2048 + strlen(pj);
    o->text = malloc(cap);
    if (!o->text) {
        free(pj);
        return -1;
    }
    int n = snprintf(
        o->text, cap,
        "{\"asset\":{\"version\":\"2.0\",\"generator\":\"pdesolid\",\"extras\":{\"id\":\"%s\",\"units\":\"metres\","
        "\"up\":\"+Y; glTF (X, Y, Z) = the model's (x, z, -y)\",\"properties\":%s}},"
        "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0,\"name\":\"solid\"}],"
        "\"meshes\":[{\"name\":\"skin\",\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"_DETJ\":3},\"indices\":2,\"mode\":4}]}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\",%s},"
        "{\"bufferView\":1,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"},"
        "{\"bufferView\":3,\"componentType\":5126,\"count\":%zu,\"type\":\"SCALAR\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu,\"target\":34962},"
        "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":34962},"
        "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":34963},"
        "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":34962}],"
        "\"buffers\":[{\"byteLength\":%zu%s",
        o->id, pj, nv, mm, nv, 3 * nt, nv, 12 * nv, 12 * nv, 12 * nv, 28 * nv, 12 * nt, 24 * nv, 4 * nv, o->blob_len,
        gltf ? ",\"uri\":\"data:application/octet-stream;base64," : "}]}");
    free(pj);
    if (n < 0 || (size_t)n >= cap)
        return -1;
    o->text_len = (size_t)n;
    size_t b64 = (o->blob_len + 2) / 3 * 4;
    if (gltf) {
        o->size = (long long)(n + b64 + 5);    /* "}]}\n" */
    } else {
        size_t jlen = (o->text_len + 3) & ~(size_t)3;
        o->size = (long long)(12 + 8 + jlen + 8 + o->blob_len);
    }
    return 0;
}

static const char b64chars[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static int fill_gltf(api_output *o)
{
    switch (o->phase) {
    case 0:
        o->phase = 1;
        return put(o, o->text, o->text_len);
    case 1: {
        if (o->blob_pos == o->blob_len) {
            o->phase = 2;
            return puts_(o, "\"}]}\n");
        }
        size_t n = o->blob_len - o->blob_pos;
        if (n > 49152)
            n = 49152;       /* a multiple of 3, so runs join without padding */
        if (reserve(o, n / 3 * 4 + 4))
            return -1;
        const unsigned char *s = o->blob + o->blob_pos;
        char *d = o->buf + o->len;
        size_t i = 0;
        for (; i + 3 <= n; i += 3) {
            uint32_t v = (uint32_t)s[i] << 16 | (uint32_t)s[i + 1] << 8 | s[i + 2];
            *d++ = b64chars[v >> 18];
            *d++ = b64chars[(v >> 12) & 63];
            *d++ = b64chars[(v >> 6) & 63];
            *d++ = b64chars[v & 63];
        }
        if (i < n) {
            uint32_t v = (uint32_t)s[i] << 16 | (i + 1 < n ? (uint32_t)s[i + 1] << 8 : 0);
            *d++ = b64chars[v >> 18];
            *d++ = b64chars[(v >> 12) & 63];
            *d++ = i + 1 < n ? b64chars[(v >> 6) & 63] : '=';
            *d++ = '=';
        }
        o->len = (size_t)(d - o->buf);
        o->blob_pos += n;
        return 0;
    }
    }
    return 1;
}

static int fill_glb(api_output *o)
{
    unsigned char h[20];
    switch (o->phase) {
    case 0: {
        size_t jlen = (o->text_len + 3) & ~(size_t)3;
        memcpy(h, "glTF", 4);
        le32(h + 4, 2);
        le32(h + 8, (uint32_t)o->size);
        le32(h + 12, (uint32_t)jlen);
        memcpy(h + 16, "JSON", 4);
        o->phase = 1;
        if (put(o, h, 20) || put(o, o->text, o->text_len) || put(o, "   ", jlen - o->text_len))
            return -1;
        le32(h, (uint32_t)o->blob_len);
        memcpy(h + 4, "BIN\0", 4);
        return put(o, h, 8);
    }
    case 1: {
        if (o->blob_pos == o->blob_len)
            return 1;
        size_t n = o->blob_len - o->blob_pos;
        if (n > 1 << 20)
            n = 1 << 20;
        if (put(o, o->blob + o->blob_pos, n))
            return -1;
        o->blob_pos += n;
        return 0;
    }
    }
    return 1;
}

static int fill_stl(api_output *o)
{
    const api_mesh *m = &o->mesh;
    if (o->phase == 0) {
        unsigned char h[84];
        memset(h, ' ', 80);
        int n = snprintf((char *)h, 80, "pdesolid binary STL of the solid %s", o->id[0] ? o->id : "");
        if (n > 0 && n < 80)
            h[n] = ' ';
        le32(h + 80, (uint32_t)m->ntris);
        o->phase = 1;
        return put(o, h, 84);
    }
    if (o->j == m->ntris)
        return 1;
    size_t n = m->ntris - o->j < 4096 ? m->ntris - o->j : 4096;
    if (reserve(o, 50 * n))
        return -1;
    for (size_t t = o->j; t < o->j + n; t++) {
        const float *p[3];
        for (int i = 0; i < 3; i++)
            p[i] = m->pos + 3 * m->tri[3 * t + i];
        double a[3], b[3], c[3];
        for (int k = 0; k < 3; k++)
            a[k] = (double)p[1][k] - p[0][k], b[k] = (double)p[2][k] - p[0][k];
        c[0] = a[1] * b[2] - a[2] * b[1];
        c[1] = a[2] * b[0] - a[0] * b[2];
        c[2] = a[0] * b[1] - a[1] * b[0];
        double len = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        float rec[12];
        for (int k = 0; k < 3; k++)
            rec[k] = len > 0 ? (float)(c[k] / len) : 0.0f;
        for (int i = 0; i < 3; i++)
            memcpy(rec + 3 + 3 * i, p[i], 3 * sizeof(float));
        if (put_f32(o, rec, 12) || put(o, "\0\0", 2))
            return -1;
    }
    o->j += n;
    return 0;
}

/* ---- the stream ---- */

api_output *api_output_open(const pde_solution *sol, const char *id, const pde_props *props, api_format f,
                            const unsigned res[3], const pde_cancel *cancel, api_error *err)
{
    api_error local;
    if (!err)
        err = &local;
    api_output *o = calloc(1, sizeof *o);
    if (!o) {
        api_fail(err, API_ERR_NOMEM, "", "out of memory");
        return NULL;
    }
    o->fmt = f;
    o->sol = sol;
    if (props) {
        o->props = *props;
        o->have_props = 1;
    }
    o->size = -1;
    snprintf(o->id, sizeof o->id, "%s", id ? id : "");
    memcpy(o->res, res, sizeof o->res);
    int rc = 0;
    err->message[0] = '\0';
    switch (f) {
    case API_FMT_GRID:
        rc = grid_open(o);
        break;
    case API_FMT_F32:
        rc = grid_open(o);
        o->size = 12 * points(o);
        break;
    case API_FMT_VTS: {
        rc = props_of(o, cancel, err) ? grid_open(o) : -1;
        if (!rc && !vts_header(o)) {  /* measure the header once for the size */
            o->size = (long long)o->len + 8 + 12 * points(o) + 8 + 4 * points(o) + (long long)strlen(vts_footer);
            o->len = 0;
        }
        break;
    }
    case API_FMT_GLTF:
    case API_FMT_GLB:
    case API_FMT_STL:
        rc = mesh_open(o, cancel, err);
        break;
    case API_FMT_JSON:
        rc = json_document(o, cancel, err);
        o->size = (long long)o->len;
        o->phase = 1;
        break;
    }
    if (rc) {
        if (!err->message[0])
            api_fail(err, API_ERR_NOMEM, "", "out of memory");
        api_output_free(o);
        return NULL;
    }
    return o;
}

long long api_output_size(const api_output *o)
{
    return o->size;
}

static int fill(api_output *o)
{
    switch (o->fmt) {
    case API_FMT_JSON: return 1;
    case API_FMT_GRID: return fill_grid_json(o);
    case API_FMT_F32: return fill_f32(o);
    case API_FMT_VTS: return fill_vts(o);
    case API_FMT_GLTF: return fill_gltf(o);
    case API_FMT_GLB: return fill_glb(o);
    case API_FMT_STL: return fill_stl(o);
    }
    return 1;
}

long api_output_read(api_output *o, char *buf, size_t max)
{
    size_t done = 0;
    while (done < max) {
        if (o->pos == o->len) {
            if (done)
                break;      /* one piece of work per call: a caller can poll between calls */
            if (o->fmt != API_FMT_JSON)
                o->pos = o->len = 0;
            int r = fill(o);
            if (r < 0)
                return -1;
            if (r > 0 && o->pos == o->len)
                break;
        }
        size_t n = o->len - o->pos < max - done ? o->len - o->pos : max - done;
        memcpy(buf + done, o->buf + o->pos, n);
        o->pos += n;
        done += n;
    }
    return (long)done;
}

void api_output_free(api_output *o)
{
    if (!o)
        return;
    pde_grid_free(o->grid);
    free(o->buf);
    free(o->xyz);
    free(o->xu);
    free(o->xv);
    free(o->xw);
    api_mesh_free(&o->mesh);
    free(o->blob);
    free(o->text);
    free(o);
}
