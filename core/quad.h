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
    int roots_skipped;  /* the work's bound stopped lines locating det J's roots (or the area's) */
} quad_result;

/* jscale: the size of det J over the solid, for what counts as zero; vscale: the size of the
 * volume (jscale will do), for the refinement's tolerance. */
pde_status quad_solid(const pde_solution *s, const double x0[3], double jscale, double vscale,
                      const pde_cancel *cancel, quad_result *out);

/* The area of the skin; size: the solid's extent, for deciding that two faces coincide. Its panels
 * are the solid's, and so is its rules' error. info->acc[Q_SIGNED] is the signed volume computed
 * another way, from the faces: (1/3) of the flux of x through them (divergence theorem). */
pde_status quad_area(const pde_solution *s, double size, const pde_cancel *cancel, double *area,
                     quad_result *info);

/* Panels per axis and Gauss-Legendre points per panel on each axis (also for api/cost.h). */
void quad_panels(const pde_solution *s, int np[3], int n[3]);

#endif
