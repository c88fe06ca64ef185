/*
 * fmt_gltf.c: the gltf and glb formats: glTF 2.0 of the closed skin, +Y up,
 * in metres, with normals, det J as the float vertex attribute _DETJ, and the
 * properties in asset.extras; gltf carries its buffer as a base64 data URI,
 * glb in its BIN chunk.
 *
 * FRAME: glTF is +Y up, so the vertices are written in glTF's frame,
 * (X, Y, Z) = the model's (x, z, -y): a rotation about x, which keeps the
 * solid's handedness; the paper's height w, along z, stands along +Y.
 * Negation is exact, so POSITION's min and max are the float32 values.
 *
 * COMPRESSION (compress=meshopt): the streams of api/meshopt.h, in buffer 0;
 * the views decode into buffer 1, a fallback without data, so both
 * EXT_meshopt_compression and KHR_mesh_quantization are required (the
 * extension's spec: a fallback buffer without a uri makes it required).
 *
 * The JSON is written size-first (cgltf_write's manner): one writer measures
 * it with no buffer, then writes it into one of that size.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cost.h"
#include "fmt.h"
#include "meshopt.h"

typedef struct {
    api_mesh mesh;
    api_meshopt z;
    int compressed;
    unsigned char *blob;        /* buffer 0: the plain blob, or z.data */
    size_t blob_len, blob_pos;
    char *text;                 /* the JSON; gltf's base64 goes at text[split] */
    size_t text_len, split;
    int phase;
} gltf_state;

static void gltf_close(void *st)
{
    gltf_state *s = st;
    if (!s)
        return;
    api_mesh_free(&s->mesh);
    if (!s->compressed)
        free(s->blob);
    api_meshopt_free(&s->z);
    free(s->text);
    free(s);
}

/* A float32 bound at 17 digits: the exact value, as the validator compares it. */
static void vec3(api_sw *w, const char *name, const float v[3])
{
    api_sw_printf(w, ",\"%s\":[%.17g,%.17g,%.17g]", name, v[0], v[1], v[2]);
}

/* A bufferView, left open (for its extensions): the caller closes it. */
static void view(api_sw *w, int first, size_t buffer, size_t offset, size_t length, size_t stride, int target)
{
    api_sw_printf(w, "%s{\"buffer\":%zu,\"byteOffset\":%zu,\"byteLength\":%zu", first ? "" : ",", buffer, offset,
                  length);
    if (stride)
        api_sw_printf(w, ",\"byteStride\":%zu", stride);
    api_sw_printf(w, ",\"target\":%d", target);
}

/* The JSON, size-first: returns the bytes it takes (writing them when w->buf has room); *split is where
 * gltf's base64 goes (the end of buffer 0's data URI prefix). */
static void gltf_json(api_sw *w, const api_output *o, const gltf_state *s, const char *props, int glb, size_t *split)
{
    const api_mesh *m = &s->mesh;
    size_t nv = m->nverts, nt = m->ntris;
    api_sw_printf(w,
                  "{\"asset\":{\"version\":\"2.0\",\"generator\":\"pdesolid\",\"extras\":{\"id\":\"%s\","
                  "\"units\":\"metres\",\"up\":\"+Y; glTF (X, Y, Z) = the model's (x, z, -y)\"",
                  o->id);
    if (s->compressed)
        api_sw_printf(w, ",\"compression\":\"meshopt\",\"position_error\":%.3g", s->z.pos_error);
    api_sw_printf(w, ",\"properties\":%s}},", props);
    if (s->compressed)
        api_sw_puts(w, "\"extensionsUsed\":[\"EXT_meshopt_compression\",\"KHR_mesh_quantization\"],"
                       "\"extensionsRequired\":[\"EXT_meshopt_compression\",\"KHR_mesh_quantization\"],");
    api_sw_puts(w, "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0,\"name\":\"solid\"}],"
                   "\"meshes\":[{\"name\":\"skin\",\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,"
                   "\"_DETJ\":2},\"indices\":3,\"mode\":4}]}],\"accessors\":[");
    if (!s->compressed) {
        float mn[3] = { m->min[0], m->min[2], -m->max[1] }, mx[3] = { m->max[0], m->max[2], -m->min[1] };
        api_sw_printf(w, "{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"", nv);
        vec3(w, "min", mn);
        vec3(w, "max", mx);
        api_sw_printf(w, "},{\"bufferView\":1,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"}"
                         ",{\"bufferView\":2,\"componentType\":5126,\"count\":%zu,\"type\":\"SCALAR\"}"
                         ",{\"bufferView\":3,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"}],\"bufferViews\":[",
                      nv, nv, 3 * nt);
        static const int target[4] = { 34962, 34962, 34962, 34963 };
        const size_t at[5] = { 0, 12 * nv, 24 * nv, 28 * nv, 28 * nv + 12 * nt };
        for (int i = 0; i < 4; i++) {
            view(w, i == 0, 0, at[i], at[i + 1] - at[i], 0, target[i]);
            api_sw_puts(w, "}");
        }
        api_sw_puts(w, "],");
    } else {
        /* The streams are POSITION, NORMAL, _DETJ, indices: accessor and view i each. */
        for (int i = 0; i < s->z.nstreams; i++) {
            const api_meshopt_stream *t = &s->z.stream[i];
            api_sw_printf(w, "%s{\"bufferView\":%d,\"componentType\":%d,%s\"count\":%zu,\"type\":\"%s\"", i ? "," : "",
                          i, t->component_type, t->normalized ? "\"normalized\":true," : "", t->count, t->type);
            if (t->attribute && !strcmp(t->attribute, "POSITION")) {
                vec3(w, "min", t->min);
                vec3(w, "max", t->max);
            }
            api_sw_puts(w, "}");
        }
        api_sw_puts(w, "],\"bufferViews\":[");
        for (int i = 0; i < s->z.nstreams; i++) {
            const api_meshopt_stream *t = &s->z.stream[i];
            view(w, i == 0, 1, t->decoded_offset, t->stride * t->count, t->attribute ? t->stride : 0,
                 t->attribute ? 34962 : 34963);
            api_sw_printf(w, ",\"extensions\":{\"EXT_meshopt_compression\":{\"buffer\":0,\"byteOffset\":%zu,"
                             "\"byteLength\":%zu,\"byteStride\":%zu,\"count\":%zu,\"mode\":\"%s\"",
                          t->offset, t->length, t->stride, t->count, t->mode);
            if (strcmp(t->filter, "NONE"))
                api_sw_printf(w, ",\"filter\":\"%s\"", t->filter);
            api_sw_puts(w, "}}}");
        }
        api_sw_puts(w, "],");
    }
    api_sw_printf(w, "\"buffers\":[{\"byteLength\":%zu", s->blob_len);
    if (!glb)
        api_sw_puts(w, ",\"uri\":\"data:application/octet-stream;base64,");
    *split = w->need;
    api_sw_puts(w, glb ? "}" : "\"}");
    if (s->compressed)
        api_sw_printf(w, ",{\"byteLength\":%zu,\"extensions\":{\"EXT_meshopt_compression\":{\"fallback\":true}}}",
                      s->z.decoded_len);
    api_sw_puts(w, glb ? "]}" : "]}\n");
}

/*
 * Bytes [off, off + n) of the plain blob, both multiples of 4, into dst: positions and normals in
 * glTF's frame (x, z, -y), det J, indices; each a multiple of 4 bytes. glb streams it straight from
 * the mesh a chunk at a time; gltf's base64 reads it whole.
 */
static void plain_bytes(const api_mesh *m, size_t off, unsigned char *dst, size_t n)
{
    const size_t nv = m->nverts, end = off + n;
    for (int seg = 0; seg < 2 && off < end; seg++) {   /* positions, then normals */
        const size_t s0 = 12 * nv * (size_t)seg, s1 = s0 + 12 * nv;
        const float *src = seg ? m->nrm : m->pos;
        const size_t stop = s1 < end ? s1 : end;
        while (off < stop) {
            const size_t f = (off - s0) / 4, c = f % 3;
            const float *v = src + (f - c);
            if (c == 0 && off + 12 <= stop) {   /* whole vertices */
                const size_t nw = (stop - off) / 12;
                for (size_t i = 0; i < nw; i++, v += 3) {
                    const float t[3] = { v[0], v[2], -v[1] };
                    memcpy(dst + 12 * i, t, 12);
                }
                off += 12 * nw, dst += 12 * nw;
                continue;
            }
            const float x = c == 0 ? v[0] : c == 1 ? v[2] : -v[1];
            memcpy(dst, &x, 4);
            off += 4, dst += 4;
        }
    }
    if (off < end && off < 28 * nv) {
        const size_t k = (end < 28 * nv ? end : 28 * nv) - off;
        memcpy(dst, (const unsigned char *)m->detj + (off - 24 * nv), k);
        off += k, dst += k;
    }
    if (off < end)
        memcpy(dst, (const unsigned char *)m->tri + (off - 28 * nv), end - off);
}

static size_t plain_len(const api_mesh *m)
{
    return 28 * m->nverts + 12 * m->ntris;
}

/* The plain blob whole, for gltf's base64. */
static int plain_blob(gltf_state *s)
{
    s->blob_len = plain_len(&s->mesh);
    s->blob = malloc(s->blob_len);
    if (!s->blob)
        return -1;
    plain_bytes(&s->mesh, 0, s->blob, s->blob_len);
    return 0;
}

/* The skin in glTF's frame through api/meshopt.c; buffer 0 is its streams. */
static int compressed_blob(gltf_state *s, api_error *err)
{
    const api_mesh *m = &s->mesh;
    size_t nv = m->nverts;
    api_mesh r = *m;
    float *p = malloc((6 * nv + 1) * sizeof *p);
    if (!p)
        return -1;
    r.pos = p;
    r.nrm = p + 3 * nv;
    for (size_t i = 0; i < nv; i++) {
        const float *a = m->pos + 3 * i, *q = m->nrm + 3 * i;
        r.pos[3 * i] = a[0], r.pos[3 * i + 1] = a[2], r.pos[3 * i + 2] = -a[1];
        r.nrm[3 * i] = q[0], r.nrm[3 * i + 1] = q[2], r.nrm[3 * i + 2] = -q[1];
    }
    int rc = api_meshopt_encode(&r, &s->z, err);
    free(p);
    if (rc)
        return -1;
    s->compressed = 1;
    s->blob = s->z.data;
    s->blob_len = s->z.len;
    return 0;
}

static int open_as(api_output *o, const pde_cancel *cancel, api_error *err, int glb)
{
    gltf_state *s = calloc(1, sizeof *s);
    o->st = s;
    if (!s || api_out_mesh(o, cancel, &s->mesh, err))
        return -1;
    if (o->opts.compress == API_COMPRESS_MESHOPT ? compressed_blob(s, err) : glb ? 0 : plain_blob(s))
        return -1;
    if (glb && !s->compressed)
        s->blob_len = plain_len(&s->mesh);   /* streamed from the mesh by glb_fill, never held whole */
    const pde_props *props = api_out_props(o, cancel, err);
    char *pj = props ? api_props_json(props) : NULL;
    if (!pj)
        return -1;
    api_sw w = { NULL, 0, 0 };
    gltf_json(&w, o, s, pj, glb, &s->split);      /* measure */
    s->text = malloc(w.need + 1);
    if (s->text) {
        w = (api_sw){ s->text, w.need + 1, 0 };
        gltf_json(&w, o, s, pj, glb, &s->split);  /* write */
        s->text_len = w.need;
    }
    free(pj);
    if (!s->text)
        return -1;
    if (glb)
        o->size = (long long)(12 + 8 + ((s->text_len + 3) & ~(size_t)3) + 8 + s->blob_len);
    else
        o->size = (long long)(s->text_len + (s->blob_len + 2) / 3 * 4);
    return 0;
}

static int gltf_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    return open_as(o, cancel, err, 0);
}

static int glb_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    return open_as(o, cancel, err, 1);
}

static const char b64chars[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static int gltf_fill(api_output *o)
{
    gltf_state *s = o->st;
    switch (s->phase) {
    case 0:
        s->phase = 1;
        return api_out_put(o, s->text, s->split);
    case 1: {
        if (s->blob_pos == s->blob_len) {
            s->phase = 2;
            return api_out_put(o, s->text + s->split, s->text_len - s->split);
        }
        size_t n = s->blob_len - s->blob_pos;
        if (n > 49152)
            n = 49152;       /* a multiple of 3, so runs join without padding */
        if (api_out_reserve(o, n / 3 * 4 + 4))
            return -1;
        const unsigned char *p = s->blob + s->blob_pos;
        char *d = o->buf + o->len;
        size_t i = 0;
        for (; i + 3 <= n; i += 3) {
            uint32_t v = (uint32_t)p[i] << 16 | (uint32_t)p[i + 1] << 8 | p[i + 2];
            *d++ = b64chars[v >> 18];
            *d++ = b64chars[(v >> 12) & 63];
            *d++ = b64chars[(v >> 6) & 63];
            *d++ = b64chars[v & 63];
        }
        if (i < n) {
            uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0);
            *d++ = b64chars[v >> 18];
            *d++ = b64chars[(v >> 12) & 63];
            *d++ = i + 1 < n ? b64chars[(v >> 6) & 63] : '=';
            *d++ = '=';
        }
        o->len = (size_t)(d - o->buf);
        s->blob_pos += n;
        return 0;
    }
    }
    return 1;
}

static int glb_fill(api_output *o)
{
    gltf_state *s = o->st;
    unsigned char h[20];
    if (s->phase == 0) {
        size_t jlen = (s->text_len + 3) & ~(size_t)3;
        memcpy(h, "glTF", 4);
        api_le32(h + 4, 2);
        api_le32(h + 8, (uint32_t)o->size);
        api_le32(h + 12, (uint32_t)jlen);
        memcpy(h + 16, "JSON", 4);
        s->phase = 1;
        if (api_out_put(o, h, 20) || api_out_put(o, s->text, s->text_len) ||
            api_out_put(o, "   ", jlen - s->text_len))
            return -1;
        api_le32(h, (uint32_t)s->blob_len);
        memcpy(h + 4, "BIN\0", 4);
        return api_out_put(o, h, 8);
    }
    if (s->blob_pos == s->blob_len)
        return 1;
    /* 64 KiB a piece: it stays in cache between this write and the reader's copy; the plain blob goes
     * straight into the reader's buffer, as many whole floats as it holds (plain_bytes works in floats) */
    size_t n = s->blob_len - s->blob_pos;
    if (!s->compressed && o->dst && o->dst_max >= 4) {
        if (n > (o->dst_max & ~(size_t)3))
            n = o->dst_max & ~(size_t)3;
        plain_bytes(&s->mesh, s->blob_pos, (unsigned char *)o->dst, n);
        o->dst_len = n;
        s->blob_pos += n;
        return 0;
    }
    if (n > 1 << 16)
        n = 1 << 16;
    if (s->compressed) {
        if (api_out_put(o, s->blob + s->blob_pos, n))
            return -1;
    } else {
        if (api_out_reserve(o, n))
            return -1;
        plain_bytes(&s->mesh, s->blob_pos, (unsigned char *)o->buf + o->len, n);
        o->len += n;
    }
    s->blob_pos += n;
    return 0;
}

/* The plain blob is 28 bytes a vertex and 12 a triangle, base64'd (1 unit a byte, cost.c's K_B64) or
 * copied; meshopt's encoder keeps about 100 bytes a vertex and 24 a triangle of scratch, and works
 * about 2 units a byte of it. */
static void cost_as(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, struct api_cost *c,
                    double work_byte)
{
    if (opts->compress == API_COMPRESS_MESHOPT)
        api_cost_skin(sol, res, 100.0, 24.0, 2.0 + work_byte, 0.0, c);
    else
        api_cost_skin(sol, res, 28.0, 12.0, work_byte, 0.0, c);
}

static void gltf_cost(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, struct api_cost *c)
{
    cost_as(sol, res, opts, c, 1.0);
}

static void glb_cost(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, struct api_cost *c)
{
    cost_as(sol, res, opts, c, 0.1);
}

const api_format_info api_format_gltf = {
    .name = "gltf", .mime = "model/gltf+json", .ext = ".gltf", .mesh = 1, .props = 1, .compress = 1,
    .open = gltf_open, .fill = gltf_fill, .close = gltf_close, .cost = gltf_cost,
};

const api_format_info api_format_glb = {
    .name = "glb", .mime = "model/gltf-binary", .ext = ".glb", .mesh = 1, .props = 1, .binary = 1, .compress = 1,
    .open = glb_open, .fill = glb_fill, .close = gltf_close, .cost = glb_cost,
};
