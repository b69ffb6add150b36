/* Bounding volume hierarchy over a triangle soup: binned-SAH build, 32-byte nodes, closest-hit and
 * any-hit traversal. The build reorders the triangles into leaf order; every method of microshadow
 * names triangles by that order (prim ids), so the hit triangle can be excluded consistently. */
#ifndef MS_BVH_H
#define MS_BVH_H
#include <stddef.h>
#include <stdint.h>

typedef struct ms_bvh_node {
    float bmin[3];
    uint32_t first;   /* interior: index of the left child (right = first + 1); leaf: first triangle */
    float bmax[3];
    uint32_t count;   /* 0 for interior nodes, else the number of triangles in the leaf */
} ms_bvh_node;

typedef struct ms_bvh {
    ms_bvh_node *nodes;
    uint32_t n_nodes;
    float *tri;           /* 9 floats per triangle, leaf order */
    uint32_t *tri_source; /* leaf-order index -> index in the soup given to the build */
    float *tri_n;         /* 3 floats per triangle, leaf order: its plane normal (ms_wt_normal) */
    uint32_t n_tris;
    int depth;
    double build_s;
} ms_bvh;

typedef struct ms_ray {
    float o[3], d[3];
    float tmin, tmax;     /* hit parameter range along d (d need not be unit) */
} ms_ray;

typedef struct ms_ray_hit {
    float t, u, v;
    uint32_t prim;        /* leaf-order triangle index, UINT32_MAX on a miss */
} ms_ray_hit;

/* Builds over n triangles (copied). Returns 0, or -1 when out of memory. */
/* threads: OpenMP threads for the build (0: all cores); the caller's OpenMP settings are left alone. */
int ms_bvh_build(ms_bvh *b, const float *tri, size_t n, int threads);
void ms_bvh_free(ms_bvh *b);
/* The BVH of the triangles of src with keep[i] != 0 (i in src's leaf order), pruned from src's tree
 * (bvh_filter.c) rather than built anew: the same nodes less the emptied ones, boxes refitted, the kept
 * triangles in src's order. out->tri_source[j] is the src leaf-order index of out's triangle j. Returns 0,
 * or -1 when out of memory or nothing is kept (out zeroed). */
int ms_bvh_filter(ms_bvh *out, const ms_bvh *src, const uint8_t *keep);

/* 1 and the nearest hit in (tmin, tmax), or 0. */
int ms_bvh_closest(const ms_bvh *b, const ms_ray *r, ms_ray_hit *hit);
/* The same, counting only the hits accept(user, prim, r) returns non-zero for (a rejected hit does not shorten
 * the ray: traversal goes on past it; e.g. alpha-tested triangles where they are transparent). accept NULL:
 * ms_bvh_closest. */
typedef int (*ms_bvh_hit_filter)(const void *user, uint32_t prim, const ms_ray *r);
int ms_bvh_closest_filter(const ms_bvh *b, const ms_ray *r, ms_ray_hit *hit, ms_bvh_hit_filter accept, const void *user);
/* 1 if any triangle other than skip_prim is hit with t in [tmin, tmax]. */
int ms_bvh_occluded(const ms_bvh *b, const ms_ray *r, uint32_t skip_prim);

/* Two-sided watertight ray/triangle test (ray_triangle.h: Woop, Benthin & Wald 2013); 1 and t,u,v when
 * the ray hits with t in [tmin, tmax]. Shared by tests as the per-triangle oracle of the traversals
 * (which prepare the ray once and call ms_wt_intersect, the same arithmetic). */
int ms_intersect_triangle(const float tri[9], const float o[3], const float d[3], float tmin, float tmax,
                          float *t, float *u, float *v);

#define MS_BVH_STACK 64

/* A shallower view of a BVH for the multi-frusta traversals (Benthin & Wald 2009, sec. 5: a deep BVH suits
 * single rays and packets, "a shallower BVH" suits frusta, which cull poorly deep down the tree and test
 * a leaf's triangles with cheap per-frustum culling first). Every subtree of b holding at most max_leaf
 * triangles becomes one leaf over the same contiguous triangle range (the build keeps subtrees
 * contiguous), so triangles, prim ids and normals stay b's: nodes only, no second copy of the scene.
 * Nodes have b's layout (first = left child of a pair, or first triangle; count = 0 for interior). */
typedef struct ms_bvh_shallow {
    ms_bvh_node *nodes;
    uint32_t n_nodes;
    int max_leaf, depth;
} ms_bvh_shallow;

/* Returns 0, or -1 when out of memory. */
int ms_bvh_shallow_build(ms_bvh_shallow *s, const ms_bvh *b, int max_leaf);
void ms_bvh_shallow_free(ms_bvh_shallow *s);

#endif
