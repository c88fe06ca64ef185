/*
 * harm.c: the area of a face of one harmonic (harm.h).
 *
 * Why: on fig. 2 and 4 the face u = 1 took three quarters of pde_properties (2-D panels along lines,
 * refined around the rounded folds), where its element is a trigonometric polynomial in theta at
 * each w: a mean over theta, a 1-D integral in w. At a point w, with A = (A_x, A_y, A_z)(w) and so on:
 *
 *     x_t = k pi (A cos theta - B sin theta),   x_w = A' sin theta + B' cos theta + D',
 *     x_t x x_w = c0 + c1 cos theta + s1 sin theta + c2 cos 2 theta + s2 sin 2 theta,
 *
 * c0 = k pi (A x B' - B x A') / 2, c1 = k pi A x D', s1 = -k pi B x D', c2 = k pi (A x B' + B x A') / 2,
 * s2 = k pi (A x A' - B x B') / 2; |x_t x x_w|^2 from their dot products, nine Fourier coefficients,
 * and the flux's mean D . c0 + (A . s1 + B . c1) / 2 exactly.
 *
 * Where |x_t x x_w|^2 has no odd harmonics (fig. 2 and 4: D' normal to A, B, A', B'), it is a
 * trigonometric polynomial of degree 2 in 2 theta, and where the trapezoidal rule converges slowly (a
 * dip) the mean comes from its roots instead (even_mean): a fixed cost, whatever the dips' depth.
 */
#include <complex.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "harm.h"

#define NT 256          /* points of theta per 2 pi on the trapezoidal rule's finest level */
#define N0 16           /* ... on its first */
#define TRAP_TOL 1e-8   /* two levels agree to this, relative: geometric convergence puts the finer
                         * near its square */
#define DEPTH 40        /* halvings of a panel of w, at most */
#define NOISE 1e-11     /* ... nor once it agrees with its halves to this, relative: a mean's own error (the
                         * cuts and pieces of a dip change with w) is not smooth in w */
#define DEEP 0.02       /* an element below this of its largest at 64 points of 2 pi, in a narrow dip
                         * (narrow), goes there directly */
#define GRADE 0.45      /* a dip in theta: pieces graded towards its least value, each this of the distance left */
#define GRADE_LEVELS 60 /* ... this many at most, */
#define PIECE_MAX 0.5   /* ... none wider than this (a wide dip's) */
#define U_LEVELS 2      /* ... or, where its width is known, this many such pieces, */
#define U_NEAR 8.0      /* ... while the distance left is above this of the width, */
#define U_WIDTH 2.0     /* ... and the rest in panels of u (s = width sinh u) this wide */
#define HALVES_AGREE 1e-2 /* a panel whose Kronrod rule fails against its Gauss rule keeps it where its halves'
                          * Gauss rules agree with it to this of the tolerance (at the tolerance itself,
                          * fig. 4x's area moved by 7.7e-13) */
#define P43_TRY 1e4     /* ... and Patterson's extension where the two differ by at most this of the tolerance
                         * (beyond, on the presets, it failed but twice, and its 22 points were lost: fig.
                         * 2c's layer at w = 0), kept where it agrees with the Kronrod rule to HALVES_AGREE
                         * of the tolerance: at the tolerance itself both were 1.2e-9 off on a fig. 4 model
                         * (b = 4, c = -10, r0 = 1.16, r1 = 1.13, r'0 = 3.3, r'1 = -1.2, h'0 = 5.8, h'1 = 0.9,
                         * p0 = 5e5, xi = 7: w in [0.982, 1]), agreeing to 3.4e-2 of it */
#define P43_CUT 100     /* ... and before a cut at a dip of w where they differ by at most this (fig. 4l's
                         * dips of 0.03 to 0.05 of the largest, 4 to 24 tolerances: cut, they took 94 points
                         * where Patterson's rule took 22) */
#define DIP 0.05        /* a panel of w that fails its halves with the element below this of its largest */
#define DIP_EPS 1e-7    /* ... is cut at the least place, located to this of the panel, */
#define W_GRADE 0.1     /* ... and graded towards it, each piece this of the distance left, */
#define W_LEVELS 2      /* ... in this many pieces and the last */
#define POLL_NODES 256  /* points of w between polls of the caller's stop(), */
#define POLL_THETA 1e5  /* ... or points of theta of one harmonic's cuts (about 2 ms) */
#define MAX_SPLITS 32   /* cuts at dips of w in a face, at most: a cut inside a graded piece may cut
                         * again (a stiff model's valley of dips cut 30 deep, each deeper) */
#define MAX_NODES 40000 /* points of w in a face, at most (fig. 2c: 2400), else the panels */
#define CUT_WORK 4e6    /* a face of one harmonic: the points of theta of its sections' cuts and their
                         * minima's intervals, at most, else the panels (stiff models 2.8e6, the cusp
                         * loft of test_props 2.9e6, presets 352; a loft of sections alternating a
                         * segment along z and along x took 1.2e7, 0.55 s, four times the estimate) */
#define MANY_WORK 1.5e7 /* a face of many harmonics (below): its points of theta times (harmonics + 1), at
                         * most, else the panels (tower and blade 5.4e6: 1.65e5 points of 32 harmonics; a
                         * loft of 80 harmonics took 2e6 points, 1.6e8, before it gave up) */

#define EV_N 1024       /* the cut's rule (even_mean): intervals of beta on [0, pi] on its finest level */
#define EV_N0 8         /* ... on its first */
#define EV_MAP 0.05     /* ... alpha(beta) where a root lies within this of the circle, else alpha = beta */
#define EV_SWITCH 1e-3  /* the trapezoidal rule's levels, from N0 points over pi, differ by more than this
                         * relative: even_mean instead of its next levels */
#define EV_GUARD 1e-8   /* the roots reproduce the element's square to this of its largest sample (a bound over the circle) */

/* cos j theta_i, then sin j theta_i, j = 1..4, at theta_i = 2 pi i / NT */
static double trig[NT][8];
/* cos 2 theta_i, sin 2 theta_i, cos 4 theta_i, sin 4 theta_i, i < NT / 2, each a column in the order samples()
 * takes them without odd harmonics (the first level's i, then each next level's new ones, ascending): a
 * level's points two at a time lie side by side */
static double etrig[4][NT / 2];
/* cos alpha(beta_i), the trapezoidal rule's weight alpha'(beta_i) (half at the ends), 1 - cos alpha and
 * 1 + cos alpha (without cancellation), at beta_i = pi i / EV_N: [0] alpha = beta, [1] alpha = beta - sin(2 beta) / 2;
 * each a column, in the order even_mean takes the points (its first level's EV_N0 + 1, then each next level's
 * new ones, i ascending), so that a level's points two at a time lie side by side (one more, unused, at the end) */
static double evt[2][4][EV_N + 2];
static pthread_once_t trig_once = PTHREAD_ONCE_INIT;

static void trig_init(void)
{
    for (int i = 0; i < NT; i++)
        for (int j = 1; j <= 4; j++)
            trig[i][j - 1] = cos(2.0 * M_PI * i * j / NT), trig[i][j + 3] = sin(2.0 * M_PI * i * j / NT);
    for (int st = NT / N0, p = 0, first = 1; st >= 1; st /= 2, first = 0)
        for (int i = first ? 0 : st; i < NT / 2; i += first ? st : 2 * st, p++)
            etrig[0][p] = trig[i][1], etrig[1][p] = trig[i][5], etrig[2][p] = trig[i][3], etrig[3][p] = trig[i][7];
    for (int st = EV_N / EV_N0, p = 0, first = 1; st >= 1; st /= 2, first = 0)
        for (int i = first ? 0 : st; i <= EV_N; i += first ? st : 2 * st, p++) {
            const double b = M_PI * i / EV_N;
            for (int m = 0; m < 2; m++) {
                const double a = m ? b - 0.5 * sin(2.0 * b) : b, sa = sin(0.5 * a), ca = cos(0.5 * a);
                evt[m][0][p] = cos(a), evt[m][2][p] = 2.0 * sa * sa, evt[m][3][p] = 2.0 * ca * ca;
                evt[m][1][p] = m ? 2.0 * sin(b) * sin(b) : i == 0 || i == EV_N ? 0.5 : 1.0;
            }
        }
}

/* x_t x x_w = v[0] + v[1] cos theta + v[2] sin theta + v[3] cos 2 theta + v[4] sin 2 theta, and its
 * square |x_t x x_w|^2 = a[0] + sum_j a[j] cos j theta + b[j] sin j theta; period pi where odd is 0 */
typedef struct {
    double v[5][3], a[5], b[5];
    int odd;
} trig4;

/* even_mean's two roots inside the circle at the last section that took it, to start from */
typedef struct {
    double complex z[2];
    int ok;
} ev_hint;

typedef struct {
    const harm_opts *o;
    const pde_solution *s;
    size_t nm;
    double *wt, *h, *dh;       /* per mode: its factor of the face's fixed parameter at the side; per
                                * distinct h(w) of tab: h, h' */
    wtable *tab;               /* s's distinct h(w) (fig. 2 and 4: 3 of 5), each evaluated once a point */
    const unsigned *map;       /* per mode of s: its h's place in h, dh */
    unsigned char *slot;       /* per mode: 3 part + c, part 0 sin (A), 1 cos (B), 2 the factor 1 (D) */
    double kpi, tol[2];
    double dip, dip_at;        /* the least element over its largest at the points of w since reset, and where */
    size_t nodes, next_poll;
    double next_poll_work;     /* ... or once H->work reaches this (one harmonic's cuts: 1200 points of theta a section) */
    int splits;                /* cuts at a dip of w left */
    int stopped;               /* o->cancel asked to stop */
    ev_hint roots;             /* even_mean's last roots */
    size_t poll_every, max_nodes;
    double max_work;           /* H->work at most (MANY_WORK or CUT_WORK), else the panels */
    /* Many harmonics (the section below): */
    int many, nh;              /* the harmonics along t are hj[0..nh - 1] */
    int *hj, *mslot;           /* per mode: (0: D, 1 + 2 h: sin of hj[h], 2 + 2 h: cos) * 3 + c */
    double *cf;                /* per such entry: x's 3 components, then x_w's */
    double *e;                 /* the samples of the element on MT points */
    double big;                /* the largest sample at the w being integrated */
    double work;               /* points of theta so far (one harmonic's: of its cuts, and their minima's intervals) */
    int fold;                  /* the element met 0 at a point of theta: a fold's cuspidal edge */
} harm_ctx;

/* cos j theta into cs[j - 1], sin j theta into cs[j + 3], j = 1..4 */
static void harmonics(double th, double cs[8])
{
    cs[0] = cos(th), cs[4] = sin(th);
    for (int j = 1; j < 4; j++) {
        cs[j] = cs[j - 1] * cs[0] - cs[j + 3] * cs[4];
        cs[j + 4] = cs[j + 3] * cs[0] + cs[j - 1] * cs[4];
    }
}

static double q_at(const trig4 *q, const double cs[8])
{
    if (!q->odd)   /* the same sums without the odd harmonics' zeros (half the trapezoidal rule's work) */
        return q->a[0] + (q->a[2] * cs[1] + q->b[2] * cs[5]) + (q->a[4] * cs[3] + q->b[4] * cs[7]);
    double v = q->a[0];
    for (int j = 1; j <= 4; j++)
        v += q->a[j] * cs[j - 1] + q->b[j] * cs[j + 3];
    return v;
}

/* The element at theta (a piece's rule between two least values): from x_t x x_w, not from its
 * square, whose rounding near a least value m (of its coefficients' size times 1e-16) would be
 * 1e-16 / m^2 of m^2 and swamp the rule's tolerance there (fig. 4a: m 2e-3 of 44). */
static double elem_cs(const trig4 *q, double c1, double s1)
{
    const double c2 = c1 * c1 - s1 * s1, s2 = 2.0 * s1 * c1;
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = q->v[0][k] + q->v[1][k] * c1 + q->v[2][k] * s1 + q->v[3][k] * c2 + q->v[4][k] * s2;
    return sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

static void elem_fn(void *arg, double th, double *val)
{
    *val = elem_cs(arg, cos(th), sin(th));
}

/* q's derivatives 1 to n (at most TAYLOR) at theta into d[1..n]: with C_j = a_j cos j theta + b_j sin j theta and
 * S_j = b_j cos j theta - a_j sin j theta, the kth is sum_j j^k of S_j, -C_j, -S_j, C_j for k = 1, 2, 3, 4 mod 4 */
#define TAYLOR 8
static void dq_all(const trig4 *q, double th, int n, double d[TAYLOR + 1])
{
    double cs[8], C[4], S[4];
    harmonics(th, cs);
    for (int j = 0; j < 4; j++)
        C[j] = q->a[j + 1] * cs[j] + q->b[j + 1] * cs[j + 4], S[j] = q->b[j + 1] * cs[j] - q->a[j + 1] * cs[j + 4];
    double jk[4] = { 1.0, 1.0, 1.0, 1.0 };   /* j^k */
    for (int k = 1; k <= n; k++) {
        double s = 0.0;
        for (int j = 0; j < 4; j++)
            jk[j] *= j + 1, s += jk[j] * (k % 2 ? S[j] : C[j]);
        d[k] = k % 4 == 1 || k % 4 == 0 ? s : -s;
    }
}

/* q' (returned) and q'' (into *d2) at theta, for q = |x_t x x_w|^2 */
static double dq(const trig4 *q, double th, double *d2)
{
    double d[TAYLOR + 1];
    dq_all(q, th, 2, d);
    *d2 = d[2];
    return d[1];
}

/* |x_t x x_w|^2's least in [lo, hi] (around a least sample), by Newton on its derivative kept inside
 * the bracket, bisecting where a step leaves it; its second derivative there into *d2. */
static double least(const trig4 *q, double lo, double hi, double *d2)
{
    double x = 0.5 * (lo + hi);
    for (int it = 0; it < 60; it++) {
        const double d1 = dq(q, x, d2);
        if (d1 < 0.0)
            lo = x;
        else
            hi = x;
        double nx = *d2 > 0.0 ? x - d1 / *d2 : NAN;
        if (!(nx > lo && nx < hi))
            nx = 0.5 * (lo + hi);
        if (fabs(nx - x) <= 1e-15 * (1.0 + fabs(x)))
            return nx;
        x = nx;
    }
    return x;
}

/*
 * Every least value of |x_t x x_w|^2 in [lo, hi] (q' there d1lo, d1hi) into at[], *n of them, located
 * (least). q' is a trigonometric polynomial of degree 4, with at most 8 zeros a period, but two of
 * them (two narrow dips) may sit closer than any sampling's spacing: they are isolated by Taylor's
 * theorem instead. With d_k = q^(k)(mid), h the half-width and L[k] = sum_j j^k times the harmonics'
 * amplitudes (a bound of |q^(k)|): no zero of q' where |d_1| > L[2] h, or > sum_{k = 2..TAYLOR}
 * |d_k| h^(k-1) / (k-1)! + L[TAYLOR + 1] h^TAYLOR / TAYLOR!; at most one (q' monotone: a least value
 * where it rises through 0) where the same holds for q'' (|d_2| > L[3] h, or > its sum); else halved,
 * to 2^-CRIT_DEPTH. Where q' vanishes to high order (an element like |sin theta| (1 - cos theta), a
 * section's cusp: q ~ theta^6), the first bounds alone left every interval near the zero undecided at
 * every depth, 2^40 of them (make fuzz: one section ran for hours); the whole series leaves a few a
 * level, as many as the zero's order. Each call's intervals are counted against *left (CRIT_WORK a
 * section): 0 where it runs out, the cuts then unknown, else 1.
 */
#define CRIT_DEPTH 40
#define CRIT_MAX 8
#define CRIT_WORK 4096
static int minima(const trig4 *q, double lo, double hi, double d1lo, double d1hi, const double L[TAYLOR + 2],
                  int depth, double *at, int *n, int *left)
{
    const double h = 0.5 * (hi - lo), mid = lo + h;
    double d[TAYLOR + 1], r[2];
    if (--*left < 0)
        return 0;
    dq_all(q, mid, TAYLOR, d);
    for (int i = 0; i < 2; i++) {   /* the series of q' (i = 0) and q'' (i = 1) about mid, but its first term */
        double hk = 1.0, s = 0.0;
        for (int k = 2 + i; k <= TAYLOR; k++)
            hk *= h / (k - 1 - i), s += fabs(d[k]) * hk;
        r[i] = s + L[TAYLOR + 1] * hk * h / (TAYLOR - i);
    }
    const double a1 = fabs(d[1]), a2 = fabs(d[2]);
    if (a1 > L[2] * h || a1 > r[0])
        return 1;
    if (a2 > L[3] * h || a2 > r[1] || depth >= CRIT_DEPTH) {
        double d2;
        if (d1lo < 0.0 && d1hi >= 0.0 && *n < CRIT_MAX)
            at[(*n)++] = least(q, lo, hi, &d2);
        return 1;
    }
    return minima(q, lo, mid, d1lo, d[1], L, depth + 1, at, n, left) &&
           minima(q, mid, hi, d[1], d1hi, L, depth + 1, at, n, left);
}

/* The element at c + t, cos c = cb and sin c = sb, |t| <= PIECE_MAX: cos and sin of t by their series */
static double elem_off(const trig4 *q, double cb, double sb, double t)
{
    const double t2 = t * t;
    const double ct = 1.0 - t2 / 2 * (1.0 - t2 / 12 * (1.0 - t2 / 30 * (1.0 - t2 / 56 * (1.0 - t2 / 90 *
                      (1.0 - t2 / 132 * (1.0 - t2 / 182))))));
    const double st = t * (1.0 - t2 / 6 * (1.0 - t2 / 20 * (1.0 - t2 / 42 * (1.0 - t2 / 72 * (1.0 - t2 / 110 *
                      (1.0 - t2 / 156 * (1.0 - t2 / 210)))))));
    return elem_cs(q, cb * ct - sb * st, sb * ct + cb * st);
}

/* [c + lo, c + d] (offsets of either sign) by the rule, in pieces no wider than PIECE_MAX (a wide
 * dip's: the rest of theta too); one sin and cos a piece, at its start */
static double span(const harm_opts *o, const trig4 *q, double c, double lo, double d, double *work)
{
    const int np = (int)ceil(fabs(d - lo) / PIECE_MAX);
    *work += (double)np * o->n;
    const double len = (d - lo) / np;
    double sum = 0.0;
    for (int p = 0; p < np; p++) {
        const double t0 = c + lo + len * p, cb = cos(t0), sb = sin(t0);
        double piece = 0.0;
        for (int i = 0; i < o->n; i++)
            piece += o->wt[i] * elem_off(q, cb, sb, len * o->x[i]);
        sum += fabs(len) * piece;
    }
    return sum;
}

/*
 * Near a least value m at c, the element is about sqrt(m^2 + kappa^2 (theta - c)^2): smooth only on
 * the scale m / kappa. So from far to c, pieces graded geometrically, each GRADE of the distance
 * left, down to a quarter of that scale (or 1e-7: a kink), each with the rule: a piece's nearest
 * singularity lies at least 2 GRADE / (1 - GRADE) of its half-length beyond its end, where the rule's
 * error falls like 5^-2n; the last piece's lies 8 of them away.
 */
static double toward(const harm_opts *o, const trig4 *q, double far, double c, double scale, double *work)
{
    double sum = 0.0, d = far - c;
    for (int k = 0; k <= GRADE_LEVELS; k++, d *= GRADE) {
        const int last = k == GRADE_LEVELS || !(fabs(d) > fmax(0.25 * scale, 1e-7));
        sum += span(o, q, c, last ? 0.0 : GRADE * d, d, work);
        if (last)
            break;
    }
    return sum;
}

/*
 * The same integral where the dip's width scale = m / kappa > 0 is known: its first U_LEVELS pieces
 * graded as there (the element's other branch points, O(far - c) away, are left as far behind),
 * the rest, [c, c + d], by s = scale sinh u (theta = c + s), which takes sqrt(m^2 + kappa^2 s^2) ds
 * to m scale cosh^2 u du, entire: the element's branch points near c +- i scale go to u near
 * +- i pi / 2, so panels of u U_WIDTH wide keep the rule's error near rho^-2n, rho = 3.4, and u runs
 * only to asinh(|d| / scale), where the graded pieces took log(4 |d| / scale) / log(1 / GRADE) of
 * them. One exp a point.
 */
static double toward_sinh(const harm_opts *o, const trig4 *q, double far, double c, double scale, double *work)
{
    double d = far - c, sum = 0.0;
    for (int k = 0; k < U_LEVELS && fabs(d) > U_NEAR * scale; k++, d *= GRADE)
        sum += span(o, q, c, GRADE * d, d, work);
    if (fabs(d) > PIECE_MAX)
        return sum + toward(o, q, c + d, c, scale, work);
    const double sg = d < 0.0 ? -1.0 : 1.0, U = asinh(fabs(d) / scale), cb = cos(c), sb = sin(c);
    const int np = (int)ceil(U / U_WIDTH);
    *work += (double)np * o->n;
    double in = 0.0;
    for (int p = 0; p < np; p++) {
        const double lo = U * p / np, hi = U * (p + 1) / np;
        double piece = 0.0;
        for (int i = 0; i < o->n; i++) {
            const double u = lo + (hi - lo) * o->x[i], e = exp(u);
            piece += o->wt[i] * 0.5 * (e + 1.0 / e) * elem_off(q, cb, sb, sg * scale * 0.5 * (e - 1.0 / e));
        }
        in += (hi - lo) * piece;
    }
    return sum + scale * in;
}

/* The least of the samples e[0, stride, ...] is under half its neighbours: a dip narrower than
 * their spacing, which the trapezoidal rule would take many levels to resolve. */
static int narrow(const double *e, int per, int stride)
{
    int at = 0;
    for (int i = stride; i < per; i += stride)
        if (e[i] < e[at])
            at = i;
    return 2.0 * e[at] < e[(at + per - stride) % per] && 2.0 * e[at] < e[(at + stride) % per];
}

/*
 * The mean of |x_t x x_w| over a period: the trapezoidal rule on N0, 2 N0, ... NT points of 2 pi
 * (half as many over pi) until two levels agree. Where they never do, the element dips towards 0
 * within the period (a rounded fold, or a section that degenerates to a segment): the period is cut at
 * every least value of the element (minima), and each piece between two cuts integrated
 * graded towards both (toward); so too at once where the first samples dip below DEEP of their
 * largest. *dip: the least sample over the largest.
 */
/* |z|^2, |z| without hypot's care for overflow (the coefficients are O(1)) */
static double norm2(double complex z)
{
    return creal(z) * creal(z) + cimag(z) * cimag(z);
}

static double mag(double complex z)
{
    return sqrt(norm2(z));
}

/* The principal square root, without cancellation (libm's csqrt takes care of infinities too, at 5 times the cost) */
static double complex root2(double complex w)
{
    const double x = creal(w), y = cimag(w), r = sqrt(x * x + y * y);
    if (r == 0.0)
        return 0.0;
    if (x >= 0.0) {
        const double sr = sqrt(0.5 * (r + x));
        return sr + I * (0.5 * y / sr);
    }
    const double si = copysign(sqrt(0.5 * (r - x)), y);
    return 0.5 * y / si + I * si;
}

/* The roots of y^2 + B y + C into y[0], y[1], the larger first (no cancellation). */
static void quad_roots(double complex B, double complex C, double complex *y)
{
    const double complex d = root2(B * B - 4.0 * C), t = mag(-B - d) >= mag(-B + d) ? -B - d : -B + d;
    y[0] = 0.5 * t;
    y[1] = y[0] != 0.0 ? C / y[0] : 0.0;
}

/* The roots of z^4 + b z^3 + c z^2 + d z + e into r: Ferrari's (the resolvent cubic's largest root by
 * Cardano), unpolished. */
static void quartic_roots(double complex b, double complex c, double complex d, double complex e, double complex *r)
{
    const double complex b2 = b * b, p = c - 0.375 * b2, q = d - 0.5 * b * c + 0.125 * b2 * b,
                         s = e - 0.25 * b * d + b2 * c / 16.0 - 3.0 * b2 * b2 / 256.0;
    /* m^3 + p m^2 + (p^2 / 4 - s) m - q^2 / 8 = 0, as t^3 + P t + Q = 0 with m = t - p / 3 */
    const double complex B = 0.25 * p * p - s, P = B - p * p / 3.0, Q = 2.0 * p * p * p / 27.0 - p * B / 3.0 - 0.125 * q * q,
                         D = root2(0.25 * Q * Q + P * P * P / 27.0);
    const double complex u3 = mag(-0.5 * Q - D) > mag(-0.5 * Q + D) ? -0.5 * Q - D : -0.5 * Q + D;
    double complex m = -p / 3.0;
    if (u3 != 0.0) {
        const double complex w = -0.5 + 0.5 * sqrt(3.0) * I;
        const double ang = carg(u3) / 3.0;
        double complex u = cbrt(mag(u3)) * (cos(ang) + I * sin(ang));
        m = 0.0;
        for (int k = 0; k < 3; k++, u *= w) {
            const double complex mk = u - P / (3.0 * u) - p / 3.0;
            if (mag(mk) > mag(m))
                m = mk;
        }
    }
    double complex y[4];
    if (m == 0.0) {   /* q = 0: y^4 + p y^2 + s */
        quad_roots(p, s, y);
        y[2] = -(y[0] = root2(y[0])), y[3] = -(y[1] = root2(y[1]));
    } else {
        const double complex sq = root2(2.0 * m);
        quad_roots(-sq, 0.5 * p + m + q / (2.0 * sq), y);
        quad_roots(sq, 0.5 * p + m - q / (2.0 * sq), y + 2);
    }
    for (int k = 0; k < 4; k++)
        r[k] = y[k] - 0.25 * b;
}

/* A root z of z^4 + b z^3 + c z^2 + d z + e polished by Newton while that lowers |f| (a root of a pair
 * about to coincide comes out to their separation's share of the rounding, all the factors need);
 * *settled (where not NULL) set where it stopped there (f = 0, or a step that did not lower it), so
 * that polishing the root again would change nothing, clear where it stopped after 4 steps. */
static double complex polish(double complex b, double complex c, double complex d, double complex e, double complex z,
                             int *settled)
{
    double complex f = (((z + b) * z + c) * z + d) * z + e;
    int it = 0;
    for (; it < 4 && f != 0.0; it++) {
        const double complex fp = ((4.0 * z + 3.0 * b) * z + 2.0 * c) * z + d, nz = z - f / fp,
                             nf = (((nz + b) * nz + c) * nz + d) * nz + e;
        if (!(norm2(nf) < norm2(f)))
            break;
        z = nz, f = nf;
    }
    if (settled)
        *settled = it < 4 || f == 0.0;
    return z;
}

/*
 * Two roots of z^4 + b z^3 + c z^2 + d z + e, not a root's mirror 1 / conj(z), into r[0], r[1], from
 * start[1] (the last section's root nearest the circle) by Newton, the other pair by deflation:
 * returns 0 where Newton does not converge in a few steps (Ferrari's formulas then). r[0] is polished,
 * *settled as polish's.
 */
static int deflated(double complex b, double complex c, double complex d, double complex e, const double complex *start,
                    double complex *r, int *settled)
{
    double complex z = start[1];
    for (int it = 0;; it++) {
        const double complex f = (((z + b) * z + c) * z + d) * z + e, fp = ((4.0 * z + 3.0 * b) * z + 2.0 * c) * z + d;
        if (it == 12 || fp == 0.0)
            return 0;
        const double complex dz = f / fp;
        z -= dz;
        if (!(norm2(dz) > 1e-24 * norm2(z)))
            break;
    }
    z = polish(b, c, d, e, z, settled);
    /* z^4 + ... = (z^2 - sum z + prod) (z^2 + B z + C), sum and prod of z and 1 / conj(z) */
    const double complex zm = 1.0 / conj(z), sum = z + zm, prod = z * zm, B = b + sum, C = c + sum * B - prod;
    double complex y[2];
    quad_roots(B, C, y);
    r[0] = z, r[1] = norm2(y[0]) < norm2(y[1]) ? y[0] : y[1];
    return 1;
}

/* Two doubles, one per lane of the cut's rule (even_mean): its points two at a time, each lane's
 * operations those of one point alone (the same roundings) */
typedef double v2d __attribute__((vector_size(16)));
typedef long long v2i __attribute__((vector_size(16)));

static inline v2d v2_sqrt(v2d x)
{
#ifdef __SSE2__
    return _mm_sqrt_pd(x);
#else
    return (v2d){ sqrt(x[0]), sqrt(x[1]) };
#endif
}

/* m ? a : b lane by lane, m a comparison's lanes (all bits set or none) */
static inline v2d v2_select(v2i m, v2d a, v2d b)
{
    return (v2d)(((v2i)a & m) | ((v2i)b & ~m));
}

/* The cut from z1 to z2 (even_mean): z = M + H cos alpha, w = (e1 + g1 (1 - cos alpha)) (e2 + g2 (1 + cos
 * alpha)), each number in both lanes */
typedef struct {
    v2d Mr, Mi, Hr, Hi, g1r, g1i, g2r, g2i, e1, e2;
} ev_cut;

/*
 * At the points p and p + 1 of the rule's table tab (evt's, a lane each): the rule's weight over
 * sqrt(w), its real and imaginary parts, into v[0], v[1], times z into v[2], v[3] and times z^2 into
 * v[4], v[5]. 1 / sqrt(w) = conj(sqrt(w)) / |w|, sqrt(w) without cancellation: with s = sqrt((|w| +
 * |x|) / 2), sqrt(w) = s + i y / 2s where x = Re w >= 0, else y / 2s' + i s', s' = s with y's sign.
 */
static inline void ev_pair(const ev_cut *c, const double (*tab)[EV_N + 2], int p, v2d v[6])
{
    v2d c0, wt, om, op;
    memcpy(&c0, &tab[0][p], sizeof c0), memcpy(&wt, &tab[1][p], sizeof wt);
    memcpy(&om, &tab[2][p], sizeof om), memcpy(&op, &tab[3][p], sizeof op);
    const v2d sgn = { -0.0, -0.0 }, half = { 0.5, 0.5 };   /* sgn: the sign bits */
    const v2d zr = c->Mr + c->Hr * c0, zi = c->Mi + c->Hi * c0;
    const v2d f1r = c->e1 + c->g1r * om, f1i = c->g1i * om, f2r = c->e2 + c->g2r * op, f2i = c->g2i * op;
    const v2d x = f1r * f2r - f1i * f2i, y = f1r * f2i + f1i * f2r, rw = v2_sqrt(x * x + y * y);
    const v2d ax = (v2d)((v2i)x & ~(v2i)sgn), s = v2_sqrt(half * (rw + ax));
    const v2i pos = x >= (v2d){ 0.0, 0.0 };
    const v2d den = v2_select(pos, s, (v2d)(((v2i)s & ~(v2i)sgn) | ((v2i)y & (v2i)sgn))), q = half * y / den;
    const v2d a = v2_select(pos, s, q), b = v2_select(pos, q, den);
    const v2d g = wt / rw, ur = a * g, ui = -b * g, vr = ur * zr - ui * zi, vi = ur * zi + ui * zr;
    v[0] = ur, v[1] = ui, v[2] = vr, v[3] = vi, v[4] = vr * zr - vi * zi, v[5] = vr * zi + vi * zr;
}

/*
 * The mean over theta of the element where its square has no odd harmonics (so in phi = 2 theta, the
 * sections of fig. 2 and 4: D' normal to A, B and their derivatives), without sampling the dips:
 *
 *     P(phi) = p0 + c1 z + conj(c1 z) + c2 z^2 + conj(c2 z^2),    z = e^(i phi),
 *
 * and the mean of sqrt(P) is that of P / sqrt(P), p0 m0 + 2 Re(c1 m1 + c2 m2) with m_j the mean of
 * z^j / sqrt(P) = (1 / 2 pi i) times the integral of z^j dz / sqrt(Q(z)) round the circle, Q = z^2 P a
 * quartic whose roots pair as zeta, 1 / conj(zeta): the two inside, z1 and z2, joined by a cut, to
 * which the contour shrinks (no pole inside for j >= 0). On the cut, z = M + H cos alpha (M, H their
 * mid-point and half-difference), the roots' square roots cancel dz's, and
 *
 *     m_j = +-(1 / pi) int_0^pi z^j dalpha / sqrt(C0 (1 - z conj(z1)) (1 - z conj(z2))),   C0 = c2 / conj(z1 z2),
 *
 * analytic but where z meets the outside roots, near the ends when a dip is deep (a root near the
 * circle: alpha about 2i sqrt of its distance); alpha = beta - sin(2 beta) / 2 (alpha near beta^3 at
 * the ends) takes that to about its cube root, and the trapezoidal rule in beta, the integrand even
 * and periodic, converges geometrically: EV_N0, 2 EV_N0, ... points until two levels agree. The sign
 * is m0's: positive. Returns 0 (the sampled path then) where c2 is small (a root near 0 or infinity),
 * a root lies on the circle (the element meets 0), the roots do not reproduce P to
 * EV_GUARD, or the rule did not converge. *dip: the least over the largest of the element.
 */
static int even_mean(const trig4 *q, const double *e, ev_hint *hint, double *mean, double *dip)
{
    const double p0 = q->a[0];
    const double complex c1 = 0.5 * (q->a[2] - I * q->b[2]), c2 = 0.5 * (q->a[4] - I * q->b[4]);
    if (!(mag(c2) > 1e-6 * p0))
        return 0;
    double e2[N0], lo = INFINITY, big = 0.0;
    const int stride = NT / 2 / N0;   /* N0 points over pi */
    for (int i = 0; i < N0; i++) {
        e2[i] = e[stride * i] * e[stride * i];
        lo = e2[i] < lo ? e2[i] : lo;
        big = big > e2[i] ? big : e2[i];
    }
    if (!(lo > 0.0))
        return 0;
    const double complex qb = c1 / c2, qc = p0 / c2, qd = conj(c1) / c2, qe = conj(c2) / c2;
    double complex z1, z2, dc1, dc2;
    double K, dp0, e1, e2_;
    /* From a root of the last section that took this path (Newton a few steps along w, and the other
     * pair by deflation), else by Ferrari's formulas: either way checked by P~ - P */
    for (int warm = hint && hint->ok;; warm = 0) {
        double complex r[4];
        int settled[2] = { 0, 0 };   /* polished already, to no further change */
        if (!(warm && deflated(qb, qc, qd, qe, hint->z, r, &settled[0]))) {
            warm = 0, settled[0] = 0;
            quartic_roots(qb, qc, qd, qe, r);
            for (int i = 1; i < 4; i++)   /* the two inside first */
                for (int j = i; j > 0 && norm2(r[j]) < norm2(r[j - 1]); j--) {
                    const double complex t = r[j];
                    r[j] = r[j - 1], r[j - 1] = t;
                }
        }
        /* the two inside, polished (a root's mirror 1 / conj(z) is one too) */
        for (int k = 0; k < 2; k++)
            if (norm2(r[k] = settled[k] ? r[k] : polish(qb, qc, qd, qe, r[k], NULL)) > 1.0)
                r[k] = 1.0 / conj(r[k]);
        z1 = norm2(r[0]) <= norm2(r[1]) ? r[0] : r[1], z2 = norm2(r[0]) <= norm2(r[1]) ? r[1] : r[0];
        /* The roots' P~ = K |z - z1|^2 |z - z2|^2 (C0 = K): its coefficients, p0 + dp0 and so on; P~ - P
         * is below the sum of their moduli at every phi */
        K = mag(c2) / (mag(z1) * mag(z2));
        e1 = 1.0 - norm2(z1), e2_ = 1.0 - norm2(z2);
        const double A1 = 2.0 - e1, A2 = 2.0 - e2_;
        dp0 = K * (A1 * A2 + 2.0 * creal(conj(z1) * z2)) - p0;
        dc1 = -K * (A1 * conj(z2) + A2 * conj(z1)) - c1, dc2 = K * conj(z1) * conj(z2) - c2;
        if (norm2(z2) < 1.0 && fabs(dp0) + 2.0 * (mag(dc1) + mag(dc2)) <= EV_GUARD * big)
            break;
        if (!warm)
            return 0;
    }
    if (hint)
        hint->z[0] = z1, hint->z[1] = z2, hint->ok = 1;
    /* P's least also where a root is nearest the circle (a narrow dip between the samples), where the
     * roots must reproduce P to 1e-3 (the correction below is of first order) but for P's rounding */
    for (int k = 0; k < 2; k++) {
        const double complex z = k ? z2 : z1, c = z / mag(z);
        const double d1 = mag(c - z1), d2 = mag(c - z2), pk = K * d1 * d1 * d2 * d2,
                     pc = p0 + 2.0 * creal(c1 * c + c2 * c * c);
        if (!(fabs(pc - pk) <= 1e-3 * pk + 1e-14 * big))
            return 0;
        lo = pk < lo ? pk : lo;
    }
    const double complex M = 0.5 * (z1 + z2), H = 0.5 * (z1 - z2);
    /* w = (1 - z conj(z1)) (1 - z conj(z2)), each factor from its end, z = z1 - H (1 - cos alpha) =
     * z2 + H (1 + cos alpha): e_k + ..., no cancellation where it is small (a root near the circle) */
    const double complex g1 = conj(z1) * H, g2 = -conj(z2) * H;
    const double (*tab)[EV_N + 2] = evt[1.0 - mag(z2) < EV_MAP];
    const double Mr = creal(M), Mi = cimag(M), Hr = creal(H), Hi = cimag(H), g1r = creal(g1), g1i = cimag(g1),
                 g2r = creal(g2), g2i = cimag(g2);
    const ev_cut cut = { { Mr, Mr }, { Mi, Mi }, { Hr, Hr }, { Hi, Hi }, { g1r, g1r }, { g1i, g1i }, { g2r, g2r },
                         { g2i, g2i }, { e1, e1 }, { e2_, e2_ } };
    double s0r = 0.0, s0i = 0.0, s1r = 0.0, s1i = 0.0, s2r = 0.0, s2i = 0.0, prev = NAN;
    for (int st = EV_N / EV_N0, p = 0; st >= 1; st /= 2) {
        const int end = EV_N / st + 1;   /* the points up to this level */
        for (; p < end; p += 2) {   /* the level's two at a time (the first's last alone) */
            v2d v[6];
            ev_pair(&cut, tab, p, v);
            for (int l = 0; l < 1 + (p + 1 < end); l++)   /* added in the points' order, as one at a time */
                s0r += v[0][l], s0i += v[1][l], s1r += v[2][l], s1i += v[3][l], s2r += v[4][l], s2i += v[5][l];
        }
        p = end;
        const double complex S[3] = { s0r + I * s0i, s1r + I * s1i, s2r + I * s2i };
        const double f = 1.0 / ((double)(EV_N / st) * sqrt(K)), sg = s0r > 0.0 ? f : -f;
        const double complex m0 = sg * S[0], m1 = sg * S[1], m2 = sg * S[2];
        /* mean sqrt(P) = mean sqrt(P~) + mean (P - P~) / (2 sqrt(P~)) to first order in P - P~, the roots'
         * error (1e-10 of P where a pair of them nearly coincides, their mean place; P's own rounding
         * near them): mean P / sqrt(P~) less half of mean (P - P~) / sqrt(P~) */
        const double cur = p0 * creal(m0) + 2.0 * creal(c1 * m1 + c2 * m2) +
                           0.5 * (dp0 * creal(m0) + 2.0 * creal(dc1 * m1 + dc2 * m2));
        if (fabs(cur - prev) <= TRAP_TOL * cur) {
            if (!(fabs(cimag(m0)) <= 1e-10 * fabs(creal(m0))))
                return 0;
            *mean = cur;
            *dip = sqrt(lo / big);
            return 1;
        }
        prev = cur;
    }
    return 0;
}

/* The element at theta_i, i = from, from + step, ... below per, into e[i], added to *sum in that order;
 * *lo, *big the least and largest so far. Without odd harmonics two at a time (a lane each, q_at's
 * operations: the same roundings). */
static void samples(const trig4 *q, double *e, int from, int step, int per, double *sum, double *lo, double *big)
{
    int i = from;
    double sm = *sum, l = *lo, bg = *big;   /* kept apart from e[] */
    if (!q->odd) {
        const v2d a0 = { q->a[0], q->a[0] }, a2 = { q->a[2], q->a[2] }, b2 = { q->b[2], q->b[2] },
                  a4 = { q->a[4], q->a[4] }, b4 = { q->b[4], q->b[4] }, zero = { 0.0, 0.0 };
        for (int at = from ? per / step : 0; i + step < per; i += 2 * step, at += 2) {   /* etrig's place of i */
            v2d c2, s2, c4, s4;
            memcpy(&c2, &etrig[0][at], sizeof c2), memcpy(&s2, &etrig[1][at], sizeof s2);
            memcpy(&c4, &etrig[2][at], sizeof c4), memcpy(&s4, &etrig[3][at], sizeof s4);
            const v2d p = a0 + (a2 * c2 + b2 * s2) + (a4 * c4 + b4 * s4), r = v2_select(p > zero, v2_sqrt(p), zero);
            e[i] = r[0], e[i + step] = r[1];
            for (int k = 0; k < 2; k++)
                sm += r[k], l = r[k] < l ? r[k] : l, bg = r[k] > bg ? r[k] : bg;
        }
    }
    for (; i < per; i += step) {
        const double p = q_at(q, trig[i]);
        sm += e[i] = p > 0.0 ? sqrt(p) : 0.0;
        l = e[i] < l ? e[i] : l, bg = e[i] > bg ? e[i] : bg;
    }
    *sum = sm, *lo = l, *big = bg;
}

static double elem_mean(const harm_opts *o, const trig4 *q, ev_hint *hint, double *dip, double *work)
{
    double ev = 0.0;
    const int per = q->odd ? NT : NT / 2;
    double e[NT], sum = 0.0, mean, lo = INFINITY, big = 0.0;
    int stride = NT / N0;
    samples(q, e, 0, stride, per, &sum, &lo, &big);
    mean = sum * stride / per;
    *dip = big > 0.0 ? lo / big : 1.0;
    int tried = 0;   /* even_mean failed on these samples (it would again: it reads only them) */
    while (stride > 1 && !(stride <= NT / 64 && *dip < DEEP && narrow(e, per, stride))) {
        const int half = stride / 2;
        samples(q, e, half, stride, per, &sum, &lo, &big);
        stride = half;
        const double next = sum * stride / per;
        *dip = big > 0.0 ? lo / big : 1.0;
        /* a dip at N0 points over pi stays one at every finer level (lo only falls, big only rises), so
         * every way out below ends in even_mean on these same N0 samples: take it now, not after the
         * finer levels (the same value; fig. 4a: a third of its sections) */
        if (!q->odd && stride == NT / 2 / N0 && *dip < DEEP) {
            if (even_mean(q, e, hint, &ev, dip))
                return ev;
            tried = 1;
        }
        /* two levels agree; but where the samples dip deep, maybe by chance (the k = 4 stress model's
         * face, at some w: 4.6e-8 off), so even_mean there where it can */
        if (fabs(next - mean) <= TRAP_TOL * next)
            return q->odd || tried || !(*dip < DEEP) || !even_mean(q, e, hint, &ev, dip) ? next : ev;
        /* slow to converge: a dip, which even_mean takes at a fixed cost */
        if (!q->odd && !tried && stride <= NT / 2 / N0 && fabs(next - mean) > EV_SWITCH * next) {
            if (even_mean(q, e, hint, &ev, dip))
                return ev;
            tried = 1;
        }
        mean = next;
    }
    if (!q->odd && !tried && stride <= NT / 2 / N0 && even_mean(q, e, hint, &ev, dip))
        return ev;
    const double period = per * (2.0 * M_PI / NT);
    /* the cuts: every least value of the element, isolated by bounds (minima), not at the least
     * samples, which took two narrow dips between two samples for one (2.5e-6 of the mean off) */
    double cut[CRIT_MAX], scale[CRIT_MAX], L[TAYLOR + 2] = { 0.0 }, d2;
    int ncut = 0, left = CRIT_WORK;
    for (int j = 1; j <= 4; j++) {
        const double amp = hypot(q->a[j], q->b[j]);
        for (int k = 0, jk = 1; k <= TAYLOR + 1; k++, jk *= j)
            L[k] += jk * amp;
    }
    /* q' at 16 ends, its value at 0 also at the period's end: a least value at a shared end then goes to
     * exactly one side (q' < 0 on the left, >= 0 on the right) */
    double d1[17];
    for (int p = 0; p < 16; p++)
        d1[p] = dq(q, period * p / 16, &d2);
    d1[16] = d1[0];
    for (int p = 0; p < 16; p++)
        if (!minima(q, period * p / 16, period * (p + 1) / 16, d1[p], d1[p + 1], L, 0, cut, &ncut, &left))
            return NAN;   /* harm_face then declines the face (at_w's NaN): the general path's panels */
    *work += CRIT_WORK - left;
    for (int j = 0; j < ncut; j++) {
        double m;
        dq(q, cut[j], &d2);
        elem_fn((void *)q, cut[j], &m);
        scale[j] = d2 > 0.0 ? m / sqrt(0.5 * d2) : 0.0;
    }
    if (!ncut)
        cut[ncut] = 0.0, scale[ncut++] = period;
    double total = 0.0;
    for (int j = 0; j < ncut; j++) {
        const int k = (j + 1) % ncut;
        const double a = cut[j], b = j + 1 < ncut ? cut[j + 1] : cut[0] + period, mid = 0.5 * (a + b);
        if (b > a)
            total += (scale[j] > 0.0 ? toward_sinh : toward)(o, q, mid, a, scale[j], work) +
                     (scale[k] > 0.0 ? toward_sinh : toward)(o, q, mid, b, scale[k], work);
    }
    return total / period;
}

static void cross(const double a[3], const double b[3], double s, double *out)
{
    out[0] = s * (a[1] * b[2] - a[2] * b[1]);
    out[1] = s * (a[2] * b[0] - a[0] * b[2]);
    out[2] = s * (a[0] * b[1] - a[1] * b[0]);
}

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* |x_t x x_w|^2's coefficients into q from x_t x x_w's, q->v */
static void square(trig4 *q)
{
    const double (*v)[3] = (const double (*)[3])q->v;
    double g[5][5];
    for (int i = 0; i < 5; i++)
        for (int j = i; j < 5; j++)
            g[i][j] = dot(v[i], v[j]);
    const double a[5] = { g[0][0] + 0.5 * (g[1][1] + g[2][2] + g[3][3] + g[4][4]), 2.0 * g[0][1] + g[1][3] + g[2][4],
                          2.0 * g[0][3] + 0.5 * (g[1][1] - g[2][2]), g[1][3] - g[2][4], 0.5 * (g[3][3] - g[4][4]) };
    const double b[5] = { 0.0, 2.0 * g[0][2] + g[1][4] - g[2][3], 2.0 * g[0][4] + g[1][2], g[1][4] + g[2][3], g[3][4] };
    memcpy(q->a, a, sizeof a), memcpy(q->b, b, sizeof b);
    /* Odd harmonics come from D' alone (c1, s1); below rounding, the period is pi. */
    q->odd = !(fabs(a[1]) + fabs(b[1]) + fabs(a[3]) + fabs(b[3]) <= 1e-15 * a[0]);
    if (!q->odd)
        q->a[1] = q->b[1] = q->a[3] = q->b[3] = 0.0;
}

/* The section at w: x_t x x_w's coefficients and its square's into q; the flux's mean over theta,
 * returned. */
static double section(harm_ctx *H, double w, trig4 *q)
{
    double x[9] = { 0 }, d[9] = { 0 };   /* A, B, D and their w-derivatives, component c of part p at 3 p + c */
    wtable_eval(H->tab, w, H->h, H->dh);
    for (size_t m = 0; m < H->nm; m++)
        x[H->slot[m]] += H->wt[m] * H->h[H->map[m]], d[H->slot[m]] += H->wt[m] * H->dh[H->map[m]];
    H->nodes++;
    const double *A = x, *B = x + 3, *D = x + 6, *Ap = d, *Bp = d + 3, *Dp = d + 6, s = 0.5 * H->kpi;
    double (*v)[3] = q->v, t[3];
    cross(A, Bp, s, v[0]), cross(Ap, B, s, t);
    for (int c = 0; c < 3; c++)
        v[3][c] = v[0][c] - t[c], v[0][c] += t[c];
    cross(A, Dp, H->kpi, v[1]), cross(Dp, B, H->kpi, v[2]);
    cross(A, Ap, s, v[4]), cross(B, Bp, s, t);
    for (int c = 0; c < 3; c++)
        v[4][c] -= t[c];
    square(q);
    return dot(D, v[0]) + 0.5 * (dot(A, v[2]) + dot(B, v[1]));
}

double harm_mean(const double v[5][3], const double *x, const double *wt, int n)
{
    const harm_opts o = { .x = x, .wt = wt, .n = n };
    trig4 q;
    double dip, work = 0.0;
    memcpy(q.v, v, sizeof q.v);
    square(&q);
    pthread_once(&trig_once, trig_init);
    return elem_mean(&o, &q, NULL, &dip, &work);
}

/* At w: val[0] the element's mean over theta, val[1] the flux's; the least of the element over its
 * largest kept in H->dip, where it is at in H->dip_at. */
static void many_at_w(void *arg, double w, double *val);

static void at_w(void *arg, double w, double *val)
{
    harm_ctx *H = arg;
    trig4 q;
    double dip;
    val[1] = section(H, w, &q);
    val[0] = elem_mean(H->o, &q, &H->roots, &dip, &H->work);
    if (dip < H->dip)
        H->dip = dip, H->dip_at = w;
}

/* The element's least over theta at w, located (least) from a coarse sample: what a degenerate
 * section or a rounded fold along w makes small. */
static double least_at(harm_ctx *H, double w)
{
    trig4 q;
    section(H, w, &q);
    const int per = q.odd ? NT : NT / 2, stride = NT / N0;
    int at = 0;
    double lo = INFINITY, d2, m;
    for (int i = 0; i < per; i += stride) {
        const double e = q_at(&q, trig[i]);
        if (e < lo)
            lo = e, at = i;
    }
    const double dt = 2.0 * M_PI / NT;
    elem_fn(&q, least(&q, (at - stride) * dt, (at + stride) * dt, &d2), &m);
    return m;
}

/*
 * Where the element's least over theta is least in [a, b], by Brent's minimisation (golden section and
 * parabolas) of its square: about g^2 (w - w0)^2 + m0^2 there, a parabola where the least itself has a
 * kink (a section that degenerates), so the parabolas land on w0 in a few steps where golden section
 * took 34 (fig. 2c: 324 points of w for 9 cuts). To DIP_EPS of the interval, or a few ulps of w where
 * the interval is too short for that (nested pieces of a dip: below about 1e-9 it never ended), and
 * in at most DIP_STEPS steps; ended once every point left is below lo or above hi, where the caller's
 * snapping takes it to the panel's end (a cut made before: golden section took 20 steps more).
 */
#define DIP_STEPS 48
struct dip_ctx {
    harm_ctx *H;
    double lo, hi;
};

static double least_sq(void *arg, double w)
{
    const double m = least_at(((struct dip_ctx *)arg)->H, w);
    return m * m;
}

static int dip_outside(void *arg, double a, double b, double x, double fx)
{
    const struct dip_ctx *c = arg;
    (void)x, (void)fx;
    return b <= c->lo || a >= c->hi;
}

static double dip_place(harm_ctx *H, double a, double b, double lo, double hi)
{
    struct dip_ctx c = { H, lo, hi };
    const brent_fn fn = { least_sq, dip_outside, &c };
    const double x = a + 0.5 * (3.0 - sqrt(5.0)) * (b - a), tol = 0.25 * DIP_EPS * (b - a);
    double fx;
    return brent_min(&fn, a, b, x, least_sq(&c, x), tol, DIP_STEPS, &fx);
}

/*
 * Along w, each panel's 10-point Gauss rule, then its 21-point Kronrod extension (QUADPACK's qk21 on
 * [-1, 1]: xgk[1], xgk[3], ... the Gauss rule's nodes, wg its weights): 11 points more where halving
 * took 20, the Gauss points kept for it (wpanel). Where the two differ, Patterson's 43-point extension
 * of the Kronrod rule (22 points more, xp; wpk its weights at the Kronrod rule's points in xgk's order,
 * wpn at xp; exact for degree 65, computed anew to 60 digits: the Stieltjes polynomials of P_10 and of
 * the Kronrod rule's nodes), kept where it agrees with the Kronrod rule to HALVES_AGREE of the
 * tolerance; else the halves' Gauss rules, the children's own, which keep it where they agree with it
 * as closely. A face of many harmonics (a loft's) against its halves still (outer).
 */
static const double xgk[11] = { 0.995657163025808080735527280689003, 0.973906528517171720077964012084452,
                                0.930157491355708226001207180059508, 0.865063366688984510732096688423493,
                                0.780817726586416897063717578345042, 0.679409568299024406234327365114874,
                                0.562757134668604683339000099272694, 0.433395394129247190799265943165784,
                                0.294392862701460198131126603103866, 0.148874338981631210884826001129720, 0.0 };
static const double wgk[11] = { 0.011694638867371874278064396062192, 0.032558162307964727478818972459390,
                                0.054755896574351996031381300244580, 0.075039674810919952767043140916190,
                                0.093125454583697605535065465083366, 0.109387158802297641899210590325805,
                                0.123491976262065851077958109831074, 0.134709217311473325928054001771707,
                                0.142775938577060080797094273138717, 0.147739104901338491374841515972068,
                                0.149445554002916905664936468389821 };
static const double wg[5] = { 0.066671344308688137593568809893332, 0.149451349150580593145776339657697,
                              0.219086362515982043995534934228163, 0.269266719309996355091226921569469,
                              0.295524224714752870173892994651338 };

static const double xp[11] = { 0.999333360901932081394099323919911, 0.987433402908088869795961478381209,
                               0.954807934814266299257919200290473, 0.900148695748328293625099494069092,
                               0.825198314983114150847066732588520, 0.732148388989304982612354848755461,
                               0.622847970537725238641159120344323, 0.499479574071056499952214885499755,
                               0.364901661346580768043989548502644, 0.222254919776601296498260928066212,
                               0.0746506174613833220439144357965059 };
static const double wpk[11] = { 0.00576855605976979618418432790865461, 0.0162967342896665649242819746176625,
                                0.0273718905932488420812760692891511, 0.0375228761208695014616137958981146,
                                0.0465608269104288307433391544338236, 0.0546949020582554421472126854650048,
                                0.0617449952014425644962403360308832, 0.0673554146094780860755531663021745,
                                0.0713872672686933977685591144255160, 0.0738701996323939534321406952513671,
                                0.0747221475174030055944251682804227 };
static const double wpn[11] = { 0.00184447764021241410038910655296516, 0.0107986895858916517404654067412932,
                                0.0218953638677954281025231230751493, 0.0325974639753456894438822225261371,
                                0.0421631379351918118476279243279552, 0.0507419396001845777801890200920840,
                                0.0583793955426192483754753693302063, 0.0647464049514458855446892595175109,
                                0.0695661979123564845286333150384049, 0.0728244414718332081509395351928418,
                                0.0745077510141751182735718138428888 };

typedef struct {
    double sum[2];       /* the Gauss rule's, area and flux */
    double f[5][2][2];   /* its values at c -+ h xgk[2 i + 1]: [i][side][area, flux] */
} wpanel;

/* The means at w (one harmonic's, or many's), each fn a constant for the compiler */
static void at_w(void *arg, double w, double *val);
static void mean_w(harm_ctx *H, double w, double *val)
{
    if (H->many)
        many_at_w(H, w, val);
    else
        at_w(H, w, val);
}

/* A side of a cut in s (outer_toward): w = c + d s^2 */
typedef struct {
    double c, d;
} wmap;

/* The means at x, w = x where sq is NULL, else w = sq's map of x and the means times dw/dx */
static void mean_at(harm_ctx *H, const wmap *sq, double x, double *val)
{
    if (!sq) {
        mean_w(H, x, val);
        return;
    }
    mean_w(H, sq->c + sq->d * x * x, val);
    for (int k = 0; k < 2; k++)
        val[k] *= 2.0 * fabs(sq->d) * x;
}

/* The Gauss rule over [a, b] (of w, or of s where sq is not NULL) into p. The rules take their points in
 * order along w, the Kronrod rule's back from where the Gauss rule's ended, and add them in their own
 * order: even_mean starts from the last section's roots, now the nearest (fig. 4a 1.610 -> 1.586 M
 * instructions, 4s 4.079 -> 4.007 M; areas within 2e-16). */
static void rule_w(harm_ctx *H, const wmap *sq, double a, double b, wpanel *p)
{
    const double c = 0.5 * (a + b), h = 0.5 * (b - a);
    p->sum[0] = p->sum[1] = 0.0;
    for (int j = 0; j < 10; j++) {   /* ascending */
        const int sd = j >= 5, i = sd ? 9 - j : j;
        mean_at(H, sq, c + (sd ? h : -h) * xgk[2 * i + 1], p->f[i][sd]);
    }
    for (int i = 0; i < 5; i++)
        for (int sd = 0; sd < 2; sd++)
            for (int k = 0; k < 2; k++)
                p->sum[k] += wg[i] * p->f[i][sd][k];
    for (int k = 0; k < 2; k++)
        p->sum[k] *= h;
}

/* The Kronrod rule over [a, b], whose Gauss rule is p, into K; its values at c -+ h xgk[2 i] into
 * kv[2 i + side], at c into kv[10] */
static void kronrod_w(harm_ctx *H, const wmap *sq, double a, double b, const wpanel *p, double kv[11][2], double *K)
{
    const double c = 0.5 * (a + b), h = 0.5 * (b - a);
    for (int j = 10; j >= 0; j--) {   /* descending, from where the Gauss rule ended */
        const int sd = j > 5, i = sd ? 10 - j : j;
        if (j == 5)
            mean_at(H, sq, c, kv[10]);
        else
            mean_at(H, sq, c + (sd ? h : -h) * xgk[2 * i], kv[2 * i + sd]);
    }
    for (int k = 0; k < 2; k++)
        K[k] = wgk[10] * kv[10][k];
    for (int i = 0; i < 5; i++)
        for (int sd = 0; sd < 2; sd++)
            for (int k = 0; k < 2; k++)
                K[k] += wgk[2 * i] * kv[2 * i + sd][k] + wgk[2 * i + 1] * p->f[i][sd][k];
    for (int k = 0; k < 2; k++)
        K[k] *= h;
}

/* Patterson's rule over [a, b], whose Gauss rule is p and Kronrod rule's values kv, into P */
static void patterson_w(harm_ctx *H, const wmap *sq, double a, double b, const wpanel *p, double kv[11][2], double *P)
{
    const double c = 0.5 * (a + b), h = 0.5 * (b - a);
    for (int k = 0; k < 2; k++)
        P[k] = wpk[10] * kv[10][k];
    for (int i = 0; i < 5; i++)   /* the Kronrod rule's points */
        for (int sd = 0; sd < 2; sd++)
            for (int k = 0; k < 2; k++)
                P[k] += wpk[2 * i] * kv[2 * i + sd][k] + wpk[2 * i + 1] * p->f[i][sd][k];
    double pv[11][2][2];
    for (int j = 0; j < 22; j++) {   /* its own, ascending */
        const int sd = j >= 11, i = sd ? 21 - j : j;
        mean_at(H, sq, c + (sd ? h : -h) * xp[i], pv[i][sd]);
    }
    for (int i = 0; i < 11; i++)
        for (int sd = 0; sd < 2; sd++)
            for (int k = 0; k < 2; k++)
                P[k] += wpn[i] * pv[i][sd][k];
    for (int k = 0; k < 2; k++)
        P[k] *= h;
}

/* X and Y (area, flux) over a length len agree to f of the tolerances per unit length, or of NOISE of X */
static int agree(const harm_ctx *H, const double *X, const double *Y, double len, double f)
{
    int ok = 1;
    for (int k = 0; k < 2; k++)
        ok &= fabs(X[k] - Y[k]) <= f * fmax(H->tol[k] * len, NOISE * fabs(X[k]));
    return ok;
}

/*
 * The Kronrod rule K over [a, b] (Gauss rule p, its own values kv) trusted without Patterson's: its
 * error from the Gauss rule's, |K - G|, as QUADPACK's qk21 takes it, R (|K - G| / R)^1.5 with R the
 * rule's integral of |f - K / (b - a)| (without qk21's factor 200), within HALVES_AGREE of the
 * tolerance, as Patterson's agreement with K is asked; a tenth of that where the Kronrod points dip
 * below DIP (near a degenerate section the mean's singularity slows the rules below the geometric rate
 * the power assumes). On the 39 presets' 63 panels where Patterson's rule was taken, it passed on 28
 * (fig. 4a 2 of 3, 4i 1 of 4, 4u 2 of 2), where |P - K| was at most 0.68 of it without a dip (17
 * times at rounding: fig. 4w, 1e-13), 2 times with one (fig. 4s, 4.5e-4 of the tolerance; fig. 4b's
 * 2.2 times, 8e-3 of it, is refused), and 2e-3 of the tolerance at most. The sides of a cut
 * (outer_toward) keep Patterson's: their s^5 log s converges algebraically, and the estimate passed
 * there with K 0.15 of the tolerance off (fig. 4t).
 */
static int kronrod_trusted(const harm_ctx *H, double a, double b, const wpanel *p, const double kv[11][2],
                           const double *K)
{
    const double h = 0.5 * (b - a), f = H->dip < DIP ? 0.1 * HALVES_AGREE : HALVES_AGREE;
    int ok = 1;
    for (int k = 0; k < 2; k++) {
        const double mean = K[k] / (b - a), d = fabs(K[k] - p->sum[k]);
        double r = wgk[10] * fabs(kv[10][k] - mean);
        for (int i = 0; i < 5; i++)
            for (int sd = 0; sd < 2; sd++)
                r += wgk[2 * i] * fabs(kv[2 * i + sd][k] - mean) + wgk[2 * i + 1] * fabs(p->f[i][sd][k] - mean);
        r *= h;
        const double est = d < r ? r * pow(d / r, 1.5) : d;
        ok &= est <= f * fmax(H->tol[k] * (b - a), NOISE * fabs(K[k]));
    }
    return ok;
}

static int outer(harm_ctx *H, double a, double b, const wpanel *coarse, int depth, int split, double *out);

/*
 * [c, c + d] (d < 0: [c + d, c]) from a cut c at a dip of w. Where the section degenerates at c, the
 * element's mean is a(w) + b(w) t^2 log|t| (t = w - c; to a segment) or |t| a(w) (to a point), a and b
 * analytic: w = c + d s^2 takes it to a function of s as smooth as s^5 log s at 0, and one Gauss-Kronrod
 * rule in s takes the whole side (fig. 4a: its 4 sides within 2e-14 of a fine grading, the Gauss rule's
 * error 2.5e-11 to 1e-10 against tolerances 1.3e-10 to 1.6e-10), or its Patterson extension as outer's.
 * Where they fail their tests (the side's far part: the panel's own scale, another dip), the far piece
 * [c + W_GRADE d, c + d] goes to outer (which may halve it, or cut it again) and the rest as the side,
 * W_LEVELS times, then the last to outer.
 */
static int outer_toward(harm_ctx *H, double c, double d, int depth, double *out)
{
    for (int k = 0;; k++, d *= W_GRADE) {
        const wmap sq = { c, d };
        wpanel g;
        double K[2], kv[11][2], P[2];
        const double *best = K;
        rule_w(H, &sq, 0.0, 1.0, &g);
        kronrod_w(H, &sq, 0.0, 1.0, &g, kv, K);
        int ok = agree(H, K, g.sum, fabs(d), 1.0);
        if (!ok && agree(H, K, g.sum, fabs(d), P43_TRY)) {   /* Patterson's rule against K, as outer's */
            patterson_w(H, &sq, 0.0, 1.0, &g, kv, P);
            ok = agree(H, P, K, fabs(d), HALVES_AGREE);
            best = P;
        }
        if (ok) {
            for (int j = 0; j < 2; j++)
                out[j] += best[j];
            return 1;
        }
        const double lo = k < W_LEVELS ? c + W_GRADE * d : c, hi = c + d, a = fmin(lo, hi), b = fmax(lo, hi);
        wpanel coarse;
        rule_w(H, NULL, a, b, &coarse);
        if (!outer(H, a, b, &coarse, depth, 1, out))
            return 0;
        if (k == W_LEVELS)
            return 1;
    }
}

/*
 * [a, b], whose Gauss rule gave coarse, against its Kronrod rule, and where they differ (by more than
 * the tolerances per unit length, or NOISE of the value) halved; but where the element dipped below
 * DIP of its largest at a point of theirs (a section degenerating to a segment, where the element's
 * mean over theta has a singularity (w - w0)^2 log |w - w0|; a rounded fold, smooth on its own small
 * scale), cut at the deepest place w0 (dip_place) and graded towards it from both sides: split 2 (a
 * panel of the plan), also where w0 is at an end (fig. 2c's layer at w = 0), from one side; 1 (a
 * graded piece: fig. 2c's second dip, 0.02 from the first), where w0 is inside; 0 not (halves whose
 * dip is at the cut already made).
 */
static int outer(harm_ctx *H, double a, double b, const wpanel *coarse, int depth, int split, double *out)
{
    const double m = 0.5 * (a + b);
    double K[2], kv[11][2];
    wpanel l, r;
    if (H->nodes >= H->next_poll || H->work >= H->next_poll_work) {   /* a dip's points of w may take a few ms */
        H->next_poll = H->nodes + H->poll_every, H->next_poll_work = H->work + POLL_THETA;
        H->stopped |= pde_stopped(H->o->cancel);
    }
    if (H->stopped || H->nodes > H->max_nodes || H->work > H->max_work || H->fold)
        return 0;   /* the panels then, which bound their work */
    H->dip = INFINITY;
    if (H->many) {   /* a loft's: its halves (the Kronrod rule moved the tower's area by 1.3e-12) */
        rule_w(H, NULL, a, m, &l);
        rule_w(H, NULL, m, b, &r);
        for (int k = 0; k < 2; k++)
            K[k] = l.sum[k] + r.sum[k];
    } else
        kronrod_w(H, NULL, a, b, coarse, kv, K);
    if (isnan(K[0]) || isnan(K[1]))
        return 0;   /* no refinement mends it */
    if (agree(H, K, coarse->sum, b - a, 1.0)) {
        for (int k = 0; k < 2; k++)
            out[k] += K[k];
        return 1;
    }
    if (depth >= DEPTH)
        return 0;
    const int cut = split && H->dip < DIP && H->splits > 0;   /* the Kronrod points' dip */
    double P[2];
    const double *best = K;
    if (!H->many && agree(H, K, coarse->sum, b - a, cut ? P43_CUT : P43_TRY)) {   /* Patterson's rule against K */
        if (kronrod_trusted(H, a, b, coarse, kv, K)) {
            for (int k = 0; k < 2; k++)
                out[k] += K[k];
            return 1;
        }
        patterson_w(H, NULL, a, b, coarse, kv, P);
        best = P;
        if (agree(H, P, K, b - a, HALVES_AGREE)) {
            for (int k = 0; k < 2; k++)
                out[k] += P[k];
            return 1;
        }
    }
    if (cut) {   /* no halves where it is cut */
        H->splits--;
        const double q = 0.125 * (b - a), near = 1e3 * DIP_EPS * (b - a);
        double w0 = dip_place(H, fmax(a, H->dip_at - q), fmin(b, H->dip_at + q), a + near, b - near);
        w0 = w0 <= a + near ? a : w0 >= b - near ? b : w0;
        if (split == 2 || (w0 > a && w0 < b))   /* at an end, graded towards it from one side */
            return (w0 == a || outer_toward(H, w0, a - w0, depth + 1, out)) &&
                   (w0 == b || outer_toward(H, w0, b - w0, depth + 1, out));
        split = 0;   /* the dip is at an end, where a cut was: halves */
    }
    if (!H->many) {   /* the halves' Gauss rules, the children's own, against the best so far */
        rule_w(H, NULL, a, m, &l);
        rule_w(H, NULL, m, b, &r);
        const double LR[2] = { l.sum[0] + r.sum[0], l.sum[1] + r.sum[1] };
        if (agree(H, best, LR, b - a, HALVES_AGREE)) {
            for (int k = 0; k < 2; k++)
                out[k] += best[k];
            return 1;
        }
    }
    return outer(H, a, m, &l, depth + 1, split, out) && outer(H, m, b, &r, depth + 1, split, out);
}

/*
 * Many harmonics (a loft's face u = 1: its profile's Fourier series, k = 1..32). Where every mode's
 * factor along t is 1 or sin, cos of 2 pi j t for whole j, each coordinate is at each w
 *
 *     x_c(theta, w) = D_c(w) + sum_j S_cj(w) sin j theta + C_cj(w) cos j theta,    theta = 2 pi t,
 *
 * and the element |x_t x x_w| = 2 pi |g|, g = x_theta x x_w, is the root of a trigonometric
 * polynomial of degree 4 M (M the largest j), positive where the section is regular: the trapezoidal
 * rule on N = 2^n points of theta converges geometrically, and is exact for the flux x . (x_t x x_w)
 * (degree 3 M) once N > 3 M. So: x_theta and x_w sampled at N0 > 3 M points from the coefficients
 * (a table of 2 pi i / MT), then N doubled until two levels agree to TRAP_TOL. Where they do not by
 * MT, or the samples show a narrow dip (a profile's sharp corner, say an airfoil's trailing edge:
 * blade, 1e-3 of the largest over 1e-3 of the period), the period is cut at its deep least values
 * (located by Newton on |g|^2), and each side of each cut integrated in s = scale sinh u as
 * toward_sinh does, adaptively in u (far from the cut the harmonics, not the dip, set the scale).
 */
#define MT 4096          /* points of theta per 2 pi on the finest level; a power of 2 */
#define MANY_MAX 512     /* harmonics at most (N0 <= MT / 2) */
#define MANY_MIN 4       /* ... and at least: with 2 or 3 (fig. 3, its skin's element dips along curves of
                          * (t, w), where the mean over theta is rough in w) the general path's panels took
                          * 0.3 to 30 times the instructions (fig. 3a 58 M, here 1.8 G) */
#define MANY_DEEP 0.05   /* a narrow dip below this of the largest sample goes to the cuts */
#define MANY_CUT 0.2     /* ... which are at the least samples below this of the largest, */
#define MANY_CUTS 64     /* ... this many at most */
#define MANY_FOLD 1e-6  /* a least value below this of the largest: a fold, which the general path locates
                          * (fig. 3a, 3b, 3d: 3 to 30 times its instructions here) */
#define MANY_TOL 1e-13   /* the cuts' adaptive rule, absolute on the mean over the largest */
#define MANY_DEPTH 24    /* ... and its halvings of a panel of u at most */
#define MANY_NODES 6000  /* points of w in a face, at most (tower 600, blade 900), else the panels */
#define MANY_POLL 32     /* ... between polls of the caller's stop() (up to 100 us each) */

static double mtrig[MT][2];   /* cos, sin of 2 pi i / MT */
static pthread_once_t mtrig_once = PTHREAD_ONCE_INIT;

static void mtrig_init(void)
{
    for (int i = 0; i < MT; i++)
        mtrig[i][0] = cos(2.0 * M_PI * i / MT), mtrig[i][1] = sin(2.0 * M_PI * i / MT);
}

/* The element over 2 pi, |g|, at theta = 2 pi idx / MT; x . g into *flux where flux is not NULL. */
static double many_sample(harm_ctx *H, int idx, double *flux)
{
    H->work += 1.0 + H->nh;   /* a point's cost: its harmonics */
    const double *cf = H->cf;
    double xt[3] = { 0, 0, 0 }, xw[3] = { cf[3], cf[4], cf[5] }, x[3] = { cf[0], cf[1], cf[2] };
    for (int h = 0; h < H->nh; h++) {
        const int j = H->hj[h], k = (int)(((long)idx * j) & (MT - 1));
        const double c = mtrig[k][0], sn = mtrig[k][1], *S = cf + 6 * (1 + 2 * h), *C = S + 6;
        for (int q = 0; q < 3; q++) {
            xt[q] += j * (S[q] * c - C[q] * sn);
            xw[q] += S[3 + q] * sn + C[3 + q] * c;
        }
        if (flux)
            for (int q = 0; q < 3; q++)
                x[q] += S[q] * sn + C[q] * c;
    }
    double g[3];
    cross(xt, xw, 1.0, g);
    if (flux)
        *flux = dot(x, g);
    return sqrt(dot(g, g));
}

/* g = x_theta x x_w at theta, and with nd = 2 its first two derivatives in theta (d[1], d[2]). */
static void many_g(harm_ctx *H, double th, int nd, double d[3][3])
{
    H->work += 1.0 + H->nh;   /* a point's cost: its harmonics */
    const double *cf = H->cf, c1 = cos(th), s1 = sin(th);
    double xt[3][3] = { { 0 } }, xw[3][3] = { { cf[3], cf[4], cf[5] }, { 0 }, { 0 } };   /* [order][comp] */
    double c = 1.0, sn = 0.0;
    for (int h = 0, j = 0; h < H->nh; h++) {
        for (; j < H->hj[h]; j++) {   /* cos, sin of j theta by rotation */
            const double t = c * c1 - sn * s1;
            sn = sn * c1 + c * s1, c = t;
        }
        const double *S = cf + 6 * (1 + 2 * h), *C = S + 6, jj = j, j2 = jj * jj;
        for (int q = 0; q < 3; q++) {
            const double a = S[q] * c - C[q] * sn, b = S[q] * sn + C[q] * c;   /* d/dtheta b = j a, of a = -j b */
            const double aw = S[3 + q] * c - C[3 + q] * sn, bw = S[3 + q] * sn + C[3 + q] * c;
            xt[0][q] += jj * a, xt[1][q] -= j2 * b, xt[2][q] -= j2 * jj * a;
            xw[0][q] += bw, xw[1][q] += jj * aw, xw[2][q] -= j2 * bw;
        }
    }
    double t[3];
    cross(xt[0], xw[0], 1.0, d[0]);
    if (nd < 2)
        return;
    cross(xt[1], xw[0], 1.0, d[1]), cross(xt[0], xw[1], 1.0, t);
    for (int q = 0; q < 3; q++)
        d[1][q] += t[q];
    cross(xt[2], xw[0], 1.0, d[2]), cross(xt[0], xw[2], 1.0, t);
    for (int q = 0; q < 3; q++)
        d[2][q] += t[q];
    cross(xt[1], xw[1], 2.0, t);
    for (int q = 0; q < 3; q++)
        d[2][q] += t[q];
}

/* |g|^2's least in [lo, hi], by Newton on its derivative kept in the bracket (least's); the element's
 * width scale there, |g| / sqrt(|g|^2'' / 2), into *scale. */
static double many_least(harm_ctx *H, double lo, double hi, double *scale)
{
    double x = 0.5 * (lo + hi), d[3][3], f2 = 0.0;
    for (int it = 0; it < 60; it++) {
        many_g(H, x, 2, d);
        const double f1 = 2.0 * dot(d[0], d[1]);
        f2 = 2.0 * (dot(d[1], d[1]) + dot(d[0], d[2]));
        if (f1 < 0.0)
            lo = x;
        else
            hi = x;
        double nx = f2 > 0.0 ? x - f1 / f2 : NAN;
        if (!(nx > lo && nx < hi))
            nx = 0.5 * (lo + hi);
        if (fabs(nx - x) <= 1e-15 * (1.0 + fabs(x))) {
            x = nx;
            break;
        }
        x = nx;
    }
    many_g(H, x, 2, d);
    f2 = 2.0 * (dot(d[1], d[1]) + dot(d[0], d[2]));
    const double m = sqrt(dot(d[0], d[0]));
    *scale = f2 > 0.0 ? m / sqrt(0.5 * f2) : 0.0;
    H->fold |= !(m > MANY_FOLD * H->big);
    return x;
}

typedef struct {
    harm_ctx *H;
    double c, sg, scale, tol;   /* theta = c + sg scale sinh u; tol per unit of u */
} many_half;

static double many_rule(const many_half *f, double lo, double hi)
{
    const harm_opts *o = f->H->o;
    double sum = 0.0, d[3][3];
    for (int i = 0; i < o->n; i++) {
        const double u = lo + (hi - lo) * o->x[i], e = exp(u);
        many_g(f->H, f->c + f->sg * f->scale * 0.5 * (e - 1.0 / e), 1, d);
        sum += o->wt[i] * 0.5 * (e + 1.0 / e) * sqrt(dot(d[0], d[0]));
    }
    return (hi - lo) * f->scale * sum;
}

static double many_adapt(const many_half *f, double lo, double hi, double coarse, int depth)
{
    const double m = 0.5 * (lo + hi), l = many_rule(f, lo, m), r = many_rule(f, m, hi);
    if (!(fabs(l + r - coarse) > f->tol * (hi - lo)) || depth >= MANY_DEPTH || f->H->work > MANY_WORK)
        return l + r;   /* past the work's bound the face goes to the panels (harm_face): no more halving */
    return many_adapt(f, lo, m, l, depth + 1) + many_adapt(f, m, hi, r, depth + 1);
}

/* The integral of |g| over [c, c + sg d], d > 0, graded towards c (a least value, its width scale) */
static double many_toward(harm_ctx *H, double c, double sg, double d, double scale)
{
    scale = fmax(scale, 1e-14);
    const double U = asinh(d / scale);
    const int np = (int)ceil(U / U_WIDTH);
    const many_half f = { H, c, sg, scale, MANY_TOL * H->big / U };
    double sum = 0.0;
    for (int p = 0; p < np; p++) {
        const double lo = U * p / np, hi = U * (p + 1) / np;
        sum += many_adapt(&f, lo, hi, many_rule(&f, lo, hi), 0);
    }
    return sum;
}

/* The mean over t of the element |x_t x x_w| (val[0]) and of the flux (val[1]) at the w of H->cf. */
static void many_mean(harm_ctx *H, double *val)
{
    int n = 32;
    while (n <= 3 * H->hj[H->nh - 1])
        n *= 2;
    int stride = MT / n;
    double *e = H->e, sum = 0.0, fsum = 0.0, lo = INFINITY, big = 0.0, mean;
    for (int i = 0; i < MT; i += stride) {
        double fl;
        sum += e[i] = many_sample(H, i, &fl);
        fsum += fl;
        lo = fmin(lo, e[i]), big = fmax(big, e[i]);
    }
    val[1] = 2.0 * M_PI * fsum / n;
    mean = 2.0 * M_PI * sum / n;
    H->big = big;
    H->dip = fmin(H->dip, big > 0.0 ? lo / big : 1.0);
    while (stride > 1) {
        const int half = stride / 2;
        for (int i = half; i < MT; i += stride) {
            sum += e[i] = many_sample(H, i, NULL);
            lo = fmin(lo, e[i]), big = fmax(big, e[i]);
        }
        stride = half;
        const double next = 2.0 * M_PI * sum * stride / MT;
        if (fabs(next - mean) <= TRAP_TOL * next) {
            val[0] = next;
            return;
        }
        mean = next;
        if (lo < MANY_DEEP * big && stride <= MT / 256 && narrow(e, MT, stride))
            break;
    }
    H->big = big;
    /* the cuts: the least samples below MANY_CUT of the largest, and the least of all */
    const double dt = 2.0 * M_PI * stride / MT;
    const int ns = MT / stride;
    double cut[MANY_CUTS], scale[MANY_CUTS];
    int ncut = 0, at = 0;
    for (int j = 0; j < ns; j++) {
        const double ej = e[j * stride], l = e[(j + ns - 1) % ns * stride], r = e[(j + 1) % ns * stride];
        if (ej < e[at * stride])
            at = j;
        if (ej < l && ej <= r && ej < MANY_CUT * big && ncut < MANY_CUTS)
            cut[ncut] = many_least(H, (j - 1) * dt, (j + 1) * dt, &scale[ncut]), ncut++;
    }
    if (!ncut)
        cut[ncut] = many_least(H, (at - 1) * dt, (at + 1) * dt, &scale[ncut]), ncut++;
    double total = 0.0;
    for (int j = 0; j < ncut; j++) {
        const int k = (j + 1) % ncut;
        const double a = cut[j], b = j + 1 < ncut ? cut[j + 1] : cut[0] + 2.0 * M_PI, mid = 0.5 * (a + b);
        if (b > a)
            total += many_toward(H, a, 1.0, mid - a, scale[j]) + many_toward(H, b, -1.0, b - mid, scale[k]);
    }
    val[0] = total;   /* the mean over t of 2 pi |g| */
}

static void many_at_w(void *arg, double w, double *val)
{
    harm_ctx *H = arg;
    double *cf = H->cf;
    memset(cf, 0, 6 * (2 * (size_t)H->nh + 1) * sizeof *cf);
    wtable_eval(H->tab, w, H->h, H->dh);
    for (size_t m = 0; m < H->nm; m++) {
        const int sl = H->mslot[m], at = 6 * (sl / 3) + sl % 3;
        cf[at] += H->wt[m] * H->h[H->map[m]], cf[at + 3] += H->wt[m] * H->dh[H->map[m]];
    }
    H->nodes++;
    many_mean(H, val);
}

/*
 * The face's modes along its other parameter t (axis 0: v, 1: u): 1 where each has the factor 1 or
 * sin, cos of p pi t with p even (2 pi j t, j whole) and at most PDE_MAX_FREQ, else 0; the j's up to
 * MANY_MAX marked in seen (*over set where one is beyond), and *k = p where all share one p (one
 * harmonic, harm.h's form), else 0. One scan for both paths.
 */
static int face_form(const pde_solution *s, int axis, unsigned char seen[MANY_MAX + 1], double *k, int *over)
{
    int one = 1;
    *k = 0.0, *over = 0;
    memset(seen, 0, MANY_MAX + 1);
    for (int c = 0; c < 3; c++)
        for (size_t m = 0; m < s->comp[c].nmodes; m++) {
            const pde_factor f = axis == 0 ? s->comp[c].modes[m].v : s->comp[c].modes[m].u;
            const double p = fabs(f.p);
            if (f.kind == PDE_POW && f.p == 0.0)
                continue;
            if (!((f.kind == PDE_SIN || f.kind == PDE_COS) && p >= 2.0 && p <= PDE_MAX_FREQ && p == 2.0 * floor(0.5 * p)))
                return 0;
            one &= *k == 0.0 || p == *k;
            *k = p;
            if (p <= 2.0 * MANY_MAX)
                seen[(int)(0.5 * p)] = 1;
            else
                *over = 1;
        }
    if (!one)
        *k = 0.0;
    return 1;
}

/* The face's many harmonics, seen (face_form's, none beyond MANY_MAX): the distinct j ascending into
 * H->hj, H->nh, and each mode's entry into H->mslot. 0 where fewer than MANY_MIN, or out of memory. */
static int many_form(const pde_solution *s, int axis, const unsigned char seen[MANY_MAX + 1], harm_ctx *H)
{
    int idx[MANY_MAX + 1];
    H->nh = 0;
    for (int j = 1; j <= MANY_MAX; j++)
        if (seen[j])
            idx[j] = H->nh++;
    if (H->nh < MANY_MIN)
        return 0;
    H->hj = malloc(H->nh * sizeof *H->hj);
    H->mslot = malloc(H->nm * sizeof *H->mslot);
    H->cf = malloc(6 * (2 * (size_t)H->nh + 1) * sizeof *H->cf);
    H->e = malloc(MT * sizeof *H->e);
    if (!H->hj || !H->mslot || !H->cf || !H->e)
        return 0;
    for (int j = 1; j <= MANY_MAX; j++)
        if (seen[j])
            H->hj[idx[j]] = j;
    for (int c = 0, m = 0; c < 3; c++)
        for (size_t i = 0; i < s->comp[c].nmodes; i++, m++) {
            const pde_factor f = axis == 0 ? s->comp[c].modes[i].v : s->comp[c].modes[i].u;
            const int ent = f.kind == PDE_SIN ? 1 + 2 * idx[(int)(0.5 * fabs(f.p))]
                            : f.kind == PDE_COS ? 2 + 2 * idx[(int)(0.5 * fabs(f.p))] : 0;
            H->mslot[m] = 3 * ent + c;
        }
    pthread_once(&mtrig_once, mtrig_init);
    return 1;
}

/*
 * The face w = side (axis 2) of a loft: x = C + u P(v), C constant along v and u, P of many
 * harmonics along v (the modes' factors of u are 1 where those of v are, else u). Its element
 * x_u x x_v = u (P x P_v) is linear in u, so the face's area is half the mean over v of |P x P_v|
 * (many_mean, with P in x_w's place: exact where P x P_v keeps its sign, the cuts where it does
 * not), and its flux x . (x_u x x_v) = u C . (P x P_v) half the mean of -(x . (P_v x P)) at u = 1.
 * Returns 0 where the face is not of that form.
 */
static int many_cap(harm_ctx *H, int side, double *area, double *flux)
{
    const pde_solution *s = H->s;
    for (int c = 0, m = 0; c < 3; c++)
        for (size_t i = 0; i < s->comp[c].nmodes; i++, m++) {
            const pde_mode *md = &s->comp[c].modes[i];
            const int cst = md->v.kind == PDE_POW && md->v.p == 0.0;
            if (md->u.kind != PDE_POW || md->u.p != (cst ? 0.0 : 1.0))
                return 0;
        }
    double *cf = H->cf, val[2];
    memset(cf, 0, 6 * (2 * (size_t)H->nh + 1) * sizeof *cf);
    solution_factors(s, 2, side, H->h, H->dh);
    for (int c = 0, m = 0; c < 3; c++)
        for (size_t i = 0; i < s->comp[c].nmodes; i++, m++) {
            const int sl = H->mslot[m], at = 6 * (sl / 3) + sl % 3;
            double fu, du;
            factor_eval(s->comp[c].modes[i].u, 1.0, &fu, &du);
            cf[at] += H->h[m] * fu, cf[at + 3] += H->h[m] * du;
        }
    H->nodes++;
    H->dip = INFINITY;
    many_mean(H, val);
    *area = 0.5 * val[0];
    *flux = -0.5 * val[1];
    return 1;
}

int harm_face(const pde_solution *s, int axis, int side, const harm_opts *o, double *area, double *flux,
              size_t *nodes)
{
    double k;
    unsigned char seen[MANY_MAX + 1];
    int over;
    harm_ctx H = { .o = o, .s = s, .splits = MAX_SPLITS, .poll_every = POLL_NODES, .max_nodes = MAX_NODES,
                   .max_work = CUT_WORK };
    for (int c = 0; c < 3; c++)
        H.nm += s->comp[c].nmodes;
    if (!face_form(s, axis == 1, seen, &k, &over))
        return 0;
    H.many = k == 0.0;
    if (axis > 1 && !H.many)
        return 0;   /* a cap of one harmonic: the general path's line is cheaper (fig. 2a, 4a) */
    H.kpi = k * M_PI;
    H.wt = malloc(3 * H.nm * sizeof *H.wt);
    H.slot = malloc(H.nm);
    H.tab = wtable_new(s);
    int ok = H.wt && H.slot && H.tab && (!H.many || (!over && many_form(s, axis == 1, seen, &H)));
    if (H.many)   /* no cuts of w at dips: least_at's one harmonic */
        H.splits = 0, H.poll_every = MANY_POLL, H.max_nodes = MANY_NODES, H.max_work = MANY_WORK;
    if (ok) {
        H.h = H.wt + H.nm, H.dh = H.h + H.nm;
        for (int c = 0, m = 0; c < 3; c++)
            for (size_t i = 0; i < s->comp[c].nmodes; i++, m++) {
                const pde_mode *md = &s->comp[c].modes[i];
                const pde_factor f = axis == 0 ? md->v : md->u;
                double der;
                factor_eval(axis == 0 ? md->u : md->v, side, &H.wt[m], &der);
                const int part = f.kind == PDE_SIN ? 0 : f.kind == PDE_COS ? 1 : 2;
                if (f.kind == PDE_SIN && f.p < 0.0)
                    H.wt[m] = -H.wt[m];
                H.slot[m] = (unsigned char)(3 * part + c);
            }
        H.map = H.tab->map;
        pthread_once(&trig_once, trig_init);
        H.tol[0] = o->tol, H.tol[1] = o->tol * o->size;
    }
    double sum[2] = { 0.0, 0.0 };
    if (ok && axis > 1)
        ok = many_cap(&H, side, &sum[0], &sum[1]);
    else if (ok && H.many) {   /* every harmonic's factor 0 on the face: a curve (u = 0), nothing */
        int flat = 1;
        for (size_t m = 0; m < H.nm && flat; m++)
            flat = H.mslot[m] < 3 || H.wt[m] == 0.0;
        if (flat)
            ok = 2;
    }
    for (int i = 0; i < o->np && ok == 1 && axis < 2; i++) {
        wpanel coarse;
        rule_w(&H, NULL, o->edge[i], o->edge[i + 1], &coarse);
        ok = outer(&H, o->edge[i], o->edge[i + 1], &coarse, 0, 2, sum);
    }
    if (H.fold || H.work > H.max_work)
        ok = 0;
    if (H.stopped)
        ok = -1;
    free(H.wt);
    free(H.slot);
    wtable_free(H.tab);
    free(H.hj);
    free(H.mslot);
    free(H.cf);
    free(H.e);
    *nodes += H.nodes;
    if (ok == 2)
        ok = 1;
    if (ok == 1)
        *area = sum[0], *flux = sum[1];
    return ok;
}
