/*
 * fmt_grid.c: the grid format: {"resolution": [nu, nv, nw], "x": [...],
 * "y": [...], "z": [...]}, u fastest, then v, then w, at float32's shortest
 * digits; sampled a few rows at a time, once per component.
 */
#include <stdio.h>
#include <stdlib.h>

#include "cost.h"
#include "fmt.h"
#include "numfmt.h"

static int grid_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    (void)cancel;
    return api_sampled_open(o, 0, err);
}

static int grid_fill(api_output *o)
{
    static const char *const open[3] = { "],\"x\":[", "],\"y\":[", "],\"z\":[" };
    api_sampled *g = o->st;
    if (g->phase == 0) {
        char head[96];
        snprintf(head, sizeof head, "{\"resolution\":[%u,%u,%u],\"x\":[", o->res[0], o->res[1], o->res[2]);
        g->phase = 1;
        g->first = 1;
        return api_out_puts(o, head);
    }
    if (g->phase == 2)
        return 1;
    if (g->rows.k == o->res[2]) {
        g->rows.k = g->rows.j = 0;
        g->first = 1;
        if (++g->c == 3) {
            g->phase = 2;
            return api_out_puts(o, "]}\n");
        }
        return api_out_puts(o, open[g->c]);
    }
    size_t n = api_rows_next(&g->rows, o, 0);
    if (api_out_reserve(o, n * (API_F32_MAX + 1)))
        return -1;
    char *p = o->buf + o->len;
    for (size_t i = 0; i < n; i++) {
        if (!g->first)
            *p++ = ',';
        g->first = 0;
        p += api_fmt_f32(p, g->rows.xyz[3 * i + g->c]);
    }
    o->len = (size_t)(p - o->buf);
    return 0;
}

const api_format_info api_format_grid = {
    .name = "grid", .mime = "application/json", .ext = ".grid.json", .range = API_RANGE_POINTS,
    .open = grid_open, .fill = grid_fill, .close = api_sampled_close, .cost = api_cost_grid_json,
};
