/* Lightmap UVs from xatlas. Soups have no shared vertices, and xatlas grows charts over shared edges,
 * so equal positions are welded first (exact bit patterns, through a hash table), then xatlas charts and
 * packs into one atlas at the lightmap's resolution; should it need more than one atlas, the texel
 * density is lowered until one suffices. */
#include "lightmap_unwrap.h"
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xatlas_c.h>

static uint64_t hash_pos(const float *p)
{
    uint32_t b[3];
    memcpy(b, p, sizeof b);
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (int i = 0; i < 3; i++) { h ^= b[i]; h *= 0xBF58476D1CE4E5B9ull; h ^= h >> 29; }
    return h;
}

int ms_lightmap_unwrap(const float *tri, size_t n, const uint8_t *want, int size, int padding, float *uv,
                       char *err, size_t errlen)
{
    size_t nw = 0;
    for (size_t i = 0; i < n; i++) nw += want[i] != 0;
    for (size_t i = 0; i < n; i++)
        if (want[i]) for (int k = 0; k < 6; k++) uv[6 * i + k] = NAN;
    if (!nw) return 0;
    if (3 * nw > UINT32_MAX / 2) { snprintf(err, errlen, "too many triangles to unwrap"); return -1; }
    /* Weld: open addressing over 2x the corner count. */
    const size_t corners = 3 * nw, cap = 2 * corners;
    uint32_t *slot = malloc(cap * sizeof *slot), *index = malloc(corners * sizeof *index);
    float *pos = malloc(corners * 3 * sizeof *pos);
    size_t *which = malloc(nw * sizeof *which);
    if (!slot || !index || !pos || !which) {
        free(slot); free(index); free(pos); free(which);
        snprintf(err, errlen, "out of memory unwrapping %zu triangles", nw);
        return -1;
    }
    memset(slot, 0xff, cap * sizeof *slot);
    uint32_t nv = 0;
    size_t f = 0;
    for (size_t i = 0; i < n; i++) {
        if (!want[i]) continue;
        which[f] = i;
        for (int k = 0; k < 3; k++) {
            const float *p = tri + 9 * i + 3 * k;
            size_t h = (size_t)(hash_pos(p) % cap);
            while (slot[h] != UINT32_MAX && memcmp(pos + 3 * (size_t)slot[h], p, 3 * sizeof(float))) h = (h + 1) % cap;
            if (slot[h] == UINT32_MAX) { slot[h] = nv; memcpy(pos + 3 * (size_t)nv, p, 3 * sizeof(float)); nv++; }
            index[3 * f + (size_t)k] = slot[h];
        }
        f++;
    }
    free(slot);

    int rc = -1, told = 0;
    float density = 0.0f;   /* 0: xatlas estimates it from the resolution */
    for (int attempt = 0; attempt < 12; attempt++) {
        xatlasAtlas *atlas = xatlasCreate();
        if (!atlas) { snprintf(err, errlen, "xatlas: out of memory"); told = 1; break; }
        xatlasMeshDecl decl;
        xatlasMeshDeclInit(&decl);
        decl.vertexPositionData = pos;
        decl.vertexCount = nv;
        decl.vertexPositionStride = 3 * sizeof(float);
        decl.indexData = index;
        decl.indexCount = (uint32_t)corners;
        decl.indexFormat = XATLAS_INDEX_FORMAT_UINT32;
        xatlasAddMeshError e = xatlasAddMesh(atlas, &decl, 1);
        if (e != XATLAS_ADD_MESH_ERROR_SUCCESS) {
            snprintf(err, errlen, "xatlas: %s", xatlasAddMeshErrorString(e));
            told = 1;
            xatlasDestroy(atlas);
            break;
        }
        xatlasChartOptions co;
        xatlasChartOptionsInit(&co);
        xatlasPackOptions po;
        xatlasPackOptionsInit(&po);
        po.resolution = (uint32_t)size;
        po.padding = (uint32_t)padding;
        po.texelsPerUnit = density;
        po.bilinear = true;
        xatlasGenerate(atlas, &co, &po);
        if (atlas->atlasCount > 1 || atlas->meshCount != 1 || atlas->meshes[0].indexCount != corners) {
            /* more than one atlas: lower the density and try again */
            density = (density > 0.0f ? density : atlas->texelsPerUnit) * 0.8f;
            xatlasDestroy(atlas);
            if (!(density > 0.0f)) break;
            continue;
        }
        const xatlasMesh *m = &atlas->meshes[0];
        const float w = (float)atlas->width, hgt = (float)atlas->height;
        for (size_t t = 0; t < nw; t++) {
            float *u = uv + 6 * which[t];
            int ok = 1;
            for (int k = 0; k < 3; k++) {
                const xatlasVertex *v = &m->vertexArray[m->indexArray[3 * t + (size_t)k]];
                if (v->atlasIndex < 0) ok = 0;
                u[2 * k] = v->uv[0] / w;
                u[2 * k + 1] = v->uv[1] / hgt;
            }
            if (!ok) for (int k = 0; k < 6; k++) u[k] = NAN;
        }
        xatlasDestroy(atlas);
        rc = 0;
        break;
    }
    if (rc && !told) snprintf(err, errlen, "xatlas: the charts do not fit one %dx%d atlas", size, size);
    free(index);
    free(pos);
    free(which);
    return rc;
}
