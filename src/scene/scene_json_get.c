/* Scene files' JSON getters and key validation: the known keys per object, unknown-key warnings with the
 * nearest known key, duplicate keys, and numbers and vectors with their error messages. */
#include "scene_json_get.h"
#include "scene_internal.h"
#include <cjson/cJSON.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Known keys, per object, for the unknown-key warnings. */
const char *const ms_json_top_keys[] = { "meshes", "procedural", "camera", "light", "lights", "render",
                                         "allow_outside_paths", "lights_from_emissive", "lights_from_punctual",
                                         "punctual_radius", NULL };
const char *const ms_json_procedural_keys[] = { "type", "triangles", "seed", NULL };
/* The camera's keys depend on camera.type (docs/cameras.md): each type reads the common ones and its own. */
#define CAMERA_COMMON_KEYS "type", "eye", "target", "up", "width", "height"
static const char *const camera_keys_pinhole[] = { CAMERA_COMMON_KEYS, "fov_y", NULL };
static const char *const camera_keys_ortho[] = { CAMERA_COMMON_KEYS, "ortho_height", NULL };
static const char *const camera_keys_fisheye[] = { CAMERA_COMMON_KEYS, "fov", NULL };
static const char *const camera_keys_panorama[] = { CAMERA_COMMON_KEYS, NULL };
const char *const ms_json_camera_keys_any[] = { CAMERA_COMMON_KEYS, "fov_y", "ortho_height", "fov", NULL };
const ms_json_camera_type ms_json_camera_types[] = {
    { "pinhole", MS_CAMERA_PINHOLE, camera_keys_pinhole, "fov_y" },
    { "orthographic", MS_CAMERA_ORTHOGRAPHIC, camera_keys_ortho, "ortho_height" },
    { "fisheye", MS_CAMERA_FISHEYE, camera_keys_fisheye, "fov" },
    { "latlong", MS_CAMERA_LATLONG, camera_keys_panorama, NULL },
    { "parabolic", MS_CAMERA_PARABOLIC, camera_keys_panorama, NULL },
};
const size_t ms_json_n_camera_types = sizeof ms_json_camera_types / sizeof ms_json_camera_types[0];
/* The keys of the camera being parsed (its type's, set by scene_json.c), for the warnings and typo hints. */
_Thread_local const char *const *ms_json_camera_keys = camera_keys_pinhole;
/* Filled from the light-shape table for each light parsed (scene_json_lights.c). */
_Thread_local const char *ms_json_light_keys[MS_JSON_LIGHT_KEYS_MAX] = { "shape", NULL };
const char *const ms_json_render_keys[] = { "samples", "aa", NULL };
const char *const ms_json_mesh_keys[] = { "file", "transform", "lightmap", NULL };
const char *const ms_json_mesh_lightmap_keys[] = { "scale", NULL };

/* Set by the load for the time of one parse (scene_json.c). */
_Thread_local ms_json_warn_list *ms_json_warnings;

void ms_json_warn(const char *fmt, ...)
{
    if (!ms_json_warnings || ms_json_warnings->n >= MS_JSON_MAX_WARNINGS) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ms_json_warnings->line[ms_json_warnings->n++], sizeof ms_json_warnings->line[0], fmt, ap);
    va_end(ap);
}

int ms_json_is_known(const char *name, const char *const *known)
{
    for (int k = 0; known[k]; k++)
        if (!strcmp(name, known[k])) return 1;
    return 0;
}

/* For "X is missing": the unknown key of obj that was probably meant (its nearest known key is X). */
static const char *meant_for(const cJSON *obj, const char *key, const char *const *known)
{
    const cJSON *it;
    cJSON_ArrayForEach(it, obj)
        if (!ms_json_is_known(it->string, known) && !strcmp(ms_nearest_name(it->string, known, NULL), key)) return it->string;
    return NULL;
}

static const char *const *known_for(const char *objname)
{
    return !strcmp(objname, "camera") ? ms_json_camera_keys : !strncmp(objname, "light", 5) ? ms_json_light_keys
         : !strcmp(objname, "render") ? ms_json_render_keys
         : !strcmp(objname, "procedural") ? ms_json_procedural_keys : ms_json_top_keys;
}

/* "X is missing", with the unknown key that was probably meant. */
void ms_json_missing(const cJSON *obj, const char *objname, const char *key, const char *path, char *err,
                     size_t errlen)
{
    const char *typo = meant_for(obj, key, known_for(objname));
    char hint[128] = "";
    if (typo && !strcmp(objname, "camera") && ms_json_is_known(typo, ms_json_camera_keys_any))
        snprintf(hint, sizeof hint, " (\"%.40s\" is another camera type's key)", typo);
    else if (typo) snprintf(hint, sizeof hint, " (\"%.40s\" is not a known key: a typo?)", typo);
    if (objname[0]) snprintf(err, errlen, "%s: %s.%s is missing%s", path, objname, key, hint);
    else snprintf(err, errlen, "%s: \"%s\" is missing%s", path, key, hint);
}

/* Warns about each key of obj in neither known nor also (NULL: none), naming the nearest known key. Keys
 * that begin with '_' are comments ("_comment", "_note"): JSON has no other kind, so they pass silently. */
void ms_json_warn_unknown_except(const cJSON *obj, const char *objname, const char *const *known,
                                 const char *const *also, const char *path)
{
    const cJSON *it;
    cJSON_ArrayForEach(it, obj) {
        if (it->string[0] == '_' || ms_json_is_known(it->string, known) || (also && ms_json_is_known(it->string, also))) continue;
        ms_json_warn("%.200s: unknown key \"%s%s%.40s\" ignored (the nearest known key is \"%s\")", path, objname,
                     objname[0] ? "." : "", it->string, ms_nearest_name(it->string, known, NULL));
    }
}

void ms_json_warn_unknown(const cJSON *obj, const char *objname, const char *const *known, const char *path)
{
    ms_json_warn_unknown_except(obj, objname, known, NULL, path);
}

/* Keys another camera type reads: a warning that says so, rather than "unknown". */
void ms_json_warn_camera_keys(const cJSON *cam, const char *type_name, const char *path)
{
    const cJSON *it;
    cJSON_ArrayForEach(it, cam)
        if (!ms_json_is_known(it->string, ms_json_camera_keys) && ms_json_is_known(it->string, ms_json_camera_keys_any))
            ms_json_warn("%.200s: camera.%s ignored (a %s camera does not use it)", path, it->string, type_name);
}

static int cmp_str(const void *a, const void *b) { return strcmp(*(const char *const *)a, *(const char *const *)b); }

/* Duplicate keys anywhere: cJSON keeps both and returns the first, which silently drops the second. */
int ms_json_check_duplicates(const cJSON *node, const char *where, const char *path, char *err, size_t errlen)
{
    if (!cJSON_IsObject(node) && !cJSON_IsArray(node)) return 0;
    size_t n = 0;
    const cJSON *it;
    cJSON_ArrayForEach(it, node) n++;
    if (cJSON_IsObject(node) && n > 1) {
        const char **names = malloc(n * sizeof *names);
        if (!names) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
        size_t i = 0;
        cJSON_ArrayForEach(it, node) names[i++] = it->string;
        qsort(names, n, sizeof *names, cmp_str);
        for (i = 1; i < n; i++)
            if (!strcmp(names[i - 1], names[i])) {
                snprintf(err, errlen, "%s: duplicate key \"%s%s%.64s\"", path, where, where[0] ? "." : "", names[i]);
                free(names);
                return -1;
            }
        free(names);
    }
    size_t i = 0;
    cJSON_ArrayForEach(it, node) {
        char sub[256];
        if (cJSON_IsObject(node)) snprintf(sub, sizeof sub, "%s%s%.64s", where, where[0] ? "." : "", it->string);
        else snprintf(sub, sizeof sub, "%s[%zu]", where, i);
        if (ms_json_check_duplicates(it, sub, path, err, errlen)) return -1;
        i++;
    }
    return 0;
}

/* A number read into a float: finite, and within float range (1e39 would become infinity). */
int ms_json_float_ok(double d, const char *objname, const char *key, int index, const char *path, char *err,
                     size_t errlen)
{
    if (fabs(d) <= FLT_MAX) return 0;
    if (index >= 0) snprintf(err, errlen, "%s: %s.%s[%d] = %g overflows a float (largest magnitude %g)", path, objname, key, index, d, (double)FLT_MAX);
    else snprintf(err, errlen, "%s: %s.%s = %g overflows a float (largest magnitude %g)", path, objname, key, d, (double)FLT_MAX);
    return -1;
}

/* Reads key as an array of three finite numbers. */
int ms_json_vec3(const cJSON *obj, const char *objname, const char *key, int required, ms_vec3 *out,
                 const char *path, char *err, size_t errlen)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!a) {
        if (!required) return 0;
        ms_json_missing(obj, objname, key, path, err, errlen);
        return -1;
    }
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != 3) {
        snprintf(err, errlen, "%s: %s.%s must be an array of 3 numbers", path, objname, key);
        return -1;
    }
    float v[3];
    for (int i = 0; i < 3; i++) {
        const cJSON *x = cJSON_GetArrayItem(a, i);
        if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble)) {
            snprintf(err, errlen, "%s: %s.%s must be an array of 3 finite numbers", path, objname, key);
            return -1;
        }
        if (ms_json_float_ok(x->valuedouble, objname, key, i, path, err, errlen)) return -1;
        v[i] = (float)x->valuedouble;
    }
    out->x = v[0]; out->y = v[1]; out->z = v[2];
    return 0;
}

/* The double values of a vec3 that ms_json_vec3 accepted (a position: the scene's frame is subtracted from these
 * before rounding, scene_frame.c). */
void ms_json_vec3_d(const cJSON *obj, const char *key, double out[3])
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, key);
    for (int i = 0; i < 3; i++) out[i] = a ? cJSON_GetArrayItem(a, i)->valuedouble : 0.0;
}

int ms_json_number(const cJSON *obj, const char *objname, const char *key, int required, double *out,
                   const char *path, char *err, size_t errlen)
{
    const cJSON *x = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!x) {
        if (!required) return 0;
        ms_json_missing(obj, objname, key, path, err, errlen);
        return -1;
    }
    if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble)) {
        snprintf(err, errlen, "%s: %s.%s must be a finite number", path, objname, key);
        return -1;
    }
    *out = x->valuedouble;
    return 0;
}

int ms_json_int(const cJSON *obj, const char *objname, const char *key, int required, int lo, int hi,
                int *out, const char *path, char *err, size_t errlen)
{
    double d = *out;
    if (ms_json_number(obj, objname, key, required, &d, path, err, errlen)) return -1;
    if (d != floor(d) || d < lo || d > hi) {
        snprintf(err, errlen, "%s: %s.%s must be an integer in [%d, %d]", path, objname, key, lo, hi);
        return -1;
    }
    *out = (int)d;
    return 0;
}

const cJSON *ms_json_object(const cJSON *root, const char *key, const char *path, char *err, size_t errlen)
{
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(root, key);
    if (!o) { ms_json_missing(root, "", key, path, err, errlen); return NULL; }
    if (!cJSON_IsObject(o)) { snprintf(err, errlen, "%s: \"%s\" must be an object", path, key); return NULL; }
    return o;
}
