/* Scene files' JSON getters and key validation (scene_json_get.c), shared by scene_json.c and
 * scene_json_lights.c: the known keys per object, the unknown-key warnings, duplicate keys, and numbers and
 * vectors with their error messages. */
#ifndef MS_SCENE_JSON_GET_H
#define MS_SCENE_JSON_GET_H

#include "microshadow.h"
#include <cjson/cJSON.h>
#include <stddef.h>

/* Known keys, per object, for the unknown-key warnings. */
extern const char *const ms_json_top_keys[];
extern const char *const ms_json_procedural_keys[];
extern const char *const ms_json_render_keys[];
extern const char *const ms_json_mesh_keys[];
extern const char *const ms_json_mesh_lightmap_keys[];
/* Every camera type's keys, for "another camera type's key". */
extern const char *const ms_json_camera_keys_any[];
/* The camera types (docs/cameras.md): each reads the common keys and its own number (own; NULL: none). */
typedef struct ms_json_camera_type {
    const char *name;
    ms_camera_type type;
    const char *const *keys;
    const char *own;
} ms_json_camera_type;
extern const ms_json_camera_type ms_json_camera_types[];
extern const size_t ms_json_n_camera_types;
/* The keys of the camera being parsed (its type's), for the unknown-key warnings and typo hints. */
extern _Thread_local const char *const *ms_json_camera_keys;
/* A light's keys: "shape", every shape's own (its row's keys, light/light_shape.h, in table order), the
 * emission's and "texture" (ms_json_light_keys_fill, scene_json_lights.c). */
#define MS_JSON_LIGHT_KEYS_MAX 48
extern _Thread_local const char *ms_json_light_keys[MS_JSON_LIGHT_KEYS_MAX];

/* Warnings wait until the scene loaded: a failed load prints its one error line only. The list is set by
 * the load (scene_json.c) for the time of one parse; NULL: no warnings are kept. */
#define MS_JSON_MAX_WARNINGS 16
typedef struct ms_json_warn_list { int n; char line[MS_JSON_MAX_WARNINGS][320]; } ms_json_warn_list;
extern _Thread_local ms_json_warn_list *ms_json_warnings;
/* Adds one warning line (formatted) while there is a list with room. */
void ms_json_warn(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

int ms_json_is_known(const char *name, const char *const *known);
/* "X is missing", with the unknown key that was probably meant. */
void ms_json_missing(const cJSON *obj, const char *objname, const char *key, const char *path, char *err,
                     size_t errlen);
/* Warns about each key of obj in neither known nor also (NULL: none), naming the nearest known key. */
void ms_json_warn_unknown_except(const cJSON *obj, const char *objname, const char *const *known,
                                 const char *const *also, const char *path);
void ms_json_warn_unknown(const cJSON *obj, const char *objname, const char *const *known, const char *path);
/* Keys another camera type reads: a warning that says so, rather than "unknown". */
void ms_json_warn_camera_keys(const cJSON *cam, const char *type_name, const char *path);
/* Duplicate keys anywhere in node (where: its name, "" for the top level). */
int ms_json_check_duplicates(const cJSON *node, const char *where, const char *path, char *err, size_t errlen);
/* A number read into a float: finite, and within float range (index >= 0: an array's element). */
int ms_json_float_ok(double d, const char *objname, const char *key, int index, const char *path, char *err,
                     size_t errlen);
/* Reads key as an array of three finite numbers. */
int ms_json_vec3(const cJSON *obj, const char *objname, const char *key, int required, ms_vec3 *out,
                 const char *path, char *err, size_t errlen);
/* The double values of a vec3 that ms_json_vec3 accepted. */
void ms_json_vec3_d(const cJSON *obj, const char *key, double out[3]);
int ms_json_number(const cJSON *obj, const char *objname, const char *key, int required, double *out,
                   const char *path, char *err, size_t errlen);
int ms_json_int(const cJSON *obj, const char *objname, const char *key, int required, int lo, int hi, int *out,
                const char *path, char *err, size_t errlen);
/* root[key], an object; NULL (err set) if absent or not an object. */
const cJSON *ms_json_object(const cJSON *root, const char *key, const char *path, char *err, size_t errlen);

#endif
