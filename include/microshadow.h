/*
 * microshadow — physically based soft shadows from parallelogram area lights, on the CPU.
 *
 * One entry point does a whole frame:
 *
 *     ms_scene scene;
 *     char err[512];
 *     if (ms_scene_load("scene.json", &scene, err, sizeof err) != 0) { puts(err); return 2; }
 *     ms_render_options opt;
 *     ms_render_options_default(&opt);          // method "scanline", grid pattern, all cores
 *     ms_frame frame;
 *     if (ms_render(&scene, &opt, &frame, err, sizeof err) != 0) { ... }
 *     ms_write_png(&frame, "out.png", err, sizeof err);
 *     ms_frame_free(&frame); ms_scene_free(&scene);
 *
 * Visibility V(pixel) is the fraction of the light's samples L(s_i,t_i) whose segment from the primary
 * hit point is unblocked by any triangle (two-sided, purely geometric; the hit triangle never occludes).
 * Every shadow method computes V on the same samples, so methods can be compared sample for sample.
 * Pixels whose primary ray misses the scene get V = -1.
 *
 * Errors: functions that can fail return 0 on success and non-zero on failure, writing one line of
 * text (naming the file where there is one) into the caller's buffer err[errlen].
 */
#ifndef MICROSHADOW_H
#define MICROSHADOW_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define MS_VERSION_STRING "0.1.0"

typedef struct ms_vec3 { float x, y, z; } ms_vec3;

/* Pinhole camera. Pixel (x,y), y = 0 the top row; the primary ray passes through (x+0.5, y+0.5).
 * right = normalize(cross(forward, up)), true up = cross(right, forward). fov_y in degrees. */
typedef struct ms_camera {
    ms_vec3 eye, target, up;
    float fov_y;
    int width, height;
} ms_camera;

/* Parallelogram light L(s,t) = corner + s*edge_s + t*edge_t, s,t in [0,1]. It emits radiance
 * `emission` (linear RGB) from the side cross(edge_s, edge_t) points to. */
typedef struct ms_light {
    ms_vec3 corner, edge_s, edge_t;
    ms_vec3 emission;
} ms_light;

/* A triangle soup: tri[9*i .. 9*i+8] are the three vertices of triangle i. */
typedef struct ms_scene {
    float *tri;
    size_t n_tris;
    ms_camera camera;
    ms_light light;
    int samples;         /* light samples per pixel from the scene file (render.samples) */
    double load_s;       /* seconds spent loading meshes */
} ms_scene;

/* Warnings (an unknown key in a scene file) go to this handler, one line each without a newline; by
 * default they are printed to stderr as "microshadow: warning: ...". NULL restores the default. */
typedef void (*ms_warning_fn)(void *user, const char *message);
void ms_set_warning_handler(ms_warning_fn fn, void *user);

/* Loads a JSON scene file (meshes: OBJ, PLY, OFF, STL through assimp, glTF 2.0 through cgltf; paths
 * relative to the JSON file). Regular files only, at most 16 MiB of JSON; duplicate keys are errors,
 * unknown keys warnings. */
int ms_scene_load(const char *json_path, ms_scene *out, char *err, size_t errlen);
/* The built-in procedural scene: a ground, occluders of several sizes, a light. */
int ms_scene_default(ms_scene *out);
/* Checks camera, light and geometry for NaN/inf and degenerate cases. `what` names the source. */
int ms_scene_validate(const ms_scene *s, const char *what, char *err, size_t errlen);
void ms_scene_free(ms_scene *s);

typedef enum ms_pattern {
    MS_PATTERN_GRID = 0,       /* k x k lattice, slightly rotated and shifted per pixel (Woop, sec. 6) */
    MS_PATTERN_STRATIFIED = 1  /* k x k jittered strata, jitter hashed from pixel, sample and seed */
} ms_pattern;

typedef void (*ms_progress_fn)(void *user, double fraction_done);

typedef struct ms_render_options {
    const char *method;     /* shadow method by name: see ms_method_names() */
    ms_pattern pattern;
    int samples;            /* 256, 1024 or 4096 (k*k with k = 16, 32, 64) */
    int width, height;      /* 0: the scene camera's */
    int threads;            /* 0: all cores */
    uint32_t seed;
    ms_progress_fn progress;/* may be NULL; called from one thread */
    void *progress_user;
} ms_render_options;

void ms_render_options_default(ms_render_options *o);

/* Names of the shadow methods compiled in, NULL-terminated. */
const char *const *ms_method_names(void);
/* 1 if `name` is a known method compiled into this build, 0 if unknown, -1 if known but not compiled in. */
int ms_method_available(const char *name);

#define MS_MAX_COUNTERS 16

typedef struct ms_stats {
    size_t triangles;
    /* Seconds: scene loading, our BVH build, the methods' own set-up (e.g. Embree's scene build), primary
     * visibility, shadows, and all of it (total_s). */
    double load_s, build_s, setup_s, primary_s, shadow_s, total_s;
    int samples, threads, width, height;
    const char *method;
    const char *pattern;
    uint64_t visible_pixels;
    uint64_t shadow_rays;          /* visible pixels x samples: the work every method answers */
    int n_counters;                /* method-specific counters */
    const char *counter_name[MS_MAX_COUNTERS];
    uint64_t counter[MS_MAX_COUNTERS];
} ms_stats;

typedef struct ms_frame {
    int width, height;
    float *vis;       /* width*height, row 0 at the top; -1 where the primary ray missed */
    float *rgb;       /* 3*width*height linear radiance: albedo/pi * E_unshadowed * V */
    float exposure;   /* scale that maps the 99th percentile of unshadowed radiance to 1 (for PNG) */
    ms_stats stats;
} ms_frame;

int ms_render(const ms_scene *scene, const ms_render_options *opt, ms_frame *out,
              char *err, size_t errlen);
void ms_frame_free(ms_frame *f);

/* Outputs. Each is written to a temporary file beside the target and renamed at the end. */
int ms_write_png(const ms_frame *f, const char *path, char *err, size_t errlen);      /* tone-mapped sRGB */
int ms_write_vis(const ms_frame *f, const char *path, char *err, size_t errlen);      /* .pfm or .exr, float V */
int ms_write_stats_json(const ms_frame *f, const char *path, char *err, size_t errlen);

/* Exact unshadowed irradiance at point p with unit normal n from the light (polygon form factor,
 * light clipped to the receiver's hemisphere), per unit emitted radiance. */
float ms_light_irradiance(const ms_light *l, const float p[3], const float n[3]);

#ifdef __cplusplus
}
#endif
#endif
