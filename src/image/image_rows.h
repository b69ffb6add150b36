/* The image writers row by row (#24 item 2): each format is begun with the frame's size, given bands of
 * rows top to bottom, and ended. The whole-frame writers (ms_png_write_stream, ms_vis_write_stream,
 * ms_shadow_write_stream, ms_exr_write_stream) are one band of every row, so a streamed frame's files
 * equal the in-memory frame's byte for byte by construction.
 *
 * A band is an ms_frame whose width is the frame's and whose height is the band's rows: its planes hold those
 * rows only (light l's plane at vis + l * width * height, as in a whole frame). */
#ifndef MS_IMAGE_ROWS_H
#define MS_IMAGE_ROWS_H
#include "microshadow.h"
#include <stdio.h>

/* What an output holds, from its writer (ms_output.write). */
typedef enum ms_image_kind {
    MS_IMAGE_OTHER = 0,   /* a caller's own writer: it needs the whole frame */
    MS_IMAGE_PNG,         /* tone-mapped rgb (needs the exposure, i.e. the whole frame's radiance first) */
    MS_IMAGE_EXR_RGB,     /* R, G, B, S and V per light */
    MS_IMAGE_VIS,         /* V (PFM: light 0; EXR: a channel per light) */
    MS_IMAGE_SHADOW,      /* S, likewise */
    MS_IMAGE_STATS        /* the stats: written at the end from the frame's stats */
} ms_image_kind;
ms_image_kind ms_image_kind_of(ms_output_write_fn write);

typedef struct ms_image_rows ms_image_rows;
/* Begins kind's file of a W x H frame with n_lights lights on out (a seekable file: PFM rows are placed at
 * their offsets, bottom row first as the format wants). NULL with a message on failure. */
ms_image_rows *ms_image_rows_begin(ms_image_kind kind, int W, int H, int n_lights, FILE *out, const char *path,
                                   char *err, size_t errlen);
/* The band's rows, which start at row y0; bands come top to bottom, each (but the last) a multiple of 16 rows
 * (an EXR ZIP block). 0, or -1 with a message. */
int ms_image_rows_write(ms_image_rows *r, const ms_frame *band, int y0, char *err, size_t errlen);
/* Ends the file (EXR: its offset table) and frees r (also after an error: then pass ok = 0). */
int ms_image_rows_end(ms_image_rows *r, int ok, char *err, size_t errlen);

#endif
