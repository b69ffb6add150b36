/* The viewer's standard mode (viewer/index.html, viewer/live_lights.mjs) against microshadow's full frame: the glb's
 * own materials lit by live three.js lights made from the bake's lights (extras.microshadow.lights), each light's
 * direct light times its shadowmask channel at TEXCOORD_1, exposed by the exposure the bake wrote for the standard
 * frame. A small textured scene (a checkered ground, a striped box, a floating plate; a rect light overhead and a
 * sphere light low at the side, so that the two shadows fall apart) is baked to a glb by the CLI, shot in standard
 * mode with no exposure given, and compared with the CLI's own PNG of the scene (standard shading, its automatic
 * exposure) over the pixels the frame hits: luminance correlation >= 0.9, mean brightness within 20%. The control:
 * the same screenshot with the shadowmask ignored (shadowmask=off: the lights unshadowed) must correlate below 0.9,
 * so that the shadows, not the textures and the light falloff alone, carry the agreement.
 * Skipped with a message without node, Chromium or viewer/node_modules. */
#include "testutil.h"
#include "glb_read.h"
#include "viewer.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A w x w texture of n x n squares alternating between linear grey levels lo and hi (stripes: columns only). */
static void write_pattern(const char *path, int w, int n, float lo, float hi, int stripes, const float tint[3])
{
    float *rgb = malloc((size_t)w * w * 3 * sizeof *rgb);
    assert_non_null(rgb);
    for (int y = 0; y < w; y++)
        for (int x = 0; x < w; x++) {
            const int odd = stripes ? (x * n / w) & 1 : ((x * n / w) + (y * n / w)) & 1;
            for (int c = 0; c < 3; c++) rgb[3 * ((size_t)y * w + x) + c] = (odd ? hi : lo) * tint[c];
        }
    tu_write_texture_png(path, w, w, rgb);
    free(rgb);
}

/* The scene in dir, its path into json. */
static void write_scene(const char *dir, char *json, size_t n)
{
    char p[1024];
    static const float grey[3] = { 1, 1, 1 }, warm[3] = { 1, 0.55f, 0.3f };
    write_pattern(tu_path(p, sizeof p, dir, "checker.png"), 64, 8, 0.55f, 0.75f, 0, grey);
    write_pattern(tu_path(p, sizeof p, dir, "stripes.png"), 64, 4, 0.3f, 0.9f, 1, warm);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "m.mtl"),
        "newmtl ground\nKd 1 1 1\nmap_Kd checker.png\nPr 0.6\nPm 0\n"
        "newmtl box\nKd 1 1 1\nmap_Kd stripes.png\nPr 0.5\nPm 0\n"
        "newmtl plate\nKd 0.25 0.4 0.75\nPr 0.7\nPm 0\n"), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "ground.obj"),
        "mtllib m.mtl\nusemtl ground\nv -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nvt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\n"
        "f 1/1 2/2 3/3 4/4\n"), 0);
    /* each face with its own UVs 0-1 */
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "box.obj"),
        "mtllib m.mtl\nusemtl box\n"
        "v 0.3 0 -0.5\nv 1.3 0 -0.5\nv 1.3 0 0.5\nv 0.3 0 0.5\nv 0.3 1 -0.5\nv 1.3 1 -0.5\nv 1.3 1 0.5\nv 0.3 1 0.5\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
        "f 1/1 2/2 3/3 4/4\nf 8/1 7/2 6/3 5/4\nf 1/1 5/2 6/3 2/4\nf 2/1 6/2 7/3 3/4\nf 3/1 7/2 8/3 4/4\nf 4/1 8/2 5/3 1/4\n"), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "plate.obj"),
        "mtllib m.mtl\nusemtl plate\nv -1.7 1 -0.2\nv -1.7 1 1.8\nv 0.1 1 1.8\nv 0.1 1 -0.2\n"
        "f 1 2 3 4\nf 4 3 2 1\n"), 0);
    assert_int_equal(tu_write_file(tu_path(json, n, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"ground.obj\"},{\"file\":\"box.obj\"},{\"file\":\"plate.obj\"}],"
        "\"camera\":{\"eye\":[0,4.5,5.5],\"target\":[0,0.3,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":160,\"height\":120},"
        "\"lights\":[{\"corner\":[-1.5,6,-1.5],\"edge_s\":[3,0,0],\"edge_t\":[0,0,3],\"emission\":[1,1,1]},"
        "{\"shape\":\"sphere\",\"center\":[3.2,1.1,0.9],\"radius\":0.25,\"emission\":[4,3.6,3.2]}]}"), 0);
}

static void test_standard_mode_matches_frame(void **st)
{
    (void)st;
    if (!tu_have_browser()) skip();
    const char *dir = tu_tmpdir("viewer_standard");
    char json[1024], glb[1024], lm[1024], frame[1024], vis[1024], shot[1024], off[1024], line[512];
    write_scene(dir, json, sizeof json);
    tu_path(glb, sizeof glb, dir, "scene.glb");
    tu_path(lm, sizeof lm, dir, "lm.exr");
    const char *bake[] = { "bake", json, "--size", "512", "--samples", "256", "-o", lm, "--gltf", glb, "--quiet", NULL };
    assert_int_equal(tu_run_cli(bake, line, sizeof line), 0);
    /* the glb names both lights, and the shadowmask's channels name them */
    tu_glb g;
    assert_int_equal(tu_glb_read(glb, &g), 0);
    const cJSON *ms = cJSON_GetObjectItem(cJSON_GetObjectItem(tu_glb_item(&g, "scenes", 0), "extras"), "microshadow");
    const cJSON *lights = cJSON_GetObjectItem(ms, "lights");
    assert_int_equal(cJSON_GetArraySize(lights), 2);
    assert_string_equal(cJSON_GetObjectItem(cJSON_GetArrayItem(lights, 0), "shape")->valuestring, "rect");
    assert_string_equal(cJSON_GetObjectItem(cJSON_GetArrayItem(lights, 1), "shape")->valuestring, "sphere");
    assert_true(cJSON_GetObjectItem(cJSON_GetArrayItem(lights, 1), "radius")->valuedouble == 0.25);
    tu_glb_free(&g);
    /* the full frame as the CLI makes it (its own exposure), its hits from --vis (which also keeps it at one primary
     * sample per pixel, as the viewer's canvas has no anti-aliasing) */
    tu_path(frame, sizeof frame, dir, "frame.png");
    tu_path(vis, sizeof vis, dir, "frame.pfm");
    const char *render[] = { json, "--samples", "256", "-o", frame, "--vis", vis, "--quiet", NULL };
    assert_int_equal(tu_run_cli(render, line, sizeof line), 0);
    int W, H;
    float *hit = tu_read_pfm(vis, &W, &H);
    assert_non_null(hit);
    tu_path(shot, sizeof shot, dir, "standard.png");
    tu_path(off, sizeof off, dir, "unshadowed.png");
    tu_screenshot(glb, json, shot, "--mode standard");
    tu_screenshot(glb, json, off, "--mode standard --shadowmask off");
    double *a = tu_png_luminance(shot, W, H), *c = tu_png_luminance(off, W, H), *b = tu_png_luminance(frame, W, H);
    const tu_lum_agreement ag = tu_lum_compare(a, b, hit, (size_t)W * H), ctl = tu_lum_compare(c, b, hit, (size_t)W * H);
    printf("viewer (standard mode, shadowmasked live lights, no exposure given) vs `microshadow SCENE`: %ld hit pixels, "
           "luminance correlation %.4f, mean brightness %.4f vs %.4f (ratio %.4f)\n", ag.n, ag.corr, ag.mean_a, ag.mean_b,
           ag.ratio);
    printf("control, shadowmask=off (the lights unshadowed): correlation %.4f, ratio %.4f\n", ctl.corr, ctl.ratio);
    assert_true(ag.n > W * H / 3);
    assert_true(ag.corr >= 0.9);
    assert_true(ag.ratio >= 0.8 && ag.ratio <= 1.2);
    assert_true(ctl.corr < 0.9);
    free(a);
    free(b);
    free(c);
    free(hit);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_standard_mode_matches_frame),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
