/* Pixel anti-aliasing's resolve (ms_render_options.aa): a frame rendered s times larger in each direction
 * becomes the output frame, each pixel the box-filtered average of its s x s primary samples. */
#ifndef MS_FRAME_AA_H
#define MS_FRAME_AA_H
#include "microshadow.h"

/* Replaces f's planes (rgb; every light's vis, shadow, shadow_spec, front) by their s x s box averages and
 * divides f's width and height by s. rgb averages all s*s samples (a miss is black); V, S and S_spec average
 * the samples that hit (-1 where none did); front is the pixel's samples in front: the hits' mean times
 * front_scale (1 when every hit has the pixel's N samples, s*s when they split them). 0, or -1 out of memory
 * (f unchanged). */
int ms_frame_aa_resolve(ms_frame *f, int s, int front_scale);
/* The same into out's planes (allocated by the caller for f's width / s by height / s, light by light), for a
 * streamed band (frame_stream.c); f's shadow_spec or front may be NULL (then out's are not written). Sets out's
 * size, lights, exposure and stats from f. */
void ms_frame_aa_resolve_into(const ms_frame *f, int s, int front_scale, ms_frame *out);
#endif
