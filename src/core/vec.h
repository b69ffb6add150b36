/* Small inline 3-vector helpers on float[3] (the layout of the triangle soup), and the same on double[3]
 * for the set-ups that need double (alpha, 3D edge functions, hpc volumes, mft frames). */
#ifndef MS_VEC_H
#define MS_VEC_H
#include <math.h>
#include "cpu.h" /* the portable-file guard */

/* Compare-based min/max (the only definition): fminf/fmaxf compile to library calls without -ffast-math. */
static inline float ms_minf(float a, float b) { return a < b ? a : b; }
static inline float ms_maxf(float a, float b) { return a > b ? a : b; }

static inline void v3_sub(float r[3], const float a[3], const float b[3]) { r[0] = a[0] - b[0]; r[1] = a[1] - b[1]; r[2] = a[2] - b[2]; }
static inline void v3_add(float r[3], const float a[3], const float b[3]) { r[0] = a[0] + b[0]; r[1] = a[1] + b[1]; r[2] = a[2] + b[2]; }
static inline void v3_scale(float r[3], const float a[3], float s) { r[0] = a[0] * s; r[1] = a[1] * s; r[2] = a[2] * s; }
static inline void v3_madd(float r[3], const float a[3], const float b[3], float s) { r[0] = a[0] + b[0] * s; r[1] = a[1] + b[1] * s; r[2] = a[2] + b[2] * s; }
static inline float v3_dot(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static inline void v3_cross(float r[3], const float a[3], const float b[3])
{
    float x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    r[0] = x; r[1] = y; r[2] = z;
}
static inline float v3_len(const float a[3]) { return sqrtf(v3_dot(a, a)); }
static inline void v3_normalize(float r[3], const float a[3])
{
    float l = v3_len(a);
    float s = l > 0.0f ? 1.0f / l : 0.0f;
    v3_scale(r, a, s);
}
static inline int v3_finite(const float a[3]) { return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]); }

static inline void d3_sub(double r[3], const double a[3], const double b[3]) { r[0] = a[0] - b[0]; r[1] = a[1] - b[1]; r[2] = a[2] - b[2]; }
static inline double d3_dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static inline void d3_cross(double r[3], const double a[3], const double b[3])
{
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    r[0] = x; r[1] = y; r[2] = z;
}
static inline double d3_len(const double a[3]) { return sqrt(d3_dot(a, a)); }

#endif
