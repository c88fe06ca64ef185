/*
 * internal.h: what the modules of core/ share and nothing outside sees.
 *
 * A solution lives in one arena: a chain of blocks freed together, so that a
 * solve that fails halfway frees everything by freeing the arena, and the
 * cache can count the bytes of a solution in one number.
 */
#ifndef PDE_INTERNAL_H
#define PDE_INTERNAL_H

#include <complex.h>
#include <stddef.h>
#include <string.h>

#include "pde.h"

typedef struct arena_block arena_block;

typedef struct {
    arena_block *head;
    size_t bytes;
} arena;

/* Zeroed memory, aligned for any type; NULL when out of memory. */
void *arena_alloc(arena *a, size_t size);
void arena_free(arena *a);

/* One component's part of a solution. */
typedef struct {
    double a, b, c;
    size_t nmodes;
    pde_mode *modes;
    size_t nbterms, nfterms;    /* the model's terms, kept for residuals and the force */
    pde_bterm *bterms;
    pde_fterm *fterms;
    /* Per mode, the particular solution's h(0), h'(0), h(1), h'(1): what the force (or a chain
     * parent) asks of the boundary fit besides the data, the scale of the boundary residual. */
    double (*drive)[4];
    /* Lofts: per mode, its data at the sections, x[m * nsections + k] and xw (NULL without tangents),
     * the sums over the component's terms (loft_bc_residual). NULL for a model. */
    double *lx, *lxw;
} comp_solution;

struct pde_solution {
    arena mem;                  /* owns everything below, and the solution itself */
    comp_solution comp[3];
    /* Lofts: the sections (0 and NULL for a model), and the worst condition estimate of a slab
     * system with the mode it belongs to (pde_solution_condition). */
    size_t nsections;
    pde_section *sections;
    double cond;
    double fit_error;           /* pde_loft.fit_error */
    int cond_comp;
    size_t cond_mode;
};

/* The slab of breaks[0 .. nslabs] that holds w (pde.h: below 0 the first slab, above 1 the last, at an
 * interior break the slab on its right). */
static inline size_t slab_index(const double *breaks, size_t nslabs, double w)
{
    size_t lo = 0, hi = nslabs - 1;     /* the last slab whose start is <= w */
    while (lo < hi) {
        size_t mid = (lo + hi + 1) / 2;
        if (breaks[mid] <= w)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

/* The terms of the slab of m that holds w: terms[*k0] .. terms[*k1 - 1]. */
static inline void mode_slab(const pde_mode *m, double w, size_t *k0, size_t *k1)
{
    if (m->nslabs <= 1) {
        *k0 = 0;
        *k1 = m->nterms;
        return;
    }
    const size_t lo = slab_index(m->breaks, m->nslabs, w);
    *k0 = m->first[lo];
    *k1 = m->first[lo + 1];
}

/* Lofts: the largest error of the section conditions (docs/MATH.md, "Lofts"), relative to the
 * section data's scale; 0 for a model. */
double loft_bc_residual(const pde_solution *s);

extern const char *const pde_comp_name[3];   /* "x", "y", "z" */

/* The determinant of the matrix with rows a, b, c. */
static inline double det3(const double a[3], const double b[3], const double c[3])
{
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
}

/* The slabs' breaks along w (pde_mode): every mode has the same; [0, 1] without modes. */
static inline const double *solution_breaks(const pde_solution *s, size_t *nslabs)
{
    static const double unit[2] = { 0.0, 1.0 };
    for (int c = 0; c < 3; c++)
        if (s->comp[c].nmodes) {
            *nslabs = s->comp[c].modes[0].nslabs;
            return s->comp[c].modes[0].breaks;
        }
    *nslabs = 1;
    return unit;
}

/* Non-zero when the caller asks the running call to stop (pde.h). */
static inline int pde_stopped(const pde_cancel *c)
{
    return c && c->stop && c->stop(c->arg);
}

/* Clears d (if not NULL): nothing at fault yet. */
static inline void pde_diag_clear(pde_diag *d)
{
    if (d)
        memset(d, 0, sizeof *d), d->component = -1, d->term = -1, d->section = -1;
}

/* A solve that failed with st: its message, if none was written, and its memory freed; returns st. */
pde_status pde_solve_abandon(arena *mem, pde_status st, pde_diag *d);

/* Fills d (if not NULL) and returns st. */
pde_status pde_fail(pde_diag *d, pde_status st, int comp, int in_force, long term, const char *field,
                    const char *fmt, ...) __attribute__((format(printf, 7, 8)));

/* Checks a component's numbers and factors; names the field at fault in d. */
pde_status model_check_component(const pde_component *c, int ci, pde_diag *d);

/* The basis function f is a multiple of: key and sign with f = sign key; 0 if f is identically 0. */
int factor_normalise(pde_factor f, pde_factor *key, double *sign);
int factor_compare(pde_factor a, pde_factor b);
const char *factor_name(pde_factor_kind k);

/* f^(n)(t) of one factor, for any order n >= 0. */
double factor_deriv(pde_factor f, double t, int n);

/* f(t) and f'(t) together, the common case. */
void factor_eval(pde_factor f, double t, double *val, double *der);

/* The d4 eigenvalue: f'''' = lambda f, 0 for t^n (which chains instead). */
double factor_lambda(pde_factor f);

/* d^n/dw^n of one w-term at w. */
double wterm_deriv(const pde_wterm *t, double w, int n);

/* f^(k)(t) for k = 0..n (n <= 7) into d[0..n]; the same for a mode's h(w). */
void factor_derivs(pde_factor f, double t, int n, double *d);
void mode_h_derivs(const pde_mode *m, double w, int n, double *d);

/* Bounds of |f^(k)| over [t0, t1], k = 0..n (n <= 7), into d[0..n]; the same for a mode's h(w). */
void factor_bounds(pde_factor f, double t0, double t1, int n, double *d);
void mode_h_bounds(const pde_mode *m, double w0, double w1, int n, double *d);

/* h(w) and h'(w) of a mode. */
void mode_h(const pde_mode *m, double w, double *h, double *dh);

/* Every mode's factor along axis (0: f_u, 1: f_v, 2: h) and its derivative at t, the modes of x,
 * y, z in order, into val[] and der[]: the values of factor_eval and mode_h, each factor and each
 * w-term's exp and sincos computed once where modes share them. */
void solution_factors(const pde_solution *s, int axis, double t, double *val, double *der);

/* The distinct h(w) among s's modes (quad.c's quad_same_h; fig. 2 and 4: 3 of 5): the first mode of each into
 * dm[], and each mode's (x's, y's, then z's) place among them into map[]; returns how many. dm and map
 * hold as many as s has modes. Cannot fail. */
size_t distinct_h(const pde_solution *s, const pde_mode **dm, unsigned *map);

/*
 * The distinct h(w) of a solution, made to be evaluated together (wtable_eval): the distinct exps
 * exp(alpha (w - shift)) and sincos of beta w of their terms, slab by slab, each term's place among
 * them, so that a point of w takes each once and each term without a search (the values of mode_h,
 * to the bit). Built by wtable_new (NULL when out of memory), freed by wtable_free (NULL: nothing).
 * wtable_eval writes the table's scratch: one table per thread.
 */
typedef struct {
    size_t nd;                  /* distinct h(w) */
    const pde_mode **dm;        /* nd: the first mode of each */
    unsigned *map;              /* per mode of the solution (x's, y's, then z's): its h's place */
    size_t nslabs;
    const double *breaks;
    unsigned *eoff, *boff;      /* nslabs + 1: slab k's exps are ea[eoff[k] ..], its sincos bb[boff[k] ..] */
    double *ea, *ev;            /* pairs alpha, shift; their exps at the current w (slot 0: alpha = 0, 1) */
    double *bb, *cs;            /* beta; cos and sin of beta w at the current w */
    unsigned *toff;             /* nd + 1: mode d's terms' places in ie, ib from toff[d] */
    unsigned *ie, *ib;          /* per term: its exp's slot, and its sincos's (beta != 0) */
} wtable;

wtable *wtable_new(const pde_solution *s);
void wtable_free(wtable *t);

/* h and h' of each distinct h(w) at w, into h[0 .. nd - 1] and dh[]. */
void wtable_eval(wtable *t, double w, double *h, double *dh);

/* A sampling grid (pde.h). Modes that share their u-factor share a row of the
 * u table, so a point costs one multiply-add per distinct u-factor, not per
 * mode. row holds, for row j of the current plane, x then xu, xv, xw, each as
 * three runs of nu doubles (x, y, z components). */
struct pde_grid {
    const pde_solution *sol;
    size_t nu, nv;
    size_t nm[3];               /* modes */
    size_t nd[3];               /* distinct u-factors among them */
    size_t *group[3];           /* nm: each mode's u-factor */
    double *phi[3], *dphi[3];   /* nd x nu: f_u and f_u' at each u */
    double *psi[3], *dpsi[3];   /* nm x nv */
    double *hs;                 /* h of every mode, x's modes then y's and z's, then h' likewise */
    double *h[3], *dh[3];       /* nm: h and h' at the current plane, in hs */
    double w;                   /* the current plane, NaN before the first */
    double *k[3];               /* 3 nd: a row's coefficients for x, xv and xw */
    double *row;                /* 12 nu */
    double *col;                /* nu <= COL_NU: max(3 max(nd), 9) nv, the coefficients of a plane's rows side by side */
    double *blk;                /* wider, with BLK_MODES modes or more in a component: 3 nd BLK_ROWS per component,
                                 * the coefficients of BLK_ROWS rows (col_coefs' layout), x's then y's and z's */
};

/* Grids this narrow (faces u = const) fill a plane column-wise: the coefficients of all its rows at
 * once, over contiguous v, instead of a few points per row. */
enum { COL_NU = 2 };
/* Wider grids with this many modes in a component take their rows' coefficients BLK_ROWS rows at a
 * time the same way (eval.c's grid_blocks): a row at a time read a cache line per mode. */
enum { BLK_MODES = 64, BLK_ROWS = 64, BLK_ND = 4 /* distinct u-factors a component, at most */ };

enum { GRID_X = 1, GRID_XU = 2, GRID_XV = 4, GRID_XW = 8 };

/* Moves the grid to the plane w; then grid_row() fills the rows wanted for row j. */
void grid_set_w(pde_grid *g, double w);
void grid_row(pde_grid *g, size_t j, unsigned want);

/* search.c: f's root in [a, b], where fa = f(a) and fb = f(b) have opposite signs (Illinois). */
double illinois(double (*f)(void *, double), void *arg, double a, double b, double fa, double fb);

/* A function to minimise, and an early end: enough(arg, a, b, x, fx), asked before each step with
 * the bracket [a, b] and the best point so far (NULL: none). */
typedef struct {
    double (*f)(void *arg, double t);
    int (*enough)(void *arg, double a, double b, double x, double fx);
    void *arg;
} brent_fn;

/* f's least in [a, b] by Brent's method from x inside (fx = f(x)), to tol + 2 eps |x|, in at most
 * steps evaluations: returns the place, its value into *fmin. */
double brent_min(const brent_fn *fn, double a, double b, double x, double fx, double tol, int steps,
                 double *fmin);

#endif
