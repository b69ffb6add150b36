/* The lightmap's chart seams, measured (bake_seams.c). */
#ifndef MS_BAKE_SEAMS_H
#define MS_BAKE_SEAMS_H
#include "microshadow.h"

/* Over every edge exactly two baked triangles share in space (the same two endpoints, bit for bit) but not in UVs,
 * where the surface is smooth (their planes within 8 degrees: across a crease the sides differ by right):
 * the irradiance's largest channel sampled bilinearly on either side at 8 points of the edge, the absolute
 * difference relative to the lightmap's largest value; its mean and max and the number of points (0, 0, 0
 * when there is no seam). 0, or -1 when out of memory. */
int ms_bake_seams(const ms_scene *sc, const ms_lightmap *lm, double *mean, double *max, size_t *points);

#endif
