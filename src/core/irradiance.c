/* Exact irradiance from a Lambertian parallelogram: the polygon form factor (Lambert's formula,
 * a sum over the edges of the light as seen from p), after clipping the light to the receiver's
 * upper hemisphere so that a light straddling the horizon is counted only above it. */
#include "microshadow.h"
#include "vec.h"
#include <math.h>

float ms_light_irradiance(const ms_light *l, const float p[3], const float n[3])
{
    const float P[3] = { l->corner.x, l->corner.y, l->corner.z };
    const float S[3] = { l->edge_s.x, l->edge_s.y, l->edge_s.z };
    const float T[3] = { l->edge_t.x, l->edge_t.y, l->edge_t.z };
    float ln[3], rel[3];
    v3_cross(ln, S, T);
    v3_sub(rel, p, P);
    if (!(v3_dot(rel, ln) > 0.0f)) return 0.0f;   /* behind the emitting side */

    /* Light corners relative to p, in order around the parallelogram. */
    float poly[8][3];
    for (int c = 0; c < 3; c++) {
        poly[0][c] = P[c] - p[c];
        poly[1][c] = P[c] + S[c] - p[c];
        poly[2][c] = P[c] + S[c] + T[c] - p[c];
        poly[3][c] = P[c] + T[c] - p[c];
    }
    /* Sutherland-Hodgman against the plane n.x >= 0. */
    float clip[8][3];
    int m = 0;
    for (int i = 0; i < 4; i++) {
        const float *a = poly[i], *b = poly[(i + 1) & 3];
        float da = v3_dot(a, n), db = v3_dot(b, n);
        if (da >= 0.0f) { clip[m][0] = a[0]; clip[m][1] = a[1]; clip[m][2] = a[2]; m++; }
        if ((da >= 0.0f) != (db >= 0.0f)) {
            float t = da / (da - db);
            for (int c = 0; c < 3; c++) clip[m][c] = a[c] + t * (b[c] - a[c]);
            m++;
        }
    }
    if (m < 3) return 0.0f;
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
    return (float)(0.5 * fabs(sum));
}
