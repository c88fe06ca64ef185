/*
 * test_strict.c: strict input (strict.h). api_json_check against a verdict
 * table that node's JSON.parse confirms, api_text_clean against node's
 * TextDecoder, error messages that stay valid UTF-8 whatever the input (by
 * our own decoder and by glibc's iconv), and eval results that are never
 * nan or inf in JSON.
 */
#include <errno.h>
#include <iconv.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cJSON.h>
#include <cmocka.h>

#include "model.h"
#include "output.h"
#include "strict.h"
#include "support.h"

/* UTF-8 decoded to code points, a way apart from strict.c's table of byte ranges. */
static int utf8_valid_by_decoding(const char *text, size_t n)
{
    const unsigned char *s = (const unsigned char *)text;
    for (size_t i = 0; i < n;) {
        unsigned c = s[i];
        size_t len;
        unsigned long cp, min;
        if (c < 0x80) {
            i++;
            continue;
        } else if ((c & 0xE0) == 0xC0) {
            len = 2, cp = c & 0x1F, min = 0x80;
        } else if ((c & 0xF0) == 0xE0) {
            len = 3, cp = c & 0x0F, min = 0x800;
        } else if ((c & 0xF8) == 0xF0) {
            len = 4, cp = c & 0x07, min = 0x10000;
        } else {
            return 0;
        }
        if (n - i < len)
            return 0;
        for (size_t k = 1; k < len; k++) {
            if ((s[i + k] & 0xC0) != 0x80)
                return 0;
            cp = cp << 6 | (s[i + k] & 0x3F);
        }
        if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
            return 0;
        i += len;
    }
    return 1;
}

/* glibc's opinion: the text converts from UTF-8 to UTF-32 without an error. */
static int iconv_valid(const char *text, size_t n)
{
    iconv_t cd = iconv_open("UTF-32LE", "UTF-8");
    assert_true(cd != (iconv_t)-1);
    char *in = (char *)text, out[4 * 1024];
    size_t inleft = n;
    int ok = 1;
    while (inleft > 0 && ok) {
        char *o = out;
        size_t oleft = sizeof out;
        if (iconv(cd, &in, &inleft, &o, &oleft) == (size_t)-1 && errno != E2BIG)
            ok = 0;
    }
    iconv_close(cd);
    return ok;
}

/* Valid UTF-8 by both, and no control characters: fit for a JSON string and a terminal. */
static void assert_clean_text(const char *what, const char *s)
{
    size_t n = strlen(s);
    if (!utf8_valid_by_decoding(s, n) || !iconv_valid(s, n))
        fail_msg("%s is not valid UTF-8", what);
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)s[i] < 0x20 || s[i] == 0x7f)
            fail_msg("%s holds the control character 0x%02X", what, (unsigned char)s[i]);
}

static void the_test_validators_should_refuse_what_utf8_forbids(void **state)
{
    (void)state;
    static const char *const bad[] = { "\xc0\x80", "\xc1\xbf", "\xe0\x80\xaf", "\xed\xa0\x80", "\xf0\x80\x80\xaf",
                                       "\xf4\x90\x80\x80", "\xf5\x80\x80\x80", "\x80", "\xc3", "\xe2\x82", "\xff" };
    static const char *const good[] = { "", "a", "\xc3\xa9", "\xe2\x82\xac", "\xf0\x9f\x98\x80", "\xf4\x8f\xbf\xbf",
                                        "\xed\x9f\xbf", "\xee\x80\x80" };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        assert_false(utf8_valid_by_decoding(bad[i], strlen(bad[i])));
        assert_false(iconv_valid(bad[i], strlen(bad[i])));
    }
    for (size_t i = 0; i < sizeof good / sizeof *good; i++) {
        assert_true(utf8_valid_by_decoding(good[i], strlen(good[i])));
        assert_true(iconv_valid(good[i], strlen(good[i])));
    }
}

/* Runs node on one line per input ("x" then the bytes in hex) and returns its line of output (free it). */
static char *node_run(const char *script, char *const *texts, const size_t *lens, size_t n)
{
    char path[] = "/tmp/pdesolid-strict-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    for (size_t i = 0; i < n; i++) {
        fputc('x', f);
        for (size_t k = 0; k < lens[i]; k++)
            fprintf(f, "%02x", (unsigned char)texts[i][k]);
        fputc('\n', f);
    }
    fclose(f);
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "node -e '%s' %s", script, path);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t cap = 64 + n * 1024, len = 0;
    char *out = malloc(cap);
    size_t got;
    while ((got = fread(out + len, 1, cap - 1 - len, p)) > 0)
        len += got;
    out[len] = '\0';
    assert_int_equal(pclose(p), 0);
    unlink(path);
    return out;
}

/* For each line, 1 if JSON.parse accepts the bytes as strict UTF-8 (TextDecoder fatal, BOM kept), else 0. */
static const char node_verdicts[] =
    "const L=require(\"fs\").readFileSync(process.argv[1],\"latin1\").split(\"\\n\").slice(0,-1);"
    "let o=\"\";for(const h of L){let ok=1;try{JSON.parse(new TextDecoder(\"utf-8\",{fatal:true,ignoreBOM:true})"
    ".decode(Buffer.from(h.slice(1),\"hex\")))}catch(e){ok=0}o+=ok}console.log(o)";

typedef struct {
    const char *text;
    size_t len;
    int ok;            /* api_json_check's verdict */
    int node_differs;  /* JSON.parse's verdict is the other one: an intended difference, said in why */
    const char *pointer;   /* the pointer of the fault, or NULL not to check it */
    long at;           /* the byte the message names, or -1 not to check it */
    const char *why;
} json_case;

#define T(s) s, sizeof s - 1
#define DEEP_OK ((const char *)1)    /* API_MAX_DEPTH nested arrays, built at run time */
#define DEEP_BAD ((const char *)2)   /* one more */

static const json_case json_cases[] = {
    { T("{}"), 1, 0, NULL, -1, "an empty object" },
    { T("[]"), 1, 0, NULL, -1, "an empty array" },
    { T(" \t\r\n[1, 2.5, -0, 0.0, -0.5e-3, 1E+9, 2e-999, 1e999] \n"), 1, 0, NULL, -1, "numbers, white space" },
    { T("123456789012345678901234567890123456789012345678901234567890123456789"), 1, 0, NULL, -1, "a big integer" },
    { T("0"), 1, 0, NULL, -1, "a lone zero" },
    { T("-0.0e+0"), 1, 0, NULL, -1, "every part of a number" },
    { T("\"\""), 1, 0, NULL, -1, "an empty string" },
    { T("\"\\\"\\\\\\/\\b\\f\\n\\r\\t\""), 1, 0, NULL, -1, "every short escape" },
    { T("\"\\u00e9\\u20AC\\ud83d\\ude00\\u0001\""), 1, 0, NULL, -1, "\\u escapes and a surrogate pair" },
    { T("\"a\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80\""), 1, 0, NULL, -1, "UTF-8 of 1, 2, 3 and 4 bytes" },
    { T("\"\xed\x9f\xbf\xee\x80\x80\xef\xbf\xbf\xf4\x8f\xbf\xbf\xc2\x80\""), 1, 0, NULL, -1,
      "the edges of UTF-8: U+D7FF, U+E000, U+FFFF, U+10FFFF, U+0080" },
    { T("\"\x7f\""), 1, 0, NULL, -1, "DEL is no control character to RFC 8259" },
    { T("true"), 1, 0, NULL, -1, "true" },
    { T("false"), 1, 0, NULL, -1, "false" },
    { T("null"), 1, 0, NULL, -1, "null" },
    { T("{\"a\":{\"b\":[{\"c\":null},[]],\"\":{}}}"), 1, 0, NULL, -1, "objects in arrays in objects" },
    { DEEP_OK, 0, 1, 0, NULL, -1, "nesting at the limit" },
    { T(""), 0, 0, "", 0, "nothing" },
    { T("  \n "), 0, 0, "", -1, "white space only" },
    { T("\0"), 0, 0, "", 0, "a raw NUL" },
    { T("[1,\0 2]"), 0, 0, "/1", 3, "a raw NUL taken for white space" },
    { T("{}\0"), 0, 0, "", 2, "a raw NUL after the value" },
    { T("[\"a\0b\"]"), 0, 0, "/0", 3, "a raw NUL in a string" },
    { T("\"\\u0000\""), 0, 1, "", 1, "JSON.parse accepts \\u0000; cJSON would cut the string there" },
    { T("{\"pde\\u0000junk\":1}"), 0, 1, "", 5, "JSON.parse accepts a NUL escape in a key" },
    { T("{\"a/b\":{\"m~n\":\"x\\u0000\"}}"), 0, 1, "/a~1b/m~0n", 16, "the pointer escapes / and ~" },
    { T("\"\\ud800\""), 0, 1, "", 1, "JSON.parse accepts a lone first half" },
    { T("\"\\udc00\""), 0, 1, "", 1, "JSON.parse accepts a lone second half" },
    { T("\"\\ud800\\u0041\""), 0, 1, "", 1, "JSON.parse accepts a first half before a non-surrogate" },
    { T("\"\\uD800\\uD800\""), 0, 1, "", 1, "JSON.parse accepts two first halves" },
    { T("\"\\ud800x\""), 0, 1, "", 1, "JSON.parse accepts a first half before a letter" },
    { T("\"\xc0\x80\""), 0, 0, "", 1, "an overlong NUL" },
    { T("\"\xc1\xbf\""), 0, 0, "", 1, "an overlong of two bytes" },
    { T("\"\xe0\x80\xaf\""), 0, 0, "", 1, "an overlong of three bytes" },
    { T("\"\xf0\x80\x80\xaf\""), 0, 0, "", 1, "an overlong of four bytes" },
    { T("\"\xed\xa0\x80\""), 0, 0, "", 1, "an encoded surrogate" },
    { T("\"\xf5\x80\x80\x80\""), 0, 0, "", 1, "F5, past U+10FFFF" },
    { T("\"\xf4\x90\x80\x80\""), 0, 0, "", 1, "U+110000" },
    { T("\"ab\xff\""), 0, 0, "", 3, "FF" },
    { T("\"\x80\""), 0, 0, "", 1, "a lone continuation byte" },
    { T("\"\xc3\""), 0, 0, "", 1, "a two-byte character cut short" },
    { T("\"\xe2\x82\""), 0, 0, "", 1, "a three-byte character cut short" },
    { T("{\"\\u00e9\":[0,\"\xff\"]}"), 0, 0, "/\xc3\xa9/1", 14, "a pointer through a non-ASCII key" },
    { T("\xc3\xa9"), 0, 0, "", 0, "UTF-8 outside a string" },
    { T("\xef\xbb\xbf{}"), 0, 0, "", 0, "a byte order mark" },
    { T("\"a\tb\""), 0, 0, "", 2, "a raw tab in a string" },
    { T("\"a\nb\""), 0, 0, "", 2, "a raw line feed in a string" },
    { T("01"), 0, 0, "", 0, "a leading zero" },
    { T("-01"), 0, 0, "", 0, "a leading zero after a minus" },
    { T("0001"), 0, 0, "", 0, "leading zeros" },
    { T("{\"pde\":{\"a\":[1,01]}}"), 0, 0, "/pde/a/1", 15, "the pointer of a number" },
    { T("1."), 0, 0, "", 2, "no digit after the point" },
    { T(".5"), 0, 0, "", 0, "no digit before the point" },
    { T("+1"), 0, 0, "", 0, "a plus sign" },
    { T("1e"), 0, 0, "", 2, "no exponent" },
    { T("1e+"), 0, 0, "", 3, "no exponent after its sign" },
    { T("-"), 0, 0, "", 1, "a minus alone" },
    { T("0x10"), 0, 0, "", 1, "hex" },
    { T("NaN"), 0, 0, "", 0, "NaN" },
    { T("Infinity"), 0, 0, "", 0, "Infinity" },
    { T("[-Infinity]"), 0, 0, "/0", 2, "-Infinity" },
    { T("tRue"), 0, 0, "", 0, "a capital in true" },
    { T("[1,]"), 0, 0, "/1", 3, "a trailing comma in an array" },
    { T("{\"a\":1,}"), 0, 0, "", 7, "a trailing comma in an object" },
    { T("[1 2]"), 0, 0, "", 3, "no comma" },
    { T("{\"a\" 1}"), 0, 0, "", 5, "no colon" },
    { T("{a:1}"), 0, 0, "", 1, "a bare key" },
    { T("{'a':1}"), 0, 0, "", 1, "single quotes" },
    { T("[[1],[2,+1]]"), 0, 0, "/1/1", 8, "the pointer in nested arrays" },
    { T("// c\n{}"), 0, 0, "", 0, "a line comment" },
    { T("{} /* c */"), 0, 0, "", 3, "a block comment" },
    { T("{} x"), 0, 0, "", 3, "trailing garbage" },
    { T("{}{}"), 0, 0, "", 2, "two values" },
    { T("[1]]"), 0, 0, "", 3, "one bracket too many" },
    { T("{"), 0, 0, "", 1, "an object cut short" },
    { T("[1,"), 0, 0, "/1", 3, "an array cut short after a comma" },
    { T("{\"a\":"), 0, 0, "/a", 5, "an object cut short after a colon" },
    { T("{\"pde\":}"), 0, 0, "/pde", 7, "no value after a colon" },
    { T("\"abc"), 0, 0, "", 4, "a string cut short" },
    { T("\"\\u12"), 0, 0, "", 1, "an escape cut short" },
    { T("tru"), 0, 0, "", 0, "true cut short" },
    { T("{\"a\""), 0, 0, "", 4, "a key cut short" },
    { T("\"\\x41\""), 0, 0, "", 1, "an unknown escape" },
    { T("\"\\U0041\""), 0, 0, "", 1, "a capital U escape" },
    { DEEP_BAD, 0, 0, 1, "", API_MAX_DEPTH, "JSON.parse takes any depth; the limit is ours" },
};

/* The case's text: its own, or the deep ones built (free the result). */
static char *case_text(const json_case *c, size_t *len)
{
    if (c->text != DEEP_OK && c->text != DEEP_BAD) {
        char *t = malloc(c->len ? c->len : 1);
        memcpy(t, c->text, c->len);   /* an exact-size copy: ASan sees any over-read */
        *len = c->len;
        return t;
    }
    size_t d = API_MAX_DEPTH + (c->text == DEEP_BAD);
    char *t = malloc(2 * d);
    memset(t, '[', d);
    memset(t + d, ']', d);
    *len = 2 * d;
    return t;
}

static void json_check_should_follow_rfc8259_strictly_as_node_does(void **state)
{
    (void)state;
    size_t n = sizeof json_cases / sizeof *json_cases;
    assert_true(n >= 40);
    char **texts = calloc(n, sizeof *texts);
    size_t *lens = calloc(n, sizeof *lens);
    for (size_t i = 0; i < n; i++) {
        const json_case *c = &json_cases[i];
        texts[i] = case_text(c, &lens[i]);
        api_error err;
        memset(&err, 'x', sizeof err);
        int rc = api_json_check(texts[i], lens[i], &err);
        if ((rc == 0) != c->ok)
            fail_msg("case %zu (%s): got %d: %s", i, c->why, rc, rc ? err.message : "");
        if (rc == 0)
            continue;
        assert_int_equal(err.status, c->text == DEEP_BAD ? API_ERR_LIMIT : API_ERR_NOT_JSON);
        /* The message repeats none of the input: it is ASCII, whatever the input. */
        for (const char *m = err.message; *m; m++)
            if ((unsigned char)*m < 0x20 || (unsigned char)*m >= 0x7f)
                fail_msg("case %zu (%s): a byte 0x%02X in the message %s", i, c->why, (unsigned char)*m, err.message);
        assert_clean_text("the pointer", err.pointer);
        if (c->pointer && strcmp(err.pointer, c->pointer) != 0)
            fail_msg("case %zu (%s): pointer \"%s\", want \"%s\" (%s)", i, c->why, err.pointer, c->pointer, err.message);
        char at[32];
        snprintf(at, sizeof at, "byte %ld", c->at);
        if (c->at >= 0 && !strstr(err.message, at))
            fail_msg("case %zu (%s): want %s in: %s", i, c->why, at, err.message);
    }
    char *node = node_run(node_verdicts, texts, lens, n);
    assert_true(strlen(node) == n + 1);
    for (size_t i = 0; i < n; i++)
        if ((node[i] == '1') != (json_cases[i].ok != json_cases[i].node_differs))
            fail_msg("case %zu (%s): JSON.parse says %c", i, json_cases[i].why, node[i]);
    free(node);
    for (size_t i = 0; i < n; i++)
        free(texts[i]);
    free(texts);
    free(lens);
}

static void json_check_should_say_where_and_what_is_wrong(void **state)
{
    (void)state;
    api_error err;
    const char *t = "{\n  \"pde\": 01\n}";
    assert_int_equal(api_json_check(t, strlen(t), &err), -1);
    assert_string_equal(err.pointer, "/pde");
    assert_non_null(strstr(err.message, "leading zero"));
    assert_non_null(strstr(err.message, "line 2, column 10 (byte 11)"));
    assert_int_equal(api_json_check(t, 3, &err), -1);
    assert_non_null(strstr(err.message, "the end of the text"));
    assert_int_equal(api_json_check("{}", 2, NULL), 0);
    assert_int_equal(api_json_check("{", 1, NULL), -1);
    /* Each way UTF-8 goes wrong, in words. */
    static const char *const utf8[][2] = {
        { "\"\xc0\x80\"", "overlong" }, { "\"\xe0\x80\xaf\"", "overlong" }, { "\"\xf0\x8f\xbf\xbf\"", "overlong" },
        { "\"\xed\xa0\x80\"", "surrogate" }, { "\"\xf4\x90\x80\x80\"", "past U+10FFFF" },
        { "\"\xc3\"", "breaks off" }, { "\"\xe2\x82\"", "breaks off" }, { "\"\x80\"", "continues no character" },
        { "\"\xf8\x88\x80\x80\x80\"", "never UTF-8" },
    };
    for (size_t i = 0; i < sizeof utf8 / sizeof *utf8; i++) {
        assert_int_equal(api_json_check(utf8[i][0], strlen(utf8[i][0]), &err), -1);
        if (!strstr(err.message, utf8[i][1]) || !strstr(err.message, "(byte 1)"))
            fail_msg("case %zu: %s", i, err.message);
    }
}

typedef struct {
    const char *in;
    size_t n, outn;
    const char *out;
} clean_case;

static void text_clean_should_replace_bad_bytes_and_cut_at_characters(void **state)
{
    (void)state;
#define R "\xef\xbf\xbd"
    static const clean_case cases[] = {
        { T("abc"), 64, "abc" },
        { T("a\nb\x7f"), 64, "a" R "b" R },
        { T("a\0b"), 64, "a" R "b" },
        { T("\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80"), 64, "\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80" },
        { T("\xc0\x80"), 64, R R },                  /* C0 starts nothing: each byte is one U+FFFD */
        { T("\xe2\x82"), 64, R },                    /* a maximal subpart is one U+FFFD */
        { T("\xe2\x82x"), 64, R "x" },
        { T("\xed\xa0\x80"), 64, R R R },            /* ED A0 is no start of a character */
        { T("\xf4\x90\x80\x80"), 64, R R R R },
        { T("\xf0\x9f\x98"), 64, R },
        { T("a\xc3\xa9\xc3\xa9"), 4, "a\xc3\xa9" },   /* cut before a character that does not fit */
        { T("a\xc3\xa9"), 3, "a" },
        { T("\xff"), 3, "" },
        { T("abc"), 1, "" },
        { T(""), 8, "" },
    };
#undef R
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        char out[64];
        memset(out, 'x', sizeof out);
        size_t w = api_text_clean(out, cases[i].outn, cases[i].in, cases[i].n);
        if (w != strlen(cases[i].out) || strcmp(out, cases[i].out) != 0)
            fail_msg("case %zu: got %zu bytes", i, w);
    }
}

static uint64_t rng = 0x9E3779B97F4A7C15u;

static unsigned rnd(unsigned n)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (unsigned)(rng % n);
}

/* Random bytes, leaning to the ones UTF-8 and JSON care about. */
static size_t random_bytes(char *buf, size_t max)
{
    static const unsigned char pick[] = { 0x00, 0x09, 0x0a, 0x1f, '"', '\\', 'u', '0', 'd', '{', '}', '[', ']', ':',
                                          ',', 'a', 0x7f, 0x80, 0xbf, 0xc0, 0xc1, 0xc2, 0xc3, 0xdf, 0xe0, 0xe2,
                                          0xed, 0xef, 0xf0, 0xf4, 0xf5, 0xff, 0xa0, 0x9f, 0x90, 0x8f };
    size_t n = rnd((unsigned)max);
    for (size_t i = 0; i < n; i++)
        buf[i] = (char)(rnd(3) ? pick[rnd(sizeof pick)] : rnd(256));
    return n;
}

static void text_clean_should_agree_with_node_textdecoder(void **state)
{
    (void)state;
    /* TextDecoder replaces maximal subparts as WHATWG's Encoding standard says; then the control characters. */
    static const char script[] =
        "const L=require(\"fs\").readFileSync(process.argv[1],\"latin1\").split(\"\\n\").slice(0,-1);"
        "for(const h of L){const s=new TextDecoder().decode(Buffer.from(h.slice(1),\"hex\"))"
        ".replace(/[\\x00-\\x1f\\x7f]/g,\"\\ufffd\");console.log(Buffer.from(s).toString(\"hex\"))}";
    enum { N = 400 };
    char *texts[N];
    size_t lens[N];
    for (size_t i = 0; i < N; i++) {
        texts[i] = malloc(48);
        lens[i] = random_bytes(texts[i], 48);
    }
    char *node = node_run(script, texts, lens, N), *line = node;
    for (size_t i = 0; i < N; i++) {
        char out[48 * 3 + 1], hex[sizeof out * 2 + 1] = "";
        size_t w = api_text_clean(out, sizeof out, texts[i], lens[i]);
        for (size_t k = 0; k < w; k++)
            sprintf(hex + 2 * k, "%02x", (unsigned char)out[k]);
        char *nl = strchr(line, '\n');
        assert_non_null(nl);
        *nl = '\0';
        if (strcmp(hex, line) != 0)
            fail_msg("input %zu: ours %s, node's %s", i, hex, line);
        assert_clean_text("the cleaned text", out);
        line = nl + 1;
        free(texts[i]);
    }
    free(node);
}

/* Every error of every parser: valid UTF-8 and no control characters, in the message and the pointer. */
static void check_all_parsers(const char *text, size_t len)
{
    char *copy = malloc(len ? len : 1);
    memcpy(copy, text, len);
    api_error err;
    api_model *m = api_model_parse(copy, len, &err);
    if (!m) {
        assert_clean_text("a model error", err.message);
        assert_clean_text("a model error's pointer", err.pointer);
    }
    api_model_free(m);
    double *p = NULL;
    size_t n;
    int d;
    if (api_eval_parse(copy, len, 10, &p, &n, &d, &err)) {
        assert_clean_text("an eval error", err.message);
        assert_clean_text("an eval error's pointer", err.pointer);
    }
    free(p);
    p = NULL;
    if (api_points_parse(copy, len, &p, &n, &err)) {
        assert_clean_text("a points error", err.message);
        assert_clean_text("a points error's pointer", err.pointer);
    }
    free(p);
    free(copy);
}

/* A random character as UTF-8: ASCII, controls and every length, surrogates left out. */
static size_t random_char(char *out)
{
    static const unsigned long base[] = { 0x20, 0x1, 0x80, 0x800, 0xE000, 0x10000, 0x10FF00 };
    static const unsigned long span[] = { 0x5F, 0x1F, 0x780, 0xD000, 0x2000, 0xFFFF, 0xFF };
    int k = (int)rnd(7);
    unsigned long cp = base[k] + rnd((unsigned)span[k]);
    if (cp < 0x80) {
        out[0] = (char)cp;
        return 1;
    }
    if (cp < 0x800) {
        out[0] = (char)(0xC0 | cp >> 6), out[1] = (char)(0x80 | (cp & 0x3F));
        return 2;
    }
    if (cp < 0x10000) {
        out[0] = (char)(0xE0 | cp >> 12), out[1] = (char)(0x80 | (cp >> 6 & 0x3F)), out[2] = (char)(0x80 | (cp & 0x3F));
        return 3;
    }
    out[0] = (char)(0xF0 | cp >> 18), out[1] = (char)(0x80 | (cp >> 12 & 0x3F));
    out[2] = (char)(0x80 | (cp >> 6 & 0x3F)), out[3] = (char)(0x80 | (cp & 0x3F));
    return 4;
}

/* A JSON string of random valid characters (controls escaped), which passes the check and reaches the schema. */
static size_t random_json_string(char *out, size_t max_chars)
{
    size_t w = 0, n = rnd((unsigned)max_chars) + 1;
    out[w++] = '"';
    for (size_t i = 0; i < n; i++) {
        char ch[4];
        size_t k = random_char(ch);
        if (k == 1 && ((unsigned char)ch[0] < 0x20 || ch[0] == '"' || ch[0] == '\\'))
            w += (size_t)sprintf(out + w, "\\u%04x", (unsigned char)ch[0]);
        else
            memcpy(out + w, ch, k), w += k;
    }
    out[w++] = '"';
    out[w] = '\0';
    return w;
}

/* Appends a random JSON-like value at buf + *w (at most about 600 bytes), mostly valid, sometimes not. */
static void random_json(char *buf, size_t *w, int depth)
{
    static const char *const ws[] = { "", "", " ", "\n", "\t", "\r", " \r\n ", "\f", "\v" };
    static const char *const numbers[] = { "0", "-0", "1", "-12", "3.25", "1e5", "1E+2", "-0.0e-7", "123456789012345678901234",
                                           "01", "1.", ".5", "+1", "-", "1e", "0x1", "1.5e+", "00", "-01.5" };
    static const char *const lits[] = { "true", "false", "null", "nul", "True", "NaN", "Infinity", "truex" };
    static const char *const pieces[] = { "a", "\\n", "\\\"", "\\/", "\\u0041", "\\u00e9", "\\ud83d\\ude00", "\\ud800",
                                          "\\udc00", "\\u0000", "\\uDBFF\\uDFFF", "\\x", "\\u12G4", "\xc3\xa9",
                                          "\xe2\x82\xac", "\xf0\x9f\x98\x80", "\xff", "\xc0\x80", "\xed\xa0\x80",
                                          "\x7f", "\t", "\x01", "/", "~" };
    *w += (size_t)sprintf(buf + *w, "%s", ws[rnd(sizeof ws / sizeof *ws)]);
    unsigned kind = rnd(depth > 4 ? 3 : 4);
    if (kind == 0) {
        *w += (size_t)sprintf(buf + *w, "%s", numbers[rnd(sizeof numbers / sizeof *numbers)]);
    } else if (kind == 1) {
        *w += (size_t)sprintf(buf + *w, "%s", lits[rnd(sizeof lits / sizeof *lits)]);
    } else if (kind == 2) {
        buf[(*w)++] = '"';
        for (unsigned i = rnd(4); i > 0; i--)
            *w += (size_t)sprintf(buf + *w, "%s", pieces[rnd(sizeof pieces / sizeof *pieces)]);
        buf[(*w)++] = '"';
    } else {
        int obj = (int)rnd(2);
        buf[(*w)++] = obj ? '{' : '[';
        for (unsigned i = rnd(4), first = 1; i > 0; i--, first = 0) {
            if (!first)
                buf[(*w)++] = ',';
            if (obj)
                *w += (size_t)sprintf(buf + *w, "%s\"%s\"%s:", ws[rnd(3)], pieces[rnd(sizeof pieces / sizeof *pieces)],
                                      ws[rnd(3)]);
            random_json(buf, w, depth + 1);
        }
        *w += (size_t)sprintf(buf + *w, "%s%c", ws[rnd(3)], obj ? '}' : ']');
    }
    *w += (size_t)sprintf(buf + *w, "%s", ws[rnd(3)]);
}

static void json_check_should_agree_with_node_on_random_documents(void **state)
{
    (void)state;
    enum { N = 3000 };
    char **texts = calloc(N, sizeof *texts);
    size_t *lens = calloc(N, sizeof *lens);
    for (size_t i = 0; i < N; i++) {
        static char buf[1 << 17];   /* far more than 3^5 leaves of at most 100 bytes need */
        size_t w = 0;
        random_json(buf, &w, 0);
        for (unsigned k = rnd(6) == 0 ? rnd(3) + 1 : 0; k > 0 && w > 0; k--) {   /* mutate a few */
            size_t at = rnd((unsigned)w);
            unsigned op = rnd(3);
            if (op == 0)
                memmove(buf + at, buf + at + 1, --w - at);
            else if (op == 1)
                memmove(buf + at + 1, buf + at, w++ - at), buf[at] = (char)rnd(256);
            else
                buf[at] = (char)rnd(256);
        }
        texts[i] = malloc(w ? w : 1);
        memcpy(texts[i], buf, w);
        lens[i] = w;
    }
    char *node = node_run(node_verdicts, texts, lens, N);
    assert_true(strlen(node) == N + 1);
    size_t accepted = 0, differ = 0;
    for (size_t i = 0; i < N; i++) {
        api_error err;
        int ours = api_json_check(texts[i], lens[i], &err) == 0;
        accepted += ours;
        if (ours == (node[i] == '1'))
            continue;
        /* The intended differences: JSON.parse takes \u0000 and unpaired surrogate escapes. */
        if (ours || (!strstr(err.message, "\\u0000") && !strstr(err.message, "surrogate pair")))
            fail_msg("document %zu: ours %d, JSON.parse %c: %s", i, ours, node[i], ours ? "" : err.message);
        differ++;
    }
    /* Enough of both kinds for the comparison to mean something. */
    if (accepted < N / 5 || accepted > N * 4 / 5 || differ == 0)
        fail_msg("%zu of %d accepted, %zu intended differences", accepted, N, differ);
    free(node);
    for (size_t i = 0; i < N; i++)
        free(texts[i]);
    free(texts);
    free(lens);
}

static void errors_should_be_valid_utf8_whatever_the_input(void **state)
{
    (void)state;
    static const char *const frames[] = {
        "{\"preset\":%s}", "{\"template\":%s}", "{\"preset\":\"fig4a\",\"params\":{%s:1}}",
        "{\"template\":\"example4\",\"params\":{%s:[1,2,3]}}", "{%s:{}}", "{\"pde\":{%s:[1,1,1]}}",
        "{\"points\":[],%s:1}", "{\"points\":[[1,2,3]],\"derivatives\":%s}",
        "{\"pde\":{\"a\":[1,1,1],\"b\":[1,1,1],\"c\":[1,1,1]},\"boundary\":{\"x\":[{\"u\":{%s:1}}]}}",
    };
    char buf[4096], s[2048];
    for (int i = 0; i < 3000; i++) {
        size_t len;
        if (i % 3 == 0) {
            len = random_bytes(buf, 200);
        } else if (i % 3 == 1) {
            /* a valid frame with random bytes written over some of it */
            len = (size_t)snprintf(buf, sizeof buf, frames[rnd(sizeof frames / sizeof *frames)], "\"k\"");
            for (int k = (int)rnd(4); k >= 0; k--)
                buf[rnd((unsigned)len)] = rnd(2) ? (char)rnd(256) : "\0\xff\xc3\"\\0"[rnd(6)];
            if (rnd(4) == 0)
                len = rnd((unsigned)len + 1);
        } else {
            /* a checked-valid frame quoting a long random key or name: the schema's messages quote it */
            random_json_string(s, rnd(2) ? 8 : 120);
            len = (size_t)snprintf(buf, sizeof buf, frames[rnd(sizeof frames / sizeof *frames)], s);
        }
        check_all_parsers(buf, len);
    }
}

static void long_non_ascii_names_should_be_cut_at_a_character(void **state)
{
    (void)state;
    /* 59 ASCII bytes and then two-byte characters: %.60s cuts one in half. */
    char name[128] = "";
    memset(name, 'a', 59);
    for (int i = 0; i < 10; i++)
        strcat(name, "\xc3\xa9");
    static const char *const frames[] = { "{\"preset\":\"%s\"}", "{\"template\":\"%s\"}",
                                          "{\"preset\":\"fig4a\",\"params\":{\"%s\":1}}",
                                          "{\"preset\":\"fig4a\",\"params\":{\"%s\":1,\"%s\":2}}",
                                          "{\"pde\":{},\"%s\":1}" };
    for (size_t i = 0; i < sizeof frames / sizeof *frames; i++) {
        char text[512];
        snprintf(text, sizeof text, frames[i], name, name);
        api_error err;
        assert_null(api_model_parse(text, strlen(text), &err));
        assert_int_equal(err.status, API_ERR_DOCUMENT);
        assert_clean_text("the message", err.message);
        assert_clean_text("the pointer", err.pointer);
        /* model.c quotes whole characters; template.c's %.60s half a one, which becomes U+FFFD */
        assert_non_null(strstr(err.message, i < 2 || i == 4 ? "aaa\xc3\xa9" : "aaa"));
    }
}

static void eval_check_should_name_the_first_point_that_is_not_finite(void **state)
{
    (void)state;
    double v[9] = { 1, 2, 3, 4, 5, 6, 7, 8, 9 }, du[9] = { 0 }, dv[9] = { 0 }, dw[9] = { 0 };
    api_error err;
    assert_int_equal(api_eval_check(v, du, dv, dw, 3, &err), 0);
    assert_int_equal(api_eval_check(v, NULL, NULL, NULL, 3, &err), 0);
    assert_int_equal(api_eval_check(NULL, NULL, NULL, NULL, 0, &err), 0);
    dw[7] = -INFINITY;
    assert_int_equal(api_eval_check(v, du, dv, dw, 3, &err), -1);
    assert_string_equal(err.pointer, "/points/2");
    assert_int_equal(err.status, API_ERR_DOCUMENT);
    assert_non_null(strstr(err.message, "derivative in w"));
    assert_int_equal(api_eval_check(v, du, dv, NULL, 3, &err), 0);   /* dw not asked for */
    v[4] = NAN;
    assert_int_equal(api_eval_check(v, du, dv, dw, 3, &err), -1);
    assert_string_equal(err.pointer, "/points/1");
    assert_non_null(strstr(err.message, "not a finite number"));
    /* A real solid far outside the unit cube: fig4a's sin(3 pi w) and t^1 terms overflow. */
    const char *req = "{\"preset\":\"fig4a\"}";
    api_model *m = api_model_parse(req, strlen(req), &err);
    assert_non_null(m);
    pde_solution *sol;
    assert_int_equal(api_solve(m, &sol, &err), 0);
    api_model_free(m);
    double pts[6] = { 0.5, 0.25, 0.5, 1e300, 1e300, 1e300 }, x[6];
    for (int i = 0; i < 2; i++)
        pde_eval(sol, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], x + 3 * i);
    pde_solution_free(sol);
    assert_true(isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]));
    assert_false(isfinite(x[3]) && isfinite(x[4]) && isfinite(x[5]));
    assert_int_equal(api_eval_check(x, NULL, NULL, NULL, 2, &err), -1);
    assert_string_equal(err.pointer, "/points/1");
    assert_int_equal(api_eval_check(x, NULL, NULL, NULL, 1, &err), 0);
}

static void eval_json_should_write_null_for_what_is_not_finite(void **state)
{
    (void)state;
    double v[6] = { 1.5, NAN, -NAN, INFINITY, -INFINITY, -2.25 }, du[6] = { 0, 0, 0, 0, 0, NAN };
    char *s = api_eval_json("abc", v, du, NULL, NULL, 2);
    assert_non_null(s);
    assert_null(strstr(s, "nan"));
    assert_null(strstr(s, "inf"));
    assert_int_equal(api_json_check(s, strlen(s), NULL), 0);
    cJSON *root = cJSON_Parse(s);
    assert_non_null(root);
    cJSON *vals = cJSON_GetObjectItemCaseSensitive(root, "values");
    assert_int_equal(cJSON_GetArraySize(vals), 2);
    assert_true(cJSON_GetArrayItem(cJSON_GetArrayItem(vals, 0), 0)->valuedouble == 1.5);
    for (int k = 1; k < 3; k++)
        assert_true(cJSON_IsNull(cJSON_GetArrayItem(cJSON_GetArrayItem(vals, 0), k)));
    for (int k = 0; k < 2; k++)
        assert_true(cJSON_IsNull(cJSON_GetArrayItem(cJSON_GetArrayItem(vals, 1), k)));
    assert_true(cJSON_GetArrayItem(cJSON_GetArrayItem(vals, 1), 2)->valuedouble == -2.25);
    assert_true(cJSON_IsNull(cJSON_GetArrayItem(cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, "du"), 1), 2)));
    assert_null(cJSON_GetObjectItemCaseSensitive(root, "dv"));
    cJSON_Delete(root);
    free(s);
}

/* Runs `bin args` in dir; returns the exit status, with stdout and stderr in *out and *err (free them). */
static int run_cli(const char *dir, const char *bin, const char *args, char **out, char **err)
{
    char cmd[2048], path[256];
    snprintf(cmd, sizeof cmd, "cd %s && %s %s >out 2>err", dir, bin, args);
    int st = system(cmd);
    assert_true(WIFEXITED(st));
    snprintf(path, sizeof path, "%s/out", dir);
    *out = read_file(path, NULL);
    snprintf(path, sizeof path, "%s/err", dir);
    *err = read_file(path, NULL);
    assert_non_null(*out);
    assert_non_null(*err);
    return WEXITSTATUS(st);
}

/* The CLI's eval refuses a point whose value overflows, offline and through a server, like a bad document:
 * exit 2, the point, and nothing on standard output. */
static void cli_eval_should_refuse_points_whose_values_are_not_finite(void **state)
{
    (void)state;
    const char *name = getenv("PDESOLID_SAN") ? getenv("PDESOLID_SAN") : "build/san/pdesolid";
    const char *dname = getenv("PDESOLIDD_SAN") ? getenv("PDESOLIDD_SAN") : "build/san/pdesolidd";
    char bin[4096];
    if (!realpath(name, bin) || access(dname, X_OK) != 0) {
        fprintf(stderr, "test_strict: no %s or %s; run `make test`\n", name, dname);
        skip();
    }
    char dir[] = "/tmp/pdesolid-strict-XXXXXX";
    assert_int_equal(tmpdir_make(dir), 0);
    char path[256], args[512], *out, *err;
    snprintf(path, sizeof path, "%s/pts.json", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("[[0.5,0.5,0.5],[1e300,1e300,1e300]]", f);
    fclose(f);
    assert_int_equal(run_cli(dir, bin, "eval --preset fig4a pts.json", &out, &err), 2);
    if (!strstr(err, "pts.json: /1: x(u, v, w) is not a finite number"))
        fail_msg("stderr: %s", err);
    assert_string_equal(out, "");
    free(out);
    free(err);
    daemon_t d;
    daemon_start(&d, dir, "");
    snprintf(args, sizeof args, "eval --server %s --preset fig4a pts.json", d.base);
    int st = run_cli(dir, bin, args, &out, &err);
    daemon_stop(&d);
    /* /1 from the CLI on the server's null, or /points/1 from a server that refuses the point itself */
    if (st != 2 || !strstr(err, "/1: x(u, v, w) is not a finite number"))
        fail_msg("status %d, stderr: %s", st, err);
    assert_string_equal(out, "");
    free(out);
    free(err);
    assert_int_equal(tmpdir_remove(dir), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_test_validators_should_refuse_what_utf8_forbids),
        cmocka_unit_test(json_check_should_follow_rfc8259_strictly_as_node_does),
        cmocka_unit_test(json_check_should_say_where_and_what_is_wrong),
        cmocka_unit_test(json_check_should_agree_with_node_on_random_documents),
        cmocka_unit_test(text_clean_should_replace_bad_bytes_and_cut_at_characters),
        cmocka_unit_test(text_clean_should_agree_with_node_textdecoder),
        cmocka_unit_test(errors_should_be_valid_utf8_whatever_the_input),
        cmocka_unit_test(long_non_ascii_names_should_be_cut_at_a_character),
        cmocka_unit_test(eval_check_should_name_the_first_point_that_is_not_finite),
        cmocka_unit_test(eval_json_should_write_null_for_what_is_not_finite),
        cmocka_unit_test(cli_eval_should_refuse_points_whose_values_are_not_finite),
    };
    test_filter_from_env();
    return cmocka_run_group_tests_name("strict", tests, NULL, NULL);
}
