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
 * step 1% of the camera distance high is another surface whose shadow differs. Measured against 4096-sample
 * frames, the slope test at 0.01 gave the least error of the depth tests tried (figures:
 * docs/notebook/2026-11-29-source-comment-figures.md). Normals: within about 25 degrees
 * (MS_FILTER_NORMAL_COS = 0.9; the facets of a tessellated curved surface differ by a few degrees, a crease
 * or a box on a floor by 90; 0.97 changed nothing measurable). Each neighbour is weighted by its number of
 * samples in front of its plane, so V becomes (sum of visible) / (sum of front samples) over the window: the
 * ratio estimator over the union of the sets, as if the pixel had traced them all; a neighbour with no sample
 * in front adds nothing, and a pixel with none keeps V = S = 0 (its light is behind its plane; on curved
 * surfaces its neighbours within the normal tolerance may see it, which costs measurable error on Sponza). S
 * is averaged with the same weights.
 *
 * The per-pixel definition, in the order every instance follows (interleave_filter_impl.h: 16 pixels of a
 * row in vector lanes, the same operations per lane): for each neighbour (dy, then dx, -2..2) in the frame
 * with a hit and a sample in front: d = p_j - p_i; off = |d . n_i|; chord = sqrt(d . d); cos = n_j . n_i
 * (each dot product summed x, y, z in order); skipped unless off <= 0.01 chord and cos >= 0.9; else
 * w = (tap(dx) tap(dy)) front_j, and wsum, vsum, ssum (and the S_spec sum) += w, w V_j, w S_j. A pixel
 * with a hit, a sample in front and wsum > 0 takes vsum / wsum, ssum / wsum; every other keeps its raw
 * values.
 *
 * What it cannot do: a hard shadow edge on one surface (contact shadows) is blurred over the window like a
 * penumbra; on scenes full of them the filtered error exceeds the raw one at low resolution
 * (docs/design.md, docs/scenes.md). */
#include "interleave_filter.h"
#include "core/cpu.h"
#include <stdlib.h>
#include <string.h>

int ms_interleave_filter(int W, int H, const ms_hit *hits, const uint16_t *front, float *vis, float *shadow,
                         float *spec, int threads)
{
    const size_t npix = (size_t)W * H;
    float *v0 = malloc(npix * sizeof *v0), *s0 = malloc(npix * sizeof *s0);
    float *sp0 = spec ? malloc(npix * sizeof *sp0) : NULL;
    int rc = -1;
    if (v0 && s0 && (sp0 || !spec)) {
        memcpy(v0, vis, npix * sizeof *v0);
        memcpy(s0, shadow, npix * sizeof *s0);
        if (spec) memcpy(sp0, spec, npix * sizeof *sp0);
        rc = ms_interleave_filter_rows(W, H, hits, front, v0, s0, sp0, 0, H, 0, H, vis, shadow, spec, threads);
    }
    free(v0);
    free(s0);
    free(sp0);
    return rc;
}

typedef int (*filter_rows_fn)(int W, int H, const ms_hit *hits, const uint16_t *front, const float *v0, const float *s0,
                              const float *sp0, int wy0, int a, int b, float *vis, float *shadow, float *spec, int threads);

int ms_interleave_filter_rows_isa(ms_isa isa, int W, int H, const ms_hit *hits, const uint16_t *front, const float *v0,
                                  const float *s0, const float *sp0, int wy0, int wrows, int a, int b, float *vis,
                                  float *shadow, float *spec, int threads)
{
    (void)wrows;   /* the caller's promise: rows a - 2 .. b + 1 of the frame are in the window */
    static const filter_rows_fn by_isa[] = {
        [MS_ISA_SCALAR] = ms_interleave_filter_rows_scalar,
        [MS_ISA_AVX2] = ms_interleave_filter_rows_avx2,
        [MS_ISA_AVX512] = ms_interleave_filter_rows_avx512,
    };
    return by_isa[isa](W, H, hits, front, v0, s0, sp0, wy0, a, b, vis, shadow, spec, threads);
}

int ms_interleave_filter_rows(int W, int H, const ms_hit *hits, const uint16_t *front, const float *v0, const float *s0,
                              const float *sp0, int wy0, int wrows, int a, int b, float *vis, float *shadow, float *spec,
                              int threads)
{
    /* Every instance gives the same floats (interleave_filter_impl.h), so no cap applies: the best the CPU
     * runs, as ms_mask_count. */
    return ms_interleave_filter_rows_isa(ms_isa_select(MS_ISA_AUTO, MS_ISA_ALL), W, H, hits, front, v0, s0, sp0, wy0,
                                         wrows, a, b, vis, shadow, spec, threads);
}
