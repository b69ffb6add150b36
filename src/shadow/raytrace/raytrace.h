/* The per-sample reference tracer's packet code, one instance per ISA (raytrace_impl.h), and its choice. */
#ifndef MS_RAYTRACE_H
#define MS_RAYTRACE_H
#include "shadow/method.h"
#include "core/cpu.h"

enum { C_PACKETS, C_NODE_VISITS, C_TRI_TESTS };

/* Writes to vis the front samples of q that are unoccluded and returns their number (see
 * ms_raytrace_visible_samples below). */
typedef int (*ms_raytrace_fn)(const ms_render_ctx *ctx, const ms_shadow_query *q, float *pts, const uint64_t *front,
                              uint64_t *vis, uint64_t *cnt);
int ms_raytrace_samples_scalar(const ms_render_ctx *, const ms_shadow_query *, float *, const uint64_t *, uint64_t *, uint64_t *);
int ms_raytrace_samples_avx2(const ms_render_ctx *, const ms_shadow_query *, float *, const uint64_t *, uint64_t *, uint64_t *);
int ms_raytrace_samples_avx512(const ms_render_ctx *, const ms_shadow_query *, float *, const uint64_t *, uint64_t *, uint64_t *);

/* The instance for the capped ISA (every level has one). */
ms_raytrace_fn ms_raytrace_select(ms_isa cap, ms_isa *chosen);

/* The reference answer for one point (raytrace.c; microraster falls back to it): writes to vis the front samples that are unoccluded and
 * returns their number. pts: scratch for 3*k*k floats; cnt: the raytrace method's 3 counters. */
int ms_raytrace_visible_samples(const ms_render_ctx *ctx, const ms_shadow_query *q, float *pts,
                                const uint64_t *front, uint64_t *vis, uint64_t *cnt);

#endif
