/*
 * fmt_stl.c: the stl format: binary STL of the closed skin, in the model's
 * frame (z up, as slicers expect), each triangle's normal from its corners.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cost.h"
#include "fmt.h"

static int stl_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    if (api_skin_open(o, cancel, err))
        return -1;
    o->size = 84 + 50LL * (long long)((api_skin *)o->st)->mesh.ntris;
    return 0;
}

static int stl_fill(api_output *o)
{
    api_skin *s = o->st;
    const api_mesh *m = &s->mesh;
    if (s->phase == 0) {
        unsigned char h[84];
        memset(h, ' ', 80);
        int n = snprintf((char *)h, 80, "pdesolid binary STL of the solid %s", o->id);
        if (n > 0 && n < 80)
            h[n] = ' ';
        api_le32(h + 80, (uint32_t)m->ntris);
        s->phase = 1;
        return api_out_put(o, h, 84);
    }
    if (s->k == m->ntris)
        return 1;
    size_t n = m->ntris - s->k < 4096 ? m->ntris - s->k : 4096;
    if (api_out_reserve(o, 50 * n))
        return -1;
    for (size_t t = s->k; t < s->k + n; t++) {
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
        if (api_out_f32(o, rec, 12) || api_out_put(o, "\0\0", 2))
            return -1;
    }
    s->k += n;
    return 0;
}

/* The mesh alone; 25 units a triangle written (cost.c's K_STL). */
static void stl_cost(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, struct api_cost *c)
{
    (void)opts;
    api_cost_skin(sol, res, 0.0, 0.0, 0.0, 25.0, c);
}

const api_format_info api_format_stl = {
    .name = "stl", .mime = "model/stl", .ext = ".stl", .mesh = 1, .binary = 1,
    .open = stl_open, .fill = stl_fill, .close = api_skin_close, .cost = stl_cost,
};
