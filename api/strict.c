/*
 * strict.c: a strict RFC 8259 check run before cJSON, a UTF-8 cleaner for
 * messages, and the finiteness check of eval results (strict.h).
 *
 * The check is one pass over the bytes with a fixed stack of API_MAX_DEPTH
 * levels. Each level remembers its array index or the offset of its current
 * key, which is all it takes to name the JSON pointer of a fault, and that
 * pointer is only built when there is one.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "strict.h"

#define REPLACEMENT "\xEF\xBF\xBD"   /* U+FFFD in UTF-8 */

/* The ranges are Table 3-7 of Unicode 15: they exclude overlongs, surrogates and code points past U+10FFFF. */
size_t api_utf8_char(const unsigned char *s, size_t n, size_t *part)
{
    unsigned char c = s[0], lo = 0x80, hi = 0xBF;
    size_t need;
    *part = 1;
    if (c < 0x80)
        return 1;
    if (c >= 0xC2 && c <= 0xDF) {
        need = 1;
    } else if (c >= 0xE0 && c <= 0xEF) {
        need = 2;
        if (c == 0xE0)
            lo = 0xA0;
        else if (c == 0xED)
            hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
        need = 3;
        if (c == 0xF0)
            lo = 0x90;
        else if (c == 0xF4)
            hi = 0x8F;
    } else {
        return 0;
    }
    for (size_t k = 1; k <= need; k++) {
        if (k >= n || s[k] < lo || s[k] > hi) {
            *part = k;
            return 0;
        }
        lo = 0x80;
        hi = 0xBF;
    }
    return need + 1;
}

size_t api_text_clean(char *out, size_t outn, const char *s, size_t n)
{
    if (outn == 0)
        return 0;
    const unsigned char *u = (const unsigned char *)s;
    size_t w = 0, i = 0;
    while (i < n) {
        size_t part, k = api_utf8_char(u + i, n - i, &part);
        const char *src = s + i;
        size_t m = k;
        if (k == 0 || (k == 1 && (u[i] < 0x20 || u[i] == 0x7f))) {
            src = REPLACEMENT;
            m = 3;
        }
        if (m > outn - 1 - w)
            break;
        memcpy(out + w, src, m);
        w += m;
        i += k ? k : part;
    }
    out[w] = '\0';
    return w;
}

typedef struct {
    const unsigned char *s;
    size_t len, pos;
    int depth;
    unsigned char is_obj[API_MAX_DEPTH];
    unsigned char has_key[API_MAX_DEPTH];  /* an object level's key is read: its value is being checked */
    size_t index[API_MAX_DEPTH];           /* an array level's current element */
    size_t key_at[API_MAX_DEPTH];          /* an object level's current key: its opening quote */
    api_error *err;
} checker;

static int hex_digit(unsigned char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

/* The four hex digits at s[at..], or -1. */
static long hex4(const checker *c, size_t at)
{
    if (at > c->len || c->len - at < 4)
        return -1;
    long v = 0;
    for (int k = 0; k < 4; k++) {
        int d = hex_digit(c->s[at + k]);
        if (d < 0)
            return -1;
        v = v * 16 + d;
    }
    return v;
}

static size_t put_utf8(char *out, unsigned long cp)
{
    if (cp < 0x80) {
        out[0] = (char)cp;
        return 1;
    }
    if (cp < 0x800) {
        out[0] = (char)(0xC0 | cp >> 6);
        out[1] = (char)(0x80 | (cp & 0x3F));
        return 2;
    }
    if (cp < 0x10000) {
        out[0] = (char)(0xE0 | cp >> 12);
        out[1] = (char)(0x80 | (cp >> 6 & 0x3F));
        out[2] = (char)(0x80 | (cp & 0x3F));
        return 3;
    }
    out[0] = (char)(0xF0 | cp >> 18);
    out[1] = (char)(0x80 | (cp >> 12 & 0x3F));
    out[2] = (char)(0x80 | (cp >> 6 & 0x3F));
    out[3] = (char)(0x80 | (cp & 0x3F));
    return 4;
}

/*
 * "/" and the already checked key whose opening quote is at `at`, decoded and
 * escaped as RFC 6901 says (~ as ~0, / as ~1), into out; 0 if it does not fit.
 */
static size_t key_token(const checker *c, size_t at, char *out, size_t n)
{
    size_t w = 0;
    char ch[8];
    out[w++] = '/';
    for (size_t i = at + 1; c->s[i] != '"';) {
        size_t m = 1;
        ch[0] = (char)c->s[i];
        if (c->s[i] == '\\') {
            static const char esc[] = "\"\\/bfnrt", val[] = "\"\\/\b\f\n\r\t";
            unsigned char e = c->s[i + 1];
            if (e == 'u') {
                unsigned long cp = (unsigned long)hex4(c, i + 2);
                i += 6;
                if (cp >= 0xD800 && cp <= 0xDBFF) {
                    cp = 0x10000 + ((cp - 0xD800) << 10) + ((unsigned long)hex4(c, i + 2) - 0xDC00);
                    i += 6;
                }
                m = put_utf8(ch, cp);
            } else {
                ch[0] = val[strchr(esc, e) - esc];
                i += 2;
            }
        } else {
            i++;
        }
        if (m == 1 && (ch[0] == '~' || ch[0] == '/')) {
            ch[1] = ch[0] == '~' ? '0' : '1';
            ch[0] = '~';
            m = 2;
        }
        if (w + m >= n)
            return 0;
        memcpy(out + w, ch, m);
        w += m;
    }
    return w;
}

/* The pointer of the value at stack level `levels` (0: the whole document), as far as it fits in out. */
static void build_pointer(const checker *c, int levels, char *out, size_t n)
{
    size_t w = 0;
    out[0] = '\0';
    for (int l = 0; l < levels; l++) {
        char tok[sizeof c->err->pointer];
        size_t m;
        if (!c->is_obj[l])
            m = (size_t)snprintf(tok, sizeof tok, "/%zu", c->index[l]);
        else if (c->has_key[l])
            m = key_token(c, c->key_at[l], tok, sizeof tok);
        else
            break;
        if (m == 0 || w + m >= n)
            break;
        memcpy(out + w, tok, m);
        w += m;
        out[w] = '\0';
    }
}

/* What the byte is, in words: a message never repeats the input's bytes. */
static const char *describe(unsigned char b, char *buf, size_t n)
{
    static const struct { char c; const char *name; } named[] = {
        { '{', "an opening brace" }, { '}', "a closing brace" }, { '[', "an opening bracket" },
        { ']', "a closing bracket" }, { ',', "a comma" }, { ':', "a colon" }, { '"', "a double quote" },
        { '\'', "a single quote (JSON strings take double quotes)" }, { '/', "a slash (JSON has no comments)" },
        { '#', "a hash sign (JSON has no comments)" }, { '.', "a decimal point" }, { '+', "a plus sign" },
        { '-', "a minus sign" }, { '\\', "a backslash" },
    };
    for (size_t i = 0; i < sizeof named / sizeof *named; i++)
        if (named[i].c == (char)b)
            return named[i].name;
    if (b == 0)
        return "a NUL byte";
    if (b >= '0' && b <= '9')
        return "a digit";
    if ((b >= 'a' && b <= 'z') || (b >= 'A' && b <= 'Z') || b == '_')
        return "a letter";
    if (b < 0x20 || b == 0x7f)
        snprintf(buf, n, "the control character 0x%02X", b);
    else if (b >= 0x80)
        snprintf(buf, n, "the byte 0x%02X (only white space and ASCII punctuation may stand outside strings)", b);
    else
        snprintf(buf, n, "the character 0x%02X", b);
    return buf;
}

/* Fills err for a fault at byte `at` in the value at stack level `levels`; returns -1. */
__attribute__((format(printf, 4, 5)))
static int fail(checker *c, size_t at, int levels, const char *fmt, ...)
{
    if (!c->err)
        return -1;
    char what[240], ptr[sizeof c->err->pointer];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    size_t line = 1, col = 1;
    for (size_t i = 0; i < at && i < c->len; i++, col++)
        if (c->s[i] == '\n')
            line++, col = 0;
    build_pointer(c, levels, ptr, sizeof ptr);
    api_fail(c->err, API_ERR_NOT_JSON, ptr, "not valid JSON: %s, at line %zu, column %zu (byte %zu%s)", what, line, col, at,
             at >= c->len ? ", the end of the text" : "");
    return -1;
}

static void skip_ws(checker *c)
{
    while (c->pos < c->len && (c->s[c->pos] == ' ' || c->s[c->pos] == '\t' || c->s[c->pos] == '\n' ||
                               c->s[c->pos] == '\r'))
        c->pos++;
}

/* Why no UTF-8 character starts at s, whose longest valid start is part bytes (utf8_char). */
static const char *utf8_fault(const unsigned char *s, size_t n, size_t part)
{
    unsigned char b = s[0], next = n > 1 ? s[1] : 0;
    if (b >= 0x80 && b <= 0xBF)
        return "continues no character";
    if (b >= 0xF5)
        return "is never UTF-8";
    if (b <= 0xC1 || (part == 1 && ((b == 0xE0 && next >= 0x80 && next <= 0x9F) ||
                                    (b == 0xF0 && next >= 0x80 && next <= 0x8F))))
        return "starts an overlong encoding";
    if (part == 1 && b == 0xED && next >= 0xA0 && next <= 0xBF)
        return "starts an encoded surrogate (U+D800 to U+DFFF)";
    if (part == 1 && b == 0xF4 && next >= 0x90 && next <= 0xBF)
        return "starts a code point past U+10FFFF";
    return "starts a character that breaks off before its end";
}

/* The string whose opening quote is at c->pos; levels: the pointer to give a fault in it. */
static int string(checker *c, int levels)
{
    char buf[120];
    size_t start = c->pos++;
    for (;;) {
        if (c->pos >= c->len)
            return fail(c, c->pos, levels, "the text ends inside the string that starts at byte %zu", start);
        size_t at = c->pos;
        unsigned char b = c->s[at];
        if (b == '"') {
            c->pos++;
            return 0;
        }
        if (b == '\\') {
            if (at + 1 >= c->len)
                return fail(c, at + 1, levels, "the text ends inside an escape");
            unsigned char e = c->s[at + 1];
            if (e != 'u') {
                if (!e || !strchr("\"\\/bfnrt", e))
                    return fail(c, at, levels, "an unknown escape: %s cannot follow a backslash; the escapes are "
                                "\\\" \\\\ \\/ \\b \\f \\n \\r \\t and \\uXXXX", describe(e, buf, sizeof buf));
                c->pos += 2;
                continue;
            }
            long cp = hex4(c, at + 2);
            if (cp < 0)
                return fail(c, at, levels, "\\u must be followed by four hex digits");
            if (cp == 0)
                return fail(c, at, levels, "the escape \\u0000 (NUL) is not allowed in a string");
            if (cp >= 0xDC00 && cp <= 0xDFFF)
                return fail(c, at, levels, "the escape \\u%04lX is the second half of a surrogate pair, with "
                            "no first half before it", cp);
            c->pos += 6;
            if (cp >= 0xD800 && cp <= 0xDBFF) {
                long lo = c->pos + 1 < c->len && c->s[c->pos] == '\\' && c->s[c->pos + 1] == 'u'
                              ? hex4(c, c->pos + 2) : -1;
                if (lo < 0xDC00 || lo > 0xDFFF)
                    return fail(c, at, levels, "the escape \\u%04lX is the first half of a surrogate pair, "
                                "and no \\uDC00 to \\uDFFF follows it", cp);
                c->pos += 6;
            }
            continue;
        }
        if (b == 0)
            return fail(c, at, levels, "a raw NUL byte in a string");
        if (b < 0x20)
            return fail(c, at, levels, "the control character 0x%02X in a string; write it escaped (\\n, "
                        "\\t, \\u00XX)", b);
        size_t part, k = api_utf8_char(c->s + at, c->len - at, &part);
        if (k == 0)
            return fail(c, at, levels, "invalid UTF-8 in a string: the byte 0x%02X %s", b,
                        utf8_fault(c->s + at, c->len - at, part));
        c->pos += k;
    }
}

static int is_digit(const checker *c)
{
    return c->pos < c->len && c->s[c->pos] >= '0' && c->s[c->pos] <= '9';
}

static int number(checker *c, int levels)
{
    size_t start = c->pos;
    if (c->s[c->pos] == '-')
        c->pos++;
    if (!is_digit(c))
        return fail(c, c->pos, levels, "a digit must follow the minus sign");
    if (c->s[c->pos] == '0') {
        c->pos++;
        if (is_digit(c))
            return fail(c, start, levels, "a number with a leading zero; JSON writes 1, not 01");
    } else {
        while (is_digit(c))
            c->pos++;
    }
    if (c->pos < c->len && c->s[c->pos] == '.') {
        c->pos++;
        if (!is_digit(c))
            return fail(c, c->pos, levels, "a digit must follow the decimal point (1.0, not 1.)");
        while (is_digit(c))
            c->pos++;
    }
    if (c->pos < c->len && (c->s[c->pos] == 'e' || c->s[c->pos] == 'E')) {
        c->pos++;
        if (c->pos < c->len && (c->s[c->pos] == '+' || c->s[c->pos] == '-'))
            c->pos++;
        if (!is_digit(c))
            return fail(c, c->pos, levels, "a digit must follow the exponent's e");
        while (is_digit(c))
            c->pos++;
    }
    return 0;
}

/* A key, its colon and the white space around them, at c->pos inside an object. */
static int key(checker *c)
{
    char buf[120];
    int top = c->depth - 1;
    c->has_key[top] = 0;
    skip_ws(c);
    if (c->pos >= c->len)
        return fail(c, c->pos, top, "the text ends inside an object, where a key should be");
    if (c->s[c->pos] != '"')
        return fail(c, c->pos, top, "a key in double quotes should come here, not %s",
                    describe(c->s[c->pos], buf, sizeof buf));
    c->key_at[top] = c->pos;
    if (string(c, top))
        return -1;
    skip_ws(c);
    if (c->pos >= c->len || c->s[c->pos] != ':')
        return fail(c, c->pos, top, "a colon should follow the key, not %s",
                    c->pos >= c->len ? "the end of the text" : describe(c->s[c->pos], buf, sizeof buf));
    c->pos++;
    c->has_key[top] = 1;
    return 0;
}

int api_json_check(const char *text, size_t len, api_error *err)
{
    checker c = { .s = (const unsigned char *)text, .len = len, .err = err };
    char buf[120];
    skip_ws(&c);
    if (c.pos == len)
        return fail(&c, c.pos, 0, "the document is empty, with no value in it");
    int want_value = 1;
    for (;;) {
        skip_ws(&c);
        if (want_value) {
            if (c.pos >= len)
                return fail(&c, c.pos, c.depth, "the text ends where a value should be");
            unsigned char b = c.s[c.pos];
            want_value = 0;
            if (b == '{' || b == '[') {
                if (c.depth == API_MAX_DEPTH) {
                    if (err) {
                        api_fail(err, API_ERR_LIMIT, "", "the document nests arrays and objects deeper than %d levels, the "
                                 "limit (at byte %zu)", API_MAX_DEPTH, c.pos);
                    }
                    return -1;
                }
                int top = c.depth++;
                c.is_obj[top] = b == '{';
                c.has_key[top] = 0;
                c.index[top] = 0;
                c.pos++;
                skip_ws(&c);
                if (c.pos < len && c.s[c.pos] == (b == '{' ? '}' : ']')) {
                    c.pos++;
                    c.depth--;
                } else if (b == '[') {
                    want_value = 1;
                } else if (key(&c)) {
                    return -1;
                } else {
                    want_value = 1;
                }
            } else if (b == '"') {
                if (string(&c, c.depth))
                    return -1;
            } else if (b == '-' || (b >= '0' && b <= '9')) {
                if (number(&c, c.depth))
                    return -1;
            } else {
                static const char *const lit[] = { "true", "false", "null" };
                size_t i = 0;
                while (i < 3 && !(len - c.pos >= strlen(lit[i]) && memcmp(c.s + c.pos, lit[i], strlen(lit[i])) == 0))
                    i++;
                if (i == 3)
                    return fail(&c, c.pos, c.depth, "a value should come here, not %s%s",
                                describe(b, buf, sizeof buf),
                                (b >= 'a' && b <= 'z') || (b >= 'A' && b <= 'Z')
                                    ? "; the words of JSON are true, false and null (no NaN, no Infinity)" : "");
                c.pos += strlen(lit[i]);
            }
            continue;
        }
        if (c.depth == 0) {
            if (c.pos < len)
                return fail(&c, c.pos, 0, "text after the end of the value: %s", describe(c.s[c.pos], buf, sizeof buf));
            return 0;
        }
        int top = c.depth - 1;
        const char *what = c.is_obj[top] ? "object" : "array";
        char close = c.is_obj[top] ? '}' : ']';
        if (c.pos >= len)
            return fail(&c, c.pos, top, "the text ends inside an %s", what);
        if (c.s[c.pos] == ',') {
            c.pos++;
            if (c.is_obj[top] && key(&c))
                return -1;
            c.index[top]++;
            want_value = 1;
        } else if (c.s[c.pos] == close) {
            c.pos++;
            c.depth--;
        } else {
            return fail(&c, c.pos, top, "a comma or a %s should follow a value in an %s, not %s",
                        c.is_obj[top] ? "closing brace" : "closing bracket", what,
                        describe(c.s[c.pos], buf, sizeof buf));
        }
    }
}

int api_eval_check(const double *values, const double *du, const double *dv, const double *dw, size_t n,
                   api_error *err)
{
    static const char *const names[4] = { "x(u, v, w)", "its derivative in u", "its derivative in v",
                                          "its derivative in w" };
    const double *arr[4] = { values, du, dv, dw };
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 4; a++)
            for (int k = 0; arr[a] && k < 3; k++)
                if (!isfinite(arr[a][3 * i + k])) {
                    char ptr[40];
                    snprintf(ptr, sizeof ptr, "/points/%zu", i);
                    return api_fail(err, API_ERR_DOCUMENT, ptr, "%s is not a finite number at this point: its %c component is %s; "
                                    "points far outside the unit cube can overflow a double", names[a], "xyz"[k],
                                    isnan(arr[a][3 * i + k]) ? "NaN" : "infinite");
                }
    return 0;
}
