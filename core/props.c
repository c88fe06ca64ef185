/*
 * props.c: properties of a solved solid, from its closed form (pde.h,
 * docs/MATH.md "Properties").
 *
 * 1. Extremes: a uniform sample, then branch and bound (bound.h) from its
 *    best points, until the certified bound is
 *    within 1e-9 of the solid's size of the best value (or a box budget ends:
 *    the gap says how far it got). A polynomial solid (fig. 1) instead takes
 *    a branch and bound over Bernstein coefficients (poly.h), without sample.
 *    A solid whose properties cannot be finite is refused from these first
 *    values (a polynomial solid's at its corners and centre), before any
 *    branch and bound (beyond_double).
 * 2. Integrals over the solid weighted by |det J| (quad.h): volume, signed
 *    volume, first and second moments about the box's centre, hence the
 *    centroid, the inertia tensor about it and its principal axes (Jacobi).
 * 3. The skin's area (quad.h).
 * 4. The accuracy certificate: the boundary conditions against the model's
 *    own boundary terms, relative to the problem's size and not the
 *    solution's (which an ill-conditioned fit inflates), and the PDE with the
 *    closed form's exact fourth derivatives.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bound.h"
#include "poly.h"
#include "quad.h"

#define SIGN_BOXES 200         /* boxes to certify det J's sign where it touches 0 */
/* A loft's branch and bounds over the face t = 1 (radial_extreme): the tower (99 modes, 32 harmonics)
 * took 2.4k boxes a coordinate, 5k for det J's maximum and 10.7k to certify its minimum, 0 (D1 > 0);
 * the blade 150 to 1000. */
#define RADIAL_BOXES 16000
#define JZERO 1e-10            /* det J's largest sample below this of its terms' magnitude: 0 but for rounding */
#define RADIAL_JSIGN 1e-5      /* of det J's tolerance (1e-9 of its scale): below the sign's 1e-13 */

/*
 * Cancellation: the caller's stop() is polled once per POLL_WORK units of
 * work, a unit being a mode or a coefficient of a w-term evaluated at one
 * point (about 10 ns), so that small solids pay nothing for it and big ones
 * are polled about every millisecond.
 */
#define POLL_WORK 65536

typedef struct {
    const pde_cancel *cancel;
    size_t point;     /* units of one pde_eval_d() */
    size_t modes;     /* modes of the three components */
    size_t work;
    int stopped;
} poller;

/* Counts units of work done; 1 once the caller has asked to stop. */
static int poll_after(poller *p, size_t units)
{
    if (p->stopped)
        return 1;
    p->work += units;
    if (p->work < POLL_WORK)
        return 0;
    p->work = 0;
    return p->stopped = pde_stopped(p->cancel);
}

typedef struct {
    double lo[3], hi[3], lo_at[3][3], hi_at[3][3];
    double jmin, jmax, jmin_at[3], jmax_at[3];
    int overflow;   /* a coordinate or det J was inf or NaN (which no comparison notes) */
} extremes;

static void extremes_init(extremes *e)
{
    for (int c = 0; c < 3; c++) {
        e->lo[c] = DBL_MAX, e->hi[c] = -DBL_MAX;
        for (int a = 0; a < 3; a++)
            e->lo_at[c][a] = e->hi_at[c][a] = e->jmin_at[a] = e->jmax_at[a] = 0.5;
    }
    e->jmin = DBL_MAX;
    e->jmax = -DBL_MAX;
    e->overflow = 0;
}

static void note_point(extremes *e, const double p[3], const double x[3], double dj)
{
    if (!(isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]) && isfinite(dj)))
        e->overflow = 1;
    for (int c = 0; c < 3; c++) {
        if (x[c] < e->lo[c])
            e->lo[c] = x[c], e->lo_at[c][0] = p[0], e->lo_at[c][1] = p[1], e->lo_at[c][2] = p[2];
        if (x[c] > e->hi[c])
            e->hi[c] = x[c], e->hi_at[c][0] = p[0], e->hi_at[c][1] = p[1], e->hi_at[c][2] = p[2];
    }
    if (dj < e->jmin)
        e->jmin = dj, e->jmin_at[0] = p[0], e->jmin_at[1] = p[1], e->jmin_at[2] = p[2];
    if (dj > e->jmax)
        e->jmax = dj, e->jmax_at[0] = p[0], e->jmax_at[1] = p[1], e->jmax_at[2] = p[2];
}

/* Walks a grid over us x vs x ws, noting extremes. */
static pde_status sweep(const pde_solution *s, const double *us, size_t nu, const double *vs,
                        size_t nv, const double *ws, size_t nw, poller *pl, extremes *e)
{
    pde_grid *g;
    pde_status st = pde_grid_create(s, us, nu, vs, nv, &g);
    if (st != PDE_OK)
        return st;
    for (size_t k = 0; k < nw; k++) {
        grid_set_w(g, ws[k]);
        for (size_t j = 0; j < nv; j++) {
            /* A row: coefficients of every mode, four arrays of nu multiply-adds per u-factor. */
            if (poll_after(pl, (j ? 0 : pl->point) + pl->modes * (4 + nu) / 16)) {
                pde_grid_free(g);
                return PDE_ERR_CANCELLED;
            }
            grid_row(g, j, GRID_X | GRID_XU | GRID_XV | GRID_XW);
            for (size_t i = 0; i < nu; i++) {
                double x[3], a[3], b[3], c[3];
                for (int q = 0; q < 3; q++) {
                    x[q] = g->row[q * nu + i];
                    a[q] = g->row[(3 + q) * nu + i];
                    b[q] = g->row[(6 + q) * nu + i];
                    c[q] = g->row[(9 + q) * nu + i];
                }
                double dj = det3(a, b, c);
                const double p[3] = { us[i], vs[j], ws[k] };
                note_point(e, p, x, dj);
            }
        }
    }
    pde_grid_free(g);
    return PDE_OK;
}

/* fmax and fmin without the library call, in the residuals' inner loops (where b may be NaN: a). */
static inline double max2(double a, double b)
{
    return b > a ? b : a;
}

static inline double min2(double a, double b)
{
    return b < a ? b : a;
}

/* The factor along axis a (0: u, 1: v) of a component's k-th mode, then of its force terms (force = 1)
 * or its boundary terms (force = 0). */
static pde_factor term_factor(const comp_solution *cs, int a, int force, size_t k)
{
    if (k < cs->nmodes)
        return a ? cs->modes[k].v : cs->modes[k].u;
    k -= cs->nmodes;
    if (force)
        return a ? cs->fterms[k].v : cs->fterms[k].u;
    return a ? cs->bterms[k].v : cs->bterms[k].u;
}

/*
 * The residuals' samples t[0 .. n - 1] along axis a that decide their largest values. Where every
 * mode of cs and every term (force terms for the PDE, force = 1; boundary terms for the conditions)
 * has the same factor f along a, the residual and each of its terms and scales are |f(t_i)| times
 * a function of the two other parameters (for the PDE, where f'''' = lambda f: every factor but t^n
 * with n >= 4), and so are their sums of absolute values; the largest over the samples is then at
 * the sample of largest |f|, which alone is taken (fig. 2's x, y and z: the PDE residual at 9 of
 * its 729 points, both residuals at the same values up to the rounding of the other samples).
 * Returns the number of samples to take, from *i0 on: n from 0, or 1.
 */
static size_t residual_samples(const comp_solution *cs, int a, int force, const double *t, size_t n, size_t *i0)
{
    const size_t nt = cs->nmodes + (force ? cs->nfterms : cs->nbterms);
    *i0 = 0;
    if (nt == 0)
        return 1;
    const pde_factor f = term_factor(cs, a, force, 0);
    if (force && f.kind == PDE_POW && f.p >= 4.0)
        return n;
    for (size_t k = 1; k < nt; k++) {
        const pde_factor g = term_factor(cs, a, force, k);
        if (g.kind != f.kind || g.p != f.p)
            return n;
    }
    double big = -1.0;
    for (size_t i = 0; i < n; i++) {
        const double v = fabs(factor_deriv(f, t[i], 0));
        if (v > big)
            big = v, *i0 = i;
    }
    return 1;
}

/*
 * The boundary residual: the largest error of x and x_w on res x res points of w = 0 and w = 1,
 * relative to the size of the problem, which must not be the solution's size alone:
 *
 * - near a clamped eigenvalue the boundary fit amplifies: the solution grows like 1/delta and
 *   keeps about 4e-16/delta of its digits; measured against the data, the error shows that loss;
 * - a force (or a chain parent) drives the fit through the particular solution's boundary values;
 *   without boundary terms these are the only scale (the solution is ~0 on w = 0, 1);
 * - but a particular solution much larger than the solution (a w^12 force with e = 6) cancels
 *   against the fit and loses digits in proportion: so the drive counts only up to the solution's
 *   own size, own[c] = max |x_c| over the solid.
 *
 * So scale = max(data, min(drive, own)), data and drive as sums of the absolute values of their
 * terms at each point; own alone for a component with neither. The closed form on w = 0 and 1 is
 * the sum over modes of f_u f_v times h(0), h'(0), h(1), h'(1), each mode's four values once; along u
 * and v it is sampled where residual_samples says (one sample where every term has the same factor).
 */
static pde_status bc_residual(const pde_solution *s, int res, const double own_size[3], poller *pl,
                              double *out)
{
    if (s->nsections) {   /* a loft: its conditions at every section (core/loft.c) */
        *out = loft_bc_residual(s);
        return PDE_OK;
    }
    const size_t n = (size_t)res;
    size_t nt = 0;
    for (int c = 0; c < 3; c++)
        nt = nt > s->comp[c].nmodes + s->comp[c].nbterms ? nt : s->comp[c].nmodes + s->comp[c].nbterms;
    /* per term (modes, then boundary terms) its factors at the samples; per mode h, h' at w = 0, 1 */
    double *uni = malloc((n + 2 * nt * n + 4 * nt) * sizeof *uni);
    if (!uni)
        return PDE_ERR_NOMEM;
    double *fu = uni + n, *fv = fu + nt * n, *hb = fv + nt * n;
    for (size_t i = 0; i < n; i++)
        uni[i] = (double)i / (double)(n - 1);
    double worst = 0.0;
    for (int c = 0; c < 3; c++) {
        const comp_solution *cs = &s->comp[c];
        const size_t nm = cs->nmodes, nb = cs->nbterms;
        size_t i0, j0;
        const size_t ni = residual_samples(cs, 0, 0, uni, n, &i0), nj = residual_samples(cs, 1, 0, uni, n, &j0);
        for (size_t t = 0; t < nm + nb; t++) {
            for (size_t i = i0; i < i0 + ni; i++)
                fu[t * n + i] = factor_deriv(term_factor(cs, 0, 0, t), uni[i], 0);
            for (size_t j = j0; j < j0 + nj; j++)
                fv[t * n + j] = factor_deriv(term_factor(cs, 1, 0, t), uni[j], 0);
        }
        for (size_t m = 0; m < nm; m++) {
            mode_h(&cs->modes[m], 0.0, &hb[4 * m], &hb[4 * m + 1]);
            mode_h(&cs->modes[m], 1.0, &hb[4 * m + 2], &hb[4 * m + 3]);
        }
        double err = 0.0, scale = 0.0;
        for (size_t j = j0; j < j0 + nj; j++) {
            if (poll_after(pl, (2 * nm + nb) * (ni + 2) / 4 + 1)) {
                free(uni);
                return PDE_ERR_CANCELLED;
            }
            for (size_t i = i0; i < i0 + ni; i++) {
                double x[4] = { 0, 0, 0, 0 }, d[4] = { 0, 0, 0, 0 }, dabs[4] = { 0, 0, 0, 0 };
                double drive[4] = { 0, 0, 0, 0 };
                for (size_t m = 0; m < nm; m++) {
                    const double f = fu[m * n + i] * fv[m * n + j];
                    for (int k = 0; k < 4; k++) {
                        x[k] += hb[4 * m + k] * f;
                        drive[k] += fabs(cs->drive[m][k] * f);
                    }
                }
                for (size_t t = 0; t < nb; t++) {
                    const pde_bterm *b = &cs->bterms[t];
                    const double f = fu[(nm + t) * n + i] * fv[(nm + t) * n + j];
                    const double bv[4] = { b->w0, b->dw0, b->w1, b->dw1 };
                    for (int k = 0; k < 4; k++) {
                        d[k] += bv[k] * f;
                        dabs[k] += fabs(bv[k] * f);
                    }
                }
                for (int k = 0; k < 4; k++) {
                    err = max2(err, fabs(x[k] - d[k]));
                    scale = max2(scale, max2(dabs[k], min2(drive[k], own_size[c])));
                }
            }
        }
        const double sc = scale > 0.0 ? scale : own_size[c];
        worst = fmax(worst, sc > 0.0 ? err / sc : err);
    }
    free(uni);
    *out = worst;
    return PDE_OK;
}

/*
 * The PDE residual: the largest |a x_uuuu + b x_vvvv + c x_wwww - p| at res^3 points inside the
 * cube, with the closed form's exact derivatives (those of pde_eval_partial), relative to the
 * largest of the four terms over the points, so that cancellation between large terms is
 * measured against their size. The derivatives of each factor and each h are tabulated once per
 * sample line: a point then costs three multiply-adds per mode.
 */
/* A factor's value and fourth derivative at t: lambda f for every kind but t^n (factor_lambda is
 * factor_deriv's w^4, to the bit), one sin, cos or exp rather than two. */
static void factor_04(pde_factor f, double t, double *v, double *v4)
{
    *v = factor_deriv(f, t, 0);
    *v4 = f.kind == PDE_POW ? factor_deriv(f, t, 4) : factor_lambda(f) * *v;
}

#define RESIDUAL_TWINS 64   /* modes at most among which pde_residual looks for the same h(w) */

static pde_status pde_residual(const pde_solution *s, int res, poller *pl, double *out)
{
    const size_t n = (size_t)res, mt = s->comp[0].nmodes + s->comp[1].nmodes + s->comp[2].nmodes;
    double worst = 0.0;
    /* h and h'''' of every mode at the samples, x's modes then y's and z's: a mode with the same h(w) as
     * an earlier one (fig. 4: each of x's again in y) copies its rows */
    double *hall = malloc((2 * mt * n + n) * sizeof *hall), *ts = hall + 2 * mt * n;
    if (!hall)
        return PDE_ERR_NOMEM;
    for (size_t i = 0; i < n; i++)
        ts[i] = (i + 0.5) / res;
    for (size_t o = 0, c = 0, m = 0; o < mt; o++, m++) {
        while (m >= s->comp[c].nmodes)
            c++, m = 0;
        const pde_mode *md = &s->comp[c].modes[m];
        if (poll_after(pl, n * (4 + md->nterms * 8))) {
            free(hall);
            return PDE_ERR_CANCELLED;
        }
        size_t tw = o;
        for (size_t p = 0, pc = 0, pm = 0; p < o && mt <= RESIDUAL_TWINS && tw == o; p++, pm++) {
            while (pm >= s->comp[pc].nmodes)
                pc++, pm = 0;
            if (quad_same_h(&s->comp[pc].modes[pm], md))
                tw = p;
        }
        for (size_t i = 0; i < n; i++) {
            double h0 = 0.0, hw = 0.0;
            if (tw < o)
                h0 = hall[tw * n + i], hw = hall[(mt + tw) * n + i];
            else {
                const double t = ts[i];
                size_t k0, k1;
                mode_slab(md, t, &k0, &k1);   /* a loft's slab of t */
                for (size_t k = k0; k < k1; k++) {
                    h0 += wterm_deriv(&md->terms[k], t, 0);
                    hw += wterm_deriv(&md->terms[k], t, 4);
                }
            }
            hall[o * n + i] = h0, hall[(mt + o) * n + i] = hw;
        }
    }
    for (int c = 0, off = 0; c < 3; off += (int)s->comp[c].nmodes, c++) {
        const comp_solution *cs = &s->comp[c];
        const size_t nm = cs->nmodes;
        if (nm == 0 && cs->nfterms == 0)
            continue;
        /* Per mode and sample: f_u, its fourth derivative, f_v, its fourth, h, its fourth; then per mode
         * the products of the u- and v-factors of the three terms on the current (u, v). The force's
         * terms likewise: each factor at the samples, and per term coef f_u f_v on the current (u, v)
         * (pde_force's values, in its order, without its three factor evaluations a point). */
        const size_t nf = cs->nfterms;
        double *tab = malloc((4 * nm * n + 3 * nm + 3 * nf * n + nf + 1) * sizeof *tab);
        if (!tab) {
            free(hall);
            return PDE_ERR_NOMEM;
        }
        double *fu = tab, *fu4 = fu + nm * n, *fv = fu4 + nm * n, *fv4 = fv + nm * n, *uv = fv4 + nm * n;
        const double *h = hall + off * n, *h4 = hall + (mt + off) * n;
        double *pu = uv + 3 * nm, *pv = pu + nf * n, *pw = pv + nf * n, *puv = pw + nf * n;
        size_t i0, j0;
        const size_t ni = residual_samples(cs, 0, 1, ts, n, &i0), nj = residual_samples(cs, 1, 1, ts, n, &j0);
        for (size_t t = 0; t < nf; t++) {
            const pde_fterm *ft = &cs->fterms[t];
            for (size_t i = 0; i < n; i++) {
                pu[t * n + i] = i >= i0 && i < i0 + ni ? factor_deriv(ft->u, ts[i], 0) : 0.0;
                pv[t * n + i] = i >= j0 && i < j0 + nj ? factor_deriv(ft->v, ts[i], 0) : 0.0;
                pw[t * n + i] = factor_deriv(ft->w, ts[i], 0);
            }
        }
        for (size_t m = 0; m < nm; m++) {
            const pde_mode *md = &cs->modes[m];
            for (size_t i = i0; i < i0 + ni; i++)
                factor_04(md->u, ts[i], &fu[m * n + i], &fu4[m * n + i]);
            for (size_t j = j0; j < j0 + nj; j++)
                factor_04(md->v, ts[j], &fv[m * n + j], &fv4[m * n + j]);
        }
        double err = 0.0, scale = 0.0;
        for (size_t i = i0; i < i0 + ni; i++)
            for (size_t j = j0; j < j0 + nj; j++) {
                if (poll_after(pl, n * (nm + cs->nfterms))) {
                    free(tab);
                    free(hall);
                    return PDE_ERR_CANCELLED;
                }
                for (size_t m = 0; m < nm; m++) {
                    const double a = fu[m * n + i], b = fv[m * n + j];
                    uv[3 * m] = fu4[m * n + i] * b, uv[3 * m + 1] = a * fv4[m * n + j], uv[3 * m + 2] = a * b;
                }
                for (size_t t = 0; t < nf; t++)
                    puv[t] = cs->fterms[t].coef * pu[t * n + i] * pv[t * n + j];
                for (size_t k = 0; k < n; k++) {
                    double tu = 0.0, tv = 0.0, tw = 0.0;
                    for (size_t m = 0; m < nm; m++) {
                        tu += uv[3 * m] * h[m * n + k];
                        tv += uv[3 * m + 1] * h[m * n + k];
                        tw += uv[3 * m + 2] * h4[m * n + k];
                    }
                    tu *= cs->a, tv *= cs->b, tw *= cs->c;
                    double p = 0.0;
                    for (size_t t = 0; t < nf; t++)
                        p += puv[t] * pw[t * n + k];
                    err = max2(err, fabs(tu + tv + tw - p));
                    scale = max2(scale, max2(max2(fabs(tu), fabs(tv)), max2(fabs(tw), fabs(p))));
                }
            }
        free(tab);
        worst = fmax(worst, scale > 0.0 ? err / scale : err);
    }
    free(hall);
    *out = worst;
    return PDE_OK;
}

void pde_properties_nodes(const pde_solution *s, size_t nodes[3])
{
    int np[3], n[3];
    quad_panels(s, np, n);
    for (int a = 0; a < 3; a++)
        nodes[a] = (size_t)np[a] * (size_t)n[a];
}

int pde_properties_flat_axis(const pde_solution *s)
{
    quad_sep sp;
    quad_separate(s, &sp);
    return sp.axis;
}

int pde_properties_free_axis(const pde_solution *s)
{
    quad_sep sp;
    quad_separate(s, &sp);
    return sp.free;
}

/*
 * Eigenvalues (ascending) and unit eigenvectors (rows) of a symmetric 3 x 3 matrix, by cyclic
 * Jacobi rotations (Golub and Van Loan, section 8.5): accurate to rounding for every spectrum.
 * The axes form a right-handed frame; the first two have their largest component positive.
 */
static void eigen_sym3(const double A[3][3], double val[3], double vec[3][3])
{
    double a[3][3], v[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
    memcpy(a, A, sizeof a);
    for (int sweep_ = 0; sweep_ < 50; sweep_++) {
        double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
        if (off == 0.0)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (a[p][q] == 0.0)
                    continue;
                double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                double t = fabs(theta) > 1e150 ? 0.5 / theta   /* theta^2 would overflow */
                                               : (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), sn = t * c;
                for (int k = 0; k < 3; k++) {   /* a = J' a J */
                    double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - sn * akq;
                    a[k][q] = sn * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) {
                    double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - sn * aqk;
                    a[q][k] = sn * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) {
                    double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - sn * vkq;
                    v[k][q] = sn * vkp + c * vkq;
                }
            }
    }
    int ord[3] = { 0, 1, 2 };
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (a[ord[j]][ord[j]] < a[ord[i]][ord[i]]) {
                int t = ord[i];
                ord[i] = ord[j], ord[j] = t;
            }
    for (int i = 0; i < 3; i++) {
        val[i] = a[ord[i]][ord[i]];
        for (int k = 0; k < 3; k++)
            vec[i][k] = v[k][ord[i]];
    }
    for (int i = 0; i < 2; i++) {
        int big = 0;
        for (int k = 1; k < 3; k++)
            if (fabs(vec[i][k]) > fabs(vec[i][big]))
                big = k;
        if (vec[i][big] < 0)
            for (int k = 0; k < 3; k++)
                vec[i][k] = -vec[i][k];
    }
    vec[2][0] = vec[0][1] * vec[1][2] - vec[0][2] * vec[1][1];
    vec[2][1] = vec[0][2] * vec[1][0] - vec[0][0] * vec[1][2];
    vec[2][2] = vec[0][0] * vec[1][1] - vec[0][1] * vec[1][0];
}

/* Volume, signed volume, centroid, inertia and principal axes from the integrals about x0. */
static void mass_properties(const quad_result *q, const double x0[3], pde_props *r)
{
    const double V = q->acc[Q_VOL];
    r->volume = V;
    r->signed_volume = q->acc[Q_SIGNED];
    double d[3] = { 0, 0, 0 }, S[3][3];
    for (int i = 0; i < 3; i++) {
        d[i] = V > 0.0 ? q->acc[Q_M1 + i] / V : 0.0;
        r->centroid[i] = x0[i] + d[i];
    }
    /* Second moments about x0 (r0r0, r1r1, r2r2, r0r1, r0r2, r1r2), then about the centroid. */
    static const int pi[6] = { 0, 1, 2, 0, 0, 1 }, pj[6] = { 0, 1, 2, 1, 2, 2 };
    for (int k = 0; k < 6; k++)
        S[pi[k]][pj[k]] = S[pj[k]][pi[k]] = q->acc[Q_M2 + k] - V * d[pi[k]] * d[pj[k]];
    double tr = S[0][0] + S[1][1] + S[2][2];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r->inertia[i][j] = (i == j ? tr : 0.0) - S[i][j];
    eigen_sym3(r->inertia, r->principal_moments, r->principal_axes);
}

/*
 * What the integrals' error may be, relative (docs/MATH.md, "The integrals' error"): the signed
 * volume by the solid's rules against the same by the faces' (divergence theorem), which shows
 * whether the rules resolve the solid's frequencies; 1e-12, the refinement's tolerance, where det J
 * may change sign; for panels where det J may change sign left
 * unrefined by the work's bound, what refinement changed on the refined ones, on average, times their
 * number (1e-4 of the volume when none was refined: the unrefined error measured on fig. 4l); at least
 * 1e-2 when lines stopped locating roots; at least the rules' a-priori error when the work's bound made
 * them coarser than the solid's frequencies.
 */
static double integral_error(const quad_result *q, const quad_result *qa)
{
    const double vol = fmax(fabs(q->acc[Q_VOL]), DBL_MIN);
    double e = fabs(q->acc[Q_SIGNED] - qa->acc[Q_SIGNED]) / vol;
    if (q->lined)
        e += 1e-12;   /* the refinement's tolerance where det J may change sign */
    e += q->refine_left / vol;   /* boxes whose last refinement still changed their volume */
    if (q->unrefined)
        e += q->refined ? q->unrefined * q->refine_change / q->refined / vol : 1e-4;
    if (q->roots_skipped || qa->roots_skipped)
        e = fmax(e, 1e-2);
    /* The signed volume multiplies three factors, the second moments five: where the work's bound
     * made the rules coarser than the fastest of those, their a-priori error stands (pessimistic);
     * where they resolve them, their estimate (a loft's periodic path: its rows' Legendre tails) is
     * the least said, as two signed volumes agreeing to every digit do not make the integrals exact. */
    const double rules = fmax(q->err, qa->err);
    e = fmax(e, rules);
    return e == e ? fmin(e, 1.0) : 1.0;
}

/*
 * What the area's error may be, relative (docs/MATH.md, "The area's error"): harm.c's faces' tolerance
 * over w, plus what the last halving changed on every face panel whose refinement stopped (the error
 * left is about that or less: it falls at least as h^2 along a cusp, h^3 at a cone point), plus 1e-2
 * of the estimate of each panel accepted without halving, plus for panels the work's bound left
 * unrefined what refinement changed on the others, on average; at least the rules' a-priori error, and
 * 1e-2 where lines stopped locating the element's roots. Pessimistic (fig. 3b: 1.1e-7 where it is
 * 1.6e-10 off), but never below the miss on 109 random folding solids.
 */
static double area_error(const quad_result *qa, double area)
{
    double e = qa->area_left / fmax(fabs(area), DBL_MIN);
    e = fmax(e, qa->err);
    if (qa->roots_skipped)
        e = fmax(e, 1e-2);
    return e == e ? fmin(e, 1.0) : 1.0;
}

/*
 * A component whose modes all share the factor t^n (n >= 0) along one of u, v (axis a) and have sin
 * or cos of one frequency k >= 2 along the other (b): x_c = t_a^n (alpha(w) sin k pi t_b + beta(w)
 * cos k pi t_b), alpha the sum of the sin modes' h, beta of the cos modes' (fig. 4's x and y, fig. 2's
 * too). The harmonic runs a whole period over [0, 1], so at fixed (t_a, w) it spans
 * t_a^n [-R, R] exactly, R = sqrt(alpha^2 + beta^2), and x_c's extremes are -+ max_w R(w), at t_a = 1:
 * a problem in w alone (docs/MATH.md, "Harmonic components").
 */
typedef struct {
    int a, b;                 /* the axes of t^n and of the harmonic */
    double n, k;
    size_t nmodes;
    const pde_mode *modes;
    double M4[2];             /* bounds of |alpha''''|, |beta''''| over [0, 1] (sums over the modes) */
} harmonic;

static int harmonic_of(const pde_solution *s, int c, harmonic *hc)
{
    const comp_solution *cs = &s->comp[c];
    if (cs->nmodes == 0)
        return 0;
    for (int a = 0; a < 2; a++) {
        const pde_factor fa = a ? cs->modes[0].v : cs->modes[0].u, fb = a ? cs->modes[0].u : cs->modes[0].v;
        int ok = fa.kind == PDE_POW && (fb.kind == PDE_SIN || fb.kind == PDE_COS) && fb.p >= 2.0;
        for (size_t m = 1; m < cs->nmodes && ok; m++) {
            const pde_factor ga = a ? cs->modes[m].v : cs->modes[m].u, gb = a ? cs->modes[m].u : cs->modes[m].v;
            ok = ga.kind == PDE_POW && ga.p == fa.p && (gb.kind == PDE_SIN || gb.kind == PDE_COS) && gb.p == fb.p;
        }
        if (ok) {
            *hc = (harmonic){ a, 1 - a, fa.p, fb.p, cs->nmodes, cs->modes, { 0.0, 0.0 } };
            for (size_t m = 0; m < cs->nmodes; m++) {
                double d[5];
                mode_h_bounds(&cs->modes[m], 0.0, 1.0, 4, d);
                hc->M4[(a ? cs->modes[m].u : cs->modes[m].v).kind == PDE_COS] += d[4];
            }
            return 1;
        }
    }
    return 0;
}

static int harmonic_is_cos(const harmonic *hc, size_t m)
{
    return (hc->b ? hc->modes[m].v : hc->modes[m].u).kind == PDE_COS;
}

/*
 * Taylor models along w about a point c: f(c + d) = p0 + p1 d + p2 d^2 + e(d), |e(d)| <= k |d|^3 for
 * |d| <= r. From a function's value and first two derivatives at c and a bound T of |f'''| over the
 * interval, k = T / 6 (Lagrange's rest). Sums and products keep the form (a product's terms of
 * degree 3 and 4 and the rests' cross terms go to k), so a bound of a combination holds pointwise
 * too: near c, where p1 is small, it is as tight as the quadratic, however wide the interval.
 */
typedef struct {
    double p[3], k;
} tm1;

static tm1 tm_jet(const double d[3], double T)
{
    return (tm1){ { d[0], d[1], 0.5 * d[2] }, T / 6.0 };
}

/* max |p0 + p1 d + p2 d^2| over |d| <= r */
static double tm_polymax(const tm1 *a, double r)
{
    return fabs(a->p[0]) + r * (fabs(a->p[1]) + r * fabs(a->p[2]));
}

static tm1 tm_add(tm1 a, const tm1 *b, double sb)
{
    for (int i = 0; i < 3; i++)
        a.p[i] += sb * b->p[i];
    a.k += b->k;
    return a;
}

static tm1 tm_mul(const tm1 *a, const tm1 *b, double r)
{
    const double *x = a->p, *y = b->p;
    const double c3 = x[1] * y[2] + x[2] * y[1], c4 = x[2] * y[2];
    return (tm1){ { x[0] * y[0], x[0] * y[1] + x[1] * y[0], x[0] * y[2] + x[1] * y[1] + x[2] * y[0] },
                  fabs(c3) + r * fabs(c4) + tm_polymax(a, r) * b->k + tm_polymax(b, r) * a->k + a->k * b->k * r * r * r };
}

/* min over [0, R] of q0 + q1 s + q2 s^2 - k s^3: at an end or where the derivative vanishes. */
static double cubic_min(double q0, double q1, double q2, double k, double R)
{
    double m = fmin(q0, q0 + R * (q1 + R * (q2 - k * R))), s[2] = { -1.0, -1.0 };
    const double disc = q2 * q2 + 3.0 * k * q1;
    if (k > 0.0 && disc >= 0.0) {
        const double t = q2 + copysign(sqrt(disc), q2);   /* the roots without cancellation */
        if (t != 0.0)
            s[0] = t / (3.0 * k), s[1] = -q1 / t;
    } else if (k == 0.0 && q2 != 0.0)
        s[0] = -q1 / (2.0 * q2);
    for (int i = 0; i < 2; i++)
        if (s[i] > 0.0 && s[i] < R)
            m = fmin(m, q0 + s[i] * (q1 + s[i] * (q2 - k * s[i])));
    return m;
}

/* A function of w alone to minimise: its Taylor model about c over [w0, w1] (w0 <= c <= w1), its value at w. */
typedef struct {
    void (*model)(const void *ctx, double w0, double w1, double c, tm1 *m);
    double (*value)(const void *ctx, double w);
    const void *ctx;
} line_fn;

typedef struct {
    double key;   /* first: bb_heap's; the parent's lower bound */
    double w0, w1;
    double v0, v1;   /* sign f at w0 and w1 where known (a slab's end, a parent's centre), else NaN */
} lbox;

/*
 * min over [0, 1] of sign f by branch and bound over intervals of w (a loft's slabs first: a model
 * holds within one), from start: *lower certified (for the exact closed form), *best = sign f(*wbest),
 * best - lower <= tol / 2 (a margin for the caller's pad) unless `budget` intervals ran out. An
 * interval's model is about the best point found when it holds it, else about an end where f is
 * known to be as low (within tol: a second minimum, as fig. 2's det J = 0 at w = 1 beside the best
 * point w = 0, where Z' = 0 at both), else about its centre; its bound is the model's least value
 * with the rest pointwise, so the interval holding the minimum closes as soon as the quadratic
 * dominates the rest there, not when the rest falls below tol (about a minimum at an end, the slope
 * away from it dominates: fig. 2a's det J closed on w = 1 in 2 intervals where centres took 11). The
 * quadratic's own argmin is evaluated too: a Newton step, the best point converging as fast.
 */
static pde_status line_minimise(const pde_solution *s, const line_fn *f, double sign, double start, double tol,
                                size_t budget, const pde_cancel *cancel, double *lower, double *best, double *wbest)
{
    double low = DBL_MAX, b = sign * f->value(f->ctx, start);   /* low: over the intervals dropped */
    *wbest = start;
    bb_heap h = { .size = sizeof(lbox) };
    size_t nslabs, boxes = 0;
    const double *br = solution_breaks(s, &nslabs);
    pde_status st = PDE_OK;
    for (size_t k = 0; k < nslabs && st == PDE_OK; k++) {
        const lbox l = { -INFINITY, br[k], br[k + 1], NAN, NAN };
        if (bb_heap_push(&h, &l))
            st = PDE_ERR_NOMEM;
    }
    tol *= 0.5;
    while (st == PDE_OK && h.n && bb_heap_min(&h) < b - tol && boxes < budget) {
        if ((++boxes & 15) == 0 && pde_stopped(cancel)) {
            st = PDE_ERR_CANCELLED;
            break;
        }
        lbox top;
        bb_heap_pop(&h, &top);
        /* about the best point where it lies inside (a loft's slab ends belong to the next slab) */
        const double mid = 0.5 * (top.w0 + top.w1), wb = *wbest;
        double c = mid;
        if ((wb > top.w0 && wb < top.w1) || (nslabs == 1 && wb >= top.w0 && wb <= top.w1))
            c = wb;
        else {
            /* where the best point is an end of [0, 1], the other end evaluated when first needed (once:
             * the children keep it): a minimum at both ends is no coincidence (fig. 2's det J) */
            for (int e = 0; e < 2; e++) {
                double *v = e ? &top.v1 : &top.v0;
                const double we = e ? top.w1 : top.w0;
                if (isnan(*v) && we == br[e ? nslabs : 0] && wb == br[e ? 0 : nslabs]) {
                    *v = sign * f->value(f->ctx, we);
                    if (*v < b)
                        b = *v, *wbest = we;
                }
            }
        }
        if (c == mid && (top.v0 <= b + tol || top.v1 <= b + tol))
            c = top.v0 <= top.v1 || !(top.v1 <= b + tol) ? top.w0 : top.w1;
        tm1 m;
        f->model(f->ctx, top.w0, top.w1, c, &m);
        const double q0 = sign * m.p[0], q1 = sign * m.p[1], q2 = sign * m.p[2];
        if (q0 < b)
            b = q0, *wbest = c;
        const double lb = fmin(cubic_min(q0, q1, q2, m.k, top.w1 - c), cubic_min(q0, -q1, q2, m.k, c - top.w0));
        if (!(lb == lb)) {   /* NaN: no bound (the caller's general path) */
            st = PDE_ERR_INVALID;
            break;
        }
        /* the quadratic's argmin within the interval: a better value there */
        double dm = q1 > 0.0 ? top.w0 - c : top.w1 - c;
        if (q2 > 0.0)
            dm = fmin(fmax(-q1 / (2.0 * q2), top.w0 - c), top.w1 - c);
        if (dm != 0.0 && q0 + dm * (q1 + q2 * dm) < b) {
            const double x = sign * f->value(f->ctx, c + dm);
            if (x < b)
                b = x, *wbest = c + dm;
        }
        if (lb >= b - tol || top.w1 - top.w0 <= 2.0 * DBL_EPSILON * fabs(mid)) {
            low = fmin(low, lb);
            continue;
        }
        const double vm = c == mid ? q0 : NAN;
        const lbox lo = { lb, top.w0, mid, top.v0, vm }, hi = { lb, mid, top.w1, vm, top.v1 };
        if (bb_heap_push(&h, &lo) || bb_heap_push(&h, &hi))
            st = PDE_ERR_NOMEM;
    }
    if (st == PDE_OK) {
        if (h.n)
            low = fmin(low, bb_heap_min(&h));
        *lower = fmin(low, b), *best = b;
    }
    free(h.a);
    return st;
}

/*
 * The models of alpha and beta about c over [w0, w1] (m[0], m[1]), their third derivatives bounded
 * by |alpha'''(c)| + r M4 (r = max |w - c|): no bound of each mode over each interval, and near c as
 * tight as the sum's own value (a mode's bound loses the cancellation between its terms).
 */
static void harmonic_models_of(const harmonic *hc, double w0, double w1, double c, const int *twin,
                               const double (*known)[4], double (*jet)[4], tm1 m[2])
{
    const double r = fmax(c - w0, w1 - c);
    double j[2][4] = { { 0, 0, 0, 0 }, { 0, 0, 0, 0 } };
    for (size_t k = 0; k < hc->nmodes; k++) {
        double e[4];
        const double *d = e;
        const int i = harmonic_is_cos(hc, k);
        if (twin && twin[k] >= 0)
            d = known[twin[k]];
        else
            mode_h_derivs(&hc->modes[k], c, 3, jet ? (double *)(d = jet[k]) : e);
        j[i][0] += d[0], j[i][1] += d[1], j[i][2] += d[2], j[i][3] += d[3];
    }
    for (int i = 0; i < 2; i++)
        m[i] = tm_jet(j[i], fabs(j[i][3]) + r * hc->M4[i]);
}

static void harmonic_models(const harmonic *hc, double w0, double w1, double c, tm1 m[2])
{
    harmonic_models_of(hc, w0, w1, c, NULL, NULL, NULL, m);
}

/* alpha and beta at w, from the modes' h there (hv; NULL: mode_h's). */
static void harmonic_ab_of(const harmonic *hc, const double *hv, double w, double ab[2])
{
    ab[0] = ab[1] = 0.0;
    for (size_t m = 0; m < hc->nmodes; m++) {
        double h, dh;
        if (hv)
            h = hv[m];
        else
            mode_h(&hc->modes[m], w, &h, &dh);
        ab[harmonic_is_cos(hc, m)] += h;
    }
}

static void harmonic_ab(const harmonic *hc, double w, double ab[2])
{
    harmonic_ab_of(hc, NULL, w, ab);
}

/* R^2 = alpha^2 + beta^2, for line_minimise. */
static void r2_model(const void *ctx, double w0, double w1, double c, tm1 *m)
{
    const double r = fmax(c - w0, w1 - c);
    tm1 ab[2];
    harmonic_models(ctx, w0, w1, c, ab);
    const tm1 a2 = tm_mul(&ab[0], &ab[0], r), b2 = tm_mul(&ab[1], &ab[1], r);
    *m = tm_add(a2, &b2, 1.0);
}

static double r2_value(const void *ctx, double w)
{
    double ab[2];
    harmonic_ab(ctx, w, ab);
    return ab[0] * ab[0] + ab[1] * ab[1];
}

/*
 * max_w R(w), R = sqrt(alpha^2 + beta^2): *upper certified, *wbest where the largest R found is.
 * line_minimise's tolerance on R^2 is 2 R tol at the start's R, which R only exceeds: R's gap stays
 * within tol.
 */
static pde_status harmonic_max(const pde_solution *s, const harmonic *hc, double start, double tol, size_t budget,
                               const pde_cancel *cancel, double *upper, double *wbest)
{
    const line_fn f = { r2_model, r2_value, hc };
    const double tol2 = tol * fmax(2.0 * sqrt(r2_value(hc, start)), tol);
    double lo, b;
    pde_status st = line_minimise(s, &f, -1.0, start, tol2, budget, cancel, &lo, &b, wbest);
    if (st == PDE_OK)
        *upper = sqrt(fmax(-lo, 0.0));
    return st;
}

/* The place of the min (e = 0) or max (1) of x_c at w, where alpha, beta are ab: t_a = 1, and the
 * harmonic's phase k pi t_b = phi (max) or phi + pi (min), phi = atan2(alpha, beta), within [0, 2 pi). */
static void harmonic_place(const harmonic *hc, double w, const double ab[2], int e, double at[3])
{
    double th = fmod(atan2(ab[0], ab[1]) + (e ? 2.0 : 3.0) * M_PI, 2.0 * M_PI);
    at[hc->a] = 1.0, at[hc->b] = fmin(th / (hc->k * M_PI), 1.0), at[2] = w;
}

/*
 * The extremes of such a component (bound, best, at: as single_mode_extremes'); PDE_ERR_INVALID where
 * it is not one (or its bound is no number). start: a w to begin from.
 */
/* The modes of a whose factor is (not) cos (ia) are b's of ib, one by one with the same h(w). */
static int same_modes(const harmonic *a, int ia, const harmonic *b, int ib)
{
    size_t i = 0, k = 0;
    for (;; i++, k++) {
        while (i < a->nmodes && harmonic_is_cos(a, i) != ia)
            i++;
        while (k < b->nmodes && harmonic_is_cos(b, k) != ib)
            k++;
        if (i == a->nmodes || k == b->nmodes)
            return i == a->nmodes && k == b->nmodes;
        if (!quad_same_h(&a->modes[i], &b->modes[k]))
            return 0;
    }
}

/* A harmonic's largest R(w) found, for another component with the same R^2 = alpha^2 + beta^2 term by
 * term (fig. 4's y = h2 sin + h1 cos beside x = h1 sin + h2 cos: alpha and beta swapped): its search
 * would be the same, point by point, from the same start. */
typedef struct {
    int done;
    harmonic hc;
    double start, tol, up, w;
    size_t budget;
} harmonic_memo;

static pde_status harmonic_extremes(const pde_solution *s, int c, const harmonic *known, double start, double tol,
                                    size_t budget, const pde_cancel *cancel, harmonic_memo *memo, double bound[2],
                                    double best[2], double at[2][3])
{
    harmonic hc;
    if (known)
        hc = *known;
    else if (!harmonic_of(s, c, &hc))
        return PDE_ERR_INVALID;
    double up, w, ab[2];
    const harmonic *p = memo && memo->done ? &memo->hc : NULL;
    if (p && memo->start == start && memo->tol == tol && memo->budget == budget &&
        ((same_modes(p, 0, &hc, 0) && same_modes(p, 1, &hc, 1)) || (same_modes(p, 0, &hc, 1) && same_modes(p, 1, &hc, 0))))
        up = memo->up, w = memo->w;
    else {
        pde_status st = harmonic_max(s, &hc, start, tol, budget, cancel, &up, &w);
        if (st != PDE_OK)
            return st;
        if (memo)
            *memo = (harmonic_memo){ 1, hc, start, tol, up, w, budget };
    }
    harmonic_ab(&hc, w, ab);
    for (int e = 0; e < 2; e++) {
        double x[3];
        harmonic_place(&hc, w, ab, e, at[e]);
        pde_eval(s, at[e][0], at[e][1], at[e][2], x);
        best[e] = x[c];
    }
    bound[0] = fmin(-up, best[0]), bound[1] = fmax(up, best[1]);
    return PDE_OK;
}

pde_status props_harmonic_extremes(const pde_solution *s, int c, double start, double tol, size_t budget,
                                   const pde_cancel *cancel, double bound[2], double best[2], double at[2][3])
{
    return harmonic_extremes(s, c, NULL, start, tol, budget, cancel, NULL, bound, best, at);
}

/* Non-zero when every mode of the component has the factors 1 along u and v: x_c = Z(w) (fig. 2's and 4's z). */
static int w_only(const comp_solution *cs)
{
    for (size_t m = 0; m < cs->nmodes; m++)
        if (cs->modes[m].u.kind != PDE_POW || cs->modes[m].u.p != 0.0 || cs->modes[m].v.kind != PDE_POW ||
            cs->modes[m].v.p != 0.0)
            return 0;
    return 1;
}

/* Z's model (derivative 0) or Z''s (1), about c over [w0, w1]. */
static tm1 w_only_model(const comp_solution *cs, int der, double w0, double w1, double c)
{
    double j[3] = { 0, 0, 0 }, T = 0.0;
    for (size_t k = 0; k < cs->nmodes; k++) {
        double e[5];
        mode_h_derivs(&cs->modes[k], c, 2 + der, e);
        j[0] += e[der], j[1] += e[der + 1], j[2] += e[der + 2];
        mode_h_bounds(&cs->modes[k], w0, w1, 3 + der, e);
        T += e[3 + der];
    }
    return tm_jet(j, T);
}

static void z_model(const void *ctx, double w0, double w1, double c, tm1 *m)
{
    *m = w_only_model(ctx, 0, w0, w1, c);
}

static double z_value(const void *ctx, double w)
{
    const comp_solution *cs = ctx;
    double z = 0.0;
    for (size_t k = 0; k < cs->nmodes; k++) {
        double h, dh;
        mode_h(&cs->modes[k], w, &h, &dh);
        z += h;
    }
    return z;
}

/* The extremes of a component x_c = Z(w) (as single_mode_extremes'), from the sample's places start. */
static pde_status w_only_extremes(const pde_solution *s, int c, const double *start[2], double tol, const pde_cancel *cancel,
                                  double bound[2], double best[2], double at[2][3])
{
    const line_fn f = { z_model, z_value, &s->comp[c] };
    for (int e = 0; e < 2; e++) {
        double lo, b, w;
        pde_status st = line_minimise(s, &f, e ? -1.0 : 1.0, start[e][2], tol, PDE_PROPS_BOXES, cancel, &lo, &b, &w);
        if (st != PDE_OK)
            return st;
        at[e][0] = start[e][0], at[e][1] = start[e][1], at[e][2] = w;
        double x[3];
        pde_eval(s, at[e][0], at[e][1], w, x);
        best[e] = x[c];
        bound[e] = e ? fmax(-lo, best[e]) : fmin(lo, best[e]);
    }
    return PDE_OK;
}

/*
 * det J where two components are harmonic (c[0] < c[1], alike: the same axes, n >= 1 and k) and the
 * third, z, a function of w alone (fig. 2, 4): with x_c[0] = t^n (alpha S + beta C), x_c[1] = t^n
 * (gamma S + delta C), the rows' (t, s) minor is n k pi t^(2n - 1) (beta gamma - alpha delta)
 * (S^2 + C^2 = 1), so det J = t^(2n - 1) g(w), g = sigma n k pi Z'(w) (beta gamma - alpha delta),
 * sigma the sign the rows' and columns' order gives: g's extremes are a problem in w alone.
 */
#define DL_MODES 8   /* modes of each harmonic at most whose h a twin of the other's shares */
#define DL_VALUE_MODES 32   /* modes at most whose h detj_line_value takes at once */
#define DL_MEMO 128  /* g's models remembered across pde_properties' searches of det J */

/* g's models by their interval and point (w0, w1, c): det J's searches for its least value, its
 * largest and its sign (fig. 2a: 9, 23 and 29 models) share their intervals from [0, 1] down, and
 * each takes the other's model where its own best point puts c at the same place. Direct-mapped. */
typedef struct {
    double key[DL_MEMO][3];
    tm1 model[DL_MEMO];
} detj_memo;

typedef struct {
    const pde_solution *sol;
    int c[2];             /* the components of h[0], h[1] */
    harmonic h[2];
    const comp_solution *zc;   /* z */
    double scale;         /* sigma n k pi */
    /* the mode of h[0] with the same h(w) as h[1]'s mode k (fig. 4: x = h1 sin + h2 cos, y = h2 sin
     * + h1 cos), or -1: its jet once; twins[1] NULL where a harmonic has more than DL_MODES */
    int twin[DL_MODES];
    const int *twins[2];
    detj_memo *memo;      /* NULL: none */
} detj_line;

static int detj_line_of(const pde_solution *s, detj_line *d)
{
    for (int z = 0; z < 3; z++) {
        const comp_solution *zc = &s->comp[z];
        const int c0 = z == 0 ? 1 : 0, c1 = z == 2 ? 1 : 2;
        if (!w_only(zc) || !harmonic_of(s, c0, &d->h[0]) || !harmonic_of(s, c1, &d->h[1]))
            continue;
        const harmonic *a = &d->h[0], *b = &d->h[1];
        if (a->a != b->a || a->n != b->n || a->k != b->k || a->n < 1.0)
            continue;
        /* sigma: the determinant with beta = gamma = 1, alpha = delta = 0, n = k pi = Z' = 1 */
        double M[3][3] = { { 0 } };
        M[c0][a->a] = 1.0, M[c1][a->b] = 1.0, M[z][2] = 1.0;
        d->sol = s;
        d->c[0] = c0, d->c[1] = c1;
        d->zc = zc;
        d->scale = det3(M[0], M[1], M[2]) * a->n * a->k * M_PI;
        d->twins[0] = d->twins[1] = NULL;
        if (a->nmodes <= DL_MODES && b->nmodes <= DL_MODES) {
            for (size_t k = 0; k < b->nmodes; k++) {
                d->twin[k] = -1;
                for (size_t i = 0; i < a->nmodes && d->twin[k] < 0; i++)
                    if (quad_same_h(&a->modes[i], &b->modes[k]))
                        d->twin[k] = (int)i;
            }
            d->twins[1] = d->twin;
        }
        return 1;
    }
    return 0;
}

static void detj_line_model(const void *ctx, double w0, double w1, double c, tm1 *m)
{
    const detj_line *d = ctx;
    unsigned slot = 0;
    if (d->memo) {
        uint64_t b[3];
        memcpy(&b[0], &w0, sizeof b[0]), memcpy(&b[1], &w1, sizeof b[1]), memcpy(&b[2], &c, sizeof b[2]);
        slot = (unsigned)(((b[0] * 3 + b[1] * 5 + b[2]) * 0x9e3779b97f4a7c15u) >> 56) % DL_MEMO;
        const double *k = d->memo->key[slot];
        if (k[0] == w0 && k[1] == w1 && k[2] == c) {
            *m = d->memo->model[slot];
            return;
        }
    }
    const double r = fmax(c - w0, w1 - c);
    tm1 ab[2], gd[2];
    double jet[DL_MODES][4];   /* each mode of h[0]: h and its derivatives at c */
    harmonic_models_of(&d->h[0], w0, w1, c, NULL, NULL, d->twins[1] ? jet : NULL, ab);
    harmonic_models_of(&d->h[1], w0, w1, c, d->twins[1], (const double(*)[4])jet, NULL, gd);
    const tm1 zp = w_only_model(d->zc, 1, w0, w1, c), bg = tm_mul(&ab[1], &gd[0], r), ad = tm_mul(&ab[0], &gd[1], r);
    const tm1 q = tm_add(bg, &ad, -1.0);
    *m = tm_mul(&zp, &q, r);
    for (int k = 0; k < 3; k++)
        m->p[k] *= d->scale;
    m->k *= fabs(d->scale);
    if (d->memo) {
        d->memo->key[slot][0] = w0, d->memo->key[slot][1] = w1, d->memo->key[slot][2] = c;
        d->memo->model[slot] = *m;
    }
}

/* g at w: every mode's h at once where they are few (solution_factors' exps and sincos shared: fig.
 * 4's y repeats x's terms), the same values to the bit as mode_h's one by one. */
static double detj_line_value(const void *ctx, double w)
{
    const detj_line *d = ctx;
    const pde_solution *s = d->sol;
    const size_t off[3] = { 0, s->comp[0].nmodes, s->comp[0].nmodes + s->comp[1].nmodes },
                 mt = off[2] + s->comp[2].nmodes, z = (size_t)(d->zc - s->comp);
    double hv[DL_VALUE_MODES], dv[DL_VALUE_MODES], ab[2], gd[2], zp = 0.0;
    const int all = mt <= DL_VALUE_MODES;
    if (all)
        solution_factors(s, 2, w, hv, dv);
    harmonic_ab_of(&d->h[0], all ? hv + off[d->c[0]] : NULL, w, ab);
    harmonic_ab_of(&d->h[1], all ? hv + off[d->c[1]] : NULL, w, gd);
    for (size_t k = 0; k < d->zc->nmodes; k++) {
        double h, dh = all ? dv[off[z] + k] : 0.0;
        if (!all)
            mode_h(&d->zc->modes[k], w, &h, &dh);
        zp += dh;
    }
    return d->scale * zp * (ab[1] * gd[0] - ab[0] * gd[1]);
}

/* g's certified sign on [w0, w1] beyond -tol (+1: g >= -tol; -1: g <= tol), else 0: its model about the
 * centre, or about an end where g is within tol of 0 (g0, g1: g at the ends, NaN where unknown; fig. 4's
 * g = 0 at w = 0, where Z' = 0: about the centre, the rest there exceeds g's slope), else its halves'
 * (down to two halvings) with one sign. */
static int detj_line_span(const detj_line *d, double w0, double w1, double g0, double g1, double tol, int depth)
{
    const int z0 = fabs(g0) <= tol, z1 = fabs(g1) <= tol;
    const double mid = 0.5 * (w0 + w1), c = z0 ? w0 : z1 ? w1 : mid;
    tm1 m = { { NAN, NAN, NAN }, NAN };
    /* g = 0 at both ends (a lobe between two roots): about either, the rest there exceeds g's value at
     * the other, 0; its halves only */
    if (!(z0 && z1) || depth >= 2) {
        detj_line_model(d, w0, w1, c, &m);
        for (int sg = 1; sg >= -1; sg -= 2) {
            const double q0 = sg * m.p[0], q1 = sg * m.p[1], q2 = sg * m.p[2];
            if (fmin(cubic_min(q0, q1, q2, m.k, w1 - c), cubic_min(q0, -q1, q2, m.k, c - w0)) >= -tol)
                return sg;
        }
    }
    if (depth >= 2)
        return 0;
    const double gm = c == mid ? m.p[0] : NAN;
    const int a = detj_line_span(d, w0, mid, g0, gm, tol, depth + 1);
    return a && detj_line_span(d, mid, w1, gm, g1, tol, depth + 1) == a ? a : 0;
}

/* quad_wsign's certificate (quad.h) from g's models, within one slab of w (a model holds within one). */
static int detj_line_sign(const void *ctx, double w0, double w1, double g0, double g1, double tol)
{
    const detj_line *d = ctx;
    size_t nslabs;
    const double *br = solution_breaks(d->sol, &nslabs);
    for (size_t k = 1; k < nslabs; k++)
        if (br[k] > w0 && br[k] < w1)
            return 0;
    return detj_line_span(d, w0, w1, g0, g1, tol, 0);
}

/*
 * The extreme of sign * det J (what 3) or of a coordinate where det J separates (quad.h: det J =
 * t^p D1, D1 det J on the face t = 1, p = n ns - 1; x_c = t^(n in[c]) X_c): branch and bound over
 * that face alone, a 2-D problem, then over t exactly: t^p is 1 when p = 0, else it spans [0, 1],
 * so the minimum is min(D1's, 0), attained at t = 0 when it is 0; likewise t^n X_c when in[c].
 * Without this, the 3-D branch and bound meets det J = 0 on the whole face t = 0, where its Taylor
 * models never close the gap, and a coordinate's boxes split along t wherever X_c changes sign.
 */
static pde_status separable_extreme(const pde_solution *s, const quad_sep *sp, int what, double sign,
                                    const double start[3], double tol, size_t budget, const pde_cancel *cancel,
                                    const detj_line *dl, bb_result *out)
{
    pbox face = { { 0, 0, 0 }, { 1, 1, 1 } };
    face.lo[sp->axis] = 1.0;
    double at[3] = { start[0], start[1], start[2] };
    at[sp->axis] = 1.0;
    if (what == 3 && sp->free >= 0)   /* det J is constant along it: a segment of w, a 1-D problem */
        face.lo[sp->free] = face.hi[sp->free] = at[sp->free];
    /* det J repeats itself along the face's other parameter t where the solid turns about an axis
     * (the box of x, y does not): its extremes over one period, the start folded into it */
    const int t = 1 - sp->axis;
    int mirror;
    double len;
    if (what == 3 && sp->axis < 2 && sp->free != t && (len = quad_detj_period(s, t, &mirror)) < 1.0) {
        const double per = mirror ? 2.0 * len : len, a = fmod(at[t], per);
        face.hi[t] = len;
        at[t] = a > len ? per - a : a;
    }
    bb_result b = { .at = { at[0], at[1], at[2] } };
    pde_status st = PDE_ERR_INVALID;
    if (what == 3 && dl) {
        const line_fn f = { detj_line_model, detj_line_value, dl };   /* g(w) alone */
        st = line_minimise(s, &f, sign, at[2], tol, budget, cancel, &b.lower, &b.best, &b.at[2]);
    }
    if (st == PDE_ERR_INVALID)
        st = bb_minimise(s, what, sign, at, &face, tol, budget, cancel, &b);
    if (st != PDE_OK)
        return st;
    if (what == 3 ? sp->n * sp->ns > 1 : sp->in[what]) {
        b.lower = fmin(b.lower, 0.0);
        if (b.best >= 0.0)
            b.best = 0.0, b.at[sp->axis] = 0.0;
    }
    *out = b;
    return PDE_OK;
}

/*
 * Lofts (api/loft.c): a component whose modes each have the factors 1 along u and v (its centre
 * C_c(w)) or the factor t^n along one of them, axis a, the same n >= 1 for all (its profile, t^n
 * P_c(s, w), s the other parameter): x_c = C_c(w) + t^n P_c(s, w). Returns a, or -1 where the
 * component is not so (or has no profile). quad_separate finds no axis for it (the centre has no
 * factor t^n), and the 3-D branch and bound meets det J = 0 on the whole face t = 0.
 */
static int radial_axis(const comp_solution *cs, double *n)
{
    for (int a = 0; a < 2; a++) {
        double p = -1.0;
        int ok = 1;
        for (size_t m = 0; m < cs->nmodes && ok; m++) {
            const pde_factor f[2] = { cs->modes[m].u, cs->modes[m].v };
            const int centre = f[0].kind == PDE_POW && f[0].p == 0.0 && f[1].kind == PDE_POW && f[1].p == 0.0;
            if (centre)
                continue;
            ok = f[a].kind == PDE_POW && f[a].p >= 1.0 && (p < 0.0 || f[a].p == p);
            p = f[a].p;
        }
        if (ok && p >= 1.0) {
            *n = p;
            return a;
        }
    }
    return -1;
}

/*
 * The axis a where det J = n t^(2n - 1) D1(s, w) (t the parameter of axis a, D1 det J on the face t
 * = 1): one component a function of w alone (z = Z(w)) and the two others radial (radial_axis) along
 * a with one n. Then the columns of t and s lie in the plane of the two, and det J = Z' times their
 * minor, n t^(2n - 1) (P_x P_y,s - P_y P_x,s). -1 where it is not so.
 */
static int radial_detj_axis(const pde_solution *s)
{
    for (int z = 0; z < 3; z++) {
        if (!s->comp[z].nmodes || !w_only(&s->comp[z]))
            continue;
        const int c0 = z == 0 ? 1 : 0, c1 = z == 2 ? 1 : 2;
        double n0, n1;
        const int a0 = radial_axis(&s->comp[c0], &n0), a1 = radial_axis(&s->comp[c1], &n1);
        if (a0 >= 0 && a0 == a1 && n0 == n1)
            return a0;
    }
    return -1;
}

/*
 * The extreme of sign * x_c (what < 3, x_c radial along a) or sign * det J (3, radial_detj_axis a)
 * over the cube: x_c = C + t^n P with t^n in [0, 1] takes its extremes on the face t = 1 or on t = 0,
 * where it is C(w) alone (a segment of w); det J's are D1's on the face t = 1 and 0, attained at t =
 * 0, so that the face's search may stop once certified above 0 (bb_minimise_floor). A 2-D search
 * and a 1-D one where the 3-D one never closed its gap (tower: 0.083 of the size; det J bounded by
 * -+13600 around [0, 158]).
 */
static pde_status radial_extreme(const pde_solution *s, int a, int what, double sign, const double start[3],
                                 double tol, size_t budget, const pde_cancel *cancel, bb_result *out)
{
    pbox face = { { 0, 0, 0 }, { 1, 1, 1 } };
    face.lo[a] = 1.0;
    double at[3] = { start[0], start[1], start[2] };
    at[a] = 1.0;
    bb_result b;
    /* above 0 to 1e-5 of the tolerance: det J's sign certified at once, for the integrals (RADIAL_JSIGN) */
    pde_status st = bb_minimise_floor(s, what, sign, at, &face, what == 3 ? 0.0 : INFINITY, RADIAL_JSIGN * tol, tol,
                                      budget, cancel, &b);
    if (st != PDE_OK)
        return st;
    if (what == 3) {
        b.lower = fmin(b.lower, 0.0);
        if (b.best >= 0.0)
            b.best = 0.0, b.at[a] = 0.0;
    } else {
        pbox seg = { { 0, 0, 0 }, { 0, 0, 1 } };
        seg.lo[1 - a] = seg.hi[1 - a] = 0.5;
        const double s0[3] = { seg.lo[0], seg.lo[1], start[2] };
        bb_result c;
        if ((st = bb_minimise(s, what, sign, s0, &seg, tol, budget, cancel, &c)) != PDE_OK)
            return st;
        b.boxes += c.boxes;
        b.lower = fmin(b.lower, c.lower);
        if (c.best < b.best)
            b.best = c.best, memcpy(b.at, c.at, sizeof b.at);
    }
    *out = b;
    return PDE_OK;
}

/* The range of a factor over [0, 1], with where it is attained: its ends and, for sin and cos, its
 * first two critical points (all the extremes there are: +-1). */
typedef struct {
    double lo, hi, at_lo, at_hi;
} range1;

static void factor_range(pde_factor f, range1 *r)
{
    double t[4] = { 0.0, 1.0, 2.0, 2.0 }, v, d;
    if ((f.kind == PDE_SIN || f.kind == PDE_COS) && f.p != 0.0) {
        const double k = fabs(f.p), c0 = f.kind == PDE_SIN ? 0.5 : 1.0;
        t[2] = c0 / k, t[3] = (c0 + 1.0) / k;
    }
    r->lo = DBL_MAX, r->hi = -DBL_MAX;
    for (int i = 0; i < 4; i++) {
        if (t[i] > 1.0)
            continue;
        factor_eval(f, t[i], &v, &d);
        if (v < r->lo)
            r->lo = v, r->at_lo = t[i];
        if (v > r->hi)
            r->hi = v, r->at_hi = t[i];
    }
}

/*
 * The extremes of a component that is one mode, x_c = f_u(u) f_v(v) h(w) (fig. 2, 4): the product
 * of three independent ranges, so the extremes are among the products of the ends of f_u's and
 * f_v's (exact) and h's, which two branch and bounds certify on a segment of w (one dimension,
 * where the cube's took hundreds of boxes: an extreme on a face where a derivative vanishes).
 * lo, hi: the certified bounds of x_c; best[2], at[2]: the extremes found (min, max).
 */
static pde_status single_mode_extremes(const pde_solution *s, int c, double tol, const pde_cancel *cancel,
                                       double bound[2], double best[2], double at[2][3])
{
    const pde_mode *md = &s->comp[c].modes[0];
    range1 ru, rv;
    factor_range(md->u, &ru);
    factor_range(md->v, &rv);
    /* The segment where |f_u f_v| is largest: there h's extremes are certified. */
    const double us = fabs(ru.lo) > fabs(ru.hi) ? ru.at_lo : ru.at_hi, vs = fabs(rv.lo) > fabs(rv.hi) ? rv.at_lo : rv.at_hi;
    double fu, fv, d;
    factor_eval(md->u, us, &fu, &d);
    factor_eval(md->v, vs, &fv, &d);
    const double P = fu * fv;
    if (!(fabs(P) > 0.0) || !isfinite(P))
        return PDE_ERR_INVALID;   /* the caller's general path */
    const pbox seg = { { us, vs, 0.0 }, { us, vs, 1.0 } };
    double hb[2], hf[2], hw[2];   /* h's certified min and max, those found, and where */
    for (int k = 0; k < 2; k++) {
        const double sg = (P > 0) == (k == 0) ? 1.0 : -1.0;   /* sg x_c = |P| h for the min of h */
        const double start[3] = { us, vs, 0.5 };
        bb_result b;
        pde_status st = bb_minimise(s, c, sg, start, &seg, tol, PDE_PROPS_BOXES, cancel, &b);
        if (st != PDE_OK)
            return st;
        const double m = k == 0 ? 1.0 : -1.0;
        hb[k] = m * b.lower / fabs(P), hf[k] = m * b.best / fabs(P), hw[k] = b.at[2];
    }
    /* Over the corners (ends of f_u, f_v) and h's two extremes. */
    const double fa[2] = { ru.lo, ru.hi }, ua[2] = { ru.at_lo, ru.at_hi };
    const double fb[2] = { rv.lo, rv.hi }, vb[2] = { rv.at_lo, rv.at_hi };
    bound[0] = DBL_MAX, bound[1] = -DBL_MAX, best[0] = DBL_MAX, best[1] = -DBL_MAX;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            for (int k = 0; k < 2; k++) {
                const double ab = fa[i] * fb[j], vb_ = ab * hb[k];
                double x[3];
                pde_eval(s, ua[i], vb[j], hw[k], x);
                bound[0] = fmin(bound[0], vb_), bound[1] = fmax(bound[1], vb_);
                for (int e = 0; e < 2; e++)
                    if (e == 0 ? x[c] < best[0] : x[c] > best[1]) {
                        best[e] = x[c];
                        at[e][0] = ua[i], at[e][1] = vb[j], at[e][2] = hw[k];
                    }
            }
    (void)hf;
    bound[0] = fmin(bound[0], best[0]), bound[1] = fmax(bound[1], best[1]);
    return PDE_OK;
}

/* The solid's size and det J's from the extremes best (min x, max x, ..., min det J, max det J). */
static void scales(const double best[8], double *size, double *jscale)
{
    double sz = 0.0, js = fmax(fabs(best[6]), fabs(best[7]));
    for (int c = 0; c < 3; c++)
        sz = fmax(sz, best[2 * c + 1] - best[2 * c]);
    *size = sz > 0.0 ? sz : 1.0;
    *jscale = js > 0.0 ? js : 1.0;
}

/*
 * det J's box budget: PDE_PROPS_BOXES_J times (w / pi)^2 / 2, at most PDE_PROPS_BOXES_J_MAX boxes,
 * w the solid's fastest rate (of a sin, cos, sinh, cosh or exp factor, or of a w-term). A branch
 * and bound first covers the region where det J is near its extreme with boxes whose remainder
 * bounds, (w r)^4 times the looseness of bounds of products, are below det J's variation, so r ~
 * 1/w along each axis: fig. 3's sin(8..30 pi v) took 3.3k to 23k boxes a side (2-D fig. 3a, 3b: 3.3k
 * to 16k; 3-D fig. 3c, 3d: 3.6k to 23k) where fig. 1, 2 and 4 take at most 1000. The budget only
 * caps a search that has not closed its gap. Its growth stops at PDE_PROPS_J_WORK / (modes + 3)^2.
 */
size_t pde_properties_detj_boxes(const pde_solution *s)
{
    double w = 0.0;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++) {
            const pde_mode *md = &s->comp[c].modes[m];
            const pde_factor f[2] = { md->u, md->v };
            for (int a = 0; a < 2; a++)
                if (f[a].kind != PDE_POW)
                    w = fmax(w, fabs(f[a].p) * (f[a].kind == PDE_SIN || f[a].kind == PDE_COS ? M_PI : 1.0));
            for (size_t k = 0; k < md->nterms; k++)
                w = fmax(w, hypot(md->terms[k].alpha, md->terms[k].beta));
        }
    const double grow = fmin(fmax(0.5 * (w / M_PI) * (w / M_PI), 1.0), (double)PDE_PROPS_BOXES_J_MAX / PDE_PROPS_BOXES_J);
    /* The growth is for solids of few fast modes (fig. 3: 5 or 6). A box costs jets of every mode, and a
     * solid of many (a loft of 64-point sections: tower, 99 modes) did not close its gap in 3000 boxes
     * either: the budget falls back to PDE_PROPS_BOXES_J as (modes + 3)^2 reaches PDE_PROPS_J_WORK / 1000. */
    size_t modes = 0;
    for (int c = 0; c < 3; c++)
        modes += s->comp[c].nmodes;
    const double cap = fmax((double)PDE_PROPS_BOXES_J, PDE_PROPS_J_WORK / ((double)(modes + 3) * (double)(modes + 3)));
    return (size_t)fmin(grow * PDE_PROPS_BOXES_J, cap);
}

/* The extreme of sign * det J by branch and bound, over the face where det J separates. */
static pde_status what_detj(const pde_solution *s, const quad_sep *sp, double sign, const double start[3],
                            double tol, size_t budget, const pde_cancel *cancel, const detj_line *dl, bb_result *out)
{
    if (sp->axis >= 0)
        return separable_extreme(s, sp, 3, sign, start, tol, budget, cancel, dl, out);
    const int a = radial_detj_axis(s);
    if (a >= 0)
        return radial_extreme(s, a, 3, sign, start, tol, budget, cancel, out);
    return bb_minimise(s, OBJ_DETJ, sign, start, NULL, tol, budget, cancel, out);
}

/*
 * A polynomial solid's objectives (poly.h): x, y, z and det J by their Bernstein coefficients over
 * the cube, and the sums of the magnitudes of their terms (the rounding's scale). NULL where the
 * solid is not a polynomial within poly.h's limits (or memory ran out: the general path then).
 */
typedef struct {
    poly3 x[3], b[4];   /* x: power basis; b: Bernstein, of x, y, z, det J */
} poly_objs;

static poly_objs *poly_objs_new(const pde_solution *s)
{
    poly_objs *p = malloc(sizeof *p);
    if (!p || !poly_solution(s, p->x) || !poly_detj(p->x, &p->b[3])) {
        free(p);
        return NULL;
    }
    for (int c = 0; c < 3; c++) {
        const int n = p->x[c].n[0] * p->x[c].n[1] * p->x[c].n[2];
        memcpy(p->b[c].n, p->x[c].n, sizeof p->b[c].n);
        memcpy(p->b[c].c, p->x[c].c, (size_t)n * sizeof p->b[c].c[0]);
    }
    return p;
}

/* The objectives at the corners and the centre, noted as a sample's would be; then the Bernstein forms. */
static void poly_sample(poly_objs *p, extremes *e)
{
    for (int i = 0; i < 9; i++) {
        const double at[3] = { i < 8 ? i & 1 : 0.5, i < 8 ? i >> 1 & 1 : 0.5, i < 8 ? i >> 2 : 0.5 };
        double x[3];
        for (int c = 0; c < 3; c++)
            x[c] = poly_eval(&p->x[c], at);
        note_point(e, at, x, poly_eval(&p->b[3], at));
    }
    for (int o = 0; o < 4; o++)
        poly_bernstein(&p->b[o]);
}

/*
 * Refuses (PDE_ERR_RANGE) at once a solid whose properties cannot be finite, before the branch and
 * bound and the quadrature, which would otherwise spend their whole budget on it (NaN stops no
 * refinement: a 1e300 solid took a second to end as inf):
 *
 * - a coordinate or det J that overflows at a sample (e->overflow): the bounds, which hold it, cannot
 *   be finite, and nor can the integrals evaluated from the same partials;
 * - a moment of inertia beyond RANGE_MARGIN times DBL_MAX by the trapezoid rule over the sample's grid,
 *   about its own centroid. The margin is for what a grid of 9 points an axis makes of an integrand
 *   concentrated near a face (|det J| r^2 of exp(700 u) factors: 131 times its integral an axis), so
 *   that no solid whose properties are finite is refused; those within it are computed and refused at
 *   the end as before. (The volume needs no test: over the unit cube it is below the largest |det J|.)
 *
 * The second moments are below the largest |det J| times the largest extent squared: only a sample
 * past that needs the grid's sums (a polynomial solid's is 9 points, the grid's own sweep then). The
 * sums are scaled by both, and Welford's updates keep the moments about the running centroid, so that
 * nothing overflows or cancels.
 */
#define RANGE_MARGIN 1e20

static pde_status beyond_double(const pde_solution *s, const double *uni, int res, poller *pl, const extremes *e)
{
    if (e->overflow)
        return PDE_ERR_RANGE;
    const double limit = log2(DBL_MAX) + log2(RANGE_MARGIN);
    double J = fmax(fabs(e->jmin), fabs(e->jmax)), E = 0.0;   /* E: half the largest extent (no overflow) */
    for (int c = 0; c < 3; c++)
        E = fmax(E, 0.5 * e->hi[c] - 0.5 * e->lo[c]);
    if (!(J > 0.0 && E > 0.0) || log2(J) + 2.0 * log2(2.0 * E) <= limit)
        return PDE_OK;
    extremes g;
    extremes_init(&g);
    pde_status st = sweep(s, uni, res, uni, res, uni, res, pl, &g);
    if (st != PDE_OK)
        return st;
    if (g.overflow)
        return PDE_ERR_RANGE;
    J = fmax(fabs(g.jmin), fabs(g.jmax)), E = 0.0;
    double mid[3];
    for (int c = 0; c < 3; c++)
        E = fmax(E, 0.5 * g.hi[c] - 0.5 * g.lo[c]), mid[c] = 0.5 * g.lo[c] + 0.5 * g.hi[c];
    if (!(J > 0.0 && E > 0.0))
        return PDE_OK;
    pde_grid *gr;
    if ((st = pde_grid_create(s, uni, (size_t)res, uni, (size_t)res, &gr)) != PDE_OK)
        return st;
    const size_t n = (size_t)res;
    double W = 0.0, mean[3] = { 0, 0, 0 }, S[3] = { 0, 0, 0 };
    for (size_t k = 0; k < n && st == PDE_OK; k++) {
        grid_set_w(gr, uni[k]);
        const double wk = (k == 0 || k == n - 1 ? 0.5 : 1.0) / (double)(n - 1);
        for (size_t j = 0; j < n; j++) {
            if (poll_after(pl, (j ? 0 : pl->point) + pl->modes * (4 + n) / 16)) {
                st = PDE_ERR_CANCELLED;
                break;
            }
            grid_row(gr, j, GRID_X | GRID_XU | GRID_XV | GRID_XW);
            const double wjk = wk * (j == 0 || j == n - 1 ? 0.5 : 1.0) / (double)(n - 1);
            for (size_t i = 0; i < n; i++) {
                double a[3], b[3], c[3];
                for (int q = 0; q < 3; q++) {
                    a[q] = gr->row[(3 + q) * n + i];
                    b[q] = gr->row[(6 + q) * n + i];
                    c[q] = gr->row[(9 + q) * n + i];
                }
                const double wt = wjk * (i == 0 || i == n - 1 ? 0.5 : 1.0) / (double)(n - 1) * fabs(det3(a, b, c)) / J;
                if (!(wt > 0.0))
                    continue;
                W += wt;
                for (int q = 0; q < 3; q++) {
                    const double y = (gr->row[q * n + i] - mid[q]) / E, d = y - mean[q];
                    mean[q] += d * wt / W;
                    S[q] += wt * d * (y - mean[q]);
                }
            }
        }
    }
    pde_grid_free(gr);
    if (st != PDE_OK)
        return st;
    /* A moment of inertia about an axis holds the second moments along the two others. */
    const double m2 = fmax(S[0] + S[1], fmax(S[1] + S[2], S[0] + S[2]));
    return m2 > 0.0 && log2(m2) + log2(J) + 2.0 * log2(E) > limit ? PDE_ERR_RANGE : PDE_OK;
}

pde_status pde_properties(const pde_solution *s, const pde_props_opts *opts, pde_props *out)
{
    if (!s || !out)
        return PDE_ERR_INVALID;
    int res = opts && opts->res > 0 ? opts->res : 9;
    const pde_cancel *cancel = opts ? opts->cancel : NULL;
    poller pl = { .cancel = cancel };
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++) {
            const pde_mode *md = &s->comp[c].modes[m];
            pl.modes++;
            pl.point++;
            for (size_t k = 0; k < md->nterms; k++)
                pl.point += (size_t)md->terms[k].deg + 1;
        }
    if (res < 2 || res > 1025)
        return PDE_ERR_INVALID;
    double *uni = malloc(2 * (size_t)res * sizeof *uni);
    if (!uni)
        return PDE_ERR_NOMEM;
    for (int i = 0; i < res; i++)
        uni[i] = (double)i / (res - 1);
    extremes e;
    extremes_init(&e);
    quad_sep sp;
    quad_separate(s, &sp);
    /* det J = t^p g(w), x and y harmonic alike, z = Z(w) (fig. 2, 4): g's models for det J's searches
     * and quad_solid's certificates, and the harmonics' bounds, once (their memo across the searches) */
    detj_memo jm;
    for (size_t i = 0; i < DL_MEMO; i++)
        jm.key[i][0] = NAN;
    detj_line dl;
    const int line = sp.axis >= 0 && sp.free >= 0 && detj_line_of(s, &dl) && dl.h[0].a == sp.axis;
    dl.memo = &jm;
    /* A polynomial solid: its extremes from Bernstein coefficients, where a sample is of no help. Where
     * every extreme is a search in w (det J's, and each component's: x, y harmonic and z = Z(w), with
     * modes), the face t = 1 alone (x_c = t^n X_c and det J = t^p g take their
     * extremes there, or 0 at t = 0, which the searches add), every other point along its other
     * parameter (fig. 2a: 45 points, not 729). */
    poly_objs *po = poly_objs_new(s);
    pde_status st = PDE_OK;
    const int inw = res >= 5 && res % 2 && line && dl.zc->nmodes;   /* odd: the ends kept */
    const double one = 1.0, *ax[2] = { uni, uni };
    double *sub = uni + res;
    size_t na[2] = { (size_t)res, (size_t)res };
    for (int a = 0; a < 2 && inw; a++) {
        for (int i = 0; i < res; i += 2)
            sub[i / 2] = uni[i];
        ax[a] = a == sp.axis ? &one : sub, na[a] = a == sp.axis ? 1 : (size_t)(res - 1) / 2 + 1;
    }
    if (po)
        poly_sample(po, &e);
    else
        st = sweep(s, ax[0], na[0], ax[1], na[1], uni, res, &pl, &e);
    if (st == PDE_OK)
        st = beyond_double(s, uni, res, &pl, &e);
    free(uni);
    if (st != PDE_OK) {
        free(po);
        return st;
    }

    /* Into a local result, so that a cancelled call leaves *out untouched. */
    pde_props r = { 0 };
    double best[8], *at[8];
    for (int c = 0; c < 3; c++) {
        best[2 * c] = e.lo[c], at[2 * c] = e.lo_at[c];
        best[2 * c + 1] = e.hi[c], at[2 * c + 1] = e.hi_at[c];
    }
    best[6] = e.jmin, at[6] = e.jmin_at;
    best[7] = e.jmax, at[7] = e.jmax_at;
    /* The tolerances from the samples' extremes: no larger than those found by the boxes. */
    double size, jscale;
    scales(best, &size, &jscale);
    /* Certify each extreme by branch and bound from its sampled point (a compass search polishing it
     * first cost more than it saved: the boxes' centres converge on the extreme as fast). */
    double jlow[2], jat[2][3];   /* det J's certified lower bounds of +det J, -det J, without the pad */
    int single[3] = { 0, 0, 0 };   /* components of one mode: both extremes from single_mode_extremes */
    /* A loft's det J takes RADIAL_BOXES a sign; but where it is at rounding at every sample (every section a
     * segment: the solid a surface, det J 0 but for rounding), no tolerance of its scale can be met and
     * the search took them all: the general budget then, its gap reported. */
    const int radial = sp.axis < 0 && radial_detj_axis(s) >= 0;
    const int jzero = radial && !(fmax(fabs(e.jmin), fabs(e.jmax)) > JZERO * obj_magnitude(s, OBJ_DETJ));
    const size_t jbudget = radial && !jzero ? RADIAL_BOXES : pde_properties_detj_boxes(s);
    int ra;
    double rn;
    bb_result sb[3][2];
    harmonic_memo hmemo = { 0 };
    const detj_line *jl = line ? &dl : NULL;
    double magnitude = 0.0;
    for (int o = 0; o < 8; o++) {
        const int what = o < 6 ? o / 2 : 3;
        const double sign = (o & 1) ? -1.0 : 1.0, tol = (o < 6 ? 1e-12 * size : 1e-9 * jscale);
        bb_result b;
        if (po) {
            /* det J to 1e-11 of its scale, not 1e-9: its halvings are cheap, and close as their square */
            if ((st = poly_minimise(&po->b[what], sign, what < 3 ? tol : 1e-2 * tol,
                                    what < 3 ? PDE_PROPS_BOXES : jbudget, &b)) != PDE_OK)
                break;
        } else if (what < 3 && !(o & 1)) {
            /* Both extremes of a component of w alone, a harmonic one, or one of one mode, at once. */
            const double *lo = at[o], *hi = at[o + 1];
            double bd[2], bs[2], ba[2][3];
            const double *starts[2] = { lo, hi };
            st = s->comp[what].nmodes && w_only(&s->comp[what])
                     ? w_only_extremes(s, what, starts, tol, cancel, bd, bs, ba)
                     : harmonic_extremes(s, what, line && dl.c[0] == what ? &dl.h[0] : line && dl.c[1] == what ? &dl.h[1] : NULL,
                                         fabs(best[o]) > fabs(best[o + 1]) ? lo[2] : hi[2], tol,
                                         PDE_PROPS_BOXES, cancel, &hmemo, bd, bs, ba);
            if (st == PDE_ERR_INVALID && s->comp[what].nmodes == 1)
                st = single_mode_extremes(s, what, tol, cancel, bd, bs, ba);
            if (st == PDE_OK) {
                single[what] = 1;
                for (int k = 0; k < 2; k++) {
                    sb[what][k].lower = k ? -bd[1] : bd[0], sb[what][k].best = k ? -bs[1] : bs[0];
                    memcpy(sb[what][k].at, ba[k], sizeof ba[k]);
                }
            } else if (st != PDE_ERR_INVALID)
                return st;
        }
        if (po)
            (void)0;
        else if (what < 3 && single[what])
            b = sb[what][o & 1];
        else if ((st = what == 3        ? what_detj(s, &sp, sign, at[o], tol, jbudget, cancel, jl, &b)
                       : sp.axis >= 0 ? separable_extreme(s, &sp, what, sign, at[o], tol, PDE_PROPS_BOXES, cancel, NULL, &b)
                       : (ra = radial_axis(&s->comp[what], &rn)) >= 0
                           ? radial_extreme(s, ra, what, sign, at[o], tol, RADIAL_BOXES, cancel, &b)
                                      : bb_minimise(s, what, sign, at[o], NULL, tol, PDE_PROPS_BOXES, cancel, &b)) != PDE_OK)
            return st;
        if (o >= 6)
            jlow[o - 6] = b.lower, jat[o - 6][0] = b.at[0], jat[o - 6][1] = b.at[1], jat[o - 6][2] = b.at[2];
        /* The bound holds for the exact closed form; evaluated values may differ by their rounding. */
        if (!(o & 1))   /* each objective's magnitude once: its two extremes share it */
            magnitude = obj_magnitude(s, what);
        const double pad = 64.0 * DBL_EPSILON * magnitude;
        const double bound = sign * (b.lower - pad), gap = b.best - b.lower + pad;
        best[o] = sign * b.best + 0.0;   /* + 0: no -0 */
        if (o < 6) {
            (o & 1 ? r.bbox_max : r.bbox_min)[what] = bound;
            r.bbox_gap = fmax(r.bbox_gap, gap);
        } else {
            *(o == 6 ? &r.detj_min : &r.detj_max) = bound;
            *(o == 6 ? &r.detj_min_found : &r.detj_max_found) = best[o];
            memcpy(o == 6 ? r.detj_min_at : r.detj_max_at, b.at, sizeof b.at);
            r.detj_gap = fmax(r.detj_gap, gap);
        }
    }
    if (st != PDE_OK) {   /* poly_minimise's (the other paths return) */
        free(po);
        return st;
    }
    /* The scales from the extremes found, which the branch and bound only improved. */
    scales(best, &size, &jscale);
    /* det J keeps its sign over the whole solid, up to what the integrals count as zero (1e-13 of its
     * size): then every panel takes its tensor rule (quad_solid's jsign). Where det J touches 0 (on
     * a face, fig. 1), the branch and bound stopped within 1e-9 of its size of 0: it goes on, for a
     * few boxes, to certify the sign to that tighter tolerance. */
    int jsign = 0;
    const double jtol = 1e-13 * jscale;
    for (int k = 0; k < 2 && !jsign; k++) {
        const double sign = k ? -1.0 : 1.0;
        if (jlow[k] < -jtol && fabs(best[6 + k]) <= 1e-9 * jscale) {
            bb_result b;
            st = po ? poly_minimise(&po->b[3], sign, 0.5 * jtol, SIGN_BOXES, &b)
                    : what_detj(s, &sp, sign, jat[k], 0.5 * jtol, SIGN_BOXES, cancel, jl, &b);
            if (st != PDE_OK) {
                free(po);
                return st;
            }
            jlow[k] = fmax(jlow[k], b.lower);
        }
        if (jlow[k] >= -jtol)
            jsign = k ? -1 : 1;
    }
    free(po);
    /* Folds are witnessed by attained values of both signs. */
    double tol = 1e-9 * jscale;
    r.folds = best[6] < -tol && best[7] > tol;

    /* About the centre of the extremes found (finite, where a bound may have overflowed). */
    double x0[3], vol_scale = 1.0;
    for (int c = 0; c < 3; c++) {
        x0[c] = 0.5 * (best[2 * c] + best[2 * c + 1]);
        vol_scale *= fmax(best[2 * c + 1] - best[2 * c], 1e-3 * size);
    }
    /* det J = t^p g(w) (fig. 2, 4): g's sign certified panel by panel of w where it folds elsewhere */
    const quad_wsign ws = { detj_line_sign, &dl };
    quad_result q, qa;
    if ((st = quad_solid_signs(s, x0, jscale, vol_scale, 1, jsign, line && !jsign ? &ws : NULL, cancel, &q)) != PDE_OK ||
        (st = quad_area(s, size, cancel, &r.surface_area, &qa)) != PDE_OK)
        return st;
    mass_properties(&q, x0, &r);
    r.integral_error = integral_error(&q, &qa);
    r.surface_area_error = area_error(&qa, r.surface_area);
    int cc;
    size_t cm;
    r.condition = pde_solution_condition(s, &cc, &cm);
    r.fit_error = s->fit_error;
    if (cc >= 0) {
        const pde_factor v = s->comp[cc].modes[cm].v;
        r.condition_harmonic = v.kind == PDE_SIN || v.kind == PDE_COS ? 0.5 * v.p : 0.0;
    }
    /* Integrals beyond a double: say so rather than hand back inf and NaN. Each on its own: a sum of
     * finite ones may overflow. */
    int finite = isfinite(r.volume) && isfinite(r.signed_volume) && isfinite(r.surface_area);
    for (int i = 0; i < 3; i++) {
        finite &= isfinite(r.centroid[i]) && isfinite(r.principal_moments[i]);
        for (int k = 0; k < 3; k++)
            finite &= isfinite(r.inertia[i][k]) && isfinite(r.principal_axes[i][k]);
    }
    if (!finite)
        return PDE_ERR_RANGE;

    double own[3];   /* the solution's size: attained values, not bounds (which may be loose) */
    for (int c = 0; c < 3; c++)
        own[c] = fmax(fabs(best[2 * c]), fabs(best[2 * c + 1]));
    if ((st = bc_residual(s, res < 17 ? 17 : res, own, &pl, &r.bc_residual)) != PDE_OK ||
        (st = pde_residual(s, res < 9 ? res : 9, &pl, &r.pde_residual)) != PDE_OK)
        return st;
    *out = r;
    return PDE_OK;
}
