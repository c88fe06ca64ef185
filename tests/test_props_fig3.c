/*
 * test_props_fig3.c: the volume integrals of a paper's figure 3 solid that folds (fig. 3c, 3d: det J
 * changes sign inside the cube) against an independent quadrature written here, and the error the
 * properties report: at most 1e-9, and no less than their real miss.
 *
 * The reference uses the figures' structure, not the code under test: every factor along u is 1 or u,
 * so x = A(v, w) + u B(v, w) and det J = d0 + d1 u + d2 u^2 (here d0 = 0: x_v, x_w vanish at u = 0
 * but z's), whose root r = -d1 / d2 in u is known in closed form. Along u, the pieces between 0, r
 * and 1 take 3 Gauss points each (|det J| x_c x_d is of degree 4 on each): exact. Along w the u
 * integrals have kinks where r crosses 0 or 1 (d1 = 0, d1 + d2 = 0): bracketed among 128 samples
 * (64 missed close pairs worth 4e-12 of fig. 3c's volume) and located to 1e-14, and the pieces
 * between take Gauss-Legendre panels of 20 points. Along v, what is left is smooth but where those
 * kinks' curves turn: panels of 20 Gauss points, each halved where it differs from its halves,
 * checked against a coarser tolerance with fewer samples.
 */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "quad.h"   /* Q_VOL, ... */
#include "support.h"

/* h(w) and h'(w) of a mode (one slab: a model), from its terms (pde.h's pde_wterm). */
static void ref_h(const pde_mode *md, double w, double *h, double *dh)
{
    double s = 0, d = 0;
    for (size_t k = 0; k < md->nterms; k++) {
        const pde_wterm *t = &md->terms[k];
        double A = 0, B = 0, dA = 0, dB = 0, p = 1, dp = 0;
        for (int i = 0; i <= t->deg; i++) {
            A += t->A[i] * p, B += t->B[i] * p, dA += t->A[i] * dp, dB += t->B[i] * dp;
            dp = dp * w + p, p *= w;
        }
        const double e = exp(t->alpha * (w - t->shift)), c = cos(t->beta * w), sn = sin(t->beta * w);
        const double f = A * c + B * sn;
        s += e * f;
        d += e * (t->alpha * f + dA * c - A * t->beta * sn + dB * sn + B * t->beta * c);
    }
    *h = s, *dh = d;
}

enum { MAXM = 16, NG = 20, NS = 256 };

/* One line of v: its modes' factors along v (f, f'), and what det J's u-polynomial is along w. */
typedef struct {
    const pde_mode *md[3];
    size_t nm[3];
    double fv[3][MAXM][2];
    double gx[NG], gw[NG], ux[3], uw[3];
    double acc[Q_N];
    int ns, wpanels;     /* samples of the kinks along w; panels of w */
} fig3_line;

static double ref_det3(const double a[3], const double b[3], const double c[3])
{
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
}

/* At w: x = A + u B with the partials of A, B along v and w; det J's coefficients d[0..2]. */
static void line_at(const fig3_line *L, double w, double A[3], double B[3], double d[3])
{
    double Av[3], Aw[3], Bv[3], Bw[3];
    for (int c = 0; c < 3; c++) {
        A[c] = B[c] = Av[c] = Aw[c] = Bv[c] = Bw[c] = 0.0;
        for (size_t m = 0; m < L->nm[c]; m++) {
            double h, dh;
            ref_h(&L->md[c][m], w, &h, &dh);
            const int lin = L->md[c][m].u.p == 1.0;
            (lin ? B : A)[c] += h * L->fv[c][m][0];
            (lin ? Bv : Av)[c] += h * L->fv[c][m][1];
            (lin ? Bw : Aw)[c] += dh * L->fv[c][m][0];
        }
    }
    d[0] = ref_det3(B, Av, Aw);
    d[1] = ref_det3(B, Bv, Aw) + ref_det3(B, Av, Bw);
    d[2] = ref_det3(B, Bv, Bw);
}

/* The kink functions along w: r = -d1/d2 crosses 0 (d1) or 1 (d1 + d2). */
static double kink(const fig3_line *L, double w, int which)
{
    double A[3], B[3], d[3];
    line_at(L, w, A, B, d);
    return which ? d[1] + d[2] : d[1];
}

/* The u integrals at w, times wt, into L->acc. */
static void u_integrals(fig3_line *L, double w, double wt)
{
    double A[3], B[3], d[3];
    line_at(L, w, A, B, d);
    /* d0 = 0: the figures' u factors vanish at u = 0 in x and y (x_v = x_w = 0 there) */
    assert_true(fabs(d[0]) <= 1e-12 * (1.0 + fabs(d[1]) + fabs(d[2])));
    double cut[3] = { 0.0, 1.0, 1.0 };
    int nc = 2;
    if (d[2] != 0.0) {
        const double r = -d[1] / d[2];
        if (r > 0.0 && r < 1.0)
            cut[1] = r, cut[2] = 1.0, nc = 3;
    }
    for (int k = 0; k + 1 < nc; k++) {
        const double a = cut[k], len = cut[k + 1] - a;
        for (int i = 0; i < 3; i++) {
            const double u = a + len * L->ux[i], J = u * (d[1] + d[2] * u), ww = wt * len * L->uw[i];
            double x[3];
            for (int c = 0; c < 3; c++)
                x[c] = A[c] + u * B[c];
            const double aj = ww * fabs(J);
            L->acc[Q_VOL] += aj, L->acc[Q_SIGNED] += ww * J;
            for (int c = 0; c < 3; c++)
                L->acc[Q_M1 + c] += aj * x[c], L->acc[Q_M2 + c] += aj * x[c] * x[c];
            L->acc[Q_M2 + 3] += aj * x[0] * x[1], L->acc[Q_M2 + 4] += aj * x[0] * x[2];
            L->acc[Q_M2 + 5] += aj * x[1] * x[2];
        }
    }
}

typedef struct {
    const fig3_line *L;
    int which;
} kink_arg;

static double kink_of(void *arg, double w)
{
    const kink_arg *k = arg;
    return kink(k->L, w, k->which);
}

/* The root of kink `which` in [a, b], where it changes sign (fa, fb) */
static double kink_root(const fig3_line *L, double a, double b, double fa, double fb, int which)
{
    kink_arg k = { L, which };
    return ref_root(kink_of, &k, a, fa, b, fb);
}

/* The line of v: w cut at the kinks (found among L->ns samples), each piece in panels of at most
 * 1 / `panels` of NG points. */
static void w_line(fig3_line *L, int panels)
{
    double cut[2 * NS + 2], prev[2] = { 0, 0 };
    int nc = 0;
    cut[nc++] = 0.0, cut[nc++] = 1.0;
    for (int i = 0; i <= L->ns; i++) {
        double A[3], B[3], d[3];
        const double w = (double)i / L->ns;
        line_at(L, w, A, B, d);
        const double f[2] = { d[1], d[1] + d[2] };
        for (int which = 0; which < 2; which++) {
            if (i && (f[which] < 0) != (prev[which] < 0) && f[which] != 0.0 && prev[which] != 0.0 &&
                nc < 2 * NS + 2)
                cut[nc++] = kink_root(L, (double)(i - 1) / L->ns, w, prev[which], f[which], which);
            prev[which] = f[which];
        }
    }
    qsort(cut, (size_t)nc, sizeof *cut, ref_cmp_double);
    for (int k = 0; k + 1 < nc; k++) {
        const double a = cut[k], b = cut[k + 1];
        if (b <= a)
            continue;
        const int np = (int)ceil((b - a) * panels);
        for (int p = 0; p < np; p++)
            for (int i = 0; i < NG; i++)
                u_integrals(L, a + (b - a) * (p + L->gx[i]) / np, (b - a) / np * L->gw[i]);
    }
}

/* The integrals of the line of v (over u and w), into acc. */
static void v_line(fig3_line *L, double v, double acc[Q_N])
{
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < L->nm[c]; m++)
            for (int dd = 0; dd < 2; dd++)
                L->fv[c][m][dd] = tfactor(L->md[c][m].v, v, dd);
    memset(L->acc, 0, sizeof L->acc);
    w_line(L, L->wpanels);
    memcpy(acc, L->acc, sizeof L->acc);
}

/* [a, b] of v by NG Gauss points, into out. */
static void v_gauss(fig3_line *L, double a, double b, double out[Q_N])
{
    double line[Q_N];
    memset(out, 0, sizeof(double) * Q_N);
    for (int i = 0; i < NG; i++) {
        v_line(L, a + (b - a) * L->gx[i], line);
        for (int e = 0; e < Q_N; e++)
            out[e] += (b - a) * L->gw[i] * line[e];
    }
}

/* [a, b] against its halves, halved where they differ by more than tol (of the volume): the lines'
 * integrals are smooth in v but where the kinks' curves turn, which this isolates. */
static void v_adapt(fig3_line *L, double a, double b, const double whole[Q_N], double tol, int depth,
                    double out[Q_N])
{
    double h0[Q_N], h1[Q_N];
    const double m = 0.5 * (a + b);
    v_gauss(L, a, m, h0);
    v_gauss(L, m, b, h1);
    double diff = 0.0;
    for (int e = 0; e < Q_N; e++)
        diff = fmax(diff, fabs(h0[e] + h1[e] - whole[e]));
    if (diff > tol && depth < 30) {
        v_adapt(L, a, m, h0, tol / 2, depth + 1, h0);
        v_adapt(L, m, b, h1, tol / 2, depth + 1, h1);
    }
    for (int e = 0; e < Q_N; e++)
        out[e] = h0[e] + h1[e];
}

/* The integrals over the cube: `panels` panels of v, each adaptive to tol (absolute, per unit of v). */
static void ref_fig3(const pde_solution *sol, int panels, double tol, int ns, int wpanels, double acc[Q_N])
{
    fig3_line *L = calloc(1, sizeof *L);
    assert_non_null(L);
    L->ns = ns, L->wpanels = wpanels;
    ref_gauss_legendre(NG, L->gx, L->gw);
    ref_gauss_legendre(3, L->ux, L->uw);
    for (int c = 0; c < 3; c++) {
        L->md[c] = pde_solution_modes(sol, c, &L->nm[c]);
        assert_true(L->nm[c] <= MAXM);
        for (size_t m = 0; m < L->nm[c]; m++) {   /* the structure the reference relies on */
            const pde_mode *md = &L->md[c][m];
            assert_true(md->u.kind == PDE_POW && md->u.p <= 1 && md->nslabs == 1);
        }
    }
    memset(acc, 0, sizeof(double) * Q_N);
    for (int j = 0; j < panels; j++) {
        const double a = (double)j / panels, b = (double)(j + 1) / panels;
        double whole[Q_N], part[Q_N];
        v_gauss(L, a, b, whole);
        v_adapt(L, a, b, whole, tol / panels, 0, part);
        for (int e = 0; e < Q_N; e++)
            acc[e] += part[e];
    }
    free(L);
}

/* The largest difference of two sets of integrals, each relative to its own kind's scale. */
static double ref_misfit(const double a[Q_N], const double b[Q_N], double size)
{
    const double trace = b[Q_M2] + b[Q_M2 + 1] + b[Q_M2 + 2];
    double worst = 0.0;
    for (int e = 0; e < Q_N; e++) {
        const double scale = e == Q_VOL || e == Q_SIGNED ? fabs(b[Q_VOL]) : e < Q_M2 ? fabs(b[Q_VOL]) * size : trace;
        worst = fmax(worst, fabs(a[e] - b[e]) / scale);
    }
    return worst;
}

static void check_fig3(const char *name)
{
    pde_solution *sol = preset_solution(name);
    assert_non_null(sol);
    double ref[Q_N], half[Q_N];
    ref_fig3(sol, 16, INFINITY, 16, 4, half);   /* the volume's scale, roughly: the tolerances' */
    const double V0 = half[Q_VOL];
    ref_fig3(sol, 16, 2e-11 * V0, 128, 16, ref);
    ref_fig3(sol, 16, 2e-10 * V0, 64, 16, half);
    const double V = ref[Q_VOL], size = sqrt((ref[Q_M2] + ref[Q_M2 + 1] + ref[Q_M2 + 2]) / V);
    const double conv = ref_misfit(half, ref, size);
    print_message("%s: reference volume %.17g signed %.17g (against a coarser one: %.3g)\n", name, V,
                  ref[Q_SIGNED], conv);
    assert_true(conv <= 1e-10);   /* the reference converged: the finer one far better still */

    /* the properties against it: the real miss, relative to each kind's scale */
    pde_props p;
    assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
    double c[3], S[3][3];
    static const int pi[6] = { 0, 1, 2, 0, 0, 1 }, pj[6] = { 0, 1, 2, 1, 2, 2 };
    for (int k = 0; k < 3; k++)
        c[k] = ref[Q_M1 + k] / V;
    for (int k = 0; k < 6; k++)
        S[pi[k]][pj[k]] = S[pj[k]][pi[k]] = ref[Q_M2 + k] - V * c[pi[k]] * c[pj[k]];
    const double tr = S[0][0] + S[1][1] + S[2][2];
    double miss = fmax(fabs(p.volume - V) / V, fabs(p.signed_volume - ref[Q_SIGNED]) / V);
    for (int k = 0; k < 3; k++)
        miss = fmax(miss, fabs(p.centroid[k] - c[k]) / size);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            miss = fmax(miss, fabs(p.inertia[i][j] - ((i == j ? tr : 0.0) - S[i][j])) / tr);
    print_message("%s: volume %.17g, off by %.3g; integral_error %.3g\n", name, p.volume, miss, p.integral_error);
    assert_true(p.folds);
    if (!(miss <= 1e-9))
        fail_msg("%s: the properties off the reference by %.3g", name, miss);
    if (!(p.integral_error <= 1e-9 && p.integral_error >= miss))
        fail_msg("%s: integral_error %.3g against the real miss %.3g", name, p.integral_error, miss);
    pde_solution_free(sol);
}

static void fig3c_volume_centroid_and_inertia_match_an_independent_quadrature(void **state)
{
    (void)state;
    check_fig3("fig3c");
}

/* fig. 3d (n_xy = 14, n_z = 6): 1.2e-11 off with 1.1e-10 reported; refining the boxes whose quarters all
 * look smooth once more (session 17, not kept) moved it 5.7e-9 away. */
static void fig3d_volume_centroid_and_inertia_match_an_independent_quadrature(void **state)
{
    (void)state;
    check_fig3("fig3d");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fig3c_volume_centroid_and_inertia_match_an_independent_quadrature),
        cmocka_unit_test(fig3d_volume_centroid_and_inertia_match_an_independent_quadrature),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
