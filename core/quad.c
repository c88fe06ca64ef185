/*
 * quad.c: integrals over the solid weighted by |det J|, and the skin's area
 * (quad.h).
 *
 * |det J| has a kink where det J changes sign, which a Gauss rule does not
 * see: it loses its order there (fig. 4a's volume was 3e-4 off). So:
 *
 * 1. The cube is cut into panels sized to the integrand's frequencies, and
 *    each panel gets the fewest Gauss-Legendre points per axis whose error on
 *    exp(i f t) is below 1e-14.
 * 2. On a panel where det J has a certified sign (bound.h), a tensor rule.
 * 3. Elsewhere, the panel is integrated along lines of the axis that crosses
 *    det J's zero set most often on a 4 x 4 x 4 sample (line_axis). On each
 *    line det J is sampled at the ends and the rule's nodes, every sign
 *    change and every dip through zero and back between samples is located
 *    to rounding (Illinois, golden section), and each
 *    piece between roots gets its own n-point rule: the line integral is
 *    exact to rounding. Across lines it is smooth except where roots appear
 *    or leave the panel, a singularity of order 3/2 at worst, which the
 *    outer tensor rule integrates to about 1e-13 relative on the paper's
 *    figures (fig. 4a: 8.15592346144658 against 8.15592346144647 computed
 *    with 160 digits).
 *
 * Where det J separates along u or v (quad_separate: det J = n t^p G), all of
 * this runs on the face t = 1 alone, the flat axis (n 0: one point, weight 1),
 * and the integrals over t are exact (separable_moments); so do the skin's
 * faces whose element separates too (face_separates). Where G = g(w) moreover
 * (fig. 2, 4), the integrals over the face's other parameter are exact too,
 * from the modes' moments, and only a rule along w is left (free_solid). Where det J may change
 * sign there, depends on both of the face's parameters, and the solid repeats
 * itself along the other one (param_symmetry, or turned about an axis:
 * param_rotation), one period of the face goes by rows of w instead of 2-D
 * panels: whole lines of the other parameter, refined along w alone
 * (face_rows).
 *
 * The skin's faces run on lines the same way, with |x_a x x_b| for |det J|: cut at the roots of its
 * component along its direction (a cuspidal edge), and where a fold is rounded (the element dips
 * near 0 without vanishing) at the located least, with pieces graded towards it (face_toward).
 *
 * Where det J does not separate but every factor along v is 1 or a whole harmonic of 2 pi v (a loft's
 * profiles, x = C(w) + u P(v, w)), the panels along v side by side make one uniform rule over the
 * period, exact on the integrands where det J keeps its sign (periodic_points: tower and blade, 32
 * harmonics, were within 1e-13 and 3e-11 of an independent quadrature, but reported the err 2 of the
 * a-priori estimate on sin 64 pi v; now 1e-14 with err 3e-14 and 6e-15); lines along u
 * (poly_line) show whether it does, else the general path runs instead; and w's panels are halved
 * where their rows' Legendre coefficients do not fall fast enough, which estimates the error
 * (mid_panel, mid_tail). Where a loft's det J may change sign (jsign 0; x = C(w) + t^n P(s, w), z =
 * Z(w)), det J = n t^(2n - 1) Z'(w) Q(s, w) instead: rows of w, each exact from Q's roots along s,
 * and w cut where the roots' count changes (fold_solid).
 *
 * Each panel tabulates every mode's factor of each axis at its rules' points
 * once (axis_tab), so a point on a line is four multiply-adds per mode; only
 * roots, dips and the rules of pieces between roots evaluate factors afresh.
 * The work is bounded (PDE_PROPS_WORK), and the result says what it cost in
 * accuracy (props.c's integral_error).
 */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bound.h"
#include "harm.h"
#include "quad.h"

#define GMAX 24        /* Gauss points per panel axis, at most */
#define MAX_PANELS 32
#define PANEL_PHASE 8.0       /* radians of the integrand per panel */
#define MAX_WORK PDE_PROPS_WORK   /* nodes of the rules times (modes + 1), at most: bounded work */
#define MAX_EDGES (MAX_PANELS + PDE_MAX_SECTIONS)   /* panels along w: MAX_PANELS, plus one per slab */
#define FACE_DEPTH 4          /* halvings of a face's panel in its refinement, at most */
#define FACE_DEPTH_MAX 8      /* ... and 8 where a panel still differs from its quarters by FACE_DEEP tolerances */
#define FACE_DEEP 30.0        /* (fig. 4a: two panels at a cusp of the fold, 8.7e-7 apart at depth 4) */
#define FACE_EST 1e4          /* a face panel whose estimate is below this times the tolerance is not split */
#define FACE_EST_MIN 0.3      /* ... unless its element falls below this of its largest at the nodes */
#define FACE_EST_OFF 1e-2     /* ... and its error counted as this of the estimate (face_refine's measure) */
#define GRADE_RATIO 0.15      /* a rounded fold: pieces graded towards its least, each this of the distance left, */
#define GRADE_POINTS 10       /* ... the first with this rule, each next with 2 points fewer, 4 at least */
#define GRADE_LEVELS 12       /* ... this many pieces at most */
#define GRADE_MIN 1e-7        /* ... where the least is above this of the line's largest (below, |t| there) */
#define DIP_WORK (0.7 * OFF_WORK)   /* ... while the points off the tables stay below this (the rest: roots) */
/* Face panels refined, at most: every panel of the six faces. At 256 (fig. 4's, not all of fig. 3's),
 * fig. 3d's area was 6.6e-8 off the reference, now 2.4e-10 (fig. 3c: 7.3e-10 -> 8e-13) for 6% and 8%
 * more instructions; REFINE_WORK bounds the work. */
#define FACE_REFINE (6 * MAX_PANELS * MAX_PANELS)
#define POLL_WORK 65536       /* factor evaluations between polls of the caller's stop() */
#define OUTER_DEPTH 2         /* halvings of a panel in its refinement, at most */
#define OFF_WORK MAX_WORK   /* points off the tables times (modes + 1), at most */
#define REFINE_WORK (2 * MAX_WORK)   /* points times modes after which no panel is refined */
#define REFINE_PANELS 96      /* panels refined, at most: fig. 4's 24 to 72, not fig. 3's 1024 */
/* The same where det J separates (quad_separate) and the face has no period (face_rows' lines would
 * take more than OFF_WORK on fig. 3a at an odd n_xy >= 25): a face's quadrants cost a quarter of a
 * box's octants, so every panel is refined, deeper: fig. 3b's volume came within 1e-11 of the
 * reference at four halvings (7e-7 at two, within 96 panels). */
#define FLAT_DEPTH 4
#define FLAT_PANELS ((size_t)-1)
/* The same where every line runs along a polynomial axis (qctx's along): its boxes are halved in the
 * two other axes only, each line exact (poly_line). */
#define ALONG_DEPTH 5
#define ALONG_PANELS ((size_t)-1)
/* ... and halved at least ALONG_MIN_DEPTH times where their lines disagree before a box agreeing with
 * its quarters stops: a lobe of det J's fold narrower than both rules' spacing can make the two agree
 * and both miss it (fig. 3d: a box agreed to 1e-10 at its first halving, both 3e-9 off; the volume
 * was 1.7e-10 off an independent quadrature, 1.2e-11 now). */
#define ALONG_MIN_DEPTH 3
#define ALONG_NEAR 0.01       /* ... and refined where |det J| at a line's end comes near 0 (ends_clear) */
/* ... converging at least by ALONG_RHO each halving (solid_run's estimate: a kink |s| of the lines' integrals) */
#define ALONG_RHO 0.25
#define SEG_MEMO 128          /* segments of w remembered by free_panel */
#define ROW_DEPTH 12          /* halvings of a row of the face along w (row_refine), at most */
#define ROW_DEPTH_MAX 40      /* ... and of its spans between the points where a line's signature changes */
#define ROW_EPS 1e-9          /* those points located to this, in w */
#define ROW_TOL 1e-13         /* a span agrees with its halves to this of the solid's volume */
#define FREE_DEPTH 2          /* halvings along w where det J does not depend on the face's other parameter */
/* A loft's periodic axis (quad_solid's periodic path): its uniform rule's panels and points, and the
 * halvings of a row of w panels where the rows' Legendre tail is above MID_TOL of the solid's volume. */
#define MID_DEPTH 6
#define MID_TOL 1e-14
#define MID_AMP 1e-15         /* ... and where a term of h above this of the largest on the panel */
#define MID_SPACING 1.0       /* ... changes by more than e (or a radian) between the rule's points */
#define MID_POINTS 8          /* ... whose rules take this many points at least: mid_tail's six coefficients */
#define HARM_RULE 10          /* harm_face's Gauss points per panel of w and piece of theta */
#define HARM_TOL 1e-10        /* ... and its tolerance on a unit of w, of the solid's size squared */

/* The components of each second moment Q_M2 + k (quad.h's order): r[m2_i[k]] r[m2_j[k]]. */
static const int m2_i[6] = { 0, 1, 2, 0, 0, 1 }, m2_j[6] = { 0, 1, 2, 1, 2, 2 };

/* A point's x as line_point gives it: x[0..2], and where the face's integrals lift (qctx's lifted), x[c] is
 * only the part of x_c with the factor t^n and x[3 + c] the rest, its modes of w alone less x0_c. */
#define QX 6

/* The panels: their edges along each axis, the points of each axis's rule, and its estimated error. */
typedef struct {
    int np[3], n[3];
    double edge[3][MAX_EDGES + 1];
    double phase[3];             /* the fastest phase over a panel of the axis */
    double err;
} qplan;

/* Every factor of one axis at a panel's points along it: its start, its rule's n nodes and its end
 * (n = 0: the one point lo, a face's fixed parameter). val[i * mt + o], o = off[c] + m. */
typedef struct {
    double t[GMAX + 2];
    int n;
    double *val, *der;
} axis_tab;

typedef struct {
    const pde_solution *s;
    const pde_cancel *cancel;
    double x0[3], jtol;
    double f[3];                 /* the integrand's frequencies (at least 1) */
    int poly[3];                 /* the solution's degree along each axis where it is a polynomial, else -1 */
    double vscale;               /* the solid's volume, roughly: for refinement's tolerance */
    const double (*gx)[GMAX], (*gw)[GMAX];   /* n-point rules on [0, 1] (rules_x, rules_w) */
    int n[3];                    /* the current panel's points per axis (0: the flat axis) */
    int flat;                    /* the axis fixed at 1 (quad_separate), or -1 */
    int along;                   /* a polynomial axis every line runs along, never split (quad_solid), or -1 */
    double along_added, along_change;   /* box_refine's last halvings' changes, and their parents' */
    double end_min[2], end_max[2];   /* poly_line: the least and largest |det J| at the lines' two ends */
    int line_sig, line_mixed;    /* poly_line: the first line's signs and roots in panel_lines, and whether
                                  * another line's differ */
    int jsign;                   /* det J's sign where certified over the whole solid (quad_solid), or 0 */
    const quad_wsign *wsign;     /* free_solid's certificates of G's sign on a panel of w, or NULL */
    int free;                    /* the face's parameter det J does not depend on (quad_sep), or -1 */
    /* The axis whose panels take the uniform (midpoint) rule, quad_solid's periodic path, or -1; the
     * signature of its first line along u (poly_line), and whether a line had another or a root; the
     * rows' estimated error (the Legendre tail of the rows' volume, mid_panel), and the row values
     * of w's nodes panel_lines collects where rows is not NULL. */
    int mid, mid_sig, mid_rough;
    double mid_err, *rows;
    /* free_panel's segments of w whose sign was certified or not, the same for every panel of the
     * other parameter: remembered, up to SEG_MEMO of them */
    double seg_lo[SEG_MEMO], seg_hi[SEG_MEMO];
    unsigned char seg_def[SEG_MEMO];
    int nseg;
    int max_depth;               /* OUTER_DEPTH, or FLAT_DEPTH with a flat axis */
    size_t max_panels;           /* REFINE_PANELS, or FLAT_PANELS */
    size_t off[3], mt;           /* modes of the components before c; modes in all */
    axis_tab tab[3];             /* the current panel's factors */
    pbox tab_box;                /* the box of the tables when tab_ok (tabs_for) */
    int tab_n[3], tab_ok;        /* tab_ok: a bit per axis whose table is tab_box's */
    double *g, *dg;              /* mt: the line's own factor at a point off the tables */
    /* The current line: along axis k, per mode, the fixed factors' product P and its derivatives
     * along the two other axes (i, j in axis order). */
    int k, ax[2];
    double *P, *Pi, *Pj;         /* mt each */
    int line_roots, line_lo;     /* the roots line_integrate located on its last line, and whether det J is
                                  * above jtol at its start */
    int count_only;              /* line_integrate only counts the roots (row_sig_at), adding nothing */
    int node_sig[GMAX + 2];      /* panel_lines: the lines' signatures through each index of w, summed over
                                  * panels: twice their roots, plus 1 where det J is above jtol at s = 0 */
    /* Where det J separates with a lift (quad_sep's lift) off the free path: lifted[o] = 1 for a lifted
     * component's modes of w alone (else NULL), x0 of the lifted components (their moments are taken
     * about it, before any product), and the factors by which add_value scales the terms with those
     * modes: each has one factor t^n fewer to integrate over t (solid_run). */
    unsigned char *lifted;
    double lift_x0[3], lift1[3], lift_xl[6], lift_ll[6];
    quad_result r;
    size_t modes, next_poll;
    size_t off_evals;            /* points off the tables: roots, dips and the rules of pieces */
    int stopped;
} qctx;

/* Points off the tables cost a factor per mode each; past OFF_WORK of them (times modes), lines no
 * longer locate det J's roots, and the result says so. */
static int off_budget(qctx *q)
{
    if (q->off_evals * q->modes < OFF_WORK)
        return 1;
    q->r.roots_skipped = 1;
    return 0;
}

/* A face's rounded folds (face_toward) take DIP_WORK at most: the rest is for the roots (fig. 3b's
 * face u = 1 took it all once, and its faces w = 0 and 1 were 1e-3 off without their roots). */
static int dip_budget(const qctx *q)
{
    return q->off_evals * q->modes < DIP_WORK;
}

/* Gauss-Legendre nodes and weights on [0, 1], by Newton on P_n. */
static void gauss_legendre(int n, double *x, double *w)
{
    for (int i = 0; i < (n + 1) / 2; i++) {
        double z = cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1.0, p1 = z;
            for (int k = 2; k <= n; k++) {
                double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
                p0 = p1, p1 = p2;
            }
            if (n == 1)
                p0 = 1.0, p1 = z;
            dp = n * (z * p1 - p0) / (z * z - 1.0);
            double dz = p1 / dp;
            z -= dz;
            if (fabs(dz) < 1e-16)
                break;
        }
        double wt = 2.0 / ((1.0 - z * z) * dp * dp);
        x[i] = 0.5 * (1.0 - z), x[n - 1 - i] = 0.5 * (1.0 + z);
        w[i] = w[n - 1 - i] = 0.5 * wt;
    }
}

/* The rules of 1 .. GMAX points, computed once for every thread. */
static double rules_x[GMAX + 1][GMAX], rules_w[GMAX + 1][GMAX];
/* rules_leg[n][j][i] = (2k + 1) w_i P_k(2 x_i - 1), k = n - 1 - j: the n-point rule's weights for
 * the Legendre coefficient a_k of the polynomial through its nodes (legendre_tail). */
static double rules_leg[GMAX + 1][2][GMAX];
/* The uniform rules of 1 .. GMAX points on [0, 1], midpoints, weights 1/n: panels of them side by side
 * over a period make one uniform rule, exact on a trigonometric polynomial of a lower degree than its
 * points (quad_solid's periodic path). */
static double mid_x[GMAX + 1][GMAX], mid_w[GMAX + 1][GMAX];
static pthread_once_t rules_once = PTHREAD_ONCE_INIT;

static void rules_init(void)
{
    for (int n = 1; n <= GMAX; n++) {
        gauss_legendre(n, rules_x[n], rules_w[n]);
        for (int i = 0; i < n; i++)
            mid_x[n][i] = (i + 0.5) / n, mid_w[n][i] = 1.0 / n;
        for (int i = 0; i < n; i++) {
            const double y = 2.0 * rules_x[n][i] - 1.0;
            double p[GMAX + 1] = { 1.0, y };
            for (int k = 2; k < n; k++)
                p[k] = ((2 * k - 1) * y * p[k - 1] - (k - 1) * p[k - 2]) / k;
            for (int j = 0; j < 2 && j < n; j++)
                rules_leg[n][j][i] = (2 * (n - 1 - j) + 1) * rules_w[n][i] * p[n - 1 - j];
        }
    }
}

/* The n-point rule of axis a: nodes and weights on [0, 1] (uniform on q->mid, else Gauss-Legendre). */
static const double *rule_x(const qctx *q, int a, int n)
{
    return a == q->mid ? mid_x[n] : q->gx[n];
}

static const double *rule_w(const qctx *q, int a, int n)
{
    return a == q->mid ? mid_w[n] : q->gw[n];
}

/* Every factor of axis a at the tables' points tb->t[0 .. np - 1] (the modes of x, y, z in order, as
 * q->off lays them out; factors and w-terms that modes share computed once). */
static void tab_eval(qctx *q, int a, int np)
{
    axis_tab *tb = &q->tab[a];
    for (int i = 0; i < np; i++)
        solution_factors(q->s, a, tb->t[i], tb->val + (size_t)i * q->mt, tb->der + (size_t)i * q->mt);
}

/* Fills q->tab[a] for [lo, hi] with an n-point rule (n = 0: the point lo alone). */
static void tab_fill(qctx *q, int a, double lo, double hi, int n)
{
    axis_tab *tb = &q->tab[a];
    tb->n = n;
    tb->t[0] = lo;
    if (n) {
        for (int i = 0; i < n; i++)
            tb->t[i + 1] = lo + (hi - lo) * rule_x(q, a, n)[i];
        tb->t[n + 1] = hi;
    }
    tab_eval(q, a, n ? n + 2 : 1);
}

/* x's partials d[axis][component] at the tables' points idx[0], idx[1], idx[2]. */
static void tab_partials(const qctx *q, const int idx[3], double d[3][3])
{
    const size_t o0 = (size_t)idx[0] * q->mt, o1 = (size_t)idx[1] * q->mt, o2 = (size_t)idx[2] * q->mt;
    for (int c = 0; c < 3; c++) {
        double su = 0, sv = 0, sw = 0;
        for (size_t o = q->off[c], end = o + q->s->comp[c].nmodes; o < end; o++) {
            const double U = q->tab[0].val[o0 + o], dU = q->tab[0].der[o0 + o];
            const double V = q->tab[1].val[o1 + o], dV = q->tab[1].der[o1 + o];
            const double H = q->tab[2].val[o2 + o], dH = q->tab[2].der[o2 + o];
            su += dU * V * H, sv += U * dV * H, sw += U * V * dH;
        }
        d[0][c] = su, d[1][c] = sv, d[2][c] = sw;
    }
}

/* The table's point of axis a nearest to t. */
static int tab_nearest(const qctx *q, int a, double t)
{
    const axis_tab *tb = &q->tab[a];
    int best = 0;
    for (int i = 1; i < (tb->n ? tb->n + 2 : 1); i++)
        if (fabs(tb->t[i] - t) < fabs(tb->t[best] - t))
            best = i;
    return best;
}

/* The tables of box b with the current rules, each axis's unless it is already: boxes side by side
 * share the axes they are not split along (along a polynomial axis, every box its one panel: fig. 3c
 * refilled it for each, a quarter of the integrals' factor evaluations). */
static void tabs_for(qctx *q, const pbox *b)
{
    for (int a = 0; a < 3; a++)
        if (!(q->tab_ok >> a & 1) || q->tab_box.lo[a] != b->lo[a] || q->tab_box.hi[a] != b->hi[a] ||
            q->tab_n[a] != q->n[a]) {
            tab_fill(q, a, b->lo[a], b->hi[a], q->n[a]);
            q->tab_box.lo[a] = b->lo[a], q->tab_box.hi[a] = b->hi[a], q->tab_n[a] = q->n[a];
            q->tab_ok |= 1 << a;
        }
}

/* Fixes the line along axis k through the tables' points idx[a] of the two other axes. */
static void line_set(qctx *q, int k, const int idx[3])
{
    q->k = k;
    for (int a = 0, n = 0; a < 3; a++)
        if (a != k)
            q->ax[n++] = a;
    const axis_tab *ti = &q->tab[q->ax[0]], *tj = &q->tab[q->ax[1]];
    const double *fi = ti->val + (size_t)idx[q->ax[0]] * q->mt, *di = ti->der + (size_t)idx[q->ax[0]] * q->mt;
    const double *fj = tj->val + (size_t)idx[q->ax[1]] * q->mt, *dj = tj->der + (size_t)idx[q->ax[1]] * q->mt;
    for (size_t o = 0; o < q->mt; o++)
        q->P[o] = fi[o] * fj[o], q->Pi[o] = di[o] * fj[o], q->Pj[o] = fi[o] * dj[o];
}

/* line_point where the face's integrals lift (qctx's lifted): x[c] the part of x_c with the factor t^n,
 * x[3 + c] its modes of w alone less x0_c. */
static double line_point_lifted(qctx *q, const double *g, const double *dg, double x[QX], double d[3][3])
{
    const int k = q->k, i = q->ax[0], j = q->ax[1];
    for (int c = 0; c < 3; c++) {
        double sx = 0, sk = 0, si = 0, sj = 0, sl = 0;
        for (size_t o = q->off[c], e = o + q->s->comp[c].nmodes; o < e; o++) {
            const double v = q->P[o] * g[o];
            *(q->lifted[o] ? &sl : &sx) += v;
            sk += q->P[o] * dg[o], si += q->Pi[o] * g[o], sj += q->Pj[o] * g[o];
        }
        x[c] = sx, d[k][c] = sk, d[i][c] = si, d[j][c] = sj;
        x[3 + c] = q->lift1[c] != 0.0 ? sl - q->lift_x0[c] : 0.0;
    }
    q->r.evals++;
    return det3(d[0], d[1], d[2]);
}

/* x (QX), the partials d[axis][component] and det J on the current line where its own factors are g, dg
 * (the lifted sums apart: fig. 3a's lines took 2.8 % more instructions with the test in their loop). */
static double line_point(qctx *q, const double *g, const double *dg, double x[QX], double d[3][3])
{
    if (q->lifted)
        return line_point_lifted(q, g, dg, x, d);
    const int k = q->k, i = q->ax[0], j = q->ax[1];
    for (int c = 0; c < 3; c++) {
        double sx = 0, sk = 0, si = 0, sj = 0;
        for (size_t o = q->off[c], e = o + q->s->comp[c].nmodes; o < e; o++)
            sx += q->P[o] * g[o], sk += q->P[o] * dg[o], si += q->Pi[o] * g[o], sj += q->Pj[o] * g[o];
        x[c] = sx, d[k][c] = sk, d[i][c] = si, d[j][c] = sj;
    }
    q->r.evals++;
    return det3(d[0], d[1], d[2]);
}

/* The same at the current line's table point it. */
static double line_eval_at(qctx *q, int it, double x[QX], double d[3][3])
{
    const axis_tab *tb = &q->tab[q->k];
    return line_point(q, tb->val + (size_t)it * q->mt, tb->der + (size_t)it * q->mt, x, d);
}

/* The same at t, anywhere on the line. */
static double line_eval_d(qctx *q, double t, double x[QX], double d[3][3])
{
    q->off_evals++;
    solution_factors(q->s, q->k, t, q->g, q->dg);
    return line_point(q, q->g, q->dg, x, d);
}

static double line_eval(qctx *q, double t, double x[QX])
{
    double d[3][3];
    return line_eval_d(q, t, x, d);
}

static void add_value(qctx *q, const double x[QX], double j, double wt)
{
    double a = wt * fabs(j);
    if (q->lifted) {   /* x_c = X_c + L_c (line_point): each product's terms scaled by their factors t^n */
        const double *X = x, *L = x + 3;
        double *acc = q->r.acc;
        acc[Q_VOL] += a;
        for (int c = 0; c < 3; c++)
            acc[Q_M1 + c] += a * (X[c] + q->lift1[c] * L[c]);
        for (int k = 0; k < 6; k++) {
            const int i = m2_i[k], l = m2_j[k];
            acc[Q_M2 + k] += a * (X[i] * X[l] + q->lift_xl[k] * (X[i] * L[l] + L[i] * X[l]) + q->lift_ll[k] * L[i] * L[l]);
        }
        acc[Q_SIGNED] += wt * j;
        return;
    }
    double r0 = x[0] - q->x0[0], r1 = x[1] - q->x0[1], r2 = x[2] - q->x0[2];
    double *acc = q->r.acc;
    acc[Q_VOL] += a;
    acc[Q_M1] += a * r0, acc[Q_M1 + 1] += a * r1, acc[Q_M1 + 2] += a * r2;
    acc[Q_M2] += a * r0 * r0, acc[Q_M2 + 1] += a * r1 * r1, acc[Q_M2 + 2] += a * r2 * r2;
    acc[Q_M2 + 3] += a * r0 * r1, acc[Q_M2 + 4] += a * r0 * r2, acc[Q_M2 + 5] += a * r1 * r2;
    acc[Q_SIGNED] += wt * j;
}

static double line_detj(void *arg, double t)
{
    double x[QX];
    return line_eval(arg, t, x);
}

/* The root of det J on the current line in [a, b], where fa and fb have opposite signs. */
static double line_root(qctx *q, double a, double b, double fa, double fb)
{
    return illinois(line_detj, q, a, b, fa, fb);
}

/* The current line over the whole panel, at its rule's nodes in the table. */
static void line_gauss_tab(qctx *q, double wt)
{
    const int n = q->n[q->k];
    const double h = q->tab[q->k].t[n + 1] - q->tab[q->k].t[0], *gw = rule_w(q, q->k, n);
    double x[QX], d[3][3];
    for (int i = 0; i < n; i++) {
        double j = line_eval_at(q, i + 1, x, d);
        add_value(q, x, j, wt * h * gw[i]);
    }
}

/* The fewest Gauss-Legendre points whose error on exp(i f t) over a panel of phase phi = f h is
 * below 1e-14: (e phi / 8n)^(2n), the rule's asymptotic error. */
static int rule_points(double phi);

/* The points of a rule over a panel of width h along axis a: where the solution is a polynomial of
 * degree d along it, the integrands (det J times up to two coordinates: five factors) are of degree
 * at most 5 d wherever det J keeps its sign, and ceil((5 d + 1) / 2) points integrate them exactly. */
static int poly_points(int d)
{
    return d < 0 ? 0 : (5 * d) / 2 + 1;
}

static int axis_points(const qctx *q, int a, double h)
{
    return q->poly[a] >= 0 ? poly_points(q->poly[a]) : rule_points(q->f[a] * h);
}

/* The current line over [a, b], a piece between roots, with a rule sized to the piece. */
static void line_gauss(qctx *q, double a, double b, double wt)
{
    const int n = axis_points(q, q->k, b - a);
    double x[QX], h = b - a;
    for (int i = 0; i < n; i++) {
        double j = line_eval(q, a + h * q->gx[n][i], x);
        add_value(q, x, j, wt * h * q->gw[n][i]);
    }
}

static int sign_changes(double fa, double fb, double tol)
{
    return (fa < -tol && fb > tol) || (fa > tol && fb < -tol);
}

/*
 * Where |det J| has a local minimum among the samples t0 < t1 < t2 without a sign change, det J
 * may dip through zero between them and back: golden-section search for the extreme of sign *
 * det J, from t0 to t2; returns 1 when it crosses zero, with the crossing extreme in *at, *fat.
 */
static int line_dip(qctx *q, double t0, double t2, double sign, double *at, double *fat)
{
    const double g = 0.5 * (3.0 - sqrt(5.0));
    double a = t0, b = t2, x[QX];
    double c = a + g * (b - a), d = b - g * (b - a);
    double fc = sign * line_eval(q, c, x), fd = sign * line_eval(q, d, x);
    for (int it = 0; it < 40 && b - a > 1e-9 * (t2 - t0); it++) {
        if (fc < fd) {
            b = d, d = c, fd = fc;
            c = a + g * (b - a);
            fc = sign * line_eval(q, c, x);
        } else {
            a = c, c = d, fc = fd;
            d = b - g * (b - a);
            fd = sign * line_eval(q, d, x);
        }
        if (fmin(fc, fd) < -q->jtol)
            break;
    }
    *at = fc < fd ? c : d;
    *fat = sign * fmin(fc, fd);
    return fmin(fc, fd) < -q->jtol;
}

/* det J's degree on a line, at most, whose roots poly_line finds from the polynomial itself. */
#define POLY_LINE_DEG 5

/* The coefficients c[0 .. m - 1] in powers of s of the polynomial through (s[i], y[i]), i < m: Newton's
 * divided differences, then expanded. */
static void poly_through(const double *s, const double *y, int m, double *c)
{
    double dd[POLY_LINE_DEG + 1];
    memcpy(dd, y, (size_t)m * sizeof *dd);
    for (int k = 1; k < m; k++)
        for (int i = m - 1; i >= k; i--)
            dd[i] = (dd[i] - dd[i - 1]) / (s[i] - s[i - k]);
    memset(c, 0, (size_t)m * sizeof *c);
    c[0] = dd[m - 1];
    for (int k = m - 2; k >= 0; k--) {   /* c = c (s - s_k) + dd_k */
        for (int i = m - 1 - k; i >= 1; i--)
            c[i] = c[i - 1] - s[k] * c[i];
        c[0] = dd[k] - s[k] * c[0];
    }
}

typedef struct {
    const double *c;
    int deg;
} qpoly;

static double poly_at(void *arg, double s)
{
    const qpoly *p = arg;
    double v = p->c[p->deg];
    for (int i = p->deg - 1; i >= 0; i--)
        v = v * s + p->c[i];
    return v;
}

/* The points of (0, 1), ascending, where the polynomial c of degree deg changes sign: between its
 * derivative's sign changes (found the same way) it is monotone, so each such piece holds one root at
 * most, bracketed by its ends (Illinois). Returns their number. */
static int poly_roots(const double *c, int deg, double *root)
{
    double e[POLY_LINE_DEG + 2], dc[POLY_LINE_DEG];
    int ne = 1, nr = 0;
    if (deg == 2 && c[2] != 0.0) {   /* in closed form, without cancellation (fig. 3c, 3d: x linear in u) */
        const double disc = c[1] * c[1] - 4.0 * c[2] * c[0];
        if (!(disc > 0.0))
            return 0;   /* no sign change: a double root at most */
        const double h = -0.5 * (c[1] + copysign(sqrt(disc), c[1]));
        double r0 = h / c[2], r1 = h != 0.0 ? c[0] / h : r0;
        if (r0 > r1) {
            const double tmp = r0;
            r0 = r1, r1 = tmp;
        }
        if (r0 > 0.0 && r0 < 1.0)
            root[nr++] = r0;
        if (r1 > 0.0 && r1 < 1.0 && r1 > r0)
            root[nr++] = r1;
        return nr;
    }
    e[0] = 0.0;
    if (deg >= 2) {
        for (int i = 0; i < deg; i++)
            dc[i] = (i + 1) * c[i + 1];
        ne += poly_roots(dc, deg - 1, e + 1);
    }
    e[ne++] = 1.0;
    qpoly p = { c, deg };
    double pa = poly_at(&p, 0.0);
    for (int i = 0; i + 1 < ne; i++) {
        const double pb = poly_at(&p, e[i + 1]);
        if ((pa < 0 && pb > 0) || (pa > 0 && pb < 0))
            root[nr++] = illinois(poly_at, &p, e[i], e[i + 1], pa, pb);
        else if (pb == 0.0 && i + 2 < ne)
            root[nr++] = e[i + 1];   /* on an extreme: a cut there costs nothing */
        pa = pb;
    }
    return nr;
}

/*
 * Along an axis where the solution is a polynomial of degree d (within a slab: poly_degrees), x on a
 * line is a polynomial of degree d and det J one of degree at most 3d - 1 (x_t has degree d - 1, the
 * two other partials d): both are known exactly from their values at the table's points, f and x
 * at t[0 .. n + 1]. So det J's sign changes are found on the polynomial itself (poly_roots, not
 * between samples, where a lobe can hide), and each piece between them is integrated with the rule
 * exact on the integrands (poly_points), from the two polynomials: no factor is evaluated afresh.
 * The line integral is exact to rounding. Returns 0, with nothing added, where this does not apply
 * (not a polynomial axis, or too few points for the degree).
 */
static int poly_line(qctx *q, double a, double b, const double *f, double x[][QX], double wt)
{
    const int d = q->poly[q->k], n = q->n[q->k], deg = 3 * d - 1;
    if (d < 1 || deg > POLY_LINE_DEG || deg + 1 > n + 2)
        return 0;
    const double *t = q->tab[q->k].t;
    double s[POLY_LINE_DEG + 1], y[POLY_LINE_DEG + 1], cj[POLY_LINE_DEG + 1], cx[QX][POLY_LINE_DEG + 1];
    for (int i = 0; i <= deg; i++) {   /* deg + 1 of the n + 2 points, spread from a to b */
        const int at = (i * (n + 1) + deg / 2) / deg;
        s[i] = (t[at] - a) / (b - a), y[i] = f[at];
    }
    poly_through(s, y, deg + 1, cj);
    double root[POLY_LINE_DEG];
    const int nr = poly_roots(cj, deg, root);
    const int sig = (f[0] > 0) | (f[n + 1] > 0) << 1 | nr << 2;
    if (q->line_sig < 0)
        q->line_sig = sig;
    q->line_mixed |= sig != q->line_sig;
    for (int e = 0; e < 2; e++) {   /* the ends' least and largest |det J| (panel_lines) */
        const double fe = fabs(f[e ? n + 1 : 0]);
        q->end_min[e] = fmin(q->end_min[e], fe), q->end_max[e] = fmax(q->end_max[e], fe);
    }
    q->line_roots = nr, q->line_lo = f[0] > q->jtol;
    if (q->mid >= 0) {   /* the periodic path: one signature, no root, on every line of the solid */
        if (q->mid_sig < 0)
            q->mid_sig = sig;
        q->mid_rough |= sig != q->mid_sig || nr;
    }
    if (!nr) {
        const double *gw = rule_w(q, q->k, n);
        for (int i = 0; i < n; i++)
            add_value(q, x[i + 1], f[i + 1], wt * (b - a) * gw[i]);
        return 1;
    }
    const int nx = q->lifted ? QX : 3;   /* a lift's parts of x apart (line_point_lifted): each a polynomial */
    for (int c = 0; c < nx; c++) {
        for (int i = 0; i <= d; i++) {
            const int at = (i * (n + 1) + d / 2) / d;
            s[i] = (t[at] - a) / (b - a), y[i] = x[at][c];
        }
        poly_through(s, y, d + 1, cx[c]);
    }
    const int m = poly_points(d);
    qpoly pj = { cj, deg };
    for (int r = 0; r <= nr; r++) {
        const double s0 = r ? root[r - 1] : 0.0, s1 = r < nr ? root[r] : 1.0;
        for (int i = 0; i < m; i++) {
            const double si = s0 + (s1 - s0) * q->gx[m][i];
            double xi[QX];
            for (int c = 0; c < nx; c++)
                xi[c] = poly_at(&(qpoly){ cx[c], d }, si);
            add_value(q, xi, poly_at(&pj, si), wt * (b - a) * (s1 - s0) * q->gw[m][i]);
        }
    }
    return 1;
}

/*
 * The current line over the panel [a, b]: det J at the ends and the rule's n nodes (the table). Each sign change
 * between neighbours (bracketed from the last value clear of zero) is located, and so is each dip
 * through zero and back between samples (line_dip). Without either, the samples are the rule;
 * else each piece between roots gets its own.
 */
static void line_integrate(qctx *q, double a, double b, double wt)
{
    const int n = q->n[q->k], m = n + 1;
    const double *t = q->tab[q->k].t;   /* a, the rule's nodes, b */
    double f[GMAX + 2], x[GMAX + 2][QX], d[3][3];
    if (q->along == q->k && q->poly[q->k] == 1 && m > 1) {
        /* x linear along the line (fig. 3c, 3d: every factor along u is 1 or u): x and its partials at
         * the ends give them at the rule's nodes, so only the ends take the modes' sums (a line took
         * 45% of fig. 3c's integrals' instructions, five points of them) */
        double de[2][3][3];
        f[0] = line_eval_at(q, 0, x[0], de[0]);
        f[m] = line_eval_at(q, m, x[m], de[1]);
        for (int i = 1; i < m; i++) {
            const double s1 = (t[i] - a) / (b - a), s0 = 1.0 - s1;
            for (int c = 0; c < 3; c++) {
                x[i][c] = s0 * x[0][c] + s1 * x[m][c];
                for (int e = 0; e < 3; e++)
                    d[e][c] = s0 * de[0][e][c] + s1 * de[1][e][c];
            }
            f[i] = det3(d[0], d[1], d[2]);
        }
        q->r.evals += (size_t)m - 1;   /* the work's measure as before: points on lines */
    } else
        for (int i = 0; i <= m; i++)
            f[i] = line_eval_at(q, i, x[i], d);
    if (poly_line(q, a, b, f, x, wt))
        return;
    q->line_mixed = 1;   /* no signature: box_refine refines it */
    q->mid_rough |= q->mid >= 0;   /* (the periodic path's lines are along a polynomial u) */
    double cut[2 * GMAX + 4];
    int ncut = 0, last = 0;
    q->line_roots = 0, q->line_lo = f[0] > q->jtol;
    for (int i = 1; i <= m && off_budget(q); i++) {
        if (sign_changes(f[last], f[i], q->jtol))
            cut[ncut++] = q->count_only ? t[i] : line_root(q, t[last], t[i], f[last], f[i]);
        else if (i < m && fabs(f[i]) <= fabs(f[i - 1]) && fabs(f[i]) < fabs(f[i + 1]) &&
                 fabs(f[i]) > q->jtol && !sign_changes(f[i], f[i + 1], q->jtol)) {
            double at, fat, sign = f[i] > 0 ? 1.0 : -1.0;
            if (line_dip(q, t[i - 1], t[i + 1], sign, &at, &fat)) {
                int l = at > t[i] ? i : i - 1, r = at < t[i] ? i : i + 1;
                if (q->count_only)
                    ncut += 2;
                else {
                    cut[ncut++] = line_root(q, t[l], at, f[l], fat);
                    cut[ncut++] = line_root(q, at, t[r], fat, f[r]);
                }
            }
        }
        if (fabs(f[i]) > q->jtol || fabs(f[last]) <= q->jtol)
            last = i;
    }
    q->line_roots = ncut;
    if (q->count_only)
        return;
    if (!ncut) {
        const double *gw = rule_w(q, q->k, n);
        for (int i = 0; i < n; i++)
            add_value(q, x[i + 1], f[i + 1], wt * (b - a) * gw[i]);
        return;
    }
    double t0 = a;
    for (int c = 0; c < ncut; c++)
        if (cut[c] > t0) {
            line_gauss(q, t0, cut[c], wt);
            t0 = cut[c];
        }
    line_gauss(q, t0, b, wt);
}

/* Polls the caller's stop() once per POLL_WORK factor evaluations. */
static int poll(qctx *q)
{
    if (q->stopped || q->r.evals * q->modes < q->next_poll)
        return q->stopped;
    q->next_poll = q->r.evals * q->modes + POLL_WORK;
    return q->stopped = pde_stopped(q->cancel);
}

/* det J has a certified sign on b, up to jtol. */
static int sign_definite(qctx *q, const pbox *b)
{
    double val, at[3];
    pbox c = *b;
    if (obj_lower(q->s, OBJ_DETJ, 1.0, &c, &val, at) > -q->jtol)
        return 1;
    c = *b;
    return obj_lower(q->s, OBJ_DETJ, -1.0, &c, &val, at) > -q->jtol;
}

/*
 * Along a polynomial axis (q->along), a box's lines all alike (poly_line's signatures) may still
 * straddle a curve where a root of det J leaves the lines through an end, a kink of the line
 * integrals between two lines: so the box counts as smooth only where |det J| at each end stays
 * above ALONG_NEAR of its largest there over the lines (or within jtol of 0 throughout, as on fig. 3's
 * u = 0, where det J = u D(v, w)). On fig. 3c, boxes of lines all alike were 4e-10 off, and the
 * volume 4e-11 off an independent quadrature; 2e-12 now, for 9% more points (fig. 3d: 15%). Bounds
 * of det J on the ends (sign_definite) tell too, but certify few boxes: 2.8 times the instructions.
 */
static int ends_clear(const qctx *q)
{
    for (int e = 0; e < 2; e++)
        if (q->end_max[e] > q->jtol && q->end_min[e] < ALONG_NEAR * q->end_max[e])
            return 0;
    return 1;
}

/*
 * The axis for the lines of a panel where det J may change sign: the one along which the most
 * lines of a 4 x 4 x 4 sample grid cross its zero set, so that the lines cross the zero set
 * rather than run along it; without crossings, the axis det J varies most along.
 */
static int line_axis(qctx *q, const pbox *b)
{
    enum { S = 4 };
    double j[S][S][S];
    if (q->along >= 0)
        return q->along;
    tabs_for(q, b);
    int at[3][S];   /* the table's points nearest (i + 1/2) / S of each axis */
    for (int a = 0; a < 3; a++)
        for (int i = 0; i < S; i++)
            at[a][i] = tab_nearest(q, a, b->lo[a] + (b->hi[a] - b->lo[a]) * (i + 0.5) / S);
    for (int a = 0; a < S; a++)
        for (int c = 0; c < S; c++)
            for (int e = 0; e < S; e++) {
                double d[3][3];
                tab_partials(q, (const int[3]){ at[0][a], at[1][c], at[2][e] }, d);
                j[a][c][e] = det3(d[0], d[1], d[2]);
            }
    double cross[3] = { 0, 0, 0 }, vary[3] = { 0, 0, 0 };
    for (int a = 0; a < S; a++)
        for (int c = 0; c < S; c++)
            for (int e = 0; e + 1 < S; e++) {
                const double d[3][2] = { { j[e][a][c], j[e + 1][a][c] },
                                         { j[a][e][c], j[a][e + 1][c] },
                                         { j[a][c][e], j[a][c][e + 1] } };
                for (int k = 0; k < 3; k++) {
                    cross[k] += sign_changes(d[k][0], d[k][1], q->jtol);
                    vary[k] += fabs(d[k][1] - d[k][0]);
                }
            }
    int k = q->flat == 0 ? 1 : 0;
    for (int a = k + 1; a < 3; a++)
        if (a != q->flat && (cross[a] > cross[k] || (cross[a] == cross[k] && vary[a] > vary[k])))
            k = a;
    return k;
}

/* The lines along axis k through the rule's nodes on the other two axes of b, into acc. */
static void panel_lines(qctx *q, const pbox *b, int k, int definite, double acc[Q_N])
{
    double saved[Q_N];
    memcpy(saved, q->r.acc, sizeof saved);
    memset(q->r.acc, 0, sizeof q->r.acc);
    int i = k == 0 ? 1 : 0, j = k == 2 ? 1 : 2;
    /* A flat axis (q->n 0) is its table's one point, weight 1. */
    const int ni = q->n[i] ? q->n[i] : 1, nj = q->n[j] ? q->n[j] : 1;
    const double hi = q->n[i] ? b->hi[i] - b->lo[i] : 1.0, hj = q->n[j] ? b->hi[j] - b->lo[j] : 1.0;
    const double *wi = q->n[i] ? rule_w(q, i, ni) : (const double[1]){ 1.0 };
    const double *wj = q->n[j] ? rule_w(q, j, nj) : (const double[1]){ 1.0 };
    tabs_for(q, b);
    q->line_sig = -1, q->line_mixed = 0;
    q->end_min[0] = q->end_min[1] = INFINITY, q->end_max[0] = q->end_max[1] = 0.0;
    int idx[3] = { 0, 0, 0 };
    for (int a = 0; a < ni && !poll(q); a++)
        for (int c = 0; c < nj; c++) {
            idx[i] = q->n[i] ? a + 1 : 0, idx[j] = q->n[j] ? c + 1 : 0;
            line_set(q, k, idx);
            double wt = hi * wi[a] * hj * wj[c], before = q->r.acc[Q_VOL];
            if (definite)
                line_gauss_tab(q, wt);
            else {
                line_integrate(q, b->lo[k], b->hi[k], wt);
                q->node_sig[idx[j]] += 2 * q->line_roots + (b->lo[k] == 0.0 && q->line_lo);
            }
            if (q->rows)
                q->rows[c] += (q->r.acc[Q_VOL] - before) / (hj * wj[c]);
        }
    memcpy(acc, q->r.acc, sizeof q->r.acc);
    memcpy(q->r.acc, saved, sizeof saved);
}

/*
 * Where det J may change sign, the line integrals are not smooth across lines that touch its zero
 * set tangentially. So the box's result is checked against the sum over its eight octants, each
 * with lines along its own best axis (in a small box the zero set is nearly flat, and the lines
 * cross it rather than touch it) and a rule sized to it; octants are refined the same way where
 * the two differ by more than 1e-12 of the solid's volume, down to OUTER_DEPTH halvings (FLAT_DEPTH). Lines
 * that all cross the zero set the same number of times do not show that nothing was missed: a
 * narrow lobe of det J near tangency can lie between samples (fig. 4b), so every such panel is
 * refined, within REFINE_PANELS (FLAT_PANELS). Lines along a polynomial axis (q->along) miss no lobe
 * (poly_line): their boxes are quarters, not octants, down to ALONG_DEPTH halvings, and a box whose
 * lines all agree in det J's signs at their ends and number of roots is not refined further.
 */
static void box_refine(qctx *q, const pbox *b, const double coarse[Q_N], int depth, double out[Q_N])
{
    const int saved_n[3] = { q->n[0], q->n[1], q->n[2] };
    pbox sub[8];
    int definite[8], axis[8], nsub[8][3], smooth[8], used[8] = { 0 };
    double part[8][Q_N], fine[Q_N] = { 0 };
    for (int s = 0; s < 8; s++) {
        sub[s] = *b;
        smooth[s] = 1;   /* an octant across the flat axis: none, nothing to add */
        memset(part[s], 0, sizeof part[s]);
        const int keep = q->flat >= 0 ? q->flat : q->along;   /* an axis not split */
        if (keep >= 0 && (s >> keep & 1))
            continue;
        used[s] = 1;
        for (int a = 0; a < 3; a++) {
            if (a == keep) {
                nsub[s][a] = q->n[a] = saved_n[a];
                continue;
            }
            double mid = 0.5 * (b->lo[a] + b->hi[a]);
            if (s >> a & 1)
                sub[s].lo[a] = mid;
            else
                sub[s].hi[a] = mid;
            nsub[s][a] = q->n[a] = rule_points(q->f[a] * (sub[s].hi[a] - sub[s].lo[a]));
        }
        /* Along a polynomial axis, the lines themselves tell (poly_line): no branch and bound (on
         * fig. 3c and 3d it certified no box of a refinement). */
        definite[s] = q->along >= 0 ? 0 : sign_definite(q, &sub[s]);
        axis[s] = definite[s] ? (q->flat == 0 ? 1 : 0) : line_axis(q, &sub[s]);
        panel_lines(q, &sub[s], axis[s], definite[s], part[s]);
        smooth[s] = definite[s] || (q->along >= 0 && !q->line_mixed && ends_clear(q));
        for (int e = 0; e < Q_N; e++)
            fine[e] += part[s][e];
    }
    const int agreed =
        fabs(fine[Q_VOL] - coarse[Q_VOL]) <= 1e-12 * q->vscale && (q->along < 0 || depth >= ALONG_MIN_DEPTH);
    if (depth + 1 >= q->max_depth || q->stopped || q->r.evals * q->modes >= REFINE_WORK || agreed) {
        if (!agreed)
            q->r.refine_left += fabs(fine[Q_VOL] - coarse[Q_VOL]);
        memcpy(out, fine, sizeof fine);
        memcpy(q->n, saved_n, sizeof saved_n);
        return;
    }
    memset(out, 0, Q_N * sizeof *out);
    /* Along a polynomial axis, quarters whose lines all keep one signature are smooth, but not always
     * resolved: where the box has not agreed and every quarter looks smooth, nothing tells the kink
     * between them from a near singularity of the lines' integrals (det J = x_v (u P(w) - Q(w)) where P
     * and Q both nearly vanish: a box that changed by 8.2e-8 left 1.5e-7 off, unreported; P = 0 just
     * beyond a slab of w where the root sweeps the lines, whose rules are sized to the solid's
     * frequencies, not to 1 / P: quarters that changed by 3e-12 each, below the tolerance but above
     * depth, left 1.6e-11 off with 1e-12 reported), so they are halved too, down to ALONG_MIN_DEPTH
     * or agreement, where the halving changed more than 1e-2 of the tolerance (below it, fig. 3c and
     * 3d spent 10 % more instructions for the same volumes to the last bit). Not where only some
     * quarters look smooth: their neighbours hold what changed (halving those too moved fig. 3d
     * 5.7e-9 off, its work's bound spent on them). */
    int all_smooth = q->along >= 0 && fabs(fine[Q_VOL] - coarse[Q_VOL]) > 1e-14 * q->vscale;
    for (int s = 0; s < 8 && all_smooth; s++)
        all_smooth = !used[s] || smooth[s];
    const double left = q->r.refine_left;
    for (int s = 0; s < 8; s++) {
        double o[Q_N];
        if (!used[s] || (smooth[s] && !all_smooth))
            memcpy(o, part[s], sizeof o);
        else {
            memcpy(q->n, nsub[s], sizeof q->n);
            box_refine(q, &sub[s], part[s], depth + 1, o);
        }
        for (int e = 0; e < Q_N; e++)
            out[e] += o[e];
    }
    if (q->along >= 0 && depth + 2 == q->max_depth && q->r.refine_left > left) {   /* the last halving's rate */
        q->along_added += q->r.refine_left - left;
        q->along_change += fabs(fine[Q_VOL] - coarse[Q_VOL]);
    }
    memcpy(q->n, saved_n, sizeof saved_n);
}

/*
 * A row of the face t = 1 (quad_separate, where det J depends on both of its parameters): the strip
 * [lo, hi] of w across the whole range of the face's other parameter s, integrated along lines of s
 * through the w rule's nw nodes (nw 0: the one line at lo, weight 1), each across every panel of s
 * (line_integrate: exact to rounding between located roots). Each line's signature, twice its roots
 * plus 1 where det J starts above 0, goes to q->node_sig at its node's index (1 .. nw; 0 for the line
 * at lo).
 */
static void row_lines(qctx *q, const qplan *p, int sa, double lo, double hi, int nw, double acc[Q_N])
{
    const int saved = q->n[2];
    q->n[2] = nw;
    memset(acc, 0, Q_N * sizeof *acc);
    memset(q->node_sig, 0, sizeof q->node_sig);
    for (int i = 0; i < p->np[sa] && !q->stopped; i++) {
        pbox b = { { 1.0, 1.0, lo }, { 1.0, 1.0, nw ? hi : lo } };
        b.lo[sa] = p->edge[sa][i], b.hi[sa] = p->edge[sa][i + 1];
        double part[Q_N];
        panel_lines(q, &b, sa, 0, part);
        for (int e = 0; e < Q_N; e++)
            acc[e] += part[e];
    }
    q->n[2] = saved;
}

/* The signature of the whole line of s at w (row_lines), its roots counted, not located. */
static int row_sig_at(qctx *q, const qplan *p, int sa, double w)
{
    double acc[Q_N];
    q->count_only = 1;
    row_lines(q, p, sa, w, w, 0, acc);
    q->count_only = 0;
    return q->node_sig[0];
}

static void row_span(qctx *q, const qplan *p, int sa, double lo, double hi, int slo, int shi, int depth,
                     double out[Q_N], double *coarse_vol);

/*
 * A whole line's integral I(w) has no kink where a root crosses a panel's edge of s, only where the
 * line's signature changes: roots meet (a tangency, (w - w*)^(3/2)), leave the face's ends (a jump in
 * I''), or det J changes sign along the whole line (a kink: fig. 2c, det J = u g(w)). row_span locates
 * those points to ROW_EPS and splits the row there; between them, a span whose lines all have the
 * signature s is checked against its two halves along w, each refined the same way where they differ
 * by more than ROW_TOL of the solid's volume, down to ROW_DEPTH halvings. A change of signature among
 * the halves' lines (a lobe between the coarse rule's nodes) sends both halves back to row_span.
 */
static void row_refine(qctx *q, const qplan *p, int sa, double lo, double hi, const double coarse[Q_N], int s,
                       int depth, double out[Q_N])
{
    const double mid = 0.5 * (lo + hi);
    const int nh = axis_points(q, 2, mid - lo);
    double half[2][Q_N], fine[Q_N];
    int changed = 0;
    for (int h = 0; h < 2; h++) {
        row_lines(q, p, sa, h ? mid : lo, h ? hi : mid, nh, half[h]);
        for (int i = 1; i <= nh; i++)
            changed |= q->node_sig[i] != s;
    }
    const int smid = row_sig_at(q, p, sa, mid);
    if ((changed || smid != s) && depth + 1 < ROW_DEPTH_MAX) {
        double o[2][Q_N];
        row_span(q, p, sa, lo, mid, s, smid, depth + 1, o[0], NULL);
        row_span(q, p, sa, mid, hi, smid, s, depth + 1, o[1], NULL);
        for (int e = 0; e < Q_N; e++)
            out[e] = o[0][e] + o[1][e];
        return;
    }
    for (int e = 0; e < Q_N; e++)
        fine[e] = half[0][e] + half[1][e];
    const int agreed = fabs(fine[Q_VOL] - coarse[Q_VOL]) <= ROW_TOL * q->vscale;
    if (agreed || depth + 1 >= ROW_DEPTH || q->stopped || q->r.evals * q->modes >= REFINE_WORK) {
        if (!agreed)
            q->r.refine_left += fabs(fine[Q_VOL] - coarse[Q_VOL]);
        memcpy(out, fine, sizeof fine);
        return;
    }
    double o[2][Q_N];
    row_refine(q, p, sa, lo, mid, half[0], s, depth + 1, o[0]);
    row_refine(q, p, sa, mid, hi, half[1], s, depth + 1, o[1]);
    for (int e = 0; e < Q_N; e++)
        out[e] = o[0][e] + o[1][e];
}

/*
 * The span [lo, hi] of w, whose lines at lo and hi have the signatures slo and shi: its rule's lines
 * (their volume in *coarse_vol, unless NULL), and where the signature changes between two neighbours
 * (ends included), the point where it does, by bisection to ROW_EPS: the span is split there, and
 * each side spanned again (the bracket, ROW_EPS wide, takes its own rule). Where it does not,
 * row_refine.
 */
static void row_span(qctx *q, const qplan *p, int sa, double lo, double hi, int slo, int shi, int depth,
                     double out[Q_N], double *coarse_vol)
{
    const int n = axis_points(q, 2, hi - lo);
    double coarse[Q_N], t[GMAX + 2];
    int sig[GMAX + 2];
    row_lines(q, p, sa, lo, hi, n, coarse);
    if (coarse_vol)
        *coarse_vol = coarse[Q_VOL];
    t[0] = lo, t[n + 1] = hi, sig[0] = slo, sig[n + 1] = shi;
    for (int i = 1; i <= n; i++)
        t[i] = lo + (hi - lo) * q->gx[n][i - 1], sig[i] = q->node_sig[i];
    int i = 0;
    while (i <= n && sig[i] == sig[i + 1])
        i++;
    if (i > n || hi - lo <= 2 * ROW_EPS || depth >= ROW_DEPTH_MAX || !off_budget(q)) {
        if (i <= n || depth >= ROW_DEPTH_MAX)
            memcpy(out, coarse, sizeof coarse);
        else
            row_refine(q, p, sa, lo, hi, coarse, slo, depth, out);
        return;
    }
    double a = t[i], b = t[i + 1];
    int sa_ = sig[i], sb = sig[i + 1];
    while (b - a > ROW_EPS && !q->stopped) {
        const double m = 0.5 * (a + b);
        const int sm = row_sig_at(q, p, sa, m);
        if (sm == sa_)
            a = m;
        else
            b = m, sb = sm;
    }
    double part[3][Q_N];
    memset(part, 0, sizeof part);
    if (a > lo)
        row_span(q, p, sa, lo, a, slo, sa_, depth + 1, part[0], NULL);
    row_lines(q, p, sa, a, b, axis_points(q, 2, b - a), part[1]);
    if (b < hi)
        row_span(q, p, sa, b, hi, sb, shi, depth + 1, part[2], NULL);
    for (int e = 0; e < Q_N; e++)
        out[e] = part[0][e] + part[1][e] + part[2][e];
}

/* The face t = 1 where det J may change sign on it and depends on both of its parameters: row by
 * row of w panels (row_span). */
static void face_rows(qctx *q, const qplan *p, int sa)
{
    int shi = 0, slo = row_sig_at(q, p, sa, p->edge[2][0]);
    for (int l = 0; l < p->np[2] && !q->stopped; l++, slo = shi) {
        const double lo = p->edge[2][l], hi = p->edge[2][l + 1];
        double acc[Q_N];
        shi = row_sig_at(q, p, sa, hi);
        q->r.lined++;
        if (q->r.evals * q->modes < REFINE_WORK) {
            double coarse;
            row_span(q, p, sa, lo, hi, slo, shi, 0, acc, &coarse);
            q->r.refined++;
            q->r.refine_change += fabs(acc[Q_VOL] - coarse);
        } else {
            row_lines(q, p, sa, lo, hi, q->n[2], acc);
            q->r.unrefined++;
        }
        for (int e = 0; e < Q_N; e++)
            q->r.acc[e] += acc[e];
    }
}

/*
 * Where det J does not depend on the face's parameter q->free (quad_sep), its sign on b is its sign
 * on b's segment of w at any one value of it, certified in 1-D (sign_definite), where the bounds
 * close. Where it is not certified, the w-range is halved, down to FREE_DEPTH halvings, then
 * integrated along lines of w through the rule's nodes in the other parameter: each line's
 * integral is exact to rounding (line_integrate), and across lines the integrand is smooth, since
 * det J's roots are the same on every line. No octants, no refinement.
 */
static void free_panel(qctx *q, const pbox *b, int depth, double acc[Q_N])
{
    int definite = -1;
    for (int i = 0; i < q->nseg && definite < 0; i++)
        if (q->seg_lo[i] == b->lo[2] && q->seg_hi[i] == b->hi[2])
            definite = q->seg_def[i];
    if (definite < 0 && q->jsign)
        definite = 1;
    if (definite < 0) {   /* at any one value of the other parameter: 1/2 */
        pbox seg = *b;
        seg.lo[q->free] = seg.hi[q->free] = 0.5;
        definite = sign_definite(q, &seg);
        if (q->nseg < SEG_MEMO)
            q->seg_lo[q->nseg] = b->lo[2], q->seg_hi[q->nseg] = b->hi[2], q->seg_def[q->nseg++] = (unsigned char)definite;
    }
    if (!definite && depth < FREE_DEPTH) {
        const int saved = q->n[2];
        const double mid = 0.5 * (b->lo[2] + b->hi[2]);
        memset(acc, 0, Q_N * sizeof *acc);
        for (int h = 0; h < 2; h++) {
            pbox c = *b;
            double part[Q_N];
            *(h ? &c.lo[2] : &c.hi[2]) = mid;
            q->n[2] = axis_points(q, 2, c.hi[2] - c.lo[2]);
            free_panel(q, &c, depth + 1, part);
            for (int e = 0; e < Q_N; e++)
                acc[e] += part[e];
        }
        q->n[2] = saved;
        return;
    }
    int k = 2;
    if (definite)   /* lines along the axis with the fewer points */
        k = q->n[q->free] < q->n[2] ? q->free : 2;
    else
        q->r.lined++;
    panel_lines(q, b, k, definite, acc);
}

/* A mode of w alone: its factors along u and v are 1. */
static int mode_of_w(const pde_mode *m)
{
    return m->u.kind == PDE_POW && m->u.p == 0.0 && m->v.kind == PDE_POW && m->v.p == 0.0;
}

int quad_same_h(const pde_mode *a, const pde_mode *b)
{
    if (a->nterms != b->nterms || a->nslabs != b->nslabs)
        return 0;
    for (size_t k = 0; a->nslabs > 1 && k <= a->nslabs; k++)
        if (a->breaks[k] != b->breaks[k] || a->first[k] != b->first[k])
            return 0;
    for (size_t k = 0; k < a->nterms; k++) {
        const pde_wterm *x = &a->terms[k], *y = &b->terms[k];
        if (x->alpha != y->alpha || x->beta != y->beta || x->shift != y->shift || x->deg != y->deg)
            return 0;
        for (int i = 0; i <= x->deg; i++)
            if (x->A[i] != y->A[i] || x->B[i] != y->B[i])
                return 0;
    }
    return 1;
}

/*
 * Where det J does not depend on the face's other parameter s (quad_sep's free, with few modes): on
 * the face t = 1 det J = n G(w), and every integrand is |G| (or G) times 1, x_c or x_c x_d with x_c =
 * sum_o F_o(s) H_o(w) over c's modes o (F_o: the mode's factors of t at 1 and of s). So the integrals
 * over s are sums over the modes of exact moments, mom1[o] = int F_o ds and mom2[o][o'] = int F_o
 * F_o' ds (the plan's rule along s, once), and what is left is 1-D in w: per point of w, h and h' of
 * every mode, det J at one s, and a few multiply-adds per pair of modes (free_point). Along w, each
 * panel's samples locate G's sign changes and dips through zero (as line_integrate's), each piece
 * between them takes its own rule, and a panel is checked against its halves (free_span).
 */
#define FREE_MODES 48         /* modes at most for that path: its points cost a multiply-add per pair */
#define FREE_SPAN_DEPTH 12    /* halvings of a w-panel where its halves disagree, at most */
#define FREE_KNOWN 32         /* roots and dips remembered per w-panel */

#define FREE_MEMO 512         /* points of w remembered (a power of 2): ends, halves' ends, pieces */

/* A moment of free_point's sums that is not 0: acc[slot] += mom h[o] (h[p]). */
typedef struct {
    unsigned o, p, slot;
    double mom;
} free_term;

typedef struct {
    qctx *q;
    int flat, free;              /* the face's fixed axis t, and s */
    size_t mt;
    const int *comp;             /* each mode's component */
    double *mom1, *mom2;         /* mt, mt x mt */
    double *da, *ds, *dw;        /* det J's partials' coefficients at s0: F'_t F_s, F_t F'_s, F_t F_s */
    double *h, *dh;              /* mt: the current point's h, h' */
    /* Each distinct h(w) once (wtable: fig. 2 and 4: 3 of 5 modes, each of x's h again in y); mode
     * o's h is hd[tab->map[o]]. */
    wtable *tab;
    double *hd, *dhd;
    /* The moments that are not 0, in free_point's order of (o, p): fig. 2 and 4's products of sin
     * and cos 2 pi v (half of them 0) add nothing, and skipping them leaves every sum as it was. */
    free_term *terms;
    size_t nterms;
    /* Points of w evaluated, by the bits of w (direct-mapped): G and, where had_m, the integrals m.
     * Panels share their ends with their halves and neighbours, and a piece between a root and an
     * end is the same piece in the panel and in its half (fig. 4a: 356 points a call, 300 distinct). */
    double *memo_w, *memo_j, (*memo_m)[Q_N];
    unsigned char *memo_had_m;
    /* The current w-panel's roots of G, and its dip searches' leasts (where G's sign at them), found
     * by its coarse rule: its halves' brackets that hold one take it rather than search again. */
    double root[FREE_KNOWN], dip_at[FREE_KNOWN], dip_f[FREE_KNOWN];
    int nroot, ndip;
    /* Moments about x0 where a component has a mode of w alone (factors 1: its term of x_c is h): its
     * h less x0_c, before any product (a loft 3000 from the origin lost 5.6e-9 of its inertia to
     * moments_about's cancellation after the sums); shift_o[c] = that mode, or -1. */
    long shift_o[3];
    double shift_x[3];
} free_ctx;

static unsigned free_slot(double w)
{
    uint64_t k;
    memcpy(&k, &w, sizeof k);
    k *= 0x9e3779b97f4a7c15u;
    return (unsigned)(k >> 55) & (FREE_MEMO - 1);
}

/* det J at w on the face (at s0), and into m[Q_N] the integrals over s of 1, x_c, x_c x_d at w. */
static double free_point(free_ctx *f, double w, double m[Q_N])
{
    qctx *q = f->q;
    const unsigned at = free_slot(w);
    if (f->memo_w[at] == w && (!m || f->memo_had_m[at])) {
        if (m)
            memcpy(m, f->memo_m[at], sizeof f->memo_m[at]);
        return f->memo_j[at];
    }
    wtable_eval(f->tab, w, f->hd, f->dhd);
    for (size_t o = 0; o < f->mt; o++)
        f->h[o] = f->hd[f->tab->map[o]], f->dh[o] = f->dhd[f->tab->map[o]];
    q->r.evals++;
    double d[3][3] = { { 0 } };
    for (size_t o = 0; o < f->mt; o++) {
        const int c = f->comp[o];
        d[f->flat][c] += f->da[o] * f->h[o], d[f->free][c] += f->ds[o] * f->h[o], d[2][c] += f->dw[o] * f->dh[o];
    }
    const double j = det3(d[0], d[1], d[2]);
    f->memo_w[at] = w, f->memo_j[at] = j, f->memo_had_m[at] = m != NULL;
    if (!m)
        return j;
    for (int c = 0; c < 3; c++)
        if (f->shift_o[c] >= 0)
            f->h[f->shift_o[c]] -= f->shift_x[c];
    for (int e = 0; e < Q_N; e++)
        m[e] = 0.0;
    m[Q_VOL] = 1.0;
    for (size_t i = 0; i < f->nterms; i++) {
        const free_term *t = &f->terms[i];
        m[t->slot] += t->slot < Q_M2 ? t->mom * f->h[t->o] : t->mom * f->h[t->o] * f->h[t->p];
    }
    memcpy(f->memo_m[at], m, sizeof f->memo_m[at]);
    return j;
}

static double free_detj(void *arg, double w)
{
    free_ctx *f = arg;
    f->q->off_evals++;
    return free_point(f, w, NULL);
}

/* Adds |j| wt times m (and j wt to the signed volume) into acc. */
static void free_add(double acc[Q_N], const double m[Q_N], double j, double wt)
{
    const double a = wt * fabs(j);
    for (int e = 0; e < Q_SIGNED; e++)
        acc[e] += a * m[e];
    acc[Q_SIGNED] += wt * j;
}

/* [a, b], a piece of w between G's roots, with a rule sized to it. */
static void free_gauss(free_ctx *f, double a, double b, double acc[Q_N])
{
    const int n = axis_points(f->q, 2, b - a);
    for (int i = 0; i < n; i++) {
        double m[Q_N];
        const double j = free_point(f, a + (b - a) * f->q->gx[n][i], m);
        free_add(acc, m, j, (b - a) * f->q->gw[n][i]);
    }
}

/* G's root in [a, b], where ga and gb have opposite signs: one the panel's coarse rule located
 * inside (a, b), else by Illinois (and remembered). */
static double free_root(free_ctx *f, double a, double b, double ga, double gb)
{
    for (int i = 0; i < f->nroot; i++)
        if (f->root[i] > a && f->root[i] < b)
            return f->root[i];
    const double r = illinois(free_detj, f, a, b, ga, gb);
    if (f->nroot < FREE_KNOWN)
        f->root[f->nroot++] = r;
    return r;
}

struct free_dip_ctx {
    free_ctx *f;
    double sign, stop;
};

static double free_signed(void *arg, double w)
{
    const struct free_dip_ctx *c = arg;
    return c->sign * free_detj(c->f, w);
}

static int free_crossed(void *arg, double a, double b, double x, double fx)
{
    (void)a, (void)b, (void)x;
    return fx < ((const struct free_dip_ctx *)arg)->stop;
}

/* The extreme of sign * G between t0 and t2, from the least sample t1 inside (f1 = sign * G there), by
 * Brent's minimiser (golden section, and parabolic steps where they fall inside): to 1e-9 of t2 - t0
 * as line_dip's golden section, in about a quarter of its points where G is smooth at that scale
 * (fig. 4a's dip of |G| at w = 0.9446, 11.3 deep, took 40); 1 when it crosses 0. */
static int free_dip(free_ctx *f, double t0, double t1, double f1, double t2, double sign, double *at,
                    double *fat)
{
    for (int i = 0; i < f->ndip; i++)
        if (f->dip_at[i] > t0 && f->dip_at[i] < t2) {
            *at = f->dip_at[i], *fat = f->dip_f[i];
            return sign * *fat < -f->q->jtol;
        }
    struct free_dip_ctx c = { f, sign, -f->q->jtol };
    const brent_fn fn = { free_signed, free_crossed, &c };
    double fx;
    const double x = brent_min(&fn, t0, t2, t1, f1, 0.25e-9 * (t2 - t0), 60, &fx);
    *at = x;
    *fat = sign * fx;
    if (f->ndip < FREE_KNOWN)
        f->dip_at[f->ndip] = *at, f->dip_f[f->ndip++] = *fat;
    return fx < c.stop;
}

/* The panel [a, b] of w: G at its ends and rule's nodes, its sign changes and dips located, and each
 * piece between them with its own rule (none: the nodes are the rule). Where *definite is not NULL,
 * a panel whose points all have one sign asks q->wsign for a certificate of it, and 1 into *definite
 * where G's sign is certified, by it or over the whole solid (jsign): then no roots or dips are
 * sought; or where they were, and q->wsign certifies the sign of every piece between them. Returns
 * the roots found. */
static int free_rule(free_ctx *f, double a, double b, int *definite, double acc[Q_N])
{
    qctx *q = f->q;
    const int n = axis_points(q, 2, b - a), m = n + 1;
    double t[GMAX + 2], g[GMAX + 2], mv[GMAX + 2][Q_N], cut[2 * GMAX + 4];
    memset(acc, 0, Q_N * sizeof *acc);
    t[0] = a, t[m] = b;
    for (int i = 1; i <= n; i++)
        t[i] = a + (b - a) * q->gx[n][i - 1];
    for (int i = 0; i <= m; i++)
        g[i] = free_point(f, t[i], i && i < m ? mv[i] : NULL);
    int sure = q->jsign != 0;
    if (!sure && definite && q->wsign) {
        int pos = 0, neg = 0;
        for (int i = 0; i <= m; i++)
            pos |= g[i] > q->jtol, neg |= g[i] < -q->jtol;
        sure = !(pos && neg) && q->wsign->sign(q->wsign->ctx, a, b, g[0], g[m], q->jtol) != 0;
    }
    if (definite)
        *definite = sure;
    int ncut = 0, last = 0;
    for (int i = 0; i <= m && !sure && off_budget(q); i++) {
        /* A least |G| among the samples, the panel's ends included: a lobe next to a panel's edge,
         * where |G| is least, has samples on one side only in each panel. An end counts where |G|
         * grows beyond it too (a sample as far outside, none beyond [0, 1]), not on a slope. */
        int least = fabs(g[i]) > q->jtol && (i == 0 || fabs(g[i]) <= fabs(g[i - 1])) &&
                    (i == m || fabs(g[i]) < fabs(g[i + 1]));
        if (least && (i == 0 || i == m)) {
            const double out = i ? 2 * t[m] - t[m - 1] : 2 * t[0] - t[1];
            least = !(out >= 0.0 && out <= 1.0) || fabs(free_detj(f, out)) > fabs(g[i]);
        }
        if (i && sign_changes(g[last], g[i], q->jtol))
            cut[ncut++] = free_root(f, t[last], t[i], g[last], g[i]);
        else if (least && !(i < m && sign_changes(g[i], g[i + 1], q->jtol))) {
            double at, fat;
            const double sign = g[i] > 0 ? 1.0 : -1.0;
            if (free_dip(f, t[i ? i - 1 : 0], t[i], sign * g[i], t[i < m ? i + 1 : m], sign, &at, &fat)) {
                const int l = at > t[i] ? i : i - 1, r = at < t[i] ? i : i + 1;
                cut[ncut++] = free_root(f, t[l], at, g[l], fat);
                cut[ncut++] = free_root(f, at, t[r], fat, g[r]);
            }
        }
        if (fabs(g[i]) > q->jtol || fabs(g[last]) <= q->jtol)
            last = i;
    }
    if (!ncut) {
        for (int i = 1; i <= n; i++)
            free_add(acc, mv[i], g[i], (b - a) * q->gw[n][i - 1]);
        return 0;
    }
    /* Each piece between roots with its own rule; where q->wsign certifies G's sign on every piece
     * (G = 0 at the roots, about which its models go), no root or lobe was missed, and the panel is as
     * sure as one of one sign (fig. 4a's two panels with a root each: their halves agreed to the bit). */
    int pieces = definite && q->wsign && !q->jsign;
    double t0 = a, g0 = g[0];
    for (int c = 0; c <= ncut; c++) {
        const double t1 = c < ncut ? cut[c] : b;
        if (!(t1 > t0))
            continue;
        free_gauss(f, t0, t1, acc);
        pieces = pieces && q->wsign->sign(q->wsign->ctx, t0, t1, g0, c < ncut ? 0.0 : g[m], q->jtol) != 0;
        t0 = t1, g0 = 0.0;
    }
    if (definite)
        *definite = pieces;
    return ncut;
}

/* [a, b] against its two halves, each refined the same way where they differ by more than ROW_TOL of
 * the volume, down to FREE_SPAN_DEPTH halvings. */
static void free_span(free_ctx *f, double a, double b, const double coarse[Q_N], int depth, double out[Q_N])
{
    qctx *q = f->q;
    const double mid = 0.5 * (a + b);
    double half[2][Q_N];
    free_rule(f, a, mid, NULL, half[0]);
    free_rule(f, mid, b, NULL, half[1]);
    const double fine = half[0][Q_VOL] + half[1][Q_VOL];
    const int agreed = fabs(fine - coarse[Q_VOL]) <= ROW_TOL * q->vscale;
    if (agreed || depth + 1 >= FREE_SPAN_DEPTH || poll(q) || q->r.evals * q->modes >= REFINE_WORK) {
        if (!agreed)
            q->r.refine_left += fabs(fine - coarse[Q_VOL]);
        for (int e = 0; e < Q_N; e++)
            out[e] = half[0][e] + half[1][e];
        return;
    }
    double o[2][Q_N];
    free_span(f, a, mid, half[0], depth + 1, o[0]);
    free_span(f, mid, b, half[1], depth + 1, o[1]);
    for (int e = 0; e < Q_N; e++)
        out[e] = o[0][e] + o[1][e];
}

/* The face t = 1 where G = g(w) (quad_sep's free): 1-D along w, as above. Returns 0 (nothing done)
 * where it has too many modes for the moments of pairs, or out of memory. */
/* A lifted component's mode of w alone (quad_sep's lift): 1, else 0. */
static int lifted_mode(const qctx *q, const quad_sep *sp, int c, size_t o)
{
    return sp->lift[c] && mode_of_w(&q->s->comp[c].modes[o - q->off[c]]);
}

static int free_solid(qctx *q, const qplan *p, const quad_sep *sp, const double x0[3], int shifted[3])
{
    const int flat = sp->axis, sa = sp->free;
    const size_t mt = q->mt;
    if (mt == 0 || mt > FREE_MODES)
        return 0;
    double *buf = malloc((2 * mt * mt + 13 * mt + (2 + Q_N) * FREE_MEMO) * sizeof *buf);
    int *comp = malloc(mt * sizeof *comp);
    free_term *terms = malloc((mt * mt + mt) * sizeof *terms);
    unsigned char *had = malloc(FREE_MEMO);
    wtable *tab = wtable_new(q->s);
    if (!buf || !comp || !terms || !had || !tab) {
        free(buf);
        free(comp);
        free(terms);
        free(had);
        wtable_free(tab);
        return 0;
    }
    free_ctx f = { .q = q, .flat = flat, .free = sa, .mt = mt, .comp = comp, .terms = terms, .memo_had_m = had,
                   .tab = tab };
    for (int c = 0; c < 3; c++) {
        f.shift_o[c] = -1, f.shift_x[c] = x0[c];
        for (size_t m = 0; m < q->s->comp[c].nmodes && f.shift_o[c] < 0; m++)
            if (mode_of_w(&q->s->comp[c].modes[m]))
                f.shift_o[c] = (long)(q->off[c] + m);
        shifted[c] = f.shift_o[c] >= 0;
    }
    f.mom2 = buf, f.mom1 = buf + mt * mt, f.da = f.mom1 + mt, f.ds = f.da + mt, f.dw = f.ds + mt;
    f.h = f.dw + mt, f.dh = f.h + mt;
    double *ft = f.dh + mt, *dft = ft + mt, *fs = dft + mt, *dfs = fs + mt, *abs2 = dfs + mt, *abs1 = abs2 + mt * mt;
    f.hd = abs1 + mt, f.dhd = f.hd + mt;
    f.memo_w = f.dhd + mt, f.memo_j = f.memo_w + FREE_MEMO, f.memo_m = (double(*)[Q_N])(f.memo_j + FREE_MEMO);
    for (size_t i = 0; i < FREE_MEMO; i++)
        f.memo_w[i] = NAN;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < q->s->comp[c].nmodes; m++)
            comp[q->off[c] + m] = c;
    solution_factors(q->s, flat, 1.0, ft, dft);
    /* det J's coefficients at s0 = 1/2: G is the same at every s */
    solution_factors(q->s, sa, 0.5, fs, dfs);
    for (size_t o = 0; o < mt; o++)
        f.da[o] = dft[o] * fs[o], f.ds[o] = ft[o] * dfs[o], f.dw[o] = ft[o] * fs[o];
    /* The moments over s with the plan's panels and rule along it (exact to 1e-14 on five factors). */
    memset(buf, 0, (mt * mt + mt) * sizeof *buf);
    memset(abs2, 0, (mt * mt + mt) * sizeof *abs2);
    for (int i = 0; i < p->np[sa]; i++) {
        const double lo = p->edge[sa][i], h = p->edge[sa][i + 1] - lo;
        const int n = p->n[sa];
        for (int k = 0; k < n; k++) {
            const double wt = h * q->gw[n][k];
            solution_factors(q->s, sa, lo + h * q->gx[n][k], fs, dfs);
            for (size_t o = 0; o < mt; o++) {
                const double a = ft[o] * fs[o];
                f.mom1[o] += wt * a, abs1[o] += wt * fabs(a);
                for (size_t r = 0; r < mt; r++) {
                    const double b = wt * a * ft[r] * fs[r];
                    f.mom2[o * mt + r] += b, abs2[o * mt + r] += fabs(b);
                }
            }
        }
    }
    /* A moment within the rule's error (1e-14 of its factors' size) of 0 is 0, as the integral of
     * sin 2 pi v is: fig. 2 and 4's centroids on the axis and products of inertia about it exact. */
    for (size_t o = 0; o < mt * mt + mt; o++)
        if (fabs(buf[o]) <= 1e-14 * abs2[o])
            buf[o] = 0.0;
    /* free_point's sums, each pair (c <= d) once (o's component first), in the order of (o, p). A
     * lifted component's modes of w alone lack the factor t^n that separable_moments' integral over t
     * counts for their component: k factors t^n integrate to 1 / (n (ns + k)), so such a term's
     * moment is scaled by (ns + k) / (ns + k - its modes of w alone). */
    const double ns = sp->ns;
    for (size_t o = 0; o < mt; o++) {
        const int c = comp[o], lo = lifted_mode(q, sp, c, o);
        if (f.mom1[o] != 0.0)
            terms[f.nterms++] = (free_term){ (unsigned)o, 0, (unsigned)(Q_M1 + c),
                                             f.mom1[o] * (ns + sp->in[c]) / (ns + sp->in[c] - lo) };
        for (size_t r = 0; r < mt; r++) {
            const int cd = comp[r], k = sp->in[c] + sp->in[cd];
            if (cd >= c && f.mom2[o * mt + r] != 0.0)
                terms[f.nterms++] = (free_term){ (unsigned)o, (unsigned)r,
                                                 (unsigned)(Q_M2 + (cd == c ? c : c == 0 ? (cd == 1 ? 3 : 4) : 5)),
                                                 f.mom2[o * mt + r] * (ns + k) /
                                                     (ns + k - lo - lifted_mode(q, sp, cd, r)) };
        }
    }
    for (int l = 0; l < p->np[2] && !poll(q); l++) {
        const double lo = p->edge[2][l], hi = p->edge[2][l + 1];
        double coarse[Q_N], acc[Q_N];
        f.nroot = f.ndip = 0;
        /* G's sign certified on the panel (the whole solid's, or the caller's 1-D models): no root, no
         * dip, and |G| as smooth as G, which the rule integrates (fig. 4a: 3 of its 6 panels) */
        int definite;
        const int roots = free_rule(&f, lo, hi, &definite, coarse);
        if (roots || !definite)   /* det J may change sign: integral_error's 1e-12 stands */
            q->r.lined++;
        if (definite)
            memcpy(acc, coarse, sizeof acc);
        else {
            free_span(&f, lo, hi, coarse, 0, acc);
            q->r.refined++;
            q->r.refine_change += fabs(acc[Q_VOL] - coarse[Q_VOL]);
        }
        for (int e = 0; e < Q_N; e++)
            q->r.acc[e] += acc[e];
    }
    free(buf);
    free(comp);
    free(terms);
    free(had);
    wtable_free(tab);
    return 1;
}

static void panel(qctx *q, const pbox *b)
{
    if (q->free >= 0) {
        double acc[Q_N];
        free_panel(q, b, 0, acc);
        for (int e = 0; e < Q_N; e++)
            q->r.acc[e] += acc[e];
        return;
    }
    const int definite = q->jsign ? 1 : q->along >= 0 ? 0 : sign_definite(q, b);
    int k = 0;
    if (definite) {   /* lines along the axis with the fewest points, the cheapest */
        k = q->flat == 0 ? 1 : 0;
        for (int a = k + 1; a < 3; a++)
            if (a != q->flat && q->n[a] < q->n[k])
                k = a;
    } else {
        k = line_axis(q, b);
        q->r.lined++;
    }
    double acc[Q_N];
    panel_lines(q, b, k, definite, acc);
    /* Refined within a budget: the first REFINE_PANELS panels where det J may change sign. */
    const int smooth = definite || (q->along >= 0 && !q->line_mixed && ends_clear(q));
    if (!smooth && q->r.lined <= q->max_panels && q->r.evals * q->modes < REFINE_WORK) {
        double refined[Q_N];
        box_refine(q, b, acc, 0, refined);
        q->r.refined++;
        q->r.refine_change += fabs(refined[Q_VOL] - acc[Q_VOL]);
        memcpy(acc, refined, sizeof acc);
    } else if (!smooth)
        q->r.unrefined++;
    for (int e = 0; e < Q_N; e++)
        q->r.acc[e] += acc[e];
}

/* The solution's degree along each axis where every factor along it is a polynomial (along w: every
 * term of every h, within each slab of a loft), else -1; -1 too beyond a degree whose integrands'
 * exact rule would need more than GMAX points. */
static void poly_degrees(const pde_solution *s, int deg[3])
{
    deg[0] = deg[1] = deg[2] = 0;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++) {
            const pde_mode *md = &s->comp[c].modes[m];
            const pde_factor fa[2] = { md->u, md->v };
            for (int a = 0; a < 2; a++)
                if (deg[a] >= 0)
                    deg[a] = fa[a].kind != PDE_POW ? -1 : fa[a].p > deg[a] ? (int)fa[a].p : deg[a];
            for (size_t k = 0; k < md->nterms && deg[2] >= 0; k++) {
                const pde_wterm *t = &md->terms[k];
                deg[2] = t->alpha != 0.0 || t->beta != 0.0 ? -1 : t->deg > deg[2] ? t->deg : deg[2];
            }
        }
    for (int a = 0; a < 3; a++)
        if (poly_points(deg[a]) > GMAX)
            deg[a] = -1;
}

/* The fastest change along each axis of a product of `factors` of the solution's factors, in
 * radians over the unit interval; polynomials count by their degree. */
static void frequencies(const pde_solution *s, double factors, double f[3])
{
    f[0] = f[1] = f[2] = 0.0;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++) {
            const pde_mode *md = &s->comp[c].modes[m];
            const pde_factor fa[2] = { md->u, md->v };
            for (int a = 0; a < 2; a++) {
                double v = fa[a].kind == PDE_POW  ? fa[a].p
                           : fa[a].kind == PDE_SIN || fa[a].kind == PDE_COS ? fabs(fa[a].p) * M_PI
                                                                            : fabs(fa[a].p);
                f[a] = fmax(f[a], v);
            }
            for (size_t k = 0; k < md->nterms; k++) {
                const pde_wterm *t = &md->terms[k];
                f[2] = fmax(f[2], hypot(t->alpha, t->beta) + t->deg);
            }
        }
    for (int a = 0; a < 3; a++)
        f[a] = fmax(factors * f[a], 1.0);
}

static int rule_points(double phi)
{
    int n = 3;
    while (n < GMAX && 2 * n * log(M_E * phi / (8.0 * n)) > log(1e-14))
        n++;
    return n;
}

/*
 * Panels and points for an integrand that multiplies `factors` of the solution's factors; exact (a
 * mask of axes): along such an axis where the solution is a polynomial, one panel and the rule exact
 * on the solid's integrands (poly_points). Along w,
 * panels never straddle a slab's break, where h's higher derivatives jump: each slab gets panels of
 * its own, as many as its share of the axis calls for.
 */
static void plan_for(const pde_solution *s, double factors, int exact, qplan *p)
{
    double f[3];
    size_t mt = 1, nslabs;
    for (int c = 0; c < 3; c++)
        mt += s->comp[c].nmodes;
    const double *br = solution_breaks(s, &nslabs);
    frequencies(s, factors, f);
    int want[3], deg[3];
    poly_degrees(s, deg);
    for (int a = 0; a < 3; a++) {
        double v = ceil(f[a] / PANEL_PHASE);   /* then 12 points per panel */
        want[a] = v < 1 ? 1 : v > MAX_PANELS ? MAX_PANELS : (int)v;
        if ((exact >> a & 1) && deg[a] >= 0)
            want[a] = 1;   /* one panel (a slab's, along w), with a rule exact on it */
    }
    /* Bounded work: past MAX_WORK in all, the busiest axis gets fewer, wider panels, and its rule
     * more points, up to GMAX: beyond, the integrals lose digits, which p->err estimates. */
    for (;;) {
        for (int a = 0; a < 3; a++) {
            int np = want[a];
            if (a == 2) {
                np = 0;
                for (size_t k = 0; k < nslabs; k++) {
                    int m = (int)ceil(want[2] * (br[k + 1] - br[k]) - 1e-9);
                    np += m < 1 ? 1 : m;
                }
            }
            p->np[a] = np;
        }
        /* The edges, and each axis's rule from its widest panel. */
        for (int a = 0; a < 3; a++) {
            double widest = 0.0;
            if (a < 2) {
                for (int i = 0; i <= p->np[a]; i++)
                    p->edge[a][i] = (double)i / p->np[a];
            } else {
                int e = 0;
                for (size_t k = 0; k < nslabs; k++) {
                    int m = (int)ceil(want[2] * (br[k + 1] - br[k]) - 1e-9);
                    m = m < 1 ? 1 : m;
                    for (int i = 0; i < m; i++)
                        p->edge[2][e++] = br[k] + (br[k + 1] - br[k]) * i / m;
                }
                p->edge[2][e] = 1.0;
            }
            for (int i = 0; i < p->np[a]; i++)
                widest = fmax(widest, p->edge[a][i + 1] - p->edge[a][i]);
            const int ex = (exact >> a & 1) && deg[a] >= 0;
            p->n[a] = ex ? poly_points(deg[a]) : rule_points(f[a] * widest);
            p->phase[a] = ex ? 0.0 : f[a] * widest;
        }
        if ((double)p->np[0] * p->n[0] * p->np[1] * p->n[1] * p->np[2] * p->n[2] * (double)mt <= MAX_WORK)
            break;
        int a = want[0] * p->n[0] >= want[1] * p->n[1] && want[0] * p->n[0] >= want[2] * p->n[2] ? 0
                : want[1] * p->n[1] >= want[2] * p->n[2] ? 1 : 2;
        if (want[a] == 1)
            break;
        want[a] = (want[a] + 1) / 2;
    }
    /* The rules' asymptotic error on the fastest exp(i f t) of a panel, relative. */
    p->err = 0.0;
    for (int a = 0; a < 3; a++) {
        if (p->phase[a] == 0.0)
            continue;   /* exact */
        double e = 2 * p->n[a] * log(M_E * p->phase[a] / (8.0 * p->n[a]));
        p->err += e < -700 ? 0.0 : fmin(1.0, exp(e));
    }
}

void quad_panels(const pde_solution *s, int np[3], int n[3])
{
    qplan p;
    /* The second moments times det J: five factors. The panels of a solid whose det J may change
     * sign (exact rules along a polynomial axis only once its sign is certified, quad_solid): an
     * estimate made before the properties cannot know which (api/cost.c). */
    plan_for(s, 5.0, 0, &p);
    memcpy(np, p.np, sizeof p.np);
    memcpy(n, p.n, sizeof p.n);
}

/* A context for s with its tables (one allocation), or NULL when out of memory. */
static qctx *qctx_new(const pde_solution *s, const pde_cancel *cancel)
{
    qctx *q = calloc(1, sizeof *q);
    if (!q)
        return NULL;
    for (int c = 0; c < 3; c++)
        q->off[c] = q->mt, q->mt += s->comp[c].nmodes;
    const size_t mt = q->mt ? q->mt : 1, per = (size_t)(GMAX + 2) * mt;
    double *buf = malloc((5 * mt + 6 * per) * sizeof *buf);
    if (!buf) {
        free(q);
        return NULL;
    }
    q->P = buf, q->Pi = buf + mt, q->Pj = buf + 2 * mt, q->g = buf + 3 * mt, q->dg = buf + 4 * mt;
    for (int a = 0; a < 3; a++)
        q->tab[a].val = buf + 5 * mt + 2 * a * per, q->tab[a].der = q->tab[a].val + per;
    q->s = s;
    q->cancel = cancel;
    q->flat = -1;
    q->along = -1;
    q->free = -1;
    q->mid = q->mid_sig = -1;
    q->nseg = 0;
    q->max_depth = OUTER_DEPTH;
    q->max_panels = REFINE_PANELS;
    q->modes = q->mt + 1;
    poly_degrees(s, q->poly);
    pthread_once(&rules_once, rules_init);
    q->gx = (const double(*)[GMAX])rules_x;
    q->gw = (const double(*)[GMAX])rules_w;
    return q;
}

static void qctx_free(qctx *q)
{
    if (q) {
        free(q->P);
        free(q->lifted);
    }
    free(q);
}

/* The Wronskian a b' - b a' of two factors is constant: see quad_sep's free. Sufficient, not
 * necessary: an unrecognised pair only keeps the general path. */
static int wronskian_constant(pde_factor a, pde_factor b)
{
    if ((a.kind == PDE_SIN && a.p == 0.0) || (b.kind == PDE_SIN && b.p == 0.0))
        return 1;   /* a factor 0 */
    if (a.kind == b.kind && a.p == b.p)
        return 1;   /* W(f, f) = 0 */
    if (a.kind == PDE_POW && b.kind == PDE_POW)
        return a.p + b.p == 1.0;   /* W(1, t) = 1 */
    if (a.kind == PDE_EXP && b.kind == PDE_EXP)
        return a.p == -b.p;   /* W = -2 alpha */
    if (a.p != b.p)
        return 0;
    return (a.kind == PDE_SIN && b.kind == PDE_COS) || (a.kind == PDE_COS && b.kind == PDE_SIN) ||
           (a.kind == PDE_SINH && b.kind == PDE_COSH) || (a.kind == PDE_COSH && b.kind == PDE_SINH);
}

/* quad_sep's free: the face's other parameter along which G is constant, or -1 (a lifted component's
 * modes of w alone add nothing to G: not in the Wronskians). */
static int separate_free(const pde_solution *s, const quad_sep *sp)
{
    if (sp->ns != 2)
        return -1;
    const int f = 1 - sp->axis;   /* the face's other parameter, u or v */
    int c1 = -1, c2 = -1;
    for (int c = 0; c < 3; c++) {
        const comp_solution *cs = &s->comp[c];
        if (sp->in[c]) {
            if (c1 < 0)
                c1 = c;
            else
                c2 = c;
            continue;
        }
        for (size_t m = 0; m < cs->nmodes; m++) {
            const pde_factor g = f == 0 ? cs->modes[m].u : cs->modes[m].v;
            if (g.kind != PDE_POW || g.p != 0.0)
                return -1;
        }
    }
    const comp_solution *a = &s->comp[c1], *b = &s->comp[c2];
    for (size_t i = 0; i < a->nmodes; i++)
        for (size_t j = 0; j < b->nmodes; j++)
            if (!mode_of_w(&a->modes[i]) && !mode_of_w(&b->modes[j]) &&
                !wronskian_constant(f == 0 ? a->modes[i].u : a->modes[i].v, f == 0 ? b->modes[j].u : b->modes[j].v))
                return -1;
    return f;
}

/* A lift keeps det J = n t^(n ns - 1) G: with ns = 1 (the two other components have no factor t^n, so
 * their (t, s) minor is 0), or with ns = 2 where the third component is a function of w alone (its row
 * (0, 0, Z')). */
static int lift_keeps_form(const pde_solution *s, const quad_sep *sp)
{
    if (sp->ns == 1)
        return 1;
    if (sp->ns != 2)
        return 0;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; !sp->in[c] && m < s->comp[c].nmodes; m++)
            if (!mode_of_w(&s->comp[c].modes[m]))
                return 0;
    return 1;
}

/* quad_separate, and where lift, components whose modes of w alone (mode_of_w) sit beside modes of
 * t^n: quad_sep's lift, kept where it keeps det J's form (lift_keeps_form). */
static void separate_lifted(const pde_solution *s, int lift, quad_sep *sep)
{
    sep->axis = -1;
    sep->free = -1;
    sep->lift[0] = sep->lift[1] = sep->lift[2] = 0;
    for (int a = 0; a < 2; a++) {
        int n = 0, ok = 1;
        for (int c = 0; c < 3 && ok; c++) {
            const comp_solution *cs = &s->comp[c];
            int kind = -1, of_w = 0;   /* kind -1: no modes yet; 0: every factor 1; else n */
            for (size_t m = 0; m < cs->nmodes && ok; m++) {
                const pde_factor f = a == 0 ? cs->modes[m].u : cs->modes[m].v;
                const int p = f.kind == PDE_POW && f.p == floor(f.p) ? (int)f.p : -1;
                if (lift && mode_of_w(&cs->modes[m])) {
                    of_w = 1;
                    continue;
                }
                if (p < 0 || (kind >= 0 && p != kind) || (p > 0 && n > 0 && p != n))
                    ok = 0;
                kind = p;
            }
            sep->in[c] = kind > 0;
            sep->lift[c] = kind > 0 && of_w;
            if (kind > 0)
                n = kind;
        }
        if (ok && n > 0) {
            sep->axis = a, sep->n = n, sep->ns = sep->in[0] + sep->in[1] + sep->in[2];
            sep->free = separate_free(s, sep);
            if ((sep->lift[0] || sep->lift[1] || sep->lift[2]) && sep->free < 0 && !lift_keeps_form(s, sep)) {
                separate_lifted(s, 0, sep);   /* without: another axis may separate (review: x ~ v, y ~ u + C) */
                return;
            }
            return;
        }
    }
}

void quad_separate(const pde_solution *s, quad_sep *sep)
{
    separate_lifted(s, 0, sep);
}

/* The moments about the origin in acc, about x0 instead. */
static void moments_about(const double x0[3], double acc[Q_N])
{
    const double V = acc[Q_VOL], M1[3] = { acc[Q_M1], acc[Q_M1 + 1], acc[Q_M1 + 2] };
    for (int c = 0; c < 3; c++)
        acc[Q_M1 + c] = M1[c] - x0[c] * V;
    for (int k = 0; k < 6; k++)
        acc[Q_M2 + k] += -x0[m2_i[k]] * M1[m2_j[k]] - x0[m2_j[k]] * M1[m2_i[k]] + x0[m2_i[k]] * x0[m2_j[k]] * V;
}

/*
 * Separable det J (quad_separate): the integrals over the face t = 1 with x0 = 0, in acc, times the
 * exact integrals over t: a product of k of the in[c] components' factors t^n with |det J| = n t^(n
 * ns - 1) |G| integrates to n / (n (ns + k)) against n at t = 1; then the moments about x0.
 */
static void separable_moments(const quad_sep *sp, const double x0[3], double acc[Q_N])
{
    const double n = sp->n;
    acc[Q_VOL] /= n * sp->ns;
    for (int c = 0; c < 3; c++)
        acc[Q_M1 + c] /= n * (sp->ns + sp->in[c]);
    for (int k = 0; k < 6; k++)
        acc[Q_M2 + k] /= n * (sp->ns + sp->in[m2_i[k]] + sp->in[m2_j[k]]);
    acc[Q_SIGNED] /= n * sp->ns;
    moments_about(x0, acc);
}

/*
 * The solid repeats itself along t (u or v) when every component's modes have the factor sin(k pi t)
 * or cos(k pi t) along t, one integer k >= 2 for all, or else the factor 1, the same kind for all of
 * a component's modes: t -> t + 1/k flips the sign of the first kind's components, x -> D x with
 * D = diag(+-1) (fig. 2 and 4: x, y of sin, cos(2 pi v), z of 1, k = 2). When moreover each
 * component's factors are all sin or all cos (or 1), t -> 1/k - t maps the half period [0, 1/2k] onto
 * the other half, with the tangent along t reversed: x -> M x, M = diag(+-1) flipping the components
 * of cos. Returns k (0: none), D in d and M in m (m[0] = 0: no mirror).
 */
static int param_symmetry(const pde_solution *s, int t, int d[3], int m[3])
{
    int k = 0, mirror = 1;
    d[0] = d[1] = d[2] = m[0] = m[1] = m[2] = 1;
    for (int c = 0; c < 3; c++) {
        int kind = -1, parity = -1;   /* kind 0: factors 1, 1: sin, cos of k; parity 1: cos */
        for (size_t i = 0; i < s->comp[c].nmodes; i++) {
            const pde_factor f = t == 0 ? s->comp[c].modes[i].u : s->comp[c].modes[i].v;
            int mk;
            if (f.kind == PDE_POW && f.p == 0.0)
                mk = 0;
            else if ((f.kind == PDE_SIN || f.kind == PDE_COS) && fabs(f.p) >= 2.0 && fabs(f.p) <= 1e6 &&
                     fabs(f.p) == floor(fabs(f.p)) && (k == 0 || fabs(f.p) == k))
                mk = 1, k = (int)fabs(f.p);
            else
                return 0;
            const int mp = f.kind == PDE_COS;   /* cos(pi - a) = -cos a, sin(pi - a) = sin a */
            if (kind >= 0 && mk != kind)
                return 0;
            if (parity >= 0 && mp != parity)
                mirror = 0;
            kind = mk, parity = mp;
        }
        d[c] = kind == 1 ? -1 : 1;
        m[c] = parity == 1 ? -1 : 1;
    }
    if (!mirror)
        m[0] = 0;
    return k;
}

/*
 * A symmetry of the solid along t (u or v): t -> t + 1/k maps x to R x, and where half = 2,
 * t -> 1/k - t maps x to H x (R, H orthogonal). Then one period of t, or half of one, is integrated
 * (moments about the origin), and the copies' integrals follow (sym_moments).
 */
typedef struct {
    int t, k, half;
    double R[3][3], H[3][3];
} qsym;

/* The integrals of a copy x -> A x of the part in `in`, added to out: |det J| the same, the first
 * moments A M1, the second A M2 A^T, det J times sig. */
static void sym_add(const double A[3][3], double sig, const double in[Q_N], double out[Q_N])
{
    static const int at[3][3] = { { 0, 3, 4 }, { 3, 1, 5 }, { 4, 5, 2 } };
    out[Q_VOL] += in[Q_VOL];
    out[Q_SIGNED] += sig * in[Q_SIGNED];
    for (int c = 0; c < 3; c++)
        for (int e = 0; e < 3; e++)
            out[Q_M1 + c] += A[c][e] * in[Q_M1 + e];
    for (int q = 0; q < 6; q++)
        for (int e = 0; e < 3; e++)
            for (int f = 0; f < 3; f++)
                out[Q_M2 + q] += A[m2_i[q]][e] * A[m2_j[q]][f] * in[Q_M2 + at[e][f]];
}

static double det33(const double A[3][3])
{
    return det3(A[0], A[1], A[2]);
}

static void mat_mul(const double A[3][3], const double B[3][3], double C[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[i][j] = A[i][0] * B[0][j] + A[i][1] * B[1][j] + A[i][2] * B[2][j];
}

/*
 * The integrals over one period of t (half of one, mirrored) extended to [0, 1]: the other half is
 * x -> H x with the tangent along t reversed (det J: -det H times), the j-th period x -> R^j x (det J:
 * det R^j times).
 */
static void sym_moments(const qsym *sy, double acc[Q_N])
{
    double period[Q_N] = { 0 }, A[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
    sym_add(A, 1.0, acc, period);
    if (sy->half == 2)
        sym_add(sy->H, -det33(sy->H), acc, period);
    memset(acc, 0, Q_N * sizeof *acc);
    const double dr = det33(sy->R);
    double sig = 1.0;
    for (int j = 0; j < sy->k; j++) {
        sym_add(A, sig, period, acc);
        double B[3][3];
        mat_mul(sy->R, A, B);
        memcpy(A, B, sizeof B);
        sig *= dr;
    }
}

/* x(t + dt) against A x(t) (mirror: x(dt - t)) at 16 points: the largest difference against the
 * largest |x|. */
static double sym_misfit(const pde_solution *s, int t, double dt, int mirror, const double A[3][3])
{
    double worst = 0.0, size = 0.0;
    for (int i = 0; i < 16; i++) {
        double p[3] = { fmod(0.1 + 0.618034 * i, 1.0), fmod(0.3 + 0.414214 * i, 1.0), fmod(0.7 + 0.732051 * i, 1.0) };
        double x[3], y[3];
        pde_eval(s, p[0], p[1], p[2], x);
        p[t] = mirror ? dt - p[t] : p[t] + dt;
        pde_eval(s, p[0], p[1], p[2], y);
        for (int c = 0; c < 3; c++) {
            const double ax = A[c][0] * x[0] + A[c][1] * x[1] + A[c][2] * x[2];
            worst = fmax(worst, fabs(y[c] - ax));
            size = fmax(size, fabs(x[c]));
        }
    }
    return worst / fmax(size, DBL_MIN);
}

/* The integer frequency k >= 1 (in pi) of a factor sin(k pi t) or cos(k pi t), 0 for the factor 1,
 * else -1. */
static int harmonic(pde_factor f)
{
    if (f.kind == PDE_POW && f.p == 0.0)
        return 0;
    if ((f.kind == PDE_SIN || f.kind == PDE_COS) && fabs(f.p) >= 1.0 && fabs(f.p) <= 1e6 && fabs(f.p) == floor(fabs(f.p)))
        return (int)fabs(f.p);
    return -1;
}

/*
 * A rotation along t: two components a, b whose modes all have the factor sin or cos(k pi t) (k >= 1,
 * not one k: fig. 3a's x + i y = i u (H1(w) e^(-2 pi i v) + H2(w) e^(-20 pi i v))), the third's 1 or of
 * frequencies k with k / N even. Then t -> t + 1/N turns x_a + i x_b by phi = +-k0 pi / N when every
 * k is k0 or -k0 modulo 2N: e^(-i k pi t) by e^(-i k pi / N). The largest such N and a sign of phi
 * that the closed form meets at 16 points to 1e-13 (the candidates come from the factors alone; the
 * points decide between them and pair the modes). Mirrored (half = 2) where a's and b's factors are
 * each all sin or all cos, the third's too: t -> -t flips the components of sin, M, and
 * t -> 1/N - t maps x to H = R M. Returns 1 with sy filled, else 0.
 */
static int param_rotation(const pde_solution *s, int t, qsym *sy)
{
    for (int c3 = 0; c3 < 3; c3++) {
        const int a = c3 == 0 ? 1 : 0, b = c3 == 2 ? 1 : 2, comp[3] = { a, b, c3 };
        int ks[64], nk = 0, ok = 1, parity[3] = { -1, -1, -1 };
        for (int i = 0; i < 3 && ok; i++) {
            const comp_solution *cs = &s->comp[comp[i]];
            if (i < 2 && !cs->nmodes)
                ok = 0;
            for (size_t m = 0; m < cs->nmodes && ok; m++) {
                const pde_factor f = t == 0 ? cs->modes[m].u : cs->modes[m].v;
                const int k = harmonic(f), par = f.kind == PDE_SIN;
                if (k < 0 || (i < 2 && k == 0) || (i < 2 && nk == 64))
                    ok = 0;
                else if (i < 2)
                    ks[nk++] = k;
                if (parity[i] >= 0 && parity[i] != par)
                    parity[i] = 2;   /* sin beside cos or 1: no mirror */
                else if (parity[i] < 0)
                    parity[i] = par;
            }
        }
        if (!ok)
            continue;
        int kmax = 0;
        for (int i = 0; i < nk; i++)
            kmax = ks[i] > kmax ? ks[i] : kmax;
        for (int n = kmax + ks[0]; n >= 2; n--) {
            int fits = 1;
            for (int i = 0; i < nk && fits; i++)
                fits = (ks[i] - ks[0]) % (2 * n) == 0 || (ks[i] + ks[0]) % (2 * n) == 0;
            for (size_t m = 0; m < s->comp[c3].nmodes && fits; m++) {
                const pde_factor f = t == 0 ? s->comp[c3].modes[m].u : s->comp[c3].modes[m].v;
                fits = harmonic(f) % (2 * n) == 0;
            }
            if (!fits)
                continue;
            for (int sg = -1; sg <= 1; sg += 2) {
                const double phi = sg * ks[0] * M_PI / n;
                double R[3][3] = { { 0 } };
                R[c3][c3] = 1.0;
                R[a][a] = R[b][b] = cos(phi), R[a][b] = -sin(phi), R[b][a] = sin(phi);
                if (!(sym_misfit(s, t, 1.0 / n, 0, R) <= 1e-13))
                    continue;
                sy->t = t, sy->k = n, sy->half = 1;
                memcpy(sy->R, R, sizeof R);
                if (parity[0] < 2 && parity[1] < 2 && parity[2] < 2) {
                    double M[3][3] = { { 0 } };
                    for (int i = 0; i < 3; i++)
                        M[comp[i]][comp[i]] = parity[i] == 1 ? -1.0 : 1.0;
                    mat_mul(R, M, sy->H);
                    if (sym_misfit(s, t, 1.0 / n, 1, sy->H) <= 1e-13)
                        sy->half = 2;
                }
                return 1;
            }
        }
    }
    return 0;
}

double quad_detj_period(const pde_solution *s, int t, int *mirror)
{
    qsym sy;
    *mirror = 0;
    if (!param_rotation(s, t, &sy))
        return 1.0;
    /* det J(1/N - t) = -det H det J(t): the mirrored half repeats it where det H = -1 */
    *mirror = sy.half == 2 && det33(sy.H) < 0.0;
    return (*mirror ? 0.5 : 1.0) / sy.k;
}

/* The polynomial axis of lowest degree (the fewest pieces per line) along which poly_line applies with
 * its exact rule, or -1. */
static int along_axis(const qctx *q)
{
    int best = -1;
    for (int a = 0; a < 3; a++)
        if (q->poly[a] >= 1 && 3 * q->poly[a] - 1 <= POLY_LINE_DEG && (best < 0 || q->poly[a] < q->poly[best]))
            best = a;
    return best;
}

/*
 * Where every factor along t of every mode is 1 or sin, cos(k pi t) with k even (whole periods over
 * [0, 1]: a loft's profiles), the points of a uniform rule over [0, 1] exact on the solid's integrands
 * wherever det J keeps its sign: each row of det J is one component's, of degree d_c in e^(2 pi i t)
 * (the largest k / 2 of its modes), so det J has degree d_0 + d_1 + d_2 at most and det J r_i r_j
 * 2 max d_c more, and n uniform points integrate a degree below n exactly. 0 where a factor is
 * another, or every one is 1.
 */
static int periodic_points(const pde_solution *s, int t)
{
    int d[3] = { 0, 0, 0 }, top = 0;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++) {
            const int k = harmonic(t == 0 ? s->comp[c].modes[m].u : s->comp[c].modes[m].v);
            if (k < 0 || k % 2 || k > 2 * GMAX * MAX_PANELS)
                return 0;
            d[c] = k / 2 > d[c] ? k / 2 : d[c];
        }
    for (int c = 0; c < 3; c++)
        top = d[c] > top ? d[c] : top;
    return top ? d[0] + d[1] + d[2] + 2 * top + 1 : 0;
}

/*
 * The estimated error of the n-point Gauss-Legendre rule on f, sampled at its nodes, over [0, 1]: it
 * integrates f's Legendre expansion exactly up to degree 2n - 1, and f (a row of the periodic path,
 * analytic within a slab: det J keeps its sign) has coefficients that fall geometrically, at the rate
 * r per degree, from a_(n - 1) on. r^2 is taken as the slower of the ratios of the pairs (a_(n-1),
 * a_(n-2)), (a_(n-3), a_(n-4)), (a_(n-5), a_(n-6)) (pairs: even and odd parts may fall apart), and
 * the error as the last pair times r^(n + 1); where they do not fall (r >= 1: the rule does not
 * resolve f), the last pair itself, as legendre_tail. Coefficients below rounding (1e-16 of the
 * largest value) count as that, so that noise reads as no decay.
 */
static double mid_tail(const qctx *q, const double *f, int n)
{
    if (n < MID_POINTS)
        return INFINITY;   /* too few coefficients to see a decay (not on the periodic path's rules) */
    double a[6] = { 0 }, top = 0.0;
    for (int i = 0; i < n; i++) {
        const double y = 2.0 * q->gx[n][i] - 1.0;
        double p0 = 1.0, p1 = y;
        for (int k = 2; k < n; k++) {
            const double p2 = ((2 * k - 1) * y * p1 - (k - 1) * p0) / k;
            p0 = p1, p1 = p2;
            if (k >= n - 6)
                a[n - 1 - k] += (2 * k + 1) * q->gw[n][i] * p1 * f[i];
        }
        top = fmax(top, fabs(f[i]));
    }
    double t[3];
    for (int j = 0; j < 3; j++)
        t[j] = fmax(fabs(a[2 * j]) + fabs(a[2 * j + 1]), 1e-16 * top);
    const double r2 = fmax(t[0] / t[1], t[1] / t[2]);
    return r2 >= 1.0 ? t[0] : t[0] * pow(r2, 0.5 * (n + 1));
}

/*
 * The rows' tails see only what w's rule samples: a boundary layer narrower than its points' spacing
 * (exp(-6000 w) beside panels of 1/16) passes between them unseen. So every term of h whose bound on
 * the panel [a, b] (its coefficients times its exponential's largest value there) is above MID_AMP of
 * the largest term's must change by a factor e at most, or a radian, between the n points: its rate
 * hypot(alpha, beta) + deg times (b - a) / n at most MID_SPACING. Returns the largest such term's share
 * that does not (0: every one does).
 */
static double mid_unsampled(const qctx *q, double a, double b, int n)
{
    size_t nslabs;
    const double *br = solution_breaks(q->s, &nslabs);
    size_t sl = 0;
    while (sl + 1 < nslabs && br[sl + 1] <= 0.5 * (a + b))
        sl++;
    double top = 0.0, worst = 0.0;
    for (int pass = 0; pass < 2; pass++)   /* the largest term's bound, then the terms against it */
        for (int c = 0; c < 3; c++)
            for (size_t m = 0; m < q->s->comp[c].nmodes; m++) {
                const pde_mode *md = &q->s->comp[c].modes[m];
                for (size_t k = md->first[sl]; k < md->first[sl + 1]; k++) {
                    const pde_wterm *t = &md->terms[k];
                    double coef = 0.0;
                    for (int i = 0; i <= t->deg; i++)
                        coef += fabs(t->A[i]) + fabs(t->B[i]);
                    const double amp = coef * exp(t->alpha * ((t->alpha > 0 ? b : a) - t->shift));
                    if (!pass)
                        top = fmax(top, amp);
                    else if (amp > MID_AMP * top && (hypot(t->alpha, t->beta) + t->deg) * (b - a) > MID_SPACING * n)
                        worst = fmax(worst, amp / top);
                }
            }
    return worst;
}

/*
 * The periodic path's panel b (the whole period of v, a panel of w): lines along u (poly_line where
 * det J may change sign, else the tensor rule), the volume of w's rows at its nodes collected. Along v
 * the rule is exact (periodic_points) where every line has one signature and no root (else quad_solid
 * goes back to the general path); along w, where the rows' Legendre tail (their last two coefficients,
 * legendre_tail) times the panel's width exceeds MID_TOL of the solid's volume, the panel is halved,
 * down to MID_DEPTH halvings within REFINE_WORK. The tails left are the error's estimate (mid_err):
 * pessimistic, as the rule integrates twice the degree of those coefficients.
 */
static void mid_panel(qctx *q, const pbox *b, int depth, double acc[Q_N])
{
    double rows[GMAX];
    const int n = q->n[2];
    memset(rows, 0, sizeof rows);
    q->rows = rows;
    panel_lines(q, b, 0, q->jsign != 0, acc);
    q->rows = NULL;
    const double h = b->hi[2] - b->lo[2], unseen = mid_unsampled(q, b->lo[2], b->hi[2], n);
    double est = h * mid_tail(q, rows, n);
    if ((est <= MID_TOL * q->vscale && !unseen) || depth >= MID_DEPTH || q->stopped ||
        q->r.evals * q->modes >= REFINE_WORK) {
        if (unseen) {   /* what the rule may have missed: the term's share of the panel's volume, at least */
            double top = 0.0;
            for (int i = 0; i < n; i++)
                top = fmax(top, fabs(rows[i]));
            est = fmax(est, h * top * fmax(unseen, 1e-6));
        }
        q->mid_err += est;
        return;
    }
    const double mid = 0.5 * (b->lo[2] + b->hi[2]);
    q->n[2] = axis_points(q, 2, 0.5 * h) > MID_POINTS ? axis_points(q, 2, 0.5 * h) : MID_POINTS;
    memset(acc, 0, Q_N * sizeof *acc);
    for (int k = 0; k < 2; k++) {
        pbox c = *b;
        double part[Q_N];
        *(k ? &c.lo[2] : &c.hi[2]) = mid;
        mid_panel(q, &c, depth + 1, part);
        for (int e = 0; e < Q_N; e++)
            acc[e] += part[e];
    }
    q->n[2] = n;
}

/*
 * Lobes of det J along w narrower than the plan's nodes. Where det J's sign is not certified and it
 * does not separate (the general path), its lines run along u or v and its boxes' rules sample w at
 * their nodes: a lobe between two nodes (det J through 0 and back) is in none of them, nor in the
 * quarters' nodes when it is narrower still, and the refinement, agreeing with itself, says nothing
 * (random fig. 4-like solids whose y or z has a term of w alone, or t^n and t^(n+1): volumes 2e-6 and
 * 7e-6 off with an error of 4e-7 and 4e-6 reported). So LOBE_COLS^2 columns of (u, v) sample det J at
 * the plan's nodes along w; where |det J| has a least among them below half the column's largest,
 * Brent's search for a crossing of 0 (free_dip's), and a lobe found adds its two roots to w's edges:
 * the boxes then have the lobe's zero set at their faces (where it is a plane w = const, as there,
 * each box keeps one sign) or within one box's span of w, whose nodes sample it.
 */
#define LOBE_COLS 4
static const double lobe_at[LOBE_COLS] = { 1.0 / 64, 1.0 / 3, 2.0 / 3, 63.0 / 64 };

typedef struct {
    const pde_solution *s;
    double u, v, sign, stop;
    size_t evals;
} lobe_col;

static double lobe_detj(void *arg, double w)
{
    lobe_col *c = arg;
    double x[3], d[3][3];
    c->evals++;
    pde_eval_d(c->s, c->u, c->v, w, x, d[0], d[1], d[2]);
    return det3(d[0], d[1], d[2]);
}

static double lobe_signed(void *arg, double w)
{
    const lobe_col *c = arg;
    return c->sign * lobe_detj(arg, w);
}

static int lobe_crossed(void *arg, double a, double b, double x, double fx)
{
    (void)a, (void)b, (void)x;
    return fx < ((const lobe_col *)arg)->stop;
}

/* det J vanishes at w on every column (to 1e-9 of |det J| at w +- 1e-3 there): a zero set w = const. */
static int lobe_planar(lobe_col *c, double w, double jtol)
{
    lobe_col o = *c;
    for (int cu = 0; cu < LOBE_COLS; cu++)
        for (int cv = 0; cv < LOBE_COLS; cv++) {
            o.u = lobe_at[cu], o.v = lobe_at[cv];
            const double near = fmax(fabs(lobe_detj(&o, fmax(w - 1e-3, 0.0))), fabs(lobe_detj(&o, fmin(w + 1e-3, 1.0))));
            if (!(fabs(lobe_detj(&o, w)) <= fmax(1e-9 * near, jtol)))   /* NaN: not planar */
                return c->evals += o.evals - c->evals, 0;
        }
    c->evals = o.evals;
    return 1;
}

/* A root found already (on another column) in (a, b): that lobe's or plane's. */
static int lobe_known(const double *add, int na, double a, double b)
{
    for (int i = 0; i < na; i++)
        if (add[i] > a && add[i] < b)
            return 1;
    return 0;
}

/*
 * The sign change of c's det J on [*a, *b] (values *fa, *fb) narrowed past the roots found already
 * inside it: 0 where one of them is c's own (|det J| there below 1e-6 of the ends'), else 1 with the
 * bracket between two of them, or one and an end, where the sign changes. Two planes in one interval
 * of the samples (f058 of the review's family: Q = 0 and P = Q 3.2e-4 apart in w, the root crossing
 * every line along u between them) are two edges, where lobe_known kept the first alone (3.7e-7 off
 * with 2.9e-9 reported).
 */
static int lobe_bracket(lobe_col *c, const double *add, int na, double *a, double *fa, double *b, double *fb)
{
    const double zero = 1e-6 * fmax(fabs(*fa), fabs(*fb));
    double lo = *a, flo = *fa;
    for (;;) {
        double e = *b;   /* the nearest known root above lo */
        for (int i = 0; i < na; i++)
            if (add[i] > lo && add[i] < e)
                e = add[i];
        if (e == *b)
            break;
        const double fe = lobe_detj(c, e);
        if (!(fabs(fe) > zero))   /* c's own (NaN: as known) */
            return 0;
        if ((fe < 0) != (flo < 0)) {
            *b = e, *fb = fe;
            break;
        }
        lo = e, flo = fe;
    }
    *a = lo, *fa = flo;
    return 1;
}

/*
 * A lobe at the sample k of c's column (values f at t, ns of them, largest |f| top): where |f[k]| is a
 * least of its neighbours' below half of top and above zero, and they keep its sign, Brent's search
 * between them for a crossing of c->stop; found, its two roots into r. Returns 1 if found.
 */
static int lobe_dip(lobe_col *c, const double *t, const double *f, int ns, int k, double top, double zero,
                    const double *add, int na, double r[2])
{
    const int a = k > 0 ? k - 1 : 0, b = k + 1 < ns ? k + 1 : ns - 1;
    if (!(fabs(f[k]) <= fabs(f[a]) && fabs(f[k]) <= fabs(f[b]) && fabs(f[k]) < 0.5 * top) ||
        fabs(f[k]) <= zero || (f[a] < 0) != (f[k] < 0) || (f[b] < 0) != (f[k] < 0) ||
        lobe_known(add, na, t[a], t[b]))
        return 0;
    c->sign = f[k] < 0 ? -1.0 : 1.0;
    const int end = a == k || b == k;   /* a least at w = 0 or 1: from the middle of its interval */
    const double x0 = end ? 0.5 * (t[a] + t[b]) : t[k];
    const brent_fn fn = { lobe_signed, lobe_crossed, c };
    double fx;
    const double x = brent_min(&fn, t[a], t[b], x0, end ? lobe_signed(c, x0) : c->sign * f[k],
                               0.25e-9 * (t[b] - t[a]), 60, &fx);
    if (!(fx < c->stop))
        return 0;
    r[0] = illinois(lobe_detj, c, t[a], x, f[a], c->sign * fx);
    r[1] = illinois(lobe_detj, c, x, t[b], c->sign * fx, f[b]);
    return 1;
}

/* qsort's order of doubles (lobe_edges' edges, fold_row's roots) */
static int double_cmp(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/*
 * The faces u, v = 0, 1. A line along t (u or v) is integrated exactly between its located roots, and
 * across lines its integral is smooth but where a root of det J leaves the line through an end: at
 * t = 0, where det J's lowest term in t vanishes, or at t = 1, where det J does: the line integrals go
 * as s |s| there (a jump of their second derivative), which the boxes' halvings in the two other axes
 * converge to slowly, and which a box whose lines all have one root takes for smooth. Where that zero
 * set is a plane w = const (det J = x_v(v, w) (u P(w) - Q(w)): at Q = 0 and P = Q), it becomes an edge
 * of w, and every box keeps it at a face. The review's x = v X(w) + v^2 X2(w), y = u A(w) + C(w), z = u
 * B(w) (tests/test_props.c): 4.2e-9 off with 5.3e-11 reported, and halving deeper changed nothing; now
 * 5e-15 off. Each face t = 0 is sampled at t = 2^-40 (det J's lowest term where det J is 0 at t = 0:
 * its root within ~1e-12 of the plane), along w at the plan's nodes on LOBE_COLS columns of the face's
 * other parameter; a root on one is kept where every column's |det J| there is below 1e-6 of its own at
 * w +- 1e-3 (a plane to ~1e-9 in w). Returns na.
 */
#define END_T 0x1p-40

/* c's det J vanishes at w on every column of its face (other: the column's parameter, back to col's) */
static int end_planar(lobe_col *c, double *other, int col, double w)
{
    int planar = 1;
    for (int o = 0; o < LOBE_COLS && planar; o++) {
        *other = lobe_at[o];
        const double near = fmax(fabs(lobe_detj(c, fmax(w - 1e-3, 0.0))), fabs(lobe_detj(c, fmin(w + 1e-3, 1.0))));
        planar = fabs(lobe_detj(c, w)) <= 1e-6 * near;   /* NaN: not planar */
    }
    *other = lobe_at[col];
    return planar;
}

static int end_planes(lobe_col *c, const double *t, double *f, int ns, double *add, int na, int max)
{
    for (int a = 0; a < 2; a++)
        for (int e = 0; e < 2; e++)
            for (int col = 0; col < LOBE_COLS && na < max; col++) {
                double *at = a == 0 ? &c->u : &c->v, *other = a == 0 ? &c->v : &c->u;
                *at = e ? 1.0 : END_T, *other = lobe_at[col];
                double top = 0.0;
                for (int k = 0; k < ns; k++)
                    f[k] = lobe_detj(c, t[k]), top = fmax(top, fabs(f[k]));
                const double zero = 1e-13 * top;
                c->stop = -zero;   /* lobe_dip's: a pair through the face between two samples (f059: P = Q twice, 0.02 apart) */
                for (int k = 0; k < ns && na < max; k++) {
                    double r[2], lo = t[k], flo = f[k], hi = t[k + (k + 1 < ns)], fhi = f[k + (k + 1 < ns)];
                    int nr = 0;
                    if ((flo < 0) != (fhi < 0) && fabs(flo) > zero && fabs(fhi) > zero &&
                        lobe_bracket(c, add, na, &lo, &flo, &hi, &fhi))
                        r[nr++] = illinois(lobe_detj, c, lo, hi, flo, fhi);
                    if (!nr && na + 2 <= max && lobe_dip(c, t, f, ns, k, top, zero, add, na, r))
                        nr = 2;
                    for (int i = 0; i < nr; i++)
                        if (end_planar(c, other, col, r[i]))
                            add[na++] = r[i];
                }
            }
    return na;
}

/* The lobes' roots into p's edges along w, MAX_EDGES at most. */
static void lobe_edges(qctx *q, qplan *p)
{
    const int np = p->np[2], n = p->n[2], ns = np * (n + 1) + 1;
    double *t = malloc(2 * (size_t)ns * sizeof *t), add[MAX_EDGES];
    if (!t)
        return;
    double *f = t + ns;
    for (int l = 0, k = 0; l < np; l++) {
        const double lo = p->edge[2][l], h = p->edge[2][l + 1] - lo;
        t[k++] = lo;
        for (int i = 0; i < n; i++)
            t[k++] = lo + h * q->gx[n][i];
    }
    t[ns - 1] = 1.0;
    int na = 0;
    lobe_col c = { .s = q->s, .stop = -q->jtol };
    for (int cu = 0; cu < LOBE_COLS; cu++)
        for (int cv = 0; cv < LOBE_COLS && na + 2 <= MAX_EDGES - np; cv++) {
            c.u = lobe_at[cu], c.v = lobe_at[cv];
            double top = 0.0;
            for (int k = 0; k < ns; k++)
                f[k] = lobe_detj(&c, t[k]), top = fmax(top, fabs(f[k]));
            for (int k = 0; k + 1 < ns && na + 1 <= MAX_EDGES - np; k++) {   /* roots seen, where planar */
                double a = t[k], fa = f[k], b = t[k + 1], fb = f[k + 1];
                if ((fa < 0) == (fb < 0) || fabs(fa) <= q->jtol || fabs(fb) <= q->jtol ||
                    !lobe_bracket(&c, add, na, &a, &fa, &b, &fb))
                    continue;
                const double r = illinois(lobe_detj, &c, a, b, fa, fb);
                if (lobe_planar(&c, r, q->jtol))
                    add[na++] = r;
            }
            for (int k = 0; k < ns && na + 2 <= MAX_EDGES - np; k++)
                na += 2 * lobe_dip(&c, t, f, ns, k, top, q->jtol, add, na, add + na);
        }
    na = end_planes(&c, t, f, ns, add, na, MAX_EDGES - np);
    q->r.evals += c.evals;
    free(t);
    if (!na)
        return;
    /* among the edges, which stay (a slab's break among them); a root within 1e-9 of one, or not finite
     * (det J NaN), is dropped */
    double *e = p->edge[2];
    int m = np + 1;
    for (int i = 0; i < na; i++) {
        int near = !(add[i] > 0.0 && add[i] < 1.0);
        for (int k = 0; k < m && !near; k++)
            near = fabs(add[i] - e[k]) <= 1e-9;
        if (!near)
            e[m++] = add[i];
    }
    qsort(e, (size_t)m, sizeof *e, double_cmp);
    p->np[2] = m - 1;
}

static pde_status solid_run(const pde_solution *s, const double x0[3], double jscale, double vscale, int separate,
                            int jsign, const quad_wsign *ws, const pde_cancel *cancel, int periodic, quad_result *out,
                            int *rough)
{
    qctx *q = qctx_new(s, cancel);
    if (!q)
        return PDE_ERR_NOMEM;
    q->wsign = ws;
    quad_sep sp = { .axis = -1, .free = -1 };
    if (separate) {
        /* A lift (quad_sep's) on the free path, and on the face's other paths where det J may change
         * sign, where the cube's boxes did worse than the face's (a centre C(w) beside x = u (X1 cos 3 pi
         * v + X2 sin 6 pi v): 5.4e-9 off with 3.8e-8 reported; now its twin's without C, 1.2e-12 off).
         * Where det J's sign is certified, the cube's tensor rules are exact (fig. 1), or a loft's
         * uniform rule along v (the periodic path below). */
        separate_lifted(s, 1, &sp);
        if ((sp.lift[0] || sp.lift[1] || sp.lift[2]) && jsign && !(separate == 1 && sp.free >= 0 && q->mt <= FREE_MODES))
            separate_lifted(s, 0, &sp);
    }
    const int lifted = sp.axis >= 0 && (sp.lift[0] || sp.lift[1] || sp.lift[2]);
    q->free = separate == 1 ? sp.free : -1;
    if (lifted) {   /* the face's paths (free_solid has its own moments): add_value's lifted terms */
        if (!(q->lifted = calloc(q->mt, 1))) {
            qctx_free(q);
            return PDE_ERR_NOMEM;
        }
        const double ns = sp.ns;
        for (int c = 0; c < 3; c++) {
            for (size_t m = 0; sp.lift[c] && m < s->comp[c].nmodes; m++)
                q->lifted[q->off[c] + m] = (unsigned char)mode_of_w(&s->comp[c].modes[m]);
            /* a term with k factors t^n integrates to 1 / (n (ns + k)) (separable_moments), one with j of
             * them lifted (a mode of w alone in place of t^n X_c) to 1 / (n (ns + k - j)) */
            q->lift1[c] = sp.lift[c] ? (ns + 1) / ns : 0.0;
            q->lift_x0[c] = sp.lift[c] ? x0[c] : 0.0;
        }
        for (int k = 0; k < 6; k++) {
            const int in = sp.in[m2_i[k]] + sp.in[m2_j[k]];
            q->lift_xl[k] = in >= 1 ? (ns + in) / (ns + in - 1) : 0.0;
            q->lift_ll[k] = in >= 2 ? (ns + in) / (ns + in - 2) : 0.0;
        }
    }
    q->jtol = 1e-13 * jscale;
    q->vscale = vscale;
    q->jsign = jsign;
    /* One exact panel along a polynomial axis. In 3-D where det J may change sign, lines along such
     * an axis are exact (poly_line), but across lines their integrals are not polynomials (where
     * roots enter or leave the line): so only the axis the lines run along (along_axis) is exact,
     * the others stay sized to the frequencies. Not over the cube (separate 0, the tests' general
     * path): where det J = t G (fig. 2c, 4), whole lines along t flip sign where G does, a kink |G|
     * of the line integrals, to which the 2-D refinement converges slowly (fig. 2c: 2e-5 off). */
    const int along = separate && sp.axis < 0 && !jsign ? along_axis(q) : -1;
    qplan p;
    plan_for(s, 5.0, jsign != 0 || sp.axis >= 0 ? 7 : along >= 0 ? 1 << along : 0, &p);
    if (along >= 0) {   /* every panel where det J may change sign refined in 2-D, deeper */
        q->along = along;
        q->max_depth = ALONG_DEPTH;
        q->max_panels = ALONG_PANELS;
    }
    if (sp.axis >= 0) {   /* the face t = 1 alone: one panel along the flat axis, no rule */
        q->flat = sp.axis;
        q->max_depth = FLAT_DEPTH;
        q->max_panels = FLAT_PANELS;
        p.np[sp.axis] = 1, p.n[sp.axis] = 0;
        p.edge[sp.axis][0] = p.edge[sp.axis][1] = 1.0;
    } else
        memcpy(q->x0, x0, sizeof q->x0);
    /* The periodic path: v's panels side by side make one uniform rule over the period, exact
     * (periodic_points); the lines along u exact where det J may change sign (poly_line); w's panels
     * refined by their rows' tails (mid_panel). Within MAX_WORK, else the general path. Only where
     * det J's sign is certified (jsign): lines along u see no fold of a loft (det J = u D1(v, w)), and
     * the rule's nodes along v none between them (review: an epicycle loft's lobes fell between its 9
     * nodes; its volume came out as its signed volume, 5% low, with an err of 3e-16). */
    const int nv = periodic && sp.axis < 0 && jsign ? periodic_points(s, 1) : 0;
    const int pv = (nv + GMAX - 1) / GMAX, mv = pv ? (nv + pv - 1) / pv : 0;
    const int nw = p.n[2] > MID_POINTS ? p.n[2] : MID_POINTS;
    const double wpoints = (double)p.np[2] * nw;
    if (nv && pv <= MAX_PANELS &&
        (double)p.np[0] * p.n[0] * pv * mv * wpoints * (double)(q->mt + 1) <= MAX_WORK) {
        q->mid = 1;
        p.np[1] = pv, p.n[1] = mv, p.n[2] = nw, p.phase[1] = p.phase[2] = 0.0;
        for (int i = 0; i <= pv; i++)
            p.edge[1][i] = (double)i / pv;
        p.err = 0.0;   /* u's rule: exact along u (the lines' polynomial, or its tensor rule's degree) */
        if (p.phase[0] != 0.0) {
            const double e = 2 * p.n[0] * log(M_E * p.phase[0] / (8.0 * p.n[0]));
            p.err = e < -700 ? 0.0 : fmin(1.0, exp(e));
        }
    }
    if (sp.axis < 0 && !jsign && q->mid < 0 && q->along != 2)   /* lines along w see them */
        lobe_edges(q, &p);
    memcpy(q->n, p.n, sizeof p.n);
    q->r.err = p.err;
    frequencies(s, 5.0, q->f);
    /* Where det J separates (moments about the origin), one period of a parameter along which the
     * solid repeats itself, or half of one mirrored: the rest by symmetry (sym_moments). A reflection
     * or half-turn (param_symmetry) where the period is a whole number of panels; else, where the face
     * is integrated by rows (face_rows), a rotation (param_rotation), with the period's own panels. */
    /* G = g(w): 1-D along w over the whole face, no period needed */
    int shifted[3] = { 0, 0, 0 };   /* components whose moments were taken about x0 */
    const int one_d = q->free >= 0 && free_solid(q, &p, &sp, x0, shifted);
    for (int c = 0; c < 3 && !one_d; c++)   /* the face's paths: the lifted components (add_value) */
        shifted[c] = sp.lift[c] && sp.axis >= 0;
    qsym sy = { .k = 0 };
    const int folds = sp.axis >= 0 && q->free < 0 && !jsign;   /* on the face, G depending on both */
    for (int t = 0; t < 2 && sp.axis >= 0 && separate != 3 && !sy.k && !one_d; t++) {
        int sd[3], sm[3], per;
        if (t != sp.axis && (per = param_symmetry(s, t, sd, sm)) > 1 && p.np[t] % per == 0) {
            sy = (qsym){ .t = t, .k = per, .half = sm[0] && p.np[t] % (2 * per) == 0 ? 2 : 1 };
            for (int c = 0; c < 3; c++)
                sy.R[c][c] = sd[c], sy.H[c][c] = sm[c];
            p.np[t] /= per * sy.half;
        }
    }
    if (folds && !sy.k && separate != 3 && param_rotation(s, 1 - sp.axis, &sy)) {   /* its own panels */
        const int t = sy.t, per = sy.k * sy.half;
        p.np[t] = (p.np[t] + per - 1) / per;
        for (int i = 0; i <= p.np[t]; i++)
            p.edge[t][i] = (double)i / (p.np[t] * per);
    }
    if (sy.k)   /* the tolerances of the part integrated: its copies multiply its error */
        q->vscale /= sy.k * sy.half;
    /* By rows over a period; without one (an odd n_xy of fig. 3a), by the face's boxes: whole lines
     * of its other parameter exhaust OFF_WORK where it is fast (fig. 3a at n_xy = 25: 2.1 M points off
     * the tables, 0.01 reported), except in the tests (separate 2, 3). */
    if (one_d)
        (void)0;
    else if (q->mid >= 0)
        for (int l = 0; l < p.np[2] && !q->stopped; l++) {
            pbox b = { { p.edge[0][0], 0.0, p.edge[2][l] }, { p.edge[0][1], 1.0, p.edge[2][l + 1] } };
            double acc[Q_N] = { 0 }, part[Q_N];
            for (int j = 0; j < p.np[1]; j++) {   /* each panel of v on its own: their tables */
                b.lo[1] = p.edge[1][j], b.hi[1] = p.edge[1][j + 1];
                mid_panel(q, &b, 0, part);
                for (int e = 0; e < Q_N; e++)
                    acc[e] += part[e];
            }
            for (int e = 0; e < Q_N; e++)
                q->r.acc[e] += acc[e];
        }
    else if (folds && (sy.k || separate >= 2))
        face_rows(q, &p, 1 - sp.axis);
    else
        for (int i = 0; i < p.np[0]; i++)
            for (int j = 0; j < p.np[1]; j++)
                for (int l = 0; l < p.np[2] && !q->stopped; l++) {
                    pbox b = { { p.edge[0][i], p.edge[1][j], p.edge[2][l] },
                               { p.edge[0][i + 1], p.edge[1][j + 1], p.edge[2][l + 1] } };
                    panel(q, &b);
                }
    pde_status st = q->stopped ? PDE_ERR_CANCELLED : PDE_OK;
    /* Along a polynomial axis, what box_refine's last halvings changed (refine_left, where the boxes
     * still changed) against what their parents' halvings changed is the rate rho at which the
     * halvings converge, and what the last one leaves is the rest of the geometric series: rho / (1 -
     * rho) of what it changed, not all of it. The lines are exact, and what is left is the 2-D rule
     * across the curves where a root of det J leaves the lines, kinks like s |s| at worst (a jump of
     * the second derivative), where a box's error falls as h^4 and the boxes on a curve double: rho
     * 1/8 at best; but where det J vanishes on whole lines along a curve (det J = x_v(v, w) (u P(w) -
     * Q(w)) at x_v = 0), a kink |s|: rho 1/4, taken no smaller (s1_026zu in tests/test_props.c, its
     * boxes cut at the plane of its lines' ends (end_planes): 1.5e-8 off with 1.17e-8 reported at
     * 1/8, 2.0e-8 at 1/4; fig. 3c and 3d, rho above 1/4, unchanged). Where rho is above 1/2, or the work's bound stopped the
     * halvings, what they changed stands. Only boxes whose halving still changed count, not those
     * whose quarters were all smooth (a lower rho). Fig. 3c: 2.3e-9 reported where it was 4e-11 off
     * an independent quadrature; rho 0.29: now 9.1e-10, and 2e-12 off; fig. 3d: 3.3e-10 where
     * 1.7e-10 off, now 1.1e-10 where 1.2e-11 off. (Halving once more, ALONG_DEPTH 6, reported
     * 5e-12 on fig. 3c where it was 2.2e-11 off: the rate does not hold that deep.) */
    if (q->along >= 0 && q->along_added > 0.0 && q->along_added <= 0.5 * q->along_change &&
        q->r.evals * q->modes < REFINE_WORK) {
        const double rho = fmax(q->along_added / q->along_change, ALONG_RHO);
        q->r.refine_left += q->along_added * (rho / (1.0 - rho) - 1.0);
    }
    if (st == PDE_OK) {
        if (sy.k) {
            sym_moments(&sy, q->r.acc);
            q->r.refine_left *= sy.k * sy.half, q->r.refine_change *= sy.k * sy.half;
        }
        if (sp.axis >= 0)
            separable_moments(&sp, (const double[3]){ shifted[0] ? 0.0 : x0[0], shifted[1] ? 0.0 : x0[1],
                                                      shifted[2] ? 0.0 : x0[2] }, q->r.acc);
        if (q->mid >= 0)   /* and rounding, of sums over 1e5 points and more */
            q->r.err += q->mid_err / fmax(fabs(q->r.acc[Q_VOL]), DBL_MIN) + 16 * DBL_EPSILON;
        else if (one_d)   /* rounding (a lifted loft's signed volume: 5.8 eps off, its rules' estimate 2.9) */
            q->r.err += 16 * DBL_EPSILON;
        *out = q->r;
    }
    *rough = q->mid >= 0 && q->mid_rough;
    qctx_free(q);
    return st;
}

/*
 * ---- A loft that folds: det J = n t^(2n - 1) D1(s, w) ----
 *
 * Where x_c = C_c(w) + t^n P_c(s, w) for x and y, z = Z(w), and P's factors along s are whole
 * harmonics of 2 pi s (a loft's profiles), det J = n t^(2n - 1) Z'(w) Q(s, w), Q = P_x P_y,s - P_y P_x,s,
 * a trigonometric polynomial in s of degree 2K (K: P's fastest harmonic). Its sign does not depend on
 * t, and every integral over t is exact: of n t^(2n - 1) t^(kn), 1 / (2 + k). Per row w, the integrals
 * over s of |Q| times 1, P_c, P_c P_d are the signed ones over the period (a uniform rule of N > 4K
 * points, exact) less twice those over the pieces where Q has the minority sign, between Q's roots
 * (Gauss-Legendre, sized to the pieces' phase): exact to rounding where the roots are found. They are
 * bracketed on N >= FOLD_SAMPLES * 2K samples, by sign changes and by the dips of |Q| through 0 and
 * back between samples (Q' located by Illinois at a sample's local least), and polished by Illinois.
 * Along w, the rows' integrals are analytic but where a lobe appears or leaves (a double root of Q):
 * there they go as |w - w0|^(3/2). So w's spans are cut where the rows' root counts change (located by
 * bisection on rows that only count the roots, to 1e-13 of the span), and a span that ends at such a
 * point takes w = w0 + L s^2 towards it, in which the rows are smooth again; each span's FOLD_RULE
 * rule is checked against its FOLD_CHECK one (26 rows, where its halves took 48), halved in s where
 * they differ by more than FOLD_TOL of the volume, and those differences are the error's estimate
 * (pessimistic: the finer rule's sum is kept). A dip is searched only at a sample below half the
 * samples' largest |Q| (fold_row). A star loft of 32 harmonics (docs/MATH.md) took 8.7 G
 * instructions, now 3.1 G. Against an independent root-split quadrature (tests/test_props_loft.c):
 * the epicycle loft's volume, 7e-6 off on the general path (its err 6e-16), is within 3e-16 (err
 * 4e-15); a twisted loft with c = -2 (lobes appearing and leaving along w) within 3e-16, where the
 * face's rows (face_rows) were 6e-12 off with an err of 4e-16; a 30-harmonic loft with boundary
 * layers (c = 0.05) within 3e-14, where the general path was 1.1e-6 off.
 */
#define FOLD_K 256            /* P's harmonics, at most */
#define FOLD_SAMPLES 8        /* samples of Q per wavelength of its fastest harmonic (2K) */
#define FOLD_RULE 16          /* Gauss points per panel of a span of w (in its own variable) */
#define FOLD_CHECK 10         /* ... and of the rule it is checked against */
#define FOLD_OVER_RULE 4      /* ... and of a span's one rule past the work's bound */
#define FOLD_DEPTH 30         /* halvings of a span, at most */
#define FOLD_TOL 1e-15        /* a panel and its halves agree to this of the volume (each integral's scale) */
#define FOLD_SPANS 512        /* spans of w (cut where the rows' root counts change), at most */
#define FOLD_EPS 1e-12        /* a count change this close (of the span) to a cut already there is that cut */
#define FOLD_WORK (2 * MAX_WORK)   /* samples and fold_eval's calls times (K + 1) (fold_ctx.work), at most:
                                    * past it no span is halved or cut, and err says so (fold_span; 1e-9 at
                                    * least). At 10 MAX_WORK a loft of 127 harmonics (4 sections of 256
                                    * points, c = -1e-3) spent 5.4 s here, past any --job-timeout: a unit
                                    * costs more than the 30 instructions first thought, and 2 MAX_WORK is
                                    * about a second */

typedef struct {
    const pde_solution *s;
    const pde_cancel *cancel;
    double x0[3], scale[Q_N];
    int K, N;
    double *ct, *st;          /* cos, sin(2 pi k j / N): [j * (K + 1) + k], j < N, k <= K */
    double *coef;             /* the current row: P_c = sum_k a_ck cos 2 pi k s + b_ck sin 2 pi k s, */
    double *dcoef;            /* ... and 2 pi k b_ck, -2 pi k a_ck (P_c' = sum_k those times cos, sin) */
    double r[3], dz;          /* ... r_c = C_c - x0_c, Z' */
    double *q;                /* Q at the N samples */
    double *roots;            /* the current row's roots, 4K + 2 at most */
    size_t rows, spans;
    double work;              /* rows' samples times (K + 1), and fold_eval's calls times (K + 1) */
    double err;               /* the sum of |fine - coarse| of the volume over accepted panels */
    int stopped, capped;
    double next_poll;         /* work at which the caller's stop() is asked next */
} fold_ctx;

/* P_c and its derivative of order d (1 or 2) along s at s, c = 0, 1 (by the rotation e^{2 pi i s}: two
 * trig calls a point, and one of the derivatives only: Q needs P', Q' = P_x P_y'' - P_y P_x''). */
static void fold_eval(fold_ctx *f, double s, int d, double P[2], double D[2])
{
    f->work += f->K + 1;
    const double c1 = cos(2 * M_PI * s), s1 = sin(2 * M_PI * s);
    const double *a0 = f->coef, *b0 = a0 + (f->K + 1), *a1 = b0 + (f->K + 1), *b1 = a1 + (f->K + 1);
    const double *da0 = f->dcoef, *db0 = da0 + (f->K + 1), *da1 = db0 + (f->K + 1), *db1 = da1 + (f->K + 1);
    double ck = 1.0, sk = 0.0, p0 = a0[0], p1 = a1[0], d0 = 0.0, d1 = 0.0;
    for (int k = 1; k <= f->K; k++) {
        const double t = ck * c1 - sk * s1;
        sk = sk * c1 + ck * s1, ck = t;
        const double e0 = a0[k] * ck + b0[k] * sk, e1 = a1[k] * ck + b1[k] * sk;
        p0 += e0, p1 += e1;
        if (d == 1) {
            d0 += da0[k] * ck + db0[k] * sk, d1 += da1[k] * ck + db1[k] * sk;
        } else {
            const double om2 = (double)k * k;
            d0 -= om2 * e0, d1 -= om2 * e1;
        }
    }
    const double sc = d == 1 ? 1.0 : 4 * M_PI * M_PI;
    P[0] = p0, P[1] = p1, D[0] = sc * d0, D[1] = sc * d1;
}

static double fold_q(void *arg, double s)
{
    double P[2], D[2];
    fold_eval(arg, s, 1, P, D);
    return P[0] * D[1] - P[1] * D[0];
}

static double fold_dq(void *arg, double s)
{
    double P[2], D[2];
    fold_eval(arg, s, 2, P, D);
    return P[0] * D[1] - P[1] * D[0];
}

/* The integrand's basis at s: 1, P_x, P_y, P_x^2, P_y^2, P_x P_y, times Q, added with weight wt. */
static void fold_add(double g[6], const double P[2], double qv, double wt)
{
    const double a = wt * qv;
    g[0] += a, g[1] += a * P[0], g[2] += a * P[1];
    g[3] += a * P[0] * P[0], g[4] += a * P[1] * P[1], g[5] += a * P[0] * P[1];
}

/* The row w: its integrals over (t, s) about x0 into out (not scaled by dw), and the number of Q's roots
 * along s; out NULL: the number only (the roots counted, not polished). */
static int fold_row(fold_ctx *f, double w, double out[Q_N])
{
    const int K = f->K, N = f->N;
    memset(f->coef, 0, sizeof(double) * 4 * (size_t)(K + 1));
    f->dz = 0.0;
    for (int c = 0; c < 3; c++) {
        f->r[c] = -f->x0[c];
        for (size_t m = 0; m < f->s->comp[c].nmodes; m++) {
            const pde_mode *md = &f->s->comp[c].modes[m];
            double h, dh;
            mode_h(md, w, &h, &dh);
            const int k = harmonic(md->v) / 2;
            if (md->u.p == 0.0) {   /* the centre (fold_solid's check: its factor along s is 1) */
                f->r[c] += h;
                if (c == 2)
                    f->dz += dh;
            } else   /* a coefficient of P_c (c < 2) */
                f->coef[(2 * c + (md->v.kind == PDE_SIN)) * (K + 1) + k] += h;
        }
    }
    f->rows++;
    if (!f->stopped && f->work >= f->next_poll) {   /* a row of 127 harmonics is some 1 ms: by work, not panels */
        f->next_poll = f->work + POLL_WORK;
        f->stopped |= pde_stopped(f->cancel);
    }
    f->work += (double)N * (K + 1);
    for (int c = 0; c < 2; c++)
        for (int k = 0; k <= K; k++) {
            f->dcoef[2 * c * (K + 1) + k] = 2 * M_PI * k * f->coef[(2 * c + 1) * (K + 1) + k];
            f->dcoef[(2 * c + 1) * (K + 1) + k] = -2 * M_PI * k * f->coef[2 * c * (K + 1) + k];
        }
    /* the samples: Q, and the signed integrals by the uniform rule (exact: degree 4K < N) */
    double U[6] = { 0 }, qmax = 0.0;
    for (int j = 0; j < N; j++) {
        const double *cj = &f->ct[(size_t)j * (K + 1)], *sj = &f->st[(size_t)j * (K + 1)];
        double P[2] = { 0, 0 }, P1[2] = { 0, 0 };
        for (int c = 0; c < 2; c++) {
            const double *a = &f->coef[2 * c * (K + 1)], *b = a + (K + 1);
            const double *da = &f->dcoef[2 * c * (K + 1)], *db = da + (K + 1);
            P[c] = a[0];
            for (int k = 1; k <= K; k++)
                P[c] += a[k] * cj[k] + b[k] * sj[k], P1[c] += da[k] * cj[k] + db[k] * sj[k];
        }
        f->q[j] = P[0] * P1[1] - P[1] * P1[0];
        qmax = fmax(qmax, fabs(f->q[j]));
        fold_add(U, P, f->q[j], 1.0 / N);
    }
    /* no dip where |Q| at the sample exceeds Q'' h^2 / 2 (h = 1 / N, the least within h of it):
     * |Q''| <= (4 pi K)^2 |Q|_max (Bernstein), |Q|_max <= |Q|_samples / cos(pi 2K / N) (N = 16K:
     * 1.09 of it): 0.34 of the samples' largest, 0.5 with a margin */
    const double qdip = 0.5 * qmax;
    /* the roots: sign changes between samples, and dips through 0 and back (at a sample's local least
     * of |Q|, Q' bracketed by its neighbours) */
    int nr = 0;
    for (int j = 0; j < N; j++) {
        const double a = (double)j / N, b = (double)(j + 1) / N, qa = f->q[j], qb = f->q[(j + 1) % N];
        const double qp = f->q[(j + N - 1) % N];
        if ((qa < 0) != (qb < 0)) {
            if (nr < 4 * K + 2)
                f->roots[nr] = out ? illinois(fold_q, f, a, b, qa, qb) : a, nr++;
            continue;
        }
        const double sg = qa < 0 ? -1.0 : 1.0;
        if ((qp < 0) != (qa < 0) || !(sg * qa <= sg * qp && sg * qa <= sg * qb) || sg * qa > qdip || nr + 2 > 4 * K + 2)
            continue;
        const double lo = a - 1.0 / N, dlo = sg * fold_dq(f, lo), dhi = sg * fold_dq(f, b);
        if (!(dlo < 0 && dhi > 0))
            continue;
        const double at = illinois(fold_dq, f, lo, b, sg * dlo, sg * dhi), qat = fold_q(f, at);
        if (sg * qat < 0 && out) {
            f->roots[nr++] = illinois(fold_q, f, lo, at, qp, qat);
            f->roots[nr++] = illinois(fold_q, f, at, b, qat, qb);
        } else if (sg * qat < 0)
            nr += 2;
    }
    if (!out)
        return nr;
    /* the minority's pieces: Q's integrals there, by Gauss-Legendre sized to their phase (the
     * integrands' degree 4K) */
    const double sg = U[0] < 0 ? -1.0 : 1.0;
    double G[6] = { 0 };
    if (nr) {
        for (int i = 0; i < nr; i++)
            f->roots[i] -= floor(f->roots[i]);
        qsort(f->roots, (size_t)nr, sizeof *f->roots, double_cmp);
        f->roots[nr] = f->roots[0] + 1.0;
        for (int i = 0; i < nr; i++) {
            const double a = f->roots[i], len = f->roots[i + 1] - a;
            if (!(len > 0.0) || sg * fold_q(f, a + 0.5 * len) >= 0.0)
                continue;
            const double phase = 2 * M_PI * 4 * K * len;
            const int parts = (int)ceil(phase / PANEL_PHASE), n = rule_points(phase / parts);
            for (int p = 0; p < parts; p++)
                for (int i2 = 0; i2 < n; i2++) {
                    double P[2], P1[2];
                    fold_eval(f, a + len * (p + rules_x[n][i2]) / parts, 1, P, P1);
                    fold_add(G, P, P[0] * P1[1] - P[1] * P1[0], len * rules_w[n][i2] / parts);
                }
        }
    }
    double A[6];   /* the integrals of |D1| = |Z'| |Q| */
    for (int e = 0; e < 6; e++)
        A[e] = fabs(f->dz) * sg * (U[e] - 2.0 * G[e]);
    const double *r = f->r;
    out[Q_VOL] = 0.5 * A[0];
    out[Q_M1 + 0] = 0.5 * A[0] * r[0] + A[1] / 3.0;
    out[Q_M1 + 1] = 0.5 * A[0] * r[1] + A[2] / 3.0;
    out[Q_M1 + 2] = 0.5 * A[0] * r[2];
    out[Q_M2 + 0] = 0.5 * A[0] * r[0] * r[0] + 2.0 * r[0] * A[1] / 3.0 + 0.25 * A[3];
    out[Q_M2 + 1] = 0.5 * A[0] * r[1] * r[1] + 2.0 * r[1] * A[2] / 3.0 + 0.25 * A[4];
    out[Q_M2 + 2] = 0.5 * A[0] * r[2] * r[2];
    out[Q_M2 + 3] = 0.5 * A[0] * r[0] * r[1] + (r[0] * A[2] + r[1] * A[1]) / 3.0 + 0.25 * A[5];
    out[Q_M2 + 4] = 0.5 * A[0] * r[0] * r[2] + r[2] * A[1] / 3.0;
    out[Q_M2 + 5] = 0.5 * A[0] * r[1] * r[2] + r[2] * A[2] / 3.0;
    out[Q_SIGNED] = 0.5 * f->dz * U[0];
    return nr;
}

/* A span [wa, wb] of w whose ends at a count change (ca, cb) take w = w0 + L s^2 towards them. */
typedef struct {
    double wa, wb;
    int ca, cb;
} fold_span_t;

static double fold_map(const fold_span_t *sp, double s, double *dw)
{
    const double L = sp->wb - sp->wa;
    if (sp->ca && sp->cb)
        return *dw = 6.0 * L * s * (1.0 - s), sp->wa + L * s * s * (3.0 - 2.0 * s);
    if (sp->ca)
        return *dw = 2.0 * L * s, sp->wa + L * s * s;
    if (sp->cb)
        return *dw = 2.0 * L * (1.0 - s), sp->wb - L * (1.0 - s) * (1.0 - s);
    return *dw = L, sp->wa + L * s;
}

/* The n-point rule on [s0, s1] of the span into acc, and the rows' root counts: their count where they
 * agree, else -1 with the w of two neighbouring nodes whose counts differ, and those counts, in at[],
 * cnt[]; *w1: the first node's w. */
static int fold_rule(fold_ctx *f, const fold_span_t *sp, double s0, double s1, int n, double acc[Q_N], double at[2],
                     int cnt[2], double *w1)
{
    int sig = -2, prev = -2;
    double prev_w = 0.0;
    memset(acc, 0, Q_N * sizeof *acc);
    for (int i = 0; i < n; i++) {
        double dw, row[Q_N];
        const double w = fold_map(sp, s0 + (s1 - s0) * rules_x[n][i], &dw);
        const int c = fold_row(f, w, row);
        if (!i)
            sig = c, *w1 = w;
        else if (sig >= 0 && c != prev)
            at[0] = prev_w, at[1] = w, cnt[0] = prev, cnt[1] = c, sig = -1;
        prev = c, prev_w = w;
        for (int e = 0; e < Q_N; e++)
            acc[e] += (s1 - s0) * rules_w[n][i] * dw * row[e];
    }
    return sig;
}

static int fold_count(fold_ctx *f, double w)
{
    return fold_row(f, w, NULL);
}

/* Past the work's bound, or asked to stop: no more cuts, bisections or halvings */
static int fold_over(const fold_ctx *f)
{
    return f->stopped || f->work >= FOLD_WORK;
}

/* [s0, s1] of the span by the FOLD_RULE-point rule against the FOLD_CHECK-point one, halved where they
 * differ; accepted panels' sums into out, their differences into *err. *sig: the rows' root count (-2:
 * the first rule's), at *wsig. Returns 0, or -1 where a rule's rows' counts differ from *sig (at[],
 * cnt[] say where: two points whose counts differ); lenient: they may. */
static int fold_adapt(fold_ctx *f, const fold_span_t *sp, double s0, double s1, int *sig, double *wsig, int lenient,
                      int depth, double out[Q_N], double *err, double at[2], int cnt[2])
{
    static const int rn[2] = { FOLD_RULE, FOLD_CHECK };
    double g[2][Q_N];
    for (int k = 0; k < 2; k++) {
        double w1;
        const int c = fold_rule(f, sp, s0, s1, rn[k], g[k], at, cnt, &w1);
        if (*sig == -2 && (c >= 0 || lenient))   /* the span's first rule: its count */
            *sig = c >= 0 ? c : cnt[0], *wsig = c >= 0 ? w1 : at[0];
        else if (!lenient && c != *sig) {
            if (c >= 0)   /* the rule's count differs from wsig's: between them */
                at[0] = *wsig, at[1] = w1, cnt[0] = *sig, cnt[1] = c;
            return -1;
        }
    }
    double diff = 0.0;
    for (int e = 0; e < Q_N; e++)
        diff = fmax(diff, fabs(g[0][e] - g[1][e]) / f->scale[e]);
    if (diff <= FOLD_TOL || depth >= FOLD_DEPTH || fold_over(f) || (f->stopped = pde_stopped(f->cancel))) {
        if (diff > FOLD_TOL)
            f->capped = 1;
        for (int e = 0; e < Q_N; e++)
            out[e] += g[0][e];
        *err += fabs(g[0][Q_VOL] - g[1][Q_VOL]);
        return 0;
    }
    const double m = 0.5 * (s0 + s1);
    for (int k = 0; k < 2; k++)
        if (fold_adapt(f, sp, k ? m : s0, k ? s1 : m, sig, wsig, lenient, depth + 1, out, err, at, cnt))
            return -1;
    return 0;
}

/* The span: adapted as a whole, or cut where its rows' counts change (a lobe appears or leaves). */
static void fold_span(fold_ctx *f, fold_span_t sp, double acc[Q_N])
{
    f->spans++;
    /* past the work's bound, as it is: its lobes, unresolved, count in err as a whole (the rules'
     * difference missed a star loft's error by 15%), and err is 1e-9 at least (capped) */
    if (f->stopped)
        return;
    const int over = fold_over(f);
    if (over) {
        f->capped = 1;   /* one short rule, its lobes in err as a whole: the spans still pending past the bound (98
                   * of a loft of 127 harmonics) took two full rules each, 5 s */
        double part[Q_N], at[2], w1;
        int cnt[2];
        fold_rule(f, &sp, 0.0, 1.0, FOLD_OVER_RULE, part, at, cnt, &w1);
        for (int e = 0; e < Q_N; e++)
            acc[e] += part[e];
        f->err += fabs(part[Q_VOL]) - fabs(part[Q_SIGNED]);
        return;
    }
    for (int lenient = 0; lenient < 2; lenient++) {
        double part[Q_N] = { 0 }, at[2], err = 0.0, wsig = 0.0;
        int cnt[2], sig = -2;
        if (!fold_adapt(f, &sp, 0.0, 1.0, &sig, &wsig, lenient, 0, part, &err, at, cnt)) {
            for (int e = 0; e < Q_N; e++)
                acc[e] += part[e];
            f->err += over || fold_over(f) ? fmax(err, fabs(part[Q_VOL]) - fabs(part[Q_SIGNED])) : err;
            return;
        }
        /* the change between at[0] (count cnt[0]) and at[1], located by bisection */
        double lo = fmin(at[0], at[1]), hi = fmax(at[0], at[1]);
        int clo = at[0] < at[1] ? cnt[0] : cnt[1];
        while (hi - lo > 0.1 * FOLD_EPS * (sp.wb - sp.wa) && hi - lo > 4 * DBL_EPSILON * fmax(fabs(lo), fabs(hi)) &&
               !fold_over(f)) {   /* a row a step: within the work's bound too (512 cuts of 40 steps, 127
                                   * harmonics: 5 s) */
            const double mid = 0.5 * (lo + hi);
            if (!(mid > lo && mid < hi))
                break;
            if (fold_count(f, mid) == clo)
                lo = mid;
            else
                hi = mid;
        }
        const double w0 = 0.5 * (lo + hi), L = sp.wb - sp.wa;
        if (w0 - sp.wa > FOLD_EPS * L && sp.wb - w0 > FOLD_EPS * L && f->spans + 2 <= FOLD_SPANS && !fold_over(f)) {
            fold_span(f, (fold_span_t){ sp.wa, w0, sp.ca, 1 }, acc);
            fold_span(f, (fold_span_t){ w0, sp.wb, 1, sp.cb }, acc);
            return;
        }
        /* at a cut already there (rounding of a tiny lobe's sign), or past FOLD_SPANS or the work's bound:
         * as it is */
    }
}

/* Z'(w), z = Z(w) a function of w alone (fold_solid's form) */
static double fold_dz(void *arg, double w)
{
    double x[3], xu[3], xv[3], xw[3];
    pde_eval_d(arg, 0.5, 0.5, w, x, xu, xv, xw);
    return xw[2];
}

/*
 * Where Z' changes sign in (a, b), |det J| = n t^(2n - 1) |Z'(w)| |Q| has a kink that no count of Q's
 * roots shows: the roots there, located where FOLD_ZSAMPLES samples change sign (Illinois), into cut,
 * ascending; returns how many (at most max). A z turning back along w (Z'(0) < 0 < Z'(1)) was 1.2e-8
 * off with 8.4e-15 reported, its span's rules agreeing across the kink.
 */
#define FOLD_ZSAMPLES 64
static int fold_zcuts(const pde_solution *s, double a, double b, double *cut, int max)
{
    int n = 0;
    double t0 = a, f0 = fold_dz((void *)s, a);
    for (int i = 1; i <= FOLD_ZSAMPLES && n < max; i++) {
        const double t1 = i == FOLD_ZSAMPLES ? b : a + (b - a) * i / FOLD_ZSAMPLES, f1 = fold_dz((void *)s, t1);
        if ((f0 < 0.0 && f1 > 0.0) || (f0 > 0.0 && f1 < 0.0))
            cut[n++] = illinois(fold_dz, (void *)s, t0, t1, f0, f1);
        t0 = t1, f0 = f1;
    }
    return n;
}

/*
 * A model of the loft's form (below) that is not a loft takes these rows only where no other exact path
 * does: the free path (G = g(w): fig. 2, 4, and a centre C(w) beside them, quad_sep's lift) and a
 * period's rows (face_rows, where the solid repeats itself along v: fig. 3a, 3b, as exact and 1.6 to 2.7
 * times cheaper there). Else its face went by 2-D boxes, whose outer rule converges slowly across the
 * curves where Q's roots leave the rows (x = u (X1(w) cos 2 pi v + X2(w) sin 4 pi v), y = u Y(w) sin
 * 2 pi v, z = Z(w) that folds: 2.5e-9 to 1.6e-7 off an independent quadrature with 6.8e-8 to 1.9e-7
 * reported), and with a centre C(w) the general path's 3-D boxes (to 2.3e-7 off, 3.1e-6 reported);
 * these rows: within 6e-13 (tests/test_props.c, loft_form_...). Only up to FOLD_DIRECT_K harmonics:
 * past the work's bound the rows' error counts only the lobes of the spans left unresolved, which
 * misses what boundary layers leave (tests/test_props_loft.c's tubes of harmonics 96 to 100, z = w,
 * signed volume 6.4e-2 off with 1.3e-6 reported at c = 1e-8, 1e-6 off with 1e-9 at c = 1, where the
 * general path reports honestly; lofts still take them so).
 */
#define FOLD_DIRECT_K 8
static int fold_direct(const pde_solution *s)
{
    quad_sep sp;
    qsym sy;
    int d[3], m[3];
    for (int c = 0; c < 3; c++)
        for (size_t i = 0; i < s->comp[c].nmodes; i++)
            if (harmonic(s->comp[c].modes[i].v) > 2 * FOLD_DIRECT_K)
                return 0;
    separate_lifted(s, 1, &sp);
    if (sp.axis >= 0 && sp.free >= 0)
        return 0;
    if (sp.axis >= 0 && (param_symmetry(s, 1, d, m) > 1 || param_rotation(s, 1, &sy)))
        return 0;
    return 1;
}

/*
 * The loft's form above, or 0: every mode's factor along u is 1 or t^n (one n >= 1), along v 1 or a
 * whole harmonic of 2 pi v (at most FOLD_K); a mode with the factor 1 along u has 1 along v (the
 * centre C); z has no mode with t^n. Then the integrals into out, 1.
 */
static int fold_solid(const pde_solution *s, const double x0[3], double vscale, const pde_cancel *cancel,
                      quad_result *out, pde_status *st)
{
    double n = 0.0;
    int K = 0;
    if (!s->nsections && !fold_direct(s))
        return 0;
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++) {
            const pde_mode *md = &s->comp[c].modes[m];
            const int k = harmonic(md->v);
            if (md->u.kind != PDE_POW || k < 0 || k % 2 || k / 2 > FOLD_K)
                return 0;
            if (md->u.p == 0.0) {
                if (k)
                    return 0;
                continue;
            }
            if (c == 2 || (n != 0.0 && md->u.p != n))
                return 0;
            n = md->u.p;
            K = k / 2 > K ? k / 2 : K;
        }
    if (!K)
        return 0;
    pthread_once(&rules_once, rules_init);
    fold_ctx f = { .s = s, .cancel = cancel, .K = K };
    f.N = FOLD_SAMPLES * 2 * K;
    const size_t tk = (size_t)f.N * (K + 1);
    double *mem = malloc(sizeof(double) * (2 * tk + 8 * (size_t)(K + 1) + (size_t)f.N + 4 * (size_t)K + 3));
    if (!mem)
        return *st = PDE_ERR_NOMEM, 1;
    f.ct = mem, f.st = mem + tk, f.coef = mem + 2 * tk, f.dcoef = f.coef + 4 * (K + 1), f.q = f.dcoef + 4 * (K + 1);
    f.roots = f.q + f.N;
    for (int j = 0; j < f.N; j++)
        for (int k = 0; k <= K; k++) {
            const double t = 2 * M_PI * (double)((long)j * k % f.N) / f.N;
            f.ct[(size_t)j * (K + 1) + k] = cos(t), f.st[(size_t)j * (K + 1) + k] = sin(t);
        }
    memcpy(f.x0, x0, sizeof f.x0);
    const double size = cbrt(vscale);
    for (int e = 0; e < Q_N; e++)
        f.scale[e] = vscale * (e == Q_VOL || e == Q_SIGNED ? 1.0 : e < Q_M2 ? size : size * size);
    memset(out, 0, sizeof *out);
    size_t nslabs;
    const double *br = solution_breaks(s, &nslabs);
    for (size_t sl = 0; sl < nslabs && !f.stopped; sl++) {
        /* panels of PANEL_PHASE radians of the slab's fastest term */
        double rate = 1.0;
        for (int c = 0; c < 3; c++)
            for (size_t m = 0; m < s->comp[c].nmodes; m++) {
                const pde_mode *md = &s->comp[c].modes[m];
                for (size_t k = md->first[sl]; k < md->first[sl + 1]; k++)
                    rate = fmax(rate, hypot(md->terms[k].alpha, md->terms[k].beta) + md->terms[k].deg);
            }
        const double len = br[sl + 1] - br[sl];
        const int np = (int)fmin(MAX_PANELS, ceil(rate * len / PANEL_PHASE));
        for (int p = 0; p < np && !f.stopped; p++) {
            const double a = br[sl] + len * p / np, b = p + 1 == np ? br[sl + 1] : br[sl] + len * (p + 1) / np;
            double cut[8];
            const int nc = fold_zcuts(s, a, b, cut, 8);
            for (int c = 0; c <= nc && !f.stopped; c++)   /* each side of Z''s sign changes on its own */
                fold_span(&f, (fold_span_t){ c ? cut[c - 1] : a, c < nc ? cut[c] : b, 0, 0 }, out->acc);
        }
    }
    free(mem);
    if (f.stopped)
        return *st = PDE_ERR_CANCELLED, 1;
    out->evals = f.rows * (size_t)f.N;
    /* the panels' differences, and rounding of sums over 1e4 points and more; where the work's bound
     * stopped the halving, at least 1e-9 */
    out->err = f.err / fmax(fabs(out->acc[Q_VOL]), DBL_MIN) + 16 * DBL_EPSILON;
    if (f.capped)
        out->err = fmax(out->err, 1e-9);
    *st = PDE_OK;
    return 1;
}

pde_status quad_solid_signs(const pde_solution *s, const double x0[3], double jscale, double vscale, int separate,
                            int jsign, const quad_wsign *ws, const pde_cancel *cancel, quad_result *out)
{
    int rough = 0;
    pde_status st;
    /* a loft whose det J may change sign: root-split rows (fold_solid), where it has that form */
    if (!jsign && separate == 1 && fold_solid(s, x0, vscale, cancel, out, &st))
        return st;
    st = solid_run(s, x0, jscale, vscale, separate, jsign, ws, cancel, 1, out, &rough);
    if (st == PDE_OK && rough)   /* det J's sign changes along u: the general path */
        st = solid_run(s, x0, jscale, vscale, separate, jsign, ws, cancel, 0, out, &rough);
    return st;
}

pde_status quad_solid(const pde_solution *s, const double x0[3], double jscale, double vscale, int separate,
                      int jsign, const pde_cancel *cancel, quad_result *out)
{
    return quad_solid_signs(s, x0, jscale, vscale, separate, jsign, NULL, cancel, out);
}

/* ---- the skin ---- */

/* A polynomial solid's faces from its power basis (poly.h): points, planarity, curved faces' rules. */
#include "poly.h"

/* x and the two tangents of face (axis, side) at its parameters (s, t), the others in axis order;
 * from px, a polynomial solid's x, y, z, where not NULL (a tenth of pde_eval_d's cost on fig. 1). */
static void face_point(const pde_solution *s, const poly3 *px, int axis, int side, double a, double b, double x[3],
                       double ta[3], double tb[3])
{
    double p[3], d[3][3];
    int o[2], n = 0;
    for (int k = 0; k < 3; k++)
        if (k != axis)
            o[n++] = k;
    p[axis] = side;
    p[o[0]] = a, p[o[1]] = b;
    if (px)
        for (int c = 0; c < 3; c++) {
            double g[3];
            poly_eval_d(&px[c], p, &x[c], g);
            d[0][c] = g[0], d[1][c] = g[1], d[2][c] = g[2];
        }
    else
        pde_eval_d(s, p[0], p[1], p[2], x, d[0], d[1], d[2]);
    for (int c = 0; c < 3; c++)
        ta[c] = d[o[0]][c], tb[c] = d[o[1]][c];
}

/* Faces (axis, 0) and (axis, 1) are the same surface (the seam of a solid of revolution). Along u
 * or v, where every mode's factor is 1 or a whole harmonic, sin or cos(k pi t) with k even (fig. 2
 * and 4's v, a loft's), the closed form takes the same values on both: they coincide exactly, and
 * no samples are needed (the 49 pairs of pde_eval_d were fig. 2a's 0.17 M instructions a call).
 * Otherwise the faces are compared at 7 x 7 points. */
static int faces_coincide(const pde_solution *s, const poly3 *px, int axis, double size)
{
    int periodic = axis < 2;
    for (int c = 0; c < 3 && periodic; c++)
        for (size_t m = 0; m < s->comp[c].nmodes && periodic; m++) {
            const int k = harmonic(axis ? s->comp[c].modes[m].v : s->comp[c].modes[m].u);
            periodic = k >= 0 && k % 2 == 0;
        }
    if (periodic)
        return 1;
    for (int i = 0; i <= 6; i++)
        for (int j = 0; j <= 6; j++) {
            double x0[3], x1[3], ta[3], tb[3];
            face_point(s, px, axis, 0, i / 6.0, j / 6.0, x0, ta, tb);
            face_point(s, px, axis, 1, i / 6.0, j / 6.0, x1, ta, tb);
            for (int c = 0; c < 3; c++)
                if (!(fabs(x0[c] - x1[c]) <= 1e-9 * size))
                    return 0;
        }
    return 1;
}

/*
 * A face's area element |x_a x x_b| has a kink where it vanishes inside the face: on a cuspidal
 * edge of the skin, where the face folds over and x_a x x_b turns through zero to the opposite
 * direction. So each panel of a face is integrated like a panel of the solid where det J may
 * change sign: along lines, with the roots of s = (x_a x x_b) . nu, nu the element's direction at
 * the panel's centre, located to rounding and a rule on each piece. The lines are the solid's
 * (qctx) with the face's own axis fixed at its side.
 */
typedef struct {
    qctx *q;
    int axis, side, la;       /* the face, and the face parameter (0, 1) the lines run along */
    int o[2];                 /* the face's parameters' axes */
    double nu[3], tol;
} face_line;

/* |x_a x x_b| from the partials d, and (x_a x x_b) . nu into *sdir. */
static double face_elem_of(const face_line *f, double d[3][3], double *sdir)
{
    const double *ta = d[f->o[0]], *tb = d[f->o[1]];
    const double c[3] = { ta[1] * tb[2] - ta[2] * tb[1], ta[2] * tb[0] - ta[0] * tb[2], ta[0] * tb[1] - ta[1] * tb[0] };
    *sdir = c[0] * f->nu[0] + c[1] * f->nu[1] + c[2] * f->nu[2];
    double m = fmax(fabs(c[0]), fmax(fabs(c[1]), fabs(c[2])));   /* scaled: no overflow in the squares */
    return m > 0.0 ? m * sqrt((c[0] / m) * (c[0] / m) + (c[1] / m) * (c[1] / m) + (c[2] / m) * (c[2] / m)) : 0.0;
}

/* The element at t on the current line, and at its table point it. */
static double face_elem(const face_line *f, double t, double *sdir)
{
    double x[QX], d[3][3];
    line_eval_d(f->q, t, x, d);
    return face_elem_of(f, d, sdir);
}

/* flux: x . (x_a x x_b), whose integrals over the faces give the signed volume (quad_area). */
static double face_elem_at(const face_line *f, int it, double *sdir, double *flux)
{
    double x[QX], d[3][3];
    line_eval_at(f->q, it, x, d);
    const double *ta = d[f->o[0]], *tb = d[f->o[1]];
    *flux = x[0] * (ta[1] * tb[2] - ta[2] * tb[1]) + x[1] * (ta[2] * tb[0] - ta[0] * tb[2]) +
            x[2] * (ta[0] * tb[1] - ta[1] * tb[0]);
    return face_elem_of(f, d, sdir);
}

static double face_sign(void *arg, double t)
{
    double sd;
    return face_elem(arg, t, &sd), sd;
}

static double face_root(const face_line *f, double a, double b, double fa, double fb)
{
    return illinois(face_sign, (void *)f, a, b, fa, fb);
}

/*
 * A bound, loose by design, on the n-point Gauss rule's error on f from its values at the nodes
 * alone (no second rule, no more points): |a_(n-1)| + |a_(n-2)|, the two highest Legendre
 * coefficients of the polynomial through them, relative to the panel's length. The rule is exact
 * to degree 2n - 1, so its error is far smaller: on the faces of fig. 2c and 4a-c (890 panels), a
 * panel differed from its four quarters by 1e-2 to 1e-8 of this, at least 20 times less, but where
 * the element nears 0 inside the panel (a fold between the nodes: 12 tolerances against 989; see
 * face_panel). Extrapolating the coefficients' decay to a_(2n) was tried: it missed such panels
 * by 1e8.
 */
static double legendre_tail(const double *f, int n)
{
    double a[2] = { 0, 0 };
    for (int j = 0; j < 2 && j < n; j++)
        for (int i = 0; i < n; i++)
            a[j] += rules_leg[n][j][i] * f[i];
    return fabs(a[0]) + fabs(a[1]);
}

/* The n-point rule's sum of the element over [a, b] (either order), off the tables. */
static double face_rule(const face_line *f, double a, double b, int n)
{
    double sum = 0.0, dummy;
    for (int i = 0; i < n; i++)
        sum += f->q->gw[n][i] * face_elem(f, a + (b - a) * f->q->gx[n][i], &dummy);
    return fabs(b - a) * sum;
}

/*
 * A rounded fold: where |x_a x x_b| has a minimum m > 0 at c, it is about sqrt(m^2 + g^2 (t - c)^2),
 * smooth only on the scale m / g (fig. 2c: 1e-4 of its largest, 3e-4 wide in w), and a rule over
 * [far, c] loses its order. So pieces graded geometrically towards c (each GRADE_RATIO of the
 * distance left), until the element at the piece's start is within twice m: the rest is smooth on
 * its own scale. The error falls exponentially with the pieces (hp-style), and the nearer pieces,
 * which hold less of the integral, take fewer points.
 */
static double face_toward(const face_line *f, double far, double c, double m)
{
    double sum = 0.0, lo = far, dummy;
    int np = GRADE_POINTS;
    for (int k = 0; k < GRADE_LEVELS && dip_budget(f->q) && face_elem(f, lo, &dummy) > 2.0 * m; k++) {
        const double e = c - GRADE_RATIO * (c - lo);
        sum += face_rule(f, lo, e, np);
        lo = e;
        np = np > 6 ? np - 2 : 4;
    }
    return sum + face_rule(f, lo, c, np);
}

/* |x_a x x_b|'s least in [a, b], bracketed by the samples, by golden section on its square (smooth,
 * where the element itself has a kink at a cusp), to a bracket well inside the dip's width: *m the
 * least. */
static double face_min(const face_line *f, double a, double b, double *m)
{
    const double g = 0.5 * (3.0 - sqrt(5.0)), len = b - a;
    double dummy, c = a + g * (b - a), d = b - g * (b - a);
    double fc = face_elem(f, c, &dummy), fd = face_elem(f, d, &dummy);
    const double slope = fmax(face_elem(f, a, &dummy), face_elem(f, b, &dummy)) / len;
    for (int it = 0; it < 60 && b - a > 1e-12 * len && (b - a) * slope > 0.2 * fmin(fc, fd); it++) {
        if (fc < fd) {
            b = d, d = c, fd = fc;
            c = a + g * (b - a);
            fc = face_elem(f, c, &dummy);
        } else {
            a = c, c = d, fc = fd;
            d = b - g * (b - a);
            fd = face_elem(f, d, &dummy);
        }
    }
    *m = fmin(fc, fd);
    return fc < fd ? c : d;
}

/* The integral of |x_a x x_b| along the current line over the panel [a, b], with the table's n-point
 * rule at its nodes; and the flux's (smooth: the rule alone) into *flux, into *tail a bound on the
 * rule's error on the element (legendre_tail; infinite where the element changes sign or dips), and
 * the element's values at the nodes widen range [min, max]. The line is cut at the roots of the
 * element's component along nu and at the least of every dip of the element below FACE_EST_MIN of
 * its largest, and each piece's rule graded towards a cut where the element stays above GRADE_MIN
 * of its largest there (face_toward). */
static double face_line_integral(const face_line *f, double a, double b, int n, const double *gw, double *flux,
                                 double *tail, double range[2])
{
    double v[GMAX + 2] = { 0 }, sd[GMAX + 2], fl[GMAX + 2], vmax = 0.0;
    const double *t = f->q->tab[f->q->k].t;
    for (int i = 0; i < n + 2; i++) {
        v[i] = face_elem_at(f, i, &sd[i], &fl[i]);
        vmax = fmax(vmax, v[i]);
    }
    *flux = 0.0;
    for (int i = 0; i < n; i++)
        *flux += (b - a) * gw[i] * fl[i + 1];
    /* cuts: cut[0] = a, cut[ncut - 1] = b; cm[k] the element there where graded towards, else -1 */
    double cut[3 * GMAX], cm[3 * GMAX], sum = 0.0, dummy;
    int ncut = 1, last = 0, crossed[GMAX + 2] = { 0 }, at_b = 0;
    cut[0] = a, cm[0] = -1.0;
    const double floor = GRADE_MIN * vmax;
    for (int i = 1; i < n + 2 && off_budget(f->q); i++) {
        if (sign_changes(sd[last], sd[i], f->tol)) {
            cut[ncut] = face_root(f, t[last], t[i], sd[last], sd[i]);
            const double m = face_elem(f, cut[ncut], &dummy);
            cm[ncut++] = m > floor ? m : -1.0;
            crossed[last] = crossed[i] = 1;
        }
        if (fabs(sd[i]) > f->tol || fabs(sd[last]) <= f->tol)
            last = i;
    }
    for (int i = 0; i < n + 2 && dip_budget(f->q); i++) {
        const int l = i > 0 ? i - 1 : 0, r = i < n + 1 ? i + 1 : n + 1;
        if (!(v[i] < FACE_EST_MIN * vmax && v[i] > floor && v[i] <= v[l] && v[i] <= v[r]) || crossed[i] ||
            crossed[l] || crossed[r])
            continue;
        double m, at = face_min(f, t[l], t[r], &m);
        if (!(m > floor))
            continue;
        if (at - a <= 1e-9 * (b - a))
            cm[0] = m;
        else if (b - at > 1e-9 * (b - a))
            cut[ncut] = at, cm[ncut++] = m;
        else if (!at_b)
            cut[ncut] = b, cm[ncut++] = m, at_b = 1;
    }
    if (ncut == 1 && cm[0] < 0.0) {
        for (int i = 0; i < n; i++) {
            sum += (b - a) * gw[i] * v[i + 1];
            range[0] = fmin(range[0], v[i + 1]), range[1] = fmax(range[1], v[i + 1]);
        }
        *tail = (b - a) * legendre_tail(v + 1, n);
        return sum;
    }
    *tail = INFINITY;
    if (!at_b)
        cut[ncut] = b, cm[ncut++] = -1.0;
    for (int i = 1; i < ncut; i++)   /* in order: few cuts, an insertion sort */
        for (int j = i; j > 1 && cut[j] < cut[j - 1]; j--) {
            double tc = cut[j], tm = cm[j];
            cut[j] = cut[j - 1], cm[j] = cm[j - 1];
            cut[j - 1] = tc, cm[j - 1] = tm;
        }
    for (int c = 0; c + 1 < ncut; c++) {
        const double t0 = cut[c], t1 = cut[c + 1], mid = 0.5 * (t0 + t1);
        if (!(t1 > t0))
            continue;
        if (cm[c] < 0.0 && cm[c + 1] < 0.0)
            sum += face_rule(f, t0, t1, n);   /* the panel's rule: the element's root is a kink of sqrt */
        else if (cm[c] < 0.0)
            sum += face_toward(f, t0, t1, cm[c + 1]);
        else if (cm[c + 1] < 0.0)
            sum += face_toward(f, t1, t0, cm[c]);
        else
            sum += face_toward(f, mid, t0, cm[c]) + face_toward(f, mid, t1, cm[c + 1]);
    }
    return sum;
}

typedef struct {
    face_line line;
    double f[2];                 /* the element's frequencies along the face's parameters */
    double tol;                  /* of a panel's refinement, absolute */
    const pde_cancel *cancel;
    int refined;                 /* panels refined so far */
    int max_refined;             /* FACE_REFINE; where det J separates, every panel (REFINE_WORK bounds it) */
    int flat;                    /* the face parameter (0, 1) fixed at 1 where the face separates, or -1 */
    int stopped;
    double left;                 /* the face's estimated error: its panels' last halvings' changes (face_refine) */
} face_ctx;

/* One panel [lo, lo + h] of the face: lines along the parameter that crosses the sign changes of
 * the element's component along its direction at the centre most often, rules sized to it. The
 * flux's integral goes into *flux, and into *est a bound on the rules' error from their own points
 * (legendre_tail along both parameters), infinite where a line crosses a fold or the element falls
 * below FACE_EST_MIN of its largest at the nodes. */
static double face_panel(face_ctx *c, const double lo[2], const double h[2], double *flux, double *est)
{
    face_line *f = &c->line;
    qctx *q = f->q;
    double big = 0.0;
    /* The centre and a 4 x 4 sample from the tables: the factors of each parameter at its 4 + 1
     * points, not a pde_eval_d (every factor, h's exp and sin) per point. */
    enum { S = 4 };
    for (int k = 0; k < 2; k++) {
        axis_tab *tk = &q->tab[f->o[k]];
        for (int i = 0; i < S; i++)
            tk->t[i] = lo[k] + h[k] * (i + 0.5) / S;
        tk->t[S] = lo[k] + 0.5 * h[k];
        tab_eval(q, f->o[k], S + 1);
    }
    q->tab[f->axis].t[0] = f->side;
    tab_eval(q, f->axis, 1);
    q->tab_ok = 0;
    int at[3];
    double dc[3][3];
    at[f->axis] = 0, at[f->o[0]] = S, at[f->o[1]] = S;
    tab_partials(q, at, dc);
    const double *ta = dc[f->o[0]], *tb = dc[f->o[1]];
    f->nu[0] = ta[1] * tb[2] - ta[2] * tb[1], f->nu[1] = ta[2] * tb[0] - ta[0] * tb[2];
    f->nu[2] = ta[0] * tb[1] - ta[1] * tb[0];
    double nn = sqrt(f->nu[0] * f->nu[0] + f->nu[1] * f->nu[1] + f->nu[2] * f->nu[2]);
    for (int k = 0; k < 3; k++)
        f->nu[k] = nn > 0 ? f->nu[k] / nn : (k == 2);
    /* Sampled evenly, not at the rules' nodes: the lines' direction decides how well a cuspidal
     * edge is integrated (fig. 3a's area moved by 1.5e-7 when sampled at the nodes). */
    double sd[S][S], el[S][S], least = INFINITY;
    for (int i = 0; i < S; i++)
        for (int j = 0; j < S; j++) {
            double d[3][3];
            at[f->o[0]] = i, at[f->o[1]] = j;
            tab_partials(q, at, d);
            el[i][j] = face_elem_of(f, d, &sd[i][j]);
            big = fmax(big, el[i][j]), least = fmin(least, el[i][j]);
        }
    f->tol = 1e-13 * big;
    int cross[2] = { 0, 0 };
    double vary[2] = { 0, 0 };
    for (int i = 0; i < S; i++)
        for (int j = 0; j + 1 < S; j++) {
            cross[0] += sign_changes(sd[j][i], sd[j + 1][i], f->tol);
            cross[1] += sign_changes(sd[i][j], sd[i][j + 1], f->tol);
            vary[0] += fabs(el[j + 1][i] - el[j][i]), vary[1] += fabs(el[i][j + 1] - el[i][j]);
        }
    /* Where the element dips and no fold decides, the lines run across the valley, along the parameter
     * the element varies along most (fig. 2c: across the rounded fold) */
    if (cross[0] == cross[1] && least < FACE_EST_MIN * big)
        cross[1] += vary[1] > vary[0], cross[0] += vary[0] > vary[1];
    f->la = c->flat >= 0 ? 1 - c->flat : cross[1] > cross[0];
    const int lb = 1 - f->la, na = rule_points(c->f[f->la] * h[f->la]);
    const int nb = lb == c->flat ? 1 : rule_points(c->f[lb] * h[lb]);
    const double hb = lb == c->flat ? 1.0 : h[lb];   /* a flat parameter: one point, weight 1 */
    const int ka = f->o[f->la], kb = f->o[lb];
    q->tab_ok = 0;
    tab_fill(q, f->axis, f->side, f->side, 0);
    tab_fill(q, ka, lo[f->la], lo[f->la] + h[f->la], na);
    tab_fill(q, kb, lo[lb], lo[lb] + h[lb], nb);
    int idx[3];
    idx[f->axis] = 0;
    double total = 0.0, fl, tail, lines[GMAX], range[2] = { INFINITY, 0.0 };
    *flux = 0.0, *est = 0.0;
    for (int i = 0; i < nb; i++) {
        idx[kb] = i + 1;
        line_set(q, ka, idx);
        lines[i] = face_line_integral(f, lo[f->la], lo[f->la] + h[f->la], na, q->gw[na], &fl, &tail, range);
        total += hb * q->gw[nb][i] * lines[i];
        *flux += hb * q->gw[nb][i] * fl;
        *est += hb * q->gw[nb][i] * tail;
    }
    if (nb > 1)
        *est += hb * legendre_tail(lines, nb);
    if (!(range[0] >= FACE_EST_MIN * range[1]))
        *est = INFINITY;   /* the element nears 0: a fold may lie between the nodes */
    return total;
}

/* A panel against its four quarters, each with its own lines, and so on where they differ; a panel
 * whose own estimate (face_panel's est) is below FACE_EST tolerances is not split (on fig. 2c and
 * 4a-c, such panels differed from their quarters by at most 0.14 tolerance; their quarters were
 * computed only to find that out). */
static double face_refine(face_ctx *c, const double lo[2], const double h[2], double coarse, double est, int depth)
{
    if (!c->stopped && pde_stopped(c->cancel))
        c->stopped = 1;
    if (!(est > FACE_EST * c->tol)) {   /* NaN too: values beyond a double refine to nothing better */
        c->left += FACE_EST_OFF * est;
        return coarse;
    }
    double q[4] = { 0, 0, 0, 0 }, ql[4][2], qe[4] = { 0, 0, 0, 0 }, fine = 0.0;
    const double hh[2] = { c->flat == 0 ? h[0] : 0.5 * h[0], c->flat == 1 ? h[1] : 0.5 * h[1] };
    for (int k = 0; k < 4; k++) {
        ql[k][0] = lo[0] + (k & 1) * hh[0], ql[k][1] = lo[1] + (k >> 1) * hh[1];
        if (c->flat >= 0 && (k >> c->flat & 1))
            continue;   /* halves, not quarters, of a separable face */
        double fl;
        fine += q[k] = face_panel(c, ql[k], hh, &fl, &qe[k]);
    }
    const double diff = fabs(fine - coarse);
    if (c->stopped || c->line.q->r.evals * c->line.q->modes >= REFINE_WORK || !(diff > c->tol) ||
        depth + 1 >= FACE_DEPTH_MAX || (depth + 1 >= FACE_DEPTH && !(diff > FACE_DEEP * c->tol))) {
        c->left += diff;   /* the error left is about this, or less where it converges */
        return fine;
    }
    double sum = 0.0;
    for (int k = 0; k < 4; k++)
        if (c->flat < 0 || !(k >> c->flat & 1))
            sum += face_refine(c, ql[k], hh, q[k], qe[k], depth + 1);
    return sum;
}

/*
 * Where det J separates along t (quad_separate), a face of another axis has the parameters t and p,
 * and x_t x x_p = n t^(n-1) (t^n A(p) + B(p)): A from pairs of components with in = 1, B from
 * pairs of one with in = 1 and one without, whose p-partials make it. With ns = 1, A = 0; with
 * ns >= 2, B = 0 when every component with in = 0 is constant along p (p is u or v and its
 * modes' factors of p are 1). Then the face's area is the integral along its line t = 1 times
 * ascale (1/n: the integral of n t^(n-1); 1/(2n): of n t^(2n-1), each over n at t = 1), and its
 * flux x . (x_t x x_p) the same times fscale (x_e adds t^n when e has in = 1: ns = 3).
 * Returns the index (0, 1) of t among the face's parameters, or -1.
 */
static int face_separates(const pde_solution *s, const quad_sep *sp, int axis, double *ascale, double *fscale)
{
    if (sp->axis < 0 || axis == sp->axis)
        return -1;
    const int p = 3 - axis - sp->axis;   /* the face's other parameter */
    const double n = sp->n;
    if (sp->ns == 1) {
        *ascale = *fscale = 1.0 / n;
    } else {
        for (int c = 0; c < 3; c++)
            for (size_t m = 0; !sp->in[c] && m < s->comp[c].nmodes; m++) {
                const pde_mode *md = &s->comp[c].modes[m];
                if (p == 2 || (p == 0 ? md->u : md->v).kind != PDE_POW || (p == 0 ? md->u : md->v).p != 0)
                    return -1;
            }
        *ascale = 1.0 / (2.0 * n);
        *fscale = 1.0 / ((sp->ns == 2 ? 2.0 : 3.0) * n);
    }
    return sp->axis < p ? 0 : 1;
}

/*
 * An end cap w = side where two components are harmonic alike and the third is a function of w alone
 * (fig. 2 and 4): x_a = t^n (alpha(w) S + beta(w) C), x_b = t^n (gamma(w) S + delta(w) C), S, C =
 * sin, cos(k pi s), the same t (u or v), n >= 1 and k for both, x_z = Z(w). On the cap the element
 * x_u x x_v has only its z component, the (u, v) minor of rows a, b: +-n k pi t^(2n-1) (beta gamma -
 * alpha delta) (S^2 + C^2 = 1), so the cap's area is |k pi (beta gamma - alpha delta)| / 2 (the
 * integral of n t^(2n-1) is 1/2) and its flux Z times the signed same, exactly: the panels' lines and
 * their check against quarters took fig. 4a's two caps 0.12 M instructions. Returns 0 where the
 * solid is not so.
 */
static int face_cap(const pde_solution *s, int side, double *area, double *flux)
{
    int zc = -1, nab = 0, t = -1;
    double n = 0.0, k = 0.0, co[2][2] = { { 0, 0 }, { 0, 0 } }, Z = 0.0;   /* co[i]: alpha, beta of ab[i] */
    for (int c = 0; c < 3; c++) {
        const comp_solution *cs = &s->comp[c];
        int wonly = 1;
        for (size_t m = 0; m < cs->nmodes && wonly; m++)
            wonly = cs->modes[m].u.kind == PDE_POW && cs->modes[m].u.p == 0.0 && cs->modes[m].v.kind == PDE_POW &&
                    cs->modes[m].v.p == 0.0;
        if (wonly && zc < 0) {
            zc = c;
            continue;
        }
        if (nab == 2 || cs->nmodes == 0)
            return 0;
        for (size_t m = 0; m < cs->nmodes; m++) {
            const pde_mode *md = &cs->modes[m];
            if (t < 0)
                t = md->u.kind == PDE_POW ? 0 : 1, n = (t ? md->v : md->u).p, k = (t ? md->u : md->v).p;
            const pde_factor ft = t ? md->v : md->u, fs = t ? md->u : md->v;
            if (ft.kind != PDE_POW || ft.p != n || n < 1.0 || (fs.kind != PDE_SIN && fs.kind != PDE_COS) ||
                fs.p != k || k == 0.0)
                return 0;
            double h, dh;
            mode_h(md, side, &h, &dh);
            co[nab][fs.kind == PDE_COS] += h;
        }
        nab++;
    }
    if (zc < 0 || nab != 2)
        return 0;
    for (size_t m = 0; m < s->comp[zc].nmodes; m++) {
        double h, dh;
        mode_h(&s->comp[zc].modes[m], side, &h, &dh);
        Z += h;
    }
    /* the (u, v) minor of the harmonic rows a < b: +(x_t y_s - y_t x_s) with t = u; the element's
     * component zc has the sign of the permutation (a, b, zc) */
    const double minor = k * M_PI * (co[0][1] * co[1][0] - co[0][0] * co[1][1]) * (t ? -1.0 : 1.0);
    const double eps = zc == 1 ? -1.0 : 1.0;
    *area = 0.5 * fabs(minor);
    *flux = 0.5 * eps * Z * minor;
    return 1;
}

/*
 * A face along whose parameters the solution is a polynomial, of degrees d0 and d1 (within one slab):
 * its element c = x_a x x_b is a polynomial of degree at most 2 d - 1 along each, so when c x nu
 * vanishes on a grid of (2 d + 1)^2 points, to rounding, nu a unit vector, it vanishes everywhere:
 * the face is planar, c = g nu, and |c| = |g|, a polynomial. Where g keeps its sign on the grid and
 * at the rule's nodes, the face's area is |the integral of g| and its flux the integral of x . c, by
 * rules exact on them (3 d / 2 + 1 points). Returns 0, with nothing set, where it does not apply.
 */
static int face_planar(const pde_solution *s, const poly3 *px, int axis, int side, const int d[2], double *area,
                       double *flux)
{
    double x[3], ta[3], tb[3], c[2 * GMAX + 1][3], big = 0.0, nu[3] = { 0, 0, 0 };
    const int n0 = 2 * d[0] + 1, n1 = 2 * d[1] + 1;
    if (n0 * n1 > 2 * GMAX + 1)
        return 0;
    for (int i = 0; i < n0; i++)
        for (int j = 0; j < n1; j++) {
            double *e = c[i * n1 + j];
            face_point(s, px, axis, side, n0 > 1 ? (double)i / (n0 - 1) : 0.5, n1 > 1 ? (double)j / (n1 - 1) : 0.5,
                       x, ta, tb);
            e[0] = ta[1] * tb[2] - ta[2] * tb[1], e[1] = ta[2] * tb[0] - ta[0] * tb[2], e[2] = ta[0] * tb[1] - ta[1] * tb[0];
            const double m = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            if (m > big)
                big = m, nu[0] = e[0] / m, nu[1] = e[1] / m, nu[2] = e[2] / m;
        }
    const double tol = 1e-13 * big;
    int pos = 0, neg = 0;
    for (int k = 0; k < n0 * n1; k++) {
        const double *e = c[k];
        const double cx[3] = { e[1] * nu[2] - e[2] * nu[1], e[2] * nu[0] - e[0] * nu[2], e[0] * nu[1] - e[1] * nu[0] };
        if (fabs(cx[0]) > tol || fabs(cx[1]) > tol || fabs(cx[2]) > tol)
            return 0;
        const double g = e[0] * nu[0] + e[1] * nu[1] + e[2] * nu[2];
        pos |= g > tol, neg |= g < -tol;
    }
    const int m0 = 3 * d[0] / 2 + 1, m1 = 3 * d[1] / 2 + 1;
    double sa = 0.0, sf = 0.0;
    for (int i = 0; i < m0; i++)
        for (int j = 0; j < m1; j++) {
            face_point(s, px, axis, side, rules_x[m0][i], rules_x[m1][j], x, ta, tb);
            const double e[3] = { ta[1] * tb[2] - ta[2] * tb[1], ta[2] * tb[0] - ta[0] * tb[2], ta[0] * tb[1] - ta[1] * tb[0] };
            const double g = e[0] * nu[0] + e[1] * nu[1] + e[2] * nu[2], wt = rules_w[m0][i] * rules_w[m1][j];
            pos |= g > tol, neg |= g < -tol;
            sa += wt * g;
            sf += wt * (x[0] * e[0] + x[1] * e[1] + x[2] * e[2]);
        }
    if (pos && neg)
        return 0;   /* the face folds over itself: the general path locates the fold */
    *area = fabs(sa);
    *flux = sf;
    return 1;
}

/*
 * A curved face of a polynomial solid: its element c = x_a x x_b is a polynomial, and so are |c|^2
 * and the flux x . c, whose integral is exact from its coefficients. Where |c|^2 is certified
 * (poly_minimise) above FACE_POLY_MIN of its largest Bernstein coefficient over the face, there is
 * no fold and no cusp, |c| = sqrt(|c|^2) is analytic on the face, and Gauss rules converge
 * geometrically on it: each panel's POLY_RULE-point rule (along each parameter |c|^2 depends on)
 * against twice as many, the finer accepted where they agree within the panel's share of tol, else
 * the panel halved along those parameters, down to POLY_DEPTH halvings; points from |c|^2's
 * power coefficients, not from the solution's factors. Returns 0 where this does not apply: the
 * general path then (its panels and refinement took fig. 1e 3.7 M instructions).
 */
#define POLY_RULE 6
#define POLY_DEPTH 6
#define FACE_POLY_MIN 1e-4

typedef struct {
    const poly3 *e2;
    int o[2], vary[2];
    double tol;
    int ok;
} poly_face;

/* The n-point rule (one point where |c| does not vary) of |c| over the panel lo + [0, h]. */
static double poly_face_rule(const poly_face *f, const double lo[2], const double h[2], int n)
{
    const int m[2] = { f->vary[0] ? n : 1, f->vary[1] ? n : 1 };
    double sum = 0.0, at[3] = { 0, 0, 0 };
    for (int i = 0; i < m[0]; i++)
        for (int j = 0; j < m[1]; j++) {
            at[f->o[0]] = lo[0] + h[0] * rules_x[m[0]][i], at[f->o[1]] = lo[1] + h[1] * rules_x[m[1]][j];
            sum += rules_w[m[0]][i] * rules_w[m[1]][j] * sqrt(fmax(poly_eval(f->e2, at), 0.0));
        }
    return h[0] * h[1] * sum;
}

static double poly_face_adapt(poly_face *f, const double lo[2], const double h[2], double coarse, int depth)
{
    const double fine = poly_face_rule(f, lo, h, 2 * POLY_RULE);
    if (!(fabs(fine - coarse) > f->tol * h[0] * h[1]))   /* or NaN: no refinement mends it */
        return fine;
    if (depth == POLY_DEPTH) {
        f->ok = 0;
        return fine;
    }
    const double hh[2] = { f->vary[0] ? 0.5 * h[0] : h[0], f->vary[1] ? 0.5 * h[1] : h[1] };
    double sum = 0.0;
    for (int k = 0; k < 4 && f->ok; k++) {
        if ((k & 1 && !f->vary[0]) || (k & 2 && !f->vary[1]))
            continue;
        const double ql[2] = { lo[0] + (k & 1) * hh[0], lo[1] + (k >> 1) * hh[1] };
        sum += poly_face_adapt(f, ql, hh, poly_face_rule(f, ql, hh, POLY_RULE), depth + 1);
    }
    return sum;
}

static int face_poly(const poly3 *px, int axis, int side, double tol, double *area, double *flux)
{
    poly3 *e2 = malloc(2 * sizeof *e2);
    if (!e2)
        return 0;
    poly_face f = { .e2 = e2, .tol = tol, .ok = poly_face_element(px, axis, side, e2, flux) };
    for (int k = 0, m = 0; k < 3; k++)
        if (k != axis)
            f.o[m++] = k;
    if (f.ok) {
        /* A parameter |c|^2 does not depend on (a coefficient of a power of it not 0): one point along it. */
        const int *n = e2->n;
        for (int q = 0; q < n[0] * n[1] * n[2]; q++) {
            const int idx[3] = { q / (n[1] * n[2]), q / n[2] % n[1], q % n[2] };
            for (int k = 0; k < 2; k++)
                f.vary[k] |= idx[f.o[k]] > 0 && e2->c[q] != 0.0;
        }
        /* Only the powers of the parameters |c|^2 depends on: fewer terms a point. */
        for (int k = 0; k < 2; k++)
            if (!f.vary[k]) {
                const int a = f.o[k], m[3] = { n[0], n[1], n[2] };
                e2->n[a] = 1;
                for (int q = 0; q < e2->n[0] * e2->n[1] * e2->n[2]; q++) {
                    const int i = q / (e2->n[1] * e2->n[2]), j = q / e2->n[2] % e2->n[1], l = q % e2->n[2];
                    e2->c[q] = e2->c[(i * m[1] + j) * m[2] + l];
                }
            }
        e2[1] = e2[0];
        poly_bernstein(&e2[1]);
        double hi = 0.0;
        for (int q = 0; q < e2[1].n[0] * e2[1].n[1] * e2[1].n[2]; q++)
            hi = fmax(hi, e2[1].c[q]);
        bb_result r;
        f.ok = hi > 0.0 && poly_minimise(&e2[1], 1.0, 0.5 * FACE_POLY_MIN * hi, 200, &r) == PDE_OK &&
               r.lower >= 0.5 * FACE_POLY_MIN * hi;
    }
    if (f.ok) {
        const double lo[2] = { 0, 0 }, h[2] = { 1, 1 };
        *area = poly_face_adapt(&f, lo, h, poly_face_rule(&f, lo, h, POLY_RULE), 0);
    }
    free(e2);
    return f.ok;
}

/* param_rotation along u and v, found once (known) for all the faces. */
typedef struct {
    int known[2], has[2];
    qsym sy[2];
} face_rot;

/*
 * A face repeats itself along its parameter t (u or v) where the solid does: where t -> t + 1/k maps
 * x to A x (A orthogonal), x_a x x_b goes to det A A (x_a x x_b), so the element |x_a x x_b| is the
 * same and the flux x . (x_a x x_b) det A times the same; mirrored, t -> 1/k - t mapping x to H x
 * with the tangent along t reversed, -det H times. So one period, or half of one mirrored, is
 * integrated, times its copies. A reflection or half-turn A = diag(+-1) (param_symmetry: fig. 2 and
 * 4) where the period is a whole number of the face's *np panels, which stay; else a rotation about
 * an axis (param_rotation: fig. 3a, 3b, det A = 1), the period with panels of its own, as wide as
 * the face's or narrower: *div per unit of t, so that every panel edge falls on a multiple of
 * 1/(k half) and the fold's handling (face_line_integral) sees each of the period's dips whole.
 * With period 0 (tests), no period is used: the whole face, with the same panels. Returns the
 * copies k (1: none) and sets *np (panels integrated), *div (0: the plan's edges), *half (2:
 * mirrored), det A into *det and -det H into *rdet (0: no mirror).
 */
static int face_period(const pde_solution *s, int t, int period, face_rot *rot, int *np, int *div, int *half,
                       double *det, double *rdet)
{
    int d[3], m[3], k = param_symmetry(s, t, d, m);
    if (k < 2 || *np % k) {
        if (!rot->known[t])   /* its 16 points' checks once per parameter, not per face */
            rot->has[t] = param_rotation(s, t, &rot->sy[t]), rot->known[t] = 1;
    }
    const qsym sy = rot->sy[t];
    if (k >= 2 && *np % k == 0) {
        *det = d[0] * d[1] * d[2];
        *rdet = m[0] ? -m[0] * m[1] * m[2] : 0.0;
        *half = *rdet != 0.0 && *np % (2 * k) == 0 ? 2 : 1;
        if (*half == 1)
            *rdet = 0.0;
        *div = 0;
        *np /= period ? k * *half : 1;
    } else if (rot->has[t]) {
        k = sy.k, *half = sy.half;
        *det = det33(sy.R);
        *rdet = sy.half == 2 ? -det33(sy.H) : 0.0;
        const int n = (*np + k * *half - 1) / (k * *half);   /* panels per period */
        *div = n * k * *half;
        *np = period ? n : *div;
    } else
        return 1;
    if (!period)
        *half = 1, *det = 1.0, *rdet = 0.0, k = 1;
    return k;
}

/*
 * The skin's area: each face's panels (sized to the element's frequencies, counted like the
 * solid's integrals as five factors') along lines that locate the cuspidal edges of a folded
 * face. Each panel is checked against its quarters and refined where they differ by more than
 * 1e-13 of the solid's size squared, down to FACE_DEPTH halvings (in a small panel the lines
 * cross an edge rather than touch it), for the first FACE_REFINE panels.
 */
pde_status quad_area_period(const pde_solution *s, double size, int period, const pde_cancel *cancel, double *area,
                            quad_result *info)
{
    face_ctx *c = calloc(1, sizeof *c);
    qctx *q = qctx_new(s, cancel);
    poly3 *px = malloc(3 * sizeof *px);   /* a polynomial solid's x, y, z, or NULL */
    if (!c || !q) {
        free(c);
        free(px);
        qctx_free(q);
        return PDE_ERR_NOMEM;
    }
    if (px && !poly_solution(s, px)) {
        free(px);
        px = NULL;
    }
    qplan p;
    plan_for(s, 5.0, 0, &p);   /* the faces' panels sized to the frequencies even along a polynomial axis: a
                                 * curved face refines less from smaller panels (planar ones: face_planar) */
    double f[3];
    frequencies(s, 5.0, f);
    quad_sep sp;
    quad_separate(s, &sp);
    c->tol = 1e-11 * size * size;
    c->cancel = cancel;
    size_t nslabs;
    solution_breaks(s, &nslabs);
    /* Where det J separates, the faces of another axis are lines: the budget of refined panels
     * goes to the rest (fig. 3b's area 1.1e-5 -> 1.6e-8 of the reference quadrature's). */
    c->max_refined = sp.axis >= 0 ? INT_MAX : FACE_REFINE;
    double total = 0.0, flux = 0.0, left = 0.0;   /* left: the area's estimated error */
    int panels = 0;   /* faces integrated on the plan's panels, whose a-priori error stands */
    face_rot rot = { .known = { 0, 0 } };
    for (int axis = 0; axis < 3 && !c->stopped; axis++) {
        if (faces_coincide(s, px, axis, size))
            continue;   /* both lie inside the solid, as api/mesh.c drops them */
        int o[2], m = 0;
        for (int k = 0; k < 3; k++)
            if (k != axis)
                o[m++] = k;
        c->f[0] = f[o[0]], c->f[1] = f[o[1]];
        for (int side = 0; side < 2; side++) {
            /* Where det J separates with ns >= 2, x_c = 0 on t = 0 but for one component at most:
             * the face is a curve or a point, its area and flux exactly 0 (quad_separate). */
            if (axis == sp.axis && side == 0 && sp.ns >= 2)
                continue;
            double ascale = 1.0, fscale = 1.0, face = 0.0, fflux = 0.0;
            const int d[2] = { q->poly[o[0]], q->poly[o[1]] };
            if ((axis == 2 && nslabs == 1 && face_cap(s, side, &face, &fflux)) ||
                (d[0] >= 0 && d[1] >= 0 && (axis == 2 || nslabs == 1) && face_planar(s, px, axis, side, d, &face, &fflux)) ||
                (px && face_poly(px, axis, side, c->tol, &face, &fflux))) {
                flux += (side ? 1.0 : -1.0) * (axis == 1 ? -1.0 : 1.0) * fflux;
                total += face;
                continue;
            }
            if (!(period & QUAD_GENERAL)) {   /* a face of one harmonic along u or v (harm.h) */
                const harm_opts ho = { .edge = p.edge[2], .np = p.np[2], .x = q->gx[HARM_RULE], .wt = q->gw[HARM_RULE],
                                       .n = HARM_RULE, .tol = HARM_TOL * size * size, .size = size, .cancel = cancel };
                const int h = harm_face(s, axis, side, &ho, &face, &fflux, &q->r.evals);
                if (h < 0)
                    c->stopped = 1;
                if (h) {
                    flux += (side ? 1.0 : -1.0) * (axis == 1 ? -1.0 : 1.0) * fflux;
                    total += face;
                    left += ho.tol;   /* its rules' tolerance over the unit of w */
                    continue;
                }
            }
            panels = 1;
            c->line = (face_line){ .q = q, .axis = axis, .side = side, .o = { o[0], o[1] } };
            c->flat = face_separates(s, &sp, axis, &ascale, &fscale);
            /* np[k] panels along the face's parameter k: p's edges, or [i, i + 1] / div[k] where div[k] > 0
             * (the panels of a period, face_period) */
            int np[2] = { c->flat == 0 ? 1 : p.np[o[0]], c->flat == 1 ? 1 : p.np[o[1]] }, div[2] = { 0, 0 };
            int per = 1, half = 1;
            double fdet = 1.0, rdet = 0.0;
            for (int k = 0; k < 2 && per == 1; k++)
                if (o[k] <= 1 && k != c->flat)
                    per = face_period(s, o[k], period & QUAD_PERIOD, &rot, &np[k], &div[k], &half, &fdet, &rdet);
            double change = 0.0;   /* what refinement changed, over the panels refined */
            int nref = 0, nleft = 0;
            c->left = 0.0;
            for (int pa = 0; pa < np[0] && !c->stopped; pa++)
                for (int pb = 0; pb < np[1] && !c->stopped; pb++) {
                    const int i[2] = { pa, pb };
                    double lo[2], h[2];
                    for (int k = 0; k < 2; k++) {
                        const double *e = p.edge[o[k]];
                        lo[k] = div[k] ? (double)i[k] / div[k] : e[i[k]];
                        h[k] = div[k] ? 1.0 / div[k] : e[i[k] + 1] - e[i[k]];
                    }
                    if (c->flat >= 0)   /* the line t = 1 of the face */
                        lo[c->flat] = 1.0, h[c->flat] = 0.0;
                    if (pde_stopped(cancel))   /* a panel of a face */
                        c->stopped = 1;
                    double fl, est, a = face_panel(c, lo, h, &fl, &est);
                    fflux += fl;
                    if (c->refined++ >= c->max_refined || q->r.evals * q->modes >= REFINE_WORK) {
                        face += a, nleft++;
                    } else {
                        const double fine = face_refine(c, lo, h, a, est, 0);
                        face += fine, change += fabs(fine - a), nref++;
                    }
                }
            /* panels the work's bound left unrefined: what refinement changed on the others, on average */
            if (nleft)
                c->left += nref ? nleft * change / nref : fabs(face);
            /* Outward: side 1 along +axis; (o0, o1, axis) is odd for axis 1. */
            double fsum = 0.0, sig = 1.0;   /* the periods' fluxes: det R^j times the first's, and its mirror's */
            for (int j = 0; j < per; j++, sig *= fdet)
                fsum += sig;
            if (half == 2)
                fsum *= 1.0 + rdet;
            flux += (side ? 1.0 : -1.0) * (axis == 1 ? -1.0 : 1.0) * fscale * fsum * fflux;
            total += ascale * per * half * face;
            left += ascale * per * half * c->left;
        }
    }
    pde_status st = c->stopped ? PDE_ERR_CANCELLED : PDE_OK;
    free(c);
    free(px);
    if (st == PDE_OK) {
        *area = total;
        /* Faces by their exact or adaptive 1-D paths (planar, polynomial, harm.h) have none of the panels'
         * error: the lofts' skin and caps, whose plan the work's bound made coarse (tower: 2). */
        q->r.err = panels ? p.err : fmin(p.err, 1e-14);
        q->r.acc[Q_SIGNED] = flux / 3.0;
        q->r.area_left = left;
        *info = q->r;
    }
    qctx_free(q);
    return st;
}

pde_status quad_area(const pde_solution *s, double size, const pde_cancel *cancel, double *area, quad_result *info)
{
    return quad_area_period(s, size, QUAD_PERIOD, cancel, area, info);
}
