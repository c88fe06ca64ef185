/*
 * fuzz_model.c: the request body of POST /solve, end to end. Bytes go
 * through api_model_parse, api_solve and, when the solution is small, every
 * output format at a tiny resolution (2 or 3 samples per axis), all under a
 * pde_cancel that may stop the work after a number of polls the input picks.
 * Invariants: a refusal is a sane api_error; a cancelled call says so and
 * leaks nothing; every cost estimate (cost.h) is finite and not negative, so
 * that a budget check cannot be passed by a NaN; an accepted model has a
 * well-formed id; every output's bytes number api_output_size(), the JSON
 * ones are strict JSON (support.h's own checker, not the api's), and the
 * binary ones have the lengths their headers declare.
 */
#define _GNU_SOURCE   /* memmem */
#include <math.h>

#include "cost.h"
#include "fuzz.h"
#include "id.h"
#include "output.h"
#include "pde.h"

#define MAX_INPUT 4096   /* bytes: a few dozen terms, so that a solve stays in milliseconds */
#define MAX_MODES 12     /* over all components: outputs and properties cost modes x samples */
#define FUZZ_PROPS_WORK 3e7   /* api_cost_props units: the properties only below this (see below) */
#define MAX_OUTPUT (8u << 20)

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Reads o whole in uneven pieces into a new buffer; *len its size. */
static char *read_all(api_output *o, size_t *len)
{
    static const size_t piece[] = { 1, 4096, 7, 65536, 3 };
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    FUZZ_CHECK(buf, "out of memory");
    for (int k = 0;; k++) {
        size_t want = piece[k % 5];
        if (cap - n < want) {
            buf = realloc(buf, cap *= 2);
            FUZZ_CHECK(buf, "out of memory");
        }
        long got = api_output_read(o, buf + n, want);
        FUZZ_CHECK(got >= 0 && (size_t)got <= want, "api_output_read gave %ld for %zu bytes", got, want);
        if (got == 0)
            break;
        n += (size_t)got;
        FUZZ_CHECK(n <= MAX_OUTPUT, "more than %u bytes at a tiny resolution", MAX_OUTPUT);
    }
    *len = n;
    return buf;
}

static void check_cost(const api_cost *c, const char *what)
{
    FUZZ_CHECK(isfinite(c->work) && c->work >= 0 && isfinite(c->bytes) && c->bytes >= 0,
               "the cost of %s is work %g, bytes %g", what, c->work, c->bytes);
}

/* Stops the work after *arg polls, when *arg is not negative. */
static int stop_after(void *arg)
{
    long *left = arg;
    return *left >= 0 && (*left)-- == 0;
}

/* A refusal, or a cancelled call: status API_ERR_CANCELLED and nothing made. */
static void check_refusal(const api_error *err, int may_cancel)
{
    if (may_cancel && err->status == API_ERR_CANCELLED)
        FUZZ_CHECK(!strcmp(err->message, "cancelled"), "cancelled with \"%s\"", err->message);
    else
        fuzz_check_error(err);
}

static void check_output(api_format f, const unsigned res[3], const char *b, size_t n)
{
    const unsigned char *u = (const unsigned char *)b;
    switch (f) {
    case API_FMT_JSON:
    case API_FMT_GRID:
    case API_FMT_GLTF:
        FUZZ_CHECK(json_strict_valid(b, n), "the %s output is not strict JSON: %.200s", api_format_info_of(f)->name,
                   b);
        break;
    case API_FMT_F32:
        FUZZ_CHECK(n == 12ull * res[0] * res[1] * res[2], "f32: %zu bytes for %ux%ux%u", n, res[0], res[1], res[2]);
        break;
    case API_FMT_GLB: {
        FUZZ_CHECK(n >= 20 && !memcmp(b, "glTF", 4) && le32(u + 4) == 2 && le32(u + 8) == n,
                   "glb: bad header for %zu bytes", n);
        uint32_t jlen = le32(u + 12);
        FUZZ_CHECK(jlen <= n - 20 && !memcmp(b + 16, "JSON", 4), "glb: bad JSON chunk");
        size_t end = jlen;   /* the JSON chunk is padded with spaces, which JSON allows */
        FUZZ_CHECK(json_strict_valid(b + 20, end), "glb: the JSON chunk is not strict JSON");
        break;
    }
    case API_FMT_STL:
        FUZZ_CHECK(n >= 84 && n == 84 + 50ull * le32(u + 80), "stl: %zu bytes", n);
        break;
    case API_FMT_VTS: {
        /* XML, then after '_' the points and det J as raw blocks, each after its UInt64 byte count. */
        static const char mark[] = "<AppendedData encoding=\"raw\">";
        const char *data = memmem(b, n, mark, sizeof mark - 1);
        FUZZ_CHECK(n > 5 && !memcmp(b, "<?xml", 5) && data, "vts: no XML declaration or no appended data");
        const char *us = memchr(data, '_', n - (size_t)(data - b));
        FUZZ_CHECK(us && utf8_valid(b, (size_t)(us - b)), "vts: the XML is not UTF-8, or no '_'");
        size_t at = (size_t)(us + 1 - b), pts = (size_t)res[0] * res[1] * res[2];
        size_t tail = at + 16 + 16 * pts;
        FUZZ_CHECK(tail <= n && le32(u + at) == 12 * pts && le32(u + at + 4) == 0 &&
                       le32(u + at + 8 + 12 * pts) == 4 * pts && le32(u + at + 12 + 12 * pts) == 0,
                   "vts: block sizes wrong for %zu points", pts);
        FUZZ_CHECK(memmem(b + tail, n - tail, "</VTKFile>", 10), "vts: does not end in </VTKFile>");
        break;
    }
    case API_FMT_OBJ:
        FUZZ_CHECK(n > 2 && b[0] == '#' && b[n - 1] == '\n' && utf8_valid(b, n), "obj: not lines of text");
        break;
    case API_FMT_PLY: {
        static const char end[] = "end_header\n";
        const char *h = memmem(b, n, end, sizeof end - 1);
        FUZZ_CHECK(n > 4 && !memcmp(b, "ply\n", 4) && h, "ply: no header");
        unsigned long nv = 0, nf = 0;
        const char *ev = memmem(b, (size_t)(h - b), "element vertex ", 15), *ef = memmem(b, (size_t)(h - b), "element face ", 13);
        FUZZ_CHECK(ev && ef && sscanf(ev, "element vertex %lu", &nv) == 1 && sscanf(ef, "element face %lu", &nf) == 1,
                   "ply: no element counts");
        FUZZ_CHECK(n == (size_t)(h - b) + sizeof end - 1 + 28 * nv + 13 * nf, "ply: %zu bytes for %lu vertices, %lu faces",
                   n, nv, nf);
        break;
    }
    case API_FMT_MSH:
        FUZZ_CHECK(n > 12 && !memcmp(b, "$MeshFormat\n", 12) && memmem(b, n, "$EndElements", 12), "msh: no sections");
        break;
    case API_FMT_VTU:
        FUZZ_CHECK(n > 5 && !memcmp(b, "<?xml", 5) && memmem(b, n, "</VTKFile>", 10), "vtu: not a VTK XML file");
        break;
    case API_FMT_COUNT:
        break;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > MAX_INPUT)
        return 0;
    /* JSON allows white space at the end, so the input's tail picks how to run it: its last byte res 2
     * or 3 (bit 0), whether the outputs get the properties or compute them (bit 1) and which of them
     * computes them then (bits 2 to 4, below); k >= 2 trailing
     * white space bytes cancel the work at the 3 (k - 2)th poll. */
    unsigned pick = size ? data[size - 1] : 0;
    size_t ws = 0;
    while (ws < size && strchr(" \t\r\n", data[size - 1 - ws]) && data[size - 1 - ws])
        ws++;
    long left = ws >= 2 ? 3 * (long)(ws - 2) : -1;
    pde_cancel cancel = { stop_after, &left };

    api_error err;
    memset(&err, 'X', sizeof err);
    api_model *m = api_model_parse((const char *)data, size, &err);
    if (!m) {
        fuzz_check_error(&err);
        return 0;
    }
    api_cost cost;
    api_cost_model(m, &cost);
    check_cost(&cost, "the solve");
    pde_solution *sol = NULL;
    memset(&err, 'X', sizeof err);
    if (api_solve_ex(m, &cancel, &sol, &err) != 0) {
        check_refusal(&err, 1);
        FUZZ_CHECK(!sol, "a refused solve left a solution");
        api_model_free(m);
        return 0;
    }
    FUZZ_CHECK(sol, "api_solve gave 0 and no solution");
    char id[API_ID_LEN + 1];
    pde_diag diag;
    FUZZ_CHECK(api_request_id(m, id, &diag) == PDE_OK, "a solved model has no id");
    FUZZ_CHECK(api_id_valid(id), "id \"%s\"", id);
    size_t modes = 0;
    for (int c = 0; c < 3; c++) {
        size_t k = 0;
        pde_solution_modes(sol, c, &k);
        modes += k;
    }
    /* The daemon refuses what is over --max-work (1e9 units, about 2 s); the harness's budget for the
     * properties is tighter, since libFuzzer's instrumentation makes them about 60 times slower (a model at
     * 4.2e7 units: 0.05 s at -O3, 3.5 s) and an input has 10 s (make fuzz found a folding model with sin 20
     * pi v at 4.7e8 units: 0.86 s a computation, -O3). Paper figures (fig. 4a: 2.2e7) stay within it. */
    int light = modes <= MAX_MODES;
    if (light) {
        api_cost_props(sol, &cost);
        check_cost(&cost, "the properties");
        light = cost.work <= FUZZ_PROPS_WORK;
    }
    if (light) {
        pde_props props;
        pde_props_opts opts = { .res = 5, .cancel = &cancel };
        pde_status ps = pick & 2 ? PDE_ERR_CANCELLED : pde_properties(sol, &opts, &props);
        /* The properties are the costly part: once an input. Where they were not computed here (bit 1),
         * one output that carries them computes its own (which: bits 2 to 4, counted over those runs) and
         * the others that carry them are left out. Seven computations (json, gltf and glb each plain and
         * compressed, vts, vtu) ran past libFuzzer's 10 s under instrumentation; five came within 2 s of
         * it (a model at 4.2e7 units: 7.8 s, a computation 3.5 s: instrumented, the properties run about
         * 60 times slower than at -O3). */
        int pruns = 0, prun = 0;
        for (int run = 0; run < 2 * API_FMT_COUNT; run++) {
            const api_format_info *fi = api_format_info_of((api_format)(run / 2));
            pruns += fi->props && (run % 2 == 0 || fi->compress);
        }
        const int chosen = (int)((pick >> 2) & 7) % (pruns ? pruns : 1);
        /* Every format, and those that take it compressed too. */
        for (int run = 0; run < 2 * API_FMT_COUNT; run++) {
            int f = run / 2;
            unsigned res[3] = { 2, 2 + (pick & 1), 2 };
            const api_format_info *fi = api_format_info_of((api_format)f);
            api_output_opts oo = { .compress = run % 2 ? API_COMPRESS_MESHOPT : API_COMPRESS_NONE };
            if (oo.compress && !fi->compress)
                continue;
            api_cost_output_ex(sol, (api_format)f, res, &oo, &cost);
            check_cost(&cost, fi->name);
            memset(&err, 'X', sizeof err);
            if (fi->props && ps != PDE_OK && prun++ != chosen)
                continue;
            api_output *o = api_output_open_ex(sol, id, ps == PDE_OK ? &props : NULL, (api_format)f, res, &oo,
                                               &cancel, &err);
            if (!o) {
                check_refusal(&err, 1);
                continue;
            }
            long long want = api_output_size(o);
            size_t n;
            char *b = read_all(o, &n);
            FUZZ_CHECK(want < 0 || (size_t)want == n, "%s: %zu bytes, %lld announced", fi->name, n, want);
            check_output((api_format)f, res, b, n);
            free(b);
            api_output_free(o);
        }
    }
    pde_solution_free(sol);
    api_model_free(m);
    return 0;
}
