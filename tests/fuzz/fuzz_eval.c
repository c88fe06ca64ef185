/*
 * fuzz_eval.c: the request body of POST /solids/{id}/eval. Bytes go
 * through api_eval_parse, then pde_eval_d at every point on a fixed small
 * solution (the paper's figure 4a), then api_eval_check and api_eval_json,
 * as the server does. Invariants: a refusal is a sane api_error; at most
 * MAX_POINTS points; a finite cost estimate (cost.h); a non-finite value is
 * refused at the first point that has one; otherwise the answer is strict
 * JSON whose numbers read back to the very doubles computed.
 */
#include <math.h>

#include <cJSON.h>

#include "cost.h"
#include "fuzz.h"
#include "id.h"
#include "output.h"
#include "pde.h"
#include "strict.h"

#define MAX_POINTS 64

static const char fig4a[] =
    "{\"pde\": {\"a\": [1, 1, 1], \"b\": [1, 1, 1], \"c\": [-9.5, -9.5, -10]},"
    " \"boundary\": {"
    "  \"x\": [{\"w0\": 0.5, \"dw0\": 0, \"w1\": 0.5, \"dw1\": 0, \"u\": {\"pow\": 1}, \"v\": {\"sin\": 2}}],"
    "  \"y\": [{\"w0\": 0.5, \"dw0\": 0, \"w1\": 0.5, \"dw1\": 0, \"u\": {\"pow\": 1}, \"v\": {\"cos\": 2}}],"
    "  \"z\": [{\"w0\": 0, \"dw0\": 0, \"w1\": 3, \"dw1\": 7.5}]},"
    " \"force\": {"
    "  \"x\": [{\"coef\": 30000, \"u\": {\"pow\": 1}, \"v\": {\"cos\": 2}, \"w\": {\"sin\": 3}}],"
    "  \"y\": [{\"coef\": 30000, \"u\": {\"pow\": 1}, \"v\": {\"sin\": 2}, \"w\": {\"sin\": 3}}]}}";

static pde_solution *sol;
static char id[API_ID_LEN + 1];

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    api_error err;
    api_model *m = api_model_parse(fig4a, sizeof fig4a - 1, &err);
    FUZZ_CHECK(m && api_solve(m, &sol, &err) == 0, "figure 4a does not solve: %s", err.message);
    pde_diag diag;
    FUZZ_CHECK(api_model_id(api_model_get(m), id, &diag) == PDE_OK, "figure 4a has no id");
    api_model_free(m);
    return 0;
}

static int finite3(const double *x)
{
    return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]);
}

/* The array of n triples doubles[] at key in the answer, compared bit for bit (17 digits round-trip). */
static void check_array(const cJSON *doc, const char *key, const double *want, size_t n)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(doc, key);
    FUZZ_CHECK(cJSON_IsArray(a) && (size_t)cJSON_GetArraySize(a) == n, "\"%s\" is not an array of %zu", key, n);
    size_t i = 0;
    for (const cJSON *t = a->child; t; t = t->next, i++) {
        FUZZ_CHECK(cJSON_IsArray(t) && cJSON_GetArraySize(t) == 3, "%s[%zu] is not a triple", key, i);
        int k = 0;
        for (const cJSON *x = t->child; x; x = x->next, k++) {
            double w = want[3 * i + (size_t)k];
            FUZZ_CHECK(cJSON_IsNumber(x) && (x->valuedouble == w || (w == 0 && x->valuedouble == 0)),
                       "%s[%zu][%d] reads %.17g, computed %.17g", key, i, k, x->valuedouble, w);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!sol)
        LLVMFuzzerInitialize(NULL, NULL);
    api_error err;
    memset(&err, 'X', sizeof err);
    double *pts = NULL;
    size_t n = 0;
    int derivs = -1;
    if (api_eval_parse((const char *)data, size, MAX_POINTS, &pts, &n, &derivs, &err) != 0) {
        fuzz_check_error(&err);
        free(pts);
        return 0;
    }
    FUZZ_CHECK(n <= MAX_POINTS, "%zu points, over the limit of %d", n, MAX_POINTS);
    FUZZ_CHECK(derivs == 0 || derivs == 1, "derivatives %d", derivs);
    FUZZ_CHECK(pts || n == 0, "no points array");
    api_cost cost;
    api_cost_eval(sol, n, derivs, &cost);
    FUZZ_CHECK(isfinite(cost.work) && cost.work >= 0 && isfinite(cost.bytes) && cost.bytes >= 0,
               "the cost of %zu points is work %g, bytes %g", n, cost.work, cost.bytes);
    double *v = malloc((n ? n : 1) * 12 * sizeof *v);
    FUZZ_CHECK(v, "out of memory");
    double *du = v + 3 * n, *dv = v + 6 * n, *dw = v + 9 * n;
    for (size_t i = 0; i < n; i++) {
        FUZZ_CHECK(finite3(pts + 3 * i), "point %zu is not finite", i);
        pde_eval_d(sol, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], v + 3 * i, derivs ? du + 3 * i : NULL,
                   derivs ? dv + 3 * i : NULL, derivs ? dw + 3 * i : NULL);
    }
    size_t first_bad = n;
    for (size_t i = 0; i < n && first_bad == n; i++)
        if (!finite3(v + 3 * i) || (derivs && (!finite3(du + 3 * i) || !finite3(dv + 3 * i) || !finite3(dw + 3 * i))))
            first_bad = i;
    memset(&err, 'X', sizeof err);
    int rc = api_eval_check(v, derivs ? du : NULL, derivs ? dv : NULL, derivs ? dw : NULL, n, &err);
    if (first_bad < n) {
        FUZZ_CHECK(rc != 0, "point %zu is not finite, yet api_eval_check passed it", first_bad);
        fuzz_check_error(&err);
        char want[32];
        snprintf(want, sizeof want, "/points/%zu", first_bad);
        FUZZ_CHECK(err.status == API_ERR_DOCUMENT && !strcmp(err.pointer, want), "status %d pointer \"%s\", want %d %s",
                   (int)err.status, err.pointer, (int)API_ERR_DOCUMENT, want);
    } else {
        FUZZ_CHECK(rc == 0, "api_eval_check refused finite values: %s", err.message);
        char *json = api_eval_json(id, v, derivs ? du : NULL, derivs ? dv : NULL, derivs ? dw : NULL, n);
        FUZZ_CHECK(json, "api_eval_json gave NULL");
        FUZZ_CHECK(json_strict_valid(json, strlen(json)), "the answer is not strict JSON: %.300s", json);
        cJSON *doc = cJSON_Parse(json);
        FUZZ_CHECK(doc, "cJSON cannot read the answer");
        const cJSON *jid = cJSON_GetObjectItemCaseSensitive(doc, "id");
        FUZZ_CHECK(cJSON_IsString(jid) && !strcmp(jid->valuestring, id), "the answer's id is not %s", id);
        check_array(doc, "values", v, n);
        if (derivs) {
            check_array(doc, "du", du, n);
            check_array(doc, "dv", dv, n);
            check_array(doc, "dw", dw, n);
        } else {
            FUZZ_CHECK(!cJSON_GetObjectItemCaseSensitive(doc, "du"), "du without derivatives");
        }
        cJSON_Delete(doc);
        free(json);
    }
    free(v);
    free(pts);
    return 0;
}
