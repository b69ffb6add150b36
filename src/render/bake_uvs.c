/* The UVs a bake bakes into (microshadow.h, "Lightmap baking"; docs/baking.md, "UVs that respect the asset").
 *
 * Per object (ms_scene.tri_object: a glTF node's mesh, a file of another format), the triangles that have the
 * chosen UV set keep the asset's charts; the rest get xatlas charts. The file's UVs are kept exactly when they
 * can be: every baked triangle has the set, no two objects cover the same texel centre, all lie in [0,1]^2
 * and every mesh's texel-density weight is 1. Otherwise each object with the set (when objects overlap, as
 * the Unity/Bevy convention of a 0-1 lightmap UV set per object makes them) or the file's layout as a whole
 * (when they do not) is fitted into a rectangle of its own - one scale and one offset, like Unity's
 * lightmapScaleOffset, so every chart keeps its shape - and xatlas charts the triangles without the set
 * into one more rectangle. A rectangle's area is proportional to the world area it carries times the square
 * of its mesh's "lightmap": {"scale": s}, divided by the fraction of its UV rectangle the charts cover, so
 * texel density per world unit is the same everywhere (times s); rectangles are packed on shelves, `padding`
 * texels apart, at the largest common scale that fits (bisection). Never a silent change: a warning says
 * when and why the file's UVs were moved. */
#include "bake_uvs.h"
#include "lightmap_unwrap.h"
#include "scene/scene_internal.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint32_t object_of(const ms_scene *sc, size_t t)
{
    if (sc->tri_object) return sc->tri_object[t];
    return sc->tri_mesh ? sc->tri_mesh[t] : 0;
}

static size_t object_count(const ms_scene *sc)
{
    if (sc->tri_object) return sc->n_objects ? sc->n_objects : 1;
    return sc->tri_mesh && sc->n_meshes ? sc->n_meshes : 1;
}

static float scale_of(const ms_scene *sc, size_t t)
{
    if (!sc->mesh_lightmap_scale || !sc->tri_mesh || sc->tri_mesh[t] >= sc->n_meshes) return 1.0f;
    return sc->mesh_lightmap_scale[sc->tri_mesh[t]];
}

static double world_area(const float *t)
{
    const double e1[3] = { t[3] - t[0], t[4] - t[1], t[5] - t[2] }, e2[3] = { t[6] - t[0], t[7] - t[1], t[8] - t[2] };
    const double c[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
    return 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

static double uv_area(const float *u)
{
    return 0.5 * fabs(((double)u[2] - u[0]) * ((double)u[5] - u[1]) - ((double)u[3] - u[1]) * ((double)u[4] - u[0]));
}

/* A rectangle to place: its aspect (width / height) and weight (area share); where it went, in texels. */
typedef struct rect {
    double aspect, weight;
    double x, y, w, h;
} rect;

static int cmp_height(const void *a, const void *b)
{
    const rect *const *p = a, *const *q = b;
    const double x = (*p)->weight / (*p)->aspect, y = (*q)->weight / (*q)->aspect;   /* h^2 up to the scale */
    return (x < y) - (x > y);
}

/* Shelf packing of the rectangles (order: tallest first) at scale k (w = k sqrt(weight aspect), h = k
 * sqrt(weight / aspect), texels) into size x size with `pad` texels between and around them; 1 if they fit. */
static int shelf_pack(rect *const *order, size_t n, double k, int size, int pad)
{
    double x = pad, y = pad, shelf = 0.0;
    for (size_t i = 0; i < n; i++) {
        rect *r = order[i];
        r->w = k * sqrt(r->weight * r->aspect);
        r->h = k * sqrt(r->weight / r->aspect);
        if (r->w + 2 * pad > size || r->h + 2 * pad > size) return 0;
        if (x + r->w + pad > size) { x = pad; y += ceil(shelf) + pad; shelf = 0.0; }
        r->x = x;
        r->y = y;
        x += ceil(r->w) + pad;
        shelf = fmax(shelf, r->h);
        if (y + r->h + pad > size) return 0;
    }
    return 1;
}

/* Places the rectangles at the largest scale that fits; -1 when none does (size too small for the padding). */
static int pack(rect *rs, size_t n, int size, int pad)
{
    rect **order = malloc((n ? n : 1) * sizeof *order);
    if (!order) return -1;
    for (size_t i = 0; i < n; i++) order[i] = &rs[i];
    qsort(order, n, sizeof *order, cmp_height);
    double lo = 0.0, hi = 0.0;
    for (size_t i = 0; i < n; i++) hi = fmax(hi, fmax(sqrt(rs[i].weight * rs[i].aspect), sqrt(rs[i].weight / rs[i].aspect)));
    hi = size / hi;
    for (int it = 0; it < 50; it++) {
        const double mid = 0.5 * (lo + hi);
        if (shelf_pack(order, n, mid, size, pad)) lo = mid;
        else hi = mid;
    }
    const int ok = lo > 0.0 && shelf_pack(order, n, lo, size, pad);
    free(order);
    return ok ? 0 : -1;
}

/* Per object: the UV rectangle of its triangles with the set, the UV area they cover, the world area. */
typedef struct object_uv {
    double lo[2], hi[2], uv_area, world_area, weight;
    size_t tris;
    int region;
} object_uv;

/* Texel centres that triangles of two different objects both cover, rasterized at size x size. */
static size_t count_overlap(const ms_scene *sc, const float *set, const uint8_t *use, int size, char *err, size_t errlen,
                            int *fail)
{
    const size_t np = (size_t)size * size;
    uint32_t *owner = malloc(np * sizeof *owner);
    if (!owner) { snprintf(err, errlen, "out of memory checking the UVs for overlaps"); *fail = 1; return 0; }
    memset(owner, 0xff, np * sizeof *owner);
    size_t overlap = 0;
    for (size_t t = 0; t < sc->n_tris; t++) {
        if (!use[t]) continue;
        const uint32_t ob = object_of(sc, t);
        double a[3][2];
        for (int k = 0; k < 3; k++) { a[k][0] = set[6 * t + 2 * k] * (double)size; a[k][1] = set[6 * t + 2 * k + 1] * (double)size; }
        const double area = (a[1][0] - a[0][0]) * (a[2][1] - a[0][1]) - (a[1][1] - a[0][1]) * (a[2][0] - a[0][0]);
        if (area == 0.0) continue;
        const double sg = area > 0 ? 1.0 : -1.0;
        double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY };
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 2; d++) { lo[d] = fmin(lo[d], a[k][d]); hi[d] = fmax(hi[d], a[k][d]); }
        const int x0 = (int)fmax(floor(lo[0]), 0.0), x1 = (int)fmin(floor(hi[0]), size - 1.0);
        const int y0 = (int)fmax(floor(lo[1]), 0.0), y1 = (int)fmin(floor(hi[1]), size - 1.0);
        for (int y = y0; y <= y1; y++)
            for (int x = x0; x <= x1; x++) {
                const double p[2] = { x + 0.5, y + 0.5 };
                int in = 1;
                for (int k = 0; k < 3 && in; k++) {
                    const double *s0 = a[k], *s1 = a[(k + 1) % 3];
                    in = sg * ((s1[0] - s0[0]) * (p[1] - s0[1]) - (s1[1] - s0[1]) * (p[0] - s0[0])) > 0.0;
                }
                if (!in) continue;
                uint32_t *o = &owner[(size_t)y * size + x];
                if (*o == UINT32_MAX) *o = ob;
                else if (*o != ob && *o != UINT32_MAX - 1) { overlap++; *o = UINT32_MAX - 1; }   /* counted once */
            }
    }
    free(owner);
    return overlap;
}

int ms_bake_uvs(const ms_scene *sc, int uv_set, int size, int padding, float *uv, ms_bake_uv_report *rep, char *err,
                size_t errlen)
{
    memset(rep, 0, sizeof *rep);
    const size_t n = sc->n_tris, nobj = object_count(sc);
    const float *set = uv_set >= 0 ? sc->tri_uv[uv_set] : NULL;
    uint8_t *use = calloc(n ? n : 1, 1), *want = calloc(n ? n : 1, 1);
    object_uv *ob = calloc(nobj, sizeof *ob);
    float *scaled = NULL, *xuv = NULL;
    rect *rs = NULL;
    int rc = -1;
    if (!use || !want || !ob) { snprintf(err, errlen, "out of memory for the UVs of %zu triangles", n); goto out; }
    for (size_t o = 0; o < nobj; o++) {
        ob[o].lo[0] = ob[o].lo[1] = INFINITY;
        ob[o].hi[0] = ob[o].hi[1] = -INFINITY;
        ob[o].region = -1;
    }
    /* which triangles keep the file's UVs (use), which xatlas charts (want), which are not baked */
    size_t n_use = 0, n_want = 0;
    int inside = 1, weighted = 0;
    double want_weight = 0.0;
    for (size_t t = 0; t < n; t++) {
        for (int k = 0; k < 6; k++) uv[6 * t + k] = NAN;
        const float s = scale_of(sc, t);
        if (!(s > 0.0f)) { rep->excluded++; continue; }
        weighted |= s != 1.0f;
        int ok = set != NULL;
        for (int k = 0; k < 6 && ok; k++) ok = isfinite(set[6 * t + k]);
        if (ok && uv_area(set + 6 * t) == 0.0) ok = 0;   /* a chart without area bakes nothing: chart it anew */
        const double wa = world_area(sc->tri + 9 * t) * (double)s * s;
        if (!ok) { want[t] = 1; n_want++; want_weight += wa; continue; }
        use[t] = 1;
        n_use++;
        object_uv *o = &ob[object_of(sc, t)];
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 2; d++) {
                const double v = set[6 * t + 2 * k + d];
                o->lo[d] = fmin(o->lo[d], v);
                o->hi[d] = fmax(o->hi[d], v);
                inside &= v >= 0.0 && v <= 1.0;
            }
        o->uv_area += uv_area(set + 6 * t);
        o->world_area += wa;
        o->tris++;
    }
    int fail = 0;
    if (n_use) rep->overlap_texels = count_overlap(sc, set, use, size, err, errlen, &fail);
    if (fail) goto out;
    if (!n_want && !rep->overlap_texels && inside && !weighted) {   /* the file's UVs as they are */
        for (size_t t = 0; t < n; t++)
            if (use[t]) memcpy(uv + 6 * t, set + 6 * t, 6 * sizeof(float));
        rc = 0;
        goto out;
    }
    if (!n_use) {   /* xatlas alone, over the whole lightmap */
        rc = 0;
        if (n_want) {
            scaled = malloc(n * 9 * sizeof *scaled);
            if (!scaled) { snprintf(err, errlen, "out of memory for the UVs of %zu triangles", n); rc = -1; goto out; }
            /* texel density by mesh: xatlas sizes charts by world area, so scale each mesh's positions by its s */
            for (size_t t = 0; t < n; t++)
                for (int k = 0; k < 9; k++) scaled[9 * t + k] = sc->tri[9 * t + k] * (want[t] ? scale_of(sc, t) : 1.0f);
            rc = ms_lightmap_unwrap(weighted ? scaled : sc->tri, n, want, size, padding, uv, err, errlen);
            rep->unwrapped = n_want;
        }
        goto out;
    }
    /* Regions: one per object with the set when objects overlap, else one for the file's layout as a whole;
     * one more for xatlas. */
    const int per_object = rep->overlap_texels > 0 || weighted;   /* each mesh's scale needs its own region */
    size_t nr = 0;
    rs = calloc(nobj + 2, sizeof *rs);
    if (!rs) { snprintf(err, errlen, "out of memory for the lightmap's regions"); goto out; }
    object_uv all;
    memset(&all, 0, sizeof all);
    all.lo[0] = all.lo[1] = INFINITY;
    all.hi[0] = all.hi[1] = -INFINITY;
    for (size_t o = 0; o < nobj; o++) {
        if (!ob[o].tris) continue;
        for (int d = 0; d < 2; d++) { all.lo[d] = fmin(all.lo[d], ob[o].lo[d]); all.hi[d] = fmax(all.hi[d], ob[o].hi[d]); }
        all.uv_area += ob[o].uv_area;
        all.world_area += ob[o].world_area;
    }
    for (size_t o = 0; o < nobj + 1; o++) {
        object_uv *q = per_object ? (o < nobj ? &ob[o] : NULL) : (o == nobj ? &all : NULL);
        if (!q || (per_object && !q->tris)) continue;
        const double ew = q->hi[0] - q->lo[0], eh = q->hi[1] - q->lo[1];
        rs[nr].aspect = ew / eh;
        /* world area per covered UV area, times the rectangle's UV area: the same texels per world unit */
        rs[nr].weight = q->world_area / q->uv_area * ew * eh;
        if (!(rs[nr].weight > 0.0) || !isfinite(rs[nr].weight) || !(rs[nr].aspect > 0.0) || !isfinite(rs[nr].aspect)) {
            rs[nr].weight = 1e-12;
            rs[nr].aspect = 1.0;
        }
        q->region = (int)nr++;
    }
    const int xatlas_region = n_want ? (int)nr : -1;
    if (n_want) { rs[nr].aspect = 1.0; rs[nr].weight = want_weight > 0.0 ? want_weight : 1e-12; nr++; }
    /* weights relative to the largest, so that tiny objects do not underflow */
    double wmax = 0.0;
    for (size_t r = 0; r < nr; r++) wmax = fmax(wmax, rs[r].weight);
    for (size_t r = 0; r < nr; r++) rs[r].weight = fmax(rs[r].weight / wmax, 1e-9);
    if (pack(rs, nr, size, padding)) {
        snprintf(err, errlen, "the lightmap's %zu regions do not fit a %dx%d lightmap with %d texels of padding", nr, size, size, padding);
        goto out;
    }
    rep->regions = nr;
    rep->relaid = 1;
    for (size_t t = 0; t < n; t++) {
        if (!use[t]) continue;
        const object_uv *q = per_object ? &ob[object_of(sc, t)] : &all;
        const rect *r = &rs[q->region];
        const double k = r->w / (q->hi[0] - q->lo[0]);   /* = h / (hi[1] - lo[1]): one scale, charts keep their shape */
        for (int c = 0; c < 3; c++) {
            uv[6 * t + 2 * c] = (float)((r->x + (set[6 * t + 2 * c] - q->lo[0]) * k) / size);
            uv[6 * t + 2 * c + 1] = (float)((r->y + (set[6 * t + 2 * c + 1] - q->lo[1]) * k) / size);
        }
    }
    if (n_want) {
        const rect *r = &rs[xatlas_region];
        const int side = (int)floor(fmin(r->w, r->h));
        xuv = malloc(n * 6 * sizeof *xuv);
        scaled = weighted ? malloc(n * 9 * sizeof *scaled) : NULL;
        if (!xuv || (weighted && !scaled)) { snprintf(err, errlen, "out of memory for the UVs of %zu triangles", n); goto out; }
        if (weighted)
            for (size_t t = 0; t < n; t++)
                for (int k = 0; k < 9; k++) scaled[9 * t + k] = sc->tri[9 * t + k] * (want[t] ? scale_of(sc, t) : 1.0f);
        if (side < 1 || ms_lightmap_unwrap(weighted ? scaled : sc->tri, n, want, side, padding, xuv, err, errlen)) {
            if (side < 1) snprintf(err, errlen, "no room left in a %dx%d lightmap for the xatlas charts", size, size);
            goto out;
        }
        for (size_t t = 0; t < n; t++)
            if (want[t])
                for (int c = 0; c < 3; c++) {
                    uv[6 * t + 2 * c] = (float)((r->x + xuv[6 * t + 2 * c] * side) / size);
                    uv[6 * t + 2 * c + 1] = (float)((r->y + xuv[6 * t + 2 * c + 1] * side) / size);
                }
        rep->unwrapped = n_want;
    }
    if (per_object) {
        size_t with = 0;
        for (size_t o = 0; o < nobj; o++) with += ob[o].tris > 0;
        ms_warn("UV set %d: %zu objects' UVs overlap (%zu texel centres covered twice): each object gets its own region "
                "of the lightmap, its UVs scaled and offset (the baked UVs: ms_lightmap.uv, the glTF's TEXCOORD_1)",
                uv_set, with, rep->overlap_texels);
    } else
        ms_warn("UV set %d: the file's UVs are scaled and offset as a whole into a region of the lightmap (%s%s%s; the "
                "baked UVs: ms_lightmap.uv, the glTF's TEXCOORD_1)", uv_set, n_want ? "room for xatlas charts of the triangles without the set" : "",
                n_want && (weighted || !inside) ? ", " : "", weighted ? "per-mesh lightmap scales" : !inside ? "UVs outside [0,1]" : "");
    rc = 0;
out:
    if (rc == 0 && n_want && !rep->unwrapped) rep->unwrapped = n_want;
    free(use);
    free(want);
    free(ob);
    free(scaled);
    free(xuv);
    free(rs);
    return rc;
}
