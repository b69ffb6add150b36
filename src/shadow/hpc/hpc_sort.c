/* Coarse blocker sorting (Laine & Aila 2005, sec. 3.3): large triangles first, so that large umbra regions
 * are found early and later triangles stop at umbra nodes. As the paper, by bucketing on area in linear
 * time: one pass builds a histogram, a second places the triangles; here the buckets are the binary
 * exponents of the area (the paper leaves the ranges open) and the "files" are ranges of one index array. */
#include "hpc.h"
#include <math.h>
#include <stdlib.h>

#define BUCKETS 128

static int bucket_of(const float *t)
{
    const double e1[3] = { t[3] - t[0], t[4] - t[1], t[5] - t[2] }, e2[3] = { t[6] - t[0], t[7] - t[1], t[8] - t[2] };
    const double c[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
    const double a = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];   /* (2 area)^2: the same order */
    if (!(a > 0.0) || !isfinite(a)) return BUCKETS - 1;          /* zero-area last: they block almost nothing */
    int e;
    frexp(a, &e);
    e = 64 - e / 4;                                              /* larger area, smaller bucket */
    return e < 0 ? 0 : e > BUCKETS - 2 ? BUCKETS - 2 : e;
}

uint32_t *ms_hpc_area_order(const float *tri, size_t n)
{
    uint32_t *order = malloc((n ? n : 1) * sizeof *order);
    uint8_t *b = malloc(n ? n : 1);
    if (!order || !b) { free(order); free(b); return NULL; }
    size_t start[BUCKETS + 1] = { 0 };
    for (size_t i = 0; i < n; i++) {
        b[i] = (uint8_t)bucket_of(tri + 9 * i);
        start[b[i] + 1]++;
    }
    for (int i = 0; i < BUCKETS; i++) start[i + 1] += start[i];
    for (size_t i = 0; i < n; i++) order[start[b[i]]++] = (uint32_t)i;
    free(b);
    return order;
}
