/*
 * test_volmesh.c: hexahedral volume meshes (api/volmesh.h): counts derived from the samples and the
 * collapsed axes, orientation, volumes against core's pde_properties, merges, and the msh and vtu
 * files read back by python3-meshio and checked by gmsh.
 */
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "loft.h"
#include "model.h"
#include "output.h"
#include "support.h"
#include "volmesh.h"

static double tet6(const double *a, const double *b, const double *c, const double *d)
{
    double e[3], f[3], g[3];
    for (int k = 0; k < 3; k++)
        e[k] = b[k] - a[k], f[k] = c[k] - a[k], g[k] = d[k] - a[k];
    return e[0] * (f[1] * g[2] - f[2] * g[1]) - e[1] * (f[0] * g[2] - f[2] * g[0]) + e[2] * (f[0] * g[1] - f[1] * g[0]);
}

/* A cell's signed volume from tetrahedra: a hex by its six around the diagonal 0-6, a wedge by three. */
static double cell_volume(const api_volmesh *m, size_t c)
{
    const uint32_t *q = m->conn + 8 * c;
    const double *P[8];
    for (int k = 0; k < (m->type[c] == API_CELL_HEX ? 8 : 6); k++)
        P[k] = m->pos + 3 * q[k];
    if (m->type[c] == API_CELL_HEX) {
        static const int t[6][2] = { { 1, 2 }, { 2, 3 }, { 3, 7 }, { 7, 4 }, { 4, 5 }, { 5, 1 } };
        double v = 0;
        for (int i = 0; i < 6; i++)
            v += tet6(P[0], P[t[i][0]], P[t[i][1]], P[6]);
        return v / 6;
    }
    const double *g[6] = { P[0], P[2], P[1], P[3], P[5], P[4] };   /* Gmsh's prism order */
    return (tet6(g[0], g[1], g[2], g[3]) + tet6(g[1], g[2], g[3], g[4]) + tet6(g[2], g[3], g[4], g[5])) / 6;
}

static pde_solution *vase(void)
{
    static const char doc[] = "{\"preset\":\"vase\"}";
    api_error err;
    api_model *m = api_model_parse(doc, sizeof doc - 1, &err);
    assert_non_null(m);
    pde_solution *s = NULL;
    assert_int_equal(api_solve(m, &s, &err), 0);
    api_model_free(m);
    return s;
}

static pde_solution *solid(const char *name)
{
    return strcmp(name, "vase") ? preset_solution(name) : vase();
}

typedef struct {
    const char *name;
    int polar;     /* u = 0 collapses along v, and v = 0, 1 is a seam */
    int exact;     /* the cells' volumes sum to the solid's to rounding */
} solid_row;

static const solid_row solids[] = {
    { "fig1a", 0, 1 }, { "fig1c", 0, 1 }, { "fig4a", 1, 0 }, { "fig4w", 1, 0 }, { "vase", 1, 0 },
};

static void build(const pde_solution *s, unsigned nu, unsigned nv, unsigned nw, api_volmesh *m)
{
    unsigned r[3] = { nu, nv, nw };
    api_error err;
    int rc = api_volmesh_build(s, r, NULL, m, &err);
    if (rc)
        fail_msg("%s", err.message);
}

static void counts_should_follow_the_samples_and_the_collapsed_axes(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof solids / sizeof solids[0]; i++) {
        pde_solution *s = solid(solids[i].name);
        unsigned nu = 5, nv = 7, nw = 4;
        api_volmesh m;
        build(s, nu, nv, nw, &m);
        size_t np, nhex, nwedge;
        if (solids[i].polar) {   /* one node per w on the axis; v = 1 is v = 0 */
            np = nw * (1 + (size_t)(nu - 1) * (nv - 1));
            nhex = (size_t)(nu - 2) * (nv - 1) * (nw - 1);
            nwedge = (size_t)(nv - 1) * (nw - 1);
        } else {
            np = (size_t)nu * nv * nw;
            nhex = (size_t)(nu - 1) * (nv - 1) * (nw - 1);
            nwedge = 0;
        }
        print_message("%s: %zu points, %zu hex, %zu wedges, %zu folded\n", solids[i].name, m.npoints, m.nhex,
                      m.nwedge, m.nfolded);
        assert_int_equal(m.npoints, np);
        assert_int_equal(m.nhex, nhex);
        assert_int_equal(m.nwedge, nwedge);
        assert_int_equal(m.ncells, nhex + nwedge);
        for (size_t c = 0; c < m.ncells; c++)
            assert_int_equal(m.type[c], c < nhex ? API_CELL_HEX : API_CELL_WEDGE);
        /* the skin: u0 collapses and v0, v1 are a seam for the polar solids */
        size_t fq[6] = { (size_t)(nv - 1) * (nw - 1), (size_t)(nv - 1) * (nw - 1), (size_t)(nu - 1) * (nw - 1),
                         (size_t)(nu - 1) * (nw - 1), (size_t)(nu - 1) * (nv - 1), (size_t)(nu - 1) * (nv - 1) };
        if (solids[i].polar)
            fq[0] = fq[2] = fq[3] = 0;
        for (int f = 0; f < 6; f++)
            assert_int_equal(m.face_nquads[f], fq[f]);
        api_volmesh_free(&m);
        pde_solution_free(s);
    }
}

static double mesh_volume(const api_volmesh *m, int positive_only_check)
{
    double v = 0;
    for (size_t c = 0; c < m->ncells; c++) {
        double cv = cell_volume(m, c);
        if (positive_only_check && !m->fold[c])
            assert_true(cv > 0);
        v += cv;
    }
    return v;
}

static void cells_should_be_positive_and_sum_to_the_volume_at_second_order(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof solids / sizeof solids[0]; i++) {
        pde_solution *s = solid(solids[i].name);
        pde_props p;
        assert_int_equal(pde_properties(s, NULL, &p), PDE_OK);
        double err[2];
        for (int h = 0; h < 2; h++) {
            unsigned n = h ? 33 : 17;
            api_volmesh m;
            build(s, n, n, n, &m);
            double v = mesh_volume(&m, 1);
            if (!p.folds)
                assert_int_equal(m.nfolded, 0);
            err[h] = fabs(fabs(v) - (p.folds ? fabs(p.signed_volume) : p.volume));
            api_volmesh_free(&m);
        }
        print_message("%s: volume %.12g, errors %.3g %.3g, ratio %.3g\n", solids[i].name, p.volume, err[0], err[1],
                      err[0] / err[1]);
        if (!strcmp(solids[i].name, "fig1a"))
            assert_true(fabs(p.volume - 1) < 1e-12);
        if (solids[i].exact) {   /* the map is linear along each edge's direction: the tetrahedra are exact */
            assert_true(err[0] < 1e-12 * p.volume && err[1] < 1e-12 * p.volume);
        } else {
            assert_true(err[0] / err[1] > 3.0 && err[0] / err[1] < 5.0);
        }
        pde_solution_free(s);
    }
}

static void fig4a_should_flag_the_cells_where_det_j_is_negative(void **state)
{
    (void)state;
    pde_solution *s = preset_solution("fig4a");
    api_volmesh m;
    build(s, 17, 17, 17, &m);
    size_t negative = 0;
    for (size_t c = 0; c < m.ncells; c++) {
        /* recompute det J at the cell's centre from core: cell_detj must agree */
        if (m.sign * m.cell_detj[c] < 0) {
            negative++;
            assert_int_equal(m.fold[c], 1);
        }
    }
    assert_true(negative > 0);
    /* core's det J at the 16^3 cells' centres, counted independently: as many negative as flagged so */
    size_t core_negative = 0;
    for (int i = 0; i < 16; i++)
        for (int j = 0; j < 16; j++)
            for (int k = 0; k < 16; k++) {
                double xu[3], xv[3], xw[3];
                pde_eval_d(s, (i + 0.5) / 16, (j + 0.5) / 16, (k + 0.5) / 16, NULL, xu, xv, xw);
                double dj = xu[0] * (xv[1] * xw[2] - xv[2] * xw[1]) - xu[1] * (xv[0] * xw[2] - xv[2] * xw[0]) +
                            xu[2] * (xv[0] * xw[1] - xv[1] * xw[0]);
                core_negative += m.sign * dj < 0;
            }
    assert_int_equal(core_negative, negative);
    /* an inverted cell (negative volume from its tetrahedra) is always flagged */
    for (size_t c = 0; c < m.ncells; c++)
        if (cell_volume(&m, c) <= 0)
            assert_int_equal(m.fold[c], 1);
    assert_true(m.nfolded >= negative);
    pde_props p;
    assert_int_equal(pde_properties(s, NULL, &p), PDE_OK);
    assert_true(p.folds);
    api_volmesh_free(&m);
    pde_solution_free(s);
}

static int cmp_pos(const void *a, const void *b)
{
    return memcmp(a, b, 3 * sizeof(double));
}

static void fig4a_should_have_no_two_points_in_one_place(void **state)
{
    (void)state;
    pde_solution *s = preset_solution("fig4a");
    api_volmesh m;
    build(s, 9, 12, 5, &m);
    double *p = malloc(m.npoints * 3 * sizeof *p);
    memcpy(p, m.pos, m.npoints * 3 * sizeof *p);
    for (size_t k = 0; k < 3 * m.npoints; k++)
        if (p[k] == 0)
            p[k] = 0;   /* -0 as +0 */
    size_t close = 0;
    for (size_t a = 0; a < m.npoints; a++)
        for (size_t b = a + 1; b < m.npoints; b++) {
            double d = fabs(p[3 * a] - p[3 * b]) + fabs(p[3 * a + 1] - p[3 * b + 1]) + fabs(p[3 * a + 2] - p[3 * b + 2]);
            close += d < 1e-9;
        }
    assert_int_equal(close, 0);
    qsort(p, m.npoints, 3 * sizeof *p, cmp_pos);
    for (size_t a = 1; a < m.npoints; a++)
        assert_true(memcmp(p + 3 * (a - 1), p + 3 * a, 3 * sizeof *p) != 0);
    free(p);
    api_volmesh_free(&m);
    pde_solution_free(s);
}

static void res_should_be_bounded(void **state)
{
    (void)state;
    pde_solution *s = preset_solution("fig1a");
    api_volmesh m;
    api_error err;
    unsigned big[3] = { 1000, 1000, 1000 }, one[3] = { 1, 4, 4 };
    assert_int_equal(api_volmesh_build(s, big, NULL, &m, &err), -1);
    assert_int_equal(err.status, API_ERR_LIMIT);
    assert_int_equal(api_volmesh_build(s, one, NULL, &m, &err), -1);
    pde_solution_free(s);
}

/* 3 samples along v, which loops on fig. 4a, are 2 points around it: cells of no volume (QA). Refused,
 * naming v and 4. */
static void three_samples_around_a_loop_should_be_refused_naming_the_axis(void **state)
{
    (void)state;
    pde_solution *s = preset_solution("fig4a");
    api_volmesh m;
    api_error err;
    unsigned three[3] = { 4, 3, 4 }, four[3] = { 3, 4, 3 };
    assert_int_equal(api_volmesh_build(s, three, NULL, &m, &err), -1);
    assert_int_equal(err.status, API_ERR_DOCUMENT);
    if (!strstr(err.message, "along v") || !strstr(err.message, "at least 4"))
        fail_msg("the message does not name v and 4: %s", err.message);
    assert_int_equal(api_volmesh_build(s, four, NULL, &m, &err), 0);
    assert_true(m.ncells > 0);
    api_volmesh_free(&m);
    pde_solution_free(s);
}

static int stop_now(void *arg)
{
    (void)arg;
    return 1;
}

static void a_cancelled_build_should_say_so(void **state)
{
    (void)state;
    pde_solution *s = preset_solution("fig1a");
    api_volmesh m;
    api_error err;
    unsigned r[3] = { 4, 4, 4 };
    pde_cancel c = { stop_now, NULL };
    assert_int_equal(api_volmesh_build(s, r, &c, &m, &err), -1);
    assert_int_equal(err.status, API_ERR_CANCELLED);
    pde_solution_free(s);
}

/* A stop that counts its calls and answers yes from call number at on. */
typedef struct {
    unsigned calls, at;
} countdown;

static int stop_at(void *arg)
{
    countdown *c = arg;
    return ++c->calls > c->at;
}

/* The samples poll per row (u), not per plane (u, v): a plane of a big loft is seconds of pde_eval_d
 * past --job-timeout. Counted, not timed: a whole build polls at least once a row, so at most res[0]
 * evaluations go by unpolled, and a stop asked for midway ends the build at its next poll. */
static void a_build_should_poll_its_cancel_once_a_row(void **state)
{
    (void)state;
    pde_solution *s = preset_solution("fig1a");
    api_volmesh m;
    api_error err;
    unsigned r[3] = { 40, 6, 5 };
    countdown never = { 0, UINT_MAX };
    pde_cancel c = { stop_at, &never };
    assert_int_equal(api_volmesh_build(s, r, &c, &m, &err), 0);
    api_volmesh_free(&m);
    assert_true(never.calls >= r[1] * r[2]);
    countdown mid = { 0, r[1] * r[2] / 2 };
    c.arg = &mid;
    assert_int_equal(api_volmesh_build(s, r, &c, &m, &err), -1);
    assert_int_equal(err.status, API_ERR_CANCELLED);
    assert_int_equal(mid.calls, mid.at + 1);
    pde_solution_free(s);
}

static int put_file(void *ctx, const void *p, size_t n)
{
    return fwrite(p, 1, n, ctx) == n ? 0 : -1;
}

static void write_file(const api_volmesh *m, const pde_props *props, const char *path, int vtu)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    api_volmesh_cursor c = { 0, 0 };
    int r, pieces = 0;
    while ((r = vtu ? api_volmesh_vtu_piece(m, props, &c, put_file, f) : api_volmesh_msh_piece(m, props, &c, put_file, f)) == 0)
        pieces++;
    assert_int_equal(r, 1);
    assert_int_equal(fclose(f), 0);
}

/* The msh's $Entities: each surface's box is its own face's (QA: every one was the whole solid's). fig. 1a is
 * the cuboid [-0.5, 0.5]^2 x [0, 1]: its face u = 0 (surface 1) lies at x = -0.5, w = 1 (surface 6) at z = 1;
 * the volume's box is the whole. */
static void msh_entities_should_bound_their_own_faces(void **state)
{
    (void)state;
    pde_solution *s = preset_solution("fig1a");
    api_volmesh m;
    api_error err;
    const unsigned res[3] = { 3, 3, 3 };
    assert_int_equal(api_volmesh_build(s, res, NULL, &m, &err), 0);
    char path[] = "/tmp/pdesolid-ent-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    write_file(&m, NULL, path, 0);
    FILE *f = fopen(path, "r");
    char line[512];
    int in = 0, seen = 0;
    while (fgets(line, sizeof line, f)) {
        if (!strncmp(line, "$Entities", 9)) {
            in = 1;
            assert_non_null(fgets(line, sizeof line, f));   /* the counts */
            continue;
        }
        if (!strncmp(line, "$EndEntities", 12))
            break;
        int tag;
        double b[6];
        if (!in || sscanf(line, "%d %lf %lf %lf %lf %lf %lf", &tag, &b[0], &b[1], &b[2], &b[3], &b[4], &b[5]) != 7)
            continue;
        const double whole[6] = { -0.5, -0.5, 0, 0.5, 0.5, 1 };
        double want[6];
        memcpy(want, whole, sizeof want);
        if (seen < 6) {   /* surface tag = 2 axis + side + 1: that coordinate is the side's end; the volume last */
            const int axis = (tag - 1) / 2, side = (tag - 1) % 2;
            want[axis] = want[axis + 3] = whole[axis + 3 * side];
        }
        for (int k = 0; k < 6; k++)
            if (fabs(b[k] - want[k]) > 1e-12)
                fail_msg("entity %d (line %d): box %g %g %g %g %g %g, want %g %g %g %g %g %g", tag, seen, b[0], b[1],
                         b[2], b[3], b[4], b[5], want[0], want[1], want[2], want[3], want[4], want[5]);
        seen++;
    }
    fclose(f);
    unlink(path);
    assert_int_equal(seen, 7);
    api_volmesh_free(&m);
    pde_solution_free(s);
}

/* meshio reads the files back; det J at sample points is checked against core's pde_eval_d. */
static void files_should_read_back_in_meshio(void **state)
{
    (void)state;
    if (access("/usr/bin/python3", X_OK) || system("/usr/bin/python3 -c 'import meshio' 2>/dev/null")) {
        fail_msg("python3-meshio is missing: apt-get install python3-meshio");
    }
    const char *names[] = { "fig4a", "vase", "fig1a" };
    for (size_t i = 0; i < 3; i++) {
        pde_solution *s = solid(names[i]);
        pde_props p;
        assert_int_equal(pde_properties(s, NULL, &p), PDE_OK);
        api_volmesh m;
        unsigned nu = 6, nv = 9, nw = 5;
        build(s, nu, nv, nw, &m);
        char msh[64], vtu[64], py[64];
        snprintf(msh, sizeof msh, "/tmp/test_volmesh_%d.msh", (int)getpid());
        snprintf(vtu, sizeof vtu, "/tmp/test_volmesh_%d.vtu", (int)getpid());
        snprintf(py, sizeof py, "/tmp/test_volmesh_%d.py", (int)getpid());
        write_file(&m, &p, msh, 0);
        write_file(&m, &p, vtu, 1);
        /* det J at three samples: (u, v, w) = (1, 0, 0), (0.6, 0.5, 0.5), (0.8, 0.25, 1); their nodes by position */
        double uvw[3][3] = { { 1, 0, 0 }, { 0.6, 0.5, 0.5 }, { 0.8, 0.25, 1 } };
        FILE *f = fopen(py, "w");
        fprintf(f, "import meshio, numpy as np, sys\n"
                   "for path in sys.argv[1:]:\n"
                   "    m = meshio.read(path)\n"
                   "    assert len(m.points) == %zu, (path, len(m.points))\n"
                   "    n = {b.type: len(b.data) for b in m.cells}\n"
                   "    assert n.get('hexahedron', 0) == %zu and n.get('wedge', 0) == %zu, (path, n)\n"
                   "    d = m.point_data.get('detJ', m.point_data.get('det J'))\n",
                m.npoints, m.nhex, m.nwedge);
        for (int k = 0; k < 3; k++) {
            double x[3], xu[3], xv[3], xw[3];
            pde_eval_d(s, uvw[k][0], uvw[k][1], uvw[k][2], x, xu, xv, xw);
            double dj = xu[0] * (xv[1] * xw[2] - xv[2] * xw[1]) - xu[1] * (xv[0] * xw[2] - xv[2] * xw[0]) +
                        xu[2] * (xv[0] * xw[1] - xv[1] * xw[0]);
            fprintf(f, "    i = np.argmin(np.sum((m.points - [%.17g, %.17g, %.17g])**2, axis=1))\n"
                       "    assert abs(d[i] - %.17g) <= 1e-6 * (1 + abs(%.17g)), (path, d[i], %.17g)\n",
                    x[0], x[1], x[2], dj, dj, dj);
        }
        fprintf(f, "print('ok')\n");
        fclose(f);
        char cmd[256];
        snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s %s %s", py, msh, vtu);
        assert_int_equal(system(cmd), 0);
        if (access("/usr/bin/gmsh", X_OK))
            fail_msg("gmsh is missing: apt-get install --no-install-recommends gmsh (.ci/deps)");
        snprintf(cmd, sizeof cmd, "/usr/bin/gmsh -check %s > /dev/null 2>&1", msh);
        assert_int_equal(system(cmd), 0);
        if (!p.folds) {   /* Gmsh's own Jacobians of the cells (hexahedra and prisms): all positive */
            char geo[80];
            snprintf(geo, sizeof geo, "%s.geo", msh);
            f = fopen(geo, "w");
            fprintf(f, "Merge \"%s\";\nPlugin(AnalyseMeshQuality).JacobianDeterminant = 1;\n"
                       "Plugin(AnalyseMeshQuality).CreateView = 0;\nPlugin(AnalyseMeshQuality).Run;\n", msh);
            fclose(f);
            snprintf(cmd, sizeof cmd, "/usr/bin/gmsh %s -nopopup -0 -o %s.out.msh 2>&1", geo, geo);
            FILE *g = popen(cmd, "r");
            char line[512];
            double minj = -1;
            int found = 0;
            while (fgets(line, sizeof line, g)) {
                const char *at = strstr(line, "minJ      =");
                if (at && sscanf(at + 11, "%lf", &minj) == 1)
                    found = 1;
            }
            pclose(g);
            unlink(geo);
            snprintf(cmd, sizeof cmd, "%s.out.msh", geo);
            unlink(cmd);
            print_message("%s: gmsh's smallest Jacobian %g\n", names[i], minj);
            assert_true(found);
            assert_true(minj > 0);
        }
        if (!getenv("VOLMESH_KEEP"))
            unlink(msh), unlink(vtu), unlink(py);
        api_volmesh_free(&m);
        pde_solution_free(s);
    }
}

typedef struct {
    size_t total, pieces, largest;
} count_ctx;

static int put_count(void *ctx, const void *p, size_t n)
{
    (void)p;
    count_ctx *c = ctx;
    c->total += n, c->pieces++;
    c->largest = n > c->largest ? n : c->largest;
    return 0;
}

/* A 40^3 fig1a: the vtu's size is its header plus the appended blocks, each with its 8-byte length; the
 * pieces stay near 1 MB. */
static void large_files_should_stream_in_pieces_of_about_a_megabyte(void **state)
{
    (void)state;
    pde_solution *s = preset_solution("fig1a");
    api_volmesh m;
    build(s, 40, 40, 40, &m);
    for (int vtu = 0; vtu < 2; vtu++) {
        count_ctx cc = { 0, 0, 0 };
        api_volmesh_cursor c = { 0, 0 };
        int r;
        while ((r = vtu ? api_volmesh_vtu_piece(&m, NULL, &c, put_count, &cc)
                        : api_volmesh_msh_piece(&m, NULL, &c, put_count, &cc)) == 0)
            ;
        assert_int_equal(r, 1);
        assert_true(cc.pieces > 2);
        assert_true(cc.largest <= (1u << 20) + 65536);
        if (vtu) {
            size_t blocks = 7 * 8 + m.npoints * (4 + 24) + m.ncells * (1 + 4 + 8 * 8 + 8 + 1);
            assert_true(cc.total > blocks && cc.total < blocks + 4096);
        }
    }
    api_volmesh_free(&m);
    pde_solution_free(s);
}

/* A solid with no volume (a loft of zero sections: every point at the origin) gets no mesh of any kind: a
 * document error that says so, rather than a volume mesh of flat cells (a QA probe got 9 nodes at the origin and
 * one hexahedron of volume 0 at res 4, and at res 3 a message asking for the 3 samples it had). */
static void a_solid_with_no_volume_should_get_no_mesh_and_say_why(void **state)
{
    (void)state;
    static const char doc[] = "{\"loft\":{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[2,2,2]},\"sections\":["
                              "{\"w\":0,\"profile\":[[0,0,0],[0,0,0],[0,0,0]]},{\"w\":1,\"profile\":[[0,0,0],[0,0,0],[0,0,0]]}]}}";
    api_error err;
    api_model *md = api_model_parse(doc, sizeof doc - 1, &err);
    assert_non_null(md);
    pde_solution *s = NULL;
    assert_int_equal(api_solve(md, &s, &err), 0);
    api_model_free(md);
    const api_format fmts[] = { API_FMT_MSH, API_FMT_VTU, API_FMT_STL, API_FMT_GLB };
    const unsigned res[][3] = { { 3, 3, 3 }, { 4, 4, 4 }, { 9, 17, 5 } };
    for (size_t i = 0; i < sizeof fmts / sizeof *fmts; i++)
        for (size_t k = 0; k < sizeof res / sizeof *res; k++) {
            api_output *o = api_output_open_ex(s, NULL, NULL, fmts[i], res[k], NULL, NULL, &err);
            if (o)
                fail_msg("%s at %u: opened a mesh of a solid with no volume", api_format_info_of(fmts[i])->name,
                         res[k][0]);
            assert_int_equal(err.status, API_ERR_DOCUMENT);
            if (!strstr(err.message, "no volume"))
                fail_msg("%s at %u: %s", api_format_info_of(fmts[i])->name, res[k][0], err.message);
        }
    pde_solution_free(s);
    /* A solid with volume at too few samples: the message names res, as the volume meshes' does. */
    pde_solution *f = preset_solution("fig4a");
    assert_null(api_output_open_ex(f, NULL, NULL, API_FMT_STL, (const unsigned[3]){ 2, 2, 2 }, NULL, NULL, &err));
    assert_int_equal(err.status, API_ERR_DOCUMENT);
    if (!strstr(err.message, "res") || !strstr(err.message, "at least 3"))
        fail_msg("stl at 2: %s", err.message);
    pde_solution_free(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(counts_should_follow_the_samples_and_the_collapsed_axes),
        cmocka_unit_test(cells_should_be_positive_and_sum_to_the_volume_at_second_order),
        cmocka_unit_test(fig4a_should_flag_the_cells_where_det_j_is_negative),
        cmocka_unit_test(fig4a_should_have_no_two_points_in_one_place),
        cmocka_unit_test(res_should_be_bounded),
        cmocka_unit_test(three_samples_around_a_loop_should_be_refused_naming_the_axis),
        cmocka_unit_test(msh_entities_should_bound_their_own_faces),
        cmocka_unit_test(a_cancelled_build_should_say_so),
        cmocka_unit_test(a_build_should_poll_its_cancel_once_a_row),
        cmocka_unit_test(a_solid_with_no_volume_should_get_no_mesh_and_say_why),
        cmocka_unit_test(files_should_read_back_in_meshio),
        cmocka_unit_test(large_files_should_stream_in_pieces_of_about_a_megabyte),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
