/*
 * meshopt.c: a skin compressed for EXT_meshopt_compression (meshopt.h), by
 * meshoptimizer's vertex and index codecs and filters.
 */
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include <meshoptimizer.h>

#include "meshopt.h"

/* EXT_meshopt_compression decodes vertex codec version 0 and index codec version 1. */
static pthread_once_t versions_once = PTHREAD_ONCE_INIT;

static void set_versions(void)
{
    meshopt_encodeVertexVersion(0);
    meshopt_encodeIndexVersion(1);
}

void api_meshopt_free(api_meshopt *z)
{
    if (!z)
        return;
    free(z->data);
    memset(z, 0, sizeof *z);
}

static size_t align4(size_t n)
{
    return (n + 3) & ~(size_t)3;
}

/* Appends a stream's compressed bytes to z (capacity cap) and describes it. */
static void add_stream(api_meshopt *z, const api_meshopt_stream *s, size_t written)
{
    api_meshopt_stream *d = &z->stream[z->nstreams++];
    *d = *s;
    d->offset = z->len;
    d->length = written;
    d->decoded_offset = z->decoded_len;
    z->len = align4(d->offset + written);
    memset(z->data + d->offset + written, 0, z->len - (d->offset + written));   /* nothing of the heap's */
    z->decoded_len = align4(z->decoded_len + d->stride * d->count);
}

int api_meshopt_encode(const api_mesh *m, api_meshopt *out, api_error *err)
{
    pthread_once(&versions_once, set_versions);
    memset(out, 0, sizeof *out);
    const size_t ni = 3 * m->ntris, n = m->nverts;
    unsigned *idx = malloc((ni + 1) * sizeof *idx), *remap = malloc((n + 1) * sizeof *remap);
    float *pos = malloc((3 * n + 1) * sizeof *pos), *nrm4 = malloc((4 * n + 1) * sizeof *nrm4);
    float *detj = malloc((n + 1) * sizeof *detj);
    unsigned char *filtered = malloc(12 * n + 1);
    const size_t vbound = meshopt_encodeVertexBufferBound(n, 12), ibound = meshopt_encodeIndexBufferBound(ni, n);
    /* The streams' bounds, each aligned: positions (12), normals (4), det J (4), indices. */
    const size_t cap = align4(vbound) + 2 * align4(meshopt_encodeVertexBufferBound(n, 4)) + align4(ibound) + 16;
    out->data = malloc(cap);
    int rc = -1;
    if (!idx || !remap || !pos || !nrm4 || !detj || !filtered || !out->data) {
        api_meshopt_free(out);
        api_fail_nomem(err);
        goto done;
    }

    /* Triangles for the vertex cache, then vertices in the order the triangles fetch them. */
    meshopt_optimizeVertexCache(idx, m->tri, ni, n);
    const size_t nv = meshopt_optimizeVertexFetchRemap(remap, idx, ni, n);
    meshopt_remapIndexBuffer(idx, idx, ni, remap);
    for (size_t v = 0; v < n; v++) {
        const unsigned r = remap[v];
        if (r == ~0u)
            continue;   /* used by no triangle */
        memcpy(pos + 3 * r, m->pos + 3 * v, 3 * sizeof *pos);
        memcpy(nrm4 + 4 * r, m->nrm + 3 * v, 3 * sizeof *nrm4);
        nrm4[4 * r + 3] = 0.0f;
        const float j = m->detj ? m->detj[v] : 0.0f;
        detj[r] = isfinite(j) ? j : j > 0 ? FLT_MAX : -FLT_MAX;
    }

    /* POSITION: shared exponent per vertex, API_MESHOPT_POS_BITS of mantissa. */
    api_meshopt_stream s = { .attribute = "POSITION", .stride = 12, .count = nv, .mode = "ATTRIBUTES",
                             .filter = "EXPONENTIAL", .component_type = 5126, .type = "VEC3" };
    meshopt_encodeFilterExp(filtered, nv, 12, API_MESHOPT_POS_BITS, pos);
    size_t w = meshopt_encodeVertexBuffer(out->data + out->len, cap - out->len, filtered, nv, 12);
    /* The values as the decoder gives them: the accessor's bounds and the error. */
    meshopt_decodeFilterExp(filtered, nv, 12);
    const float *dec = (const float *)filtered;
    for (int c = 0; c < 3; c++)
        s.min[c] = FLT_MAX, s.max[c] = -FLT_MAX;
    for (size_t k = 0; k < 3 * nv; k++) {
        const int c = (int)(k % 3);
        s.min[c] = dec[k] < s.min[c] ? dec[k] : s.min[c];
        s.max[c] = dec[k] > s.max[c] ? dec[k] : s.max[c];
        out->pos_error = fmax(out->pos_error, fabs((double)dec[k] - pos[k]));
    }
    if (!nv)
        memset(s.min, 0, sizeof s.min), memset(s.max, 0, sizeof s.max);
    add_stream(out, &s, w);

    /* NORMAL: octahedral, 8 bits. */
    s = (api_meshopt_stream){ .attribute = "NORMAL", .stride = 4, .count = nv, .mode = "ATTRIBUTES",
                              .filter = "OCTAHEDRAL", .component_type = 5120, .normalized = 1, .type = "VEC3" };
    meshopt_encodeFilterOct(filtered, nv, 4, 8, nrm4);
    w = meshopt_encodeVertexBuffer(out->data + out->len, cap - out->len, filtered, nv, 4);
    add_stream(out, &s, w);

    /* _DETJ: 16 bits of mantissa, its own exponent. */
    s = (api_meshopt_stream){ .attribute = "_DETJ", .stride = 4, .count = nv, .mode = "ATTRIBUTES",
                              .filter = "EXPONENTIAL", .component_type = 5126, .type = "SCALAR" };
    meshopt_encodeFilterExp(filtered, nv, 4, 16, detj);
    w = meshopt_encodeVertexBuffer(out->data + out->len, cap - out->len, filtered, nv, 4);
    add_stream(out, &s, w);

    /* The indices. */
    s = (api_meshopt_stream){ .stride = nv < 65536 ? 2 : 4, .count = ni, .mode = "TRIANGLES", .filter = "NONE",
                              .component_type = nv < 65536 ? 5123 : 5125, .type = "SCALAR" };
    w = meshopt_encodeIndexBuffer(out->data + out->len, cap - out->len, idx, ni);
    add_stream(out, &s, w);
    rc = 0;
done:
    free(idx);
    free(remap);
    free(pos);
    free(nrm4);
    free(detj);
    free(filtered);
    return rc;
}
