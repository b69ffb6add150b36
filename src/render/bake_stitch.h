/* Least-squares seam stitching of a baked lightmap (bake_stitch.c). */
#ifndef MS_BAKE_STITCH_H
#define MS_BAKE_STITCH_H
#include "bake_seams.h"

/* Makes the bilinear lookups from both sides of every seam agree (Liu, Ferguson, Jacobson and Gingold,
 * "Seamless", 2017, seam erasure): the irradiance (rgb) and every light's S of f, over the texels those
 * lookups read and no other, each as close to its baked value as the seams allow (those whose centre lies on
 * their triangle, by the baked uv and texel triangles, held more firmly than the rest). Texels not yet filled
 * (vis < 0: beyond dilation) are left out with the points that read them. The texels changed in *texels.
 * 0, or -1 when out of memory (f untouched). */
int ms_bake_stitch(ms_frame *f, const float *uv, const uint32_t *triangle, const ms_seam *seams, size_t n, int threads,
                   size_t *texels);

/* An upper bound of the bytes ms_bake_stitch allocates for these seams on f (its peak), for the bake's
 * memory budget: the seams are known only once the layout is, after the budget's first check. */
uint64_t ms_bake_stitch_need(const ms_frame *f, const ms_seam *seams, size_t n);

#endif
