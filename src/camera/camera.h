/* Pinhole camera: pixel (x,y) with y = 0 the top row, primary ray through (x+0.5, y+0.5). */
#ifndef MS_CAMERA_H
#define MS_CAMERA_H
#include "microshadow.h"

typedef struct ms_camera_basis {
    float eye[3];
    float forward[3], right[3], up[3];   /* orthonormal */
    float tan_half_y, aspect;
    int width, height;
} ms_camera_basis;

/* 0, or -1 if degenerate (eye = target, up parallel to the view, fov out of (0,180)). */
int ms_camera_basis_init(ms_camera_basis *b, const ms_camera *c, int width, int height);
/* Unnormalised direction through the centre of pixel (x, y). */
void ms_camera_ray(const ms_camera_basis *b, int x, int y, float dir[3]);
/* Continuous pixel coordinates of a world point (the inverse of ms_camera_ray); -1 if behind. */
int ms_camera_project(const ms_camera_basis *b, const float p[3], float *px, float *py);

#endif
