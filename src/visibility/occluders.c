/* A light's occluders (occluders.h): the closed-component cull of accel/closed.c applied to the scene, and
 * a BVH over what is kept. */
#include "occluders.h"
#include "alpha.h"
#include "context.h"
#include "light/light_shape.h"
#include "light/light_frame.h"
#include "accel/coplanar.h"
#include "accel/holes.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Points whose convex hull holds every point of the light (the proof's Λ), and their box: a planar
 * shape's parallelogram (a disk inside its bounding square), a round shape's bounding box (every outline
 * disk a receiver sees lies inside the sphere). Returns the number of points. */
int ms_light_hull(const ms_light *l, float pts[8][3], float box[6])
{
    const ms_light_shape_ops *ops = ms_light_shape_of(l->shape);
    int n;
    if (ops && ops->hull) {
        n = ops->hull(l, pts);
    } else if (ops && ops->outline) {
        const float c[3] = { l->center.x, l->center.y, l->center.z }, r = l->radius;
        for (n = 0; n < 8; n++)
            for (int a = 0; a < 3; a++) pts[n][a] = c[a] + (n >> a & 1 ? r : -r);
    } else {
        const float c[3] = { l->corner.x, l->corner.y, l->corner.z };
        const float s[3] = { l->edge_s.x, l->edge_s.y, l->edge_s.z }, t[3] = { l->edge_t.x, l->edge_t.y, l->edge_t.z };
        for (n = 0; n < 4; n++)
            for (int a = 0; a < 3; a++) pts[n][a] = c[a] + (n & 1 ? s[a] : 0.0f) + (n & 2 ? t[a] : 0.0f);
    }
    for (int a = 0; a < 3; a++) {
        box[a] = box[3 + a] = pts[0][a];
        for (int q = 1; q < n; q++) {
            box[a] = fminf(box[a], pts[q][a]);
            box[3 + a] = fmaxf(box[3 + a], pts[q][a]);
        }
    }
    return n;
}

void ms_occluders_ctx(const ms_occluders *o, ms_render_ctx *c)
{
    if (o->active) {
        c->bvh = &o->bvh;
        c->alpha = o->alpha;
        c->prim_map = o->prim_map;
        c->prim_merged = o->prim_merged;
    }
    if (o->interior.n_tris) {
        c->interior = &o->interior;
        c->interior_box_bvh = &o->interior_box_bvh;
        c->interior_box = (const float (*)[6])o->interior_box;
    }
}

void ms_occluders_free(ms_occluders *o)
{
    for (int a = 0; a < 3; a++)
        if (o->for_axis[a]) { ms_occluders_free(o->for_axis[a]); free(o->for_axis[a]); }
    ms_bvh_free(&o->bvh);
    ms_alpha_free(o->alpha);
    free(o->prim_map);
    free(o->prim_merged);
    ms_bvh_free(&o->interior);
    ms_bvh_free(&o->interior_box_bvh);
    free(o->interior_box);
    memset(o, 0, sizeof *o);
}

/* The diagonal of box b (6 floats) and the light's hull box together. */
static double joint_diag(const float b[6], const float lbox[6])
{
    double d2 = 0.0;
    for (int a = 0; a < 3; a++) {
        const double d = fmax((double)b[3 + a], lbox[3 + a]) - fmin((double)b[a], lbox[a]);
        d2 += d * d;
    }
    return sqrt(d2);
}

static void root_box(const ms_bvh *b, float box[6])
{
    for (int a = 0; a < 3; a++) { box[a] = b->nodes[0].bmin[a]; box[3 + a] = b->nodes[0].bmax[a]; }
}

double ms_interior_clearance(const ms_bvh *scene_bvh, const ms_light *lights, size_t n_lights)
{
    float sbox[6];
    root_box(scene_bvh, sbox);
    double d = 0.0;
    for (size_t l = 0; l < n_lights; l++) {
        float pts[8][3], lbox[6];
        ms_light_hull(&lights[l], pts, lbox);
        d = fmax(d, joint_diag(sbox, lbox));
    }
    return 2.5 * (double)MS_SEGMENT_NEAR * d;
}

/* Per closed component (group: per interior boxes' group, a mod-2 cycle or a holed set): 1 when it holds an
 * alpha-tested triangle (its surface is porous: neither the cull nor the interior boxes hold), or NULL when the
 * scene is opaque. */
static uint8_t *porous_of(const ms_closed *closed, int group, const ms_bvh *scene_bvh, const struct ms_alpha *alpha, int *oom)
{
    *oom = 0;
    const size_t n = group ? ms_closed_groups(closed) : closed->n_components;
    if (!alpha || !alpha->n_alpha || !n) return NULL;
    uint8_t *porous = calloc(n, 1);
    if (!porous) { *oom = 1; return NULL; }
    for (uint32_t i = 0; i < scene_bvh->n_tris; i++) {
        const uint32_t t = scene_bvh->tri_source[i];
        const uint32_t c = group ? ms_closed_group_of(closed, t) : closed->component[t];
        if (ms_alpha_tested(alpha, i) && c != MS_OPEN_COMPONENT) porous[c] = 1;
    }
    return porous;
}

/* 1 when box b of group k holds for the light: a cycle's always; a holed set's when no segment from the box to
 * the light can pass through one of its caps (holes.h, ms_cap_hidden), so that every segment from inside it to
 * the light leaves through the real surface (docs/culling.md, "Holes"). tol: the light points' rounding. *tests
 * counts the cap tests of the light: past MS_CAP_TESTS_PER_LIGHT the holed sets' boxes left are left out (a
 * long rim and many boxes would otherwise cost boxes times caps). */
static int box_holds(const ms_closed *closed, size_t k, const float b[6], const float (*pts)[3], int np, double tol,
                     size_t *tests)
{
    if (k < closed->n_cycles) return 1;
    const size_t h = k - closed->n_cycles, n_caps = closed->cap_start[h + 1] - closed->cap_start[h];
    if (*tests + n_caps > MS_CAP_TESTS_PER_LIGHT) return 0;
    *tests += n_caps;
    for (size_t i = closed->cap_start[h]; i < closed->cap_start[h + 1]; i++)
        if (!ms_cap_hidden(b, pts, np, closed->cap + 9 * i, tol)) return 0;
    return 1;
}

/* The interior boxes whose cycle is apart from the light by `margin`, as up to 12 triangles each. */
static int interior_build(ms_occluders *o, const ms_closed *closed, const ms_interior *in, const uint8_t *porous,
                          const float (*pts)[3], int np, const float lbox[6], double margin, int threads)
{
    float *tri = malloc((in->n_boxes ? in->n_boxes : 1) * 12 * 9 * sizeof *tri);
    float *btri = malloc((in->n_boxes ? in->n_boxes : 1) * 9 * sizeof *btri);
    float (*kept)[6] = malloc((in->n_boxes ? in->n_boxes : 1) * sizeof *kept);
    if (!tri || !btri || !kept) { free(tri); free(btri); free(kept); return -1; }
    size_t nb = 0, nt = 0, cap_tests = 0;
    for (size_t i = 0; i < in->n_boxes; i++) {
        const uint32_t k = in->component[i];
        if (porous && porous[k]) continue;
        const float *cb = ms_closed_group_box(closed, k);
        int sep = 0;
        for (int a = 0; a < 3; a++)
            sep |= (double)lbox[a] > (double)cb[3 + a] + margin || (double)lbox[3 + a] < (double)cb[a] - margin;
        if (!sep) continue;
        const float *b = in->box[i];
        if (!box_holds(closed, k, b, pts, np, margin, &cap_tests)) continue;
        /* The whole box as one prim: a triangle from its low corner to its high one has the box as its bounds. */
        memcpy(kept[nb], b, sizeof kept[nb]);
        for (int a = 0; a < 3; a++) btri[9 * nb + a] = btri[9 * nb + 6 + a] = b[a];
        for (int a = 0; a < 3; a++) btri[9 * nb + 3 + a] = b[3 + a];
        float v[8][3];
        for (int c = 0; c < 8; c++)
            for (int a = 0; a < 3; a++) v[c][a] = b[(c >> a & 1) ? 3 + a : a];
        /* The faces (corner bits: x = 1, y = 2, z = 4; face 2a is the low side of axis a, 2a + 1 the high),
         * two triangles each; the winding does not matter (the kernels are two-sided). Only the faces that
         * some light point lies beyond: a segment that meets the box leaves it through a face its light
         * sample lies beyond (the sample is outside the box), so those faces alone block every segment the
         * whole box blocks; and a box face blocks nothing the real surface does not (the proof above), so
         * leaving faces out can never change an answer. With a light above, about half the faces go. */
        static const int face[6][4] = { { 0, 2, 6, 4 }, { 1, 3, 7, 5 }, { 0, 1, 5, 4 }, { 2, 3, 7, 6 }, { 0, 1, 3, 2 }, { 4, 5, 7, 6 } };
        for (int f = 0; f < 6; f++) {
            const int a = f >> 1;
            if ((f & 1) ? !(lbox[3 + a] > b[3 + a]) : !(lbox[a] < b[a])) continue;
            const int *q = face[f];
            const int tv[2][3] = { { q[0], q[1], q[2] }, { q[0], q[2], q[3] } };
            for (int t = 0; t < 2; t++)
                for (int c = 0; c < 3; c++) memcpy(tri + 9 * (nt + (size_t)t) + 3 * c, v[tv[t][c]], 3 * sizeof(float));
            nt += 2;
        }
        nb++;
    }
    int rc = 0;
    if (nt) {
        rc = ms_bvh_build(&o->interior, tri, nt, threads);
        o->interior_boxes = nb;
        if (!rc) rc = ms_bvh_build(&o->interior_box_bvh, btri, nb, threads);
        if (!rc && !(o->interior_box = malloc(nb * sizeof *o->interior_box))) rc = -1;
        for (uint32_t i = 0; !rc && i < o->interior_box_bvh.n_tris; i++)
            memcpy(o->interior_box[i], kept[o->interior_box_bvh.tri_source[i]], sizeof kept[0]);
    }
    free(tri);
    free(btri);
    free(kept);
    return rc;
}

/* The triangles kept by the cull (keep NULL: all), with coplanar rectangles merged when `merge` (alpha-tested
 * triangles left alone), into o->bvh, o->alpha, o->prim_map; o->active = 0 when that changes nothing. */
static int set_build(ms_occluders *o, const ms_scene *scene, const ms_bvh *scene_bvh, const uint8_t *keep, size_t culled,
                     int merge, int no_axis, const struct ms_alpha *scene_alpha, int threads)
{
    const size_t n = scene->n_tris;
    if (culled == n || (!culled && !merge)) return 0;   /* all culled: only degenerate inputs; keep it simple */
    const size_t nk = n - culled;
    float *tri = malloc(nk * 9 * sizeof *tri), *mtri = NULL;
    uint32_t *src = malloc(nk * sizeof *src), *of_kept = NULL, *msrc = NULL;
    uint8_t *mflag = NULL;
    uint32_t *occ_of_tri = malloc(n * sizeof *occ_of_tri);
    uint8_t *opaque = merge ? malloc(nk ? nk : 1) : NULL;
    uint32_t *leaf_of = scene_alpha && merge ? malloc(n * sizeof *leaf_of) : NULL;
    int rc = -1;
    if (!tri || !src || !occ_of_tri || (merge && !opaque) || (scene_alpha && merge && !leaf_of)) goto done;
    for (uint32_t i = 0; leaf_of && i < scene_bvh->n_tris; i++) leaf_of[scene_bvh->tri_source[i]] = i;
    size_t m = 0;
    for (size_t t = 0; t < n; t++) {
        if (keep && !keep[t]) continue;
        memcpy(tri + 9 * m, scene->tri + 9 * t, 9 * sizeof *tri);
        if (opaque) opaque[m] = !(leaf_of && ms_alpha_tested(scene_alpha, leaf_of[t]));
        src[m++] = (uint32_t)t;
    }
    size_t nb = nk;
    const float *btri = tri;
    if (merge) {
        if (ms_coplanar_merge(tri, nk, opaque, no_axis, &mtri, &nb, &of_kept, &msrc, &mflag, &o->merged_axes)) goto done;
        if (!culled && nb == nk) { rc = 0; goto done; }   /* nothing merged, nothing culled */
        btri = mtri;
        o->merged = nk - nb;
    }
    o->prim_map = malloc((size_t)scene_bvh->n_tris * sizeof *o->prim_map);
    if (!o->prim_map) goto done;
    for (size_t t = 0; t < n; t++) occ_of_tri[t] = UINT32_MAX;
    if (nb == nk) {
        /* Nothing merged: the scene's tree pruned to the kept triangles (ms_bvh_filter), a pass over it
         * where a build would sort them again; its tri_source (scene leaf order) composed back to the
         * scene's triangles. */
        uint8_t *keep_leaf = malloc(scene_bvh->n_tris ? scene_bvh->n_tris : 1);
        if (!keep_leaf) goto done;
        for (uint32_t i = 0; i < scene_bvh->n_tris; i++) keep_leaf[i] = keep[scene_bvh->tri_source[i]];
        const int frc = ms_bvh_filter(&o->bvh, scene_bvh, keep_leaf);
        free(keep_leaf);
        if (frc) goto done;
        for (uint32_t i = 0; i < o->bvh.n_tris; i++) {
            o->bvh.tri_source[i] = scene_bvh->tri_source[o->bvh.tri_source[i]];
            occ_of_tri[o->bvh.tri_source[i]] = i;
        }
    } else {
        if (ms_bvh_build(&o->bvh, btri, nb, threads)) goto done;
        /* The occluder BVH's tri_source indexes its input list: composed back to the scene's triangles (a
         * merged rectangle names one of its halves), and each scene triangle's occluder prim (a merged one:
         * its rectangle's first triangle; the near range keeps a receiver off the coplanar second). */
        uint32_t *leaf_of_set = malloc((nb ? nb : 1) * sizeof *leaf_of_set);
        if (!leaf_of_set) goto done;
        for (uint32_t i = 0; i < o->bvh.n_tris; i++) {
            const uint32_t in = o->bvh.tri_source[i];
            leaf_of_set[in] = i;
            o->bvh.tri_source[i] = src[merge ? msrc[in] : in];
        }
        for (size_t k = 0; k < nk; k++) occ_of_tri[src[k]] = leaf_of_set[merge ? of_kept[k] : k];
        free(leaf_of_set);
    }
    for (uint32_t i = 0; i < scene_bvh->n_tris; i++) o->prim_map[i] = occ_of_tri[scene_bvh->tri_source[i]];
    if (o->merged) {
        /* Receivers on merged faces (coplanar.h) are answered on the scene's own triangles. */
        uint8_t *on = calloc(n ? n : 1, 1);
        o->prim_merged = malloc((size_t)scene_bvh->n_tris);
        if (!on || !o->prim_merged) { free(on); goto done; }
        for (size_t k = 0; k < nk; k++) on[src[k]] = mflag[k];
        for (uint32_t i = 0; i < scene_bvh->n_tris; i++) o->prim_merged[i] = on[scene_bvh->tri_source[i]];
        free(on);
    }
    if (scene_alpha && ms_alpha_build(scene, &o->bvh, &o->alpha)) goto done;
    o->culled = culled;
    o->active = 1;
    rc = 0;
done:
    free(tri);
    free(src);
    free(occ_of_tri);
    free(opaque);
    free(leaf_of);
    free(mtri);
    free(of_kept);
    free(msrc);
    free(mflag);
    if (rc || !o->active) {
        ms_bvh_free(&o->bvh);
        ms_alpha_free(o->alpha);
        free(o->prim_map);
        free(o->prim_merged);
        o->alpha = NULL;
        o->prim_map = NULL;
        o->prim_merged = NULL;
        o->merged = o->culled = 0;
        o->merged_axes = 0;
        o->active = 0;
    }
    return rc;
}

/* The sets exact for the axes along which o merged (occluders.h, for_axis): the same cull, no merge along that
 * axis; their receivers on merged faces join o's. */
static int axis_sets_build(ms_occluders *o, const ms_scene *scene, const ms_bvh *scene_bvh, const uint8_t *keep,
                           size_t culled, const struct ms_alpha *scene_alpha, int threads)
{
    for (int a = 0; a < 3; a++) {
        if (!(o->merged_axes >> a & 1u)) continue;
        ms_occluders *s = calloc(1, sizeof *s);
        if (!s || set_build(s, scene, scene_bvh, keep, culled, 1, a, scene_alpha, threads)) { free(s); return -1; }
        if (!s->active) { free(s); continue; }   /* nothing culled or merged: the scene's own triangles serve */
        for (uint32_t i = 0; s->prim_merged && i < scene_bvh->n_tris; i++) o->prim_merged[i] |= s->prim_merged[i];
        o->for_axis[a] = s;
    }
    return 0;
}

/* The cull's keep flags (docs/culling.md); returns the triangles culled (0 with *keep NULL when nothing). */
static int cull_keep(const ms_scene *scene, const ms_closed *closed, const uint8_t *porous,
                     const float (*pts)[3], int np, const float lbox[6], double margin, uint8_t **keep_out, size_t *culled_out)
{
    const size_t n = scene->n_tris;
    *keep_out = NULL;
    *culled_out = 0;
    uint8_t *keep = malloc(n ? n : 1);
    if (!keep) return -1;
    size_t culled = ms_closed_cull(closed, scene->tri, pts, np, lbox, margin, keep);
    /* Condition 2 of the proof: an alpha-tested triangle makes its component porous; keep the whole
     * component two-sided. */
    for (size_t t = 0; porous && culled && t < n; t++) {
        const uint32_t c = closed->component[t];
        if (!keep[t] && porous[c]) { keep[t] = 1; culled--; }
    }
    if (!culled) { free(keep); return 0; }
    *keep_out = keep;
    *culled_out = culled;
    return 0;
}

int ms_occluders_build(ms_occluders *o, const ms_scene *scene, const ms_bvh *scene_bvh, const ms_closed *closed,
                       const ms_interior *interior, double interior_eps, const struct ms_alpha *scene_alpha,
                       const ms_light *l, int what, int threads)
{
    memset(o, 0, sizeof *o);
    const size_t n = scene->n_tris;
    if (closed->n_tris != n || !scene_bvh->n_nodes || (!ms_closed_groups(closed) && !(what & MS_OCC_MERGE))) return 0;
    float pts[8][3], lbox[6], sbox[6];
    const int np = ms_light_hull(l, pts, lbox);
    for (int i = 0; i < 6; i++)
        if (!isfinite(lbox[i])) return 0;
    root_box(scene_bvh, sbox);
    /* The proof's margin: the far range (1 - MS_SEGMENT_FAR) times the longest segment, bounded by the
     * diagonal of the scene's and the light's boxes together; doubled for the rounding of the boxes. */
    const double diag = joint_diag(sbox, lbox);
    const double margin = 2.0 * (1.0 - (double)MS_SEGMENT_FAR) * diag;
    int rc = 0, oom;
    /* Interior boxes hold for this light when their clearance covers the near range of its longest
     * segment (docs/culling.md). */
    if ((what & MS_OCC_INTERIOR) && interior && interior->n_boxes && interior_eps >= 2.0 * (double)MS_SEGMENT_NEAR * diag) {
        uint8_t *porous = porous_of(closed, 1, scene_bvh, scene_alpha, &oom);
        rc = oom ? -1 : interior_build(o, closed, interior, porous, (const float (*)[3])pts, np, lbox, margin, threads);
        free(porous);
    }
    uint8_t *keep = NULL;
    size_t culled = 0;
    if (!rc && (what & MS_OCC_CULL) && closed->n_components) {
        uint8_t *porous = porous_of(closed, 0, scene_bvh, scene_alpha, &oom);
        rc = oom ? -1 : cull_keep(scene, closed, porous, (const float (*)[3])pts, np, lbox, margin, &keep, &culled);
        free(porous);
    }
    if (!rc && (culled || (what & MS_OCC_MERGE)))
        /* A method that must equal raytrace gets no merge along the light's preferred shear axis: most segments are
         * sheared along it (ms_wt_packet_axis), and so stay on this set (exact_split.h) */
        rc = set_build(o, scene, scene_bvh, keep, culled, (what & MS_OCC_MERGE) != 0,
                       (what & MS_OCC_MERGE_EXACT) ? ms_light_shear_axis(l) : -1, scene_alpha, threads);
    if (!rc && (what & MS_OCC_MERGE_EXACT) && o->merged_axes)
        rc = axis_sets_build(o, scene, scene_bvh, keep, culled, scene_alpha, threads);
    free(keep);
    if (rc) ms_occluders_free(o);
    return rc;
}

/* The axis a of an axis-aligned triangle's plane x_a = c (its three vertices' a equal bitwise), or -1. */
static int face_axis(const float tri[9])
{
    for (int a = 0; a < 3; a++)
        if (tri[a] == tri[3 + a] && tri[a] == tri[6 + a]) return a;
    return -1;
}

int ms_merged_receiver_ok(const float tri[9], const float p[3], const float (*hull)[3], int n_hull)
{
    const int a = face_axis(tri);
    if (a < 0) return 1;   /* not on an axis-aligned face: never merged */
    const double c = tri[a], d = fabs((double)p[a] - c);
    double lmin = INFINITY;
    int above = 0, below = 0;
    for (int q = 0; q < n_hull; q++) {
        const double e = (double)hull[q][a] - c;
        above |= e > 0.0;
        below |= e < 0.0;
        lmin = fmin(lmin, fabs(e));
    }
    return !(above && below) && lmin > 0.0 && d < 0.5 * (double)MS_SEGMENT_NEAR * lmin;
}

int ms_merged_receiver_ok_samples(const float tri[9], const float p[3], const float *pts, const uint64_t *front, int n)
{
    const int a = face_axis(tri);
    if (a < 0) return 1;
    const double c = tri[a], dp = (double)p[a] - c, d = fabs(dp), need = d / (0.5 * (double)MS_SEGMENT_NEAR);
    for (int i = 0; i < n; i++) {
        if (!(front[i >> 6] >> (i & 63) & 1u)) continue;
        const double e = (double)pts[3 * i + a] - c;
        if (e * dp > 0.0) continue;             /* both strictly on one side: the segment never meets the plane */
        if (!(fabs(e) > need)) return 0;        /* it may meet it beyond half the near range */
    }
    return 1;
}
