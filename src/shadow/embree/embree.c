/* Method "embree": the same V as "raytrace", computed by Intel Embree 3, the ray tracer our users
 * would otherwise use. Everything we claim is a ratio against this method, and it is the independent
 * cross-check of our answers (tests/test_embree.c). See docs/embree.md.
 *
 * The Embree scene is shared with the primary method "embree" (visibility/embree_scene.h).
 *
 * Shadow rays: per pixel the segments to the samples of the chosen pattern (ms_pattern_points) that are
 * in front of the receiver's plane (the front mask, receiver.h), origin q.p, direction sample - q.p
 * unnormalised, tnear = ctx->near, tfar = ctx->far, exactly as raytrace.
 * Traced as 16-wide packets (rtcOccluded16), 8-wide packets (rtcOccluded8) or one coherent stream per
 * pixel (rtcOccluded1M with RTC_INTERSECT_CONTEXT_FLAG_COHERENT), chosen by ms_render_options.embree_mode
 * (default packet16; which is fastest depends on the CPU, docs/embree.md).
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
 * ray id being the sample index), so Embree goes on looking; for primary rays the ray's own line decides. */
#include "shadow/method.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "light/pattern.h"
#include "core/vec.h"
#include "light/light_frame.h"
#include "visibility/embree_scene.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { C_RAYS, C_CALLS, C_FILTERED_PIXELS, C_FILTER_REJECTS, C_BUILD_US };

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
    ms_light_frame F;
    ms_light_frame_of(L, &F);
    const float *c0 = F.corner, *es = F.edge_s, *et = F.edge_t;
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
    void *packet;              /* packet8 / packet16: one packet (struct RTCRay8 or RTCRay16) */
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
static void eb_trace_stream(ms_embree_scene *s, ms_embree_ictx *ic, const ms_render_ctx *ctx, const ms_shadow_query *q,
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

/* Packets of W = 8 or 16 rays (rtcOccluded8 / rtcOccluded16), written once for both widths: which is
 * faster depends on the CPU (a core that runs 512-bit operations as two halves favours 8). */
#define EB_TRACE_PACKET(W)                                                                                          \
    static void eb_trace_packet##W(ms_embree_scene *s, ms_embree_ictx *ic, const ms_render_ctx *ctx,               \
                                   const ms_shadow_query *q, const eb_scratch *w, const uint64_t *front,            \
                                   uint64_t *vis, uint64_t *cnt)                                                    \
    {                                                                                                               \
        _Alignas(64) int valid[W];                                                                                  \
        const int ns = ctx->samples;                                                                                \
        struct RTCRay##W *r = (struct RTCRay##W *)w->packet;                                                        \
        for (int base = 0; base < ns; base += W) {                                                                  \
            const unsigned lanes = (unsigned)(front[base >> 6] >> (base & 63) & ((1u << W) - 1u));                 \
            if (!lanes) continue;                                                                                   \
            const float *pt = w->pts + 3 * base;                                                                    \
            for (int l = 0; l < W; l++) {                                                                           \
                valid[l] = lanes >> l & 1u ? -1 : 0;                                                                \
                r->org_x[l] = q->p[0]; r->org_y[l] = q->p[1]; r->org_z[l] = q->p[2];                                \
                r->tnear[l] = ctx->near;                                                                            \
                r->dir_x[l] = pt[3 * l] - q->p[0];                                                                  \
                r->dir_y[l] = pt[3 * l + 1] - q->p[1];                                                              \
                r->dir_z[l] = pt[3 * l + 2] - q->p[2];                                                              \
                r->time[l] = 0.0f;                                                                                  \
                r->tfar[l] = ctx->far;                                                                              \
                r->mask[l] = 0xFFFFFFFFu;                                                                           \
                r->id[l] = (unsigned)(base + l);                                                                    \
                r->flags[l] = 0;                                                                                    \
            }                                                                                                       \
            rtcOccluded##W(valid, s->scene, &ic->c, r);                                                             \
            cnt[C_CALLS]++;                                                                                         \
            cnt[C_RAYS] += (uint64_t)__builtin_popcount(lanes);                                                     \
            uint64_t bits = 0;                                                                                      \
            for (int l = 0; l < W; l++) bits |= (uint64_t)((lanes >> l & 1u) && r->tfar[l] >= 0.0f) << l;          \
            vis[base >> 6] |= bits << (base & 63);                                                                  \
        }                                                                                                           \
    }
EB_TRACE_PACKET(8)
EB_TRACE_PACKET(16)
#undef EB_TRACE_PACKET

static int eb_visibility(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int nq,
                         const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    ms_embree_scene *s = state;
    const int ns = ctx->samples;
    const size_t mw = (size_t)ctx->mask_words;
    if (!__atomic_exchange_n(&s->build_reported, 1, __ATOMIC_RELAXED)) cnt[C_BUILD_US] += s->build_us;

    eb_scratch w = { 0 };
    w.pts = malloc((size_t)ns * 3 * sizeof(float));
    if (s->mode == MS_EMBREE_STREAM) w.rays = aligned_alloc(64, (size_t)ns * sizeof *w.rays);
    else w.packet = aligned_alloc(64, sizeof(struct RTCRay16));
    if (!w.pts || (!w.rays && !w.packet)) { free(w.pts); free(w.rays); free(w.packet); return -1; }
    void (*trace)(ms_embree_scene *, ms_embree_ictx *, const ms_render_ctx *, const ms_shadow_query *,
                  const eb_scratch *, const uint64_t *, uint64_t *, uint64_t *) =
        s->mode == MS_EMBREE_STREAM ? eb_trace_stream : s->mode == MS_EMBREE_PACKET8 ? eb_trace_packet8 : eb_trace_packet16;

    unsigned mx = ms_embree_enter();
    ms_embree_ictx ic;
    rtcInitIntersectContext(&ic.c);
    ic.c.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    ic.rejects = &cnt[C_FILTER_REJECTS];
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
        ic.c.filter = filt || ctx->alpha ? ms_embree_context_filter : NULL;
        ic.skip = filt ? q[qi].prim : UINT32_MAX;
        ic.p = q[qi].p;
        cnt[C_FILTERED_PIXELS] += (uint64_t)filt;
        trace(s, &ic, ctx, &q[qi], &w, fm, vm, cnt);
    }
    ms_embree_leave(mx);
    free(w.pts);
    free(w.rays);
    free(w.packet);
    return 0;
}

const ms_shadow_method ms_shadow_embree = {
    .name = "embree",
    .primary = "embree",
    .needs_grid = 0,
    .n_counters = 5,
    .counter_names = { "rays", "embree_calls", "filtered_pixels", "filter_rejects", "embree_build_us" },
    .create = ms_embree_scene_acquire,
    .visibility = eb_visibility,
    .destroy = ms_embree_scene_release,
};

