/* A light's parallelogram as float[3] vectors, unpacked once from the ms_vec3 fields of ms_light: the
 * corner, the two edges (L(s,t) = corner + s edge_s + t edge_t) and the emitting side's normal
 * cross(edge_s, edge_t), not normalised (its length is the parallelogram's area). A sphere light's
 * parallelogram is the square around it that ms_light_sphere keeps (per receiver, its outline disk's). */
#ifndef MS_LIGHT_FRAME_H
#define MS_LIGHT_FRAME_H
#include "microshadow.h"
#include <math.h>
#include "core/vec.h"

typedef struct ms_light_frame {
    float corner[3], edge_s[3], edge_t[3];
    float normal[3];
} ms_light_frame;

/* The shear axis the segments to light l prefer (accel/ray_triangle.h, ms_wt_packet_axis): the largest component
 * of its plane's normal edge_s x edge_t (the first on ties), -1 when the light has no plane (a sphere before its
 * outline: zero edges). Every method's segments to one light share it. */
static inline int ms_light_shear_axis(const ms_light *l)
{
    const float n[3] = { l->edge_s.y * l->edge_t.z - l->edge_s.z * l->edge_t.y,
                         l->edge_s.z * l->edge_t.x - l->edge_s.x * l->edge_t.z,
                         l->edge_s.x * l->edge_t.y - l->edge_s.y * l->edge_t.x };
    const float x = fabsf(n[0]), y = fabsf(n[1]), z = fabsf(n[2]);
    if (!(x + y + z > 0.0f) || !isfinite(x + y + z)) return -1;
    return x >= y ? (x >= z ? 0 : 2) : (y >= z ? 1 : 2);
}

static inline void ms_light_frame_of(const ms_light *l, ms_light_frame *f)
{
    f->corner[0] = l->corner.x; f->corner[1] = l->corner.y; f->corner[2] = l->corner.z;
    f->edge_s[0] = l->edge_s.x; f->edge_s[1] = l->edge_s.y; f->edge_s[2] = l->edge_s.z;
    f->edge_t[0] = l->edge_t.x; f->edge_t[1] = l->edge_t.y; f->edge_t[2] = l->edge_t.z;
    v3_cross(f->normal, f->edge_s, f->edge_t);
}

#endif
