/*
 * factor.c: the one-variable factors f(t) of boundary and force terms, and
 * the exponential-polynomial w-terms of a solution: values and derivatives of
 * any order.
 */
#include <complex.h>
#include <math.h>
#include <stdlib.h>

#include "internal.h"
#include "quad.h"   /* quad_same_h */

/* n (n-1) ... (n-k+1) */
static double falling(double n, int k)
{
    double r = 1.0;
    for (int i = 0; i < k; i++)
        r *= n - i;
    return r;
}

static double ipow(double t, int n)
{
    double r = 1.0;
    for (; n > 0; n >>= 1, t *= t)
        if (n & 1)
            r *= t;
    return r;
}

double factor_lambda(pde_factor f)
{
    double w;
    switch (f.kind) {
    case PDE_SIN:
    case PDE_COS:
        w = f.p * M_PI;
        break;
    case PDE_EXP:
    case PDE_SINH:
    case PDE_COSH:
        w = f.p;
        break;
    default:
        return 0.0;
    }
    return (w * w) * (w * w);
}

double factor_deriv(pde_factor f, double t, int n)
{
    double w;
    switch (f.kind) {
    case PDE_POW: {
        int p = (int)f.p;
        if (n > p)
            return 0.0;
        return falling(p, n) * ipow(t, p - n);
    }
    case PDE_SIN:
    case PDE_COS: {
        w = f.p * M_PI;
        double s = sin(w * t), c = cos(w * t);
        /* Each derivative turns sin -> cos -> -sin -> -cos; cos starts one step on. */
        int phase = (n + (f.kind == PDE_COS)) & 3;
        double v = phase == 0 ? s : phase == 1 ? c : phase == 2 ? -s : -c;
        return ipow(w, n) * v;
    }
    case PDE_EXP:
        return ipow(f.p, n) * exp(f.p * t);
    case PDE_SINH:
    case PDE_COSH: {
        /* sinh' = cosh and cosh' = sinh: sinh at even orders of sinh and odd orders of cosh. */
        int is_sinh = ((n & 1) == 0) == (f.kind == PDE_SINH);
        return ipow(f.p, n) * (is_sinh ? sinh(f.p * t) : cosh(f.p * t));
    }
    }
    return 0.0;
}

void factor_eval(pde_factor f, double t, double *val, double *der)
{
    double w;
    switch (f.kind) {
    case PDE_POW: {
        int p = (int)f.p;
        double tp = p > 0 ? ipow(t, p - 1) : 0.0;
        *val = p > 0 ? tp * t : 1.0;
        *der = p * tp;
        return;
    }
    case PDE_SIN:
        w = f.p * M_PI;
        *val = sin(w * t);
        *der = w * cos(w * t);
        return;
    case PDE_COS:
        w = f.p * M_PI;
        *val = cos(w * t);
        *der = -w * sin(w * t);
        return;
    case PDE_EXP:
        *val = exp(f.p * t);
        *der = f.p * *val;
        return;
    case PDE_SINH:
        *val = sinh(f.p * t);
        *der = f.p * cosh(f.p * t);
        return;
    case PDE_COSH:
        *val = cosh(f.p * t);
        *der = f.p * sinh(f.p * t);
        return;
    }
    *val = *der = 0.0;
}

/* P(w) and P'(w) by Horner (a constant, fig. 2 and 4's every term of x and y, without the loop). */
static inline void horner2(const double *c, int deg, double w, double *p, double *dp)
{
    if (deg == 0) {
        *p = c[0], *dp = 0.0;
        return;
    }
    double v = c[deg], d = 0.0;
    for (int k = deg - 1; k >= 0; k--) {
        d = d * w + v;
        v = v * w + c[k];
    }
    *p = v;
    *dp = d;
}

/*
 * The exps and sincos already taken at one w, by (alpha, shift) and by beta: w-terms of other modes
 * often share them (the sin and cos modes of one frequency have the same terms' exponents). The
 * last MEMO_N of each are kept.
 */
enum { MEMO_N = 8 };

typedef struct {
    unsigned ne, nt;
    double ea[MEMO_N], es[MEMO_N], ev[MEMO_N];   /* alpha, shift: exp(alpha (w - shift)) */
    double tb[MEMO_N], tc[MEMO_N], ts[MEMO_N];   /* beta: cos(beta w), sin(beta w) */
} wmemo;

static inline double memo_exp(wmemo *mc, const pde_wterm *t, double w)
{
    if (t->alpha == 0.0)
        return 1.0;
    if (!mc)
        return exp(t->alpha * (w - t->shift));
    for (unsigned i = 0; i < mc->ne && i < MEMO_N; i++)
        if (mc->ea[i] == t->alpha && mc->es[i] == t->shift)
            return mc->ev[i];
    const double e = exp(t->alpha * (w - t->shift));
    const unsigned i = mc->ne++ % MEMO_N;
    mc->ea[i] = t->alpha, mc->es[i] = t->shift, mc->ev[i] = e;
    return e;
}

static inline void memo_sincos(wmemo *mc, double beta, double w, double *c, double *s)
{
    if (!mc) {
        *c = cos(beta * w), *s = sin(beta * w);
        return;
    }
    for (unsigned i = 0; i < mc->nt && i < MEMO_N; i++)
        if (mc->tb[i] == beta) {
            *c = mc->tc[i], *s = mc->ts[i];
            return;
        }
    *c = cos(beta * w), *s = sin(beta * w);
    const unsigned i = mc->nt++ % MEMO_N;
    mc->tb[i] = beta, mc->tc[i] = *c, mc->ts[i] = *s;
}

/* A term's value and w-derivative added to *hv, *hd, given E = exp(alpha (w - shift)) (1 where alpha
 * = 0) and, where beta is not 0, c = cos(beta w), s = sin(beta w). */
static inline void wterm_add(const pde_wterm *t, double w, double E, double c, double s, double *hv, double *hd)
{
    double a, da;
    horner2(t->A, t->deg, w, &a, &da);
    if (t->beta == 0.0) {
        *hv += E * a;
        *hd += E * (t->alpha * a + da);
        return;
    }
    double b, db;
    horner2(t->B, t->deg, w, &b, &db);
    double v = a * c + b * s;
    *hv += E * v;
    *hd += E * (t->alpha * v + da * c + db * s + t->beta * (b * c - a * s));
}

/* mode_h, with the exps and sincos of mc (NULL: none kept). The library calls come first in a term,
 * so that fewer values live across them (and are spilled to memory). */
static inline void mode_h_memo(const pde_mode *m, double w, wmemo *mc, double *h, double *dh)
{
    double hv = 0.0, hd = 0.0;
    size_t k0, k1;
    mode_slab(m, w, &k0, &k1);
    for (size_t k = k0; k < k1; k++) {
        const pde_wterm *t = &m->terms[k];
        const double E = memo_exp(mc, t, w);
        double c = 0.0, s = 0.0;
        if (t->beta != 0.0)
            memo_sincos(mc, t->beta, w, &c, &s);
        wterm_add(t, w, E, c, s, &hv, &hd);
    }
    *h = hv;
    *dh = hd;
}

size_t distinct_h(const pde_solution *s, const pde_mode **dm, unsigned *map)
{
    size_t nd = 0, o = 0;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++, o++) {
            const pde_mode *md = &s->comp[c].modes[m];
            size_t i = 0;
            while (i < nd && !quad_same_h(dm[i], md))
                i++;
            if (i == nd)
                dm[nd++] = md;
            map[o] = (unsigned)i;
        }
    return nd;
}

/* The index of v among vals[lo .. *n - 1] (pairs where two is set: vals[2 i], vals[2 i + 1]), added at
 * *n where it is not there. */
static unsigned wtab_slot(double *vals, int two, size_t lo, size_t *n, double v0, double v1)
{
    size_t i = lo;
    while (i < *n && !(vals[two ? 2 * i : i] == v0 && (!two || vals[2 * i + 1] == v1)))
        i++;
    if (i == *n) {
        if (two)
            vals[2 * i] = v0, vals[2 * i + 1] = v1;
        else
            vals[i] = v0;
        ++*n;
    }
    return (unsigned)i;
}

wtable *wtable_new(const pde_solution *s)
{
    size_t nm = 0, nt = 0;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++, nm++)
            nt += s->comp[c].modes[m].nterms;
    size_t nslabs;
    const double *breaks = solution_breaks(s, &nslabs);
    /* one block: the struct, its doubles (ea: nt + 1 pairs, ev: nt + 1, bb: nt, cs: nt + 1 pairs), its
     * pointers (dm), its unsigneds (toff, eoff, boff, ie, ib, map) */
    const size_t ndbl = 2 * (nt + 1) + (nt + 1) + nt + 2 * (nt + 1), nuns = (nm + 1) + 2 * (nslabs + 1) + 2 * nt + nm;
    wtable *t = calloc(1, sizeof *t + ndbl * sizeof(double) + nm * sizeof *t->dm + nuns * sizeof(unsigned));
    if (!t)
        return NULL;
    double *p = (double *)(t + 1);
    t->ea = p, p += 2 * (nt + 1);
    t->ev = p, p += nt + 1;
    t->bb = p, p += nt;
    t->cs = p, p += 2 * (nt + 1);
    t->dm = (const pde_mode **)p;
    t->toff = (unsigned *)(t->dm + nm);
    t->eoff = t->toff + nm + 1, t->boff = t->eoff + nslabs + 1;
    t->ie = t->boff + nslabs + 1, t->ib = t->ie + nt, t->map = t->ib + nt;
    t->nslabs = nslabs, t->breaks = breaks;
    t->nd = distinct_h(s, t->dm, t->map);
    for (size_t d = 0; d < t->nd; d++)
        t->toff[d + 1] = t->toff[d] + (unsigned)t->dm[d]->nterms;
    size_t ne = 1, nb = 0;   /* the exps' slot 0: alpha = 0, E = 1 */
    t->ev[0] = 1.0;
    for (size_t k = 0; k < nslabs; k++) {
        t->eoff[k] = (unsigned)ne, t->boff[k] = (unsigned)nb;
        for (size_t d = 0; d < t->nd; d++) {
            const pde_mode *m = t->dm[d];
            const size_t k0 = m->nslabs <= 1 ? 0 : m->first[k], k1 = m->nslabs <= 1 ? m->nterms : m->first[k + 1];
            for (size_t i = k0; i < k1; i++) {
                const pde_wterm *w = &m->terms[i];
                t->ie[t->toff[d] + i] = w->alpha == 0.0 ? 0 : wtab_slot(t->ea, 1, t->eoff[k], &ne, w->alpha, w->shift);
                t->ib[t->toff[d] + i] = w->beta == 0.0 ? 0 : wtab_slot(t->bb, 0, t->boff[k], &nb, w->beta, 0.0);
            }
        }
    }
    t->eoff[nslabs] = (unsigned)ne, t->boff[nslabs] = (unsigned)nb;
    return t;
}

void wtable_free(wtable *t)
{
    free(t);
}

void wtable_eval(wtable *t, double w, double *h, double *dh)
{
    const size_t k = slab_index(t->breaks, t->nslabs, w);
    for (size_t i = t->eoff[k]; i < t->eoff[k + 1]; i++)
        t->ev[i] = exp(t->ea[2 * i] * (w - t->ea[2 * i + 1]));
    for (size_t i = t->boff[k]; i < t->boff[k + 1]; i++) {
        const double x = t->bb[i] * w;   /* loaded once: one sincos */
        t->cs[2 * i] = cos(x), t->cs[2 * i + 1] = sin(x);
    }
    for (size_t d = 0; d < t->nd; d++) {
        const pde_mode *m = t->dm[d];
        const size_t k0 = m->nslabs <= 1 ? 0 : m->first[k], k1 = m->nslabs <= 1 ? m->nterms : m->first[k + 1];
        const unsigned *ie = t->ie + t->toff[d], *ib = t->ib + t->toff[d];
        double hv = 0.0, hd = 0.0;
        for (size_t i = k0; i < k1; i++)
            wterm_add(&m->terms[i], w, t->ev[ie[i]], t->cs[2 * ib[i]], t->cs[2 * ib[i] + 1], &hv, &hd);
        h[d] = hv, dh[d] = hd;
    }
}

void mode_h(const pde_mode *m, double w, double *h, double *dh)
{
    mode_h_memo(m, w, NULL, h, dh);
}

void solution_factors(const pde_solution *s, int axis, double t, double *val, double *der)
{
    size_t o = 0;
    if (axis == 2) {
        wmemo mc;
        mc.ne = mc.nt = 0;
        for (int c = 0; c < 3; c++)
            for (size_t m = 0; m < s->comp[c].nmodes; m++, o++)
                mode_h_memo(&s->comp[c].modes[m], t, &mc, &val[o], &der[o]);
        return;
    }
    /* the last MEMO_N distinct factors and their places in val, der: a factor recurs across modes;
     * and sin(k pi t), cos(k pi t) by k, which sin and cos factors of one k share */
    pde_factor key[MEMO_N];
    size_t at[MEMO_N];
    double tk[MEMO_N], ts[MEMO_N], tc[MEMO_N];
    unsigned nk = 0, nt = 0;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++, o++) {
            const pde_factor f = axis ? s->comp[c].modes[m].v : s->comp[c].modes[m].u;
            unsigned i = 0;
            while (i < nk && i < MEMO_N && !(key[i].kind == f.kind && key[i].p == f.p))
                i++;
            if (i < nk && i < MEMO_N) {
                val[o] = val[at[i]], der[o] = der[at[i]];
                continue;
            }
            if (f.kind == PDE_SIN || f.kind == PDE_COS) {   /* factor_eval's values */
                const double w = f.p * M_PI;
                unsigned j = 0;
                while (j < nt && j < MEMO_N && tk[j] != f.p)
                    j++;
                if (!(j < nt && j < MEMO_N)) {
                    j = nt++ % MEMO_N;
                    tk[j] = f.p, ts[j] = sin(w * t), tc[j] = cos(w * t);
                }
                val[o] = f.kind == PDE_SIN ? ts[j] : tc[j];
                der[o] = f.kind == PDE_SIN ? w * tc[j] : -w * ts[j];
            } else
                factor_eval(f, t, &val[o], &der[o]);
            i = nk++ % MEMO_N;
            key[i] = f, at[i] = o;
        }
}

/*
 * The term is Re[(A - iB)(w) exp(alpha (w - shift)) exp(i beta w)], and
 * d^n/dw^n [P(w) e^{zw}] = e^{zw} sum_j C(n,j) z^(n-j) P^(j)(w), z = alpha + i beta; with beta = 0
 * the term is A(w) E, the real parts of the same sums.
 */
double wterm_deriv(const pde_wterm *t, double w, int n)
{
    const double E = t->alpha != 0.0 ? exp(t->alpha * (w - t->shift)) : 1.0;
    double binom = 1.0;
    if (t->beta == 0.0) {
        double sum = 0.0, zp = 1.0;
        for (int j = n; j >= 0; j--) {
            double pj = 0.0;
            for (int k = t->deg; k >= j; k--)
                pj = pj * w + falling(k, j) * t->A[k];
            sum += binom * zp * pj;
            zp *= t->alpha;
            binom = binom * j / (n - j + 1);
        }
        return E * sum;
    }
    double complex z = t->alpha + I * t->beta;
    double complex sum = 0.0, zp = 1.0;
    for (int j = n; j >= 0; j--) {
        /* P^(j)(w): Horner over the j-th derivative's coefficients. */
        double complex pj = 0.0;
        for (int k = t->deg; k >= j; k--)
            pj = pj * w + falling(k, j) * (t->A[k] - I * t->B[k]);
        sum += binom * zp * pj;
        zp *= z;
        binom = binom * j / (n - j + 1);
    }
    return E * (creal(sum) * cos(t->beta * w) - cimag(sum) * sin(t->beta * w));
}

void factor_derivs(pde_factor f, double t, int n, double *d)
{
    double w, s, c, e;
    switch (f.kind) {
    case PDE_POW: {
        int p = (int)f.p;
        for (int k = 0; k <= n; k++)
            d[k] = k > p ? 0.0 : falling(p, k) * ipow(t, p - k);
        return;
    }
    case PDE_SIN:
    case PDE_COS: {
        w = f.p * M_PI;
        s = sin(w * t), c = cos(w * t);
        /* sin: s, wc, -w^2 s, -w^3 c, ...; cos: c, -ws, -w^2 c, w^3 s, ... */
        const double cyc[4] = { s, c, -s, -c };
        double wk = 1.0;
        for (int k = 0; k <= n; k++, wk *= w)
            d[k] = wk * cyc[(k + (f.kind == PDE_COS)) & 3];
        return;
    }
    case PDE_EXP:
        e = exp(f.p * t);
        for (int k = 0; k <= n; k++, e *= f.p)
            d[k] = e;
        return;
    case PDE_SINH:
    case PDE_COSH: {
        s = sinh(f.p * t), c = cosh(f.p * t);
        double wk = 1.0;
        for (int k = 0; k <= n; k++, wk *= f.p)
            d[k] = wk * (((k & 1) == (f.kind == PDE_SINH)) ? c : s);
        return;
    }
    }
    for (int k = 0; k <= n; k++)
        d[k] = 0.0;
}

/* C(k, j) for k, j <= 7, exact: the binomial sums of the derivatives of P(w) e^{zw}. */
static const double binom7[8][8] = {
    { 1 }, { 1, 1 }, { 1, 2, 1 }, { 1, 3, 3, 1 }, { 1, 4, 6, 4, 1 }, { 1, 5, 10, 10, 5, 1 },
    { 1, 6, 15, 20, 15, 6, 1 }, { 1, 7, 21, 35, 35, 21, 7, 1 },
};

/*
 * P^(j)(w), j = 0..n, of the coefficients c[0..deg] (stride 1) by one Horner pass per j, all passes
 * sharing each coefficient: q[j] = q[j] w + k!/(k-j)! c[k], k from deg down to j.
 */
static void poly_derivs(const double *c, int deg, double w, int n, double *q)
{
    for (int j = 0; j <= n; j++)
        q[j] = 0.0;
    for (int k = deg; k >= 0; k--) {
        double f = 1.0;
        for (int j = 0; j <= n && j <= k; j++) {
            q[j] = q[j] * w + f * c[k];
            f *= k - j;
        }
    }
}

/*
 * The term is Re[(A - iB)(w) e^{alpha (w - shift)} e^{i beta w}] and, with z = alpha + i beta,
 * d^k [P e^{zw}] = e^{zw} sum_(j <= k) C(k,j) z^(k-j) P^(j)(w). With beta = 0 the term is A(w) E
 * and takes real arithmetic (the real parts of the complex sums, the same roundings); with alpha = 0
 * as well its k-th derivative is A^(k). A term of degree 0 (fig. 2 and 4's every term of x and y)
 * is (A - iB) z^k e^{zw}, its powers of z by products in real arithmetic: the Taylor models' inner
 * loop, at 40 % of the general sums' instructions (fig. 4i's properties: 127 k to 75 k).
 */
void mode_h_derivs(const pde_mode *m, double w, int n, double *d)
{
    for (int k = 0; k <= n; k++)
        d[k] = 0.0;
    size_t i0, i1;
    mode_slab(m, w, &i0, &i1);
    for (size_t i = i0; i < i1; i++) {
        const pde_wterm *t = &m->terms[i];
        if (t->deg == 0) {   /* constant A and B (fig. 2 and 4): (A - iB) z^k, z^k by products */
            const double E = t->alpha != 0.0 ? exp(t->alpha * (w - t->shift)) : 1.0;
            if (t->beta == 0.0) {   /* E A alpha^k (0 beyond k = 0 where alpha = 0) */
                double p = E * t->A[0];
                for (int k = 0; k <= n; k++, p *= t->alpha)
                    d[k] += p;
                continue;
            }
            const double c = E * cos(t->beta * w), s = E * sin(t->beta * w);
            double pr = t->A[0], pi = -t->B[0];
            for (int k = 0; k <= n; k++) {
                d[k] += c * pr - s * pi;
                const double r = pr * t->alpha - pi * t->beta;
                pi = pr * t->beta + pi * t->alpha, pr = r;
            }
            continue;
        }
        double a[8], b[8];   /* A^(j)(w), B^(j)(w), j <= n */
        poly_derivs(t->A, t->deg, w, n, a);
        if (t->alpha == 0.0 && t->beta == 0.0) {
            for (int k = 0; k <= n; k++)
                d[k] += a[k];
            continue;
        }
        const double E = t->alpha != 0.0 ? exp(t->alpha * (w - t->shift)) : 1.0;
        if (t->beta == 0.0) {
            double zp[8] = { 1.0 };
            for (int k = 1; k <= n; k++)
                zp[k] = zp[k - 1] * t->alpha;
            for (int k = 0; k <= n; k++) {
                double sum = 0.0;
                for (int j = k < t->deg ? k : t->deg; j >= 0; j--)   /* a[j > deg] = 0 */
                    sum += binom7[k][j] * zp[k - j] * a[j];
                d[k] += E * sum;
            }
            continue;
        }
        poly_derivs(t->B, t->deg, w, n, b);
        const double complex z = t->alpha + I * t->beta;
        double complex zp[8] = { 1.0 };
        for (int k = 1; k <= n; k++)
            zp[k] = zp[k - 1] * z;
        const double c = cos(t->beta * w), s = sin(t->beta * w);
        for (int k = 0; k <= n; k++) {
            double complex sum = 0.0;
            for (int j = k < t->deg ? k : t->deg; j >= 0; j--)
                sum += binom7[k][j] * zp[k - j] * (a[j] - I * b[j]);
            d[k] += (E * c) * creal(sum) - (E * s) * cimag(sum);
        }
    }
}

/* max |sin| and max |cos| over [a, b]: 1 where the interval holds a peak, else the larger end */
static void maxabs_sincos(double a, double b, double *ms, double *mc)
{
    if (b - a >= M_PI) {
        *ms = *mc = 1.0;
        return;
    }
    const int speak = M_PI_2 + ceil((a - M_PI_2) / M_PI) * M_PI <= b, cpeak = ceil(a / M_PI) * M_PI <= b;
    if (speak && cpeak) {
        *ms = *mc = 1.0;
        return;
    }
    const double sa = sin(a), ca = cos(a), sb = sin(b), cb = cos(b);
    *ms = speak ? 1.0 : fmax(fabs(sa), fabs(sb));
    *mc = cpeak ? 1.0 : fmax(fabs(ca), fabs(cb));
}

void factor_bounds(pde_factor f, double t0, double t1, int n, double *d)
{
    const double T = fmax(fabs(t0), fabs(t1));
    switch (f.kind) {
    case PDE_POW: {
        int p = (int)f.p;
        for (int k = 0; k <= n; k++)
            d[k] = k > p ? 0.0 : falling(p, k) * ipow(T, p - k);
        return;
    }
    case PDE_SIN:
    case PDE_COS: {
        /* |sin| at even phases (k + cos), |cos| at odd ones: two maxima for all orders */
        double w = fabs(f.p) * M_PI, wk = 1.0, mx[2];
        maxabs_sincos(w * t0, w * t1, &mx[0], &mx[1]);
        for (int k = 0; k <= n; k++, wk *= w)
            d[k] = wk * mx[(k + (f.kind == PDE_COS)) & 1];
        return;
    }
    case PDE_EXP: {
        double e = exp(f.p * (f.p >= 0 ? t1 : t0)), a = fabs(f.p);
        for (int k = 0; k <= n; k++, e *= a)
            d[k] = e;
        return;
    }
    case PDE_SINH:
    case PDE_COSH: {
        double a = fabs(f.p), s = sinh(a * T), c = cosh(a * T), wk = 1.0;
        for (int k = 0; k <= n; k++, wk *= a)
            d[k] = wk * (((k & 1) == (f.kind == PDE_SINH)) ? c : s);
        return;
    }
    }
    for (int k = 0; k <= n; k++)
        d[k] = 0.0;
}

/* |x + iy|, without hypot where one part is 0 (the same value). */
static double cabs2(double x, double y)
{
    return y == 0.0 ? fabs(x) : x == 0.0 ? fabs(y) : hypot(x, y);
}

/*
 * Bounds over [w0, w1] of the terms i0 .. i1 - 1: |(A - iB)^(j)| <= the same polynomial's derivative
 * with coefficients |A_k - iB_k| at W = max |w| (|A_k| alone where beta = 0, which makes the term
 * A(w) E), and |z| for z, in mode_h_derivs' sums.
 */
static void terms_bounds(const pde_mode *m, size_t i0, size_t i1, double w0, double w1, int n, double *d)
{
    const double W = fmax(fabs(w0), fabs(w1));
    for (int k = 0; k <= n; k++)
        d[k] = 0.0;
    for (size_t i = i0; i < i1; i++) {
        const pde_wterm *t = &m->terms[i];
        double q[8];   /* bounds of |(A - iB)^(j)| over the interval, Horner passes as in poly_derivs */
        for (int j = 0; j <= n; j++)
            q[j] = 0.0;
        for (int k = t->deg; k >= 0; k--) {
            const double c = t->beta == 0.0 ? fabs(t->A[k]) : cabs2(t->A[k], t->B[k]);
            double f = 1.0;
            for (int j = 0; j <= n && j <= k; j++) {
                q[j] = q[j] * W + f * c;
                f *= k - j;
            }
        }
        if (t->alpha == 0.0 && t->beta == 0.0) {
            for (int k = 0; k <= n; k++)
                d[k] += q[k];
            continue;
        }
        const double az = cabs2(t->alpha, t->beta);
        const double E = exp(t->alpha * ((t->alpha >= 0 ? w1 : w0) - t->shift));
        double zp[8] = { 1.0 };
        for (int k = 1; k <= n; k++)
            zp[k] = zp[k - 1] * az;
        for (int k = 0; k <= n; k++) {
            double sum = 0.0;
            for (int j = k < t->deg ? k : t->deg; j >= 0; j--)   /* q[j > deg] = 0 */
                sum += binom7[k][j] * zp[k - j] * q[j];
            d[k] += E * sum;
        }
    }
}

void mode_h_bounds(const pde_mode *m, double w0, double w1, int n, double *d)
{
    if (m->nslabs <= 1) {
        terms_bounds(m, 0, m->nterms, w0, w1, n, d);
        return;
    }
    /* The max over the slabs that [w0, w1] meets, each bounded over its part (the first slab
     * reaches down to -inf, the last up to +inf). */
    for (int k = 0; k <= n; k++)
        d[k] = 0.0;
    for (size_t s = 0; s < m->nslabs; s++) {
        double lo = s == 0 ? -INFINITY : m->breaks[s], hi = s + 1 == m->nslabs ? INFINITY : m->breaks[s + 1];
        double a = fmax(w0, lo), b = fmin(w1, hi);
        if (a > b)
            continue;
        double ds[8];
        terms_bounds(m, m->first[s], m->first[s + 1], a, b, n, ds);
        for (int k = 0; k <= n; k++)
            d[k] = fmax(d[k], ds[k]);
    }
}
