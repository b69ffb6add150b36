/* Scene files' lights (scene_json_lights.c): "light" / "lights", and the asset's own lights (its emitters and
 * KHR_lights_punctual lights) after those the file names. */
#ifndef MS_SCENE_JSON_LIGHTS_H
#define MS_SCENE_JSON_LIGHTS_H

#include "microshadow.h"
#include "scene_internal.h"
#include "light/light_shape.h"
#include <cjson/cJSON.h>
#include <stddef.h>

/* A light's shape and the values of its geometry keys as the file gives them: what re-derives the light in
 * the scene's frame. */
typedef struct light_pos { const ms_light_shape_ops *shape; ms_light_params v; } light_pos;

/* Where the lights come from: the top-level keys "lights_from_emissive", "lights_from_punctual" and
 * "punctual_radius", and whether the file names lights of its own. */
typedef struct ms_json_light_opts {
    int file_lights;                /* the file has "light" or "lights" */
    const cJSON *from_emissive;     /* "lights_from_emissive" (NULL: absent) */
    int emitter_list;               /* it is a list of material names */
    int emitters;                   /* the asset's emissive triangles become lights */
    int punctuals;                  /* its KHR_lights_punctual lights do */
    double punctual_radius;
    int none_ok;                    /* no light at all is not an error (an asset given as the scene) */
} ms_json_light_opts;

int ms_json_light_options(const cJSON *root, ms_json_light_opts *lo, const char *path, char *err, size_t errlen);
/* lp: MS_MAX_LIGHTS positions as the file gives them (scene_frame.c). none_ok: the file may name no light
 * (the emitters will be the lights; nothing is set then). */
int ms_json_parse_lights(const cJSON *root, ms_scene *out, light_pos *lp, int none_ok, const char *path, char *err,
                         size_t errlen);
/* Builds l's geometry from the values of its shape's keys with the scene's origin o subtracted from its points
 * (in double, then rounded once, as ms_scene_frame_point). */
int ms_json_light_build(ms_light *l, const light_pos *lp, const double o[3], char *msg, size_t n);
/* A glTF file's mesh-entry transform m (3 x 4, row-major) on a punctual light: its position moved, its
 * direction turned by the linear part (renormalised). */
void ms_json_punctual_transform(ms_punctual *p, const double m[12]);
/* The asset's lights after the meshes were read into out (the soup's arrays already out's): the emitters
 * chosen by lo, the punctual lights, and the warnings about those left out. Frees the soup's material names
 * and punctual lights, also on failure. With lo->none_ok, a scene left without any light is no error. */
int ms_json_asset_lights(ms_scene *out, const ms_json_light_opts *lo, ms_tri_soup *soup, const char *path, char *err,
                         size_t errlen);

#endif
