/* Filling the render context (context.h). */
#include "context.h"
#include "light/pattern.h"
#include "light/light_shape.h"
#include <string.h>

void ms_render_ctx_init(ms_render_ctx *ctx, const ms_scene *scene, const ms_bvh *bvh, const ms_light *light,
                        ms_pattern pattern, int k, uint32_t seed, int threads)
{
    memset(ctx, 0, sizeof *ctx);
    ctx->scene = scene;
    ctx->bvh = bvh;
    if (light) ctx->light = *light;
    ctx->pattern = pattern;
    ctx->k = k;
    ctx->samples = ms_pattern_spp(pattern, k);
    ctx->mask_words = (ctx->samples + 63) / 64;   /* bits past samples stay 0 */
    ctx->seed = seed;
    ctx->near = MS_SEGMENT_NEAR;
    ctx->far = MS_SEGMENT_FAR;
    ctx->threads = threads;
    ctx->isa_cap = MS_ISA_AUTO;
}

const ms_render_ctx *ms_ctx_for_query(const ms_render_ctx *ctx, const ms_shadow_query *q, ms_render_ctx *own)
{
    if (!ctx->outline_per_query) return ctx;
    const ms_light_shape_ops *shape = ms_light_shape_of(ctx->light.shape);
    *own = *ctx;
    own->outline_per_query = 0;
    if (shape && shape->outline) shape->outline(&ctx->light, q->p, &own->light);
    return own;
}
