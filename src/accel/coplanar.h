/* Axis-aligned coplanar rectangles merged, for occluder sets (docs/culling.md, "Merged rectangles").
 *
 * Modelled and generated geometry cuts flat faces into strips: the grid of thin bars has 32 segments on
 * every face of every bar (64 triangles where 2 cover the face), floors and walls are tiled. A shadow
 * method pays per (point, triangle), so such a face costs 32 times what it covers. Here two triangles
 * that are the two halves of one axis-aligned rectangle (every vertex on one plane x, y or z = c, bitwise,
 * and the four corners of a rectangle in the other two axes, bitwise) become that rectangle, and
 * rectangles of one plane that share a whole side are merged into one, greedily; each rectangle is
 * emitted as two triangles. The region covered is the same set of points (the rectangles tile it
 * exactly: all coordinates are the input's floats), so a segment meets the merged set iff it meets the
 * original one, in exact arithmetic. Internal seams disappear. Triangles that are not halves of such a
 * rectangle pass through unchanged.
 *
 * When the watertight test (ray_triangle.h) decides alike. It shears the vertices relative to the ray's
 * origin along the ray's axis kz, and its edge functions have the exact sign of the sheared float vertices
 * (a float difference of two rounded products keeps the sign of the exact one or gives 0, and 0 is redone in
 * double, where the products are exact). For a rectangle in the plane x_n = c and a ray with kz = n, every
 * vertex has the same (c - o_n), so a vertex's sheared x is a monotone function of its own coordinate along
 * one in-plane axis alone and its sheared y of the other: the tiling stays a tiling of axis-aligned rectangles
 * in the sheared plane, with the merged rectangle's sides on the very lines of the pieces' sides, and the
 * union of the pieces' closed triangles is the merged rectangle's, float for float. With kz along an in-plane
 * axis b the same holds for every side that runs across b (its vertices share x_b and x_n), but not for the
 * sides along b: their vertices' sheared coordinates both move with x_b and round apart, so a side made of
 * several pieces is a polyline a few ulps off the merged rectangle's one straight side, and a ray passing
 * within those ulps is decided differently (measured: 8 of 262,144 pixels of the grid of bars off raytrace by
 * one sample). A rectangle merged along b is therefore exact for every ray whose kz is not b: *merged_axes
 * says which axes the merge joined pieces along, and no_axis forbids one, so that the methods that must equal
 * raytrace (ms_occluders.for_axis) take each sample from a set exact for its segment's axis.
 * (The t range is tested on the plane distance scaled by the triangle's own normal, so a segment ending
 * within an ulp of a merged face's plane, at the near range, may still round apart; the receivers on merged
 * faces, below, are the case where that happens.)
 *
 * What does change is a receiver lying on a merged face: rounding leaves its hit point just off the plane,
 * and a grazing segment then meets its own plane beyond the near range in another part of the face,
 * which the original tiling and the merged one cut differently (measured: 322 of 65,536 pixels of the grid
 * of bars off raytrace by up to 36 samples). The caller answers such receivers on the original triangles
 * (*merged says which). */
#ifndef MS_ACCEL_COPLANAR_H
#define MS_ACCEL_COPLANAR_H
#include <stddef.h>
#include <stdint.h>

/* Merges among the n triangles tri (9 floats each) those with eligible[i] != 0 (NULL: all), never along the
 * world axis no_axis (0, 1, 2; -1: along any). *merged_axes: bit a set when rectangles were joined along
 * axis a (rays sheared along a may tie on them, above). *out: the
 * triangles (9 floats each) of the merged set, *n_out of them; *of_input: per input triangle, the output
 * triangle that stands for it (its own copy, or the first of its rectangle's two); *source: per output
 * triangle, an input triangle it came from; *merged: per input triangle, 1 when it is part of a rectangle
 * merged from two or more pairs (a single pair stays as it was). 0, or -1 when out of memory (outputs
 * NULL). */
int ms_coplanar_merge(const float *tri, size_t n, const uint8_t *eligible, int no_axis, float **out, size_t *n_out,
                      uint32_t **of_input, uint32_t **source, uint8_t **merged, unsigned *merged_axes);

/* Whether triangles a and b (9 floats each) are the two halves of one axis-aligned rectangle, by the test the
 * merge uses (every vertex on one plane x, y or z = c and the corners a rectangle in the other two axes, all
 * bitwise; the halves leave out opposite corners). 1 and corners (12 floats: the rectangle's four corners in
 * order around it, each a vertex of a or b bit for bit up to the sign of a zero, the last the one a lacks, so
 * that a's vertices are corners 0, 1, 2 and b's 0, 2, 3), else 0. */
int ms_coplanar_rect_pair(const float *a, const float *b, float corners[12]);

#endif
