/* Penumbra volumes of hierarchical penumbra casting (Laine & Aila 2005, sec. 3.2): the separating planes
 * between a convex polygon (the light, or a light-sample group's bounding polygon) and a blocker triangle,
 * capped by the triangle's plane when that plane misses the polygon. Every point that the triangle can
 * shadow from any point of the polygon lies on the inner side of every plane, so a box or point outside
 * one plane (beyond a margin) is culled. Planes are kept with a bit per plane, the active plane sets of
 * sec. 3.3 B: a plane the box lies wholly inside of is dropped for the subtree. */
#ifndef MS_HPC_VOLUME_H
#define MS_HPC_VOLUME_H
#include <stdint.h>

#define HPC_MAX_PLANES 16
#define HPC_ALL_PLANES UINT32_MAX   /* the paper's token ALL (also before a lazy volume exists) */

typedef struct hpc_volume {
    int n;                          /* planes; 0 with unbounded = 1: nothing can be culled */
    int unbounded;
    float eps;                      /* culling margin: a point is outside only below -eps */
    float pl[HPC_MAX_PLANES][4];    /* unit normal, offset: inside is n . x + d >= -eps */
    /* The same planes by component (unused ones 0), for the engine's 16-lane tests over all planes at
     * once (vol_box, vol_point: hpc_traverse_impl.h): HPC_MAX_PLANES is one l16. */
    float soa[4][HPC_MAX_PLANES];
} hpc_volume;

/* Builds the volume of polygon poly (np vertices, convex, planar) and triangle tri (9 floats). eps: the
 * caller's culling margin (a non-finite eps makes the volume unbounded). Returns the number of planes. */
int hpc_volume_build(hpc_volume *v, const double *poly, int np, const float tri[9], float eps);

/* The same for a blocker of nt (3 or 4) points pts (3 floats each), any shape: the planes bound the
 * shadows of the points' convex hull. */
int hpc_volume_build_points(hpc_volume *v, const double *poly, int np, const float *pts, int nt, float eps);

/* 0 when the box [lo, hi] lies outside a plane of the active set act; else 1 and *out = act less the
 * planes the box lies wholly inside of. *tests counts plane tests. */
int hpc_volume_box(const hpc_volume *v, uint32_t act, const float lo[3], const float hi[3], uint32_t *out,
                   uint64_t *tests);

/* 1 when point p is inside every plane of the active set. */
int hpc_volume_point(const hpc_volume *v, uint32_t act, const float p[3], uint64_t *tests);

#endif
