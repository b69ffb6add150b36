/* The baked glTF in a real browser: viewer/index.html (three.js, MOZ_lightmap on uv1, the scene file's camera)
 * in headless Chromium (viewer/screenshot.mjs, puppeteer-core), against microshadow's own frame of the same
 * camera. Both show the diffuse radiance albedo / pi * E (the viewer: MeshBasicMaterial, whose light map three.js
 * shades as base colour * lightmap * intensity / pi; the frame: no materials, so no specular term), exposed by
 * the frame's exposure, clipped and sRGB-encoded. Over the pixels the frame hits, the luminance of the two
 * (linearised) correlates >= 0.95; the mean relative error is reported.
 * Without an exposure given, on coloured, partly metallic and glossy materials: the viewer's diffuse mode
 * takes the exposure the bake wrote into the glb (the frame's own automatic exposure of diffuse shading,
 * checked equal to ms_render's), and its screenshot against the PNG of `microshadow SCENE --shading diffuse`
 * (base colour x E x S / pi, no specular) correlates >= 0.95 in luminance with mean brightness within 20%.
 * As a user would: a mouse drag orbits the view (another picture, the scene still in it) and the key M gives
 * the standard mode's picture pixel for pixel.
 * Skipped with a message without node, Chromium or viewer/node_modules (scripts/install-deps.sh installs
 * them). */
#include "testutil.h"
#include "glb_read.h"
#include "viewer.h"
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The scene of both tests in dir, its path into json: a floor, a box standing on it, a plate above it casting a
 * soft shadow, a rect light. With materials: a grey glossy floor, a red half-metallic box, a blue plate. */
static void write_scene(const char *dir, int materials, char *json, size_t n)
{
    static const char *const mesh[3][2] = {
        { "floor", "v -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nf 1 2 3 4\n" },
        { "box", "v 0.5 0 -0.5\nv 1.5 0 -0.5\nv 1.5 0 0.5\nv 0.5 0 0.5\nv 0.5 1 -0.5\nv 1.5 1 -0.5\nv 1.5 1 0.5\nv 0.5 1 0.5\n"
                 "f 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n" },
        { "plate", "v -1.6 1.2 -0.6\nv -1.6 1.2 0.6\nv -0.4 1.2 0.6\nv -0.4 1.2 -0.6\nf 1 2 3 4\nf 4 3 2 1\n" },
    };
    char p[1024], name[64], text[1024];
    if (materials)
        assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "m.mtl"),
            "newmtl floor\nKd 0.7 0.7 0.65\nPr 0.3\nPm 0\nnewmtl box\nKd 0.8 0.25 0.15\nPr 0.4\nPm 0.5\n"
            "newmtl plate\nKd 0.2 0.35 0.8\nPr 0.6\nPm 0\n"), 0);
    for (int m = 0; m < 3; m++) {
        snprintf(name, sizeof name, "%s.obj", mesh[m][0]);
        if (materials) snprintf(text, sizeof text, "mtllib m.mtl\nusemtl %s\n%s", mesh[m][0], mesh[m][1]);
        else snprintf(text, sizeof text, "%s", mesh[m][1]);
        assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, name), text), 0);
    }
    assert_int_equal(tu_write_file(tu_path(json, n, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"floor.obj\"},{\"file\":\"box.obj\"},{\"file\":\"plate.obj\"}],"
        "\"camera\":{\"eye\":[0,4.5,5.5],\"target\":[0,0.3,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":160,\"height\":120},"
        "\"light\":{\"corner\":[-0.6,4,-0.6],\"edge_s\":[1.2,0,0],\"edge_t\":[0,0,1.2],\"emission\":[1,1,1]}}"), 0);
}

/* The scene baked (512^2, xatlas UVs, 256 samples) into lm and written as dir/scene.glb (its path into glb). */
static void bake_glb(const ms_scene *sc, const char *dir, ms_lightmap *lm, char *glb, size_t n)
{
    char err[512] = "";
    ms_bake_options bo;
    tu_bake_options(&bo, 512, -1, 256);
    assert_int_equal(ms_bake(sc, NULL, &bo, lm, err, sizeof err), MS_OK);
    tu_path(glb, n, dir, "scene.glb");
    assert_int_equal(ms_bake_write_gltf(sc, lm, NULL, glb, err, sizeof err), MS_OK);
}

static void test_viewer_matches_frame(void **st)
{
    (void)st;
    if (!tu_have_browser()) skip();
    const char *dir = tu_tmpdir("bake_viewer");
    char json[1024], glb[1024], shot[1024], err[512] = "";
    write_scene(dir, 0, json, sizeof json);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_lightmap lm;
    bake_glb(&sc, dir, &lm, glb, sizeof glb);
    ms_render_options ro;
    tu_render_options_default(&ro);
    ro.samples = 256;
    ms_frame fr;
    assert_int_equal(ms_render(&sc, &ro, &fr, err, sizeof err), 0);
    tu_path(shot, sizeof shot, dir, "shot.png");
    char exposure[64];
    snprintf(exposure, sizeof exposure, "--exposure %.9g", (double)fr.exposure);
    tu_screenshot(glb, json, shot, exposure);
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    assert_true(png_image_begin_read_from_file(&img, shot));
    img.format = PNG_FORMAT_RGB;
    const int W = fr.width, H = fr.height;
    assert_int_equal((int)img.width, W);
    assert_int_equal((int)img.height, H);
    uint8_t *px = malloc((size_t)W * H * 3);
    assert_non_null(px);
    assert_true(png_image_finish_read(&img, NULL, px, 0, NULL));
    /* luminance over the hit pixels: the screenshot linearised, the frame exposed and clipped as its PNG */
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, rel = 0;
    long n = 0, nrel = 0;
    for (int i = 0; i < W * H; i++) {
        if (fr.vis[i] < 0.0f) continue;
        double a = 0, b = 0;
        static const double wy[3] = { 0.2126, 0.7152, 0.0722 };
        for (int c = 0; c < 3; c++) {
            a += wy[c] * tu_srgb_to_linear(px[3 * i + c] / 255.0);
            b += wy[c] * fmin(fmax(fr.rgb[3 * i + c] * fr.exposure, 0.0), 1.0);
        }
        sa += a; sb += b; saa += a * a; sbb += b * b; sab += a * b;
        n++;
        if (b > 0.05) { rel += fabs(a - b) / b; nrel++; }
    }
    const double cov = sab / n - (sa / n) * (sb / n), va = saa / n - (sa / n) * (sa / n), vb = sbb / n - (sb / n) * (sb / n);
    const double corr = cov / sqrt(va * vb);
    printf("viewer vs frame (exposure %.6g given): %ld hit pixels, luminance correlation %.4f, mean relative error %.4f over "
           "the %ld pixels above 0.05, mean luminance %.4f vs %.4f\n", (double)fr.exposure, n, corr, rel / (double)nrel, nrel,
           sa / n, sb / n);
    assert_true(n > W * H / 3);
    assert_true(corr >= 0.95);
    free(px);
    ms_frame_free(&fr);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

static void test_viewer_exposes_as_frame(void **st)
{
    (void)st;
    if (!tu_have_browser()) skip();
    const char *dir = tu_tmpdir("bake_viewer_exposure");
    char json[1024], glb[1024], shot[1024], frame_png[1024], err[512] = "";
    write_scene(dir, 1, json, sizeof json);   /* the scene of the first test with materials */
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_non_null(sc.tri_material);
    ms_lightmap lm;
    bake_glb(&sc, dir, &lm, glb, sizeof glb);
    /* the glb's exposures are the frame's own, standard and diffuse */
    ms_render_options ro;
    tu_render_options_default(&ro);
    ro.samples = 256;
    ms_frame fs, fd;
    assert_int_equal(ms_render(&sc, &ro, &fs, err, sizeof err), 0);
    ro.shading = MS_SHADING_DIFFUSE;
    assert_int_equal(ms_render(&sc, &ro, &fd, err, sizeof err), 0);
    tu_glb g;
    assert_int_equal(tu_glb_read(glb, &g), 0);
    const cJSON *ex = cJSON_GetObjectItem(cJSON_GetObjectItem(tu_glb_item(&g, "scenes", 0), "extras"), "microshadow");
    const cJSON *es = cJSON_GetObjectItem(ex, "exposure"), *ed = cJSON_GetObjectItem(ex, "exposure_diffuse");
    assert_true(cJSON_IsNumber(es) && cJSON_IsNumber(ed));
    printf("exposure: the glb's %.6g (standard), %.6g (diffuse); ms_render's %.6g, %.6g\n", es->valuedouble, ed->valuedouble,
           (double)fs.exposure, (double)fd.exposure);
    assert_true(es->valuedouble == (double)fs.exposure);
    assert_true(ed->valuedouble == (double)fd.exposure);
    assert_true(fd.exposure != fs.exposure);   /* the specular and the metallic box change what is exposed */
    tu_glb_free(&g);
    /* the frame as the CLI makes it, and the viewer with no exposure given */
    tu_path(frame_png, sizeof frame_png, dir, "frame.png");
    const char *args[] = { json, "--shading", "diffuse", "--samples", "256", "-o", frame_png, "--quiet", NULL };
    char line[512];
    assert_int_equal(tu_run_cli(args, line, sizeof line), 0);
    tu_path(shot, sizeof shot, dir, "shot.png");
    tu_screenshot(glb, json, shot, "");
    const int W = fd.width, H = fd.height;
    double *a = tu_png_luminance(shot, W, H), *b = tu_png_luminance(frame_png, W, H);
    const tu_lum_agreement ag = tu_lum_compare(a, b, fd.vis, (size_t)W * H);
    printf("viewer (diffuse mode, no exposure given) vs `microshadow --shading diffuse`: %ld hit pixels, luminance "
           "correlation %.4f, mean brightness %.4f vs %.4f (ratio %.4f)\n", ag.n, ag.corr, ag.mean_a, ag.mean_b, ag.ratio);
    assert_true(ag.n > W * H / 3);
    assert_true(ag.corr >= 0.95);
    assert_true(ag.ratio >= 0.8 && ag.ratio <= 1.2);
    /* no scene file: the camera the bake wrote into the glb, the same picture (its numbers went through floats) */
    char alone[1024];
    tu_path(alone, sizeof alone, dir, "alone.png");
    tu_screenshot(glb, "", alone, "");
    double *al = tu_png_luminance(alone, W, H);
    long unlike = 0;
    for (int i = 0; i < W * H; i++) unlike += fabs(al[i] - a[i]) > 0.02;
    printf("viewer without the scene file: %ld of %d pixels unlike the screenshot with it\n", unlike, W * H);
    assert_true(unlike <= W * H / 200);
    free(al);
    /* the orbit and the mode key */
    char drag[1024], key[1024], std[1024];
    tu_path(drag, sizeof drag, dir, "drag.png");
    tu_path(key, sizeof key, dir, "key.png");
    tu_path(std, sizeof std, dir, "standard.png");
    tu_screenshot(glb, json, drag, "--drag 40,0");
    tu_screenshot(glb, json, key, "--key m");
    tu_screenshot(glb, json, std, "--mode standard");
    double *dr = tu_png_luminance(drag, W, H), *ky = tu_png_luminance(key, W, H), *sd = tu_png_luminance(std, W, H);
    long moved = 0, lit = 0, key_off = 0, mode_changed = 0;
    for (int i = 0; i < W * H; i++) {
        moved += fabs(dr[i] - a[i]) > 0.02;
        lit += dr[i] > 0.05;
        key_off += ky[i] != sd[i];
        mode_changed += fabs(ky[i] - a[i]) > 0.02;
    }
    printf("orbit: %ld of %d pixels changed by a 40-pixel drag (%ld lit after it); key M: %ld pixels unlike mode=standard, "
           "%ld unlike the diffuse mode\n", moved, W * H, lit, key_off, mode_changed);
    assert_true(moved > W * H / 10);
    assert_true(lit > W * H / 4);
    assert_int_equal(key_off, 0);
    assert_true(mode_changed > W * H / 20);
    free(dr);
    free(ky);
    free(sd);
    free(a);
    free(b);
    ms_frame_free(&fs);
    ms_frame_free(&fd);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_viewer_matches_frame),
        cmocka_unit_test(test_viewer_exposes_as_frame),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
