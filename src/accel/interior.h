/* Interior boxes of closed surfaces (mod-2 cycles, closed.h): virtual occluders for the micro-rasterization methods
 * (docs/culling.md, "Interior boxes").
 *
 * A dense closed mesh (a scanned statue) shadows a receiver with hundreds of small triangles, and a pixel
 * in its umbra rasterizes them one by one until its buffer is empty. The solid they bound is mostly
 * empty of triangles inside: boxes that lie inside it, away from its surface, are occluders with the same
 * answer and a few large triangles each. A segment that meets such a box has a point inside the solid at
 * least `eps` from the surface; from there it must cross the surface to reach a light sample outside the
 * cycle's box, and a closed surface crossed is a hit for the watertight test: the sample is occluded
 * for every method (the full argument, with its conditions, is in docs/culling.md). Rasterizing the boxes
 * first empties most umbra buffers and most of a penumbra buffer's occluded part in a few kernel calls;
 * the real triangles then only decide what is left.
 *
 * The surface need not be oriented: a mod-2 cycle (every edge shared by an even number of triangles) has an
 * inside, the points from which a ray crosses it an odd number of times, and a segment from inside to
 * outside crosses it. Scans with a flipped triangle or a fin are cycles, not closed components.
 *
 * The boxes: a grid over each cycle's box; cells whose closure comes within eps of one of the cycle's
 * triangles (L-infinity: a triangle-box overlap test with a margin, so a doubt marks) are marked; unmarked
 * cells reached from the grid's border through unmarked cells (26-connected) are outside; every other group
 * of unmarked cells is entirely inside or entirely outside (no triangle crosses it), and the parity of a
 * ray's crossings from a cell centre at least half a cell from the surface (double; another direction when
 * it passes near an edge) says which. Interior cells are merged greedily into boxes. */
#ifndef MS_ACCEL_INTERIOR_H
#define MS_ACCEL_INTERIOR_H
#include <stddef.h>
#include <stdint.h>
#include "closed.h"

/* At most one box per this many triangles of a cycle, and one more (the memory budget counts them so). */
#define MS_INTERIOR_TRIS_PER_BOX 64

typedef struct ms_interior {
    size_t n_boxes;
    float (*box)[6];        /* min x, y, z, max x, y, z: every point at least eps (L-infinity) from the
                             * cycle's triangles, inside it */
    uint32_t *component;    /* per box: its group (closed.h: a cycle, or n_cycles + a holed set) */
} ms_interior;

/* The interior boxes of every group of c (closed.h: each cycle, and each holed set with its caps) of the n
 * triangles tri (9 floats each) with at least min_tris triangles of the scene, on a grid of `res` cells along
 * each group's longest side (halved, down to 16, while a cell is no wider than four clearances); eps: the
 * clearance from the surface, caps included, in world units; threads: OpenMP threads of the parity rays. Work
 * O(n + res^3 + groups * n), memory O(res^3). 0, or -1 when out of memory (out zeroed). A holed set's box holds
 * for a light only where its caps hide it (visibility/occluders.c). */
int ms_interior_find(const float *tri, size_t n, const ms_closed *c, int res, size_t min_tris, double eps,
                     int threads, ms_interior *out);
void ms_interior_free(ms_interior *in);

#endif
