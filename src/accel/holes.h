/* Holed surfaces capped for the interior boxes (docs/culling.md, "Holes"): a scanned statue with a few holes in
 * its surface (the Stanford bunny's base, an ogre's eyes) is no mod-2 cycle, so it had no inside and no interior
 * boxes. Capping each hole's rim with a fan of triangles makes it one; the caps are not geometry (no method sees
 * them), so a box inside the capped surface is an exact occluder for a light only where no segment from the box to
 * the light can pass through a cap (ms_cap_hidden): every segment from inside to the light then leaves through
 * the real surface.
 *
 * Internal to accel/: closed.c finds the holed sets while it matches edges (ms_holes_cap); interior.c takes them as
 * it takes the cycles; the per-light choice of boxes (visibility/occluders.c) calls ms_cap_hidden. */
#ifndef MS_ACCEL_HOLES_H
#define MS_ACCEL_HOLES_H
#include <stddef.h>
#include <stdint.h>
#include "closed.h"

/* The holed sets of the n triangles tri into out (closed.h: holed, n_holed, holed_box, cap, cap_start): the sets
 * of the union-find `parent` (any shared edge unites) with at least MS_HOLED_MIN_TRIS triangles whose rim, the
 * n_rim edges used an odd number of times, has at most one edge per MS_HOLED_TRIS_PER_RIM_EDGE triangles. rim[i]:
 * the corner 3 t + k of a triangle t on rim edge i where the edge starts (it ends at corner 3 t + (k + 1) % 3);
 * id: the welded vertex of each corner. Each rim's edges split into closed walks (every vertex of a set's rim has
 * an even number of its rim edges), each capped by a fan from the walk's centroid: every edge of the set and its
 * caps is then used an even number of times. 0, or -1 when out of memory. */
int ms_holes_cap(const float *tri, size_t n, const uint32_t *id, const uint32_t *rim, size_t n_rim, uint32_t *parent,
                 ms_closed *out);

/* The most cap tests a light's boxes take (visibility/occluders.c): a bound on the set-up that does not grow with
 * boxes times caps. */
#define MS_CAP_TESTS_PER_LIGHT (1u << 21)

/* 1 when no segment from a point of box b (min x, y, z, max x, y, z) to a point of the convex hull of the n_pts
 * light points pts comes within tol of the triangle cap (9 floats): a plane found (in double) with the box and
 * the light on one side and the cap beyond tol on the other. 0 when none of the candidate planes separates them:
 * the box is then left out for that light, which is never wrong. */
int ms_cap_hidden(const float b[6], const float (*pts)[3], int n_pts, const float cap[9], double tol);

#endif
