/*
 * pde.h: the closed-form solver for the fourth-order PDE solid.
 *
 * For each component i of x = (x, y, z), on (u, v, w) in [0,1]^3,
 *
 *     a_i x_uuuu + b_i x_vvvv + c_i x_wwww = p_i(u, v, w)            (paper eq. 1)
 *
 * with x and x_w given on w = 0 and w = 1 (eq. 2). Boundary data are sums of
 * separable terms f(u) f(v) (eq. 3), forces are sums of coef f(u) f(v) f(w).
 *
 * USAGE
 *
 *   pde_model m = {0};                      // fill m.comp[0..2]
 *   pde_solution *sol;
 *   pde_diag diag;
 *   if (pde_solve(&m, &sol, &diag) != PDE_OK) { puts(diag.message); ... }
 *   double x[3];
 *   pde_eval(sol, u, v, w, x);
 *   pde_solution_free(sol);
 *
 * Plan, then execute (as FFTW does): pde_solve() does all the work once and
 * builds an immutable solution. Every other call takes the solution const and
 * may run on any number of threads at once. A pde_grid holds scratch memory
 * and belongs to one thread at a time; make one per thread.
 *
 * OWNERSHIP
 *
 * pde_solve() copies what it needs from the model; the model may be freed
 * afterwards. The solution is freed with pde_solution_free(), a grid with
 * pde_grid_free(); both accept NULL. Pointers returned by pde_solution_modes()
 * live as long as the solution.
 *
 * ERRORS
 *
 * Every fallible call returns a pde_status; results come back through
 * out-parameters, which are left untouched on error. No call aborts or writes
 * global state. pde_solve() also fills a pde_diag naming the component, the
 * term and the field at fault.
 */
#ifndef PDE_H
#define PDE_H

#include <stddef.h>

typedef enum {
    PDE_OK = 0,        /* success */
    PDE_ERR_NOMEM,     /* an allocation failed */
    PDE_ERR_INVALID,   /* a number is not finite, or a factor is malformed */
    PDE_ERR_ILLPOSED,  /* the equation is not fourth order in w (c_i = 0) */
    PDE_ERR_SINGULAR,  /* the boundary problem has no unique solution */
    PDE_ERR_RANGE,     /* a value of the model or solution overflows a double */
    PDE_ERR_LIMIT,     /* the model exceeds a size limit below */
    PDE_ERR_CANCELLED  /* the caller's pde_cancel asked the call to stop */
} pde_status;

/* A sentence describing the status; never NULL. */
const char *pde_strerror(pde_status status);

/*
 * Cooperative cancellation. The long calls (pde_solve_ex, pde_properties,
 * and api/'s mesh and output builders) call stop(arg) between bounded pieces
 * of work, a mode of a solve, a row of a mesh face, about a millisecond of the
 * properties: about 1 to 5 ms of work at most between two polls. Once stop() returns non-zero the call frees what it
 * made and returns PDE_ERR_CANCELLED, leaving its out-parameters untouched.
 * stop() runs on the caller's thread; a deadline check (clock_gettime) or an
 * atomic flag is what it is for. A NULL pde_cancel *, or a NULL stop, never
 * stops.
 */
typedef struct {
    int (*stop)(void *arg);
    void *arg;
} pde_cancel;

/* Limits that keep one solve bounded in time and memory. */
#define PDE_MAX_POW   100    /* largest n of a t^n factor */
#define PDE_MAX_ARG   700.0  /* largest |alpha| of exp, sinh, cosh: e^700 < DBL_MAX */
#define PDE_MAX_FREQ  1e6    /* largest |k| of sin, cos: beyond, k pi t has no digits left */
#define PDE_MAX_MODES 4096   /* separated (u, v) modes per component */

/* A one-variable factor f(t). A zeroed factor is {PDE_POW, 0}, the constant 1. */
typedef enum {
    PDE_POW = 0,  /* t^n, n an integer in [0, PDE_MAX_POW] */
    PDE_SIN,      /* sin(k pi t) */
    PDE_COS,      /* cos(k pi t) */
    PDE_EXP,      /* exp(alpha t) */
    PDE_SINH,     /* sinh(alpha t) */
    PDE_COSH      /* cosh(alpha t) */
} pde_factor_kind;

typedef struct {
    pde_factor_kind kind;
    double p;     /* n, k or alpha */
} pde_factor;

/* A boundary term: f(u) f(v) times w0 at w = 0, dw0 as x_w at w = 0, and so on. */
typedef struct {
    pde_factor u, v;
    double w0, dw0, w1, dw1;
} pde_bterm;

/* A force term: coef f(u) f(v) f(w). */
typedef struct {
    double coef;
    pde_factor u, v, w;
} pde_fterm;

typedef struct {
    double a, b, c;
    const pde_bterm *bterms;
    size_t nbterms;
    const pde_fterm *fterms;
    size_t nfterms;
} pde_component;

typedef struct {
    pde_component comp[3];   /* x, y, z */
} pde_model;

/* Where and why pde_solve() failed. term is -1 when no term is at fault. */
typedef struct {
    int component;        /* 0, 1, 2, or -1 */
    int in_force;         /* 1: term indexes fterms; 0: bterms */
    long term;            /* index of the term, or -1 */
    int section;          /* a loft's section (pde_solve_loft), or -1 */
    char field[8];        /* "a", "b", "c", "u", "v", "w", "coef", "w0", ... or "" */
    char message[240];    /* a sentence for a person */
} pde_diag;

typedef struct pde_solution pde_solution;

/*
 * Solves the model. On success stores a new solution in *out. On failure
 * returns the status, leaves *out unchanged and, if diag is not NULL,
 * describes the failure there. Terms with equal factors add up; a term
 * whose factor is identically zero (sin 0, sinh 0) contributes nothing.
 */
pde_status pde_solve(const pde_model *model, pde_solution **out, pde_diag *diag);

/* A zeroed options struct (or NULL) gives pde_solve(). cancel is polled between modes. */
typedef struct {
    const pde_cancel *cancel;
} pde_solve_opts;

pde_status pde_solve_ex(const pde_model *model, const pde_solve_opts *opts, pde_solution **out,
                        pde_diag *diag);

void pde_solution_free(pde_solution *sol);

/*
 * The canonical form of a model, which equal models share however they are
 * written: factors normalised (sin(-k) -> -sin(k), cos 0 -> 1, ...), terms
 * with equal factors merged (sums independent of the order of the terms),
 * terms that vanish dropped, terms sorted, -0 made +0. It solves to the same
 * solution. Validates like pde_solve(). On success *out owns new term arrays:
 * free them with pde_model_canonical_free(), which accepts a zeroed model.
 */
pde_status pde_model_canonical(const pde_model *model, pde_model *out, pde_diag *diag);
void pde_model_canonical_free(pde_model *model);

/* Bytes held by the solution, for a cache's accounting. Cannot fail. */
size_t pde_solution_bytes(const pde_solution *sol);

/*
 * The closed form, read-only. Component i of x is the sum over its modes of
 * h(w) f_u(u) f_v(v), and h(w) is the sum of its terms
 *
 *     exp(alpha (w - shift)) (A(w) cos(beta w) + B(w) sin(beta w))
 *
 * with polynomials A, B of degree deg (coefficients of w^0 first) and shift
 * 1 for growing exponentials, so that no term exceeds its coefficients.
 */
typedef struct {
    double alpha, beta, shift;
    int deg;
    const double *A, *B;
} pde_wterm;

typedef struct {
    pde_factor u, v;        /* normalised: k, alpha >= 0 except for exp */
    double e;               /* h'''' = e h + force: e = -(a lu + b lv) / c (eq. 8) */
    size_t nterms;
    const pde_wterm *terms; /* every slab's terms, slab by slab */
    /* h is piecewise along w: on slab s, breaks[s] <= w <= breaks[s + 1], it is the sum of
     * terms[first[s]] .. terms[first[s + 1] - 1]. A model has one slab, [0, 1]; a loft one per pair of
     * neighbouring sections. Every mode of a solution has the same breaks. Below 0 the first slab's
     * terms hold, above 1 the last's; at an interior break, the slab on its right. */
    size_t nslabs;
    const double *breaks;   /* nslabs + 1 values, 0 first and 1 last */
    const size_t *first;    /* nslabs + 1 offsets into terms; first[nslabs] = nterms */
} pde_mode;

const pde_mode *pde_solution_modes(const pde_solution *sol, int comp, size_t *nmodes);

/*
 * Lofts: solids through K >= 2 sections at 0 = w_0 < w_1 < ... < w_(K-1) = 1 (docs/MATH.md,
 * "Lofts"). Between sections each component solves a x_uuuu + b x_vvvv + c x_wwww = 0 (no force).
 * At section k every term gives x (the factor times x[k]); a section with tangent set also gives
 * x_w (the factor times xw[k]). The conditions:
 *   an end section with a tangent:         x and x_w given (clamped);
 *   an end section without one:            x given and x_ww = 0 (natural);
 *   an interior section with a tangent:    x and x_w given on both sides;
 *   an interior section without one:       x given, x_w and x_ww continuous across it (C2).
 * Each mode's h(w) is then one exponential polynomial per slab between neighbouring sections
 * (pde_mode's breaks). pde_solve_loft() validates like pde_solve(); diag->section names the section
 * at fault, and a singular slab problem names the slab and the mode in the message.
 */
#define PDE_MAX_SECTIONS 64

typedef struct {
    double w;
    int tangent;            /* non-zero: x_w is given at this section */
} pde_section;

/* A term of a loft: f(u) f(v) times x[k] at section k, and times xw[k] as x_w at a section with a
 * tangent. x has nsections values; so has xw, which may be NULL when no section has a tangent. */
typedef struct {
    pde_factor u, v;
    const double *x;
    const double *xw;
} pde_lterm;

typedef struct {
    double a, b, c;
    const pde_lterm *terms;
    size_t nterms;
} pde_lcomponent;

typedef struct {
    const pde_section *sections;
    size_t nsections;           /* 2 .. PDE_MAX_SECTIONS */
    pde_lcomponent comp[3];
    double fit_error;           /* how far the caller's data lies from these terms (a fit's error); the
                                 * solution keeps it and pde_properties() reports it; 0 if exact */
} pde_loft;

pde_status pde_solve_loft(const pde_loft *loft, const pde_solve_opts *opts, pde_solution **out,
                          pde_diag *diag);

/* The worst 1-norm condition estimate among a loft's slab systems (docs/MATH.md, "Lofts"), and the
 * component and index (into pde_solution_modes) of a mode it belongs to; comp and mode may be NULL.
 * 1 for a model, with *comp = -1. A loft with condition above 1e12 is refused as singular. */
double pde_solution_condition(const pde_solution *sol, int *comp, size_t *mode);

/* x(u, v, w). Cannot fail; any point is accepted, [0,1]^3 is the solid. */
void pde_eval(const pde_solution *sol, double u, double v, double w, double x[3]);

/* x and its first partial derivatives; any of the outputs may be NULL. */
void pde_eval_d(const pde_solution *sol, double u, double v, double w,
                double x[3], double xu[3], double xv[3], double xw[3]);

/* det J = det(x_u, x_v, x_w) at (u, v, w). */
double pde_eval_detj(const pde_solution *sol, double u, double v, double w);

/* 1 if the solid has no volume: det J is 0 (against Hadamard's bound, 1e-12) at 64 interior points, so the
 * solid is a surface, a curve or a point (a loft of zero sections), and a mesh of it would be all flat cells.
 * A cheap test for outputs; pde_properties' certified det J range is the exact one. */
int pde_solution_is_flat(const pde_solution *sol);

/* d^(nu+nv+nw) x_comp / du^nu dv^nv dw^nw, for any orders (residuals, tests). */
double pde_eval_partial(const pde_solution *sol, int comp, double u, double v, double w,
                        int nu, int nv, int nw);

/* p_comp(u, v, w), the force of the model. */
double pde_force(const pde_solution *sol, int comp, double u, double v, double w);

/*
 * Tensor-product sampling. A grid fixes the u and v samples; each call to
 * pde_grid_plane() then fills one plane w = const, u fastest, as interleaved
 * float32 x, y, z (3 nu nv floats). Each h(w) is evaluated once per plane and
 * each f(u), f(v) once per grid, so a point costs one multiply-add per mode.
 * Faces u = 0 or 1 are grids with nu = 1, and so on.
 */
typedef struct pde_grid pde_grid;

pde_status pde_grid_create(const pde_solution *sol, const double *us, size_t nu,
                           const double *vs, size_t nv, pde_grid **out);
void pde_grid_free(pde_grid *grid);
void pde_grid_plane(pde_grid *grid, double w, float *xyz);
/* The same plane with dx/du, dx/dv, dx/dw (each 3 nu nv floats; may be NULL). */
void pde_grid_plane_d(pde_grid *grid, double w, float *xyz, float *xu, float *xv, float *xw);
/* Rows j0 <= j < j1 of the plane w only (3 nu (j1 - j0) floats each), for streaming in bounded
 * memory; h(w) is kept from the previous call when w repeats. */
void pde_grid_rows(pde_grid *grid, double w, size_t j0, size_t j1, float *xyz, float *xu, float *xv,
                   float *xw);

/* Row j of the plane w in double precision, for outputs that keep it (volume meshes): x, y, z
 * interleaved (3 nu doubles), and dx/du, dx/dv, dx/dw the same way (each may be NULL). */
void pde_grid_row_d(pde_grid *grid, double w, size_t j, double *xyz, double *xu, double *xv, double *xw);

/* Samples i/(n-1) on each axis (0.5 when n = 1) into out, 3 nu nv nw floats. */
pde_status pde_sample(const pde_solution *sol, size_t nu, size_t nv, size_t nw, float *out);

/*
 * Properties of the solid, computed from the closed form (docs/MATH.md, "Properties").
 *
 * Every integral is over the parameter cube, weighted by |det J|: where the
 * solid folds (det J changes sign), a point of space is counted as often as
 * the parametrisation covers it, and folds is set. Mass properties are at
 * unit density. The bounds are certified: every point of the solid lies in
 * [bbox_min, bbox_max], every value of det J in [detj_min, detj_max], and
 * the solid comes within bbox_gap (det J within detj_gap) of each bound.
 */
typedef struct {
    double bbox_min[3], bbox_max[3];
    double bbox_gap;         /* largest distance from a face of the box to the solid */
    double volume;           /* integral of |det J| over the unit cube */
    double signed_volume;    /* integral of det J */
    double detj_min, detj_max;     /* certified bounds of det J */
    double detj_min_found, detj_max_found;   /* the extremes found: det J at detj_min_at, detj_max_at */
    double detj_min_at[3];   /* (u, v, w) */
    double detj_max_at[3];
    double detj_gap;         /* largest distance from a bound to the extreme found */
    int folds;               /* det J takes both signs: the solid overlaps itself */
    double centroid[3];
    double inertia[3][3];    /* about the centroid: integral of (|r|^2 I - r r^T) */
    double principal_moments[3];   /* eigenvalues of inertia, ascending */
    double principal_axes[3][3];   /* principal_axes[k]: the unit axis of moment k; a right-handed frame */
    double surface_area;     /* of the closed skin: collapsed faces add nothing, inner seams are left out */
    double bc_residual;      /* largest error of x, x_w on w = 0, 1, relative to the data and force (MATH.md) */
    double pde_residual;     /* largest a x_uuuu + b x_vvvv + c x_wwww - p, relative to its largest term */
    double fit_error;        /* a loft's pde_loft.fit_error: its data against its terms (0 for a model) */
    double condition;        /* a loft's worst slab system's condition estimate (1 for a model) */
    double condition_harmonic;   /* its mode's harmonic m in v (cos, sin 2 pi m v), 0 if none */
    double integral_error;   /* the estimated error of volume, signed_volume, centroid, inertia, relative: about
                              * 1e-14 unless PDE_PROPS_WORK bounded them (docs/MATH.md) */
    double surface_area_error;   /* the estimated error of surface_area, relative (docs/MATH.md) */
} pde_props;

/* The integrals' work, at most: their rules' points times (modes + 1), beyond which the panels get
 * coarser (the error is reported); and as much again for the refinement of panels where det J may
 * change sign, and for the skin's. */
#define PDE_PROPS_WORK (6.0 * (1u << 21))

/* Boxes of one branch and bound, at most: of a coordinate's extreme, and of det J's (pde_properties),
 * whose budget grows with the solid's frequencies from PDE_PROPS_BOXES_J up to PDE_PROPS_BOXES_J_MAX. */
#define PDE_PROPS_BOXES       2000
#define PDE_PROPS_BOXES_J     1000
#define PDE_PROPS_BOXES_J_MAX 32000
#define PDE_PROPS_J_WORK      3e6    /* det J's grown budget stops at this / (modes + 3)^2 (fig. 3: 32000, tower: 1000) */

/* A zeroed options struct gives the defaults. */
typedef struct {
    int res;                    /* samples per axis of the search for extremes (the boundary residual: at least 17); 0: 9 */
    const pde_cancel *cancel;   /* polled about once per ms of work (small solids: never); NULL never stops */
} pde_props_opts;

pde_status pde_properties(const pde_solution *sol, const pde_props_opts *opts, pde_props *out);

/* The Gauss-Legendre nodes per axis that pde_properties() integrates over (for api/cost.h). */
void pde_properties_nodes(const pde_solution *sol, size_t nodes[3]);

/* The axis (0: u, 1: v) along which det J separates, so that pde_properties() integrates the solid
 * over the face of that axis at 1 alone (docs/MATH.md, "Separable solids"), or -1 (for api/cost.h). */
int pde_properties_flat_axis(const pde_solution *sol);

/* det J's branch-and-bound budget of boxes per extreme: PDE_PROPS_BOXES_J, grown with the solid's fastest
 * rate up to PDE_PROPS_BOXES_J_MAX (for api/cost.h). */
size_t pde_properties_detj_boxes(const pde_solution *sol);

/* The bytes of the branch and bound's memo of factors (core/bound.c), 0 for a solution of too many
 * modes to have one (for api/cost.h). */
size_t pde_properties_memo_bytes(const pde_solution *sol);

/* Where det J also does not depend on that face's other parameter (docs/MATH.md, "det J constant
 * along the face"): that parameter (0: u, 1: v), so that det J's bounds and the integrals' roots
 * are 1-D along w; else -1 (for api/cost.h). */
int pde_properties_free_axis(const pde_solution *sol);

/*
 * Bounds over the unit cube of |x_c| (mag[c][0]) and of |dx_c/du|, |dx_c/dv|, |dx_c/dw| (mag[c][1..3]),
 * each a sum over the modes of products of their factors' bounds (core/bound.c): never below the true
 * maximum (up to rounding), above it where modes cancel, inf or nan where a bound overflows. For
 * deciding, before sampling, whether a solid fits a narrower type (api/output.c: float32). Cannot fail.
 */
void pde_solution_magnitudes(const pde_solution *sol, double mag[3][4]);

#endif
