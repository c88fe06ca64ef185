/*
 * fmt_f32.c: the f32 format: little-endian float32 x, y, z per sample, u
 * fastest, then v, then w (the grid format's order), 12 bytes a point.
 */
#include <stdlib.h>

#include "cost.h"
#include "fmt.h"

static int f32_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    (void)cancel;
    o->size = 12 * api_out_points(o);
    return api_sampled_open(o, 0, err);
}

static int f32_fill(api_output *o)
{
    api_rows *r = &((api_sampled *)o->st)->rows;
    size_t n = api_rows_next(r, o, 0);
    return n ? api_out_f32(o, r->xyz, 3 * n) : 1;
}

const api_format_info api_format_f32 = {
    .name = "f32", .mime = "application/octet-stream", .ext = ".f32", .binary = 1, .range = API_RANGE_POINTS,
    .open = f32_open, .fill = f32_fill, .close = api_sampled_close, .cost = api_cost_f32,
};
