/*
 * host.h: which Host headers pdesolidd answers (--allow-host), against DNS
 * rebinding. A page at evil.example can point its name at 127.0.0.1: the
 * victim's browser then sends the page's requests to the local daemon with
 * Host: evil.example:8080 and an Origin to match, which the same-origin check
 * cannot tell from the daemon's own front-end. Rebinding needs a DNS name, so
 * an IP literal is safe, and so is localhost with its subdomains, which
 * browsers resolve to loopback themselves (RFC 6761); any other name must be
 * listed. The models are Vite's server.allowedHosts and webpack-dev-server's
 * allowedHosts, whose list syntax this follows.
 *
 * USAGE
 *
 *   if (srv_host_list_check(arg))            // at start-up: --allow-host's value
 *       ... refuse the flag ...
 *   if (!srv_host_allowed(cfg.allow_host, host_header_or_NULL))
 *       ... 403, suggesting --allow-host with the srv_host_name(host) bytes of host ...
 *
 * A list is names separated by commas (spaces around them ignored): NAME
 * allows NAME, .NAME allows NAME and every name under it, * allows every
 * host (no check). Names compare without regard to case, a trailing dot
 * ignored, in the list and in the header. Both calls are pure, reentrant and
 * cannot fail.
 */
#ifndef SRV_HOST_H
#define SRV_HOST_H

#include <stddef.h>

/* 0 if list is a valid --allow-host value (the empty list too), -1 if an item is not a host name (letters,
 * digits, '-' and '_' in dot-separated labels, an optional leading and trailing dot) nor "*". */
int srv_host_list_check(const char *list);

/* 1 if a request with this Host header value may be answered: none (NULL: HTTP/1.0), an IPv4 address, an IPv6
 * address in brackets, localhost or NAME.localhost, or a name list allows; each with an optional :PORT. A name is
 * labels of letters, digits, '-' and '_' between dots; a value that is none of these is allowed by "*" only. */
int srv_host_allowed(const char *list, const char *host);

/* The length of the name at the start of host, without its port and trailing dot; 0 if host (or NULL) is not a
 * name: an address, or malformed. For a message: "--allow-host %.*s". */
size_t srv_host_name(const char *host);

#endif
