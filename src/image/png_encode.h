/* 8-bit images encoded as PNG into memory (png_encode.c), for files that embed them (the baked glTF). */
#ifndef MS_PNG_ENCODE_H
#define MS_PNG_ENCODE_H
#include <stddef.h>
#include <stdint.h>

/* w x h pixels of `channels` (1 grey, 2 grey+alpha, 3 RGB, 4 RGBA) bytes each, row 0 first, written as they
 * are (no colour conversion) into a malloc'ed PNG *out of *len bytes. 0, or -1 with one line naming `what`. */
int ms_png_encode(const uint8_t *px, int w, int h, int channels, const char *what, unsigned char **out, size_t *len,
                  char *err, size_t errlen);

#endif
