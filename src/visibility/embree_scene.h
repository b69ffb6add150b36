/* The Embree scene shared by the primary method "embree" (primary/primary_embree.c) and the shadow method
 * "embree" (shadow/embree/embree.c), below both (docs/embree.md).
 *
 * Scene: ctx->bvh->tri (leaf order) as one Embree triangle geometry, so Embree's primID is our prim
 * id; build quality high; two-sided (acquiring fails if this Embree was built with back-face culling).
 * The two methods share one RTCDevice/RTCScene: the first create() of a frame builds it, the other finds
 * it in a small mutex-protected cache keyed by the frame's BVH and holds a reference; the last destroy()
 * releases it.
 *
 * FTZ/DAZ: Embree wants flush-to-zero and denormals-are-zero; every entry point that calls into
 * Embree sets them in MXCSR for the calling thread (ms_embree_enter) and restores the caller's MXCSR on
 * return (ms_embree_leave), so that other methods run on the same OpenMP threads are not affected.
 *
 * Robust mode (RTC_SCENE_FLAG_ROBUST) for the one scene, so for shadow and primary rays alike: Embree's
 * watertight triangle test and conservative traversal, as ours (src/accel/ray_triangle.h): no ray
 * slips between two triangles that share an edge. Every triangle is given as it is, slivers and
 * zero-area ones included, as our ray tests take them all.
 *
 * Timing: the Embree build happens in create(), which ms_render does not time; the shadow method reports
 * it once per frame as the counter "embree_build_us". */
#ifndef MS_EMBREE_SCENE_H
#define MS_EMBREE_SCENE_H
#include <stddef.h>
#include <stdint.h>
#include <embree3/rtcore.h>
#include "visibility/context.h"
#include "visibility/alpha.h"

/* One Embree scene for one frame, shared by the primary and the shadow method. */
typedef struct ms_embree_scene {
    struct ms_embree_scene *next;
    const ms_bvh *bvh;         /* key: the frame's BVH and its triangle array */
    const float *tri;
    uint32_t n_tris;
    int refs;                  /* guarded by cache_lock */
    RTCDevice dev;
    RTCScene scene;
    ms_embree_mode mode;
    ms_embree_filter filter;
    uint64_t build_us;
    int build_reported;        /* set once by the visibility call that reports build_us */
    char msg[256];             /* Embree's last error message (error callback) */
} ms_embree_scene;

/* RTCIntersectContext extended with what the filter needs; Embree hands the filter our pointer. */
typedef struct ms_embree_ictx {
    struct RTCIntersectContext c;   /* must be first */
    uint32_t skip;                  /* the receiver's triangle, UINT32_MAX: none to reject */
    uint64_t *rejects;              /* counts the receiver-triangle rejections; NULL: not counted */
    /* Alpha-tested triangles (alpha.h), NULL: none. Shadow rays: the receiver point and its sample points
     * (ray id = sample index); primary rays (primary = 1): the ray's own origin and direction decide. */
    const ms_alpha *alpha;
    const float *p, *pts;
    int primary;
} ms_embree_ictx;

/* Finds or builds the frame's scene and takes a reference (*state: the ms_embree_scene); 0, or -1 with a
 * message in err. The create() of both methods. */
int ms_embree_scene_acquire(const ms_render_ctx *ctx, void **state, char *err, size_t errlen);
/* Drops the reference; the last one frees the scene. The destroy() of both methods. */
void ms_embree_scene_release(void *state);

/* Sets FTZ/DAZ for the calling thread and returns the caller's MXCSR, which ms_embree_leave restores. */
unsigned ms_embree_enter(void);
void ms_embree_leave(unsigned saved);

/* The context filter: rejects the receiver's own triangle, and a hit on an alpha-tested triangle where it is
 * transparent (any hit for shadow rays, closest hit for primary rays: Embree then goes on past it), by the
 * decision every method shares (alpha.h): the segment from the receiver to the ray's sample point, or the
 * camera ray's line. */
void ms_embree_context_filter(const struct RTCFilterFunctionNArguments *a);

#endif
