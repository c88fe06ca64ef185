/*
 * fmt_msh.c: the msh format: the solid as a Gmsh 4.1 (ASCII) volume mesh of
 * hexahedra and wedges (api/volmesh.h): physical groups for the six faces
 * u0 ... w1 and the volume, det J per element as element data. Samples per
 * axis as the grid formats take them; the size is known only at the end.
 */
#include <stdlib.h>

#include "cost.h"
#include "fmt.h"

static int msh_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    api_vol *s = calloc(1, sizeof *s);
    o->st = s;
    return s ? api_out_volmesh(o, cancel, &s->mesh, err) : -1;
}

static int msh_fill(api_output *o)
{
    api_vol *s = o->st;
    if (s->done)
        return 1;
    int r = api_volmesh_msh_piece(&s->mesh, NULL, &s->cur, api_vol_put, o);
    s->done = r == 1;
    return r < 0 ? -1 : 0;
}

/* About 60 bytes of text a point (its node line and node data), 80 a cell (its element line and element
 * data): measured about 1.6 us a point in all (fig1a at res 80: 1.02 s, of which 0.27 s the build). */
static void msh_cost(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, struct api_cost *c)
{
    (void)opts;
    api_cost_volmesh(sol, res, 1750.0, c);
}

const api_format_info api_format_msh = {
    .name = "msh", .mime = "text/plain", .ext = ".msh", .range = API_RANGE_DETJ, .mesh = 0,
    .open = msh_open, .fill = msh_fill, .close = api_vol_close, .cost = msh_cost,
};
