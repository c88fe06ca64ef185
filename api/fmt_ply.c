/*
 * fmt_ply.c: the ply format: binary little-endian PLY 1.0 of the closed skin
 * in the model's frame (z up, metres): per vertex x, y, z, the normal nx,
 * ny, nz and det J as the float property detj; triangles as lists of three
 * uint indices, wound counter-clockwise seen from outside. The header is
 * made at open, so the size is known.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cost.h"
#include "fmt.h"

#define PLY_ROWS 16384   /* vertices or triangles a piece */

/* The header, size-first: with buf NULL (n 0) it only measures. */
static int ply_header(char *buf, size_t n, const api_output *o, const api_mesh *m)
{
    return snprintf(buf, n,
                    "ply\nformat binary_little_endian 1.0\n"
                    "comment pdesolid: the closed skin of the solid %s, metres, z up; detj = det d(x,y,z)/d(u,v,w)\n"
                    "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
                    "property float nx\nproperty float ny\nproperty float nz\nproperty float detj\n"
                    "element face %zu\nproperty list uchar uint vertex_indices\nend_header\n",
                    o->id[0] ? o->id : "(no id)", m->nverts, m->ntris);
}

/* Phases: 0 the header, 1 the vertices, 2 the faces. */
static int ply_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    if (api_skin_open(o, cancel, err))
        return -1;
    const api_mesh *m = &((api_skin *)o->st)->mesh;
    o->size = (long long)ply_header(NULL, 0, o, m) + 28LL * (long long)m->nverts + 13LL * (long long)m->ntris;
    return 0;
}

static int ply_fill(api_output *o)
{
    api_skin *s = o->st;
    const api_mesh *m = &s->mesh;
    if (s->phase == 0) {
        s->phase = 1;
        int n = ply_header(NULL, 0, o, m);
        if (api_out_reserve(o, (size_t)n + 1))
            return -1;
        o->len += (size_t)ply_header(o->buf + o->len, (size_t)n + 1, o, m);
        return 0;
    }
    if (s->phase == 1 && s->k == m->nverts)
        s->phase = 2, s->k = 0;
    if (s->phase == 1) {
        size_t n = m->nverts - s->k < PLY_ROWS ? m->nverts - s->k : PLY_ROWS;
        for (size_t i = s->k; i < s->k + n; i++) {
            float rec[7] = { m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2], m->nrm[3 * i], m->nrm[3 * i + 1],
                             m->nrm[3 * i + 2], m->detj[i] };
            if (api_out_f32(o, rec, 7))
                return -1;
        }
        s->k += n;
        return 0;
    }
    if (s->k == m->ntris)
        return 1;
    size_t n = m->ntris - s->k < PLY_ROWS ? m->ntris - s->k : PLY_ROWS;
    if (api_out_reserve(o, 13 * n))
        return -1;
    unsigned char *p = (unsigned char *)o->buf + o->len;
    for (size_t t = s->k; t < s->k + n; t++, p += 13) {
        p[0] = 3;
        for (int c = 0; c < 3; c++)
            api_le32(p + 1 + 4 * c, m->tri[3 * t + c]);
    }
    o->len += 13 * n;
    s->k += n;
    return 0;
}

/* The mesh, then about 28 bytes a vertex and 13 a triangle copied. */
static void ply_cost(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, struct api_cost *c)
{
    (void)opts;
    api_cost_skin(sol, res, 0.0, 0.0, 0.0, 10.0, c);
}

const api_format_info api_format_ply = {
    .name = "ply", .mime = "application/octet-stream", .ext = ".ply", .mesh = 1, .binary = 1,
    .open = ply_open, .fill = ply_fill, .close = api_skin_close, .cost = ply_cost,
};
