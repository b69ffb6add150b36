/* The lightmap's chart seams: found, measured (bake_seams.c) and stitched (bake_stitch.c). */
#ifndef MS_BAKE_SEAMS_H
#define MS_BAKE_SEAMS_H
#include "microshadow.h"

/* One seam: an edge exactly two baked triangles share in space (the same two endpoints, bit for bit) but not
 * in UVs, on a smooth surface; each side's UVs at the edge's endpoints, a0 and b0 at the same endpoint. */
typedef struct ms_seam {
    float a0[2], a1[2];
    float b0[2], b1[2];
} ms_seam;

/* Every seam of the triangles' baked UVs (6 floats per triangle, NaN: not baked) on a smooth edge: where
 * both sides' shading normals (ms_scene.tri_normal) agree at both endpoints, the same NORMAL on both sides
 * as an engine gets them; where a side has none, where their planes meet within 8 degrees facing the same
 * way (a crease, or a flip of the winding, differs by right). *seams is malloc'ed (NULL when there is
 * none), their number in *n. 0, or -1 when out of memory. */
int ms_bake_seam_list(const ms_scene *sc, const float *uv, ms_seam **seams, size_t *n);

/* Points along a seam of UV length len_texels on the longer side: spaced at most 1/per_texel texel, at
 * least one. The measure takes 2 per texel, the stitch 3 (at other places along the edge). */
int ms_seam_samples(double len_texels, int per_texel);
double ms_seam_len_texels(const ms_seam *s, int width, int height);   /* texels across a width x height frame */

/* The seam error as an engine sees it: at 2 points per texel along every seam, the irradiance's largest
 * channel sampled bilinearly (clamped, texel centres at (x + 0.5) / size) on either side, the absolute
 * difference relative to the lightmap's largest value; its mean, 99th percentile and max and the number
 * of points (all 0 when there is no seam). 0, or -1 when out of memory. */
typedef struct ms_seam_error {
    double mean, p99, max;
    size_t points;
} ms_seam_error;
int ms_bake_seams(const ms_frame *f, const ms_seam *seams, size_t n, ms_seam_error *out);

#endif
