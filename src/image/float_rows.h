/* The float images (PFM, EXR) row by row (vis_image.c), behind image_rows.h. */
#ifndef MS_IMAGE_FLOAT_ROWS_H
#define MS_IMAGE_FLOAT_ROWS_H
#include "image_rows.h"

typedef struct ms_float_rows ms_float_rows;
ms_float_rows *ms_float_rows_begin(ms_image_kind kind, int W, int H, int n_lights, FILE *out, const char *path,
                                   char *err, size_t errlen);
int ms_float_rows_write(ms_float_rows *r, const ms_frame *band, int y0, char *err, size_t errlen);
int ms_float_rows_end(ms_float_rows *r, int ok, char *err, size_t errlen);

#endif
