/*
 * eval.c: evaluation of a solution at points, and tensor-product sampling.
 *
 * x_i(u,v,w) = sum over modes h(w) f_u(u) f_v(v) (eq. 4). A grid evaluates
 * each f_u and f_v once per sample and each h once per plane, so the inner
 * loop is one multiply-add per mode and point, over contiguous memory.
 */
#include <math.h>
#include <stdlib.h>

#include "internal.h"

void pde_eval_d(const pde_solution *sol, double u, double v, double w,
                double x[3], double xu[3], double xv[3], double xw[3])
{
    for (int c = 0; c < 3; c++) {
        const comp_solution *cs = &sol->comp[c];
        double s = 0.0, su = 0.0, sv = 0.0, sw = 0.0;
        for (size_t m = 0; m < cs->nmodes; m++) {
            const pde_mode *md = &cs->modes[m];
            double fu, dfu, fv, dfv, h, dh;
            factor_eval(md->u, u, &fu, &dfu);
            factor_eval(md->v, v, &fv, &dfv);
            mode_h(md, w, &h, &dh);
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
        for (size_t k = 0; k < md->nterms; k++)
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
        free(g->phi[c]);
        free(g->psi[c]);
        free(g->h[c]);
    }
    free(g->row);
    free(g->coef);
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
    g->maxm = 1;
    for (int c = 0; c < 3; c++)
        if (sol->comp[c].nmodes > g->maxm)
            g->maxm = sol->comp[c].nmodes;
    g->row = malloc(12 * nu * sizeof *g->row);
    g->coef = malloc(3 * g->maxm * sizeof *g->coef);
    if (!g->row || !g->coef)
        goto nomem;
    for (int c = 0; c < 3; c++) {
        size_t nm = sol->comp[c].nmodes, k = nm ? nm : 1;
        g->nm[c] = nm;
        g->phi[c] = malloc(2 * k * nu * sizeof(double));
        g->psi[c] = malloc(2 * k * nv * sizeof(double));
        g->h[c] = malloc(2 * k * sizeof(double));
        if (!g->phi[c] || !g->psi[c] || !g->h[c])
            goto nomem;
        g->dphi[c] = g->phi[c] + k * nu;
        g->dpsi[c] = g->psi[c] + k * nv;
        g->dh[c] = g->h[c] + k;
        for (size_t m = 0; m < nm; m++) {
            const pde_mode *md = &sol->comp[c].modes[m];
            for (size_t i = 0; i < nu; i++)
                factor_eval(md->u, us[i], &g->phi[c][m * nu + i], &g->dphi[c][m * nu + i]);
            for (size_t j = 0; j < nv; j++)
                factor_eval(md->v, vs[j], &g->psi[c][m * nv + j], &g->dpsi[c][m * nv + j]);
        }
    }
    *out = g;
    return PDE_OK;
nomem:
    pde_grid_free(g);
    return PDE_ERR_NOMEM;
}

/* row[i] = sum_m k_m tab[m][i]: the kernel of all sampling. */
static void combine(double *restrict row, const double *restrict tab, const double *restrict k,
                    size_t nm, size_t n)
{
    for (size_t i = 0; i < n; i++)
        row[i] = 0.0;
    for (size_t m = 0; m < nm; m++) {
        const double km = k[m];
        const double *restrict t = tab + m * n;
        for (size_t i = 0; i < n; i++)
            row[i] += km * t[i];
    }
}

static void interleave(float *restrict out, const double *restrict row, size_t n)
{
    const double *x = row, *y = row + n, *z = row + 2 * n;
    for (size_t i = 0; i < n; i++) {
        out[3 * i] = (float)x[i];
        out[3 * i + 1] = (float)y[i];
        out[3 * i + 2] = (float)z[i];
    }
}

void grid_set_w(pde_grid *g, double w)
{
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < g->nm[c]; m++)
            mode_h(&g->sol->comp[c].modes[m], w, &g->h[c][m], &g->dh[c][m]);
}

void grid_row(pde_grid *g, size_t j, unsigned want)
{
    const size_t nu = g->nu, nv = g->nv;
    double *kx = g->coef, *kv = g->coef + g->maxm, *kw = g->coef + 2 * g->maxm;
    for (int c = 0; c < 3; c++) {
        const size_t nm = g->nm[c];
        for (size_t m = 0; m < nm; m++) {
            double p = g->psi[c][m * nv + j];
            kx[m] = g->h[c][m] * p;
            kv[m] = g->h[c][m] * g->dpsi[c][m * nv + j];
            kw[m] = g->dh[c][m] * p;
        }
        if (want & GRID_X)
            combine(g->row + c * nu, g->phi[c], kx, nm, nu);
        if (want & GRID_XU)
            combine(g->row + (3 + c) * nu, g->dphi[c], kx, nm, nu);
        if (want & GRID_XV)
            combine(g->row + (6 + c) * nu, g->phi[c], kv, nm, nu);
        if (want & GRID_XW)
            combine(g->row + (9 + c) * nu, g->phi[c], kw, nm, nu);
    }
}

void pde_grid_plane_d(pde_grid *g, double w, float *xyz, float *xu, float *xv, float *xw)
{
    const size_t nu = g->nu;
    float *outs[4] = { xyz, xu, xv, xw };
    unsigned want = 0;
    for (int q = 0; q < 4; q++)
        if (outs[q])
            want |= 1u << q;
    grid_set_w(g, w);
    for (size_t j = 0; j < g->nv; j++) {
        grid_row(g, j, want);
        for (int q = 0; q < 4; q++)
            if (outs[q])
                interleave(outs[q] + 3 * j * nu, g->row + 3 * nu * q, nu);
    }
}

void pde_grid_plane(pde_grid *g, double w, float *xyz)
{
    pde_grid_plane_d(g, w, xyz, NULL, NULL, NULL);
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
