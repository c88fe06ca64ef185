/*
 * host.c: the Host header against --allow-host (host.h). A header is split
 * into its host and port as RFC 9110 writes it (uri-host [":" port]); what
 * does not split so, or names neither an address nor a name, is refused
 * unless the list is "*".
 */
#include <arpa/inet.h>
#include <string.h>
#include <strings.h>

#include "config.h"
#include "host.h"

static int label_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
}

/* n bytes of s are labels of letters, digits, '-' and '_', separated by dots. */
static int name_ok(const char *s, size_t n)
{
    size_t label = 0;
    for (size_t i = 0; i < n; i++) {
        if (s[i] != '.' && !label_char(s[i]))
            return 0;
        if (s[i] == '.' && !label)
            return 0;   /* an empty label */
        label = s[i] == '.' ? 0 : label + 1;
    }
    return label > 0;
}

/* An item of n bytes of the list, *item moved past its leading dot (.NAME: NAME and the names under it, *under
 * set); its length without that dot and a trailing one. */
static size_t strip(const char **item, size_t n, int *under)
{
    *under = n && **item == '.';
    if (*under)
        ++*item, n--;
    if (n && (*item)[n - 1] == '.')
        n--;
    return n;
}

int srv_host_list_check(const char *list)
{
    if (!*list)
        return 0;
    const char *item;
    int under;
    for (const char *p = list; p;) {
        size_t n = srv_config_item(p, &item, &p);
        if (n == 1 && *item == '*')
            continue;
        n = strip(&item, n, &under);
        if (!name_ok(item, n))
            return -1;
    }
    return 0;
}

/* Whether list allows the name of n bytes (its trailing dot removed); "*" allows anything, an empty name too. */
static int listed(const char *list, const char *name, size_t n)
{
    const char *item;
    int under;
    for (const char *p = list; p;) {
        size_t len = srv_config_item(p, &item, &p);
        if (len == 1 && *item == '*')
            return 1;
        if (!(len = strip(&item, len, &under)))
            continue;
        if (n == len && !strncasecmp(name, item, len))
            return 1;
        if (under && n > len && name[n - len - 1] == '.' && !strncasecmp(name + n - len, item, len))
            return 1;
    }
    return 0;
}

enum { MALFORMED, ADDRESS, NAME };

/* What host (a Host header's value) names: an IPv4 or bracketed IPv6 ADDRESS, or a NAME of *n bytes at its start
 * without its trailing dot; each with an optional :PORT. Anything else, a name with a character DNS names do not
 * hold among them, is MALFORMED. */
static int split(const char *host, size_t *n)
{
    char text[64];
    unsigned char addr[16];
    const char *port;
    if (*host == '[') {   /* an IPv6 address: nothing else is bracketed */
        const char *close = strchr(host, ']');
        *n = close ? (size_t)(close - host - 1) : sizeof text;
        if (*n >= sizeof text)
            return MALFORMED;
        memcpy(text, host + 1, *n);
        text[*n] = '\0';
        if (inet_pton(AF_INET6, text, addr) != 1)
            return MALFORMED;
        port = close + 1;
    } else {
        *n = strcspn(host, ":");
        port = host + *n;
    }
    if (*port && (*port != ':' || strspn(port + 1, "0123456789") != strlen(port + 1)))
        return MALFORMED;
    if (*host == '[')
        return ADDRESS;
    if (*n && host[*n - 1] == '.')
        --*n;
    if (!name_ok(host, *n))
        return MALFORMED;
    if (*n >= sizeof text)
        return NAME;   /* longer than any address */
    memcpy(text, host, *n);
    text[*n] = '\0';
    return inet_pton(AF_INET, text, addr) == 1 ? ADDRESS : NAME;
}

size_t srv_host_name(const char *host)
{
    size_t n;
    return host && split(host, &n) == NAME ? n : 0;
}

int srv_host_allowed(const char *list, const char *host)
{
    if (!host)
        return 1;   /* HTTP/1.0 without Host, which no browser sends */
    size_t n;
    switch (split(host, &n)) {
    case ADDRESS:
        return 1;
    case NAME:
        return listed(".localhost", host, n) || listed(list, host, n);
    default:
        return listed(list, "", 0);   /* only * allows what is not a host */
    }
}
