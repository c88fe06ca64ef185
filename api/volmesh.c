/*
 * volmesh.c: the solid as hexahedra and wedges, and its msh and vtu writers (volmesh.h).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmt.h"
#include "mesh.h"
#include "volmesh.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the vtu writer copies little-endian values as they are"
#endif

typedef struct {
    unsigned n[3];
    double *pos;        /* 3 per sample */
    double *det;        /* per sample */
    double *cdet;       /* per cell, at its centre */
    uint32_t *rep;      /* union-find: the smallest sample of each merged set is its root */
    double tol;
} samples;

static size_t sidx(const samples *g, const unsigned a[3])
{
    return a[0] + (size_t)g->n[0] * (a[1] + (size_t)g->n[1] * a[2]);
}

static uint32_t root(const samples *g, uint32_t x)
{
    while (g->rep[x] != x)
        x = g->rep[x];
    return x;
}

static void unite(samples *g, uint32_t a, uint32_t b)
{
    a = root(g, a);
    b = root(g, b);
    if (a < b)
        g->rep[b] = a;
    else if (b < a)
        g->rep[a] = b;
}

static int same(const samples *g, size_t a, size_t b)
{
    for (int c = 0; c < 3; c++)
        if (fabs(g->pos[3 * a + c] - g->pos[3 * b + c]) > g->tol)
            return 0;
    return 1;
}

static double det3(const double a[3], const double b[3], const double c[3])
{
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
}

/* On the face a[d] = s * (n[d] - 1): do all lines along axis p coincide? If so, merge each. */
static int face_axis_collapse(samples *g, int d, int s, int p, int merge)
{
    int q = 3 - d - p;
    unsigned a[3];
    a[d] = s ? g->n[d] - 1 : 0;
    for (a[q] = 0; a[q] < g->n[q]; a[q]++) {
        unsigned b[3] = { a[0], a[1], a[2] };
        b[p] = 0;
        size_t first = sidx(g, b);
        for (b[p] = 1; b[p] < g->n[p]; b[p]++) {
            size_t x = sidx(g, b);
            if (!merge && !same(g, first, x))
                return 0;
            if (merge)
                unite(g, (uint32_t)first, (uint32_t)x);
        }
    }
    return 1;
}

/* Do the faces a[d] = 0 and a[d] = n[d] - 1 coincide? If so, merge them. */
static int seam(samples *g, int d, int merge)
{
    int p = (d + 1) % 3, q = (d + 2) % 3;
    unsigned a[3], b[3];
    for (a[p] = 0; a[p] < g->n[p]; a[p]++)
        for (a[q] = 0; a[q] < g->n[q]; a[q]++) {
            memcpy(b, a, sizeof b);
            a[d] = 0;
            b[d] = g->n[d] - 1;
            size_t x = sidx(g, a), y = sidx(g, b);
            if (!merge && !same(g, x, y))
                return 0;
            if (merge)
                unite(g, (uint32_t)x, (uint32_t)y);
        }
    return 1;
}

static const int hex_off[8][3] = {
    { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 },
};

/* The wedge of a cell whose two parallel edges of one face collapse, or -1. ids by offset (u + 2v + 4w). */
static int wedge_of(const uint32_t id[8], int sign, uint32_t out[6])
{
    for (int p = 0; p < 3; p++)
        for (int q = 0; q < 3; q++) {
            if (q == p)
                continue;
            int r = 3 - p - q;
            for (int s = 0; s < 2; s++) {
                int ok = 1;
                for (int t = 0; t < 2 && ok; t++) {   /* both edges along p on face q = s: collapsed */
                    int o0[3], o1[3];
                    o0[p] = 0, o1[p] = 1, o0[q] = o1[q] = s, o0[r] = o1[r] = t;
                    ok = id[o0[0] + 2 * o0[1] + 4 * o0[2]] == id[o1[0] + 2 * o1[1] + 4 * o1[2]];
                }
                if (!ok)
                    continue;
                int A[3], B[3], C[3];
                A[q] = s, A[p] = 0, A[r] = 0;
                B[q] = 1 - s, B[p] = 0, B[r] = 0;
                C[q] = 1 - s, C[p] = 1, C[r] = 0;
                double ba[3], ca[3], er[3] = { 0, 0, 0 };
                for (int c = 0; c < 3; c++)
                    ba[c] = B[c] - A[c], ca[c] = C[c] - A[c];
                er[r] = 1;
                if (det3(ba, ca, er) * sign > 0) {   /* VTK: (0,1,2)'s normal away from (3,4,5) */
                    int T[3];
                    memcpy(T, B, sizeof T), memcpy(B, C, sizeof T), memcpy(C, T, sizeof T);
                }
                const int *v[3] = { A, B, C };
                for (int t = 0; t < 2; t++)
                    for (int k = 0; k < 3; k++) {
                        int o[3] = { v[k][0], v[k][1], v[k][2] };
                        o[r] = t;
                        out[3 * t + k] = id[o[0] + 2 * o[1] + 4 * o[2]];
                    }
                return 0;
            }
        }
    return -1;
}

static int stopped(const pde_cancel *c)
{
    return c && c->stop && c->stop(c->arg);
}

/*
 * det J (and the position, when pos is not NULL) at ((i + off) / (res[0] - 1), (j + off) / (res[1] - 1),
 * (k + off) / (res[2] - 1)), u fastest: off 0 the samples, 0.5 the cells' centres (one fewer an axis).
 * Through a pde_grid, whose tables hold every factor once and each h(w) once a plane (the tower loft's
 * 99 modes at 33^3: 0.6 s point by point with pde_eval_d). Polled once a row.
 */
static pde_status sample_grid(const pde_solution *s, const unsigned res[3], double off, double *pos, double *det,
                              const pde_cancel *cancel)
{
    const unsigned cut = off > 0.0, n[3] = { res[0] - cut, res[1] - cut, res[2] - cut };
    double *t = malloc((n[0] + n[1] + 9 * (size_t)n[0]) * sizeof *t);
    pde_grid *g = NULL;
    if (!t)
        return PDE_ERR_NOMEM;
    double *us = t, *vs = us + n[0], *xu = vs + n[1], *xv = xu + 3 * (size_t)n[0], *xw = xv + 3 * (size_t)n[0];
    for (unsigned i = 0; i < n[0]; i++)
        us[i] = (i + off) / (res[0] - 1);
    for (unsigned j = 0; j < n[1]; j++)
        vs[j] = (j + off) / (res[1] - 1);
    pde_status st = pde_grid_create(s, us, n[0], vs, n[1], &g);
    for (unsigned k = 0; k < n[2] && st == PDE_OK; k++)
        for (unsigned j = 0; j < n[1] && st == PDE_OK; j++) {
            if (stopped(cancel)) {
                st = PDE_ERR_CANCELLED;
                break;
            }
            const size_t x0 = n[0] * (j + (size_t)n[1] * k);
            pde_grid_row_d(g, (k + off) / (res[2] - 1), j, pos ? pos + 3 * x0 : NULL, xu, xv, xw);
            for (unsigned i = 0; i < n[0]; i++)
                det[x0 + i] = det3(xu + 3 * i, xv + 3 * i, xw + 3 * i);
        }
    pde_grid_free(g);
    free(t);
    return st;
}

int api_volmesh_build(const pde_solution *s, const unsigned res[3], const pde_cancel *cancel,
                      api_volmesh *out, api_error *err)
{
    for (int d = 0; d < 3; d++)
        if (res[d] < 2)
            return api_fail(err, API_ERR_LIMIT, "", "a volume mesh needs at least 2 samples per axis, not %u", res[d]);
    size_t ncell_max = (size_t)(res[0] - 1) * (res[1] - 1) * (res[2] - 1);
    if ((double)(res[0] - 1) * (res[1] - 1) * (res[2] - 1) > (double)API_VOLMESH_MAX_CELLS)
        return api_fail(err, API_ERR_LIMIT, "", "a volume mesh of %u x %u x %u samples has over %zu cells", res[0], res[1],
                        res[2], API_VOLMESH_MAX_CELLS);
    samples g = { { res[0], res[1], res[2] }, NULL, NULL, NULL, NULL, 0 };
    size_t N = (size_t)res[0] * res[1] * res[2];
    api_volmesh m;
    memset(&m, 0, sizeof m);
    uint32_t *id = NULL, *conn = NULL;
    unsigned char *type = NULL, *fold = NULL;
    float *cdet = NULL;
    g.pos = malloc(3 * N * sizeof *g.pos);
    g.det = malloc(N * sizeof *g.det);
    g.rep = malloc(N * sizeof *g.rep);
    g.cdet = malloc(ncell_max * sizeof *g.cdet);
    id = malloc(N * sizeof *id);
    if (!g.pos || !g.det || !g.rep || !g.cdet || !id)
        goto oom;
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    double sum = 0, dmax = 0;
    unsigned a[3];
    pde_status st = sample_grid(s, res, 0.0, g.pos, g.det, cancel);
    if (st == PDE_OK)
        st = sample_grid(s, res, 0.5, NULL, g.cdet, cancel);
    if (st == PDE_ERR_CANCELLED)
        goto cancelled;
    if (st == PDE_ERR_NOMEM)
        goto oom;
    if (st != PDE_OK) {   /* pde_grid_create's refusal of its arguments: PDE_ERR_INVALID, no solution */
        api_fail(err, api_status_of(st), "", "a volume mesh of %u x %u x %u samples: %s", res[0], res[1], res[2],
                 pde_strerror(st));
        goto fail;
    }
    for (size_t x = 0; x < N; x++) {
        g.rep[x] = (uint32_t)x;
        sum += g.det[x];
        dmax = fmax(dmax, fabs(g.det[x]));
        for (int c = 0; c < 3; c++)
            lo[c] = fmin(lo[c], g.pos[3 * x + c]), hi[c] = fmax(hi[c], g.pos[3 * x + c]);
    }
    g.tol = API_VOLMESH_TOL * sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                   (hi[2] - lo[2]) * (hi[2] - lo[2]));
    m.sign = sum < 0 ? -1 : 1;
    int seamed[3];
    for (int d = 0; d < 3; d++)
        for (int sd = 0; sd < 2; sd++)
            for (int p = 0; p < 3; p++)
                if (p != d && face_axis_collapse(&g, d, sd, p, 0))
                    face_axis_collapse(&g, d, sd, p, 1);
    for (int d = 0; d < 3; d++) {
        seamed[d] = seam(&g, d, 0);
        if (seamed[d] && res[d] == 3) {
            char loop[200];
            api_mesh_loop_message(d, loop, sizeof loop);
            api_fail(err, API_ERR_DOCUMENT, "", "%s", loop);
            goto fail;
        }
        if (seamed[d])
            seam(&g, d, 1);
    }
    for (size_t x = 0; x < N; x++)
        if (root(&g, (uint32_t)x) == x)
            id[x] = (uint32_t)m.npoints++;
        else
            id[x] = id[root(&g, (uint32_t)x)];
    m.pos = malloc(3 * m.npoints * sizeof *m.pos);
    m.detj = malloc(m.npoints * sizeof *m.detj);
    conn = malloc(8 * ncell_max * sizeof *conn);
    type = malloc(ncell_max);
    fold = malloc(ncell_max);
    cdet = malloc(ncell_max * sizeof *cdet);
    if (!m.pos || !m.detj || !conn || !type || !fold || !cdet)
        goto oom;
    for (size_t x = 0; x < N; x++)
        if (g.rep[x] == x) {
            memcpy(m.pos + 3 * id[x], g.pos + 3 * x, 3 * sizeof *m.pos);
            m.detj[id[x]] = (float)g.det[x];
        }
    /* cells: hexahedra, then wedges (two passes) */
    for (int pass = 0; pass < 2; pass++)
        for (a[2] = 0; a[2] + 1 < res[2]; a[2]++) {
            if (stopped(cancel))
                goto cancelled;
            for (a[1] = 0; a[1] + 1 < res[1]; a[1]++)
                for (a[0] = 0; a[0] + 1 < res[0]; a[0]++) {
                    uint32_t byoff[8], hid[8];
                    size_t sx[8];
                    int distinct = 0;
                    for (int k = 0; k < 8; k++) {
                        unsigned b[3] = { a[0] + (k & 1), a[1] + ((k >> 1) & 1), a[2] + ((k >> 2) & 1) };
                        sx[k] = sidx(&g, b);
                        byoff[k] = id[sx[k]];
                        int seen = 0;
                        for (int j = 0; j < k; j++)
                            seen |= byoff[j] == byoff[k];
                        distinct += !seen;
                    }
                    uint32_t *cc = conn + 8 * m.ncells;
                    if (distinct == 8 && pass == 0) {
                        static const int mirror[8] = { 1, 0, 3, 2, 5, 4, 7, 6 };
                        for (int k = 0; k < 8; k++) {
                            const int *o = hex_off[m.sign > 0 ? k : mirror[k]];
                            hid[k] = byoff[o[0] + 2 * o[1] + 4 * o[2]];
                        }
                        memcpy(cc, hid, sizeof hid);
                        type[m.ncells] = API_CELL_HEX;
                        m.nhex++;
                    } else if (distinct == 6 && pass == 1 && wedge_of(byoff, m.sign, cc) == 0) {
                        cc[6] = cc[7] = UINT32_MAX;
                        type[m.ncells] = API_CELL_WEDGE;
                        m.nwedge++;
                    } else
                        continue;
                    double dc = g.cdet[a[0] + (res[0] - 1) * (a[1] + (size_t)(res[1] - 1) * a[2])];
                    int f = m.sign * dc <= 0;
                    for (int k = 0; k < 8; k++)
                        f |= m.sign * g.det[sx[k]] < -1e-9 * dmax;
                    cdet[m.ncells] = (float)dc;
                    fold[m.ncells] = (unsigned char)f;
                    m.nfolded += (size_t)f;
                    m.ncells++;
                }
        }
    /* skin */
    for (int d = 0; d < 3; d++)
        for (int sd = 0; sd < 2; sd++) {
            int f = 2 * d + sd;
            if (seamed[d])
                continue;
            int p = d == 0 ? 1 : 0, q = d == 2 ? 1 : 2;
            size_t cap = (size_t)(res[p] - 1) * (res[q] - 1);
            uint32_t *fq = malloc(4 * cap * sizeof *fq);
            if (!fq)
                goto oom;
            m.face_quads[f] = fq;
            int nsign = d == 1 ? -1 : 1, outward = sd ? 1 : -1;
            int rev = nsign * m.sign != outward;
            a[d] = sd ? res[d] - 1 : 0;
            for (a[q] = 0; a[q] + 1 < res[q]; a[q]++)
                for (a[p] = 0; a[p] + 1 < res[p]; a[p]++) {
                    static const int cp[4] = { 0, 1, 1, 0 }, cq[4] = { 0, 0, 1, 1 };
                    uint32_t v[4], w[4];
                    for (int k = 0; k < 4; k++) {
                        unsigned b[3] = { a[0], a[1], a[2] };
                        int kk = rev ? 3 - k : k;
                        b[p] += cp[kk], b[q] += cq[kk];
                        v[k] = id[sidx(&g, b)];
                    }
                    int n = 0;
                    for (int k = 0; k < 4; k++)
                        if (v[k] != v[(k + 3) % 4] && !(n > 0 && w[0] == v[k]))
                            w[n++] = v[k];
                    if (n < 3)
                        continue;
                    if (n == 3)
                        w[3] = UINT32_MAX;
                    memcpy(fq + 4 * m.face_nquads[f]++, w, sizeof w);
                }
        }
    m.conn = conn, m.type = type, m.fold = fold, m.cell_detj = cdet;
    free(g.pos), free(g.det), free(g.cdet), free(g.rep), free(id);
    *out = m;
    return 0;
oom:
    api_fail(err, API_ERR_NOMEM, "", "out of memory for a volume mesh of %u x %u x %u samples", res[0], res[1], res[2]);
    goto fail;
cancelled:
    api_fail_cancelled(err);
fail:
    m.conn = conn, m.type = type, m.fold = fold, m.cell_detj = cdet;
    api_volmesh_free(&m);
    free(g.pos), free(g.det), free(g.cdet), free(g.rep), free(id);
    return -1;
}

void api_volmesh_free(api_volmesh *m)
{
    if (!m)
        return;
    free(m->pos), free(m->detj), free(m->conn), free(m->type), free(m->cell_detj), free(m->fold);
    for (int f = 0; f < 6; f++)
        free(m->face_quads[f]);
    memset(m, 0, sizeof *m);
}

/* ---- streaming ---- */

#define PIECE (1u << 20)

typedef struct {
    char *p;
    size_t n, cap;
} sbuf;

static void addf(sbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void addf(sbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(b->p + b->n, b->cap - b->n, fmt, ap);
    va_end(ap);
    if (k > 0 && (size_t)k < b->cap - b->n)
        b->n += (size_t)k;
}

static void addb(sbuf *b, const void *p, size_t n)
{
    memcpy(b->p + b->n, p, n);
    b->n += n;
}

typedef int (*step_fn)(const api_volmesh *m, const pde_props *props, api_volmesh_cursor *c, sbuf *b);

static int run(const api_volmesh *m, const pde_props *props, api_volmesh_cursor *c, api_volmesh_put put,
               void *ctx, step_fn step)
{
    sbuf b = { malloc(PIECE + 65536), 0, PIECE + 65536 };
    if (!b.p)
        return -1;
    int done = 0;
    while (!done && b.n < PIECE)
        done = step(m, props, c, &b);
    int r = b.n && put(ctx, b.p, b.n) != 0 ? -1 : done;
    free(b.p);
    return r;
}

/* -- msh -- */

static const char *const face_names[6] = { "u0", "u1", "v0", "v1", "w0", "w1" };

static size_t face_ntri(const api_volmesh *m, int f)
{
    size_t n = 0;
    for (size_t k = 0; k < m->face_nquads[f]; k++)
        n += m->face_quads[f][4 * k + 3] == UINT32_MAX;
    return n;
}

static size_t face_base(const api_volmesh *m, int f)
{
    size_t t = 1;
    for (int g = 0; g < f; g++)
        t += m->face_nquads[g];
    return t;
}

/* The box of the mesh's points (face < 0), or of face's quads' corners. */
static void bbox(const api_volmesh *m, int face, double lo[3], double hi[3])
{
    for (int c = 0; c < 3; c++)
        lo[c] = INFINITY, hi[c] = -INFINITY;
    const size_t n = face < 0 ? m->npoints : 4 * m->face_nquads[face];
    for (size_t i = 0; i < n; i++) {
        const size_t k = face < 0 ? i : m->face_quads[face][i];
        if (k == UINT32_MAX)   /* a triangle's 4th */
            continue;
        for (int c = 0; c < 3; c++)
            lo[c] = fmin(lo[c], m->pos[3 * k + c]), hi[c] = fmax(hi[c], m->pos[3 * k + c]);
    }
}

enum { M_HEAD, M_TAGS, M_XYZ, M_ELHEAD, M_FACE0, M_HEX = M_FACE0 + 12, M_WEDGE, M_EDATA, M_EDATA_VOL, M_NDATA,
       M_END };

static int msh_step(const api_volmesh *m, const pde_props *props, api_volmesh_cursor *c, sbuf *b)
{
    (void)props;
    size_t vbase = face_base(m, 6);
    switch (c->phase) {
    case M_HEAD: {
        double lo[3], hi[3], flo[3], fhi[3];
        bbox(m, -1, lo, hi);
        int ns = 0;
        for (int f = 0; f < 6; f++)
            ns += m->face_nquads[f] > 0;
        addf(b, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n7\n");
        for (int f = 0; f < 6; f++)
            addf(b, "2 %d \"%s\"\n", f + 1, face_names[f]);
        addf(b, "3 7 \"solid\"\n$EndPhysicalNames\n$Entities\n0 0 %d 1\n", ns);
        for (int f = 0; f < 6; f++)
            if (m->face_nquads[f]) {
                bbox(m, f, flo, fhi);
                addf(b, "%d %.17g %.17g %.17g %.17g %.17g %.17g 1 %d 0\n", f + 1, flo[0], flo[1], flo[2], fhi[0],
                     fhi[1], fhi[2], f + 1);
            }
        addf(b, "1 %.17g %.17g %.17g %.17g %.17g %.17g 1 7 %d", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], ns);
        for (int f = 0; f < 6; f++)
            if (m->face_nquads[f])
                addf(b, " %d", f + 1);
        addf(b, "\n$EndEntities\n$Nodes\n1 %zu 1 %zu\n3 1 0 %zu\n", m->npoints, m->npoints, m->npoints);
        c->phase = M_TAGS, c->k = 0;
        return 0;
    }
    case M_TAGS:
        for (; c->k < m->npoints && b->n < PIECE; c->k++)
            addf(b, "%zu\n", c->k + 1);
        if (c->k == m->npoints)
            c->phase = M_XYZ, c->k = 0;
        return 0;
    case M_XYZ:
        for (; c->k < m->npoints && b->n < PIECE; c->k++)
            addf(b, "%.17g %.17g %.17g\n", m->pos[3 * c->k], m->pos[3 * c->k + 1], m->pos[3 * c->k + 2]);
        if (c->k == m->npoints)
            c->phase = M_ELHEAD, c->k = 0;
        return 0;
    case M_ELHEAD: {
        size_t blocks = (m->nhex > 0) + (m->nwedge > 0), nel = m->ncells;
        for (int f = 0; f < 6; f++) {
            size_t t = face_ntri(m, f);
            blocks += (t > 0) + (m->face_nquads[f] - t > 0);
            nel += m->face_nquads[f];
        }
        addf(b, "$EndNodes\n$Elements\n%zu %zu 1 %zu\n", blocks, nel, vbase + m->ncells - 1);
        c->phase = M_FACE0, c->k = 0;
        return 0;
    }
    case M_HEX:
    case M_WEDGE: {
        int hex = c->phase == M_HEX;
        size_t k0 = hex ? 0 : m->nhex, k1 = hex ? m->nhex : m->ncells;
        if (c->k == 0 && k1 > k0)
            addf(b, "3 1 %d %zu\n", hex ? 5 : 6, k1 - k0);
        if (c->k < k0)
            c->k = k0;
        static const int prism[6] = { 0, 2, 1, 3, 5, 4 };
        for (; c->k < k1 && b->n < PIECE; c->k++) {
            const uint32_t *q = m->conn + 8 * c->k;
            addf(b, "%zu", vbase + c->k);
            for (int j = 0; j < (hex ? 8 : 6); j++)
                addf(b, " %u", q[hex ? j : prism[j]] + 1);
            addf(b, "\n");
        }
        if (c->k >= k1)
            c->phase++, c->k = 0;
        return 0;
    }
    case M_EDATA:
        addf(b, "$EndElements\n$ElementData\n1\n\"det J\"\n1\n0\n3\n0\n1\n%zu\n", vbase - 1 + m->ncells);
        c->phase = M_EDATA_VOL, c->k = 0;
        return 0;
    case M_EDATA_VOL: {
        /* the skin's elements first (det J at their first node), then the cells */
        size_t nskin = vbase - 1;
        for (; c->k < nskin + m->ncells && b->n < PIECE; c->k++) {
            if (c->k < nskin) {
                int f = 0;
                size_t k = c->k;
                while (k >= m->face_nquads[f])
                    k -= m->face_nquads[f++];
                addf(b, "%zu %.9g\n", c->k + 1, m->detj[m->face_quads[f][4 * k]]);
            } else
                addf(b, "%zu %.9g\n", c->k + 1, m->cell_detj[c->k - nskin]);
        }
        if (c->k == nskin + m->ncells) {
            addf(b, "$EndElementData\n$NodeData\n1\n\"det J\"\n1\n0\n3\n0\n1\n%zu\n", m->npoints);
            c->phase = M_NDATA, c->k = 0;
        }
        return 0;
    }
    case M_NDATA:
        for (; c->k < m->npoints && b->n < PIECE; c->k++)
            addf(b, "%zu %.9g\n", c->k + 1, m->detj[c->k]);
        if (c->k == m->npoints) {
            addf(b, "$EndNodeData\n");
            c->phase = M_END;
        }
        return 0;
    case M_END:
        return 1;
    default: {   /* a face's triangles or quads */
        int f = (c->phase - M_FACE0) / 2, tri = (c->phase - M_FACE0) % 2 == 0;
        size_t nt = face_ntri(m, f), n = tri ? nt : m->face_nquads[f] - nt;
        if (c->k == 0 && n)
            addf(b, "2 %d %d %zu\n", f + 1, tri ? 2 : 3, n);
        size_t base = face_base(m, f);
        for (; c->k < m->face_nquads[f] && b->n < PIECE; c->k++) {
            const uint32_t *q = m->face_quads[f] + 4 * c->k;
            if ((q[3] == UINT32_MAX) != tri)
                continue;
            addf(b, "%zu %u %u %u", base + c->k, q[0] + 1, q[1] + 1, q[2] + 1);
            if (!tri)
                addf(b, " %u", q[3] + 1);
            addf(b, "\n");
        }
        if (c->k >= m->face_nquads[f])
            c->phase++, c->k = 0;
        return 0;
    }
    }
}

int api_volmesh_msh_piece(const api_volmesh *m, const pde_props *props, api_volmesh_cursor *c,
                          api_volmesh_put put, void *ctx)
{
    return run(m, props, c, put, ctx, msh_step);
}

/* -- vtu -- */

enum { V_DETJ, V_FOLD, V_CDETJ, V_POS, V_CONN, V_OFF, V_TYPE, V_NBLOCK };

static size_t vtu_bytes(const api_volmesh *m, int blk)
{
    switch (blk) {
    case V_DETJ: return m->npoints * 4;
    case V_FOLD: return m->ncells;
    case V_CDETJ: return m->ncells * 4;
    case V_POS: return m->npoints * 24;
    case V_CONN: return (8 * m->nhex + 6 * m->nwedge) * 8;
    case V_OFF: return m->ncells * 8;
    default: return m->ncells;
    }
}

static int sbuf_put(void *ctx, const void *p, size_t n)
{
    sbuf *b = ctx;
    if (n > b->cap - b->n)
        return -1;
    addb(b, p, n);
    return 0;
}

/* The properties as field data: api_vtk_field_data (api/fmt.h), the same arrays and names as vts's. */
static void vtu_field(const pde_props *p, sbuf *b)
{
    (void)api_vtk_field_data(p, sbuf_put, b);   /* a few KB into an empty piece of a MB: fits */
}

static int vtu_step(const api_volmesh *m, const pde_props *props, api_volmesh_cursor *c, sbuf *b)
{
    if (c->phase == 0) {
        size_t off[V_NBLOCK], o = 0;
        for (int k = 0; k < V_NBLOCK; k++)
            off[k] = o, o += 8 + vtu_bytes(m, k);
        addf(b, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
                "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n");
        if (props)
            vtu_field(props, b);
        addf(b, "    <Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n"
                "      <PointData Scalars=\"detJ\">\n"
                "        <DataArray type=\"Float32\" Name=\"detJ\" format=\"appended\" offset=\"%zu\"/>\n"
                "      </PointData>\n      <CellData Scalars=\"fold\">\n"
                "        <DataArray type=\"UInt8\" Name=\"fold\" format=\"appended\" offset=\"%zu\"/>\n"
                "        <DataArray type=\"Float32\" Name=\"detJ\" format=\"appended\" offset=\"%zu\"/>\n"
                "      </CellData>\n      <Points>\n"
                "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"%zu\"/>\n"
                "      </Points>\n      <Cells>\n"
                "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"%zu\"/>\n"
                "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"%zu\"/>\n"
                "        <DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"%zu\"/>\n"
                "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n_",
             m->npoints, m->ncells, off[V_DETJ], off[V_FOLD], off[V_CDETJ], off[V_POS], off[V_CONN], off[V_OFF],
             off[V_TYPE]);
        c->phase = 1, c->k = 0;
        return 0;
    }
    int blk = c->phase - 1;
    if (blk >= V_NBLOCK) {
        if (c->phase == V_NBLOCK + 1) {
            addf(b, "\n  </AppendedData>\n</VTKFile>\n");
            c->phase++;
        }
        return 1;
    }
    size_t n = blk == V_DETJ || blk == V_POS ? m->npoints : m->ncells;
    if (c->k == 0) {
        uint64_t h = vtu_bytes(m, blk);
        addb(b, &h, 8);
    }
    for (size_t end = c->k + 512 < n ? c->k + 512 : n; c->k < end; c->k++) {   /* at most 32 KB */
        size_t k = c->k;
        switch (blk) {
        case V_DETJ: addb(b, m->detj + k, 4); break;
        case V_FOLD: addb(b, m->fold + k, 1); break;
        case V_CDETJ: addb(b, m->cell_detj + k, 4); break;
        case V_POS: addb(b, m->pos + 3 * k, 24); break;
        case V_CONN:
            for (int j = 0; j < (m->type[k] == API_CELL_HEX ? 8 : 6); j++) {
                int64_t v = m->conn[8 * k + j];
                addb(b, &v, 8);
            }
            break;
        case V_OFF: {
            int64_t v = k < m->nhex ? 8 * (int64_t)(k + 1) : 8 * (int64_t)m->nhex + 6 * (int64_t)(k + 1 - m->nhex);
            addb(b, &v, 8);
            break;
        }
        default: addb(b, m->type + k, 1); break;
        }
    }
    if (c->k == n)
        c->phase++, c->k = 0;
    return 0;
}

int api_volmesh_vtu_piece(const api_volmesh *m, const pde_props *props, api_volmesh_cursor *c,
                          api_volmesh_put put, void *ctx)
{
    return run(m, props, c, put, ctx, vtu_step);
}
