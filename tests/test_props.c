/*
 * test_props.c: properties of solids, and the accuracy of every paper
 * figure's solution: boundary conditions against the model's own boundary
 * terms, and the PDE by finite differences of the evaluated solution.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "internal.h"   /* to perturb a solution's closed form, which the public API keeps immutable */
#include "model.h"
#include "support.h"
#include "template.h"

static double hermite(const double d[4], double w, int der)
{
    double H[4], D[4];
    H[0] = 2 * w * w * w - 3 * w * w + 1, D[0] = 6 * w * w - 6 * w;
    H[1] = w * w * w - 2 * w * w + w, D[1] = 3 * w * w - 4 * w + 1;
    H[2] = -2 * w * w * w + 3 * w * w, D[2] = -6 * w * w + 6 * w;
    H[3] = w * w * w - w * w, D[3] = 3 * w * w - 2 * w;
    double s = 0;
    for (int i = 0; i < 4; i++)
        s += d[i] * (der ? D[i] : H[i]);
    return s;
}

static pde_solution *figure(size_t i, pde_model *m)
{
    paper_figure_model(i, m);
    pde_solution *sol = NULL;
    pde_diag d;
    if (pde_solve(m, &sol, &d) != PDE_OK)
        fail_msg("%s: %s", paper_figure_name(i), d.message);
    return sol;
}

static void props_should_give_unit_volume_and_exact_bounds_for_the_cuboid(void **state)
{
    (void)state;
    pde_model m;
    pde_solution *sol = figure(0, &m);   /* fig. 1a: x = u - 1/2, y = v - 1/2, z = 3w^2 - 2w^3 */
    pde_props p;
    assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
    assert_rel(p.volume, 1.0, 1e-12, 0);
    assert_rel(p.signed_volume, 1.0, 1e-12, 0);
    /* The box is certified: it holds the cuboid, and lies within its gap (at most 1e-12) of it. */
    const double lo[3] = { -0.5, -0.5, 0 }, hi[3] = { 0.5, 0.5, 1 };
    assert_true(p.bbox_gap >= 0 && p.bbox_gap <= 1e-12);
    for (int c = 0; c < 3; c++) {
        assert_true(p.bbox_min[c] <= lo[c] && p.bbox_min[c] >= lo[c] - p.bbox_gap);
        assert_true(p.bbox_max[c] >= hi[c] && p.bbox_max[c] <= hi[c] + p.bbox_gap);
    }
    /* det J = z'(w) = 6w(1 - w): 0 on the faces w = 0, 1, and 1.5 at w = 1/2. */
    assert_rel(p.detj_min, 0.0, 1e-12, 1);
    assert_rel(p.detj_max, 1.5, 1e-9, 1);
    assert_false(p.folds);
    assert_true(p.bc_residual < 1e-14);
    assert_true(p.pde_residual < 1e-14);
    pde_solution_free(sol);
}

static void props_should_match_the_hand_integrated_volume_of_figure_1(void **state)
{
    (void)state;
    for (size_t f = 1; f < 4; f++) {
        pde_model m;
        pde_solution *sol = figure(f, &m);
        /* x = X0(w) + X1(w) u, y = Y0 + Y1 v, z = Z(w): det J = X1 Y1 Z'. */
        const pde_bterm *xb = &m.comp[0].bterms[1], *yb = &m.comp[1].bterms[1], *zb = &m.comp[2].bterms[0];
        double dx[4] = { xb->w0, xb->dw0, xb->w1, xb->dw1 }, dy[4] = { yb->w0, yb->dw0, yb->w1, yb->dw1 };
        double dz[4] = { zb->w0, zb->dw0, zb->w1, zb->dw1 };
        int n = 200000;
        double vol = 0, svol = 0;
        for (int i = 0; i <= n; i++) {   /* Simpson */
            double w = (double)i / n, wt = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
            double dj = hermite(dx, w, 0) * hermite(dy, w, 0) * hermite(dz, w, 1);
            vol += wt * fabs(dj);
            svol += wt * dj;
        }
        vol /= 3.0 * n;
        svol /= 3.0 * n;
        pde_props p;
        assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
        assert_rel(p.volume, vol, 1e-6, 0);   /* |det J| has kinks, where Simpson is O(h^2) */
        assert_rel(p.signed_volume, svol, 1e-10, 0);
        pde_solution_free(sol);
    }
}

static void props_should_flag_a_solid_that_folds(void **state)
{
    (void)state;
    /* The cuboid, with z'(0) = -6: z goes down before it goes up, so det J = z' changes sign. */
    pde_bterm bx = { F_pow(1), F_pow(0), 1, 0, 1, 0 }, by = { F_pow(0), F_pow(1), 1, 0, 1, 0 };
    pde_bterm bz = { F_pow(0), F_pow(0), 0, -6, 1, 0 };
    pde_model m = { { { 1, 1, -1, &bx, 1, NULL, 0 }, { 1, 1, -1, &by, 1, NULL, 0 }, { 1, 1, -1, &bz, 1, NULL, 0 } } };
    pde_solution *sol = NULL;
    assert_int_equal(pde_solve(&m, &sol, NULL), PDE_OK);
    pde_props p;
    assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
    assert_true(p.folds);
    /* z = -8w^3 + 15w^2 - 6w by hand, z' = -24w^2 + 30w - 6: least at w = 0, where det J = -6,
     * greatest at w = 5/8, 3.375. */
    assert_rel(p.detj_min, -6.0, 1e-9, 1);
    assert_true(p.detj_min_at[2] < 1e-6);
    assert_rel(p.detj_max, 3.375, 1e-9, 1);
    assert_true(p.volume > p.signed_volume);
    pde_props_opts bad = { .res = 1 };
    assert_int_equal(pde_properties(sol, &bad, &p), PDE_ERR_INVALID);
    pde_solution_free(sol);
}

/* Per-axis rate of change of a model, to size the difference steps. */
static double rate(const pde_model *m, const pde_solution *sol, int axis)
{
    double r = 1.0;
    for (int c = 0; c < 3; c++) {
        const pde_component *k = &m->comp[c];
        for (size_t j = 0; j < k->nbterms + k->nfterms; j++) {
            pde_factor f = j < k->nbterms ? (axis ? k->bterms[j].v : k->bterms[j].u)
                                          : (axis ? k->fterms[j - k->nbterms].v : k->fterms[j - k->nbterms].u);
            if (axis == 2 && j >= k->nbterms)
                f = k->fterms[j - k->nbterms].w;
            else if (axis == 2)
                continue;
            r = fmax(r, f.kind == PDE_SIN || f.kind == PDE_COS ? fabs(f.p) * M_PI : fabs(f.p));
        }
        if (axis == 2) {
            size_t nm;
            const pde_mode *md = pde_solution_modes(sol, c, &nm);
            for (size_t i = 0; i < nm; i++)
                r = fmax(r, pow(fabs(md[i].e), 0.25));
        }
    }
    return r;
}

/* d4 x_comp along an axis: Richardson on the 5-point fourth difference. */
static double d4(const pde_solution *sol, int comp, const double p[3], int axis, double h)
{
    double d[2];
    for (int r = 0; r < 2; r++) {
        double hh = r ? 2 * h : h, s = 0;
        static const double st[5] = { 1, -4, 6, -4, 1 };
        for (int i = 0; i < 5; i++) {
            double q[3] = { p[0], p[1], p[2] }, x[3];
            q[axis] += (i - 2) * hh;
            pde_eval(sol, q[0], q[1], q[2], x);
            s += st[i] * x[comp];
        }
        d[r] = s / (hh * hh * hh * hh);
    }
    return (4 * d[0] - d[1]) / 3;
}

static void check_accuracy(const pde_model *m, const pde_solution *sol, const char *name)
{
    /* Boundary conditions, against the model's terms evaluated here. */
    for (int c = 0; c < 3; c++) {
        double err = 0, scale = 0;
        for (int i = 0; i <= 20; i++)
            for (int j = 0; j <= 40; j++) {
                double u = i / 20.0, v = j / 40.0, g[4] = { 0, 0, 0, 0 };
                for (size_t t = 0; t < m->comp[c].nbterms; t++) {
                    const pde_bterm *b = &m->comp[c].bterms[t];
                    double f = tfactor(b->u, u, 0) * tfactor(b->v, v, 0);
                    g[0] += b->w0 * f, g[1] += b->dw0 * f, g[2] += b->w1 * f, g[3] += b->dw1 * f;
                }
                for (int side = 0; side < 2; side++) {
                    double x[3], xw[3];
                    pde_eval_d(sol, u, v, side, x, NULL, NULL, xw);
                    err = fmax(err, fmax(fabs(x[c] - g[2 * side]), fabs(xw[c] - g[2 * side + 1])));
                    scale = fmax(scale, fmax(fabs(g[2 * side]), fabs(g[2 * side + 1])));
                }
            }
        if (err > 1e-12 * fmax(scale, 1e-300))
            fail_msg("%s: component %d boundary residual %.3g relative to %.3g", name, c, err, scale);
    }
    /* The PDE, by differences, inside the cube. */
    double h[3], r4[3];
    for (int a = 0; a < 3; a++) {
        double r = rate(m, sol, a);
        h[a] = 0.01 / r;
        r4[a] = r * r * r * r;
    }
    for (int c = 0; c < 3; c++) {
        const pde_component *k = &m->comp[c];
        /* Differences resolve d4 x only to about eps |x| / h^4: measure against that scale too. */
        double err = 0, scale = 0, size = 0;
        for (int i = 0; i < 27; i++) {
            const double p[3] = { 0.2 + 0.25 * (i % 3), 0.2 + 0.25 * (i / 3 % 3), 0.2 + 0.25 * (i / 9) };
            double tu = k->a * d4(sol, c, p, 0, h[0]), tv = k->b * d4(sol, c, p, 1, h[1]);
            double tw = k->c * d4(sol, c, p, 2, h[2]), f = 0;
            for (size_t t = 0; t < k->nfterms; t++) {
                const pde_fterm *ft = &k->fterms[t];
                f += ft->coef * tfactor(ft->u, p[0], 0) * tfactor(ft->v, p[1], 0) * tfactor(ft->w, p[2], 0);
            }
            double x[3];
            pde_eval(sol, p[0], p[1], p[2], x);
            err = fmax(err, fabs(tu + tv + tw - f));
            scale = fmax(scale, fabs(tu) + fabs(tv) + fabs(tw) + fabs(f));
            size = fmax(size, (fabs(k->a) * r4[0] + fabs(k->b) * r4[1] + fabs(k->c) * r4[2]) * fabs(x[c]));
        }
        scale = fmax(scale, size);
        if (err > 1e-5 * scale)
            fail_msg("%s: component %d PDE residual %.3g relative to %.3g", name, c, err, scale);
    }
    /* And the solution's own certificate agrees. */
    pde_props p;
    assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
    if (!(p.bc_residual <= 1e-12 && p.pde_residual <= 1e-10))
        fail_msg("%s: certificate bc %.3g pde %.3g", name, p.bc_residual, p.pde_residual);
}

static void every_paper_figure_should_meet_its_boundary_conditions_and_the_pde(void **state)
{
    (void)state;
    for (size_t i = 0; i < paper_figure_count(); i++) {
        pde_model m;
        pde_solution *sol = figure(i, &m);
        check_accuracy(&m, sol, paper_figure_name(i));
        pde_solution_free(sol);
    }
}

static void stiff_models_should_meet_their_boundary_conditions_and_the_pde(void **state)
{
    (void)state;
    const double k[3] = { 100, 200, 300 };
    for (int i = 0; i < 3; i++) {
        pde_bterm bt[2] = { { F_pow(1), F_sin(k[i]), 0.5, 1, 0.25, -1 }, { F_pow(0), F_pow(0), 1, 0, 2, 0 } };
        pde_fterm ft = { 1e6, F_pow(1), F_cos(k[i]), F_sin(3) };
        for (int sign = -1; sign <= 1; sign += 2) {
            pde_model m = { { { 1, 1, sign, bt, 2, &ft, 1 }, { 1, 1, -1, &bt[1], 1, NULL, 0 },
                              { 1, 1, -1, &bt[1], 1, NULL, 0 } } };
            pde_solution *sol = NULL;
            assert_int_equal(pde_solve(&m, &sol, NULL), PDE_OK);
            check_accuracy(&m, sol, "stiff");
            pde_solution_free(sol);
        }
    }
}

static void force_and_partials_should_not_swap_sinh_and_cosh(void **state)
{
    (void)state;
    /* The certificate's false alarms on sinh and cosh came from these: checked against tfactor(). */
    pde_bterm bx = { F_sinh(1.5), F_cosh(0.7), 1, 0.5, 2, -1 };
    pde_bterm by = { F_pow(0), F_pow(1), 1, 0, 1, 0 }, bz = { F_pow(0), F_pow(0), 0, 1, 1, 1 };
    pde_fterm fz = { 3, F_cosh(2), F_sinh(-1), F_cosh(1.2) };
    pde_model m = { { { 1, 1, -1, &bx, 1, NULL, 0 }, { 1, 1, -1, &by, 1, NULL, 0 }, { 1, 1, -1, &bz, 1, &fz, 1 } } };
    pde_solution *sol = NULL;
    assert_int_equal(pde_solve(&m, &sol, NULL), PDE_OK);
    const double u = 0.3, v = 0.8, w = 0.6;
    assert_rel(pde_force(sol, 2, u, v, w), 3 * cosh(2 * u) * sinh(-v) * cosh(1.2 * w), 1e-14, 0);
    /* x = h(w) sinh(1.5 u) cosh(0.7 v): its u- and v-derivatives are those of the factors. */
    double x = pde_eval_partial(sol, 0, u, v, w, 0, 0, 0);
    for (int n = 1; n <= 4; n++) {
        assert_rel(pde_eval_partial(sol, 0, u, v, w, n, 0, 0), x * tfactor(bx.u, u, n) / tfactor(bx.u, u, 0), 1e-13, 0);
        assert_rel(pde_eval_partial(sol, 0, u, v, w, 0, n, 0), x * tfactor(bx.v, v, n) / tfactor(bx.v, v, 0), 1e-13, 0);
    }
    pde_solution_free(sol);
}

/* The certificate: the larger of the two residuals. */
static double certificate(const pde_solution *sol)
{
    pde_props p;
    assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
    return fmax(p.bc_residual, p.pde_residual);
}

static void certificate_should_be_near_rounding_on_every_preset(void **state)
{
    (void)state;
    for (size_t i = 0; i < api_preset_count(); i++) {
        const api_preset *ps = api_preset_at(i);
        api_params par;
        api_error err;
        api_preset_params(ps, &par);
        api_model *am = api_template_expand(api_preset_template(ps), &par, &err);
        assert_non_null(am);
        pde_solution *sol = NULL;
        assert_int_equal(pde_solve(api_model_get(am), &sol, NULL), PDE_OK);
        pde_props p;
        assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
        if (!(p.bc_residual < 1e-11 && p.pde_residual < 1e-11))
            fail_msg("%s: certificate bc %.3g pde %.3g", ps->name, p.bc_residual, p.pde_residual);
        pde_solution_free(sol);
        api_model_free(am);
    }
}

/* One factor of every kind, with parameters away from the clamped eigenvalues (e < 500 or between). */
static const pde_factor every_kind[] = {
    { PDE_POW, 6 }, { PDE_SIN, 1.2 }, { PDE_COS, 2 }, { PDE_EXP, -1.3 }, { PDE_SINH, 2 }, { PDE_COSH, 1.7 },
};
#define NKINDS (sizeof every_kind / sizeof every_kind[0])

/*
 * x = u, y = v and z a cubic in w, plus one term with the factor f: place 0, 1 a boundary term of x
 * with f in u or v; 2, 3, 4 a force on x with f in u, v or w; 5 a force with f in w on z, which then
 * has no boundary term at all. Solved with c = -1 (e > 0) or c = +1 (e < 0).
 */
static pde_solution *kind_model(pde_factor f, int place, double c)
{
    static pde_bterm bx[2], by, bz;
    static pde_fterm fx, fz;
    bx[0] = (pde_bterm){ F_pow(1), F_pow(0), 1, 0, 1.5, 0.5 };
    bx[1] = (pde_bterm){ place == 0 ? f : F_cos(1), place == 1 ? f : F_pow(2), 0.3, -0.2, 0.7, 0.4 };
    by = (pde_bterm){ F_pow(0), F_pow(1), 1, 0.2, 1, -0.1 };
    bz = (pde_bterm){ F_pow(0), F_pow(0), 0, 1, 1, 1 };
    fx = (pde_fterm){ 2.5, place == 2 ? f : F_pow(1), place == 3 ? f : F_sin(1), place == 4 ? f : F_cos(0.5) };
    fz = (pde_fterm){ -4, F_sin(1), F_pow(1), f };
    pde_model m = { { { 1, 0.5, c, bx, place < 2 ? 2 : 1, &fx, place >= 2 && place <= 4 },
                      { 1, 1, c, &by, 1, NULL, 0 },
                      { 0.7, 1, c, place == 5 ? NULL : &bz, place == 5 ? 0 : 1, &fz, place == 5 } } };
    pde_solution *sol = NULL;
    pde_diag d;
    if (pde_solve(&m, &sol, &d) != PDE_OK)
        fail_msg("%s(%g), place %d, c %g: %s", factor_name(f.kind), f.p, place, c, d.message);
    return sol;
}

static void certificate_should_be_near_rounding_for_every_factor_kind_in_u_v_and_w(void **state)
{
    (void)state;
    static const char *const where[] = { "boundary u", "boundary v", "force u", "force v", "force w",
                                         "forced-only w" };
    for (size_t k = 0; k < NKINDS; k++)
        for (int place = 0; place < 6; place++)
            for (int c = -1; c <= 1; c += 2) {
                pde_solution *sol = kind_model(every_kind[k], place, c);
                pde_props p;
                assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
                if (!(p.bc_residual < 1e-11 && p.pde_residual < 1e-11))
                    fail_msg("%s(%g) in %s, c = %d: certificate bc %.3g pde %.3g", factor_name(every_kind[k].kind),
                             every_kind[k].p, where[place], c, p.bc_residual, p.pde_residual);
                pde_solution_free(sol);
            }
}

/* Multiplies the largest coefficient of component c's closed form by 1 + rel; returns it, to restore. */
static double *perturb_largest(pde_solution *sol, int c, double rel, double *old)
{
    double *at = NULL;
    comp_solution *cs = &sol->comp[c];
    for (size_t m = 0; m < cs->nmodes; m++)
        for (size_t k = 0; k < cs->modes[m].nterms; k++) {
            const pde_wterm *t = &cs->modes[m].terms[k];
            for (int j = 0; j <= t->deg; j++) {
                const double *q[2] = { &t->A[j], &t->B[j] };
                for (int i = 0; i < 2; i++)
                    if (!at || fabs(*q[i]) > fabs(*at))
                        at = (double *)q[i];
            }
        }
    assert_non_null(at);
    *old = *at;
    *at *= 1.0 + rel;
    return at;
}

static void certificate_should_catch_a_closed_form_coefficient_perturbed_by_1e_6(void **state)
{
    (void)state;
    /* fig. 4a, then every factor kind, in each of the places above, on each component that has terms. */
    pde_model fm;
    pde_solution *sols[1 + NKINDS * 6];
    size_t n = 0;
    sols[n++] = figure(11, &fm);
    assert_string_equal(paper_figure_name(11), "fig4a");
    for (size_t k = 0; k < NKINDS; k++)
        for (int place = 0; place < 6; place++)
            sols[n++] = kind_model(every_kind[k], place, -1);
    double least = INFINITY;
    for (size_t i = 0; i < n; i++) {
        assert_true(certificate(sols[i]) < 1e-11);
        for (int c = 0; c < 3; c++) {
            if (sols[i]->comp[c].nmodes == 0)
                continue;
            double old, *at = perturb_largest(sols[i], c, 1e-6, &old);
            double cert = certificate(sols[i]);
            if (!(cert > 1e-8))
                fail_msg("model %zu, component %d: certificate %.3g after a 1e-6 perturbation", i, c, cert);
            least = fmin(least, cert);
            *at = old;
        }
        pde_solution_free(sols[i]);
    }
    print_message("least certificate after a perturbation: %.3g\n", least);
}

/* The first root of cos t cosh t = 1, by Newton from 4.73. */
static double first_clamped_root(void)
{
    double t = 4.73;
    for (int i = 0; i < 8; i++)
        t -= (cos(t) * cosh(t) - 1) / (cos(t) * sinh(t) - sin(t) * cosh(t));
    return t;
}

static void certificate_should_grow_like_one_over_the_distance_to_a_clamped_eigenvalue(void **state)
{
    (void)state;
    /* x = h(w) sin(pi u) with e = a pi^4 = t1^4 (1 + delta): the boundary fit's condition grows like 1/delta,
     * and double precision keeps about 4e-16/delta of h's digits. Driven by boundary data, then by a force
     * alone (x then has no boundary term, and h grows like 1/delta all the same). */
    double t1 = first_clamped_root(), e1 = t1 * t1 * t1 * t1;
    assert_rel(e1, 500.5639017, 1e-9, 0);
    const double deltas[] = { 1e-6, 1e-7, 1e-8, 1e-9 };
    for (int forced = 0; forced < 2; forced++) {
        double cert[4];
        for (int i = 0; i < 4; i++) {
            double a = e1 * (1 + deltas[i]) / pow(M_PI, 4);
            pde_bterm bx = { F_sin(1), F_pow(0), 1, 0.5, -0.25, 2 }, by = { F_pow(0), F_pow(1), 1, 0, 1, 0 };
            pde_bterm bz = { F_pow(0), F_pow(0), 0, 1, 1, 1 };
            pde_fterm fx = { 30, F_sin(1), F_pow(0), F_pow(0) };
            pde_model m = { { { a, 0, -1, forced ? NULL : &bx, !forced, forced ? &fx : NULL, forced },
                              { 1, 1, -1, &by, 1, NULL, 0 }, { 1, 1, -1, &bz, 1, NULL, 0 } } };
            pde_solution *sol = NULL;
            assert_int_equal(pde_solve(&m, &sol, NULL), PDE_OK);
            cert[i] = certificate(sol);
            pde_solution_free(sol);
            /* The loss shows: at least a fortieth of it, and no more than a hundred times it. */
            if (!(cert[i] > 1e-17 / deltas[i] && cert[i] < 4e-14 / deltas[i]))
                fail_msg("%s, delta %g: certificate %.3g, expected about %.3g", forced ? "forced" : "data",
                         deltas[i], cert[i], 4e-16 / deltas[i]);
        }
        /* 1000 times closer: the certificate grows by about 1000. */
        if (!(cert[3] > 100 * cert[0]))
            fail_msg("%s: certificate %.3g at delta 1e-6, %.3g at 1e-9", forced ? "forced" : "data", cert[0], cert[3]);
    }
}

/* q(w) = w^n, for the independent solver. */
static void q_power(double w, double *out, void *ctx)
{
    out[0] = pow(w, *(const int *)ctx);
}

static void certificate_should_show_the_digits_lost_when_a_large_particular_solution_cancels(void **state)
{
    (void)state;
    /* x = h(w) sin(pi u / 2) forced by w^n alone, e = (pi/2)^4: the particular solution grows like
     * n!/e^(n/4) while h stays small, and the fit cancels the difference. Against the independent
     * solver, the certificate is within a factor 1000 of the real error, above and below. */
    const int ns[] = { 4, 8, 12, 16 };
    for (int i = 0; i < 4; i++) {
        pde_fterm fx = { 1, F_sin(0.5), F_pow(0), F_pow(ns[i]) };
        pde_bterm by = { F_pow(0), F_pow(1), 1, 0, 1, 0 }, bz = { F_pow(0), F_pow(0), 0, 1, 1, 1 };
        pde_model m = { { { 1, 1, -1, NULL, 0, &fx, 1 }, { 1, 1, -1, &by, 1, NULL, 0 },
                          { 1, 1, -1, &bz, 1, NULL, 0 } } };
        pde_solution *sol = NULL;
        assert_int_equal(pde_solve(&m, &sol, NULL), PDE_OK);
        double mu = pow(0.5 * M_PI, 4), bc[4] = { 0, 0, 0, 0 };
        indep_problem p = { 1, -1, &mu, NULL, bc, q_power, (void *)&ns[i], 2 };
        indep_solution *ind = indep_solve(&p);
        assert_non_null(ind);
        double err = 0, size = 0;
        for (int k = 0; k <= 50; k++) {
            double w = k / 50.0, x[3], h = indep_eval(ind, 0, 0, w);
            pde_eval(sol, 1, 0.5, w, x);   /* sin(pi / 2) = 1 */
            err = fmax(err, fabs(x[0] - h));
            size = fmax(size, fabs(h));
        }
        indep_free(ind);
        double real = err / size, cert = certificate(sol);
        print_message("w^%d: real error %.3g, certificate %.3g\n", ns[i], real, cert);
        if (!(cert > real / 1000 && cert < 1000 * fmax(real, 1e-13)))
            fail_msg("w^%d: certificate %.3g for a real error of %.3g", ns[i], cert, real);
        pde_solution_free(sol);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(props_should_give_unit_volume_and_exact_bounds_for_the_cuboid),
        cmocka_unit_test(props_should_match_the_hand_integrated_volume_of_figure_1),
        cmocka_unit_test(props_should_flag_a_solid_that_folds),
        cmocka_unit_test(every_paper_figure_should_meet_its_boundary_conditions_and_the_pde),
        cmocka_unit_test(stiff_models_should_meet_their_boundary_conditions_and_the_pde),
        cmocka_unit_test(force_and_partials_should_not_swap_sinh_and_cosh),
        cmocka_unit_test(certificate_should_be_near_rounding_on_every_preset),
        cmocka_unit_test(certificate_should_be_near_rounding_for_every_factor_kind_in_u_v_and_w),
        cmocka_unit_test(certificate_should_catch_a_closed_form_coefficient_perturbed_by_1e_6),
        cmocka_unit_test(certificate_should_grow_like_one_over_the_distance_to_a_clamped_eigenvalue),
        cmocka_unit_test(certificate_should_show_the_digits_lost_when_a_large_particular_solution_cancels),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("props", tests, NULL, NULL);
}
