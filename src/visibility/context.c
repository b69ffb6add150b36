/* Filling the render context (context.h). */
#include "context.h"
#include "light/pattern.h"
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
