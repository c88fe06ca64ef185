/*
 * quad.h: integrals over the solid, weighted by |det J|, and its skin's area
 * (internal to core/; used by props.c).
 */
#ifndef PDE_QUAD_H
#define PDE_QUAD_H

#include "internal.h"

/* The integrals of |det J| times 1, r_i, r_i r_j (r = x - x0), and of det J. */
enum { Q_VOL = 0, Q_M1 = 1, Q_M2 = 4, Q_SIGNED = 10, Q_N = 11 };
/* Q_M2 + 0..5: r0r0, r1r1, r2r2, r0r1, r0r2, r1r2 */

typedef struct {
    double acc[Q_N];
    size_t evals;       /* points evaluated */
    size_t lined;       /* panels integrated along lines, where det J may change sign */
    double err;         /* the rules' estimated error on the fastest term, relative: 1e-14 unless the
                         * work's bound made them coarser */
    size_t refined, unrefined;   /* lined panels refined, and left unrefined by the work's bound */
    double refine_change;        /* the sum of what refinement changed of the refined panels' volume */
    double refine_left;          /* the sum of |fine - coarse| of the volume over boxes whose refinement
                                  * stopped at its depth (or the work's bound) before it agreed */
    int roots_skipped;  /* the work's bound stopped lines locating det J's roots (or the area's) */
    double area_left;   /* quad_area: the area's estimated error, absolute (quad.c's face_refine) */
} quad_result;

/*
 * det J separates along axis (0: u, 1: v) when each component either has every mode's factor of that
 * axis t^n (the same n >= 1 for all of them: in[c] = 1) or every mode's factor 1 (in[c] = 0; a
 * component without modes counts so). With ns = in[0] + in[1] + in[2] >= 1, x_c = t^(n in[c]) X_c
 * of the two other parameters, and
 *
 *     det J = n t^(n ns - 1) G,     G = det J at t = 1, divided by n,
 *
 * (multiply det J's column of the axis by t / n: each row with in[c] = 1 becomes t^n (X_c, its two
 * partials); a row with in[c] = 0 has 0 there). So |det J| and its sign are G's, times a
 * factor >= 0 of t alone, and every integral over the cube is a product of an exact integral over t
 * and one over the face t = 1 (docs/MATH.md, "Separable solids"). axis = -1 when det J does not
 * separate so.
 */
typedef struct {
    int axis, n, ns, in[3];
    /* The face's other parameter s (not the axis, not w) when G does not depend on it: ns = 2, the
     * component with in[c] = 0 a function of w alone, and every pair of s-factors of the two others
     * with a constant Wronskian a b' - b a' (sin and cos, sinh and cosh of one frequency, one factor
     * twice, exp(+-alpha s), 1 and s). Then G = Z'(w) sum h_i(w) k_j(w) W_ij = g(w); else -1. */
    int free;
    /* Components with in[c] = 1 that have modes of w alone as well (factors 1 along u and v: a centre
     * C_c(w) moving along w, x_c = t^n X_c + C_c). Only quad_solid takes them (lift[c] = 1;
     * quad_separate leaves them 0 and refuses such a solid): on the free path, and on the face's
     * other paths where det J may change sign. There ns = 1, or ns = 2 and the third component is
     * a function of w alone, its row (0, 0, Z'), so C_c's row (0, 0, C_c') adds C_c' times a (t, s)
     * minor that is 0 to det J, which keeps its form; only the integrals over t of C_c's terms
     * differ (one factor t^n fewer). */
    int lift[3];
} quad_sep;

void quad_separate(const pde_solution *s, quad_sep *sep);

/* jscale: the size of det J over the solid, for what counts as zero; jsign: +1 or -1 where det J
 * is certified to keep that sign over the whole cube (up to 1e-13 jscale; pde_properties' branch and
 * bound), so that every panel takes its tensor rule, else 0; vscale: the size of the
 * volume (jscale will do), for the refinement's tolerance. separate: where det J separates
 * (quad_separate), integrate over the face t = 1 only, and along w alone where det J does not
 * depend on the face's other parameter (pde_properties), else by rows of w refined along w over one
 * period of the face where the solid repeats itself along it (quad.c's face_rows, param_rotation), and
 * by the face's 2-D panels where it does not; where it does not separate, along a polynomial axis
 * (quad.c's poly_line); 2: the face by rows, even where det J does not depend on its other parameter
 * or the face has no period (tests); 3: the same over the whole face, no period used (tests); 0: over
 * the cube, lines along the axis that crosses det J's zero set most often, in 3-D (tests).
 * Where det J does not separate and every factor along v is 1 or a whole harmonic of 2 pi v (lofts),
 * with lines along u where jsign is 0, v takes one uniform rule over the period, exact where det J
 * keeps its sign (checked on the lines, else the path above), and out->err is the a-posteriori
 * estimate of w's rules instead (their rows' Legendre tails), large where the work's bound stopped
 * their refinement. A loft (x, y = C(w) + t^n P(s, w), z = Z(w)) whose jsign is 0 takes rows of w
 * split at det J's roots along s instead (quad.c's fold_solid): exact where the roots are found. */
pde_status quad_solid(const pde_solution *s, const double x0[3], double jscale, double vscale, int separate,
                      int jsign, const pde_cancel *cancel, quad_result *out);

/* Where det J does not depend on the face's other parameter (quad_sep's free: det J = n t^p g(w)), a
 * certificate of g's sign over a span of w: sign(ctx, w0, w1, g0, g1, tol), g0 and g1 g's values at w0
 * and w1, is +1 where g >= -tol is certified on [w0, w1], -1 where g <= tol is, else 0 (pde_properties:
 * g's Taylor models). A panel of w so
 * certified takes its rule alone, with no roots or dips sought and no halves to check it against, as
 * every panel does where jsign certifies the whole cube. quad_solid_signs: quad_solid with it (ws
 * NULL: none). */
typedef struct {
    int (*sign)(const void *ctx, double w0, double w1, double g0, double g1, double tol);
    const void *ctx;
} quad_wsign;

pde_status quad_solid_signs(const pde_solution *s, const double x0[3], double jscale, double vscale, int separate,
                            int jsign, const quad_wsign *ws, const pde_cancel *cancel, quad_result *out);

/* The area of the skin; size: the solid's extent, for deciding that two faces coincide. Its panels
 * are the solid's, and so is its rules' error; a face that repeats itself along u or v, reflected or
 * turned about an axis, over one period (or half of one, mirrored) times its copies (quad.c's
 * face_period). info->acc[Q_SIGNED] is the signed volume computed
 * another way, from the faces: (1/3) of the flux of x through them (divergence theorem). */
pde_status quad_area(const pde_solution *s, double size, const pde_cancel *cancel, double *area,
                     quad_result *info);
/* The same with period 0: each face whole, its periods' panels kept but no period used (tests; quad.c's
 * face_period); QUAD_PERIOD: quad_area; QUAD_GENERAL added: no face of one harmonic by its fast path
 * (harm.h), the panels instead (tests). */
enum { QUAD_PERIOD = 1, QUAD_GENERAL = 2 };
pde_status quad_area_period(const pde_solution *s, double size, int period, const pde_cancel *cancel, double *area,
                            quad_result *info);

/* The part [0, len] of t (u or v) over which det J repeats itself, returned: where t -> t + 1/N turns
 * the solid about an axis (quad.c's param_rotation; det R = 1), 1/N, and 1/(2N) with *mirror = 1
 * where the mirror t -> 1/N - t keeps det J too (fig. 3a, 3b); else 1. */
double quad_detj_period(const pde_solution *s, int t, int *mirror);

/* Whether two modes have the same h(w): the same slabs and terms (fig. 4's x = h1 sin + h2 cos, y =
 * h2 sin + h1 cos: each h twice). Cannot fail. */
int quad_same_h(const pde_mode *a, const pde_mode *b);

/* Panels per axis and Gauss-Legendre points per panel on each axis (also for api/cost.h). */
void quad_panels(const pde_solution *s, int np[3], int n[3]);

#endif
