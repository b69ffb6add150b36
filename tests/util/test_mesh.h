/* Meshes for the tests of closed surfaces and their interior boxes (test_closed.c, test_holes.c): triangle soups
 * built here, and a segment-triangle test in double that is no code of the library. */
#ifndef MS_TEST_MESH_H
#define MS_TEST_MESH_H
#include <stddef.h>

/* The segments' occlusion range, as the library defines it (docs/design.md, "Visibility, precisely"). */
#define TM_NEAR 1e-4
#define TM_FAR (1.0 - 1e-4)

typedef struct tm_mesh { float *tri; size_t n, cap; } tm_mesh;

/* Append triangle (a, b, c). */
void tm_add_tri(tm_mesh *m, const double a[3], const double b[3], const double c[3]);
/* An icosphere of radius r around c, subdivided s times, outward winding (flip: inward); the vertices moved
 * radially by up to jitter (shared vertices move alike: the surface stays closed). */
void tm_icosphere(tm_mesh *m, const double c[3], double r, int s, int flip, double jitter, unsigned seed);
/* The Quad's ground: two triangles over [-10, 10] x [-10, 10] at y = 0, facing up. */
void tm_ground(tm_mesh *m);
/* An axis-aligned box [lo, hi], outward winding (flip: inward). */
void tm_box(tm_mesh *m, const double lo[3], const double hi[3], int flip);
/* The centroid of triangle t into pos and its winding's normal (not normalised) into nrm. */
void tm_centroid_normal(const float *t, float pos[3], float nrm[3]);
/* Does the segment p + u (l - p), u in [TM_NEAR, TM_FAR], meet triangle t? Double precision, Moller-Trumbore. */
int tm_seg_hits(const float *t, const double p[3], const double l[3]);
/* A uniform number in [0, 1) from the state s. */
double tm_urand(unsigned *s);

#endif
