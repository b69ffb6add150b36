/* Primary method "depth", for streamed (procedural) scenes: the paper's first step (Laine & Aila 2005,
 * sec. 3.2, "rasterize the scene, store depth values of visible surfaces"), a depth-buffer pass over the
 * scene's triangles in batches, so that no stage of the frame holds the scene. Per triangle, the pixel
 * centres its projection may cover (its screen box widened by a pixel; the whole screen when a vertex is
 * behind the eye; for the curved cameras the box of the cone around it, curved_box) are tested with the
 * same watertight ray/triangle test and the same rays as the BVH
 * primary (ms_camera_ray, ms_wt_intersect with the triangle's ms_wt_normal, t in [0, inf)), keeping the
 * nearest; ties go to the smaller triangle index (the BVH keeps the last one it tests, so the two may
 * differ only at exact ties). The hit is finished by ms_hit_finish_tri, as every primary finishes it. The
 * whole pass runs in create; trace copies.
 * Threads split the image into row bands, each band sees every triangle of a batch: no locks. */
#include "primary.h"
#include "accel/ray_triangle.h"
#include "core/vec.h"
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEPTH_BATCH 65536

typedef struct depth_state {
    int W, H;
    ms_hit *hits;
    float *t;
} depth_state;

/* The curved projections (latlong, fisheye, parabolic): a screen box of the pixel centres whose rays may
 * meet the triangle, from the cone around it seen from the eye (axis to its centroid, half-angle
 * asin(radius / distance), widened for rounding): the cone's range of polar angle and, when it contains
 * neither pole (axis), of longitude (azimuth), imaged by the projection's monotone maps. 0: the box;
 * 1: no pixel can see it; -1: no useful bound (the eye within the triangle's bounding sphere, a cap over
 * a pole or the latlong seam): the whole image. */
static int curved_box(const ms_camera_basis *cb, const float *tri, float *xmin, float *xmax, float *ymin, float *ymax)
{
    float c[3], a[3], rho = 0.0f;
    for (int k = 0; k < 3; k++) c[k] = (tri[k] + tri[3 + k] + tri[6 + k]) / 3.0f;
    for (int v = 0; v < 3; v++) {
        float e[3];
        v3_sub(e, tri + 3 * v, c);
        rho = ms_maxf(rho, v3_len(e));
    }
    v3_sub(a, c, cb->eye);
    const float D = v3_len(a);
    if (!(D > 1.001f * rho + 1e-6f * D)) return -1;
    const float alpha = asinf(rho / D) * 1.0001f + 1e-5f;
    const float ax = v3_dot(a, cb->right) / D, ay = v3_dot(a, cb->up) / D, az = v3_dot(a, cb->forward) / D;
    const float pi = (float)M_PI;
    if (cb->type == MS_CAMERA_LATLONG) {
        const float th = atan2f(sqrtf(ax * ax + az * az), ay), t0 = th - alpha, t1 = th + alpha;
        *ymin = (float)cb->height * ms_maxf(0.0f, t0) / pi;
        *ymax = (float)cb->height * ms_minf(pi, t1) / pi;
        *xmin = 0.0f;
        *xmax = (float)cb->width;
        if (t0 <= 0.0f || t1 >= pi) return 0;   /* over a pole: every longitude */
        const float lc = atan2f(ax, az), dl = asinf(ms_minf(1.0f, sinf(alpha) / sinf(th))) * 1.0001f + 1e-5f;
        if (lc - dl <= -pi || lc + dl >= pi) return 0;   /* across the seam */
        *xmin = ((lc - dl) / (2.0f * pi) + 0.5f) * (float)cb->width;
        *xmax = ((lc + dl) / (2.0f * pi) + 0.5f) * (float)cb->width;
        return 0;
    }
    /* fisheye, parabolic: polar angle from forward to image radius, monotone */
    const float th = atan2f(sqrtf(ax * ax + ay * ay), az), lim = cb->type == MS_CAMERA_FISHEYE ? cb->max_theta : 0.5f * pi;
    const float t0 = ms_maxf(0.0f, th - alpha), t1 = ms_minf(lim, th + alpha);
    if (t0 > lim) return 1;
    const float r0 = cb->type == MS_CAMERA_FISHEYE ? t0 / cb->max_theta * cb->radius : cb->radius * tanf(0.5f * t0);
    const float r1 = cb->type == MS_CAMERA_FISHEYE ? t1 / cb->max_theta * cb->radius : cb->radius * tanf(0.5f * t1);
    if (th - alpha <= 0.0f || th + alpha >= pi) {   /* over the axis or its antipode: every azimuth */
        *xmin = cb->cx - r1; *xmax = cb->cx + r1; *ymin = cb->cy - r1; *ymax = cb->cy + r1;
        return 0;
    }
    const float pc = atan2f(ay, ax), dp = asinf(ms_minf(1.0f, sinf(alpha) / sinf(th))) * 1.0001f + 1e-5f;
    *xmin = *ymin = INFINITY;
    *xmax = *ymax = -INFINITY;
    /* the annular sector's box: its four corners and its outer arc's extreme points within the range */
    const float r[2] = { r0, r1 }, ph[2] = { pc - dp, pc + dp };
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            const float x = cb->cx + r[i] * cosf(ph[j]), y = cb->cy - r[i] * sinf(ph[j]);
            *xmin = ms_minf(*xmin, x); *xmax = ms_maxf(*xmax, x); *ymin = ms_minf(*ymin, y); *ymax = ms_maxf(*ymax, y);
        }
    for (int q = -4; q <= 4; q++) {
        const float p = 0.5f * pi * (float)q;
        if (p < ph[0] || p > ph[1]) continue;
        const float x = cb->cx + r1 * cosf(p), y = cb->cy - r1 * sinf(p);
        *xmin = ms_minf(*xmin, x); *xmax = ms_maxf(*xmax, x); *ymin = ms_minf(*ymin, y); *ymax = ms_maxf(*ymax, y);
    }
    return 0;
}

static void depth_triangle(const ms_render_ctx *ctx, depth_state *s, const float *tri, uint32_t id, int y0, int y1)
{
    const ms_camera_basis *cb = &ctx->cam;
    float xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    int behind = 0;
    if (!ms_camera_planar(cb)) {   /* curved edge images: the box of the vertices does not bound them */
        const int rc = curved_box(cb, tri, &xmin, &xmax, &ymin, &ymax);
        if (rc > 0) return;
        behind = rc < 0;
    }
    for (int v = 0; v < 3 && !behind && ms_camera_planar(cb); v++) {
        float px, py;
        if (ms_camera_project(cb, tri + 3 * v, &px, &py)) { behind = 1; break; }
        xmin = ms_minf(xmin, px); xmax = ms_maxf(xmax, px);
        ymin = ms_minf(ymin, py); ymax = ms_maxf(ymax, py);
    }
    int bx0 = 0, bx1 = s->W - 1, by0 = y0, by1 = y1 - 1;
    if (!behind) {
        if (!(xmax >= -1.0f && xmin <= (float)s->W + 1.0f && ymax >= -1.0f && ymin <= (float)s->H + 1.0f)) return;
        /* centre x + 0.5 in [xmin, xmax], widened by a pixel for the projection's rounding */
        bx0 = (int)ms_maxf(0.0f, floorf(xmin - 1.5f));
        bx1 = (int)ms_minf((float)(s->W - 1), ceilf(xmax + 0.5f));
        by0 = (int)ms_maxf((float)y0, floorf(ymin - 1.5f));
        by1 = (int)ms_minf((float)(y1 - 1), ceilf(ymax + 0.5f));
    }
    if (bx0 > bx1 || by0 > by1) return;
    float N[3];
    ms_wt_normal(tri, N);
    for (int y = by0; y <= by1; y++)
        for (int x = bx0; x <= bx1; x++) {
            float o[3], d[3], t, u, v;
            if (ms_camera_ray(cb, x, y, o, d)) continue;
            ms_wt_ray w;
            ms_wt_prepare(&w, o, d);
            const size_t i = (size_t)y * s->W + x;
            if (!ms_wt_intersect(&w, tri, N, 0.0f, s->t[i], &t, &u, &v)) continue;
            if (t == s->t[i] && s->hits[i].prim < id) continue;
            s->t[i] = t;
            ms_hit_finish_tri(tri, o, d, t, id, &s->hits[i]);
        }
}

static int depth_create(const ms_render_ctx *ctx, void **state, char *err, size_t errlen)
{
    const ms_scene *sc = ctx->scene;
    depth_state *s = calloc(1, sizeof *s);
    const int W = ctx->cam.width, H = ctx->cam.height;
    float *tri = malloc((size_t)DEPTH_BATCH * 9 * sizeof *tri);
    if (s) {
        s->W = W;
        s->H = H;
        s->hits = malloc((size_t)W * H * sizeof *s->hits);
        s->t = malloc((size_t)W * H * sizeof *s->t);
    }
    if (!s || !tri || !s->hits || !s->t) {
        if (s) { free(s->hits); free(s->t); }
        free(s);
        free(tri);
        snprintf(err, errlen, "out of memory for the depth pass");
        return -1;
    }
    for (size_t i = 0; i < (size_t)W * H; i++) { s->t[i] = INFINITY; s->hits[i].prim = UINT32_MAX; }
    const int threads = ctx->threads > 0 ? ctx->threads : 1;
    for (size_t first = 0; first < sc->n_tris; first += DEPTH_BATCH) {
        const size_t n = sc->n_tris - first < DEPTH_BATCH ? sc->n_tris - first : DEPTH_BATCH;
#pragma omp parallel num_threads(threads)
        {
            const int nt = omp_get_num_threads(), me = omp_get_thread_num();
            const size_t per = (n + (size_t)nt - 1) / (size_t)nt, g0 = per * (size_t)me;
            if (g0 < n) ms_procedural_triangles(sc, first + g0, g0 + per < n ? per : n - g0, tri + 9 * g0);
#pragma omp barrier
            /* one band of rows per thread: each triangle is projected once per thread */
            const int y0 = (int)((long)H * me / nt), y1 = (int)((long)H * (me + 1) / nt);
            for (size_t i = 0; i < n && y0 < y1; i++) depth_triangle(ctx, s, tri + 9 * i, (uint32_t)(first + i), y0, y1);
        }
    }
    free(tri);
    *state = s;
    return 0;
}

static void depth_trace(void *state, const ms_render_ctx *ctx, int x0, int y0, int x1, int y1, ms_hit *out)
{
    (void)ctx;
    const depth_state *s = state;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) *out++ = s->hits[(size_t)y * s->W + x];
}

static void depth_destroy(void *state)
{
    depth_state *s = state;
    if (!s) return;
    free(s->hits);
    free(s->t);
    free(s);
}

const ms_primary_method ms_primary_depth = {
    .name = "depth",
    .create = depth_create,
    .trace = depth_trace,
    .destroy = depth_destroy,
    .streams = 1,
};
