/* microshadow/points.h, a part of <microshadow.h>: visibility at any points: the acceleration structure and the
 * points API for bakers. Programs include <microshadow.h>, which includes every part in order; a part relies on
 * the ones before it. */
#ifndef MICROSHADOW_POINTS_H
#define MICROSHADOW_POINTS_H
#ifndef MICROSHADOW_H
#error "include <microshadow.h>: it includes this part in its place"
#endif

/* ---- Visibility at any points: the library for bakers (docs/baking.md) ----
 *
 * A baker needs V and S at its own receivers (texels, vertices, probes), not at pixels. The scene's
 * acceleration structure is built once (ms_accel_build) and reused by any number of calls, from any
 * number of threads at once (the handle is read-only after the build). Each call answers V and S under
 * the definition above, with the receiver's plane given by its normal and the triangle it lies on (if
 * given) never occluding it, on the same sample patterns as frames: point i's pattern is that of
 * pixel (key[2i], key[2i+1]) of a frame with the same seed, or of pixel (i, 0) without keys, so results
 * do not depend on the order in which points are processed or on the number of threads. Internally
 * points are grouped by proximity (Morton order of their positions) so that coherent methods stay
 * coherent; results come back in the caller's order. */



typedef struct ms_accel ms_accel;
/* Builds the acceleration structure of the scene's triangles (copied: the scene may be freed after).
 * threads: 0 for all cores. MS_OK and *out, or an error with *out = NULL. */
static inline ms_status ms_accel_build(const ms_scene *scene, int threads, ms_accel **out, char *err, size_t errlen);
MS_API void ms_accel_free(ms_accel *a);
MS_API size_t ms_accel_triangles(const ms_accel *a);
/* The lights of the scene the accel was built from (its own copies, texels included: valid until
 * ms_accel_free); *n gets their number (ms_scene_lights of that scene). */
MS_API const ms_light *ms_accel_lights(const ms_accel *a, size_t *n);
/* The origin of the accel's scene's frame (ms_scene.origin) into origin[3]: world = local + origin. The lights
 * of ms_accel_lights are local; the positions given to ms_visibility_points are world coordinates. */
MS_API void ms_accel_origin(const ms_accel *a, double origin[3]);

#define MS_NO_TRIANGLE UINT32_MAX

typedef struct ms_points {
    size_t n;
    const float *position;   /* 3n floats, world coordinates (moved into the scene's frame inside: world - origin
                              * in double, exact for points near the geometry; ms_accel_origin) */
    const float *normal;     /* 3n floats: the side of each receiver (need not be unit length, not zero) */
    const uint32_t *triangle;/* n or NULL: index of the scene triangle (ms_scene.tri) each point lies on,
                              * which never occludes it, or MS_NO_TRIANGLE; NULL: none. Without it a point
                              * on a surface is still not occluded by that surface's plane (the near
                              * range), but may be by a triangle meeting it at a crease. */
    const uint32_t *key;     /* 2n or NULL: the pixel whose sample pattern point i uses (see above) */
} ms_points;

/* Every field's zero means its default (as ms_render_options). */
typedef struct ms_points_options {
    const char *method;     /* NULL: MS_DEFAULT_METHOD */
    ms_pattern pattern;
    int samples;            /* 256, 1024 or 4096; 0: MS_SAMPLES_DEFAULT */
    int threads;            /* 0: all cores */
    uint32_t seed;
    ms_isa isa;
    ms_progress_cancel_fn progress;   /* may be NULL */
    void *progress_user;
    ms_embree_mode embree_mode;
    ms_embree_filter embree_filter;
    uint64_t max_memory;    /* the memory budget in bytes (ms_memory_budget); 0: the default. Bakes: this field of
                             * ms_bake_options.points */
} ms_points_options;

/* V, S and the front count of each point (any output may be NULL; each has n entries). light: NULL for
 * the first light of the scene the accel was built from (ms_accel_lights lists them all). A sphere light
 * is sampled per point on its outline disk as in frames; a point inside the sphere gets V = S = 0. Stats (timing, counters, no image fields) into
 * stats when non-NULL. */
/* A V or S that came out NaN or infinite is MS_ERR_INVALID naming the first such point (the arrays are then
 * not to be used). */
static inline ms_status ms_visibility_points(const ms_accel *a, const ms_light *light, const ms_points *pts,
                                             const ms_points_options *opt, float *vis, float *shadow, uint16_t *front,
                                             ms_stats *stats, char *err, size_t errlen);

#endif
