/* The Embree scene shared by the primary and the shadow method "embree" (embree_scene.h). */
#include "embree_scene.h"
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <xmmintrin.h>
#include <pmmintrin.h>

static pthread_mutex_t cache_lock = PTHREAD_MUTEX_INITIALIZER;
static ms_embree_scene *cache;


/* ---- FTZ/DAZ around every call into Embree ---- */

unsigned ms_embree_enter(void)
{
    unsigned saved = _mm_getcsr();
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    return saved;
}

void ms_embree_leave(unsigned saved) { _mm_setcsr(saved); }

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
    ms_embree_scene *s = user;
    snprintf(s->msg, sizeof s->msg, "%s%s%s", eb_error_name(code), str && *str ? ": " : "", str ? str : "");
}

/* 0 if the device has no pending error, else -1 and "Embree <what>: <error>" in err. */
static int eb_check(ms_embree_scene *s, const char *what, char *err, size_t errlen)
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

static void eb_free(ms_embree_scene *s)
{
    if (s->scene) rtcReleaseScene(s->scene);
    if (s->dev) rtcReleaseDevice(s->dev);
    free(s);
}

static int eb_build(const ms_render_ctx *ctx, ms_embree_scene *s, char *err, size_t errlen)
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
    if (s->mode == MS_EMBREE_PACKET8 && !rtcGetDeviceProperty(s->dev, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) {
        snprintf(err, errlen, "this Embree has no 8-wide packets on this CPU; try the stream mode");
        return -1;
    }
    if (s->mode == MS_EMBREE_STREAM && !rtcGetDeviceProperty(s->dev, RTC_DEVICE_PROPERTY_RAY_STREAM_SUPPORTED)) {
        snprintf(err, errlen, "this Embree has no ray streams; try the packet16 mode");
        return -1;
    }

    unsigned mx = ms_embree_enter();
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
    ms_embree_leave(mx);
    return rc;
}

/* Finds or builds the frame's scene and takes a reference. */
int ms_embree_scene_acquire(const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    *state = NULL;
    if ((unsigned)ctx->embree_mode > MS_EMBREE_PACKET8 || (unsigned)ctx->embree_filter > MS_EMBREE_FILTER_NONE) {
        snprintf(err, errlen, "embree: unknown mode %d or filter %d", (int)ctx->embree_mode, (int)ctx->embree_filter);
        return -1;
    }
    pthread_mutex_lock(&cache_lock);
    ms_embree_scene *s;
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

void ms_embree_scene_release(void *state)
{
    ms_embree_scene *s = state;
    if (!s) return;
    pthread_mutex_lock(&cache_lock);
    int last = --s->refs == 0;
    if (last)
        for (ms_embree_scene **p = &cache; *p; p = &(*p)->next)
            if (*p == s) { *p = s->next; break; }
    pthread_mutex_unlock(&cache_lock);
    if (last) eb_free(s);
}

/* ---- the context filter ---- */

void ms_embree_context_filter(const struct RTCFilterFunctionNArguments *a)
{
    const ms_embree_ictx *c = (const ms_embree_ictx *)a->context;
    const unsigned *prim = (const unsigned *)a->hit + 5 * a->N;   /* RTCHitN primID lane array */
    for (unsigned i = 0; i < a->N; i++) {
        if (!a->valid[i]) continue;
        if (prim[i] == c->skip) {
            a->valid[i] = 0;
            if (c->rejects) (*c->rejects)++;
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

