/*
 * bench_loft: a loft's fit and solve against a paper figure's parse and solve, in the same run
 * (issue 10's goal: a 3-section loft of 64 points per section within 10x of one figure).
 *
 *   build/bench/bench_loft    medians of 301 runs each: the gallery's "vase" (3 sections, 64 points,
 *                             its document as GET /presets/vase gives it) parsed, fitted (FFTW) and
 *                             solved; examples/fig4a.json parsed and solved; and their ratio.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "catalog.h"
#include "model.h"

#ifndef RUNS
#define RUNS 301
#endif

static double run(const char *text, size_t len)
{
    double t0 = now();
    api_error err;
    api_model *m = api_model_parse(text, len, &err);
    pde_solution *s = NULL;
    if (!m || api_solve(m, &s, &err)) {
        fprintf(stderr, "bench_loft: %s: %s\n", err.pointer, err.message);
        exit(1);
    }
    double t = now() - t0;
    pde_solution_free(s);
    api_model_free(m);
    return t;
}

int main(void)
{
    char *doc = api_loft_preset_json("vase");
    const char *at = doc ? strstr(doc, "\"loft\":") : NULL;
    FILE *f = fopen("examples/fig4a.json", "rb");
    if (!at || !f) {
        fprintf(stderr, "bench_loft: run from the repository's top (examples/fig4a.json)\n");
        return 1;
    }
    static char fig[1 << 16];
    size_t flen = fread(fig, 1, sizeof fig, f);
    fclose(f);
    size_t llen = strlen(at) + 1;
    char *loft = malloc(llen + 1);
    snprintf(loft, llen + 1, "{%s", at);
    double tl[RUNS], tf[RUNS];
    for (int i = 0; i < RUNS; i++) {   /* interleaved: both see the same machine */
        tl[i] = run(loft, llen);
        tf[i] = run(fig, flen);
    }
    double ml = median(tl, RUNS), mf = median(tf, RUNS);
    printf("## Lofts: fit and solve\n\n");
    printf("| case | median us |\n|---|---|\n");
    printf("| vase: 3 sections x 64 points, parse + FFTW fit + solve | %.1f |\n", ml * 1e6);
    printf("| fig4a (examples/fig4a.json): parse + solve | %.1f |\n", mf * 1e6);
    printf("\nratio vase / fig4a: %.1f (goal: <= 10)\n\n", ml / mf);
    free(loft);
    free(doc);
    return 0;
}
