/*
 * test_numfmt.c: the grid JSON's number writer. Every float32 it writes must
 * parse back (as float, and as double then float, as JavaScript does) to the
 * same float32, in valid JSON syntax.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "numfmt.h"
#include "support.h"

static void check(float f)
{
    char b[API_F32_MAX + 1];
    size_t n = api_fmt_f32(b, f);
    assert_true(n > 0 && n <= API_F32_MAX);
    b[n] = '\0';
    if (!isfinite(f)) {
        assert_string_equal(b, "null");
        return;
    }
    char *end;
    float g = strtof(b, &end);
    assert_true(*end == '\0');
    if (g != f || (float)strtod(b, NULL) != f)
        fail_msg("%a written as %s reads back as %a", (double)f, b, (double)g);
    /* JSON numbers: -?digits[.digits][e[-]digits], no leading '+', no leading zeros, no trailing '.'. */
    const char *p = b + (b[0] == '-');
    assert_true(p[0] >= '0' && p[0] <= '9');
    assert_false(p[0] == '0' && p[1] >= '0' && p[1] <= '9');
    assert_null(strchr(b, '+'));
    const char *dot = strchr(b, '.');
    if (dot)
        assert_true(dot[1] >= '0' && dot[1] <= '9');
}

static void fmt_should_round_trip_float32_across_the_whole_range(void **state)
{
    (void)state;
    /* Every 4099th bit pattern (about a million values: all exponents, both signs, subnormals). */
    for (uint64_t u = 0; u <= 0xffffffffull; u += 4099) {
        uint32_t w = (uint32_t)u;
        float f;
        memcpy(&f, &w, 4);
        check(f);
    }
    const float edge[] = { 0.0f, -0.0f, 1.0f, -1.0f, 0.1f, 1e-45f, 1.17549435e-38f, 3.40282347e38f, 1e9f,
                           999999999.0f, 1e8f, 123456.789f, 1e-5f, 9.99999e-6f, 0.5f, 100.0f, INFINITY, NAN };
    for (size_t i = 0; i < sizeof edge / sizeof *edge; i++)
        check(edge[i]);
}

static void fmt_should_write_short_plain_forms(void **state)
{
    (void)state;
    const struct {
        float f;
        const char *s;
    } cases[] = { { 0.0f, "0" },     { 1.5f, "1.5" },        { 1500.0f, "1500" },  { -2.5f, "-2.5" },
                  { 0.5f, "0.5" },   { 3.0f, "3" },          { 1e9f, "1e9" },      { 0.25f, "0.25" },
                  { 1e-7f, "1.00000001e-7" }, { 0.00012f, "0.000119999997" } };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        char b[API_F32_MAX + 1];
        b[api_fmt_f32(b, cases[i].f)] = '\0';
        assert_string_equal(b, cases[i].s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fmt_should_round_trip_float32_across_the_whole_range),
        cmocka_unit_test(fmt_should_write_short_plain_forms),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("numfmt", tests, NULL, NULL);
}
