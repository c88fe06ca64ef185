/*
 * ep.c: exponential polynomials and the ODE h'''' - e h = q(w).
 *
 * DESIGN
 * The paper writes the homogeneous solution as c1 e^{tw} + c2 e^{-tw} +
 * c3 cos tw + c4 sin tw (eq. 15) and treats e > 0 and e = 0 only. Here every
 * case is one mechanism: the roots r of r^4 = e are simple when e != 0, so
 * for |e| > 1 the basis is exp(r (w - shift)) with the growing exponentials
 * scaled; for |e| <= 1 the roots crowd towards 0, the exponential basis
 * degenerates, and power series (which converge in a few terms there) take
 * over. Forces are exponential polynomials too, so a particular solution is
 * found term by term by undetermined coefficients, with the secular w factor
 * when a term's exponent is a root (resonance).
 */
#include <math.h>
#include <string.h>

#include "ep.h"

#define SMALL_E   1.0    /* |e| at or below: power-series regime */
#define EXPAND_Z  2.0    /* in that regime, |z| at or below: expand exp(z w) */
#define NEAR_ROOT 0.5    /* |z - r| at or below: shift onto the root r */
#define SERIES_TOL 1e-19
#define MAX_SERIES 512   /* degree cap of a series; never reached for |e| <= 1 */

/* |re| + |im|: within a factor sqrt(2) of |z|, without hypot, for sizes that are only compared. */
static double cabs1(cplx z)
{
    return fabs(creal(z)) + fabs(cimag(z));
}

int ep_shift(cplx z)
{
    return creal(z) > 0.0;
}

static cplx *poly_new(arena *s, int deg)
{
    return arena_alloc(s, (size_t)(deg + 1) * sizeof(cplx));
}

pde_status ep_add(arena *s, ep *dst, cplx z, int shift, const cplx *p, int deg, cplx scale)
{
    while (deg > 0 && p[deg] == 0.0)
        deg--;
    if (scale == 0.0 || (deg == 0 && p[0] == 0.0))
        return PDE_OK;
    for (size_t i = 0; i < dst->n; i++) {
        ep_term *t = &dst->t[i];
        if (t->z != z || t->shift != shift)
            continue;
        if (deg > t->deg) {
            cplx *np = poly_new(s, deg);
            if (!np)
                return PDE_ERR_NOMEM;
            memcpy(np, t->p, (size_t)(t->deg + 1) * sizeof(cplx));
            t->p = np;
            t->deg = deg;
        }
        for (int k = 0; k <= deg; k++)
            t->p[k] += scale * p[k];
        return PDE_OK;
    }
    if (dst->n == dst->cap) {
        size_t cap = dst->cap ? 2 * dst->cap : 4;
        ep_term *nt = arena_alloc(s, cap * sizeof *nt);
        if (!nt)
            return PDE_ERR_NOMEM;
        if (dst->n)
            memcpy(nt, dst->t, dst->n * sizeof *nt);
        dst->t = nt;
        dst->cap = cap;
    }
    cplx *np = poly_new(s, deg);
    if (!np)
        return PDE_ERR_NOMEM;
    for (int k = 0; k <= deg; k++)
        np[k] = scale * p[k];
    dst->t[dst->n++] = (ep_term){ z, shift, deg, np };
    return PDE_OK;
}

pde_status ep_add_ep(arena *s, ep *dst, const ep *src, cplx scale)
{
    for (size_t i = 0; i < src->n; i++) {
        const ep_term *t = &src->t[i];
        pde_status st = ep_add(s, dst, t->z, t->shift, t->p, t->deg, scale);
        if (st != PDE_OK)
            return st;
    }
    return PDE_OK;
}

void ep_boundary(const ep *h, cplx out[4])
{
    out[0] = out[1] = out[2] = out[3] = 0.0;
    for (size_t i = 0; i < h->n; i++) {
        const ep_term *t = &h->t[i];
        cplx p1 = 0.0, dp1 = 0.0;
        for (int k = t->deg; k >= 0; k--) {
            p1 += t->p[k];
            dp1 += (double)k * t->p[k];
        }
        cplx p0 = t->p[0], dp0 = t->deg > 0 ? t->p[1] : 0.0;
        /* exp(z (w - shift)) is 1 at w = shift and exp(-+z) at the other end. */
        cplx E0 = t->shift ? cexp(-t->z) : 1.0;
        cplx E1 = t->shift ? 1.0 : cexp(t->z);
        out[0] += p0 * E0;
        out[1] += (dp0 + t->z * p0) * E0;
        out[2] += p1 * E1;
        out[3] += (dp1 + t->z * p1) * E1;
    }
}

/* n (n-1) ... (n-k+1) */
static double falling(int n, int k)
{
    double r = 1.0;
    for (int i = 0; i < k; i++)
        r *= n - i;
    return r;
}

/*
 * Q with (D^4 - e)[Q e^{zw}] = P e^{zw}. With L(r) = r^4 - e, the left side is
 * e^{zw} sum_j L^(j)(z)/j! Q^(j). At a root (res = 1) L(z) = 0 and Q = w R:
 * the secular form. Back substitution from the top degree down.
 */
static cplx *undetermined(arena *s, double e, cplx z, int res, const cplx *p, int deg)
{
    cplx l[5] = { res ? 0.0 : z * z * z * z - e, 4.0 * z * z * z, 6.0 * z * z, 4.0 * z, 1.0 };
    int qd = deg + res;
    cplx *q = poly_new(s, qd);
    if (!q)
        return NULL;
    for (int m = deg; m >= 0; m--) {
        cplx acc = p[m];
        for (int j = res + 1; j <= 4 && m + j <= qd; j++)
            acc -= l[j] * q[m + j] * falling(m + j, j);
        q[m + res] = acc / (l[res] * falling(m + res, res));
    }
    return q;
}

/*
 * Power series h = sum h_n w^n of h'''' - e h = q with h_j = init[j] for
 * j < 4: h_{n+4} = (q_n + e h_n) n!/(n+4)!. For |e| <= 1 the tail shrinks
 * factorially once q is used up; stop when four coefficients in a row are
 * negligible. Returns the degree, or -1 when out of memory.
 */
static int series(arena *s, double e, const cplx *q, int qdeg, const cplx init[4], cplx **out)
{
    int cap = qdeg + 36;     /* |e| <= 1: 1/(4n)! < 1e-19 by n = 6, so 28 more terms suffice */
    if (cap > MAX_SERIES)
        cap = MAX_SERIES;
    cplx *h = poly_new(s, cap);
    if (!h)
        return -1;
    double size = 0.0;
    for (int j = 0; j < 4; j++) {
        h[j] = init[j];
        size += cabs1(h[j]);
    }
    int deg = 3;
    for (int n = 0; n + 4 <= cap; n++) {
        cplx qn = n <= qdeg ? q[n] : 0.0;
        h[n + 4] = (qn + e * h[n]) / falling(n + 4, 4);
        size += cabs1(h[n + 4]);
        deg = n + 4;
        if (n >= qdeg) {
            double tail = 0.0;
            for (int j = 1; j <= 4; j++)
                tail += cabs1(h[n + j]);
            if (tail <= SERIES_TOL * size)
                break;
        }
    }
    while (deg > 0 && h[deg] == 0.0)
        deg--;
    *out = h;
    return deg;
}

/* exp(c w) as a Taylor polynomial accurate to rounding on [0,1]; |c| is small. */
static int exp_taylor(arena *s, cplx c, cplx **out)
{
    int deg = 0;
    double term = 1.0;
    while (deg < 60 && term > 1e-18) {
        deg++;
        term *= cabs(c) / deg;
    }
    cplx *p = poly_new(s, deg);
    if (!p)
        return -1;
    p[0] = 1.0;
    for (int k = 1; k <= deg; k++)
        p[k] = p[k - 1] * c / k;
    *out = p;
    return deg;
}

/* a * b into a new polynomial. */
static cplx *poly_mul(arena *s, const cplx *a, int da, const cplx *b, int db)
{
    cplx *r = poly_new(s, da + db);
    if (!r)
        return NULL;
    for (int i = 0; i <= da; i++)
        for (int j = 0; j <= db; j++)
            r[i + j] += a[i] * b[j];
    return r;
}

static void roots(double e, cplx r[4])
{
    if (e > 0.0) {
        double t = pow(e, 0.25);
        r[0] = t;
        r[1] = -t;
        r[2] = I * t;
        r[3] = -I * t;
    } else {
        /* r^4 = -|e|: r = beta (+-1 +- i), beta = (|e|/4)^(1/4). */
        double b = pow(-e / 4.0, 0.25);
        r[0] = b + I * b;
        r[1] = b - I * b;
        r[2] = -b + I * b;
        r[3] = -b - I * b;
    }
}

pde_status ep_particular(arena *s, double e, const ep *q, ep *out)
{
    int small = fabs(e) <= SMALL_E;
    cplx r[4];
    if (!small)
        roots(e, r);
    cplx *poly = NULL;      /* small regime: the expanded part of q */
    int pdeg = -1;
    for (size_t i = 0; i < q->n; i++) {
        const ep_term *t = &q->t[i];
        if (small && cabs(t->z) <= EXPAND_Z) {
            /* P(w) e^{z(w - shift)} = e^{-z shift} P(w) exp(z w), expanded. */
            cplx *ex;
            int dx = exp_taylor(s, t->z, &ex);
            if (dx < 0)
                return PDE_ERR_NOMEM;
            cplx *pr = poly_mul(s, t->p, t->deg, ex, dx);
            if (!pr)
                return PDE_ERR_NOMEM;
            cplx k = t->shift ? cexp(-t->z) : 1.0;
            int nd = t->deg + dx > pdeg ? t->deg + dx : pdeg;
            cplx *np = poly_new(s, nd);
            if (!np)
                return PDE_ERR_NOMEM;
            for (int j = 0; j <= pdeg; j++)
                np[j] = poly[j];
            for (int j = 0; j <= t->deg + dx; j++)
                np[j] += k * pr[j];
            poly = np;
            pdeg = nd;
            continue;
        }
        cplx z = t->z;
        int shift = t->shift, res = 0, deg = t->deg;
        const cplx *p = t->p;
        if (!small) {
            int best = 0;
            double dmin = INFINITY;
            for (int j = 0; j < 4; j++) {
                cplx dz = z - r[j];
                double d2 = creal(dz) * creal(dz) + cimag(dz) * cimag(dz);
                if (d2 < dmin)
                    dmin = d2, best = j;
            }
            cplx d = z - r[best];
            if (cabs(d) <= NEAR_ROOT) {
                /* e^{z(w-sz)} = e^{r(w-sr)} e^{r sr - z sz} e^{d w}: resonance on r. */
                int sr = ep_shift(r[best]);
                cplx k = cexp(r[best] * (double)sr - z * (double)shift);
                cplx *pk = (cplx *)p;
                if (d != 0.0) {
                    cplx *ex;
                    int dx = exp_taylor(s, d, &ex);
                    if (dx < 0)
                        return PDE_ERR_NOMEM;
                    pk = poly_mul(s, p, deg, ex, dx);
                    if (!pk)
                        return PDE_ERR_NOMEM;
                    deg += dx;
                }
                if (k != 1.0) {
                    cplx *pc = poly_new(s, deg);
                    if (!pc)
                        return PDE_ERR_NOMEM;
                    for (int j = 0; j <= deg; j++)
                        pc[j] = k * pk[j];
                    pk = pc;
                }
                p = pk;
                z = r[best];
                shift = sr;
                res = 1;
            }
        }
        cplx *sol = undetermined(s, e, z, res, p, deg);
        if (!sol)
            return PDE_ERR_NOMEM;
        pde_status st = ep_add(s, out, z, shift, sol, deg + res, 1.0);
        if (st != PDE_OK)
            return st;
    }
    if (pdeg >= 0) {
        static const cplx zero[4] = { 0 };
        cplx *h;
        int hd = series(s, e, poly, pdeg, zero, &h);
        if (hd < 0)
            return PDE_ERR_NOMEM;
        return ep_add(s, out, 0.0, 0, h, hd, 1.0);
    }
    return PDE_OK;
}

pde_status ep_homogeneous(arena *s, double e, ep basis[4], double *deriv_scale)
{
    memset(basis, 0, 4 * sizeof *basis);
    if (fabs(e) <= SMALL_E) {
        static const double fact[4] = { 1.0, 1.0, 2.0, 6.0 };
        for (int j = 0; j < 4; j++) {
            cplx init[4] = { 0 };
            init[j] = 1.0 / fact[j];    /* K_j^(j)(0) = 1 */
            cplx *h;
            int hd = series(s, e, NULL, -1, init, &h);
            if (hd < 0)
                return PDE_ERR_NOMEM;
            pde_status st = ep_add(s, &basis[j], 0.0, 0, h, hd, 1.0);
            if (st != PDE_OK)
                return st;
        }
        *deriv_scale = 1.0;
        return PDE_OK;
    }
    cplx r[4];
    roots(e, r);
    static const cplx one = 1.0;
    for (int j = 0; j < 4; j++) {
        pde_status st = ep_add(s, &basis[j], r[j], ep_shift(r[j]), &one, 0, 1.0);
        if (st != PDE_OK)
            return st;
    }
    *deriv_scale = 1.0 / pow(fabs(e), 0.25);
    return PDE_OK;
}
