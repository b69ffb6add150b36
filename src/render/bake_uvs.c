/* The UVs a bake bakes into (microshadow/bake.h, "Lightmap baking"; docs/baking.md, "Charts").
 *
 * Per object (ms_scene.tri_object: a glTF node's mesh, a file of another format), the first of its UV sets
 * (the one asked for, then 0, 1, ...) that is a valid layout of the object (uv_validity.c: present on every
 * triangle, with area, no two triangles overlapping) is kept: its charts keep their shape and placement, one
 * scale and one offset for the object (Unity's lightmapScaleOffset). Objects with none get xatlas charts.
 * The file's UVs are kept exactly when every object uses the same set, no two objects cover the same texel
 * centre, all lie in [0,1]^2, every mesh's texel-density weight is 1 and no density is asked for. Otherwise
 * every object with a layout (or the file's layout as a whole, when objects do not overlap) gets a
 * rectangle of its own, and xatlas charts the rest. A rectangle's area is proportional to the world area it
 * carries times the square of its mesh's "lightmap": {"scale": s}, divided by the fraction of its UV
 * rectangle the charts cover, so that every object gets the same texels per world unit (times s); with a
 * density T that is T texels per world unit. Rectangles alone are packed by atlas_pack.c; with xatlas
 * charts, xatlas's packer places rectangles and charts together (atlas_xpack.c). Without a density
 * everything shares one page at the largest scale that fits; with one, as many pages as it takes. Never a
 * silent change: a warning says when and why the file's UVs were moved or not used. */
#include "bake_uvs.h"
#include "atlas_pack.h"
#include "atlas_xpack.h"
#include "uv_validity.h"
#include "xatlas_meshes.h"   /* ms_chart_padding */
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


size_t ms_bake_uv_objects(const ms_scene *sc) { return object_count(sc); }

/* Per object: the UV rectangle of its triangles in its set, the UV area they cover, the world area. */
typedef struct object_uv {
    double lo[2], hi[2], uv_area, world_area;
    size_t tris;
    int region;
} object_uv;

static void box_init(object_uv *q)
{
    memset(q, 0, sizeof *q);
    q->lo[0] = q->lo[1] = INFINITY;
    q->hi[0] = q->hi[1] = -INFINITY;
    q->region = -1;
}

/* A rectangle for q: at scale 1 its area is (world area per covered UV area) x (its UV rectangle's area),
 * so that every region gets the same texels per world unit. */
static void region_of(const object_uv *q, ms_pack_rect *r)
{
    const double ew = q->hi[0] - q->lo[0], eh = q->hi[1] - q->lo[1];
    double k = sqrt(q->world_area / q->uv_area);   /* scale-1 texels per UV unit */
    if (!(k > 0.0) || !isfinite(k) || !(ew > 0.0) || !(eh > 0.0)) k = 1e-6;
    memset(r, 0, sizeof *r);
    r->w0 = k * fmax(ew, 1e-9);
    r->h0 = k * fmax(eh, 1e-9);
}

/* Picks each object's UV set (the asked one first, then the others in order): bad[i] (in tris' order) marks
 * the triangles of a usable layout that overlap others or have no area (xatlas charts those); *invalid
 * counts objects that have sets but no usable one, *partial the overlapping triangles of usable ones.
 * Returns -1 when out of memory. */
static int choose_sets(const ms_scene *sc, int first, const uint32_t *start, const uint32_t *tris, size_t nobj, int *set,
                       uint8_t *bad, ms_uv_validity *why, size_t *fallback, size_t *invalid, size_t *partial)
{
    for (size_t o = 0; o < nobj; o++) {
        if (start[o] == start[o + 1]) continue;
        set[o] = -1;
        if (first < 0) continue;
        int tried = 0;
        for (int c = 0; c < MS_MAX_UV_SETS; c++) {
            const int s = c == 0 ? first : c - 1 < first ? c - 1 : c;
            if (!sc->tri_uv[s]) continue;
            ms_uv_validity v;
            const int ok = ms_uv_layout_valid(sc->tri, sc->tri_uv[s], tris + start[o], start[o + 1] - start[o], bad + start[o], &v);
            if (ok < 0) return -1;
            if (ok) { set[o] = s; *fallback += s != first; *partial += v.overlapping; break; }
            if (!v.missing && !tried++) {   /* the first set the object has, for the warning */
                why->overlapping += v.overlapping;
                why->degenerate += v.degenerate;
            }
        }
        *invalid += set[o] < 0 && tried;
    }
    return 0;
}

/* Which triangles keep their object's file UVs (use, their UVs copied into src and counted in ob) and which
 * xatlas charts (want): those of objects without a usable set, and those with no area or overlapping others
 * (bad) in it. Counts both, and says whether the kept UVs lie in [0,1]^2 and whether objects use different
 * sets. */
static void keep_or_chart(const ms_scene *sc, size_t nobj, const uint32_t *start, const uint32_t *tris, const uint8_t *bad,
                          const int *set, uint8_t *use, uint8_t *want, float *src, object_uv *ob, ms_bake_uv_report *rep,
                          size_t *n_use, size_t *n_want, int *inside, int *mixed)
{
    int one_set = -1;
    for (size_t o = 0; o < nobj; o++) {
        const int s = set[o];
        if (s < -1) continue;
        if (s >= 0) { rep->objects_kept++; *mixed |= one_set >= 0 && one_set != s; one_set = s; }
        else rep->objects_unwrapped++;
        for (uint32_t i = start[o]; i < start[o + 1]; i++) {
            const size_t t = tris[i];
            const float sc_ = scale_of(sc, t);
            const double wa = world_area(sc->tri + 9 * t) * (double)sc_ * sc_;
            if (s < 0 || bad[i] || uv_area(sc->tri_uv[s] + 6 * t) == 0.0) {   /* no area, or overlapping: xatlas */
                want[t] = 1;
                (*n_want)++;
                continue;
            }
            use[t] = 1;
            (*n_use)++;
            memcpy(src + 6 * t, sc->tri_uv[s] + 6 * t, 6 * sizeof(float));
            for (int k = 0; k < 3; k++)
                for (int d = 0; d < 2; d++) {
                    const double v = src[6 * t + 2 * k + d];
                    ob[o].lo[d] = fmin(ob[o].lo[d], v);
                    ob[o].hi[d] = fmax(ob[o].hi[d], v);
                    *inside &= v >= 0.0 && v <= 1.0;
                }
            ob[o].uv_area += uv_area(src + 6 * t);
            ob[o].world_area += wa;
            ob[o].tris++;
        }
    }
}

/* The space the rectangle packer leaves between two regions (and to the page's edges) for `pad` texels of padding:
 * a lookup inside a region reads the texels whose centres lie within one texel of it, so rectangles 2 + 2 c apart
 * leave 2 c texels between two regions' footprints, as xatlas's packer leaves between charts' (xatlas_meshes.h). */
static int region_gap(int pad) { return 2 + 2 * ms_chart_padding(pad); }

/* The regions to pack into rs: the file's layout as a whole (all, the objects' union) when whole and it has
 * area, else one per object with a layout (ob[o].region, all->region say which); with a density T, sized at
 * T texels per world unit, a region larger than a page shrunk to fit one (and the whole layout given up for
 * per-object regions when it does not fit). Returns their count. */
static size_t make_regions(object_uv *ob, size_t nobj, object_uv *all, int whole, double T, int size, int pad, ms_pack_rect *rs)
{
    box_init(all);
    for (size_t o = 0; o < nobj; o++) {
        if (!ob[o].tris) continue;
        for (int d = 0; d < 2; d++) { all->lo[d] = fmin(all->lo[d], ob[o].lo[d]); all->hi[d] = fmax(all->hi[d], ob[o].hi[d]); }
        all->uv_area += ob[o].uv_area;
        all->world_area += ob[o].world_area;
    }
    size_t nr = 0;
    for (int attempt = 0; attempt < 2; attempt++) {
        nr = 0;
        for (size_t o = 0; o < nobj; o++) ob[o].region = -1;
        all->region = -1;
        if (whole && all->uv_area > 0.0) { region_of(all, &rs[nr]); all->region = (int)nr++; }
        else
            for (size_t o = 0; o < nobj; o++)
                if (ob[o].tris) { region_of(&ob[o], &rs[nr]); ob[o].region = (int)nr++; }
        if (!(T > 0.0)) break;
        /* a density: T texels per (scaled) world unit; a region larger than a page is shrunk to fit */
        int shrunk = 0;
        for (size_t r = 0; r < nr; r++) {
            rs[r].w0 *= T;
            rs[r].h0 *= T;
            const double f = fmin(1.0, (size - 2.0 * region_gap(pad)) / fmax(rs[r].w0, rs[r].h0));
            if (f < 1.0) { shrunk++; rs[r].w0 *= f; rs[r].h0 *= f; }
        }
        if (shrunk && whole) { whole = 0; continue; }   /* the whole layout does not fit: per object */
        if (shrunk)
            ms_warn("texel density %g: %d objects are larger than a %dx%d page at that density and were scaled down to fit one",
                    T, shrunk, size, size);
        break;
    }
    return nr;
}

/* Regions alone placed as rectangles (atlas_pack.c): at the density T over as many pages as it takes
 * (*pages_used), or at the largest common scale that fits one page. 0, or -1 with a message. */
static int place_regions(ms_pack_rect *rs, size_t nr, int size, int pad, double T, int *pages_used, char *err, size_t errlen)
{
    const int gap = region_gap(pad);
    if (!(T > 0.0)) {
        double wmax = 0.0;
        for (size_t r = 0; r < nr; r++) wmax = fmax(wmax, rs[r].w0 * rs[r].h0);
        for (size_t r = 0; r < nr; r++) {   /* relative sizes, so that tiny objects do not underflow */
            rs[r].w0 = fmax(rs[r].w0 / sqrt(wmax), 1e-5);
            rs[r].h0 = fmax(rs[r].h0 / sqrt(wmax), 1e-5);
        }
        if (ms_pack_one_page(rs, nr, size, gap)) {
            snprintf(err, errlen, "the lightmap's %zu regions do not fit a %dx%d lightmap with %d texels of padding", nr, size, size, pad);
            return -1;
        }
    } else {
        const int pages = ms_pack_pages(rs, nr, 1.0, size, gap, 0);
        if (pages < 0) { snprintf(err, errlen, "the lightmap's %zu regions do not fit %dx%d pages", nr, size, size); return -1; }
        *pages_used = pages ? pages : 1;
    }
    return 0;
}

/* The kept triangles' UVs moved into their region (the object's, or the whole layout's), one scale and offset
 * per object (out->object_scale_offset), and their pages. */
static void place_kept(size_t nobj, const uint32_t *start, const uint32_t *tris, const uint8_t *use, const float *src,
                       const object_uv *ob, const object_uv *all, const ms_pack_rect *rs, int size, ms_bake_uv_layout *out)
{
    for (size_t o = 0; o < nobj; o++) {
        const object_uv *q = all->region >= 0 ? all : &ob[o];
        if (out->object_set[o] < 0 || q->region < 0) continue;
        const ms_pack_rect *r = &rs[q->region];
        const double k = r->w / fmax(q->hi[0] - q->lo[0], 1e-30);   /* = h / (hi[1] - lo[1]): one scale */
        float *so = out->object_scale_offset + 4 * o;
        so[0] = so[1] = (float)(k / size);
        so[2] = (float)((r->x - q->lo[0] * k) / size);
        so[3] = (float)((r->y - q->lo[1] * k) / size);
        for (uint32_t i = start[o]; i < start[o + 1]; i++) {
            const size_t t = tris[i];
            if (!use[t]) continue;
            out->page[t] = (uint32_t)r->page;
            for (int c = 0; c < 3; c++) {
                out->uv[6 * t + 2 * c] = (float)((r->x + (src[6 * t + 2 * c] - q->lo[0]) * k) / size);
                out->uv[6 * t + 2 * c + 1] = (float)((r->y + (src[6 * t + 2 * c + 1] - q->lo[1]) * k) / size);
            }
        }
    }
}

/* One page: the largest scale at which xatlas packs the regions and charts of xp on a size x size page. It
 * steps by the ratio of the page to the atlas's extent until the scale is bracketed, then bisects to 1% (the
 * extent is not proportional to the scale: every chart brings its padding). area: the regions' and charts'
 * area at scale 1, for the first guess. 0 with *scale and xp->grow set for it, or -1 with a message. */
static int fit_one_page(ms_xpack *xp, double area, int size, int pad, double *scale, char *err, size_t errlen)
{
    const double target = size - 2.0 * pad;
    double best = 0.0, worst = INFINITY, sc_ = sqrt(0.7 * target * target / fmax(area, 1e-30));
    int best_grow = 1;
    for (int it = 0; it < 30; it++) {
        /* the growing atlas stays square-ish, which may stack two wide regions and leave a strip; a
         * page of its own size, placed by random probes, may put them side by side: either will do */
        char e2[256];
        xp->grow = 1;
        const double extent = (ms_xpack_run(xp, sc_, e2, sizeof e2) == 1) ? 0.0 : xp->extent;
        int fits = extent == 0.0;
        if (!fits) {
            xp->grow = 0;
            fits = ms_xpack_run(xp, sc_, e2, sizeof e2) == 1;
            xp->extent = extent;
        }
        if (fits) { best = sc_; best_grow = xp->grow; }
        else worst = fmin(worst, sc_);
        if (best > 0.0 && isfinite(worst)) {
            if (worst / best < 1.01) break;
            sc_ = sqrt(best * worst);
        } else {
            const double r = xp->extent > 0.0 ? target / xp->extent : 0.5;
            sc_ *= fits ? fmin(1.5, fmax(1.02, r)) : fmax(0.5, fmin(0.98, r));
        }
    }
    xp->grow = best_grow;
    if (!(best > 0.0) || ms_xpack_run(xp, best, err, errlen) != 1) {
        snprintf(err, errlen, "the lightmap's regions and charts do not fit a %dx%d lightmap with %d texels of padding", size, size, pad);
        return -1;
    }
    *scale = best;
    return 0;
}

/* Kept layouts packed island by island (MS_UV_PACK_ISLANDS): the triangles to place (use), their file
 * UVs (src), and per object its texels per UV unit at scale 1 (k: world units per UV unit, as region_of). */
typedef struct islands {
    const uint8_t *use;
    const float *src;
    const double *k;
    const ms_scene *sc;
} islands;

/* Regions and xatlas charts placed together (atlas_xpack.c): the wanted triangles of xtri charted by xatlas
 * (xuv, xpage: its UVs and atlases, the caller's arrays of n), then regions rs[0..nr), charts and the islands
 * of is (may be NULL) packed at the density T over as many pages as it takes, or on one page at the largest
 * scale that fits. Sets the regions' places, the charted and island triangles' UVs and pages in out,
 * out->pages and rep->charts. 0, or -1 with a message. */
static int place_charts(const float *xtri, size_t n, const uint8_t *want, const uint32_t *group, int size, int pad, double T,
                        float *xuv, uint32_t *xpage, ms_pack_rect *rs, size_t nr, const islands *is,
                        ms_bake_uv_layout *out, ms_bake_uv_report *rep, char *err, size_t errlen)
{
    ms_unwrap_info info;
    memset(&info, 0, sizeof info);
    double *rdim = NULL;
    int *rpage = NULL, rc = -1;
    float *xin = NULL, *xout = NULL;
    uint32_t *xkey = NULL;
    size_t *xtri_of = NULL;
    const int res = size - 2 * pad;
    if (ms_lightmap_unwrap(xtri, n, want, group, res, pad, (float)T, xuv, xpage, &info, err, errlen)) goto fail;
    rep->charts = info.charts;
    /* region texels per rs unit at the charts' density (without charts any: one page is scaled to fit) */
    const double k0 = T > 0.0 ? 1.0 : info.charts ? info.texels_per_unit : 1.0;
    rdim = malloc((nr ? nr : 1) * 4 * sizeof *rdim);
    rpage = malloc((nr ? nr : 1) * sizeof *rpage);
    xin = malloc(n * 6 * sizeof *xin);
    xout = malloc(n * 6 * sizeof *xout);
    xkey = malloc(n * 2 * sizeof *xkey);   /* the charts' keys (stage-1 atlases), then their pages */
    xtri_of = malloc(n * sizeof *xtri_of);
    if (!rdim || !rpage || !xin || !xout || !xkey || !xtri_of) { snprintf(err, errlen, "out of memory packing the lightmap"); goto fail; }
    double area = 0.0;
    for (size_t r = 0; r < nr; r++) {
        rdim[r] = rs[r].w0 * k0;
        rdim[nr + r] = rs[r].h0 * k0;
        area += rdim[r] * rdim[nr + r];
    }
    size_t nx = 0;
    for (size_t t = 0; t < n; t++) {
        if (!want[t] || !isfinite(xuv[6 * t])) continue;
        for (int k = 0; k < 6; k++) xin[6 * nx + k] = xuv[6 * t + k] * (float)res;
        area += uv_area(xin + 6 * nx) / 0.7;   /* charts' boxes */
        xkey[nx] = xpage[t];
        xtri_of[nx++] = t;
    }
    /* The islands: each object's file UVs at its density, one UV mesh per object (key above xatlas's atlases),
     * which xatlas's packer splits into charts at the UVs they do not share: the asset's own islands. */
    for (size_t t = 0; is && t < n; t++) {
        if (!is->use[t]) continue;
        const uint32_t o = object_of(is->sc, t);
        for (int k = 0; k < 6; k++) xin[6 * nx + k] = (float)(is->src[6 * t + k] * is->k[o] * k0);
        area += uv_area(xin + 6 * nx) / 0.7;
        xkey[nx] = 0x80000000u + o;
        xtri_of[nx++] = t;
    }
    area += (double)info.charts * (2.0 * pad + 2.0) * (2.0 * pad + 2.0);   /* and their padding */
    ms_xpack xp = { nr, rdim, rdim + nr, nx, xin, xkey, size, pad, !(T > 0.0), rdim + 2 * nr, rdim + 3 * nr, rpage, xout, xkey + n, 0.0 };
    double scale = 1.0;
    if (T > 0.0) {
        const int pages = ms_xpack_run(&xp, 1.0, err, errlen);
        if (pages < 0) goto fail;
        out->pages = pages;
    } else if (fit_one_page(&xp, area, size, pad, &scale, err, errlen)) {   /* one page */
        goto fail;
    }
    for (size_t r = 0; r < nr; r++) {
        rs[r].x = rdim[2 * nr + r];
        rs[r].y = rdim[3 * nr + r];
        rs[r].w = rdim[r] * scale;
        rs[r].h = rdim[nr + r] * scale;
        rs[r].page = rpage[r];
    }
    size_t shrunk = 0;   /* island triangles xatlas scaled down (an island larger than a page at a density; on one
                          * page the scale found fits everything) */
    for (size_t i = 0; i < nx; i++) {
        const size_t t = xtri_of[i];
        for (int k = 0; k < 6; k++) out->uv[6 * t + k] = xout[6 * i + k] / (float)size;
        out->page[t] = xkey[n + i];
        shrunk += T > 0.0 && is && is->use[t] && uv_area(xout + 6 * i) < 0.98 * uv_area(xin + 6 * i);
    }
    if (shrunk)
        ms_warn("texel density %g: islands of %zu triangles are larger than a %dx%d page at that density and were scaled "
                "down to fit one", T, shrunk, size, size);
    rc = 0;
fail:
    free(rdim);
    free(rpage);
    free(xin);
    free(xout);
    free(xkey);
    free(xtri_of);
    return rc;
}

/* The kept layouts island by island (MS_UV_PACK_ISLANDS, the default), packed with xatlas's charts of the rest: one
 * texel density for all, but no object keeps one scale-offset (its object_scale_offset stays 0). 0, or -1. */
static int place_islands(const ms_scene *sc, size_t n, size_t nobj, const object_uv *ob, const uint8_t *use, const float *src,
                         const float *xtri, const uint8_t *want, const uint32_t *group, int size, int pad, double T, float *xuv,
                         uint32_t *xpage, ms_bake_uv_layout *out, ms_bake_uv_report *rep, char *err, size_t errlen)
{
    double *k = malloc((nobj ? nobj : 1) * sizeof *k);
    if (!k) { snprintf(err, errlen, "out of memory for the lightmap's islands"); return -1; }
    for (size_t o = 0; o < nobj; o++) {   /* as region_of: scale-1 texels per UV unit (world units) */
        k[o] = ob[o].uv_area > 0.0 ? sqrt(ob[o].world_area / ob[o].uv_area) : 0.0;
        if (T > 0.0) k[o] *= T;
    }
    const islands is = { use, src, k, sc };
    const int rc = place_charts(xtri, n, want, group, size, pad, T, xuv, xpage, NULL, 0, &is, out, rep, err, errlen);
    free(k);
    return rc;
}

int ms_bake_uvs(const ms_scene *sc, const ms_bake_uv_params *p, ms_bake_uv_layout *out, ms_bake_uv_report *rep, char *err,
                size_t errlen)
{
    memset(rep, 0, sizeof *rep);
    const size_t n = sc->n_tris, nobj = object_count(sc);
    const int size = p->size, pad = p->padding;
    const double T = p->density;
    uint8_t *use = calloc(n ? n : 1, 1), *want = calloc(n ? n : 1, 1), *bad = calloc(n ? n : 1, 1);
    uint32_t *start = calloc(nobj + 1, sizeof *start), *tris = malloc((n ? n : 1) * sizeof *tris), *group = NULL;
    uint32_t *xpage = NULL;
    object_uv *ob = malloc(nobj * sizeof *ob);
    float *src = malloc((n ? n : 1) * 6 * sizeof *src), *scaled = NULL, *xuv = NULL;
    ms_pack_rect *rs = NULL;
    int rc = -1;
    if (!use || !want || !bad || !start || !tris || !ob || !src) { snprintf(err, errlen, "out of memory for the UVs of %zu triangles", n); goto out; }
    out->pages = 1;
    for (size_t o = 0; o < nobj; o++) {
        box_init(&ob[o]);
        out->object_set[o] = -2;
        for (int k = 0; k < 4; k++) out->object_scale_offset[4 * o + k] = 0.0f;
    }
    /* the baked triangles by object (counting sort) */
    int weighted = 0;
    for (size_t t = 0; t < n; t++) {
        for (int k = 0; k < 6; k++) out->uv[6 * t + k] = src[6 * t + k] = NAN;
        out->page[t] = 0;
        const float s = scale_of(sc, t);
        if (!(s > 0.0f)) { rep->excluded++; continue; }
        weighted |= s != 1.0f;
        start[object_of(sc, t) + 1]++;
    }
    for (size_t o = 0; o < nobj; o++) start[o + 1] += start[o];
    for (size_t t = 0; t < n; t++)
        if (scale_of(sc, t) > 0.0f) tris[start[object_of(sc, t)]++] = (uint32_t)t;
    for (size_t o = nobj; o > 0; o--) start[o] = start[o - 1];
    start[0] = 0;
    ms_uv_validity why;
    memset(&why, 0, sizeof why);
    size_t fallback = 0, invalid = 0, partial = 0;
    if (choose_sets(sc, p->uv_set, start, tris, nobj, out->object_set, bad, &why, &fallback, &invalid, &partial)) {
        snprintf(err, errlen, "out of memory checking the UV sets for overlaps");
        goto out;
    }
    /* which triangles keep the file's UVs (use), which xatlas charts (want) */
    size_t n_use = 0, n_want = 0;
    int inside = 1, mixed = 0;
    keep_or_chart(sc, nobj, start, tris, bad, out->object_set, use, want, src, ob, rep, &n_use, &n_want, &inside, &mixed);
    rep->unwrapped = n_want;
    int fail = 0;
    if (n_use) rep->overlap_texels = count_overlap(sc, src, use, size, err, errlen, &fail);
    if (fail) goto out;
    if (invalid)
        ms_warn("%zu objects have no UV set that is a valid lightmap layout (in the first set each has: %zu or more triangles overlap others, "
                "%zu have no area): xatlas charts them", invalid, why.overlapping, why.degenerate);
    if (partial)
        ms_warn("%zu triangles overlap others in their object's UV layout: xatlas charts them, the rest keeps the layout", partial);
    if (fallback) ms_warn("%zu objects have no valid UV set %d and are baked in another set of theirs", fallback, p->uv_set);
    if (!n_want && !rep->overlap_texels && inside && !weighted && !mixed && !(T > 0.0) && p->packing != MS_UV_PACK_ISLANDS) {   /* the file's UVs as they are */
        for (size_t t = 0; t < n; t++)
            if (use[t]) memcpy(out->uv + 6 * t, src + 6 * t, 6 * sizeof(float));
        for (size_t o = 0; o < nobj; o++)
            if (out->object_set[o] >= 0) out->object_scale_offset[4 * o] = out->object_scale_offset[4 * o + 1] = 1.0f;
        rc = 0;
        goto out;
    }
    /* xatlas's input: positions scaled by each mesh's weight (xatlas sizes charts by world area), one mesh
     * per object */
    const int islands = p->packing != MS_UV_PACK_REGIONS;
    if (n_want || (islands && n_use)) {
        xuv = malloc(n * 6 * sizeof *xuv);
        xpage = calloc(n, sizeof *xpage);
        group = malloc(n * sizeof *group);
        scaled = weighted ? malloc(n * 9 * sizeof *scaled) : NULL;
        if (!xuv || !xpage || !group || (weighted && !scaled)) { snprintf(err, errlen, "out of memory for the UVs of %zu triangles", n); goto out; }
        for (size_t t = 0; t < n; t++) group[t] = object_of(sc, t);
        if (weighted)
            for (size_t t = 0; t < n; t++)
                for (int k = 0; k < 9; k++) scaled[9 * t + k] = sc->tri[9 * t + k] * (want[t] ? scale_of(sc, t) : 1.0f);
    }
    const float *xtri = weighted ? scaled : sc->tri;
    if (islands && n_use) {   /* every kept layout island by island, with xatlas's charts */
        if (place_islands(sc, n, nobj, ob, use, src, xtri, want, group, size, pad, T, xuv, xpage, out, rep, err, errlen)) goto out;
        rc = 0;
        goto out;
    }
    /* Regions: the file's layout as a whole when objects share one set and do not overlap, else one per
     * object with a layout; xatlas's square (one page) or its pages (a density). */
    int whole = !rep->overlap_texels && !weighted && !mixed;
    rs = calloc(nobj + n + 2, sizeof *rs);
    if (!rs) { snprintf(err, errlen, "out of memory for the lightmap's regions"); goto out; }
    object_uv all;
    const size_t nr = make_regions(ob, nobj, &all, whole, T, size, pad, rs);
    /* Placement. Regions alone are rectangles (atlas_pack.c): at the density, or at the largest common scale
     * that fits one page. With xatlas charts, xatlas's packer places the regions and the charts together
     * (atlas_xpack.c): at the density over as many pages as it takes, or on one page at the largest scale
     * found by stepping it. */
    if (!n_want) {
        if (place_regions(rs, nr, size, pad, T, &out->pages, err, errlen)) goto out;
    } else if (place_charts(xtri, n, want, group, size, pad, T, xuv, xpage, rs, nr, NULL, out, rep, err, errlen)) {
        goto out;
    }
    rep->regions = nr;
    rep->relaid = n_use > 0;
    place_kept(nobj, start, tris, use, src, ob, &all, rs, size, out);
    if (rep->overlap_texels)
        ms_warn("%zu objects' UVs overlap each other (%zu texel centres covered twice): each object gets its own region "
                "of the lightmap, its UVs scaled and offset (the baked UVs: ms_lightmap.uv, the glTF's TEXCOORD_1)",
                rep->objects_kept, rep->overlap_texels);
    rc = 0;
out:
    free(use);
    free(want);
    free(bad);
    free(start);
    free(tris);
    free(group);
    free(xpage);
    free(ob);
    free(src);
    free(scaled);
    free(xuv);
    free(rs);
    return rc;
}
