/*
 * mesh.c: the closed skin of a solid (mesh.h).
 *
 * DESIGN
 * 1. Each face is sampled on its own grid and triangulated, wound so that
 *    its normal points out of the parameter cube.
 * 2. Positions closer than 1e-6 of the solid's extent are welded (a spatial
 *    hash, searched over neighbouring cells): seams, shared edges and
 *    collapsed rows become one position each.
 * 3. Triangles with a repeated position, or no area, are dropped: that removes
 *    faces that collapse to a line or a point. Pairs of triangles over the
 *    same three positions with opposite orientations cancel: that removes
 *    faces that coincide, which lie inside the solid.
 * 4. If the enclosed volume comes out negative (the parametrisation reverses
 *    orientation, as x = u sin 2pi v, y = u cos 2pi v does), every triangle
 *    is flipped.
 * 5. Vertices are (position, face) pairs, with area-weighted normals.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"

/* ---- a small open-addressing map from 64-bit keys to 32-bit values ---- */

typedef struct {
    uint64_t *keys;
    uint32_t *vals;
    size_t cap;    /* a power of two */
} u64map;

#define EMPTY UINT64_MAX

static int map_init(u64map *m, size_t n)
{
    m->cap = 16;
    while (m->cap < 2 * n)
        m->cap *= 2;
    m->keys = malloc(m->cap * sizeof *m->keys);
    m->vals = malloc(m->cap * sizeof *m->vals);
    if (!m->keys || !m->vals)
        return -1;
    memset(m->keys, 0xff, m->cap * sizeof *m->keys);
    return 0;
}

static void map_free(u64map *m)
{
    free(m->keys);
    free(m->vals);
}

static size_t slot(const u64map *m, uint64_t key)
{
    uint64_t h = key * 0x9e3779b97f4a7c15ull;
    size_t i = (size_t)(h >> 20) & (m->cap - 1);
    while (m->keys[i] != EMPTY && m->keys[i] != key)
        i = (i + 1) & (m->cap - 1);
    return i;
}

/* The value of key, or the given one stored now; *found tells which. */
static uint32_t map_get_or_put(u64map *m, uint64_t key, uint32_t val, int *found)
{
    size_t i = slot(m, key);
    *found = m->keys[i] == key;
    if (!*found) {
        m->keys[i] = key;
        m->vals[i] = val;
    }
    return m->vals[i];
}

/* ---- sampling the faces ---- */

typedef struct {
    int axis, side;       /* the face axis = side */
    size_t na, nb;        /* samples along its fast and slow parameters */
    int reverse;          /* wind the other way to face outward */
} face;

static double sample(size_t i, size_t n)
{
    return n > 1 ? (double)i / (double)(n - 1) : 0.5;
}

static int stopped(const pde_cancel *c)
{
    return c && c->stop && c->stop(c->arg);
}

/* Positions of a face, na x nb, fast index first, into out (3 na nb floats); 1 when cancelled. */
static int sample_face(const pde_solution *sol, const face *f, const unsigned res[3], const pde_cancel *cancel,
                       float *out)
{
    size_t nu = res[0], nv = res[1], nw = res[2];
    double *us = malloc((nu + nv) * sizeof *us), *vs = us ? us + nu : NULL;
    if (!us)
        return -1;
    for (size_t i = 0; i < nu; i++)
        us[i] = sample(i, nu);
    for (size_t j = 0; j < nv; j++)
        vs[j] = sample(j, nv);
    double fixed = f->side;
    pde_grid *g = NULL;
    pde_status st;
    if (f->axis == 0)
        st = pde_grid_create(sol, &fixed, 1, vs, nv, &g);        /* (v, w) */
    else if (f->axis == 1)
        st = pde_grid_create(sol, us, nu, &fixed, 1, &g);        /* (u, w) */
    else
        st = pde_grid_create(sol, us, nu, vs, nv, &g);           /* (u, v) */
    free(us);
    if (st != PDE_OK)
        return -1;
    int rc = 0;
    if (f->axis == 2) {
        for (size_t j = 0; j < nv && !rc; j++)       /* a row at a time, to poll between rows */
            if (!(rc = stopped(cancel)))
                pde_grid_rows(g, fixed, j, j + 1, out + 3 * j * nu, NULL, NULL, NULL);
    } else {
        for (size_t k = 0; k < nw && !rc; k++)
            if (!(rc = stopped(cancel)))
                pde_grid_plane(g, sample(k, nw), out + 3 * k * f->na);
    }
    pde_grid_free(g);
    return rc;
}

#define DEAD 0xff    /* rface mark of a dropped triangle */

/* A cell's key: 21 bits of each coordinate (cells wrap around far apart, which only costs a probe). */
static uint64_t cell_key(int64_t x, int64_t y, int64_t z)
{
    return ((uint64_t)(x & 0x1fffff) << 42) | ((uint64_t)(y & 0x1fffff) << 21) | (uint64_t)(z & 0x1fffff);
}

/* The triple in increasing order; returns the parity of the sorting permutation. */
static int sorted(const uint32_t t[3], uint32_t s[3])
{
    int parity = 0;
    uint32_t x;
    s[0] = t[0], s[1] = t[1], s[2] = t[2];
    if (s[0] > s[1]) x = s[0], s[0] = s[1], s[1] = x, parity ^= 1;
    if (s[1] > s[2]) x = s[1], s[1] = s[2], s[2] = x, parity ^= 1;
    if (s[0] > s[1]) x = s[0], s[0] = s[1], s[1] = x, parity ^= 1;
    return parity;
}

/* A 64-bit hash of a sorted triple (splitmix64 steps). */
static uint64_t mix3(const uint32_t s[3])
{
    uint64_t h = 0;
    for (int i = 0; i < 3; i++) {
        h += s[i] + 0x9e3779b97f4a7c15ull;
        h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
        h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
        h ^= h >> 31;
    }
    return h == EMPTY ? 0 : h;
}

static void cross(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* Twice the area vector of triangle (p, q, r). */
static void tri_normal(const float *p, const float *q, const float *r, double n[3])
{
    double a[3], b[3];
    for (int k = 0; k < 3; k++) {
        a[k] = (double)q[k] - p[k];
        b[k] = (double)r[k] - p[k];
    }
    cross(a, b, n);
}

void api_mesh_free(api_mesh *m)
{
    if (!m)
        return;
    free(m->pos);
    free(m->nrm);
    free(m->tri);
    free(m->weld);
    memset(m, 0, sizeof *m);
}

/* Polls every 8192 steps of a pass over points or triangles. */
#define POLL(i) ((i) % 8192 == 8191 && stopped(cancel))

int api_mesh_build(const pde_solution *sol, const unsigned res[3], const pde_cancel *cancel, api_mesh *out,
                   api_error *err)
{
    /* e_v x e_w = +e_u, e_u x e_w = -e_v, e_u x e_v = +e_w: which faces must reverse. */
    face faces[6];
    size_t nraw = 0, ntraw = 0;
    for (int a = 0; a < 3; a++)
        for (int s = 0; s < 2; s++) {
            face *f = &faces[2 * a + s];
            f->axis = a;
            f->side = s;
            f->na = a == 0 ? res[1] : res[0];
            f->nb = a == 2 ? res[1] : res[2];
            int outward_plus = s == 1, frame_plus = a != 1;
            f->reverse = outward_plus != frame_plus;
            nraw += f->na * f->nb;
            ntraw += 2 * (f->na - 1) * (f->nb - 1);
        }
    float *raw = malloc(3 * nraw * sizeof *raw);
    uint32_t *rtri = malloc(3 * ntraw * sizeof *rtri);
    uint8_t *rface = malloc(ntraw);
    uint32_t *wid = malloc(nraw * sizeof *wid);
    double *wpos = malloc(3 * nraw * sizeof *wpos);
    uint32_t *chain = malloc(nraw * sizeof *chain);
    u64map cells = { 0 }, tris = { 0 };
    memset(out, 0, sizeof *out);
    int rc = -1, cancelled = 0;
    const char *why = "out of memory building the mesh";
    api_status why_status = API_ERR_NOMEM;
    if (!raw || !rtri || !rface || !wid || !wpos || !chain)
        goto done;

    /* 1. Faces. */
    size_t base = 0, nt = 0;
    for (int fi = 0; fi < 6; fi++) {
        const face *f = &faces[fi];
        int r = sample_face(sol, f, res, cancel, raw + 3 * base);
        if (r) {
            cancelled = r > 0;
            goto done;
        }
        for (size_t b = 0; b + 1 < f->nb; b++)
            for (size_t a = 0; a + 1 < f->na; a++) {
                uint32_t v00 = (uint32_t)(base + b * f->na + a), v10 = v00 + 1;
                uint32_t v01 = (uint32_t)(v00 + f->na), v11 = v01 + 1;
                uint32_t q[2][3] = { { v00, v10, v11 }, { v00, v11, v01 } };
                for (int t = 0; t < 2; t++, nt++) {
                    rtri[3 * nt] = q[t][0];
                    rtri[3 * nt + 1] = f->reverse ? q[t][2] : q[t][1];
                    rtri[3 * nt + 2] = f->reverse ? q[t][1] : q[t][2];
                    rface[nt] = (uint8_t)fi;
                }
            }
        base += f->na * f->nb;
    }

    /* 2. Weld. */
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (size_t i = 0; i < nraw; i++)
        for (int k = 0; k < 3; k++) {
            if (!isfinite(raw[3 * i + k])) {
                why = "the solid's coordinates exceed the range of float32; no mesh can hold them";
                why_status = API_ERR_DOCUMENT;
                goto done;
            }
            lo[k] = fmin(lo[k], raw[3 * i + k]);
            hi[k] = fmax(hi[k], raw[3 * i + k]);
        }
    double extent = fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
    double eps = extent > 0 ? 1e-6 * extent : 1e-30, cell = 4 * eps;
    if (map_init(&cells, nraw))
        goto done;
    size_t npos = 0;
    for (size_t i = 0; i < nraw; i++) {
        if (POLL(i)) {
            cancelled = 1;
            goto done;
        }
        const float *p = raw + 3 * i;
        int64_t c[3];
        int span[3][2];     /* neighbouring cells worth a look: only within eps of a side */
        for (int k = 0; k < 3; k++) {
            double f = (p[k] - lo[k]) / cell;
            c[k] = (int64_t)floor(f);
            double frac = (f - (double)c[k]) * cell;
            span[k][0] = frac < eps ? -1 : 0;
            span[k][1] = cell - frac < eps ? 1 : 0;
        }
        uint32_t hit = UINT32_MAX;
        for (int dx = span[0][0]; dx <= span[0][1] && hit == UINT32_MAX; dx++)
            for (int dy = span[1][0]; dy <= span[1][1] && hit == UINT32_MAX; dy++)
                for (int dz = span[2][0]; dz <= span[2][1] && hit == UINT32_MAX; dz++) {
                    uint64_t key = cell_key(c[0] + dx, c[1] + dy, c[2] + dz);
                    size_t s = slot(&cells, key);
                    if (cells.keys[s] != key)
                        continue;
                    for (uint32_t w = cells.vals[s]; w != UINT32_MAX && hit == UINT32_MAX; w = chain[w])
                        if (fabs(wpos[3 * w] - p[0]) <= eps && fabs(wpos[3 * w + 1] - p[1]) <= eps &&
                            fabs(wpos[3 * w + 2] - p[2]) <= eps)
                            hit = w;
                }
        if (hit == UINT32_MAX) {
            hit = (uint32_t)npos++;
            for (int k = 0; k < 3; k++)
                wpos[3 * hit + k] = p[k];
            uint64_t key = cell_key(c[0], c[1], c[2]);
            int found;
            uint32_t head = map_get_or_put(&cells, key, hit, &found);
            chain[hit] = found ? head : UINT32_MAX;
            if (found)
                cells.vals[slot(&cells, key)] = hit;
        }
        wid[i] = hit;
    }

    /* 3. Drop collapsed triangles; cancel coincident pairs of opposite orientation. */
    for (size_t t = 0; t < nt; t++) {
        if (POLL(t)) {
            cancelled = 1;
            goto done;
        }
        uint32_t *w = &rtri[3 * t];
        double n[3];
        tri_normal(raw + 3 * w[0], raw + 3 * w[1], raw + 3 * w[2], n);
        for (int k = 0; k < 3; k++)
            w[k] = wid[w[k]];                           /* from here on, position ids */
        if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2] ||
            sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) <= 1e-12 * extent * extent)
            rface[t] = DEAD;
    }
    /* Only a triangle whose three positions all lie on a second face can have a coincident twin. */
    uint8_t *mask = calloc(npos + 1, 1);
    if (!mask)
        goto done;
    size_t ncand = 0;
    for (size_t t = 0; t < nt; t++)
        if (rface[t] != DEAD)
            for (int i = 0; i < 3; i++)
                mask[rtri[3 * t + i]] |= (uint8_t)(1u << rface[t]);
    for (size_t t = 0; t < nt; t++) {
        if (rface[t] == DEAD)
            continue;
        uint8_t m = mask[rtri[3 * t]] & mask[rtri[3 * t + 1]] & mask[rtri[3 * t + 2]];
        if (m & (m - 1))     /* two faces or more */
            ncand++;
    }
    if (map_init(&tris, ncand)) {
        free(mask);
        goto done;
    }
    for (size_t t = 0; t < nt; t++) {
        if (POLL(t)) {
            free(mask);
            cancelled = 1;
            goto done;
        }
        if (rface[t] == DEAD)
            continue;
        uint8_t m = mask[rtri[3 * t]] & mask[rtri[3 * t + 1]] & mask[rtri[3 * t + 2]];
        if (!(m & (m - 1)))
            continue;
        uint32_t s3[3];
        int parity = sorted(&rtri[3 * t], s3);
        uint64_t key = (mix3(s3) & ~1ull) | (uint64_t)parity;
        size_t st = slot(&tris, key ^ 1);
        if (tris.keys[st] == (key ^ 1) && tris.vals[st] != UINT32_MAX) {
            uint32_t o = tris.vals[st], so[3];
            sorted(&rtri[3 * o], so);
            if (so[0] == s3[0] && so[1] == s3[1] && so[2] == s3[2]) {
                rface[t] = rface[o] = DEAD;             /* coincident faces: inside the solid */
                tris.vals[st] = UINT32_MAX;
                continue;
            }
        }
        int found;
        map_get_or_put(&tris, key, (uint32_t)t, &found);
        if (found)
            tris.vals[slot(&tris, key)] = (uint32_t)t;
    }
    free(mask);

    /* 4. Outward: the enclosed volume must be positive. */
    double vol = 0.0;
    for (size_t t = 0; t < nt; t++) {
        if (rface[t] == DEAD)
            continue;
        const double *p = wpos + 3 * rtri[3 * t], *q = wpos + 3 * rtri[3 * t + 1], *r = wpos + 3 * rtri[3 * t + 2];
        double c[3];
        cross(q, r, c);
        vol += p[0] * c[0] + p[1] * c[1] + p[2] * c[2];
    }
    int flip = vol < 0.0;

    /* 5. Vertices are (position, face) pairs; normals are area-weighted. */
    size_t ntri = 0;
    for (size_t t = 0; t < nt; t++)
        ntri += rface[t] != DEAD;
    out->tri = malloc((3 * ntri + 1) * sizeof *out->tri);
    uint32_t *vof = malloc((npos + 1) * sizeof *vof);   /* this face's vertex at each position */
    if (!out->tri || !vof) {
        free(vof);
        goto done;
    }
    memset(vof, 0xff, (npos + 1) * sizeof *vof);
    size_t nv = 0, k = 0, first = 0;
    for (int fi = 0; fi < 6; fi++) {
        for (size_t t = 0; t < nt; t++) {
            if (rface[t] != fi)
                continue;
            uint32_t w[3] = { rtri[3 * t], rtri[3 * t + (flip ? 2 : 1)], rtri[3 * t + (flip ? 1 : 2)] };
            for (int i = 0; i < 3; i++) {
                if (vof[w[i]] == UINT32_MAX) {
                    vof[w[i]] = (uint32_t)nv;
                    chain[nv++] = w[i];                 /* chain now maps vertex -> position id */
                }
                out->tri[k++] = vof[w[i]];
            }
        }
        for (size_t v = first; v < nv; v++)             /* the next face starts afresh */
            vof[chain[v]] = UINT32_MAX;
        first = nv;
    }
    free(vof);
    out->pos = malloc((3 * nv + 1) * sizeof *out->pos);
    out->nrm = malloc((3 * nv + 1) * sizeof *out->nrm);
    out->weld = malloc((nv ? nv : 1) * sizeof *out->weld);
    double *acc = calloc(3 * nv + 1, sizeof *acc);
    if (!out->pos || !out->nrm || !out->weld || !acc) {
        free(acc);
        goto done;
    }
    for (size_t v = 0; v < nv; v++) {
        out->weld[v] = chain[v];
        for (int c = 0; c < 3; c++)
            out->pos[3 * v + c] = (float)wpos[3 * chain[v] + c];
    }
    for (size_t t = 0; t < ntri; t++) {
        const uint32_t *w = &out->tri[3 * t];
        double n[3];
        tri_normal(out->pos + 3 * w[0], out->pos + 3 * w[1], out->pos + 3 * w[2], n);
        for (int i = 0; i < 3; i++)
            for (int c = 0; c < 3; c++)
                acc[3 * w[i] + c] += n[c];
    }
    for (int c = 0; c < 3; c++)
        out->min[c] = INFINITY, out->max[c] = -INFINITY;
    for (size_t v = 0; v < nv; v++) {
        double *n = acc + 3 * v, len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int c = 0; c < 3; c++) {
            out->nrm[3 * v + c] = len > 0 ? (float)(n[c] / len) : (c == 2 ? 1.0f : 0.0f);
            out->min[c] = fminf(out->min[c], out->pos[3 * v + c]);
            out->max[c] = fmaxf(out->max[c], out->pos[3 * v + c]);
        }
    }
    free(acc);
    out->nverts = nv;
    out->ntris = ntri;
    out->npos = npos;
    rc = 0;
done:
    if (rc) {
        api_mesh_free(out);
        api_fail(err, cancelled ? API_ERR_CANCELLED : why_status, "", "%s", cancelled ? "cancelled" : why);
    }
    free(raw);
    free(rtri);
    free(rface);
    free(wid);
    free(wpos);
    free(chain);
    map_free(&cells);
    map_free(&tris);
    return rc;
}
