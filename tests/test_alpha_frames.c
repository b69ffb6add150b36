/* Alpha-tested occluders in whole frames, bakes and scene files, on the leaf-card scene of util/alpha_leaves.c
 * (the masks against its oracle: test_alpha.c): every method's frames equal raytrace's V and S; every primary
 * through the cut-outs the same V and S bit for bit; without the alpha table the cards occlude as whole quads;
 * a bake honours alpha; the loading rules of alpha modes and cutoffs. */
#include "alpha_leaves.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "accel/bvh.h"
#include "light/pattern.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- whole frames: every method's V and S equal raytrace's ---- */

static void test_frames_equal_raytrace(void **state)
{
    (void)state;
    ms_scene sc;
    char dir[4096];
    al_load_scene("gltf", &sc, dir, sizeof dir);
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = "raytrace";
    o.samples = 1024;
    o.width = o.height = 32;
    o.threads = 1;
    ms_frame ref;
    char err[512];
    assert_int_equal(ms_render(&sc, &o, &ref, err, sizeof err), 0);
    const char *const *names = ms_method_names();
    for (int m = 0; names[m]; m++) {
        ms_frame f;
        o.method = names[m];
        const int rc = ms_render(&sc, &o, &f, err, sizeof err);
        if (rc) fprintf(stderr, "%s: %s\n", names[m], err);
        assert_int_equal(rc, 0);
        const tu_agreement a = tu_compare_frames(&f, &ref);
        printf("frame %-13s vs raytrace: %ld of %ld pixels differ in V, %ld in S only\n", names[m], a.differ, a.pixels,
               a.s_differ_same_v);
        assert_int_equal(a.miss_mismatch, 0);
        /* The leaf samples near the cutoff are ties between methods only where the alpha function's inputs
         * differ, and they do not: every method hands it the same floats. */
        assert_int_equal(a.differ, 0);
        assert_int_equal(a.s_differ_same_v, 0);
        ms_frame_free(&f);
    }
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

/* The 3D-rasterization primaries and bvh --consistent (issue 14) look through the cut-outs as the bvh primary
 * does: the same V and S bit for bit among themselves, and no pixel hit by one and missed by the watertight
 * bvh primary (which would mean a hole seen differently). */
static void test_primaries_through_cutouts(void **state)
{
    (void)state;
    ms_scene sc;
    char dir[4096], err[512];
    al_load_scene("gltf", &sc, dir, sizeof dir);
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = "raytrace";
    o.samples = 256;
    o.width = o.height = 40;
    o.threads = 1;
    ms_frame wt, ref;
    assert_int_equal(ms_render(&sc, &o, &wt, err, sizeof err), 0);
    o.primary = "bvh";
    o.consistent_primary = 1;
    assert_int_equal(ms_render(&sc, &o, &ref, err, sizeof err), 0);
    o.consistent_primary = 0;
    const tu_agreement w = tu_compare_frames(&ref, &wt);
    printf("bvh --consistent vs bvh through cut-outs: %ld of %ld pixels differ in V, %ld hit by one only\n", w.differ,
           w.pixels, w.miss_mismatch);
    assert_int_equal(w.miss_mismatch, 0);
    static const char *const names[] = { "3dr-bb", "3dr-bin", "3dr-fc", "3dr-fs", "3dr-full" };
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        ms_frame f;
        o.primary = names[i];
        assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
        assert_memory_equal(f.vis, ref.vis, (size_t)40 * 40 * sizeof(float));
        assert_memory_equal(f.shadow, ref.shadow, (size_t)40 * 40 * sizeof(float));
        ms_frame_free(&f);
    }
    ms_frame_free(&ref);
    ms_frame_free(&wt);
    ms_scene_free(&sc);
}

/* Without the alpha table (what an opaque material gives) the cards occlude as whole quads: the alpha test only
 * ever gives samples back, and it does give many. */
static void test_opaque_cards_are_quads(void **state)
{
    (void)state;
    setup s;
    al_setup_make(&s, "gltf", 24);
    /* The same BVH without the alpha table: every card a full quad. */
    ms_render_ctx ctx = s.ctx;
    ctx.alpha = NULL;
    const ms_shadow_method *sm = ms_find_shadow_method("scanline");
    const size_t mw = (size_t)ctx.mask_words, n = (size_t)s.nq * mw;
    uint64_t *front = calloc(n + 1, 8), *va = calloc(n + 1, 8), *vo = calloc(n + 1, 8), cnt[MS_MAX_COUNTERS] = { 0 };
    assert_non_null(front);
    assert_non_null(va);
    assert_non_null(vo);
    for (int i = 0; i < s.nq; i++) ms_front_mask(&ctx, &s.q[i], NULL, front + i * mw);
    char err[256];
    void *st = NULL;
    assert_int_equal(sm->create(&s.ctx, &st, err, sizeof err), 0);
    assert_int_equal(sm->visibility(st, &s.ctx, s.q, s.nq, front, va, cnt), 0);
    sm->destroy(st);
    assert_int_equal(sm->create(&ctx, &st, err, sizeof err), 0);
    assert_int_equal(sm->visibility(st, &ctx, s.q, s.nq, front, vo, cnt), 0);
    sm->destroy(st);
    long more = 0, fewer = 0;
    for (size_t w = 0; w < n; w++) {
        more += __builtin_popcountll(va[w] & ~vo[w]);
        fewer += __builtin_popcountll(vo[w] & ~va[w]);
    }
    printf("alpha-tested vs opaque cards: %ld samples lit only through the cut-outs, %ld lit only when opaque\n", more, fewer);
    assert_true(more > 1000);
    assert_int_equal(fewer, 0);
    free(front);
    free(va);
    free(vo);
    al_setup_free(&s);
}

/* Baking goes through the points API, so it honours alpha: the same lightmap with the cards alpha-tested and
 * opaque has every texel at least as visible (the alpha test only gives samples back, on the same samples)
 * and many texels more. */
static void test_bake_honours_alpha(void **state)
{
    (void)state;
    ms_scene sc;
    char dir[4096], err[512];
    al_load_scene("gltf", &sc, dir, sizeof dir);
    ms_bake_options bo;
    memset(&bo, 0, sizeof bo);
    bo.size = 64;
    bo.uv_set = -1;   /* xatlas for every triangle: the cards' own UVs overlap (and repeat) */
    bo.points.threads = 1;
    bo.points.isa = tu_isa_cap();
    ms_lightmap a, o;
    ms_status rc = ms_bake(&sc, NULL, &bo, &a, err, sizeof err);
    if (rc) fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, MS_OK);
    sc.materials[0].alpha_mode = MS_ALPHA_OPAQUE;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &o, err, sizeof err), MS_OK);
    long more = 0, less = 0, texels = 0;
    for (int i = 0; i < 64 * 64; i++) {
        if (a.triangle[i] == MS_NO_TRIANGLE) continue;
        texels++;
        more += a.frame.vis[i] > o.frame.vis[i];
        less += a.frame.vis[i] < o.frame.vis[i];
    }
    printf("bake: %ld texels on triangles, %ld more visible with alpha-tested cards, %ld less\n", texels, more, less);
    assert_true(more > texels / 50);
    assert_int_equal(less, 0);
    ms_lightmap_free(&a);
    ms_lightmap_free(&o);
    ms_scene_free(&sc);
}

/* Loading: BLEND is tested as MASK at 0.5 with one warning; `d` without map_d stays opaque; a bad alpha mode or
 * cutoff from a library caller is refused by validation. */
static int n_warnings;
static char last_warning[512];
static void on_warning(void *user, const char *msg)
{
    (void)user;
    n_warnings++;
    snprintf(last_warning, sizeof last_warning, "%s", msg);
}

static void test_loading_rules(void **state)
{
    (void)state;
    ms_scene sc;
    char dir[4096], path[4096], err[512];
    al_load_scene("gltf", &sc, dir, sizeof dir);
    ms_scene_free(&sc);
    /* The same glTF with BLEND instead of MASK (and a cutoff BLEND ignores). */
    FILE *f = fopen(tu_path(path, sizeof path, dir, "leaves.gltf"), "r");
    assert_non_null(f);
    static char text[16384];
    const size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = 0;
    char *m = strstr(text, "\"alphaMode\":\"MASK\",\"alphaCutoff\":0.5");
    assert_non_null(m);
    memcpy(m, "\"alphaMode\":\"BLEND\",\"alphaCutoff\":0.9", strlen("\"alphaMode\":\"BLEND\",\"alphaCutoff\":0.9"));
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "leaves.gltf"), text), 0);
    n_warnings = 0;
    ms_set_warning_handler(on_warning, NULL);
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), &sc, err, sizeof err), 0);
    ms_set_warning_handler(NULL, NULL);
    printf("BLEND: %d warning(s): %s\n", n_warnings, last_warning);
    assert_int_equal(n_warnings, 1);
    assert_non_null(strstr(last_warning, "BLEND"));
    assert_int_equal((int)sc.n_materials, 1);
    assert_int_equal(sc.materials[0].alpha_mode, MS_ALPHA_MASK);
    assert_true(sc.materials[0].alpha_cutoff == 0.5f);
    /* A library caller's bad alpha fields. */
    sc.materials[0].alpha_cutoff = 1.5f;
    assert_int_not_equal(ms_scene_validate(&sc, "caller", err, sizeof err), 0);
    printf("refused: %s\n", err);
    sc.materials[0].alpha_cutoff = 0.5f;
    sc.materials[0].alpha_mode = 7;
    assert_int_not_equal(ms_scene_validate(&sc, "caller", err, sizeof err), 0);
    sc.materials[0].alpha_mode = MS_ALPHA_MASK_MAP;
    sc.materials[0].alpha_texture = 99;
    assert_int_not_equal(ms_scene_validate(&sc, "caller", err, sizeof err), 0);
    ms_scene_free(&sc);
    /* OBJ: d 0.3 without map_d is opaque; with map_d the map decides. */
    al_load_scene("obj", &sc, dir, sizeof dir);
    ms_scene_free(&sc);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "leaves.mtl"),
                                   "newmtl ground\nKd 0.8 0.8 0.8\n\nnewmtl leaf\nKd 0.2 0.6 0.2\nd 0.3\nmap_Kd leaf.png\n"), 0);
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), &sc, err, sizeof err), 0);
    for (size_t i = 0; i < sc.n_materials; i++) assert_int_equal(sc.materials[i].alpha_mode, MS_ALPHA_OPAQUE);
    ms_scene_free(&sc);
    /* A map_d that cannot be read: one warning, opaque. */
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "leaves.mtl"),
                                   "newmtl leaf\nmap_d missing.png\n"), 0);
    n_warnings = 0;
    ms_set_warning_handler(on_warning, NULL);
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), &sc, err, sizeof err), 0);
    ms_set_warning_handler(NULL, NULL);
    printf("missing map_d: %d warning(s): %s\n", n_warnings, last_warning);
    assert_int_equal(n_warnings, 1);
    for (size_t i = 0; i < sc.n_materials; i++) assert_int_equal(sc.materials[i].alpha_mode, MS_ALPHA_OPAQUE);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frames_equal_raytrace),
        cmocka_unit_test(test_primaries_through_cutouts),
        cmocka_unit_test(test_opaque_cards_are_quads),
        cmocka_unit_test(test_loading_rules),
        cmocka_unit_test(test_bake_honours_alpha),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
