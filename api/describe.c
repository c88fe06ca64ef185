/*
 * describe.c: the closed form of a solution, written for people.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "describe.h"

void api_factor_text(char *buf, size_t n, pde_factor f, char var)
{
    switch (f.kind) {
    case PDE_POW:
        if (f.p == 0)
            snprintf(buf, n, "1");
        else if (f.p == 1)
            snprintf(buf, n, "%c", var);
        else
            snprintf(buf, n, "%c^%d", var, (int)f.p);
        return;
    case PDE_SIN:
    case PDE_COS:
        snprintf(buf, n, "%s(%.10g*pi*%c)", f.kind == PDE_SIN ? "sin" : "cos", f.p, var);
        return;
    case PDE_EXP:
    case PDE_SINH:
    case PDE_COSH:
        snprintf(buf, n, "%s(%.10g*%c)", f.kind == PDE_EXP ? "exp" : f.kind == PDE_SINH ? "sinh" : "cosh",
                 f.p, var);
        return;
    }
    snprintf(buf, n, "?");
}

static void poly(FILE *out, const double *c, int deg)
{
    int terms = 0;
    for (int k = 0; k <= deg; k++)
        terms += c[k] != 0.0;
    if (terms > 1)
        fputc('(', out);
    int first = 1;
    for (int k = 0; k <= deg; k++) {
        if (c[k] == 0.0)
            continue;
        if (!first)
            fputs(c[k] < 0 ? " - " : " + ", out);
        fprintf(out, "%.10g", first ? c[k] : fabs(c[k]));
        if (k == 1)
            fputs("*w", out);
        else if (k > 1)
            fprintf(out, "*w^%d", k);
        first = 0;
    }
    if (first)
        fputc('0', out);
    if (terms > 1)
        fputc(')', out);
}

static void wterm(FILE *out, const pde_wterm *t)
{
    int nz_a = 0, nz_b = 0;
    for (int k = 0; k <= t->deg; k++) {
        nz_a |= t->A[k] != 0.0;
        nz_b |= t->B[k] != 0.0;
    }
    if (t->beta != 0.0 && nz_a && nz_b)
        fputc('(', out);
    if (nz_a || t->beta == 0.0) {
        poly(out, t->A, t->deg);
        if (t->beta != 0.0)
            fprintf(out, "*cos(%.10g*w)", t->beta);
    }
    if (t->beta != 0.0 && nz_b) {
        if (nz_a)
            fputs(" + ", out);
        poly(out, t->B, t->deg);
        fprintf(out, "*sin(%.10g*w)", t->beta);
    }
    if (t->beta != 0.0 && nz_a && nz_b)
        fputc(')', out);
    if (t->alpha != 0.0) {
        if (t->shift != 0.0)
            fprintf(out, "*exp(%.10g*(w - 1))", t->alpha);
        else
            fprintf(out, "*exp(%.10g*w)", t->alpha);
    }
}

static void regime(FILE *out, double e)
{
    if (e > 0)
        fprintf(out, "e = %.10g > 0, t = e^(1/4) = %.10g", e, pow(e, 0.25));
    else if (e < 0)
        fprintf(out, "e = %.10g < 0, beta = (|e|/4)^(1/4) = %.10g", e, pow(-e / 4, 0.25));
    else
        fprintf(out, "e = 0");
}

void api_describe(FILE *out, const pde_solution *sol, const pde_props *props)
{
    static const char names[3] = { 'x', 'y', 'z' };
    for (int c = 0; c < 3; c++) {
        size_t nm;
        const pde_mode *modes = pde_solution_modes(sol, c, &nm);
        fprintf(out, "%c(u,v,w) = sum over %zu mode%s of h(w)*f(u)*f(v)%s\n", names[c], nm,
                nm == 1 ? "" : "s", nm ? ":" : " = 0");
        for (size_t m = 0; m < nm; m++) {
            char fu[64], fv[64];
            api_factor_text(fu, sizeof fu, modes[m].u, 'u');
            api_factor_text(fv, sizeof fv, modes[m].v, 'v');
            fprintf(out, "  %s * %s  [", fu, fv);
            regime(out, modes[m].e);
            fputs("]\n", out);
            /* A loft's mode is piecewise: one h(w) per slab. */
            const pde_mode *md = &modes[m];
            for (size_t sl = 0; sl < (md->nslabs > 1 ? md->nslabs : 1); sl++) {
                size_t t0 = md->nslabs > 1 ? md->first[sl] : 0, t1 = md->nslabs > 1 ? md->first[sl + 1] : md->nterms;
                if (md->nslabs > 1)
                    fprintf(out, "    on %.10g <= w <= %.10g:\n", md->breaks[sl], md->breaks[sl + 1]);
                fputs("    h(w) = ", out);
                for (size_t k = t0; k < t1; k++) {
                    if (k > t0)
                        fputs("\n         + ", out);
                    wterm(out, &md->terms[k]);
                }
                if (t0 == t1)
                    fputs("0", out);
                fputc('\n', out);
            }
        }
    }
    if (props)
        api_describe_props(out, props);
}

static void triple(FILE *out, const char *fmt, const double v[3])
{
    fprintf(out, "(");
    for (int i = 0; i < 3; i++) {
        fprintf(out, i ? ", " : "");
        fprintf(out, fmt, v[i]);
    }
    fprintf(out, ")");
}

void api_describe_props(FILE *out, const pde_props *props)
{
    const pde_props *p = props;
    fprintf(out, "properties:\n");
    fprintf(out, "  bounding box: [%.10g, %.10g, %.10g] to [%.10g, %.10g, %.10g]\n", p->bbox_min[0], p->bbox_min[1],
            p->bbox_min[2], p->bbox_max[0], p->bbox_max[1], p->bbox_max[2]);
    fprintf(out, "    certified: the solid lies inside and comes within %.3g of each face\n", p->bbox_gap);
    fprintf(out, "  volume: %.10g (integral of |det J|; of det J: %.10g)\n", p->volume, p->signed_volume);
    fprintf(out, "  surface area: %.10g\n", p->surface_area);
    fprintf(out, "  centroid: ");
    triple(out, "%.10g", p->centroid);
    fprintf(out, "\n  inertia about the centroid (unit density):\n");
    for (int i = 0; i < 3; i++)
        fprintf(out, "    [%17.10g %17.10g %17.10g ]\n", p->inertia[i][0], p->inertia[i][1], p->inertia[i][2]);
    fprintf(out, "  principal moments: %.10g, %.10g, %.10g (ascending)\n", p->principal_moments[0],
            p->principal_moments[1], p->principal_moments[2]);
    fprintf(out, "  principal axes: ");
    for (int k = 0; k < 3; k++) {
        fprintf(out, k ? ", " : "");
        triple(out, "%.6g", p->principal_axes[k]);
    }
    fprintf(out, " (right-handed)\n");
    fprintf(out, "  det J: min %.10g at (u,v,w) = ", p->detj_min_found);
    triple(out, "%.6g", p->detj_min_at);
    fprintf(out, ", max %.10g at ", p->detj_max_found);
    triple(out, "%.6g", p->detj_max_at);
    fprintf(out, "\n    certified: every value lies in [%.10g, %.10g]\n", p->detj_min, p->detj_max);
    fprintf(out, "  folds: %s\n", p->folds ? "yes: det J changes sign, the solid overlaps itself" : "no");
    fprintf(out, "  accuracy: boundary residual %.3g, PDE residual %.3g, integrals %.3g, area %.3g (relative)\n",
            p->bc_residual, p->pde_residual, p->integral_error, p->surface_area_error);
}
