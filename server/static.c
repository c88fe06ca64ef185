/*
 * static.c: the front-end's files and the OpenAPI document (internal.h).
 * A fixed table maps URLs to files, so no path from a URL ever reaches the
 * file system. The files are read once at start; the OpenAPI document is
 * linked into the binary (the Makefile's openapi.o), so it is always there.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

#define JS "text/javascript; charset=utf-8"

static const struct {
    const char *url, *file, *type;   /* file: under the web directory, or NULL for the OpenAPI document */
} files[] = {
    { "/", "index.html", "text/html; charset=utf-8" },
    { "/index.html", "index.html", "text/html; charset=utf-8" },
    { "/app.js", "app.js", JS },
    { "/loft.js", "loft.js", JS },
    { "/style.css", "style.css", "text/css; charset=utf-8" },
    { "/openapi.yaml", NULL, "application/yaml; charset=utf-8" },
    { "/vendor/three/three.module.js", "node_modules/three/build/three.module.js", JS },
    { "/vendor/three/three.core.js", "node_modules/three/build/three.core.js", JS },
    { "/vendor/three/addons/loaders/GLTFLoader.js", "node_modules/three/examples/jsm/loaders/GLTFLoader.js", JS },
    { "/vendor/three/addons/utils/BufferGeometryUtils.js",
      "node_modules/three/examples/jsm/utils/BufferGeometryUtils.js", JS },
    { "/vendor/three/addons/utils/SkeletonUtils.js", "node_modules/three/examples/jsm/utils/SkeletonUtils.js", JS },
    { "/vendor/three/addons/controls/OrbitControls.js", "node_modules/three/examples/jsm/controls/OrbitControls.js",
      JS },
    { "/vendor/three/addons/libs/meshopt_decoder.module.js", "node_modules/three/examples/jsm/libs/meshopt_decoder.module.js", JS },
    { "/vendor/lil-gui/lil-gui.esm.js", "node_modules/lil-gui/dist/lil-gui.esm.js", JS },
};
#define NFILES (sizeof files / sizeof *files)

/* docs/openapi.yaml, linked in by `ld -r -b binary`. */
extern const char _binary_docs_openapi_yaml_start[], _binary_docs_openapi_yaml_end[];

struct srv_static {
    char dir[1024];
    char *data[NFILES];
    size_t len[NFILES];
};

int srv_static_find(const char *path)
{
    for (size_t i = 0; i < NFILES; i++)
        if (!strcmp(path, files[i].url))
            return (int)i;
    return -1;
}

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *data = NULL;
    long n;
    if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (data = malloc((size_t)n + 1)))
        *len = fread(data, 1, (size_t)n, f);
    fclose(f);
    return data;
}

srv_static *srv_static_load(const char *dir, char *err, size_t errlen)
{
    srv_static *w = calloc(1, sizeof *w);
    if (!w) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    snprintf(w->dir, sizeof w->dir, "%s", dir);
    for (size_t i = 0; i < NFILES; i++) {
        if (!files[i].file)
            continue;
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", dir, files[i].file);
        w->data[i] = slurp(path, &w->len[i]);
    }
    return w;
}

void srv_static_free(srv_static *w)
{
    if (!w)
        return;
    for (size_t i = 0; i < NFILES; i++)
        free(w->data[i]);
    free(w);
}

void srv_static_get(srv_req *r)
{
    int i = srv_static_find(r->path);
    srv_static *w = r->s->web;
    if (files[i].file && !w->data[i]) {
        srv_problem(r, 404, NULL, "%s is not installed in %s; run `make run`", files[i].file, w->dir);
        return;
    }
    r->status = 200;
    r->ctype = files[i].type;
    r->ref = files[i].file ? w->data[i] : _binary_docs_openapi_yaml_start;
    r->ref_len = files[i].file ? w->len[i] : (size_t)(_binary_docs_openapi_yaml_end - _binary_docs_openapi_yaml_start);
}
