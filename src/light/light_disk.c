/* The disk light (shape "disk"): centre, emitting normal, radius; sampled on its bounding square with the
 * samples off the disk masked off ((2s-1)^2 + (2t-1)^2 < 1). */
#include "light_shape.h"
#include "core/vec.h"
#include <math.h>
#include <stdio.h>

#define DISK_POLY 256   /* the irradiance's polygon across the horizon */

static int disk_contains(float s, float t)
{
    const float x = 2.0f * s - 1.0f, y = 2.0f * t - 1.0f;
    return x * x + y * y < 1.0f;
}

ms_status ms_light_disk(ms_light *l, ms_vec3 c, ms_vec3 m, float r)
{
    float n[3] = { m.x, m.y, m.z };
    const float len = v3_len(n);
    if (!(len > 0.0f) || !(r > 0.0f) || !isfinite(len) || !isfinite(r)) return MS_ERR_INVALID;
    v3_scale(n, n, 1.0f / len);
    /* An orthonormal frame from n alone (Duff et al. 2017, "Building an orthonormal basis, revisited"):
     * continuous except where n.z changes sign, and exact enough that the square is a square. */
    const float sign = copysignf(1.0f, n[2]), a = -1.0f / (sign + n[2]), b = n[0] * n[1] * a;
    float e1[3] = { 1.0f + sign * n[0] * n[0] * a, sign * b, -sign * n[0] };
    float e2[3] = { b, sign + n[1] * n[1] * a, -n[1] };
    /* cross(e1, e2) = n: the square emits towards m. */
    const float d = 2.0f * r;
    l->corner = (ms_vec3){ c.x - r * (e1[0] + e2[0]), c.y - r * (e1[1] + e2[1]), c.z - r * (e1[2] + e2[2]) };
    l->edge_s = (ms_vec3){ d * e1[0], d * e1[1], d * e1[2] };
    l->edge_t = (ms_vec3){ d * e2[0], d * e2[1], d * e2[2] };
    l->shape = MS_LIGHT_DISK;
    return MS_OK;
}

static float disk_area(const ms_light *l, const ms_light_frame *F)
{
    (void)l;
    return v3_len(F->normal) * (float)(M_PI / 4.0);
}

/* A disk over a square: the closed form, 0 wholly below the horizon, or -1 when it crosses the horizon. */
static double disk_closed_form(const float C[3], const float S[3], const float T[3], const float p[3], const float n[3])
{
    float m[3], w[3], rho[3];
    v3_cross(m, S, T);
    v3_normalize(m, m);
    const double r = 0.5 * (double)v3_len(S);
    /* Below the horizon somewhere: (c - p) . n <= r |n - (n.m) m| */
    float nt[3], cp[3];
    v3_madd(nt, n, m, -v3_dot(n, m));
    v3_sub(cp, C, p);
    const double above = (double)v3_dot(cp, n), reach = r * (double)v3_len(nt);
    if (above < -reach * (1.0 + 1e-6)) return 0.0;   /* wholly below the horizon */
    if (!(above > reach * (1.0 + 1e-6))) return -1.0;
    v3_sub(w, p, C);
    const double h = (double)v3_dot(w, m);
    v3_madd(rho, w, m, -(float)h);
    const double a = (double)v3_len(rho);
    const double z = a * a + h * h + r * r, q = sqrt(z * z - 4.0 * r * r * a * a);
    const double fpar = 0.5 * (1.0 - (z - 2.0 * r * r) / q);
    const double fperp = a > 0.0 ? h / (2.0 * a) * (z / q - 1.0) : 0.0;
    const double nrho = a > 0.0 ? (double)v3_dot(rho, n) / a : 0.0;
    return M_PI * (fpar * -(double)v3_dot(m, n) + fperp * -nrho);
}

/* Exact where the whole disk (a circle: its parallelogram a square) lies above the receiver's plane,
 * E = n . Phi with the vector irradiance Phi = pi (F_par (-m) + F_perp (-rho)) of the disk (centre c,
 * emitting normal m, radius r) at lateral offset a and height h: the classic differential-element-to-disk
 * form factors (Howell's catalogue, configurations "plane element parallel to / perpendicular to a disk"),
 * F_par = (1 - (z - 2r^2)/q)/2, F_perp = h/(2a) (z/q - 1), z = a^2 + h^2 + r^2, q = sqrt(z^2 - 4 r^2 a^2);
 * E is linear in n only while no part of the disk is below the horizon. Across the horizon, and for an
 * ellipse (a disk over a non-square parallelogram): the polygon formula on a clipped 256-gon inscribed in
 * the shape with its area (half-diameters scaled by sqrt((2pi/N)/sin(2pi/N))): an approximation, within
 * 1e-4 relative of numerical integration (tests/test_lights.c). */
static float disk_irradiance(const ms_light *l, const ms_light_frame *F, const float p[3], const float n[3])
{
    (void)l;
    const float *P = F->corner, *S = F->edge_s, *T = F->edge_t;
    float rel[3];
    v3_sub(rel, p, P);
    if (!(v3_dot(rel, F->normal) > 0.0f)) return 0.0f;   /* behind the emitting side */
    float C[3];
    for (int c = 0; c < 3; c++) C[c] = P[c] + 0.5f * (S[c] + T[c]);
    const float ls = v3_len(S), lt = v3_len(T);
    const int circle = fabsf(ls - lt) <= 1e-5f * ls && fabsf(v3_dot(S, T)) <= 1e-5f * ls * lt;
    if (circle) {
        const double e = disk_closed_form(C, S, T, p, n);
        if (e >= 0.0) return (float)e;
    }
    float poly[DISK_POLY][3], clip[DISK_POLY + 2][3];
    const double step = 2.0 * M_PI / DISK_POLY, grow = sqrt(step / sin(step));
    for (int i = 0; i < DISK_POLY; i++) {
        const float cs = (float)(0.5 * grow * cos(step * i)), sn = (float)(0.5 * grow * sin(step * i));
        for (int c = 0; c < 3; c++) poly[i][c] = C[c] + cs * S[c] + sn * T[c] - p[c];
    }
    return (float)ms_light_polygon_irradiance((const float (*)[3])poly, DISK_POLY, n, clip);
}

/* The regular `sides`-gon inscribed in the disk's ellipse, scaled to the ellipse's area (an approximation:
 * the specular of a disk by a polygon of equal area, off by less than the 32-gon's shape, 0.3% of the
 * radius, for LTC's 32 sides). */
static int disk_polygon(const ms_light_frame *F, const float p[3], int sides, float (*q)[3])
{
    const float *C = F->corner, *S = F->edge_s, *T = F->edge_t;
    const double scale = sqrt(M_PI / (0.5 * sides * sin(2.0 * M_PI / sides)));
    for (int c = 0; c < sides; c++) {
        const double a = 2.0 * M_PI * c / sides, cs = 0.5 * scale * cos(a), sn = 0.5 * scale * sin(a);
        for (int i = 0; i < 3; i++) q[c][i] = (float)(C[i] + 0.5 * (S[i] + T[i]) + cs * S[i] + sn * T[i] - p[i]);
    }
    return sides;
}

static int disk_build(ms_light *l, const ms_light_params *v, float max_coord, char *msg, size_t n)
{
    const double r = v->v[2][0];
    if (!(r > 0) || r > max_coord) { snprintf(msg, n, "radius must be in (0, %g]", (double)max_coord); return -1; }
    const ms_vec3 c = { (float)v->v[0][0], (float)v->v[0][1], (float)v->v[0][2] };
    const ms_vec3 m = { (float)v->v[1][0], (float)v->v[1][1], (float)v->v[1][2] };
    if (ms_light_disk(l, c, m, (float)r)) { snprintf(msg, n, "normal must not be zero"); return -1; }
    return 0;
}

const ms_light_shape_ops ms_light_disk_shape = {
    .shape = MS_LIGHT_DISK,
    .name = "disk",
    .textured = 1,
    .contains = disk_contains,
    .area = disk_area,
    .irradiance = disk_irradiance,
    .polygon = disk_polygon,
    .keys = { { "center", MS_LIGHT_KEY_POINT, 1, 0, 0 }, { "normal", MS_LIGHT_KEY_VECTOR, 1, 0, 0 },
              { "radius", MS_LIGHT_KEY_NUMBER, 1, 0, 0 } },
    .build = disk_build,
};

/* The ellipse (shape "ellipse"): the ellipse inscribed in any parallelogram, as Blender's and Unity's ellipse
 * area lights are; the same MS_LIGHT_DISK everywhere else, only its scene-file keys differ from the disk's. */
static int ellipse_build(ms_light *l, const ms_light_params *v, float max_coord, char *msg, size_t n)
{
    (void)max_coord; (void)msg; (void)n;   /* the parallelogram is checked as every light is (scene_validate.c) */
    ms_light_parallelogram_from(l, v);
    l->shape = MS_LIGHT_DISK;
    return 0;
}

const ms_light_shape_ops ms_light_ellipse_shape = {
    .shape = MS_LIGHT_DISK,
    .name = "ellipse",
    .textured = 1,
    .contains = disk_contains,
    .area = disk_area,
    .irradiance = disk_irradiance,
    .polygon = disk_polygon,
    .keys = { { "corner", MS_LIGHT_KEY_POINT, 1, 0, 0 }, { "edge_s", MS_LIGHT_KEY_VECTOR, 1, 0, 0 },
              { "edge_t", MS_LIGHT_KEY_VECTOR, 1, 0, 0 } },
    .build = ellipse_build,
};
