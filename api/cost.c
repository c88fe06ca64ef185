/*
 * cost.c: estimates of work and memory (cost.h).
 *
 * DESIGN
 * Every estimate counts the operations of the code it stands for, and prices
 * each kind with one coefficient (the K_ constants, in ns of the reference
 * machine, fitted by bench/bench_cost.c):
 *   - a point of pde_eval_d() costs, per mode, the factors f_u, f_v and h(w);
 *     h costs per w-term a Horner pass over its degree and its exp, cos, sin;
 *   - a pde_grid costs its tables (a factor per mode and sample), a plane
 *     costs h of every mode, a row the coefficients of every mode and one
 *     multiply-add per distinct u-factor and sample for each array it fills;
 *     the multiply-adds cost more once the u table leaves the cache;
 *   - a mesh samples six faces and then welds, cleans and indexes them;
 *   - the properties sweep two grids with derivatives, polish eight extremes
 *     by compass search and take residuals with fourth derivatives.
 * The memory estimates add the arrays the code allocates at its peak.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cost.h"

/* ---- coefficients, ns on the reference machine (bench/bench_cost.c) ---- */

#define K_FE_POW   3.0    /* factor_eval of t^n */
#define K_FE_TRIG  14.0   /* sin and cos of one argument */
#define K_FE_EXP   8.0    /* exp */
#define K_FE_HYP   16.0   /* sinh and cosh */
#define K_H_TERM   2.0    /* a w-term of h(w): its loop */
#define K_H_EXP    10.0   /* its exp, when alpha != 0 */
#define K_H_TRIG   16.0   /* its cos and sin, when beta != 0 */
#define K_H_DEG    1.0    /* a coefficient of its Horner passes (A, and B when beta != 0) */
#define K_EV_MODE  3.0    /* a mode of pde_eval_d beyond its factors and h */
#define K_WD_DEG   1.6    /* a coefficient of wterm_deriv's complex Horner, per derivative order + 1 */
#define K_WD_TERM  25.0   /* wterm_deriv's exp, cexp and loop */
#define K_COEF     2.0    /* a mode of a grid row's coefficients */
#define K_COEF_MEM 16.0   /* the same past STRIDED_FAST modes, the f_v table beyond L2 */
#define K_FMA      1.0    /* a multiply-add of a sampled row (strided over the u table; a chain of adds) */
#define K_FMA_L2   2.0    /* the same past STRIDED_FAST rows, the table in L2 (strided()) */
#define K_FMA_MEM  8.0    /* the same past STRIDED_FAST rows, the table beyond L2 */
#define K_COMBINE  0.2    /* a multiply-add of a properties row (contiguous) */
#define K_COMBINE_L2 0.3  /* the same, table beyond 1 MB */
#define K_COMBINE_MEM 0.55 /* the same, table beyond 4 MB */
#define CACHE_BYTES (1 << 20)   /* tables read at full speed (the reference machine: L1 48 KB, L2 2 MB) */
#define L2_BYTES (2 << 20)
#define STRIDED_FAST 1024.0 /* table rows read in turn before the loop turns memory-bound (strided()) */
#define K_GROUP    0.5    /* a comparison of pde_grid_create's grouping of u-factors */
#define K_TOUCH    0.1    /* a byte of fresh memory (page faults, zeroing) */
#define K_PT_PROPS 10.0   /* a point of a properties sweep: det J and extremes */
#define K_BOX_MODE 150.0  /* a mode of a box's model in branch and bound: its factors' bounds and jets */
#define K_BOX_X    100.0  /* a coordinate's model beyond its modes */
#define K_BOXES_X  150.0  /* boxes of a coordinate's branch and bound, typically */
#define K_BOX_J    1500.0 /* det J's model beyond its modes: the series products */
#define K_AREA_REFINE 8.0 /* a refined face panel's quarters and theirs, per its own work */
#define K_REFINE   5.0    /* a refined panel's octants and theirs, per its own work */
#define K_Q_POINT  20.0   /* a point of the integrals beyond its modes: det J, sums, roots' bookkeeping */
#define K_Q_MODE   10.0   /* a mode of a point of the integrals: table multiply-adds, and factors off the tables */
#define QUAD_REFINE_WORK (2.0 * PDE_PROPS_WORK)   /* core/quad.c's bound of refinement, points times (modes + 1) */
#define K_LINE_PT  2.0    /* points per integration node: the samples are the rule, more where roots are */
#define K_PT_F32   1.0    /* a sample written as f32 */
#define K_TABLE_BYTE 0.25 /* a byte of a grid's v-table read from memory, a plane's pass (sweep_work) */
#define K_FMT_F32  17.0   /* a float32 printed for grid json */
#define K_VOL_POINT 100.0 /* a point of a volume mesh's build beyond its evaluation (api/volmesh.c) */
#define K_DET      4.0    /* det J of a vts point */
#define K_WELD     60.0   /* a face sample welded */
#define K_TRI      40.0   /* a face triangle cleaned, cancelled or indexed, with its normals */
#define K_STL      25.0   /* an STL triangle written */
#define K_B64      1.0    /* a byte of base64 */
#define K_JNODE    90.0   /* a cJSON node made and freed */
#define K_JMODE    6000.0 /* a mode's factors and regime printed in the closed form's text */
#define K_JNUM     300.0  /* a number printed by cJSON (it prints, reads back, may print again) */
#define K_DESC     250.0  /* a coefficient printed by the closed form's text */
#define K_EVNUM    250.0  /* a %.17g number of an eval answer */
#define K_S_MODE   400.0  /* a mode of the solve: its fit and real form, |e| <= 1 (plans shared) */
#define K_S_PLAN   500.0  /* a mode with |e| > 1: its own plan (roots, LU, condition) */
#define K_S_TERM   120.0  /* a term of the solve */
#define K_S_DEG    35.0   /* a coefficient of a force's polynomial through the solve */
#define K_S_PAIR   3.0    /* two force terms on one mode (merging searches linearly) */
#define POLISH_EVALS 100  /* typical evaluations of one compass search (at most 400) */

/* ---- what a solution holds ---- */

typedef struct {
    double nm, nd;          /* modes, distinct u-factors */
    double fu, fv;          /* sum over modes of a factor_eval of f_u, of f_v */
    double h;               /* sum over modes of mode_h */
    double d4, d0;          /* sum over modes of wterm_deriv with n = 4, and with n = 0 */
    double coefs;           /* sum over modes of their w-terms' coefficients (json) */
    double wterms;
} comp_stats;

static double fe_cost(pde_factor f)
{
    switch (f.kind) {
    case PDE_POW: return K_FE_POW;
    case PDE_SIN:
    case PDE_COS: return K_FE_TRIG;
    case PDE_EXP: return K_FE_EXP;
    case PDE_SINH:
    case PDE_COSH: return K_FE_HYP;
    }
    return K_FE_TRIG;
}

static int factor_cmp(const void *pa, const void *pb)
{
    const pde_factor *a = pa, *b = pb;
    if (a->kind != b->kind)
        return a->kind < b->kind ? -1 : 1;
    return (a->p > b->p) - (a->p < b->p);
}

static void stats_of(const pde_solution *sol, comp_stats st[3])
{
    memset(st, 0, 3 * sizeof *st);
    for (int c = 0; c < 3; c++) {
        size_t nm;
        const pde_mode *md = pde_solution_modes(sol, c, &nm);
        comp_stats *s = &st[c];
        s->nm = (double)nm;
        pde_factor *us = malloc((nm ? nm : 1) * sizeof *us);
        for (size_t m = 0; m < nm; m++) {
            s->fu += fe_cost(md[m].u);
            s->fv += fe_cost(md[m].v);
            s->h += K_EV_MODE;
            for (size_t k = 0; k < md[m].nterms; k++) {
                const pde_wterm *t = &md[m].terms[k];
                double d1 = t->deg + 1.0, passes = t->beta != 0.0 ? 2.0 : 1.0;
                s->h += K_H_TERM + (t->alpha != 0.0 ? K_H_EXP : 0.0) + (t->beta != 0.0 ? K_H_TRIG : 0.0) +
                        K_H_DEG * 2.0 * passes * d1;
                s->d4 += K_WD_TERM + K_WD_DEG * 5.0 * d1;
                s->d0 += K_WD_TERM + K_WD_DEG * d1;
                s->coefs += 2.0 * d1;
            }
            s->wterms += (double)md[m].nterms;
            if (us)
                us[m] = md[m].u;
        }
        if (us && nm) {
            qsort(us, nm, sizeof *us, factor_cmp);
            size_t nd = 1;
            for (size_t m = 1; m < nm; m++)
                nd += factor_cmp(&us[m - 1], &us[m]) != 0;
            s->nd = (double)nd;
        } else {
            s->nd = s->nm;
        }
        free(us);
    }
}

/* One point of pde_eval_d(): every mode of every component. */
static double point_cost(const comp_stats st[3])
{
    double w = 0.0;
    for (int c = 0; c < 3; c++)
        w += st[c].fu + st[c].fv + st[c].h;
    return w;
}

/* ---- a pde_grid: its tables, its planes, its rows ---- */

static double grid_bytes(const comp_stats st[3], double nu, double nv)
{
    double b = 96.0 * nu + 256.0;
    for (int c = 0; c < 3; c++)
        b += 8.0 * st[c].nm + 16.0 * st[c].nd * nu + 16.0 * st[c].nm * nv + 40.0 * st[c].nm;
    return b;
}

static double grid_create_work(const comp_stats st[3], double nu, double nv)
{
    double w = K_TOUCH * grid_bytes(st, nu, nv);
    for (int c = 0; c < 3; c++) {
        double nm = st[c].nm > 0 ? st[c].nm : 1.0;
        w += st[c].fu / nm * st[c].nm * nu + st[c].fv * nv;   /* f_u is evaluated per mode, not per distinct */
        w += K_GROUP * st[c].nm * st[c].nd * 0.5;
    }
    return w;
}

static double plane_work(const comp_stats st[3])
{
    return st[0].h + st[1].h + st[2].h;
}

/*
 * A loop that reads one element of each of n table rows in turn, for each
 * sample, reuses a cache line per row from one sample to the next; up to
 * about 1024 rows the chain of adds bounds it, beyond about 2048 rows every
 * read waits for memory (measured: 1.0 to 1.4 ns at 513 and 1025 rows, 7 to
 * 9 ns at 4096, whatever the row length).
 */
static double strided(double n, double table_bytes, double fast, double l2, double slow)
{
    if (n <= STRIDED_FAST)
        return fast;
    return table_bytes <= L2_BYTES ? l2 : slow;
}

/* A row of nu samples filling `arrays` arrays (x; or x, xu, xv, xw); props: the contiguous combine(). */
static double row_work(const comp_stats st[3], double nu, double nv, double arrays, int props)
{
    double w = 0.0;
    for (int c = 0; c < 3; c++) {
        /* emit1() has vectorised loops for up to three distinct u-factors. */
        double table = 16.0 * st[c].nd * nu;   /* f_u and f_u' */
        double k = props ? (table > 4.0 * CACHE_BYTES ? K_COMBINE_MEM : table > CACHE_BYTES ? K_COMBINE_L2 : K_COMBINE)
                         : st[c].nd <= 3 ? K_COMBINE : strided(st[c].nd, table / 2.0, K_FMA, K_FMA_L2, K_FMA_MEM);
        double kc = props ? K_COEF : strided(st[c].nm, 16.0 * st[c].nm * nv, K_COEF, K_COEF, K_COEF_MEM);
        w += kc * st[c].nm + arrays * k * st[c].nd * nu;
    }
    return w;
}

/* A grid of nu x nv over nw planes, all rows, `arrays` arrays per row. */
static double sweep_work(const comp_stats st[3], double nu, double nv, double nw, double arrays, int props)
{
    double w = grid_create_work(st, nu, nv) + nw * plane_work(st) + nw * nv * row_work(st, nu, nv, arrays, props);
    /* Each plane reads every mode's v-table (f_v and f_v', 16 nv bytes a mode) once; beyond L2 that is
     * a cache line from memory at a time, a mode's row apart from the next (a loft of 2049 modes at 256
     * per axis: 8.4 MB a plane, 1.1 s of its f32's 1.1 s; estimated 0.55 s without this). */
    const double table = 16.0 * nv * (st[0].nm + st[1].nm + st[2].nm);
    if (!props && table > L2_BYTES)
        w += nw * table * K_TABLE_BYTE;
    return w;
}

/* ---- the properties ---- */

/* Every mode t^n along u and 1 or a whole harmonic of 2 pi v along v, a loft's form (core/props.c's radial
 * paths, core/quad.c's periodic and folding ones): its highest harmonic K (0 for none), else -1. */
static int loft_harmonics(const pde_solution *sol)
{
    int K = 0;
    for (int c = 0; c < 3; c++) {
        size_t nm;
        const pde_mode *m = pde_solution_modes(sol, c, &nm);
        for (size_t i = 0; i < nm; i++) {
            const pde_factor v = m[i].v;
            if (m[i].u.kind != PDE_POW ||
                !((v.kind == PDE_POW && v.p == 0.0) || ((v.kind == PDE_SIN || v.kind == PDE_COS) && fmod(v.p, 2.0) == 0.0)))
                return -1;
            if (v.kind != PDE_POW)
                K = fmax(K, fabs(v.p) / 2.0);
        }
    }
    return K;
}

void api_cost_props(const pde_solution *sol, api_cost *c)
{
    comp_stats st[3];
    stats_of(sol, st);
    size_t nq[3];
    pde_properties_nodes(sol, nq);
    const double res = 9.0, bres = 17.0, rres = 9.0, pt = point_cost(st);
    double modes = st[0].nm + st[1].nm + st[2].nm;
    double w = 0.0;
    /* The sample sweep, then eight compass searches. */
    w += sweep_work(st, res, res, res, 4.0, 1) + K_PT_PROPS * res * res * res;
    w += 8.0 * POLISH_EVALS * pt;
    /* Branch and bound: a box is two or three models, each a bound and a point jet of every mode,
     * and for det J its series products (core/bound.c). Coordinates typically take K_BOXES_X
     * boxes (at most PDE_PROPS_BOXES, a bounded error), det J half its budget. */
    w += 6.0 * K_BOXES_X * 2.5 * (K_BOX_MODE * modes + K_BOX_X);
    /* Where det J is constant along the separable face's other parameter, its branch and bound is
     * along w alone and closes its gap: a tenth of that (fig. 4a: 82 M -> 4.6 M instructions). */
    const int free_axis = pde_properties_free_axis(sol);
    /* Its budget grows with the solid's fastest rate (fig. 3: 32000 boxes a side, of which 3k to 23k taken;
     * on the face of a separable solid, 2-D boxes, fig. 3a and 3b: 3.3k to 16k). */
    const double jboxes = (double)pde_properties_detj_boxes(sol);
    const double jused = free_axis >= 0 ? 0.05 : pde_properties_flat_axis(sol) >= 0 ? 0.2 : 0.5;
    w += 2.0 * jused * jboxes * 2.5 * (2.0 * K_BOX_MODE * modes + K_BOX_J);
    /* The integrals: lines through the panels' nodes, each node a few points (sampling, roots and
     * the rule on each piece where det J may change sign), each a multiply-add per mode from the
     * panel's factor tables (core/quad.c); refined panels, about K_REFINE times their own work,
     * stop at a bounded number of points times modes (QUAD_REFINE_WORK). */
    double nodes = (double)nq[0] * (double)nq[1] * (double)nq[2];
    double panels = 1.0, panel_n[3];
    for (int a = 0; a < 3; a++)
        panels *= panel_n[a] = fmax(1.0, (double)nq[a] / 12.0);
    /* Where det J separates, the solid's integrals are over one face (core/quad.c). */
    const int flat = pde_properties_flat_axis(sol);
    if (flat >= 0)
        nodes /= (double)nq[flat], panels /= panel_n[flat];
    /* Where det J separates, every panel is refined (core/quad.c's FLAT_PANELS, FACE_REFINE). */
    /* ... except where det J is constant along the face's other parameter: lines along w, halved
     * twice at most near det J's roots, and no refinement (fig. 4a: 54 M -> 12.5 M instructions). */
    double base = K_LINE_PT * nodes,
           refined = free_axis >= 0 ? 0.2 : flat >= 0 ? 1.0 : fmin(1.0, 96.0 / panels);
    double evals = base + fmin(K_REFINE * refined * base, QUAD_REFINE_WORK / (modes + 1.0));
    /* The skin: six faces of nodes, and the refinement of its first 256 panels, about
     * K_AREA_REFINE times their own work, within the same bound. */
    double face_nodes = 2.0 * ((double)nq[0] * (double)nq[1] + (double)nq[1] * (double)nq[2] +
                               (double)nq[0] * (double)nq[2]);
    double face_panels = 2.0 * (panel_n[0] * panel_n[1] + panel_n[1] * panel_n[2] + panel_n[0] * panel_n[2]);
    double fbase = K_LINE_PT * face_nodes;
    evals += fbase + fmin(K_AREA_REFINE * (flat >= 0 ? 1.0 : fmin(1.0, 256.0 / face_panels)) * fbase, QUAD_REFINE_WORK / (modes + 1.0));
    w += evals * (K_Q_POINT + K_Q_MODE * (modes + 1.0));
    /* Boundary residual: per component, bres^2 points at w = 0 and 1 (each a full pde_eval_d). */
    w += 3.0 * bres * bres * 2.0 * pt;
    /* PDE residual: per component, 9^3 points of x_uuuu, x_vvvv (h itself) and x_wwww. */
    for (int i = 0; i < 3; i++)
        w += rres * rres * rres * (st[i].d4 + 2.0 * st[i].d0 + 3.0 * (st[i].fu + st[i].fv));
    /* A loft of more modes than core/bound.c's memo serves (256) bounds its boxes without it, and its
     * faces and folds take their paths to their work's bounds: measured 2 to 4 times the above (a loft
     * of 511 modes, 4 sections of 256 points, c = -1e-3: 3.9 s against 1.27 s; 319 modes: 1.45 s
     * against 0.71 s), where the loft presets, under 256 modes, are over (tower 0.26 s against 0.89 s). */
    const int K = loft_harmonics(sol);
    if (modes > 256.0 && K >= 0)
        w *= 3.0;
    c->work = w;
    /* core/quad.c's factor tables: each axis's values and derivatives at up to 26 points per mode;
     * core/bound.c's memo of factors (up to 16 MB, for up to 256 modes). */
    c->bytes = grid_bytes(st, res, res) + 64.0 * (PDE_PROPS_BOXES + jboxes) + 64.0 * modes + 65536.0 +
               8.0 * (6.0 * 26.0 + 5.0) * (modes + 1.0) + (double)pde_properties_memo_bytes(sol);
    /* ... and a loft's folding path's cos and sin tables: 16 N (K + 1) bytes, N = 16 K samples a row (16.7 MB
     * at K = 255; core/quad.c's fold_solid, for K up to FOLD_K = 256) */
    if (K > 0 && K <= 256)
        c->bytes += 256.0 * K * (K + 1.0);
}

/* ---- outputs ---- */

/* The six faces of api_mesh_build(): their samples, planes and rows, then welding and cleaning. */
static void mesh_cost(const comp_stats st[3], const unsigned res[3], api_cost *c)
{
    double nu = res[0], nv = res[1], nw = res[2];
    double w = 0.0;
    /* u = 0, 1: grids 1 x nv over nw planes, nv rows of one sample each. */
    w += 2.0 * sweep_work(st, 1.0, nv, nw, 1.0, 0);
    /* v = 0, 1: grids nu x 1 over nw planes, one row each. */
    w += 2.0 * sweep_work(st, nu, 1.0, nw, 1.0, 0);
    /* w = 0, 1: grids nu x nv, one plane. */
    w += 2.0 * sweep_work(st, nu, nv, 1.0, 1.0, 0);
    double nraw = 2.0 * (nv * nw + nu * nw + nu * nv);
    double ntraw = 4.0 * ((nv - 1) * (nw - 1) + (nu - 1) * (nw - 1) + (nu - 1) * (nv - 1));
    w += K_WELD * nraw + K_TRI * ntraw;
    /* api/mesh.c's two blocks: the mesh (pos, nrm, detj, weld: 32 bytes a sample; tri: 12 a triangle) and
     * the scratch (up, vof, pid, flag: 13 a sample), each with a 32-byte header and pad; and, while it
     * samples, its four grids (u = 0, 1; v = 0, 1; w = 0; w = 1) and row buffers. */
    double blocks = nraw * (32.0 + 13.0) + ntraw * 12.0 + 64.0;
    double nmax = fmax(nu, nv);
    double g = grid_bytes(st, 2.0, nv) + grid_bytes(st, nu, 2.0) + 2.0 * grid_bytes(st, nu, nv) + 8.0 * (nu + nv) +
               96.0 * nmax;
    c->work = w + K_TOUCH * blocks;
    c->bytes = blocks + g;
}

void api_cost_output_ex(const pde_solution *sol, api_format f, const unsigned res[3], const api_output_opts *opts,
                        api_cost *c)
{
    static const api_output_opts none;
    c->work = c->bytes = 0.0;
    const api_format_info *fi = api_format_info_of(f);
    if (fi)
        fi->cost(sol, res, opts ? opts : &none, c);
}

void api_cost_output(const pde_solution *sol, api_format f, const unsigned res[3], api_cost *c)
{
    api_cost_output_ex(sol, f, res, NULL, c);
}

/* Rows per read: the chunk of fmt.c's api_rows (16384 points); the buffers hold them. */
static double rows_chunk(const unsigned res[3])
{
    double nu = res ? res[0] : 0;
    return nu > 0 ? fmax(1.0, floor(16384.0 / nu)) * nu : 0.0;
}

void api_cost_f32(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, api_cost *c)
{
    (void)opts;
    comp_stats st[3];
    stats_of(sol, st);
    double nu = res[0], nv = res[1], nw = res[2], n = nu * nv * nw, chunk = rows_chunk(res);
    c->work = sweep_work(st, nu, nv, nw, 1.0, 0) + K_PT_F32 * n;
    c->bytes = grid_bytes(st, nu, nv) + 2.0 * 12.0 * chunk + 12.0 * chunk;
}

void api_cost_grid_json(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, api_cost *c)
{
    (void)opts;
    comp_stats st[3];
    stats_of(sol, st);
    double nu = res[0], nv = res[1], nw = res[2], n = nu * nv * nw, chunk = rows_chunk(res);
    /* Three passes, one per component, each sampling all three; every sample printed once. */
    c->work = grid_create_work(st, nu, nv) + 3.0 * (nw * plane_work(st) + nw * nv * row_work(st, nu, nv, 1.0, 0)) +
              K_FMT_F32 * 3.0 * n;
    c->bytes = grid_bytes(st, nu, nv) + 12.0 * chunk + 2.0 * 17.0 * chunk;
}

void api_cost_vts(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, api_cost *c)
{
    (void)opts;
    comp_stats st[3];
    stats_of(sol, st);
    double nu = res[0], nv = res[1], nw = res[2], n = nu * nv * nw, chunk = rows_chunk(res);
    /* Positions, then positions and the three derivatives again for det J. */
    c->work = grid_create_work(st, nu, nv) + nw * (2.0 * plane_work(st)) + nw * nv * row_work(st, nu, nv, 5.0, 0) +
              (K_PT_F32 * 4.0 + K_DET) * n;
    c->bytes = grid_bytes(st, nu, nv) + 4.0 * 12.0 * chunk + 2.0 * 12.0 * chunk;
}

void api_cost_skin(const pde_solution *sol, const unsigned res[3], double blob_vertex, double blob_tri,
                   double work_byte, double out_tri, api_cost *c)
{
    comp_stats st[3];
    stats_of(sol, st);
    double nu = res[0], nv = res[1], nw = res[2];
    mesh_cost(st, res, c);
    double nraw = 2.0 * (nv * nw + nu * nw + nu * nv);
    double ntri = 4.0 * ((nv - 1) * (nw - 1) + (nu - 1) * (nw - 1) + (nu - 1) * (nv - 1));
    double blob = blob_vertex * nraw + blob_tri * ntri;
    c->work += work_byte * blob + K_TOUCH * blob + out_tri * ntri;
    /* After the build the mesh, the blob and a read buffer remain; the build's peak is larger. */
    c->bytes = fmax(c->bytes, (nraw * 28.0 + ntri * 12.0) + blob + (2 << 20));
}

void api_cost_volmesh(const pde_solution *sol, const unsigned res[3], double write_point, api_cost *c)
{
    double n = (double)res[0] * res[1] * res[2];
    double cells = (double)(res[0] - 1) * (res[1] - 1) * (res[2] - 1);
    comp_stats st[3];
    stats_of(sol, st);
    /* The samples (x and its derivatives, for det J) and the cells' centres (the derivatives) through
     * two pde_grids, rows in double precision (grid_row's contiguous combine); the build's own work
     * beyond them (merging, cells, folds, the faces' quads: K_VOL_POINT a point, 50 a cell); then the
     * writer's, write_point a point (its share of the cells included). Calibrated on fig1a (cheap
     * points) and fig4a at res 80 (docs/BENCHMARKS.md). */
    const double nu = res[0], nv = res[1], nw = res[2];
    c->work = sweep_work(st, nu, nv, nw, 4.0, 1) + sweep_work(st, nu - 1.0, nv - 1.0, nw - 1.0, 3.0, 1) +
              K_DET * (n + cells) + (K_VOL_POINT + write_point) * n + 50.0 * cells;
    /* Points (24 + 8 + 4), cells (8 + 32 + 4 + 2), the faces' quads, a grid's tables; a writer's piece
     * of text (about 1 MB) and the output's buffer holding it (bench_cost: fig4a at 33^3 peaks at 5.5 MB). */
    c->bytes = 36.0 * n + 46.0 * cells + 16.0 * 2.0 * (n / fmax(1.0, nu)) + grid_bytes(st, nu, nv) + (4 << 20);
}

void api_cost_json(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, api_cost *c)
{
    (void)res;
    (void)opts;
    comp_stats st[3];
    stats_of(sol, st);
    /* A cJSON tree of every mode and coefficient, printed, and the closed form as text. */
    double nodes = 0.0, nums = 0.0;
    for (int i = 0; i < 3; i++) {
        nodes += 8.0 * st[i].nm + 6.0 * st[i].wterms + st[i].coefs;
        nums += st[i].nm + 3.0 * st[i].wterms + st[i].coefs;
    }
    c->work = K_JMODE * (st[0].nm + st[1].nm + st[2].nm) + K_JNODE * nodes + K_JNUM * nums +
              K_DESC * (st[0].coefs + st[1].coefs + st[2].coefs) / 2.0 + 30000.0;
    /* The tree and cJSON's doubling print buffer; then the text and its copy into the output's
     * doubling buffer; the closed form's text (about 14 bytes a coefficient) beside them. */
    double text = 24.0 * nums + 8.0 * nodes;
    c->bytes = fmax(80.0 * nodes + 2.0 * text, 3.0 * text) + 14.0 * (st[0].coefs + st[1].coefs + st[2].coefs) / 2.0 +
               65536.0;
}

/* ---- eval ---- */

void api_cost_eval(const pde_solution *sol, size_t npoints, int derivatives, api_cost *c)
{
    comp_stats st[3];
    stats_of(sol, st);
    double n = (double)npoints, arrays = derivatives ? 4.0 : 1.0;
    c->work = n * point_cost(st) + n * arrays * 3.0 * K_EVNUM;
    /* The points, the values (12 doubles a point), the answer's text. */
    c->bytes = n * (24.0 + 96.0) + n * arrays * (3.0 * 24.0 + 4.0) + 4096.0;
}

/* ---- the solve ---- */

static int term_key_cmp(const void *pa, const void *pb)
{
    const pde_factor *a = pa, *b = pb;
    int r = factor_cmp(&a[0], &b[0]);
    return r ? r : factor_cmp(&a[1], &b[1]);
}


static double lambda(pde_factor f)
{
    double w = f.kind == PDE_SIN || f.kind == PDE_COS ? f.p * M_PI : f.kind == PDE_POW ? 0.0 : f.p;
    return w * w * w * w;
}

/* A loft's solve (core/loft.c): per mode, its slab system's banded solve (shared by equal e) and
 * the real form of its slabs' terms; per term, the sums at the sections. */
void api_cost_loft(const pde_loft *l, api_cost *c)
{
    double modes = 0.0, terms = 0.0, K = (double)l->nsections;
    for (int ci = 0; ci < 3; ci++)
        modes += (double)l->comp[ci].nterms, terms += (double)l->comp[ci].nterms;
    c->work = (K_S_MODE + K_S_PLAN) * modes * (K - 1.0) + K_S_TERM * terms * K;
    c->bytes = 1600.0 * modes * (K - 1.0) + 64.0 * K * K * 16.0;
}

void api_cost_model(const api_model *m, api_cost *c)
{
    if (api_model_loft(m))
        api_cost_loft(api_model_loft(m), c);
    else
        api_cost_solve(api_model_get(m), c);
}

void api_cost_solve(const pde_model *m, api_cost *c)
{
    double w = 0.0, bytes = 0.0;
    for (int ci = 0; ci < 3; ci++) {
        const pde_component *pc = &m->comp[ci];
        double modes = 0.0, plans = 0.0, chain = 0.0;
        size_t nt = pc->nbterms + pc->nfterms;
        /* Chains: t^n brings t^(n-4), t^(n-8), ... along. */
        for (size_t j = 0; j < nt; j++) {
            pde_factor u = j < pc->nbterms ? pc->bterms[j].u : pc->fterms[j - pc->nbterms].u;
            pde_factor v = j < pc->nbterms ? pc->bterms[j].v : pc->fterms[j - pc->nbterms].v;
            double iu = u.kind == PDE_POW && u.p >= 0 ? floor(fmin(u.p, PDE_MAX_POW) / 4) : 0;
            double iv = v.kind == PDE_POW && v.p >= 0 ? floor(fmin(v.p, PDE_MAX_POW) / 4) : 0;
            modes += (iu + 1) * (iv + 1);
            /* A chain's modes are forced by their parents: degree 4 (i + j) + 3 at step (i, j). */
            chain += (iu + 1) * (iv + 1) * (4 + 2 * (iu + iv));
            double e = pc->c != 0.0 ? -(pc->a * lambda(u) + pc->b * lambda(v)) / pc->c : 0.0;
            plans += fabs(e) > 1.0;
        }
        modes = fmin(modes, 4.0 * PDE_MAX_MODES);
        w += K_S_MODE * modes + K_S_PLAN * fmin(plans, modes) + K_S_TERM * (double)nt + K_S_DEG * chain;
        bytes += 1600.0 * modes + 6.0 * 16.0 * chain;   /* modes, plans, eps, the solution's arena */
        /* Force terms: their polynomials through force_w, the particular solution and the real form. */
        pde_factor *keys = malloc((pc->nfterms ? pc->nfterms : 1) * 2 * sizeof *keys);
        for (size_t j = 0; j < pc->nfterms; j++) {
            const pde_fterm *t = &pc->fterms[j];
            double d1 = (t->w.kind == PDE_POW && t->w.p >= 0 ? fmin(t->w.p, PDE_MAX_POW) : 0.0) + 1.0;
            double e = pc->c != 0.0 ? -(pc->a * lambda(t->u) + pc->b * lambda(t->v)) / pc->c : 0.0;
            if (fabs(e) <= 1.0)
                d1 += 40.0;    /* the power-series regime expands the force and sums a series */
            w += K_S_DEG * d1;
            bytes += 6.0 * 16.0 * d1;
            if (keys) {
                keys[2 * j] = t->u;
                keys[2 * j + 1] = t->v;
            }
        }
        /* Force terms that share a mode merge by linear searches: the square of their count. */
        if (keys && pc->nfterms) {
            qsort(keys, pc->nfterms, 2 * sizeof *keys, term_key_cmp);
            double run = 1.0;
            for (size_t j = 1; j <= pc->nfterms; j++) {
                if (j < pc->nfterms && term_key_cmp(&keys[2 * (j - 1)], &keys[2 * j]) == 0) {
                    run += 1.0;
                    continue;
                }
                w += K_S_PAIR * run * run;
                run = 1.0;
            }
        }
        free(keys);
    }
    c->work = w + 500.0;
    c->bytes = bytes + 4096.0;
}

void api_cost_parse(size_t len, api_cost *c)
{
    /* cJSON makes a 64-byte node for every value and copies every key and string: a model's JSON,
     * mostly short numbers and keys, peaks at about 42 bytes per byte of text (bench_cost); the strict
     * check and the tree take some 12 ns a byte. */
    c->work = 12.0 * (double)len;
    c->bytes = 48.0 * (double)len + 4096.0;
}

void api_cost_add(api_cost *sum, const api_cost *part)
{
    sum->work += part->work;
    sum->bytes = fmax(sum->bytes, part->bytes);
}
