/* The form-factor weights of the grid pattern for ms_resolve_vs (receiver.c), one source compiled per ISA:
 * receiver_weights.c (portable), receiver_weights_avx2.c, receiver_weights_avx512.c. The loops are plain
 * C over 16 independent lanes that each file's compiler vectorises; every lane does the same IEEE
 * operations in the same order (no FMA contraction) and the lanes are summed in a fixed order, so every
 * instance gives the same S. Included once per file; defines ms_grid_weights_<isa>. */
#include "receiver.h"
#include "core/perk.h"
#include "core/vec.h"

/* Adds the weights of row j's front samples to wf[] and of its visible ones to wv[] (16 lane sums). With
 * d = L - P, cos theta_r = d . n / r = (h . (i, j, 1)) / r (n is unit) and cos theta_l = b / r with
 * b = -d . n_l, so w = a b / r^4. On the grid every sample lies on the light's plane, b is the same for all
 * of them and cancels in S: the rows sum a / r^4. Written as 16 independent lanes (no reduction inside
 * the loop) so that it vectorises without reassociating float sums, and sums in the same order on every
 * ISA. */
#define WLANES 16
static inline void grid_row_weights(const ms_grid *g, const float rel0[3], const float h[3], int k, int j,
                             uint64_t fbits, uint64_t vbits, float wf[WLANES], float wv[WLANES])
{
    static const uint32_t bit[WLANES] = { 1u << 0, 1u << 1, 1u << 2, 1u << 3, 1u << 4, 1u << 5, 1u << 6, 1u << 7,
                                          1u << 8, 1u << 9, 1u << 10, 1u << 11, 1u << 12, 1u << 13, 1u << 14, 1u << 15 };
    const float fj = (float)j;
    const float bx = rel0[0] + fj * g->dt[0], by = rel0[1] + fj * g->dt[1], bz = rel0[2] + fj * g->dt[2];
    const float hb = h[2] + fj * h[1];
    for (int i0 = 0; i0 < k; i0 += WLANES) {
        const uint32_t fb = (uint32_t)(fbits >> i0) & 0xFFFFu, vb = (uint32_t)(vbits >> i0) & 0xFFFFu;
        if (!fb) continue;
        for (int l = 0; l < WLANES; l++) {
            const float fi = (float)(i0 + l);
            const float dx = bx + fi * g->ds[0], dy = by + fi * g->ds[1], dz = bz + fi * g->ds[2];
            const float r2 = dx * dx + dy * dy + dz * dz;
            const float a = ms_maxf(hb + fi * h[0], 0.0f);
            const float w = a / (r2 * r2);
            wf[l] += (fb & bit[l]) ? w : 0.0f;
            wv[l] += (vb & bit[l]) ? w : 0.0f;
        }
    }
}

static inline uint64_t mask_row(const uint64_t *m, int k, int j)
{
    const int bit = j * k;
    const uint64_t w = m[bit >> 6] >> (bit & 63);
    return k == 64 ? w : w & ((UINT64_C(1) << k) - 1);
}

/* In the ISA files the POPCNT instruction; the portable file gets the compiler's portable popcount. */
int MS_CAT(ms_mask_count_, MS_ISA_SUFFIX)(const uint64_t *m, int n)
{
    int c = 0;
    for (int i = 0; i < n; i++) c += __builtin_popcountll(m[i]);
    return c;
}

void MS_CAT(ms_grid_weights_, MS_ISA_SUFFIX)(const ms_grid *g, const float rel0[3], const float h[3], int k,
                                              const uint64_t *front, const uint64_t *vis, float *wf, float *wv)
{
    float lf[WLANES] = { 0 }, lv[WLANES] = { 0 };
    for (int j = 0; j < k; j++) {
        const uint64_t fb = mask_row(front, k, j);
        if (fb) grid_row_weights(g, rel0, h, k, j, fb, mask_row(vis, k, j), lf, lv);
    }
    float sf = 0.0f, sv = 0.0f;
    for (int l = 0; l < WLANES; l++) { sf += lf[l]; sv += lv[l]; }
    *wf = sf;
    *wv = sv;
}
