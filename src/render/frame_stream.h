/* A frame whose outputs are written as its rows finish (frame_stream.c, #24 item 2): the tile-by-tile frame
 * (frame_job.c) with planes for one band of tile rows at a time instead of the whole frame. */
#ifndef MS_RENDER_FRAME_STREAM_H
#define MS_RENDER_FRAME_STREAM_H
#include "microshadow.h"

/* ms_frame_job_create with stream (ms_stream_mode): MS_STREAM_OFF a whole frame, MS_STREAM_ON bands, MS_STREAM_AUTO
 * bands when only they fit the memory budget. *band_rows: the band's rows (a multiple of MS_TILE_SIZE), or 0
 * for a whole frame (then render and finish it as usual). */
int ms_frame_job_create_stream(const ms_scene *scene, const ms_render_options *opt, int stream, ms_frame_job **job,
                               int *band_rows, char *err, size_t errlen);
/* The frame's size: the rendered frame's, s times the output's with anti-aliasing. */
void ms_frame_job_size(const ms_frame_job *job, int *W, int *H);
/* Anti-aliasing: *s the frame's scale (1: none) and the front counts' scale of its resolve (frame_aa.h). A
 * banded job's bands are whole output rows (a multiple of s rows of the frame). */
void ms_frame_job_aa(const ms_frame_job *job, int *s, int *front_scale);
/* A banded job: renders rows y0 .. y0 + rows (the rows after those rendered before; y0 a multiple of
 * MS_TILE_SIZE, rows at most the band's and a multiple of MS_TILE_SIZE unless the frame ends there) for every
 * light. 0, or -1 / MS_ERR_CANCELLED with a message. */
int ms_frame_job_band_render(ms_frame_job *job, int y0, int rows, char *err, size_t errlen);
/* The next finished band, in order: 1 with *band (width W, height its rows: filtered V, S, S_spec per light,
 * shaded rgb; valid until the next call) and its first row *y0, when it is ready (with the interleaved filter
 * a band is ready once two rows of the next are rendered, or the frame ends); 0 when none is (*band left as it
 * was); -1 with a
 * message. lum (W * band rows floats, may be NULL) gets each pixel's unshadowed luminance (-INFINITY on misses)
 * for the exposure. With the last band, band->stats are the frame's. */
int ms_frame_job_band_take(ms_frame_job *job, ms_frame *band, int *y0, float *lum, char *err, size_t errlen);

#endif
