/*
 * id.c: SHA-256 (nettle, from Debian) of the canonical model's exact bytes:
 * every double by its bit pattern, little-endian, after a version tag, so the
 * id changes only when the model does, or when the format version is raised.
 */
#include <stdint.h>
#include <string.h>

#include <nettle/sha2.h>

#include "id.h"
#include "model.h"

static void put_u64(struct sha256_ctx *h, uint64_t v)
{
    uint8_t b[8];
    for (int i = 0; i < 8; i++)
        b[i] = (uint8_t)(v >> (8 * i));
    sha256_update(h, sizeof b, b);
}

static void put_f64(struct sha256_ctx *h, double d)
{
    uint64_t v;
    memcpy(&v, &d, sizeof v);
    put_u64(h, v);
}

static void put_factor(struct sha256_ctx *h, pde_factor f)
{
    put_u64(h, (uint64_t)f.kind);
    put_f64(h, f.p);
}

/* The hex digits of a digest's first API_ID_LEN / 2 bytes. */
static void hex_id(struct sha256_ctx *h, char id[API_ID_LEN + 1])
{
    uint8_t digest[SHA256_DIGEST_SIZE];
    sha256_digest(h, sizeof digest, digest);
    static const char hex[] = "0123456789abcdef";
    for (int i = 0; i < API_ID_LEN / 2; i++) {
        id[2 * i] = hex[digest[i] >> 4];
        id[2 * i + 1] = hex[digest[i] & 15];
    }
    id[API_ID_LEN] = '\0';
}

pde_status api_model_id(const pde_model *m, char id[API_ID_LEN + 1], pde_diag *diag)
{
    pde_model c;
    pde_status st = pde_model_canonical(m, &c, diag);
    if (st != PDE_OK)
        return st;
    struct sha256_ctx h;
    sha256_init(&h);
    static const char tag[] = "pdesolid model v1";
    sha256_update(&h, sizeof tag, (const uint8_t *)tag);
    for (int i = 0; i < 3; i++) {
        const pde_component *k = &c.comp[i];
        put_f64(&h, k->a);
        put_f64(&h, k->b);
        put_f64(&h, k->c);
        put_u64(&h, k->nbterms);
        for (size_t j = 0; j < k->nbterms; j++) {
            const pde_bterm *t = &k->bterms[j];
            put_factor(&h, t->u);
            put_factor(&h, t->v);
            put_f64(&h, t->w0);
            put_f64(&h, t->dw0);
            put_f64(&h, t->w1);
            put_f64(&h, t->dw1);
        }
        put_u64(&h, k->nfterms);
        for (size_t j = 0; j < k->nfterms; j++) {
            const pde_fterm *t = &k->fterms[j];
            put_f64(&h, t->coef);
            put_factor(&h, t->u);
            put_factor(&h, t->v);
            put_factor(&h, t->w);
        }
    }
    pde_model_canonical_free(&c);
    hex_id(&h, id);
    return PDE_OK;
}

/* api/loft.c builds a loft's terms merged and sorted, numbers without -0: its bytes are canonical. */
pde_status api_loft_id(const pde_loft *l, char id[API_ID_LEN + 1])
{
    struct sha256_ctx h;
    sha256_init(&h);
    static const char tag[] = "pdesolid loft v1";
    sha256_update(&h, sizeof tag, (const uint8_t *)tag);
    const size_t K = l->nsections;
    put_u64(&h, K);
    for (size_t k = 0; k < K; k++) {
        put_f64(&h, l->sections[k].w + 0.0);
        put_u64(&h, l->sections[k].tangent != 0);
    }
    for (int i = 0; i < 3; i++) {
        const pde_lcomponent *c = &l->comp[i];
        put_f64(&h, c->a + 0.0);
        put_f64(&h, c->b + 0.0);
        put_f64(&h, c->c + 0.0);
        put_u64(&h, c->nterms);
        for (size_t j = 0; j < c->nterms; j++) {
            put_factor(&h, c->terms[j].u);
            put_factor(&h, c->terms[j].v);
            for (size_t k = 0; k < K; k++) {
                put_f64(&h, c->terms[j].x[k] + 0.0);
                put_f64(&h, l->sections[k].tangent && c->terms[j].xw ? c->terms[j].xw[k] + 0.0 : 0.0);
            }
        }
    }
    hex_id(&h, id);
    return PDE_OK;
}

pde_status api_request_id(const api_model *m, char id[API_ID_LEN + 1], pde_diag *diag)
{
    return api_model_loft(m) ? api_loft_id(api_model_loft(m), id) : api_model_id(api_model_get(m), id, diag);
}

int api_id_valid(const char *s)
{
    size_t n = 0;
    for (; s[n]; n++)
        if (!((s[n] >= '0' && s[n] <= '9') || (s[n] >= 'a' && s[n] <= 'f')))
            return 0;
    return n == API_ID_LEN;
}
