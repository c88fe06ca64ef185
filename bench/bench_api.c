/*
 * bench_api: the writers of api/, as medians on a noisy shared machine.
 *
 *   1. The grid JSON number writer against cJSON_PrintUnformatted of the same
 *      numbers (tree and print, as a cJSON user would) and against
 *      snprintf("%.9g"), all in this run (goals: >= 10x and >= 3x).
 *   2. The whole grid JSON output (sampling and writing) in bytes per second.
 *   3. glb of fig4a at 256 x 256 per face (mesh, weld, write; the properties
 *      given, as the server has them cached), in bytes per second against
 *      memcpy of as many bytes in the same run (goal: >= 0.1 of memcpy into
 *      mapped pages), read through a reused 64 KiB buffer as the server and
 *      the CLI read it; api_mesh_build alone; minor page faults of each.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <sys/mman.h>
#include <sys/resource.h>

#include <cJSON.h>

#include "bench.h"
#include "mesh.h"
#include "numfmt.h"
#include "output.h"
#include "template.h"


static pde_solution *solve_preset(const char *name)
{
    const api_preset *ps = api_preset_find(name);
    api_params p;
    api_error err;
    api_preset_params(ps, &p);
    api_model *m = api_template_expand(api_preset_template(ps), &p, &err);
    pde_solution *s = NULL;
    if (!m || api_solve(m, &s, &err))
        fprintf(stderr, "%s: %s\n", name, err.message);
    api_model_free(m);
    return s;
}

static volatile size_t sink;

static long minflt(void)
{
    struct rusage u;
    return getrusage(RUSAGE_SELF, &u) ? 0 : u.ru_minflt;
}

/* `bench_api glb` runs the glb's section alone. */
int main(int argc, char **argv)
{
    const int glb_only = argc > 1 && !strcmp(argv[1], "glb");
    pde_solution *sol = solve_preset("fig4a");
    if (!sol)
        return 1;
    size_t bytes = 0;
    static char chunk[1 << 16];
    /* The numbers: x, y, z of fig4a on a 64^3 grid, 786,432 floats. */
    enum { N = 64, RUNS = 11 };
    size_t count = 3 * (size_t)N * N * N;
    float *v = malloc(count * sizeof *v);
    pde_sample(sol, N, N, N, v);
    char *buf = malloc(count * 20 + 64);
    if (glb_only)
        goto glb;

    double tf[RUNS], tc[RUNS], ts[RUNS], rc[RUNS], rs[RUNS];
    size_t bf = 0, bc = 0, bs = 0;
    for (int r = 0; r < RUNS; r++) {
        double t0 = now();
        char *p = buf;
        *p++ = '[';
        for (size_t i = 0; i < count; i++) {
            if (i)
                *p++ = ',';
            p += api_fmt_f32(p, v[i]);
        }
        *p++ = ']';
        bf = (size_t)(p - buf);
        double t1 = now();
        cJSON *a = cJSON_CreateArray();
        for (size_t i = 0; i < count; i++)
            cJSON_AddItemToArray(a, cJSON_CreateNumber(v[i]));
        char *s = cJSON_PrintUnformatted(a);
        bc = strlen(s);
        free(s);
        cJSON_Delete(a);
        double t2 = now();
        p = buf;
        *p++ = '[';
        for (size_t i = 0; i < count; i++) {
            if (i)
                *p++ = ',';
            p += snprintf(p, 20, "%.9g", (double)v[i]);
        }
        *p++ = ']';
        bs = (size_t)(p - buf);
        double t3 = now();
        tf[r] = t1 - t0;
        tc[r] = t2 - t1;
        ts[r] = t3 - t2;
        rc[r] = tc[r] / tf[r];
        rs[r] = ts[r] / tf[r];
        sink += bf + bc + bs;
    }
    printf("## Grid JSON numbers: %zu float32 values (fig4a, 64^3, x y z)\n\n", count);
    printf("| writer | output | median time | numbers/s | bytes/s | time relative to api_fmt_f32 |\n|---|---|---|---|---|---|\n");
    double mf = median(tf, RUNS), mc = median(tc, RUNS), ms = median(ts, RUNS);
    printf("| api_fmt_f32 loop | %.1f MB | %.1f ms | %.0f M | %.0f MB/s | 1 |\n", bf / 1e6, mf * 1e3, count / mf / 1e6,
           bf / mf / 1e6);
    printf("| cJSON tree + cJSON_PrintUnformatted | %.1f MB | %.1f ms | %.1f M | %.0f MB/s | %.1f |\n", bc / 1e6,
           mc * 1e3, count / mc / 1e6, bc / mc / 1e6, median(rc, RUNS));
    printf("| snprintf(\"%%.9g\") loop | %.1f MB | %.1f ms | %.1f M | %.0f MB/s | %.1f |\n\n", bs / 1e6, ms * 1e3,
           count / ms / 1e6, bs / ms / 1e6, median(rs, RUNS));

    /* The whole grid JSON stream, sampling included. */
    unsigned res[3] = { 128, 128, 128 };
    double tg[RUNS];
    for (int r = 0; r < RUNS; r++) {
        double t0 = now();
        api_error err;
        api_output *o = api_output_open(sol, NULL, NULL, API_FMT_GRID, res, NULL, &err);
        long n;
        bytes = 0;
        while ((n = api_output_read(o, chunk, sizeof chunk)) > 0)
            bytes += (size_t)n;
        api_output_free(o);
        tg[r] = now() - t0;
    }
    double mg = median(tg, RUNS);
    printf("## Grid JSON output, fig4a at 128^3, sampled and written\n\n%.1f MB in %.1f ms: %.0f MB/s\n\n", bytes / 1e6,
           mg * 1e3, bytes / mg / 1e6);

    /* glb of fig4a at 256 per face, the properties given, against memcpy of as many bytes. The glb is read
     * through one reused 64 KiB buffer, as the server's fill jobs read into their ring and the CLI into its
     * buffer: a reader never holds the whole file. memcpy copies as many bytes from a buffer made once,
     * into fresh pages (mmap'd per run: page faults, ~12 us a page on this VM) and into the same pages
     * again (mapped: memcpy's own bandwidth, the goal's yardstick). Minor page faults (getrusage) per run. */
glb:;
    unsigned mres[3] = { 256, 256, 256 };
    pde_props props;
    if (pde_properties(sol, NULL, &props) != PDE_OK)
        return 1;
    double tm[RUNS], tb[RUNS], tcopy[RUNS], twarm[RUNS], ratio[RUNS], ratio_warm[RUNS], fm[RUNS], fb[RUNS], fcopy[RUNS];
    char *src = malloc(16u << 20);
    if (!src)
        return 1;
    memset(src, 1, 16u << 20);
    for (int r = 0; r < RUNS; r++) {
        long f0 = minflt();
        double t0 = now();
        api_error err;
        api_output *o = api_output_open(sol, "bench", &props, API_FMT_GLB, mres, NULL, &err);
        long n;
        bytes = 0;
        while ((n = api_output_read(o, chunk, sizeof chunk)) > 0)
            bytes += (size_t)n;
        api_output_free(o);
        double t1 = now();
        fm[r] = (double)(minflt() - f0);
        /* fresh pages from the kernel: malloc's would be its heap's, mapped since an earlier run */
        char *copy = mmap(NULL, 16u << 20, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (copy == MAP_FAILED || bytes > (16u << 20))
            return 1;
        long fc = minflt();
        t1 = now();
        memcpy(copy, src, bytes);   /* into fresh pages */
        sink += (size_t)copy[bytes / 2];
        double t2 = now();
        memcpy(copy, src, bytes);   /* again, the pages now mapped: memcpy's own bandwidth */
        sink += (size_t)copy[bytes / 3];
        twarm[r] = now() - t2;
        tcopy[r] = t2 - t1;
        fcopy[r] = (double)(minflt() - fc);
        munmap(copy, 16u << 20);
        f0 = minflt();
        t2 = now();
        api_mesh m;
        api_mesh_build(sol, mres, NULL, &m, &err);
        sink += m.ntris;
        api_mesh_free(&m);
        tb[r] = now() - t2;
        fb[r] = (double)(minflt() - f0);
        tm[r] = t1 - t0;
        ratio[r] = tcopy[r] / tm[r];
        ratio_warm[r] = twarm[r] / tm[r];
    }
    free(src);
    double mm = median(tm, RUNS), mb = median(tb, RUNS), mcp = median(tcopy, RUNS);
    printf("## glb of fig4a at 256 x 256 per face (properties given; read through a reused 64 KiB buffer)\n\n");
    printf("| what | bytes | median time | bytes/s | minor page faults (median) | relative to memcpy (median of "
           "per-run ratios) |\n|---|---|---|---|---|---|\n");
    /* also the fastest memcpy over the fastest glb: on a shared machine the median carries the neighbours' load */
    double tmin = tm[0], twmin = twarm[0];
    for (int r = 1; r < RUNS; r++)
        tmin = tm[r] < tmin ? tm[r] : tmin, twmin = twarm[r] < twmin ? twarm[r] : twmin;
    printf("| glb, api_output_open + read | %.1f MB | %.1f ms | %.0f MB/s | %.0f | %.3f (fresh pages), %.3f (mapped; "
           "fastest runs %.3f) |\n",
           bytes / 1e6, mm * 1e3, bytes / mm / 1e6, median(fm, RUNS), median(ratio, RUNS), median(ratio_warm, RUNS),
           twmin / tmin);
    printf("| api_mesh_build + api_mesh_free alone | | %.1f ms | | %.0f | |\n", mb * 1e3, median(fb, RUNS));
    const double mw = median(twarm, RUNS);
    printf("| memcpy of the glb into fresh pages | %.1f MB | %.2f ms | %.0f MB/s | %.0f | 1 |\n", bytes / 1e6, mcp * 1e3,
           bytes / mcp / 1e6, median(fcopy, RUNS));
    printf("| memcpy of the glb into mapped pages | %.1f MB | %.2f ms | %.0f MB/s | 0 | |\n", bytes / 1e6, mw * 1e3,
           bytes / mw / 1e6);
    if (glb_only)
        goto end;
    /* Every row of the format table, and the compressed forms, for fig4a at the format's default res (64 per
     * face edge, 33 per axis): bytes and the median time of open + read, the properties given. */
    printf("\n## Every format of the table, fig4a at its default res (properties given)\n\n");
    printf("| format | res | bytes | median time | bytes relative to the plain format |\n|---|---|---|---|---|\n");
    char *sink_buf = malloc(64u << 20);
    for (int run = 0; sink_buf && run < 2 * API_FMT_COUNT; run++) {
        api_format f = (api_format)(run / 2);
        api_output_opts opts = { .compress = run % 2 ? API_COMPRESS_MESHOPT : API_COMPRESS_NONE };
        if (opts.compress && !api_format_info_of(f)->compress)
            continue;
        unsigned fres[3];
        api_res_parse(NULL, f, fres, NULL);
        double tt[RUNS];
        static size_t plain_bytes;
        for (int r = 0; r < RUNS; r++) {
            double t0 = now();
            api_error err;
            api_output *o = api_output_open_ex(sol, "bench", &props, f, fres, &opts, NULL, &err);
            long n;
            bytes = 0;
            while (o && (n = api_output_read(o, sink_buf + (bytes % (32u << 20)), 1u << 20)) > 0)
                bytes += (size_t)n;
            api_output_free(o);
            tt[r] = now() - t0;
        }
        if (!opts.compress)
            plain_bytes = bytes;
        printf("| %s%s | %u | %zu | %.2f ms | %.3f |\n", api_format_info_of(f)->name,
               opts.compress ? ", compress=meshopt" : "", fres[0], bytes, median(tt, RUNS) * 1e3,
               (double)bytes / (double)plain_bytes);
    }
    free(sink_buf);
end:
    free(v);
    free(buf);
    pde_solution_free(sol);
    return 0;
}
