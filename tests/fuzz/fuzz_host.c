/*
 * fuzz_host.c: the Host header against an --allow-host list (server/host.c).
 * The input is the list, a newline, then the header's value (up to the first
 * NUL or newline; no newline: the list is empty). A list that
 * srv_host_list_check refuses is replaced by the empty list, as the daemon
 * would not start with it. Invariants: "*" allows every value; a value and
 * its upper-case spelling are allowed alike; an IP literal and no header
 * are allowed by the empty list; and where srv_host_name names a host (the
 * 403's suggestion "--allow-host NAME"), that name is a valid list, and the
 * list of it, and of it with a leading dot, allow the value.
 */
#include <arpa/inet.h>
#include <ctype.h>

#include "fuzz.h"
#include "host.h"

#define MAX_LEN 300

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char list[MAX_LEN + 1] = "", host[MAX_LEN + 1], upper[MAX_LEN + 1], name[MAX_LEN + 2];
    if (size > 2 * MAX_LEN)
        return 0;
    const uint8_t *nl = memchr(data, '\n', size);
    size_t ll = nl ? (size_t)(nl - data) : 0, at = nl ? ll + 1 : 0;
    if (ll > MAX_LEN)
        return 0;
    memcpy(list, data, ll);
    list[strnlen(list, ll)] = '\0';
    size_t hl = strnlen((const char *)data + at, size - at);
    const uint8_t *end = memchr(data + at, '\n', hl);
    hl = end ? (size_t)(end - (data + at)) : hl;
    if (hl > MAX_LEN)
        return 0;
    memcpy(host, data + at, hl);
    host[hl] = '\0';
    for (size_t i = 0; i <= hl; i++)
        upper[i] = (char)toupper((unsigned char)host[i]);
    if (srv_host_list_check(list))
        list[0] = '\0';

    const int ok = srv_host_allowed(list, host);
    FUZZ_CHECK(ok == 0 || ok == 1, "srv_host_allowed gave %d", ok);
    FUZZ_CHECK(srv_host_allowed("*", host) == 1, "\"*\" refused Host %s", host);
    FUZZ_CHECK(srv_host_allowed(list, upper) == ok, "Host %s and %s differ under --allow-host %s", host, upper, list);
    FUZZ_CHECK(srv_host_allowed("", NULL) == 1, "no Host header was refused");

    const size_t n = srv_host_name(host);
    FUZZ_CHECK(n <= hl, "a name of %zu bytes in a Host of %zu", n, hl);
    if (n) {
        name[0] = '.';
        memcpy(name + 1, host, n);
        name[n + 1] = '\0';
        FUZZ_CHECK(srv_host_list_check(name + 1) == 0, "the suggested --allow-host %s is refused", name + 1);
        FUZZ_CHECK(srv_host_allowed(name + 1, host) == 1, "--allow-host %s does not allow Host %s", name + 1, host);
        FUZZ_CHECK(srv_host_allowed(name, host) == 1, "--allow-host %s does not allow Host %s", name, host);
    }
    unsigned char addr[16];   /* a bare address, without a port: allowed by any list */
    char ip[MAX_LEN + 1];
    const int v6 = host[0] == '[' && hl > 2 && host[hl - 1] == ']';
    memcpy(ip, host + v6, hl - 2 * v6);
    ip[hl - 2 * v6] = '\0';
    if (inet_pton(v6 ? AF_INET6 : AF_INET, ip, addr) == 1)
        FUZZ_CHECK(srv_host_allowed("", host) == 1, "the address %s was refused", host);
    return 0;
}
