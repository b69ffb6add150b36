/* What the glb says per primitive about its lightmap page and layout (bake_gltf_pages.c). */
#ifndef MS_BAKE_GLTF_PAGES_H
#define MS_BAKE_GLTF_PAGES_H
#include "microshadow.h"
#include <cjson/cJSON.h>
/* prim.extras.lightmap = {page, uvSet, scaleOffset}: the page whose lightmap the primitive's material
 * references, and for an object baked in its own UV set, that set and the scale-offset that maps it to
 * TEXCOORD_1 (uv1 = uv * [su, sv] + [ou, ov], Unity's lightmapScaleOffset); uvSet -1 for xatlas charts. */
void ms_bake_gltf_lightmap_extras(cJSON *prim, const ms_lightmap *lm, uint32_t object, uint32_t page);
#endif
