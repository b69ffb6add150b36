/* Lightmap baking (microshadow/bake.h, "Lightmap baking"): UVs (the scene's set, xatlas for the rest), texels
 * rasterized conservatively onto the triangles' UV images and carried to world points, V and S there
 * through ms_visibility_points (so every method bakes, on the frames' sample patterns keyed by texel),
 * irradiance from the exact unshadowed value times S, then dilation across chart seams and the seams
 * stitched (bake_stitch.c). */
#include "microshadow.h"
#include "core/abi.h"
#include "points.h"
#include "bake_uvs.h"
#include "bake_leaks.h"
#include "bake_seams.h"
#include "bake_stitch.h"
#include "shade.h"
#include "bake_unbaked.h"
#include "bake_pages.h"
#include "footprint.h"
#include "budget.h"
#include "light/pattern.h"
#include "light/light_shape.h"
#include "visibility/receiver.h"
#include "shadow/method.h"
#include "scene/scene_internal.h"   /* ms_warn */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void ms_lightmap_free(ms_lightmap *lm)
{
    if (!lm) return;
    ms_frame_free(&lm->frame);
    free(lm->position);
    free(lm->normal);
    free(lm->triangle);
    free(lm->uv);
    ms_bake_pages_free(lm);
    memset(lm, 0, sizeof *lm);
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Closest point to p on triangle abc in 2D (Ericson, Real-Time Collision Detection 5.1.5), as
 * barycentric weights w (of a, b, c). */
static void closest_on_triangle(const double p[2], const double a[2], const double b[2], const double c[2], double w[3])
{
    const double ab[2] = { b[0] - a[0], b[1] - a[1] }, ac[2] = { c[0] - a[0], c[1] - a[1] };
    const double ap[2] = { p[0] - a[0], p[1] - a[1] };
    const double d1 = ab[0] * ap[0] + ab[1] * ap[1], d2 = ac[0] * ap[0] + ac[1] * ap[1];
    if (d1 <= 0 && d2 <= 0) { w[0] = 1; w[1] = w[2] = 0; return; }
    const double bp[2] = { p[0] - b[0], p[1] - b[1] };
    const double d3 = ab[0] * bp[0] + ab[1] * bp[1], d4 = ac[0] * bp[0] + ac[1] * bp[1];
    if (d3 >= 0 && d4 <= d3) { w[1] = 1; w[0] = w[2] = 0; return; }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) { const double v = d1 / (d1 - d3); w[0] = 1 - v; w[1] = v; w[2] = 0; return; }
    const double cp[2] = { p[0] - c[0], p[1] - c[1] };
    const double d5 = ab[0] * cp[0] + ab[1] * cp[1], d6 = ac[0] * cp[0] + ac[1] * cp[1];
    if (d6 >= 0 && d5 <= d6) { w[2] = 1; w[0] = w[1] = 0; return; }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) { const double t = d2 / (d2 - d6); w[0] = 1 - t; w[2] = t; w[1] = 0; return; }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        w[1] = 1 - t; w[2] = t; w[0] = 0;
        return;
    }
    const double den = 1.0 / (va + vb + vc);
    w[1] = vb * den;
    w[2] = vc * den;
    w[0] = 1.0 - w[1] - w[2];
}

/* The normal the irradiance's cosine takes at texel point p of scene triangle t (unit geometric normal ng):
 * the vertex normals interpolated as frames shade (shade.c), so that a smooth surface bakes smooth and the
 * two faces of a smooth edge agree there; ng where the mesh has none. Visibility keeps ng (lightmaps are
 * one-sided): the result is turned to ng's side. A texel point moved off its triangle (an edge texel, the
 * leak fix) takes its barycentrics clamped into the triangle rather than extrapolated normals. */
static void shading_normal(const ms_scene *sc, uint32_t t, const float p[3], const float ng[3], float ns[3])
{
    memcpy(ns, ng, 3 * sizeof(float));
    if (!sc->tri_normal || t >= sc->n_tris) return;
    float b[3];
    ms_barycentric(sc->tri + 9 * (size_t)t, p, b);
    if (b[0] < 0.0f || b[1] < 0.0f || b[2] < 0.0f) {
        float sum = 0.0f;
        for (int k = 0; k < 3; k++) sum += b[k] = b[k] > 0.0f ? b[k] : 0.0f;
        if (!(sum > 0.0f)) return;
        for (int k = 0; k < 3; k++) b[k] /= sum;
    }
    if (!ms_interpolated_normal(sc, t, b, ns)) return;
    if (ns[0] * ng[0] + ns[1] * ng[1] + ns[2] * ng[2] < 0.0f)
        for (int k = 0; k < 3; k++) ns[k] = -ns[k];
}

/* Texels of every triangle's UV image (conservative: every texel square the triangle overlaps, tested
 * with each edge function pushed out by half a texel in L1), each texel kept by the triangle nearest its
 * centre in UV space (0 inside; ties to the lower index, so the result does not depend on order). */
static ms_status rasterize(const ms_scene *sc, int size, int height, const float *frame_uv, ms_lightmap *lm, char *err,
                           size_t errlen)
{
    const size_t nt = (size_t)size * height;
    float *dist = malloc(nt * sizeof *dist);
    lm->triangle = malloc(nt * sizeof *lm->triangle);
    lm->position = malloc(nt * 3 * sizeof(float));
    lm->normal = malloc(nt * 3 * sizeof(float));
    if (!dist || !lm->triangle || !lm->position || !lm->normal) {
        free(dist);
        snprintf(err, errlen, "out of memory for a %dx%d lightmap", size, size);
        return MS_ERR_NO_MEMORY;
    }
    for (size_t i = 0; i < nt; i++) { dist[i] = INFINITY; lm->triangle[i] = MS_NO_TRIANGLE; }
    for (size_t i = 0; i < 3 * nt; i++) lm->position[i] = lm->normal[i] = NAN;
    for (size_t t = 0; t < sc->n_tris; t++) {
        const float *uv = frame_uv + 6 * t;
        double a[2] = { uv[0] * (double)size, uv[1] * (double)height }, b[2] = { uv[2] * (double)size, uv[3] * (double)height },
               c[2] = { uv[4] * (double)size, uv[5] * (double)height };
        if (!(isfinite(a[0]) && isfinite(a[1]) && isfinite(b[0]) && isfinite(b[1]) && isfinite(c[0]) && isfinite(c[1]))) continue;
        double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if (area == 0.0) continue;
        if (area < 0.0) { const double s[2] = { b[0], b[1] }; b[0] = c[0]; b[1] = c[1]; c[0] = s[0]; c[1] = s[1]; }
        const double *v[3] = { a, b, c };
        double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY };
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 2; d++) { lo[d] = fmin(lo[d], v[k][d]); hi[d] = fmax(hi[d], v[k][d]); }
        const int x0 = (int)fmax(floor(lo[0]), 0.0), x1 = (int)fmin(floor(hi[0]), size - 1.0);
        const int y0 = (int)fmax(floor(lo[1]), 0.0), y1 = (int)fmin(floor(hi[1]), height - 1.0);
        const float *w = sc->tri + 9 * t;
        float nn[3];
        if (ms_bake_tri_normal(w, nn)) continue;   /* no plane, no receiver */
        for (int y = y0; y <= y1; y++)
            for (int x = x0; x <= x1; x++) {
                const double p[2] = { x + 0.5, y + 0.5 };
                int in = 1, touches = 1;
                for (int k = 0; k < 3; k++) {
                    const double *s0 = v[k], *s1 = v[(k + 1) % 3];
                    const double ex = s1[0] - s0[0], ey = s1[1] - s0[1];
                    const double e = ex * (p[1] - s0[1]) - ey * (p[0] - s0[0]);   /* > 0 inside (counter-clockwise) */
                    in &= e >= 0.0;
                    touches &= e + 0.5 * (fabs(ex) + fabs(ey)) >= 0.0;
                }
                if (!touches) continue;
                double bw[3];
                float dd = 0.0f;
                if (in) {
                    const double l1 = ((c[0] - b[0]) * (p[1] - b[1]) - (c[1] - b[1]) * (p[0] - b[0])) / fabs(area);
                    const double l2 = ((a[0] - c[0]) * (p[1] - c[1]) - (a[1] - c[1]) * (p[0] - c[0])) / fabs(area);
                    bw[0] = l1; bw[1] = l2; bw[2] = 1.0 - l1 - l2;
                } else {
                    closest_on_triangle(p, a, b, c, bw);
                    const double q0 = bw[0] * a[0] + bw[1] * b[0] + bw[2] * c[0], q1 = bw[0] * a[1] + bw[1] * b[1] + bw[2] * c[1];
                    dd = (float)hypot(q0 - p[0], q1 - p[1]);
                }
                const size_t i = (size_t)y * size + x;
                if (dd > dist[i] || (dd == dist[i] && lm->triangle[i] < t)) continue;
                dist[i] = dd;
                lm->triangle[i] = (uint32_t)t;
                /* bw weighs a, b, c as rasterized; undo the swap of b and c for the world vertices */
                const double wa = bw[0], wb = area < 0.0 ? bw[2] : bw[1], wc = area < 0.0 ? bw[1] : bw[2];
                for (int d = 0; d < 3; d++) {
                    lm->position[3 * i + d] = (float)(wa * w[d] + wb * w[3 + d] + wc * w[6 + d]);
                    lm->normal[3 * i + d] = nn[d];
                }
            }
    }
    ms_bake_page_fill(lm, dist, size);
    free(dist);
    return MS_OK;
}

/* Fills texels off the triangles from the average of their filled 8-neighbours, `passes` rings deep: the
 * irradiance and every light's V and S. A texel of a chart's bilinear footprint takes only its own chart's
 * (footprint.h: charts packed with no padding touch), which the first pass always finds: a point of the
 * chart within one texel of its centre lies in the square of a neighbour, which the chart rasterized. */
static int dilate(ms_frame *f, int passes, const ms_lightmap *lm)
{
    if (passes <= 0) return 0;
    const int W = f->width, H = f->height;
    const size_t nl = f->n_lights > 1 ? (size_t)f->n_lights : 1, np = (size_t)W * H;
    uint8_t *filled = malloc(np), *next = malloc(np);
    double *acc = malloc((3 + 2 * nl) * sizeof *acc);
    uint32_t *owner = malloc(np * sizeof *owner);
    if (!filled || !next || !acc || !owner ||
        ms_footprint_owners(lm->uv, lm->page, lm->n_tris, W, lm->pages > 0 ? lm->pages : 1, owner)) {
        free(filled); free(next); free(acc); free(owner);
        return -1;
    }
    for (size_t i = 0; i < np; i++) filled[i] = f->vis[i] >= 0.0f;
    for (int pass = 0; pass < passes; pass++) {
        memcpy(next, filled, np);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const size_t i = (size_t)y * W + x;
                if (filled[i]) continue;
                memset(acc, 0, (3 + 2 * nl) * sizeof *acc);
                int cnt = 0;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        const int xx = x + dx, yy = y + dy;
                        if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
                        const size_t j = (size_t)yy * W + xx;
                        if (!filled[j] || (owner[i] != UINT32_MAX && owner[j] != owner[i])) continue;
                        for (int c = 0; c < 3; c++) acc[c] += f->rgb[3 * j + c];
                        for (size_t l = 0; l < nl; l++) {
                            acc[3 + 2 * l] += f->vis[l * np + j];
                            acc[4 + 2 * l] += f->shadow[l * np + j];
                        }
                        cnt++;
                    }
                if (!cnt) continue;
                for (int c = 0; c < 3; c++) f->rgb[3 * i + c] = (float)(acc[c] / cnt);
                for (size_t l = 0; l < nl; l++) {
                    f->vis[l * np + i] = (float)(acc[3 + 2 * l] / cnt);
                    f->shadow[l * np + i] = (float)(acc[4 + 2 * l] / cnt);
                }
                next[i] = 1;
            }
        uint8_t *t = filled; filled = next; next = t;
    }
    free(filled);
    free(next);
    free(acc);
    free(owner);
    return 0;
}

/* The memory budget of a bake (budget.h) with its size and lights, building the accel here or not; the
 * estimate into *need when not NULL. */
static ms_status bake_budget(const ms_scene *scene, const ms_bake_options *o, int size, int pages, int build_accel,
                             uint64_t *need, char *err, size_t errlen)
{
    ms_bake_shape bs;
    memset(&bs, 0, sizeof bs);
    bs.size = size;
    bs.pages = pages;
    ms_scene_lights(scene, &bs.nl);
    bs.n_tris = scene->n_tris;
    bs.build_accel = build_accel;
    bs.unwrap = o->uv_set < 0 || !scene->tri_uv[o->uv_set];
    const int samples = o->points.samples > 0 ? o->points.samples : MS_SAMPLES_DEFAULT;
    bs.mask_words = (samples + 63) / 64;
    bs.threads = o->points.threads > 0 ? o->points.threads : omp_get_num_procs();
    const char *method = o->points.method ? o->points.method : MS_DEFAULT_METHOD;
    if (strcmp(method, MS_AUTO_METHOD) == 0) method = ms_auto_method(o->points.pattern);
    const ms_shadow_method *sm = ms_find_shadow_method(method);
    bs.whole_tri_copy = sm && sm->visibility_all;
    if (need) *need = ms_bake_need(&bs, NULL);
    return ms_bake_budget_check(&bs, ms_memory_budget(o->points.max_memory), err, errlen) ? MS_ERR_BUDGET : MS_OK;
}

/* A checked entry point's first steps: the ABI check, then the options as this library reads them (an earlier
 * header's at its size, NULL as the defaults) in *o, which may point at copy. */
static ms_status bake_entry(const ms_abi *abi, const char *fn, const ms_bake_options *in, ms_bake_options *copy,
                            const ms_bake_options **o, char *err, size_t errlen)
{
    const ms_status st = ms_abi_check(abi, fn, err, errlen);
    *o = st ? NULL : ms_abi_bake_options(abi, in, copy);
    return st;
}

/* The layout of the lightmap (ms_bake_layout): checks, UVs, texel rasterization, the frame's arrays. */
ms_status ms_bake_layout_abi(const ms_abi *abi, const ms_scene *scene, const ms_bake_options *opt_in, ms_lightmap *out,
                             char *err, size_t errlen)
{
    ms_bake_options opt_copy;
    const ms_bake_options *o;
    const ms_status ast = bake_entry(abi, "ms_bake_layout", opt_in, &opt_copy, &o, err, errlen);
    if (ast) return ast;
    if (!out) { snprintf(err, errlen, "ms_bake: out is NULL"); return MS_ERR_INVALID; }
    memset(out, 0, sizeof *out);
    if (!scene) { snprintf(err, errlen, "ms_bake: no scene"); return MS_ERR_INVALID; }
    if (!scene->tri && scene->n_tris) {
        snprintf(err, errlen, "ms_bake: a procedural scene has no triangles in memory (only the streaming methods render it)");
        return MS_ERR_INVALID;
    }
    const int size = o->size ? o->size : 1024;
    if (size < 1 || size > MS_MAX_IMAGE_SIZE) { snprintf(err, errlen, "lightmap size must be in [1, %d]", MS_MAX_IMAGE_SIZE); return MS_ERR_INVALID; }
    if (o->uv_set < -1 || o->uv_set >= MS_MAX_UV_SETS) {
        snprintf(err, errlen, "UV set must be in [0, %d], or -1 for xatlas", MS_MAX_UV_SETS - 1);
        return MS_ERR_INVALID;
    }
    if ((int)o->uv_packing < MS_UV_PACK_DEFAULT || (int)o->uv_packing > MS_UV_PACK_REGIONS) {
        snprintf(err, errlen, "ms_bake: uv_packing %d is not one of 0 (default), 1 (islands), 2 (regions)", (int)o->uv_packing);
        return MS_ERR_INVALID;
    }
    ms_status bst = bake_budget(scene, o, size, 1, 0, NULL, err, errlen);
    if (bst) return bst;
    const int padding = o->padding > 0 ? o->padding : 0;
    ms_status st = ms_bake_choose_uvs(scene, o, size, padding, out, err, errlen);
    if (!st && o->pass) o->pass(o->pass_user, out->uv_cached ? "UVs (from the cache)" : "UVs", out->unwrap_s);
    if (!st && out->pages > 1) st = bake_budget(scene, o, size, out->pages, 0, NULL, err, errlen);   /* known now */
    const int height = st ? size : size * out->pages;
    float *frame_uv = st ? NULL : ms_bake_frame_uv(out);
    if (!st && !frame_uv) { snprintf(err, errlen, "out of memory for the UVs of %zu triangles", scene->n_tris); st = MS_ERR_NO_MEMORY; }
    const double t_raster = omp_get_wtime();
    if (!st) st = rasterize(scene, size, height, frame_uv, out, err, errlen);
    out->raster_s = omp_get_wtime() - t_raster;
    if (!st) {   /* every triangle baked or named */
        size_t count[MS_UNBAKED_REASONS];
        ms_bake_report_unbaked(scene, out, size, count);
        out->excluded_tris = count[MS_UNBAKED_EXCLUDED];
        for (int r = MS_UNBAKED_NO_AREA; r < MS_UNBAKED_REASONS; r++) out->unbaked_tris += count[r];
    }
    if (!st && o->pass) o->pass(o->pass_user, "texels", out->raster_s);
    const double t_leak = omp_get_wtime();
    if (!st && !o->no_leak_fix &&
        ms_bake_fix_leaks(scene, size, height, frame_uv, out->triangle, out->position, out->normal, o->points.threads,
                          &out->texels_moved, err, errlen))
        st = MS_ERR_NO_MEMORY;
    if (frame_uv != out->uv) free(frame_uv);
    out->leak_s = omp_get_wtime() - t_leak;
    if (!st && o->pass && !o->no_leak_fix) o->pass(o->pass_user, "leak test", out->leak_s);
    out->n_tris = scene->n_tris;
    const size_t nt = (size_t)size * height;
    size_t nl;
    ms_scene_lights(scene, &nl);
    ms_frame *f = &out->frame;
    if (!st) {
        /* One plane of V, S and front per light, as frames have them (ms_frame.n_lights). */
        f->width = size;
        f->height = height;
        f->n_lights = (int)nl;
        f->vis = malloc(nl * nt * sizeof(float));
        f->shadow = malloc(nl * nt * sizeof(float));
        f->front = calloc(nl * nt, sizeof *f->front);
        f->rgb = calloc(nt * 3, sizeof(float));
        if (!f->vis || !f->shadow || !f->front || !f->rgb) {
            snprintf(err, errlen, "out of memory for a %dx%d lightmap", size, size);
            st = MS_ERR_NO_MEMORY;
        }
    }
    if (!st)
        for (size_t i = 0; i < nt; i++) {
            for (size_t l = 0; l < nl; l++) f->vis[l * nt + i] = f->shadow[l * nt + i] = -1.0f;
            out->texels += out->triangle[i] != MS_NO_TRIANGLE;
        }
    if (st) ms_lightmap_free(out);
    return st;
}

/* Adds one ms_visibility_points call's stats to the lightmap's (the first call's are taken whole); the
 * texels count once (count_texels: the first light's call), the segments and penumbrae per light, as in
 * frames. */
static void add_stats(ms_stats *sum, const ms_stats *s, int count_texels)
{
    if (!sum->method) { *sum = *s; return; }
    sum->setup_s += s->setup_s;
    sum->shadow_s += s->shadow_s;
    sum->shadow_factor_s += s->shadow_factor_s;
    if (count_texels) sum->visible_pixels += s->visible_pixels;
    sum->penumbra_pixels += s->penumbra_pixels;
    sum->shadow_rays += s->shadow_rays;
    for (int c = 0; c < s->n_counters && c < MS_MAX_COUNTERS; c++) sum->counter[c] += s->counter[c];
}

/* Progress over several lights: light l's fraction f is (l + f) / n of the rows' bake. */
typedef struct bake_progress {
    ms_progress_cancel_fn fn;
    void *user;
    size_t light, n;
} bake_progress;

static int light_progress(void *user, double f)
{
    const bake_progress *p = user;
    return p->fn(p->user, ((double)p->light + f) / (double)p->n);
}

ms_status ms_bake_rows_abi(const ms_abi *abi, const ms_accel *accel, const ms_bake_options *opt_in, ms_lightmap *lm,
                           int y0, int y1, char *err, size_t errlen)
{
    ms_bake_options opt_copy;
    const ms_bake_options *o;
    const ms_status ast = bake_entry(abi, "ms_bake_rows", opt_in, &opt_copy, &o, err, errlen);
    if (ast) return ast;
    ms_frame *f = &lm->frame;
    const int size = f->width;
    if (!accel || !f->vis || y0 < 0 || y1 > f->height || y0 > y1) {
        snprintf(err, errlen, "ms_bake_rows: no accel or layout, or rows [%d, %d) not within [0, %d)", y0, y1, f->height);
        return MS_ERR_INVALID;
    }
    const size_t first = (size_t)y0 * size, last = (size_t)y1 * size;
    size_t m = 0;
    for (size_t i = first; i < last; i++) m += lm->triangle[i] != MS_NO_TRIANGLE;
    float *pos = malloc((m ? m : 1) * 3 * sizeof *pos), *nor = malloc((m ? m : 1) * 3 * sizeof *nor);
    uint32_t *tri = malloc((m ? m : 1) * sizeof *tri), *key = malloc((m ? m : 1) * 2 * sizeof *key);
    size_t *where = malloc((m ? m : 1) * sizeof *where);
    ms_status st = MS_OK;
    if (!pos || !nor || !tri || !key || !where) { snprintf(err, errlen, "out of memory for %zu texels", m); st = MS_ERR_NO_MEMORY; }
    if (!st) {
        size_t j = 0;
        for (size_t i = first; i < last; i++) {
            if (lm->triangle[i] == MS_NO_TRIANGLE) continue;
            memcpy(pos + 3 * j, lm->position + 3 * i, 3 * sizeof(float));
            memcpy(nor + 3 * j, lm->normal + 3 * i, 3 * sizeof(float));
            tri[j] = lm->triangle[i];
            key[2 * j] = (uint32_t)(i % (size_t)size);
            key[2 * j + 1] = (uint32_t)(i / (size_t)size);
            where[j++] = i;
        }
        ms_points pts = { m, pos, nor, tri, key };
        size_t nl;
        const ms_light *lights = ms_accel_lights(accel, &nl);
        if (f->n_lights != (int)nl) {
            snprintf(err, errlen, "ms_bake_rows: the lightmap was laid out for %d lights, the accel has %zu", f->n_lights, nl);
            st = MS_ERR_INVALID;
        }
        /* Each light in turn (its own ms_visibility_points call, as frames run a shadow pass per light),
         * the results kept aside until every light succeeded: lm is left as it was on an error. */
        const size_t nt = (size_t)size * f->height;
        float *vl = st ? NULL : malloc((m ? m : 1) * nl * sizeof *vl), *sl = st ? NULL : malloc((m ? m : 1) * nl * sizeof *sl);
        uint16_t *fl = st ? NULL : malloc((m ? m : 1) * nl * sizeof *fl);
        ms_stats sum;
        memset(&sum, 0, sizeof sum);
        if (!st && (!vl || !sl || !fl)) { snprintf(err, errlen, "out of memory for %zu texels", m); st = MS_ERR_NO_MEMORY; }
        bake_progress bp = { o->points.progress, o->points.progress_user, 0, nl };
        ms_points_options po = o->points;
        if (po.progress) { po.progress = light_progress; po.progress_user = &bp; }
        for (size_t l = 0; l < nl && !st; l++) {
            ms_stats one;
            memset(&one, 0, sizeof one);
            bp.light = l;
            const double t_light = omp_get_wtime();
            st = ms_visibility_points_local(accel, &lights[l], &pts, &po, vl + l * m, sl + l * m, fl + l * m, &one, err, errlen);
            if (!st) add_stats(&sum, &one, l == 0);
            if (!st && o->pass) {
                char name[48];
                snprintf(name, sizeof name, "light %zu/%zu", l + 1, nl);
                o->pass(o->pass_user, name, omp_get_wtime() - t_light);
            }
        }
        if (!st) {
            for (size_t l = 0; l < nl; l++)
                for (size_t k = 0; k < m; k++) {
                    f->vis[l * nt + where[k]] = vl[l * m + k];
                    f->shadow[l * nt + where[k]] = sl[l * m + k];
                    f->front[l * nt + where[k]] = fl[l * m + k];
                }
            add_stats(&f->stats, &sum, 1);
        }
        free(vl);
        free(sl);
        free(fl);
    }
    free(pos);
    free(nor);
    free(tri);
    free(key);
    free(where);
    return st;
}

/* The seams of smooth edges (bake_seams.c): stitched (bake_stitch.c) unless o->no_seam_stitch, then measured. */
static ms_status seams(const ms_scene *scene, const ms_bake_options *o, ms_lightmap *lm, int threads, char *err, size_t errlen)
{
    ms_seam *list = NULL;
    size_t n = 0;
    float *frame_uv = ms_bake_frame_uv(lm);   /* the UVs in the frame's rows: pages stacked */
    if (!frame_uv || ms_bake_seam_list(scene, frame_uv, &list, &n)) {
        if (frame_uv != lm->uv) free(frame_uv);
        snprintf(err, errlen, "out of memory finding the lightmap's seams");
        return MS_ERR_NO_MEMORY;
    }
    /* The stitch's memory is known only now, with the seams: checked against what the budget leaves beside
     * the bake's own estimate; over it, the lightmap stays unstitched (correct, with its seams), and says so. */
    int stitch = !o->no_seam_stitch;
    if (stitch) {
        uint64_t bake_need = 0;
        char ignored[8];
        bake_budget(scene, o, lm->frame.width, lm->pages > 1 ? lm->pages : 1, 1, &bake_need, ignored, sizeof ignored);
        const uint64_t need = ms_bake_stitch_need(&lm->frame, list, n), budget = ms_memory_budget(o->points.max_memory);
        if (bake_need + need > budget) {
            ms_warn("seam stitching skipped: it needs %.1f MiB beside the bake's %.1f MiB, over the memory budget of "
                    "%.1f MiB (raise it, or pass --no-seam-stitch to silence this)",
                    need / 1048576.0, bake_need / 1048576.0, budget / 1048576.0);
            stitch = 0;
        }
    }
    if (stitch) {
        const double t0 = omp_get_wtime();
        const int rc = ms_bake_stitch(&lm->frame, frame_uv, lm->triangle, list, n, threads, &lm->stitched_texels);
        lm->stitch_s = omp_get_wtime() - t0;
        if (rc) {
            free(list);
            if (frame_uv != lm->uv) free(frame_uv);
            snprintf(err, errlen, "out of memory stitching the lightmap's seams");
            return MS_ERR_NO_MEMORY;
        }
        if (o->pass) o->pass(o->pass_user, "seam stitching", lm->stitch_s);
    }
    if (frame_uv != lm->uv) free(frame_uv);
    const double t0 = omp_get_wtime();
    ms_seam_error se;
    const int rc = ms_bake_seams(&lm->frame, list, n, &se);
    free(list);
    if (rc) { snprintf(err, errlen, "out of memory measuring the lightmap's seams"); return MS_ERR_NO_MEMORY; }
    lm->seam_mean = se.mean;
    lm->seam_p99 = se.p99;
    lm->seam_max = se.max;
    lm->seam_points = se.points;
    if (o->pass) o->pass(o->pass_user, "seams", omp_get_wtime() - t0);
    return MS_OK;
}

ms_status ms_bake_finish_abi(const ms_abi *abi, const ms_scene *scene, const ms_bake_options *opt_in, ms_lightmap *lm,
                             char *err, size_t errlen)
{
    ms_bake_options opt_copy;
    const ms_bake_options *o;
    const ms_status ast = bake_entry(abi, "ms_bake_finish", opt_in, &opt_copy, &o, err, errlen);
    if (ast) return ast;
    const int passes = o->dilate == 0 ? 4 : o->dilate < 0 ? 0 : o->dilate;
    const double t_finish = omp_get_wtime();
    ms_frame *f = &lm->frame;
    const int size = f->width;
    const size_t nt = (size_t)size * f->height, m = lm->texels;
    /* Irradiance summed over the lights and the exposure (99th percentile), texels in row order: per light
     * E_unshadowed * S * emission, a textured light's emission times the weighted mean texel the texel's
     * front samples see (as frames shade, render.c). */
    size_t nl;
    const ms_light *lights = ms_scene_lights(scene, &nl);
    if (f->n_lights != (int)nl) {
        snprintf(err, errlen, "ms_bake_finish: the lightmap has %d lights, the scene %zu", f->n_lights, nl);
        return MS_ERR_INVALID;
    }
    const int samples = o->points.samples > 0 ? o->points.samples : MS_SAMPLES_DEFAULT;
    ms_render_ctx tctx;   /* for the textured lights' mean texels: the points' pattern (points.c) */
    ms_render_ctx_init(&tctx, NULL, NULL, NULL, o->points.pattern, ms_samples_to_k(samples), o->points.seed, 0);
    float *lum = malloc((nt ? nt : 1) * sizeof *lum);
    if (!lum) { snprintf(err, errlen, "out of memory for a %dx%d lightmap", size, size); return MS_ERR_NO_MEMORY; }
    const int threads = o->points.threads > 0 ? o->points.threads : omp_get_num_procs();
#pragma omp parallel for schedule(dynamic, 1024) num_threads(threads)
    for (size_t i = 0; i < nt; i++) {
        if (lm->triangle[i] == MS_NO_TRIANGLE) continue;
        const float *p = lm->position + 3 * i, *n = lm->normal + 3 * i;
        float ns[3];
        shading_normal(scene, lm->triangle[i], p, n, ns);
        float c[3] = { 0, 0, 0 }, y = 0.0f;
        for (size_t l = 0; l < nl; l++) {
            ms_light L = lights[l];
            const ms_light_shape_ops *shape = ms_light_shape_of(L.shape);
            if (L.texture && shape && shape->textured) {
                ms_render_ctx ctx = tctx;
                ctx.light = L;
                ms_shadow_query q;
                memcpy(q.p, p, sizeof q.p);
                memcpy(q.n, n, sizeof q.n);
                q.prim = UINT32_MAX;
                q.px = (uint32_t)(i % (size_t)size);
                q.py = (uint32_t)(i / (size_t)size);
                float t[3];
                ms_light_texture_mean(&ctx, &q, t);
                L.emission.x *= t[0];
                L.emission.y *= t[1];
                L.emission.z *= t[2];
            }
            const float e = ms_light_irradiance(&L, p, ns), sh = f->shadow[l * nt + i];
            c[0] += e * L.emission.x * sh;
            c[1] += e * L.emission.y * sh;
            c[2] += e * L.emission.z * sh;
            y += e * (0.2126f * L.emission.x + 0.7152f * L.emission.y + 0.0722f * L.emission.z);
        }
        memcpy(f->rgb + 3 * i, c, sizeof c);
        lum[i] = y;
    }
    size_t kk = 0;   /* the texels' luminances, in row order */
    for (size_t i = 0; i < nt; i++)
        if (lm->triangle[i] != MS_NO_TRIANGLE) lum[kk++] = lum[i];
    f->exposure = 1.0f;
    if (lum && m) {
        qsort(lum, m, sizeof *lum, cmp_float);
        const float p99 = lum[(size_t)(0.99 * (double)(m - 1))];
        if (p99 > 0.0f) f->exposure = 1.0f / p99;
    }
    free(lum);
    if (dilate(f, passes, lm)) { snprintf(err, errlen, "out of memory dilating the lightmap"); return MS_ERR_NO_MEMORY; }
    /* A NaN or infinite texel is an error, never a lightmap (microshadow.h: MS_MAX_RADIANCE); checked before
     * the stitching would spread it. */
    if (ms_frame_check_finite(f, "the lightmap", err, errlen)) return MS_ERR_INVALID;
    if (o->pass) o->pass(o->pass_user, "irradiance and dilation", omp_get_wtime() - t_finish);
    ms_status st = seams(scene, o, lm, threads, err, errlen);
    if (st) return st;
    f->stats.width = size;
    f->stats.height = f->height;
    f->stats.triangles = scene->n_tris;
    f->stats.load_s = scene->load_s;
    f->stats.total_s = scene->load_s + lm->unwrap_s + lm->raster_s + lm->leak_s + f->stats.build_s + f->stats.setup_s + f->stats.shadow_s +
                        lm->stitch_s;
    return MS_OK;
}

/* ms_bake_layout, every row in one ms_bake_rows call, ms_bake_finish. */
ms_status ms_bake_abi(const ms_abi *abi, const ms_scene *scene, const ms_accel *accel, const ms_bake_options *opt_in,
                      ms_lightmap *out, char *err, size_t errlen)
{
    ms_bake_options opt_copy;
    const ms_bake_options *o;
    const ms_status ast = bake_entry(abi, "ms_bake", opt_in, &opt_copy, &o, err, errlen);
    if (ast) return ast;
    const double t_start = omp_get_wtime();
    if (out) memset(out, 0, sizeof *out);
    const int size = o->size ? o->size : 1024;
    uint64_t need = 0;
    if (scene && (scene->tri || !scene->n_tris) && size >= 1 && size <= MS_MAX_IMAGE_SIZE && o->uv_set >= -1 &&
        o->uv_set < MS_MAX_UV_SETS) {   /* with the accel built here; ms_bake_layout checks the rest */
        ms_status bst = bake_budget(scene, o, size, 1, !accel, &need, err, errlen);
        if (bst) return bst;
    }
    ms_status st = ms_bake_layout(scene, o, out, err, errlen);
    if (st) return st;
    ms_accel *own = NULL;
    if (!accel) {
        const double t_accel = omp_get_wtime();
        st = ms_accel_build(scene, o->points.threads, &own, err, errlen);
        accel = own;
        if (!st && o->pass) o->pass(o->pass_user, "acceleration structure", omp_get_wtime() - t_accel);
    }
    if (!st) st = ms_bake_rows(accel, o, out, 0, out->frame.height, err, errlen);
    if (!st) st = ms_bake_finish(scene, o, out, err, errlen);
    ms_accel_free(own);
    if (st) { ms_lightmap_free(out); return st; }
    out->frame.stats.total_s = omp_get_wtime() - t_start + scene->load_s;
    out->frame.stats.memory_need = need;
    out->frame.stats.memory_budget = ms_memory_budget(o->points.max_memory);
    return MS_OK;
}
