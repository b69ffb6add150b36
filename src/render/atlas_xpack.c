/* Regions and xatlas charts on the same pages through xatlas's bitmap packer (atlas_xpack.h). Rectangles
 * alone (atlas_pack.c) leave the empty space between irregular charts unused; xatlas's packer rasterizes
 * each chart and places it where its texels fit, so the charts of the objects without a layout fill the
 * gaps beside the objects' regions. Each region is a UV mesh of its own (a w x h rectangle: one chart, so
 * its layout keeps one scale and one offset), and the charts of each key another (xatlas groups a UV
 * mesh's triangles into charts by shared UV vertices; separate meshes never merge). */
#include "atlas_xpack.h"
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "xatlas_meshes.h"
#include "atlas_footprints.h"
#include "core/union_find.h"

typedef struct tkey_rec { uint32_t key; uint32_t tri; } tkey_rec;

static int cmp_tkey(const void *a, const void *b)
{
    const tkey_rec *p = a, *q = b;
    if (p->key != q->key) return p->key < q->key ? -1 : 1;
    return (p->tri > q->tri) - (p->tri < q->tri);
}

static uint64_t hash_uv(const float *u)
{
    uint32_t b[2];
    memcpy(b, u, sizeof b);
    uint64_t h = (b[0] * 0x9E3779B97F4A7C15ull) ^ (b[1] + 0x632BE59BD9B4E019ull);
    h ^= h >> 31;
    return h * 0xBF58476D1CE4E5B9ull;
}

/* The packed layout of x (pages used: pages) with no two footprints sharing a texel: the charts (triangles of one
 * xatlas mesh joined by a shared vertex, as xatlas forms them) and regions moved where they did. The pages used;
 * 0 when a chart found no room (x->grow: on the one page; else one larger than a page); -1 when out of memory. */
static int separate(ms_xpack *x, double s, int pages, const tkey_rec *ord, const size_t *seg, const size_t *vseg, const uint32_t *idx,
                    size_t ng)
{
    const size_t nt = x->nt;
    uint32_t *unit = malloc((nt ? nt : 1) * sizeof *unit), *first = malloc((vseg[ng] ? vseg[ng] : 1) * sizeof *first);
    uint32_t *parent = malloc((nt ? nt : 1) * sizeof *parent);
    int rc = -1;
    if (!unit || !first || !parent) goto out;
    for (size_t v = 0; v < vseg[ng]; v++) first[v] = UINT32_MAX;
    for (size_t t = 0; t < nt; t++) parent[t] = (uint32_t)t;
    for (size_t g = 0; g < ng; g++)
        for (size_t t = seg[g]; t < seg[g + 1]; t++)
            for (int k = 0; k < 3; k++) {
                uint32_t *f = &first[vseg[g] + idx[3 * t + (size_t)k]];
                if (*f == UINT32_MAX) *f = (uint32_t)t;
                else ms_uf_union(parent, *f, (uint32_t)t);
            }
    size_t nu = 0;   /* units numbered by their first triangle (sorted order) */
    for (size_t t = 0; t < nt; t++) {
        const uint32_t a = ms_uf_find(parent, (uint32_t)t);
        unit[ord[t].tri] = a == t ? (uint32_t)nu++ : unit[ord[a].tri];
    }
    ms_fp_layout l = { x->size, pages, !x->grow, x->nr, x->rx, x->ry, NULL, NULL, x->rpage, nt, nu, x->out_uv, x->tpage, unit, 0 };
    double *rdim = malloc((x->nr ? x->nr : 1) * 2 * sizeof *rdim);
    if (!rdim) goto out;
    for (size_t i = 0; i < x->nr; i++) { rdim[i] = x->rw[i] * s; rdim[x->nr + i] = x->rh[i] * s; }
    l.rw = rdim;
    l.rh = rdim + x->nr;
    const int fp = ms_fp_separate(&l);
    free(rdim);
    if (fp < 0) goto out;
    rc = fp ? 0 : l.pages;
out:
    free(unit);
    free(first);
    free(parent);
    return rc;
}

int ms_xpack_run(ms_xpack *x, double s, char *err, size_t errlen)
{
    const size_t nt = x->nt, nr = x->nr;
    tkey_rec *ord = malloc((nt ? nt : 1) * sizeof *ord);
    float *vuv = malloc((nt ? 6 * nt : 1) * sizeof *vuv + 8 * (nr ? nr : 1) * sizeof(float));
    uint32_t *idx = malloc((nt ? 3 * nt : 1) * sizeof *idx + 6 * (nr ? nr : 1) * sizeof(uint32_t));
    uint32_t *slot = malloc((nt ? 6 * nt : 1) * sizeof *slot);
    size_t *seg = malloc((nt + 2) * sizeof *seg), *vseg = malloc((nt + 2) * sizeof *vseg);
    xatlasAtlas *atlas = NULL;
    int rc = -1;
    if (!ord || !vuv || !idx || !slot || !seg || !vseg) { snprintf(err, errlen, "out of memory packing the lightmap"); goto out; }
    for (size_t i = 0; i < nr; i++)
        if (!(x->rw[i] * s + 2 * x->pad <= x->size && x->rh[i] * s + 2 * x->pad <= x->size)) {
            snprintf(err, errlen, "a region of %.0f x %.0f texels does not fit a %dx%d page", x->rw[i] * s, x->rh[i] * s, x->size, x->size);
            goto out;
        }
    for (size_t t = 0; t < nt; t++) { ord[t].key = x->tkey[t]; ord[t].tri = (uint32_t)t; }
    qsort(ord, nt, sizeof *ord, cmp_tkey);
    atlas = xatlasCreate();
    if (!atlas) { snprintf(err, errlen, "xatlas: out of memory"); goto out; }
    /* the regions: one rectangle mesh each */
    float *rv = vuv + 6 * nt;
    uint32_t *ri = idx + 3 * nt;
    for (size_t i = 0; i < nr; i++) {
        const float w = (float)(x->rw[i] * s), h = (float)(x->rh[i] * s);
        const float q[8] = { 0, 0, w, 0, w, h, 0, h };
        memcpy(rv + 8 * i, q, sizeof q);
        const uint32_t f[6] = { 0, 1, 2, 0, 2, 3 };
        memcpy(ri + 6 * i, f, sizeof f);
        xatlasUvMeshDecl d;
        xatlasUvMeshDeclInit(&d);
        d.vertexUvData = rv + 8 * i;
        d.vertexCount = 4;
        d.vertexStride = 2 * sizeof(float);
        d.indexData = ri + 6 * i;
        d.indexCount = 6;
        d.indexFormat = XATLAS_INDEX_FORMAT_UINT32;
        if (xatlasAddUvMesh(atlas, &d) != XATLAS_ADD_MESH_ERROR_SUCCESS) { snprintf(err, errlen, "xatlas: a region was refused"); goto out; }
    }
    /* the charts: per key, vertices welded by their UV (bits), scaled */
    size_t ng = 0, nv = 0;
    const size_t cap = 6 * (nt ? nt : 1);
    memset(slot, 0xff, cap * sizeof *slot);
    for (size_t a = 0, b; a < nt; a = b) {
        for (b = a; b < nt && ord[b].key == ord[a].key; b++) {}
        seg[ng] = a;
        vseg[ng] = nv;
        const size_t v0 = nv;
        for (size_t t = a; t < b; t++)
            for (int k = 0; k < 3; k++) {
                const float *u = x->tuv + 6 * (size_t)ord[t].tri + 2 * k;
                size_t h = (size_t)(hash_uv(u) % cap);
                while (slot[h] != UINT32_MAX && (slot[h] < v0 || memcmp(vuv + 2 * (size_t)slot[h], u, 2 * sizeof(float)))) h = (h + 1) % cap;
                if (slot[h] == UINT32_MAX) { slot[h] = (uint32_t)nv; memcpy(vuv + 2 * nv, u, 2 * sizeof(float)); nv++; }
                idx[3 * t + (size_t)k] = slot[h] - (uint32_t)v0;
            }
        ng++;
    }
    seg[ng] = nt;
    vseg[ng] = nv;
    for (size_t v = 0; v < nv; v++) {   /* scaled after welding: equal UVs stay equal */
        vuv[2 * v] = (float)(vuv[2 * v] * s);
        vuv[2 * v + 1] = (float)(vuv[2 * v + 1] * s);
    }
    if (ms_xatlas_add_meshes(atlas, 2, vuv, vseg, idx, seg, ng) != XATLAS_ADD_MESH_ERROR_SUCCESS) {
        snprintf(err, errlen, "xatlas: charts were refused");
        goto out;
    }
    xatlasChartOptions co;
    xatlasChartOptionsInit(&co);
    xatlasComputeCharts(atlas, &co);
    xatlasPackOptions po;
    xatlasPackOptionsInit(&po);
    po.resolution = x->grow ? 0 : (uint32_t)x->size;
    ms_xatlas_pack_padding(&po, x->pad);
    po.texelsPerUnit = 1.0f;   /* UVs are texels already */
    po.rotateCharts = false;
    po.rotateChartsToAxis = false;
    xatlasPackCharts(atlas, &po);
    if (atlas->meshCount != nr + ng) { snprintf(err, errlen, "xatlas: %u meshes packed of %zu", atlas->meshCount, nr + ng); goto out; }
    for (size_t i = 0; i < nr; i++) {
        const xatlasMesh *m = &atlas->meshes[i];
        double lo[2] = { INFINITY, INFINITY };
        x->rpage[i] = -1;
        for (uint32_t v = 0; v < m->vertexCount; v++) {
            lo[0] = fmin(lo[0], m->vertexArray[v].uv[0]);
            lo[1] = fmin(lo[1], m->vertexArray[v].uv[1]);
            x->rpage[i] = m->vertexArray[v].atlasIndex;
        }
        if (x->rpage[i] < 0) { snprintf(err, errlen, "xatlas: a region was not packed"); goto out; }
        x->rx[i] = lo[0];
        x->ry[i] = lo[1];
    }
    for (size_t g = 0; g < ng; g++) {
        const xatlasMesh *m = &atlas->meshes[nr + g];
        for (size_t t = seg[g]; t < seg[g + 1]; t++) {
            float *u = x->out_uv + 6 * (size_t)ord[t].tri;
            for (int k = 0; k < 3; k++) {
                const xatlasVertex *v = &m->vertexArray[m->indexArray[3 * (t - seg[g]) + (size_t)k]];
                u[2 * k] = v->uv[0];
                u[2 * k + 1] = v->uv[1];
                x->tpage[ord[t].tri] = v->atlasIndex < 0 ? 0 : (uint32_t)v->atlasIndex;
            }
        }
    }
    rc = (int)(atlas->atlasCount ? atlas->atlasCount : 1);
    if (x->grow) {   /* one atlas of the size it took: moved to (pad, pad); 2 when it exceeds the page */
        double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY };
        for (size_t i = 0; i < nr; i++) {
            lo[0] = fmin(lo[0], x->rx[i]);
            lo[1] = fmin(lo[1], x->ry[i]);
            hi[0] = fmax(hi[0], x->rx[i] + x->rw[i] * s);
            hi[1] = fmax(hi[1], x->ry[i] + x->rh[i] * s);
        }
        for (size_t i = 0; i < 6 * nt; i++) {
            lo[i & 1] = fmin(lo[i & 1], x->out_uv[i]);
            hi[i & 1] = fmax(hi[i & 1], x->out_uv[i]);
        }
        /* by whole texels: xatlas puts chart edges on texel centres, where footprints end (footprint.h) */
        const double sx = x->pad - floor(lo[0]), sy = x->pad - floor(lo[1]);
        for (size_t i = 0; i < nr; i++) { x->rx[i] += sx; x->ry[i] += sy; x->rpage[i] = 0; }
        for (size_t i = 0; i < 6 * nt; i++) x->out_uv[i] = (float)(x->out_uv[i] + ((i & 1) ? sy : sx));
        for (size_t t = 0; t < nt; t++) x->tpage[t] = 0;
        x->extent = fmax(hi[0] - lo[0], hi[1] - lo[1]);
        rc = hi[0] + sx + x->pad <= x->size && hi[1] + sy + x->pad <= x->size ? 1 : 2;
    }
    if (!x->grow || rc == 1) {   /* footprints made disjoint (atlas_footprints.h) */
        const int fp = separate(x, s, rc, ord, seg, vseg, idx, ng);
        if (fp < 0) { snprintf(err, errlen, "out of memory packing the lightmap"); rc = -1; goto out; }
        if (!fp && !x->grow) { snprintf(err, errlen, "a lightmap chart does not fit a %dx%d page", x->size, x->size); rc = -1; goto out; }
        rc = fp ? fp : 2;
    }
out:
    if (atlas) xatlasDestroy(atlas);
    free(ord);
    free(vuv);
    free(idx);
    free(slot);
    free(seg);
    free(vseg);
    return rc;
}
