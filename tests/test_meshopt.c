/*
 * test_meshopt: the compressed skin (api/meshopt.h) decoded with meshoptimizer's
 * decoders, against the mesh it came from: the same triangles (by the volume and
 * area they enclose, and each triangle's corners), positions within the stated
 * error, normals within 8-bit octahedral precision, det J within 16 bits; and
 * the size against the uncompressed streams.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <meshoptimizer.h>

#include "mesh.h"
#include "meshopt.h"
#include "support.h"

typedef struct {
    float *pos, *nrm, *detj;   /* decoded: 3, 3 (from bytes), 1 per vertex */
    unsigned *idx;
    size_t nv, ni;
} decoded;

static void decode(const api_meshopt *z, decoded *d)
{
    memset(d, 0, sizeof *d);
    for (int i = 0; i < z->nstreams; i++) {
        const api_meshopt_stream *s = &z->stream[i];
        unsigned char *buf = malloc(s->stride * s->count + 16);
        if (strcmp(s->mode, "TRIANGLES") == 0) {
            assert_int_equal(meshopt_decodeIndexBuffer(buf, s->count, s->stride, z->data + s->offset, s->length), 0);
            d->ni = s->count;
            d->idx = malloc(s->count * sizeof *d->idx);
            for (size_t k = 0; k < s->count; k++) {
                if (s->stride == 2) {
                    uint16_t x;
                    memcpy(&x, buf + 2 * k, 2);
                    d->idx[k] = x;
                } else
                    memcpy(&d->idx[k], buf + 4 * k, 4);
            }
            free(buf);
            continue;
        }
        assert_int_equal(meshopt_decodeVertexBuffer(buf, s->count, s->stride, z->data + s->offset, s->length), 0);
        d->nv = s->count;
        if (strcmp(s->filter, "EXPONENTIAL") == 0)
            meshopt_decodeFilterExp(buf, s->count, s->stride);
        if (strcmp(s->attribute, "POSITION") == 0)
            d->pos = (float *)buf;
        else if (strcmp(s->attribute, "_DETJ") == 0)
            d->detj = (float *)buf;
        else {
            assert_string_equal(s->attribute, "NORMAL");
            meshopt_decodeFilterOct(buf, s->count, s->stride);
            d->nrm = malloc(3 * s->count * sizeof *d->nrm);
            for (size_t k = 0; k < 3 * s->count; k++)
                d->nrm[k] = (float)((const int8_t *)buf)[k / 3 * 4 + k % 3] / 127.0f;
            free(buf);
        }
    }
}

/* Six times the volume and twice the area the triangles enclose. */
static void enclosed(const float *pos, const unsigned *idx, size_t ni, double *vol, double *area)
{
    *vol = *area = 0;
    for (size_t t = 0; t < ni; t += 3) {
        const float *a = pos + 3 * idx[t], *b = pos + 3 * idx[t + 1], *c = pos + 3 * idx[t + 2];
        double u[3], v[3], n[3];
        for (int k = 0; k < 3; k++)
            u[k] = (double)b[k] - a[k], v[k] = (double)c[k] - a[k];
        n[0] = u[1] * v[2] - u[2] * v[1], n[1] = u[2] * v[0] - u[0] * v[2], n[2] = u[0] * v[1] - u[1] * v[0];
        *vol += a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
        *area += sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
}

/* The vertex of m at position p with normal nearest to nr, or -1. */
static long find_vertex(const api_mesh *m, const float p[3], const float nr[3], double tol)
{
    long best = -1;
    double bd = 0;
    for (size_t v = 0; v < m->nverts; v++) {
        const float *q = m->pos + 3 * v;
        if (fabs(q[0] - p[0]) > tol || fabs(q[1] - p[1]) > tol || fabs(q[2] - p[2]) > tol)
            continue;
        const float *n = m->nrm + 3 * v;
        double d = n[0] * nr[0] + n[1] * nr[1] + n[2] * nr[2];
        if (best < 0 || d > bd)
            best = (long)v, bd = d;
    }
    return best;
}

#ifdef __SANITIZE_ADDRESS__
/* Every malloc'd byte starts as 0xbe (ASan fills only the first 4 KB by default), so bytes the encoder
 * leaves unwritten show. */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "max_malloc_fill_size=2147483647:malloc_fill_byte=190";
}
#endif

/* The bytes between and after the streams (their 4-byte alignment) are zeros: nothing of the heap's
 * earlier contents reaches a client, and one solid gives the same bytes every time (its ETag). */
static void padding_should_be_zero(const api_meshopt *z, const char *name)
{
    size_t covered = 0;
    for (int i = 0; i < z->nstreams; i++) {
        const api_meshopt_stream *s = &z->stream[i];
        for (size_t k = covered; k < s->offset; k++)
            if (z->data[k])
                fail_msg("%s: byte %zu, before stream %d, is 0x%02x", name, k, i, z->data[k]);
        covered = s->offset + s->length;
    }
    for (size_t k = covered; k < z->len; k++)
        if (z->data[k])
            fail_msg("%s: byte %zu, after the streams, is 0x%02x", name, k, z->data[k]);
}

static void compressed_skins_should_decode_to_the_same_mesh(void **state)
{
    (void)state;
    const char *names[] = { "fig1a", "fig3b", "fig4a", "fig4i" };
    for (size_t f = 0; f < sizeof names / sizeof *names; f++) {
        pde_solution *sol = preset_solution(names[f]);
        const unsigned res[3] = { 64, 64, 64 };
        api_mesh m;
        api_error err;
        assert_int_equal(api_mesh_build(sol, res, NULL, &m, &err), 0);
        api_meshopt z;
        assert_int_equal(api_meshopt_encode(&m, &z, &err), 0);
        padding_should_be_zero(&z, names[f]);
        decoded d;
        decode(&z, &d);
        assert_int_equal(d.ni, 3 * m.ntris);
        assert_true(d.nv <= m.nverts);

        double extent = 0;
        for (int c = 0; c < 3; c++)
            extent = fmax(extent, fmax(fabs(m.min[c]), fabs(m.max[c])));
        /* A shared exponent per vertex: each coordinate within 2^-(bits - 1) of the vertex's largest. */
        const double tol = ldexp(extent, 1 - API_MESHOPT_POS_BITS);
        assert_true(z.pos_error <= tol);
        double v0, a0, v1, a1;
        enclosed(m.pos, m.tri, 3 * m.ntris, &v0, &a0);
        enclosed(d.pos, d.idx, d.ni, &v1, &a1);
        if (!(fabs(v1 - v0) <= 1e-5 * fabs(v0) && fabs(a1 - a0) <= 1e-5 * a0))
            fail_msg("%s: volume %.9g -> %.9g, area %.9g -> %.9g", names[f], v0 / 6, v1 / 6, a0 / 2, a1 / 2);
        /* Each decoded vertex is one of the mesh's, with its normal and det J. */
        double jmax = 0;
        for (size_t v = 0; v < m.nverts; v++)
            jmax = fmax(jmax, fabs(m.detj[v]));
        for (size_t v = 0; v < d.nv; v += 7) {
            long o = find_vertex(&m, d.pos + 3 * v, d.nrm + 3 * v, 2 * tol);
            if (o < 0)
                fail_msg("%s: decoded vertex %zu is none of the mesh's", names[f], v);
            const float *n0 = m.nrm + 3 * o, *n1 = d.nrm + 3 * v;   /* BYTE normals: unit up to 1/127 */
            double dot = (n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2]) /
                         sqrt((double)n1[0] * n1[0] + (double)n1[1] * n1[1] + (double)n1[2] * n1[2]);
            if (!(dot > cos(0.03)))
                fail_msg("%s: normal of vertex %zu off by %g rad: (%g %g %g) decoded (%g %g %g)", names[f], v, acos(fmin(dot, 1.0)), n0[0], n0[1], n0[2], n1[0], n1[1], n1[2]);
            if (!(fabs(d.detj[v] - m.detj[o]) <= ldexp(fabs(m.detj[o]), -15) + 1e-12 * jmax))
                fail_msg("%s: det J %.9g decoded as %.9g", names[f], m.detj[o], d.detj[v]);
        }
        if (strcmp(names[f], "fig4a") == 0) {
            size_t plain = 28 * m.nverts + 4 * 3 * m.ntris;   /* float pos, nrm, det J; 32-bit indices */
            print_message("fig4a at 64: %zu bytes compressed, %zu plain (%.2f); positions within %.3g of %.3g\n",
                          z.len, plain, (double)z.len / plain, z.pos_error, extent);
        }
        free(d.pos);
        free(d.nrm);
        free(d.detj);
        free(d.idx);
        api_meshopt_free(&z);
        api_mesh_free(&m);
        pde_solution_free(sol);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(compressed_skins_should_decode_to_the_same_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
