/*
 * numfmt.c: float32 to decimal in nine significant digits.
 *
 * Nine digits always round-trip a float32: a unit in the ninth digit is at
 * most 1e-8 of the value, and float32 values lie at least 2^-24 = 6e-8 of
 * their size apart, so even a last digit off by one names the same float. So
 * the digits can come from one double multiplication by a power of ten and a
 * rounding to a nine-digit integer, with no shortest-digits search and no
 * printf. Trailing zeros are dropped.
 *
 * Doubles (api_fmt_f64) are rarer, a model's numbers and the properties, and
 * take printf's digits: 15, or 16 or 17 where 15 do not read back.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "numfmt.h"

/* 10^k for k in [-60, 60], each literal correctly rounded; float32 needs 10^(8 - e) for e in [-46, 39]. */
static const double pow10_table[121] = {
    1e-60, 1e-59, 1e-58, 1e-57, 1e-56, 1e-55, 1e-54, 1e-53, 1e-52, 1e-51, 1e-50, 1e-49, 1e-48, 1e-47,
    1e-46, 1e-45, 1e-44, 1e-43, 1e-42, 1e-41, 1e-40, 1e-39, 1e-38, 1e-37, 1e-36, 1e-35, 1e-34, 1e-33,
    1e-32, 1e-31, 1e-30, 1e-29, 1e-28, 1e-27, 1e-26, 1e-25, 1e-24, 1e-23, 1e-22, 1e-21, 1e-20, 1e-19,
    1e-18, 1e-17, 1e-16, 1e-15, 1e-14, 1e-13, 1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4,
    1e-3, 1e-2, 1e-1, 1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14,
    1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22, 1e23, 1e24, 1e25, 1e26, 1e27, 1e28, 1e29, 1e30,
    1e31, 1e32, 1e33, 1e34, 1e35, 1e36, 1e37, 1e38, 1e39, 1e40, 1e41, 1e42, 1e43, 1e44, 1e45, 1e46,
    1e47, 1e48, 1e49, 1e50, 1e51, 1e52, 1e53, 1e54, 1e55, 1e56, 1e57, 1e58, 1e59, 1e60
};

static double pow10i(int k)
{
    return pow10_table[k + 60];
}

static const char digits2[] = "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
                              "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
                              "8081828384858687888990919293949596979899";

/* Writes n (< 10^9) as exactly nd digits into out. */
static void put_digits(char *out, uint32_t n, int nd)
{
    char *p = out + nd;
    while (nd >= 2) {
        uint32_t q = n / 100, r = n - q * 100;
        p -= 2;
        memcpy(p, &digits2[2 * r], 2);
        n = q;
        nd -= 2;
    }
    if (nd)
        *--p = (char)('0' + n);
}

size_t api_fmt_f32(char *out, float v)
{
    if (!isfinite(v)) {
        memcpy(out, "null", 4);
        return 4;
    }
    if (v == 0.0f) {
        out[0] = '0';
        return 1;
    }
    char *p = out;
    double d = v;
    if (d < 0) {
        *p++ = '-';
        d = -d;
    }
    /* Decimal exponent from the binary one, corrected by at most one step. */
    int e2;
    frexp(d, &e2);
    int e10 = (int)floor((e2 - 1) * 0.30102999566398120);
    if (d >= pow10i(e10 + 1))
        e10++;
    else if (d < pow10i(e10))
        e10--;
    uint32_t n = (uint32_t)llrint(d * pow10i(8 - e10));
    if (n >= 1000000000u) {
        n = 100000000u;
        e10++;
    }
    int nd = 9;
    while (n % 10 == 0) {
        n /= 10;
        nd--;
    }
    if (e10 >= 0 && e10 < 9) {
        if (nd <= e10 + 1) {            /* an integer: digits then zeros */
            put_digits(p, n, nd);
            memset(p + nd, '0', (size_t)(e10 + 1 - nd));
            p += e10 + 1;
        } else {                        /* ddd.ddd */
            char tmp[9];
            put_digits(tmp, n, nd);
            memcpy(p, tmp, (size_t)e10 + 1);
            p[e10 + 1] = '.';
            memcpy(p + e10 + 2, tmp + e10 + 1, (size_t)(nd - e10 - 1));
            p += nd + 1;
        }
    } else if (e10 < 0 && e10 >= -5) {  /* 0.000ddd */
        *p++ = '0';
        *p++ = '.';
        memset(p, '0', (size_t)(-e10 - 1));
        p += -e10 - 1;
        put_digits(p, n, nd);
        p += nd;
    } else {                            /* d.ddde+XX */
        char tmp[9] = { 0 };
        put_digits(tmp, n, nd);
        *p++ = tmp[0];
        if (nd > 1) {
            *p++ = '.';
            memcpy(p, tmp + 1, (size_t)nd - 1);
            p += nd - 1;
        }
        *p++ = 'e';
        int ex = e10;
        if (ex < 0) {
            *p++ = '-';
            ex = -ex;
        }
        if (ex >= 10) {
            memcpy(p, &digits2[2 * ex], 2);
            p += 2;
        } else {
            *p++ = (char)('0' + ex);
        }
    }
    return (size_t)(p - out);
}

size_t api_fmt_f64(char out[API_F64_MAX], double v)
{
    char b[API_F64_MAX];
    int n = 0;
    for (int digits = 15; digits <= 17; digits++) {
        n = snprintf(b, sizeof b, "%.*g", digits, v);
        if (strtod(b, NULL) == v)
            break;
    }
    memcpy(out, b, (size_t)n + 1);
    return (size_t)n;
}
