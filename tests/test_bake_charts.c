/* Charts, texel density, pages and the unwrap cache of a bake (src/render/bake_uvs.c, uv_validity.c,
 * atlas_pack.c, uv_cache.c, bake_pages.c), against answers made here:
 *   - an object whose UV0 is a valid layout keeps it (moved whole: MS_UV_PACK_REGIONS): in the glb (read by
 *     the tests' own reader) its TEXCOORD_1 is its TEXCOORD_0 under one scale and one offset, fitted here
 *     from the vertices, and the primitive's extras name UV set 0 and that scale-offset; an object whose UV0 overlaps itself goes to
 *     xatlas (its baked UV images are disjoint, which no single scale-offset of its UV0 could make);
 *   - a texel density that needs two pages gives two, each at least 70% covered by texel centres on
 *     triangles (counted here by rasterizing the baked UVs), every triangle on one page with its texels
 *     there and no texel centre in two triangles, and the lightmap looked up bilinearly at random surface
 *     points of both pages equals ms_visibility_points irradiance there; the CLI writes lm.exr and
 *     lm.1.exr;
 *   - the unwrap cache: a re-bake with another light takes the same UVs byte for byte, nothing unwrapped;
 *   - a cache of other geometry, a truncated one and one that is no cache are not used, each with one
 *     warning naming the file and the reason;
 *   - a 2 mm plate of triangles far under xatlas's area epsilon gets UVs for every triangle. */
#include "testutil.h"
#include "glb_read.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* An OBJ of quads (4 corners each, counter-clockwise seen from +normal) with one UV square per quad. */
static void write_quads(const char *path, int nq, const float (*p)[4][3], const float (*uv)[4])
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    for (int q = 0; q < nq; q++)
        for (int k = 0; k < 4; k++) fprintf(f, "v %.9g %.9g %.9g\n", p[q][k][0], p[q][k][1], p[q][k][2]);
    if (uv)
        for (int q = 0; q < nq; q++) {
            const float *r = uv[q];   /* u0 v0 u1 v1 */
            fprintf(f, "vt %.9g %.9g\nvt %.9g %.9g\nvt %.9g %.9g\nvt %.9g %.9g\n", r[0], r[1], r[2], r[1], r[2], r[3], r[0], r[3]);
        }
    for (int q = 0; q < nq; q++) {
        const int b = 4 * q + 1;
        if (uv) fprintf(f, "f %d/%d %d/%d %d/%d\nf %d/%d %d/%d %d/%d\n", b, b, b + 1, b + 1, b + 2, b + 2, b, b, b + 2, b + 2, b + 3, b + 3);
        else fprintf(f, "f %d %d %d\nf %d %d %d\n", b, b + 1, b + 2, b, b + 2, b + 3);
    }
    fclose(f);
}

/* A horizontal quad facing up: x0..x1, z0..z1 at height y. */
static void flat(float q[4][3], float x0, float x1, float z0, float z1, float y)
{
    const float c[4][3] = { { x0, y, z1 }, { x1, y, z1 }, { x1, y, z0 }, { x0, y, z0 } };
    memcpy(q, c, sizeof c);
}

static char g_warn[2048];
static void keep_warning(void *user, const char *msg)
{
    (void)user;
    if (strstr(msg, "UV cache")) snprintf(g_warn, sizeof g_warn, "%s", msg);
}

static void bake_opts(ms_bake_options *bo, int size)
{
    memset(bo, 0, sizeof *bo);
    bo->size = size;
    bo->uv_set = 1;   /* the CLI's default; the objects here have UV0 only */
    bo->points.samples = 256;
    bo->points.isa = tu_isa_cap();
}

/* ---- (a) a valid UV0 is kept, an overlapping one goes to xatlas ---- */

static void test_keep_and_chart(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_charts_keep");
    char path[512], json[512], text[2048], err[512] = "";
    float p[4][4][3];
    /* panel: two quads side by side in UV0 islands of different sizes */
    flat(p[0], 0, 1, 0, 1, 0);
    flat(p[1], 1, 2, 0, 1, 0);
    const float uv_panel[2][4] = { { 0.05f, 0.1f, 0.45f, 0.9f }, { 0.55f, 0.3f, 0.75f, 0.7f } };
    write_quads(tu_path(path, sizeof path, dir, "panel.obj"), 2, p, uv_panel);
    /* tiled: two quads on the same UV square (a tiling layout) */
    flat(p[2], 0, 1, 2, 3, 0);
    flat(p[3], 1, 2, 2, 3, 0);
    const float uv_tiled[2][4] = { { 0, 0, 1, 1 }, { 0, 0, 1, 1 } };
    write_quads(tu_path(path, sizeof path, dir, "tiled.obj"), 2, p + 2, uv_tiled);
    snprintf(text, sizeof text,
             "{\"meshes\":[{\"file\":\"panel.obj\"},{\"file\":\"tiled.obj\"}],"
             "\"camera\":{\"eye\":[1,5,1.5],\"target\":[1,0,1.5],\"up\":[0,0,-1],\"fov_y\":60,\"width\":64,\"height\":64},"
             "\"light\":{\"corner\":[0.5,3,1],\"edge_s\":[1,0,0],\"edge_t\":[0,0,1]}}");
    tu_path(json, sizeof json, dir, "scene.json");
    assert_int_equal(tu_write_file(json, text), 0);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_bake_options bo;
    bake_opts(&bo, 128);
    bo.uv_packing = MS_UV_PACK_REGIONS;   /* the kept layout under one scale-offset, recorded in the glb */
    ms_lightmap lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    assert_int_equal(lm.n_objects, 2);
    assert_int_equal(lm.object_uv_set[0], 0);
    assert_int_equal(lm.object_uv_set[1], -1);
    assert_int_equal(lm.unwrapped_tris, 4);
    /* tiled's baked UV images are disjoint: no texel centre in two of them */
    int twice = 0;
    for (int y = 0; y < 128; y++)
        for (int x = 0; x < 128; x++) {
            int in = 0;
            for (size_t t = 0; t < sc.n_tris; t++) {
                if (sc.tri_mesh[t] != 1) continue;
                const float *u = lm.uv + 6 * t;
                const double px = (x + 0.5) / 128, py = (y + 0.5) / 128;
                double e[3];
                for (int k = 0; k < 3; k++) {
                    const float *a = u + 2 * k, *b = u + 2 * ((k + 1) % 3);
                    e[k] = ((double)b[0] - a[0]) * (py - a[1]) - ((double)b[1] - a[1]) * (px - a[0]);
                }
                in += (e[0] > 0 && e[1] > 0 && e[2] > 0) || (e[0] < 0 && e[1] < 0 && e[2] < 0);
            }
            twice += in > 1;
        }
    assert_int_equal(twice, 0);
    /* the glb: panel's TEXCOORD_1 = TEXCOORD_0 * s + o, one s and o fitted here */
    char glb[512];
    tu_path(glb, sizeof glb, dir, "out.glb");
    assert_int_equal(ms_bake_write_gltf(&sc, &lm, NULL, glb, err, sizeof err), MS_OK);
    tu_glb g;
    assert_int_equal(tu_glb_read(glb, &g), 0);
    int kept = 0, charted = 0;
    for (int m = 0; tu_glb_item(&g, "meshes", m); m++) {
        const cJSON *prims = cJSON_GetObjectItem(tu_glb_item(&g, "meshes", m), "primitives");
        for (int k = 0; k < cJSON_GetArraySize(prims); k++) {
            const cJSON *pr = cJSON_GetArrayItem(prims, k);
            const cJSON *ex = cJSON_GetObjectItem(cJSON_GetObjectItem(pr, "extras"), "lightmap");
            assert_non_null(ex);
            const int set = cJSON_GetObjectItem(ex, "uvSet")->valueint;
            if (set < 0) { charted++; continue; }
            assert_int_equal(set, 0);
            const cJSON *attr = cJSON_GetObjectItem(pr, "attributes");
            size_t n0, n1;
            int c0, c1;
            float *t0 = tu_glb_floats(&g, cJSON_GetObjectItem(attr, "TEXCOORD_0")->valueint, &n0, &c0);
            float *t1 = tu_glb_floats(&g, cJSON_GetObjectItem(attr, "TEXCOORD_1")->valueint, &n1, &c1);
            assert_non_null(t0);
            assert_non_null(t1);
            assert_int_equal(n0, n1);
            /* fit from the vertices with the smallest and largest u0 */
            size_t lo = 0, hi = 0;
            for (size_t i = 0; i < n0; i++) {
                if (t0[2 * i] < t0[2 * lo]) lo = i;
                if (t0[2 * i] > t0[2 * hi]) hi = i;
            }
            const double s = (t1[2 * hi] - t1[2 * lo]) / (t0[2 * hi] - t0[2 * lo]);
            const double ou = t1[2 * lo] - s * t0[2 * lo], ov = t1[2 * lo + 1] - s * t0[2 * lo + 1];
            double worst = 0.0;
            for (size_t i = 0; i < n0; i++) {
                worst = fmax(worst, fabs(t1[2 * i] - (s * t0[2 * i] + ou)));
                worst = fmax(worst, fabs(t1[2 * i + 1] - (s * t0[2 * i + 1] + ov)));
            }
            printf("kept layout: TEXCOORD_1 = TEXCOORD_0 * %.6f + (%.6f, %.6f), worst residual %.2g\n", s, ou, ov, worst);
            assert_true(worst < 1e-6);
            assert_true(s > 0.0);
            const cJSON *so = cJSON_GetObjectItem(ex, "scaleOffset");
            assert_true(fabs(cJSON_GetArrayItem(so, 0)->valuedouble - s) < 1e-6);
            assert_true(fabs(cJSON_GetArrayItem(so, 2)->valuedouble - ou) < 1e-6);
            assert_true(fabs(cJSON_GetArrayItem(so, 3)->valuedouble - ov) < 1e-6);
            kept++;
            free(t0);
            free(t1);
        }
    }
    assert_int_equal(kept, 1);
    assert_int_equal(charted, 1);
    tu_glb_free(&g);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

/* ---- (b) a texel density over two pages ---- */

#define PSIZE 256
#define PLANES 8

/* Eight 2 x 2 plates with UV0 0-1 on a 4 x 2 grid, a floating plate not baked, a light above. */
static void write_pages_scene(const char *dir, char *json, size_t n, float light_x)
{
    char path[512], text[4096];
    int at = snprintf(text, sizeof text, "{\"meshes\":[");
    for (int i = 0; i < PLANES; i++) {
        char name[32];
        float q[1][4][3];
        const float x0 = -4.0f + 2.0f * (float)(i % 4), z0 = -2.0f + 2.0f * (float)(i / 4);
        flat(q[0], x0, x0 + 2.0f, z0, z0 + 2.0f, 0.0f);
        const float uv[1][4] = { { 0, 0, 1, 1 } };
        snprintf(name, sizeof name, "plate%d.obj", i);
        write_quads(tu_path(path, sizeof path, dir, name), 1, q, uv);
        at += snprintf(text + at, sizeof text - (size_t)at, "{\"file\":\"%s\"},", name);
    }
    float q[1][4][3];
    flat(q[0], -1.5f, 0.5f, -0.5f, 0.5f, 1.0f);
    write_quads(tu_path(path, sizeof path, dir, "occluder.obj"), 1, q, NULL);
    snprintf(text + at, sizeof text - (size_t)at,
             "{\"file\":\"occluder.obj\",\"lightmap\":false}],"
             "\"camera\":{\"eye\":[0,8,0.1],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":60,\"width\":64,\"height\":64},"
             "\"light\":{\"corner\":[%g,3,-0.5],\"edge_s\":[1,0,0],\"edge_t\":[0,0,1]}}", light_x);
    tu_path(json, n, dir, "pages.json");
    assert_int_equal(tu_write_file(json, text), 0);
}

static int centre_in(const float *u, double px, double py)
{
    double e[3];
    for (int k = 0; k < 3; k++) {
        const float *a = u + 2 * k, *b = u + 2 * ((k + 1) % 3);
        e[k] = ((double)b[0] - a[0]) * (py - a[1]) - ((double)b[1] - a[1]) * (px - a[0]);
    }
    return (e[0] >= 0 && e[1] >= 0 && e[2] >= 0) || (e[0] <= 0 && e[1] <= 0 && e[2] <= 0);
}

static void test_pages(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_charts_pages");
    char json[512], err[512] = "";
    write_pages_scene(dir, json, sizeof json, -1.0f);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_bake_options bo;
    bake_opts(&bo, PSIZE);
    bo.texel_density = 60.0f;   /* a plate: 120 x 120 texels, four to a 256 x 256 page */
    ms_lightmap lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    printf("pages: %d, fill %.3f %.3f (the bake's count)\n", lm.pages, lm.page_fill[0], lm.pages > 1 ? lm.page_fill[1] : 0.0);
    assert_int_equal(lm.pages, 2);
    assert_int_equal(lm.frame.width, PSIZE);
    assert_int_equal(lm.frame.height, 2 * PSIZE);
    /* per page: texel centres in how many baked triangles (rasterized here) */
    size_t on[2] = { 0, 0 };
    for (int pg = 0; pg < 2; pg++)
        for (int y = 0; y < PSIZE; y++)
            for (int x = 0; x < PSIZE; x++) {
                int in = 0;
                uint32_t which = MS_NO_TRIANGLE;
                for (size_t t = 0; t < sc.n_tris; t++)
                    if (isfinite(lm.uv[6 * t]) && lm.page[t] == (uint32_t)pg && centre_in(lm.uv + 6 * t, (x + 0.5) / PSIZE, (y + 0.5) / PSIZE)) {
                        in++;
                        which = (uint32_t)t;
                    }
                assert_true(in <= 2);   /* two only on a shared diagonal of a plate's two triangles */
                if (in == 2) {
                    uint32_t a = MS_NO_TRIANGLE;
                    for (size_t t = 0; t < sc.n_tris; t++)
                        if (isfinite(lm.uv[6 * t]) && lm.page[t] == (uint32_t)pg && centre_in(lm.uv + 6 * t, (x + 0.5) / PSIZE, (y + 0.5) / PSIZE)) {
                            if (a == MS_NO_TRIANGLE) a = (uint32_t)t;
                            else assert_int_equal(sc.tri_mesh[a], sc.tri_mesh[t]);   /* one plate */
                        }
                }
                on[pg] += in > 0;
                const uint32_t got = lm.triangle[(size_t)(pg * PSIZE + y) * PSIZE + x];
                if (in == 1) assert_int_equal(got, which);
            }
    for (int pg = 0; pg < 2; pg++) {
        const double fill = (double)on[pg] / (PSIZE * PSIZE);
        printf("page %d: %.1f%% of the texel centres on triangles (counted here), %.1f%% (the bake)\n", pg, 100 * fill,
               100 * lm.page_fill[pg]);
        assert_true(fill >= 0.70);
        assert_true(fabs(fill - lm.page_fill[pg]) < 0.01);
    }
    /* every plate triangle on one page, its texels there and only there */
    for (size_t t = 0; t < sc.n_tris; t++) {
        if (sc.tri_mesh[t] == PLANES) { assert_false(isfinite(lm.uv[6 * t])); continue; }
        assert_true(lm.page[t] < 2);
        size_t mine = 0;
        for (size_t i = 0; i < (size_t)PSIZE * 2 * PSIZE; i++)
            if (lm.triangle[i] == t) {
                assert_int_equal(i / ((size_t)PSIZE * PSIZE), lm.page[t]);
                mine++;
            }
        assert_true(mine > 1000);
    }
    /* the lightmap at random points of every plate against the oracle */
    ms_accel *acc;
    assert_int_equal(ms_accel_build(&sc, 0, &acc, err, sizeof err), MS_OK);
    double emax = 0.0;
    for (size_t i = 0; i < (size_t)PSIZE * 2 * PSIZE; i++)
        if (lm.triangle[i] != MS_NO_TRIANGLE) emax = fmax(emax, lm.frame.rgb[3 * i + 1]);
    tu_rng rng = { 12345 };
    double sum = 0.0, worst = 0.0;
    int n = 0, seen[2] = { 0, 0 };
    for (int k = 0; k < 400; k++) {
        const size_t t = (size_t)(tu_rng_next(&rng) % (2 * PLANES));
        double a = (double)(tu_rng_next(&rng) % 100000) / 100000.0, b = (double)(tu_rng_next(&rng) % 100000) / 100000.0;
        if (a + b > 1.0) { a = 1.0 - a; b = 1.0 - b; }
        const double w[3] = { 1.0 - a - b, a, b };
        float p[3];
        double uv[2];
        tu_tri_point(&sc, lm.uv, t, w, p, uv);
        const float nrm[3] = { 0, 1, 0 };
        const double want = tu_point_irradiance(acc, &sc, p, nrm, (uint32_t)t, uv, PSIZE);
        const double got = tu_lightmap_green(&lm.frame, (int)lm.page[t], uv[0], uv[1]);
        sum += fabs(got - want) / emax;
        worst = fmax(worst, fabs(got - want) / emax);
        seen[lm.page[t]]++;
        n++;
    }
    printf("lightmap at %d random points (%d on page 0, %d on page 1) against ms_visibility_points: mean %.5f, worst %.4f "
           "of the largest irradiance\n", n, seen[0], seen[1], sum / n, worst);
    assert_true(seen[0] > 50 && seen[1] > 50);
    assert_true(sum / n <= 0.002);
    assert_true(worst <= 0.05);
    ms_accel_free(acc);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
    /* the CLI names the pages' files */
    char exr[512], exr1[512], line[1024] = "", dens[16];
    tu_path(exr, sizeof exr, dir, "lm.exr");
    tu_path(exr1, sizeof exr1, dir, "lm.1.exr");
    snprintf(dens, sizeof dens, "60");
    const char *args[] = { "bake", json, "--size", "256", "--samples", "256", "--texel-density", dens, "-o", exr, "--quiet", NULL };
    assert_int_equal(tu_run_cli(args, line, sizeof line), 0);
    assert_true(tu_file_exists(exr));
    assert_true(tu_file_exists(exr1));
    float *g = malloc((size_t)PSIZE * PSIZE * sizeof *g);
    assert_int_equal(tu_read_exr_channel(exr1, "G", PSIZE, PSIZE, g), 0);
    free(g);
}

/* ---- (c), (d) the unwrap cache ---- */

static void test_uv_cache(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_charts_cache");
    char json[512], cache[512], err[512] = "";
    tu_path(cache, sizeof cache, dir, "lm.uvcache");
    remove(cache);
    write_pages_scene(dir, json, sizeof json, -1.0f);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_bake_options bo;
    bake_opts(&bo, 128);
    bo.uv_set = -1;   /* xatlas for every plate: an unwrap worth caching */
    bo.uv_cache = cache;
    ms_lightmap a, b;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &a, err, sizeof err), MS_OK);
    assert_int_equal(a.uv_cached, 0);
    assert_true(a.charts > 0);
    FILE *f = fopen(cache, "wb");
    assert_non_null(f);
    assert_int_equal(ms_bake_write_uv_cache(&a, f, cache, err, sizeof err), MS_OK);
    fclose(f);
    ms_scene_free(&sc);
    /* the light moved: the same UVs, nothing unwrapped */
    write_pages_scene(dir, json, sizeof json, 1.0f);
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_int_equal(ms_bake(&sc, NULL, &bo, &b, err, sizeof err), MS_OK);
    printf("re-bake: cached %d, unwrap %.4f s (first %.3f s), charts %zu\n", b.uv_cached, b.unwrap_s, a.unwrap_s, b.charts);
    assert_int_equal(b.uv_cached, 1);
    assert_int_equal(b.unwrapped_tris, 0);
    assert_int_equal(b.pages, a.pages);
    assert_memory_equal(a.uv, b.uv, a.n_tris * 6 * sizeof(float));
    assert_memory_equal(a.page, b.page, a.n_tris * sizeof(uint32_t));
    ms_lightmap_free(&b);
    /* other UV options (the size): the key differs, the cache is not used, one warning names it */
    ms_set_warning_handler(keep_warning, NULL);
    g_warn[0] = 0;
    bo.size = 64;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &b, err, sizeof err), MS_OK);
    assert_int_equal(b.uv_cached, 0);
    printf("warning: %s\n", g_warn);
    assert_non_null(strstr(g_warn, cache));
    assert_non_null(strstr(g_warn, "other geometry or UV options"));
    ms_lightmap_free(&b);
    bo.size = 128;
    /* the islands packed one by one: another layout, so the cache is not used either */
    g_warn[0] = 0;
    bo.uv_packing = MS_UV_PACK_ISLANDS;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &b, err, sizeof err), MS_OK);
    assert_int_equal(b.uv_cached, 0);
    assert_non_null(strstr(g_warn, "other geometry or UV options"));
    ms_lightmap_free(&b);
    bo.uv_packing = MS_UV_PACK_DEFAULT;
    ms_scene_free(&sc);
    /* other geometry (a plate moved) */
    {
        char path[512];
        float q[1][4][3];
        flat(q[0], -4.0f, -2.0f, -2.0f, 0.0f, 0.25f);
        const float uv[1][4] = { { 0, 0, 1, 1 } };
        write_quads(tu_path(path, sizeof path, dir, "plate0.obj"), 1, q, uv);
    }
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    g_warn[0] = 0;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &b, err, sizeof err), MS_OK);
    assert_int_equal(b.uv_cached, 0);
    assert_non_null(strstr(g_warn, "other geometry or UV options"));
    ms_lightmap_free(&b);
    ms_scene_free(&sc);
    /* truncated, and not a cache at all */
    write_pages_scene(dir, json, sizeof json, 1.0f);
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    f = fopen(cache, "rb");
    assert_non_null(f);
    unsigned char *buf = malloc(1 << 20);
    const size_t len = fread(buf, 1, 1 << 20, f);
    fclose(f);
    assert_true(len > 100);
    f = fopen(cache, "wb");
    fwrite(buf, 1, len - 9, f);
    fclose(f);
    g_warn[0] = 0;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &b, err, sizeof err), MS_OK);
    assert_int_equal(b.uv_cached, 0);
    printf("warning: %s\n", g_warn);
    assert_non_null(strstr(g_warn, "truncated"));
    ms_lightmap_free(&b);
    buf[len / 2] ^= 0x40;   /* one flipped bit in the payload */
    f = fopen(cache, "wb");
    fwrite(buf, 1, len, f);
    fclose(f);
    g_warn[0] = 0;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &b, err, sizeof err), MS_OK);
    assert_int_equal(b.uv_cached, 0);
    printf("warning: %s\n", g_warn);
    assert_non_null(strstr(g_warn, "corrupt"));
    ms_lightmap_free(&b);
    assert_int_equal(tu_write_file(cache, "this is not a cache\n"), 0);
    g_warn[0] = 0;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &b, err, sizeof err), MS_OK);
    assert_int_equal(b.uv_cached, 0);
    assert_non_null(strstr(g_warn, "not a microshadow UV cache"));
    ms_set_warning_handler(NULL, NULL);
    free(buf);
    ms_lightmap_free(&b);
    ms_lightmap_free(&a);
    ms_scene_free(&sc);
}

/* ---- tiny triangles: xatlas drops faces of area <= FLT_EPSILON in its units ---- */

static void test_tiny_triangles(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_charts_tiny");
    char path[512], json[512], text[1024], err[512] = "";
    /* a 2 mm plate of 16 x 16 quads (triangle areas 3.9e-9, far under FLT_EPSILON) without UVs */
    enum { Q = 16 };
    static float p[Q * Q][4][3];
    for (int i = 0; i < Q; i++)
        for (int j = 0; j < Q; j++) {
            const float h = 0.002f / Q;
            flat(p[i * Q + j], i * h, (i + 1) * h, j * h, (j + 1) * h, 0.0f);
        }
    write_quads(tu_path(path, sizeof path, dir, "tiny.obj"), Q * Q, (const float (*)[4][3])p, NULL);
    snprintf(text, sizeof text,
             "{\"meshes\":[{\"file\":\"tiny.obj\"}],"
             "\"camera\":{\"eye\":[0.001,0.01,0.001],\"target\":[0.001,0,0.001],\"up\":[0,0,-1],\"fov_y\":60,\"width\":32,\"height\":32},"
             "\"light\":{\"corner\":[0,0.01,0],\"edge_s\":[0.002,0,0],\"edge_t\":[0,0,0.002]}}");
    tu_path(json, sizeof json, dir, "tiny.json");
    assert_int_equal(tu_write_file(json, text), 0);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_int_equal(sc.n_tris, 2 * Q * Q);
    ms_bake_options bo;
    bake_opts(&bo, 128);
    bo.uv_set = -1;
    ms_lightmap lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    size_t with = 0;
    for (size_t t = 0; t < sc.n_tris; t++) with += isfinite(lm.uv[6 * t]) && isfinite(lm.uv[6 * t + 5]);
    printf("tiny plate: %zu of %zu triangles with UVs, %zu texels\n", with, sc.n_tris, lm.texels);
    assert_int_equal(with, sc.n_tris);
    assert_true(lm.texels > 1000);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_keep_and_chart),
        cmocka_unit_test(test_tiny_triangles),
        cmocka_unit_test(test_pages),
        cmocka_unit_test(test_uv_cache),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
