/* Unshadowed irradiance per unit radiance (ms_light_irradiance): each shape's row (light_shape.h) gives
 * its own, exact or closed-form where it can; Lambert's polygon formula, shared by the planar shapes, is
 * here. */
#include "light_shape.h"
#include "core/vec.h"
#include "light_frame.h"
#include <math.h>

/* Lambert's formula over the polygon rel[0..m-1] (vertices relative to p), clipped to n . x >= 0;
 * scratch holds at least m + 1 vertices. */
double ms_light_polygon_irradiance(const float (*rel)[3], int m_in, const float n[3], float (*clip)[3])
{
    int m = 0;
    for (int i = 0; i < m_in; i++) {
        const float *a = rel[i], *b = rel[(i + 1) % m_in];
        float da = v3_dot(a, n), db = v3_dot(b, n);
        if (da >= 0.0f) { clip[m][0] = a[0]; clip[m][1] = a[1]; clip[m][2] = a[2]; m++; }
        if ((da >= 0.0f) != (db >= 0.0f)) {
            float t = da / (da - db);
            for (int c = 0; c < 3; c++) clip[m][c] = a[c] + t * (b[c] - a[c]);
            m++;
        }
    }
    if (m < 3) return 0.0;
    double sum = 0.0;
    for (int i = 0; i < m; i++) {
        float a[3], b[3], g[3];
        v3_normalize(a, clip[i]);
        v3_normalize(b, clip[(i + 1) % m]);
        v3_cross(g, a, b);
        float gl = v3_len(g);
        if (!(gl > 0.0f)) continue;
        double theta = atan2((double)gl, (double)v3_dot(a, b));
        sum += theta * (double)v3_dot(g, n) / (double)gl;
    }
    /* E = L/2 * |sum|: pi times the form factor, per unit radiance. */
    return 0.5 * fabs(sum);
}

float ms_light_irradiance(const ms_light *l, const float p[3], const float n[3])
{
    const ms_light_shape_ops *shape = ms_light_shape_of(l->shape);
    if (!shape) shape = ms_light_shape_of(MS_LIGHT_RECT);   /* unvalidated: the parallelogram, as ever */
    ms_light_frame F;
    ms_light_frame_of(l, &F);
    return shape->irradiance(l, &F, p, n);
}
