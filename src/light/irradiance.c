/* Unshadowed irradiance per unit radiance (ms_light_irradiance).
 * Parallelogram: exact, the polygon form factor (Lambert's formula, a sum over the edges of the light as
 * seen from p), after clipping the light to the receiver's upper hemisphere so that a light straddling the
 * horizon is counted only above it.
 * Disk (a circle: its parallelogram a square): exact where the whole disk lies above the receiver's plane,
 * E = n . Phi with the vector irradiance Phi = pi (F_par (-m) + F_perp (-rho)) of the disk (centre c,
 * emitting normal m, radius r) at lateral offset a and height h: the classic differential-element-to-disk
 * form factors (Howell's catalogue, configurations "plane element parallel to / perpendicular to a disk"),
 * F_par = (1 - (z - 2r^2)/q)/2, F_perp = h/(2a) (z/q - 1), z = a^2 + h^2 + r^2, q = sqrt(z^2 - 4 r^2 a^2);
 * E is linear in n only while no part of the disk is below the horizon. Across the horizon, and for an
 * ellipse (a disk over a non-square parallelogram): the polygon formula on a clipped 256-gon inscribed in
 * the shape with its area (half-diameters scaled by sqrt((2pi/N)/sin(2pi/N))): an approximation, within
 * 1e-4 relative of numerical integration (tests/test_lights.c). */
#include "microshadow.h"
#include "core/vec.h"
#include "light_frame.h"
#include <math.h>

#define DISK_POLY 256

/* Lambert's formula over the polygon rel[0..m-1] (vertices relative to p), clipped to n . x >= 0;
 * scratch holds at least m + 1 vertices. */
static double polygon_irradiance(const float (*rel)[3], int m_in, const float n[3], float (*clip)[3])
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

/* A sphere of radius r at distance d, its centre at angle theta from the normal (sin^2 sigma = (r/d)^2):
 * pi sin^2 sigma cos theta when wholly above the horizon (cos^2 theta > sin^2 sigma), else Snyder's exact
 * expression for the part above it (Lagarde & de Rousiers 2014, "illuminanceSphereOrDisk"). */
static double sphere_irradiance(const ms_light *l, const float p[3], const float n[3])
{
    const double w[3] = { (double)l->center.x - p[0], (double)l->center.y - p[1], (double)l->center.z - p[2] };
    const double d2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], r = l->radius;
    if (!(d2 > r * r)) return 0.0;
    const double s2 = r * r / d2;
    const double ct = (w[0] * n[0] + w[1] * n[1] + w[2] * n[2]) / sqrt(d2);
    if (ct * ct > s2) return ct > 0.0 ? M_PI * s2 * ct : 0.0;
    const double st = sqrt(fmax(1.0 - ct * ct, 0.0)), x = sqrt(1.0 / s2 - 1.0);
    const double y = -x * ct / st, sty = st * sqrt(fmax(1.0 - y * y, 0.0));
    return fmax((ct * acos(y) - x * sty) * s2 + atan(sty / x), 0.0);
}

float ms_light_irradiance(const ms_light *l, const float p[3], const float n[3])
{
    if (l->shape == MS_LIGHT_SPHERE) return (float)sphere_irradiance(l, p, n);
    ms_light_frame F;
    ms_light_frame_of(l, &F);
    const float *P = F.corner, *S = F.edge_s, *T = F.edge_t, *ln = F.normal;
    float rel[3];
    v3_sub(rel, p, P);
    if (!(v3_dot(rel, ln) > 0.0f)) return 0.0f;   /* behind the emitting side */

    if (l->shape == MS_LIGHT_DISK) {
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
        return (float)polygon_irradiance((const float (*)[3])poly, DISK_POLY, n, clip);
    }

    /* Light corners relative to p, in order around the parallelogram. */
    float poly[4][3], clip[8][3];
    for (int c = 0; c < 3; c++) {
        poly[0][c] = P[c] - p[c];
        poly[1][c] = P[c] + S[c] - p[c];
        poly[2][c] = P[c] + S[c] + T[c] - p[c];
        poly[3][c] = P[c] + T[c] - p[c];
    }
    return (float)polygon_irradiance((const float (*)[3])poly, 4, n, clip);
}
