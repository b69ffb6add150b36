/* --method auto (MS_AUTO_METHOD): the rule of src/shadow/registry.c, ms_auto_method, checked from the
 * outside. The oracle for each case is the named method run with the same options: "auto" must give its
 * frame byte for byte (V, S, front counts) and name it in the stats.
 *   - the grid pattern: scanline;
 *   - the interleaved pattern: mft;
 *   - the stratified pattern (micro-raster methods cannot take it): embree when compiled in, else raytrace;
 *   - a procedural scene that does not fit the memory budget materialised: hpc, which streams it, where the
 *     default method is refused (MS_ERR_BUDGET);
 *   - the points API takes the name too. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "testutil.h"

static void render_or_fail(const ms_scene *sc, const ms_render_options *o, ms_frame *f)
{
    char err[1024];
    const int rc = ms_render(sc, o, f, err, sizeof err);
    if (rc) fprintf(stderr, "%s: %s\n", o->method, err);
    assert_int_equal(rc, 0);
}

static void assert_same_frame(const ms_frame *a, const ms_frame *b)
{
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    const size_t n = (size_t)a->width * a->height * (size_t)(a->n_lights ? a->n_lights : 1);
    assert_memory_equal(a->vis, b->vis, n * sizeof *a->vis);
    assert_memory_equal(a->shadow, b->shadow, n * sizeof *a->shadow);
    assert_memory_equal(a->front, b->front, n * sizeof *a->front);
}

/* auto under options o equals `expect` under the same options. */
static void auto_equals(const ms_scene *sc, ms_render_options o, const char *expect)
{
    ms_frame fa, fe;
    o.method = MS_AUTO_METHOD;
    render_or_fail(sc, &o, &fa);
    o.method = expect;
    render_or_fail(sc, &o, &fe);
    printf("auto, %s pattern: %s (expected %s)\n", ms_pattern_name(o.pattern), fa.stats.method, expect);
    assert_string_equal(fa.stats.method, expect);
    assert_same_frame(&fa, &fe);
    ms_frame_free(&fa);
    ms_frame_free(&fe);
}

static void test_patterns(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_render_options o;
    tu_render_options_default(&o);
    o.width = o.height = 48;
    o.samples = 256;
    o.threads = 2;
    o.pattern = MS_PATTERN_GRID;
    auto_equals(&sc, o, "scanline");
    o.pattern = MS_PATTERN_INTERLEAVED;
    auto_equals(&sc, o, "mft");
    o.pattern = MS_PATTERN_STRATIFIED;
    auto_equals(&sc, o, ms_method_available("embree") == 1 ? "embree" : "raytrace");
    ms_scene_free(&sc);
}

static void test_procedural_over_budget(void **state)
{
    (void)state;
    char path[1024];
    tu_path(path, sizeof path, tu_tmpdir("test_auto_method"), "flowers.json");
    assert_int_equal(tu_write_file(path,
        "{\"procedural\": {\"type\": \"flowers\", \"triangles\": 400000, \"seed\": 1}, "
        "\"camera\": {\"eye\": [0, 14, 18], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 60, \"width\": 32, \"height\": 32}, "
        "\"light\": {\"corner\": [-1, 16, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2]}, \"render\": {\"samples\": 256}}"), 0);
    ms_scene sc;
    char err[1024];
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    ms_render_options o;
    tu_render_options_default(&o);
    o.threads = 2;
    o.max_memory = 8u << 20;   /* 400K triangles materialised with their BVH need several times this */
    ms_frame f;
    const int rc = ms_render(&sc, &o, &f, err, sizeof err);
    printf("the default method over 8 MiB: %d (%s)\n", rc, err);
    assert_int_equal(rc, MS_ERR_BUDGET);
    auto_equals(&sc, o, "hpc");
    ms_scene_free(&sc);
}

static void test_points(void **state)
{
    (void)state;
    ms_scene sc;
    tu_make_quad(&sc);
    ms_accel *a = NULL;
    char err[512];
    assert_int_equal(ms_accel_build(&sc, 2, &a, err, sizeof err), MS_OK);
    /* A row of ground points across the occluder's shadow. */
    float pos[3 * 16], nrm[3 * 16];
    for (int i = 0; i < 16; i++) {
        pos[3 * i] = -4.0f + 0.5f * (float)i; pos[3 * i + 1] = 0.0f; pos[3 * i + 2] = 0.3f;
        nrm[3 * i] = 0.0f; nrm[3 * i + 1] = 1.0f; nrm[3 * i + 2] = 0.0f;
    }
    ms_points pts;
    memset(&pts, 0, sizeof pts);
    pts.n = 16;
    pts.position = pos;
    pts.normal = nrm;
    ms_points_options po;
    memset(&po, 0, sizeof po);
    po.samples = 256;
    float va[16], ve[16];
    po.method = MS_AUTO_METHOD;
    assert_int_equal(ms_visibility_points(a, NULL, &pts, &po, va, NULL, NULL, NULL, err, sizeof err), MS_OK);
    po.method = "scanline";
    assert_int_equal(ms_visibility_points(a, NULL, &pts, &po, ve, NULL, NULL, NULL, err, sizeof err), MS_OK);
    assert_memory_equal(va, ve, sizeof va);
    int lit = 0, dark = 0;
    for (int i = 0; i < 16; i++) { lit += va[i] > 0.99f; dark += va[i] < 0.01f; }
    assert_true(lit > 0 && dark > 0);   /* the row crosses the shadow: the comparison means something */
    ms_accel_free(a);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_patterns),
        cmocka_unit_test(test_procedural_over_budget),
        cmocka_unit_test(test_points),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
