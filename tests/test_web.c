/*
 * test_web.c: the browser front-end in a real browser. Starts pdesolidd
 * with the front-end and runs tests/node/browser.mjs, which drives Debian's
 * Chromium through playwright-core: the page loads with no console errors and
 * draws fig4a; the gallery loads every preset; a control re-solves and changes
 * the picture; an invalid value shows the server's error beside its field;
 * the panel shows the centroid, surface area, moments and inertia the server
 * computed; the loft editor builds, uploads and solves lofts and shows a bad
 * section's error beside it, and the loft presets draw (while the daemon
 * refuses lofts, browser.mjs says so and skips those); share links reopen a
 * solid, also after the daemon restarts on the same --store; undo and redo;
 * the automatic resolution; framing clear of the panels; det J on the skin;
 * the gallery by keyboard; axe-core; the 390x844 drawer; the responsiveness
 * figure (input to frame, printed and saved). The loft editor's shape
 * generators are checked in node against their curves (tests/node/shapes.mjs).
 * Screenshots go to build/artifacts/web/.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "support.h"

static char dir[] = "/tmp/pdesolid-web-XXXXXX";

static void the_front_end_should_work_in_a_real_browser(void **state)
{
    (void)state;
    assert_int_equal(tmpdir_make(dir), 0);
    daemon_t d;
    char args[256], cmd[768], path[128];
    /* A durable store, so that share links (GET /solids/{id}/request) work, and still work after a restart. */
    snprintf(args, sizeof args, "--web clients/web --quiet --store %s/store", dir);
    daemon_start(&d, dir, args);
    snprintf(cmd, sizeof cmd, "node tests/node/browser.mjs %s build/artifacts/web > %s/browser.txt 2>&1", d.base, dir);
    int st = system(cmd);
    snprintf(path, sizeof path, "%s/browser.txt", dir);
    char *report = read_file(path, NULL);
    printf("%s", report ? report : "");
    daemon_stop(&d);
    free(report);
    if (st != 0)
        fail_msg("the browser checks failed (screenshots in build/artifacts/web)");
    /* The same store after a restart (on another port): the share link the first run took still opens its solid. */
    daemon_start(&d, dir, args);
    snprintf(cmd, sizeof cmd,
             "node tests/node/browser.mjs %s build/artifacts/web --reopen build/artifacts/web/share-id.txt > %s/reopen.txt 2>&1",
             d.base, dir);
    st = system(cmd);
    snprintf(path, sizeof path, "%s/reopen.txt", dir);
    report = read_file(path, NULL);
    printf("%s", report ? report : "");
    daemon_stop(&d);
    free(report);
    if (st != 0)
        fail_msg("the share link did not survive a restart (screenshots in build/artifacts/web)");
    assert_int_equal(tmpdir_remove(dir), 0);
}

static void the_loft_shape_generators_should_lie_on_their_curves(void **state)
{
    (void)state;
    char out[1 << 12] = "";
    FILE *p = popen("node tests/node/shapes.mjs 2>&1", "r");
    assert_non_null(p);
    size_t n = fread(out, 1, sizeof out - 1, p);
    out[n] = '\0';
    int st = pclose(p);
    printf("%s", out);
    assert_int_equal(st, 0);
    /* every check ran and passed: shapes.mjs ends with "all N checks passed" and prints no "not ok" line */
    assert_non_null(strstr(out, " checks passed"));
    assert_null(strstr(out, "not ok"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_loft_shape_generators_should_lie_on_their_curves),
        cmocka_unit_test(the_front_end_should_work_in_a_real_browser),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("web", tests, NULL, NULL);
}
