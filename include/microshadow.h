/*
 * microshadow — physically based soft shadows from area lights (parallelograms, disks, spheres, triangles, the sun), on the CPU.
 *
 * One entry point does a whole frame:
 *
 *     ms_scene scene;
 *     char err[512];
 *     if (ms_scene_load("scene.json", &scene, err, sizeof err) != MS_OK) { puts(err); return 2; }
 *     ms_render_options opt;
 *     ms_render_options_default(&opt);          // method "scanline", grid pattern, all cores
 *     ms_frame frame;
 *     if (ms_render(&scene, &opt, &frame, err, sizeof err) != MS_OK) { ... }
 *     ms_write_png(&frame, "out.png", err, sizeof err);
 *     ms_frame_free(&frame); ms_scene_free(&scene);
 *
 * Visibility, defined once for every method (docs/design.md). For a pixel whose primary ray hits the scene
 * at P on triangle T, with n the unit geometric normal of T turned towards the camera, and the light samples
 * L_1..L_N of the pixel's pattern:
 *   - a sample counts only when it lies strictly in front of the receiver's plane, (L_i - P) . n > 0, and
 *     on the light's shape (the disk mask: (2s-1)^2 + (2t-1)^2 < 1 in the parameters of a disk's bounding
 *     square; a sphere light is sampled, per receiver, on its outline disk seen from P, with that mask);
 *     other samples are neither visible nor occluded;
 *   - a sample in front is occluded when a triangle other than T meets the segment P + u (L_i - P) at a
 *     parameter u in [1e-4, 1 - 1e-4] (two-sided, purely geometric); a triangle with an alpha-tested material
 *     (ms_material.alpha_mode) occludes only where its alpha at the point the segment meets its plane is
 *     >= the cutoff (one function of the triangle, P and L_i, computed in double: docs/design.md), and camera
 *     rays pass through it where it is below;
 *   - V = (unoccluded samples in front) / (samples in front), and V = 0 when no sample is in front;
 *   - the shadow factor S = sum_i w_i v_i / sum_i w_i over the samples in front (v_i = 1 when unoccluded),
 *     with the form-factor weight w_i = max(cos theta_r,i, 0) max(cos theta_l,i, 0) / r_i^2 (theta_r at
 *     the receiver, theta_l at the light, whose emitting side is cross(edge_s, edge_t)), times the sample's
 *     texel luminance for a textured light; S = V when every w_i is 0. With several lights, V and S per light. E_unshadowed * S is exact where the light is wholly visible or hidden and converges to
 *     the shadowed irradiance as N grows (a ratio estimator).
 * P is the hit point itself, not lifted off the surface: V and S do not depend on which side of the
 * surface rounding leaves it. Every shadow method computes V and S on the same samples, so methods can be
 * compared sample for sample. Pixels whose primary ray misses the scene get V = S = -1.
 *
 * Errors: every function that can fail returns an ms_status, MS_OK (0) on success, writing one line of text
 * (naming the file where there is one) into the caller's buffer err[errlen] on failure.
 *
 * ABI: the entry points that take the public structs check, on every call, that the program was compiled
 * against this library's layout of them (microshadow/abi.h, "The ABI check").
 *
 * This header is the whole API; it includes its parts by topic from include/microshadow/ (each part documented
 * at its head), which are not meant to be included alone.
 */
#ifndef MICROSHADOW_H
#define MICROSHADOW_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The version, from CMake's project() (microshadow_version.h is generated into the build tree and installed
 * beside this header): MS_VERSION_MAJOR, MS_VERSION_MINOR, MS_VERSION_PATCH and MS_VERSION_STRING are what a
 * program was compiled against; ms_version() is what it runs with. Before 1.0 every minor version may change
 * the ABI, so the shared library's soname carries major.minor (libmicroshadow.so.0.2); from 1.0 on, the major. */
#include "microshadow_version.h"

/* Only declarations marked MS_API are exported from the shared library (the rest is built with hidden
 * visibility and a version script keeps everything else local: tests/check_exports.sh). */
#if defined(__GNUC__) || defined(__clang__)
#define MS_API __attribute__((visibility("default")))
#else
#define MS_API
#endif

/* What every function that can fail returns: MS_OK (0), or the kind of failure, with one line of text (naming
 * the file where there is one) in the caller's buffer err[errlen] where the function takes one. The CLI maps
 * them to exit codes (README, "Exit codes"). */
typedef enum ms_status {
    MS_OK = 0,
    MS_ERR_INVALID = 1,     /* a bad argument (the message names it) */
    MS_ERR_NO_MEMORY = 2,
    MS_ERR_CANCELLED = 3,   /* the progress callback returned non-zero */
    MS_ERR_METHOD = 4,      /* unknown method, not compiled in, or its set-up failed */
    MS_ERR_IO = 5,          /* reading or writing a file failed */
    MS_ERR_BUDGET = 6       /* the call would need more memory than its budget (max_memory): refused before
                             * allocating; the message names the need, the budget and what would fit */
} ms_status;
/* "ok", "invalid argument", "out of memory", "cancelled", "method", "i/o", "over the memory budget". */
MS_API const char *ms_status_name(ms_status s);

/* The version of the library that is running: the string (e.g. "0.2.0"), and its numbers through whichever
 * pointers are not NULL. Compare with MS_VERSION_MAJOR/MINOR to detect a library other than the one a
 * program was built against. */
MS_API const char *ms_version(int *major, int *minor, int *patch);

/* Of the NULL-terminated names, the one nearest to word by edit distance (case-insensitive), and that
 * distance in *distance (may be NULL); NULL when names is empty. For "did you mean" hints: the scene
 * loader's unknown keys, the command line's unknown options and method names. */
MS_API const char *ms_nearest_name(const char *word, const char *const *names, size_t *distance);

/* The layout of a public struct as this library was compiled: with field NULL, the struct's size in *size;
 * else the field's offset and size. MS_OK, or MS_ERR_INVALID when the struct or field is not listed (src/core/layout.c
 * lists what bindings read). For bindings that mirror the structs (the Python module checks its mirror at
 * load time with it); C and C++ programs have the header. offset and size may be NULL. */
MS_API ms_status ms_layout(const char *structure, const char *field, size_t *offset, size_t *size);

/* Limits. Images are at most MS_MAX_IMAGE_SIZE pixels on a side; a frame has N = 256, 1024 or 4096 light
 * samples (a k x k grid, k = 16, 32, 64), the stratified pattern also 16 or 64 (k = 4, 8). Every pixel
 * gets all N, except with the interleaved pattern: N/16 per pixel. */
#define MS_MAX_IMAGE_SIZE 16384
#define MS_SAMPLES_MIN 16
#define MS_SAMPLES_DEFAULT 1024
#define MS_SAMPLES_MAX 4096
#define MS_DEFAULT_METHOD "scanline"
/* A method name that picks the method measured fastest for the options (docs/methods.md, "What to pick"):
 * scanline for the grid pattern, mft for the interleaved one, embree (else raytrace) for the stratified one,
 * hpc for a procedural scene that would not fit the memory budget materialised. ms_stats.method names the choice. */
#define MS_AUTO_METHOD "auto"

/* Memory budget (docs/memory.md). Frames, bakes and point queries estimate what each phase will allocate
 * (frame planes, per-light planes, the BVH and its triangles, a procedural scene materialised, hpc's receiver
 * hierarchy and masks, lightmap atlases) before allocating it, and refuse with MS_ERR_BUDGET and one line
 * naming the need, the budget and what would fit when the sum exceeds the budget. The budget is the options'
 * max_memory in bytes, or when that is 0 MS_MEMORY_DEFAULT_PERCENT percent of the physical memory. It bounds
 * what the call allocates beyond the scene it is given (the loaders bound that by the files' sizes).
 * ms_accel_build, which takes no options, uses the default. */
#define MS_MEMORY_DEFAULT_PERCENT 75
/* The budget in effect for max_memory: max_memory itself, or the default when it is 0. */
MS_API uint64_t ms_memory_budget(uint64_t max_memory);

typedef struct ms_vec3 { float x, y, z; } ms_vec3;

/* The API by topic, one part each (include/microshadow/): light shapes; scenes; frames; outputs; visibility
 * at any points; lightmap baking; the ABI check, whose inline wrappers come last. */
#include "microshadow/lights.h"
#include "microshadow/scene.h"
#include "microshadow/render.h"
#include "microshadow/output.h"
#include "microshadow/points.h"
#include "microshadow/bake.h"
#include "microshadow/abi.h"

#ifdef __cplusplus
}
#endif
#endif
