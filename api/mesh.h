/*
 * mesh.h: the skin of a solid as a triangle mesh: the six isoparametric
 * faces u, v, w = 0, 1 that the paper draws, made into one closed surface.
 *
 * Faces that collapse to a line or a point (u = 0 of the circular examples)
 * vanish, faces that coincide (v = 0 and v = 1 of a closed loop) cancel, seams
 * are welded, and triangles are wound so that normals point outward (the
 * enclosed volume is positive). Vertices are shared within a face, so normals
 * are smooth across a face and sharp at the creases between faces; weld[]
 * gives each vertex's position id across faces, for formats without normals.
 * Normals and det J come from the closed form's derivatives at each vertex
 * (a collapsed row's point, where the face's tangents vanish, takes the
 * area-weighted normal of its triangles). Seams and collapsed rows are found
 * from the face grids' structure, not by searching positions (mesh.c).
 */
#ifndef API_MESH_H
#define API_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "model.h"
#include "pde.h"

typedef struct {
    size_t nverts, ntris, npos;
    float *pos;        /* 3 nverts */
    float *nrm;        /* 3 nverts, unit length */
    float *detj;       /* nverts: det J = det(x_u, x_v, x_w) at the vertex (<= 0 where the solid folds) */
    uint32_t *tri;     /* 3 ntris, counter-clockwise seen from outside */
    uint32_t *weld;    /* nverts: position id in [0, npos) */
    float min[3], max[3];   /* of pos, exactly */
} api_mesh;

/*
 * res[0..2]: samples along u, v and w on the faces. Returns 0, or -1 with err
 * (out zeroed). cancel (NULL: never) is polled between rows of the faces and
 * every few thousand points or triangles of the later passes; when it stops,
 * everything is freed and err has status API_ERR_CANCELLED. Memory peaks
 * at about 70 bytes per face sample, 6 res^2 samples in all: about 28 MB at
 * res 256 (api/cost.h estimates it); the mesh keeps 56 of them until freed.
 * Vertices come face by face in sample order (u fastest, then v, then w).
 *
 * Thread-safe: builds may run on any threads at once. Their memory is two
 * blocks, the mesh's and a build's scratch, which api_mesh_free and the end
 * of a build keep for the next build (two blocks per process, each at most
 * 64 MB), since fresh pages cost a page fault each.
 */
int api_mesh_build(const pde_solution *sol, const unsigned res[3], const pde_cancel *cancel, api_mesh *out,
                   api_error *err);
/*
 * api_mesh_build's refusal of res 3 along an axis that closes into a loop (api_mesh_loop_message), by the
 * build's own steps (the faces sampled and joined; no triangle, normal or det J): 0, or -1 with err as
 * api_mesh_build's. Only where some res[a] is 3, else 0 at once, as for a flat solid (pde_solution_is_flat:
 * its outputs refuse it first, for having no volume). For a caller with dearer work to do before the build,
 * as the properties of gltf and glb; the build itself then samples the faces again.
 */
int api_mesh_check_loops(const pde_solution *sol, const unsigned res[3], const pde_cancel *cancel, api_error *err);

/* Gives the mesh's block back for the next build; NULL or a zeroed mesh does nothing. */
void api_mesh_free(api_mesh *m);

/* Into buf: why res[axis] = 3 samples will not do along an axis that closes into a loop (its opposite faces
 * meet throughout): 2 points around it, a mesh folded flat onto itself (api_mesh_build, api_volmesh_build). */
void api_mesh_loop_message(int axis, char *buf, size_t n);
/* Frees the blocks kept for the next build (at exit, or to hand memory back to the system). */
void api_mesh_release_spares(void);

#endif
