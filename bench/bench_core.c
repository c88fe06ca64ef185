/*
 * bench_core: the core's speed, as medians on a noisy shared machine.
 *
 *   1. pde_solve() + pde_solution_free() of each paper figure's model, in
 *      microseconds (goal: <= 5 us).
 *   2. pde_properties() of each figure's solution (goal: <= 100 us), median of rounds.
 *   3. Grid sampling on one thread into float32 x, y, z: bytes per second as
 *      a ratio of memcpy's bandwidth over the same number of bytes, both
 *      measured in this run, interleaved (goal: >= 0.3).
 *
 * The figure models are the presets (api/template.c), built as a client's
 * {"preset": NAME} request would build them.
 *
 *   bench_core                    the tables for docs/BENCHMARKS.md
 *   bench_core --solve NAME N     only N solves of the preset NAME, for instruction counts:
 *     valgrind --tool=callgrind build/bench/bench_core --solve fig4a 1000
 *   bench_core --props NAME N     N calls of pde_properties() on NAME's solution (a figure or a loft preset), then its
 *                                 properties in 17 digits, the median time of the calls:
 *     valgrind --tool=callgrind --toggle-collect=pde_properties build/bench/bench_core --props fig4a 1
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include "model.h"
#include "pde.h"


/* A preset's model, as a client's {"preset": name} gives it: a paper figure's or a loft's */
static api_model *load(const char *name)
{
    char doc[200];
    snprintf(doc, sizeof doc, "{\"preset\": \"%s\"}", name);
    api_error err;
    api_model *m = api_model_parse(doc, strlen(doc), &err);
    if (!m)
        fprintf(stderr, "%s: %s\n", name, err.message);
    return m;
}

static volatile double sink;

/*
 * Rounds over all figures, a batch of solves of each per round, so that the
 * host's noisy stretches fall on every figure alike; median and minimum over
 * the rounds.
 */
static void bench_solve(char **names, int nnames)
{
    enum { BATCH = 100, ROUNDS = 61, MAXF = 64 };
    static double t[MAXF][ROUNDS];
    api_model *models[MAXF];
    size_t modes[MAXF] = { 0 };
    for (int i = 0; i < nnames; i++) {
        if (!(models[i] = load(names[i])))
            return;
        pde_solution *s;
        if (pde_solve(api_model_get(models[i]), &s, NULL) != PDE_OK)
            return;
        for (int c = 0; c < 3; c++) {
            size_t n;
            pde_solution_modes(s, c, &n);
            modes[i] += n;
        }
        pde_solution_free(s);
    }
    for (int r = 0; r < ROUNDS; r++)
        for (int i = 0; i < nnames; i++) {
            const pde_model *pm = api_model_get(models[i]);
            double t0 = now();
            for (int k = 0; k < BATCH; k++) {
                pde_solution *s;
                pde_solve(pm, &s, NULL);
                sink += (double)pde_solution_bytes(s);
                pde_solution_free(s);
            }
            t[i][r] = (now() - t0) / BATCH * 1e6;
        }
    printf("| model | modes | solve + free, median us | min us |\n|---|---|---|---|\n");
    double med[MAXF], worst = 0.0;
    for (int i = 0; i < nnames; i++) {
        double lo = t[i][0];
        for (int r = 1; r < ROUNDS; r++)
            lo = t[i][r] < lo ? t[i][r] : lo;
        med[i] = median(t[i], ROUNDS);
        worst = med[i] > worst ? med[i] : worst;
        printf("| %s | %zu | %.2f | %.2f |\n", names[i], modes[i], med[i], lo);
        api_model_free(models[i]);
    }
    printf("\nmedian over the %d figures: %.2f us; slowest figure's median: %.2f us\n\n", nnames,
           median(med, nnames), worst);
}

/* pde_properties() per figure: rounds over all figures, one call each per round; median and min. */
static void bench_props(char **names, int nnames)
{
    enum { ROUNDS = 7, MAXF = 64 };
    static double t[MAXF][ROUNDS];
    pde_solution *sols[MAXF];
    for (int i = 0; i < nnames; i++) {
        api_model *m = load(names[i]);
        if (!m || pde_solve(api_model_get(m), &sols[i], NULL) != PDE_OK)
            return;
        api_model_free(m);
    }
    for (int r = 0; r < ROUNDS; r++)
        for (int i = 0; i < nnames; i++) {
            pde_props p;
            double t0 = now();
            pde_properties(sols[i], NULL, &p);
            t[i][r] = (now() - t0) * 1e6;
            sink += p.volume;
        }
    printf("| model | properties, median us | min us | folds | bbox gap | det J gap |\n|---|---|---|---|---|---|\n");
    double med[MAXF];
    for (int i = 0; i < nnames; i++) {
        pde_props p;
        pde_properties(sols[i], NULL, &p);
        double lo = t[i][0];
        for (int r = 1; r < ROUNDS; r++)
            lo = t[i][r] < lo ? t[i][r] : lo;
        med[i] = median(t[i], ROUNDS);
        printf("| %s | %.0f | %.0f | %s | %.1e | %.1e |\n", names[i], med[i], lo, p.folds ? "yes" : "no",
               p.bbox_gap, p.detj_gap);
        pde_solution_free(sols[i]);
    }
    printf("\nmedian over the %d figures: %.0f us\n\n", nnames, median(med, nnames));
}

static void bench_sample(const char *name, size_t n)
{
    api_model *m = load(name);
    pde_solution *s;
    if (!m || pde_solve(api_model_get(m), &s, NULL) != PDE_OK)
        return;
    size_t bytes = 3 * sizeof(float) * n * n * n;
    float *out = malloc(bytes);
    char *src = malloc(bytes), *dst = malloc(bytes);
    memset(src, 1, bytes);
    memset(dst, 2, bytes);
    memset(out, 0, bytes);
    enum { RUNS = 11 };
    double ts[RUNS], tm[RUNS], ratio[RUNS];
    for (int r = 0; r < RUNS; r++) {
        double t0 = now();
        pde_sample(s, n, n, n, out);
        double t1 = now();
        memcpy(dst, src, bytes);
        double t2 = now();
        sink += out[r] + dst[r];
        ts[r] = t1 - t0;
        tm[r] = t2 - t1;
        ratio[r] = tm[r] / ts[r];
    }
    double ms = median(ts, RUNS), mm = median(tm, RUNS);
    printf("| %s | %zu^3 | %.1f MB | %.2f GB/s | %.2f GB/s | %.2f |\n", name, n, bytes / 1e6, bytes / ms / 1e9,
           bytes / mm / 1e9, median(ratio, RUNS));
    free(out);
    free(src);
    free(dst);
    pde_solution_free(s);
    api_model_free(m);
}

/* bench_core --props NAME N: NAME a paper figure's preset or a loft's */
static int props_one(const char *name, long n)
{
    api_model *m = load(name);
    pde_solution *s = NULL;
    if (!m || n < 1 || n > 1000 || api_solve(m, &s, NULL) != 0)
        return 1;
    double t[1000];
    pde_props p;
    for (long k = 0; k < n; k++) {
        double t0 = now();
        if (pde_properties(s, NULL, &p) != PDE_OK)
            return 1;
        t[k] = 1e6 * (now() - t0);
    }
    printf("%s: %.0f us (median of %ld), det J separates along axis %d\nvolume %.17g\nsigned %.17g\narea %.17g\ncentroid %.17g %.17g %.17g\n",
           name, median(t, (int)n), n, pde_properties_flat_axis(s), p.volume, p.signed_volume, p.surface_area, p.centroid[0], p.centroid[1],
           p.centroid[2]);
    printf("inertia %.17g %.17g %.17g %.17g %.17g %.17g\ndetj [%.17g, %.17g] found [%.17g, %.17g] gap %.3g folds %d\n"
           "integrals %.3g\n", p.inertia[0][0], p.inertia[1][1], p.inertia[2][2], p.inertia[0][1], p.inertia[0][2],
           p.inertia[1][2], p.detj_min, p.detj_max, p.detj_min_found, p.detj_max_found, p.detj_gap, p.folds,
           p.integral_error);
    pde_solution_free(s);
    api_model_free(m);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 4 && strcmp(argv[1], "--solve") == 0) {
        api_model *m = load(argv[2]);
        if (!m)
            return 1;
        for (long k = atol(argv[3]); k > 0; k--) {
            pde_solution *s;
            if (pde_solve(api_model_get(m), &s, NULL) != PDE_OK)
                return 1;
            pde_solution_free(s);
        }
        api_model_free(m);
        return 0;
    }
    if (argc == 4 && strcmp(argv[1], "--props") == 0)
        return props_one(argv[2], atol(argv[3]));
    char *names[] = { "fig1a", "fig1c", "fig1e", "fig1g", "fig2a", "fig2b", "fig2c", "fig3a", "fig3b",
                      "fig3c", "fig3d", "fig4a", "fig4b", "fig4c", "fig4d", "fig4e", "fig4f", "fig4g",
                      "fig4h", "fig4i", "fig4j", "fig4k", "fig4l", "fig4m", "fig4n", "fig4o", "fig4p",
                      "fig4q", "fig4r", "fig4s", "fig4t", "fig4u", "fig4v", "fig4w", "fig4x" };
    printf("## pde_solve\n\n");
    bench_solve(names, (int)(sizeof names / sizeof *names));
    printf("## pde_properties\n\n");
    bench_props(names, (int)(sizeof names / sizeof *names));
    printf("## Grid sampling, one thread, float32 x,y,z\n\n");
    printf("| model | grid | output | sampling | memcpy | ratio (median of per-run ratios) |\n|---|---|---|---|---|---|\n");
    const char *grids[] = { "fig1a", "fig4a", "fig3d" };
    for (int i = 0; i < 3; i++)
        bench_sample(grids[i], 128);
    bench_sample("fig4a", 256);
    return 0;
}
