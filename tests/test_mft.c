/* Method mft (multi-frusta tracing, Benthin & Wald 2009) against the reference ray tracer on identical
 * samples: mft decides every ray by raytrace's own watertight test and only culls what cannot be hit,
 * so V and S must equal raytrace's bit for bit (grid and stratified, 256 and 1024 samples) on the Quad,
 * the built-in scene and real scenes; its scalar, AVX2 and AVX-512 instances give the same masks and
 * the same counters; its switches (frustum shrinking, child order) change no mask; its counters
 * account for every triangle-frustum pair. */
#include "testutil.h"
#include "shadow/method.h"
#include "shadow/raytrace/raytrace.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "accel/bvh.h"
#include "accel/ray_triangle.h"
#include "light/pattern.h"
#include "light/light_frame.h"
#include "shadow/microraster/block_traverse.h"
#include "shadow/mft/mft.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void render_ok(const ms_scene *sc, const char *method, ms_pattern pat, int samples, int size, ms_frame *f)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.pattern = pat;
    o.samples = samples;
    o.width = o.height = size;
    tu_render_ok(sc, &o, f);
}

/* mft equals raytrace, V and S, at every pixel, for the three patterns (interleaved: filtered, so the
 * raw per-pixel values equal too) and the given sample counts. */
static void equal_on_scene(const ms_scene *sc, const char *label, const int *samples, int n_samples, int size)
{
    static const ms_pattern pats[] = { MS_PATTERN_GRID, MS_PATTERN_STRATIFIED, MS_PATTERN_INTERLEAVED };
    for (int p = 0; p < 3; p++)
        for (int s = 0; s < n_samples; s++) {
            ms_frame ref, f;
            render_ok(sc, "raytrace", pats[p], samples[s], size, &ref);
            render_ok(sc, "mft", pats[p], samples[s], size, &f);
            const tu_agreement a = tu_compare_frames(&f, &ref);
            printf("%-26s %-10s N=%-4d mft vs raytrace: %ld of %ld pixels differ (V), %ld (S only); %llu shadow rays\n",
                   label, pats[p] == MS_PATTERN_GRID ? "grid" : pats[p] == MS_PATTERN_STRATIFIED ? "stratified" : "interleaved",
                   samples[s], a.differ, a.pixels,
                   a.s_differ_same_v, (unsigned long long)f.stats.shadow_rays);
            assert_int_equal(a.miss_mismatch, 0);
            assert_int_equal(a.differ, 0);
            const size_t n = (size_t)size * (size_t)size;
            assert_memory_equal(f.vis, ref.vis, n * sizeof *f.vis);
            assert_memory_equal(f.shadow, ref.shadow, n * sizeof *f.shadow);
            assert_string_equal(f.stats.method, "mft");
            ms_frame_free(&f);
            ms_frame_free(&ref);
        }
}

/* Stratified 16 and 64 samples (k = 4, 8: a 16-ray packet is 4 or 2 whole rows): mft once tested no ray
 * there and answered the front mask. Built-in scene, frames equal raytrace's bit for bit. */
static void test_stratified_few_samples(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    for (int samples = 16; samples <= 64; samples *= 4) {
        ms_frame ref, f;
        render_ok(&sc, "raytrace", MS_PATTERN_STRATIFIED, samples, 96, &ref);
        render_ok(&sc, "mft", MS_PATTERN_STRATIFIED, samples, 96, &f);
        long partial = 0;
        for (size_t i = 0; i < 96 * 96; i++) partial += ref.vis[i] > 0.0f && ref.vis[i] < 1.0f;
        printf("built-in stratified N=%d: %ld penumbra pixels, mft %llu 16-ray tests\n", samples, partial,
               (unsigned long long)f.stats.counter[13]);
        assert_true(partial > 100);
        assert_memory_equal(f.vis, ref.vis, 96 * 96 * sizeof *f.vis);
        assert_memory_equal(f.shadow, ref.shadow, 96 * 96 * sizeof *f.shadow);
        ms_frame_free(&f);
        ms_frame_free(&ref);
    }
    ms_scene_free(&sc);
}

static void test_quad_equals_raytrace(void **state)
{
    (void)state;
    ms_scene sc;
    tu_make_quad(&sc);
    const int samples[] = { 256, 1024 };
    equal_on_scene(&sc, "quad", samples, 2, 64);
    ms_scene_free(&sc);
}

static void test_default_scene_equals_raytrace(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    const int samples[] = { 256, 1024 };
    equal_on_scene(&sc, "default", samples, 2, 64);
    ms_scene_free(&sc);
}

/* Tiny occluders under a big light (grid pattern): each triangle's footprint on the light is a fraction of a
 * cell, so mft keeps, row by row, only the columns whose sample (the grid's position inside its cell, per
 * pixel: mft_grid_cols) lies in the footprint's box, and drops the pairs with none. A wrong position (the
 * pixel's shift misread, another lane's, u for v) loses hits: V and S must still equal raytrace's bit for bit
 * at k = 16, 32 and 64, with many penumbra pixels. */
static void test_tiny_occluders_grid_cut(void **state)
{
    (void)state;
    enum { NT = 3000 };
    ms_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.tri = malloc((size_t)(NT + 2) * 9 * sizeof *sc.tri);
    assert_non_null(sc.tri);
    static const float ground[18] = { -10, 0, -10, 10, 0, 10, 10, 0, -10, -10, 0, -10, -10, 0, 10, 10, 0, 10 };
    memcpy(sc.tri, ground, sizeof ground);
    uint32_t h = 12345u;
#define TU_RND() ((h = h * 1664525u + 1013904223u), (float)(h >> 8) * (1.0f / 16777216.0f))
    for (int i = 0; i < NT; i++) {
        const float cx = -3.0f + 6.0f * TU_RND(), cy = 0.5f + 3.0f * TU_RND(), cz = -3.0f + 6.0f * TU_RND();
        const float size = 0.01f + 0.04f * TU_RND();
        float *t = sc.tri + 9 * (size_t)(i + 2);
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) t[3 * v + a] = (a == 0 ? cx : a == 1 ? cy : cz) + size * (2.0f * TU_RND() - 1.0f);
    }
#undef TU_RND
    sc.n_tris = NT + 2;
    sc.camera = (ms_camera){ { 0, 9, 7 }, { 0, 0, 0 }, { 0, 1, 0 }, 50.0f, 48, 48, MS_CAMERA_PINHOLE, 0, 0 };
    sc.light = (ms_light){ { -4, 6, -4 }, { 8, 0, 0 }, { 0, 0, 8 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    sc.samples = 1024;
    for (int samples = 256; samples <= 4096; samples *= 4) {
        ms_frame ref, f;
        render_ok(&sc, "raytrace", MS_PATTERN_GRID, samples, 48, &ref);
        render_ok(&sc, "mft", MS_PATTERN_GRID, samples, 48, &f);
        long partial = 0;
        for (size_t i = 0; i < 48 * 48; i++) partial += ref.vis[i] > 0.0f && ref.vis[i] < 1.0f;
        const tu_agreement a = tu_compare_frames(&f, &ref);
        printf("tiny occluders, big light, grid N=%d: %ld penumbra pixels, mft vs raytrace: %ld pixels differ (V)\n",
               samples, partial, a.differ);
        assert_true(partial > 1000);
        assert_memory_equal(f.vis, ref.vis, 48 * 48 * sizeof *f.vis);
        assert_memory_equal(f.shadow, ref.shadow, 48 * 48 * sizeof *f.shadow);
        ms_frame_free(&f);
        ms_frame_free(&ref);
    }
    ms_scene_free(&sc);
}

static void real_scene(const char *rel, int size)
{
    ms_scene sc;
    tu_shared_scene_load(rel, &sc);
    const int samples[] = { 1024 };
    equal_on_scene(&sc, rel, samples, 1, size);
    ms_scene_free(&sc);
}

/* The big light: wide frusta, large occluders reaching behind the receivers (the footprint's clipping). */
static void test_sponza_biglight_equals(void **state) { (void)state; real_scene("dabrovic-sponza/dabrovic-sponza-biglight.json", 48); }
/* Small triangles: many partly occluded frusta (early termination, CR). */
static void test_bunny_equals(void **state) { (void)state; real_scene("stanford-bunny/stanford-bunny.json", 48); }

/* A grazing sliver (found at 1024^2 on Sponza's big light, pixel (634, 161), 1024 samples): triangle 58724
 * lies 3e-5 above the plane of its neighbour 58725, the receiver, so its rays graze it; raytrace's
 * watertight test finds sample 533 blocked although the exact segment passes 2.5e-4 outside the triangle
 * (rational arithmetic). mft must give raytrace's answer, so its footprint culling must not drop the
 * triangle there (it did, by one sample). The 16 pixels of that block through the method's interface,
 * each against the reference tracer. */
static void test_grazing_sliver_block(void **state)
{
    (void)state;
    if (!tu_have_shared_scenes()) skip();
    char path[4096], err[512];
    ms_scene sc;
    assert_int_equal(ms_scene_load(tu_shared_scene(path, sizeof path, "dabrovic-sponza/dabrovic-sponza-biglight.json"),
                                   &sc, err, sizeof err), 0);
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 1), 0);
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, &sc, &bvh, 1024, 1024, 32);
    ctx.threads = 1;
    const ms_primary_method *pm = ms_find_primary_method("bvh");
    const ms_shadow_method *sm = ms_find_shadow_method("mft");
    void *ps = NULL, *ss = NULL;
    assert_int_equal(pm->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit hits[16];
    pm->trace(ps, &ctx, 632, 160, 636, 164, hits);
    pm->destroy(ps);
    ms_shadow_query q[16];
    int nq = 0;
    for (int i = 0; i < 16; i++)
        if (hits[i].prim != UINT32_MAX) tu_query_from_hit(&q[nq++], &hits[i], 632 + i % 4, 160 + i / 4);
    assert_true(nq > 0);
    const size_t mw = (size_t)ctx.mask_words;
    uint64_t front[16 * 16] = { 0 }, vis[16 * 16] = { 0 }, ref[16] = { 0 }, cnt[MS_MAX_COUNTERS] = { 0 };
    float *pts = malloc((size_t)ctx.samples * 3 * sizeof *pts);
    assert_non_null(pts);
    for (int i = 0; i < nq; i++) ms_front_mask(&ctx, &q[i], NULL, front + (size_t)i * mw);
    for (int cap = MS_ISA_SCALAR; cap <= MS_ISA_AVX512; cap++) {
        if (!tu_isa_allowed((ms_isa)cap) || cap > (int)ms_cpu_isa()) continue;
        ctx.isa_cap = (ms_isa)cap;
        assert_int_equal(sm->create(&ctx, &ss, err, sizeof err), 0);
        memset(vis, 0, sizeof vis);
        assert_int_equal(sm->visibility(ss, &ctx, q, nq, front, vis, cnt), 0);
        sm->destroy(ss);
        int differ = 0;
        for (int i = 0; i < nq; i++) {
            ms_raytrace_visible_samples(&ctx, &q[i], pts, front + (size_t)i * mw, ref, cnt);
            differ += memcmp(ref, vis + (size_t)i * mw, mw * sizeof *ref) != 0;
        }
        printf("grazing sliver block, %s: %d of %d pixels differ from raytrace\n", ms_isa_name((ms_isa)cap), differ, nq);
        assert_int_equal(differ, 0);
    }
    free(pts);
    ms_bvh_free(&bvh);
    ms_scene_free(&sc);
}

/* The masks and counters of mft on a size x size view of sc, through the method's interface, under an
 * ISA cap and the given switches. Caller frees the masks. */
static uint64_t *mft_masks_ex(const ms_scene *sc, ms_pattern pat, int k, int size, ms_isa cap, int fs, int no_order,
                              int in_order, uint64_t cnt[MS_MAX_COUNTERS], ms_isa *isa, int *n_out, int *mw_out,
                              uint64_t **ref_out)
{
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc->tri, sc->n_tris, 1), 0);
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, sc, &bvh, size, size, k);
    ctx.isa_cap = cap;
    tu_ctx_set_pattern(&ctx, pat);
    ctx.queries_in_order = in_order;
    ctx.frustum_shrink = fs;
    ctx.no_child_order = no_order;
    const ms_shadow_method *sm = ms_find_shadow_method("mft");
    assert_non_null(sm);
    assert_int_equal(sm->needs_grid, 0);
    char err[256];
    void *ss = NULL;
    int nq;
    ms_shadow_query *q = tu_frame_queries(&ctx, size, &nq);
    const size_t mw = (size_t)ctx.mask_words;
    uint64_t *front = calloc((size_t)nq * mw + 1, sizeof *front), *vis = calloc((size_t)nq * mw + 1, sizeof *vis);
    assert_non_null(front);
    assert_non_null(vis);
    float *pts = malloc((size_t)ctx.samples * 3 * sizeof *pts);
    assert_non_null(pts);
    for (int i = 0; i < nq; i++) {
        ms_pattern_points(pat, &ctx.light, k, q[i].px, q[i].py, ctx.seed, pts);
        ms_front_mask(&ctx, &q[i], pat == MS_PATTERN_GRID ? NULL : pts, front + i * mw);
    }
    free(pts);
    assert_int_equal(sm->create(&ctx, &ss, err, sizeof err), 0);
    ms_isa trav;
    sm->isa_used(ss, isa, &trav);
    memset(cnt, 0, MS_MAX_COUNTERS * sizeof *cnt);
    assert_int_equal(sm->visibility(ss, &ctx, q, nq, front, vis, cnt), 0);
    sm->destroy(ss);
    if (ref_out) {
        /* The reference tracer's masks for the same queries, samples and front masks. */
        uint64_t *ref = calloc((size_t)nq * mw + 1, sizeof *ref), rc[MS_MAX_COUNTERS] = { 0 };
        float *rp = malloc((size_t)ctx.samples * 3 * sizeof *rp);
        assert_non_null(ref);
        assert_non_null(rp);
        for (int i = 0; i < nq; i++) ms_raytrace_visible_samples(&ctx, &q[i], rp, front + i * mw, ref + i * mw, rc);
        free(rp);
        *ref_out = ref;
    }
    if (mw_out) *mw_out = (int)mw;
    free(front);
    free(q);
    ms_bvh_free(&bvh);
    *n_out = nq;
    return vis;
}

static uint64_t *mft_masks(const ms_scene *sc, ms_pattern pat, int k, int size, ms_isa cap, int fs, int no_order,
                           uint64_t cnt[MS_MAX_COUNTERS], ms_isa *isa, int *n_out)
{
    return mft_masks_ex(sc, pat, k, size, cap, fs, no_order, 0, cnt, isa, n_out, NULL, NULL);
}

/* The interleaved mode's two ways of forming a block's ray groups (mft.c): by set (a frame's 4x4 blocks:
 * 16 distinct sets) and the general one (queries in proximity order, the points API: 16 consecutive
 * queries of a row share sets). Both give raytrace's masks, query for query; the ISA instances give the
 * same masks and counters. */
static void test_interleaved_group_paths(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    for (int in_order = 0; in_order <= 1; in_order++)
        for (int k = 16; k <= 32; k *= 2) {
            uint64_t c0[MS_MAX_COUNTERS], *ref = NULL;
            ms_isa isa0;
            int n0, mw;
            uint64_t *got = mft_masks_ex(&sc, MS_PATTERN_INTERLEAVED, k, 48, MS_ISA_SCALAR, 0, 0, in_order, c0, &isa0, &n0,
                                         &mw, &ref);
            long differ = 0, partial = 0;
            for (int i = 0; i < n0; i++) {
                differ += memcmp(got + (size_t)i * mw, ref + (size_t)i * mw, (size_t)mw * sizeof *got) != 0;
                int nv = 0;
                for (int w = 0; w < mw; w++) nv += __builtin_popcountll(ref[(size_t)i * mw + w]);
                partial += nv > 0 && nv < k * k / 16;
            }
            printf("interleaved N=%d, %s: %ld of %d queries differ from raytrace (%ld partly lit), %llu groups, %llu 16-ray tests\n",
                   k * k, in_order ? "queries in order (general grouping)" : "4x4 blocks (by set)", differ, n0, partial,
                   (unsigned long long)c0[MS_MFT_FRUSTA], (unsigned long long)c0[MS_MFT_ISEC16]);
            assert_true(partial > 20);
            assert_int_equal(differ, 0);
            assert_int_equal(c0[MS_MFT_PAIRS], c0[MS_MFT_CULLED_BOX] + c0[MS_MFT_CULLED_PLANE] + c0[MS_MFT_PAIRS_TESTED]);
            assert_true(c0[MS_MFT_ISEC16] <= c0[MS_MFT_PAIRS_TESTED]);
            assert_true(c0[MS_MFT_FRUSTA] <= 16 * c0[MS_BT_BLOCKS] + 16);
            for (int cap = MS_ISA_AVX2; cap <= MS_ISA_AVX512; cap++) {
                if (!tu_isa_allowed((ms_isa)cap) || cap > (int)ms_cpu_isa()) continue;
                uint64_t c1[MS_MAX_COUNTERS];
                ms_isa isa1;
                int n1;
                uint64_t *g1 = mft_masks_ex(&sc, MS_PATTERN_INTERLEAVED, k, 48, (ms_isa)cap, 0, 0, in_order, c1, &isa1, &n1,
                                            NULL, NULL);
                assert_int_equal(n1, n0);
                assert_memory_equal(got, g1, (size_t)n0 * mw * sizeof *got);
                assert_memory_equal(c0, c1, sizeof c0);
                free(g1);
            }
            free(got);
            free(ref);
        }
    ms_scene_free(&sc);
}

/* mft's masks for the nq queries q (front masks `front`) on every ISA instance this machine and the test's cap
 * allow, each equal to raytrace's `ref` query for query; `got` is scratch of nq * mask_words words. */
static void mft_equals_raytrace_every_isa(ms_render_ctx *ctx, const ms_shadow_query *q, int nq, const uint64_t *front,
                                          const uint64_t *ref, uint64_t *got, const char *what)
{
    const size_t mw = (size_t)ctx->mask_words;
    const ms_shadow_method *sm = ms_find_shadow_method("mft");
    assert_non_null(sm);
    for (int cap = MS_ISA_SCALAR; cap <= MS_ISA_AVX512; cap++) {
        if (!tu_isa_allowed((ms_isa)cap) || cap > (int)ms_cpu_isa()) continue;
        ctx->isa_cap = (ms_isa)cap;
        char err[256];
        void *ss = NULL;
        assert_int_equal(sm->create(ctx, &ss, err, sizeof err), 0);
        uint64_t cnt[MS_MAX_COUNTERS] = { 0 };
        assert_int_equal(sm->visibility(ss, ctx, q, nq, front, got, cnt), 0);
        sm->destroy(ss);
        int differ = 0;
        for (int i = 0; i < nq; i++) differ += memcmp(got + (size_t)i * mw, ref + (size_t)i * mw, mw * sizeof *got) != 0;
        if (differ) fail_msg("%s, ISA cap %d: %d of %d queries differ from raytrace", what, cap, differ, nq);
    }
}

/* Blocks whose 16 receivers are scattered over the scene (random points and normals low among its
 * occluders): in one
 * ray group (a cell of the light, one ray per pixel) the slots then have different shear axes, some are
 * tested alone, some slots are absent (no sample in front) or partly live. The group tracer must still
 * give each ray its own pixel's axis, shear, origin and sample (mft_group_impl.h: the slot's axes found
 * once per block at 256 samples, the groups' first boxes from their cells): raytrace's masks, query for
 * query, on every instance. */
static void test_interleaved_scattered_blocks(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 1), 0);
    enum { BLOCKS = 96, NQ = 16 * BLOCKS };
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, &sc, &bvh, 64, 64, 16);
    tu_ctx_set_pattern(&ctx, MS_PATTERN_INTERLEAVED);
    const size_t mw = (size_t)ctx.mask_words;
    ms_shadow_query *q = malloc(NQ * sizeof *q);
    uint64_t *front = calloc(NQ * mw, sizeof *front), *ref = calloc(NQ * mw, sizeof *ref);
    float *pts = malloc((size_t)ctx.samples * 3 * sizeof *pts);
    assert_non_null(q); assert_non_null(front); assert_non_null(ref); assert_non_null(pts);
    tu_rng rng = { 2026 };
    const float *lo = bvh.nodes[0].bmin, *hi = bvh.nodes[0].bmax;
    int mixed = 0, partial = 0, blocked = 0;
    uint64_t rc[MS_MAX_COUNTERS] = { 0 };
    for (int b = 0; b < BLOCKS; b++) {
        int axes = 0;
        for (int s = 0; s < 16; s++) {
            ms_shadow_query *Q = &q[16 * b + s];
            float len = 0.0f;
            for (int a = 0; a < 3; a++) {
                /* low over the ground (y up): even slots among the occluders, odd ones anywhere out to three
                 * times the scene's width (their rays' largest axis horizontal, and more than twice the
                 * vertical for the farthest: the light's own axis y no longer serves, ms_wt_packet_axis) */
                const float u = (float)(tu_rng_next(&rng) % 10000) / 10000.0f;
                Q->p[a] = lo[a] + (hi[a] - lo[a]) * (a == 1 ? 0.15f * u : s & 1 ? 6.0f * u - 2.5f : 0.3f + 0.4f * u);
                Q->n[a] = (float)(tu_rng_next(&rng) % 2001) / 1000.0f - 1.0f;
                len += Q->n[a] * Q->n[a];
            }
            len = len > 0.0f ? 1.0f / sqrtf(len) : 0.0f;
            for (int a = 0; a < 3; a++) Q->n[a] = len > 0.0f ? Q->n[a] * len : (a == 1 ? 1.0f : 0.0f);
            Q->prim = UINT32_MAX;
            Q->px = (uint32_t)(4 * (b % 8) + (s & 3));   /* block b, slot s: the 16 sets */
            Q->py = (uint32_t)(4 * (b / 8) + (s >> 2));
            ms_pattern_points(MS_PATTERN_INTERLEAVED, &ctx.light, ctx.k, Q->px, Q->py, ctx.seed, pts);
            ms_front_mask(&ctx, Q, pts, front + (size_t)(16 * b + s) * mw);
            ms_raytrace_visible_samples(&ctx, Q, pts, front + (size_t)(16 * b + s) * mw, ref + (size_t)(16 * b + s) * mw, rc);
            float dx[16], dy[16], dz[16];
            for (int j = 0; j < 16; j++) {
                dx[j] = pts[3 * j] - Q->p[0]; dy[j] = pts[3 * j + 1] - Q->p[1]; dz[j] = pts[3 * j + 2] - Q->p[2];
            }
            const int kz = ms_wt_packet_axis(dx, dy, dz, 16, ms_light_shear_axis(&ctx.light), NULL);
            if (front[(size_t)(16 * b + s) * mw]) axes |= 1 << (kz + 1);
            const int nf = __builtin_popcountll(front[(size_t)(16 * b + s) * mw]);
            const int nv = __builtin_popcountll(ref[(size_t)(16 * b + s) * mw]);
            partial += nv > 0 && nv < nf;
            blocked += nv < nf;
        }
        mixed += __builtin_popcount((unsigned)axes) > 1;
    }
    printf("scattered interleaved blocks: %d of %d with slots of different shear axes; of %d queries %d with a "
           "blocked ray, %d partly lit\n", mixed, BLOCKS, NQ, blocked, partial);
    assert_true(mixed > BLOCKS / 2);
    assert_true(blocked > NQ / 20);
    assert_true(partial > 10);
    uint64_t *got = calloc(NQ * mw, sizeof *got);
    assert_non_null(got);
    mft_equals_raytrace_every_isa(&ctx, q, NQ, front, ref, got, "scattered blocks");
    free(got); free(q); free(front); free(ref); free(pts);
    ms_bvh_free(&bvh);
    ms_scene_free(&sc);
}

/* One tiny occluder on each of half the rays of the interleaved blocks (a triangle 1/500 of the segment
 * across, at a random point along it, square to it): every blocked ray is blocked by its own triangle only,
 * so a ray that any cull of the group tracer drops wrongly (a lane's frustum from another cell's box, a
 * frustum test skipped or ordered wrongly, a box test on the wrong receiver, a slot's shear axis or live
 * bit misread) shows as a visible sample where raytrace finds it blocked. Receivers tilted up to 63 degrees
 * (partial front masks), 256 and 1024 samples (the two ways of forming the rays), every instance. */
static void test_interleaved_ray_occluders(void **state)
{
    (void)state;
    enum { BLOCKS = 12, NQ = 16 * BLOCKS };
    for (int k = 16; k <= 32; k *= 2) {
        ms_scene sc;
        memset(&sc, 0, sizeof sc);
        sc.light = (ms_light){ { -3, 5, -3 }, { 6, 0, 0 }, { 0, 0, 6 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
        sc.camera = (ms_camera){ { 0, 9, 7 }, { 0, 0, 0 }, { 0, 1, 0 }, 50.0f, 32, 32, MS_CAMERA_PINHOLE, 0, 0 };
        ms_render_ctx ctx;
        tu_ctx_init(&ctx, &sc, NULL, 32, 32, k);
        tu_ctx_set_pattern(&ctx, MS_PATTERN_INTERLEAVED);
        const size_t mw = (size_t)ctx.mask_words;
        const int n = ctx.samples;   /* a pixel's points: N / 16 */
        ms_shadow_query *q = calloc(NQ, sizeof *q);
        uint64_t *front = calloc(NQ * mw, sizeof *front), *ref = calloc(NQ * mw, sizeof *ref), *got = calloc(NQ * mw, sizeof *got);
        float *pts = malloc((size_t)NQ * n * 3 * sizeof *pts);
        sc.tri = malloc((size_t)NQ * n * 9 * sizeof *sc.tri);
        assert_non_null(q); assert_non_null(front); assert_non_null(ref); assert_non_null(got); assert_non_null(pts);
        assert_non_null(sc.tri);
        tu_rng rng = { 77 };
#define RND() ((float)(tu_rng_next(&rng) % 100000) / 100000.0f)
        int nt = 0, front_rays = 0;
        for (int b = 0; b < BLOCKS; b++) {
            const float bx = -2.5f + 5.0f * RND(), bz = -2.5f + 5.0f * RND();
            for (int s = 0; s < 16; s++) {
                ms_shadow_query *Q = &q[16 * b + s];
                const float tx = 4.0f * RND() - 2.0f, tz = 4.0f * RND() - 2.0f, len = sqrtf(tx * tx + 1.0f + tz * tz);
                Q->p[0] = bx + 0.05f * (float)(s & 3);
                Q->p[1] = 0.0f;
                Q->p[2] = bz + 0.05f * (float)(s >> 2);
                Q->n[0] = tx / len; Q->n[1] = 1.0f / len; Q->n[2] = tz / len;
                Q->prim = UINT32_MAX;
                Q->px = (uint32_t)(4 * (b % 8) + (s & 3));
                Q->py = (uint32_t)(4 * (b / 8) + (s >> 2));
                float *P = pts + (size_t)(16 * b + s) * n * 3;
                ms_pattern_points(MS_PATTERN_INTERLEAVED, &ctx.light, ctx.k, Q->px, Q->py, ctx.seed, P);
                uint64_t *F = front + (size_t)(16 * b + s) * mw;
                ms_front_mask(&ctx, Q, P, F);
                for (int j = 0; j < n; j++) {
                    if (!(F[j >> 6] >> (j & 63) & 1)) continue;
                    front_rays++;
                    if (tu_rng_next(&rng) & 1) continue;
                    float d[3], u[3], v[3], m[3];
                    for (int a = 0; a < 3; a++) d[a] = P[3 * j + a] - Q->p[a];
                    const float t = 0.2f + 0.6f * RND(), dl = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    /* u, v: square to d (d is never along x: the light is above) */
                    u[0] = 0.0f; u[1] = d[2]; u[2] = -d[1];
                    v[0] = d[1] * u[2] - d[2] * u[1]; v[1] = d[2] * u[0] - d[0] * u[2]; v[2] = d[0] * u[1] - d[1] * u[0];
                    const float ul = sqrtf(u[1] * u[1] + u[2] * u[2]), vl = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                    const float e = 0.002f * dl;
                    float *T = sc.tri + 9 * (size_t)nt++;
                    for (int a = 0; a < 3; a++) {
                        m[a] = Q->p[a] + t * d[a];
                        T[a] = m[a] + e * u[a] / ul;
                        T[3 + a] = m[a] - 0.5f * e * u[a] / ul + 0.87f * e * v[a] / vl;
                        T[6 + a] = m[a] - 0.5f * e * u[a] / ul - 0.87f * e * v[a] / vl;
                    }
                }
            }
        }
#undef RND
        sc.n_tris = nt;
        ms_bvh bvh;
        assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 1), 0);
        tu_ctx_init(&ctx, &sc, &bvh, 32, 32, k);
        tu_ctx_set_pattern(&ctx, MS_PATTERN_INTERLEAVED);
        uint64_t rc[MS_MAX_COUNTERS] = { 0 };
        int blocked = 0, partial = 0, part_front = 0;
        for (int i = 0; i < NQ; i++) {
            ms_raytrace_visible_samples(&ctx, &q[i], pts + (size_t)i * n * 3, front + i * mw, ref + i * mw, rc);
            int nf = 0, nv = 0;
            for (size_t w = 0; w < mw; w++) {
                nf += __builtin_popcountll(front[i * mw + w]);
                nv += __builtin_popcountll(ref[i * mw + w]);
            }
            blocked += nf - nv;
            partial += nv > 0 && nv < nf;
            part_front += nf > 0 && nf < n;
        }
        printf("one occluder per ray, interleaved N=%d: %d triangles, %d of %d front rays blocked, %d queries partly lit, "
               "%d with a partial front mask\n", k * k, nt, blocked, front_rays, partial, part_front);
        assert_true(blocked >= nt * 9 / 10);
        assert_true(partial > NQ / 2);
        assert_true(part_front > NQ / 10);
        char what[64];
        snprintf(what, sizeof what, "one occluder per ray, N=%d", k * k);
        mft_equals_raytrace_every_isa(&ctx, q, NQ, front, ref, got, what);
        ms_bvh_free(&bvh);
        free(q); free(front); free(ref); free(got); free(pts);
        ms_scene_free(&sc);
    }
}

/* The portable, AVX2 and AVX-512 instances: the same masks and the same counters (every decision is
 * the same IEEE operations, lanes16.h); the portable one reports itself as scalar. */
static void test_isa_instances_identical(void **state)
{
    (void)state;
    ms_scene scenes[2];
    assert_int_equal(ms_scene_default(&scenes[0]), 0);
    tu_make_quad(&scenes[1]);
    for (int si = 0; si < 2; si++)
        for (int p = 0; p < 2; p++) {
            const ms_pattern pat = p ? MS_PATTERN_STRATIFIED : MS_PATTERN_GRID;
            uint64_t c0[MS_MAX_COUNTERS], c1[MS_MAX_COUNTERS];
            ms_isa isa0, isa1;
            int n0, n1;
            uint64_t *ref = mft_masks(&scenes[si], pat, 32, 40, MS_ISA_SCALAR, 0, 0, c0, &isa0, &n0);
            assert_int_equal(isa0, MS_ISA_SCALAR);
            assert_true(c0[MS_BT_AABB_TESTS] > 0);
            for (int cap = MS_ISA_AVX2; cap <= MS_ISA_AVX512; cap++) {
                if (!tu_isa_allowed((ms_isa)cap) || cap > (int)ms_cpu_isa()) continue;
                uint64_t *got = mft_masks(&scenes[si], pat, 32, 40, (ms_isa)cap, 0, 0, c1, &isa1, &n1);
                assert_int_equal(isa1, cap);
                assert_int_equal(n1, n0);
                assert_memory_equal(ref, got, (size_t)n0 * 16 * sizeof *ref);
                assert_memory_equal(c0, c1, sizeof c0);
                printf("%s %s: mft %s masks and counters identical to the portable ones on %d points\n",
                       si ? "quad" : "default", p ? "stratified" : "grid", ms_isa_name(isa1), n0);
                free(got);
            }
            free(ref);
        }
    ms_scene_free(&scenes[0]);
    ms_scene_free(&scenes[1]);
}

/* Frustum shrinking of the traversal bounds (FS) and the child order only change the work, not a mask. */
static void test_switches_keep_masks(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    const ms_isa cap = tu_isa_cap();
    uint64_t c0[MS_MAX_COUNTERS], c1[MS_MAX_COUNTERS], c2[MS_MAX_COUNTERS];
    ms_isa isa;
    int n0, n1, n2;
    uint64_t *base = mft_masks(&sc, MS_PATTERN_GRID, 32, 48, cap, 0, 0, c0, &isa, &n0);
    uint64_t *fs = mft_masks(&sc, MS_PATTERN_GRID, 32, 48, cap, 1, 0, c1, &isa, &n1);
    uint64_t *unordered = mft_masks(&sc, MS_PATTERN_GRID, 32, 48, cap, 0, 1, c2, &isa, &n2);
    assert_int_equal(n0, n1);
    assert_int_equal(n0, n2);
    assert_memory_equal(base, fs, (size_t)n0 * 16 * sizeof *base);
    assert_memory_equal(base, unordered, (size_t)n0 * 16 * sizeof *base);
    printf("default scene: AABB tests %llu (CR), %llu (CR+FS), %llu (no child order)\n",
           (unsigned long long)c0[MS_BT_AABB_TESTS], (unsigned long long)c1[MS_BT_AABB_TESTS],
           (unsigned long long)c2[MS_BT_AABB_TESTS]);
    free(base);
    free(fs);
    free(unordered);
    ms_scene_free(&sc);
}

/* The counters reach ms_stats (and --stats) by name, and account for every triangle-frustum pair: each is
 * culled by exactly one test (horizon, plane, corner rays, footprint) or tested, and tests at most N/16
 * packets; blocks hold at most 16 frusta, and a frustum ends early at most once. */
static void test_counters_account(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_frame f;
    render_ok(&sc, "mft", MS_PATTERN_GRID, 1024, 64, &f);
    const ms_stats *st = &f.stats;
    assert_int_equal(st->n_counters, ms_find_shadow_method("mft")->n_counters);
    assert_true(st->n_counters >= 16);   /* the block traversal's and the leaf's counters, all reported */
    const uint64_t pairs = tu_stat_counter(st, "tri_frustum_pairs"), tested = tu_stat_counter(st, "pairs_tested");
    printf("default scene 64x64: %llu AABB tests, %llu triangles accessed, %llu pairs, %llu tested, %llu 16-ray tests\n",
           (unsigned long long)tu_stat_counter(st, "aabb_tests"), (unsigned long long)tu_stat_counter(st, "tris_accessed"),
           (unsigned long long)pairs, (unsigned long long)tested, (unsigned long long)tu_stat_counter(st, "isec_tests16"));
    assert_true(tested > 0);
    assert_int_equal(pairs, tu_stat_counter(st, "culled_horizon") + tu_stat_counter(st, "culled_plane") + tu_stat_counter(st, "culled_corner_rays") +
                                tu_stat_counter(st, "culled_footprint") + tested);
    assert_true(tu_stat_counter(st, "isec_tests16") <= tested * (1024 / 16));   /* a pair tests at most N/16 packets */
    assert_true(tu_stat_counter(st, "frusta") <= 16 * tu_stat_counter(st, "blocks"));
    assert_true(tu_stat_counter(st, "frusta") <= st->visible_pixels);
    assert_true(tu_stat_counter(st, "frusta_early_out") <= tu_stat_counter(st, "frusta"));
    ms_frame_free(&f);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_quad_equals_raytrace),
        cmocka_unit_test(test_stratified_few_samples),
        cmocka_unit_test(test_tiny_occluders_grid_cut),
        cmocka_unit_test(test_default_scene_equals_raytrace),
        cmocka_unit_test(test_sponza_biglight_equals),
        cmocka_unit_test(test_bunny_equals),
        cmocka_unit_test(test_grazing_sliver_block),
        cmocka_unit_test(test_isa_instances_identical),
        cmocka_unit_test(test_interleaved_group_paths),
        cmocka_unit_test(test_interleaved_scattered_blocks),
        cmocka_unit_test(test_interleaved_ray_occluders),
        cmocka_unit_test(test_switches_keep_masks),
        cmocka_unit_test(test_counters_account),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
