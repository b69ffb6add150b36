/* Closed components of a triangle soup, for exact back-face culling of shadow occluders (docs/culling.md).
 *
 * A component (triangles connected through edges shared by exactly two triangles that traverse it in
 * opposite directions) is closed when each of its edges is traversed by its triangles as often in one
 * direction as in the other (consistently oriented, no boundary, no fin; two solids, or two parts of one,
 * may touch along an edge). Vertices are shared when their three coordinates are bitwise equal, as a
 * loader that reads an indexed mesh leaves them. A closed component bounds a solid; its orientation
 * (outward when the signed volume is positive, inward otherwise) says which side is inside. A segment from
 * a point to a light sample outside that solid's box leaves the solid through a triangle whose outward side
 * faces the sample, so a triangle that has the whole light behind its outward side never decides whether
 * such a segment is occluded (docs/culling.md proves it, with the cases it needs: the light outside the
 * component's box by more than the far range, no alpha-tested triangle, no self-intersection). */
#ifndef MS_ACCEL_CLOSED_H
#define MS_ACCEL_CLOSED_H
#include <stddef.h>
#include <stdint.h>

#define MS_OPEN_COMPONENT UINT32_MAX

typedef struct ms_closed {
    size_t n_tris;
    uint32_t *component;   /* per triangle: its closed component, or MS_OPEN_COMPONENT */
    size_t n_components;   /* closed components */
    float (*box)[6];       /* per closed component: min x, y, z, max x, y, z */
    int8_t *outward;       /* per closed component: +1 when the triangles' winding (cross(b - a, c - a))
                            * points out of the solid (positive signed volume), -1 when it points in */
    size_t closed_tris;    /* triangles in closed components */
    /* Mod-2 cycles (the interior boxes need no more, accel/interior.h): triangles connected through shared
     * edges, every edge used by an even number of them, whatever their orientation (a flipped triangle or a
     * fin of four leaves a scan a cycle, not a closed component). Every closed component is a cycle. */
    uint32_t *cycle;       /* per triangle: its cycle, or MS_OPEN_COMPONENT */
    size_t n_cycles;
    float (*cycle_box)[6];
    size_t cycle_tris;
    /* Holed sets (accel/holes.h): triangles connected through shared edges, not a cycle, with at least
     * MS_HOLED_MIN_TRIS triangles and a short rim (the edges used an odd number of times: at most one per
     * MS_HOLED_TRIS_PER_RIM_EDGE triangles), each made a mod-2 cycle by cap triangles across its rim. For the
     * interior boxes only; they number after the cycles there (group n_cycles + h, ms_closed_group_box). */
    uint32_t *holed;       /* per triangle: its holed set, or MS_OPEN_COMPONENT */
    size_t n_holed;
    float (*holed_box)[6]; /* per holed set, its caps included */
    float *cap;            /* the cap triangles, 9 floats each, set by set */
    size_t *cap_start;     /* holed set h's caps: cap_start[h] .. cap_start[h + 1] - 1 */
} ms_closed;

#define MS_HOLED_MIN_TRIS 256
#define MS_HOLED_TRIS_PER_RIM_EDGE 16

/* The interior boxes' groups: the cycles, then the holed sets. */
static inline size_t ms_closed_groups(const ms_closed *c) { return c->n_cycles + c->n_holed; }
static inline const float *ms_closed_group_box(const ms_closed *c, size_t k)
{
    return k < c->n_cycles ? c->cycle_box[k] : c->holed_box[k - c->n_cycles];
}
/* Triangle t's group, or MS_OPEN_COMPONENT. */
static inline uint32_t ms_closed_group_of(const ms_closed *c, size_t t)
{
    if (c->cycle[t] != MS_OPEN_COMPONENT) return c->cycle[t];
    return c->holed && c->holed[t] != MS_OPEN_COMPONENT ? (uint32_t)c->n_cycles + c->holed[t] : MS_OPEN_COMPONENT;
}

/* The closed components, the mod-2 cycles and the holed sets with their caps of n triangles (tri: 9 floats
 * each). Work O(n log n), memory O(n). 0, or -1 when out of memory (out zeroed). */
int ms_closed_find(const float *tri, size_t n, ms_closed *out);
void ms_closed_free(ms_closed *c);

/* For a light whose every point lies in the convex hull of the n_pts points pts (3 floats each; e.g. the
 * corners of a rect light's parallelogram, of a disk's bounding square, of a sphere's bounding box), and
 * whose box is lbox: keep[t] = 0 for each triangle t of a closed component that the proof allows to skip
 * (the component's box and lbox apart by more than margin, every pts behind or on the triangle's outward
 * plane), 1 otherwise. The plane test is done in double with a relative slack, so a triangle is culled
 * only when every light point is behind it beyond rounding. margin: the segments' far range times the
 * longest segment (docs/culling.md). Returns the number of triangles culled. */
size_t ms_closed_cull(const ms_closed *c, const float *tri, const float (*pts)[3], int n_pts, const float lbox[6],
                      double margin, uint8_t *keep);
#endif
