/* The points driver inside the library (points.c). */
#ifndef MS_RENDER_POINTS_H
#define MS_RENDER_POINTS_H
#include "microshadow.h"

/* ms_visibility_points with positions already in the scene's frame (local coordinates, ms_scene.origin
 * subtracted): the bakes' texels, which never leave that frame. */
ms_status ms_visibility_points_local(const ms_accel *a, const ms_light *light, const ms_points *pts,
                                     const ms_points_options *opt, float *vis, float *shadow, uint16_t *front,
                                     ms_stats *stats, char *err, size_t errlen);

#endif
