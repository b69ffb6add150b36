#include "camera.h"
#include "../core/vec.h"
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
    if (!(c->fov_y > 0.0f && c->fov_y < 180.0f) || width <= 0 || height <= 0) return -1;
    for (int a = 0; a < 3; a++) { b->eye[a] = eye[a]; b->forward[a] = f[a]; b->right[a] = r[a]; b->up[a] = u[a]; }
    b->tan_half_y = tanf(0.5f * c->fov_y * (float)M_PI / 180.0f);
    b->aspect = (float)width / (float)height;
    b->width = width;
    b->height = height;
    return 0;
}

void ms_camera_ray(const ms_camera_basis *b, int x, int y, float dir[3])
{
    float sx = (2.0f * ((float)x + 0.5f) / (float)b->width - 1.0f) * b->tan_half_y * b->aspect;
    float sy = (1.0f - 2.0f * ((float)y + 0.5f) / (float)b->height) * b->tan_half_y;
    for (int a = 0; a < 3; a++) dir[a] = b->forward[a] + sx * b->right[a] + sy * b->up[a];
}

int ms_camera_project(const ms_camera_basis *b, const float p[3], float *px, float *py)
{
    float d[3];
    v3_sub(d, p, b->eye);
    float z = v3_dot(d, b->forward);
    if (!(z > 0.0f)) return -1;
    float sx = v3_dot(d, b->right) / (z * b->tan_half_y * b->aspect);
    float sy = v3_dot(d, b->up) / (z * b->tan_half_y);
    *px = 0.5f * (sx + 1.0f) * (float)b->width;
    *py = 0.5f * (1.0f - sy) * (float)b->height;
    return 0;
}
