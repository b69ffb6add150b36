/* The scene's lights and camera in the glb (bake_gltf_lights.c), for a viewer that lights the file's materials
 * with live lights and shadows them by the shadowmask, through the scene's camera. */
#ifndef MS_BAKE_GLTF_LIGHTS_H
#define MS_BAKE_GLTF_LIGHTS_H
#include "microshadow.h"
#include <cjson/cJSON.h>
/* ms.lights = one object per light of ms_scene_lights, in its order (the shadowmask channels' "light" index),
 * in the glb's world coordinates (the scene's frame plus its origin, as the root node places the meshes):
 * {"shape", "radiance": [r, g, b], ...} with rect, disk, triangle: "corner", "edge_s", "edge_t" (the disk's
 * bounding square; the triangle's vertices corner, corner + edge_s, corner + edge_t); sphere: "center",
 * "radius"; sun: "direction" (unit, towards the sun), "angular_diameter_deg". A textured light's radiance is
 * its emission times its mean texel, with "textured": true. */
void ms_bake_gltf_lights(cJSON *ms, const ms_scene *sc);
/* ms.camera = the scene's pinhole camera in the glb's world coordinates: {"eye", "target", "up", "fov_y" (degrees),
 * "width", "height"}, as a scene file gives it (viewer/index.html reads it when given no scene file); nothing for
 * another camera type. */
void ms_bake_gltf_camera(cJSON *ms, const ms_scene *sc);
#endif
