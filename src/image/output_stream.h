/* Outputs written band by band (#24 item 2; output.c): the same staging as ms_outputs_write (a staging file
 * beside each target, renamed into place only when all were written, removed on failure or a signal), with
 * the images written as their rows arrive (image_rows.h) instead of from a whole frame. The PNG comes last
 * (its exposure needs the whole frame's radiance): its rows are given apart (png = 1) once it is known. */
#ifndef MS_IMAGE_OUTPUT_STREAM_H
#define MS_IMAGE_OUTPUT_STREAM_H
#include "microshadow.h"

/* 0 when every requested output has a writer that can take rows (microshadow.h's own), else -1 naming it. */
int ms_outputs_streamable(const ms_output *outs, int n, char *err, size_t errlen);

typedef struct ms_outputs_stream ms_outputs_stream;
/* Staging files for outs[0..n) (checked by ms_outputs_check) of a W x H frame with n_lights lights, their
 * headers written. 0, or -1 with a message (nothing left behind). */
int ms_outputs_stream_open(const ms_output *outs, int n, int W, int H, int n_lights, ms_outputs_stream **s, char *err,
                           size_t errlen);
/* The PNG's path, or NULL when none is requested. */
const char *ms_outputs_stream_png_path(const ms_outputs_stream *s);
/* Rows [y0, y0 + band->height) (band: image_rows.h) into every image output but the PNG (png = 0) or into the
 * PNG alone (png = 1: band's rgb, light 0's vis and exposure). 0, or -1 with a message. */
int ms_outputs_stream_rows(ms_outputs_stream *s, const ms_frame *band, int y0, int png, char *err, size_t errlen);
/* Ends every file, writes the stats output from f (its stats), renames all into place; frees s. 0, or -1 with
 * a message and nothing renamed. */
int ms_outputs_stream_commit(ms_outputs_stream *s, const ms_frame *f, char *err, size_t errlen);
/* Removes every staging file; frees s (NULL: nothing). */
void ms_outputs_stream_abort(ms_outputs_stream *s);

/* ms_frame_check_finite of a band whose first row is frame row y0 (the message names frame coordinates). */
int ms_band_check_finite(const ms_frame *band, int y0, const char *what, char *err, size_t errlen);

/* A scratch file beside path (on its filesystem, not in memory as a tmpfs /tmp would be), unlinked at once:
 * its descriptor, or -1 with a message. */
int ms_outputs_spill(const char *near, char *err, size_t errlen);

#endif
