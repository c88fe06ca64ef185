/*
 * model.c: what makes a model valid, how factors normalise, and the
 * canonical form of a model, which equal models share however they are
 * spelled (terms in another order, split in two, sin(-k) for -sin(k), ...).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

const char *const pde_comp_name[3] = { "x", "y", "z" };

pde_status pde_fail(pde_diag *d, pde_status st, int comp, int in_force, long term, const char *field,
                    const char *fmt, ...)
{
    if (!d)
        return st;
    d->component = comp;
    d->in_force = in_force;
    d->term = term;
    d->section = -1;
    snprintf(d->field, sizeof d->field, "%s", field);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(d->message, sizeof d->message, fmt, ap);
    va_end(ap);
    return st;
}

const char *factor_name(pde_factor_kind k)
{
    static const char *const w[] = { "pow", "sin", "cos", "exp", "sinh", "cosh" };
    return (unsigned)k < 6 ? w[k] : "?";
}

/* NULL if the factor is valid, else what is wrong with it. */
static const char *factor_problem(pde_factor f)
{
    if (!isfinite(f.p))
        return "is not a finite number";
    switch (f.kind) {
    case PDE_POW:
        if (f.p != floor(f.p) || f.p < 0 || f.p > PDE_MAX_POW)
            return "must be an integer power from 0 to 100";
        return NULL;
    case PDE_SIN:
    case PDE_COS:
        if (fabs(f.p) > PDE_MAX_FREQ)
            return "has a frequency k beyond 1e6";
        return NULL;
    case PDE_EXP:
    case PDE_SINH:
    case PDE_COSH:
        if (fabs(f.p) > PDE_MAX_ARG)
            return "has |alpha| > 700, so its values overflow a double";
        return NULL;
    }
    return "has an unknown kind";
}

int factor_normalise(pde_factor f, pde_factor *key, double *sign)
{
    static const pde_factor one = { PDE_POW, 0.0 };
    *key = f;
    *sign = 1.0;
    switch (f.kind) {
    case PDE_POW:
        break;
    case PDE_SIN:
    case PDE_SINH:
        if (f.p == 0.0)
            return 0;
        if (f.p < 0.0) {
            key->p = -f.p;
            *sign = -1.0;
        }
        break;
    case PDE_COS:
    case PDE_COSH:
    case PDE_EXP:
        if (f.p == 0.0)
            *key = one;
        else if (f.kind != PDE_EXP)
            key->p = fabs(f.p);
        break;
    }
    key->p += 0.0;   /* -0 -> +0 */
    return 1;
}

int factor_compare(pde_factor a, pde_factor b)
{
    if (a.kind != b.kind)
        return a.kind < b.kind ? -1 : 1;
    return a.p < b.p ? -1 : a.p > b.p;
}

pde_status model_check_component(const pde_component *c, int ci, pde_diag *diag)
{
    static const char *const abc[3] = { "a", "b", "c" };
    static const char *const bf[4] = { "w0", "dw0", "w1", "dw1" };
    static const char *const uvw[3] = { "u", "v", "w" };
    const double v[3] = { c->a, c->b, c->c };
    for (int k = 0; k < 3; k++)
        if (!isfinite(v[k]))
            return pde_fail(diag, PDE_ERR_INVALID, ci, -1, -1, abc[k], "%s of component %s is not a finite number",
                            abc[k], pde_comp_name[ci]);
    if (c->c == 0.0)
        return pde_fail(diag, PDE_ERR_ILLPOSED, ci, -1, -1, "c",
                        "c of component %s is 0: the equation is then not fourth order in w and "
                        "the four boundary conditions cannot all hold", pde_comp_name[ci]);
    if ((c->nbterms && !c->bterms) || (c->nfterms && !c->fterms))
        return pde_fail(diag, PDE_ERR_INVALID, ci, -1, -1, "", "component %s has a NULL term list",
                        pde_comp_name[ci]);
    for (size_t j = 0; j < c->nbterms; j++) {
        const pde_bterm *t = &c->bterms[j];
        const double d[4] = { t->w0, t->dw0, t->w1, t->dw1 };
        for (int k = 0; k < 4; k++)
            if (!isfinite(d[k]))
                return pde_fail(diag, PDE_ERR_INVALID, ci, 0, (long)j, bf[k], "%s is not a finite number", bf[k]);
        const pde_factor f[2] = { t->u, t->v };
        for (int k = 0; k < 2; k++) {
            const char *why = factor_problem(f[k]);
            if (why)
                return pde_fail(diag, PDE_ERR_INVALID, ci, 0, (long)j, uvw[k], "the %s factor %s %s", uvw[k],
                                factor_name(f[k].kind), why);
        }
    }
    for (size_t j = 0; j < c->nfterms; j++) {
        const pde_fterm *t = &c->fterms[j];
        if (!isfinite(t->coef))
            return pde_fail(diag, PDE_ERR_INVALID, ci, 1, (long)j, "coef", "coef is not a finite number");
        const pde_factor f[3] = { t->u, t->v, t->w };
        for (int k = 0; k < 3; k++) {
            const char *why = factor_problem(f[k]);
            if (why)
                return pde_fail(diag, PDE_ERR_INVALID, ci, 1, (long)j, uvw[k], "the %s factor %s %s", uvw[k],
                                factor_name(f[k].kind), why);
        }
    }
    return PDE_OK;
}

/*
 * Canonical form. Each term is split into (key, slot, value) entries, one per
 * coefficient; sorting them by key, slot and value and summing runs gives
 * sums that do not depend on the order of the terms.
 */
typedef struct {
    pde_factor f[3];   /* u, v, and w for forces */
    int slot;          /* 0..3: w0, dw0, w1, dw1; 0: coef */
    double value;
} entry;

static int entry_cmp(const void *pa, const void *pb)
{
    const entry *a = pa, *b = pb;
    for (int k = 0; k < 3; k++) {
        int c = factor_compare(a->f[k], b->f[k]);
        if (c)
            return c;
    }
    if (a->slot != b->slot)
        return a->slot - b->slot;
    return (a->value > b->value) - (a->value < b->value);
}

static int same_key(const entry *a, const entry *b)
{
    return factor_compare(a->f[0], b->f[0]) == 0 && factor_compare(a->f[1], b->f[1]) == 0 &&
           factor_compare(a->f[2], b->f[2]) == 0;
}

/* Sorts and sums the entries of one list into n merged coefficient rows of width `slots`. */
static size_t merge(entry *e, size_t n, int slots, pde_factor (*keys)[3], double (*vals)[4])
{
    qsort(e, n, sizeof *e, entry_cmp);
    size_t out = 0;
    for (size_t i = 0; i < n;) {
        size_t j = i;
        double v[4] = { 0, 0, 0, 0 };
        while (j < n && same_key(&e[i], &e[j])) {
            v[e[j].slot] += e[j].value;
            j++;
        }
        int nonzero = 0;
        for (int s = 0; s < slots; s++) {
            v[s] += 0.0;   /* -0 -> +0 */
            nonzero |= v[s] != 0.0;
        }
        if (nonzero) {
            memcpy(keys[out], e[i].f, sizeof keys[out]);
            memcpy(vals[out], v, sizeof vals[out]);
            out++;
        }
        i = j;
    }
    return out;
}

void pde_model_canonical_free(pde_model *m)
{
    if (!m)
        return;
    for (int c = 0; c < 3; c++) {
        free((void *)m->comp[c].bterms);
        free((void *)m->comp[c].fterms);
        m->comp[c].bterms = NULL;
        m->comp[c].fterms = NULL;
    }
}

pde_status pde_model_canonical(const pde_model *m, pde_model *out, pde_diag *diag)
{
    pde_model r;
    memset(&r, 0, sizeof r);
    for (int ci = 0; ci < 3; ci++) {
        const pde_component *c = &m->comp[ci];
        pde_status st = model_check_component(c, ci, diag);
        if (st != PDE_OK) {
            pde_model_canonical_free(&r);
            return st;
        }
        size_t nb = c->nbterms, nf = c->nfterms, ne = 4 * nb + nf;
        entry *e = malloc((ne ? ne : 1) * sizeof *e);
        pde_factor(*keys)[3] = malloc((ne ? ne : 1) * sizeof *keys);
        double(*vals)[4] = malloc((ne ? ne : 1) * sizeof *vals);
        pde_bterm *bt = malloc((nb ? nb : 1) * sizeof *bt);
        pde_fterm *ft = malloc((nf ? nf : 1) * sizeof *ft);
        r.comp[ci].bterms = bt;
        r.comp[ci].fterms = ft;
        if (!e || !keys || !vals || !bt || !ft) {
            free(e), free(keys), free(vals);
            pde_model_canonical_free(&r);
            return pde_fail(diag, PDE_ERR_NOMEM, ci, -1, -1, "", "out of memory");
        }
        size_t k = 0;
        for (size_t j = 0; j < nb; j++) {
            const pde_bterm *t = &c->bterms[j];
            pde_factor ku, kv;
            double su, sv;
            if (!factor_normalise(t->u, &ku, &su) || !factor_normalise(t->v, &kv, &sv))
                continue;
            const double d[4] = { t->w0, t->dw0, t->w1, t->dw1 };
            for (int s = 0; s < 4; s++)
                e[k++] = (entry){ { ku, kv, { PDE_POW, 0 } }, s, su * sv * d[s] };
        }
        size_t n = merge(e, k, 4, keys, vals);
        for (size_t j = 0; j < n; j++)
            bt[j] = (pde_bterm){ keys[j][0], keys[j][1], vals[j][0], vals[j][1], vals[j][2], vals[j][3] };
        r.comp[ci].nbterms = n;
        k = 0;
        for (size_t j = 0; j < nf; j++) {
            const pde_fterm *t = &c->fterms[j];
            pde_factor ku, kv, kw;
            double su, sv, sw;
            if (!factor_normalise(t->u, &ku, &su) || !factor_normalise(t->v, &kv, &sv) ||
                !factor_normalise(t->w, &kw, &sw))
                continue;
            e[k++] = (entry){ { ku, kv, kw }, 0, su * sv * sw * t->coef };
        }
        n = merge(e, k, 1, keys, vals);
        for (size_t j = 0; j < n; j++)
            ft[j] = (pde_fterm){ vals[j][0], keys[j][0], keys[j][1], keys[j][2] };
        r.comp[ci].nfterms = n;
        r.comp[ci].a = c->a + 0.0;
        r.comp[ci].b = c->b + 0.0;
        r.comp[ci].c = c->c + 0.0;
        free(e), free(keys), free(vals);
    }
    *out = r;
    return PDE_OK;
}
