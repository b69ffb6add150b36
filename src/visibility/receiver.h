/* What one receiver point sees of the light, the same for every shadow method (docs/design.md,
 * "Visibility, precisely"):
 *   - its front mask: the light samples strictly in front of its plane, (L_i - P) . n > 0, and on the
 *     light's shape (a disk: (2s-1)^2 + (2t-1)^2 < 1 in the parallelogram's parameters); samples behind
 *     or off the shape are neither visible nor occluded;
 *   - from a method's visible mask (the front samples no triangle occludes), V = visible / front (0 when
 *     no sample is in front) and the shadow factor S = sum_vis w_i / sum_front w_i with the form-factor
 *     weight w_i = max(cos theta_r, 0) max(cos theta_l, 0) / r_i^2, times the sample's texel luminance for a
 *     textured light (S = V when every weight is 0: the
 *     light is behind the point or edge-on, and E_unshadowed is 0 there anyway).
 *
 * Masks: ctx->mask_words 64-bit words per point; bit s of the little-endian bit stream is sample s = j*k + i,
 * which is bit i of scanline j in the micro-rasterizer's k x k buffers (raster.h), so a buffer is a mask.
 * With the interleaved pattern bit s is the pixel's s-th sample of ctx->samples = N/16; bits past
 * ctx->samples are 0. */
#ifndef MS_RECEIVER_H
#define MS_RECEIVER_H
#include <stdint.h>
#include "visibility/context.h"
#include "light/pattern.h"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "sample masks alias the k x k scanline buffers as a little-endian bit stream"
#endif

static inline int ms_mask_get(const uint64_t *m, int s) { return (int)(m[s >> 6] >> (s & 63) & 1u); }

/* The receiver's horizon as an edge in the grid's sample coordinates: h . (i, j, 1) = (S_ij - P) . n. */
void ms_horizon_edge(const ms_grid *g, const float p[3], const float n[3], float h[3]);

/* Writes q's front mask: the samples in front of q's plane and on the light's shape (a disk masks off the
 * samples of its bounding square outside it, ms_shape_mask_apply). pts: the pattern's sample points (3*ctx->samples floats) for the other patterns, NULL
 * for grid, where the horizon is rasterized by the Scanline row loop (ms_raster_clear_halfplane).
 * Returns the number of samples in front. */
int ms_front_mask(const ms_render_ctx *ctx, const ms_shadow_query *q, const float *pts, uint64_t *front);

/* The shear axis of the watertight test (accel/ray_triangle.h) for the n segments from p to samples first ..
 * first + n - 1 (pts: their points, 3 floats each), as raytrace, mft and hpc choose it: the axis its
 * 16-sample packet shares (ms_wt_packet_axis over samples 16j .. 16j + 15, the directions pts - p in float,
 * pref the light's ms_light_shear_axis), else the segment's own largest. Sets bit s of axes + a * mw when segment s is sheared along axis a (mw words
 * each; other bits untouched). For the sets exact per axis (visibility/occluders.h, for_axis). first and n:
 * multiples of 16. */
void ms_segment_axes(const float p[3], const float *pts, int first, int n, int pref, int mw, uint64_t *axes);

/* V and S from the front and visible masks (pts as above). Returns 1 when the weights had to be evaluated
 * (penumbra: some but not all front samples visible), 0 when S follows from the counts. */
int ms_resolve_vs(const ms_render_ctx *ctx, const ms_shadow_query *q, const float *pts, const uint64_t *front,
                   const uint64_t *vis, float *v, float *s);

/* A textured light (ctx->light.texture): the form-factor-weighted mean texel colour over q's front samples,
 * which times the untextured E_unshadowed approximates the textured light's unshadowed irradiance (a ratio
 * estimator, exact for a uniform texture). White for an untextured light. */
void ms_light_texture_mean(const ms_render_ctx *ctx, const ms_shadow_query *q, float rgb[3]);

/* The grid's weight sums over the front (wf) and visible (wv) samples, per ISA (receiver_weights_impl.h). */
void ms_grid_weights_scalar(const ms_grid *g, const float rel0[3], const float h[3], int k, const uint64_t *front,
                            const uint64_t *vis, float *wf, float *wv);
void ms_grid_weights_avx2(const ms_grid *g, const float rel0[3], const float h[3], int k, const uint64_t *front,
                          const uint64_t *vis, float *wf, float *wv);
void ms_grid_weights_avx512(const ms_grid *g, const float rel0[3], const float h[3], int k, const uint64_t *front,
                            const uint64_t *vis, float *wf, float *wv);

int ms_mask_count_scalar(const uint64_t *m, int n);
int ms_mask_count_avx2(const uint64_t *m, int n);
int ms_mask_count_avx512(const uint64_t *m, int n);

/* Number of set bits in n words. */
int ms_mask_count(const uint64_t *m, int n);

#endif
