/*
 * test_solve.c: pde_solve() against hand-derived closed forms and against the
 * independent multiple-shooting solver of support.c, in every case the core
 * distinguishes: e = 0, e > 0, e < 0, |e| <= 1, forces, resonance and near
 * resonance, polynomial chains, stiff terms, singular and ill-posed models.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "support.h"

#define TOL 1e-10

static double lambda(pde_factor f)
{
    double k = f.kind == PDE_SIN || f.kind == PDE_COS ? f.p * M_PI : f.kind == PDE_POW ? 0.0 : f.p;
    return k * k * k * k;
}

typedef struct {
    pde_factor u, v;
} uv;

/* Force terms of an independent problem: q_m(w) += coef f(w). */
typedef struct {
    int m;
    double coef;
    pde_factor w;
} qterm;

typedef struct {
    int n;
    qterm t[8];
    int M;
} qspec;

static void qfun(double w, double *out, void *ctx)
{
    const qspec *q = ctx;
    for (int m = 0; m < q->M; m++)
        out[m] = 0.0;
    for (int i = 0; i < q->n; i++)
        out[q->t[i].m] += q->t[i].coef * tfactor(q->t[i].w, w, 0);
}

static const double us[] = { 0.0, 0.13, 0.5, 0.77, 1.0 };
static const double ws[] = { 0.0, 1e-4, 1e-3, 0.01, 0.1, 0.25, 0.5, 0.62, 0.75, 0.9, 0.99, 0.999, 1.0 };
#define NU (sizeof us / sizeof *us)
#define NW (sizeof ws / sizeof *ws)

/* Component comp of sol against sum_m h_m(w) f_u(u) f_v(v), value and x_w, at a grid of points. */
static void compare_indep(const pde_solution *sol, int comp, const uv *modes, int M,
                          const indep_solution *ind, double tol)
{
    double ref[NU][NU][NW][2], scale[2] = { 0, 0 };
    for (size_t i = 0; i < NU; i++)
        for (size_t j = 0; j < NU; j++)
            for (size_t k = 0; k < NW; k++)
                for (int d = 0; d < 2; d++) {
                    double s = 0.0;
                    for (int m = 0; m < M; m++)
                        s += indep_eval(ind, m, d, ws[k]) * tfactor(modes[m].u, us[i], 0) *
                             tfactor(modes[m].v, us[j], 0);
                    ref[i][j][k][d] = s;
                    scale[d] = fmax(scale[d], fabs(s));
                }
    assert_true(scale[0] > 0.0);
    for (size_t i = 0; i < NU; i++)
        for (size_t j = 0; j < NU; j++)
            for (size_t k = 0; k < NW; k++) {
                double x[3], xw[3];
                pde_eval_d(sol, us[i], us[j], ws[k], x, NULL, NULL, xw);
                assert_rel(x[comp], ref[i][j][k][0], tol, scale[0]);
                assert_rel(xw[comp], ref[i][j][k][1], tol, scale[1]);
            }
}

/* A model with one component (x) holding the given terms; y and z are zero. */
static pde_model one_comp(double a, double b, double c, const pde_bterm *bt, size_t nb,
                          const pde_fterm *ft, size_t nf)
{
    pde_model m;
    memset(&m, 0, sizeof m);
    m.comp[0] = (pde_component){ a, b, c, bt, nb, ft, nf };
    m.comp[1] = m.comp[2] = (pde_component){ 1, 1, 1, NULL, 0, NULL, 0 };
    return m;
}

static pde_solution *solve_ok(const pde_model *m)
{
    pde_solution *sol = NULL;
    pde_diag d;
    pde_status st = pde_solve(m, &sol, &d);
    if (st != PDE_OK)
        fail_msg("pde_solve: %s: %s", pde_strerror(st), d.message);
    return sol;
}

/* One mode with force terms on that same mode, against the independent solver. */
static void check_single(double a, double b, double c, pde_bterm bt, const pde_fterm *ft, size_t nf,
                         double freq, double tol)
{
    pde_model m = one_comp(a, b, c, &bt, 1, ft, nf);
    pde_solution *sol = solve_ok(&m);
    double mu = a * lambda(bt.u) + b * lambda(bt.v);
    double bc[4] = { bt.w0, bt.dw0, bt.w1, bt.dw1 };
    qspec q = { .M = 1 };
    for (size_t i = 0; i < nf; i++)
        q.t[q.n++] = (qterm){ 0, ft[i].coef, ft[i].w };
    indep_problem p = { 1, c, &mu, NULL, bc, nf ? qfun : NULL, &q, freq };
    indep_solution *ind = indep_solve(&p);
    assert_non_null(ind);
    uv mode = { bt.u, bt.v };
    compare_indep(sol, 0, &mode, 1, ind, tol);
    indep_free(ind);
    pde_solution_free(sol);
}

/* ---- e = 0 ---- */

static void solve_should_give_the_hermite_cubic_when_e_is_zero(void **state)
{
    (void)state;
    pde_bterm bt[2] = { { F_pow(0), F_pow(0), 1, -2, 3, 0.5 }, { F_pow(1), F_pow(3), -1, 4, 0, 2 } };
    pde_model m = one_comp(2, 3, -7, bt, 2, NULL, 0);
    pde_solution *sol = solve_ok(&m);
    for (size_t i = 0; i < NU; i++)
        for (size_t k = 0; k < NW; k++) {
            double w = ws[k], u = us[i], v = us[(i + 2) % NU];
            double H00 = 2 * w * w * w - 3 * w * w + 1, H10 = w * w * w - 2 * w * w + w;
            double H01 = -2 * w * w * w + 3 * w * w, H11 = w * w * w - w * w;
            double want = 0.0;
            for (int j = 0; j < 2; j++)
                want += (bt[j].w0 * H00 + bt[j].dw0 * H10 + bt[j].w1 * H01 + bt[j].dw1 * H11) *
                        tfactor(bt[j].u, u, 0) * tfactor(bt[j].v, v, 0);
            double x[3];
            pde_eval(sol, u, v, w, x);
            assert_rel(x[0], want, 1e-13, 1.0);
            assert_true(x[1] == 0.0 && x[2] == 0.0);
        }
    pde_solution_free(sol);
}

/* ---- e > 0 and the paper's t ---- */

/* h'''' = e h with t = e^(1/4): the 4x4 fit of C1 e^{t(w-1)} + C2 e^{-tw} + C3 cos tw + C4 sin tw, by hand. */
static void hand_fit(double t, const double bc[4], double C[4])
{
    double E = exp(-t);
    long double M[4][5] = {
        { E, 1, 1, 0, bc[0] },
        { t * E, -t, 0, t, bc[1] },
        { 1, E, cos(t), sin(t), bc[2] },
        { t, -t * E, -t * sin(t), t * cos(t), bc[3] },
    };
    for (int k = 0; k < 4; k++) {
        int p = k;
        for (int i = k + 1; i < 4; i++)
            if (fabsl(M[i][k]) > fabsl(M[p][k]))
                p = i;
        for (int j = 0; j < 5; j++) {
            long double x = M[k][j];
            M[k][j] = M[p][j];
            M[p][j] = x;
        }
        for (int i = k + 1; i < 4; i++) {
            long double f = M[i][k] / M[k][k];
            for (int j = k; j < 5; j++)
                M[i][j] -= f * M[k][j];
        }
    }
    for (int i = 3; i >= 0; i--) {
        long double s = M[i][4];
        for (int j = i + 1; j < 4; j++)
            s -= M[i][j] * C[j];
        C[i] = (double)(s / M[i][i]);
    }
}

static double hand_h(double t, const double C[4], double w)
{
    return C[0] * exp(t * (w - 1)) + C[1] * exp(-t * w) + C[2] * cos(t * w) + C[3] * sin(t * w);
}

static void solve_should_use_t_equal_to_the_fourth_root_of_e_not_the_papers_printed_t(void **state)
{
    (void)state;
    /* Fig. 2b's x: u sin(2 pi v), b = 2.5, c = -10. */
    double b = 2.5, c = -10;
    pde_bterm bt = { F_pow(1), F_sin(2), 0.5, 0.5, 0.5, 0 };
    pde_model m = one_comp(1, b, c, &bt, 1, NULL, 0);
    pde_solution *sol = solve_ok(&m);
    size_t nm;
    const pde_mode *md = pde_solution_modes(sol, 0, &nm);
    assert_int_equal(nm, 1);
    double t_pde = 2 * M_PI * pow(-b / c, 0.25);     /* e^(1/4): satisfies eq. (7) */
    double t_paper = 2 * M_PI * sqrt(-b / c);        /* as printed in eqs. (21), (24), (27) */
    assert_rel(pow(md[0].e, 0.25), t_pde, 1e-15, 0);
    double bc[4] = { bt.w0, bt.dw0, bt.w1, bt.dw1 }, C[4], P[4];
    hand_fit(t_pde, bc, C);
    hand_fit(t_paper, bc, P);
    for (size_t k = 0; k < NW; k++) {
        double x[3];
        pde_eval(sol, 1.0, 0.25, ws[k], x);
        assert_rel(x[0], hand_h(t_pde, C, ws[k]), 1e-12, 1.0);
    }
    /* eq. (7) residual h'''' - e h of each, by central differences at w = 0.4. */
    double e = md[0].e, hh = 1e-2, res[2];
    for (int which = 0; which < 2; which++) {
        double t = which ? t_paper : t_pde, *K = which ? P : C, f[5];
        for (int i = 0; i < 5; i++)
            f[i] = hand_h(t, K, 0.4 + (i - 2) * hh);
        double d4 = (f[0] - 4 * f[1] + 6 * f[2] - 4 * f[3] + f[4]) / (hh * hh * hh * hh);
        res[which] = fabs(d4 - e * f[2]) / (fabs(d4) + fabs(e * f[2]));
    }
    assert_true(res[0] < 1e-3);   /* the difference quotient's own error */
    assert_true(res[1] > 0.3);    /* the printed t is not a solution */
    pde_solution_free(sol);
}

static void solve_should_match_independent_solution_when_e_is_positive(void **state)
{
    (void)state;
    pde_bterm bt = { F_pow(2), F_sin(1.5), 0.3, -1.2, 0.8, 2.0 };
    check_single(1, 1, -1, bt, NULL, 0, 0, TOL);
    pde_bterm bt2 = { F_cos(1), F_sinh(2), 1, 0, -1, 0.5 };
    check_single(2, 0.5, -3, bt2, NULL, 0, 0, TOL);
}

static void solve_should_match_independent_solution_when_e_is_negative(void **state)
{
    (void)state;
    pde_bterm bt = { F_sin(1), F_cos(2), 0.7, 0.1, -0.4, 1.5 };
    check_single(1, 1, 2, bt, NULL, 0, 0, TOL);
    pde_bterm bt2 = { F_exp(-1.5), F_cosh(3), 1, 2, 3, 4 };
    check_single(1, 2, 0.25, bt2, NULL, 0, 0, TOL);
}

static void solve_should_stay_exact_when_e_is_small(void **state)
{
    (void)state;
    /* |e| <= 1: the power-series regime, and either side of its edge. */
    const double alphas[] = { 1e-6, 0.01, 0.3, 0.999999, 1.0, 1.000001, 1.2 };
    for (size_t i = 0; i < sizeof alphas / sizeof *alphas; i++)
        for (int sign = -1; sign <= 1; sign += 2) {
            pde_bterm bt = { F_exp(alphas[i]), F_pow(0), 1, -0.5, 2, 0.25 };
            pde_fterm ft[2] = { { 0.7, F_exp(alphas[i]), F_pow(0), F_exp(0.4) },
                                { -1.3, F_exp(alphas[i]), F_pow(0), F_pow(3) } };
            check_single(1, 1, -sign, bt, ft, 2, 1, TOL);
        }
}

/* ---- forces ---- */

static void solve_should_meet_the_tangent_conditions_that_the_papers_eq_30_misses(void **state)
{
    (void)state;
    /* Fig. 4a's x: u sin 2pi v on the boundary, p0 u cos 2pi v sin(xi pi w) as the force. */
    double b = 1, c = -9.5, p0 = 3e4, xi = 3;
    pde_bterm bt = { F_pow(1), F_sin(2), 0.5, 0, 0.5, 0 };
    pde_fterm ft = { p0, F_pow(1), F_cos(2), F_sin(xi) };
    pde_model m = one_comp(1, b, c, &bt, 1, &ft, 1);
    pde_solution *sol = solve_ok(&m);
    /* eq. (29) is the right particular solution: the sin(xi pi w) term of mode u cos 2pi v. */
    size_t nm;
    const pde_mode *md = pde_solution_modes(sol, 0, &nm);
    assert_int_equal(nm, 2);
    double K = p0 / ((16 * b + c * pow(xi, 4)) * pow(M_PI, 4)), found = NAN;
    for (size_t i = 0; i < nm; i++)
        for (size_t k = 0; k < md[i].nterms; k++)
            if (md[i].v.kind == PDE_COS && md[i].terms[k].beta == xi * M_PI && md[i].terms[k].alpha == 0)
                found = md[i].terms[k].B[0];
    assert_rel(found, K, 1e-14, 0);
    /* Ours: x_w = 0 at w = 0 and 1. Eq. (30) adds K u sin(xi pi w) cos 2pi v to a complementary
     * part fitted to the boundary data alone, so its x_w at w = 0 is xi pi K u cos 2pi v. */
    for (size_t i = 0; i < NU; i++)
        for (int side = 0; side < 2; side++) {
            double xw[3], u = us[i], v = us[(i + 1) % NU];
            pde_eval_d(sol, u, v, side, NULL, NULL, NULL, xw);
            assert_true(fabs(xw[0]) < 1e-12);
        }
    double paper_tangent = xi * M_PI * K * 1.0 * cos(0.0);
    assert_true(fabs(paper_tangent) > 0.1);
    /* And against the independent solver, both modes. */
    double mu = b * pow(2 * M_PI, 4), mus[2] = { mu, mu }, bc[8] = { 0.5, 0, 0.5, 0, 0, 0, 0, 0 };
    qspec q = { .M = 2, .n = 1, .t = { { 1, p0, F_sin(xi) } } };
    indep_problem p = { 2, c, mus, NULL, bc, qfun, &q, xi * M_PI };
    indep_solution *ind = indep_solve(&p);
    uv modes[2] = { { F_pow(1), F_sin(2) }, { F_pow(1), F_cos(2) } };
    compare_indep(sol, 0, modes, 2, ind, TOL);
    indep_free(ind);
    pde_solution_free(sol);
}

static void solve_should_match_independent_solution_for_every_kind_of_force(void **state)
{
    (void)state;
    pde_bterm bt = { F_pow(1), F_sin(1), 0.5, 1, -0.5, 2 };
    pde_fterm ft[6] = { { 50, F_pow(1), F_sin(1), F_sin(2.5) },  { -20, F_pow(1), F_sin(1), F_cos(1.5) },
                        { 3, F_pow(1), F_sin(1), F_exp(2) },     { 4, F_pow(1), F_sin(1), F_sinh(-3) },
                        { 1.5, F_pow(1), F_sin(1), F_cosh(1) },  { 7, F_pow(1), F_sin(1), F_pow(5) } };
    check_single(1, 1, -0.2, bt, ft, 6, 8, TOL);   /* e > 0 */
    check_single(1, 1, 0.2, bt, ft, 6, 8, TOL);    /* e < 0 */
    check_single(1, 1e-9, 3, bt, ft, 6, 8, TOL);   /* |e| small */
}

static void solve_should_give_the_secular_form_at_resonance(void **state)
{
    (void)state;
    /* t = 2 pi and the force sin(2 pi w): h_p = (F/c) w cos(tw) / (4 t^3), by hand. */
    double c = -1, F = 40, t = 2 * M_PI;
    pde_bterm bt = { F_pow(1), F_sin(2), 0.2, 0, 1, -1 };
    pde_fterm ft = { F, F_pow(1), F_sin(2), F_sin(2) };
    pde_model m = one_comp(1, 1, c, &bt, 1, &ft, 1);
    pde_solution *sol = solve_ok(&m);
    double hp[4] = { 0, F / c / (4 * t * t * t), F / c / (4 * t * t * t) * (cos(t) - t * sin(t)), 0 };
    hp[3] = F / c / (4 * t * t * t) * (cos(t) - t * sin(t));
    hp[2] = F / c / (4 * t * t * t) * cos(t);
    double bc[4] = { bt.w0 - 0.0, bt.dw0 - hp[1], bt.w1 - hp[2], bt.dw1 - hp[3] }, C[4];
    hand_fit(t, bc, C);
    for (size_t k = 0; k < NW; k++) {
        double w = ws[k], x[3];
        double want = hand_h(t, C, w) + F / c * w * cos(t * w) / (4 * t * t * t);
        pde_eval(sol, 1.0, 0.25, w, x);
        assert_rel(x[0], want, 1e-12, 0.1);
    }
    pde_solution_free(sol);
    check_single(1, 1, c, bt, &ft, 1, t, TOL);
    /* A real root: t = 3 and the force exp(3 w). */
    pde_bterm bt2 = { F_pow(0), F_exp(3), 1, 0, 0, 1 };
    pde_fterm ft2 = { 2, F_pow(0), F_exp(3), F_exp(3) };
    check_single(1, 1, -1, bt2, &ft2, 1, 3, TOL);
    pde_fterm ft3 = { 2, F_pow(0), F_exp(3), F_exp(-3) };
    check_single(1, 1, -1, bt2, &ft3, 1, 3, TOL);
    /* Resonance with a polynomial in front: the force w^2 cos(2 pi w), via two factors is not
     * expressible, so a chain supplies it below; here a cosine at resonance. */
    pde_fterm ft4 = { -15, F_pow(1), F_sin(2), F_cos(-2) };
    check_single(1, 1, c, bt, &ft4, 1, t, TOL);
}

static void solve_should_stay_exact_near_resonance(void **state)
{
    (void)state;
    const double d[] = { 1e-13, 1e-9, 1e-6, 1e-3, 0.05, 0.15, 0.16, 0.3 };
    pde_bterm bt = { F_pow(1), F_sin(2), 0.2, 0, 1, -1 };
    for (size_t i = 0; i < sizeof d / sizeof *d; i++)
        for (int s = -1; s <= 1; s += 2) {
            pde_fterm ft = { 40, F_pow(1), F_sin(2), F_sin(2 + s * d[i]) };
            check_single(1, 1, -1, bt, &ft, 1, 7, TOL);
        }
}

/* ---- polynomial chains ---- */

static void solve_should_chain_powers_of_four_and_more(void **state)
{
    (void)state;
    /* u^8 sin(pi v): modes u^8, u^4, 1, each forced by the one above. */
    double a = 1.5, b = 1, c = -2;
    pde_bterm bt = { F_pow(8), F_sin(1), 1, 0, 2, 1 };
    pde_fterm ft = { 3, F_pow(4), F_sin(1), F_sin(1) };
    pde_model m = one_comp(a, b, c, &bt, 1, &ft, 1);
    pde_solution *sol = solve_ok(&m);
    double mu = b * pow(M_PI, 4), mus[3] = { mu, mu, mu };
    double K[9] = { 0, 0, 0, a * 8 * 7 * 6 * 5, 0, 0, 0, a * 4 * 3 * 2 * 1, 0 };
    double bc[12] = { 1, 0, 2, 1 };
    qspec q = { .M = 3, .n = 1, .t = { { 1, 3, F_sin(1) } } };
    indep_problem p = { 3, c, mus, K, bc, qfun, &q, M_PI };
    indep_solution *ind = indep_solve(&p);
    uv modes[3] = { { F_pow(8), F_sin(1) }, { F_pow(4), F_sin(1) }, { F_pow(0), F_sin(1) } };
    compare_indep(sol, 0, modes, 3, ind, TOL);
    indep_free(ind);
    pde_solution_free(sol);

    /* u^5 v^6 with e = 0 and a w^2 force: four coupled modes. */
    pde_bterm bt2 = { F_pow(5), F_pow(6), 1, -1, 0.5, 2 };
    pde_fterm ft2 = { 2, F_pow(5), F_pow(6), F_pow(2) };
    m = one_comp(a, b, c, &bt2, 1, &ft2, 1);
    sol = solve_ok(&m);
    double mu0[4] = { 0, 0, 0, 0 };
    /* modes: 0 (5,6), 1 (1,6), 2 (5,2), 3 (1,2) */
    double K2[16] = { 0 };
    K2[1 * 4 + 0] = a * 5 * 4 * 3 * 2;
    K2[2 * 4 + 0] = b * 6 * 5 * 4 * 3;
    K2[3 * 4 + 1] = b * 6 * 5 * 4 * 3;
    K2[3 * 4 + 2] = a * 5 * 4 * 3 * 2;
    double bc2[16] = { 1, -1, 0.5, 2 };
    qspec q2 = { .M = 4, .n = 1, .t = { { 0, 2, F_pow(2) } } };
    indep_problem p2 = { 4, c, mu0, K2, bc2, qfun, &q2, 1 };
    ind = indep_solve(&p2);
    uv modes2[4] = { { F_pow(5), F_pow(6) }, { F_pow(1), F_pow(6) }, { F_pow(5), F_pow(2) }, { F_pow(1), F_pow(2) } };
    compare_indep(sol, 0, modes2, 4, ind, TOL);
    indep_free(ind);
    pde_solution_free(sol);
}

/* ---- stiff terms ---- */

static void solve_should_stay_exact_for_stiff_terms_up_to_k_300(void **state)
{
    (void)state;
    /* t = 300 pi ~ 942: exp(942) would overflow; the scaled exponentials do not. */
    pde_bterm bt = { F_pow(1), F_sin(300), 0.5, -2, 1, 3 };
    pde_fterm ft = { 1e9, F_pow(1), F_sin(300), F_sin(2) };
    check_single(1, 1, -1, bt, &ft, 1, 300 * M_PI, TOL);
    check_single(1, 1, 1, bt, &ft, 1, 300 * M_PI, TOL);
    pde_bterm bt2 = { F_cos(150), F_cos(200), 1, 1, 1, 1 };
    check_single(1, 1, -1, bt2, NULL, 0, 0, TOL);
}

/* ---- singular and ill-posed ---- */

static void solve_should_report_the_clamped_eigenvalues_as_singular(void **state)
{
    (void)state;
    /* Roots of cos t cosh t = 1, the clamped-beam eigenvalues. */
    const double t0[] = { 4.730040744862704, 7.853204624095838, 10.99560783800167 };
    for (size_t i = 0; i < 3; i++) {
        double c = -pow(M_PI / t0[i], 4);     /* e = pi^4 / |c| = t0^4 for sin(pi v) */
        pde_bterm bt[2] = { { F_pow(2), F_pow(0), 1, 0, 1, 0 }, { F_pow(1), F_sin(1), 1, 0, 0, 0 } };
        pde_model m = one_comp(1, 1, c, bt, 2, NULL, 0);
        m.comp[1] = m.comp[0];
        m.comp[0] = (pde_component){ 1, 1, 1, NULL, 0, NULL, 0 };
        pde_solution *sol = (pde_solution *)0x1;
        pde_diag d;
        assert_int_equal(pde_solve(&m, &sol, &d), PDE_ERR_SINGULAR);
        assert_ptr_equal(sol, (pde_solution *)0x1);
        assert_int_equal(d.component, 1);
        assert_int_equal(d.in_force, 0);
        assert_int_equal(d.term, 1);
        assert_non_null(strstr(d.message, "component y"));
        assert_non_null(strstr(d.message, "eigenvalue"));
        /* Just off the eigenvalue it solves, and e < 0 (c > 0) never is singular. */
        m.comp[1].c = c * 1.01;
        sol = solve_ok(&m);
        pde_solution_free(sol);
        m.comp[1].c = -c;
        sol = solve_ok(&m);
        pde_solution_free(sol);
    }
}

static void expect_error(const pde_model *m, pde_status want, int comp, int in_force, long term,
                         const char *field)
{
    pde_solution *sol = NULL;
    pde_diag d;
    assert_int_equal(pde_solve(m, &sol, &d), want);
    assert_null(sol);
    assert_int_equal(d.component, comp);
    if (term >= 0)
        assert_int_equal(d.in_force, in_force);
    assert_int_equal(d.term, term);
    assert_string_equal(d.field, field);
    assert_true(strlen(d.message) > 10);
}

static void solve_should_reject_ill_posed_and_non_finite_models(void **state)
{
    (void)state;
    pde_bterm bt[2] = { { F_pow(1), F_sin(2), 1, 0, 1, 0 }, { F_pow(0), F_pow(0), 1, 0, 1, 0 } };
    pde_fterm ft[2] = { { 1, F_pow(0), F_pow(0), F_pow(0) }, { 1, F_pow(0), F_pow(0), F_pow(0) } };
    pde_model m = one_comp(1, 1, 0, bt, 2, ft, 2);
    expect_error(&m, PDE_ERR_ILLPOSED, 0, 0, -1, "c");
    m.comp[0].c = -1;
    m.comp[2].a = NAN;
    expect_error(&m, PDE_ERR_INVALID, 2, 0, -1, "a");
    m.comp[2].a = 1;
    m.comp[1].b = INFINITY;
    expect_error(&m, PDE_ERR_INVALID, 1, 0, -1, "b");
    m.comp[1].b = 1;
    bt[1].dw1 = NAN;
    expect_error(&m, PDE_ERR_INVALID, 0, 0, 1, "dw1");
    bt[1].dw1 = 0;
    bt[1].v = F_pow(2);
    bt[1].v.p = 2.5;
    expect_error(&m, PDE_ERR_INVALID, 0, 0, 1, "v");
    bt[1].v = F_pow(-1);
    expect_error(&m, PDE_ERR_INVALID, 0, 0, 1, "v");
    bt[1].v = F_pow(101);
    expect_error(&m, PDE_ERR_INVALID, 0, 0, 1, "v");
    bt[1].v = F_pow(0);
    ft[1].w = F_exp(800);
    expect_error(&m, PDE_ERR_INVALID, 0, 1, 1, "w");
    ft[1].w = F_sinh(NAN);
    expect_error(&m, PDE_ERR_INVALID, 0, 1, 1, "w");
    ft[1].w = F_pow(0);
    ft[0].coef = -INFINITY;
    expect_error(&m, PDE_ERR_INVALID, 0, 1, 0, "coef");
    ft[0].coef = 1;
    ft[0].u.kind = (pde_factor_kind)42;
    expect_error(&m, PDE_ERR_INVALID, 0, 1, 0, "u");
    ft[0].u = F_pow(0);
    /* A force that overflows the solution's coefficients. */
    ft[0].coef = 1e300;
    ft[0].u = F_pow(2);
    ft[0].w = F_exp(700);
    expect_error(&m, PDE_ERR_RANGE, 0, 1, 0, "");
    /* A NULL model or output. */
    pde_solution *sol;
    assert_int_equal(pde_solve(NULL, &sol, NULL), PDE_ERR_INVALID);
    assert_int_equal(pde_solve(&m, NULL, NULL), PDE_ERR_INVALID);
}

static void solve_should_reject_models_with_too_many_modes(void **state)
{
    (void)state;
    static pde_bterm bt[200];
    for (int i = 0; i < 200; i++)
        bt[i] = (pde_bterm){ F_sin(i + 1), F_pow(100), 1, 0, 0, 0 };   /* 26 modes each */
    pde_model m = one_comp(1, 1, -1, bt, 200, NULL, 0);
    expect_error(&m, PDE_ERR_LIMIT, 0, 0, -1, "");
}

/* ---- merging and normalisation ---- */

static void solve_should_add_up_terms_with_equal_factors(void **state)
{
    (void)state;
    pde_bterm split[4] = { { F_pow(1), F_sin(2), 1, 0, 0.5, 0 },
                           { F_pow(1), F_sin(2), 2, 1, 0, 0 },
                           { F_pow(1), F_sin(-2), 0, 0, -0.5, 1 },   /* sin(-2) = -sin(2) */
                           { F_sinh(0), F_cos(3), 9, 9, 9, 9 } };    /* sinh 0 = 0 */
    pde_bterm whole = { F_pow(1), F_sin(2), 3, 1, 1, -1 };
    pde_fterm fs[2] = { { 1, F_pow(0), F_cos(-1), F_sin(2) }, { 2, F_pow(0), F_cos(1), F_sin(2) } };
    pde_fterm fw = { 3, F_exp(0), F_cos(1), F_sin(2) };
    pde_model a = one_comp(1, 1, -1, split, 4, fs, 2), b = one_comp(1, 1, -1, &whole, 1, &fw, 1);
    pde_solution *sa = solve_ok(&a), *sb = solve_ok(&b);
    size_t na, nb;
    pde_solution_modes(sa, 0, &na);
    pde_solution_modes(sb, 0, &nb);
    assert_int_equal(na, nb);
    for (size_t i = 0; i < NU; i++)
        for (size_t k = 0; k < NW; k++) {
            double xa[3], xb[3];
            pde_eval(sa, us[i], us[(i + 3) % NU], ws[k], xa);
            pde_eval(sb, us[i], us[(i + 3) % NU], ws[k], xb);
            assert_rel(xa[0], xb[0], 1e-14, 1.0);
        }
    pde_solution_free(sa);
    pde_solution_free(sb);
}

static void solve_should_give_an_empty_solution_for_an_empty_model(void **state)
{
    (void)state;
    pde_model m = one_comp(1, 1, -1, NULL, 0, NULL, 0);
    pde_solution *sol = solve_ok(&m);
    double x[3] = { 1, 1, 1 };
    pde_eval(sol, 0.3, 0.3, 0.3, x);
    assert_true(x[0] == 0 && x[1] == 0 && x[2] == 0);
    assert_true(pde_solution_bytes(sol) > 0);
    pde_solution_free(sol);
    pde_solution_free(NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(solve_should_give_the_hermite_cubic_when_e_is_zero),
        cmocka_unit_test(solve_should_use_t_equal_to_the_fourth_root_of_e_not_the_papers_printed_t),
        cmocka_unit_test(solve_should_match_independent_solution_when_e_is_positive),
        cmocka_unit_test(solve_should_match_independent_solution_when_e_is_negative),
        cmocka_unit_test(solve_should_stay_exact_when_e_is_small),
        cmocka_unit_test(solve_should_meet_the_tangent_conditions_that_the_papers_eq_30_misses),
        cmocka_unit_test(solve_should_match_independent_solution_for_every_kind_of_force),
        cmocka_unit_test(solve_should_give_the_secular_form_at_resonance),
        cmocka_unit_test(solve_should_stay_exact_near_resonance),
        cmocka_unit_test(solve_should_chain_powers_of_four_and_more),
        cmocka_unit_test(solve_should_stay_exact_for_stiff_terms_up_to_k_300),
        cmocka_unit_test(solve_should_report_the_clamped_eigenvalues_as_singular),
        cmocka_unit_test(solve_should_reject_ill_posed_and_non_finite_models),
        cmocka_unit_test(solve_should_reject_models_with_too_many_modes),
        cmocka_unit_test(solve_should_add_up_terms_with_equal_factors),
        cmocka_unit_test(solve_should_give_an_empty_solution_for_an_empty_model),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("solve", tests, NULL, NULL);
}
