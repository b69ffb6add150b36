/* The triangle light (shape "triangle"): vertices a, b, c, sampled on the parallelogram corner a, edges
 * b - a and c - a with the samples where s + t >= 1 masked off, as the disk masks its square; it emits
 * towards cross(b - a, c - a) (the vertices counter-clockwise seen from the lit side). */
#include "light_shape.h"
#include "core/vec.h"
#include <math.h>
#include <stdio.h>

ms_status ms_light_triangle(ms_light *l, ms_vec3 a, ms_vec3 b, ms_vec3 c)
{
    const float s[3] = { b.x - a.x, b.y - a.y, b.z - a.z }, t[3] = { c.x - a.x, c.y - a.y, c.z - a.z };
    float n[3];
    v3_cross(n, s, t);
    if (!(v3_dot(n, n) > 0.0f) || !v3_finite(n)) return MS_ERR_INVALID;
    l->corner = a;
    l->edge_s = (ms_vec3){ s[0], s[1], s[2] };
    l->edge_t = (ms_vec3){ t[0], t[1], t[2] };
    l->shape = MS_LIGHT_TRIANGLE;
    return MS_OK;
}

/* Strict, as the disk's: a sample on the diagonal s + t = 1 is off the triangle. */
static int triangle_contains(float s, float t) { return s + t < 1.0f; }

static float triangle_area(const ms_light *l, const ms_light_frame *F)
{
    (void)l;
    return 0.5f * v3_len(F->normal);
}

/* The triangle's corners a, a + edge_s, a + edge_t relative to p. */
static int triangle_polygon(const ms_light_frame *F, const float p[3], int sides, float (*q)[3])
{
    (void)sides;
    const float *C = F->corner, *S = F->edge_s, *T = F->edge_t;
    for (int i = 0; i < 3; i++) {
        q[0][i] = C[i] - p[i];
        q[1][i] = C[i] + S[i] - p[i];
        q[2][i] = C[i] + T[i] - p[i];
    }
    return 3;
}

/* Exact: Lambert's polygon formula over the triangle clipped to the receiver's upper hemisphere, as the
 * parallelogram's. */
static float triangle_irradiance(const ms_light *l, const ms_light_frame *F, const float p[3], const float n[3])
{
    (void)l;
    float rel[3];
    v3_sub(rel, p, F->corner);
    if (!(v3_dot(rel, F->normal) > 0.0f)) return 0.0f;   /* behind the emitting side */
    float poly[3][3], clip[6][3];
    triangle_polygon(F, p, 3, poly);
    return (float)ms_light_polygon_irradiance((const float (*)[3])poly, 3, n, clip);
}

static int triangle_build(ms_light *l, const ms_light_params *v, float max_coord, char *msg, size_t n)
{
    (void)max_coord;   /* the corner and edges are checked as every light's are (scene_validate.c) */
    const double *p = v->v[0];
    const ms_vec3 a = { (float)p[0], (float)p[1], (float)p[2] }, b = { (float)p[3], (float)p[4], (float)p[5] },
                  c = { (float)p[6], (float)p[7], (float)p[8] };
    if (ms_light_triangle(l, a, b, c)) {
        snprintf(msg, n, "vertices must not be collinear");
        return -1;
    }
    return 0;
}

const ms_light_shape_ops ms_light_triangle_shape = {
    .shape = MS_LIGHT_TRIANGLE,
    .name = "triangle",
    .textured = 0,
    .contains = triangle_contains,
    .area = triangle_area,
    .irradiance = triangle_irradiance,
    .polygon = triangle_polygon,
    .keys = { { "vertices", MS_LIGHT_KEY_POINT, 3, 0, 0 } },
    .build = triangle_build,
};
