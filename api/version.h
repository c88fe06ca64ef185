/*
 * version.h: pdesolid's version, in one place. The CLI (pdesolid --version),
 * the daemon (pdesolidd --version, GET /version) and docs/openapi.yaml's
 * info.version all say this; tests/test_config.c checks the last against it.
 */
#ifndef PDESOLID_VERSION_H
#define PDESOLID_VERSION_H

#define PDESOLID_VERSION "0.4.0"

#endif
