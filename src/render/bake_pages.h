/* A bake's UV layout and its pages (bake_pages.c): the UVs chosen or taken from the cache, the UVs in the
 * frame's rows (pages stacked), the fill of each page. */
#ifndef MS_BAKE_PAGES_H
#define MS_BAKE_PAGES_H
#include "microshadow.h"

/* lm->uv, page, pages, object_uv_set, object_scale_offset, charts, unwrapped_tris, unwrap_s, uv_key,
 * uv_cached: from o->uv_cache when it holds this layout, else ms_bake_uvs. */
ms_status ms_bake_choose_uvs(const ms_scene *sc, const ms_bake_options *o, int size, int padding, ms_lightmap *lm, char *err,
                             size_t errlen);
/* The UVs in the frame of all pages (v = (page + v) / pages): lm->uv itself with one page, else a malloc'ed
 * copy; NULL when out of memory. */
float *ms_bake_frame_uv(const ms_lightmap *lm);
/* lm->page_fill from the rasterizer's distances (0: the texel's centre lies on its triangle). */
void ms_bake_page_fill(ms_lightmap *lm, const float *dist, int size);
void ms_bake_pages_free(ms_lightmap *lm);
#endif
