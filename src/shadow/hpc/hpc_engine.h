/* Methods "hpc" and "hpc-scanline": hierarchical penumbra casting (Laine & Aila, "Hierarchical Penumbra
 * Casting", EGSR 2005, sec. 3), the transpose of ray tracing: for each triangle, find every (light sample ->
 * receiver point) relation it blocks, with a hierarchy over the receiver points and a three-level hierarchy
 * over the light samples, never a hierarchy over the scene. The triangles are read once, in any order, in
 * batches (hpc_source), so they need not be in memory together.
 *
 * What is the paper's (sec. 3.1-3.3, the pseudocode of its Fig. 3, line numbers L..):
 *  - the receiver points (the frame's visible hit points) in a BVH of axis-aligned boxes: nodes of more
 *    than 1K points split at the middle of the box, smaller ones by surface area (hpc_build_tree);
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
 *    (hpc_pair_batch): one traversal, one V_L of their four points (hpc_volume_build_points), one per-receiver
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
 *    hard shadow volume (L22); here the functions the footprint already evaluated decide most of them (on
 *    merged bars most sample tests take it); only footprints over several groups take it (cast_blocks). Where
 *    the triangle lies
 *    well between every receiver of a leaf (or the one receiver) and the light, even the t range is proven
 *    (hpc_t_sure), and such samples are blocked without any test.
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
 * The engine's files (docs/hpc.md, "Files", maps them): what does not depend on the ISA is compiled once and
 * declared in this header (hpc_tree.c, hpc_chunks.c, hpc_slots.c, hpc_triangle.c, hpc_footprint.c, hpc_tsure.c,
 * hpc_exact.c, hpc_frame.c); the 16-lane parts are one source per ISA, hpc_impl.h and the *_impl.h files it
 * includes, compiled as hpc_scalar.c, hpc_avx2.c and hpc_avx512.c, each defining ms_hpc_cast_<isa>; hpc.c picks
 * one under the context's cap. hpc_impl.h says what the ISA changes: nothing in the masks and counters.
 * Measuring switches (ms_hpc_switches, hpc.h; the tests' copy of the library only) turn off each optimisation of
 * sec. 3.3 and each SIMD form.
 *
 * Threads: the receiver points are split into spatially coherent chunks (the top of a middle-split
 * hierarchy, up to 16 per thread, the largest split first: hpc_make_chunks), each with its own hierarchy, masks
 * and umbra bits; every batch of triangles is read once, its V_L made once in parallel, and then every chunk
 * processes the whole batch, chunks scheduled dynamically over the threads. No point is shared between
 * chunks, so there are no locks, and the answer (an OR over triangles per relation) does not depend on the
 * split. */

#ifndef MS_HPC_ENGINE_H
#define MS_HPC_ENGINE_H
#include "hpc.h"
#include "hpc_volume.h"
#include "shadow/method.h"
#include "light/pattern.h"
#include "raster/raster.h"
#include "core/vec.h"
#include <math.h>
#include <stddef.h>
#include <stdint.h>

#define LEAF_POINTS 8
#define LEAF_POINTS_FOOTPRINT 16   /* hpc's leaves, whose points are tested 16 at a time (cast_leaf_footprint) */
#define MIDDLE_SPLIT_ABOVE 1024   /* the paper's 1K */
#define SAH_BINS 16
#define MEDIAN_BELOW_DEPTH 40     /* median splits from here: depth at most 40 + log2(points) */
#define BATCH 16384               /* triangles read and prepared together */
#define EDGE_ON 1e-3f             /* as microraster.c */
#define LEAF_FP_MIN 6
#define LANES 16                  /* the reference tracer's packet width (raytrace_impl.h) */
#define SURE_MIN_GROUPS 4         /* the sure lanes only for footprints over this many groups (cast_footprint) */

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
    C_SAMPLES_TSURE,     /* of samples_sure, those blocked without the t range's operations (hpc_t_sure) */
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
                              * -1: cast with the previous one (its vl unused); 0: alone (hpc_pair_batch) */
    int rect;                /* pair 1 only: the two are the halves of one axis-aligned rectangle, corners rc */
    float rc[12];
    hpc_volume vl;
} tri_job;

typedef struct act_group { uint32_t k, planes; } act_group;

/* Per frame, read-only while the triangles are cast. */
typedef struct shared {
    const ms_render_ctx *ctx;
#ifdef MS_TEST_HOOKS
    int sw;                          /* ms_hpc_switches when the cast started (hpc_sw) */
#endif
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
    int pairs;                       /* footprint with p0: triangles sharing an edge cast in pairs (hpc_pair_batch) */
    float grid_ds[3], grid_dt[3];    /* the grid's steps, the same for every pixel (pattern.c) */
    float *p0;                       /* per receiver: its grid's origin and hpc_footprint_rel (NULL: formed per pair) */
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

/* Whether one of the measuring switches or faults in bits (hpc.h) is set for this cast: in the tests' copy of the
 * library only (core/test_hooks.h); 0 in the library users get, where each branch on it folds away (sh is
 * still named there, so that a function that reads it for nothing else has no unused parameter). */
#define hpc_sw(sh, bits) ((void)(sh), MS_HOOK((sh)->sw & (bits)))

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

/* ---- masks on demand (D): a receiver's slot in its chunk's pool (hpc_slots.c, hpc_slots_impl.h) ---- */

static inline uint64_t *slot_mask(const shared *sh, const chunk *c, int32_t s) { return (uint64_t *)(c->pool + (size_t)s * sh->slot_bytes); }
static inline ms_raster_frame *slot_frame(const shared *sh, const chunk *c, int32_t s) { return (ms_raster_frame *)(c->pool + (size_t)s * sh->slot_bytes + sh->frame_off); }
static inline int8_t *slot_kz(const shared *sh, const chunk *c, int32_t s) { return (int8_t *)(c->pool + (size_t)s * sh->slot_bytes + sh->kz_off); }

/* The samples of receiver r still open: its mask slot's, or its front mask before a triangle first may block it. */
static inline const uint64_t *open_of(const shared *sh, chunk *c, uint32_t r)
{
    const int32_t s = sh->slot[r];
    return s >= 0 ? slot_mask(sh, c, s) : sh->front + (size_t)sh->orig[r] * sh->mw;
}

static inline int group_done(const shared *sh, const uint64_t *open, int gk)
{
    const uint64_t *m = sh->gmask + (size_t)gk * sh->mw;
    for (int w = sh->gw0[gk]; w <= sh->gw1[gk]; w++)
        if (open[w] & m[w]) return 0;
    return 1;
}

/* A leaf's umbra bits from its points' (A: ANDed upwards, L50-L54). */
static inline void node_bits_from_points(const shared *sh, const chunk *c, hnode *N)
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

/* A free slot of chunk c (its pool grows by doubling), counted; -1 out of memory. */
int32_t hpc_slot_get(const shared *sh, chunk *c);
void hpc_slot_put(chunk *c, int32_t s);
/* Receiver r's open groups after a triangle (L72-L75): its umbra bits, and at full umbra its mask back. */
void hpc_record_umbra(const shared *sh, chunk *c, uint32_t r, int32_t s, uint64_t gu);

/* ---- the receiver hierarchy (hpc_tree.c) and the chunks (hpc_chunks.c) ---- */

/* (Re)builds the chunk's hierarchy over its points that are not in full umbra. 0, or -1 out of memory. */
int hpc_build_tree(const shared *sh, chunk *c);
/* Splits the receivers idx[0..n) into at most cap chunks of at most `target` points (out); returns the count,
 * -1 out of memory. */
int hpc_make_chunks(const shared *sh, uint32_t *idx, uint32_t n, uint32_t target, chunk *out, int cap, int threads);

/* ---- per triangle (hpc_triangle.c) ---- */

/* The group volumes V_Gk of triangle t for chunk c (C: made lazily). */
void hpc_group_volumes(const shared *sh, chunk *c, const tri_job *t);
/* Reorders a batch so that triangles sharing an edge and a plane follow each other, pairs[i] = 1, -1 (the
 * second), 0 (alone); returns the number of pairs. */
size_t hpc_pair_batch(float *tri, uint32_t *ids, int8_t *pairs, size_t n);
/* The batch's jobs: each triangle's normal, id, pairing and V_L (in parallel). pairs may be NULL. */
void hpc_prepare_batch(const shared *sh, tri_job *jobs, const float *tri, const uint32_t *ids, const int8_t *pairs,
                       size_t n);

/* ---- the exact test, one sample at a time (hpc_exact.c; the 16-lane form in hpc_exact_impl.h) ---- */

int hpc_sample_blocked(const float o[3], const float d[3], int kz, const float *tri, const float N[3],
                       const float A[3], const float B[3], const float C[3], float num, float tmin, float tmax);
int hpc_alpha_opaque(const shared *sh, const tri_job *t, const ms_shadow_query *q, const ms_grid *g, int i, int j);
int hpc_cast_group(const shared *sh, chunk *c, uint64_t *open, const int8_t *kz, int gk, const ms_shadow_query *q,
                   const ms_grid *g, const tri_job *t, const float A[3], const float B[3], const float C[3], float num);

/* ---- the footprint test (hpc_footprint.c; its lanes in hpc_footprint_impl.h) ---- */

/* A receiver's footprint of a triangle: its edge functions as affine functions of the sample's indices, with
 * their slacks (hpc_footprint.c has the proof). */
typedef struct hpc_footprint {
    float e[4][3];   /* per edge function, and their sum (e[3]): e0, e1 (per column i), e2 (per row j) */
    float s[3];      /* per edge function: the slack */
    float dlo[4], dhi[4];   /* each function's least and largest change over a group from its first sample */
} hpc_footprint;

static inline float inf_norm3(const float v[3]) { return ms_maxf(fabsf(v[0]), ms_maxf(fabsf(v[1]), fabsf(v[2]))); }

void hpc_footprint_spans(hpc_footprint *f, float span);
float hpc_footprint_rel(const ms_grid *g, const float p[3], int k);
void hpc_footprint_setup(hpc_footprint *f, const float A[3], const float B[3], const float C[3], const ms_grid *g,
                         const float p[3], float rel);

/* ---- the sure lanes' t range (hpc_tsure.c) ---- */

static inline int tsure_on(const shared *sh) { return !hpc_sw(sh, MS_HPC_OFF_SURE | MS_HPC_OFF_TSURE); }
/* 1 when every segment from a receiver in the box pc +- h to the light meets t's plane well inside the exact
 * test's range (hpc_tsure.c has the proof). */
int hpc_t_sure(const shared *sh, const float pc[3], const float h[3], const tri_job *t);

/* ---- the frame (hpc_frame.c): what one ms_hpc_cast_<isa> holds ---- */

typedef struct hpc_frame {
    shared sh;
    int threads, cap, nchunks;       /* nchunks -1 when the split ran out of memory */
    size_t batch;                    /* triangles per batch: BATCH, or fewer when the source has fewer */
    chunk *ch;
    uint32_t *idx, nlive;            /* the live receivers (not in full umbra from the start), by chunk */
    uint64_t *gumbra0;               /* by the caller's numbers (sh's arrays are by hierarchy order after */
    uint8_t *full0;                  /* the renumbering) */
    int32_t *slot0;
    uint32_t *orig;
    ms_shadow_query *q2;
    uint64_t *gumbra2;
    uint8_t *full2;
    int32_t *slot2;
    tri_job *jobs;                   /* a batch: its jobs, triangles, ids and pairing */
    float *tri;
    uint32_t *ids;
    int8_t *pairs;
} hpc_frame;

/* Everything before the triangles: the shared state, the light's polygons, the groups, the receivers' horizon,
 * the chunks and their hierarchies, the renumbering and the grid origins. 0, or -1 out of memory (F is then
 * still to be ended). */
int hpc_frame_begin(hpc_frame *F, const ms_render_ctx *ctx, int scanline, ms_raster_fn raster,
                    const ms_shadow_query *q, size_t n, const uint64_t *front, size_t batch, uint64_t *counters);
/* The visible masks, by the caller's numbers. */
void hpc_frame_vis(const hpc_frame *F, uint64_t *vis);
/* The chunks' counters and memory into counters; frees everything. */
void hpc_frame_end(hpc_frame *F, uint64_t *counters);

#endif
