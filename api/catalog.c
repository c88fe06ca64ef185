/*
 * catalog.c: presets and templates as JSON (catalog.h).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "catalog.h"
#include "id.h"
#include "jsonparse.h"
#include "loft.h"

char *api_presets_json(void)
{
    cJSON *root = cJSON_CreateObject(), *list = cJSON_AddArrayToObject(root, "presets");
    for (size_t i = 0; list && i < api_preset_count(); i++) {
        const api_preset *p = api_preset_at(i);
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToArray(list, o);
        cJSON_AddStringToObject(o, "name", p->name);
        cJSON_AddStringToObject(o, "template", p->template);
        cJSON_AddStringToObject(o, "caption", p->caption);
    }
    for (size_t i = 0; list && i < api_loft_preset_count(); i++) {
        const char *caption, *name = api_loft_preset_name(i, &caption);
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToArray(list, o);
        cJSON_AddStringToObject(o, "name", name);
        cJSON_AddStringToObject(o, "template", "loft");
        cJSON_AddStringToObject(o, "caption", caption);
    }
    cJSON *tl = cJSON_AddArrayToObject(root, "templates");
    for (size_t i = 0; tl && i < api_template_count(); i++) {
        const api_template *t = api_template_at(i);
        cJSON *o = cJSON_CreateObject(), *ps;
        cJSON_AddItemToArray(tl, o);
        cJSON_AddStringToObject(o, "name", api_template_name(t));
        cJSON_AddStringToObject(o, "title", api_template_title(t));
        ps = cJSON_AddArrayToObject(o, "params");
        size_t n;
        const api_param_info *info = api_template_params(t, &n);
        for (size_t k = 0; ps && k < n; k++) {
            cJSON *q = cJSON_CreateObject();
            cJSON_AddItemToArray(ps, q);
            cJSON_AddStringToObject(q, "name", info[k].name);
            cJSON_AddNumberToObject(q, "size", info[k].slots);
            cJSON_AddStringToObject(q, "help", info[k].help);
        }
    }
    char *s = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    return s;
}

char *api_preset_json(const api_preset *ps)
{
    const api_template *t = api_preset_template(ps);
    api_params p;
    api_preset_params(ps, &p);
    api_error err;
    api_model *m = api_template_expand(t, &p, &err);
    cJSON *model = m ? api_model_tree(api_model_get(m)) : NULL;   /* no cJSON_Parse: it writes a global */
    char id[API_ID_LEN + 1] = "";
    if (m)
        api_model_id(api_model_get(m), id, NULL);
    api_model_free(m);
    cJSON *root = cJSON_CreateObject(), *params = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "name", ps->name);
    cJSON_AddStringToObject(root, "template", ps->template);
    cJSON_AddStringToObject(root, "caption", ps->caption);
    cJSON_AddStringToObject(root, "id", id);
    size_t n;
    const api_param_info *info = api_template_params(t, &n);
    for (size_t k = 0; k < n; k++) {
        double v[3];
        int slots = api_params_get(t, &p, info[k].name, v);
        cJSON_AddItemToObject(params, info[k].name, slots == 3 ? api_json_exact_array(v, 3) : api_json_exact(v[0]));
    }
    cJSON_AddItemToObject(root, "params", params);
    cJSON_AddItemToObject(root, "model", model ? model : cJSON_CreateNull());
    char *s = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    return s;
}

void api_json_exact_numbers(cJSON *j)
{
    for (cJSON *c = j->child, *next; c; c = next) {
        next = c->next;
        if (cJSON_IsNumber(c)) {
            cJSON *raw = api_json_exact(c->valuedouble + 0.0);
            if (raw && c->string)
                cJSON_ReplaceItemInObjectCaseSensitive(j, c->string, raw);   /* keeps the key */
            else if (raw)
                cJSON_ReplaceItemViaPointer(j, c, raw);
        } else
            api_json_exact_numbers(c);
    }
}

char *api_loft_preset_json(const char *name)
{
    cJSON *doc = api_loft_preset_tree(name);
    if (!doc)
        return NULL;
    const char *caption = "";
    for (size_t i = 0; i < api_loft_preset_count(); i++)
        if (!strcmp(api_loft_preset_name(i, &caption), name))
            break;
    char id[API_ID_LEN + 1] = "";
    api_error err;
    api_loft *l = api_loft_parse(cJSON_GetObjectItemCaseSensitive(doc, "loft"), "/loft", &err);
    if (l)
        api_loft_id(api_loft_get(l), id);
    api_loft_free(l);
    cJSON *loft = cJSON_DetachItemFromObjectCaseSensitive(doc, "loft");
    cJSON_Delete(doc);
    if (loft)
        api_json_exact_numbers(loft);
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "name", name);
    cJSON_AddStringToObject(root, "template", "loft");
    cJSON_AddStringToObject(root, "caption", caption);
    cJSON_AddStringToObject(root, "id", id);
    cJSON_AddItemToObject(root, "loft", loft);
    char *s = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    return s;
}
