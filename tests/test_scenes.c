/* Every shared scene (every .json one folder below ../shared/scenes) loads and renders with raytrace at 64x64 and 256
 * samples; V is -1 or k/256 for an integer k in [0, 256]; the stats agree with the scene. Skips (77)
 * when the folder is absent. The quad scene's file holds the geometry test_quad_exact builds. */
#include "testutil.h"
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_scenes;

static void render_one(const char *json)
{
    char err[1024];
    ms_scene s;
    if (ms_scene_load(json, &s, err, sizeof err)) fail_msg("%s", err);
    assert_true(s.n_tris > 0);
    ms_render_options opt;
    tu_render_options_default(&opt);
    opt.method = "raytrace";
    opt.samples = 256;
    opt.width = 64;
    opt.height = 64;
    ms_frame fr;
    if (ms_render(&s, &opt, &fr, err, sizeof err)) fail_msg("%s: %s", json, err);
    int visible = 0, lit = 0;
    for (int i = 0; i < 64 * 64; i++) {
        float v = fr.vis[i];
        if (v == -1.0f) continue;
        /* V = visible / front: a fraction of the pixel's front count */
        float k = v * (float)fr.front[i];
        if (!(v >= 0.0f && v <= 1.0f && fr.front[i] <= 256 && fabsf(k - roundf(k)) < 1e-3f))
            fail_msg("%s: pixel %d has V=%.9g with %d samples in front", json, i, v, fr.front[i]);
        visible++;
        lit += v > 0;
    }
    assert_int_equal(fr.stats.visible_pixels, (uint64_t)visible);
    assert_int_equal(fr.stats.triangles, s.n_tris);
    print_message("%s: %zu triangles, %d visible pixels, %d lit, load %.2fs build %.2fs shadow %.2fs\n", json, s.n_tris,
                  visible, lit, s.load_s, fr.stats.build_s, fr.stats.shadow_s);
    assert_true(visible > 0);
    assert_true(lit > 0);
    ms_frame_free(&fr);
    ms_scene_free(&s);
    g_scenes++;
}

static void test_all_scenes(void **st)
{
    (void)st;
    char root[4096];
    tu_shared_scene(root, sizeof root, "");
    DIR *d = opendir(root);
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.') continue;
        char sub[8192];
        snprintf(sub, sizeof sub, "%s/%s", root, e->d_name);
        DIR *d2 = opendir(sub);
        if (!d2) continue;
        struct dirent *f;
        while ((f = readdir(d2))) {
            size_t n = strlen(f->d_name);
            if (n > 5 && strcmp(f->d_name + n - 5, ".json") == 0) {
                char json[16384];
                snprintf(json, sizeof json, "%s/%s", sub, f->d_name);
                render_one(json);
            }
        }
        closedir(d2);
    }
    closedir(d);
    assert_true(g_scenes >= 1);
}

static void test_quad_file_matches(void **st)
{
    (void)st;
    char json[4096], err[512];
    tu_shared_scene(json, sizeof json, "quad/quad.json");
    if (!tu_file_exists(json)) { print_message("no quad/quad.json; skipped\n"); return; }
    ms_scene s;
    if (ms_scene_load(json, &s, err, sizeof err)) fail_msg("%s", err);
    assert_int_equal(s.n_tris, 4);
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (size_t i = 0; i < 12; i++)
        for (int a = 0; a < 3; a++) {
            float x = s.tri[3 * i + a];
            lo[a] = x < lo[a] ? x : lo[a];
            hi[a] = x > hi[a] ? x : hi[a];
        }
    assert_true(lo[0] == -10 && hi[0] == 10 && lo[1] == 0 && hi[1] == 2 && lo[2] == -10 && hi[2] == 10);
    assert_true(s.light.corner.x == -1 && s.light.corner.y == 6 && s.light.corner.z == -1);
    assert_true(s.light.edge_s.x == 2 && s.light.edge_t.z == 2);
    assert_true(s.camera.eye.y == 10 && s.camera.eye.z == 12 && s.camera.fov_y == 60);
    ms_scene_free(&s);
}

int main(int argc, char **argv)
{
    if (!tu_have_shared_scenes()) return 77;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_quad_file_matches),
        cmocka_unit_test(test_all_scenes),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
