/* Bakes of several lights and of every light shape (ms_bake, `microshadow bake`), each against an oracle:
 *   - two lights (a rect and a sphere; and a textured rect with a disk): every light's V, S and front
 *     planes equal, texel for texel and bit for bit, the bake of the scene with that light alone, and the
 *     irradiance on the triangles is the sum of the single-light irradiances (every method);
 *   - a sphere light: every method's baked V, S and front equal raytrace's texel for texel, and raytrace's
 *     V equals a brute-force test of each texel's samples on its exact outline disk where that decides;
 *   - the CLI: a two-light bake's EXR has S0, S1, V0, V1 equal to the API's planes, --vis as PFM is light
 *     0, --shadow as EXR has every light. */
#include "testutil.h"
#include "light/pattern.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void bake_options(ms_bake_options *o, const char *method, int size)
{
    memset(o, 0, sizeof *o);
    o->size = size;
    o->uv_set = -1;        /* xatlas: the same layout for the same triangles */
    o->points.samples = 256;
    o->points.threads = 2;
    o->points.method = method;
    o->points.isa = tu_isa_cap();
}

static ms_light sphere_light(float x, float y, float z, float r, ms_vec3 em)
{
    ms_light l;
    memset(&l, 0, sizeof l);
    assert_int_equal(ms_light_sphere(&l, (ms_vec3){ x, y, z }, r), 0);
    l.emission = em;
    return l;
}

/* The quad (tu_make_quad) with lights[0..n) (copied; textures duplicated, the scene owns them). */
static void quad_with(ms_scene *sc, const ms_light *lights, size_t n)
{
    tu_make_quad(sc);
    sc->lights = calloc(n, sizeof *sc->lights);
    assert_non_null(sc->lights);
    for (size_t l = 0; l < n; l++) {
        sc->lights[l] = lights[l];
        if (lights[l].texture) {
            const size_t nt = (size_t)lights[l].texture_width * lights[l].texture_height * 3;
            float *t = malloc(nt * sizeof *t);
            assert_non_null(t);
            memcpy(t, lights[l].texture, nt * sizeof *t);
            sc->lights[l].texture = t;
        }
    }
    sc->n_lights = n;
    sc->light = sc->lights[0];
}

/* The two-light bake against the single-light bakes, for one method. */
static void two_lights_vs_single(const ms_light *pair, const char *method, int size)
{
    ms_scene both, one[2];
    quad_with(&both, pair, 2);
    quad_with(&one[0], &pair[0], 1);
    quad_with(&one[1], &pair[1], 1);
    char err[512];
    ms_bake_options bo;
    bake_options(&bo, method, size);
    ms_lightmap lm, lm1[2];
    assert_int_equal(ms_bake(&both, NULL, &bo, &lm, err, sizeof err), MS_OK);
    assert_int_equal(lm.frame.n_lights, 2);
    const size_t nt = (size_t)size * size;
    long partial[2] = { 0, 0 }, rgb_checked = 0;
    for (int l = 0; l < 2; l++) {
        assert_int_equal(ms_bake(&one[l], NULL, &bo, &lm1[l], err, sizeof err), MS_OK);
        assert_int_equal(lm1[l].frame.n_lights, 1);
        assert_int_equal(lm1[l].texels, lm.texels);
        long differ = 0;
        for (size_t i = 0; i < nt; i++) {
            differ += memcmp(&lm.frame.vis[l * nt + i], &lm1[l].frame.vis[i], sizeof(float)) != 0 ||
                      memcmp(&lm.frame.shadow[l * nt + i], &lm1[l].frame.shadow[i], sizeof(float)) != 0 ||
                      lm.frame.front[l * nt + i] != lm1[l].frame.front[i];
            partial[l] += lm1[l].frame.vis[i] > 0.0f && lm1[l].frame.vis[i] < 1.0f;
        }
        if (differ) fprintf(stderr, "two lights, %s: light %d: %ld texels differ from its single-light bake\n", method, l, differ);
        assert_int_equal(differ, 0);
    }
    for (size_t i = 0; i < nt; i++) {
        if (lm.triangle[i] == MS_NO_TRIANGLE) continue;
        for (int c = 0; c < 3; c++) {
            const float sum = lm1[0].frame.rgb[3 * i + c] + lm1[1].frame.rgb[3 * i + c];
            assert_true(fabsf(lm.frame.rgb[3 * i + c] - sum) <= 1e-6f * fmaxf(1.0f, fabsf(sum)));
        }
        rgb_checked++;
    }
    /* both lights cast a penumbra somewhere: the comparison saw shadowed texels of each */
    assert_true(partial[0] > 0 && partial[1] > 0);
    assert_true(rgb_checked > 0);
    ms_lightmap_free(&lm);
    ms_lightmap_free(&lm1[0]);
    ms_lightmap_free(&lm1[1]);
    ms_scene_free(&both);
    ms_scene_free(&one[0]);
    ms_scene_free(&one[1]);
}

static void test_rect_and_sphere(void **st)
{
    (void)st;
    ms_light pair[2];
    memset(&pair[0], 0, sizeof pair[0]);
    pair[0] = (ms_light){ { -1, 6, -1 }, { 2, 0, 0 }, { 0, 0, 2 }, { 3, 3, 3 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    pair[1] = sphere_light(3.0f, 4.5f, 1.0f, 0.7f, (ms_vec3){ 1, 2, 4 });
    const char *const *names = ms_method_names();
    for (int mi = 0; names[mi]; mi++) two_lights_vs_single(pair, names[mi], 32);
}

static void test_textured_and_disk(void **st)
{
    (void)st;
    /* a 4x2 texture with a black column and coloured texels: S weights by it, the irradiance by its mean */
    float tex[4 * 2 * 3] = { 1, 1, 1, 0, 0, 0, 2, 1, 0.5f, 0.2f, 0.9f, 0.3f,
                             0.5f, 0.5f, 0.5f, 0, 0, 0, 1, 3, 1, 0.7f, 0.1f, 0.1f };
    ms_light pair[2];
    pair[0] = (ms_light){ { -1, 6, -1 }, { 2, 0, 0 }, { 0, 0, 2 }, { 2, 2, 2 }, MS_LIGHT_RECT, tex, 4, 2, { 0, 0, 0 }, 0 };
    memset(&pair[1], 0, sizeof pair[1]);
    assert_int_equal(ms_light_disk(&pair[1], (ms_vec3){ -3, 4, 0.5f }, (ms_vec3){ 0.6f, -1, 0 }, 0.8f), 0);
    pair[1].emission = (ms_vec3){ 4, 2, 1 };
    two_lights_vs_single(pair, "scanline", 32);
    two_lights_vs_single(pair, "raytrace", 32);
}

typedef enum { NO = 0, YES = 1, UNSURE = 2 } verdict;   /* tu_segment_hits' answers */

/* Every method's sphere-light bake equals raytrace's; raytrace's V the brute force where it decides. The
 * sphere above the occluder, and one the occluder cuts through (texels inside it: V = S = 0, front 0; texels
 * that see part of its outline disk below their horizon). */
static void sphere_every_method(ms_light sph, int want_inside)
{
    ms_scene sc;
    quad_with(&sc, &sph, 1);
    const int size = 56;   /* enough occluder texels inside the cutting sphere (more than 10) in xatlas's layout */
    const size_t nt = (size_t)size * size;
    char err[512];
    ms_bake_options bo;
    bake_options(&bo, "raytrace", size);
    ms_lightmap ref, lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &ref, err, sizeof err), MS_OK);
    const char *const *names = ms_method_names();
    for (int mi = 0; names[mi]; mi++) {
        bake_options(&bo, names[mi], size);
        assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
        long differ = 0;
        for (size_t i = 0; i < nt; i++)
            differ += lm.frame.vis[i] != ref.frame.vis[i] || lm.frame.shadow[i] != ref.frame.shadow[i] ||
                      lm.frame.front[i] != ref.frame.front[i];
        if (differ) fprintf(stderr, "sphere bake, method %s: %ld texels differ from raytrace\n", names[mi], differ);
        assert_int_equal(differ, 0);
        ms_lightmap_free(&lm);
    }
    /* brute force: each texel's samples on its outline disk, every triangle but its own */
    float *pts = malloc(3 * 256 * sizeof *pts);
    assert_non_null(pts);
    const double c[3] = { sph.center.x, sph.center.y, sph.center.z }, R = sph.radius;
    long decided = 0, partial = 0, bad = 0, inside = 0, horizon = 0;
    for (size_t i = 0; i < nt; i++) {
        if (ref.triangle[i] == MS_NO_TRIANGLE) continue;
        const float *p = ref.position + 3 * i, *n = ref.normal + 3 * i;
        const double pd[3] = { p[0], p[1], p[2] };
        const double w[3] = { pd[0] - c[0], pd[1] - c[1], pd[2] - c[2] };
        const double d = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        ms_light disk;
        if (ms_light_sphere_outline(&sph, p, &disk)) {   /* inside the sphere */
            if (d < R * (1 - 1e-5)) {
                inside++;
                bad += ref.frame.vis[i] != 0.0f || ref.frame.shadow[i] != 0.0f || ref.frame.front[i] != 0;
            }
            continue;
        }
        ms_pattern_points(MS_PATTERN_GRID, &disk, 16, (uint32_t)(i % size), (uint32_t)(i / size), 0, pts);
        const double f2 = R * R / (d * d);
        const double dc[3] = { c[0] + w[0] * f2, c[1] + w[1] * f2, c[2] + w[2] * f2 }, dr = R * sqrt(d * d - R * R) / d;
        int nf = 0, nv = 0, unsure = 0, behind = 0;
        for (int s = 0; s < 256 && !unsure; s++) {
            const double L[3] = { pts[3 * s], pts[3 * s + 1], pts[3 * s + 2] };
            const double r[3] = { L[0] - dc[0], L[1] - dc[1], L[2] - dc[2] };
            const double rr = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
            const double side = (L[0] - pd[0]) * n[0] + (L[1] - pd[1]) * n[1] + (L[2] - pd[2]) * n[2];
            if (fabs(rr - dr) < 1e-5 * dr || fabs(side) < 1e-6) { unsure = 1; break; }
            if (rr > dr) continue;   /* off the disk: not counted */
            if (side <= 0) { behind = 1; continue; }   /* below the receiver's horizon: not counted */
            nf++;
            verdict v = YES;
            for (size_t t = 0; t < sc.n_tris && v != NO; t++) {
                if (t == ref.triangle[i]) continue;
                const verdict h = (verdict)tu_segment_hits(sc.tri + 9 * t, pd, L, 1e-4, 1.0 - 1e-4);
                if (h == UNSURE) { unsure = 1; break; }
                if (h == YES) v = NO;
            }
            nv += v == YES;
        }
        if (unsure) continue;
        decided++;
        partial += nv > 0 && nv < nf;
        horizon += behind && nf > 0;
        const float want = nf ? (float)nv / (float)nf : 0.0f;
        bad += want != ref.frame.vis[i] || nf != ref.frame.front[i];
    }
    printf("sphere bake (centre %g %g %g, r %g): %ld texels decided by the brute force (%ld in penumbra, %ld with the "
           "disk across their horizon), %ld inside the sphere; %ld differ from raytrace\n", c[0], c[1], c[2], R, decided,
           partial, horizon, inside, bad);
    assert_int_equal(bad, 0);
    assert_true(decided > (long)ref.texels * 8 / 10 && partial > 10);
    if (want_inside) assert_true(inside > 10 && horizon > 10);
    free(pts);
    ms_lightmap_free(&ref);
    ms_scene_free(&sc);
}

static void test_sphere_every_method(void **st)
{
    (void)st;
    sphere_every_method(sphere_light(0.5f, 5.0f, 0.2f, 0.9f, (ms_vec3){ 1, 1, 1 }), 0);
    sphere_every_method(sphere_light(0.3f, 1.6f, 0.2f, 1.2f, (ms_vec3){ 1, 1, 1 }), 1);
}

/* PFM (little-endian, rows bottom to top) into img. */
static void read_pfm(const char *path, int w, int h, float *img)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    int fw = 0, fh = 0;
    double scale = 0;
    assert_int_equal(fscanf(f, "Pf %d %d %lf", &fw, &fh, &scale), 3);
    fgetc(f);
    assert_int_equal(fw, w);
    assert_int_equal(fh, h);
    for (int y = h - 1; y >= 0; y--) assert_int_equal(fread(img + (size_t)y * w, sizeof(float), (size_t)w, f), (size_t)w);
    fclose(f);
}

static void test_cli_channels(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_lights_cli");
    char obj[1024], json[1024], exr[1024], vis[1024], sh[1024], e[512];
    tu_path(obj, sizeof obj, dir, "q.obj");
    tu_path(json, sizeof json, dir, "two.json");
    tu_path(exr, sizeof exr, dir, "lm.exr");
    tu_path(vis, sizeof vis, dir, "v.pfm");
    tu_path(sh, sizeof sh, dir, "s.exr");
    FILE *f = fopen(obj, "w");
    assert_non_null(f);
    fputs("v -10 0 -10\nv 10 0 10\nv 10 0 -10\nv -10 0 10\nv -2 2 -2\nv 2 2 2\nv 2 2 -2\nv -2 2 2\n"
          "f 1 2 3\nf 1 4 2\nf 5 6 7\nf 5 8 6\n", f);
    fclose(f);
    f = fopen(json, "w");
    assert_non_null(f);
    fputs("{ \"meshes\": [ { \"file\": \"q.obj\" } ],\n"
          "  \"camera\": { \"eye\": [0, 10, 12], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 60, \"width\": 32, \"height\": 32 },\n"
          "  \"lights\": [ { \"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2], \"emission\": [3, 3, 3] },\n"
          "    { \"shape\": \"sphere\", \"center\": [3, 4.5, 1], \"radius\": 0.7, \"emission\": [1, 2, 4] } ],\n"
          "  \"render\": { \"samples\": 256 } }\n", f);
    fclose(f);
    const int size = 24;
    const char *args[] = { "bake", json, "--uv", "xatlas", "--size", "24", "--samples", "256", "--threads", "2", "--quiet",
                           "-o", exr, "--vis", vis, "--shadow", sh, NULL };
    assert_int_equal(tu_run_cli(args, e, sizeof e), 0);
    ms_scene sc;
    char err[512];
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_bake_options bo;
    bake_options(&bo, NULL, size);
    bo.points.isa = MS_ISA_AUTO;   /* as the CLI runs: every ISA gives the same answer (test_points) */
    ms_lightmap lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    const size_t nt = (size_t)size * size;
    float *img = malloc(nt * sizeof *img);
    assert_non_null(img);
    static const char *const names[] = { "S0", "S1", "V0", "V1" };
    for (int c = 0; c < 4; c++) {
        assert_int_equal(tu_read_exr_channel(exr, names[c], size, size, img), 0);
        const float *want = (names[c][0] == 'S' ? lm.frame.shadow : lm.frame.vis) + (size_t)(names[c][1] - '0') * nt;
        assert_memory_equal(img, want, nt * sizeof *img);
    }
    assert_int_equal(tu_read_exr_channel(exr, "V", size, size, img), -1);   /* no plain V with several lights */
    assert_int_equal(tu_read_exr_channel(exr, "R", size, size, img), 0);
    for (size_t i = 0; i < nt; i++) assert_true(img[i] == lm.frame.rgb[3 * i]);
    assert_int_equal(tu_read_exr_channel(sh, "S1", size, size, img), 0);
    assert_memory_equal(img, lm.frame.shadow + nt, nt * sizeof *img);
    read_pfm(vis, size, size, img);
    assert_memory_equal(img, lm.frame.vis, nt * sizeof *img);
    free(img);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rect_and_sphere),
        cmocka_unit_test(test_textured_and_disk),
        cmocka_unit_test(test_sphere_every_method),
        cmocka_unit_test(test_cli_channels),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
