/*
 * test_errors.c: api/'s one error type. Every api_status has a phrase and
 * one HTTP status (srv_http_status); out of memory injected by a failing
 * allocator (malloc, calloc and realloc wrapped at link time, see the
 * Makefile) at each allocation of api_output_open, in every format, gives
 * API_ERR_NOMEM (500 over HTTP), never a bad document's 422, and leaks nothing;
 * api_model_tree gives NULL or the whole tree, never a part.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>
#include <cmocka.h>

#include "../server/internal.h"   /* srv_http_status (core has an internal.h too) */
#include "output.h"
#include "support.h"

/* ---- the failing allocator: after fail_after more allocations, every one fails; -1 never ---- */

static long fail_after = -1;

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t k);
void *__real_realloc(void *p, size_t n);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t k);
void *__wrap_realloc(void *p, size_t n);

static int should_fail(void)
{
    if (fail_after < 0)
        return 0;
    if (fail_after == 0)
        return 1;
    fail_after--;
    return 0;
}

void *__wrap_malloc(size_t n)
{
    return should_fail() ? NULL : __real_malloc(n);
}

void *__wrap_calloc(size_t n, size_t k)
{
    return should_fail() ? NULL : __real_calloc(n, k);
}

void *__wrap_realloc(void *p, size_t n)
{
    return should_fail() ? NULL : __real_realloc(p, n);
}

/* cJSON is a shared library, which --wrap does not reach: its hooks count too. */
static void *hook_malloc(size_t n)
{
    return __wrap_malloc(n);
}

static void every_status_should_have_a_phrase_and_its_http_status(void **state)
{
    (void)state;
    static const struct {
        api_status s;
        int http;
        const char *words;
    } rows[] = {
        { API_ERR_NOMEM, 500, "memory" },   { API_ERR_LIMIT, 413, "limit" },
        { API_ERR_DOCUMENT, 422, "document" }, { API_ERR_NOT_JSON, 400, "JSON" },
        { API_ERR_CANCELLED, 503, "cancelled" }, { API_ERR_NOT_FOUND, 404, "found" },
    };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        if (srv_http_status(rows[i].s) != rows[i].http)
            fail_msg("status %d: HTTP %d, want %d", (int)rows[i].s, srv_http_status(rows[i].s), rows[i].http);
        if (!strstr(api_strerror(rows[i].s), rows[i].words))
            fail_msg("status %d: \"%s\" lacks \"%s\"", (int)rows[i].s, api_strerror(rows[i].s), rows[i].words);
    }
    assert_string_equal(api_strerror((api_status)999), "unknown error");
}

static void api_fail_should_carry_the_status_it_is_given(void **state)
{
    (void)state;
    api_error err;
    assert_int_equal(api_fail(&err, API_ERR_LIMIT, "/points", "over %d", 3), -1);
    assert_int_equal(err.status, API_ERR_LIMIT);
    assert_string_equal(err.pointer, "/points");
    assert_string_equal(err.message, "over 3");
    assert_int_equal(api_fail_nomem(&err), -1);
    assert_int_equal(err.status, API_ERR_NOMEM);
    assert_int_equal(api_fail_cancelled(&err), PDE_ERR_CANCELLED);
    assert_int_equal(err.status, API_ERR_CANCELLED);
    assert_int_equal(api_fail(NULL, API_ERR_DOCUMENT, "", "x"), -1);
}

static void output_open_out_of_memory_should_be_a_500_in_every_format(void **state)
{
    (void)state;
    api_model *m = preset_model("fig4a");
    pde_solution *sol;
    api_error err;
    if (api_solve(m, &sol, &err))
        fail_msg("fig4a: %s", err.message);
    api_model_free(m);
    for (int run = 0; run < 2 * API_FMT_COUNT; run++) {   /* every format, and compressed where it takes it */
        int f = run / 2;
        api_output_opts opts = { .compress = run % 2 ? API_COMPRESS_MESHOPT : API_COMPRESS_NONE };
        if (opts.compress && !api_format_info_of((api_format)f)->compress)
            continue;
        unsigned res[3];
        assert_int_equal(api_res_parse("5", (api_format)f, res, NULL), 0);
        long k = 0, failures = 0;
        for (;; k++) {
            fail_after = k;
            api_output *o = api_output_open_ex(sol, "id", NULL, (api_format)f, res, &opts, NULL, &err);
            fail_after = -1;
            if (o) {
                api_output_free(o);
                break;
            }
            failures++;
            if (err.status != API_ERR_NOMEM || srv_http_status(err.status) != 500)
                fail_msg("%s, allocation %ld failing: status %d (HTTP %d): %s", api_format_info_of((api_format)f)->name,
                         k, (int)err.status, srv_http_status(err.status), err.message);
        }
        if (!failures)
            fail_msg("%s: no allocation to fail", api_format_info_of((api_format)f)->name);
    }
    pde_solution_free(sol);
}

static void model_tree_should_be_null_or_whole_when_memory_runs_out(void **state)
{
    (void)state;
    api_model *m = preset_model("fig4a");
    char *whole = api_model_json(api_model_get(m));
    assert_non_null(whole);
    cJSON_Hooks hooks = { hook_malloc, free };
    cJSON_InitHooks(&hooks);
    long nulls = 0;
    for (long k = 0;; k++) {
        fail_after = k;
        cJSON *t = api_model_tree(api_model_get(m));
        fail_after = -1;
        if (!t) {
            nulls++;
            continue;
        }
        char *s = cJSON_PrintUnformatted(t);
        cJSON_Delete(t);
        assert_non_null(s);
        if (strcmp(s, whole) != 0)
            fail_msg("allocation %ld failing: a partial tree %s", k, s);
        cJSON_free(s);
        break;
    }
    cJSON_InitHooks(NULL);
    assert_true(nulls > 3);
    free(whole);
    api_model_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_status_should_have_a_phrase_and_its_http_status),
        cmocka_unit_test(api_fail_should_carry_the_status_it_is_given),
        cmocka_unit_test(output_open_out_of_memory_should_be_a_500_in_every_format),
        cmocka_unit_test(model_tree_should_be_null_or_whole_when_memory_runs_out),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
