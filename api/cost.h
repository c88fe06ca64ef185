/*
 * cost.h: what a request will cost, estimated before doing the work, so that
 * a server can refuse one over its budget instead of running it.
 *
 * USAGE
 *
 *   api_cost c = { 0 }, part;
 *   api_cost_solve(api_model_get(m), &part);        // before pde_solve()
 *   api_cost_add(&c, &part);
 *   ...solve...
 *   api_cost_props(sol, &part);                     // if the properties are not cached
 *   api_cost_add(&c, &part);
 *   api_cost_output(sol, API_FMT_GLB, res, &part);  // or api_cost_eval(sol, n, derivs, &part)
 *   api_cost_add(&c, &part);
 *   if (c.work > max_work || c.bytes > 64e6) refuse(c.work, max_work);
 *
 * work is in units of about 1 ns of one core of the reference machine (the
 * one docs/BENCHMARKS.md names), so 2e9 is about 2 CPU-seconds there. bytes is
 * the peak scratch memory the call allocates beyond its inputs: sampling
 * tables, mesh arrays, JSON trees and texts. The estimates follow what the
 * code does (modes per component, w-terms and their degrees, distinct
 * factors, samples, triangles, planes and rows), with coefficients measured by
 * bench/bench_cost.c, which prints estimate against measured time; they are
 * within about a factor of 2 of the measured CPU time over the presets and the
 * heavy synthetic models there. Each call fills *c (it does not add) and
 * cannot fail; every call is reentrant and reads its arguments only.
 */
#ifndef API_COST_H
#define API_COST_H

#include <stddef.h>

#include "model.h"
#include "output.h"
#include "pde.h"

typedef struct api_cost {
    double work;    /* units of about 1 ns of one core of the reference machine */
    double bytes;   /* peak scratch memory, in bytes */
} api_cost;

/* Parsing a JSON document of len bytes (api_model_parse, api_eval_parse), before it is read. */
void api_cost_parse(size_t len, api_cost *c);
/* pde_solve() of the model, from its terms (the model need not be valid). */
void api_cost_solve(const pde_model *m, api_cost *c);
/* pde_solve_loft() of a loft. */
void api_cost_loft(const pde_loft *l, api_cost *c);
/* What api_model_parse() read: a model's solve, or a loft's. */
void api_cost_model(const api_model *m, api_cost *c);
/* pde_properties() with the default options. */
void api_cost_props(const pde_solution *sol, api_cost *c);
/* api_output_open() and reading the whole output, excluding the properties (api_cost_props): the
 * format's own estimate (api_format_info.cost). */
void api_cost_output(const pde_solution *sol, api_format f, const unsigned res[3], api_cost *c);
/* The same with api_output_open_ex()'s options (NULL: the defaults). */
void api_cost_output_ex(const pde_solution *sol, api_format f, const unsigned res[3], const api_output_opts *opts,
                        api_cost *c);

/* The estimates the formats' cost callbacks are made of (api/fmt_*.c). */
void api_cost_json(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, api_cost *c);
void api_cost_grid_json(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, api_cost *c);
void api_cost_f32(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, api_cost *c);
void api_cost_vts(const pde_solution *sol, const unsigned res[3], const api_output_opts *opts, api_cost *c);
/* A skin written from a blob of blob_vertex bytes a vertex and blob_tri a triangle (0, 0: written from the
 * mesh itself), at work_byte units a byte of output, and out_tri units a triangle. */
void api_cost_skin(const pde_solution *sol, const unsigned res[3], double blob_vertex, double blob_tri,
                   double work_byte, double out_tri, api_cost *c);
/* A volume mesh (api/volmesh.h) of res points: its build, and its writer at write_point units a point. */
void api_cost_volmesh(const pde_solution *sol, const unsigned res[3], double write_point, api_cost *c);
/* pde_eval_d() at npoints points and api_eval_json() of the answer (with derivatives or not). */
void api_cost_eval(const pde_solution *sol, size_t npoints, int derivatives, api_cost *c);

/* sum->work += part->work; sum->bytes = the larger of the two (steps run one after another). */
void api_cost_add(api_cost *sum, const api_cost *part);

#endif
