/*
 * pdesolid: the command-line tool. Solves models offline and writes their
 * closed form, properties, values at points, sampled grids and meshes.
 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cJSON.h>

#include "catalog.h"
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

/* The commands as bits, for the commands each option goes with. */
enum { CMD_SOLVE = 1, CMD_EVAL = 2, CMD_PRESETS = 4 };

typedef struct {
    const char *preset, *template, *format, *res, *compress, *out, *server;
    const char *params[64];
    int nparams;
    const char *args[4];   /* the command's files, the first four */
    int nargs;             /* all of them */
    char base[2048];       /* --server as remote_base() cleaned it */
} options;

/* One row an option that takes a value: the commands that take it, where its value goes (--param, repeatable,
 * has its own list), and its help (lines after the first indented by print_rows). */
static const struct opt_row {
    const char *name, *arg;
    unsigned cmds;
    int repeat;
    size_t field;
    const char *help;
} opt_rows[] = {
    { "--preset", "NAME", CMD_SOLVE | CMD_EVAL | CMD_PRESETS, 0, offsetof(options, preset),
      "instead of MODEL.json: a preset (see `pdesolid presets`)" },
    { "--template", "NAME", CMD_SOLVE | CMD_EVAL, 0, offsetof(options, template),
      "instead of MODEL.json: a template (example1 to example4,\ndocs/API.md), its defaults changed by --param" },
    { "--param", "NAME=VALUE", CMD_SOLVE | CMD_EVAL, 1, 0,
      "with --preset or --template, a parameter; VALUE is a\nnumber as JSON writes one (2e5, -1.5), or x,y,z for a,\nb and c; repeatable" },
    { "--format", "F", CMD_SOLVE, 0, offsetof(options, format), "one of the formats below" },
    { "--res", "N|NU,NV,NW", CMD_SOLVE, 0, offsetof(options, res),
      "samples per axis, or per face edge for the formats that\nmesh the skin (the defaults below)" },
    { "--compress", "meshopt", CMD_SOLVE, 0, offsetof(options, compress),
      "gltf, glb: EXT_meshopt_compression with KHR_mesh_quantization" },
    { "-o", "FILE", CMD_SOLVE | CMD_EVAL | CMD_PRESETS, 0, offsetof(options, out),
      "write to FILE instead of standard output (- is\nstandard output)" },
    { "--server", "URL", CMD_SOLVE | CMD_EVAL | CMD_PRESETS, 0, offsetof(options, server),
      "do it on a pdesolidd (its base URL, e.g.\nhttp://127.0.0.1:8080) instead of here; the output is\nthe same" },
};

static int cmd_solve(const options *o);
static int cmd_eval(const options *o);
static int cmd_presets(const options *o);

/* One row a command: its files (the first, when a MODEL.json, replaced by --preset or --template), its usage
 * after the name, and its help. */
static const struct cmd_row {
    const char *name;
    unsigned bit;
    const char *files[2];
    const char *synopsis, *help;
    int (*run)(const options *o);
} cmd_rows[] = {
    { "solve", CMD_SOLVE, { "MODEL.json" }, "[MODEL.json]",
      "the closed form and the solid's properties, or the\n"
      "solid in a format: --format's, or the one of -o\n"
      "FILE's extension (with --format, an extension of\n"
      "another format is refused)", cmd_solve },
    { "eval", CMD_EVAL, { "MODEL.json", "POINTS.json" }, "MODEL.json POINTS.json",
      "[[x,y,z], ...] at each [u,v,w] of POINTS.json, with\n17 significant digits", cmd_eval },
    { "presets", CMD_PRESETS, { NULL }, "", "the paper's solids and the loft presets: name,\ntemplate and caption; "
      "with --preset NAME, its document\n(a loft, or the figure's parameters) to edit and solve", cmd_presets },
};
#define NCMDS (sizeof cmd_rows / sizeof *cmd_rows)
#define NOPTS (sizeof opt_rows / sizeof *opt_rows)

static const char about[] =
    "Solves a solid of the fourth-order PDE a x_uuuu + b x_vvvv + c x_wwww = p\n"
    "in closed form (You, Comninos and Zhang), here or on a pdesolidd.\n";

static const char model_text_help[] =
    "MODEL.json is a model, a loft ({\"loft\": {\"pde\": ..., \"sections\": [...]}}: a solid through\n"
    "sections of your own) or a request ({\"preset\": \"fig4a\", \"params\": {...}});\n"
    "docs/API.md describes the format.\n";

static const char exit_help[] =
    "exit status: 0 success, 2 bad input (the message names the field as a JSON\n"
    "pointer, or the argument), 1 anything else.\n";

static const char **opt_slot(options *o, const struct opt_row *r)
{
    return (const char **)(void *)((char *)o + r->field);
}

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

/* A refused option's value: the api's message starts with the query parameter's name ("res: ..."), the option's. */
static int report_option(const char *name, const api_error *err)
{
    size_t k = strlen(name);
    int named = !strncmp(err->message, name, k) && err->message[k] == ':';
    fprintf(stderr, "pdesolid: --%s%s%s\n", named ? "" : name, named ? "" : ": ", err->message);
    return 2;
}

/* --param's VALUE: a number as JSON writes one, or x,y,z (three), checked by api_json_check as any request is.
 * NULL after a message. */
static cJSON *param_value(const char *name, const char *text)
{
    char json[256];
    size_t n = strlen(text);
    api_error err;
    if (n == 0 || n > 200 || strspn(text, "0123456789+-.eE,") != n ||
        api_json_check(json, (size_t)snprintf(json, sizeof json, strchr(text, ',') ? "[%s]" : "%s", text), &err)) {
        fprintf(stderr, "pdesolid: --param %s: \"%s\" is not a number as JSON writes one (16, -1.5, 2e5), or x,y,z\n",
                name, text);
        return NULL;
    }
    cJSON *v = cJSON_Parse(json), *x;
    if (!v)
        fprintf(stderr, "pdesolid: out of memory\n");
    int finite = !cJSON_IsNumber(v) || isfinite(v->valuedouble);
    cJSON_ArrayForEach(x, (cJSON_IsArray(v) ? v : NULL))
        finite &= isfinite(x->valuedouble);
    if (v && !finite) {   /* cJSON reads 1e400 as inf, and would write it as null */
        fprintf(stderr, "pdesolid: --param %s: %s must be a finite number; this one overflows a double\n", name, text);
        cJSON_Delete(v);
        return NULL;
    }
    return v;
}

/* The request {"preset" or "template": NAME, "params": {...}} of --preset or --template and --param, as JSON
 * text (malloc'd), parsed by the api here or sent to a server alike; NULL after a message. */
static char *request_text(const options *o, size_t *len)
{
    cJSON *req = cJSON_CreateObject(), *params = NULL;
    int ok = req && cJSON_AddStringToObject(req, o->preset ? "preset" : "template", o->preset ? o->preset : o->template);
    if (ok && o->nparams)
        ok = (params = cJSON_AddObjectToObject(req, "params")) != NULL;
    for (int i = 0; ok && i < o->nparams; i++) {
        const char *eq = strchr(o->params[i], '=');
        if (!eq || eq == o->params[i]) {
            fprintf(stderr, "pdesolid: --param %s: write NAME=VALUE\n", o->params[i]);
            cJSON_Delete(req);
            return NULL;
        }
        char *name = strndup(o->params[i], (size_t)(eq - o->params[i]));
        if (name && cJSON_GetObjectItemCaseSensitive(params, name)) {
            fprintf(stderr, "pdesolid: --param %s is given twice; give it once\n", name);
            free(name);
            cJSON_Delete(req);
            return NULL;
        }
        cJSON *v = name ? param_value(name, eq + 1) : NULL;
        if (!v || !cJSON_AddItemToObject(params, name, v)) {
            cJSON_Delete(v);
            free(name);
            cJSON_Delete(req);
            return NULL;
        }
        free(name);
    }
    if (ok)
        api_json_exact_numbers(req);   /* --param r0=0.5609999999999999 is that double, not 0.561 */
    char *text = ok ? cJSON_PrintUnformatted(req) : NULL;
    cJSON_Delete(req);
    if (!text)
        fprintf(stderr, "pdesolid: out of memory\n");
    else
        *len = strlen(text);
    return text;
}

/* What the messages call the model: its file, or the preset or template. */
static const char *model_name(const options *o)
{
    return o->preset ? o->preset : o->template ? o->template : o->args[0];
}

/* The model's JSON text (malloc'd): its file, or request_text(). NULL after a message, with the exit status. */
static char *model_text(const options *o, size_t *len, int *status)
{
    *status = o->preset || o->template ? 2 : 1;
    return o->preset || o->template ? request_text(o, len) : slurp(o->args[0], len);
}

/* Loads and solves the model; returns 0 or the exit status. id may be NULL. */
static int load(const options *o, pde_solution **sol, char *id)
{
    api_error err;
    size_t len;
    int rc;
    char *text = model_text(o, &len, &rc);
    if (!text)
        return rc;
    api_model *m = api_model_parse(text, len, &err);
    free(text);
    if (!m)
        return report(model_name(o), &err);
    int st = api_solve(m, sol, &err);
    if (!st && id)
        api_request_id(m, id, NULL);
    api_model_free(m);
    if (st == PDE_ERR_NOMEM) {
        fprintf(stderr, "pdesolid: out of memory\n");
        return 1;
    }
    return st ? report(model_name(o), &err) : 0;
}

/* --format (json when not given), --res and --compress as the server reads them: 0, or 2 after a message. */
static int output_options(const options *o, api_format *f, unsigned res[3], api_output_opts *opts)
{
    api_error err;
    if (api_format_parse(o->format ? o->format : "json", f, &err))
        return report_option("format", &err);
    if (api_res_parse(o->res, *f, res, &err))
        return report_option("res", &err);
    if (api_compress_parse(o->compress, *f, &opts->compress, &err))
        return report_option("compress", &err);
    return 0;
}

/* The solid in format f (output_options()'s) to standard output (-o's file: out_begin()). */
static int write_output(const pde_solution *sol, const char *id, api_format f, const unsigned res[3],
                        const api_output_opts *opts)
{
    api_error err;
    api_output *w = api_output_open_ex(sol, id, NULL, f, res, opts, NULL, &err);
    if (!w)
        return report("output", &err);
    static char buf[1 << 16];
    long n;
    while ((n = api_output_read(w, buf, sizeof buf)) > 0)
        if (fwrite(buf, 1, (size_t)n, stdout) != (size_t)n)
            break;
    api_output_free(w);
    if (n < 0) {
        fprintf(stderr, "pdesolid: out of memory\n");
        return 1;
    }
    return 0;   /* a write error: out_end() names it */
}

/*
 * -o FILE, written whole or not at all: the commands write to standard output, which out_begin() points at a
 * temporary file beside FILE (so that rename() stays on one file system); out_end() renames it over FILE when
 * the command succeeded and removes it otherwise, so a failed command never creates or truncates FILE, and
 * eval's POINTS.json may be its own -o. A FILE that exists and is not a regular file (/dev/null, a pipe) is
 * written in place: there is nothing to replace. A symbolic link is followed, and stays a link.
 */
typedef struct {
    char *path;   /* where the output goes (a link resolved); NULL: standard output as it is */
    char *tmp;    /* the temporary file, NULL when written in place */
    mode_t mode;  /* the file's: the existing one's, or what creat() would give */
} out_file;

/* out_begin()'s temporary file while it exists: a signal that ends the command (Ctrl-C) removes it too. */
static char *volatile out_tmp;

static void out_on_signal(int sig)
{
    if (out_tmp)
        unlink(out_tmp);   /* async-signal-safe */
    signal(sig, SIG_DFL);
    raise(sig);
}

/* 0, or 1 after a message naming path. */
static int out_begin(out_file *of, const char *path)
{
    memset(of, 0, sizeof *of);
    if (!path)
        return 0;
    struct stat st;
    int exists = stat(path, &st) == 0;
    of->path = exists ? realpath(path, NULL) : strdup(path);
    int fd = -1;
    if (of->path && exists && !S_ISREG(st.st_mode)) {
        fd = open(of->path, O_WRONLY | O_TRUNC);
    } else if (of->path && (of->tmp = malloc(strlen(of->path) + 8)) != NULL) {
        sprintf(of->tmp, "%s.XXXXXX", of->path);
        mode_t mask = umask(0);
        umask(mask);
        of->mode = exists ? st.st_mode & 07777 : 0666 & ~mask;
        fd = mkstemp(of->tmp);
        if (fd < 0) {
            free(of->tmp);
            of->tmp = NULL;
        }
    }
    if (fd < 0 || dup2(fd, STDOUT_FILENO) < 0) {
        fprintf(stderr, "pdesolid: %s: %s\n", path, strerror(errno));
        if (fd >= 0)
            close(fd);
        if (of->tmp)
            unlink(of->tmp);
        free(of->tmp);
        free(of->path);
        return 1;
    }
    close(fd);
    out_tmp = of->tmp;
    static const int sigs[] = { SIGINT, SIGTERM, SIGHUP, SIGQUIT };
    for (size_t i = 0; of->tmp && i < sizeof sigs / sizeof *sigs; i++)
        signal(sigs[i], out_on_signal);
    return 0;
}

/* Ends what out_begin() began with the command's exit status rc; returns it, or 1 after a message when the
 * output could not be written. */
static int out_end(out_file *of, int rc, const char *path)
{
    int bad = fflush(stdout) != 0 || ferror(stdout);
    int err = errno;
    if (of->tmp) {
        bad = bad || fchmod(STDOUT_FILENO, of->mode) != 0 || close(STDOUT_FILENO) != 0;
        err = bad ? errno : 0;
        if (!rc && !bad && rename(of->tmp, of->path) != 0) {
            bad = 1;
            err = errno;
        }
        if (rc || bad)
            unlink(of->tmp);
        out_tmp = NULL;
    }
    if (bad) {
        fprintf(stderr, "pdesolid: %s: %s\n", path ? path : "standard output", strerror(err));
        rc = rc ? rc : 1;
    }
    free(of->tmp);
    free(of->path);
    return rc;
}

static int remote_solve_to(const options *o)
{
    size_t len;
    int rc;
    char *body = model_text(o, &len, &rc);
    if (!body)
        return rc;
    rc = remote_solve(o->server, body, len, o->format, o->res, o->compress);
    free(body);
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
    api_format f;   /* checked here as the server checks them, with --server or without, --format or not */
    unsigned res[3];
    api_output_opts opts = { 0 };
    if (output_options(o, &f, res, &opts))
        return 2;
    if (o->format && !o->out && isatty(STDOUT_FILENO) && api_format_info_of(f)->binary) {
        fprintf(stderr, "pdesolid: %s is binary; give -o FILE, or redirect standard output\n", o->format);
        return 2;
    }
    if (o->server)
        return remote_solve_to(o);
    pde_solution *sol;
    char id[API_ID_LEN + 1] = "";
    int rc = load(o, &sol, id);
    if (rc)
        return rc;
    if (o->format) {
        rc = write_output(sol, id, f, res, &opts);
        pde_solution_free(sol);
        return rc;
    }
    pde_props props;
    api_error err;
    if (api_properties(sol, NULL, &props, &err) != PDE_OK) {
        pde_solution_free(sol);
        if (err.status == API_ERR_DOCUMENT)   /* too large: as --format json and --server say it, exit 2 */
            return report("properties", &err);
        fprintf(stderr, "pdesolid: %s\n", err.message);
        return 1;
    }
    printf("solid %s\n", id);
    api_describe(stdout, sol, &props);
    pde_solution_free(sol);
    return 0;
}

/* The values at the points, in place, from a server (remote.h), at the id the server would give the model:
 * computed here, so that the server solves it only when it does not have it. A model this api cannot read
 * goes to the server without an id, which then names what is wrong with it (as POST /solve does). */
static int remote_values(const options *o, double *pts, size_t n, const char *points_path)
{
    size_t len;
    int rc;
    char *body = model_text(o, &len, &rc);
    if (!body)
        return rc;
    char id[API_ID_LEN + 1] = "";
    api_error err;
    api_model *m = api_model_parse(body, len, &err);
    if (!m || api_request_id(m, id, NULL) != PDE_OK)
        id[0] = '\0';
    api_model_free(m);
    rc = remote_eval(o->server, body, len, id, pts, n, points_path);
    free(body);
    return rc;
}

static int cmd_eval(const options *o)
{
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
    if (o->server) {
        rc = remote_values(o, pts, n, points_path);
    } else {
        pde_solution *sol;
        if ((rc = load(o, &sol, NULL)) == 0) {
            for (size_t i = 0; i < n; i++)   /* in place: point i is read before its value is written */
                pde_eval(sol, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], pts + 3 * i);
            pde_solution_free(sol);
        }
    }
    if (rc) {
        free(pts);
        return rc;
    }
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
    return 0;
}

static void preset_row(const char *name, const char *template, const char *caption)
{
    printf("%-6s %-9s %s\n", name, template, caption);
}

/* A preset's document, from GET /presets/NAME's answer (api_preset_json, api_loft_preset_json): the loft of
 * a loft preset, {"preset", "params"} with every parameter of a paper figure's; what `solve` takes back. */
static int print_preset_document(const char *name, const char *catalog)
{
    cJSON *c = cJSON_Parse(catalog ? catalog : ""), *doc = cJSON_CreateObject();
    cJSON *loft = cJSON_DetachItemFromObjectCaseSensitive(c, "loft");
    cJSON *params = cJSON_DetachItemFromObjectCaseSensitive(c, "params");
    if (loft)
        cJSON_AddItemToObject(doc, "loft", loft);
    else if (params) {
        cJSON_AddStringToObject(doc, "preset", name);
        cJSON_AddItemToObject(doc, "params", params);
        params = NULL;
    }
    api_json_exact_numbers(doc);   /* the same id as the preset's */
    char *text = loft || cJSON_GetObjectItem(doc, "preset") ? cJSON_Print(doc) : NULL;
    cJSON_Delete(params);
    cJSON_Delete(doc);
    cJSON_Delete(c);
    if (!text) {
        fprintf(stderr, "pdesolid: presets: the preset %s has no document\n", name);
        return 1;
    }
    printf("%s\n", text);
    free(text);
    return 0;
}

static int cmd_presets(const options *o)
{
    if (o->preset) {
        const api_preset *p = api_preset_find(o->preset);
        char *catalog = NULL;
        int rc = 0;
        /* a name is letters, digits, - and _: anything else names no preset (and would not go into a URL as is) */
        const int named = o->preset[0] && !o->preset[strspn(o->preset, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_")];
        if (named && o->server)
            rc = remote_preset(o->server, o->preset, &catalog);
        else if (!named || !(catalog = p ? api_preset_json(p) : api_loft_preset_json(o->preset))) {
            fprintf(stderr, "pdesolid: presets: no preset \"%s\"; `pdesolid presets` lists them\n", o->preset);
            rc = 2;
        }
        if (!rc)
            rc = print_preset_document(o->preset, catalog);
        free(catalog);
        return rc;
    }
    if (o->server)
        return remote_presets(o->server, preset_row);
    for (size_t i = 0; i < api_preset_count(); i++) {
        const api_preset *p = api_preset_at(i);
        preset_row(p->name, p->template, p->caption);
    }
    for (size_t i = 0; i < api_loft_preset_count(); i++) {
        const char *caption, *name = api_loft_preset_name(i, &caption);
        preset_row(name, "loft", caption);
    }
    return 0;
}

/* Each row's label in a column of width col - 2, its text after it (below it when the label is longer), the
 * text's further lines indented to col. */
static void print_row(FILE *f, int col, const char *label, const char *text)
{
    int used = fprintf(f, "  %s", label);
    if (used >= col)
        used = fprintf(f, "\n") - 1;
    fprintf(f, "%*s", col - used, "");
    for (const char *c = text; *c; c++)
        if (*c == '\n')
            fprintf(f, "\n%*s", col, "");
        else
            fputc(*c, f);
    fputc('\n', f);
}

/* The options cmd takes (all when cmd is NULL). */
static void print_options(FILE *f, const struct cmd_row *cmd)
{
    fputs("\noptions:\n", f);
    for (size_t i = 0; i < NOPTS; i++)
        if (!cmd || opt_rows[i].cmds & cmd->bit) {
            char label[64];
            snprintf(label, sizeof label, "%s %s", opt_rows[i].name, opt_rows[i].arg);
            print_row(f, 23, label, opt_rows[i].help);
        }
    print_row(f, 23, "-h, --help", cmd ? "this text" : "this text; after a command, its usage and options");
    if (!cmd)
        print_row(f, 23, "--version", "the version");
}

/* The formats as output.h's table has them. */
static void print_formats(FILE *f)
{
    fputs("\nformats (--format NAME, or -o FILE ending with the extension):\n", f);
    for (int i = 0; i < API_FMT_COUNT; i++) {
        const api_format_info *fi = api_format_info_of((api_format)i);
        fprintf(f, "  %-6s %-11s %-26s res %u %s%s%s\n", fi->name, fi->ext, fi->mime,
                fi->mesh ? API_RES_MESH_DEFAULT : API_RES_GRID_DEFAULT, fi->mesh ? "per face edge" : "per axis",
                fi->props ? ", with the properties" : "", fi->compress ? ", --compress meshopt" : "");
    }
}

/* The whole usage (cmd NULL), or one command's: its usage, its options and what they refer to. */
static void print_usage(FILE *f, const struct cmd_row *cmd)
{
    if (cmd) {
        fprintf(f, "usage: pdesolid %s%s%s [OPTIONS]\n\n%s\n", cmd->name, cmd->synopsis[0] ? " " : "", cmd->synopsis,
                cmd->help);
    } else {
        fprintf(f, "usage: pdesolid COMMAND [ARGS] [OPTIONS]\n       pdesolid COMMAND --help\n\n%s\ncommands:\n", about);
        for (size_t i = 0; i < NCMDS; i++) {
            char label[64];
            snprintf(label, sizeof label, "%s %s", cmd_rows[i].name, cmd_rows[i].synopsis);
            print_row(f, 28, label, cmd_rows[i].help);
        }
    }
    if (!cmd || cmd->files[0])   /* standard input: the one file of solve, one of eval's two */
        fprintf(f, "\n%s%s\n", model_text_help,
                !cmd ? "Either file may be - for standard input (eval: not both)." :
                cmd->files[1] ? "Either file may be - for standard input (not both)." : "MODEL.json may be - for standard input.");
    print_options(f, cmd);
    fprintf(f, "\n%s", exit_help);
    if (!cmd || cmd->bit == CMD_SOLVE)
        print_formats(f);
}

static const struct opt_row *opt_find(const char *name)
{
    for (size_t i = 0; i < NOPTS; i++)
        if (!strcmp(opt_rows[i].name, name))
            return &opt_rows[i];
    return NULL;
}

static const struct cmd_row *cmd_find(const char *name)
{
    for (size_t i = 0; i < NCMDS; i++)
        if (!strcmp(cmd_rows[i].name, name))
            return &cmd_rows[i];
    return NULL;
}

/* The files cmd takes, and whether o has the ones it needs: 0, or 2 after a one-line message naming what is
 * missing or too many. */
static int check_files(const struct cmd_row *cmd, const options *o)
{
    int files = cmd->files[0] ? cmd->files[1] ? 2 : 1 : 0;
    int given = o->preset || o->template, want = files - (given && files);
    const char *how = o->preset ? "--preset" : "--template";
    if (o->nargs > want && given && o->nargs == files)
        fprintf(stderr, "pdesolid: %s: %s and %s %s both give the model; give one\n", cmd->name, o->args[0], how,
                model_name(o));
    else if (o->nargs > want)
        fprintf(stderr, "pdesolid: %s: an argument too many: \"%s\" (pdesolid %s%s%s [OPTIONS])\n", cmd->name,
                o->args[want], cmd->name, cmd->synopsis[0] ? " " : "", cmd->synopsis);
    else if (o->nargs < want)
        fprintf(stderr, "pdesolid: %s: %s is missing%s (pdesolid %s %s [OPTIONS])\n", cmd->name,
                cmd->files[o->nargs + given], o->nargs + given ? "" : "; or give --preset or --template", cmd->name,
                cmd->synopsis);
    else if (files == 2 && !given && !strcmp(o->args[0], "-") && !strcmp(o->args[1], "-"))
        fprintf(stderr, "pdesolid: %s: %s and %s are both standard input (-); only one can be\n", cmd->name,
                cmd->files[0], cmd->files[1]);
    else
        return 0;
    return 2;
}

int main(int argc, char **argv)
{
    options o = { 0 };
    const struct cmd_row *cmd = NULL;
    int help = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const struct opt_row *r;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0 || (!cmd && strcmp(a, "help") == 0)) {
            help = 1;
        } else if (strcmp(a, "--version") == 0) {
            printf("pdesolid %s\n", PDESOLID_VERSION);
            return 0;
        } else if (a[0] == '-' && a[1]) {
            if (!(r = opt_find(a))) {
                fprintf(stderr, "pdesolid: unknown option %s; `pdesolid --help` lists them\n", a);
                return 2;
            }
            if (i + 1 >= argc) {
                fprintf(stderr, "pdesolid: %s needs a value (%s)\n", a, r->arg);
                return 2;
            }
            const char *v = argv[++i], **slot = r->repeat ? &o.params[o.nparams] : opt_slot(&o, r);
            if (r->repeat && o.nparams == (int)(sizeof o.params / sizeof *o.params)) {
                fprintf(stderr, "pdesolid: --param: at most %d\n", o.nparams);
                return 2;
            }
            if (*slot && !r->repeat) {
                fprintf(stderr, "pdesolid: %s is given twice (%s, then %s); give it once\n", a, *slot, v);
                return 2;
            }
            *slot = v;
            o.nparams += r->repeat;
        } else if (!cmd) {
            if (!(cmd = cmd_find(a))) {
                fprintf(stderr, "pdesolid: unknown command \"%s\"; the commands are", a);
                for (size_t k = 0; k < NCMDS; k++)
                    fprintf(stderr, "%s %s", k ? "," : "", cmd_rows[k].name);
                fputc('\n', stderr);
                return 2;
            }
        } else {
            if (o.nargs < (int)(sizeof o.args / sizeof *o.args))
                o.args[o.nargs] = a;
            o.nargs++;
        }
    }
    if (help || !cmd) {
        print_usage(help ? stdout : stderr, cmd);
        return help ? 0 : 2;
    }
    for (size_t i = 0; i < NOPTS; i++)
        if (!(opt_rows[i].cmds & cmd->bit) && (opt_rows[i].repeat ? o.nparams > 0 : *opt_slot(&o, &opt_rows[i]) != NULL)) {
            fprintf(stderr, "pdesolid: %s takes no %s (`pdesolid %s --help` lists its options)\n", cmd->name,
                    opt_rows[i].name, cmd->name);
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
    if (check_files(cmd, &o))
        return 2;
    if (o.out && !strcmp(o.out, "-"))
        o.out = NULL;
    if (o.server) {
        if (remote_base(o.server, o.base, sizeof o.base))
            return 2;
        o.server = o.base;
    }
    out_file of;   /* -o is never ignored */
    if (out_begin(&of, o.out))
        return 1;
    return out_end(&of, cmd->run(&o), o.out);
}
