/* microshadow/scene.h, a part of <microshadow.h>: cameras, procedural sources, the scene (triangle soup,
 * materials, textures, lights), warnings, loading and checking scenes. Programs include <microshadow.h>, which
 * includes every part in order; a part relies on the ones before it. */
#ifndef MICROSHADOW_SCENE_H
#define MICROSHADOW_SCENE_H
#ifndef MICROSHADOW_H
#error "include <microshadow.h>: it includes this part in its place"
#endif

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
 * unknown keys warnings. A path ending in a mesh format's extension (.gltf, .glb, .obj, .ply, .off, .stl, any
 * case) loads that asset as the scene: what a scene file naming it alone gives (its own KHR_lights_punctual
 * lights and emissive triangles as lights), with a pinhole camera looking at its bounding box's centre from
 * the front, right and above (Y up, 45 degrees, 1024 x 768) and, when it has no light of its own, one disk
 * light above it (radius 0.15 of the box's diagonal, 1.5 diagonals from the centre, radiance giving about pi
 * of irradiance there); a warning says so. */
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

#endif
