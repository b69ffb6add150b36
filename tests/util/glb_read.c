#include "glb_read.h"
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint32_t rd32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }

int tu_glb_read(const char *path, tu_glb *g)
{
    memset(g, 0, sizeof *g);
    FILE *f = fopen(path, "rb");
    if (!f) { printf("glb_read: %s: cannot open\n", path); return -1; }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    g->file = malloc(n > 0 ? (size_t)n : 1);
    if (!g->file || n < 28 || fread(g->file, 1, (size_t)n, f) != (size_t)n) { fclose(f); printf("glb_read: %s: short\n", path); tu_glb_free(g); return -1; }
    fclose(f);
    g->len = (size_t)n;
    const unsigned char *p = g->file;
    if (rd32(p) != 0x46546C67u || rd32(p + 4) != 2 || rd32(p + 8) != g->len) { printf("glb_read: %s: bad header\n", path); tu_glb_free(g); return -1; }
    const uint32_t jl = rd32(p + 12);
    if (rd32(p + 16) != 0x4E4F534Au || jl % 4 || 20 + (size_t)jl > g->len) { printf("glb_read: %s: bad JSON chunk\n", path); tu_glb_free(g); return -1; }
    g->json = cJSON_ParseWithLength((const char *)p + 20, jl);
    if (!g->json) { printf("glb_read: %s: JSON does not parse\n", path); tu_glb_free(g); return -1; }
    const size_t b = 20 + (size_t)jl;
    if (b + 8 <= g->len) {
        const uint32_t bl = rd32(p + b);
        if (rd32(p + b + 4) != 0x004E4942u || b + 8 + (size_t)bl != g->len) { printf("glb_read: %s: bad BIN chunk\n", path); tu_glb_free(g); return -1; }
        g->bin = p + b + 8;
        g->bin_len = bl;
    }
    return 0;
}

void tu_glb_free(tu_glb *g)
{
    cJSON_Delete(g->json);
    free(g->file);
    memset(g, 0, sizeof *g);
}

const cJSON *tu_glb_item(const tu_glb *g, const char *name, int k)
{
    return cJSON_GetArrayItem(cJSON_GetObjectItem(g->json, name), k);
}

static int num(const cJSON *o, const char *k, double def)
{
    const cJSON *v = cJSON_GetObjectItem(o, k);
    return cJSON_IsNumber(v) ? (int)v->valuedouble : (int)def;
}

/* The bytes of bufferView v: pointer and length, NULL when out of the chunk. */
static const unsigned char *view_bytes(const tu_glb *g, int v, size_t *len)
{
    const cJSON *bv = tu_glb_item(g, "bufferViews", v);
    if (!bv || num(bv, "buffer", -1) != 0) return NULL;
    const size_t off = (size_t)num(bv, "byteOffset", 0), n = (size_t)num(bv, "byteLength", -1);
    if (off > g->bin_len || n > g->bin_len - off) return NULL;
    *len = n;
    return g->bin + off;
}

static void *accessor(const tu_glb *g, int acc, int want_type, size_t *count, int *comps)
{
    const cJSON *a = tu_glb_item(g, "accessors", acc);
    if (!a || num(a, "componentType", 0) != want_type) return NULL;
    const char *t = cJSON_GetStringValue(cJSON_GetObjectItem(a, "type"));
    const int c = !t ? 0 : !strcmp(t, "SCALAR") ? 1 : !strcmp(t, "VEC2") ? 2 : !strcmp(t, "VEC3") ? 3 : !strcmp(t, "VEC4") ? 4 : 0;
    size_t vl;
    const unsigned char *v = view_bytes(g, num(a, "bufferView", -1), &vl);
    const size_t n = (size_t)num(a, "count", 0), off = (size_t)num(a, "byteOffset", 0);
    if (!c || !v || off + n * (size_t)c * 4 > vl) return NULL;
    void *out = malloc(n * (size_t)c * 4 + 4);
    if (!out) return NULL;
    memcpy(out, v + off, n * (size_t)c * 4);
    *count = n;
    if (comps) *comps = c;
    return out;
}

float *tu_glb_floats(const tu_glb *g, int acc, size_t *count, int *comps) { return accessor(g, acc, 5126, count, comps); }

uint32_t *tu_glb_indices(const tu_glb *g, int acc, size_t *count)
{
    int c;
    uint32_t *p = accessor(g, acc, 5125, count, &c);
    if (p && c != 1) { free(p); return NULL; }
    return p;
}

uint8_t *tu_glb_texture(const tu_glb *g, int tex, int channels, int *w, int *h)
{
    const cJSON *t = tu_glb_item(g, "textures", tex);
    const cJSON *im = t ? tu_glb_item(g, "images", num(t, "source", -1)) : NULL;
    if (!im || strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(im, "mimeType")) ? cJSON_GetStringValue(cJSON_GetObjectItem(im, "mimeType")) : "", "image/png")) return NULL;
    size_t len;
    const unsigned char *bytes = view_bytes(g, num(im, "bufferView", -1), &len);
    if (!bytes) return NULL;
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&img, bytes, len)) return NULL;
    /* the stored values as they are: no gamma or colour-space change */
    img.format = channels == 4 ? PNG_FORMAT_RGBA : PNG_FORMAT_RGB;
    uint8_t *px = malloc((size_t)img.width * img.height * (size_t)channels);
    if (!px || !png_image_finish_read(&img, NULL, px, 0, NULL)) { free(px); png_image_free(&img); return NULL; }
    *w = (int)img.width;
    *h = (int)img.height;
    return px;
}
