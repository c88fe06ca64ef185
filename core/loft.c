/*
 * loft.c: pde_solve_loft(), solids through sections (pde.h, docs/MATH.md "Lofts").
 *
 * DESIGN
 * Between sections there is no force, so each mode (f_u, f_v) solves h'''' = e h on each slab
 * [w_s, w_(s+1)], e = -(a lu + b lv) / c (eq. 8). On a slab h is a combination of four basis
 * functions, so the loft's problem for one e is a banded system of 4 S unknowns (S slabs): two
 * conditions at each end section, four at each interior one. The system depends on e and the
 * breaks only; it is factored once per distinct e and shared by the modes and components with
 * that e. Lofts take no powers t^n with n >= 4 (they would chain, as in solve.c).
 *
 * The basis of a slab of width L, with t = |e|^(1/4):
 *   t L > 1, e > 0:  exp(t (w - w1)), exp(-t (w - w0)), cos t (w - w0), sin t (w - w0);
 *   t L > 1, e < 0:  exp(z (w - w1)), exp(z' (w - w0)) (real and imaginary parts),
 *                    z = (1 + i) t / sqrt 2, z' = (-1 + i) t / sqrt 2;
 *   t L <= 1:        the series B_j = sum q_n ((w - w0) / L)^n with B_j^(k)(w0) = delta_jk L^-k,
 *                    which tends to the cubic basis as e L^4 -> 0 and stays well conditioned.
 * Growing exponentials are anchored at the slab's far end, so no basis function exceeds 1 (times its
 * coefficient) on its slab, whatever the width. Derivative rows are scaled by rho^-k, rho = max(t, 1/L),
 * so that the entries are O(1); the condition estimate is that of the scaled system.
 */
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

#define LOFT_COND_LIMIT 1e12    /* as solve.c's COND_LIMIT */
#define LOFT_THIN_COND 100.0     /* a slab of width L alone: condition below this / L (check_thin_slab) */
#define LOFT_RESIDUAL_LIMIT 1e-6   /* a solution's section conditions, relative (check_sections_met) */
#define KL 5                    /* sub-diagonals of the slab system */
#define KU 10                   /* super-diagonals of its U factor, with the row swaps */
#define BW (KL + KU + 1)
#define SERIES_MAX 64
/* t L at or below: the series basis. Its expansion in powers of w loses about eps (t / 0.02)^4 L^-4 of
 * h; the exponential basis above loses about eps / (t L)^3. Both stay near 1e-11 at L = 1e-3. */
#define SERIES_TL 0.02

/* One slab's basis for one e. */
typedef struct {
    int kind;             /* 0: series; 1: e > 0 exponentials; 2: e < 0 */
    double rho;           /* the row scale: derivative k rows times rho^-k */
    double t;             /* |e|^(1/4) */
    double D[4][2][4];    /* [basis j][end 0/1][order k]: rho^-k B_j^(k) at the slab's ends */
    int deg;              /* series: degree of q */
    double q[4][SERIES_MAX + 1];   /* series: B_j = sum q_n ((w - w0) / L)^n */
} slab_basis;

typedef struct {
    double e;
    size_t n;             /* 4 S unknowns */
    slab_basis *sb;       /* S */
    double *lu;           /* n x BW band: A[i][j] at lu[i * BW + j - i + KL] */
    int *piv;
    double cond;
    size_t worst_slab;    /* the slab of the smallest pivot */
    int singular;
} loft_plan;

static void basis_for(double e, double w0, double w1, slab_basis *b)
{
    const double L = w1 - w0, t = pow(fabs(e), 0.25);
    memset(b, 0, sizeof *b);
    b->t = t;
    if (!(t * L > SERIES_TL)) {
        /* Series in s = (w - w0) / L: q_(n+4) = e L^4 q_n / ((n+1)..(n+4)), q_j = 1/j!. */
        b->kind = 0;
        b->rho = 1.0 / L;
        const double eL4 = e * L * L * L * L;
        static const double fact[4] = { 1.0, 1.0, 2.0, 6.0 };
        int deg = 3;
        for (int j = 0; j < 4; j++) {
            b->q[j][j] = 1.0 / fact[j];
            for (int n = j; n + 4 <= SERIES_MAX; n += 4) {
                double next = b->q[j][n] * eL4 / ((n + 1.0) * (n + 2.0) * (n + 3.0) * (n + 4.0));
                if (fabs(next) < 1e-19 * b->q[j][j])
                    break;
                b->q[j][n + 4] = next;
                if (n + 4 > deg)
                    deg = n + 4;
            }
        }
        b->deg = deg;
        for (int j = 0; j < 4; j++)
            for (int k = 0; k < 4; k++) {
                b->D[j][0][k] = j == k ? 1.0 : 0.0;
                double s = 0.0;
                for (int n = deg; n >= k; n--) {
                    double f = 1.0;
                    for (int i = 0; i < k; i++)
                        f *= n - i;
                    s += f * b->q[j][n];
                }
                b->D[j][1][k] = s;
            }
        return;
    }
    b->rho = t;
    if (e > 0.0) {
        b->kind = 1;
        const double E = exp(-t * L);
        const double complex eitl = cexp(I * t * L);
        double complex ik = 1.0;   /* (i t)^k / t^k */
        for (int k = 0; k < 4; k++) {
            double sg = k & 1 ? -1.0 : 1.0;
            b->D[0][0][k] = E, b->D[0][1][k] = 1.0;
            b->D[1][0][k] = sg, b->D[1][1][k] = sg * E;
            b->D[2][0][k] = creal(ik), b->D[3][0][k] = cimag(ik);
            b->D[2][1][k] = creal(ik * eitl), b->D[3][1][k] = cimag(ik * eitl);
            ik *= I;
        }
        return;
    }
    b->kind = 2;
    const double complex z = (1.0 + I) * M_SQRT1_2, zd = (-1.0 + I) * M_SQRT1_2;   /* over t */
    const double complex Eg = cexp(-z * t * L), Ed = cexp(zd * t * L);
    double complex zk = 1.0, zdk = 1.0;
    for (int k = 0; k < 4; k++) {
        b->D[0][0][k] = creal(zk * Eg), b->D[1][0][k] = cimag(zk * Eg);
        b->D[0][1][k] = creal(zk), b->D[1][1][k] = cimag(zk);
        b->D[2][0][k] = creal(zdk), b->D[3][0][k] = cimag(zdk);
        b->D[2][1][k] = creal(zdk * Ed), b->D[3][1][k] = cimag(zdk * Ed);
        zk *= z;
        zdk *= zd;
    }
}

static double *band_at(double *lu, size_t i, size_t j)
{
    return &lu[i * BW + (j + KL - i)];
}

/* The rows of section k: (slab, basis j) coefficients, for the conditions of pde.h. The row scale of
 * a derivative row of order d is rho^-d of its slab (both slabs' largest rho for a continuity row). */
typedef struct {
    int kind;      /* 0: value on the left slab, 1: on the right; 2: continuity of order d */
    int d;
} cond_row;

static int section_rows(const pde_section *sec, size_t k, size_t K, cond_row r[4])
{
    if (k == 0) {
        r[0] = (cond_row){ 1, 0 };
        r[1] = (cond_row){ 1, sec[k].tangent ? 1 : 2 };
        return 2;
    }
    if (k == K - 1) {
        r[0] = (cond_row){ 0, 0 };
        r[1] = (cond_row){ 0, sec[k].tangent ? 1 : 2 };
        return 2;
    }
    if (sec[k].tangent) {
        r[0] = (cond_row){ 0, 0 };
        r[1] = (cond_row){ 0, 1 };
        r[2] = (cond_row){ 1, 0 };
        r[3] = (cond_row){ 1, 1 };
    } else {
        r[0] = (cond_row){ 0, 0 };
        r[1] = (cond_row){ 1, 0 };
        r[2] = (cond_row){ 2, 1 };
        r[3] = (cond_row){ 2, 2 };
    }
    return 4;
}

static void band_solve(const loft_plan *p, double *x)
{
    const size_t n = p->n;
    for (size_t k = 0; k < n; k++) {
        size_t q = (size_t)p->piv[k];
        if (q != k) {
            double t = x[k];
            x[k] = x[q];
            x[q] = t;
        }
        for (size_t i = k + 1; i < n && i <= k + KL; i++)
            x[i] -= p->lu[i * BW + (k + KL - i)] * x[k];
    }
    for (size_t i = n; i-- > 0;) {
        double s = x[i];
        for (size_t j = i + 1; j < n && j <= i + KU; j++)
            s -= p->lu[i * BW + (j + KL - i)] * x[j];
        x[i] = s / p->lu[i * BW + KL];
    }
}

static pde_status plan_build(const pde_loft *lf, double e, int estimate, loft_plan *p)
{
    const size_t K = lf->nsections, S = K - 1, n = 4 * S;
    p->e = e;
    p->n = n;
    p->sb = malloc(S * sizeof *p->sb);
    p->lu = calloc(n * BW, sizeof *p->lu);
    p->piv = malloc(n * sizeof *p->piv);
    if (!p->sb || !p->lu || !p->piv)
        return PDE_ERR_NOMEM;
    for (size_t s = 0; s < S; s++)
        basis_for(e, lf->sections[s].w, lf->sections[s + 1].w, &p->sb[s]);
    size_t row = 0;
    for (size_t k = 0; k < K; k++) {
        cond_row r[4];
        int nr = section_rows(lf->sections, k, K, r);
        for (int i = 0; i < nr; i++, row++) {
            if (r[i].kind < 2) {
                size_t s = r[i].kind ? k : k - 1;
                for (int j = 0; j < 4; j++)
                    *band_at(p->lu, row, 4 * s + (size_t)j) = p->sb[s].D[j][r[i].kind ? 0 : 1][r[i].d];
            } else {
                const slab_basis *bl = &p->sb[k - 1], *br = &p->sb[k];
                double rm = fmax(bl->rho, br->rho);
                double fl = pow(bl->rho / rm, r[i].d), fr = pow(br->rho / rm, r[i].d);
                for (int j = 0; j < 4; j++) {
                    *band_at(p->lu, row, 4 * (k - 1) + (size_t)j) = fl * bl->D[j][1][r[i].d];
                    *band_at(p->lu, row, 4 * k + (size_t)j) = -fr * br->D[j][0][r[i].d];
                }
            }
        }
    }
    /* The 1-norm of the matrix, then LU with partial pivoting inside the band. */
    double norm = 0.0;
    for (size_t j = 0; j < n; j++) {
        double col = 0.0;
        for (size_t i = j >= KU ? j - KU : 0; i < n && i <= j + KL; i++)
            col += fabs(*band_at(p->lu, i, j));
        norm = fmax(norm, col);
    }
    double pmin = INFINITY;
    p->worst_slab = 0;
    p->singular = 0;
    for (size_t k = 0; k < n; k++) {
        size_t q = k;
        for (size_t i = k + 1; i < n && i <= k + KL; i++)
            if (fabs(*band_at(p->lu, i, k)) > fabs(*band_at(p->lu, q, k)))
                q = i;
        p->piv[k] = (int)q;
        size_t jend = k + KU < n - 1 ? k + KU : n - 1;
        if (q != k)
            for (size_t j = k; j <= jend; j++) {
                double t = *band_at(p->lu, k, j);
                *band_at(p->lu, k, j) = *band_at(p->lu, q, j);
                *band_at(p->lu, q, j) = t;
            }
        double piv = *band_at(p->lu, k, k);
        if (fabs(piv) < pmin)
            pmin = fabs(piv), p->worst_slab = k / 4;
        if (piv == 0.0) {
            p->singular = 1;
            p->cond = INFINITY;
            return PDE_OK;
        }
        for (size_t i = k + 1; i < n && i <= k + KL; i++) {
            double l = *band_at(p->lu, i, k) / piv;
            *band_at(p->lu, i, k) = l;
            if (l != 0.0)
                for (size_t j = k + 1; j <= jend; j++)
                    *band_at(p->lu, i, j) -= l * *band_at(p->lu, k, j);
        }
    }
    p->cond = 0.0;
    if (estimate) {
        double *x = malloc(n * sizeof *x), inorm = 0.0;
        if (!x)
            return PDE_ERR_NOMEM;
        for (size_t c = 0; c < n; c++) {
            memset(x, 0, n * sizeof *x);
            x[c] = 1.0;
            band_solve(p, x);
            double s = 0.0;
            for (size_t i = 0; i < n; i++)
                s += fabs(x[i]);
            inorm = fmax(inorm, s);
        }
        free(x);
        p->cond = norm * inorm;
        if (!(p->cond <= LOFT_COND_LIMIT))
            p->singular = 1;
    }
    return PDE_OK;
}

static void plan_free(loft_plan *p)
{
    free(p->sb);
    free(p->lu);
    free(p->piv);
}

/* A mode of a loft: its factors and data, summed over the terms with these factors. */
typedef struct {
    pde_factor u, v;
    long src;           /* the first term with these factors */
    double *x, *xw;     /* nsections each */
} lmode;

typedef struct {
    pde_factor u, v;
    double sign;
    long term;
} lkey;

static int lkey_cmp(const void *pa, const void *pb)
{
    const lkey *a = pa, *b = pb;
    int c = factor_compare(a->u, b->u);
    if (!c)
        c = factor_compare(a->v, b->v);
    return c ? c : (a->term > b->term) - (a->term < b->term);
}

static void mode_text(pde_factor u, pde_factor v, char *buf, size_t n)
{
    snprintf(buf, n, "%s %.6g (u) times %s %.6g (v)", factor_name(u.kind), u.p, factor_name(v.kind), v.p);
}

static pde_status fail_section(pde_diag *d, pde_status st, int comp, long term, int section,
                               const char *field, const char *msg)
{
    pde_fail(d, st, comp, 0, term, field, "%s", msg);
    if (d)
        d->section = section;
    return st;
}

/* w as given, in the fewest digits that read back as it (0.9999999999999999 is not "1"). */
static void w_text(char *buf, size_t n, double w)
{
    snprintf(buf, n, "%.15g", w);
    if (strtod(buf, NULL) != w)
        snprintf(buf, n, "%.17g", w);
}

/*
 * A singular slab problem that a thin slab explains is the sections' fault, not the PDE's: a slab of width L
 * alone gives the scaled system a condition of about 3/L to 20/L (measured: 2.8/L for e = -390, 18/L for
 * e = 0), past LOFT_COND_LIMIT below L = 2e-11, whatever a, b, c. So when the thinnest slab is below
 * LOFT_THIN_COND / LOFT_COND_LIMIT the refusal names it as too close, pointing at the section beside it
 * that can move (not the last, whose w is 1). The smallest pivot's slab (plan_build) is no guide here:
 * elimination carries the thin slab's loss of rank into a later slab.
 */
static pde_status check_thin_slab(const pde_loft *lf, int comp, long term, const char *mode, double cond,
                                  pde_diag *diag)
{
    const size_t K = lf->nsections;
    size_t s = 0;
    for (size_t i = 1; i + 1 < K; i++)
        if (lf->sections[i + 1].w - lf->sections[i].w < lf->sections[s + 1].w - lf->sections[s].w)
            s = i;
    const double L = lf->sections[s + 1].w - lf->sections[s].w;
    if (!(L * LOFT_COND_LIMIT <= LOFT_THIN_COND))
        return PDE_OK;
    const size_t k = s + 1 < K - 1 ? s + 1 : s, j = k == s ? s + 1 : s;
    char wk[32], wj[32], msg[400];
    w_text(wk, sizeof wk, lf->sections[k].w);
    w_text(wj, sizeof wj, lf->sections[j].w);
    snprintf(msg, sizeof msg,
             "section %zu (w = %s): section %zu (w = %s) is %.3g apart, too close: the slab between them makes the "
             "slab problem of the mode %s singular (condition %.3g, limit %g); move them apart",
             k, wk, j, wj, L, mode, cond, LOFT_COND_LIMIT);
    return fail_section(diag, PDE_ERR_SINGULAR, comp, term, (int)k, "w", msg);
}

static pde_status validate(const pde_loft *lf, pde_diag *diag)
{
    char msg[200];
    if (!lf->sections && lf->nsections)
        return pde_fail(diag, PDE_ERR_INVALID, -1, 0, -1, "", "the loft has no section list");
    if (lf->nsections < 2)
        return pde_fail(diag, PDE_ERR_INVALID, -1, 0, -1, "", "a loft needs at least 2 sections, it has %zu",
                        lf->nsections);
    if (lf->nsections > PDE_MAX_SECTIONS)
        return pde_fail(diag, PDE_ERR_LIMIT, -1, 0, -1, "", "a loft has at most %d sections, this one %zu",
                        PDE_MAX_SECTIONS, lf->nsections);
    const size_t K = lf->nsections;
    int any_tangent = 0;
    for (size_t k = 0; k < K; k++) {
        double w = lf->sections[k].w;
        any_tangent |= lf->sections[k].tangent != 0;
        const char *why = !isfinite(w)                              ? "is not a finite number"
                          : k == 0 && w != 0.0                      ? "of the first section must be 0"
                          : k == K - 1 && w != 1.0                  ? "of the last section must be 1"
                          : k > 0 && !(w > lf->sections[k - 1].w)   ? "must be larger than the previous section's"
                                                                    : NULL;
        if (why) {
            char wt[32];
            w_text(wt, sizeof wt, w);
            snprintf(msg, sizeof msg, "section %zu: w = %s %s", k, wt, why);
            return fail_section(diag, PDE_ERR_INVALID, -1, -1, (int)k, "w", msg);
        }
    }
    for (int ci = 0; ci < 3; ci++) {
        const pde_lcomponent *c = &lf->comp[ci];
        if (c->nterms && !c->terms)
            return pde_fail(diag, PDE_ERR_INVALID, ci, 0, -1, "", "component %s has a NULL term list",
                            pde_comp_name[ci]);
        /* a, b, c and the factors, as for a model. */
        pde_bterm *bt = calloc(c->nterms ? c->nterms : 1, sizeof *bt);
        if (!bt)
            return pde_fail(diag, PDE_ERR_NOMEM, ci, 0, -1, "", "out of memory");
        for (size_t j = 0; j < c->nterms; j++)
            bt[j].u = c->terms[j].u, bt[j].v = c->terms[j].v;
        pde_component mc = { c->a, c->b, c->c, bt, c->nterms, NULL, 0 };
        pde_status st = model_check_component(&mc, ci, diag);
        free(bt);
        if (st != PDE_OK)
            return st;
        for (size_t j = 0; j < c->nterms; j++) {
            const pde_lterm *t = &c->terms[j];
            const pde_factor f[2] = { t->u, t->v };
            for (int k = 0; k < 2; k++)
                if (f[k].kind == PDE_POW && f[k].p >= 4)
                    return pde_fail(diag, PDE_ERR_INVALID, ci, 0, (long)j, k ? "v" : "u",
                                    "the %s factor pow %g: lofts take powers t^0 to t^3 only", k ? "v" : "u",
                                    f[k].p);
            if (!t->x)
                return pde_fail(diag, PDE_ERR_INVALID, ci, 0, (long)j, "x", "term %zu has no section values", j);
            if (any_tangent && !t->xw)
                return pde_fail(diag, PDE_ERR_INVALID, ci, 0, (long)j, "xw",
                                "term %zu has no tangent values, and a section has a tangent", j);
            for (size_t k = 0; k < K; k++) {
                if (!isfinite(t->x[k])) {
                    snprintf(msg, sizeof msg, "component %s, term %zu: x at section %zu is not a finite number",
                             pde_comp_name[ci], j, k);
                    return fail_section(diag, PDE_ERR_INVALID, ci, (long)j, (int)k, "x", msg);
                }
                if (lf->sections[k].tangent && !isfinite(t->xw[k])) {
                    snprintf(msg, sizeof msg, "component %s, term %zu: xw at section %zu is not a finite number",
                             pde_comp_name[ci], j, k);
                    return fail_section(diag, PDE_ERR_INVALID, ci, (long)j, (int)k, "xw", msg);
                }
            }
        }
    }
    return PDE_OK;
}

/* The modes of one component, sorted by their factors, data summed; in scratch memory. */
static pde_status collect(arena *s, const pde_loft *lf, int ci, lmode **out, size_t *nout, pde_diag *diag)
{
    const pde_lcomponent *c = &lf->comp[ci];
    const size_t K = lf->nsections;
    lkey *keys = arena_alloc(s, (c->nterms ? c->nterms : 1) * sizeof *keys);
    lmode *modes = arena_alloc(s, (c->nterms ? c->nterms : 1) * sizeof *modes);
    if (!keys || !modes)
        return PDE_ERR_NOMEM;
    size_t nk = 0;
    for (size_t j = 0; j < c->nterms; j++) {
        pde_factor ku, kv;
        double su, sv;
        if (!factor_normalise(c->terms[j].u, &ku, &su) || !factor_normalise(c->terms[j].v, &kv, &sv))
            continue;
        keys[nk++] = (lkey){ ku, kv, su * sv, (long)j };
    }
    if (nk)
        qsort(keys, nk, sizeof *keys, lkey_cmp);
    size_t n = 0;
    for (size_t i = 0; i < nk; i++) {
        if (n == 0 || factor_compare(modes[n - 1].u, keys[i].u) || factor_compare(modes[n - 1].v, keys[i].v)) {
            lmode *m = &modes[n++];
            m->u = keys[i].u;
            m->v = keys[i].v;
            m->src = keys[i].term;
            m->x = arena_alloc(s, 2 * K * sizeof *m->x);
            if (!m->x)
                return PDE_ERR_NOMEM;
            m->xw = m->x + K;
        }
        lmode *m = &modes[n - 1];
        const pde_lterm *t = &c->terms[keys[i].term];
        for (size_t k = 0; k < K; k++) {
            m->x[k] += keys[i].sign * t->x[k];
            if (lf->sections[k].tangent)
                m->xw[k] += keys[i].sign * t->xw[k];
        }
    }
    if (n > PDE_MAX_MODES)
        return pde_fail(diag, PDE_ERR_LIMIT, ci, 0, -1, "", "component %s needs %zu separated modes, more than %d",
                        pde_comp_name[ci], n, PDE_MAX_MODES);
    *out = modes;
    *nout = n;
    return PDE_OK;
}

/* Appends one real w-term to the mode's list (capacity is 3 per slab). */
static pde_status add_term(arena *mem, pde_wterm *terms, size_t *nt, double alpha, double beta, double shift,
                           int deg, const double *A, const double *B)
{
    int nz = 0;
    for (int j = 0; j <= deg; j++)
        nz |= A[j] != 0.0 || (B && B[j] != 0.0);
    if (!nz)
        return PDE_OK;
    double *a = arena_alloc(mem, 2 * (size_t)(deg + 1) * sizeof *a);
    if (!a)
        return PDE_ERR_NOMEM;
    memcpy(a, A, (size_t)(deg + 1) * sizeof *a);
    if (B)
        memcpy(a + deg + 1, B, (size_t)(deg + 1) * sizeof *a);
    terms[(*nt)++] = (pde_wterm){ alpha, beta, shift, deg, a, a + deg + 1 };
    return PDE_OK;
}

/* The closed form of one slab from its basis coefficients c[0..3]. */
static pde_status slab_terms(arena *mem, const slab_basis *b, double w0, double w1, const double c[4],
                             pde_wterm *terms, size_t *nt)
{
    const double t = b->t;
    pde_status st;
    if (b->kind == 0) {
        /* sum_j c_j sum_n q_jn ((w - w0) / L)^n, expanded in powers of w. */
        const double L = w1 - w0;
        double loc[SERIES_MAX + 1], A[SERIES_MAX + 1];
        int deg = b->deg;
        double Ln = 1.0;
        for (int n = 0; n <= deg; n++, Ln /= L) {
            loc[n] = 0.0;
            for (int j = 0; j < 4; j++)
                loc[n] += c[j] * b->q[j][n];
            loc[n] *= Ln;
        }
        /* Taylor shift: P(w) = sum loc_n (w - w0)^n. Horner with (w - w0) synthetic division. */
        for (int n = 0; n <= deg; n++)
            A[n] = 0.0;
        for (int n = deg; n >= 0; n--) {
            /* A := A * (w - w0) + loc_n */
            for (int i = deg; i >= 1; i--)
                A[i] = A[i - 1] - w0 * A[i];
            A[0] = -w0 * A[0] + loc[n];
        }
        while (deg > 0 && A[deg] == 0.0)
            deg--;
        static const double zero[SERIES_MAX + 1];
        return add_term(mem, terms, nt, 0.0, 0.0, 0.0, deg, A, zero);
    }
    if (b->kind == 1) {
        double A, B;
        if ((st = add_term(mem, terms, nt, t, 0.0, w1, 0, &c[0], &(double){ 0.0 })) != PDE_OK ||
            (st = add_term(mem, terms, nt, -t, 0.0, w0, 0, &c[1], &(double){ 0.0 })) != PDE_OK)
            return st;
        /* c2 cos t(w - w0) + c3 sin t(w - w0) = A cos tw + B sin tw. */
        double cs = cos(t * w0), sn = sin(t * w0);
        A = c[2] * cs - c[3] * sn;
        B = c[2] * sn + c[3] * cs;
        return add_term(mem, terms, nt, 0.0, t, 0.0, 0, &A, &B);
    }
    /* e < 0: beta = t / sqrt 2; exp(beta (w - a)) (c cos beta (w - a) + d sin beta (w - a)). */
    const double be = t * M_SQRT1_2;
    const double anchor[2] = { w1, w0 }, alpha[2] = { be, -be };
    for (int g = 0; g < 2; g++) {
        double cs = cos(be * anchor[g]), sn = sin(be * anchor[g]);
        double A = c[2 * g] * cs - c[2 * g + 1] * sn, B = c[2 * g] * sn + c[2 * g + 1] * cs;
        if ((st = add_term(mem, terms, nt, alpha[g], be, anchor[g], 0, &A, &B)) != PDE_OK)
            return st;
    }
    return PDE_OK;
}

typedef struct {
    loft_plan *p;
    size_t n, cap;
} plan_list;

static pde_status plan_get(plan_list *pl, const pde_loft *lf, double e, loft_plan **out)
{
    for (size_t i = 0; i < pl->n; i++)
        if (pl->p[i].e == e) {
            *out = &pl->p[i];
            return PDE_OK;
        }
    if (pl->n == pl->cap) {
        size_t cap = pl->cap ? 2 * pl->cap : 16;
        loft_plan *np = realloc(pl->p, cap * sizeof *np);
        if (!np)
            return PDE_ERR_NOMEM;
        pl->p = np;
        pl->cap = cap;
    }
    loft_plan *p = &pl->p[pl->n++];
    memset(p, 0, sizeof *p);
    /* Only e > 0 can be singular (for e <= 0 the problem minimises a positive energy); others are
     * estimated when small. */
    pde_status st = plan_build(lf, e, e > 0.0 || lf->nsections <= 17, p);
    *out = p;
    return st;
}

static pde_status solve_component(arena *mem, arena *scratch, plan_list *plans, const pde_loft *lf, int ci,
                                  const double *breaks, const pde_cancel *cancel, pde_solution *sol,
                                  pde_diag *diag)
{
    const pde_lcomponent *c = &lf->comp[ci];
    comp_solution *out = &sol->comp[ci];
    const size_t K = lf->nsections, S = K - 1, nu = 4 * S;
    lmode *modes = NULL;
    size_t n = 0;
    pde_status st = collect(scratch, lf, ci, &modes, &n, diag);
    if (st != PDE_OK)
        return st;
    out->a = c->a, out->b = c->b, out->c = c->c;
    out->modes = arena_alloc(mem, (n ? n : 1) * sizeof *out->modes);
    out->lx = arena_alloc(mem, (n ? n : 1) * K * sizeof *out->lx);
    int tangents = 0;
    for (size_t k = 0; k < K; k++)
        tangents |= lf->sections[k].tangent != 0;
    out->lxw = tangents ? arena_alloc(mem, (n ? n : 1) * K * sizeof *out->lxw) : NULL;
    double *rhs = arena_alloc(scratch, nu * sizeof *rhs);
    if (!out->modes || !out->lx || (tangents && !out->lxw) || !rhs)
        return PDE_ERR_NOMEM;
    size_t kept = 0;
    for (size_t i = 0; i < n; i++) {
        if (pde_stopped(cancel))
            return PDE_ERR_CANCELLED;
        lmode *m = &modes[i];
        int nz = 0;
        for (size_t k = 0; k < K; k++)
            nz |= m->x[k] != 0.0 || (lf->sections[k].tangent && m->xw[k] != 0.0);
        if (!nz)
            continue;
        double e = -(c->a * factor_lambda(m->u) + c->b * factor_lambda(m->v)) / c->c;
        char mt[120];
        if (!isfinite(e)) {
            mode_text(m->u, m->v, mt, sizeof mt);
            return pde_fail(diag, PDE_ERR_RANGE, ci, 0, m->src, "", "component %s, mode %s: e overflows a double",
                            pde_comp_name[ci], mt);
        }
        loft_plan *p;
        if ((st = plan_get(plans, lf, e, &p)) != PDE_OK)
            return st;
        if (p->singular) {
            mode_text(m->u, m->v, mt, sizeof mt);
            if ((st = check_thin_slab(lf, ci, m->src, mt, p->cond, diag)) != PDE_OK)
                return st;
            size_t s = p->worst_slab;
            return pde_fail(diag, PDE_ERR_SINGULAR, ci, 0, m->src, "",
                            "component %s: the slab problem of the mode %s (e = %.6g) is singular near slab %zu "
                            "(w from %g to %g): condition %.3g",
                            pde_comp_name[ci], mt, e, s, lf->sections[s].w, lf->sections[s + 1].w, p->cond);
        }
        /* The right-hand side, row by row as in plan_build. */
        size_t row = 0;
        for (size_t k = 0; k < K; k++) {
            cond_row r[4];
            int nr = section_rows(lf->sections, k, K, r);
            for (int j = 0; j < nr; j++, row++) {
                if (r[j].kind == 2 || r[j].d == 2)
                    rhs[row] = 0.0;
                else if (r[j].d == 0)
                    rhs[row] = m->x[k];
                else
                    rhs[row] = m->xw[k] / p->sb[r[j].kind ? k : k - 1].rho;
            }
        }
        band_solve(p, rhs);
        pde_mode *pm = &out->modes[kept];
        pde_wterm *terms = arena_alloc(mem, 3 * S * sizeof *terms);
        size_t *first = arena_alloc(mem, K * sizeof *first);
        if (!terms || !first)
            return PDE_ERR_NOMEM;
        size_t nt = 0;
        for (size_t s = 0; s < S; s++) {
            first[s] = nt;
            if ((st = slab_terms(mem, &p->sb[s], lf->sections[s].w, lf->sections[s + 1].w, rhs + 4 * s, terms,
                                 &nt)) != PDE_OK)
                return st;
        }
        first[S] = nt;
        for (size_t k = 0; k < nt; k++)
            for (int j = 0; j <= terms[k].deg; j++)
                if (!isfinite(terms[k].A[j]) || !isfinite(terms[k].B[j])) {
                    mode_text(m->u, m->v, mt, sizeof mt);
                    return pde_fail(diag, PDE_ERR_RANGE, ci, 0, m->src, "",
                                    "component %s, mode %s: the solution's coefficients overflow a double",
                                    pde_comp_name[ci], mt);
                }
        *pm = (pde_mode){ .u = m->u, .v = m->v, .e = e, .nterms = nt, .terms = terms, .nslabs = S,
                          .breaks = breaks, .first = first };
        memcpy(out->lx + kept * K, m->x, K * sizeof *out->lx);
        if (tangents)
            memcpy(out->lxw + kept * K, m->xw, K * sizeof *out->lxw);
        if (p->cond > sol->cond) {
            sol->cond = p->cond;
            sol->cond_comp = ci;
            sol->cond_mode = kept;
        }
        kept++;
    }
    out->nmodes = kept;
    return PDE_OK;
}

static pde_status check_sections_met(const pde_solution *sol, const pde_loft *lf, pde_diag *diag);

pde_status pde_solve_loft(const pde_loft *loft, const pde_solve_opts *opts, pde_solution **out,
                          pde_diag *diag)
{
    const pde_cancel *cancel = opts ? opts->cancel : NULL;
    pde_diag_clear(diag);
    if (!loft || !out)
        return pde_fail(diag, PDE_ERR_INVALID, -1, 0, -1, "", "no loft given");
    pde_status st = validate(loft, diag);
    if (st != PDE_OK)
        return st;
    arena mem = { 0 }, scratch = { 0 };
    plan_list plans = { 0 };
    pde_solution *sol = arena_alloc(&mem, sizeof *sol);
    st = sol ? PDE_OK : PDE_ERR_NOMEM;
    if (sol) {
        sol->nsections = loft->nsections;
        sol->fit_error = isfinite(loft->fit_error) ? fabs(loft->fit_error) : 0.0;
        sol->sections = arena_alloc(&mem, loft->nsections * sizeof *sol->sections);
        if (!sol->sections)
            st = PDE_ERR_NOMEM;
        else
            memcpy(sol->sections, loft->sections, loft->nsections * sizeof *sol->sections);
        sol->cond_comp = -1;
    }
    double *breaks = st == PDE_OK ? arena_alloc(&mem, loft->nsections * sizeof *breaks) : NULL;
    if (st == PDE_OK && !breaks)
        st = PDE_ERR_NOMEM;
    for (size_t k = 0; st == PDE_OK && k < loft->nsections; k++)
        breaks[k] = loft->sections[k].w;
    for (int ci = 0; ci < 3 && st == PDE_OK; ci++)
        st = solve_component(&mem, &scratch, &plans, loft, ci, breaks, cancel, sol, diag);
    for (size_t i = 0; i < plans.n; i++)
        plan_free(&plans.p[i]);
    free(plans.p);
    arena_free(&scratch);
    if (st == PDE_OK)
        st = check_sections_met(sol, loft, diag);
    if (st != PDE_OK)
        return pde_solve_abandon(&mem, st, diag);
    if (sol->cond_comp < 0)
        sol->cond = 1.0;
    sol->mem = mem;
    *out = sol;
    return PDE_OK;
}

double pde_solution_condition(const pde_solution *sol, int *comp, size_t *mode)
{
    int c = -1;
    size_t m = 0;
    double cond = 1.0;
    if (sol && sol->nsections) {
        c = sol->cond_comp;
        m = sol->cond_mode;
        cond = sol->cond;
    }
    if (comp)
        *comp = c;
    if (mode)
        *mode = m;
    return cond;
}

/*
 * The largest error of the section conditions. Per section and condition, the errors of the modes
 * add up (each times the largest |f_u f_v| on the unit square), relative to the larger of the data's
 * scale (the same sum over the data) and the size of the derivative being matched.
 */
static int is_constant(pde_factor f)
{
    return f.kind == PDE_POW && f.p == 0.0;
}

static double bc_worst(const pde_solution *sol, int *worst_comp, size_t *worst_section)
{
    const size_t K = sol->nsections;
    double worst = 0.0;
    *worst_comp = -1, *worst_section = 0;
    for (int ci = 0; ci < 3; ci++) {
        const comp_solution *cs = &sol->comp[ci];
        /* The scale: each mode's largest data, but the constant mode's (the sections' centres) only as far as
         * it varies, so that a part far from the origin is measured against its own size (review: at 1e7, a
         * miss of 4.6 counted as 4.6e-7). */
        double scale = 0.0;
        for (size_t m = 0; m < cs->nmodes; m++) {
            double bu, bv, dmax = 0.0, lo = INFINITY, hi = -INFINITY;
            factor_bounds(cs->modes[m].u, 0.0, 1.0, 0, &bu);
            factor_bounds(cs->modes[m].v, 0.0, 1.0, 0, &bv);
            const int centre = is_constant(cs->modes[m].u) && is_constant(cs->modes[m].v);
            for (size_t k = 0; k < K; k++) {
                dmax = fmax(dmax, fabs(cs->lx[m * K + k]));
                lo = fmin(lo, cs->lx[m * K + k]), hi = fmax(hi, cs->lx[m * K + k]);
                if (cs->lxw && sol->sections[k].tangent)
                    dmax = fmax(dmax, fabs(cs->lxw[m * K + k]));
            }
            if (centre) {
                dmax = hi - lo;
                for (size_t k = 0; cs->lxw && k < K; k++)
                    if (sol->sections[k].tangent)
                        dmax = fmax(dmax, fabs(cs->lxw[m * K + k]));
            }
            scale += bu * bv * dmax;
        }
        for (size_t k = 0; k < K; k++) {
            const double w = sol->sections[k].w;
            const int end = k == 0 || k == K - 1, tan = sol->sections[k].tangent;
            /* err[d], size[d]: d = 0 x, 1 x_w, 2 x_ww (natural end), 3 jump of x_w, 4 of x_ww. */
            double err[5] = { 0 }, size[5] = { 0 };
            for (size_t m = 0; m < cs->nmodes; m++) {
                const pde_mode *md = &cs->modes[m];
                double bu, bv;
                factor_bounds(md->u, 0.0, 1.0, 0, &bu);
                factor_bounds(md->v, 0.0, 1.0, 0, &bv);
                const double f = bu * bv;
                const int centre = is_constant(md->u) && is_constant(md->v);
                double dd[2][3] = { { 0 } };   /* h, h', h'' on the left and on the right */
                for (int side = 0; side < 2; side++) {
                    if ((side == 0 && k == 0) || (side == 1 && k == K - 1))
                        continue;
                    size_t s = side ? k : k - 1;
                    for (size_t i = md->first[s]; i < md->first[s + 1]; i++)
                        for (int o = 0; o < 3; o++)
                            dd[side][o] += wterm_deriv(&md->terms[i], w, o);
                    err[0] += fabs(dd[side][0] - cs->lx[m * K + k]) * f;
                    size[0] += centre ? 0.0 : fabs(cs->lx[m * K + k]) * f;
                    if (tan) {
                        err[1] += fabs(dd[side][1] - cs->lxw[m * K + k]) * f;
                        size[1] += fabs(dd[side][1]) * f;
                    } else if (end) {
                        err[2] += fabs(dd[side][2]) * f;
                        size[2] += fabs(dd[side][1]) * f;   /* x_ww against the slope's size */
                    }
                }
                if (!end && !tan) {
                    err[3] += fabs(dd[0][1] - dd[1][1]) * f;
                    err[4] += fabs(dd[0][2] - dd[1][2]) * f;
                    size[3] += (fabs(dd[0][1]) + fabs(dd[1][1])) * f;
                    size[4] += (fabs(dd[0][2]) + fabs(dd[1][2])) * f;
                }
            }
            for (int o = 0; o < 5; o++) {
                double ref = fmax(scale, size[o]);
                if (ref > 0.0 && !(err[o] / ref <= worst))   /* NaN counts as the worst */
                    worst = err[o] / ref, *worst_comp = ci, *worst_section = k;
            }
        }
    }
    return worst;
}

double loft_bc_residual(const pde_solution *sol)
{
    if (!sol || !sol->nsections)
        return 0.0;
    int c;
    size_t k;
    return bc_worst(sol, &c, &k);
}

/*
 * A solution that misses its own sections (loft_bc_residual) beyond LOFT_RESIDUAL_LIMIT: refused, naming
 * the worst section and its nearer neighbour. A slab thin for the difference of its sections swells as
 * (difference) / width^2 or more, and its closed form then cancels that many digits: sections 1e-9 apart
 * that differ by 0.2 have a condition of 1.8e10, under LOFT_COND_LIMIT, but missed their data by 450% of
 * the solid's size.
 */
static pde_status check_sections_met(const pde_solution *sol, const pde_loft *lf, pde_diag *diag)
{
    int c;
    size_t k;
    const double r = bc_worst(sol, &c, &k);
    if (r <= LOFT_RESIDUAL_LIMIT)
        return PDE_OK;
    const size_t K = lf->nsections;
    size_t j = k == 0 ? 1 : k == K - 1 ? K - 2 : lf->sections[k + 1].w - lf->sections[k].w < lf->sections[k].w - lf->sections[k - 1].w ? k + 1 : k - 1;
    char wk[32], wj[32], msg[400];
    w_text(wk, sizeof wk, lf->sections[k].w);
    w_text(wj, sizeof wj, lf->sections[j].w);
    snprintf(msg, sizeof msg,
             "section %zu (w = %s): the solution misses it by %.2g of the solid's size (%s; limit %g): section "
             "%zu (w = %s) is %.3g apart, too close for their difference; move them apart or make them alike",
             k, wk, r, pde_comp_name[c < 0 ? 0 : c], LOFT_RESIDUAL_LIMIT, j, wj, fabs(lf->sections[j].w - lf->sections[k].w));
    return fail_section(diag, PDE_ERR_SINGULAR, c, -1, (int)k, "w", msg);
}
