/*
 * fmt.h: what a format's file (api/fmt_*.c) sees of an output: the stream's
 * common state and the helpers the formats share. Not for callers outside
 * api/; they use output.h.
 *
 * A FORMAT is one api_format_info (output.h), defined in its own file and
 * named by one row of formats.def. Its callbacks:
 *
 *   open(o, cancel, err)  does the long work (a mesh, the properties, a whole
 *                         document), polling cancel; keeps what it made in
 *                         o->st and sets o->size when the total is known
 *                         (size first: a writer measures before it writes).
 *                         0, or -1 with err (left empty: out of memory).
 *   fill(o)               appends the next bounded piece to o->buf (through
 *                         api_out_put and friends): 0 while there is more,
 *                         1 at the end (having appended nothing or the last
 *                         piece), -1 out of memory. o->buf is empty on entry.
 *                         Where o->dst is not NULL, fill may instead write
 *                         its piece straight into the reader's buffer: at
 *                         most o->dst_max bytes at o->dst, their count in
 *                         o->dst_len, appending nothing to o->buf (it saves
 *                         the copy from o->buf; the glb's blob does this).
 *   close(st)             frees o->st (NULL: nothing to free).
 *   cost(sol, res, opts, c)  api_cost_output's estimate of open and read.
 *
 * open is called once, then fill until it returns 1, then close once, also
 * after a failed open (with whatever st holds).
 */
#ifndef API_FMT_H
#define API_FMT_H

#include <stddef.h>
#include <stdint.h>

#include "id.h"
#include "mesh.h"
#include "output.h"
#include "volmesh.h"

struct api_output {
    const api_format_info *fmt;
    api_output_opts opts;
    const pde_solution *sol;
    char id[API_ID_LEN + 1];       /* "" when none */
    unsigned res[3];
    long long size;                /* -1 until known */
    char *buf;                     /* the current piece: buf[pos, len) is unread */
    size_t len, pos, cap;
    char *dst;                     /* during fill: the reader's buffer, or NULL (see fill above) */
    size_t dst_max, dst_len;
    pde_props props;
    int have_props;
    void *st;                      /* the format's own state */
};

/* Appending to o->buf; each returns 0, or -1 out of memory. */
int api_out_reserve(api_output *o, size_t n);
int api_out_put(api_output *o, const void *p, size_t n);
int api_out_puts(api_output *o, const char *s);
int api_out_f32(api_output *o, const float *f, size_t n);    /* n floats, little-endian */
void api_le32(unsigned char *p, uint32_t v);
void api_le64(unsigned char *p, uint64_t v);

/* The caller's properties, or computed now; NULL with err when cancelled or when they overflow a double (a document
 * error), NULL (err untouched) when out of memory. */
const pde_props *api_out_props(api_output *o, const pde_cancel *cancel, api_error *err);
/* -1 with err set to API_ERR_CANCELLED. */
int api_out_cancelled(api_error *err);

/* The properties as VTK FieldData, one array per property named group_name ("detJ_min_at"), through
 * put(ctx, ...) (0, or -1 when put fails): the one writer of them, for vts and vtu alike. */
int api_vtk_field_data(const pde_props *p, api_volmesh_put put, void *ctx);
int api_out_vtk_field_data(api_output *o, const pde_props *p);   /* the same into o->buf */

/* ---- grids sampled a few rows at a time (grid, f32, vts) ---- */

typedef struct {
    pde_grid *grid;
    float *xyz, *xu, *xv, *xw;     /* one chunk's samples (and derivatives) */
    size_t chunk, j, k;            /* rows per chunk; the next row and plane */
} api_rows;

/* A grid format's state: its rows and where it is (phase, first, c as the format likes). */
typedef struct {
    api_rows rows;
    int phase, first, c;
} api_sampled;

/* o->st as a new api_sampled, its rows set up; 0, or -1 with err (api_rows_open's). */
int api_sampled_open(api_output *o, int derivs, api_error *err);
void api_sampled_close(void *st);

/* Sets up o->res's sampling tables, with derivatives or not; 0, or -1 with err: out of memory, or the core's
 * refusal of the grid (pde_grid_create's status, as api_status_of maps it; a document error naming res). */
int api_rows_open(api_rows *r, const api_output *o, int derivs, api_error *err);
/* The next chunk of rows; returns the number of points (0 when every plane is done). */
size_t api_rows_next(api_rows *r, const api_output *o, int derivs);
void api_rows_free(api_rows *r);
long long api_out_points(const api_output *o);

/* ---- skins (gltf, glb, stl, obj, ply) ---- */

/* Builds the skin at o->res; 0, or -1 with err (a skin with no triangles is a document error). */
int api_out_mesh(api_output *o, const pde_cancel *cancel, api_mesh *m, api_error *err);

/* A skin format's state: the mesh and where it is (the next vertex or triangle k, in phase). */
typedef struct {
    api_mesh mesh;
    int phase;
    size_t k;
} api_skin;

/* o->st as a new api_skin with the skin built (api_out_mesh); 0, or -1 with err. */
int api_skin_open(api_output *o, const pde_cancel *cancel, api_error *err);
void api_skin_close(void *st);

/* ---- volume meshes (msh, vtu) ---- */

typedef struct {
    api_volmesh mesh;
    api_volmesh_cursor cur;
    int done;           /* the writer returned 1 */
} api_vol;

/* Builds the volume mesh at o->res into *m; 0, or -1 with err (a mesh with no cells is a document error
 * naming res, *m then empty). */
int api_out_volmesh(api_output *o, const pde_cancel *cancel, api_volmesh *m, api_error *err);
void api_vol_close(void *st);                          /* frees an api_vol */
int api_vol_put(void *ctx, const void *p, size_t n);   /* the writers' put: ctx is the api_output */

/* ---- size-first text ---- */

/*
 * A writer in cgltf_write's manner: with buf NULL it only counts, so one
 * function both measures a text and writes it into a buffer of that size.
 */
typedef struct {
    char *buf;          /* NULL: count only */
    size_t cap, need;   /* need: bytes the text takes so far (without a NUL) */
} api_sw;

void api_sw_printf(api_sw *w, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void api_sw_puts(api_sw *w, const char *s);

#endif
