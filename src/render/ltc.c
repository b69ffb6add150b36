/* Area-light GGX specular by linearly transformed cosines (ltc.h). As in the authors' demo
 * (ltc_code/webgl/shaders/ltc/ltc_quad.fs): the light's corners go into the frame (T1, T2, n) with the
 * view in the T1-z plane, through the fitted inverse matrix Minv, and the clamped-cosine integral over the
 * transformed polygon is Lambert's edge sum after clipping to z >= 0. Departure: the matrix is
 * interpolated here in C from the table entries normalised by their (1,1) element (what the demo's
 * texture holds), not by texture hardware. */
#include "ltc.h"
#include "microshadow.h"
#include "ltc_table.h"
#include "core/vec.h"
#include "light/light_shape.h"
#include <math.h>

/* Bilinear Minv (normalised by its (1,1) element) and magnitude at (roughness, cos theta_v). */
static void lookup(float roughness, float cos_v, double minv[9], double *mag)
{
    const int N = ms_ltc_table_size();
    double x = (double)roughness * (N - 1), y = sqrt(1.0 - (double)cos_v) * (N - 1);
    if (x < 0) x = 0;
    if (x > N - 1) x = N - 1;
    if (!(y >= 0)) y = 0;
    if (y > N - 1) y = N - 1;
    int a0 = (int)x, t0 = (int)y;
    if (a0 > N - 2) a0 = N - 2;
    if (t0 > N - 2) t0 = N - 2;
    const double fx = x - a0, fy = y - t0;
    for (int c = 0; c < 9; c++) minv[c] = 0.0;
    *mag = 0.0;
    for (int dy = 0; dy < 2; dy++)
        for (int dx = 0; dx < 2; dx++) {
            const double w = (dx ? fx : 1.0 - fx) * (dy ? fy : 1.0 - fy);
            const int idx = (a0 + dx) + (t0 + dy) * N;
            const double *m = ms_ltc_table_minv(idx);
            for (int c = 0; c < 9; c++) minv[c] += w * m[c] / m[4];
            *mag += w * ms_ltc_table_magnitude(idx);
        }
}

#define DISK_SIDES 32

/* The light's outline as a convex polygon (relative to p) into q[][3]; returns the vertex count, 0 when p
 * sees no emitting side. The shape's own polygon (light_shape.h): a disk (and a sphere's outline disk seen
 * from p) is the regular DISK_SIDES-gon inscribed in its ellipse, scaled to the ellipse's area. */
static int light_polygon(const ms_light *l0, const float p[3], float q[DISK_SIDES][3])
{
    ms_light planar;
    const ms_light *l = l0;
    const ms_light_shape_ops *shape = ms_light_shape_of(l0->shape);
    if (!shape) shape = ms_light_shape_of(MS_LIGHT_RECT);
    if (shape->outline) {
        if (shape->outline(l0, p, &planar)) return 0;   /* inside the shape */
        l = &planar;
        shape = ms_light_shape_of(l->shape);
    }
    ms_light_frame F;
    ms_light_frame_of(l, &F);
    float rel[3];
    v3_sub(rel, p, F.corner);
    if (!(v3_dot(rel, F.normal) > 0.0f)) return 0;   /* behind the emitting side */
    return shape->polygon(&F, p, DISK_SIDES, q);
}

float ms_ltc_ggx(const ms_light *l, const float p[3], const float n[3], const float v[3], float roughness)
{
    float q[DISK_SIDES][3];
    const int nq = light_polygon(l, p, q);
    if (!nq) return 0.0f;
    const float nv = v3_dot(n, v);
    if (!(nv > 0.0f)) return 0.0f;
    /* T1: the view's tangential part; at normal incidence any tangent does (the lobe is symmetric). */
    float t1[3], t2[3];
    v3_madd(t1, v, n, -nv);
    if (!(v3_len(t1) > 1e-6f)) {
        const float a[3] = { 1, 0, 0 }, b[3] = { 0, 1, 0 };
        v3_cross(t1, fabsf(n[0]) < 0.9f ? a : b, n);
    }
    v3_normalize(t1, t1);
    v3_cross(t2, n, t1);
    double minv[9], mag;
    lookup(roughness, nv > 1.0f ? 1.0f : nv, minv, &mag);
    double poly[DISK_SIDES][3];
    for (int c = 0; c < nq; c++) {
        const double loc[3] = { v3_dot(q[c], t1), v3_dot(q[c], t2), v3_dot(q[c], n) };
        for (int r = 0; r < 3; r++) poly[c][r] = minv[r] * loc[0] + minv[3 + r] * loc[1] + minv[6 + r] * loc[2];
    }
    /* Sutherland-Hodgman against z >= 0 (the transformed horizon): a convex polygon gains at most one vertex. */
    double clip[DISK_SIDES + 1][3];
    int m = 0;
    for (int i = 0; i < nq; i++) {
        const double *a = poly[i], *b = poly[(i + 1) % nq];
        if (a[2] >= 0.0) { clip[m][0] = a[0]; clip[m][1] = a[1]; clip[m][2] = a[2]; m++; }
        if ((a[2] >= 0.0) != (b[2] >= 0.0)) {
            const double t = a[2] / (a[2] - b[2]);
            for (int c = 0; c < 3; c++) clip[m][c] = a[c] + t * (b[c] - a[c]);
            m++;
        }
    }
    if (m < 3) return 0.0f;
    double sum = 0.0;
    for (int i = 0; i < m; i++) {
        double a[3], b[3], g[3];
        const double la = sqrt(clip[i][0] * clip[i][0] + clip[i][1] * clip[i][1] + clip[i][2] * clip[i][2]);
        const double *cb = clip[(i + 1) % m];
        const double lb = sqrt(cb[0] * cb[0] + cb[1] * cb[1] + cb[2] * cb[2]);
        if (!(la > 0.0) || !(lb > 0.0)) continue;
        for (int c = 0; c < 3; c++) { a[c] = clip[i][c] / la; b[c] = cb[c] / lb; }
        g[0] = a[1] * b[2] - a[2] * b[1];
        g[1] = a[2] * b[0] - a[0] * b[2];
        g[2] = a[0] * b[1] - a[1] * b[0];
        const double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if (!(gl > 0.0)) continue;
        sum += atan2(gl, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * g[2] / gl;
    }
    /* The clamped cosine's integral over the polygon: |edge sum| / (2 pi). */
    return (float)(mag * fabs(sum) / (2.0 * M_PI));
}
