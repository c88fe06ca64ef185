/*
 * harm.h: the area of a face of one harmonic (internal to core/; used by quad.c's quad_area_period).
 *
 * On the face u = side (or v = side) of a solid whose every mode has, along the face's other parameter
 * t, the factor sin(k pi t), cos(k pi t) (one even k for all) or 1, each coordinate is
 *
 *     x_c(t, w) = A_c(w) sin theta + B_c(w) cos theta + D_c(w),    theta = k pi t,
 *
 * (fig. 2 and 4: the sections w = const are ellipses), so the element x_t x x_w is a trigonometric
 * polynomial of degree 2 in theta, |x_t x x_w|^2 one of degree 4, and t in [0, 1] covers k / 2 whole
 * periods of both: the face's area is the integral over w of the element's mean over theta (the
 * trapezoidal rule, geometric where the element keeps away from 0; adaptive between its located
 * least values where it dips), and its flux x . (x_t x x_w) the integral of a mean known exactly from
 * the coefficients. A, B, D and their w-derivatives come from every distinct h(w) once per point of
 * w; a point of theta costs a dozen flops. Along w, Gauss-Kronrod(-Patterson) rules on panels, each
 * side of a degenerate section by one rule in s, w = w0 + d s^2 (docs/MATH.md, "A face of one
 * harmonic").
 *
 * Faces of 4 or more harmonics along t (a loft's skin u = 1: its profile's Fourier series) the same
 * way, the mean over theta by the trapezoidal rule on 2^n points from the coefficients at each w, cut
 * and graded at narrow dips; and a loft's end caps w = 0, 1 (x = C + u P(v)) as half the mean of
 * |P x P_v| (harm.c, "Many harmonics").
 */
#ifndef PDE_HARM_H
#define PDE_HARM_H

#include "internal.h"

/* What harm_face needs besides the solution: w's panels to start from (edge[0] = 0 < ... <
 * edge[np] = 1, every slab's break among them), an n-point Gauss-Legendre rule on [0, 1] (x, wt),
 * and the tolerance of the area on a unit of w (the flux's: tol times size). */
typedef struct {
    const double *edge;
    int np;
    const double *x, *wt;
    int n;
    double tol, size;
    const pde_cancel *cancel;
} harm_opts;

/*
 * The face (axis, side), axis 0 or 1 (or 2: a cap of many harmonics), when it has that form: returns 1 with its area in *area, the
 * integral of x . (x_a x x_b) over it in *flux (a, b its parameters in axis order) and the points of w
 * evaluated added to *nodes; 0, nothing set, where the face is not of that form, memory ran out,
 * the integration did not converge within its depth, or it ran past its work (points of w, or of
 * theta: harm.c's MAX_NODES, CUT_WORK, MANY_WORK; the general path then); -1 where o->cancel
 * stopped it. Reentrant.
 */
int harm_face(const pde_solution *s, int axis, int side, const harm_opts *o, double *area, double *flux,
              size_t *nodes);

/* The mean over theta of |v[0] + v[1] cos theta + v[2] sin theta + v[3] cos 2 theta + v[4] sin 2 theta|,
 * as harm_face takes it at a point of w (x, wt: its n-point Gauss-Legendre rule on [0, 1]); NaN where
 * the search for its least values ran out of work (harm_face then declines the face); for the tests.
 * Reentrant. */
double harm_mean(const double v[5][3], const double *x, const double *wt, int n);

#endif
