/* Camera projections (docs/cameras.md), every type: world point -> ms_camera_project -> ms_camera_ray_at
 * passes through the point, and pixel -> ray -> point -> project gives the pixel back, over random cameras,
 * with the seams, poles, rims and antipodes; what project refuses is out of view by an independent
 * (double precision) test; ms_camera_angle_per_pixel bounds the angle between any two rays and is
 * nearly attained; the primary hits of every type match a brute-force loop over the triangles and the
 * Embree primary's; a fisheye of 180 degrees and a parabolic camera see the same triangle in the same
 * direction; and each type renders end to end through the CLI's scene files. */
#include "testutil.h"
#include "camera/camera.h"
#include "accel/bvh.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint32_t g_rng = 12345u;
static float rnd(void)
{
    g_rng = g_rng * 1664525u + 1013904223u;
    return (float)(g_rng >> 8) / 16777216.0f;
}

static const ms_camera_type all_types[] = { MS_CAMERA_PINHOLE, MS_CAMERA_ORTHOGRAPHIC, MS_CAMERA_FISHEYE,
                                            MS_CAMERA_LATLONG, MS_CAMERA_PARABOLIC };
static const char *const type_names[] = { "pinhole", "orthographic", "fisheye", "latlong", "parabolic" };

static ms_camera random_camera(ms_camera_type t)
{
    ms_camera c;
    memset(&c, 0, sizeof c);
    c.eye = (ms_vec3){ 20 * rnd() - 10, 20 * rnd() - 10, 20 * rnd() - 10 };
    c.target = (ms_vec3){ 4 * rnd() - 2, 4 * rnd() - 2, 4 * rnd() - 2 };
    c.up = (ms_vec3){ 2 * rnd() - 1, 2 * rnd() - 1, 2 * rnd() - 1 };
    c.type = t;
    c.fov_y = 10 + 160 * rnd();
    c.fov = rnd() < 0.2f ? 360.0f : rnd() < 0.2f ? 180.0f : 5 + 355 * rnd();
    c.ortho_height = 0.1f + 30 * rnd();
    c.width = 1 + (int)(600 * rnd());
    c.height = 1 + (int)(600 * rnd());
    return c;
}

static double dotd(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double lend(const double a[3]) { return sqrt(dotd(a, a)); }

/* Angle between two float vectors, in double (atan2 of the cross and dot: accurate at small angles). */
static double angle_between(const float a[3], const float b[3])
{
    double x[3] = { a[0], a[1], a[2] }, y[3] = { b[0], b[1], b[2] };
    double c[3] = { x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0] };
    return atan2(lend(c), dotd(x, y));
}

/* The camera's frame in double, from the camera alone (not from the basis under test). */
static void frame_d(const ms_camera *c, double f[3], double r[3], double u[3])
{
    double e[3] = { c->eye.x, c->eye.y, c->eye.z }, t[3] = { c->target.x, c->target.y, c->target.z };
    double up[3] = { c->up.x, c->up.y, c->up.z };
    for (int k = 0; k < 3; k++) f[k] = t[k] - e[k];
    double l = lend(f);
    for (int k = 0; k < 3; k++) f[k] /= l;
    r[0] = f[1] * up[2] - f[2] * up[1]; r[1] = f[2] * up[0] - f[0] * up[2]; r[2] = f[0] * up[1] - f[1] * up[0];
    l = lend(r);
    for (int k = 0; k < 3; k++) r[k] /= l;
    u[0] = r[1] * f[2] - r[2] * f[1]; u[1] = r[2] * f[0] - r[0] * f[2]; u[2] = r[0] * f[1] - r[1] * f[0];
}

/* Independent: does the camera see direction/point p (double, margin eps in the tested quantity)?
 * 1 inside by more than eps, 0 outside by more than eps, -1 too close to call. */
static int sees(const ms_camera *c, const float p[3], double eps)
{
    double f[3], r[3], u[3], d[3] = { p[0] - c->eye.x, p[1] - c->eye.y, p[2] - c->eye.z };
    frame_d(c, f, r, u);
    const double z = dotd(d, f), l = lend(d);
    double m;
    switch (c->type) {
    case MS_CAMERA_PINHOLE: m = z / l; break;
    case MS_CAMERA_ORTHOGRAPHIC: m = z / (l + 1.0); break;
    case MS_CAMERA_FISHEYE: m = 0.5 * c->fov * M_PI / 180.0 - acos(fmax(-1.0, fmin(1.0, z / l))); break;
    case MS_CAMERA_LATLONG: return 1;
    default: m = z / l; break;   /* parabolic: the hemisphere */
    }
    return m > eps ? 1 : m < -eps ? 0 : -1;
}

/* Distance from p to the ray (o, d), and p's distance from o (the scale). */
static double ray_distance(const float o[3], const float d[3], const float p[3], double *scale)
{
    double dd[3] = { d[0], d[1], d[2] }, v[3] = { p[0] - (double)o[0], p[1] - (double)o[1], p[2] - (double)o[2] };
    const double l = lend(dd), t = dotd(v, dd) / l;
    *scale = lend(v);
    if (t < 0) return *scale;   /* behind the origin: not on the ray */
    double w[3];
    for (int k = 0; k < 3; k++) w[k] = v[k] - t * dd[k] / l;
    return lend(w);
}

/* The size of a pixel at image position (sx, sy), along x and along y: the angle (radians) between the
 * rays half a pixel either side for the central projections, the distance (world units) between their
 * origins for the orthographic one. Float rounding of positions and coordinates is judged against it. */
static void footprint(const ms_camera_basis *b, float sx, float sy, double *fx, double *fy)
{
    float o0[3], d0[3], o1[3], d1[3];
    *fx = *fy = INFINITY;
    for (int axis = 0; axis < 2; axis++) {
        const float ax = axis ? 0.0f : 0.5f, ay = axis ? 0.5f : 0.0f;
        if (ms_camera_ray_at(b, sx - ax, sy - ay, o0, d0) || ms_camera_ray_at(b, sx + ax, sy + ay, o1, d1)) continue;
        double f;
        if (b->type == MS_CAMERA_ORTHOGRAPHIC)
            f = sqrt(((double)o1[0] - o0[0]) * (o1[0] - o0[0]) + ((double)o1[1] - o0[1]) * (o1[1] - o0[1]) +
                     ((double)o1[2] - o0[2]) * (o1[2] - o0[2]));
        else
            f = angle_between(d0, d1);
        if (axis) *fy = f;
        else *fx = f;
    }
}

/* Rounding of single-precision world coordinates around the eye and the point: a few ulps of the
 * largest magnitude involved. */
static double coord_ulps(const ms_camera *c, const float p[3])
{
    const double m = fmax(fmax(fabs(c->eye.x), fabs(c->eye.y)), fmax(fabs(c->eye.z), 1.0)) +
                     fmax(fmax(fabs(p[0]), fabs(p[1])), fabs(p[2]));
    return 8 * 6e-8 * m;
}

/* How far the image position of p moves per world unit p moves (finite differences along each axis,
 * steps of 1e-3 of p's distance; the largest): the conditioning of the projection at p, by which the
 * rounding of world coordinates becomes an error in pixels (large near the latlong's poles, the
 * fisheye's antipode, the rim of a wide pinhole). */
static void sensitivity(const ms_camera_basis *b, const float p[3], double *sx, double *sy)
{
    float px, py, qx, qy, q[3];
    *sx = *sy = 0;
    if (ms_camera_project(b, p, &px, &py)) return;
    const double dist = hypot(hypot(p[0] - b->eye[0], p[1] - b->eye[1]), p[2] - b->eye[2]);
    const float h = (float)(1e-3 * fmax(dist, 1e-3));
    for (int k = 0; k < 3; k++) {
        memcpy(q, p, sizeof q);
        q[k] += h;
        if (ms_camera_project(b, q, &qx, &qy)) continue;
        double dx = fabs(qx - px);
        if (b->type == MS_CAMERA_LATLONG) dx = fmin(dx, b->width - dx);
        *sx = fmax(*sx, dx / h);
        *sy = fmax(*sy, fabs(qy - py) / h);
    }
}

/* (a) world point -> project -> ray through that position passes through the point. */
static void test_point_round_trip(void **st)
{
    (void)st;
    for (size_t ti = 0; ti < 5; ti++) {
        long seen = 0, refused = 0;
        for (int it = 0; it < 300; it++) {
            ms_camera c = random_camera(all_types[ti]);
            ms_camera_basis b;
            if (ms_camera_basis_init(&b, &c, c.width, c.height)) continue;
            for (int j = 0; j < 60; j++) {
                float p[3] = { 40 * rnd() - 20, 40 * rnd() - 20, 40 * rnd() - 20 }, px, py, o[3], d[3];
                if (ms_camera_project(&b, p, &px, &py)) {
                    refused++;
                    if (sees(&c, p, 1e-5) == 1) fail_msg("%s refused a point it sees", type_names[ti]);
                    continue;
                }
                if (sees(&c, p, 1e-5) == 0) fail_msg("%s projected a point it does not see", type_names[ti]);
                seen++;
                /* latlong px in [0, W); the others may be outside the image (pinhole, ortho) but near the
                 * circle for fisheye and parabolic */
                if (c.type == MS_CAMERA_LATLONG) assert_true(px >= 0.0f && px < (float)c.width);
                if (ms_camera_ray_at(&b, px, py, o, d)) {
                    /* only the rim's rounding may leave the circle */
                    const double rr = hypot(px - b.cx, py - b.cy) / b.radius;
                    if (!(rr < 1.0 + 1e-5)) fail_msg("%s: projected to %g radii, no ray there", type_names[ti], rr);
                    continue;
                }
                double scale, fx, fy;
                const double dist = ray_distance(o, d, p, &scale);
                footprint(&b, px, py, &fx, &fy);
                /* a thousandth of a pixel (the float position's rounding, amplified where a pixel spans a
                 * wide angle) plus the coordinates' own rounding */
                const double pix = fmin(fx, fy) * (c.type == MS_CAMERA_ORTHOGRAPHIC ? 1.0 : scale);
                const double tol = 1e-3 * pix + 2e-5 * scale + coord_ulps(&c, p);
                if (!(dist <= tol))
                    fail_msg("%s %dx%d: point %g from its ray (scale %g) at (%g, %g)", type_names[ti], c.width,
                             c.height, dist, scale, (double)px, (double)py);
            }
        }
        fprintf(stderr, "%s: %ld points projected and on their rays, %ld refused (out of view)\n", type_names[ti],
                seen, refused);
        assert_true(seen > 1000);
    }
}

/* (a) pixel -> ray -> point on the ray -> project -> the same pixel position. */
static void test_pixel_round_trip(void **st)
{
    (void)st;
    for (size_t ti = 0; ti < 5; ti++) {
        long n = 0, none = 0;
        for (int it = 0; it < 200; it++) {
            ms_camera c = random_camera(all_types[ti]);
            ms_camera_basis b;
            if (ms_camera_basis_init(&b, &c, c.width, c.height)) continue;
            for (int j = 0; j < 40; j++) {
                const float sx = rnd() * (float)c.width, sy = rnd() * (float)c.height;
                float o[3], d[3], p[3], px, py;
                if (ms_camera_ray_at(&b, sx, sy, o, d)) {
                    none++;
                    assert_true(hypot(sx - b.cx, sy - b.cy) > b.radius);   /* outside the circle only */
                    assert_true(c.type == MS_CAMERA_FISHEYE || c.type == MS_CAMERA_PARABOLIC);
                    continue;
                }
                const double r_px = hypot(sx - b.cx, sy - b.cy);
                /* the fisheye 360's rim is the antipode: every rim position is the same direction */
                if (c.type == MS_CAMERA_FISHEYE && c.fov > 300.0f && r_px > b.radius - 1.0) continue;
                const float t = 0.5f + 20 * rnd();
                for (int k = 0; k < 3; k++) p[k] = o[k] + t * d[k];
                if (ms_camera_project(&b, p, &px, &py)) {
                    /* the boundary of the hemisphere (parabolic rim, orthographic origin plane) may round out */
                    assert_true(c.type == MS_CAMERA_PARABOLIC || c.type == MS_CAMERA_FISHEYE);
                    assert_true(r_px > b.radius * (1 - 1e-3));
                    continue;
                }
                n++;
                /* a thousandth of a pixel, plus the rounding of the world coordinates in pixels (a pixel
                 * spans little near the latlong's poles or the fisheye's antipode: there x or y is
                 * ill-conditioned); the latlong's x wraps at the seam */
                double ex = fabs(px - sx), ey = fabs(py - sy), sens_x, sens_y;
                if (c.type == MS_CAMERA_LATLONG) ex = fmin(ex, (double)c.width - ex);
                sensitivity(&b, p, &sens_x, &sens_y);
                const double tolx = 2e-3 + 4 * coord_ulps(&c, p) * sens_x, toly = 2e-3 + 4 * coord_ulps(&c, p) * sens_y;
                if (!(ex <= tolx && ey <= toly))
                    fail_msg("%s %dx%d (fov %g): (%g, %g) came back as (%g, %g)", type_names[ti], c.width, c.height,
                             (double)c.fov, (double)sx, (double)sy, (double)px, (double)py);
            }
        }
        fprintf(stderr, "%s: %ld image positions round-tripped, %ld without a ray\n", type_names[ti], n, none);
        assert_true(n > 3000);
    }
}

static ms_camera axis_camera(ms_camera_type t, int W, int H)
{
    ms_camera c;
    memset(&c, 0, sizeof c);
    c.eye = (ms_vec3){ 0, 0, 0 };
    c.target = (ms_vec3){ 0, 0, -1 };   /* forward -z, right +x, up +y */
    c.up = (ms_vec3){ 0, 1, 0 };
    c.type = t;
    c.fov_y = 90;
    c.fov = 360;
    c.ortho_height = 2;
    c.width = W;
    c.height = H;
    return c;
}

static void assert_dir(const float d[3], double x, double y, double z, double tol)
{
    const double l = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
    if (!(fabs(d[0] / l - x) < tol && fabs(d[1] / l - y) < tol && fabs(d[2] / l - z) < tol))
        fail_msg("direction (%g, %g, %g), expected (%g, %g, %g)", d[0] / l, d[1] / l, d[2] / l, x, y, z);
}

/* The conventions by hand (docs/cameras.md) and the edge cases: latlong seam and poles, fisheye 360
 * antipode, parabolic rim, orthographic points behind the plane. */
static void test_conventions_and_edges(void **st)
{
    (void)st;
    ms_camera_basis b;
    float o[3], d[3], px, py;
    /* latlong 400x200: centre column forward, 3/4 right, 1/4 left, the edge columns backward, row 0 up */
    ms_camera c = axis_camera(MS_CAMERA_LATLONG, 400, 200);
    assert_int_equal(ms_camera_basis_init(&b, &c, 400, 200), 0);
    assert_int_equal(ms_camera_ray_at(&b, 200, 100, o, d), 0); assert_dir(d, 0, 0, -1, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 300, 100, o, d), 0); assert_dir(d, 1, 0, 0, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 100, 100, o, d), 0); assert_dir(d, -1, 0, 0, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 0, 100, o, d), 0); assert_dir(d, 0, 0, 1, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 400, 100, o, d), 0); assert_dir(d, 0, 0, 1, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 37, 0, o, d), 0); assert_dir(d, 0, 1, 0, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 321, 200, o, d), 0); assert_dir(d, 0, -1, 0, 1e-6);
    /* seam: just left and right of backward land at the two ends, always in [0, W) */
    float back_l[3] = { -1e-4f, 0, 1 }, back_r[3] = { 1e-4f, 0, 1 }, back[3] = { 0, 0, 1 };
    assert_int_equal(ms_camera_project(&b, back_l, &px, &py), 0); assert_true(px < 0.01f); assert_true(fabsf(py - 100) < 1e-3f);
    assert_int_equal(ms_camera_project(&b, back_r, &px, &py), 0); assert_true(px > 399.99f && px < 400.0f);
    assert_int_equal(ms_camera_project(&b, back, &px, &py), 0); assert_true(px >= 0.0f && px < 400.0f);
    assert_int_equal(ms_camera_ray_at(&b, px, py, o, d), 0); assert_dir(d, 0, 0, 1, 1e-5);
    /* poles: row 0 and row H whatever the column; near the pole the row is still accurate (atan2) */
    float pole[3] = { 0, 5, 0 }, south[3] = { 0, -5, 0 }, near_pole[3] = { 1e-3f, 1, 0 };
    assert_int_equal(ms_camera_project(&b, pole, &px, &py), 0); assert_true(fabsf(py) < 1e-4f);
    assert_int_equal(ms_camera_project(&b, south, &px, &py), 0); assert_true(fabsf(py - 200) < 1e-4f);
    assert_int_equal(ms_camera_project(&b, near_pole, &px, &py), 0);
    assert_true(fabs(py - 1e-3 / M_PI * 200) < 1e-5);
    assert_true(fabsf(px - 300) < 1e-2f);   /* toward +x: longitude 90 degrees */
    assert_true(ms_camera_angle_per_pixel(&b) > 0.0f);
    assert_int_equal(ms_camera_planar(&b), 0);

    /* fisheye 360 (101x101, radius 50.5): the centre forward, the rim the antipode (backward), half the
     * radius sideways; the antipode projects onto the rim, whose ray goes back */
    c = axis_camera(MS_CAMERA_FISHEYE, 101, 101);
    assert_int_equal(ms_camera_basis_init(&b, &c, 101, 101), 0);
    assert_int_equal(ms_camera_ray_at(&b, 50.5f, 50.5f, o, d), 0); assert_dir(d, 0, 0, -1, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 50.5f + 25.25f, 50.5f, o, d), 0); assert_dir(d, 1, 0, 0, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 50.5f, 50.5f - 25.25f, o, d), 0); assert_dir(d, 0, 1, 0, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 50.5f, 101.0f, o, d), 0); assert_dir(d, 0, 0, 1, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 0.0f, 0.0f, o, d), -1);   /* a corner: outside the circle */
    assert_int_equal(ms_camera_project(&b, back, &px, &py), 0);
    assert_true(fabs(hypot(px - 50.5, py - 50.5) - 50.5) < 1e-3);
    assert_int_equal(ms_camera_ray_at(&b, px, py, o, d), 0); assert_dir(d, 0, 0, 1, 1e-6);
    float eye[3] = { 0, 0, 0 };
    assert_int_equal(ms_camera_project(&b, eye, &px, &py), -1);
    /* fisheye 180: the rim sideways; behind is not seen */
    c.fov = 180;
    assert_int_equal(ms_camera_basis_init(&b, &c, 101, 101), 0);
    assert_int_equal(ms_camera_ray_at(&b, 101.0f, 50.5f, o, d), 0); assert_dir(d, 1, 0, 0, 1e-6);
    assert_int_equal(ms_camera_project(&b, back, &px, &py), -1);

    /* parabolic: centre forward, rim sideways, half the radius at 2 atan(1/2) from forward; behind refused */
    c = axis_camera(MS_CAMERA_PARABOLIC, 101, 101);
    assert_int_equal(ms_camera_basis_init(&b, &c, 101, 101), 0);
    assert_int_equal(ms_camera_ray_at(&b, 50.5f, 50.5f, o, d), 0); assert_dir(d, 0, 0, -1, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 50.5f, 0.0f, o, d), 0); assert_dir(d, 0, 1, 0, 1e-6);
    assert_int_equal(ms_camera_ray_at(&b, 50.5f + 25.25f, 50.5f, o, d), 0);
    assert_dir(d, sin(2 * atan(0.5)), 0, -cos(2 * atan(0.5)), 1e-6);
    float side[3] = { -3, 0, 0 }, behind_side[3] = { -3, 0, 1e-3f };
    assert_int_equal(ms_camera_project(&b, side, &px, &py), 0);
    assert_true(fabsf(px) < 1e-4f && fabsf(py - 50.5f) < 1e-4f);
    assert_int_equal(ms_camera_project(&b, behind_side, &px, &py), -1);
    assert_int_equal(ms_camera_ray_at(&b, 50.5f + 50.6f, 50.5f, o, d), -1);

    /* orthographic 2 units high, 4x2 pixels: pixel (3,0)'s ray starts at (1.5, 0.5, 0), along -z; points
     * behind the origin plane are refused, on it accepted */
    c = axis_camera(MS_CAMERA_ORTHOGRAPHIC, 4, 2);
    c.eye = (ms_vec3){ 1, 2, 3 };
    c.target = (ms_vec3){ 1, 2, 2 };
    assert_int_equal(ms_camera_basis_init(&b, &c, 4, 2), 0);
    assert_int_equal(ms_camera_ray(&b, 3, 0, o, d), 0);
    assert_true(fabsf(o[0] - 2.5f) < 1e-6f && fabsf(o[1] - 2.5f) < 1e-6f && fabsf(o[2] - 3) < 1e-6f);
    assert_dir(d, 0, 0, -1, 1e-7);
    float on_plane[3] = { 2.5f, 2.5f, 3 }, in_front[3] = { 2.5f, 2.5f, -100 }, behind_plane[3] = { 2.5f, 2.5f, 3.01f };
    assert_int_equal(ms_camera_project(&b, on_plane, &px, &py), 0); assert_true(fabsf(px - 3.5f) < 1e-5f && fabsf(py - 0.5f) < 1e-5f);
    assert_int_equal(ms_camera_project(&b, in_front, &px, &py), 0); assert_true(fabsf(px - 3.5f) < 1e-5f && fabsf(py - 0.5f) < 1e-5f);
    assert_int_equal(ms_camera_project(&b, behind_plane, &px, &py), -1);
    assert_int_equal(ms_camera_planar(&b), 1);
    /* the viewer for shading: up the ray, so the view vector is -forward everywhere */
    float viewer[3];
    ms_camera_viewer(&b, in_front, viewer);
    assert_true(fabsf(viewer[2] - (-99.0f)) < 1e-4f && viewer[0] == in_front[0]);

    /* zeroed fields past height: a pinhole; an unknown type or a field out of range is refused */
    ms_camera z = axis_camera(MS_CAMERA_PINHOLE, 8, 8);
    assert_int_equal(ms_camera_basis_init(&b, &z, 8, 8), 0);
    z.type = (ms_camera_type)7;
    assert_int_equal(ms_camera_basis_init(&b, &z, 8, 8), -1);
    z = axis_camera(MS_CAMERA_FISHEYE, 8, 8); z.fov = 360.5f;
    assert_int_equal(ms_camera_basis_init(&b, &z, 8, 8), -1);
    z = axis_camera(MS_CAMERA_ORTHOGRAPHIC, 8, 8); z.ortho_height = 0;
    assert_int_equal(ms_camera_basis_init(&b, &z, 8, 8), -1);
    z.ortho_height = 1e15f;   /* 16384 x 1 pixels: origins 8e18 from the eye, beyond the coordinate range */
    assert_int_equal(ms_camera_basis_init(&b, &z, 8, 8), 0);
    assert_int_equal(ms_camera_basis_init(&b, &z, 16384, 1), -1);
}

/* (c) ms_camera_angle_per_pixel is a Lipschitz bound: for random pairs of image positions, the angle
 * between their rays is at most L times their distance; and it is nearly attained (a bound 10x too
 * loose would make the 3D rasterizer's cones needlessly wide). */
static void test_angle_bound(void **st)
{
    (void)st;
    const ms_camera_type curved[] = { MS_CAMERA_FISHEYE, MS_CAMERA_LATLONG, MS_CAMERA_PARABOLIC };
    for (int ti = 0; ti < 3; ti++) {
        double worst = 0.0;
        long n = 0;
        for (int it = 0; it < 200; it++) {
            ms_camera c = random_camera(curved[ti]);
            c.width = 2 + (int)(1000 * rnd());
            c.height = 2 + (int)(1000 * rnd());
            ms_camera_basis b;
            if (ms_camera_basis_init(&b, &c, c.width, c.height)) continue;
            const double L = ms_camera_angle_per_pixel(&b);
            assert_true(L > 0.0);
            for (int j = 0; j < 200; j++) {
                float ax = rnd() * c.width, ay = rnd() * c.height, bx, by;
                if (j % 2) {   /* neighbours, a pixel or so away, in any direction */
                    bx = ax + 2 * rnd() - 1;
                    by = ay + 2 * rnd() - 1;
                } else {
                    bx = rnd() * c.width;
                    by = rnd() * c.height;
                }
                float o[3], da[3], db[3];
                if (ms_camera_ray_at(&b, ax, ay, o, da) || ms_camera_ray_at(&b, bx, by, o, db)) continue;
                const double r = hypot((double)ax - bx, (double)ay - by);
                if (r < 0.25) continue;   /* below, the float rays' own rounding (1e-7 rad) is comparable */
                const double ang = angle_between(da, db);
                /* float rounding: 1e-4 relative (the interface's promise), and the float rays' own rounding
                 * (unit vectors to 6e-8 a component: 3e-7 rad), which dominates below a pixel or so */
                if (!(ang <= L * r * (1 + 1e-4) + 3e-7))
                    fail_msg("%s %dx%d: angle %.9g > L r = %.9g (r %g)", type_names[curved[ti]], c.width, c.height,
                             ang, L * r, r);
                worst = fmax(worst, ang / (L * r));
                n++;
            }
        }
        fprintf(stderr, "%s: %ld pairs, largest angle / (L r) = %.5f\n", type_names[curved[ti]], n, worst);
        assert_true(n > 10000);
        assert_true(worst > 0.9);
    }
    /* planar types: 0 */
    ms_camera c = axis_camera(MS_CAMERA_PINHOLE, 8, 8);
    ms_camera_basis b;
    assert_int_equal(ms_camera_basis_init(&b, &c, 8, 8), 0);
    assert_true(ms_camera_angle_per_pixel(&b) == 0.0f);
}

/* Brute force: the source triangle nearest along the ray (double precision Moller-Trumbore), or -1;
 * *margin the smallest barycentric (a hit near an edge may go either way). */
static long brute_force(const ms_scene *sc, const float o[3], const float d[3], double *margin)
{
    long best = -1;
    double bt = INFINITY;
    *margin = 0;
    for (size_t t = 0; t < sc->n_tris; t++) {
        const float *v = sc->tri + 9 * t;
        double e1[3], e2[3], s[3], p[3], q[3];
        for (int k = 0; k < 3; k++) { e1[k] = v[3 + k] - v[k]; e2[k] = v[6 + k] - v[k]; s[k] = o[k] - (double)v[k]; }
        p[0] = d[1] * e2[2] - d[2] * e2[1]; p[1] = d[2] * e2[0] - d[0] * e2[2]; p[2] = d[0] * e2[1] - d[1] * e2[0];
        const double det = dotd(e1, p);
        if (fabs(det) < 1e-30) continue;
        const double u = dotd(s, p) / det;
        q[0] = s[1] * e1[2] - s[2] * e1[1]; q[1] = s[2] * e1[0] - s[0] * e1[2]; q[2] = s[0] * e1[1] - s[1] * e1[0];
        const double dd[3] = { d[0], d[1], d[2] };
        const double v2 = dotd(dd, q) / det, t2 = dotd(e2, q) / det;
        if (u < 0 || v2 < 0 || u + v2 > 1 || !(t2 > 0) || t2 >= bt) continue;
        bt = t2;
        best = (long)t;
        *margin = fmin(fmin(u, v2), 1 - u - v2);
    }
    return best;
}

/* Inside the built-in scene (a 16x16 ground, a pillar, a cube, a plate and a sphere), looking at them. */
static ms_camera default_scene_camera(ms_camera_type t)
{
    ms_camera c;
    memset(&c, 0, sizeof c);
    c.eye = (ms_vec3){ 0.5f, 2.5f, 4.0f };
    c.target = (ms_vec3){ -0.5f, 0.8f, -1.0f };
    c.up = (ms_vec3){ 0, 1, 0 };
    c.fov_y = 50;
    c.type = t;
    c.fov = 230;
    c.ortho_height = 9;
    return c;
}

/* (b) every type: the BVH primary's triangle at every pixel is the brute-force one except near edges,
 * misses exactly where there is no ray or nothing in the way; and the Embree primary (when compiled in)
 * gives the same triangle and the very same point wherever it picks the same triangle. */
static void test_primaries(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 0), 0);
    const int W = 96, H = 64;
    for (int ti = 0; ti < 5; ti++) {
        sc.camera = default_scene_camera(all_types[ti]);
        ms_render_ctx ctx;
        tu_ctx_init(&ctx, &sc, &bvh, W, H, 16);
        const ms_primary_method *pb = ms_find_primary_method("bvh");
        void *sb = NULL;
        char err[512] = "";
        assert_int_equal(pb->create(&ctx, &sb, err, sizeof err), 0);
        ms_hit *hb = malloc(sizeof *hb * W * H);
        assert_non_null(hb);
        pb->trace(sb, &ctx, 0, 0, W, H, hb);
        long hits = 0, noray = 0, edge = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const ms_hit *h = &hb[y * W + x];
                float o[3], d[3];
                if (ms_camera_ray(&ctx.cam, x, y, o, d)) { noray++; assert_int_equal(h->prim, UINT32_MAX); continue; }
                double margin;
                const long bf = brute_force(&sc, o, d, &margin);
                const long got = h->prim == UINT32_MAX ? -1 : (long)bvh.tri_source[h->prim];
                if (got != bf) {
                    if (!(margin < 1e-4 || bf < 0 || got < 0)) fail_msg("%s (%d,%d): bvh %ld, brute force %ld (margin %g)",
                                                                       type_names[ti], x, y, got, bf, margin);
                    edge++;
                    continue;
                }
                if (got < 0) continue;
                hits++;
                /* the hit point lies on the pixel's ray */
                double scale;
                assert_true(ray_distance(o, d, h->p, &scale) <= 1e-5 * (scale + 1));
            }
        fprintf(stderr, "%s: %ld pixels hit as brute force, %ld without a ray, %ld edge ties\n", type_names[ti], hits,
                noray, edge);
        assert_true(hits > W * H / 8);
        assert_true(edge * 100 <= W * H);
        if (all_types[ti] == MS_CAMERA_FISHEYE || all_types[ti] == MS_CAMERA_PARABOLIC) assert_true(noray > 0);
        else assert_int_equal(noray, 0);
#ifdef MS_HAVE_EMBREE
        const ms_primary_method *pe = ms_find_primary_method("embree");
        void *se = NULL;
        assert_int_equal(pe->create(&ctx, &se, err, sizeof err), 0);
        ms_hit *he = malloc(sizeof *he * W * H);
        assert_non_null(he);
        memset(he, 0x5a, sizeof *he * W * H);   /* every pixel must be written, misses outside the circle too */
        for (int y0 = 0; y0 < H; y0 += 13)
            for (int x0 = 0; x0 < W; x0 += 11) {
                int x1 = x0 + 11 < W ? x0 + 11 : W, y1 = y0 + 13 < H ? y0 + 13 : H;
                ms_hit tile[13 * 11];
                memset(tile, 0x5a, sizeof tile);
                pe->trace(se, &ctx, x0, y0, x1, y1, tile);
                for (int y = y0; y < y1; y++)
                    for (int x = x0; x < x1; x++) he[y * W + x] = tile[(y - y0) * (x1 - x0) + (x - x0)];
            }
        long same = 0, other = 0;
        for (int i = 0; i < W * H; i++) {
            if (hb[i].prim == UINT32_MAX || he[i].prim == UINT32_MAX) {
                if (hb[i].prim != he[i].prim) other++;
                continue;
            }
            assert_true(he[i].prim < bvh.n_tris);
            if (hb[i].prim != he[i].prim) { other++; continue; }
            same++;
            assert_memory_equal(hb[i].p, he[i].p, sizeof hb[i].p);
            assert_memory_equal(hb[i].n, he[i].n, sizeof hb[i].n);
        }
        fprintf(stderr, "%s: embree %ld same triangle and point, %ld otherwise (ties)\n", type_names[ti], same, other);
        assert_true(other * 100 <= W * H);
        free(he);
        pe->destroy(se);
#endif
        free(hb);
        pb->destroy(sb);
    }
    ms_bvh_free(&bvh);
    ms_scene_free(&sc);
}

/* (d) a fisheye of 180 degrees and a parabolic camera on the same axis: a fisheye pixel's direction,
 * projected into the parabolic image and cast back from there, is the same direction, and the parabolic
 * primary at the nearest pixel sees the same triangle except at edges. */
static void test_fisheye_parabolic(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 0), 0);
    const int W = 128, H = 128;
    sc.camera = default_scene_camera(MS_CAMERA_FISHEYE);
    sc.camera.fov = 180;
    ms_render_ctx cf, cp;
    tu_ctx_init(&cf, &sc, &bvh, W, H, 16);
    sc.camera.type = MS_CAMERA_PARABOLIC;
    tu_ctx_init(&cp, &sc, &bvh, W, H, 16);
    const ms_primary_method *pb = ms_find_primary_method("bvh");
    ms_hit *hf = malloc(sizeof *hf * W * H), *hp = malloc(sizeof *hp * W * H);
    assert_non_null(hf);
    assert_non_null(hp);
    pb->trace(NULL, &cf, 0, 0, W, H, hf);
    pb->trace(NULL, &cp, 0, 0, W, H, hp);
    long same = 0, differ = 0, compared = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float o[3], d[3], q[3], px, py, o2[3], d2[3];
            if (ms_camera_ray(&cf.cam, x, y, o, d)) continue;
            for (int k = 0; k < 3; k++) q[k] = o[k] + d[k];
            assert_int_equal(ms_camera_project(&cp.cam, q, &px, &py), 0);
            assert_int_equal(ms_camera_ray_at(&cp.cam, px, py, o2, d2), 0);
            assert_true(angle_between(d, d2) < 2e-6);
            /* the exact direction through the BVH from the parabolic side: the fisheye's triangle */
            ms_ray r;
            ms_ray_hit rh;
            memcpy(r.o, o2, sizeof r.o);
            memcpy(r.d, d2, sizeof r.d);
            r.tmin = 0;
            r.tmax = INFINITY;
            const uint32_t prim = ms_bvh_closest(&bvh, &r, &rh) ? rh.prim : UINT32_MAX;
            const ms_hit *a = &hf[y * W + x];
            compared++;
            if (prim == a->prim) same++;
            else differ++;
        }
    /* image level: each parabolic pixel's hit point, projected into the fisheye image, lands on a pixel
     * that sees the same triangle, except within a pixel of a triangle's edge */
    long img_same = 0, img_other = 0;
    for (int i = 0; i < W * H; i++) {
        if (hp[i].prim == UINT32_MAX) continue;
        float px, py;
        assert_int_equal(ms_camera_project(&cf.cam, hp[i].p, &px, &py), 0);
        const int ix = (int)floorf(px), iy = (int)floorf(py);
        if (ix < 0 || iy < 0 || ix >= W || iy >= H) { img_other++; continue; }
        if (hf[iy * W + ix].prim == hp[i].prim) img_same++;
        else img_other++;
    }
    fprintf(stderr, "fisheye 180 vs parabolic: %ld directions the same triangle, %ld not; image level %ld same, "
            "%ld at edges\n", same, differ, img_same, img_other);
    assert_true(compared > W * H / 2);
    assert_true(differ * 1000 <= compared);
    assert_true(img_same > W * H / 4);
    assert_true(img_other * 10 <= img_same);
    free(hf);
    free(hp);
    ms_bvh_free(&bvh);
    ms_scene_free(&sc);
}

static void render_ok(const ms_scene *sc, const char *method, int w, int h, ms_frame *f)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.samples = 256;
    o.width = w;
    o.height = h;
    o.seed = 3;
    tu_render_ok(sc, &o, f);
}

/* End to end, every type: whole frames of the built-in scene by the reference ray tracer and by the
 * paper's scanline method (and Embree's, when compiled in) agree sample for sample but for ties, with
 * the same misses; a pixel without a ray is a miss: V = S = -1 and black. */
static void test_frames(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    const int W = 64, H = 48;
    const char *const others[] = { "scanline",
#ifdef MS_HAVE_EMBREE
                                   "embree",
#endif
                                   NULL };
    for (int ti = 0; ti < 5; ti++) {
        sc.camera = default_scene_camera(all_types[ti]);
        ms_frame rt;
        render_ok(&sc, "raytrace", W, H, &rt);
        ms_camera_basis b;
        assert_int_equal(ms_camera_basis_init(&b, &sc.camera, W, H), 0);
        long noray = 0, lit = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const size_t i = (size_t)y * W + x;
                float o[3], d[3];
                if (ms_camera_ray(&b, x, y, o, d)) {
                    noray++;
                    assert_true(rt.vis[i] == -1.0f && rt.shadow[i] == -1.0f);
                    assert_true(rt.rgb[3 * i] == 0.0f && rt.rgb[3 * i + 1] == 0.0f && rt.rgb[3 * i + 2] == 0.0f);
                }
                lit += rt.vis[i] > 0.0f;
            }
        assert_true(lit > W * H / 8);
        for (int m = 0; others[m]; m++) {
            ms_frame f;
            render_ok(&sc, others[m], W, H, &f);
            const tu_agreement a = tu_compare_frames(&f, &rt);
            fprintf(stderr, "%s: %s vs raytrace: %ld of %ld pixels differ, max |dV| %.2f samples, %ld without a ray\n",
                    type_names[ti], others[m], a.differ, a.pixels, a.max_steps, noray);
            assert_int_equal(a.miss_mismatch, 0);
            assert_int_equal(a.beyond_one, 0);
            assert_int_equal(a.s_beyond, 0);
            assert_true((double)a.differ <= 0.01 * (double)a.pixels);
            ms_frame_free(&f);
        }
        ms_frame_free(&rt);
    }
    ms_scene_free(&sc);
}

/* Streamed (procedural) scenes take their primary hits from the depth pass (primary_depth.c), which for
 * the curved types tests every pixel against each triangle: hpc streamed against raytrace on the same
 * scene materialised (BVH primary), every type, with the camera from a scene file. */
static void test_streamed(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("test_cameras");
    const char *const cams[] = { "\"type\": \"orthographic\", \"ortho_height\": 20", "\"type\": \"fisheye\", \"fov\": 250",
                                 "\"type\": \"latlong\"", "\"type\": \"parabolic\"" };
    for (int k = 0; k < 4; k++) {
        char path[4096], text[2048], err[1024];
        snprintf(text, sizeof text,
                 "{\"procedural\": {\"type\": \"flowers\", \"triangles\": 3000, \"seed\": 5},\n"
                 " \"camera\": {%s, \"eye\": [0, 6, 9], \"target\": [0, 0, 0], \"up\": [0, 1, 0]},\n"
                 " \"light\": {\"corner\": [-2, 12, -2], \"edge_s\": [4, 0, 0], \"edge_t\": [0, 0, 4]}}\n", cams[k]);
        tu_path(path, sizeof path, dir, "flowers.json");
        assert_int_equal(tu_write_file(path, text), 0);
        ms_scene sc;
        if (ms_scene_load(path, &sc, err, sizeof err)) fail_msg("%s", err);
        assert_null(sc.tri);
        /* the depth pass's hits against the BVH primary's on the triangles materialised, at 256x128: the
         * same triangle at every pixel (a pixel left out of a triangle's box would see another) */
        {
            const int W = 256, H = 128;
            float *tri = malloc(sizeof(float) * 9 * sc.n_tris);
            assert_non_null(tri);
            ms_procedural_triangles(&sc, 0, sc.n_tris, tri);
            ms_bvh bvh;
            assert_int_equal(ms_bvh_build(&bvh, tri, sc.n_tris, 0), 0);
            ms_render_ctx ctx;
            tu_ctx_init(&ctx, &sc, &bvh, W, H, 16);
            const ms_primary_method *pd = ms_find_primary_method("depth"), *pb = ms_find_primary_method("bvh");
            assert_non_null(pd);
            void *sd = NULL;
            ctx.bvh = NULL;   /* streamed: the depth pass reads the procedural source */
            assert_int_equal(pd->create(&ctx, &sd, err, sizeof err), 0);
            ms_hit *hd = malloc(sizeof *hd * W * H), *hb = malloc(sizeof *hb * W * H);
            assert_non_null(hd);
            assert_non_null(hb);
            pd->trace(sd, &ctx, 0, 0, W, H, hd);
            ctx.bvh = &bvh;
            pb->trace(NULL, &ctx, 0, 0, W, H, hb);
            long same = 0, other = 0;
            for (int i = 0; i < W * H; i++) {
                const long b = hb[i].prim == UINT32_MAX ? -1 : (long)bvh.tri_source[hb[i].prim];
                const long d = hd[i].prim == UINT32_MAX ? -1 : (long)hd[i].prim;
                if (b == d) same += b >= 0;
                else other++;
            }
            fprintf(stderr, "depth pass %s: %ld pixels the BVH's triangle, %ld another\n", cams[k], same, other);
            assert_true(same > W * H / 8);
            /* exact ties only (none seen; the one-pixel margin without the cone left 2-3 pixels out) */
            assert_true(other * 20000 <= W * H);
            pd->destroy(sd);
            free(hd);
            free(hb);
            ms_bvh_free(&bvh);
            free(tri);
        }
        ms_frame ref, f;
        render_ok(&sc, "raytrace", 40, 32, &ref);   /* materialised, BVH primary */
        render_ok(&sc, "hpc", 40, 32, &f);          /* streamed, depth-pass primary */
        assert_true(f.stats.build_s == 0.0);
        const tu_agreement a = tu_compare_frames(&f, &ref);
        long hit = 0;
        for (int i = 0; i < 40 * 32; i++) hit += ref.vis[i] >= 0.0f;
        fprintf(stderr, "streamed %s: %ld hit pixels, %ld differ, max |dV| %.2f samples\n", cams[k], hit, a.differ,
                a.max_steps);
        assert_true(hit > 40 * 32 / 8);
        assert_int_equal(a.miss_mismatch, 0);
        assert_int_equal(a.beyond_one, 0);
        assert_true((double)a.differ <= 0.01 * (double)a.pixels);
        ms_frame_free(&f);
        ms_frame_free(&ref);
        ms_scene_free(&sc);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_conventions_and_edges),
        cmocka_unit_test(test_point_round_trip),
        cmocka_unit_test(test_pixel_round_trip),
        cmocka_unit_test(test_angle_bound),
        cmocka_unit_test(test_primaries),
        cmocka_unit_test(test_fisheye_parabolic),
        cmocka_unit_test(test_frames),
        cmocka_unit_test(test_streamed),
    };
    return cmocka_run_group_tests_name("cameras", tests, NULL, NULL);
}
