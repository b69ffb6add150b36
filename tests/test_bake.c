/* Lightmap baking (ms_bake, `microshadow bake`) against independent answers:
 *   - the frame: at every pixel of a frame whose hit point lies inside a baked triangle's texel, the
 *     baked irradiance equals the frame's (rgb / (albedo/pi) / emission) within what the texel's offset
 *     from the hit point and the two sample patterns allow (built-in scene, and the shared Quad);
 *   - analytic texel positions: a glTF ground quad with TEXCOORD_1 mapping (u, v) to (x, z) linearly
 *     bakes into exactly those UVs, and every texel whose centre lies inside it is evaluated at the
 *     point the linear map gives; an occluder without TEXCOORD_1 gets xatlas UVs outside the region the
 *     file's charts are scaled (one factor) and offset into; OBJ texture coordinates load as UV set 0;
 *   - xatlas charts do not overlap: no texel centre lies inside two triangles' UV images;
 *   - dilation fills the texels around charts from their neighbours and leaves the rest at -1;
 *   - the CLI writes the EXR and the PNG together and refuses bad options with exit 2. */
#include "testutil.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ALBEDO 0.8f

static void bake_options(ms_bake_options *o, int size, int uv_set, int samples)
{
    memset(o, 0, sizeof *o);
    o->size = size;
    o->uv_set = uv_set;
    o->points.samples = samples;
    o->points.isa = tu_isa_cap();
}

/* Barycentric weights of p on triangle t (world), by areas of the sub-triangles projected on its normal. */
static void bary(const float *t, const float p[3], double w[3])
{
    double e1[3], e2[3], n[3], q[3][3];
    for (int d = 0; d < 3; d++) { e1[d] = t[3 + d] - t[d]; e2[d] = t[6 + d] - t[d]; }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 3; d++) q[k][d] = t[3 * k + d] - p[d];
    for (int k = 0; k < 3; k++) {
        const double *a = q[(k + 1) % 3], *b = q[(k + 2) % 3];
        const double c[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
        w[k] = (c[0] * n[0] + c[1] * n[1] + c[2] * n[2]) / nn;
    }
}

/* 1 if the texel centre (x+0.5, y+0.5) lies strictly inside triangle t's UV image (by a margin). */
static int centre_inside(const float *uv, int size, int x, int y, double margin)
{
    const double p[2] = { x + 0.5, y + 0.5 };
    double a[3][2];
    for (int k = 0; k < 3; k++) { a[k][0] = uv[2 * k] * (double)size; a[k][1] = uv[2 * k + 1] * (double)size; }
    const double area = (a[1][0] - a[0][0]) * (a[2][1] - a[0][1]) - (a[1][1] - a[0][1]) * (a[2][0] - a[0][0]);
    if (area == 0.0 || !isfinite(area)) return 0;
    for (int k = 0; k < 3; k++) {
        const double *s0 = a[k], *s1 = a[(k + 1) % 3];
        const double ex = s1[0] - s0[0], ey = s1[1] - s0[1];
        const double e = (ex * (p[1] - s0[1]) - ey * (p[0] - s0[0])) * (area > 0 ? 1.0 : -1.0);
        if (e <= margin * hypot(ex, ey)) return 0;
    }
    return 1;
}

/* The frame's hit points (BVH primary), and for each pixel whose triangle faces the camera by its
 * winding, the texel its UV falls in; compares irradiance there. */
static void compare_with_frame(const ms_scene *sc, const char *name, int W, int H, int size)
{
    char err[512] = "";
    ms_bake_options bo;
    bake_options(&bo, size, 1, 1024);
    ms_lightmap lm;
    assert_int_equal(ms_bake(sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    ms_render_options ro;
    tu_render_options_default(&ro);
    ro.width = W;
    ro.height = H;
    ro.samples = 1024;
    ms_frame fr;
    assert_int_equal(ms_render(sc, &ro, &fr, err, sizeof err), 0);

    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc->tri, sc->n_tris, 0), 0);
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, sc, &bvh, W, H, 16);
    const ms_primary_method *pb = ms_find_primary_method("bvh");
    void *ps = NULL;
    assert_int_equal(pb->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit *h = malloc(sizeof *h * W * H);
    assert_non_null(h);
    pb->trace(ps, &ctx, 0, 0, W, H, h);
    pb->destroy(ps);

    const ms_light *L = &sc->light;
    double emax = 0.0;
    for (int i = 0; i < W * H; i++)
        if (h[i].prim != UINT32_MAX) emax = fmax(emax, ms_light_irradiance(L, h[i].p, h[i].n) * L->emission.y);
    long compared = 0, beyond2 = 0, beyond10 = 0;
    double sum = 0.0, worst = 0.0;
    for (int i = 0; i < W * H; i++) {
        if (h[i].prim == UINT32_MAX) continue;
        const uint32_t t = bvh.tri_source[h[i].prim];
        const float *tri = sc->tri + 9 * t;
        double e1[3], e2[3], wn[3];
        for (int d = 0; d < 3; d++) { e1[d] = tri[3 + d] - tri[d]; e2[d] = tri[6 + d] - tri[d]; }
        wn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        wn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        wn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        if (wn[0] * h[i].n[0] + wn[1] * h[i].n[1] + wn[2] * h[i].n[2] <= 0.0) continue;   /* seen from behind */
        double w[3];
        bary(tri, h[i].p, w);
        const float *uv = lm.uv + 6 * t;
        const double u = w[0] * uv[0] + w[1] * uv[2] + w[2] * uv[4], v = w[0] * uv[1] + w[1] * uv[3] + w[2] * uv[5];
        const int x = (int)floor(u * size), y = (int)floor(v * size);
        if (x < 0 || y < 0 || x >= size || y >= size) continue;
        const size_t ti = (size_t)y * size + x;
        if (lm.triangle[ti] != t || !centre_inside(uv, size, x, y, 0.0)) continue;
        const double e_frame = fr.rgb[3 * i + 1] / (ALBEDO / M_PI);
        const double e_bake = lm.frame.rgb[3 * ti + 1];
        const double d = fabs(e_frame - e_bake) / emax;
        compared++;
        sum += d;
        worst = fmax(worst, d);
        beyond2 += d > 0.02;
        beyond10 += d > 0.10;
    }
    printf("%s: %ldx%d frame vs %dx%d lightmap (%zu texels, %zu unwrapped triangles): %ld pixels compared, |dE|/Emax "
           "mean %.5f, worst %.4f, %ld beyond 2%%, %ld beyond 10%%\n",
           name, (long)W, H, size, size, lm.texels, lm.unwrapped_tris, compared, compared ? sum / compared : 0.0, worst,
           beyond2, beyond10);
    assert_true(compared > W * H / 4);
    assert_true(sum / compared < 0.005);
    assert_true(beyond2 * 50 <= compared);
    assert_true(beyond10 * 500 <= compared);
    free(h);
    ms_bvh_free(&bvh);
    ms_frame_free(&fr);
    ms_lightmap_free(&lm);
}

static void test_matches_frame_default(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    compare_with_frame(&sc, "built-in scene", 96, 72, 256);
    ms_scene_free(&sc);
}

static void test_matches_frame_quad(void **st)
{
    (void)st;
    if (!tu_have_shared_scenes()) skip();
    char path[1024];
    ms_scene sc;
    char err[512];
    assert_int_equal(ms_scene_load(tu_shared_scene(path, sizeof path, "quad/quad.json"), &sc, err, sizeof err), 0);
    compare_with_frame(&sc, "quad", 96, 96, 256);
    ms_scene_free(&sc);
}

/* ---- a glTF with TEXCOORD_1 on the ground and none on the occluder ---- */


/* Ground: x, z in [-4, 4] at y = 0, two triangles facing up, TEXCOORD_1 (u, v) = ((x+4)/8, (z+4)/8).
 * Occluder: a 1x1 square at y = 1.5, no TEXCOORD_1 (only TEXCOORD_0, which must not be used). */
static void write_gltf_scene(const char *dir, char *json_path, size_t n)
{
    const float gpos[18] = { -4, 0, -4, -4, 0, 4, 4, 0, 4, -4, 0, -4, 4, 0, 4, 4, 0, -4 };
    float guv[12];
    for (int k = 0; k < 6; k++) { guv[2 * k] = (gpos[3 * k] + 4) / 8; guv[2 * k + 1] = (gpos[3 * k + 2] + 4) / 8; }
    const float opos[18] = { -0.5f, 1.5f, -0.5f, -0.5f, 1.5f, 0.5f, 0.5f, 1.5f, 0.5f, -0.5f, 1.5f, -0.5f, 0.5f, 1.5f, 0.5f, 0.5f, 1.5f, -0.5f };
    /* the occluder's UV0 maps both triangles onto one (a tiling layout): not a lightmap layout, so xatlas
     * charts it (a valid UV0 would be kept: test_bake_charts) */
    const float ouv0[12] = { 0, 0, 0, 1, 1, 1, 0, 0, 0, 1, 1, 1 };
    unsigned char buf[72 + 48 + 72 + 48];
    memcpy(buf, gpos, 72);
    memcpy(buf + 72, guv, 48);
    memcpy(buf + 120, opos, 72);
    memcpy(buf + 192, ouv0, 48);
    char enc[400];
    tu_base64(buf, sizeof buf, enc);
    char text[4096];
    snprintf(text, sizeof text,
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
        "\"nodes\":[{\"mesh\":0},{\"mesh\":1}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_1\":1}}]},"
        "{\"primitives\":[{\"attributes\":{\"POSITION\":2,\"TEXCOORD_0\":3}}]}],"
        "\"buffers\":[{\"byteLength\":240,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":72},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":48},"
        "{\"buffer\":0,\"byteOffset\":120,\"byteLength\":72},{\"buffer\":0,\"byteOffset\":192,\"byteLength\":48}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\",\"min\":[-4,0,-4],\"max\":[4,0,4]},"
        "{\"bufferView\":1,\"componentType\":5126,\"count\":6,\"type\":\"VEC2\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\",\"min\":[-0.5,1.5,-0.5],\"max\":[0.5,1.5,0.5]},"
        "{\"bufferView\":3,\"componentType\":5126,\"count\":6,\"type\":\"VEC2\"}]}", enc);
    char p[1024];
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "two.gltf"), text), 0);
    assert_int_equal(tu_write_file(tu_path(json_path, n, dir, "two.json"),
        "{\"meshes\":[{\"file\":\"two.gltf\"}],"
        "\"camera\":{\"eye\":[0,8,8],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":64,\"height\":64},"
        "\"light\":{\"corner\":[-1,5,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2],\"emission\":[1,1,1]}}"), 0);
}

static void test_gltf_uvs(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_gltf");
    char json[1024], err[512] = "";
    write_gltf_scene(dir, json, sizeof json);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_int_equal(sc.n_tris, 4);
    assert_int_equal(sc.n_meshes, 1);
    assert_non_null(sc.tri_uv[0]);
    assert_non_null(sc.tri_uv[1]);
    assert_null(sc.tri_uv[2]);
    /* the ground has set 1, the occluder not; the occluder has set 0 */
    for (int t = 0; t < 4; t++) {
        const int ground = sc.tri[9 * t + 1] == 0.0f;
        assert_int_equal(isnan(sc.tri_uv[1][6 * t]), !ground);
        assert_int_equal(isnan(sc.tri_uv[0][6 * t]), ground);
    }
    const int size = 64;
    ms_bake_options bo;
    bake_options(&bo, size, 1, 256);
    ms_lightmap lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    assert_int_equal(lm.unwrapped_tris, 2);
    /* The ground keeps the file's charts, scaled by one k and offset (its region); the occluder's xatlas
     * charts lie outside that region. */
    double lo[2] = { 1, 1 }, hi[2] = { 0, 0 };
    for (int t = 0; t < 4; t++)
        if (sc.tri[9 * t + 1] == 0.0f)
            for (int k = 0; k < 6; k++) { lo[k & 1] = fmin(lo[k & 1], lm.uv[6 * t + k]); hi[k & 1] = fmax(hi[k & 1], lm.uv[6 * t + k]); }
    const double kscale = hi[0] - lo[0];
    assert_true(kscale > 0.3 && fabs((hi[1] - lo[1]) - kscale) < 1e-6);   /* the file's charts span [0,1]^2: one scale */
    for (int t = 0; t < 4; t++) {
        const int ground = sc.tri[9 * t + 1] == 0.0f;
        for (int k = 0; k < 3; k++) {
            const float *u = lm.uv + 6 * t + 2 * k;
            if (ground) {
                assert_true(fabs(u[0] - (lo[0] + kscale * sc.tri_uv[1][6 * t + 2 * k])) < 1e-6);
                assert_true(fabs(u[1] - (lo[1] + kscale * sc.tri_uv[1][6 * t + 2 * k + 1])) < 1e-6);
            } else {
                assert_true(u[0] >= 0.0f && u[0] <= 1.0f && u[1] >= 0.0f && u[1] <= 1.0f);
                assert_true(u[0] <= lo[0] || u[0] >= hi[0] || u[1] <= lo[1] || u[1] >= hi[1]);
            }
        }
    }
    long inside = 0;
    /* Texels inside the ground: evaluated where the linear map puts their centre. */
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            const size_t i = (size_t)y * size + x;
            const uint32_t t = lm.triangle[i];
            if (t == MS_NO_TRIANGLE || sc.tri[9 * t + 1] != 0.0f || !centre_inside(lm.uv + 6 * t, size, x, y, 1e-3)) continue;
            const double u = ((x + 0.5) / size - lo[0]) / kscale, v = ((y + 0.5) / size - lo[1]) / kscale;
            assert_true(fabs(lm.position[3 * i] - (u * 8 - 4)) < 1e-4);
            assert_true(fabs(lm.position[3 * i + 1]) < 1e-6);
            assert_true(fabs(lm.position[3 * i + 2] - (v * 8 - 4)) < 1e-4);
            assert_true(lm.normal[3 * i + 1] == 1.0f);
            assert_true(lm.frame.vis[i] >= 0.0f && lm.frame.front[i] > 0);
            inside++;
        }
    printf("glTF: %ld ground texels at their analytic positions (region scale %.3f)\n", inside, kscale);
    assert_true(inside > (long)(kscale * kscale * size * size) - 4 * size);
    /* The occluder (xatlas) got texels too, and the texel under the occluder's centre is dark. */
    long occl = 0;
    for (size_t i = 0; i < (size_t)size * size; i++) occl += lm.triangle[i] != MS_NO_TRIANGLE && sc.tri[9 * lm.triangle[i] + 1] != 0.0f;
    assert_true(occl > 10);
    const size_t below = (size_t)((lo[1] + 0.5 * kscale) * size) * size + (size_t)((lo[0] + 0.5 * kscale) * size);   /* (0, 0, 0) */
    assert_true(lm.frame.vis[below] == 0.0f);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

static void test_obj_uv_set0(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_obj");
    char p[1024], json[1024], err[512];
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "g.obj"),
        "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nvt 0.25 0.5\nvt 0.75 0.5\nvt 0.75 1\nf 1/1 3/3 2/2\n"), 0);
    assert_int_equal(tu_write_file(tu_path(json, sizeof json, dir, "g.json"),
        "{\"meshes\":[{\"file\":\"g.obj\"}],"
        "\"camera\":{\"eye\":[0,8,8],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":64,\"height\":64},"
        "\"light\":{\"corner\":[-1,5,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2],\"emission\":[1,1,1]}}"), 0);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_non_null(sc.tri_uv[0]);
    assert_null(sc.tri_uv[1]);
    /* vertex (1,0,1) carries vt 3 = (0.75, 1) */
    for (int k = 0; k < 3; k++)
        if (sc.tri[9 * 0 + 3 * k] == 1.0f && sc.tri[3 * k + 2] == 1.0f) {
            assert_true(sc.tri_uv[0][2 * k] == 0.75f);
            assert_true(sc.tri_uv[0][2 * k + 1] == 1.0f);
        }
    ms_bake_options bo;
    bake_options(&bo, 32, 0, 256);
    ms_lightmap lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    assert_int_equal(lm.unwrapped_tris, 0);
    assert_memory_equal(lm.uv, sc.tri_uv[0], 6 * sizeof(float));
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

/* xatlas charts of the built-in scene: no texel centre inside two UV triangles; dilation. */
static void test_xatlas_and_dilation(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    char err[512];
    const int size = 128;
    ms_bake_options bo;
    bake_options(&bo, size, -1, 256);
    bo.dilate = 2;
    ms_lightmap lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    assert_int_equal(lm.unwrapped_tris, sc.n_tris);
    uint8_t *count = calloc((size_t)size * size, 1);
    assert_non_null(count);
    long dropped = 0;
    double max_dropped = 0.0;
    for (size_t t = 0; t < sc.n_tris; t++) {
        const float *uv = lm.uv + 6 * t;
        if (isnan(uv[0])) {
            /* xatlas leaves out zero-area triangles only (the sphere's poles have 96) */
            const float *w = sc.tri + 9 * t;
            double e1[3], e2[3];
            for (int d = 0; d < 3; d++) { e1[d] = w[3 + d] - w[d]; e2[d] = w[6 + d] - w[d]; }
            const double c[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
            const double area = 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
            max_dropped = fmax(max_dropped, area);
            dropped += area > 1e-6;   /* slivers at the poles are 1e-8 or so after sinf/cosf */
            continue;
        }
        for (int k = 0; k < 6; k++) assert_true(uv[k] >= 0.0f && uv[k] <= 1.0f);
        for (int y = 0; y < size; y++)
            for (int x = 0; x < size; x++)
                if (centre_inside(uv, size, x, y, 1e-6)) count[(size_t)y * size + x]++;
    }
    long overlap = 0, ring = 0, untouched = 0;
    for (size_t i = 0; i < (size_t)size * size; i++) overlap += count[i] > 1;
    /* Dilation: a texel off the triangles is filled iff a triangle texel lies within 2 (Chebyshev). */
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            const size_t i = (size_t)y * size + x;
            if (lm.triangle[i] != MS_NO_TRIANGLE) continue;
            int near = 0;
            for (int dy = -2; dy <= 2 && !near; dy++)
                for (int dx = -2; dx <= 2 && !near; dx++) {
                    const int xx = x + dx, yy = y + dy;
                    near = xx >= 0 && yy >= 0 && xx < size && yy < size && lm.triangle[(size_t)yy * size + xx] != MS_NO_TRIANGLE;
                }
            assert_int_equal(lm.frame.vis[i] >= 0.0f, near);
            assert_int_equal(lm.frame.front[i], 0);
            ring += near;
            untouched += !near;
        }
    printf("xatlas: %zu triangles (%ld with area > 1e-6 left out; largest left out %.3g), %zu texels, %ld overlapping "
           "centres; dilation filled %ld, left %ld\n", sc.n_tris, dropped, max_dropped, lm.texels, overlap, ring, untouched);
    assert_int_equal(overlap, 0);
    assert_true(ring > 0 && untouched > 0);
    assert_int_equal(dropped, 0);
    free(count);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

static void test_bad_options(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    char err[512];
    ms_lightmap lm;
    ms_bake_options bo;
    bake_options(&bo, MS_MAX_IMAGE_SIZE + 1, 1, 256);
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_ERR_INVALID);
    bake_options(&bo, 16, MS_MAX_UV_SETS, 256);
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_ERR_INVALID);
    bake_options(&bo, 16, 1, 100);
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_ERR_INVALID);
    bake_options(&bo, 16, 1, 256);
    bo.uv_packing = (ms_uv_packing)3;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "uv_packing 3"));
    assert_null(lm.frame.vis);
    ms_scene_free(&sc);
}

static void test_cli(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_cli");
    char exr[1024], png[1024], e[512];
    tu_path(exr, sizeof exr, dir, "lm.exr");
    tu_path(png, sizeof png, dir, "lm.png");
    const char *ok[] = { "bake", "--size", "64", "--samples", "256", "--quiet", "-o", exr, "--png", png, NULL };
    assert_int_equal(tu_run_cli(ok, e, sizeof e), 0);
    assert_true(tu_file_exists(exr) && tu_file_exists(png));
    const char *bad_uv[] = { "bake", "--uv", "7", "-o", exr, NULL };
    assert_int_equal(tu_run_cli(bad_uv, e, sizeof e), 2);
    assert_non_null(strstr(e, "--uv"));
    const char *bad_ext[] = { "bake", "-o", png, NULL };
    assert_int_equal(tu_run_cli(bad_ext, e, sizeof e), 2);
    const char *bad_scene[] = { "bake", "/nonexistent/scene.json", "-o", exr, NULL };
    assert_int_equal(tu_run_cli(bad_scene, e, sizeof e), 2);
    assert_non_null(strstr(e, "/nonexistent/scene.json"));
    /* all or nothing: a PNG that cannot be written leaves no EXR behind */
    char exr2[1024];
    tu_path(exr2, sizeof exr2, dir, "second.exr");
    const char *bad_png[] = { "bake", "--size", "16", "--samples", "256", "--quiet", "-o", exr2, "--png", "/nonexistent/dir/x.png", NULL };
    assert_int_equal(tu_run_cli(bad_png, e, sizeof e), 2);
    assert_false(tu_file_exists(exr2));
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_frame_default),
        cmocka_unit_test(test_matches_frame_quad),
        cmocka_unit_test(test_gltf_uvs),
        cmocka_unit_test(test_obj_uv_set0),
        cmocka_unit_test(test_xatlas_and_dilation),
        cmocka_unit_test(test_bad_options),
        cmocka_unit_test(test_cli),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
