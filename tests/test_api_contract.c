/* The library's contract (issue 23): the ABI check of the checked entry points (a program's ABI level and
 * struct sizes against the library's: a mismatch is refused before any struct is read or written; an option
 * struct of an earlier header of the level is read at its size, the rest taken as zero), named counters
 * (ms_stats_counter), and the status every
 * failing function returns, one case per kind, each provoked for real (a missing file, a method that does
 * not exist, a budget too small, a callback that cancels, an unwritable output). */
#include "testutil.h"
#include "core/abi.h"
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static ms_abi table(void) { return *ms_abi_compiled(); }

static void test_abi_matches(void **st)
{
    (void)st;
    ms_abi a = table();
    assert_int_equal(a.abi_size, sizeof(ms_abi));
    assert_int_equal(a.render_options, sizeof(ms_render_options));
    assert_int_equal(a.frame, sizeof(ms_frame));
    ms_scene sc;
    assert_int_equal(ms_scene_default_abi(&a, &sc), MS_OK);
    assert_true(sc.n_tris > 0);
    ms_scene_free(&sc);
}

/* A struct of another size is refused, the message names the entry point and the struct, and the caller's
 * output is left as it was (not written at the library's size). */
static void test_abi_size_mismatch(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), MS_OK);
    ms_render_options o;
    ms_render_options_default(&o);
    o.width = o.height = 16;
    ms_abi a = table();
    a.render_options += 8;
    ms_frame f;
    memset(&f, 0xab, sizeof f);
    char err[256] = "";
    assert_int_equal(ms_render_abi(&a, &sc, &o, &f, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "ms_render:"));
    assert_non_null(strstr(err, "ms_render_options"));
    unsigned char expect[sizeof f];
    memset(expect, 0xab, sizeof expect);
    assert_memory_equal(&f, expect, sizeof f);

    a = table();
    a.frame -= 8;
    assert_int_equal(ms_render_abi(&a, &sc, &o, &f, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "ms_frame"));
    a = table();
    a.lightmap += 16;   /* a struct the call does not take: the whole table is one program's, so it is refused too */
    ms_accel *acc = NULL;
    assert_int_equal(ms_accel_build_abi(&a, &sc, 1, &acc, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "ms_accel_build"));
    assert_non_null(strstr(err, "ms_lightmap"));
    ms_scene_free(&sc);
}

static void test_abi_version_and_table(void **st)
{
    (void)st;
    char err[256] = "";
    ms_scene sc;
    ms_abi a = table();
    a.abi_level += 1;
    assert_int_equal(ms_scene_load_abi(&a, "/nonexistent/scene.json", NULL, &sc, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "built against microshadow"));
    assert_non_null(strstr(err, "ABI level"));
    /* Another minor version of the same ABI level is accepted: the level, not the version, decides. */
    a = table();
    a.version_minor += 1;
    assert_int_equal(ms_scene_default_abi(&a, &sc), MS_OK);
    ms_scene_free(&sc);
    /* Zeroes are not compared: a binding that mirrors only some structs passes 0 for the others. */
    ms_abi z;
    memset(&z, 0, sizeof z);
    z.abi_size = sizeof z;
    assert_int_equal(ms_scene_default_abi(&z, &sc), MS_OK);
    ms_scene_free(&sc);
    /* A table from an older header lists fewer structs; those it does not list are not compared. */
    a = table();
    a.abi_size = (uint32_t)offsetof(ms_abi, scene);
    a.scene += 8;
    assert_int_equal(ms_scene_default_abi(&a, &sc), MS_OK);
    ms_scene_free(&sc);
    a.abi_size = 4;
    assert_int_equal(ms_scene_load_abi(&a, "x.json", NULL, &sc, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "too small"));
    assert_int_equal(ms_scene_load_abi(NULL, "x.json", NULL, &sc, err, sizeof err), MS_ERR_INVALID);
}

/* Option structs: a later header's (larger) is refused, naming it as newer; one smaller than the level's
 * first size is refused; a fixed struct of another size is refused whichever way it differs. */
static void test_abi_option_sizes(void **st)
{
    (void)st;
    char err[256] = "";
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), MS_OK);
    ms_render_options o;
    ms_render_options_default(&o);
    o.width = o.height = 8;
    ms_frame f;
    ms_abi a = table();
    a.render_options += 8;
    assert_int_equal(ms_render_abi(&a, &sc, &o, &f, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "header is newer"));
    a = table();
    a.render_options -= 8;   /* below the level's first size: not a header of this level */
    assert_int_equal(ms_render_abi(&a, &sc, &o, &f, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "ms_render_options"));
    a = table();
    a.stats += 8;
    assert_int_equal(ms_render_abi(&a, &sc, &o, &f, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "ms_stats"));
    assert_null(strstr(err, "newer"));
    ms_scene_free(&sc);
}

/* An option struct read at the size the program passed: its bytes, then zeroes; nothing read past it (the
 * buffer is exactly that size, so AddressSanitizer would see an over-read); a full-size one is used as it is. */
static void test_abi_options_read_at_their_size(void **st)
{
    (void)st;
    const uint32_t theirs = (uint32_t)offsetof(ms_render_options, shading);
    unsigned char *buf = malloc(theirs);
    assert_non_null(buf);
    for (uint32_t i = 0; i < theirs; i++) buf[i] = (unsigned char)(i * 7 + 1);
    ms_render_options mine;
    memset(&mine, 0xcd, sizeof mine);
    const ms_render_options *o = ms_abi_options(buf, theirs, &mine, sizeof mine);
    assert_ptr_equal(o, &mine);
    assert_memory_equal(o, buf, theirs);
    for (size_t i = theirs; i < sizeof mine; i++) assert_int_equal(((const unsigned char *)o)[i], 0);
    assert_int_equal(o->shading, MS_SHADING_STANDARD);
    free(buf);
    ms_render_options full;
    ms_render_options_default(&full);
    assert_ptr_equal(ms_abi_options(&full, sizeof full, &mine, sizeof mine), &full);
    assert_ptr_equal(ms_abi_options(&full, 0, &mine, sizeof mine), &full);
    assert_null(ms_abi_options(NULL, 8, &mine, sizeof mine));
}

/* ms_bake_options of an earlier header whose ms_points_options was 8 bytes shorter (without max_memory) and
 * whose own fields stopped before uv_packing: laid out as that header would, byte for byte, and read back
 * into this library's struct with those fields at their places and the rest zero. */
static void test_abi_bake_options_of_an_earlier_header(void **st)
{
    (void)st;
    ms_bake_options want;
    memset(&want, 0, sizeof want);
    want.points.method = "raytrace";
    want.points.samples = 256;
    want.points.seed = 7;
    want.size = 64;
    want.uv_set = 1;
    want.padding = 3;
    want.texel_density = 2.5f;
    const size_t pts = offsetof(ms_points_options, max_memory), own = offsetof(ms_bake_options, uv_packing)
        - sizeof(ms_points_options);
    assert_int_equal(pts % 8, 0);
    unsigned char *buf = calloc(1, pts + own);
    assert_non_null(buf);
    memcpy(buf, &want.points, pts);
    memcpy(buf + pts, (const unsigned char *)&want + sizeof(ms_points_options), own);
    ms_abi a = table();
    a.points_options = (uint32_t)pts;
    a.bake_options = (uint32_t)(pts + own);
    ms_bake_options mine;
    memset(&mine, 0xcd, sizeof mine);
    const ms_bake_options *o = ms_abi_bake_options(&a, (const ms_bake_options *)(const void *)buf, &mine);
    assert_ptr_equal(o, &mine);
    assert_memory_equal(o, &want, sizeof want);
    free(buf);
    ms_abi same = table();
    assert_ptr_equal(ms_abi_bake_options(&same, &want, &mine), &want);
    /* No options: a zeroed struct, the defaults. */
    memset(&mine, 0xcd, sizeof mine);
    ms_bake_options zero;
    memset(&zero, 0, sizeof zero);
    assert_ptr_equal(ms_abi_bake_options(&same, NULL, &mine), &mine);
    assert_memory_equal(&mine, &zero, sizeof zero);
}

/* Counters by name: each of a frame's counters found with its value, an unknown name not. */
static void test_stats_counter_by_name(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), MS_OK);
    ms_render_options o;
    ms_render_options_default(&o);
    o.method = "scanline";
    o.width = o.height = 32;
    o.samples = 256;
    o.aa = 1;
    ms_frame f;
    char err[256] = "";
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), MS_OK);
    assert_true(f.stats.n_counters > 0 && f.stats.n_counters <= MS_MAX_COUNTERS);
    for (int c = 0; c < f.stats.n_counters; c++) {
        uint64_t v = ~0ull;
        assert_int_equal(ms_stats_counter(&f.stats, f.stats.counter_name[c], &v), 1);
        assert_true(v == f.stats.counter[c]);
    }
    uint64_t blocks = 0;
    assert_int_equal(ms_stats_counter(&f.stats, "blocks", &blocks), 1);
    assert_true(blocks > 0);
    assert_int_equal(ms_stats_counter(&f.stats, "no such counter", NULL), 0);
    assert_int_equal(ms_stats_counter(NULL, "blocks", NULL), 0);
    ms_frame_free(&f);
    ms_scene_free(&sc);
}

static int cancel_at_once(void *user, double frac)
{
    (void)user; (void)frac;
    return 1;
}

/* Each status, provoked. */
static void test_statuses(void **st)
{
    (void)st;
    char err[512] = "";
    ms_pattern p;
    assert_int_equal(ms_pattern_from_name("gird", &p), MS_ERR_INVALID);
    assert_int_equal(ms_pattern_from_name("grid", &p), MS_OK);
    ms_isa isa;
    assert_int_equal(ms_isa_from_name("sse9", &isa), MS_ERR_INVALID);
    size_t off, size;
    assert_int_equal(ms_layout("ms_nothing", NULL, &off, &size), MS_ERR_INVALID);
    assert_int_equal(ms_layout("ms_frame", "vis", &off, &size), MS_OK);
    assert_int_equal(off, offsetof(ms_frame, vis));
    ms_light l;
    memset(&l, 0, sizeof l);
    assert_int_equal(ms_light_disk(&l, (ms_vec3){ 0, 1, 0 }, (ms_vec3){ 0, -1, 0 }, 0.0f), MS_ERR_INVALID);
    assert_int_equal(ms_light_sphere(&l, (ms_vec3){ 0, 1, 0 }, -1.0f), MS_ERR_INVALID);

    const char *dir = tu_tmpdir("test_api_contract");
    char path[512];
    ms_scene sc;
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "missing.json"), &sc, err, sizeof err), MS_ERR_IO);
    assert_non_null(strstr(err, "missing.json"));
    tu_path(path, sizeof path, dir, "broken.json");
    assert_int_equal(tu_write_file(path, "{ \"camera\": "), 0);
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "broken.json"));

    assert_int_equal(ms_scene_default(&sc), MS_OK);
    assert_int_equal(ms_scene_validate(&sc, "built-in", err, sizeof err), MS_OK);
    ms_render_options o;
    tu_render_options_default(&o);
    o.width = o.height = 32;
    o.samples = 256;
    ms_frame f;
    o.method = "no-such-method";
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), MS_ERR_METHOD);
    assert_non_null(strstr(err, "no-such-method"));
    o.method = "scanline";
    o.max_memory = 4096;
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), MS_ERR_BUDGET);
    o.max_memory = 0;
    o.aa = 3;
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), MS_ERR_INVALID);
    o.aa = 0;
    o.progress = cancel_at_once;
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), MS_ERR_CANCELLED);
    o.progress = NULL;
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), MS_OK);

    /* Outputs: a wrong ending is the caller's mistake, an unwritable place an i/o failure. */
    static const char *const png_only[] = { ".png", NULL };
    ms_output out = { "-o", tu_path(path, sizeof path, dir, "x.jpg"), ms_png_write_stream, png_only, NULL, 0 };
    assert_int_equal(ms_outputs_check(&out, 1, err, sizeof err), MS_ERR_INVALID);
    out.path = "/nonexistent-dir/x.png";
    assert_int_equal(ms_outputs_check(&out, 1, err, sizeof err), MS_ERR_IO);
    assert_int_equal(ms_write_png(&f, "/nonexistent-dir/x.png", err, sizeof err), MS_ERR_IO);
    assert_int_equal(ms_write_png(&f, tu_path(path, sizeof path, dir, "ok.png"), err, sizeof err), MS_OK);
    assert_true(tu_file_exists(path));
    /* An output without a writer is its bytes (a glb made after the render), written with the others, all or
     * nothing: read back equal; bytes promised but missing are refused and nothing is left behind. */
    static const char glb_bytes[] = "glTF\x02\0\0\0 any bytes, \0 zeros included";
    ms_output raw[2] = { { "-o", tu_path(path, sizeof path, dir, "ok2.png"), ms_png_write_stream, NULL, NULL, 0 },
                         { "--gltf", NULL, NULL, NULL, glb_bytes, sizeof glb_bytes } };
    char raw_path[4096];
    raw[1].path = tu_path(raw_path, sizeof raw_path, dir, "raw.glb");
    assert_int_equal(ms_outputs_check(raw, 2, err, sizeof err), MS_OK);
    assert_int_equal(ms_outputs_write(&f, raw, 2, err, sizeof err), MS_OK);
    FILE *rf = fopen(raw_path, "rb");
    assert_non_null(rf);
    char back[sizeof glb_bytes + 8];
    assert_int_equal(fread(back, 1, sizeof back, rf), sizeof glb_bytes);
    fclose(rf);
    assert_memory_equal(back, glb_bytes, sizeof glb_bytes);
    assert_int_equal(remove(raw_path), 0);
    assert_int_equal(remove(path), 0);
    raw[1].bytes = NULL;
    assert_int_equal(ms_outputs_write(&f, raw, 2, err, sizeof err), MS_ERR_IO);
    printf("bytes missing: %s\n", err);
    assert_false(tu_file_exists(raw_path));
    assert_false(tu_file_exists(path));
    f.vis[5] = NAN;
    assert_int_equal(ms_frame_check_finite(&f, "frame", err, sizeof err), MS_ERR_INVALID);
    ms_frame_free(&f);
    ms_scene_free(&sc);
    assert_string_equal(ms_status_name(MS_ERR_BUDGET), "over the memory budget");
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_abi_matches),
        cmocka_unit_test(test_abi_size_mismatch),
        cmocka_unit_test(test_abi_version_and_table),
        cmocka_unit_test(test_abi_option_sizes),
        cmocka_unit_test(test_abi_options_read_at_their_size),
        cmocka_unit_test(test_abi_bake_options_of_an_earlier_header),
        cmocka_unit_test(test_stats_counter_by_name),
        cmocka_unit_test(test_statuses),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
