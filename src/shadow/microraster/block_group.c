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
    if (ctx->queries_in_order || nq <= 1) {
        for (int i = 0; i < nq; i++) order[i] = i;
        return 0;
    }
    /* A frame's queries cover a rectangle of blocks about as many as the queries / 16: a counting sort by
     * block (stable: a block's queries in their given order, as the merge sort below leaves them), linear
     * where a sort would be n log n. */
    uint32_t bx0 = UINT32_MAX, bx1 = 0, by0 = UINT32_MAX, by1 = 0;
    for (int i = 0; i < nq; i++) {
        const uint32_t bx = q[i].px >> 2, by = q[i].py >> 2;
        bx0 = bx < bx0 ? bx : bx0; bx1 = bx > bx1 ? bx : bx1;
        by0 = by < by0 ? by : by0; by1 = by > by1 ? by : by1;
    }
    const uint64_t nbx = (uint64_t)(bx1 - bx0) + 1, nblocks = nbx * ((uint64_t)(by1 - by0) + 1);
    int *start = nblocks <= 4 * (uint64_t)nq + 1024 ? calloc((size_t)nblocks + 1, sizeof *start) : NULL;
    if (start) {
        for (int i = 0; i < nq; i++) start[(size_t)((q[i].py >> 2) - by0) * nbx + ((q[i].px >> 2) - bx0) + 1]++;
        for (size_t b = 0; b < nblocks; b++) start[b + 1] += start[b];
        for (int i = 0; i < nq; i++) order[start[(size_t)((q[i].py >> 2) - by0) * nbx + ((q[i].px >> 2) - bx0)]++] = i;
        free(start);
        return 0;
    }
    for (int i = 0; i < nq; i++) order[i] = i;
    qsort_r(order, (size_t)nq, sizeof *order, cmp_by_block, (void *)q);
    return 0;
}

int ms_block_group_end(const ms_render_ctx *ctx, const ms_shadow_query *q, const int *order, int nq, int g)
{
    const uint64_t key = block_key(&q[order[g]]);
    int e = g + 1;
    while (e < nq && e - g < MS_BLOCK_LANES && (ctx->queries_in_order || block_key(&q[order[e]]) == key)) e++;
    return e;
}
