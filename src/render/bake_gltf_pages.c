/* Per-primitive lightmap extras of the glb (bake_gltf_pages.h): an engine that keeps the asset's own UV set
 * instead of TEXCOORD_1 can place the lightmap with the page and the scale-offset. */
#include "bake_gltf_pages.h"

void ms_bake_gltf_lightmap_extras(cJSON *prim, const ms_lightmap *lm, uint32_t object, uint32_t page)
{
    cJSON *ex = cJSON_GetObjectItem(prim, "extras");
    if (!ex) ex = cJSON_AddObjectToObject(prim, "extras");
    cJSON *j = cJSON_AddObjectToObject(ex, "lightmap");
    cJSON_AddNumberToObject(j, "page", page);
    const int has = lm->object_uv_set && object < lm->n_objects;
    /* a layout packed island by island (MS_UV_PACK_ISLANDS) has no one scale-offset: TEXCOORD_1 alone, as xatlas's */
    const int set = has && lm->object_scale_offset[4 * (size_t)object] != 0.0f ? lm->object_uv_set[object] : -1;
    cJSON_AddNumberToObject(j, "uvSet", set);
    if (set >= 0) {
        cJSON *so = cJSON_AddArrayToObject(j, "scaleOffset");
        for (int k = 0; k < 4; k++) cJSON_AddItemToArray(so, cJSON_CreateNumber(lm->object_scale_offset[4 * (size_t)object + k]));
    }
}
