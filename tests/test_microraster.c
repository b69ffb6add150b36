/* Soft shadows by micro-rasterization against the reference ray tracer on identical samples:
 * scanline, bounds and hierarchical must give raytrace's V and S at every pixel, bit for bit; the scalar
 * paths too; the Quad scene against its exact V; an open quad shadows from both sides. */
#include "testutil.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "accel/bvh.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const kernels[] = { "scanline", "bounds", "hierarchical" };

typedef tu_agreement agreement;

static agreement compare(const ms_frame *a, const ms_frame *b, int samples)
{
    (void)samples;
    agreement g = tu_compare_frames(a, b);
    assert_int_equal(g.miss_mismatch, 0);
    assert_true(g.s_differ_same_v * 1000 <= g.pixels);
    assert_int_equal(g.s_beyond, 0);
    return g;
}

static void render_ok(const ms_scene *sc, const char *method, int samples, int size, ms_frame *f)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.samples = samples;
    o.width = o.height = size;
    tu_render_ok(sc, &o, f);
}

/* Every kernel against raytrace on one scene, for the given sample counts. */
static void agree_on_scene(const ms_scene *sc, const char *label, const int *samples, int n_samples, int size)
{
    for (int s = 0; s < n_samples; s++) {
        ms_frame ref;
        render_ok(sc, "raytrace", samples[s], size, &ref);
        for (int k = 0; k < 3; k++) {
            ms_frame f;
            render_ok(sc, kernels[k], samples[s], size, &f);
            agreement a = compare(&f, &ref, samples[s]);
            printf("%-14s %-12s N=%-4d differ %ld/%ld pixels (%.4f%%), max |dV| %.2f samples, max |dS| %.5f\n",
                   label, kernels[k], samples[s], a.differ, a.pixels, 100.0 * (double)a.differ / (double)a.pixels,
                   a.max_steps, a.max_ds);
            assert_int_equal(a.beyond_one, 0);
            assert_int_equal(a.differ, 0);
            const size_t n = (size_t)size * (size_t)size;
            assert_memory_equal(f.vis, ref.vis, n * sizeof *f.vis);
            assert_memory_equal(f.shadow, ref.shadow, n * sizeof *f.shadow);
            ms_frame_free(&f);
        }
        ms_frame_free(&ref);
    }
}

static void test_quad_agrees_with_raytrace(void **state)
{
    (void)state;
    ms_scene sc;
    tu_make_quad(&sc);
    const int samples[] = { 256, 1024, 4096 };
    agree_on_scene(&sc, "quad", samples, 3, 96);
    ms_scene_free(&sc);
}

/* Exact V of a ground point (y = 0): the occluder's central projection from P onto the light plane is
 * the square of half-size 2*h/(h-2) around P + (6-0)/(2-0)*(0 - P) in x and z, h = 6. */
static double quad_exact_v(double px, double pz)
{
    const double scale = 6.0 / 2.0;        /* (light height - P.y) / (occluder height - P.y) */
    double cx = px + scale * (0.0 - px), cz = pz + scale * (0.0 - pz), half = 2.0 * scale;
    double ox = fmax(0.0, fmin(1.0, cx + half) - fmax(-1.0, cx - half));
    double oz = fmax(0.0, fmin(1.0, cz + half) - fmax(-1.0, cz - half));
    return 1.0 - ox * oz / 4.0;
}

static void test_quad_exact(void **state)
{
    (void)state;
    ms_scene sc;
    tu_make_quad(&sc);
    const int W = 96;
    for (int k = 0; k < 3; k++) {
        ms_frame f;
        render_ok(&sc, kernels[k], 1024, W, &f);
        /* Camera rays in double, per the header's conventions, to find the ground pixels. */
        double eye[3] = { 0, 10, 12 }, fw[3] = { 0, -10, -12 }, len = sqrt(244.0);
        for (int a = 0; a < 3; a++) fw[a] /= len;
        double right[3] = { -fw[2], 0, fw[0] };   /* cross(fw, up) with up = y */
        double rl = sqrt(right[0] * right[0] + right[2] * right[2]);
        right[0] /= rl; right[2] /= rl;
        double up[3] = { right[1] * fw[2] - right[2] * fw[1], right[2] * fw[0] - right[0] * fw[2],
                         right[0] * fw[1] - right[1] * fw[0] };
        double th = tan(30.0 * M_PI / 180.0), sum = 0.0, worst = 0.0;
        int n = 0;
        for (int y = 0; y < W; y++)
            for (int x = 0; x < W; x++) {
                double sx = (2.0 * (x + 0.5) / W - 1.0) * th, sy = (1.0 - 2.0 * (y + 0.5) / W) * th, d[3];
                for (int a = 0; a < 3; a++) d[a] = fw[a] + sx * right[a] + sy * up[a];
                double t2 = (2.0 - eye[1]) / d[1];
                double ox = eye[0] + t2 * d[0], oz = eye[2] + t2 * d[2];
                if (fabs(ox) <= 2.0 && fabs(oz) <= 2.0) continue;   /* sees the occluder's top */
                double t0 = -eye[1] / d[1];
                double gx = eye[0] + t0 * d[0], gz = eye[2] + t0 * d[2];
                if (fabs(gx) > 10.0 || fabs(gz) > 10.0) continue;
                double e = fabs(f.vis[y * W + x] - quad_exact_v(gx, gz));
                sum += e;
                worst = fmax(worst, e);
                n++;
            }
        printf("quad exact, %s: %d ground pixels, MAE %.5f, max %.5f\n", kernels[k], n, sum / n, worst);
        assert_true(n > W * W / 2);
        assert_true(sum / n < 0.002);
        assert_true(worst < 0.05);
        ms_frame_free(&f);
    }
    ms_scene_free(&sc);
}

/* A single open quad between a ground and the light, wound one way and then the other: both windings
 * must shadow, and match raytrace. */
static void test_open_quad_both_sides(void **state)
{
    (void)state;
    for (int flip = 0; flip < 2; flip++) {
        ms_scene sc;
        tu_make_quad(&sc);
        if (flip)
            for (int t = 2; t < 4; t++) {   /* swap two vertices: the other winding */
                float tmp[3];
                memcpy(tmp, sc.tri + 9 * t + 3, sizeof tmp);
                memcpy(sc.tri + 9 * t + 3, sc.tri + 9 * t + 6, sizeof tmp);
                memcpy(sc.tri + 9 * t + 6, tmp, sizeof tmp);
            }
        ms_frame f, ref;
        render_ok(&sc, "scanline", 1024, 64, &f);
        render_ok(&sc, "raytrace", 1024, 64, &ref);
        size_t dark = 0;
        for (size_t i = 0; i < 64 * 64; i++) dark += f.vis[i] == 0.0f;
        printf("open quad winding %d: %zu umbra pixels\n", flip, dark);
        assert_true(dark > 50);
        agreement a = compare(&f, &ref, 1024);
        assert_int_equal(a.beyond_one, 0);
        ms_frame_free(&f);
        ms_frame_free(&ref);
        ms_scene_free(&sc);
    }
}

/* The visible masks (ctx->mask_words words per point) of the points of a size x size view of sc, through
 * the shadow method's interface with the render context's ISA cap; *kernel and *trav: the ISAs the
 * method reports. Caller frees. (Through the method rather than ms_render, to compare masks.) */
static uint64_t *method_masks(const ms_scene *sc, const char *method, int k, int size, ms_isa cap, ms_isa *kernel,
                              ms_isa *trav, int *n_out)
{
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc->tri, sc->n_tris, 1), 0);
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, sc, &bvh, size, size, k);
    ctx.isa_cap = cap;
    const ms_shadow_method *sm = ms_find_shadow_method(method);
    assert_non_null(sm);
    assert_non_null(sm->isa_used);
    char err[256];
    void *ss = NULL;
    int nq;
    ms_shadow_query *q = tu_frame_queries(&ctx, size, &nq);
    const size_t mw = (size_t)ctx.mask_words;
    uint64_t *front = calloc((size_t)nq * mw + 1, sizeof *front), *vis = calloc((size_t)nq * mw + 1, sizeof *vis);
    assert_non_null(front);
    assert_non_null(vis);
    for (int i = 0; i < nq; i++) ms_front_mask(&ctx, &q[i], NULL, front + i * mw);
    assert_int_equal(sm->create(&ctx, &ss, err, sizeof err), 0);
    sm->isa_used(ss, kernel, trav);
    uint64_t cnt[MS_MAX_COUNTERS] = { 0 };
    assert_int_equal(sm->visibility(ss, &ctx, q, nq, front, vis, cnt), 0);
    sm->destroy(ss);
    free(front);
    free(q);
    ms_bvh_free(&bvh);
    *n_out = nq;
    return vis;
}

/* The portable scalar paths (kernels and traversal, forced by the context's ISA cap, and reported as
 * scalar) give the same V as the SIMD ones; the raytrace instances the same masks. */
static void test_scalar_paths_match(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    for (int m = 0; m < 3; m++) {
        ms_isa kern_simd, trav_simd, kern_scalar, trav_scalar;
        int n_simd, n_scalar;
        uint64_t *simd = method_masks(&sc, kernels[m], 32, 80, tu_isa_cap(), &kern_simd, &trav_simd, &n_simd);
        uint64_t *scalar = method_masks(&sc, kernels[m], 32, 80, MS_ISA_SCALAR, &kern_scalar, &trav_scalar, &n_scalar);
        assert_int_equal(kern_scalar, MS_ISA_SCALAR);
        assert_int_equal(trav_scalar, MS_ISA_SCALAR);
        /* uncapped: the kernel and the traversal run the CPU's best */
        if (tu_isa_cap() == MS_ISA_AUTO) {
            assert_int_equal(trav_simd, ms_cpu_isa());
            assert_int_equal(kern_simd, ms_cpu_isa());
        }
        assert_int_equal(n_simd, n_scalar);
        /* per point: samples whose visibility differs (at most one, at a tie), and points that differ */
        long differ = 0, beyond_one = 0;
        for (int i = 0; i < n_simd; i++) {
            int d = 0;
            for (int w = 0; w < 16; w++) d += __builtin_popcountll(simd[16 * i + w] ^ scalar[16 * i + w]);
            differ += d > 0;
            beyond_one += d > 1;
        }
        printf("default scene %s: scalar vs %s kernel / %s traversal differ %ld of %d pixels\n", kernels[m],
               ms_isa_name(kern_simd), ms_isa_name(trav_simd), differ, n_simd);
        assert_int_equal(beyond_one, 0);
        assert_true((double)differ <= 0.001 * (double)n_simd);
        free(simd);
        free(scalar);
    }
    /* The reference tracer's packets, one source compiled per ISA: the very same masks. */
    for (int cap = MS_ISA_SCALAR; cap <= MS_ISA_AVX512; cap++) {
        if (!tu_isa_allowed((ms_isa)cap) || cap > (int)ms_cpu_isa()) continue;
        ms_isa kern, trav, kern0, trav0;
        int n, n0;
        uint64_t *ref = method_masks(&sc, "raytrace", 32, 48, MS_ISA_SCALAR, &kern0, &trav0, &n0);
        uint64_t *got = method_masks(&sc, "raytrace", 32, 48, (ms_isa)cap, &kern, &trav, &n);
        assert_int_equal(kern0, MS_ISA_SCALAR);
        assert_int_equal(kern, cap);
        assert_int_equal(n, n0);
        assert_memory_equal(ref, got, (size_t)n * 16 * sizeof *ref);
        printf("raytrace %s packets: masks identical to the portable ones on %d points\n", ms_isa_name(kern), n);
        free(ref);
        free(got);
    }
    ms_scene_free(&sc);
}

/* Through the public options: the cap reaches kernel and traversal, the stats name what ran, and a
 * zeroed options struct renders with the defaults. */
static void test_options_isa_and_defaults(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_render_options o;
    memset(&o, 0, sizeof o);
    o.width = o.height = 48;
    ms_frame a, b;
    char err[256];
    assert_int_equal(ms_render(&sc, &o, &a, err, sizeof err), 0);
    assert_string_equal(a.stats.method, MS_DEFAULT_METHOD);
    assert_int_equal(a.stats.samples, sc.samples);
    assert_string_equal(a.stats.kernel_isa, ms_isa_name(ms_cpu_isa()));
    assert_string_equal(a.stats.traversal_isa, ms_isa_name(ms_cpu_isa()));
    o.isa = MS_ISA_SCALAR;
    assert_int_equal(ms_render(&sc, &o, &b, err, sizeof err), 0);
    assert_string_equal(b.stats.kernel_isa, "scalar");
    assert_string_equal(b.stats.traversal_isa, "scalar");
    agreement g = compare(&a, &b, sc.samples);
    assert_int_equal(g.beyond_one, 0);
    ms_frame_free(&a);
    ms_frame_free(&b);
    o.method = "raytrace";   /* its packets are compiled per ISA too, under the same cap */
    assert_int_equal(ms_render(&sc, &o, &a, err, sizeof err), 0);
    assert_string_equal(a.stats.kernel_isa, "scalar");
    if (ms_method_available("embree") == 1) {
        ms_frame_free(&a);
        o.method = "embree";   /* Embree dispatches for itself */
        assert_int_equal(ms_render(&sc, &o, &a, err, sizeof err), 0);
        assert_string_equal(a.stats.kernel_isa, "none");
    }
    ms_frame_free(&a);
    ms_scene_free(&sc);
}

static void test_default_scene_agrees(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    const int samples[] = { 256, 1024 };
    agree_on_scene(&sc, "default", samples, 2, 96);
    ms_scene_free(&sc);
}

static void real_scene(const char *rel, int size)
{
    ms_scene sc;
    tu_shared_scene_load(rel, &sc);
    const int samples[] = { 1024 };
    agree_on_scene(&sc, rel, samples, 1, size);
    ms_scene_free(&sc);
}

/* 64x64 frames: the shared scenes' full frames are checked the same way by bench_scenes. */
static void test_sponza_agrees(void **state) { (void)state; real_scene("dabrovic-sponza/dabrovic-sponza.json", 64); }
static void test_sibenik_agrees(void **state) { (void)state; real_scene("sibenik/sibenik.json", 64); }
static void test_bunny_agrees(void **state) { (void)state; real_scene("stanford-bunny/stanford-bunny.json", 64); }

/* The pixel-class counters of the block traversal against the frame's own planes: a pixel is lit when V = 1,
 * in umbra when V = 0 with front samples, in penumbra otherwise, facing away with no front sample (the
 * frame's front count); the classes' tests and rasterizations add up to the method's totals, and only
 * penumbra and umbra pixels rasterize. On the bunny (a closed scanned mesh with its shadow on a ground) at
 * 256 and 1024 samples. */
static void test_pixel_class_counters(void **state)
{
    (void)state;
    if (!tu_have_shared_scenes()) skip();
    char path[4096], err[512];
    ms_scene sc;
    assert_int_equal(ms_scene_load(tu_shared_scene(path, sizeof path, "stanford-bunny/stanford-bunny.json"), &sc, err, sizeof err), 0);
    const int samples[] = { 256, 1024 };
    for (int si = 0; si < 2; si++) {
        ms_frame f;
        ms_render_options o;
        tu_render_options_default(&o);
        o.method = "scanline";
        o.samples = samples[si];
        o.width = o.height = 64;
        tu_render_ok(&sc, &o, &f);
        uint64_t lit = 0, umbra = 0, pen = 0, away = 0;
        for (size_t i = 0; i < (size_t)f.width * (size_t)f.height; i++) {
            if (f.vis[i] < 0.0f) continue;
            if (!f.front[i]) away++;
            else if (f.vis[i] == 1.0f) lit++;
            else if (f.vis[i] == 0.0f) umbra++;
            else pen++;
        }
        const ms_stats *st = &f.stats;
        assert_int_equal(tu_stat_counter(st, "pixels_traced_edge_on"), 0);
        assert_int_equal(tu_stat_counter(st, "pixels_lit"), lit);
        assert_int_equal(tu_stat_counter(st, "pixels_umbra"), umbra);
        assert_int_equal(tu_stat_counter(st, "pixels_penumbra"), pen);
        assert_int_equal(tu_stat_counter(st, "pixels_facing_away"), away);
        assert_true(pen > 0 && umbra > 0 && lit > 0);
        const uint64_t tests = tu_stat_counter(st, "tests_lit") + tu_stat_counter(st, "tests_umbra") + tu_stat_counter(st, "tests_penumbra");
        const uint64_t rast = tu_stat_counter(st, "rasterized_lit") + tu_stat_counter(st, "rasterized_umbra") +
                              tu_stat_counter(st, "rasterized_penumbra");
        assert_int_equal(tests, tu_stat_counter(st, "tri_pixel_tests"));
        assert_int_equal(rast, tu_stat_counter(st, "triangles_rasterized"));
        /* A rasterization that cleared a sample leaves the pixel short of lit; one that cleared none is possible
         * anywhere, but a lit pixel rasterizes only such. */
        assert_true(tu_stat_counter(st, "rasterized_penumbra") > 0 && tu_stat_counter(st, "rasterized_umbra") > 0);
        printf("bunny N=%d: lit %llu, umbra %llu, penumbra %llu, facing away %llu pixels; tests per pixel %.1f / %.1f / %.1f\n",
               samples[si], (unsigned long long)lit, (unsigned long long)umbra, (unsigned long long)pen, (unsigned long long)away,
               (double)tu_stat_counter(st, "tests_lit") / (double)lit, (double)tu_stat_counter(st, "tests_umbra") / (double)umbra,
               (double)tu_stat_counter(st, "tests_penumbra") / (double)pen);
        ms_frame_free(&f);
    }
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_quad_agrees_with_raytrace),
        cmocka_unit_test(test_quad_exact),
        cmocka_unit_test(test_open_quad_both_sides),
        cmocka_unit_test(test_scalar_paths_match),
        cmocka_unit_test(test_options_isa_and_defaults),
        cmocka_unit_test(test_default_scene_agrees),
        cmocka_unit_test(test_sponza_agrees),
        cmocka_unit_test(test_sibenik_agrees),
        cmocka_unit_test(test_bunny_agrees),
        cmocka_unit_test(test_pixel_class_counters),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
