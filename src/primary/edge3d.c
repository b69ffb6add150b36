/* 3D edge functions: set-up, tile culling and screen bounds (edge3d.h). */
#include "edge3d.h"
#include "core/vec.h"
#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void ms_e3_cam_init(ms_e3_cam *c, const ms_camera_basis *b)
{
    const int ortho = b->type == MS_CAMERA_ORTHOGRAPHIC;
    c->w = ortho ? 0 : 1;
    for (int a = 0; a < 3; a++) {
        c->e[a] = ortho ? (double)b->forward[a] : (double)b->eye[a];
        c->right[a] = b->right[a];
        c->down[a] = -(double)b->up[a];
        c->forward[a] = b->forward[a];
    }
}

/* Lexicographic order of two vertices: the canonical direction of an edge. */
static int lex_less(const float *a, const float *b)
{
    if (a[0] != b[0]) return a[0] < b[0];
    if (a[1] != b[1]) return a[1] < b[1];
    return a[2] < b[2];
}

void ms_e3_setup(const ms_e3_cam *c, const float tri[9], ms_e3_tri *T)
{
    double M[3][3], K[3];
    for (int i = 0; i < 3; i++) {
        const float *a = tri + 3 * i, *b = tri + 3 * (i + 1 == 3 ? 0 : i + 1);
        double s = 1.0;
        if (lex_less(b, a)) { const float *x = a; a = b; b = x; s = -1.0; }
        /* canonical: m = (w b - e) x (a - b), k = -w' m . a (w' = 1 - w) */
        double u[3], v[3], m[3];
        for (int k = 0; k < 3; k++) {
            u[k] = (c->w ? (double)b[k] : 0.0) - c->e[k];
            v[k] = (double)a[k] - (double)b[k];
        }
        d3_cross(m, u, v);
        double kk = 0.0;
        if (!c->w) { const double ad[3] = { a[0], a[1], a[2] }; kk = -d3_dot(m, ad); }
        /* s: the cyclic direction (exact negation keeps |V| identical for both triangles of the edge) */
        for (int k = 0; k < 3; k++) M[i][k] = s * m[k];
        K[i] = s * kk;
    }
    /* sigma: the orientation, edge 0's function at vertex 2 (the tetrahedron's D_123E) */
    double q2[3];
    for (int k = 0; k < 3; k++) q2[k] = (double)tri[6 + k] - (c->w ? c->e[k] : 0.0);
    const double vol = K[0] + d3_dot(M[0], q2);
    T->ok = vol != 0.0 && isfinite(vol);
    const double sigma = vol > 0.0 ? 1.0 : -1.0;
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < 3; k++) T->m[i][k] = sigma * M[i][k];
        T->k[i] = sigma * K[i];
        /* the top-left rule in 3D: the ray perturbed by eps right + eps^2 down + eps^3 forward */
        const double r = d3_dot(T->m[i], c->right), dn = d3_dot(T->m[i], c->down), f = d3_dot(T->m[i], c->forward);
        T->tie[i] = r > 0.0 || (r == 0.0 && (dn > 0.0 || (dn == 0.0 && f > 0.0)));
    }
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        T->p0[k] = tri[k];
        e1[k] = (double)tri[3 + k] - (double)tri[k];
        e2[k] = (double)tri[6 + k] - (double)tri[k];
    }
    d3_cross(T->n, e1, e2);
}

/* Rounding margin of the culling tests: the rays the per-pixel test scores are float (ms_camera_ray), a
 * few ulps (1e-7 relative) from the exact rays of their image positions that the tile bounds describe. */
#define E3_REL 1e-6

int ms_e3_tile_planar(const ms_e3_tri *T, const double q[4][3], double qmag)
{
    if (!T->ok) return 0;
    for (int i = 0; i < 3; i++) {
        const double *m = T->m[i];
        double hi = -INFINITY;
        for (int c = 0; c < 4; c++) {
            const double v = T->k[i] + d3_dot(m, q[c]);
            hi = v > hi ? v : hi;
        }
        const double mm = sqrt(d3_dot(m, m));
        if (hi < -E3_REL * (mm * qmag + fabs(T->k[i]))) return 0;
    }
    return 1;
}

/* Curved cameras: the paper (sec. 4.1) shifts the corners of a bin towards the centre of the circle the
 * parabolic map makes of an edge. That is specific to one projection; here every curved camera is
 * handled alike through ms_camera_angle_per_pixel: a tile's rays lie in the cone of its centre ray with
 * half-angle alpha = L * half-diagonal, and the largest value of V = m . d over unit d in that cone is
 * |m| cos(max(0, angle(m, axis) - alpha)); it is negative iff angle(m, axis) > pi/2 + alpha. */
int ms_e3_tile_cone(const ms_e3_tri *T, const double a[3], double alpha)
{
    if (!T->ok) return 0;
    if (alpha + E3_REL >= 0.5 * M_PI) return 1;
    /* angle(m, a) > pi/2 + alpha  <=>  cos angle(m, a) < -sin alpha (alpha < pi/2): no acos per edge */
    const double lim = -sin(alpha + E3_REL);
    for (int i = 0; i < 3; i++) {
        const double *m = T->m[i];
        const double mm = sqrt(d3_dot(m, m));
        if (!(mm > 0.0)) return 0;
        if (d3_dot(m, a) < lim * mm) return 0;
    }
    return 1;
}

static int clampi(double v, int lo, int hi)
{
    if (!(v > (double)lo)) return lo;   /* also NaN */
    if (v > (double)hi) return hi;
    return (int)v;
}

/* A box of continuous image positions [x0, x1] x [y0, y1] to the pixels whose centres it may hold,
 * widened by a pixel for the rounding of the projection. 0 if none. */
static int pixel_box(const ms_camera_basis *b, double x0, double y0, double x1, double y1, ms_e3_box *o)
{
    if (!(x1 >= -1.0 && x0 <= b->width + 1.0 && y1 >= -1.0 && y0 <= b->height + 1.0)) return 0;
    o->x0 = clampi(floor(x0 - 1.5), 0, b->width - 1);
    o->x1 = clampi(ceil(x1 + 0.5), 0, b->width - 1);
    o->y0 = clampi(floor(y0 - 1.5), 0, b->height - 1);
    o->y1 = clampi(ceil(y1 + 0.5), 0, b->height - 1);
    return o->x0 <= o->x1 && o->y0 <= o->y1;
}

static int whole(const ms_camera_basis *b, ms_e3_box *o)
{
    o->x0 = 0; o->y0 = 0; o->x1 = b->width - 1; o->y1 = b->height - 1;
    return 1;
}

/* Curved cameras: the triangle's directions from the eye lie in the smallest-ish cap around the mean of
 * its vertex directions (a spherical triangle lies in any cap of radius < pi/2 holding its vertices);
 * the cap becomes an interval of the polar angle theta and of the azimuth phi around the projection's
 * axis (up for latlong, forward for fisheye and parabolic), and that a box of pixels. */
static int bounds_curved(const ms_camera_basis *b, const float tri[9], ms_e3_box box[2])
{
    double u[3][3], c[3] = { 0, 0, 0 };
    for (int v = 0; v < 3; v++) {
        double l = 0.0;
        for (int k = 0; k < 3; k++) { u[v][k] = (double)tri[3 * v + k] - (double)b->eye[k]; l += u[v][k] * u[v][k]; }
        l = sqrt(l);
        if (!(l > 0.0) || !isfinite(l)) return whole(b, box);
        for (int k = 0; k < 3; k++) { u[v][k] /= l; c[k] += u[v][k]; }
    }
    const double cl = sqrt(d3_dot(c, c));
    if (!(cl > 1e-3)) return whole(b, box);
    for (int k = 0; k < 3; k++) c[k] /= cl;
    double r = 0.0;
    for (int v = 0; v < 3; v++) {
        double d = d3_dot(c, u[v]);
        d = d > 1.0 ? 1.0 : d < -1.0 ? -1.0 : d;
        const double a = acos(d);
        r = a > r ? a : r;
    }
    r += 1e-4;   /* the rounding of the rays and of this set-up, far below a pixel at 8192 wide */
    if (r >= 0.5 * M_PI) return whole(b, box);
    /* frame: axis A, and B, C spanning the azimuth (phi from B towards C) */
    double A[3], B[3], C[3];
    const int latlong = b->type == MS_CAMERA_LATLONG;
    for (int k = 0; k < 3; k++) {
        A[k] = latlong ? b->up[k] : b->forward[k];
        B[k] = latlong ? b->forward[k] : b->right[k];
        C[k] = latlong ? b->right[k] : b->up[k];
    }
    double ca = d3_dot(c, A);
    ca = ca > 1.0 ? 1.0 : ca < -1.0 ? -1.0 : ca;
    const double thc = acos(ca), phc = atan2(d3_dot(c, C), d3_dot(c, B));
    double th0 = thc - r, th1 = thc + r, dphi = M_PI;
    const int full = th0 <= 0.0 || th1 >= M_PI;
    if (th0 < 0.0) th0 = 0.0;
    if (th1 > M_PI) th1 = M_PI;
    if (!full) {
        const double s = sin(r) / sin(thc);
        dphi = s >= 1.0 ? M_PI : asin(s);
    }
    const int fullphi = full || dphi >= M_PI;
    const double W = b->width, H = b->height;
    if (latlong) {
        /* x = (phi / 2 pi + 0.5) W, y = theta / pi H */
        const double y0 = th0 / M_PI * H, y1 = th1 / M_PI * H;
        if (fullphi) return pixel_box(b, 0.0, y0, W, y1, box);
        double x0 = ((phc - dphi) / (2.0 * M_PI) + 0.5) * W, x1 = ((phc + dphi) / (2.0 * M_PI) + 0.5) * W;
        int n = 0;
        if (x0 < 0.0) {   /* wraps at the left edge */
            n += pixel_box(b, x0 + W, y0, W, y1, &box[n]);
            x0 = 0.0;
        } else if (x1 > W) {
            n += pixel_box(b, 0.0, y0, x1 - W, y1, &box[n]);
            x1 = W;
        }
        n += pixel_box(b, x0, y0, x1, y1, &box[n]);
        return n;
    }
    /* fisheye and parabolic: image radius rho(theta), increasing; the azimuth phi from right towards up
     * at (cx + rho cos phi, cy - rho sin phi) */
    double rho0, rho1;
    if (b->type == MS_CAMERA_FISHEYE) {
        if (th0 > b->max_theta) return 0;
        rho0 = th0 / b->max_theta * b->radius;
        rho1 = (th1 < b->max_theta ? th1 : b->max_theta) / b->max_theta * b->radius;
    } else {
        if (th0 > 0.5 * M_PI) return 0;
        rho0 = b->radius * tan(0.5 * th0);
        rho1 = b->radius * tan(0.5 * (th1 < 0.5 * M_PI ? th1 : 0.5 * M_PI));
    }
    if (fullphi) return pixel_box(b, b->cx - rho1, b->cy - rho1, b->cx + rho1, b->cy + rho1, box);
    /* the annular sector's box: its four corners and the outer arc where it crosses an axis */
    double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
    const double ph[2] = { phc - dphi, phc + dphi }, rh[2] = { rho0, rho1 };
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            const double x = b->cx + rh[j] * cos(ph[i]), y = b->cy - rh[j] * sin(ph[i]);
            xlo = x < xlo ? x : xlo; xhi = x > xhi ? x : xhi;
            ylo = y < ylo ? y : ylo; yhi = y > yhi ? y : yhi;
        }
    for (int q = -4; q <= 4; q++) {
        const double a = q * 0.5 * M_PI;
        if (a < ph[0] || a > ph[1]) continue;
        const double x = b->cx + rho1 * cos(a), y = b->cy - rho1 * sin(a);
        xlo = x < xlo ? x : xlo; xhi = x > xhi ? x : xhi;
        ylo = y < ylo ? y : ylo; yhi = y > yhi ? y : yhi;
    }
    return pixel_box(b, xlo, ylo, xhi, yhi, box);
}

int ms_e3_bounds(const ms_camera_basis *b, const float tri[9], ms_e3_box box[2])
{
    if (!ms_camera_planar(b)) return bounds_curved(b, tri, box);
    /* depth along forward of each vertex; a ray needs t > 0, and every ray has d . forward > 0 */
    double z[3], a[3], c[3], zmax = -INFINITY, zmin = INFINITY, len = 0.0;
    for (int v = 0; v < 3; v++) {
        double p[3];
        for (int k = 0; k < 3; k++) p[k] = (double)tri[3 * v + k] - (double)b->eye[k];
        const double f[3] = { b->forward[0], b->forward[1], b->forward[2] };
        const double rr[3] = { b->right[0], b->right[1], b->right[2] }, uu[3] = { b->up[0], b->up[1], b->up[2] };
        z[v] = d3_dot(p, f); a[v] = d3_dot(p, rr); c[v] = d3_dot(p, uu);
        zmax = z[v] > zmax ? z[v] : zmax;
        zmin = z[v] < zmin ? z[v] : zmin;
        const double l = sqrt(d3_dot(p, p));
        len = l > len ? l : len;
    }
    if (!isfinite(len)) return whole(b, box);
    if (zmax < -1e-6 * len) return 0;   /* wholly behind */
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    if (b->type == MS_CAMERA_ORTHOGRAPHIC) {
        for (int v = 0; v < 3; v++) {
            const double px = 0.5 * (a[v] / b->half_w + 1.0) * b->width, py = 0.5 * (1.0 - c[v] / b->half_h) * b->height;
            x0 = px < x0 ? px : x0; x1 = px > x1 ? px : x1;
            y0 = py < y0 ? py : y0; y1 = py > y1 ? py : y1;
        }
        return pixel_box(b, x0, y0, x1, y1, box);
    }
    if (!(zmin > 1e-6 * len)) return whole(b, box);   /* crosses the eye's plane: no bounded image */
    for (int v = 0; v < 3; v++) {
        const double sx = a[v] / (z[v] * b->tan_half_y * b->aspect), sy = c[v] / (z[v] * b->tan_half_y);
        const double px = 0.5 * (sx + 1.0) * b->width, py = 0.5 * (1.0 - sy) * b->height;
        x0 = px < x0 ? px : x0; x1 = px > x1 ? px : x1;
        y0 = py < y0 ? py : y0; y1 = py > y1 ? py : y1;
    }
    return pixel_box(b, x0, y0, x1, y1, box);
}
