/* Scene files: JSON (cJSON) naming meshes (assimp), camera, light and render settings. */
#include "microshadow.h"
#include "scene_internal.h"
#include <cjson/cJSON.h>
#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static char *read_file(const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (!f) { snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno)); return NULL; }
    char *buf = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (len + 4096 + 1 > cap) {
            cap = cap ? 2 * cap : 65536;
            char *nb = realloc(buf, cap);
            if (!nb) { free(buf); fclose(f); snprintf(err, errlen, "%s: out of memory", path); return NULL; }
            buf = nb;
        }
        size_t n = fread(buf + len, 1, cap - len - 1, f);
        len += n;
        if (n == 0) break;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) { free(buf); snprintf(err, errlen, "%s: cannot read: %s", path, strerror(errno)); return NULL; }
    buf[len] = 0;
    return buf;
}

/* Reads key as an array of three finite numbers. */
static int get_vec3(const cJSON *obj, const char *objname, const char *key, int required, ms_vec3 *out,
                    const char *path, char *err, size_t errlen)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!a) {
        if (!required) return 0;
        snprintf(err, errlen, "%s: %s.%s is missing", path, objname, key);
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
        v[i] = (float)x->valuedouble;
    }
    out->x = v[0]; out->y = v[1]; out->z = v[2];
    return 0;
}

static int get_number(const cJSON *obj, const char *objname, const char *key, int required, double *out,
                      const char *path, char *err, size_t errlen)
{
    const cJSON *x = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!x) {
        if (!required) return 0;
        snprintf(err, errlen, "%s: %s.%s is missing", path, objname, key);
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
    if (!o) { snprintf(err, errlen, "%s: \"%s\" is missing", path, key); return NULL; }
    if (!cJSON_IsObject(o)) { snprintf(err, errlen, "%s: \"%s\" must be an object", path, key); return NULL; }
    return o;
}

int ms_scene_load(const char *json_path, ms_scene *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    char *text = read_file(json_path, err, errlen);
    if (!text) return -1;
    const char *where = NULL;
    cJSON *root = cJSON_ParseWithOpts(text, &where, 1);
    if (!root) {
        long off = where ? (long)(where - text) : -1;
        int line = 1;
        for (long i = 0; i < off && text[i]; i++) line += text[i] == '\n';
        snprintf(err, errlen, "%s: malformed JSON near line %d", json_path, line);
        free(text);
        return -1;
    }
    free(text);
    int rc = -1;
    if (!cJSON_IsObject(root)) { snprintf(err, errlen, "%s: the top level must be an object", json_path); goto done; }

    const cJSON *cam = get_object(root, "camera", json_path, err, errlen);
    if (!cam) goto done;
    ms_camera *c = &out->camera;
    double fov = 60.0;
    c->width = 1024; c->height = 1024;
    if (get_vec3(cam, "camera", "eye", 1, &c->eye, json_path, err, errlen) ||
        get_vec3(cam, "camera", "target", 1, &c->target, json_path, err, errlen) ||
        get_vec3(cam, "camera", "up", 1, &c->up, json_path, err, errlen) ||
        get_number(cam, "camera", "fov_y", 1, &fov, json_path, err, errlen) ||
        get_int(cam, "camera", "width", 0, 1, MS_MAX_IMAGE_SIZE, &c->width, json_path, err, errlen) ||
        get_int(cam, "camera", "height", 0, 1, MS_MAX_IMAGE_SIZE, &c->height, json_path, err, errlen))
        goto done;
    c->fov_y = (float)fov;

    const cJSON *light = get_object(root, "light", json_path, err, errlen);
    if (!light) goto done;
    ms_light *l = &out->light;
    l->emission = (ms_vec3){ MS_DEFAULT_EMISSION, MS_DEFAULT_EMISSION, MS_DEFAULT_EMISSION };
    if (get_vec3(light, "light", "corner", 1, &l->corner, json_path, err, errlen) ||
        get_vec3(light, "light", "edge_s", 1, &l->edge_s, json_path, err, errlen) ||
        get_vec3(light, "light", "edge_t", 1, &l->edge_t, json_path, err, errlen) ||
        get_vec3(light, "light", "emission", 0, &l->emission, json_path, err, errlen))
        goto done;
    if (l->emission.x < 0 || l->emission.y < 0 || l->emission.z < 0) {
        snprintf(err, errlen, "%s: light.emission must not be negative", json_path);
        goto done;
    }

    out->samples = 1024;
    const cJSON *render = cJSON_GetObjectItemCaseSensitive(root, "render");
    if (render) {
        if (!cJSON_IsObject(render)) { snprintf(err, errlen, "%s: \"render\" must be an object", json_path); goto done; }
        if (get_int(render, "render", "samples", 0, 1, 1 << 20, &out->samples, json_path, err, errlen)) goto done;
    }

    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(root, "meshes");
    if (!meshes) { snprintf(err, errlen, "%s: \"meshes\" is missing", json_path); goto done; }
    if (!cJSON_IsArray(meshes) || cJSON_GetArraySize(meshes) == 0) {
        snprintf(err, errlen, "%s: \"meshes\" must be a non-empty array of {\"file\": ...}", json_path);
        goto done;
    }
    char *dircopy = strdup(json_path);
    if (!dircopy) { snprintf(err, errlen, "%s: out of memory", json_path); goto done; }
    const char *dir = dirname(dircopy);
    ms_tri_soup soup = { 0 };
    int i = 0;
    const cJSON *m;
    cJSON_ArrayForEach(m, meshes) {
        const cJSON *file = cJSON_IsObject(m) ? cJSON_GetObjectItemCaseSensitive(m, "file") : NULL;
        if (!cJSON_IsString(file) || !file->valuestring[0]) {
            snprintf(err, errlen, "%s: meshes[%d].file must be a non-empty string", json_path, i);
            goto mesh_fail;
        }
        char mesh_path[4096];
        if (file->valuestring[0] == '/') snprintf(mesh_path, sizeof mesh_path, "%s", file->valuestring);
        else snprintf(mesh_path, sizeof mesh_path, "%s/%s", dir, file->valuestring);
        if (ms_mesh_load(mesh_path, &soup, err, errlen)) goto mesh_fail;
        i++;
    }
    free(dircopy);
    out->tri = soup.tri;
    out->n_tris = soup.n;
    rc = ms_scene_validate(out, json_path, err, errlen);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    out->load_s = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    goto done;
mesh_fail:
    free(dircopy);
    free(soup.tri);
done:
    cJSON_Delete(root);
    if (rc) ms_scene_free(out);
    return rc;
}

void ms_scene_free(ms_scene *s)
{
    free(s->tri);
    memset(s, 0, sizeof *s);
}
