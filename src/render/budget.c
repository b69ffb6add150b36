/* Memory budgets (budget.h). Every constant below is the byte count of the allocation it stands for, taken
 * from the allocation site named beside it, so that the estimate is an upper bound of what is allocated;
 * docs/memory.md compares the estimates with measured peak RSS. */
#include "budget.h"
#include "primary/primary.h"
#include "shade.h"
#include "visibility/context.h"
#include "visibility/occluders.h"   /* MS_INTERIOR_RES_SILHOUETTE, MS_INTERIOR_TRIS_PER_BOX */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* Triangles as 9 floats: a materialised procedural scene (render_materialise.c), hpc's per-call copy. */
#define TRI_BYTES 36u
/* BVH nodes (32 bytes) are counted as one per triangle: the binned SAH with leaves of at most 4 made 0.59-0.67
 * per triangle on the shared scenes and the flowers (docs/memory.md); its worst case is 2, which the build
 * allocates but does not touch. */
/* ms_bvh_build at its peak: centroids 12, boxes 24, indices 4, nodes 32, and the result's triangles 36,
 * sources 4, normals 12 (accel/bvh_build.c). */
#define BVH_BUILD_PER_TRI 124u
/* A built BVH: triangles, sources, normals, nodes. */
#define BVH_PER_TRI 84u
/* A shallow view per light (bvh_shallow.c; with leaves of 8 it had 0.32-0.36 nodes per triangle, counted as
 * 0.5): nodes 16, and the build's ranges (8 per BVH node) while it runs. */
#define SHALLOW_PER_TRI 24u
/* hpc on a soup (hpc_method.c, hpc_sort.c): area order 4, leaf map 4, buckets 1. */
#define HPC_ORDER_PER_TRI 9u
/* Embree's scene (visibility/embree_scene.c, robust build): its BVH, triangle copies and its build's
 * temporaries, measured at about 150 bytes per triangle at the peak (docs/memory.md). */
#define EMBREE_PER_TRI 192u
/* 3dr-* primaries' per-triangle set-up (primary_3dr.c: r3_setup, an ms_e3_tri of doubles and two boxes). */
#define R3_SETUP_PER_TRI 200u
/* hpc (hpc.c) per receiver: umbra bits 8, full 1, slot 4, index 4; its receiver tree (leaves of up to 16
 * points: counted as one 48-byte node per receiver) and the build's stack (16); the copies in hierarchy
 * order made beside the caller's (hpc_impl.h: original number 4, query 36, umbra bits 8, full 1, slot 4),
 * the receivers' grid origins (16) and the chunks' partition buffer (4, make_chunks); its mask slots (mask,
 * packet axes, for hpc-scanline a raster frame) come on top, counted as if every receiver held one at once
 * (the masks on demand's worst case: measured peaks are 1.4-2.2x below). */
#define HPC_PER_RECEIVER (8u + 1u + 4u + 4u + 48u + 16u + 4u + 36u + 8u + 1u + 4u + 16u + 4u)
#define HPC_RASTER_FRAME 112u
/* Closed components (accel/closed.c, ms_closed_find) while they are found: the weld's hash table of a power
 * of two >= 6n vertex slots (4 bytes), corner ids 12, the directed edges grouped by first vertex (offsets at
 * most 12, targets 12, triangles 12), unions 8, flags 2, components and cycles 8 per triangle (kept while
 * the lights' occluders are built), and the interior boxes' grid (accel/interior.c: at most
 * (MS_INTERIOR_RES_SILHOUETTE + 4)^3 cells of 9 bytes, one cycle at a time). The holed sets (accel/holes.c)
 * take the rim's corners (at most 12 per triangle) while the edges are matched, within the sum above, then their
 * sizes, rim counts, numbers, rim edges, ends and caps (at most 12 + 4 + 5) once the hash table and the edges
 * are freed, within what those held; what stays is their labels (4) and one group's ids for its grid (4). */
static uint64_t closed_find_bytes(uint64_t n)
{
    uint64_t m = 16;
    while (m < 6 * n) m <<= 1;
    const uint64_t side = MS_INTERIOR_RES_SILHOUETTE + 4u;   /* res cells, a border each side, a spare, rounding */
    return m * 4u + n * (12u + 36u + 8u + 2u + 8u + 4u + 4u) + side * side * side * 9u;
}
/* A light's interior boxes (visibility/occluders.c, interior_build): at most one per MS_INTERIOR_TRIS_PER_BOX
 * triangles of a cycle and one more, whose MS_INTERIOR_MIN_TRIS triangles or more bound the extra one
 * (accel/interior.c); per box twelve face triangles and the box as one prim in two BVHs, built or building
 * (the build's per-triangle bytes bound both), their shallow views, the box (24) and the faces' copy (432). */
#define INTERIOR_PER_BOX (13u * (BVH_BUILD_PER_TRI + SHALLOW_PER_TRI) + 24u + 432u)
#define INTERIOR_PER_TRI (INTERIOR_PER_BOX / MS_INTERIOR_TRIS_PER_BOX + INTERIOR_PER_BOX / MS_INTERIOR_MIN_TRIS + 1u)
/* A light's occluders (visibility/occluders.c): a BVH over the kept triangles (at most all), the map from
 * the scene's prims (4) and the merged-face flags (1); while one is built, the kept triangles, sources,
 * map, flags and alpha leaf map (49), the merged copy with its maps and flags (45), and the build's
 * temporaries (the merge's own, 84 per triangle, are freed before the build and stay below them). */
#define OCCLUDERS_PER_TRI (BVH_PER_TRI + 5u)
#define OCCLUDERS_BUILD_PER_TRI (94u + BVH_BUILD_PER_TRI - BVH_PER_TRI)

/* Thread-private buffers and what OpenMP and the allocator keep per thread. */
#define PER_THREAD (256u * 1024u)
/* The call's own small allocations (method states, tables). */
#define FIXED (1u << 20)

void ms_need_add(ms_need *n, const char *name, uint64_t bytes)
{
    n->total = n->total + bytes < n->total ? UINT64_MAX : n->total + bytes;
    if (!bytes) return;
    for (int i = 0; i < n->n; i++)
        if (strcmp(n->name[i], name) == 0) {
            n->bytes[i] = n->bytes[i] + bytes < n->bytes[i] ? UINT64_MAX : n->bytes[i] + bytes;
            return;
        }
    if (n->n < MS_NEED_PARTS) {
        n->name[n->n] = name;
        n->bytes[n->n++] = bytes;
    }
}

void ms_bytes_text(uint64_t b, char *buf, size_t len)
{
    static const char *const unit[] = { "B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB" };
    double v = (double)b;
    int u = 0;
    while (v >= 1024.0 && u < 6) { v /= 1024.0; u++; }
    if (u == 0) snprintf(buf, len, "%llu B", (unsigned long long)b);
    else snprintf(buf, len, v < 10.0 ? "%.2f %s" : v < 100.0 ? "%.1f %s" : "%.0f %s", v, unit[u]);
}

uint64_t ms_memory_budget(uint64_t max_memory)
{
    if (max_memory) return max_memory;
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0) return UINT64_MAX;   /* unknown: no default bound */
    return (uint64_t)pages * (uint64_t)page / 100u * MS_MEMORY_DEFAULT_PERCENT;
}

static uint64_t mul(uint64_t a, uint64_t b) { return a && b > UINT64_MAX / a ? UINT64_MAX : a * b; }

uint64_t ms_accel_need(size_t n_tris)
{
    /* points.c: the BVH, then the closed components found over it (kept: 8 per triangle), the leaf map 4. */
    const uint64_t build = mul(n_tris, BVH_BUILD_PER_TRI), find = mul(n_tris, BVH_PER_TRI) + closed_find_bytes(n_tris);
    return (build > find ? build : find) + mul(n_tris, 12u);
}

uint64_t ms_frame_need(const ms_frame_shape *s, ms_need *need)
{
    ms_need local;
    if (!need) need = &local;
    memset(need, 0, sizeof *need);
    const uint64_t P = (uint64_t)s->W * (uint64_t)s->H, n = s->n_tris, mw8 = (uint64_t)s->mask_words * 8u;
    /* The pixels the frame's planes hold at once: all, or a band's (streamed outputs, frame_stream.c). */
    /* With the interleaved filter a band is kept until two rows of the next are rendered: 2 bands + 2 rows. */
    const uint64_t rows_held = s->band_rows > 0 ? (uint64_t)s->band_rows * (s->filter ? 2u : 1u) + (s->filter ? 2u : 0u) : 0;
    const uint64_t PB = rows_held && rows_held < (uint64_t)s->H ? (uint64_t)s->W * rows_held : P;
    const uint64_t band_px = s->band_rows > 0 && (uint64_t)s->band_rows < (uint64_t)s->H ? (uint64_t)s->W * (uint64_t)s->band_rows : P;
    /* Phase 1 (frame_job.c, before the planes): the materialised scene and the BVH's build. */
    const uint64_t soup = s->materialise ? mul(n, TRI_BYTES) : 0;
    const uint64_t build = s->bvh ? mul(n, BVH_BUILD_PER_TRI) : 0;
    /* Phase 2: what stays (the BVH, per-light method states, the primary's state) and the frame. */
    ms_need_add(need, "procedural triangles materialised", soup);
    ms_need_add(need, "BVH and triangles", s->bvh ? mul(n, BVH_PER_TRI) : 0);
    uint64_t per_light = 0;
    if (s->bvh && s->shallow_per_light) per_light += mul(n, SHALLOW_PER_TRI);
    if (s->bvh && s->hpc_order) per_light += mul(n, HPC_ORDER_PER_TRI);
    ms_need_add(need, "per-light method state", mul(per_light, s->nl));
    ms_need_add(need, "Embree scene", s->embree ? mul(n, EMBREE_PER_TRI) : 0);
    ms_need_add(need, "3dr set-ups", s->primary_3dr_setups ? mul(n, R3_SETUP_PER_TRI) : 0);
    /* frame_job.c: hits, rgb, per light V, S, S_spec (floats) and front (uint16), surfaces, tile flags. */
    const uint64_t frame_pp = sizeof(ms_hit) + 12u + (s->surf ? sizeof(ms_surface) : 0);
    ms_need_add(need, "frame planes", mul(PB, frame_pp) + P / 256u + 1u);
    ms_need_add(need, "per-light planes", mul(mul(PB, 14u), s->nl));
    uint64_t prim_pp = 0;
    if (s->primary_depth) prim_pp += sizeof(ms_hit) + 4u;                           /* primary_depth.c */
    if (s->primary_3dr) prim_pp += 20u + (s->primary_depth ? 0 : s->bvh ? 0 : sizeof(ms_hit));   /* primary_3dr.c */
    ms_need_add(need, "primary visibility", mul(P, prim_pp));
    /* The shadow phase's frame-level buffers (shadow_frame.c: queries, pixel index, front and visible masks)
     * and hpc's receiver hierarchy and mask slots (one light at a time), or the finish's (filter copies, the
     * exposure's luminances, textured lights' mean texels; the PNG writer's 3 bytes after it). */
    uint64_t shadow_pp = 0;
    if (s->whole_frame) {
        const uint64_t slot = (mw8 + (s->scanline_slots ? HPC_RASTER_FRAME : 0) + (uint64_t)s->npk + 1u + 63u) / 64u * 64u;
        shadow_pp = sizeof(ms_shadow_query) + sizeof(size_t) + 1u + 2u * mw8 + HPC_PER_RECEIVER + slot;   /* 1: the merged-face flag */
        /* exact_split.c: the axes (3 masks), the selected, compacted front and visible masks, the compacted
         * query, its index and its scene prim */
        if (s->exact_sets) shadow_pp += 6u * mw8 + sizeof(ms_shadow_query) + sizeof(size_t) + 4u;
    }
    /* frame_shade.c: the luminances and glibc qsort's merge buffer of as many; textured lights' mean texels. */
    uint64_t finish_pp = 8u + (s->textured ? mul(12u, s->nl) : 0);
    if (s->filter && finish_pp < 8u + (s->surf ? 4u : 0)) finish_pp = 8u + (s->surf ? 4u : 0);
    if (s->whole_frame && shadow_pp > finish_pp) ms_need_add(need, "hpc receiver hierarchy and masks", mul(P, shadow_pp));
    else if (s->band_rows > 0) {
        /* A band: its luminances (4), the PNG's scratch records (16) and the band it writes from them (rgb and
         * the miss test, 16), textured lights' mean texels, the filtered V, S, S_spec per light; the writers' buffers (frame_stream.c): an EXR's
         * 16-row block of every channel (at most R, G, B and V, S twice per light over the outputs) as given,
         * packed and compressed, and the exposure's 65536-bucket histogram. */
        /* Anti-aliased, the records and the band written are the resolved band's (band_px / s^2 pixels), which
         * holds rgb and per light V, S, S_spec and front (12 + 14 nl bytes a pixel) besides. */
        const uint64_t as = s->aa_s > 1 ? (uint64_t)s->aa_s : 1u, out_px = band_px / (as * as) + 1u;
        ms_need_add(need, "finishing (filter, exposure)", mul(band_px, 4u + (s->textured ? mul(12u, s->nl) : 0) +
                                                                 (s->filter ? mul(12u, s->nl) : 0)) +
                                                             mul(out_px, 32u + (as > 1 ? 12u + mul(14u, s->nl) : 0)));
        ms_need_add(need, "streamed outputs", mul(mul((uint64_t)s->W / as + 1u, 16u * 4u * 3u), 3u + 4u * (uint64_t)s->nl) + (1u << 20));
    } else
        ms_need_add(need, "finishing (filter, exposure)", mul(P, finish_pp));
    ms_need_add(need, "threads", mul((uint64_t)(s->threads > 0 ? s->threads : 1), PER_THREAD + 512u * mw8) + FIXED);
    /* The lights' occluders stay; the closed components' search, or the last light's build, come on top. */
    if (s->bvh && s->occluders) {
        ms_need_add(need, "per-light occluder BVHs", mul(mul(n, OCCLUDERS_PER_TRI), s->nl));
        ms_need_add(need, "per-light interior boxes", mul(mul(n, INTERIOR_PER_TRI), s->nl));
        /* the sets exact per axis: at most one per axis, each at most every triangle */
        if (s->exact_sets) ms_need_add(need, "per-light occluder sets exact per axis", mul(mul(n, 3u * OCCLUDERS_PER_TRI), s->nl));
        const uint64_t find = closed_find_bytes(n), build_occ = mul(n, 8u + OCCLUDERS_BUILD_PER_TRI);
        ms_need_add(need, "closed components", find > build_occ ? find : build_occ);
    }
    /* The peak is the larger phase: the build's temporaries are freed before the planes exist. */
    const uint64_t phase1 = soup + build + FIXED;
    if (phase1 > need->total) {
        const uint64_t extra = phase1 - need->total;
        ms_need_add(need, "BVH and triangles", extra);
    }
    return need->total;
}

int ms_frame_band_rows(const ms_frame_shape *s, int rows, uint64_t budget)
{
    ms_frame_shape t = *s;
    const int unit = (s->aa_s > 1 ? s->aa_s : 1) * MS_TILE_SIZE;
    for (t.band_rows = rows; t.band_rows > unit; t.band_rows = t.band_rows / 2 / unit * unit)
        if (ms_frame_need(&t, NULL) <= budget) return t.band_rows;
    return unit;
}

/* One line of the parts, largest first: "frame planes 9.0 GiB, per-light planes 3.5 GiB". */
static void parts_text(const ms_need *n, char *buf, size_t len)
{
    int order[MS_NEED_PARTS], m = 0;
    for (int i = 0; i < n->n; i++) order[m++] = i;
    for (int a = 1; a < m; a++)
        for (int b = a; b > 0 && n->bytes[order[b - 1]] < n->bytes[order[b]]; b--) {
            const int t = order[b]; order[b] = order[b - 1]; order[b - 1] = t;
        }
    size_t at = 0;
    buf[0] = 0;
    for (int i = 0; i < m && i < 3 && at < len; i++) {
        char b[32];
        ms_bytes_text(n->bytes[order[i]], b, sizeof b);
        at += (size_t)snprintf(buf + at, len - at, "%s%s %s", i ? ", " : "", n->name[order[i]], b);
    }
}

int ms_frame_budget_check(const ms_frame_shape *s, uint64_t budget, char *err, size_t errlen)
{
    ms_need need;
    const uint64_t total = ms_frame_need(s, &need);
    if (total <= budget) return 0;
    char parts[256], tb[32], bb[32], hints[512];
    parts_text(&need, parts, sizeof parts);
    ms_bytes_text(total, tb, sizeof tb);
    ms_bytes_text(budget, bb, sizeof bb);
    size_t at = 0;
    hints[0] = 0;
    /* A smaller frame at the same aspect: the largest scale whose need fits (the need grows with it). */
    ms_frame_shape t = *s;
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 40; it++) {
        const double m = 0.5 * (lo + hi);
        t.W = (int)(s->W * m) > 0 ? (int)(s->W * m) : 1;
        t.H = (int)(s->H * m) > 0 ? (int)(s->H * m) : 1;
        if (ms_frame_need(&t, NULL) <= budget) lo = m;
        else hi = m;
    }
    t.W = (int)(s->W * lo);
    t.H = (int)(s->H * lo);
    if (t.W >= 1 && t.H >= 1 && ms_frame_need(&t, NULL) <= budget)
        at += (size_t)snprintf(hints + at, sizeof hints - at, "%dx%d would fit", t.W, t.H);
    /* Fewer lights at this size. */
    if (s->nl > 1 && at < sizeof hints) {
        t = *s;
        size_t best = 0;
        for (t.nl = s->nl - 1; t.nl >= 1; t.nl--)
            if (ms_frame_need(&t, NULL) <= budget) { best = t.nl; break; }
        if (best)
            at += (size_t)snprintf(hints + at, sizeof hints - at, "%s%zu of the %zu lights would fit at this size",
                                   at ? "; or " : "", best, s->nl);
    }
    /* A procedural scene streamed by hpc instead of materialised. */
    if (s->materialise && at < sizeof hints) {
        t = *s;
        t.materialise = t.bvh = t.shallow_per_light = t.hpc_order = t.embree = t.primary_3dr = t.primary_3dr_setups = 0;
        t.primary_depth = 1;
        t.whole_frame = 1;
        t.band_rows = t.stream_rows = 0;   /* hpc takes the whole frame */
        t.scanline_slots = 0;
        t.filter = 0;
        char hb[32];
        const uint64_t h = ms_frame_need(&t, NULL);
        ms_bytes_text(h, hb, sizeof hb);
        at += (size_t)snprintf(hints + at, sizeof hints - at, "%s--method hpc streams the procedural triangles (about %s%s)",
                               at ? "; or " : "", hb, h <= budget ? ", which fits" : "");
    }
    /* The outputs written as the rows finish. */
    if (!s->band_rows && s->stream_rows > 0 && at < sizeof hints) {
        t = *s;
        t.band_rows = ms_frame_band_rows(s, s->stream_rows, budget);
        char sb[32];
        const uint64_t h = ms_frame_need(&t, NULL);
        ms_bytes_text(h, sb, sizeof sb);
        if (h <= budget || h <= total / 2)   /* said when it fits or saves much (not for a scene-bound need) */
            at += (size_t)snprintf(hints + at, sizeof hints - at, "%s--stream writes the outputs as the rows finish (about %s%s)",
                                   at ? "; or " : "", sb, h <= budget ? ", which fits" : "");
    }
    if (!hints[0]) snprintf(hints, sizeof hints, "no frame size fits: the scene alone needs more");
    snprintf(err, errlen, "a %dx%d frame%s with %zu light%s and %zu triangles needs about %s (%s) but the memory budget is "
             "%s (--max-memory): %s", s->W, s->H, s->band_rows ? " streamed" : "", s->nl, s->nl == 1 ? "" : "s", s->n_tris, tb,
             parts, bb, hints);
    return MS_ERR_BUDGET;
}

uint64_t ms_bake_need(const ms_bake_shape *s, ms_need *need)
{
    ms_need local;
    if (!need) need = &local;
    memset(need, 0, sizeof *need);
    const uint64_t P = (uint64_t)s->size * (uint64_t)s->size * (uint64_t)(s->pages > 1 ? s->pages : 1), n = s->n_tris, mw8 = (uint64_t)s->mask_words * 8u;
    /* bake.c: per texel position and normal 24, triangle 4, the rasterization's distances 4, rgb 12; per light
     * V, S 8 and front 2; per triangle UVs 24 and a flag. xatlas's meshes and charts: about 400 bytes per
     * triangle unwrapped (its vertex and index copies, chart graphs). */
    ms_need_add(need, "lightmap atlas", mul(P, 44u) + mul(n, 25u));
    ms_need_add(need, "per-light planes", mul(mul(P, 10u), s->nl));
    ms_need_add(need, "xatlas", s->unwrap ? mul(n, 400u) : 0);
    /* ms_bake_rows over every row: each texel's point (position, normal, triangle, key, place: 40), its
     * per-light V, S, front (10) and the points call's Morton order (16). */
    ms_need_add(need, "texel points", mul(P, 56u + 10u * (uint64_t)s->nl));
    if (s->build_accel) ms_need_add(need, "BVH and triangles", ms_accel_need(n));
    /* ms_bake_layout's leak test (bake_leaks.c): a BVH and the closed components, freed before the rows */
    ms_need_add(need, "texel leak test", ms_accel_need(n) + closed_find_bytes(n));
    ms_need_add(need, "per-call triangle copies", s->whole_tri_copy ? mul(n, TRI_BYTES + HPC_ORDER_PER_TRI) : 0);
    ms_need_add(need, "threads", mul((uint64_t)(s->threads > 0 ? s->threads : 1), PER_THREAD + 512u * mw8) + FIXED);
    return need->total;
}

int ms_bake_budget_check(const ms_bake_shape *s, uint64_t budget, char *err, size_t errlen)
{
    ms_need need;
    const uint64_t total = ms_bake_need(s, &need);
    if (total <= budget) return 0;
    char parts[256], tb[32], bb[32], hint[96] = "";
    parts_text(&need, parts, sizeof parts);
    ms_bytes_text(total, tb, sizeof tb);
    ms_bytes_text(budget, bb, sizeof bb);
    ms_bake_shape t = *s;
    int lo = 0, hi = s->size;
    while (lo < hi) {   /* the largest size that fits */
        t.size = (lo + hi + 1) / 2;
        if (ms_bake_need(&t, NULL) <= budget) lo = t.size;
        else hi = t.size - 1;
    }
    if (lo >= 1) snprintf(hint, sizeof hint, "--size %d would fit", lo);
    else snprintf(hint, sizeof hint, "no lightmap size fits: the scene alone needs more");
    char pg[32] = "";
    if (s->pages > 1) snprintf(pg, sizeof pg, " (%d pages)", s->pages);
    snprintf(err, errlen, "a %dx%d lightmap%s with %zu light%s and %zu triangles needs about %s (%s) but the memory budget "
             "is %s (--max-memory): %s", s->size, s->size, pg, s->nl, s->nl == 1 ? "" : "s", s->n_tris, tb, parts, bb, hint);
    return MS_ERR_BUDGET;
}

uint64_t ms_points_need(size_t n, size_t n_tris, int whole_tri_copy, int mask_words, int threads, ms_need *need)
{
    ms_need local;
    if (!need) need = &local;
    memset(need, 0, sizeof *need);
    /* points.c: the Morton order (16 per point); hpc's scene-order copy and its order per call; per thread
     * two batches of masks and queries. */
    ms_need_add(need, "point order", mul(n, 16u));
    ms_need_add(need, "per-call triangle copies", whole_tri_copy ? mul(n_tris, TRI_BYTES + HPC_ORDER_PER_TRI) : 0);
    ms_need_add(need, "threads", mul((uint64_t)(threads > 0 ? threads : 1), PER_THREAD + 512u * 8u * (uint64_t)mask_words) + FIXED);
    return need->total;
}

uint64_t ms_culled_sets_need(size_t n_tris, size_t held, int build)
{
    /* Each held set: a BVH over at most every triangle with its map, and its interior boxes; a build on top: the
     * scene-order copy it culls from and the build's temporaries. */
    return mul(mul(n_tris, OCCLUDERS_PER_TRI + INTERIOR_PER_TRI), held + (build ? 1u : 0u))
           + (build ? mul(n_tris, OCCLUDERS_BUILD_PER_TRI + TRI_BYTES) : 0);
}

int ms_points_budget_check(size_t n, size_t n_tris, int whole_tri_copy, int mask_words, int threads, uint64_t budget,
                           char *err, size_t errlen)
{
    ms_need need;
    const uint64_t total = ms_points_need(n, n_tris, whole_tri_copy, mask_words, threads, &need);
    if (total <= budget) return 0;
    char parts[256], tb[32], bb[32], hint[96];
    parts_text(&need, parts, sizeof parts);
    ms_bytes_text(total, tb, sizeof tb);
    ms_bytes_text(budget, bb, sizeof bb);
    const uint64_t fixed = ms_points_need(0, n_tris, whole_tri_copy, mask_words, threads, NULL);
    if (fixed < budget) snprintf(hint, sizeof hint, "at most %llu points per call would fit",
                                 (unsigned long long)((budget - fixed) / 16u));
    else snprintf(hint, sizeof hint, "no number of points fits with this method");
    snprintf(err, errlen, "%zu points need about %s (%s) but the memory budget is %s (max_memory): %s", n, tb, parts, bb,
             hint);
    return MS_ERR_BUDGET;
}
