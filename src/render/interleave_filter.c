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
 * surface. Depth: the paper compares depths; we ask instead that the neighbour's hit point lie within
 * MS_FILTER_PLANE_TOL (0.01, about 0.6 degrees) of the pixel's tangent plane as seen from the pixel, i.e.
 * |(p_j - p_i) . n_i| <= 0.01 |p_j - p_i|. A relative depth threshold cannot serve both ends: on a plane
 * seen at a grazing angle the depth changes by several percent per pixel at 256x256, while a ledge or
 * step 1% of the camera distance high is another surface whose shadow differs. Measured at 256x256 against
 * 4096-sample frames (MAE of V): "within 1% of the camera distance" gave dabrovic-sponza 0.0197, 0.05% of
 * it 0.0117, the slope test 0.0110 at 0.02 and about the same at 0.01, which also did best on the bunny
 * (0.0091) and crytek (0.024). Normals: within about 25 degrees (MS_FILTER_NORMAL_COS = 0.9; the facets of
 * a tessellated curved surface differ by a few degrees, a crease or a box on a floor by 90; 0.97 changed
 * nothing measurable). Each neighbour is weighted by its number of samples in front of its plane, so V
 * becomes (sum of visible) / (sum of front samples) over the window: the ratio estimator over the union of
 * the sets, as if the pixel had traced them all; a neighbour with no sample in front adds nothing, and a
 * pixel with none keeps V = S = 0 (its light is behind its plane; on curved surfaces its neighbours within
 * the normal tolerance may see it, which cost sponza 0.0045 of MAE). S is averaged with the same weights.
 *
 * What it cannot do: a hard shadow edge on one surface (contact shadows) is blurred over the window like a
 * penumbra; on scenes full of them the filtered error exceeds the raw one at low resolution
 * (docs/design.md, docs/scenes.md). */
#include "interleave_filter.h"
#include "primary/primary.h"
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static float tap(int d) { return d == -2 || d == 2 ? 0.5f : 1.0f; }

int ms_interleave_filter(int W, int H, const ms_hit *hits, const uint16_t *front, float *vis, float *shadow,
                         float *spec, int threads)
{
    const size_t npix = (size_t)W * H;
    float *v0 = malloc(npix * sizeof *v0), *s0 = malloc(npix * sizeof *s0);
    float *sp0 = spec ? malloc(npix * sizeof *sp0) : NULL;
    if (!v0 || !s0 || (spec && !sp0)) { free(v0); free(s0); free(sp0); return -1; }
    memcpy(v0, vis, npix * sizeof *v0);
    memcpy(s0, shadow, npix * sizeof *s0);
    if (spec) memcpy(sp0, spec, npix * sizeof *sp0);
    ms_interleave_filter_rows(W, H, hits, front, v0, s0, sp0, 0, H, 0, H, vis, shadow, spec, threads);
    free(v0);
    free(s0);
    free(sp0);
    return 0;
}

void ms_interleave_filter_rows(int W, int H, const ms_hit *hits, const uint16_t *front, const float *v0, const float *s0,
                               const float *sp0, int wy0, int wrows, int a, int b, float *vis, float *shadow, float *spec,
                               int threads)
{
    (void)wrows;   /* the caller's promise: rows a - 2 .. b + 1 of the frame are in the window */
    /* S_spec (sp0 -> spec) takes the same weights as V and S, in the same pass: the weights depend on the
     * hits and the front counts only, and the sums are formed in the same order as a pass of its own. */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = a; y < b; y++)
        for (int x = 0; x < W; x++) {
            const size_t i = (size_t)(y - wy0) * W + x, o = (size_t)(y - a) * W + x;
            const ms_hit *c = &hits[i];
            /* A pixel with no sample in front keeps V = S = 0: its light is behind its plane, whatever its
             * neighbours (facets of a curved surface, within the normal tolerance) see. A miss stays -1. */
            if (vis) vis[o] = v0[i];
            shadow[o] = s0[i];
            if (spec) spec[o] = sp0[i];
            if (c->prim == UINT32_MAX || !front[i]) continue;
            float wsum = 0.0f, vsum = 0.0f, ssum = 0.0f, spsum = 0.0f;
            for (int dy = -2; dy <= 2; dy++) {
                const int yy = y + dy;
                if (yy < 0 || yy >= H) continue;
                for (int dx = -2; dx <= 2; dx++) {
                    const int xx = x + dx;
                    if (xx < 0 || xx >= W) continue;
                    const size_t j = (size_t)(yy - wy0) * W + xx;
                    const ms_hit *h = &hits[j];
                    if (h->prim == UINT32_MAX || !front[j]) continue;
                    const float d[3] = { h->p[0] - c->p[0], h->p[1] - c->p[1], h->p[2] - c->p[2] };
                    const float off_plane = fabsf(d[0] * c->n[0] + d[1] * c->n[1] + d[2] * c->n[2]);
                    const float chord = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    const float cosn = h->n[0] * c->n[0] + h->n[1] * c->n[1] + h->n[2] * c->n[2];
                    if (!(off_plane <= MS_FILTER_PLANE_TOL * chord) || !(cosn >= MS_FILTER_NORMAL_COS)) continue;
                    const float w = tap(dx) * tap(dy) * (float)front[j];
                    wsum += w;
                    vsum += w * v0[j];
                    ssum += w * s0[j];
                    if (spec) spsum += w * sp0[j];
                }
            }
            if (wsum > 0.0f) {
                if (vis) vis[o] = vsum / wsum;
                shadow[o] = ssum / wsum;
                if (spec) spec[o] = spsum / wsum;
            }
        }
}
