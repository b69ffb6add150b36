/* The interleaved pattern's filter over rows (interleave_filter.h), one source compiled per ISA
 * (interleave_filter_scalar.c, _avx2.c, _avx512.c) with lanes16.h for the file's target; defines
 * ms_interleave_filter_rows_<isa>. Sixteen pixels of a row at a time, one per lane: every lane takes the
 * operations of the per-pixel definition (interleave_filter.c) in the same order, each a single IEEE
 * operation (no FMA, a correctly rounded square root and division), and a neighbour the definition skips
 * leaves the sums as they were (a select, not an added zero), so every instance gives that definition's
 * floats bit for bit (test_interleaved checks them against each other and an oracle). The hits, front
 * counts and values of a band of rows are first laid out by plane (position, normal, weight, V, S, S_spec),
 * two columns of padding on each side whose weight 0 stands for "outside the frame". */
#include <stdlib.h>
#include <string.h>
#include "interleave_filter.h"
#include "visibility/lanes16.h"
#include "core/perk.h"

enum { IF_PLANES = 10, IF_BAND = 16, IF_PAD = 2 };

int MS_CAT(ms_interleave_filter_rows_, MS_ISA_SUFFIX)(int W, int H, const ms_hit *hits, const uint16_t *front,
                                                      const float *v0, const float *s0, const float *sp0, int wy0,
                                                      int a, int b, float *vis, float *shadow, float *spec, int threads)
{
    /* A row's stride: the padding, then W rounded up to whole chunks, then the padding the last chunk's
     * right taps read. */
    const int chunks = (W + 15) / 16, stride = 16 * chunks + 2 * IF_PAD;
    const size_t plane = (size_t)(IF_BAND + 4) * stride;
    int failed = 0;
#pragma omp parallel num_threads(threads) reduction(| : failed)
    {
        float *buf = malloc(plane * IF_PLANES * sizeof *buf);
        failed |= !buf;
#pragma omp for schedule(static)
        for (int y0 = a; y0 < b; y0 += IF_BAND) {
            if (!buf) continue;
            const int y1 = y0 + IF_BAND < b ? y0 + IF_BAND : b;
            /* rows r0 .. r1 - 1 laid out: the band and two rows either side that the frame has */
            const int r0 = y0 - 2 > 0 ? y0 - 2 : 0, r1 = y1 + 2 < H ? y1 + 2 : H;
            float *P[IF_PLANES];
            for (int k = 0; k < IF_PLANES; k++) P[k] = buf + (size_t)k * plane;
            for (int r = r0; r < r1; r++) {
                const size_t o = (size_t)(r - r0) * stride;
                for (int k = 0; k < IF_PLANES; k++) memset(P[k] + o, 0, (size_t)stride * sizeof(float));
                for (int x = 0; x < W; x++) {
                    const size_t i = (size_t)(r - wy0) * W + x, j = o + IF_PAD + (size_t)x;
                    const ms_hit *h = &hits[i];
                    if (h->prim == UINT32_MAX || !front[i]) continue;   /* weight 0: never taken */
                    P[0][j] = h->p[0]; P[1][j] = h->p[1]; P[2][j] = h->p[2];
                    P[3][j] = h->n[0]; P[4][j] = h->n[1]; P[5][j] = h->n[2];
                    P[6][j] = (float)front[i];
                    P[7][j] = v0[i];
                    P[8][j] = s0[i];
                    P[9][j] = sp0 ? sp0[i] : 0.0f;
                }
            }
            const l16 zero = l16_set1(0.0f), tol = l16_set1(MS_FILTER_PLANE_TOL), ncos = l16_set1(MS_FILTER_NORMAL_COS);
            for (int y = y0; y < y1; y++)
                for (int ch = 0; ch < chunks; ch++) {
                    const int x0 = 16 * ch;
                    const size_t ci = (size_t)(y - r0) * stride + IF_PAD + (size_t)x0;
                    const l16 cp0 = l16_load(P[0] + ci), cp1 = l16_load(P[1] + ci), cp2 = l16_load(P[2] + ci);
                    const l16 cn0 = l16_load(P[3] + ci), cn1 = l16_load(P[4] + ci), cn2 = l16_load(P[5] + ci);
                    const unsigned centre = l16_gt(l16_load(P[6] + ci), zero);
                    l16 wsum = zero, vsum = zero, ssum = zero, spsum = zero;
                    for (int dy = -2; dy <= 2 && centre; dy++) {
                        const int yy = y + dy;
                        if (yy < 0 || yy >= H) continue;
                        const float ty = dy == -2 || dy == 2 ? 0.5f : 1.0f;
                        for (int dx = -2; dx <= 2; dx++) {
                            const size_t j = (size_t)(yy - r0) * stride + IF_PAD + (size_t)(x0 + dx);
                            const l16 hf = l16_load(P[6] + j);
                            const unsigned there = l16_gt(hf, zero);
                            if (!there) continue;
                            const l16 d0 = l16_sub(l16_load(P[0] + j), cp0), d1 = l16_sub(l16_load(P[1] + j), cp1),
                                      d2 = l16_sub(l16_load(P[2] + j), cp2);
                            const l16 off = l16_abs(l16_add(l16_add(l16_mul(d0, cn0), l16_mul(d1, cn1)), l16_mul(d2, cn2)));
                            const l16 chord = l16_sqrt(l16_add(l16_add(l16_mul(d0, d0), l16_mul(d1, d1)), l16_mul(d2, d2)));
                            const l16 cosn = l16_add(l16_add(l16_mul(l16_load(P[3] + j), cn0), l16_mul(l16_load(P[4] + j), cn1)),
                                                     l16_mul(l16_load(P[5] + j), cn2));
                            const unsigned ok = there & l16_le(off, l16_mul(tol, chord)) & l16_le(ncos, cosn);
                            if (!ok) continue;
                            const float tx = dx == -2 || dx == 2 ? 0.5f : 1.0f;
                            const l16 w = l16_mul(l16_set1(tx * ty), hf);
                            wsum = l16_select(ok, l16_add(wsum, w), wsum);
                            vsum = l16_select(ok, l16_add(vsum, l16_mul(w, l16_load(P[7] + j))), vsum);
                            ssum = l16_select(ok, l16_add(ssum, l16_mul(w, l16_load(P[8] + j))), ssum);
                            if (sp0) spsum = l16_select(ok, l16_add(spsum, l16_mul(w, l16_load(P[9] + j))), spsum);
                        }
                    }
                    /* The quotients where the centre has a sample in front and a neighbour counted; else the raw
                     * values (a miss stays -1, a pixel with nothing in front V = S = 0). */
                    const unsigned use = centre & l16_gt(wsum, zero);
                    const l16 den = l16_select(use, wsum, l16_set1(1.0f));
                    float qv[16], qs[16], qsp[16];
                    l16_store(qv, l16_div(vsum, den));
                    l16_store(qs, l16_div(ssum, den));
                    l16_store(qsp, l16_div(spsum, den));
                    const int n = W - x0 < 16 ? W - x0 : 16;
                    for (int l = 0; l < n; l++) {
                        const size_t i = (size_t)(y - wy0) * W + (size_t)(x0 + l), o = (size_t)(y - a) * W + (size_t)(x0 + l);
                        const int u = (int)(use >> l & 1u);
                        if (vis) vis[o] = u ? qv[l] : v0[i];
                        shadow[o] = u ? qs[l] : s0[i];
                        if (spec) spec[o] = u ? qsp[l] : sp0[i];
                    }
                }
        }
        free(buf);
    }
    return failed ? -1 : 0;
}
