/* Reading OpenEXR images (light emission textures). */
#ifndef MS_EXR_READ_H
#define MS_EXR_READ_H
#include <stddef.h>

/* 1 when bytes begin with the OpenEXR magic number. */
int ms_is_exr(const void *bytes, size_t len);

/* Decodes a one-part scanline EXR held in memory into linear RGB floats (3 per texel, row 0 = the data
 * window's first row, as a PNG's first row): channels R, G, B (half, float or uint), or Y alone as grey;
 * alpha and other channels are ignored. Refused with one line naming `name`: more than max_side texels a
 * side (checked from the header before any pixel memory), tiled or deep images, subsampled channels, no
 * R, G, B (or Y), a texel that is negative, NaN, infinite or above MS_MAX_LIGHT_TEXEL (microshadow.h), or data
 * OpenEXR cannot decode. 0, or -1. */
int ms_exr_decode_linear(const char *name, const void *bytes, size_t len, int max_side, float **rgb, int *w, int *h,
                         char *err, size_t errlen);

#endif
