/*
 * test_eval.c: evaluation and sampling. Points, derivatives of any order,
 * grids and faces against pointwise evaluation, and evaluation from many
 * threads at once.
 */
#include <complex.h>
#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "internal.h"   /* the factor and w-term evaluations the properties use */
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

/* Faces u = 0, 1 as one narrow grid (nu = 2, column-wise, the three components at once when each has one
 * u-factor) give the bits of the same columns of a wide grid (row by row), for any rows asked. */
static void narrow_grid_should_match_a_wide_grids_columns(void **state)
{
    (void)state;
    const char *figs[] = { "fig4a", "fig1e", "fig2a", "fig4d" };
    enum { NV = 23 };
    double vs[NV], ends[2] = { 0.0, 1.0 }, wide[3] = { 0.0, 1.0, 0.5 };
    for (int j = 0; j < NV; j++)
        vs[j] = j / (double)(NV - 1);
    int ones = 0, more = 0;   /* both of grid_cols' paths taken */
    for (size_t f = 0; f < sizeof figs / sizeof *figs; f++) {
        pde_solution *sol = solve_figure(figs[f]);
        pde_grid *gn, *gw;
        assert_int_equal(pde_grid_create(sol, ends, 2, vs, NV, &gn), PDE_OK);
        assert_int_equal(pde_grid_create(sol, wide, 3, vs, NV, &gw), PDE_OK);
        if (gn->nd[0] == 1 && gn->nd[1] == 1 && gn->nd[2] == 1)
            ones++;
        else
            more++;
        float n[4][6 * NV], wv[4][9 * NV], only[6 * NV];
        for (int k = 0; k <= 3; k++) {
            const double w = k / 3.0;
            pde_grid_plane_d(gw, w, wv[0], wv[1], wv[2], wv[3]);
            pde_grid_plane_d(gn, w, n[0], n[1], n[2], n[3]);
            pde_grid_rows(gn, w, 5, 12, only, NULL, NULL, NULL);   /* positions alone, from row 5, an odd count */
            assert_memory_equal(only, n[0] + 6 * 5, 6 * 7 * sizeof(float));
            pde_grid_rows(gn, w, 2, 9, NULL, only, NULL, NULL);
            assert_memory_equal(only, n[1] + 6 * 2, 6 * 7 * sizeof(float));
            for (int q = 0; q < 4; q++)
                for (int j = 0; j < NV; j++)
                    assert_memory_equal(n[q] + 6 * j, wv[q] + 9 * j, 6 * sizeof(float));
        }
        pde_grid_free(gn);
        pde_grid_free(gw);
        pde_solution_free(sol);
    }
    assert_true(ones > 0 && more > 0);
}

/*
 * A wide grid of many modes (BLK_MODES or more in a component) takes its rows' coefficients a block of rows
 * at a time (eval.c's grid_blocks): its planes, with and without derivatives, and any run of rows (across a
 * block's end, positions alone or one derivative alone) against pointwise evaluation and the plane's own rows.
 */
static void a_wide_grid_of_many_modes_should_match_pointwise_evaluation(void **state)
{
    (void)state;
    enum { NM = 80, NU = 5, NV = 70, NW = 4 };
    static pde_bterm b[3][NM + 1];
    for (int c = 0; c < 3; c++) {
        b[c][0] = (pde_bterm){ c == 0 ? F_pow(1) : F_pow(0), c == 1 ? F_pow(1) : F_pow(0), c == 2 ? 0 : 1, c == 2,
                               1, c == 2 };
        for (int k = 1; k <= NM; k++)   /* x and y: u cos / sin of 2 k pi v; z: u^2 cos */
            b[c][k] = (pde_bterm){ F_pow(c == 2 ? 2 : 1), c == 1 ? F_sin(2 * k) : F_cos(2 * k), 0.3 / k, 0.1 / k,
                                   0.2 / k, -0.05 / k };
    }
    pde_model m = { { { 1, 1, 1, b[0], NM + 1, NULL, 0 }, { 1, 1, 1, b[1], NM + 1, NULL, 0 },
                      { 1, 1, 1, b[2], NM + 1, NULL, 0 } } };
    pde_solution *sol;
    assert_int_equal(pde_solve(&m, &sol, NULL), PDE_OK);
    double us[NU], vs[NV];
    for (int i = 0; i < NU; i++)
        us[i] = i / (NU - 1.0);
    for (int j = 0; j < NV; j++)
        vs[j] = j / (NV - 1.0);
    pde_grid *g;
    assert_int_equal(pde_grid_create(sol, us, NU, vs, NV, &g), PDE_OK);
    assert_non_null(g->blk);   /* the path under test */
    static float q[4][3 * NU * NV], only[3 * NU * NV];
    for (int k = 0; k < NW; k++) {
        const double w = k / (NW - 1.0);
        pde_grid_plane_d(g, w, q[0], q[1], q[2], q[3]);
        for (int j = 0; j < NV; j++)
            for (int i = 0; i < NU; i++) {
                double x[3], d[3][3];
                pde_eval_d(sol, us[i], vs[j], w, x, d[0], d[1], d[2]);
                for (int c = 0; c < 3; c++) {
                    const int at = 3 * (j * NU + i) + c;
                    assert_rel(q[0][at], x[c], 1e-6, 1.0);
                    for (int a = 0; a < 3; a++)
                        assert_rel(q[1 + a][at], d[a][c], 1e-6, 1.0);
                }
            }
        pde_grid_rows(g, w, 60, NV, only, NULL, NULL, NULL);   /* across the first block's end, positions alone */
        assert_memory_equal(only, q[0] + 3 * NU * 60, 3 * NU * (NV - 60) * sizeof(float));
        pde_grid_rows(g, w, 3, 67, NULL, NULL, only, NULL);    /* x_v alone, a block and a part */
        assert_memory_equal(only, q[2] + 3 * NU * 3, 3 * NU * 64 * sizeof(float));
    }
    pde_grid_free(g);
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

/* det J against the determinant of x's central differences (Richardson, as fd above) on figures that fold and
 * that don't; and a solid whose z is cleared is flat, while every figure is not. */
static void detj_should_be_the_determinant_of_differences_and_flat_solids_found(void **state)
{
    (void)state;
    const char *figs[3] = { "fig4a", "fig3c", "fig1c" };
    const double pts[3][3] = { { 0.4, 0.3, 0.55 }, { 0.91, 0.07, 0.33 }, { 0.15, 0.62, 0.8 } };
    for (int f = 0; f < 3; f++) {
        pde_solution *sol = solve_figure(figs[f]);
        for (int k = 0; k < 3; k++) {
            double d[3][3], scale = 1.0;
            for (int axis = 0; axis < 3; axis++)
                for (int c = 0; c < 3; c++) {
                    d[axis][c] = fd(sol, c, pts[k], axis, 1, 1e-3);
                    scale = fmax(scale, fabs(d[axis][c]));
                }
            const double j = d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1])
                             - d[1][0] * (d[0][1] * d[2][2] - d[0][2] * d[2][1])
                             + d[2][0] * (d[0][1] * d[1][2] - d[0][2] * d[1][1]);
            assert_rel(pde_eval_detj(sol, pts[k][0], pts[k][1], pts[k][2]), j, 1e-6, scale * scale * scale);
        }
        assert_false(pde_solution_is_flat(sol));
        pde_solution_free(sol);
    }
    for (size_t i = 0; i < paper_figure_count(); i++) {
        pde_model m;
        paper_figure_model(i, &m);
        pde_solution *sol = NULL;
        assert_int_equal(pde_solve(&m, &sol, NULL), PDE_OK);
        assert_false(pde_solution_is_flat(sol));
        pde_solution_free(sol);
        /* One coordinate 1e7 times and one 1e-7 times the rest, or 1e150 times: still a solid (the old test took
         * the cube of the largest partial as det J's scale, and refused a solid 1e7 wide as flat). */
        const double scales[3][3] = { { 1e7, 1, 1e-7 }, { 1, 1e150, 1 }, { 1e-150, 1, 1 } };
        for (int k = 0; k < 3; k++) {
            pde_bterm b[3][64];
            pde_fterm f[3][64];
            pde_model ms = m;
            for (int c = 0; c < 3; c++) {
                assert_true(m.comp[c].nbterms <= 64 && m.comp[c].nfterms <= 64);
                for (size_t t = 0; t < m.comp[c].nbterms; t++) {
                    b[c][t] = m.comp[c].bterms[t];
                    b[c][t].w0 *= scales[k][c], b[c][t].dw0 *= scales[k][c];
                    b[c][t].w1 *= scales[k][c], b[c][t].dw1 *= scales[k][c];
                }
                for (size_t t = 0; t < m.comp[c].nfterms; t++) {
                    f[c][t] = m.comp[c].fterms[t];
                    f[c][t].coef *= scales[k][c];
                }
                ms.comp[c].bterms = b[c];
                ms.comp[c].fterms = f[c];
            }
            assert_int_equal(pde_solve(&ms, &sol, NULL), PDE_OK);
            assert_false(pde_solution_is_flat(sol));
            pde_solution_free(sol);
        }
        m.comp[2].nbterms = m.comp[2].nfterms = 0;   /* z = 0: a surface */
        assert_int_equal(pde_solve(&m, &sol, NULL), PDE_OK);
        assert_true(pde_solution_is_flat(sol));
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

/* w-terms of every kind mode_h_derivs and terms_bounds treat apart: polynomial, real exponential,
 * pure rotation and both, of degrees 0 .. 3, one slab. */
static const double T_A[4][4] = { { 0.5, -1.25, 3.0, -2.0 }, { 1.5, 0.25, -0.75, 0 }, { -0.8, 0.3, 0, 0 },
                                  { 0.7, -0.4, 0.9, 0 } };
static const double T_B[4][4] = { { 0, 0, 0, 0 }, { 0, 0, 0, 0 }, { 0.6, -1.1, 0, 0 }, { 0, 0.35, -0.2, 0 } };
static const pde_wterm T_TERMS[4] = {
    { 0.0, 0.0, 0.0, 3, T_A[0], T_B[0] },    /* polynomial */
    { -2.5, 0.0, 0.0, 2, T_A[1], T_B[1] },   /* real exponential */
    { 0.0, 7.0, 0.0, 1, T_A[2], T_B[2] },    /* rotation */
    { 3.0, 4.5, 1.0, 2, T_A[3], T_B[3] },    /* both */
};

/* d^n/dw^n of a term from its definition Re[(A - iB)(w) e^{alpha (w - shift)} e^{i beta w}]: the
 * Leibniz sum in complex arithmetic, each piece's derivatives taken apart. */
static double term_deriv_ref(const pde_wterm *t, double w, int n)
{
    double complex z = t->alpha + I * t->beta, sum = 0.0;
    for (int j = 0; j <= n; j++) {
        double complex pj = 0.0;   /* (A - iB)^(j)(w) */
        for (int k = t->deg; k >= j; k--) {
            double f = 1.0;
            for (int i = 0; i < j; i++)
                f *= k - i;
            pj = pj * w + f * (t->A[k] - I * t->B[k]);
        }
        double binom = 1.0;
        double complex zp = 1.0;   /* z^(n - j); cpow(0, 0) is not 1 */
        for (int i = 0; i < j; i++)
            binom = binom * (n - i) / (i + 1);
        for (int i = j; i < n; i++)
            zp *= z;
        sum += binom * zp * pj;
    }
    return creal(sum * cexp(t->alpha * (w - t->shift) + I * t->beta * w));
}

static void factor_paths_should_match_a_general_complex_evaluation(void **state)
{
    (void)state;
    const size_t first[2] = { 0, 1 };
    const double breaks[2] = { 0.0, 1.0 };
    for (int i = 0; i < 4; i++) {
        const pde_mode m = { F_pow(0), F_pow(0), 0.0, 1, &T_TERMS[i], 1, breaks, first };
        for (int p = 0; p <= 8; p++) {
            const double w = p / 8.0;
            double d[5], h, dh;
            mode_h_derivs(&m, w, 4, d);
            mode_h(&m, w, &h, &dh);
            for (int n = 0; n <= 4; n++) {
                const double ref = term_deriv_ref(&T_TERMS[i], w, n), scale = pow(10.0, n);
                assert_rel(d[n], ref, 1e-13, scale);
                assert_rel(wterm_deriv(&T_TERMS[i], w, n), ref, 1e-13, scale);
            }
            assert_rel(h, d[0], 1e-14, 1.0);
            assert_rel(dh, d[1], 1e-14, 10.0);
            /* the bounds over [w - 1/16, w + 1/16] hold at its ends and centre */
            double b[5];
            mode_h_bounds(&m, w - 0.0625, w + 0.0625, 4, b);
            for (int q = -1; q <= 1; q++) {
                mode_h_derivs(&m, w + q * 0.0625, 4, d);
                for (int n = 0; n <= 4; n++)
                    assert_true(fabs(d[n]) <= b[n]);
            }
        }
    }
}

static void sin_and_cos_bounds_should_hold_over_any_interval(void **state)
{
    (void)state;
    const pde_factor fs[4] = { F_sin(1.0), F_cos(1.0), F_sin(3.5), F_cos(0.25) };
    for (int f = 0; f < 4; f++)
        for (int i = 0; i < 40; i++) {
            /* intervals with and without a peak of |sin| or |cos|, short and long */
            const double t0 = -0.3 + 0.037 * i, t1 = t0 + 0.011 * (1 + i % 7) * (1 + i % 3);
            double b[5], d[5];
            factor_bounds(fs[f], t0, t1, 4, b);
            double top[5] = { 0 };
            for (int q = 0; q <= 200; q++) {
                factor_derivs(fs[f], t0 + (t1 - t0) * q / 200.0, 4, d);
                for (int k = 0; k <= 4; k++) {
                    assert_true(fabs(d[k]) <= b[k] * (1 + 1e-15));
                    top[k] = fmax(top[k], fabs(d[k]));
                }
            }
            for (int k = 0; k <= 4; k++)   /* and are the maxima, to the sampling's resolution */
                assert_rel(b[k], top[k], 1e-3, 0.0);
        }
}

static void solution_factors_should_be_factor_eval_and_mode_h(void **state)
{
    (void)state;
    for (size_t f = 0; f < paper_figure_count(); f++) {
        pde_solution *sol = solve_figure(paper_figure_name(f));
        size_t mt = 0;
        for (int c = 0; c < 3; c++)
            mt += sol->comp[c].nmodes;
        double *val = malloc(2 * (mt ? mt : 1) * sizeof *val), *der = val + (mt ? mt : 1);
        assert_non_null(val);
        for (int axis = 0; axis < 3; axis++)
            for (int p = 0; p <= 6; p++) {
                const double t = p / 6.0 - 0.05;
                solution_factors(sol, axis, t, val, der);
                size_t o = 0;
                for (int c = 0; c < 3; c++)
                    for (size_t m = 0; m < sol->comp[c].nmodes; m++, o++) {
                        const pde_mode *md = &sol->comp[c].modes[m];
                        double v, d;
                        if (axis == 2)
                            mode_h(md, t, &v, &d);
                        else
                            factor_eval(axis ? md->v : md->u, t, &v, &d);
                        assert_true(v == val[o] && d == der[o]);   /* the same roundings */
                    }
            }
        free(val);
        pde_solution_free(sol);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(eval_should_give_identical_results_from_many_threads),
        cmocka_unit_test(sample_should_match_pointwise_evaluation),
        cmocka_unit_test(grid_should_give_faces_and_derivatives),
        cmocka_unit_test(narrow_grid_should_match_a_wide_grids_columns),
        cmocka_unit_test(a_wide_grid_of_many_modes_should_match_pointwise_evaluation),
        cmocka_unit_test(eval_partial_should_agree_with_differences_and_first_derivatives),
        cmocka_unit_test(detj_should_be_the_determinant_of_differences_and_flat_solids_found),
        cmocka_unit_test(force_should_be_the_models_force),
        cmocka_unit_test(factor_paths_should_match_a_general_complex_evaluation),
        cmocka_unit_test(sin_and_cos_bounds_should_hold_over_any_interval),
        cmocka_unit_test(solution_factors_should_be_factor_eval_and_mode_h),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("eval", tests, NULL, NULL);
}
