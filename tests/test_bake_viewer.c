/* The baked glTF in a real browser: viewer/index.html (three.js, MOZ_lightmap on uv1, the scene file's camera)
 * in headless Chromium (viewer/screenshot.mjs, puppeteer-core), against microshadow's own frame of the same
 * camera. Both show the diffuse radiance albedo / pi * E (the viewer: MeshBasicMaterial, whose light map three.js
 * shades as base colour * lightmap * intensity / pi; the frame: no materials, so no specular term), exposed by
 * the frame's exposure, clipped and sRGB-encoded. Over the pixels the frame hits, the luminance of the two
 * (linearised) correlates >= 0.95; the mean relative error is reported. Skipped with a message without node,
 * Chromium or viewer/node_modules (scripts/install-deps.sh installs them). */
#include "testutil.h"
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int have_browser(void)
{
    if (system("node --version > /dev/null 2>&1") != 0) { printf("skipped: node not found (scripts/install-deps.sh installs nodejs)\n"); return 0; }
    if (access("/usr/bin/chromium", X_OK) != 0) { printf("skipped: /usr/bin/chromium not found (scripts/install-deps.sh installs chromium)\n"); return 0; }
    if (access(MS_VIEWER_DIR "/node_modules/puppeteer-core/package.json", R_OK) != 0 ||
        access(MS_VIEWER_DIR "/node_modules/three/build/three.module.js", R_OK) != 0) {
        printf("skipped: " MS_VIEWER_DIR "/node_modules lacks three or puppeteer-core (scripts/install-deps.sh runs npm ci there)\n");
        return 0;
    }
    return 1;
}

static double srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static void test_viewer_matches_frame(void **st)
{
    (void)st;
    if (!have_browser()) skip();
    const char *dir = tu_tmpdir("bake_viewer");
    char p[1024], json[1024], glb[1024], shot[1024], err[512] = "";
    /* a floor, a box standing on it, a plate above it casting a soft shadow, a rect light */
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "floor.obj"),
        "v -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nf 1 2 3 4\n"), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "box.obj"),
        "v 0.5 0 -0.5\nv 1.5 0 -0.5\nv 1.5 0 0.5\nv 0.5 0 0.5\nv 0.5 1 -0.5\nv 1.5 1 -0.5\nv 1.5 1 0.5\nv 0.5 1 0.5\n"
        "f 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n"), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "plate.obj"),
        "v -1.6 1.2 -0.6\nv -1.6 1.2 0.6\nv -0.4 1.2 0.6\nv -0.4 1.2 -0.6\nf 1 2 3 4\nf 4 3 2 1\n"), 0);
    assert_int_equal(tu_write_file(tu_path(json, sizeof json, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"floor.obj\"},{\"file\":\"box.obj\"},{\"file\":\"plate.obj\"}],"
        "\"camera\":{\"eye\":[0,4.5,5.5],\"target\":[0,0.3,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":160,\"height\":120},"
        "\"light\":{\"corner\":[-0.6,4,-0.6],\"edge_s\":[1.2,0,0],\"edge_t\":[0,0,1.2],\"emission\":[1,1,1]}}"), 0);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_bake_options bo;
    memset(&bo, 0, sizeof bo);
    bo.size = 512;
    bo.uv_set = -1;
    bo.points.samples = 256;
    bo.points.isa = tu_isa_cap();
    ms_lightmap lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    tu_path(glb, sizeof glb, dir, "scene.glb");
    assert_int_equal(ms_bake_write_gltf(&sc, &lm, NULL, glb, err, sizeof err), MS_OK);
    ms_render_options ro;
    tu_render_options_default(&ro);
    ro.samples = 256;
    ms_frame fr;
    assert_int_equal(ms_render(&sc, &ro, &fr, err, sizeof err), 0);
    tu_path(shot, sizeof shot, dir, "shot.png");
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "node '%s/screenshot.mjs' '%s' '%s' '%s' --exposure %.9g", MS_VIEWER_DIR, glb, json, shot,
             (double)fr.exposure);
    fflush(stdout);
    assert_int_equal(system(cmd), 0);
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
            a += wy[c] * srgb_to_linear(px[3 * i + c] / 255.0);
            b += wy[c] * fmin(fmax(fr.rgb[3 * i + c] * fr.exposure, 0.0), 1.0);
        }
        sa += a; sb += b; saa += a * a; sbb += b * b; sab += a * b;
        n++;
        if (b > 0.05) { rel += fabs(a - b) / b; nrel++; }
    }
    const double cov = sab / n - (sa / n) * (sb / n), va = saa / n - (sa / n) * (sa / n), vb = sbb / n - (sb / n) * (sb / n);
    const double corr = cov / sqrt(va * vb);
    printf("viewer vs frame: %ld hit pixels, luminance correlation %.4f, mean relative error %.4f over the %ld pixels above "
           "0.05, mean luminance %.4f vs %.4f\n", n, corr, rel / (double)nrel, nrel, sa / n, sb / n);
    assert_true(n > W * H / 3);
    assert_true(corr >= 0.95);
    free(px);
    ms_frame_free(&fr);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_viewer_matches_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
