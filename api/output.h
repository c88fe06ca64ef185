/*
 * output.h: a solution as bytes for a client, in any of the formats, as a
 * stream that is read in pieces of any size in bounded memory (the server
 * hands it to libmicrohttpd's content callback; the CLI to a file).
 *
 * The formats are a table: formats.def lists them, one row each, and each
 * is defined in its own file, api/fmt_NAME.c (docs/API.md describes them):
 *
 *   json  the closed form per component and mode, the properties and the id
 *   grid  {"resolution": [nu, nv, nw], "x": [...], "y": [...], "z": [...]},
 *         u fastest, then v, then w, sampled at i/(n-1), float32 digits
 *   f32   little-endian float32 x, y, z per point, in the same order
 *   gltf  glTF 2.0 of the closed skin (+Y up), the buffer in a base64 data URI
 *   glb   the same as binary glTF
 *   vts   the volume as a VTK XML StructuredGrid with det J as a point field,
 *         the properties as field data
 *   stl   binary STL of the closed skin
 *   obj   Wavefront OBJ text of the closed skin, with normals
 *   ply   binary little-endian PLY of the closed skin: normals and det J per vertex
 *   msh   Gmsh 4.1 hexahedral volume mesh (api/volmesh.h)
 *   vtu   the same as a VTK XML UnstructuredGrid
 *
 * A new format is one file that defines its api_format_info and one row in
 * formats.def; the server, the CLI and GET /formats read the table.
 *
 * USAGE
 *
 *   api_output *o = api_output_open(sol, id, NULL, API_FMT_GLB, res, NULL, &err);
 *   long n;
 *   while ((n = api_output_read(o, buf, sizeof buf)) > 0) fwrite(buf, 1, n, f);
 *   api_output_free(o);
 *
 *   api_output_opts opts = { .compress = API_COMPRESS_MESHOPT };   // gltf, glb only
 *   o = api_output_open_ex(sol, id, NULL, API_FMT_GLB, res, &opts, NULL, &err);
 *
 * The output reads the solution, which must outlive it. Outputs are
 * independent of one another and may be read on different threads.
 */
#ifndef API_OUTPUT_H
#define API_OUTPUT_H

#include <stddef.h>
#include <stdio.h>

#include "model.h"
#include "pde.h"

/* API_FMT_JSON, API_FMT_GLB, ... in formats.def's order, and API_FMT_COUNT, counted by the list. */
typedef enum {
#define API_FORMAT(id, entry) API_FMT_##id,
#include "formats.def"
#undef API_FORMAT
    API_FMT_COUNT
} api_format;

/* Compression of a format that takes it (api_format_info.compress). */
typedef enum {
    API_COMPRESS_NONE = 0,  /* as the format is */
    API_COMPRESS_MESHOPT,   /* gltf, glb: EXT_meshopt_compression with KHR_mesh_quantization */
} api_compress;

/* Options of api_output_open_ex(); a zeroed struct (or NULL) is every default. */
typedef struct {
    api_compress compress;
} api_output_opts;

typedef struct api_output api_output;
struct api_cost;

/* What of the solid a format writes as float32, which api_output_open() checks fits (a zero column: all). */
typedef enum {
    API_RANGE_DERIVS = 0,   /* the coordinates and products of derivatives: normals, det J (skins, volumes) */
    API_RANGE_POINTS,       /* the coordinates only (grid, f32) */
    API_RANGE_DETJ,         /* det J only: the points are doubles (msh, vtu) */
    API_RANGE_DOUBLES,      /* doubles only (json: its properties refuse what overflows a double) */
} api_range;

typedef struct api_format_info {
    const char *name;      /* as in ?format= and --format */
    const char *mime;
    const char *ext;       /* file extension, with the dot */
    int mesh;              /* resolution per face edge rather than per volume axis */
    int props;             /* carries the properties: api_output_open() computes them when not given */
    int binary;            /* bytes that are not text: not written to a terminal */
    int compress;          /* takes compress=meshopt */
    int unsampled;         /* writes no samples: res is taken and ignored (api_res_parse gives the default) */
    api_range range;       /* what must fit float32 */
    /* The stream (api/fmt.h says what each does). */
    int (*open)(api_output *o, const pde_cancel *cancel, api_error *err);
    int (*fill)(api_output *o);
    void (*close)(void *st);
    void (*cost)(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, struct api_cost *c);
} api_format_info;

const api_format_info *api_format_info_of(api_format f);
/* "none" or "meshopt" (NULL or "": none) for format f; 0, or -1 with err naming compress and what f takes. */
int api_compress_parse(const char *text, api_format f, api_compress *c, api_error *err);
const char *api_compress_name(api_compress c);
/* The table as GET /formats serves it: [{"name", "media_type", "extension", "binary", "mesh", "properties",
 * "default_res"}, ...] in the table's order (malloc'd; NULL if out of memory). */
char *api_formats_json(void);
/* Returns 0, or -1 with err listing the formats. */
int api_format_parse(const char *name, api_format *f, api_error *err);

#define API_RES_GRID_DEFAULT 33
#define API_RES_MESH_DEFAULT 64
#define API_RES_GRID_MAX 4096          /* samples per axis */
#define API_RES_GRID_POINTS (1u << 25) /* samples in all: 400 MB of f32 */
#define API_RES_MESH_MAX 512           /* samples per face edge */

/* "N" or "NU,NV,NW"; NULL or "" gives the format's default. Returns 0, or -1 with err naming the limit. */
int api_res_parse(const char *text, api_format f, unsigned res[3], api_error *err);

/*
 * id: the model's id (id.h), or NULL. props: the solution's properties if the
 * caller has them (the formats with props set carry them), or NULL to compute them.
 * NULL and err on failure (out of memory, a mesh out of range). A solid that
 * could reach beyond float32's range in what the format writes (its range
 * column) is a document error before any work, in every format alike: the
 * bound is the closed form's, the sum of its modes' largest magnitudes, so
 * no format ever writes an inf or a NaN. The long work
 * happens here: the properties it computes, the mesh (gltf, glb, stl, obj, ply, msh, vtu), the
 * whole json document; cancel (NULL: never) is polled through it, and when
 * it stops the call frees everything and err has status API_ERR_CANCELLED.
 * Grid formats only set up their sampling tables here (api/cost.h's bytes).
 */
api_output *api_output_open(const pde_solution *sol, const char *id, const pde_props *props, api_format f,
                            const unsigned res[3], const pde_cancel *cancel, api_error *err);
/* The same with options (NULL: the defaults); a compression the format does not take is a document error. */
api_output *api_output_open_ex(const pde_solution *sol, const char *id, const pde_props *props, api_format f,
                               const unsigned res[3], const api_output_opts *opts, const pde_cancel *cancel,
                               api_error *err);
/* pde_properties() (cancel: NULL never stops) with its failure as err: a solid whose properties overflow a
 * double a document error (the client scales it down), a cancelled call API_ERR_CANCELLED, else out of
 * memory. Returns the
 * status; *out as pde_properties() leaves it. The formats that carry the properties compute them so. */
pde_status api_properties(const pde_solution *sol, const pde_cancel *cancel, pde_props *out, api_error *err);
/* The refusals of api_output_open_ex() that take no work (a format that is none, a compression it does not
 * take, a solid beyond its float32 range): 0, or -1 with err as api_output_open_ex() would set it. For a
 * caller that computes the properties first (server/routes.c), so that it refuses before that work. */
int api_output_check(const pde_solution *sol, api_format f, const api_output_opts *opts, api_error *err);
/* The total size in bytes, or -1 when it is known only at the end (grid, obj, msh, vtu). */
long long api_output_size(const api_output *o);
/*
 * Up to max bytes into buf; returns the count, 0 at the end, or -1 out of
 * memory. Each call does at most one bounded piece of work, so a server can
 * poll a deadline between calls: up to 16384 sampled points and about 2^21
 * multiply-adds of sampling (at least one row), 4096 STL triangles or OBJ
 * lines, 16384 PLY vertices or faces, about 1 MB of a volume mesh (msh, vtu),
 * 48 KB of base64 or 1 MB of copying. It may return fewer than max bytes
 * before the end; read until it returns 0.
 */
long api_output_read(api_output *o, char *buf, size_t max);
void api_output_free(api_output *o);

/* The properties as JSON text (for asset.extras and the json format); malloc'd, NULL if out of memory. */
char *api_props_json(const pde_props *p);
/* The same as a cJSON tree (cJSON_Delete it); NULL if out of memory. */
struct cJSON *api_props_tree(const pde_props *p);
/* Reads such a tree back (a server's answer); what is missing or not a number reads as 0. Cannot fail. */
void api_props_from_tree(const struct cJSON *t, pde_props *out);

/* An eval answer {"id", "values": [[x, y, z], ...]} and, when given, "du", "dv", "dw" (3 n doubles
 * each), at 17 significant digits; malloc'd, NULL if out of memory. */
char *api_eval_json(const char *id, const double *values, const double *du, const double *dv, const double *dw,
                    size_t n);

#endif
