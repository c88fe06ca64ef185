/*
 * output.c: the stream of output.h over the format table. formats.def lists
 * the formats; each api/fmt_*.c defines its entry (api/fmt.h). Here: the
 * table and what reads it (names, resolutions, compression, GET /formats),
 * the properties as JSON (shared by json, glTF's extras and the VTK files),
 * eval answers, and api_output_open/read/free, which call the entry's
 * open, fill and close.
 */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "fmt.h"
#include "jsonparse.h"
#include "output.h"

#define API_FORMAT(id, entry) extern const api_format_info entry;
#include "formats.def"
#undef API_FORMAT

static const api_format_info *const formats[API_FMT_COUNT] = {
#define API_FORMAT(id, entry) &entry,
#include "formats.def"
#undef API_FORMAT
};

char *api_formats_json(void)
{
    cJSON *a = cJSON_CreateArray();
    int ok = a != NULL;
    for (int i = 0; ok && i < API_FMT_COUNT; i++) {
        const api_format_info *f = formats[i];
        cJSON *o = cJSON_CreateObject();
        ok = o && cJSON_AddItemToArray(a, o) && cJSON_AddStringToObject(o, "name", f->name) &&
             cJSON_AddStringToObject(o, "media_type", f->mime) && cJSON_AddStringToObject(o, "extension", f->ext) &&
             cJSON_AddBoolToObject(o, "binary", f->binary) && cJSON_AddBoolToObject(o, "mesh", f->mesh) &&
             cJSON_AddBoolToObject(o, "properties", f->props) &&
             cJSON_AddNumberToObject(o, "default_res", f->mesh ? API_RES_MESH_DEFAULT : API_RES_GRID_DEFAULT);
        cJSON *c = ok ? cJSON_AddArrayToObject(o, "compress") : NULL;
        ok = c && cJSON_AddItemToArray(c, cJSON_CreateString("none")) &&
             (!f->compress || cJSON_AddItemToArray(c, cJSON_CreateString("meshopt")));
        if (!o)
            break;
    }
    char *s = ok ? cJSON_PrintUnformatted(a) : NULL;
    cJSON_Delete(a);
    return s;
}

const api_format_info *api_format_info_of(api_format f)
{
    return (unsigned)f < API_FMT_COUNT ? formats[f] : NULL;
}

/* The names of the formats with flag set (every one when want is 0), "a, b, c", into list. */
static void names(char *list, size_t size, int want)
{
    size_t n = 0;
    list[0] = '\0';
    for (int i = 0; i < API_FMT_COUNT && n < size; i++)
        if (!want || formats[i]->compress)
            n += (size_t)snprintf(list + n, size - n, "%s%s", n ? ", " : "", formats[i]->name);
}

int api_format_parse(const char *name, api_format *f, api_error *err)
{
    for (int i = 0; i < API_FMT_COUNT; i++)
        if (strcmp(formats[i]->name, name) == 0) {
            *f = (api_format)i;
            return 0;
        }
    char list[256];
    names(list, sizeof list, 0);
    return api_fail(err, API_ERR_DOCUMENT, "", "format: \"%.40s\" is not a format; the formats are %s", name, list);
}

const char *api_compress_name(api_compress c)
{
    return c == API_COMPRESS_MESHOPT ? "meshopt" : "none";
}

int api_compress_parse(const char *text, api_format f, api_compress *c, api_error *err)
{
    *c = API_COMPRESS_NONE;
    if (!text || !*text || !strcmp(text, "none"))
        return 0;
    if (strcmp(text, "meshopt"))
        return api_fail(err, API_ERR_DOCUMENT, "", "compress: \"%.40s\" is not a compression; it is none or meshopt",
                        text);
    if (!formats[f]->compress) {
        char list[128];
        names(list, sizeof list, 1);
        return api_fail(err, API_ERR_DOCUMENT, "", "compress: meshopt applies to %s, not to %s", list, formats[f]->name);
    }
    *c = API_COMPRESS_MESHOPT;
    return 0;
}

int api_res_parse(const char *text, api_format f, unsigned res[3], api_error *err)
{
    int mesh = formats[f]->mesh;
    unsigned dflt = mesh ? API_RES_MESH_DEFAULT : API_RES_GRID_DEFAULT;
    unsigned max = mesh ? API_RES_MESH_MAX : API_RES_GRID_MAX;
    const char *what = mesh ? "samples per face edge" : "samples per axis";
    res[0] = res[1] = res[2] = dflt;
    if (!text || !*text || formats[f]->unsampled)
        return 0;   /* json: res=2 (the front-end's) and res=512 are one answer, one ETag */
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
        if (v[i] > max)   /* the text as sent: strtoull saturates past 2^64 */
            return api_fail(err, API_ERR_DOCUMENT, "", "res: \"%.40s\" is more than the limit of %u %s for %s", text, max,
                            what, formats[f]->name);
        total *= v[i];
    }
    if (!mesh && total > API_RES_GRID_POINTS)
        return api_fail(err, API_ERR_DOCUMENT, "", "res: %llu points in all is more than the limit of %u", total, API_RES_GRID_POINTS);
    for (int i = 0; i < 3; i++)
        res[i] = (unsigned)v[i];
    return 0;
}

/* ---- the properties ---- */

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
    PROP("residuals", "area", surface_area_error, 1, 1),
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

static cJSON *prop_value(const pde_props *p, const prop_row *r)
{
    const double *v = prop_at(p, r);
    if (r->flag)
        return cJSON_CreateBool(*(const int *)(const void *)v);
    if (r->cols == 1)
        return api_json_exact(*v);
    if (r->rows == 1)
        return api_json_exact_array(v, r->cols);
    cJSON *m = cJSON_CreateArray();
    for (int i = 0; m && i < r->rows; i++)
        cJSON_AddItemToArray(m, api_json_exact_array(v + i * r->cols, r->cols));
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

/* The properties as VTK field data, one array per row of prop_rows named group_name ("detJ_min_at"),
 * in ascii at 17 digits, so ParaView lists them with the dataset. vts (through api_out_vtk_field_data)
 * and vtu (api/volmesh.c's writer) both write them here. */
int api_vtk_field_data(const pde_props *props, api_volmesh_put put, void *ctx)
{
    static const char open[] = "    <FieldData>\n", close[] = "    </FieldData>\n";
    if (put(ctx, open, sizeof open - 1))
        return -1;
    for (size_t i = 0; i < PROP_ROWS; i++) {
        const prop_row *r = &prop_rows[i];
        const double *v = prop_at(props, r);
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
        if (put(ctx, line, (size_t)(p - line)))
            return -1;
    }
    return put(ctx, close, sizeof close - 1);
}

int api_out_vtk_field_data(api_output *o, const pde_props *props)
{
    return api_vtk_field_data(props, api_vol_put, o);
}

/* ---- what must fit float32 ---- */

/*
 * 0 if what format fi writes of the solid fits float32 everywhere on the cube (api_range), else -1 with a
 * document error naming what would overflow. Bounds of |x| and of |x_u|, |x_v|, |x_w| from the closed
 * form (pde_solution_magnitudes); the skin's normals are bounded by products of two of those, det J by
 * all three (Hadamard). Half of FLT_MAX leaves room for the rounding of what is
 * computed within the bound.
 */
static int range_check(const pde_solution *sol, const api_format_info *fi, api_error *err)
{
    if (fi->range == API_RANGE_DOUBLES)
        return 0;
    const double limit = FLT_MAX / 2;
    double mag[3][4], x = 0.0, d[3][3];   /* d[c][a]: component c's derivative along u, v, w */
    pde_solution_magnitudes(sol, mag);
    for (int c = 0; c < 3; c++) {
        x = fmax(x, isnan(mag[c][0]) ? INFINITY : mag[c][0]);
        for (int a = 0; a < 3; a++)
            d[c][a] = mag[c][a + 1];
    }
    if (!(x <= limit) && fi->range != API_RANGE_DETJ)
        return api_fail(err, API_ERR_DOCUMENT, "", "the solid is too large for %s: its coordinates could reach "
                        "%.3g, beyond the range of float32 (%.3g), in which %s samples them; scale the model's data "
                        "or forces down", fi->name, x, (double)FLT_MAX, fi->name);
    if (fi->range == API_RANGE_POINTS)
        return 0;
    double n[3];
    for (int a = 0; a < 3; a++)
        n[a] = sqrt(d[0][a] * d[0][a] + d[1][a] * d[1][a] + d[2][a] * d[2][a]);
    const double p = fmax(fmax(fmax(n[0] * n[1], n[1] * n[2]), n[0] * n[2]), n[0] * n[1] * n[2]);
    if (!(p <= limit))
        return api_fail(err, API_ERR_DOCUMENT, "", "the solid is too large for %s: %s, but its derivatives' "
                        "products (%s) could reach %.3g, beyond the range of float32 (%.3g), in which %s writes them; "
                        "scale the model's data or forces down", fi->name,
                        fi->range == API_RANGE_DETJ ? "its points are written as doubles" : "its coordinates fit float32",
                        fi->range == API_RANGE_DETJ ? "det J" : "det J, the skin's normals", p, (double)FLT_MAX,
                        fi->name);
    return 0;
}

/* ---- the stream ---- */

/* ---- the properties ---- */

pde_status api_properties(const pde_solution *sol, const pde_cancel *cancel, pde_props *out, api_error *err)
{
    api_error local;
    if (!err)
        err = &local;
    const pde_props_opts opts = { .cancel = cancel };
    pde_status st = pde_properties(sol, &opts, out);
    if (st == PDE_ERR_CANCELLED)
        api_fail_cancelled(err);
    else if (st == PDE_ERR_RANGE)
        api_fail(err, API_ERR_DOCUMENT, "", "the solid is too large: its properties (volume, inertia) exceed "
                 "the range of a double; scale the model's data or forces down");
    else if (st == PDE_ERR_NOMEM)
        api_fail_nomem(err);
    else if (st != PDE_OK)   /* pde_properties' refusal of its arguments: PDE_ERR_INVALID, no solution */
        api_fail(err, api_status_of(st), "", "the properties: %s", pde_strerror(st));
    return st;
}

int api_output_check(const pde_solution *sol, api_format f, const api_output_opts *opts, api_error *err)
{
    api_error local;
    if (!err)
        err = &local;
    const api_format_info *fi = api_format_info_of(f);
    if (!fi)
        return api_fail(err, API_ERR_DOCUMENT, "", "format: %d is not a format", (int)f);
    if (opts && opts->compress != API_COMPRESS_NONE && !fi->compress) {
        api_compress_parse(api_compress_name(opts->compress), f, &(api_compress){ 0 }, err);
        return -1;
    }
    return range_check(sol, fi, err);
}

api_output *api_output_open_ex(const pde_solution *sol, const char *id, const pde_props *props, api_format f,
                               const unsigned res[3], const api_output_opts *opts, const pde_cancel *cancel,
                               api_error *err)
{
    api_error local;
    if (!err)
        err = &local;
    if (api_output_check(sol, f, opts, err))
        return NULL;
    const api_format_info *fi = api_format_info_of(f);
    api_output *o = calloc(1, sizeof *o);
    if (!o) {
        api_fail_nomem(err);
        return NULL;
    }
    o->fmt = fi;
    if (opts)
        o->opts = *opts;
    o->sol = sol;
    if (props) {
        o->props = *props;
        o->have_props = 1;
    }
    o->size = -1;
    snprintf(o->id, sizeof o->id, "%s", id ? id : "");
    memcpy(o->res, res, sizeof o->res);
    err->message[0] = '\0';
    if (fi->open(o, cancel, err)) {
        if (!err->message[0])
            api_fail_nomem(err);
        api_output_free(o);
        return NULL;
    }
    return o;
}

api_output *api_output_open(const pde_solution *sol, const char *id, const pde_props *props, api_format f,
                            const unsigned res[3], const pde_cancel *cancel, api_error *err)
{
    return api_output_open_ex(sol, id, props, f, res, NULL, cancel, err);
}

long long api_output_size(const api_output *o)
{
    return o->size;
}

long api_output_read(api_output *o, char *buf, size_t max)
{
    size_t done = 0;
    while (done < max) {
        if (o->pos == o->len) {
            if (done)
                break;      /* one piece of work per call: a caller can poll between calls */
            o->pos = o->len = 0;
            o->dst = buf, o->dst_max = max, o->dst_len = 0;   /* fill may write straight into buf */
            int r = o->fmt->fill(o);
            o->dst = NULL;
            if (r < 0)
                return -1;
            if (o->dst_len)
                return (long)o->dst_len;
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
    if (o->fmt->close)
        o->fmt->close(o->st);
    free(o->buf);
    free(o);
}
