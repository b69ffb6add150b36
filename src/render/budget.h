/* Memory budgets (#24, docs/memory.md): what a frame, a bake or a points call will allocate, estimated from
 * the sizes it is given before anything is allocated, and checked against the caller's max_memory. The
 * estimates are sums of named parts (the refusal names the largest), each an upper bound of what the code
 * allocates for it: sizes of the structs themselves where the render layer sees them, else the byte counts
 * of the allocation sites they stand for (noted beside each constant in budget.c). */
#ifndef MS_RENDER_BUDGET_H
#define MS_RENDER_BUDGET_H
#include "microshadow.h"
#include <stddef.h>
#include <stdint.h>

#define MS_NEED_PARTS 16

typedef struct ms_need {
    const char *name[MS_NEED_PARTS];
    uint64_t bytes[MS_NEED_PARTS];
    int n;
    uint64_t total;
} ms_need;

/* Adds a part (saturating: an absurd size stays absurd instead of wrapping to small). */
void ms_need_add(ms_need *n, const char *name, uint64_t bytes);

/* Three significant digits: "15.0 GiB", "640 KiB", "12 B". */
void ms_bytes_text(uint64_t b, char *buf, size_t len);

/* What a frame needs, from what ms_frame_job_create knows before it allocates. */
typedef struct ms_frame_shape {
    int W, H;
    size_t nl;              /* lights */
    size_t n_tris;
    int materialise;        /* a procedural scene materialised for a method that does not stream */
    int bvh;                /* a BVH is built (every scene but a streamed one) */
    int surf;               /* per-pixel surfaces (materials or normals) */
    int mask_words;         /* 64-bit words of one sample mask */
    int npk;                /* 16-sample packets per mask (hpc's slots) */
    int whole_frame;        /* the shadow method takes the whole frame at once (hpc, hpc-scanline) */
    int scanline_slots;     /* hpc-scanline: its mask slots also hold a raster frame */
    int shallow_per_light;  /* block traversal (micro-raster methods, mft): a shallow BVH per light */
    int hpc_order;          /* hpc on a triangle soup: its area order and leaf map */
    int embree;             /* Embree's own scene (shadow method or primary) */
    int primary_depth;      /* the depth primary: its own hits and depths per pixel */
    int primary_3dr;        /* a 3dr-* primary: per-pixel rays and depths (and hits when streamed) */
    int primary_3dr_setups; /* 3dr-* on a triangle soup: one set-up per triangle */
    int filter;             /* the interleaved pattern's filter runs in finish */
    int textured;           /* some light is textured (finish keeps a mean texel per light and pixel) */
    int occluders;          /* per-light occluders (visibility/occluders.h): closed components, culled BVHs */
    int exact_sets;         /* with them, the sets exact per shear axis (for_axis, MS_OCC_MERGE_EXACT): up to 3 more
                             * per light, and the exact split's per-receiver scratch (render/exact_split.c) */
    int threads;
    /* Streamed outputs (frame_stream.c): the planes hold band_rows rows at a time (0: the whole frame); when the
     * frame is not streamed, stream_rows is what a streamed one would hold (0: it cannot be streamed), for the
     * hint. */
    int band_rows, stream_rows;
    int aa_s;               /* anti-aliasing: W, H are s times the output's (0 or 1: none); a band is resolved
                             * into output rows before it is written, and holds a multiple of s tiles' rows */
} ms_frame_shape;

/* Streamed: the largest band of rows (rows, then halves of it, each a multiple of MS_TILE_SIZE times the
 * anti-aliasing scale aa_s) whose frame fits budget, or the smallest such band when none does. */
int ms_frame_band_rows(const ms_frame_shape *s, int rows, uint64_t budget);

/* The frame's estimated peak in bytes, its parts into need (may be NULL). */
uint64_t ms_frame_need(const ms_frame_shape *s, ms_need *need);

/* 0 when the frame fits the budget; else MS_ERR_BUDGET and one line: "a WxH frame (...) needs about X (parts)
 * but the memory budget is B (--max-memory): hints", the hints saying what would fit (a smaller size at the
 * same aspect, fewer lights, --method hpc to stream a procedural scene, --stream to write the outputs as
 * the rows finish). */
int ms_frame_budget_check(const ms_frame_shape *s, uint64_t budget, char *err, size_t errlen);

/* A lightmap bake: size x size texels, nl lights, the scene's triangles, whether the BVH is built here. */
typedef struct ms_bake_shape {
    int size;
    size_t nl, n_tris;
    int build_accel;        /* ms_bake without an accel: it builds one */
    int unwrap;             /* xatlas unwraps some triangles */
    int mask_words;
    int threads;
    int whole_tri_copy;     /* the method reads the triangles in scene order (hpc): a copy per points call */
    int pages;              /* lightmap pages of size x size (0: 1) */
} ms_bake_shape;
uint64_t ms_bake_need(const ms_bake_shape *s, ms_need *need);
int ms_bake_budget_check(const ms_bake_shape *s, uint64_t budget, char *err, size_t errlen);

/* A points call: n points, the method's per-call copies. */
uint64_t ms_points_need(size_t n, size_t n_tris, int whole_tri_copy, int mask_words, int threads, ms_need *need);
int ms_points_budget_check(size_t n, size_t n_tris, int whole_tri_copy, int mask_words, int threads, uint64_t budget,
                           char *err, size_t errlen);

/* The points calls' occluder sets with the closed-component cull kept in an accel (points.c): `held` of them
 * over n_tris triangles, and one more being built when `build`. */
uint64_t ms_culled_sets_need(size_t n_tris, size_t held, int build);

/* ms_accel_build over n triangles at its peak: the BVH's build, or the closed components' search after it. */
uint64_t ms_accel_need(size_t n_tris);

#endif
