#include "camera.h"
#include "core/vec.h"
#include <math.h>

int ms_camera_basis_init(ms_camera_basis *b, const ms_camera *c, int width, int height)
{
    float eye[3] = { c->eye.x, c->eye.y, c->eye.z };
    float target[3] = { c->target.x, c->target.y, c->target.z };
    float up[3] = { c->up.x, c->up.y, c->up.z };
    float f[3], r[3], u[3];
    v3_sub(f, target, eye);
    float fl = v3_len(f);
    if (!(fl > 0.0f) || !(v3_len(up) > 0.0f)) return -1;
    v3_scale(f, f, 1.0f / fl);
    v3_cross(r, f, up);
    float rl = v3_len(r);
    if (!(rl > 1e-6f * v3_len(up))) return -1;
    v3_scale(r, r, 1.0f / rl);
    v3_cross(u, r, f);
    if (width <= 0 || height <= 0) return -1;
    b->type = c->type;
    switch (c->type) {
    case MS_CAMERA_PINHOLE:
        if (!(c->fov_y > 0.0f && c->fov_y < 180.0f)) return -1;
        break;
    case MS_CAMERA_ORTHOGRAPHIC:
        if (!(c->ortho_height > 0.0f && c->ortho_height <= 3e38f)) return -1;
        break;
    case MS_CAMERA_FISHEYE:
        if (!(c->fov > 0.0f && c->fov <= 360.0f)) return -1;
        break;
    case MS_CAMERA_LATLONG:
    case MS_CAMERA_PARABOLIC:
        break;
    default:
        return -1;
    }
    for (int a = 0; a < 3; a++) { b->eye[a] = eye[a]; b->forward[a] = f[a]; b->right[a] = r[a]; b->up[a] = u[a]; }
    b->tan_half_y = c->type == MS_CAMERA_PINHOLE ? tanf(0.5f * c->fov_y * (float)M_PI / 180.0f) : 0.0f;
    b->aspect = (float)width / (float)height;
    b->half_h = c->type == MS_CAMERA_ORTHOGRAPHIC ? 0.5f * c->ortho_height : 0.0f;
    b->half_w = b->half_h * b->aspect;
    /* ray origins stay within the coordinate range scenes are checked against (1e18, scene_validate.c) */
    if (!(b->half_w <= 1e18f && b->half_h <= 1e18f)) return -1;
    b->cx = 0.5f * (float)width;
    b->cy = 0.5f * (float)height;
    b->radius = 0.5f * (float)(width < height ? width : height);
    b->max_theta = c->type == MS_CAMERA_FISHEYE ? 0.5f * c->fov * (float)M_PI / 180.0f : 0.0f;
    b->width = width;
    b->height = height;
    return 0;
}

/* d = a right + b up + c forward */
static void frame_dir(const ms_camera_basis *b, float a, float bb, float c, float d[3])
{
    for (int k = 0; k < 3; k++) d[k] = a * b->right[k] + bb * b->up[k] + c * b->forward[k];
}

int ms_camera_ray_at(const ms_camera_basis *b, float sx, float sy, float o[3], float d[3])
{
    switch (b->type) {
    case MS_CAMERA_PINHOLE: {
        /* Kept operation for operation as before the other projections, so pinhole rays stay bit-identical. */
        float a = (2.0f * sx / (float)b->width - 1.0f) * b->tan_half_y * b->aspect;
        float c = (1.0f - 2.0f * sy / (float)b->height) * b->tan_half_y;
        for (int k = 0; k < 3; k++) { o[k] = b->eye[k]; d[k] = b->forward[k] + a * b->right[k] + c * b->up[k]; }
        return 0;
    }
    case MS_CAMERA_ORTHOGRAPHIC: {
        float a = (2.0f * sx / (float)b->width - 1.0f) * b->half_w;
        float c = (1.0f - 2.0f * sy / (float)b->height) * b->half_h;
        for (int k = 0; k < 3; k++) { o[k] = b->eye[k] + a * b->right[k] + c * b->up[k]; d[k] = b->forward[k]; }
        return 0;
    }
    case MS_CAMERA_FISHEYE: {
        float dx = sx - b->cx, dy = b->cy - sy;
        float r = sqrtf(dx * dx + dy * dy);
        if (!(r <= b->radius)) return -1;
        float th = r / b->radius * b->max_theta, st = sinf(th);
        float ca = r > 0.0f ? dx / r : 0.0f, sa = r > 0.0f ? dy / r : 0.0f;
        frame_dir(b, st * ca, st * sa, cosf(th), d);
        break;
    }
    case MS_CAMERA_LATLONG: {
        float lon = 2.0f * (float)M_PI * (sx / (float)b->width - 0.5f);
        float th = (float)M_PI * sy / (float)b->height, st = sinf(th);
        frame_dir(b, st * sinf(lon), cosf(th), st * cosf(lon), d);
        break;
    }
    case MS_CAMERA_PARABOLIC: {
        float u = (sx - b->cx) / b->radius, v = (b->cy - sy) / b->radius;
        float r2 = u * u + v * v;
        if (!(r2 <= 1.0f)) return -1;
        float s = 1.0f / (1.0f + r2);
        frame_dir(b, 2.0f * u * s, 2.0f * v * s, (1.0f - r2) * s, d);
        break;
    }
    default:
        return -1;
    }
    for (int k = 0; k < 3; k++) o[k] = b->eye[k];
    return 0;
}

int ms_camera_ray(const ms_camera_basis *b, int x, int y, float o[3], float d[3])
{
    return ms_camera_ray_at(b, (float)x + 0.5f, (float)y + 0.5f, o, d);
}

int ms_camera_project(const ms_camera_basis *b, const float p[3], float *px, float *py)
{
    float d[3];
    v3_sub(d, p, b->eye);
    const float a = v3_dot(d, b->right), c = v3_dot(d, b->up), z = v3_dot(d, b->forward);
    switch (b->type) {
    case MS_CAMERA_PINHOLE: {
        if (!(z > 0.0f)) return -1;
        float sx = v3_dot(d, b->right) / (z * b->tan_half_y * b->aspect);
        float sy = v3_dot(d, b->up) / (z * b->tan_half_y);
        *px = 0.5f * (sx + 1.0f) * (float)b->width;
        *py = 0.5f * (1.0f - sy) * (float)b->height;
        return 0;
    }
    case MS_CAMERA_ORTHOGRAPHIC:
        if (!(z >= 0.0f)) return -1;
        *px = 0.5f * (a / b->half_w + 1.0f) * (float)b->width;
        *py = 0.5f * (1.0f - c / b->half_h) * (float)b->height;
        return 0;
    default:
        break;
    }
    const float len = v3_len(d);
    if (!(len > 0.0f)) return -1;
    switch (b->type) {
    case MS_CAMERA_FISHEYE: {
        /* atan2, not acos(z/len): acos loses half the digits near the axis (0.1 pixel at 1024^2, 180 deg) */
        float lat = sqrtf(a * a + c * c);
        float th = atan2f(lat, z);
        if (!(th <= b->max_theta)) return -1;
        float r = th / b->max_theta * b->radius;
        if (!(lat > 0.0f)) {
            /* On the axis: the centre, or (fov 360) the antipode, which the whole rim sees: take its right end. */
            *px = b->cx + (z < 0.0f ? r : 0.0f);
            *py = b->cy;
            return 0;
        }
        *px = b->cx + r * a / lat;
        *py = b->cy - r * c / lat;
        return 0;
    }
    case MS_CAMERA_LATLONG: {
        float lon = atan2f(a, z);
        float th = atan2f(sqrtf(a * a + z * z), c);   /* from up; atan2 keeps the poles accurate */
        float x = (lon / (2.0f * (float)M_PI) + 0.5f) * (float)b->width;
        if (x >= (float)b->width) x -= (float)b->width;
        if (x < 0.0f) x = 0.0f;
        *px = x;
        *py = th / (float)M_PI * (float)b->height;
        return 0;
    }
    case MS_CAMERA_PARABOLIC: {
        float zc = z / len;
        if (!(zc >= 0.0f)) return -1;
        *px = b->cx + b->radius * (a / len) / (1.0f + zc);
        *py = b->cy - b->radius * (c / len) / (1.0f + zc);
        return 0;
    }
    default:
        return -1;
    }
}

int ms_camera_planar(const ms_camera_basis *b)
{
    return b->type == MS_CAMERA_PINHOLE || b->type == MS_CAMERA_ORTHOGRAPHIC;
}

/* The bounds follow from the metric of each map: ds^2 = dtheta^2 + sin^2(theta) dphi^2 on the sphere of
 * directions, with each projection's own (theta, phi) per pixel. */
float ms_camera_angle_per_pixel(const ms_camera_basis *b)
{
    switch (b->type) {
    case MS_CAMERA_FISHEYE:
        /* radial dtheta/dr = max_theta/R; tangential sin(theta)/r with theta = r max_theta/R: at most the same */
        return b->max_theta / b->radius;
    case MS_CAMERA_LATLONG: {
        /* dtheta/dy = pi/H; along a parallel sin(theta) 2 pi/W <= 2 pi/W */
        float ly = (float)M_PI / (float)b->height, lx = 2.0f * (float)M_PI / (float)b->width;
        return ly > lx ? ly : lx;
    }
    case MS_CAMERA_PARABOLIC:
        /* theta = 2 atan(r) in disk units: dtheta/dr = 2/(1+r^2) <= 2, tangential sin(theta)/r = 2/(1+r^2) <= 2 */
        return 2.0f / b->radius;
    default:
        return 0.0f;
    }
}

void ms_camera_viewer(const ms_camera_basis *b, const float p[3], float viewer[3])
{
    if (b->type == MS_CAMERA_ORTHOGRAPHIC)
        for (int k = 0; k < 3; k++) viewer[k] = p[k] - b->forward[k];
    else
        for (int k = 0; k < 3; k++) viewer[k] = b->eye[k];
}
