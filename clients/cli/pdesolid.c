/*
 * pdesolid: the command-line tool. Solves models offline and writes their
 * closed form, properties, values at points, sampled grids and meshes.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "describe.h"
#include "id.h"
#include "loft.h"
#include "model.h"
#include "output.h"
#include "remote.h"
#include "strict.h"
#include "template.h"
#include "version.h"

#define MAX_INPUT (64u << 20)

static const char usage[] =
    "usage: pdesolid COMMAND [ARGS] [OPTIONS]\n"
    "\n"
    "Solves a solid of the fourth-order PDE a x_uuuu + b x_vvvv + c x_wwww = p\n"
    "in closed form (You, Comninos and Zhang), offline.\n"
    "\n"
    "commands:\n"
    "  solve MODEL.json          the closed form and the solid's properties, or with\n"
    "                            --format the solid in that format\n"
    "  eval MODEL.json POINTS.json\n"
    "                            [[x,y,z], ...] at each [u,v,w] of POINTS.json, with\n"
    "                            17 significant digits\n"
    "  presets                   the paper's solids: name, template and caption\n"
    "\n"
    "MODEL.json is a model, a loft ({\"loft\": {\"pde\": ..., \"sections\": [...]}}: a solid through\n"
    "sections of your own) or a request ({\"preset\": \"fig4a\", \"params\": {...}});\n"
    "either file may be - for standard input. docs/API.md describes the format.\n"
    "\n"
    "options:\n"
    "  --preset NAME        instead of MODEL.json: a preset (see `pdesolid presets`)\n"
    "  --template NAME      instead of MODEL.json: a template (example1 to example4,\n"
    "                       docs/API.md), its defaults changed by --param\n"
    "  --param NAME=VALUE   with --preset or --template, a parameter; VALUE is a number, or x,y,z for\n"
    "                       a, b and c; repeatable\n"
    "  --format F           solve: one of the formats below\n"
    "  --res N|NU,NV,NW     samples per axis, or per face edge for the formats that\n"
    "                       mesh the skin (the defaults below)\n"
    "  --compress meshopt   gltf, glb: EXT_meshopt_compression with KHR_mesh_quantization\n"
    "  -o FILE              write to FILE instead of standard output; solve without\n"
    "                       --format takes the format from FILE's extension, and\n"
    "                       with it refuses an extension of another format\n"
    "  --server URL         solve and eval on a pdesolidd (e.g. http://127.0.0.1:8080)\n"
    "                       instead of here; the output is the same\n"
    "  -h, --help           this text\n"
    "  --version            the version\n"
    "\n"
    "exit status: 0 success, 2 bad input (the message names the field as a JSON\n"
    "pointer), 1 anything else.\n";

typedef struct {
    const char *preset, *template, *format, *res, *compress, *out, *server;
    const char *params[64];
    int nparams;
    const char *args[3];
    int nargs;
} options;

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

static int report(const char *what, const api_error *err)
{
    fprintf(stderr, "pdesolid: %s: %s%s%s\n", what, err->pointer, err->pointer[0] ? ": " : "", err->message);
    return 2;
}

/* The model of --preset (or --template) and --param. */
static api_model *preset_model(const options *o, api_error *err)
{
    const api_template *t = NULL;
    api_params p;
    if (o->template) {
        if (!(t = api_template_find(o->template))) {
            char names[256] = "";
            for (size_t i = 0, n = 0; i < api_template_count() && n < sizeof names; i++)
                n += (size_t)snprintf(names + n, sizeof names - n, "%s%s", i ? ", " : "", api_template_name(api_template_at(i)));
            api_fail(err, API_ERR_DOCUMENT, "/template", "no template \"%s\"; the templates are %s", o->template, names);
            return NULL;
        }
        api_template_defaults(t, &p);
    }
    const api_preset *ps = t ? NULL : api_preset_find(o->preset);
    cJSON *loft = ps || t ? NULL : api_loft_preset_tree(o->preset);
    if (loft) {   /* a loft of the gallery: its document */
        cJSON_Delete(loft);
        if (o->nparams) {
            api_fail(err, API_ERR_DOCUMENT, "/params", "the loft preset \"%s\" takes no --param; `pdesolid presets` shows its document", o->preset);
            return NULL;
        }
        char body[128];
        int n = snprintf(body, sizeof body, "{\"preset\": \"%.60s\"}", o->preset);
        return api_model_parse(body, (size_t)n, err);
    }
    if (!ps && !t) {
        api_fail(err, API_ERR_DOCUMENT, "/preset", "no preset \"%s\"; `pdesolid presets` lists them", o->preset);
        return NULL;
    }
    if (ps) {
        t = api_preset_template(ps);
        api_preset_params(ps, &p);
    }
    for (int i = 0; i < o->nparams; i++) {
        char name[64];
        const char *eq = strchr(o->params[i], '=');
        if (!eq || eq == o->params[i] || (size_t)(eq - o->params[i]) >= sizeof name) {
            api_fail(err, API_ERR_DOCUMENT, "", "--param %s: write NAME=VALUE", o->params[i]);
            return NULL;
        }
        snprintf(name, sizeof name, "%.*s", (int)(eq - o->params[i]), o->params[i]);
        double v[3];
        int n = 0;
        const char *s = eq + 1;
        char *end;
        do {
            v[n++] = strtod(s, &end);
            if (end == s) {
                api_fail(err, API_ERR_DOCUMENT, "", "--param %s: \"%s\" is not a number", name, s);
                return NULL;
            }
            s = end + (*end == ',');
        } while (*end == ',' && n < 3);
        if (*end) {
            api_fail(err, API_ERR_DOCUMENT, "", "--param %s: \"%s\" is not a number or x,y,z", name, eq + 1);
            return NULL;
        }
        if (api_params_set(t, &p, name, v, n, err))
            return NULL;
    }
    return api_template_expand(t, &p, err);
}

/* Loads and solves the model; returns 0 or the exit status. id may be NULL. */
static int load(const options *o, const char *path, pde_solution **sol, char *id)
{
    api_error err;
    api_model *m;
    const char *what = path;
    if (o->preset || o->template) {
        what = o->preset ? o->preset : o->template;
        m = preset_model(o, &err);
    } else {
        size_t len;
        char *text = slurp(path, &len);
        if (!text)
            return 1;
        m = api_model_parse(text, len, &err);
        free(text);
    }
    if (!m)
        return report(what, &err);
    int st = api_solve(m, sol, &err);
    if (!st && id)
        api_request_id(m, id, NULL);
    api_model_free(m);
    if (st == PDE_ERR_NOMEM) {
        fprintf(stderr, "pdesolid: out of memory\n");
        return 1;
    }
    return st ? report(what, &err) : 0;
}

static int write_output(const options *o, const pde_solution *sol, const char *id)
{
    api_error err;
    api_format f;
    unsigned res[3];
    api_output_opts opts = { 0 };
    if (api_format_parse(o->format, &f, &err) || api_res_parse(o->res, f, res, &err) ||
        api_compress_parse(o->compress, f, &opts.compress, &err))
        return report("option", &err);
    if (!o->out && isatty(STDOUT_FILENO) && api_format_info_of(f)->binary) {
        fprintf(stderr, "pdesolid: %s is binary; give -o FILE, or redirect standard output\n", o->format);
        return 2;
    }
    FILE *out = o->out ? fopen(o->out, "wb") : stdout;
    if (!out) {
        fprintf(stderr, "pdesolid: %s: %s\n", o->out, strerror(errno));
        return 1;
    }
    api_output *w = api_output_open_ex(sol, id, NULL, f, res, &opts, NULL, &err);
    if (!w) {
        if (out != stdout)
            fclose(out);
        return report("output", &err);
    }
    static char buf[1 << 16];
    long n;
    while ((n = api_output_read(w, buf, sizeof buf)) > 0)
        if (fwrite(buf, 1, (size_t)n, out) != (size_t)n)
            break;
    int bad = n != 0 || ferror(out);
    api_output_free(w);
    if ((out != stdout ? fclose(out) : fflush(out)) != 0 || bad) {
        fprintf(stderr, "pdesolid: %s: %s\n", o->out ? o->out : "standard output", n < 0 ? "out of memory" : strerror(errno));
        return 1;
    }
    return 0;
}

/* The request for --server: the model file's text, or {"preset": NAME, "params": {...}}. NULL on error. */
static char *request_text(const options *o, const char *path, size_t *len)
{
    if (!o->preset && !o->template)
        return slurp(path, len);
    size_t cap = 256 + 96 * (size_t)o->nparams, n = 0;
    char *b = malloc(cap);
    if (!b)
        return NULL;
    n += (size_t)snprintf(b, cap, "{\"%s\":\"%.60s\",\"params\":{", o->preset ? "preset" : "template",
                          o->preset ? o->preset : o->template);
    for (int i = 0; i < o->nparams; i++) {
        const char *eq = strchr(o->params[i], '=');
        double v[3];
        int k = 0;
        char *end = NULL;
        const char *s = eq ? eq + 1 : "";
        do {
            v[k++] = strtod(s, &end);
            s = end + (*end == ',');
        } while (end && *end == ',' && k < 3);
        if (!eq || eq == o->params[i] || end == eq + 1 || *end || eq - o->params[i] > 40) {
            fprintf(stderr, "pdesolid: --param %s: write NAME=VALUE, with a number or x,y,z\n", o->params[i]);
            free(b);
            return NULL;
        }
        n += (size_t)snprintf(b + n, cap - n, "%s\"%.*s\":", i ? "," : "", (int)(eq - o->params[i]), o->params[i]);
        if (k == 3)
            n += (size_t)snprintf(b + n, cap - n, "[%.17g,%.17g,%.17g]", v[0], v[1], v[2]);
        else
            n += (size_t)snprintf(b + n, cap - n, "%.17g", v[0]);
    }
    n += (size_t)snprintf(b + n, cap - n, "}}");
    *len = n;
    return b;
}

static int remote(const options *o, int eval)
{
    size_t len, plen = 0;
    char *body = request_text(o, o->nargs && !o->preset && !o->template ? o->args[0] : NULL, &len);
    if (!body)
        return 2;
    char *pts = eval ? slurp(o->args[o->nargs - 1], &plen) : NULL;
    int rc;
    if (eval && !pts) {
        rc = 1;
    } else if (eval) {
        rc = remote_eval(o->server, body, len, pts, plen, stdout);
    } else {
        FILE *out = o->out ? fopen(o->out, "wb") : stdout;
        if (!out) {
            fprintf(stderr, "pdesolid: %s: %s\n", o->out, strerror(errno));
            rc = 1;
        } else {
            rc = remote_solve(o->server, body, len, o->format, o->res, o->compress, out);
            if (out != stdout && fclose(out) != 0)
                rc = 1;
        }
    }
    free(body);
    free(pts);
    return rc;
}

/* The format whose extension path ends with (the longest, so that x.grid.json is a grid; x.PLY too), or NULL. */
static const api_format_info *format_of_extension(const char *path)
{
    const api_format_info *found = NULL;
    size_t n = strlen(path), best = 0;
    for (int i = 0; i < API_FMT_COUNT; i++) {
        const api_format_info *f = api_format_info_of((api_format)i);
        size_t k = strlen(f->ext);
        if (k < n && k > best && strcasecmp(path + n - k, f->ext) == 0) {
            best = k;
            found = f;
        }
    }
    return found;
}

/*
 * The format of -o FILE: without --format, the one its extension names; with it, the extension must not name
 * another (a name that ends in no format's extension takes --format as given). 0, or 2 with a message naming
 * the extensions, or --format and FILE.
 */
static int format_from_extension(options *o)
{
    const api_format_info *f = format_of_extension(o->out);
    if (o->format) {
        api_format given;
        api_error err;
        if (!f || !strcmp(f->name, o->format) || api_format_parse(o->format, &given, &err))
            return 0;   /* an unknown --format is named by its own check */
        fprintf(stderr, "pdesolid: --format %s and -o %s disagree: %s is the extension of %s; drop --format, or "
                "give a name that ends in %s's extension\n", o->format, o->out, f->ext, f->name, o->format);
        return 2;
    }
    if (f) {
        o->format = f->name;
        return 0;
    }
    fprintf(stderr, "pdesolid: %s: no format has this extension; give --format, or end the name with one of", o->out);
    for (int i = 0; i < API_FMT_COUNT; i++)
        fprintf(stderr, "%s %s", i ? "," : "", api_format_info_of((api_format)i)->ext);
    fputc('\n', stderr);
    return 2;
}

static int cmd_solve(const options *oo)
{
    options copy = *oo, *o = &copy;
    if (o->out && format_from_extension(o))
        return 2;
    if (o->compress && !o->format) {
        fprintf(stderr, "pdesolid: --compress needs a format that takes it (--format glb, or -o FILE.glb)\n");
        return 2;
    }
    if (o->server)
        return remote(o, 0);
    pde_solution *sol;
    char id[API_ID_LEN + 1] = "";
    int rc = load(o, o->nargs ? o->args[0] : NULL, &sol, id);
    if (rc)
        return rc;
    if (o->format) {
        rc = write_output(o, sol, id);
        pde_solution_free(sol);
        return rc;
    }
    pde_props props;
    pde_status st = pde_properties(sol, NULL, &props);
    if (st != PDE_OK) {
        fprintf(stderr, "pdesolid: properties: %s\n", pde_strerror(st));
        pde_solution_free(sol);
        return 1;
    }
    printf("solid %s\n", id);
    api_describe(stdout, sol, &props);
    pde_solution_free(sol);
    return 0;
}

static int cmd_eval(const options *o)
{
    if (o->server)
        return remote(o, 1);
    const char *points_path = o->args[o->nargs - 1];
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
    if ((rc = load(o, o->nargs == 2 ? o->args[0] : NULL, &sol, NULL)) != 0) {
        free(pts);
        return rc;
    }
    for (size_t i = 0; i < n; i++)   /* in place: point i is read before its value is written */
        pde_eval(sol, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], pts + 3 * i);
    pde_solution_free(sol);
    if (api_eval_check(pts, NULL, NULL, NULL, n, &err)) {
        free(pts);
        /* The points file is the array itself: its pointer has no "/points" in front. */
        memmove(err.pointer, err.pointer + 7, strlen(err.pointer + 7) + 1);
        return report(points_path, &err);
    }
    fputc('[', stdout);
    for (size_t i = 0; i < n; i++)
        printf("%s[%.17g,%.17g,%.17g]", i ? ",\n" : "", pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
    fputs("]\n", stdout);
    free(pts);
    return fflush(stdout) == 0 ? 0 : 1;
}

static int cmd_presets(void)
{
    for (size_t i = 0; i < api_preset_count(); i++) {
        const api_preset *p = api_preset_at(i);
        printf("%-6s %-9s %s\n", p->name, p->template, p->caption);
    }
    for (size_t i = 0; i < api_loft_preset_count(); i++) {
        const char *caption, *name = api_loft_preset_name(i, &caption);
        printf("%-6s %-9s %s\n", name, "loft", caption);
    }
    return 0;
}

/* The usage, then the formats as output.h's table has them. */
static void print_usage(FILE *f)
{
    fputs(usage, f);
    fputs("\nformats (--format NAME, or -o FILE ending with the extension):\n", f);
    for (int i = 0; i < API_FMT_COUNT; i++) {
        const api_format_info *fi = api_format_info_of((api_format)i);
        fprintf(f, "  %-6s %-11s %-26s res %u %s%s%s\n", fi->name, fi->ext, fi->mime,
                fi->mesh ? API_RES_MESH_DEFAULT : API_RES_GRID_DEFAULT, fi->mesh ? "per face edge" : "per axis",
                fi->props ? ", with the properties" : "", fi->compress ? ", --compress meshopt" : "");
    }
}

int main(int argc, char **argv)
{
    options o = { 0 };
    const char *cmd = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char **val = NULL;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0 || strcmp(a, "help") == 0) {
            print_usage(stdout);
            return 0;
        } else if (strcmp(a, "--version") == 0) {
            printf("pdesolid %s\n", PDESOLID_VERSION);
            return 0;
        } else if (strcmp(a, "--preset") == 0) {
            val = &o.preset;
        } else if (strcmp(a, "--template") == 0) {
            val = &o.template;
        } else if (strcmp(a, "--format") == 0) {
            val = &o.format;
        } else if (strcmp(a, "--res") == 0) {
            val = &o.res;
        } else if (strcmp(a, "--compress") == 0) {
            val = &o.compress;
        } else if (strcmp(a, "-o") == 0) {
            val = &o.out;
        } else if (strcmp(a, "--server") == 0) {
            val = &o.server;
        } else if (strcmp(a, "--param") == 0) {
            if (i + 1 >= argc || o.nparams == 64) {
                fprintf(stderr, "pdesolid: --param needs NAME=VALUE (at most 64)\n");
                return 2;
            }
            o.params[o.nparams++] = argv[++i];
            continue;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "pdesolid: unknown option %s\n\n", a);
            print_usage(stderr);
            return 2;
        } else if (!cmd) {
            cmd = a;
            continue;
        } else if (o.nargs < 3) {
            o.args[o.nargs++] = a;
            continue;
        } else {
            fprintf(stderr, "pdesolid: too many arguments\n");
            return 2;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "pdesolid: %s needs a value\n", a);
            return 2;
        }
        *val = argv[++i];
    }
    if (!cmd) {
        print_usage(stderr);
        return 2;
    }
    if (o.nparams && !o.preset && !o.template) {
        fprintf(stderr, "pdesolid: --param goes with --preset or --template\n");
        return 2;
    }
    if (o.preset && o.template) {
        fprintf(stderr, "pdesolid: give --preset or --template, not both\n");
        return 2;
    }
    int model_args = o.preset || o.template ? 0 : 1;
    if (strcmp(cmd, "solve") == 0 && o.nargs == model_args)
        return cmd_solve(&o);
    int eval = strcmp(cmd, "eval") == 0 && o.nargs == model_args + 1;
    int presets = strcmp(cmd, "presets") == 0 && o.nargs == 0;
    if ((eval || presets) && o.out && !freopen(o.out, "wb", stdout)) {   /* -o is never ignored */
        fprintf(stderr, "pdesolid: %s: %s\n", o.out, strerror(errno));
        return 1;
    }
    if (eval)
        return cmd_eval(&o);
    if (presets)
        return cmd_presets();
    fprintf(stderr, "pdesolid: unknown command or wrong arguments: %s\n\n", cmd);
    print_usage(stderr);
    return 2;
}
