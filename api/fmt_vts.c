/*
 * fmt_vts.c: the vts format: the sampled volume as a VTK XML StructuredGrid,
 * the points and det J (a point field, from the closed form's derivatives)
 * as raw appended float32, the properties as field data. The header is
 * measured at open, so the size is known before the first byte.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cost.h"
#include "fmt.h"

static int vts_header(api_output *o)
{
    unsigned a = o->res[0] - 1, b = o->res[1] - 1, c = o->res[2] - 1;
    char h[1024];
    int n = snprintf(h, sizeof h,
                     "<?xml version=\"1.0\"?>\n"
                     "<!-- pdesolid: the solid %s, x(u,v,w) at u, v, w = i/(n-1); detJ = det d(x,y,z)/d(u,v,w); "
                     "the field data are its properties (docs/API.md) -->\n"
                     "<VTKFile type=\"StructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
                     "  <StructuredGrid WholeExtent=\"0 %u 0 %u 0 %u\">\n",
                     o->id[0] ? o->id : "(no id)", a, b, c);
    if (api_out_put(o, h, (size_t)n) || api_out_vtk_field_data(o, &o->props))
        return -1;
    n = snprintf(h, sizeof h,
                 "    <Piece Extent=\"0 %u 0 %u 0 %u\">\n"
                 "      <PointData Scalars=\"detJ\">\n"
                 "        <DataArray type=\"Float32\" Name=\"detJ\" NumberOfComponents=\"1\" format=\"appended\" offset=\"%lld\"/>\n"
                 "      </PointData>\n"
                 "      <Points>\n"
                 "        <DataArray type=\"Float32\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>\n"
                 "      </Points>\n"
                 "    </Piece>\n"
                 "  </StructuredGrid>\n"
                 "  <AppendedData encoding=\"raw\">\n   _",
                 a, b, c, 8 + 12 * api_out_points(o));
    return api_out_put(o, h, (size_t)n);
}

static const char vts_footer[] = "\n  </AppendedData>\n</VTKFile>\n";

static int vts_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    if (!api_out_props(o, cancel, err) || api_sampled_open(o, 1, err) || vts_header(o))
        return -1;
    long long n = api_out_points(o);   /* the header measured once, for the size */
    o->size = (long long)o->len + 8 + 12 * n + 8 + 4 * n + (long long)strlen(vts_footer);
    o->len = 0;
    return 0;
}

static int vts_fill(api_output *o)
{
    api_sampled *v = o->st;
    api_rows *r = &v->rows;
    unsigned char len8[8];
    switch (v->phase) {
    case 0:
        v->phase = 1;
        api_le64(len8, (uint64_t)(12 * api_out_points(o)));
        return vts_header(o) || api_out_put(o, len8, 8);
    case 1:
        if (r->k < o->res[2])
            return api_out_f32(o, r->xyz, 3 * api_rows_next(r, o, 0));
        r->k = r->j = 0;
        v->phase = 2;
        api_le64(len8, (uint64_t)(4 * api_out_points(o)));
        return api_out_put(o, len8, 8);
    case 2:
        if (r->k < o->res[2]) {
            size_t n = api_rows_next(r, o, 1);
            for (size_t i = 0; i < n; i++) {
                const float *a = r->xu + 3 * i, *b = r->xv + 3 * i, *c = r->xw + 3 * i;
                double d = (double)a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
                           (double)a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
                           (double)a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
                r->xyz[i] = (float)d;
            }
            return api_out_f32(o, r->xyz, n);
        }
        v->phase = 3;
        return api_out_puts(o, vts_footer);
    }
    return 1;
}

const api_format_info api_format_vts = {
    .name = "vts", .mime = "application/xml", .ext = ".vts", .props = 1, .binary = 1, /* XML around raw float32 */
    .open = vts_open, .fill = vts_fill, .close = api_sampled_close, .cost = api_cost_vts,
};
