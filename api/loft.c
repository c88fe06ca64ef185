/*
 * loft.c: loft documents to pde_loft (loft.h, docs/API.md "Lofts").
 *
 * Each section gives records (component, u factor, v factor, section, x, x_w); sorting them and
 * merging equal factors gives the loft's terms, each with its values at every section (0 where a
 * section lacks it), in a canonical order: equal lofts get equal pde_lofts, so equal ids (id.c).
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fftw3.h>

#include "jsonparse.h"
#include "loft.h"

typedef struct {
    int comp;
    pde_factor u, v;
    int section;
    double x, xw;
} record;

typedef struct {
    record *r;
    size_t n, cap;
} records;

struct api_loft {
    pde_loft loft;
    pde_section *sec;
    pde_lterm *t[3];
    double *vals;          /* every term's x then xw, K each */
    double fit_error;
};

static const char *const comp_key[3] = { "x", "y", "z" };

static int push(records *rs, int comp, pde_factor u, pde_factor v, int section, double x, double xw)
{
    if (x == 0.0 && xw == 0.0)
        return 0;
    if (rs->n == rs->cap) {
        size_t cap = rs->cap ? 2 * rs->cap : 64;
        record *r = realloc(rs->r, cap * sizeof *r);
        if (!r)
            return -1;
        rs->r = r, rs->cap = cap;
    }
    rs->r[rs->n++] = (record){ comp, u, v, section, x + 0.0, xw + 0.0 };   /* -0 as 0 */
    return 0;
}

static int cmp_factor(pde_factor a, pde_factor b)
{
    if (a.kind != b.kind)
        return a.kind < b.kind ? -1 : 1;
    return a.p < b.p ? -1 : a.p > b.p;
}

static int cmp_record(const void *pa, const void *pb)
{
    const record *a = pa, *b = pb;
    int c = a->comp != b->comp ? (a->comp < b->comp ? -1 : 1) : cmp_factor(a->u, b->u);
    if (!c)
        c = cmp_factor(a->v, b->v);
    return c ? c : (a->section > b->section) - (a->section < b->section);
}

/* c as three finite numbers into out, quickly: 0, or -1 without a word (the caller then asks
 * api_json_vector3() for the error, so that a pointer is only written for a bad point). */
static int quick_vector3(const cJSON *c, double out[3])
{
    if (!cJSON_IsArray(c))
        return -1;
    int i = 0;
    for (const cJSON *e = c->child; e; e = e->next, i++)
        if (i > 2 || !cJSON_IsNumber(e) || !isfinite(e->valuedouble))
            return -1;
        else
            out[i] = e->valuedouble;
    return i == 3 ? 0 : -1;
}

/* ---- FFTW: plans once per size and direction, under a lock ---- */

#define PLAN_CACHE 64

static pthread_mutex_t plan_lock = PTHREAD_MUTEX_INITIALIZER;
static struct {
    int n, inverse;
    fftw_plan p;
} plans[PLAN_CACHE];
static int nplans;

enum { R2C, C2R, DCT1 };   /* real to complex, its inverse, and the DCT-I (FFTW's REDFT00) */

/* The plan of a transform of n points of this kind, or NULL if FFTW fails. Past PLAN_CACHE sizes
 * the plan is made for this call alone (*owned set): give it back with plan_done(). */
static fftw_plan plan_for(int n, int kind, int *owned)
{
    pthread_mutex_lock(&plan_lock);
    fftw_plan p = NULL;
    *owned = 0;
    for (int i = 0; i < nplans && !p; i++)
        if (plans[i].n == n && plans[i].inverse == kind)
            p = plans[i].p;
    if (!p) {
        double *r = fftw_alloc_real((size_t)n), *r2 = fftw_alloc_real((size_t)n);
        fftw_complex *c = fftw_alloc_complex((size_t)n / 2 + 1);
        if (r && r2 && c)
            p = kind == C2R   ? fftw_plan_dft_c2r_1d(n, c, r, FFTW_ESTIMATE)
                : kind == R2C ? fftw_plan_dft_r2c_1d(n, r, c, FFTW_ESTIMATE)
                              : fftw_plan_r2r_1d(n, r, r2, FFTW_REDFT00, FFTW_ESTIMATE);
        fftw_free(r);
        fftw_free(r2);
        fftw_free(c);
        if (p && nplans < PLAN_CACHE)
            plans[nplans].n = n, plans[nplans].inverse = kind, plans[nplans++].p = p;
        else if (p)
            *owned = 1;
    }
    pthread_mutex_unlock(&plan_lock);
    return p;
}

static void plan_done(fftw_plan p, int owned)
{
    if (!owned || !p)
        return;
    pthread_mutex_lock(&plan_lock);   /* FFTW's planner state is shared: destroying is not thread-safe */
    fftw_destroy_plan(p);
    pthread_mutex_unlock(&plan_lock);
}

/*
 * The records of one closed curve of n points pts[j] (x, y, z) at v = j/n, as x = C + u (P(v) - C)
 * at section k, into x (tangent 0) or x_w (tangent 1); centre NULL: the points' mean. Harmonics
 * below tol of the curve's size are dropped; *fit gets the largest distance from a point to the
 * fitted curve.
 */
static int fit_curve(records *rs, int k, int tangent, const double (*pts)[3], int n, const double *centre,
                     double tol, double *fit)
{
    const int nh = n / 2 + 1;
    int own_f, own_i;
    fftw_plan fwd = plan_for(n, R2C, &own_f), inv = plan_for(n, C2R, &own_i);
    double *in = fftw_alloc_real((size_t)n);
    fftw_complex *out = fftw_alloc_complex((size_t)nh);
    int rc = fwd && inv && in && out ? 0 : -1;
    double mean[3], size = 0.0;
    for (int c = 0; c < 3 && !rc; c++) {
        mean[c] = 0.0;
        for (int j = 0; j < n; j++)
            mean[c] += pts[j][c];
        mean[c] /= n;
    }
    for (int j = 0; j < n && !rc; j++)
        for (int c = 0; c < 3; c++)
            size = fmax(size, fabs(pts[j][c] - (centre ? centre[c] : mean[c])));
    const double cut = tol * size;
    for (int c = 0; c < 3 && !rc; c++) {
        const double C = centre ? centre[c] : mean[c];
        for (int j = 0; j < n; j++)
            in[j] = pts[j][c];
        fftw_execute_dft_r2c(fwd, in, out);
        const pde_factor one = { PDE_POW, 0 }, u = { PDE_POW, 1 };
        double x0 = fabs(C) < cut ? 0.0 : C, x1 = fabs(mean[c] - C) < cut ? 0.0 : mean[c] - C;
        out[0][0] = (x0 + x1) * n, out[0][1] = 0.0;   /* the kept mean, for the fit error */
        rc |= push(rs, c, one, one, k, tangent ? 0 : x0, tangent ? x0 : 0);
        rc |= push(rs, c, u, one, k, tangent ? 0 : x1, tangent ? x1 : 0);
        for (int m = 1; m < nh; m++) {
            const int top = 2 * m == n;   /* even n: the Nyquist term, a cosine alone */
            double a = (top ? 1.0 : 2.0) * out[m][0] / n, b = top ? 0.0 : -2.0 * out[m][1] / n;
            if (fabs(a) < cut)
                a = 0.0, out[m][0] = 0.0;
            if (fabs(b) < cut)
                b = 0.0, out[m][1] = 0.0;
            const pde_factor cs = { PDE_COS, 2.0 * m }, sn = { PDE_SIN, 2.0 * m };
            rc |= push(rs, c, u, cs, k, tangent ? 0 : a, tangent ? a : 0);
            rc |= push(rs, c, u, sn, k, tangent ? 0 : b, tangent ? b : 0);
        }
        /* The fitted curve at the points (u = 1): the kept coefficients transformed back. */
        fftw_execute_dft_c2r(inv, out, in);
        for (int j = 0; j < n; j++)
            *fit = fmax(*fit, fabs(in[j] / n - pts[j][c]));
    }
    fftw_free(in);
    fftw_free(out);
    plan_done(fwd, own_f);
    plan_done(inv, own_i);
    return rc;
}

/* The cosine (or, periodic, Fourier) coefficients of n samples in place, by DCT-I (REDFT00) at t = i/(n-1)
 * or the real DFT at t = i/n: x[k] of cos(k pi t) (k < n); periodic, x[2m-1] of cos(2 pi m t), x[2m] of sin. */
static int coefficients(double *x, int n, int periodic)
{
    int own;
    fftw_plan p = plan_for(n, periodic ? R2C : DCT1, &own);
    double *in = fftw_alloc_real((size_t)n), *out = fftw_alloc_real((size_t)n);
    fftw_complex *c = fftw_alloc_complex((size_t)n / 2 + 1);
    int rc = p && in && out && c ? 0 : -1;
    if (!rc) {
        memcpy(in, x, (size_t)n * sizeof *x);
        if (periodic) {
            fftw_execute_dft_r2c(p, in, c);
            x[0] = c[0][0] / n;
            for (int m = 1; 2 * m <= n; m++) {   /* even n: the Nyquist term, a cosine alone */
                const int top = 2 * m == n;
                x[2 * m - 1] = (top ? 1.0 : 2.0) * c[m][0] / n;
                if (!top)
                    x[2 * m] = -2.0 * c[m][1] / n;
            }
        } else {
            fftw_execute_r2r(p, in, out);
            for (int k = 0; k < n; k++)
                x[k] = out[k] / (n - 1) * (k == 0 || k == n - 1 ? 0.5 : 1.0);
        }
    }
    fftw_free(in);
    fftw_free(out);
    fftw_free(c);
    plan_done(p, own);
    return rc;
}

/* The factor of coefficient k of coefficients(): cos(k pi t), or periodic cos / sin(2 pi m t); 1 for k = 0. */
static pde_factor coefficient_factor(int k, int periodic)
{
    if (k == 0)
        return (pde_factor){ PDE_POW, 0 };
    if (!periodic)
        return (pde_factor){ PDE_COS, k };
    return k % 2 ? (pde_factor){ PDE_COS, k + 1.0 } : (pde_factor){ PDE_SIN, k };   /* 2 pi m t: k pi t, k = 2m */
}

/*
 * A sampled surface: nv rows of nu points, p[j * nu + i] at u = i/(nu - 1), v = j/(nv - 1) (periodic:
 * j/nv), fitted by cosine series in u and in v (Fourier in a periodic v): eigenfunctions of d4, so each
 * product is a mode. Coefficients below tol of the surface's size are dropped.
 */
static int fit_grid(records *rs, int k, const double (*p)[3], int nu, int nv, int periodic, double tol, double *fit)
{
    double *a = malloc((size_t)nu * nv * sizeof *a), *col = malloc((size_t)(nu > nv ? nu : nv) * sizeof *col);
    int rc = a && col ? 0 : -1;
    double mean[3] = { 0, 0, 0 }, size = 0.0;
    for (int q = 0; q < nu * nv; q++)
        for (int c = 0; c < 3; c++)
            mean[c] += p[q][c] / (nu * nv);
    for (int q = 0; q < nu * nv; q++)
        for (int c = 0; c < 3; c++)
            size = fmax(size, fabs(p[q][c] - mean[c]));
    for (int c = 0; c < 3 && !rc; c++) {
        double dropped = 0.0;   /* each basis function is at most 1 in size: a bound of the fit's error */
        for (int j = 0; j < nv && !rc; j++) {   /* along u, each row */
            for (int i = 0; i < nu; i++)
                a[j * nu + i] = p[j * nu + i][c];
            rc = coefficients(a + (size_t)j * nu, nu, 0);
        }
        for (int i = 0; i < nu && !rc; i++) {   /* then along v, each column */
            for (int j = 0; j < nv; j++)
                col[j] = a[j * nu + i];
            if ((rc = coefficients(col, nv, periodic)))
                break;
            for (int j = 0; j < nv && !rc; j++)
                if (fabs(col[j]) >= tol * size && col[j] != 0.0)
                    rc = push(rs, c, coefficient_factor(i, 0), coefficient_factor(j, periodic), k, col[j], 0);
                else
                    dropped += fabs(col[j]);
        }
        *fit = fmax(*fit, dropped);
    }
    free(a);
    free(col);
    return rc;
}

/* An array of n >= 3 points [x, y, z] (want: the count it must have, or 0). */
static int get_points(const cJSON *j, const char *ptr, int want, double (**out)[3], int *n, api_error *err)
{
    if (!cJSON_IsArray(j))
        return api_fail(err, API_ERR_DOCUMENT, ptr, "must be an array of points [x, y, z], not %s", api_json_type(j));
    int k = cJSON_GetArraySize(j);
    if (want && k != want)
        return api_fail(err, API_ERR_DOCUMENT, ptr, "has %d vector%s; it needs one for each of the profile's %d points", k, k == 1 ? "" : "s", want);
    if (k < 3)
        return api_fail(err, API_ERR_DOCUMENT, ptr, "has %d points; a closed curve needs at least 3", k);
    if (k > API_LOFT_MAX_POINTS) {
        return api_fail(err, API_ERR_LIMIT, ptr, "has %d points, over the limit of %d", k, API_LOFT_MAX_POINTS);
    }
    double(*p)[3] = malloc((size_t)k * sizeof *p);
    if (!p)
        return api_fail(err, API_ERR_NOMEM, ptr, "out of memory");
    int i = 0;
    for (const cJSON *c = j->child; c; c = c->next, i++) {
        if (!quick_vector3(c, p[i]))
            continue;
        char q[200];
        snprintf(q, sizeof q, "%s/%d", ptr, i);
        if (api_json_vector3(c, q, p[i], err)) {
            free(p);
            return -1;
        }
    }
    *out = p, *n = k;
    return 0;
}

/* A term's factor: as a model's, but a loft's powers are t^0 to t^3 (higher ones chain modes, which core/loft.c
 * does not take), said at the factor's own pointer rather than the core's /loft/pde. */
static int loft_factor(const cJSON *j, const char *ptr, pde_factor *f, api_error *err)
{
    const cJSON *pw = cJSON_IsObject(j) ? cJSON_GetObjectItemCaseSensitive(j, "pow") : NULL;
    if (cJSON_IsNumber(pw) && !(pw->valuedouble >= 0 && pw->valuedouble <= 3 && pw->valuedouble == floor(pw->valuedouble))) {
        char q[260];
        api_json_child(q, sizeof q, ptr, "pow");
        return api_fail(err, API_ERR_DOCUMENT, q, "lofts take powers t^0 to t^3 only (0, 1, 2 or 3), not %.17g",
                        pw->valuedouble);
    }
    return api_json_factor(j, ptr, f, err);
}

/* A section of the terms form: {"x": [{"u": F, "v": F, "c": n, "dw": n}], ...}; *tangent: any "dw". */
static int parse_terms(const cJSON *j, const char *ptr, records *rs, int k, int *tangent, api_error *err)
{
    static const char *const xyz[] = { "x", "y", "z", NULL };
    static const char *const keys[] = { "u", "v", "c", "dw", NULL };
    const cJSON *comps[3];
    if (api_json_object(j, ptr, xyz, comps, err))
        return -1;
    for (int c = 0; c < 3; c++) {
        if (!comps[c])
            continue;
        char q[200];
        api_json_child(q, sizeof q, ptr, comp_key[c]);
        if (!cJSON_IsArray(comps[c]))
            return api_fail(err, API_ERR_DOCUMENT, q, "must be an array of terms, not %s", api_json_type(comps[c]));
        int i = 0;
        for (const cJSON *t = comps[c]->child; t; t = t->next, i++) {
            char r[220], s[240];
            snprintf(r, sizeof r, "%s/%d", q, i);
            const cJSON *f[4];
            pde_factor u, v;
            double x, xw;
            if (api_json_object(t, r, keys, f, err))
                return -1;
            api_json_child(s, sizeof s, r, "u");
            if (loft_factor(f[0], s, &u, err))
                return -1;
            api_json_child(s, sizeof s, r, "v");
            if (loft_factor(f[1], s, &v, err))
                return -1;
            api_json_child(s, sizeof s, r, "c");
            if (api_json_number(f[2], s, &x, err))
                return -1;
            api_json_child(s, sizeof s, r, "dw");
            if (api_json_number(f[3], s, &xw, err))
                return -1;
            *tangent |= f[3] != NULL;
            if (push(rs, c, u, v, k, x, xw))
                return api_fail(err, API_ERR_NOMEM, r, "out of memory");
        }
    }
    return 0;
}

/* "grid": nv rows of nu points [x, y, z] each, nu, nv >= 2 (periodic: nv >= 3); "periodic": v wraps. */
static int parse_grid(const cJSON *g, const cJSON *per, const char *ptr, int k, double tol, records *rs, double *fit,
                      api_error *err)
{
    if (per && !cJSON_IsBool(per))
        return api_fail(err, API_ERR_DOCUMENT, ptr, "\"periodic\" must be true or false");
    const int periodic = per && cJSON_IsTrue(per);
    if (!cJSON_IsArray(g) || cJSON_GetArraySize(g) < (periodic ? 3 : 2))
        return api_fail(err, API_ERR_DOCUMENT, ptr, "must be an array of at least %d rows (one per v) of points [x, y, z]", periodic ? 3 : 2);
    const int nv = cJSON_GetArraySize(g), nu = cJSON_IsArray(g->child) ? cJSON_GetArraySize(g->child) : 0;
    if (nu < 2)
        return api_fail(err, API_ERR_DOCUMENT, ptr, "each row must be an array of at least 2 points [x, y, z] (one per u)");
    if ((long)nu * nv > API_LOFT_MAX_GRID) {
        return api_fail(err, API_ERR_LIMIT, ptr, "has %d x %d points, over the limit of %d", nv, nu, API_LOFT_MAX_GRID);
    }
    double(*p)[3] = malloc((size_t)nu * nv * sizeof *p);
    if (!p)
        return api_fail(err, API_ERR_NOMEM, ptr, "out of memory");
    int j = 0, rc = 0;
    for (const cJSON *row = g->child; row && !rc; row = row->next, j++) {
        char r[220];
        snprintf(r, sizeof r, "%s/%d", ptr, j);
        if (!cJSON_IsArray(row) || cJSON_GetArraySize(row) != nu) {
            rc = api_fail(err, API_ERR_DOCUMENT, r, "must be an array of %d points, as the first row", nu);
            break;
        }
        int i = 0;
        for (const cJSON *c = row->child; c && !rc; c = c->next, i++) {
            if (!quick_vector3(c, p[j * nu + i]))
                continue;
            char t[240];
            snprintf(t, sizeof t, "%s/%d", r, i);
            rc = api_json_vector3(c, t, p[j * nu + i], err);
        }
    }
    if (!rc && fit_grid(rs, k, (const double(*)[3])p, nu, nv, periodic, tol, fit))
        rc = api_fail(err, API_ERR_NOMEM, ptr, "out of memory");
    free(p);
    return rc;
}

static int parse_section(const cJSON *j, const char *ptr, int k, double tol, api_loft *l, records *rs, api_error *err)
{
    static const char *const keys[] = { "w", "profile", "tangent", "centre", "terms", "grid", "periodic", NULL };
    const cJSON *f[7];
    char q[200];
    if (api_json_object(j, ptr, keys, f, err))
        return -1;
    api_json_child(q, sizeof q, ptr, "w");
    if (!f[0])
        return api_fail(err, API_ERR_DOCUMENT, q, "is required: the section's place along w, from 0 to 1");
    if (api_json_number(f[0], q, &l->sec[k].w, err))
        return -1;
    if (!!f[1] + !!f[4] + !!f[5] != 1)
        return api_fail(err, API_ERR_DOCUMENT, ptr, "a section %s one of \"profile\" (points of a curve), \"grid\" (a sampled surface) "
                        "or \"terms\" (closed form)", (!!f[1] + !!f[4] + !!f[5]) ? "takes only" : "needs");
    if (f[6] && !f[5])
        return api_fail(err, API_ERR_DOCUMENT, ptr, "\"periodic\" goes with \"grid\"");
    if (f[5]) {
        if (f[2] || f[3])
            return api_fail(err, API_ERR_DOCUMENT, ptr, "\"tangent\" and \"centre\" go with \"profile\"");
        api_json_child(q, sizeof q, ptr, "grid");
        return parse_grid(f[5], f[6], q, k, tol, rs, &l->fit_error, err);
    }
    if (f[4]) {
        if (f[2] || f[3])
            return api_fail(err, API_ERR_DOCUMENT, ptr, "\"tangent\" and \"centre\" go with \"profile\"; in \"terms\", give x_w as \"dw\"");
        api_json_child(q, sizeof q, ptr, "terms");
        return parse_terms(f[4], q, rs, k, &l->sec[k].tangent, err);
    }
    double(*pts)[3] = NULL, (*tan)[3] = NULL, centre[3];
    int n = 0, nt = 0, rc = 0;
    api_json_child(q, sizeof q, ptr, "profile");
    if (get_points(f[1], q, 0, &pts, &n, err))
        return -1;
    if (f[3]) {
        api_json_child(q, sizeof q, ptr, "centre");
        rc = api_json_vector3(f[3], q, centre, err);
    }
    if (!rc && f[2]) {
        api_json_child(q, sizeof q, ptr, "tangent");
        rc = get_points(f[2], q, n, &tan, &nt, err);
        l->sec[k].tangent = 1;
    }
    if (!rc && fit_curve(rs, k, 0, (const double(*)[3])pts, n, f[3] ? centre : NULL, tol, &l->fit_error))
        rc = api_fail(err, API_ERR_NOMEM, ptr, "out of memory");
    if (!rc && tan && fit_curve(rs, k, 1, (const double(*)[3])tan, nt, NULL, tol, &l->fit_error))
        rc = api_fail(err, API_ERR_NOMEM, ptr, "out of memory");
    free(pts);
    free(tan);
    return rc;
}

/* Record i of the sorted records starts a term: its component or factors differ from i - 1's. */
static int new_term(const records *rs, size_t i)
{
    const record *a = &rs->r[i], *b = i ? &rs->r[i - 1] : NULL;
    return !b || a->comp != b->comp || cmp_factor(a->u, b->u) || cmp_factor(a->v, b->v);
}

/* The sorted records as terms with K values each. */
static int build_terms(api_loft *l, records *rs, api_error *err)
{
    const size_t K = l->loft.nsections;
    if (rs->n)   /* sections that are all zero leave none: the zero solid (qsort takes no NULL) */
        qsort(rs->r, rs->n, sizeof *rs->r, cmp_record);
    size_t nt[3] = { 0, 0, 0 }, total = 0;
    for (size_t i = 0; i < rs->n; i++)
        if (new_term(rs, i))
            nt[rs->r[i].comp]++, total++;
    l->vals = calloc(2 * K * (total ? total : 1), sizeof *l->vals);
    for (int c = 0; c < 3; c++)
        l->t[c] = calloc(nt[c] ? nt[c] : 1, sizeof *l->t[c]);
    if (!l->vals || !l->t[0] || !l->t[1] || !l->t[2])
        return api_fail(err, API_ERR_NOMEM, "", "out of memory");
    double *x = l->vals;
    for (size_t i = 0, used = 0; i < rs->n; i++) {
        const record *r = &rs->r[i];
        if (new_term(rs, i)) {
            x = l->vals + 2 * K * used++;
            l->t[r->comp][l->loft.comp[r->comp].nterms++] = (pde_lterm){ r->u, r->v, x, x + K };
        }
        x[r->section] += r->x;
        x[K + r->section] += r->xw;
    }
    for (int c = 0; c < 3; c++)
        l->loft.comp[c].terms = l->t[c];
    return 0;
}

api_loft *api_loft_parse(const cJSON *j, const char *ptr, api_error *err)
{
    static const char *const keys[] = { "pde", "sections", "tol", NULL };
    static const char *const abc[] = { "a", "b", "c", NULL };
    const cJSON *f[3], *p[3];
    char q[200];
    if (api_json_object(j, ptr, keys, f, err))
        return NULL;
    api_loft *l = calloc(1, sizeof *l);
    records rs = { 0 };
    if (!l) {
        api_fail(err, API_ERR_NOMEM, ptr, "out of memory");
        return NULL;
    }
    double tol = API_LOFT_TOL;
    int rc = 0;
    api_json_child(q, sizeof q, ptr, "pde");
    if (!f[0])
        rc = api_fail(err, API_ERR_DOCUMENT, q, "is required: {\"a\": [..], \"b\": [..], \"c\": [..]}, the PDE's coefficients");
    else if (!(rc = api_json_object(f[0], q, abc, p, err)))
        for (int k = 0; k < 3 && !rc; k++) {
            double v[3];
            char r[220];
            api_json_child(r, sizeof r, q, abc[k]);
            if (!(rc = api_json_vector3(p[k], r, v, err)))
                for (int c = 0; c < 3; c++)
                    *(k == 0 ? &l->loft.comp[c].a : k == 1 ? &l->loft.comp[c].b : &l->loft.comp[c].c) = v[c];
        }
    if (!rc && f[2]) {
        api_json_child(q, sizeof q, ptr, "tol");
        if (!(rc = api_json_number(f[2], q, &tol, err)) && !(tol >= 0 && tol < 1))
            rc = api_fail(err, API_ERR_DOCUMENT, q, "must be at least 0 and below 1: the fraction of a section's size below which harmonics are dropped");
    }
    api_json_child(q, sizeof q, ptr, "sections");
    int ns = cJSON_IsArray(f[1]) ? cJSON_GetArraySize(f[1]) : -1;
    if (!rc && !f[1])
        rc = api_fail(err, API_ERR_DOCUMENT, q, "is required: an array of sections, the first at w = 0 and the last at w = 1");
    else if (!rc && ns < 0)
        rc = api_fail(err, API_ERR_DOCUMENT, q, "must be an array of sections, not %s", api_json_type(f[1]));
    else if (!rc && ns < 2)
        rc = api_fail(err, API_ERR_DOCUMENT, q, "has %d section%s; a loft needs at least 2, at w = 0 and w = 1", ns, ns == 1 ? "" : "s");
    else if (!rc && ns > PDE_MAX_SECTIONS) {
        rc = api_fail(err, API_ERR_LIMIT, q, "has %d sections, over the limit of %d", ns, PDE_MAX_SECTIONS);
    }
    if (!rc && !(l->sec = calloc((size_t)ns, sizeof *l->sec)))
        rc = api_fail(err, API_ERR_NOMEM, ptr, "out of memory");
    int k = 0;
    for (const cJSON *s = rc ? NULL : f[1]->child; s && !rc; s = s->next, k++) {
        char r[220];
        snprintf(r, sizeof r, "%s/%d", q, k);
        rc = parse_section(s, r, k, tol, l, &rs, err);
    }
    if (!rc) {
        l->loft.sections = l->sec;
        l->loft.nsections = (size_t)ns;
        l->loft.fit_error = l->fit_error;
        rc = build_terms(l, &rs, err);
    }
    free(rs.r);
    if (rc) {
        api_loft_free(l);
        return NULL;
    }
    return l;
}

void api_loft_free(api_loft *l)
{
    if (!l)
        return;
    for (int c = 0; c < 3; c++)
        free(l->t[c]);
    free(l->vals);
    free(l->sec);
    free(l);
}

const pde_loft *api_loft_get(const api_loft *l)
{
    return &l->loft;
}

int api_loft_solve(const api_loft *l, const char *ptr, const pde_cancel *cancel, pde_solution **out, api_error *err)
{
    pde_diag d;
    pde_solve_opts o = { .cancel = cancel };
    pde_status st = pde_solve_loft(&l->loft, &o, out, &d);
    if (st == PDE_OK)
        return 0;
    if (st == PDE_ERR_CANCELLED)
        return api_fail_cancelled(err);
    char p[200];
    if (d.section >= 0)
        snprintf(p, sizeof p, "%s/sections/%d%s", ptr, d.section, strcmp(d.field, "w") ? "" : "/w");
    else if (d.component >= 0 && d.field[0] && strchr("abc", d.field[0]) && !d.field[1])
        snprintf(p, sizeof p, "%s/pde/%s/%d", ptr, d.field, d.component);
    else
        snprintf(p, sizeof p, "%s/pde", ptr);
    api_fail(err, api_status_of(st), p, "%s",
             d.message[0] ? d.message : pde_strerror(st));
    return (int)st;
}
