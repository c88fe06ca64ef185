/*
 * mesh.c: the closed skin of a solid (mesh.h).
 *
 * DESIGN
 * The skin is the image of the parameter cube's boundary, sampled on the
 * lattice i/(n-1) of each axis, so its topology is known before any position
 * is: no position is hashed or searched for.
 * 1. The two faces of each axis are sampled on one grid with the closed
 *    form's first derivatives (pde_grid; u = 0, 1 as a grid of nu = 2, which
 *    core fills column-wise), and triangulated, wound so that each face's
 *    normal points out of the parameter cube.
 * 2. Samples are joined (union-find) where they are one point:
 *    - a face's edge row is its neighbour's (the cube's 12 edges): by the
 *      lattice alone;
 *    - adjacent samples of a face's line that the map makes one, within 1e-6
 *      of the solid's extent: a collapsed row (u = 0 of the circular examples);
 *    - the same sample on opposite faces that the map makes one: a closed
 *      loop's seam (v = 0 and v = 1).
 * 3. Triangles with a repeated point, or no area, are dropped: faces that
 *    collapse to a line or a point go. A cell of opposite faces whose
 *    triangles join the same points lies inside the solid: both go (faces that
 *    coincide).
 * 4. If the enclosed volume comes out negative (the parametrisation reverses
 *    orientation, as x = u sin 2pi v, y = u cos 2pi v does), every triangle
 *    is flipped.
 * 5. Vertices are (point, face) pairs. A vertex's normal is the face's
 *    x_a x x_b from the closed form, and its det J is det(x_u, x_v, x_w);
 *    where a vertex joins several samples of its face, or x_a x x_b vanishes
 *    (a collapsed row's point), the normal is the area-weighted mean of its
 *    triangles' instead.
 * Every pass is linear in the samples.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"

typedef struct {
    int axis, side;       /* the face axis = side */
    size_t na, nb;        /* samples along its fast and slow parameters: (v, w), (u, w) or (u, v) */
    int reverse;          /* wind the other way to face outward */
    size_t base;          /* its first sample's index */
} face;

static double sample(size_t i, size_t n)
{
    return n > 1 ? (double)i / (double)(n - 1) : 0.5;
}

static int stopped(const pde_cancel *c)
{
    return c && c->stop && c->stop(c->arg);
}

/* The fast and slow parameters' axes of a face. */
static void face_axes(const face *f, int o[2])
{
    o[0] = f->axis == 0 ? 1 : 0;
    o[1] = f->axis == 2 ? 1 : 2;
}

/* The sample of face f at lattice point ijk, which must lie on f. */
static size_t face_sample(const face *f, const size_t ijk[3])
{
    int o[2];
    face_axes(f, o);
    return f->base + ijk[o[1]] * f->na + ijk[o[0]];
}

/* The raw samples: positions, the face's x_a x x_b, and det J; lo, hi of the positions, and whether
 * any is not finite. */
typedef struct {
    float *pos, *nrm, *detj;
    float lo[3], hi[3];
    int bad;
} samples;

/*
 * The two faces of an axis, f[0] at 0 and f[1] at 1, na x nb samples each, fast index first, from the
 * closed form with its derivatives. One grid holds both faces' fixed parameter, so each plane's h(w)
 * and each row's coefficients serve both: u = 0, 1 is a grid of nu = 2 (a plane of w, rows along v),
 * v = 0, 1 one of nv = 2 (rows 0 and 1 of a plane), w = 0, 1 the planes 0 and 1 of the (u, v) grid,
 * one row at a time. 1 when cancelled, -1 out of memory.
 */
static int sample_faces(const pde_solution *sol, const face f[2], const unsigned res[3], const pde_cancel *cancel,
                        samples *out)
{
    const int axis = f[0].axis;
    const size_t nu = res[0], nv = res[1], nmax = nu > nv ? nu : nv;
    double *us = malloc((nu + nv) * sizeof *us), *vs = us ? us + nu : NULL;
    float *d = malloc(4 * 3 * 2 * nmax * sizeof *d);   /* x, x_u, x_v, x_w of a plane's row(s) */
    if (!us || !d) {
        free(us);
        free(d);
        return -1;
    }
    for (size_t i = 0; i < nu; i++)
        us[i] = sample(i, nu);
    for (size_t j = 0; j < nv; j++)
        vs[j] = sample(j, nv);
    const double ends[2] = { 0.0, 1.0 };
    pde_grid *g = NULL, *g1 = NULL;   /* g1: the plane w = 1's own grid, so neither moves between planes */
    pde_status st;
    if (axis == 0)
        st = pde_grid_create(sol, ends, 2, vs, nv, &g);         /* (v, w) */
    else if (axis == 1)
        st = pde_grid_create(sol, us, nu, ends, 2, &g);         /* (u, w) */
    else if ((st = pde_grid_create(sol, us, nu, vs, nv, &g)) == PDE_OK)   /* (u, v) */
        st = pde_grid_create(sol, us, nu, vs, nv, &g1);
    free(us);
    if (st != PDE_OK) {
        pde_grid_free(g);
        free(d);
        return -1;
    }
    int o[2], rc = 0;
    face_axes(&f[0], o);
    const size_t na = f[0].na, m = 6 * nmax;
    float *x = d, *xd[3] = { d + m, d + 2 * m, d + 3 * m };   /* x, then x_u, x_v, x_w */
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    int bad = 0;
    for (size_t b = 0; b < f[0].nb && !rc; b++) {       /* a row at a time, to poll between rows */
        if ((rc = stopped(cancel)))
            break;
        if (axis == 2) {
            pde_grid_rows(g, 0.0, b, b + 1, x, xd[0], xd[1], xd[2]);
            pde_grid_rows(g1, 1.0, b, b + 1, x + 3 * na, xd[0] + 3 * na, xd[1] + 3 * na, xd[2] + 3 * na);
        } else {
            pde_grid_plane_d(g, sample(b, res[2]), x, xd[0], xd[1], xd[2]);
        }
        for (int side = 0; side < 2; side++) {
            if (side && (rc = stopped(cancel)))   /* a poll per face row, as before the faces were paired */
                break;
            /* sample a of this side in the plane's layout: (v, u) interleaved for u = 0, 1, else by rows */
            const size_t step = axis == 0 ? 2 : 1, first = axis == 0 ? (size_t)side : (size_t)side * na;
            const size_t s0 = f[side].base + b * na;
            float *restrict pos = out->pos + 3 * s0, *restrict nrm = out->nrm + 3 * s0, *restrict dj = out->detj + s0;
            const float sg = axis == 1 ? -1.0f : 1.0f;
            for (size_t a = 0; a < na; a++) {
                const size_t e = 3 * (first + a * step);
                const float *ta = xd[o[0]] + e, *tb = xd[o[1]] + e, *tc = xd[axis] + e;
                double n[3] = { (double)ta[1] * tb[2] - (double)ta[2] * tb[1], (double)ta[2] * tb[0] - (double)ta[0] * tb[2],
                                (double)ta[0] * tb[1] - (double)ta[1] * tb[0] };
                /* det(x_u, x_v, x_w) = (x_a x x_b) . x_axis, times the sign of (a, b, axis)'s order */
                double det = n[0] * tc[0] + n[1] * tc[1] + n[2] * tc[2];
                for (int k = 0; k < 3; k++) {
                    const float p = x[e + k];
                    pos[3 * a + k] = p;
                    nrm[3 * a + k] = (float)n[k];
                    bad |= !isfinite(p);
                    lo[k] = p < lo[k] ? p : lo[k];
                    hi[k] = p > hi[k] ? p : hi[k];
                }
                dj[a] = sg * (float)det;
            }
        }
    }
    for (int k = 0; k < 3; k++) {
        out->lo[k] = lo[k] < out->lo[k] ? lo[k] : out->lo[k];
        out->hi[k] = hi[k] > out->hi[k] ? hi[k] : out->hi[k];
    }
    out->bad |= bad;
    pde_grid_free(g);
    pde_grid_free(g1);
    free(d);
    return rc;
}

/* ---- union-find over the samples; a set's root is its least sample ---- */

static uint32_t find(uint32_t *up, uint32_t i)
{
    while (up[i] != i) {
        up[i] = up[up[i]];
        i = up[i];
    }
    return i;
}

static void join(uint32_t *up, uint32_t a, uint32_t b)
{
    a = find(up, a), b = find(up, b);
    if (a < b)
        up[b] = a;
    else if (b < a)
        up[a] = b;
}

static int near(const float *p, const float *q, double eps)
{
    return fabs((double)p[0] - q[0]) <= eps && fabs((double)p[1] - q[1]) <= eps && fabs((double)p[2] - q[2]) <= eps;
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

/*
 * Cell v00 (a sample index; na samples to a row) of a face: its triangles' normals (twice their area
 * vectors) in the unreversed winding, (v00, v10, v11) and (v00, v11, v01), and six times the signed
 * volume of the tetrahedra (0, triangle) in the face's winding (sgn -1 when it reverses), as
 * x_00 . n, so the volume costs a dot product on the normal.
 */
static inline void cell_normals(const float *restrict pos, size_t v00, size_t na, double sgn, double n[2][3],
                                double vol[2])
{
    const float *p = pos + 3 * v00, *p10 = p + 3, *p01 = p + 3 * na, *p11 = p01 + 3;
    double e1[3], d[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = (double)p10[k] - p[k];
        d[k] = (double)p11[k] - p[k];
        e2[k] = (double)p01[k] - p[k];
    }
    cross(e1, d, n[0]);
    cross(d, e2, n[1]);
    for (int q = 0; q < 2; q++)
        vol[q] = sgn * ((double)p[0] * n[q][0] + (double)p[1] * n[q][1] + (double)p[2] * n[q][2]);
}

/* The samples of triangle q (0, 1) of cell (a, b) of face f, wound outward of the cube. */
static void cell_tri(const face *f, size_t a, size_t b, int q, uint32_t t[3])
{
    uint32_t v00 = (uint32_t)(f->base + b * f->na + a), v10 = v00 + 1;
    uint32_t v01 = (uint32_t)(v00 + f->na), v11 = v01 + 1;
    t[0] = v00;
    t[1] = q ? (f->reverse ? v01 : v11) : (f->reverse ? v11 : v10);
    t[2] = q ? (f->reverse ? v11 : v01) : (f->reverse ? v10 : v11);
}

void api_mesh_free(api_mesh *m)
{
    if (!m)
        return;
    free(m->pos);
    free(m->nrm);
    free(m->detj);
    free(m->tri);
    free(m->weld);
    memset(m, 0, sizeof *m);
}

int api_mesh_build(const pde_solution *sol, const unsigned res[3], const pde_cancel *cancel, api_mesh *out,
                   api_error *err)
{
    memset(out, 0, sizeof *out);
    if (res[0] < 2 || res[1] < 2 || res[2] < 2) {
        api_fail(err, API_ERR_LIMIT, "", "a mesh needs at least 2 samples per face edge");
        return -1;
    }
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
            f->base = nraw;
            nraw += f->na * f->nb;
            ntraw += 2 * (f->na - 1) * (f->nb - 1);
        }
    samples raw = { malloc(3 * nraw * sizeof(float)), malloc(3 * nraw * sizeof(float)), malloc(nraw * sizeof(float)),
                    { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY }, 0 };
    uint32_t *up = malloc(nraw * sizeof *up);
    uint32_t *vof = malloc(nraw * sizeof *vof);    /* this face's vertex at each root, or UINT32_MAX */
    uint32_t *pid = malloc(nraw * sizeof *pid);    /* the position id of each root, or UINT32_MAX */
    uint8_t *live = malloc(ntraw);
    double *acc = NULL;
    uint32_t *vsam = NULL;    /* each vertex's sample */
    int rc = -1, cancelled = 0;
    const char *why = "out of memory building the mesh";
    api_status why_status = API_ERR_NOMEM;
    if (!raw.pos || !raw.nrm || !raw.detj || !up || !vof || !pid || !live)
        goto done;

    /* 1. Faces. */
    for (int a = 0; a < 3; a++) {
        int r = sample_faces(sol, &faces[2 * a], res, cancel, &raw);
        if (r) {
            cancelled = r > 0;
            goto done;
        }
    }
    if (raw.bad) {
        why = "the solid's coordinates exceed the range of float32; no mesh can hold them";
        why_status = API_ERR_DOCUMENT;
        goto done;
    }
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++)
        lo[k] = raw.lo[k], hi[k] = raw.hi[k];
    const double extent = fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
    const double eps = extent > 0 ? 1e-6 * extent : 1e-30;

    /* 2. Join: the cube's edges by the lattice; collapsed rows and seams where the map joins them. */
    for (size_t i = 0; i < nraw; i++)
        up[i] = (uint32_t)i;
    for (int fi = 0; fi < 6; fi++) {
        const face *f = &faces[fi];
        int o[2];
        face_axes(f, o);
        size_t ijk[3];
        ijk[f->axis] = f->side ? res[f->axis] - 1 : 0;
        for (size_t b = 0; b < f->nb; b++)
            for (size_t a = 0; a < f->na; a++) {
                const uint32_t i = (uint32_t)(f->base + b * f->na + a);
                const float *p = raw.pos + 3 * i;
                if (a + 1 < f->na && near(p, p + 3, eps))
                    join(up, i, i + 1);
                if (b + 1 < f->nb && near(p, p + 3 * f->na, eps))
                    join(up, i, (uint32_t)(i + f->na));
                if (a > 0 && a + 1 < f->na && b > 0 && b + 1 < f->nb)
                    continue;
                ijk[o[0]] = a, ijk[o[1]] = b;
                for (int e = 0; e < 3; e++)    /* the neighbouring faces this sample lies on */
                    if (e != f->axis && (ijk[e] == 0 || ijk[e] == res[e] - 1))
                        join(up, i, (uint32_t)face_sample(&faces[2 * e + (ijk[e] != 0)], ijk));
            }
    }
    size_t seams[3] = { 0, 0, 0 };   /* samples of opposite faces joined, per axis */
    for (int a = 0; a < 3; a++) {
        const face *f0 = &faces[2 * a], *f1 = &faces[2 * a + 1];
        for (size_t k = 0; k < f0->na * f0->nb; k++)
            if (near(raw.pos + 3 * (f0->base + k), raw.pos + 3 * (f1->base + k), eps))
                join(up, (uint32_t)(f0->base + k), (uint32_t)(f1->base + k)), seams[a]++;
    }
    for (size_t i = 0; i < nraw; i++)
        up[i] = find(up, (uint32_t)i);
    if (stopped(cancel)) {
        cancelled = 1;
        goto done;
    }

    /* 3. Triangles that collapse go; so do the cells of opposite faces that coincide. */
    const double tiny = 1e-12 * extent * extent, tiny2 = tiny * tiny;
    size_t t = 0, ntri = 0;
    double vol = 0.0;   /* six times the enclosed volume, over the live triangles */
    for (int fi = 0; fi < 6; fi++) {
        const face *f = &faces[fi];
        const double sgn = f->reverse ? -1.0 : 1.0;
        for (size_t b = 0; b + 1 < f->nb; b++) {
            const uint32_t *restrict u0 = up + f->base + b * f->na, *restrict u1 = u0 + f->na;
            for (size_t a = 0; a + 1 < f->na; a++, t += 2) {
                double n[2][3], v[2];
                cell_normals(raw.pos, f->base + b * f->na + a, f->na, sgn, n, v);
                const uint32_t r00 = u0[a], r10 = u0[a + 1], r01 = u1[a], r11 = u1[a + 1];
                /* both triangles hold v00 and v11: (v00, v10, v11) and (v00, v11, v01), either winding */
                const int diag = r00 != r11;
                live[t] = diag && r10 != r00 && r10 != r11 && n[0][0] * n[0][0] + n[0][1] * n[0][1] + n[0][2] * n[0][2] > tiny2;
                live[t + 1] = diag && r01 != r00 && r01 != r11 && n[1][0] * n[1][0] + n[1][1] * n[1][1] + n[1][2] * n[1][2] > tiny2;
                if (live[t])
                    vol += v[0], ntri++;
                if (live[t + 1])
                    vol += v[1], ntri++;
            }
        }
    }
    for (int a = 0; a < 3; a++) {
        const face *f0 = &faces[2 * a], *f1 = &faces[2 * a + 1];
        if (seams[a] < 3)
            continue;   /* no triangle of one lies on the other */
        size_t first0 = 0;    /* the faces' first triangles */
        for (int fi = 0; fi < 2 * a; fi++)
            first0 += 2 * (faces[fi].na - 1) * (faces[fi].nb - 1);
        const size_t first1 = first0 + 2 * (f0->na - 1) * (f0->nb - 1);
        for (size_t b = 0; b + 1 < f0->nb; b++)
            for (size_t c = 0; c + 1 < f0->na; c++)
                for (int q = 0; q < 2; q++) {
                    const size_t k = 2 * (b * (f0->na - 1) + c) + (size_t)q;
                    if (!live[first0 + k] || !live[first1 + k])
                        continue;
                    uint32_t s0[3], s1[3], r0[3], r1[3];
                    cell_tri(f0, c, b, q, s0);
                    cell_tri(f1, c, b, q, s1);
                    for (int i = 0; i < 3; i++)
                        s0[i] = up[s0[i]], s1[i] = up[s1[i]];
                    if (sorted(s0, r0) != sorted(s1, r1) && memcmp(r0, r1, sizeof r0) == 0) {
                        live[first0 + k] = live[first1 + k] = 0;
                        double n[2][3], v0[2], v1[2];
                        cell_normals(raw.pos, f0->base + b * f0->na + c, f0->na, f0->reverse ? -1.0 : 1.0, n, v0);
                        cell_normals(raw.pos, f1->base + b * f1->na + c, f1->na, f1->reverse ? -1.0 : 1.0, n, v1);
                        vol -= v0[q] + v1[q];
                        ntri -= 2;
                    }
                }
    }

    /* 4. Outward: the enclosed volume (summed in 3) must be positive. */
    const int flip = vol < 0.0;

    /* 5. Vertices, (point, face) pairs, made in the order the face's triangles first use them, at the
     * sample that first does; a second sample of the face at the vertex's point makes it a collapsed
     * row's point, whose normal comes from its triangles. */
    out->pos = malloc(3 * nraw * sizeof *out->pos);
    out->nrm = malloc(3 * nraw * sizeof *out->nrm);
    out->detj = malloc(nraw * sizeof *out->detj);
    out->weld = malloc(nraw * sizeof *out->weld);
    out->tri = malloc((3 * ntri + 1) * sizeof *out->tri);
    vsam = malloc(nraw * sizeof *vsam);
    if (!out->pos || !out->nrm || !out->detj || !out->weld || !out->tri || !vsam)
        goto done;
    memset(pid, 0xff, nraw * sizeof *pid);
    size_t nv = 0, npos = 0, k3 = 0, tri_of[7] = { 0 };
    int has_nan[6] = { 0 };
    t = 0;
    for (int fi = 0; fi < 6; fi++) {
        if (stopped(cancel)) {
            cancelled = 1;
            goto done;
        }
        const face *f = &faces[fi];
        const size_t end = f->base + f->na * f->nb, first = nv;
        const double sgn = (f->reverse ? -1.0 : 1.0) * (flip ? -1.0 : 1.0);
        for (size_t k = f->base; k < end; k++)
            vof[up[k]] = UINT32_MAX;
        uint32_t off[2][3];   /* the corners of a cell's triangles, from its v00, as wound in the mesh */
        for (int q = 0; q < 2; q++) {
            cell_tri(f, 0, 0, q, off[q]);
            for (int i = 0; i < 3; i++)
                off[q][i] -= (uint32_t)f->base;
            if (flip) {
                const uint32_t x = off[q][1];
                off[q][1] = off[q][2], off[q][2] = x;
            }
        }
        for (size_t b = 0; b + 1 < f->nb; b++)
            for (size_t a = 0; a + 1 < f->na; a++)
                for (int q = 0; q < 2; q++, t++) {
                    if (!live[t])
                        continue;
                    const uint32_t v00 = (uint32_t)(f->base + b * f->na + a);
                    const uint32_t s[3] = { v00 + off[q][0], v00 + off[q][1], v00 + off[q][2] };
                    for (int i = 0; i < 3; i++) {
                        const uint32_t r = up[s[i]];
                        if (vof[r] == UINT32_MAX) {
                            const uint32_t v = (uint32_t)nv++, k = s[i];
                            vof[r] = v;
                            vsam[v] = k;
                            if (pid[r] == UINT32_MAX)
                                pid[r] = (uint32_t)npos++;
                            out->weld[v] = pid[r];
                            memcpy(out->pos + 3 * v, raw.pos + 3 * r, 3 * sizeof(float));
                            out->detj[v] = raw.detj[k];
                            const float *n = raw.nrm + 3 * k;
                            const double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
                            has_nan[fi] |= !(len > tiny);
                            for (int c = 0; c < 3; c++)
                                out->nrm[3 * v + c] = len > tiny ? (float)(sgn * n[c] / len) : NAN;
                        }
                        out->tri[k3++] = vof[r];
                    }
                }
        for (size_t k = f->base; k < end; k++) {
            const uint32_t v = vof[up[k]];
            if (v != UINT32_MAX && v >= first && vsam[v] != k)
                out->nrm[3 * v] = NAN, has_nan[fi] = 1;
        }
        tri_of[fi + 1] = k3 / 3;
    }
    /* Area-weighted normals for the vertices marked NaN, from their faces' triangles. */
    acc = calloc(3 * nv + 1, sizeof *acc);
    if (!acc)
        goto done;
    for (int fi = 0; fi < 6; fi++)
        for (size_t tt = has_nan[fi] ? tri_of[fi] : tri_of[fi + 1]; tt < tri_of[fi + 1]; tt++) {
            const uint32_t *w = &out->tri[3 * tt];
            if (!isnan(out->nrm[3 * w[0]]) && !isnan(out->nrm[3 * w[1]]) && !isnan(out->nrm[3 * w[2]]))
                continue;
            double n[3];
            tri_normal(out->pos + 3 * w[0], out->pos + 3 * w[1], out->pos + 3 * w[2], n);
            for (int i = 0; i < 3; i++)
                for (int c = 0; c < 3; c++)
                    acc[3 * w[i] + c] += n[c];
        }
    for (int c = 0; c < 3; c++)
        out->min[c] = INFINITY, out->max[c] = -INFINITY;
    for (size_t v = 0; v < nv; v++) {
        if (isnan(out->nrm[3 * v])) {
            const double *n = acc + 3 * v, len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (int c = 0; c < 3; c++)
                out->nrm[3 * v + c] = len > 0 ? (float)(n[c] / len) : (c == 2 ? 1.0f : 0.0f);
        }
        for (int c = 0; c < 3; c++) {
            const float x = out->pos[3 * v + c];
            out->min[c] = x < out->min[c] ? x : out->min[c];
            out->max[c] = x > out->max[c] ? x : out->max[c];
        }
    }
    out->nverts = nv;
    out->ntris = ntri;
    out->npos = npos;
    /* Down to what is used (realloc to a smaller size keeps the block where it cannot move it). */
    float *p;
    uint32_t *w;
    if ((p = realloc(out->pos, (3 * nv + 1) * sizeof *p)))
        out->pos = p;
    if ((p = realloc(out->nrm, (3 * nv + 1) * sizeof *p)))
        out->nrm = p;
    if ((p = realloc(out->detj, (nv + 1) * sizeof *p)))
        out->detj = p;
    if ((w = realloc(out->weld, (nv + 1) * sizeof *w)))
        out->weld = w;
    rc = 0;
done:
    if (rc) {
        api_mesh_free(out);
        api_fail(err, cancelled ? API_ERR_CANCELLED : why_status, "", "%s", cancelled ? "cancelled" : why);
    }
    free(raw.pos);
    free(raw.nrm);
    free(raw.detj);
    free(up);
    free(vof);
    free(pid);
    free(live);
    free(acc);
    free(vsam);
    return rc;
}
