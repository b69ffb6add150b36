/* Materials, textures and normals in whole frames (docs/shading.md) against independent oracles (the GGX and
 * S_spec oracles: test_shading.c):
 *   - a glTF scene written here (two materials, a PNG base-colour texture): shaded colours at chosen
 *     pixels against values computed by hand from the material factors and the texel;
 *   - smooth shading normals change the colours but not V or S;
 *   - OBJ/MTL materials; the CLI's EXR output and exposure;
 *   - hostile textures and materials: one-line errors. */
#include "testutil.h"
#include "render/ltc.h"
#include "render/shade.h"
#include "visibility/receiver.h"
#include "light/pattern.h"
#include "camera/camera.h"
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- A glTF scene written here ---- */

static uint32_t crc32_of(const uint8_t *b, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= b[i];
        for (int k = 0; k < 8; k++) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    }
    return ~c;
}

static void put32(uint8_t *p, uint32_t v) { p[0] = (uint8_t)(v >> 24); p[1] = (uint8_t)(v >> 16); p[2] = (uint8_t)(v >> 8); p[3] = (uint8_t)v; }

/* An RGBA8 PNG of w x h texels (w * h <= 8), its deflate stream one stored block (no compression). */
static size_t tiny_png(const uint8_t *rgba, int w, int h, uint8_t *out)
{
    static const uint8_t sig[8] = { 137, 80, 78, 71, 13, 10, 26, 10 };
    size_t n = 0;
    memcpy(out, sig, 8);
    n = 8;
    uint8_t ihdr[13];
    put32(ihdr, (uint32_t)w);
    put32(ihdr + 4, (uint32_t)h);
    ihdr[8] = 8; ihdr[9] = 6; ihdr[10] = ihdr[11] = ihdr[12] = 0;
    uint8_t raw[8 + 32];
    size_t rl = 0;
    for (int y = 0; y < h; y++) {
        raw[rl++] = 0;   /* filter: none */
        memcpy(raw + rl, rgba + (size_t)4 * w * y, (size_t)4 * w);
        rl += (size_t)4 * w;
    }
    uint8_t z[64];
    size_t zn = 0;
    z[zn++] = 0x78; z[zn++] = 0x01;
    z[zn++] = 1;   /* final stored block */
    z[zn++] = (uint8_t)rl; z[zn++] = (uint8_t)(rl >> 8); z[zn++] = (uint8_t)~rl; z[zn++] = (uint8_t)(~rl >> 8);
    memcpy(z + zn, raw, rl);
    zn += rl;
    uint32_t a = 1, b = 0;
    for (size_t i = 0; i < rl; i++) { a = (a + raw[i]) % 65521; b = (b + a) % 65521; }
    put32(z + zn, (b << 16) | a);
    zn += 4;
    const struct { const char *type; const uint8_t *data; size_t len; } chunks[3] = {
        { "IHDR", ihdr, 13 }, { "IDAT", z, zn }, { "IEND", NULL, 0 } };
    for (int c = 0; c < 3; c++) {
        put32(out + n, (uint32_t)chunks[c].len);
        memcpy(out + n + 4, chunks[c].type, 4);
        if (chunks[c].len) memcpy(out + n + 8, chunks[c].data, chunks[c].len);
        put32(out + n + 8 + chunks[c].len, crc32_of(out + n + 4, 4 + chunks[c].len));
        n += 12 + chunks[c].len;
    }
    return n;
}


/* The texture: two texels, A on the left, B on the right (sRGB). */
static const uint8_t TEX_A[4] = { 200, 100, 50, 255 }, TEX_B[4] = { 10, 240, 90, 255 };
/* Materials: 0 matte orange, factor only; 1 half metal, its base colour the texture. */
static const float MAT0_BASE[3] = { 0.8f, 0.3f, 0.1f }, MAT0_METAL = 0.0f, MAT0_ROUGH = 0.9f;
static const float MAT1_METAL = 0.5f, MAT1_ROUGH = 0.5f;

/* Writes dir/scene.json, dir/scene.gltf (buffers base64-embedded) and dir/tex.png. The ground y = 0 is two
 * quads: x in [-2, 0] material 0, x in [0, 2] material 1 with u = 0.25 + 0.25 x, v = 0.5 (so the base colour
 * runs from texel A's centre at x = 0 to texel B's at x = 2). occluder: a quad at y = 1.2 over the middle.
 * tilt: NORMAL attributes leaning towards +x (0 none). image: the PNG's bytes (NULL: the tiny texture). */
static int g_image_mode;   /* the glTF's image: 0 the file tex.png, 1 a base64 data: URI, 2 a bufferView */

static void write_gltf_scene(const char *dir, int occluder, float tilt, const uint8_t *image, size_t image_len)
{
    enum { MAXV = 18 };
    float pos[MAXV][3], uv[MAXV][2], nrm[MAXV][3];
    const float quads[3][4] = { { -2, 0, -2, 2 }, { 0, 2, -2, 2 }, { -0.4f, 0.4f, -0.4f, 0.4f } };   /* x0 x1 z0 z1 */
    const int nq = occluder ? 3 : 2;
    int nv = 0;
    for (int q = 0; q < nq; q++) {
        const float y = q == 2 ? 1.2f : 0.0f;
        /* Two triangles wound so that the normal is +y: (x0,z1) (x1,z1) (x1,z0) and (x0,z1) (x1,z0) (x0,z0). */
        const float cx[6] = { quads[q][0], quads[q][1], quads[q][1], quads[q][0], quads[q][1], quads[q][0] };
        const float cz[6] = { quads[q][3], quads[q][3], quads[q][2], quads[q][3], quads[q][2], quads[q][2] };
        for (int i = 0; i < 6; i++, nv++) {
            pos[nv][0] = cx[i]; pos[nv][1] = y; pos[nv][2] = cz[i];
            uv[nv][0] = 0.25f + 0.25f * cx[i]; uv[nv][1] = 0.5f;
            float nn[3] = { tilt, 1.0f, 0.0f }, l = sqrtf(tilt * tilt + 1.0f);
            for (int c = 0; c < 3; c++) nrm[nv][c] = nn[c] / l;
        }
    }
    char path[512];
    uint8_t png[256];
    size_t pl;
    if (image) { memcpy(png, image, image_len < sizeof png ? image_len : sizeof png); pl = image_len < sizeof png ? image_len : sizeof png; }
    else {
        uint8_t texels[8];
        memcpy(texels, TEX_A, 4);
        memcpy(texels + 4, TEX_B, 4);
        pl = tiny_png(texels, 2, 1, png);
    }
    uint8_t buf[MAXV * 8 * 4 + 256];
    size_t bl = 0;
    memcpy(buf, pos, (size_t)nv * 12); bl += (size_t)nv * 12;
    memcpy(buf + bl, uv, (size_t)nv * 8); bl += (size_t)nv * 8;
    memcpy(buf + bl, nrm, (size_t)nv * 12); bl += (size_t)nv * 12;
    const size_t png_at = bl;
    memcpy(buf + bl, png, pl);   /* bufferView 3 (used by image mode 2) */
    bl += pl;
    char b64[sizeof buf * 2];
    tu_base64(buf, bl, b64);
    char images[1024], png64[512];
    tu_base64(png, pl, png64);
    if (g_image_mode == 0) snprintf(images, sizeof images, "[{\"uri\":\"tex.png\"}]");
    else if (g_image_mode == 1) snprintf(images, sizeof images, "[{\"uri\":\"data:image/png;base64,%s\"}]", png64);
    else snprintf(images, sizeof images, "[{\"bufferView\":3,\"mimeType\":\"image/png\"}]");
    FILE *f = fopen(tu_path(path, sizeof path, dir, "tex.png"), "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(png, 1, pl, f), pl);
    fclose(f);
    /* Accessors per quad q: POSITION 3q, TEXCOORD_0 3q+1, NORMAL 3q+2; views: positions, uvs, normals. */
    char acc[4096] = "", prims[2048] = "";
    size_t al = 0, pl2 = 0;
    for (int q = 0; q < nq; q++) {
        const float y = q == 2 ? 1.2f : 0.0f;
        al += (size_t)snprintf(acc + al, sizeof acc - al,
            "%s{\"bufferView\":0,\"byteOffset\":%d,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\",\"min\":[%g,%g,%g],\"max\":[%g,%g,%g]},"
            "{\"bufferView\":1,\"byteOffset\":%d,\"componentType\":5126,\"count\":6,\"type\":\"VEC2\"},"
            "{\"bufferView\":2,\"byteOffset\":%d,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"}",
            q ? "," : "", q * 72, quads[q][0], y, quads[q][2], quads[q][1], y, quads[q][3], q * 48, q * 72);
        pl2 += (size_t)snprintf(prims + pl2, sizeof prims - pl2,
            "%s{\"attributes\":{\"POSITION\":%d,\"TEXCOORD_0\":%d%s},\"material\":%d}", q ? "," : "", 3 * q, 3 * q + 1,
            tilt != 0.0f ? (q == 0 ? ",\"NORMAL\":2" : q == 1 ? ",\"NORMAL\":5" : ",\"NORMAL\":8") : "", q == 1 ? 1 : 0);
    }
    static char gl[16384];
    snprintf(gl, sizeof gl,
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"primitives\":[%s]}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[%g,%g,%g,1],\"metallicFactor\":%g,\"roughnessFactor\":%g}},"
        "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0},\"metallicFactor\":%g,\"roughnessFactor\":%g}}],"
        "\"textures\":[{\"source\":0}],\"images\":%s,"
        "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%d},{\"buffer\":0,\"byteOffset\":%d,\"byteLength\":%d},"
        "{\"buffer\":0,\"byteOffset\":%d,\"byteLength\":%d},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
        "\"accessors\":[%s]}",
        prims, MAT0_BASE[0], MAT0_BASE[1], MAT0_BASE[2], MAT0_METAL, MAT0_ROUGH, MAT1_METAL, MAT1_ROUGH, images, bl, b64,
        nv * 12, nv * 12, nv * 8, nv * 20, nv * 12, png_at, pl, acc);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "scene.gltf"), gl), 0);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"scene.gltf\"}],"
        "\"camera\":{\"eye\":[0,4,4],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":48,\"height\":48},"
        "\"light\":{\"corner\":[-1,3,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2],\"emission\":[3,3,3]},"
        "\"render\":{\"samples\":256}}"), 0);
}

static double srgb_lin(uint8_t c)
{
    double x = c / 255.0;
    return x <= 0.04045 ? x / 12.92 : pow((x + 0.055) / 1.055, 2.4);
}

static int load_and_render(const char *dir, ms_scene *sc, ms_frame *fr, const char *method)
{
    char path[512], err[512];
    if (ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), sc, err, sizeof err)) {
        printf("load: %s\n", err);
        return -1;
    }
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.threads = 2;
    if (ms_render(sc, &o, fr, err, sizeof err)) { printf("render: %s\n", err); ms_scene_free(sc); return -1; }
    return 0;
}

/* Two materials and a texture: every pixel that sees the ground well inside one quad, against the colour
 * computed here from the material factors and the decoded texels. No occluder: V = S = S_spec = 1, so the
 * expectation is emission * (c_diff/pi * E + F * LTC) with E = ms_light_irradiance (test_irradiance) and
 * LTC = ms_ltc_ggx (above): what is checked is the material path (factors, metallic mix, Fresnel, the
 * texture's decoding, sRGB, UVs and bilinear lookup). */
static void test_gltf_materials(void **st)
{
    (void)st;
  for (g_image_mode = 0; g_image_mode < 3; g_image_mode++) {
    const char *dir = tu_tmpdir("shading_gltf");
    write_gltf_scene(dir, 0, 0.0f, NULL, 0);
    if (g_image_mode) {   /* the image must come from inside the glTF, not the file */
        char tp[512];
        assert_int_equal(unlink(tu_path(tp, sizeof tp, dir, "tex.png")), 0);
    }
    ms_scene sc;
    ms_frame fr;
    assert_int_equal(load_and_render(dir, &sc, &fr, NULL), 0);
    assert_int_equal((int)sc.n_materials, 2);
    assert_int_equal((int)sc.n_textures, 1);
    ms_camera_basis cb;
    assert_int_equal(ms_camera_basis_init(&cb, &sc.camera, fr.width, fr.height), 0);
    int checked[2] = { 0, 0 };
    double worst = 0;
    for (int y = 0; y < fr.height; y++)
        for (int x = 0; x < fr.width; x++) {
            float o[3], d[3];
            ms_camera_ray(&cb, x, y, o, d);
            if (!(d[1] < 0)) continue;
            const double t = -cb.eye[1] / d[1];
            const float p[3] = { (float)(cb.eye[0] + t * d[0]), 0.0f, (float)(cb.eye[2] + t * d[2]) };
            if (fabsf(p[0]) < 0.1f || fabsf(p[0]) > 1.9f || fabsf(p[2]) > 1.9f) continue;   /* near an edge */
            const size_t i = (size_t)y * fr.width + x;
            assert_true(fr.vis[i] == 1.0f && fr.shadow[i] == 1.0f && fr.shadow_spec[i] == 1.0f);
            const int m = p[0] > 0;
            double base[3], metal = m ? MAT1_METAL : MAT0_METAL, rough = m ? MAT1_ROUGH : MAT0_ROUGH;
            for (int c = 0; c < 3; c++) {
                if (!m) base[c] = MAT0_BASE[c];
                else {
                    const double fx = 0.5 * p[0];   /* u*2 - 0.5 with u = 0.25 + 0.25 x */
                    base[c] = (1 - fx) * srgb_lin(TEX_A[c]) + fx * srgb_lin(TEX_B[c]);
                }
            }
            double v[3] = { cb.eye[0] - p[0], cb.eye[1] - p[1], cb.eye[2] - p[2] };
            tu_unit3(v);
            const float n[3] = { 0, 1, 0 }, vf[3] = { (float)v[0], (float)v[1], (float)v[2] };
            const double E = ms_light_irradiance(&sc.light, p, n);
            const double ltc = ms_ltc_ggx(&sc.light, p, n, vf, (float)rough);
            const double c5 = pow(1 - v[1], 5);
            for (int c = 0; c < 3; c++) {
                const double f0 = 0.04 * (1 - metal) + base[c] * metal;
                const double want = 3.0 * (base[c] * (1 - metal) / M_PI * E + (f0 + (1 - f0) * c5) * ltc);
                const double rel = fabs(fr.rgb[3 * i + c] - want) / want;
                if (rel > worst) worst = rel;
                if (rel > 2e-3) printf("pixel (%d,%d) channel %d: %g, want %g\n", x, y, c, fr.rgb[3 * i + c], want);
                assert_true(rel <= 2e-3);
            }
            checked[m]++;
        }
    printf("glTF materials (image from %s): %d pixels of material 0, %d of material 1 (textured) match, worst relative "
           "error %.2g\n", g_image_mode == 0 ? "a file" : g_image_mode == 1 ? "a data URI" : "a bufferView", checked[0],
           checked[1], worst);
    assert_true(checked[0] > 50 && checked[1] > 50);
    ms_frame_free(&fr);
    ms_scene_free(&sc);
  }
  g_image_mode = 0;
}

/* Smooth normals: tilted NORMALs change the colours but not V, S (visibility stays geometric), for a
 * ray tracer and a micro-raster method; and with an occluder, S_spec resolves penumbrae. */
static void test_normals_change_shading_not_visibility(void **st)
{
    (void)st;
    const char *methods[2] = { "raytrace", "scanline" };
    for (int mi = 0; mi < 2; mi++) {
        const char *dir = tu_tmpdir(mi ? "shading_normals_s" : "shading_normals_r");
        ms_scene a, b;
        ms_frame fa, fb;
        write_gltf_scene(dir, 1, 0.0f, NULL, 0);
        assert_int_equal(load_and_render(dir, &a, &fa, methods[mi]), 0);
        write_gltf_scene(dir, 1, 0.6f, NULL, 0);
        assert_int_equal(load_and_render(dir, &b, &fb, methods[mi]), 0);
        assert_null(a.tri_normal);
        assert_non_null(b.tri_normal);
        const size_t np = (size_t)fa.width * fa.height;
        size_t changed = 0, penumbra = 0, spec_differs = 0, visible = 0;
        for (size_t i = 0; i < np; i++) {
            assert_true(fa.vis[i] == fb.vis[i]);
            assert_true(fa.shadow[i] == fb.shadow[i]);
            assert_true(fa.front[i] == fb.front[i]);
            if (fa.vis[i] < 0) continue;
            visible++;
            if (fabsf(fa.rgb[3 * i] - fb.rgb[3 * i]) > 1e-3f * fa.rgb[3 * i]) changed++;
            if (fa.vis[i] > 0 && fa.vis[i] < 1) {
                penumbra++;
                if (fabsf(fa.shadow_spec[i] - fa.shadow[i]) > 0.01f) spec_differs++;
            }
        }
        printf("%s: %zu of %zu visible pixels change colour with tilted normals, V and S identical; %zu penumbra pixels, "
               "%zu with S_spec off S by more than 0.01\n", methods[mi], changed, visible, penumbra, spec_differs);
        assert_true(changed > visible * 9 / 10);
        assert_true(penumbra > 20 && spec_differs > 0);
        ms_frame_free(&fa);
        ms_frame_free(&fb);
        ms_scene_free(&a);
        ms_scene_free(&b);
    }
}

static char g_warning[2048];
static int g_warnings;
static char g_first_warning[1024];

static void catch_warning(void *user, const char *msg)
{
    (void)user;
    snprintf(g_warning, sizeof g_warning, "%s", msg);
    if (!g_warnings) snprintf(g_first_warning, sizeof g_first_warning, "%s", msg);
    g_warnings++;
}

/* Textures that cannot be used (JPEG, not a PNG, too large, truncated): one warning line naming the file
 * and the problem, the scene loads with the material's factors (no crash, bounded memory). */
static void test_bad_textures(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("shading_bad_tex");
    static const uint8_t jpeg[16] = { 0xFF, 0xD8, 0xFF, 0xE0, 0, 16, 'J', 'F', 'I', 'F', 0 };
    uint8_t big[128];
    const uint8_t one[4] = { 1, 2, 3, 4 };
    size_t bn = tiny_png(one, 1, 1, big);
    put32(big + 16, 20000);   /* IHDR width past the texture limit, with its CRC made right again */
    put32(big + 29, crc32_of(big + 12, 17));
    uint8_t cut[128];
    size_t cn = tiny_png(one, 1, 1, cut) - 20;   /* ends inside IDAT */
    const struct { const uint8_t *b; size_t n; const char *needle; } cases[4] = {
        { jpeg, sizeof jpeg, "bad JPEG" },
        { (const uint8_t *)"not an image at all", 19, "not a PNG, JPEG, WebP or KTX2 image" },
        { big, bn, "a 20000x1 texture (at most 16384 a side)" },
        { cut, cn, "bad PNG" },
    };
    ms_set_warning_handler(catch_warning, NULL);
    for (int c = 0; c < 4; c++) {
        write_gltf_scene(dir, 0, 0.0f, cases[c].b, cases[c].n);
        ms_scene sc;
        char path[512], err[512];
        g_warnings = 0;
        assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), &sc, err, sizeof err), 0);
        printf("warning: %s\n", g_warning);
        assert_int_equal(g_warnings, 1);
        assert_non_null(strstr(g_warning, "tex.png: "));   /* the image file is named */
        assert_non_null(strstr(g_warning, cases[c].needle));
        assert_non_null(strstr(g_warning, "texture ignored"));
        assert_null(strchr(g_warning, '\n'));
        assert_int_equal((int)sc.n_materials, 2);
        assert_int_equal((int)sc.n_textures, 0);
        assert_int_equal(sc.materials[1].base_color_texture, -1);
        ms_scene_free(&sc);
    }
    ms_set_warning_handler(NULL, NULL);
}

/* OBJ + MTL through assimp: usemtl names map to the MTL's materials (Kd, Pm, Pr; Ns when there is no Pr),
 * map_Kd a PNG whose v runs bottom-up (OBJ's convention); vertex normals vn shade. Same scene and checks as
 * the glTF test, with the expectations computed here. */
static void test_obj_mtl_materials(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("shading_obj");
    char path[512];
    /* 1 x 2 texture: top row A, bottom row B; v = 0.25 at every vertex is the bottom row's centre: B. */
    uint8_t texels[8], png[256];
    memcpy(texels, TEX_A, 4);
    memcpy(texels + 4, TEX_B, 4);
    const size_t pl = tiny_png(texels, 1, 2, png);
    FILE *f = fopen(tu_path(path, sizeof path, dir, "wall.png"), "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(png, 1, pl, f), pl);
    fclose(f);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "m.mtl"),
        "# two materials\nnewmtl matte\nKd 0.8 0.3 0.1\nNs 10\n\nnewmtl textured\nKd 1 1 1\nPm 0.5\nPr 0.5\n"
        "map_Kd -bm 1 wall.png\n"), 0);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "m.obj"),
        "mtllib m.mtl\n"
        "v -2 0 -2\nv 0 0 -2\nv 2 0 -2\nv -2 0 2\nv 0 0 2\nv 2 0 2\n"
        "vt 0.5 0.25\nvn 0 1 0\n"
        "usemtl matte\nf 4/1/1 5/1/1 2/1/1\nf 4/1/1 2/1/1 1/1/1\n"
        "usemtl textured\nf 5/1/1 6/1/1 3/1/1\nf 5/1/1 3/1/1 2/1/1\n"), 0);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"m.obj\"}],"
        "\"camera\":{\"eye\":[0,4,4],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":48,\"height\":48},"
        "\"light\":{\"corner\":[-1,3,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2],\"emission\":[3,3,3]},"
        "\"render\":{\"samples\":256}}"), 0);
    ms_scene sc;
    ms_frame fr;
    assert_int_equal(load_and_render(dir, &sc, &fr, NULL), 0);
    assert_int_equal((int)sc.n_materials, 2);
    assert_int_equal((int)sc.n_textures, 1);
    assert_non_null(sc.tri_normal);
    ms_camera_basis cb;
    assert_int_equal(ms_camera_basis_init(&cb, &sc.camera, fr.width, fr.height), 0);
    const double rough0 = sqrt(sqrt(2.0 / (10 + 2)));   /* Ns 10: alpha = sqrt(2 / (Ns + 2)) */
    int checked[2] = { 0, 0 };
    for (int y = 0; y < fr.height; y++)
        for (int x = 0; x < fr.width; x++) {
            float o[3], d[3];
            ms_camera_ray(&cb, x, y, o, d);
            if (!(d[1] < 0)) continue;
            const double t = -cb.eye[1] / d[1];
            const float p[3] = { (float)(cb.eye[0] + t * d[0]), 0.0f, (float)(cb.eye[2] + t * d[2]) };
            if (fabsf(p[0]) < 0.1f || fabsf(p[0]) > 1.9f || fabsf(p[2]) > 1.9f) continue;
            const size_t i = (size_t)y * fr.width + x;
            const int m = p[0] > 0;
            double base[3], metal = m ? 0.5 : 0.0, rough = m ? 0.5 : rough0;
            for (int c = 0; c < 3; c++) base[c] = m ? srgb_lin(TEX_B[c]) : MAT0_BASE[c];
            double v[3] = { cb.eye[0] - p[0], cb.eye[1] - p[1], cb.eye[2] - p[2] };
            tu_unit3(v);
            const float n[3] = { 0, 1, 0 }, vf[3] = { (float)v[0], (float)v[1], (float)v[2] };
            const double E = ms_light_irradiance(&sc.light, p, n), ltc = ms_ltc_ggx(&sc.light, p, n, vf, (float)rough);
            const double c5 = pow(1 - v[1], 5);
            for (int c = 0; c < 3; c++) {
                const double f0 = 0.04 * (1 - metal) + base[c] * metal;
                const double want = 3.0 * (base[c] * (1 - metal) / M_PI * E + (f0 + (1 - f0) * c5) * ltc);
                if (fabs(fr.rgb[3 * i + c] - want) > 2e-3 * want) printf("pixel (%d,%d) channel %d: %g, want %g\n", x, y, c, fr.rgb[3 * i + c], want);
                assert_true(fabs(fr.rgb[3 * i + c] - want) <= 2e-3 * want);
            }
            checked[m]++;
        }
    printf("OBJ/MTL materials: %d pixels of 'matte', %d of 'textured' match\n", checked[0], checked[1]);
    assert_true(checked[0] > 50 && checked[1] > 50);
    ms_frame_free(&fr);
    ms_scene_free(&sc);
}

/* Mean sRGB byte of a PNG (libpng's simplified reader), -1 if it cannot be read. */
static double png_mean(const char *path)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path)) return -1;
    img.format = PNG_FORMAT_RGB;
    uint8_t *px = malloc(PNG_IMAGE_SIZE(img));
    if (!px || !png_image_finish_read(&img, NULL, px, 0, NULL)) { free(px); png_image_free(&img); return -1; }
    double sum = 0;
    for (size_t i = 0; i < PNG_IMAGE_SIZE(img); i++) sum += px[i];
    const double mean = sum / PNG_IMAGE_SIZE(img);
    free(px);
    return mean;
}

/* The CLI: -o OUT.exr writes the linear radiance as EXR (channels R, G, B, V, S), -o OUT.png stays
 * tone-mapped, and --exposure EV brightens it; a bad --exposure is one line and exit 2. */
static void test_cli_exr_and_exposure(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("shading_cli");
    write_gltf_scene(dir, 1, 0.0f, NULL, 0);
    char scene[512], exr[512], a[512], b[512], err[1024];
    tu_path(scene, sizeof scene, dir, "scene.json");
    const char *x[] = { scene, "--quiet", "-o", tu_path(exr, sizeof exr, dir, "out.exr"), NULL };
    assert_int_equal(tu_run_cli(x, err, sizeof err), 0);
    FILE *f = fopen(exr, "rb");
    assert_non_null(f);
    uint8_t head[512];
    const size_t n = fread(head, 1, sizeof head, f);
    fclose(f);
    static const uint8_t magic[4] = { 0x76, 0x2f, 0x31, 0x01 };
    assert_true(n > 64 && !memcmp(head, magic, 4));
    /* The channel list: names NUL-terminated, then 16 bytes each (pixel type 2 = FLOAT first). */
    const char *names[5] = { "B", "G", "R", "S", "V" };
    for (int c = 0; c < 5; c++) {
        int found = 0;
        for (size_t i = 1; i + 6 < n && !found; i++)
            found = head[i - 1] == 0 && head[i] == (uint8_t)names[c][0] && head[i + 1] == 0 && head[i + 2] == 2;
        assert_true(found);
    }
    const char *pa[] = { scene, "--quiet", "-o", tu_path(a, sizeof a, dir, "a.png"), NULL };
    const char *pb[] = { scene, "--quiet", "--exposure", "1.5", "-o", tu_path(b, sizeof b, dir, "b.png"), NULL };
    assert_int_equal(tu_run_cli(pa, err, sizeof err), 0);
    assert_int_equal(tu_run_cli(pb, err, sizeof err), 0);
    const double ma = png_mean(a), mb = png_mean(b);
    printf("PNG mean byte: exposure 0 %.2f, +1.5 EV %.2f\n", ma, mb);
    assert_true(ma > 0 && mb > ma + 5);
    const char *bad[] = { scene, "--quiet", "--exposure", "bright", "-o", tu_path(b, sizeof b, dir, "c.png"), NULL };
    assert_int_equal(tu_run_cli(bad, err, sizeof err), 2);
    assert_non_null(strstr(err, "--exposure"));
}

/* Hostile MTL input: an mtllib and a map_Kd that are FIFOs (never opened for a blocking read), a
 * directory, junk numbers; the scene loads with warnings, each one line. (Absolute paths and paths leading
 * out of the folder are errors: tests/test_asset_paths.c.) */
static void test_hostile_mtl(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("shading_hostile_mtl");
    char path[512], fifo1[512], fifo2[512];
    unlink(tu_path(fifo1, sizeof fifo1, dir, "fifo.mtl"));
    unlink(tu_path(fifo2, sizeof fifo2, dir, "fifo.png"));
    assert_int_equal(mkfifo(fifo1, 0600), 0);
    assert_int_equal(mkfifo(fifo2, 0600), 0);
    mkdir(tu_path(path, sizeof path, dir, "adir.png"), 0700);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "ok.mtl"),
        "Kd 1 1 1\nnewmtl a\nKd nan inf -3\nPm 1e39\nPr -inf\nmap_Kd fifo.png\nnewmtl b\nmap_Kd adir.png\n"
        "newmtl c\nmap_Kd nosuch.png\nnewmtl d\nmap_Kd\nNs -5\n"), 0);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "m.obj"),
        "mtllib fifo.mtl\nmtllib ok.mtl\nmtllib nosuch.mtl\nmtllib\n"
        "v 0 0 0\nv 1 0 0\nv 0 0 1\nusemtl a\nf 1 3 2\nusemtl b\nf 1 3 2\nusemtl nosuch\nf 1 3 2\nusemtl d\nf 1 3 2\n"), 0);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"m.obj\"}],"
        "\"camera\":{\"eye\":[0,4,4],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":16,\"height\":16},"
        "\"light\":{\"corner\":[-1,3,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2]}}"), 0);
    ms_set_warning_handler(catch_warning, NULL);
    /* verbose: one warning per unusable file; then the default: one line with their number and the first */
    ms_set_warning_verbose(1);
    g_warnings = 0;
    g_first_warning[0] = 0;
    ms_scene sc;
    char err[512];
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), &sc, err, sizeof err), 0);
    ms_scene_free(&sc);
    const int each = g_warnings;
    char first[1024];
    snprintf(first, sizeof first, "%s", g_first_warning);
    printf("%d warnings, the first: %s\n", each, first);
    assert_true(each >= 5);   /* fifo.mtl, nosuch.mtl, fifo.png, adir.png, nosuch.png */
    ms_set_warning_verbose(0);
    g_warnings = 0;
    assert_int_equal(ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), &sc, err, sizeof err), 0);
    ms_set_warning_handler(NULL, NULL);
    printf("summary: %s\n", g_warning);
    assert_int_equal(g_warnings, 1);
    char want[1400];
    snprintf(want, sizeof want, "%d material files, textures or glTF features could not be used", each);
    assert_non_null(strstr(g_warning, want));
    snprintf(want, sizeof want, "(first: %s)", first);
    assert_non_null(strstr(g_warning, want));
    /* the CLI: one warning line; --verbose every one */
    char out_png[512], errs[8192];
    const char *quiet_args[] = { path, "--quiet", "-o", tu_path(out_png, sizeof out_png, dir, "w.png"), NULL };
    const char *verbose_args[] = { path, "--quiet", "--verbose", "-o", out_png, NULL };
    tu_run_result rr;
    assert_int_equal(tu_run_cli_ex(quiet_args, NULL, errs, sizeof errs, &rr), 0);
    assert_int_equal(rr.lines, 1);
    assert_int_equal(tu_run_cli_ex(verbose_args, NULL, errs, sizeof errs, &rr), 0);
    assert_int_equal(rr.lines, each);
    assert_int_equal((int)sc.n_materials, 4);
    assert_int_equal((int)sc.n_textures, 0);
    for (size_t i = 0; i < sc.n_materials; i++) {
        const ms_material *m = &sc.materials[i];
        for (int c = 0; c < 4; c++) assert_true(m->base_color[c] >= 0 && m->base_color[c] <= 1);
        assert_true(m->metallic >= 0 && m->metallic <= 1 && m->roughness >= 0 && m->roughness <= 1);
    }
    assert_int_equal(sc.tri_material[2], MS_NO_MATERIAL);   /* usemtl nosuch */
    ms_frame fr;
    ms_render_options o;
    tu_render_options_default(&o);
    assert_int_equal(ms_render(&sc, &o, &fr, err, sizeof err), 0);
    for (size_t i = 0; i < 3 * (size_t)fr.width * fr.height; i++) assert_true(isfinite(fr.rgb[i]));
    ms_frame_free(&fr);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gltf_materials),
        cmocka_unit_test(test_normals_change_shading_not_visibility),
        cmocka_unit_test(test_bad_textures),
        cmocka_unit_test(test_obj_mtl_materials),
        cmocka_unit_test(test_cli_exr_and_exposure),
        cmocka_unit_test(test_hostile_mtl),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
