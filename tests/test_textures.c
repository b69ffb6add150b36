/* Textures and materials as real assets have them (issue 30), against oracles computed here:
 *   - one glTF, written here, with a JPEG, a KTX2 (R8G8B8A8_SRGB), a 16-bit PNG, a paletted PNG and a
 *     KHR_texture_transform'ed PNG (with the texCoord override), and the same image through a sampler with
 *     wrapS CLAMP_TO_EDGE, wrapT MIRRORED_REPEAT and a transform reaching past [0, 1]: at pixels well inside a texel, the shaded
 *     colour equals emission * (base/pi * E + F * LTC) with base the texel the test selects and decodes
 *     itself (the JPEG with TurboJPEG here, the others from the bytes the test wrote), E and LTC from
 *     ms_light_irradiance and ms_ltc_ggx (each checked against brute force in test_irradiance and
 *     test_shading);
 *   - a normal-mapped quad: the same with the normal perturbed by hand (T = +x, B = +z for its UVs); V and
 *     S bit-identical with and without the normal map (visibility stays geometric); penumbra pixels with the
 *     frame's S and S_spec as factors;
 *   - emission: emissiveFactor x KHR_materials_emissive_strength added to the rest;
 *   - extensionsRequired with an unknown extension: exit 2, one line naming it; an unknown extension in
 *     extensionsUsed and a Basis-compressed KTX2: one warning each, naming what is left out. */
#include "testutil.h"
#include "render/ltc.h"
#include "camera/camera.h"
#include <math.h>
#include <png.h>
#include <turbojpeg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double srgb_lin(double c8)
{
    const double x = c8 / 255.0;
    return x <= 0.04045 ? x / 12.92 : pow((x + 0.055) / 1.055, 2.4);
}

static void write_bytes(const char *dir, const char *name, const void *b, size_t n)
{
    char path[512];
    FILE *f = fopen(tu_path(path, sizeof path, dir, name), "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, n, f), n);
    fclose(f);
}

/* A PNG through libpng's low-level writer (no gAMA/sRGB chunk): colour type ct, bit depth bd, rows of
 * raw bytes (16-bit samples big-endian, as PNG stores them); a palette of np RGB entries when ct is 3. */
static void write_png(const char *dir, const char *name, int w, int h, int bd, int ct, const uint8_t *rows, size_t stride,
                      const uint8_t *palette, int np)
{
    char path[512];
    FILE *f = fopen(tu_path(path, sizeof path, dir, name), "wb");
    assert_non_null(f);
    png_structp p = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(p);
    assert_non_null(p);
    assert_non_null(info);
    if (setjmp(png_jmpbuf(p))) fail_msg("libpng failed writing %s", name);
    png_init_io(p, f);
    png_set_IHDR(p, info, (png_uint_32)w, (png_uint_32)h, bd, ct, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    if (ct == PNG_COLOR_TYPE_PALETTE) {
        png_color pal[16];
        for (int i = 0; i < np; i++) { pal[i].red = palette[3 * i]; pal[i].green = palette[3 * i + 1]; pal[i].blue = palette[3 * i + 2]; }
        png_set_PLTE(p, info, pal, np);
    }
    png_write_info(p, info);
    for (int y = 0; y < h; y++) png_write_row(p, rows + (size_t)y * stride);
    png_write_end(p, info);
    png_destroy_write_struct(&p, &info);
    fclose(f);
}

static void put32le(uint8_t *p, uint32_t v) { for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i)); }
static void put64le(uint8_t *p, uint64_t v) { for (int i = 0; i < 8; i++) p[i] = (uint8_t)(v >> (8 * i)); }

/* A KTX2 file (KTX 2.0 spec, section 3): header, index (no DFD/KVD/SGD, enough for a reader of
 * uncompressed data), one level of w x h texels of bpp bytes, tightly packed rows; scheme: the
 * supercompression (1: BasisLZ). Returns its length in out. */
static size_t make_ktx2(uint8_t *out, uint32_t vk, uint32_t w, uint32_t h, uint32_t scheme, const uint8_t *texels, size_t n)
{
    static const uint8_t id[12] = { 0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n' };
    memset(out, 0, 104);
    memcpy(out, id, 12);
    const uint32_t hdr[9] = { vk, 1, w, h, 0, 0, 1, 1, scheme };
    for (int i = 0; i < 9; i++) put32le(out + 12 + 4 * i, hdr[i]);
    /* index: dfd, kvd (offset, length u32), sgd (u64, u64): all empty; level 0 at 104 */
    put64le(out + 80, 104);
    put64le(out + 88, n);
    put64le(out + 96, n);
    memcpy(out + 104, texels, n);
    return 104 + n;
}

static int g_tangent_w;   /* write_scene: 0 no TANGENT; +1 or -1: TANGENT (1, 0, 0, w) on every vertex */

static const char *tangent_attr(int accessor)
{
    static char b[64];
    if (!g_tangent_w) return "";
    snprintf(b, sizeof b, ",\"TANGENT\":%d", accessor);
    return b;
}

/* The ground quads q = 0..nq-1: x in [2q, 2q + 1.6], z in [-0.8, 0.8], y = 0, normal +y, two triangles,
 * TEXCOORD_0 (u, v) = ((x - 2q) / 1.6, (z + 0.8) / 1.6) and TEXCOORD_1 constant (0.99, 0.99); primitive q
 * has material q. With occluder, a 0.5 x 0.5 quad at y = 0.5 over quad 0's corner, material-less.
 * materials/textures/images/samplers are the JSON arrays' contents; root_extra is more root members. */
static void write_scene(const char *dir, int nq, int occluder, const char *materials, const char *textures,
                        const char *images, const char *samplers, const char *root_extra)
{
    enum { MAXQ = 8 };
    const int nquads = nq + (occluder != 0);
    float pos[MAXQ * 6][3], uv0[MAXQ * 6][2], uv1[MAXQ * 6][2], nrm[MAXQ * 6][3], tan[MAXQ * 6][4];
    int nv = 0;
    for (int q = 0; q < nquads; q++) {
        const float x0 = q < nq ? 2.0f * q : 0.9f, x1 = q < nq ? x0 + 1.6f : 1.4f, z0 = q < nq ? -0.8f : -0.2f,
                    z1 = q < nq ? 0.8f : 0.3f, y = q < nq ? 0.0f : 0.5f;
        const float cx[6] = { x0, x1, x1, x0, x1, x0 }, cz[6] = { z1, z1, z0, z1, z0, z0 };
        for (int i = 0; i < 6; i++, nv++) {
            pos[nv][0] = cx[i]; pos[nv][1] = y; pos[nv][2] = cz[i];
            uv0[nv][0] = (cx[i] - x0) / 1.6f; uv0[nv][1] = (cz[i] + 0.8f) / 1.6f;
            uv1[nv][0] = uv1[nv][1] = 0.99f;
            nrm[nv][0] = 0; nrm[nv][1] = 1; nrm[nv][2] = 0;
            tan[nv][0] = 1; tan[nv][1] = 0; tan[nv][2] = 0; tan[nv][3] = (float)g_tangent_w;
        }
    }
    static uint8_t buf[MAXQ * 6 * 56];
    size_t bl = 0;
    memcpy(buf + bl, pos, (size_t)nv * 12); bl += (size_t)nv * 12;
    memcpy(buf + bl, uv0, (size_t)nv * 8); bl += (size_t)nv * 8;
    memcpy(buf + bl, uv1, (size_t)nv * 8); bl += (size_t)nv * 8;
    memcpy(buf + bl, nrm, (size_t)nv * 12); bl += (size_t)nv * 12;
    memcpy(buf + bl, tan, (size_t)nv * 16); bl += (size_t)nv * 16;
    write_bytes(dir, "scene.bin", buf, bl);
    static char acc[8192], prims[4096], gl[32768];
    size_t al = 0, pl = 0;
    for (int q = 0; q < nquads; q++) {
        const float x0 = q < nq ? 2.0f * q : 0.9f, x1 = q < nq ? x0 + 1.6f : 1.4f, z0 = q < nq ? -0.8f : -0.2f,
                    z1 = q < nq ? 0.8f : 0.3f, y = q < nq ? 0.0f : 0.5f;
        al += (size_t)snprintf(acc + al, sizeof acc - al,
            "%s{\"bufferView\":0,\"byteOffset\":%d,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\",\"min\":[%g,%g,%g],\"max\":[%g,%g,%g]},"
            "{\"bufferView\":1,\"byteOffset\":%d,\"componentType\":5126,\"count\":6,\"type\":\"VEC2\"},"
            "{\"bufferView\":2,\"byteOffset\":%d,\"componentType\":5126,\"count\":6,\"type\":\"VEC2\"},"
            "{\"bufferView\":3,\"byteOffset\":%d,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"},"
            "{\"bufferView\":4,\"byteOffset\":%d,\"componentType\":5126,\"count\":6,\"type\":\"VEC4\"}",
            q ? "," : "", q * 72, x0, y, z0, x1, y, z1, q * 48, q * 48, q * 72, q * 96);
        char mat[32] = "";
        if (q < nq) snprintf(mat, sizeof mat, ",\"material\":%d", q);
        pl += (size_t)snprintf(prims + pl, sizeof prims - pl,
            "%s{\"attributes\":{\"POSITION\":%d,\"TEXCOORD_0\":%d,\"TEXCOORD_1\":%d,\"NORMAL\":%d%s}%s}", q ? "," : "",
            5 * q, 5 * q + 1, 5 * q + 2, 5 * q + 3, tangent_attr(5 * q + 4), mat);
    }
    snprintf(gl, sizeof gl,
        "{\"asset\":{\"version\":\"2.0\"},%s\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"primitives\":[%s]}],\"materials\":[%s],\"textures\":[%s],\"images\":[%s],\"samplers\":[%s],"
        "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"scene.bin\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%d},{\"buffer\":0,\"byteOffset\":%d,\"byteLength\":%d},"
        "{\"buffer\":0,\"byteOffset\":%d,\"byteLength\":%d},{\"buffer\":0,\"byteOffset\":%d,\"byteLength\":%d},"
        "{\"buffer\":0,\"byteOffset\":%d,\"byteLength\":%d}],"
        "\"accessors\":[%s]}",
        root_extra ? root_extra : "", prims, materials, textures, images, samplers, bl, nv * 12, nv * 12, nv * 8,
        nv * 20, nv * 8, nv * 28, nv * 12, nv * 40, nv * 16, acc);
    char path[512];
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "scene.gltf"), gl), 0);
    /* An orthographic camera straight down (image up = -z), 48 pixels per 2 units; a light over everything. */
    char js[2048];
    const double cx = nq - 0.2;
    snprintf(js, sizeof js,
        "{\"meshes\":[{\"file\":\"scene.gltf\"}],"
        "\"camera\":{\"type\":\"orthographic\",\"eye\":[%g,5,0],\"target\":[%g,0,0],\"up\":[0,0,-1],\"ortho_height\":2,"
        "\"width\":%d,\"height\":48},"
        "\"light\":{\"corner\":[-1,3,-2],\"edge_s\":[%d,0,0],\"edge_t\":[0,0,4],\"emission\":[1,1,1]},"
        "\"render\":{\"samples\":256}}", cx, cx, 48 * nq, 2 * nq + 2);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "scene.json"), js), 0);
}

static int load_render(const char *dir, ms_scene *sc, ms_frame *fr)
{
    char path[512], err[512];
    if (ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), sc, err, sizeof err)) {
        printf("load: %s\n", err);
        return -1;
    }
    ms_render_options o;
    tu_render_options_default(&o);
    o.threads = 2;
    if (ms_render(sc, &o, fr, err, sizeof err)) { printf("render: %s\n", err); ms_scene_free(sc); return -1; }
    return 0;
}

/* For each pixel that sees quad q well inside it: p, the unit direction to the eye v and quad q's (u, v). */
typedef void (*pixel_fn)(void *user, int q, size_t i, const float p[3], const float v[3], double u, double tv);

static void each_pixel(const ms_scene *sc, const ms_frame *fr, int nq, pixel_fn fn, void *user)
{
    ms_camera_basis cb;
    assert_int_equal(ms_camera_basis_init(&cb, &sc->camera, fr->width, fr->height), 0);
    for (int y = 0; y < fr->height; y++)
        for (int x = 0; x < fr->width; x++) {
            float o[3], d[3];
            assert_int_equal(ms_camera_ray(&cb, x, y, o, d), 0);
            const double t = -o[1] / d[1];
            const float p[3] = { (float)(o[0] + t * d[0]), 0.0f, (float)(o[2] + t * d[2]) };
            const int q = (int)floorf(p[0] / 2.0f);
            const double lx = p[0] - 2.0 * q;
            if (q < 0 || q >= nq || lx < 0.03 || lx > 1.57 || fabsf(p[2]) > 0.77f) continue;
            const float v[3] = { -d[0], -d[1], -d[2] };
            fn(user, q, (size_t)y * fr->width + x, p, v, lx / 1.6, (p[2] + 0.8) / 1.6);
        }
}

/* The shaded radiance of a metallic 0, roughness 1 material of linear base colour base with shading normal
 * n, unshadowed, emission 1: base/pi E + F LTC, F = 0.04 + 0.96 (1 - n.v)^5. */
static void expected(const ms_scene *sc, const float p[3], const float n[3], const float v[3], const double base[3],
                     double s, double s_spec, double out[3])
{
    const double E = ms_light_irradiance(&sc->light, p, n), ltc = ms_ltc_ggx(&sc->light, p, n, v, 1.0f);
    double nv = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
    nv = nv < 0 ? 0 : nv > 1 ? 1 : nv;
    const double F = 0.04 + 0.96 * pow(1 - nv, 5);
    for (int c = 0; c < 3; c++) out[c] = base[c] / M_PI * E * s + F * ltc * s_spec;
}

/* ---- the textured quads ---- */
enum { Q_JPEG, Q_KTX2, Q_PNG16, Q_PALETTE, Q_XFORM, Q_WRAP, NQ };
typedef struct tex_case {
    int w[NQ], h[NQ];
    double lin[NQ][16][3];   /* linear texels, row-major from the top row */
    double xf[NQ][6];        /* the transforms of Q_XFORM and Q_WRAP (as KHR_texture_transform defines them) */
    int wrap_s[NQ], wrap_t[NQ];   /* 0 repeat, 1 clamp to edge, 2 mirrored repeat */
    const ms_scene *sc;
    const ms_frame *fr;
    int checked[NQ];
    double worst;
} tex_case;

static double frac(double x) { return x - floor(x); }

/* Texel index i (a floor) in 0..n-1 by the glTF wrap mode: 0 repeat, 1 clamp to edge, 2 mirrored repeat
 * (period 2n: 0..n-1 then n-1..0). */
static int wrap_texel(double i, int n, int mode)
{
    if (mode == 1) return i < 0 ? 0 : i > n - 1 ? n - 1 : (int)i;
    const int period = mode == 2 ? 2 * n : n;
    int k = (int)(i - period * floor(i / period));
    return k < n ? k : period - 1 - k;
}

static void check_tex_pixel(void *user, int q, size_t i, const float p[3], const float v[3], double u, double tv)
{
    tex_case *tc = user;
    if (q == Q_XFORM || q == Q_WRAP) {   /* uv' = T R S uv */
        const double *m = tc->xf[q], uu = m[0] * u + m[2] * tv + m[4], vv = m[1] * u + m[3] * tv + m[5];
        u = uu;
        tv = vv;
    }
    const double fx = u * tc->w[q], fy = tv * tc->h[q];
    if (frac(fx) < 0.1 || frac(fx) > 0.9 || frac(fy) < 0.1 || frac(fy) > 0.9) return;   /* near a texel edge */
    const int tx = wrap_texel(floor(fx), tc->w[q], tc->wrap_s[q]), ty = wrap_texel(floor(fy), tc->h[q], tc->wrap_t[q]);
    assert_true(tc->fr->vis[i] == 1.0f && tc->fr->shadow[i] == 1.0f);
    const float n[3] = { 0, 1, 0 };
    double want[3];
    expected(tc->sc, p, n, v, tc->lin[q][ty * tc->w[q] + tx], 1.0, 1.0, want);
    for (int c = 0; c < 3; c++) {
        const double got = tc->fr->rgb[3 * i + c], rel = fabs(got - want[c]) / want[c];
        if (rel > tc->worst) tc->worst = rel;
        if (rel > 2e-3) printf("quad %d texel (%d,%d) channel %d: %g, want %g\n", q, tx, ty, c, got, want[c]);
        assert_true(rel <= 2e-3);
    }
    tc->checked[q]++;
}

static void test_texture_formats(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("textures_formats");
    static tex_case tc;
    memset(&tc, 0, sizeof tc);
    /* JPEG: 16 x 16, four flat 8 x 8 blocks (one block per colour: the DCT of a flat block is its DC term
     * alone), 4:4:4, quality 95, decoded again here with TurboJPEG for the expected texels. */
    {
        static const uint8_t quad_rgb[4][3] = { { 200, 40, 30 }, { 30, 180, 60 }, { 40, 70, 210 }, { 230, 220, 90 } };
        uint8_t src[16 * 16 * 3], dec[16 * 16 * 3];
        for (int y = 0; y < 16; y++)
            for (int x = 0; x < 16; x++) memcpy(src + 3 * (16 * y + x), quad_rgb[(y / 8) * 2 + x / 8], 3);
        tjhandle tj = tjInitCompress();
        unsigned char *jpg = NULL;
        unsigned long jl = 0;
        assert_int_equal(tjCompress2(tj, src, 16, 0, 16, TJPF_RGB, &jpg, &jl, TJSAMP_444, 95, 0), 0);
        tjDestroy(tj);
        write_bytes(dir, "a.jpg", jpg, jl);
        tj = tjInitDecompress();
        assert_int_equal(tjDecompress2(tj, jpg, jl, dec, 16, 0, 16, TJPF_RGB, TJFLAG_ACCURATEDCT), 0);
        tjDestroy(tj);
        tjFree(jpg);
        tc.w[Q_JPEG] = tc.h[Q_JPEG] = 2;   /* nearest on 16 x 16 flat blocks = nearest on the 2 x 2 block grid */
        for (int b = 0; b < 4; b++)
            for (int c = 0; c < 3; c++) {
                const int y = (b / 2) * 8 + 4, x = (b % 2) * 8 + 4;
                tc.lin[Q_JPEG][b][c] = srgb_lin(dec[3 * (16 * y + x) + c]);
                /* and the decoded block is flat: */
                assert_int_equal(dec[3 * (16 * ((b / 2) * 8) + (b % 2) * 8) + c], dec[3 * (16 * y + x) + c]);
            }
    }
    /* KTX2, R8G8B8A8_SRGB (43), 2 x 2. */
    {
        static const uint8_t t[16] = { 250, 10, 10, 255, 10, 250, 10, 255, 10, 10, 250, 255, 120, 130, 140, 255 };
        uint8_t k[256];
        write_bytes(dir, "b.ktx2", k, make_ktx2(k, 43, 2, 2, 0, t, sizeof t));
        tc.w[Q_KTX2] = tc.h[Q_KTX2] = 2;
        for (int i = 0; i < 4; i++)
            for (int c = 0; c < 3; c++) tc.lin[Q_KTX2][i][c] = srgb_lin(t[4 * i + c]);
    }
    /* PNG, 16-bit RGBA without gAMA/sRGB (glTF: sRGB), 2 x 2; samples 257 k are the 8-bit k exactly. */
    {
        static const uint16_t t[16] = { 257 * 60, 257 * 200, 257 * 90, 65535, 257 * 255, 257 * 0, 257 * 128, 65535,
                                        257 * 17, 257 * 34, 257 * 240, 65535, 257 * 100, 257 * 100, 257 * 100, 65535 };
        uint8_t rows[2 * 16];
        for (int i = 0; i < 16; i++) { rows[2 * i] = (uint8_t)(t[i] >> 8); rows[2 * i + 1] = (uint8_t)t[i]; }
        write_png(dir, "c.png", 2, 2, 16, PNG_COLOR_TYPE_RGB_ALPHA, rows, 16, NULL, 0);
        tc.w[Q_PNG16] = tc.h[Q_PNG16] = 2;
        for (int i = 0; i < 4; i++)
            for (int c = 0; c < 3; c++) tc.lin[Q_PNG16][i][c] = srgb_lin(t[4 * i + c] / 257);
    }
    /* Paletted PNG, 8-bit indices, 2 x 2 over a 4-colour palette. */
    {
        static const uint8_t pal[12] = { 255, 128, 0, 0, 128, 255, 64, 64, 64, 250, 250, 250 };
        static const uint8_t idx[4] = { 2, 0, 3, 1 };
        write_png(dir, "d.png", 2, 2, 8, PNG_COLOR_TYPE_PALETTE, idx, 2, pal, 4);
        tc.w[Q_PALETTE] = tc.h[Q_PALETTE] = 2;
        for (int i = 0; i < 4; i++)
            for (int c = 0; c < 3; c++) tc.lin[Q_PALETTE][i][c] = srgb_lin(pal[3 * idx[i] + c]);
    }
    /* 8-bit PNG 4 x 4 of distinct texels with KHR_texture_transform: offset (0.3, 0.1), rotation 0.4,
     * scale (1.5, 0.7), its texCoord 0 overriding the textureInfo's 1 (TEXCOORD_1 is constant 0.99: a
     * reader ignoring the override shows one texel). The spec's matrix T R S: u' = ox + sx cos u + sy sin v,
     * v' = oy - sx sin u + sy cos v (its example: offset (0, 1), rotation pi/2, scale 0.5 is the
     * lower-left quadrant, checked below). */
    {
        uint8_t rgba[64];
        for (int i = 0; i < 16; i++) {
            rgba[4 * i] = (uint8_t)(15 * i + 10);
            rgba[4 * i + 1] = (uint8_t)(240 - 13 * i);
            rgba[4 * i + 2] = (uint8_t)(i % 2 ? 200 : 40);
            rgba[4 * i + 3] = 255;
        }
        write_png(dir, "e.png", 4, 4, 8, PNG_COLOR_TYPE_RGB_ALPHA, rgba, 16, NULL, 0);
        tc.w[Q_XFORM] = tc.h[Q_XFORM] = 4;
        for (int i = 0; i < 16; i++)
            for (int c = 0; c < 3; c++) tc.lin[Q_XFORM][i][c] = srgb_lin(rgba[4 * i + c]);
        const double r = 0.4, sx = 1.5, sy = 0.7;
        const double xf[6] = { sx * cos(r), -sx * sin(r), sy * sin(r), sy * cos(r), 0.3, 0.1 };
        memcpy(tc.xf[Q_XFORM], xf, sizeof xf);
        /* Q_WRAP: the same image through another texture, sampler wrapS CLAMP_TO_EDGE, wrapT MIRRORED_REPEAT,
         * nearest, transformed to (2.2 u - 0.6, 2 v - 0.5): both modes reached on both sides */
        const double xw[6] = { 2.2, 0, 0, 2.0, -0.6, -0.5 };
        memcpy(tc.xf[Q_WRAP], xw, sizeof xw);
        tc.wrap_s[Q_WRAP] = 1;
        tc.wrap_t[Q_WRAP] = 2;
        tc.w[Q_WRAP] = tc.h[Q_WRAP] = 4;
        memcpy(tc.lin[Q_WRAP], tc.lin[Q_XFORM], sizeof tc.lin[Q_XFORM]);
        /* the spec's example, through the same formula: (u, v) in [0,1]^2 -> u' in [0, 0.5], v' in [0.5, 1] */
        for (int k = 0; k < 4; k++) {
            const double u = k & 1, v = k >> 1, c = cos(M_PI / 2), s = sin(M_PI / 2);
            const double uu = 0.5 * c * u + 0.5 * s * v, vv = 1 - 0.5 * s * u + 0.5 * c * v;
            assert_true(uu > -1e-9 && uu < 0.5 + 1e-9 && vv > 0.5 - 1e-9 && vv < 1 + 1e-9);
        }
    }
    const char *mat = "{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":1,\"baseColorTexture\":{\"index\":%d%s}}}";
    char mats[2048] = "";
    size_t ml = 0;
    for (int q = 0; q < NQ; q++) {
        ml += (size_t)snprintf(mats + ml, sizeof mats - ml, q ? "," : "");
        ml += (size_t)snprintf(mats + ml, sizeof mats - ml, mat, q,
                               q == Q_XFORM ? ",\"texCoord\":1,\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0.3,0.1],"
                                              "\"rotation\":0.4,\"scale\":[1.5,0.7],\"texCoord\":0}}"
                               : q == Q_WRAP ? ",\"extensions\":{\"KHR_texture_transform\":{\"offset\":[-0.6,-0.5],"
                                               "\"scale\":[2.2,2.0]}}" : "");
    }
    write_scene(dir, NQ, 0, mats,
                "{\"source\":0,\"sampler\":0},{\"sampler\":0,\"extensions\":{\"KHR_texture_basisu\":{\"source\":1}}},"
                "{\"source\":2,\"sampler\":0},{\"source\":3,\"sampler\":0},{\"source\":4,\"sampler\":0},{\"source\":4,\"sampler\":1}",
                "{\"uri\":\"a.jpg\"},{\"uri\":\"b.ktx2\",\"mimeType\":\"image/ktx2\"},{\"uri\":\"c.png\"},{\"uri\":\"d.png\"},"
                "{\"uri\":\"e.png\"}",
                "{\"magFilter\":9728,\"minFilter\":9728},{\"magFilter\":9728,\"wrapS\":33071,\"wrapT\":33648}",
                "\"extensionsUsed\":[\"KHR_texture_transform\",\"KHR_texture_basisu\"],"
                "\"extensionsRequired\":[\"KHR_texture_transform\",\"KHR_texture_basisu\"],");
    ms_scene sc;
    ms_frame fr;
    assert_int_equal(load_render(dir, &sc, &fr), 0);
    assert_int_equal((int)sc.n_textures, NQ - 1);   /* e.png decoded once for two textures */
    tc.sc = &sc;
    tc.fr = &fr;
    each_pixel(&sc, &fr, NQ, check_tex_pixel, &tc);
    printf("textures: pixels checked: JPEG %d, KTX2 %d, 16-bit PNG %d, paletted PNG %d, transformed %d, clamp/mirror %d; "
           "worst relative error %.2g\n", tc.checked[0], tc.checked[1], tc.checked[2], tc.checked[3], tc.checked[4],
           tc.checked[5], tc.worst);
    for (int q = 0; q < NQ; q++) assert_true(tc.checked[q] > 100);
    ms_frame_free(&fr);
    ms_scene_free(&sc);
}

/* ---- normal map and emission ---- */
typedef struct nm_case {
    const ms_scene *sc;
    const ms_frame *fr;
    uint8_t texel[4][3];
    double scale, emissive[3];
    int normal_map, checked;
    double w;
    double worst;
} nm_case;

static void check_nm_pixel(void *user, int q, size_t i, const float p[3], const float v[3], double u, double tv)
{
    nm_case *c = user;
    if (q != 0 || (p[0] > 0.85f && p[0] < 1.45f && p[2] > -0.25f && p[2] < 0.35f)) return;   /* the occluder is seen */
    const double fx = 2 * u, fy = 2 * tv;
    if (frac(fx) < 0.1 || frac(fx) > 0.9 || frac(fy) < 0.1 || frac(fy) > 0.9) return;
    if (!(c->fr->vis[i] > 0.0f)) return;
    float n[3] = { 0, 1, 0 };
    if (c->normal_map) {
        /* tangent-space (x, y, z) = 2 texel / 255 - 1, x and y times the scale; T = +x (u grows with x),
         * N = +y, B = w N x T = -w z: glTF's +Y runs up the image, towards decreasing v, and v grows with z
         * here (w = 1: MikkTSpace's frame where the asset has no TANGENT; the TANGENT's w otherwise) */
        const uint8_t *t = c->texel[(int)fy * 2 + (int)fx];
        const double x = (2.0 * t[0] / 255 - 1) * c->scale, y = (2.0 * t[1] / 255 - 1) * c->scale, z = 2.0 * t[2] / 255 - 1;
        const double l = sqrt(x * x + y * y + z * z);
        n[0] = (float)(x / l);
        n[1] = (float)(z / l);
        n[2] = (float)(-c->w * y / l);
    }
    const double base[3] = { 0.6, 0.6, 0.6 };
    double want[3];
    expected(c->sc, p, n, v, base, c->fr->shadow[i], c->fr->shadow_spec[i], want);
    for (int k = 0; k < 3; k++) {
        want[k] += c->emissive[k];
        const double got = c->fr->rgb[3 * i + k], rel = fabs(got - want[k]) / want[k];
        if (rel > c->worst) c->worst = rel;
        if (rel > 2e-3) printf("pixel %zu channel %d: %g, want %g\n", i, k, got, want[k]);
        assert_true(rel <= 2e-3);
    }
    c->checked++;
}

/* A 2 x 2 normal map (nearest) on quad 0, normalTexture.scale 0.8, an occluder casting a penumbra over part
 * of it; the same scene without the map. Colours against the hand-perturbed normal; V and S equal bit for
 * bit. Then emission: emissiveFactor (0.5, 0.25, 1) x strength 4 adds (2, 1, 4). */
static void test_normal_map_and_emission(void **st)
{
    (void)st;
    static nm_case c;
    memset(&c, 0, sizeof c);
    static const uint8_t texel[4][3] = { { 200, 128, 220 }, { 128, 60, 230 }, { 90, 180, 210 }, { 150, 100, 240 } };
    memcpy(c.texel, texel, sizeof texel);
    c.scale = 0.8;
    ms_scene sc[4];
    ms_frame fr[4];
    static const char *const names[5] = { "textures_nm0", "textures_nm1", "textures_em", "textures_nm_tan", "textures_nm_tanm" };
    for (int variant = 0; variant < 5; variant++) {
        /* 0: no map, 1: the normal map (MikkTSpace), 2: emission, 3, 4: the map with TANGENT (1, 0, 0, +-1) */
        const char *dir = tu_tmpdir(names[variant]);
        g_tangent_w = variant == 3 ? 1 : variant == 4 ? -1 : 0;
        c.w = variant == 4 ? -1.0 : 1.0;
        uint8_t rgba[16];
        for (int i = 0; i < 4; i++) { memcpy(rgba + 4 * i, texel[i], 3); rgba[4 * i + 3] = 255; }
        write_png(dir, "n.png", 2, 2, 8, PNG_COLOR_TYPE_RGB_ALPHA, rgba, 8, NULL, 0);
        const char *m = variant == 0 ? "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.6,0.6,0.6,1],\"metallicFactor\":0}}"
                      : variant != 2 ? "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.6,0.6,0.6,1],\"metallicFactor\":0},"
                                       "\"normalTexture\":{\"index\":0,\"scale\":0.8},\"occlusionTexture\":{\"index\":0}}"
                                     : "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.6,0.6,0.6,1],\"metallicFactor\":0},"
                                       "\"emissiveFactor\":[0.5,0.25,1],\"extensions\":{\"KHR_materials_emissive_strength\":"
                                       "{\"emissiveStrength\":4}}}";
        write_scene(dir, 1, 1, m, "{\"source\":0,\"sampler\":0}", "{\"uri\":\"n.png\"}", "{\"magFilter\":9728}",
                    variant == 2 ? "\"extensionsUsed\":[\"KHR_materials_emissive_strength\"]," : NULL);
        const int k = variant < 3 ? variant : 3;   /* frames 0..2 kept; 3, 4 checked and freed */
        assert_int_equal(load_render(dir, &sc[k], &fr[k]), 0);
        if (variant == 1) assert_non_null(sc[k].tri_tangent);   /* MikkTSpace ran */
        c.sc = &sc[k];
        c.fr = &fr[k];
        c.normal_map = variant == 1 || variant >= 3;
        for (int k = 0; k < 3; k++) c.emissive[k] = variant == 2 ? (k == 0 ? 2.0 : k == 1 ? 1.0 : 4.0) : 0.0;
        c.checked = 0;
        each_pixel(&sc[k], &fr[k], 1, check_nm_pixel, &c);
        printf("%s: %d pixels checked, worst relative error %.2g\n", variant == 0 ? "no normal map" : variant == 1 ?
               "normal map (MikkTSpace)" : variant == 2 ? "emission" : variant == 3 ? "normal map, TANGENT w = 1" :
               "normal map, TANGENT w = -1", c.checked, c.worst);
        assert_true(c.checked > 100);
        if (k == 3) { ms_frame_free(&fr[3]); ms_scene_free(&sc[3]); }
    }
    g_tangent_w = 0;
    /* V and S: identical with and without the normal map, with a penumbra present */
    const size_t n = (size_t)fr[0].width * fr[0].height;
    size_t pen = 0, diff_rgb = 0;
    for (size_t i = 0; i < n; i++) {
        assert_true(fr[0].vis[i] == fr[1].vis[i]);
        assert_true(fr[0].shadow[i] == fr[1].shadow[i]);
        pen += fr[0].vis[i] > 0.0f && fr[0].vis[i] < 1.0f;
        diff_rgb += fr[0].rgb[3 * i] != fr[1].rgb[3 * i];
    }
    printf("normal map: V and S identical at %zu pixels (%zu in penumbra); colour differs at %zu\n", n, pen, diff_rgb);
    assert_true(pen > 20 && diff_rgb > 100);
    for (int v = 0; v < 3; v++) {
        ms_frame_free(&fr[v]);
        ms_scene_free(&sc[v]);
    }
}

static char g_warn[8][1024];
static int g_nwarn;
static void catch_warning(void *user, const char *msg)
{
    (void)user;
    if (g_nwarn < 8) snprintf(g_warn[g_nwarn], sizeof g_warn[0], "%s", msg);
    g_nwarn++;
}

/* extensionsRequired naming an extension microshadow lacks: exit 2, one line naming it. In extensionsUsed
 * only, and a Basis-compressed KTX2: warnings naming them (verbose: one each), the scene renders. */
static void test_extensions(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("textures_ext");
    const char *mat = "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}";
    uint8_t k[256], t[16] = { 0 };
    write_bytes(dir, "basis.ktx2", k, make_ktx2(k, 0, 2, 2, 1, t, sizeof t));
    write_scene(dir, 1, 0, mat, "{\"extensions\":{\"KHR_texture_basisu\":{\"source\":0}}}", "{\"uri\":\"basis.ktx2\"}", "",
                "\"extensionsUsed\":[\"KHR_texture_basisu\",\"EXT_made_up_thing\"],\"extensionsRequired\":[\"EXT_made_up_thing\"],");
    char path[512], out[512], all[4096];
    tu_path(path, sizeof path, dir, "scene.json");
    tu_path(out, sizeof out, dir, "out.png");
    const char *args[] = { path, "--width", "16", "--height", "16", "-o", out, NULL };
    tu_run_result res;
    const tu_run_opts opts = { 0, -1, 60 };
    const int rc = tu_run_cli_ex(args, &opts, all, sizeof all, &res);
    printf("extensionsRequired: exit %d, %d line(s): %s", rc, res.lines, all);
    assert_int_equal(rc, 2);
    assert_int_equal(res.lines, 1);
    assert_non_null(strstr(all, "EXT_made_up_thing"));
    assert_non_null(strstr(all, "scene.gltf"));
    /* used, not required: warnings, and the scene loads */
    write_scene(dir, 1, 0, mat, "{\"extensions\":{\"KHR_texture_basisu\":{\"source\":0}}}", "{\"uri\":\"basis.ktx2\"}", "",
                "\"extensionsUsed\":[\"KHR_texture_basisu\",\"EXT_made_up_thing\",\"KHR_materials_variants\"],");
    ms_set_warning_handler(catch_warning, NULL);
    ms_set_warning_verbose(1);
    g_nwarn = 0;
    ms_scene sc;
    char err[512];
    tu_path(path, sizeof path, dir, "scene.json");
    assert_int_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
    ms_set_warning_verbose(0);
    ms_set_warning_handler(NULL, NULL);
    for (int i = 0; i < g_nwarn && i < 8; i++) printf("warning: %s\n", g_warn[i]);
    assert_int_equal(g_nwarn, 3);
    int made_up = 0, lights = 0, basis = 0;
    for (int i = 0; i < 3; i++) {
        assert_null(strchr(g_warn[i], '\n'));
        made_up += strstr(g_warn[i], "scene.gltf: glTF extension EXT_made_up_thing") != NULL;
        lights += strstr(g_warn[i], "scene.gltf: glTF extension KHR_materials_variants") != NULL;
        basis += strstr(g_warn[i], "basis.ktx2: ") && strstr(g_warn[i], "BasisLZ");   /* the texture file named */
    }
    assert_true(made_up == 1 && lights == 1 && basis == 1);
    assert_int_equal((int)sc.n_textures, 0);   /* the material keeps its factors */
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_texture_formats),
        cmocka_unit_test(test_normal_map_and_emission),
        cmocka_unit_test(test_extensions),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
