/*
 * loft_presets.c: the gallery's lofts (loft.h): sections made by shape generators, one row each.
 * Each is a loft document, as a client would POST it; {"preset": NAME} solves it.
 */
#include <math.h>
#include <string.h>

#include "loft.h"

#define POINTS 64

typedef enum { CIRCLE, STAR, SQUARE, NACA } shape;

typedef struct {
    double w, z;        /* the section's place, and its height */
    shape kind;
    double size;        /* radius, half width, or chord */
    double aux;         /* STAR: the points' depth; SQUARE: the superellipse's exponent; NACA: its 4 digits */
    double turn;        /* rotation about z, degrees */
    double tz;          /* > 0: a tangent (0, 0, tz) at every point: the section is clamped */
} section;

typedef struct {
    const char *name, *caption;
    double c;           /* a = b = 1, c: how far each section's harmonics reach along w */
    int n;
    section s[5];
} preset;

static const preset presets[] = {
    { "vase", "A vase: a circle, a five-pointed rounded star at its waist, a narrower circle at its lip", 4, 3,
      { { 0, 0, CIRCLE, 1.0, 0, 0, 0 }, { 0.45, 1.4, STAR, 1.3, 0.18, 0, 0 }, { 1, 3, CIRCLE, 0.8, 0, 0, 0 } } },
    { "tower", "A twisted tower: rounded squares turned by 30 degrees a storey", 4, 4,
      { { 0, 0, SQUARE, 1, 6, 0, 0 }, { 1.0 / 3, 1.4, SQUARE, 0.9, 6, 30, 0 }, { 2.0 / 3, 2.8, SQUARE, 0.8, 6, 60, 0 },
        { 1, 4.2, SQUARE, 0.7, 6, 90, 0 } } },
    { "blade", "A blade: a circular root to a NACA 2418 airfoil at the tip", 4, 3,
      { { 0, 0, CIRCLE, 0.35, 0, 0, 0 }, { 0.3, 1.2, NACA, 1.6, 2418, 10, 0 }, { 1, 4, NACA, 1.0, 2418, 25, 0 } } },
    { "bottle", "A bottle: a round body, and a neck whose tangent is set so that it rises straight", 4, 4,
      { { 0, 0, CIRCLE, 1.0, 0, 0, 0 }, { 0.45, 1.8, CIRCLE, 1.05, 0, 0, 0 }, { 0.8, 3.0, CIRCLE, 0.35, 0, 0, 2.5 },
        { 1, 3.6, CIRCLE, 0.35, 0, 0, 0 } } },
};

#define NPRESETS (sizeof presets / sizeof *presets)

/* NACA 4-digit mmpt: camber m%, at p/10 of the chord, thickness t%; closed trailing edge. The point at
 * angle a in [0, 2 pi): the upper surface from the trailing edge to the leading edge, then the lower. */
static void naca(int digits, double a, double *x, double *y)
{
    const double m = digits / 1000 / 100.0, p = digits / 100 % 10 / 10.0, t = digits % 100 / 100.0;
    const double xc = 0.5 * (1 + cos(a));   /* cosine spacing: 1 at a = 0, 0 at a = pi */
    const double yt = 5 * t * (0.2969 * sqrt(xc) - 0.1260 * xc - 0.3516 * xc * xc + 0.2843 * xc * xc * xc -
                               0.1036 * xc * xc * xc * xc);
    double yc = 0, dy = 0;
    if (m > 0 && p > 0) {
        if (xc < p)
            yc = m / (p * p) * (2 * p * xc - xc * xc), dy = 2 * m / (p * p) * (p - xc);
        else
            yc = m / ((1 - p) * (1 - p)) * (1 - 2 * p + 2 * p * xc - xc * xc), dy = 2 * m / ((1 - p) * (1 - p)) * (p - xc);
    }
    const double th = atan(dy), sgn = a < M_PI ? 1 : -1;
    *x = xc - sgn * yt * sin(th) - 0.25;   /* about the quarter chord */
    *y = yc + sgn * yt * cos(th);
}

static void point(const section *s, double a, double out[3])
{
    double x, y;
    switch (s->kind) {
    case STAR: {
        double r = s->size * (1 + s->aux * cos(5 * a));
        x = r * cos(a), y = r * sin(a);
        break;
    }
    case SQUARE: {   /* the superellipse |x|^n + |y|^n = size^n */
        double c = cos(a), sn = sin(a), e = 2.0 / s->aux;
        x = s->size * copysign(pow(fabs(c), e), c), y = s->size * copysign(pow(fabs(sn), e), sn);
        break;
    }
    case NACA:
        naca((int)s->aux, a, &x, &y);
        x *= s->size, y *= s->size;
        break;
    default:
        x = s->size * cos(a), y = s->size * sin(a);
    }
    const double r = s->turn * M_PI / 180;
    out[0] = x * cos(r) - y * sin(r), out[1] = x * sin(r) + y * cos(r), out[2] = s->z;
}

size_t api_loft_preset_count(void)
{
    return NPRESETS;
}

const char *api_loft_preset_name(size_t i, const char **caption)
{
    if (i >= NPRESETS)
        return NULL;
    if (caption)
        *caption = presets[i].caption;
    return presets[i].name;
}

cJSON *api_loft_preset_tree(const char *name)
{
    const preset *ps = NULL;
    for (size_t i = 0; i < NPRESETS && !ps; i++)
        if (!strcmp(presets[i].name, name))
            ps = &presets[i];
    if (!ps)
        return NULL;
    cJSON *root = cJSON_CreateObject(), *loft = cJSON_AddObjectToObject(root, "loft");
    cJSON *pde = cJSON_AddObjectToObject(loft, "pde"), *secs = cJSON_AddArrayToObject(loft, "sections");
    const double one[3] = { 1, 1, 1 }, c[3] = { ps->c, ps->c, ps->c };
    cJSON_AddItemToObject(pde, "a", cJSON_CreateDoubleArray(one, 3));
    cJSON_AddItemToObject(pde, "b", cJSON_CreateDoubleArray(one, 3));
    cJSON_AddItemToObject(pde, "c", cJSON_CreateDoubleArray(c, 3));
    for (int k = 0; k < ps->n && secs; k++) {
        const section *s = &ps->s[k];
        cJSON *o = cJSON_CreateObject(), *prof = cJSON_CreateArray(), *tan = s->tz > 0 ? cJSON_CreateArray() : NULL;
        cJSON_AddItemToArray(secs, o);
        cJSON_AddNumberToObject(o, "w", s->w);
        cJSON_AddItemToObject(o, "profile", prof);
        if (tan)
            cJSON_AddItemToObject(o, "tangent", tan);
        for (int j = 0; j < POINTS; j++) {
            double p[3];
            point(s, 2 * M_PI * j / POINTS, p);
            cJSON_AddItemToArray(prof, cJSON_CreateDoubleArray(p, 3));
            if (tan)
                cJSON_AddItemToArray(tan, cJSON_CreateDoubleArray((const double[3]){ 0, 0, s->tz }, 3));
        }
    }
    return root;
}
