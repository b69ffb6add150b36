/* Whether a UV set is a usable lightmap layout for one object (uv_validity.c): every triangle has it, it has
 * area, and no two triangles overlap in UV. */
#ifndef MS_UV_VALIDITY_H
#define MS_UV_VALIDITY_H
#include <stddef.h>
#include <stdint.h>

typedef struct ms_uv_validity {
    size_t missing;      /* triangles without the set (a non-finite UV) */
    size_t degenerate;   /* triangles whose UV image has (next to) no area */
    size_t overlapping;  /* triangles whose UV image overlaps another's interior */
    double degenerate_world_area, overlapping_world_area, world_area;
} ms_uv_validity;

/* The triangles tris[0..n-1] (indices into the soup: 9 floats of positions, 6 of UVs each) as one object's
 * layout in `set`. Two triangles overlap when their interiors do by more than 1e-5 of the layout's extent;
 * a triangle is degenerate when its UV area is below 1e-12 of the layout's box. Returns 1 when the layout
 * is usable: none missing, and the overlapping and degenerate triangles together carry at most 2% of the
 * object's world area (bad[i] = 1 marks them, when bad is not NULL: they get charts of their own, the rest
 * keeps the layout). 0 when not (the search stops once that is certain), -1 when out of memory. */
int ms_uv_layout_valid(const float *pos, const float *set, const uint32_t *tris, size_t n, uint8_t *bad, ms_uv_validity *out);

#endif
