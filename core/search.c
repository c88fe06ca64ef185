/*
 * search.c: the scalar searches the properties share: a root in a bracket (Illinois) and a minimum
 * in a bracket (Brent). Each calls f(arg, t) and nothing else, so a path that caches its function's
 * values (quad.c's free path, harm.c's sections) keeps its cache in arg.
 */
#include <float.h>
#include <math.h>

#include "internal.h"

double illinois(double (*f)(void *, double), void *arg, double a, double b, double fa, double fb)
{
    double c = 0.5 * (a + b);
    for (int it = 0, side = 0; it < 100 && b - a > 4 * DBL_EPSILON * fmax(fabs(a), fabs(b)); it++) {
        c = (a * fb - b * fa) / (fb - fa);
        if (!(c > a && c < b))
            c = 0.5 * (a + b);
        double fc = f(arg, c);
        if (fc == 0.0)
            break;
        if ((fc < 0) == (fa < 0)) {
            a = c, fa = fc;
            if (side == -1)
                fb *= 0.5;
            side = -1;
        } else {
            b = c, fb = fc;
            if (side == 1)
                fa *= 0.5;
            side = 1;
        }
    }
    return c;
}

/*
 * Brent's minimiser (Brent 1973, ch. 5; netlib's fmin): golden section, and a parabola through the
 * three best points wherever its step falls inside the bracket and shrinks, so that a smooth
 * minimum (or the square of a kink) is found in a few steps where golden section takes 30 or more.
 * Each step asks enough(arg, a, b, x, fx) first, where a caller can end the search once it knows
 * enough (a negative value found, a bracket outside its window).
 */
double brent_min(const brent_fn *fn, double a, double b, double x, double fx, double tol, int steps,
                 double *fmin)
{
    const double gold = 0.5 * (3.0 - sqrt(5.0));
    double w = x, v = x, fw = fx, fv = fx, d = 0.0, e = 0.0;
    for (int it = 0; it < steps && !(fn->enough && fn->enough(fn->arg, a, b, x, fx)); it++) {
        const double m = 0.5 * (a + b), tol1 = tol + 2.0 * DBL_EPSILON * fabs(x), tol2 = 2.0 * tol1;
        if (fabs(x - m) <= tol2 - 0.5 * (b - a))
            break;
        double p = 0.0, q = 0.0, r = 0.0;
        if (fabs(e) > tol1) {   /* a parabola through x, w, v */
            r = (x - w) * (fx - fv);
            q = (x - v) * (fx - fw);
            p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if (q > 0.0)
                p = -p;
            else
                q = -q;
            r = e;
            e = d;
        }
        if (fabs(p) < fabs(0.5 * q * r) && p > q * (a - x) && p < q * (b - x)) {
            d = p / q;
            if (x + d - a < tol2 || b - (x + d) < tol2)
                d = x < m ? tol1 : -tol1;
        } else {
            e = (x < m ? b : a) - x;
            d = gold * e;
        }
        const double u = x + (fabs(d) >= tol1 ? d : d > 0.0 ? tol1 : -tol1), fu = fn->f(fn->arg, u);
        if (fu <= fx) {
            if (u < x)
                b = x;
            else
                a = x;
            v = w, fv = fw, w = x, fw = fx, x = u, fx = fu;
        } else {
            if (u < x)
                a = u;
            else
                b = u;
            if (fu <= fw || w == x)
                v = w, fv = fw, w = u, fw = fu;
            else if (fu <= fv || v == x || v == w)
                v = u, fv = fu;
        }
    }
    *fmin = fx;
    return x;
}
