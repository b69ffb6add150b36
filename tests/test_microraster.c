/* Soft shadows by micro-rasterization against the reference ray tracer on identical samples:
 * scanline, bounds and hierarchical must give raytrace's V at every pixel except where a sample sits
 * within rounding of an edge (at most 1/N per such pixel, at most 0.1% of pixels); the scalar paths
 * too; the Quad scene against its exact V; an open quad shadows from both sides. */
#include "testutil.h"
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
    ms_render_options_default(&o);
    o.method = method;
    o.samples = samples;
    o.width = o.height = size;
    char err[512];
    int rc = ms_render(sc, &o, f, err, sizeof err);
    if (rc) fprintf(stderr, "render %s: %s\n", method, err);
    assert_int_equal(rc, 0);
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
            assert_true((double)a.differ <= 0.001 * (double)a.pixels);
            ms_frame_free(&f);
        }
        ms_frame_free(&ref);
    }
}

/* The Quad: 20x20 ground at y=0, 4x4 occluder at y=2, 2x2 light at y=6 (as ../shared/scenes/quad). */
static void make_quad(ms_scene *sc)
{
    static const float tri[4][9] = {
        { -10, 0, -10, 10, 0, 10, 10, 0, -10 }, { -10, 0, -10, -10, 0, 10, 10, 0, 10 },
        { -2, 2, -2, 2, 2, 2, 2, 2, -2 }, { -2, 2, -2, -2, 2, 2, 2, 2, 2 } };
    memset(sc, 0, sizeof *sc);
    sc->tri = malloc(sizeof tri);
    memcpy(sc->tri, tri, sizeof tri);
    sc->n_tris = 4;
    sc->camera = (ms_camera){ { 0, 10, 12 }, { 0, 0, 0 }, { 0, 1, 0 }, 60.0f, 96, 96 };
    sc->light = (ms_light){ { -1, 6, -1 }, { 2, 0, 0 }, { 0, 0, 2 }, { 1, 1, 1 } };
    sc->samples = 1024;
}

static void test_quad_agrees_with_raytrace(void **state)
{
    (void)state;
    ms_scene sc;
    make_quad(&sc);
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
    make_quad(&sc);
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
        make_quad(&sc);
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

/* The portable scalar paths (kernels and traversal) give the same V as the SIMD ones. */
static void test_scalar_paths_match(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    for (int k = 0; k < 3; k++) {
        ms_frame simd, scalar;
        unsetenv("MS_FORCE_SCALAR");
        render_ok(&sc, kernels[k], 1024, 80, &simd);
        setenv("MS_FORCE_SCALAR", "1", 1);
        render_ok(&sc, kernels[k], 1024, 80, &scalar);
        unsetenv("MS_FORCE_SCALAR");
        agreement a = compare(&simd, &scalar, 1024);
        printf("default scene %s: scalar vs SIMD differ %ld pixels\n", kernels[k], a.differ);
        assert_int_equal(a.beyond_one, 0);
        assert_true((double)a.differ <= 0.001 * (double)a.pixels);
        ms_frame_free(&simd);
        ms_frame_free(&scalar);
    }
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
    if (!tu_have_shared_scenes()) skip();
    char path[4096];
    ms_scene sc;
    char err[512];
    int rc = ms_scene_load(tu_shared_scene(path, sizeof path, rel), &sc, err, sizeof err);
    if (rc) fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, 0);
    const int samples[] = { 1024 };
    agree_on_scene(&sc, rel, samples, 1, size);
    ms_scene_free(&sc);
}

static void test_sponza_agrees(void **state) { (void)state; real_scene("dabrovic-sponza/dabrovic-sponza.json", 96); }
static void test_sibenik_agrees(void **state) { (void)state; real_scene("sibenik/sibenik.json", 96); }
static void test_bunny_agrees(void **state) { (void)state; real_scene("stanford-bunny/stanford-bunny.json", 96); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_quad_agrees_with_raytrace),
        cmocka_unit_test(test_quad_exact),
        cmocka_unit_test(test_open_quad_both_sides),
        cmocka_unit_test(test_scalar_paths_match),
        cmocka_unit_test(test_default_scene_agrees),
        cmocka_unit_test(test_sponza_agrees),
        cmocka_unit_test(test_sibenik_agrees),
        cmocka_unit_test(test_bunny_agrees),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
