/*
 * test_deploy.c: `make install` into a temporary tree, and what it installs:
 * the programs, the front-end's files (every file the daemon's table serves),
 * the manual pages (rendered by man -l without a warning, naming every option
 * of the programs' --help) and the systemd unit (systemd-analyze verify). The
 * installed daemon, given no --web, serves the installed front-end.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "support.h"

static char dir[] = "/tmp/pdesolid-deploy-XXXXXX";

/* Runs a shell command; its status, with its output in dir/out.txt. */
static int run(const char *cmd)
{
    char full[2048];
    snprintf(full, sizeof full, "(%s) >%s/out.txt 2>&1", cmd, dir);
    return system(full);
}

static char *output(void)
{
    char path[128];
    snprintf(path, sizeof path, "%s/out.txt", dir);
    char *t = read_file(path, NULL);
    return t ? t : strdup("");
}

/* make install, outside the make that runs the tests (its jobserver is not ours). */
static void install(const char *vars)
{
    char cmd[512];
    snprintf(cmd, sizeof cmd, "env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s install %s", vars);
    if (run(cmd)) {
        char *o = output();
        fail_msg("%s failed:\n%s", cmd, o);
    }
}

static int setup(void **state)
{
    (void)state;
    if (!mkdtemp(dir))
        return -1;
    char vars[256];
    snprintf(vars, sizeof vars, "DESTDIR=%s/dest", dir);
    install(vars);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) ? -1 : 0;
}

static void installed_files_should_be_in_place_with_their_modes(void **state)
{
    (void)state;
    static const struct {
        const char *path;
        unsigned mode;
    } want[] = {
        { "usr/local/bin/pdesolid", 0755 },
        { "usr/local/sbin/pdesolidd", 0755 },
        { "usr/local/share/man/man1/pdesolid.1", 0644 },
        { "usr/local/share/man/man8/pdesolidd.8", 0644 },
        { "usr/local/lib/systemd/system/pdesolidd.service", 0644 },
        { "usr/local/share/pdesolid/web/index.html", 0644 },
        { "usr/local/share/pdesolid/web/node_modules/three/build/three.module.js", 0644 },
    };
    for (size_t i = 0; i < sizeof want / sizeof *want; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/dest/%s", dir, want[i].path);
        struct stat st;
        if (stat(path, &st))
            fail_msg("%s was not installed", want[i].path);
        if ((st.st_mode & 0777) != want[i].mode)
            fail_msg("%s has mode %o, not %o", want[i].path, st.st_mode & 0777, want[i].mode);
    }
    /* The unit names the installed paths, not the placeholders. */
    char path[512];
    snprintf(path, sizeof path, "%s/dest/usr/local/lib/systemd/system/pdesolidd.service", dir);
    char *unit = read_file(path, NULL);
    assert_non_null(unit);
    assert_null(strstr(unit, "@SBINDIR@"));
    assert_null(strstr(unit, "@DATADIR@"));
    assert_non_null(strstr(unit, "ExecStart=/usr/local/sbin/pdesolidd "));
    assert_non_null(strstr(unit, "--web /usr/local/share/pdesolid/web"));
    free(unit);
}

/* Each option of `prog --help` (a line's first word starting with -) appears in the page as \-\-opt. */
static void page_should_name_every_option(const char *prog, const char *page)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "%s --help", prog);
    assert_int_equal(run(cmd), 0);
    char *help = output(), *text = read_file(page, NULL);
    assert_non_null(text);
    size_t n = 0;
    for (char *line = strtok(help, "\n"); line; line = strtok(NULL, "\n")) {
        while (*line == ' ')
            line++;
        if (line[0] != '-')
            continue;
        char opt[64], roff[160] = "";
        size_t k = 0;
        while (line[k] && line[k] != ' ' && line[k] != ',' && k + 1 < sizeof opt)
            opt[k] = line[k], k++;
        opt[k] = '\0';
        for (const char *c = opt; *c; c++)
            strncat(roff, *c == '-' ? "\\-" : (char[2]){ *c, 0 }, sizeof roff - strlen(roff) - 1);
        if (!strstr(text, roff))
            fail_msg("%s does not document %s (%s)", page, opt, roff);
        n++;
    }
    assert_true(n >= 5);
    free(help);
    free(text);
}

static void manual_pages_should_render_cleanly_and_name_every_option(void **state)
{
    (void)state;
    const char *pages[] = { "man1/pdesolid.1", "man8/pdesolidd.8" };
    for (int i = 0; i < 2; i++) {
        char cmd[512];
        snprintf(cmd, sizeof cmd, "MANWIDTH=80 man --warnings -E UTF-8 -l %s/dest/usr/local/share/man/%s >/dev/null", dir,
                 pages[i]);
        int rc = run(cmd);
        char *o = output();
        if (rc || o[0])
            fail_msg("man -l %s: status %d:\n%s", pages[i], rc, o);
        free(o);
    }
    char page[512];
    snprintf(page, sizeof page, "%s/dest/usr/local/share/man/man1/pdesolid.1", dir);
    page_should_name_every_option(getenv("PDESOLID") ? getenv("PDESOLID") : "build/pdesolid", page);
    snprintf(page, sizeof page, "%s/dest/usr/local/share/man/man8/pdesolidd.8", dir);
    page_should_name_every_option(getenv("PDESOLIDD_SAN") ? getenv("PDESOLIDD_SAN") : "build/san/pdesolidd", page);
}

static void the_unit_should_pass_systemd_analyze_verify(void **state)
{
    (void)state;
    if (access("/usr/bin/systemd-analyze", X_OK)) {
        print_message("skipped: no systemd-analyze\n");
        return;
    }
    /* Installed with the temporary tree as its PREFIX, so that ExecStart's path exists. */
    char vars[256], cmd[512];
    snprintf(vars, sizeof vars, "PREFIX=%s/prefix", dir);
    install(vars);
    snprintf(cmd, sizeof cmd, "systemd-analyze verify --man=no %s/prefix/lib/systemd/system/pdesolidd.service", dir);
    int rc = run(cmd);
    char *o = output();
    if (rc || o[0])
        fail_msg("%s: status %d:\n%s", cmd, rc, o);
    free(o);
}

static void the_installed_daemon_should_serve_the_installed_front_end(void **state)
{
    (void)state;
    char bin[512], *saved = getenv("PDESOLIDD_SAN") ? strdup(getenv("PDESOLIDD_SAN")) : NULL;
    snprintf(bin, sizeof bin, "%s/dest/usr/local/sbin/pdesolidd", dir);
    setenv("PDESOLIDD_SAN", bin, 1);
    daemon_t d;
    daemon_start(&d, dir, "--quiet");
    if (saved) {
        setenv("PDESOLIDD_SAN", saved, 1);
        free(saved);
    } else
        unsetenv("PDESOLIDD_SAN");
    const char *paths[] = { "/", "/app.js", "/vendor/three/three.module.js" };
    for (int i = 0; i < 3; i++) {
        char req[256];
        int n = snprintf(req, sizeof req, "GET %s HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n", paths[i]);
        raw_reply r = raw_request(d.port, req, (size_t)n, 5000);
        if (r.status != 200)
            fail_msg("GET %s from the installed daemon: %d", paths[i], r.status);
        raw_reply_free(&r);
    }
    daemon_stop(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(installed_files_should_be_in_place_with_their_modes),
        cmocka_unit_test(manual_pages_should_render_cleanly_and_name_every_option),
        cmocka_unit_test(the_unit_should_pass_systemd_analyze_verify),
        cmocka_unit_test(the_installed_daemon_should_serve_the_installed_front_end),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
