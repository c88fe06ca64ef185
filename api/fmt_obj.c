/*
 * fmt_obj.c: the obj format: Wavefront OBJ text of the closed skin in the
 * model's frame (z up, metres), a normal per vertex ("vn", the closed form's)
 * and triangles "f a//a b//b c//c" wound counter-clockwise seen from outside.
 * Vertices at the creases between faces appear once per face, with that
 * face's normal (mesh.h). Numbers are float32's shortest digits.
 */
#include <stdio.h>
#include <stdlib.h>

#include "cost.h"
#include "fmt.h"
#include "numfmt.h"

#define OBJ_ROWS 4096    /* vertices or triangles a piece */

/* The skin's phases: 0 the header, 1 v, 2 vn, 3 f. */
static int obj_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    return api_skin_open(o, cancel, err);
}

/* "tag x y z\n" for OBJ_ROWS rows of v from s->k. */
static int triples(api_output *o, api_skin *s, const char *tag, const float *v)
{
    size_t n = s->mesh.nverts - s->k < OBJ_ROWS ? s->mesh.nverts - s->k : OBJ_ROWS;
    if (api_out_reserve(o, n * (3 * (API_F32_MAX + 1) + 4)))
        return -1;
    char *p = o->buf + o->len;
    for (size_t i = s->k; i < s->k + n; i++) {
        for (const char *t = tag; *t; t++)
            *p++ = *t;
        for (int c = 0; c < 3; c++) {
            *p++ = ' ';
            p += api_fmt_f32(p, v[3 * i + c]);
        }
        *p++ = '\n';
    }
    o->len = (size_t)(p - o->buf);
    s->k += n;
    return 0;
}

static int obj_fill(api_output *o)
{
    api_skin *s = o->st;
    const api_mesh *m = &s->mesh;
    if (s->phase == 0) {
        char h[256];
        int n = snprintf(h, sizeof h,
                         "# pdesolid: the closed skin of the solid %s, metres, z up; %zu vertices, %zu triangles\n",
                         o->id[0] ? o->id : "(no id)", m->nverts, m->ntris);
        s->phase = 1;
        return api_out_put(o, h, (size_t)n);
    }
    if ((s->phase == 1 || s->phase == 2) && s->k == m->nverts)
        s->phase++, s->k = 0;
    if (s->phase == 1)
        return triples(o, s, "v", m->pos);
    if (s->phase == 2)
        return triples(o, s, "vn", m->nrm);
    if (s->phase == 3 && s->k < m->ntris) {
        size_t n = m->ntris - s->k < OBJ_ROWS ? m->ntris - s->k : OBJ_ROWS;
        if (api_out_reserve(o, n * 72 + 1))
            return -1;
        char *p = o->buf + o->len;
        for (size_t t = s->k; t < s->k + n; t++) {
            const uint32_t *v = m->tri + 3 * t;
            p += sprintf(p, "f %lu//%lu %lu//%lu %lu//%lu\n", (unsigned long)v[0] + 1, (unsigned long)v[0] + 1,
                         (unsigned long)v[1] + 1, (unsigned long)v[1] + 1, (unsigned long)v[2] + 1,
                         (unsigned long)v[2] + 1);
        }
        o->len = (size_t)(p - o->buf);
        s->k += n;
        return 0;
    }
    return 1;
}

/* The mesh, then text: six numbers a vertex at about 17 units each (cost.c's K_FMT_F32), about half a
 * vertex a triangle, and about 100 units a face line. */
static void obj_cost(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, struct api_cost *c)
{
    (void)opts;
    api_cost_skin(sol, res, 0.0, 0.0, 0.0, 100.0 + 6.0 * 17.0 / 2.0, c);
}

const api_format_info api_format_obj = {
    .name = "obj", .mime = "model/obj", .ext = ".obj", .mesh = 1,
    .open = obj_open, .fill = obj_fill, .close = api_skin_close, .cost = obj_cost,
};
