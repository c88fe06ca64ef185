/*
 * mesh.c: the closed skin of a solid (mesh.h).
 *
 * DESIGN
 * The skin is the image of the parameter cube's boundary, sampled on the
 * lattice i/(n-1) of each axis, so its topology is known before any position
 * is: no position is hashed or searched for.
 * 1. The two faces of each axis are sampled on one grid (pde_grid; u = 0, 1
 *    as a grid of nu = 2, which core fills column-wise), straight into the
 *    mesh's arrays, and triangulated, wound so that each face's normal points
 *    out of the parameter cube. Positions first, with the closed form's
 *    first derivatives (normal, det J) for u = 0, 1 only (their narrow grid's
 *    row coefficients serve both) but for their rows that are one point; the
 *    other faces' derivatives, and those rows', after step 3, on the faces
 *    that keep a triangle (fig4a drops three of six, and takes no derivative
 *    of its u = 0, whose every row is one point). A joined
 *    sample then takes its root's position, so every copy of a point has the
 *    same bits.
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
 *    coincide). A face left with no triangle is not visited again.
 * 4. If the enclosed volume comes out negative (the parametrisation reverses
 *    orientation, as x = u sin 2pi v, y = u cos 2pi v does), every triangle
 *    is flipped.
 * 5. Vertices are (point, face) pairs, made face by face in sample order and
 *    packed down over the samples' own data (a vertex never comes after its
 *    sample), so the mesh's arrays are the sampling's. A vertex's normal is
 *    the face's x_a x x_b from the closed form, and its det J is
 *    det(x_u, x_v, x_w); where a vertex joins several samples of its face,
 *    or x_a x x_b vanishes (a collapsed row's point), the normal is the
 *    area-weighted mean of its triangles' instead. A sample joined with no
 *    other (almost all) skips every map: its vertex and position id are the
 *    next ones.
 * Every pass is linear in the samples, and the hot ones take 2 to 16 samples
 * a step in SSE2 where it is, with the scalar code's arithmetic, so the bits
 * do not depend on it: neighbour and seam tests (a run of near samples costs
 * a join each, no further test), bounds, x_a x x_b and det J, the roots (a
 * sample that is its own root stores nothing), the live test (4 cells whose
 * triangles all have three points; 4 of which none has, a collapsed row's,
 * cost a test and no more), the vertices (4 samples used and joined
 * with no other) and the triangles (4 cells whose 8 triangles live). The
 * scalar code handles the rest: collapsed rows, seams, opposite faces, edges.
 * Memory: one block for the mesh (32 bytes a sample, 12 a triangle) and one
 * of scratch (13 bytes a sample), both kept for the next build
 * (api_mesh_free): on a server, builds after the first touch no fresh page.
 */
#include <math.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

#if defined(__SSE2__)
/* Two points' x, y, z (lanes 0 and 1 of c[0..2]) rounded to float, to o[0..5] as x0 y0 z0 x1 y1 z1. */
static inline void store2_xyz(float *o, const __m128d c[3])
{
    const __m128 fz = _mm_cvtpd_ps(c[2]), xy = _mm_unpacklo_ps(_mm_cvtpd_ps(c[0]), _mm_cvtpd_ps(c[1]));   /* x0 y0 x1 y1 */
    _mm_storel_pi((__m64 *)o, xy), _mm_store_ss(o + 2, fz);
    _mm_storeh_pi((__m64 *)(o + 3), xy), _mm_store_ss(o + 5, _mm_shuffle_ps(fz, fz, 1));
}
#endif

/* Bounds of n floats of interleaved x, y, z: lanes l of lo12, hi12 hold axis l % 3 (4 points, 12
 * floats, a step); sum12 turns NaN on any NaN or infinity. */
static void row_bounds(const float *restrict p, size_t n, float lo12[12], float hi12[12], float sum12[12])
{
    size_t j = 0;
#if defined(__SSE2__)
    __m128 lo[3], hi[3], sm[3];
    const __m128 zero = _mm_setzero_ps();
    for (int i = 0; i < 3; i++)
        lo[i] = _mm_loadu_ps(lo12 + 4 * i), hi[i] = _mm_loadu_ps(hi12 + 4 * i), sm[i] = _mm_loadu_ps(sum12 + 4 * i);
    for (; j + 12 <= n; j += 12)
        for (int i = 0; i < 3; i++) {
            const __m128 x = _mm_loadu_ps(p + j + 4 * (size_t)i);
            lo[i] = _mm_min_ps(x, lo[i]);   /* x < lo ? x : lo, as below */
            hi[i] = _mm_max_ps(x, hi[i]);
            sm[i] = _mm_add_ps(sm[i], _mm_mul_ps(x, zero));
        }
    for (int i = 0; i < 3; i++)
        _mm_storeu_ps(lo12 + 4 * i, lo[i]), _mm_storeu_ps(hi12 + 4 * i, hi[i]), _mm_storeu_ps(sum12 + 4 * i, sm[i]);
#endif
    for (; j < n; j++) {
        const float x = p[j];
        lo12[j % 3] = x < lo12[j % 3] ? x : lo12[j % 3];
        hi12[j % 3] = x > hi12[j % 3] ? x : hi12[j % 3];
        sum12[j % 3] += x * 0.0f;
    }
}

/* What the faces' sampling shares: the grids, the plane's or row's buffers and the bounds so far. One grid holds
 * both faces of an axis, so each plane's and row's coefficients serve both: u = 0, 1 is a grid of nu = 2 (a plane
 * of w, rows along v), v = 0, 1 one of nv = 2 (rows 0 and 1 of a plane); w = 0, 1 are the (u, v) grid's planes 0
 * and 1, one row at a time. */
typedef struct {
    pde_grid *g[4];              /* u = 0, 1; v = 0, 1; w = 0; w = 1 (each its own h) */
    double *us;                  /* the lattice of u, then of v */
    float *x, *xd[3];            /* x, then x_u, x_v, x_w, 6 max(nu, nv) floats each */
    float lo12[12], hi12[12], sum12[12];
    uint8_t *point[2];           /* u = 0, 1: row b (w) is one point, its derivatives not yet taken (one_point) */
} sampler;

static void sampler_free(sampler *sp)
{
    for (int i = 0; i < 4; i++)
        pde_grid_free(sp->g[i]);
    free(sp->us);
    free(sp->x);
    free(sp->point[0]);
}

/* 0, or -1 out of memory (sp then holds nothing to free). */
static int sampler_init(sampler *sp, const pde_solution *sol, const unsigned res[3])
{
    const size_t nu = res[0], nv = res[1], nmax = nu > nv ? nu : nv, m = 6 * nmax;
    memset(sp, 0, sizeof *sp);
    sp->us = malloc((nu + nv) * sizeof *sp->us);
    sp->x = malloc(4 * m * sizeof *sp->x);
    sp->point[0] = calloc(2 * (size_t)res[2], 1);
    if (!sp->us || !sp->x || !sp->point[0])
        goto fail;
    sp->point[1] = sp->point[0] + res[2];
    double *vs = sp->us + nu;
    for (size_t i = 0; i < nu; i++)
        sp->us[i] = sample(i, nu);
    for (size_t j = 0; j < nv; j++)
        vs[j] = sample(j, nv);
    const double ends[2] = { 0.0, 1.0 };
    if (pde_grid_create(sol, ends, 2, vs, nv, &sp->g[0]) != PDE_OK ||
        pde_grid_create(sol, sp->us, nu, ends, 2, &sp->g[1]) != PDE_OK ||
        pde_grid_create(sol, sp->us, nu, vs, nv, &sp->g[2]) != PDE_OK ||
        pde_grid_create(sol, sp->us, nu, vs, nv, &sp->g[3]) != PDE_OK)
        goto fail;
    for (int i = 0; i < 3; i++)
        sp->xd[i] = sp->x + (size_t)(i + 1) * m;
    for (int l = 0; l < 12; l++)
        sp->lo12[l] = INFINITY, sp->hi12[l] = -INFINITY;
    return 0;
fail:
    sampler_free(sp);
    memset(sp, 0, sizeof *sp);
    return -1;
}

/*
 * Whether the n points x, y, z of p are one point by ==, so 0 and -0 are one: a row the map collapses exactly
 * (u = 0 of the circular examples). Its samples are then near for any eps, so step 2 joins them all, and
 * every cell it borders has a triangle with a repeated point. Mostly answered by the first two points.
 */
static int one_point(const float *p, size_t n)
{
    size_t a = 1;
#if defined(__SSE2__)
    if (n >= 5 && p[3] == p[0] && p[4] == p[1] && p[5] == p[2]) {   /* 4 points a step against p[0] repeated */
        const __m128 c0 = _mm_setr_ps(p[0], p[1], p[2], p[0]), c1 = _mm_setr_ps(p[1], p[2], p[0], p[1]),
                     c2 = _mm_setr_ps(p[2], p[0], p[1], p[2]);
        for (; a + 4 <= n; a += 4) {
            const float *q = p + 3 * a;
            const __m128 e = _mm_and_ps(_mm_and_ps(_mm_cmpeq_ps(_mm_loadu_ps(q), c0), _mm_cmpeq_ps(_mm_loadu_ps(q + 4), c1)),
                                        _mm_cmpeq_ps(_mm_loadu_ps(q + 8), c2));
            if (_mm_movemask_ps(e) != 15)
                return 0;
        }
    }
#endif
    for (; a < n; a++)
        if (p[3 * a] != p[0] || p[3 * a + 1] != p[1] || p[3 * a + 2] != p[2])
            return 0;
    return 1;
}

/*
 * Face f's row b from the sampler's buffers, where its sample a is point first + a step. The positions pass
 * (derivs 0) writes positions and their bounds; the derivatives pass x_a x x_b in double (the products of
 * floats are exact) and det J.
 */
static void emit_row(const face *f, size_t b, size_t first, size_t step, int derivs, sampler *sp, samples *out)
{
    int o[2];
    face_axes(f, o);
    const int axis = f->axis;
    const size_t na = f->na, s0 = f->base + b * na;
    float *restrict pos = out->pos + 3 * s0, *restrict nrm = out->nrm + 3 * s0, *restrict dj = out->detj + s0;
    if (!derivs) {
        const float *restrict x = sp->x;
        for (size_t a = 0; a < na; a++) {
            const size_t e = 3 * (first + a * step);
            pos[3 * a] = x[e], pos[3 * a + 1] = x[e + 1], pos[3 * a + 2] = x[e + 2];
        }
        row_bounds(pos, 3 * na, sp->lo12, sp->hi12, sp->sum12);
        return;
    }
    const float *restrict ta0 = sp->xd[o[0]], *restrict tb0 = sp->xd[o[1]], *restrict tc0 = sp->xd[axis];
    const float sg = axis == 1 ? -1.0f : 1.0f;
    size_t a = 0;
#if defined(__SSE2__)
    for (; a + 2 <= na; a += 2) {   /* two samples in double lanes, the loop's products and sums below */
        const size_t e = 3 * (first + a * step), e1 = e + 3 * step;
        __m128d A[3], B[3], C[3], n[3];
        for (int k = 0; k < 3; k++)
            A[k] = _mm_set_pd(ta0[e1 + k], ta0[e + k]), B[k] = _mm_set_pd(tb0[e1 + k], tb0[e + k]),
            C[k] = _mm_set_pd(tc0[e1 + k], tc0[e + k]);
        for (int k = 0; k < 3; k++) {
            const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
            n[k] = _mm_sub_pd(_mm_mul_pd(A[k1], B[k2]), _mm_mul_pd(A[k2], B[k1]));
        }
        const __m128d det = _mm_add_pd(_mm_add_pd(_mm_mul_pd(n[0], C[0]), _mm_mul_pd(n[1], C[1])), _mm_mul_pd(n[2], C[2]));
        store2_xyz(nrm + 3 * a, n);
        _mm_storel_pi((__m64 *)(dj + a), _mm_mul_ps(_mm_set1_ps(sg), _mm_cvtpd_ps(det)));
    }
#endif
    for (; a < na; a++) {
        const size_t e = 3 * (first + a * step);
        const float *ta = ta0 + e, *tb = tb0 + e, *tc = tc0 + e;
        double n[3] = { (double)ta[1] * tb[2] - (double)ta[2] * tb[1], (double)ta[2] * tb[0] - (double)ta[0] * tb[2],
                        (double)ta[0] * tb[1] - (double)ta[1] * tb[0] };
        /* det(x_u, x_v, x_w) = (x_a x x_b) . x_axis, times the sign of (a, b, axis)'s order */
        double det = n[0] * tc[0] + n[1] * tc[1] + n[2] * tc[2];
        nrm[3 * a] = (float)n[0], nrm[3 * a + 1] = (float)n[1], nrm[3 * a + 2] = (float)n[2];
        dj[a] = sg * (float)det;
    }
}

/*
 * The six faces, na x nb samples each, fast index first, from the closed form. The positions pass (keep NULL)
 * samples x on every face, and x_u, x_v, x_w on u = 0, 1; the derivatives pass x_u, x_v, x_w on the other
 * faces with keep[face] != 0 (those that kept a triangle: such a face dropped whole costs no derivative).
 * Polled before each face row. 1 when cancelled.
 */
static int sample_faces(sampler *sp, const face f[6], const unsigned res[3], const size_t *keep,
                        const pde_cancel *cancel, samples *out)
{
    const size_t nu = res[0], nv = res[1];
    const int derivs = keep != NULL;
    float *x = derivs ? NULL : sp->x, *xu = derivs ? sp->xd[0] : NULL, *xv = derivs ? sp->xd[1] : NULL,
          *xw = derivs ? sp->xd[2] : NULL;
    int rc = 0;
    /* u = 0, 1 and v = 0, 1, plane by plane */
    for (size_t b = 0; b < res[2] && !rc; b++) {
        const double w = sample(b, res[2]);
        for (int axis = 0; axis < 2 && !rc; axis++) {
            /* u = 0, 1 take their derivatives with their positions: a narrow grid's cost is its row
             * coefficients, and x's serve x_u too, so one pass of all four costs less than two passes; but
             * a row that is one point (one_point) takes them in the derivatives pass, and only if its face
             * keeps a triangle (then not every row is one point): fig4a's u = 0 takes none */
            const int with_d = axis == 0;
            unsigned sides = 3;
            if (derivs) {
                sides = with_d ? (unsigned)(keep[0] && sp->point[0][b]) | (unsigned)(keep[1] && sp->point[1][b]) << 1
                               : (unsigned)(keep[2 * axis] != 0) | (unsigned)(keep[2 * axis + 1] != 0) << 1;
                if (!sides)
                    continue;
            }
            if ((rc = stopped(cancel)))
                break;
            if (with_d)
                pde_grid_plane_d(sp->g[axis], w, x, sp->xd[0], sp->xd[1], sp->xd[2]);
            else
                pde_grid_plane_d(sp->g[axis], w, x, xu, xv, xw);
            for (int side = 0; side < 2; side++) {
                if (!(sides >> side & 1))
                    continue;
                if (side && (rc = stopped(cancel)))
                    break;
                /* u = 0, 1: (v, u) interleaved; v = 0, 1: by rows */
                if (axis == 0) {
                    const face *fs = &f[side];
                    if (!derivs) {
                        emit_row(fs, b, (size_t)side, 2, 0, sp, out);
                        if (one_point(out->pos + 3 * (fs->base + b * fs->na), fs->na)) {
                            sp->point[side][b] = 1;
                            continue;
                        }
                    }
                    emit_row(fs, b, (size_t)side, 2, 1, sp, out);
                } else
                    emit_row(&f[2 + side], b, (size_t)side * nu, 1, derivs, sp, out);
            }
        }
    }
    /* w = 0, 1, a row at a time */
    for (size_t b = 0; b < nv && !rc; b++)
        for (int side = 0; side < 2; side++) {
            if (derivs && !keep[4 + side])
                continue;
            if ((rc = stopped(cancel)))
                break;
            /* a row of w = 0, 1 is a face row in the mesh's layout: positions straight to the mesh */
            float *row = derivs ? NULL : out->pos + 3 * (f[4 + side].base + b * f[4 + side].na);
            pde_grid_rows(sp->g[2 + side], side ? 1.0 : 0.0, b, b + 1, row, xu, xv, xw);
            if (derivs)
                emit_row(&f[4 + side], b, 0, 1, derivs, sp, out);
            else
                row_bounds(row, 3 * f[4 + side].na, sp->lo12, sp->hi12, sp->sum12);
        }
    if (!derivs)
        for (int l = 0; l < 12; l++) {
            out->lo[l % 3] = sp->lo12[l] < out->lo[l % 3] ? sp->lo12[l] : out->lo[l % 3];
            out->hi[l % 3] = sp->hi12[l] > out->hi[l % 3] ? sp->hi12[l] : out->hi[l % 3];
            out->bad |= sp->sum12[l] != 0.0f;
        }
    return rc;
}

/* ---- memory: two blocks kept for the next build ---- */

/*
 * A mesh takes a block for itself (pos, nrm, detj, weld, tri) and one of scratch; api_mesh_free and the
 * end of a build give them back to two process-wide slots (atomic, so builds on any threads may share
 * them), from which the next build takes them: fresh pages cost a page fault each (about 12 us a 4 KiB
 * page on our VMs, more than the mesh's arithmetic), and malloc returns big blocks to the system. At
 * most SPARE_MAX bytes a slot are kept; api_mesh_release_spares() frees them.
 */
enum { SPARES = 2 };
#define SPARE_MAX ((size_t)64 << 20)
typedef struct {
    size_t cap;
    size_t pad;   /* the data 16-byte aligned */
} block_hdr;
static _Atomic(block_hdr *) spare[SPARES];

static void *block_get(size_t n)
{
    for (int i = 0; i < SPARES; i++) {
        block_hdr *h = atomic_exchange(&spare[i], NULL);
        if (h && h->cap >= n)
            return h + 1;
        free(h);
    }
    block_hdr *h = malloc(sizeof *h + n);
    if (!h)
        return NULL;
    h->cap = n;
    return h + 1;
}

static void block_put(void *p)
{
    if (!p)
        return;
    block_hdr *h = (block_hdr *)p - 1;
    for (int i = 0; i < SPARES && h && h->cap <= SPARE_MAX; i++)
        h = atomic_exchange(&spare[i], h);   /* the one it displaces tries the next slot */
    free(h);
}

void api_mesh_release_spares(void)
{
    for (int i = 0; i < SPARES; i++)
        free(atomic_exchange(&spare[i], NULL));
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

/* Within eps on every axis; in float, where the difference of two close floats is exact. */
static inline int near(const float *p, const float *q, float eps)
{
    return (fabsf(p[0] - q[0]) <= eps) & (fabsf(p[1] - q[1]) <= eps) & (fabsf(p[2] - q[2]) <= eps);
}

/* Joins sample ip + i with iq + i for every i < n where p + 3i and q + 3i are near, in increasing i; returns
 * how many. 4 samples (12 floats) a step where SSE2 is, with near's arithmetic; a run of near samples (a
 * collapsed row, a seam) costs a join each and no other test. */
static size_t join_near(uint32_t *up, const float *p, const float *q, uint32_t ip, uint32_t iq, size_t n, float eps)
{
    size_t i = 0, joined = 0;
#if defined(__SSE2__)
    const __m128 e = _mm_set1_ps(eps), abs = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    for (; i + 4 <= n; i += 4) {
        const float *x = p + 3 * i, *y = q + 3 * i;
        unsigned m = 0;
        for (int k = 0; k < 3; k++) {
            const __m128 d = _mm_and_ps(_mm_sub_ps(_mm_loadu_ps(x + 4 * k), _mm_loadu_ps(y + 4 * k)), abs);
            m |= (unsigned)_mm_movemask_ps(_mm_cmple_ps(d, e)) << (4 * k);
        }
        m &= (m >> 1) & (m >> 2) & 01111u;   /* bit 3j: all three axes of sample i + j */
        if (m == 01111u) {   /* a run: a collapsed row's, a seam's */
            for (uint32_t j = 0; j < 4; j++)
                join(up, ip + (uint32_t)i + j, iq + (uint32_t)i + j);
            joined += 4;
            continue;
        }
        for (; m; m &= m - 1, joined++) {
            const uint32_t j = (uint32_t)(i + (size_t)__builtin_ctz(m) / 3);
            join(up, ip + j, iq + j);
        }
    }
#endif
    for (; i < n; i++)
        if (near(p + 3 * i, q + 3 * i, eps))
            join(up, ip + (uint32_t)i, iq + (uint32_t)i), joined++;
    return joined;
}

/* Joins samples i0 .. i0 + n - 1 into one set: the joins of each with the next, the root kept at hand. */
static void join_chain(uint32_t *up, uint32_t i0, size_t n)
{
    uint32_t r = find(up, i0);
    for (uint32_t i = 1; i < (uint32_t)n; i++) {
        const uint32_t s = find(up, i0 + i);
        if (s < r)
            up[r] = s, r = s;
        else if (r < s)
            up[s] = r;
    }
}

/* The first k' >= k below end with fl[k'] & bits, or end; 16 flags a step where SSE2 is. */
static size_t next_flag(const uint8_t *fl, size_t k, size_t end, uint8_t bits)
{
#if defined(__SSE2__)
    const __m128i b = _mm_set1_epi8((char)bits), zero = _mm_setzero_si128();
    for (; k + 16 <= end; k += 16) {
        const __m128i x = _mm_and_si128(_mm_loadu_si128((const __m128i *)(fl + k)), b);
        const unsigned m = (unsigned)_mm_movemask_epi8(_mm_cmpeq_epi8(x, zero)) ^ 0xffffu;
        if (m)
            return k + (size_t)__builtin_ctz(m);
    }
#endif
    for (; k < end && !(fl[k] & bits); k++)
        ;
    return k;
}

#if defined(__SSE2__)
/*
 * Samples k..k+3 to vertices v..v+3 (v <= k) as api_mesh_build's vertex loop moves them: position and
 * det J copied, x_a x x_b times sgn / |x_a x x_b|, in double two lanes at a time with its arithmetic.
 * Returns 0 and writes nothing where some |x_a x x_b| <= tiny (the loop's fallback).
 */
static inline int plain4(float *P, float *N, float *J, size_t k, size_t v, double sgn, double tiny)
{
    const float *n = N + 3 * k;
    __m128d x[2], y[2], z[2], len[2];
    for (int h = 0; h < 2; h++, n += 6) {
        x[h] = _mm_set_pd(n[3], n[0]), y[h] = _mm_set_pd(n[4], n[1]), z[h] = _mm_set_pd(n[5], n[2]);
        len[h] = _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(x[h], x[h]), _mm_mul_pd(y[h], y[h])), _mm_mul_pd(z[h], z[h])));
    }
    const __m128d t = _mm_set1_pd(tiny);
    if ((_mm_movemask_pd(_mm_cmpgt_pd(len[0], t)) & _mm_movemask_pd(_mm_cmpgt_pd(len[1], t))) != 3)
        return 0;
    const __m128 p0 = _mm_loadu_ps(P + 3 * k), p1 = _mm_loadu_ps(P + 3 * k + 4), p2 = _mm_loadu_ps(P + 3 * k + 8);
    _mm_storeu_ps(P + 3 * v, p0), _mm_storeu_ps(P + 3 * v + 4, p1), _mm_storeu_ps(P + 3 * v + 8, p2);
    _mm_storeu_ps(J + v, _mm_loadu_ps(J + k));
    for (int h = 0; h < 2; h++) {
        const __m128d s = _mm_div_pd(_mm_set1_pd(sgn), len[h]);
        const __m128d sn[3] = { _mm_mul_pd(s, x[h]), _mm_mul_pd(s, y[h]), _mm_mul_pd(s, z[h]) };
        store2_xyz(N + 3 * (v + 2 * (size_t)h), sn);
    }
    return 1;
}
#endif

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

/*
 * Cell v00 (a sample index; na samples to a row) of a face: its triangles' normals (twice their area
 * vectors) in the unreversed winding, (v00, v10, v11) and (v00, v11, v01), and six times the signed
 * volume of the tetrahedra (0, triangle) in the face's winding (sgn -1 when it reverses), as
 * x_00 . n, so the volume costs a dot product on the normal. In double, where the products of float
 * differences are exact, so a collapsed triangle's area is 0.
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

/*
 * The live test of a cell's triangles q in want (bit q) with cell_normals' arithmetic: a triangle lives
 * when |n_q|^2 > tiny2; adds the live ones' volumes to *vol. With SSE2 both at once, lane q holding
 * n_q = e_q x d, where e_0 = e1 and e_1 = -e2 (d x e2 = -e2 x d, the same products and roundings).
 */
static inline unsigned cell_live(const float *restrict pos, size_t v00, size_t na, double sgn, double tiny2,
                                 unsigned want, double *vol)
{
#if defined(__SSE2__)
    const float *p = pos + 3 * v00, *p10 = p + 3, *p01 = p + 3 * na, *p11 = p01 + 3;
    __m128d A[3], D[3];
    for (int k = 0; k < 3; k++) {
        const double p0 = p[k];
        A[k] = _mm_set_pd(p0 - (double)p01[k], (double)p10[k] - p0);
        D[k] = _mm_set1_pd((double)p11[k] - p0);
    }
    const __m128d nx = _mm_sub_pd(_mm_mul_pd(A[1], D[2]), _mm_mul_pd(A[2], D[1]));
    const __m128d ny = _mm_sub_pd(_mm_mul_pd(A[2], D[0]), _mm_mul_pd(A[0], D[2]));
    const __m128d nz = _mm_sub_pd(_mm_mul_pd(A[0], D[1]), _mm_mul_pd(A[1], D[0]));
    const __m128d nn = _mm_add_pd(_mm_add_pd(_mm_mul_pd(nx, nx), _mm_mul_pd(ny, ny)), _mm_mul_pd(nz, nz));
    const unsigned live = (unsigned)_mm_movemask_pd(_mm_cmpgt_pd(nn, _mm_set1_pd(tiny2))) & want;
    if (live) {
        const __m128d d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(_mm_set1_pd(p[0]), nx), _mm_mul_pd(_mm_set1_pd(p[1]), ny)),
                                     _mm_mul_pd(_mm_set1_pd(p[2]), nz));
        double v[2];
        _mm_storeu_pd(v, _mm_mul_pd(_mm_set1_pd(sgn), d));
        *vol += (live & 1 ? v[0] : 0.0) + (live & 2 ? v[1] : 0.0);
    }
    return live;
#else
    double n[2][3], v[2];
    cell_normals(pos, v00, na, sgn, n, v);
    const unsigned live = ((unsigned)(n[0][0] * n[0][0] + n[0][1] * n[0][1] + n[0][2] * n[0][2] > tiny2) |
                           (unsigned)(n[1][0] * n[1][0] + n[1][1] * n[1][1] + n[1][2] * n[1][2] > tiny2) << 1) & want;
    *vol += (live & 1 ? v[0] : 0.0) + (live & 2 ? v[1] : 0.0);
    return live;
#endif
}

#if defined(__SSE2__)
/*
 * cell_live for the 4 cells v00..v00+3 of a row, both triangles wanted. Returns their live triangles, bit
 * 4h + 2q + c for triangle q of cell 2h + c (0xff: all 8), and the volumes: v[h][q][c] for that triangle,
 * s[i] = v of cell i's triangle 0 + its triangle 1 (what the caller adds where both live), to be added to
 * the total in cell order. Lanes are cells, two at a time; the products and sums are cell_normals' (d x e2 =
 * -e2 x d: cell_live's lane 1), so the bits are the same.
 */
static inline unsigned cells4_live(const float *restrict pos, size_t v00, size_t na, double sgn, double tiny2,
                                   double v[2][2][2], double s[4])
{
    const __m128d t2 = _mm_set1_pd(tiny2), sg = _mm_set1_pd(sgn);
    unsigned live = 0;
    for (int h = 0; h < 2; h++) {
        const float *p = pos + 3 * (v00 + 2 * (size_t)h), *q = p + 3 * na;
        __m128d p0[3], e1[3], d[3], e2[3];
        for (int k = 0; k < 3; k++) {
            p0[k] = _mm_set_pd(p[3 + k], p[k]);
            e1[k] = _mm_sub_pd(_mm_set_pd(p[6 + k], p[3 + k]), p0[k]);
            d[k] = _mm_sub_pd(_mm_set_pd(q[6 + k], q[3 + k]), p0[k]);
            e2[k] = _mm_sub_pd(_mm_set_pd(q[3 + k], q[k]), p0[k]);
        }
        __m128d n[2][3], vq[2];
        for (int k = 0; k < 3; k++) {
            const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
            n[0][k] = _mm_sub_pd(_mm_mul_pd(e1[k1], d[k2]), _mm_mul_pd(e1[k2], d[k1]));
            n[1][k] = _mm_sub_pd(_mm_mul_pd(d[k1], e2[k2]), _mm_mul_pd(d[k2], e2[k1]));
        }
        for (int t = 0; t < 2; t++) {
            const __m128d *x = n[t];
            const __m128d nn = _mm_add_pd(_mm_add_pd(_mm_mul_pd(x[0], x[0]), _mm_mul_pd(x[1], x[1])), _mm_mul_pd(x[2], x[2]));
            live |= (unsigned)_mm_movemask_pd(_mm_cmpgt_pd(nn, t2)) << (4 * h + 2 * t);
            const __m128d dot = _mm_add_pd(_mm_add_pd(_mm_mul_pd(p0[0], x[0]), _mm_mul_pd(p0[1], x[1])), _mm_mul_pd(p0[2], x[2]));
            vq[t] = _mm_mul_pd(sg, dot);
            _mm_storeu_pd(v[h][t], vq[t]);
        }
        _mm_storeu_pd(s + 2 * h, _mm_add_pd(vq[0], vq[1]));
    }
    return live;
}
#endif

/* The samples of triangle q (0, 1) of cell (a, b) of face f, wound outward of the cube. */
static void cell_tri(const face *f, size_t a, size_t b, int q, uint32_t t[3])
{
    uint32_t v00 = (uint32_t)(f->base + b * f->na + a), v10 = v00 + 1;
    uint32_t v01 = (uint32_t)(v00 + f->na), v11 = v01 + 1;
    t[0] = v00;
    t[1] = q ? (f->reverse ? v01 : v11) : (f->reverse ? v11 : v10);
    t[2] = q ? (f->reverse ? v11 : v01) : (f->reverse ? v10 : v11);
}

#if defined(__SSE2__)
/*
 * Both triangles of the 4 cells whose v00 are samples u[0..3] (u holding vertex ids, na to a row), in
 * the order and windings of the scalar loop in api_mesh_build: per cell (v00, v10, v11), (v00, v11, v01),
 * or with swap (v00, v11, v10), (v00, v01, v11). 24 ids to T.
 */
static inline void tri4(uint32_t *T, const uint32_t *u, size_t na, int swap)
{
    const __m128i A = _mm_loadu_si128((const __m128i *)u), B = _mm_loadu_si128((const __m128i *)(u + 1));
    const __m128i C = _mm_loadu_si128((const __m128i *)(u + na)), D = _mm_loadu_si128((const __m128i *)(u + na + 1));
    /* triangles (A, s, t) and (A, p, q) */
    const __m128i s = swap ? D : B, t = swap ? B : D, p = swap ? C : D, q = swap ? D : C;
    const __m128i lo[3] = { _mm_unpacklo_epi32(A, s), _mm_unpacklo_epi32(t, A), _mm_unpacklo_epi32(p, q) };
    const __m128i hi[3] = { _mm_unpackhi_epi32(A, s), _mm_unpackhi_epi32(t, A), _mm_unpackhi_epi32(p, q) };
    const __m128i *h[2] = { lo, hi };
    for (int i = 0; i < 2; i++, T += 12) {   /* cells 0, 1 from the low halves, 2, 3 from the high */
        const __m128i *x = h[i];   /* x[0] = A0 s0 A1 s1, x[1] = t0 A0 t1 A1, x[2] = p0 q0 p1 q1 */
        _mm_storeu_si128((__m128i *)T, _mm_unpacklo_epi64(x[0], x[1]));
        _mm_storeu_si128((__m128i *)(T + 4),
                         _mm_castpd_si128(_mm_shuffle_pd(_mm_castsi128_pd(x[2]), _mm_castsi128_pd(x[0]), 2)));
        _mm_storeu_si128((__m128i *)(T + 8), _mm_unpackhi_epi64(x[1], x[2]));
    }
}
#endif

void api_mesh_free(api_mesh *m)
{
    if (!m)
        return;
    block_put(m->pos);   /* the one block: pos, nrm, detj, weld, tri */
    memset(m, 0, sizeof *m);
}

/* A sample's flags: joined with another sample; used by a live triangle of its face; on a cell's v00,
 * which of the cell's two triangles live; its vertex's normal marked for its triangles' mean. */
enum { SHARED = 1, USED = 2, LIVE0 = 4, LIVE1 = 8, NANV = 16 };

/* Cell v00's live triangles (bits 0, 1) to its flags: LIVE0, LIVE1 on v00; USED on the corners they use. */
static inline void mark_live(uint8_t *fl, size_t na, unsigned live)
{
    fl[0] |= (uint8_t)(live * LIVE0 | USED), fl[na + 1] |= USED;
    fl[1] |= (uint8_t)(live & 1 ? USED : 0), fl[na] |= (uint8_t)(live & 2 ? USED : 0);
}

/* fl[0..3] |= the bytes of x. */
static inline void or4(uint8_t *fl, uint32_t x)
{
    uint32_t y;
    memcpy(&y, fl, 4);
    y |= x;
    memcpy(fl, &y, 4);
}

/* vof[r] while face f's vertices are made: the face has one (TAG1) or several (TAG2) samples at root r
 * and no vertex there yet; vertex ids of earlier faces are below the face's first, tags above any id. */
#define TAG1(f) (UINT32_MAX - 2u * (uint32_t)(f) - 1u)
#define TAG2(f) (UINT32_MAX - 2u * (uint32_t)(f) - 2u)
#define TAGMIN (UINT32_MAX - 13u)

/* Growable accumulators of the area-weighted normals of the vertices marked NaN, and those vertices. */
typedef struct {
    double *acc;
    uint32_t *v;
    size_t n, cap;
} nan_acc;

/* Marks vertex v's normal for the area-weighted mean of its triangles: NaN in x, its accumulator's
 * index in y's bits. 0, or -1 out of memory. */
static int mark_nan(float *nrm, uint32_t v, nan_acc *a)
{
    if (isnan(nrm[3 * v]))
        return 0;
    if (a->n == a->cap) {
        size_t cap = a->cap ? 2 * a->cap : 256;
        double *p = realloc(a->acc, 3 * cap * sizeof *p);
        if (p)
            a->acc = p;
        uint32_t *q = p ? realloc(a->v, cap * sizeof *q) : NULL;
        if (!q)
            return -1;
        a->v = q, a->cap = cap;
    }
    const uint32_t i = (uint32_t)a->n++;
    a->acc[3 * i] = a->acc[3 * i + 1] = a->acc[3 * i + 2] = 0.0;
    a->v[i] = v;
    nrm[3 * v] = NAN;
    memcpy(&nrm[3 * v + 1], &i, 4);
    return 0;
}

void api_mesh_loop_message(int axis, char *buf, size_t n)
{
    const char t = "uvw"[axis];
    snprintf(buf, n, "res: 3 samples along %c, where the solid closes into a loop (%c = 0 and %c = 1 meet), are 2 "
             "points around it, and the mesh folds flat onto itself; take at least 4 along %c", t, t, t, t);
}

/* api_mesh_build, or with loops_only its steps 1 and 2 alone, to the test of 3 samples around a loop: then 0
 * (out given back) or -1 with err as the build's. */
static int build(const pde_solution *sol, const unsigned res[3], const pde_cancel *cancel, api_mesh *out,
                 api_error *err, int loops_only)
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
    /* The mesh's block holds every sample's position, normal and det J until step 5 packs the
     * vertices down over them (a vertex is never after its sample). */
    float *blk = block_get(nraw * 32 + ntraw * 12 + 16);
    uint32_t *up = block_get(nraw * 13 + 16);
    uint32_t *vof = up ? up + nraw : NULL;     /* step 5: a root's vertex in the face, or a tag */
    uint32_t *pid = up ? vof + nraw : NULL;    /* step 5: a shared root's position id, or UINT32_MAX */
    uint8_t *flag = up ? (uint8_t *)(pid + nraw) : NULL;
    nan_acc nacc = { NULL, NULL, 0, 0 };
    sampler sp;
    int rc = -1, cancelled = 0, have_sp = 0;
    const char *why = "out of memory building the mesh";
    api_status why_status = API_ERR_NOMEM;
    if (!blk || !up) {
        block_put(up);
        up = NULL;
        goto done;
    }
    out->pos = blk;
    out->nrm = blk + 3 * nraw;
    out->detj = blk + 6 * nraw;
    out->weld = (uint32_t *)(blk + 7 * nraw);
    out->tri = out->weld + nraw;
    samples raw = { out->pos, out->nrm, out->detj,
                    { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY }, 0 };

    /* 1. Faces: positions now (and u = 0, 1's derivatives), the others' derivatives after step 3 where a face
     * keeps a triangle. */
    if (sampler_init(&sp, sol, res))
        goto done;
    have_sp = 1;
    if (sample_faces(&sp, faces, res, NULL, cancel, &raw)) {
        cancelled = 1;
        goto done;
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
    const float epsf = (float)eps;
    float *restrict P = out->pos;

    /* 2. Join: the cube's edges by the lattice; collapsed rows and seams where the map joins them. */
    for (uint32_t i = 0; i < (uint32_t)nraw; i++)
        up[i] = i;
    for (int fi = 0; fi < 6 && !loops_only; fi++) {   /* the loops' test counts near samples, joined or not */
        const face *f = &faces[fi];
        const size_t na = f->na, nb = f->nb;
        int o[2];
        face_axes(f, o);
        size_t ijk[3];
        ijk[f->axis] = f->side ? res[f->axis] - 1 : 0;
        for (size_t b = 0; b < nb; b++) {
            const uint32_t row = (uint32_t)(f->base + b * na);
            const float *p = P + 3 * (size_t)row;
            /* along the row, then to the next row; a row that is one point (u = 0, 1: one_point) is near all
             * along, and near all of the next row, or none of it, where that is one point too: then one join
             * does, the next row joining all its samples next */
            const int pt = fi < 2 && sp.point[fi][b], pt1 = pt && b + 1 < nb && sp.point[fi][b + 1];
            if (pt)
                join_chain(up, row, na);
            else
                join_near(up, p, p + 3, row, row + 1, na - 1, epsf);
            if (pt1 && near(p, p + 3 * na, epsf))
                join(up, row, (uint32_t)(row + na));
            else if (b + 1 < nb && !pt1)
                join_near(up, p, p + 3 * na, row, (uint32_t)(row + na), na, epsf);
            /* the neighbouring faces this row's samples lie on: its ends, or all of an edge row */
            const int edge_row = b == 0 || b + 1 == nb;
            for (size_t a = 0; a < na; a += edge_row || a + 1 == na ? 1 : na - 1) {
                ijk[o[0]] = a, ijk[o[1]] = b;
                for (int e = 0; e < 3; e++)
                    if (e != f->axis && (ijk[e] == 0 || ijk[e] == res[e] - 1))
                        join(up, row + (uint32_t)a, (uint32_t)face_sample(&faces[2 * e + (ijk[e] != 0)], ijk));
            }
        }
    }
    size_t seams[3] = { 0, 0, 0 };   /* samples of opposite faces joined, per axis */
    for (int a = 0; a < 3; a++) {
        const face *f0 = &faces[2 * a], *f1 = &faces[2 * a + 1];
        const float *p0 = P + 3 * f0->base, *p1 = P + 3 * f1->base;
        const size_t n = f0->na * f0->nb;
        seams[a] = join_near(up, p0, p1, (uint32_t)f0->base, (uint32_t)f1->base, n, epsf);
    }
    char loop[200];
    for (int a = 0; a < 3; a++)
        if (res[a] == 3 && seams[a] == faces[2 * a].na * faces[2 * a].nb) {
            api_mesh_loop_message(a, loop, sizeof loop);
            why = loop, why_status = API_ERR_DOCUMENT;
            goto done;
        }
    if (loops_only) {
        api_mesh_free(out);
        rc = 0;
        goto done;
    }
    /* Roots; a joined sample takes its root's position, so that every copy of a point is the same
     * bits (the root, the least sample, is settled before any other of its set). Almost every sample
     * is its own root and needs no store: 4 a step in SSE2 find the others. */
    memset(flag, 0, nraw);
    for (size_t i = 0; i < nraw;) {
#if defined(__SSE2__)
        const __m128i step4 = _mm_set1_epi32(4);
        for (__m128i ids = _mm_add_epi32(_mm_set1_epi32((int)i), _mm_setr_epi32(0, 1, 2, 3));
             i + 4 <= nraw && _mm_movemask_epi8(_mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(up + i)), ids)) == 0xffff;
             i += 4)
            ids = _mm_add_epi32(ids, step4);
#endif
        /* the next 4 one at a time (a run of joined samples, a collapsed row's or a seam's, costs no 4-test each) */
        for (const size_t end = i + 4 < nraw ? i + 4 : nraw; i < end; i++) {
            const uint32_t r = up[up[i]];   /* up[i] < i is a root already, or points at one */
            if (r == i)
                continue;
            up[i] = r;
            flag[i] = SHARED;
            if (!flag[r])   /* the root's first joined sample (a collapsed row's first sample has na - 1 more) */
                flag[r] = SHARED, vof[r] = pid[r] = UINT32_MAX;
            memcpy(P + 3 * i, P + 3 * (size_t)r, 3 * sizeof *P);
        }
    }
    if (stopped(cancel)) {
        cancelled = 1;
        goto done;
    }

    /* 3. Triangles that collapse go; so do the cells of opposite faces that coincide: first those whose
     * corners are the opposite cell's points (the same positions, wound the other way: their volumes
     * would cancel exactly), then any with the same three points in another order. */
    const double tiny = 1e-12 * extent * extent, tiny2 = tiny * tiny;
    size_t ftri[6] = { 0 };   /* each face's live triangles */
    double vol = 0.0;   /* six times the enclosed volume, over the live triangles */
    for (int fi = 0; fi < 6; fi++) {
        const face *f = &faces[fi];
        if (seams[f->axis] == f->na * f->nb)
            continue;   /* every sample is its opposite's: every cell coincides with the opposite one (below) */
        const double sgn = f->reverse ? -1.0 : 1.0;
        /* the opposite face's samples, where the two may coincide */
        const ptrdiff_t opp = seams[f->axis] >= 3 ? (ptrdiff_t)faces[fi ^ 1].base - (ptrdiff_t)f->base : 0;
        for (size_t b = 0; b + 1 < f->nb; b++) {
            const size_t row = f->base + b * f->na;
            const uint32_t *restrict u0 = up + row, *restrict u1 = u0 + f->na;
            const uint32_t *o0 = u0 + opp, *o1 = u1 + opp;
            uint8_t *restrict fl = flag + row;
            for (size_t a = 0; a + 1 < f->na; a++) {
#if defined(__SSE2__)
                /* 4 cells a step where no face coincides here and every triangle, or none, has three points */
                for (; !opp && a + 5 <= f->na; a += 4) {
                    const __m128i r00 = _mm_loadu_si128((const __m128i *)(u0 + a)), r11 = _mm_loadu_si128((const __m128i *)(u1 + a + 1));
                    const __m128i r10 = _mm_loadu_si128((const __m128i *)(u0 + a + 1)), r01 = _mm_loadu_si128((const __m128i *)(u1 + a));
                    /* the scalar code's !c0 and !c1 below, lane by lane */
                    const __m128i r0011 = _mm_cmpeq_epi32(r00, r11);
                    const __m128i dead0 = _mm_or_si128(r0011, _mm_or_si128(_mm_cmpeq_epi32(r10, r00), _mm_cmpeq_epi32(r10, r11)));
                    const __m128i dead1 = _mm_or_si128(r0011, _mm_or_si128(_mm_cmpeq_epi32(r01, r00), _mm_cmpeq_epi32(r01, r11)));
                    if (_mm_movemask_epi8(_mm_and_si128(dead0, dead1)) == 0xffff)
                        continue;   /* no triangle of the 4 has three points (a collapsed row's cells) */
                    if (_mm_movemask_epi8(_mm_or_si128(dead0, dead1)))
                        break;
                    double v[2][2][2], vs[4];
                    const unsigned live = cells4_live(P, row + a, f->na, sgn, tiny2, v, vs);
                    if (live == 0xff) {   /* all 8 (almost always): as below, the flags 4 cells at once */
                        vol += vs[0], vol += vs[1], vol += vs[2], vol += vs[3];
                        or4(fl + a, 0x0e0e0e0eu), fl[a + 4] |= USED;   /* LIVE0 | LIVE1 | USED */
                        or4(fl + a + f->na, 0x02020202u), fl[a + f->na + 4] |= USED;
                        ftri[fi] += 8;
                        continue;
                    }
                    for (unsigned i = 0; i < 4; i++) {
                        const unsigned h = i >> 1, c = i & 1, li = (live >> (4 * h + c) & 1) | (live >> (4 * h + 2 + c) & 1) << 1;
                        if (li) {
                            vol += (li & 1 ? v[h][0][c] : 0.0) + (li & 2 ? v[h][1][c] : 0.0);
                            mark_live(fl + a + i, f->na, li);
                            ftri[fi] += (li & 1) + (li >> 1);
                        }
                    }
                }
                if (a + 1 >= f->na)
                    break;
#endif
                const uint32_t r00 = u0[a], r10 = u0[a + 1], r01 = u1[a], r11 = u1[a + 1];
                /* both triangles hold v00 and v11: (v00, v10, v11) and (v00, v11, v01), either winding */
                const int diag = r00 != r11;
                const int c0 = diag && r10 != r00 && r10 != r11, c1 = diag && r01 != r00 && r01 != r11;
                if (!(c0 | c1))
                    continue;
                if (opp && r00 == o0[a] && r10 == o0[a + 1] && r01 == o1[a] && r11 == o1[a + 1])
                    continue;
                const unsigned live = cell_live(P, row + a, f->na, sgn, tiny2, (unsigned)c0 | (unsigned)c1 << 1, &vol);
                if (!live)
                    continue;
                mark_live(fl + a, f->na, live);
                ftri[fi] += (live & 1) + (live >> 1);
            }
        }
    }
    int reused[3] = { 0, 0, 0 };   /* the axes whose faces lost triangles here: their USED flags are stale */
    for (int a = 0; a < 3; a++) {
        const face *f0 = &faces[2 * a], *f1 = &faces[2 * a + 1];
        if (seams[a] < 3 || !ftri[2 * a] || !ftri[2 * a + 1])
            continue;   /* no triangle of one lies on the other */
        for (size_t b = 0; b + 1 < f0->nb; b++)
            for (size_t c = 0; c + 1 < f0->na; c++)
                for (int q = 0; q < 2; q++) {
                    const uint8_t bit = q ? LIVE1 : LIVE0;
                    uint8_t *l0 = flag + f0->base + b * f0->na + c, *l1 = flag + f1->base + b * f1->na + c;
                    if (!(*l0 & bit) || !(*l1 & bit))
                        continue;
                    uint32_t s0[3], s1[3], r0[3], r1[3];
                    cell_tri(f0, c, b, q, s0);
                    cell_tri(f1, c, b, q, s1);
                    for (int i = 0; i < 3; i++)
                        s0[i] = up[s0[i]], s1[i] = up[s1[i]];
                    if (sorted(s0, r0) != sorted(s1, r1) && memcmp(r0, r1, sizeof r0) == 0) {
                        *l0 &= (uint8_t)~bit;
                        *l1 &= (uint8_t)~bit;
                        reused[a] = 1;
                        double n[2][3], v0[2], v1[2];
                        cell_normals(P, f0->base + b * f0->na + c, f0->na, f0->reverse ? -1.0 : 1.0, n, v0);
                        cell_normals(P, f1->base + b * f1->na + c, f1->na, f1->reverse ? -1.0 : 1.0, n, v1);
                        vol -= v0[q] + v1[q];
                        ftri[2 * a]--, ftri[2 * a + 1]--;
                    }
                }
    }

    /* 1, continued: x_a x x_b and det J on the faces that keep a triangle. */
    if (sample_faces(&sp, faces, res, ftri, cancel, &raw)) {
        cancelled = 1;
        goto done;
    }

    /* 4. Outward: the enclosed volume (summed in 3) must be positive. */
    const int flip = vol < 0.0;
    const size_t ntri = ftri[0] + ftri[1] + ftri[2] + ftri[3] + ftri[4] + ftri[5];

    /* 5. Vertices, (point, face) pairs, face by face in sample order, each at the first sample of the
     * face that a live triangle uses, packed down over the samples; then the face's triangles. A point
     * the face samples twice (a collapsed row's) takes its triangles' normal, as does one where
     * x_a x x_b vanishes. */
    size_t nv = 0, npos = 0, k3 = 0;
    float lo12[12], hi12[12], sum12[12];   /* the vertices' bounds (row_bounds) */
    for (int l = 0; l < 12; l++)
        lo12[l] = INFINITY, hi12[l] = -INFINITY, sum12[l] = 0.0f;
    float *restrict N = out->nrm, *restrict J = out->detj;
    uint32_t *restrict W = out->weld, *restrict T = out->tri;
    for (int fi = 0; fi < 6; fi++) {
        if (stopped(cancel)) {
            cancelled = 1;
            goto done;
        }
        const face *f = &faces[fi];
        if (!ftri[fi])
            continue;   /* collapsed, or cancelled by its opposite: no vertex */
        const size_t na = f->na, end = f->base + na * f->nb;
        const uint32_t first = (uint32_t)nv;
        const double sgn = (f->reverse ? -1.0 : 1.0) * (flip ? -1.0 : 1.0);
        /* the samples the live triangles use, again where step 3 dropped some */
        if (reused[f->axis])
            for (size_t k = f->base; k < end; k++)
                flag[k] &= (uint8_t)~USED;
        for (size_t b = 0; reused[f->axis] && b + 1 < f->nb; b++) {
            uint8_t *restrict fl = flag + f->base + b * na;
            for (size_t a = 0; a + 1 < na; a++) {
                const uint8_t c = fl[a];
                if (!(c & (LIVE0 | LIVE1)))
                    continue;
                fl[a] |= USED, fl[a + na + 1] |= USED;
                if (c & LIVE0)
                    fl[a + 1] |= USED;
                if (c & LIVE1)
                    fl[a + na] |= USED;
            }
        }
        /* how many samples of the face each shared root has */
        for (size_t k = next_flag(flag, f->base, end, SHARED); k < end; k = next_flag(flag, k + 1, end, SHARED)) {
            const uint32_t r = up[k];
            vof[r] = vof[r] == TAG1(fi) || vof[r] == TAG2(fi) ? TAG2(fi) : TAG1(fi);
        }
        const size_t nacc0 = nacc.n;
        for (size_t k = f->base; k < end; k++) {
#if defined(__SSE2__)
            /* 4 samples a step where each is used and joined with no other (almost all) and its x_a x x_b
             * does not vanish: vertices nv.., position ids npos.. */
            for (uint32_t c4; k + 4 <= end; k += 4, nv += 4, npos += 4) {
                memcpy(&c4, flag + k, 4);
                if ((c4 & 0x03030303u) != 0x02020202u || !plain4(P, N, J, k, nv, sgn, tiny))
                    break;
                for (uint32_t i = 0; i < 4; i++)
                    W[nv + i] = (uint32_t)npos + i, up[k + i] = (uint32_t)nv + i;
            }
            if (k == end)
                break;
#endif
            const uint8_t c = flag[k];
            uint32_t v;
            int twice = 0;
            if (!(c & SHARED)) {
                if (!(c & USED))
                    continue;
                v = (uint32_t)nv++;
                W[v] = (uint32_t)npos++;
            } else {
                const uint32_t r = up[k], at = vof[r];
                const int made = at >= first && at < TAGMIN;
                if (!(c & USED)) {
                    if (made && mark_nan(N, at, &nacc))
                        goto done;
                    continue;
                }
                if (made) {   /* a second sample of the face at the vertex's point */
                    up[k] = at;
                    if (mark_nan(N, at, &nacc))
                        goto done;
                    continue;
                }
                twice = at == TAG2(fi);
                v = (uint32_t)nv++;
                vof[r] = v;
                if (pid[r] == UINT32_MAX)
                    pid[r] = (uint32_t)npos++;
                W[v] = pid[r];
            }
            up[k] = v;
            /* the sample's data down to the vertex (v <= k) */
            const float *p = P + 3 * k, *n = N + 3 * k;
            const double nx = n[0], ny = n[1], nz = n[2], len = sqrt(nx * nx + ny * ny + nz * nz);
            P[3 * v] = p[0], P[3 * v + 1] = p[1], P[3 * v + 2] = p[2];
            J[v] = J[k];
            if (len > tiny) {
                const double s = sgn / len;
                N[3 * v] = (float)(s * nx), N[3 * v + 1] = (float)(s * ny), N[3 * v + 2] = (float)(s * nz);
            } else {
                N[3 * v] = 0.0f;   /* not NaN yet: mark_nan's test */
                twice = 1;
            }
            if (twice) {
                flag[k] |= NANV;
                if (mark_nan(N, v, &nacc))
                    goto done;
            }
        }
        row_bounds(P + 3 * (size_t)first, 3 * (nv - first), lo12, hi12, sum12);
        /* the face's triangles as cell_tri winds them, (v00, v10, v11) and (v00, v11, v01), their second and
         * third corners swapped where the face reverses, and again where the solid flips; the choice made
         * once a face, so the corners stay in registers */
        const int swap = f->reverse != flip;
        /* a corner's vertex may have a NaN normal where its sample is joined (SHARED) or was marked (NANV) */
        const uint8_t maybe_nan = nacc.n > nacc0 ? SHARED | NANV : 0;
        const uint64_t nan5 = maybe_nan * 0x0101010101u;   /* the flags of a 4-cell step's 5 corners a row */
        for (size_t b = 0; b + 1 < f->nb; b++) {
            const size_t row = f->base + b * na;
            const uint8_t *restrict fl = flag + row;
            const uint32_t *restrict u = up + row;
            for (size_t a = 0; a + 1 < na; a++) {
#if defined(__SSE2__)
                uint32_t live4;
                uint64_t c0, c1;
                for (; a + 8 <= na; a += 4, k3 += 24) {   /* 4 cells a step where all 8 triangles live */
                    memcpy(&live4, fl + a, 4), memcpy(&c0, fl + a, 8), memcpy(&c1, fl + a + na, 8);
                    if ((live4 & 0x0c0c0c0cu) != 0x0c0c0c0cu || ((c0 | c1) & nan5))
                        break;
                    tri4(T + k3, u + a, na, swap);
                }
#endif
                const uint8_t c = fl[a];
                if (!(c & (LIVE0 | LIVE1)))
                    continue;
                const uint32_t w00 = u[a], w10 = u[a + 1], w01 = u[a + na], w11 = u[a + na + 1];
                const uint32_t *t = T + k3;
                if (c & LIVE0)
                    T[k3] = w00, T[k3 + 1] = swap ? w11 : w10, T[k3 + 2] = swap ? w10 : w11, k3 += 3;
                if (c & LIVE1)
                    T[k3] = w00, T[k3 + 1] = swap ? w01 : w11, T[k3 + 2] = swap ? w11 : w01, k3 += 3;
                if (!((c | fl[a + 1] | fl[a + na] | fl[a + na + 1]) & maybe_nan))
                    continue;
                for (; t < T + k3; t += 3) {
                    if (!isnan(N[3 * t[0]]) && !isnan(N[3 * t[1]]) && !isnan(N[3 * t[2]]))
                        continue;
                    double e1[3], e2[3], n[3];
                    for (int i = 0; i < 3; i++) {
                        e1[i] = (double)P[3 * t[1] + i] - P[3 * t[0] + i];
                        e2[i] = (double)P[3 * t[2] + i] - P[3 * t[0] + i];
                    }
                    cross(e1, e2, n);
                    for (int i = 0; i < 3; i++)
                        if (isnan(N[3 * t[i]])) {
                            uint32_t j;
                            memcpy(&j, &N[3 * t[i] + 1], 4);
                            for (int c2 = 0; c2 < 3; c2++)
                                nacc.acc[3 * j + c2] += n[c2];
                        }
                }
            }
        }
        /* the area-weighted normals of the face's marked vertices (a vertex is marked once) */
        for (size_t j = nacc0; j < nacc.n; j++) {
            const uint32_t v = nacc.v[j];
            const double *n = nacc.acc + 3 * j, len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (int c2 = 0; c2 < 3; c2++)
                N[3 * v + c2] = len > 0 ? (float)(n[c2] / len) : (c2 == 2 ? 1.0f : 0.0f);
        }
    }
    for (int c = 0; c < 3; c++)
        out->min[c] = INFINITY, out->max[c] = -INFINITY;
    for (int l = 0; l < 12; l++) {
        out->min[l % 3] = lo12[l] < out->min[l % 3] ? lo12[l] : out->min[l % 3];
        out->max[l % 3] = hi12[l] > out->max[l % 3] ? hi12[l] : out->max[l % 3];
    }
    out->nverts = nv;
    out->ntris = ntri;
    out->npos = npos;
    rc = 0;
done:
    if (rc) {
        if (!out->pos)
            block_put(blk);
        api_mesh_free(out);
        api_fail(err, cancelled ? API_ERR_CANCELLED : why_status, "", "%s", cancelled ? "cancelled" : why);
    }
    block_put(up);
    free(nacc.acc);
    free(nacc.v);
    if (have_sp)
        sampler_free(&sp);
    return rc;
}

int api_mesh_build(const pde_solution *sol, const unsigned res[3], const pde_cancel *cancel, api_mesh *out,
                   api_error *err)
{
    return build(sol, res, cancel, out, err, 0);
}

int api_mesh_check_loops(const pde_solution *sol, const unsigned res[3], const pde_cancel *cancel, api_error *err)
{
    if ((res[0] != 3 && res[1] != 3 && res[2] != 3) || pde_solution_is_flat(sol))
        return 0;   /* no axis for the test; a flat solid's output refuses it first, for having no volume */
    api_mesh m;
    return build(sol, res, cancel, &m, err, 1);
}
