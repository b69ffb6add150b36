/* The primary-visibility interface: a primary method finds what each pixel sees (docs/primary.md). To add
 * one: implement ms_primary_method in its own file of this folder and list it in registry.c. */
#ifndef MS_PRIMARY_H
#define MS_PRIMARY_H
#include <stddef.h>
#include <stdint.h>
#include "visibility/context.h"

typedef struct ms_hit {
    float p[3], n[3];
    uint32_t prim;               /* UINT32_MAX: the ray missed */
} ms_hit;

typedef struct ms_primary_method {
    const char *name;
    int (*create)(const ms_render_ctx *ctx, void **state, char *err, size_t errlen);
    /* Hits for pixels [x0,x1) x [y0,y1), row-major into out. Thread-safe. */
    void (*trace)(void *state, const ms_render_ctx *ctx, int x0, int y0, int x1, int y1, ms_hit *out);
    void (*destroy)(void *state);
    /* Optional (NULL: none): the counters of the paper's Table 1 (Dachsbacher et al.) over the frame so far:
     * triangle set-ups S, edge-function evaluations E, BVH nodes visited N. */
    void (*counters)(const void *state, uint64_t c[3]);
    int streams;                 /* 1: reads a procedural scene in batches (ctx->bvh NULL), never all at once */
} ms_primary_method;

/* Known primary methods, compiled in or not (registry.c). */
const ms_primary_method *ms_find_primary_method(const char *name);

/* Finishes a hit from a ray and a hit triangle: the point o + t d (not lifted: the horizon and the near
 * range make V independent of which side of the surface rounding puts it), and the unit normal facing
 * the ray's origin. Shared by every primary method so that all agree on the receiver. */
void ms_hit_finish(const ms_render_ctx *ctx, const float o[3], const float d[3], float t, uint32_t prim,
                   ms_hit *h);
/* The same from the triangle's 9 floats (for passes without a BVH). */
void ms_hit_finish_tri(const float *tri, const float o[3], const float d[3], float t, uint32_t prim, ms_hit *h);

/* The shadow query of a primary hit at pixel (x, y): the hit point, its normal and triangle (the one way
 * frames, their shading and the tests turn a hit into a receiver). */
static inline void ms_query_from_hit(ms_shadow_query *q, const ms_hit *h, uint32_t x, uint32_t y)
{
    for (int a = 0; a < 3; a++) { q->p[a] = h->p[a]; q->n[a] = h->n[a]; }
    q->prim = h->prim;
    q->px = x;
    q->py = y;
}

#endif
