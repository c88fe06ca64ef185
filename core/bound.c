/*
 * bound.c: derivatives of x, their bounds over boxes, and branch and bound
 * (bound.h).
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bound.h"

/* Partial derivatives of total order <= 5, ordered by order, then by the u order, then the v order. */
enum { MI2 = 10, MI3 = 20, MI4 = 35, MIN = 56 };
static const int mi_count[6] = { 1, 4, 10, 20, 35, 56 };
static const unsigned char mi_u[MIN] = { 0, 1, 0, 0, 2, 1, 1, 0, 0, 0, 3, 2, 2, 1, 1, 1, 0, 0, 0, 0, 4, 3, 3, 2, 2, 2, 1, 1,
                                         1, 1, 0, 0, 0, 0, 0, 5, 4, 4, 3, 3, 3, 2, 2, 2, 2, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0 };
static const unsigned char mi_v[MIN] = { 0, 0, 1, 0, 0, 1, 0, 2, 1, 0, 0, 1, 0, 2, 1, 0, 3, 2, 1, 0, 0, 1, 0, 2, 1, 0, 3, 2,
                                         1, 0, 4, 3, 2, 1, 0, 0, 1, 0, 2, 1, 0, 3, 2, 1, 0, 4, 3, 2, 1, 0, 5, 4, 3, 2, 1, 0 };
static const unsigned char mi_w[MIN] = { 0, 0, 0, 1, 0, 0, 1, 0, 1, 2, 0, 0, 1, 0, 1, 2, 0, 1, 2, 3, 0, 0, 1, 0, 1, 2, 0, 1,
                                         2, 3, 0, 1, 2, 3, 4, 0, 0, 1, 0, 1, 2, 0, 1, 2, 3, 0, 1, 2, 3, 4, 0, 1, 2, 3, 4, 5 };

static int mi(const int n[3])
{
    static const int base[6] = { 0, 1, 4, 10, 20, 35 };
    int o = n[0] + n[1] + n[2];
    return base[o] + (o - n[0]) * (o - n[0] + 1) / 2 + (o - n[0] - n[1]);
}

typedef struct {
    double d[3][MIN];
} xjet;

/*
 * A branch and bound's memo of every mode's factor derivatives (at a point) or their bounds (over
 * an interval) along each axis: a box's two halves share its intervals and centres along the two
 * axes not split, so most of a box's factors were evaluated for its parent (core/bound.c's
 * bb_minimise). Direct-mapped by the interval; only for solutions of at most JC_MODES modes. Slots:
 * a power of 2 up to JC_N, as many as JC_BYTES hold (a loft's face meets more s-intervals than 256
 * slots held: the tower's extremes took 12% more instructions), at least JC_N_MIN.
 */
enum { JC_N = 1024, JC_N_MIN = 256, JC_MODES = 256, JC_D = 6 };   /* derivatives 0..5 */
#define JC_BYTES (16u << 20)   /* 1024 slots for 99 modes (tower), 512 for 129 (blade); 9.4 MB for 256 modes */

typedef struct {
    double lo, hi;
    int order, bound;   /* order -1: empty */
} jc_key;

/*
 * The jet's indices q < n whose u and v orders are at most du and dv: a factor t^p has no derivative
 * of order above p, so a mode's products there are 0 (a loft's centre, 1 along u and v, has 6 of 56;
 * its profile, t along u, 36). The lists are built as they are first asked for, once per branch and bound (in its memo; no
 * static state: solutions are bounded from several threads).
 */
typedef struct {
    signed char len[JC_D][JC_D][JC_D];   /* by the jet's order, du, dv; -1: not built yet */
    unsigned char q[JC_D][JC_D][JC_D][MIN];
} jet_lists;

static const unsigned char *jet_list(jet_lists *L, int order, int du, int dv, int *len)
{
    if (L->len[order][du][dv] < 0) {
        int k = 0;
        for (int q = 0; q < mi_count[order]; q++)
            if (mi_u[q] <= du && mi_v[q] <= dv)
                L->q[order][du][dv][k++] = (unsigned char)q;
        L->len[order][du][dv] = (signed char)k;
    }
    *len = L->len[order][du][dv];
    return L->q[order][du][dv];
}

enum { JG_MAX = 4 };   /* jet_grouped's groups a component */

typedef struct jet_cache {
    size_t mt, nslot;
    int shift;  /* the hash's top bits, log2 nslot, pick the slot */
    int only;   /* the one component a coordinate's branch and bound needs, or -1: all three */
    /* jet_grouped's groups along u and v: a mode's group, the first mode of each (whose factor's
     * derivatives stand for the group's), and their count a component, JG_MAX + 1 where more */
    unsigned char grp[2][JC_MODES], first[2][3][JG_MAX], ngrp[2][3];
    jet_lists lists;
    jc_key key[3][JC_N];
    double val[];   /* axis a, slot i: val + (a * nslot + i) * JC_D mt */
} jet_cache;

/* The memo's slots an axis for mt modes (into *bits, their log2), 0 where it has none. */
static size_t jc_slots(size_t mt, int *bits)
{
    size_t nslot = JC_N;
    *bits = 10;   /* log2 JC_N */
    if (mt > JC_MODES)
        return 0;
    while (nslot > JC_N_MIN && 3 * nslot * JC_D * mt * sizeof(double) > JC_BYTES)
        nslot /= 2, (*bits)--;
    return nslot;
}

size_t pde_properties_memo_bytes(const pde_solution *s)
{
    const size_t mt = s->comp[0].nmodes + s->comp[1].nmodes + s->comp[2].nmodes;
    int bits;
    const size_t nslot = jc_slots(mt, &bits);
    return nslot ? sizeof(jet_cache) + 3 * nslot * JC_D * mt * sizeof(double) : 0;
}

static jet_cache *jet_cache_new(const pde_solution *s, int what)
{
    size_t mt = s->comp[0].nmodes + s->comp[1].nmodes + s->comp[2].nmodes;
    int bits;
    const size_t nslot = jc_slots(mt, &bits);
    if (!nslot)
        return NULL;
    jet_cache *jc = malloc(sizeof *jc + 3 * nslot * JC_D * mt * sizeof *jc->val);
    if (!jc)
        return NULL;   /* no memo: slower, not wrong */
    jc->mt = mt;
    jc->nslot = nslot;
    jc->shift = 64 - bits;
    jc->only = what < 3 ? what : -1;
    /* Modes of one component with the same factor along an axis (kind and rate) have the same
     * derivatives there: a loft's t^n profile modes and its centre's 1. */
    for (int a = 0; a < 2; a++)
        for (size_t c = 0, o = 0; c < 3; c++) {
            int ng = 0;
            for (size_t m = 0; m < s->comp[c].nmodes; m++, o++) {
                const pde_factor f = a ? s->comp[c].modes[m].v : s->comp[c].modes[m].u;
                int g = 0;
                while (g < ng && g < JG_MAX) {
                    const pde_mode *r = &s->comp[c].modes[jc->first[a][c][g]];
                    const pde_factor e = a ? r->v : r->u;
                    if (e.kind == f.kind && e.p == f.p)
                        break;
                    g++;
                }
                if (g == ng && ng <= JG_MAX) {
                    if (ng < JG_MAX)
                        jc->first[a][c][ng] = (unsigned char)m;
                    ng++;
                }
                jc->grp[a][o] = (unsigned char)(g < JG_MAX ? g : 0);
            }
            jc->ngrp[a][c] = (unsigned char)ng;
        }
    memset(jc->lists.len, -1, sizeof jc->lists.len);
    for (int a = 0; a < 3; a++)
        for (size_t i = 0; i < nslot; i++)
            jc->key[a][i].order = -1;
    return jc;
}

/*
 * Bounds of |h^(k)| over [w0, w1], k = 0..n: mode_h_bounds, which bounds each term about w = 0,
 * except where h is a polynomial (every term's alpha and beta 0, one slab: fig. 1): from its
 * Taylor coefficients b_j at the interval's centre c, |h^(k)| <= sum_(j >= k) j!/(j - k)! |b_j|
 * r^(j - k), which tightens as the interval shrinks (about 0, h = 3 w^2 - 2 w^3 is bounded by 5 on
 * [0.9, 1], at the centre by 1.0003).
 */
enum { H_POLY_DEG = 40 };

static void h_bounds(const pde_mode *m, double w0, double w1, int n, double *d)
{
    int deg = 0;
    for (size_t i = 0; i < m->nterms; i++) {
        const pde_wterm *t = &m->terms[i];
        if (m->nslabs > 1 || t->alpha != 0.0 || t->beta != 0.0 || t->deg > H_POLY_DEG) {
            mode_h_bounds(m, w0, w1, n, d);
            return;
        }
        deg = t->deg > deg ? t->deg : deg;
    }
    double b[H_POLY_DEG + 1] = { 0 };
    for (size_t i = 0; i < m->nterms; i++)
        for (int k = 0; k <= m->terms[i].deg; k++)
            b[k] += m->terms[i].A[k];
    const double c = 0.5 * (w0 + w1), r = 0.5 * (w1 - w0);
    for (int i = 0; i < deg; i++)   /* Taylor shift to c: b[j] = h^(j)(c) / j! */
        for (int k = deg - 1; k >= i; k--)
            b[k] += c * b[k + 1];
    for (int k = 0; k <= n; k++) {
        double sum = 0.0;
        for (int j = deg; j >= k; j--) {   /* Horner in r over the falling factorials */
            double f = 1.0;
            for (int i = 0; i < k; i++)
                f *= j - i;
            sum = sum * r + f * fabs(b[j]);
        }
        d[k] = sum;
    }
}

/* Every mode's factor of axis a, derivatives 0..order at lo (bound 0) or their bounds over [lo, hi],
 * JC_D per mode, modes of the components in order; from the memo when it holds them. */
static const double *axis_factors(const pde_solution *s, jet_cache *jc, int a, double lo, double hi, int order,
                                  int bound)
{
    uint64_t kl, kh;
    memcpy(&kl, &lo, sizeof kl);
    memcpy(&kh, &hi, sizeof kh);
    const uint64_t hsh = (kl * 0x9E3779B97F4A7C15u) ^ (kh * 0xC2B2AE3D27D4EB4Fu) ^ (uint64_t)(order * 2 + bound);
    const size_t slot = (size_t)(hsh >> jc->shift);
    jc_key *k = &jc->key[a][slot];
    double *out = jc->val + ((size_t)a * jc->nslot + slot) * JC_D * jc->mt;
    if (k->order == order && k->bound == bound && k->lo == lo && k->hi == hi)
        return out;
    *k = (jc_key){ lo, hi, order, bound };
    size_t o = 0;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++, o++) {
            if (jc->only >= 0 && c != jc->only)
                continue;   /* never read */
            const pde_mode *md = &s->comp[c].modes[m];
            double *d = out + JC_D * o;
            if (a == 2)
                bound ? h_bounds(md, lo, hi, order, d) : mode_h_derivs(md, lo, order, d);
            else
                bound ? factor_bounds(a ? md->v : md->u, lo, hi, order, d)
                      : factor_derivs(a ? md->v : md->u, lo, order, d);
        }
    return out;
}

/* The highest order of f's derivatives that may not vanish, at most order. */
static int factor_top(pde_factor f, int order)
{
    return f.kind == PDE_POW && f.p >= 0.0 && f.p == floor(f.p) && f.p < order ? (int)f.p : order;
}

/* Adds one mode's products of factors fu, fv, h (derivatives or bounds) to component c of j, over the
 * indices qs (the others' products are 0). */
static void jet_add(xjet *j, int c, const unsigned char *qs, int len, const double *fu, const double *fv,
                    const double *h)
{
    for (int i = 0; i < len; i++) {
        const int q = qs[i];
        /* A factor that is exactly 0 makes the term 0, even beside an overflowed bound. */
        double p = fu[mi_u[q]], r = fv[mi_v[q]], e = h[mi_w[q]];
        j->d[c][q] += (p == 0.0 || r == 0.0 || e == 0.0) ? 0.0 : p * r * e;
    }
}

/*
 * Component c's jet where the box is flat along axis f, u or v (a loft's face t = 1, or a segment):
 * modes with the same factor along f fall in a group (jet_cache's grp), and x's partial at orders
 * (i_f, i_p, i_q) is sum over groups of f's i_f-th derivative times the sum over the group's modes of
 * the p- and q-factors' product. That sum is a dense outer product a mode, which the compiler
 * vectorises, where jet_add gathers each index's three factors: a loft's 99 modes fall in two groups
 * (its centre and its profile, t^n), and a face's jets cost a quarter. Returns 0 (j's component
 * unset) where the modes make more than JG_MAX groups, or a product is NaN (0 times an overflowed
 * bound, which jet_add counts as 0): then jet_add's way.
 */
static inline __attribute__((always_inline)) void outer_add(double acc[][JC_D], const double *fp, const double *fq,
                                                            int d)
{
    for (int i = 0; i < d; i++)
        for (int k = 0; k < d; k++)
            acc[i][k] += fp[i] * fq[k];
}

static int jet_grouped(const pde_solution *s, const jet_cache *jc, int c, size_t o, int f, int order,
                       const double *const F[3], xjet *j)
{
    static const unsigned char *const mia[3] = { mi_u, mi_v, mi_w };
    const int ng = jc->ngrp[f][c];
    if (ng > JG_MAX)
        return 0;
    const int p = f == 0 ? 1 : 0, q = 2, d = order + 1;
    double acc[JG_MAX][JC_D][JC_D];
    memset(acc, 0, sizeof acc);
    const size_t o0 = o, nm = s->comp[c].nmodes;
    /* constant sizes, so that each loop unrolls and vectorises */
    for (size_t m = 0; m < nm; m++, o++) {
        const double *fp = F[p] + JC_D * o, *fq = F[q] + JC_D * o;
        double(*a)[JC_D] = acc[jc->grp[f][o]];
        if (d == 5)
            outer_add(a, fp, fq, 5);
        else if (d == 6)
            outer_add(a, fp, fq, 6);
        else
            outer_add(a, fp, fq, d);
    }
    for (int g = 0; g < ng; g++)
        for (int i = 0; i < d; i++)
            for (int k = 0; k + i < d; k++)
                if (acc[g][i][k] != acc[g][i][k])
                    return 0;
    for (int r = 0; r < mi_count[order]; r++) {
        double t = 0.0;
        for (int g = 0; g < ng; g++) {
            const double e = F[f][JC_D * (o0 + jc->first[f][c][g]) + mia[f][r]];
            t += e == 0.0 ? 0.0 : e * acc[g][mia[p][r]][mia[q][r]];
        }
        j->d[c][r] = t;
    }
    return 1;
}

/* bound = 0: x's partials up to order at the point b->lo; 1: bounds of their magnitudes over b; 2:
 * the same from the sums of the magnitudes of h's terms (mode_h_bounds), the scale of their rounding.
 * jc: a branch and bound's memo, or NULL. only: the one component wanted (the others are left
 * unset), or -1. flat: an axis along which the box (not only the point) is flat, or -1 (jet_grouped). */
static void xjet_fill(const pde_solution *s, const pbox *b, int order, int bound, int only, jet_cache *jc, int flat,
                      xjet *j)
{
    const int n = mi_count[order];
    /* without a memo (a single model: obj_magnitude), every index: no lists to build */
    static const unsigned char every[MIN] = { 0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 13,
                                              14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27,
                                              28, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40, 41,
                                              42, 43, 44, 45, 46, 47, 48, 49, 50, 51, 52, 53, 54, 55 };
    const double *F[3] = { NULL, NULL, NULL };
    if (jc)
        for (int a = 0; a < 3; a++)
            F[a] = axis_factors(s, jc, a, b->lo[a], bound ? b->hi[a] : b->lo[a], order, bound);
    size_t o = 0;
    for (int c = 0; c < 3; c++) {
        const comp_solution *cs = &s->comp[c];
        if (only >= 0 && c != only) {
            o += cs->nmodes;
            continue;
        }
        if (jc && flat >= 0 && jet_grouped(s, jc, c, o, flat, order, F, j)) {
            o += cs->nmodes;
            continue;
        }
        for (int q = 0; q < n; q++)
            j->d[c][q] = 0.0;
        for (size_t m = 0; m < cs->nmodes; m++, o++) {
            const pde_mode *md = &cs->modes[m];
            int len = n;
            const unsigned char *qs =
                jc ? jet_list(&jc->lists, order, factor_top(md->u, order), factor_top(md->v, order), &len) : every;
            if (jc) {
                jet_add(j, c, qs, len, F[0] + JC_D * o, F[1] + JC_D * o, F[2] + JC_D * o);
                continue;
            }
            double fu[JC_D], fv[JC_D], h[JC_D];
            if (bound) {
                factor_bounds(md->u, b->lo[0], b->hi[0], order, fu);
                factor_bounds(md->v, b->lo[1], b->hi[1], order, fv);
                (bound == 2 ? mode_h_bounds : h_bounds)(md, b->lo[2], b->hi[2], order, h);
            } else {
                factor_derivs(md->u, b->lo[0], order, fu);
                factor_derivs(md->v, b->lo[1], order, fv);
                mode_h_derivs(md, b->lo[2], order, h);
            }
            jet_add(j, c, qs, len, fu, fv, h);
        }
    }
}

/*
 * Truncated Taylor series in (u, v, w) up to order 4, coefficients t[a] = d^a f / a! indexed like
 * the jets: products of series are then plain convolutions. conv lists (c, a, b) with a + b = c,
 * sorted by c, so that the first conv_n[K] entries make the product to order K.
 */
static const unsigned char conv[210][3] = {
    { 0, 0, 0 }, { 1, 0, 1 }, { 1, 1, 0 }, { 2, 0, 2 }, { 2, 2, 0 }, { 3, 0, 3 }, { 3, 3, 0 }, { 4, 0, 4 },
    { 4, 1, 1 }, { 4, 4, 0 }, { 5, 0, 5 }, { 5, 1, 2 }, { 5, 2, 1 }, { 5, 5, 0 }, { 6, 0, 6 }, { 6, 1, 3 },
    { 6, 3, 1 }, { 6, 6, 0 }, { 7, 0, 7 }, { 7, 2, 2 }, { 7, 7, 0 }, { 8, 0, 8 }, { 8, 2, 3 }, { 8, 3, 2 },
    { 8, 8, 0 }, { 9, 0, 9 }, { 9, 3, 3 }, { 9, 9, 0 }, { 10, 0, 10 }, { 10, 1, 4 }, { 10, 4, 1 }, { 10, 10, 0 },
    { 11, 0, 11 }, { 11, 1, 5 }, { 11, 2, 4 }, { 11, 4, 2 }, { 11, 5, 1 }, { 11, 11, 0 }, { 12, 0, 12 }, { 12, 1, 6 },
    { 12, 3, 4 }, { 12, 4, 3 }, { 12, 6, 1 }, { 12, 12, 0 }, { 13, 0, 13 }, { 13, 1, 7 }, { 13, 2, 5 }, { 13, 5, 2 },
    { 13, 7, 1 }, { 13, 13, 0 }, { 14, 0, 14 }, { 14, 1, 8 }, { 14, 2, 6 }, { 14, 3, 5 }, { 14, 5, 3 }, { 14, 6, 2 },
    { 14, 8, 1 }, { 14, 14, 0 }, { 15, 0, 15 }, { 15, 1, 9 }, { 15, 3, 6 }, { 15, 6, 3 }, { 15, 9, 1 }, { 15, 15, 0 },
    { 16, 0, 16 }, { 16, 2, 7 }, { 16, 7, 2 }, { 16, 16, 0 }, { 17, 0, 17 }, { 17, 2, 8 }, { 17, 3, 7 }, { 17, 7, 3 },
    { 17, 8, 2 }, { 17, 17, 0 }, { 18, 0, 18 }, { 18, 2, 9 }, { 18, 3, 8 }, { 18, 8, 3 }, { 18, 9, 2 }, { 18, 18, 0 },
    { 19, 0, 19 }, { 19, 3, 9 }, { 19, 9, 3 }, { 19, 19, 0 }, { 20, 0, 20 }, { 20, 1, 10 }, { 20, 4, 4 }, { 20, 10, 1 },
    { 20, 20, 0 }, { 21, 0, 21 }, { 21, 1, 11 }, { 21, 2, 10 }, { 21, 4, 5 }, { 21, 5, 4 }, { 21, 10, 2 }, { 21, 11, 1 },
    { 21, 21, 0 }, { 22, 0, 22 }, { 22, 1, 12 }, { 22, 3, 10 }, { 22, 4, 6 }, { 22, 6, 4 }, { 22, 10, 3 }, { 22, 12, 1 },
    { 22, 22, 0 }, { 23, 0, 23 }, { 23, 1, 13 }, { 23, 2, 11 }, { 23, 4, 7 }, { 23, 5, 5 }, { 23, 7, 4 }, { 23, 11, 2 },
    { 23, 13, 1 }, { 23, 23, 0 }, { 24, 0, 24 }, { 24, 1, 14 }, { 24, 2, 12 }, { 24, 3, 11 }, { 24, 4, 8 }, { 24, 5, 6 },
    { 24, 6, 5 }, { 24, 8, 4 }, { 24, 11, 3 }, { 24, 12, 2 }, { 24, 14, 1 }, { 24, 24, 0 }, { 25, 0, 25 }, { 25, 1, 15 },
    { 25, 3, 12 }, { 25, 4, 9 }, { 25, 6, 6 }, { 25, 9, 4 }, { 25, 12, 3 }, { 25, 15, 1 }, { 25, 25, 0 }, { 26, 0, 26 },
    { 26, 1, 16 }, { 26, 2, 13 }, { 26, 5, 7 }, { 26, 7, 5 }, { 26, 13, 2 }, { 26, 16, 1 }, { 26, 26, 0 }, { 27, 0, 27 },
    { 27, 1, 17 }, { 27, 2, 14 }, { 27, 3, 13 }, { 27, 5, 8 }, { 27, 6, 7 }, { 27, 7, 6 }, { 27, 8, 5 }, { 27, 13, 3 },
    { 27, 14, 2 }, { 27, 17, 1 }, { 27, 27, 0 }, { 28, 0, 28 }, { 28, 1, 18 }, { 28, 2, 15 }, { 28, 3, 14 }, { 28, 5, 9 },
    { 28, 6, 8 }, { 28, 8, 6 }, { 28, 9, 5 }, { 28, 14, 3 }, { 28, 15, 2 }, { 28, 18, 1 }, { 28, 28, 0 }, { 29, 0, 29 },
    { 29, 1, 19 }, { 29, 3, 15 }, { 29, 6, 9 }, { 29, 9, 6 }, { 29, 15, 3 }, { 29, 19, 1 }, { 29, 29, 0 }, { 30, 0, 30 },
    { 30, 2, 16 }, { 30, 7, 7 }, { 30, 16, 2 }, { 30, 30, 0 }, { 31, 0, 31 }, { 31, 2, 17 }, { 31, 3, 16 }, { 31, 7, 8 },
    { 31, 8, 7 }, { 31, 16, 3 }, { 31, 17, 2 }, { 31, 31, 0 }, { 32, 0, 32 }, { 32, 2, 18 }, { 32, 3, 17 }, { 32, 7, 9 },
    { 32, 8, 8 }, { 32, 9, 7 }, { 32, 17, 3 }, { 32, 18, 2 }, { 32, 32, 0 }, { 33, 0, 33 }, { 33, 2, 19 }, { 33, 3, 18 },
    { 33, 8, 9 }, { 33, 9, 8 }, { 33, 18, 3 }, { 33, 19, 2 }, { 33, 33, 0 }, { 34, 0, 34 }, { 34, 3, 19 }, { 34, 9, 9 },
    { 34, 19, 3 }, { 34, 34, 0 }
};
static const int conv_n[5] = { 1, 7, 28, 84, 210 };

/* For q < MI4: the index of q + e_a (mi), and 1 / (n_u! n_v! n_w!) of q (a product, not a division:
 * 630 of them a box made fig. 3c's boxes slow beyond their instructions). */
static const unsigned char mi_up[3][MI4] = {
    { 1, 4, 5, 6, 10, 11, 12, 13, 14, 15, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44,
      45, 46, 47, 48, 49 },
    { 2, 5, 7, 8, 11, 13, 14, 16, 17, 18, 21, 23, 24, 26, 27, 28, 30, 31, 32, 33, 36, 38, 39, 41, 42, 43, 45, 46, 47, 48,
      50, 51, 52, 53, 54 },
    { 3, 6, 8, 9, 12, 14, 15, 17, 18, 19, 22, 24, 25, 27, 28, 29, 31, 32, 33, 34, 37, 39, 40, 42, 43, 44, 46, 47, 48, 49,
      51, 52, 53, 54, 55 }
};
static const double mi_rfact[MI4] = { 1, 1, 1, 1, 1. / 2, 1, 1, 1. / 2, 1, 1. / 2, 1. / 6, 1. / 2, 1. / 2, 1. / 2,
                                      1, 1. / 2, 1. / 6, 1. / 2, 1. / 2, 1. / 6, 1. / 24, 1. / 6, 1. / 6, 1. / 4,
                                      1. / 2, 1. / 4, 1. / 6, 1. / 2, 1. / 2, 1. / 6, 1. / 24, 1. / 6, 1. / 4, 1. / 6,
                                      1. / 24 };

/* Unrolled but in clang's AddressSanitizer builds (the fuzzers, `make fuzz`): there the 45 unrolled
 * copies in model_at took clang 14 ten minutes to compile, even at -O1 (10 s without). */
#if defined(__clang__) && defined(__has_feature)
#if __has_feature(address_sanitizer)
#define UNROLL_CONV
#endif
#endif
#ifndef UNROLL_CONV
#define UNROLL_CONV _Pragma("GCC unroll 210")
#endif

/* Inlined with a constant K and unrolled: the table's indices become constants (a box's det J
 * model multiplies 18 series; the table's loads were most of its cost). */
static inline __attribute__((always_inline)) void series_mul(const double *a, const double *b, double *out, int K)
{
    for (int q = 0; q < mi_count[K]; q++)
        out[q] = 0.0;
    UNROLL_CONV
    for (int i = 0; i < conv_n[K]; i++)
        out[conv[i][0]] += a[conv[i][1]] * b[conv[i][2]];
}

/*
 * det J as a series to order K, from a jet of x (order K + 1): entry (r, a) of J is d x_r / d axis
 * a, whose series coefficients are x_r's derivatives at index e_a + b over b!. With a bound jet
 * (bound = 1), every term counts positively: the result bounds the series of det J term by term.
 */
static inline __attribute__((always_inline)) void detj_series(const xjet *j, int K, int bound, double *out)
{
    double e[3][3][MI4], t[MI4], p[MI4];
    for (int r = 0; r < 3; r++)
        for (int a = 0; a < 3; a++)
            for (int q = 0; q < mi_count[K]; q++)
                e[r][a][q] = j->d[r][mi_up[a][q]] * mi_rfact[q];
    /* By cofactors along the first row: nine products of series, not twelve. */
    const double sg = bound ? 1.0 : -1.0;
    for (int q = 0; q < mi_count[K]; q++)
        out[q] = 0.0;
    for (int a = 0; a < 3; a++) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        double minor[MI4];
        series_mul(e[1][b], e[2][c], t, K);
        series_mul(e[1][c], e[2][b], p, K);
        for (int q = 0; q < mi_count[K]; q++)
            minor[q] = t[q] + sg * p[q];
        series_mul(e[0][a], minor, p, K);
        for (int q = 0; q < mi_count[K]; q++)
            out[q] += p[q];
    }
}

static double cubic_rest(const obj_model *m, const double r[3]);

/* 1 when every factor is a power of its parameter and every w-term a polynomial (alpha = beta = 0). */
static int polynomial(const pde_solution *s)
{
    for (int c = 0; c < 3; c++)
        for (size_t k = 0; k < s->comp[c].nmodes; k++) {
            const pde_mode *md = &s->comp[c].modes[k];
            if (md->u.kind != PDE_POW || md->v.kind != PDE_POW)
                return 0;
            for (size_t i = 0; i < md->nterms; i++)
                if (md->terms[i].alpha != 0.0 || md->terms[i].beta != 0.0)
                    return 0;
        }
    return 1;
}

/* r^n for n <= 4. */
static double ipow3(double r, int n)
{
    double p = 1.0;
    for (int i = 0; i < n; i++)
        p *= r;
    return p;
}

/* obj_model_at with a branch and bound's memo jc (or NULL). */
static void model_at(const pde_solution *s, int what, const pbox *b, jet_cache *jc, obj_model *m)
{
    pbox c;
    double r[3];
    for (int a = 0; a < 3; a++) {
        c.lo[a] = c.hi[a] = 0.5 * (b->lo[a] + b->hi[a]);
        r[a] = 0.5 * (b->hi[a] - b->lo[a]);
    }
    /* det J's remainder one order up (below) where the solid has a rate to lose in bounds of products:
     * on a polynomial solid (fig. 1) the third-order one closes as fast, at 0.6 of the cost a box. */
    const int high = what == 3 && !polynomial(s);
    const int order = what < 3 ? 2 : high ? 4 : 3;
    xjet pt, mx;
    const int only = what < 3 ? what : -1;
    /* the box's flat axis, u or v (a loft's t: two groups of modes), for jet_grouped */
    const int flat = r[0] == 0.0 ? 0 : r[1] == 0.0 ? 1 : -1;
    xjet_fill(s, &c, order, 0, only, jc, flat, &pt);
    xjet_fill(s, b, order + 1, 1, only, jc, flat, &mx);
    /* Taylor coefficients: the value, the gradient, the Hessian at the centre, the third-order bound;
     * for det J the cubic terms at the centre and the fourth-order bounds too (m->rest). */
    double tp[MI4], tb[MI4];
    if (what < 3) {
        static const double fact[4] = { 1, 1, 2, 6 };
        for (int q = 0; q < MI3; q++) {
            double f = fact[mi_u[q]] * fact[mi_v[q]] * fact[mi_w[q]];
            tp[q] = q < MI2 ? pt.d[what][q] / f : 0.0;
            tb[q] = mx.d[what][q] / f;
        }
    } else if (!high) {
        detj_series(&pt, 2, 0, tp);
        detj_series(&mx, 3, 1, tb);
    } else {
        detj_series(&pt, 3, 0, tp);
        detj_series(&mx, 4, 1, tb);
        /* det J's third derivatives over the box: at most the exact ones at the centre plus the
         * fourth-order bounds times the radii (see rest below). */
        for (int q = MI2; q < MI3; q++) {
            double t = fabs(tp[q]);
            t += (mi_u[q] + 1) * tb[mi_up[0][q]] * r[0];
            t += (mi_v[q] + 1) * tb[mi_up[1][q]] * r[1];
            t += (mi_w[q] + 1) * tb[mi_up[2][q]] * r[2];
            tb[q] = fmin(tb[q], t);
        }
    }
    m->v = tp[0];
    for (int k = 0; k < 3; k++) {
        int n[3] = { 0, 0, 0 };
        n[k]++;
        m->g[k] = tp[mi(n)];
        for (int l = k; l < 3; l++) {
            int n2[3] = { n[0], n[1], n[2] };
            n2[l]++;
            m->H[k][l] = m->H[l][k] = tp[mi(n2)] * (k == l ? 2.0 : 1.0);
            for (int q = l; q < 3; q++) {
                int n3[3] = { n2[0], n2[1], n2[2] };
                n3[q]++;
                double f = (k == q) ? 6.0 : (k == l || l == q) ? 2.0 : 1.0;
                double t = tb[mi(n3)] * f;
                m->T[k][l][q] = m->T[k][q][l] = m->T[l][k][q] = m->T[l][q][k] = m->T[q][k][l] =
                    m->T[q][l][k] = t;
            }
        }
    }
    m->rest = cubic_rest(m, r);
    if (high) {
        /* Lagrange's remainder one order up: the exact cubic terms at the centre and the fourth-order
         * bounds, each once (T above counts a fourth-order term once per axis of its index). */
        double rest = 0.0;
        for (int q = MI2; q < MI4; q++) {
            const double rq = ipow3(r[0], mi_u[q]) * ipow3(r[1], mi_v[q]) * ipow3(r[2], mi_w[q]);
            rest += (q < MI3 ? fabs(tp[q]) : tb[q]) * rq;
        }
        m->rest = fmin(m->rest, rest);
    }
}

void obj_model_at(const pde_solution *s, int what, const pbox *b, obj_model *m)
{
    model_at(s, what, b, NULL, m);
}

double obj_magnitude(const pde_solution *s, int what)
{
    const pbox cube = { { 0, 0, 0 }, { 1, 1, 1 } };
    xjet mx;
    xjet_fill(s, &cube, 1, 2, what < 3 ? what : -1, NULL, -1, &mx);
    if (what < 3)
        return mx.d[what][0];
    double t[MI3];
    detj_series(&mx, 0, 1, t);
    return t[0];
}

void pde_solution_magnitudes(const pde_solution *s, double mag[3][4])
{
    const pbox cube = { { 0, 0, 0 }, { 1, 1, 1 } };
    xjet mx;
    xjet_fill(s, &cube, 1, 1, -1, NULL, -1, &mx);
    for (int c = 0; c < 3; c++)
        for (int q = 0; q < 4; q++)   /* the jets' order: x, x_u, x_v, x_w */
            mag[c][q] = mx.d[c][q];
}

/* The half-widths of the partial derivatives' ranges over a box of radii r around the centre. */
static void grad_spread(const obj_model *m, const double r[3], double spread[3])
{
    for (int k = 0; k < 3; k++) {
        double s = 0.0;
        for (int l = 0; l < 3; l++) {
            s += fabs(m->H[k][l]) * r[l];
            for (int q = 0; q < 3; q++)
                s += 0.5 * m->T[k][l][q] * r[l] * r[q];
        }
        spread[k] = s;
    }
}

/* A lower bound of g.d + d'Hd/2 over |d_k| <= r_k. */
static double quad_lower(const double g[3], const double H[3][3], const double r[3])
{
    double simple = 0.0;
    for (int k = 0; k < 3; k++) {
        simple -= fabs(g[k]) * r[k];
        simple += 0.5 * fmin(0.0, H[k][k]) * r[k] * r[k];
        for (int l = 0; l < 3; l++)
            if (l != k)
                simple -= 0.5 * fabs(H[k][l]) * r[k] * r[l];
    }
    /* On the axes the box spans, a positive definite H bounds the quadratic by its minimum over all d. */
    int ax[3], n = 0;
    for (int k = 0; k < 3; k++)
        if (r[k] > 0.0)
            ax[n++] = k;
    double L[3][3] = { { 0 } }, y[3];
    for (int i = 0; i < n; i++)
        for (int j = 0; j <= i; j++) {
            double t = H[ax[i]][ax[j]];
            for (int q = 0; q < j; q++)
                t -= L[i][q] * L[j][q];
            if (i == j) {
                if (!(t > 0.0))
                    return simple;
                L[i][i] = sqrt(t);
            } else
                L[i][j] = t / L[j][j];
        }
    double gHg = 0.0;   /* g' H^-1 g = |L^-1 g|^2 */
    for (int i = 0; i < n; i++) {
        double t = g[ax[i]];
        for (int q = 0; q < i; q++)
            t -= L[i][q] * y[q];
        y[i] = t / L[i][i];
        gHg += y[i] * y[i];
    }
    return fmax(simple, -0.5 * gHg);
}

static double cubic_rest(const obj_model *m, const double r[3])
{
    double t = 0.0;
    for (int k = 0; k < 3; k++)
        for (int l = 0; l < 3; l++)
            for (int q = 0; q < 3; q++)
                t += m->T[k][l][q] * r[k] * r[l] * r[q];
    return t / 6.0;
}

/* obj_lower, leaving the final box's model in *mp. */
static double lower_model(const pde_solution *s, int what, double sign, pbox *b, double *val, double at[3],
                          jet_cache *jc, obj_model *mp)
{
    obj_model m;
    double r[3], spread[3];
    for (int pass = 0;; pass++) {
        model_at(s, what, b, jc, &m);
        for (int k = 0; k < 3; k++)
            r[k] = 0.5 * (b->hi[k] - b->lo[k]);
        if (pass == 3)
            break;
        grad_spread(&m, r, spread);
        int moved = 0;
        for (int k = 0; k < 3; k++) {
            if (r[k] == 0.0)
                continue;
            /* Non-decreasing (the derivative's lower bound >= 0, as at a face where the objective's
             * derivative vanishes, fig. 1's z at w = 0): the minimum is on the low face. */
            double g = sign * m.g[k];
            if (g - spread[k] >= 0.0)
                b->hi[k] = b->lo[k], moved = 1;
            else if (g + spread[k] <= 0.0)
                b->lo[k] = b->hi[k], moved = 1;
        }
        if (!moved)
            break;
    }
    double g[3], H[3][3];
    for (int k = 0; k < 3; k++) {
        g[k] = sign * m.g[k];
        for (int l = 0; l < 3; l++)
            H[k][l] = sign * m.H[k][l];
    }
    *val = sign * m.v;
    for (int k = 0; k < 3; k++)
        at[k] = 0.5 * (b->lo[k] + b->hi[k]);
    double lb = sign * m.v + quad_lower(g, H, r) - m.rest;
    *mp = m;
    return lb == lb ? lb : -INFINITY;   /* NaN from overflowed bounds: no bound */
}

double obj_lower(const pde_solution *s, int what, double sign, pbox *b, double *val, double at[3])
{
    obj_model m;
    return lower_model(s, what, sign, b, val, at, NULL, &m);
}

/* ---- branch and bound ---- */

typedef struct {
    double lb;  /* first: bb_heap's key */
    pbox b;
    int axis;   /* split_axis of b's model, -1 for a point */
} bb_node;

static double heap_key(const bb_heap *h, size_t i)
{
    double k;
    memcpy(&k, h->a + i * h->size, sizeof k);
    return k;
}

double bb_heap_min(const bb_heap *h)
{
    return heap_key(h, 0);
}

int bb_heap_push(bb_heap *h, const void *x)
{
    if (h->n == h->cap) {
        size_t cap = h->cap ? 2 * h->cap : 64;
        unsigned char *a = realloc(h->a, cap * h->size);
        if (!a)
            return -1;
        h->a = a, h->cap = cap;
    }
    double k;
    memcpy(&k, x, sizeof k);
    size_t i = h->n++;
    while (i > 0 && heap_key(h, (i - 1) / 2) > k) {
        memcpy(h->a + i * h->size, h->a + (i - 1) / 2 * h->size, h->size);
        i = (i - 1) / 2;
    }
    memcpy(h->a + i * h->size, x, h->size);
    return 0;
}

void bb_heap_pop(bb_heap *h, void *top)
{
    unsigned char *last = h->a + --h->n * h->size;
    memcpy(top, h->a, h->size);
    double k;
    memcpy(&k, last, sizeof k);
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= h->n)
            break;
        if (c + 1 < h->n && heap_key(h, c + 1) < heap_key(h, c))
            c++;
        if (heap_key(h, c) >= k)
            break;
        memcpy(h->a + i * h->size, h->a + c * h->size, h->size);
        i = c;
    }
    if (h->n)
        memmove(h->a + i * h->size, last, h->size);
}

/* The axis along which b's half-width contributes most to its model m's bound, or -1 for a point. */
static int split_axis(const obj_model *m, const pbox *b)
{
    double r[3], spread[3];
    for (int k = 0; k < 3; k++)
        r[k] = 0.5 * (b->hi[k] - b->lo[k]);
    grad_spread(m, r, spread);
    int best = -1;
    double most = -1.0;
    for (int k = 0; k < 3; k++) {
        double c = r[k] * (fabs(m->g[k]) + spread[k]);
        if (r[k] > 0.0 && (c > most || c != c))
            most = c == c ? c : INFINITY, best = k;
    }
    return best;
}

/*
 * Where sign * f's quadratic model over b is convex on the axes b spans, the points where it can be
 * below target lie in the ellipsoid (d - d*)'H(d - d*)/2 <= target - min + rest, d* the model's
 * minimiser: b shrinks to the box around that ellipsoid, like a Newton step, where bisection would
 * take a split per axis and halving (fig. 1c's interior maximum of det J). Returns 0 (b unchanged,
 * or shrunk by less than a quarter along every axis), 1 (b shrunk), 2 (nothing of b is below target).
 */
static int reduce_box(const obj_model *m, double sign, double target, pbox *b)
{
    int ax[3], n = 0;
    double r[3], c[3];
    for (int k = 0; k < 3; k++) {
        r[k] = 0.5 * (b->hi[k] - b->lo[k]);
        c[k] = 0.5 * (b->lo[k] + b->hi[k]);
        if (r[k] > 0.0)
            ax[n++] = k;
    }
    if (n == 0)
        return 0;
    double L[3][3] = { { 0 } };
    for (int i = 0; i < n; i++)
        for (int j = 0; j <= i; j++) {
            double t = sign * m->H[ax[i]][ax[j]];
            for (int q = 0; q < j; q++)
                t -= L[i][q] * L[j][q];
            if (i == j) {
                if (!(t > 0.0))
                    return 0;
                L[i][i] = sqrt(t);
            } else
                L[i][j] = t / L[j][j];
        }
    /* H^-1 column by column (L L' x = e_j): the minimiser and the ellipsoid's extents. */
    double Hi[3][3], ds[3] = { 0, 0, 0 };
    for (int j = 0; j < n; j++) {
        double y[3], x[3];
        for (int i = 0; i < n; i++) {
            double t = i == j ? 1.0 : 0.0;
            for (int q = 0; q < i; q++)
                t -= L[i][q] * y[q];
            y[i] = t / L[i][i];
        }
        for (int i = n - 1; i >= 0; i--) {
            double t = y[i];
            for (int q = i + 1; q < n; q++)
                t -= L[q][i] * x[q];
            x[i] = t / L[i][i];
        }
        for (int i = 0; i < n; i++)
            Hi[i][j] = x[i];
    }
    double gHg = 0.0;
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++)
            ds[i] -= Hi[i][j] * sign * m->g[ax[j]];
        gHg -= sign * m->g[ax[i]] * ds[i];
    }
    const double delta = target - (sign * m->v - 0.5 * gHg) + m->rest;
    if (!(delta == delta) || !isfinite(delta))
        return 0;
    if (delta < 0.0)
        return 2;
    int shrunk = 0;
    for (int i = 0; i < n; i++) {
        const int k = ax[i];
        const double e = sqrt(2.0 * delta * fmax(Hi[i][i], 0.0));
        const double lo = fmax(b->lo[k], c[k] + ds[i] - e), hi = fmin(b->hi[k], c[k] + ds[i] + e);
        if (!(lo <= hi))
            return 2;
        if (hi - lo < 0.75 * (b->hi[k] - b->lo[k]))
            shrunk = 1;
    }
    if (!shrunk)
        return 0;
    for (int i = 0; i < n; i++) {
        const int k = ax[i];
        const double e = sqrt(2.0 * delta * fmax(Hi[i][i], 0.0));
        b->lo[k] = fmax(b->lo[k], c[k] + ds[i] - e);
        b->hi[k] = fmin(b->hi[k], c[k] + ds[i] + e);
    }
    return 1;
}

pde_status bb_minimise(const pde_solution *s, int what, double sign, const double start[3], const pbox *within,
                       double tol, size_t budget, const pde_cancel *cancel, bb_result *out)
{
    return bb_minimise_floor(s, what, sign, start, within, INFINITY, 0.0, tol, budget, cancel, out);
}

/* What an open box's bound must reach to close: best - tol, or floor - ftol below it. */
static double bb_target(double best, double floor, double ftol, double tol)
{
    return fmin(best - tol, floor - ftol);
}

pde_status bb_minimise_floor(const pde_solution *s, int what, double sign, const double start[3], const pbox *within,
                             double floor, double ftol, double tol, size_t budget, const pde_cancel *cancel,
                             bb_result *out)
{
    bb_result r = { .lower = DBL_MAX, .boxes = 0 };
    pbox p0 = { { start[0], start[1], start[2] }, { start[0], start[1], start[2] } };
    obj_model m0;
    jet_cache *jc = jet_cache_new(s, what);   /* NULL: without the memo */
    model_at(s, what, &p0, jc, &m0);
    r.best = sign * m0.v;
    for (int k = 0; k < 3; k++)
        r.at[k] = start[k];

    /* A box per slab of a loft: a box's Taylor model holds within one slab, where h is analytic. */
    bb_heap h = { .size = sizeof(bb_node) };
    size_t nslabs;
    const double *br = solution_breaks(s, &nslabs);
    double val, at[3];
    for (size_t k = 0; k < nslabs; k++) {
        bb_node n = { 0, { { 0, 0, br[k] }, { 1, 1, br[k + 1] } }, -1 };
        if (within) {
            for (int a = 0; a < 3; a++)
                n.b.lo[a] = fmax(n.b.lo[a], within->lo[a]), n.b.hi[a] = fmin(n.b.hi[a], within->hi[a]);
            if (n.b.lo[2] > n.b.hi[2] || (n.b.lo[2] == n.b.hi[2] && within->lo[2] < within->hi[2]))
                continue;   /* a slab outside within, or only touching it */
        }
        obj_model m;
        n.lb = lower_model(s, what, sign, &n.b, &val, at, jc, &m);
        n.axis = split_axis(&m, &n.b);
        r.boxes++;
        if (val < r.best)
            r.best = val, r.at[0] = at[0], r.at[1] = at[1], r.at[2] = at[2];
        if (bb_heap_push(&h, &n)) {
            free(h.a);
            free(jc);
            return PDE_ERR_NOMEM;
        }
    }
    pde_status st = PDE_OK;
    unsigned iterations = 0;
    while (h.n) {
        if (bb_heap_min(&h) >= bb_target(r.best, floor, ftol, tol) || r.boxes >= budget)
            break;
        if ((++iterations & 7) == 0 && pde_stopped(cancel)) {   /* every 16 boxes */
            st = PDE_ERR_CANCELLED;
            break;
        }
        bb_node top;
        bb_heap_pop(&h, &top);
        const int k = top.axis;
        if (k < 0) {   /* a point: its bound is its value */
            r.lower = fmin(r.lower, top.lb);
            continue;
        }
        double mid = 0.5 * (top.b.lo[k] + top.b.hi[k]);
        for (int half = 0; half < 2; half++) {
            bb_node c = top;
            if (half)
                c.b.lo[k] = mid;
            else
                c.b.hi[k] = mid;
            obj_model m;
            c.lb = lower_model(s, what, sign, &c.b, &val, at, jc, &m);
            r.boxes++;
            if (val < r.best)
                r.best = val, r.at[0] = at[0], r.at[1] = at[1], r.at[2] = at[2];
            /* Cut off what is certified above best - tol / 2: the gap stays within tol. */
            for (int pass = 0; pass < 2 && c.lb < bb_target(r.best, floor, ftol, tol); pass++) {
                const double cut = bb_target(r.best, floor, 0.5 * ftol, 0.5 * tol);
                const int red = reduce_box(&m, sign, cut, &c.b);
                if (red == 0)
                    break;
                r.lower = fmin(r.lower, cut);
                if (red == 2) {
                    c.lb = cut;
                    break;
                }
                c.lb = fmax(c.lb, lower_model(s, what, sign, &c.b, &val, at, jc, &m));
                r.boxes++;
                if (val < r.best)
                    r.best = val, r.at[0] = at[0], r.at[1] = at[1], r.at[2] = at[2];
            }
            c.axis = split_axis(&m, &c.b);
            c.lb = fmax(c.lb, top.lb);   /* a child's minimum is at least its parent's bound */
            if (c.lb < bb_target(r.best, floor, ftol, tol)) {
                if (bb_heap_push(&h, &c)) {
                    st = PDE_ERR_NOMEM;
                    break;
                }
            } else
                r.lower = fmin(r.lower, c.lb);
        }
        if (st != PDE_OK)
            break;
    }
    if (h.n)
        r.lower = fmin(r.lower, bb_heap_min(&h));
    r.lower = fmin(r.lower, r.best);
    free(h.a);
    free(jc);
    if (st == PDE_OK)
        *out = r;
    return st;
}
