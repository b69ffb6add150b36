/* Streamed outputs (#24 item 2, docs/memory.md): ms_render_outputs writing the outputs band by band.
 *   - streamed and whole-frame files are equal byte for byte (PNG, EXR with R, G, B, S, V, V and S as EXR and
 *     PFM; the PNG's with the interleaved pattern's filter, which reads rows of the next band), on the built-in
 *     scene with two lights and a frame whose height is no multiple of the band's, both
 *     asked for (stream on / off) and chosen by the budget (a budget below the whole frame's estimate, above
 *     the streamed one's: stats.stream_rows says it streamed);
 *   - the files hold the frame ms_render computes (read back by the tests' own PFM and EXR readers, against
 *     ms_render's planes: an oracle that does not go through the writers);
 *   - a budget below even the streamed estimate is refused (MS_ERR_BUDGET, "streamed" in the message) and
 *     leaves no file; frame-level methods are refused when streaming is forced;
 *   - the CLI: --max-memory below the whole frame streams and says so; the files equal --no-stream's; the
 *     largest frame under a budget below even its streamed need is refused in one line, nothing written. */
#include "testutil.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 150
#define H 250  /* bands of 32 rows (options: stream_rows), the last of 26 */

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    const long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = malloc((size_t)len + 1);
    if (b && fread(b, 1, (size_t)len, f) != (size_t)len) { free(b); b = NULL; }
    fclose(f);
    *n = (size_t)len;
    return b;
}

static void assert_same_file(const char *a, const char *b)
{
    size_t na, nb;
    char *x = slurp(a, &na), *y = slurp(b, &nb);
    assert_non_null(x);
    assert_non_null(y);
    if (na != nb || memcmp(x, y, na)) fail_msg("%s and %s differ (%zu, %zu bytes)", a, b, na, nb);
    free(x);
    free(y);
}

/* The built-in scene with a second light (a disk): two planes per light-dependent output. */
static void two_light_scene(ms_scene *sc)
{
    assert_int_equal(ms_scene_default(sc), 0);
    ms_light *two = calloc(2, sizeof *two);
    assert_non_null(two);
    two[0] = sc->light;
    assert_int_equal(ms_light_disk(&two[1], (ms_vec3){ 2, 5, 2 }, (ms_vec3){ -0.3f, -1, -0.2f }, 0.8f), 0);
    two[1].emission = (ms_vec3){ 0.3f, 0.5f, 1.5f };
    sc->lights = two;
    sc->n_lights = 2;
}

static void options(ms_render_options *o)
{
    tu_render_options_default(o);
    o->width = W;
    o->height = H;
    o->threads = 2;
    o->samples = 256;
    o->stream_rows = 32;   /* several bands at this size (the default band would hold it all) */
}

/* Renders sc into dir/<tag>.png (or .exr), <tag>-vis.exr / .pfm, <tag>-shadow.pfm / .exr. */
static int render_to(const ms_scene *sc, const ms_render_options *o, const char *dir, const char *tag, int exr_rgb,
                     ms_stats *st, char *err, size_t errlen)
{
    static char p[3][1024];
    char name[64];
    snprintf(name, sizeof name, "%s.%s", tag, exr_rgb ? "exr" : "png");
    tu_path(p[0], sizeof p[0], dir, name);
    snprintf(name, sizeof name, "%s-vis.%s", tag, exr_rgb ? "pfm" : "exr");
    tu_path(p[1], sizeof p[1], dir, name);
    snprintf(name, sizeof name, "%s-shadow.%s", tag, exr_rgb ? "exr" : "pfm");
    tu_path(p[2], sizeof p[2], dir, name);
    static const char *const img[] = { ".png", ".exr", NULL };
    const ms_output outs[3] = {
        { "-o", p[0], exr_rgb ? ms_exr_write_stream : ms_png_write_stream, img, NULL, 0 },
        { "--vis", p[1], ms_vis_write_stream, ms_float_image_suffixes, NULL, 0 },
        { "--shadow", p[2], ms_shadow_write_stream, ms_float_image_suffixes, NULL, 0 },
    };
    if (ms_outputs_check(outs, 3, err, errlen)) return -1;
    return ms_render_outputs(sc, o, 0.5, outs, 3, st, err, errlen);
}

static void assert_same_outputs(const char *dir, const char *a, const char *b, int exr_rgb)
{
    const char *const fmt[3] = { exr_rgb ? "%s/%s.exr" : "%s/%s.png", exr_rgb ? "%s/%s-vis.pfm" : "%s/%s-vis.exr",
                                 exr_rgb ? "%s/%s-shadow.exr" : "%s/%s-shadow.pfm" };
    for (int k = 0; k < 3; k++) {
        char pa[1024], pb[1024];
        snprintf(pa, sizeof pa, fmt[k], dir, a);
        snprintf(pb, sizeof pb, fmt[k], dir, b);
        assert_same_file(pa, pb);
    }
}

static void test_streamed_equals_whole(void **state)
{
    (void)state;
    const char *dir = tu_tmpdir("test_stream");
    ms_scene sc;
    two_light_scene(&sc);
    ms_render_options o;
    options(&o);
    char err[1024];
    ms_stats whole, streamed, autos;
    for (int exr_rgb = 0; exr_rgb < 2; exr_rgb++) {
        /* The interleaved pattern's filter reads two rows beyond a band: the PNG run with it (raytrace). */
        o.method = exr_rgb ? NULL : "raytrace";
        o.pattern = exr_rgb ? MS_PATTERN_GRID : MS_PATTERN_INTERLEAVED;
        o.stream = MS_STREAM_OFF;
        o.max_memory = 0;
        if (render_to(&sc, &o, dir, "whole", exr_rgb, &whole, err, sizeof err)) fail_msg("whole: %s", err);
        assert_int_equal(whole.stream_rows, 0);
        o.stream = MS_STREAM_ON;
        if (render_to(&sc, &o, dir, "streamed", exr_rgb, &streamed, err, sizeof err)) fail_msg("streamed: %s", err);
        assert_int_equal(streamed.stream_rows, 32);
        assert_same_outputs(dir, "whole", "streamed", exr_rgb);
        /* The budget's choice: below the whole frame's estimate, above the streamed one's. */
        assert_true(streamed.memory_need < whole.memory_need);
        o.stream = MS_STREAM_AUTO;
        o.max_memory = (whole.memory_need + streamed.memory_need) / 2;
        if (render_to(&sc, &o, dir, "auto", exr_rgb, &autos, err, sizeof err)) fail_msg("auto: %s", err);
        assert_int_equal(autos.stream_rows, 32);
        assert_int_equal(autos.memory_need, streamed.memory_need);
        assert_same_outputs(dir, "whole", "auto", exr_rgb);
        /* Under a budget that holds the whole frame, AUTO does not stream. */
        o.max_memory = whole.memory_need;
        if (render_to(&sc, &o, dir, "auto", exr_rgb, &autos, err, sizeof err)) fail_msg("auto, whole: %s", err);
        assert_int_equal(autos.stream_rows, 0);
    }
    /* The files hold ms_render's frames (read back by the tests' own readers): the second round's (grid) V as
     * PFM and R, G, B, S, V as EXR, the first round's (interleaved, filtered) S as PFM. */
    o.method = NULL;
    o.pattern = MS_PATTERN_GRID;
    o.stream = MS_STREAM_AUTO;
    o.max_memory = 0;
    ms_frame f, fi;
    tu_render_ok(&sc, &o, &f);
    o.method = "raytrace";
    o.pattern = MS_PATTERN_INTERLEAVED;
    tu_render_ok(&sc, &o, &fi);
    const size_t npix = (size_t)W * H;
    char path[1024];
    int w, h;
    float *pfm = tu_read_pfm(tu_path(path, sizeof path, dir, "streamed-vis.pfm"), &w, &h);   /* light 0 */
    assert_non_null(pfm);
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    for (size_t i = 0; i < npix; i++) assert_true(pfm[i] == f.vis[i]);
    free(pfm);
    pfm = tu_read_pfm(tu_path(path, sizeof path, dir, "streamed-shadow.pfm"), &w, &h);
    assert_non_null(pfm);
    for (size_t i = 0; i < npix; i++) assert_true(pfm[i] == fi.shadow[i]);
    free(pfm);
    ms_frame_free(&fi);
    float *ch = malloc(npix * sizeof *ch);
    assert_non_null(ch);
    static const char *const names[] = { "S0", "S1", "V0", "V1", "R", "G", "B" };
    for (int c = 0; c < 7; c++) {
        assert_int_equal(tu_read_exr_channel(tu_path(path, sizeof path, dir, "streamed.exr"), names[c], W, H, ch), 0);
        const float *want = c < 2 ? f.shadow + (size_t)c * npix : c < 4 ? f.vis + (size_t)(c - 2) * npix : f.rgb + (c - 4);
        const size_t stride = c < 4 ? 1 : 3;
        for (size_t i = 0; i < npix; i++) assert_true(ch[i] == want[i * stride]);
    }
    free(ch);
    ms_frame_free(&f);
    ms_scene_free(&sc);
}

/* Anti-aliased frames streamed: each band of the s-times larger frame is resolved into whole output rows (several
 * bands, the last short), byte for byte the whole frame's files, for aa 4, 9 and 16, on the grid pattern
 * (scanline) and the interleaved one (raytrace: its filter reads rows beyond a band); a band size that is not
 * a multiple of s tiles is refused. */
static void test_streamed_antialiased(void **state)
{
    (void)state;
    const char *dir = tu_tmpdir("test_stream_aa");
    ms_scene sc;
    two_light_scene(&sc);
    ms_render_options o;
    options(&o);
    o.width = 70;
    o.height = 90;   /* rendered 140 x 180, 210 x 270, 280 x 360 */
    char err[1024], tag[32];
    ms_stats whole, streamed;
    for (int s = 2; s <= 4; s++)
        for (int exr_rgb = 0; exr_rgb < 2; exr_rgb++) {
            o.aa = s * s;
            o.method = exr_rgb ? NULL : "raytrace";
            o.pattern = exr_rgb ? MS_PATTERN_GRID : MS_PATTERN_INTERLEAVED;
            o.stream_rows = 2 * s * MS_TILE_SIZE;   /* 32 output rows a band */
            o.stream = MS_STREAM_OFF;
            snprintf(tag, sizeof tag, "whole%d", s);
            if (render_to(&sc, &o, dir, tag, exr_rgb, &whole, err, sizeof err)) fail_msg("whole, aa %d: %s", s * s, err);
            o.stream = MS_STREAM_ON;
            char tag2[32];
            snprintf(tag2, sizeof tag2, "streamed%d", s);
            if (render_to(&sc, &o, dir, tag2, exr_rgb, &streamed, err, sizeof err)) fail_msg("streamed, aa %d: %s", s * s, err);
            assert_int_equal(streamed.stream_rows, 32);
            assert_same_outputs(dir, tag, tag2, exr_rgb);
            o.stream_rows = s * MS_TILE_SIZE + MS_TILE_SIZE;   /* not whole output blocks */
            assert_int_equal(render_to(&sc, &o, dir, "bad", exr_rgb, &streamed, err, sizeof err), MS_ERR_INVALID);
            assert_non_null(strstr(err, "stream_rows"));
        }
    ms_scene_free(&sc);
}

static void test_refusals(void **state)
{
    (void)state;
    const char *dir = tu_tmpdir("test_stream_refuse");
    ms_scene sc;
    two_light_scene(&sc);
    ms_render_options o;
    options(&o);
    char err[1024];
    ms_stats st;
    o.stream = MS_STREAM_ON;
    o.stream_rows = MS_TILE_SIZE;   /* the smallest band: under its need nothing streamed fits */
    assert_int_equal(render_to(&sc, &o, dir, "a", 0, &st, err, sizeof err), 0);
    const uint64_t need = st.memory_need;
    assert_int_equal(tu_count_entries(dir), 3);
    /* Even streamed it does not fit: refused (the whole frame's refusal: streaming would not fit either), and
     * nothing written; forced to stream, the refusal is the streamed frame's. */
    const char *sub = tu_tmpdir("test_stream_refuse_none");
    o.stream = MS_STREAM_AUTO;
    o.max_memory = need - 1;
    assert_int_equal(render_to(&sc, &o, sub, "b", 0, &st, err, sizeof err), MS_ERR_BUDGET);
    assert_non_null(strstr(err, "--max-memory"));
    assert_null(strstr(err, "frame streamed"));
    assert_null(strstr(err, "which fits"));
    o.stream = MS_STREAM_ON;
    assert_int_equal(render_to(&sc, &o, sub, "b", 0, &st, err, sizeof err), MS_ERR_BUDGET);
    assert_non_null(strstr(err, "frame streamed"));
    assert_int_equal(tu_count_entries(sub), 0);
    /* Not streamed, the refusal says that streaming would fit. */
    o.stream = MS_STREAM_OFF;
    o.max_memory = need + 1;
    assert_int_equal(render_to(&sc, &o, sub, "b", 0, &st, err, sizeof err), MS_ERR_BUDGET);
    assert_non_null(strstr(err, "--stream writes the outputs as the rows finish"));
    assert_non_null(strstr(err, "which fits"));
    assert_int_equal(tu_count_entries(sub), 0);
    /* Forced streaming where it cannot be done. */
    o.max_memory = 0;
    o.stream = MS_STREAM_ON;
    o.method = "hpc";
    assert_int_equal(render_to(&sc, &o, sub, "b", 0, &st, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "whole frame"));
    assert_int_equal(tu_count_entries(sub), 0);
    ms_scene_free(&sc);
}

static void test_cli(void **state)
{
    (void)state;
    const char *dir = tu_tmpdir("test_stream_cli");
    char a[3][1024], b[3][1024], line[1024];
    tu_path(a[0], sizeof a[0], dir, "a.png");
    tu_path(a[1], sizeof a[1], dir, "a.exr");
    tu_path(a[2], sizeof a[2], dir, "a.pfm");
    tu_path(b[0], sizeof b[0], dir, "b.png");
    tu_path(b[1], sizeof b[1], dir, "b.exr");
    tu_path(b[2], sizeof b[2], dir, "b.pfm");
    const char *whole[] = { "--width", "600", "--height", "400", "--samples", "256", "--threads", "2", "--no-stream",
                            "-o", a[0], "--vis", a[1], "--shadow", a[2], "--quiet", NULL };
    assert_int_equal(tu_run_cli(whole, line, sizeof line), 0);
    /* The CLI's built-in scene (three lights) at 600x400 needs about 42 MiB whole; streamed, bands of 16 rows
     * fit 16 MiB (the budget picks them). */
    const char *streamed[] = { "--width", "600", "--height", "400", "--samples", "256", "--threads", "2",
                               "--max-memory", "16M", "-o", b[0], "--vis", b[1], "--shadow", b[2], NULL };
    assert_int_equal(tu_run_cli(streamed, line, sizeof line), 0);
    if (!strstr(line, "written as the rows finished")) fail_msg("no word of streaming: %s", line);
    for (int k = 0; k < 3; k++) assert_same_file(a[k], b[k]);
    /* The largest frame: streamed it needs about 46 MiB (one tile row of 16384 pixels at a time), over 16 MiB:
     * refused before allocating, one line naming the streamed need, nothing written. */
    const char *sub = tu_tmpdir("test_stream_cli_big");
    tu_path(a[0], sizeof a[0], sub, "big.png");
    const char *big[] = { "--width", "16384", "--height", "16384", "--aa", "1", "--max-memory", "16M", "--quiet", "-o", a[0], NULL };
    char all[2048];
    tu_run_result res;
    assert_int_equal(tu_run_cli_ex(big, NULL, all, sizeof all, &res), 2);
    assert_int_equal(res.lines, 1);
    if (!strstr(all, "--stream writes the outputs as the rows finish (about")) fail_msg("no streamed need: %s", all);
    assert_null(strstr(all, "which fits"));
    assert_int_equal(tu_count_entries(sub), 0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_streamed_equals_whole),
        cmocka_unit_test(test_streamed_antialiased),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_cli),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
