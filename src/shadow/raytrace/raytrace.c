/* Method "raytrace": the reference. One any-hit shadow segment per light sample in front of the
 * receiver's plane through our BVH, from the hit point to the sample, occluding for parameters in [near, far] and never by
 * the hit triangle. The k*k rays of a pixel share their origin and point at one small light, so they
 * are traced as 16-ray packets: a node is visited when any live ray of the packet enters it, and each
 * triangle is tested against the packet's rays that are still unoccluded (raytrace_impl.h, compiled per
 * ISA and chosen under the context's cap; the lane loops are plain C that each file's compiler vectorises
 * for its instruction set). */
#include "raytrace.h"
#include "visibility/occluders.h"
#include <stdio.h>
#include <stdlib.h>

ms_raytrace_fn ms_raytrace_select(ms_isa cap, ms_isa *chosen)
{
    static const ms_raytrace_fn table[] = {
        [MS_ISA_SCALAR] = ms_raytrace_samples_scalar,
        [MS_ISA_AVX2] = ms_raytrace_samples_avx2,
        [MS_ISA_AVX512] = ms_raytrace_samples_avx512,
    };
    const ms_isa isa = ms_isa_select(cap, MS_ISA_ALL);   /* every level has an instance: never AUTO */
    if (chosen) *chosen = isa;
    return table[isa];
}

int ms_raytrace_visible_samples(const ms_render_ctx *ctx, const ms_shadow_query *q, float *pts,
                                const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    return ms_raytrace_select(ctx->isa_cap, NULL)(ctx, q, pts, front, vis, cnt);
}

typedef struct rt_state {
    ms_raytrace_fn trace;
    ms_isa isa;
} rt_state;

static int rt_create(const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    rt_state *s = malloc(sizeof *s);
    if (!s) { snprintf(err, errlen, "out of memory"); return -1; }
    s->trace = ms_raytrace_select(ctx->isa_cap, &s->isa);
    *state = s;
    return 0;
}

static int rt_visibility(void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int nq,
                         const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    const rt_state *s = state;
    float *pts = malloc((size_t)ctx->samples * 3 * sizeof(float));
    if (!pts) return -1;
    const size_t mw = (size_t)ctx->mask_words;
    for (int qi = 0; qi < nq; qi++) s->trace(ctx, &q[qi], pts, front + qi * mw, vis + qi * mw, cnt);
    free(pts);
    return 0;
}

static void rt_destroy(void *state) { free(state); }

static void rt_isa_used(const void *state, ms_isa *kernel, ms_isa *traversal)
{
    const rt_state *s = state;
    *kernel = *traversal = s->isa;
}

const ms_shadow_method ms_shadow_raytrace = {
    .name = "raytrace",
    .primary = "bvh",
    .needs_grid = 0,
    .occluders = MS_OCC_CULL,
    .n_counters = 3,
    .counter_names = { "packets", "packet_node_visits", "packet_triangle_tests" },
    .create = rt_create,
    .visibility = rt_visibility,
    .destroy = rt_destroy,
    .isa_used = rt_isa_used,
};
