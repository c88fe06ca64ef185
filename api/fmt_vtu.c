/*
 * fmt_vtu.c: the vtu format: the solid as a VTK XML UnstructuredGrid of
 * hexahedra and wedges (api/volmesh.h), det J as point data, det J at each
 * cell's centre and a per-cell fold flag as cell data, the properties as
 * field data. Samples per axis as the grid formats take them.
 */
#include <stdlib.h>

#include "cost.h"
#include "fmt.h"

static int vtu_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    api_vol *s = calloc(1, sizeof *s);
    o->st = s;
    if (!s || !api_out_props(o, cancel, err))
        return -1;
    return api_out_volmesh(o, cancel, &s->mesh, err);
}

static int vtu_fill(api_output *o)
{
    api_vol *s = o->st;
    if (s->done)
        return 1;
    int r = api_volmesh_vtu_piece(&s->mesh, &o->props, &s->cur, api_vol_put, o);
    s->done = r == 1;
    return r < 0 ? -1 : 0;
}

/* Raw binary: about 28 bytes a point and 80 a cell, copied at well under a unit a byte. */
static void vtu_cost(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, struct api_cost *c)
{
    (void)opts;
    api_cost_volmesh(sol, res, 40.0, c);
}

const api_format_info api_format_vtu = {
    .name = "vtu", .mime = "application/xml", .ext = ".vtu", .range = API_RANGE_DETJ, .props = 1, .binary = 1,
    .open = vtu_open, .fill = vtu_fill, .close = api_vol_close, .cost = vtu_cost,
};
