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
 * against this library's layout of them ("The ABI check", at the end).
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

/* Camera projections (scene file: camera.type; docs/cameras.md). The view frame is forward =
 * normalize(target - eye), right = normalize(cross(forward, up)), true up = cross(right, forward).
 *   MS_CAMERA_PINHOLE: perspective through a planar image, vertical field of view fov_y (degrees);
 *   MS_CAMERA_ORTHOGRAPHIC: parallel rays along forward from the plane through eye; the image spans
 *     ortho_height world units vertically (width in proportion);
 *   MS_CAMERA_FISHEYE: equidistant, the angle from forward proportional to the distance from the image
 *     centre; the circle inscribed in the image spans fov degrees (up to 360); pixels outside it see nothing;
 *   MS_CAMERA_LATLONG: the 360 x 180 degree panorama (light probes, VR): x is the longitude around up
 *     (the centre column looks along forward, right at 3/4 of the width), y the latitude from up (row 0)
 *     to down;
 *   MS_CAMERA_PARABOLIC: the hemisphere around forward by the paraboloid map (Heidrich & Seidel 1998) on
 *     the disk inscribed in the image; pixels outside it see nothing. */
typedef enum ms_camera_type {
    MS_CAMERA_PINHOLE = 0, MS_CAMERA_ORTHOGRAPHIC = 1, MS_CAMERA_FISHEYE = 2, MS_CAMERA_LATLONG = 3,
    MS_CAMERA_PARABOLIC = 4
} ms_camera_type;

/* A camera. Pixel (x,y), y = 0 the top row; the primary ray passes through (x+0.5, y+0.5). Zeroed
 * fields past height keep a pinhole camera. */
typedef struct ms_camera {
    ms_vec3 eye, target, up;
    float fov_y;         /* MS_CAMERA_PINHOLE: vertical field of view, degrees in (0, 180) */
    int width, height;
    ms_camera_type type;
    float fov;           /* MS_CAMERA_FISHEYE: field of view of the inscribed circle, degrees in (0, 360] */
    float ortho_height;  /* MS_CAMERA_ORTHOGRAPHIC: the image's height in world units, > 0 */
} ms_camera;

/* Light shapes (docs/design.md, "Light shapes"). Every shape is sampled on its parallelogram
 * L(s,t) = corner + s*edge_s + t*edge_t, s,t in [0,1]: the pattern's samples are those of the
 * parallelogram, and the shape masks off the samples outside it by their parameters (s,t):
 *   MS_LIGHT_RECT: the parallelogram itself (every sample; the zero value, so older callers keep it);
 *   MS_LIGHT_DISK: the ellipse inscribed in the parallelogram, (2s-1)^2 + (2t-1)^2 < 1; for a disk of
 *     centre c, unit normal m and radius r the parallelogram is its bounding square (ms_light_disk);
 *   MS_LIGHT_SPHERE: a sphere (center, radius; the parallelogram fields unused). Seen from a receiver P
 *     outside it, its outline is a disk facing P (ms_light_sphere_outline): each receiver is sampled on
 *     its own outline disk, a per-receiver light frame (frames, points and bakes alike); not textured.
 *   MS_LIGHT_TRIANGLE: the triangle corner, corner + edge_s, corner + edge_t: the parameters with s + t < 1
 *     (ms_light_triangle); emits towards cross(edge_s, edge_t); not textured.
 *   MS_LIGHT_SUN: a disk at infinity (ms_light_sun): the cone of directions of angular diameter 2 alpha about
 *     the unit direction `center` (towards the sun), the same from every receiver. Each receiver P is sampled
 *     on its own outline, the disk of radius D tan(alpha) at P + D center facing P, with the disk's mask; D
 *     (`radius`) is set by the renderer from the scene's extent so that every segment ends outside the
 *     scene (no far limit for the scene's occluders; the near range is 1e-4 D): docs/design.md, "The sun";
 *     not textured. */
typedef enum ms_light_shape { MS_LIGHT_RECT = 0, MS_LIGHT_DISK = 1, MS_LIGHT_SPHERE = 2, MS_LIGHT_TRIANGLE = 3, MS_LIGHT_SUN = 4 } ms_light_shape;

/* An area light. It emits radiance `emission` (linear RGB) from the side cross(edge_s, edge_t) points to,
 * from the samples of its shape. Zero-initialised fields past emission keep a uniform parallelogram.
 * A textured light (texture non-NULL) emits emission times the texel at its parameters (s,t): the
 * nearest of texture_width x texture_height linear RGB texels (3 floats each, row 0 at t = 0, column 0
 * at s = 0). Its texels weight the samples in S (docs/design.md: w_i times the texel's luminance) and
 * the shading; V stays the unweighted fraction. The caller owns the texels (ms_scene_free frees a loaded
 * scene's). */
/* Bounds on what a light emits, so that every output stays finite in single precision: a light texture's
 * texels lie in [0, MS_MAX_LIGHT_TEXEL] and a light's radiance (after "power" or "lumens" are divided by
 * pi times its area) in [-MS_MAX_RADIANCE, MS_MAX_RADIANCE] per channel; ms_scene_validate refuses more, and
 * the EXR reader refuses such a texel naming it. Why these suffice: a pixel's radiance is a sum over at most
 * 64 lights of albedo/pi * E * S * t plus a specular term, where the unshadowed irradiance E <= pi L (the
 * projected solid angle of the receiver's hemisphere is pi), S <= 1, the mean texel t <= 1e6 and the
 * specular term (LTC-integrated GGX: directional albedo <= 1) <= L t. So a pixel is at most
 * 64 * 2 * 1e20 * 1e6 = 1.3e28, a baked irradiance at most 64 * pi * 1e26 = 2e28, and S's texel-weighted
 * sums (at most 4096 weights times a luminance <= 1e6, summed in double) stay as far from overflow: ten
 * orders of magnitude below FLT_MAX = 3.4e38, room for the intermediate products. 1e6 is beyond any light
 * profile's useful dynamic range (scale the emission instead); 1e20 is 1e11 times the sun's luminance in
 * nits. What geometry alone can make infinite (the form-factor weight of a receiver touching the light)
 * is caught by the last check before outputs are written (ms_outputs_write, ms_bake, ms_visibility_points). */
#define MS_MAX_LIGHT_TEXEL 1e6f
#define MS_MAX_RADIANCE 1e20f

typedef struct ms_light {
    ms_vec3 corner, edge_s, edge_t;
    ms_vec3 emission;
    ms_light_shape shape;
    const float *texture;
    int texture_width, texture_height;
    ms_vec3 center;      /* MS_LIGHT_SPHERE only (MS_LIGHT_SUN: the unit direction towards the sun) */
    float radius;        /* MS_LIGHT_SPHERE only (MS_LIGHT_SUN: the placement distance D, 0 until rendered) */
} ms_light;

/* Fills l as a sphere light of centre c and radius r (emission left as it is). MS_OK, or MS_ERR_INVALID when r is
 * not > 0. */
MS_API ms_status ms_light_sphere(ms_light *l, ms_vec3 c, float r);
/* The outline of sphere light l seen from p: the disk where the cone of tangents from p touches the sphere,
 * centre c + (p - c) r^2/d^2, radius r sqrt(d^2 - r^2)/d (d = |p - c|), facing p, as a disk light
 * (ms_light_disk) with l's emission. Every ray from p to this disk meets the sphere first at its near side,
 * and the disk subtends the sphere's solid angle. MS_OK, or MS_ERR_INVALID when p is not outside the sphere. */
MS_API ms_status ms_light_sphere_outline(const ms_light *l, const float p[3], ms_light *disk);

/* Luminance of the texel at (s,t) of a textured light (0.2126 R + 0.7152 G + 0.0722 B), and its colour
 * into rgb when rgb is not NULL; 1 (and white) for an untextured light. */
MS_API float ms_light_texel(const ms_light *l, float s, float t, float *rgb);

/* Fills l as a disk light of centre c, normal m (emitting towards m; need not be unit length, not zero)
 * and radius r: its bounding square, edges 2r along two unit vectors perpendicular to m chosen from m
 * alone, and shape MS_LIGHT_DISK; emission is left as it is. MS_OK, or MS_ERR_INVALID when m is zero or r not
 * > 0. */
MS_API ms_status ms_light_disk(ms_light *l, ms_vec3 c, ms_vec3 m, float r);

/* Fills l as a triangle light of vertices a, b, c (corner a, edges b - a and c - a, shape MS_LIGHT_TRIANGLE),
 * emitting towards cross(b - a, c - a); emission is left as it is. MS_OK, or MS_ERR_INVALID when the vertices are
 * collinear. */
MS_API ms_status ms_light_triangle(ms_light *l, ms_vec3 a, ms_vec3 b, ms_vec3 c);

/* Fills l as a sun (MS_LIGHT_SUN): a disk at infinity in unit direction dir from the scene (towards the sun;
 * need not be unit length, not zero) of angular diameter angular_diameter_deg in (0, 90] degrees (the Sun's:
 * 0.53). Its parallelogram is the outline's bounding square at unit distance (the disk of radius
 * tan(alpha) at dir, emitting towards -dir), center the unit dir, radius 0 (the renderer places it);
 * emission, its radiance, is left as it is (irradiance at normal incidence E = pi L sin^2 alpha).
 * MS_OK, or MS_ERR_INVALID when dir is zero or the diameter out of range. */
MS_API ms_status ms_light_sun(ms_light *l, ms_vec3 dir, float angular_diameter_deg);

/* 1 if light parameters (s,t) lie on the light's shape (see ms_light_shape), 0 if not. */
MS_API int ms_light_shape_contains(ms_light_shape shape, float s, float t);

/* The emitting area of the light's shape (|edge_s x edge_t|, times pi/4 for a disk, 1/2 for a triangle; 4 pi r^2 for a sphere;
 * sin^2 alpha for a sun, so that watts and lumens convert to radiance from W m^-2 and lux at normal incidence). */
MS_API float ms_light_area(const ms_light *l);

/* Units of a light's emission in a scene file (docs/design.md, "Units"). The renderer works in radiance;
 * the others are converted by the shape's emitting area A, every light emitting as a one-sided
 * Lambertian surface (Drobot, GPU Pro 5, "physically based area lights": flux = pi * A * radiance):
 *   MS_UNITS_RADIANCE: emission is radiance (W sr^-1 m^-2 or the scene's own linear unit);
 *   MS_UNITS_WATTS: radiant flux Phi in W per channel, radiance = Phi / (pi A);
 *   MS_UNITS_LUMENS: luminous flux in lm per channel, luminance = Phi_v / (pi A) in cd m^-2 (nits);
 *     the renderer's radiance unit is then the nit (no 683 lm/W: the image stays photometric). */
typedef enum ms_light_units { MS_UNITS_RADIANCE = 0, MS_UNITS_WATTS = 1, MS_UNITS_LUMENS = 2 } ms_light_units;
/* The radiance of light l (its shape and edges set) emitting `amount` in `units`. */
MS_API ms_vec3 ms_light_radiance_from(const ms_light *l, ms_vec3 amount, ms_light_units units);

#define MS_MAX_UV_SETS 4

/* A procedural triangle source (scene file: "procedural": {"type": "flowers", "triangles": N, "seed": S}):
 * triangle i is a pure function of (type, seed, i), generated in batches when needed, so that methods that
 * stream their triangles (hpc, hpc-scanline) never hold the scene; the others get it materialised. */
typedef enum ms_procedural_type { MS_PROCEDURAL_NONE = 0, MS_PROCEDURAL_FLOWERS = 1 } ms_procedural_type;
typedef struct ms_procedural {
    ms_procedural_type type;
    uint32_t seed;
} ms_procedural;

/* A triangle soup: tri[9*i .. 9*i+8] are the three vertices of triangle i. With a procedural source, tri is
 * NULL and n_tris counts the triangles it generates.
 * The scene's frame (docs/design.md, "The scene's frame"): every position of an ms_scene - tri, the camera's
 * eye and target, the lights' corners and centres, and so ms_scene_lights and ms_accel_lights - is local,
 * world = local + origin (in double). ms_scene_load puts a scene that lies far from the world's origin into a
 * frame centred on its geometry, subtracting in double before rounding to float, so that a model 100 km out
 * keeps the detail and the speed it has at home; a scene within 2 of its sizes of the origin keeps origin = 0
 * and its floats as they were. Scenes built by the caller (zeroed origin; ms_scene_localize moves them), the
 * built-in and the procedural scenes are in world coordinates (origin 0). Frames are images and need no conversion; ms_visibility_points takes world
 * positions (converted with the origin of the accel's scene, ms_accel_origin); ms_lightmap.position is in
 * the scene's frame (add origin for world coordinates). Directions (normals, edges, up) are the same in both. */
typedef struct ms_scene {
    float *tri;
    size_t n_tris;
    ms_camera camera;
    ms_light light;
    int samples;         /* light samples per pixel from the scene file (render.samples) */
    double load_s;       /* seconds spent loading meshes */
    /* For baking (NULL where not known; ms_scene_free frees them). tri_mesh[i]: the mesh of the scene
     * file (0-based, in its "meshes" order) triangle i came from. tri_uv[s][6*i .. 6*i+5]: (u, v) of
     * triangle i's three vertices in UV set s (glTF TEXCOORD_s, assimp channel s), NaN where its mesh has
     * no such set; tri_uv[s] is NULL when no mesh has it. */
    uint32_t *tri_mesh;
    float *tri_uv[MS_MAX_UV_SETS];
    size_t n_meshes;
    ms_procedural procedural;
    /* Surfaces (docs/shading.md; NULL/0 where no mesh has them; ms_scene_free frees them). tri_material[i]:
     * index into materials of triangle i, or MS_NO_MATERIAL (the default Lambertian grey of albedo 0.8).
     * tri_normal[9*i .. 9*i+8]: the shading normals of its three vertices, NaN where its mesh has none
     * (then the geometric normal shades). Visibility (V, S) never uses either. */
    struct ms_material *materials;
    size_t n_materials;
    uint32_t *tri_material;
    float *tri_normal;
    struct ms_texture *textures;
    size_t n_textures;
    /* Several lights (scene file: "lights": [...]): lights[0 .. n_lights-1], each with its own V and S;
     * light is a copy of lights[0]. n_lights = 0 (lights NULL): the one light `light`. ms_scene_free
     * frees lights. */
    ms_light *lights;
    size_t n_lights;
    /* Normal-map tangents (NULL where no mesh has them): tri_tangent[12*i .. 12*i+11], (x, y, z, w) of
     * triangle i's three vertices, NaN where its mesh has none (glTF TANGENT, else MikkTSpace for primitives
     * with a normal map; w: the bitangent is w n x t). */
    float *tri_tangent;
    /* The world position of the local frame's origin (see above): 0, 0, 0 unless ms_scene_load moved a
     * distant scene. */
    double origin[3];
    /* Objects (NULL where not known: one per mesh, tri_mesh): tri_object[i] is the object triangle i came
     * from, numbered 0 .. n_objects-1 across the scene: each glTF node with a mesh, each file of another
     * format. A baker gives each object its own region of the lightmap when their UVs overlap. */
    uint32_t *tri_object;
    size_t n_objects;
    /* Per scene-file mesh (n_meshes entries, NULL: all 1): its texel density weight in bakes (scene file
     * "lightmap": {"scale": s}), 0 for "lightmap": false (not baked; it still casts shadows). */
    float *mesh_lightmap_scale;
    int aa;              /* primary samples per pixel from the scene file (render.aa; 0: not given) */
} ms_scene;

#define MS_NO_MATERIAL UINT32_MAX

/* An 8-bit RGBA image, sRGB-encoded colour, row 0 at v = 0 (glTF's convention). */
typedef struct ms_texture {
    int width, height;
    uint8_t *rgba;
} ms_texture;

/* glTF 2.0 metallic-roughness (OBJ/MTL maps Kd/map_Kd, Pr, Pm onto it). base = base_color * texture
 * (sampled bilinearly with repeat at the triangle's UVs of set base_color_uv). */
/* How a material samples one of its textures (glTF sampler and KHR_texture_transform). Zero is glTF's
 * default: repeat, bilinear, untransformed. */
typedef struct ms_texture_sampling {
    int32_t wrap_s, wrap_t;    /* MS_WRAP_REPEAT (0), MS_WRAP_CLAMP, MS_WRAP_MIRROR */
    int32_t nearest;           /* 1: the nearest texel (magFilter NEAREST); 0: bilinear */
    int32_t transformed;       /* 1: (u, v) -> (t[0] u + t[2] v + t[4], t[1] u + t[3] v + t[5]) before the lookup */
    float transform[6];
} ms_texture_sampling;

enum { MS_WRAP_REPEAT = 0, MS_WRAP_CLAMP = 1, MS_WRAP_MIRROR = 2 };

typedef struct ms_material {
    float base_color[4];       /* linear RGBA factor */
    float metallic, roughness; /* in [0, 1]; roughness is perceptual: GGX alpha = roughness^2 */
    int32_t base_color_texture;/* index into ms_scene.textures, -1: none */
    int32_t base_color_uv;     /* UV set (0 .. MS_MAX_UV_SETS-1) of the texture's coordinates */
    /* Alpha testing (docs/shading.md, "Alpha-tested occluders"); zero: opaque, as older initialisers leave it.
     * An alpha-tested triangle occludes shadow segments and camera rays only where its alpha >= alpha_cutoff,
     * alpha = base_color[3] times the texture's value at the point (bilinear with repeat, UV set base_color_uv):
     * MS_ALPHA_MASK: the base-colour texture's alpha channel (glTF alphaMode MASK, and BLEND, loaded as MASK);
     * MS_ALPHA_MASK_MAP: the separate map alpha_texture (MTL map_d: its alpha channel, or its red channel when
     * the image is opaque everywhere). No texture: base_color[3] alone decides. */
    int32_t alpha_mode;        /* MS_ALPHA_OPAQUE, MS_ALPHA_MASK, MS_ALPHA_MASK_MAP */
    float alpha_cutoff;        /* glTF alphaCutoff (default 0.5); MTL map_d: 0.5 */
    int32_t alpha_texture;     /* MS_ALPHA_MASK_MAP: index into ms_scene.textures (-1: none) */
    /* Issue 30 (zero: as before). The base-colour texture's sampler and transform (the alpha test uses the
     * transform too). A tangent-space normal map when normal_map is 1: texture normal_texture (linear RGB,
     * n = 2 rgb - 1, x and y times normal_scale) at UV set normal_uv, tangents from the triangle's positions
     * and UVs (docs/shading.md). Emission: emissive (linear, times KHR_materials_emissive_strength) times
     * the sRGB texture emissive_texture when emissive_map is 1, added to the shaded radiance. */
    ms_texture_sampling base_color_sampling;
    int32_t normal_map, normal_texture, normal_uv;
    float normal_scale;
    ms_texture_sampling normal_sampling;
    float emissive[3];
    int32_t emissive_map, emissive_texture, emissive_uv;
    ms_texture_sampling emissive_sampling;
    /* glTF metallicRoughnessTexture when mr_map is 1: metallic times its blue channel, roughness times its
     * green (linear). */
    int32_t mr_map, mr_texture, mr_uv;
    ms_texture_sampling mr_sampling;
} ms_material;

enum { MS_ALPHA_OPAQUE = 0, MS_ALPHA_MASK = 1, MS_ALPHA_MASK_MAP = 2 };

/* The scene's lights: its n_lights lights, or `light` alone when n_lights is 0. Sets *n. */
MS_API const ms_light *ms_scene_lights(const ms_scene *s, size_t *n);

/* Triangles [first, first + count) of a procedural scene (9 floats each) into out. */
MS_API void ms_procedural_triangles(const ms_scene *s, size_t first, size_t count, float *out);

/* Warnings (an unknown key in a scene file) go to this handler, one line each without a newline; by
 * default they are printed to stderr as "microshadow: warning: ...". NULL restores the default. */
typedef void (*ms_warning_fn)(void *user, const char *message);
MS_API void ms_set_warning_handler(ms_warning_fn fn, void *user);
/* Material files and textures a scene's meshes name but that cannot be used (missing, unreadable, an undecoded
 * format, an absolute path) are one warning per ms_scene_load: that warning, or "N material files, textures or
 * glTF features could not be used ... (first: ...)" (unimplemented glTF extensions and features are counted with
 * them). With verbose non-zero (process-wide, like the handler) each is its own warning. */
MS_API void ms_set_warning_verbose(int verbose);

/* Loads a JSON scene file (meshes: OBJ, PLY, OFF, STL read by microshadow, glTF 2.0 through cgltf; paths
 * relative to the JSON file). Regular files only, at most 16 MiB of JSON; duplicate keys are errors,
 * unknown keys warnings. */
static inline ms_status ms_scene_load(const char *json_path, ms_scene *out, char *err, size_t errlen);
/* Options of ms_scene_load_ex; zero (or NULL) means ms_scene_load's behaviour. */
typedef struct ms_scene_load_options {
    /* Files that meshes name - glTF buffer and image URIs, OBJ mtllib files, MTL maps (map_Kd, map_d) - are
     * read only from inside the folder of the file naming them: an absolute path, `..` leading out of that
     * folder, or a symbolic link resolving outside it is an error naming the file and the path (a downloaded
     * asset reads only its own files). Non-zero reads them anyway, for trusted assets, as the scene file's
     * "allow_outside_paths": true does (either one allows). Mesh and texture paths in the scene file itself
     * are the scene author's and are not restricted. */
    int allow_outside_paths;
} ms_scene_load_options;
static inline ms_status ms_scene_load_ex(const char *json_path, const ms_scene_load_options *opt, ms_scene *out, char *err,
                                         size_t errlen);
/* The built-in procedural scene: a ground, occluders of several sizes, a light (the tests' fixture). */
static inline ms_status ms_scene_default(ms_scene *out);
/* The built-in scene the CLI renders without a scene file: smooth-shaded curved objects (per-vertex normals),
 * a procedurally textured ground, a metal and rough plastics, alpha-tested leaf cards, and a rect, a disk and a
 * sphere light of different colours; 768 x 512, 256 samples. MS_OK, or MS_ERR_NO_MEMORY. */
static inline ms_status ms_scene_showcase(ms_scene *out);
/* Puts a scene built in world coordinates (tri, camera, lights as floats; origin usually 0) into the frame
 * ms_scene_load would choose for it (see ms_scene): tri, the camera's eye and target and the lights' corners
 * and centres moved, origin set. The detail a float lost far from the origin is not recovered, but every
 * method then works at the scene's own magnitudes (bounds as tight, time as at home). Nothing changes for a
 * scene about the origin, a procedural scene, or one already in its frame. MS_OK, or MS_ERR_NO_MEMORY. */
MS_API ms_status ms_scene_localize(ms_scene *s);
/* Checks camera, light and geometry for NaN/inf and degenerate cases. `what` names the source. */
MS_API ms_status ms_scene_validate(const ms_scene *s, const char *what, char *err, size_t errlen);
MS_API void ms_scene_free(ms_scene *s);

typedef enum ms_pattern {
    MS_PATTERN_GRID = 0,       /* k x k lattice, slightly rotated and shifted per pixel (Woop, sec. 6) */
    MS_PATTERN_STRATIFIED = 1, /* k x k jittered strata, jitter hashed from pixel, sample and seed */
    MS_PATTERN_INTERLEAVED = 2 /* Benthin & Wald 2009: N QMC points in all, each pixel of a 4x4 block a
                                * different N/16 of them, then a 4x4 discontinuity-aware filter over V, S */
} ms_pattern;

/* "grid", "stratified", "interleaved" ("unknown" otherwise). */
MS_API const char *ms_pattern_name(ms_pattern p);
/* Parses one of those names; MS_OK, or MS_ERR_INVALID for anything else. */
MS_API ms_status ms_pattern_from_name(const char *name, ms_pattern *out);

/* Instruction-set levels of the SIMD kernels and the traversal, in increasing order. As a cap,
 * MS_ISA_AUTO (0) means none: the best level the CPU runs; a cap above the CPU gives the CPU's best. */
typedef enum ms_isa {
    MS_ISA_AUTO = 0,
    MS_ISA_SCALAR = 1,  /* portable C */
    MS_ISA_AVX2 = 2,    /* AVX2 + FMA + BMI1/2 + LZCNT + POPCNT */
    MS_ISA_AVX512 = 3   /* the above + AVX-512 F/BW/VL/DQ */
} ms_isa;

/* "auto", "scalar", "avx2", "avx512". */
MS_API const char *ms_isa_name(ms_isa isa);
/* Parses one of those names; MS_OK, or MS_ERR_INVALID for anything else. */
MS_API ms_status ms_isa_from_name(const char *name, ms_isa *out);
/* The best level this CPU (and OS: saved register state) runs. */
MS_API ms_isa ms_cpu_isa(void);

/* Progress with cancellation (like Embree's progress monitor), for frames, points and bakes: called with the
 * fraction done, from one thread at a time (never concurrently for one call), fractions growing to 1; return 0
 * to go on, non-zero to cancel the call, which then returns MS_ERR_CANCELLED soon after without results. */
typedef int (*ms_progress_cancel_fn)(void *user, double fraction_done);

/* How the embree method hands rays to Embree (docs/embree.md). */
typedef enum ms_embree_mode {
    MS_EMBREE_PACKET16 = 0,    /* rtcOccluded16 over groups of 16 samples (the faster here) */
    MS_EMBREE_STREAM = 1       /* one coherent rtcOccluded1M stream per pixel */
} ms_embree_mode;

/* When the embree method filters out the receiver's own triangle. */
typedef enum ms_embree_filter {
    MS_EMBREE_FILTER_PLANE = 0,  /* only where a segment can meet its plane in the occluding range */
    MS_EMBREE_FILTER_ALWAYS = 1, /* every pixel (same V, slower) */
    MS_EMBREE_FILTER_NONE = 2    /* never: for measuring only, the receiver then occludes itself */
} ms_embree_filter;

/* How the micro-rasterization methods find the triangles between a point and the light. */
typedef enum ms_traversal {
    MS_TRAVERSAL_AUTO = 0,   /* the default: MS_TRAVERSAL_BLOCK */
    MS_TRAVERSAL_BLOCK = 1,  /* the frusta of a 4x4 pixel block together through a shallow BVH (Benthin & Wald 2009) */
    MS_TRAVERSAL_PIXEL = 2   /* each pixel's frustum alone through the deep BVH (Woop 2010) */
} ms_traversal;

/* Every field's zero means its default, so a zeroed struct renders with the defaults. */
/* Whether a light's occluders leave out the back of closed meshes (ms_render_options.closed_cull). */
typedef enum ms_closed_cull_mode {
    MS_CLOSED_CULL_DEFAULT = 0,   /* the method's measured choice */
    MS_CLOSED_CULL_ON = 1,
    MS_CLOSED_CULL_OFF = 2
} ms_closed_cull_mode;

/* Whether ms_render_outputs writes the outputs as the rows finish (ms_render_options.stream; docs/memory.md). */
typedef enum ms_stream_mode {
    MS_STREAM_AUTO = 0,   /* only when the whole frame would exceed the memory budget and a streamed one fits */
    MS_STREAM_ON = 1,     /* always (refused for frame-level methods and the interleaved filter) */
    MS_STREAM_OFF = 2     /* never: the whole frame in memory, then the outputs */
} ms_stream_mode;

/* What a frame shades (ms_render_options.shading; docs/shading.md). */
typedef enum ms_shading {
    MS_SHADING_STANDARD = 0,  /* the materials as they are: diffuse and GGX specular, emission */
    MS_SHADING_DIFFUSE = 1    /* base colour * E_unshadowed * S / pi alone (no specular, no metallic darkening, no
                               * emission): the picture a lightmap can give, to compare with the baked glb's
                               * viewer (docs/baking.md) */
} ms_shading;

typedef struct ms_render_options {
    const char *method;     /* shadow method by name: see ms_method_names(); NULL: MS_DEFAULT_METHOD */
    ms_pattern pattern;
    int samples;            /* N: 256, 1024 or 4096 (k*k with k = 16, 32, 64), stratified also 16, 64;
                             * 0: the scene's */
    int width, height;      /* 0: the scene camera's */
    int threads;            /* 0: all cores; the host's OpenMP settings are left alone */
    uint32_t seed;
    ms_progress_cancel_fn progress;   /* may be NULL; non-zero from it cancels the frame */
    void *progress_user;
    ms_isa isa;             /* cap on the instruction set of kernels and traversal; MS_ISA_AUTO: the CPU's best */
    /* Switches to measure what a part buys; leave them 0. */
    int no_occlusion_cull;  /* micro-raster methods: no coverage cull of BVH nodes */
    int no_child_order;     /* micro-raster methods: no near-first order of BVH children */
    ms_embree_mode embree_mode;
    ms_embree_filter embree_filter;
    ms_traversal traversal; /* micro-raster methods: block (default) or per-pixel traversal */
    int frustum_shrink;     /* block traversal and mft: also narrow a pixel's traversal frustum as its samples are
                             * occluded (the paper's "FS"; off: only its leaf rectangle shrinks, "CR") */
    int no_filter;          /* interleaved pattern: leave out the 4x4 discontinuity-aware filter (raw V, S) */
    /* Primary visibility (docs/primary.md): NULL pairs it with the shadow method ("bvh", "embree"; "depth"
     * for a streamed procedural scene), else one of bvh, embree, depth (procedural scenes only), 3dr-bb,
     * 3dr-bin, 3dr-fc, 3dr-fs, 3dr-full. A procedural scene is streamed when both the shadow method and the
     * primary stream (3dr-bb, 3dr-bin, depth), else materialised. */
    const char *primary;
    int consistent_primary; /* bvh primary: decide each ray with the 3D rasterizers' consistent edge test
                             * (ties by the top-left rule, t ties to the smaller id): the same hits as 3dr-* */
    ms_closed_cull_mode closed_cull; /* leave out of every light's occluders the triangles of closed meshes that face
                             * away from the whole light: the same V and S (docs/culling.md). Default: on for the
                             * micro-raster methods and mft (with their interior boxes it pays: thin closed parts
                             * halve) and hpc, hpc-scanline (every triangle left out is pairs saved), off for
                             * raytrace (on bulky meshes it costs it: the kept far side projects smaller); embree
                             * never culls */
    int no_interior;        /* micro-raster methods: no interior boxes (virtual occluders inside closed meshes,
                             * docs/culling.md: the same V and S); to measure what they buy */
    int no_merge;           /* micro-raster methods, mft, hpc: occluders as given, without merging the two halves
                             * of axis-aligned rectangles and rectangles sharing a side into one (docs/culling.md:
                             * the same points; the same V and S for mft and hpc, which take each sample from a
                             * set that decides it as the pieces do, and up to ties on the rectangles' sides for
                             * the micro-raster methods) */
    uint64_t max_memory;    /* the memory budget in bytes (ms_memory_budget); 0: the default */
    ms_stream_mode stream;  /* ms_render_outputs only (ms_render always holds the whole frame) */
    int stream_rows;        /* streamed: rows per band of the rendered frame (with anti-aliasing s times the output's,
                             * s = sqrt aa), a multiple of s * MS_TILE_SIZE; 0: about 512 tiles' worth, fewer (down to
                             * s tile rows) when the budget needs */
    /* Pixel anti-aliasing (docs/antialiasing.md): K = aa primary samples per pixel (1, 4, 9 or 16; 0: the
     * scene's render.aa, else 1), on the s x s grid of the pixel's strata centres (s = sqrt K). Each has its own
     * hit, front mask and shadow query (every method answers each as a pixel of an s-times larger frame, on
     * that pixel's samples), and the frame's rgb, V, S and S_spec are their box-filtered average per pixel (V,
     * S over the samples that hit; -1 where none did; rgb counts misses as black). K = 1 is the frame as without
     * anti-aliasing, bit for bit. */
    int aa;
    int aa_split;           /* aa > 1: the pixel's N light samples split among its K hits (N/K each, which must be
                             * a valid sample count for the pattern) instead of all N for every hit */
    ms_shading shading;     /* 0: standard; the automatic exposure is that of the picture shaded */
} ms_render_options;

/* Zeroes o and names the default method: the same as a zeroed struct. */
static inline void ms_render_options_default(ms_render_options *o)
{
    memset(o, 0, sizeof *o);
    o->method = MS_DEFAULT_METHOD;
}

/* Names of the shadow methods compiled in, NULL-terminated. */
MS_API const char *const *ms_method_names(void);
/* 1 if `name` is a known method compiled into this build, 0 if unknown, -1 if known but not compiled in. */
MS_API int ms_method_available(const char *name);

#define MS_MAX_COUNTERS 32

typedef struct ms_stats {
    size_t triangles;
    /* Seconds: scene loading, our BVH build, the methods' own set-up (e.g. Embree's scene build), primary
     * visibility, shadows, and all of it (total_s). */
    double load_s, build_s, setup_s, primary_s, shadow_s, total_s;
    int samples, threads, width, height;   /* samples: N, the frame's light samples */
    int samples_per_pixel;         /* N, or N/16 for the interleaved pattern */
    const char *method;
    const char *pattern;
    const char *kernel_isa;        /* instruction set the method's kernel ran ("none" when it has none) */
    const char *traversal_isa;     /* ... and its traversal */
    uint64_t visible_pixels;
    uint64_t shadow_rays;          /* samples in front of the visible points: the segments every method answers */
    uint64_t penumbra_pixels;      /* pixels with some but not all front samples visible: S needs weights */
    double shadow_factor_s;        /* part of shadow_s spent resolving V and S from the sample masks
                                    * (thread-seconds / threads) */
    double filter_s;               /* part of shadow_s spent in the interleaved pattern's filter (0: none) */
    int n_counters;                /* method-specific counters */
    const char *counter_name[MS_MAX_COUNTERS];
    uint64_t counter[MS_MAX_COUNTERS];
    double shadow_cpu_s;           /* frames: the process's CPU seconds (all threads) during shadow_s, the
                                    * figure to compare methods by on a machine shared with other work;
                                    * 0 from the points API (other callers may share the process) */
    const char *primary;           /* the primary-visibility method used */
    /* Its counters where it has them (the 3D rasterizers, the consistent bvh caster; Dachsbacher et al.'s
     * Table 1): triangle set-ups, edge-function evaluations, BVH nodes visited; 0 otherwise. */
    uint64_t primary_setups, primary_edge_evals, primary_nodes;
    /* Triangles of closed components left out of the lights' occluders (ms_render_options.closed_cull),
     * and interior boxes rasterized before the triangles (micro-raster methods), summed over the lights
     * (docs/culling.md). */
    uint64_t occluders_culled, interior_boxes;
    uint64_t occluders_merged;     /* triangles saved by merging coplanar rectangles, summed over the lights */
    uint64_t receivers_on_merged;  /* visible points on a merged face, answered on the scene's own triangles by
                                    * the reference tracer (docs/culling.md), summed over the lights */
    uint64_t memory_need;          /* bytes the call estimated it would allocate, checked against its memory budget */
    uint64_t memory_budget;        /* that budget (max_memory, or the default: ms_memory_budget) */
    int stream_rows;               /* ms_render_outputs: the output rows of a band when the outputs were streamed, else 0 */
} ms_stats;

typedef struct ms_frame {
    int width, height;
    float *vis;       /* width*height, row 0 at the top: V; -1 where the primary ray missed */
    float *shadow;    /* width*height: the shadow factor S; -1 where the primary ray missed */
    uint16_t *front;  /* width*height: the pixel's samples in front of the receiver's plane (0..samples per
                       * pixel); 0 on misses */
    /* With the interleaved pattern (filter on) vis and shadow hold the filtered values: each mixes 16
     * pixels' sample sets, so they are not comparable sample for sample with another method's. */
    float *rgb;       /* 3*width*height linear radiance (docs/shading.md): emission * (c_diff/pi *
                       * E_unshadowed * S + F * LTC_GGX * S_spec); without materials albedo 0.8, no specular */
    float exposure;   /* scale that maps the 99th percentile of unshadowed radiance to 1 (for PNG) */
    ms_stats stats;
    /* The specular shadow factor S_spec (docs/shading.md), one width*height plane per light like shadow:
     * S where the pixel's material has no specular lobe; -1 where the primary ray missed. */
    float *shadow_spec;
    /* Lights of the frame (0 means 1). vis, shadow and front hold one width*height plane per light, light l
     * at vis + l*width*height (the first plane is light 0, as with one light); rgb sums the lights. */
    int n_lights;
} ms_frame;

/* A frame: MS_OK, or a status with a message in err and *out zeroed: MS_ERR_CANCELLED when the progress
 * callback cancelled it, MS_ERR_BUDGET when it would need more memory than the budget (nothing was allocated
 * for it then), MS_ERR_METHOD for a method (or primary) unknown, not compiled in or failing its set-up,
 * MS_ERR_NO_MEMORY, MS_ERR_INVALID for bad options or a bad scene. */
static inline ms_status ms_render(const ms_scene *scene, const ms_render_options *opt, ms_frame *out, char *err,
                                  size_t errlen);
MS_API void ms_frame_free(ms_frame *f);

/* ---- A frame tile by tile: for drivers that spread one frame over processes (the CLI's MPI mode) ----
 *
 * ms_render is ms_frame_job_create, one ms_frame_job_render of every tile, and ms_frame_job_finish. A driver
 * may instead render any tiles in any number of calls, in several jobs of the same scene and options (one
 * per process), copy the rendered tiles' pixels of vis, shadow, shadow_spec and front, every light's plane
 * (ms_frame_job_frame), into one job, and finish that one: its frame equals ms_render's bit for bit, because
 * a pixel's V, S and S_spec depend only on the pixel, the seed and the scene, and finish does what depends on
 * the whole frame (primary hits and surfaces of the tiles rendered elsewhere, the interleaved pattern's
 * filter, the textured lights' mean texels, the shading and its exposure). Tiles are
 * MS_TILE_SIZE pixels square, numbered row by row: tile t covers x from MS_TILE_SIZE (t % tiles_x) and y
 * from MS_TILE_SIZE (t / tiles_x), clipped to the frame. A job is used from one thread at a time (each call
 * threads itself). */
#define MS_TILE_SIZE 16
typedef struct ms_frame_job ms_frame_job;
/* Checks the options, builds the acceleration structure and sets up the methods, the shadow method once per
 * light, kept until ms_frame_job_free (what ms_render does first, with its messages). MS_OK and *job, or a status
 * as ms_render's (MS_ERR_BUDGET over the memory budget, before allocating) with *job = NULL. */
static inline ms_status ms_frame_job_create(const ms_scene *scene, const ms_render_options *opt, ms_frame_job **job,
                                            char *err, size_t errlen);
/* The number of tiles; tiles_x and tiles_y (may be NULL) get the frame's tiles per row and per column. */
MS_API int ms_frame_job_tiles(const ms_frame_job *job, int *tiles_x, int *tiles_y);
/* 1 when the method renders split frames with the whole frame's answer; 0 for a frame-level method whose
 * answer at a pixel depends on the others (hpc-scanline), which ms_frame_job_render then refuses unless given
 * the whole frame in its first call. */
MS_API int ms_frame_job_splittable(const ms_frame_job *job);
/* Primary hits, and V, S, S_spec and front for every light, of the n tiles listed (tiles NULL: all of them, n = the number of tiles) into
 * the job's frame, the stats' visible_pixels, shadow_rays, penumbra_pixels, counters and seconds (primary_s,
 * shadow_s, shadow_cpu_s, and shadow_factor_s in thread-seconds until finish) summed over calls. MS_OK, or a status with a message
 * (MS_ERR_CANCELLED when the options' progress callback cancelled: the job's frame is then incomplete). */
MS_API ms_status ms_frame_job_render(ms_frame_job *job, const int *tiles, int n, char *err, size_t errlen);
/* The frame being assembled (full size, n_lights planes; only the rendered tiles' pixels are set;
 * vis, shadow and shadow_spec unfiltered).
 * Owned by the job. A driver may write other jobs' tiles and sums of their stats into it before finish. */
MS_API ms_frame *ms_frame_job_frame(ms_frame_job *job);
/* Completes the frame (see above) and moves it to *out (ms_frame_free it); the job is left empty: free it.
 * Every tile must have been rendered here or copied in. MS_OK, or a status with a message. */
MS_API ms_status ms_frame_job_finish(ms_frame_job *job, ms_frame *out, char *err, size_t errlen);
MS_API void ms_frame_job_free(ms_frame_job *job);

/* Outputs, all or nothing. A caller that writes several outputs of one frame lists them in an ms_output
 * table: ms_outputs_check before the render refuses bad targets (two outputs to one file, a target that
 * exists and is not a regular file, an unwritable directory, a name past the filesystem's limit, a wrong
 * ending); ms_outputs_write after it writes each to a staging file beside its target and renames them
 * into place only when all were written; any failure removes the staging files, and so do SIGINT,
 * SIGTERM, SIGHUP and SIGQUIT once ms_outputs_cleanup_on_signals was called (for programs: a library
 * caller with its own signal handling need not call it). New files get 0666 less the umask. */
typedef ms_status (*ms_output_write_fn)(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
typedef struct ms_output {
    const char *flag;             /* how the caller named it, for messages ("-o", "--vis") */
    const char *path;             /* NULL: not requested */
    ms_output_write_fn write;     /* one of the writers below, or the caller's own */
    const char *const *suffixes;  /* NULL-terminated accepted endings (case-insensitive), or NULL: any */
} ms_output;
#define MS_MAX_OUTPUTS 64   /* a paged lightmap writes each output once per page */
MS_API ms_status ms_outputs_check(const ms_output *outs, int n, char *err, size_t errlen);
/* Before writing anything it checks the frame (ms_frame_check_finite): a NaN or infinite value is an error
 * naming the first output's path and the pixel, and no file is written. */
MS_API ms_status ms_outputs_write(const ms_frame *f, const ms_output *outs, int n, char *err, size_t errlen);
/* 0 when every value of the frame or lightmap (rgb, each light's vis, shadow, shadow_spec; the NULL ones
 * skipped) and, with rgb, the exposure are finite; else MS_ERR_INVALID with one line "what: ... at pixel (x, y) is NaN". */
MS_API ms_status ms_frame_check_finite(const ms_frame *f, const char *what, char *err, size_t errlen);
MS_API void ms_outputs_cleanup_on_signals(void);
/* The writers: tone-mapped sRGB PNG; V resp. S as .pfm or .exr (by name; with several lights the EXR has
 * one channel per light, V0, V1, ... resp. S0, S1, ..., and the PFM light 0); the stats as JSON. */
MS_API ms_status ms_png_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
MS_API ms_status ms_vis_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
MS_API ms_status ms_shadow_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
MS_API ms_status ms_stats_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);
extern const char *const ms_float_image_suffixes[];   /* ".pfm", ".exr" */

/* A frame rendered and written to outs[0..n) (ms_outputs_check them first), all or nothing: the whole frame in
 * memory, then ms_outputs_write; or, streamed (opt->stream, docs/memory.md), band by band of MS_TILE_SIZE-row
 * tile rows, each image output (the writers above) taking a band's rows as they finish, so that memory holds
 * one band of the frame's planes instead of all of them; the PNG last, from the band's radiance spilled to an
 * unlinked scratch file beside it, once its exposure (the exact 99th percentile, from a histogram gathered as the
 * bands finish and one pass over the spill) is known. Byte for byte the same files either way. exposure_ev:
 * stops added to the PNG's automatic exposure. stats (may be NULL) gets the frame's stats. 0; MS_ERR_BUDGET,
 * MS_ERR_CANCELLED or another status when the frame failed (nothing written); MS_ERR_IO when an output failed (nothing
 * written either); each with a message. */
static inline ms_status ms_render_outputs(const ms_scene *scene, const ms_render_options *opt, double exposure_ev,
                                          const ms_output *outs, int n, ms_stats *stats, char *err, size_t errlen);

/* One output alone, all or nothing (checked, staged and renamed). */
MS_API ms_status ms_write_png(const ms_frame *f, const char *path, char *err, size_t errlen);      /* tone-mapped sRGB */
MS_API ms_status ms_write_vis(const ms_frame *f, const char *path, char *err, size_t errlen);      /* .pfm or .exr, float V */
MS_API ms_status ms_write_shadow(const ms_frame *f, const char *path, char *err, size_t errlen);   /* .pfm or .exr, float S */
MS_API ms_status ms_write_stats_json(const ms_frame *f, const char *path, char *err, size_t errlen);

/* Unshadowed irradiance at point p with unit normal n from the light, per unit emitted radiance.
 * Parallelogram: exact (polygon form factor, light clipped to the receiver's hemisphere). Disk over a
 * square (a circle, as ms_light_disk makes): exact closed form (the disk's vector irradiance from the
 * parallel and perpendicular differential-element form factors) when the whole disk is above the
 * receiver's plane; across the horizon, and for an ellipse, the polygon formula on a clipped 256-gon of
 * the same area (an approximation; error measured in tests/test_lights.c). Sphere: exact, pi (r/d)^2
 * cos theta wholly above the horizon, Snyder's closed form across it (as in Lagarde & de Rousiers,
 * "Moving Frostbite to PBR", 2014); 0 at points inside the sphere. Sun: the same cone, exact, pi sin^2 alpha
 * cos theta wholly above the horizon (theta from the sun's direction), Snyder's form across it; the same at
 * every p. */
MS_API float ms_light_irradiance(const ms_light *l, const float p[3], const float n[3]);

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

/* ---- Lightmap baking (docs/baking.md) ----
 *
 * Texel (x, y) of a size x size lightmap covers u in [x, x+1)/size and v in [y, y+1)/size of the UV set
 * baked into (row 0 at v = 0, the top of the image as glTF has it); page p of a paged lightmap is rows
 * [p size, (p+1) size) of the frame, its texel (x, y) at row p size + y. Every texel a triangle's UV image
 * touches (conservative rasterization) is carried to the triangle's surface: its centre's barycentric
 * coordinates, moved to the nearest point of the triangle when the centre lies outside (a texel several
 * triangles touch takes the one containing its centre, else the nearest), give the world position; the
 * normal (ms_lightmap.normal) is the triangle's, by its winding (cross(b - a, c - a)). V and S there come
 * from ms_visibility_points with the triangle as receiver and the texel as pattern key; the irradiance is
 * E_unshadowed * S * emission (ms_light_irradiance), E_unshadowed's cosine taken with the shading normal as
 * frames shade (the vertex normals interpolated, turned to the winding's side; the triangle's where the mesh
 * has none), so that smooth surfaces bake smooth. Texels no triangle touches are filled by dilation
 * from their neighbours (across chart seams) so that bilinear lookups do not bleed black. Then the seams
 * are stitched (unless no_seam_stitch): along every UV seam of a smooth edge the texels that bilinear
 * lookups from its two sides read are moved, by least squares, until both sides' lookups agree (the
 * irradiance and every light's S; V stays as baked); no other texel changes (docs/baking.md, "Seams"). */
/* Called at the end of each pass of a bake, from the calling thread, with its name ("UVs", "texels", "leak
 * test", "acceleration structure", "light 1/3", ..., "irradiance and dilation", "seam stitching", "seams") and its seconds: one
 * progress line per pass for a command line (the points' progress callback goes on within the lights). */
typedef void (*ms_bake_pass_fn)(void *user, const char *pass, double seconds);
typedef struct ms_bake_options {
    ms_points_options points;  /* method, pattern, samples, threads, seed, isa, progress; zero: defaults */
    int size;                  /* texels per side; 0: 1024 (at most MS_MAX_IMAGE_SIZE) */
    int uv_set;                /* the UV set tried first (0 .. MS_MAX_UV_SETS-1): per object, the first of
                                * this set and then the others in order that is a valid layout (on every
                                * triangle, with area, no overlap) is kept in a region of its own; objects
                                * without one are charted by xatlas (docs/baking.md, "Charts"); -1: xatlas
                                * for every triangle */
    int dilate;                /* texels of dilation; 0: 4; -1: none */
    int padding;               /* texels between charts (xatlas's and the lightmap's regions); 0: 4 */
    int no_leak_fix;           /* 1: texels inside geometry keep their points (docs/baking.md, "Quality"); 0: moved */
    ms_bake_pass_fn pass;      /* may be NULL */
    void *pass_user;
    int no_seam_stitch;        /* 1: the seams keep the baked texels; 0: stitched (docs/baking.md, "Seams") */
    float texel_density;       /* texels per world unit (times each mesh's "lightmap" scale) on as many size x size
                                * pages as it takes (ms_lightmap.pages); 0: everything on one page, at the
                                * largest density that fits */
    const char *uv_cache;      /* a UV cache file (ms_bake_write_uv_cache) to take the UVs from when it was
                                * made for this scene's geometry and these UV options (no unwrap); one that
                                * was not is not used, with a warning; a missing file is not an error. NULL:
                                * none (docs/baking.md, "The unwrap cache") */
} ms_bake_options;

typedef struct ms_lightmap {
    /* width = size, height = size * pages (one page: a square; "Pages" below); rgb: irradiance E (not
     * radiance, summed over the lights), vis and shadow V
     * and S per light (-1 where neither a triangle nor dilation reached), front: the texel's front samples
     * per light (0 off the triangles);
     * exposure and stats as for frames (visible_pixels: texels on triangles). The ms_output writers and
     * ms_exr_write_stream take &lightmap.frame. */
    ms_frame frame;
    float *position, *normal;  /* 3 floats per texel: where it was evaluated, in the scene's frame (world =
                                * position + ms_scene.origin); NaN off the triangles */
    uint32_t *triangle;        /* per texel: the scene triangle, MS_NO_TRIANGLE off the triangles */
    float *uv;                 /* 6 floats per scene triangle: the UVs baked into, in [0,1]^2; NaN if none */
    size_t n_tris;
    size_t texels;             /* texels on triangles */
    size_t unwrapped_tris;     /* triangles whose UVs xatlas made */
    double unwrap_s, raster_s; /* seconds in xatlas and in the texel rasterization */
    size_t texels_moved;       /* texels whose centre lay inside geometry, moved to the visible side */
    double leak_s;             /* seconds finding them */
    /* Chart seams (ms_bake_finish), after any stitching: where two triangles share an edge in space but not
     * in UVs on a smooth surface (their shading normals the same at both ends, or without shading normals
     * their planes within 8 degrees: across a crease the sides differ by right), the lightmap sampled
     * bilinearly on both sides at 2 points per texel of the edge; the difference of the irradiance's
     * largest channel relative to the lightmap's largest value, mean and max over the points, and their
     * number; seam_p99 their 99th percentile. */
    double seam_mean, seam_max;
    size_t seam_points;
    double seam_p99;
    size_t stitched_texels;    /* texels the seam stitching changed (0 with no_seam_stitch) */
    double stitch_s;           /* seconds stitching */
    /* Triangles left out of the lightmap (ms_bake_layout): excluded_tris of meshes with "lightmap": false (as
     * asked: reported, not warned about); unbaked_tris for any other reason - no area, no UVs (xatlas leaves out
     * triangles of area at most FLT_EPSILON once the scene's extent is scaled to about 1024 units), UVs without area or outside the lightmap - each reason a warning
     * with its count (ms_set_warning_handler). The glb names their primitives and materials after the reason. */
    size_t excluded_tris, unbaked_tris;
    /* Pages (docs/baking.md, "Texel density and pages"): the frame holds them stacked, width size, height
     * size * pages, page p in rows [p * size, (p + 1) * size); uv is in [0,1]^2 of the triangle's page. */
    int pages;
    uint32_t *page;            /* per scene triangle: its page */
    double *page_fill;         /* per page: the fraction of its texels whose centre lies on a triangle */
    /* Per object (ms_scene.tri_object; else per mesh): the UV set its layout was kept from (-1: xatlas
     * charted it, -2: not baked) and, for a kept layout, its scale and offset (uv = file uv * (su, sv) +
     * (ou, ov), 4 floats: su, sv, ou, ov; 0 for xatlas's). */
    size_t n_objects;
    int *object_uv_set;
    float *object_scale_offset;
    size_t charts;             /* charts xatlas made (0: none, or the UVs came from the cache) */
    int uv_cached;             /* 1: the UVs came from ms_bake_options.uv_cache, nothing was unwrapped */
    uint64_t uv_key;           /* the hash of what the UVs depend on (geometry, UV sets, scales, UV options) */
} ms_lightmap;

/* Bakes the scene's lights into a lightmap: V, S and front per light (frame.n_lights planes, light l at
 * vis + l*size*size, as frames hold them), the irradiance summed over the lights. accel: the scene's
 * (ms_accel_build), or NULL to build one here. MS_OK, or an error with out zeroed. */
static inline ms_status ms_bake(const ms_scene *scene, const ms_accel *accel, const ms_bake_options *opt, ms_lightmap *out,
                                char *err, size_t errlen);
MS_API void ms_lightmap_free(ms_lightmap *lm);

/* A lightmap row by row, for drivers that spread a bake over processes (the CLI's MPI mode): ms_bake is
 * ms_bake_layout, ms_bake_rows over every row, ms_bake_finish. A driver may bake any rows in any number of
 * calls in several lightmaps laid out from the same scene and options, copy the baked rows' vis, shadow and
 * front into one, and finish that one: the same lightmap bit for bit (each texel's V and S depend only on
 * the texel, its point and the seed; the irradiance, exposure and dilation, which look across rows, are
 * finish's). */
/* The options' checks, the UVs (xatlas where needed) and the texels' points: out->position, normal,
 * triangle, texels, and frame's arrays (vis, shadow -1 until baked). MS_OK, or an error with out zeroed. */
static inline ms_status ms_bake_layout(const ms_scene *scene, const ms_bake_options *opt, ms_lightmap *out, char *err,
                                       size_t errlen);
/* V, S and front of the texels of rows [y0, y1) for every light of the accel (ms_visibility_points with
 * the texel keys, one call per light), their stats added to lm->frame.stats. lm is left as it was on an
 * error. */
MS_API ms_status ms_bake_rows(const ms_accel *accel, const ms_bake_options *opt, ms_lightmap *lm, int y0, int y1, char *err,
                       size_t errlen);
/* Irradiance (rgb), exposure and dilation over the whole lightmap, once every row was baked; the stats'
 * image fields; total_s: the sum of the parts' seconds. */
MS_API ms_status ms_bake_finish(const ms_scene *scene, const ms_bake_options *opt, ms_lightmap *lm, char *err, size_t errlen);

/* The UV cache of a bake (docs/baking.md, "The unwrap cache"): lm's key, UVs, pages and per-object sets and
 * scale-offsets, which a later bake of the same geometry with the same UV options (lights, samples and
 * methods may differ) reads through ms_bake_options.uv_cache instead of unwrapping. An ms_output-style
 * writer; name is for messages. */
static inline ms_status ms_bake_write_uv_cache(const ms_lightmap *lm, FILE *out, const char *name, char *err, size_t errlen);

/* One EXR of a frame or lightmap: 32-bit float channels R, G, B (rgb: radiance of frames, irradiance
 * of lightmaps), V and S; with several lights S0, S1, ... and V0, V1, ... (one per light) instead of S
 * and V. An ms_output_write_fn; ends in .exr. */
MS_API ms_status ms_exr_write_stream(const ms_frame *f, FILE *out, const char *name, char *err, size_t errlen);

/* ---- The bake back onto the asset: a binary glTF 2.0 (docs/baking.md, "Back onto the asset") ----
 *
 * The scene's triangles as they were baked, in one .glb: node transforms applied (the loaders flatten every
 * node tree into world positions, so each object is one node with the identity transform,
 * under a root node that carries ms_scene.origin as its translation when it is not zero: positions stay in
 * the scene's frame, as exact as the scene holds them). One glTF node and mesh per object (ms_scene.tri_object:
 * a glTF node's mesh, a file of another format; else per scene-file mesh), one primitive per material in it;
 * vertices welded per primitive where position, normal and both UV sets agree bit for bit (a chart seam or a
 * crease keeps two vertices). Attributes: POSITION, NORMAL (the shading normals where the scene has them,
 * else the triangle's), TEXCOORD_0 (UV set 0 where the primitive has it, else a copy of TEXCOORD_1: glTF
 * numbers the sets densely) and TEXCOORD_1 = the UVs the lightmap was baked into (ms_lightmap.uv), and TANGENT where the
 * material carries a normal texture (the scene's tangents, MikkTSpace's where the asset has none); triangles without
 * baked UVs (a mesh left out of the bake, triangles xatlas left out) form their own primitive without TEXCOORD_1 and
 * without the lightmap, its extras {"name": "not baked: REASON", "triangles": n} and its material's name saying
 * why. The scene's extras.microshadow {exposure, exposure_diffuse}: the automatic exposures of microshadow's frame
 * of the scene's camera (ms_render_options.shading standard, diffuse), for a viewer's default. Materials carry
 * the scene's base colour, metallic, roughness, emission and alpha mode, and their base-colour, normal,
 * emissive and metallic-roughness textures (the decoded texels re-encoded as PNG: no file is read) where
 * those use UV set 0. Every baked material references:
 *   - the lightmap, extension MOZ_lightmap {index, texCoord: 1, intensity}: the irradiance summed over the
 *     lights (ms_lightmap.frame.rgb), linear (no sRGB curve), divided by its largest value I over the texels
 *     and channels, as an 8-bit RGB PNG; intensity = I restores it (E = texel / 255 * I, within half a step,
 *     I / 510). Texels neither a triangle nor dilation reached are 0;
 *   - the shadowmask in extras.shadowmask {index, texCoord: 1, channels: [{channel, light, shape}]}: S of
 *     lights 0..3 in R, G, B, A of an 8-bit RGBA PNG (linear, S = byte / 255; unused channels 0, alpha 255
 *     when fewer than 4 lights), a warning naming the lights left out beyond 4.
 * Zero-area triangles (no normal) are left out with a warning. */
typedef struct ms_bake_gltf_options {
    int no_textures;     /* 1: materials keep their factors, no embedded material textures */
    int no_shadowmask;   /* 1: no shadowmask image */
} ms_bake_gltf_options;
/* The .glb of scene and its lightmap lm (ms_bake of that scene) into a malloc'ed buffer *glb of *len bytes
 * (free it). opt may be NULL. MS_OK, or an error with *glb = NULL. */
static inline ms_status ms_bake_gltf(const ms_scene *scene, const ms_lightmap *lm, const ms_bake_gltf_options *opt,
                                     unsigned char **glb, size_t *len, char *err, size_t errlen);
/* The same written to path (ending in .glb), all or nothing (staged beside it and renamed: ms_outputs_write). */
static inline ms_status ms_bake_write_gltf(const ms_scene *scene, const ms_lightmap *lm, const ms_bake_gltf_options *opt,
                                           const char *path, char *err, size_t errlen);

/* ---- The ABI check ----
 *
 * Each checked entry point above (ms_scene_load, ms_scene_load_ex, ms_scene_default, ms_scene_showcase,
 * ms_render, ms_render_outputs, ms_frame_job_create, ms_accel_build, ms_visibility_points, ms_bake,
 * ms_bake_layout, ms_bake_gltf, ms_bake_write_gltf, ms_bake_write_uv_cache) is an inline function that hands the library the size of
 * every public struct as the program was compiled (ms_abi_compiled), and the library compares them with its own
 * before it reads or writes any: a program built against another microshadow header - a static library or a
 * shared one from another version, a binding's mirror gone stale - gets MS_ERR_INVALID and one line naming the
 * first struct that differs, never a struct read or written at the wrong size. Fields are only appended to the
 * structs, so a later version can accept an older program's smaller structs; before 1.0 it does not (the
 * soname changes with every minor version). Bindings that mirror the structs call the *_abi functions with
 * their mirrors' sizes (0 for a struct they do not mirror: not compared). */
typedef struct ms_abi {
    uint32_t abi_size;                      /* sizeof(ms_abi): the fields that follow that the caller knows */
    uint32_t version_major, version_minor;  /* MS_VERSION_MAJOR, MS_VERSION_MINOR; 0, 0: not compared */
    uint32_t camera, light, procedural, scene, texture, texture_sampling, material, scene_load_options,
             render_options, stats, frame, output, points, points_options, bake_options, lightmap,
             bake_gltf_options;
} ms_abi;

static inline const ms_abi *ms_abi_compiled(void)
{
    static const ms_abi abi = {
        (uint32_t)sizeof(ms_abi), MS_VERSION_MAJOR, MS_VERSION_MINOR, (uint32_t)sizeof(ms_camera),
        (uint32_t)sizeof(ms_light), (uint32_t)sizeof(ms_procedural), (uint32_t)sizeof(ms_scene),
        (uint32_t)sizeof(ms_texture), (uint32_t)sizeof(ms_texture_sampling), (uint32_t)sizeof(ms_material),
        (uint32_t)sizeof(ms_scene_load_options), (uint32_t)sizeof(ms_render_options), (uint32_t)sizeof(ms_stats),
        (uint32_t)sizeof(ms_frame), (uint32_t)sizeof(ms_output), (uint32_t)sizeof(ms_points),
        (uint32_t)sizeof(ms_points_options), (uint32_t)sizeof(ms_bake_options), (uint32_t)sizeof(ms_lightmap),
        (uint32_t)sizeof(ms_bake_gltf_options)
    };
    return &abi;
}

/* The exported forms of the checked entry points: abi first, then the arguments documented above
 * (ms_scene_load is ms_scene_load_abi with opt NULL). */
MS_API ms_status ms_scene_load_abi(const ms_abi *abi, const char *json_path, const ms_scene_load_options *opt,
                                   ms_scene *out, char *err, size_t errlen);
MS_API ms_status ms_scene_default_abi(const ms_abi *abi, ms_scene *out);
MS_API ms_status ms_scene_showcase_abi(const ms_abi *abi, ms_scene *out);
MS_API ms_status ms_render_abi(const ms_abi *abi, const ms_scene *scene, const ms_render_options *opt, ms_frame *out,
                               char *err, size_t errlen);
MS_API ms_status ms_render_outputs_abi(const ms_abi *abi, const ms_scene *scene, const ms_render_options *opt,
                                       double exposure_ev, const ms_output *outs, int n, ms_stats *stats, char *err,
                                       size_t errlen);
MS_API ms_status ms_frame_job_create_abi(const ms_abi *abi, const ms_scene *scene, const ms_render_options *opt,
                                         ms_frame_job **job, char *err, size_t errlen);
MS_API ms_status ms_accel_build_abi(const ms_abi *abi, const ms_scene *scene, int threads, ms_accel **out, char *err,
                                    size_t errlen);
MS_API ms_status ms_visibility_points_abi(const ms_abi *abi, const ms_accel *a, const ms_light *light,
                                          const ms_points *pts, const ms_points_options *opt, float *vis,
                                          float *shadow, uint16_t *front, ms_stats *stats, char *err, size_t errlen);
MS_API ms_status ms_bake_abi(const ms_abi *abi, const ms_scene *scene, const ms_accel *accel, const ms_bake_options *opt,
                             ms_lightmap *out, char *err, size_t errlen);
MS_API ms_status ms_bake_layout_abi(const ms_abi *abi, const ms_scene *scene, const ms_bake_options *opt,
                                    ms_lightmap *out, char *err, size_t errlen);
MS_API ms_status ms_bake_write_uv_cache_abi(const ms_abi *abi, const ms_lightmap *lm, FILE *out, const char *name, char *err,
                                            size_t errlen);
MS_API ms_status ms_bake_gltf_abi(const ms_abi *abi, const ms_scene *scene, const ms_lightmap *lm,
                                  const ms_bake_gltf_options *opt, unsigned char **glb, size_t *len, char *err,
                                  size_t errlen);
MS_API ms_status ms_bake_write_gltf_abi(const ms_abi *abi, const ms_scene *scene, const ms_lightmap *lm,
                                        const ms_bake_gltf_options *opt, const char *path, char *err, size_t errlen);

static inline ms_status ms_scene_load(const char *json_path, ms_scene *out, char *err, size_t errlen)
{ return ms_scene_load_abi(ms_abi_compiled(), json_path, NULL, out, err, errlen); }
static inline ms_status ms_scene_load_ex(const char *json_path, const ms_scene_load_options *opt, ms_scene *out, char *err,
                                         size_t errlen)
{ return ms_scene_load_abi(ms_abi_compiled(), json_path, opt, out, err, errlen); }
static inline ms_status ms_scene_default(ms_scene *out) { return ms_scene_default_abi(ms_abi_compiled(), out); }
static inline ms_status ms_scene_showcase(ms_scene *out) { return ms_scene_showcase_abi(ms_abi_compiled(), out); }
static inline ms_status ms_render(const ms_scene *scene, const ms_render_options *opt, ms_frame *out, char *err,
                                  size_t errlen)
{ return ms_render_abi(ms_abi_compiled(), scene, opt, out, err, errlen); }
static inline ms_status ms_render_outputs(const ms_scene *scene, const ms_render_options *opt, double exposure_ev,
                                          const ms_output *outs, int n, ms_stats *stats, char *err, size_t errlen)
{ return ms_render_outputs_abi(ms_abi_compiled(), scene, opt, exposure_ev, outs, n, stats, err, errlen); }
static inline ms_status ms_frame_job_create(const ms_scene *scene, const ms_render_options *opt, ms_frame_job **job,
                                            char *err, size_t errlen)
{ return ms_frame_job_create_abi(ms_abi_compiled(), scene, opt, job, err, errlen); }
static inline ms_status ms_accel_build(const ms_scene *scene, int threads, ms_accel **out, char *err, size_t errlen)
{ return ms_accel_build_abi(ms_abi_compiled(), scene, threads, out, err, errlen); }
static inline ms_status ms_visibility_points(const ms_accel *a, const ms_light *light, const ms_points *pts,
                                             const ms_points_options *opt, float *vis, float *shadow, uint16_t *front,
                                             ms_stats *stats, char *err, size_t errlen)
{ return ms_visibility_points_abi(ms_abi_compiled(), a, light, pts, opt, vis, shadow, front, stats, err, errlen); }
static inline ms_status ms_bake(const ms_scene *scene, const ms_accel *accel, const ms_bake_options *opt, ms_lightmap *out,
                                char *err, size_t errlen)
{ return ms_bake_abi(ms_abi_compiled(), scene, accel, opt, out, err, errlen); }
static inline ms_status ms_bake_layout(const ms_scene *scene, const ms_bake_options *opt, ms_lightmap *out, char *err,
                                       size_t errlen)
{ return ms_bake_layout_abi(ms_abi_compiled(), scene, opt, out, err, errlen); }
static inline ms_status ms_bake_write_uv_cache(const ms_lightmap *lm, FILE *out, const char *name, char *err, size_t errlen)
{ return ms_bake_write_uv_cache_abi(ms_abi_compiled(), lm, out, name, err, errlen); }
static inline ms_status ms_bake_gltf(const ms_scene *scene, const ms_lightmap *lm, const ms_bake_gltf_options *opt,
                                     unsigned char **glb, size_t *len, char *err, size_t errlen)
{ return ms_bake_gltf_abi(ms_abi_compiled(), scene, lm, opt, glb, len, err, errlen); }
static inline ms_status ms_bake_write_gltf(const ms_scene *scene, const ms_lightmap *lm, const ms_bake_gltf_options *opt,
                                           const char *path, char *err, size_t errlen)
{ return ms_bake_write_gltf_abi(ms_abi_compiled(), scene, lm, opt, path, err, errlen); }

#ifdef __cplusplus
}
#endif
#endif
