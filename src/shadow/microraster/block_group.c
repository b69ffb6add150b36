/* Grouping of queries into blocks of at most 16 frusta (block_group.h). */
#include "block_group.h"
#include "block_traverse.h"
#include <stdlib.h>

/* A query's 4x4 pixel block, as a sort key: rows of blocks, then blocks in a row. */
static uint64_t block_key(const ms_shadow_query *q) { return (uint64_t)(q->py >> 2) << 32 | (q->px >> 2); }

static int cmp_by_block(const void *a, const void *b, void *arg)
{
    const ms_shadow_query *q = arg;
    const uint64_t ka = block_key(&q[*(const int *)a]), kb = block_key(&q[*(const int *)b]);
    return ka < kb ? -1 : ka > kb;
}

int ms_block_order(const ms_render_ctx *ctx, const ms_shadow_query *q, int nq, int *order)
{
    for (int i = 0; i < nq; i++) order[i] = i;
    if (!ctx->queries_in_order) qsort_r(order, (size_t)nq, sizeof *order, cmp_by_block, (void *)q);
    return 0;
}

int ms_block_group_end(const ms_render_ctx *ctx, const ms_shadow_query *q, const int *order, int nq, int g)
{
    const uint64_t key = block_key(&q[order[g]]);
    int e = g + 1;
    while (e < nq && e - g < MS_BLOCK_LANES && (ctx->queries_in_order || block_key(&q[order[e]]) == key)) e++;
    return e;
}
