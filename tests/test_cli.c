/*
 * test_cli.c: build/pdesolid as a user runs it. eval agrees with the
 * independent solver; solve prints the closed form and the properties; bad
 * input exits 2 with the field's JSON pointer. $PDESOLID names the binary
 * (build/pdesolid), $PDESOLID_SAN its sanitised twin for the error paths.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cJSON.h>
#include <cmocka.h>

#include "output.h"
#include "support.h"

static char dir[] = "/tmp/pdesolid-cli-XXXXXX";
static char bins[2][4096];   /* absolute paths of the plain and the sanitised binary */

static int setup(void **state)
{
    (void)state;
    const char *names[2] = { getenv("PDESOLID"), getenv("PDESOLID_SAN") };
    const char *dflt[2] = { "build/pdesolid", "build/san/pdesolid" };
    for (int i = 0; i < 2; i++)
        if (!realpath(names[i] ? names[i] : dflt[i], bins[i])) {
            fprintf(stderr, "test_cli: no %s; run `make test`\n", names[i] ? names[i] : dflt[i]);
            return -1;
        }
    return tmpdir_make(dir);
}

static int teardown(void **state)
{
    (void)state;
    return tmpdir_remove(dir);
}

static void write_text(const char *name, const char *text)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* Runs the tool; returns its exit status, with stdout and stderr in *out and *err (free them). */
static int run(int sanitised, const char *args, char **out, char **err)
{
    char cmd[4096 + 1024];
    snprintf(cmd, sizeof cmd, "cd %s && %s %s >out.txt 2>err.txt", dir, bins[sanitised], args);
    int st = system(cmd);
    char path[256];
    snprintf(path, sizeof path, "%s/out.txt", dir);
    *out = read_file(path, NULL);
    snprintf(path, sizeof path, "%s/err.txt", dir);
    *err = read_file(path, NULL);
    assert_true(WIFEXITED(st));
    return WEXITSTATUS(st);
}

static void q4a(double w, double *out, void *ctx)
{
    (void)ctx;
    out[0] = 0.0;
    out[1] = 3e4 * sin(3 * M_PI * w);
}

static void eval_should_agree_with_the_independent_solution(void **state)
{
    (void)state;
    char *model = read_file("examples/fig4a.json", NULL);
    assert_non_null(model);
    write_text("fig4a.json", model);
    free(model);
    const double pts[][3] = { { 0.5, 0.25, 0 }, { 1, 0.125, 0.5 }, { 0.3, 0.7, 0.4 }, { 0.9, 0.05, 0.97 },
                              { 0, 0.5, 0.5 }, { 1, 1, 1 }, { 0.61, 0.33, 0.02 } };
    size_t np = sizeof pts / sizeof *pts;
    char text[1024] = "[", *p = text + 1;
    for (size_t i = 0; i < np; i++)
        p += sprintf(p, "%s[%.17g,%.17g,%.17g]", i ? "," : "", pts[i][0], pts[i][1], pts[i][2]);
    strcpy(p, "]");
    write_text("pts.json", text);
    char *out, *err;
    assert_int_equal(run(0, "eval fig4a.json pts.json", &out, &err), 0);
    cJSON *arr = cJSON_Parse(out);
    assert_non_null(arr);
    assert_int_equal(cJSON_GetArraySize(arr), (int)np);
    /* x and y: modes u sin 2pi v (boundary) and u cos 2pi v (force), b = 1, c = -9.5, by
     * multiple shooting; z: the Hermite cubic with z(1) = 3, z'(1) = 7.5. */
    double mu = pow(2 * M_PI, 4), mus[2] = { mu, mu }, bc[8] = { 0.5, 0, 0.5, 0, 0, 0, 0, 0 };
    indep_problem prob = { 2, -9.5, mus, NULL, bc, q4a, NULL, 3 * M_PI };
    indep_solution *ind = indep_solve(&prob);
    for (size_t i = 0; i < np; i++) {
        double u = pts[i][0], v = pts[i][1], w = pts[i][2];
        double h0 = indep_eval(ind, 0, 0, w), h1 = indep_eval(ind, 1, 0, w);
        double want[3] = { h0 * u * sin(2 * M_PI * v) + h1 * u * cos(2 * M_PI * v),
                           h0 * u * cos(2 * M_PI * v) + h1 * u * sin(2 * M_PI * v),
                           3 * (3 * w * w - 2 * w * w * w) + 7.5 * (w * w * w - w * w) };
        cJSON *row = cJSON_GetArrayItem(arr, (int)i);
        for (int c = 0; c < 3; c++)
            assert_rel(cJSON_GetArrayItem(row, c)->valuedouble, want[c], 1e-10, 1.0);
    }
    indep_free(ind);
    cJSON_Delete(arr);
    free(out);
    free(err);
}

static void solve_should_print_the_closed_form_and_properties(void **state)
{
    (void)state;
    char *out, *err;
    assert_int_equal(run(0, "solve fig4a.json", &out, &err), 0);
    const char *want[] = { "x(u,v,w) = sum over 2 modes", "u * sin(2*pi*v)", "t = e^(1/4) = 3.578895",
                           "sin(9.424777961*w)", "z(u,v,w) = sum over 1 mode", "(1.5*w^2 + 1.5*w^3)",
                           "bounding box:", "volume:", "det J: min", "folds:", "accuracy:",
                           "surface area:", "centroid: (", "inertia about the centroid", "principal moments:",
                           "principal axes: (", "certified: the solid lies inside" };
    for (size_t i = 0; i < sizeof want / sizeof *want; i++)
        if (!strstr(out, want[i]))
            fail_msg("missing \"%s\" in:\n%s", want[i], out);
    free(out);
    free(err);
}

static void bad_input_should_exit_2_and_name_the_field(void **state)
{
    (void)state;
    write_text("bad.json", "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-1,-1,-1]},"
                           "\"boundary\":{\"x\":[{\"u\":{\"pow\":1.5}}]}}");
    write_text("zero.json", "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[-1,0,-1]}}");
    write_text("pts.json", "[[0,0,0]]");
    write_text("badpts.json", "[[0,0]]");
    const struct {
        const char *args, *words;
        int status;
    } cases[] = {
        { "eval bad.json pts.json", "bad.json: /boundary/x/0/u/pow: the power must be a whole number", 2 },
        { "solve bad.json", "/boundary/x/0/u/pow", 2 },
        { "solve zero.json", "zero.json: /pde/c/1: c of component y is 0", 2 },
        { "eval zero.json badpts.json", "badpts.json: /0: must be a point", 2 },
        { "solve missing.json", "missing.json: No such file", 1 },
        { "frobnicate", "unknown command", 2 },
        { "", "usage:", 2 },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        char *out, *err;
        int st = run(1, cases[i].args, &out, &err);
        if (st != cases[i].status || !strstr(err, cases[i].words))
            fail_msg("pdesolid %s: status %d, stderr: %s", cases[i].args, st, err);
        free(out);
        free(err);
    }
    const struct {
        const char *args, *words;
    } more[] = {
        { "solve --preset fig9", "fig9: /preset: no preset \"fig9\"" },
        { "solve --preset fig4a --param p0", "--param p0: write NAME=VALUE" },
        { "solve --preset fig4a --param p0=lots", "\"lots\" is not a number" },
        { "solve --preset fig4a --param q=1", "/params/q: example4 has no parameter \"q\"" },
        { "solve --preset fig4a --param c=-1,-1,0", "/params/c/2: c of component z is 0" },
        { "solve --preset fig4a --format dae -o x", "\"dae\" is not a format" },
        { "solve --preset fig4a --format grid --res 9999", "limit of 4096" },
        { "solve fig4a.json --param p0=1", "--param goes with --preset or --template" },
        { "solve --res", "--res needs a value" },
        { "solve --bogus fig4a.json", "unknown option --bogus" },
    };
    for (size_t i = 0; i < sizeof more / sizeof *more; i++) {
        char *out, *err;
        int st = run(1, more[i].args, &out, &err);
        if (st != 2 || !strstr(err, more[i].words))
            fail_msg("pdesolid %s: status %d, stderr: %s", more[i].args, st, err);
        free(out);
        free(err);
    }
    char *out, *err;
    assert_int_equal(run(1, "--help", &out, &err), 0);
    assert_non_null(strstr(out, "eval MODEL.json POINTS.json"));
    free(out);
    free(err);
    assert_int_equal(run(1, "eval - pts.json <bad.json", &out, &err), 2);
    assert_non_null(strstr(err, "-: /boundary/x/0/u/pow"));
    free(out);
    free(err);
}

/* -o is never ignored: the format comes from the file's extension (the table's), a bad one or an
 * unwritable path fails with a message and a nonzero status, and eval writes its values there too. */
static void output_file_should_never_be_ignored(void **state)
{
    (void)state;
    char *out, *err, path[256];
    size_t len;
    const char *exts[] = { "json", "grid.json", "glb", "stl", "obj", "ply", "msh", "vtu", "PLY", "Glb" };   /* any case */
    for (size_t i = 0; i < sizeof exts / sizeof *exts; i++) {
        char args[128];
        snprintf(args, sizeof args, "solve --preset fig3d --res 8 -o byext.%s", exts[i]);
        if (run(1, args, &out, &err) != 0)
            fail_msg("pdesolid %s: %s", args, err);
        assert_string_equal(out, "");
        free(out);
        free(err);
        snprintf(path, sizeof path, "%s/byext.%s", dir, exts[i]);
        unsigned char *got = (unsigned char *)read_file(path, &len);
        assert_non_null(got);
        /* What the extension names: glb's magic, stl's 84 + 50 n bytes, grid's resolution, json's id. */
        if (!strcasecmp(exts[i], "glb"))
            assert_memory_equal(got, "glTF", 4);
        else if (!strcmp(exts[i], "stl"))
            assert_int_equal((len - 84) % 50, 0);
        else if (!strcmp(exts[i], "grid.json"))
            assert_non_null(strstr((char *)got, "\"resolution\""));
        else if (!strcmp(exts[i], "obj"))
            assert_memory_equal(got, "# pdesolid", 10);
        else if (!strcasecmp(exts[i], "ply"))
            assert_memory_equal(got, "ply\nformat binary_little_endian", 31);
        else if (!strcmp(exts[i], "msh"))
            assert_memory_equal(got, "$MeshFormat\n4.1", 15);
        else if (!strcmp(exts[i], "vtu"))
            assert_non_null(strstr((char *)got, "UnstructuredGrid"));
        else
            assert_non_null(strstr((char *)got, "\"properties\""));
        free(got);
    }
    /* --compress meshopt: gltf and glb only, named when refused. */
    assert_int_equal(run(1, "solve --preset fig3d --res 8 --compress meshopt -o small.glb", &out, &err), 0);
    free(out);
    free(err);
    snprintf(path, sizeof path, "%s/small.glb", dir);
    unsigned char *glb = (unsigned char *)read_file(path, &len);
    assert_non_null(glb);
    assert_non_null(strstr((char *)glb + 20, "\"extensionsRequired\":[\"EXT_meshopt_compression\""));
    free(glb);
    assert_int_equal(run(1, "solve --preset fig3d --compress meshopt -o x.stl", &out, &err), 2);
    assert_non_null(strstr(err, "compress: meshopt applies to gltf, glb, not to stl"));
    free(out);
    free(err);
    assert_int_equal(run(1, "solve --preset fig3d --compress meshopt", &out, &err), 2);
    assert_non_null(strstr(err, "--compress"));
    free(out);
    free(err);
    assert_int_equal(run(1, "solve --preset fig3d -o solid.txt", &out, &err), 2);
    assert_non_null(strstr(err, "solid.txt"));
    assert_non_null(strstr(err, ".glb"));
    snprintf(path, sizeof path, "%s/solid.txt", dir);
    assert_int_not_equal(access(path, F_OK), 0);
    free(out);
    free(err);
    assert_int_equal(run(1, "solve --preset fig3d -o /nonexistent/dir/x.json", &out, &err), 1);
    assert_non_null(strstr(err, "/nonexistent/dir/x.json"));
    free(out);
    free(err);
    write_text("one.json", "[[0.3,0.6,0.7]]");
    char *direct;
    assert_int_equal(run(1, "eval --preset fig4b one.json", &direct, &err), 0);
    free(err);
    assert_int_equal(run(1, "eval --preset fig4b one.json -o vals.json", &out, &err), 0);
    assert_string_equal(out, "");
    free(out);
    free(err);
    snprintf(path, sizeof path, "%s/vals.json", dir);
    char *written = read_file(path, NULL);
    assert_non_null(written);
    assert_string_equal(written, direct);
    free(written);
    free(direct);
    /* README's eval of examples/points.json, offline: 4 points, the first fig. 4a's at (0.5, 0.25, 0.5). */
    char cwd[1024], args[2200];
    assert_non_null(getcwd(cwd, sizeof cwd));
    snprintf(args, sizeof args, "eval %s/examples/fig4a.json %s/examples/points.json", cwd, cwd);
    assert_int_equal(run(1, args, &out, &err), 0);
    char *readme = out;
    free(err);
    assert_int_equal(run(1, "eval --preset fig4a one.json", &out, &err), 0);   /* a different point: */
    free(out);
    free(err);
    write_text("mid.json", "[[0.5, 0.25, 0.5]]");
    assert_int_equal(run(1, "eval --preset fig4a mid.json", &out, &err), 0);
    out[strcspn(out, "]") + 1] = '\0';
    size_t lines = 0;
    for (const char *c = readme; *c; c++)
        lines += *c == '\n';
    if (strncmp(readme, out, strlen(out)) != 0 || lines != 4)
        fail_msg("examples/points.json: %s, want 4 points starting %s", readme, out);
    free(readme);
    free(out);
    free(err);
    assert_int_equal(run(1, "eval --preset fig4b one.json -o /nonexistent/dir/v.json", &out, &err), 1);
    assert_non_null(strstr(err, "/nonexistent/dir/v.json"));
    free(out);
    free(err);
}

/* --format and -o's extension must agree (--format obj -o x.ply wrote OBJ into x.ply): a disagreement exits 2
 * naming both and writes nothing; a name whose extension is no format's takes --format as given. */
static void format_and_the_output_extension_should_agree(void **state)
{
    (void)state;
    char *out, *err, path[256];
    static const struct {
        const char *args, *file;
        int rc;
    } cases[] = {
        { "--format obj -o x.ply", "x.ply", 2 },
        { "--format stl -o x.PLY", "x.PLY", 2 },
        { "--format json -o x.grid.json", "x.grid.json", 2 },
        { "--format glb -o x.gltf", "x.gltf", 2 },
        { "--format obj -o x.obj", "x.obj", 0 },
        { "--format grid -o y.grid.json", "y.grid.json", 0 },
        { "--format f32 -o y.bin", "y.bin", 0 },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        char args[160];
        snprintf(args, sizeof args, "solve --preset fig4a --res 5 %s", cases[i].args);
        int rc = run(1, args, &out, &err);
        if (rc != cases[i].rc)
            fail_msg("pdesolid %s: exit %d, want %d: %s", args, rc, cases[i].rc, err);
        snprintf(path, sizeof path, "%s/%s", dir, cases[i].file);
        if (cases[i].rc) {
            const char *fmt = strstr(cases[i].args, "--format ") + 9;
            char name[16];
            snprintf(name, sizeof name, "%.*s", (int)strcspn(fmt, " "), fmt);
            if (!strstr(err, name) || !strstr(err, cases[i].file))
                fail_msg("pdesolid %s: the message does not name --format %s and %s: %s", args, name, cases[i].file,
                         err);
            if (access(path, F_OK) == 0)
                fail_msg("pdesolid %s: wrote %s", args, cases[i].file);
        } else if (access(path, F_OK) != 0) {
            fail_msg("pdesolid %s: no %s", args, cases[i].file);
        }
        free(out);
        free(err);
    }
}

/* --template NAME is the request {"template": NAME, "params": {...}}: the same solid, by its id; its defaults
 * are the family's first figure (example4's is fig4a); --help lists every format of the table. */
static void templates_should_work_from_the_command_line(void **state)
{
    (void)state;
    char *a, *b, *err;
    write_text("treq.json", "{\"template\":\"example4\",\"params\":{\"p0\":12345,\"c\":[-11,-11,-10]}}");
    assert_int_equal(run(1, "solve --template example4 --param p0=12345 --param c=-11,-11,-10", &a, &err), 0);
    free(err);
    assert_int_equal(run(1, "solve treq.json", &b, &err), 0);
    free(err);
    assert_memory_equal(a, b, strcspn(b, "\n"));
    assert_non_null(strstr(a, "solid "));
    free(a);
    free(b);
    assert_int_equal(run(1, "solve --template example4", &a, &err), 0);
    free(err);
    assert_int_equal(run(1, "solve --preset fig4a", &b, &err), 0);
    free(err);
    assert_memory_equal(a, b, strcspn(b, "\n"));
    free(a);
    free(b);
    assert_int_equal(run(1, "solve --template example9", &a, &err), 2);
    assert_non_null(strstr(err, "/template: no template \"example9\"; the templates are example1, example2"));
    free(a);
    free(err);
    assert_int_equal(run(1, "solve --template example4 --preset fig4a", &a, &err), 2);
    assert_non_null(strstr(err, "not both"));
    free(a);
    free(err);
    assert_int_equal(run(1, "--help", &a, &err), 0);
    for (int i = 0; i < API_FMT_COUNT; i++) {
        const api_format_info *f = api_format_info_of((api_format)i);
        char line[64];
        snprintf(line, sizeof line, "  %-6s %-11s %s", f->name, f->ext, f->mime);
        if (!strstr(a, line))
            fail_msg("--help lacks \"%s\":\n%s", line, a);
    }
    free(a);
    free(err);
}

static void presets_and_formats_should_work_from_the_command_line(void **state)
{
    (void)state;
    char *out, *err;
    assert_int_equal(run(0, "presets", &out, &err), 0);
    assert_non_null(strstr(out, "fig1a"));
    assert_non_null(strstr(out, "fig4x  example4  Fig. 4:"));
    free(out);
    free(err);
    /* The preset with a parameter equals the same request given as a file. */
    write_text("req.json", "{\"preset\":\"fig4b\",\"params\":{\"p0\":12345,\"c\":[-11,-11,-10]}}");
    write_text("p.json", "[[0.3,0.6,0.7]]");
    char *a, *b;
    assert_int_equal(run(0, "eval --preset fig4b --param p0=12345 --param c=-11,-11,-10 p.json", &a, &err), 0);
    free(err);
    assert_int_equal(run(0, "eval req.json p.json", &b, &err), 0);
    free(err);
    assert_string_equal(a, b);
    free(a);
    free(b);
    assert_int_equal(run(0, "solve req.json", &out, &err), 0);
    assert_non_null(strstr(out, "solid "));
    free(out);
    free(err);
    /* Every format to a file, of the size the format implies. */
    assert_int_equal(run(0, "solve --preset fig2a --format f32 --res 4,5,6 -o g.f32", &out, &err), 0);
    free(out);
    free(err);
    char path[256];
    snprintf(path, sizeof path, "%s/g.f32", dir);
    size_t len;
    free(read_file(path, &len));
    assert_int_equal(len, 12 * 4 * 5 * 6);
    const char *fmts[] = { "json", "grid", "gltf", "glb", "vts", "stl" };
    for (size_t i = 0; i < 6; i++) {
        char args[128];
        snprintf(args, sizeof args, "solve --preset fig3d --format %s --res 8 -o s.%s", fmts[i], fmts[i]);
        assert_int_equal(run(0, args, &out, &err), 0);
        free(out);
        free(err);
        snprintf(path, sizeof path, "%s/s.%s", dir, fmts[i]);
        free(read_file(path, &len));
        assert_true(len > 100);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(presets_and_formats_should_work_from_the_command_line),
        cmocka_unit_test(output_file_should_never_be_ignored),
        cmocka_unit_test(format_and_the_output_extension_should_agree),
        cmocka_unit_test(templates_should_work_from_the_command_line),
        cmocka_unit_test(eval_should_agree_with_the_independent_solution),
        cmocka_unit_test(solve_should_print_the_closed_form_and_properties),
        cmocka_unit_test(bad_input_should_exit_2_and_name_the_field),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("cli", tests, setup, teardown);
}
