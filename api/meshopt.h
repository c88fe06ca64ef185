/*
 * meshopt.h: a skin (mesh.h) compressed for glTF's EXT_meshopt_compression,
 * with KHR_mesh_quantization, by Debian's meshoptimizer (0.18).
 *
 * USAGE
 *
 *   api_meshopt z;
 *   if (api_meshopt_encode(&mesh, &z, &err)) { ... err.message ... }
 *   for (int i = 0; i < z.nstreams; i++) { a bufferView and an accessor per z.stream[i] }
 *   the compressed bytes z.data[0 .. z.len) are the glTF buffer 0 (the GLB's BIN chunk);
 *   buffer 1, of z.decoded_len bytes and no data, is the fallback the views decode into.
 *   api_meshopt_free(&z);
 *
 * What is kept (docs/API.md, "Compression"):
 *   POSITION  float32 VEC3 through the EXPONENTIAL filter: a shared exponent per
 *             vertex and API_MESHOPT_POS_BITS of mantissa, so each coordinate is
 *             within 2^-(API_MESHOPT_POS_BITS - 1) of the vertex's largest one
 *             (pos_error: the largest error, measured);
 *   NORMAL    OCTAHEDRAL filter, 8-bit normalized BYTE (VEC3 of a 4-byte element);
 *   _DETJ     float32 SCALAR through the EXPONENTIAL filter, 16 bits of mantissa;
 *   indices   the TRIANGLES index codec, 16-bit when fewer than 65536 vertices.
 * Vertices and triangles are first reordered for the GPU's vertex cache and
 * for fetching (which also makes the codecs compress better). The mesh is
 * left as it was.
 */
#ifndef API_MESHOPT_H
#define API_MESHOPT_H

#include <stddef.h>

#include "mesh.h"
#include "model.h"

#define API_MESHOPT_POS_BITS 24

typedef struct {
    const char *attribute;     /* "POSITION", "NORMAL", "_DETJ"; NULL for the indices */
    size_t offset, length;     /* the compressed bytes, in data */
    size_t decoded_offset;     /* where they decode to, in the fallback buffer (4-aligned) */
    size_t stride, count;      /* of the decoded elements */
    const char *mode;          /* EXT_meshopt_compression's: "ATTRIBUTES" or "TRIANGLES" */
    const char *filter;        /* "NONE", "OCTAHEDRAL" or "EXPONENTIAL" */
    int component_type;        /* glTF's: 5120 BYTE, 5123 UNSIGNED_SHORT, 5125 UNSIGNED_INT, 5126 FLOAT */
    int normalized;
    const char *type;          /* "VEC3", "SCALAR" */
    float min[3], max[3];      /* POSITION's bounds, of the values as decoded */
} api_meshopt_stream;

typedef struct {
    unsigned char *data;       /* the compressed streams, each 4-aligned */
    size_t len;
    size_t decoded_len;        /* the fallback buffer's byteLength */
    api_meshopt_stream stream[4];
    int nstreams;
    double pos_error;          /* the largest error of a decoded coordinate */
} api_meshopt;

/* Returns 0, or -1 with err (out of memory). */
int api_meshopt_encode(const api_mesh *m, api_meshopt *out, api_error *err);
void api_meshopt_free(api_meshopt *z);

#endif
