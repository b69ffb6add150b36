/* The light-shape table: one row per shape (microshadow.h's ms_light_shape), each in its own file
 * (light_rect.c, light_disk.c, light_sphere.c), over the light's precomputed frame (light_frame.h). A new
 * shape is one file with its row plus its entry in light_shape.c's table (CONTRIBUTING.md). The row names
 * its scene-file keys and builds the light from their values (keys, build): the scene layer reads the JSON
 * generically (scene_json_lights.c) and checks a light with the row's validate (scene_validate.c); this layer
 * knows no JSON.
 *
 * Every shape is a mask over the parameters (s,t) of a parallelogram, so every pattern, every method and
 * the weights stay those of the parallelogram; a shape that is not planar (the sphere) stands, for each
 * receiver, for the planar light it looks like from there (its outline). */
#ifndef MS_LIGHT_SHAPE_H
#define MS_LIGHT_SHAPE_H
#include "microshadow.h"
#include "light_frame.h"
#include <stddef.h>

/* A scene-file key of a shape's geometry. A point is moved into the scene's frame before build (the scene
 * subtracts its origin in double); a vector and a number are taken as they are. */
typedef enum ms_light_key_kind { MS_LIGHT_KEY_POINT, MS_LIGHT_KEY_VECTOR, MS_LIGHT_KEY_NUMBER } ms_light_key_kind;
typedef struct ms_light_key {
    const char *name;           /* NULL ends a row's list */
    ms_light_key_kind kind;
    int count;                  /* points and vectors: how many ([x, y, z], or [[x, y, z], ...] when more than 1) */
    int optional;               /* 1: may be left out, then `fallback` (a number) */
    double fallback;
} ms_light_key;
#define MS_LIGHT_KEYS_MAX 4
#define MS_LIGHT_KEY_VALUES 9   /* three points */
/* The values read for a row's keys, in the order of its list: v[key][0 .. 3 count - 1] (a number: v[key][0]). */
typedef struct ms_light_params { double v[MS_LIGHT_KEYS_MAX][MS_LIGHT_KEY_VALUES]; } ms_light_params;

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
    /* Points whose convex hull holds every sample the shape gives (occluders.c's ms_light_hull) into pts;
     * returns their number (at most 8). NULL: the parallelogram, or a round shape's box. */
    int (*hull)(const ms_light *l, float pts[8][3]);
    /* A planar shape's outline as a convex polygon relative to p (the LTC specular, render/ltc.c): round
     * shapes as `sides` vertices inscribed and scaled to the shape's area; returns the vertex count (at most
     * max(4, sides)). */
    int (*polygon)(const ms_light_frame *F, const float p[3], int sides, float (*q)[3]);
    /* The checks of the shape's own fields beyond the parallelogram's (a scene's lights, scene_validate.c):
     * 0, or -1 with the problem in msg; coordinates must stay within +-max_coord. NULL: none. */
    int (*validate)(const ms_light *l, float max_coord, char *msg, size_t n);
    /* The scene file's keys of the shape's geometry (besides "shape", the emission's and "texture"). */
    ms_light_key keys[MS_LIGHT_KEYS_MAX + 1];
    /* Sets l's geometry and shape from the values of `keys` (points in the scene's frame), leaving its emission
     * and texture as they are: 0, or -1 with the problem in msg, which begins with the key it concerns
     * ("radius must be in (0, 1e+18]"); coordinates and lengths must stay within +-max_coord. */
    int (*build)(ms_light *l, const ms_light_params *v, float max_coord, char *msg, size_t n);
    /* 1 when l's own fields are finite and make a light of positive area (the points API's check,
     * render/points.c). NULL: the parallelogram's corner and edges. */
    int (*finite)(const ms_light *l);
} ms_light_shape_ops;

/* corner, edge_s, edge_t from the first three keys' values (the rect's and the ellipse's build). */
void ms_light_parallelogram_from(ms_light *l, const ms_light_params *v);

/* The row of a shape; NULL for a value outside the enum (validation refuses those before they get here). */
const ms_light_shape_ops *ms_light_shape_of(ms_light_shape shape);
/* The row named `name` ("rect", "disk", "sphere"), NULL when there is none. */
const ms_light_shape_ops *ms_light_shape_named(const char *name);
/* The rows in table order, for listing names and keys: the i-th (0, 1, ...), NULL past the last. */
const ms_light_shape_ops *ms_light_shape_at(size_t i);
/* 1 when l's emission and geometry are finite and its area positive (its row's finite, or the
 * parallelogram's); 0 also for an unknown shape. */
int ms_light_finite(const ms_light *l);

/* The irradiance per unit radiance of a round cone of directions of half-angle sigma (sin^2 sigma = s2)
 * whose axis makes cos theta = ct with the receiver's normal, exact across the horizon (light_sphere.c). */
double ms_light_cone_irradiance(double ct, double s2);
/* The sun (light_sun.c): its outline seen from p (a disk at p + D_P direction, facing p), and its placement
 * for the scene whose triangles' box (local frame) is box: sets the distance D (l->radius) so that every
 * segment from the scene ends outside it. Other shapes are left as they are. */
int ms_light_sun_outline(const ms_light *l, const float p[3], ms_light *disk);
void ms_light_sun_place(ms_light *l, const float box[6]);

/* Lambert's formula over the polygon rel[0..m-1] (vertices relative to the receiver), clipped to its
 * hemisphere n . x >= 0 (irradiance.c); clip: scratch for at least m + 1 vertices. */
double ms_light_polygon_irradiance(const float (*rel)[3], int m, const float n[3], float (*clip)[3]);

#endif
