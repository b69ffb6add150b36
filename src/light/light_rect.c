/* The parallelogram light (shape "rect", the default): L(s,t) = corner + s edge_s + t edge_t. */
#include "light_shape.h"
#include "core/vec.h"
#include <math.h>

static float rect_area(const ms_light *l, const ms_light_frame *F)
{
    (void)l;
    return v3_len(F->normal);
}

/* Exact: the polygon form factor (Lambert's formula) after clipping the light to the receiver's upper
 * hemisphere, so that a light straddling the horizon is counted only above it. */
static float rect_irradiance(const ms_light *l, const ms_light_frame *F, const float p[3], const float n[3])
{
    (void)l;
    const float *P = F->corner, *S = F->edge_s, *T = F->edge_t;
    float rel[3];
    v3_sub(rel, p, P);
    if (!(v3_dot(rel, F->normal) > 0.0f)) return 0.0f;   /* behind the emitting side */
    /* Light corners relative to p, in order around the parallelogram. */
    float poly[4][3], clip[8][3];
    for (int c = 0; c < 3; c++) {
        poly[0][c] = P[c] - p[c];
        poly[1][c] = P[c] + S[c] - p[c];
        poly[2][c] = P[c] + S[c] + T[c] - p[c];
        poly[3][c] = P[c] + T[c] - p[c];
    }
    return (float)ms_light_polygon_irradiance((const float (*)[3])poly, 4, n, clip);
}

static int rect_polygon(const ms_light_frame *F, const float p[3], int sides, float (*q)[3])
{
    (void)sides;
    const float *C = F->corner, *S = F->edge_s, *T = F->edge_t;
    for (int c = 0; c < 4; c++)
        for (int i = 0; i < 3; i++) q[c][i] = C[i] + ((c == 1 || c == 2) ? S[i] : 0.0f) + ((c >= 2) ? T[i] : 0.0f) - p[i];
    return 4;
}

void ms_light_parallelogram_from(ms_light *l, const ms_light_params *v)
{
    l->corner = (ms_vec3){ (float)v->v[0][0], (float)v->v[0][1], (float)v->v[0][2] };
    l->edge_s = (ms_vec3){ (float)v->v[1][0], (float)v->v[1][1], (float)v->v[1][2] };
    l->edge_t = (ms_vec3){ (float)v->v[2][0], (float)v->v[2][1], (float)v->v[2][2] };
}

static int rect_build(ms_light *l, const ms_light_params *v, float max_coord, char *msg, size_t n)
{
    (void)max_coord; (void)msg; (void)n;   /* the parallelogram is checked as every light is (scene_validate.c) */
    ms_light_parallelogram_from(l, v);
    l->shape = MS_LIGHT_RECT;
    return 0;
}

const ms_light_shape_ops ms_light_rect = {
    .shape = MS_LIGHT_RECT,
    .name = "rect",
    .textured = 1,
    .area = rect_area,
    .irradiance = rect_irradiance,
    .polygon = rect_polygon,
    .keys = { { "corner", MS_LIGHT_KEY_POINT, 1, 0, 0 }, { "edge_s", MS_LIGHT_KEY_VECTOR, 1, 0, 0 },
              { "edge_t", MS_LIGHT_KEY_VECTOR, 1, 0, 0 } },
    .build = rect_build,
};
