/*
 * factor.c: the one-variable factors f(t) of boundary and force terms, and
 * the exponential-polynomial w-terms of a solution: values and derivatives of
 * any order.
 */
#include <complex.h>
#include <math.h>

#include "internal.h"

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

/* P(w) and P'(w) by Horner. */
static void horner2(const double *c, int deg, double w, double *p, double *dp)
{
    double v = c[deg], d = 0.0;
    for (int k = deg - 1; k >= 0; k--) {
        d = d * w + v;
        v = v * w + c[k];
    }
    *p = v;
    *dp = d;
}

void mode_h(const pde_mode *m, double w, double *h, double *dh)
{
    double hv = 0.0, hd = 0.0;
    size_t k0, k1;
    mode_slab(m, w, &k0, &k1);
    for (size_t k = k0; k < k1; k++) {
        const pde_wterm *t = &m->terms[k];
        double a, da;
        horner2(t->A, t->deg, w, &a, &da);
        double E = t->alpha != 0.0 ? exp(t->alpha * (w - t->shift)) : 1.0;
        if (t->beta == 0.0) {
            hv += E * a;
            hd += E * (t->alpha * a + da);
        } else {
            double b, db;
            horner2(t->B, t->deg, w, &b, &db);
            double c = cos(t->beta * w), s = sin(t->beta * w);
            double v = a * c + b * s;
            hv += E * v;
            hd += E * (t->alpha * v + da * c + db * s + t->beta * (b * c - a * s));
        }
    }
    *h = hv;
    *dh = hd;
}

/*
 * The term is Re[(A - iB)(w) exp(alpha (w - shift)) exp(i beta w)], and
 * d^n/dw^n [P(w) e^{zw}] = e^{zw} sum_j C(n,j) z^(n-j) P^(j)(w), z = alpha + i beta.
 */
double wterm_deriv(const pde_wterm *t, double w, int n)
{
    double complex z = t->alpha + I * t->beta;
    double complex sum = 0.0, zp = 1.0;
    double binom = 1.0;
    for (int j = n; j >= 0; j--) {
        /* P^(j)(w): Horner over the j-th derivative's coefficients. */
        double complex pj = 0.0;
        for (int k = t->deg; k >= j; k--)
            pj = pj * w + falling(k, j) * (t->A[k] - I * t->B[k]);
        sum += binom * zp * pj;
        zp *= z;
        binom = binom * j / (n - j + 1);
    }
    double E = exp(t->alpha * (w - t->shift));
    return E * creal(sum * cexp(I * t->beta * w));
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

void mode_h_derivs(const pde_mode *m, double w, int n, double *d)
{
    for (int k = 0; k <= n; k++)
        d[k] = 0.0;
    size_t i0, i1;
    mode_slab(m, w, &i0, &i1);
    for (size_t i = i0; i < i1; i++) {
        const pde_wterm *t = &m->terms[i];
        const double complex z = t->alpha + I * t->beta;
        double complex q[8];   /* (A - iB)^(j)(w), j <= n */
        for (int j = 0; j <= n; j++) {
            q[j] = 0.0;
            for (int k = t->deg; k >= j; k--)
                q[j] = q[j] * w + falling(k, j) * (t->A[k] - I * t->B[k]);
        }
        const double complex e = exp(t->alpha * (w - t->shift)) * cexp(I * t->beta * w);
        for (int k = 0; k <= n; k++) {
            double complex sum = 0.0, zp = 1.0;
            double binom = 1.0;
            for (int j = k; j >= 0; j--) {
                sum += binom * zp * q[j];
                zp *= z;
                binom = binom * j / (k - j + 1);
            }
            d[k] += creal(e * sum);
        }
    }
}

/* max |sin| over [a, b] */
static double maxabs_sin(double a, double b)
{
    if (b - a >= M_PI)
        return 1.0;
    double m = ceil((a - M_PI_2) / M_PI);
    if (M_PI_2 + m * M_PI <= b)
        return 1.0;
    return fmax(fabs(sin(a)), fabs(sin(b)));
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
        double w = fabs(f.p) * M_PI, wk = 1.0;
        for (int k = 0; k <= n; k++, wk *= w) {
            double ph = (k + (f.kind == PDE_COS)) * M_PI_2;
            d[k] = wk * maxabs_sin(w * t0 + ph, w * t1 + ph);
        }
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

/* Bounds over [w0, w1] of the terms i0 .. i1 - 1. */
static void terms_bounds(const pde_mode *m, size_t i0, size_t i1, double w0, double w1, int n, double *d)
{
    const double W = fmax(fabs(w0), fabs(w1));
    for (int k = 0; k <= n; k++)
        d[k] = 0.0;
    for (size_t i = i0; i < i1; i++) {
        const pde_wterm *t = &m->terms[i];
        const double az = hypot(t->alpha, t->beta);
        double q[8];   /* bounds of |(A - iB)^(j)| over the interval */
        for (int j = 0; j <= n; j++) {
            q[j] = 0.0;
            for (int k = t->deg; k >= j; k--)
                q[j] = q[j] * W + falling(k, j) * hypot(t->A[k], t->B[k]);
        }
        const double E = exp(t->alpha * ((t->alpha >= 0 ? w1 : w0) - t->shift));
        for (int k = 0; k <= n; k++) {
            double sum = 0.0, zp = 1.0, binom = 1.0;
            for (int j = k; j >= 0; j--) {
                sum += binom * zp * q[j];
                zp *= az;
                binom = binom * j / (k - j + 1);
            }
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
