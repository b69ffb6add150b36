/* Methods "hpc" and "hpc-scanline": hierarchical penumbra casting (Laine & Aila, "Hierarchical Penumbra
 * Casting", EGSR 2005, sec. 3), the transpose of ray tracing: for each triangle, find every (light sample ->
 * receiver point) relation it blocks, with a hierarchy over the receiver points and a three-level hierarchy
 * over the light samples, never a hierarchy over the scene. The triangles are read once, in any order, in
 * batches (hpc_source), so they need not be in memory together.
 *
 * What is the paper's (sec. 3.1-3.3, the pseudocode of its Fig. 3, line numbers L..):
 *  - the receiver points (the frame's visible hit points) in a BVH of axis-aligned boxes: nodes of more
 *    than 1K points split at the middle of the box, smaller ones by surface area (build_tree);
 *  - the light: the whole polygon Delta_L, groups G_k of gs x gs neighbouring samples with bounding
 *    polygons Delta_Gk, the samples; per triangle the penumbra volumes V_L and V_Gk (separating planes of
 *    every vertex-edge pair, hpc_volume.c) and the samples' hard-shadow tests;
 *  - the recursive traversal with the list of active groups and their active plane sets (B, L36-L45);
 *  - A, umbra bits: group-umbra and full-umbra bits per point and per node, ANDed upwards (L50-L54,
 *    L72-L80), ending the traversal at full-umbra nodes and dropping umbra groups (L35, L39, L57, L66),
 *    and the rebuild of the receiver hierarchy without the full-umbra points when they exceed a quarter
 *    of the points it holds (L29);
 *  - C, lazy volumes: V_Gk and the per-point sample data are made only when a point inside V_L that is
 *    not in umbra is reached (L31, L40-L44, L60-L64);
 *  - D, on-demand bit masks: a point gets its mask when a triangle first may block it and gives it back
 *    when it reaches full umbra (L59, L75);
 *  - coarse blocker sorting: triangles bucketed by area, largest first, in linear time (hpc_sort.c).
 *
 * Multiple sample sets (sec. 3.4): each receiver uses its own pixel's samples (the per-pixel rotated and
 * shifted grid, pattern.h), so hpc answers sample for sample like every other method. The group polygons
 * bound their samples over all pixels: with the grid every sample (i, j) lies in cell (i, j) of the light
 * (pattern.h), so a group's polygon is the union of its cells, widened by 1e-3 of a cell for rounding.
 *
 * Departures, and why:
 *  - the hard-shadow test of a sample (L70) is the reference tracer's watertight ray/triangle test from the
 *    receiver to the sample (ms_wt_segment_sheared in accel/ray_triangle.h, the scalar form of raytrace's
 *    lane loop: the same shear axis of the 16-sample packet, the same float operations, the same double
 *    fall-back on a zero edge function). Its three edge functions are the signed volumes of the sample,
 *    the receiver and each triangle edge, i.e. the receiver against the three planes of V_li through the
 *    sample and the edges, and its t range is the fourth plane, the triangle's, moved to the near/far
 *    range of the visibility definition. Evaluated this way the answer equals raytrace bit for bit; the
 *    plane form rounds differently at the edges. The per-point part of "constructing V_li" (the packet
 *    shear axes, ms_wt_packet_axis) is made lazily with the point's mask.
 *  - the penumbra volumes cull with a margin (hpc_volume.h) that covers the rounding of that exact test:
 *    the error of a float test is magnified behind the triangle by (distance to the light) / (triangle's
 *    distance from the light, bounded below on separating axes), so the margin grows with it
 *    (tri_margin); a triangle that may touch the light gets no volume (nothing culled, every relation
 *    tested).
 *  - below 1K points the split is a 16-bin SAH (count-weighted, the paper's "total surface area of the
 *    children" unweighted would split off single points), and leaves hold up to 8 points (16 for hpc,
 *    whose leaves test 16 points at once).
 *  - the light samples behind a receiver's plane (the horizon) count as blocked from the start, so umbra
 *    bits mean "no front sample left open"; a receiver's hit triangle never blocks it.
 *  - hpc (not hpc-scanline) replaces the group volumes V_Gk by the footprint test (below, "the footprint
 *    test"): per receiver and triangle, the exact test's edge functions as affine functions of the sample
 *    indices, bounded per group and per 16-sample block with a proven slack for the exact test's rounding.
 *    V_Gk bounds a group over the whole group polygon and every pixel's grid, and costs 24 double-precision
 *    candidate planes per group and triangle; the footprint is one receiver's own grid, in float, and
 *    leaves only the samples the triangle may cover (on a GRIDS-like scene 162M sample tests became 6M).
 *    Nodes are then culled by V_L alone (no group volumes to test boxes against); the paper's form stays
 *    for hpc-scanline (whose Scanline kernel the slack does not bound) and under MS_HPC_OFF_FOOTPRINT.
 *    A leaf's points (up to 16 for hpc) take the point-in-V_L test and the footprint set-up 16 at a time,
 *    and the receivers are renumbered in hierarchy order so that a leaf's data lie together in memory.
 *  - hpc bounds the footprint over a whole leaf (below, "the leaf footprint"): per light sample, over every
 *    receiver position in the leaf's box and every grid origin in its origins' box, with a proven bound and
 *    the footprint's slack. The samples it leaves (at 1024^2 on a GRIDS-like scene ~11 of 256 per leaf and
 *    triangle, fewer as the leaves shrink with resolution) are then tested for the leaf's receivers 16 at a
 *    time, so receivers whose footprint holds none of them cost no per-receiver work. The paper's nodes cull
 *    whole light groups with V_Gk; a leaf's group of samples is rarely empty here because every pixel has
 *    its own jittered grid (the paper used 8 sample sets), so the leaf works at the sample level instead.
 *    Used for pairs only, and only where a chunk's recent leaves show it pays (leaf_fp_pays; docs/hpc.md).
 *  - hpc casts two triangles that share an edge and a plane (a box's face, a mesh's quad) as one job
 *    (pair_batch): one traversal, one V_L of their four points (hpc_volume_build_points), one per-receiver
 *    loop over the groups and blocks, where each triangle's footprint keeps its own lanes and each triangle's
 *    exact test runs on its own lanes, so the answers stay raytrace's. The paper names this extension
 *    (sec. 5: "process multiple blocker triangles simultaneously") without doing it; on a GRIDS-like scene 95%
 *    of the triangles pair up. A convex quad's own four edge functions are not used for the exact test: on the
 *    shared edge they would round differently from the two triangles' tests. They bound the leaf footprint of
 *    a pair that is exactly an axis-aligned rectangle (below, "rectangle pairs": one bound for both triangles,
 *    proven to keep every sample either triangle's exact test blocks).
 *  - the footprint's slack also proves the other way: a sample whose three edge functions lie beyond their
 *    slacks with one sign passes the exact test's edge functions (footprint_sure_lanes), so a block whose
 *    candidates are all such samples is decided by the exact test's t range alone (t_range16, its own
 *    operations). The paper has no such step: every open relation of an active group is tested against its
 *    hard shadow volume (L22); here the functions the footprint already evaluated decide most of them. On the
 *    merged bars (1,322 large rectangles) 70M of 90M sample tests take it and the cast is 10% faster; only
 *    footprints over several groups take it (cast_blocks; docs/hpc.md, session 15). Where the triangle lies
 *    well between every receiver of a leaf (or the one receiver) and the light, even the t range is proven
 *    (t_sure), and such samples are blocked without any test.
 *  - with the leaf footprint, the samples it leaves are tested for the leaf's receivers in the lanes, one
 *    sample for 16 receivers per operation (below, "the leaf's receivers in the lanes"), instead of being
 *    handed to each receiver's groups and blocks: the paper's leaf handles its points one by one (L56-L75).
 *  - the triangles are ctx->bvh's: with the light's occluders (hpc_method.c), those of closed components
 *    facing away from the whole light are left out (docs/culling.md proves it changes no V or S), and
 *    axis-aligned coplanar rectangles are merged (accel/coplanar.h: the same points; the driver gives each
 *    sample to a set merged only where it decides as the pieces do, render/exact_split.c, so V and S stay
 *    raytrace's bit for bit).
 *  - hpc-scanline: the leaf rasterizes the triangle into the receiver's k x k buffer with the Scanline
 *    kernel (Woop 2010; src/raster) once some active group's volume holds the point, instead of testing
 *    the samples one by one (points that see the light nearly edge-on are tested per sample, as
 *    microraster.c hands them to the tracer). Its answers are Scanline's: equal to raytrace up to ties.
 *
 * One source per ISA (CONTRIBUTING.md, "An ISA kernel"): this file is compiled as hpc_scalar.c, hpc_avx2.c and
 * hpc_avx512.c, each defining ms_hpc_cast_<isa>; hpc.c picks one under the context's cap. What the ISA
 * changes is the 16-lane code of lanes16.h (IEEE operations per lane, no FMA), so every instance gives the
 * same masks and counters (test_hpc checks it):
 *  - the hard-shadow test (L70) runs over 16 samples of a group at once (group_block16): a group of 4 x 4
 *    samples (k = 16, 32) is one call, one of 8 x 8 (k = 64) four calls of 2 rows. Each lane forms its
 *    sample, its direction and its shear exactly as the scalar form (and raytrace) does: the per-lane
 *    shear axis of its 16-sample packet (selected per lane; lanes whose packet has none are tested one by
 *    one, as raytrace does), sx = d[kx] * (1 / d[kz]), the same edge functions, the same double fall-back
 *    on a zero edge, the same plane-distance range. The paper tests the four planes of V_li with SSE,
 *    one sample at a time; here the SIMD width goes to the samples instead;
 *  - the box- and point-in-volume tests (INTERSECTS, POINT-IN-VOLUME) evaluate all the planes of a volume
 *    in one 16-lane operation (hpc_volume.h keeps them by component) and then keep the active ones: the
 *    scalar form's arithmetic per plane, without its early exit (the counter counts every active plane).
 * Measuring switches (ms_hpc_switches, hpc.h) turn off each optimisation of sec. 3.3 and each SIMD form.
 *
 * Threads: the receiver points are split into spatially coherent chunks (the top of a middle-split
 * hierarchy, up to 16 per thread, the largest split first: make_chunks), each with its own hierarchy, masks
 * and umbra bits; every batch of triangles is read once, its V_L made once in parallel, and then every chunk
 * processes the whole batch, chunks scheduled dynamically over the threads. No point is shared between
 * chunks, so there are no locks, and the answer (an OR over triangles per relation) does not depend on the
 * split. */
#include "hpc.h"
#include "hpc_volume.h"
#include "shadow/method.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "accel/ray_triangle.h"
#include "accel/coplanar.h"
#include "light/pattern.h"
#include "light/light_frame.h"
#include "core/vec.h"
#include "raster/raster.h"
#include "core/perk.h"
#include "visibility/lanes16.h"
#include "visibility/wt_rays16.h"
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LEAF_POINTS 8
#define LEAF_POINTS_FOOTPRINT 16   /* hpc's leaves, whose points are tested 16 at a time (cast_leaf_footprint) */
#define MIDDLE_SPLIT_ABOVE 1024   /* the paper's 1K */
#define SAH_BINS 16
#define MEDIAN_BELOW_DEPTH 40     /* median splits from here: depth at most 40 + log2(points) */
#define BATCH 16384               /* triangles read and prepared together */
#define EDGE_ON 1e-3f             /* as microraster.c */
#ifndef LEAF_FP_MIN
#define LEAF_FP_MIN 6
#endif
#define LANES 16                  /* the reference tracer's packet width (raytrace_impl.h) */
#ifndef SURE_MIN_GROUPS
#define SURE_MIN_GROUPS 4         /* the sure lanes only for footprints over this many groups (cast_footprint) */
#endif

enum {
    C_TRIANGLES, C_TRI_CHUNK_PASSES, C_NODE_VISITS, C_NODES_OUTSIDE_VL, C_UMBRA_NODE_SKIPS, C_PLANE_TESTS,
    C_GROUP_VOLUMES_BUILT, C_POINT_TESTS, C_GROUP_POINT_TESTS, C_SAMPLE_TESTS, C_SAMPLES_BLOCKED,
    C_MASKS_ALLOCATED, C_MASKS_PEAK, C_REBUILDS, C_FULL_UMBRA_POINTS, C_RASTER_CALLS,
    /* The paper's Table 2 breakdown: phase times (microseconds; the sort is the source's, hpc_method.c) and
     * memory by kind (bytes allocated at the peak). */
    C_SORT_US, C_BUILD_US, C_REBUILD_THREAD_US, C_CAST_US, C_SAMPLE_BYTES, C_HIERARCHY_BYTES, C_MASK_BYTES,
    C_PAIRS_IN_VL,   /* (receiver, triangle) pairs past the point-in-V_L test: the work the samples' tests start from */
    C_PAIRS_FOOTPRINT,   /* of those, the pairs that reach the per-receiver footprint (past the leaf footprint) */
    C_LEAF_CULLS,        /* (leaf, triangle) pairs the leaf footprint rules out for every receiver of the leaf */
    C_LEAF_CULLS_BLOCKED,   /* of the others, those whose candidate samples are blocked already for every receiver */
    C_RECT_PAIRS,        /* (leaf, pair) bounded by the pair's rectangle (one footprint for both triangles) */
    C_SAMPLES_SURE,      /* of the sample tests, those decided on the t range alone (footprint_sure_lanes) */
    C_LEAF_LANE_TESTS,   /* of the sample tests, those made for a leaf's receivers in the lanes (leaf_lanes_sample) */
    C_SAMPLES_TSURE,     /* of samples_sure, those blocked without the t range's operations (t_sure) */
    C_COUNT
};
_Static_assert(C_COUNT == HPC_N_COUNTERS, "hpc.h names the counters");
_Static_assert(C_SORT_US == HPC_COUNTER_SORT_US, "hpc.h names the sort counter");

typedef struct hnode {
    float lo[3], hi[3];
    uint32_t first, count;   /* interior: count 0, children first and first + 1; leaf: points idx[first..] */
    uint64_t gumbra;
    int full;
} hnode;

typedef struct tri_job {
    float v[9], N[3];
    uint32_t self;           /* the triangle's id: receivers on it are not blocked by it */
    int pair;                /* 1: cast together with the next job (a triangle sharing an edge), vl bounds both;
                              * -1: cast with the previous one (its vl unused); 0: alone (pair_batch) */
    int rect;                /* pair 1 only: the two are the halves of one axis-aligned rectangle, corners rc */
    float rc[12];
    hpc_volume vl;
} tri_job;

typedef struct act_group { uint32_t k, planes; } act_group;

/* Per frame, read-only while the triangles are cast. */
typedef struct shared {
    const ms_render_ctx *ctx;
    int sw;                          /* ms_hpc_switches when the cast started */
    int scanline;
    ms_raster_fn raster;
    int k, mw, gs, G, npk;
    int shear_axis;                  /* the light's (ms_light_shear_axis): the packets' preferred axis */
    uint64_t all_groups;
    uint64_t *gmask;                 /* G x mw: the samples of each group */
    int gw0[64], gw1[64];            /* each group's first and last mask word (its rows lie in those only) */
    double light_poly[12];
    double group_poly[64][12];
    float group_i0[64], group_j0[64]; /* each group's first sample column and row (the footprint test) */
    float bit_i[64], bit_j[64];      /* bit b of a mask word: its sample's column, and its row from the word's first */
    int footprint;                   /* hpc (not hpc-scanline) with the footprint test: no V_Gk */
    int pairs;                       /* footprint with p0: triangles sharing an edge cast in pairs (pair_batch) */
    float grid_ds[3], grid_dt[3];    /* the grid's steps, the same for every pixel (pattern.c) */
    float *p0;                       /* per receiver: its grid's origin and footprint_rel (NULL: formed per pair) */
    float light_lo[3], light_hi[3], scale;
    float reach;                     /* farthest distance from the light's box to the receivers' box */
    size_t n;
    const ms_shadow_query *q;
    const uint64_t *front;           /* indexed by the caller's receiver numbers: orig[r] */
    const uint32_t *orig;            /* per receiver: the caller's number (receivers are renumbered in
                                      * hierarchy order, so that a leaf's points lie together in memory) */
    uint64_t *gumbra;                /* per receiver */
    uint8_t *full;
    int32_t *slot;
    size_t slot_bytes, frame_off, kz_off;
} shared;

/* One chunk of receivers with its own hierarchy and mask pool (one thread at a time). */
typedef struct chunk {
    uint32_t base, n0;               /* its receivers' numbers: base .. base + n0 - 1 */
    uint32_t *idx;
    uint32_t n;                      /* points in the hierarchy (full-umbra ones leave at a rebuild) */
    uint32_t umbra_in_tree;
    hnode *nodes;
    uint32_t n_nodes;
    size_t node_bytes_peak;          /* the largest node array this chunk held (Table 2 memory) */
    uint8_t *pool;
    int32_t n_slots, cap_slots, n_free, live, peak;
    int32_t *free_list;
    hpc_volume gvol[64];
    int gvol_built;
    uint64_t cnt[C_COUNT];
    uint32_t lf_leaves, lf_in, lf_kept, lf_cands;   /* leaves that could use the leaf footprint; of those cast
                                                     * with it, the receivers, of those the ones with samples
                                                     * left, and the samples the leaf left (leaf_fp_pays) */
    int failed;
} chunk;

/* ---- receiver hierarchy ---- */

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

static void node_bits_from_points(const shared *sh, const chunk *c, hnode *N)
{
    uint64_t g = sh->all_groups;
    int full = 1;
    for (uint32_t i = N->first; i < N->first + N->count; i++) {
        g &= sh->gumbra[c->idx[i]];
        full &= sh->full[c->idx[i]];
    }
    N->gumbra = g;
    N->full = full;
}

/* (Re)builds the chunk's hierarchy over its points that are not in full umbra. 0, or -1 out of memory. */
static int build_tree(const shared *sh, chunk *c)
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

/* ---- masks on demand (D) ---- */

static uint64_t *slot_mask(const shared *sh, const chunk *c, int32_t s) { return (uint64_t *)(c->pool + (size_t)s * sh->slot_bytes); }
static ms_raster_frame *slot_frame(const shared *sh, const chunk *c, int32_t s) { return (ms_raster_frame *)(c->pool + (size_t)s * sh->slot_bytes + sh->frame_off); }
static int8_t *slot_kz(const shared *sh, const chunk *c, int32_t s) { return (int8_t *)(c->pool + (size_t)s * sh->slot_bytes + sh->kz_off); }

/* The shear axis of each 16-sample packet exactly as the reference tracer chooses it (packet_shear), or -1
 * (lane by lane); for hpc-scanline also the Scanline frame, or -2 in kz[0]'s place for edge-on points. */
static void slot_setup(const shared *sh, chunk *c, int32_t s, const ms_shadow_query *q, const ms_grid *g)
{
    const ms_render_ctx *ctx = sh->ctx;
    const int k = sh->k;
    int8_t *kz = slot_kz(sh, c, s);
    /* ms_wt_packet_axis in the lanes (it was 9% of the cast on the merged bars in scalar form): a packet is
     * 16 consecutive samples of one row (k >= 16), its directions formed as group_block16 forms them, the
     * axis the light's (sh->shear_axis) or else lane 0's largest, kept when every lane's |d| on it is at
     * least half its largest. */
    static const float lane_i[LANES] = { 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15 };
    const l16 li0 = l16_load(lane_i), two = l16_set1(2.0f), zero = l16_set1(0.0f);
    for (int pk = 0; pk < sh->npk; pk++) {
        const int s0 = pk * LANES;
        const l16 li = l16_add(l16_set1((float)(s0 % k)), li0), lj = l16_set1((float)(s0 / k));
        l16 d[3], ad[3];
        float d0[3];
        for (int a = 0; a < 3; a++) {
            d[a] = l16_sub(l16_add(l16_add(l16_set1(g->p0[a]), l16_mul(li, l16_set1(g->ds[a]))), l16_mul(lj, l16_set1(g->dt[a]))),
                           l16_set1(q->p[a]));
            ad[a] = l16_abs(d[a]);
            float tmp[LANES];
            l16_store(tmp, d[a]);
            d0[a] = tmp[0];
        }
        const int z = ms_wt_max_axis(d0), pref = sh->shear_axis;
        const l16 m = l16_max(ad[0], l16_max(ad[1], ad[2]));
        const unsigned ok = l16_le(m, l16_mul(two, ad[z])) & l16_gt(m, zero);
        const unsigned okp = pref >= 0 ? l16_le(m, l16_mul(two, ad[pref])) & l16_gt(m, zero) : 0u;
        kz[pk] = (int8_t)(okp == 0xffffu ? pref : ok == 0xffffu ? z : -1);
    }
    /* kz[npk]: the axis every packet shares, or -1 (leaf_lanes_sample then needs no per-packet look-up) */
    int8_t uni = kz[0];
    for (int pk = 1; pk < sh->npk && uni >= 0; pk++) uni = kz[pk] == uni ? uni : -1;
    kz[sh->npk] = uni;
    if (sh->scanline) {
        ms_raster_frame *f = slot_frame(sh, c, s);
        float n[3], rel[3];
        v3_cross(n, g->ds, g->dt);
        v3_sub(rel, g->p0, q->p);
        const float h = fabsf(v3_dot(n, rel)), dd = v3_len(n) * v3_len(rel);
        if (!(h > EDGE_ON * dd) || ms_raster_frame_init(f, q->p, g, ctx->near, ctx->far, 0) != 0) f->k = 0;   /* edge-on */
    }
}

static int32_t slot_get(const shared *sh, chunk *c)
{
    int32_t s;
    if (c->n_free) s = c->free_list[--c->n_free];
    else {
        if (c->n_slots == c->cap_slots) {
            const int32_t cap = c->cap_slots ? 2 * c->cap_slots : 256;
            uint8_t *p = realloc(c->pool, (size_t)cap * sh->slot_bytes);
            int32_t *fl = realloc(c->free_list, (size_t)cap * sizeof *fl);
            if (p) c->pool = p;
            if (fl) c->free_list = fl;
            if (!p || !fl) return -1;
            c->cap_slots = cap;
        }
        s = c->n_slots++;
    }
    c->live++;
    if (c->live > c->peak) c->peak = c->live;
    c->cnt[C_MASKS_ALLOCATED]++;
    return s;
}

static void slot_put(chunk *c, int32_t s)
{
    c->free_list[c->n_free++] = s;
    c->live--;
}

/* ---- per triangle ---- */

/* A lower bound on the distance between the triangle and the light: the largest gap between their
 * projections on the separating axes of two convex polygons (the box axes, both normals, and the cross
 * products of their edges); a projection never lengthens a distance. 0 when they may touch. */
static double tri_light_gap(const shared *sh, const float v[9])
{
    double T[3][3], L[4][3], ax[14][3];
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) T[i][a] = v[3 * i + a];
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++) L[i][a] = sh->light_poly[3 * i + a];
    int n = 0;
    for (int a = 0; a < 3; a++) { ax[n][0] = a == 0; ax[n][1] = a == 1; ax[n][2] = a == 2; n++; }
    double te[3][3], le[2][3];
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) te[i][a] = T[(i + 1) % 3][a] - T[i][a];
    for (int a = 0; a < 3; a++) { le[0][a] = L[1][a] - L[0][a]; le[1][a] = L[3][a] - L[0][a]; }
#define CROSS(r, x, y) (r[0] = x[1] * y[2] - x[2] * y[1], r[1] = x[2] * y[0] - x[0] * y[2], r[2] = x[0] * y[1] - x[1] * y[0])
    CROSS(ax[n], te[0], te[1]); n++;
    CROSS(ax[n], le[0], le[1]); n++;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 2; j++) { CROSS(ax[n], te[i], le[j]); n++; }
#undef CROSS
    double gap = 0.0;
    for (int k = 0; k < n; k++) {
        const double len = sqrt(ax[k][0] * ax[k][0] + ax[k][1] * ax[k][1] + ax[k][2] * ax[k][2]);
        if (!(len > 0.0)) continue;
        double tmin = INFINITY, tmax = -INFINITY, lmin = INFINITY, lmax = -INFINITY;
        for (int i = 0; i < 3; i++) {
            const double d = (T[i][0] * ax[k][0] + T[i][1] * ax[k][1] + T[i][2] * ax[k][2]) / len;
            tmin = fmin(tmin, d); tmax = fmax(tmax, d);
        }
        for (int i = 0; i < 4; i++) {
            const double d = (L[i][0] * ax[k][0] + L[i][1] * ax[k][1] + L[i][2] * ax[k][2]) / len;
            lmin = fmin(lmin, d); lmax = fmax(lmax, d);
        }
        gap = fmax(gap, fmax(lmin - tmax, tmin - lmax));
    }
    return gap;
}

/* The culling margin for a triangle (see the departures above). The exact test rounds the vertices and the
 * sample relative to the receiver, by ulps of their distance to it (at most sh->reach, the farthest
 * distance from the light's box to the receivers' box); a ray from a sample through the triangle passes it
 * at least D from the sample (D: the larger of tri_light_gap and the gap between the bounding boxes, less
 * a relative 1e-6 for their rounding), so an error at
 * the triangle moves the shadow at the receiver by up to reach / D. The samples' own rounding is absorbed
 * by the polygons (setup_light), the plane evaluation's by ulps of the coordinates. 256 ulps of each for
 * safety; a triangle that may touch the light: infinite (no culling). The coordinates (sc, sh->scale) are
 * the scene frame's (scene_frame.c), within 6 half-extents of the geometry at any distance from the
 * world's origin, so the margin and the volumes' planes cull as they do at home. */
static float tri_margin(const shared *sh, const float v[9])
{
    float sc = sh->scale, box2 = 0.0f;
    for (int a = 0; a < 3; a++) {   /* the gap between the bounding boxes, another lower bound */
        const float lo = ms_minf(v[a], ms_minf(v[3 + a], v[6 + a])), hi = ms_maxf(v[a], ms_maxf(v[3 + a], v[6 + a]));
        const float g = ms_maxf(sh->light_lo[a] - hi, lo - sh->light_hi[a]);
        if (g > 0.0f) box2 += g * g;
        sc = ms_maxf(sc, ms_maxf(fabsf(lo), fabsf(hi)));
    }
    const float D = (float)(fmax(tri_light_gap(sh, v), sqrt((double)box2)) - 1e-6 * sc);
    if (!(D > 1e-6f * sc)) return INFINITY;
    return 256.0f * 1.1920929e-07f * (sc + sh->reach * (1.0f + 4.0f * sh->reach / D));
}

static void build_group_volumes(const shared *sh, chunk *c, const tri_job *t)
{
    for (int g = 0; g < sh->G; g++) hpc_volume_build(&c->gvol[g], sh->group_poly[g], 4, t->v, t->vl.eps);
    c->gvol_built = 1;
    c->cnt[C_GROUP_VOLUMES_BUILT]++;
}

/* The reference tracer's lane test for one sample (ray_triangle.h, as raytrace's packets): 1 if the
 * triangle blocks the segment from the receiver o to o + d at a parameter in [near, far]. A, B, C: the
 * vertices minus o; num: ms_wt_offset(o, tri, N). */
static int sample_blocked(const float o[3], const float d[3], int kz, const float *tri, const float N[3],
                          const float A[3], const float B[3], const float C[3], float num, float tmin, float tmax)
{
    if (kz < 0) return ms_wt_segment(o, d, tri, N, tmin, tmax);
    const int kx = kz + 1 == 3 ? 0 : kz + 1, ky = kx + 1 == 3 ? 0 : kx + 1;
    const float inv = 1.0f / d[kz];
    return ms_wt_segment_sheared(A, B, C, kz, d[kx] * inv, d[ky] * inv, d, N, num, tmin, tmax);
}

/* Alpha-tested triangle t (alpha.h) at sample (i, j) of q's grid: 1 where it occludes. The sample point is the
 * pattern's float, formed as ms_pattern_points_range forms it. */
static int alpha_opaque(const shared *sh, const tri_job *t, const ms_shadow_query *q, const ms_grid *g, int i, int j)
{
    float L[3];
    for (int a = 0; a < 3; a++) L[a] = g->p0[a] + (float)i * g->ds[a] + (float)j * g->dt[a];
    return ms_alpha_segment_occludes(sh->ctx->alpha, t->self, q->p, L);
}

/* ---- the footprint test (hpc, in place of the paper's group volumes V_Gk) ----
 *
 * Departure from the paper. For a receiver p and a triangle (vertices A, B, C relative to p, the floats the
 * exact test uses), the exact test's edge functions for the direction d are U = ((C x B) . d) / d[kz],
 * V = ((A x C) . d) / d[kz], W = ((B x A) . d) / d[kz] (the 2D cross product of two vertices sheared along d
 * is the triple product over d[kz]), and it reports a hit only when they do not have strictly mixed signs.
 * The sample directions d(i, j) = p0 + i ds + j dt - p of the receiver's grid are affine in (i, j), so each
 * E_e = (X_e . d) is an affine function e0 + i e1 + j e2 of the sample's indices: the triangle's footprint on
 * the light, in the grid's own coordinates, for this one receiver (V_Gk bounds it over the whole group
 * polygon and all pixels' grids, and costs 24 double-precision planes per group and triangle). A group or a
 * lane is rejected when over all its samples some E_e > s_e and some E_e' < -s_e'.
 *
 * The slack s_e bounds the exact test's rounding, so that no sample it calls blocked is ever rejected: with
 * the shear |sx|, |sy| <= 2 (the packet axis, ms_wt_packet_axis; 1 for a lane's own axis) the sheared
 * coordinates are off by at most 9.1 u |V|inf (u = 2^-24, V the vertex), U by at most 146 u |Y1|inf
 * |Y2|inf for the two vertices Y1, Y2 of its edge (the double fall-back at a zero edge only rounds less),
 * so E = U d[kz] by 146 u |Y1| |Y2| |d|inf; the float direction d is off the affine d(i, j) by at most
 * 5 u S per component (S = |p0| + k |ds| + k |dt| + |p|, all inf-norms), which moves E by at most
 * |X_e|_1 5 u S <= 30 u |Y1| |Y2| S; and this test's own float evaluation (the cross product, the three
 * dots, the affine sum) errs by at most 90 u |Y1| |Y2| dmax (dmax >= |d|inf of every sample). s_e =
 * u |Y1| |Y2| (512 dmax + 128 S) covers the sum twice. The t range and alpha only remove hits. */
typedef struct hpc_footprint {
    float e[4][3];   /* per edge function, and their sum (e[3]): e0, e1 (per column i), e2 (per row j) */
    float s[3];      /* per edge function: the slack */
    float dlo[4], dhi[4];   /* each function's least and largest change over a group from its first sample */
} hpc_footprint;

/* dlo, dhi of a group of gs x gs samples (span = gs - 1) from the coefficients e1, e2 (footprint_groups);
 * cast_leaf_footprint forms the same per lane, 16 receivers at once. */
static void footprint_spans(hpc_footprint *f, float span)
{
    for (int e = 0; e < 4; e++) {
        const float di = f->e[e][1] * span, dj = f->e[e][2] * span;
        f->dlo[e] = ms_minf(di, 0.0f) + ms_minf(dj, 0.0f);
        f->dhi[e] = ms_maxf(di, 0.0f) + ms_maxf(dj, 0.0f);
    }
}

static inline float inf_norm3(const float v[3]) { return ms_maxf(fabsf(v[0]), ms_maxf(fabsf(v[1]), fabsf(v[2]))); }

/* The slack's factor for a receiver at p with grid g: u (512 dmax + 128 S), 1% up for its own rounding. */
static float footprint_rel(const ms_grid *g, const float p[3], int k)
{
    float dmax = 0.0f, S = 0.0f;
    for (int a = 0; a < 3; a++) {
        const float ext = (float)(k - 1) * (fabsf(g->ds[a]) + fabsf(g->dt[a]));
        dmax = ms_maxf(dmax, fabsf(g->p0[a] - p[a]) + ext);           /* >= |d|inf of every sample */
        S = ms_maxf(S, fabsf(g->p0[a]) + ext + fabsf(p[a]));
    }
    return 5.9604645e-08f * (1.01f * (512.0f * dmax + 128.0f * S));
}

/* rel: footprint_rel of the receiver. */
static void footprint_setup(hpc_footprint *f, const float A[3], const float B[3], const float C[3], const ms_grid *g,
                            const float p[3], float rel)
{
    const float *Y[3][2] = { { C, B }, { A, C }, { B, A } };
    const float w[3] = { g->p0[0] - p[0], g->p0[1] - p[1], g->p0[2] - p[2] };
    const float nA = inf_norm3(A), nB = inf_norm3(B), nC = inf_norm3(C);
    const float nrm[3][2] = { { nC, nB }, { nA, nC }, { nB, nA } };
    for (int e = 0; e < 3; e++) {
        float X[3];
        v3_cross(X, Y[e][0], Y[e][1]);
        f->e[e][0] = v3_dot(X, w);
        f->e[e][1] = v3_dot(X, g->ds);
        f->e[e][2] = v3_dot(X, g->dt);
        f->s[e] = rel * nrm[e][0] * nrm[e][1];
    }
    for (int c = 0; c < 3; c++) f->e[3][c] = f->e[0][c] + f->e[1][c] + f->e[2][c];
}

/* Which sign a hit needs, from the sum of the edge functions, E_sum = -((B - A) x (C - A)) . d (which side of
 * the triangle's plane the direction points to): a hit has all three of one sign (zeros aside), so where
 * E_sum stays above twice the sum of the slacks (its coefficients' and evaluation's rounding are far below
 * them) not all three can be <= 0 up to their slacks: all are >= 0, and any E_e < -s_e rules the samples
 * out; alike below. Elsewhere (the plane through the receiver parallel to the triangle crosses these
 * samples) only mixed signs beyond the slacks rule them out. lo, hi: bounds of E_0, E_1, E_2 and E_sum over
 * each lane's samples; s: each lane's slacks. Returns the lanes that may be hit. */
static inline unsigned footprint_keep_n(const l16 *lo, const l16 *hi, const l16 *s, int n)
{
    l16 ss = s[0];
    for (int e = 1; e < n; e++) ss = l16_add(ss, s[e]);
    const l16 s2 = l16_mul(l16_set1(2.0f), ss);
    const unsigned up = l16_gt(lo[n], s2), down = l16_lt(hi[n], l16_sub(l16_set1(0.0f), s2));
    unsigned pos = 0, neg = 0;
    for (int e = 0; e < n; e++) {
        pos |= l16_gt(lo[e], s[e]);                          /* E_e > s_e throughout */
        neg |= l16_lt(hi[e], l16_sub(l16_set1(0.0f), s[e]));   /* E_e < -s_e throughout */
    }
    return ~((pos & neg) | (up & neg) | (down & pos)) & 0xffffu;
}

/* A triangle's three functions and their sum (lo[3], hi[3]). */
static inline unsigned footprint_keep_lanes(const l16 lo[4], const l16 hi[4], const l16 s[3]) { return footprint_keep_n(lo, hi, s, 3); }

/* The same with one slack for every lane (a receiver's functions over 16 groups or samples). */
static inline unsigned footprint_keep(const l16 lo[4], const l16 hi[4], const float s[3])
{
    const l16 sl[3] = { l16_set1(s[0]), l16_set1(s[1]), l16_set1(s[2]) };
    return footprint_keep_lanes(lo, hi, sl);
}

/* The lanes whose samples the exact test's edge functions surely pass: all three E_e beyond their slacks with one
 * sign. The slack bounds |E_e - U_e d[kz]| by half of s_e (above: it covers the error sum twice), so there each
 * of the exact test's U, V, W is nonzero with the sign of E_e d[kz]: no zero edge (no double fall-back), no
 * mixed signs, det = U + V + W nonzero. Only the t range is then left to decide (block_hits). A slack below
 * the normal range proves nothing (its product may have underflowed): footprint_slack_ok gives the lanes whose
 * three slacks are normal, valid; the others are left to the exact test. */
static inline unsigned footprint_sure_lanes(const l16 E[3], const l16 s[3], unsigned valid)
{
    unsigned pos = valid, neg = valid;
    for (int e = 0; e < 3; e++) {
        pos &= l16_gt(E[e], s[e]);
        neg &= l16_lt(E[e], l16_sub(l16_set1(0.0f), s[e]));
    }
    return pos | neg;
}

static inline unsigned footprint_slack_ok(const l16 s[3])
{
    const l16 tiny = l16_set1(1e-30f);
    return l16_gt(s[0], tiny) & l16_gt(s[1], tiny) & l16_gt(s[2], tiny);
}

/* The groups (bit gk) whose samples the footprint may hold, bounding each edge function over the group's
 * gs x gs samples (16 groups per operation). base: each function at each group's first sample, [e][gk]. */
static uint64_t footprint_groups(const shared *sh, const hpc_footprint *f, float base[4][64])
{
    const float *dlo = f->dlo, *dhi = f->dhi;
    uint64_t cand = 0;
    for (int g0 = 0; g0 < sh->G; g0 += LANES) {
        const l16 gi = l16_load(sh->group_i0 + g0), gj = l16_load(sh->group_j0 + g0);
        l16 lo[4], hi[4];
        for (int e = 0; e < 4; e++) {
            const l16 b = l16_add(l16_add(l16_set1(f->e[e][0]), l16_mul(l16_set1(f->e[e][1]), gi)), l16_mul(l16_set1(f->e[e][2]), gj));
            l16_store(base[e] + g0, b);
            lo[e] = l16_add(b, l16_set1(dlo[e]));
            hi[e] = l16_add(b, l16_set1(dhi[e]));
        }
        cand |= (uint64_t)footprint_keep(lo, hi, f->s) << g0;
    }
    return cand & sh->all_groups;
}

/* The lanes of the 16-sample block at (i0, j0) the footprint may hold; off[e]: the block's offsets
 * e1 di + e2 dj per lane, made once per pair (footprint_offsets). gbase: the functions at the block's first
 * sample when it is a group's first (footprint_groups made them), else NULL. E: the functions per lane, for
 * the sure lanes (footprint_sure_lanes), which the caller asks only of blocks with lanes to test. */
static unsigned footprint_lanes(const hpc_footprint *f, const l16 off[4], int i0, int j0, const float *gbase, int gk,
                                l16 E[4])
{
    for (int e = 0; e < 4; e++)
        E[e] = l16_add(l16_set1(gbase ? gbase[64 * e + gk] : f->e[e][0] + f->e[e][1] * (float)i0 + f->e[e][2] * (float)j0), off[e]);
    return footprint_keep(E, E, f->s);
}

static void footprint_offsets(const hpc_footprint *f, l16 oi, l16 oj, l16 off[4])
{
    for (int e = 0; e < 4; e++) off[e] = l16_add(l16_mul(l16_set1(f->e[e][1]), oi), l16_mul(l16_set1(f->e[e][2]), oj));
}

/* ---- the leaf footprint (hpc: the footprint test bounded over a whole leaf) ----
 *
 * Departure from the paper (whose group volumes V_Gk cull whole light groups at a node): the footprint test's
 * edge functions bounded over every receiver of a leaf at once, per light sample. The leaf's receivers lie in
 * a box (centre pc, half extents h) and their grid origins in a box (centre p0c, half extents J); all share
 * the grid's steps ds, dt. For receiver p = pc + q and origin p0 = p0c + j, with Y1, Y2 an edge's vertices
 * relative to pc and x' = w + i ds + j dt (w = p0c - pc) the sample relative to pc, the edge function
 * E = det(Y1 - q, Y2 - q, x' + j - q) is affine in q and in the sample, so, exactly in reals,
 *     E = X . x' + X . j + g(i, j) . q - q . (D x j),   X = Y1 x Y2, D = Y2 - Y1, g = -(X + D x x'),
 * and |E - X . x'| <= sum_c h_c |g_c(i, j)| + sum_c |X_c| J_c + sum_c h_c (|D_c+1| J_c+2 + |D_c+2| J_c+1).
 * g is affine in (i, j), so over a group of gs x gs samples |g_c| <= |g_c(centre)| + (gs-1)/2 (|g_1c| + |g_2c|)
 * (g_1, g_2 its steps): one bound U per function and group. The sum of the three functions (the side of the
 * triangle's plane) is Xs . (x' + j - q), Xs = the sum of the X: its bound is sum_c |Xs_c| (J_c + h_c).
 * footprint_keep then rules a sample out for every receiver of the leaf when E_c - U and E_c + U (E_c = X . x')
 * are beyond the slacks. The slack is the footprint test's for a receiver anywhere in the box with an origin
 * anywhere in its box (|Y - p|inf <= |Y1|inf + |h|inf, dmax and S over both boxes), taken twice: it covers the
 * exact test's rounding as the per-receiver footprint's does, the exact test's vertices being v - p rounded
 * (u of them: at most 12 u |Y1| |Y2| dmax in E, where the bound above is for v - p exact), and this bound's own
 * evaluation (E_c is the footprint's arithmetic at pc; U is a sum of non-negative terms, rounded up by 1e-3 of
 * itself, plus 20 u of the magnitudes of g's terms, which may cancel). So no sample
 * the exact test blocks for any receiver of the leaf is ever ruled out. What it buys: a leaf whose triangle
 * covers no sample of any receiver (a thin bar whose shadow passes between the sample rows of the leaf's
 * receivers) is dropped with one test instead of one footprint per receiver, and the candidate samples of
 * the others bound each receiver's groups and lanes. */
typedef struct leaf_box { float pc[3], h[3], p0c[3], J[3]; } leaf_box;

/* The bound's terms per edge function of a shape (leaf_setup: a triangle, or a rectangle pair's rectangle) and
 * the sum's (at [nf]). */
typedef struct leaf_fn {
    int nf;                   /* edge functions: 3 (a triangle) or 4 (a rectangle) */
    float e[5][3], s[4];      /* E_c's coefficients (as hpc_footprint's), the slacks */
    float gst[4][3][3];       /* per function: g at the grid's origin, per column, per row */
    float ufix[5], uspan[4];  /* per function: U's terms that do not depend on the group */
} leaf_fn;

/* ---- rectangle pairs (hpc: one leaf footprint for a pair that is an axis-aligned rectangle) ----
 *
 * A pair (pair_batch) whose triangles are the two halves of one axis-aligned rectangle (ms_coplanar_rect_pair,
 * the test coplanar.c merges by: every vertex on one plane, the corners a rectangle, all bitwise) covers exactly
 * that rectangle. Its corners P0..P3 in order around it, the first triangle T0 = (P0, P1, P2), the second
 * T1 = (P0, P2, P3). Relative to a receiver p, as reals (the corners' floats minus p exactly) and for a
 * direction d, the sides' functions are F_i = (P_i+1 x P_i) . d (the footprint's orientation) and the
 * diagonal's D = (P0 x P2) . d: T0's three functions are F0, F1, D and T1's F2, F3, -D (each up to one sign for
 * all three: its own winding). The corners are a parallelogram, P3 = P0 + P2 - P1 exactly in the reals, so
 * P3 x P2 = P0 x P2 + P2 x P1 and P0 x P3 = P0 x P2 + P1 x P0, i.e. exactly
 *     F2 = F1 + D,   F3 = F0 + D.
 * The footprint test's argument (above) makes a sample T0's exact test blocks have T0's three real functions
 * all >= -e or all <= e, e the exact test's error (146 u |Y1| |Y2| dmax, 30 u |Y1| |Y2| S for the direction,
 * and 12 u |Y1| |Y2| dmax for its vertices v - p rounded, as the leaf footprint's comment: at most
 * u M^2 (158 dmax + 30 S), M the largest |P_i - p|inf). Then F2 = F1 + D and F3 = F0 + D are >= -2e (alike
 * <= 2e), and for T1 F0 = F3 - D, F1 = F2 - D likewise: all four sides have no strictly mixed signs beyond 2e,
 * which is the convexity of the rectangle made exact. Each side evaluated (the footprint's arithmetic, off by
 * at most u M^2 102 dmax with the vertices' rounding) is then beyond -s_R for every block by either triangle
 * when s_R >= 2e + 102 u M^2 dmax = u M^2 (418 dmax + 60 S); s_R = RECT_SLACK rel M^2 = 2.02 u M^2
 * (512 dmax + 128 S) covers that twice. The sum of the four is twice either triangle's sum (2 (F0 + F1 + D));
 * a block with all of T0's or T1's functions <= e makes it at most 6e (the evaluated one below 8 s_R), so where
 * it exceeds 2 x the four slacks (8 s_R) the block has the >= signs, and any side below -s_R rules the sample
 * out; alike below: footprint_keep's logic with four functions (footprint_keep_n).
 * Each side is an edge function of two corners, so the leaf footprint's bound over a box of receivers and grid
 * origins applies to it unchanged, and the sum's, Xs . (x' + j - q), Xs = the sum of the P_i+1 x P_i (which
 * does not depend on q around a closed polygon), has the triangle's bound |Xs| . (J + h); the slack is s_R for
 * any receiver in the box (M from the corners' distances to the box centre plus its half extent), taken twice,
 * as the triangle's. So one leaf footprint serves the pair (leaf_setup of 4 functions instead of 6, one
 * leaf_footprint instead of two, no sample either triangle blocks for any receiver of the leaf ruled out).
 * Its candidates are then looped over once for the leaf's receivers, where the four sides and D are evaluated
 * per lane and each triangle's own footprint test (F0, F1, D and F2, F3, -D: its own functions exactly, as a
 * cross product's operands swapped and a negation are exact; their sums from the values, whose rounding is far
 * below the slacks) picks its samples, so that each triangle's exact tests stay on its own candidates (the
 * rectangle's for both doubled the exact tests). MS_HPC_OFF_RECT: every pair as two triangles. */

/* A footprint's shape: a triangle (3 vertices, its own edge functions) or a rectangle pair's rectangle (4
 * corners in order around it; "rectangle pairs" below). fp_edges: each function's two vertices, Y1 x Y2, the
 * same orientation for both (C x B, A x C, B x A as footprint_setup; P1 x P0, ..., P0 x P3 around the
 * rectangle). */
typedef struct fp_shape { const float *v; int nv; } fp_shape;
static const int fp_edges[2][4][2] = { { { 2, 1 }, { 0, 2 }, { 1, 0 }, { 0, 0 } }, { { 1, 0 }, { 2, 1 }, { 3, 2 }, { 0, 3 } } };

/* The slack's factor of a rectangle's functions (above): s_R = RECT_SLACK rel M^2, M the largest |corner - p|inf. */
#define RECT_SLACK 2.0f

/* A rectangle pair's functions per receiver: its four sides and the diagonal P0 x P2 (the first triangle's
 * third function; the second's is its negation, exactly); rect_tri: each triangle's three of them (above). */
static const int rect_fns[5][2] = { { 1, 0 }, { 2, 1 }, { 3, 2 }, { 0, 3 }, { 0, 2 } };
static const int rect_tri[2][3] = { { 0, 1, 4 }, { 2, 3, 4 } };

/* leaf_fn of the ns shapes shp for box b: the functions of all shapes in the lanes (up to 6), each lane the
 * arithmetic the comments above give (IEEE per lane, as everywhere in lanes16.h). */
static void leaf_setup(const shared *sh, const leaf_box *b, const fp_shape *shp, int ns, leaf_fn *out)
{
    const int k = sh->k, gs = sh->gs;
    const float *ds = sh->grid_ds, *dt = sh->grid_dt;
    float w[3], hmax = 0.0f, dmax = 0.0f, S = 0.0f;
    for (int a = 0; a < 3; a++) {
        w[a] = b->p0c[a] - b->pc[a];
        hmax = ms_maxf(hmax, b->h[a]);
        const float ext = (float)(k - 1) * (fabsf(ds[a]) + fabsf(dt[a]));
        dmax = ms_maxf(dmax, fabsf(w[a]) + b->J[a] + b->h[a] + ext);
        S = ms_maxf(S, fabsf(b->p0c[a]) + b->J[a] + ext + fabsf(b->pc[a]) + b->h[a]);
    }
    const float rel = 2.0f * 5.9604645e-08f * (1.01f * (512.0f * dmax + 128.0f * S));
    float y1[3][LANES] = { { 0 } }, y2[3][LANES] = { { 0 } }, n12[LANES] = { 0 };
    int lane0[2];
    for (int u = 0, l = 0; u < ns; u++) {
        const int nv = shp[u].nv, (*pair)[2] = fp_edges[nv == 4];
        float Y[4][3], nY[4], M = 0.0f;
        for (int v = 0; v < nv; v++) {
            for (int a = 0; a < 3; a++) Y[v][a] = shp[u].v[3 * v + a] - b->pc[a];
            nY[v] = inf_norm3(Y[v]) + hmax;
            M = ms_maxf(M, nY[v]);
        }
        lane0[u] = l;
        for (int f = 0; f < nv; f++, l++) {
            for (int a = 0; a < 3; a++) { y1[a][l] = Y[pair[f][0]][a]; y2[a][l] = Y[pair[f][1]][a]; }
            n12[l] = nv == 4 ? RECT_SLACK * M * M : nY[pair[f][0]] * nY[pair[f][1]];
        }
    }
    l16 Y1[3], Y2[3], X[3], D[3], Dw[3], Dds[3], Ddt[3];
    for (int a = 0; a < 3; a++) { Y1[a] = l16_load(y1[a]); Y2[a] = l16_load(y2[a]); D[a] = l16_sub(Y2[a], Y1[a]); }
    const l16 W[3] = { l16_set1(w[0]), l16_set1(w[1]), l16_set1(w[2]) };
    const l16 DS[3] = { l16_set1(ds[0]), l16_set1(ds[1]), l16_set1(ds[2]) }, DT[3] = { l16_set1(dt[0]), l16_set1(dt[1]), l16_set1(dt[2]) };
#define HPC_CROSS16(r, x, y)                                                                   \
    (r[0] = l16_sub(l16_mul(x[1], y[2]), l16_mul(x[2], y[1])),                                 \
     r[1] = l16_sub(l16_mul(x[2], y[0]), l16_mul(x[0], y[2])),                                 \
     r[2] = l16_sub(l16_mul(x[0], y[1]), l16_mul(x[1], y[0])))
#define HPC_DOT16(x, y) l16_add(l16_add(l16_mul(x[0], y[0]), l16_mul(x[1], y[1])), l16_mul(x[2], y[2]))
    HPC_CROSS16(X, Y1, Y2);
    HPC_CROSS16(Dw, D, W);
    HPC_CROSS16(Dds, D, DS);
    HPC_CROSS16(Ddt, D, DT);
    float E0[LANES], E1[LANES], E2[LANES], SL[LANES], G[3][3][LANES], UF[LANES], US[LANES], XA[3][LANES];
    l16_store(E0, HPC_DOT16(X, W));
    l16_store(E1, HPC_DOT16(X, DS));
    l16_store(E2, HPC_DOT16(X, DT));
#undef HPC_CROSS16
#undef HPC_DOT16
    l16_store(SL, l16_mul(l16_set1(rel), l16_load(n12)));
    const l16 zero = l16_set1(0.0f);
    l16 jx = zero, kx = zero, sp = zero, mag = l16_add(l16_add(l16_abs(X[0]), l16_abs(X[1])), l16_abs(X[2]));
    const l16 nD = l16_add(l16_add(l16_abs(D[0]), l16_abs(D[1])), l16_abs(D[2]));
    for (int a = 0; a < 3; a++) {
        const int a1 = (a + 1) % 3, a2 = (a + 2) % 3;
        l16_store(G[0][a], l16_sub(zero, l16_add(X[a], Dw[a])));
        l16_store(G[1][a], l16_sub(zero, Dds[a]));
        l16_store(G[2][a], l16_sub(zero, Ddt[a]));
        l16_store(XA[a], X[a]);
        const l16 h = l16_set1(b->h[a]);
        jx = l16_add(jx, l16_mul(l16_abs(X[a]), l16_set1(b->J[a])));
        kx = l16_add(kx, l16_mul(h, l16_add(l16_mul(l16_abs(D[a1]), l16_set1(b->J[a2])), l16_mul(l16_abs(D[a2]), l16_set1(b->J[a1])))));
        sp = l16_add(sp, l16_mul(h, l16_add(l16_abs(Dds[a]), l16_abs(Ddt[a]))));
        /* the rounding of g's terms (X + D x w may cancel) and of their affine sums: 20 u of the magnitudes */
        mag = l16_add(mag, l16_mul(l16_mul(l16_set1(2.0f), nD), l16_set1(fabsf(w[a]) + (float)k * (fabsf(ds[a]) + fabsf(dt[a])))));
    }
    l16_store(UF, l16_add(l16_add(jx, kx), l16_mul(l16_set1(1.2e-6f * (b->h[0] + b->h[1] + b->h[2])), mag)));
    l16_store(US, l16_mul(l16_set1(0.5f * (float)(gs - 1)), sp));
    for (int u = 0; u < ns; u++) {
        leaf_fn *o = &out[u];
        const int nf = shp[u].nv;
        o->nf = nf;
        float Xs[3] = { 0.0f, 0.0f, 0.0f };
        for (int f = 0; f < nf; f++) {
            const int l = lane0[u] + f;
            o->e[f][0] = E0[l];
            o->e[f][1] = E1[l];
            o->e[f][2] = E2[l];
            o->s[f] = SL[l];
            for (int q = 0; q < 3; q++)
                for (int a = 0; a < 3; a++) o->gst[f][q][a] = G[q][a][l];
            o->ufix[f] = UF[l];
            o->uspan[f] = US[l];
            for (int a = 0; a < 3; a++) Xs[a] += XA[a][l];
        }
        for (int c = 0; c < 3; c++) {
            o->e[nf][c] = o->e[0][c] + o->e[1][c] + o->e[2][c];
            if (nf == 4) o->e[nf][c] += o->e[3][c];
        }
        o->ufix[nf] = 0.0f;
        for (int a = 0; a < 3; a++) o->ufix[nf] += fabsf(Xs[a]) * (b->J[a] + b->h[a]);
        o->ufix[nf] *= 1.001f;
    }
}

/* The samples (bits as a mask's) a triangle (its leaf_fn) may block for some receiver of box b, in cand (mw
 * words); its groups are returned (0: the triangle blocks no sample of any of them). */
static uint64_t leaf_footprint(const shared *sh, const leaf_box *b, const leaf_fn *fn, uint64_t *cand)
{
    const int k = sh->k, gs = sh->gs, rows = LANES / gs;
    const float (*e)[3] = fn->e, *ufix = fn->ufix, *uspan = fn->uspan;
    const int nf = fn->nf;
    const l16 s[4] = { l16_set1(fn->s[0]), l16_set1(fn->s[1]), l16_set1(fn->s[2]), l16_set1(nf == 4 ? fn->s[3] : 0.0f) };
    /* the groups: each function at each group's first sample, its change over the group, +- U */
    float base[5][64], U[4][64];
    uint64_t groups = 0;
    const float half = 0.5f * (float)(gs - 1), span = (float)(gs - 1);
    for (int g0 = 0; g0 < sh->G; g0 += LANES) {
        const l16 gi = l16_load(sh->group_i0 + g0), gj = l16_load(sh->group_j0 + g0);
        const l16 ci = l16_add(gi, l16_set1(half)), cj = l16_add(gj, l16_set1(half));
        l16 lo[5], hi[5];
        for (int f = 0; f <= nf; f++) {
            const l16 bs = l16_add(l16_add(l16_set1(e[f][0]), l16_mul(l16_set1(e[f][1]), gi)), l16_mul(l16_set1(e[f][2]), gj));
            l16_store(base[f] + g0, bs);
            l16 u = l16_set1(ufix[f]);
            if (f < nf) {
                l16 acc = l16_set1(ufix[f] + uspan[f]);
                for (int a = 0; a < 3; a++) {
                    const l16 ga = l16_add(l16_add(l16_set1(fn->gst[f][0][a]), l16_mul(l16_set1(fn->gst[f][1][a]), ci)),
                                           l16_mul(l16_set1(fn->gst[f][2][a]), cj));
                    acc = l16_add(acc, l16_mul(l16_abs(ga), l16_set1(b->h[a])));
                }
                u = l16_mul(acc, l16_set1(1.001f));
                l16_store(U[f] + g0, u);
            }
            const float di = e[f][1] * span, dj = e[f][2] * span;
            lo[f] = l16_sub(l16_add(bs, l16_set1(ms_minf(di, 0.0f) + ms_minf(dj, 0.0f))), u);
            hi[f] = l16_add(l16_add(bs, l16_set1(ms_maxf(di, 0.0f) + ms_maxf(dj, 0.0f))), u);
        }
        groups |= (uint64_t)footprint_keep_n(lo, hi, s, nf) << g0;
    }
    groups &= sh->all_groups;
    memset(cand, 0, (size_t)sh->mw * sizeof *cand);
    if (!groups) return 0;
    static const float off[2][2][LANES] = {
        { { 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3 }, { 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3 } },
        { { 0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7 }, { 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1 } } };
    const int wi = gs == 8;
    const l16 oi = l16_load(off[wi][0]), oj = l16_load(off[wi][1]);
    l16 foff[5];
    for (int f = 0; f <= nf; f++) foff[f] = l16_add(l16_mul(l16_set1(e[f][1]), oi), l16_mul(l16_set1(e[f][2]), oj));
    const uint64_t seg = (UINT64_C(1) << gs) - 1u;
    uint64_t out = 0;
    for (uint64_t m = groups; m; m &= m - 1) {
        const int gk = __builtin_ctzll(m);
        const int i0 = (int)sh->group_i0[gk], j0 = (int)sh->group_j0[gk];
        for (int jb = j0; jb < j0 + gs; jb += rows) {
            l16 lo[5], hi[5];
            for (int f = 0; f <= nf; f++) {
                const float b0 = jb == j0 ? base[f][gk] : e[f][0] + e[f][1] * (float)i0 + e[f][2] * (float)jb;
                const l16 E = l16_add(l16_set1(b0), foff[f]), u = l16_set1(f < nf ? U[f][gk] : ufix[nf]);
                lo[f] = l16_sub(E, u);
                hi[f] = l16_add(E, u);
            }
            const unsigned keep = footprint_keep_n(lo, hi, s, nf);
            if (!keep) continue;
            out |= UINT64_C(1) << gk;
            for (int rr = 0; rr < rows; rr++) {
                const int s0 = (jb + rr) * k + i0;
                cand[s0 >> 6] |= (uint64_t)(keep >> (rr * gs) & seg) << (s0 & 63);
            }
        }
    }
    return out;
}

/* Tests the open samples of group gk of receiver r (L68-L71); returns 1 when none is left open. An
 * alpha-tested triangle blocks a sample only where it is opaque (any hit, alpha.h). */
static int cast_group(const shared *sh, chunk *c, uint64_t *open, const int8_t *kz, int gk, const ms_shadow_query *q,
                      const ms_grid *g, const tri_job *t, const float A[3], const float B[3], const float C[3], float num)
{
    const int k = sh->k, gs = sh->gs, gpr = k / gs;
    const int i0 = (gk % gpr) * gs, j0 = (gk / gpr) * gs;
    const uint64_t seg = (UINT64_C(1) << gs) - 1u;   /* gs <= 8 */
    const int alpha = ms_alpha_tested(sh->ctx->alpha, t->self);
    int left = 0;
    for (int j = j0; j < j0 + gs; j++) {
        const int s0 = j * k + i0, w = s0 >> 6, b = s0 & 63;
        uint64_t bits = open[w] >> b & seg;
        while (bits) {
            const int di = __builtin_ctzll(bits);
            bits &= bits - 1u;
            const int i = i0 + di, s = s0 + di;
            float d[3];
            for (int a = 0; a < 3; a++) d[a] = (g->p0[a] + (float)i * g->ds[a] + (float)j * g->dt[a]) - q->p[a];
            c->cnt[C_SAMPLE_TESTS]++;
            if (sample_blocked(q->p, d, kz[s / LANES], t->v, t->N, A, B, C, num, sh->ctx->near, sh->ctx->far) &&
                !(alpha && !alpha_opaque(sh, t, q, g, i, j))) {
                open[w] &= ~(UINT64_C(1) << (b + di));
                c->cnt[C_SAMPLES_BLOCKED]++;
            }
        }
        left |= (open[w] >> b & seg) != 0;
    }
    return !left;
}

/* sel3(m0, m1, x0, x1, x2): per lane x0 where m0, x1 where m1, else x2 (a lane's component by its axis). */
static inline l16 sel3(unsigned m0, unsigned m1, l16 x0, l16 x1, l16 x2) { return l16_select(m0, x0, l16_select(m1, x1, x2)); }

/* The hard-shadow test (L70) of 16 rays in the lanes, each lane what sample_blocked computes for its ray, in the
 * same order: ray l from its receiver P[l] along d[l] (formed by the caller as sample_blocked forms it), sheared
 * along its packet's axis (one packet = 16 consecutive samples of a row of that receiver's grid, raytrace's):
 * axis 0 on lanes m0, 1 on m1, none on mneg (each its own, ms_wt_rays16_own: raytrace's ms_wt_segment), 2 on the
 * others; z0 >= 0: every lane's axis is z0 (no per-lane selection). V: the triangle's vertices relative to each
 * lane's receiver (world axes); num: each lane's plane offset (ms_wt_offset). Lanes with an edge function
 * exactly 0 go to the scalar form too (as raytrace's lanes do). Returns the lanes of live triangle t blocks.
 * Written once for both layouts: a receiver's 16 samples (group_block16) and a leaf's 16 receivers at one
 * sample (leaf_lanes_sample). */
static unsigned exact16(const shared *sh, const tri_job *t, const l16 P[3], const l16 V[3][3], const l16 d[3], l16 num,
                        unsigned m0, unsigned m1, unsigned mneg, int z0, unsigned live)
{
    /* kz = 0: kx = 1, ky = 2; kz = 1: kx = 2, ky = 0; kz = 2: kx = 0, ky = 1 */
    l16 dz, dx, dy, V3[3][3];
    if (z0 >= 0) {
        const int zx = z0 + 1 == 3 ? 0 : z0 + 1, zy = zx + 1 == 3 ? 0 : zx + 1;
        dz = d[z0]; dx = d[zx]; dy = d[zy];
        for (int v = 0; v < 3; v++) { V3[v][0] = V[v][zx]; V3[v][1] = V[v][zy]; V3[v][2] = V[v][z0]; }
    } else {
        dz = sel3(m0, m1, d[0], d[1], d[2]); dx = sel3(m0, m1, d[1], d[2], d[0]); dy = sel3(m0, m1, d[2], d[0], d[1]);
        for (int v = 0; v < 3; v++) {
            V3[v][0] = sel3(m0, m1, V[v][1], V[v][2], V[v][0]);
            V3[v][1] = sel3(m0, m1, V[v][2], V[v][0], V[v][1]);
            V3[v][2] = sel3(m0, m1, V[v][0], V[v][1], V[v][2]);
        }
    }
    const l16 inv = l16_div(l16_set1(1.0f), dz), sx = l16_mul(dx, inv), sy = l16_mul(dy, inv);
    const float *N = t->N, near = sh->ctx->near, far = sh->ctx->far;
    unsigned z, zown = 0;
    unsigned hit = ms_wt_rays16(V3, sx, sy, d, N, num, near, far, live & ~mneg, &z);
    if (live & mneg) hit |= ms_wt_rays16_own(V, d, N, num, near, far, live & mneg, &zown);
    const unsigned rest = z | zown;
    if (rest) {
        float dv[3][LANES], pv[3][LANES], vv[3][3][LANES], sxv[LANES], syv[LANES], nv[LANES];
        for (int a = 0; a < 3; a++) {
            l16_store(dv[a], d[a]);
            l16_store(pv[a], P[a]);
            for (int v = 0; v < 3; v++) l16_store(vv[v][a], V[v][a]);
        }
        l16_store(sxv, sx);
        l16_store(syv, sy);
        l16_store(nv, num);
        for (unsigned m = rest; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            const float dl[3] = { dv[0][l], dv[1][l], dv[2][l] }, pl[3] = { pv[0][l], pv[1][l], pv[2][l] };
            const float A[3] = { vv[0][0][l], vv[0][1][l], vv[0][2][l] }, B[3] = { vv[1][0][l], vv[1][1][l], vv[1][2][l] };
            const float C[3] = { vv[2][0][l], vv[2][1][l], vv[2][2][l] };
            const int kl = (mneg >> l & 1) ? -1 : (m0 >> l & 1) ? 0 : (m1 >> l & 1) ? 1 : 2;
            const int b = kl < 0 ? ms_wt_segment(pl, dl, t->v, N, near, far)
                                 : ms_wt_segment_sheared(A, B, C, kl, sxv[l], syv[l], dl, N, nv[l], near, far);
            hit |= (unsigned)b << l;
        }
    }
    return hit;
}

/* The lanes of live whose ray (d from its receiver, num its plane offset) meets triangle t's plane within [near,
 * far], by the exact test's own operations (ms_wt_rays16's tail: d . N, the signed offset num against near and far
 * times |d . N|): for lanes whose edge functions surely pass (footprint_sure_lanes) this is the whole of the exact
 * test's answer, bit for bit, without the shear and the edge functions. */
static unsigned t_range16(const shared *sh, const tri_job *t, const l16 d[3], l16 num, unsigned live)
{
    const float *N = t->N;
    const l16 zero = l16_set1(0.0f);
    const l16 den = l16_add(l16_add(l16_mul(d[0], l16_set1(N[0])), l16_mul(d[1], l16_set1(N[1]))), l16_mul(d[2], l16_set1(N[2])));
    const l16 ns = l16_select(l16_lt(den, zero), l16_sub(zero, num), num), aden = l16_abs(den);
    return live & l16_gt(aden, zero) & l16_le(l16_mul(l16_set1(sh->ctx->near), aden), ns) &
           l16_le(ns, l16_mul(l16_set1(sh->ctx->far), aden));
}

/* The directions of receiver q's 16 samples (i0 + l % w, j0 + l / w) of its grid g (w = 4 or 8 columns), formed
 * as sample_blocked forms them. */
static void block_dirs(const ms_shadow_query *q, const ms_grid *g, int i0, int j0, int w, l16 d[3])
{
    /* Lane l's column and row offsets in the block (small integers: exact in float). */
    static const float off[2][2][LANES] = {
        { { 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3 }, { 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3 } },
        { { 0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7 }, { 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1 } } };
    const int wi = w == 8;
    const l16 li = l16_add(l16_set1((float)i0), l16_load(off[wi][0])), lj = l16_add(l16_set1((float)j0), l16_load(off[wi][1]));
    for (int a = 0; a < 3; a++)
        d[a] = l16_sub(l16_add(l16_add(l16_set1(g->p0[a]), l16_mul(li, l16_set1(g->ds[a]))), l16_mul(lj, l16_set1(g->dt[a]))),
                       l16_set1(q->p[a]));
}

/* The hard-shadow test of 16 samples of receiver q at once (L70): lane l is sample (i0 + l % w, j0 + l / w) of
 * its grid g (w = 4 or 8 columns); live: the lanes to test; A, B, C: the vertices relative to q; num: q's plane
 * offset. Returns the lanes triangle t blocks (exact16). */
static unsigned group_block16(const shared *sh, const ms_shadow_query *q, const ms_grid *g, const int8_t *kz, int i0,
                              int j0, int w, unsigned live, const tri_job *t, const float A[3], const float B[3],
                              const float C[3], float num)
{
    const int k = sh->k, rows = LANES / w;
    /* A group lies within one 16-sample packet per row: the row's packet gives its lanes' shear axis. */
    unsigned m0 = 0, m1 = 0, mneg = 0;
    const unsigned rowbits = (1u << w) - 1u;
    int z0 = kz[(j0 * k + i0) / LANES], uniform = z0 >= 0;
    for (int r = 0; r < rows; r++) {
        const int z = kz[((j0 + r) * k + i0) / LANES];
        uniform &= z == z0;
        m0 |= (z == 0 ? rowbits : 0u) << (r * w);
        m1 |= (z == 1 ? rowbits : 0u) << (r * w);
        mneg |= (z < 0 ? rowbits : 0u) << (r * w);
    }
    l16 d[3];
    block_dirs(q, g, i0, j0, w, d);
    const l16 P[3] = { l16_set1(q->p[0]), l16_set1(q->p[1]), l16_set1(q->p[2]) };
    const l16 V[3][3] = { { l16_set1(A[0]), l16_set1(A[1]), l16_set1(A[2]) },
                          { l16_set1(B[0]), l16_set1(B[1]), l16_set1(B[2]) },
                          { l16_set1(C[0]), l16_set1(C[1]), l16_set1(C[2]) } };
    return exact16(sh, t, P, V, d, l16_set1(num), m0, m1, mneg, uniform ? z0 : -1, live);
}

/* cast_group with the 16-lane test: the group's open samples 16 at a time. */
static int cast_group16(const shared *sh, chunk *c, uint64_t *open, const int8_t *kz, int gk, const ms_shadow_query *q,
                        const ms_grid *g, const tri_job *t, const float A[3], const float B[3], const float C[3], float num)
{
    const int k = sh->k, gs = sh->gs, gpr = k / gs, rows = LANES / gs;
    const int i0 = (gk % gpr) * gs, j0 = (gk / gpr) * gs;
    const uint64_t seg = (UINT64_C(1) << gs) - 1u;
    const int alpha = ms_alpha_tested(sh->ctx->alpha, t->self);
    int left = 0;
    for (int jb = j0; jb < j0 + gs; jb += rows) {
        unsigned live = 0;
        for (int r = 0; r < rows; r++) {
            const int s0 = (jb + r) * k + i0;
            live |= (unsigned)(open[s0 >> 6] >> (s0 & 63) & seg) << (r * gs);
        }
        if (!live) continue;
        c->cnt[C_SAMPLE_TESTS] += (uint64_t)__builtin_popcount(live);
        unsigned hit = group_block16(sh, q, g, kz, i0, jb, gs, live, t, A, B, C, num);
        if (hit && alpha)
            for (unsigned m = hit; m; m &= m - 1) {
                const int l = __builtin_ctz(m);
                if (!alpha_opaque(sh, t, q, g, i0 + l % gs, jb + l / gs)) hit &= ~(1u << l);
            }
        c->cnt[C_SAMPLES_BLOCKED] += (uint64_t)__builtin_popcount(hit);
        for (int r = 0; r < rows; r++) {
            const int s0 = (jb + r) * k + i0;
            open[s0 >> 6] &= ~((uint64_t)(hit >> (r * gs) & seg) << (s0 & 63));
        }
    }
    for (int j = j0; j < j0 + gs && !left; j++) {
        const int s0 = j * k + i0;
        left |= (open[s0 >> 6] >> (s0 & 63) & seg) != 0;
    }
    return !left;
}

/* INTERSECTS (hpc_volume_box) over all planes at once: per plane the scalar form's arithmetic. */
static int vol_box(const shared *sh, const hpc_volume *v, uint32_t act, const float lo[3], const float hi[3],
                   uint32_t *out, uint64_t *tests)
{
    if (sh->sw & MS_HPC_OFF_SIMD_PLANES) return hpc_volume_box(v, act, lo, hi, out, tests);
    act &= v->n >= 32 ? UINT32_MAX : (UINT32_C(1) << v->n) - 1u;
    if (!act) { *out = 0; return 1; }
    l16 mx = l16_load(v->soa[3]), mn = mx;
    for (int a = 0; a < 3; a++) {
        const l16 n = l16_load(v->soa[a]), x = l16_mul(n, l16_set1(lo[a])), y = l16_mul(n, l16_set1(hi[a]));
        mx = l16_add(mx, l16_max(x, y));
        mn = l16_add(mn, l16_min(y, x));
    }
    *tests += (uint64_t)__builtin_popcount(act);
    if (l16_lt(mx, l16_set1(-v->eps)) & act) return 0;
    *out = act & ~l16_le(l16_set1(v->eps), mn);   /* wholly inside, with room for rounding */
    return 1;
}

/* POINT-IN-VOLUME (hpc_volume_point) over all planes at once. */
static int vol_point(const shared *sh, const hpc_volume *v, uint32_t act, const float p[3], uint64_t *tests)
{
    if (sh->sw & MS_HPC_OFF_SIMD_PLANES) return hpc_volume_point(v, act, p, tests);
    act &= v->n >= 32 ? UINT32_MAX : (UINT32_C(1) << v->n) - 1u;
    if (!act) return 1;
    const l16 s = l16_add(l16_add(l16_add(l16_mul(l16_load(v->soa[0]), l16_set1(p[0])), l16_mul(l16_load(v->soa[1]), l16_set1(p[1]))),
                                  l16_mul(l16_load(v->soa[2]), l16_set1(p[2]))),
                          l16_load(v->soa[3]));
    *tests += (uint64_t)__builtin_popcount(act);
    return !(l16_lt(s, l16_set1(-v->eps)) & act);
}

static int group_done(const shared *sh, const uint64_t *open, int gk)
{
    const uint64_t *m = sh->gmask + (size_t)gk * sh->mw;
    for (int w = sh->gw0[gk]; w <= sh->gw1[gk]; w++)
        if (open[w] & m[w]) return 0;
    return 1;
}

/* Receiver r's open groups after a triangle (L72-L75): its umbra bits, and at full umbra its mask back. */
static void record_umbra(const shared *sh, chunk *c, uint32_t r, int32_t s, uint64_t gu)
{
    if (sh->sw & MS_HPC_OFF_UMBRA) return;   /* A off: umbra found by casting is not recorded */
    sh->gumbra[r] = gu;
    if (gu == sh->all_groups) {
        sh->full[r] = 1;
        if (!(sh->sw & MS_HPC_OFF_ON_DEMAND)) {   /* D: the mask goes back (L75) */
            slot_put(c, s);
            sh->slot[r] = -1;
        }
        c->umbra_in_tree++;
        c->cnt[C_FULL_UMBRA_POINTS]++;
    }
}

/* The samples of receiver r still open: its mask slot's, or its front mask before a triangle first may block it. */
static inline const uint64_t *open_of(const shared *sh, chunk *c, uint32_t r)
{
    const int32_t s = sh->slot[r];
    return s >= 0 ? slot_mask(sh, c, s) : sh->front + (size_t)sh->orig[r] * sh->mw;
}

/* The mask and sample data of receiver r (D: made when a triangle first may block it, L59-L64). -1 when out
 * of memory. */
static int32_t slot_of(const shared *sh, chunk *c, uint32_t r, const ms_grid *g)
{
    int32_t s = sh->slot[r];
    if (s >= 0) return s;
    if ((s = slot_get(sh, c)) < 0) { c->failed = 1; return -1; }
    sh->slot[r] = s;
    memcpy(slot_mask(sh, c, s), sh->front + (size_t)sh->orig[r] * sh->mw, (size_t)sh->mw * sizeof(uint64_t));
    slot_setup(sh, c, s, &sh->q[r], g);
    return s;
}

/* The open bits of the 16 samples (i0 + l % gs, jb + l / gs) as lanes l, gs = 4 (4 rows) or 8 (2 rows); written
 * out row by row (a loop over the rows is vectorised into a gather, slower than these loads). */
static inline unsigned block_open(const uint64_t *open, int k, int i0, int jb, int gs)
{
    const int s0 = jb * k + i0, s1 = s0 + k;
    if (gs == 8)
        return (unsigned)(open[s0 >> 6] >> (s0 & 63) & 0xffu) | (unsigned)(open[s1 >> 6] >> (s1 & 63) & 0xffu) << 8;
    const int s2 = s1 + k, s3 = s2 + k;
    return (unsigned)(open[s0 >> 6] >> (s0 & 63) & 15u) | (unsigned)(open[s1 >> 6] >> (s1 & 63) & 15u) << 4 |
           (unsigned)(open[s2 >> 6] >> (s2 & 63) & 15u) << 8 | (unsigned)(open[s3 >> 6] >> (s3 & 63) & 15u) << 12;
}

/* A receiver's view of a job (one triangle, or two sharing an edge cast together: pair_batch): the triangles
 * that may block it (not its own), each with its footprint and its vertices relative to the receiver. */
typedef struct hpc_view {
    int nt;
    const tri_job *t[2];
    hpc_footprint fp[2];
    const uint64_t *ncand[2];   /* direct: per triangle, this receiver's samples the footprint may hold */
    const uint64_t *nsure[2];   /* direct: of those, the ones whose edge functions surely pass (footprint_sure_lanes) */
    uint64_t ngroups;           /* direct: groups holding them (a superset), over the triangles */
    int direct;                 /* 1: ncand and ngroups made by the leaf (cast_leaf_footprint), fp unused */
} hpc_view;

/* Whether every segment from a receiver in the box pc +- h to a sample of the light meets triangle t's plane well
 * inside the exact test's range, so that wherever the exact test's edge functions surely pass
 * (footprint_sure_lanes) it reports a hit, whatever its shear axis, without its t range's operations. With
 * alpha = N . p, xi = N . x (x the sample) and gamma = N . v (v any vertex: N, ms_wt_normal's, is not exactly
 * normal to the third edge), the exact test's t is (gamma - alpha) / (xi - alpha) up to its rounding: the plane
 * offset num = (v - p) . N from a vertex rounded relative to p (at most 5 u M |N|_1, M >= |v - p|inf) and d . N
 * from the direction formed in float (at most 3 u S |N|_1 for the product and 4 u S |N|_1 for d itself, S >=
 * |p0| + |p| bounds every partial sum, the grid's points lying on the light). So when the ranges of alpha over
 * the box, gamma over the vertices and xi over the light's polygon (the samples' cells, pattern.h) are
 * separated in that order (or its reverse), with gamma - alpha >= 2 near D + E and xi - gamma >= 2 (1 - far) D +
 * E, D >= |xi - alpha|, E = 16 u (M + S) |N|_1 above all those errors, the computed test lies in [near, far]
 * for every lane: ms_wt_rays16's plane-distance form, and the scalar form's division clamped to the vertices'
 * depths (ms_wt_hit_t: the exact hit lies within them, the clamp moves t by rounding only). In double. */
/* fmin and fmax are library calls without -ffast-math (as hpc_volume.c notes); the values here are finite. */
static inline double tmin_d(double a, double b) { return a < b ? a : b; }
static inline double tmax_d(double a, double b) { return a > b ? a : b; }

static inline int tsure_on(const shared *sh) { return !(sh->sw & (MS_HPC_OFF_SURE | MS_HPC_OFF_TSURE)); }

static int t_sure(const shared *sh, const float pc[3], const float h[3], const tri_job *t)
{
    const float *N = t->N;
    double n1 = 0.0, a0 = 0.0, ah = 0.0, hmax = 0.0, pmax = 0.0, lmax = 0.0, M = 0.0;
    for (int a = 0; a < 3; a++) {
        n1 += fabs((double)N[a]);
        a0 += (double)N[a] * pc[a];
        ah += fabs((double)N[a]) * h[a];
        hmax = tmax_d(hmax, h[a]);
        pmax = tmax_d(pmax, fabs((double)pc[a]));
    }
    double gl = INFINITY, gh = -INFINITY, xl = INFINITY, xh = -INFINITY;
    for (int v = 0; v < 3; v++) {
        double gv = 0.0, mv = 0.0;
        for (int a = 0; a < 3; a++) {
            gv += (double)N[a] * t->v[3 * v + a];
            mv = tmax_d(mv, fabs((double)t->v[3 * v + a] - pc[a]));
        }
        gl = tmin_d(gl, gv);
        gh = tmax_d(gh, gv);
        M = tmax_d(M, mv + hmax);
    }
    for (int v = 0; v < 4; v++) {
        double xv = 0.0;
        for (int a = 0; a < 3; a++) {
            xv += (double)N[a] * sh->light_poly[3 * v + a];
            lmax = tmax_d(lmax, fabs(sh->light_poly[3 * v + a]));
        }
        xl = tmin_d(xl, xv);
        xh = tmax_d(xh, xv);
    }
    const double S = 2.0 * (lmax + pmax + hmax), E = 1.01 * 16.0 * 0x1p-24 * (M + S) * n1;
    const double al = a0 - ah, au = a0 + ah;
    const double D = tmax_d(xh, au) - tmin_d(xl, al);
    const double nearm = 2.0 * (double)sh->ctx->near * D + E, farm = 2.0 * (1.0 - (double)sh->ctx->far) * D + E;
    if (au < gl && gh < xl) return gl - au >= nearm && xl - gh >= farm;   /* receivers, plane, light in order */
    if (xh < gl && gh < al) return al - gh >= nearm && gl - xh >= farm;   /* and in reverse */
    return 0;
}

/* The lanes triangle t blocks of the 16-sample block at (i0, jb) of receiver q (live: the lanes to test), with
 * the 16-lane test or, switched off, one lane at a time; alpha-tested triangles only where opaque. sure: lanes
 * whose edge functions surely pass (footprint_sure_lanes): when they are all of live, they are blocked outright
 * where t_sure holds for this receiver (*tsure: -1 until first asked, then 0 or 1), else, when no row of the
 * block leaves its lanes to the own-axis form (a packet without a shared axis, kz < 0: ms_wt_segment, its own
 * shear and t), only the t range is tested (counter samples_sure). */
static unsigned block_hits(const shared *sh, chunk *c, const ms_shadow_query *q, const ms_grid *g, const int8_t *kz, int i0,
                           int jb, unsigned live, unsigned sure, int *tsure, const tri_job *t, const float V[3][3], float num)
{
    const int k = sh->k, gs = sh->gs;
    unsigned hit;
    int shared_axis = 1;
    const int all_sure = !(live & ~sure) && !(sh->sw & (MS_HPC_OFF_SURE | MS_HPC_OFF_SIMD_SAMPLES));
    if (all_sure && *tsure < 0) {   /* t_sure for this receiver, once a block could use it (-1: not yet known) */
        static const float zero3[3] = { 0.0f, 0.0f, 0.0f };
        *tsure = tsure_on(sh) && ((sh->sw & MS_HPC_BREAK_TSURE) || t_sure(sh, q->p, zero3, t));
    }
    if (all_sure && !*tsure)
        for (int r = 0; r < LANES / gs; r++) shared_axis &= kz[((jb + r) * k + i0) / LANES] >= 0;
    if (all_sure && *tsure) {   /* t_sure: the t range passes too, on any axis */
        c->cnt[C_SAMPLES_SURE] += (uint64_t)__builtin_popcount(live);
        c->cnt[C_SAMPLES_TSURE] += (uint64_t)__builtin_popcount(live);
        hit = live;
    } else if (all_sure && shared_axis) {
        c->cnt[C_SAMPLES_SURE] += (uint64_t)__builtin_popcount(live);
        l16 d[3];
        block_dirs(q, g, i0, jb, gs, d);
        hit = t_range16(sh, t, d, l16_set1(num), live);
    } else if (sh->sw & MS_HPC_OFF_SIMD_SAMPLES) {   /* one lane at a time, the scalar form */
        hit = 0;
        for (unsigned b = live; b; b &= b - 1) {
            const int l = __builtin_ctz(b), i = i0 + l % gs, j = jb + l / gs;
            float d[3];
            for (int a = 0; a < 3; a++) d[a] = (g->p0[a] + (float)i * g->ds[a] + (float)j * g->dt[a]) - q->p[a];
            hit |= (unsigned)sample_blocked(q->p, d, kz[(j * k + i) / LANES], t->v, t->N, V[0], V[1], V[2], num,
                                            sh->ctx->near, sh->ctx->far) << l;
        }
    } else {
        hit = group_block16(sh, q, g, kz, i0, jb, gs, live, t, V[0], V[1], V[2], num);
    }
    if (hit && ms_alpha_tested(sh->ctx->alpha, t->self))
        for (unsigned b = hit; b; b &= b - 1) {
            const int l = __builtin_ctz(b);
            if (!alpha_opaque(sh, t, q, g, i0 + l % gs, jb + l / gs)) hit &= ~(1u << l);
        }
    return hit;
}

/* cast_footprint's loop over the groups and blocks (below: its comment), written once and instantiated twice:
 * with the sure lanes (with_sure, a constant) for footprints over several groups, without for the others. A small
 * triangle's footprint rarely holds a whole block's live lanes, and there merely having the sure test in the
 * loop (its functions kept per block, its branch) cost more than it saved: the bunny (512², 256 samples, one
 * thread) 4.30-4.35 s without it against 4.72-4.80 s with it in the loop, taken or not. */
static inline __attribute__((always_inline)) void cast_blocks(const shared *sh, chunk *c, uint32_t r, const ms_grid *g,
                                                              const hpc_view *v, uint64_t todo, uint64_t gu,
                                                              float (*base)[4][64], const int with_sure)
{
    const ms_shadow_query *q = &sh->q[r];
    static const float off[2][2][LANES] = {
        { { 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3 }, { 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3 } },
        { { 0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7 }, { 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1 } } };
    const int k = sh->k, gs = sh->gs, rows = LANES / gs, wi = gs == 8, nt = v->nt;
    const uint64_t seg = (UINT64_C(1) << gs) - 1u;
    /* the sure lanes' slacks per triangle (negated under MS_HPC_BREAK_SURE, wrong on purpose) and whether
     * they prove anything (footprint_slack_ok) */
    l16 ssl[2][3];
    unsigned sok[2] = { 0u, 0u };
    for (int u = 0; u < nt && !v->direct && with_sure; u++) {
        for (int e = 0; e < 3; e++) ssl[u][e] = l16_set1((sh->sw & MS_HPC_BREAK_SURE) ? -v->fp[u].s[e] : v->fp[u].s[e]);
        sok[u] = v->fp[u].s[0] > 1e-30f && v->fp[u].s[1] > 1e-30f && v->fp[u].s[2] > 1e-30f ? 0xffffu : 0u;
    }
    l16 foff[2][4];
    for (int u = 0; u < nt && !v->direct; u++) footprint_offsets(&v->fp[u], l16_load(off[wi][0]), l16_load(off[wi][1]), foff[u]);
    int32_t s = sh->slot[r];
    const uint64_t *open = open_of(sh, c, r);
    float num[2] = { 0.0f, 0.0f }, V[2][3][3];   /* per triangle at its first exact test: offset, A, B, C */
    int tsure[2] = { -1, -1 };                    /* and t_sure for this receiver (-1: not yet known) */
    int have_num[2] = { 0, 0 };
    const int8_t *kz = NULL;
    const uint64_t gu0 = gu;
    for (uint64_t m = todo; m; m &= m - 1) {
        const int gk = __builtin_ctzll(m);
        const int i0 = (int)sh->group_i0[gk], j0 = (int)sh->group_j0[gk];
        unsigned any = 0;
        for (int jb = j0; jb < j0 + gs; jb += rows) {
            unsigned lanes[2] = { 0u, 0u }, sure[2] = { 0u, 0u };
            l16 E[2][4];
            if (v->direct) {
                for (int u = 0; u < nt; u++) lanes[u] = block_open(v->ncand[u], k, i0, jb, gs);
            } else {
                lanes[0] = footprint_lanes(&v->fp[0], foff[0], i0, jb, jb == j0 ? &base[0][0][0] : NULL, gk, E[0]);
                if (nt > 1) lanes[1] = footprint_lanes(&v->fp[1], foff[1], i0, jb, jb == j0 ? &base[1][0][0] : NULL, gk, E[1]);
            }
            if (!(lanes[0] | lanes[1])) continue;
            const unsigned ob = block_open(open, k, i0, jb, gs);
            if (!(ob & (lanes[0] | lanes[1]))) continue;
            if (!kz) {   /* the first exact test of this receiver and job */
                if (s < 0 && (s = slot_of(sh, c, r, g)) < 0) return;
                open = slot_mask(sh, c, s);
                kz = slot_kz(sh, c, s);
            }
            unsigned hit = 0;
            for (int u = 0; u < nt; u++) {
                const unsigned live = ob & lanes[u] & ~hit;   /* a sample the first blocks needs no second test */
                if (!live) continue;
                if (with_sure)
                    sure[u] = v->direct ? block_open(v->nsure[u], k, i0, jb, gs) : footprint_sure_lanes(E[u], ssl[u], sok[u]);
                if (!have_num[u]) {
                    num[u] = ms_wt_offset(q->p, v->t[u]->v, v->t[u]->N);
                    for (int i = 0; i < 3; i++)
                        for (int a = 0; a < 3; a++) V[u][i][a] = v->t[u]->v[3 * i + a] - q->p[a];
                    have_num[u] = 1;
                }
                c->cnt[C_SAMPLE_TESTS] += (uint64_t)__builtin_popcount(live);
                hit |= block_hits(sh, c, q, g, kz, i0, jb, live, sure[u], &tsure[u], v->t[u], V[u], num[u]);
            }
            if (!hit) continue;
            c->cnt[C_SAMPLES_BLOCKED] += (uint64_t)__builtin_popcount(hit);
            any |= hit;
            uint64_t *w = slot_mask(sh, c, s);
            for (int rr = 0; rr < rows; rr++) {
                const int s0 = (jb + rr) * k + i0;
                w[s0 >> 6] &= ~((uint64_t)(hit >> (rr * gs) & seg) << (s0 & 63));
            }
        }
        if (any && group_done(sh, open, gk)) gu |= UINT64_C(1) << gk;
    }
    if (gu != gu0) record_umbra(sh, c, r, s, gu);
}

/* Receiver r inside V_L against a job's triangles (v), with the footprint test in place of V_Gk (above): the
 * groups some triangle's footprint may touch, then in each block the lanes each footprint may hold, and the
 * exact test of each triangle only on those of its lanes that are still open. A sample is blocked when one of
 * the triangles blocks it, as raytrace's any-hit over both: the pair shares the traversal, the V_L test, the
 * per-pair set-up and the block loop, never the exact test (a convex quad's own edge functions would round
 * differently on the shared edge). The mask, the packets' shear axes and the plane offsets are made only
 * when some lane needs the exact test. */
static void cast_footprint(const shared *sh, chunk *c, uint32_t r, const ms_grid *g, const hpc_view *v)
{
    uint64_t gu = sh->gumbra[r];
    c->cnt[C_GROUP_POINT_TESTS] += (uint64_t)__builtin_popcountll(sh->all_groups & ~gu);
    c->cnt[C_PAIRS_FOOTPRINT] += (uint64_t)v->nt;
    /* The open groups a footprint may touch (a node's umbra groups are its points' too). */
    float base[2][4][64];   /* each function at each group's first sample (footprint_groups) */
    uint64_t todo;
    if (v->direct) todo = v->ngroups;
    else {
        todo = footprint_groups(sh, &v->fp[0], base[0]);
        if (v->nt > 1) todo |= footprint_groups(sh, &v->fp[1], base[1]);
    }
    todo &= ~gu;
    if (!todo) return;
    if (__builtin_popcountll(todo) >= SURE_MIN_GROUPS) cast_blocks(sh, c, r, g, v, todo, gu, base, 1);
    else cast_blocks(sh, c, r, g, v, todo, gu, base, 0);
}

/* One receiver against one triangle with the footprint test (receivers without their grid origins formed
 * up front, or in a leaf of more than 16 points). */
static void cast_point_footprint(const shared *sh, chunk *c, uint32_t r, const tri_job *t)
{
    const ms_shadow_query *q = &sh->q[r];
    ms_grid g;
    if (sh->p0) {
        memcpy(g.p0, sh->p0 + 4 * (size_t)r, sizeof g.p0);
        memcpy(g.ds, sh->grid_ds, sizeof g.ds);
        memcpy(g.dt, sh->grid_dt, sizeof g.dt);
        g.k = sh->k;
    } else {
        ms_grid_for_pixel(&sh->ctx->light, sh->k, q->px, q->py, sh->ctx->seed, &g);
    }
    hpc_view v;
    v.nt = 1;
    v.t[0] = t;
    v.direct = 0;
    float A[3], B[3], C[3];
    for (int a = 0; a < 3; a++) { A[a] = t->v[a] - q->p[a]; B[a] = t->v[3 + a] - q->p[a]; C[a] = t->v[6 + a] - q->p[a]; }
    footprint_setup(&v.fp[0], A, B, C, &g, q->p, sh->p0 ? sh->p0[4 * (size_t)r + 3] : footprint_rel(&g, q->p, sh->k));
    footprint_spans(&v.fp[0], (float)(sh->gs - 1));
    cast_footprint(sh, c, r, &g, &v);
}

/* One receiver of a leaf against the triangle (L56-L75). */
static void cast_point(const shared *sh, chunk *c, uint32_t r, const tri_job *t, uint32_t pl, const act_group *ag, int nag)
{
    const ms_shadow_query *q = &sh->q[r];
    if (sh->full[r] || q->prim == t->self) return;
    c->cnt[C_POINT_TESTS]++;
    if (!vol_point(sh, &t->vl, pl, q->p, &c->cnt[C_PLANE_TESTS])) return;
    c->cnt[C_PAIRS_IN_VL]++;
    if (sh->footprint) { cast_point_footprint(sh, c, r, t); return; }
    ms_grid g;   /* the point's samples, formed when first needed */
    int have_g = 0;
#define HPC_GRID() (have_g ? (void)0 : (ms_grid_for_pixel(&sh->ctx->light, sh->k, q->px, q->py, sh->ctx->seed, &g), (void)(have_g = 1)))
    int32_t s = sh->slot[r];
    if (s < 0) {
        HPC_GRID();
        if ((s = slot_get(sh, c)) < 0) { c->failed = 1; return; }
        sh->slot[r] = s;
        memcpy(slot_mask(sh, c, s), sh->front + (size_t)sh->orig[r] * sh->mw, (size_t)sh->mw * sizeof(uint64_t));
        slot_setup(sh, c, s, q, &g);
    }
    if (!c->gvol_built) build_group_volumes(sh, c, t);
    uint64_t *open = slot_mask(sh, c, s);
    const int8_t *kz = slot_kz(sh, c, s);
    float A[3], B[3], C[3];
    for (int a = 0; a < 3; a++) { A[a] = t->v[a] - q->p[a]; B[a] = t->v[3 + a] - q->p[a]; C[a] = t->v[6 + a] - q->p[a]; }
    const float num = ms_wt_offset(q->p, t->v, t->N);
    uint64_t gu = sh->gumbra[r];
    if (sh->scanline && slot_frame(sh, c, s)->k) {
        int any = 0;
        for (int i = 0; i < nag && !any; i++) {
            if (gu >> ag[i].k & 1u) continue;
            c->cnt[C_GROUP_POINT_TESTS]++;
            any = vol_point(sh, &c->gvol[ag[i].k], ag[i].planes, q->p, &c->cnt[C_PLANE_TESTS]);
        }
        if (any) {
            c->cnt[C_RASTER_CALLS]++;
            if (ms_alpha_tested(sh->ctx->alpha, t->self)) {   /* its opaque samples only (alpha.h) */
                const ms_alpha_pixel ap = { sh->ctx, q };
                ms_alpha_raster(&ap, slot_frame(sh, c, s), sh->raster, t->v, t->self, open);
            } else {
                sh->raster(slot_frame(sh, c, s), t->v, open);
            }
            for (int gk = 0; gk < sh->G; gk++)
                if (!(gu >> gk & 1u) && group_done(sh, open, gk)) gu |= UINT64_C(1) << gk;
        }
    } else {
        for (int i = 0; i < nag; i++) {
            const int gk = (int)ag[i].k;
            if (gu >> gk & 1u) continue;
            c->cnt[C_GROUP_POINT_TESTS]++;
            if (!vol_point(sh, &c->gvol[gk], ag[i].planes, q->p, &c->cnt[C_PLANE_TESTS])) continue;
            HPC_GRID();
            const int done = sh->sw & MS_HPC_OFF_SIMD_SAMPLES ? cast_group(sh, c, open, kz, gk, q, &g, t, A, B, C, num)
                                                              : cast_group16(sh, c, open, kz, gk, q, &g, t, A, B, C, num);
            if (done) gu |= UINT64_C(1) << gk;
        }
    }
#undef HPC_GRID
    record_umbra(sh, c, r, s, gu);
}

/* footprint_spans per lane: e1, e2 of 16 receivers' function; the least and largest change to dlo, dhi. */
static inline void spans16(l16 e1, l16 e2, l16 span, l16 zero, float *dlo, float *dhi)
{
    const l16 di = l16_mul(e1, span), dj = l16_mul(e2, span);
    l16_store(dlo, l16_add(l16_min(di, zero), l16_min(dj, zero)));
    l16_store(dhi, l16_add(l16_max(di, zero), l16_max(dj, zero)));
}

/* Whether the leaf footprint pays here, from this chunk's recent leaves cast with it (the counts halved as they
 * grow, so that they follow the triangles of the moment): only while it has left at most LEAF_FP_CANDS samples
 * per receiver to test in the lanes and, where its samples go to each receiver in turn (not lanes: the leaf lanes
 * off, or alpha), at most LEAF_FP_KEEP of the receivers to that per-receiver work; one leaf in LEAF_FP_PROBE uses
 * it regardless, to keep the counts current. Per chunk, so the same on every ISA and run. Measured (1024^2, the
 * leaf footprint on every leaf, before the leaf lanes): on a GRIDS-like scene's bars 58% of the receivers kept,
 * 2.1 samples per receiver, and it pays; Dabrovic Sponza's large triangles leave 12.5 samples per receiver (76%
 * kept), a scanned bunny's small ones keep 72% of the receivers (1.9 samples each): there it cost 20-25%. With
 * the leaf lanes a kept receiver costs no work of its own, and the keep rule off took the bars' cast 2.54 ->
 * 2.32 s (two threads), Sibenik, Dabrovic Sponza and the bunny within noise (docs/hpc.md, session 16). */
#define LEAF_FP_PROBE 64u
#define LEAF_FP_KEEP 0.75f
#define LEAF_FP_CANDS 6.0f
static inline int leaf_fp_pays(chunk *c, int lanes)
{
    if (c->lf_leaves++ % LEAF_FP_PROBE == 0) return 1;
    return (lanes || (float)c->lf_kept <= LEAF_FP_KEEP * (float)c->lf_in) && (float)c->lf_cands <= LEAF_FP_CANDS * (float)c->lf_in;
}

/* The points of a leaf inside V_L against a job (a triangle, or a pair: pair_batch) with the footprint test,
 * 16 receivers per operation (departure: the paper handles a leaf's points one by one): the point-in-V_L test
 * (POINT-IN-VOLUME, the same arithmetic as vol_point per lane) and footprint_setup (the same arithmetic per
 * lane, per triangle), then each point's groups and samples (cast_footprint). */
_Static_assert(LEAF_POINTS_FOOTPRINT <= LANES, "a leaf's points fit the lanes");
/* A leaf's shape u ruled out (counter cnt): the triangles it stands for (both for a rectangle pair, else
 * triangle u) leave the leaf, each counted when it had a receiver there. */
static inline void shape_off(chunk *c, int cnt, unsigned act, unsigned on[2], int u, int rect)
{
    for (int x = u; x <= (rect ? 1 : u); x++) {
        c->cnt[cnt] += (uint64_t)((act & on[x]) != 0);
        on[x] = 0;
    }
}

/* ---- the leaf's receivers in the lanes (hpc: the exact test of one sample for 16 receivers at once) ----
 *
 * Departure from the paper, whose leaf tests its points one by one (L56-L75). With the leaf footprint, every
 * sample it leaves is tested for the leaf's receivers in the lanes: lane l is receiver l's ray to its own sample
 * (i, j) (its own grid origin, its own packet's shear axis, its own vertices relative to it and plane offset),
 * each lane exactly what sample_blocked computes for it (exact16, the same operations as for a receiver's 16
 * samples), so the answers stay raytrace's bit for bit. What it removes is the per-receiver work: handing each
 * receiver its candidate samples, then its groups and blocks (cast_footprint), which on the merged bars cost
 * about 400 cycles per (receiver, triangle) for 4 samples tested. Per (leaf, triangle) the work is now one
 * 16-lane test per sample the leaf footprint leaves open, which as leaves shrink with resolution approaches the
 * receivers' own samples. MS_HPC_OFF_LEAF_LANES: the per-receiver form. */
typedef struct leaf_lanes {
    uint32_t rr[LANES];             /* each lane's receiver */
    unsigned act;                   /* the lanes in play */
    const uint64_t *open[LANES];    /* each lane's open samples: its mask, or its front mask before it has one */
    const int8_t *kz[LANES];        /* ready lanes: their packets' shear axes (slot_kz) */
    l16 p[3], p0[3];                /* each lane's receiver and grid origin */
    unsigned ready;                 /* lanes whose mask exists (and with it the packets' shear axes) */
    unsigned axis[3], mixed;        /* of those, the lanes whose every packet has shear axis 0, 1, 2; the others */
    l16w ow;                        /* the lanes' open samples in the current mask word (leaf_lanes_word) */
    unsigned have;                  /* bit u: triangle u's per-lane vertices and offset made */
    unsigned tsure;                 /* bit u: t_sure of triangle u over the leaf's box */
    float pc[3], h[3];              /* the leaf's box (cast_leaf_footprint's) */
    l16 V[2][3][3], num[2];         /* per triangle: its vertices relative to each lane's receiver, its offset */
    uint64_t touched[LANES];        /* per lane: the groups where it lost samples */
    unsigned has[2];                /* per triangle: the lanes it was tested for */
} leaf_lanes;

/* Files ready lane l under the axis all its packets share (slot_setup), or under mixed. */
static inline void leaf_lanes_axis(const shared *sh, const chunk *c, leaf_lanes *L, int l)
{
    L->kz[l] = slot_kz(sh, c, sh->slot[L->rr[l]]);
    const int z = L->kz[l][sh->npk];
    if (z >= 0) L->axis[z] |= 1u << l;
    else L->mixed |= 1u << l;
}

/* The lanes' open samples of mask word wd, before its samples are tested. */
static inline void leaf_lanes_word(leaf_lanes *L, int wd)
{
    uint64_t w[LANES] = { 0 };
    for (unsigned m = L->act; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        w[l] = L->open[l][wd];
    }
    L->ow = l16w_load(w);
}

/* Gives lanes need a mask (and the packets' shear axes: slot_of); the masks may move (the pool grows), so every
 * lane's open pointer is taken again. 0 when out of memory. */
static int leaf_lanes_ready(const shared *sh, chunk *c, leaf_lanes *L, unsigned need)
{
    for (unsigned m = need & ~L->ready; m; m &= m - 1) {
        const uint32_t r = L->rr[__builtin_ctz(m)];
        ms_grid g;
        memcpy(g.p0, sh->p0 + 4 * (size_t)r, sizeof g.p0);
        memcpy(g.ds, sh->grid_ds, sizeof g.ds);
        memcpy(g.dt, sh->grid_dt, sizeof g.dt);
        g.k = sh->k;
        if (slot_of(sh, c, r, &g) < 0) return 0;
    }
    for (unsigned m = need & ~L->ready; m; m &= m - 1) leaf_lanes_axis(sh, c, L, __builtin_ctz(m));
    L->ready |= need;
    for (unsigned m = L->act; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        L->open[l] = open_of(sh, c, L->rr[l]);
        if (L->ready >> l & 1u) L->kz[l] = slot_kz(sh, c, sh->slot[L->rr[l]]);
    }
    return 1;
}

/* Sample sidx (bit b of mask word wd) for the leaf's lanes: cand[x] the lanes whose footprint of triangle tu[x]
 * may hold it, sure[x] those whose edge functions surely pass (footprint_sure_lanes); the triangles in turn,
 * the second only on lanes the first left open (raytrace's any hit). The lanes it blocks lose the sample.
 * 0 when out of memory. */
static int leaf_lanes_sample(const shared *sh, chunk *c, const tri_job *t, leaf_lanes *L, const int tu[2], int nx,
                             int wd, int b, const unsigned cand[2], const unsigned sure[2])
{
    const unsigned open = l16w_bit(L->ow, b) & (cand[0] | cand[1]);
    if (!open) return 1;
    const int k = sh->k, sidx = 64 * wd + b, i = sidx % k, j = sidx / k, pk = sidx / LANES;
    l16 d[3];
    int have_d = 0;
    unsigned hit = 0;
    for (int x = 0; x < nx; x++) {
        const unsigned live = cand[x] & open & ~hit;
        if (!live) continue;
        const int u = tu[x];
        const tri_job *tr = &t[u];
        if ((live & ~L->ready) && !leaf_lanes_ready(sh, c, L, live)) return 0;
        if (!(L->have >> u & 1u)) {
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) L->V[u][v][a] = l16_sub(l16_set1(tr->v[3 * v + a]), L->p[a]);
            L->num[u] = ms_wt_offset16((const l16 (*)[3])L->V[u], tr->N);
            L->have |= 1u << u;
            if (tsure_on(sh) && ((sh->sw & MS_HPC_BREAK_TSURE) || t_sure(sh, L->pc, L->h, tr))) L->tsure |= 1u << u;
        }
        L->has[u] |= live;
        c->cnt[C_SAMPLE_TESTS] += (uint64_t)__builtin_popcount(live);
        c->cnt[C_LEAF_LANE_TESTS] += (uint64_t)__builtin_popcount(live);
        if (!(live & ~sure[x]) && (L->tsure >> u & 1u)) {   /* blocked on every lane: no test (t_sure) */
            c->cnt[C_SAMPLES_SURE] += (uint64_t)__builtin_popcount(live);
            c->cnt[C_SAMPLES_TSURE] += (uint64_t)__builtin_popcount(live);
            hit |= live;
            continue;
        }
        if (!have_d) {
            for (int a = 0; a < 3; a++)
                d[a] = l16_sub(l16_add(l16_add(L->p0[a], l16_set1((float)i * sh->grid_ds[a])), l16_set1((float)j * sh->grid_dt[a])),
                               L->p[a]);
            have_d = 1;
        }
        unsigned m0 = L->axis[0] & live, m1 = L->axis[1] & live, mneg = 0;
        for (unsigned m = live & L->mixed; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            const int z = L->kz[l][pk];
            m0 |= (unsigned)(z == 0) << l;
            m1 |= (unsigned)(z == 1) << l;
            mneg |= (unsigned)(z < 0) << l;
        }
        if (!(live & ~sure[x]) && !mneg && !(sh->sw & MS_HPC_OFF_SURE)) {
            c->cnt[C_SAMPLES_SURE] += (uint64_t)__builtin_popcount(live);
            hit |= t_range16(sh, tr, d, L->num[u], live);
        } else {
            hit |= exact16(sh, tr, L->p, L->V[u], d, L->num[u], m0, m1, mneg, -1, live);
        }
    }
    if (!hit) return 1;
    c->cnt[C_SAMPLES_BLOCKED] += (uint64_t)__builtin_popcount(hit);
    const int gk = (j / sh->gs) * (k / sh->gs) + i / sh->gs;
    L->ow = l16w_clear(L->ow, hit, b);
    for (unsigned m = hit; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        ((uint64_t *)L->open[l])[wd] &= ~(UINT64_C(1) << b);   /* a lane it blocks is ready: its own mask */
        L->touched[l] |= UINT64_C(1) << gk;
    }
    return 1;
}

/* After the leaf's samples: each lane's groups left without an open sample, its umbra bits (record_umbra). */
static void leaf_lanes_umbra(const shared *sh, chunk *c, const leaf_lanes *L)
{
    for (unsigned m = L->act; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        if (!L->touched[l]) continue;
        const uint32_t r = L->rr[l];
        const int32_t s = sh->slot[r];
        const uint64_t gu0 = sh->gumbra[r];
        uint64_t gu = gu0;
        for (uint64_t g = L->touched[l]; g; g &= g - 1)
            if (group_done(sh, slot_mask(sh, c, s), __builtin_ctzll(g))) gu |= g & -g;
        if (gu != gu0) record_umbra(sh, c, r, s, gu);
    }
}

static void cast_leaf_footprint(const shared *sh, chunk *c, const hnode *N, const tri_job *t, uint32_t pl)
{
    const int nt = t->pair > 0 ? 2 : 1;
    float P[3][LANES] = { { 0 } }, W[3][LANES] = { { 0 } }, R[LANES] = { 0 };
    uint32_t rr[LANES];
    unsigned act = 0, on[2] = { 0, 0 };   /* on[u]: the lanes triangle u may block (not their own) */
    for (uint32_t i = 0; i < N->count; i++) {
        const uint32_t r = c->idx[N->first + i];
        rr[i] = r;
        if (sh->full[r]) continue;
        for (int u = 0; u < nt; u++) on[u] |= (unsigned)(sh->q[r].prim != t[u].self) << i;
        if (!((on[0] | on[1]) >> i & 1u)) continue;
        act |= 1u << i;
        for (int a = 0; a < 3; a++) { P[a][i] = sh->q[r].p[a]; W[a][i] = sh->p0[4 * (size_t)r + a] - P[a][i]; }
        R[i] = sh->p0[4 * (size_t)r + 3];
    }
    if (!act) return;
    const int tested = __builtin_popcount(act);
    c->cnt[C_POINT_TESTS] += (uint64_t)tested;
    const l16 px = l16_load(P[0]), py = l16_load(P[1]), pz = l16_load(P[2]);
    const hpc_volume *v = &t->vl;
    uint32_t planes = pl & (v->n >= 32 ? UINT32_MAX : (UINT32_C(1) << v->n) - 1u);
    c->cnt[C_PLANE_TESTS] += (uint64_t)tested * (uint64_t)__builtin_popcount(planes);
    const l16 neps = l16_set1(-v->eps);
    for (; planes && act; planes &= planes - 1) {
        const int i = __builtin_ctz(planes);
        const l16 d = l16_add(l16_add(l16_add(l16_mul(l16_set1(v->soa[0][i]), px), l16_mul(l16_set1(v->soa[1][i]), py)),
                                      l16_mul(l16_set1(v->soa[2][i]), pz)),
                              l16_set1(v->soa[3][i]));
        act &= ~l16_lt(d, neps);
    }
    if (!act) return;
    c->cnt[C_PAIRS_IN_VL] += (uint64_t)__builtin_popcount(act & on[0]) + (uint64_t)__builtin_popcount(act & on[1]);
    /* the leaf footprint over the receivers left (their box and their grid origins' box) */
    uint64_t ncand[2][64], ngroups[2] = { ~UINT64_C(0), ~UINT64_C(0) };
    const uint64_t *lopen[LANES] = { 0 };   /* with the leaf footprint: each lane's open samples */
    /* pairs only: a lone triangle's set-up is shared by half as much work (measured on a scanned bunny, whose
     * triangles are 91% alone: it cost 5% there even with leaf_fp_pays) */
    /* the leaf's receivers in the lanes (leaf_lanes, above): not for alpha-tested triangles (their opacity is
     * looked up per hit, alpha_opaque) nor with the 16-lane sample test off */
    int lanes_ok = !(sh->sw & (MS_HPC_OFF_LEAF_LANES | MS_HPC_OFF_SIMD_SAMPLES));
    for (int u = 0; u < nt && lanes_ok; u++) lanes_ok = !ms_alpha_tested(sh->ctx->alpha, t[u].self);
    const int leaf_fp = !(sh->sw & MS_HPC_OFF_LEAF_FOOTPRINT) &&
                        ((sh->sw & MS_HPC_ALL_LEAF_FOOTPRINT) ||
                         (nt == 2 && __builtin_popcount(act) >= LEAF_FP_MIN && leaf_fp_pays(c, lanes_ok)));
    /* The shapes whose footprints are formed: each triangle, or for a rectangle pair under the leaf footprint
     * its rectangle, standing for both ("rectangle pairs" above; measured on grids, one thread, 1024^2: the
     * cast 9.42 -> 8.71 s, 7%; the other scenes within noise: docs/hpc.md). */
    /* Not where a receiver lies on one of the two (its own is not cast against it): the other, coplanar with it,
     * rules out every sample by mixed signs, while the rectangle around the receiver rules out none (on the
     * Quad's ground, with the leaf footprint on every leaf, the cast went 0.26 -> 0.85 s). */
    const int rect = leaf_fp && nt == 2 && t->rect && !(sh->sw & MS_HPC_OFF_RECT) && (act & on[0] & on[1]) == act,
              ns = rect ? 1 : nt;
    fp_shape shape[2];
    for (int u = 0; u < ns; u++) shape[u] = rect ? (fp_shape){ t->rc, 4 } : (fp_shape){ t[u].v, 3 };
    if (rect && (sh->sw & MS_HPC_BREAK_RECT)) shape[0].nv = 3;   /* wrong on purpose: the first triangle for both */
    leaf_box bx;   /* with the leaf footprint: the receivers' box and their grid origins' */
    if (leaf_fp) {
        for (int a = 0; a < 3; a++) {
            float plo = INFINITY, phi = -INFINITY, olo = INFINITY, ohi = -INFINITY;
            for (unsigned m = act; m; m &= m - 1) {
                const int l = __builtin_ctz(m);
                plo = ms_minf(plo, P[a][l]);
                phi = ms_maxf(phi, P[a][l]);
                const float p0 = sh->p0[4 * (size_t)rr[l] + a];
                olo = ms_minf(olo, p0);
                ohi = ms_maxf(ohi, p0);
            }
            /* centres and half extents; the differences rounded up (a float difference is off by u of itself) */
            bx.pc[a] = 0.5f * (plo + phi);
            bx.h[a] = ms_maxf(phi - bx.pc[a], bx.pc[a] - plo) * 1.000001f;
            bx.p0c[a] = 0.5f * (olo + ohi);
            bx.J[a] = ms_maxf(ohi - bx.p0c[a], bx.p0c[a] - olo) * 1.000001f;
            if (sh->sw & MS_HPC_BREAK_LEAF_BOUND) bx.J[a] = 0.0f;   /* wrong on purpose (test_hpc) */
        }
        leaf_fn fn[2];
        leaf_setup(sh, &bx, shape, ns, fn);
        c->cnt[C_RECT_PAIRS] += (uint64_t)rect;
        for (int u = 0; u < ns; u++) {   /* a rectangle: shape 0 stands for both triangles (on[0] covers act) */
            if (!(act & on[u])) {   /* no receiver for it: no samples (read by the rule's counts below) */
                memset(ncand[u], 0, (size_t)sh->mw * sizeof ncand[u][0]);
                continue;
            }
            ngroups[u] = leaf_footprint(sh, &bx, &fn[u], ncand[u]);
            if (!ngroups[u]) shape_off(c, C_LEAF_CULLS, act, on, u, rect);
        }
        act &= on[0] | on[1];
        if (!act) return;
        /* A sample blocked already for every receiver of the leaf needs no test for any (the paper's L21, for a
         * whole leaf): the candidates masked by the union of the receivers' open samples, and below each
         * receiver's by its own. Measured (session 14, one thread, 1024²): grids -13%, Sibenik -3 to -9%,
         * Dabrovic Sponza -3%, the bunny -1 to -6%; on grids 32% fewer pairs reach per-receiver work. */
        uint64_t any_open[64] = { 0 };
        for (unsigned m = act; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            lopen[l] = open_of(sh, c, rr[l]);
            for (int wd = 0; wd < sh->mw; wd++) any_open[wd] |= lopen[l][wd];
        }
        for (int u = 0; u < ns; u++) {
            if (!(act & on[u])) continue;
            uint64_t left = 0;
            for (int wd = 0; wd < sh->mw; wd++) left |= ncand[u][wd] &= any_open[wd];
            if (!left) shape_off(c, C_LEAF_CULLS_BLOCKED, act, on, u, rect);
        }
        act &= on[0] | on[1];
        if (!act) return;
    }
    /* footprint_setup per lane, per triangle; for a rectangle pair its five distinct functions (rect_fns), each
     * triangle's footprint taken from them below */
    const l16 w[3] = { l16_load(W[0]), l16_load(W[1]), l16_load(W[2]) }, rel = l16_load(R);
    float fe[2][5][3][LANES], fs[2][5][LANES], fdl[2][4][LANES], fdh[2][4][LANES];
    const l16 span = l16_set1((float)(sh->gs - 1)), zero = l16_set1(0.0f);
    for (int u = 0; u < ns; u++) {
        const int nv = rect ? 4 : 3, nfn = rect ? 5 : 3, (*pair)[2] = rect ? rect_fns : fp_edges[0];
        l16 Y[4][3], nY[4];
        for (int vtx = 0; vtx < nv; vtx++) {
            const l16 pc[3] = { px, py, pz };
            for (int a = 0; a < 3; a++) Y[vtx][a] = l16_sub(l16_set1(shape[u].v[3 * vtx + a]), pc[a]);
            nY[vtx] = l16_max(l16_abs(Y[vtx][0]), l16_max(l16_abs(Y[vtx][1]), l16_abs(Y[vtx][2])));
        }
        l16 esum[3] = { l16_set1(0.0f), l16_set1(0.0f), l16_set1(0.0f) };   /* 0 + x = x */
        for (int e = 0; e < nfn; e++) {
            const l16 *y1 = Y[pair[e][0]], *y2 = Y[pair[e][1]];
            const l16 X[3] = { l16_sub(l16_mul(y1[1], y2[2]), l16_mul(y1[2], y2[1])), l16_sub(l16_mul(y1[2], y2[0]), l16_mul(y1[0], y2[2])),
                               l16_sub(l16_mul(y1[0], y2[1]), l16_mul(y1[1], y2[0])) };
            const l16 c0 = l16_add(l16_add(l16_mul(X[0], w[0]), l16_mul(X[1], w[1])), l16_mul(X[2], w[2]));
            const l16 c1 = l16_add(l16_add(l16_mul(X[0], l16_set1(sh->grid_ds[0])), l16_mul(X[1], l16_set1(sh->grid_ds[1]))),
                                   l16_mul(X[2], l16_set1(sh->grid_ds[2])));
            const l16 c2 = l16_add(l16_add(l16_mul(X[0], l16_set1(sh->grid_dt[0])), l16_mul(X[1], l16_set1(sh->grid_dt[1]))),
                                   l16_mul(X[2], l16_set1(sh->grid_dt[2])));
            l16_store(fe[u][e][0], c0);
            l16_store(fe[u][e][1], c1);
            l16_store(fe[u][e][2], c2);
            if (!leaf_fp) spans16(c1, c2, span, zero, fdl[u][e], fdh[u][e]);
            l16_store(fs[u][e], l16_mul(l16_mul(rel, nY[pair[e][0]]), nY[pair[e][1]]));
            if (rect) continue;
            esum[0] = l16_add(esum[0], c0);
            esum[1] = l16_add(esum[1], c1);
            esum[2] = l16_add(esum[2], c2);
        }
        if (rect) continue;
        for (int a = 0; a < 3; a++) l16_store(fe[u][3][a], esum[a]);
        if (!leaf_fp) spans16(esum[1], esum[2], span, zero, fdl[u][3], fdh[u][3]);
    }
    /* With the leaf footprint: each sample it left, tested for the leaf's receivers in the lanes (footprint_keep
     * per receiver, the footprint_lanes arithmetic with the sample's own indices), giving each receiver its
     * samples: the work per leaf follows the samples left, which fall as the leaves shrink with resolution.
     * A rectangle pair's samples (its rectangle's, for both triangles) are looped over once, and each
     * triangle's own footprint is tested on them from the five functions, so that each triangle's exact tests
     * run on its own candidates only (the rectangle's would double them). */
    const int mw = sh->mw;
    uint64_t rc[2][LANES][64], rg[2][LANES];   /* per triangle and lane: the receiver's samples, their groups */
    uint64_t rsu[2][LANES][64];                /* of rc, the samples whose edge functions surely pass */
    unsigned has[2] = { 0u, 0u };
    const int lanes = leaf_fp && lanes_ok;
    leaf_lanes L;
    if (lanes) {
        L.act = act;
        L.ready = L.have = L.mixed = L.tsure = 0;
        memcpy(L.pc, bx.pc, sizeof L.pc);
        memcpy(L.h, bx.h, sizeof L.h);
        L.axis[0] = L.axis[1] = L.axis[2] = 0;
        L.has[0] = L.has[1] = 0;
        float p0[3][LANES] = { { 0 } };
        for (unsigned m = act; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            L.rr[l] = rr[l];
            L.open[l] = lopen[l];
            L.touched[l] = 0;
            L.ready |= (unsigned)(sh->slot[rr[l]] >= 0) << l;
            for (int a = 0; a < 3; a++) p0[a][l] = sh->p0[4 * (size_t)rr[l] + a];
        }
        for (unsigned m = L.ready; m; m &= m - 1) leaf_lanes_axis(sh, c, &L, __builtin_ctz(m));
        for (int a = 0; a < 3; a++) { L.p[a] = l16_load(P[a]); L.p0[a] = l16_load(p0[a]); }
    }
    if (leaf_fp)
        for (int u = 0; u < ns; u++) {
            const unsigned lanes_u[2] = { act & (rect ? on[0] : on[u]), rect ? act & on[1] : 0u };
            const unsigned lanes_on = lanes_u[0] | lanes_u[1];
            if (!lanes_on) continue;
            const int tu[2] = { u, u + 1 };   /* the triangles of the shape: u, or both of a rectangle pair */
            for (int x = 0; x < 1 + rect && !lanes; x++)
                for (unsigned m = lanes_u[x]; m; m &= m - 1) {
                    memset(rc[u + x][__builtin_ctz(m)], 0, (size_t)mw * sizeof(uint64_t));
                    memset(rsu[u + x][__builtin_ctz(m)], 0, (size_t)mw * sizeof(uint64_t));
                    rg[u + x][__builtin_ctz(m)] = 0;
                }
            const int nfn = rect ? 5 : 4;   /* with the triangle's sum */
            l16 c0[5], c1[5], c2[5], sl[2][3];
            for (int e = 0; e < nfn; e++) { c0[e] = l16_load(fe[u][e][0]); c1[e] = l16_load(fe[u][e][1]); c2[e] = l16_load(fe[u][e][2]); }
            unsigned slok[2] = { 0u, 0u };
            l16 slsure[2][3];   /* the sure lanes' slacks: sl, or -sl (MS_HPC_BREAK_SURE, wrong on purpose) */
            for (int x = 0; x < 1 + rect; x++) {
                for (int e = 0; e < 3; e++) {
                    sl[x][e] = l16_load(fs[u][rect ? rect_tri[x][e] : e]);
                    slsure[x][e] = (sh->sw & MS_HPC_BREAK_SURE) ? l16_sub(zero, sl[x][e]) : sl[x][e];
                }
                slok[x] = footprint_slack_ok(sl[x]);
            }
            for (int wd = 0; wd < mw; wd++) {
                if (lanes && ncand[u][wd]) leaf_lanes_word(&L, wd);
                for (uint64_t bits = ncand[u][wd]; bits; bits &= bits - 1) {
                    const int bit = __builtin_ctzll(bits), sidx = 64 * wd + bit;
                    /* k = 16, 32 or 64 (sh->gs), so a word holds whole rows */
                    const l16 fi = l16_set1(sh->bit_i[bit]), fj = l16_set1((float)(64 / sh->k * wd) + sh->bit_j[bit]);
                    l16 E[5];
                    for (int e = 0; e < nfn; e++) E[e] = l16_add(l16_add(c0[e], l16_mul(c1[e], fi)), l16_mul(c2[e], fj));
                    unsigned hitl[2], surel[2];
                    if (rect) {   /* rectangle pairs, above: each triangle's functions and their sum */
                        const l16 nd = l16_sub(zero, E[4]);
                        const l16 T0[4] = { E[0], E[1], E[4], l16_add(l16_add(E[0], E[1]), E[4]) };
                        const l16 T1[4] = { E[2], E[3], nd, l16_add(l16_add(E[2], E[3]), nd) };
                        hitl[0] = footprint_keep_lanes(T0, T0, sl[0]) & lanes_u[0];
                        hitl[1] = footprint_keep_lanes(T1, T1, sl[1]) & lanes_u[1];
                        surel[0] = footprint_sure_lanes(T0, slsure[0], slok[0]);
                        surel[1] = footprint_sure_lanes(T1, slsure[1], slok[1]);
                    } else {
                        hitl[0] = footprint_keep_lanes(E, E, sl[0]) & lanes_u[0];
                        hitl[1] = 0;
                        surel[0] = footprint_sure_lanes(E, slsure[0], slok[0]);
                        surel[1] = 0;
                    }
                    if (!(hitl[0] | hitl[1])) continue;
                    if (lanes) {
                        if (!leaf_lanes_sample(sh, c, t, &L, tu, 1 + rect, wd, bit, hitl, surel)) return;
                        continue;
                    }
                    const int gk = (sidx / sh->k / sh->gs) * (sh->k / sh->gs) + (sidx % sh->k) / sh->gs;
                    for (int x = 0; x < 2; x++)
                        for (unsigned h2 = hitl[x]; h2; h2 &= h2 - 1) {
                            const int l = __builtin_ctz(h2);
                            if (!(lopen[l][wd] >> bit & 1u)) continue;   /* blocked already for this receiver */
                            rc[u + x][l][wd] |= UINT64_C(1) << bit;
                            rsu[u + x][l][wd] |= (uint64_t)(surel[x] >> l & 1u) << bit;
                            rg[u + x][l] |= UINT64_C(1) << gk;
                            has[u + x] |= 1u << l;
                        }
                }
            }
        }
    if (lanes) {
        has[0] = L.has[0];
        has[1] = L.has[1];
        c->cnt[C_PAIRS_FOOTPRINT] += (uint64_t)(__builtin_popcount(has[0]) + __builtin_popcount(has[1]));
        leaf_lanes_umbra(sh, c, &L);
    }
    if (leaf_fp) {
        c->lf_in += (uint32_t)__builtin_popcount(act);
        c->lf_kept += (uint32_t)__builtin_popcount(act & (has[0] | has[1]));
        for (int u = 0; u < ns; u++)
            for (int wd = 0; wd < mw; wd++) c->lf_cands += (uint32_t)__builtin_popcountll(ncand[u][wd]);
        if (c->lf_in > 4096u) { c->lf_in >>= 1; c->lf_kept >>= 1; c->lf_cands >>= 1; }   /* the recent leaves count */
    }
    if (lanes) return;
    for (unsigned m = leaf_fp ? act & (has[0] | has[1]) : act; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        const uint32_t r = rr[l];
        hpc_view view;
        view.nt = 0;
        view.direct = leaf_fp;
        view.ngroups = 0;
        for (int u = 0; u < nt; u++) {
            if (!((leaf_fp ? has[u] : on[u]) >> l & 1u)) continue;
            const int x = view.nt++;
            view.t[x] = &t[u];
            if (leaf_fp) {
                view.ncand[x] = rc[u][l];
                view.nsure[x] = rsu[u][l];
                view.ngroups |= rg[u][l];
                continue;
            }
            for (int e = 0; e < 4; e++)
                for (int a = 0; a < 3; a++) view.fp[x].e[e][a] = fe[u][e][a][l];
            for (int e = 0; e < 3; e++) view.fp[x].s[e] = fs[u][e][l];
            for (int e = 0; e < 4; e++) { view.fp[x].dlo[e] = fdl[u][e][l]; view.fp[x].dhi[e] = fdh[u][e][l]; }
        }
        ms_grid g;
        memcpy(g.p0, sh->p0 + 4 * (size_t)r, sizeof g.p0);
        memcpy(g.ds, sh->grid_ds, sizeof g.ds);
        memcpy(g.dt, sh->grid_dt, sizeof g.dt);
        g.k = sh->k;
        cast_footprint(sh, c, r, &g, &view);
    }
}

/* PROCESS-RECURSIVE (L35-L81). */
static void cast_node(const shared *sh, chunk *c, uint32_t ni, const tri_job *t, uint32_t pl, const act_group *ag, int nag)
{
    hnode *N = &c->nodes[ni];
    c->cnt[C_NODE_VISITS]++;
    if (N->full) { c->cnt[C_UMBRA_NODE_SKIPS]++; return; }
    uint32_t pl2;
    if (!vol_box(sh, &t->vl, pl, N->lo, N->hi, &pl2, &c->cnt[C_PLANE_TESTS])) { c->cnt[C_NODES_OUTSIDE_VL]++; return; }
    const int sets = !(sh->sw & MS_HPC_OFF_PLANE_SETS);
    if (!sets) pl2 = HPC_ALL_PLANES;
    act_group ag2[64];
    int n2 = 0;
    for (int i = 0; i < nag; i++) {
        if (N->gumbra >> ag[i].k & 1u) continue;
        if (c->gvol_built) {
            uint32_t p2;
            if (vol_box(sh, &c->gvol[ag[i].k], ag[i].planes, N->lo, N->hi, &p2, &c->cnt[C_PLANE_TESTS]))
                ag2[n2++] = (act_group){ ag[i].k, sets ? p2 : HPC_ALL_PLANES };
        } else ag2[n2++] = (act_group){ ag[i].k, HPC_ALL_PLANES };
    }
    if (!n2) return;
    if (!N->count) {
        const uint32_t l = N->first;
        cast_node(sh, c, l, t, pl2, ag2, n2);
        cast_node(sh, c, l + 1, t, pl2, ag2, n2);
        N->gumbra = c->nodes[l].gumbra & c->nodes[l + 1].gumbra;
        N->full = c->nodes[l].full & c->nodes[l + 1].full;
    } else {
        if (sh->footprint && sh->p0 && N->count <= LANES) cast_leaf_footprint(sh, c, N, t, pl2);
        else   /* a pair's second triangle: its vl is the pair's (prepare_batch); pairs only with the footprint */
            for (int u = 0; u < (t->pair > 0 ? 2 : 1); u++)
                for (uint32_t i = N->first; i < N->first + N->count; i++) cast_point(sh, c, c->idx[i], &t[u], pl2, ag2, n2);
        node_bits_from_points(sh, c, N);
    }
}

/* PROCESS-BLOCKER-OPTIMIZED (L29-L34). */
static void cast_triangle(const shared *sh, chunk *c, const tri_job *t)
{
    if (c->failed || !c->n_nodes) return;
    if (c->umbra_in_tree > 64 && 4 * c->umbra_in_tree > c->n) {
        c->cnt[C_REBUILDS]++;
        const double t0 = omp_get_wtime();
        const int bad = build_tree(sh, c);
        c->cnt[C_REBUILD_THREAD_US] += (uint64_t)((omp_get_wtime() - t0) * 1e6);
        if (bad) { c->failed = 1; return; }
        if (!c->n_nodes) return;
    }
    c->cnt[C_TRI_CHUNK_PASSES]++;
    c->gvol_built = 0;
    /* C off: before the traversal (not for a pair: the group volumes are one triangle's, and they would cull
     * nodes for the other; with the footprint test they serve only that node culling) */
    if ((sh->sw & MS_HPC_OFF_LAZY) && t->pair <= 0) build_group_volumes(sh, c, t);
    act_group ag[64];
    for (int g = 0; g < sh->G; g++) ag[g] = (act_group){ (uint32_t)g, HPC_ALL_PLANES };
    cast_node(sh, c, 0, t, HPC_ALL_PLANES, ag, sh->G);
}

/* ---- the frame ---- */

/* make_chunks' split of idx[0..n) at split on axis, over the threads: the points below it first, both sides in
 * their order (a stable partition, so the result does not depend on the threads); tmp: n entries. Returns the
 * number below. */
static uint32_t partition_parallel(const shared *sh, uint32_t *idx, uint32_t n, int axis, float split, uint32_t *tmp,
                                   int threads)
{
    enum { MAX_T = 256 };
    uint32_t below[MAX_T + 1] = { 0 };
    const int nt = threads < MAX_T ? threads : MAX_T;
    const uint32_t per = (n + (uint32_t)nt - 1) / (uint32_t)nt;
#pragma omp parallel for schedule(static) num_threads(nt)
    for (int t = 0; t < nt; t++) {
        const uint32_t b = (uint32_t)t * per, e = b + per < n ? b + per : n;
        uint32_t c = 0;
        for (uint32_t i = b; i < e; i++) c += sh->q[idx[i]].p[axis] < split;
        below[t + 1] = c;
    }
    for (int t = 0; t < nt; t++) below[t + 1] += below[t];
    const uint32_t m = below[nt];
#pragma omp parallel for schedule(static) num_threads(nt)
    for (int t = 0; t < nt; t++) {
        const uint32_t b = (uint32_t)t * per, e = b + per < n ? b + per : n;
        uint32_t lo = below[t], hi = m + (b < n ? b : n) - below[t];
        for (uint32_t i = b; i < e; i++) {
            if (sh->q[idx[i]].p[axis] < split) tmp[lo++] = idx[i];
            else tmp[hi++] = idx[i];
        }
    }
    memcpy(idx, tmp, (size_t)n * sizeof *idx);
    return m;
}

/* bounds_of over the threads (min and max are exact, so the order does not matter). */
static void bounds_parallel(const shared *sh, const uint32_t *idx, uint32_t n, float lo[3], float hi[3], int threads)
{
    float l0 = INFINITY, l1 = INFINITY, l2 = INFINITY, h0 = -INFINITY, h1 = -INFINITY, h2 = -INFINITY;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(min : l0, l1, l2) reduction(max : h0, h1, h2)
    for (uint32_t i = 0; i < n; i++) {
        const float *p = sh->q[idx[i]].p;
        l0 = ms_minf(l0, p[0]); l1 = ms_minf(l1, p[1]); l2 = ms_minf(l2, p[2]);
        h0 = ms_maxf(h0, p[0]); h1 = ms_maxf(h1, p[1]); h2 = ms_maxf(h2, p[2]);
    }
    lo[0] = l0; lo[1] = l1; lo[2] = l2;
    hi[0] = h0; hi[1] = h1; hi[2] = h2;
}

/* Splits the receivers into at most cap chunks by middle splits, always the one with the most points next,
 * until every chunk holds at most `target` points; returns the count. Splitting the largest first keeps the
 * chunks' sizes even when the cap runs out: depth first, empty regions used up the cap and left a GRIDS-like
 * frame's densest region as one chunk of 28% of the points, which one thread cast alone while the other
 * waited at the batch's end (at 1024² the last batch took 4.9 s of wall time for 5.0 s of CPU). Each split's
 * bounds and partition run over the threads (serial, they took 0.23 s of a 2048² frame's wall time). */
static int make_chunks(const shared *sh, uint32_t *idx, uint32_t n, uint32_t target, chunk *out, int cap, int threads)
{
    typedef struct { uint32_t b, n; } range;
    range *r = malloc((size_t)cap * sizeof *r);
    uint32_t *tmp = malloc((size_t)n * sizeof *tmp);
    if (!r || !tmp) { free(r); free(tmp); return -1; }
    int nc = 1;
    r[0] = (range){ 0, n };
    while (nc < cap) {
        int big = 0;
        for (int i = 1; i < nc; i++)
            if (r[i].n > r[big].n) big = i;
        if (r[big].n <= target) break;
        const range x = r[big];
        float lo[3], hi[3];
        bounds_parallel(sh, idx + x.b, x.n, lo, hi, threads);
        const float ext[3] = { hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] };
        const int axis = ext[0] >= ext[1] ? (ext[0] >= ext[2] ? 0 : 2) : (ext[1] >= ext[2] ? 1 : 2);
        uint32_t m = partition_parallel(sh, idx + x.b, x.n, axis, lo[axis] + 0.5f * ext[axis], tmp, threads);
        if (m == 0 || m == x.n) m = x.n / 2;   /* coincident points: any split */
        /* The halves stay next to each other in the list (spatial order, which the renumbering keeps). */
        memmove(r + big + 2, r + big + 1, (size_t)(nc - big - 1) * sizeof *r);
        r[big] = (range){ x.b, m };
        r[big + 1] = (range){ x.b + m, x.n - m };
        nc++;
    }
    for (int i = 0; i < nc; i++) {
        out[i].idx = idx + r[i].b;
        out[i].n = r[i].n;
    }
    free(r);
    free(tmp);
    return nc;
}

/* The vertex of triangle b (9 floats) that triangle a lacks when they share exactly one edge (two vertices
 * bit for bit) and lie in nearly one plane (normals within about 0.1 degree); else -1. */
static int pair_vertex(const float *a, const float *b)
{
    int shared_v = 0, other = -1;
    for (int i = 0; i < 3; i++) {
        int found = 0;
        for (int j = 0; j < 3; j++) found |= !memcmp(b + 3 * i, a + 3 * j, 3 * sizeof *b);
        if (found) shared_v++;
        else other = i;
    }
    if (shared_v != 2) return -1;
    double na[3], nb[3], e1[3], e2[3];
    for (int x = 0; x < 3; x++) { e1[x] = (double)a[3 + x] - a[x]; e2[x] = (double)a[6 + x] - a[x]; }
    d3_cross(na, e1, e2);
    for (int x = 0; x < 3; x++) { e1[x] = (double)b[3 + x] - b[x]; e2[x] = (double)b[6 + x] - b[x]; }
    d3_cross(nb, e1, e2);
    const double dot = d3_dot(na, nb), la = d3_dot(na, na), lb = d3_dot(nb, nb);
    return la > 0.0 && lb > 0.0 && dot * dot >= (1.0 - 4e-6) * la * lb ? other : -1;
}

/* Departure from the paper: two triangles that share an edge and a plane (a box's face, a mesh's quad) are
 * cast as one job. Each receiver's exact tests stay per triangle (cast_footprint), so the answers are
 * raytrace's; what they share is the traversal, one V_L (of their four points) and the per-receiver work
 * around the samples' tests, which on a GRIDS-like scene (bars of boxes, each face two long thin triangles
 * with nearly the same footprint) is most of a pair's cost. The batch's triangles are reordered so that a
 * triangle's partner, looked for among the next PAIR_WINDOW, follows it (any order gives the same answer).
 * Returns the number of pairs. */
#define PAIR_WINDOW 16
static size_t pair_batch(float *tri, uint32_t *ids, int8_t *pairs, size_t n)
{
    size_t np = 0;
    memset(pairs, 0, n);
    for (size_t i = 0; i + 1 < n; i++) {
        if (pairs[i]) continue;
        for (size_t j = i + 1; j < n && j <= i + PAIR_WINDOW; j++) {
            if (pair_vertex(tri + 9 * i, tri + 9 * j) < 0) continue;
            if (j != i + 1) {   /* move j next to i */
                float tmp[9];
                memcpy(tmp, tri + 9 * (i + 1), sizeof tmp);
                memcpy(tri + 9 * (i + 1), tri + 9 * j, sizeof tmp);
                memcpy(tri + 9 * j, tmp, sizeof tmp);
                const uint32_t id = ids[i + 1];
                ids[i + 1] = ids[j];
                ids[j] = id;
            }
            pairs[i] = 1;
            pairs[i + 1] = -1;
            np++;
            break;
        }
    }
    return np;
}

static void prepare_batch(const shared *sh, tri_job *jobs, const float *tri, const uint32_t *ids, const int8_t *pairs,
                          size_t n)
{
#pragma omp parallel for schedule(static) num_threads(sh->ctx->threads)
    for (size_t i = 0; i < n; i++) {
        tri_job *t = &jobs[i];
        memcpy(t->v, tri + 9 * i, sizeof t->v);
        ms_wt_normal(t->v, t->N);
        t->self = ids[i];
        t->pair = pairs ? pairs[i] : 0;
        t->rect = 0;
        if (t->pair < 0) continue;   /* the pair's vl, made with the first */
        if (t->pair == 0) {
            hpc_volume_build(&t->vl, sh->light_poly, 4, t->v, tri_margin(sh, t->v));
            continue;
        }
        /* The pair's volume: of its four points, with the larger of the two margins (a relation either
         * triangle's exact test calls blocked lies within its margin of that triangle's shadow, which the
         * pair's contains). */
        const float *b = tri + 9 * (i + 1);
        t->rect = ms_coplanar_rect_pair(t->v, b, t->rc);
        float pts[12];
        memcpy(pts, t->v, sizeof t->v);
        memcpy(pts + 9, b + 3 * pair_vertex(t->v, b), 3 * sizeof *pts);
        hpc_volume_build_points(&t->vl, sh->light_poly, 4, pts, 4, ms_maxf(tri_margin(sh, t->v), tri_margin(sh, b)));
        jobs[i + 1].vl = t->vl;
    }
}

static void setup_light(shared *sh)
{
    const ms_light *L = &sh->ctx->light;
    sh->shear_axis = ms_light_shear_axis(L);
    const double P[3] = { L->corner.x, L->corner.y, L->corner.z };
    const double S[3] = { L->edge_s.x, L->edge_s.y, L->edge_s.z }, T[3] = { L->edge_t.x, L->edge_t.y, L->edge_t.z };
    const int k = sh->k, gpr = k / sh->gs;
    /* Widened by 1e-3 of a cell and by 16 ulps of the frame's coordinates (sh->scale, set by the caller):
     * the float samples round off their cells by ulps of their coordinates, which the polygons absorb so
     * that the culling margin need not magnify them. */
    const double ls = fmin(sqrt(S[0] * S[0] + S[1] * S[1] + S[2] * S[2]), sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2]));
    const double w = 1e-3 / k + (ls > 0.0 ? 16.0 * 1.1920929e-07 * sh->scale / ls : 0.0);
    const double corners[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
    for (int v = 0; v < 4; v++) {
        const double s = corners[v][0] * (1 + 2 * w) - w, t = corners[v][1] * (1 + 2 * w) - w;
        for (int a = 0; a < 3; a++) sh->light_poly[3 * v + a] = P[a] + s * S[a] + t * T[a];
    }
    for (int g = 0; g < sh->G; g++) {
        const double s0 = (double)(g % gpr * sh->gs) / k, t0 = (double)(g / gpr * sh->gs) / k, e = (double)sh->gs / k;
        for (int v = 0; v < 4; v++) {
            const double s = s0 - w + corners[v][0] * (e + 2 * w), t = t0 - w + corners[v][1] * (e + 2 * w);
            for (int a = 0; a < 3; a++) sh->group_poly[g][3 * v + a] = P[a] + s * S[a] + t * T[a];
        }
    }
    for (int a = 0; a < 3; a++) {
        sh->light_lo[a] = INFINITY;
        sh->light_hi[a] = -INFINITY;
        for (int v = 0; v < 4; v++) {
            sh->light_lo[a] = ms_minf(sh->light_lo[a], (float)sh->light_poly[3 * v + a]);
            sh->light_hi[a] = ms_maxf(sh->light_hi[a], (float)sh->light_poly[3 * v + a]);
        }
    }
}

int MS_CAT(ms_hpc_cast_, MS_ISA_SUFFIX)(const ms_render_ctx *ctx, int scanline, ms_raster_fn raster,
                                        const ms_shadow_query *q, size_t n, const uint64_t *front, uint64_t *vis,
                                        const hpc_source *src, uint64_t *counters)
{
    const int k = ctx->k, mw = ctx->mask_words;
    shared sh;
    memset(&sh, 0, sizeof sh);
    sh.ctx = ctx;
    sh.sw = ms_hpc_switches;
    sh.scanline = scanline;
    sh.raster = raster;
    sh.k = k;
    sh.mw = mw;
    sh.gs = k >= 64 ? 8 : 4;     /* 16, 64, 64 groups for k = 16, 32, 64 (a group-umbra word; 2x2 groups at
                                  * k = 16 tripled the box-plane tests and the time on a flowers scene) */
    sh.G = (k / sh.gs) * (k / sh.gs);
    for (int g = 0; g < sh.G; g++) {
        sh.group_i0[g] = (float)(g % (k / sh.gs) * sh.gs);
        sh.group_j0[g] = (float)(g / (k / sh.gs) * sh.gs);
    }
    for (int b = 0; b < 64; b++) { sh.bit_i[b] = (float)(b % k); sh.bit_j[b] = (float)(b / k); }
    sh.footprint = !scanline && !(sh.sw & MS_HPC_OFF_FOOTPRINT);
    sh.all_groups = sh.G == 64 ? UINT64_MAX : (UINT64_C(1) << sh.G) - 1u;
    sh.npk = k * k / LANES;
    sh.n = n;
    sh.q = q;
    sh.front = front;
    sh.frame_off = (size_t)mw * sizeof(uint64_t);
    sh.kz_off = sh.frame_off + (scanline ? sizeof(ms_raster_frame) : 0);
    sh.slot_bytes = (sh.kz_off + (size_t)sh.npk + 1 + 63) / 64 * 64;   /* + 1: the shared axis (slot_setup) */
    {
        ms_light_frame F;
        ms_light_frame_of(&ctx->light, &F);
        for (int a = 0; a < 3; a++) {   /* the light's four corners */
            const float c[4] = { F.corner[a], F.corner[a] + F.edge_s[a], F.corner[a] + F.edge_t[a],
                                 F.corner[a] + F.edge_s[a] + F.edge_t[a] };
            for (int v = 0; v < 4; v++) sh.scale = ms_maxf(sh.scale, 2.0f * fabsf(c[v]));
        }
    }
    const int threads = ctx->threads > 0 ? ctx->threads : 1;
    /* the receivers' box, and their largest coordinate in sh.scale (in parallel: the serial parts of a frame
     * count in its wall time; max and min are exact, so the order does not matter) */
    float lo0 = INFINITY, lo1 = INFINITY, lo2 = INFINITY, hi0 = -INFINITY, hi1 = -INFINITY, hi2 = -INFINITY, pmax = 0.0f;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(min : lo0, lo1, lo2) reduction(max : hi0, hi1, hi2, pmax)
    for (size_t i = 0; i < n; i++) {
        const float *p = q[i].p;
        lo0 = ms_minf(lo0, p[0]); lo1 = ms_minf(lo1, p[1]); lo2 = ms_minf(lo2, p[2]);
        hi0 = ms_maxf(hi0, p[0]); hi1 = ms_maxf(hi1, p[1]); hi2 = ms_maxf(hi2, p[2]);
        pmax = ms_maxf(pmax, ms_maxf(fabsf(p[0]), ms_maxf(fabsf(p[1]), fabsf(p[2]))));
    }
    sh.scale = ms_maxf(sh.scale, pmax);
    setup_light(&sh);
    const float rlo[3] = { lo0, lo1, lo2 }, rhi[3] = { hi0, hi1, hi2 };
    float reach2 = 0.0f;
    for (int a = 0; a < 3 && n; a++) {
        const float e = ms_maxf(fabsf(rhi[a] - sh.light_lo[a]), fabsf(sh.light_hi[a] - rlo[a]));
        reach2 += e * e;
    }
    sh.reach = sqrtf(reach2);

    int rc = -1, nchunks = 0;
    const int cap = 16 * threads;   /* chunks: see make_chunks */
    sh.gmask = calloc((size_t)sh.G * mw, sizeof *sh.gmask);
    sh.gumbra = malloc(n * sizeof *sh.gumbra);
    sh.full = malloc(n);
    sh.slot = malloc(n * sizeof *sh.slot);
    uint64_t *const gumbra0 = sh.gumbra, *gumbra2 = NULL;   /* by the caller's numbers, by hierarchy order */
    uint8_t *const full0 = sh.full, *full2 = NULL;
    int32_t *const slot0 = sh.slot, *slot2 = NULL;
    uint32_t *orig = NULL, nlive = 0;
    ms_shadow_query *q2 = NULL;
    uint32_t *idx = malloc(n * sizeof *idx);
    chunk *ch = calloc((size_t)cap, sizeof *ch);
    tri_job *jobs = malloc(BATCH * sizeof *jobs);
    float *tri = malloc(BATCH * 9 * sizeof *tri);
    uint32_t *ids = malloc(BATCH * sizeof *ids);
    int8_t *pairs = malloc(BATCH);
    if (!sh.gmask || !sh.gumbra || !sh.full || !sh.slot || !idx || !ch || !jobs || !tri || !ids || !pairs) goto done;
    for (int g = 0; g < sh.G; g++) {
        const int gpr = k / sh.gs, i0 = g % gpr * sh.gs, j0 = g / gpr * sh.gs;
        for (int j = j0; j < j0 + sh.gs; j++)
            for (int i = i0; i < i0 + sh.gs; i++) {
                const int s = j * k + i;
                sh.gmask[(size_t)g * mw + (s >> 6)] |= UINT64_C(1) << (s & 63);
            }
        sh.gw0[g] = (j0 * k + i0) >> 6;
        sh.gw1[g] = ((j0 + sh.gs - 1) * k + i0 + sh.gs - 1) >> 6;
    }
    /* Samples behind the horizon count as blocked from the start (umbra bits: nothing open). In parallel, the
     * live receivers gathered after (the serial parts of a frame count in its wall time). */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t r = 0; r < n; r++) {
        uint64_t gu = 0;
        const uint64_t *f = front + r * mw;
        for (int g = 0; g < sh.G; g++) {
            int open = 0;
            for (int w = sh.gw0[g]; w <= sh.gw1[g]; w++) open |= (f[w] & sh.gmask[(size_t)g * mw + w]) != 0;
            if (!open) gu |= UINT64_C(1) << g;
        }
        sh.gumbra[r] = gu;
        sh.full[r] = gu == sh.all_groups;
        sh.slot[r] = -1;
    }
    for (size_t r = 0; r < n; r++)
        if (!sh.full[r]) idx[nlive++] = (uint32_t)r;
    const uint32_t target = (uint32_t)((nlive + cap - 1) / cap) > 1024u ? (uint32_t)((nlive + cap - 1) / cap) : 1024u;
    nchunks = nlive ? make_chunks(&sh, idx, nlive, target, ch, cap, threads) : 0;
    if (nchunks < 0) goto done;
    int failed = 0;
    double t0 = omp_get_wtime();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(| : failed)
    for (int i = 0; i < nchunks; i++) failed |= build_tree(&sh, &ch[i]) != 0;
    counters[C_BUILD_US] += (uint64_t)((omp_get_wtime() - t0) * 1e6);
    if (failed) goto done;
    /* Renumbering in hierarchy order: the chunks' receivers one after another, each chunk's in its leaves'
     * order, with their queries, umbra bits, flags and slots, so that a leaf reads its points' data from a few
     * cache lines (the caller's order scatters them: the per-pair loads of umbra bits and masks took a
     * fifth of a cast on a GRIDS-like scene); the front masks stay the caller's (read once per receiver). */
    orig = malloc((nlive ? nlive : 1) * sizeof *orig);
    q2 = malloc((nlive ? nlive : 1) * sizeof *q2);
    gumbra2 = malloc((nlive ? nlive : 1) * sizeof *gumbra2);
    full2 = malloc(nlive ? nlive : 1);
    slot2 = malloc((nlive ? nlive : 1) * sizeof *slot2);
    if (!orig || !q2 || !gumbra2 || !full2 || !slot2) goto done;
    {
        uint32_t pos = 0;
        for (int i = 0; i < nchunks; i++) {
            ch[i].base = pos;
            ch[i].n0 = ch[i].n;
            pos += ch[i].n;
        }
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int i = 0; i < nchunks; i++)
        for (uint32_t j = 0, pos = ch[i].base; j < ch[i].n; j++, pos++) {
            const uint32_t o = ch[i].idx[j];
            orig[pos] = o;
            q2[pos] = q[o];
            gumbra2[pos] = sh.gumbra[o];
            full2[pos] = sh.full[o];
            slot2[pos] = -1;
            ch[i].idx[j] = pos;
        }
    sh.orig = orig;
    sh.q = q2;
    sh.gumbra = gumbra2;
    sh.full = full2;
    sh.slot = slot2;
    if (sh.footprint && nlive) {
        /* Each receiver's grid origin, formed once: the footprint test needs its grid for every triangle whose
         * V_L holds it. The steps are the light's (the same for every pixel, pattern.c); checked bit for bit,
         * and the grids formed per pair if they ever differ. */
        ms_grid g0;
        ms_grid_for_pixel(&ctx->light, k, sh.q[0].px, sh.q[0].py, ctx->seed, &g0);
        memcpy(sh.grid_ds, g0.ds, sizeof sh.grid_ds);
        memcpy(sh.grid_dt, g0.dt, sizeof sh.grid_dt);
        sh.p0 = malloc((size_t)nlive * 4 * sizeof *sh.p0);
        int same = sh.p0 != NULL;
        const size_t n_origins = sh.p0 ? nlive : 0;   /* the bound apart from the reduction's variable (TSan) */
#pragma omp parallel for schedule(static) num_threads(threads) reduction(& : same)
        for (size_t r = 0; r < n_origins; r++) {
            ms_grid g;
            ms_grid_for_pixel(&ctx->light, k, sh.q[r].px, sh.q[r].py, ctx->seed, &g);
            memcpy(sh.p0 + 4 * r, g.p0, sizeof g.p0);
            sh.p0[4 * r + 3] = footprint_rel(&g, sh.q[r].p, k);
            same &= !memcmp(g.ds, sh.grid_ds, sizeof g.ds) && !memcmp(g.dt, sh.grid_dt, sizeof g.dt);
        }
        if (!same) { free(sh.p0); sh.p0 = NULL; }
        else counters[C_SAMPLE_BYTES] += (uint64_t)nlive * 4u * sizeof *sh.p0;
        sh.pairs = sh.p0 && !(sh.sw & MS_HPC_OFF_PAIRS);
    }
    if (sh.sw & MS_HPC_OFF_ON_DEMAND) {   /* D off: every receiver's mask and sample data before any triangle */
        for (int i = 0; i < nchunks; i++)
            for (uint32_t j = 0; j < ch[i].n; j++) {
                const uint32_t r = ch[i].idx[j];
                const int32_t s = slot_get(&sh, &ch[i]);
                if (s < 0) goto done;
                ms_grid g;
                ms_grid_for_pixel(&ctx->light, k, sh.q[r].px, sh.q[r].py, ctx->seed, &g);
                sh.slot[r] = s;
                memcpy(slot_mask(&sh, &ch[i], s), front + (size_t)orig[r] * mw, (size_t)mw * sizeof(uint64_t));
                slot_setup(&sh, &ch[i], s, &sh.q[r], &g);
            }
    }
    t0 = omp_get_wtime();

    if (src->rewind && src->rewind(src->user)) goto done;
    for (;;) {
        const size_t got = src->next(src->user, tri, ids, BATCH);
        if (got == (size_t)-1) goto done;
        if (!got) break;
        if (sh.pairs) pair_batch(tri, ids, pairs, got);
        prepare_batch(&sh, jobs, tri, ids, sh.pairs ? pairs : NULL, got);
        counters[C_TRIANGLES] += got;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
        for (int i = 0; i < nchunks; i++)
            for (size_t t = 0; t < got; t++)
                if (jobs[t].pair >= 0) cast_triangle(&sh, &ch[i], &jobs[t]);
        for (int i = 0; i < nchunks; i++)
            if (ch[i].failed) goto done;
    }
    counters[C_CAST_US] += (uint64_t)((omp_get_wtime() - t0) * 1e6);
    /* The visible masks: front where no triangle came near, nothing in full umbra, else what is open. */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t r = 0; r < n; r++) {
        uint64_t *v = vis + r * mw;
        if (full0[r]) memset(v, 0, (size_t)mw * sizeof *v);
        else memcpy(v, front + r * mw, (size_t)mw * sizeof *v);
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int i = 0; i < nchunks; i++) {
        chunk *c = &ch[i];
        for (uint32_t r = c->base; r < c->base + c->n0; r++) {
            uint64_t *v = vis + (size_t)orig[r] * mw;
            if (sh.full[r]) memset(v, 0, (size_t)mw * sizeof *v);
            else if (sh.slot[r] >= 0) memcpy(v, slot_mask(&sh, c, sh.slot[r]), (size_t)mw * sizeof *v);
        }
    }
    rc = 0;
done:
    for (int i = 0; i < (nchunks > 0 ? nchunks : 0); i++) {
        for (int c = 0; c < C_COUNT; c++)
            if (c != C_TRIANGLES && c != C_MASKS_PEAK) counters[c] += ch[i].cnt[c];
        counters[C_MASKS_PEAK] += (uint64_t)ch[i].peak;
        /* The pool as allocated (it only grows): each slot's mask, and its per-point sample data (the
         * packets' shear axes, the Scanline frame). */
        counters[C_MASK_BYTES] += (uint64_t)ch[i].cap_slots * (uint64_t)mw * 8u;
        counters[C_SAMPLE_BYTES] += (uint64_t)ch[i].cap_slots * (uint64_t)(sh.slot_bytes - (size_t)mw * 8u);
        counters[C_HIERARCHY_BYTES] += ch[i].node_bytes_peak;
        free(ch[i].nodes);
        free(ch[i].pool);
        free(ch[i].free_list);
    }
    /* The hierarchy's per-point arrays: indices, umbra bits, full flags, slot numbers; the groups' masks. */
    counters[C_HIERARCHY_BYTES] += (uint64_t)n * (sizeof *idx + sizeof *sh.gumbra + 1u + sizeof *sh.slot) +
                                   (uint64_t)nlive * (sizeof *orig + sizeof *q2 + sizeof *gumbra2 + 1u + sizeof *slot2);
    counters[C_SAMPLE_BYTES] += (uint64_t)sh.G * (uint64_t)mw * 8u;
    free(ch);
    free(idx);
    free(jobs);
    free(tri);
    free(ids);
    free(pairs);
    free(sh.gmask);
    free(gumbra0);
    free(full0);
    free(slot0);
    free(orig);
    free(q2);
    free(gumbra2);
    free(full2);
    free(slot2);
    free(sh.p0);
    return rc;
}
