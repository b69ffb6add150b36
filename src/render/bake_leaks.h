/* Texels whose centre falls inside geometry (bake_leaks.c). */
#ifndef MS_BAKE_LEAKS_H
#define MS_BAKE_LEAKS_H
#include "microshadow.h"

/* Moves the point of every texel that lies inside a closed object (under a box resting on the floor, in a
 * wall meeting another) out to the visible side: position (3 floats per texel, NaN off the triangles) is
 * changed in place, *moved counts the texels moved. A size x height frame, uv in its [0,1]^2. 0, or -1 with a message (out of memory). */
int ms_bake_fix_leaks(const ms_scene *sc, int size, int height, const float *uv, const uint32_t *texel_tri, float *position,
                      const float *normal, int threads, size_t *moved, char *err, size_t errlen);

#endif
