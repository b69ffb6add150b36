/* The receivers split into chunks (each with its own hierarchy, masks and umbra bits, cast by one thread at a
 * time): the top of a middle-split hierarchy, the largest split first. Compiled once (hpc_engine.h). */
#include "hpc_engine.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* hpc_make_chunks' split of idx[0..n) at split on axis, over the threads: the points below it first, both sides in
 * their order (a stable partition, so the result does not depend on the threads); tmp: n entries. Returns the
 * number below. */
static uint32_t partition_parallel(const shared *sh, uint32_t *idx, uint32_t n, int axis, float split, uint32_t *tmp,
                                   int threads)
{
    enum { MAX_T = 256 };
    uint32_t below[MAX_T + 1] = { 0 };
    const int nt = threads < MAX_T ? threads : MAX_T;
    const uint32_t per = (n + (uint32_t)nt - 1) / (uint32_t)nt;
#pragma omp parallel for schedule(static) num_threads(nt)
    for (int t = 0; t < nt; t++) {
        const uint32_t b = (uint32_t)t * per, e = b + per < n ? b + per : n;
        uint32_t c = 0;
        for (uint32_t i = b; i < e; i++) c += sh->q[idx[i]].p[axis] < split;
        below[t + 1] = c;
    }
    for (int t = 0; t < nt; t++) below[t + 1] += below[t];
    const uint32_t m = below[nt];
#pragma omp parallel for schedule(static) num_threads(nt)
    for (int t = 0; t < nt; t++) {
        const uint32_t b = (uint32_t)t * per, e = b + per < n ? b + per : n;
        uint32_t lo = below[t], hi = m + (b < n ? b : n) - below[t];
        for (uint32_t i = b; i < e; i++) {
            if (sh->q[idx[i]].p[axis] < split) tmp[lo++] = idx[i];
            else tmp[hi++] = idx[i];
        }
    }
    memcpy(idx, tmp, (size_t)n * sizeof *idx);
    return m;
}

/* bounds_of over the threads (min and max are exact, so the order does not matter). */
static void bounds_parallel(const shared *sh, const uint32_t *idx, uint32_t n, float lo[3], float hi[3], int threads)
{
    float l0 = INFINITY, l1 = INFINITY, l2 = INFINITY, h0 = -INFINITY, h1 = -INFINITY, h2 = -INFINITY;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(min : l0, l1, l2) reduction(max : h0, h1, h2)
    for (uint32_t i = 0; i < n; i++) {
        const float *p = sh->q[idx[i]].p;
        l0 = ms_minf(l0, p[0]); l1 = ms_minf(l1, p[1]); l2 = ms_minf(l2, p[2]);
        h0 = ms_maxf(h0, p[0]); h1 = ms_maxf(h1, p[1]); h2 = ms_maxf(h2, p[2]);
    }
    lo[0] = l0; lo[1] = l1; lo[2] = l2;
    hi[0] = h0; hi[1] = h1; hi[2] = h2;
}

/* Splits the receivers into at most cap chunks by middle splits, always the one with the most points next,
 * until every chunk holds at most `target` points; returns the count. Splitting the largest first keeps the
 * chunks' sizes even when the cap runs out: depth first, empty regions used up the cap and left a frame's
 * densest region as one chunk, which one thread cast alone while the others waited at the batch's end. Each
 * split's bounds and partition run over the threads (serial, they were a visible share of a big frame). */
int hpc_make_chunks(const shared *sh, uint32_t *idx, uint32_t n, uint32_t target, chunk *out, int cap, int threads)
{
    typedef struct { uint32_t b, n; } range;
    range *r = malloc((size_t)cap * sizeof *r);
    uint32_t *tmp = malloc((size_t)n * sizeof *tmp);
    if (!r || !tmp) { free(r); free(tmp); return -1; }
    int nc = 1;
    r[0] = (range){ 0, n };
    while (nc < cap) {
        int big = 0;
        for (int i = 1; i < nc; i++)
            if (r[i].n > r[big].n) big = i;
        if (r[big].n <= target) break;
        const range x = r[big];
        float lo[3], hi[3];
        bounds_parallel(sh, idx + x.b, x.n, lo, hi, threads);
        const float ext[3] = { hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] };
        const int axis = ext[0] >= ext[1] ? (ext[0] >= ext[2] ? 0 : 2) : (ext[1] >= ext[2] ? 1 : 2);
        uint32_t m = partition_parallel(sh, idx + x.b, x.n, axis, lo[axis] + 0.5f * ext[axis], tmp, threads);
        if (m == 0 || m == x.n) m = x.n / 2;   /* coincident points: any split */
        /* The halves stay next to each other in the list (spatial order, which the renumbering keeps). */
        memmove(r + big + 2, r + big + 1, (size_t)(nc - big - 1) * sizeof *r);
        r[big] = (range){ x.b, m };
        r[big + 1] = (range){ x.b + m, x.n - m };
        nc++;
    }
    for (int i = 0; i < nc; i++) {
        out[i].idx = idx + r[i].b;
        out[i].n = r[i].n;
    }
    free(r);
    free(tmp);
    return nc;
}
