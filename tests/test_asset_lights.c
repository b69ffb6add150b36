/* The asset's own emitters as lights (scene file "lights_from_emissive", src/scene/scene_emitters.c), each
 * against an oracle of its own, on glTF and OBJ files written here:
 *   - a Cornell-box-like glTF whose scene file names no light: its emitter quad (two triangles) is one rect
 *     light with emissiveFactor x KHR_materials_emissive_strength, facing down; the floor's unshadowed
 *     irradiance under it equals the analytic form factor of a parallel rectangle (Howell's corner formula,
 *     summed over four corner rectangles) times the emission; the emitter casts no shadow on the floor under
 *     it (V = S = 1 by every method), while it does shadow a light placed above it;
 *   - a single emissive triangle: one triangle light with its vertices and front face;
 *   - OBJ/MTL Ke: the same quad, one rect light;
 *   - 70 separate emissive triangles: one error line naming the count, the emitting materials by name with
 *     their triangle counts, and the ways out; "lights_from_emissive": ["lamp"] makes the lamp material's
 *     quad the one light (the 70 glow without being lights, in one warning line); a name that is no
 *     emitting material's is an error listing those there are; the same choice by MTL name;
 *   - "lights_from_emissive": false and no light: the missing light named;
 *   - an asset given as the scene (ms_scene_load on the mesh file): its own emitter is its light, its own
 *     camera node its camera; one without
 *     lights gets the default disk light above it, which casts a shadow the default camera sees, at the
 *     origin and 1e5 from it alike, and every method gives raytrace's V and S there. */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct prim { const float *tri; int n; const char *material; } prim;

/* name.gltf + name.bin in dir: one mesh, one non-indexed primitive per entry (positions only), at node 0;
 * more_nodes (NULL: none): n_more further root nodes (",{...}" each), top_ext: the top-level "extensions". */
static void write_gltf_ex(const char *dir, const char *name, const prim *p, int np, const char *ext_used,
                          const char *more_nodes, int n_more, const char *top_ext)
{
    char path[4096], bin[256];
    snprintf(bin, sizeof bin, "%s.bin", name);
    size_t total = 0;
    for (int i = 0; i < np; i++) total += (size_t)p[i].n * 36;
    FILE *f = fopen(tu_path(path, sizeof path, dir, bin), "wb");
    assert_non_null(f);
    for (int i = 0; i < np; i++) assert_int_equal(fwrite(p[i].tri, 36, (size_t)p[i].n, f), (size_t)p[i].n);
    fclose(f);
    size_t cap = 4096 + (size_t)np * 512, len = 0;
    char *js = malloc(cap);
    assert_non_null(js);
#define PUT(...) (len += (size_t)snprintf(js + len, cap - len, __VA_ARGS__))
    PUT("{\"asset\":{\"version\":\"2.0\"},%s%s\"scene\":0,\"scenes\":[{\"nodes\":[0", ext_used ? ext_used : "",
        top_ext ? top_ext : "");
    for (int i = 1; i <= n_more; i++) PUT(",%d", i);
    PUT("]}],\"nodes\":[{\"mesh\":0}%s],\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],\"bufferViews\":[",
        more_nodes ? more_nodes : "", bin, total);
    size_t off = 0;
    for (int i = 0; i < np; i++) {
        PUT("%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%d}", i ? "," : "", off, p[i].n * 36);
        off += (size_t)p[i].n * 36;
    }
    PUT("],\"accessors\":[");
    for (int i = 0; i < np; i++) {
        float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
        for (int v = 0; v < 3 * p[i].n; v++)
            for (int c = 0; c < 3; c++) { lo[c] = fminf(lo[c], p[i].tri[3 * v + c]); hi[c] = fmaxf(hi[c], p[i].tri[3 * v + c]); }
        PUT("%s{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\",\"min\":[%.9g,%.9g,%.9g],"
            "\"max\":[%.9g,%.9g,%.9g]}", i ? "," : "", i, 3 * p[i].n, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    }
    PUT("],\"materials\":[");
    for (int i = 0; i < np; i++) PUT("%s%s", i ? "," : "", p[i].material);
    PUT("],\"meshes\":[{\"primitives\":[");
    for (int i = 0; i < np; i++) PUT("%s{\"attributes\":{\"POSITION\":%d},\"material\":%d}", i ? "," : "", i, i);
    PUT("]}]}");
#undef PUT
    assert_true(len < cap);
    char gl[256];
    snprintf(gl, sizeof gl, "%s.gltf", name);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, gl), js), 0);
    free(js);
}

static void write_gltf(const char *dir, const char *name, const prim *p, int np, const char *ext_used)
{
    write_gltf_ex(dir, name, p, np, ext_used, NULL, 0, NULL);
}

/* A scene file over mesh `mesh` with `extra` (lights, switches) after the camera. */
static const char *write_scene(const char *dir, const char *name, const char *mesh, const char *extra)
{
    static char path[4096];
    char text[4096];
    snprintf(text, sizeof text,
             "{ \"meshes\": [ { \"file\": \"%s\" } ],\n"
             " \"camera\": { \"eye\": [0, 1, 3.5], \"target\": [0, 0.6, 0], \"up\": [0, 1, 0], \"fov_y\": 60,"
             " \"width\": 24, \"height\": 24 }%s%s,\n \"render\": { \"samples\": 256 } }\n", mesh, extra[0] ? ",\n " : "", extra);
    tu_path(path, sizeof path, dir, name);
    assert_int_equal(tu_write_file(path, text), 0);
    return path;
}

/* The box: floor (y = 0, facing up), ceiling (y = 2, facing down), back and side walls; 2 x 2 x 2. */
static const float box[10][9] = {
    { -1, 0, -1, -1, 0, 1, 1, 0, 1 }, { -1, 0, -1, 1, 0, 1, 1, 0, -1 },
    { -1, 2, -1, 1, 2, 1, -1, 2, 1 }, { -1, 2, -1, 1, 2, -1, 1, 2, 1 },
    { -1, 0, -1, 1, 0, -1, 1, 2, -1 }, { -1, 0, -1, 1, 2, -1, -1, 2, -1 },
    { -1, 0, -1, -1, 2, -1, -1, 2, 1 }, { -1, 0, -1, -1, 2, 1, -1, 0, 1 },
    { 1, 0, -1, 1, 0, 1, 1, 2, 1 }, { 1, 0, -1, 1, 2, 1, 1, 2, -1 } };
/* The emitter: x, z in [-0.25, 0.25] at y = 1.9, counter-clockwise seen from below (its front faces down). */
#define EM_Y 1.9f
static const float emitter[2][9] = { { -0.25f, EM_Y, -0.25f, 0.25f, EM_Y, -0.25f, -0.25f, EM_Y, 0.25f },
                                     { 0.25f, EM_Y, -0.25f, 0.25f, EM_Y, 0.25f, -0.25f, EM_Y, 0.25f } };
static const char *const white = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.8,0.8,0.8,1],\"metallicFactor\":0}}";
static const char *const glow = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.8,0.8,0.8,1],\"metallicFactor\":0},"
                                "\"emissiveFactor\":[1,0.5,0.25],\"extensions\":{\"KHR_materials_emissive_strength\":"
                                "{\"emissiveStrength\":4}}}";
static const char *const ext = "\"extensionsUsed\":[\"KHR_materials_emissive_strength\"],";

/* Irradiance per unit radiance at a point under the corner of a parallel rectangle [0, x] x [0, z] at height h
 * (Howell's catalogue, "differential planar element to parallel rectangle, normal through a corner":
 * pi F = (A / sqrt(1 + A^2)) atan(B / sqrt(1 + A^2)) + (B / sqrt(1 + B^2)) atan(A / sqrt(1 + B^2)), halved),
 * signed by the corner's quadrant. */
static double corner_rect(double x, double z, double h)
{
    const double A = fabs(x) / h, B = fabs(z) / h;
    const double f = 0.5 * (A / sqrt(1 + A * A) * atan(B / sqrt(1 + A * A)) + B / sqrt(1 + B * B) * atan(A / sqrt(1 + B * B)));
    return (x < 0 ? -1 : 1) * (z < 0 ? -1 : 1) * f;
}

/* The rectangle [x0, x1] x [z0, z1] at height h above the point (px, 0, pz), receiver facing up. */
static double rect_irradiance(double x0, double x1, double z0, double z1, double h, double px, double pz)
{
    x0 -= px; x1 -= px; z0 -= pz; z1 -= pz;
    return corner_rect(x1, z1, h) - corner_rect(x0, z1, h) - corner_rect(x1, z0, h) + corner_rect(x0, z0, h);
}

static void test_cornell_emitter(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("asset_lights_cornell");
    const prim p[2] = { { &box[0][0], 10, white }, { &emitter[0][0], 2, glow } };
    write_gltf(dir, "box", p, 2, ext);
    const char *path = write_scene(dir, "box.json", "box.gltf", "");
    ms_scene sc;
    char err[512];
    if (ms_scene_load(path, &sc, err, sizeof err)) fprintf(stderr, "%s\n", err);
    size_t n;
    const ms_light *L = ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 1);
    assert_int_equal(L[0].shape, MS_LIGHT_RECT);
    /* emissiveFactor (1, 0.5, 0.25) x strength 4 */
    assert_float_equal(L[0].emission.x, 4.0f, 0.0f);
    assert_float_equal(L[0].emission.y, 2.0f, 0.0f);
    assert_float_equal(L[0].emission.z, 1.0f, 0.0f);
    const float nx = L[0].edge_s.y * L[0].edge_t.z - L[0].edge_s.z * L[0].edge_t.y;
    const float ny = L[0].edge_s.z * L[0].edge_t.x - L[0].edge_s.x * L[0].edge_t.z;
    assert_float_equal(nx, 0.0f, 0.0f);
    assert_float_equal(ny, -0.25f, 1e-7f);   /* 0.5 x 0.5, facing down */
    assert_float_equal(ms_light_area(&L[0]), 0.25f, 1e-7f);
    /* the floor's irradiance, analytic, at points under and beside the emitter */
    static const float pts[4][3] = { { 0, 0, 0 }, { 0.3f, 0, -0.2f }, { -0.7f, 0, 0.6f }, { 0.1f, 0, 0.24f } };
    static const float up[4][3] = { { 0, 1, 0 }, { 0, 1, 0 }, { 0, 1, 0 }, { 0, 1, 0 } };
    double worst = 0.0;
    for (int i = 0; i < 4; i++) {
        const double want = rect_irradiance(-0.25, 0.25, -0.25, 0.25, EM_Y, pts[i][0], pts[i][2]);
        const double got = ms_light_irradiance(&L[0], pts[i], up[i]);
        worst = fmax(worst, fabs(got - want) / want);
        printf("floor (%g, %g): irradiance %.6g x emission (4, 2, 1), analytic %.6g\n", pts[i][0], pts[i][2], got, want);
    }
    assert_true(worst < 1e-5);
    /* no shadow of the emitter on the floor: V = S = 1 by every method */
    ms_accel *acc = NULL;
    assert_int_equal(ms_accel_build(&sc, 2, &acc, err, sizeof err), 0);
    const ms_points q = { .n = 4, .position = &pts[0][0], .normal = &up[0][0] };
    const char *const *names = ms_method_names();
    for (int mi = 0; names[mi]; mi++) {
        ms_points_options o;
        memset(&o, 0, sizeof o);
        o.method = names[mi];
        o.samples = 256;
        o.threads = 1;
        float v[4], s[4];
        uint16_t fr[4];
        assert_int_equal(ms_visibility_points(acc, NULL, &q, &o, v, s, fr, NULL, err, sizeof err), 0);
        for (int i = 0; i < 4; i++) {
            if (v[i] != 1.0f || s[i] != 1.0f) fprintf(stderr, "%s: point %d: V %g S %g\n", names[mi], i, v[i], s[i]);
            assert_true(v[i] == 1.0f && s[i] == 1.0f);
            assert_true(fr[i] > 0);
        }
    }
    /* A light just above the emitter, facing down: the emitter does shadow it. */
    ms_light above = L[0];
    above.corner.y = 1.95f;
    float v[4], s[4];
    ms_points_options o;
    memset(&o, 0, sizeof o);
    o.samples = 256;
    o.threads = 1;
    assert_int_equal(ms_visibility_points(acc, &above, &q, &o, v, s, NULL, NULL, err, sizeof err), 0);
    assert_true(v[0] == 0.0f);
    ms_accel_free(acc);
    ms_scene_free(&sc);
    /* A scene file naming a light: the emitters are added only on request, after it. */
    path = write_scene(dir, "box_light.json", "box.gltf",
                       "\"light\": { \"corner\": [-0.5, 1.99, -0.5], \"edge_s\": [1, 0, 0], \"edge_t\": [0, 0, 1] }");
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 1);
    ms_scene_free(&sc);
    {   /* not silently: the CLI says the emitters were not made lights */
        char out[4096], errbuf[2048];
        tu_path(out, sizeof out, dir, "out.png");
        const char *args[] = { path, "--quiet", "-o", out, NULL };
        tu_run_result res;
        assert_int_equal(tu_run_cli_ex(args, NULL, errbuf, sizeof errbuf, &res), 0);
        assert_non_null(strstr(errbuf, "2 emissive triangles not made lights"));
    }
    path = write_scene(dir, "box_both.json", "box.gltf",
                       "\"light\": { \"corner\": [-0.5, 1.99, -0.5], \"edge_s\": [1, 0, 0], \"edge_t\": [0, 0, 1] },"
                       " \"lights_from_emissive\": true");
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    L = ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 2);
    assert_float_equal(L[0].corner.y, 1.99f, 0.0f);
    assert_float_equal(L[1].emission.x, 4.0f, 0.0f);
    ms_scene_free(&sc);
    path = write_scene(dir, "box_none.json", "box.gltf", "\"lights_from_emissive\": false");
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "\"light\" is missing"));
}

static void test_single_triangle_and_mtl(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("asset_lights_tri");
    const prim p[2] = { { &box[0][0], 10, white }, { &emitter[0][0], 1, glow } };
    write_gltf(dir, "tri", p, 2, ext);
    ms_scene sc;
    char err[512];
    assert_int_equal(ms_scene_load(write_scene(dir, "tri.json", "tri.gltf", ""), &sc, err, sizeof err), 0);
    size_t n;
    const ms_light *L = ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 1);
    assert_int_equal(L[0].shape, MS_LIGHT_TRIANGLE);
    assert_float_equal(ms_light_area(&L[0]), 0.125f, 1e-7f);
    const float *t = emitter[0];
    assert_true(L[0].corner.x == t[0] && L[0].corner.y == t[1] && L[0].corner.z == t[2]);
    assert_true(L[0].edge_s.x == t[3] - t[0] && L[0].edge_t.z == t[8] - t[2]);
    /* it emits down: the floor below is lit, a point above it is not */
    const float below[3] = { -0.1f, 0, -0.1f }, above[3] = { -0.1f, 3, -0.1f }, nu[3] = { 0, 1, 0 }, nd[3] = { 0, -1, 0 };
    assert_true(ms_light_irradiance(&L[0], below, nu) > 0.0f);
    assert_true(ms_light_irradiance(&L[0], above, nd) == 0.0f);
    ms_scene_free(&sc);
    /* OBJ/MTL: Ke on the quad (one face of four vertices, triangulated into two): one rect light */
    char path[4096];
    tu_write_file(tu_path(path, sizeof path, dir, "q.mtl"), "newmtl lamp\nKd 0.8 0.8 0.8\nKe 2 3 4\n");
    tu_write_file(tu_path(path, sizeof path, dir, "q.obj"),
                  "mtllib q.mtl\nv -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nf 1 2 3 4\n"
                  "v -0.25 1.9 -0.25\nv 0.25 1.9 -0.25\nv 0.25 1.9 0.25\nv -0.25 1.9 0.25\nusemtl lamp\nf 5 6 7 8\n");
    assert_int_equal(ms_scene_load(write_scene(dir, "q.json", "q.obj", ""), &sc, err, sizeof err), 0);
    L = ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 1);
    assert_int_equal(L[0].shape, MS_LIGHT_RECT);
    assert_float_equal(L[0].emission.z, 4.0f, 0.0f);
    assert_float_equal(ms_light_area(&L[0]), 0.25f, 1e-7f);
    assert_true(ms_light_irradiance(&L[0], below, nu) > 0.0f);
    ms_scene_free(&sc);
}

/* A named copy of glow (its emission) and its name. */
static const char *const screen = "{\"name\":\"screen\",\"emissiveFactor\":[0.2,0.2,0.2]}";
static const char *const lamp = "{\"name\":\"lamp\",\"emissiveFactor\":[3,2,1]}";

/* 70 separate emissive triangles ("screen") beside a quad ("lamp"): 71 lights, over the limit of 64: one line
 * with the count, the materials, and the ways out; then the lamp chosen by name. */
static void test_too_many_emitters(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("asset_lights_many");
    float *t = malloc(70 * 9 * sizeof *t);
    assert_non_null(t);
    for (int i = 0; i < 70; i++) {
        const float x = -0.9f + 0.025f * (float)i;
        const float v[9] = { x, 1.9f, 0, x + 0.01f, 1.9f, 0, x, 1.9f, 0.01f };
        memcpy(t + 9 * i, v, sizeof v);
    }
    const prim p[3] = { { &box[0][0], 10, white }, { t, 70, screen }, { &emitter[0][0], 2, lamp } };
    write_gltf(dir, "many", p, 3, NULL);
    free(t);
    const char *path = write_scene(dir, "many.json", "many.gltf", "");
    char out[4096], errbuf[2048];
    tu_path(out, sizeof out, dir, "out.png");
    const char *args[] = { path, "--quiet", "-o", out, NULL };
    tu_run_result res;
    const int rc = tu_run_cli_ex(args, NULL, errbuf, sizeof errbuf, &res);
    printf("70 emitters: exit %d: %s", rc, errbuf);
    assert_int_equal(rc, 2);
    assert_int_equal(res.lines, 1);
    assert_non_null(strstr(errbuf, "many.json"));
    assert_non_null(strstr(errbuf, "71 lights"));
    assert_non_null(strstr(errbuf, "\"screen\": 70 triangles, \"lamp\": 2 triangles"));
    assert_non_null(strstr(errbuf, "\"lights_from_emissive\": [\"name\", ...]"));
    assert_non_null(strstr(errbuf, "\"lights_from_emissive\": false"));
    assert_false(tu_file_exists(out));

    /* Only the lamp: one rect light of its emission; the screen's 70 triangles said in one warning line. */
    path = write_scene(dir, "lamp.json", "many.gltf", "\"lights_from_emissive\": [\"lamp\"]");
    ms_scene sc;
    char err[1024];
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), MS_OK);
    size_t n;
    const ms_light *L = ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 1);
    assert_int_equal(L[0].shape, MS_LIGHT_RECT);
    assert_true(L[0].emission.x == 3.0f && L[0].emission.y == 2.0f && L[0].emission.z == 1.0f);
    assert_float_equal(ms_light_area(&L[0]), 0.25f, 1e-7f);
    ms_scene_free(&sc);
    const char *args2[] = { path, "--quiet", "-o", out, NULL };
    assert_int_equal(tu_run_cli_ex(args2, NULL, errbuf, sizeof errbuf, &res), 0);
    assert_non_null(strstr(errbuf, "70 emissive triangles of materials not listed in \"lights_from_emissive\""));
    assert_true(tu_file_exists(out));
    /* Both named: over the limit again, the same line. */
    path = write_scene(dir, "both.json", "many.gltf", "\"lights_from_emissive\": [\"lamp\", \"screen\"]");
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "71 lights"));
    /* A name that is no emitting material's ("white" has no name; a typo): the error lists those there are. */
    path = write_scene(dir, "typo.json", "many.gltf", "\"lights_from_emissive\": [\"lamp \"]");
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "names \"lamp \", which is no emitting material"));
    assert_non_null(strstr(err, "\"screen\": 70 triangles, \"lamp\": 2 triangles"));
    path = write_scene(dir, "empty.json", "many.gltf", "\"lights_from_emissive\": []");
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "a non-empty list of material names"));
    /* MTL: the same choice by newmtl name. */
    char mpath[4096];
    tu_write_file(tu_path(mpath, sizeof mpath, dir, "m.mtl"), "newmtl sign\nKe 0.1 0.1 0.1\nnewmtl lamp\nKe 2 3 4\n");
    tu_write_file(tu_path(mpath, sizeof mpath, dir, "m.obj"),
                  "mtllib m.mtl\nv -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nusemtl sign\nf 1 2 3 4\n"
                  "v -0.25 1.9 -0.25\nv 0.25 1.9 -0.25\nv 0.25 1.9 0.25\nv -0.25 1.9 0.25\nusemtl lamp\nf 5 6 7 8\n");
    assert_int_equal(ms_scene_load(write_scene(dir, "m.json", "m.obj", "\"lights_from_emissive\": [\"lamp\"]"), &sc,
                                   err, sizeof err), MS_OK);
    L = ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 1);
    assert_true(L[0].emission.z == 4.0f && L[0].corner.y == 1.9f);
    ms_scene_free(&sc);
    assert_int_equal(ms_scene_load(write_scene(dir, "m2.json", "m.obj", ""), &sc, err, sizeof err), MS_OK);
    ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 2);
    ms_scene_free(&sc);
}

/* KHR_lights_punctual: a point light (10 cd, extras.radius 0.1) becomes a sphere of radiance 10 / (pi 0.1^2);
 * a spot facing down (node rotated -90 degrees about x) a disk facing down of the scene file's
 * punctual_radius; a directional light (3 lux, the node turned so that its +Z is up) a sun straight up of
 * radiance 3 / (pi sin^2 0.265 deg); V and S of the frame equal raytrace's by every method. */
static void test_punctual(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("asset_lights_punctual");
    const prim p[1] = { { &box[0][0], 10, white } };
    write_gltf_ex(dir, "pl", p, 1, "\"extensionsUsed\":[\"KHR_lights_punctual\"],",
                  ",{\"translation\":[0.2,1.5,-0.1],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}"
                  ",{\"translation\":[-0.3,1.8,0.2],\"rotation\":[-0.70710678,0,0,0.70710678],"
                  "\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}}"
                  ",{\"rotation\":[-0.70710678,0,0,0.70710678],\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}}", 3,
                  "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":["
                  "{\"type\":\"point\",\"color\":[1,0.5,0.25],\"intensity\":10,\"extras\":{\"radius\":0.1}},"
                  "{\"type\":\"spot\",\"intensity\":2,\"spot\":{\"outerConeAngle\":0.5}},"
                  "{\"type\":\"directional\",\"intensity\":3}]}},");
    const char *path = write_scene(dir, "pl.json", "pl.gltf", "\"punctual_radius\": 0.2");
    ms_scene sc;
    char err[512];
    if (ms_scene_load(path, &sc, err, sizeof err)) fprintf(stderr, "%s\n", err);
    size_t n;
    const ms_light *L = ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 3);
    assert_int_equal(L[0].shape, MS_LIGHT_SPHERE);
    assert_float_equal(L[0].center.x, 0.2f, 0.0f);
    assert_float_equal(L[0].center.y, 1.5f, 0.0f);
    assert_float_equal(L[0].center.z, -0.1f, 0.0f);
    assert_float_equal(L[0].radius, 0.1f, 0.0f);
    /* candela to radiance: I = L pi r^2 */
    assert_float_equal(L[0].emission.x, (float)(10.0 / (M_PI * 0.01)), 1e-3f);
    assert_float_equal(L[0].emission.y, (float)(5.0 / (M_PI * 0.01)), 1e-3f);
    assert_int_equal(L[1].shape, MS_LIGHT_DISK);
    assert_float_equal(ms_light_area(&L[1]), (float)(M_PI * 0.04), 1e-6f);
    assert_float_equal(L[1].emission.x, (float)(2.0 / (M_PI * 0.04)), 1e-4f);
    const float ny = L[1].edge_s.z * L[1].edge_t.x - L[1].edge_s.x * L[1].edge_t.z;
    assert_true(ny < 0.0f);   /* emits down */
    /* the disk's centre */
    assert_float_equal(L[1].corner.x + 0.5f * (L[1].edge_s.x + L[1].edge_t.x), -0.3f, 1e-6f);
    assert_float_equal(L[1].corner.y + 0.5f * (L[1].edge_s.y + L[1].edge_t.y), 1.8f, 1e-6f);
    assert_int_equal(L[2].shape, MS_LIGHT_SUN);
    assert_true(fabsf(L[2].center.x) < 1e-6f && fabsf(L[2].center.y - 1.0f) < 1e-6f && fabsf(L[2].center.z) < 1e-6f);
    const double sa = sin(0.265 * M_PI / 180.0);
    assert_true(fabs(L[2].emission.x / (3.0 / (M_PI * sa * sa)) - 1.0) < 1e-5);
    /* every method's frame equals raytrace's, light by light */
    ms_render_options o;
    tu_render_options_default(&o);
    o.width = o.height = 24;
    o.samples = 256;
    o.threads = 2;
    ms_frame ref;
    tu_every_method_as_raytrace(&sc, &o, "punctual lights", &ref, NULL, NULL);
    long lit = 0;
    for (int i = 0; i < 2 * 24 * 24; i++) lit += ref.vis[i] > 0.0f;   /* the sun (light 2) is outside the box */
    assert_true(lit > 24 * 24 / 2);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
    /* the CLI: one warning line for the spot's cone, none for the directional light */
    char out[4096], errbuf[4096];
    tu_path(out, sizeof out, dir, "out.png");
    const char *args[] = { path, "-o", out, "--quiet", NULL };
    tu_run_result res;
    assert_int_equal(tu_run_cli_ex(args, NULL, errbuf, sizeof errbuf, &res), 0);
    printf("%s", errbuf);
    assert_null(strstr(errbuf, "directional"));
    assert_non_null(strstr(errbuf, "the cone is not modelled"));
}

/* An asset given as the scene: the emitter glTF read directly is the scene file's scene (its quad the one
 * rect light, the same triangles); an OBJ block on a ground without lights gets a camera looking at its box's
 * centre (Y up) and one disk light above it, facing it, that shadows part of the ground the camera sees (some
 * ground pixels in full light, some darkened), with every method's V and S raytrace's; the same OBJ moved 1e5
 * away gives the same camera and light relative to the geometry. */
static void test_asset_as_scene(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("asset_as_scene");
    const prim p[2] = { { &box[0][0], 10, white }, { &emitter[0][0], 2, glow } };
    write_gltf(dir, "cb", p, 2, ext);
    char path[4096], err[512];
    ms_scene sc, ref_sc;
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "cb.gltf"), &sc, err, sizeof err), 0);
    assert_int_equal(ms_scene_load(write_scene(dir, "cb.json", "cb.gltf", ""), &ref_sc, err, sizeof err), 0);
    size_t n, n_ref;
    const ms_light *L = ms_scene_lights(&sc, &n), *R = ms_scene_lights(&ref_sc, &n_ref);
    assert_int_equal((int)n, 1);
    assert_int_equal((int)n_ref, 1);
    assert_int_equal(L[0].shape, MS_LIGHT_RECT);
    assert_int_equal(R[0].shape, MS_LIGHT_RECT);
    assert_memory_equal(&L[0].corner, &R[0].corner, sizeof L[0].corner);
    assert_memory_equal(&L[0].edge_s, &R[0].edge_s, sizeof L[0].edge_s);
    assert_memory_equal(&L[0].edge_t, &R[0].edge_t, sizeof L[0].edge_t);
    assert_memory_equal(&L[0].emission, &R[0].emission, sizeof L[0].emission);
    assert_int_equal((int)sc.n_tris, (int)ref_sc.n_tris);
    assert_memory_equal(sc.tri, ref_sc.tri, 9 * sizeof(float) * sc.n_tris);
    assert_float_equal(sc.camera.up.y, 1.0f, 0.0f);
    ms_scene_free(&sc);
    ms_scene_free(&ref_sc);
    /* the asset's own camera: the first camera node's, turned 90 degrees about +Y (its -Z towards -X), with
     * its field of view and aspect ratio */
    write_gltf_ex(dir, "cam", p, 2, ext, ",{\"camera\":0,\"translation\":[2.5,1,0.5],"
                  "\"rotation\":[0,0.70710678,0,0.70710678]},{\"camera\":0}", 2,
                  "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":1.0,\"aspectRatio\":1.5,"
                  "\"znear\":0.1}}],");
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "cam.gltf"), &sc, err, sizeof err), 0);
    const ms_camera *cam = &sc.camera;
    assert_int_equal(cam->type, MS_CAMERA_PINHOLE);
    assert_float_equal(cam->eye.x, 2.5f, 1e-6f);
    assert_float_equal(cam->eye.y, 1.0f, 1e-6f);
    assert_float_equal(cam->eye.z, 0.5f, 1e-6f);
    const float dx = cam->target.x - cam->eye.x, dy = cam->target.y - cam->eye.y, dz = cam->target.z - cam->eye.z;
    assert_true(dx < 0.0f && fabsf(dy) < 1e-5f * fabsf(dx) && fabsf(dz) < 1e-5f * fabsf(dx));
    assert_float_equal(cam->up.y, 1.0f, 1e-6f);
    assert_float_equal(cam->fov_y, (float)(180.0 / M_PI), 1e-4f);
    assert_int_equal(cam->width, 1024);
    assert_int_equal(cam->height, 683);
    ms_scene_free(&sc);

    /* a 2 x 2 x 2 block on a 6 x 6 ground, at the origin and far from it */
    for (int far = 0; far < 2; far++) {
        const double off = far ? 1e5 : 0.0;
        char obj[4096];
        snprintf(obj, sizeof obj,
                 "v %g 0 %g\nv %g 0 %g\nv %g 0 %g\nv %g 0 %g\nf 1 2 3 4\n"
                 "v %g 0 %g\nv %g 0 %g\nv %g 0 %g\nv %g 0 %g\nv %g 2 %g\nv %g 2 %g\nv %g 2 %g\nv %g 2 %g\n"
                 "f 5 9 10 6\nf 6 10 11 7\nf 7 11 12 8\nf 8 12 9 5\nf 9 12 11 10\n",
                 off - 3, off - 3, off - 3, off + 3, off + 3, off + 3, off + 3, off - 3,
                 off - 1, off - 1, off + 1, off - 1, off + 1, off + 1, off - 1, off + 1,
                 off - 1, off - 1, off + 1, off - 1, off + 1, off + 1, off - 1, off + 1);
        const char *name = far ? "far.obj" : "block.obj";
        assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, name), obj), 0);
        if (ms_scene_load(path, &sc, err, sizeof err)) fail_msg("%s", err);
        L = ms_scene_lights(&sc, &n);
        assert_int_equal((int)n, 1);
        assert_int_equal(L[0].shape, MS_LIGHT_DISK);
        /* the box's centre in the scene's frame (origin: where the loader moved it) */
        const float c[3] = { (float)(off - sc.origin[0]), (float)(1.0 - sc.origin[1]), (float)(off - sc.origin[2]) };
        const float r = sqrtf(36.0f + 4.0f + 36.0f);
        assert_float_equal(sc.camera.target.x, c[0], 1e-5f * r);
        assert_float_equal(sc.camera.target.y, c[1], 1e-5f * r);
        assert_float_equal(sc.camera.target.z, c[2], 1e-5f * r);
        const float ex = sc.camera.eye.x - c[0], ey = sc.camera.eye.y - c[1], ez = sc.camera.eye.z - c[2];
        assert_float_equal(sqrtf(ex * ex + ey * ey + ez * ez), 1.35f * r, 1e-4f * r);
        assert_true(ey > 0.0f);
        const float lc[3] = { L[0].corner.x + 0.5f * (L[0].edge_s.x + L[0].edge_t.x) - c[0],
                              L[0].corner.y + 0.5f * (L[0].edge_s.y + L[0].edge_t.y) - c[1],
                              L[0].corner.z + 0.5f * (L[0].edge_s.z + L[0].edge_t.z) - c[2] };
        assert_true(lc[1] > 1.0f);   /* above the block */
        /* it faces the centre: the block's top receives about pi cos(52 deg) of irradiance (the geometric factor
         * times the radiance) */
        const float top[3] = { c[0], c[1] + 1.0f, c[2] }, up[3] = { 0, 1, 0 };
        const double E = ms_light_irradiance(&L[0], top, up) * L[0].emission.y;
        assert_true(E > 1.5 && E < 3.0);
        ms_render_options o;
        tu_render_options_default(&o);
        o.width = 64;
        o.height = 48;
        o.samples = 256;
        o.threads = 2;
        ms_frame ref;
        tu_every_method_as_raytrace(&sc, &o, far ? "asset far from the origin" : "asset as the scene", &ref, NULL, NULL);
        long full = 0, shaded = 0;
        for (int i = 0; i < 64 * 48; i++) {
            full += ref.vis[i] == 1.0f;
            shaded += ref.vis[i] >= 0.0f && ref.vis[i] < 0.5f;
        }
        assert_true(full > 64 * 48 / 20);   /* the ground and block fill about a sixth of the frame */
        assert_true(shaded > 20);
        ms_frame_free(&ref);
        ms_scene_free(&sc);
    }
    /* the CLI takes the asset where a scene file goes, and says what it chose */
    char out[4096], errbuf[4096];
    tu_path(out, sizeof out, dir, "block.png");
    const char *args[] = { tu_path(path, sizeof path, dir, "block.obj"), "-o", out, "--width", "16", "--height", "12",
                           "--samples", "256", NULL };
    tu_run_result res;
    assert_int_equal(tu_run_cli_ex(args, NULL, errbuf, sizeof errbuf, &res), 0);
    assert_non_null(strstr(errbuf, "an asset given as the scene"));
    assert_true(tu_file_exists(out));
    /* a damaged asset: one line naming the file */
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "bad.glb"), "glTF but not binary"), 0);
    assert_int_not_equal(ms_scene_load(path, &sc, err, sizeof err), MS_OK);
    assert_non_null(strstr(err, "bad.glb"));
    assert_null(strchr(err, '\n'));
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell_emitter),
        cmocka_unit_test(test_single_triangle_and_mtl),
        cmocka_unit_test(test_too_many_emitters),
        cmocka_unit_test(test_punctual),
        cmocka_unit_test(test_asset_as_scene),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
