/* Outputs read back: PFM (by hand) and EXR (OpenEXRCore, FLOAT channel "V") equal the frame bit for
 * bit; PNG has its signature and size; --stats JSON (cJSON) has the required keys with values that
 * match the render; successful writes leave no temporary behind; failed ones leave nothing. */
#include "testutil.h"
#include <OpenEXR/openexr.h>
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FW 37
#define FH 23

static void make_frame(ms_frame *f)
{
    memset(f, 0, sizeof *f);
    f->width = FW;
    f->height = FH;
    f->vis = malloc(sizeof(float) * FW * FH);
    f->shadow = malloc(sizeof(float) * FW * FH);
    f->rgb = malloc(3 * sizeof(float) * FW * FH);
    for (int y = 0; y < FH; y++)
        for (int x = 0; x < FW; x++) {
            int i = y * FW + x;
            f->vis[i] = (x + y) % 7 == 0 ? -1.0f : (float)((x * 31 + y * 17) % 1025) / 1024.0f;
            f->shadow[i] = f->vis[i] < 0.0f ? -1.0f : (float)((x * 13 + y * 29) % 997) / 996.0f;   /* not V */
            for (int c = 0; c < 3; c++) f->rgb[3 * i + c] = 0.01f * (float)(x + c) * (float)y;
        }
    f->exposure = 1.0f;
    f->stats.method = "raytrace";
    f->stats.pattern = "grid";
}

static void test_pfm(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("outputs_pfm");
    char path[4096], err[512];
    ms_frame f;
    make_frame(&f);
    assert_int_equal(ms_write_vis(&f, tu_path(path, sizeof path, dir, "v.pfm"), err, sizeof err), 0);
    assert_int_equal(tu_count_entries(dir), 1);
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    static unsigned char buf[65536];
    size_t n = fread(buf, 1, sizeof buf, fp);
    fclose(fp);
    const char *hdr = "Pf\n37 23\n-1.0\n";
    size_t hl = strlen(hdr);
    assert_int_equal(n, hl + 4 * FW * FH);
    assert_memory_equal(buf, hdr, hl);
    for (int r = 0; r < FH; r++)
        for (int x = 0; x < FW; x++) {
            const unsigned char *b = buf + hl + 4 * (size_t)(r * FW + x);
            uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;   /* little-endian */
            float v;
            memcpy(&v, &u, 4);
            assert_true(v == f.vis[(FH - 1 - r) * FW + x]);   /* rows bottom to top */
        }
    /* S through the same writer: its own data, read back top row first */
    assert_int_equal(ms_write_shadow(&f, tu_path(path, sizeof path, dir, "s.pfm"), err, sizeof err), 0);
    int w = 0, h = 0;
    float *sv = tu_read_pfm(path, &w, &h);
    assert_non_null(sv);
    assert_int_equal(w, FW);
    assert_int_equal(h, FH);
    assert_memory_equal(sv, f.shadow, sizeof(float) * FW * FH);
    free(sv);
    ms_frame_free(&f);
}

static void check_exr(const ms_frame *fr, int shadow)
{
    const char *dir = tu_tmpdir(shadow ? "outputs_exr_s" : "outputs_exr");
    char path[4096], err[512];
    const ms_frame f = *fr;
    if (shadow) assert_int_equal(ms_write_shadow(&f, tu_path(path, sizeof path, dir, "s.exr"), err, sizeof err), 0);
    else assert_int_equal(ms_write_vis(&f, tu_path(path, sizeof path, dir, "v.exr"), err, sizeof err), 0);
    assert_int_equal(tu_count_entries(dir), 1);

    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    assert_int_equal(exr_start_read(&ctx, path, &init), EXR_ERR_SUCCESS);
    int parts = 0;
    assert_int_equal(exr_get_count(ctx, &parts), EXR_ERR_SUCCESS);
    assert_int_equal(parts, 1);
    exr_attr_box2i_t dw;
    assert_int_equal(exr_get_data_window(ctx, 0, &dw), EXR_ERR_SUCCESS);
    assert_int_equal(dw.max.x - dw.min.x + 1, FW);
    assert_int_equal(dw.max.y - dw.min.y + 1, FH);
    const exr_attr_chlist_t *chl = NULL;
    assert_int_equal(exr_get_channels(ctx, 0, &chl), EXR_ERR_SUCCESS);
    assert_int_equal(chl->num_channels, 1);
    assert_string_equal(chl->entries[0].name.str, shadow ? "S" : "V");
    assert_int_equal(chl->entries[0].pixel_type, EXR_PIXEL_FLOAT);
    exr_finish(&ctx);
    float *img = calloc(FW * FH, sizeof(float));
    assert_non_null(img);
    assert_int_equal(tu_read_exr_channel(path, shadow ? "S" : "V", FW, FH, img), 0);
    /* EXR rows are top to bottom, as in the frame. */
    assert_memory_equal(img, shadow ? f.shadow : f.vis, sizeof(float) * FW * FH);
    free(img);
}

static void test_exr(void **st)
{
    (void)st;
    ms_frame f;
    make_frame(&f);
    check_exr(&f, 0);
    check_exr(&f, 1);
    /* The EXR of everything (ms_write_exr): R, G, B, V and S read back as written; only .exr is accepted. */
    const char *dir = tu_tmpdir("outputs_exr_all");
    char path[4096], err[512];
    assert_int_not_equal(ms_write_exr(&f, tu_path(path, sizeof path, dir, "all.pfm"), err, sizeof err), 0);
    assert_int_equal(ms_write_exr(&f, tu_path(path, sizeof path, dir, "all.exr"), err, sizeof err), 0);
    assert_int_equal(tu_count_entries(dir), 1);
    float *img = calloc(FW * FH, sizeof(float));
    assert_non_null(img);
    assert_int_equal(tu_read_exr_channel(path, "V", FW, FH, img), 0);
    assert_memory_equal(img, f.vis, sizeof(float) * FW * FH);
    assert_int_equal(tu_read_exr_channel(path, "S", FW, FH, img), 0);
    assert_memory_equal(img, f.shadow, sizeof(float) * FW * FH);
    assert_int_equal(tu_read_exr_channel(path, "G", FW, FH, img), 0);
    for (int i = 0; i < FW * FH; i++) assert_true(img[i] == f.rgb[3 * i + 1]);
    free(img);
    ms_frame_free(&f);
}

static void test_png_and_failures(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("outputs_png");
    char path[4096], err[512];
    ms_frame f;
    make_frame(&f);
    assert_int_equal(ms_write_png(&f, tu_path(path, sizeof path, dir, "a.png"), err, sizeof err), 0);
    FILE *fp = fopen(path, "rb");
    unsigned char b[24];
    assert_int_equal(fread(b, 1, 24, fp), 24);
    fclose(fp);
    assert_memory_equal(b, "\x89PNG\r\n\x1a\n", 8);
    assert_memory_equal(b + 12, "IHDR", 4);
    assert_int_equal((b[16] << 24) | (b[17] << 16) | (b[18] << 8) | b[19], FW);
    assert_int_equal((b[20] << 24) | (b[21] << 16) | (b[22] << 8) | b[23], FH);
    assert_int_equal(tu_count_entries(dir), 1);
    /* Failures report the path and leave nothing. */
    const char *bad[4] = { "/nonexistent-microshadow-dir/a.png", "/nonexistent-microshadow-dir/v.pfm",
                           "/nonexistent-microshadow-dir/v.exr", "/nonexistent-microshadow-dir/s.json" };
    assert_int_not_equal(ms_write_png(&f, bad[0], err, sizeof err), 0);
    assert_non_null(strstr(err, bad[0]));
    assert_int_not_equal(ms_write_vis(&f, bad[1], err, sizeof err), 0);
    assert_non_null(strstr(err, bad[1]));
    assert_int_not_equal(ms_write_vis(&f, bad[2], err, sizeof err), 0);
    assert_non_null(strstr(err, bad[2]));
    assert_int_not_equal(ms_write_stats(&f, bad[3], err, sizeof err), 0);
    assert_non_null(strstr(err, bad[3]));
    assert_int_not_equal(ms_write_vis(&f, tu_path(path, sizeof path, dir, "v.tiff"), err, sizeof err), 0);
    assert_int_equal(tu_count_entries(dir), 1);
    ms_frame_free(&f);
}

static void check_stats(const char *path, const ms_frame *fr, size_t tris)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    static char text[65536];
    size_t n = fread(text, 1, sizeof text - 1, fp);
    fclose(fp);
    text[n] = 0;
    cJSON *o = cJSON_Parse(text);
    assert_non_null(o);
    const char *num_keys[] = { "triangles", "load_s", "build_s", "setup_s", "primary_s", "shadow_s", "total_s", "samples", "threads" };
    for (int i = 0; i < 9; i++) {
        const cJSON *x = cJSON_GetObjectItemCaseSensitive(o, num_keys[i]);
        if (!cJSON_IsNumber(x)) fail_msg("stats: '%s' missing or not a number", num_keys[i]);
        assert_true(x->valuedouble >= 0);
    }
    const cJSON *m = cJSON_GetObjectItemCaseSensitive(o, "method");
    assert_true(cJSON_IsString(m));
    assert_string_equal(m->valuestring, "raytrace");
    assert_int_equal((size_t)cJSON_GetObjectItemCaseSensitive(o, "triangles")->valuedouble, tris);
    assert_int_equal(cJSON_GetObjectItemCaseSensitive(o, "samples")->valueint, 256);
    assert_true(cJSON_GetObjectItemCaseSensitive(o, "threads")->valueint >= 1);
    double total = cJSON_GetObjectItemCaseSensitive(o, "total_s")->valuedouble;
    double parts = cJSON_GetObjectItemCaseSensitive(o, "build_s")->valuedouble +
                   cJSON_GetObjectItemCaseSensitive(o, "setup_s")->valuedouble +
                   cJSON_GetObjectItemCaseSensitive(o, "primary_s")->valuedouble +
                   cJSON_GetObjectItemCaseSensitive(o, "shadow_s")->valuedouble;
    assert_true(total >= parts * 0.999);
    if (fr) {
        assert_int_equal(cJSON_GetObjectItemCaseSensitive(o, "threads")->valueint, fr->stats.threads);
        /* cJSON prints 15 significant digits when they read back within its epsilon. */
        double sh = cJSON_GetObjectItemCaseSensitive(o, "shadow_s")->valuedouble;
        assert_true(fabs(sh - fr->stats.shadow_s) <= 1e-12 * fr->stats.shadow_s);
    }
    cJSON_Delete(o);
}

static void test_stats(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("outputs_stats");
    char path[4096], err[512];
    ms_scene s;
    assert_int_equal(ms_scene_showcase(&s), 0);   /* the CLI's built-in scene, rendered below through it too */
    ms_render_options opt;
    tu_render_options_default(&opt);
    opt.method = "raytrace";
    opt.samples = 256;
    opt.width = 24;
    opt.height = 16;
    opt.threads = 2;
    ms_frame fr;
    assert_int_equal(ms_render(&s, &opt, &fr, err, sizeof err), 0);
    assert_int_equal(fr.stats.threads, 2);
    assert_int_equal(ms_write_stats(&fr, tu_path(path, sizeof path, dir, "s.json"), err, sizeof err), 0);
    check_stats(path, &fr, s.n_tris);
    /* Through the CLI (built-in scene), with all four outputs: exactly four files, no temporaries; the S
     * image is the frame's S (the same render through the library). */
    char png[4096], exr[4096], js[4096], spfm[4096];
    const char *args[] = { "--method", "raytrace", "--samples", "256", "--width", "24", "--height", "16", "--quiet",
                           "--threads", "2", "-o", tu_path(png, sizeof png, dir, "c.png"), "--vis",
                           tu_path(exr, sizeof exr, dir, "c.exr"), "--shadow", tu_path(spfm, sizeof spfm, dir, "c.pfm"),
                           "--stats", tu_path(js, sizeof js, dir, "c.json"), NULL };
    int rc = tu_run_cli(args, err, sizeof err);
    if (rc) fail_msg("CLI exit %d: %s", rc, err);
    assert_int_equal(tu_count_entries(dir), 5);
    check_stats(js, NULL, s.n_tris);
    int w = 0, h = 0;
    float *sv = tu_read_pfm(spfm, &w, &h);
    assert_non_null(sv);
    assert_int_equal(w * h, 24 * 16);
    assert_memory_equal(sv, fr.shadow, sizeof(float) * 24 * 16);
    free(sv);
    /* a bad --isa or --shadow ending: exit 2 before rendering */
    const char *bad_isa[] = { "--isa", "sse9", "--quiet", NULL };
    assert_int_equal(tu_run_cli(bad_isa, err, sizeof err), 2);
    assert_non_null(strstr(err, "--isa"));
    const char *bad_s[] = { "--shadow", tu_path(spfm, sizeof spfm, dir, "s.tiff"), "--quiet", NULL };
    assert_int_equal(tu_run_cli(bad_s, err, sizeof err), 2);
    assert_non_null(strstr(err, "s.tiff"));
    ms_frame_free(&fr);
    ms_scene_free(&s);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pfm),
        cmocka_unit_test(test_exr),
        cmocka_unit_test(test_png_and_failures),
        cmocka_unit_test(test_stats),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
