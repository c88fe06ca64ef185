/*
 * support.c: the tests' independent solver and helpers (support.h).
 */
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cJSON.h>
#include <cmocka.h>
#include <curl/curl.h>

#include "support.h"
#include "template.h"

/* ---- banded Gaussian elimination with partial pivoting ---- */

typedef struct {
    int n, kl, ku, w;   /* row i stores columns i-kl .. i+kl+ku */
    double *a;
} band;

static double *bat(band *b, int i, int j)
{
    return &b->a[(size_t)i * b->w + (j - i + b->kl)];
}

static int band_solve(band *b, double *rhs)
{
    int n = b->n, kl = b->kl, ku = b->ku;
    for (int k = 0; k < n; k++) {
        int last = k + kl < n - 1 ? k + kl : n - 1;
        int p = k;
        for (int i = k + 1; i <= last; i++)
            if (fabs(*bat(b, i, k)) > fabs(*bat(b, p, k)))
                p = i;
        if (*bat(b, p, k) == 0.0)
            return -1;
        int right = k + kl + ku < n - 1 ? k + kl + ku : n - 1;
        if (p != k) {
            for (int j = k; j <= right; j++) {
                double t = *bat(b, k, j);
                *bat(b, k, j) = j - p >= -kl ? *bat(b, p, j) : 0.0;
                if (j - p >= -kl)
                    *bat(b, p, j) = t;
            }
            double t = rhs[k];
            rhs[k] = rhs[p];
            rhs[p] = t;
        }
        for (int i = k + 1; i <= last; i++) {
            double f = *bat(b, i, k) / *bat(b, k, k);
            if (f == 0.0)
                continue;
            for (int j = k + 1; j <= right; j++)
                *bat(b, i, j) -= f * *bat(b, k, j);
            *bat(b, i, k) = 0.0;
            rhs[i] -= f * rhs[k];
        }
    }
    for (int i = n - 1; i >= 0; i--) {
        int right = i + kl + ku < n - 1 ? i + kl + ku : n - 1;
        double s = rhs[i];
        for (int j = i + 1; j <= right; j++)
            s -= *bat(b, i, j) * rhs[j];
        rhs[i] = s / *bat(b, i, i);
    }
    return 0;
}

/* ---- the first-order system y' = A y + f(w) ---- */

struct indep_solution {
    indep_problem p;
    int n, K;            /* state size 4M, intervals */
    double s;            /* state scale: y_j = h^(j) / s^j */
    double *A;           /* n x n */
    double *Y;           /* (K+1) x n states at the nodes */
    double *qbuf;
};

static const double gl16_x[16] = {
    -0.9894009349916499, -0.9445750230732326, -0.8656312023878318, -0.7554044083550030,
    -0.6178762444026438, -0.4580167776572274, -0.2816035507792589, -0.0950125098376374,
    0.0950125098376374,  0.2816035507792589,  0.4580167776572274,  0.6178762444026438,
    0.7554044083550030,  0.8656312023878318,  0.9445750230732326,  0.9894009349916499 };
static const double gl16_w[16] = {
    0.0271524594117541, 0.0622535239386479, 0.0951585116824928, 0.1246289712555339,
    0.1495959888165767, 0.1691565193950025, 0.1826034150449236, 0.1894506104550685,
    0.1894506104550685, 0.1826034150449236, 0.1691565193950025, 0.1495959888165767,
    0.1246289712555339, 0.0951585116824928, 0.0622535239386479, 0.0271524594117541 };

/* E = exp(A tau) by Taylor series; ||A tau|| is kept below about 1 by the caller. */
static void expm(const indep_solution *s, double tau, double *E)
{
    int n = s->n;
    double *T = malloc(2 * (size_t)n * n * sizeof *T), *U = T + (size_t)n * n;
    for (int i = 0; i < n * n; i++)
        E[i] = T[i] = (i / n == i % n) ? 1.0 : 0.0;
    for (int k = 1; k <= 40; k++) {
        /* T = T A tau / k */
        double mx = 0.0;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                double acc = 0.0;
                for (int l = 0; l < n; l++)
                    acc += T[i * n + l] * s->A[l * n + j];
                U[i * n + j] = acc * tau / k;
                mx = fmax(mx, fabs(U[i * n + j]));
            }
        memcpy(T, U, (size_t)n * n * sizeof *T);
        for (int i = 0; i < n * n; i++)
            E[i] += T[i];
        if (mx < 1e-300 || (k > 4 && mx < 1e-19))
            break;
    }
    free(T);
}

/* The force in the scaled state: only the y_{m,3} rows get q_m / (c s^3). */
static void force(const indep_solution *s, double w, double *f)
{
    memset(f, 0, (size_t)s->n * sizeof *f);
    if (!s->p.q)
        return;
    s->p.q(w, s->qbuf, s->p.ctx);
    for (int m = 0; m < s->p.M; m++)
        f[4 * m + 3] = s->qbuf[m] / (s->p.c * s->s * s->s * s->s);
}

/* y(a + tau) = E(tau) y(a) + integral_0^tau E(tau - r) f(a + r) dr, into out. */
static void propagate(const indep_solution *s, double a, double tau, const double *ya, double *out)
{
    int n = s->n;
    double *E = malloc(((size_t)n * n + 2 * (size_t)n) * sizeof *E), *f = E + (size_t)n * n,
           *acc = f + n;
    expm(s, tau, E);
    for (int i = 0; i < n; i++) {
        acc[i] = 0.0;
        for (int j = 0; j < n; j++)
            acc[i] += E[i * n + j] * ya[j];
    }
    if (s->p.q && tau > 0.0) {
        for (int g = 0; g < 16; g++) {
            double r = 0.5 * tau * (gl16_x[g] + 1.0), wt = 0.5 * tau * gl16_w[g];
            expm(s, tau - r, E);
            force(s, a + r, f);
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++)
                    acc[i] += wt * E[i * n + j] * f[j];
        }
    }
    memcpy(out, acc, (size_t)n * sizeof *out);
    free(E);
}

indep_solution *indep_solve(const indep_problem *p)
{
    indep_solution *s = calloc(1, sizeof *s);
    int M = p->M, n = 4 * M;
    s->p = *p;
    s->n = n;
    double big = 1.0;
    for (int m = 0; m < M; m++)
        big = fmax(big, pow(fabs(p->mu[m] / p->c), 0.25));
    if (p->K)
        for (int i = 0; i < M * M; i++)
            big = fmax(big, pow(fabs(p->K[i] / p->c), 0.25));
    s->s = big;
    double rate = fmax(big, p->freq);
    s->K = (int)fmax(16.0, ceil(2.0 * rate));
    s->A = calloc((size_t)n * n, sizeof *s->A);
    s->qbuf = calloc((size_t)M, sizeof *s->qbuf);
    double c3 = p->c * big * big * big;
    for (int m = 0; m < M; m++) {
        for (int j = 0; j < 3; j++)
            s->A[(4 * m + j) * n + 4 * m + j + 1] = big;
        s->A[(4 * m + 3) * n + 4 * m] -= p->mu[m] / c3;
        if (p->K)
            for (int k = 0; k < M; k++)
                s->A[(4 * m + 3) * n + 4 * k] -= p->K[m * M + k] / c3;
    }
    /* Unknowns: Y_0 .. Y_K. Rows: 2M boundary at 0, K blocks of n continuity, 2M boundary at 1. */
    int K = s->K, N = n * (K + 1);
    band b = { N, 2 * n, 2 * n, 0, NULL };
    b.w = 2 * b.kl + b.ku + 1;
    b.a = calloc((size_t)N * b.w, sizeof *b.a);
    double *rhs = calloc((size_t)N, sizeof *rhs), *E = malloc((size_t)n * n * sizeof *E);
    double *zero = calloc((size_t)n, sizeof *zero), *r = malloc((size_t)n * sizeof *r);
    int row = 0;
    for (int m = 0; m < M; m++) {
        *bat(&b, row, 4 * m) = 1.0;
        rhs[row++] = p->bc[4 * m];
        *bat(&b, row, 4 * m + 1) = 1.0;
        rhs[row++] = p->bc[4 * m + 1] / big;
    }
    double h = 1.0 / K;
    expm(s, h, E);
    for (int k = 0; k < K; k++) {
        propagate(s, k * h, h, zero, r);   /* the forced part alone */
        for (int i = 0; i < n; i++, row++) {
            for (int j = 0; j < n; j++)
                *bat(&b, row, n * k + j) = E[i * n + j];
            *bat(&b, row, n * (k + 1) + i) = -1.0;
            rhs[row] = -r[i];
        }
    }
    for (int m = 0; m < M; m++) {
        *bat(&b, row, n * K + 4 * m) = 1.0;
        rhs[row++] = p->bc[4 * m + 2];
        *bat(&b, row, n * K + 4 * m + 1) = 1.0;
        rhs[row++] = p->bc[4 * m + 3] / big;
    }
    if (band_solve(&b, rhs) != 0) {
        free(rhs);
        rhs = NULL;
    }
    s->Y = rhs;
    free(b.a);
    free(E);
    free(zero);
    free(r);
    if (!s->Y) {
        indep_free(s);
        return NULL;
    }
    return s;
}

double indep_eval(const indep_solution *s, int m, int d, double w)
{
    int k = (int)floor(w * s->K);
    if (k < 0)
        k = 0;
    if (k >= s->K)
        k = s->K - 1;
    double a = (double)k / s->K;
    double *y = malloc((size_t)s->n * sizeof *y);
    propagate(s, a, w - a, s->Y + (size_t)k * s->n, y);
    double v = y[4 * m + d] * pow(s->s, d);
    free(y);
    return v;
}

void indep_free(indep_solution *s)
{
    if (!s)
        return;
    free(s->A);
    free(s->Y);
    free(s->qbuf);
    free(s);
}

int close_rel(double a, double b, double tol, double floor)
{
    return fabs(a - b) <= tol * fmax(fmax(fabs(a), fabs(b)), floor);
}

/* ---- factors ---- */

pde_factor F_pow(int n) { return (pde_factor){ PDE_POW, n }; }
pde_factor F_sin(double k) { return (pde_factor){ PDE_SIN, k }; }
pde_factor F_cos(double k) { return (pde_factor){ PDE_COS, k }; }
pde_factor F_exp(double a) { return (pde_factor){ PDE_EXP, a }; }
pde_factor F_sinh(double a) { return (pde_factor){ PDE_SINH, a }; }
pde_factor F_cosh(double a) { return (pde_factor){ PDE_COSH, a }; }

double tfactor(pde_factor f, double t, int n)
{
    double k = f.p * M_PI, a = f.p;
    switch (f.kind) {
    case PDE_POW: {
        double c = 1.0;
        int p = (int)f.p;
        if (n > p)
            return 0.0;
        for (int i = 0; i < n; i++)
            c *= p - i;
        return c * pow(t, p - n);
    }
    case PDE_SIN: return pow(k, n) * sin(k * t + n * M_PI / 2);
    case PDE_COS: return pow(k, n) * cos(k * t + n * M_PI / 2);
    case PDE_EXP: return pow(a, n) * exp(a * t);
    case PDE_SINH: return pow(a, n) * (n % 2 ? cosh(a * t) : sinh(a * t));
    case PDE_COSH: return pow(a, n) * (n % 2 ? sinh(a * t) : cosh(a * t));
    }
    return NAN;
}

/* ---- the paper's figures ---- */

static pde_bterm fig_b[3][2];
static pde_fterm fig_f[2];

/* Example 1, eq. (17): a[0..3], b[0..3], primes, h0, h1 and primes. */
static void example1(pde_model *m, const double a[4], const double ap[4], const double b[4],
                     const double bp[4], double h0, double h0p, double h1, double h1p)
{
    fig_b[0][0] = (pde_bterm){ F_pow(0), F_pow(0), a[0], ap[0], a[2], ap[2] };
    fig_b[0][1] = (pde_bterm){ F_pow(1), F_pow(0), a[1], ap[1], a[3], ap[3] };
    fig_b[1][0] = (pde_bterm){ F_pow(0), F_pow(0), b[0], bp[0], b[2], bp[2] };
    fig_b[1][1] = (pde_bterm){ F_pow(0), F_pow(1), b[1], bp[1], b[3], bp[3] };
    fig_b[2][0] = (pde_bterm){ F_pow(0), F_pow(0), h0, h0p, h1, h1p };
    memset(m, 0, sizeof *m);
    for (int c = 0; c < 3; c++) {
        /* Not given in the paper, and immaterial: every mode has e = 0. */
        m->comp[c] = (pde_component){ 1, 1, -10, fig_b[c], c < 2 ? 2 : 1, NULL, 0 };
    }
}

/* Example 4, eqs. (25) and (28). */
static void example4(pde_model *m, double b, double c, double r0, double r0p, double r1, double r1p,
                     double h0, double h0p, double h1, double h1p, double p0, double xi)
{
    fig_b[0][0] = (pde_bterm){ F_pow(1), F_sin(2), r0, r0p, r1, r1p };
    fig_b[1][0] = (pde_bterm){ F_pow(1), F_cos(2), r0, r0p, r1, r1p };
    fig_b[2][0] = (pde_bterm){ F_pow(0), F_pow(0), h0, h0p, h1, h1p };
    fig_f[0] = (pde_fterm){ p0, F_pow(1), F_cos(2), F_sin(xi) };
    fig_f[1] = (pde_fterm){ p0, F_pow(1), F_sin(2), F_sin(xi) };
    memset(m, 0, sizeof *m);
    m->comp[0] = (pde_component){ 1, b, c, fig_b[0], 1, &fig_f[0], 1 };
    m->comp[1] = (pde_component){ 1, b, c, fig_b[1], 1, &fig_f[1], 1 };
    m->comp[2] = (pde_component){ 1, 1, -10, fig_b[2], 1, NULL, 0 };
}

static const double fig4[24][12] = {
    /* b, c, r0, r0', r1, r1', h0, h0', h1, h1', p0, xi */
    { 1, -9.5, 0.5, 0, 0.5, 0, 0, 0, 3, 7.5, 3e4, 3 },
    { 2.5, -10, 0.5, 2.5, 0.5, 2.5, 0, 0, 3, 3, 8e4, 5 },
    { 4, -100, 0.5, 2.5, 0.5, 2.5, 0, 0, 3, 6, 1.8e6, 7 },
    { 4, -10, 0.5, -1.5, 0.5, 2, 0, 3, 3, 6, 3e5, 7 },
    { 4, -10, 0.5, -1.5, 0.5, 2, 0, 3, 3, 6, -3e5, 7 },
    { 2.5, -10, 0.5, -1.5, 0.5, 1.5, 0, 6, 3, 4.5, 1e5, 7 },
    { 2.5, -10, 0.5, -1.5, 0.5, 2, 0, 3, 3, 9, -3e4, 5 },
    { 2.5, -10, 0.5, -1, 0.5, 0.5, 0, 3, 3, 6, 1.5e4, 3 },
    { 2.5, -10, 0.8, 0.8, 0.5, -1.6, 0, 3, 3, 6, 1.5e4, 3 },
    { 2.5, -10, 0.6, -1.8, 0.5, -0.6, 0, 3, 3, 6, -5.5e4, 5 },
    { 2.5, -10, 0.6, -1.8, 0.5, -0.6, 0, 3, 3, 6, 5.5e4, 5 },
    { 3.5, -10, 0.8, -2.4, 0.5, 0.5, 0, 3, 3, 9, -5.5e4, 5 },
    { 3.5, -10, 0.8, -2.4, 0.5, 0.5, 0, 3, 3, 9, 5.5e4, 9 },
    { 5, -20, 1.5, -4.5, 0.5, 0, 0, 3, 3, 3, 5e5, 7 },
    { 3, -20, 1, -5, 0.5, -1, 0, 6, 3, 6, -9e5, 11 },
    { 15, -40, 1, -2, 0.5, -1, 0, 6, 3, 4.5, 3e6, 11 },
    { 1, -10, 1, 3, 0.5, -1, 0, 6, 3, 9, 3e4, 3 },
    { 1, -10, 1, -3, 0.5, -2, 0, 9, 3, 3, 3e4, 3 },
    { 1, -10, 1, -3, 0.5, -2, 0, 9, 3, 3, 3e5, 7 },
    { 1, -10, 1, -3, 0.5, -1, 0, 9, 3, 0, 3e5, 5 },
    { 1, -10, 1, 3, 0.5, 1, 0, 9, 3, 7.5, 3e4, 5 },
    { 1, -10, 1, 1, 0.5, 3, 0, 3, 3, 9, 5e5, 9 },
    { 1, -10, 1, 6, 0.5, 3, 0, 3, 3, 10.5, 3e5, 9 },
    { 1, -10, 0.8, -4, 1, -2.4, 0, 6, 3, 9, 5e5, 7 },
};

static const char *const fig_names[] = {
    "fig1a", "fig1c", "fig1e", "fig1g", "fig2a", "fig2b", "fig2c", "fig3a", "fig3b", "fig3c", "fig3d",
    "fig4a", "fig4b", "fig4c", "fig4d", "fig4e", "fig4f", "fig4g", "fig4h", "fig4i", "fig4j", "fig4k",
    "fig4l", "fig4m", "fig4n", "fig4o", "fig4p", "fig4q", "fig4r", "fig4s", "fig4t", "fig4u", "fig4v",
    "fig4w", "fig4x" };

size_t paper_figure_count(void)
{
    return sizeof fig_names / sizeof *fig_names;
}

const char *paper_figure_name(size_t i)
{
    return fig_names[i];
}

void paper_figure_model(size_t i, pde_model *m)
{
    if (i < 4) {
        /* Fig. 1a, then 1c, 1e, 1g as the text changes the parameters. */
        double a[4] = { -0.5, 1, -0.5, 1 }, b[4] = { -0.5, 1, -0.5, 1 }, ap[4] = { 0 }, bp[4] = { 0 };
        double h0 = 0, h1 = 1, h0p = 0, h1p = 0;
        if (i >= 1)
            a[2] = b[2] = -1, a[3] = b[3] = h1 = 2;
        if (i >= 2) {
            a[0] = -0.5, a[1] = 1.5, a[2] = b[0] = -1, a[3] = b[1] = 3, b[2] = -0.4, b[3] = 1;
            h0 = 0, h1 = 2;
            memcpy(ap, a, sizeof a);
            memcpy(bp, b, sizeof b);
            h0p = h1, h1p = 2 * h1;
        }
        if (i == 3) {
            ap[0] = 2.5 * a[0], ap[1] = 2.5 * a[1], ap[2] = -2 * a[2], ap[3] = -2 * a[3];
            bp[0] = -2.5 * b[0], bp[1] = -2.5 * b[1], h1p = h1;
        }
        example1(m, a, ap, b, bp, h0, h0p, h1, h1p);
        return;
    }
    if (i < 7) {
        /* Example 2, eq. (19): r0 = r0' = a0 = 0.5, b0 = 1, h1 = 2, the rest 0. */
        static const double bc[3][2] = { { 4, -100 }, { 2.5, -10 }, { 4, -10 } };
        fig_b[0][0] = (pde_bterm){ F_pow(1), F_sin(2), 0.5, 0.5, 0.5, 0 };
        fig_b[1][0] = (pde_bterm){ F_pow(1), F_cos(2), 0.5, 0.5, 1, 0 };
        fig_b[2][0] = (pde_bterm){ F_pow(0), F_pow(0), 0, 0, 2, 0 };
        memset(m, 0, sizeof *m);
        for (int c = 0; c < 3; c++)
            m->comp[c] = (pde_component){ 1, bc[i - 4][0], bc[i - 4][1], fig_b[c], 1, NULL, 0 };
        return;
    }
    if (i < 11) {
        /* Example 3, eq. (22). */
        static const double v[4][3] = { { 20, 0, 0.5 }, { 30, 0, 0.5 }, { 8, 10, 0.8 }, { 14, 6, 0.8 } };
        double nxy = v[i - 7][0], nz = v[i - 7][1], r2 = v[i - 7][2];
        double r0 = 0.5, r1 = 0.1, h0 = 2, h1 = 0.1, h2 = 0, h3 = -0.1;
        fig_b[0][0] = (pde_bterm){ F_pow(1), F_sin(2), r0, 0, r2, 0 };
        fig_b[0][1] = (pde_bterm){ F_pow(1), F_sin(nxy), r1, 0, 0, 0 };
        fig_b[1][0] = (pde_bterm){ F_pow(1), F_cos(2), r0, 0, r2, 0 };
        fig_b[1][1] = (pde_bterm){ F_pow(1), F_cos(nxy), r1, 0, 0, 0 };
        fig_b[2][0] = (pde_bterm){ F_pow(0), F_pow(0), h0, 0, h2, 0 };
        fig_b[2][1] = (pde_bterm){ F_pow(1), F_sin(nz), h1, 0, h3, 0 };
        memset(m, 0, sizeof *m);
        for (int c = 0; c < 3; c++)
            m->comp[c] = (pde_component){ 1, 2.5, -10, fig_b[c], 2, NULL, 0 };
        return;
    }
    const double *p = fig4[i - 11];
    example4(m, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11]);
}

char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap + 1);
    size_t got;
    while ((got = fread(buf + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap)
            buf = realloc(buf, (cap *= 2) + 1);
    }
    fclose(f);
    buf[n] = '\0';
    if (len)
        *len = n;
    return buf;
}

void daemon_start(daemon_t *d, const char *dir, const char *args)
{
    const char *bin = getenv("PDESOLIDD_SAN") ? getenv("PDESOLIDD_SAN") : "build/san/pdesolidd";
    static int n;
    snprintf(d->log, sizeof d->log, "%s/daemon%d.log", dir, n++);
    char cmd[1024];
    /* Sanitised builds run several times slower: a job's deadline that suits them (a test's own args win). */
    snprintf(cmd, sizeof cmd, "exec %s --port 0 --threads 2 --job-timeout 30 %s 2>%s", bin, args, d->log);
    pid_t pid = fork();
    if (pid == 0) {
        execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
        _exit(127);
    }
    d->pid = (int)pid;
    /* Wait for "listening on http://127.0.0.1:PORT/". */
    for (int i = 0; i < 400; i++) {
        char *text = read_file(d->log, NULL);
        const char *p = text ? strstr(text, "listening on http://127.0.0.1:") : NULL;
        if (p) {
            d->port = atoi(p + strlen("listening on http://127.0.0.1:"));
            free(text);
            snprintf(d->base, sizeof d->base, "http://127.0.0.1:%d", d->port);
            return;
        }
        free(text);
        int st;
        if (waitpid(pid, &st, WNOHANG) == pid)
            fail_msg("pdesolidd exited at start (status %d)", st);
        usleep(25000);
    }
    fail_msg("pdesolidd did not start");
}

void daemon_stop(daemon_t *d)
{
    kill(d->pid, SIGTERM);
    int st;
    waitpid(d->pid, &st, 0);
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        char *log = read_file(d->log, NULL);
        fail_msg("pdesolidd exited with status %d:\n%s", WIFEXITED(st) ? WEXITSTATUS(st) : -1, log ? log : "");
    }
}

/* ---- raw HTTP over loopback sockets, and a strict JSON check ---- */

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <strings.h>
#include <sys/socket.h>
#include <time.h>

double mono_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

int raw_dial(int port)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0)
        return -1;
    struct sockaddr_in a = { .sin_family = AF_INET, .sin_port = htons((uint16_t)port) };
    inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    if (connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

void raw_send_all(int fd, const void *s, size_t n)
{
    const char *p = s;
    while (n > 0) {
        ssize_t k = send(fd, p, n, MSG_NOSIGNAL);
        if (k <= 0)
            return;
        p += k, n -= (size_t)k;
    }
}

long raw_read_to_close(int fd, char *buf, size_t cap, double seconds)
{
    size_t n = 0;
    double end = mono_now() + seconds;
    buf[0] = '\0';
    for (;;) {
        double left = end - mono_now();
        struct pollfd p = { fd, POLLIN, 0 };
        if (left <= 0 || poll(&p, 1, (int)(left * 1000) + 1) <= 0)
            return -1;
        ssize_t k = recv(fd, buf + n, cap - n - 1, 0);
        if (k <= 0) {
            buf[n] = '\0';
            return (long)n;
        }
        n += (size_t)k;
        buf[n] = '\0';
    }
}

void threads_start(pthread_t *t, int n, void *(*fn)(void *), void *args, size_t size)
{
    for (int i = 0; i < n; i++)
        assert_int_equal(pthread_create(&t[i], NULL, fn, (char *)args + (size_t)i * size), 0);
}

void threads_join(pthread_t *t, int n)
{
    for (int i = 0; i < n; i++)
        pthread_join(t[i], NULL);
}

void expect_problem_pointer(const cJSON *problem, const char *pointer, const char *body)
{
    const cJSON *ptr = cJSON_GetObjectItem(problem, "pointer");
    if (pointer) {
        if (!cJSON_IsString(ptr))
            fail_msg("no pointer in %s", body);
        assert_string_equal(ptr->valuestring, pointer);
    } else if (ptr) {
        fail_msg("a pointer where no field is at fault: %s", body);
    }
}

/* Case-insensitive search for a header in a head block; its value's start and length. */
static const char *head_find(const char *head, size_t hlen, const char *name, size_t *vlen)
{
    size_t nl = strlen(name);
    for (size_t i = 0; i + nl < hlen; i++) {
        if ((i == 0 || head[i - 1] == '\n') && !strncasecmp(head + i, name, nl) && head[i + nl] == ':') {
            const char *v = head + i + nl + 1;
            while (v < head + hlen && (*v == ' ' || *v == '\t'))
                v++;
            const char *e = v;
            while (e < head + hlen && *e != '\r' && *e != '\n')
                e++;
            *vlen = (size_t)(e - v);
            return v;
        }
    }
    return NULL;
}

/*
 * Parses one response at buf[0..n): returns the bytes it spans (head and
 * body), 0 if incomplete, or -1 if buf does not start with a status line.
 * to_close: the body runs to the close (no length, not chunked).
 */
static long parse_response(const char *buf, size_t n, int closed, int *status, size_t *head_len, char **body,
                           size_t *blen)
{
    if (n < 5)
        return closed && n ? -1 : 0;
    if (strncmp(buf, "HTTP/", 5))
        return -1;
    const char *end = NULL;
    for (size_t i = 0; i + 3 < n; i++)
        if (!memcmp(buf + i, "\r\n\r\n", 4)) {
            end = buf + i + 4;
            break;
        }
    if (!end)
        return 0;
    *head_len = (size_t)(end - buf);
    const char *sp = memchr(buf, ' ', *head_len);
    *status = sp ? atoi(sp + 1) : 0;
    size_t vlen;
    const char *te = head_find(buf, *head_len, "Transfer-Encoding", &vlen);
    const char *cl = head_find(buf, *head_len, "Content-Length", &vlen);
    size_t off = *head_len;
    *body = NULL;
    *blen = 0;
    if ((*status >= 100 && *status < 200) || *status == 204 || *status == 304) {
        *body = calloc(1, 1);
        return (long)off;
    }
    if (te && strstr(te, "chunked") && strstr(te, "chunked") < te + vlen) {
        size_t cap = 1;
        char *b = calloc(1, cap);
        size_t bl = 0;
        for (;;) {
            const char *line = buf + off, *crlf = NULL;
            for (size_t i = off; i + 1 < n; i++)
                if (buf[i] == '\r' && buf[i + 1] == '\n') {
                    crlf = buf + i;
                    break;
                }
            if (!crlf) {
                free(b);
                return 0;
            }
            unsigned long long k = strtoull(line, NULL, 16);
            off = (size_t)(crlf - buf) + 2;
            if (k == 0) {
                /* Trailers, then an empty line. */
                for (;;) {
                    const char *c2 = NULL;
                    for (size_t i = off; i + 1 < n; i++)
                        if (buf[i] == '\r' && buf[i + 1] == '\n') {
                            c2 = buf + i;
                            break;
                        }
                    if (!c2) {
                        free(b);
                        return 0;
                    }
                    int empty = c2 == buf + off;
                    off = (size_t)(c2 - buf) + 2;
                    if (empty)
                        break;
                }
                *body = b;
                *blen = bl;
                return (long)off;
            }
            if (k > n || off + k + 2 > n) {
                free(b);
                return 0;
            }
            b = realloc(b, bl + k + 1);
            memcpy(b + bl, buf + off, k);
            bl += k;
            b[bl] = '\0';
            off += k + 2;
        }
    }
    size_t want;
    if (cl)
        want = (size_t)strtoull(cl, NULL, 10);
    else if (closed)
        want = n - off;
    else
        return 0;
    if (n - off < want)
        return 0;
    *body = malloc(want + 1);
    memcpy(*body, buf + off, want);
    (*body)[want] = '\0';
    *blen = want;
    return (long)(off + want);
}

raw_reply raw_exchange(int fd, const void *req, size_t len, int timeout_ms)
{
    raw_reply r = { 0 };
    double t0 = mono_now(), deadline = t0 + timeout_ms / 1000.0;
    int fl = fcntl(fd, F_GETFL);
    fcntl(fd, F_SETFL, fl | O_NONBLOCK);
    size_t cap = 65536, n = 0, sent = 0, whole = len;
    char *buf = malloc(cap + 1);
    int complete = 0, reading_closed = 0;
    double quiet_until = 0;
    while (!reading_closed) {
        double t = mono_now();
        if (t >= deadline)
            break;
        if (complete && t >= quiet_until)
            break;
        double until = complete && quiet_until < deadline ? quiet_until : deadline;
        struct pollfd p = { fd, (short)(POLLIN | (sent < len ? POLLOUT : 0)), 0 };
        int ms = (int)((until - t) * 1000) + 1;
        if (poll(&p, 1, ms) <= 0)
            continue;
        if ((p.revents & POLLOUT) && sent < len) {
            ssize_t k = send(fd, (const char *)req + sent, len - sent, MSG_NOSIGNAL);
            if (k > 0)
                sent += (size_t)k;
            else if (k < 0 && errno != EAGAIN && errno != EWOULDBLOCK)
                len = sent;   /* the peer is gone: read what it said */
        }
        if (p.revents & (POLLIN | POLLHUP | POLLERR)) {
            if (n == cap)
                buf = realloc(buf, (cap *= 2) + 1);
            ssize_t k = recv(fd, buf + n, cap - n, 0);
            if (k > 0) {
                n += (size_t)k;
            } else if (k == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) {
                reading_closed = 1;
                r.closed = 1;
            }
        }
        /* Complete once a final response has fully arrived. */
        size_t off = 0;
        int fin = 0;
        for (;;) {
            int st;
            size_t hl, bl;
            char *b;
            long span = parse_response(buf + off, n - off, r.closed, &st, &hl, &b, &bl);
            if (span <= 0)
                break;
            free(b);
            off += (size_t)span;
            if (st >= 200) {
                fin = 1;
                break;
            }
        }
        if (fin && !complete) {
            complete = 1;
            r.first_response = mono_now() - t0;
            quiet_until = mono_now() + 0.3;
        }
    }
    buf[n] = '\0';
    r.sent_all = sent == whole;
    r.timed_out = !complete && !r.closed;
    /* Walk the responses: the first final one is the answer; count the rest. */
    size_t off = 0;
    for (;;) {
        int st;
        size_t hl, bl;
        char *b;
        long span = parse_response(buf + off, n - off, r.closed, &st, &hl, &b, &bl);
        if (span < 0) {
            /* Junk after a response: count any status line in it. */
            for (const char *q = buf + off; (q = strstr(q, "HTTP/1.")); q++)
                if (q == buf + off || q[-1] == '\n')
                    r.responses++;
            break;
        }
        if (span == 0) {
            if (n > off && !strncmp(buf + off, "HTTP/", 5))
                r.responses++;   /* a partial response still has a status line */
            break;
        }
        if (st >= 200) {
            r.responses++;
            if (!r.head) {
                r.status = st;
                r.head = malloc(hl + 1);
                memcpy(r.head, buf + off, hl);
                r.head[hl] = '\0';
                r.body = b;
                r.body_len = bl;
                b = NULL;
            }
        }
        free(b);
        off += (size_t)span;
    }
    /* A status line inside what a Content-Length claimed (libmicrohttpd 0.9.75 sends its head twice). */
    int lines = 0;
    for (size_t i = 0; i + 13 <= n; i++)
        if ((i == 0 || buf[i - 1] == '\n') && !strncmp(buf + i, "HTTP/1.", 7) && buf[i + 8] == ' ' &&
            buf[i + 9] >= '1' && buf[i + 9] <= '5' && buf[i + 12] == ' ' && buf[i + 9] != '1')
            lines++;
    if (lines > r.responses)
        r.responses = lines;
    if (!r.head)
        r.head = calloc(1, 1);
    if (!r.body)
        r.body = calloc(1, 1);
    free(buf);
    r.seconds = mono_now() - t0;
    return r;
}

raw_reply raw_request(int port, const void *req, size_t len, int timeout_ms)
{
    int fd = raw_dial(port);
    if (fd < 0) {
        raw_reply r = { 0 };
        r.head = calloc(1, 1);
        r.body = calloc(1, 1);
        r.closed = 1;
        return r;
    }
    raw_reply r = raw_exchange(fd, req, len, timeout_ms);
    close(fd);
    return r;
}

void raw_reply_free(raw_reply *r)
{
    free(r->head);
    free(r->body);
    r->head = r->body = NULL;
}

int raw_header(const raw_reply *r, const char *name, char *out, size_t n)
{
    return http_header(r->head, name, out, n);
}

int utf8_valid(const char *s, size_t n)
{
    const unsigned char *p = (const unsigned char *)s, *e = p + n;
    while (p < e) {
        unsigned c = *p;
        int k;
        unsigned cp, min;
        if (c < 0x80) {
            p++;
            continue;
        } else if ((c & 0xe0) == 0xc0) {
            k = 1, cp = c & 0x1f, min = 0x80;
        } else if ((c & 0xf0) == 0xe0) {
            k = 2, cp = c & 0x0f, min = 0x800;
        } else if ((c & 0xf8) == 0xf0) {
            k = 3, cp = c & 0x07, min = 0x10000;
        } else {
            return 0;
        }
        if (e - p <= k)
            return 0;
        for (int i = 1; i <= k; i++) {
            if ((p[i] & 0xc0) != 0x80)
                return 0;
            cp = cp << 6 | (p[i] & 0x3f);
        }
        if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
            return 0;
        p += k + 1;
    }
    return 1;
}

typedef struct {
    const char *p, *e;
    int depth;
} jscan;

static void j_ws(jscan *j)
{
    while (j->p < j->e && (*j->p == ' ' || *j->p == '\t' || *j->p == '\n' || *j->p == '\r'))
        j->p++;
}

static int j_hex4(jscan *j, unsigned *v)
{
    if (j->e - j->p < 4)
        return 0;
    *v = 0;
    for (int i = 0; i < 4; i++) {
        char c = j->p[i];
        int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
        if (d < 0)
            return 0;
        *v = *v << 4 | (unsigned)d;
    }
    j->p += 4;
    return 1;
}

static int j_string(jscan *j)
{
    if (j->p >= j->e || *j->p != '"')
        return 0;
    j->p++;
    const char *run = j->p;
    while (j->p < j->e) {
        unsigned char c = (unsigned char)*j->p;
        if (c == '"') {
            if (!utf8_valid(run, (size_t)(j->p - run)))
                return 0;
            j->p++;
            return 1;
        }
        if (c < 0x20)
            return 0;
        if (c == '\\') {
            if (!utf8_valid(run, (size_t)(j->p - run)))
                return 0;
            j->p++;
            if (j->p >= j->e)
                return 0;
            char x = *j->p++;
            if (x == 'u') {
                unsigned v, w;
                if (!j_hex4(j, &v))
                    return 0;
                if (v >= 0xdc00 && v <= 0xdfff)
                    return 0;   /* a lone low surrogate */
                if (v >= 0xd800 && v <= 0xdbff) {
                    if (j->e - j->p < 6 || j->p[0] != '\\' || j->p[1] != 'u')
                        return 0;
                    j->p += 2;
                    if (!j_hex4(j, &w) || w < 0xdc00 || w > 0xdfff)
                        return 0;
                }
            } else if (!strchr("\"\\/bfnrt", x) || x == 0) {
                return 0;
            }
            run = j->p;
            continue;
        }
        j->p++;
    }
    return 0;
}

static int j_digits(jscan *j)
{
    const char *s = j->p;
    while (j->p < j->e && *j->p >= '0' && *j->p <= '9')
        j->p++;
    return j->p > s;
}

static int j_number(jscan *j)
{
    if (j->p < j->e && *j->p == '-')
        j->p++;
    if (j->p < j->e && *j->p == '0')
        j->p++;
    else if (!j_digits(j))
        return 0;
    if (j->p < j->e && *j->p == '.') {
        j->p++;
        if (!j_digits(j))
            return 0;
    }
    if (j->p < j->e && (*j->p == 'e' || *j->p == 'E')) {
        j->p++;
        if (j->p < j->e && (*j->p == '+' || *j->p == '-'))
            j->p++;
        if (!j_digits(j))
            return 0;
    }
    return 1;
}

static int j_value(jscan *j)
{
    j_ws(j);
    if (j->p >= j->e || ++j->depth > 512)
        return 0;
    int ok = 0;
    char c = *j->p;
    if (c == '{' || c == '[') {
        char close_c = c == '{' ? '}' : ']';
        j->p++;
        j_ws(j);
        if (j->p < j->e && *j->p == close_c) {
            j->p++;
            ok = 1;
        } else {
            for (;;) {
                if (c == '{') {
                    j_ws(j);
                    if (!j_string(j))
                        break;
                    j_ws(j);
                    if (j->p >= j->e || *j->p++ != ':')
                        break;
                }
                if (!j_value(j))
                    break;
                j_ws(j);
                if (j->p < j->e && *j->p == ',') {
                    j->p++;
                    continue;
                }
                if (j->p < j->e && *j->p == close_c) {
                    j->p++;
                    ok = 1;
                }
                break;
            }
        }
    } else if (c == '"') {
        ok = j_string(j);
    } else if (c == '-' || (c >= '0' && c <= '9')) {
        ok = j_number(j);
    } else {
        static const char *const lit[] = { "true", "false", "null" };
        for (int i = 0; i < 3 && !ok; i++) {
            size_t l = strlen(lit[i]);
            if ((size_t)(j->e - j->p) >= l && !memcmp(j->p, lit[i], l)) {
                j->p += l;
                ok = 1;
            }
        }
    }
    j->depth--;
    return ok;
}

int json_strict_valid(const char *s, size_t n)
{
    jscan j = { s, s + n, 0 };
    if (!j_value(&j))
        return 0;
    j_ws(&j);
    return j.p == j.e;
}

/* ---- presets ---- */

api_model *preset_model(const char *name)
{
    const api_preset *ps = api_preset_find(name);
    if (!ps)
        fail_msg("no preset %s", name);
    api_params p;
    api_error err;
    api_preset_params(ps, &p);
    api_model *m = api_template_expand(api_preset_template(ps), &p, &err);
    assert_non_null(m);
    return m;
}

/* ---- HTTP through libcurl ---- */

static size_t on_body(char *p, size_t size, size_t n, void *cls)
{
    http_reply *r = cls;
    r->body = realloc(r->body, r->len + size * n + 1);
    memcpy(r->body + r->len, p, size * n);
    r->len += size * n;
    r->body[r->len] = '\0';
    return size * n;
}

static size_t on_header(char *p, size_t size, size_t n, void *cls)
{
    http_reply *r = cls;
    size_t have = strlen(r->headers);
    if (have + size * n < sizeof r->headers) {
        memcpy(r->headers + have, p, size * n);
        r->headers[have + size * n] = '\0';
    }
    return size * n;
}

http_reply http_request(void *handle, const char *base, const char *method, const char *path, const void *body,
                        size_t blen, const char *headers, const char *encoding)
{
    http_reply r = { 0 };
    CURL *c = handle ? handle : curl_easy_init();
    char url[512];
    snprintf(url, sizeof url, "%s%s", base, path);
    curl_easy_reset(c);
    curl_easy_setopt(c, CURLOPT_URL, url);
    curl_easy_setopt(c, CURLOPT_CUSTOMREQUEST, method);
    if (body) {
        curl_easy_setopt(c, CURLOPT_POSTFIELDS, body);
        curl_easy_setopt(c, CURLOPT_POSTFIELDSIZE_LARGE, (curl_off_t)blen);
    }
    struct curl_slist *h = curl_slist_append(NULL, "Expect:");
    for (const char *p = headers; p && *p;) {
        size_t k = strcspn(p, "\n");
        char line[512];
        snprintf(line, sizeof line, "%.*s", (int)(k < sizeof line ? k : sizeof line - 1), p);
        h = curl_slist_append(h, line);
        p += k + (p[k] == '\n');
    }
    curl_easy_setopt(c, CURLOPT_HTTPHEADER, h);
    if (encoding)
        curl_easy_setopt(c, CURLOPT_ACCEPT_ENCODING, encoding);
    curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, on_body);
    curl_easy_setopt(c, CURLOPT_WRITEDATA, &r);
    curl_easy_setopt(c, CURLOPT_HEADERFUNCTION, on_header);
    curl_easy_setopt(c, CURLOPT_HEADERDATA, &r);
    curl_easy_setopt(c, CURLOPT_TIMEOUT, 120L);
    CURLcode rc = curl_easy_perform(c);
    if (rc != CURLE_OK)
        r.status = -(long)rc;
    else
        curl_easy_getinfo(c, CURLINFO_RESPONSE_CODE, &r.status);
    curl_slist_free_all(h);
    if (!handle)
        curl_easy_cleanup(c);
    if (!r.body)
        r.body = calloc(1, 1);
    return r;
}

int http_header(const char *headers, const char *name, char *out, size_t n)
{
    const char *end = strstr(headers, "\r\n\r\n");
    size_t vlen;
    const char *v = head_find(headers, end ? (size_t)(end - headers) + 2 : strlen(headers), name, &vlen);
    if (!v)
        return 0;
    snprintf(out, n, "%.*s", (int)(vlen < n ? vlen : n - 1), v);
    return 1;
}

/* ---- temporary directories ---- */

int tmpdir_make(char *tmpl)
{
    return mkdtemp(tmpl) ? 0 : -1;
}

int tmpdir_remove(const char *dir)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* ---- running one case ---- */

void test_filter_from_env(void)
{
    const char *f = getenv("CMOCKA_FILTER");
    if (f && *f)
        cmocka_set_test_filter(f);
}
