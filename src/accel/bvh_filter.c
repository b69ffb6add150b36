/* A BVH over a subset of another's triangles, by pruning rather than building (bvh.h, ms_bvh_filter): the
 * source's tree with its leaves cut down to the kept triangles, empty subtrees removed, a node with one
 * non-empty child replaced by that child, and every box refitted. The per-light occluder set of the
 * closed-component cull (visibility/occluders.c) keeps one side of each solid: whole leaves of a smooth
 * surface stay or go together, so the pruned tree holds nearly full leaves at the cost of one pass over the
 * source, where a new build sorts the kept triangles again. */
#include "bvh.h"
#include <float.h>
#include <stdlib.h>
#include <string.h>

typedef struct filter_ctx {
    const ms_bvh *src;
    const uint8_t *keep;   /* per source triangle in leaf order */
    uint32_t *kept;        /* per source node: kept triangles in its subtree */
    ms_bvh *out;
    uint32_t next_node, next_tri;
    int depth;
} filter_ctx;

static uint32_t count_kept(filter_ctx *c, uint32_t ni)
{
    const ms_bvh_node *n = &c->src->nodes[ni];
    uint32_t k = 0;
    if (n->count)
        for (uint32_t i = 0; i < n->count; i++) k += c->keep[n->first + i] != 0;
    else
        k = count_kept(c, n->first) + count_kept(c, n->first + 1);
    return c->kept[ni] = k;
}

/* Source subtree si (with kept triangles) into output node di. */
static void emit(filter_ctx *c, uint32_t si, uint32_t di, int depth)
{
    const ms_bvh_node *s = &c->src->nodes[si];
    ms_bvh_node *d = &c->out->nodes[di];
    if (depth > c->depth) c->depth = depth;
    if (!s->count) {
        const uint32_t l = s->first, r = s->first + 1;
        if (!c->kept[l] || !c->kept[r]) {   /* one side empty: this node becomes the other */
            emit(c, c->kept[l] ? l : r, di, depth);
            return;
        }
        const uint32_t p = c->next_node;
        c->next_node += 2;
        emit(c, l, p, depth + 1);
        emit(c, r, p + 1, depth + 1);
        d = &c->out->nodes[di];
        const ms_bvh_node *a = &c->out->nodes[p], *b = &c->out->nodes[p + 1];
        for (int k = 0; k < 3; k++) {
            d->bmin[k] = a->bmin[k] < b->bmin[k] ? a->bmin[k] : b->bmin[k];
            d->bmax[k] = a->bmax[k] > b->bmax[k] ? a->bmax[k] : b->bmax[k];
        }
        d->first = p;
        d->count = 0;
        return;
    }
    for (int k = 0; k < 3; k++) { d->bmin[k] = FLT_MAX; d->bmax[k] = -FLT_MAX; }
    d->first = c->next_tri;
    for (uint32_t i = s->first; i < s->first + s->count; i++) {
        if (!c->keep[i]) continue;
        const uint32_t o = c->next_tri++;
        const float *t = c->src->tri + 9 * (size_t)i;
        memcpy(c->out->tri + 9 * (size_t)o, t, 9 * sizeof *t);
        memcpy(c->out->tri_n + 3 * (size_t)o, c->src->tri_n + 3 * (size_t)i, 3 * sizeof *t);
        c->out->tri_source[o] = i;
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++) {
                if (t[3 * v + k] < d->bmin[k]) d->bmin[k] = t[3 * v + k];
                if (t[3 * v + k] > d->bmax[k]) d->bmax[k] = t[3 * v + k];
            }
    }
    d->count = c->next_tri - d->first;
}

int ms_bvh_filter(ms_bvh *out, const ms_bvh *src, const uint8_t *keep)
{
    memset(out, 0, sizeof *out);
    if (!src->n_nodes) return -1;
    filter_ctx c = { src, keep, malloc((size_t)src->n_nodes * sizeof(uint32_t)), out, 1, 0, 1 };
    if (!c.kept) return -1;
    const uint32_t n = count_kept(&c, 0);
    if (!n) { free(c.kept); return -1; }
    out->nodes = malloc((size_t)(2 * n - 1) * sizeof *out->nodes);
    out->tri = malloc((size_t)n * 9 * sizeof(float));
    out->tri_n = malloc((size_t)n * 3 * sizeof(float));
    out->tri_source = malloc((size_t)n * sizeof(uint32_t));
    if (!out->nodes || !out->tri || !out->tri_n || !out->tri_source) {
        free(c.kept);
        ms_bvh_free(out);
        return -1;
    }
    emit(&c, 0, 0, 1);
    free(c.kept);
    out->n_nodes = c.next_node;
    out->n_tris = n;
    out->depth = c.depth;
    return 0;
}
