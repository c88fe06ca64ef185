/*
 * catalog.h: the presets and templates as JSON documents, for GET /presets
 * and GET /presets/{name}. Reentrant (cJSON only prints here).
 */
#ifndef API_CATALOG_H
#define API_CATALOG_H

#include <cJSON.h>

#include "template.h"

/* Every number under j in the digits that read back exactly, in place (api_fmt_f64): cJSON prints 15 where
 * they read back within an epsilon, and a document that does not read back exactly would get another id. */
void api_json_exact_numbers(cJSON *j);

/* {"presets": [{"name", "template", "caption"}], "templates": [{"name", "title", "params": [...]}]}; malloc'd. */
char *api_presets_json(void);
/* {"name", "template", "caption", "id", "params": {...}, "model": {...}}; malloc'd, NULL if out of memory. */
char *api_preset_json(const api_preset *ps);

/* A loft preset (loft.h) as {"name", "template": "loft", "caption", "id", "loft": {...}}: its document, which
 * POST /solve takes as {"loft": ...}; NULL if no loft preset has the name. The list above has them too. */
char *api_loft_preset_json(const char *name);

#endif
