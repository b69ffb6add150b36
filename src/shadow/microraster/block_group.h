/* Which queries traverse together in the multi-frusta methods (block_raster, mft): the pixels of one 4x4
 * pixel block (frames), or, when the queries come in proximity order (the points API:
 * ms_render_ctx.queries_in_order), 16 consecutive ones. */
#ifndef MS_BLOCK_GROUP_H
#define MS_BLOCK_GROUP_H
#include "shadow/method.h"

/* Fills order[0..nq) with the query indices, grouped; returns 0, or -1 when out of memory. */
int ms_block_order(const ms_render_ctx *ctx, const ms_shadow_query *q, int nq, int *order);
/* The end of the group that starts at order[g] (at most 16 queries). */
int ms_block_group_end(const ms_render_ctx *ctx, const ms_shadow_query *q, const int *order, int nq, int g);

#endif
