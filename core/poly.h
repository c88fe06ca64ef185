/*
 * poly.h: a solid that is a polynomial (every factor t^n, every h(w) a polynomial, one slab: fig. 1)
 * in the power basis, and certified ranges of polynomials over the cube from their Bernstein
 * coefficients (internal to core/; used by props.c and quad.c; docs/MATH.md "Properties").
 *
 * A poly3 is sum c[(i n1 + j) n2 + k] u^i v^j w^k, n = its degree + 1 along each axis. Over a box
 * mapped to [0, 1]^3, the same polynomial is sum b_ijk B_i(u) B_j(v) B_k(w) in the Bernstein
 * basis; the polynomial lies between its least and largest b there (the basis is >= 0 and sums to
 * 1), the corner coefficients are its values at the corners, and halving a
 * box (de Casteljau) gives its halves' coefficients, which close on the range as the square of the
 * width. poly_detj, poly_face_element and poly_minimise allocate their scratch (and free it); every
 * function is reentrant. A poly3 is 2 KB: the limits below are fig. 1's with room (at 1024
 * coefficients the scratch's allocations, trimmed back to the system and faulted in again, cost fig.
 * 1e 30 us a call).
 */
#ifndef PDE_POLY_H
#define PDE_POLY_H

#include "bound.h"

enum {
    POLY_AXIS = 16,   /* coefficients along an axis, at most (det J of degree 15: x of degree 5) */
    POLY_MAX = 256    /* coefficients in all: det J of x of degrees (1, 1, 3), fig. 1, has 160 */
};

typedef struct {
    int n[3];
    double c[POLY_MAX];
} poly3;

/* x, y, z of a polynomial solid, 1; 0 (nothing set) where s is not one or exceeds the limits. */
int poly_solution(const pde_solution *s, poly3 x[3]);

/* d/d axis of p. */
void poly_deriv(const poly3 *p, int axis, poly3 *out);

/* det J of x (its sizes 3 n - 2); 0 where memory ran out. */
int poly_detj(const poly3 x[3], poly3 *dj);

/* The Bernstein coefficients of p over the unit cube, in place. */
void poly_bernstein(poly3 *p);

/* p at (u, v, w), from its power coefficients. */
double poly_eval(const poly3 *p, const double at[3]);

/* |x_a x x_b|^2 on the face (axis, side) of x, a, b its parameters in axis order, as a poly3 of size
 * 1 along axis, and into *flux the exact integral of x . (x_a x x_b) over the face; 0 where it
 * exceeds the limits or memory ran out. */
int poly_face_element(const poly3 x[3], int axis, int side, poly3 *e2, double *flux);

/* p and its three first partials at (u, v, w). */
void poly_eval_d(const poly3 *p, const double at[3], double *v, double d[3]);

/*
 * The minimum of sign * f over the unit cube, f given by its Bernstein coefficients bern, by
 * branch and bound over boxes' Bernstein coefficients, until best - lower <= tol or `budget`
 * boxes (bb_minimise's contract, bound.h). A box whose coefficients rise (fall) along an axis
 * shrinks to its low (high) face; a box whose least coefficient is a corner's is settled, exactly.
 * Like bound.h's bounds, lower holds up to the rounding of the coefficients (a few ulps of the
 * magnitudes of the terms), which props.c's pad covers. out->at: where best is attained (a
 * corner of a box). Returns PDE_ERR_NOMEM, out unchanged, where memory ran out.
 */
pde_status poly_minimise(const poly3 *bern, double sign, double tol, size_t budget, bb_result *out);

#endif
