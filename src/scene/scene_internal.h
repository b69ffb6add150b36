#ifndef MS_SCENE_INTERNAL_H
#define MS_SCENE_INTERNAL_H
#include <stddef.h>
#include <stdint.h>

#define MS_DEFAULT_EMISSION 1.0f

/* Input limits (docs/design.md, "Hostile input"): every loader's memory and work is a fixed multiple
 * of the bytes it was given. */
#define MS_MAX_SCENE_BYTES ((size_t)16 << 20)     /* a scene file is a few hundred bytes of JSON */
#define MS_MAX_MESH_BYTES ((size_t)2 << 30)       /* per mesh file, and per glTF buffer */
#define MS_MAX_POLYGON 256                        /* vertices per face: triangulation is quadratic */
#define MS_MAX_TRIS_PER_BYTE 4                    /* triangles emitted per input byte (glTF instancing) */
#define MS_MAX_LIGHT_TEXTURE 8192                 /* texels per side of a light's emission image */
#define MS_MAX_COORD 1e18f                        /* |coordinate|: squares and cross products stay finite in float */
#define MS_MAX_LIGHTS 64                          /* a frame holds V and S per light: bounded memory */

struct ms_scene;
/* A glTF KHR_lights_punctual light where the file puts it (mesh_gltf.c; world coordinates, the scene file's
 * mesh transform applied by scene_json.c), made a light by scene_punctual.c. */
enum { MS_PUNCTUAL_POINT = 0, MS_PUNCTUAL_SPOT = 1, MS_PUNCTUAL_DIRECTIONAL = 2 };
typedef struct ms_punctual {
    int type;
    float color[3], intensity;   /* linear RGB; candela (point, spot) or lux (directional) */
    double pos[3], dir[3];       /* the node's origin and its -Z axis (unit) */
    float radius;                /* extras.radius; 0: not given */
    float angular_deg;           /* directional: extras.angular_diameter_deg; 0: not given */
    uint32_t mesh;               /* the scene file's mesh entry */
} ms_punctual;
/* A glTF file's first camera (in the order nodes are walked), in world coordinates: what an asset given as the
 * scene (scene_asset.c) looks through. */
typedef struct ms_asset_camera {
    int present, ortho;
    double eye[3], dir[3], up[3];   /* the node's origin, its -Z and +Y axes (unit) */
    float yfov_deg, aspect;         /* perspective: its vertical field of view; aspect ratio (0: not given) */
    float ymag;                     /* orthographic: half the view's height */
} ms_asset_camera;
/* rel resolved against the folder of json_path (absolute paths as they are) into out; -1 if too long. */
int ms_path_beside(const char *json_path, const char *rel, char *out, size_t n);
struct ms_light;
/* The punctual lights p[0 .. n-1] as area lights in the scene's frame (scene_punctual.c): *out (malloc'd,
 * NULL when none) and *n_out; radius default_radius where the light gives none; what is approximated or
 * left out is told through warn; 0, or -1 with one line in err (naming path) when more than `room`. */
int ms_scene_punctual_lights(const ms_punctual *p, size_t n, const double origin[3], double default_radius, size_t room,
                             const char *path, void (*warn)(const char *line), struct ms_light **out, size_t *n_out,
                             char *err, size_t errlen);
/* Which emitting materials become lights (scene file "lights_from_emissive": true or a list of names):
 * lit[m] for material m (NULL: every one); names[m] the materials' names for messages (NULL: none kept,
 * or NULL entries). */
typedef struct ms_emitter_choice {
    const unsigned char *lit;
    char *const *names;
} ms_emitter_choice;
/* How many of the scene's triangles emit and are chosen (those ms_scene_emitter_lights makes lights of;
 * choice NULL: every emissive triangle). */
size_t ms_scene_emissive_triangles(const struct ms_scene *s, const ms_emitter_choice *choice);
/* The scene's emitting materials as text for a message, e.g. "light.000: 10 triangles, material 4: 2 triangles",
 * the most triangles first, at most six named ("and 3 more"). */
void ms_scene_emissive_materials_text(const struct ms_scene *s, char *const *names, char *buf, size_t n);
/* The lights of the scene's chosen emissive triangles (scene_emitters.c): *out (malloc'd, NULL when none)
 * and *n_out; 0, or -1 with one line in err (naming path and the emitting materials) when they would be
 * more than `room` lights. */
int ms_scene_emitter_lights(const struct ms_scene *s, const ms_emitter_choice *choice, size_t room, const char *path,
                            struct ms_light **out, size_t *n_out, char *err, size_t errlen);
#define MS_SOUP_UV_SETS 4   /* = MS_MAX_UV_SETS */
/* Triangles as they are loaded, with the mesh each came from (cur_mesh at the push) and, per UV set,
 * the UVs of its vertices (6 floats; the array appears with the first triangle that has the set, NaN
 * for those before and for triangles without it). */
typedef struct ms_tri_soup {
    float *tri;
    /* The same positions in double (9 per triangle), as exact as the file gives them: the scene's local frame
     * (scene_frame.c) is subtracted from these before they are rounded to float, so that a model far from
     * the origin keeps its detail. tri holds what the loaders always produced, used as it is when the
     * frame is the identity (images of scenes near the origin unchanged bit for bit). */
    double *tri_d;
    size_t n, cap;
    uint32_t *mesh;
    float *uv[MS_SOUP_UV_SETS];
    uint32_t cur_mesh;
    /* The object each triangle came from (cur_object at the push): a glTF node's mesh, or a whole file of
     * another format; numbered across the scene (ms_scene.tri_object). ms_soup_new_object starts one. */
    uint32_t *object;
    uint32_t cur_object, n_objects;
    int object_used;   /* cur_object has triangles */
    /* Surfaces (material.c): per-triangle material index (MS_NO_MATERIAL) and vertex normals (9 floats,
     * NaN), each appearing with the first triangle that has one; the materials and textures loaded. */
    uint32_t *material;
    float *normal;
    struct ms_material *mats;
    size_t n_mats;
    /* The materials' names as the files give them (glTF material name, MTL newmtl), NULL for none: only
     * for choosing the asset's emitters by name (scene file "lights_from_emissive": [...]); not handed to
     * the scene (ms_soup_free_names). */
    char **mat_names;
    struct ms_texture *tex;
    size_t n_tex;
    size_t tex_bytes;   /* decoded texture bytes so far (bounded: MS_MAX_TEXTURE_BYTES) */
    /* Normal-map tangents (tangent.c): 12 floats per triangle (x, y, z, w per vertex) for triangles
     * [0, tangent_n), NaN where none; NULL until a primitive has them. */
    float *tangent;
    size_t tangent_n;
    int allow_outside_paths;   /* files named by the meshes may lie outside their folders (ms_resolve_inside) */
    ms_punctual *punctual;     /* glTF KHR_lights_punctual lights (ms_soup_free frees them) */
    size_t n_punctual;
    ms_asset_camera camera;    /* a glTF file's first camera */
} ms_tri_soup;
/* Tangents t12 (12 floats per triangle) of triangles [first, first + count); 0, or -1 out of memory. */
int ms_soup_set_tangents(ms_tri_soup *soup, size_t first, size_t count, const float *t12);
/* MikkTSpace tangents of triangles [first, first + count) from their positions, normals (face normals where
 * none) and UV set `set` (nothing when the set is absent or the input is not finite); 0, or -1 out of memory. */
int ms_soup_mikktspace(ms_tri_soup *soup, size_t first, size_t count, int set);
/* The tangent array for all soup->n triangles (NaN-filled past the last set), handed over (NULL: none). */
float *ms_soup_take_tangents(ms_tri_soup *soup);
void ms_soup_free(ms_tri_soup *soup);
/* Starts a new object for the triangles pushed from now on (the current one goes on while it has none). */
void ms_soup_new_object(ms_tri_soup *soup);
/* The same push with a material index (MS_NO_MATERIAL: none) and three vertex normals (or NULL). */
int ms_soup_push_full(ms_tri_soup *soup, const float v[9], const float *const uv[MS_SOUP_UV_SETS],
                      uint32_t material, const float *normal9);
/* The same with the positions also in double (vd, 9; NULL: v widened), for tri_d. */
int ms_soup_push_d(ms_tri_soup *soup, const float v[9], const double *vd, const float *const uv[MS_SOUP_UV_SETS],
                   uint32_t material, const float *normal9);

/* The scene's local frame (scene_frame.c, docs/design.md "The scene's frame"): the origin chosen from the
 * bounds of the n triangles' double positions tri_d (all zero when the scene lies about the origin), and
 * the positions tri moved into it: tri = (float)(tri_d - origin) when the origin is not zero. */
void ms_scene_frame_origin(const double *tri_d, size_t n, double origin[3]);
void ms_scene_frame_apply(float *tri, const double *tri_d, size_t n, const double origin[3]);
/* A world position (double) in the frame: out = (float)(p - origin), each coordinate. */
void ms_scene_frame_point(const double p[3], const double origin[3], float out[3]);
/* Appends a material and its name (NULL: none; copied); its index, or -1 when out of memory or past
 * MS_MAX_MATERIALS. */
long ms_soup_add_material(ms_tri_soup *soup, const struct ms_material *m, const char *name);
/* Frees the materials' names (also done by ms_soup_free). */
void ms_soup_free_names(ms_tri_soup *soup);

/* Textures (texture.c). At most MS_MAX_TEXTURE_SIDE texels a side, MS_MAX_TEXTURE_BYTES decoded per scene. */
#define MS_MAX_TEXTURE_SIDE 16384
#define MS_MAX_TEXTURE_BYTES ((size_t)1 << 30)
#define MS_MAX_MATERIALS 65536
/* Decodes a PNG, JPEG or KTX2 image (texture.c) from memory into RGBA8 (colour as the file encodes it,
 * sRGB for colour textures), at most MS_MAX_TEXTURE_SIDE a side and `budget` bytes decoded; 0, or -1 with
 * one line in err naming `what` (out->rgba NULL). */
struct ms_texture;
int ms_texture_decode(const unsigned char *buf, size_t len, const char *what, int flip_rows, size_t budget,
                      struct ms_texture *out, char *err, size_t errlen);
/* The same decode appended to the soup as a texture; its index, or -1 with one line in err naming `what`. flip_rows: store the rows bottom-up (OBJ's v = 0 is
 * the image's last row; textures follow glTF, v = 0 the first). Loaders treat a texture that fails as a
 * warning, the material keeping its factors: a scene whose textures are missing or undecodable still loads. */
/* The size check every decoder makes before allocating: at most MS_MAX_TEXTURE_SIDE a side and w x h RGBA8
 * within `budget`; 1, or 0 with one line in err naming `what`. */
int ms_texture_size_ok(unsigned w, unsigned h, size_t budget, const char *what, char *err, size_t errlen);
/* A KTX2 file (texture_ktx2.c): level 0 of an 8-bit uncompressed format, stored plain or Zstandard-
 * supercompressed; anything else refused with one line naming what it is. As ms_texture_decode. */
int ms_texture_decode_ktx2(const unsigned char *buf, size_t len, const char *what, int flip_rows, size_t budget,
                           struct ms_texture *out, char *err, size_t errlen);
long ms_soup_add_texture_memory(ms_tri_soup *soup, const unsigned char *buf, size_t len, const char *what,
                                int flip_rows, char *err, size_t errlen);
/* The same from a file (a regular file of at most MS_MAX_MESH_BYTES). */
long ms_soup_add_texture_file(ms_tri_soup *soup, const char *path, int flip_rows, char *err, size_t errlen);

/* OBJ materials (mtl.c): the materials of MTL files, by name, added to the soup as they are read. */
typedef struct ms_mtl_lib {
    char **names;
    uint32_t *index;   /* soup material of names[i] */
    size_t n;
    char **tex_path;   /* textures read so far, each once: soup texture tex_id[i] (-1: unusable) */
    long *tex_id;
    size_t n_tex;
} ms_mtl_lib;
/* Reads the MTL file `ref` that the mesh file `owner` names (an OBJ's mtllib argument, relative to its folder)
 * - newmtl, Kd, d, map_Kd, Pr, Pm, Ns - into lib and the soup. ref and its maps must stay inside their
 * folders unless soup->allow_outside_paths (ms_resolve_inside). A file that cannot be read and a texture that
 * cannot be used are warnings; 0, or -1 with one line in err (a path leading outside, out of memory). */
int ms_mtl_load(const char *owner, const char *ref, ms_tri_soup *soup, ms_mtl_lib *lib, char *err, size_t errlen);
/* The same from the bytes of MTL file `path` (buf[len] == 0; the lines are cut in place): the fuzzers' entry. */
int ms_mtl_load_memory(char *buf, size_t len, const char *path, ms_tri_soup *soup, ms_mtl_lib *lib, char *err,
                       size_t errlen);
/* The soup material named `name`, or MS_NO_MATERIAL. The last definition of a name wins. */
uint32_t ms_mtl_find(const ms_mtl_lib *lib, const char *name);
void ms_mtl_lib_free(ms_mtl_lib *lib);

/* MS_INPUT_AUX: a file a mesh refers to (an MTL file, a texture), named "file" in messages;
 * MS_INPUT_TEXTURE: a light's emission image, named "texture file". */
typedef enum ms_input_kind { MS_INPUT_SCENE, MS_INPUT_MESH, MS_INPUT_AUX, MS_INPUT_TEXTURE } ms_input_kind;
/* Reads a whole regular file of at most max_bytes (a FIFO, device or directory is refused without
 * blocking) into a malloc'ed, NUL-terminated buffer. */
int ms_read_input(const char *path, size_t max_bytes, ms_input_kind kind, char **out, size_t *len, char *err,
                  size_t errlen);
/* A path named by a file (a glTF buffer or image URI, percent-decoded; an OBJ's mtllib; an MTL map), resolved
 * against the folder of that file, `owner`, into out[n]. Unless allow (the scene's "allow_outside_paths",
 * ms_scene_load_options), refused with one line naming owner, `what` ("mtllib", "buffer 0 uri") and ref:
 * an absolute ref, `..` components climbing out of the folder, or a file that resolves (symbolic links
 * followed, realpath) outside the folder's own resolved path. 0, or -1. */
int ms_resolve_inside(const char *owner, const char *ref, int allow, const char *what, char *out, size_t n, char *err,
                      size_t errlen);

/* Appends the triangles of a mesh file (OBJ, PLY, OFF, STL through microshadow's own readers;
 * glTF 2.0 through cgltf), triangulated, node transforms applied. Fails with one line naming the file. */
int ms_mesh_load(const char *path, ms_tri_soup *soup, char *err, size_t errlen);
/* The same from bytes already in memory (the fuzzers' entry point). `ext` is the lower-case extension
 * without the dot; `path` names the file in messages and locates a glTF's external buffers. */
int ms_mesh_load_memory(const char *buf, size_t len, const char *ext, const char *path, ms_tri_soup *soup,
                        char *err, size_t errlen);
int ms_soup_push(ms_tri_soup *soup, const float v[9]);
/* The same with UVs: uv[s] is 6 floats (three vertices' u, v) or NULL when the triangle lacks set s. */
int ms_soup_push_uv(ms_tri_soup *soup, const float v[9], const float *const uv[MS_SOUP_UV_SETS]);

/* glTF 2.0 through cgltf (mesh_gltf.c); OBJ, PLY, OFF and STL: mesh_reader.h. Each appends to soup and
 * sets *added. */
int ms_mesh_gltf(const char *buf, size_t len, const char *path, ms_tri_soup *soup, size_t *added, char *err,
                 size_t errlen);

/* The scene JSON from memory (text[len] == 0); json_path names it and locates the meshes. */
int ms_scene_parse(const char *text, size_t len, const char *json_path, struct ms_scene *out, char *err,
                   size_t errlen);
/* An asset given as the scene (scene_asset.c): 1 when path ends in a mesh format's extension (.gltf, .glb, .obj,
 * .ply, .off, .stl), which ms_scene_load then reads as the scene of that one mesh. */
int ms_scene_asset_path(const char *path);
/* Such a scene's camera, the asset's own (cam, when present) or one from its triangles' box (Y up), and, when
 * add_light, its one disk light; -1 with err set when the triangles have no extent. */
int ms_scene_asset_view(struct ms_scene *s, const ms_asset_camera *cam, int add_light, const char *path, char *err,
                        size_t errlen);
/* Makes err one printable line: names taken from files may hold newlines or control characters. */
void ms_one_line(char *err);
/* Reports a warning through the handler set with ms_set_warning_handler. */
void ms_warn(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* A material file or texture that cannot be used (the geometry loads; its material keeps its factors or the
 * default). Between ms_material_warnings_begin and _end (one scene load) they are counted, and _end reports
 * them as one line: the warning itself when there was one, else their number and the first; each at once
 * when ms_set_warning_verbose is on, or outside a load. report 0: drop them (the load failed). */
void ms_warn_material(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void ms_material_warnings_begin(void);
void ms_material_warnings_end(int report);

#endif
