/* Placing suns (light/light_sun.c) for the scene a frame or the points are computed on: the distance D of a
 * sun's per-receiver disk comes from the box of the scene's triangles (docs/design.md, "The sun"). */
#ifndef MS_SUN_PLACE_H
#define MS_SUN_PLACE_H
#include "microshadow.h"
#include "accel/bvh.h"

/* The box of the scene's triangles (local frame) into box[6]: bvh's root when bvh has nodes (its box is the
 * triangles' exact bounds), else the triangles themselves (a procedural scene streamed in batches). */
void ms_scene_tri_box(const ms_scene *s, const ms_bvh *bvh, float box[6]);
/* A malloc'd copy of lights[0 .. n-1] with every sun placed for the box of s's triangles (ms_scene_tri_box
 * with bvh); NULL when none is a sun (nothing to do, and no box computed: a streamed procedural scene is not
 * generated for it) or, with *oom = 1, when out of memory. */
ms_light *ms_lights_placed(const ms_light *lights, size_t n, const ms_scene *s, const ms_bvh *bvh, int *oom);

#endif
