/*
 * test_output.c: presets, templates, ids and every output format. Presets
 * against the paper's text and the tests' own transcription; glTF and GLB
 * through the Khronos glTF-Validator; grids read back against f32; the STL
 * skin closed and enclosing the computed volume; VTS offsets and det J; every
 * property under its documented name in json, glTF extras and VTS field data.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cJSON.h>
#include <cmocka.h>

#include "catalog.h"
#include "id.h"
#include "mesh.h"
#include "output.h"
#include "support.h"
#include "template.h"
#include "volmesh.h"

static char dir[] = "/tmp/pdesolid-out-XXXXXX";

static int setup(void **state)
{
    (void)state;
    return tmpdir_make(dir);
}

static int teardown(void **state)
{
    (void)state;
    return tmpdir_remove(dir);
}

static pde_solution *solve_preset(const char *name, char id[API_ID_LEN + 1])
{
    api_model *m = preset_model(name);
    pde_solution *sol;
    api_error err;
    if (api_solve(m, &sol, &err))
        fail_msg("%s: %s", name, err.message);
    if (id)
        assert_int_equal(api_model_id(api_model_get(m), id, NULL), PDE_OK);
    api_model_free(m);
    return sol;
}

/* The whole output in memory, with the caller's properties (NULL: computed); checks the declared size. */
static unsigned char *render_opts(const pde_solution *sol, const char *id, const pde_props *props, api_format f,
                                  const unsigned res[3], const api_output_opts *opts, size_t *len)
{
    api_error err;
    api_output *o = api_output_open_ex(sol, id, props, f, res, opts, NULL, &err);
    if (!o)
        fail_msg("%s: %s", api_format_info_of(f)->name, err.message);
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = malloc(cap);
    long got;
    /* Odd read sizes, to cross every internal boundary. */
    while ((got = api_output_read(o, (char *)buf + n, cap - n < 7777 ? cap - n : 7777)) > 0) {
        n += (size_t)got;
        if (cap - n < 8192)
            buf = realloc(buf, cap *= 2);
    }
    assert_int_equal(got, 0);
    if (api_output_size(o) >= 0)
        assert_int_equal((long long)n, api_output_size(o));
    api_output_free(o);
    *len = n;
    return buf;
}

static unsigned char *render_props(const pde_solution *sol, const char *id, const pde_props *props, api_format f,
                                   const unsigned res[3], size_t *len)
{
    return render_opts(sol, id, props, f, res, NULL, len);
}

static unsigned char *render(const pde_solution *sol, const char *id, api_format f, const unsigned res[3], size_t *len)
{
    return render_props(sol, id, NULL, f, res, len);
}

static const api_output_opts meshopt = { .compress = API_COMPRESS_MESHOPT };

/*
 * The properties by their names in docs/API.md, the tests' own transcription: the object under
 * "properties" (NULL: its top), the name, the vts field's name, and where the value is in p (n numbers,
 * a 3x3 matrix row by row). folds, the one boolean, is checked apart.
 */
typedef struct {
    const char *group, *name, *vts;
    double *v;
    int n;
} prop_path;

static size_t prop_paths(pde_props *p, prop_path out[32])
{
    const prop_path all[] = {
        { "bbox", "min", "bbox_min", p->bbox_min, 3 },
        { "bbox", "max", "bbox_max", p->bbox_max, 3 },
        { "bbox", "gap", "bbox_gap", &p->bbox_gap, 1 },
        { NULL, "volume", "volume", &p->volume, 1 },
        { NULL, "signed_volume", "signed_volume", &p->signed_volume, 1 },
        { "detJ", "min", "detJ_min", &p->detj_min, 1 },
        { "detJ", "max", "detJ_max", &p->detj_max, 1 },
        { "detJ", "min_at", "detJ_min_at", p->detj_min_at, 3 },
        { "detJ", "max_at", "detJ_max_at", p->detj_max_at, 3 },
        { "detJ", "gap", "detJ_gap", &p->detj_gap, 1 },
        { NULL, "centroid", "centroid", p->centroid, 3 },
        { NULL, "inertia", "inertia", &p->inertia[0][0], 9 },
        { "principal", "moments", "principal_moments", p->principal_moments, 3 },
        { "principal", "axes", "principal_axes", &p->principal_axes[0][0], 9 },
        { NULL, "surface_area", "surface_area", &p->surface_area, 1 },
        { "residuals", "boundary", "residuals_boundary", &p->bc_residual, 1 },
        { "residuals", "pde", "residuals_pde", &p->pde_residual, 1 },
        { "residuals", "integrals", "residuals_integrals", &p->integral_error, 1 },
        { "residuals", "area", "residuals_area", &p->surface_area_error, 1 },
        { "residuals", "fit", "residuals_fit", &p->fit_error, 1 },
        { "conditioning", "condition", "conditioning_condition", &p->condition, 1 },
        { "conditioning", "harmonic", "conditioning_harmonic", &p->condition_harmonic, 1 },
    };
    memcpy(out, all, sizeof all);
    return sizeof all / sizeof *all;
}

/* Properties whose every number differs from every other, so a value under a wrong name shows. */
static void distinct_props(pde_props *p)
{
    memset(p, 0, sizeof *p);
    prop_path paths[32];
    size_t n = prop_paths(p, paths);
    double x = 1.0;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < paths[i].n; k++, x += 1.0)
            paths[i].v[k] = x + 1.0 / 3.0 + x * 1e-9;
    p->folds = 1;
}

/* Every property of want in a "properties" tree, bit for bit (17 digits round-trip). */
static void props_tree_should_hold(const cJSON *t, const pde_props *want, const char *where)
{
    pde_props copy = *want;
    prop_path paths[32];
    size_t n = prop_paths(&copy, paths);
    assert_non_null(t);
    for (size_t i = 0; i < n; i++) {
        const cJSON *parent = paths[i].group ? cJSON_GetObjectItemCaseSensitive(t, paths[i].group) : t;
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(parent, paths[i].name);
        if (!v)
            fail_msg("%s: no %s%s%s", where, paths[i].group ? paths[i].group : "", paths[i].group ? "." : "",
                     paths[i].name);
        for (int k = 0; k < paths[i].n; k++) {
            const cJSON *x = paths[i].n == 1 ? v
                             : paths[i].n == 3 ? cJSON_GetArrayItem(v, k)
                                               : cJSON_GetArrayItem(cJSON_GetArrayItem(v, k / 3), k % 3);
            if (!cJSON_IsNumber(x) || x->valuedouble != paths[i].v[k])
                fail_msg("%s: %s[%d] is %.17g, want %.17g", where, paths[i].vts, k,
                         cJSON_IsNumber(x) ? x->valuedouble : NAN, paths[i].v[k]);
        }
        if (paths[i].n == 9)
            assert_int_equal(cJSON_GetArraySize(v), 3);
    }
    assert_int_equal(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(t, "folds")), want->folds != 0);
}

/* The same of a vts document's field data. */
static void vts_field_data_should_hold(const char *text, const pde_props *want)
{
    pde_props copy = *want;
    prop_path paths[32];
    size_t n = prop_paths(&copy, paths);
    const char *fd = strstr(text, "<FieldData>"), *end = strstr(text, "</FieldData>");
    assert_true(fd && end && fd < strstr(text, "<Piece"));
    for (size_t i = 0; i < n; i++) {
        char key[128];
        snprintf(key, sizeof key, "Name=\"%s\" NumberOfComponents=\"%d\" NumberOfTuples=\"1\" format=\"ascii\">",
                 paths[i].vts, paths[i].n);
        const char *at = strstr(fd, key);
        if (!at || at > end)
            fail_msg("vts: no field %s", key);
        char *p = (char *)at + strlen(key);
        for (int k = 0; k < paths[i].n; k++) {
            double x = strtod(p, &p);
            if (x != paths[i].v[k])
                fail_msg("vts: %s[%d] is %.17g, want %.17g", paths[i].vts, k, x, paths[i].v[k]);
        }
        assert_true(!strncmp(p, "</DataArray>", 12));
    }
    char folds[128];
    snprintf(folds, sizeof folds, "Name=\"folds\" NumberOfComponents=\"1\" NumberOfTuples=\"1\" format=\"ascii\">%d<",
             want->folds != 0);
    assert_non_null(strstr(fd, folds));
}

/* The properties object of a json document or of a GLB's asset.extras; cJSON_Delete *doc. */
static const cJSON *props_of_output(const unsigned char *bytes, size_t len, api_format f, cJSON **doc)
{
    if (f == API_FMT_GLB) {
        uint32_t jlen;
        memcpy(&jlen, bytes + 12, 4);
        *doc = cJSON_ParseWithLength((const char *)bytes + 20, jlen);
        return cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(*doc, "asset"), "extras"), "properties");
    }
    *doc = cJSON_ParseWithLength((const char *)bytes, len);
    return cJSON_GetObjectItem(*doc, "properties");
}

static void every_output_with_properties_should_carry_each_of_them_by_name(void **state)
{
    (void)state;
    pde_solution *sol = solve_preset("fig4a", NULL);
    pde_props computed, distinct;
    assert_int_equal(pde_properties(sol, NULL, &computed), PDE_OK);
    distinct_props(&distinct);
    const pde_props *cases[] = { NULL, &distinct };   /* computed by the output, and given to it */
    const api_format fmts[] = { API_FMT_JSON, API_FMT_GLB, API_FMT_VTS, API_FMT_VTU };
    for (size_t c = 0; c < 2; c++)
        for (size_t i = 0; i < 4; i++) {
            const pde_props *want = cases[c] ? cases[c] : &computed;
            assert_true(api_format_info_of(fmts[i])->props);
            const unsigned res[3] = { 4, 4, 4 };
            size_t len;
            unsigned char *b = render_props(sol, "abc", cases[c], fmts[i], res, &len);
            if (fmts[i] == API_FMT_VTS || fmts[i] == API_FMT_VTU) {   /* one writer of VTK field data */
                b = realloc(b, len + 1);
                b[len] = '\0';
                vts_field_data_should_hold((const char *)b, want);
            } else {
                cJSON *doc;
                props_tree_should_hold(props_of_output(b, len, fmts[i], &doc), want,
                                       api_format_info_of(fmts[i])->name);
                cJSON_Delete(doc);
            }
            free(b);
        }
    assert_false(api_format_info_of(API_FMT_STL)->props);
    pde_solution_free(sol);
}

static void properties_should_read_back_from_their_tree(void **state)
{
    (void)state;
    pde_props p, back;
    distinct_props(&p);
    cJSON *t = api_props_tree(&p);
    pde_props direct;
    api_props_from_tree(t, &direct);
    char *text = cJSON_PrintUnformatted(t);
    cJSON_Delete(t);
    t = cJSON_Parse(text);
    free(text);
    props_tree_should_hold(t, &p, "api_props_tree");
    api_props_from_tree(t, &back);
    cJSON_Delete(t);
    assert_memory_equal(&direct, &back, sizeof back);
    pde_props copy = back;
    prop_path a[32], b[32];
    size_t n = prop_paths(&p, a);
    prop_paths(&copy, b);
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < a[i].n; k++)
            assert_true(a[i].v[k] == b[i].v[k]);
    assert_int_equal(back.folds, 1);
}

static void presets_should_carry_the_papers_values(void **state)
{
    (void)state;
    struct {
        const char *preset, *param;
        double value;
    } cases[] = {
        { "fig1a", "a0", -0.5 }, { "fig1a", "h1", 1 },     { "fig1c", "a3", 2 },     { "fig1c", "b2", -1 },
        { "fig1e", "a1", 1.5 },  { "fig1e", "b2", -0.4 },  { "fig1e", "h0p", 2 },    { "fig1e", "h1p", 4 },
        { "fig1g", "a3p", -6 },  { "fig1g", "b1p", -7.5 }, { "fig1g", "h1p", 2 },    { "fig1g", "b2p", -0.4 },
        { "fig2a", "r0p", 0.5 }, { "fig2a", "b0", 1 },     { "fig2c", "h1", 2 },     { "fig3a", "n_xy", 20 },
        { "fig3b", "n_xy", 30 }, { "fig3c", "r2", 0.8 },   { "fig3c", "n_z", 10 },   { "fig3d", "n_xy", 14 },
        { "fig3d", "h3", -0.1 }, { "fig4a", "h1p", 7.5 },  { "fig4a", "p0", 3e4 },   { "fig4c", "p0", 1.8e6 },
        { "fig4c", "xi", 7 },    { "fig4e", "p0", -3e5 },  { "fig4n", "r0", 1.5 },   { "fig4o", "xi", 11 },
        { "fig4p", "h1p", 4.5 }, { "fig4w", "h1p", 10.5 }, { "fig4x", "r1p", -2.4 },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        const api_preset *ps = api_preset_find(cases[i].preset);
        api_params p;
        api_preset_params(ps, &p);
        double v[3];
        assert_int_equal(api_params_get(api_preset_template(ps), &p, cases[i].param, v), 1);
        if (v[0] != cases[i].value)
            fail_msg("%s %s = %g, the paper says %g", cases[i].preset, cases[i].param, v[0], cases[i].value);
    }
    struct {
        const char *preset;
        double b, c;
    } pde[] = { { "fig2a", 4, -100 }, { "fig2b", 2.5, -10 }, { "fig2c", 4, -10 }, { "fig4a", 1, -9.5 },
                { "fig4c", 4, -100 }, { "fig4p", 15, -40 } };
    for (size_t i = 0; i < sizeof pde / sizeof *pde; i++) {
        const api_preset *ps = api_preset_find(pde[i].preset);
        api_params p;
        double b[3], c[3];
        api_preset_params(ps, &p);
        api_params_get(api_preset_template(ps), &p, "b", b);
        api_params_get(api_preset_template(ps), &p, "c", c);
        assert_true(b[0] == pde[i].b && b[1] == pde[i].b && c[0] == pde[i].c && c[1] == pde[i].c);
    }
    assert_int_equal(api_preset_count(), 35);
    assert_null(api_preset_find("fig5a"));
}

static void presets_should_be_the_tests_own_transcription(void **state)
{
    (void)state;
    for (size_t i = 0; i < paper_figure_count(); i++) {
        pde_solution *a = solve_preset(paper_figure_name(i), NULL), *b;
        pde_model ref;
        paper_figure_model(i, &ref);
        assert_int_equal(pde_solve(&ref, &b, NULL), PDE_OK);
        for (int k = 0; k < 64; k++) {
            double p[3] = { (k % 4) / 3.0, (k / 4 % 4) / 3.0 + 0.01, (k / 16) / 3.0 }, x[3], y[3];
            pde_eval(a, p[0], p[1], p[2], x);
            pde_eval(b, p[0], p[1], p[2], y);
            for (int c = 0; c < 3; c++)
                if (!close_rel(x[c], y[c], 1e-14, 1e-12))
                    fail_msg("%s differs at (%g,%g,%g): %.17g %.17g", paper_figure_name(i), p[0], p[1], p[2], x[c],
                             y[c]);
        }
        pde_solution_free(a);
        pde_solution_free(b);
    }
}

static void every_preset_should_give_gltf_and_glb_that_the_khronos_validator_passes(void **state)
{
    (void)state;
    char cmd[32768];
    int n = snprintf(cmd, sizeof cmd, "node tests/node/validate_gltf.mjs");
    const unsigned res[3] = { 24, 24, 24 };
    for (size_t i = 0; i < api_preset_count(); i++) {
        const char *name = api_preset_at(i)->name;
        char id[API_ID_LEN + 1];
        pde_solution *sol = solve_preset(name, id);
        for (int g = 0; g < 4; g++) {   /* gltf, glb, and each compressed */
            size_t len;
            unsigned char *bytes = render_opts(sol, id, NULL, g % 2 ? API_FMT_GLB : API_FMT_GLTF, res,
                                               g / 2 ? &meshopt : NULL, &len);
            char path[128];
            snprintf(path, sizeof path, "%s/%s%s.%s", dir, name, g / 2 ? "-meshopt" : "", g % 2 ? "glb" : "gltf");
            FILE *f = fopen(path, "wb");
            assert_non_null(f);
            fwrite(bytes, 1, len, f);
            fclose(f);
            free(bytes);
            n += snprintf(cmd + n, sizeof cmd - (size_t)n, " %s", path);
        }
        pde_solution_free(sol);
    }
    snprintf(cmd + n, sizeof cmd - (size_t)n, " > %s/validator.txt 2>&1", dir);
    int st = system(cmd);
    if (st != 0) {
        char path[96];
        snprintf(path, sizeof path, "%s/validator.txt", dir);
        char *report = read_file(path, NULL);
        fail_msg("glTF-Validator (status %d):\n%s", st, report ? report : "(no report)");
    }
}

static void gltf_should_carry_the_id_properties_and_exact_bounds(void **state)
{
    (void)state;
    char id[API_ID_LEN + 1];
    pde_solution *sol = solve_preset("fig4a", id);
    const unsigned res[3] = { 32, 32, 32 };
    size_t len;
    unsigned char *bytes = render(sol, id, API_FMT_GLB, res, &len);
    /* GLB: 12-byte header, JSON chunk, BIN chunk. */
    uint32_t jlen;
    memcpy(&jlen, bytes + 12, 4);
    char *json = strndup((char *)bytes + 20, jlen);
    cJSON *g = cJSON_Parse(json);
    assert_non_null(g);
    cJSON *extras = cJSON_GetObjectItem(cJSON_GetObjectItem(g, "asset"), "extras");
    assert_string_equal(cJSON_GetObjectItem(extras, "id")->valuestring, id);
    assert_true(cJSON_IsTrue(cJSON_GetObjectItem(cJSON_GetObjectItem(extras, "properties"), "folds")));
    cJSON *pos = cJSON_GetArrayItem(cJSON_GetObjectItem(g, "accessors"), 0);
    int count = cJSON_GetObjectItem(pos, "count")->valueint;
    const float *p = (const float *)(bytes + 20 + jlen + 8);
    for (int c = 0; c < 3; c++) {
        float lo = INFINITY, hi = -INFINITY;
        for (int i = 0; i < count; i++)
            lo = fminf(lo, p[3 * i + c]), hi = fmaxf(hi, p[3 * i + c]);
        assert_true((float)cJSON_GetArrayItem(cJSON_GetObjectItem(pos, "min"), c)->valuedouble == lo);
        assert_true((float)cJSON_GetArrayItem(cJSON_GetObjectItem(pos, "max"), c)->valuedouble == hi);
        assert_true(cJSON_GetArrayItem(cJSON_GetObjectItem(pos, "min"), c)->valuedouble == (double)lo);
    }
    cJSON_Delete(g);
    free(json);
    free(bytes);
    pde_solution_free(sol);
}

/* glTF is +Y up: fig4a's height (z in the model, w in the paper: 0 to 3) lies along glTF's +Y. The GLB's
 * POSITION min and max are the STL's (the same skin, in the model's frame) as (x, z, -y), exactly. */
static void gltf_should_stand_the_height_along_plus_y(void **state)
{
    (void)state;
    pde_solution *sol = solve_preset("fig4a", NULL);
    const unsigned res[3] = { 24, 24, 24 };
    size_t glen, slen;
    unsigned char *glb = render(sol, NULL, API_FMT_GLB, res, &glen);
    unsigned char *stl = render(sol, NULL, API_FMT_STL, res, &slen);
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    uint32_t ntri;
    memcpy(&ntri, stl + 80, 4);
    for (uint32_t t = 0; t < ntri; t++)
        for (int v = 0; v < 3; v++)
            for (int c = 0; c < 3; c++) {
                float x;
                memcpy(&x, stl + 84 + 50 * (size_t)t + 12 + 12 * v + 4 * c, 4);
                lo[c] = fminf(lo[c], x), hi[c] = fmaxf(hi[c], x);
            }
    uint32_t jlen;
    memcpy(&jlen, glb + 12, 4);
    char *json = strndup((char *)glb + 20, jlen);
    cJSON *g = cJSON_Parse(json);
    const cJSON *pos = cJSON_GetArrayItem(cJSON_GetObjectItem(g, "accessors"), 0);
    const cJSON *mn = cJSON_GetObjectItem(pos, "min"), *mx = cJSON_GetObjectItem(pos, "max");
    const double want_min[3] = { lo[0], lo[2], -hi[1] }, want_max[3] = { hi[0], hi[2], -lo[1] };
    for (int c = 0; c < 3; c++) {
        if (cJSON_GetArrayItem(mn, c)->valuedouble != want_min[c] || cJSON_GetArrayItem(mx, c)->valuedouble != want_max[c])
            fail_msg("axis %d: glTF [%.9g, %.9g], want [%.9g, %.9g]", c, cJSON_GetArrayItem(mn, c)->valuedouble,
                     cJSON_GetArrayItem(mx, c)->valuedouble, want_min[c], want_max[c]);
    }
    /* The height, 3 m, along +Y; and the asset says so, in metres. */
    assert_float_equal(cJSON_GetArrayItem(mn, 1)->valuedouble, 0.0, 1e-6);
    assert_float_equal(cJSON_GetArrayItem(mx, 1)->valuedouble, 3.0, 1e-6);
    const cJSON *extras = cJSON_GetObjectItem(cJSON_GetObjectItem(g, "asset"), "extras");
    assert_string_equal(cJSON_GetObjectItem(extras, "units")->valuestring, "metres");
    cJSON_Delete(g);
    free(json);
    free(glb);
    free(stl);
    pde_solution_free(sol);
}

/* The GLB's _DETJ attribute is the skin's det J (api_mesh.detj), vertex for vertex: a float SCALAR the
 * front-end colours folds by. */
static void glb_should_carry_det_j_as_the_detj_attribute(void **state)
{
    (void)state;
    pde_solution *sol = solve_preset("fig4a", NULL);
    const unsigned res[3] = { 20, 20, 20 };
    api_mesh m;
    assert_int_equal(api_mesh_build(sol, res, NULL, &m, NULL), 0);
    size_t len;
    unsigned char *glb = render(sol, NULL, API_FMT_GLB, res, &len);
    uint32_t jlen;
    memcpy(&jlen, glb + 12, 4);
    cJSON *g = cJSON_ParseWithLength((const char *)glb + 20, jlen);
    const cJSON *prim = cJSON_GetArrayItem(cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(g, "meshes"), 0),
                                                                "primitives"), 0);
    const cJSON *at = cJSON_GetObjectItem(cJSON_GetObjectItem(prim, "attributes"), "_DETJ");
    assert_non_null(at);
    const cJSON *acc = cJSON_GetArrayItem(cJSON_GetObjectItem(g, "accessors"), at->valueint);
    assert_int_equal(cJSON_GetObjectItem(acc, "componentType")->valueint, 5126);
    assert_string_equal(cJSON_GetObjectItem(acc, "type")->valuestring, "SCALAR");
    assert_int_equal(cJSON_GetObjectItem(acc, "count")->valueint, (int)m.nverts);
    const cJSON *view = cJSON_GetArrayItem(cJSON_GetObjectItem(g, "bufferViews"),
                                           cJSON_GetObjectItem(acc, "bufferView")->valueint);
    size_t off = (size_t)cJSON_GetObjectItem(view, "byteOffset")->valuedouble;
    assert_int_equal((size_t)cJSON_GetObjectItem(view, "byteLength")->valuedouble, 4 * m.nverts);
    assert_memory_equal(glb + 20 + jlen + 8 + off, m.detj, 4 * m.nverts);
    int negative = 0;
    for (size_t i = 0; i < m.nverts; i++)
        negative += m.detj[i] < 0;
    assert_true(negative > 0);     /* fig4a folds */
    cJSON_Delete(g);
    free(glb);
    api_mesh_free(&m);
    pde_solution_free(sol);
}

/* compress=meshopt: fig4a at res 64 in at most a quarter of the plain GLB's bytes; the same skin, +Y up (its
 * POSITION bounds within the stated tolerance of the plain one's), the extensions required as the
 * EXT_meshopt_compression spec asks of a fallback buffer without data. */
static void meshopt_glb_should_be_a_quarter_of_the_plain_one_and_stand_along_plus_y(void **state)
{
    (void)state;
    pde_solution *sol = solve_preset("fig4a", NULL);
    const unsigned res[3] = { 64, 64, 64 };
    size_t plen, zlen;
    unsigned char *plain = render(sol, NULL, API_FMT_GLB, res, &plen);
    unsigned char *z = render_opts(sol, NULL, NULL, API_FMT_GLB, res, &meshopt, &zlen);
    print_message("fig4a res 64: glb %zu bytes, meshopt glb %zu (%.3f)\n", plen, zlen, (double)zlen / (double)plen);
    assert_true(4 * zlen <= plen);
    cJSON *g[2];
    for (int k = 0; k < 2; k++) {
        const unsigned char *b = k ? z : plain;
        uint32_t jlen;
        memcpy(&jlen, b + 12, 4);
        g[k] = cJSON_ParseWithLength((const char *)b + 20, jlen);
        assert_non_null(g[k]);
    }
    for (int r = 0; r < 2; r++) {
        const cJSON *list = cJSON_GetObjectItem(g[1], r ? "extensionsRequired" : "extensionsUsed");
        assert_int_equal(cJSON_GetArraySize(list), 2);
        assert_string_equal(cJSON_GetArrayItem(list, 0)->valuestring, "EXT_meshopt_compression");
        assert_string_equal(cJSON_GetArrayItem(list, 1)->valuestring, "KHR_mesh_quantization");
    }
    const cJSON *extras = cJSON_GetObjectItem(cJSON_GetObjectItem(g[1], "asset"), "extras");
    double tol = cJSON_GetObjectItem(extras, "position_error")->valuedouble;
    assert_true(tol > 0 && tol < 1e-6);    /* docs/API.md: positions within 1 micrometre */
    assert_non_null(cJSON_GetObjectItem(cJSON_GetObjectItem(extras, "properties"), "volume"));
    const cJSON *p0 = cJSON_GetArrayItem(cJSON_GetObjectItem(g[0], "accessors"), 0);
    const cJSON *p1 = cJSON_GetArrayItem(cJSON_GetObjectItem(g[1], "accessors"), 0);
    for (int c = 0; c < 3; c++)
        for (int mx = 0; mx < 2; mx++) {
            double a = cJSON_GetArrayItem(cJSON_GetObjectItem(p0, mx ? "max" : "min"), c)->valuedouble;
            double b = cJSON_GetArrayItem(cJSON_GetObjectItem(p1, mx ? "max" : "min"), c)->valuedouble;
            if (fabs(a - b) > 2 * tol + 1e-7)
                fail_msg("axis %d %s: plain %.9g, meshopt %.9g", c, mx ? "max" : "min", a, b);
        }
    assert_float_equal(cJSON_GetArrayItem(cJSON_GetObjectItem(p1, "max"), 1)->valuedouble, 3.0, 1e-6);   /* height along +Y */
    cJSON_Delete(g[0]);
    cJSON_Delete(g[1]);
    free(plain);
    free(z);
    pde_solution_free(sol);
}

static void grid_json_should_read_back_as_the_f32_output(void **state)
{
    (void)state;
    const char *names[3] = { "fig3c", "fig4a", "fig1g" };
    const unsigned res[3] = { 7, 11, 5 };
    for (int f = 0; f < 3; f++) {
        pde_solution *sol = solve_preset(names[f], NULL);
        size_t jl, bl;
        char *json = (char *)render(sol, NULL, API_FMT_GRID, res, &jl);
        float *bin = (float *)render(sol, NULL, API_FMT_F32, res, &bl);
        json = realloc(json, jl + 1);
        json[jl] = '\0';
        cJSON *g = cJSON_Parse(json);
        assert_non_null(g);
        cJSON *r = cJSON_GetObjectItem(g, "resolution");
        for (int k = 0; k < 3; k++)
            assert_int_equal(cJSON_GetArrayItem(r, k)->valueint, (int)res[k]);
        size_t n = res[0] * res[1] * res[2];
        assert_int_equal(bl, 12 * n);
        static const char *const comp[3] = { "x", "y", "z" };
        for (int c = 0; c < 3; c++) {
            cJSON *a = cJSON_GetObjectItem(g, comp[c]);
            assert_int_equal((size_t)cJSON_GetArraySize(a), n);
            size_t i = 0;
            for (cJSON *e = a->child; e; e = e->next, i++)
                if ((float)e->valuedouble != bin[3 * i + c])
                    fail_msg("%s %s[%zu]: %.9g in JSON, %.9g in f32", names[f], comp[c], i, e->valuedouble,
                             (double)bin[3 * i + c]);
        }
        /* And the f32 is the solution at i/(n-1). */
        double x[3];
        pde_eval(sol, 0.5, 1.0, 0.25, x);
        size_t at = 3 * ((1 * res[1] + 10) * res[0] + 3);
        for (int c = 0; c < 3; c++)
            assert_rel(bin[at + c], x[c], 1e-6, 1.0);
        cJSON_Delete(g);
        free(json);
        free(bin);
        pde_solution_free(sol);
    }
}

/* Directed edges (two float triples) ordered by their bytes. */
static int cmp(const void *pa, const void *pb)
{
    return memcmp(pa, pb, 24);
}

/* Reads binary STL triangles; checks that every edge is used once in each direction. */
static double stl_closed_volume(const unsigned char *b, size_t len, size_t *ntri)
{
    uint32_t n;
    memcpy(&n, b + 80, 4);
    assert_int_equal(len, 84 + 50 * (size_t)n);
    *ntri = n;
    typedef struct {
        float a[3], b[3];
    } edge;
    edge *e = malloc(3 * n * sizeof *e);
    double vol = 0;
    for (uint32_t t = 0; t < n; t++) {
        float v[3][3];
        memcpy(v, b + 84 + 50 * (size_t)t + 12, sizeof v);
        for (int i = 0; i < 3; i++) {
            memcpy(e[3 * t + i].a, v[i], 12);
            memcpy(e[3 * t + i].b, v[(i + 1) % 3], 12);
        }
        double c[3] = { (double)v[1][1] * v[2][2] - (double)v[1][2] * v[2][1],
                        (double)v[1][2] * v[2][0] - (double)v[1][0] * v[2][2],
                        (double)v[1][0] * v[2][1] - (double)v[1][1] * v[2][0] };
        vol += (v[0][0] * c[0] + v[0][1] * c[1] + v[0][2] * c[2]) / 6;
    }
    /* Sort the directed edges; each needs its reverse exactly once. */
    qsort(e, 3 * (size_t)n, sizeof *e, cmp);
    for (size_t i = 0; i < 3 * (size_t)n; i++) {
        edge r;
        memcpy(r.a, e[i].b, 12);
        memcpy(r.b, e[i].a, 12);
        edge *hit = bsearch(&r, e, 3 * (size_t)n, sizeof *e, cmp);
        if (!hit)
            fail_msg("edge (%g,%g,%g)-(%g,%g,%g) has no twin: the skin is open", e[i].a[0], e[i].a[1], e[i].a[2],
                     e[i].b[0], e[i].b[1], e[i].b[2]);
        if ((hit > e && cmp(hit - 1, &r) == 0) || (hit + 1 < e + 3 * n && cmp(hit + 1, &r) == 0))
            fail_msg("an edge is shared by more than two triangles");
    }
    free(e);
    return vol;
}


static void stl_skin_should_be_closed_and_enclose_the_computed_volume(void **state)
{
    (void)state;
    const char *names[] = { "fig1a", "fig1e", "fig2b", "fig3a", "fig3d", "fig4b", "fig4h" };
    for (size_t f = 0; f < sizeof names / sizeof *names; f++) {
        pde_solution *sol = solve_preset(names[f], NULL);
        const unsigned res[3] = { 48, 160, 64 };
        size_t len, nt;
        unsigned char *b = render(sol, NULL, API_FMT_STL, res, &len);
        double vol = stl_closed_volume(b, len, &nt);
        pde_props p;
        assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
        if (!close_rel(vol, fabs(p.signed_volume), 2e-3, 0))
            fail_msg("%s: the skin encloses %.9g, the solid's volume is %.9g", names[f], vol, p.signed_volume);
        assert_true(vol > 0);
        free(b);
        pde_solution_free(sol);
    }
}

/* Every preset and loft: the skin closed (each edge used once each way), the vertices' normals
 * (the closed form's) on the side their triangles face, and det J at the vertices of w = 1 equal
 * to det(x_u, x_v, x_w) from pde_eval_d there. */
static void every_skin_should_be_closed_with_normals_and_det_j_from_the_closed_form(void **state)
{
    (void)state;
    const char *lofts[] = { "vase", "tower", "blade", "bottle" };
    const size_t nfig = paper_figure_count(), n = nfig + sizeof lofts / sizeof *lofts;
    for (size_t f = 0; f < n; f++) {
        const char *name = f < nfig ? paper_figure_name(f) : lofts[f - nfig];
        pde_solution *sol = solve_preset(name, NULL);
        api_error err;
        const unsigned res[3] = { 24, 160, 24 };   /* fig. 3's sin 30 pi v: 10 samples a period */
        size_t len, nt;
        unsigned char *b = render(sol, NULL, API_FMT_STL, res, &len);
        if (!(stl_closed_volume(b, len, &nt) > 0))
            fail_msg("%s: the skin encloses no positive volume", name);
        free(b);

        api_mesh m;
        assert_int_equal(api_mesh_build(sol, res, NULL, &m, &err), 0);
        double *acc = calloc(3 * m.nverts, sizeof *acc);
        for (size_t t = 0; t < m.ntris; t++) {
            const float *p[3];
            for (int i = 0; i < 3; i++)
                p[i] = m.pos + 3 * m.tri[3 * t + i];
            double a[3], c[3], d[3];
            for (int k = 0; k < 3; k++)
                a[k] = (double)p[1][k] - p[0][k], c[k] = (double)p[2][k] - p[0][k];
            d[0] = a[1] * c[2] - a[2] * c[1], d[1] = a[2] * c[0] - a[0] * c[2], d[2] = a[0] * c[1] - a[1] * c[0];
            for (int i = 0; i < 3; i++)
                for (int k = 0; k < 3; k++)
                    acc[3 * m.tri[3 * t + i] + k] += d[k];
        }
        size_t agree = 0, used = 0;
        for (size_t v = 0; v < m.nverts; v++) {
            const double *a = acc + 3 * v;
            const float *nr = m.nrm + 3 * v;
            double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
            if (!(la > 0))
                continue;
            used++;
            double c = (a[0] * nr[0] + a[1] * nr[1] + a[2] * nr[2]) / la;
            agree += c > 0.5;
            assert_true(fabs(sqrt((double)nr[0] * nr[0] + (double)nr[1] * nr[1] + (double)nr[2] * nr[2]) - 1) < 1e-6);
        }
        /* Not all: on a cuspidal edge of a folded face (fig. 3b's) the triangles around a vertex mix
         * both sheets; a normal of the wrong sign would agree nowhere. */
        if (agree < used * 90 / 100)
            fail_msg("%s: only %zu of %zu vertex normals lie within 60 degrees of their triangles'", name, agree, used);

        /* det J at the interior samples of w = 1, found by their positions. */
        double jmax = 0;
        for (size_t v = 0; v < m.nverts; v++)
            jmax = fmax(jmax, fabs(m.detj[v]));
        size_t checked = 0;
        for (unsigned i = 1; i + 1 < res[0]; i += 3)
            for (unsigned j = 1; j + 1 < res[1]; j += 3) {
                double u = (double)i / (res[0] - 1), vv = (double)j / (res[1] - 1), x[3], xu[3], xv[3], xw[3];
                pde_eval_d(sol, u, vv, 1.0, x, xu, xv, xw);
                const double dj = xu[0] * (xv[1] * xw[2] - xv[2] * xw[1]) - xu[1] * (xv[0] * xw[2] - xv[2] * xw[0]) +
                                  xu[2] * (xv[0] * xw[1] - xv[1] * xw[0]);
                size_t hit = SIZE_MAX, hits = 0;
                for (size_t v = 0; v < m.nverts; v++)
                    if (m.pos[3 * v] == (float)x[0] && m.pos[3 * v + 1] == (float)x[1] && m.pos[3 * v + 2] == (float)x[2] &&
                        fabs(m.nrm[3 * v + 2]) >= 0)
                        hit = v, hits++;
                if (hits != 1)
                    continue;   /* on a fold or a seam the position does not tell the sample */
                checked++;
                if (!(fabs(m.detj[hit] - dj) <= 1e-5 * jmax + 1e-6 * fabs(dj)))
                    fail_msg("%s: det J at (%g, %g, 1) is %.9g in the mesh, %.9g from pde_eval_d", name, u, vv,
                             m.detj[hit], dj);
            }
        if (checked < 10)
            fail_msg("%s: only %zu samples of w = 1 found among the vertices", name, checked);
        free(acc);
        api_mesh_free(&m);
        pde_solution_free(sol);
    }
}

/* The mesh's memory is kept for the next build (mesh.h): a mesh built into kept blocks, while another
 * still holds one, of another size, or after the blocks are released, is the same mesh, bit for bit. */
static void mesh_build_should_give_the_same_mesh_in_kept_and_fresh_memory(void **state)
{
    (void)state;
    pde_solution *sol = solve_preset("fig4a", NULL);
    const unsigned res[3] = { 20, 28, 24 }, small[3] = { 6, 5, 4 };
    api_mesh a, b, c, d;
    api_mesh_release_spares();
    assert_int_equal(api_mesh_build(sol, res, NULL, &a, NULL), 0);   /* fresh */
    assert_int_equal(api_mesh_build(sol, small, NULL, &c, NULL), 0);  /* while a is held */
    api_mesh_free(&c);
    assert_int_equal(api_mesh_build(sol, res, NULL, &b, NULL), 0);    /* into c's kept block: too small */
    assert_int_equal(api_mesh_build(sol, small, NULL, &c, NULL), 0);
    api_mesh_free(&b);
    assert_int_equal(api_mesh_build(sol, res, NULL, &d, NULL), 0);    /* into b's kept block */
    api_mesh_release_spares();
    for (const api_mesh *m = &d;; m = &b) {
        assert_int_equal(m->nverts, a.nverts);
        assert_int_equal(m->ntris, a.ntris);
        assert_int_equal(m->npos, a.npos);
        assert_memory_equal(m->pos, a.pos, 3 * a.nverts * sizeof *a.pos);
        assert_memory_equal(m->nrm, a.nrm, 3 * a.nverts * sizeof *a.nrm);
        assert_memory_equal(m->detj, a.detj, a.nverts * sizeof *a.detj);
        assert_memory_equal(m->weld, a.weld, a.nverts * sizeof *a.weld);
        assert_memory_equal(m->tri, a.tri, 3 * a.ntris * sizeof *a.tri);
        assert_memory_equal(m->min, a.min, sizeof a.min);
        assert_memory_equal(m->max, a.max, sizeof a.max);
        if (m == &b)
            break;
        api_mesh_free(&d);
        api_mesh_release_spares();
        assert_int_equal(api_mesh_build(sol, res, NULL, &b, NULL), 0);   /* fresh again */
    }
    api_mesh_free(&a);
    api_mesh_free(&b);
    api_mesh_free(&c);
    api_mesh_free(&c);   /* a freed mesh is zeroed: freeing it again does nothing */
    api_mesh_release_spares();
    pde_solution_free(sol);
}

/* The glb's blob is written straight into the reader's buffer (fmt.h's o->dst): the bytes must not depend on
 * the buffer's size, down to 1 byte (smaller than a float) and odd sizes that split floats. */
static void glb_should_be_the_same_bytes_whatever_the_reader_s_buffer(void **state)
{
    (void)state;
    pde_solution *sol = solve_preset("fig4a", NULL);
    const unsigned res[3] = { 9, 12, 7 };
    const size_t sizes[] = { 65536, 1, 3, 5, 777, 4096 };
    unsigned char *first = NULL;
    size_t first_len = 0;
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
        api_error err;
        api_output *o = api_output_open(sol, "abc", NULL, API_FMT_GLB, res, NULL, &err);
        assert_non_null(o);
        const size_t cap = (size_t)api_output_size(o) + 65536;
        unsigned char *buf = malloc(cap);
        assert_non_null(buf);
        size_t n = 0;
        long got;
        while ((got = api_output_read(o, (char *)buf + n, sizes[s] < cap - n ? sizes[s] : cap - n)) > 0)
            n += (size_t)got;
        assert_int_equal(got, 0);
        assert_int_equal((long long)n, api_output_size(o));
        api_output_free(o);
        if (!first) {
            first = buf, first_len = n;
            continue;
        }
        assert_int_equal(n, first_len);
        assert_memory_equal(buf, first, n);
        free(buf);
    }
    free(first);
    pde_solution_free(sol);
}

static void vts_should_hold_the_points_and_det_j(void **state)
{
    (void)state;
    pde_solution *sol = solve_preset("fig2b", NULL);
    const unsigned res[3] = { 5, 9, 4 };
    size_t len;
    unsigned char *b = render(sol, "abc", API_FMT_VTS, res, &len);
    const char *text = (const char *)b;
    assert_non_null(strstr(text, "WholeExtent=\"0 4 0 8 0 3\""));
    const char *mark = strstr(text, "<AppendedData encoding=\"raw\">\n   _");
    assert_non_null(mark);
    const unsigned char *data = (const unsigned char *)mark + strlen("<AppendedData encoding=\"raw\">\n   _");
    size_t n = 5 * 9 * 4;
    uint64_t nbytes;
    memcpy(&nbytes, data, 8);
    assert_int_equal(nbytes, 12 * n);
    const char *off = strstr(text, "Name=\"detJ\" NumberOfComponents=\"1\" format=\"appended\" offset=\"");
    assert_non_null(off);
    assert_int_equal(atoll(off + strlen("Name=\"detJ\" NumberOfComponents=\"1\" format=\"appended\" offset=\"")),
                     (long long)(8 + 12 * n));
    /* The appended data start wherever the header ends: copy them out to aligned floats. */
    float pts[3 * 5 * 9 * 4], dj[5 * 9 * 4];
    memcpy(pts, data + 8, sizeof pts);
    memcpy(dj, data + 8 + 12 * n + 8, sizeof dj);
    for (size_t k = 0; k < 4; k++)
        for (size_t j = 0; j < 9; j++)
            for (size_t i = 0; i < 5; i++) {
                size_t at = (k * 9 + j) * 5 + i;
                double u = i / 4.0, v = j / 8.0, w = k / 3.0, x[3], a[3], bb[3], c[3];
                pde_eval_d(sol, u, v, w, x, a, bb, c);
                double d = a[0] * (bb[1] * c[2] - bb[2] * c[1]) - a[1] * (bb[0] * c[2] - bb[2] * c[0]) +
                           a[2] * (bb[0] * c[1] - bb[1] * c[0]);
                for (int q = 0; q < 3; q++)
                    assert_rel(pts[3 * at + q], x[q], 1e-6, 1);
                assert_rel(dj[at], d, 1e-5, 1);
            }
    assert_non_null(strstr((const char *)data + 8 + 12 * n + 8 + 4 * n, "</AppendedData>\n</VTKFile>\n"));
    free(b);
    pde_solution_free(sol);
}

static void json_should_hold_the_closed_form_properties_and_id(void **state)
{
    (void)state;
    char id[API_ID_LEN + 1];
    pde_solution *sol = solve_preset("fig4a", id);
    const unsigned res[3] = { 2, 2, 2 };
    size_t len;
    char *text = (char *)render(sol, id, API_FMT_JSON, res, &len);
    text = realloc(text, len + 1);
    text[len] = '\0';
    cJSON *j = cJSON_Parse(text);
    assert_non_null(j);
    assert_string_equal(cJSON_GetObjectItem(j, "id")->valuestring, id);
    cJSON *modes = cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(j, "components"), "x"), "modes");
    assert_int_equal(cJSON_GetArraySize(modes), 2);
    /* Rebuild x at a point from the JSON's closed form alone. */
    double u = 0.7, v = 0.2, w = 0.35, x = 0;
    for (cJSON *m = modes->child; m; m = m->next) {
        double fu = u;   /* both modes have u^1 */
        cJSON *fv = cJSON_GetObjectItem(m, "v");
        double k = fv->child->valuedouble * M_PI;
        double g = strcmp(fv->child->string, "sin") == 0 ? sin(k * v) : cos(k * v), h = 0;
        for (cJSON *t = cJSON_GetObjectItem(m, "h")->child; t; t = t->next) {
            double al = cJSON_GetObjectItem(t, "alpha")->valuedouble, be = cJSON_GetObjectItem(t, "beta")->valuedouble;
            double sh = cJSON_GetObjectItem(t, "shift")->valuedouble, A = 0, B = 0, wp = 1;
            cJSON *ca = cJSON_GetObjectItem(t, "A")->child, *cb = cJSON_GetObjectItem(t, "B")->child;
            for (; ca; ca = ca->next, cb = cb->next, wp *= w)
                A += ca->valuedouble * wp, B += cb->valuedouble * wp;
            h += exp(al * (w - sh)) * (A * cos(be * w) + B * sin(be * w));
        }
        x += h * fu * g;
    }
    double want[3];
    pde_eval(sol, u, v, w, want);
    assert_rel(x, want[0], 1e-13, 1);
    /* and every number of it is the solution's to the last bit (cJSON's writer settled for 15 digits) */
    size_t nm, exact = 0, all = 0;
    const pde_mode *md = pde_solution_modes(sol, 0, &nm);
    cJSON *m = modes->child;
    for (size_t i = 0; i < nm; i++, m = m->next) {
        all++, exact += cJSON_GetObjectItem(m, "e")->valuedouble == md[i].e;
        cJSON *t = cJSON_GetObjectItem(m, "h")->child;
        for (size_t k = 0; k < md[i].nterms; k++, t = t->next) {
            const pde_wterm *wt = &md[i].terms[k];
            all += 3, exact += (cJSON_GetObjectItem(t, "alpha")->valuedouble == wt->alpha) +
                               (cJSON_GetObjectItem(t, "beta")->valuedouble == wt->beta) +
                               (cJSON_GetObjectItem(t, "shift")->valuedouble == wt->shift);
            cJSON *ca = cJSON_GetObjectItem(t, "A")->child, *cb = cJSON_GetObjectItem(t, "B")->child;
            for (int d = 0; d <= wt->deg; d++, ca = ca->next, cb = cb->next)
                all += 2, exact += (ca->valuedouble == wt->A[d]) + (cb->valuedouble == wt->B[d]);
        }
    }
    assert_int_equal(exact, all);
    assert_non_null(strstr(cJSON_GetObjectItem(j, "closed_form")->valuestring, "x(u,v,w) = sum over 2 modes"));
    cJSON *props = cJSON_GetObjectItem(j, "properties");
    assert_true(cJSON_GetObjectItem(props, "volume")->valuedouble > 0);
    assert_true(cJSON_GetObjectItem(cJSON_GetObjectItem(props, "residuals"), "boundary")->valuedouble < 1e-12);
    cJSON_Delete(j);
    free(text);
    pde_solution_free(sol);
}

static void id_should_not_depend_on_how_the_model_is_spelled(void **state)
{
    (void)state;
    const char *a = "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-9.5,-9.5,-10]},"
                    "\"boundary\":{\"x\":[{\"u\":{\"pow\":1},\"v\":{\"sin\":2},\"w0\":0.5,\"w1\":0.5}],"
                    "\"y\":[{\"u\":{\"pow\":1},\"v\":{\"cos\":2},\"w0\":0.5,\"w1\":0.5}],"
                    "\"z\":[{\"w1\":3,\"dw1\":7.5}]},"
                    "\"force\":{\"x\":[{\"coef\":30000,\"u\":{\"pow\":1},\"v\":{\"cos\":2},\"w\":{\"sin\":3}}],"
                    "\"y\":[{\"coef\":30000,\"u\":{\"pow\":1},\"v\":{\"sin\":2},\"w\":{\"sin\":3}}]}}";
    /* The same solid: keys reordered, a term split in two, sin(-2) for -sin(2), a zero term, 3e4. */
    const char *b = "{\"force\":{\"y\":[{\"w\":{\"sin\":3},\"coef\":3e4,\"v\":{\"sin\":2},\"u\":{\"pow\":1}}],"
                    "\"x\":[{\"coef\":10000,\"u\":{\"pow\":1},\"v\":{\"cos\":2},\"w\":{\"sin\":3}},"
                    "{\"coef\":20000,\"u\":{\"pow\":1},\"v\":{\"cos\":-2},\"w\":{\"sin\":3}}]},"
                    "\"boundary\":{\"z\":[{\"dw1\":7.5,\"w1\":3},{\"u\":{\"sin\":5}}],"
                    "\"x\":[{\"u\":{\"pow\":1},\"v\":{\"sin\":-2},\"w0\":-0.5,\"w1\":-0.5}],"
                    "\"y\":[{\"u\":{\"pow\":1},\"v\":{\"cos\":2},\"w1\":0.5,\"w0\":0.5}]},"
                    "\"pde\":{\"c\":[-9.5,-9.5,-10],\"b\":[1,1,1],\"a\":[1,1,1]}}";
    const char *c = "{\"preset\":\"fig4a\"}";
    const char *d = "{\"preset\":\"fig4a\",\"params\":{\"p0\":30001}}";
    const char *texts[4] = { a, b, c, d };
    char ids[4][API_ID_LEN + 1];
    for (int i = 0; i < 4; i++) {
        api_error err;
        api_model *m = api_model_parse(texts[i], strlen(texts[i]), &err);
        if (!m)
            fail_msg("%d: %s: %s", i, err.pointer, err.message);
        assert_int_equal(api_model_id(api_model_get(m), ids[i], NULL), PDE_OK);
        assert_int_equal(strlen(ids[i]), API_ID_LEN);
        api_model_free(m);
    }
    assert_string_equal(ids[0], ids[1]);
    assert_string_equal(ids[0], ids[2]);
    assert_string_not_equal(ids[0], ids[3]);
}

static void bad_formats_and_resolutions_should_name_the_limit(void **state)
{
    (void)state;
    const struct {
        const char *res, *format, *words;
    } cases[] = {
        { "0", "grid", "too few" },        { "1", "f32", "too few" },
        { "5000", "grid", "limit of 4096" }, { "600", "glb", "limit of 512" },
        { "1024", "f32", "points in all" }, { "a,b,c", "grid", "NU,NV,NW" },
        { "3,3", "grid", "NU,NV,NW" },      { "-4", "grid", "NU,NV,NW" },
        { "4,4,4,", "grid", "NU,NV,NW" },   { "99999999999999999999", "grid", "99999999999999999999\" is more than the limit" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        api_format f;
        api_error err;
        unsigned res[3];
        assert_int_equal(api_format_parse(cases[i].format, &f, &err), 0);
        assert_int_equal(api_res_parse(cases[i].res, f, res, &err), -1);
        if (!strstr(err.message, cases[i].words))
            fail_msg("res %s: %s", cases[i].res, err.message);
    }
    api_format f;
    api_error err;
    unsigned res[3];
    /* json samples nothing: any res is one answer (res=512 was refused as too many points, and res=5 and 33
     * gave one body under two ETags: QA), the default's. */
    static const char *const any[] = { "2", "512", "5,6,7", "abc", "99999999999999999999" };
    for (size_t i = 0; i < sizeof any / sizeof *any; i++) {
        unsigned want[3];
        assert_int_equal(api_res_parse(NULL, API_FMT_JSON, want, &err), 0);
        assert_int_equal(api_res_parse(any[i], API_FMT_JSON, res, &err), 0);
        assert_memory_equal(res, want, sizeof res);
    }
    assert_int_equal(api_format_parse("dae", &f, &err), -1);
    assert_non_null(strstr(err.message, "json, grid, f32, gltf, glb, vts, stl, obj, ply, msh, vtu"));
    api_compress c;
    assert_int_equal(api_compress_parse("meshopt", API_FMT_STL, &c, &err), -1);
    assert_non_null(strstr(err.message, "compress: meshopt applies to gltf, glb, not to stl"));
    assert_int_equal(api_compress_parse("draco", API_FMT_GLB, &c, &err), -1);
    assert_non_null(strstr(err.message, "compress: \"draco\" is not a compression"));
    assert_int_equal(api_compress_parse("meshopt", API_FMT_GLTF, &c, &err), 0);
    assert_int_equal(c, API_COMPRESS_MESHOPT);
    assert_int_equal(api_compress_parse(NULL, API_FMT_STL, &c, &err), 0);
    assert_int_equal(c, API_COMPRESS_NONE);
    assert_int_equal(api_format_parse("glb", &f, &err), 0);
    assert_int_equal(api_res_parse(NULL, f, res, &err), 0);
    assert_int_equal(res[0], API_RES_MESH_DEFAULT);
    assert_int_equal(api_res_parse("8,16,32", f, res, &err), 0);
    assert_true(res[0] == 8 && res[1] == 16 && res[2] == 32);
}

/* A volume mesh with no cells (fig4a at 2 samples a side, or 2 of u and v: every cell collapses) is a
 * document error naming res and what res works, as the skins refuse an empty skin. */
static void empty_volume_meshes_should_be_a_document_error_naming_res(void **state)
{
    (void)state;
    pde_solution *sol = solve_preset("fig4a", NULL);
    const unsigned bad[][3] = { { 2, 2, 2 }, { 2, 2, 64 } };
    const api_format fmts[] = { API_FMT_MSH, API_FMT_VTU };
    for (size_t i = 0; i < 2; i++)
        for (size_t k = 0; k < 2; k++) {
            api_error err;
            api_output *o = api_output_open_ex(sol, NULL, NULL, fmts[i], bad[k], NULL, NULL, &err);
            if (o)
                fail_msg("%s at %u,%u,%u: opened with no cells", api_format_info_of(fmts[i])->name, bad[k][0],
                         bad[k][1], bad[k][2]);
            assert_int_equal(err.status, API_ERR_DOCUMENT);
            if (!strstr(err.message, "res") || !strstr(err.message, "at least 3"))
                fail_msg("%s: %s", api_format_info_of(fmts[i])->name, err.message);
        }
    const unsigned ok[3] = { 3, 4, 3 };   /* 4 along v, which loops (3 are 2 points around it: test_volmesh) */
    for (size_t i = 0; i < 2; i++) {
        size_t len;
        free(render(sol, NULL, fmts[i], ok, &len));
        assert_true(len > 0);
    }
    pde_solution_free(sol);
}

/* Writes the output of f to path. */
static void render_to(const pde_solution *sol, api_format f, const unsigned res[3], const char *path)
{
    size_t len;
    unsigned char *b = render(sol, "abc", f, res, &len);
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(b, 1, len, fp), len);
    fclose(fp);
    free(b);
}

/* det J from core's derivatives at (u, v, w), and x there. */
static double detj_at(const pde_solution *sol, const double uvw[3], double x[3])
{
    double xu[3], xv[3], xw[3];
    pde_eval_d(sol, uvw[0], uvw[1], uvw[2], x, xu, xv, xw);
    return xu[0] * (xv[1] * xw[2] - xv[2] * xw[1]) - xu[1] * (xv[0] * xw[2] - xv[2] * xw[0]) +
           xu[2] * (xv[0] * xw[1] - xv[1] * xw[0]);
}

/*
 * obj, ply, msh and vtu, written through the format table, read back by Debian's python3-meshio: the
 * point and cell counts of the skin (api_mesh) and of the volume mesh (api_volmesh); the volume the skin
 * encloses (divergence theorem) and the sum of the cells' volumes (6 tetrahedra a hexahedron, 3 a wedge;
 * unsigned: the orientation is test_volmesh's)
 * near the solid's; det J in ply (detj), msh and vtu at sample points equal to core's closed form; msh's
 * physical groups. Solids that do not fold, so that the volume is the cells' sum.
 */
static void obj_ply_msh_and_vtu_should_read_back_in_meshio(void **state)
{
    (void)state;
    if (access("/usr/bin/python3", X_OK) || system("/usr/bin/python3 -c 'import meshio' 2>/dev/null"))
        fail_msg("python3-meshio is missing: apt-get install python3-meshio");
    const char *names[] = { "fig1a", "fig2b" };
    for (size_t i = 0; i < 2; i++) {
        pde_solution *sol = solve_preset(names[i], NULL);
        pde_props p;
        assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
        assert_false(p.folds);
        const unsigned sres[3] = { 41, 81, 41 }, vres[3] = { 17, 33, 17 };
        api_mesh m;
        api_volmesh vm;
        assert_int_equal(api_mesh_build(sol, sres, NULL, &m, NULL), 0);
        assert_int_equal(api_volmesh_build(sol, vres, NULL, &vm, NULL), 0);
        char obj[96], ply[96], msh[96], vtu[96], py[96];
        snprintf(obj, sizeof obj, "%s/%s.obj", dir, names[i]);
        snprintf(ply, sizeof ply, "%s/%s.ply", dir, names[i]);
        snprintf(msh, sizeof msh, "%s/%s.msh", dir, names[i]);
        snprintf(vtu, sizeof vtu, "%s/%s.vtu", dir, names[i]);
        snprintf(py, sizeof py, "%s/%s.py", dir, names[i]);
        render_to(sol, API_FMT_OBJ, sres, obj);
        render_to(sol, API_FMT_PLY, sres, ply);
        render_to(sol, API_FMT_MSH, vres, msh);
        render_to(sol, API_FMT_VTU, vres, vtu);
        FILE *f = fopen(py, "w");
        fprintf(f,
                "import meshio, numpy as np\n"
                "def skin(path, nv, nt):\n"
                "    m = meshio.read(path)\n"
                "    assert len(m.points) == nv, (path, len(m.points), nv)\n"
                "    t = m.cells_dict['triangle']\n"
                "    assert len(t) == nt, (path, len(t), nt)\n"
                "    p = m.points[t]\n"
                "    v = np.sum(np.einsum('ij,ij->i', p[:, 0], np.cross(p[:, 1], p[:, 2]))) / 6\n"
                "    assert abs(v - %.17g) <= 5e-3 * %.17g, (path, v)\n"
                "    return m\n"
                "def tets(p, q):\n"
                "    a, b, c, d = (p[:, k] for k in q)\n"
                "    return np.sum(np.abs(np.einsum('ij,ij->i', b - a, np.cross(c - a, d - a)))) / 6\n"
                "def vol(path, hexes, wedges):\n"
                "    m = meshio.read(path)\n"
                "    assert len(m.points) == %zu, (path, len(m.points))\n"
                "    h, w = m.cells_dict.get('hexahedron', []), m.cells_dict.get('wedge', [])\n"
                "    assert len(h) == hexes and len(w) == wedges, (path, len(h), len(w))\n"
                "    v = 0\n"
                "    if len(h):\n"
                "        p = m.points[h]\n"
                "        for q in ((0,1,2,6), (0,2,3,6), (0,3,7,6), (0,7,4,6), (0,4,5,6), (0,5,1,6)):\n"
                "            v += tets(p, q)\n"
                "    if len(w):\n"
                "        p = m.points[w]\n"
                "        for q in ((0,1,2,3), (1,2,3,4), (2,3,4,5)):\n"
                "            v += tets(p, q)\n"
                "    assert abs(abs(v) - %.17g) <= 2e-2 * %.17g, (path, v)\n"
                "    return m\n"
                "def near(m, x):\n"
                "    return np.argmin(np.sum((m.points - x)**2, axis=1))\n"
                "skin('%s', %zu, %zu)\n"
                "P = skin('%s', %zu, %zu)\n"
                "assert P.point_data['detj'].dtype == np.float32\n"
                "M = vol('%s', %zu, %zu)\n"
                "assert {'u0', 'u1', 'v0', 'v1', 'w0', 'w1', 'solid'} <= set(M.field_data), M.field_data\n"
                "V = vol('%s', %zu, %zu)\n",
                fabs(p.signed_volume), fabs(p.signed_volume), vm.npoints, fabs(p.signed_volume),
                fabs(p.signed_volume), obj, m.nverts, m.ntris, ply, m.nverts, m.ntris, msh, vm.nhex, vm.nwedge, vtu,
                vm.nhex, vm.nwedge);
        /* Samples on the skin (w = 0 and 1) and inside, on both grids. */
        const double uvw[4][3] = { { 0.5, 0.25, 0 }, { 0.75, 0.5, 1 }, { 0.25, 0.75, 0 }, { 0.5, 0.5, 0.5 } };
        for (int k = 0; k < 4; k++) {
            double x[3], dj = detj_at(sol, uvw[k], x);
            if (k < 3)
                fprintf(f, "i = near(P, [%.17g, %.17g, %.17g])\n"
                           "assert abs(P.point_data['detj'][i] - %.17g) <= 1e-5 * (1 + abs(%.17g)), ('ply', %d)\n",
                        x[0], x[1], x[2], dj, dj, k);
            fprintf(f, "for X, key in ((M, 'det J'), (V, 'detJ')):\n"
                       "    i = near(X, [%.17g, %.17g, %.17g])\n"
                       "    assert abs(X.point_data[key][i] - %.17g) <= 1e-5 * (1 + abs(%.17g)), (key, %d)\n",
                    x[0], x[1], x[2], dj, dj, k);
        }
        fprintf(f, "print('ok')\n");
        fclose(f);
        char cmd[256];
        snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s", py);
        if (system(cmd) != 0)
            fail_msg("%s: meshio's reading failed (%s)", names[i], py);
        api_mesh_free(&m);
        api_volmesh_free(&vm);
        pde_solution_free(sol);
    }
}

/* A solid far from the origin, whose points overflow float32 but whose derivatives do not (x = 1e39 + u):
 * the formats whose points are doubles (msh, vtu) write it, the others say float32 can't hold its
 * coordinates (msh refused it "beyond the range of float32, in which msh samples them": QA). */
static void points_beyond_float32_should_be_refused_only_where_they_are_float32(void **state)
{
    (void)state;
    const char *doc = "{\"pde\": {\"a\": [1, 1, 1], \"b\": [1, 1, 1], \"c\": [1, 1, 1]}, \"boundary\": {"
                      "\"x\": [{\"w0\": 1e39, \"w1\": 1e39}, {\"u\": {\"pow\": 1}, \"w0\": 1, \"w1\": 1}],"
                      " \"y\": [{\"v\": {\"pow\": 1}, \"w0\": 1, \"w1\": 1}], \"z\": [{\"w1\": 1, \"dw0\": 1, \"dw1\": 1}]}}";
    pde_solution *sol = solve_text(doc);
    api_error err;
    for (int f = 0; f < API_FMT_COUNT; f++) {
        const api_format_info *fi = api_format_info_of((api_format)f);
        const int doubles = f == API_FMT_JSON || f == API_FMT_MSH || f == API_FMT_VTU;
        memset(&err, 0, sizeof err);
        const int refused = api_output_check(sol, (api_format)f, NULL, &err) != 0;
        if (refused == doubles)
            fail_msg("%s: %s", fi->name, refused ? err.message : "not refused");
        if (refused && !strstr(err.message, "coordinates could reach 1e+39, beyond the range of float32"))
            fail_msg("%s: \"%s\"", fi->name, err.message);
    }
    pde_solution_free(sol);
}

/* A solid whose integrals overflow a double (fig. 4a with p0 = 1e100) is a document the client can mend,
 * not an out-of-memory 500: every format that carries the properties says why. */
static void properties_beyond_a_double_should_be_a_document_error(void **state)
{
    (void)state;
    const char *doc = "{\"preset\":\"fig4a\",\"params\":{\"p0\":1e100}}";
    pde_solution *sol = solve_text(doc);
    api_error err;
    for (int f = 0; f < API_FMT_COUNT; f++) {
        const api_format_info *fi = api_format_info_of((api_format)f);
        if (!fi->props)
            continue;
        const unsigned res[3] = { 4, 4, 4 };
        memset(&err, 0, sizeof err);
        api_output *o = api_output_open(sol, NULL, NULL, (api_format)f, res, NULL, &err);
        if (o)
            fail_msg("%s: opened a solid whose integrals overflow", fi->name);
        if (err.status != API_ERR_DOCUMENT || !(strstr(err.message, "too large") || strstr(err.message, "float32")))
            fail_msg("%s: status %d, \"%s\"", fi->name, (int)err.status, err.message);
    }
    pde_solution_free(sol);
}

/* A grid the core refuses (no samples along u, or more than it takes) is the caller's res, a document error
 * that names it, not "out of memory" (api_rows_open dropped pde_grid_create's status: review). */
static void a_grid_the_core_refuses_should_be_a_document_error_naming_res(void **state)
{
    (void)state;
    pde_solution *sol = preset_solution("fig2a");
    static const api_format sampled[] = { API_FMT_GRID, API_FMT_F32, API_FMT_VTS };
    static const unsigned res[][3] = { { 0, 4, 4 }, { 4, 0, 4 }, { (1u << 24) + 1, 1, 1 } };
    for (size_t f = 0; f < sizeof sampled / sizeof *sampled; f++)
        for (size_t i = 0; i < sizeof res / sizeof *res; i++) {
            api_error err;
            memset(&err, 0, sizeof err);
            api_output *o = api_output_open(sol, NULL, NULL, sampled[f], res[i], NULL, &err);
            if (o || err.status != API_ERR_DOCUMENT || strncmp(err.message, "res: ", 5))
                fail_msg("%s at res %u,%u,%u: %s, status %d, \"%s\"", api_format_info_of(sampled[f])->name, res[i][0],
                         res[i][1], res[i][2], o ? "opened" : "refused", (int)err.status, err.message);
            api_output_free(o);
        }
    pde_solution_free(sol);
}

/* The skin's faces u = 0, 1 come from a grid of nu = 2, which fills its planes column-wise (core/eval.c);
 * every bit of it, and of nu = 1, must be what a wide grid gives at the same u. */
static void narrow_grids_should_sample_the_same_bits_as_wide_ones(void **state)
{
    (void)state;
    enum { NV = 19, NW = 5 };
    const double wide[5] = { 0.0, 0.25, 0.5, 0.75, 1.0 }, ends[2] = { 0.0, 1.0 };
    double vs[NV];
    for (int j = 0; j < NV; j++)
        vs[j] = j / (double)(NV - 1);
    for (size_t i = 0; i < paper_figure_count(); i++) {
        pde_solution *sol = solve_preset(paper_figure_name(i), NULL);
        pde_grid *gw, *g2, *g1;
        assert_int_equal(pde_grid_create(sol, wide, 5, vs, NV, &gw), PDE_OK);
        assert_int_equal(pde_grid_create(sol, ends, 2, vs, NV, &g2), PDE_OK);
        assert_int_equal(pde_grid_create(sol, wide + 4, 1, vs, NV, &g1), PDE_OK);
        static float a[4][3 * 5 * NV], b[4][3 * 2 * NV], c[4][3 * NV];
        for (int k = 0; k < NW; k++) {
            const double w = k / (double)(NW - 1);
            pde_grid_plane_d(gw, w, a[0], a[1], a[2], a[3]);
            pde_grid_plane_d(g2, w, b[0], b[1], b[2], b[3]);
            pde_grid_rows(g1, w, 3, NV, c[0] + 9, c[1] + 9, c[2] + 9, c[3] + 9);   /* rows 3.. only */
            pde_grid_rows(g1, w, 0, 3, c[0], c[1], c[2], c[3]);
            for (int q = 0; q < 4; q++)
                for (int j = 0; j < NV; j++) {
                    if (memcmp(&b[q][3 * 2 * j], &a[q][3 * 5 * j], 12) || memcmp(&b[q][3 * (2 * j + 1)], &a[q][3 * (5 * j + 4)], 12))
                        fail_msg("%s: nu = 2 differs at v %d, w %g, quantity %d", paper_figure_name(i), j, w, q);
                    if (memcmp(&c[q][3 * j], &a[q][3 * (5 * j + 4)], 12))
                        fail_msg("%s: nu = 1 differs at v %d, w %g, quantity %d", paper_figure_name(i), j, w, q);
                }
        }
        pde_grid_free(gw);
        pde_grid_free(g2);
        pde_grid_free(g1);
        pde_solution_free(sol);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(properties_beyond_a_double_should_be_a_document_error),
        cmocka_unit_test(a_grid_the_core_refuses_should_be_a_document_error_naming_res),
        cmocka_unit_test(points_beyond_float32_should_be_refused_only_where_they_are_float32),
        cmocka_unit_test(presets_should_carry_the_papers_values),
        cmocka_unit_test(presets_should_be_the_tests_own_transcription),
        cmocka_unit_test(every_preset_should_give_gltf_and_glb_that_the_khronos_validator_passes),
        cmocka_unit_test(gltf_should_carry_the_id_properties_and_exact_bounds),
        cmocka_unit_test(gltf_should_stand_the_height_along_plus_y),
        cmocka_unit_test(glb_should_carry_det_j_as_the_detj_attribute),
        cmocka_unit_test(meshopt_glb_should_be_a_quarter_of_the_plain_one_and_stand_along_plus_y),
        cmocka_unit_test(grid_json_should_read_back_as_the_f32_output),
        cmocka_unit_test(stl_skin_should_be_closed_and_enclose_the_computed_volume),
        cmocka_unit_test(every_skin_should_be_closed_with_normals_and_det_j_from_the_closed_form),
        cmocka_unit_test(narrow_grids_should_sample_the_same_bits_as_wide_ones),
        cmocka_unit_test(mesh_build_should_give_the_same_mesh_in_kept_and_fresh_memory),
        cmocka_unit_test(glb_should_be_the_same_bytes_whatever_the_reader_s_buffer),
        cmocka_unit_test(vts_should_hold_the_points_and_det_j),
        cmocka_unit_test(json_should_hold_the_closed_form_properties_and_id),
        cmocka_unit_test(every_output_with_properties_should_carry_each_of_them_by_name),
        cmocka_unit_test(properties_should_read_back_from_their_tree),
        cmocka_unit_test(id_should_not_depend_on_how_the_model_is_spelled),
        cmocka_unit_test(bad_formats_and_resolutions_should_name_the_limit),
        cmocka_unit_test(obj_ply_msh_and_vtu_should_read_back_in_meshio),
        cmocka_unit_test(empty_volume_meshes_should_be_a_document_error_naming_res),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("output", tests, setup, teardown);
}
