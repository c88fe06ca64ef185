/*
 * test_eval.c: evaluation and sampling. Points, derivatives of any order,
 * grids and faces against pointwise evaluation, and evaluation from many
 * threads at once.
 */
#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "support.h"

static pde_solution *solve_figure(const char *name)
{
    for (size_t i = 0; i < paper_figure_count(); i++)
        if (strcmp(paper_figure_name(i), name) == 0) {
            pde_model m;
            paper_figure_model(i, &m);
            pde_solution *sol = NULL;
            assert_int_equal(pde_solve(&m, &sol, NULL), PDE_OK);
            return sol;
        }
    fail_msg("no figure %s", name);
    return NULL;
}

#define NPTS 3000

typedef struct {
    const pde_solution *sol;
    const double *pts;
    double *out;     /* 12 per point */
} job;

static void eval_all(const pde_solution *sol, const double *pts, double *out)
{
    for (int i = 0; i < NPTS; i++)
        pde_eval_d(sol, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], out + 12 * i, out + 12 * i + 3,
                   out + 12 * i + 6, out + 12 * i + 9);
}

static void *worker(void *arg)
{
    job *j = arg;
    eval_all(j->sol, j->pts, j->out);
    return NULL;
}

static void eval_should_give_identical_results_from_many_threads(void **state)
{
    (void)state;
    const char *figs[2] = { "fig3b", "fig4x" };
    for (int f = 0; f < 2; f++) {
        pde_solution *sol = solve_figure(figs[f]);
        double *pts = malloc(3 * NPTS * sizeof *pts), *ref = malloc(12 * NPTS * sizeof *ref);
        srand(7);
        for (int i = 0; i < 3 * NPTS; i++)
            pts[i] = (double)rand() / RAND_MAX;
        eval_all(sol, pts, ref);
        enum { T = 8 };
        pthread_t th[T];
        job jobs[T];
        for (int t = 0; t < T; t++) {
            jobs[t] = (job){ sol, pts, malloc(12 * NPTS * sizeof(double)) };
            assert_int_equal(pthread_create(&th[t], NULL, worker, &jobs[t]), 0);
        }
        for (int t = 0; t < T; t++) {
            pthread_join(th[t], NULL);
            assert_memory_equal(jobs[t].out, ref, 12 * NPTS * sizeof(double));
            free(jobs[t].out);
        }
        free(pts);
        free(ref);
        pde_solution_free(sol);
    }
}

static void sample_should_match_pointwise_evaluation(void **state)
{
    (void)state;
    pde_solution *sol = solve_figure("fig3c");
    enum { NU = 17, NV = 33, NW = 9 };
    float *g = malloc(3 * NU * NV * NW * sizeof *g);
    assert_int_equal(pde_sample(sol, NU, NV, NW, g), PDE_OK);
    for (int k = 0; k < NW; k++)
        for (int j = 0; j < NV; j++)
            for (int i = 0; i < NU; i++) {
                double x[3];
                pde_eval(sol, i / (NU - 1.0), j / (NV - 1.0), k / (NW - 1.0), x);
                for (int c = 0; c < 3; c++)
                    assert_rel(g[3 * ((k * NV + j) * NU + i) + c], x[c], 1e-6, 1.0);
            }
    free(g);
    assert_int_equal(pde_sample(sol, 0, 3, 3, NULL), PDE_ERR_INVALID);
    pde_solution_free(sol);
}

static void grid_should_give_faces_and_derivatives(void **state)
{
    (void)state;
    pde_solution *sol = solve_figure("fig4d");
    double vs[21], one[1] = { 1.0 };
    for (int j = 0; j < 21; j++)
        vs[j] = j / 20.0;
    /* The face u = 1: a grid with one u sample; planes are w = const. */
    pde_grid *g;
    assert_int_equal(pde_grid_create(sol, one, 1, vs, 21, &g), PDE_OK);
    float xyz[63], xu[63], xv[63], xw[63];
    for (int k = 0; k <= 4; k++) {
        double w = k / 4.0;
        pde_grid_plane_d(g, w, xyz, xu, xv, xw);
        float only[63];
        pde_grid_plane(g, w, only);
        assert_memory_equal(only, xyz, sizeof only);
        for (int j = 0; j < 21; j++) {
            double x[3], du[3], dv[3], dw[3];
            pde_eval_d(sol, 1.0, vs[j], w, x, du, dv, dw);
            for (int c = 0; c < 3; c++) {
                assert_rel(xyz[3 * j + c], x[c], 1e-6, 1.0);
                assert_rel(xu[3 * j + c], du[c], 1e-6, 1.0);
                assert_rel(xv[3 * j + c], dv[c], 1e-6, 1.0);
                assert_rel(xw[3 * j + c], dw[c], 1e-6, 1.0);
            }
        }
    }
    pde_grid_free(g);
    pde_grid_free(NULL);
    assert_int_equal(pde_grid_create(sol, one, 0, vs, 21, &g), PDE_ERR_INVALID);
    pde_solution_free(sol);
}

/* Richardson-extrapolated central differences of order n (1..4) along one axis. */
static double fd(const pde_solution *sol, int comp, const double p[3], int axis, int n, double h)
{
    static const double st[5][5] = { { 0 }, { 0, -0.5, 0, 0.5, 0 }, { 0, 1, -2, 1, 0 },
                                      { -0.5, 1, 0, -1, 0.5 }, { 1, -4, 6, -4, 1 } };
    double d[2];
    for (int r = 0; r < 2; r++) {
        double hh = r ? 2 * h : h, s = 0.0;
        for (int i = 0; i < 5; i++) {
            if (st[n][i] == 0.0)
                continue;
            double q[3] = { p[0], p[1], p[2] }, x[3];
            q[axis] += (i - 2) * hh;
            pde_eval(sol, q[0], q[1], q[2], x);
            s += st[n][i] * x[comp];
        }
        d[r] = s / pow(hh, n);
    }
    return (4 * d[0] - d[1]) / 3;
}

static void eval_partial_should_agree_with_differences_and_first_derivatives(void **state)
{
    (void)state;
    const char *figs[3] = { "fig2b", "fig4a", "fig1g" };
    for (int f = 0; f < 3; f++) {
        pde_solution *sol = solve_figure(figs[f]);
        const double p[3] = { 0.4, 0.3, 0.55 };
        double x[3], d1[3][3];
        pde_eval_d(sol, p[0], p[1], p[2], x, d1[0], d1[1], d1[2]);
        for (int c = 0; c < 3; c++) {
            assert_rel(pde_eval_partial(sol, c, p[0], p[1], p[2], 0, 0, 0), x[c], 1e-13, 1.0);
            for (int axis = 0; axis < 3; axis++) {
                int ord[3] = { 0, 0, 0 };
                ord[axis] = 1;
                double a1 = pde_eval_partial(sol, c, p[0], p[1], p[2], ord[0], ord[1], ord[2]);
                assert_rel(a1, d1[axis][c], 1e-12, 1.0);
                for (int n = 1; n <= 4; n++) {
                    ord[axis] = n;
                    double an = pde_eval_partial(sol, c, p[0], p[1], p[2], ord[0], ord[1], ord[2]);
                    double scale = fmax(1.0, pow(2 * M_PI, n));
                    assert_rel(an, fd(sol, c, p, axis, n, 2e-3), 1e-5, scale);
                }
            }
        }
        pde_solution_free(sol);
    }
}

static void force_should_be_the_models_force(void **state)
{
    (void)state;
    pde_solution *sol = solve_figure("fig4c");
    for (int i = 0; i < 10; i++) {
        double u = i / 9.0, v = 1 - u * u, w = 0.3 + 0.05 * i;
        /* eq. (28): p_x = p0 u sin(xi pi w) cos 2pi v, p_y with sin 2pi v, p_z = 0; fig. 4c. */
        double p0 = 1.8e6, xi = 7;
        assert_rel(pde_force(sol, 0, u, v, w), p0 * u * sin(xi * M_PI * w) * cos(2 * M_PI * v), 1e-13, p0);
        assert_rel(pde_force(sol, 1, u, v, w), p0 * u * sin(xi * M_PI * w) * sin(2 * M_PI * v), 1e-13, p0);
        assert_true(pde_force(sol, 2, u, v, w) == 0.0);
    }
    pde_solution_free(sol);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(eval_should_give_identical_results_from_many_threads),
        cmocka_unit_test(sample_should_match_pointwise_evaluation),
        cmocka_unit_test(grid_should_give_faces_and_derivatives),
        cmocka_unit_test(eval_partial_should_agree_with_differences_and_first_derivatives),
        cmocka_unit_test(force_should_be_the_models_force),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("eval", tests, NULL, NULL);
}
