/*
 * volmesh.h: the solid as a volume mesh for FEA: hexahedra (and wedges where
 * the parametrisation collapses), written as Gmsh 4.1 (.msh) or VTK XML
 * UnstructuredGrid (.vtu).
 *
 *   api_volmesh m;
 *   api_error err;
 *   unsigned res[3] = { 32, 32, 32 };
 *   if (api_volmesh_build(sol, res, NULL, &m, &err) != 0)
 *       report(err);
 *   api_volmesh_cursor c = { 0, 0 };
 *   int r;
 *   while ((r = api_volmesh_msh_piece(&m, &props, &c, put, ctx)) == 0)
 *       ;                                  // r == 1: done, r == -1: put failed
 *   api_volmesh_free(&m);
 *
 * api_volmesh_build reads the solution only and the writers read the mesh only (const): any number
 * may run at once on different threads. On failure build frees what it made, fills err (422 for a bad
 * res, 503 "cancelled" when cancel stopped it) and leaves *out untouched. api_volmesh_free accepts a
 * zeroed mesh and NULL. Writers cannot fail but through put; props NULL writes no metadata.
 *
 * CHOICES
 * - Samples u_i = i / (res[0] - 1) (likewise v, w), evaluated with pde_eval_d.
 * - Merging uses the grid, not a spatial hash: on each face of the cube, along
 *   each of its two axes, if every line of samples along that axis coincides
 *   (within API_VOLMESH_TOL of the solid's extent, which absorbs sin 2 pi != 0),
 *   the line becomes one node (u = 0 of the circular examples). If the faces
 *   a = 0 and a = 1 coincide sample by sample (a periodic seam, v of a closed
 *   loop), a = 1 is merged into a = 0.
 * - A cell with 8 distinct nodes is a hexahedron; one whose two parallel edges
 *   of one face collapse (6 distinct nodes) is a wedge; any other degenerate
 *   cell (fewer nodes: an axis collapsing to a point) has no volume and is
 *   dropped.
 * - Node order is VTK's (hex: 0-3 the w-bottom face counter-clockwise seen
 *   from the top, 4-7 above; wedge: (0,1,2) wound with its normal away from
 *   (3,4,5)); the msh writer converts the wedge to Gmsh's prism order. Cells
 *   are oriented by the sign of the sum of det J over the samples: if the
 *   parametrisation is left-handed they are mirrored, so that every cell where
 *   sign * det J > 0 has positive volume. detj and cell_detj keep det J's own
 *   sign.
 * - fold: sign * det J <= 0 at the cell's centre, or below -1e-9 of the
 *   largest |det J| at one of its nodes (det J = 0 at a collapsed node is
 *   expected and not a fold).
 * - face_quads: the skin of each face, wound outward; a face merged into its
 *   opposite (a seam) lies inside and has none.
 * - At most API_VOLMESH_MAX_CELLS cells (res's product of (res - 1)).
 */
#ifndef API_VOLMESH_H
#define API_VOLMESH_H

#include <stddef.h>
#include <stdint.h>

#include "pde.h"
#include "model.h"

#define API_VOLMESH_MAX_CELLS ((size_t)1 << 22)
#define API_VOLMESH_TOL 1e-12

typedef struct {
    size_t npoints, ncells;
    double *pos;            /* 3 per point */
    float *detj;            /* det J per point, from the closed form's derivatives */
    uint32_t *conn;         /* 8 per cell; a wedge uses the first 6, the rest UINT32_MAX */
    unsigned char *type;    /* API_CELL_HEX (8 nodes) or API_CELL_WEDGE (6 nodes), per cell */
    float *cell_detj;       /* det J at each cell's parametric centre */
    unsigned char *fold;    /* 1 where det J <= 0 somewhere on the cell's nodes or centre */
    size_t nfolded;
    /* the skin, for physical groups: quads (4 per quad, a degenerate quad as a triangle: the 4th
     * UINT32_MAX) of each of the six faces u=0, u=1, v=0, v=1, w=0, w=1; a face that collapses
     * to a line or point has none */
    uint32_t *face_quads[6];
    size_t face_nquads[6];
    /* added */
    size_t nhex, nwedge;
    int sign;               /* +1, or -1 for a left-handed parametrisation */
} api_volmesh;
enum { API_CELL_HEX = 12, API_CELL_WEDGE = 13 };   /* VTK's cell type numbers */

/* res: samples per axis (u, v, w), at least 2 each; bounded by the caller. cancel polled per slab. */
int api_volmesh_build(const pde_solution *s, const unsigned res[3], const pde_cancel *cancel,
                      api_volmesh *out, api_error *err);   /* 0, or -1 with err */
void api_volmesh_free(api_volmesh *m);

/* Streaming writers: each call appends the next piece (at most about 1 MB) through put(ctx, p, n)
 * (which returns 0, or -1 out of memory), and returns 1 at the end, 0 while there is more, -1 on
 * a put failure. props (may be NULL) goes into the file as metadata where the format allows
 * (vtu: FieldData; msh: ignored). */
typedef struct { int phase; size_t k; } api_volmesh_cursor;
typedef int (*api_volmesh_put)(void *ctx, const void *p, size_t n);
int api_volmesh_msh_piece(const api_volmesh *m, const pde_props *props, api_volmesh_cursor *c,
                          api_volmesh_put put, void *ctx);
int api_volmesh_vtu_piece(const api_volmesh *m, const pde_props *props, api_volmesh_cursor *c,
                          api_volmesh_put put, void *ctx);

#endif
