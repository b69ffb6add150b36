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
/* The frame's size. */
void ms_frame_job_size(const ms_frame_job *job, int *W, int *H);
/* A banded job: renders rows y0 .. y0 + rows (y0 a multiple of MS_TILE_SIZE, rows at most the band's and a
 * multiple of MS_TILE_SIZE unless the frame ends there) for every light, shades them, and points *band at them
 * (width W, height rows; valid until the next call); lum (W * rows floats, may be NULL) gets each pixel's
 * unshadowed luminance (-INFINITY on misses) for the exposure. After the last band, band->stats are the
 * frame's. 0, or -1 / MS_ERR_CANCELLED with a message. */
int ms_frame_job_band(ms_frame_job *job, int y0, int rows, ms_frame *band, float *lum, char *err, size_t errlen);

#endif
