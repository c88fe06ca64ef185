/*
 * bound.h: derivatives of x at points, their bounds over boxes of the
 * parameter cube, and certified extremes by branch and bound (internal to
 * core/; used by props.c and quad.c).
 *
 * A box of the cube may be flat along some axes (lo == hi): a face, an edge
 * or a point. An objective is one of x, y, z (0..2) or det J (3), times a
 * sign: its model over a box is its value, gradient and Hessian at the
 * centre and a bound T of the third derivatives over the whole box, so that
 *
 *     |f(c + d) - f(c) - g.d - d'Hd/2| <= 1/6 sum_klm T_klm |d_k d_l d_m|   for c + d in the box.
 *
 * For det J of a solid that is not a polynomial, the model's rest is tighter: the exact cubic terms
 * at c plus bounds of the fourth-order ones (bounds of products lose det J's cancellation; one
 * order up, they lose it on a smaller term).
 *
 * Bounds of derivatives come from bounds of each factor's derivatives over
 * the box's intervals (factor_bounds, mode_h_bounds), combined as majorants:
 * no rounding-error analysis, so "certified" holds up to the rounding of the
 * closed form's own evaluation (about 1e-16 of its terms).
 */
#ifndef PDE_BOUND_H
#define PDE_BOUND_H

#include "internal.h"

typedef struct {
    double lo[3], hi[3];
} pbox;

enum { OBJ_DETJ = 3 };

typedef struct {
    double v, g[3], H[3][3];   /* value, gradient and Hessian at the centre */
    double T[3][3][3];         /* bounds of the third derivatives' magnitudes over the box */
    double rest;               /* a bound of |f(c + d) - f(c) - g.d - d'Hd/2| over the box: at most the sum above */
} obj_model;

/* The model of objective what (0..2: x_what, 3: det J) over b, unsigned. */
void obj_model_at(const pde_solution *s, int what, const pbox *b, obj_model *m);

/*
 * A lower bound of sign * f over b. Where sign * f is certified monotone along an axis, b shrinks
 * to the face holding the minimum, so b is changed. *val gets sign * f at the final box's centre,
 * a value the solid attains, and at that centre.
 */
double obj_lower(const pde_solution *s, int what, double sign, pbox *b, double *val, double at[3]);

/* A bound of the sum of the magnitudes of the objective's terms over the cube: the scale of the
 * rounding error of its evaluation, which a certified bound must allow for. */
double obj_magnitude(const pde_solution *s, int what);

typedef struct {
    double best;      /* smallest sign * f found, at `at` */
    double at[3];
    double lower;     /* certified: sign * f >= lower over the cube */
    size_t boxes;     /* boxes bounded */
} bb_result;

/* A binary min-heap of a branch and bound's open boxes: elements of `size` bytes, each beginning with
 * the double it is ordered by. Zeroed but for size, it is empty; free(a) frees it. */
typedef struct {
    unsigned char *a;
    size_t n, cap, size;
} bb_heap;

int bb_heap_push(bb_heap *h, const void *x);   /* -1 (h unchanged) where memory ran out */
void bb_heap_pop(bb_heap *h, void *top);       /* the least into *top; h not empty */
double bb_heap_min(const bb_heap *h);          /* the least key; h not empty */

/*
 * Minimises sign * f over the box within (NULL: the unit cube; it may be flat, a face) by branch and
 * bound, from a known point start in it, until the gap best - lower is at most tol or `budget` boxes
 * have been bounded. A box whose model is convex shrinks to where the model allows values below
 * best - tol/2 (so a gap is at most tol, and often near tol/2). stop() is polled every 16 boxes; returns PDE_ERR_CANCELLED then.
 */
pde_status bb_minimise(const pde_solution *s, int what, double sign, const double start[3], const pbox *within,
                       double tol, size_t budget, const pde_cancel *cancel, bb_result *out);

/*
 * bb_minimise where only min(sign * f, floor) is wanted (a loft's det J = t^p D1 over the face t = 1,
 * whose minimum over the cube is min(D1's, 0)): the search ends once every open box is certified
 * above best - tol or above floor - ftol, so that best - lower may exceed tol where best > floor.
 */
pde_status bb_minimise_floor(const pde_solution *s, int what, double sign, const double start[3], const pbox *within,
                             double floor, double ftol, double tol, size_t budget, const pde_cancel *cancel,
                             bb_result *out);

/*
 * props.c's extremes of a harmonic component c, x_c = t^n (alpha(w) sin k pi s + beta(w) cos k pi s)
 * with (t, s) = (u, v) or (v, u), k >= 2 (docs/MATH.md, "Harmonic components"): max_w sqrt(alpha^2 +
 * beta^2) by a branch and bound over w from start, to tol, within budget intervals. bound: certified
 * [min, max] of x_c (for the exact closed form); best, at: x_c's min and max found, and where.
 * PDE_ERR_INVALID where c is no such component (pde_properties then takes its general path).
 */
pde_status props_harmonic_extremes(const pde_solution *s, int c, double start, double tol, size_t budget,
                                   const pde_cancel *cancel, double bound[2], double best[2], double at[2][3]);

#endif
