/*
 * fmt.c: what the formats of api/fmt_*.c share (fmt.h): appending to the
 * output's buffer, the properties, grids sampled a few rows at a time, the
 * skin, and the size-first text writer.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmt.h"

/* One chunk of rows samples at most CHUNK_POINTS points, or rows worth about CHUNK_WORK multiply-adds
 * (about 1 ms), whichever is fewer, but at least one row. */
#define CHUNK_POINTS 16384
#define CHUNK_WORK (1u << 21)

int api_out_reserve(api_output *o, size_t n)
{
    if (o->cap - o->len >= n)
        return 0;
    size_t cap = o->cap ? o->cap : 4096;
    while (cap - o->len < n)
        cap *= 2;
    char *b = realloc(o->buf, cap);
    if (!b)
        return -1;
    o->buf = b;
    o->cap = cap;
    return 0;
}

int api_out_put(api_output *o, const void *p, size_t n)
{
    if (api_out_reserve(o, n))
        return -1;
    memcpy(o->buf + o->len, p, n);
    o->len += n;
    return 0;
}

int api_out_puts(api_output *o, const char *s)
{
    return api_out_put(o, s, strlen(s));
}

void api_le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

void api_le64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

int api_out_f32(api_output *o, const float *f, size_t n)
{
    if (api_out_reserve(o, 4 * n))
        return -1;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    memcpy(o->buf + o->len, f, 4 * n);
#else
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, &f[i], 4);
        api_le32((unsigned char *)o->buf + o->len + 4 * i, u);
    }
#endif
    o->len += 4 * n;
    return 0;
}

int api_out_cancelled(api_error *err)
{
    return api_fail(err, API_ERR_CANCELLED, "", "cancelled");
}

const pde_props *api_out_props(api_output *o, const pde_cancel *cancel, api_error *err)
{
    if (!o->have_props && api_properties(o->sol, cancel, &o->props, err) != PDE_OK)
        return NULL;
    o->have_props = 1;
    return &o->props;
}

long long api_out_points(const api_output *o)
{
    return (long long)o->res[0] * o->res[1] * o->res[2];
}

/* ---- grids ---- */

static double axis(size_t i, size_t n)
{
    return n > 1 ? (double)i / (double)(n - 1) : 0.5;
}

int api_rows_open(api_rows *r, const api_output *o, int derivs, api_error *err)
{
    size_t nu = o->res[0], nv = o->res[1];
    double *us = malloc((nu + nv) * sizeof *us);
    if (!us)
        return api_fail_nomem(err);
    for (size_t i = 0; i < nu; i++)
        us[i] = axis(i, nu);
    for (size_t j = 0; j < nv; j++)
        us[nu + j] = axis(j, nv);
    pde_status st = pde_grid_create(o->sol, us, nu, us + nu, nv, &r->grid);
    free(us);
    if (st == PDE_ERR_NOMEM)
        return api_fail_nomem(err);
    if (st != PDE_OK)   /* the core's own refusal of the grid (a count it does not take), not memory */
        return api_fail(err, api_status_of(st), "", "res: %u,%u,%u: the solution cannot be sampled on %zu by %zu "
                        "points in u and v (%s)", o->res[0], o->res[1], o->res[2], nu, nv, pde_strerror(st));
    /* A row costs about (3 + nu) multiply-adds per mode and component (nu per distinct u-factor). */
    double row = 0.0;
    for (int c = 0; c < 3; c++) {
        size_t nm;
        pde_solution_modes(o->sol, c, &nm);
        row += (double)nm * (3.0 + (double)nu) * (derivs ? 4.0 : 1.0);
    }
    r->chunk = CHUNK_POINTS / nu;
    if (row > 0 && (double)r->chunk * row > CHUNK_WORK)
        r->chunk = (size_t)(CHUNK_WORK / row);
    if (r->chunk == 0)
        r->chunk = 1;
    size_t n = 3 * nu * r->chunk;
    r->xyz = malloc(n * sizeof(float));
    if (derivs) {
        r->xu = malloc(n * sizeof(float));
        r->xv = malloc(n * sizeof(float));
        r->xw = malloc(n * sizeof(float));
        if (!r->xu || !r->xv || !r->xw)
            return api_fail_nomem(err);
    }
    return r->xyz ? 0 : api_fail_nomem(err);
}

size_t api_rows_next(api_rows *r, const api_output *o, int derivs)
{
    if (r->k == o->res[2])
        return 0;
    size_t nu = o->res[0], nv = o->res[1], j1 = r->j + r->chunk < nv ? r->j + r->chunk : nv;
    double w = axis(r->k, o->res[2]);
    pde_grid_rows(r->grid, w, r->j, j1, r->xyz, derivs ? r->xu : NULL, derivs ? r->xv : NULL, derivs ? r->xw : NULL);
    size_t n = nu * (j1 - r->j);
    r->j = j1;
    if (r->j == nv) {
        r->j = 0;
        r->k++;
    }
    return n;
}

void api_rows_free(api_rows *r)
{
    if (!r)
        return;
    pde_grid_free(r->grid);
    free(r->xyz);
    free(r->xu);
    free(r->xv);
    free(r->xw);
    memset(r, 0, sizeof *r);
}

int api_sampled_open(api_output *o, int derivs, api_error *err)
{
    api_sampled *g = calloc(1, sizeof *g);
    o->st = g;
    return g ? api_rows_open(&g->rows, o, derivs, err) : api_fail_nomem(err);
}

void api_sampled_close(void *st)
{
    api_sampled *g = st;
    if (g)
        api_rows_free(&g->rows);
    free(g);
}

/* ---- meshes of the skin or the volume ---- */

static int no_volume(api_error *err)
{
    return api_fail(err, API_ERR_DOCUMENT, "", "the solid has no volume (det J is 0 throughout: it is a surface, a "
                    "curve or a point), so it has no mesh");
}

int api_out_mesh(api_output *o, const pde_cancel *cancel, api_mesh *m, api_error *err)
{
    if (pde_solution_is_flat(o->sol))
        return no_volume(err);
    if (api_mesh_build(o->sol, o->res, cancel, m, err))
        return -1;
    /* With 3 samples or more per axis, a skin of no triangle is one whose points weld together: meshes are
     * float32 (QA: radius 1 at 1e15, where float32 steps by 6.7e7; a 6.4e10 by 2 solid), and more samples
     * cannot help. */
    if (m->ntris == 0 && (o->res[0] < 3 || o->res[1] < 3 || o->res[2] < 3))
        return api_fail(err, API_ERR_DOCUMENT, "", "res: %u,%u,%u samples give a skin with no triangle (every face "
                        "collapses to a line or a point); take at least 3 samples per axis, more along an axis that "
                        "closes into a loop", o->res[0], o->res[1], o->res[2]);
    if (m->ntris == 0)
        return api_fail(err, API_ERR_DOCUMENT, "", "the skin has no triangle at res %u,%u,%u: the solid's extent, or "
                        "that of its thin parts, is below float32's resolution at its size and distance from the "
                        "origin, so its points weld together (every face collapses to a line or a point); meshes are "
                        "float32: move or scale the solid nearer unit size at the origin, or take json output, which "
                        "has full precision", o->res[0], o->res[1], o->res[2]);
    return 0;
}

int api_skin_open(api_output *o, const pde_cancel *cancel, api_error *err)
{
    api_skin *s = calloc(1, sizeof *s);
    o->st = s;
    return s ? api_out_mesh(o, cancel, &s->mesh, err) : -1;
}

void api_skin_close(void *st)
{
    api_skin *s = st;
    if (s)
        api_mesh_free(&s->mesh);
    free(s);
}

int api_out_volmesh(api_output *o, const pde_cancel *cancel, api_volmesh *m, api_error *err)
{
    if (pde_solution_is_flat(o->sol))
        return no_volume(err);
    if (api_volmesh_build(o->sol, o->res, cancel, m, err))
        return -1;
    if (m->ncells > 0)
        return 0;
    api_volmesh_free(m);
    *m = (api_volmesh){ 0 };
    return api_fail(err, API_ERR_DOCUMENT, "", "res: %u,%u,%u samples give a volume mesh with no cells (every cell "
                    "collapses to a face, a line or a point); take at least 3 samples per axis, more along an "
                    "axis that closes into a loop", o->res[0], o->res[1], o->res[2]);
}

void api_vol_close(void *st)
{
    api_vol *v = st;
    if (v)
        api_volmesh_free(&v->mesh);
    free(v);
}

int api_vol_put(void *ctx, const void *p, size_t n)
{
    return api_out_put(ctx, p, n);
}

/* ---- size-first text ---- */

void api_sw_printf(api_sw *w, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    size_t room = w->buf && w->need < w->cap ? w->cap - w->need : 0;
    int n = vsnprintf(room ? w->buf + w->need : NULL, room, fmt, ap);
    va_end(ap);
    if (n > 0)
        w->need += (size_t)n;
}

void api_sw_puts(api_sw *w, const char *s)
{
    size_t n = strlen(s);
    if (w->buf && w->need + n <= w->cap)
        memcpy(w->buf + w->need, s, n);
    w->need += n;
}
