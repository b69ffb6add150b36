/* Rendering a procedural scene with a method that needs all triangles at once. */
#ifndef MS_RENDER_MATERIALISE_H
#define MS_RENDER_MATERIALISE_H
#include <stddef.h>
#include "microshadow.h"

/* Generates every triangle of the procedural scene into memory and renders that soup with ms_render;
 * "out of memory" names the triangle count and the methods that stream. */
int ms_render_materialised(const ms_scene *scene, const ms_render_options *opt, ms_frame *out, char *err,
                           size_t errlen);

#endif
