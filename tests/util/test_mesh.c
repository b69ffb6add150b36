/* Meshes for the tests of closed surfaces (test_mesh.h). */
#include "test_mesh.h"
#include "testutil.h"   /* cmocka: assert_non_null */
#include <math.h>
#include <stdlib.h>
#include <string.h>

void tm_add_tri(tm_mesh *m, const double a[3], const double b[3], const double c[3])
{
    if (m->n == m->cap) {
        m->cap = m->cap ? 2 * m->cap : 64;
        m->tri = realloc(m->tri, m->cap * 9 * sizeof(float));
        assert_non_null(m->tri);
    }
    float *t = m->tri + 9 * m->n++;
    for (int k = 0; k < 3; k++) { t[k] = (float)a[k]; t[3 + k] = (float)b[k]; t[6 + k] = (float)c[k]; }
}

/* An icosphere of radius r around c, subdivided s times, outward winding (flip: inward); the vertices
 * moved radially by up to jitter (shared vertices move alike: the surface stays closed). */
void tm_icosphere(tm_mesh *m, const double c[3], double r, int s, int flip, double jitter, unsigned seed)
{
    const double g = (1.0 + sqrt(5.0)) / 2.0;
    double v[12][3] = { { -1, g, 0 }, { 1, g, 0 }, { -1, -g, 0 }, { 1, -g, 0 }, { 0, -1, g }, { 0, 1, g },
                        { 0, -1, -g }, { 0, 1, -g }, { g, 0, -1 }, { g, 0, 1 }, { -g, 0, -1 }, { -g, 0, 1 } };
    static const int f[20][3] = { { 0, 11, 5 }, { 0, 5, 1 }, { 0, 1, 7 }, { 0, 7, 10 }, { 0, 10, 11 }, { 1, 5, 9 },
                                  { 5, 11, 4 }, { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 }, { 3, 9, 4 }, { 3, 4, 2 },
                                  { 3, 2, 6 }, { 3, 6, 8 }, { 3, 8, 9 }, { 4, 9, 5 }, { 2, 4, 11 }, { 6, 2, 10 },
                                  { 8, 6, 7 }, { 9, 8, 1 } };
    /* triangles on the unit sphere, each subdivided by edge midpoints; the jitter is a function of the
     * (rounded) direction, so a vertex shared by neighbours lands at the same float position */
    int nt = 20;
    double (*t)[3][3] = malloc(sizeof *t * 20);
    for (int i = 0; i < 20; i++)
        for (int k = 0; k < 3; k++) {
            const double *p = v[f[i][k]];
            const double l = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
            for (int a = 0; a < 3; a++) t[i][k][a] = p[a] / l;
        }
    for (int level = 0; level < s; level++) {
        double (*u)[3][3] = malloc(sizeof *u * (size_t)nt * 4);
        for (int i = 0; i < nt; i++) {
            double mid[3][3];
            for (int k = 0; k < 3; k++) {
                double l = 0;
                for (int a = 0; a < 3; a++) { mid[k][a] = t[i][k][a] + t[i][(k + 1) % 3][a]; l += mid[k][a] * mid[k][a]; }
                for (int a = 0; a < 3; a++) mid[k][a] /= sqrt(l);
            }
            const double *q[4][3] = { { t[i][0], mid[0], mid[2] }, { mid[0], t[i][1], mid[1] }, { mid[2], mid[1], t[i][2] },
                                      { mid[0], mid[1], mid[2] } };
            for (int j = 0; j < 4; j++)
                for (int k = 0; k < 3; k++) memcpy(u[4 * i + j][k], q[j][k], sizeof(double[3]));
        }
        free(t);
        t = u;
        nt *= 4;
    }
    for (int i = 0; i < nt; i++) {
        double p[3][3];
        for (int k = 0; k < 3; k++) {
            /* the jitter from the direction rounded to float: equal for the copies of a shared vertex */
            unsigned h = seed;
            for (int a = 0; a < 3; a++) {
                float fa = (float)t[i][k][a];
                unsigned bits;
                memcpy(&bits, &fa, sizeof bits);
                h = (h ^ bits) * 16777619u;
            }
            const double rr = r * (1.0 + jitter * ((double)(h % 10007) / 10007.0 - 0.5));
            for (int a = 0; a < 3; a++) p[k][a] = c[a] + rr * (double)(float)t[i][k][a];
        }
        if (flip) tm_add_tri(m, p[0], p[2], p[1]);
        else tm_add_tri(m, p[0], p[1], p[2]);
    }
    free(t);
}

/* An axis-aligned box [lo, hi], outward winding (flip: inward). */
void tm_ground(tm_mesh *m)
{
    const double g[4][3] = { { -10, 0, -10 }, { 10, 0, 10 }, { 10, 0, -10 }, { -10, 0, 10 } };
    tm_add_tri(m, g[0], g[1], g[2]);
    tm_add_tri(m, g[0], g[3], g[1]);
}

void tm_box(tm_mesh *m, const double lo[3], const double hi[3], int flip)
{
    double v[8][3];
    for (int i = 0; i < 8; i++)
        for (int a = 0; a < 3; a++) v[i][a] = (i >> a & 1) ? hi[a] : lo[a];
    static const int q[6][4] = { { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 }, { 0, 4, 6, 2 }, { 1, 3, 7, 5 } };
    for (int f = 0; f < 6; f++) {
        const double *a = v[q[f][0]], *b = v[q[f][1]], *c = v[q[f][2]], *d = v[q[f][3]];
        if (flip) { tm_add_tri(m, a, c, b); tm_add_tri(m, a, d, c); }
        else { tm_add_tri(m, a, b, c); tm_add_tri(m, a, c, d); }
    }
}

/* Does the segment p + u (l - p), u in [TM_NEAR, TM_FAR], meet triangle t? Double precision, Moller-Trumbore;
 * an independent answer up to ties (a segment through an edge or vertex, which random cases avoid). */
void tm_centroid_normal(const float *t, float pos[3], float nrm[3])
{
    double e1[3], e2[3];
    for (int a = 0; a < 3; a++) {
        pos[a] = (t[a] + t[3 + a] + t[6 + a]) / 3.0f;
        e1[a] = (double)t[3 + a] - t[a];
        e2[a] = (double)t[6 + a] - t[a];
    }
    nrm[0] = (float)(e1[1] * e2[2] - e1[2] * e2[1]);
    nrm[1] = (float)(e1[2] * e2[0] - e1[0] * e2[2]);
    nrm[2] = (float)(e1[0] * e2[1] - e1[1] * e2[0]);
}

int tm_seg_hits(const float *t, const double p[3], const double l[3])
{
    double e1[3], e2[3], d[3], s[3], h[3], q[3];
    for (int a = 0; a < 3; a++) { e1[a] = (double)t[3 + a] - t[a]; e2[a] = (double)t[6 + a] - t[a]; d[a] = l[a] - p[a]; s[a] = p[a] - t[a]; }
    h[0] = d[1] * e2[2] - d[2] * e2[1]; h[1] = d[2] * e2[0] - d[0] * e2[2]; h[2] = d[0] * e2[1] - d[1] * e2[0];
    const double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
    if (det == 0.0) return 0;
    const double inv = 1.0 / det;
    const double u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) * inv;
    if (u < 0.0 || u > 1.0) return 0;
    q[0] = s[1] * e1[2] - s[2] * e1[1]; q[1] = s[2] * e1[0] - s[0] * e1[2]; q[2] = s[0] * e1[1] - s[1] * e1[0];
    const double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
    if (v < 0.0 || u + v > 1.0) return 0;
    const double w = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
    return w >= TM_NEAR && w <= TM_FAR;
}

double tm_urand(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (double)(*s >> 8) / 16777216.0;
}
