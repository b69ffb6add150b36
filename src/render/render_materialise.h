/* Procedural scenes for the methods that need all triangles at once. */
#ifndef MS_RENDER_MATERIALISE_H
#define MS_RENDER_MATERIALISE_H
#include <stddef.h>
#include "microshadow.h"

/* Generates every triangle of the procedural scene into soup (a copy of *scene with its own tri, not
 * procedural; free soup->tri), generation counted as loading; "out of memory" names the triangle count and
 * the methods that stream. 0 or -1. */
int ms_scene_materialise(const ms_scene *scene, int threads, ms_scene *soup, char *err, size_t errlen);

#endif
