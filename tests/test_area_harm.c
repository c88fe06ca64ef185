/*
 * test_area_harm.c: core/harm.c's mean over theta of a section of one harmonic whose element's square
 * has no odd harmonics (fig. 2 and 4: x_t x x_w = v0 + v1 cos theta + v2 sin theta + v3 cos 2 theta +
 * v4 sin 2 theta with v0, v3, v4 normal to v1, v2), which it takes from the roots of a quartic
 * (even_mean) where the trapezoidal rule converges slowly: harm_mean to 1e-12 against the element
 * written here, integrated by 10-point Gauss-Legendre panels halved where they differ from their
 * halves (to 1e-15 of the element's largest), and where the dips are shallow also by a trapezoidal sum
 * of 2^18 points (geometric; checked against 2^17 to 1e-13), which the adaptive rule must match to 1e-13. Sections of three kinds: fig. 4's (v0, v3, v4 along z, v1 and v2 in the
 * plane x, y: two dips a period where z's part changes sign, as deep as v1, v2 are small), v1 = v2 = 0
 * (one dip, where the curve v0 + v3 cos + v4 sin passes near 0), and v0, v3, v4 in the plane x, z with
 * v1, v2 along y; and a shallow one, which the trapezoidal rule takes.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <cmocka.h>

#include "harm.h"
#include "support.h"

static double element(const double v[5][3], double th)
{
    const double c1 = cos(th), s1 = sin(th), c2 = cos(2 * th), s2 = sin(2 * th);
    double s = 0.0;
    for (int k = 0; k < 3; k++) {
        const double c = v[0][k] + v[1][k] * c1 + v[2][k] * s1 + v[3][k] * c2 + v[4][k] * s2;
        s += c * c;
    }
    return sqrt(s);
}

/* The mean over a period by the trapezoidal rule on 2^lg points, checked against 2^(lg - 1) */
static double dense_mean(const double v[5][3], int lg)
{
    const long n = 1L << lg;
    double even = 0.0, odd = 0.0;
    for (long i = 0; i < n; i += 2) {
        even += element(v, 2 * M_PI * i / n);
        odd += element(v, 2 * M_PI * (i + 1) / n);
    }
    const double coarse = even / (n / 2), fine = (even + odd) / n;
    if (!(fabs(fine - coarse) <= 1e-13 * fine))
        fail_msg("the reference did not converge: %.17g on 2^%d points, %.17g on half", fine, lg, coarse);
    return fine;
}

typedef struct {
    const double (*v)[3];
    double x[10], wt[10], tol;
} gl_line;

static double gl_rule(const gl_line *l, double a, double b)
{
    double sum = 0.0;
    for (int i = 0; i < 10; i++)
        sum += l->wt[i] * element(l->v, a + (b - a) * l->x[i]);
    return (b - a) * sum;
}

static double gl_adapt(const gl_line *l, double a, double b, double whole, int depth)
{
    const double m = 0.5 * (a + b), left = gl_rule(l, a, m), right = gl_rule(l, m, b);
    if (fabs(left + right - whole) <= l->tol * (b - a) || depth >= 50)
        return left + right;
    return gl_adapt(l, a, m, left, depth + 1) + gl_adapt(l, m, b, right, depth + 1);
}

/* The mean over a period by 10-point Gauss-Legendre panels halved where they differ from their halves
 * by more than 1e-15 of the element's largest per unit of theta (a narrow dip's kink resolved by halving) */
static double adaptive_mean(const double v[5][3])
{
    gl_line l = { .v = v };
    ref_gauss_legendre(10, l.x, l.wt);
    double big = 0.0, sum = 0.0;
    for (int i = 0; i < 256; i++)
        big = fmax(big, element(v, 2 * M_PI * i / 256));
    l.tol = 1e-15 * big;
    for (int p = 0; p < 64; p++) {
        const double a = 2 * M_PI * p / 64, b = 2 * M_PI * (p + 1) / 64;
        sum += gl_adapt(&l, a, b, gl_rule(&l, a, b), 0);
    }
    return sum / (2 * M_PI);
}

/* The reference: the adaptive rule's mean, and where the dip is not too narrow for it (shallow), the
 * trapezoidal sum's, which must agree */
static double ref_mean(const double v[5][3], int shallow)
{
    const double a = adaptive_mean(v);
    if (shallow) {
        const double d = dense_mean(v, 18);
        if (!(fabs(a - d) <= 1e-13 * d))
            fail_msg("the references differ: adaptive %.17g, trapezoidal %.17g", a, d);
    }
    return a;
}

/* The first kind's sections: v0, v3, v4 = (0, 0, s0), (0, 0, s3), (0, 0, s4), v1, v2 = d (a, 0, 0), d (b, c, 0) */
static void fig4_kind(double s0, double s3, double s4, double a, double b, double c, double d, double v[5][3])
{
    const double w[5][3] = { { 0, 0, s0 }, { d * a, 0, 0 }, { d * b, d * c, 0 }, { 0, 0, s3 }, { 0, 0, s4 } };
    for (int i = 0; i < 5; i++)
        for (int k = 0; k < 3; k++)
            v[i][k] = w[i][k];
}

static void harm_mean_should_match_a_dense_sum_on_even_sections_with_deep_dips(void **state)
{
    (void)state;
    double x[10], wt[10];
    ref_gauss_legendre(10, x, wt);
    double worst = 0.0;
    int cases = 0;
    /* fig. 4's kind: z's part s0 + s3 cos + s4 sin changes sign (|s0| below its amplitude), so the
     * element dips to about d |v1 cos + v2 sin| twice a period; d from 1 (shallow) to 1e-5 */
    static const double ds[] = { 1.0, 0.1, 1e-2, 1e-3, 1e-4, 1e-5 };
    static const double sh[][3] = { { 34.3, 34.33, 4.08 }, { 1.0, -0.3, 1.4 }, { -0.2, 2.0, -0.5 }, { 0.9, 0.1, 1.0 } };
    for (size_t i = 0; i < sizeof sh / sizeof *sh; i++)
        for (size_t j = 0; j < sizeof ds / sizeof *ds; j++) {
            double v[5][3];
            fig4_kind(sh[i][0], sh[i][1], sh[i][2], 6.5 * (1 + i), 0.8, -0.77 + 0.3 * i, ds[j], v);
            const double ref = ref_mean(v, ds[j] >= 0.1), got = harm_mean(v, x, wt, 10);
            worst = fmax(worst, fabs(got - ref) / ref), cases++;
            if (!(fabs(got - ref) <= 1e-12 * ref))
                fail_msg("fig. 4's kind %zu, d %g: %.17g against the dense sum's %.17g (%.3g)", i, ds[j], got, ref,
                         (got - ref) / ref);
        }
    /* v1 = v2 = 0: the curve c(phi) = v0 + v3 cos phi + v4 sin phi, phi = 2 theta, an ellipse of axes v3, v4
     * about v0, passing within m of 0 (v0 = -v3 + m n, n normal to the ellipse's plane or in it) */
    static const double ms[] = { 0.5, 1e-2, 1e-4, 1e-6 };
    for (size_t i = 0; i < sizeof ms / sizeof *ms; i++)
        for (int inplane = 0; inplane < 2; inplane++) {
            const double v3[3] = { 1.2, 0.3, -0.4 }, v4[3] = { -0.2, 0.7, 0.25 }, n[3] = { 0.1, 0.35, 0.86 };
            double v[5][3] = { { 0 } };
            for (int k = 0; k < 3; k++)
                v[3][k] = v3[k], v[4][k] = v4[k], v[0][k] = -v3[k] + ms[i] * (inplane ? -v3[k] : n[k]);
            const double ref = ref_mean(v, ms[i] >= 0.1), got = harm_mean(v, x, wt, 10);
            worst = fmax(worst, fabs(got - ref) / ref), cases++;
            if (!(fabs(got - ref) <= 1e-12 * ref))
                fail_msg("v1 = v2 = 0, m %g%s: %.17g against the dense sum's %.17g (%.3g)", ms[i],
                         inplane ? " (in the plane)" : "", got, ref, (got - ref) / ref);
        }
    /* v0, v3, v4 in the plane x, z, v1, v2 along y: the element's square (s_x^2 + s_z^2) + (d h_y)^2 */
    for (size_t j = 0; j < sizeof ds / sizeof *ds; j++) {
        const double v[5][3] = { { 0.3, 0, 1.1 }, { 0, 2.0 * ds[j], 0 }, { 0, -0.7 * ds[j], 0 }, { -0.3, 0, 1.3 },
                                 { 0.31, 0, -0.2 } };
        const double ref = ref_mean(v, ds[j] >= 0.1), got = harm_mean(v, x, wt, 10);
        worst = fmax(worst, fabs(got - ref) / ref), cases++;
        if (!(fabs(got - ref) <= 1e-12 * ref))
            fail_msg("the plane x, z, d %g: %.17g against the dense sum's %.17g (%.3g)", ds[j], got, ref, (got - ref) / ref);
    }
    /* the k = 4 stress model's face (test_props) at w = 0.40092258819092: a dip to 0.0085 of the largest
     * where the trapezoidal rule's levels of 16 and 32 points agreed to 1e-8 by chance, 4.6e-8 off */
    {
        const double v[5][3] = { { 0, 0, 29.839862575751138 }, { 0, -16.492184542010349, 0 },
                                 { -0.16130083047414151, 1.090921734220329, 0 }, { 0, -0.0, 29.375613885449685 },
                                 { 0, 0, -1.9602688670929178 } };
        const double ref = ref_mean(v, 0), got = harm_mean(v, x, wt, 10);
        worst = fmax(worst, fabs(got - ref) / ref), cases++;
        if (!(fabs(got - ref) <= 1e-12 * ref))
            fail_msg("the k = 4 stress model's section: %.17g against the adaptive rule's %.17g (%.3g)", got, ref,
                     (got - ref) / ref);
    }
    print_message("harm_mean on %d even sections: %.3g off at most\n", cases, worst);
}

/* Sections with odd harmonics (the sampled path: cuts at the located least values, graded towards
 * them): fig. 4's kind with a z component e in v1 (z's part s0 + e cos theta + s3 cos 2 theta + s4 sin
 * 2 theta changes sign four times a period, in pairs 0.1 to 0.3 apart in theta: two narrow dips close
 * together, of depth about d, twice a period, each pair unlike the other). */
static void harm_mean_should_find_both_of_two_close_dips_on_odd_sections(void **state)
{
    (void)state;
    double x[10], wt[10];
    ref_gauss_legendre(10, x, wt);
    double worst = 0.0;
    int cases = 0;
    static const double ds[] = { 1.0, 0.1, 1e-2, 1e-3, 1e-4, 1e-5 };
    static const double sh[][4] = { { 34.3, 34.33, 4.08, 0.05 }, { 34.3, 34.33, 4.08, -0.4 }, { 1.0, -0.3, 1.4, 0.2 },
                                    { 0.9, 0.1, 1.0, 0.02 } };
    for (size_t i = 0; i < sizeof sh / sizeof *sh; i++)
        for (size_t j = 0; j < sizeof ds / sizeof *ds; j++) {
            double v[5][3];
            fig4_kind(sh[i][0], sh[i][1], sh[i][2], 6.5 * (1 + i), 0.8, -0.77 + 0.3 * i, ds[j], v);
            v[1][2] = sh[i][3];
            const double ref = ref_mean(v, ds[j] >= 0.1), got = harm_mean(v, x, wt, 10);
            worst = fmax(worst, fabs(got - ref) / ref), cases++;
            if (!(fabs(got - ref) <= 1e-12 * ref))
                fail_msg("odd section %zu, d %g: %.17g against the adaptive rule's %.17g (%.3g)", i, ds[j], got, ref,
                         (got - ref) / ref);
        }
    print_message("harm_mean on %d odd sections: %.3g off at most\n", cases, worst);
}

/* A section whose element vanishes to third order (make fuzz's loft, whose section at some w is
 * x_t x x_w = (s sin theta - s k / 2 sin 2 theta) e_x = s sin theta (1 - k cos theta) e_x: at k = 1,
 * |x_t x x_w|^2 ~ theta^6 at 0): its mean over a period is s / pi times the integral of |1 - k c| over
 * c in [-1, 1], 2 for k <= 1 and k + 1 / k beyond. The cuts' search (minima) halved every interval near
 * theta = 0 at every depth, 2^40 of them: one section never ended. Also with the cusp turned out of
 * the plane by t e_y in v4 (against the adaptive rule). */
static void harm_mean_should_take_a_section_whose_element_vanishes_to_third_order(void **state)
{
    (void)state;
    double x[10], wt[10];
    ref_gauss_legendre(10, x, wt);
    const double s = 9.5870525873394357;
    static const double ks[] = { 1.0, 1.0 + 1e-12, 1.0 - 1e-12, 1.0 + 1e-8, 1.0 - 1e-8, 1.0 + 1e-4, 0.999, 1.5 };
    for (size_t i = 0; i < sizeof ks / sizeof *ks; i++) {
        const double v[5][3] = { { 0, 0, 0 }, { 0, 0, 0 }, { s, 0, 0 }, { 0, 0, 0 }, { -0.5 * s * ks[i], 0, 0 } };
        const double ref = s / M_PI * (ks[i] <= 1.0 ? 2.0 : ks[i] + 1.0 / ks[i]), got = harm_mean(v, x, wt, 10);
        if (!(fabs(got - ref) <= 1e-12 * ref))
            fail_msg("k = 1 %+g: %.17g against the exact %.17g (%.3g)", ks[i] - 1.0, got, ref, (got - ref) / ref);
    }
    static const double ts[] = { 1e-9, 1e-6, 1e-3 };
    for (size_t i = 0; i < sizeof ts / sizeof *ts; i++) {
        const double v[5][3] = { { 0, 0, 0 }, { 0, 0, 0 }, { s, 0, 0 }, { 0, 0, 0 }, { -0.5 * s, ts[i] * s, 0 } };
        const double ref = ref_mean(v, 0), got = harm_mean(v, x, wt, 10);
        if (!(fabs(got - ref) <= 1e-12 * ref))
            fail_msg("t = %g: %.17g against the adaptive rule's %.17g (%.3g)", ts[i], got, ref, (got - ref) / ref);
    }
}

/* A loft whose sections alternate a segment along z and one along x (w = 0, 1/8, ..., 1): its skin
 * u = 1 is of one harmonic, and every section of it dips deep, so each takes the cuts, about 1200 points
 * of theta (and their minima's intervals) where the trapezoidal rule takes 128: the whole face took
 * 10222 sections and 1.2e7 points, 0.55 s, four times what api_cost_props estimates for the solid.
 * Past CUT_WORK (4e6) harm_face gives the face to the general path's panels, which bound their work:
 * after about a third of those sections. The area is then the panels' (test_props checks such lofts
 * against ref_props); here it must agree with the independent one to 1e-9. */
static void harm_face_should_give_a_face_whose_every_section_cuts_deep_to_the_panels_early(void **state)
{
    (void)state;
    char text[2048];
    int at = snprintf(text, sizeof text, "{\"loft\":{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-1,-1,-1]},\"sections\":[");
    for (int i = 0; i <= 8; i++)
        at += snprintf(text + at, sizeof text - (size_t)at, "%s{\"w\":%g,\"profile\":[[%s],[0,0,0],[0,0,0]]}",
                       i ? "," : "", i / 8.0, i % 2 ? "8,0,0" : "0,0,8");
    snprintf(text + at, sizeof text - (size_t)at, "]}}");
    pde_solution *sol = solve_text(text);
    assert_non_null(sol);
    double x[10], wt[10], edge[9];
    ref_gauss_legendre(10, x, wt);
    for (int i = 0; i <= 8; i++)
        edge[i] = i / 8.0;
    ref_props_out r;
    assert_int_equal(ref_props(sol, &r), 0);
    assert_true(r.converged);
    pde_props p;
    assert_int_equal(pde_properties(sol, NULL, &p), PDE_OK);
    double size = 0.0;
    for (int c = 0; c < 3; c++)
        size = fmax(size, p.bbox_max[c] - p.bbox_min[c]);
    const harm_opts o = { .edge = edge, .np = 8, .x = x, .wt = wt, .n = 10, .tol = 1e-10 * size * size, .size = size };
    double area = 0.0, flux = 0.0;
    size_t nodes = 0;
    const int h = harm_face(sol, 0, 1, &o, &area, &flux, &nodes);
    print_message("harm_face %d after %zu sections\n", h, nodes);
    assert_int_equal(h, 0);
    assert_true(nodes < 6000);   /* the whole face: 10222 */
    const double miss = fabs(p.surface_area - r.surface_area) / r.surface_area;
    print_message("surface_area %.15g, reference %.15g: %.3g off, %.3g reported\n", p.surface_area, r.surface_area,
                  miss, p.surface_area_error);
    assert_true(miss <= 1e-9 && miss <= p.surface_area_error);
    pde_solution_free(sol);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(harm_mean_should_match_a_dense_sum_on_even_sections_with_deep_dips),
        cmocka_unit_test(harm_mean_should_find_both_of_two_close_dips_on_odd_sections),
        cmocka_unit_test(harm_mean_should_take_a_section_whose_element_vanishes_to_third_order),
        cmocka_unit_test(harm_face_should_give_a_face_whose_every_section_cuts_deep_to_the_panels_early),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
