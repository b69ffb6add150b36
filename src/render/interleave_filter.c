/* The discontinuity-aware filter of the interleaved pattern (interleave_filter.h). Benthin & Wald 2009,
 * sec. 4.5: "a simple irradiance filtering pass over the image, filtering the illumination in a 4x4
 * neighbourhood around every pixel", with each pixel's normal and depth; sec. 5.4: with 16 rays per pixel
 * it comes close to 256 rays per pixel.
 *
 * The window. Any 4x4 block of pixels holds each of the 16 sample sets once (set = (x & 3) + 4 (y & 3)).
 * A 4x4 window cannot be centred on a pixel; offsets -2..+1 would move every shadow edge by half a pixel.
 * Departure: we centre it, offsets -2..+2 with the weights 1/2, 1, 1, 1, 1/2 along each axis. The two
 * outer taps of a row hold the same set, so every set still weighs exactly 1 along each axis, as in the
 * paper's 4x4 box (same effective sample count), without the shift.
 *
 * The weights. A neighbour counts only if its primary ray hit the scene and it lies on the pixel's
 * surface: its hit point within MS_FILTER_PLANE_TOL of the pixel's camera distance from the pixel's
 * tangent plane (the depth test, made slope-aware: a plain relative depth difference rejects the
 * neighbours on a plane seen at a grazing angle, whose depth changes by several percent per pixel at
 * 256x256, while a step onto another surface 1% of the distance away is rejected), and its normal within
 * about 25 degrees of the pixel's (MS_FILTER_NORMAL_COS: the facets of a tessellated curved surface
 * differ by a few degrees, a crease or a box on the floor by 90). Each neighbour is weighted by its
 * number of samples in front of its plane, so V becomes (sum of visible) / (sum of front samples) over
 * the window: the ratio estimator over the union of the sets, as if the pixel had traced them all; a
 * pixel with no sample in front adds nothing. S is averaged with the same weights. */
#include "interleave_filter.h"
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static float tap(int d) { return d == -2 || d == 2 ? 0.5f : 1.0f; }

int ms_interleave_filter(int W, int H, const ms_hit *hits, const float eye[3], const uint16_t *front, float *vis,
                         float *shadow, int threads)
{
    const size_t npix = (size_t)W * H;
    float *v0 = malloc(npix * sizeof *v0), *s0 = malloc(npix * sizeof *s0);
    if (!v0 || !s0) { free(v0); free(s0); return -1; }
    memcpy(v0, vis, npix * sizeof *v0);
    memcpy(s0, shadow, npix * sizeof *s0);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const size_t i = (size_t)y * W + x;
            const ms_hit *c = &hits[i];
            if (c->prim == UINT32_MAX) continue;
            float e[3];
            for (int a = 0; a < 3; a++) e[a] = c->p[a] - eye[a];
            const float tol = MS_FILTER_PLANE_TOL * sqrtf(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            float wsum = 0.0f, vsum = 0.0f, ssum = 0.0f;
            for (int dy = -2; dy <= 2; dy++) {
                const int yy = y + dy;
                if (yy < 0 || yy >= H) continue;
                for (int dx = -2; dx <= 2; dx++) {
                    const int xx = x + dx;
                    if (xx < 0 || xx >= W) continue;
                    const size_t j = (size_t)yy * W + xx;
                    const ms_hit *h = &hits[j];
                    if (h->prim == UINT32_MAX || !front[j]) continue;
                    const float dist = (h->p[0] - c->p[0]) * c->n[0] + (h->p[1] - c->p[1]) * c->n[1] +
                                       (h->p[2] - c->p[2]) * c->n[2];
                    const float cosn = h->n[0] * c->n[0] + h->n[1] * c->n[1] + h->n[2] * c->n[2];
                    if (!(fabsf(dist) <= tol) || !(cosn >= MS_FILTER_NORMAL_COS)) continue;
                    const float w = tap(dx) * tap(dy) * (float)front[j];
                    wsum += w;
                    vsum += w * v0[j];
                    ssum += w * s0[j];
                }
            }
            if (wsum > 0.0f) {
                vis[i] = vsum / wsum;
                shadow[i] = ssum / wsum;
            }
        }
    free(v0);
    free(s0);
    return 0;
}
