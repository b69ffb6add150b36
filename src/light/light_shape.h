/* The light-shape table: one row per shape (microshadow.h's ms_light_shape), each in its own file
 * (light_rect.c, light_disk.c, light_sphere.c), over the light's precomputed frame (light_frame.h). A new
 * shape is one file with its row plus its entry in light_shape.c's table (CONTRIBUTING.md); the scene
 * file's parsing of its keys stays in src/scene (scene_json.c), which checks a light with its row's
 * validate (scene_validate.c).
 *
 * Every shape is a mask over the parameters (s,t) of a parallelogram, so every pattern, every method and
 * the weights stay those of the parallelogram; a shape that is not planar (the sphere) stands, for each
 * receiver, for the planar light it looks like from there (its outline). */
#ifndef MS_LIGHT_SHAPE_H
#define MS_LIGHT_SHAPE_H
#include "microshadow.h"
#include "light_frame.h"
#include <stddef.h>

typedef struct ms_light_shape_ops {
    ms_light_shape shape;
    const char *name;           /* the scene file's "shape" */
    int textured;               /* 1: may carry an emission texture */
    /* 1 when the parallelogram's parameters (s, t) lie on the shape; NULL: all do (no mask). */
    int (*contains)(float s, float t);
    /* The emitting area (flux to radiance, ms_light_radiance_from). */
    float (*area)(const ms_light *l, const ms_light_frame *F);
    /* The unshadowed irradiance per unit radiance at p with unit normal n (ms_light_irradiance). */
    float (*irradiance)(const ms_light *l, const ms_light_frame *F, const float p[3], const float n[3]);
    /* A shape that is not planar: the planar light standing for it as seen from p (frames, points and bakes
     * sample each receiver on it); 0, or -1 when p sees none. NULL: the light itself is planar. */
    int (*outline)(const ms_light *l, const float p[3], ms_light *planar);
    /* A planar shape's outline as a convex polygon relative to p (the LTC specular, render/ltc.c): round
     * shapes as `sides` vertices inscribed and scaled to the shape's area; returns the vertex count (at most
     * max(4, sides)). */
    int (*polygon)(const ms_light_frame *F, const float p[3], int sides, float (*q)[3]);
    /* The checks of the shape's own fields beyond the parallelogram's (a scene's lights, scene_validate.c):
     * 0, or -1 with the problem in msg; coordinates must stay within +-max_coord. NULL: none. */
    int (*validate)(const ms_light *l, float max_coord, char *msg, size_t n);
} ms_light_shape_ops;

/* The row of a shape; NULL for a value outside the enum (validation refuses those before they get here). */
const ms_light_shape_ops *ms_light_shape_of(ms_light_shape shape);
/* The row named `name` ("rect", "disk", "sphere"), NULL when there is none. */
const ms_light_shape_ops *ms_light_shape_named(const char *name);

/* Lambert's formula over the polygon rel[0..m-1] (vertices relative to the receiver), clipped to its
 * hemisphere n . x >= 0 (irradiance.c); clip: scratch for at least m + 1 vertices. */
double ms_light_polygon_irradiance(const float (*rel)[3], int m, const float n[3], float (*clip)[3]);

#endif
