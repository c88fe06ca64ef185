/*
 * solve.c: pde_solve(), the plan. Separates variables (eq. 4), solves each
 * mode's boundary value problem exactly, and stores the closed form.
 *
 * DESIGN
 * A mode is a pair of basis functions (f_u, f_v). Sines, cosines and
 * exponentials are eigenfunctions of d4 (eq. 6), so their mode obeys
 * c h'''' + (a lu + b lv) h = force (eq. 7). A power t^m is not: d4 t^m =
 * m(m-1)(m-2)(m-3) t^(m-4), so the modes t^m, t^(m-4), ... form a chain, each
 * forced by the one above it. Modes are sorted by their total polynomial
 * degree, highest first, so each mode's parents are solved before it.
 *
 * The force's own boundary values are taken off the boundary data of every
 * mode it touches before the homogeneous part is fitted; the paper's eq. (30)
 * skips this step, so its tangents at w = 0, 1 are not met.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ep.h"

#define COND_LIMIT 1e12   /* boundary systems worse than this are singular */
/* |e| beyond this (t = |e|^(1/4) > 1e8): h(w)'s layers at w = 0, 1 are 1/t wide, and x_w there is t times
 * sums that cancel, so t eps of it is rounding (1e-8 at the limit, which the certificate shows). */
#define E_LIMIT 1e32
/* h'''' = e h with clamped ends is singular only at e = t^4 with cos t cosh t = 1; the
 * first such t is 4.7300407, e = 500.5639. Below it no condition estimate is needed. */
#define FIRST_EIGENVALUE 500.0

const char *pde_strerror(pde_status status)
{
    switch (status) {
    case PDE_OK: return "success";
    case PDE_ERR_NOMEM: return "out of memory";
    case PDE_ERR_INVALID: return "invalid model";
    case PDE_ERR_ILLPOSED: return "ill-posed equation";
    case PDE_ERR_SINGULAR: return "singular boundary problem";
    case PDE_ERR_RANGE: return "value out of range";
    case PDE_ERR_LIMIT: return "model too large";
    case PDE_ERR_CANCELLED: return "cancelled";
    }
    return "unknown status";
}

typedef struct {
    pde_factor u, v;
    int level;            /* total degree of the power factors */
    int src_force;        /* the term that first asked for this mode */
    long src_term;
    double bc[4];         /* w0, dw0, w1, dw1 */
    double drive[4];      /* the particular solution's boundary values (comp_solution) */
    long first_force;     /* head of this mode's list of force terms, -1 if none */
    ep h;                 /* the solved h(w), complex */
} mode;

static int level_of(pde_factor u, pde_factor v)
{
    return (u.kind == PDE_POW ? (int)u.p : 0) + (v.kind == PDE_POW ? (int)v.p : 0);
}

/* Order: level descending, then the factors. Equal keys: the earliest source first. */
static int mode_cmp_key(const void *pa, const void *pb)
{
    const mode *a = pa, *b = pb;
    if (a->level != b->level)
        return a->level > b->level ? -1 : 1;
    int c = factor_compare(a->u, b->u);
    return c ? c : factor_compare(a->v, b->v);
}

static int mode_cmp(const void *pa, const void *pb)
{
    int c = mode_cmp_key(pa, pb);
    if (c)
        return c;
    const mode *a = pa, *b = pb;
    if (a->src_force != b->src_force)
        return a->src_force - b->src_force;
    return (a->src_term > b->src_term) - (a->src_term < b->src_term);
}

static mode *find_mode(mode *modes, size_t n, pde_factor u, pde_factor v)
{
    mode key = { .u = u, .v = v, .level = level_of(u, v) };
    return bsearch(&key, modes, n, sizeof *modes, mode_cmp_key);
}

typedef struct {
    mode *m;
    size_t n, cap;
} mode_list;

/* Adds the mode (u, v) and the chain below it: t^m -> t^(m-4) -> ... */
static pde_status push_chain(arena *s, mode_list *l, pde_factor u, pde_factor v,
                             int in_force, long term)
{
    int iu = u.kind == PDE_POW ? (int)u.p / 4 : 0;
    int iv = v.kind == PDE_POW ? (int)v.p / 4 : 0;
    size_t need = l->n + (size_t)(iu + 1) * (size_t)(iv + 1);
    if (need > (size_t)PDE_MAX_MODES * 4)
        return PDE_ERR_LIMIT;
    if (need > l->cap) {
        size_t cap = l->cap ? l->cap : 16;
        while (cap < need)
            cap *= 2;
        mode *nm = arena_alloc(s, cap * sizeof *nm);
        if (!nm)
            return PDE_ERR_NOMEM;
        if (l->n)
            memcpy(nm, l->m, l->n * sizeof *nm);
        l->m = nm;
        l->cap = cap;
    }
    for (int i = 0; i <= iu; i++)
        for (int j = 0; j <= iv; j++) {
            mode *m = &l->m[l->n++];
            memset(m, 0, sizeof *m);
            m->u = u;
            m->v = v;
            m->u.p -= 4 * i;
            m->v.p -= 4 * j;
            m->level = level_of(m->u, m->v);
            m->src_force = in_force;
            m->src_term = term;
            m->first_force = -1;
        }
    return PDE_OK;
}

/* f(w) as an ep, times scale: sines and cosines as exp(i k pi w), of which h is the real part. */
static pde_status force_w(arena *s, ep *q, pde_factor f, double scale)
{
    cplx one = 1.0;
    switch (f.kind) {
    case PDE_POW: {
        int n = (int)f.p;
        cplx *p = arena_alloc(s, (size_t)(n + 1) * sizeof *p);
        if (!p)
            return PDE_ERR_NOMEM;
        p[n] = 1.0;
        return ep_add(s, q, 0.0, 0, p, n, scale);
    }
    case PDE_SIN:
    case PDE_COS: {
        if (f.p == 0.0)
            return f.kind == PDE_COS ? ep_add(s, q, 0.0, 0, &one, 0, scale) : PDE_OK;
        cplx z = I * f.p * M_PI;     /* Re(-i e^{i th}) = sin th, Re(e^{i th}) = cos th */
        return ep_add(s, q, z, 0, &one, 0, f.kind == PDE_SIN ? -I * scale : scale);
    }
    case PDE_EXP:
    case PDE_SINH:
    case PDE_COSH: {
        double a = f.p;
        if (a == 0.0)
            return f.kind == PDE_SINH ? PDE_OK : ep_add(s, q, 0.0, 0, &one, 0, scale);
        /* e^{a w} = e^{a shift} e^{a (w - shift)}: the stored exponent stays <= 0. */
        double sp = a > 0 ? exp(a) : 1.0, sm = a < 0 ? exp(-a) : 1.0;
        if (f.kind == PDE_EXP)
            return ep_add(s, q, a, a > 0, &one, 0, scale * sp);
        pde_status st = ep_add(s, q, a, a > 0, &one, 0, 0.5 * scale * sp);
        if (st != PDE_OK)
            return st;
        double sg = f.kind == PDE_SINH ? -0.5 : 0.5;
        return ep_add(s, q, -a, -a > 0, &one, 0, sg * scale * sm);
    }
    }
    return PDE_OK;
}

/*
 * The boundary problem of one e: its homogeneous basis and the LU factors of
 * the 4x4 system that fits it, with the derivative rows scaled by 1/|r| so
 * that the entries are O(1). Modes of a chain, and sin/cos pairs, share e,
 * and so do x and y of most models, so plans are kept in a small cache while
 * a model is solved.
 */
typedef struct {
    double e;
    ep basis[4];
    double dscale;
    cplx LU[4][4];    /* L below the diagonal, U on and above it */
    cplx inv_diag[4]; /* 1 / U[i][i] */
    int piv[4];
    double cond;      /* 1-norm condition number (|re| + |im| for the modulus); 0 when e < 500 */
} bvp_plan;

static double cabs1(cplx z)
{
    return fabs(creal(z)) + fabs(cimag(z));
}

static void lu_solve(const bvp_plan *p, const cplx b[4], cplx y[4])
{
    for (int i = 0; i < 4; i++) {
        cplx rhs = b[p->piv[i]];
        for (int j = 0; j < i; j++)
            rhs -= p->LU[i][j] * y[j];
        y[i] = rhs;
    }
    for (int i = 3; i >= 0; i--) {
        for (int j = i + 1; j < 4; j++)
            y[i] -= p->LU[i][j] * y[j];
        y[i] *= p->inv_diag[i];
    }
}

/* Factors M with partial pivoting and, if asked, estimates its condition from the explicit inverse. */
static void lu_factor(bvp_plan *p, cplx M[4][4], int estimate)
{
    double norm = 0.0;
    for (int j = 0; j < 4; j++) {
        double col = 0.0;
        for (int i = 0; i < 4; i++)
            col += cabs1(M[i][j]);
        norm = fmax(norm, col);
    }
    memcpy(p->LU, M, sizeof p->LU);
    for (int i = 0; i < 4; i++)
        p->piv[i] = i;
    for (int k = 0; k < 4; k++) {
        int q = k;
        for (int i = k + 1; i < 4; i++)
            if (cabs1(p->LU[i][k]) > cabs1(p->LU[q][k]))
                q = i;
        if (p->LU[q][k] == 0.0) {
            p->cond = INFINITY;
            return;
        }
        if (q != k) {
            for (int j = 0; j < 4; j++) {
                cplx t = p->LU[k][j];
                p->LU[k][j] = p->LU[q][j];
                p->LU[q][j] = t;
            }
            int t = p->piv[k];
            p->piv[k] = p->piv[q];
            p->piv[q] = t;
        }
        p->inv_diag[k] = 1.0 / p->LU[k][k];
        for (int i = k + 1; i < 4; i++) {
            p->LU[i][k] *= p->inv_diag[k];
            for (int j = k + 1; j < 4; j++)
                p->LU[i][j] -= p->LU[i][k] * p->LU[k][j];
        }
    }
    p->cond = 0.0;
    if (!estimate)
        return;
    double inorm = 0.0;
    for (int col = 0; col < 4; col++) {
        cplx unit[4] = { 0 }, y[4];
        unit[col] = 1.0;
        lu_solve(p, unit, y);
        double s = 0.0;
        for (int i = 0; i < 4; i++)
            s += cabs1(y[i]);
        inorm = fmax(inorm, s);
    }
    p->cond = norm * inorm;
}

#define PLAN_CACHE 4

typedef struct {
    bvp_plan plan[PLAN_CACHE];
    int n, next;
} plan_cache;

static pde_status plan_for(arena *s, plan_cache *cache, double e, const bvp_plan **out)
{
    for (int i = 0; i < cache->n; i++)
        if (cache->plan[i].e == e) {
            *out = &cache->plan[i];
            return PDE_OK;
        }
    bvp_plan *p = &cache->plan[cache->next];
    cache->next = (cache->next + 1) % PLAN_CACHE;
    if (cache->n < PLAN_CACHE)
        cache->n++;
    p->e = NAN;    /* invalid until complete */
    pde_status st = ep_homogeneous(s, e, p->basis, &p->dscale);
    if (st != PDE_OK)
        return st;
    cplx M[4][4];
    for (int j = 0; j < 4; j++) {
        cplx col[4];
        ep_boundary(&p->basis[j], col);
        for (int i = 0; i < 4; i++)
            M[i][j] = col[i] * (i & 1 ? p->dscale : 1.0);
    }
    lu_factor(p, M, e >= FIRST_EIGENVALUE);
    p->e = e;
    *out = p;
    return PDE_OK;
}

/* The real closed form of a complex ep: Re sum P e^{z(w-s)}, terms with equal (alpha, |beta|, s) merged. */
static pde_status to_real(arena *mem, const ep *h, pde_mode *out)
{
    pde_wterm *terms = arena_alloc(mem, (h->n ? h->n : 1) * sizeof *terms);
    if (!terms)
        return PDE_ERR_NOMEM;
    size_t n = 0;
    for (size_t i = 0; i < h->n; i++) {
        const ep_term *t = &h->t[i];
        double alpha = creal(t->z), beta = cimag(t->z);
        double sgn = beta > 0 ? -1.0 : 1.0;
        cplx rot = t->shift && beta != 0.0 ? cexp(-I * beta) : 1.0;   /* e^{-i beta shift} */
        size_t k = 0;
        while (k < n && !(terms[k].alpha == alpha && terms[k].beta == fabs(beta) &&
                          terms[k].shift == t->shift))
            k++;
        pde_wterm *w = &terms[k];
        int deg = t->deg;
        if (k == n) {
            n++;
            w->alpha = alpha;
            w->beta = fabs(beta);
            w->shift = t->shift;
            w->deg = -1;
        }
        if (deg > w->deg) {
            double *A = arena_alloc(mem, (size_t)(deg + 1) * sizeof *A);
            double *B = arena_alloc(mem, (size_t)(deg + 1) * sizeof *B);
            if (!A || !B)
                return PDE_ERR_NOMEM;
            for (int j = 0; j <= w->deg; j++) {
                A[j] = w->A[j];
                B[j] = w->B[j];
            }
            w->A = A;
            w->B = B;
            w->deg = deg;
        }
        double *A = (double *)w->A, *B = (double *)w->B;
        for (int j = 0; j <= deg; j++) {
            cplx p = t->p[j] * rot;
            A[j] += creal(p);
            if (beta != 0.0)
                B[j] += sgn * cimag(p);
        }
    }
    static const double unit[2] = { 0.0, 1.0 };
    size_t *first = arena_alloc(mem, 2 * sizeof *first);
    if (!first)
        return PDE_ERR_NOMEM;
    first[1] = n;
    out->terms = terms;
    out->nterms = n;
    out->nslabs = 1;
    out->breaks = unit;
    out->first = first;
    return PDE_OK;
}

static int wterms_finite(const pde_mode *m)
{
    for (size_t k = 0; k < m->nterms; k++)
        for (int j = 0; j <= m->terms[k].deg; j++)
            if (!isfinite(m->terms[k].A[j]) || !isfinite(m->terms[k].B[j]))
                return 0;
    return 1;
}

/* Collects the modes of one component, sorted, with their data attached. */
static pde_status collect(arena *s, const pde_component *c, int ci, mode **out, size_t *nout,
                          long **next_force, pde_diag *diag)
{
    mode_list l = { 0 };
    pde_factor ku, kv;
    double su, sv;
    for (int in_force = 0; in_force < 2; in_force++) {
        size_t nt = in_force ? c->nfterms : c->nbterms;
        for (size_t j = 0; j < nt; j++) {
            pde_factor fu = in_force ? c->fterms[j].u : c->bterms[j].u;
            pde_factor fv = in_force ? c->fterms[j].v : c->bterms[j].v;
            if (!factor_normalise(fu, &ku, &su) || !factor_normalise(fv, &kv, &sv))
                continue;
            pde_status st = push_chain(s, &l, ku, kv, in_force, (long)j);
            if (st == PDE_ERR_LIMIT)
                return pde_fail(diag, st, ci, in_force, (long)j, "",
                            "component %s needs more than %d separated modes", pde_comp_name[ci],
                            PDE_MAX_MODES);
            if (st != PDE_OK)
                return st;
        }
    }
    if (l.n)
        qsort(l.m, l.n, sizeof *l.m, mode_cmp);
    size_t n = 0;
    for (size_t i = 0; i < l.n; i++)
        if (n == 0 || mode_cmp_key(&l.m[n - 1], &l.m[i]) != 0)
            l.m[n++] = l.m[i];
    if (n > PDE_MAX_MODES)
        return pde_fail(diag, PDE_ERR_LIMIT, ci, -1, -1, "", "component %s needs %zu separated modes, more than %d",
                    pde_comp_name[ci], n, PDE_MAX_MODES);
    long *next = arena_alloc(s, (c->nfterms ? c->nfterms : 1) * sizeof *next);
    if (!next)
        return PDE_ERR_NOMEM;
    for (size_t j = 0; j < c->nbterms; j++) {
        const pde_bterm *t = &c->bterms[j];
        if (!factor_normalise(t->u, &ku, &su) || !factor_normalise(t->v, &kv, &sv))
            continue;
        mode *m = find_mode(l.m, n, ku, kv);
        double sg = su * sv;
        m->bc[0] += sg * t->w0;
        m->bc[1] += sg * t->dw0;
        m->bc[2] += sg * t->w1;
        m->bc[3] += sg * t->dw1;
    }
    /* Force lists, kept in term order. */
    for (size_t j = c->nfterms; j-- > 0;) {
        const pde_fterm *t = &c->fterms[j];
        next[j] = -1;
        if (!factor_normalise(t->u, &ku, &su) || !factor_normalise(t->v, &kv, &sv))
            continue;
        mode *m = find_mode(l.m, n, ku, kv);
        next[j] = m->first_force;
        m->first_force = (long)j;
    }
    *out = l.m;
    *nout = n;
    *next_force = next;
    return PDE_OK;
}

/* Solves one mode: forcing from its force terms and its chain parents, then the boundary fit. */
static pde_status solve_mode(arena *s, plan_cache *plans, const pde_component *c, int ci, mode *modes,
                             size_t nmodes, mode *m, const long *next_force, const pde_cancel *cancel,
                             pde_diag *diag)
{
    double mu = c->a * factor_lambda(m->u) + c->b * factor_lambda(m->v);
    double e = -mu / c->c;                                   /* eq. (8) */
    if (!isfinite(e))
        return pde_fail(diag, PDE_ERR_RANGE, ci, m->src_force, m->src_term, "",
                    "component %s: the separation constant e = -(a lu + b lv)/c overflows",
                    pde_comp_name[ci]);
    if (fabs(e) > E_LIMIT)
        return pde_fail(diag, PDE_ERR_RANGE, ci, 0, -1, "c",
                    "component %s: e = -(a lu + b lv)/c = %.3g for the mode %s(%g)*%s(%g) is beyond %g: h(w) "
                    "would have boundary layers of width |e|^(-1/4) = %.2g, thinner than a double resolves, "
                    "and x_w at w = 0 and 1 would lose every digit; make |c| larger against a and b",
                    pde_comp_name[ci], e, factor_name(m->u.kind), m->u.p, factor_name(m->v.kind), m->v.p,
                    E_LIMIT, pow(fabs(e), -0.25));
    ep q = { 0 };
    pde_status st;
    unsigned polls = 0;
    for (long j = m->first_force; j >= 0; j = next_force[j]) {
        /* ep_add merges by a linear search: many terms on one mode cost their square. */
        if (++polls % 64 == 0 && pde_stopped(cancel))
            return PDE_ERR_CANCELLED;
        const pde_fterm *t = &c->fterms[j];
        pde_factor ku, kv;
        double su, sv;
        factor_normalise(t->u, &ku, &su);
        factor_normalise(t->v, &kv, &sv);
        if ((st = force_w(s, &q, t->w, t->coef * su * sv / c->c)) != PDE_OK)
            return st;
    }
    /* Chain: a (m+4)(m+3)(m+2)(m+1) h_{u^(m+4)} appears on the left of this mode's equation. */
    for (int axis = 0; axis < 2; axis++) {
        pde_factor pu = m->u, pv = m->v;
        pde_factor *f = axis == 0 ? &pu : &pv;
        if (f->kind != PDE_POW)
            continue;
        double k = (f->p + 4) * (f->p + 3) * (f->p + 2) * (f->p + 1);
        f->p += 4;
        mode *parent = f->p <= PDE_MAX_POW ? find_mode(modes, nmodes, pu, pv) : NULL;
        double coef = axis == 0 ? c->a : c->b;
        if (parent && coef != 0.0 && (st = ep_add_ep(s, &q, &parent->h, -coef * k / c->c)) != PDE_OK)
            return st;
    }
    if (q.n == 0 && m->bc[0] == 0.0 && m->bc[1] == 0.0 && m->bc[2] == 0.0 && m->bc[3] == 0.0)
        return PDE_OK;    /* h = 0 */

    ep hp = { 0 };
    const bvp_plan *plan;
    if ((st = ep_particular(s, e, &q, &hp)) != PDE_OK || (st = plan_for(s, plans, e, &plan)) != PDE_OK)
        return st;
    cplx bp[4], rhs[4], coef[4];
    ep_boundary(&hp, bp);
    for (int i = 0; i < 4; i++) {
        rhs[i] = (m->bc[i] - bp[i]) * (i & 1 ? plan->dscale : 1.0);
        m->drive[i] = creal(bp[i]);
    }
    double cond = plan->cond;
    if (!(cond <= COND_LIMIT)) {
        char where[64];
        pde_factor fu = m->u, fv = m->v;
        snprintf(where, sizeof where, "%s(%g)*%s(%g)", factor_name(fu.kind), fu.p,
                 factor_name(fv.kind), fv.p);
        return pde_fail(diag, PDE_ERR_SINGULAR, ci, m->src_force, m->src_term, "",
                    "component %s, mode %s: e = %.17g is an eigenvalue of the clamped problem "
                    "(cos t cosh t = 1 with t = e^(1/4)), so h'''' = e h with these boundary "
                    "conditions has no unique solution; change a, b or c of %s",
                    pde_comp_name[ci], where, e, pde_comp_name[ci]);
    }
    lu_solve(plan, rhs, coef);
    m->h = hp;
    for (int j = 0; j < 4; j++)
        if ((st = ep_add_ep(s, &m->h, &plan->basis[j], coef[j])) != PDE_OK)
            return st;
    return PDE_OK;
}

static pde_status solve_component(arena *mem, arena *s, plan_cache *plans, const pde_model *model,
                                  int ci, const pde_cancel *cancel, comp_solution *out, pde_diag *diag)
{
    const pde_component *c = &model->comp[ci];
    pde_status st = model_check_component(c, ci, diag);
    if (st != PDE_OK)
        return st;

    mode *modes = NULL;
    size_t n = 0;
    long *next_force = NULL;
    if ((st = collect(s, c, ci, &modes, &n, &next_force, diag)) != PDE_OK)
        return st;
    if (pde_stopped(cancel))
        return PDE_ERR_CANCELLED;
    for (size_t i = 0; i < n; i++) {
        if ((st = solve_mode(s, plans, c, ci, modes, n, &modes[i], next_force, cancel, diag)) != PDE_OK)
            return st;
        if (pde_stopped(cancel))
            return PDE_ERR_CANCELLED;
    }

    out->a = c->a;
    out->b = c->b;
    out->c = c->c;
    /* The modes, then their drives, in one allocation. */
    out->modes = arena_alloc(mem, (n ? n : 1) * (sizeof *out->modes + sizeof *out->drive));
    out->bterms = arena_alloc(mem, (c->nbterms ? c->nbterms : 1) * sizeof *out->bterms);
    out->fterms = arena_alloc(mem, (c->nfterms ? c->nfterms : 1) * sizeof *out->fterms);
    if (!out->modes || !out->bterms || !out->fterms)
        return PDE_ERR_NOMEM;
    out->drive = (double (*)[4])(out->modes + (n ? n : 1));
    if (c->nbterms)
        memcpy(out->bterms, c->bterms, c->nbterms * sizeof *out->bterms);
    if (c->nfterms)
        memcpy(out->fterms, c->fterms, c->nfterms * sizeof *out->fterms);
    out->nbterms = c->nbterms;
    out->nfterms = c->nfterms;
    size_t kept = 0;
    for (size_t i = 0; i < n; i++) {
        if (i % 256 == 255 && pde_stopped(cancel))
            return PDE_ERR_CANCELLED;
        pde_mode *pm = &out->modes[kept];
        pm->u = modes[i].u;
        pm->v = modes[i].v;
        pm->e = -(c->a * factor_lambda(pm->u) + c->b * factor_lambda(pm->v)) / c->c;
        if ((st = to_real(mem, &modes[i].h, pm)) != PDE_OK)
            return st;
        memcpy(out->drive[kept], modes[i].drive, sizeof out->drive[kept]);
        if (!wterms_finite(pm))
            return pde_fail(diag, PDE_ERR_RANGE, ci, modes[i].src_force, modes[i].src_term, "",
                        "component %s: the solution's coefficients overflow a double", pde_comp_name[ci]);
        if (pm->nterms)
            kept++;
    }
    out->nmodes = kept;
    return PDE_OK;
}

pde_status pde_solve_abandon(arena *mem, pde_status st, pde_diag *d)
{
    if ((st == PDE_ERR_NOMEM || st == PDE_ERR_CANCELLED) && d && !d->message[0])
        snprintf(d->message, sizeof d->message, "%s", pde_strerror(st));
    arena_free(mem);
    return st;
}

pde_status pde_solve(const pde_model *model, pde_solution **out, pde_diag *diag)
{
    return pde_solve_ex(model, NULL, out, diag);
}

pde_status pde_solve_ex(const pde_model *model, const pde_solve_opts *opts, pde_solution **out,
                        pde_diag *diag)
{
    const pde_cancel *cancel = opts ? opts->cancel : NULL;
    pde_diag_clear(diag);
    if (!model || !out)
        return pde_fail(diag, PDE_ERR_INVALID, -1, -1, -1, "", "no model given");
    arena mem = { 0 }, scratch = { 0 };
    plan_cache plans = { .n = 0 };   /* plans depend on e alone: x and y often share them */
    pde_solution *sol = arena_alloc(&mem, sizeof *sol);
    pde_status st = sol ? PDE_OK : PDE_ERR_NOMEM;
    for (int ci = 0; ci < 3 && st == PDE_OK; ci++)
        st = solve_component(&mem, &scratch, &plans, model, ci, cancel, &sol->comp[ci], diag);
    arena_free(&scratch);
    if (st != PDE_OK)
        return pde_solve_abandon(&mem, st, diag);
    sol->mem = mem;
    *out = sol;
    return PDE_OK;
}

void pde_solution_free(pde_solution *sol)
{
    if (!sol)
        return;
    arena mem = sol->mem;     /* the solution lives inside its own arena */
    arena_free(&mem);
}

size_t pde_solution_bytes(const pde_solution *sol)
{
    return sol ? sol->mem.bytes : 0;
}

const pde_mode *pde_solution_modes(const pde_solution *sol, int comp, size_t *nmodes)
{
    if (!sol || comp < 0 || comp > 2) {
        *nmodes = 0;
        return NULL;
    }
    *nmodes = sol->comp[comp].nmodes;
    return sol->comp[comp].modes;
}
