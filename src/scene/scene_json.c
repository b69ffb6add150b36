/* Scene files: JSON (cJSON) naming meshes (mesh_load.c), camera, light and render settings. */
#include "microshadow.h"
#include "scene_internal.h"
#include "mesh_transform.h"
#include "../image/png_read.h"
#include "../image/exr_read.h"
#include "../light/light_shape.h"
#include "../core/abi.h"
_Static_assert(MS_SOUP_UV_SETS == MS_MAX_UV_SETS, "one count of UV sets");
#include <cjson/cJSON.h>
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Line number of offset off in text. */
static int line_of(const char *text, size_t off)
{
    int line = 1;
    for (size_t i = 0; i < off && text[i]; i++) line += text[i] == '\n';
    return line;
}

/* Known keys, per object, for the unknown-key warnings. */
static const char *const top_keys[] = { "meshes", "procedural", "camera", "light", "lights", "render",
                                        "allow_outside_paths", "lights_from_emissive", "lights_from_punctual",
                                        "punctual_radius", NULL };
static const char *const procedural_keys[] = { "type", "triangles", "seed", NULL };
/* The camera's keys depend on camera.type (docs/cameras.md): each type reads the common ones and its own. */
#define CAMERA_COMMON_KEYS "type", "eye", "target", "up", "width", "height"
static const char *const camera_keys_pinhole[] = { CAMERA_COMMON_KEYS, "fov_y", NULL };
static const char *const camera_keys_ortho[] = { CAMERA_COMMON_KEYS, "ortho_height", NULL };
static const char *const camera_keys_fisheye[] = { CAMERA_COMMON_KEYS, "fov", NULL };
static const char *const camera_keys_panorama[] = { CAMERA_COMMON_KEYS, NULL };
static const char *const camera_keys_any[] = { CAMERA_COMMON_KEYS, "fov_y", "ortho_height", "fov", NULL };
static const struct { const char *name; ms_camera_type type; const char *const *keys; const char *own; } camera_types[] = {
    { "pinhole", MS_CAMERA_PINHOLE, camera_keys_pinhole, "fov_y" },
    { "orthographic", MS_CAMERA_ORTHOGRAPHIC, camera_keys_ortho, "ortho_height" },
    { "fisheye", MS_CAMERA_FISHEYE, camera_keys_fisheye, "fov" },
    { "latlong", MS_CAMERA_LATLONG, camera_keys_panorama, NULL },
    { "parabolic", MS_CAMERA_PARABOLIC, camera_keys_panorama, NULL },
};
/* The keys of the camera being parsed (its type's), for the unknown-key warnings and typo hints. */
static _Thread_local const char *const *camera_keys = camera_keys_pinhole;
/* A light's keys: "shape", every shape's own (its row's keys, light/light_shape.h, in table order), the
 * emission's and "texture" (light_keys_fill). */
#define LIGHT_KEYS_MAX 48
static _Thread_local const char *light_keys[LIGHT_KEYS_MAX] = { "shape", NULL };
static const char *const render_keys[] = { "samples", "aa", NULL };
static const char *const mesh_keys[] = { "file", "transform", "lightmap", NULL };
static const char *const mesh_lightmap_keys[] = { "scale", NULL };

/* Warnings wait until the scene loaded: a failed load prints its one error line only. */
#define MAX_WARNINGS 16
typedef struct warn_list { int n; char line[MAX_WARNINGS][320]; } warn_list;
static _Thread_local warn_list *g_warnings;

static int is_known(const char *name, const char *const *known)
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
        if (!is_known(it->string, known) && !strcmp(ms_nearest_name(it->string, known, NULL), key)) return it->string;
    return NULL;
}

static const char *const *known_for(const char *objname)
{
    return !strcmp(objname, "camera") ? camera_keys : !strncmp(objname, "light", 5) ? light_keys
         : !strcmp(objname, "render") ? render_keys : !strcmp(objname, "procedural") ? procedural_keys : top_keys;
}

/* "X is missing", with the unknown key that was probably meant. */
static void missing(const cJSON *obj, const char *objname, const char *key, const char *path, char *err, size_t errlen)
{
    const char *typo = meant_for(obj, key, known_for(objname));
    char hint[128] = "";
    if (typo && !strcmp(objname, "camera") && is_known(typo, camera_keys_any))
        snprintf(hint, sizeof hint, " (\"%.40s\" is another camera type's key)", typo);
    else if (typo) snprintf(hint, sizeof hint, " (\"%.40s\" is not a known key: a typo?)", typo);
    if (objname[0]) snprintf(err, errlen, "%s: %s.%s is missing%s", path, objname, key, hint);
    else snprintf(err, errlen, "%s: \"%s\" is missing%s", path, key, hint);
}

/* Warns about each key of obj in neither known nor also (NULL: none), naming the nearest known key. Keys
 * that begin with '_' are comments ("_comment", "_note"): JSON has no other kind, so they pass silently. */
static void warn_unknown_except(const cJSON *obj, const char *objname, const char *const *known,
                                const char *const *also, const char *path)
{
    const cJSON *it;
    cJSON_ArrayForEach(it, obj) {
        if (it->string[0] == '_' || is_known(it->string, known) || (also && is_known(it->string, also))) continue;
        if (g_warnings && g_warnings->n < MAX_WARNINGS)
            snprintf(g_warnings->line[g_warnings->n++], sizeof g_warnings->line[0],
                     "%.200s: unknown key \"%s%s%.40s\" ignored (the nearest known key is \"%s\")", path, objname,
                     objname[0] ? "." : "", it->string, ms_nearest_name(it->string, known, NULL));
    }
}

static void warn_unknown(const cJSON *obj, const char *objname, const char *const *known, const char *path)
{
    warn_unknown_except(obj, objname, known, NULL, path);
}

/* Keys another camera type reads: a warning that says so, rather than "unknown". */
static void warn_camera_keys(const cJSON *cam, const char *type_name, const char *path)
{
    const cJSON *it;
    cJSON_ArrayForEach(it, cam)
        if (!is_known(it->string, camera_keys) && is_known(it->string, camera_keys_any) && g_warnings &&
            g_warnings->n < MAX_WARNINGS)
            snprintf(g_warnings->line[g_warnings->n++], sizeof g_warnings->line[0],
                     "%.200s: camera.%s ignored (a %s camera does not use it)", path, it->string, type_name);
}

static int cmp_str(const void *a, const void *b) { return strcmp(*(const char *const *)a, *(const char *const *)b); }

/* Duplicate keys anywhere: cJSON keeps both and returns the first, which silently drops the second. */
static int check_duplicates(const cJSON *node, const char *where, const char *path, char *err, size_t errlen)
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
        if (check_duplicates(it, sub, path, err, errlen)) return -1;
        i++;
    }
    return 0;
}

/* A number read into a float: finite, and within float range (1e39 would become infinity). */
static int float_ok(double d, const char *objname, const char *key, int index, const char *path, char *err, size_t errlen)
{
    if (fabs(d) <= FLT_MAX) return 0;
    if (index >= 0) snprintf(err, errlen, "%s: %s.%s[%d] = %g overflows a float (largest magnitude %g)", path, objname, key, index, d, (double)FLT_MAX);
    else snprintf(err, errlen, "%s: %s.%s = %g overflows a float (largest magnitude %g)", path, objname, key, d, (double)FLT_MAX);
    return -1;
}

/* Reads key as an array of three finite numbers. */
static int get_vec3(const cJSON *obj, const char *objname, const char *key, int required, ms_vec3 *out,
                    const char *path, char *err, size_t errlen)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!a) {
        if (!required) return 0;
        missing(obj, objname, key, path, err, errlen);
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
        if (float_ok(x->valuedouble, objname, key, i, path, err, errlen)) return -1;
        v[i] = (float)x->valuedouble;
    }
    out->x = v[0]; out->y = v[1]; out->z = v[2];
    return 0;
}

/* The double values of a vec3 that get_vec3 accepted (a position: the scene's frame is subtracted from these
 * before rounding, scene_frame.c). */
static void vec3_d(const cJSON *obj, const char *key, double out[3])
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, key);
    for (int i = 0; i < 3; i++) out[i] = a ? cJSON_GetArrayItem(a, i)->valuedouble : 0.0;
}

/* A light's shape and the values of its geometry keys as the file gives them: what re-derives the light in
 * the scene's frame. */
typedef struct light_pos { const ms_light_shape_ops *shape; ms_light_params v; } light_pos;

static int get_number(const cJSON *obj, const char *objname, const char *key, int required, double *out,
                      const char *path, char *err, size_t errlen)
{
    const cJSON *x = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!x) {
        if (!required) return 0;
        missing(obj, objname, key, path, err, errlen);
        return -1;
    }
    if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble)) {
        snprintf(err, errlen, "%s: %s.%s must be a finite number", path, objname, key);
        return -1;
    }
    *out = x->valuedouble;
    return 0;
}

static int get_int(const cJSON *obj, const char *objname, const char *key, int required, int lo, int hi,
                   int *out, const char *path, char *err, size_t errlen)
{
    double d = *out;
    if (get_number(obj, objname, key, required, &d, path, err, errlen)) return -1;
    if (d != floor(d) || d < lo || d > hi) {
        snprintf(err, errlen, "%s: %s.%s must be an integer in [%d, %d]", path, objname, key, lo, hi);
        return -1;
    }
    *out = (int)d;
    return 0;
}

static const cJSON *get_object(const cJSON *root, const char *key, const char *path, char *err, size_t errlen)
{
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(root, key);
    if (!o) { missing(root, "", key, path, err, errlen); return NULL; }
    if (!cJSON_IsObject(o)) { snprintf(err, errlen, "%s: \"%s\" must be an object", path, key); return NULL; }
    return o;
}

/* ---- Lights: "light": {...} (one) or "lights": [{...}, ...] (docs/design.md, "Light shapes", "Units") ---- */


/* Reads key as a number (grey) or an array of three numbers, none negative; 1 if present, 0 if not, -1 bad. */
static int get_amount(const cJSON *obj, const char *objname, const char *key, ms_vec3 *out, const char *path,
                      char *err, size_t errlen)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!a) return 0;
    if (cJSON_IsNumber(a)) {
        double d = 0;
        if (get_number(obj, objname, key, 1, &d, path, err, errlen) || float_ok(d, objname, key, -1, path, err, errlen))
            return -1;
        *out = (ms_vec3){ (float)d, (float)d, (float)d };
    } else if (get_vec3(obj, objname, key, 1, out, path, err, errlen)) {
        snprintf(err, errlen, "%s: %s.%s must be a number or an array of 3 numbers", path, objname, key);
        return -1;
    }
    if (out->x < 0 || out->y < 0 || out->z < 0) {
        snprintf(err, errlen, "%s: %s.%s must not be negative", path, objname, key);
        return -1;
    }
    return 1;
}

/* light_keys: "shape", every row's keys once each, then the emission's and "texture". */
static void light_keys_fill(void)
{
    static const char *const tail[] = { "emission", "power", "lumens", "texture" };
    size_t n = 0;
    light_keys[n++] = "shape";
    light_keys[n] = NULL;
    const ms_light_shape_ops *o;
    for (size_t i = 0; (o = ms_light_shape_at(i)) != NULL; i++)
        for (int k = 0; o->keys[k].name; k++)
            if (!is_known(o->keys[k].name, light_keys) && n + 1 < LIGHT_KEYS_MAX - 4) {
                light_keys[n++] = o->keys[k].name;
                light_keys[n] = NULL;
            }
    for (size_t i = 0; i < 4; i++) light_keys[n++] = tail[i];
    light_keys[n] = NULL;
}

/* The shapes' names for messages: "\"rect\", \"disk\" or \"sphere\"" (textured_only: those that take a texture). */
static void shape_names(char *buf, size_t n, int textured_only)
{
    const ms_light_shape_ops *o, *names[16];
    size_t m = 0, len = 0;
    buf[0] = 0;
    for (size_t i = 0; (o = ms_light_shape_at(i)) != NULL && m < 16; i++)
        if (!textured_only || o->textured) names[m++] = o;
    for (size_t i = 0; i < m && len < n; i++) {
        const int k = snprintf(buf + len, n - len, "%s\"%s\"", i == 0 ? "" : i + 1 == m ? " or " : ", ", names[i]->name);
        if (k < 0) break;
        len += (size_t)k;
    }
}

/* The values of a shape's geometry keys (its row's keys): each point or vector as get_vec3 checks it ([x, y, z],
 * or count of them nested), each number by get_number (an optional one absent: its fallback). */
static int get_light_keys(const cJSON *obj, const char *objname, const ms_light_shape_ops *o, ms_light_params *v,
                          const char *path, char *err, size_t errlen)
{
    memset(v, 0, sizeof *v);
    for (int k = 0; o->keys[k].name; k++) {
        const ms_light_key *key = &o->keys[k];
        const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key->name);
        if (key->kind == MS_LIGHT_KEY_NUMBER) {
            v->v[k][0] = key->fallback;
            if (get_number(obj, objname, key->name, !key->optional, &v->v[k][0], path, err, errlen)) return -1;
            continue;
        }
        if (key->count == 1) {
            ms_vec3 f;
            if (get_vec3(obj, objname, key->name, !key->optional, &f, path, err, errlen)) return -1;
            vec3_d(obj, key->name, v->v[k]);
            continue;
        }
        if (!item) {
            if (key->optional) continue;
            missing(obj, objname, key->name, path, err, errlen);
            return -1;
        }
        if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != key->count) {
            snprintf(err, errlen, "%s: %s.%s must be an array of %d points [x, y, z]", path, objname, key->name, key->count);
            return -1;
        }
        for (int i = 0; i < key->count; i++) {
            const cJSON *pt = cJSON_GetArrayItem(item, i);
            if (!cJSON_IsArray(pt) || cJSON_GetArraySize(pt) != 3) {
                snprintf(err, errlen, "%s: %s.%s[%d] must be an array of 3 numbers", path, objname, key->name, i);
                return -1;
            }
            for (int c = 0; c < 3; c++) {
                const cJSON *x = cJSON_GetArrayItem(pt, c);
                if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble)) {
                    snprintf(err, errlen, "%s: %s.%s[%d] must be an array of 3 finite numbers", path, objname, key->name, i);
                    return -1;
                }
                if (float_ok(x->valuedouble, objname, key->name, 3 * i + c, path, err, errlen)) return -1;
                v->v[k][3 * i + c] = x->valuedouble;
            }
        }
    }
    return 0;
}

/* Builds l's geometry from the values of its shape's keys with the scene's origin o subtracted from its points
 * (in double, then rounded once, as ms_scene_frame_point). */
static int light_build(ms_light *l, const light_pos *lp, const double o[3], char *msg, size_t n)
{
    ms_light_params v = lp->v;
    for (int k = 0; lp->shape->keys[k].name; k++)
        if (lp->shape->keys[k].kind == MS_LIGHT_KEY_POINT)
            for (int i = 0; i < 3 * lp->shape->keys[k].count; i++) v.v[k][i] -= o[i % 3];
    return lp->shape->build(l, &v, MS_MAX_COORD, msg, n);
}

/* One light object: "shape" (a row of light/light_shape.h's table; "rect" by default), its geometry (the
 * row's keys), and at most one of "emission" (radiance), "power" (watts) or "lumens" (luminous flux),
 * default emission 1. */
static int parse_light(const cJSON *obj, const char *objname, ms_light *l, light_pos *lp, const char *path, char *err,
                       size_t errlen)
{
    if (!cJSON_IsObject(obj)) { snprintf(err, errlen, "%s: %s must be an object", path, objname); return -1; }
    light_keys_fill();
    warn_unknown(obj, objname, light_keys, path);
    memset(l, 0, sizeof *l);
    const cJSON *shape = cJSON_GetObjectItemCaseSensitive(obj, "shape");
    const char *sh = "rect";
    char names[160];
    shape_names(names, sizeof names, 0);
    if (shape) {
        if (!cJSON_IsString(shape)) { snprintf(err, errlen, "%s: %s.shape must be %s", path, objname, names); return -1; }
        sh = shape->valuestring;
    }
    lp->shape = ms_light_shape_named(sh);
    if (!lp->shape) {
        snprintf(err, errlen, "%s: %s.shape must be %s (got \"%.40s\")", path, objname, names, sh);
        return -1;
    }
    if (get_light_keys(obj, objname, lp->shape, &lp->v, path, err, errlen)) return -1;
    if (!lp->shape->textured && cJSON_GetObjectItemCaseSensitive(obj, "texture")) {
        shape_names(names, sizeof names, 1);
        snprintf(err, errlen, "%s: %s: a %s light cannot be textured (%s can)", path, objname, sh, names);
        return -1;
    }
    static const double no_origin[3] = { 0.0, 0.0, 0.0 };
    char msg[200];
    if (light_build(l, lp, no_origin, msg, sizeof msg)) {
        snprintf(err, errlen, "%s: %s.%s", path, objname, msg);
        return -1;
    }
    static const char *const unit_key[] = { "emission", "power", "lumens" };
    static const ms_light_units unit_of[] = { MS_UNITS_RADIANCE, MS_UNITS_WATTS, MS_UNITS_LUMENS };
    ms_vec3 amount = { MS_DEFAULT_EMISSION, MS_DEFAULT_EMISSION, MS_DEFAULT_EMISSION };
    ms_light_units units = MS_UNITS_RADIANCE;
    int given = 0;
    for (int u = 0; u < 3; u++) {
        ms_vec3 a;
        const int r = get_amount(obj, objname, unit_key[u], &a, path, err, errlen);
        if (r < 0) return -1;
        if (!r) continue;
        if (given++) {
            snprintf(err, errlen, "%s: %s: give one of \"emission\", \"power\" and \"lumens\", not several", path, objname);
            return -1;
        }
        amount = a;
        units = unit_of[u];
    }
    l->emission = ms_light_radiance_from(l, amount, units);
    const cJSON *tex = cJSON_GetObjectItemCaseSensitive(obj, "texture");
    if (tex) {
        if (!cJSON_IsString(tex) || !tex->valuestring[0]) {
            snprintf(err, errlen, "%s: %s.texture must be the path of a PNG or EXR image", path, objname);
            return -1;
        }
        char tex_path[4096];
        if (ms_path_beside(path, tex->valuestring, tex_path, sizeof tex_path)) {
            snprintf(err, errlen, "%s: %s.texture: the path is too long", path, objname);
            return -1;
        }
        float *t = NULL;
        int w = 0, h = 0;
        char *bytes = NULL;
        size_t len = 0;
        char why[1024];
        int rc = ms_read_input(tex_path, MS_MAX_MESH_BYTES, MS_INPUT_TEXTURE, &bytes, &len, why, sizeof why);
        /* By content, not by name: an EXR's magic number, else PNG (whose decoder names anything else). */
        if (!rc && ms_is_exr(bytes, len)) rc = ms_exr_decode_linear(tex_path, bytes, len, MS_MAX_LIGHT_TEXTURE, &t, &w, &h, why, sizeof why);
        else if (!rc) rc = ms_png_decode_linear(tex_path, bytes, len, MS_MAX_LIGHT_TEXTURE, &t, &w, &h, why, sizeof why);
        free(bytes);
        if (rc) { snprintf(err, errlen, "%s: %s.texture: %s", path, objname, why); return -1; }
        l->texture = t;
        l->texture_width = w;
        l->texture_height = h;
    }
    return 0;
}

int ms_path_beside(const char *json_path, const char *rel, char *out, size_t n)
{
    if (rel[0] == '/') return snprintf(out, n, "%s", rel) >= (int)n ? -1 : 0;
    char *dircopy = strdup(json_path);
    if (!dircopy) return -1;
    const int k = snprintf(out, n, "%s/%s", dirname(dircopy), rel);
    free(dircopy);
    return k < 0 || (size_t)k >= n ? -1 : 0;
}

/* lp: MS_MAX_LIGHTS positions as the file gives them (scene_frame.c). none_ok: the file may name no light
 * (the emitters will be the lights; nothing is set then). */
static int parse_lights(const cJSON *root, ms_scene *out, light_pos *lp, int none_ok, const char *path, char *err,
                        size_t errlen)
{
    const cJSON *one = cJSON_GetObjectItemCaseSensitive(root, "light");
    const cJSON *many = cJSON_GetObjectItemCaseSensitive(root, "lights");
    if (one && many) { snprintf(err, errlen, "%s: give either \"light\" or \"lights\", not both", path); return -1; }
    if (!one && !many && none_ok) return 0;
    if (!many) {
        const cJSON *light = get_object(root, "light", path, err, errlen);
        return light ? parse_light(light, "light", &out->light, lp, path, err, errlen) : -1;
    }
    const int n = cJSON_IsArray(many) ? cJSON_GetArraySize(many) : 0;
    if (n < 1 || n > MS_MAX_LIGHTS) {
        snprintf(err, errlen, "%s: \"lights\" must be an array of 1 to %d light objects", path, MS_MAX_LIGHTS);
        return -1;
    }
    out->lights = calloc((size_t)n, sizeof *out->lights);
    if (!out->lights) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    out->n_lights = (size_t)n;   /* so that ms_scene_free frees the textures of a failed load */
    for (int i = 0; i < n; i++) {
        char name[32];
        snprintf(name, sizeof name, "lights[%d]", i);
        if (parse_light(cJSON_GetArrayItem(many, i), name, &out->lights[i], &lp[i], path, err, errlen)) return -1;
    }
    out->n_lights = (size_t)n;
    out->light = out->lights[0];
    return 0;
}

static int parse_with(const char *text, size_t len, const char *json_path, const ms_scene_load_options *opt,
                      ms_scene *out, char *err, size_t errlen);

/* A glTF file's mesh-entry transform m (3 x 4, row-major) on a punctual light: its position moved, its
 * direction turned by the linear part (renormalised). */
static void punctual_transform(ms_punctual *p, const double m[12])
{
    double pos[3], dir[3], len = 0.0;
    for (int r = 0; r < 3; r++) {
        pos[r] = m[4 * r] * p->pos[0] + m[4 * r + 1] * p->pos[1] + m[4 * r + 2] * p->pos[2] + m[4 * r + 3];
        dir[r] = m[4 * r] * p->dir[0] + m[4 * r + 1] * p->dir[1] + m[4 * r + 2] * p->dir[2];
        len += dir[r] * dir[r];
    }
    len = sqrt(len);
    for (int r = 0; r < 3; r++) { p->pos[r] = pos[r]; if (len > 0.0) p->dir[r] = dir[r] / len; }
}

static void warn_line(const char *line)
{
    if (g_warnings && g_warnings->n < MAX_WARNINGS)
        snprintf(g_warnings->line[g_warnings->n++], sizeof g_warnings->line[0], "%s", line);
}

/* Appends add[0 .. n_add-1] to the scene's lights (have: how many it has; "light" alone becomes lights[0]). */
static int append_lights(ms_scene *out, size_t have, ms_light *add, size_t n_add, const char *path, char *err, size_t errlen)
{
    if (!n_add) return 0;
    ms_light *all = realloc(out->lights, (have + n_add) * sizeof *all);
    if (!all) { free(add); snprintf(err, errlen, "%s: out of memory for the lights", path); return -1; }
    if (have == 1 && !out->n_lights) all[0] = out->light;   /* "light": it becomes lights[0], texture and all */
    memcpy(all + have, add, n_add * sizeof *add);
    free(add);
    out->lights = all;
    out->n_lights = have + n_add;
    out->light = all[0];
    return 0;
}

/* The materials named by "lights_from_emissive": [...] (list) as lit[m] = 1 (*lit, calloc'd), every material
 * of that name in every mesh; a name that is no emitting material's is an error listing those there are. */
static int choose_emitters(const ms_scene *out, const cJSON *list, char *const *names, unsigned char **lit,
                           const char *path, char *err, size_t errlen)
{
    *lit = calloc(out->n_materials ? out->n_materials : 1, 1);
    if (!*lit) {
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    for (const cJSON *it = list->child; it; it = it->next) {
        int found = 0;
        for (size_t m = 0; names && m < out->n_materials; m++) {
            const ms_material *mm = &out->materials[m];
            const int emits = mm->emissive[0] > 0.0f || mm->emissive[1] > 0.0f || mm->emissive[2] > 0.0f;
            if (names[m] && emits && !strcmp(names[m], it->valuestring)) (*lit)[m] = 1, found = 1;
        }
        if (!found) {
            char mats[512];
            ms_scene_emissive_materials_text(out, names, mats, sizeof mats);
            snprintf(err, errlen, "%s: \"lights_from_emissive\" names \"%.120s\", which is no emitting material of the "
                     "meshes (theirs: %s)", path, it->valuestring, mats[0] ? mats : "none");
            free(*lit);
            *lit = NULL;
            return -1;
        }
    }
    return 0;
}

/* The asset's own lights after those the file names (file_lights: it names some): its KHR_lights_punctual
 * lights (punct NULL: not wanted), then its emissive triangles of the chosen materials (emitters: wanted). */
static int add_asset_lights(ms_scene *out, int file_lights, int emitters, const ms_emitter_choice *choice,
                            const ms_punctual *punct, size_t n_punct, double punctual_radius, const char *path, char *err,
                            size_t errlen)
{
    size_t have = out->n_lights ? out->n_lights : file_lights ? 1 : 0;
    ms_light *add = NULL;
    size_t n_add = 0;
    if (punct) {
        if (ms_scene_punctual_lights(punct, n_punct, out->origin, punctual_radius, MS_MAX_LIGHTS - have, path, warn_line,
                                     &add, &n_add, err, errlen) ||
            append_lights(out, have, add, n_add, path, err, errlen))
            return -1;
        have += n_add;
    }
    if (emitters) {
        if (ms_scene_emitter_lights(out, choice, MS_MAX_LIGHTS - have, path, &add, &n_add, err, errlen) ||
            append_lights(out, have, add, n_add, path, err, errlen))
            return -1;
        have += n_add;
    }
    if (!have) {
        snprintf(err, errlen, "%s: \"light\" is missing: the scene file names no light (\"light\" or \"lights\") and its meshes have neither "
                 "emissive triangles (glTF emissiveFactor, MTL Ke) nor KHR_lights_punctual lights to light it",
                 path);
        return -1;
    }
    return 0;
}

/* The camera's eye and target and the lights' positions in the scene's frame (out->origin), from the
 * numbers of the file; nothing changes when the frame is the world's. */
static void frame_camera_lights(const cJSON *cam, ms_scene *out, const light_pos *lp)
{
    const double *o = out->origin;
    if (o[0] == 0.0 && o[1] == 0.0 && o[2] == 0.0) return;
    double p[3];
    float f[3];
    vec3_d(cam, "eye", p);
    ms_scene_frame_point(p, o, f);
    out->camera.eye = (ms_vec3){ f[0], f[1], f[2] };
    vec3_d(cam, "target", p);
    ms_scene_frame_point(p, o, f);
    out->camera.target = (ms_vec3){ f[0], f[1], f[2] };
    const size_t n = out->n_lights ? out->n_lights : 1;
    for (size_t i = 0; i < n; i++) {
        ms_light *l = out->n_lights ? &out->lights[i] : &out->light;
        char msg[200];
        light_build(l, &lp[i], o, msg, sizeof msg);   /* built from the same values at parse time: it succeeds */
    }
    if (out->n_lights) out->light = out->lights[0];
}

ms_status ms_scene_load_abi(const ms_abi *abi, const char *json_path, const ms_scene_load_options *opt, ms_scene *out,
                            char *err, size_t errlen)
{
    const ms_status st = ms_abi_check(abi, "ms_scene_load", err, errlen);
    if (st) return st;
    memset(out, 0, sizeof *out);
    char *text;
    size_t len;
    if (ms_read_input(json_path, MS_MAX_SCENE_BYTES, MS_INPUT_SCENE, &text, &len, err, errlen)) {
        ms_one_line(err);
        return MS_ERR_IO;
    }
    const int rc = parse_with(text, len, json_path, opt, out, err, errlen);
    free(text);
    return rc ? MS_ERR_INVALID : MS_OK;
}

static int scene_parse(const char *text, size_t len, const char *json_path, const ms_scene_load_options *opt,
                       ms_scene *out, char *err, size_t errlen);

int ms_scene_parse(const char *text, size_t len, const char *json_path, ms_scene *out, char *err, size_t errlen)
{
    return parse_with(text, len, json_path, NULL, out, err, errlen);
}

static int parse_with(const char *text, size_t len, const char *json_path, const ms_scene_load_options *opt,
                      ms_scene *out, char *err, size_t errlen)
{
    warn_list w;
    w.n = 0;
    g_warnings = &w;
    ms_material_warnings_begin();
    int rc = scene_parse(text, len, json_path, opt, out, err, errlen);
    g_warnings = NULL;
    if (rc) ms_one_line(err);
    else
        for (int i = 0; i < w.n; i++) ms_warn("%s", w.line[i]);
    ms_material_warnings_end(rc == 0);   /* one line for all the unusable material files and textures */
    return rc;
}

static int scene_parse(const char *text, size_t len, const char *json_path, const ms_scene_load_options *opt,
                       ms_scene *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    const char *nul = memchr(text, 0, len);
    if (nul) {
        snprintf(err, errlen, "%s: line %d: a NUL byte (not a JSON text file)", json_path, line_of(text, (size_t)(nul - text)));
        return -1;
    }
    /* cJSON decodes \u0000 into a NUL inside the string, which then silently ends it (a mesh path
     * would be cut): refuse it. Backslashes only occur inside strings in valid JSON. */
    for (size_t i = 0; i + 1 < len; i++)
        if (text[i] == '\\') {
            if (text[i + 1] == 'u' && i + 6 <= len && !memcmp(text + i + 2, "0000", 4)) {
                snprintf(err, errlen, "%s: line %d: a string contains \\u0000 (NUL is not allowed)", json_path, line_of(text, i));
                return -1;
            }
            i++;
        }
    const char *where = NULL;
    cJSON *root = cJSON_ParseWithOpts(text, &where, 1);
    if (!root) {
        size_t off = where ? (size_t)(where - text) : 0;
        snprintf(err, errlen, "%s: malformed JSON near line %d", json_path, line_of(text, off));
        return -1;
    }
    int rc = -1;
    if (!cJSON_IsObject(root)) { snprintf(err, errlen, "%s: the top level must be an object", json_path); goto done; }
    if (check_duplicates(root, "", json_path, err, errlen)) goto done;
    warn_unknown(root, "", top_keys, json_path);

    const cJSON *cam = get_object(root, "camera", json_path, err, errlen);
    if (!cam) goto done;
    size_t ct = 0;   /* camera_types[0]: pinhole, when "type" is absent */
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(cam, "type");
    if (type) {
        ct = sizeof camera_types / sizeof camera_types[0];
        for (size_t i = 0; cJSON_IsString(type) && i < ct; i++)
            if (!strcmp(type->valuestring, camera_types[i].name)) ct = i;
        if (ct == sizeof camera_types / sizeof camera_types[0]) {
            snprintf(err, errlen, "%s: camera.type must be \"pinhole\", \"orthographic\", \"fisheye\", \"latlong\" or "
                     "\"parabolic\"", json_path);
            goto done;
        }
    }
    camera_keys = camera_types[ct].keys;
    warn_camera_keys(cam, camera_types[ct].name, json_path);
    warn_unknown_except(cam, "camera", camera_keys, camera_keys_any, json_path);
    ms_camera *c = &out->camera;
    c->type = camera_types[ct].type;
    c->width = 1024; c->height = 1024;
    if (get_vec3(cam, "camera", "eye", 1, &c->eye, json_path, err, errlen) ||
        get_vec3(cam, "camera", "target", 1, &c->target, json_path, err, errlen) ||
        get_vec3(cam, "camera", "up", 1, &c->up, json_path, err, errlen) ||
        get_int(cam, "camera", "width", 0, 1, MS_MAX_IMAGE_SIZE, &c->width, json_path, err, errlen) ||
        get_int(cam, "camera", "height", 0, 1, MS_MAX_IMAGE_SIZE, &c->height, json_path, err, errlen))
        goto done;
    /* The type's own number (pinhole fov_y, orthographic ortho_height, fisheye fov), required; its range
     * is checked with the scene (ms_scene_validate), for scenes built through the API too. */
    const char *own = camera_types[ct].own;
    if (own) {
        double v = 0.0;
        if (get_number(cam, "camera", own, 1, &v, json_path, err, errlen) ||
            float_ok(v, "camera", own, -1, json_path, err, errlen))
            goto done;
        if (c->type == MS_CAMERA_PINHOLE) c->fov_y = (float)v;
        else if (c->type == MS_CAMERA_ORTHOGRAPHIC) c->ortho_height = (float)v;
        else c->fov = (float)v;
    }

    /* The asset's emitters as lights (scene_emitters.c): by default when the file names no light. */
    const int file_lights = cJSON_GetObjectItemCaseSensitive(root, "light") || cJSON_GetObjectItemCaseSensitive(root, "lights");
    /* true, false, or the names of the materials whose emissive triangles become lights (the others still
     * glow in the shading): an asset's lamps among its glowing screens, signs or text. */
    const cJSON *from_emissive = cJSON_GetObjectItemCaseSensitive(root, "lights_from_emissive");
    const int emitter_list = cJSON_IsArray(from_emissive);
    int list_ok = emitter_list && cJSON_GetArraySize(from_emissive) > 0;
    for (const cJSON *it = emitter_list ? from_emissive->child : NULL; it; it = it->next)
        list_ok &= cJSON_IsString(it) && it->valuestring[0] != '\0';
    if (from_emissive && !cJSON_IsBool(from_emissive) && !list_ok) {
        snprintf(err, errlen, "%s: \"lights_from_emissive\" must be true, false or a non-empty list of material names",
                 json_path);
        goto done;
    }
    const int emitters = from_emissive ? !cJSON_IsFalse(from_emissive) : !file_lights;
    const cJSON *from_punctual = cJSON_GetObjectItemCaseSensitive(root, "lights_from_punctual");
    if (from_punctual && !cJSON_IsBool(from_punctual)) {
        snprintf(err, errlen, "%s: \"lights_from_punctual\" must be true or false", json_path);
        goto done;
    }
    const int punctuals = from_punctual ? cJSON_IsTrue(from_punctual) : !file_lights;
    double punctual_radius = 0.05;
    if (get_number(root, "", "punctual_radius", 0, &punctual_radius, json_path, err, errlen)) goto done;
    if (!(punctual_radius > 0.0) || punctual_radius > MS_MAX_COORD) {
        snprintf(err, errlen, "%s: \"punctual_radius\" must be in (0, %g]", json_path, (double)MS_MAX_COORD);
        goto done;
    }
    light_pos lpos[MS_MAX_LIGHTS];
    memset(lpos, 0, sizeof lpos);
    if (parse_lights(root, out, lpos, emitters || punctuals, json_path, err, errlen)) goto done;

    out->samples = 1024;
    const cJSON *render = cJSON_GetObjectItemCaseSensitive(root, "render");
    if (render) {
        if (!cJSON_IsObject(render)) { snprintf(err, errlen, "%s: \"render\" must be an object", json_path); goto done; }
        warn_unknown(render, "render", render_keys, json_path);
        if (get_int(render, "render", "samples", 0, 1, 1 << 20, &out->samples, json_path, err, errlen)) goto done;
        if (cJSON_GetObjectItemCaseSensitive(render, "aa")) {   /* absent: 0, the caller's default */
            int aa = 1;
            if (get_int(render, "render", "aa", 1, 1, 16, &aa, json_path, err, errlen)) goto done;
            if (aa != 1 && aa != 4 && aa != 9 && aa != 16) {
                snprintf(err, errlen, "%s: render.aa must be 1, 4, 9 or 16 (got %d)", json_path, aa);
                goto done;
            }
            out->aa = aa;
        }
    }

    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(root, "meshes");
    const cJSON *proc = cJSON_GetObjectItemCaseSensitive(root, "procedural");
    if (proc) {
        if (meshes) { snprintf(err, errlen, "%s: give either \"meshes\" or \"procedural\", not both", json_path); goto done; }
        if (!cJSON_IsObject(proc)) { snprintf(err, errlen, "%s: \"procedural\" must be an object", json_path); goto done; }
        warn_unknown(proc, "procedural", procedural_keys, json_path);
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(proc, "type");
        if (!cJSON_IsString(type) || strcmp(type->valuestring, "flowers") != 0) {
            snprintf(err, errlen, "%s: procedural.type must be \"flowers\"", json_path);
            goto done;
        }
        double tris = 0, seed = 0;
        if (get_number(proc, "procedural", "triangles", 1, &tris, json_path, err, errlen) ||
            get_number(proc, "procedural", "seed", 0, &seed, json_path, err, errlen))
            goto done;
        /* prim ids are 32-bit with UINT32_MAX for a miss; 2^31 keeps far from it */
        if (tris != floor(tris) || tris < 1 || tris > 2147483648.0) {
            snprintf(err, errlen, "%s: procedural.triangles must be an integer in [1, 2^31]", json_path);
            goto done;
        }
        if (seed != floor(seed) || seed < 0 || seed > 4294967295.0) {
            snprintf(err, errlen, "%s: procedural.seed must be an integer in [0, 2^32 - 1]", json_path);
            goto done;
        }
        out->procedural.type = MS_PROCEDURAL_FLOWERS;
        out->procedural.seed = (uint32_t)seed;
        out->n_tris = (size_t)tris;
        if (!file_lights) { missing(root, "", "light", json_path, err, errlen); goto done; }   /* no emitters here */
        rc = ms_scene_validate(out, json_path, err, errlen);
        goto done;
    }
    if (!meshes) { missing(root, "", "meshes", json_path, err, errlen); goto done; }
    if (!cJSON_IsArray(meshes) || cJSON_GetArraySize(meshes) == 0) {
        snprintf(err, errlen, "%s: \"meshes\" must be a non-empty array of {\"file\": ...}", json_path);
        goto done;
    }
    char *dircopy = strdup(json_path);
    if (!dircopy) { snprintf(err, errlen, "%s: out of memory", json_path); goto done; }
    const char *dir = dirname(dircopy);
    ms_tri_soup soup = { 0 };
    /* Files the meshes name (glTF buffers and images, MTL files and maps) stay inside the meshes' folders
     * unless the scene file or the caller trusts the assets (ms_resolve_inside). */
    const cJSON *allow = cJSON_GetObjectItemCaseSensitive(root, "allow_outside_paths");
    if (allow && !cJSON_IsBool(allow)) {
        snprintf(err, errlen, "%s: \"allow_outside_paths\" must be true or false", json_path);
        free(dircopy);
        goto done;
    }
    soup.allow_outside_paths = (allow && cJSON_IsTrue(allow)) || (opt && opt->allow_outside_paths);
    int i = 0;
    const cJSON *m;
    /* Per entry: its triangles [from, to) and transform, applied once every file is read; a file listed
     * again (same path) is copied from its first entry rather than read again. */
    struct { char *path; size_t from, to; int has_xf; double xf[12]; float lightmap_scale; } *ent = calloc((size_t)cJSON_GetArraySize(meshes), sizeof *ent);
    if (!ent) { snprintf(err, errlen, "%s: out of memory", json_path); free(dircopy); goto done; }
    cJSON_ArrayForEach(m, meshes) {
        const cJSON *file = cJSON_IsObject(m) ? cJSON_GetObjectItemCaseSensitive(m, "file") : NULL;
        if (!cJSON_IsString(file) || !file->valuestring[0]) {
            snprintf(err, errlen, "%s: meshes[%d].file must be a non-empty string", json_path, i);
            goto mesh_fail;
        }
        char objname[32];
        snprintf(objname, sizeof objname, "meshes[%d]", i);
        warn_unknown(m, objname, mesh_keys, json_path);
        char mesh_path[4096];
        int n = file->valuestring[0] == '/' ? snprintf(mesh_path, sizeof mesh_path, "%s", file->valuestring)
                                            : snprintf(mesh_path, sizeof mesh_path, "%s/%s", dir, file->valuestring);
        if (n < 0 || (size_t)n >= sizeof mesh_path) {
            snprintf(err, errlen, "%s: meshes[%d].file: the path is longer than %zu bytes", json_path, i, sizeof mesh_path - 1);
            goto mesh_fail;
        }
        const cJSON *xf = cJSON_GetObjectItemCaseSensitive(m, "transform");
        if (xf && ms_mesh_transform_parse(xf, objname, json_path, ent[i].xf, err, errlen)) goto mesh_fail;
        ent[i].has_xf = xf != NULL;
        /* "lightmap": false (not baked, still casts) or {"scale": s} (texel density weight) */
        const cJSON *lmk = cJSON_GetObjectItemCaseSensitive(m, "lightmap");
        ent[i].lightmap_scale = 1.0f;
        if (lmk) {
            if (cJSON_IsFalse(lmk)) ent[i].lightmap_scale = 0.0f;
            else if (cJSON_IsTrue(lmk)) ent[i].lightmap_scale = 1.0f;
            else if (cJSON_IsObject(lmk)) {
                char lname[48];
                snprintf(lname, sizeof lname, "meshes[%d].lightmap", i);
                warn_unknown(lmk, lname, mesh_lightmap_keys, json_path);
                const cJSON *sc = cJSON_GetObjectItemCaseSensitive(lmk, "scale");
                if (sc && !(cJSON_IsNumber(sc) && sc->valuedouble > 0.0 && sc->valuedouble <= 1e3)) {
                    snprintf(err, errlen, "%s: meshes[%d].lightmap.scale must be a number in (0, 1000]", json_path, i);
                    goto mesh_fail;
                }
                if (sc) ent[i].lightmap_scale = (float)sc->valuedouble;
            } else {
                snprintf(err, errlen, "%s: meshes[%d].lightmap must be false, true or {\"scale\": s}", json_path, i);
                goto mesh_fail;
            }
        }
        soup.cur_mesh = (uint32_t)i;
        ms_soup_new_object(&soup);
        ent[i].from = soup.n;
        int j = 0;
        while (j < i && strcmp(ent[j].path, mesh_path)) j++;
        if (j < i) {
            if (ms_soup_copy_range(&soup, ent[j].from, ent[j].to)) { snprintf(err, errlen, "%s: out of memory", json_path); goto mesh_fail; }
        } else if (ms_mesh_load(mesh_path, &soup, err, errlen)) {
            goto mesh_fail;
        }
        ent[i].to = soup.n;
        if (!(ent[i].path = strdup(mesh_path))) { snprintf(err, errlen, "%s: out of memory", json_path); goto mesh_fail; }
        i++;
    }
    float *lm_scale = malloc((i ? (size_t)i : 1) * sizeof *lm_scale);
    if (!lm_scale) {
        snprintf(err, errlen, "%s: out of memory", json_path);
        for (int k = 0; k < i; k++) free(ent[k].path);
        free(ent);
        free(dircopy);
        ms_soup_free(&soup);
        goto done;
    }
    for (int k = 0; k < i; k++) {
        if (ent[k].has_xf) ms_soup_transform(&soup, ent[k].from, ent[k].to, ent[k].xf);
        lm_scale[k] = ent[k].lightmap_scale;
        for (size_t q = 0; q < soup.n_punctual && ent[k].has_xf; q++)
            if (soup.punctual[q].mesh == (uint32_t)k) punctual_transform(&soup.punctual[q], ent[k].xf);
        free(ent[k].path);
    }
    out->mesh_lightmap_scale = lm_scale;
    free(ent);
    free(dircopy);
    /* The scene's frame (scene_frame.c): chosen from the triangles' double positions, applied to them, the
     * camera and the lights, here and nowhere else. */
    ms_scene_frame_origin(soup.tri_d, soup.n, out->origin);
    ms_scene_frame_apply(soup.tri, soup.tri_d, soup.n, out->origin);
    frame_camera_lights(cam, out, lpos);
    free(soup.tri_d);
    soup.tri_d = NULL;
    out->tri = soup.tri;
    out->n_tris = soup.n;
    out->tri_mesh = soup.mesh;
    out->tri_object = soup.object;
    out->n_objects = soup.n_objects;
    for (int s = 0; s < MS_MAX_UV_SETS; s++) out->tri_uv[s] = soup.uv[s];
    out->n_meshes = (size_t)i;
    out->materials = soup.mats;   /* surfaces: the soup's arrays change hands (ms_scene_free frees them) */
    out->n_materials = soup.n_mats;
    out->tri_material = soup.material;
    out->tri_normal = soup.normal;
    out->tri_tangent = ms_soup_take_tangents(&soup);
    out->textures = soup.tex;
    out->n_textures = soup.n_tex;
    unsigned char *lit = NULL;
    if (emitter_list && choose_emitters(out, from_emissive, soup.mat_names, &lit, json_path, err, errlen)) {
        ms_soup_free_names(&soup);
        free(soup.punctual);
        goto done;
    }
    const ms_emitter_choice choice = { lit, soup.mat_names };
    const int lights_failed = add_asset_lights(out, file_lights, emitters, &choice, punctuals ? soup.punctual : NULL,
                                               soup.n_punctual, punctual_radius, json_path, err, errlen);
    const size_t n_unlisted = lit && !lights_failed ? ms_scene_emissive_triangles(out, NULL) -
                                                          ms_scene_emissive_triangles(out, &choice) : 0;
    ms_soup_free_names(&soup);
    free(lit);
    if (lights_failed) {
        free(soup.punctual);
        goto done;
    }
    if (n_unlisted && g_warnings && g_warnings->n < MAX_WARNINGS)
        snprintf(g_warnings->line[g_warnings->n++], sizeof g_warnings->line[0], "%.120s: %zu emissive triangle%s of "
                 "materials not listed in \"lights_from_emissive\" not made lights (they still glow)", json_path,
                 n_unlisted, n_unlisted > 1 ? "s" : "");
    if (!punctuals && soup.n_punctual && g_warnings && g_warnings->n < MAX_WARNINGS)
        snprintf(g_warnings->line[g_warnings->n++], sizeof g_warnings->line[0], "%.120s: %zu KHR_lights_punctual light%s "
                 "ignored (the scene file names its lights; \"lights_from_punctual\": true adds them)", json_path,
                 soup.n_punctual, soup.n_punctual > 1 ? "s" : "");
    free(soup.punctual);
    const size_t n_emissive = emitters ? 0 : ms_scene_emissive_triangles(out, NULL);
    if (n_emissive && g_warnings && g_warnings->n < MAX_WARNINGS)
        snprintf(g_warnings->line[g_warnings->n++], sizeof g_warnings->line[0], "%.120s: %zu emissive triangle%s not made "
                 "lights (the scene file names its lights; \"lights_from_emissive\": true adds them)", json_path, n_emissive,
                 n_emissive > 1 ? "s" : "");
    rc = ms_scene_validate(out, json_path, err, errlen);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    out->load_s = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    goto done;
mesh_fail:
    for (int k = 0; k <= i; k++) free(ent[k].path);
    free(ent);
    free(dircopy);
    ms_soup_free(&soup);
done:
    cJSON_Delete(root);
    if (rc) ms_scene_free(out);
    return rc;
}

void ms_scene_free(ms_scene *s)
{
    free(s->tri);
    free(s->tri_mesh);
    free(s->tri_object);
    free(s->mesh_lightmap_scale);
    for (int i = 0; i < MS_MAX_UV_SETS; i++) free(s->tri_uv[i]);
    free(s->materials);
    free(s->tri_material);
    free(s->tri_normal);
    free(s->tri_tangent);
    for (size_t i = 0; i < s->n_textures; i++) free(s->textures[i].rgba);
    free(s->textures);
    /* light is a copy of lights[0] when there is an array: each texture once */
    if (s->n_lights && s->lights)
        for (size_t i = 0; i < s->n_lights; i++) free((void *)s->lights[i].texture);
    else free((void *)s->light.texture);
    free(s->lights);
    memset(s, 0, sizeof *s);
}
