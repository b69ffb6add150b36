/* Lightmap UVs that respect the asset (src/render/bake_uvs.c), on a Cornell-box-like glTF made here whose six
 * objects (five walls, a short box: one glTF node and mesh each) all bring TEXCOORD_1 spanning 0-1, the
 * Unity/Bevy convention; beside it a floating cube without UVs (xatlas) and a tall block with
 * "lightmap": false. Against independent answers:
 *   - with each layout moved whole (MS_UV_PACK_REGIONS), the overlap is said (a warning), and every object gets its own region: no texel centre lies in two
 *     objects' baked UV images (rasterized here), and each object's baked UVs are its file UVs under one
 *     scale and one offset (its charts keep their shape);
 *   - the tall block is not baked (no UVs, no texels) but still casts: the floor behind it is in shadow;
 *   - the floor under the light is lit, and equals a frame of it (an orthographic camera looking down): per
 *     pixel, the frame's radiance / (albedo / pi) against the irradiance of the texel the hit point lies in;
 *   - "lightmap": {"scale": 2} on the cube gives its triangles 4 times the texels per world area (within
 *     the rounding of charts to texels), and a bad "lightmap" value is an error naming it. */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIZE 256


/* The objects as they are written: positions (non-indexed triangles) and TEXCOORD_1. */
#define MAX_V 64
typedef struct object { float pos[MAX_V * 3], uv[MAX_V * 2]; int nv; } object;

/* Quad p0 p1 p2 p3 (facing (p1-p0) x (p2-p0)) into o with UVs the cell [u0,u1] x [v0,v1]. */
static void quad(object *o, const float p[4][3], float u0, float v0, float u1, float v1)
{
    const float uv[4][2] = { { u0, v0 }, { u1, v0 }, { u1, v1 }, { u0, v1 } };
    const int c[6] = { 0, 1, 2, 0, 2, 3 };
    for (int k = 0; k < 6; k++) {
        memcpy(o->pos + 3 * o->nv, p[c[k]], 3 * sizeof(float));
        memcpy(o->uv + 2 * o->nv, uv[c[k]], 2 * sizeof(float));
        o->nv++;
    }
}

static object g_obj[6];

static void make_objects(void)
{
    memset(g_obj, 0, sizeof g_obj);
    const float floor_[4][3] = { { -1, 0, -1 }, { -1, 0, 1 }, { 1, 0, 1 }, { 1, 0, -1 } };
    const float ceil_[4][3] = { { -1, 2, -1 }, { 1, 2, -1 }, { 1, 2, 1 }, { -1, 2, 1 } };
    const float back[4][3] = { { -1, 0, -1 }, { 1, 0, -1 }, { 1, 2, -1 }, { -1, 2, -1 } };
    const float left[4][3] = { { -1, 0, -1 }, { -1, 2, -1 }, { -1, 2, 1 }, { -1, 0, 1 } };
    const float right[4][3] = { { 1, 0, -1 }, { 1, 0, 1 }, { 1, 2, 1 }, { 1, 2, -1 } };
    quad(&g_obj[0], floor_, 0, 0, 1, 1);
    quad(&g_obj[1], ceil_, 0, 0, 1, 1);
    quad(&g_obj[2], back, 0, 0, 1, 1);
    quad(&g_obj[3], left, 0, 0, 1, 1);
    quad(&g_obj[4], right, 0, 0, 1, 1);
    /* the short box: x 0.3..0.8, y 0..0.5, z 0.2..0.7; top and four sides, each a cell of a 3 x 2 grid */
    const float x0 = 0.3f, x1 = 0.8f, y1 = 0.5f, z0 = 0.2f, z1 = 0.7f;
    const float top[4][3] = { { x0, y1, z0 }, { x0, y1, z1 }, { x1, y1, z1 }, { x1, y1, z0 } };
    const float nz[4][3] = { { x0, 0, z0 }, { x0, y1, z0 }, { x1, y1, z0 }, { x1, 0, z0 } };
    const float pz[4][3] = { { x0, 0, z1 }, { x1, 0, z1 }, { x1, y1, z1 }, { x0, y1, z1 } };
    const float nx[4][3] = { { x0, 0, z0 }, { x0, 0, z1 }, { x0, y1, z1 }, { x0, y1, z0 } };
    const float px[4][3] = { { x1, 0, z0 }, { x1, y1, z0 }, { x1, y1, z1 }, { x1, 0, z1 } };
    const float (*faces[5])[3] = { top, nz, pz, nx, px };
    for (int f = 0; f < 5; f++) {
        const float cu = (float)(f % 3) / 3.0f, cv = (float)(f / 3) / 2.0f;
        quad(&g_obj[5], faces[f], cu + 0.02f, cv + 0.02f, cu + 0.31f, cv + 0.48f);
    }
}

/* cornell.gltf, cube.obj (no UVs), block.obj; scene.json with the cube's "lightmap" entry as given. */
static void write_scene(const char *dir, const char *cube_lightmap, char *json, size_t n)
{
    make_objects();
    size_t bytes = 0;
    for (int o = 0; o < 6; o++) bytes += (size_t)g_obj[o].nv * 20;
    unsigned char *buf = malloc(bytes);
    char *enc = malloc(bytes * 2 + 8), *text = malloc(bytes * 2 + 16384);
    assert_non_null(buf);
    assert_non_null(enc);
    assert_non_null(text);
    size_t off = 0;
    char views[4096] = "", accs[8192] = "", meshes[2048] = "", nodes[512] = "", roots[128] = "";
    for (int o = 0; o < 6; o++) {
        const object *ob = &g_obj[o];
        float lo[3] = { 1e9f, 1e9f, 1e9f }, hi[3] = { -1e9f, -1e9f, -1e9f };
        for (int v = 0; v < ob->nv; v++)
            for (int d = 0; d < 3; d++) { lo[d] = fminf(lo[d], ob->pos[3 * v + d]); hi[d] = fmaxf(hi[d], ob->pos[3 * v + d]); }
        memcpy(buf + off, ob->pos, (size_t)ob->nv * 12);
        memcpy(buf + off + (size_t)ob->nv * 12, ob->uv, (size_t)ob->nv * 8);
        snprintf(views + strlen(views), sizeof views - strlen(views), "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%d},"
                 "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%d}", o ? "," : "", off, ob->nv * 12, off + (size_t)ob->nv * 12, ob->nv * 8);
        snprintf(accs + strlen(accs), sizeof accs - strlen(accs), "%s{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\","
                 "\"min\":[%g,%g,%g],\"max\":[%g,%g,%g]},{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"VEC2\"}",
                 o ? "," : "", 2 * o, ob->nv, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], 2 * o + 1, ob->nv);
        /* TEXCOORD_0 too (the same values): glTF numbers texture coordinate sets densely */
        snprintf(meshes + strlen(meshes), sizeof meshes - strlen(meshes),
                 "%s{\"primitives\":[{\"attributes\":{\"POSITION\":%d,\"TEXCOORD_0\":%d,\"TEXCOORD_1\":%d}}]}", o ? "," : "", 2 * o, 2 * o + 1, 2 * o + 1);
        snprintf(nodes + strlen(nodes), sizeof nodes - strlen(nodes), "%s{\"mesh\":%d}", o ? "," : "", o);
        snprintf(roots + strlen(roots), sizeof roots - strlen(roots), "%s%d", o ? "," : "", o);
        off += (size_t)ob->nv * 20;
    }
    tu_base64(buf, bytes, enc);
    sprintf(text, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[%s]}],\"nodes\":[%s],\"meshes\":[%s],"
            "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,%s\"}],\"bufferViews\":[%s],\"accessors\":[%s]}",
            roots, nodes, meshes, bytes, enc, views, accs);
    char p[1024];
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "cornell.gltf"), text), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "cube.obj"),
        "v -0.9 0.9 0.3\nv -0.5 0.9 0.3\nv -0.5 0.9 0.7\nv -0.9 0.9 0.7\nv -0.9 1.3 0.3\nv -0.5 1.3 0.3\nv -0.5 1.3 0.7\nv -0.9 1.3 0.7\n"
        "f 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n"), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "block.obj"),
        "v -0.8 0 -0.6\nv -0.4 0 -0.6\nv -0.4 0 -0.2\nv -0.8 0 -0.2\nv -0.8 1.2 -0.6\nv -0.4 1.2 -0.6\nv -0.4 1.2 -0.2\nv -0.8 1.2 -0.2\n"
        "f 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n"), 0);
    snprintf(text, bytes * 2 + 16384,
        "{\"meshes\":[{\"file\":\"cornell.gltf\"},{\"file\":\"cube.obj\"%s},{\"file\":\"block.obj\",\"lightmap\":false}],"
        "\"camera\":{\"type\":\"orthographic\",\"eye\":[0,1.9,0],\"target\":[0,0,0],\"up\":[0,0,-1],\"ortho_height\":0.6,"
        "\"width\":32,\"height\":32},"
        "\"light\":{\"corner\":[-0.25,1.95,-0.25],\"edge_s\":[0.5,0,0],\"edge_t\":[0,0,0.5],\"emission\":[1,1,1]}}",
        cube_lightmap);
    assert_int_equal(tu_write_file(tu_path(json, n, dir, "scene.json"), text), 0);
    free(buf);
    free(enc);
    free(text);
}

static char g_warning[1024];
static void keep_warning(void *user, const char *msg)
{
    (void)user;
    if (strstr(msg, "overlap")) snprintf(g_warning, sizeof g_warning, "%s", msg);
}

static void bake(const ms_scene *sc, ms_lightmap *lm)
{
    ms_bake_options bo;
    tu_bake_options(&bo, SIZE, 1, 256);
    bo.uv_packing = MS_UV_PACK_REGIONS;   /* what is checked: each layout moved whole under one scale-offset */
    char err[512] = "";
    assert_int_equal(ms_bake(sc, NULL, &bo, lm, err, sizeof err), MS_OK);
}

/* 1 if the texel centre (x+.5, y+.5) is strictly inside triangle uv (6 floats, [0,1]) at SIZE. */
static int covers(const float *uv, int x, int y)
{
    double a[3][2];
    for (int k = 0; k < 3; k++) { a[k][0] = uv[2 * k] * SIZE; a[k][1] = uv[2 * k + 1] * SIZE; }
    const double ar = (a[1][0] - a[0][0]) * (a[2][1] - a[0][1]) - (a[1][1] - a[0][1]) * (a[2][0] - a[0][0]);
    if (!(fabs(ar) > 0)) return 0;
    for (int k = 0; k < 3; k++) {
        const double *s = a[k], *e = a[(k + 1) % 3];
        if ((ar > 0 ? 1 : -1) * ((e[0] - s[0]) * (y + 0.5 - s[1]) - (e[1] - s[1]) * (x + 0.5 - s[0])) <= 0) return 0;
    }
    return 1;
}

static double tri_area(const float *t)
{
    const double e1[3] = { t[3] - t[0], t[4] - t[1], t[5] - t[2] }, e2[3] = { t[6] - t[0], t[7] - t[1], t[8] - t[2] };
    const double c[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
    return 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

static void test_cornell(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_objects");
    char json[1024], err[512] = "";
    write_scene(dir, "", json, sizeof json);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_int_equal(sc.n_tris, 10 + 10 + 12 + 12);   /* 5 walls, the short box, the cube, the block */
    assert_int_equal(sc.n_objects, 8);                 /* 6 glTF nodes, 2 OBJ files */
    g_warning[0] = 0;
    ms_set_warning_handler(keep_warning, NULL);
    ms_lightmap lm;
    bake(&sc, &lm);
    ms_set_warning_handler(NULL, NULL);
    printf("warning: %s\n", g_warning);
    assert_non_null(strstr(g_warning, "6 objects"));   /* said, not silent */

    /* per object: its baked UVs are its file UVs under one scale and offset */
    for (uint32_t o = 0; o < 6; o++) {
        double k = NAN, off[2] = { NAN, NAN };
        for (size_t t = 0; t < sc.n_tris; t++) {
            if (sc.tri_object[t] != o) continue;
            const float *f = sc.tri_uv[1] + 6 * t, *b = lm.uv + 6 * t;
            for (int c = 0; c < 3; c++) {
                if (isnan(k)) {   /* from the first two corners that differ in u */
                    for (int c2 = 0; c2 < 3 && isnan(k); c2++)
                        if (f[2 * c2] != f[2 * c]) k = (b[2 * c2] - b[2 * c]) / (double)(f[2 * c2] - f[2 * c]);
                    off[0] = b[2 * c] - k * f[2 * c];
                    off[1] = b[2 * c + 1] - k * f[2 * c + 1];
                }
                assert_true(fabs(b[2 * c] - (off[0] + k * f[2 * c])) < 1e-5);
                assert_true(fabs(b[2 * c + 1] - (off[1] + k * f[2 * c + 1])) < 1e-5);   /* the same k: the shape kept */
            }
        }
        assert_true(k > 0.01 && k < 1.0);
    }
    /* no texel centre in two objects' UV images; the block has no UVs and no texels */
    uint32_t *owner = malloc((size_t)SIZE * SIZE * sizeof *owner);
    assert_non_null(owner);
    memset(owner, 0xff, (size_t)SIZE * SIZE * sizeof *owner);
    long twice = 0;
    for (size_t t = 0; t < sc.n_tris; t++) {
        const int block = sc.tri_mesh[t] == 2;
        assert_int_equal(isnan(lm.uv[6 * t]), block);
        if (block) continue;
        for (int y = 0; y < SIZE; y++)
            for (int x = 0; x < SIZE; x++)
                if (covers(lm.uv + 6 * t, x, y)) {
                    uint32_t *ow = &owner[(size_t)y * SIZE + x];
                    if (*ow != UINT32_MAX && *ow != sc.tri_object[t]) twice++;
                    *ow = sc.tri_object[t];
                }
    }
    assert_int_equal(twice, 0);
    free(owner);
    long lit[8] = { 0 };
    for (size_t i = 0; i < (size_t)SIZE * SIZE; i++) {
        if (lm.triangle[i] == MS_NO_TRIANGLE) continue;
        assert_int_not_equal(sc.tri_mesh[lm.triangle[i]], 2);
        lit[sc.tri_object[lm.triangle[i]]] += lm.frame.rgb[3 * i + 1] > 0.0f;
    }
    printf("lit texels per object: floor %ld, ceiling %ld, back %ld, left %ld, right %ld, short box %ld, cube %ld\n", lit[0],
           lit[1], lit[2], lit[3], lit[4], lit[5], lit[6]);
    assert_true(lit[0] > 1000 && lit[2] > 100 && lit[3] > 100 && lit[4] > 100 && lit[5] > 10);
    assert_int_equal(lit[1], 0);   /* the light faces down: the ceiling above it gets nothing */

    /* the block casts: the floor texel nearest (-0.9, 0, -0.7), whose segments to the light pass through it */
    double best = 1e9;
    size_t behind = 0;
    for (size_t i = 0; i < (size_t)SIZE * SIZE; i++) {
        if (lm.triangle[i] == MS_NO_TRIANGLE || sc.tri_object[lm.triangle[i]] != 0) continue;
        const double d = hypot(lm.position[3 * i] + 0.9, lm.position[3 * i + 2] + 0.7);
        if (d < best) { best = d; behind = i; }
    }
    printf("floor behind the block: V %.3f\n", (double)lm.frame.vis[behind]);
    assert_true(best < 0.02 && lm.frame.vis[behind] < 0.5f);

    /* the floor under the light against a frame looking down at it */
    ms_render_options ro;
    tu_render_options_default(&ro);
    ro.samples = 256;
    ms_frame fr;
    assert_int_equal(ms_render(&sc, &ro, &fr, err, sizeof err), 0);
    const int W = fr.width, H = fr.height;
    double emax = 0.0, sum = 0.0, worst = 0.0;
    long n = 0;
    for (size_t i = 0; i < (size_t)SIZE * SIZE; i++)
        if (lm.triangle[i] != MS_NO_TRIANGLE && sc.tri_object[lm.triangle[i]] == 0) emax = fmax(emax, lm.frame.rgb[3 * i + 1]);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            /* the orthographic ray of pixel (x, y) meets the floor at (a, 0, -c) (right = +x, up = -z) */
            const double a = (2.0 * (x + 0.5) / W - 1.0) * 0.3, c = (1.0 - 2.0 * (y + 0.5) / H) * 0.3;
            const double px = a, pz = -c;
            /* the floor triangle containing it and its baked UV there */
            for (size_t t = 0; t < sc.n_tris; t++) {
                if (sc.tri_object[t] != 0) continue;
                const float *p = sc.tri + 9 * t, *u = lm.uv + 6 * t;
                const double d = (p[3] - p[0]) * (p[8] - p[2]) - (p[5] - p[2]) * (p[6] - p[0]);
                const double w1 = ((px - p[0]) * (p[8] - p[2]) - (pz - p[2]) * (p[6] - p[0])) / d;
                const double w2 = ((p[3] - p[0]) * (pz - p[2]) - (p[5] - p[2]) * (px - p[0])) / d;
                if (w1 < 0 || w2 < 0 || w1 + w2 > 1) continue;
                const double uu = (1 - w1 - w2) * u[0] + w1 * u[2] + w2 * u[4], vv = (1 - w1 - w2) * u[1] + w1 * u[3] + w2 * u[5];
                const size_t ti = (size_t)floor(vv * SIZE) * SIZE + (size_t)floor(uu * SIZE);
                assert_int_equal(sc.tri_object[lm.triangle[ti]], 0);
                const double e_frame = fr.rgb[3 * ((size_t)y * W + x) + 1] / (0.8 / M_PI), e_bake = lm.frame.rgb[3 * ti + 1];
                assert_true(e_bake > 0.0);   /* lit, not black */
                sum += fabs(e_frame - e_bake) / emax;
                worst = fmax(worst, fabs(e_frame - e_bake) / emax);
                n++;
                break;
            }
        }
    printf("floor under the light: %ld pixels vs their texels, |dE|/Emax mean %.5f, worst %.5f\n", n, sum / (double)n, worst);
    assert_int_equal(n, W * H);
    assert_true(sum / (double)n < 0.005 && worst < 0.02);
    ms_frame_free(&fr);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

/* Texels on triangles per unit of world area, of the cube's triangles and of the walls'. */
static void densities(const ms_scene *sc, const ms_lightmap *lm, double *cube, double *walls)
{
    double area[2] = { 0, 0 };
    long tex[2] = { 0, 0 };
    for (size_t t = 0; t < sc->n_tris; t++) {
        const int k = sc->tri_mesh[t] == 1 ? 0 : sc->tri_object[t] < 5 ? 1 : -1;
        if (k >= 0) area[k] += tri_area(sc->tri + 9 * t);
    }
    for (size_t i = 0; i < (size_t)SIZE * SIZE; i++) {
        if (lm->triangle[i] == MS_NO_TRIANGLE) continue;
        const uint32_t t = lm->triangle[i];
        const int k = sc->tri_mesh[t] == 1 ? 0 : sc->tri_object[t] < 5 ? 1 : -1;
        if (k >= 0) tex[k]++;
    }
    *cube = tex[0] / area[0];
    *walls = tex[1] / area[1];
}

static void test_scale_and_errors(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_objects_scale");
    char json[1024], err[512] = "";
    ms_scene sc;
    ms_lightmap lm;
    double c1, w1, c2, w2;
    write_scene(dir, "", json, sizeof json);
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_set_warning_handler(keep_warning, NULL);
    bake(&sc, &lm);
    densities(&sc, &lm, &c1, &w1);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
    write_scene(dir, ",\"lightmap\":{\"scale\":2}", json, sizeof json);
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_true(sc.mesh_lightmap_scale[1] == 2.0f);
    bake(&sc, &lm);
    ms_set_warning_handler(NULL, NULL);
    densities(&sc, &lm, &c2, &w2);
    const double ratio = (c2 / w2) / (c1 / w1);
    printf("cube texels per area relative to the walls': scale 1: %.3f, scale 2: %.3f (ratio %.2f, 4 wanted)\n", c1 / w1, c2 / w2, ratio);
    assert_true(ratio > 3.0 && ratio < 5.0);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
    /* bad values: one line naming the key */
    write_scene(dir, ",\"lightmap\":{\"scale\":-1}", json, sizeof json);
    assert_int_not_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_non_null(strstr(err, "meshes[1].lightmap.scale"));
    write_scene(dir, ",\"lightmap\":3", json, sizeof json);
    assert_int_not_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_non_null(strstr(err, "meshes[1].lightmap"));
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell),
        cmocka_unit_test(test_scale_and_errors),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
