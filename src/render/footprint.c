/* Bilinear footprints of lightmap triangles (footprint.h). */
#include "footprint.h"
#include "core/union_find.h"
#include <math.h>
#include <stdlib.h>

void ms_footprint_triangle(const float uv[6], double reach, int w, int h, void (*fn)(void *user, int x, int y),
                           void *user)
{
    double v[3][2];
    for (int k = 0; k < 3; k++) {
        v[k][0] = uv[2 * k];
        v[k][1] = uv[2 * k + 1];
        if (!isfinite(v[k][0]) || !isfinite(v[k][1])) return;
    }
    const double area = (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[1][1] - v[0][1]) * (v[2][0] - v[0][0]);
    if (area == 0.0) return;
    if (area < 0.0)
        for (int d = 0; d < 2; d++) { const double s = v[1][d]; v[1][d] = v[2][d]; v[2][d] = s; }
    double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY };
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 2; d++) { lo[d] = fmin(lo[d], v[k][d]); hi[d] = fmax(hi[d], v[k][d]); }
    /* the square of half-side `reach` about a texel centre meets the triangle: the separating-axis test, the
     * square's axes (the box) and the triangle's edge normals (each edge function pushed out by reach in L1) */
    const double x0 = fmax(ceil(lo[0] - reach - 0.5), 0.0), x1 = fmin(floor(hi[0] + reach - 0.5), w - 1.0);
    const double y0 = fmax(ceil(lo[1] - reach - 0.5), 0.0), y1 = fmin(floor(hi[1] + reach - 0.5), h - 1.0);
    if (!(x0 <= x1 && y0 <= y1)) return;
    double ex[3], ey[3], push[3];
    for (int k = 0; k < 3; k++) {
        ex[k] = v[(k + 1) % 3][0] - v[k][0];
        ey[k] = v[(k + 1) % 3][1] - v[k][1];
        push[k] = reach * (fabs(ex[k]) + fabs(ey[k]));
    }
    for (int y = (int)y0; y <= (int)y1; y++)
        for (int x = (int)x0; x <= (int)x1; x++) {
            const double px = x + 0.5, py = y + 0.5;
            int in = 1;
            for (int k = 0; k < 3 && in; k++) in = ex[k] * (py - v[k][1]) - ey[k] * (px - v[k][0]) + push[k] >= 0.0;
            if (in) fn(user, x, y);
        }
}

typedef struct owners_ctx {
    uint32_t *owner, *parent;
    uint32_t t;
    size_t row0;   /* the page's first texel in the frame */
    int size;
} owners_ctx;

static void own_texel(void *user, int x, int y)
{
    owners_ctx *c = user;
    uint32_t *o = c->owner + c->row0 + (size_t)y * c->size + x;
    if (*o == UINT32_MAX) *o = c->t;
    else ms_uf_union(c->parent, *o, c->t);
}

/* Charts need no UV vertices of their own here: two triangles sharing a UV vertex (or an edge) have
 * footprints sharing the texels about it, so joining footprints that share a texel joins them too. */
int ms_footprint_owners(const float *uv, const uint32_t *page, size_t n, int size, int pages, uint32_t *owner)
{
    const size_t texels = (size_t)size * size * (size_t)pages;
    for (size_t i = 0; i < texels; i++) owner[i] = UINT32_MAX;
    if (!n) return 0;
    uint32_t *parent = malloc(n * sizeof *parent);
    if (!parent) return -1;
    for (size_t t = 0; t < n; t++) parent[t] = (uint32_t)t;
    owners_ctx c = { owner, parent, 0, 0, size };
    for (size_t t = 0; t < n; t++) {
        const uint32_t p = page ? page[t] : 0;
        if (p >= (uint32_t)pages) continue;
        float q[6];
        for (int k = 0; k < 6; k++) q[k] = uv[6 * t + k] * (float)size;
        c.t = (uint32_t)t;
        c.row0 = (size_t)p * size * size;
        ms_footprint_triangle(q, MS_FOOTPRINT_REACH_BAKE, size, size, own_texel, &c);
    }
    for (size_t i = 0; i < texels; i++)
        if (owner[i] != UINT32_MAX) owner[i] = ms_uf_find(parent, owner[i]);
    free(parent);
    return 0;
}
