/* An asset given where a scene file is expected (ms_scene_load on a .gltf, .glb, .obj, .ply, .off or .stl file):
 * the scene of that one mesh, as a scene file naming it alone would give, plus what such a file must add: a
 * camera (a glTF file's own, else one from the asset's bounding box) and, when the asset has no light of its
 * own (KHR_lights_punctual lights, emissive triangles), one disk light. Y is up, glTF's convention and that of
 * most scans; a scene file sets any other view. */
#include "microshadow.h"
#include "scene_internal.h"
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

int ms_scene_asset_path(const char *path)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash) || strlen(dot + 1) > 4) return 0;
    char ext[5] = { 0 };
    for (size_t i = 0; dot[1 + i]; i++) ext[i] = (char)tolower((unsigned char)dot[1 + i]);
    static const char *const mesh_ext[] = { "gltf", "glb", "obj", "ply", "off", "stl" };
    for (size_t i = 0; i < sizeof mesh_ext / sizeof *mesh_ext; i++)
        if (!strcmp(ext, mesh_ext[i])) return 1;
    return 0;
}

static void unit(double v[3])
{
    const double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int a = 0; a < 3; a++) v[a] /= n;
}

/* The asset's own camera in the scene's frame, looking at the distance of the box's centre c. */
static void own_camera(ms_camera *cam, const ms_asset_camera *a, const double o[3], const double c[3])
{
    double dist = 0.0;
    for (int k = 0; k < 3; k++) dist += (c[k] - (a->eye[k] - o[k])) * a->dir[k];
    dist = dist > 1e-3 ? dist : 1.0;
    cam->type = a->ortho ? MS_CAMERA_ORTHOGRAPHIC : MS_CAMERA_PINHOLE;
    cam->eye = (ms_vec3){ (float)(a->eye[0] - o[0]), (float)(a->eye[1] - o[1]), (float)(a->eye[2] - o[2]) };
    cam->target = (ms_vec3){ (float)(a->eye[0] - o[0] + dist * a->dir[0]), (float)(a->eye[1] - o[1] + dist * a->dir[1]),
                             (float)(a->eye[2] - o[2] + dist * a->dir[2]) };
    cam->up = (ms_vec3){ (float)a->up[0], (float)a->up[1], (float)a->up[2] };
    cam->fov_y = a->yfov_deg;
    cam->ortho_height = 2.0f * a->ymag;
    cam->width = 1024;
    const double h = a->aspect > 0.0f ? 1024.0 / a->aspect : 768.0;
    cam->height = h < 1.0 ? 1 : h > MS_MAX_IMAGE_SIZE ? MS_MAX_IMAGE_SIZE : (int)lround(h);
}

/* A camera from the front, right and above the box of centre c and diagonal r (Y up), at the distance where
 * its bounding sphere (radius r / 2) fills the 45 degree height with a margin. */
static void box_camera(ms_camera *cam, const double c[3], double r)
{
    double d[3] = { 0.6, 0.5, 1.0 };
    unit(d);
    const double dist = 1.35 * r;
    cam->type = MS_CAMERA_PINHOLE;
    cam->eye = (ms_vec3){ (float)(c[0] + dist * d[0]), (float)(c[1] + dist * d[1]), (float)(c[2] + dist * d[2]) };
    cam->target = (ms_vec3){ (float)c[0], (float)c[1], (float)c[2] };
    cam->up = (ms_vec3){ 0.0f, 1.0f, 0.0f };
    cam->fov_y = 45.0f;
    cam->width = 1024;
    cam->height = 768;
}

int ms_scene_asset_view(ms_scene *s, const ms_asset_camera *own, int add_light, const char *path, char *err,
                        size_t errlen)
{
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (size_t i = 0; i < 9 * s->n_tris; i++) {
        const double x = s->tri[i];
        lo[i % 3] = x < lo[i % 3] ? x : lo[i % 3];
        hi[i % 3] = x > hi[i % 3] ? x : hi[i % 3];
    }
    double c[3], r = 0.0;
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5 * (lo[a] + hi[a]);
        r += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    r = sqrt(r);
    if (!(r > 0.0) || !isfinite(r)) {
        snprintf(err, errlen, "%s: the asset has no extent to place a camera and a light by", path);
        return -1;
    }
    ms_camera *cam = &s->camera;
    memset(cam, 0, sizeof *cam);
    if (own && own->present) own_camera(cam, own, s->origin, c);
    else box_camera(cam, c, r);
    if (!add_light) return 0;
    /* The light: above, left of the camera and in front, so that the shadows it casts fall where the camera
     * sees them; radius 0.15 r; radiance such that it gives about pi of irradiance at the centre (the frame
     * exposes itself; a bake's figures stay near 1). */
    double ld[3] = { -0.5, 1.0, 0.6 };
    unit(ld);
    const double ldist = 1.5 * r, rad = 0.15 * r, L = (ldist * ldist + rad * rad) / (rad * rad);
    const ms_vec3 p = { (float)(c[0] + ldist * ld[0]), (float)(c[1] + ldist * ld[1]), (float)(c[2] + ldist * ld[2]) };
    const ms_vec3 m = { (float)-ld[0], (float)-ld[1], (float)-ld[2] };
    ms_light l;
    memset(&l, 0, sizeof l);
    if (ms_light_disk(&l, p, m, (float)rad) != MS_OK) {
        snprintf(err, errlen, "%s: the default light could not be placed (extent %g)", path, r);
        return -1;
    }
    l.emission = (ms_vec3){ (float)L, (float)L, (float)L };
    s->light = l;
    s->n_lights = 0;
    return 0;
}
