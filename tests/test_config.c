/*
 * test_config.c: pdesolidd's flags (server/config.c). Every flag in both
 * forms, the defaults, each error naming its argument, --web checked,
 * srv_config_print read back, and one version: docs/openapi.yaml's
 * info.version is api/version.h's PDESOLID_VERSION.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "config.h"
#include "support.h"
#include "version.h"

#define MAXARGS 64

typedef struct {
    int rc;
    char out[8192], err[2048];
} result;

static void slurp(FILE *f, char *buf, size_t n)
{
    rewind(f);
    size_t k = fread(buf, 1, n - 1, f);
    buf[k] = '\0';
    fclose(f);
}

/* srv_config_parse on "pdesolidd" and the NULL-terminated args. */
static result parse(srv_config *c, const char *const *args)
{
    char *argv[MAXARGS] = { "pdesolidd" };
    int argc = 1;
    for (; args[argc - 1]; argc++) {
        assert_true(argc < MAXARGS - 1);
        argv[argc] = (char *)args[argc - 1];
    }
    argv[argc] = NULL;
    FILE *out = tmpfile(), *err = tmpfile();
    assert_non_null(out);
    assert_non_null(err);
    result r;
    r.rc = srv_config_parse(argc, argv, c, out, err);
    slurp(out, r.out, sizeof r.out);
    slurp(err, r.err, sizeof r.err);
    return r;
}

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static srv_config defaults(void)
{
    srv_config c;
    result r = parse(&c, ARGS(NULL));
    assert_int_equal(r.rc, 0);
    return c;
}

static void defaults_should_be_those_the_usage_gives(void **state)
{
    (void)state;
    srv_config c;
    result r = parse(&c, ARGS(NULL));
    assert_int_equal(r.rc, 0);
    assert_string_equal(r.out, "");
    /* build/san/tests/test_config finds the source tree's front-end, two levels up. */
    assert_string_equal(r.err, "");
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    assert_string_equal(c.bind, "127.0.0.1");
    assert_int_equal(c.port, 8080);
    assert_int_equal(c.threads, cores);
    assert_int_equal(c.http_threads, cores);
    assert_int_equal(c.queue, 64);
    assert_int_equal(c.cache_bytes, 256u << 20);
    assert_int_equal(c.max_body, 1u << 20);
    assert_int_equal(c.max_points, 100000);
    assert_string_equal(c.cors, "");
    assert_string_equal(c.allow_host, "");
    assert_int_equal(c.timeout, 30);
    assert_int_equal(c.per_ip, 128);
    assert_int_equal(c.max_conns, 1024);
    assert_int_equal(c.grace, 30);
    size_t n = strlen(c.web);
    assert_true(n > 12 && !strcmp(c.web + n - 12, "/clients/web"));
    char index[1100];
    snprintf(index, sizeof index, "%s/index.html", c.web);
    assert_int_equal(access(index, R_OK), 0);
    assert_int_equal(c.quiet, 0);
    assert_true(c.request_timeout == 30.0);
    assert_true(c.job_timeout == 2.0);
    assert_true(c.max_work == 1e9);
    assert_int_equal(c.max_mem, 64u << 20);
    assert_int_equal(c.log_format, SRV_LOG_TEXT);
    assert_string_equal(c.store, "var/store");
    assert_int_equal(c.store_mb, 256);
    assert_string_equal(c.store_prefix, "pdesolid:");
    assert_int_equal(c.store_ttl, 0);
}

/* One row per flag that takes a value: a value, and the default with that one field set by hand. */
static const struct {
    const char *flag, *value;
} every_flag[] = {
    { "--bind", "::1" },           { "--port", "19001" },          { "--threads", "3" },
    { "--http-threads", "5" },     { "--queue", "7" },             { "--cache-mb", "9" },
    { "--max-body", "512KiB" },    { "--max-points", "42" },       { "--max-work", "3e9" },
    { "--max-work", "3000000000" }, { "--max-mem-mb", "16" },      { "--job-timeout", "0.5" },
    { "--request-timeout", "12.5" }, { "--timeout", "7" },         { "--max-conns-per-ip", "3" },
    { "--max-conns", "11" },       { "--grace", "4" },             { "--cors-origin", "http://a.example,http://b.example" },
    { "--web", "clients/web" },    { "--log-format", "json" },
    { "--store", "redis://127.0.0.1:6379/2" }, { "--store-mb", "3" }, { "--store-prefix", "pde:" },
    { "--store-ttl", "86400" },    { "--heavy-work", "2.5e8" },    { "--heavy-queue", "3" },
    { "--allow-host", "pdesolid.example.org,.Example.COM." },
};

static void expect(srv_config *e, const char *flag)
{
    if (!strcmp(flag, "--bind"))
        strcpy(e->bind, "::1");
    else if (!strcmp(flag, "--port"))
        e->port = 19001;
    else if (!strcmp(flag, "--threads"))
        e->threads = 3;
    else if (!strcmp(flag, "--http-threads"))
        e->http_threads = 5;
    else if (!strcmp(flag, "--queue"))
        e->queue = 7;
    else if (!strcmp(flag, "--cache-mb"))
        e->cache_bytes = 9u << 20;
    else if (!strcmp(flag, "--max-body"))
        e->max_body = 524288;
    else if (!strcmp(flag, "--max-points"))
        e->max_points = 42;
    else if (!strcmp(flag, "--max-work"))
        e->max_work = 3e9;
    else if (!strcmp(flag, "--max-mem-mb"))
        e->max_mem = 16u << 20;
    else if (!strcmp(flag, "--job-timeout"))
        e->job_timeout = 0.5;
    else if (!strcmp(flag, "--heavy-work"))
        e->heavy_work = 2.5e8;
    else if (!strcmp(flag, "--heavy-queue"))
        e->heavy_queue = 3;
    else if (!strcmp(flag, "--request-timeout"))
        e->request_timeout = 12.5;
    else if (!strcmp(flag, "--timeout"))
        e->timeout = 7;
    else if (!strcmp(flag, "--max-conns-per-ip"))
        e->per_ip = 3;
    else if (!strcmp(flag, "--max-conns"))
        e->max_conns = 11;
    else if (!strcmp(flag, "--grace"))
        e->grace = 4;
    else if (!strcmp(flag, "--cors-origin"))
        strcpy(e->cors, "http://a.example,http://b.example");
    else if (!strcmp(flag, "--allow-host"))
        strcpy(e->allow_host, "pdesolid.example.org,.Example.COM.");
    else if (!strcmp(flag, "--web"))
        strcpy(e->web, "clients/web");
    else if (!strcmp(flag, "--log-format"))
        e->log_format = SRV_LOG_JSON;
    else if (!strcmp(flag, "--store"))
        strcpy(e->store, "redis://127.0.0.1:6379/2");
    else if (!strcmp(flag, "--store-mb"))
        e->store_mb = 3;
    else if (!strcmp(flag, "--store-prefix"))
        strcpy(e->store_prefix, "pde:");
    else if (!strcmp(flag, "--store-ttl"))
        e->store_ttl = 86400;
    else
        fail_msg("no expectation for %s", flag);
}

static void every_flag_should_take_its_value_in_both_forms(void **state)
{
    (void)state;
    const srv_config d = defaults();
    for (size_t i = 0; i < sizeof every_flag / sizeof *every_flag; i++) {
        const char *f = every_flag[i].flag, *v = every_flag[i].value;
        srv_config want = d, c1, c2;
        expect(&want, f);
        char eq[256];
        snprintf(eq, sizeof eq, "%s=%s", f, v);
        result r1 = parse(&c1, ARGS(f, v)), r2 = parse(&c2, ARGS(eq));
        if (r1.rc || r2.rc)
            fail_msg("%s %s: %d, %s: %d; %s%s", f, v, r1.rc, eq, r2.rc, r1.err, r2.err);
        if (memcmp(&c1, &want, sizeof want) || memcmp(&c2, &want, sizeof want))
            fail_msg("%s %s: not the default with that field set", f, v);
    }
    srv_config c;
    assert_int_equal(parse(&c, ARGS("--quiet")).rc, 0);
    assert_int_equal(c.quiet, 1);
    /* Several at once, in both forms, and a value that starts with '-' after '='. */
    result r = parse(&c, ARGS("--port=19001", "--quiet", "--threads", "2", "--cors-origin=*", "--log-format", "json"));
    assert_int_equal(r.rc, 0);
    assert_int_equal(c.port, 19001);
    assert_int_equal(c.threads, 2);
    assert_string_equal(c.cors, "*");
    assert_int_equal(c.log_format, SRV_LOG_JSON);
}

static void every_flag_in_the_usage_should_be_tested(void **state)
{
    (void)state;
    srv_config c;
    result r = parse(&c, ARGS("--help"));
    assert_int_equal(r.rc, 1);
    int flags = 0;
    for (const char *p = r.out; (p = strstr(p, "\n  --")); p++) {
        char name[64];
        assert_int_equal(sscanf(p + 3, "%63s", name), 1);
        flags++;
        if (!strcmp(name, "--quiet") || !strcmp(name, "--version"))
            continue;
        int found = 0;
        for (size_t i = 0; i < sizeof every_flag / sizeof *every_flag; i++)
            found |= !strcmp(every_flag[i].flag, name);
        if (!found)
            fail_msg("%s is in the usage but not in every_flag", name);
    }
    assert_int_equal(flags, 28);   /* 26 with values, --quiet, --version ("-h, --help" starts otherwise) */
    assert_non_null(strstr(r.out, "-h, --help"));
}

static void each_error_should_exit_2_naming_its_argument(void **state)
{
    (void)state;
    const struct {
        const char *const *args;
        const char *says;
    } bad[] = {
        { ARGS("extra"), "unexpected argument extra:" },
        { ARGS("--port", "1", "stray"), "unexpected argument stray:" },
        { ARGS("--port"), "--port needs a value" },
        { ARGS("--port", "--quiet"), "--port needs a value" },
        { ARGS("--port=abc"), "--port=abc: not a valid value" },
        { ARGS("--port", "abc"), "--port abc: not a valid value" },
        { ARGS("--port=-1"), "--port=-1: not a valid value" },
        { ARGS("--port=65536"), "--port=65536: not a valid value; give a whole number from 0 to 65535" },
        { ARGS("--port="), "--port=: not a valid value" },
        { ARGS("--threads", "0"), "--threads 0: not a valid value" },
        { ARGS("--http-threads=257"), "--http-threads=257: not a valid value" },
        { ARGS("--frob"), "unknown option --frob " },
        { ARGS("--frob=1"), "unknown option --frob=1 " },
        { ARGS("-x"), "unknown option -x " },
        { ARGS("--quiet=yes"), "--quiet=yes: --quiet takes no value" },
        { ARGS("--max-work", "2e9x"), "--max-work 2e9x: not a valid value" },
        { ARGS("--max-work=inf"), "--max-work=inf: not a valid value" },
        { ARGS("--max-work=0x10"), "--max-work=0x10: not a valid value" },
        { ARGS("--max-work=0"), "--max-work=0: not a valid value" },
        { ARGS("--max-work= 5"), "--max-work= 5: not a valid value" },
        { ARGS("--job-timeout", "-1"), "--job-timeout -1: not a valid value" },
        { ARGS("--request-timeout=nan"), "--request-timeout=nan: not a valid value" },
        { ARGS("--max-mem-mb=0"), "--max-mem-mb=0: not a valid value" },
        { ARGS("--max-body=10"), "--max-body=10: not a valid value" },
        { ARGS("--max-body=1TiB"), "--max-body=1TiB: not a valid value" },
        { ARGS("--cache-mb", "99999999999999999999999"), "--cache-mb 99999999999999999999999: not a valid" },
        { ARGS("--log-format=xml"), "--log-format=xml: not a valid value; give text or json" },
        { ARGS("--bind="), "--bind=: not a valid value" },
        { ARGS("--allow-host=http://a.example"), "--allow-host=http://a.example: not a valid value; give host names" },
        { ARGS("--allow-host", "a.example:8080"), "--allow-host a.example:8080: not a valid value" },
        { ARGS("--allow-host", "a.example,,b.example"), "--allow-host a.example,,b.example: not a valid value" },
        { ARGS("--allow-host=*.example.com"), "--allow-host=*.example.com: not a valid value" },
        { ARGS("--bind", "0.0.0.0x"), "--bind 0.0.0.0x: not a valid value; give a numeric IPv4 or IPv6 address" },
        { ARGS("--bind=localhost"), "--bind=localhost: not a valid value; give a numeric" },
        /* a scheme of no store: not a directory of that name (it was: ./ftp:/x/data.mdb) */
        { ARGS("--store", "ftp://x"), "--store ftp://x: not a valid value; give DIR, lmdb:DIR, redis://HOST:PORT[/DB]" },
        { ARGS("--store=REDIS://127.0.0.1:6379"), "--store=REDIS://127.0.0.1:6379: not a valid value" },
        { ARGS("--store=redis:/x"), "--store=redis:/x: not a valid value" },
        { ARGS("--store=lmdb:"), "--store=lmdb:: not a valid value" },
        { ARGS("--store=redis://x:99999"), "--store=redis://x:99999: not a valid value" },
        { ARGS("--store=redis://:6379"), "--store=redis://:6379: not a valid value" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        srv_config c;
        result r = parse(&c, bad[i].args);
        if (r.rc != 2 || !strstr(r.err, bad[i].says) || r.out[0])
            fail_msg("case %zu: rc %d, err \"%s\", want 2 and \"%s\"", i, r.rc, r.err, bad[i].says);
        if (i == 0 && strstr(r.err, "needs a value"))
            fail_msg("a stray argument is not a flag without its value: %s", r.err);
    }
}

/* --request-timeout bounds a head's time on its connection; under a second (0.05 s is the watcher's first sweep)
 * every connection of a client not on loopback was closed before its head could arrive, and there is no 0 for
 * off (slow heads would hold connections, and an address's --max-conns-per-ip, forever): 1 is the least. */
static void request_timeout_should_be_a_second_or_more(void **state)
{
    (void)state;
    static const char *const refused[] = { "0", "0.0", "0.5", "0.999", "1e-9" };
    for (size_t i = 0; i < sizeof refused / sizeof *refused; i++) {
        srv_config c;
        result r = parse(&c, ARGS("--request-timeout", refused[i]));
        char want[96];
        snprintf(want, sizeof want, "--request-timeout %s: not a valid value; give a number from 1 to 86400", refused[i]);
        if (r.rc != 2 || !strstr(r.err, want))
            fail_msg("%s: rc %d, err \"%s\"", refused[i], r.rc, r.err);
    }
    srv_config c;
    result r = parse(&c, ARGS("--request-timeout=1"));
    assert_int_equal(r.rc, 0);
    assert_true(c.request_timeout == 1.0);
    /* the other seconds keep their bound: over 0 */
    r = parse(&c, ARGS("--job-timeout=0.001"));
    assert_int_equal(r.rc, 0);
    r = parse(&c, ARGS("--job-timeout=0"));
    assert_int_equal(r.rc, 2);
    assert_non_null(strstr(r.err, "give a number over 0 and at most 86400"));
}

/* The forms --bind and --store take beyond every_flag's, kept as given. */
static void store_and_bind_should_take_each_of_their_forms(void **state)
{
    (void)state;
    static const char *const ok[][2] = {
        { "--bind", "0.0.0.0" },   { "--bind", "127.0.0.1" },        { "--bind", "fe80::1" },
        { "--store", "none" },     { "--store", "var/store" },       { "--store", "/var/lib/pdesolid" },
        { "--store", "lmdb:/tmp/s" }, { "--store", "./ftp:x" },      /* a directory so named, written so */
        { "--store", "redis://127.0.0.1:6379" }, { "--store", "redis://cache.internal:6380/3" },
    };
    for (size_t i = 0; i < sizeof ok / sizeof *ok; i++) {
        srv_config c;
        result r = parse(&c, ARGS(ok[i][0], ok[i][1]));
        if (r.rc)
            fail_msg("%s %s: rc %d, %s", ok[i][0], ok[i][1], r.rc, r.err);
        assert_string_equal(!strcmp(ok[i][0], "--bind") ? c.bind : c.store, ok[i][1]);
    }
}

static void web_given_without_an_index_should_refuse_to_start(void **state)
{
    (void)state;
    srv_config c;
    result r = parse(&c, ARGS("--web", "/nonexistent/pdesolid-web"));
    assert_int_equal(r.rc, 2);
    assert_non_null(strstr(r.err, "--web /nonexistent/pdesolid-web: cannot read /nonexistent/pdesolid-web/index.html"));
    char dir[] = "/tmp/pdesolid-web-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char arg[64], index[64];
    snprintf(arg, sizeof arg, "--web=%s", dir);
    r = parse(&c, ARGS(arg));
    assert_int_equal(r.rc, 2);
    assert_non_null(strstr(r.err, dir));
    snprintf(index, sizeof index, "%s/index.html", dir);
    FILE *f = fopen(index, "w");
    assert_non_null(f);
    fputs("<!doctype html>\n", f);
    fclose(f);
    r = parse(&c, ARGS(arg));
    assert_int_equal(r.rc, 0);
    assert_string_equal(c.web, dir);
    assert_string_equal(r.err, "");
    unlink(index);
    rmdir(dir);
}

static void help_and_version_should_print_and_return_1(void **state)
{
    (void)state;
    srv_config c;
    result r = parse(&c, ARGS("--version"));
    assert_int_equal(r.rc, 1);
    assert_string_equal(r.out, "pdesolidd " PDESOLID_VERSION "\n");
    r = parse(&c, ARGS("-h"));
    assert_int_equal(r.rc, 1);
    assert_non_null(strstr(r.out, "usage: pdesolidd"));
    /* Every usage line fits 80 columns. */
    for (const char *p = r.out, *nl; *p; p = nl + 1) {
        nl = strchr(p, '\n');
        assert_non_null(nl);
        if (nl - p > 80)
            fail_msg("a usage line of %d columns: %.*s", (int)(nl - p), (int)(nl - p), p);
    }
}

/* Splits srv_config_print's line after "VERSION:" into arguments ('' is an empty one) and parses them. */
static void print_should_read_back_as_the_same_config(void **state)
{
    (void)state;
    srv_config c, back;
    result r = parse(&c, ARGS("--port=19001", "--max-work", "3e9", "--job-timeout", "0.25", "--quiet",
                              "--log-format", "json", "--cors-origin", "*", "--max-body", "64KiB"));
    assert_int_equal(r.rc, 0);
    FILE *f = tmpfile();
    srv_config_print(&c, f);
    char line[4096];
    slurp(f, line, sizeof line);
    const char *prefix = "pdesolidd " PDESOLID_VERSION ": ";
    assert_int_equal(strncmp(line, prefix, strlen(prefix)), 0);
    assert_non_null(strchr(line, '\n'));
    *strchr(line, '\n') = '\0';
    const char *args[MAXARGS];
    int n = 0;
    for (char *tok = strtok(line + strlen(prefix), " "); tok; tok = strtok(NULL, " ")) {
        assert_true(n < MAXARGS - 1);
        args[n++] = strcmp(tok, "''") ? tok : "";
    }
    args[n] = NULL;
    assert_true(n > 30);
    r = parse(&back, args);
    if (r.rc)
        fail_msg("%s", r.err);
    assert_memory_equal(&back, &c, sizeof c);
}

static void openapi_version_should_be_the_one_version(void **state)
{
    (void)state;
    char *yaml = read_file("docs/openapi.yaml", NULL);
    assert_non_null(yaml);
    const char *info = strstr(yaml, "\ninfo:\n");
    assert_non_null(info);
    /* info's own "  version:" line: two spaces deep, before the next top-level key. */
    const char *v = strstr(info, "\n  version: ");
    const char *next = info + 7;
    while ((next = strchr(next, '\n')) && (next[1] == ' ' || next[1] == '\n'))
        next++;
    assert_non_null(v);
    assert_true(!next || v < next);
    char got[32];
    assert_int_equal(sscanf(v + strlen("\n  version: "), "%31[^\n ]", got), 1);
    assert_string_equal(got, PDESOLID_VERSION);
    free(yaml);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(defaults_should_be_those_the_usage_gives),
        cmocka_unit_test(every_flag_should_take_its_value_in_both_forms),
        cmocka_unit_test(every_flag_in_the_usage_should_be_tested),
        cmocka_unit_test(each_error_should_exit_2_naming_its_argument),
        cmocka_unit_test(request_timeout_should_be_a_second_or_more),
        cmocka_unit_test(store_and_bind_should_take_each_of_their_forms),
        cmocka_unit_test(web_given_without_an_index_should_refuse_to_start),
        cmocka_unit_test(help_and_version_should_print_and_return_1),
        cmocka_unit_test(print_should_read_back_as_the_same_config),
        cmocka_unit_test(openapi_version_should_be_the_one_version),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("config", tests, NULL, NULL);
}
