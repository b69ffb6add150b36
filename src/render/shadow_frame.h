/* The shadow phase of a frame for a method with a frame-level entry (method.h, visibility_all). */
#ifndef MS_SHADOW_FRAME_H
#define MS_SHADOW_FRAME_H
#include <stdint.h>
#include "microshadow.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "shade.h"
#include "exact_split.h"

/* Moves the queries i with last[i] set after the others, with their pixels (where) and front masks (mw words
 * each), keeping the others' order; returns how many come first. (The receivers on merged faces that go to the
 * scene's own triangles: here and in frame_job.c's tiles.) */
size_t ms_queries_move_last(ms_shadow_query *q, size_t *where, uint64_t *front, size_t mw, size_t n, const uint8_t *last);

/* Gathers every visible pixel of hits (W x H) as a query with its front mask, calls the method once, and
 * resolves V and S with ms_resolve_vs exactly as the tiled path does (and S_spec where surf, per pixel or
 * NULL, has a specular lobe); writes vis, shadow, spec and front (W x H each) and adds to counters and the
 * frame's totals. pixels: NULL for the whole frame in row-major order, else only those npixels pixel
 * indices, in that order (a part of the frame: frame_job.c). own_state (NULL: none): the method's state
 * over the scene's own triangles (own_ctx) when ctx's occluders merge coplanar faces (ctx->prim_merged);
 * the receivers on merged faces that the merge could answer otherwise (ms_merged_receiver_ok) are then
 * answered by a second call over it, as the tiled path does, and counted in on_merged. split: the other
 * receivers' samples by shear axis among the light's exact sets (exact_split.h; axes 0: all on sstate). 0, or -1 out of
 * memory or when the method fails. */
int ms_shadow_frame_whole(const ms_shadow_method *sm, void *sstate, const ms_render_ctx *ctx, const ms_exact_split *split, void *own_state,
                          const ms_render_ctx *own_ctx, const ms_hit *hits,
                          const ms_surface *surf, int W, int H, const size_t *pixels, size_t npixels, float *vis, float *shadow, float *spec, uint16_t *front,
                          uint64_t *counters, uint64_t *visible, uint64_t *penumbra,
                          uint64_t *segments, uint64_t *on_merged, double *resolve_thread_s);

#endif
