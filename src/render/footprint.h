/* Bilinear footprints of lightmap triangles (footprint.c): the texels a bilinear lookup at some point of a
 * triangle reads with a weight, i.e. whose centres lie within one texel of it in both axes. Two charts whose
 * footprints share no texel never mix their light in a lookup, however close they lie; the packer keeps them
 * so (atlas_footprints.c) and the bake's dilation fills each footprint from its own chart (bake.c). */
#ifndef MS_FOOTPRINT_H
#define MS_FOOTPRINT_H
#include <stddef.h>
#include <stdint.h>

/* The reach of a footprint in texels: a texel whose centre lies one texel from the triangle takes weight 0
 * (xatlas puts chart edges on texel centres, so texels at exactly 1 are common), one a little nearer a weight
 * below 1 - reach. The bake's reach is the smaller, so that with the UVs' rounding (5e-4 texels on an 8192
 * page) every footprint it finds lies inside the one the packer kept apart from the others; the texels it
 * leaves out carry at most 0.4% of a lookup. */
#define MS_FOOTPRINT_REACH_BAKE 0.996
#define MS_FOOTPRINT_REACH_PACK 0.998

/* Calls fn(user, x, y) for every texel (x, y) of [0, w) x [0, h) whose centre (x + 0.5, y + 0.5) lies within
 * `reach` (L-infinity) of the triangle with UVs uv[0..5] in texels. A triangle without area (or with a
 * non-finite UV) has none. */
void ms_footprint_triangle(const float uv[6], double reach, int w, int h, void (*fn)(void *user, int x, int y),
                           void *user);

/* The owner of every texel of a lightmap's frame (width size, pages stacked: page p in rows [p size,
 * (p + 1) size)): the charts (triangles joined by a shared UV vertex on the same page) whose footprints hold
 * it, a chart standing for every chart whose footprint shares a texel with it (such charts read each other's
 * texels anyway); owner[i] is a triangle of that union, UINT32_MAX where no footprint reaches. uv: per triangle
 * in [0, 1] of its page (page[t]). 0, or -1 when out of memory. */
int ms_footprint_owners(const float *uv, const uint32_t *page, size_t n, int size, int pages, uint32_t *owner);

#endif
