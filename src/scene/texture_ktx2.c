/* KTX2 (Khronos KTX 2.0) material textures into RGBA8: the container is parsed here, level 0 of an 8-bit
 * uncompressed format is decoded, stored as it is (supercompression scheme 0) or Zstandard-supercompressed
 * (scheme 2, through Debian's libzstd). Basis Universal payloads (KHR_texture_basisu: BasisLZ/ETC1S, UASTC)
 * and block-compressed formats are refused naming what they are: docs/shading.md says why no Basis
 * transcoder is built in.
 *
 * Every length and offset of the file is untrusted: each is checked against the file's size in 64-bit
 * arithmetic before it is used, the image's size against the side limit and the decoded budget before any
 * pixel memory is allocated, and a level's Zstandard data must decompress to exactly the bytes its texels
 * need (libzstd never writes past the capacity it is given). */
#include "scene_internal.h"
#include "microshadow.h"
#include <zstd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { KTX2_HEADER = 80, KTX2_LEVEL_ENTRY = 24, KTX2_MAX_LEVELS = 32 };
enum { KTX2_SC_NONE = 0, KTX2_SC_BASISLZ = 1, KTX2_SC_ZSTD = 2, KTX2_SC_ZLIB = 3 };

static uint32_t rd32(const unsigned char *p) { return p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static uint64_t rd64(const unsigned char *p) { return rd32(p) | (uint64_t)rd32(p + 4) << 32; }

/* The colour model of the file's data format descriptor (KDFS 1.3, basic block: byte 12 of the DFD), which
 * alone says what a vkFormat 0 file holds; 0 when the DFD is absent or outside the file. */
static unsigned dfd_color_model(const unsigned char *buf, size_t len)
{
    const uint32_t off = rd32(buf + 48), n = rd32(buf + 52);
    if (n < 16 || off > len || 16 > len - off) return 0;
    return buf[off + 12];
}

/* The one line for a Basis Universal payload: BasisLZ is ETC1S by definition; vkFormat 0 otherwise names
 * its model in the DFD (KHR_DF_MODEL_ETC1S 163, KHR_DF_MODEL_UASTC 166). */
static void refuse_basis(const unsigned char *buf, size_t len, uint32_t scheme, const char *what, char *err, size_t errlen)
{
    const unsigned model = dfd_color_model(buf, len);
    const char *kind = scheme == KTX2_SC_BASISLZ ? "BasisLZ/ETC1S" : model == 166 ? "UASTC" : model == 163 ? "ETC1S" : NULL;
    const char *sc = scheme == KTX2_SC_ZSTD ? " with Zstandard supercompression" : "";
    if (kind)
        snprintf(err, errlen, "%s: KTX2 Basis Universal %s payload%s (KHR_texture_basisu) is not transcoded: microshadow "
                 "has no Basis transcoder (a PNG/JPEG fallback source is used when the glTF has one)", what, kind, sc);
    else
        snprintf(err, errlen, "%s: KTX2 vkFormat 0 (a format its DFD alone describes, colour model %u)%s is not decoded", what,
                 model, sc);
}

/* Bytes per texel of the 8-bit formats decoded and where R, G, B, A are in a texel (-1: absent); 0 for any
 * other vkFormat. */
static int texel_layout(uint32_t vk, int ch[4])
{
    ch[0] = ch[1] = ch[2] = ch[3] = -1;
    switch (vk) {
    case 9: case 15: ch[0] = 0; return 1;                                      /* R8_UNORM, R8_SRGB */
    case 16: case 22: ch[0] = 0; ch[1] = 1; return 2;                          /* R8G8_UNORM, _SRGB */
    case 23: case 29: ch[0] = 0; ch[1] = 1; ch[2] = 2; return 3;               /* R8G8B8_UNORM, _SRGB */
    case 30: case 36: ch[0] = 2; ch[1] = 1; ch[2] = 0; return 3;               /* B8G8R8_UNORM, _SRGB */
    case 37: case 43: ch[0] = 0; ch[1] = 1; ch[2] = 2; ch[3] = 3; return 4;    /* R8G8B8A8_UNORM, _SRGB */
    case 44: case 50: ch[0] = 2; ch[1] = 1; ch[2] = 0; ch[3] = 3; return 4;    /* B8G8R8A8_UNORM, _SRGB */
    default: return 0;
    }
}

/* Level 0's Zstandard data src[0..n) into dst, which must come out exactly `need` bytes. The frame's own
 * content size, when it states one, is checked first so that a mismatch is named as such; libzstd then
 * decodes one or more frames into the fixed capacity and fails rather than write past it. */
static int unzstd_level(const unsigned char *src, size_t n, uint8_t *dst, size_t need, const char *what, char *err,
                        size_t errlen)
{
    const unsigned long long declared = ZSTD_getFrameContentSize(src, n);
    if (declared == ZSTD_CONTENTSIZE_ERROR) {
        snprintf(err, errlen, "%s: bad KTX2: level 0 is not Zstandard data", what);
        return -1;
    }
    if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared > need) {
        snprintf(err, errlen, "%s: bad KTX2: level 0's Zstandard frame holds %llu bytes, its texels %zu", what, declared, need);
        return -1;
    }
    const size_t got = ZSTD_decompress(dst, need, src, n);
    if (ZSTD_isError(got)) {
        snprintf(err, errlen, "%s: bad KTX2: level 0's Zstandard data: %s", what, ZSTD_getErrorName(got));
        return -1;
    }
    if (got != need) {
        snprintf(err, errlen, "%s: bad KTX2: level 0's Zstandard data holds %zu bytes, its texels %zu", what, got, need);
        return -1;
    }
    return 0;
}

int ms_texture_decode_ktx2(const unsigned char *buf, size_t len, const char *what, int flip_rows, size_t budget,
                           ms_texture *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (len < KTX2_HEADER + KTX2_LEVEL_ENTRY) {
        snprintf(err, errlen, "%s: bad KTX2: %zu bytes, shorter than its header", what, len);
        return -1;
    }
    const uint32_t vk = rd32(buf + 12), w = rd32(buf + 20), h = rd32(buf + 24), depth = rd32(buf + 28),
                   layers = rd32(buf + 32), faces = rd32(buf + 36), levels = rd32(buf + 40), scheme = rd32(buf + 44);
    /* What is not decoded is named before anything else is checked: a file that is simply of another kind
     * gets the reason it is left out, not a complaint about a field. */
    if (scheme == KTX2_SC_BASISLZ || vk == 0) { refuse_basis(buf, len, scheme, what, err, errlen); return -1; }
    if (scheme != KTX2_SC_NONE && scheme != KTX2_SC_ZSTD) {
        snprintf(err, errlen, "%s: KTX2 with %s supercompression is not decoded (none and Zstandard are)", what,
                 scheme == KTX2_SC_ZLIB ? "ZLIB" : "an unknown");
        return -1;
    }
    int ch[4];
    const int bpp = texel_layout(vk, ch);
    if (!bpp) {
        snprintf(err, errlen, "%s: KTX2 vkFormat %u is not decoded (a block-compressed, packed or wider format; 8-bit R, RG, "
                 "RGB, BGR, RGBA, BGRA are)", what, vk);
        return -1;
    }
    if (depth > 1 || layers > 1 || faces != 1) {
        snprintf(err, errlen, "%s: a KTX2 %s is not a 2D texture", what,
                 depth > 1 ? "3D texture" : layers > 1 ? "array" : faces == 6 ? "cube map" : "file with a bad face count");
        return -1;
    }
    if (!ms_texture_size_ok(w, h, budget, what, err, errlen)) return -1;
    /* levelCount 0 means one level stored (the reader may make the rest); a 16384-texel side has 15. */
    const uint32_t nl = levels ? levels : 1;
    if (nl > KTX2_MAX_LEVELS || KTX2_HEADER + (size_t)KTX2_LEVEL_ENTRY * nl > len) {
        snprintf(err, errlen, "%s: bad KTX2: a level index of %u levels past the end of the %zu-byte file", what, levels, len);
        return -1;
    }
    /* Every level inside the file, not only level 0: a file cut short is named as such, whatever level it
     * cuts. */
    for (uint32_t i = 0; i < nl; i++) {
        const uint64_t o = rd64(buf + KTX2_HEADER + KTX2_LEVEL_ENTRY * i), n = rd64(buf + KTX2_HEADER + KTX2_LEVEL_ENTRY * i + 8);
        if (o > len || n > len - o) {
            snprintf(err, errlen, "%s: bad KTX2: level %u (%llu bytes at %llu) past the end of the %zu-byte file", what, i,
                     (unsigned long long)n, (unsigned long long)o, len);
            return -1;
        }
    }
    const uint64_t off = rd64(buf + KTX2_HEADER), n = rd64(buf + KTX2_HEADER + 8), ulen = rd64(buf + KTX2_HEADER + 16);
    const size_t need = (size_t)w * h * (size_t)bpp;
    if (scheme == KTX2_SC_NONE && n < need) {
        snprintf(err, errlen, "%s: bad KTX2: level 0 (%llu bytes) does not hold %ux%u texels of %d bytes", what,
                 (unsigned long long)n, w, h, bpp);
        return -1;
    }
    if (scheme == KTX2_SC_ZSTD && ulen != need) {
        snprintf(err, errlen, "%s: bad KTX2: level 0's uncompressedByteLength %llu, where %ux%u texels of %d bytes are %zu", what,
                 (unsigned long long)ulen, w, h, bpp, need);
        return -1;
    }
    /* The level's bytes go to the start of the RGBA buffer and are widened in place, so a Zstandard level
     * costs no memory beyond the decoded image the budget was checked for. */
    uint8_t *px = malloc((size_t)w * h * 4);
    if (!px) { snprintf(err, errlen, "%s: out of memory for a %ux%u texture", what, w, h); return -1; }
    if (scheme == KTX2_SC_NONE) memcpy(px, buf + off, need);
    else if (unzstd_level(buf + off, (size_t)n, px, need, what, err, errlen)) { free(px); return -1; }
    /* Last texel first: texel i's RGBA (bytes 4i..4i+3) never reaches a texel j < i still to be read (bytes
     * bpp j.. < bpp i <= 4i). */
    for (size_t i = (size_t)w * h; i-- > 0;) {
        const uint8_t *s = px + i * (size_t)bpp;
        uint8_t t[4];
        for (int c = 0; c < 4; c++) t[c] = ch[c] >= 0 ? s[ch[c]] : c == 3 ? 255 : 0;
        memcpy(px + 4 * i, t, 4);
    }
    if (flip_rows)
        for (size_t y = 0; y < h / 2; y++) {
            uint8_t *a = px + y * w * 4, *b = px + (h - 1 - y) * (size_t)w * 4;
            for (size_t k = 0; k < (size_t)w * 4; k++) { const uint8_t t = a[k]; a[k] = b[k]; b[k] = t; }
        }
    out->width = (int)w;
    out->height = (int)h;
    out->rgba = px;
    return 0;
}
