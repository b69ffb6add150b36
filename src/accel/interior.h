/* Interior boxes of closed components: virtual occluders for the micro-rasterization methods
 * (docs/culling.md, "Interior boxes").
 *
 * A dense closed mesh (a scanned statue) shadows a receiver with hundreds of small triangles, and a pixel
 * in its umbra rasterizes them one by one until its buffer is empty. The solid they bound is mostly
 * empty of triangles inside: boxes that lie inside it, away from its surface, are occluders with the same
 * answer and a few large triangles each. A segment that meets such a box has a point inside the solid at
 * least `eps` from the surface; from there it must cross the surface to reach a light sample outside the
 * component's box, and a closed surface crossed is a hit for the watertight test: the sample is occluded
 * for every method (the full argument, with its conditions, is in docs/culling.md). Rasterizing the boxes
 * first empties most umbra buffers and most of a penumbra buffer's occluded part in a few kernel calls;
 * the real triangles then only decide what is left.
 *
 * The boxes: a grid over each closed component's box; cells whose closure comes within eps of one of the
 * component's triangles (by the triangle's box, conservatively) are marked; unmarked cells reached from
 * the grid's border through unmarked cells (26-connected) are outside; every other group of unmarked
 * cells is entirely inside or entirely outside the solid (no triangle crosses it), and its winding
 * number (sum of the triangles' solid angles, in double, at a cell centre at least half a cell from the
 * surface) says which. Interior cells are merged greedily into boxes. */
#ifndef MS_ACCEL_INTERIOR_H
#define MS_ACCEL_INTERIOR_H
#include <stddef.h>
#include <stdint.h>
#include "closed.h"

typedef struct ms_interior {
    size_t n_boxes;
    float (*box)[6];        /* min x, y, z, max x, y, z: every point at least eps (L-infinity) from the
                             * component's triangles, inside the solid */
    uint32_t *component;    /* per box: its closed component (ms_closed numbering) */
} ms_interior;

/* The interior boxes of every closed component of the n triangles tri (9 floats each) with at least
 * min_tris triangles, on a grid of `res` cells along each component's longest side; eps: the clearance
 * from the surface, in world units; threads: OpenMP threads of the winding numbers. Work O(n + res^3 + groups * n), memory O(res^3). 0, or -1 when out
 * of memory (out zeroed). */
int ms_interior_find(const float *tri, size_t n, const ms_closed *c, int res, size_t min_tris, double eps,
                     int threads, ms_interior *out);
void ms_interior_free(ms_interior *in);

#endif
