/* The PNG writer row by row (png.c), behind image_rows.h. */
#ifndef MS_IMAGE_PNG_ROWS_H
#define MS_IMAGE_PNG_ROWS_H
#include "microshadow.h"
#include <stdio.h>

typedef struct ms_png_rows ms_png_rows;
ms_png_rows *ms_png_rows_begin(int W, int H, FILE *out, const char *path, char *err, size_t errlen);
/* band: rgb, vis (light 0's plane: a miss is < 0) and exposure of the next band->height rows. */
int ms_png_rows_write(ms_png_rows *p, const ms_frame *band, const char *path, char *err, size_t errlen);
int ms_png_rows_end(ms_png_rows *p, int ok, const char *path, char *err, size_t errlen);

#endif
