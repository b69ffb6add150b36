#include "microshadow.h"
#include "scene_internal.h"
#include "../camera/camera.h"
#include "../core/vec.h"
#include "../light/light_shape.h"
#include <math.h>
#include <stdio.h>

static int vec_ok(ms_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }
const ms_light *ms_scene_lights(const ms_scene *s, size_t *n)
{
    *n = s->n_lights ? s->n_lights : 1;
    return s->n_lights ? s->lights : &s->light;
}

static int in_range(ms_vec3 v) { return fabsf(v.x) <= MS_MAX_COORD && fabsf(v.y) <= MS_MAX_COORD && fabsf(v.z) <= MS_MAX_COORD; }

/* One light, named `name` ("light", "lights[2]") in messages. */
static int validate_light(const ms_light *l, const char *name, const char *what, char *err, size_t errlen)
{
    if (!vec_ok(l->corner) || !vec_ok(l->edge_s) || !vec_ok(l->edge_t) || !vec_ok(l->emission)) {
        snprintf(err, errlen, "%s: %s has a NaN or infinite value", what, name);
        return -1;
    }
    const ms_light_shape_ops *shape = ms_light_shape_of(l->shape);
    char msg[256];
    if (shape && shape->validate && shape->validate(l, MS_MAX_COORD, msg, sizeof msg)) {
        snprintf(err, errlen, "%s: %s: %s", what, name, msg);
        return -1;
    }
    const float e[3] = { l->emission.x, l->emission.y, l->emission.z };
    for (int c = 0; c < 3; c++)
        if (!(fabsf(e[c]) <= MS_MAX_RADIANCE)) {
            snprintf(err, errlen, "%s: %s emits radiance %g, beyond the limit of %g (emission, or power or lumens over "
                     "pi times the area: a tiny light with a large flux)", what, name, (double)e[c], (double)MS_MAX_RADIANCE);
            return -1;
        }
    if (l->texture) {
        if (l->texture_width < 1 || l->texture_height < 1) {
            snprintf(err, errlen, "%s: %s has a texture of %dx%d texels", what, name, l->texture_width, l->texture_height);
            return -1;
        }
        const size_t n = 3 * (size_t)l->texture_width * (size_t)l->texture_height;
        for (size_t i = 0; i < n; i++)
            if (!(l->texture[i] >= 0.0f && l->texture[i] <= MS_MAX_LIGHT_TEXEL)) {
                snprintf(err, errlen, "%s: %s: texel (%zu, %zu) is %g, outside [0, %g]", what, name,
                         i / 3 % (size_t)l->texture_width, i / 3 / (size_t)l->texture_width, (double)l->texture[i],
                         (double)MS_MAX_LIGHT_TEXEL);
                return -1;
            }
    }
    if (!shape) {
        snprintf(err, errlen, "%s: %s has an unknown shape %d", what, name, (int)l->shape);
        return -1;
    }
    const struct { const char *name; ms_vec3 v; } coords[] = {
        { "corner", l->corner }, { "edge_s", l->edge_s }, { "edge_t", l->edge_t } };
    for (size_t i = 0; i < sizeof coords / sizeof coords[0]; i++)
        if (!in_range(coords[i].v)) {
            snprintf(err, errlen, "%s: %s.%s has a coordinate beyond +-%g (too large for single precision)", what,
                     name, coords[i].name, (double)MS_MAX_COORD);
            return -1;
        }
    float S[3] = { l->edge_s.x, l->edge_s.y, l->edge_s.z }, T[3] = { l->edge_t.x, l->edge_t.y, l->edge_t.z }, n[3];
    v3_cross(n, S, T);
    if (!(v3_len(n) > 1e-6f * v3_len(S) * v3_len(T))) {
        snprintf(err, errlen, "%s: %s has zero area (edge_s and edge_t are zero or parallel)", what, name);
        return -1;
    }
    return 0;
}

ms_status ms_scene_validate(const ms_scene *s, const char *what, char *err, size_t errlen)
{
    const ms_camera *c = &s->camera;
    /* Each type's own number only (the others are unused and may be anything). */
    const float own = c->type == MS_CAMERA_PINHOLE ? c->fov_y : c->type == MS_CAMERA_ORTHOGRAPHIC ? c->ortho_height
                    : c->type == MS_CAMERA_FISHEYE ? c->fov : 0.0f;
    if (!vec_ok(c->eye) || !vec_ok(c->target) || !vec_ok(c->up) || !isfinite(own)) {
        snprintf(err, errlen, "%s: camera has a NaN or infinite value", what);
        return MS_ERR_INVALID;
    }
    size_t nl;
    const ms_light *lights = ms_scene_lights(s, &nl);
    if (s->n_lights && !s->lights) { snprintf(err, errlen, "%s: the scene has no lights array", what); return MS_ERR_INVALID; }
    for (size_t i = 0; i < nl; i++) {
        char name[32];
        if (s->n_lights) snprintf(name, sizeof name, "lights[%zu]", i);
        else snprintf(name, sizeof name, "light");
        if (validate_light(&lights[i], name, what, err, errlen)) return MS_ERR_INVALID;
    }
    /* Beyond 1e18, squared lengths and cross products overflow single precision: the camera basis or
     * the light's area would come out infinite and be misreported as degenerate. */
    const struct { const char *name; ms_vec3 v; } coords[] = {
        { "camera.eye", c->eye }, { "camera.target", c->target }, { "camera.up", c->up } };
    for (size_t i = 0; i < sizeof coords / sizeof coords[0]; i++)
        if (!in_range(coords[i].v)) {
            snprintf(err, errlen, "%s: %s has a coordinate beyond +-%g (too large for single precision)", what,
                     coords[i].name, (double)MS_MAX_COORD);
            return MS_ERR_INVALID;
        }
    switch (c->type) {
    case MS_CAMERA_PINHOLE:
        if (!(c->fov_y > 0.0f && c->fov_y < 180.0f)) {
            snprintf(err, errlen, "%s: camera.fov_y must be in (0, 180) degrees", what);
            return MS_ERR_INVALID;
        }
        break;
    case MS_CAMERA_ORTHOGRAPHIC:
        /* the image's extent, at most MS_MAX_IMAGE_SIZE times its height, keeps the ray origins in range */
        if (!(c->ortho_height > 0.0f && c->ortho_height <= MS_MAX_COORD / MS_MAX_IMAGE_SIZE)) {
            snprintf(err, errlen, "%s: camera.ortho_height must be in (0, %g] world units", what,
                     (double)(MS_MAX_COORD / MS_MAX_IMAGE_SIZE));
            return MS_ERR_INVALID;
        }
        break;
    case MS_CAMERA_FISHEYE:
        if (!(c->fov > 0.0f && c->fov <= 360.0f)) {
            snprintf(err, errlen, "%s: camera.fov must be in (0, 360] degrees", what);
            return MS_ERR_INVALID;
        }
        break;
    case MS_CAMERA_LATLONG:
    case MS_CAMERA_PARABOLIC:
        break;
    default:
        snprintf(err, errlen, "%s: camera.type %d is unknown", what, (int)c->type);
        return MS_ERR_INVALID;
    }
    if (c->width < 1 || c->height < 1 || c->width > MS_MAX_IMAGE_SIZE || c->height > MS_MAX_IMAGE_SIZE) {
        snprintf(err, errlen, "%s: camera width and height must be in [1, %d]", what, MS_MAX_IMAGE_SIZE);
        return MS_ERR_INVALID;
    }
    ms_camera_basis b;
    if (c->eye.x == c->target.x && c->eye.y == c->target.y && c->eye.z == c->target.z) {
        snprintf(err, errlen, "%s: camera.eye equals camera.target", what);
        return MS_ERR_INVALID;
    }
    if (ms_camera_basis_init(&b, c, c->width, c->height)) {
        snprintf(err, errlen, "%s: camera.up is zero or parallel to the view direction", what);
        return MS_ERR_INVALID;
    }
    if (!s->tri && s->procedural.type == MS_PROCEDURAL_NONE && s->n_tris) {
        snprintf(err, errlen, "%s: the scene has no triangle array", what);
        return MS_ERR_INVALID;
    }
    if (s->n_tris == 0) {
        snprintf(err, errlen, "%s: the scene has no triangles", what);
        return MS_ERR_INVALID;
    }
    for (size_t i = 0; s->tri && i < 9 * s->n_tris; i++) {
        if (!isfinite(s->tri[i])) {
            snprintf(err, errlen, "%s: triangle %zu has a NaN or infinite coordinate", what, i / 9);
            return MS_ERR_INVALID;
        }
        if (fabsf(s->tri[i]) > MS_MAX_COORD) {
            snprintf(err, errlen, "%s: triangle %zu has a coordinate beyond +-%g (too large for single precision)", what,
                     i / 9, (double)MS_MAX_COORD);
            return MS_ERR_INVALID;
        }
    }
    /* Surfaces (loaders produce them valid; a library caller may not): every reference in range. */
    for (size_t i = 0; i < s->n_textures; i++) {
        const ms_texture *t = &s->textures[i];
        if (!t->rgba || t->width < 1 || t->height < 1 || t->width > MS_MAX_IMAGE_SIZE || t->height > MS_MAX_IMAGE_SIZE) {
            snprintf(err, errlen, "%s: texture %zu has no pixels or a size outside 1..%d", what, i, MS_MAX_IMAGE_SIZE);
            return MS_ERR_INVALID;
        }
    }
    for (size_t i = 0; i < s->n_materials; i++) {
        const ms_material *m = &s->materials[i];
        int ok = m->metallic >= 0.0f && m->metallic <= 1.0f && m->roughness >= 0.0f && m->roughness <= 1.0f;
        for (int c = 0; c < 4; c++) ok &= m->base_color[c] >= 0.0f && m->base_color[c] <= 1.0f;
        if (!ok) { snprintf(err, errlen, "%s: material %zu has a factor outside [0, 1] (or NaN)", what, i); return MS_ERR_INVALID; }
        if (m->base_color_texture < -1 || (m->base_color_texture >= 0 && (size_t)m->base_color_texture >= s->n_textures) ||
            m->base_color_uv < 0 || m->base_color_uv >= MS_MAX_UV_SETS) {
            snprintf(err, errlen, "%s: material %zu names a texture or UV set that does not exist", what, i);
            return MS_ERR_INVALID;
        }
        if (m->alpha_mode < MS_ALPHA_OPAQUE || m->alpha_mode > MS_ALPHA_MASK_MAP ||
            (m->alpha_mode != MS_ALPHA_OPAQUE && !(m->alpha_cutoff >= 0.0f && m->alpha_cutoff <= 1.0f)) ||
            (m->alpha_mode == MS_ALPHA_MASK_MAP &&
             (m->alpha_texture < -1 || (m->alpha_texture >= 0 && (size_t)m->alpha_texture >= s->n_textures)))) {
            snprintf(err, errlen, "%s: material %zu has a bad alpha mode, cutoff (outside [0, 1]) or alpha texture", what, i);
            return MS_ERR_INVALID;
        }
        /* issue 30's fields: samplers, maps and emission */
        const ms_texture_sampling *sm[4] = { &m->base_color_sampling, &m->normal_sampling, &m->emissive_sampling, &m->mr_sampling };
        const int32_t map[3] = { m->normal_map, m->emissive_map, m->mr_map }, tex[3] = { m->normal_texture, m->emissive_texture, m->mr_texture },
                      set[3] = { m->normal_uv, m->emissive_uv, m->mr_uv };
        ok = isfinite(m->normal_scale) && fabsf(m->normal_scale) <= 1e6f;
        for (int c = 0; c < 3; c++) ok &= m->emissive[c] >= 0.0f && m->emissive[c] <= 1e30f;
        for (int k = 0; k < 4; k++) {
            ok &= sm[k]->wrap_s >= MS_WRAP_REPEAT && sm[k]->wrap_s <= MS_WRAP_MIRROR && sm[k]->wrap_t >= MS_WRAP_REPEAT &&
                  sm[k]->wrap_t <= MS_WRAP_MIRROR;
            for (int c = 0; c < 6; c++) ok &= isfinite(sm[k]->transform[c]) && fabsf(sm[k]->transform[c]) <= 1e6f;
        }
        for (int k = 0; k < 3; k++)
            ok &= !map[k] || (map[k] == 1 && tex[k] >= 0 && (size_t)tex[k] < s->n_textures && set[k] >= 0 && set[k] < MS_MAX_UV_SETS);
        if (!ok) {
            snprintf(err, errlen, "%s: material %zu has a bad sampler, transform, normal, emissive or metallic-roughness map, or emission "
                     "(negative, non-finite or beyond 1e30)", what, i);
            return MS_ERR_INVALID;
        }
    }
    for (size_t i = 0; s->tri_material && i < s->n_tris; i++)
        if (s->tri_material[i] != MS_NO_MATERIAL && s->tri_material[i] >= s->n_materials) {
            snprintf(err, errlen, "%s: triangle %zu names material %u of %zu", what, i, s->tri_material[i], s->n_materials);
            return MS_ERR_INVALID;
        }
    return MS_OK;
}
