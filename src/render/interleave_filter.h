/* The interleaved pattern's image-space filter (Benthin & Wald 2009, sec. 4.5): each pixel of a 4x4 block
 * traced a different 1/16 of the light samples; averaging V and S over a 4x4 neighbourhood gives every
 * pixel the whole set back, except across depth and normal discontinuities. */
#ifndef MS_INTERLEAVE_FILTER_H
#define MS_INTERLEAVE_FILTER_H
#include <stdint.h>
#include "shadow/method.h"
#include "primary/primary.h"
#include "core/cpu.h"

/* A neighbour is left out when its hit point lies off the pixel's tangent plane by more than this share
 * of its distance from the pixel (about 0.6 degrees) ... */
#define MS_FILTER_PLANE_TOL 0.01f
/* ... or when the cosine between the two normals is below this (about 25 degrees). */
#define MS_FILTER_NORMAL_COS 0.9f

/* Filters vis and shadow (W*H, row 0 at the top) in place, and spec (S_spec) when not NULL with the same
 * weights. hits: the frame's primary hits (misses are neither filtered nor used); front: each pixel's samples
 * in front of its plane. Returns 0, or -1 when out of memory (the values are then left raw). */
int ms_interleave_filter(int W, int H, const ms_hit *hits, const uint16_t *front, float *vis, float *shadow,
                         float *spec, int threads);

/* The same filter over rows a .. b of a W x H frame, for streamed frames (frame_job.c): hits, front and the raw
 * v0, s0 (and sp0, or NULL) hold the window of rows wy0 .. wy0 + wrows, which must include rows a - 2 .. b + 1
 * where the frame has them; the filtered rows go to vis, shadow and spec (row a first; vis and spec may be
 * NULL; S_spec is filtered with the raw V's weights, which do not depend on V). Returns 0, or -1 when out of
 * memory (a band's planes per thread; the rows are then not all written). */
int ms_interleave_filter_rows(int W, int H, const ms_hit *hits, const uint16_t *front, const float *v0, const float *s0,
                              const float *sp0, int wy0, int wrows, int a, int b, float *vis, float *shadow, float *spec,
                              int threads);
/* The same with the instance of isa, which this CPU must run (the tests compare the instances). */
int ms_interleave_filter_rows_isa(ms_isa isa, int W, int H, const ms_hit *hits, const uint16_t *front, const float *v0,
                                  const float *s0, const float *sp0, int wy0, int wrows, int a, int b, float *vis,
                                  float *shadow, float *spec, int threads);
/* The instances (interleave_filter_impl.h). */
#define MS_IF_ROWS_ARGS int W, int H, const ms_hit *hits, const uint16_t *front, const float *v0, const float *s0, \
    const float *sp0, int wy0, int a, int b, float *vis, float *shadow, float *spec, int threads
int ms_interleave_filter_rows_scalar(MS_IF_ROWS_ARGS);
int ms_interleave_filter_rows_avx2(MS_IF_ROWS_ARGS);
int ms_interleave_filter_rows_avx512(MS_IF_ROWS_ARGS);
#undef MS_IF_ROWS_ARGS

#endif
