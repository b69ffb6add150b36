/* The shading of a finished frame, the last step of the tile-by-tile frame (frame_job.c). */
#ifndef MS_FRAME_SHADE_H
#define MS_FRAME_SHADE_H
#include <stddef.h>
#include "microshadow.h"
#include "visibility/context.h"
#include "primary/primary.h"
#include "shade.h"

/* Shading: f->rgb (rows y0 .. y0 + f->height of the frame: a whole frame, or a band of a streamed one) from the hits, their surfaces (surf: per pixel, or NULL for the Lambertian
 * grey everywhere) and every light's shadow and shadow_spec planes (lights[0..nlights), ctx: the frame's,
 * for the textured lights' mean texels), and f->exposure (the 99th percentile of the unshadowed radiance
 * over the visible pixels); or, given lum (f->width * f->height floats), each pixel's unshadowed luminance there
 * (-INFINITY on misses) and no exposure. 0, or -1 out of memory. */
int ms_frame_shade(const ms_scene *scene, const ms_render_ctx *ctx, const ms_light *lights, size_t nlights,
                   const ms_hit *hits, const ms_surface *surf, int threads, int y0, ms_frame *f, float *lum);

/* The exposure ms_render of the scene's camera picks by itself under `shading` (its automatic exposure:
 * 1 / the 99th percentile of the unshadowed radiance over the hit pixels, computed by ms_frame_shade), without
 * a shadow pass (render.c). */
ms_status ms_frame_auto_exposure(const ms_scene *scene, ms_shading shading, int threads, float *exposure, char *err,
                                 size_t errlen);

#endif
