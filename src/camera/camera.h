/* Cameras: the ray of an image position and the image position of a point, for every projection
 * (ms_camera_type). Pixel (x,y), y = 0 the top row; the primary ray passes through (x+0.5, y+0.5). */
#ifndef MS_CAMERA_H
#define MS_CAMERA_H
#include "microshadow.h"

typedef struct ms_camera_basis {
    ms_camera_type type;
    float eye[3];
    float forward[3], right[3], up[3];   /* orthonormal */
    float tan_half_y, aspect;            /* pinhole */
    float half_w, half_h;                /* orthographic: half the image's extent in world units */
    float cx, cy, radius;                /* fisheye, parabolic: the inscribed circle (pixels) */
    float max_theta;                     /* fisheye: half the field of view (radians) */
    int width, height;
} ms_camera_basis;

/* 0, or -1 if degenerate (eye = target, up parallel to the view, a field of view or extent out of range,
 * an unknown type). */
int ms_camera_basis_init(ms_camera_basis *b, const ms_camera *c, int width, int height);

/* The ray through continuous image position (sx, sy) (pixel (x,y)'s centre is (x+0.5, y+0.5)): origin o
 * and direction d. Pinhole: o = eye, d = forward + a right + b up, not normalised (the historical rays,
 * kept bit for bit); the other types: d of unit length. 0, or -1 where the position maps to no ray
 * (outside a fisheye's or parabolic's circle; o and d then unset). */
int ms_camera_ray_at(const ms_camera_basis *b, float sx, float sy, float o[3], float d[3]);
/* The ray through the centre of pixel (x, y): ms_camera_ray_at(b, x + 0.5, y + 0.5, o, d). */
int ms_camera_ray(const ms_camera_basis *b, int x, int y, float o[3], float d[3]);

/* Continuous image position of a world point (the inverse of ms_camera_ray_at); -1 if the camera does
 * not see it (behind a pinhole, outside a fisheye's field of view or the parabolic hemisphere, at the
 * eye). Latlong: px in [0, width). */
int ms_camera_project(const ms_camera_basis *b, const float p[3], float *px, float *py);

/* 1 when the ray directions (pinhole) or origins (orthographic) are affine in the image position, so
 * straight edges image to straight lines; 0 for the curved projections. */
int ms_camera_planar(const ms_camera_basis *b);

/* Curved projections: L such that the rays of two image positions a distance r apart (pixels) make an
 * angle of at most L r radians (for a conservative cone around a tile of pixels: axis the ray of its
 * centre, half-angle L times its half-diagonal). 0 for the planar ones. */
float ms_camera_angle_per_pixel(const ms_camera_basis *b);

/* A point from which the surface point p is seen along its primary ray, for the view vector in shading
 * (normalize(viewer - p)): the eye for the central projections; p - forward for the orthographic one,
 * whose rays start on a plane (so the view vector is -forward whatever p's pixel). */
void ms_camera_viewer(const ms_camera_basis *b, const float p[3], float viewer[3]);

#endif
