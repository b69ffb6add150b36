/* The bake back onto the asset (ms_bake_gltf, `microshadow bake --gltf`), read back by the tests' own glb
 * reader (util/glb_read.c: cJSON for the JSON chunk, libpng for the images):
 *   - every triangle of the scene is in the glb once, at its positions, with TEXCOORD_1 = the UVs baked into;
 *     the material's base colour factor and texture texels are the scene's;
 *   - the lightmap (MOZ_lightmap, linear 8-bit, x intensity) sampled bilinearly at TEXCOORD_1 of random points
 *     on every primitive equals the same bilinear blend of ms_visibility_points irradiance computed here at the
 *     four texel centres' world points (found from the glb's own positions and UVs), within half an 8-bit step
 *     of the intensity (I/510): the quantisation is the only difference allowed; at the points themselves the
 *     difference (interpolation and sampling) is reported;
 *   - the shadowmask holds each light's S in its channel (I/510 likewise), the extras name them;
 *   - the ground's material has a normal texture: its primitive carries TANGENT (unit, orthogonal to NORMAL,
 *     w = +-1), the others none; the Khronos glTF Validator (npm gltf-validator, viewer/validate.mjs) reports
 *     0 errors and 0 warnings (skipped with a message without node or the validator);
 *   - the CLI writes the glb with the EXR, and refuses a --gltf not ending in .glb with exit 2, writing nothing;
 *   - the scene's extras list the scene's lights, every shape, in world coordinates, with their radiance, and its
 *     camera. */
#include "testutil.h"
#include "glb_read.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define SIZE 128
#define SAMPLES 256


/* The texture of the ground: 4x4 RGB, each texel its own colour. */
static void checker(uint8_t px[48])
{
    for (int i = 0; i < 16; i++) { px[3 * i] = (uint8_t)(16 * i); px[3 * i + 1] = (uint8_t)(255 - 13 * i); px[3 * i + 2] = (uint8_t)(40 + 7 * i); }
}

/* A 4x4 ground at y = 0 (glTF: TEXCOORD_0 0..1 and TEXCOORD_1 = ((x+2)/4, (z+2)/4), a textured material), a box
 * above it (OBJ, no UVs: xatlas), a rect and a disk light. */
static void write_scene(const char *dir, char *json_path, size_t n)
{
    const float gpos[18] = { -2, 0, -2, -2, 0, 2, 2, 0, 2, -2, 0, -2, 2, 0, 2, 2, 0, -2 };
    float uv0[12], uv1[12];
    for (int k = 0; k < 6; k++) {
        uv1[2 * k] = (gpos[3 * k] + 2) / 4;
        uv1[2 * k + 1] = (gpos[3 * k + 2] + 2) / 4;
        uv0[2 * k] = uv1[2 * k];
        uv0[2 * k + 1] = 1.0f - uv1[2 * k + 1];
    }
    unsigned char buf[168];
    memcpy(buf, gpos, 72);
    memcpy(buf + 72, uv0, 48);
    memcpy(buf + 120, uv1, 48);
    char enc[300];
    tu_base64(buf, sizeof buf, enc);
    uint8_t px[48];
    checker(px);
    char penc[1500];
    tu_png_base64(px, 4, 4, penc, sizeof penc);
    char text[8192];
    snprintf(text, sizeof text,
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1,\"TEXCOORD_1\":2},\"material\":0}]}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.9,0.8,0.7,1],\"baseColorTexture\":{\"index\":0},"
        "\"metallicFactor\":0,\"roughnessFactor\":0.75},\"normalTexture\":{\"index\":0,\"scale\":0.5}}],"
        "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],"
        "\"buffers\":[{\"byteLength\":168,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":72},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":48},"
        "{\"buffer\":0,\"byteOffset\":120,\"byteLength\":48}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\",\"min\":[-2,0,-2],\"max\":[2,0,2]},"
        "{\"bufferView\":1,\"componentType\":5126,\"count\":6,\"type\":\"VEC2\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":6,\"type\":\"VEC2\"}]}", penc, enc);
    char p[1024];
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "ground.gltf"), text), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "box.obj"),
        "v -0.6 0.6 -0.4\nv 0.6 0.6 -0.4\nv 0.6 0.6 0.4\nv -0.6 0.6 0.4\n"
        "v -0.6 1.4 -0.4\nv 0.6 1.4 -0.4\nv 0.6 1.4 0.4\nv -0.6 1.4 0.4\n"
        "f 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n"), 0);
    assert_int_equal(tu_write_file(tu_path(json_path, n, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"ground.gltf\"},{\"file\":\"box.obj\"}],"
        "\"camera\":{\"eye\":[0,5,5],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":64,\"height\":64},"
        "\"lights\":[{\"corner\":[-0.5,4,-0.5],\"edge_s\":[1,0,0],\"edge_t\":[0,0,1],\"emission\":[1,1,1]},"
        "{\"shape\":\"disk\",\"center\":[1.2,2.5,0.3],\"normal\":[0,-1,0],\"radius\":0.4,\"emission\":[2,1,0.5]}]}"), 0);
}

static void bake(const ms_scene *sc, ms_lightmap *lm)
{
    ms_bake_options bo;
    tu_bake_options(&bo, SIZE, 1, SAMPLES);
    char err[512] = "";
    assert_int_equal(ms_bake(sc, NULL, &bo, lm, err, sizeof err), MS_OK);
}

static int geti(const cJSON *o, const char *k) { const cJSON *v = cJSON_GetObjectItem(o, k); return cJSON_IsNumber(v) ? (int)v->valuedouble : -1; }

/* The scene triangle with exactly these three positions, or -1. */
static long find_tri(const ms_scene *sc, const float p[9])
{
    for (size_t t = 0; t < sc->n_tris; t++)
        if (!memcmp(sc->tri + 9 * t, p, 9 * sizeof(float))) return (long)t;
    return -1;
}

static double bilinear(const uint8_t *img, int W, int H, int ch, int c, double u, double v)
{
    const double x = u * W - 0.5, y = v * H - 0.5;
    const int x0 = (int)floor(x), y0 = (int)floor(y);
    const double fx = x - x0, fy = y - y0;
    double s = 0.0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            const int xx = x0 + i < 0 ? 0 : x0 + i >= W ? W - 1 : x0 + i, yy = y0 + j < 0 ? 0 : y0 + j >= H ? H - 1 : y0 + j;
            s += (i ? fx : 1 - fx) * (j ? fy : 1 - fy) * img[((size_t)yy * W + xx) * ch + c];
        }
    return s;
}

/* Barycentric coordinates of point q in the 2D triangle a (3 x 2). */
static void bary2(const double a[3][2], const double q[2], double w[3])
{
    const double d = (a[1][0] - a[0][0]) * (a[2][1] - a[0][1]) - (a[1][1] - a[0][1]) * (a[2][0] - a[0][0]);
    w[1] = ((q[0] - a[0][0]) * (a[2][1] - a[0][1]) - (q[1] - a[0][1]) * (a[2][0] - a[0][0])) / d;
    w[2] = ((a[1][0] - a[0][0]) * (q[1] - a[0][1]) - (a[1][1] - a[0][1]) * (q[0] - a[0][0])) / d;
    w[0] = 1.0 - w[1] - w[2];
}

/* Irradiance (channel c) at world point p, normal n, on scene triangle tri, pattern key (kx, ky): the oracle. */
static double oracle(const ms_accel *acc, const ms_scene *sc, const float p[3], const float n[3], uint32_t tri, uint32_t kx,
                     uint32_t ky, int c)
{
    size_t nl;
    const ms_light *L = ms_accel_lights(acc, &nl);
    ms_points_options po;
    memset(&po, 0, sizeof po);
    po.samples = SAMPLES;
    po.isa = tu_isa_cap();
    po.threads = 1;
    const uint32_t key[2] = { kx, ky };
    ms_points pts = { 1, p, n, &tri, key };
    double e = 0.0;
    char err[256];
    for (size_t l = 0; l < nl; l++) {
        float S;
        assert_int_equal(ms_visibility_points(acc, &L[l], &pts, &po, NULL, &S, NULL, NULL, err, sizeof err), MS_OK);
        const float em = c == 0 ? L[l].emission.x : c == 1 ? L[l].emission.y : L[l].emission.z;
        e += (double)ms_light_irradiance(&L[l], p, n) * S * em;
    }
    (void)sc;
    return e;
}

static void test_glb_reads_back(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_gltf_back");
    char json[1024], path[1024], err[512] = "";
    write_scene(dir, json, sizeof json);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    assert_int_equal(sc.n_tris, 14);
    ms_lightmap lm;
    bake(&sc, &lm);
    tu_path(path, sizeof path, dir, "out.glb");
    assert_int_equal(ms_bake_write_gltf(&sc, &lm, NULL, path, err, sizeof err), MS_OK);
    tu_glb g;
    assert_int_equal(tu_glb_read(path, &g), 0);

    /* the maps: the lightmap image against the lightmap, the shadowmask against S, texel by texel */
    const cJSON *mat0 = tu_glb_item(&g, "materials", 0);
    const cJSON *moz = cJSON_GetObjectItem(cJSON_GetObjectItem(mat0, "extensions"), "MOZ_lightmap");
    assert_non_null(moz);
    assert_int_equal(geti(moz, "texCoord"), 1);
    const double I = cJSON_GetObjectItem(moz, "intensity")->valuedouble;
    int W, H, w2, h2;
    uint8_t *lmap = tu_glb_texture(&g, geti(moz, "index"), 3, &W, &H);
    assert_non_null(lmap);
    assert_int_equal(W, SIZE);
    assert_int_equal(H, SIZE);
    const cJSON *sm = cJSON_GetObjectItem(cJSON_GetObjectItem(mat0, "extras"), "shadowmask");
    assert_non_null(sm);
    assert_int_equal(geti(sm, "texCoord"), 1);
    const cJSON *chans = cJSON_GetObjectItem(sm, "channels");
    assert_int_equal(cJSON_GetArraySize(chans), 2);
    assert_string_equal(cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetArrayItem(chans, 0), "channel")), "R");
    assert_string_equal(cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetArrayItem(chans, 0), "shape")), "rect");
    assert_string_equal(cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetArrayItem(chans, 1), "channel")), "G");
    assert_string_equal(cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetArrayItem(chans, 1), "shape")), "disk");
    uint8_t *mask = tu_glb_texture(&g, geti(sm, "index"), 4, &w2, &h2);
    assert_non_null(mask);
    assert_int_equal(w2, SIZE);
    double emax = 0.0;
    const size_t np = (size_t)SIZE * SIZE;
    for (size_t i = 0; i < np; i++) {
        if (lm.frame.vis[i] < 0.0f) { assert_int_equal(lmap[3 * i], 0); continue; }
        for (int c = 0; c < 3; c++) {
            emax = fmax(emax, lm.frame.rgb[3 * i + c]);
            assert_true(fabs(lmap[3 * i + c] / 255.0 * I - lm.frame.rgb[3 * i + c]) <= I / 510.0 * 1.0001);
        }
        for (int l = 0; l < 2; l++) assert_true(fabs(mask[4 * i + l] / 255.0 - lm.frame.shadow[l * np + i]) <= 1.0 / 510.0 + 1e-6);
        assert_int_equal(mask[4 * i + 2], 0);
        assert_int_equal(mask[4 * i + 3], 255);
    }
    assert_true(fabs(emax - I) <= 1e-6 * I);   /* scaled so that the largest texel is 1 */

    /* the ground's material: its factor and its texture's texels */
    int ground_mat = -1;
    for (int m = 0; tu_glb_item(&g, "materials", m); m++) {
        const cJSON *pbr = cJSON_GetObjectItem(tu_glb_item(&g, "materials", m), "pbrMetallicRoughness");
        const cJSON *bt = cJSON_GetObjectItem(pbr, "baseColorTexture");
        if (!bt) continue;
        ground_mat = m;
        const cJSON *f = cJSON_GetObjectItem(pbr, "baseColorFactor");
        const float want[4] = { 0.9f, 0.8f, 0.7f, 1.0f };
        for (int c = 0; c < 4; c++) assert_true(fabs(cJSON_GetArrayItem(f, c)->valuedouble - want[c]) < 1e-6);
        int tw, th;
        uint8_t *tx = tu_glb_texture(&g, geti(bt, "index"), 3, &tw, &th);
        assert_non_null(tx);
        uint8_t ref[48];
        checker(ref);
        assert_int_equal(tw, 4);
        assert_memory_equal(tx, ref, 48);
        free(tx);
    }
    assert_true(ground_mat >= 0);

    /* every primitive: triangles against the scene's, then random points against the oracle */
    ms_accel *acc;
    assert_int_equal(ms_accel_build(&sc, 0, &acc, err, sizeof err), MS_OK);
    uint8_t *seen = calloc(sc.n_tris, 1);
    tu_rng rng = { 12345 };
    long points = 0, prims = 0;
    double worst_q = 0.0, sum_at_p = 0.0, worst_at_p = 0.0;
    for (int mi = 0; tu_glb_item(&g, "meshes", mi); mi++) {
        const cJSON *prs = cJSON_GetObjectItem(tu_glb_item(&g, "meshes", mi), "primitives");
        for (int pi = 0; pi < cJSON_GetArraySize(prs); pi++) {
            const cJSON *pr = cJSON_GetArrayItem(prs, pi), *at = cJSON_GetObjectItem(pr, "attributes");
            size_t nv, nu, ni;
            int comps;
            float *pos = tu_glb_floats(&g, geti(at, "POSITION"), &nv, &comps);
            float *uv = tu_glb_floats(&g, geti(at, "TEXCOORD_1"), &nu, NULL);
            uint32_t *idx = tu_glb_indices(&g, geti(pr, "indices"), &ni);
            assert_non_null(pos);
            assert_non_null(uv);
            assert_non_null(idx);
            assert_int_equal(nu, nv);
            assert_true(ni % 3 == 0 && nv <= ni);   /* welded: never more vertices than corners */
            long here = 0;
            for (size_t k = 0; k < ni; k += 3) {
                float tp[9], tuv[6];
                for (int c = 0; c < 3; c++) {
                    assert_true(idx[k + c] < nv);
                    memcpy(tp + 3 * c, pos + 3 * idx[k + c], 3 * sizeof(float));
                    memcpy(tuv + 2 * c, uv + 2 * idx[k + c], 2 * sizeof(float));
                }
                const long t = find_tri(&sc, tp);
                assert_true(t >= 0);
                assert_int_equal(seen[t], 0);
                seen[t] = 1;
                assert_memory_equal(tuv, lm.uv + 6 * t, sizeof tuv);   /* TEXCOORD_1 = the UVs baked into */
                const double a[3][2] = { { tuv[0] * SIZE, tuv[1] * SIZE }, { tuv[2] * SIZE, tuv[3] * SIZE }, { tuv[4] * SIZE, tuv[5] * SIZE } };
                float nrm[3];
                {
                    const float e1[3] = { tp[3] - tp[0], tp[4] - tp[1], tp[5] - tp[2] }, e2[3] = { tp[6] - tp[0], tp[7] - tp[1], tp[8] - tp[2] };
                    nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
                    nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
                    nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
                    const float len = sqrtf(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
                    for (int d = 0; d < 3; d++) nrm[d] /= len;
                }
                for (int trial = 0; trial < 400 && here < 24; trial++) {
                    double b0 = (double)(tu_rng_next(&rng) >> 11) / 9007199254740992.0, b1 = (double)(tu_rng_next(&rng) >> 11) / 9007199254740992.0;
                    if (b0 + b1 > 1.0) { b0 = 1.0 - b0; b1 = 1.0 - b1; }
                    const double bw[3] = { 1.0 - b0 - b1, b0, b1 };
                    const double u = (bw[0] * tuv[0] + bw[1] * tuv[2] + bw[2] * tuv[4]), v = (bw[0] * tuv[1] + bw[1] * tuv[3] + bw[2] * tuv[5]);
                    const int x0 = (int)floor(u * SIZE - 0.5), y0 = (int)floor(v * SIZE - 0.5);
                    /* the four texel centres around (u, v), each strictly inside this triangle's UV image */
                    float cp[4][3];
                    int ok = x0 >= 0 && y0 >= 0 && x0 + 1 < SIZE && y0 + 1 < SIZE;
                    for (int j = 0; j < 4 && ok; j++) {
                        const double q[2] = { x0 + (j & 1) + 0.5, y0 + (j >> 1) + 0.5 };
                        double w[3];
                        bary2(a, q, w);
                        ok = w[0] > 1e-4 && w[1] > 1e-4 && w[2] > 1e-4;
                        for (int d = 0; d < 3; d++) cp[j][d] = (float)(w[0] * tp[d] + w[1] * tp[3 + d] + w[2] * tp[6 + d]);
                        const size_t ti = (size_t)(y0 + (j >> 1)) * SIZE + (size_t)(x0 + (j & 1));
                        if (ok) {
                            assert_int_equal(lm.triangle[ti], (uint32_t)t);
                            for (int d = 0; d < 3; d++) assert_true(fabsf(cp[j][d] - lm.position[3 * ti + d]) <= 1e-5f);
                        }
                    }
                    if (!ok) continue;
                    const double fx = u * SIZE - 0.5 - x0, fy = v * SIZE - 0.5 - y0;
                    float p[3];
                    for (int d = 0; d < 3; d++) p[d] = (float)(bw[0] * tp[d] + bw[1] * tp[3 + d] + bw[2] * tp[6 + d]);
                    for (int c = 0; c < 3; c++) {
                        double want = 0.0;
                        for (int j = 0; j < 4; j++)
                            want += ((j & 1) ? fx : 1 - fx) * ((j >> 1) ? fy : 1 - fy) *
                                    oracle(acc, &sc, cp[j], nrm, (uint32_t)t, (uint32_t)(x0 + (j & 1)), (uint32_t)(y0 + (j >> 1)), c);
                        const double got = bilinear(lmap, SIZE, SIZE, 3, c, u, v) / 255.0 * I;
                        worst_q = fmax(worst_q, fabs(got - want) / I);
                        assert_true(fabs(got - want) <= I / 510.0 * 1.001);
                        const double at_p = oracle(acc, &sc, p, nrm, (uint32_t)t, (uint32_t)floor(u * SIZE), (uint32_t)floor(v * SIZE), c);
                        sum_at_p += fabs(got - at_p) / I;
                        worst_at_p = fmax(worst_at_p, fabs(got - at_p) / I);
                    }
                    here++;
                    points++;
                }
            }
            assert_true(here > 0);   /* every primitive compared */
            prims++;
            free(pos);
            free(uv);
            free(idx);
        }
    }
    for (size_t t = 0; t < sc.n_tris; t++) assert_int_equal(seen[t], 1);
    printf("glb read back: %ld primitives, %ld points: lightmap vs the oracle at the texel centres, worst %.5f I "
           "(allowed I/510 = %.5f I); vs the oracle at the points themselves: mean %.5f I, worst %.5f I\n",
           prims, points, worst_q, 1.0 / 510.0, sum_at_p / (3.0 * (double)points), worst_at_p);
    assert_true(sum_at_p / (3.0 * (double)points) < 0.02);
    free(seen);
    ms_accel_free(acc);
    free(lmap);
    free(mask);
    tu_glb_free(&g);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

/* 1 when node and the validator are installed (viewer/node_modules); prints why not otherwise. */
static int have_validator(void)
{
    if (system("node --version > /dev/null 2>&1") != 0) { printf("skipped: node not found (scripts/install-deps.sh installs nodejs)\n"); return 0; }
    if (access(MS_VIEWER_DIR "/node_modules/gltf-validator/package.json", R_OK) != 0) {
        printf("skipped: " MS_VIEWER_DIR "/node_modules/gltf-validator absent (scripts/install-deps.sh runs npm install there)\n");
        return 0;
    }
    return 1;
}

static void test_validator(void **st)
{
    (void)st;
    if (!have_validator()) skip();
    const char *dir = tu_tmpdir("bake_gltf_validator");
    char json[1024], path[1024], err[512] = "";
    write_scene(dir, json, sizeof json);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_lightmap lm;
    bake(&sc, &lm);
    tu_path(path, sizeof path, dir, "valid.glb");
    assert_int_equal(ms_bake_write_gltf(&sc, &lm, NULL, path, err, sizeof err), MS_OK);
    char cmd[2600];
    /* the normal-mapped ground carries TANGENT: unit, orthogonal to its NORMAL, w = +-1 */
    tu_glb g;
    assert_int_equal(tu_glb_read(path, &g), 0);
    int tangents = 0;
    for (int m = 0; tu_glb_item(&g, "meshes", m); m++) {
        const cJSON *prims = cJSON_GetObjectItem(tu_glb_item(&g, "meshes", m), "primitives");
        for (int p = 0; p < cJSON_GetArraySize(prims); p++) {
            const cJSON *pr = cJSON_GetArrayItem(prims, p), *at = cJSON_GetObjectItem(pr, "attributes");
            const cJSON *mat = tu_glb_item(&g, "materials", geti(pr, "material"));
            const int has_nt = cJSON_GetObjectItem(mat, "normalTexture") != NULL;
            assert_int_equal(has_nt, geti(at, "TANGENT") >= 0);
            if (!has_nt) continue;
            size_t nt, nn;
            int ct, cn;
            float *t = tu_glb_floats(&g, geti(at, "TANGENT"), &nt, &ct), *n = tu_glb_floats(&g, geti(at, "NORMAL"), &nn, &cn);
            assert_true(t && n && ct == 4 && cn == 3 && nt == nn);
            for (size_t i = 0; i < nt; i++) {
                const float *a = t + 4 * i, *b = n + 3 * i;
                assert_true(fabs(sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) - 1.0) < 1e-5);
                assert_true(fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) < 1e-5);
                assert_true(a[3] == 1.0f || a[3] == -1.0f);
            }
            tangents += (int)nt;
            free(t);
            free(n);
        }
    }
    assert_true(tangents >= 3);
    tu_glb_free(&g);
    snprintf(cmd, sizeof cmd, "node '%s/validate.mjs' '%s' --max-warnings 0", MS_VIEWER_DIR, path);
    fflush(stdout);
    const int rc = system(cmd);
    assert_int_equal(rc, 0);   /* 0 errors, 0 warnings (the script prints the counts and every error and warning) */
    /* and the built-in scene, whose zero-area triangles are left out */
    ms_scene_free(&sc);
    ms_lightmap_free(&lm);
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_bake_options bo;
    tu_bake_options(&bo, 64, -1, 256);
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    tu_path(path, sizeof path, dir, "builtin.glb");
    assert_int_equal(ms_bake_write_gltf(&sc, &lm, NULL, path, err, sizeof err), MS_OK);
    snprintf(cmd, sizeof cmd, "node '%s/validate.mjs' '%s' --max-warnings 0", MS_VIEWER_DIR, path);
    fflush(stdout);
    assert_int_equal(system(cmd), 0);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

static void test_cli(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_gltf_cli");
    char json[1024], glb[1024], exr[1024], bad[1024], line[512];
    write_scene(dir, json, sizeof json);
    tu_path(glb, sizeof glb, dir, "cli.glb");
    tu_path(exr, sizeof exr, dir, "cli.exr");
    const char *args[] = { "bake", json, "--size", "64", "--samples", "256", "-o", exr, "--gltf", glb, "--quiet", NULL };
    assert_int_equal(tu_run_cli(args, line, sizeof line), 0);
    tu_glb g;
    assert_int_equal(tu_glb_read(glb, &g), 0);
    assert_non_null(tu_glb_item(&g, "meshes", 1));   /* the ground and the box */
    tu_glb_free(&g);
    /* a wrong ending: exit 2, one line naming it, nothing written */
    tu_path(bad, sizeof bad, dir, "bad.gltf");
    tu_path(exr, sizeof exr, dir, "bad.exr");
    const char *args2[] = { "bake", json, "--size", "64", "-o", exr, "--gltf", bad, "--quiet", NULL };
    assert_int_equal(tu_run_cli(args2, line, sizeof line), 2);
    assert_non_null(strstr(line, "bad.gltf"));
    assert_false(tu_file_exists(bad));
    assert_false(tu_file_exists(exr));
}

/* The warnings of one bake, kept for the test to read. */
static char g_warnings[8192];

static void keep_warning(void *user, const char *msg)
{
    (void)user;
    const size_t n = strlen(g_warnings);
    snprintf(g_warnings + n, sizeof g_warnings - n, "%s\n", msg);
}

/* The primitive whose extras.name is `name`: its extras.triangles and its material's name, or -1. */
static int unbaked_primitive(const tu_glb *g, const char *name, char *material, size_t n)
{
    for (int m = 0; tu_glb_item(g, "meshes", m); m++) {
        const cJSON *prims = cJSON_GetObjectItem(tu_glb_item(g, "meshes", m), "primitives");
        for (int p = 0; p < cJSON_GetArraySize(prims); p++) {
            const cJSON *pr = cJSON_GetArrayItem(prims, p), *ex = cJSON_GetObjectItem(pr, "extras");
            const cJSON *nm = cJSON_GetObjectItem(ex, "name");
            if (!cJSON_IsString(nm) || strcmp(nm->valuestring, name) != 0) continue;
            const cJSON *mn = cJSON_GetObjectItem(tu_glb_item(g, "materials", geti(pr, "material")), "name");
            snprintf(material, n, "%s", cJSON_IsString(mn) ? mn->valuestring : "");
            assert_int_equal(geti(pr, "TEXCOORD_1"), -1);
            return geti(ex, "triangles");
        }
    }
    return -1;
}

/* Every triangle baked or named: a ground, a crumb of area 2e-14 (below xatlas's FLT_EPSILON even after the
 * unwrap scales the scene's extent to about 1024 units: it charts it not), a triangle without area, a box with "lightmap": false. The bake warns once per reason with its
 * count (not for "lightmap": false, which it counts), the glb names the primitives and materials, and the
 * CLI says the same on stderr. */
static void test_unbaked_named(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_gltf_unbaked");
    char p[1024], json[1024], glb[1024], exr[1024], err[512] = "";
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "ground.obj"), "v -2 0 -2\nv -2 0 2\nv 2 0 2\nv 2 0 -2\nf 1 2 3 4\n"), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "bits.obj"),
        "v 0 0.5 0\nv 0.0000002 0.5 0\nv 0 0.5 0.0000002\nv 1 1 1\nv 1.5 1 1\nv 2 1 1\nf 1 2 3\nf 4 5 6\n"), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "box.obj"),
        "v 0.5 0 -0.5\nv 1.5 0 -0.5\nv 1.5 0 0.5\nv 0.5 0 0.5\nv 0.5 1 -0.5\nv 1.5 1 -0.5\nv 1.5 1 0.5\nv 0.5 1 0.5\n"
        "f 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n"), 0);
    assert_int_equal(tu_write_file(tu_path(json, sizeof json, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"ground.obj\"},{\"file\":\"bits.obj\"},{\"file\":\"box.obj\",\"lightmap\":false}],"
        "\"camera\":{\"eye\":[0,5,5],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":32,\"height\":32},"
        "\"light\":{\"corner\":[-0.5,4,-0.5],\"edge_s\":[1,0,0],\"edge_t\":[0,0,1],\"emission\":[1,1,1]}}"), 0);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_bake_options bo;
    tu_bake_options(&bo, 64, -1, 256);
    ms_lightmap lm;
    g_warnings[0] = 0;
    ms_set_warning_handler(keep_warning, NULL);
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    tu_path(glb, sizeof glb, dir, "unbaked.glb");
    assert_int_equal(ms_bake_write_gltf(&sc, &lm, NULL, glb, err, sizeof err), MS_OK);
    ms_set_warning_handler(NULL, NULL);
    printf("%s", g_warnings);
    assert_non_null(strstr(g_warnings, "1 triangle not baked: no UVs (xatlas leaves out triangles of area at most"));
    assert_non_null(strstr(g_warnings, "1 triangle not baked: no area"));
    assert_null(strstr(g_warnings, "lightmap false"));   /* asked for: counted, not warned about */
    assert_int_equal(lm.excluded_tris, 12);
    assert_int_equal(lm.unbaked_tris, 2);
    tu_glb g;
    assert_int_equal(tu_glb_read(glb, &g), 0);
    char mat[128];
    assert_int_equal(unbaked_primitive(&g, "not baked: no UVs", mat, sizeof mat), 1);
    assert_non_null(strstr(mat, "(not baked: no UVs)"));
    assert_int_equal(unbaked_primitive(&g, "not baked: lightmap false", mat, sizeof mat), 12);
    assert_non_null(strstr(mat, "(not baked: lightmap false)"));
    assert_int_equal(unbaked_primitive(&g, "not baked: no area", mat, sizeof mat), -1);   /* left out of the file */
    tu_glb_free(&g);
    /* the CLI: the same warnings and the count of "lightmap": false on the terminal */
    tu_path(exr, sizeof exr, dir, "cli.exr");
    const char *args[] = { "bake", json, "--uv", "xatlas", "--size", "64", "--samples", "256", "-o", exr, NULL };
    char all[8192];
    assert_int_equal(tu_run_cli_ex(args, NULL, all, sizeof all, NULL), 0);
    assert_non_null(strstr(all, "warning: 1 triangle not baked: no UVs"));
    assert_non_null(strstr(all, "warning: 1 triangle not baked: no area"));
    assert_non_null(strstr(all, "bake: 14 triangles not baked: 12 of meshes with \"lightmap\": false, 2 for the reasons warned about"));
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

static double num(const cJSON *o, const char *key, int i)
{
    const cJSON *v = cJSON_GetObjectItem(o, key);
    if (i >= 0) v = cJSON_GetArrayItem(v, i);
    assert_true(cJSON_IsNumber(v));
    return v->valuedouble;
}

/* The scene's lights in the glb (extras.microshadow.lights), for a viewer's live lights: every shape, in the scene's
 * order, in world coordinates although the scene lies 1e5 from the origin (so that it is loaded into a frame of its
 * own and the root node carries the origin), with their radiance ("power" converted: 40 W / (pi 4 m^2)); and the
 * scene's camera (extras.microshadow.camera), likewise in world coordinates. */
static void test_lights_listed(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_gltf_lights");
    char p[1024], json[1024], glb[1024], exr[1024], line[512];
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "ground.obj"),
        "v 99998 0 -2\nv 99998 0 2\nv 100002 0 2\nv 100002 0 -2\nf 1 2 3 4\n"), 0);
    assert_int_equal(tu_write_file(tu_path(json, sizeof json, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"ground.obj\"}],"
        "\"camera\":{\"eye\":[100000,6,6],\"target\":[100000,0,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":32,\"height\":32},\"lights\":["
        "{\"corner\":[99999,3,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2],\"power\":40},"
        "{\"shape\":\"disk\",\"center\":[100001,3,1],\"normal\":[0,-1,0],\"radius\":0.5,\"emission\":2},"
        "{\"shape\":\"sphere\",\"center\":[100000,2,0],\"radius\":0.25,\"emission\":[3,2,1]},"
        "{\"shape\":\"triangle\",\"vertices\":[[99999,2.5,1],[100000,2.5,1],[99999,2.5,2]],\"emission\":4},"
        "{\"shape\":\"sun\",\"direction\":[0,1,1],\"angular_diameter_deg\":2,\"emission\":100}]}"), 0);
    tu_path(glb, sizeof glb, dir, "lights.glb");
    tu_path(exr, sizeof exr, dir, "lights.exr");
    const char *args[] = { "bake", json, "--size", "32", "--samples", "256", "-o", exr, "--gltf", glb, "--quiet", NULL };
    assert_int_equal(tu_run_cli(args, line, sizeof line), 0);
    tu_glb g;
    assert_int_equal(tu_glb_read(glb, &g), 0);
    assert_true(fabs(num(tu_glb_item(&g, "nodes", 0), "translation", 0)) > 1e4);   /* the root carries the origin */
    const cJSON *L = cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(tu_glb_item(&g, "scenes", 0), "extras"),
                                                              "microshadow"), "lights");
    assert_int_equal(cJSON_GetArraySize(L), 5);
    static const char *const shape[5] = { "rect", "disk", "sphere", "triangle", "sun" };
    static const double radiance[5] = { 40.0 / (M_PI * 4.0), 2, 3, 4, 100 };
    for (int i = 0; i < 5; i++) {
        const cJSON *l = cJSON_GetArrayItem(L, i);
        assert_string_equal(cJSON_GetObjectItem(l, "shape")->valuestring, shape[i]);
        assert_true(fabs(num(l, "radiance", 0) - radiance[i]) < 1e-5 * radiance[i]);
    }
    const double tol = 1e-4;
    const cJSON *r = cJSON_GetArrayItem(L, 0), *d = cJSON_GetArrayItem(L, 1), *sp = cJSON_GetArrayItem(L, 2);
    const cJSON *tr = cJSON_GetArrayItem(L, 3), *sun = cJSON_GetArrayItem(L, 4);
    const double rc[3] = { 99999, 3, -1 }, re[3] = { 2, 0, 0 }, dc[3] = { 100001, 3, 1 }, sc[3] = { 100000, 2, 0 };
    const double ta[3] = { 99999, 2.5, 1 }, tb[3] = { 1, 0, 0 }, tc[3] = { 0, 0, 1 };
    for (int c = 0; c < 3; c++) {
        assert_true(fabs(num(r, "corner", c) - rc[c]) < tol);
        assert_true(fabs(num(r, "edge_s", c) - re[c]) < tol);
        /* the disk as its bounding square: its centre the disk's, its edges 2 r */
        assert_true(fabs(num(d, "corner", c) + 0.5 * (num(d, "edge_s", c) + num(d, "edge_t", c)) - dc[c]) < tol);
        assert_true(fabs(num(sp, "center", c) - sc[c]) < tol);
        assert_true(fabs(num(tr, "corner", c) - ta[c]) < tol);
        assert_true(fabs(num(tr, "edge_s", c) - tb[c]) < tol);
        assert_true(fabs(num(tr, "edge_t", c) - tc[c]) < tol);
        assert_true(fabs(num(sun, "direction", c) - (c ? M_SQRT1_2 : 0.0)) < 1e-6);
    }
    assert_true(fabs(hypot(hypot(num(d, "edge_s", 0), num(d, "edge_s", 1)), num(d, "edge_s", 2)) - 1.0) < tol);
    assert_true(fabs(num(sp, "radius", -1) - 0.25) < 1e-7);
    assert_true(fabs(num(sun, "angular_diameter_deg", -1) - 2.0) < 1e-4);
    /* the scene's camera beside them, in world coordinates too */
    const cJSON *cam = cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(tu_glb_item(&g, "scenes", 0), "extras"),
                                                                "microshadow"), "camera");
    const double eye[3] = { 100000, 6, 6 }, target[3] = { 100000, 0, 0 }, up[3] = { 0, 1, 0 };
    for (int c = 0; c < 3; c++) {
        assert_true(fabs(num(cam, "eye", c) - eye[c]) < tol);
        assert_true(fabs(num(cam, "target", c) - target[c]) < tol);
        assert_true(fabs(num(cam, "up", c) - up[c]) < 1e-7);
    }
    assert_true(num(cam, "fov_y", -1) == 50.0 && num(cam, "width", -1) == 32.0 && num(cam, "height", -1) == 32.0);
    tu_glb_free(&g);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_glb_reads_back),
        cmocka_unit_test(test_unbaked_named),
        cmocka_unit_test(test_validator),
        cmocka_unit_test(test_cli),
        cmocka_unit_test(test_lights_listed),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
