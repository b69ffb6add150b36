/* The image writers row by row (image_rows.h): which format an output is, and one interface over them. */
#include "image_rows.h"
#include "float_rows.h"
#include "png_rows.h"
#include <stdlib.h>

ms_image_kind ms_image_kind_of(ms_output_write_fn write)
{
    if (write == ms_png_write_stream) return MS_IMAGE_PNG;
    if (write == ms_exr_write_stream) return MS_IMAGE_EXR_RGB;
    if (write == ms_vis_write_stream) return MS_IMAGE_VIS;
    if (write == ms_shadow_write_stream) return MS_IMAGE_SHADOW;
    if (write == ms_stats_write_stream) return MS_IMAGE_STATS;
    return MS_IMAGE_OTHER;
}

struct ms_image_rows {
    ms_png_rows *png;
    ms_float_rows *fl;
    const char *path;
};

ms_image_rows *ms_image_rows_begin(ms_image_kind kind, int W, int H, int n_lights, FILE *out, const char *path,
                                   char *err, size_t errlen)
{
    if (kind == MS_IMAGE_OTHER || kind == MS_IMAGE_STATS) {
        snprintf(err, errlen, "%s: this output is not an image written row by row", path);
        return NULL;
    }
    ms_image_rows *r = calloc(1, sizeof *r);
    if (!r) { snprintf(err, errlen, "%s: out of memory", path); return NULL; }
    r->path = path;
    if (kind == MS_IMAGE_PNG) r->png = ms_png_rows_begin(W, H, out, path, err, errlen);
    else r->fl = ms_float_rows_begin(kind, W, H, n_lights, out, path, err, errlen);
    if (!r->png && !r->fl) { free(r); return NULL; }
    return r;
}

int ms_image_rows_write(ms_image_rows *r, const ms_frame *band, int y0, char *err, size_t errlen)
{
    return r->png ? ms_png_rows_write(r->png, band, r->path, err, errlen) : ms_float_rows_write(r->fl, band, y0, err, errlen);
}

int ms_image_rows_end(ms_image_rows *r, int ok, char *err, size_t errlen)
{
    const int rc = r->png ? ms_png_rows_end(r->png, ok, r->path, err, errlen) : ms_float_rows_end(r->fl, ok, err, errlen);
    free(r);
    return rc;
}
