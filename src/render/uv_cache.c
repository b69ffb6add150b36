/* The unwrap cache (uv_cache.h; docs/baking.md, "The unwrap cache"). Unwrapping is the one part of a bake
 * that does not depend on the lights, and on a large asset it costs more than the shadows, so a re-bake
 * after moving a light takes the layout from the file the previous bake wrote. The file carries the hash
 * of what the layout depends on; a file made for anything else (other geometry, UV sets, scales, size,
 * padding, density or chart tuning) is not used, and a checksum over the payload catches a damaged one.
 *
 * Layout: 16 bytes of magic, then key, triangles, objects (uint64), pages (uint32), 4 zero bytes; per
 * triangle its page (uint32) and 6 UVs (float32); per object its set (int32) and 4 scale-offset floats;
 * a uint64 checksum of everything after the magic. Native byte order (little-endian on every machine
 * microshadow builds for). */
#include "uv_cache.h"
#include "core/abi.h"
#include "xatlas_meshes.h"   /* ms_chart_padding */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char magic[16] = "MSUVCACHE\0\0\0\0\0\0\1";

typedef struct hasher { uint64_t h; } hasher;

static void hash_bytes(hasher *s, const void *data, size_t n)
{
    const unsigned char *p = data;
    uint64_t h = s->h;
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {   /* 8 bytes at a time: the positions of a large asset are tens of MB */
        uint64_t w;
        memcpy(&w, p + i, 8);
        h = (h ^ w) * 0x9E3779B97F4A7C15ull;
        h ^= h >> 32;
    }
    for (; i < n; i++) h = (h ^ p[i]) * 0x100000001B3ull;
    s->h = h;
}

uint64_t ms_uv_cache_key(const ms_scene *sc, const ms_bake_uv_params *p)
{
    hasher s = { 0xCBF29CE484222325ull };
    const uint64_t n = sc->n_tris;
    hash_bytes(&s, magic, sizeof magic);
    hash_bytes(&s, &n, sizeof n);
    if (sc->tri) hash_bytes(&s, sc->tri, (size_t)n * 9 * sizeof(float));
    const uint64_t nobj = ms_bake_uv_objects(sc), nm = sc->n_meshes;
    hash_bytes(&s, &nobj, sizeof nobj);
    if (sc->tri_object) hash_bytes(&s, sc->tri_object, (size_t)n * sizeof(uint32_t));
    if (sc->tri_mesh) hash_bytes(&s, sc->tri_mesh, (size_t)n * sizeof(uint32_t));
    hash_bytes(&s, &nm, sizeof nm);
    if (sc->mesh_lightmap_scale) hash_bytes(&s, sc->mesh_lightmap_scale, (size_t)nm * sizeof(float));
    for (int u = 0; u < MS_MAX_UV_SETS; u++) {
        const int has = sc->tri_uv[u] != NULL;
        hash_bytes(&s, &has, sizeof has);
        if (has) hash_bytes(&s, sc->tri_uv[u], (size_t)n * 6 * sizeof(float));
    }
    /* the padding as the packers apply it (a cache laid out by an earlier rule for the same number is remade) */
    const int ints[5] = { p->uv_set, p->size, p->padding, (int)p->packing, ms_chart_padding(p->padding) };
    hash_bytes(&s, ints, sizeof ints);
    hash_bytes(&s, &p->density, sizeof p->density);
    ms_unwrap_tuning tu;   /* the chart weights: a cache charted with other weights is not used */
    memset(&tu, 0, sizeof tu);
    ms_lightmap_unwrap_tuning_default(&tu);
    hash_bytes(&s, &tu, sizeof tu);
    return s.h;
}

typedef struct header {
    uint64_t key, n_tris, n_objects;
    uint32_t pages, zero;
} header;

ms_status ms_bake_write_uv_cache_abi(const ms_abi *abi, const ms_lightmap *lm, FILE *out, const char *name, char *err,
                                     size_t errlen)
{
    const ms_status ast = ms_abi_check(abi, "ms_bake_write_uv_cache", err, errlen);
    if (ast) return ast;
    if (!lm || !out || !lm->uv || !lm->page || (lm->n_objects && (!lm->object_uv_set || !lm->object_scale_offset))) {
        snprintf(err, errlen, "%s: no lightmap layout to write", name ? name : "UV cache");
        return MS_ERR_INVALID;
    }
    header hd = { lm->uv_key, lm->n_tris, lm->n_objects, (uint32_t)lm->pages, 0 };
    hasher s = { 0xCBF29CE484222325ull };
    const struct { const void *p; size_t n; } part[] = {
        { &hd, sizeof hd },
        { lm->page, lm->n_tris * sizeof *lm->page },
        { lm->uv, lm->n_tris * 6 * sizeof *lm->uv },
        { lm->object_uv_set, lm->n_objects * sizeof *lm->object_uv_set },
        { lm->object_scale_offset, lm->n_objects * 4 * sizeof *lm->object_scale_offset },
    };
    int ok = fwrite(magic, 1, sizeof magic, out) == sizeof magic;
    for (size_t i = 0; i < sizeof part / sizeof part[0] && ok; i++) {
        hash_bytes(&s, part[i].p, part[i].n);
        ok = part[i].n == 0 || fwrite(part[i].p, 1, part[i].n, out) == part[i].n;
    }
    ok = ok && fwrite(&s.h, sizeof s.h, 1, out) == 1;
    if (!ok) { snprintf(err, errlen, "%s: write failed: %s", name ? name : "UV cache", strerror(errno)); return MS_ERR_IO; }
    return MS_OK;
}

int ms_uv_cache_read(const char *path, uint64_t key, size_t n_tris, size_t n_objects, ms_bake_uv_layout *out, char *why,
                     size_t whylen)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        if (errno == ENOENT) return 0;
        snprintf(why, whylen, "cannot be read (%s)", strerror(errno));
        return -1;
    }
    char m[16];
    header hd;
    int rc = -1;
    uint32_t *page = NULL;
    float *uv = NULL, *so = NULL;
    int *set = NULL;
    if (fread(m, 1, sizeof m, f) != sizeof m || memcmp(m, magic, sizeof m)) { snprintf(why, whylen, "is not a microshadow UV cache"); goto out; }
    if (fread(&hd, sizeof hd, 1, f) != 1) { snprintf(why, whylen, "is truncated"); goto out; }
    if (hd.key != key || hd.n_tris != n_tris || hd.n_objects != n_objects) {
        snprintf(why, whylen, "was made for other geometry or UV options (key %016llx, %llu triangles; this bake: %016llx, %zu)",
                 (unsigned long long)hd.key, (unsigned long long)hd.n_tris, (unsigned long long)key, n_tris);
        goto out;
    }
    if (hd.pages < 1 || hd.pages > 65536) { snprintf(why, whylen, "is corrupt (%u pages)", hd.pages); goto out; }
    page = malloc((n_tris ? n_tris : 1) * sizeof *page);
    uv = malloc((n_tris ? n_tris : 1) * 6 * sizeof *uv);
    set = malloc((n_objects ? n_objects : 1) * sizeof *set);
    so = malloc((n_objects ? n_objects : 1) * 4 * sizeof *so);
    if (!page || !uv || !set || !so) { snprintf(why, whylen, "does not fit in memory"); goto out; }
    uint64_t sum;
    if (fread(page, sizeof *page, n_tris, f) != n_tris || fread(uv, 6 * sizeof *uv, n_tris, f) != n_tris ||
        fread(set, sizeof *set, n_objects, f) != n_objects || fread(so, 4 * sizeof *so, n_objects, f) != n_objects ||
        fread(&sum, sizeof sum, 1, f) != 1) {
        snprintf(why, whylen, "is truncated");
        goto out;
    }
    hasher s = { 0xCBF29CE484222325ull };
    hash_bytes(&s, &hd, sizeof hd);
    hash_bytes(&s, page, n_tris * sizeof *page);
    hash_bytes(&s, uv, n_tris * 6 * sizeof *uv);
    hash_bytes(&s, set, n_objects * sizeof *set);
    hash_bytes(&s, so, n_objects * 4 * sizeof *so);
    if (s.h != sum || fgetc(f) != EOF) { snprintf(why, whylen, "is corrupt (its checksum or length does not match)"); goto out; }
    for (size_t t = 0; t < n_tris; t++)
        if (page[t] >= hd.pages) { snprintf(why, whylen, "is corrupt (triangle %zu on page %u of %u)", t, page[t], hd.pages); goto out; }
    memcpy(out->page, page, n_tris * sizeof *page);
    memcpy(out->uv, uv, n_tris * 6 * sizeof *uv);
    memcpy(out->object_set, set, n_objects * sizeof *set);
    memcpy(out->object_scale_offset, so, n_objects * 4 * sizeof *so);
    out->pages = (int)hd.pages;
    rc = 1;
out:
    fclose(f);
    free(page);
    free(uv);
    free(set);
    free(so);
    return rc;
}
