/* Reading PNG images (light emission textures). */
#ifndef MS_PNG_READ_H
#define MS_PNG_READ_H
#include <stddef.h>

/* Decodes a PNG held in memory into linear RGB floats (3 per texel, row 0 first): libpng's simplified API
 * converts from the file's encoding (sRGB unless it says otherwise) to linear; alpha is dropped. At most
 * max_side texels per side. `name` names the file in the one-line error. 0, or -1. */
int ms_png_decode_linear(const char *name, const void *bytes, size_t len, int max_side, float **rgb, int *w, int *h,
                         char *err, size_t errlen);

#endif
