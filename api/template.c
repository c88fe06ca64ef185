/*
 * template.c: the paper's example families (its eqs. 17, 19, 22, 25 with 28)
 * and the presets of its figures 1-4. Where the paper leaves a value unstated
 * the choice is written beside it; docs/MATH.md says why none changes a solid.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model.h"
#include "template.h"

typedef void (*expand_fn)(const api_template *t, const api_params *p, pde_model *m, pde_bterm bt[3][4],
                          pde_fterm ft[3][1]);

struct api_template {
    const char *name, *title;
    const api_param_info *params;
    size_t nparams;
    const char *defaults;     /* preset-style values */
    expand_fn expand;
};

#define PDE_VECTORS                                                                   \
    { "a", 3, "a_x, a_y, a_z: the coefficients of d4x/du4 in the PDE (eq. 1)" },      \
    { "b", 3, "b_x, b_y, b_z: the coefficients of d4x/dv4" },                          \
    { "c", 3, "c_x, c_y, c_z: the coefficients of d4x/dw4, none of them 0" }

static const api_param_info ex1_params[] = {
    PDE_VECTORS,
    { "a0", 1, "x = a0 + a1 u at w = 0" }, { "a1", 1, "x = a0 + a1 u at w = 0" },
    { "a2", 1, "x = a2 + a3 u at w = 1" }, { "a3", 1, "x = a2 + a3 u at w = 1" },
    { "b0", 1, "y = b0 + b1 v at w = 0" }, { "b1", 1, "y = b0 + b1 v at w = 0" },
    { "b2", 1, "y = b2 + b3 v at w = 1" }, { "b3", 1, "y = b2 + b3 v at w = 1" },
    { "h0", 1, "z at w = 0" }, { "h1", 1, "z at w = 1" },
    { "a0p", 1, "a'0: dx/dw = a'0 + a'1 u at w = 0" }, { "a1p", 1, "a'1" },
    { "a2p", 1, "a'2: dx/dw = a'2 + a'3 u at w = 1" }, { "a3p", 1, "a'3" },
    { "b0p", 1, "b'0: dy/dw = b'0 + b'1 v at w = 0" }, { "b1p", 1, "b'1" },
    { "b2p", 1, "b'2: dy/dw = b'2 + b'3 v at w = 1" }, { "b3p", 1, "b'3" },
    { "h0p", 1, "h'0: dz/dw at w = 0" }, { "h1p", 1, "h'1: dz/dw at w = 1" },
};

static const api_param_info ex2_params[] = {
    PDE_VECTORS,
    { "r0", 1, "radius of the circle at w = 0" }, { "h0", 1, "z at w = 0" },
    { "a0", 1, "x semi-axis of the ellipse at w = 1" }, { "b0", 1, "y semi-axis of the ellipse at w = 1" },
    { "h1", 1, "z at w = 1" },
    { "r0p", 1, "r'0: tangent of the radius at w = 0" }, { "h0p", 1, "h'0: dz/dw at w = 0" },
    { "a0p", 1, "a'0: tangent at w = 1" }, { "b0p", 1, "b'0: tangent at w = 1" }, { "h1p", 1, "h'1: dz/dw at w = 1" },
};

static const api_param_info ex3_params[] = {
    PDE_VECTORS,
    { "r0", 1, "radius of u sin 2pi v, u cos 2pi v at w = 0" },
    { "r1", 1, "amplitude of u sin n_xy pi v, u cos n_xy pi v at w = 0" },
    { "r2", 1, "radius at w = 1" },
    { "h0", 1, "z at w = 0" }, { "h1", 1, "amplitude of u sin n_z pi v in z at w = 0" },
    { "h2", 1, "z at w = 1" }, { "h3", 1, "amplitude of u sin n_z pi v in z at w = 1" },
    { "n_xy", 1, "frequency of the second x, y term (even closes the seam v = 0, 1; odd or fractional leaves two faces there that overlap in the plane x = 0)" }, { "n_z", 1, "frequency of the z term (0: planar)" },
    { "r0p", 1, "r'0" }, { "r1p", 1, "r'1" }, { "r2p", 1, "r'2" },
    { "h0p", 1, "h'0" }, { "h1p", 1, "h'1" }, { "h2p", 1, "h'2" }, { "h3p", 1, "h'3" },
};

static const api_param_info ex4_params[] = {
    PDE_VECTORS,
    { "r0", 1, "radius of the upper circle (w = 0)" }, { "r1", 1, "radius of the lower circle (w = 1)" },
    { "h0", 1, "z at w = 0" }, { "h1", 1, "z at w = 1" },
    { "r0p", 1, "r'0: tangent at w = 0" }, { "r1p", 1, "r'1: tangent at w = 1" },
    { "h0p", 1, "h'0: dz/dw at w = 0" }, { "h1p", 1, "h'1: dz/dw at w = 1" },
    { "p0", 1, "force amplitude: p_x = p0 u sin(xi pi w) cos 2pi v, p_y with sin 2pi v (eq. 28)" },
    { "xi", 1, "force frequency xi" },
};

/* The value of a named parameter; the names are fixed by the tables above. */
static double val(const api_template *t, const api_params *p, const char *name)
{
    double v[3] = { 0, 0, 0 };
    api_params_get(t, p, name, v);
    return v[0];
}

static pde_factor F(pde_factor_kind k, double p)
{
    return (pde_factor){ k, p };
}

/* The PDE vectors, and the term arrays as the components' lists. */
static void pde_vectors(const api_template *t, const api_params *p, pde_model *m)
{
    double a[3], b[3], c[3];
    api_params_get(t, p, "a", a);
    api_params_get(t, p, "b", b);
    api_params_get(t, p, "c", c);
    for (int i = 0; i < 3; i++) {
        m->comp[i].a = a[i];
        m->comp[i].b = b[i];
        m->comp[i].c = c[i];
    }
}

/* Eq. (17): x = a0 + a1 u, y = b0 + b1 v, z = h0 at w = 0; a2, a3, b2, b3, h1 at w = 1. */
static void expand1(const api_template *t, const api_params *p, pde_model *m, pde_bterm bt[3][4],
                    pde_fterm ft[3][1])
{
    (void)ft;
#define V(n) val(t, p, n)
    bt[0][0] = (pde_bterm){ F(PDE_POW, 0), F(PDE_POW, 0), V("a0"), V("a0p"), V("a2"), V("a2p") };
    bt[0][1] = (pde_bterm){ F(PDE_POW, 1), F(PDE_POW, 0), V("a1"), V("a1p"), V("a3"), V("a3p") };
    bt[1][0] = (pde_bterm){ F(PDE_POW, 0), F(PDE_POW, 0), V("b0"), V("b0p"), V("b2"), V("b2p") };
    bt[1][1] = (pde_bterm){ F(PDE_POW, 0), F(PDE_POW, 1), V("b1"), V("b1p"), V("b3"), V("b3p") };
    bt[2][0] = (pde_bterm){ F(PDE_POW, 0), F(PDE_POW, 0), V("h0"), V("h0p"), V("h1"), V("h1p") };
    m->comp[0].nbterms = m->comp[1].nbterms = 2;
    m->comp[2].nbterms = 1;
}

/* Eq. (19): a circle r0 at w = 0, an ellipse a0, b0 at w = 1. */
static void expand2(const api_template *t, const api_params *p, pde_model *m, pde_bterm bt[3][4],
                    pde_fterm ft[3][1])
{
    (void)ft;
    bt[0][0] = (pde_bterm){ F(PDE_POW, 1), F(PDE_SIN, 2), V("r0"), V("r0p"), V("a0"), V("a0p") };
    bt[1][0] = (pde_bterm){ F(PDE_POW, 1), F(PDE_COS, 2), V("r0"), V("r0p"), V("b0"), V("b0p") };
    bt[2][0] = (pde_bterm){ F(PDE_POW, 0), F(PDE_POW, 0), V("h0"), V("h0p"), V("h1"), V("h1p") };
    m->comp[0].nbterms = m->comp[1].nbterms = m->comp[2].nbterms = 1;
}

/* Eq. (22): two planar (n_z = 0) or 3D surfaces. */
static void expand3(const api_template *t, const api_params *p, pde_model *m, pde_bterm bt[3][4],
                    pde_fterm ft[3][1])
{
    (void)ft;
    double nxy = V("n_xy"), nz = V("n_z");
    bt[0][0] = (pde_bterm){ F(PDE_POW, 1), F(PDE_SIN, 2), V("r0"), V("r0p"), V("r2"), V("r2p") };
    bt[0][1] = (pde_bterm){ F(PDE_POW, 1), F(PDE_SIN, nxy), V("r1"), V("r1p"), 0, 0 };
    bt[1][0] = (pde_bterm){ F(PDE_POW, 1), F(PDE_COS, 2), V("r0"), V("r0p"), V("r2"), V("r2p") };
    bt[1][1] = (pde_bterm){ F(PDE_POW, 1), F(PDE_COS, nxy), V("r1"), V("r1p"), 0, 0 };
    bt[2][0] = (pde_bterm){ F(PDE_POW, 0), F(PDE_POW, 0), V("h0"), V("h0p"), V("h2"), V("h2p") };
    bt[2][1] = (pde_bterm){ F(PDE_POW, 1), F(PDE_SIN, nz), V("h1"), V("h1p"), V("h3"), V("h3p") };
    m->comp[0].nbterms = m->comp[1].nbterms = m->comp[2].nbterms = 2;
}

/* Eqs. (25) and (28): two circles and the force p0 u sin(xi pi w) (cos 2pi v, sin 2pi v, 0). */
static void expand4(const api_template *t, const api_params *p, pde_model *m, pde_bterm bt[3][4],
                    pde_fterm ft[3][1])
{
    double p0 = V("p0"), xi = V("xi");
    bt[0][0] = (pde_bterm){ F(PDE_POW, 1), F(PDE_SIN, 2), V("r0"), V("r0p"), V("r1"), V("r1p") };
    bt[1][0] = (pde_bterm){ F(PDE_POW, 1), F(PDE_COS, 2), V("r0"), V("r0p"), V("r1"), V("r1p") };
    bt[2][0] = (pde_bterm){ F(PDE_POW, 0), F(PDE_POW, 0), V("h0"), V("h0p"), V("h1"), V("h1p") };
    ft[0][0] = (pde_fterm){ p0, F(PDE_POW, 1), F(PDE_COS, 2), F(PDE_SIN, xi) };
    ft[1][0] = (pde_fterm){ p0, F(PDE_POW, 1), F(PDE_SIN, 2), F(PDE_SIN, xi) };
    m->comp[0].nbterms = m->comp[1].nbterms = m->comp[2].nbterms = 1;
    m->comp[0].nfterms = m->comp[1].nfterms = 1;
#undef V
}

#define COUNT(a) (sizeof(a) / sizeof *(a))

/* Defaults: each family's first figure (fig1a, fig2a, fig3a, fig4a). */
static const api_template templates[] = {
    { "example1", "Example 1: a solid between two parallel planar surfaces (eq. 17)", ex1_params,
      COUNT(ex1_params),
      /* a, b, c: not given for figure 1, and immaterial (every mode has e = 0). */
      "a=1,1,1 b=1,1,1 c=-10,-10,-10 a0=-0.5 b0=-0.5 a2=-0.5 b2=-0.5 a1=1 b1=1 a3=1 b3=1 h1=1", expand1 },
    { "example2", "Example 2: a solid between a circle and an ellipse (eq. 19)", ex2_params, COUNT(ex2_params),
      /* z's a, b, c: not given, and immaterial (z's mode is constant, e = 0); x's are used. */
      "a=1,1,1 b=4,4,4 c=-100,-100,-100 r0=0.5 r0p=0.5 a0=0.5 b0=1 h1=2", expand2 },
    { "example3", "Example 3: a solid between two planar or 3D surfaces (eq. 22)", ex3_params, COUNT(ex3_params),
      "a=1,1,1 b=2.5,2.5,2.5 c=-10,-10,-10 r0=0.5 r1=0.1 h1=0.1 r2=0.5 h0=2 h2=0 h3=-0.1 n_xy=20 n_z=0",
      expand3 },
    { "example4", "Example 4: a solid between two circles under a force (eqs. 25, 28)", ex4_params,
      COUNT(ex4_params),
      /* a_x, a_y: not given, immaterial (lu = 0 for u); z's: immaterial (constant mode). */
      "a=1,1,1 b=1,1,1 c=-9.5,-9.5,-10 r0=0.5 r1=0.5 h0=0 h1=3 h1p=7.5 p0=30000 xi=3", expand4 },
};

size_t api_template_count(void)
{
    return COUNT(templates);
}

const api_template *api_template_at(size_t i)
{
    return i < COUNT(templates) ? &templates[i] : NULL;
}

const api_template *api_template_find(const char *name)
{
    for (size_t i = 0; i < COUNT(templates); i++)
        if (strcmp(templates[i].name, name) == 0)
            return &templates[i];
    return NULL;
}

const char *api_template_name(const api_template *t)
{
    return t->name;
}

const char *api_template_title(const api_template *t)
{
    return t->title;
}

const api_param_info *api_template_params(const api_template *t, size_t *n)
{
    *n = t->nparams;
    return t->params;
}

/* The first slot of a parameter, or -1. */
static int slot_of(const api_template *t, const char *name, int *slots)
{
    int s = 0;
    for (size_t i = 0; i < t->nparams; i++) {
        if (strcmp(t->params[i].name, name) == 0) {
            *slots = t->params[i].slots;
            return s;
        }
        s += t->params[i].slots;
    }
    return -1;
}

int api_params_get(const api_template *t, const api_params *p, const char *name, double *vals)
{
    int n, s = slot_of(t, name, &n);
    if (s < 0)
        return 0;
    memcpy(vals, &p->v[s], (size_t)n * sizeof *vals);
    return n;
}

int api_params_set(const api_template *t, api_params *p, const char *name, const double *vals, int n,
                   api_error *err)
{
    int want, s = slot_of(t, name, &want);
    char ptr[96];
    snprintf(ptr, sizeof ptr, "/params/%.80s", name);
    if (s < 0) {
        char list[400] = "";
        for (size_t i = 0; i < t->nparams; i++)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "", t->params[i].name);
        return api_fail(err, API_ERR_DOCUMENT, ptr, "%s has no parameter \"%.60s\"; its parameters are %s", t->name, name, list);
    }
    if (n != want)
        return api_fail(err, API_ERR_DOCUMENT, ptr, want == 3 ? "must be an array of three numbers, for x, y and z"
                                             : "must be a number");
    for (int i = 0; i < n; i++)
        if (!isfinite(vals[i]))
            return api_fail(err, API_ERR_DOCUMENT, ptr, "must be finite");
    memcpy(&p->v[s], vals, (size_t)n * sizeof *vals);
    return 0;
}

/* Applies "name=v name=v1,v2,v3 ..." (the tables' own, so always well formed). */
static void apply_values(const api_template *t, api_params *p, const char *values)
{
    const char *s = values;
    while (*s) {
        while (*s == ' ')
            s++;
        const char *eq = strchr(s, '=');
        if (!eq)
            return;
        char name[16];
        snprintf(name, sizeof name, "%.*s", (int)(eq - s), s);
        double v[3];
        int n = 0;
        char *end = (char *)eq;
        do
            v[n++] = strtod(end + 1, &end);
        while (*end == ',' && n < 3);
        api_params_set(t, p, name, v, n, NULL);
        s = end;
    }
}

void api_template_defaults(const api_template *t, api_params *p)
{
    memset(p, 0, sizeof *p);
    apply_values(t, p, t->defaults);
}

/* The value in the field a failed check names: a factor's k or power, or a term's value; 0 if none. */
static int failed_value(const pde_model *m, const pde_diag *d, double *out)
{
    if (d->component < 0 || d->component > 2 || d->term < 0)
        return 0;
    const pde_component *c = &m->comp[d->component];
    if (d->in_force ? (size_t)d->term >= c->nfterms : (size_t)d->term >= c->nbterms)
        return 0;
    const pde_fterm *f = d->in_force ? &c->fterms[d->term] : NULL;
    const pde_bterm *b = d->in_force ? NULL : &c->bterms[d->term];
    const struct {
        const char *field;
        double v;
    } fields[] = {
        { "u", f ? f->u.p : b->u.p }, { "v", f ? f->v.p : b->v.p }, { "w", f ? f->w.p : 0 },
        { "coef", f ? f->coef : 0 },  { "w0", b ? b->w0 : 0 },      { "dw0", b ? b->dw0 : 0 },
        { "w1", b ? b->w1 : 0 },      { "dw1", b ? b->dw1 : 0 },
    };
    for (size_t i = 0; i < sizeof fields / sizeof *fields; i++)
        if (!strcmp(d->field, fields[i].field)) {
            *out = fields[i].v;
            return 1;
        }
    return 0;
}

/*
 * A model the core refuses, pointed at the parameter that made it: the one parameter whose value (or its
 * negative: sin(-k) is -sin k) is the refused field's, else /params. So n_xy = 2e6 is /params/n_xy, for a
 * front-end to place the message under its field; a failure of several values together stays /params.
 */
static int refused(const api_template *t, const api_params *p, const pde_model *m, const pde_diag *d,
                   pde_status st, api_error *err)
{
    char ptr[128] = "/params";
    double v;
    int found = 0;
    if (d->component >= 0 && d->term < 0 && strchr("abc", d->field[0]) && d->field[0] && !d->field[1])
        snprintf(ptr, sizeof ptr, "/params/%s/%d", d->field, d->component), found = 1;
    else if (failed_value(m, d, &v) && v != 0)
        for (size_t i = 0; i < t->nparams; i++) {
            double pv[API_MAX_SLOTS];
            int n = api_params_get(t, p, t->params[i].name, pv);
            for (int k = 0; k < n; k++)
                if (fabs(pv[k]) == fabs(v)) {
                    if (found++ == 0)
                        snprintf(ptr, sizeof ptr, n > 1 ? "/params/%s/%d" : "/params/%s", t->params[i].name, k);
                }
        }
    return api_fail(err, api_status_of(st), found == 1 ? ptr : "/params", "%s",
                    d->message[0] ? d->message : pde_strerror(st));
}

api_model *api_template_expand(const api_template *t, const api_params *p, api_error *err)
{
    pde_model m;
    pde_bterm bt[3][4];
    pde_fterm ft[3][1];
    memset(&m, 0, sizeof m);
    memset(bt, 0, sizeof bt);
    memset(ft, 0, sizeof ft);
    pde_vectors(t, p, &m);
    t->expand(t, p, &m, bt, ft);
    for (int c = 0; c < 3; c++) {
        m.comp[c].bterms = bt[c];
        m.comp[c].fterms = ft[c];
    }
    /* The model's own checks now, while the parameters are at hand to name. */
    pde_model canon;
    pde_diag d;
    pde_status st = pde_model_canonical(&m, &canon, &d);
    if (st != PDE_OK) {
        refused(t, p, &m, &d, st, err);
        return NULL;
    }
    pde_model_canonical_free(&canon);
    return api_model_build(&m, 1, err);
}

/* The figures. Values not listed carry over from the template's defaults (the family's first figure). */
#define CAP1 "Fig. 1: PDE solids defined by two parallel planar surfaces with square or rectangular boundary curves. "
#define CAP2 "Fig. 2: Solids defined by two parallel planes confined by a circle and an ellipse. "
#define CAP3 "Fig. 3: PDE solids defined by two planar or three-dimensional surfaces. "
#define CAP4 "Fig. 4: Solids generated using different combinations of the parameters controlling their shape. "
#define EX1E "a0=-0.5 a1=1.5 a2=-1 a3=3 b0=-1 b1=3 b2=-0.4 b3=1 h0=0 h1=2 "
#define EX4(b, c, rest) "b=" #b "," #b ",1 c=" #c "," #c ",-10 " rest

static const api_preset presets[] = {
    { "fig1a", "example1", CAP1 "1a (1b another view): a0 = b0 = a2 = b2 = -0.5, a1 = b1 = a3 = b3 = h1 = 1, h0 and all tangents 0: a cuboid.", "" },
    { "fig1c", "example1", CAP1 "1c (1d): as 1a with a2 = b2 = -1 and a3 = b3 = h1 = 2: an irregular hexahedron.",
      "a2=-1 b2=-1 a3=2 b3=2 h1=2" },
    { "fig1e", "example1", CAP1 "1e (1f): a0 = -0.5, a1 = 1.5, a2 = b0 = -1, a3 = b1 = 3, b2 = -0.4, b3 = 1, h0 = 0, h1 = 2, tangents a'i = ai, b'i = bi, h'0 = h1, h'1 = 2 h1.",
      EX1E "a0p=-0.5 a1p=1.5 a2p=-1 a3p=3 b0p=-1 b1p=3 b2p=-0.4 b3p=1 h0p=2 h1p=4" },
    { "fig1g", "example1", CAP1 "1g (1h): as 1e with a'0 = 2.5 a0, a'1 = 2.5 a1, a'2 = -2 a2, a'3 = -2 a3, b'0 = -2.5 b0, b'1 = -2.5 b1 and h'1 = h1.",
      EX1E "a0p=-1.25 a1p=3.75 a2p=2 a3p=-6 b0p=2.5 b1p=-7.5 b2p=-0.4 b3p=1 h0p=2 h1p=2" },
    { "fig2a", "example2", CAP2 "2a: a = 1, b = 4, c = -100; r0 = r'0 = a0 = 0.5, b0 = 1, h1 = 2, the rest 0.", "" },
    { "fig2b", "example2", CAP2 "2b: as 2a with b = 2.5, c = -10.", "b=2.5,2.5,2.5 c=-10,-10,-10" },
    { "fig2c", "example2", CAP2 "2c: as 2b with b = 4.", "b=4,4,4 c=-10,-10,-10" },
    { "fig3a", "example3", CAP3 "3a: a = 1, b = 2.5, c = -10; r0 = 0.5, r1 = h1 = 0.1, r2 = 0.5, h0 = 2, h2 = 0, h3 = -0.1, tangents 0; n_xy = 20, n_z = 0.", "" },
    { "fig3b", "example3", CAP3 "3b: as 3a with n_xy = 30.", "n_xy=30" },
    { "fig3c", "example3", CAP3 "3c: as 3a with r2 = 0.8, n_xy = 8, n_z = 10.", "r2=0.8 n_xy=8 n_z=10" },
    { "fig3d", "example3", CAP3 "3d: as 3c with n_xy = 14, n_z = 6.", "r2=0.8 n_xy=14 n_z=6" },
    { "fig4a", "example4", CAP4 "4a: b = 1, c = -9.5, r0 = 0.5, r'0 = 0, r1 = 0.5, r'1 = 0, h0 = 0, h'0 = 0, h1 = 3, h'1 = 7.5, p0 = 3e4, xi = 3.", "" },
    { "fig4b", "example4", CAP4 "4b: b = 2.5, c = -10, r0 = 0.5, r'0 = 2.5, r1 = 0.5, r'1 = 2.5, h0 = 0, h'0 = 0, h1 = 3, h'1 = 3, p0 = 8e4, xi = 5.",
      EX4(2.5, -10, "r0=0.5 r0p=2.5 r1=0.5 r1p=2.5 h0=0 h0p=0 h1=3 h1p=3 p0=8e4 xi=5") },
    { "fig4c", "example4", CAP4 "4c: b = 4, c = -100, r0 = 0.5, r'0 = 2.5, r1 = 0.5, r'1 = 2.5, h0 = 0, h'0 = 0, h1 = 3, h'1 = 6, p0 = 1.8e6, xi = 7.",
      EX4(4, -100, "r0=0.5 r0p=2.5 r1=0.5 r1p=2.5 h0=0 h0p=0 h1=3 h1p=6 p0=1.8e6 xi=7") },
    { "fig4d", "example4", CAP4 "4d: b = 4, c = -10, r0 = 0.5, r'0 = -1.5, r1 = 0.5, r'1 = 2, h0 = 0, h'0 = 3, h1 = 3, h'1 = 6, p0 = 3e5, xi = 7.",
      EX4(4, -10, "r0=0.5 r0p=-1.5 r1=0.5 r1p=2 h0=0 h0p=3 h1=3 h1p=6 p0=3e5 xi=7") },
    { "fig4e", "example4", CAP4 "4e: as 4d with p0 = -3e5.",
      EX4(4, -10, "r0=0.5 r0p=-1.5 r1=0.5 r1p=2 h0=0 h0p=3 h1=3 h1p=6 p0=-3e5 xi=7") },
    { "fig4f", "example4", CAP4 "4f: b = 2.5, c = -10, r0 = 0.5, r'0 = -1.5, r1 = 0.5, r'1 = 1.5, h0 = 0, h'0 = 6, h1 = 3, h'1 = 4.5, p0 = 1e5, xi = 7.",
      EX4(2.5, -10, "r0=0.5 r0p=-1.5 r1=0.5 r1p=1.5 h0=0 h0p=6 h1=3 h1p=4.5 p0=1e5 xi=7") },
    { "fig4g", "example4", CAP4 "4g: b = 2.5, c = -10, r0 = 0.5, r'0 = -1.5, r1 = 0.5, r'1 = 2, h0 = 0, h'0 = 3, h1 = 3, h'1 = 9, p0 = -3e4, xi = 5.",
      EX4(2.5, -10, "r0=0.5 r0p=-1.5 r1=0.5 r1p=2 h0=0 h0p=3 h1=3 h1p=9 p0=-3e4 xi=5") },
    { "fig4h", "example4", CAP4 "4h: b = 2.5, c = -10, r0 = 0.5, r'0 = -1, r1 = 0.5, r'1 = 0.5, h0 = 0, h'0 = 3, h1 = 3, h'1 = 6, p0 = 1.5e4, xi = 3.",
      EX4(2.5, -10, "r0=0.5 r0p=-1 r1=0.5 r1p=0.5 h0=0 h0p=3 h1=3 h1p=6 p0=1.5e4 xi=3") },
    { "fig4i", "example4", CAP4 "4i: b = 2.5, c = -10, r0 = 0.8, r'0 = 0.8, r1 = 0.5, r'1 = -1.6, h0 = 0, h'0 = 3, h1 = 3, h'1 = 6, p0 = 1.5e4, xi = 3.",
      EX4(2.5, -10, "r0=0.8 r0p=0.8 r1=0.5 r1p=-1.6 h0=0 h0p=3 h1=3 h1p=6 p0=1.5e4 xi=3") },
    { "fig4j", "example4", CAP4 "4j: b = 2.5, c = -10, r0 = 0.6, r'0 = -1.8, r1 = 0.5, r'1 = -0.6, h0 = 0, h'0 = 3, h1 = 3, h'1 = 6, p0 = -5.5e4, xi = 5.",
      EX4(2.5, -10, "r0=0.6 r0p=-1.8 r1=0.5 r1p=-0.6 h0=0 h0p=3 h1=3 h1p=6 p0=-5.5e4 xi=5") },
    { "fig4k", "example4", CAP4 "4k: as 4j with p0 = 5.5e4.",
      EX4(2.5, -10, "r0=0.6 r0p=-1.8 r1=0.5 r1p=-0.6 h0=0 h0p=3 h1=3 h1p=6 p0=5.5e4 xi=5") },
    { "fig4l", "example4", CAP4 "4l: b = 3.5, c = -10, r0 = 0.8, r'0 = -2.4, r1 = 0.5, r'1 = 0.5, h0 = 0, h'0 = 3, h1 = 3, h'1 = 9, p0 = -5.5e4, xi = 5.",
      EX4(3.5, -10, "r0=0.8 r0p=-2.4 r1=0.5 r1p=0.5 h0=0 h0p=3 h1=3 h1p=9 p0=-5.5e4 xi=5") },
    { "fig4m", "example4", CAP4 "4m: as 4l with p0 = 5.5e4 and xi = 9.",
      EX4(3.5, -10, "r0=0.8 r0p=-2.4 r1=0.5 r1p=0.5 h0=0 h0p=3 h1=3 h1p=9 p0=5.5e4 xi=9") },
    { "fig4n", "example4", CAP4 "4n: b = 5, c = -20, r0 = 1.5, r'0 = -4.5, r1 = 0.5, r'1 = 0, h0 = 0, h'0 = 3, h1 = 3, h'1 = 3, p0 = 5e5, xi = 7.",
      EX4(5, -20, "r0=1.5 r0p=-4.5 r1=0.5 r1p=0 h0=0 h0p=3 h1=3 h1p=3 p0=5e5 xi=7") },
    { "fig4o", "example4", CAP4 "4o: b = 3, c = -20, r0 = 1, r'0 = -5, r1 = 0.5, r'1 = -1, h0 = 0, h'0 = 6, h1 = 3, h'1 = 6, p0 = -9e5, xi = 11.",
      EX4(3, -20, "r0=1 r0p=-5 r1=0.5 r1p=-1 h0=0 h0p=6 h1=3 h1p=6 p0=-9e5 xi=11") },
    { "fig4p", "example4", CAP4 "4p: b = 15, c = -40, r0 = 1, r'0 = -2, r1 = 0.5, r'1 = -1, h0 = 0, h'0 = 6, h1 = 3, h'1 = 4.5, p0 = 3e6, xi = 11.",
      EX4(15, -40, "r0=1 r0p=-2 r1=0.5 r1p=-1 h0=0 h0p=6 h1=3 h1p=4.5 p0=3e6 xi=11") },
    { "fig4q", "example4", CAP4 "4q: b = 1, c = -10, r0 = 1, r'0 = 3, r1 = 0.5, r'1 = -1, h0 = 0, h'0 = 6, h1 = 3, h'1 = 9, p0 = 3e4, xi = 3.",
      EX4(1, -10, "r0=1 r0p=3 r1=0.5 r1p=-1 h0=0 h0p=6 h1=3 h1p=9 p0=3e4 xi=3") },
    { "fig4r", "example4", CAP4 "4r: b = 1, c = -10, r0 = 1, r'0 = -3, r1 = 0.5, r'1 = -2, h0 = 0, h'0 = 9, h1 = 3, h'1 = 3, p0 = 3e4, xi = 3.",
      EX4(1, -10, "r0=1 r0p=-3 r1=0.5 r1p=-2 h0=0 h0p=9 h1=3 h1p=3 p0=3e4 xi=3") },
    { "fig4s", "example4", CAP4 "4s: as 4r with p0 = 3e5 and xi = 7.",
      EX4(1, -10, "r0=1 r0p=-3 r1=0.5 r1p=-2 h0=0 h0p=9 h1=3 h1p=3 p0=3e5 xi=7") },
    { "fig4t", "example4", CAP4 "4t: b = 1, c = -10, r0 = 1, r'0 = -3, r1 = 0.5, r'1 = -1, h0 = 0, h'0 = 9, h1 = 3, h'1 = 0, p0 = 3e5, xi = 5.",
      EX4(1, -10, "r0=1 r0p=-3 r1=0.5 r1p=-1 h0=0 h0p=9 h1=3 h1p=0 p0=3e5 xi=5") },
    { "fig4u", "example4", CAP4 "4u: b = 1, c = -10, r0 = 1, r'0 = 3, r1 = 0.5, r'1 = 1, h0 = 0, h'0 = 9, h1 = 3, h'1 = 7.5, p0 = 3e4, xi = 5.",
      EX4(1, -10, "r0=1 r0p=3 r1=0.5 r1p=1 h0=0 h0p=9 h1=3 h1p=7.5 p0=3e4 xi=5") },
    { "fig4v", "example4", CAP4 "4v: b = 1, c = -10, r0 = 1, r'0 = 1, r1 = 0.5, r'1 = 3, h0 = 0, h'0 = 3, h1 = 3, h'1 = 9, p0 = 5e5, xi = 9.",
      EX4(1, -10, "r0=1 r0p=1 r1=0.5 r1p=3 h0=0 h0p=3 h1=3 h1p=9 p0=5e5 xi=9") },
    { "fig4w", "example4", CAP4 "4w: b = 1, c = -10, r0 = 1, r'0 = 6, r1 = 0.5, r'1 = 3, h0 = 0, h'0 = 3, h1 = 3, h'1 = 10.5, p0 = 3e5, xi = 9.",
      EX4(1, -10, "r0=1 r0p=6 r1=0.5 r1p=3 h0=0 h0p=3 h1=3 h1p=10.5 p0=3e5 xi=9") },
    { "fig4x", "example4", CAP4 "4x: b = 1, c = -10, r0 = 0.8, r'0 = -4, r1 = 1, r'1 = -2.4, h0 = 0, h'0 = 6, h1 = 3, h'1 = 9, p0 = 5e5, xi = 7.",
      EX4(1, -10, "r0=0.8 r0p=-4 r1=1 r1p=-2.4 h0=0 h0p=6 h1=3 h1p=9 p0=5e5 xi=7") },
};

size_t api_preset_count(void)
{
    return COUNT(presets);
}

const api_preset *api_preset_at(size_t i)
{
    return i < COUNT(presets) ? &presets[i] : NULL;
}

const api_preset *api_preset_find(const char *name)
{
    for (size_t i = 0; i < COUNT(presets); i++)
        if (strcmp(presets[i].name, name) == 0)
            return &presets[i];
    return NULL;
}

const api_template *api_preset_template(const api_preset *p)
{
    return api_template_find(p->template);
}

void api_preset_params(const api_preset *ps, api_params *p)
{
    const api_template *t = api_preset_template(ps);
    api_template_defaults(t, p);
    apply_values(t, p, ps->values);
}
