/* A frame tile by tile and a lightmap row by row (the entry points the CLI's MPI mode distributes), against
 * the whole-frame answer of ms_render and ms_bake as the oracle:
 *   - the tiles of a frame rendered by two jobs in random order and random chunks, one job's tiles copied into
 *     the other, which finishes: V, S, front, rgb and exposure equal ms_render's bit for bit, for the grid and
 *     stratified patterns, the interleaved one (its filter crosses tiles) and hpc (a frame-level method);
 *   - the same with three lights (rect, disk, sphere) and OBJ/MTL materials, one specular: every light's V, S,
 *     S_spec and front planes and the summed shading;
 *   - the stats' counts (visible pixels, shadow rays, penumbra pixels) summed over the jobs equal ms_render's;
 *   - hpc-scanline refuses a split frame and renders a whole one; bad tile lists are refused;
 *   - a lightmap's rows baked by two layouts in random bands and copied into one equal ms_bake's. */
#include "testutil.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void shuffle(int *a, int n, tu_rng *r)
{
    for (int i = n - 1; i > 0; i--) {
        const int j = (int)(tu_rng_next(r) % (uint64_t)(i + 1));
        const int t = a[i]; a[i] = a[j]; a[j] = t;
    }
}

/* Renders every tile in two jobs (tiles shuffled, chunks of 1..7, alternately to job a and b), copies b's
 * tiles into a, sums b's counts into a's stats, finishes a into *out. */
static void render_split(const ms_scene *sc, const ms_render_options *o, uint64_t seed, ms_frame *out)
{
    char err[512];
    ms_frame_job *a, *b;
    assert_int_equal(ms_frame_job_create(sc, o, &a, err, sizeof err), 0);
    assert_int_equal(ms_frame_job_create(sc, o, &b, err, sizeof err), 0);
    assert_int_equal(ms_frame_job_splittable(a), 1);
    int tx, ty;
    const int n = ms_frame_job_tiles(a, &tx, &ty);
    assert_int_equal(n, tx * ty);
    int *order = malloc((size_t)n * sizeof *order);
    unsigned char *in_b = calloc((size_t)n, 1);
    assert_non_null(order);
    assert_non_null(in_b);
    for (int i = 0; i < n; i++) order[i] = i;
    tu_rng r = { seed };
    shuffle(order, n, &r);
    int turn = 0;
    for (int i = 0; i < n;) {
        int c = 1 + (int)(tu_rng_next(&r) % 7);
        if (c > n - i) c = n - i;
        ms_frame_job *j = turn ? b : a;
        if (ms_frame_job_render(j, order + i, c, err, sizeof err)) fail_msg("%s", err);
        for (int k = 0; k < c && turn; k++) in_b[order[i + k]] = 1;
        i += c;
        turn ^= 1;
    }
    ms_frame *fa = ms_frame_job_frame(a), *fb = ms_frame_job_frame(b);
    const int W = fa->width, H = fa->height;
    for (int t = 0; t < n; t++) {
        if (!in_b[t]) continue;
        for (int y = (t / tx) * MS_TILE_SIZE; y < (t / tx + 1) * MS_TILE_SIZE && y < H; y++)
            for (int x = (t % tx) * MS_TILE_SIZE; x < (t % tx + 1) * MS_TILE_SIZE && x < W; x++) {
                for (int l = 0; l < (fa->n_lights > 0 ? fa->n_lights : 1); l++) {   /* every light's planes */
                    const size_t i = (size_t)l * W * H + (size_t)y * W + x;
                    fa->vis[i] = fb->vis[i];
                    fa->shadow[i] = fb->shadow[i];
                    fa->shadow_spec[i] = fb->shadow_spec[i];
                    fa->front[i] = fb->front[i];
                }
            }
    }
    fa->stats.visible_pixels += fb->stats.visible_pixels;
    fa->stats.shadow_rays += fb->stats.shadow_rays;
    fa->stats.penumbra_pixels += fb->stats.penumbra_pixels;
    if (ms_frame_job_finish(a, out, err, sizeof err)) fail_msg("%s", err);
    ms_frame_job_free(a);
    ms_frame_job_free(b);
    free(order);
    free(in_b);
}

static void check_same(const ms_frame *w, const ms_frame *s, const char *what)
{
    const size_t n = (size_t)w->width * w->height;
    assert_int_equal(w->width, s->width);
    assert_int_equal(w->height, s->height);
    assert_int_equal(w->n_lights, s->n_lights);
    assert_int_equal(w->shadow_spec != NULL, s->shadow_spec != NULL);
    const size_t planes = w->n_lights > 0 ? (size_t)w->n_lights : 1;
    size_t bad = 0;
    for (size_t i = 0; i < n; i++)
        bad += memcmp(&w->rgb[3 * i], &s->rgb[3 * i], 3 * sizeof(float)) != 0;
    for (size_t i = 0; i < planes * n; i++)   /* every light's V, S, S_spec and front */
        bad += memcmp(&w->vis[i], &s->vis[i], sizeof(float)) || memcmp(&w->shadow[i], &s->shadow[i], sizeof(float)) ||
               w->front[i] != s->front[i] ||
               (w->shadow_spec && memcmp(&w->shadow_spec[i], &s->shadow_spec[i], sizeof(float)));
    if (bad) fail_msg("%s: %zu of %zu pixel values differ from the whole frame", what, bad, (1 + planes) * n);
    assert_memory_equal(&w->exposure, &s->exposure, sizeof(float));
}

static void test_split_frames(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    static const struct { const char *method; ms_pattern pattern; int samples; } cases[] = {
        { "scanline", MS_PATTERN_GRID, 256 },
        { "raytrace", MS_PATTERN_STRATIFIED, 64 },
        { "raytrace", MS_PATTERN_INTERLEAVED, 256 },
        { "hpc", MS_PATTERN_GRID, 256 },
    };
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        ms_render_options o;
        tu_render_options_default(&o);
        o.method = cases[c].method;
        o.pattern = cases[c].pattern;
        o.samples = cases[c].samples;
        o.width = 83;    /* partial tiles at the right and bottom */
        o.height = 50;
        o.threads = 2;
        char err[512];
        ms_frame whole, split;
        if (ms_render(&sc, &o, &whole, err, sizeof err)) fail_msg("%s", err);
        render_split(&sc, &o, 1000 + c, &split);
        char what[96];
        snprintf(what, sizeof what, "%s, %s pattern", cases[c].method, ms_pattern_name(cases[c].pattern));
        check_same(&whole, &split, what);
        assert_int_equal(whole.stats.visible_pixels, split.stats.visible_pixels);
        assert_int_equal(whole.stats.shadow_rays, split.stats.shadow_rays);
        assert_int_equal(whole.stats.penumbra_pixels, split.stats.penumbra_pixels);
        ms_frame_free(&whole);
        ms_frame_free(&split);
    }
    ms_scene_free(&sc);
}

/* Three lights (a rect, a disk, a sphere: one query at a time with its outline disk) over an occluder on a
 * ground of two OBJ/MTL materials, one with a specular lobe (S_spec differs from S there): split frames equal
 * the whole frame for every light's planes, S_spec and the summed shading; the scene's S_spec must differ
 * from S somewhere, or the specular planes were not exercised. */
static void test_split_lights_materials(void **state)
{
    (void)state;
    const char *dir = tu_tmpdir("frame_job_lights");
    char path[1024];
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "m.mtl"),
        "newmtl matte\nKd 0.8 0.3 0.1\n\nnewmtl shiny\nKd 0.9 0.9 0.9\nPm 0.5\nPr 0.3\n"), 0);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "m.obj"),
        "mtllib m.mtl\n"
        "v -3 0 -3\nv 0 0 -3\nv 3 0 -3\nv -3 0 3\nv 0 0 3\nv 3 0 3\n"
        "v -0.7 1 -0.7\nv 0.7 1 -0.7\nv 0.7 1 0.7\nv -0.7 1 0.7\n"
        "usemtl matte\nf 4 5 2\nf 4 2 1\n"
        "usemtl shiny\nf 5 6 3\nf 5 3 2\nf 7 9 8\nf 7 10 9\n"), 0);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"m.obj\"}],"
        "\"camera\":{\"eye\":[0,4,5],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":55,\"width\":45,\"height\":37},"
        "\"lights\":[{\"corner\":[-1,3,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2],\"emission\":[3,3,3]},"
        "{\"shape\":\"disk\",\"center\":[1.5,2.5,0],\"normal\":[-1,-2,0],\"radius\":0.6,\"emission\":[4,2,1]},"
        "{\"shape\":\"sphere\",\"center\":[-1.5,2,1],\"radius\":0.4,\"emission\":[1,2,4]}],"
        "\"render\":{\"samples\":256}}"), 0);
    ms_scene sc;
    char err[512];
    if (ms_scene_load(path, &sc, err, sizeof err)) fail_msg("%s", err);
    static const struct { const char *method; ms_pattern pattern; int samples; } cases[] = {
        { "scanline", MS_PATTERN_GRID, 256 },
        { "raytrace", MS_PATTERN_INTERLEAVED, 256 },
        { "hpc", MS_PATTERN_GRID, 256 },
    };
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        ms_render_options o;
        tu_render_options_default(&o);
        o.method = cases[c].method;
        o.pattern = cases[c].pattern;
        o.samples = cases[c].samples;
        o.threads = 2;
        ms_frame whole, split;
        if (ms_render(&sc, &o, &whole, err, sizeof err)) fail_msg("%s", err);
        assert_int_equal(whole.n_lights, 3);
        const size_t n = (size_t)whole.width * whole.height;
        size_t spec_differs = 0;
        for (size_t i = 0; i < 3 * n; i++) spec_differs += whole.shadow_spec[i] != whole.shadow[i];
        assert_true(spec_differs > 0);
        render_split(&sc, &o, 2000 + c, &split);
        char what[96];
        snprintf(what, sizeof what, "three lights, materials: %s, %s pattern", cases[c].method,
                 ms_pattern_name(cases[c].pattern));
        check_same(&whole, &split, what);
        assert_int_equal(whole.stats.visible_pixels, split.stats.visible_pixels);
        assert_int_equal(whole.stats.shadow_rays, split.stats.shadow_rays);
        assert_int_equal(whole.stats.penumbra_pixels, split.stats.penumbra_pixels);
        ms_frame_free(&whole);
        ms_frame_free(&split);
    }
    ms_scene_free(&sc);
}

static void test_refusals(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = "hpc-scanline";
    o.samples = 256;
    o.width = 40;
    o.height = 40;
    char err[512];
    ms_frame_job *j;
    assert_int_equal(ms_frame_job_create(&sc, &o, &j, err, sizeof err), 0);
    assert_int_equal(ms_frame_job_splittable(j), 0);
    const int t0 = 0;
    assert_int_not_equal(ms_frame_job_render(j, &t0, 1, err, sizeof err), 0);
    assert_non_null(strstr(err, "whole frames"));
    ms_frame_job_free(j);
    /* the whole frame in one call: ms_render's answer */
    ms_frame whole, viajob;
    assert_int_equal(ms_render(&sc, &o, &whole, err, sizeof err), 0);
    assert_int_equal(ms_frame_job_create(&sc, &o, &j, err, sizeof err), 0);
    assert_int_equal(ms_frame_job_render(j, NULL, ms_frame_job_tiles(j, NULL, NULL), err, sizeof err), 0);
    assert_int_equal(ms_frame_job_finish(j, &viajob, err, sizeof err), 0);
    ms_frame_job_free(j);
    check_same(&whole, &viajob, "hpc-scanline whole");
    ms_frame_free(&whole);
    ms_frame_free(&viajob);
    /* tile numbers out of range, and NULL with the wrong count */
    o.method = "raytrace";
    assert_int_equal(ms_frame_job_create(&sc, &o, &j, err, sizeof err), 0);
    const int n = ms_frame_job_tiles(j, NULL, NULL), bad[2] = { 0, n };
    assert_int_not_equal(ms_frame_job_render(j, bad, 2, err, sizeof err), 0);
    assert_non_null(strstr(err, "not in"));
    assert_int_not_equal(ms_frame_job_render(j, NULL, n - 1, err, sizeof err), 0);
    ms_frame_job_free(j);
    ms_scene_free(&sc);
}

/* Progress and cancellation of frames: fractions that only grow, to 1; a non-zero return stops the frame
 * soon after (tiles not begun are skipped) with MS_ERR_CANCELLED and no frame. */
typedef struct progress_log { int calls, cancel_at; double last; int grew; } progress_log;

static int log_progress(void *user, double f)
{
    progress_log *p = user;
    p->grew &= f > p->last;
    p->last = f;
    return ++p->calls == p->cancel_at;
}

static void test_progress_cancel(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = "raytrace";
    o.samples = 256;
    o.width = 96;
    o.height = 64;
    char err[512];
    ms_frame f;
    progress_log full = { 0, -1, 0.0, 1 };
    o.progress = log_progress;
    o.progress_user = &full;
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
    assert_true(full.grew);
    assert_true(full.last == 1.0);
    assert_true(full.calls > 4);
    ms_frame_free(&f);
    for (int at = 1; at <= 3; at++) {
        progress_log stop = { 0, at, 0.0, 1 };
        o.progress_user = &stop;
        o.threads = 1;   /* one thread: no tile is under way when it cancels, so no further call */
        assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), MS_ERR_CANCELLED);
        assert_non_null(strstr(err, "cancelled"));
        assert_int_equal(stop.calls, at);
        assert_null(f.vis);
        assert_null(f.rgb);
    }
    ms_scene_free(&sc);
}

static void test_split_bake(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_bake_options bo;
    memset(&bo, 0, sizeof bo);
    bo.size = 40;
    bo.uv_set = -1;
    bo.points.samples = 256;
    bo.points.threads = 2;
    bo.points.isa = tu_isa_cap();
    char err[512];
    ms_lightmap whole, a, b;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &whole, err, sizeof err), MS_OK);
    ms_accel *acc;
    assert_int_equal(ms_accel_build(&sc, 2, &acc, err, sizeof err), MS_OK);
    assert_int_equal(ms_bake_layout(&sc, &bo, &a, err, sizeof err), MS_OK);
    assert_int_equal(ms_bake_layout(&sc, &bo, &b, err, sizeof err), MS_OK);
    assert_int_equal(a.texels, whole.texels);
    const int W = a.frame.width;
    tu_rng r = { 77 };
    int turn = 0;
    for (int y = 0; y < W;) {
        int c = 1 + (int)(tu_rng_next(&r) % 6);
        if (c > W - y) c = W - y;
        if (ms_bake_rows(acc, &bo, turn ? &b : &a, y, y + c, err, sizeof err)) fail_msg("%s", err);
        if (turn) {
            const size_t o0 = (size_t)y * W, n = (size_t)c * W;
            memcpy(a.frame.vis + o0, b.frame.vis + o0, n * sizeof(float));
            memcpy(a.frame.shadow + o0, b.frame.shadow + o0, n * sizeof(float));
            memcpy(a.frame.front + o0, b.frame.front + o0, n * sizeof(uint16_t));
        }
        y += c;
        turn ^= 1;
    }
    assert_int_equal(ms_bake_rows(acc, &bo, &a, 5, 3, err, sizeof err), MS_ERR_INVALID);
    assert_int_equal(ms_bake_finish(&sc, &bo, &a, err, sizeof err), MS_OK);
    check_same(&whole.frame, &a.frame, "bake in bands");
    ms_lightmap_free(&whole);
    ms_lightmap_free(&a);
    ms_lightmap_free(&b);
    ms_accel_free(acc);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_split_frames),
        cmocka_unit_test(test_split_lights_materials),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_progress_cancel),
        cmocka_unit_test(test_split_bake),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
