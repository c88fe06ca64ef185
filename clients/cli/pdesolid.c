/*
 * pdesolid: the command-line tool. Solves models offline and prints their
 * closed form, properties, or values at given points.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "describe.h"
#include "model.h"

#define VERSION "0.1.0"
#define MAX_INPUT (64u << 20)

static const char usage[] =
    "usage: pdesolid COMMAND [ARGS]\n"
    "\n"
    "Solves a solid of the fourth-order PDE a x_uuuu + b x_vvvv + c x_wwww = p\n"
    "in closed form (You, Comninos and Zhang), offline.\n"
    "\n"
    "commands:\n"
    "  solve MODEL.json          print the closed form of each component and the\n"
    "                            solid's properties (bounds, volume, det J, residuals)\n"
    "  eval MODEL.json POINTS.json\n"
    "                            print [[x,y,z], ...] at each [u,v,w] of POINTS.json,\n"
    "                            with 17 significant digits\n"
    "\n"
    "Either file may be - for standard input. The model format is in docs/API.md.\n"
    "options:\n"
    "  -h, --help       this text\n"
    "  --version        the version\n"
    "\n"
    "exit status: 0 success, 2 bad input (the message names the field as a JSON\n"
    "pointer), 1 anything else.\n";

/* Reads a whole file (or stdin for "-"); NULL with a message on failure. */
static char *slurp(const char *path, size_t *len)
{
    FILE *f = strcmp(path, "-") == 0 ? stdin : fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "pdesolid: %s: %s\n", path, strerror(errno));
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    while (buf) {
        n += fread(buf + n, 1, cap - n, f);
        if (n < cap)
            break;
        if (cap >= MAX_INPUT) {
            fprintf(stderr, "pdesolid: %s: larger than %u MiB\n", path, MAX_INPUT >> 20);
            free(buf);
            buf = NULL;
            break;
        }
        char *nb = realloc(buf, cap *= 2);
        if (!nb)
            free(buf);
        buf = nb;
    }
    if (buf && ferror(f)) {
        fprintf(stderr, "pdesolid: %s: read error\n", path);
        free(buf);
        buf = NULL;
    }
    if (f != stdin)
        fclose(f);
    *len = n;
    return buf;
}

static int report(const char *path, const api_error *err)
{
    fprintf(stderr, "pdesolid: %s: %s: %s\n", path, err->pointer[0] ? err->pointer : "(document)",
            err->message);
    return 2;
}

/* Loads and solves a model; returns 0 or the exit status. */
static int load(const char *path, pde_solution **sol)
{
    size_t len;
    char *text = slurp(path, &len);
    if (!text)
        return 1;
    api_error err;
    api_model *m = api_model_parse(text, len, &err);
    free(text);
    if (!m)
        return report(path, &err);
    int st = api_solve(m, sol, &err);
    api_model_free(m);
    if (st == PDE_ERR_NOMEM) {
        fprintf(stderr, "pdesolid: out of memory\n");
        return 1;
    }
    return st ? report(path, &err) : 0;
}

static int cmd_solve(const char *path)
{
    pde_solution *sol;
    int rc = load(path, &sol);
    if (rc)
        return rc;
    pde_props props;
    pde_status st = pde_properties(sol, NULL, &props);
    if (st != PDE_OK) {
        fprintf(stderr, "pdesolid: properties: %s\n", pde_strerror(st));
        pde_solution_free(sol);
        return 1;
    }
    api_describe(stdout, sol, &props);
    pde_solution_free(sol);
    return 0;
}

static int cmd_eval(const char *model_path, const char *points_path)
{
    size_t len, n;
    char *text = slurp(points_path, &len);
    if (!text)
        return 1;
    api_error err;
    double *pts;
    int rc = api_points_parse(text, len, &pts, &n, &err);
    free(text);
    if (rc)
        return report(points_path, &err);
    pde_solution *sol;
    if ((rc = load(model_path, &sol)) != 0) {
        free(pts);
        return rc;
    }
    fputc('[', stdout);
    for (size_t i = 0; i < n; i++) {
        double x[3];
        pde_eval(sol, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], x);
        printf("%s[%.17g,%.17g,%.17g]", i ? ",\n" : "", x[0], x[1], x[2]);
    }
    fputs("]\n", stdout);
    free(pts);
    pde_solution_free(sol);
    return fflush(stdout) == 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0 ||
        strcmp(argv[1], "help") == 0) {
        fputs(usage, argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("pdesolid %s\n", VERSION);
        return 0;
    }
    if (strcmp(argv[1], "solve") == 0 && argc == 3)
        return cmd_solve(argv[2]);
    if (strcmp(argv[1], "eval") == 0 && argc == 4)
        return cmd_eval(argv[2], argv[3]);
    fprintf(stderr, "pdesolid: unknown command or wrong arguments: %s\n\n%s", argv[1], usage);
    return 2;
}
