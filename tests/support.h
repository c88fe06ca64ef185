/*
 * support.h: what the tests share. Above all an independent solver of the
 * boundary value problems the core solves in closed form, written another
 * way: multiple shooting on the first-order system, with a Taylor matrix
 * exponential on each short interval, Gauss-Legendre quadrature of the force,
 * and a banded pivoted solve of the continuity and boundary equations.
 */
#ifndef TEST_SUPPORT_H
#define TEST_SUPPORT_H

#include <pthread.h>
#include <stddef.h>

#include "pde.h"

struct api_model;
struct cJSON;

/*
 * M coupled modes: c h_m'''' + mu_m h_m + sum_k K[m][k] h_k = q_m(w) on [0,1],
 * with h_m(0), h_m'(0), h_m(1), h_m'(1) = bc[4m .. 4m+3].
 */
typedef struct {
    int M;
    double c;
    const double *mu;      /* M */
    const double *K;       /* M x M, row-major, or NULL */
    const double *bc;      /* 4 M */
    void (*q)(double w, double *out, void *ctx);   /* fills M values, or NULL */
    void *ctx;
    double freq;           /* fastest angular frequency or rate in q */
} indep_problem;

typedef struct indep_solution indep_solution;

indep_solution *indep_solve(const indep_problem *p);
/* h_m^(d)(w) for d = 0..3. */
double indep_eval(const indep_solution *s, int m, int d, double w);
void indep_free(indep_solution *s);

/*
 * The loft problem of one mode (pde.h, "Lofts"), solved the same way: h'''' = e h on each slab
 * between K sections at w[0] = 0 < ... < w[K-1] = 1, with x[k] given at every section, x_w = xw[k]
 * where tangent[k] (clamped), else x_ww = 0 at an end (natural) and continuous x_w, x_ww at an
 * interior section (C2). NULL if the shooting system is singular.
 */
typedef struct indep_loft indep_loft;

indep_loft *indep_loft_solve(double e, size_t K, const double *w, const int *tangent, const double *x,
                             const double *xw);
/* h^(d)(w), d = 0..3; at an interior section, the slab on the left when left is non-zero. */
double indep_loft_eval(const indep_loft *s, int d, double w, int left);
void indep_loft_free(indep_loft *s);

/* |a - b| <= tol * max(|a|, |b|, floor): a relative test with an absolute floor. */
int close_rel(double a, double b, double tol, double floor);

/* A root of f in [a, b], where fa = f(a) and fb = f(b) have opposite signs: Illinois steps, a bisection
 * every fourth (where they stall), to 1e-15 of max(1, |a|). The tests' references' one root finder. */
double ref_root(double (*f)(void *ctx, double x), void *ctx, double a, double fa, double b, double fb);
/* qsort's comparison of doubles, ascending. */
int ref_cmp_double(const void *a, const void *b);

#define assert_rel(a, b, tol, floor)                                                          \
    do {                                                                                      \
        double a_ = (a), b_ = (b);                                                            \
        if (!close_rel(a_, b_, (tol), (floor)))                                               \
            fail_msg("%s = %.17g, %s = %.17g, relative difference %.3g > %g", #a, a_, #b, b_,  \
                     fabs(a_ - b_) / fmax(fmax(fabs(a_), fabs(b_)), (floor)), (double)(tol)); \
    } while (0)

/* Factors, to write models briefly. */
pde_factor F_pow(int n);
pde_factor F_sin(double k);
pde_factor F_cos(double k);
pde_factor F_exp(double a);
pde_factor F_sinh(double a);
pde_factor F_cosh(double a);

/* f^(n)(t), written again here so that tests do not lean on the core's own. */
double tfactor(pde_factor f, double t, int n);

/*
 * The paper's solids, built from its four examples' parameters as the text
 * gives them (figures 1a, 1c, 1e, 1g, 2a-2c, 3a-3d, 4a-4x): a test's own
 * transcription. names[i] is "fig1a" and so on; returns the number of them.
 * A built model points into static storage: use it before the next call.
 */
size_t paper_figure_count(void);
const char *paper_figure_name(size_t i);
void paper_figure_model(size_t i, pde_model *m);

/* A preset's model, as a client's {"preset": name} gives it: a paper figure's with its default parameters
 * or a loft preset's (api_model_free it); fails the test if there is none. */
struct api_model *preset_model(const char *name);

/* 16 cosine modes in u per component (x, y; z = w), folding: a model past the properties' work bound
 * (tests/test_cost.c, test_props.c). b holds its terms, which *m points into. */
void sixteen_mode_model(pde_bterm b[3][16], pde_model *m);
/* The solution of a preset, a figure's or a loft's (a test failure if it does not solve); free with
 * pde_solution_free(). */
struct pde_solution *preset_solution(const char *name);

/* The solution of a client's document (a model, a preset or a loft, as POST /solve takes it), parsed and
 * solved through api_solve (a test failure naming the pointer if either fails); free with
 * pde_solution_free(). */
struct pde_solution *solve_text(const char *text);

/* Reads a whole file into a NUL-terminated buffer; NULL on failure. */
char *read_file(const char *path, size_t *len);

/*
 * pdesolidd for a test: started on a free loopback port with its stderr in a
 * log file in dir, and stopped with SIGTERM, which must end in exit status 0
 * (so a leak the sanitiser finds at exit fails the test). $PDESOLIDD_SAN
 * names the binary (build/san/pdesolidd). Both fail the test with cmocka on error.
 */
typedef struct {
    int pid;
    int port;
    char base[64];
    char log[160];
} daemon_t;

/* In a forked child before exec: killed when the test binary ends, as a failed assertion may skip its stop. */
void child_dies_with_parent(void);
void daemon_start(daemon_t *d, const char *dir, const char *args);
void daemon_stop(daemon_t *d);

/* ---- raw HTTP over loopback sockets, and a strict JSON check (test_hostile, test_badreq) ---- */

/*
 * One exchange on a new connection to 127.0.0.1:port: sends len bytes of req
 * (non-blocking, stopping early if the peer closes or stops reading), then
 * reads until the peer closes, or until a complete response is in and
 * 300 ms pass quietly, or until timeout_ms in all. An interim 100 Continue
 * is skipped. responses counts the status lines of final responses seen,
 * at the start of any line of what came (so a status line sent twice, or
 * hidden in a body, shows as 2). status is the first final response's
 * status, or 0 if none came; body is NUL-terminated (de-chunked if chunked),
 * head holds the status line and headers. Free with raw_reply_free.
 */
typedef struct {
    int status;
    int responses;      /* final responses seen */
    int closed;         /* the peer closed (or reset) the connection */
    int timed_out;      /* timeout_ms passed without a complete response or a close */
    int sent_all;       /* every byte of the request went out */
    char *head;
    char *body;
    size_t body_len;
    double seconds;     /* from the start of the exchange to the end of the reading */
    double first_response;   /* from the start to the first complete final response, or 0 */
} raw_reply;

int raw_dial(int port);
raw_reply raw_request(int port, const void *req, size_t len, int timeout_ms);
/* The same on a connected socket fd, which the caller closes. */
raw_reply raw_exchange(int fd, const void *req, size_t len, int timeout_ms);
void raw_reply_free(raw_reply *r);
/* Sends what it can of n bytes: stops when the peer closes or resets. */
void raw_send_all(int fd, const void *s, size_t n);
/* Reads into buf (NUL-terminated) until the peer closes or resets, or `seconds` pass in all: the bytes
 * read, or -1 on the timeout. */
long raw_read_to_close(int fd, char *buf, size_t cap, double seconds);
/* A header's value into out (1), or 0 if absent; case-insensitive names. */
int raw_header(const raw_reply *r, const char *name, char *out, size_t n);
/* n bytes of s are well-formed UTF-8: no overlong forms, surrogates or values over U+10FFFF. */
int utf8_valid(const char *s, size_t n);
/* n bytes of s are one JSON text per RFC 8259, in valid UTF-8, with no lone surrogate escapes. */
int json_strict_valid(const char *s, size_t n);
/* n threads, the i-th running fn(args + i * size) (fails the test if one cannot start); threads_join
 * waits for them all. */
void threads_start(pthread_t *t, int n, void *(*fn)(void *), void *args, size_t size);
void threads_join(pthread_t *t, int n);
/* A problem's "pointer" member: equal to pointer, or absent when pointer is NULL (docs/API.md: a pointer
 * names the field at fault); body is shown on failure. */
void expect_problem_pointer(const struct cJSON *problem, const char *pointer, const char *body);
/* Seconds on the monotonic clock. */
double mono_now(void);

/* ---- HTTP through libcurl (test_server, test_nginx) ---- */

/* A response as libcurl received it. */
typedef struct {
    long status;          /* the HTTP status, or -CURLcode when the exchange failed */
    char *body;           /* NUL-terminated (never NULL), len bytes; the caller frees it */
    size_t len;
    size_t cap;           /* bytes allocated for body (grown geometrically, so a 20 MB body is read in linear time) */
    char headers[4096];   /* the status line and header lines as received, cut at 4095 bytes */
} http_reply;

/*
 * One request to base (http://127.0.0.1:port) and path (with its query):
 * method, body of blen bytes or NULL, extra header lines separated by '\n'
 * or NULL, and Accept-Encoding (curl then decodes the body) or NULL. Sends
 * no Expect header; times out after 120 s. With a handle c the connection
 * may be kept alive across calls (c is reset first); with c NULL a handle
 * is made and cleaned up. Needs curl_global_init.
 */
http_reply http_request(void *c, const char *base, const char *method, const char *path, const void *body,
                        size_t blen, const char *headers, const char *encoding);
/* A header's value among raw header lines (up to the first blank line) into out (1), or 0 if absent. */
int http_header(const char *headers, const char *name, char *out, size_t n);

/* ---- temporary directories ---- */

/* mkdtemp(tmpl): 0, or -1 (a cmocka setup's convention). */
int tmpdir_make(char *tmpl);
/* rm -rf dir: 0, or -1. */
int tmpdir_remove(const char *dir);

/* ---- running one case (make check T=test_x F='pattern') ---- */

/* Runs only the cases whose names match $CMOCKA_FILTER (cmocka's * and ? wildcards), when it is set and
 * not empty; call it in main() before cmocka_run_group_tests. `make check F=...` sets it. */
void test_filter_from_env(void);

/* ---- independent properties of a solid (test_props) ---- */

/*
 * What pde_properties() reports, computed another way: the solid evaluated from the published closed
 * form (pde_solution_modes, checked against pde_eval_d), and every integral over the unit cube weighted
 * by |det J| by nested global-adaptive Gauss-Kronrod 7-15 over two axes, each line along the third
 * integrated exactly between the roots of det J (dense samples, a golden-section search at every
 * least of |det J| among them for a hidden lobe, roots by Illinois to 1e-15, Gauss-Legendre 20
 * between). The line runs along the axis where det J changes sign most often, so that it crosses the
 * fold. Error estimates are kept below 1e-12 of each integral's scale (looser, a lobe can hide from the
 * first few Kronrod nodes); the values agree to about 1e-12 with runs at 1e-13 and with the lines along
 * the other axes, and fig4a's volume with the 160-digit value to 1e-15. Surface area: |x_s x x_t| over
 * the six faces by nested adaptive GK 7-15 to 1e-10, each line cut first at every least of the element
 * among dense samples (agreeing to 4e-11 with runs at 1e-13); a face
 * that collapses gives 0 by itself, and two opposite faces that coincide
 * point for point (the seam v = 0, 1 of a solid of revolution) are both left out, as api/mesh.c does.
 */
typedef struct {
    double volume, signed_volume;
    double centroid[3];
    double inertia[3][3];          /* about the centroid: integral of (|r|^2 I - r r^T) |det J| */
    double principal_moments[3];   /* ascending */
    double principal_axes[3][3];   /* rows, a right-handed frame */
    double surface_area;
    double face_area[6];           /* u = 0, u = 1, v = 0, v = 1, w = 0, w = 1, seams included */
    int face_seam[6];              /* 1: the face coincides with its opposite, and is left out */
    double eval_error;             /* this evaluator against pde_eval_d, relative to the largest value */
    int converged;                 /* every adaptive integration met its tolerance, and the faces show
                                    * no fold that the integrals missed */
    size_t lines;                  /* w-lines evaluated, a measure of the work */
} ref_props_out;

/* 0, or -1 when out of memory. Uses static scratch: one thread at a time. Measured under the
 * sanitisers: 0.01 s (fig1), 0.2-0.5 s (fig2, fig4), 3 s (fig3a), 15-31 s (fig3b-d). */
int ref_props(const pde_solution *s, ref_props_out *out);

/* Gauss-Legendre nodes and weights of n points on [0, 1], by Newton on the three-term recurrence (ref_props'). */
void ref_gauss_legendre(int n, double *x, double *w);

/* Eigenvalues of a symmetric 3 x 3 matrix, ascending, and unit eigenvectors as rows of a right-handed
 * frame (cyclic Jacobi). */
void sym3_eigen(const double (*a)[3], double *val, double (*vec)[3]);

#endif
