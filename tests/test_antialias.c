/* Pixel anti-aliasing (ms_render_options.aa, docs/antialiasing.md):
 *   - a pixel straddling a half-plane silhouette edge gets the area-weighted average of the two surfaces'
 *     shading: an orthographic camera looks down on a ground and, above it, a plate covering x < e; a light
 *     between the two lights the ground fully (V = 1: nothing between) and has no sample in front of the
 *     plate (V = 0, black). With the edge at half the pixel (K = 4) or a quarter (K = 16) the hand-computed
 *     V is 1/2 resp. 3/4 and the shading the ground's (rendered without the plate at each primary sample's
 *     point) times its share of the pixel;
 *   - K = 1 (and 0) is the frame without anti-aliasing bit for bit (aa = 0 against aa = 1; the CLI's picture
 *     was compared with the unmodified binary when this was written);
 *   - every method agrees with raytrace under K = 4, full and split, as without anti-aliasing;
 *   - split: each primary sample gets N/K samples; the scene file's render.aa; bad values refused;
 *   - the CLI: anti-aliased (K = 4) by default, K = 1 when the V or S plane is written, unless --aa says. */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 8   /* the edge scene: 8 x 8 pixels over x, z in [-1, 1] */

/* Ground at y = 0; with plate, a plate at y = 1 over x < edge; a rect light at y = 0.5 over x in [2, 3]
 * emitting downwards; an orthographic camera from above, image x along world x. */
static void edge_scene(ms_scene *sc, int plate, float edge)
{
    const float tri[4][9] = {
        { -10, 0, -10, 10, 0, 10, 10, 0, -10 }, { -10, 0, -10, -10, 0, 10, 10, 0, 10 },
        { -10, 1, -10, edge, 1, 10, edge, 1, -10 }, { -10, 1, -10, -10, 1, 10, edge, 1, 10 } };
    memset(sc, 0, sizeof *sc);
    sc->n_tris = plate ? 4 : 2;
    sc->tri = malloc(sc->n_tris * 9 * sizeof *sc->tri);
    assert_non_null(sc->tri);
    memcpy(sc->tri, tri, sc->n_tris * 9 * sizeof *sc->tri);
    sc->camera = (ms_camera){ { 0, 10, 0 }, { 0, 0, 0 }, { 0, 0, -1 }, 0.0f, W, W, MS_CAMERA_ORTHOGRAPHIC, 0, 2.0f };
    sc->light = (ms_light){ { 2, 0.5f, -0.5f }, { 1, 0, 0 }, { 0, 0, 1 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    sc->samples = 256;
}

static void render(const ms_scene *sc, const char *method, int aa, int split, int w, ms_frame *f)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.threads = 2;
    o.aa = aa;
    o.aa_split = split;
    o.width = o.height = w;
    tu_render_ok(sc, &o, f);
}

/* Pixel column 4 covers x in [0, 0.25]: the edge at x0 + frac * 0.25. */
static void check_edge(int aa, float frac)
{
    const int s = (int)lround(sqrt((double)aa));
    const float edge = 0.25f * frac;
    ms_scene with, without;
    edge_scene(&with, 1, edge);
    edge_scene(&without, 0, edge);
    ms_frame f, ground;
    render(&with, "raytrace", aa, 0, W, &f);
    render(&without, "raytrace", 1, 0, W * s, &ground);   /* the ground at every primary sample's point */
    assert_int_equal(f.width, W);
    assert_int_equal(f.height, W);
    /* Hand-computed: the primary samples at x0 + (i + 1/2) / s of the pixel; those left of the edge see the
     * plate (black, V = 0), the others the ground (V = 1). */
    int on_plate = 0;
    for (int i = 0; i < s; i++) on_plate += (i + 0.5) / s < frac;
    const double share = (double)(s - on_plate) / s;   /* the ground's area in the pixel */
    assert_true(fabs(share - (1.0 - frac)) < 1e-9);    /* the edge lies on a strata boundary: exact areas */
    for (int y = 0; y < W; y++) {
        const size_t p = (size_t)y * W + 4;
        assert_float_equal(f.vis[p], (float)share, 1e-7);
        assert_float_equal(f.shadow[p], (float)share, 1e-7);
        double want[3] = { 0, 0, 0 };
        for (int j = 0; j < s; j++)
            for (int i = on_plate; i < s; i++)
                for (int k = 0; k < 3; k++) want[k] += ground.rgb[3 * ((size_t)(y * s + j) * (W * s) + 4 * s + i) + k];
        for (int k = 0; k < 3; k++) {
            want[k] /= (double)aa;
            assert_true(want[k] > 0.0);
            assert_true(fabs(f.rgb[3 * p + k] - want[k]) <= 1e-5 * want[k]);
        }
        /* A pixel wholly on the plate is black with V = 0; wholly on the ground, the ground's mean. */
        const size_t left = (size_t)y * W + 2, right = (size_t)y * W + 6;
        assert_true(f.vis[left] == 0.0f && f.rgb[3 * left] == 0.0f && f.rgb[3 * left + 1] == 0.0f);
        assert_true(f.vis[right] == 1.0f && f.shadow[right] == 1.0f);
        double mean = 0.0;
        for (int j = 0; j < s; j++)
            for (int i = 0; i < s; i++) mean += ground.rgb[3 * ((size_t)(y * s + j) * (W * s) + 6 * s + i)];
        mean /= (double)aa;
        assert_true(fabs(f.rgb[3 * right] - mean) <= 1e-5 * mean);
    }
    ms_frame_free(&f);
    ms_frame_free(&ground);
    ms_scene_free(&with);
    ms_scene_free(&without);
}

static void test_half_plane_edge(void **st)
{
    (void)st;
    check_edge(4, 0.5f);
    check_edge(16, 0.25f);
    check_edge(16, 0.75f);
}

static void frames_equal(const ms_frame *a, const ms_frame *b)
{
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    const size_t n = (size_t)a->width * a->height;
    assert_memory_equal(a->vis, b->vis, n * sizeof *a->vis);
    assert_memory_equal(a->shadow, b->shadow, n * sizeof *a->shadow);
    assert_memory_equal(a->shadow_spec, b->shadow_spec, n * sizeof *a->shadow_spec);
    assert_memory_equal(a->front, b->front, n * sizeof *a->front);
    assert_memory_equal(a->rgb, b->rgb, 3 * n * sizeof *a->rgb);
    assert_true(a->exposure == b->exposure);
}

static void test_k1_unchanged(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    const char *const methods[] = { "scanline", "raytrace", "hpc" };
    for (int m = 0; m < 3; m++) {
        ms_frame a, b;
        render(&sc, methods[m], 0, 0, 48, &a);
        render(&sc, methods[m], 1, 1, 48, &b);   /* split means nothing with one primary sample */
        frames_equal(&a, &b);
        assert_int_equal(b.stats.samples_per_pixel, 1024);
        ms_frame_free(&a);
        ms_frame_free(&b);
    }
    ms_scene_free(&sc);
}

static void test_methods_agree(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    for (int split = 0; split < 2; split++) {
        ms_frame rt;
        render(&sc, "raytrace", 4, split, 24, &rt);
        assert_int_equal(rt.width, 24);
        long pen = 0;
        for (int i = 0; i < 24 * 24; i++) pen += rt.vis[i] > 0.0f && rt.vis[i] < 1.0f;
        assert_true(pen > 20);   /* the comparison sees penumbrae */
        for (const char *const *m = ms_method_names(); *m; m++) {
            if (!strcmp(*m, "raytrace")) continue;
            ms_render_options o;
            tu_render_options_default(&o);
            o.method = *m;
            o.threads = 2;
            o.aa = 4;
            o.aa_split = split;
            o.width = o.height = 24;
            ms_frame f;
            char err[512];
            if (ms_render(&sc, &o, &f, err, sizeof err)) {   /* a method needing another pattern */
                fprintf(stderr, "%s: skipped (%s)\n", *m, err);
                continue;
            }
            /* the stats count the shading grid and say how it relates to the output */
            assert_int_equal(f.stats.aa, 4);
            assert_int_equal(f.stats.width, 2 * f.width);
            assert_int_equal(f.stats.height, 2 * f.height);
            const tu_agreement a = tu_compare_frames(&f, &rt);
            fprintf(stderr, "aa 4%s: %s vs raytrace: %ld of %ld pixels differ, max |dV| %.2f samples\n",
                    split ? " split" : "", *m, a.differ, a.pixels, a.max_steps);
            assert_int_equal(a.miss_mismatch, 0);
            assert_int_equal(a.beyond_one, 0);
            assert_int_equal(a.s_beyond, 0);
            ms_frame_free(&f);
        }
        ms_frame_free(&rt);
    }
    ms_scene_free(&sc);
}

/* Split: N/K samples per primary sample; a wholly lit pixel is V = 1 either way and the pixel's front
 * count is N; the full variant's front is N too, its shadow rays K times the split's. */
static void test_split(void **st)
{
    (void)st;
    ms_scene sc;
    edge_scene(&sc, 1, 0.125f);
    sc.samples = 1024;   /* 256 each when split */
    ms_frame full, split;
    render(&sc, "raytrace", 4, 0, W, &full);
    render(&sc, "raytrace", 4, 1, W, &split);
    assert_int_equal(full.stats.samples_per_pixel, 1024);
    assert_int_equal(split.stats.samples_per_pixel, 1024);
    const size_t right = 6;
    assert_true(full.vis[right] == 1.0f && split.vis[right] == 1.0f);
    assert_int_equal(full.front[right], 1024);
    assert_int_equal(split.front[right], 1024);
    assert_int_equal(full.front[4], 512);   /* half the primary samples on the plate, no sample in front */
    assert_int_equal(split.front[4], 512);
    assert_true(full.stats.shadow_rays == 4 * split.stats.shadow_rays);
    ms_frame_free(&full);
    ms_frame_free(&split);
    ms_scene_free(&sc);
}

static void test_bad_values(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    ms_render_options o;
    tu_render_options_default(&o);
    o.width = o.height = 16;
    ms_frame f;
    char err[512];
    const int bad[] = { 2, 3, 25, -1 };
    for (int i = 0; i < 4; i++) {
        o.aa = bad[i];
        assert_int_not_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
        assert_non_null(strstr(err, "aa must be 1, 4, 9 or 16"));
    }
    o.aa = 16;   /* 256 grid samples split 16 ways: 16 each, not a grid */
    o.aa_split = 1;
    o.samples = 256;
    assert_int_not_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
    assert_non_null(strstr(err, "aa_split"));
    /* The output is at most MS_MAX_IMAGE_SIZE wide; the frame rendered for it may be 4 times that. */
    o.width = MS_MAX_IMAGE_SIZE;
    o.height = 1;
    o.aa = 16;
    o.aa_split = 0;
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
    assert_int_equal(f.width, MS_MAX_IMAGE_SIZE);
    assert_int_equal(f.height, 1);
    ms_frame_free(&f);
    o.width = MS_MAX_IMAGE_SIZE + 1;
    assert_int_not_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
    assert_non_null(strstr(err, "width and height"));
    ms_scene_free(&sc);
}

/* render.aa in a scene file: the frame of opt.aa = 0 is that of opt.aa = 4; 3 is refused naming the file. */
static void test_scene_file(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("test_antialias");
    char obj[512], json[512], bad[512], text[2048];
    tu_path(obj, sizeof obj, dir, "quad.obj");
    tu_path(json, sizeof json, dir, "aa.json");
    tu_path(bad, sizeof bad, dir, "bad.json");
    assert_int_equal(tu_write_file(obj, "v -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\nv -1 1 -1\nv 1 1 -1\nv 1 1 1\nv -1 1 1\n"
                                        "f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n"), 0);
    const char *fmt = "{ \"meshes\": [{ \"file\": \"quad.obj\" }], \"camera\": { \"eye\": [0, 8, 9], \"target\": [0, 0, 0], \"up\": [0, 1, 0],"
                      " \"fov_y\": 50, \"width\": 20, \"height\": 16 }, \"light\": { \"corner\": [-1, 4, -1], \"edge_s\": [2, 0, 0],"
                      " \"edge_t\": [0, 0, 2] }, \"render\": { \"samples\": 256, \"aa\": %d } }";
    snprintf(text, sizeof text, fmt, 4);
    assert_int_equal(tu_write_file(json, text), 0);
    snprintf(text, sizeof text, fmt, 3);
    assert_int_equal(tu_write_file(bad, text), 0);
    ms_scene sc;
    char err[512];
    if (ms_scene_load(json, &sc, err, sizeof err)) fail_msg("%s", err);
    assert_int_equal(sc.aa, 4);
    ms_frame a, b;
    render(&sc, "scanline", 0, 0, 0, &a);
    render(&sc, "scanline", 4, 0, 0, &b);
    frames_equal(&a, &b);
    assert_int_equal(a.width, 20);
    ms_frame c;
    render(&sc, "scanline", 1, 0, 0, &c);   /* the option over the file */
    assert_true(memcmp(a.rgb, c.rgb, 20 * 16 * 3 * sizeof(float)) != 0);
    ms_frame_free(&a);
    ms_frame_free(&b);
    ms_frame_free(&c);
    ms_scene_free(&sc);
    assert_int_not_equal(ms_scene_load(bad, &sc, err, sizeof err), 0);
    assert_non_null(strstr(err, "bad.json"));
    assert_non_null(strstr(err, "render.aa"));
}

/* The CLI: anti-aliased by default (the EXR's V is the library's at aa = 4), one primary sample when the V
 * plane is asked for (the PFM is the library's at aa = 1), --aa overrides, bad values refused. */
static void test_cli(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("test_antialias_cli");
    char exr[512], pfm[512], png[512], err[512];
    tu_path(exr, sizeof exr, dir, "a.exr");
    tu_path(pfm, sizeof pfm, dir, "v.pfm");
    tu_path(png, sizeof png, dir, "p.png");
    ms_scene sc;
    assert_int_equal(ms_scene_showcase(&sc), 0);
    ms_frame f1, f4;
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = "raytrace";
    o.samples = 256;
    o.width = 24;
    o.height = 16;
    o.threads = 2;
    o.aa = 1;
    tu_render_ok(&sc, &o, &f1);
    o.aa = 4;
    tu_render_ok(&sc, &o, &f4);
    const char *base[] = { "--method", "raytrace", "--samples", "256", "--width", "24", "--height", "16", "--threads", "2",
                           "--quiet", "-o", exr, NULL, NULL, NULL, NULL };
    if (tu_run_cli(base, err, sizeof err)) fail_msg("CLI: %s", err);
    float v[24 * 16];
    assert_int_equal(tu_read_exr_channel(exr, "V0", 24, 16, v), 0);
    assert_memory_equal(v, f4.vis, sizeof v);
    base[12] = png;
    base[13] = "--vis";
    base[14] = pfm;
    if (tu_run_cli(base, err, sizeof err)) fail_msg("CLI: %s", err);
    int w, h;
    float *pv = tu_read_pfm(pfm, &w, &h);
    assert_non_null(pv);
    assert_memory_equal(pv, f1.vis, sizeof v);
    free(pv);
    base[15] = "--aa=4";   /* asked for: the planes anti-aliased too */
    if (tu_run_cli(base, err, sizeof err)) fail_msg("CLI: %s", err);
    pv = tu_read_pfm(pfm, &w, &h);
    assert_non_null(pv);
    assert_memory_equal(pv, f4.vis, sizeof v);
    free(pv);
    const char *bad[] = { "--aa", "2", "--quiet", "-o", png, NULL };
    assert_int_equal(tu_run_cli(bad, err, sizeof err), 2);
    assert_non_null(strstr(err, "--aa"));
    ms_frame_free(&f1);
    ms_frame_free(&f4);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_half_plane_edge), cmocka_unit_test(test_k1_unchanged),
        cmocka_unit_test(test_methods_agree),   cmocka_unit_test(test_split),
        cmocka_unit_test(test_bad_values),      cmocka_unit_test(test_scene_file),
        cmocka_unit_test(test_cli),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
