/* Triangles left out of a lightmap and why (bake_unbaked.c): the bake warns with each reason's count, the glb
 * names their primitives and materials after it. */
#ifndef MS_BAKE_UNBAKED_H
#define MS_BAKE_UNBAKED_H
#include "microshadow.h"

typedef enum ms_unbaked {
    MS_BAKED = 0,          /* texels rasterized from its baked UVs */
    MS_UNBAKED_EXCLUDED,   /* its mesh says "lightmap": false: intended, reported but not a warning */
    MS_UNBAKED_NO_AREA,    /* no area in space: no plane, no receiver */
    MS_UNBAKED_NO_UVS,     /* no baked UVs: xatlas left it out */
    MS_UNBAKED_UV_FLAT,    /* baked UVs without area at the lightmap's size */
    MS_UNBAKED_UV_OUTSIDE, /* baked UVs wholly outside the lightmap */
    MS_UNBAKED_REASONS
} ms_unbaked;

/* Why scene triangle t has no texels of its own in a size x size lightmap baked into uv (6 floats per
 * triangle, ms_lightmap.uv), as the texel rasterization (bake.c) decides; MS_BAKED when it has UVs to bake. */
ms_unbaked ms_bake_tri_state(const ms_scene *sc, const float *uv, int size, size_t t);

/* The unit normal nn of the triangle with world vertices w (9 floats), as the texels' rasterization takes it
 * (bake.c) and ms_bake_tri_state mirrors it: 0, or -1 when the triangle has no plane (no finite, non-zero
 * normal: no receiver). */
int ms_bake_tri_normal(const float *w, float nn[3]);

/* A short name of the reason ("no UVs"), for names in the glb. */
const char *ms_unbaked_name(ms_unbaked r);

/* Counts the triangles left out of lm by reason into count[MS_UNBAKED_REASONS] and warns (ms_warn) once
 * per reason other than "lightmap": false with its count and what it means. */
void ms_bake_report_unbaked(const ms_scene *sc, const ms_lightmap *lm, int size, size_t count[MS_UNBAKED_REASONS]);

#endif
