/* The scene's lights and camera written into the glb's scene extras (bake_gltf_lights.h): the lights exactly as
 * the bake lit the lightmap (units converted to radiance, the asset's emitters and punctual lights included, in
 * the order the shadowmask's channels name them), and the camera, so that a viewer need not re-read the scene
 * file (an asset baked alone has none). */
#include "bake_gltf_lights.h"
#include "light/light_shape.h"
#include <math.h>

static void add_vec(cJSON *o, const char *key, const double v[3])
{
    cJSON *a = cJSON_AddArrayToObject(o, key);
    for (int c = 0; c < 3; c++) cJSON_AddItemToArray(a, cJSON_CreateNumber(v[c]));
}

/* A point of the scene's frame in world coordinates (the root node's translation is the origin). */
static void add_point(cJSON *o, const char *key, ms_vec3 p, const double origin[3])
{
    const double w[3] = { (double)p.x + origin[0], (double)p.y + origin[1], (double)p.z + origin[2] };
    add_vec(o, key, w);
}

static void add_dir(cJSON *o, const char *key, ms_vec3 d)
{
    const double v[3] = { d.x, d.y, d.z };
    add_vec(o, key, v);
}

/* The light's radiance: its emission, times its mean texel colour when textured (a viewer's analytic light
 * emits uniformly; the mean keeps its power). */
static void add_radiance(cJSON *o, const ms_light *l)
{
    double r[3] = { l->emission.x, l->emission.y, l->emission.z };
    if (l->texture && l->texture_width > 0 && l->texture_height > 0) {
        const size_t n = (size_t)l->texture_width * (size_t)l->texture_height;
        double m[3] = { 0, 0, 0 };
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) m[c] += l->texture[3 * i + c];
        for (int c = 0; c < 3; c++) r[c] *= m[c] / (double)n;
        cJSON_AddBoolToObject(o, "textured", 1);
    }
    add_vec(o, "radiance", r);
}

void ms_bake_gltf_lights(cJSON *ms, const ms_scene *sc)
{
    size_t nl;
    const ms_light *L = ms_scene_lights(sc, &nl);
    cJSON *arr = cJSON_AddArrayToObject(ms, "lights");
    for (size_t i = 0; i < nl; i++) {
        const ms_light *l = &L[i];
        const ms_light_shape_ops *o = ms_light_shape_of(l->shape);
        cJSON *j = cJSON_CreateObject();
        cJSON_AddStringToObject(j, "shape", o ? o->name : "rect");
        if (l->shape == MS_LIGHT_SPHERE) {
            add_point(j, "center", l->center, sc->origin);
            cJSON_AddNumberToObject(j, "radius", l->radius);
        } else if (l->shape == MS_LIGHT_SUN) {
            /* ms_light_sun: the bounding square of the disk of radius tan(alpha) at unit distance */
            const double es = sqrt((double)l->edge_s.x * l->edge_s.x + (double)l->edge_s.y * l->edge_s.y +
                                   (double)l->edge_s.z * l->edge_s.z);
            add_dir(j, "direction", l->center);
            cJSON_AddNumberToObject(j, "angular_diameter_deg", 2.0 * atan(0.5 * es) * 180.0 / M_PI);
        } else {
            add_point(j, "corner", l->corner, sc->origin);
            add_dir(j, "edge_s", l->edge_s);
            add_dir(j, "edge_t", l->edge_t);
        }
        add_radiance(j, l);
        cJSON_AddItemToArray(arr, j);
    }
}

void ms_bake_gltf_camera(cJSON *ms, const ms_scene *sc)
{
    const ms_camera *c = &sc->camera;
    if (c->type != MS_CAMERA_PINHOLE) return;
    cJSON *j = cJSON_AddObjectToObject(ms, "camera");
    add_point(j, "eye", c->eye, sc->origin);
    add_point(j, "target", c->target, sc->origin);
    add_dir(j, "up", c->up);
    cJSON_AddNumberToObject(j, "fov_y", c->fov_y);
    cJSON_AddNumberToObject(j, "width", c->width);
    cJSON_AddNumberToObject(j, "height", c->height);
}
