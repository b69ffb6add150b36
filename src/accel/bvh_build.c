/* Binned SAH build (Wald 2007): at every node the centroids are binned along each axis into 32 bins
 * and the split with the lowest surface-area cost is taken; small or unprofitable nodes become
 * leaves. Top levels run as OpenMP tasks so large scenes build on all cores. */
#include "bvh.h"
#include "ray_triangle.h"
#include "core/vec.h"
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define BINS 32
#define MAX_LEAF 4
#define TASK_MIN 4096   /* nodes smaller than this are built by the thread that split them */

typedef struct box { float lo[3], hi[3]; } box;

typedef struct build_ctx {
    const float *tri;     /* source soup */
    float *centroid;      /* 3 per source triangle */
    box *tbox;            /* per source triangle */
    uint32_t *idx;        /* permutation being partitioned */
    ms_bvh_node *nodes;
    uint32_t cap;
    uint32_t next;        /* next free node, taken atomically in pairs */
    int depth;
} build_ctx;

static void box_empty(box *b) { for (int a = 0; a < 3; a++) { b->lo[a] = FLT_MAX; b->hi[a] = -FLT_MAX; } }
static void box_grow(box *b, const box *o)
{
    for (int a = 0; a < 3; a++) {
        b->lo[a] = ms_minf(b->lo[a], o->lo[a]);
        b->hi[a] = ms_maxf(b->hi[a], o->hi[a]);
    }
}
static void box_grow_pt(box *b, const float *p)
{
    for (int a = 0; a < 3; a++) { b->lo[a] = ms_minf(b->lo[a], p[a]); b->hi[a] = ms_maxf(b->hi[a], p[a]); }
}
static float box_area(const box *b)
{
    float e[3];
    for (int a = 0; a < 3; a++) e[a] = ms_maxf(b->hi[a] - b->lo[a], 0.0f);
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

static uint32_t take_pair(build_ctx *c)
{
    uint32_t n;
#pragma omp atomic capture
    { n = c->next; c->next += 2; }
    return n;
}

static void make_leaf(ms_bvh_node *node, uint32_t first, uint32_t count)
{
    node->first = first;
    node->count = count;
}

static void build_node(build_ctx *c, uint32_t ni, uint32_t first, uint32_t count, int depth)
{
    ms_bvh_node *node = &c->nodes[ni];
    box nb, cb;
    box_empty(&nb); box_empty(&cb);
    for (uint32_t i = first; i < first + count; i++) {
        box_grow(&nb, &c->tbox[c->idx[i]]);
        box_grow_pt(&cb, &c->centroid[3 * c->idx[i]]);
    }
    memcpy(node->bmin, nb.lo, sizeof nb.lo);
    memcpy(node->bmax, nb.hi, sizeof nb.hi);
    /* The deepest level so far, shared by the build's tasks: read and written atomically (the check
     * before the critical section is a read another thread may be writing; TSan reported it). */
    int seen;
#pragma omp atomic read
    seen = c->depth;
    if (depth > seen) {
#pragma omp critical(ms_bvh_depth)
        {
#pragma omp atomic read
            seen = c->depth;
            if (depth > seen) {
#pragma omp atomic write
                c->depth = depth;
            }
        }
    }
    if (count <= MAX_LEAF || depth >= MS_BVH_STACK - 2) { make_leaf(node, first, count); return; }

    float best_cost = FLT_MAX;
    int best_axis = -1, best_split = 0;
    for (int a = 0; a < 3; a++) {
        float ext = cb.hi[a] - cb.lo[a];
        if (!(ext > 0.0f)) continue;
        float scale = (float)BINS / ext;
        /* a subnormal extent (centroids 1e-45 apart) makes the scale infinite and 0 * inf a NaN bin */
        if (!isfinite(scale)) continue;
        box bb[BINS];
        uint32_t bn[BINS] = { 0 };
        for (int k = 0; k < BINS; k++) box_empty(&bb[k]);
        for (uint32_t i = first; i < first + count; i++) {
            uint32_t t = c->idx[i];
            int k = (int)((c->centroid[3 * t + a] - cb.lo[a]) * scale);
            k = k < 0 ? 0 : (k >= BINS ? BINS - 1 : k);
            bn[k]++;
            box_grow(&bb[k], &c->tbox[t]);
        }
        /* Sweep from the right to get the right-side areas, then from the left to cost each plane. */
        float right_area[BINS];
        uint32_t right_n[BINS];
        box acc; box_empty(&acc);
        uint32_t n = 0;
        for (int k = BINS - 1; k > 0; k--) {
            box_grow(&acc, &bb[k]); n += bn[k];
            right_area[k] = box_area(&acc); right_n[k] = n;
        }
        box_empty(&acc); n = 0;
        for (int k = 0; k < BINS - 1; k++) {
            box_grow(&acc, &bb[k]); n += bn[k];
            if (n == 0 || right_n[k + 1] == 0) continue;
            float cost = box_area(&acc) * (float)n + right_area[k + 1] * (float)right_n[k + 1];
            if (cost < best_cost) { best_cost = cost; best_axis = a; best_split = k + 1; }
        }
    }
    /* Leaf if no split beats intersecting everything (traversal cost 1 vs triangle cost 1). */
    float leaf_cost = box_area(&nb) * (float)count;
    if (best_axis < 0 || (count <= 16 && best_cost >= leaf_cost - box_area(&nb))) {
        if (best_axis < 0 && count > MAX_LEAF) {
            /* All centroids coincide: split the list in half so leaves stay small. */
            uint32_t half = count / 2;
            uint32_t l = take_pair(c);
            node->first = l; node->count = 0;
            build_node(c, l, first, half, depth + 1);
            build_node(c, l + 1, first + half, count - half, depth + 1);
            return;
        }
        make_leaf(node, first, count);
        return;
    }
    float scale = (float)BINS / (cb.hi[best_axis] - cb.lo[best_axis]);
    uint32_t i = first, j = first + count;
    while (i < j) {
        uint32_t t = c->idx[i];
        int k = (int)((c->centroid[3 * t + best_axis] - cb.lo[best_axis]) * scale);
        k = k < 0 ? 0 : (k >= BINS ? BINS - 1 : k);
        if (k < best_split) i++;
        else { c->idx[i] = c->idx[--j]; c->idx[j] = t; }
    }
    uint32_t nl = i - first;
    uint32_t l = take_pair(c);
    node->first = l; node->count = 0;
    if (count >= TASK_MIN) {
#pragma omp task default(none) firstprivate(c, l, first, nl, depth)
        build_node(c, l, first, nl, depth + 1);
        build_node(c, l + 1, first + nl, count - nl, depth + 1);
#pragma omp taskwait
    } else {
        build_node(c, l, first, nl, depth + 1);
        build_node(c, l + 1, first + nl, count - nl, depth + 1);
    }
}

int ms_bvh_build(ms_bvh *b, const float *tri, size_t n, int threads)
{
    if (threads <= 0) threads = omp_get_num_procs();
    memset(b, 0, sizeof *b);
    double t0 = omp_get_wtime();
    if (n == 0 || n > (size_t)UINT32_MAX / 2) return -1;
    build_ctx c = { 0 };
    c.tri = tri;
    c.centroid = malloc(n * 3 * sizeof(float));
    c.tbox = malloc(n * sizeof(box));
    c.idx = malloc(n * sizeof(uint32_t));
    c.cap = (uint32_t)(2 * n);
    c.nodes = malloc((size_t)c.cap * sizeof(ms_bvh_node));
    b->tri = malloc(n * 9 * sizeof(float));
    b->tri_source = malloc(n * sizeof(uint32_t));
    b->tri_n = malloc(n * 3 * sizeof(float));
    if (!c.centroid || !c.tbox || !c.idx || !c.nodes || !b->tri || !b->tri_source || !b->tri_n) {
        free(c.centroid); free(c.tbox); free(c.idx); free(c.nodes);
        ms_bvh_free(b);
        return -1;
    }
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t i = 0; i < n; i++) {
        const float *t = tri + 9 * i;
        box_empty(&c.tbox[i]);
        for (int v = 0; v < 3; v++) box_grow_pt(&c.tbox[i], t + 3 * v);
        for (int a = 0; a < 3; a++) c.centroid[3 * i + a] = 0.5f * (c.tbox[i].lo[a] + c.tbox[i].hi[a]);
        c.idx[i] = (uint32_t)i;
    }
    c.next = 1;
#pragma omp parallel num_threads(threads)
#pragma omp single
    build_node(&c, 0, 0, (uint32_t)n, 1);

    for (size_t i = 0; i < n; i++) {
        memcpy(b->tri + 9 * i, tri + 9 * (size_t)c.idx[i], 9 * sizeof(float));
        b->tri_source[i] = c.idx[i];
        ms_wt_normal(b->tri + 9 * i, b->tri_n + 3 * i);
    }
    b->nodes = realloc(c.nodes, (size_t)c.next * sizeof(ms_bvh_node));
    if (!b->nodes) b->nodes = c.nodes;
    b->n_nodes = c.next;
    b->n_tris = (uint32_t)n;
    b->depth = c.depth;
    free(c.centroid); free(c.tbox); free(c.idx);
    b->build_s = omp_get_wtime() - t0;
    return 0;
}

void ms_bvh_free(ms_bvh *b)
{
    free(b->nodes); free(b->tri); free(b->tri_source); free(b->tri_n);
    memset(b, 0, sizeof *b);
}
