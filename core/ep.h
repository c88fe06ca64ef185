/*
 * ep.h: exponential polynomials, the one representation of every h(w).
 *
 * An ep is a sum of terms P(w) exp(z (w - shift)) with complex z and complex
 * polynomial P. shift is 1 when Re z > 0, else 0, so |exp(z (w - shift))| <= 1
 * on [0,1] and nothing overflows however large z is (issue: t up to 1000 and
 * beyond). The true h(w) is the real part: the operator and the boundary
 * functionals are real, so real parts of complex solutions are solutions.
 *
 * Homogeneous, forced, resonant and chained (t^n, n >= 4) cases all reduce to
 * the two solvers below, for the ODE  h'''' - e h = q(w)  (eq. 7 with a force).
 * All memory comes from a caller's scratch arena.
 */
#ifndef PDE_EP_H
#define PDE_EP_H

#include <complex.h>

#include "internal.h"

typedef double complex cplx;

typedef struct {
    cplx z;
    int shift;      /* 0 or 1 */
    int deg;
    cplx *p;        /* deg + 1 coefficients, w^0 first */
} ep_term;

typedef struct {
    size_t n, cap;
    ep_term *t;
} ep;

/* The shift that keeps exp(z (w - shift)) bounded by 1 on [0,1]. */
int ep_shift(cplx z);

/* dst += scale * P(w) exp(z (w - shift)); terms with equal z and shift merge. */
pde_status ep_add(arena *s, ep *dst, cplx z, int shift, const cplx *p, int deg, cplx scale);

/* dst += scale * src. */
pde_status ep_add_ep(arena *s, ep *dst, const ep *src, cplx scale);

/* h(0), h'(0), h(1), h'(1). */
void ep_boundary(const ep *h, cplx out[4]);

/*
 * A particular solution of h'''' - e h = q for any ep q, added to *out.
 * |e| <= 1 ("small"): terms with |z| <= 2 are expanded into one polynomial and
 * solved by power series; others, far from every root, by undetermined
 * coefficients. |e| > 1: a term within 1/2 of a root r is rewritten as
 * exp(r w) times a Taylor polynomial of exp((z - r) w), which makes exact and
 * near resonance one case with the secular w P(w) exp(r w) form and no
 * cancellation; other terms by plain undetermined coefficients.
 */
pde_status ep_particular(arena *s, double e, const ep *q, ep *out);

/*
 * The four homogeneous solutions, as eps: for |e| <= 1 the Krylov series
 * K_j with K_j^(i)(0) = delta_ij (which tend to w^j / j! as e -> 0 and stay
 * well conditioned there); for |e| > 1 exp(r (w - shift)) for the four simple
 * roots r of r^4 = e. scale[j] is a factor for the derivative rows of the
 * boundary system (1 / |r|) that balances it.
 */
pde_status ep_homogeneous(arena *s, double e, ep basis[4], double *deriv_scale);

#endif
