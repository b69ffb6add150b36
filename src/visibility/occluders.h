/* The occluders of one light: the scene's triangles less those of closed components that face away from
 * the whole light (accel/closed.h, docs/culling.md: removing them changes no V and no S), with axis-aligned
 * coplanar rectangles merged (accel/coplanar.h: the same points, ties aside), with their own BVH, so that the methods that take it (ms_shadow_method.culls_closed) traverse and test only what can
 * decide a segment. Built per light at a frame's set-up; the primary's BVH stays the scene's.
 *
 * Prim ids: the occluder BVH names its triangles in its own leaf order. Its tri_source is composed back
 * to the scene's triangle index (as the scene's BVH's is), so that the alpha table (alpha.h) is built
 * over it unchanged; prim_map turns a receiver's prim id (the scene BVH's leaf order, from the primary)
 * into the occluder's (UINT32_MAX: culled, so nothing to skip).
 *
 * The light's interior boxes (accel/interior.h): the boxes inside closed components whose box is apart
 * from the light's (the same condition as the cull), as 12 triangles each in a BVH of their own, for the
 * micro-rasterization methods to rasterize before the scene's triangles. Their prim ids name nothing in
 * the scene: no receiver lies on them and none is alpha-tested.
 *
 * Every bound here (the far margin, the clearance, the box separations) is computed from the scene's and
 * the light's boxes in the scene's frame (docs/design.md, "The scene's frame"), so it is a fixed fraction
 * of the scene wherever the world puts it. */
#ifndef MS_OCCLUDERS_H
#define MS_OCCLUDERS_H
#include <stddef.h>
#include <stdint.h>
#include "microshadow.h"
#include "accel/bvh.h"
#include "accel/closed.h"
#include "accel/interior.h"
#include "context.h"

struct ms_alpha;

typedef struct ms_occluders {
    ms_bvh bvh;                 /* the kept triangles */
    struct ms_alpha *alpha;     /* their alpha table (NULL: all opaque) */
    uint32_t *prim_map;         /* per prim of the scene's BVH: the occluder prim, or UINT32_MAX */
    size_t culled;              /* triangles left out */
    size_t merged;              /* triangles saved by merging coplanar rectangles (accel/coplanar.h) */
    uint8_t *prim_merged;       /* per prim of the scene's BVH: 1 when its triangle is part of a merged face,
                                 * whose receivers are answered on the scene's own triangles; NULL: none */
    unsigned merged_axes;       /* bit a: rectangles were merged along axis a, so a segment whose watertight test
                                 * shears along a may be decided otherwise than on the scene's own triangles
                                 * (accel/coplanar.h); a segment sheared along any other axis never is */
    struct ms_occluders *for_axis[3];   /* with MS_OCC_MERGE_EXACT, per bit of merged_axes: the same cull, merged
                                 * along every axis but a, for the segments sheared along a; NULL: the scene's
                                 * own triangles serve them. Its receivers on merged faces are in prim_merged */
    int active;                 /* 0: nothing culled, use the scene's BVH (the fields above empty) */
    ms_bvh interior;            /* the interior boxes' triangles (n_tris 0: none) */
    ms_bvh interior_box_bvh;    /* the same boxes whole, one prim each (a triangle from corner to corner) */
    float (*interior_box)[6];   /* per prim of interior_box_bvh (its leaf order): the box */
    size_t interior_boxes;
} ms_occluders;

/* Interior boxes (accel/interior.h): grid cells along a component's longest side, and the smallest
 * component that gets them (a few boxes cannot pay for a few triangles). A method that rasterizes each box
 * whole (MS_OCC_INTERIOR_SILHOUETTE) pays one row loop per box and pixel, so more, smaller boxes inside the
 * surface pay there; as up to twelve triangles each they do not. */
#define MS_INTERIOR_RES 32
#define MS_INTERIOR_RES_SILHOUETTE 64
#define MS_INTERIOR_MIN_TRIS 256

/* What a light's occluders are built with (ms_shadow_method.occluders). MS_OCC_INTERIOR_SILHOUETTE (with
 * MS_OCC_INTERIOR; set by the driver from ms_shadow_method.interior_silhouettes): the method rasterizes the
 * boxes whole, as their silhouettes (shadow/microraster/block_box_impl.h), so the boxes are found on the finer
 * grid.
 * MS_OCC_INTERIOR_PASS (with
 * MS_OCC_INTERIOR): a method that does not rasterize the interior boxes itself is run by the frame's driver
 * over them first (a second state whose BVH is the boxes' triangles), then over the scene's triangles with
 * the samples the boxes left (frame_job.c).
 * MS_OCC_MERGE_EXACT (with MS_OCC_MERGE): the method must answer as raytrace does (mft, hpc), so the driver
 * gives each sample to the set exact for its segment's shear axis (for_axis; frame_job.c, shadow_frame.c). */
enum { MS_OCC_CULL = 1, MS_OCC_INTERIOR = 2, MS_OCC_CULL_BY_DEFAULT = 4, MS_OCC_MERGE = 8, MS_OCC_INTERIOR_PASS = 16,
       MS_OCC_MERGE_EXACT = 32, MS_OCC_INTERIOR_SILHOUETTE = 64 };

/* The interior boxes' grid for occluders built with `what` (MS_OCC_*). */
static inline int ms_interior_res(int what)
{
    return (what & MS_OCC_INTERIOR_SILHOUETTE) ? MS_INTERIOR_RES_SILHOUETTE : MS_INTERIOR_RES;
}

/* The occluders of light l (every shape: its hull is its parallelogram, or a sphere's box) for the scene
 * whose BVH is `scene_bvh` and closed components `closed` (found over scene->tri), with alpha-tested
 * components left as they are (`scene_alpha`: the scene BVH's alpha table, NULL when opaque): with
 * MS_OCC_CULL in `what` the cull, with MS_OCC_MERGE the merge (o->active = 0 when neither changes anything:
 * the scene's BVH serves), with MS_OCC_INTERIOR the boxes of
 * `interior` (found with clearance interior_eps; none for a light so far that the clearance no longer
 * covers the near range). 0, or -1 when out of memory. */
int ms_occluders_build(ms_occluders *o, const ms_scene *scene, const ms_bvh *scene_bvh, const ms_closed *closed,
                       const ms_interior *interior, double interior_eps, const struct ms_alpha *scene_alpha,
                       const ms_light *l, int what, int threads);

/* Points whose convex hull holds every point of light l (a planar shape's parallelogram, a round shape's
 * bounding box) and their box; returns their number (4 or 8). */
int ms_light_hull(const ms_light *l, float pts[8][3], float box[6]);

/* 1 when a receiver at p on triangle tri (9 floats) may be answered with merged coplanar faces (coplanar.h):
 * tri is not axis-aligned, or p is so close to tri's plane x_a = c, and every light point so far on one
 * side of it, that no segment from p to the light meets that plane at a parameter of 0.5 near or more
 * (|p_a - c| < 0.5 near |L_a - c|): then neither tiling of the face is ever met beyond the near range. */
int ms_merged_receiver_ok(const float tri[9], const float p[3], const float (*hull)[3], int n_hull);

/* The same per sample, for a receiver the light as a whole fails (a face whose plane crosses the light: a bar's
 * side under a light above): 1 when every sample point pts[i] (3 floats each, i < n) that front holds is either
 * strictly on p's side of tri's plane (the segment never meets it) or so far on the other that the segment meets
 * it below half the near range (|p_a - c| < 0.5 near |pts_a - c|, as above). Only the receiver's own samples in
 * front count: the others are blocked for every method from the start. */
int ms_merged_receiver_ok_samples(const float tri[9], const float p[3], const float *pts, const uint64_t *front, int n);

/* The clearance interior boxes need so that every light of the scene may use them (docs/culling.md):
 * 2.5 times the near range (MS_SEGMENT_NEAR) times the longest segment, the diagonal of the scene's and
 * the lights' boxes together. */
double ms_interior_clearance(const ms_bvh *scene_bvh, const ms_light *lights, size_t n_lights);
void ms_occluders_free(ms_occluders *o);
/* c over the set o, as frames and the points API hand it to a method: o's BVH, alpha table and maps when o is
 * active (else c's, the scene's, stay), and o's interior boxes when it has any. */
void ms_occluders_ctx(const ms_occluders *o, ms_render_ctx *c);

#endif
