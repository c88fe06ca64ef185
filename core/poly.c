/*
 * poly.c: polynomial solids in the power basis and Bernstein range bounds (poly.h).
 *
 * Why: on a polynomial solid (fig. 1) every objective of the properties' branch and bound is a
 * polynomial of known degree per axis, x's and det J's (3 d - 1), so its range over a box is
 * bounded by its Bernstein coefficients there, from a few hundred operations, where the general
 * path (bound.c) builds jets of every mode's factors per box; and the bound is exact wherever the
 * extreme is at a corner of a box, or on a face along which the polynomial is monotone.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "poly.h"

static int ncoef(const int n[3])
{
    return n[0] * n[1] * n[2];
}

int poly_solution(const pde_solution *s, poly3 x[3])
{
    int n[3] = { 1, 1, 1 };
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++) {
            const pde_mode *md = &s->comp[c].modes[m];
            const pde_factor f[2] = { md->u, md->v };
            if (md->nslabs > 1)
                return 0;
            for (int a = 0; a < 2; a++) {
                if (f[a].kind != PDE_POW || f[a].p < 0 || f[a].p != floor(f[a].p) || f[a].p >= POLY_AXIS)
                    return 0;
                n[a] = f[a].p + 1 > n[a] ? (int)f[a].p + 1 : n[a];
            }
            for (size_t k = 0; k < md->nterms; k++) {
                const pde_wterm *t = &md->terms[k];
                if (t->alpha != 0.0 || t->beta != 0.0 || t->deg < 0 || t->deg >= POLY_AXIS)
                    return 0;
                n[2] = t->deg + 1 > n[2] ? t->deg + 1 : n[2];
            }
        }
    /* det J has 3 n - 2 coefficients along each axis. */
    int nd = 1;
    for (int a = 0; a < 3; a++) {
        if (3 * n[a] - 2 > POLY_AXIS)
            return 0;
        nd *= 3 * n[a] - 2;
    }
    if (nd > POLY_MAX)
        return 0;
    for (int c = 0; c < 3; c++) {
        poly3 *p = &x[c];
        memcpy(p->n, n, sizeof p->n);
        memset(p->c, 0, (size_t)ncoef(n) * sizeof p->c[0]);
        for (size_t m = 0; m < s->comp[c].nmodes; m++) {
            const pde_mode *md = &s->comp[c].modes[m];
            const int i = (int)md->u.p, j = (int)md->v.p;
            for (size_t k = 0; k < md->nterms; k++)
                for (int d = 0; d <= md->terms[k].deg; d++)
                    p->c[(i * n[1] + j) * n[2] + d] += md->terms[k].A[d];
        }
    }
    return 1;
}

void poly_deriv(const poly3 *p, int axis, poly3 *out)
{
    int n[3] = { p->n[0], p->n[1], p->n[2] };
    n[axis] = n[axis] > 1 ? n[axis] - 1 : 1;
    memcpy(out->n, n, sizeof n);
    for (int i = 0; i < n[0]; i++)
        for (int j = 0; j < n[1]; j++)
            for (int k = 0; k < n[2]; k++) {
                int e[3] = { i, j, k };
                e[axis]++;
                out->c[(i * n[1] + j) * n[2] + k] =
                    e[axis] < p->n[axis] ? e[axis] * p->c[(e[0] * p->n[1] + e[1]) * p->n[2] + e[2]] : 0.0;
            }
}

/* acc += sign * a * b; acc's sizes hold the product's. */
static void mul_add(const poly3 *a, const poly3 *b, double sign, poly3 *acc)
{
    const int *m = acc->n;
    for (int i = 0; i < a->n[0]; i++)
        for (int j = 0; j < a->n[1]; j++)
            for (int k = 0; k < a->n[2]; k++) {
                const double ca = sign * a->c[(i * a->n[1] + j) * a->n[2] + k];
                if (ca == 0.0)
                    continue;
                for (int p = 0; p < b->n[0]; p++)
                    for (int q = 0; q < b->n[1]; q++)
                        for (int r = 0; r < b->n[2]; r++)
                            acc->c[((i + p) * m[1] + j + q) * m[2] + k + r] += ca * b->c[(p * b->n[1] + q) * b->n[2] + r];
            }
}

static void mul(const poly3 *a, const poly3 *b, poly3 *out)
{
    for (int k = 0; k < 3; k++)
        out->n[k] = a->n[k] + b->n[k] - 1;
    memset(out->c, 0, (size_t)ncoef(out->n) * sizeof out->c[0]);
    mul_add(a, b, 1.0, out);
}

/* det J by cofactors along the first row, from the entries e[r][a] = d x_r / d a, all of one size. */
static void detj_of(poly3 e[3][3], poly3 *t, poly3 *out)
{
    for (int k = 0; k < 3; k++)
        out->n[k] = 3 * e[0][0].n[k] - 2;
    memset(out->c, 0, (size_t)ncoef(out->n) * sizeof out->c[0]);
    for (int a = 0; a < 3; a++) {
        const int b = a == 0 ? 1 : 0, c = a == 2 ? 1 : 2;
        mul(&e[1][b], &e[2][c], t);
        mul_add(&e[1][c], &e[2][b], -1.0, t);
        mul_add(&e[0][a], t, a == 1 ? -1.0 : 1.0, out);
    }
}

/* d x / d a at x's sizes (zeros beyond the derivative's), so that every product has one size; t: scratch. */
static void entry(const poly3 *x, int a, poly3 *t, poly3 *p)
{
    const int *n = x->n;
    poly_deriv(x, a, t);
    memcpy(p->n, n, sizeof p->n);
    memset(p->c, 0, (size_t)ncoef(n) * sizeof p->c[0]);
    for (int i = 0; i < t->n[0]; i++)
        for (int j = 0; j < t->n[1]; j++)
            for (int k = 0; k < t->n[2]; k++)
                p->c[(i * n[1] + j) * n[2] + k] = t->c[(i * t->n[1] + j) * t->n[2] + k];
}

int poly_detj(const poly3 x[3], poly3 *dj)
{
    poly3 *w = malloc(10 * sizeof *w);   /* the nine entries and a scratch */
    if (!w)
        return 0;
    poly3 (*e)[3] = (poly3 (*)[3])w, *t = w + 9;
    for (int r = 0; r < 3; r++)
        for (int a = 0; a < 3; a++)
            entry(&x[r], a, t, &e[r][a]);
    detj_of(e, t, dj);
    free(w);
    return 1;
}

/* The strides of p's axes, and the number of lines along axis a with their starts' offsets into
 * start[] (at most POLY_MAX / 2 + 1 of them: a line has >= 2 coefficients where it matters). */
static int lines_along(const int n[3], int a, int *stride, int *start)
{
    const int st[3] = { n[1] * n[2], n[2], 1 };
    int m[3] = { n[0], n[1], n[2] }, count = 0;
    m[a] = 1;
    for (int i = 0; i < m[0]; i++)
        for (int j = 0; j < m[1]; j++)
            for (int k = 0; k < m[2]; k++)
                start[count++] = i * st[0] + j * st[1] + k;
    *stride = st[a];
    return count;
}

void poly_bernstein(poly3 *p)
{
    double w[POLY_AXIS][POLY_AXIS];   /* C(i, j) / C(d, j) */
    int start[POLY_MAX], st;
    for (int a = 0; a < 3; a++) {
        const int d = p->n[a] - 1;
        if (d < 1)
            continue;
        double binom[POLY_AXIS][POLY_AXIS];   /* C(i, j) */
        for (int i = 0; i <= d; i++) {
            binom[i][0] = binom[i][i] = 1.0;
            for (int j = 1; j < i; j++)
                binom[i][j] = binom[i - 1][j - 1] + binom[i - 1][j];
        }
        for (int i = 0; i <= d; i++)
            for (int j = 0; j <= i; j++)
                w[i][j] = binom[i][j] / binom[d][j];
        const int nl = lines_along(p->n, a, &st, start);
        for (int l = 0; l < nl; l++) {
            double *c = p->c + start[l], a_[POLY_AXIS];
            for (int i = 0; i <= d; i++)
                a_[i] = c[i * st];
            for (int i = 0; i <= d; i++) {   /* b_i = sum_(j <= i) C(i, j) / C(d, j) a_j */
                double sum = 0.0;
                for (int j = 0; j <= i; j++)
                    sum += w[i][j] * a_[j];
                c[i * st] = sum;
            }
        }
    }
}

double poly_eval(const poly3 *p, const double at[3])
{
    const int *n = p->n;
    double su = 0.0;
    for (int i = n[0] - 1; i >= 0; i--) {
        double sv = 0.0;
        for (int j = n[1] - 1; j >= 0; j--) {
            double sw = 0.0;
            for (int k = n[2] - 1; k >= 0; k--)
                sw = sw * at[2] + p->c[(i * n[1] + j) * n[2] + k];
            sv = sv * at[1] + sw;
        }
        su = su * at[0] + sv;
    }
    return su;
}

/* ---- branch and bound over Bernstein coefficients ---- */

typedef struct {
    double lb;   /* first: bb_heap's key */
    double lo[3], hi[3];
    int n[3], depth;
    size_t slot;   /* its coefficients: pool + slot * size */
} pnode;

typedef struct {
    bb_heap heap;   /* of pnode */
    double *pool;
    size_t *free_slot, nfree, slots, cap_slots;
    int size;      /* coefficients per slot */
} pheap;

static double *slot_of(const pheap *h, size_t slot)
{
    return h->pool + slot * (size_t)h->size;
}

/* A slot for a node's coefficients, or (size_t)-1 on NOMEM. */
static size_t slot_new(pheap *h)
{
    if (h->nfree)
        return h->free_slot[--h->nfree];
    if (h->slots == h->cap_slots) {
        size_t cap = h->cap_slots ? 2 * h->cap_slots : 16;
        double *pool = realloc(h->pool, cap * (size_t)h->size * sizeof *pool);
        if (!pool)
            return (size_t)-1;
        h->pool = pool;
        size_t *fs = realloc(h->free_slot, cap * sizeof *fs);
        if (!fs)
            return (size_t)-1;
        h->free_slot = fs;
        h->cap_slots = cap;
    }
    return h->slots++;
}

/* Keeps index `keep` along axis a only: the face of the box there. */
static void slice(double *b, int n[3], int a, int keep)
{
    int m[3] = { n[0], n[1], n[2] };
    m[a] = 1;
    for (int i = 0; i < m[0]; i++)
        for (int j = 0; j < m[1]; j++)
            for (int k = 0; k < m[2]; k++) {
                int e[3] = { i, j, k };
                e[a] = keep;
                b[(i * m[1] + j) * m[2] + k] = b[(e[0] * n[1] + e[1]) * n[2] + e[2]];
            }
    n[a] = 1;
}

/*
 * Settles a new node: where the coefficients rise (fall) along an axis the polynomial does and its
 * minimum is on the low (high) face, to which the box shrinks; its corners' values are attained
 * (best); its bound is its least coefficient, exact when that is a corner's. Returns 1 when the
 * node still needs splitting.
 */
/* The least and largest difference of neighbouring coefficients along axis a. */
static void slopes(const double *b, const int n[3], int a, double *lo, double *hi)
{
    int start[POLY_MAX], st;
    const int nl = lines_along(n, a, &st, start);
    double l = INFINITY, h = -INFINITY;
    for (int q = 0; q < nl; q++)
        for (int i = 0; i + 1 < n[a]; i++) {
            const double d = b[start[q] + (i + 1) * st] - b[start[q] + i * st];
            l = d < l ? d : l, h = d > h ? d : h;
        }
    *lo = l, *hi = h;
}

static int settle(pnode *nd, double *b, double *best, double at[3], double *done)
{
    for (int moved = 1; moved;) {
        moved = 0;
        for (int a = 0; a < 3; a++) {
            if (nd->n[a] < 2)
                continue;
            double lo, hi;
            slopes(b, nd->n, a, &lo, &hi);
            const int up = lo >= 0.0, down = hi <= 0.0;
            if (up || down) {
                slice(b, nd->n, a, up ? 0 : nd->n[a] - 1);
                if (up)
                    nd->hi[a] = nd->lo[a];
                else
                    nd->lo[a] = nd->hi[a];
                moved = 1;
            }
        }
    }
    const int nc = ncoef(nd->n);
    int arg = 0;
    for (int q = 1; q < nc; q++)
        if (b[q] < b[arg])
            arg = q;
    nd->lb = b[arg];
    int corner_arg = 0;
    for (int cr = 0; cr < 8; cr++) {
        int idx[3];
        double p[3];
        for (int a = 0; a < 3; a++) {
            const int hi = cr >> a & 1;
            idx[a] = hi ? nd->n[a] - 1 : 0;
            p[a] = hi ? nd->hi[a] : nd->lo[a];
        }
        const int q = (idx[0] * nd->n[1] + idx[1]) * nd->n[2] + idx[2];
        if (b[q] < *best)
            *best = b[q], memcpy(at, p, sizeof p);
        corner_arg |= q == arg;
    }
    if (corner_arg || !(nd->lb == nd->lb)) {
        *done = fmin(*done, nd->lb);
        return 0;
    }
    return 1;
}

/* The axis along which the coefficients' slopes spread most: where the polynomial bends. */
static int split_axis_of(const pnode *nd, const double *b)
{
    int best = -1;
    double most = -1.0;
    for (int a = 0; a < 3; a++) {
        if (nd->n[a] < 2)
            continue;
        double lo, hi;
        slopes(b, nd->n, a, &lo, &hi);
        if (hi - lo > most)
            most = hi - lo, best = a;
    }
    return best;
}

/* The halves of b along axis a (de Casteljau at 1/2): into l and r, sizes n. */
static void halve(const double *b, const int n[3], int a, double *l, double *r)
{
    int start[POLY_MAX], st;
    const int nl = lines_along(n, a, &st, start), m = n[a];
    for (int q = 0; q < nl; q++) {
        double t[POLY_AXIS];
        const int s0 = start[q];
        for (int i = 0; i < m; i++)
            t[i] = b[s0 + i * st];
        for (int lev = 0; lev < m; lev++) {
            l[s0 + lev * st] = t[0];
            r[s0 + (m - 1 - lev) * st] = t[m - 1 - lev];
            for (int i = 0; i + 1 < m - lev; i++)
                t[i] = 0.5 * (t[i] + t[i + 1]);
        }
    }
}

pde_status poly_minimise(const poly3 *bern, double sign, double tol, size_t budget, bb_result *out)
{
    pheap h = { .heap = { .size = sizeof(pnode) }, .size = ncoef(bern->n) };
    bb_result r = { .best = INFINITY, .lower = INFINITY };
    double done = INFINITY;
    pde_status st = PDE_OK;
    pnode root = { 0.0, { 0, 0, 0 }, { 1, 1, 1 }, { bern->n[0], bern->n[1], bern->n[2] }, 0, slot_new(&h) };
    if (root.slot == (size_t)-1) {
        st = PDE_ERR_NOMEM;
        goto out;
    }
    double *b0 = slot_of(&h, root.slot);
    for (int q = 0; q < h.size; q++)
        b0[q] = sign * bern->c[q];
    r.boxes = 1;
    if (settle(&root, b0, &r.best, r.at, &done) && bb_heap_push(&h.heap, &root)) {
        st = PDE_ERR_NOMEM;
        goto out;
    }
    while (h.heap.n && bb_heap_min(&h.heap) < r.best - tol && r.boxes < budget) {
        pnode top;
        bb_heap_pop(&h.heap, &top);
        const int a = split_axis_of(&top, slot_of(&h, top.slot));
        if (a < 0) {   /* constant: settled by its corners (not reached) */
            done = fmin(done, top.lb);
            h.free_slot[h.nfree++] = top.slot;
            continue;
        }
        pnode kid[2] = { top, top };
        kid[1].slot = slot_new(&h);
        if (kid[1].slot == (size_t)-1) {
            st = PDE_ERR_NOMEM;
            goto out;
        }
        const double mid = 0.5 * (top.lo[a] + top.hi[a]);
        kid[0].hi[a] = kid[1].lo[a] = mid;
        double tmp[POLY_MAX];
        double *bl = slot_of(&h, kid[0].slot), *br = slot_of(&h, kid[1].slot);
        memcpy(tmp, bl, (size_t)ncoef(top.n) * sizeof *tmp);
        halve(tmp, top.n, a, bl, br);
        for (int k = 0; k < 2; k++) {
            kid[k].depth = top.depth + 1;
            r.boxes++;
            /* A child's minimum is at least its parent's bound. */
            if (settle(&kid[k], slot_of(&h, kid[k].slot), &r.best, r.at, &done)) {
                kid[k].lb = fmax(kid[k].lb, top.lb);
                if (bb_heap_push(&h.heap, &kid[k])) {
                    st = PDE_ERR_NOMEM;
                    goto out;
                }
            } else
                h.free_slot[h.nfree++] = kid[k].slot;
        }
    }
    r.lower = fmin(done, r.best);
    if (h.heap.n)
        r.lower = fmin(r.lower, bb_heap_min(&h.heap));
out:
    free(h.heap.a);
    free(h.pool);
    free(h.free_slot);
    if (st == PDE_OK)
        *out = r;
    return st;
}

void poly_eval_d(const poly3 *p, const double at[3], double *v, double d[3])
{
    /* Horner along w, v, u in turn, each carrying the partials of the inner ones. */
    const int *n = p->n;
    double U = 0.0, Uu = 0.0, Uv = 0.0, Uw = 0.0;
    for (int i = n[0] - 1; i >= 0; i--) {
        double V = 0.0, Vv = 0.0, Vw = 0.0;
        for (int j = n[1] - 1; j >= 0; j--) {
            const double *c = p->c + (i * n[1] + j) * n[2];
            double W = 0.0, Ww = 0.0;
            for (int k = n[2] - 1; k >= 0; k--)
                Ww = Ww * at[2] + W, W = W * at[2] + c[k];
            Vv = Vv * at[1] + V, V = V * at[1] + W, Vw = Vw * at[1] + Ww;
        }
        Uu = Uu * at[0] + U, U = U * at[0] + V, Uv = Uv * at[0] + Vv, Uw = Uw * at[0] + Vw;
    }
    *v = U, d[0] = Uu, d[1] = Uv, d[2] = Uw;
}

/* The integral over the unit cube of p, from its power coefficients. */
static double integral(const poly3 *p)
{
    double sum = 0.0;
    for (int i = 0; i < p->n[0]; i++)
        for (int j = 0; j < p->n[1]; j++)
            for (int k = 0; k < p->n[2]; k++)
                sum += p->c[(i * p->n[1] + j) * p->n[2] + k] / ((i + 1.0) * (j + 1.0) * (k + 1.0));
    return sum;
}

/* Sizes that hold both a * b and c * d, or 0 beyond the limits. */
static int product_sizes(const poly3 *a, const poly3 *b, const poly3 *c, const poly3 *d, int n[3])
{
    int sz = 1;
    for (int k = 0; k < 3; k++) {
        const int n1 = a->n[k] + b->n[k] - 1, n2 = c->n[k] + d->n[k] - 1;
        n[k] = n1 > n2 ? n1 : n2;
        if (n[k] > POLY_AXIS)
            return 0;
        sz *= n[k];
    }
    return sz <= POLY_MAX;
}

int poly_face_element(const poly3 x[3], int axis, int side, poly3 *e2, double *flux)
{
    poly3 *w = malloc(13 * sizeof *w);   /* the face's x, its two partials, the element c, scratch */
    if (!w)
        return 0;
    poly3 *f = w, *ta = w + 3, *tb = w + 6, *c = w + 9, *t = w + 12;
    int o[2], m = 0;
    for (int k = 0; k < 3; k++)
        if (k != axis)
            o[m++] = k;
    for (int k = 0; k < 3; k++) {
        const int *n = x[k].n;
        memcpy(f[k].n, n, sizeof f[k].n);
        f[k].n[axis] = 1;
        memset(f[k].c, 0, (size_t)ncoef(f[k].n) * sizeof f[k].c[0]);
        for (int i = 0; i < n[0]; i++)
            for (int j = 0; j < n[1]; j++)
                for (int l = 0; l < n[2]; l++) {
                    const int e[3] = { i, j, l };
                    int g[3] = { i, j, l };
                    g[axis] = 0;
                    if (side || e[axis] == 0)   /* side^e: 1 on side 1, on side 0 only e = 0 */
                        f[k].c[(g[0] * f[k].n[1] + g[1]) * f[k].n[2] + g[2]] += x[k].c[(i * n[1] + j) * n[2] + l];
                }
        poly_deriv(&f[k], o[0], &ta[k]);
        poly_deriv(&f[k], o[1], &tb[k]);
    }
    /* c = ta x tb, then |c|^2 and the flux x . c. */
    int ok = 1;
    for (int k = 0; k < 3 && ok; k++) {
        const int p = (k + 1) % 3, q = (k + 2) % 3;
        if ((ok = product_sizes(&ta[p], &tb[q], &ta[q], &tb[p], c[k].n))) {
            memset(c[k].c, 0, (size_t)ncoef(c[k].n) * sizeof c[k].c[0]);
            mul_add(&ta[p], &tb[q], 1.0, &c[k]);
            mul_add(&ta[q], &tb[p], -1.0, &c[k]);
        }
    }
    ok = ok && product_sizes(&c[0], &c[0], &c[1], &c[1], e2->n) && product_sizes(&c[2], &c[2], &c[2], &c[2], t->n);
    for (int a = 0; a < 3 && ok; a++)
        e2->n[a] = t->n[a] > e2->n[a] ? t->n[a] : e2->n[a];
    ok = ok && product_sizes(&f[0], &c[0], &f[1], &c[1], t->n) && product_sizes(&f[2], &c[2], &f[2], &c[2], t->n);
    if (ok) {
        memset(e2->c, 0, (size_t)ncoef(e2->n) * sizeof e2->c[0]);
        *flux = 0.0;
        for (int k = 0; k < 3; k++) {
            mul_add(&c[k], &c[k], 1.0, e2);
            mul(&f[k], &c[k], t);
            *flux += integral(t);
        }
    }
    free(w);
    return ok;
}
