/* Light textures from OpenEXR files (docs/lights.md), against independent answers:
 *   - texels read back: an EXR written here (half and float channels, RGBA with alpha, Y alone) loads as
 *     exactly the values written, row 0 first as a PNG's;
 *   - the PNG equivalent: texels 0 and 1 survive a PNG's 8-bit sRGB round trip exactly, so the scene with
 *     the EXR texture and the scene with the PNG of the same texels load the same floats and render and
 *     bake the same V, S and image bit for bit;
 *   - HDR texels (a PNG cannot hold 3.5): V equals the PNG scene's, S the same ratio (the weights scale by
 *     the texture's factor) within float rounding, the unshadowed shading 3.5 times as bright. */
#include "testutil.h"
#include <OpenEXR/openexr.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char g_dir[4096];

static const char *in_dir(const char *name)
{
    static char p[4][4096];
    static int k;
    k = (k + 1) % 4;
    return tu_path(p[k], sizeof p[k], g_dir, name);
}

/* The quad scene with a textured rect light (texture file `tex`, relative to the scene). */
static const char *scene_with_texture(const char *json, const char *tex)
{
    if (!tu_file_exists(in_dir("q.obj")))
        assert_int_equal(tu_write_file(in_dir("q.obj"), "v -10 0 -10\nv 10 0 10\nv 10 0 -10\nv -10 0 10\nv -2 2 -2\nv 2 2 2\n"
                                                        "v 2 2 -2\nv -2 2 2\nf 1 2 3\nf 1 4 2\nf 5 6 7\nf 5 8 6\n"), 0);
    char text[2048];
    snprintf(text, sizeof text,
             "{ \"meshes\": [ { \"file\": \"q.obj\" } ],\n"
             "  \"camera\": { \"eye\": [0, 10, 12], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 60, \"width\": 32, \"height\": 32 },\n"
             "  \"light\": { \"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2], \"texture\": \"%s\" },\n"
             "  \"render\": { \"samples\": 256 } }\n", tex);
    const char *p = in_dir(json);
    assert_int_equal(tu_write_file(p, text), 0);
    return p;
}

/* Interleaved rgb (w*h*3) as three planes. */
static void planes_of(const float *rgb, int n, float *r, float *g, float *b)
{
    for (int i = 0; i < n; i++) { r[i] = rgb[3 * i]; g[i] = rgb[3 * i + 1]; b[i] = rgb[3 * i + 2]; }
}

static void render(const ms_scene *sc, const char *method, ms_frame *f)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.threads = 2;
    char err[512];
    assert_int_equal(ms_render(sc, &o, f, err, sizeof err), 0);
}

static void test_texels_read_back(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("light_exr_texels"));
    enum { W = 5, H = 3, N = W * H };
    float r[N], g[N], b[N], a[N], y[N];
    for (int i = 0; i < N; i++) {   /* exact halves, distinct per texel and channel, some above 1 */
        r[i] = 0.25f * (float)i;
        g[i] = 8.0f - 0.5f * (float)i;
        b[i] = (float)(i % 3);
        a[i] = 0.5f;
        y[i] = 0.125f * (float)(N - i);
    }
    const char *names4[] = { "R", "G", "B", "A" };
    const float *const rgba[] = { r, g, b, a };
    const char *ny[] = { "Y" };
    const float *const yp[] = { y };
    assert_int_equal(tu_write_exr(in_dir("half.exr"), W, H, 4, names4, rgba, 1, EXR_COMPRESSION_ZIP), 0);
    assert_int_equal(tu_write_exr(in_dir("float.exr"), W, H, 3, names4, rgba, 0, EXR_COMPRESSION_PIZ), 0);
    assert_int_equal(tu_write_exr(in_dir("grey.exr"), W, H, 1, ny, yp, 1, EXR_COMPRESSION_NONE), 0);
    const char *files[] = { "half.exr", "float.exr", "grey.exr" };
    for (int f = 0; f < 3; f++) {
        ms_scene sc;
        char err[512];
        assert_int_equal(ms_scene_load(scene_with_texture("t.json", files[f]), &sc, err, sizeof err), 0);
        assert_int_equal(sc.light.texture_width, W);
        assert_int_equal(sc.light.texture_height, H);
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++) {
                const float want = f == 2 ? y[i] : (c == 0 ? r : c == 1 ? g : b)[i];
                assert_true(sc.light.texture[3 * i + c] == want);
            }
        ms_scene_free(&sc);
    }
}

static void test_same_as_png(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("light_exr_png"));
    enum { W = 4, H = 3, N = W * H };
    /* 0 and 1 only: exact through the PNG's 8-bit sRGB; coloured, with black texels so that S moves */
    const float tex[N * 3] = { 1, 1, 1, 0, 0, 0, 1, 0, 1, 1, 1, 0,
                               0, 0, 0, 1, 1, 1, 0, 1, 1, 0, 0, 0,
                               1, 0, 0, 0, 0, 0, 1, 1, 1, 0, 1, 0 };
    float r[N], g[N], b[N], hdr[N];
    planes_of(tex, N, r, g, b);
    tu_write_texture_png(in_dir("t.png"), W, H, tex);
    const char *names[] = { "R", "G", "B" };
    const float *const p[] = { r, g, b };
    assert_int_equal(tu_write_exr(in_dir("t.exr"), W, H, 3, names, p, 1, EXR_COMPRESSION_ZIP), 0);
    /* the same texels times 3.5 (grey, so that the luminance weights scale by 3.5 too) */
    float grey[N * 3];
    for (int i = 0; i < N; i++) {
        const float v = tex[3 * i] > 0.0f ? 1.0f : 0.0f;
        grey[3 * i] = grey[3 * i + 1] = grey[3 * i + 2] = v;
        hdr[i] = 3.5f * v;
    }
    tu_write_texture_png(in_dir("grey.png"), W, H, grey);
    const float *const ph[] = { hdr, hdr, hdr };
    assert_int_equal(tu_write_exr(in_dir("hdr.exr"), W, H, 3, names, ph, 1, EXR_COMPRESSION_RLE), 0);

    ms_scene sp, se, sg, sh;
    char err[512];
    assert_int_equal(ms_scene_load(scene_with_texture("png.json", "t.png"), &sp, err, sizeof err), 0);
    assert_int_equal(ms_scene_load(scene_with_texture("exr.json", "t.exr"), &se, err, sizeof err), 0);
    assert_int_equal(ms_scene_load(scene_with_texture("grey.json", "grey.png"), &sg, err, sizeof err), 0);
    assert_int_equal(ms_scene_load(scene_with_texture("hdr.json", "hdr.exr"), &sh, err, sizeof err), 0);
    assert_memory_equal(sp.light.texture, se.light.texture, sizeof tex);
    assert_memory_equal(sp.light.texture, tex, sizeof tex);
    const char *methods[] = { "raytrace", "scanline", NULL };
    const size_t npix = 32 * 32;
    for (int m = 0; methods[m]; m++) {
        ms_frame fp, fe, fg, fh;
        render(&sp, methods[m], &fp);
        render(&se, methods[m], &fe);
        assert_memory_equal(fp.vis, fe.vis, npix * sizeof(float));
        assert_memory_equal(fp.shadow, fe.shadow, npix * sizeof(float));
        assert_memory_equal(fp.rgb, fe.rgb, 3 * npix * sizeof(float));
        render(&sg, methods[m], &fg);
        render(&sh, methods[m], &fh);
        long penumbra = 0, lit = 0;
        for (size_t i = 0; i < npix; i++) {
            assert_true(fg.vis[i] == fh.vis[i]);
            assert_true(fabsf(fg.shadow[i] - fh.shadow[i]) <= 2e-6f);
            penumbra += fg.vis[i] > 0.0f && fg.vis[i] < 1.0f && fabsf(fg.shadow[i] - fg.vis[i]) > 0.01f;
            if (fg.vis[i] == 1.0f && fg.rgb[3 * i] > 1e-3f) {
                lit++;
                for (int c = 0; c < 3; c++) assert_true(fabsf(fh.rgb[3 * i + c] - 3.5f * fg.rgb[3 * i + c]) <= 1e-5f * fh.rgb[3 * i + c]);
            }
        }
        assert_true(penumbra > 0 && lit > 0);   /* the texture weighted S somewhere; shading was compared */
        ms_frame_free(&fp);
        ms_frame_free(&fe);
        ms_frame_free(&fg);
        ms_frame_free(&fh);
    }
    /* a bake too: the EXR-textured light bakes what the PNG-textured one does */
    ms_bake_options bo;
    memset(&bo, 0, sizeof bo);
    bo.size = 24;
    bo.uv_set = -1;
    bo.points.samples = 256;
    bo.points.threads = 2;
    bo.points.isa = tu_isa_cap();
    ms_lightmap lp, le;
    assert_int_equal(ms_bake(&sp, NULL, &bo, &lp, err, sizeof err), MS_OK);
    assert_int_equal(ms_bake(&se, NULL, &bo, &le, err, sizeof err), MS_OK);
    assert_memory_equal(lp.frame.shadow, le.frame.shadow, 24 * 24 * sizeof(float));
    assert_memory_equal(lp.frame.rgb, le.frame.rgb, 3 * 24 * 24 * sizeof(float));
    ms_lightmap_free(&lp);
    ms_lightmap_free(&le);
    ms_scene_free(&sp);
    ms_scene_free(&se);
    ms_scene_free(&sg);
    ms_scene_free(&sh);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_texels_read_back),
        cmocka_unit_test(test_same_as_png),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
