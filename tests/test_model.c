/*
 * test_model.c: the canonical form of a model (core/model.c).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "support.h"

static void assert_same_canonical(const pde_model *a, const pde_model *b)
{
    pde_model ca, cb;
    assert_int_equal(pde_model_canonical(a, &ca, NULL), PDE_OK);
    assert_int_equal(pde_model_canonical(b, &cb, NULL), PDE_OK);
    for (int c = 0; c < 3; c++) {
        assert_int_equal(ca.comp[c].nbterms, cb.comp[c].nbterms);
        assert_int_equal(ca.comp[c].nfterms, cb.comp[c].nfterms);
        assert_memory_equal(ca.comp[c].bterms, cb.comp[c].bterms, ca.comp[c].nbterms * sizeof(pde_bterm));
        assert_memory_equal(ca.comp[c].fterms, cb.comp[c].fterms, ca.comp[c].nfterms * sizeof(pde_fterm));
        assert_true(ca.comp[c].a == cb.comp[c].a && ca.comp[c].b == cb.comp[c].b && ca.comp[c].c == cb.comp[c].c);
    }
    pde_model_canonical_free(&ca);
    pde_model_canonical_free(&cb);
}

static void canonical_should_not_depend_on_how_the_model_is_written(void **state)
{
    (void)state;
    /* 0.1 + 0.2 + 0.3 is not 0.3 + 0.2 + 0.1 in floating point: the sums must be order-free. */
    pde_bterm a[5] = { { F_pow(1), F_sin(2), 0.1, 1, 0, 0 },
                       { F_pow(0), F_pow(0), 1, 0, 2, 0 },
                       { F_pow(1), F_sin(2), 0.2, 0, 0, 0 },
                       { F_pow(1), F_sin(-2), -0.3, 0, 0, 0 },    /* sin(-2) = -sin(2) */
                       { F_sinh(0), F_cos(1), 5, 5, 5, 5 } };      /* sinh 0 = 0: gone */
    pde_bterm b[4] = { { F_cos(0), F_exp(0), 1, 0, 2, 0 },        /* cos 0 = exp 0 = 1 */
                       { F_pow(1), F_sin(2), 0.3, 0, 0, 0 },
                       { F_pow(1), F_sin(2), 0.2, 0, 0, 0 },
                       { F_pow(1), F_sin(2), 0.1, 1, 0, 0 } };
    pde_fterm fa[3] = { { 2, F_pow(1), F_cos(-2), F_sin(3) }, { 1, F_pow(1), F_cos(2), F_sin(3) },
                        { 0, F_pow(2), F_pow(0), F_pow(0) } };    /* coef 0: gone */
    pde_fterm fb[1] = { { -3, F_pow(1), F_cos(2), F_sin(-3) } };
    pde_model ma = { { { 1, 1, -9.5, a, 5, fa, 3 }, { 1, 1, -1, NULL, 0, NULL, 0 }, { 1, 1, -1, NULL, 0, NULL, 0 } } };
    pde_model mb = { { { 1, 1, -9.5, b, 4, fb, 1 }, { 1, 1, -1, NULL, 0, NULL, 0 }, { 1, 1, -1, NULL, 0, NULL, 0 } } };
    assert_same_canonical(&ma, &mb);
    pde_model c;
    assert_int_equal(pde_model_canonical(&ma, &c, NULL), PDE_OK);
    assert_int_equal(c.comp[0].nbterms, 2);
    assert_int_equal(c.comp[0].nfterms, 1);
    /* It solves to the same solid. */
    pde_solution *s1, *s2;
    assert_int_equal(pde_solve(&ma, &s1, NULL), PDE_OK);
    assert_int_equal(pde_solve(&c, &s2, NULL), PDE_OK);
    for (int i = 0; i < 27; i++) {
        double x1[3], x2[3], p[3] = { (i % 3) / 2.0, (i / 3 % 3) / 2.0, (i / 9) / 2.0 };
        pde_eval(s1, p[0], p[1], p[2], x1);
        pde_eval(s2, p[0], p[1], p[2], x2);
        assert_rel(x1[0], x2[0], 1e-14, 1);
    }
    pde_solution_free(s1);
    pde_solution_free(s2);
    pde_model_canonical_free(&c);
    pde_model_canonical_free(NULL);
}

static void canonical_should_validate_like_solve(void **state)
{
    (void)state;
    pde_bterm bt = { F_pow(1), F_sin(NAN), 1, 0, 0, 0 };
    pde_model m = { { { 1, 1, -1, &bt, 1, NULL, 0 }, { 1, 1, -1, NULL, 0, NULL, 0 }, { 1, 1, 0, NULL, 0, NULL, 0 } } };
    pde_model out;
    memset(&out, 0x5a, sizeof out);
    pde_model before = out;
    pde_diag d;
    assert_int_equal(pde_model_canonical(&m, &out, &d), PDE_ERR_INVALID);
    assert_string_equal(d.field, "v");
    assert_memory_equal(&out, &before, sizeof out);
    bt.v = F_sin(1);
    assert_int_equal(pde_model_canonical(&m, &out, &d), PDE_ERR_ILLPOSED);
    assert_int_equal(d.component, 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(canonical_should_not_depend_on_how_the_model_is_written),
        cmocka_unit_test(canonical_should_validate_like_solve),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("model", tests, NULL, NULL);
}
