/*
 * test_model_json.c: the JSON model format. A valid document gives the model
 * the paper describes; every kind of bad document gives an error whose JSON
 * pointer names the field, and never a crash.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "id.h"
#include "model.h"
#include "support.h"

/* Parses from an exact-size heap copy with no NUL after it, so ASan sees any over-read. */
static api_model *parse(const char *text, api_error *err)
{
    size_t n = strlen(text);
    char *buf = malloc(n ? n : 1);
    memcpy(buf, text, n);
    api_model *m = api_model_parse(buf, n, err);
    free(buf);
    return m;
}

static void model_should_read_the_issue_example_as_the_papers_figure_4a(void **state)
{
    (void)state;
    size_t len;
    char *text = read_file("examples/fig4a.json", &len);
    assert_non_null(text);
    api_error err;
    api_model *m = api_model_parse(text, len, &err);
    free(text);
    assert_non_null(m);
    pde_solution *a, *b;
    assert_int_equal(api_solve(m, &a, &err), 0);
    pde_model ref;
    for (size_t i = 0; i < paper_figure_count(); i++)
        if (strcmp(paper_figure_name(i), "fig4a") == 0)
            paper_figure_model(i, &ref);
    assert_int_equal(pde_solve(&ref, &b, NULL), PDE_OK);
    for (int i = 0; i < 50; i++) {
        double p[3] = { (i % 5) / 4.0, (i % 7) / 6.0, (i % 11) / 10.0 }, x[3], y[3];
        pde_eval(a, p[0], p[1], p[2], x);
        pde_eval(b, p[0], p[1], p[2], y);
        for (int c = 0; c < 3; c++)
            assert_true(x[c] == y[c]);
    }
    pde_solution_free(a);
    pde_solution_free(b);
    api_model_free(m);
}

static void model_should_default_omitted_factors_to_one_and_numbers_to_zero(void **state)
{
    (void)state;
    api_error err;
    api_model *m = parse("{\"pde\":{\"a\":[1,2,3],\"b\":[4,5,6],\"c\":[-1,-2,-3]},"
                         "\"boundary\":{\"z\":[{\"w1\":2}]},\"force\":{\"y\":[{\"u\":{\"cos\":1}}]}}",
                         &err);
    assert_non_null(m);
    const pde_model *pm = api_model_get(m);
    assert_true(pm->comp[1].b == 5 && pm->comp[2].c == -3);
    assert_int_equal(pm->comp[0].nbterms, 0);
    assert_int_equal(pm->comp[2].nbterms, 1);
    const pde_bterm *t = &pm->comp[2].bterms[0];
    assert_true(t->u.kind == PDE_POW && t->u.p == 0 && t->v.kind == PDE_POW && t->v.p == 0);
    assert_true(t->w0 == 0 && t->dw0 == 0 && t->w1 == 2 && t->dw1 == 0);
    assert_true(pm->comp[1].fterms[0].coef == 0 && pm->comp[1].fterms[0].u.kind == PDE_COS);
    api_model_free(m);
    api_model_free(NULL);
}

static api_error perr;

#define PDE3 "\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-1,-1,-1]}"

typedef struct {
    const char *text, *pointer, *words;
} bad_case;

static const bad_case bad[] = {
    { "", "", "empty" },
    { "  \n", "", "empty" },
    { "{", "", "not valid JSON" },
    { "{\"pde\":}", "/pde", "line 1, column 8" },
    { "[]", "", "must be an object, not an array" },
    { "{" PDE3 "} x", "", "after the end" },
    { "{}", "/pde", "required" },
    { "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1]}}", "/pde/c", "required" },
    { "{\"pde\":{\"a\":[1,1],\"b\":[1,1,1],\"c\":[1,1,1]}}", "/pde/a", "three numbers" },
    { "{\"pde\":{\"a\":[1,\"1\",1],\"b\":[1,1,1],\"c\":[1,1,1]}}", "/pde/a/1", "not a string" },
    { "{\"pde\":{\"a\":[null,1,1],\"b\":[1,1,1],\"c\":[1,1,1]}}", "/pde/a/0", "not null" },
    { "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[1,1,1],\"d\":[1,1,1]}}", "/pde/d", "unknown key \"d\"" },
    { "{" PDE3 ",\"forces\":{}}", "/forces", "unknown key \"forces\"" },
    { "{" PDE3 "," PDE3 "}", "/pde", "\"pde\" appears twice" },
    { "{" PDE3 ",\"boundary\":{\"w\":[]}}", "/boundary/w", "unknown key \"w\"" },
    { "{" PDE3 ",\"boundary\":{\"x\":{}}}", "/boundary/x", "array of terms" },
    { "{" PDE3 ",\"boundary\":{\"x\":[3]}}", "/boundary/x/0", "must be an object, not a number" },
    { "{" PDE3 ",\"boundary\":{\"x\":[{\"w0\":1,\"w0\":2}]}}", "/boundary/x/0/w0", "\"w0\" appears twice" },
    { "{" PDE3 ",\"boundary\":{\"x\":[{\"u\":{\"sin\":1,\"cos\":2}}]}}", "/boundary/x/0/u", "one key" },
    { "{" PDE3 ",\"boundary\":{\"x\":[{\"u\":{\"tan\":1}}]}}", "/boundary/x/0/u/tan", "unknown key \"tan\"" },
    { "{" PDE3 ",\"boundary\":{\"x\":[{\"u\":{}}]}}", "/boundary/x/0/u", "needs one of" },
    { "{" PDE3 ",\"boundary\":{\"x\":[{\"u\":\"sin\"}]}}", "/boundary/x/0/u", "must be an object" },
    { "{" PDE3 ",\"boundary\":{\"y\":[{},{\"v\":{\"pow\":2.5}}]}}", "/boundary/y/1/v/pow", "whole number" },
    { "{" PDE3 ",\"boundary\":{\"y\":[{\"v\":{\"pow\":-1}}]}}", "/boundary/y/0/v/pow", "whole number" },
    { "{" PDE3 ",\"boundary\":{\"y\":[{\"v\":{\"pow\":101}}]}}", "/boundary/y/0/v/pow", "0 to 100" },
    { "{" PDE3 ",\"boundary\":{\"x\":[{\"w0\":1e999}]}}", "/boundary/x/0/w0", "finite" },
    { "{" PDE3 ",\"boundary\":{\"x\":[{\"dw1\":true}]}}", "/boundary/x/0/dw1", "not a boolean" },
    { "{" PDE3 ",\"boundary\":{\"x\":[{\"u\":{\"sin\":1e7}}]}}", "/boundary/x/0/u/sin", "1e6" },
    { "{" PDE3 ",\"force\":{\"y\":[{\"coef\":\"3\"}]}}", "/force/y/0/coef", "must be a number" },
    { "{" PDE3 ",\"force\":{\"x\":[{\"w\":{\"exp\":800}}]}}", "/force/x/0/w/exp", "overflows" },
    { "{" PDE3 ",\"force\":{\"z\":[{\"w0\":1}]}}", "/force/z/0/w0", "unknown key \"w0\"" },
    { "{\"pde\":\"heat\"}", "/pde", "must be an object, not a string" },
    { "{\"preset\":\"fig9z\"}", "/preset", "no preset \"fig9z\"" },
    { "{\"preset\":4}", "/preset", "must be a string, not a number" },
    { "{\"template\":\"example7\"}", "/template", "example1, example2, example3, example4" },
    { "{\"preset\":\"fig4a\",\"template\":\"example4\"}", "", "not both" },
    { "{\"preset\":\"fig4a\",\"pde\":{}}", "/pde", "unknown key \"pde\"" },
    { "{\"preset\":\"fig4a\",\"params\":[]}", "/params", "must be an object" },
    { "{\"preset\":\"fig4a\",\"params\":{\"p00\":1}}", "/params/p00", "its parameters are a, b, c, r0" },
    { "{\"preset\":\"fig4a\",\"params\":{\"p0\":\"big\"}}", "/params/p0", "not a string" },
    { "{\"preset\":\"fig4a\",\"params\":{\"p0\":[1,2,3]}}", "/params/p0", "must be a number" },
    { "{\"preset\":\"fig4a\",\"params\":{\"c\":[1,1]}}", "/params/c", "not an array of 2" },
    { "{\"preset\":\"fig4a\",\"params\":{\"c\":-1}}", "/params/c", "three numbers" },
    { "{\"preset\":\"fig4a\",\"params\":{\"c\":[-1,-1,1e999]}}", "/params/c/2", "finite" },
    { "{\"preset\":\"fig4a\",\"params\":{\"xi\":1,\"xi\":2}}", "/params/xi", "\"xi\" appears twice" },
    { "{\"pde\":{},\"a/b~c\":1}", "/a~1b~0c", "unknown key \"a/b~c\"" },
    { "{\"preset\":\"fig4a\",\"params\":{\"r/0\":1}}", "/params/r~10", "no parameter \"r/0\"" },
    { "{\"preset\":\"fig4a\",\"params\":{\"\\n\":1}}", "/params/\xef\xbf\xbd", "no parameter \"\xef\xbf\xbd\"" },
    /* A parameter the model refuses: its pointer, not /params (the front-end places the message under it). */
    { "{\"template\":\"example3\",\"params\":{\"n_xy\":2e6}}", "/params/n_xy", "1e6" },
    { "{\"template\":\"example3\",\"params\":{\"n_z\":-3e6}}", "/params/n_z", "1e6" },
    { "{\"preset\":\"fig4a\",\"params\":{\"xi\":1e7}}", "/params/xi", "1e6" },
};

static void model_should_name_the_field_of_every_kind_of_bad_input(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        api_error err;
        memset(&err, 'x', sizeof err);
        api_model *m = parse(bad[i].text, &err);
        if (m)
            fail_msg("case %zu parsed: %s", i, bad[i].text);
        if (strcmp(err.pointer, bad[i].pointer) != 0 || !strstr(err.message, bad[i].words))
            fail_msg("case %zu: %s\n  got %s: %s\n  want %s: ...%s...", i, bad[i].text, err.pointer,
                     err.message, bad[i].pointer, bad[i].words);
    }
}

static void model_should_refuse_deep_nesting_and_huge_documents(void **state)
{
    (void)state;
    api_error err;
    size_t n = 100000;
    char *deep = malloc(n + 1);
    memset(deep, '[', n);
    deep[n] = '\0';
    assert_null(parse(deep, &err));
    assert_string_equal(err.pointer, "");
    assert_non_null(strstr(err.message, "deeper than 64 levels"));
    assert_int_equal(err.status, API_ERR_LIMIT);
    free(deep);
    /* Depth inside strings does not count; 64 levels parse (and fail the schema, 422). */
    char nest[200] = "{\"pde\":\"[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[\"}";
    assert_null(parse(nest, &err));
    assert_int_equal(err.status, API_ERR_DOCUMENT);
    assert_null(parse("{\"pde\": ", &err));
    assert_int_equal(err.status, API_ERR_NOT_JSON);
    /* 6000 terms, over 2 MB with padding: over the term limit. */
    size_t cap = 3 << 20, len = 0;
    char *big = malloc(cap);
    len += (size_t)sprintf(big, "{" PDE3 ",\"boundary\":{\"x\":[");
    for (int i = 0; i < 6000; i++)
        len += (size_t)sprintf(big + len, "%s{\"u\":{\"sin\":%d},\"w0\":1.00000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000}", i ? "," : "", i);
    len += (size_t)sprintf(big + len, "]}}");
    assert_true(len > 2000000);
    assert_null(parse(big, &err));
    assert_string_equal(err.pointer, "/boundary/x");
    assert_non_null(strstr(err.message, "limit"));
    assert_int_equal(err.status, API_ERR_LIMIT);
    free(big);
}

/* What cJSON alone lets through: it ends a string at NUL, skips a raw NUL and reads 0001 as 1. */
static void model_should_refuse_nul_leading_zeros_and_invalid_utf8_as_not_json(void **state)
{
    (void)state;
    static const struct {
        const char *text;
        size_t len;
        const char *pointer, *words;
    } cases[] = {
#define C(s) s, sizeof s - 1
        { C("{\"pde\\u0000junk\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-1,-1,-1]}}"), "", "\\u0000" },
        { C("{\"preset\":\"fig4a\\u0000x\"}"), "/preset", "\\u0000" },
        { C("{\"preset\":\"fig4a\\u0000\"}"), "/preset", "\\u0000" },
        { C("{\0\"preset\":\"fig4a\"}"), "", "NUL" },
        { C("{\"preset\":\"fig4a\"}\0"), "", "NUL" },
        { C("{\"preset\":\"fig4a\0\"}"), "/preset", "NUL" },
        { C("{\"preset\":\"fig4a\",\"params\":{\"p0\":0001}}"), "/params/p0", "leading zero" },
        { C("{\"preset\":\"fig\xff\"}"), "/preset", "UTF-8" },
        { C("{\"preset\":\"fig\xc0\xae\"}"), "/preset", "UTF-8" },
        { C("{\"preset\":\"fig\\ud800\"}"), "/preset", "surrogate" },
#undef C
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        api_error err;
        char *copy = malloc(cases[i].len);
        memcpy(copy, cases[i].text, cases[i].len);
        api_model *m = api_model_parse(copy, cases[i].len, &err);
        free(copy);
        if (m)
            fail_msg("case %zu parsed", i);
        if (err.status != API_ERR_NOT_JSON || strcmp(err.pointer, cases[i].pointer) != 0 || !strstr(err.message, cases[i].words))
            fail_msg("case %zu: got %d %s: %s", i, (int)err.status, err.pointer, err.message);
    }
    double *p;
    size_t n;
    int d;
    const char *pts = "{\"points\":[[0,0,01]]}";
    assert_int_equal(api_eval_parse(pts, strlen(pts), 10, &p, &n, &d, &perr), -1);
    assert_int_equal(perr.status, API_ERR_NOT_JSON);
    assert_string_equal(perr.pointer, "/points/0/2");
    assert_int_equal(api_points_parse("[[0,0,1]]\0", 10, &p, &n, &perr), -1);
    assert_int_equal(perr.status, API_ERR_NOT_JSON);
}

static void solve_errors_should_point_at_the_term_or_coefficient(void **state)
{
    (void)state;
    api_error err;
    api_model *m = parse("{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-1,-1,0]}}", &err);
    assert_non_null(m);
    pde_solution *sol = NULL;
    assert_int_equal(api_solve(m, &sol, &err), PDE_ERR_ILLPOSED);
    assert_string_equal(err.pointer, "/pde/c/2");
    assert_non_null(strstr(err.message, "component z"));
    api_model_free(m);
    /* Clamped-beam eigenvalue on y's second term: e = pi^4 / |c| = t0^4. */
    char text[512];
    double c = -pow(M_PI / 4.730040744862704, 4);
    snprintf(text, sizeof text,
             "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-1,%.17g,-1]},"
             "\"boundary\":{\"y\":[{\"w0\":1},{\"v\":{\"sin\":1},\"w1\":1}]}}", c);
    m = parse(text, &err);
    assert_non_null(m);
    assert_int_equal(api_solve(m, &sol, &err), PDE_ERR_SINGULAR);
    assert_string_equal(err.pointer, "/boundary/y/1");
    assert_non_null(strstr(err.message, "eigenvalue"));
    assert_null(sol);
    api_model_free(m);
    /* |c| so small against a and b that h's boundary layers (width e^(-1/4)) are thinner than a double
     * resolves: refused at c, not answered 200 with a boundary residual of 8e59 (a QA probe's model). */
    m = parse("{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-1e-300,1,1]},"
              "\"boundary\":{\"x\":[{\"u\":{\"sin\":1},\"w0\":1}]}}", &err);
    assert_non_null(m);
    assert_int_equal(api_solve(m, &sol, &err), PDE_ERR_RANGE);
    assert_string_equal(err.pointer, "/pde/c/0");
    assert_non_null(strstr(err.message, "boundary layer"));
    assert_null(sol);
    api_model_free(m);
}

static void eval_requests_should_parse_and_name_bad_entries(void **state)
{
    (void)state;
    api_error err;
    double *p;
    size_t n;
    int d = -1;
    const char *ok = "{\"points\":[[0,0.5,1]],\"derivatives\":true}";
    assert_int_equal(api_eval_parse(ok, strlen(ok), 10, &p, &n, &d, &err), 0);
    assert_true(n == 1 && d == 1 && p[1] == 0.5);
    free(p);
    const char *cases[][3] = { { "{}", "/points", "required" },
                               { "{\"points\":[],\"extra\":1}", "/extra", "unknown key \"extra\"" },
                               { "{\"points\":[[1,2,3]],\"derivatives\":1}", "/derivatives", "true or false" },
                               { "{\"points\":[[1,2]]}", "/points/0", "three numbers" },
                               { "{\"points\":[[1,2,3],[1,2,3],[1,2,3]]}", "/points", "more than 2 points" } };
    for (size_t i = 0; i < 5; i++) {
        assert_int_equal(api_eval_parse(cases[i][0], strlen(cases[i][0]), 2, &p, &n, &d, &err), -1);
        assert_string_equal(err.pointer, cases[i][1]);
        assert_non_null(strstr(err.message, cases[i][2]));
        assert_int_equal(err.status, i == 4 ? API_ERR_LIMIT : API_ERR_DOCUMENT);
    }
}

static void points_should_parse_and_name_bad_entries(void **state)
{
    (void)state;
    api_error err;
    double *p;
    size_t n;
    const char *ok = "[[0,0.5,1],[1e-3,2,-1]]";
    assert_int_equal(api_points_parse(ok, strlen(ok), &p, &n, &err), 0);
    assert_int_equal(n, 2);
    assert_true(p[1] == 0.5 && p[3] == 1e-3 && p[5] == -1);
    free(p);
    const char *cases[][3] = { { "{}", "", "array" },
                               { "[[0,0,0],[1,1]]", "/1", "three numbers" },
                               { "[[0,0,\"w\"]]", "/0/2", "must be a number" },
                               { "[[0,0,1e400]]", "/0/2", "finite" } };
    for (size_t i = 0; i < 4; i++) {
        assert_int_equal(api_points_parse(cases[i][0], strlen(cases[i][0]), &p, &n, &err), -1);
        assert_string_equal(err.pointer, cases[i][1]);
        assert_non_null(strstr(err.message, cases[i][2]));
    }
}

/* Numbers a double holds but %.15g does not name (cJSON's writer settles for 15 digits within an epsilon):
 * the model's JSON must give the same doubles, and so the same id, back; the store keeps a solid as that
 * text and rebuilt 0.5609999999999999 as 0.561, an id that was not its own. */
static void model_json_should_give_every_number_back_exactly(void **state)
{
    (void)state;
    static const char text[] =
        "{\"pde\": {\"a\": [0.30000000000000004, 1, 1], \"b\": [1, 1, 1], \"c\": [1, 1, 2.4000000000000004]},"
        " \"boundary\": {\"x\": [{\"u\": {\"pow\": 1}, \"w0\": 0.5609999999999999, \"dw0\": 1e-310,"
        " \"w1\": 0.1, \"dw1\": -1.7976931348623157e308}],"
        " \"y\": [{\"v\": {\"exp\": 0.30000000000000004}, \"w1\": 1}], \"z\": [{\"w1\": 1}]},"
        " \"force\": {\"z\": [{\"coef\": 4.000000000000001, \"w\": {\"sin\": 2}}]}}";
    api_error err;
    api_model *m = parse(text, &err);
    assert_non_null(m);
    const pde_model *a = api_model_get(m);
    assert_true(a->comp[0].bterms[0].w0 == 0.5609999999999999);
    char *json = api_model_json(a);
    assert_non_null(json);
    api_model *back = parse(json, &err);
    assert_non_null(back);
    const pde_model *b = api_model_get(back);
    char ida[API_ID_LEN + 1], idb[API_ID_LEN + 1];
    assert_int_equal(api_model_id(a, ida, NULL), PDE_OK);
    assert_int_equal(api_model_id(b, idb, NULL), PDE_OK);
    assert_string_equal(ida, idb);
    assert_true(b->comp[0].bterms[0].w0 == 0.5609999999999999);
    assert_true(b->comp[0].bterms[0].dw0 == 1e-310);
    assert_true(b->comp[1].bterms[0].v.p == 0.30000000000000004);
    assert_true(b->comp[0].a == 0.30000000000000004 && b->comp[2].c == 2.4000000000000004);
    assert_true(b->comp[2].fterms[0].coef == 4.000000000000001);
    free(json);
    api_model_free(back);
    api_model_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(model_should_read_the_issue_example_as_the_papers_figure_4a),
        cmocka_unit_test(model_json_should_give_every_number_back_exactly),
        cmocka_unit_test(model_should_default_omitted_factors_to_one_and_numbers_to_zero),
        cmocka_unit_test(model_should_name_the_field_of_every_kind_of_bad_input),
        cmocka_unit_test(model_should_refuse_deep_nesting_and_huge_documents),
        cmocka_unit_test(model_should_refuse_nul_leading_zeros_and_invalid_utf8_as_not_json),
        cmocka_unit_test(solve_errors_should_point_at_the_term_or_coefficient),
        cmocka_unit_test(points_should_parse_and_name_bad_entries),
        cmocka_unit_test(eval_requests_should_parse_and_name_bad_entries),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("model_json", tests, NULL, NULL);
}
