/* Lights in scene files and frames (docs/lights.md; docs/design.md, "Units"), each against an oracle of its own:
 *   - two lights: V, S and front of each light equal the single-light renders, the image their sum;
 *   - units: watts and lumens against hand-computed radiances;
 *   - bad light JSON: exit 2 and one line naming the file and the problem;
 *   - outputs per light: --vis to EXR has one channel per light, to PFM light 0; the EXR's channels hold the
 *     frame's planes;
 *   - a textured rect light (its right half emitting): V unchanged, S the texel-weighted ratio.
 * The light shapes' oracles (disk, sphere, triangle) are test_lights.c's. */
#include "testutil.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "light/pattern.h"
#include "visibility/disk_mask.h"
#include "core/cpu.h"
#include "accel/bvh.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- many lights ---- */

static void test_two_lights_equal_single(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    ms_light two[2];
    two[0] = sc.light;
    two[0].emission = (ms_vec3){ 1.0f, 0.5f, 0.25f };
    memset(&two[1], 0, sizeof two[1]);
    assert_int_equal(ms_light_disk(&two[1], (ms_vec3){ 3, 4, 1 }, (ms_vec3){ -0.5f, -1, 0 }, 1.0f), 0);
    two[1].emission = (ms_vec3){ 0.2f, 0.4f, 2.0f };
    ms_render_options o;
    tu_render_options_default(&o);
    o.width = o.height = 32;
    o.threads = 2;
    char err[256];
    const char *methods[] = { "raytrace", "scanline", "hpc", "mft", NULL };
    const size_t npix = 32 * 32;
    for (int mi = 0; methods[mi]; mi++) {
        o.method = methods[mi];
        ms_frame single[2], both;
        for (int l = 0; l < 2; l++) {
            sc.light = two[l];
            sc.lights = NULL;
            sc.n_lights = 0;
            assert_int_equal(ms_render(&sc, &o, &single[l], err, sizeof err), 0);
            assert_true(single[l].n_lights == 1);
        }
        sc.lights = two;
        sc.n_lights = 2;
        sc.light = two[0];
        assert_int_equal(ms_render(&sc, &o, &both, err, sizeof err), 0);
        assert_int_equal(both.n_lights, 2);
        for (int l = 0; l < 2; l++)
            for (size_t i = 0; i < npix; i++) {
                assert_true(both.vis[l * npix + i] == single[l].vis[i]);
                assert_true(both.shadow[l * npix + i] == single[l].shadow[i]);
                assert_int_equal(both.front[l * npix + i], single[l].front[i]);
            }
        for (size_t i = 0; i < 3 * npix; i++) {
            const float sum = single[0].rgb[i] + single[1].rgb[i];
            assert_true(fabsf(both.rgb[i] - sum) <= 1e-6f * fabsf(sum) + 1e-12f);
        }
        ms_frame_free(&both);
        ms_frame_free(&single[0]);
        ms_frame_free(&single[1]);
        sc.lights = NULL;
        sc.n_lights = 0;
    }
    sc.light = two[0];
    ms_scene_free(&sc);
}

/* ---- scene files: lights, units, bad input ---- */

static char g_dir[4096];

static const char *scene_with(const char *name, const char *lights)
{
    static char path[4096];
    char text[4096], p[4096];
    tu_write_file(tu_path(p, sizeof p, g_dir, "ok.obj"),
                  "v -10 0 -10\nv 10 0 -10\nv 10 0 10\nv -10 0 10\nv -2 2 -2\nv 2 2 -2\nv 2 2 2\nv -2 2 2\n"
                  "f 1 3 2\nf 1 4 3\nf 5 7 6\nf 5 8 7\n");
    snprintf(text, sizeof text,
             "{ \"meshes\": [ { \"file\": \"ok.obj\" } ],\n"
             " \"camera\": { \"eye\": [0, 10, 12], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 60,"
             " \"width\": 16, \"height\": 16 },\n %s,\n \"render\": { \"samples\": 256 } }\n", lights);
    tu_path(path, sizeof path, g_dir, name);
    assert_int_equal(tu_write_file(path, text), 0);
    return path;
}

static void test_units(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("lights_units"));
    const char *path = scene_with("units.json",
        "\"lights\": [ { \"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2], \"power\": 100 },\n"
        "  { \"shape\": \"disk\", \"center\": [0, 6, 0], \"normal\": [0, -1, 0], \"radius\": 0.5, \"lumens\": [1000, 500, 0] },\n"
        "  { \"shape\": \"disk\", \"center\": [1, 5, 0], \"normal\": [0, -2, 0], \"radius\": 2, \"emission\": [3, 2, 1] },\n"
        "  { \"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2] } ]");
    ms_scene sc;
    char err[512];
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    assert_int_equal((int)sc.n_lights, 4);
    size_t n;
    const ms_light *L = ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 4);
    /* 100 W from a 2 m x 2 m Lambertian emitter: L = 100 / (pi * 4) = 7.957747 W sr^-1 m^-2 */
    assert_float_equal(L[0].emission.x, 7.957747f, 1e-5f);
    assert_float_equal(L[0].emission.z, 7.957747f, 1e-5f);
    assert_int_equal(L[0].shape, MS_LIGHT_RECT);
    /* 1000 lm from a disk of radius 0.5 m (area pi/4): 1000 / (pi * pi / 4) = 405.2847 cd m^-2 */
    assert_float_equal(L[1].emission.x, 405.2847f, 2e-3f);
    assert_float_equal(L[1].emission.y, 202.6424f, 1e-3f);
    assert_float_equal(L[1].emission.z, 0.0f, 0.0f);
    assert_int_equal(L[1].shape, MS_LIGHT_DISK);
    /* radiance as given; the disk's square is 4 x 4 centred on (1, 5, 0), emitting towards -y */
    assert_float_equal(L[2].emission.y, 2.0f, 0.0f);
    const float cx = L[2].corner.x + 0.5f * (L[2].edge_s.x + L[2].edge_t.x);
    const float cy = L[2].corner.y + 0.5f * (L[2].edge_s.y + L[2].edge_t.y);
    assert_float_equal(cx, 1.0f, 1e-6f);
    assert_float_equal(cy, 5.0f, 1e-6f);
    const float ny = L[2].edge_s.z * L[2].edge_t.x - L[2].edge_s.x * L[2].edge_t.z;
    assert_float_equal(ny, -16.0f, 1e-4f);
    assert_float_equal(ms_light_area(&L[2]), (float)M_PI * 4.0f, 1e-5f);
    /* a sphere of radius 0.5 m emitting 100 W: area pi, L = 100 / (pi * pi) = 10.13212 */
    ms_light sph;
    memset(&sph, 0, sizeof sph);
    ms_light_sphere(&sph, (ms_vec3){ 0, 0, 0 }, 0.5f);
    assert_float_equal(ms_light_radiance_from(&sph, (ms_vec3){ 100, 100, 100 }, MS_UNITS_WATTS).x, 10.13212f, 1e-4f);
    /* no unit given: radiance 1 */
    assert_float_equal(L[3].emission.x, 1.0f, 0.0f);
    ms_scene_free(&sc);
    /* A triangle of legs 2 and 2 (area 2) emitting 100 W: L = 100 / (2 pi) = 15.91549; it emits towards
     * cross(b - a, c - a) = (0, -4, 0), down. */
    path = scene_with("units_tri.json",
        "\"light\": { \"shape\": \"triangle\", \"vertices\": [[-1, 6, -1], [1, 6, -1], [-1, 6, 1]], \"power\": 100 }");
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    assert_int_equal(sc.light.shape, MS_LIGHT_TRIANGLE);
    assert_float_equal(ms_light_area(&sc.light), 2.0f, 1e-6f);
    assert_float_equal(sc.light.emission.x, 15.91549f, 1e-4f);
    assert_float_equal(sc.light.corner.y, 6.0f, 0.0f);
    assert_float_equal(sc.light.edge_s.x, 2.0f, 0.0f);
    assert_float_equal(sc.light.edge_t.z, 2.0f, 0.0f);
    assert_float_equal(sc.light.edge_s.z * sc.light.edge_t.x - sc.light.edge_s.x * sc.light.edge_t.z, -4.0f, 0.0f);
    ms_scene_free(&sc);
    /* An ellipse inscribed in a 3 x 1 rectangle (area 3 pi / 4) emitting 100 W: a disk over the parallelogram as
     * given, L = 100 / (pi * 3 pi / 4) = 13.50949; its samples are the disk mask's */
    path = scene_with("units_ellipse.json",
        "\"light\": { \"shape\": \"ellipse\", \"corner\": [-1.5, 6, -0.5], \"edge_s\": [3, 0, 0], \"edge_t\": [0, 0, 1], "
        "\"power\": 100 }");
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    assert_int_equal(sc.light.shape, MS_LIGHT_DISK);
    assert_float_equal(sc.light.corner.x, -1.5f, 0.0f);
    assert_float_equal(sc.light.edge_s.x, 3.0f, 0.0f);
    assert_float_equal(sc.light.edge_t.z, 1.0f, 0.0f);
    assert_float_equal(ms_light_area(&sc.light), 3.0f * (float)M_PI / 4.0f, 1e-6f);
    assert_float_equal(sc.light.emission.x, 13.50949f, 1e-4f);
    assert_true(ms_light_shape_contains(sc.light.shape, 0.5f, 0.5f));
    assert_false(ms_light_shape_contains(sc.light.shape, 0.95f, 0.95f));
    ms_scene_free(&sc);
}

/* The CLI on a bad light: exit 2, one line naming the file and the problem. */
static void expect_bad(const char *name, const char *lights, const char *needle)
{
    const char *path = scene_with(name, lights);
    char out[4096], errbuf[2048];
    tu_path(out, sizeof out, g_dir, "out.png");
    const char *args[] = { path, "--quiet", "-o", out, NULL };
    tu_run_result res;
    const int rc = tu_run_cli_ex(args, NULL, errbuf, sizeof errbuf, &res);
    if (rc != 2 || res.lines != 1 || !strstr(errbuf, name) || !strstr(errbuf, needle))
        fprintf(stderr, "%s: exit %d, %d lines: %s (wanted \"%s\")\n", name, rc, res.lines, errbuf, needle);
    assert_int_equal(rc, 2);
    assert_int_equal(res.lines, 1);
    assert_non_null(strstr(errbuf, name));
    assert_non_null(strstr(errbuf, needle));
    assert_false(tu_file_exists(out));
}

static void test_bad_light_json(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("lights_bad"));
    const char *rect = "\"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2]";
    char buf[1024];
    snprintf(buf, sizeof buf, "\"light\": { \"shape\": \"hexagon\", %s }", rect);
    expect_bad("b1.json", buf, "light.shape must be \"rect\", \"disk\", \"sphere\", \"triangle\", \"sun\" or \"ellipse\" (got \"hexagon\")");
    expect_bad("b19.json", "\"light\": { \"shape\": \"triangle\", \"vertices\": [[0, 6, 0], [1, 6, 0], [2, 6, 0]] }",
               "light.vertices must not be collinear");
    expect_bad("b20.json", "\"light\": { \"shape\": \"triangle\", \"vertices\": [[0, 6, 0], [1, 6, 0]] }",
               "light.vertices must be an array of 3 points");
    expect_bad("b21.json", "\"light\": { \"shape\": \"triangle\", \"vertices\": [[0, 6, 0], [1, 6, 0], [0, 6, \"x\"]] }",
               "light.vertices[2] must be an array of 3 finite numbers");
    expect_bad("b22.json", "\"light\": { \"shape\": \"triangle\", \"corner\": [0, 6, 0] }", "light.vertices is missing");
    expect_bad("b2.json", "\"light\": { \"shape\": \"disk\", \"center\": [0, 6, 0], \"normal\": [0, -1, 0] }", "light.radius is missing");
    expect_bad("b3.json", "\"light\": { \"shape\": \"disk\", \"center\": [0, 6, 0], \"normal\": [0, -1, 0], \"radius\": -1 }",
               "light.radius must be in (0,");
    expect_bad("b4.json", "\"light\": { \"shape\": \"disk\", \"center\": [0, 6, 0], \"normal\": [0, 0, 0], \"radius\": 1 }",
               "light.normal must not be zero");
    snprintf(buf, sizeof buf, "\"light\": { %s, \"emission\": 1, \"power\": 5 }", rect);
    expect_bad("b5.json", buf, "give one of \"emission\", \"power\" and \"lumens\"");
    snprintf(buf, sizeof buf, "\"light\": { %s }, \"lights\": [ { %s } ]", rect, rect);
    expect_bad("b6.json", buf, "either \"light\" or \"lights\"");
    expect_bad("b7.json", "\"lights\": []", "\"lights\" must be an array of 1 to 64");
    expect_bad("b8.json", "\"lights\": { \"corner\": [0, 0, 0] }", "\"lights\" must be an array of 1 to 64");
    snprintf(buf, sizeof buf, "\"lights\": [ { %s }, 3 ]", rect);
    expect_bad("b9.json", buf, "lights[1] must be an object");
    snprintf(buf, sizeof buf, "\"lights\": [ { %s }, { \"corner\": [0, 6, 0], \"edge_s\": [1, 0, 0], \"edge_t\": [2, 0, 0] } ]", rect);
    expect_bad("b10.json", buf, "lights[1] has zero area");
    snprintf(buf, sizeof buf, "\"light\": { %s, \"lumens\": -3 }", rect);
    expect_bad("b11.json", buf, "light.lumens must not be negative");
    snprintf(buf, sizeof buf, "\"light\": { %s, \"power\": \"bright\" }", rect);
    expect_bad("b12.json", buf, "light.power must be a number or an array of 3 numbers");
    snprintf(buf, sizeof buf, "\"lights\": [ { \"shape\": \"disk\", \"center\": [0, 6, 0], \"normal\": [0, -1, 0], \"radius\": 1e39 } ]");
    expect_bad("b13.json", buf, "lights[0].radius");
    expect_bad("b17.json", "\"light\": { \"shape\": \"sphere\", \"center\": [0, 6, 0] }", "light.radius is missing");
    expect_bad("b18.json", "\"light\": { \"shape\": \"sphere\", \"center\": [0, 6, 0], \"radius\": 1, \"texture\": \"a.png\" }",
               "a sphere light cannot be textured");
    snprintf(buf, sizeof buf, "\"light\": { %s, \"texture\": \"nothere.png\" }", rect);
    expect_bad("b14.json", buf, "texture file not found");
    char p[4096];
    tu_write_file(tu_path(p, sizeof p, g_dir, "notpng.png"), "this is not a PNG\n");
    snprintf(buf, sizeof buf, "\"light\": { %s, \"texture\": \"notpng.png\" }", rect);
    expect_bad("b15.json", buf, "not a readable PNG image");
    snprintf(buf, sizeof buf, "\"light\": { %s, \"texture\": 7 }", rect);
    expect_bad("b16.json", buf, "light.texture must be the path of a PNG or EXR image");
}

/* --vis to EXR: one channel per light; to PFM: light 0. */
static void test_vis_outputs(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("lights_out"));
    const char *path = scene_with("two.json",
        "\"lights\": [ { \"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2] },\n"
        "  { \"shape\": \"disk\", \"center\": [3, 4, 0], \"normal\": [-0.5, -1, 0], \"radius\": 1 } ]");
    char pfm[4096], exr[4096], err[512];
    tu_path(pfm, sizeof pfm, g_dir, "v.pfm");
    tu_path(exr, sizeof exr, g_dir, "s.exr");
    const char *args[] = { path, "--quiet", "--vis", pfm, "--shadow", exr, NULL };
    assert_int_equal(tu_run_cli(args, err, sizeof err), 0);
    assert_true(tu_file_exists(exr));
    int w, h;
    float *v = tu_read_pfm(pfm, &w, &h);
    assert_non_null(v);
    ms_scene sc;
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    ms_render_options o;
    ms_render_options_default(&o);
    ms_frame f;
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
    assert_int_equal(w, f.width);
    for (int i = 0; i < w * h; i++) assert_true(v[i] == f.vis[i]);   /* light 0 */
    free(v);
    ms_frame_free(&f);
    ms_scene_free(&sc);
}

/* The per-light EXR channels hold the frame's planes: V0, V1 / S0, S1; no plain "V". */
static void test_exr_channels_per_light(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("lights_exr"));
    const char *path = scene_with("two.json",
        "\"lights\": [ { \"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2] },\n"
        "  { \"shape\": \"disk\", \"center\": [3, 4, 0], \"normal\": [-0.5, -1, 0], \"radius\": 1 } ]");
    ms_scene sc;
    char err[512], v[4096], sh[4096];
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    ms_render_options o;
    tu_render_options_default(&o);
    ms_frame f;
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
    assert_int_equal(f.n_lights, 2);
    assert_int_equal(ms_write_vis(&f, tu_path(v, sizeof v, g_dir, "v.exr"), err, sizeof err), 0);
    assert_int_equal(ms_write_shadow(&f, tu_path(sh, sizeof sh, g_dir, "s.exr"), err, sizeof err), 0);
    const size_t npix = (size_t)f.width * f.height;
    float *img = malloc(npix * sizeof *img);
    assert_non_null(img);
    const char *names[2][2] = { { "V0", "V1" }, { "S0", "S1" } };
    for (int l = 0; l < 2; l++) {
        assert_int_equal(tu_read_exr_channel(v, names[0][l], f.width, f.height, img), 0);
        assert_memory_equal(img, f.vis + l * npix, npix * sizeof *img);
        assert_int_equal(tu_read_exr_channel(sh, names[1][l], f.width, f.height, img), 0);
        assert_memory_equal(img, f.shadow + l * npix, npix * sizeof *img);
    }
    assert_int_equal(tu_read_exr_channel(v, "V", f.width, f.height, img), -1);
    /* the two lights differ somewhere (the channels are not one plane twice) */
    long differ = 0;
    for (size_t i = 0; i < npix; i++) differ += f.vis[i] != f.vis[npix + i];
    assert_true(differ > 0);
    free(img);
    ms_frame_free(&f);
    ms_scene_free(&sc);
}

/* ---- textured lights ---- */

/* A rect light whose right half (s >= 1/2) emits and left half is black: V unchanged, S the texel-weighted
 * ratio recomputed here from the visible masks, every method's S equal to raytrace's, and the shading of an
 * unshadowed point near the exact irradiance of the light's right half. */
static void test_textured_rect(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("lights_texture"));
    char png[4096];
    const float tex[6] = { 0, 0, 0, 1, 1, 1 };
    tu_write_texture_png(tu_path(png, sizeof png, g_dir, "half.png"), 2, 1, tex);
    const char *path = scene_with("tex.json",
        "\"light\": { \"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2], \"texture\": \"half.png\" }");
    ms_scene sc;
    char err[512];
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    assert_non_null(sc.light.texture);
    assert_int_equal(sc.light.texture_width, 2);
    assert_float_equal(sc.light.texture[0], 0.0f, 0.0f);
    assert_float_equal(sc.light.texture[3], 1.0f, 0.0f);
    /* Internal API: masks and S of raytrace on a 16 x 16 frame, S recomputed from the masks. */
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 1), 0);
    const int size = 16, k = 32;
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, &sc, &bvh, size, size, k);
    const ms_primary_method *pm = ms_find_primary_method("bvh");
    void *ps = NULL, *ss = NULL;
    assert_int_equal(pm->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit hits[16 * 16];
    pm->trace(ps, &ctx, 0, 0, size, size, hits);
    pm->destroy(ps);
    ms_shadow_query q[16 * 16];
    int nq = 0;
    for (int i = 0; i < size * size; i++)
        if (hits[i].prim != UINT32_MAX) tu_query_from_hit(&q[nq++], &hits[i], i % size, i / size);
    const int mw = ctx.mask_words;
    uint64_t *front = calloc((size_t)nq * mw, 8), *vis = calloc((size_t)nq * mw, 8);
    float *pts = malloc(3 * 1024 * sizeof *pts);
    assert_true(front && vis && pts);
    for (int i = 0; i < nq; i++) ms_front_mask(&ctx, &q[i], NULL, front + i * mw);
    const ms_shadow_method *rt = ms_find_shadow_method("raytrace");
    uint64_t cnt[MS_MAX_COUNTERS] = { 0 };
    assert_int_equal(rt->create(&ctx, &ss, err, sizeof err), 0);
    assert_int_equal(rt->visibility(ss, &ctx, q, nq, front, vis, cnt), 0);
    rt->destroy(ss);
    int penumbra_half = 0;
    for (int i = 0; i < nq; i++) {
        float v, s;
        ms_resolve_vs(&ctx, &q[i], NULL, front + i * mw, vis + i * mw, &v, &s);
        ms_pattern_points(MS_PATTERN_GRID, &sc.light, k, q[i].px, q[i].py, 0, pts);
        double wf = 0, wv = 0;
        int nf = 0, nv = 0;
        for (int j = 0; j < k * k; j++) {
            if (!ms_mask_get(front + i * mw, j)) continue;
            const double d[3] = { pts[3 * j] - q[i].p[0], pts[3 * j + 1] - q[i].p[1], pts[3 * j + 2] - q[i].p[2] };
            const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            /* cos at the light: its normal is -y; the texel: s from the world x (corner -1, edge 2) */
            const double w = fmax(d[0] * q[i].n[0] + d[1] * q[i].n[1] + d[2] * q[i].n[2], 0.0) * fmax(d[1], 0.0) / (r2 * r2);
            const double sx = (pts[3 * j] + 1.0) / 2.0;
            const double tau = fabs(sx - 0.5) < 1e-5 ? -1.0 : sx >= 0.5 ? 1.0 : 0.0;
            if (tau < 0) continue;   /* on the texel boundary: either texel */
            nf++;
            wf += w * tau;
            if (ms_mask_get(vis + i * mw, j)) { nv++; wv += w * tau; }
        }
        const int vis_n = ms_mask_count(vis + i * mw, mw), front_n = ms_mask_count(front + i * mw, mw);
        if (vis_n == 0 || vis_n == front_n) { assert_float_equal(s, v, 0.0f); continue; }
        assert_float_equal(v, (float)vis_n / (float)front_n, 0.0f);   /* V unweighted */
        const double want = wf > 0 ? wv / wf : v;
        if (fabs(s - want) > 1e-3) fprintf(stderr, "pixel %u,%u: S %.6f, recomputed %.6f\n", q[i].px, q[i].py, s, want);
        assert_true(fabs(s - want) <= 1e-3);
        penumbra_half += fabs(s - v) > 0.05;   /* the texture changed S */
        (void)nv;
    }
    assert_true(penumbra_half > 0);
    free(front); free(vis); free(pts);
    ms_bvh_free(&bvh);
    /* Frames: every method's S equals raytrace's; an unshadowed point sees about half the light's irradiance. */
    ms_render_options o;
    tu_render_options_default(&o);
    o.width = o.height = 32;
    o.threads = 2;
    ms_frame ref;
    tu_every_method_as_raytrace(&sc, &o, "textured rect frame", &ref, NULL, NULL);
    /* The shading's texture factor: E_unshadowed of the whole rect times the weighted mean texel, against
     * the exact irradiance of the right half alone (the polygon formula), at every receiver of the small
     * frame above; the ratio estimator's error shrinks with N (measured here at N = 1024). */
    ms_light right = sc.light;
    right.texture = NULL;
    right.corner.x += 1.0f;
    right.edge_s.x = 1.0f;
    double worst = 0;
    for (int i = 0; i < nq; i++) {
        float t[3];
        ms_light_texture_mean(&ctx, &q[i], t);
        const double est = (double)ms_light_irradiance(&sc.light, q[i].p, q[i].n) * t[0];
        const double exact = ms_light_irradiance(&right, q[i].p, q[i].n);
        if (exact > 1e-3) worst = fmax(worst, fabs(est - exact) / exact);
        assert_float_equal(t[0], t[1], 0.0f);
    }
    printf("textured light: texture-weighted E vs the exact half-light E, worst relative error %.4f\n", worst);
    assert_true(worst < 0.01);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_lights_equal_single),
        cmocka_unit_test(test_units),
        cmocka_unit_test(test_bad_light_json),
        cmocka_unit_test(test_vis_outputs),
        cmocka_unit_test(test_exr_channels_per_light),
        cmocka_unit_test(test_textured_rect),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
