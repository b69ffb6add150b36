/* Lightmap UVs from xatlas (lightmap_unwrap.h). Soups have no shared vertices, and xatlas grows charts over
 * shared edges, so equal positions are welded first (exact bit patterns, through a hash table), per group:
 * each group (an object) is its own xatlas mesh, which xatlas's task scheduler charts on its worker threads
 * in parallel. Charts are computed once; packing is repeated at a lower density only when a single atlas
 * was asked for and the charts did not fit one. */
#include "lightmap_unwrap.h"
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "xatlas_meshes.h"

/* xatlas's defaults (normal deviation 2, roundness 0.01, straightness 6, normal seam 4, texture seam 0.5,
 * max cost 2, 1 iteration) cut scanned and finely tessellated surfaces into thousands of charts a few
 * texels wide: every chart boundary is a seam to stitch and padding to pay. Welded soups carry no normals
 * and no texture seams for xatlas to respect, so what limits a chart is its normal deviation against
 * maxCost: a higher maxCost and a low straightness weight (ragged boundaries cost little in a lightmap,
 * whose texels are interpolated anyway) let charts grow over curved surfaces as long as the
 * parameterization stays valid (xatlas splits a chart whose LSCM flips or overlaps). Measured on real
 * assets (docs/notebook/2026-11-29-lightmap-charts.md); one iteration, as more cost seconds per pass. */
void ms_lightmap_unwrap_tuning_default(ms_unwrap_tuning *t)
{
    t->normal_deviation = 1.0f;
    t->roundness = 0.01f;
    t->straightness = 1.0f;
    t->normal_seam = 4.0f;
    t->texture_seam = 0.5f;
    t->max_cost = 8.0f;
    t->max_iterations = 1;
}

static uint64_t hash_pos(const float *p)
{
    uint32_t b[3];
    memcpy(b, p, sizeof b);
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (int i = 0; i < 3; i++) { h ^= b[i]; h *= 0xBF58476D1CE4E5B9ull; h ^= h >> 29; }
    return h;
}

/* Wanted triangles ordered by group (stable), for one mesh per group. */
typedef struct order_rec { uint32_t group; size_t tri; } order_rec;

static int cmp_order(const void *a, const void *b)
{
    const order_rec *p = a, *q = b;
    if (p->group != q->group) return p->group < q->group ? -1 : 1;
    return (p->tri > q->tri) - (p->tri < q->tri);
}

int ms_lightmap_unwrap(const float *tri, size_t n, const uint8_t *want, const uint32_t *group, int size, int padding,
                       float density, float *uv, uint32_t *atlas_of, ms_unwrap_info *info,
                       char *err, size_t errlen)
{
    ms_unwrap_info dummy;
    if (!info) info = &dummy;
    memset(info, 0, sizeof *info);
    size_t nw = 0;
    for (size_t i = 0; i < n; i++) nw += want[i] != 0;
    for (size_t i = 0; i < n; i++)
        if (want[i]) {
            for (int k = 0; k < 6; k++) uv[6 * i + k] = NAN;
            if (atlas_of) atlas_of[i] = 0;
        }
    if (!nw) return 0;
    if (3 * nw > UINT32_MAX / 2) { snprintf(err, errlen, "too many triangles to unwrap"); return -1; }
    const size_t corners = 3 * nw, cap = 2 * corners;
    order_rec *ord = malloc(nw * sizeof *ord);
    uint32_t *slot = malloc(cap * sizeof *slot), *index = malloc(corners * sizeof *index);
    float *pos = malloc(corners * 3 * sizeof *pos);
    size_t *seg = malloc((nw + 1) * sizeof *seg), *vbase = malloc((nw + 1) * sizeof *vbase);
    if (!ord || !slot || !index || !pos || !seg || !vbase) {
        free(ord); free(slot); free(index); free(pos); free(seg); free(vbase);
        snprintf(err, errlen, "out of memory unwrapping %zu triangles", nw);
        return -1;
    }
    size_t f = 0;
    for (size_t i = 0; i < n; i++)
        if (want[i]) { ord[f].group = group ? group[i] : 0; ord[f].tri = i; f++; }
    qsort(ord, nw, sizeof *ord, cmp_order);
    /* Weld per group: open addressing over 2x the corner count; a slot of an earlier group's vertex (below
     * v0) never matches, so one table serves every group. */
    memset(slot, 0xff, cap * sizeof *slot);
    size_t ng = 0, nv = 0;
    for (size_t a = 0, b; a < nw; a = b) {
        for (b = a; b < nw && ord[b].group == ord[a].group; b++) {}
        seg[ng] = a;
        vbase[ng] = nv;
        ng++;
        const size_t v0 = nv;
        for (size_t t = a; t < b; t++)
            for (int k = 0; k < 3; k++) {
                const float *p = tri + 9 * ord[t].tri + 3 * k;
                size_t h = (size_t)(hash_pos(p) % cap);
                while (slot[h] != UINT32_MAX && (slot[h] < v0 || memcmp(pos + 3 * (size_t)slot[h], p, 3 * sizeof(float))))
                    h = (h + 1) % cap;
                if (slot[h] == UINT32_MAX) { slot[h] = (uint32_t)nv; memcpy(pos + 3 * nv, p, 3 * sizeof(float)); nv++; }
                index[3 * t + (size_t)k] = slot[h] - (uint32_t)v0;
            }
    }
    seg[ng] = nw;
    vbase[ng] = nv;
    free(slot);
    /* xatlas drops triangles of area <= FLT_EPSILON in its units: on a small asset (the FlightHelmet is 0.6 m
     * tall) that is every triangle under half a millimetre. Positions are scaled by a power of two (exact:
     * welded vertices stay equal) so that the wanted triangles span about 1024 units; densities follow. */
    double lo = INFINITY, hi = -INFINITY;
    for (size_t v = 0; v < 3 * nv; v++) { lo = fmin(lo, pos[v]); hi = fmax(hi, pos[v]); }
    const double g = hi > lo ? ldexp(1.0, (int)floor(log2(1024.0 / (hi - lo)))) : 1.0;
    for (size_t v = 0; v < 3 * nv; v++) pos[v] = (float)(pos[v] * g);

    int rc = -1, told = 0;
    xatlasAtlas *atlas = xatlasCreate();
    if (!atlas) { snprintf(err, errlen, "xatlas: out of memory"); told = 1; goto out; }
    const xatlasAddMeshError e = ms_xatlas_add_meshes(atlas, 3, pos, vbase, index, seg, ng);
    if (e != XATLAS_ADD_MESH_ERROR_SUCCESS) {
        snprintf(err, errlen, "xatlas: %s", xatlasAddMeshErrorString(e));
        told = 1;
        goto out;
    }
    xatlasAddMeshJoin(atlas);
    ms_unwrap_tuning tu;
    ms_lightmap_unwrap_tuning_default(&tu);
    xatlasChartOptions co;
    xatlasChartOptionsInit(&co);
    co.normalDeviationWeight = tu.normal_deviation;
    co.roundnessWeight = tu.roundness;
    co.straightnessWeight = tu.straightness;
    co.normalSeamWeight = tu.normal_seam;
    co.textureSeamWeight = tu.texture_seam;
    co.maxCost = tu.max_cost;
    co.maxIterations = tu.max_iterations;
    xatlasComputeCharts(atlas, &co);
    float tpu = (float)(density / g);   /* in xatlas's units; 0: xatlas estimates it from the resolution */
    for (int attempt = 0; attempt < 12; attempt++) {
        xatlasPackOptions po;
        xatlasPackOptionsInit(&po);
        po.resolution = (uint32_t)size;
        ms_xatlas_pack_padding(&po, padding);
        po.texelsPerUnit = tpu;
        xatlasPackCharts(atlas, &po);
        if (atlas->meshCount != ng) break;
        if (density <= 0.0f && atlas->atlasCount > 1) {   /* one atlas wanted: lower the density, pack again */
            tpu = (tpu > 0.0f ? tpu : atlas->texelsPerUnit) * 0.8f;
            if (!(tpu > 0.0f)) break;
            continue;
        }
        const float w = (float)atlas->width, hgt = (float)atlas->height;
        for (size_t g = 0; g < ng; g++) {
            const xatlasMesh *m = &atlas->meshes[g];
            if (m->indexCount != 3 * (seg[g + 1] - seg[g])) { snprintf(err, errlen, "xatlas: a mesh lost triangles"); told = 1; goto out; }
            for (size_t t = seg[g]; t < seg[g + 1]; t++) {
                float *u = uv + 6 * ord[t].tri;
                int ok = 1, at = -1;
                for (int k = 0; k < 3; k++) {
                    const xatlasVertex *v = &m->vertexArray[m->indexArray[3 * (t - seg[g]) + (size_t)k]];
                    if (v->atlasIndex < 0 || (at >= 0 && v->atlasIndex != at)) ok = 0;
                    at = v->atlasIndex;
                    u[2 * k] = v->uv[0] / w;
                    u[2 * k + 1] = v->uv[1] / hgt;
                }
                if (!ok) for (int k = 0; k < 6; k++) u[k] = NAN;
                else if (atlas_of) atlas_of[ord[t].tri] = (uint32_t)at;
            }
        }
        info->charts = atlas->chartCount;
        info->atlases = atlas->atlasCount;
        info->texels_per_unit = (float)(atlas->texelsPerUnit * g);
        rc = 0;
        break;
    }
out:
    if (rc && !told) snprintf(err, errlen, "xatlas: the charts do not fit one %dx%d atlas", size, size);
    if (atlas) xatlasDestroy(atlas);
    free(ord);
    free(index);
    free(pos);
    free(seg);
    free(vbase);
    return rc;
}
