/* Scene files: JSON (cJSON) naming meshes (mesh_load.c), camera, light and render settings. The getters and
 * key checks are scene_json_get.c's, the lights scene_json_lights.c's; here the load and its steps. */
#include "microshadow.h"
#include "scene_internal.h"
#include "scene_json_get.h"
#include "scene_json_lights.h"
#include "mesh_transform.h"
#include "core/abi.h"
_Static_assert(MS_SOUP_UV_SETS == MS_MAX_UV_SETS, "one count of UV sets");
#include <cjson/cJSON.h>
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

int ms_path_beside(const char *json_path, const char *rel, char *out, size_t n)
{
    if (rel[0] == '/') return snprintf(out, n, "%s", rel) >= (int)n ? -1 : 0;
    char *dircopy = strdup(json_path);
    if (!dircopy) return -1;
    const int k = snprintf(out, n, "%s/%s", dirname(dircopy), rel);
    free(dircopy);
    return k < 0 || (size_t)k >= n ? -1 : 0;
}

/* The JSON tree of text; NULL (err set, with the line) for a NUL byte, a \u0000 or malformed JSON. */
static cJSON *parse_text(const char *text, size_t len, const char *json_path, char *err, size_t errlen)
{
    const char *nul = memchr(text, 0, len);
    if (nul) {
        snprintf(err, errlen, "%s: line %d: a NUL byte (not a JSON text file)", json_path, line_of(text, (size_t)(nul - text)));
        return NULL;
    }
    /* cJSON decodes \u0000 into a NUL inside the string, which then silently ends it (a mesh path
     * would be cut): refuse it. Backslashes only occur inside strings in valid JSON. */
    for (size_t i = 0; i + 1 < len; i++)
        if (text[i] == '\\') {
            if (text[i + 1] == 'u' && i + 6 <= len && !memcmp(text + i + 2, "0000", 4)) {
                snprintf(err, errlen, "%s: line %d: a string contains \\u0000 (NUL is not allowed)", json_path, line_of(text, i));
                return NULL;
            }
            i++;
        }
    const char *where = NULL;
    cJSON *root = cJSON_ParseWithOpts(text, &where, 1);
    if (!root) {
        size_t off = where ? (size_t)(where - text) : 0;
        snprintf(err, errlen, "%s: malformed JSON near line %d", json_path, line_of(text, off));
        return NULL;
    }
    return root;
}

/* "camera" into out->camera: its type (which sets the keys it reads), the common keys and the type's own
 * number. Returns the camera's object (its eye and target are framed later), NULL on error. */
static const cJSON *parse_camera(const cJSON *root, ms_scene *out, const char *json_path, char *err, size_t errlen)
{
    const cJSON *cam = ms_json_object(root, "camera", json_path, err, errlen);
    if (!cam) return NULL;
    size_t ct = 0;   /* ms_json_camera_types[0]: pinhole, when "type" is absent */
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(cam, "type");
    if (type) {
        ct = ms_json_n_camera_types;
        for (size_t i = 0; cJSON_IsString(type) && i < ct; i++)
            if (!strcmp(type->valuestring, ms_json_camera_types[i].name)) ct = i;
        if (ct == ms_json_n_camera_types) {
            snprintf(err, errlen, "%s: camera.type must be \"pinhole\", \"orthographic\", \"fisheye\", \"latlong\" or "
                     "\"parabolic\"", json_path);
            return NULL;
        }
    }
    const ms_json_camera_type *t = &ms_json_camera_types[ct];
    ms_json_camera_keys = t->keys;
    ms_json_warn_camera_keys(cam, t->name, json_path);
    ms_json_warn_unknown_except(cam, "camera", ms_json_camera_keys, ms_json_camera_keys_any, json_path);
    ms_camera *c = &out->camera;
    c->type = t->type;
    c->width = 1024; c->height = 1024;
    if (ms_json_vec3(cam, "camera", "eye", 1, &c->eye, json_path, err, errlen) ||
        ms_json_vec3(cam, "camera", "target", 1, &c->target, json_path, err, errlen) ||
        ms_json_vec3(cam, "camera", "up", 1, &c->up, json_path, err, errlen) ||
        ms_json_int(cam, "camera", "width", 0, 1, MS_MAX_IMAGE_SIZE, &c->width, json_path, err, errlen) ||
        ms_json_int(cam, "camera", "height", 0, 1, MS_MAX_IMAGE_SIZE, &c->height, json_path, err, errlen))
        return NULL;
    /* The type's own number (pinhole fov_y, orthographic ortho_height, fisheye fov), required; its range
     * is checked with the scene (ms_scene_validate), for scenes built through the API too. */
    if (t->own) {
        double v = 0.0;
        if (ms_json_number(cam, "camera", t->own, 1, &v, json_path, err, errlen) ||
            ms_json_float_ok(v, "camera", t->own, -1, json_path, err, errlen))
            return NULL;
        if (c->type == MS_CAMERA_PINHOLE) c->fov_y = (float)v;
        else if (c->type == MS_CAMERA_ORTHOGRAPHIC) c->ortho_height = (float)v;
        else c->fov = (float)v;
    }
    return cam;
}

/* "render": samples (1024 by default) and aa. */
static int parse_render(const cJSON *root, ms_scene *out, const char *json_path, char *err, size_t errlen)
{
    out->samples = 1024;
    const cJSON *render = cJSON_GetObjectItemCaseSensitive(root, "render");
    if (!render) return 0;
    if (!cJSON_IsObject(render)) { snprintf(err, errlen, "%s: \"render\" must be an object", json_path); return -1; }
    ms_json_warn_unknown(render, "render", ms_json_render_keys, json_path);
    if (ms_json_int(render, "render", "samples", 0, 1, 1 << 20, &out->samples, json_path, err, errlen)) return -1;
    if (cJSON_GetObjectItemCaseSensitive(render, "aa")) {   /* absent: 0, the caller's default */
        int aa = 1;
        if (ms_json_int(render, "render", "aa", 1, 1, 16, &aa, json_path, err, errlen)) return -1;
        if (aa != 1 && aa != 4 && aa != 9 && aa != 16) {
            snprintf(err, errlen, "%s: render.aa must be 1, 4, 9 or 16 (got %d)", json_path, aa);
            return -1;
        }
        out->aa = aa;
    }
    return 0;
}

/* "procedural" (in place of "meshes", has_meshes: the file gives both): the generated scene's type, size
 * and seed. */
static int parse_procedural(const cJSON *root, const cJSON *proc, int has_meshes, int file_lights, ms_scene *out,
                            const char *json_path, char *err, size_t errlen)
{
    if (has_meshes) { snprintf(err, errlen, "%s: give either \"meshes\" or \"procedural\", not both", json_path); return -1; }
    if (!cJSON_IsObject(proc)) { snprintf(err, errlen, "%s: \"procedural\" must be an object", json_path); return -1; }
    ms_json_warn_unknown(proc, "procedural", ms_json_procedural_keys, json_path);
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(proc, "type");
    if (!cJSON_IsString(type) || strcmp(type->valuestring, "flowers") != 0) {
        snprintf(err, errlen, "%s: procedural.type must be \"flowers\"", json_path);
        return -1;
    }
    double tris = 0, seed = 0;
    if (ms_json_number(proc, "procedural", "triangles", 1, &tris, json_path, err, errlen) ||
        ms_json_number(proc, "procedural", "seed", 0, &seed, json_path, err, errlen))
        return -1;
    /* prim ids are 32-bit with UINT32_MAX for a miss; 2^31 keeps far from it */
    if (tris != floor(tris) || tris < 1 || tris > 2147483648.0) {
        snprintf(err, errlen, "%s: procedural.triangles must be an integer in [1, 2^31]", json_path);
        return -1;
    }
    if (seed != floor(seed) || seed < 0 || seed > 4294967295.0) {
        snprintf(err, errlen, "%s: procedural.seed must be an integer in [0, 2^32 - 1]", json_path);
        return -1;
    }
    out->procedural.type = MS_PROCEDURAL_FLOWERS;
    out->procedural.seed = (uint32_t)seed;
    out->n_tris = (size_t)tris;
    if (!file_lights) { ms_json_missing(root, "", "light", json_path, err, errlen); return -1; }   /* no emitters here */
    return 0;
}

/* Per entry: its triangles [from, to) and transform, applied once every file is read; a file listed
 * again (same path) is copied from its first entry rather than read again. */
typedef struct mesh_entry { char *path; size_t from, to; int has_xf; double xf[12]; float lightmap_scale; } mesh_entry;

/* meshes[i].lightmap into e->lightmap_scale. */
static int mesh_lightmap(const cJSON *m, int i, mesh_entry *e, const char *json_path, char *err, size_t errlen)
{
    /* "lightmap": false (not baked, still casts) or {"scale": s} (texel density weight) */
    const cJSON *lmk = cJSON_GetObjectItemCaseSensitive(m, "lightmap");
    e->lightmap_scale = 1.0f;
    if (!lmk) return 0;
    if (cJSON_IsFalse(lmk)) e->lightmap_scale = 0.0f;
    else if (cJSON_IsTrue(lmk)) e->lightmap_scale = 1.0f;
    else if (cJSON_IsObject(lmk)) {
        char lname[48];
        snprintf(lname, sizeof lname, "meshes[%d].lightmap", i);
        ms_json_warn_unknown(lmk, lname, ms_json_mesh_lightmap_keys, json_path);
        const cJSON *sc = cJSON_GetObjectItemCaseSensitive(lmk, "scale");
        if (sc && !(cJSON_IsNumber(sc) && sc->valuedouble > 0.0 && sc->valuedouble <= 1e3)) {
            snprintf(err, errlen, "%s: meshes[%d].lightmap.scale must be a number in (0, 1000]", json_path, i);
            return -1;
        }
        if (sc) e->lightmap_scale = (float)sc->valuedouble;
    } else {
        snprintf(err, errlen, "%s: meshes[%d].lightmap must be false, true or {\"scale\": s}", json_path, i);
        return -1;
    }
    return 0;
}

/* meshes[i] (m), its file beside the scene file (dir) or absolute: its keys, and its triangles appended to
 * soup (ent[i]; ent[0 .. i-1]: the entries before it). */
static int mesh_entry_load(const cJSON *m, int i, const char *dir, mesh_entry *ent, ms_tri_soup *soup,
                           const char *json_path, char *err, size_t errlen)
{
    const cJSON *file = cJSON_IsObject(m) ? cJSON_GetObjectItemCaseSensitive(m, "file") : NULL;
    if (!cJSON_IsString(file) || !file->valuestring[0]) {
        snprintf(err, errlen, "%s: meshes[%d].file must be a non-empty string", json_path, i);
        return -1;
    }
    char objname[32];
    snprintf(objname, sizeof objname, "meshes[%d]", i);
    ms_json_warn_unknown(m, objname, ms_json_mesh_keys, json_path);
    char mesh_path[4096];
    int n = file->valuestring[0] == '/' ? snprintf(mesh_path, sizeof mesh_path, "%s", file->valuestring)
                                        : snprintf(mesh_path, sizeof mesh_path, "%s/%s", dir, file->valuestring);
    if (n < 0 || (size_t)n >= sizeof mesh_path) {
        snprintf(err, errlen, "%s: meshes[%d].file: the path is longer than %zu bytes", json_path, i, sizeof mesh_path - 1);
        return -1;
    }
    const cJSON *xf = cJSON_GetObjectItemCaseSensitive(m, "transform");
    if (xf && ms_mesh_transform_parse(xf, objname, json_path, ent[i].xf, err, errlen)) return -1;
    ent[i].has_xf = xf != NULL;
    if (mesh_lightmap(m, i, &ent[i], json_path, err, errlen)) return -1;
    soup->cur_mesh = (uint32_t)i;
    ms_soup_new_object(soup);
    ent[i].from = soup->n;
    int j = 0;
    while (j < i && strcmp(ent[j].path, mesh_path)) j++;
    if (j < i) {
        if (ms_soup_copy_range(soup, ent[j].from, ent[j].to)) { snprintf(err, errlen, "%s: out of memory", json_path); return -1; }
    } else if (ms_mesh_load(mesh_path, soup, err, errlen)) {
        return -1;
    }
    ent[i].to = soup->n;
    if (!(ent[i].path = strdup(mesh_path))) { snprintf(err, errlen, "%s: out of memory", json_path); return -1; }
    return 0;
}

/* "meshes": every entry's triangles into soup, each transformed by its entry's transform (and its punctual
 * lights with it), and out->mesh_lightmap_scale; *n_meshes: how many entries. On a failure once the soup
 * holds triangles, the soup is freed. */
static int parse_meshes(const cJSON *root, const cJSON *meshes, const ms_scene_load_options *opt, ms_scene *out,
                        ms_tri_soup *soup, int *n_meshes, const char *json_path, char *err, size_t errlen)
{
    if (!meshes) { ms_json_missing(root, "", "meshes", json_path, err, errlen); return -1; }
    if (!cJSON_IsArray(meshes) || cJSON_GetArraySize(meshes) == 0) {
        snprintf(err, errlen, "%s: \"meshes\" must be a non-empty array of {\"file\": ...}", json_path);
        return -1;
    }
    char *dircopy = strdup(json_path);
    if (!dircopy) { snprintf(err, errlen, "%s: out of memory", json_path); return -1; }
    const char *dir = dirname(dircopy);
    /* Files the meshes name (glTF buffers and images, MTL files and maps) stay inside the meshes' folders
     * unless the scene file or the caller trusts the assets (ms_resolve_inside). */
    const cJSON *allow = cJSON_GetObjectItemCaseSensitive(root, "allow_outside_paths");
    if (allow && !cJSON_IsBool(allow)) {
        snprintf(err, errlen, "%s: \"allow_outside_paths\" must be true or false", json_path);
        free(dircopy);
        return -1;
    }
    soup->allow_outside_paths = (allow && cJSON_IsTrue(allow)) || (opt && opt->allow_outside_paths);
    int i = 0;
    const cJSON *m;
    mesh_entry *ent = calloc((size_t)cJSON_GetArraySize(meshes), sizeof *ent);
    if (!ent) { snprintf(err, errlen, "%s: out of memory", json_path); free(dircopy); return -1; }
    cJSON_ArrayForEach(m, meshes) {
        if (mesh_entry_load(m, i, dir, ent, soup, json_path, err, errlen)) {
            for (int k = 0; k <= i; k++) free(ent[k].path);
            free(ent);
            free(dircopy);
            ms_soup_free(soup);
            return -1;
        }
        i++;
    }
    float *lm_scale = malloc((i ? (size_t)i : 1) * sizeof *lm_scale);
    if (!lm_scale) {
        snprintf(err, errlen, "%s: out of memory", json_path);
        for (int k = 0; k < i; k++) free(ent[k].path);
        free(ent);
        free(dircopy);
        ms_soup_free(soup);
        return -1;
    }
    for (int k = 0; k < i; k++) {
        if (ent[k].has_xf) ms_soup_transform(soup, ent[k].from, ent[k].to, ent[k].xf);
        lm_scale[k] = ent[k].lightmap_scale;
        for (size_t q = 0; q < soup->n_punctual && ent[k].has_xf; q++)
            if (soup->punctual[q].mesh == (uint32_t)k) ms_json_punctual_transform(&soup->punctual[q], ent[k].xf);
        free(ent[k].path);
    }
    out->mesh_lightmap_scale = lm_scale;
    free(ent);
    free(dircopy);
    *n_meshes = i;
    return 0;
}

/* The camera's eye and target and the lights' positions in the scene's frame (out->origin), from the
 * numbers of the file; nothing changes when the frame is the world's. */
static void frame_camera_lights(const cJSON *cam, ms_scene *out, const light_pos *lp)
{
    const double *o = out->origin;
    if (!cam || (o[0] == 0.0 && o[1] == 0.0 && o[2] == 0.0)) return;   /* no camera: an asset's (scene_asset.c) */
    double p[3];
    float f[3];
    ms_json_vec3_d(cam, "eye", p);
    ms_scene_frame_point(p, o, f);
    out->camera.eye = (ms_vec3){ f[0], f[1], f[2] };
    ms_json_vec3_d(cam, "target", p);
    ms_scene_frame_point(p, o, f);
    out->camera.target = (ms_vec3){ f[0], f[1], f[2] };
    const size_t n = out->n_lights ? out->n_lights : 1;
    for (size_t i = 0; i < n; i++) {
        ms_light *l = out->n_lights ? &out->lights[i] : &out->light;
        char msg[200];
        ms_json_light_build(l, &lp[i], o, msg, sizeof msg);   /* built from the same values at parse time: it succeeds */
    }
    if (out->n_lights) out->light = out->lights[0];
}

/* The soup of n_meshes entries into out: the scene's frame (scene_frame.c), chosen from the triangles'
 * double positions, applied to them, the camera (cam) and the lights (lp), here and nowhere else; then the
 * soup's arrays change hands. */
static void scene_from_soup(ms_scene *out, ms_tri_soup *soup, int n_meshes, const cJSON *cam, const light_pos *lp)
{
    ms_scene_frame_origin(soup->tri_d, soup->n, out->origin);
    ms_scene_frame_apply(soup->tri, soup->tri_d, soup->n, out->origin);
    frame_camera_lights(cam, out, lp);
    free(soup->tri_d);
    soup->tri_d = NULL;
    out->tri = soup->tri;
    out->n_tris = soup->n;
    out->tri_mesh = soup->mesh;
    out->tri_object = soup->object;
    out->n_objects = soup->n_objects;
    for (int s = 0; s < MS_MAX_UV_SETS; s++) out->tri_uv[s] = soup->uv[s];
    out->n_meshes = (size_t)n_meshes;
    out->materials = soup->mats;   /* surfaces: the soup's arrays change hands (ms_scene_free frees them) */
    out->n_materials = soup->n_mats;
    out->tri_material = soup->material;
    out->tri_normal = soup->normal;
    out->tri_tangent = ms_soup_take_tangents(soup);
    out->textures = soup->tex;
    out->n_textures = soup->n_tex;
}

/* The scene of the JSON tree root (the file json_path's; asset: a tree made for an asset given as the scene,
 * ms_scene_asset_path, which has no camera and may have no light). Takes root. */
static int scene_build(cJSON *root, const char *json_path, int asset, const ms_scene_load_options *opt, ms_scene *out,
                       char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int rc = -1;
    if (!cJSON_IsObject(root)) { snprintf(err, errlen, "%s: the top level must be an object", json_path); goto done; }
    if (ms_json_check_duplicates(root, "", json_path, err, errlen)) goto done;
    ms_json_warn_unknown(root, "", ms_json_top_keys, json_path);

    const cJSON *cam = asset ? NULL : parse_camera(root, out, json_path, err, errlen);
    if (!cam && !asset) goto done;
    ms_json_light_opts lo;
    if (ms_json_light_options(root, &lo, json_path, err, errlen)) goto done;
    lo.none_ok = asset;
    light_pos lpos[MS_MAX_LIGHTS];
    memset(lpos, 0, sizeof lpos);
    if (ms_json_parse_lights(root, out, lpos, lo.emitters || lo.punctuals, json_path, err, errlen)) goto done;
    if (parse_render(root, out, json_path, err, errlen)) goto done;

    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(root, "meshes");
    const cJSON *proc = cJSON_GetObjectItemCaseSensitive(root, "procedural");
    if (proc) {
        if (!parse_procedural(root, proc, meshes != NULL, lo.file_lights, out, json_path, err, errlen))
            rc = ms_scene_validate(out, json_path, err, errlen);
        goto done;
    }
    ms_tri_soup soup = { 0 };
    int n_meshes = 0;
    if (parse_meshes(root, meshes, opt, out, &soup, &n_meshes, json_path, err, errlen)) goto done;
    scene_from_soup(out, &soup, n_meshes, cam, lpos);
    if (ms_json_asset_lights(out, &lo, &soup, json_path, err, errlen)) goto done;
    if (asset) {
        const int add_light = out->n_lights == 0;   /* the asset's own lights are appended (n_lights >= 1) */
        if (ms_scene_asset_view(out, &soup.camera, add_light, json_path, err, errlen)) goto done;
        ms_json_warn("%.200s: an asset given as the scene: %s%s; a scene file naming it sets its own (README, Scene "
                     "file)", json_path, soup.camera.present ? "its own camera" : "a camera from its bounding box (Y up)",
                     add_light ? " and, as it has no light of its own, one disk light above it" : "");
    }
    rc = ms_scene_validate(out, json_path, err, errlen);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    out->load_s = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
done:
    cJSON_Delete(root);
    if (rc) ms_scene_free(out);
    return rc;
}

static int scene_parse(const char *text, size_t len, const char *json_path, const ms_scene_load_options *opt,
                       ms_scene *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    cJSON *root = parse_text(text, len, json_path, err, errlen);
    return root ? scene_build(root, json_path, 0, opt, out, err, errlen) : -1;
}

/* The tree of a scene file naming the asset at path alone: {"meshes": [{"file": its name}]} (beside it). */
static int scene_asset(const char *path, const ms_scene_load_options *opt, ms_scene *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    const char *slash = strrchr(path, '/');
    cJSON *root = cJSON_CreateObject();
    cJSON *meshes = root ? cJSON_AddArrayToObject(root, "meshes") : NULL, *m = meshes ? cJSON_CreateObject() : NULL;
    if (m && !cJSON_AddItemToArray(meshes, m)) { cJSON_Delete(m); m = NULL; }
    if (!m || !cJSON_AddStringToObject(m, "file", slash ? slash + 1 : path)) {
        cJSON_Delete(root);
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    return scene_build(root, path, 1, opt, out, err, errlen);
}

/* One parse (text, or the asset at json_path when text is NULL) with its warnings kept (ms_json_warnings)
 * until it succeeded. */
static int parse_with(const char *text, size_t len, const char *json_path, const ms_scene_load_options *opt,
                      ms_scene *out, char *err, size_t errlen)
{
    ms_json_warn_list w;
    w.n = 0;
    ms_json_warnings = &w;
    ms_material_warnings_begin();
    int rc = text ? scene_parse(text, len, json_path, opt, out, err, errlen)
                  : scene_asset(json_path, opt, out, err, errlen);
    ms_json_warnings = NULL;
    if (rc) ms_one_line(err);
    else
        for (int i = 0; i < w.n; i++) ms_warn("%s", w.line[i]);
    ms_material_warnings_end(rc == 0);   /* one line for all the unusable material files and textures */
    return rc;
}

ms_status ms_scene_load_abi(const ms_abi *abi, const char *json_path, const ms_scene_load_options *opt, ms_scene *out,
                            char *err, size_t errlen)
{
    const ms_status st = ms_abi_check(abi, "ms_scene_load", err, errlen);
    if (st) return st;
    ms_scene_load_options own;
    opt = ms_abi_options(opt, MS_ABI_SIZE(abi, scene_load_options), &own, sizeof own);
    memset(out, 0, sizeof *out);
    if (ms_scene_asset_path(json_path))
        return parse_with(NULL, 0, json_path, opt, out, err, errlen) ? MS_ERR_INVALID : MS_OK;
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

int ms_scene_parse(const char *text, size_t len, const char *json_path, ms_scene *out, char *err, size_t errlen)
{
    return parse_with(text, len, json_path, NULL, out, err, errlen);
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
