/* The receiver hierarchy of a chunk (the paper's sec. 3.1): a BVH of axis-aligned boxes over its points, middle
 * splits above 1K points, a binned SAH below, with the umbra bits of its nodes. Compiled once (hpc_engine.h). */
#include "hpc_engine.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static void bounds_of(const shared *sh, const uint32_t *idx, uint32_t n, float lo[3], float hi[3])
{
    for (int a = 0; a < 3; a++) { lo[a] = INFINITY; hi[a] = -INFINITY; }
    for (uint32_t i = 0; i < n; i++) {
        const float *p = sh->q[idx[i]].p;
        for (int a = 0; a < 3; a++) { lo[a] = ms_minf(lo[a], p[a]); hi[a] = ms_maxf(hi[a], p[a]); }
    }
}

static float half_area(const float lo[3], const float hi[3])
{
    const float x = hi[0] - lo[0], y = hi[1] - lo[1], z = hi[2] - lo[2];
    return x * y + y * z + z * x;
}

/* Partition idx[0..n) by p[axis] < split; returns the count below. */
static uint32_t partition(const shared *sh, uint32_t *idx, uint32_t n, int axis, float split)
{
    uint32_t i = 0, j = n;
    while (i < j) {
        if (sh->q[idx[i]].p[axis] < split) i++;
        else { const uint32_t t = idx[i]; idx[i] = idx[--j]; idx[j] = t; }
    }
    return i;
}

static int cmp_key(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Where to split idx[0..n): the middle of the longest axis above MIDDLE_SPLIT_ABOVE points, else a binned
 * SAH; the median when a side would be empty (coincident points) or when asked (deep in the tree: points
 * spaced exponentially would otherwise peel off one per level, and the traversal recurses). Returns the
 * left count. */
static uint32_t split_points(const shared *sh, uint32_t *idx, uint32_t n, const float lo[3], const float hi[3],
                             int median)
{
    const float ext[3] = { hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] };
    int axis = ext[0] >= ext[1] ? (ext[0] >= ext[2] ? 0 : 2) : (ext[1] >= ext[2] ? 1 : 2);
    float split = lo[axis] + 0.5f * ext[axis];
    if (n <= MIDDLE_SPLIT_ABOVE) {
        float best = INFINITY;
        for (int a = 0; a < 3; a++) {
            if (!(ext[a] > 0.0f)) continue;
            uint32_t cnt[SAH_BINS] = { 0 };
            float blo[SAH_BINS][3], bhi[SAH_BINS][3];
            for (int b = 0; b < SAH_BINS; b++)
                for (int c = 0; c < 3; c++) { blo[b][c] = INFINITY; bhi[b][c] = -INFINITY; }
            const float sc = (float)SAH_BINS / ext[a];
            for (uint32_t i = 0; i < n; i++) {
                const float *p = sh->q[idx[i]].p;
                int b = (int)((p[a] - lo[a]) * sc);
                b = b < 0 ? 0 : b >= SAH_BINS ? SAH_BINS - 1 : b;
                cnt[b]++;
                for (int c = 0; c < 3; c++) { blo[b][c] = ms_minf(blo[b][c], p[c]); bhi[b][c] = ms_maxf(bhi[b][c], p[c]); }
            }
            float rarea[SAH_BINS];
            uint32_t rcnt[SAH_BINS];
            float l[3] = { INFINITY, INFINITY, INFINITY }, h[3] = { -INFINITY, -INFINITY, -INFINITY };
            uint32_t c = 0;
            for (int b = SAH_BINS - 1; b > 0; b--) {
                for (int d = 0; d < 3; d++) { l[d] = ms_minf(l[d], blo[b][d]); h[d] = ms_maxf(h[d], bhi[b][d]); }
                c += cnt[b];
                rcnt[b] = c;
                rarea[b] = c ? half_area(l, h) : 0.0f;
            }
            for (int d = 0; d < 3; d++) { l[d] = INFINITY; h[d] = -INFINITY; }
            c = 0;
            for (int b = 0; b < SAH_BINS - 1; b++) {
                for (int d = 0; d < 3; d++) { l[d] = ms_minf(l[d], blo[b][d]); h[d] = ms_maxf(h[d], bhi[b][d]); }
                c += cnt[b];
                if (!c || !rcnt[b + 1]) continue;
                const float cost = half_area(l, h) * (float)c + rarea[b + 1] * (float)rcnt[b + 1];
                if (cost < best) { best = cost; axis = a; split = lo[a] + (float)(b + 1) / sc; }
            }
        }
    }
    uint32_t m = median ? 0 : partition(sh, idx, n, axis, split);
    if (m == 0 || m == n) {
        /* Median by sorting keys (rare: points bunched in one bin or coincident). */
        float *key = malloc((size_t)n * 2 * sizeof *key);
        if (!key) return n / 2;   /* any split is correct; only balance suffers */
        for (uint32_t i = 0; i < n; i++) { key[2 * i] = sh->q[idx[i]].p[axis]; memcpy(&key[2 * i + 1], &idx[i], 4); }
        qsort(key, n, 2 * sizeof *key, cmp_key);
        for (uint32_t i = 0; i < n; i++) memcpy(&idx[i], &key[2 * i + 1], 4);
        free(key);
        m = n / 2;
    }
    return m;
}

/* (Re)builds the chunk's hierarchy over its points that are not in full umbra. 0, or -1 out of memory. */
int hpc_build_tree(const shared *sh, chunk *c)
{
    uint32_t live = 0;
    for (uint32_t i = 0; i < c->n; i++)
        if (!sh->full[c->idx[i]]) c->idx[live++] = c->idx[i];
    c->n = live;
    c->umbra_in_tree = 0;
    free(c->nodes);
    c->nodes = NULL;
    c->n_nodes = 0;
    if (!live) return 0;
    c->nodes = malloc((size_t)(2 * live) * sizeof *c->nodes);
    if ((size_t)(2 * live) * sizeof *c->nodes > c->node_bytes_peak) c->node_bytes_peak = (size_t)(2 * live) * sizeof *c->nodes;
    uint32_t *stack = malloc((size_t)(2 * live + 64) * 2 * sizeof *stack);   /* node, depth */
    if (!c->nodes || !stack) { free(stack); return -1; }
    c->n_nodes = 1;
    c->nodes[0].first = 0;
    c->nodes[0].count = live;
    int sp = 0;
    stack[sp++] = 0;
    stack[sp++] = 0;
    while (sp) {
        const uint32_t depth = stack[--sp];
        hnode *N = &c->nodes[stack[--sp]];
        bounds_of(sh, c->idx + N->first, N->count, N->lo, N->hi);
        if (N->count <= (sh->footprint ? LEAF_POINTS_FOOTPRINT : LEAF_POINTS)) continue;
        const uint32_t m = split_points(sh, c->idx + N->first, N->count, N->lo, N->hi, depth >= MEDIAN_BELOW_DEPTH);
        const uint32_t l = c->n_nodes;
        c->n_nodes += 2;
        c->nodes[l].first = N->first;
        c->nodes[l].count = m;
        c->nodes[l + 1].first = N->first + m;
        c->nodes[l + 1].count = N->count - m;
        N->first = l;
        N->count = 0;
        stack[sp++] = l + 1;
        stack[sp++] = depth + 1;
        stack[sp++] = l;
        stack[sp++] = depth + 1;
    }
    free(stack);
    /* Children follow their parents: umbra bits bottom-up in reverse order. */
    for (uint32_t i = c->n_nodes; i-- > 0;) {
        hnode *N = &c->nodes[i];
        if (N->count) node_bits_from_points(sh, c, N);
        else {
            N->gumbra = c->nodes[N->first].gumbra & c->nodes[N->first + 1].gumbra;
            N->full = c->nodes[N->first].full & c->nodes[N->first + 1].full;
        }
    }
    return 0;
}
