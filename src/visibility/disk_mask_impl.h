/* The grid's disk mask (disk_mask.h), included once per ISA file (lanes16.h for its target); defines
 * ms_grid_disk_mask_<isa>. Sample (i, j) has s = (i + (k-1-j+u)/k)/k, t = (j + (i+v)/k)/k (ms_pattern_st) and
 * is on the disk when (2s-1)^2 + (2t-1)^2 < 1 (light_disk.c): here the same IEEE operations in the same order,
 * one per lane (lanes16.h: no FMA), 16 samples of a row at a time, so every instance gives that test's answer
 * for every sample (tests/test_lights.c checks each instance against it and against ms_shape_mask_apply).
 * It replaced a search of each row's interval (a quadratic's roots in double, then the per-sample test at the
 * ends), whose dependent chain of a square root and divisions per row cost 1.3 us a receiver at k = 32. */
#include "disk_mask.h"
#include "lanes16.h"
#include "core/perk.h"

void MS_CAT(ms_grid_disk_mask_, MS_ISA_SUFFIX)(int k, float u, float v, uint64_t *mask)
{
    static const float lane[16] = { 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15 };
    /* k is a power of two (16, 32, 64): multiplying by 1/k is exactly dividing by k, as ms_pattern_st does */
    const float ik = 1.0f / (float)k;
    const l16 vik = l16_set1(ik), one = l16_set1(1.0f), two = l16_set1(2.0f);
    /* Per column chunk, once: i (exactly: integers below 2^24) and (i + v)/k, which t takes in every row. */
    l16 fi[4], tv[4];
    for (int c = 0; c < k / 16; c++) {
        fi[c] = l16_add(l16_set1((float)(16 * c)), l16_load(lane));
        tv[c] = l16_mul(l16_add(fi[c], l16_set1(v)), vik);
    }
    const uint64_t rowbits = k == 64 ? ~UINT64_C(0) : ((UINT64_C(1) << k) - 1);
    for (int j = 0; j < k; j++) {
        const l16 a = l16_set1(((float)(k - 1 - j) + u) * ik), fj = l16_set1((float)j);
        uint64_t row = 0;
        for (int c = 0; c < k / 16; c++) {
            const l16 s = l16_mul(l16_add(fi[c], a), vik), t = l16_mul(l16_add(fj, tv[c]), vik);
            const l16 x = l16_sub(l16_mul(two, s), one), y = l16_sub(l16_mul(two, t), one);
            row |= (uint64_t)l16_lt(l16_add(l16_mul(x, x), l16_mul(y, y)), one) << (16 * c);
        }
        const int n0 = j * k;
        mask[n0 >> 6] &= ~(rowbits << (n0 & 63)) | (row << (n0 & 63));
    }
}
