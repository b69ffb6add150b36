/* Scene files' lights: "light": {...} (one) or "lights": [{...}, ...] (docs/design.md, "Light shapes",
 * "Units"), and the asset's own lights (scene_emitters.c, scene_punctual.c) after those the file names. */
#include "scene_json_lights.h"
#include "scene_json_get.h"
#include "scene_internal.h"
#include "image/png_read.h"
#include "image/exr_read.h"
#include "light/light_shape.h"
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


/* Reads key as a number (grey) or an array of three numbers, none negative; 1 if present, 0 if not, -1 bad. */
static int get_amount(const cJSON *obj, const char *objname, const char *key, ms_vec3 *out, const char *path,
                      char *err, size_t errlen)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!a) return 0;
    if (cJSON_IsNumber(a)) {
        double d = 0;
        if (ms_json_number(obj, objname, key, 1, &d, path, err, errlen) || ms_json_float_ok(d, objname, key, -1, path, err, errlen))
            return -1;
        *out = (ms_vec3){ (float)d, (float)d, (float)d };
    } else if (ms_json_vec3(obj, objname, key, 1, out, path, err, errlen)) {
        snprintf(err, errlen, "%s: %s.%s must be a number or an array of 3 numbers", path, objname, key);
        return -1;
    }
    if (out->x < 0 || out->y < 0 || out->z < 0) {
        snprintf(err, errlen, "%s: %s.%s must not be negative", path, objname, key);
        return -1;
    }
    return 1;
}

/* ms_json_light_keys: "shape", every row's keys once each, then the emission's and "texture". */
static void light_keys_fill(void)
{
    static const char *const tail[] = { "emission", "power", "lumens", "texture" };
    size_t n = 0;
    ms_json_light_keys[n++] = "shape";
    ms_json_light_keys[n] = NULL;
    const ms_light_shape_ops *o;
    for (size_t i = 0; (o = ms_light_shape_at(i)) != NULL; i++)
        for (int k = 0; o->keys[k].name; k++)
            if (!ms_json_is_known(o->keys[k].name, ms_json_light_keys) && n + 1 < MS_JSON_LIGHT_KEYS_MAX - 4) {
                ms_json_light_keys[n++] = o->keys[k].name;
                ms_json_light_keys[n] = NULL;
            }
    for (size_t i = 0; i < 4; i++) ms_json_light_keys[n++] = tail[i];
    ms_json_light_keys[n] = NULL;
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

/* The values of a shape's geometry keys (its row's keys): each point or vector as ms_json_vec3 checks it ([x, y, z],
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
            if (ms_json_number(obj, objname, key->name, !key->optional, &v->v[k][0], path, err, errlen)) return -1;
            continue;
        }
        if (key->count == 1) {
            ms_vec3 f;
            if (ms_json_vec3(obj, objname, key->name, !key->optional, &f, path, err, errlen)) return -1;
            ms_json_vec3_d(obj, key->name, v->v[k]);
            continue;
        }
        if (!item) {
            if (key->optional) continue;
            ms_json_missing(obj, objname, key->name, path, err, errlen);
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
                if (ms_json_float_ok(x->valuedouble, objname, key->name, 3 * i + c, path, err, errlen)) return -1;
                v->v[k][3 * i + c] = x->valuedouble;
            }
        }
    }
    return 0;
}

/* Builds l's geometry from the values of its shape's keys with the scene's origin o subtracted from its points
 * (in double, then rounded once, as ms_scene_frame_point). */
int ms_json_light_build(ms_light *l, const light_pos *lp, const double o[3], char *msg, size_t n)
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
    ms_json_warn_unknown(obj, objname, ms_json_light_keys, path);
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
    if (ms_json_light_build(l, lp, no_origin, msg, sizeof msg)) {
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

/* lp: MS_MAX_LIGHTS positions as the file gives them (scene_frame.c). none_ok: the file may name no light
 * (the emitters will be the lights; nothing is set then). */
int ms_json_parse_lights(const cJSON *root, ms_scene *out, light_pos *lp, int none_ok, const char *path, char *err,
                         size_t errlen)
{
    const cJSON *one = cJSON_GetObjectItemCaseSensitive(root, "light");
    const cJSON *many = cJSON_GetObjectItemCaseSensitive(root, "lights");
    if (one && many) { snprintf(err, errlen, "%s: give either \"light\" or \"lights\", not both", path); return -1; }
    if (!one && !many && none_ok) return 0;
    if (!many) {
        const cJSON *light = ms_json_object(root, "light", path, err, errlen);
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

/* A glTF file's mesh-entry transform m (3 x 4, row-major) on a punctual light: its position moved, its
 * direction turned by the linear part (renormalised). */
void ms_json_punctual_transform(ms_punctual *p, const double m[12])
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
    ms_json_warn("%s", line);
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
                            const ms_punctual *punct, size_t n_punct, double punctual_radius, int none_ok,
                            const char *path, char *err, size_t errlen)
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
    if (!have && !none_ok) {
        snprintf(err, errlen, "%s: \"light\" is missing: the scene file names no light (\"light\" or \"lights\") and its meshes have neither "
                 "emissive triangles (glTF emissiveFactor, MTL Ke) nor KHR_lights_punctual lights to light it",
                 path);
        return -1;
    }
    return 0;
}

int ms_json_light_options(const cJSON *root, ms_json_light_opts *lo, const char *path, char *err, size_t errlen)
{
    /* The asset's emitters as lights (scene_emitters.c): by default when the file names no light. */
    lo->file_lights = cJSON_GetObjectItemCaseSensitive(root, "light") || cJSON_GetObjectItemCaseSensitive(root, "lights");
    /* true, false, or the names of the materials whose emissive triangles become lights (the others still
     * glow in the shading): an asset's lamps among its glowing screens, signs or text. */
    const cJSON *from_emissive = cJSON_GetObjectItemCaseSensitive(root, "lights_from_emissive");
    lo->from_emissive = from_emissive;
    lo->emitter_list = cJSON_IsArray(from_emissive);
    int list_ok = lo->emitter_list && cJSON_GetArraySize(from_emissive) > 0;
    for (const cJSON *it = lo->emitter_list ? from_emissive->child : NULL; it; it = it->next)
        list_ok &= cJSON_IsString(it) && it->valuestring[0] != '\0';
    if (from_emissive && !cJSON_IsBool(from_emissive) && !list_ok) {
        snprintf(err, errlen, "%s: \"lights_from_emissive\" must be true, false or a non-empty list of material names",
                 path);
        return -1;
    }
    lo->emitters = from_emissive ? !cJSON_IsFalse(from_emissive) : !lo->file_lights;
    const cJSON *from_punctual = cJSON_GetObjectItemCaseSensitive(root, "lights_from_punctual");
    if (from_punctual && !cJSON_IsBool(from_punctual)) {
        snprintf(err, errlen, "%s: \"lights_from_punctual\" must be true or false", path);
        return -1;
    }
    lo->punctuals = from_punctual ? cJSON_IsTrue(from_punctual) : !lo->file_lights;
    lo->punctual_radius = 0.05;
    lo->none_ok = 0;
    if (ms_json_number(root, "", "punctual_radius", 0, &lo->punctual_radius, path, err, errlen)) return -1;
    if (!(lo->punctual_radius > 0.0) || lo->punctual_radius > MS_MAX_COORD) {
        snprintf(err, errlen, "%s: \"punctual_radius\" must be in (0, %g]", path, (double)MS_MAX_COORD);
        return -1;
    }
    return 0;
}

int ms_json_asset_lights(ms_scene *out, const ms_json_light_opts *lo, ms_tri_soup *soup, const char *path, char *err,
                         size_t errlen)
{
    unsigned char *lit = NULL;
    if (lo->emitter_list && choose_emitters(out, lo->from_emissive, soup->mat_names, &lit, path, err, errlen)) {
        ms_soup_free_names(soup);
        free(soup->punctual);
        return -1;
    }
    const ms_emitter_choice choice = { lit, soup->mat_names };
    const int lights_failed = add_asset_lights(out, lo->file_lights, lo->emitters, &choice,
                                               lo->punctuals ? soup->punctual : NULL, soup->n_punctual,
                                               lo->punctual_radius, lo->none_ok, path, err, errlen);
    const size_t n_unlisted = lit && !lights_failed ? ms_scene_emissive_triangles(out, NULL) -
                                                          ms_scene_emissive_triangles(out, &choice) : 0;
    ms_soup_free_names(soup);
    free(lit);
    if (lights_failed) {
        free(soup->punctual);
        return -1;
    }
    if (n_unlisted)
        ms_json_warn("%.120s: %zu emissive triangle%s of materials not listed in \"lights_from_emissive\" not made "
                     "lights (they still glow)", path, n_unlisted, n_unlisted > 1 ? "s" : "");
    if (!lo->punctuals && soup->n_punctual)
        ms_json_warn("%.120s: %zu KHR_lights_punctual light%s ignored (the scene file names its lights; "
                     "\"lights_from_punctual\": true adds them)", path, soup->n_punctual, soup->n_punctual > 1 ? "s" : "");
    free(soup->punctual);
    const size_t n_emissive = lo->emitters ? 0 : ms_scene_emissive_triangles(out, NULL);
    if (n_emissive)
        ms_json_warn("%.120s: %zu emissive triangle%s not made lights (the scene file names its lights; "
                     "\"lights_from_emissive\": true adds them)", path, n_emissive, n_emissive > 1 ? "s" : "");
    return 0;
}
