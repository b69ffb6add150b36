/* Hierarchical penumbra casting (methods hpc and hpc-scanline, src/shadow/hpc/hpc.c) against the reference ray
 * tracer on identical samples:
 *   - hpc equals raytrace sample for sample: V and S bit for bit at every pixel (its per-sample decision is
 *     raytrace's own ray/triangle test; the volumes only cull, with a margin), on the built-in scene, the
 *     Quad and two real scenes (shared scenes, skipped when absent), at 256 and 1024 samples, and a GRIDS-like
 *     scene of thin closed bars written by the test (the footprint test's slack and the closed-component cull:
 *     with the slack at 0, pixels differ there);
 *   - hpc-scanline equals raytrace up to ties (Scanline's rounding at edges), as test_microraster bounds
 *     the scanline method;
 *   - the answer does not depend on the triangle order or the thread count: the engine driven directly
 *     with the triangles in area order, reversed and shuffled, on 1 and 2 threads, gives the same masks
 *     bit for bit, equal to raytrace's; and a scene whose triangle array is shuffled renders to raytrace's
 *     answer on that scene;
 *   - streaming: a procedural flowers scene rendered by hpc (no BVH, depth-pass primary, triangles
 *     generated in batches) equals raytrace on the same scene materialised; bad procedural sources fail
 *     with one line naming the file (exit 2 through the CLI). */
#include "testutil.h"
#include "shadow/method.h"
#include "shadow/raytrace/raytrace.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "shadow/hpc/hpc.h"
#include "accel/bvh.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void render_ok(const ms_scene *sc, const char *method, int samples, int size, int threads, ms_frame *f)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.samples = samples;
    o.width = o.height = size;
    o.threads = threads;
    tu_render_ok(sc, &o, f);
}

/* hpc against raytrace's frame ref: V and S bit for bit. Returns the triangles hpc's light left out (the
 * closed-component cull). */
static uint64_t hpc_equals(const ms_scene *sc, const char *label, int samples, int size, const ms_frame *ref_frame)
{
    const ms_frame ref = *ref_frame;
    ms_frame f;
    render_ok(sc, "hpc", samples, size, 0, &f);
    long dv = 0, ds = 0, npix = (long)size * size, lit = 0, part = 0;
    for (long i = 0; i < npix; i++) {
        dv += memcmp(&f.vis[i], &ref.vis[i], sizeof(float)) != 0;
        ds += memcmp(&f.shadow[i], &ref.shadow[i], sizeof(float)) != 0;
        lit += ref.vis[i] > 0.0f;
        part += ref.vis[i] > 0.0f && ref.vis[i] < 1.0f;
    }
    printf("%-16s N=%-4d hpc: V differs at %ld, S at %ld of %ld pixels (%ld lit, %ld in penumbra); %llu triangles, "
           "%llu sample tests, %llu full-umbra points\n", label, samples, dv, ds, npix, lit, part,
           (unsigned long long)f.stats.counter[0], (unsigned long long)f.stats.counter[9],
           (unsigned long long)f.stats.counter[14]);
    assert_int_equal(dv, 0);
    assert_int_equal(ds, 0);
    assert_true(lit > 0);
    assert_string_equal(f.stats.counter_name[9], "sample_tests");
    const uint64_t culled = f.stats.occluders_culled;
    ms_frame_free(&f);
    return culled;
}

/* hpc bit for bit, hpc-scanline within ties. */
static void agree_on_scene(const ms_scene *sc, const char *label, int samples, int size)
{
    ms_frame ref, f;
    render_ok(sc, "raytrace", samples, size, 0, &ref);
    hpc_equals(sc, label, samples, size, &ref);

    render_ok(sc, "hpc-scanline", samples, size, 0, &f);
    tu_agreement a = tu_compare_frames(&f, &ref);
    printf("%-16s N=%-4d hpc-scanline: differ %ld/%ld pixels, max |dV| %.2f samples, max |dS| %.5f\n", label, samples,
           a.differ, a.pixels, a.max_steps, a.max_ds);
    assert_int_equal(a.miss_mismatch, 0);
    assert_int_equal(a.beyond_one, 0);
    assert_int_equal(a.s_beyond, 0);
    assert_true((double)a.differ <= 0.001 * (double)a.pixels);
    ms_frame_free(&f);
    ms_frame_free(&ref);
}

static void test_builtin(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    agree_on_scene(&sc, "built-in", 256, 96);
    agree_on_scene(&sc, "built-in", 1024, 48);
    ms_scene_free(&sc);
}

static void shared_scene(const char *rel, const char *label, int samples, int size)
{
    if (!tu_have_shared_scenes()) skip();
    char path[4096], err[1024];
    tu_shared_scene(path, sizeof path, rel);
    ms_scene sc;
    if (ms_scene_load(path, &sc, err, sizeof err)) fail_msg("%s", err);
    agree_on_scene(&sc, label, samples, size);
    ms_scene_free(&sc);
}

static void test_quad(void **st) { (void)st; shared_scene("quad/quad.json", "quad", 1024, 64); }
static void test_sibenik(void **st) { (void)st; shared_scene("sibenik/sibenik.json", "sibenik", 256, 48); }
static void test_sponza(void **st) { (void)st; shared_scene("dabrovic-sponza/dabrovic-sponza.json", "dabrovic-sponza", 256, 48); }

/* ---- the engine driven directly: order and threads ---- */

typedef struct perm_source {
    const ms_bvh *bvh;
    const uint32_t *order;   /* leaf-order ids */
    size_t n, pos;
} perm_source;

static int perm_rewind(void *u) { ((perm_source *)u)->pos = 0; return 0; }

static size_t perm_next(void *u, float *tri, uint32_t *ids, size_t max)
{
    perm_source *s = u;
    size_t n = 0;
    for (; n < max && s->pos < s->n; n++, s->pos++) {
        const uint32_t i = s->order[s->pos];
        memcpy(tri + 9 * n, s->bvh->tri + 9 * (size_t)i, 9 * sizeof *tri);
        ids[n] = i;
    }
    return n;
}

static void test_order_and_threads(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    const int W = 64, H = 64, k = 16;
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 1), 0);
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, &sc, &bvh, W, H, k);
    const ms_primary_method *pm = ms_find_primary_method("bvh");
    void *ps = NULL;
    char err[256];
    assert_int_equal(pm->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit *hits = malloc((size_t)W * H * sizeof *hits);
    pm->trace(ps, &ctx, 0, 0, W, H, hits);
    pm->destroy(ps);
    ms_shadow_query *q = malloc((size_t)W * H * sizeof *q);
    size_t n = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            if (hits[y * W + x].prim != UINT32_MAX) tu_query_from_hit(&q[n++], &hits[y * W + x], x, y);
    assert_true(n > 1000);
    const size_t mw = (size_t)ctx.mask_words;
    uint64_t *front = malloc(n * mw * sizeof *front), *ref = malloc(n * mw * sizeof *ref);
    uint64_t *vis = malloc(n * mw * sizeof *vis), *scan_ref = malloc(n * mw * sizeof *scan_ref);
    float *pts = malloc((size_t)ctx.samples * 3 * sizeof *pts);
    uint64_t rc[MS_MAX_COUNTERS] = { 0 };
    for (size_t i = 0; i < n; i++) {
        ms_front_mask(&ctx, &q[i], NULL, front + i * mw);
        ms_raytrace_visible_samples(&ctx, &q[i], pts, front + i * mw, ref + i * mw, rc);
    }
    /* Orders: area buckets (what the method uses), reversed, and three shuffles. */
    const size_t nt = bvh.n_tris;
    uint32_t *area = ms_hpc_area_order(bvh.tri, nt), *order = malloc(nt * sizeof *order);
    assert_non_null(area);
    tu_rng rng = { 0x4850434Cu };
    long blocked = 0;
    for (int variant = 0; variant < 5; variant++) {
        for (size_t i = 0; i < nt; i++) order[i] = variant == 1 ? area[nt - 1 - i] : area[i];
        if (variant >= 2)
            for (size_t i = nt - 1; i > 0; i--) {
                const size_t j = (size_t)(tu_rng_next(&rng) % (i + 1));
                const uint32_t t = order[i]; order[i] = order[j]; order[j] = t;
            }
        for (int threads = 1; threads <= 2; threads++) {
            perm_source ps2 = { &bvh, order, nt, 0 };
            const hpc_source src = { &ps2, perm_rewind, perm_next, 0 };
            ctx.threads = threads;
            uint64_t cnt[MS_MAX_COUNTERS] = { 0 };
            for (int scan = 0; scan <= 1; scan++) {
                ms_raster_fn raster = scan ? ms_raster_kernel(MS_KERNEL_SCANLINE, k, ctx.isa_cap, NULL) : NULL;
                assert_int_equal(ms_hpc_cast(&ctx, scan, raster, q, n, front, vis, &src, cnt), 0);
                long differ = 0;
                for (size_t i = 0; i < n * mw; i++) differ += vis[i] != ref[i];
                if (!scan) assert_int_equal(differ, 0);            /* hpc: raytrace's masks exactly */
                else {
                    assert_true(differ * 1000 <= (long)(n * mw));  /* hpc-scanline: raytrace's up to ties */
                    if (variant == 0 && threads == 1) memcpy(scan_ref, vis, n * mw * sizeof *vis);
                    else assert_memory_equal(vis, scan_ref, n * mw * sizeof *vis);   /* and order-free */
                }
                if (variant == 0 && threads == 1 && !scan)
                    for (size_t i = 0; i < n * mw; i++) blocked += __builtin_popcountll(front[i] & ~vis[i]);
            }
        }
    }
    printf("order/threads: %zu points, %zu triangles, %ld blocked relations, 5 orders x 2 thread counts equal\n", n, nt,
           blocked);
    assert_true(blocked > 1000);
    free(area); free(order); free(front); free(ref); free(vis); free(scan_ref); free(pts); free(q); free(hits);
    ms_bvh_free(&bvh);
    ms_scene_free(&sc);
}

/* The engine's ISA instances (hpc_impl.h compiled per ISA) give the same masks, equal to raytrace's, and the same
 * counters, at k = 16, 32 and 64 (64: groups of 8 x 8, four 16-lane blocks each); and every measuring switch
 * (ms_hpc_switches: each optimisation of sec. 3.3 and each SIMD form off) changes the work, not the answer. */
static void test_isa_instances_and_switches(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    const int W = 40, H = 40;
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 1), 0);
    const size_t nt = bvh.n_tris;
    uint32_t *area = ms_hpc_area_order(bvh.tri, nt);
    assert_non_null(area);
    for (int k = 16; k <= 64; k *= 2) {
        ms_render_ctx ctx;
        tu_ctx_init(&ctx, &sc, &bvh, W, H, k);
        const ms_primary_method *pm = ms_find_primary_method("bvh");
        void *ps = NULL;
        char err[256];
        assert_int_equal(pm->create(&ctx, &ps, err, sizeof err), 0);
        ms_hit *hits = malloc((size_t)W * H * sizeof *hits);
        pm->trace(ps, &ctx, 0, 0, W, H, hits);
        pm->destroy(ps);
        ms_shadow_query *q = malloc((size_t)W * H * sizeof *q);
        size_t n = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                if (hits[y * W + x].prim != UINT32_MAX) tu_query_from_hit(&q[n++], &hits[y * W + x], x, y);
        const size_t mw = (size_t)ctx.mask_words;
        uint64_t *front = malloc(n * mw * sizeof *front), *ref = malloc(n * mw * sizeof *ref);
        uint64_t *vis = malloc(n * mw * sizeof *vis);
        float *pts = malloc((size_t)ctx.samples * 3 * sizeof *pts);
        uint64_t rc[MS_MAX_COUNTERS] = { 0 }, cnt0[MS_MAX_COUNTERS] = { 0 };
        for (size_t i = 0; i < n; i++) {
            ms_front_mask(&ctx, &q[i], NULL, front + i * mw);
            ms_raytrace_visible_samples(&ctx, &q[i], pts, front + i * mw, ref + i * mw, rc);
        }
        int ran = 0;
        uint64_t rect_pairs = 0;
        /* as designed, with the leaf footprint (and the rectangle pairs' bound) on every leaf, and that without
         * the leaf lanes (each receiver given its samples in turn) */
        static const int modes[3] = { MS_HPC_ALL_LEAF_FOOTPRINT | MS_HPC_OFF_LEAF_LANES, MS_HPC_ALL_LEAF_FOOTPRINT, 0 };
        uint64_t lane_tests = 0;
        for (int mi = 0; mi < 3; mi++) {
            const int mode = modes[mi];
            ran = 0;
            for (int isa = MS_ISA_SCALAR; isa <= MS_ISA_AVX512; isa++) {
                const ms_hpc_cast_fn fn = ms_hpc_cast_isa((ms_isa)isa);
                if (!fn || (ctx.isa_cap != MS_ISA_AUTO && isa > (int)ctx.isa_cap)) continue;
                perm_source ps2 = { &bvh, area, nt, 0 };
                const hpc_source src = { &ps2, perm_rewind, perm_next, 0 };
                uint64_t cnt[MS_MAX_COUNTERS] = { 0 };
                memset(vis, 0xA5, n * mw * sizeof *vis);
                ms_hpc_switches = mode;
                const int rc1 = fn(&ctx, 0, NULL, q, n, front, vis, &src, cnt);
                ms_hpc_switches = 0;
                assert_int_equal(rc1, 0);
                assert_memory_equal(vis, ref, n * mw * sizeof *vis);
                /* Counters but the wall-clock ones (sort, build, rebuild, cast: microseconds). */
                cnt[16] = cnt[17] = cnt[18] = cnt[19] = 0;
                if (!ran) memcpy(cnt0, cnt, sizeof cnt);
                else assert_memory_equal(cnt, cnt0, sizeof cnt);
                ran++;
            }
            assert_true(ran >= 1);
            if (mode == MS_HPC_ALL_LEAF_FOOTPRINT) { rect_pairs = cnt0[27]; lane_tests = cnt0[29]; }
            if (mode & MS_HPC_OFF_LEAF_LANES) assert_int_equal(cnt0[29], 0);
        }
        assert_true(rect_pairs > 0);   /* the rectangle pairs' path ran in the instances compared */
        assert_true(lane_tests > 0);   /* and the leaf lanes */
        static const int switches[] = { 1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, MS_HPC_OFF_LEAF_LANES,
                                        MS_HPC_OFF_TSURE };
        for (size_t si = 0; si < sizeof switches / sizeof *switches; si++) {
            const int sw = switches[si];
            perm_source ps2 = { &bvh, area, nt, 0 };
            const hpc_source src = { &ps2, perm_rewind, perm_next, 0 };
            uint64_t cnt[MS_MAX_COUNTERS] = { 0 };
            ms_hpc_switches = sw;
            const int rc2 = ms_hpc_cast(&ctx, 0, NULL, q, n, front, vis, &src, cnt);
            ms_hpc_switches = 0;
            assert_int_equal(rc2, 0);
            assert_memory_equal(vis, ref, n * mw * sizeof *vis);
        }
        printf("k=%d: %zu points, %d ISA instances equal to raytrace and to each other (masks, counters: %llu sample "
               "tests; %llu (leaf, pair) by their rectangle and %llu sample tests in the leaf lanes on every leaf); "
               "15 switches equal\n", k, n, ran, (unsigned long long)cnt0[9], (unsigned long long)rect_pairs,
               (unsigned long long)lane_tests);
        free(front); free(ref); free(vis); free(pts); free(q); free(hits);
    }
    free(area);
    ms_bvh_free(&bvh);
    ms_scene_free(&sc);
}

/* The scene's own triangle array shuffled: the render still equals raytrace on it, on 1 and 2 threads. */
static void test_shuffled_scene(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    tu_rng rng = { 77 };
    for (size_t i = sc.n_tris - 1; i > 0; i--) {
        const size_t j = (size_t)(tu_rng_next(&rng) % (i + 1));
        float t[9];
        memcpy(t, sc.tri + 9 * i, sizeof t);
        memcpy(sc.tri + 9 * i, sc.tri + 9 * j, sizeof t);
        memcpy(sc.tri + 9 * j, t, sizeof t);
    }
    ms_frame ref, a, b;
    render_ok(&sc, "raytrace", 256, 64, 0, &ref);
    render_ok(&sc, "hpc", 256, 64, 1, &a);
    render_ok(&sc, "hpc", 256, 64, 2, &b);
    assert_memory_equal(a.vis, ref.vis, 64 * 64 * sizeof(float));
    assert_memory_equal(a.shadow, ref.shadow, 64 * 64 * sizeof(float));
    assert_memory_equal(b.vis, ref.vis, 64 * 64 * sizeof(float));
    assert_memory_equal(b.shadow, ref.shadow, 64 * 64 * sizeof(float));
    ms_frame_free(&ref); ms_frame_free(&a); ms_frame_free(&b);
    ms_scene_free(&sc);
}

/* ---- streaming ---- */

static const char *flowers_json(const char *dir, const char *name, const char *proc)
{
    static char path[4096];
    char text[2048];
    snprintf(text, sizeof text,
             "{\"procedural\": %s,\n \"camera\": {\"eye\": [0, 14, 18], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 60},\n \"light\": {\"corner\": [-2, 12, -2], \"edge_s\": [4, 0, 0], \"edge_t\": [0, 0, 4]}}\n", proc);
    tu_path(path, sizeof path, dir, name);
    assert_int_equal(tu_write_file(path, text), 0);
    return path;
}

/* The pixels whose V differs from ref's (96 x 96, 256 samples) when hpc runs with the given switches (a
 * deliberate fault among them shows that the bound it breaks is needed). */
static long hpc_pixels_off(const ms_scene *sc, int switches, const ms_frame *ref)
{
    ms_frame f;
    ms_hpc_switches = switches;
    render_ok(sc, "hpc", 256, 96, 0, &f);
    ms_hpc_switches = 0;
    long differ = 0;
    for (long i = 0; i < 96L * 96L; i++) differ += memcmp(&f.vis[i], &ref->vis[i], sizeof(float)) != 0;
    ms_frame_free(&f);
    return differ;
}

/* A GRIDS-like scene (the paper's; /work/dense/grids at full size): two layers of thin bars, closed boxes
 * in segments, crossing over a ground under a square light, seen from above. Every receiver on the ground
 * is in the penumbra of many bars whose shadows, from one receiver, are strips narrower than a sample
 * cell: the samples lie within ulps of the triangles' edges far more often than on the shared scenes, so
 * hpc's footprint test (hpc_footprint.c) must keep every sample raytrace's rounding may call blocked (with its
 * slack set to 0, pixels differ here), and half the bars' triangles face away from the light (the
 * closed-component cull, which must leave V and S as they are). The leaf footprint (hpc_leaf_bound_impl.h) rules out
 * samples for a whole leaf of receivers at once; its bound over the leaf's grid origins (which differ per
 * pixel) matters here: without it (MS_HPC_BREAK_LEAF_BOUND, wrong on purpose) pixels differ, so the scene
 * shows a bound that misses what raytrace blocks. Every face of a bar is an axis-aligned rectangle cut into two
 * triangles, so the pairs' leaf footprint is their rectangle's (hpc_leaf_bound_impl.h, "rectangle pairs"): it
 * runs here, and bounded by its first triangle alone (MS_HPC_BREAK_RECT, wrong on purpose) pixels differ. Most samples a
 * bar blocks lie well inside its footprint, where only the t range is tested (footprint_sure_lanes): that
 * runs here, and with the sure lanes' margin on the wrong side of the edges (MS_HPC_BREAK_SURE, wrong on
 * purpose) pixels differ. (With that margin at 0 none does: the samples on a bar's edge are blocked either way.)
 * Where the bars lie well between the receivers and the light even the t range needs no test (t_sure): that runs
 * here, and with t_sure true everywhere (MS_HPC_BREAK_TSURE, wrong on purpose) pixels differ, the receivers on the
 * bars whose segments meet another bar's plane outside [near, far]. Most sample tests are made for a leaf's 16
 * receivers at once (the leaf lanes), and the leaf footprint on every leaf equals raytrace too. */
static void test_bars(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("test_hpc_bars");
    const int nbars = 10, segs = 6;
    const float half = 0.015f, lo = -1.5f, len = 3.0f;
    size_t cap = 1u << 20, used = 0;
    char *obj = malloc(cap);
    assert_non_null(obj);
    int nv = 0;
    for (int layer = 0; layer < 2; layer++)
        for (int b = 0; b < nbars; b++) {
            const float y = 1.0f + 0.5f * (float)layer, c = lo + (b + 0.5f) * len / (float)nbars + 0.013f * (float)layer;
            /* layer 0: bars along x at z = c; layer 1: along z at x = c */
            const int first = nv + 1;
            for (int sgi = 0; sgi <= segs; sgi++) {
                const float u = lo + len * (float)sgi / (float)segs;
                const float cs[4][2] = { { c - half, y - half }, { c + half, y - half }, { c + half, y + half }, { c - half, y + half } };
                for (int q = 0; q < 4; q++) {
                    const float x = layer ? cs[q][0] : u, z = layer ? u : cs[q][0];
                    used += (size_t)snprintf(obj + used, cap - used, "v %.6f %.6f %.6f\n", (double)x, (double)cs[q][1], (double)z);
                    nv++;
                }
            }
            /* sides: quads between rings sgi and sgi + 1, consistently wound; caps at both ends */
            for (int sgi = 0; sgi < segs; sgi++)
                for (int q = 0; q < 4; q++) {
                    const int a = first + 4 * sgi + q, b2 = first + 4 * sgi + (q + 1) % 4;
                    const int c2 = b2 + 4, d = a + 4;
                    if (layer)
                        used += (size_t)snprintf(obj + used, cap - used, "f %d %d %d\nf %d %d %d\n", a, d, c2, a, c2, b2);
                    else
                        used += (size_t)snprintf(obj + used, cap - used, "f %d %d %d\nf %d %d %d\n", a, b2, c2, a, c2, d);
                }
            const int e = first + 4 * segs;
            if (layer)
                used += (size_t)snprintf(obj + used, cap - used, "f %d %d %d\nf %d %d %d\nf %d %d %d\nf %d %d %d\n", first,
                                         first + 1, first + 2, first, first + 2, first + 3, e, e + 3, e + 2, e, e + 2, e + 1);
            else
                used += (size_t)snprintf(obj + used, cap - used, "f %d %d %d\nf %d %d %d\nf %d %d %d\nf %d %d %d\n", first,
                                         first + 3, first + 2, first, first + 2, first + 1, e, e + 1, e + 2, e, e + 2, e + 3);
        }
    used += (size_t)snprintf(obj + used, cap - used, "v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\nf %d %d %d\nf %d %d %d\n", nv + 1,
                             nv + 3, nv + 2, nv + 1, nv + 4, nv + 3);
    char path[4096];
    tu_path(path, sizeof path, dir, "bars.obj");
    assert_int_equal(tu_write_file(path, obj), 0);
    free(obj);
    tu_path(path, sizeof path, dir, "bars.json");
    assert_int_equal(tu_write_file(path, "{\"meshes\": [{\"file\": \"bars.obj\"}],\n"
                                         " \"camera\": {\"eye\": [0.3, 5.5, 0.8], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 40},\n"
                                         " \"light\": {\"corner\": [-1.5, 4.5, -1.5], \"edge_s\": [3, 0, 0], \"edge_t\": [0, 0, 3]}}\n"), 0);
    ms_scene sc;
    char err[1024];
    if (ms_scene_load(path, &sc, err, sizeof err)) fail_msg("%s", err);
    ms_frame ref;
    render_ok(&sc, "raytrace", 256, 96, 0, &ref);
    const uint64_t culled = hpc_equals(&sc, "bars", 256, 96, &ref);
    printf("bars: %llu of %zu triangles left out by the closed-component cull\n", (unsigned long long)culled, sc.n_tris);
    assert_true(culled > 0);
    /* the leaf footprint on every leaf equals raytrace, works here (leaves ruled out, leaves whose candidates are
     * all blocked already skipped, pairs kept from the per-receiver work), and without its bound over the grid
     * origins the answer is wrong */
    ms_hpc_switches = MS_HPC_ALL_LEAF_FOOTPRINT;
    hpc_equals(&sc, "bars, leaf fp", 256, 96, &ref);
    ms_frame f;
    render_ok(&sc, "hpc", 256, 96, 0, &f);
    ms_hpc_switches = 0;
    const uint64_t lane_tests = tu_stat_counter(&f.stats, "leaf_lane_tests"), tsure = tu_stat_counter(&f.stats, "samples_t_sure");
    const uint64_t sure = tu_stat_counter(&f.stats, "samples_sure"), tests = tu_stat_counter(&f.stats, "sample_tests");
    const uint64_t rect_pairs = tu_stat_counter(&f.stats, "rect_pairs"), in_vl = tu_stat_counter(&f.stats, "pairs_in_vl");
    const uint64_t to_fp = tu_stat_counter(&f.stats, "pairs_footprint"), leaf_culls = tu_stat_counter(&f.stats, "leaf_culls");
    const uint64_t culls_blocked = tu_stat_counter(&f.stats, "leaf_culls_blocked");
    ms_frame_free(&f);
    const long differ = hpc_pixels_off(&sc, MS_HPC_ALL_LEAF_FOOTPRINT | MS_HPC_BREAK_LEAF_BOUND, &ref);
    const long differ_rect = hpc_pixels_off(&sc, MS_HPC_ALL_LEAF_FOOTPRINT | MS_HPC_BREAK_RECT, &ref);
    const long differ_sure = hpc_pixels_off(&sc, MS_HPC_BREAK_SURE, &ref);
    const long differ_sure_leaf = hpc_pixels_off(&sc, MS_HPC_ALL_LEAF_FOOTPRINT | MS_HPC_BREAK_SURE, &ref);
    const long differ_tsure = hpc_pixels_off(&sc, MS_HPC_BREAK_TSURE, &ref);
    printf("bars: leaf footprint: %llu of %llu pairs in V_L to the per-receiver test, %llu (leaf, triangle) ruled "
           "out, %llu with every candidate blocked already; without its bound over the grid origins %ld pixels "
           "differ\n", (unsigned long long)to_fp, (unsigned long long)in_vl, (unsigned long long)leaf_culls,
           (unsigned long long)culls_blocked, differ);
    printf("bars: %llu (leaf, pair) bounded by the pair's rectangle; with the rectangle's bound broken %ld pixels differ\n",
           (unsigned long long)rect_pairs, differ_rect);
    printf("bars: %llu of %llu sample tests on the t range alone; with the sure lanes' margin on the wrong side %ld pixels differ "
           "(%ld with the leaf footprint on every leaf)\n", (unsigned long long)sure, (unsigned long long)tests, differ_sure,
           differ_sure_leaf);
    printf("bars: %llu of the sample tests in the leaf lanes (a leaf's receivers at one sample)\n", (unsigned long long)lane_tests);
    printf("bars: %llu of the sure samples blocked without their t range (t_sure); with t_sure true everywhere %ld pixels "
           "differ\n", (unsigned long long)tsure, differ_tsure);
    assert_true(tsure > sure / 4);
    assert_true(differ_tsure > 0);
    assert_true(lane_tests > tests / 2);
    assert_true(leaf_culls > 0);
    assert_true(culls_blocked > 0);
    assert_true(to_fp < in_vl);
    assert_true(differ > 0);
    assert_true(rect_pairs > 0);
    assert_true(differ_rect > 0);
    assert_true(sure > 0);
    assert_true(differ_sure > 0);
    assert_true(differ_sure_leaf > 0);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

/* Pairs (hpc_triangle.c hpc_pair_batch: two triangles sharing an edge and a plane cast as one job): long thin quads at
 * random yaw, tilt and height over a ground, each two triangles split along the long diagonal, so that the
 * two triangles' hard shadows from one sample are slivers meeting along it and many samples fall within ulps
 * of the shared edge. hpc with its pairs equals raytrace bit for bit, as with every triangle cast alone
 * (--off pairs); the pairs are really formed (the pair's V_L, of four points, holds more receivers). Casting
 * only the first triangle's lanes, or the pair's V_L from the first triangle's points, fails here. */
static void test_pairs(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("test_hpc_pairs");
    tu_rng rng = { 0x9A125 };
    size_t cap = 1u << 18, used = 0;
    char *obj = malloc(cap);
    assert_non_null(obj);
    const int nq = 60;
    for (int i = 0; i < nq; i++) {
        double u[5];
        for (int k = 0; k < 5; k++) u[k] = (double)(tu_rng_next(&rng) >> 11) / 9007199254740992.0;
        const double u1 = u[0], u2 = u[1], u3 = u[2], u4 = u[3], u5 = u[4];
        const double cx = 3.0 * u1 - 1.5, cz = 3.0 * u2 - 1.5, y = 0.8 + 1.2 * u3, yaw = 6.283185307 * u4, tilt = 0.6 * u5 - 0.3;
        const double len = 0.6, wid = 0.012, ax = cos(yaw), az = sin(yaw);
        const double c[4][2] = { { -len, -wid }, { len, -wid }, { len, wid }, { -len, wid } };
        for (int v = 0; v < 4; v++) {
            const double x = cx + c[v][0] * ax - c[v][1] * az, z = cz + c[v][0] * az + c[v][1] * ax;
            used += (size_t)snprintf(obj + used, cap - used, "v %.6f %.6f %.6f\n", x, y + tilt * c[v][0], z);
        }
        const int a = 4 * i + 1;
        used += (size_t)snprintf(obj + used, cap - used, "f %d %d %d\nf %d %d %d\n", a, a + 1, a + 2, a, a + 2, a + 3);
    }
    used += (size_t)snprintf(obj + used, cap - used, "v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\nf %d %d %d\nf %d %d %d\n",
                             4 * nq + 1, 4 * nq + 3, 4 * nq + 2, 4 * nq + 1, 4 * nq + 4, 4 * nq + 3);
    char path[4096];
    tu_path(path, sizeof path, dir, "quads.obj");
    assert_int_equal(tu_write_file(path, obj), 0);
    free(obj);
    tu_path(path, sizeof path, dir, "quads.json");
    assert_int_equal(tu_write_file(path, "{\"meshes\": [{\"file\": \"quads.obj\"}],\n"
                                         " \"camera\": {\"eye\": [0.2, 5.5, 0.6], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 40},\n"
                                         " \"light\": {\"corner\": [-1, 4, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2]}}\n"), 0);
    ms_scene sc;
    char err[1024];
    if (ms_scene_load(path, &sc, err, sizeof err)) fail_msg("%s", err);
    ms_frame ref, f;
    render_ok(&sc, "raytrace", 256, 80, 0, &ref);
    uint64_t pairs_in_vl[2] = { 0, 0 };
    for (int off = 0; off < 2; off++) {
        ms_hpc_switches = off ? MS_HPC_OFF_PAIRS : 0;
        render_ok(&sc, "hpc", 256, 80, 2, &f);
        ms_hpc_switches = 0;
        assert_memory_equal(f.vis, ref.vis, 80 * 80 * sizeof(float));
        assert_memory_equal(f.shadow, ref.shadow, 80 * 80 * sizeof(float));
        for (int c = 0; c < f.stats.n_counters; c++)
            if (!strcmp(f.stats.counter_name[c], "pairs_in_vl")) pairs_in_vl[off] = f.stats.counter[c];
        ms_frame_free(&f);
    }
    long part = 0;
    for (int i = 0; i < 80 * 80; i++) part += ref.vis[i] > 0.0f && ref.vis[i] < 1.0f;
    printf("pairs: %ld penumbra pixels of %d; (receiver, triangle) pairs in V_L %llu with pairs, %llu without\n", part,
           80 * 80, (unsigned long long)pairs_in_vl[0], (unsigned long long)pairs_in_vl[1]);
    assert_true(part > 500);
    assert_true(pairs_in_vl[0] > pairs_in_vl[1]);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

/* A streamed procedural scene: hpc and hpc-scanline (no BVH, primary hits from the depth pass, triangles
 * generated batch by batch) against raytrace on the same scene materialised (BVH primary): V and S bit
 * for bit for hpc, within ties for hpc-scanline. More than one batch of triangles (16K in hpc.c, 64K in
 * the depth pass). */
static void test_streamed_flowers(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("test_hpc");
    char err[1024];
    ms_scene sc;
    if (ms_scene_load(flowers_json(dir, "flowers.json", "{\"type\": \"flowers\", \"triangles\": 70000, \"seed\": 3}"),
                      &sc, err, sizeof err))
        fail_msg("%s", err);
    assert_null(sc.tri);
    assert_int_equal(sc.n_tris, 70000);
    ms_frame ref, f;
    render_ok(&sc, "raytrace", 256, 48, 0, &ref);   /* materialised */
    render_ok(&sc, "hpc", 256, 48, 0, &f);          /* streamed */
    assert_int_equal(f.stats.build_s, 0.0);         /* no BVH */
    long lit = 0, part = 0;
    for (int i = 0; i < 48 * 48; i++) { lit += ref.vis[i] > 0.0f; part += ref.vis[i] > 0.0f && ref.vis[i] < 1.0f; }
    printf("flowers 70000: %ld lit, %ld penumbra pixels of %d\n", lit, part, 48 * 48);
    assert_true(part > 50);
    assert_memory_equal(f.vis, ref.vis, 48 * 48 * sizeof(float));
    assert_memory_equal(f.shadow, ref.shadow, 48 * 48 * sizeof(float));
    ms_frame_free(&f);
    render_ok(&sc, "hpc-scanline", 256, 48, 0, &f);
    tu_agreement a = tu_compare_frames(&f, &ref);
    assert_int_equal(a.miss_mismatch, 0);
    assert_int_equal(a.beyond_one, 0);
    assert_true((double)a.differ <= 0.002 * (double)a.pixels);
    ms_frame_free(&f);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

/* Bad procedural sources: one line naming the file and what is wrong. */
static void test_procedural_bad_input(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("test_hpc_bad");
    static const struct { const char *proc, *want; } cases[] = {
        { "{\"type\": \"trees\", \"triangles\": 10}", "procedural.type must be \"flowers\"" },
        { "{\"type\": \"flowers\", \"triangles\": 0}", "procedural.triangles must be an integer" },
        { "{\"type\": \"flowers\", \"triangles\": 1.5}", "procedural.triangles must be an integer" },
        { "{\"type\": \"flowers\", \"triangles\": 1e12}", "procedural.triangles must be an integer" },
        { "{\"type\": \"flowers\", \"triangles\": 10, \"seed\": -1}", "procedural.seed must be an integer" },
        { "{\"type\": \"flowers\"}", "triangles" },
        { "[1, 2]", "\"procedural\" must be an object" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        char err[1024], name[32];
        snprintf(name, sizeof name, "bad%zu.json", i);
        const char *path = flowers_json(dir, name, cases[i].proc);
        ms_scene sc;
        assert_int_not_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
        if (!strstr(err, cases[i].want) || !strstr(err, name)) fail_msg("case %zu: got \"%s\"", i, err);
    }
    /* meshes and procedural together */
    char path[4096], err[1024];
    tu_path(path, sizeof path, dir, "both.json");
    tu_write_file(path, "{\"meshes\": [{\"file\": \"x.obj\"}], \"procedural\": {\"type\": \"flowers\", \"triangles\": 5},"
                        " \"camera\": {\"eye\": [0, 1, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 60},"
                        " \"light\": {\"corner\": [0, 3, 0], \"edge_s\": [1, 0, 0], \"edge_t\": [0, 0, 1]}}");
    ms_scene sc;
    assert_int_not_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    assert_non_null(strstr(err, "either \"meshes\" or \"procedural\""));
    /* through the CLI: exit 2 and the message */
    const char *args[] = { flowers_json(dir, "cli.json", "{\"type\": \"tulips\", \"triangles\": 5}"), "--quiet", NULL };
    char line[1024];
    assert_int_equal(tu_run_cli(args, line, sizeof line), 2);
    assert_non_null(strstr(line, "procedural.type"));
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_builtin),
        cmocka_unit_test(test_bars),
        cmocka_unit_test(test_pairs),
        cmocka_unit_test(test_quad),
        cmocka_unit_test(test_sibenik),
        cmocka_unit_test(test_sponza),
        cmocka_unit_test(test_order_and_threads),
        cmocka_unit_test(test_isa_instances_and_switches),
        cmocka_unit_test(test_shuffled_scene),
        cmocka_unit_test(test_streamed_flowers),
        cmocka_unit_test(test_procedural_bad_input),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
