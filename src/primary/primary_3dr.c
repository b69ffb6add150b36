/* Primary methods "3dr-bb", "3dr-bin", "3dr-fc", "3dr-fs", "3dr-full": the sample points of the 3D
 * rasterization continuum of Dachsbacher et al. ("3D Rasterization - Unifying Rasterization and Ray
 * Casting", sec. 4.4 and 5), every one deciding each pixel
 * with the one 3D edge-function test of edge3d.h on the ray of ms_camera_ray, so all of them (and the
 * consistent BVH caster) give bit-identical hits: the nearest t, ties to the smaller triangle id.
 *
 *  - 3dr-bb: every pixel of the triangle's screen bounds (ms_e3_bounds; curved cameras: the bounds of the
 *    cap of its directions). Streams: a procedural scene is read in batches (ms_procedural_triangles, ids
 *    in scene order) and never held; mesh scenes are read in the BVH's leaf order with leaf ids.
 *  - 3dr-bin: hierarchical binning from the bounds down to 8x8 pixels, a bin rejected when an edge
 *    function is negative over it (ms_e3_tile_planar at its corners, ms_e3_tile_cone for curved cameras)
 *    or by early-z (the triangle's nearest possible distance behind the bin's farthest stored one). Streams.
 *  - 3dr-fc: the screen in frusta of 256x256 pixels, each culled through our BVH (frustum vs box), binning
 *    for the triangles of the leaves it reaches.
 *  - 3dr-fs: no binning; occlusion culling (a node's nearest distance behind the frustum's farthest stored
 *    one) and adaptive frustum splitting down to 32x32 pixels (the paper: 8x8) when the frustum's centre
 *    ray misses a node's box or the box is small against the frustum; per-pixel tests over the leaf
 *    triangles' bounds. 32, not 8: each split pays a frustum set-up (corner or centre rays, a cone), and
 *    below 32x32 that cost exceeded the pixel tests it saved on every shared scene (docs/primary.md:
 *    3dr-full at 1024² 0.30-0.84x of bvh with 32, 0.58-1.37x with 8; 64 measured the same as 32).
 *  - 3dr-full: 3dr-fs with binning and early-z in the leaves.
 * Departures: the paper culls back faces (microshadow's visibility is two-sided); it evaluates edge
 * functions incrementally or directly, here always directly in double (edge3d.h); frusta of curved
 * cameras are cones (axis the centre ray, half-angle from ms_camera_angle_per_pixel), of the
 * orthographic camera rectangles of ray origins, of the pinhole camera cones through the corner rays.
 * The whole pass runs in create (threads: row bands of 8-row multiples for bb/bin, frusta for the BVH
 * variants, so no pixel is written by two threads); trace copies or finishes the hits. */
#include "primary.h"
#include "edge3d.h"
#include "core/vec.h"
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define R3_BATCH 65536
#define R3_BIN 8          /* binning stops at 8x8 pixels; also the early-z block */
#define R3_FRUSTUM 256
#define R3_FS_MIN 32      /* frustum splitting stops here (see above) */

enum { V_BB, V_BIN, V_FC, V_FS, V_FULL };

/* A triangle's set-up, bounds and nearest distance: the BVH variants keep one per triangle, made once,
 * as a frustum split revisits the leaves (the paper sets a triangle up at every visit). */
typedef struct r3_setup {
    ms_e3_tri T;
    ms_e3_box box[2];
    int nb;
    float near;
} r3_setup;

typedef struct r3_state {
    int variant, W, H, bw, bh, planar, streamed;
    ms_e3_cam cam;
    float *q;             /* per pixel the scored point (d, or o for orthographic); NaN: no ray */
    float *t;             /* nearest t, INFINITY none */
    uint32_t *id;
    float *bfar;          /* per 8x8 block the farthest stored distance (INFINITY: some pixel unhit) */
    uint8_t *dirty;       /* block's bfar stale */
    ms_hit *hits;         /* streamed: finished at write (no BVH to finish from later) */
    r3_setup *setups;     /* BVH variants: per triangle (leaf order) */
    uint64_t cnt[3];      /* S, E, N */
    const ms_render_ctx *ctx;
} r3_state;

typedef struct r3_thread {
    r3_state *s;
    uint64_t S, E, N;
} r3_thread;

/* ---- the pixel decision and the depth buffer ---- */

static void pixel_ray(const r3_state *s, size_t i, const float **o, const float **d, const float **q)
{
    const ms_camera_basis *b = &s->ctx->cam;
    *q = s->q + 3 * i;
    if (s->cam.w) { *o = b->eye; *d = *q; }
    else { *o = *q; *d = b->forward; }
}

/* Distance from the ray's origin of the stored hit of pixel i: the early-z and occlusion depth. */
static float pixel_dist(const r3_state *s, size_t i)
{
    const float *q = s->q + 3 * i;
    if (q[0] != q[0]) return 0.0f;   /* no ray: never claimed, never blocks culling */
    if (s->id[i] == UINT32_MAX) return INFINITY;
    return s->cam.w ? s->t[i] * sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) : s->t[i];
}

static float block_far(r3_state *s, int bx, int by)
{
    const size_t b = (size_t)by * s->bw + bx;
    if (s->dirty[b]) {
        float f = 0.0f;
        const int x1 = (bx + 1) * R3_BIN < s->W ? (bx + 1) * R3_BIN : s->W;
        const int y1 = (by + 1) * R3_BIN < s->H ? (by + 1) * R3_BIN : s->H;
        for (int y = by * R3_BIN; y < y1; y++)
            for (int x = bx * R3_BIN; x < x1; x++) {
                const float d = pixel_dist(s, (size_t)y * s->W + x);
                f = d > f ? d : f;
            }
        s->bfar[b] = f;
        s->dirty[b] = 0;
    }
    return s->bfar[b];
}

/* Farthest stored distance over the pixels [x0,x1] x [y0,y1] (inclusive), by the 8x8 blocks they touch. */
static float rect_far(r3_state *s, int x0, int y0, int x1, int y1)
{
    float f = 0.0f;
    for (int by = y0 / R3_BIN; by <= y1 / R3_BIN; by++)
        for (int bx = x0 / R3_BIN; bx <= x1 / R3_BIN; bx++) {
            const float b = block_far(s, bx, by);
            if (b == INFINITY) return b;
            f = b > f ? b : f;
        }
    return f;
}

/* Same arithmetic as ms_hit_finish, from the triangle itself (streamed scenes have no BVH). */
static void finish_from_tri(const float *tri, const float o[3], const float d[3], float t, uint32_t prim, ms_hit *h)
{
    ms_hit_finish_tri(tri, o, d, t, prim, h);
}

static void raster_rect(r3_thread *th, const ms_e3_tri *T, const float *tri, uint32_t id, int x0, int y0, int x1, int y1)
{
    r3_state *s = th->s;
    for (int y = y0; y <= y1; y++) {
        for (int x = x0; x <= x1; x++) {
            const size_t i = (size_t)y * s->W + x;
            const float *o, *d, *q;
            pixel_ray(s, i, &o, &d, &q);
            float t;
            if (!ms_e3_hit(T, o, d, q, &t)) continue;
            if (t > s->t[i] || (t == s->t[i] && id > s->id[i])) continue;
            if (!ms_e3_accept(s->ctx->alpha, id, o, d)) continue;   /* a cut-out's hole (alpha.h) */
            s->t[i] = t;
            s->id[i] = id;
            s->dirty[(size_t)(y / R3_BIN) * s->bw + x / R3_BIN] = 1;
            if (s->hits) finish_from_tri(tri, o, d, t, id, &s->hits[i]);
        }
    }
    th->E += 3u * (uint64_t)(x1 - x0 + 1) * (uint64_t)(y1 - y0 + 1);
}

/* The cone of the rays of pixels [x0,x1] x [y0,y1] for curved cameras: 0 and no cone when the centre has
 * no ray (outside a fisheye's circle). */
static int rect_cone(const r3_state *s, int x0, int y0, int x1, int y1, double axis[3], double *alpha)
{
    const ms_camera_basis *b = &s->ctx->cam;
    float o[3], d[3];
    const float cx = 0.5f * (float)(x0 + x1 + 1), cy = 0.5f * (float)(y0 + y1 + 1);
    if (ms_camera_ray_at(b, cx, cy, o, d)) return 0;
    const double l = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
    for (int k = 0; k < 3; k++) axis[k] = d[k] / l;
    const double hd = 0.5 * hypot((double)(x1 - x0), (double)(y1 - y0));
    *alpha = ms_camera_angle_per_pixel(b) * hd * (1.0 + 1e-4) + 1e-6;
    return 1;
}

/* Can some pixel of [x0,x1] x [y0,y1] pass T's edges? Conservative (edge3d.c). */
static int rect_may_pass(r3_thread *th, const ms_e3_tri *T, int x0, int y0, int x1, int y1)
{
    const r3_state *s = th->s;
    if (s->planar) {
        double q[4][3], qm = 0.0;
        const int xs[2] = { x0, x1 }, ys[2] = { y0, y1 };
        for (int c = 0; c < 4; c++) {
            float o[3], d[3];
            ms_camera_ray(&s->ctx->cam, xs[c & 1], ys[c >> 1], o, d);
            const float *qq = s->cam.w ? d : o;
            double m = 0.0;
            for (int k = 0; k < 3; k++) { q[c][k] = qq[k]; m += q[c][k] * q[c][k]; }
            qm = m > qm ? m : qm;
        }
        th->E += 12;
        return ms_e3_tile_planar(T, q, sqrt(qm));
    }
    double axis[3], alpha;
    if (!rect_cone(s, x0, y0, x1, y1, axis, &alpha)) return 1;
    th->E += 3;
    return ms_e3_tile_cone(T, axis, alpha);
}

/* Hierarchical binning with early-z over [x0,x1] x [y0,y1]; near: the triangle's nearest distance. */
static void bin_rect(r3_thread *th, const ms_e3_tri *T, const float *tri, uint32_t id, float near,
                     int x0, int y0, int x1, int y1)
{
    r3_state *s = th->s;
    const int small = x1 - x0 < R3_BIN && y1 - y0 < R3_BIN;
    if (!small && !rect_may_pass(th, T, x0, y0, x1, y1)) return;
    /* early-z, on bins of up to 64x64 pixels (64 blocks to read) */
    if (x1 - x0 < 64 && y1 - y0 < 64 && near > rect_far(s, x0, y0, x1, y1) * (1.0f + 1e-5f)) return;
    if (small) { raster_rect(th, T, tri, id, x0, y0, x1, y1); return; }
    const int xm = x1 - x0 >= R3_BIN ? (x0 + x1) / 2 : x1, ym = y1 - y0 >= R3_BIN ? (y0 + y1) / 2 : y1;
    bin_rect(th, T, tri, id, near, x0, y0, xm, ym);
    if (xm < x1) bin_rect(th, T, tri, id, near, xm + 1, y0, x1, ym);
    if (ym < y1) bin_rect(th, T, tri, id, near, x0, ym + 1, xm, y1);
    if (xm < x1 && ym < y1) bin_rect(th, T, tri, id, near, xm + 1, ym + 1, x1, y1);
}

/* Lower bound of the distance from the ray origins to the triangle: the plane's distance from the eye
 * (a point eye), the least depth along forward of a vertex (orthographic). */
static float tri_near(const r3_state *s, const ms_e3_tri *T, const float *tri)
{
    const ms_camera_basis *b = &s->ctx->cam;
    if (!s->cam.w) {
        double z = INFINITY;
        for (int v = 0; v < 3; v++) {
            double zz = 0.0;
            for (int k = 0; k < 3; k++) zz += ((double)tri[3 * v + k] - b->eye[k]) * b->forward[k];
            z = zz < z ? zz : z;
        }
        return (float)(z * (1.0 - 1e-6));
    }
    double num = 0.0, nn = 0.0;
    for (int k = 0; k < 3; k++) { num += T->n[k] * (T->p0[k] - b->eye[k]); nn += T->n[k] * T->n[k]; }
    const double dd = fabs(num) / sqrt(nn);
    return dd == dd ? (float)(dd * (1.0 - 1e-6)) : 0.0f;
}

static void make_setup(const r3_state *s, const float *tri, r3_setup *u)
{
    u->nb = ms_e3_bounds(&s->ctx->cam, tri, u->box);
    ms_e3_setup(&s->cam, tri, &u->T);
    u->near = tri_near(s, &u->T, tri);
}

/* One triangle into the pixels of [cx0,cx1] x [cy0,cy1] (a band or a frustum); pre: its set-up, or NULL. */
static void draw_triangle(r3_thread *th, const float *tri, uint32_t id, int binning, int cx0, int cy0, int cx1, int cy1,
                          const r3_setup *pre)
{
    r3_state *s = th->s;
    ms_e3_box box[2];
    const int nb = pre ? pre->nb : ms_e3_bounds(&s->ctx->cam, tri, box);
    if (pre) memcpy(box, pre->box, sizeof box);
    int any = 0;
    for (int b = 0; b < nb; b++) {
        box[b].x0 = box[b].x0 > cx0 ? box[b].x0 : cx0; box[b].x1 = box[b].x1 < cx1 ? box[b].x1 : cx1;
        box[b].y0 = box[b].y0 > cy0 ? box[b].y0 : cy0; box[b].y1 = box[b].y1 < cy1 ? box[b].y1 : cy1;
        any |= box[b].x0 <= box[b].x1 && box[b].y0 <= box[b].y1;
    }
    if (!any) return;
    ms_e3_tri Tl;
    const ms_e3_tri *T = &Tl;
    if (pre) T = &pre->T;
    else {
        ms_e3_setup(&s->cam, tri, &Tl);
        th->S++;
    }
    if (!T->ok) return;
    const float near = pre ? pre->near : binning ? tri_near(s, T, tri) : 0.0f;
    for (int b = 0; b < nb; b++) {
        if (box[b].x0 > box[b].x1 || box[b].y0 > box[b].y1) continue;
        if (binning) bin_rect(th, T, tri, id, near, box[b].x0, box[b].y0, box[b].x1, box[b].y1);
        else raster_rect(th, T, tri, id, box[b].x0, box[b].y0, box[b].x1, box[b].y1);
    }
}

/* ---- BVH frusta (fc, fs, full) ---- */

typedef struct r3_frustum {
    int x0, y0, x1, y1;       /* pixels, inclusive */
    int cone;                 /* 1: cone (axis, alpha); 0 and ortho: origin rectangle; 0 otherwise: no culling */
    double axis[3], alpha, cos_a, sin_a;
    double a0, a1, c0, c1;
    float co[3], cd[3];       /* the centre ray (cok: it exists) */
    int cok;    /* orthographic: the origins' right and up ranges (relative to the eye) */
} r3_frustum;

static void frustum_init(const r3_state *s, r3_frustum *f, int x0, int y0, int x1, int y1)
{
    const ms_camera_basis *b = &s->ctx->cam;
    f->x0 = x0; f->y0 = y0; f->x1 = x1; f->y1 = y1;
    f->cone = 0;
    f->cok = !ms_camera_ray_at(b, 0.5f * (float)(x0 + x1 + 1), 0.5f * (float)(y0 + y1 + 1), f->co, f->cd);
    if (b->type == MS_CAMERA_ORTHOGRAPHIC) {
        const double hw = b->half_w, hh = b->half_h;
        f->a0 = (2.0 * (x0 + 0.5) / b->width - 1.0) * hw;
        f->a1 = (2.0 * (x1 + 0.5) / b->width - 1.0) * hw;
        f->c1 = (1.0 - 2.0 * (y0 + 0.5) / b->height) * hh;
        f->c0 = (1.0 - 2.0 * (y1 + 0.5) / b->height) * hh;
        const double m = 1e-5 * (hw + hh);
        f->a0 -= m; f->a1 += m; f->c0 -= m; f->c1 += m;
        return;
    }
    if (b->type == MS_CAMERA_PINHOLE) {
        float o[3], d[3];
        const float *cd = f->cd;
        double l = sqrt((double)cd[0] * cd[0] + (double)cd[1] * cd[1] + (double)cd[2] * cd[2]);
        for (int k = 0; k < 3; k++) f->axis[k] = cd[k] / l;
        double cmin = 1.0;
        const int xs[2] = { x0, x1 }, ys[2] = { y0, y1 };
        for (int c = 0; c < 4; c++) {
            ms_camera_ray(b, xs[c & 1], ys[c >> 1], o, d);
            l = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
            const double cs = (d[0] * f->axis[0] + d[1] * f->axis[1] + d[2] * f->axis[2]) / l;
            cmin = cs < cmin ? cs : cmin;
        }
        f->alpha = acos(cmin > 1.0 ? 1.0 : cmin < -1.0 ? -1.0 : cmin) * (1.0 + 1e-4) + 1e-6;
        f->cos_a = cos(f->alpha);
        f->sin_a = sin(f->alpha);
        f->cone = 1;
        return;
    }
    /* curved: the cone of the tile (rect_cone), from the centre ray made above */
    f->cone = f->cok;
    if (f->cok) {
        const double l = sqrt((double)f->cd[0] * f->cd[0] + (double)f->cd[1] * f->cd[1] + (double)f->cd[2] * f->cd[2]);
        for (int k = 0; k < 3; k++) f->axis[k] = f->cd[k] / l;
        f->alpha = ms_camera_angle_per_pixel(b) * 0.5 * hypot((double)(x1 - x0), (double)(y1 - y0)) * (1.0 + 1e-4) + 1e-6;
    }
    f->cos_a = cos(f->alpha);
    f->sin_a = sin(f->alpha);
}

/* 1 when no ray of f can reach the box (conservative). */
static int frustum_culls(const r3_state *s, const r3_frustum *f, const ms_bvh_node *n)
{
    const ms_camera_basis *b = &s->ctx->cam;
    if (b->type == MS_CAMERA_ORTHOGRAPHIC) {
        double alo = INFINITY, ahi = -INFINITY, clo = INFINITY, chi = -INFINITY, zhi = -INFINITY;
        for (int c = 0; c < 8; c++) {
            const double p[3] = { (c & 1 ? n->bmax[0] : n->bmin[0]) - b->eye[0], (c & 2 ? n->bmax[1] : n->bmin[1]) - b->eye[1],
                                  (c & 4 ? n->bmax[2] : n->bmin[2]) - b->eye[2] };
            const double a = p[0] * b->right[0] + p[1] * b->right[1] + p[2] * b->right[2];
            const double cc = p[0] * b->up[0] + p[1] * b->up[1] + p[2] * b->up[2];
            const double z = p[0] * b->forward[0] + p[1] * b->forward[1] + p[2] * b->forward[2];
            alo = a < alo ? a : alo; ahi = a > ahi ? a : ahi;
            clo = cc < clo ? cc : clo; chi = cc > chi ? cc : chi;
            zhi = z > zhi ? z : zhi;
        }
        return ahi < f->a0 || alo > f->a1 || chi < f->c0 || clo > f->c1 || zhi < 0.0;
    }
    if (!f->cone) return 0;
    double c[3], r2 = 0.0, v2 = 0.0, va = 0.0;
    for (int k = 0; k < 3; k++) {
        c[k] = 0.5 * ((double)n->bmin[k] + n->bmax[k]);
        const double h = 0.5 * ((double)n->bmax[k] - n->bmin[k]);
        r2 += h * h;
        const double v = c[k] - b->eye[k];
        v2 += v * v;
        va += v * f->axis[k];
    }
    const double r = sqrt(r2) * (1.0 + 1e-6), dist = sqrt(v2);
    if (dist <= r) return 0;
    /* angle(v, axis) > alpha + beta, sin beta = r / dist, without acos/asin: cos angle < cos(alpha + beta) */
    const double sb = r / dist, cb = sqrt(1.0 - sb * sb);
    if (f->alpha >= 0.5 * M_PI) return 0;   /* (beta < pi/2: alpha + beta < pi below) */
    return va / dist < f->cos_a * cb - f->sin_a * sb - 1e-12;
}

/* Nearest distance from the ray origins to the box (lower bound; 0 when an origin may be inside). */
static float node_near(const r3_state *s, const ms_bvh_node *n)
{
    const ms_camera_basis *b = &s->ctx->cam;
    if (!s->cam.w) {
        double z = INFINITY;
        for (int c = 0; c < 8; c++) {
            const double p[3] = { (c & 1 ? n->bmax[0] : n->bmin[0]) - b->eye[0], (c & 2 ? n->bmax[1] : n->bmin[1]) - b->eye[1],
                                  (c & 4 ? n->bmax[2] : n->bmin[2]) - b->eye[2] };
            const double zz = p[0] * b->forward[0] + p[1] * b->forward[1] + p[2] * b->forward[2];
            z = zz < z ? zz : z;
        }
        return z > 0.0 ? (float)(z * (1.0 - 1e-6)) : 0.0f;
    }
    double d2 = 0.0;
    for (int k = 0; k < 3; k++) {
        const double e = b->eye[k];
        const double g = e < n->bmin[k] ? n->bmin[k] - e : e > n->bmax[k] ? e - n->bmax[k] : 0.0;
        d2 += g * g;
    }
    return (float)(sqrt(d2) * (1.0 - 1e-6));
}

/* Does the frustum's centre ray meet the box? (the split oracle; not a culling test) */
static int centre_ray_hits(const r3_state *s, const r3_frustum *f, const ms_bvh_node *n)
{
    (void)s;
    if (!f->cok) return 1;
    const float *o = f->co, *d = f->cd;
    double tn = 0.0, tf = INFINITY;
    for (int k = 0; k < 3; k++) {
        const double inv = 1.0 / d[k];
        double a = (n->bmin[k] - o[k]) * inv, b = (n->bmax[k] - o[k]) * inv;
        if (a > b) { const double x = a; a = b; b = x; }
        if (a != a) a = -INFINITY;
        if (b != b) b = INFINITY;
        tn = a > tn ? a : tn;
        tf = b < tf ? b : tf;
    }
    return tn <= tf;
}

/* The box is small against the frustum: its angular radius (orthographic: its radius) under a quarter
 * of the frustum's. */
static int box_small(const r3_state *s, const r3_frustum *f, const ms_bvh_node *n)
{
    const ms_camera_basis *b = &s->ctx->cam;
    double r2 = 0.0, v2 = 0.0;
    for (int k = 0; k < 3; k++) {
        const double h = 0.5 * ((double)n->bmax[k] - n->bmin[k]), v = 0.5 * ((double)n->bmin[k] + n->bmax[k]) - b->eye[k];
        r2 += h * h;
        v2 += v * v;
    }
    if (b->type == MS_CAMERA_ORTHOGRAPHIC) return sqrt(r2) < 0.25 * 0.5 * hypot(f->a1 - f->a0, f->c1 - f->c0);
    if (!f->cone || v2 <= r2) return 0;
    return asin(sqrt(r2 / v2)) < 0.25 * f->alpha;
}

static void frustum_leaf(r3_thread *th, const r3_frustum *f, const ms_bvh_node *n, int binning)
{
    const ms_bvh *bvh = th->s->ctx->bvh;
    for (uint32_t i = n->first; i < n->first + n->count; i++)
        draw_triangle(th, bvh->tri + 9 * (size_t)i, i, binning, f->x0, f->y0, f->x1, f->y1, &th->s->setups[i]);
}

/* 3dr-fc: one frustum through the BVH, near child first. */
static void traverse_fc(r3_thread *th, const r3_frustum *f)
{
    const ms_bvh *bvh = th->s->ctx->bvh;
    uint32_t stack[MS_BVH_STACK * 2];
    int sp = 0;
    stack[sp++] = 0;
    while (sp) {
        const ms_bvh_node *n = &bvh->nodes[stack[--sp]];
        th->N++;
        if (frustum_culls(th->s, f, n)) continue;
        if (n->count) { frustum_leaf(th, f, n, 1); continue; }
        stack[sp++] = n->first + 1;
        stack[sp++] = n->first;
    }
}

/* Children in order of their nearest distance from the eye (near first: occlusion culls the far one). */
static void child_order(const r3_state *s, const ms_bvh *bvh, const ms_bvh_node *n, uint32_t c[2])
{
    const float a = node_near(s, &bvh->nodes[n->first]), b = node_near(s, &bvh->nodes[n->first + 1]);
    c[0] = a <= b ? n->first : n->first + 1;
    c[1] = a <= b ? n->first + 1 : n->first;
}

/* 3dr-fs and 3dr-full (binning 1): occlusion culling and adaptive frustum splitting (Fig. 8 and 9). */
static void traverse_fs(r3_thread *th, const r3_frustum *f, uint32_t node, int binning)
{
    r3_state *s = th->s;
    const ms_bvh *bvh = s->ctx->bvh;
    const ms_bvh_node *n = &bvh->nodes[node];
    th->N++;
    if (frustum_culls(s, f, n)) return;
    const int fw = f->x1 - f->x0 + 1, fh = f->y1 - f->y0 + 1;
    /* occlusion: every pixel holds a hit nearer than the box can be (frusta up to 64x64: 64 blocks) */
    if (fw <= 64 && fh <= 64 && node_near(s, n) > rect_far(s, f->x0, f->y0, f->x1, f->y1) * (1.0f + 1e-5f)) return;
    if (n->count) { frustum_leaf(th, f, n, binning); return; }
    if ((fw > R3_FS_MIN || fh > R3_FS_MIN) && (!centre_ray_hits(s, f, n) || box_small(s, f, n))) {
        const int xm = fw > R3_FS_MIN ? f->x0 + fw / 2 - 1 : f->x1, ym = fh > R3_FS_MIN ? f->y0 + fh / 2 - 1 : f->y1;
        const int rx[3] = { f->x0, xm, f->x1 }, ry[3] = { f->y0, ym, f->y1 };
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++) {
                const int x0 = i ? rx[1] + 1 : rx[0], x1 = i ? rx[2] : rx[1];
                const int y0 = j ? ry[1] + 1 : ry[0], y1 = j ? ry[2] : ry[1];
                if (x0 > x1 || y0 > y1) continue;
                r3_frustum g;
                frustum_init(s, &g, x0, y0, x1, y1);
                traverse_fs(th, &g, node, binning);
            }
        return;
    }
    uint32_t c[2];
    child_order(s, bvh, n, c);
    traverse_fs(th, f, c[0], binning);
    traverse_fs(th, f, c[1], binning);
}

/* ---- the method ---- */

static void r3_free(r3_state *s)
{
    if (!s) return;
    free(s->q); free(s->t); free(s->id); free(s->bfar); free(s->dirty); free(s->hits); free(s->setups);
    free(s);
}

static int r3_create(const ms_render_ctx *ctx, void **state, char *err, size_t errlen, int variant)
{
    const ms_scene *sc = ctx->scene;
    const int W = ctx->cam.width, H = ctx->cam.height;
    const int streamed = ctx->bvh == NULL;
    if (streamed && variant >= V_FC) {
        snprintf(err, errlen, "primary method '%s' needs a BVH and cannot stream a procedural scene (use 3dr-bb, 3dr-bin or depth)",
                 variant == V_FC ? "3dr-fc" : variant == V_FS ? "3dr-fs" : "3dr-full");
        return -1;
    }
    r3_state *s = calloc(1, sizeof *s);
    const size_t np = (size_t)W * H;
    if (s) {
        s->variant = variant; s->W = W; s->H = H; s->ctx = ctx; s->streamed = streamed;
        s->bw = (W + R3_BIN - 1) / R3_BIN; s->bh = (H + R3_BIN - 1) / R3_BIN;
        s->planar = ms_camera_planar(&ctx->cam);
        ms_e3_cam_init(&s->cam, &ctx->cam);
        s->q = malloc(np * 3 * sizeof *s->q);
        s->t = malloc(np * sizeof *s->t);
        s->id = malloc(np * sizeof *s->id);
        s->bfar = malloc((size_t)s->bw * s->bh * sizeof *s->bfar);
        s->dirty = malloc((size_t)s->bw * s->bh);
        if (streamed) s->hits = malloc(np * sizeof *s->hits);
    }
    float *batch = streamed ? malloc((size_t)R3_BATCH * 9 * sizeof *batch) : NULL;
    if (!s || !s->q || !s->t || !s->id || !s->bfar || !s->dirty || (streamed && (!s->hits || !batch))) {
        r3_free(s);
        free(batch);
        snprintf(err, errlen, "out of memory for the 3D rasterization of a %dx%d frame", W, H);
        return -1;
    }
    const int threads = ctx->threads > 0 ? ctx->threads : 1;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const size_t i = (size_t)y * W + x;
            float o[3], d[3];
            if (ms_camera_ray(&ctx->cam, x, y, o, d)) { s->q[3 * i] = s->q[3 * i + 1] = s->q[3 * i + 2] = NAN; }
            else memcpy(s->q + 3 * i, s->cam.w ? d : o, 3 * sizeof(float));
            s->t[i] = INFINITY;
            s->id[i] = UINT32_MAX;
            if (streamed) s->hits[i].prim = UINT32_MAX;
        }
    memset(s->dirty, 1, (size_t)s->bw * s->bh);
    uint64_t S = 0, E = 0, N = 0;
    if (variant <= V_BIN) {
        const int binning = variant == V_BIN;
        const size_t n_all = streamed ? sc->n_tris : ctx->bvh->n_tris;
        const size_t step = streamed ? R3_BATCH : n_all;
        for (size_t first = 0; first < n_all; first += step) {
            const size_t n = n_all - first < step ? n_all - first : step;
            const float *tris = streamed ? batch : ctx->bvh->tri + 9 * first;
#pragma omp parallel num_threads(threads) reduction(+ : S, E, N)
            {
                const int nt = omp_get_num_threads(), me = omp_get_thread_num();
                if (streamed) {
                    const size_t per = (n + (size_t)nt - 1) / (size_t)nt, g0 = per * (size_t)me;
                    if (g0 < n) ms_procedural_triangles(sc, first + g0, g0 + per < n ? per : n - g0, batch + 9 * g0);
#pragma omp barrier
                }
                /* one band of whole 8-row blocks per thread: no block is shared */
                const int y0 = R3_BIN * (int)((long)s->bh * me / nt), y1 = R3_BIN * (int)((long)s->bh * (me + 1) / nt);
                r3_thread th = { s, 0, 0, 0 };
                for (size_t i = 0; i < n && y0 < y1; i++)
                    draw_triangle(&th, tris + 9 * i, (uint32_t)(first + i), binning, 0, y0, W - 1, (y1 < H ? y1 : H) - 1, NULL);
                S += th.S; E += th.E; N += th.N;
            }
        }
    } else if (ctx->bvh->n_nodes) {
        s->setups = malloc((size_t)ctx->bvh->n_tris * sizeof *s->setups);
        if (!s->setups) {
            r3_free(s);
            snprintf(err, errlen, "out of memory for the triangle set-ups of the 3D rasterization");
            return -1;
        }
        const long nt = (long)ctx->bvh->n_tris;
#pragma omp parallel for schedule(static) num_threads(threads)
        for (long i = 0; i < nt; i++) make_setup(s, ctx->bvh->tri + 9 * (size_t)i, &s->setups[i]);
        S = (uint64_t)nt;
        const int fx = (W + R3_FRUSTUM - 1) / R3_FRUSTUM, fy = (H + R3_FRUSTUM - 1) / R3_FRUSTUM;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : S, E, N)
        for (int fi = 0; fi < fx * fy; fi++) {
            const int x0 = (fi % fx) * R3_FRUSTUM, y0 = (fi / fx) * R3_FRUSTUM;
            const int x1 = x0 + R3_FRUSTUM < W ? x0 + R3_FRUSTUM - 1 : W - 1, y1 = y0 + R3_FRUSTUM < H ? y0 + R3_FRUSTUM - 1 : H - 1;
            r3_thread th = { s, 0, 0, 0 };
            r3_frustum f;
            frustum_init(s, &f, x0, y0, x1, y1);
            if (variant == V_FC) traverse_fc(&th, &f);
            else traverse_fs(&th, &f, 0, variant == V_FULL);
            S += th.S; E += th.E; N += th.N;
        }
    }
    s->cnt[0] = S; s->cnt[1] = E; s->cnt[2] = N;
    free(batch);
    *state = s;
    return 0;
}

static void r3_trace(void *state, const ms_render_ctx *ctx, int x0, int y0, int x1, int y1, ms_hit *out)
{
    const r3_state *s = state;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            const size_t i = (size_t)y * s->W + x;
            ms_hit *h = out++;
            if (s->hits) { *h = s->hits[i]; continue; }
            if (s->id[i] == UINT32_MAX) { h->prim = UINT32_MAX; continue; }
            float o[3], d[3];
            ms_camera_ray(&ctx->cam, x, y, o, d);
            ms_hit_finish(ctx, o, d, s->t[i], s->id[i], h);
        }
}

static void r3_destroy(void *state) { r3_free(state); }

static void r3_counters(const void *state, uint64_t c[3])
{
    const r3_state *s = state;
    for (int k = 0; k < 3; k++) c[k] = s->cnt[k];
}

#define R3_METHOD(sym, nm, v)                                                                        \
    static int sym##_create(const ms_render_ctx *ctx, void **state, char *err, size_t errlen)         \
    {                                                                                                \
        return r3_create(ctx, state, err, errlen, v);                                                \
    }                                                                                                \
    const ms_primary_method sym = { .name = nm, .create = sym##_create, .trace = r3_trace,            \
                                    .destroy = r3_destroy, .counters = r3_counters, .streams = v <= V_BIN };

R3_METHOD(ms_primary_3dr_bb, "3dr-bb", V_BB)
R3_METHOD(ms_primary_3dr_bin, "3dr-bin", V_BIN)
R3_METHOD(ms_primary_3dr_fc, "3dr-fc", V_FC)
R3_METHOD(ms_primary_3dr_fs, "3dr-fs", V_FS)
R3_METHOD(ms_primary_3dr_full, "3dr-full", V_FULL)
