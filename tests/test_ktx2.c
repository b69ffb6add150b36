/* KTX2 material textures (src/scene/texture_ktx2.c) against oracles computed here:
 *   - Zstandard levels (supercompressionScheme 2) decode texel for texel to the same image stored
 *     uncompressed and to the RGBA the test expands itself, for every 8-bit format, rows either way; the
 *     Zstandard data comes from libzstd's compressor here (one frame stating its size, one frame without,
 *     two frames), the independent path; both files written and read back as files;
 *   - hostile files: every truncation; offsets, lengths and their sums past the file or overflowing;
 *     uncompressedByteLength wrong; frames holding more or less than the texels, garbage, a corrupted
 *     checksummed frame; level counts, sizes past the side limit or the budget; every header byte flipped:
 *     each refused with one line naming the file (or, for a flip, decoded within its declared size);
 *   - a glb embedding the Zstandard KTX2 as its base colour renders bit for bit as the same glb with the
 *     texture uncompressed and as a PNG (libpng's decoder), and unlike the untextured glb; through the CLI
 *     it renders without a warning, and a glTF naming a hostile KTX2 renders (exit 0) with one warning naming
 *     that file (a texture that cannot be used leaves its material the factors: docs/shading.md). */
#include "testutil.h"
#include "scene/scene_internal.h"
#include <png.h>
#include <zstd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void put32(uint8_t *p, uint32_t v) { for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i)); }
static void put64(uint8_t *p, uint64_t v) { for (int i = 0; i < 8; i++) p[i] = (uint8_t)(v >> (8 * i)); }

/* Header fields by byte offset (KTX 2.0, section 3), for the hostile variants. */
enum { F_VK = 12, F_W = 20, F_H = 24, F_DEPTH = 28, F_LAYERS = 32, F_FACES = 36, F_LEVELS = 40, F_SCHEME = 44,
       F_DFD_OFF = 48, F_DFD_LEN = 52, F_L0_OFF = 80, F_L0_LEN = 88, F_L0_ULEN = 96, HDR = 104 };

/* A KTX2 file of one level: the header, its index entry, an optional DFD of dfd_n bytes, then the level's
 * n stored bytes (ulen: its uncompressedByteLength). Caller frees. */
static uint8_t *make_ktx2(uint32_t vk, uint32_t w, uint32_t h, uint32_t scheme, const void *level, size_t n, uint64_t ulen,
                          const uint8_t *dfd, size_t dfd_n, size_t *len)
{
    static const uint8_t id[12] = { 0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n' };
    *len = HDR + dfd_n + n;
    uint8_t *b = calloc(1, *len);
    assert_non_null(b);
    memcpy(b, id, 12);
    const uint32_t hdr[9] = { vk, 1, w, h, 0, 0, 1, 1, scheme };
    for (int i = 0; i < 9; i++) put32(b + 12 + 4 * i, hdr[i]);
    if (dfd_n) { put32(b + F_DFD_OFF, HDR); put32(b + F_DFD_LEN, (uint32_t)dfd_n); memcpy(b + HDR, dfd, dfd_n); }
    put64(b + F_L0_OFF, HDR + dfd_n);
    put64(b + F_L0_LEN, n);
    put64(b + F_L0_ULEN, ulen);
    if (n) memcpy(b + HDR + dfd_n, level, n);
    return b;
}

enum { Z_ONE_FRAME, Z_NO_SIZE, Z_TWO_FRAMES, Z_CHECKSUM };

/* src[0..n) compressed by libzstd as `how` says; caller frees. */
static uint8_t *zstd_of(const uint8_t *src, size_t n, int how, size_t *out_n)
{
    const size_t cap = 2 * ZSTD_compressBound(n) + 64;
    uint8_t *dst = malloc(cap);
    assert_non_null(dst);
    ZSTD_CCtx *cc = ZSTD_createCCtx();
    assert_non_null(cc);
    ZSTD_CCtx_setParameter(cc, ZSTD_c_compressionLevel, 10);
    ZSTD_CCtx_setParameter(cc, ZSTD_c_contentSizeFlag, how != Z_NO_SIZE);
    ZSTD_CCtx_setParameter(cc, ZSTD_c_checksumFlag, how == Z_CHECKSUM);
    size_t got;
    if (how == Z_TWO_FRAMES) {
        const size_t a = ZSTD_compress2(cc, dst, cap, src, n / 2);
        assert_false(ZSTD_isError(a));
        const size_t b = ZSTD_compress2(cc, dst + a, cap - a, src + n / 2, n - n / 2);
        assert_false(ZSTD_isError(b));
        got = a + b;
    } else if (how == Z_NO_SIZE) {   /* streamed, so the frame cannot state its size */
        ZSTD_inBuffer in = { src, n, 0 };
        ZSTD_outBuffer out = { dst, cap, 0 };
        assert_int_equal(ZSTD_compressStream2(cc, &out, &in, ZSTD_e_end), 0);
        got = out.pos;
        assert_int_equal(ZSTD_getFrameContentSize(dst, got), ZSTD_CONTENTSIZE_UNKNOWN);
    } else {
        got = ZSTD_compress2(cc, dst, cap, src, n);
        assert_false(ZSTD_isError(got));
    }
    ZSTD_freeCCtx(cc);
    *out_n = got;
    return dst;
}

typedef struct fmt { uint32_t vk; int bpp; int ch[4]; } fmt;   /* ch: RGBA's byte in a texel, -1 absent */
static const fmt formats[] = {
    { 9, 1, { 0, -1, -1, -1 } },  { 15, 1, { 0, -1, -1, -1 } }, { 16, 2, { 0, 1, -1, -1 } }, { 22, 2, { 0, 1, -1, -1 } },
    { 23, 3, { 0, 1, 2, -1 } },   { 29, 3, { 0, 1, 2, -1 } },   { 30, 3, { 2, 1, 0, -1 } },  { 36, 3, { 2, 1, 0, -1 } },
    { 37, 4, { 0, 1, 2, 3 } },    { 43, 4, { 0, 1, 2, 3 } },    { 44, 4, { 2, 1, 0, 3 } },   { 50, 4, { 2, 1, 0, 3 } },
};

static const char *const PATH = "/tmp/microshadow-test/texture.ktx2";

/* A refusal: -1, no pixels, one line beginning with the file's name. */
static void assert_refused(int rc, const ms_texture *t, const char *err, const char *why)
{
    if (rc == 0) fail_msg("%s: decoded, should be refused", why);
    assert_null(t->rgba);
    if (strncmp(err, PATH, strlen(PATH)) || strncmp(err + strlen(PATH), ": ", 2) || strchr(err, '\n'))
        fail_msg("%s: the message '%s' is not one line naming the file", why, err);
}

static int decode(const uint8_t *b, size_t n, int flip, size_t budget, ms_texture *t, char *err, size_t errlen)
{
    err[0] = 0;
    return ms_texture_decode(b, n, PATH, flip, budget, t, err, errlen);
}

static void test_zstd_equals_uncompressed(void **st)
{
    (void)st;
    static const int sizes[][2] = { { 37, 23 }, { 1, 1 }, { 64, 3 }, { 2, 129 } };
    tu_rng rng = { 0x4b5458325a535444ull };
    int checked = 0;
    for (size_t f = 0; f < sizeof formats / sizeof *formats; f++)
        for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
            const fmt *F = &formats[f];
            const uint32_t w = (uint32_t)sizes[s][0], h = (uint32_t)sizes[s][1];
            const size_t need = (size_t)w * h * (size_t)F->bpp;
            uint8_t *raw = malloc(need), *want = malloc((size_t)w * h * 4);
            assert_non_null(raw);
            assert_non_null(want);
            /* smooth ramps and noise: both compress differently */
            for (size_t i = 0; i < need; i++) raw[i] = (i / 7) % 3 ? (uint8_t)(i * 5 + s) : (uint8_t)tu_rng_next(&rng);
            for (size_t i = 0; i < (size_t)w * h; i++)
                for (int c = 0; c < 4; c++) want[4 * i + c] = F->ch[c] >= 0 ? raw[i * F->bpp + F->ch[c]] : c == 3 ? 255 : 0;
            size_t pn;
            uint8_t *plain = make_ktx2(F->vk, w, h, 0, raw, need, need, NULL, 0, &pn);
            for (int how = Z_ONE_FRAME; how <= Z_CHECKSUM; how++) {
                size_t zn, kn;
                uint8_t *z = zstd_of(raw, need, how, &zn);
                uint8_t *k = make_ktx2(F->vk, w, h, 2, z, zn, need, NULL, 0, &kn);
                for (int flip = 0; flip < 2; flip++) {
                    ms_texture a, b;
                    char err[512];
                    if (decode(plain, pn, flip, (size_t)64 << 20, &a, err, sizeof err)) fail_msg("plain: %s", err);
                    if (decode(k, kn, flip, (size_t)64 << 20, &b, err, sizeof err)) fail_msg("zstd: %s", err);
                    assert_true(a.width == (int)w && a.height == (int)h && b.width == (int)w && b.height == (int)h);
                    assert_memory_equal(a.rgba, b.rgba, (size_t)w * h * 4);
                    for (uint32_t y = 0; y < h; y++)
                        assert_memory_equal(b.rgba + (size_t)(flip ? h - 1 - y : y) * w * 4, want + (size_t)y * w * 4, (size_t)w * 4);
                    free(a.rgba);
                    free(b.rgba);
                    checked++;
                }
                free(k);
                free(z);
            }
            free(plain);
            free(raw);
            free(want);
        }
    print_message("zstd KTX2 equal to uncompressed and to the expected RGBA: %d decodes (12 formats, 4 sizes, "
                  "4 ways to compress, rows both ways)\n", checked);

    /* Both files written and read back as files (what a scene's textures are). */
    const char *dir = tu_tmpdir("ktx2_files");
    const uint32_t w = 19, h = 11;
    uint8_t raw[19 * 11 * 3];
    for (size_t i = 0; i < sizeof raw; i++) raw[i] = (uint8_t)(i * 37 + (i >> 3));
    size_t zn, kn, pn;
    uint8_t *z = zstd_of(raw, sizeof raw, Z_ONE_FRAME, &zn);
    uint8_t *k = make_ktx2(23, w, h, 2, z, zn, sizeof raw, NULL, 0, &kn), *plain = make_ktx2(23, w, h, 0, raw, sizeof raw,
                                                                                              sizeof raw, NULL, 0, &pn);
    char pa[512], pb[512], err[512];
    FILE *fa = fopen(tu_path(pa, sizeof pa, dir, "plain.ktx2"), "wb"), *fb = fopen(tu_path(pb, sizeof pb, dir, "zstd.ktx2"), "wb");
    assert_true(fa && fb);
    assert_int_equal(fwrite(plain, 1, pn, fa), pn);
    assert_int_equal(fwrite(k, 1, kn, fb), kn);
    fclose(fa);
    fclose(fb);
    ms_tri_soup soup = { 0 };
    assert_int_equal(ms_soup_add_texture_file(&soup, pa, 0, err, sizeof err), 0);
    assert_int_equal(ms_soup_add_texture_file(&soup, pb, 0, err, sizeof err), 1);
    assert_memory_equal(soup.tex[0].rgba, soup.tex[1].rgba, (size_t)w * h * 4);
    print_message("files: %zu bytes uncompressed, %zu with Zstandard, the same %ux%u texels\n", pn, kn, w, h);
    ms_soup_free(&soup);
    free(z);
    free(k);
    free(plain);
}

/* A valid Zstandard RGBA8 file of 16 x 8 texels (checksummed) to spoil: its bytes, the level's raw texels. */
static uint8_t g_raw[16 * 8 * 4];

static uint8_t *good_file(size_t *n)
{
    for (size_t i = 0; i < sizeof g_raw; i++) g_raw[i] = (uint8_t)(i * 13 + (i >> 4));
    size_t zn;
    uint8_t *z = zstd_of(g_raw, sizeof g_raw, Z_CHECKSUM, &zn);
    uint8_t *k = make_ktx2(43, 16, 8, 2, z, zn, sizeof g_raw, NULL, 0, n);
    free(z);
    return k;
}

/* The file with field `at` set to v (32 or 64 bits), decoded: must be refused. */
static void refuse_field(const uint8_t *good, size_t n, int at, int bits, uint64_t v, const char *why, const char *must_say)
{
    uint8_t *b = malloc(n);
    assert_non_null(b);
    memcpy(b, good, n);
    if (bits == 64) put64(b + at, v);
    else put32(b + at, (uint32_t)v);
    ms_texture t;
    char err[512];
    assert_refused(decode(b, n, 0, (size_t)16 << 20, &t, err, sizeof err), &t, err, why);
    if (must_say && !strstr(err, must_say)) fail_msg("%s: '%s' does not say '%s'", why, err, must_say);
    free(b);
}

/* The file with level 0 replaced by data[0..dn) (and its lengths with it), decoded: must be refused. */
static void refuse_level(const uint8_t *data, size_t dn, uint64_t ulen, const char *why, const char *must_say)
{
    size_t n;
    uint8_t *b = make_ktx2(43, 16, 8, 2, data, dn, ulen, NULL, 0, &n);
    ms_texture t;
    char err[512];
    assert_refused(decode(b, n, 0, (size_t)16 << 20, &t, err, sizeof err), &t, err, why);
    if (must_say && !strstr(err, must_say)) fail_msg("%s: '%s' does not say '%s'", why, err, must_say);
    free(b);
}

static void test_hostile(void **st)
{
    (void)st;
    size_t n;
    uint8_t *good = good_file(&n);
    ms_texture t;
    char err[512];
    assert_int_equal(decode(good, n, 0, (size_t)16 << 20, &t, err, sizeof err), 0);
    assert_memory_equal(t.rgba, g_raw, sizeof g_raw);
    free(t.rgba);
    /* every truncation */
    for (size_t k = 0; k < n; k++) {
        char why[64];
        snprintf(why, sizeof why, "cut to %zu bytes", k);
        assert_refused(decode(good, k, 0, (size_t)16 << 20, &t, err, sizeof err), &t, err, why);
    }
    const uint64_t big = ~(uint64_t)0;
    refuse_field(good, n, F_L0_OFF, 64, big, "byteOffset 2^64-1", "past the end");
    refuse_field(good, n, F_L0_OFF, 64, n, "byteOffset at the end", NULL);
    refuse_field(good, n, F_L0_OFF, 64, big - 7, "byteOffset + byteLength overflowing", "past the end");
    refuse_field(good, n, F_L0_LEN, 64, big, "byteLength 2^64-1", "past the end");
    refuse_field(good, n, F_L0_LEN, 64, (uint64_t)1 << 32, "byteLength 2^32", "past the end");
    refuse_field(good, n, F_L0_LEN, 64, 0, "byteLength 0", NULL);
    refuse_field(good, n, F_L0_ULEN, 64, sizeof g_raw + 1, "uncompressedByteLength + 1", "uncompressedByteLength");
    refuse_field(good, n, F_L0_ULEN, 64, sizeof g_raw - 1, "uncompressedByteLength - 1", "uncompressedByteLength");
    refuse_field(good, n, F_L0_ULEN, 64, big, "uncompressedByteLength 2^64-1", "uncompressedByteLength");
    refuse_field(good, n, F_LEVELS, 32, 0xFFFFFFFFu, "levelCount 2^32-1", "level index");
    refuse_field(good, n, F_LEVELS, 32, 2, "levelCount 2 (the index past level 0's data)", NULL);
    refuse_field(good, n, F_W, 32, 0, "width 0", "0x8 texture");
    refuse_field(good, n, F_W, 32, 16385, "width 16385", "at most 16384");
    refuse_field(good, n, F_H, 32, 0xFFFFFFFFu, "height 2^32-1", NULL);
    refuse_field(good, n, F_DEPTH, 32, 2, "a 3D texture", "3D texture");
    refuse_field(good, n, F_LAYERS, 32, 2, "an array", "array");
    refuse_field(good, n, F_FACES, 32, 6, "a cube map", "cube map");
    refuse_field(good, n, F_FACES, 32, 0, "faceCount 0", "face count");
    refuse_field(good, n, F_SCHEME, 32, 1, "BasisLZ", "BasisLZ/ETC1S");
    refuse_field(good, n, F_SCHEME, 32, 3, "ZLIB", "ZLIB");
    refuse_field(good, n, F_SCHEME, 32, 77, "an unknown scheme", "unknown");
    refuse_field(good, n, F_VK, 32, 131, "BC1 (block-compressed)", "vkFormat 131");
    refuse_field(good, n, F_VK, 32, 0, "vkFormat 0 without a DFD", "vkFormat 0");
    /* Past the budget: 4096 x 4096 RGBA is 64 MiB against a budget of 16 MiB, refused from the header. */
    {
        uint8_t *b = malloc(n);
        assert_non_null(b);
        memcpy(b, good, n);
        put32(b + F_W, 4096);
        put32(b + F_H, 4096);
        assert_refused(decode(b, n, 0, (size_t)16 << 20, &t, err, sizeof err), &t, err, "past the budget");
        assert_non_null(strstr(err, "exceed"));
        free(b);
    }
    /* UASTC (vkFormat 0, DFD colour model 166) with and without Zstandard: named as Basis Universal. */
    {
        uint8_t dfd[44] = { 44 };
        dfd[12] = 166;
        size_t kn;
        for (uint32_t sc = 0; sc <= 2; sc += 2) {
            uint8_t *k = make_ktx2(0, 16, 8, sc, g_raw, 64, 64, dfd, sizeof dfd, &kn);
            assert_refused(decode(k, kn, 0, (size_t)16 << 20, &t, err, sizeof err), &t, err, "UASTC");
            assert_non_null(strstr(err, "UASTC"));
            assert_non_null(strstr(err, "KHR_texture_basisu"));
            if (sc) assert_non_null(strstr(err, "Zstandard"));
            put32(k + F_DFD_OFF, 0xFFFFFFF0u);   /* the DFD past the end: the model unknown, still refused */
            assert_refused(decode(k, kn, 0, (size_t)16 << 20, &t, err, sizeof err), &t, err, "vkFormat 0, DFD past the end");
            assert_non_null(strstr(err, "vkFormat 0"));
            free(k);
        }
    }
    /* Level data that is not what the header says. */
    {
        uint8_t more[sizeof g_raw + 1000], garbage[64];
        memcpy(more, g_raw, sizeof g_raw);
        memset(more + sizeof g_raw, 7, 1000);
        for (size_t i = 0; i < sizeof garbage; i++) garbage[i] = (uint8_t)(i * 91 + 3);
        size_t zn;
        uint8_t *z = zstd_of(more, sizeof more, Z_ONE_FRAME, &zn);
        refuse_level(z, zn, sizeof g_raw, "a frame stating 1000 bytes more", "holds");
        free(z);
        z = zstd_of(more, sizeof more, Z_NO_SIZE, &zn);   /* libzstd must stop at the capacity (ASan watches) */
        refuse_level(z, zn, sizeof g_raw, "a frame without its size, 1000 bytes more", "Zstandard");
        free(z);
        z = zstd_of(g_raw, sizeof g_raw - 1, Z_ONE_FRAME, &zn);
        refuse_level(z, zn, sizeof g_raw, "a frame one byte short", "holds");
        free(z);
        z = zstd_of(g_raw, sizeof g_raw - 1, Z_NO_SIZE, &zn);
        refuse_level(z, zn, sizeof g_raw, "a frame without its size, one byte short", "holds");
        free(z);
        refuse_level(garbage, sizeof garbage, sizeof g_raw, "garbage", "not Zstandard");
        z = zstd_of(g_raw, sizeof g_raw, Z_CHECKSUM, &zn);
        z[zn / 2] ^= 0x55;
        refuse_level(z, zn, sizeof g_raw, "a corrupted checksummed frame", "Zstandard");
        free(z);
    }
    /* Every byte of the header, index and the frame's start flipped two ways: refused with one line, or
     * decoded into an image of the size the (changed) header declares within the budget. */
    int refused = 0, decoded = 0;
    for (size_t i = 0; i < n && i < HDR + 24; i++)
        for (int m = 0; m < 2; m++) {
            uint8_t *b = malloc(n);
            assert_non_null(b);
            memcpy(b, good, n);
            b[i] ^= m ? 0xFF : 0x01;
            char why[64];
            snprintf(why, sizeof why, "byte %zu ^ 0x%02x", i, m ? 0xFF : 0x01);
            if (decode(b, n, 0, (size_t)16 << 20, &t, err, sizeof err)) {
                assert_refused(-1, &t, err, why);
                refused++;
            } else {
                assert_true(t.width >= 1 && t.height >= 1 && (size_t)t.width * t.height * 4 <= ((size_t)16 << 20));
                free(t.rgba);
                decoded++;
            }
            free(b);
        }
    print_message("hostile: %zu truncations refused; flipped bytes: %d refused, %d still decoded (fields the reader "
                  "does not use)\n", n, refused, decoded);
    free(good);
}

/* ---- a glb with the texture, rendered ---- */

/* A glb of one quad, x and z in [-1, 1] at y = 0, normal +y, UVs (x + 1) / 2, (z + 1) / 2, a material of
 * base colour texture (nearest filter): image[0..image_n) in a bufferView of mime type `mime`, or the file
 * `uri`, or none when both are NULL. */
static void write_glb(const char *path, const uint8_t *image, size_t image_n, const char *mime, const char *uri)
{
    const float cx[6] = { -1, 1, 1, -1, 1, -1 }, cz[6] = { 1, 1, -1, 1, -1, -1 };
    float pos[18], nrm[18], uv[12];
    for (int i = 0; i < 6; i++) {
        pos[3 * i] = cx[i]; pos[3 * i + 1] = 0; pos[3 * i + 2] = cz[i];
        nrm[3 * i] = 0; nrm[3 * i + 1] = 1; nrm[3 * i + 2] = 0;
        uv[2 * i] = (cx[i] + 1) / 2; uv[2 * i + 1] = (cz[i] + 1) / 2;
    }
    if (!image) image_n = 0;
    const size_t img_pad = (image_n + 3) & ~(size_t)3, bin_n = sizeof pos + sizeof nrm + sizeof uv + img_pad;
    uint8_t *bin = calloc(1, bin_n);
    assert_non_null(bin);
    memcpy(bin, pos, sizeof pos);
    memcpy(bin + sizeof pos, nrm, sizeof nrm);
    memcpy(bin + sizeof pos + sizeof nrm, uv, sizeof uv);
    if (image) memcpy(bin + sizeof pos + sizeof nrm + sizeof uv, image, image_n);
    char tex[512] = "", view[128] = "";
    if (image) {
        snprintf(tex, sizeof tex, "\"textures\":[{\"source\":0,\"sampler\":0}],\"samplers\":[{\"magFilter\":9728}],"
                 "\"images\":[{\"bufferView\":3,\"mimeType\":\"%s\"}],", mime);
        snprintf(view, sizeof view, ",{\"buffer\":0,\"byteOffset\":192,\"byteLength\":%zu}", image_n);
    } else if (uri)
        snprintf(tex, sizeof tex, "\"textures\":[{\"source\":0,\"sampler\":0}],\"samplers\":[{\"magFilter\":9728}],"
                 "\"images\":[{\"uri\":\"%s\"}],", uri);
    char json[4096];
    int jn = snprintf(json, sizeof json,
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"material\":0}]}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{%s\"metallicFactor\":0,\"roughnessFactor\":1}}],%s"
        "\"buffers\":[{\"byteLength\":%zu}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":72},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":72},"
        "{\"buffer\":0,\"byteOffset\":144,\"byteLength\":48}%s],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\",\"min\":[-1,0,-1],\"max\":[1,0,1]},"
        "{\"bufferView\":1,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":6,\"type\":\"VEC2\"}]}",
        tex[0] ? "\"baseColorTexture\":{\"index\":0}," : "", tex, bin_n, view);
    assert_true(jn > 0 && (size_t)jn + 4 < sizeof json);
    while (jn % 4) json[jn++] = ' ';
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    uint8_t h[12], ch[8];
    put32(h, 0x46546C67u);   /* "glTF", version 2, total length */
    put32(h + 4, 2);
    put32(h + 8, (uint32_t)(12 + 8 + (size_t)jn + 8 + bin_n));
    fwrite(h, 1, 12, f);
    put32(ch, (uint32_t)jn);
    put32(ch + 4, 0x4E4F534Au);   /* JSON */
    fwrite(ch, 1, 8, f);
    fwrite(json, 1, (size_t)jn, f);
    put32(ch, (uint32_t)bin_n);
    put32(ch + 4, 0x004E4942u);   /* BIN */
    fwrite(ch, 1, 8, f);
    fwrite(bin, 1, bin_n, f);
    assert_int_equal(fclose(f), 0);
    free(bin);
}

/* dir/scene.json over dir/<mesh>: an orthographic camera straight down on the quad, a light above. */
static void write_scene_json(const char *dir, const char *mesh)
{
    char js[1024], path[512];
    snprintf(js, sizeof js,
        "{\"meshes\":[{\"file\":\"%s\"}],"
        "\"camera\":{\"type\":\"orthographic\",\"eye\":[0,5,0],\"target\":[0,0,0],\"up\":[0,0,-1],\"ortho_height\":2,"
        "\"width\":48,\"height\":48},"
        "\"light\":{\"corner\":[-1,3,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2],\"emission\":[1,1,1]},"
        "\"render\":{\"samples\":256}}", mesh);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "scene.json"), js), 0);
}

static float *render_rgb(const char *dir, int *npx)
{
    char path[512], err[512];
    ms_scene sc;
    if (ms_scene_load(tu_path(path, sizeof path, dir, "scene.json"), &sc, err, sizeof err)) fail_msg("load: %s", err);
    ms_render_options o;
    tu_render_options_default(&o);
    o.threads = 2;
    ms_frame fr;
    if (ms_render(&sc, &o, &fr, err, sizeof err)) fail_msg("render: %s", err);
    *npx = fr.width * fr.height;
    float *rgb = malloc((size_t)*npx * 3 * sizeof *rgb);
    assert_non_null(rgb);
    memcpy(rgb, fr.rgb, (size_t)*npx * 3 * sizeof *rgb);
    ms_frame_free(&fr);
    ms_scene_free(&sc);
    return rgb;
}

static uint8_t *png_of(const uint8_t *rgba, int w, int h, size_t *n)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = (png_uint_32)w;
    img.height = (png_uint_32)h;
    img.format = PNG_FORMAT_RGBA;
    png_alloc_size_t cap = 0;
    assert_true(png_image_write_to_memory(&img, NULL, &cap, 0, rgba, 0, NULL));
    uint8_t *b = malloc(cap);
    assert_non_null(b);
    assert_true(png_image_write_to_memory(&img, b, &cap, 0, rgba, 0, NULL));
    *n = cap;
    return b;
}

static void test_glb_renders(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("ktx2_glb");
    enum { W = 8, H = 8 };
    uint8_t rgba[W * H * 4];
    for (int i = 0; i < W * H; i++) {
        rgba[4 * i] = (uint8_t)(40 + 25 * (i % W));
        rgba[4 * i + 1] = (uint8_t)(30 + 27 * (i / W));
        rgba[4 * i + 2] = (uint8_t)(i * 37 % 251);
        rgba[4 * i + 3] = 255;
    }
    size_t zn, kn, pn, pngn;
    uint8_t *z = zstd_of(rgba, sizeof rgba, Z_ONE_FRAME, &zn);
    uint8_t *k = make_ktx2(43, W, H, 2, z, zn, sizeof rgba, NULL, 0, &kn);
    uint8_t *plain = make_ktx2(43, W, H, 0, rgba, sizeof rgba, sizeof rgba, NULL, 0, &pn);
    uint8_t *png = png_of(rgba, W, H, &pngn);
    char path[512];
    const struct { const char *name; const uint8_t *img; size_t n; const char *mime; } v[] = {
        { "zstd.glb", k, kn, "image/ktx2" }, { "plain.glb", plain, pn, "image/ktx2" }, { "png.glb", png, pngn, "image/png" },
        { "none.glb", NULL, 0, NULL } };
    float *rgb[4];
    int npx = 0;
    for (int i = 0; i < 4; i++) {
        write_glb(tu_path(path, sizeof path, dir, v[i].name), v[i].img, v[i].n, v[i].mime, NULL);
        write_scene_json(dir, v[i].name);
        rgb[i] = render_rgb(dir, &npx);
    }
    assert_memory_equal(rgb[0], rgb[1], (size_t)npx * 3 * sizeof(float));
    assert_memory_equal(rgb[0], rgb[2], (size_t)npx * 3 * sizeof(float));
    long differ = 0;
    for (int i = 0; i < npx * 3; i++) differ += rgb[0][i] != rgb[3][i];
    assert_true(differ > npx);   /* the texture is seen */
    print_message("glb: the Zstandard KTX2 renders bit for bit as uncompressed and as PNG (%d pixels), %ld of %d "
                  "values differ from the untextured quad\n", npx, differ, npx * 3);
    for (int i = 0; i < 4; i++) free(rgb[i]);

    /* The CLI: the Zstandard glb without a word; a glTF naming a hostile KTX2 with one warning naming it. */
    char out[512], line[1024];
    write_scene_json(dir, "zstd.glb");
    const char *args[] = { tu_path(path, sizeof path, dir, "scene.json"), "-o", tu_path(out, sizeof out, dir, "zstd.png"),
                           "--aa", "1", "--quiet", NULL };
    assert_int_equal(tu_run_cli(args, line, sizeof line), 0);
    if (line[0]) fail_msg("the zstd glb: unexpected '%s'", line);
    put64(k + F_L0_ULEN, sizeof rgba * 2);   /* uncompressedByteLength twice the texels' */
    FILE *f = fopen(tu_path(path, sizeof path, dir, "hostile.ktx2"), "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(k, 1, kn, f), kn);
    fclose(f);
    write_glb(tu_path(path, sizeof path, dir, "hostile.glb"), NULL, 0, NULL, "hostile.ktx2");
    write_scene_json(dir, "hostile.glb");
    const char *args2[] = { tu_path(path, sizeof path, dir, "scene.json"), "-o", tu_path(out, sizeof out, dir, "hostile.png"),
                            "--aa", "1", "--quiet", NULL };
    static char all[8192];
    tu_run_result res;
    const tu_run_opts opts = { 0, -1, 300 };
    assert_int_equal(tu_run_cli_ex(args2, &opts, all, sizeof all, &res), 0);
    if (res.lines != 1 || !strstr(all, "hostile.ktx2: ") || !strstr(all, "uncompressedByteLength"))
        fail_msg("the hostile KTX2: want one warning naming hostile.ktx2, got '%s'", all);
    print_message("CLI: %s", all);
    free(z);
    free(k);
    free(plain);
    free(png);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_zstd_equals_uncompressed),
        cmocka_unit_test(test_hostile),
        cmocka_unit_test(test_glb_renders),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
