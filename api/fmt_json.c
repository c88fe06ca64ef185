/*
 * fmt_json.c: the json format: the closed form per component and mode (as a
 * tree and as text), the properties and the id, made whole at open.
 */
#include <stdio.h>
#include <stdlib.h>

#include <cJSON.h>

#include "cost.h"
#include "describe.h"
#include "fmt.h"
#include "jsonparse.h"

static int stopped(const pde_cancel *c)
{
    return c && c->stop && c->stop(c->arg);
}

/* The document is made whole here, into the output's buffer: read copies it out. */
static int json_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    const pde_props *props = api_out_props(o, cancel, err);
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
                return api_out_cancelled(err);
            }
            cJSON *mo = cJSON_CreateObject(), *terms;
            cJSON_AddItemToArray(modes, mo);
            cJSON_AddItemToObject(mo, "u", api_factor_tree(md[m].u));
            cJSON_AddItemToObject(mo, "v", api_factor_tree(md[m].v));
            api_json_add_exact(mo, "e", md[m].e);
            /* A loft's mode is piecewise: "slabs": [{"w": [w0, w1], "h": [...]}] instead of "h". */
            cJSON *slabs = md[m].nslabs > 1 ? cJSON_AddArrayToObject(mo, "slabs") : NULL;
            for (size_t sl = 0; sl < (slabs ? md[m].nslabs : 1); sl++) {
                cJSON *holder = mo;
                if (slabs) {
                    holder = cJSON_CreateObject();
                    cJSON_AddItemToArray(slabs, holder);
                    cJSON_AddItemToObject(holder, "w", api_json_exact_array(md[m].breaks + sl, 2));
                }
                if (!(terms = cJSON_AddArrayToObject(holder, "h")))
                    continue;
                size_t t0 = slabs ? md[m].first[sl] : 0, t1 = slabs ? md[m].first[sl + 1] : md[m].nterms;
                for (size_t t = t0; t < t1; t++) {
                    const pde_wterm *w = &md[m].terms[t];
                    cJSON *to = cJSON_CreateObject();
                    cJSON_AddItemToArray(terms, to);
                    api_json_add_exact(to, "alpha", w->alpha);
                    api_json_add_exact(to, "beta", w->beta);
                    api_json_add_exact(to, "shift", w->shift);
                    cJSON_AddItemToObject(to, "A", api_json_exact_array(w->A, w->deg + 1));
                    cJSON_AddItemToObject(to, "B", api_json_exact_array(w->B, w->deg + 1));
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
    cJSON_AddItemToObject(root, "properties", api_props_tree(props));
    char *s = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    if (!s)
        return -1;
    int rc = api_out_puts(o, s) || api_out_puts(o, "\n");
    free(s);
    o->size = (long long)o->len;
    return rc ? -1 : 0;
}

/* The document is in the buffer from open on. */
static int json_fill(api_output *o)
{
    (void)o;
    return 1;
}

const api_format_info api_format_json = {
    .name = "json", .mime = "application/json", .ext = ".json", .props = 1, .unsampled = 1, .range = API_RANGE_DOUBLES,
    .open = json_open, .fill = json_fill, .cost = api_cost_json,
};
