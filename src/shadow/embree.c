/* Method "embree": the same V as "raytrace", computed by Intel Embree 3, the ray tracer our users
 * would otherwise use. Everything we claim is a ratio against this method, and it is the independent
 * cross-check of our answers (tests/test_embree.c). See docs/embree.md.
 *
 * Scene: ctx->bvh->tri (leaf order) as one Embree triangle geometry, so Embree's primID is our prim
 * id; build quality high; two-sided (create fails if this Embree was built with back-face culling).
 * The primary method "embree" and the shadow method "embree" share one RTCDevice/RTCScene: the first
 * create() of a frame builds it, the other finds it in a small mutex-protected cache keyed by the
 * frame's BVH and holds a reference; the last destroy() releases it.
 *
 * Shadow rays: per pixel the segments to the samples of the chosen pattern (ms_pattern_points) that are
 * in front of the receiver's plane (the front mask, receiver.h), origin q.p, direction sample - q.p
 * unnormalised, tnear = ctx->near, tfar = ctx->far, exactly as raytrace.
 * Traced either as 16-wide packets (rtcOccluded16) or as one coherent stream per pixel (rtcOccluded1M
 * with RTC_INTERSECT_CONTEXT_FLAG_COHERENT), chosen by ms_render_options.embree_mode (default packet16:
 * the faster here, docs/embree.md).
 *
 * The hit triangle q.prim never occludes. Embree excludes it through a context filter function that
 * rejects primID == q.prim, the prim passed in an extension of RTCIntersectContext. The filter is
 * only needed when the receiver's own triangle can be hit within [near, far] at all. Only front samples
 * are traced, so it cannot when rounding left the hit point on the front side of its triangle's plane,
 * nor, when it left it behind by dp, when every light corner is higher above the point than 2|dp|/near
 * (every segment crosses the plane at t < near/2); the margin is orders of magnitude above Embree's
 * rounding, so for those pixels the filter is left out (eb_needs_filter). Exactly consistent with
 * raytrace either way (the test checks bit-identical V against filtering every pixel); the choice is
 * ms_render_options.embree_filter: plane (default), always, or none (for measuring only: the receiver's
 * triangle then occludes, V is wrong).
 *
 * Alpha-tested triangles (alpha.h): the same context filter, set for every pixel when the scene has any, rejects
 * a hit where the triangle is transparent for that ray's segment (the receiver point and the sample point, the
 * ray id being the sample index), so Embree goes on looking; for primary rays the ray's own line decides.
 *
 * FTZ/DAZ: Embree wants flush-to-zero and denormals-are-zero; every entry point that calls into
 * Embree sets them in MXCSR for the calling thread and restores the caller's MXCSR on return, so that
 * other methods run on the same OpenMP threads are not affected.
 *
 * Robust mode (RTC_SCENE_FLAG_ROBUST) for the one scene, so for shadow and primary rays alike: Embree's
 * watertight triangle test and conservative traversal, as ours (src/accel/ray_triangle.h): no ray
 * slips between two triangles that share an edge. Every triangle is given as it is, slivers and
 * zero-area ones included, as our ray tests take them all.
 *
 * Timing: the Embree build happens in create(), which ms_render does not time; it is reported once per
 * frame as the counter "embree_build_us". */
#include "method.h"
#include "receiver.h"
#include "alpha.h"
#include "../core/pattern.h"
#include "../core/vec.h"
#include "../accel/ray_triangle.h"
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <xmmintrin.h>
#include <pmmintrin.h>

enum { C_RAYS, C_CALLS, C_FILTERED_PIXELS, C_FILTER_REJECTS, C_BUILD_US };

/* One Embree scene for one frame, shared by the primary and the shadow method. */
typedef struct eb_shared {
    struct eb_shared *next;
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
} eb_shared;

static pthread_mutex_t cache_lock = PTHREAD_MUTEX_INITIALIZER;
static eb_shared *cache;

/* RTCIntersectContext extended with what the filter needs; Embree hands the filter our pointer. */
typedef struct eb_ictx {
    struct RTCIntersectContext c;   /* must be first */
    uint32_t skip;                  /* the receiver's triangle, UINT32_MAX: none to reject */
    uint64_t *cnt;
    /* Alpha-tested triangles (alpha.h), NULL: none. Shadow rays: the receiver point and its sample points
     * (ray id = sample index); primary rays (primary = 1): the ray's own origin and direction decide. */
    const ms_alpha *alpha;
    const float *p, *pts;
    int primary;
} eb_ictx;

/* ---- FTZ/DAZ around every call into Embree ---- */

static unsigned eb_enter(void)
{
    unsigned saved = _mm_getcsr();
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    return saved;
}

static void eb_leave(unsigned saved) { _mm_setcsr(saved); }

/* ---- errors ---- */

static const char *eb_error_name(enum RTCError e)
{
    switch (e) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_UNKNOWN: return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    }
    return "unrecognised error";
}

static void eb_error_cb(void *user, enum RTCError code, const char *str)
{
    eb_shared *s = user;
    snprintf(s->msg, sizeof s->msg, "%s%s%s", eb_error_name(code), str && *str ? ": " : "", str ? str : "");
}

/* 0 if the device has no pending error, else -1 and "Embree <what>: <error>" in err. */
static int eb_check(eb_shared *s, const char *what, char *err, size_t errlen)
{
    enum RTCError e = rtcGetDeviceError(s->dev);
    if (e == RTC_ERROR_NONE) return 0;
    snprintf(err, errlen, "Embree %s failed: %s", what, s->msg[0] ? s->msg : eb_error_name(e));
    return -1;
}

static double eb_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- the shared scene ---- */

static void eb_free(eb_shared *s)
{
    if (s->scene) rtcReleaseScene(s->scene);
    if (s->dev) rtcReleaseDevice(s->dev);
    free(s);
}

static int eb_build(const ms_render_ctx *ctx, eb_shared *s, char *err, size_t errlen)
{
    const ms_bvh *b = ctx->bvh;
    char cfg[64];
    snprintf(cfg, sizeof cfg, "threads=%d,set_affinity=0", ctx->threads > 0 ? ctx->threads : 0);
    s->dev = rtcNewDevice(cfg);
    if (!s->dev) {
        snprintf(err, errlen, "Embree device creation failed: %s", eb_error_name(rtcGetDeviceError(NULL)));
        return -1;
    }
    rtcSetDeviceErrorFunction(s->dev, eb_error_cb, s);
    if (rtcGetDeviceProperty(s->dev, RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED)) {
        snprintf(err, errlen, "this Embree was built with back-face culling; the embree method needs two-sided triangles");
        return -1;
    }
    if ((s->filter != MS_EMBREE_FILTER_NONE || ctx->alpha) && !rtcGetDeviceProperty(s->dev, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED)) {
        snprintf(err, errlen, "this Embree was built without filter functions; the embree method needs them");
        return -1;
    }
    if (s->mode == MS_EMBREE_PACKET16 && !rtcGetDeviceProperty(s->dev, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) {
        snprintf(err, errlen, "this Embree has no 16-wide packets on this CPU; try the stream mode");
        return -1;
    }
    if (s->mode == MS_EMBREE_STREAM && !rtcGetDeviceProperty(s->dev, RTC_DEVICE_PROPERTY_RAY_STREAM_SUPPORTED)) {
        snprintf(err, errlen, "this Embree has no ray streams; try the packet16 mode");
        return -1;
    }

    unsigned mx = eb_enter();
    double t0 = eb_now();
    int rc = -1;
    s->scene = rtcNewScene(s->dev);
    if (eb_check(s, "scene creation", err, errlen)) goto out;
    /* Robust: watertight, like our ray tests. The context filter must be enabled on the scene to be
     * called at all ("none": no filter). */
    rtcSetSceneFlags(s->scene, RTC_SCENE_FLAG_ROBUST |
                               (s->filter != MS_EMBREE_FILTER_NONE || ctx->alpha ? RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION
                                                                                 : RTC_SCENE_FLAG_NONE));
    rtcSetSceneBuildQuality(s->scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry g = rtcNewGeometry(s->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (eb_check(s, "geometry creation", err, errlen)) goto out;
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    /* Embree's own buffers (they are padded for its SIMD loads; ours are not). */
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                       3 * (size_t)b->n_tris);
    unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                           b->n_tris);
    if (!v || !ix || eb_check(s, "buffer allocation", err, errlen)) {
        if (!err[0]) snprintf(err, errlen, "Embree buffer allocation failed");
        rtcReleaseGeometry(g);
        goto out;
    }
    memcpy(v, b->tri, 9 * sizeof(float) * (size_t)b->n_tris);
    for (uint32_t i = 0; i < 3 * b->n_tris; i++) ix[i] = i;
    rtcCommitGeometry(g);
    unsigned id = rtcAttachGeometry(s->scene, g);
    rtcReleaseGeometry(g);
    if (eb_check(s, "geometry set-up", err, errlen)) goto out;
    if (id != 0) { snprintf(err, errlen, "Embree gave geometry id %u, expected 0", id); goto out; }
    rtcCommitScene(s->scene);
    if (eb_check(s, "BVH build", err, errlen)) goto out;
    rc = 0;
out:
    s->build_us = (uint64_t)((eb_now() - t0) * 1e6 + 0.5);
    eb_leave(mx);
    return rc;
}

/* Finds or builds the frame's scene and takes a reference. */
static int eb_acquire(const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    *state = NULL;
    if ((unsigned)ctx->embree_mode > MS_EMBREE_STREAM || (unsigned)ctx->embree_filter > MS_EMBREE_FILTER_NONE) {
        snprintf(err, errlen, "embree: unknown mode %d or filter %d", (int)ctx->embree_mode, (int)ctx->embree_filter);
        return -1;
    }
    pthread_mutex_lock(&cache_lock);
    eb_shared *s;
    for (s = cache; s; s = s->next)
        if (s->bvh == ctx->bvh && s->tri == ctx->bvh->tri && s->n_tris == ctx->bvh->n_tris) break;
    if (s) {
        s->refs++;
    } else if (!(s = calloc(1, sizeof *s))) {
        snprintf(err, errlen, "out of memory for the Embree scene");
    } else {
        s->bvh = ctx->bvh;
        s->tri = ctx->bvh->tri;
        s->n_tris = ctx->bvh->n_tris;
        s->mode = ctx->embree_mode;
        s->filter = ctx->embree_filter;
        if (err && errlen) err[0] = '\0';
        if (eb_build(ctx, s, err, errlen)) {
            eb_free(s);
            s = NULL;
        } else {
            s->refs = 1;
            s->next = cache;
            cache = s;
        }
    }
    pthread_mutex_unlock(&cache_lock);
    *state = s;
    return s ? 0 : -1;
}

static void eb_release(void *state)
{
    eb_shared *s = state;
    if (!s) return;
    pthread_mutex_lock(&cache_lock);
    int last = --s->refs == 0;
    if (last)
        for (eb_shared **p = &cache; *p; p = &(*p)->next)
            if (*p == s) { *p = s->next; break; }
    pthread_mutex_unlock(&cache_lock);
    if (last) eb_free(s);
}

/* ---- shadow rays ---- */

/* The context filter: rejects the receiver's own triangle, and a hit on an alpha-tested triangle where it is
 * transparent (any hit for shadow rays, closest hit for primary rays: Embree then goes on past it), by the
 * decision every method shares (alpha.h): the segment from the receiver to the ray's sample point, or the
 * camera ray's line. */
static void eb_filter_fn(const struct RTCFilterFunctionNArguments *a)
{
    const eb_ictx *c = (const eb_ictx *)a->context;
    const unsigned *prim = (const unsigned *)a->hit + 5 * a->N;   /* RTCHitN primID lane array */
    for (unsigned i = 0; i < a->N; i++) {
        if (!a->valid[i]) continue;
        if (prim[i] == c->skip) {
            a->valid[i] = 0;
            if (c->cnt) c->cnt[C_FILTER_REJECTS]++;
            continue;
        }
        if (!ms_alpha_tested(c->alpha, prim[i])) continue;
        /* RTCRayN lane arrays (rtcore_ray.h's accessors are C++ only): org_x..z at 0..2, dir_x..z at 4..6, id at 10. */
        const float *rf = (const float *)a->ray;
        const unsigned *ru = (const unsigned *)a->ray, N = a->N;
        int opaque;
        if (c->primary) {
            const float o[3] = { rf[0 * N + i], rf[1 * N + i], rf[2 * N + i] };
            const float d[3] = { rf[4 * N + i], rf[5 * N + i], rf[6 * N + i] };
            opaque = ms_alpha_ray_occludes(c->alpha, prim[i], o, d);
        } else {
            opaque = ms_alpha_segment_occludes(c->alpha, prim[i], c->p, c->pts + 3 * (size_t)ru[10 * N + i]);
        }
        if (!opaque) a->valid[i] = 0;
    }
}

/* 1 if a segment from q.p to a front sample can cross the plane of q's own triangle within the
 * occluding range, i.e. if Embree could report the receiver's triangle; see the header comment. */
static int eb_needs_filter(const ms_render_ctx *ctx, const ms_shadow_query *q)
{
    if (q->prim == UINT32_MAX) return 0;   /* a point on no triangle (the points API): nothing to filter */
    const float *tri = ctx->bvh->tri + 9 * (size_t)q->prim;
    float d[3];
    v3_sub(d, q->p, tri);
    /* The point's signed distance to its triangle's plane along q.n (unit) is non-zero only by rounding;
     * `below` bounds how far under the plane it may be, the dot product's own rounding included. Above
     * the plane a segment to a front sample never comes back to it. */
    const float err = 1e-6f * (fabsf(q->n[0] * d[0]) + fabsf(q->n[1] * d[1]) + fabsf(q->n[2] * d[2]));
    const float below = err - v3_dot(q->n, d);
    if (below <= 0.0f) return 0;
    /* Below it, the segment to a sample at height a = (L - P) . n > 0 crosses the plane at t <= below / a:
     * before near/2 (outside the occluding range with a margin) when a > 2 below / near. The height is
     * affine on the light, so its four corners bound every sample's. */
    const ms_light *L = &ctx->light;
    const float c0[3] = { L->corner.x, L->corner.y, L->corner.z };
    const float es[3] = { L->edge_s.x, L->edge_s.y, L->edge_s.z }, et[3] = { L->edge_t.x, L->edge_t.y, L->edge_t.z };
    float rel[3];
    v3_sub(rel, c0, q->p);
    const float a0 = v3_dot(rel, q->n), as = v3_dot(es, q->n), at = v3_dot(et, q->n);
    const float lo = ms_minf(ms_minf(a0, a0 + as), ms_minf(a0 + at, a0 + as + at));
    return !(ctx->near > 0.0f && lo > 2.0f * below / ctx->near);
}

/* Scratch per visibility call: sample points and the ray storage of either mode. */
typedef struct eb_scratch {
    float *pts;
    struct RTCRay *rays;       /* stream: the front samples' rays */
    struct RTCRay16 *r16;      /* packet16: one packet */
} eb_scratch;

static void eb_ray_init(struct RTCRay *r, const ms_render_ctx *ctx, const float p[3], const float *pt, int id)
{
    r->org_x = p[0]; r->org_y = p[1]; r->org_z = p[2];
    r->tnear = ctx->near;
    r->dir_x = pt[0] - p[0];
    r->dir_y = pt[1] - p[1];
    r->dir_z = pt[2] - p[2];
    r->time = 0.0f;
    r->tfar = ctx->far;
    r->mask = 0xFFFFFFFFu;
    r->id = (unsigned)id;
    r->flags = 0;
}

/* Both modes trace only the front samples and set their bits in vis when unoccluded. */
static void eb_trace_stream(eb_shared *s, eb_ictx *ic, const ms_render_ctx *ctx, const ms_shadow_query *q,
                            const eb_scratch *w, const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    const int ns = ctx->samples;
    struct RTCRay *r = w->rays;
    unsigned n = 0;
    for (int i = 0; i < ns; i++)
        if (ms_mask_get(front, i)) eb_ray_init(&r[n++], ctx, q->p, w->pts + 3 * i, i);
    if (!n) return;
    rtcOccluded1M(s->scene, &ic->c, r, n, sizeof *r);
    cnt[C_CALLS]++;
    cnt[C_RAYS] += n;
    for (unsigned i = 0; i < n; i++)
        if (r[i].tfar >= 0.0f) vis[r[i].id >> 6] |= UINT64_C(1) << (r[i].id & 63);   /* occluded: -inf */
}

static void eb_trace_packet16(eb_shared *s, eb_ictx *ic, const ms_render_ctx *ctx, const ms_shadow_query *q,
                              const eb_scratch *w, const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    _Alignas(64) int valid[16];
    const int ns = ctx->samples;
    struct RTCRay16 *r = w->r16;
    for (int base = 0; base < ns; base += 16) {
        const unsigned lanes = (unsigned)(front[base >> 6] >> (base & 63) & 0xFFFFu);
        if (!lanes) continue;
        const float *pt = w->pts + 3 * base;
        for (int l = 0; l < 16; l++) {
            valid[l] = lanes >> l & 1u ? -1 : 0;
            r->org_x[l] = q->p[0]; r->org_y[l] = q->p[1]; r->org_z[l] = q->p[2];
            r->tnear[l] = ctx->near;
            r->dir_x[l] = pt[3 * l] - q->p[0];
            r->dir_y[l] = pt[3 * l + 1] - q->p[1];
            r->dir_z[l] = pt[3 * l + 2] - q->p[2];
            r->time[l] = 0.0f;
            r->tfar[l] = ctx->far;
            r->mask[l] = 0xFFFFFFFFu;
            r->id[l] = (unsigned)(base + l);
            r->flags[l] = 0;
        }
        rtcOccluded16(valid, s->scene, &ic->c, r);
        cnt[C_CALLS]++;
        cnt[C_RAYS] += (uint64_t)__builtin_popcount(lanes);
        uint64_t bits = 0;
        for (int l = 0; l < 16; l++) bits |= (uint64_t)((lanes >> l & 1u) && r->tfar[l] >= 0.0f) << l;
        vis[base >> 6] |= bits << (base & 63);
    }
}

static int eb_visibility(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int nq,
                         const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    eb_shared *s = state;
    const int ns = ctx->samples;
    const size_t mw = (size_t)ctx->mask_words;
    if (!__atomic_exchange_n(&s->build_reported, 1, __ATOMIC_RELAXED)) cnt[C_BUILD_US] += s->build_us;

    eb_scratch w = { 0 };
    w.pts = malloc((size_t)ns * 3 * sizeof(float));
    if (s->mode == MS_EMBREE_STREAM) w.rays = aligned_alloc(64, (size_t)ns * sizeof *w.rays);
    else w.r16 = aligned_alloc(64, sizeof *w.r16);
    if (!w.pts || (!w.rays && !w.r16)) { free(w.pts); free(w.rays); free(w.r16); return -1; }

    unsigned mx = eb_enter();
    eb_ictx ic;
    rtcInitIntersectContext(&ic.c);
    ic.c.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    ic.cnt = cnt;
    ic.alpha = ctx->alpha;
    ic.pts = w.pts;
    ic.primary = 0;
    for (int qi = 0; qi < nq; qi++) {
        const uint64_t *fm = front + qi * mw;
        uint64_t *vm = vis + qi * mw;
        memset(vm, 0, mw * sizeof *vm);
        if (!ms_mask_count(fm, (int)mw)) continue;
        ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q[qi].px, q[qi].py, ctx->seed, w.pts);
        int filt = s->filter == MS_EMBREE_FILTER_ALWAYS || (s->filter == MS_EMBREE_FILTER_PLANE && eb_needs_filter(ctx, &q[qi]));
        ic.c.filter = filt || ctx->alpha ? eb_filter_fn : NULL;
        ic.skip = filt ? q[qi].prim : UINT32_MAX;
        ic.p = q[qi].p;
        cnt[C_FILTERED_PIXELS] += (uint64_t)filt;
        if (s->mode == MS_EMBREE_STREAM) eb_trace_stream(s, &ic, ctx, &q[qi], &w, fm, vm, cnt);
        else eb_trace_packet16(s, &ic, ctx, &q[qi], &w, fm, vm, cnt);
    }
    eb_leave(mx);
    free(w.pts);
    free(w.rays);
    free(w.r16);
    return 0;
}

const ms_shadow_method ms_shadow_embree = {
    .name = "embree",
    .primary = "embree",
    .needs_grid = 0,
    .n_counters = 5,
    .counter_names = { "rays", "embree_calls", "filtered_pixels", "filter_rejects", "embree_build_us" },
    .create = eb_acquire,
    .visibility = eb_visibility,
    .destroy = eb_release,
};

/* ---- primary visibility: camera rays as 16-ray packets over 4x4 pixel blocks ---- */

/* The hit parameter of ray (o, d) on the plane of tri, by the very operations of the watertight test
 * (ms_wt_hit_t: so bit for bit the t the BVH primary finds on that triangle), without its inside
 * test: Embree may report a triangle at an edge that our test would just miss. Embree's own t if the
 * triangle is edge-on. */
static float eb_plane_t(const float tri[9], const float n[3], const float o[3], const float d[3], float t_embree)
{
    ms_wt_ray w;
    ms_wt_eval e;
    ms_wt_prepare(&w, o, d);
    ms_wt_evaluate(&w, tri, &e);
    if (e.det == 0.0f) return t_embree;
    float t = ms_wt_hit_t(&w, tri, n, &e);
    return isfinite(t) && t > 0.0f ? t : t_embree;
}

static void eb_primary_trace(void *state, const ms_render_ctx *ctx, int x0, int y0, int x1, int y1, ms_hit *out)
{
    eb_shared *s = state;
    const int tw = x1 - x0;
    unsigned mx = eb_enter();
    /* Alpha-tested triangles: the context filter lets camera rays through their transparent texels. */
    eb_ictx ec = { .skip = UINT32_MAX, .alpha = ctx->alpha, .primary = 1 };
    struct RTCIntersectContext *const icp = &ec.c;
    rtcInitIntersectContext(icp);
    icp->flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    if (ctx->alpha) icp->filter = eb_filter_fn;
    struct RTCRayHit16 rh __attribute__((aligned(64)));
    int valid[16] __attribute__((aligned(64)));
    int inside[16];   /* the pixel is in the tile (it may still have no ray: outside a fisheye's circle) */
    for (int by = y0; by < y1; by += 4)
        for (int bx = x0; bx < x1; bx += 4) {
            for (int l = 0; l < 16; l++) {
                int x = bx + (l & 3), y = by + (l >> 2);
                float o[3] = { ctx->cam.eye[0], ctx->cam.eye[1], ctx->cam.eye[2] }, d[3] = { 0.0f, 0.0f, 1.0f };
                inside[l] = x < x1 && y < y1;
                valid[l] = inside[l] ? -1 : 0;
                if (valid[l] && ms_camera_ray(&ctx->cam, x, y, o, d)) valid[l] = 0;
                rh.ray.org_x[l] = o[0]; rh.ray.org_y[l] = o[1]; rh.ray.org_z[l] = o[2];
                rh.ray.dir_x[l] = d[0]; rh.ray.dir_y[l] = d[1]; rh.ray.dir_z[l] = d[2];
                rh.ray.tnear[l] = 0.0f;
                rh.ray.tfar[l] = INFINITY;
                rh.ray.time[l] = 0.0f;
                rh.ray.mask[l] = 0xFFFFFFFFu;
                rh.ray.id[l] = (unsigned)l;
                rh.ray.flags[l] = 0;
                rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
                rh.hit.primID[l] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect16(valid, s->scene, icp, &rh);
            for (int l = 0; l < 16; l++) {
                if (!inside[l]) continue;
                int x = bx + (l & 3), y = by + (l >> 2);
                ms_hit *h = &out[(y - y0) * tw + (x - x0)];
                if (!valid[l] || rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) { h->prim = UINT32_MAX; continue; }
                const float o[3] = { rh.ray.org_x[l], rh.ray.org_y[l], rh.ray.org_z[l] };
                const float d[3] = { rh.ray.dir_x[l], rh.ray.dir_y[l], rh.ray.dir_z[l] };
                uint32_t prim = rh.hit.primID[l];
                /* Embree decides which triangle is seen; the hit parameter on it is recomputed by the
                 * shared triangle test, so that a pixel that sees the same triangle gets the very same
                 * point C as with the BVH primary (Embree's t differs by up to tens of ulps). */
                ms_hit_finish(ctx, o, d, eb_plane_t(ctx->bvh->tri + 9 * (size_t)prim, ctx->bvh->tri_n + 3 * (size_t)prim, o, d, rh.ray.tfar[l]), prim, h);
            }
        }
    eb_leave(mx);
}

const ms_primary_method ms_primary_embree = {
    .name = "embree",
    .create = eb_acquire,
    .trace = eb_primary_trace,
    .destroy = eb_release,
};
