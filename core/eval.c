/*
 * eval.c: evaluation of a solution at points, and tensor-product sampling.
 *
 * x_i(u,v,w) = sum over modes h(w) f_u(u) f_v(v) (eq. 4). A grid evaluates
 * each f_u and f_v once per sample and each h once per plane, so the inner
 * loop is one multiply-add per mode and point, over contiguous memory.
 */
#include <math.h>
#include <stdlib.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "internal.h"

#define EVAL_SHARED 64   /* modes at most whose factors pde_eval_d takes from solution_factors */

void pde_eval_d(const pde_solution *sol, double u, double v, double w,
                double x[3], double xu[3], double xv[3], double xw[3])
{
    /* Every mode's factors at once, a factor, an exp or a sincos that recurs across modes once (the
     * same values as each mode's own: factor_eval's, mode_h's). */
    double f[6][EVAL_SHARED];
    const size_t mt = sol->comp[0].nmodes + sol->comp[1].nmodes + sol->comp[2].nmodes;
    const int shared = mt <= EVAL_SHARED;
    if (shared) {
        solution_factors(sol, 0, u, f[0], f[1]);
        solution_factors(sol, 1, v, f[2], f[3]);
        solution_factors(sol, 2, w, f[4], f[5]);
    }
    for (int c = 0, o = 0; c < 3; c++) {
        const comp_solution *cs = &sol->comp[c];
        double s = 0.0, su = 0.0, sv = 0.0, sw = 0.0;
        for (size_t m = 0; m < cs->nmodes; m++, o++) {
            const pde_mode *md = &cs->modes[m];
            double fu, dfu, fv, dfv, h, dh;
            if (shared)
                fu = f[0][o], dfu = f[1][o], fv = f[2][o], dfv = f[3][o], h = f[4][o], dh = f[5][o];
            else {
                factor_eval(md->u, u, &fu, &dfu);
                factor_eval(md->v, v, &fv, &dfv);
                mode_h(md, w, &h, &dh);
            }
            s += h * fu * fv;
            su += h * dfu * fv;
            sv += h * fu * dfv;
            sw += dh * fu * fv;
        }
        if (x)
            x[c] = s;
        if (xu)
            xu[c] = su;
        if (xv)
            xv[c] = sv;
        if (xw)
            xw[c] = sw;
    }
}

void pde_eval(const pde_solution *sol, double u, double v, double w, double x[3])
{
    pde_eval_d(sol, u, v, w, x, NULL, NULL, NULL);
}

/* det(x_u, x_v, x_w) from d[axis][component] */
static double det_of(const double d[3][3])
{
    return d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) - d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0])
           + d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
}

double pde_eval_detj(const pde_solution *sol, double u, double v, double w)
{
    double d[3][3];
    pde_eval_d(sol, u, v, w, NULL, d[0], d[1], d[2]);
    return det_of(d);
}

/* 4 x 4 x 4 interior points at irrational places, so that no sample falls on a fold. At each, det J against
 * Hadamard's bound, the product of the three components' gradient lengths: a scale of its own per coordinate
 * (a solid 1e7 wide and 1 high is not flat), and no cube of a large number to overflow. */
int pde_solution_is_flat(const pde_solution *sol)
{
    for (int i = 0; i < 64; i++) {
        const double u = 0.1 + 0.8 * ((i & 3) + 0.5 * M_SQRT1_2) / 4, v = 0.1 + 0.8 * ((i >> 2 & 3) + 0.3 * M_SQRT2) / 4,
                     w = 0.1 + 0.8 * ((i >> 4) + 0.1 * M_PI) / 4;
        double d[3][3];
        pde_eval_d(sol, u, v, w, NULL, d[0], d[1], d[2]);
        double bound = 1e-12;
        for (int c = 0; c < 3; c++)
            bound *= hypot(hypot(d[0][c], d[1][c]), d[2][c]);
        if (fabs(det_of(d)) > bound)
            return 0;
    }
    return 1;
}

double pde_eval_partial(const pde_solution *sol, int comp, double u, double v, double w,
                        int nu, int nv, int nw)
{
    const comp_solution *cs = &sol->comp[comp];
    double s = 0.0;
    for (size_t m = 0; m < cs->nmodes; m++) {
        const pde_mode *md = &cs->modes[m];
        double fu = factor_deriv(md->u, u, nu);
        double fv = factor_deriv(md->v, v, nv);
        if (fu == 0.0 || fv == 0.0)
            continue;
        double h = 0.0;
        size_t k0, k1;
        mode_slab(md, w, &k0, &k1);
        for (size_t k = k0; k < k1; k++)
            h += wterm_deriv(&md->terms[k], w, nw);
        s += h * fu * fv;
    }
    return s;
}

double pde_force(const pde_solution *sol, int comp, double u, double v, double w)
{
    const comp_solution *cs = &sol->comp[comp];
    double s = 0.0;
    for (size_t j = 0; j < cs->nfterms; j++) {
        const pde_fterm *t = &cs->fterms[j];
        s += t->coef * factor_deriv(t->u, u, 0) * factor_deriv(t->v, v, 0) * factor_deriv(t->w, w, 0);
    }
    return s;
}

void pde_grid_free(pde_grid *g)
{
    if (!g)
        return;
    for (int c = 0; c < 3; c++) {
        free(g->group[c]);
        free(g->phi[c]);
        free(g->psi[c]);
        free(g->k[c]);
    }
    free(g->hs);
    free(g->row);
    free(g->col);
    free(g->blk);
    free(g);
}

pde_status pde_grid_create(const pde_solution *sol, const double *us, size_t nu,
                           const double *vs, size_t nv, pde_grid **out)
{
    if (!sol || !us || !vs || nu == 0 || nv == 0 || nu > ((size_t)1 << 24) || nv > ((size_t)1 << 24))
        return PDE_ERR_INVALID;
    pde_grid *g = calloc(1, sizeof *g);
    if (!g)
        return PDE_ERR_NOMEM;
    g->sol = sol;
    g->nu = nu;
    g->nv = nv;
    g->w = NAN;
    const size_t mt = sol->comp[0].nmodes + sol->comp[1].nmodes + sol->comp[2].nmodes;
    g->row = malloc(12 * nu * sizeof *g->row);
    g->hs = malloc(2 * (mt ? mt : 1) * sizeof *g->hs);
    if (!g->row || !g->hs)
        goto nomem;
    size_t off = 0;
    for (int c = 0; c < 3; off += sol->comp[c].nmodes, c++) {
        const pde_mode *modes = sol->comp[c].modes;
        size_t nm = sol->comp[c].nmodes, k = nm ? nm : 1, nd = 0;
        g->nm[c] = nm;
        g->group[c] = malloc(k * sizeof *g->group[c]);
        g->psi[c] = malloc(2 * k * nv * sizeof(double));
        g->h[c] = g->hs + off;
        g->dh[c] = g->hs + (mt ? mt : 1) + off;
        g->k[c] = malloc(3 * k * sizeof(double));
        if (!g->group[c] || !g->psi[c] || !g->k[c])
            goto nomem;
        for (size_t m = 0; m < nm; m++) {
            size_t d = 0;
            while (d < m && !(modes[d].u.kind == modes[m].u.kind && modes[d].u.p == modes[m].u.p))
                d++;
            g->group[c][m] = d < m ? g->group[c][d] : nd++;
        }
        g->nd[c] = nd;
        g->phi[c] = malloc(2 * (nd ? nd : 1) * nu * sizeof(double));
        if (!g->phi[c])
            goto nomem;
        g->dphi[c] = g->phi[c] + (nd ? nd : 1) * nu;
        g->dpsi[c] = g->psi[c] + k * nv;
        for (size_t m = 0; m < nm; m++) {
            size_t d = g->group[c][m];
            for (size_t i = 0; i < nu; i++)
                factor_eval(modes[m].u, us[i], &g->phi[c][d * nu + i], &g->dphi[c][d * nu + i]);
            for (size_t j = 0; j < nv; j++)
                factor_eval(modes[m].v, vs[j], &g->psi[c][m * nv + j], &g->dpsi[c][m * nv + j]);
        }
    }
    /* col_coefs scans every mode for each u-factor: nd nm a block, fine for a loft's few u-factors (1, t),
     * not for 4000 distinct ones (tests/test_hostile.c's heavy stream stalled /livez) */
    if (nu > COL_NU && (g->nm[0] >= BLK_MODES || g->nm[1] >= BLK_MODES || g->nm[2] >= BLK_MODES) &&
        g->nd[0] <= BLK_ND && g->nd[1] <= BLK_ND && g->nd[2] <= BLK_ND &&
        !(g->blk = malloc(3 * (g->nd[0] + g->nd[1] + g->nd[2] + 3) * BLK_ROWS * sizeof *g->blk)))
        goto nomem;
    if (nu <= COL_NU) {
        size_t ndmax = 1;
        for (int c = 0; c < 3; c++)
            ndmax = g->nd[c] > ndmax ? g->nd[c] : ndmax;
        /* 3 nv more when nd = 1, 1, 1: grid_cols then keeps the three components' coefficients */
        if (!(g->col = malloc((3 * ndmax > 9 ? 3 * ndmax : 9) * nv * sizeof *g->col)))
            goto nomem;
    }
    *out = g;
    return PDE_OK;
nomem:
    pde_grid_free(g);
    return PDE_ERR_NOMEM;
}

/* row[i] = sum_d k_d tab[d][i], the first product stored rather than added to 0 (but for its zero's sign, the
 * same sums). */
static void combine(double *restrict row, const double *restrict tab, const double *restrict k,
                    size_t nd, size_t n)
{
    if (nd == 0) {
        for (size_t i = 0; i < n; i++)
            row[i] = 0.0;
        return;
    }
    for (size_t i = 0; i < n; i++)
        row[i] = k[0] * tab[i];
    for (size_t d = 1; d < nd; d++) {
        const double kd = k[d];
        const double *restrict t = tab + d * n;
        for (size_t i = 0; i < n; i++)
            row[i] += kd * t[i];
    }
}

void grid_set_w(pde_grid *g, double w)
{
    if (w == g->w)
        return;
    g->w = w;
    solution_factors(g->sol, 2, w, g->h[0], g->dh[0]);
}

/* Each distinct u-factor's coefficient in row j: sums of h f_v over its modes. */
static void grid_coefs(pde_grid *g, size_t j)
{
    for (int c = 0; c < 3; c++) {
        const size_t nd = g->nd[c], nv = g->nv;
        double *kx = g->k[c], *kv = kx + nd, *kw = kv + nd;
        for (size_t d = 0; d < 3 * nd; d++)
            kx[d] = 0.0;
        for (size_t m = 0; m < g->nm[c]; m++) {
            size_t d = g->group[c][m];
            double p = g->psi[c][m * nv + j];
            kx[d] += g->h[c][m] * p;
            kv[d] += g->h[c][m] * g->dpsi[c][m * nv + j];
            kw[d] += g->dh[c][m] * p;
        }
    }
}

void grid_row(pde_grid *g, size_t j, unsigned want)
{
    const size_t nu = g->nu;
    grid_coefs(g, j);
    for (int c = 0; c < 3; c++) {
        const size_t nd = g->nd[c];
        const double *kx = g->k[c], *kv = kx + nd, *kw = kv + nd;
        if (want & GRID_X)
            combine(g->row + c * nu, g->phi[c], kx, nd, nu);
        if (want & GRID_XU)
            combine(g->row + (3 + c) * nu, g->dphi[c], kx, nd, nu);
        if (want & GRID_XV)
            combine(g->row + (6 + c) * nu, g->phi[c], kv, nd, nu);
        if (want & GRID_XW)
            combine(g->row + (9 + c) * nu, g->phi[c], kw, nd, nu);
    }
}

/*
 * out[3i + c] = sum_d k[d] tab[d][i] for one component c, straight to float32:
 * the hot loop of sampling. A row of output (12 nu bytes) stays in L1 while
 * the three components are written into it, each by a loop specialised to its
 * number of distinct u-factors.
 */
static void emit1(float *restrict out, size_t nu, const double *restrict tab, const double *restrict k,
                  size_t nd)
{
    const double *restrict t0 = tab, *restrict t1 = tab + nu, *restrict t2 = tab + 2 * nu;
    switch (nd) {
    case 0:
        for (size_t i = 0; i < nu; i++)
            out[3 * i] = 0.0f;
        return;
    case 1:
        for (size_t i = 0; i < nu; i++)
            out[3 * i] = (float)(k[0] * t0[i]);
        return;
    case 2:
        for (size_t i = 0; i < nu; i++)
            out[3 * i] = (float)(k[0] * t0[i] + k[1] * t1[i]);
        return;
    case 3:
        for (size_t i = 0; i < nu; i++)
            out[3 * i] = (float)(k[0] * t0[i] + k[1] * t1[i] + k[2] * t2[i]);
        return;
    }
    for (size_t i = 0; i < nu; i++) {
        double s = 0.0;
        for (size_t d = 0; d < nd; d++)
            s += k[d] * tab[d * nu + i];
        out[3 * i] = (float)s;
    }
}

static void emit(float *out, size_t nu, const double *const tab[3], const double *const k[3],
                 const size_t nd[3])
{
    if (nd[0] == 1 && nd[1] == 1 && nd[2] == 1) {   /* emit1's case 1 for the three at once */
        const double k0 = k[0][0], k1 = k[1][0], k2 = k[2][0];
        const double *restrict t0 = tab[0], *restrict t1 = tab[1], *restrict t2 = tab[2];
        float *restrict o = out;
        size_t i = 0;
#if defined(__SSE2__)
        /* four, then two points a step: the same products, rounded to float as below, interleaved */
        const __m128d K0 = _mm_set1_pd(k0), K1 = _mm_set1_pd(k1), K2 = _mm_set1_pd(k2);
        for (; i + 4 <= nu; i += 4) {   /* four points: x, y, z of each as below, then interleaved */
            const __m128 x = _mm_movelh_ps(_mm_cvtpd_ps(_mm_mul_pd(K0, _mm_loadu_pd(t0 + i))),
                                           _mm_cvtpd_ps(_mm_mul_pd(K0, _mm_loadu_pd(t0 + i + 2))));
            const __m128 y = _mm_movelh_ps(_mm_cvtpd_ps(_mm_mul_pd(K1, _mm_loadu_pd(t1 + i))),
                                           _mm_cvtpd_ps(_mm_mul_pd(K1, _mm_loadu_pd(t1 + i + 2))));
            const __m128 z = _mm_movelh_ps(_mm_cvtpd_ps(_mm_mul_pd(K2, _mm_loadu_pd(t2 + i))),
                                           _mm_cvtpd_ps(_mm_mul_pd(K2, _mm_loadu_pd(t2 + i + 2))));
            const __m128 xy = _mm_unpacklo_ps(x, y), xy2 = _mm_unpackhi_ps(x, y);         /* x0 y0 x1 y1, x2 y2 x3 y3 */
            const __m128 zx = _mm_shuffle_ps(z, x, _MM_SHUFFLE(1, 1, 0, 0));                /* z0 z0 x1 x1 */
            const __m128 yz = _mm_shuffle_ps(y, z, _MM_SHUFFLE(1, 1, 1, 1));                /* y1 y1 z1 z1 */
            const __m128 zxy = _mm_shuffle_ps(z, xy2, _MM_SHUFFLE(3, 2, 3, 2));             /* z2 z3 x3 y3 */
            _mm_storeu_ps(o + 3 * i, _mm_shuffle_ps(xy, zx, _MM_SHUFFLE(2, 0, 1, 0)));      /* x0 y0 z0 x1 */
            _mm_storeu_ps(o + 3 * i + 4, _mm_shuffle_ps(yz, xy2, _MM_SHUFFLE(1, 0, 2, 0))); /* y1 z1 x2 y2 */
            _mm_storeu_ps(o + 3 * i + 8, _mm_shuffle_ps(zxy, zxy, _MM_SHUFFLE(1, 3, 2, 0))); /* z2 x3 y3 z3 */
        }
        for (; i + 2 <= nu; i += 2) {
            const __m128 x = _mm_cvtpd_ps(_mm_mul_pd(K0, _mm_loadu_pd(t0 + i)));
            const __m128 y = _mm_cvtpd_ps(_mm_mul_pd(K1, _mm_loadu_pd(t1 + i)));
            const __m128 z = _mm_cvtpd_ps(_mm_mul_pd(K2, _mm_loadu_pd(t2 + i)));
            const __m128 xy = _mm_unpacklo_ps(x, y);                                   /* x0 y0 x1 y1 */
            const __m128 zx = _mm_shuffle_ps(z, xy, _MM_SHUFFLE(2, 2, 0, 0));          /* z0 z0 x1 x1 */
            const __m128 yz = _mm_shuffle_ps(xy, z, _MM_SHUFFLE(1, 1, 3, 3));          /* y1 y1 z1 z1 */
            _mm_storeu_ps(o + 3 * i, _mm_shuffle_ps(xy, zx, _MM_SHUFFLE(2, 0, 1, 0))); /* x0 y0 z0 x1 */
            _mm_storel_pi((__m64 *)(void *)(o + 3 * i + 4), _mm_shuffle_ps(yz, yz, _MM_SHUFFLE(0, 0, 2, 0)));
        }
#endif
        for (; i < nu; i++)
            o[3 * i] = (float)(k0 * t0[i]), o[3 * i + 1] = (float)(k1 * t1[i]), o[3 * i + 2] = (float)(k2 * t2[i]);
        return;
    }
    for (int c = 0; c < 3; c++)
        emit1(out + c, nu, tab[c], k[c], nd[c]);
}

/* sum_d k[d ks] t[d ts] to float32, in emit1's order, so both paths give the same bits. */
static inline float dot_k(const double *k, size_t ks, const double *t, size_t ts, size_t nd)
{
    switch (nd) {
    case 0:
        return 0.0f;
    case 1:
        return (float)(k[0] * t[0]);
    case 2:
        return (float)(k[0] * t[0] + k[ks] * t[ts]);
    case 3:
        return (float)(k[0] * t[0] + k[ks] * t[ts] + k[2 * ks] * t[2 * ts]);
    }
    double s = 0.0;
    for (size_t d = 0; d < nd; d++)
        s += k[d * ks] * t[d * ts];
    return (float)s;
}

#if defined(__SSE2__)
/* col_coefs' sums for the 8 rows from j of u-factor d, in registers: kx[s i] for row j + i (kv, kw likewise). */
static inline void col_block(const pde_grid *g, int c, size_t d, size_t j, int xonly, size_t s, double *restrict kx,
                             double *restrict kv, double *restrict kw)
{
    const size_t nm = g->nm[c], nv = g->nv;
    __m128d ax[4], av[4], aw[4];
    for (int q = 0; q < 4; q++)
        ax[q] = av[q] = aw[q] = _mm_setzero_pd();
    for (size_t m = 0; m < nm; m++) {
        if (g->group[c][m] != d)
            continue;
        const __m128d h = _mm_set1_pd(g->h[c][m]), dh = _mm_set1_pd(g->dh[c][m]);
        const double *p = g->psi[c] + m * nv + j, *dp = g->dpsi[c] + m * nv + j;
        if (xonly)
            for (int q = 0; q < 4; q++)
                ax[q] = _mm_add_pd(ax[q], _mm_mul_pd(h, _mm_loadu_pd(p + 2 * q)));
        else
            for (int q = 0; q < 4; q++) {
                const __m128d pq = _mm_loadu_pd(p + 2 * q);
                ax[q] = _mm_add_pd(ax[q], _mm_mul_pd(h, pq));
                av[q] = _mm_add_pd(av[q], _mm_mul_pd(h, _mm_loadu_pd(dp + 2 * q)));
                aw[q] = _mm_add_pd(aw[q], _mm_mul_pd(dh, pq));
            }
    }
    for (size_t q = 0; q < 4; q++) {
        _mm_storel_pd(kx + s * 2 * q, ax[q]), _mm_storeh_pd(kx + s * (2 * q + 1), ax[q]);
        if (!xonly) {
            _mm_storel_pd(kv + s * 2 * q, av[q]), _mm_storeh_pd(kv + s * (2 * q + 1), av[q]);
            _mm_storel_pd(kw + s * 2 * q, aw[q]), _mm_storeh_pd(kw + s * (2 * q + 1), aw[q]);
        }
    }
}
#endif

/*
 * Component c's coefficients of rows j0 .. j0 + n - 1 of a narrow grid, grid_coefs' sums in the same order: u-factor d's
 * of row j at kx[s (d n + j)] (kv, kw likewise; not written when xonly), BLK rows at a time in registers, summed over
 * its modes in order, mode by mode over contiguous v.
 */
static void col_coefs(const pde_grid *g, int c, size_t j0, size_t n, int xonly, size_t s, double *restrict kx,
                      double *restrict kv, double *restrict kw)
{
    const size_t nd = g->nd[c], nm = g->nm[c], nv = g->nv;
    enum { BLK = 8 };
    for (size_t d = 0; d < nd; d++)
        for (size_t jb = 0; jb < n; jb += BLK) {
            const size_t nb = n - jb < BLK ? n - jb : BLK;
#if defined(__SSE2__)
            if (nb == BLK) {   /* the loops below, two rows to a pair of lanes: the same products and sums */
                col_block(g, c, d, j0 + jb, xonly, s, kx + s * (d * n + jb), kv + s * (d * n + jb), kw + s * (d * n + jb));
                continue;
            }
#endif
            double ax[BLK] = { 0 }, av[BLK] = { 0 }, aw[BLK] = { 0 };
            for (size_t m = 0; m < nm; m++) {
                if (g->group[c][m] != d)
                    continue;
                const double h = g->h[c][m], dh = g->dh[c][m];
                const double *restrict p = g->psi[c] + m * nv + j0 + jb, *restrict dp = g->dpsi[c] + m * nv + j0 + jb;
                if (nb == BLK && !xonly) {
                    for (size_t j = 0; j < BLK; j++) {
                        ax[j] += h * p[j];
                        av[j] += h * dp[j];
                        aw[j] += dh * p[j];
                    }
                } else if (nb == BLK) {   /* positions only: x's coefficients alone */
                    for (size_t j = 0; j < BLK; j++)
                        ax[j] += h * p[j];
                } else {
                    for (size_t j = 0; j < nb; j++) {
                        ax[j] += h * p[j];
                        av[j] += h * dp[j];
                        aw[j] += dh * p[j];
                    }
                }
            }
            for (size_t j = 0; j < nb; j++)
                kx[s * (d * n + jb + j)] = ax[j];
            for (size_t j = 0; j < nb && !xonly; j++) {
                kv[s * (d * n + jb + j)] = av[j];
                kw[s * (d * n + jb + j)] = aw[j];
            }
        }
}

/*
 * Faces u = 0, 1 of one u-factor a component (nd = 1, 1, 1), each output's 6 floats a row: k[3j + c] t[c] for
 * u = 0, then k[3j + c] t[3 + c] for u = 1, k a row's three coefficients side by side. The products and their
 * rounding to float of grid_cols' case 1, two rows (12 floats) a step.
 */
static void emit_ends(float *restrict o, size_t n, const double *restrict k, const double t[6])
{
    size_t j = 0;
#if defined(__SSE2__)
    const __m128d T0 = _mm_loadu_pd(t), T1 = _mm_loadu_pd(t + 2), T2 = _mm_loadu_pd(t + 4);   /* x0 y0, z0 x1, y1 z1 */
    for (; j + 2 <= n; j += 2) {
        const __m128d A = _mm_loadu_pd(k + 3 * j), B = _mm_loadu_pd(k + 3 * j + 2), C = _mm_loadu_pd(k + 3 * j + 4);
        /* A = kx ky, B = kz kx', C = ky' kz' (' the next row) */
        const __m128 p0 = _mm_cvtpd_ps(_mm_mul_pd(A, T0));
        const __m128 p1 = _mm_cvtpd_ps(_mm_mul_pd(_mm_shuffle_pd(B, A, 0), T1));
        const __m128 p2 = _mm_cvtpd_ps(_mm_mul_pd(_mm_shuffle_pd(A, B, 1), T2));
        const __m128 p3 = _mm_cvtpd_ps(_mm_mul_pd(_mm_shuffle_pd(B, C, 1), T0));
        const __m128 p4 = _mm_cvtpd_ps(_mm_mul_pd(_mm_shuffle_pd(C, B, 3), T1));
        const __m128 p5 = _mm_cvtpd_ps(_mm_mul_pd(C, T2));
        _mm_storeu_ps(o + 6 * j, _mm_movelh_ps(p0, p1));
        _mm_storeu_ps(o + 6 * j + 4, _mm_movelh_ps(p2, p3));
        _mm_storeu_ps(o + 6 * j + 8, _mm_movelh_ps(p4, p5));
    }
#endif
    for (; j < n; j++)
        for (int c = 0; c < 3; c++)
            o[6 * j + c] = (float)(k[3 * j + c] * t[c]), o[6 * j + 3 + c] = (float)(k[3 * j + c] * t[3 + c]);
}

/*
 * Rows j0 <= j < j1 of a narrow grid (nu <= COL_NU): grid_coefs for every row at once (col_coefs), then each point's
 * few dot products.
 */
static void grid_cols(pde_grid *g, size_t j0, size_t j1, float *const outs[4])
{
    const size_t nu = g->nu, n = j1 - j0;
    const int xonly = !outs[1] && !outs[2] && !outs[3];   /* kv, kw unused */
    if (nu == 2 && g->nd[0] == 1 && g->nd[1] == 1 && g->nd[2] == 1) {   /* the three components' rows at once */
        double *kx = g->col, *kv = kx + 3 * n, *kw = kv + 3 * n;
        for (int c = 0; c < 3; c++)
            col_coefs(g, c, j0, n, xonly, 3, kx + c, kv + c, kw + c);
        const double *ks[4] = { kx, kx, kv, kw };
        for (int q = 0; q < 4; q++) {
            if (!outs[q])
                continue;
            double *const *tab = q == 1 ? g->dphi : g->phi;   /* x_u: the factors' derivatives */
            const double t[6] = { tab[0][0], tab[1][0], tab[2][0], tab[0][1], tab[1][1], tab[2][1] };
            emit_ends(outs[q], n, ks[q], t);
        }
        return;
    }
    for (int c = 0; c < 3; c++) {
        const size_t nd = g->nd[c];
        double *restrict kx = g->col, *restrict kv = kx + nd * n, *restrict kw = kv + nd * n;
        col_coefs(g, c, j0, n, xonly, 1, kx, kv, kw);
        const double *tab[4] = { g->phi[c], g->dphi[c], g->phi[c], g->phi[c] };
        const double *ks[4] = { kx, kx, kv, kw };
        for (int q = 0; q < 4; q++) {
            float *o = outs[q];
            if (!o)
                continue;
            const double *restrict k = ks[q], *restrict t = tab[q];
            switch (nd) {   /* dot_k's cases, the switch out of the loop */
            case 1:
                if (nu == 2) {   /* faces u = 0, 1: both columns at once */
                    const double t0 = t[0], t1 = t[1];
                    for (size_t j = 0; j < n; j++)
                        o[6 * j + c] = (float)(k[j] * t0), o[6 * j + 3 + c] = (float)(k[j] * t1);
                    break;
                }
                for (size_t j = 0; j < n; j++)
                    for (size_t i = 0; i < nu; i++)
                        o[3 * (j * nu + i) + c] = (float)(k[j] * t[i]);
                break;
            case 2:
                if (nu == 2) {
                    const double t0 = t[0], t1 = t[1], u0 = t[2], u1 = t[3];
                    for (size_t j = 0; j < n; j++)
                        o[6 * j + c] = (float)(k[j] * t0 + k[n + j] * u0), o[6 * j + 3 + c] = (float)(k[j] * t1 + k[n + j] * u1);
                    break;
                }
                for (size_t j = 0; j < n; j++)
                    for (size_t i = 0; i < nu; i++)
                        o[3 * (j * nu + i) + c] = (float)(k[j] * t[i] + k[n + j] * t[nu + i]);
                break;
            default:
                for (size_t j = 0; j < n; j++)
                    for (size_t i = 0; i < nu; i++)
                        o[3 * (j * nu + i) + c] = dot_k(k + j, n, t + i, nu, nd);
            }
        }
    }
}

/* A wide grid's row from its coefficients in g->k: the arrays asked for, from out + off each. */
static void emit_row(const pde_grid *g, size_t off, float *xyz, float *xu, float *xv, float *xw)
{
    const size_t nu = g->nu;
    const double *phi[3] = { g->phi[0], g->phi[1], g->phi[2] };
    const double *dphi[3] = { g->dphi[0], g->dphi[1], g->dphi[2] };
    const double *kx[3], *kv[3], *kw[3];
    for (int c = 0; c < 3; c++) {
        kx[c] = g->k[c];
        kv[c] = g->k[c] + g->nd[c];
        kw[c] = g->k[c] + 2 * g->nd[c];
    }
    if (xyz)
        emit(xyz + off, nu, phi, kx, g->nd);
    if (xu)
        emit(xu + off, nu, dphi, kx, g->nd);
    if (xv)
        emit(xv + off, nu, phi, kv, g->nd);
    if (xw)
        emit(xw + off, nu, phi, kw, g->nd);
}

/*
 * Rows j0 <= j < j1 of a wide grid of many modes, BLK_ROWS at a time: their coefficients by col_coefs
 * (each mode's v-factors read along contiguous v), then each row's emit() as pde_grid_rows' own. Row by
 * row, grid_coefs read one double of each mode's table row in turn, a cache line per mode: 8 to 10 ns a
 * mode and row once the tables outgrew L1 (a loft of 2049 modes at 256 per axis: 1.6 s of f32, of which
 * grid_coefs 81%). The sums are grid_coefs' in the same order: the same values.
 */
static void grid_blocks(pde_grid *g, size_t j0, size_t j1, float *xyz, float *xu, float *xv, float *xw)
{
    const int xonly = !xu && !xv && !xw;
    for (size_t jb = j0; jb < j1; jb += BLK_ROWS) {
        const size_t n = j1 - jb < BLK_ROWS ? j1 - jb : BLK_ROWS;
        double *b[3];
        for (int c = 0, off = 0; c < 3; off += 3 * (int)g->nd[c] * BLK_ROWS, c++) {
            b[c] = g->blk + off;
            col_coefs(g, c, jb, n, xonly, 1, b[c], b[c] + g->nd[c] * n, b[c] + 2 * g->nd[c] * n);
        }
        for (size_t j = 0; j < n; j++) {
            for (int c = 0; c < 3; c++) {
                const size_t nd = g->nd[c];
                double *k = g->k[c];
                for (size_t d = 0; d < nd; d++) {
                    k[d] = b[c][d * n + j];
                    if (!xonly)
                        k[nd + d] = b[c][(nd + d) * n + j], k[2 * nd + d] = b[c][(2 * nd + d) * n + j];
                }
            }
            emit_row(g, 3 * (jb + j - j0) * g->nu, xyz, xu, xv, xw);
        }
    }
}

void pde_grid_rows(pde_grid *g, double w, size_t j0, size_t j1, float *xyz, float *xu, float *xv,
                   float *xw)
{
    const size_t nu = g->nu;
    if (g->col) {
        const size_t end = j1 < g->nv ? j1 : g->nv;
        float *const outs[4] = { xyz, xu, xv, xw };
        grid_set_w(g, w);
        if (j0 < end)
            grid_cols(g, j0, end, outs);
        return;
    }
    grid_set_w(g, w);
    if (g->blk) {
        grid_blocks(g, j0, j1 < g->nv ? j1 : g->nv, xyz, xu, xv, xw);
        return;
    }
    for (size_t j = j0; j < j1 && j < g->nv; j++) {
        grid_coefs(g, j);
        emit_row(g, 3 * (j - j0) * nu, xyz, xu, xv, xw);
    }
}

void pde_grid_plane_d(pde_grid *g, double w, float *xyz, float *xu, float *xv, float *xw)
{
    pde_grid_rows(g, w, 0, g->nv, xyz, xu, xv, xw);
}

void pde_grid_plane(pde_grid *g, double w, float *xyz)
{
    pde_grid_plane_d(g, w, xyz, NULL, NULL, NULL);
}

void pde_grid_row_d(pde_grid *g, double w, size_t j, double *xyz, double *xu, double *xv, double *xw)
{
    double *const outs[4] = { xyz, xu, xv, xw };   /* GRID_X, GRID_XU, GRID_XV, GRID_XW */
    unsigned want = 0;
    for (int a = 0; a < 4; a++)
        want |= outs[a] ? 1u << a : 0u;
    grid_set_w(g, w);
    grid_row(g, j, want);
    for (int a = 0; a < 4; a++) {
        if (!outs[a])
            continue;
        for (int c = 0; c < 3; c++)
            for (size_t i = 0; i < g->nu; i++)
                outs[a][3 * i + c] = g->row[(3 * a + c) * g->nu + i];
    }
}

pde_status pde_sample(const pde_solution *sol, size_t nu, size_t nv, size_t nw, float *out)
{
    if (!sol || !out || nu == 0 || nv == 0 || nw == 0)
        return PDE_ERR_INVALID;
    double *us = malloc((nu + nv) * sizeof *us);
    if (!us)
        return PDE_ERR_NOMEM;
    double *vs = us + nu;
    for (size_t i = 0; i < nu; i++)
        us[i] = nu > 1 ? (double)i / (double)(nu - 1) : 0.5;
    for (size_t j = 0; j < nv; j++)
        vs[j] = nv > 1 ? (double)j / (double)(nv - 1) : 0.5;
    pde_grid *g;
    pde_status st = pde_grid_create(sol, us, nu, vs, nv, &g);
    free(us);
    if (st != PDE_OK)
        return st;
    for (size_t k = 0; k < nw; k++)
        pde_grid_plane(g, nw > 1 ? (double)k / (double)(nw - 1) : 0.5, out + 3 * nu * nv * k);
    pde_grid_free(g);
    return PDE_OK;
}
