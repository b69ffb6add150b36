/* Seam error (microshadow.h, ms_lightmap.seam_*): what a viewer sees across a chart seam is the lightmap
 * sampled at two different places for one point of the surface; their difference is the seam's line. Edges
 * are matched by their endpoints' exact positions (the loaders keep shared vertices bit-identical). */
#include "bake_seams.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Neighbours within 8 degrees of each other count as one smooth surface (a tessellated sphere's do). */
#define SMOOTH_COS 0.99f

static int unit_normal(const float *t, float n[3])
{
    const float e1[3] = { t[3] - t[0], t[4] - t[1], t[5] - t[2] }, e2[3] = { t[6] - t[0], t[7] - t[1], t[8] - t[2] };
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(l > 0.0f)) return 0;
    for (int d = 0; d < 3; d++) n[d] /= l;
    return 1;
}

typedef struct edge_rec {
    float a[3], b[3];   /* endpoints, a before b in byte order */
    uint32_t tri;
    float ua[2], ub[2]; /* their UVs in tri */
} edge_rec;

static int cmp_edge(const void *x, const void *y)
{
    const edge_rec *p = x, *q = y;
    int c = memcmp(p->a, q->a, sizeof p->a);
    if (!c) c = memcmp(p->b, q->b, sizeof p->b);
    if (!c) c = (p->tri > q->tri) - (p->tri < q->tri);
    return c;
}

/* The largest channel of the irradiance, bilinear at (u, v) with the texel centres at (x + 0.5) / size, clamped. */
static double sample(const ms_frame *f, double u, double v)
{
    const int W = f->width, H = f->height;
    const double x = u * W - 0.5, y = v * H - 0.5;
    const int x0 = (int)floor(x), y0 = (int)floor(y);
    const double fx = x - x0, fy = y - y0;
    double s = 0.0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            const int xx = x0 + i < 0 ? 0 : x0 + i >= W ? W - 1 : x0 + i, yy = y0 + j < 0 ? 0 : y0 + j >= H ? H - 1 : y0 + j;
            const float *c = f->rgb + 3 * ((size_t)yy * W + xx);
            s += (i ? fx : 1 - fx) * (j ? fy : 1 - fy) * fmax(c[0], fmax(c[1], c[2]));
        }
    return s;
}

int ms_bake_seams(const ms_scene *sc, const ms_lightmap *lm, double *mean, double *max, size_t *points)
{
    *mean = *max = 0.0;
    *points = 0;
    const size_t n = sc->n_tris;
    edge_rec *e = malloc((n ? 3 * n : 1) * sizeof *e);
    if (!e) return -1;
    size_t m = 0;
    for (size_t t = 0; t < n; t++) {
        const float *uv = lm->uv + 6 * t;
        int ok = 1;
        for (int k = 0; k < 6 && ok; k++) ok = isfinite(uv[k]);
        if (!ok) continue;
        for (int k = 0; k < 3; k++) {
            const int k2 = (k + 1) % 3;
            const float *p = sc->tri + 9 * t + 3 * k, *q = sc->tri + 9 * t + 3 * k2;
            const int swap = memcmp(p, q, 3 * sizeof(float)) > 0;
            edge_rec *r = &e[m++];
            memcpy(r->a, swap ? q : p, sizeof r->a);
            memcpy(r->b, swap ? p : q, sizeof r->b);
            memcpy(r->ua, uv + 2 * (swap ? k2 : k), sizeof r->ua);
            memcpy(r->ub, uv + 2 * (swap ? k : k2), sizeof r->ub);
            r->tri = (uint32_t)t;
        }
    }
    qsort(e, m, sizeof *e, cmp_edge);
    double fmaxv = 0.0;
    const ms_frame *f = &lm->frame;
    for (size_t i = 0; i < (size_t)f->width * f->height; i++)
        if (f->vis[i] >= 0.0f) fmaxv = fmax(fmaxv, fmax(f->rgb[3 * i], fmax(f->rgb[3 * i + 1], f->rgb[3 * i + 2])));
    double sum = 0.0;
    for (size_t i = 0, j; i < m; i = j) {
        /* the run of records of one edge: a seam only where exactly two triangles meet (manifold) */
        for (j = i + 1; j < m && !memcmp(e[j].a, e[i].a, sizeof e[i].a) && !memcmp(e[j].b, e[i].b, sizeof e[i].b); j++) {}
        if (j - i != 2) continue;
        const edge_rec *x = &e[i], *y = &e[i + 1];
        /* only where the surface goes on smoothly: across a crease the two sides differ by right */
        float na[3], nb[3];
        if (!unit_normal(sc->tri + 9 * (size_t)x->tri, na) || !unit_normal(sc->tri + 9 * (size_t)y->tri, nb) ||
            fabsf(na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2]) < SMOOTH_COS)
            continue;
        if (!memcmp(x->ua, y->ua, sizeof x->ua) && !memcmp(x->ub, y->ub, sizeof x->ub)) continue;   /* one chart */
        for (int k = 0; k < 8; k++) {
            const double s = (k + 0.5) / 8.0;
            const double a = sample(f, x->ua[0] + s * (x->ub[0] - x->ua[0]), x->ua[1] + s * (x->ub[1] - x->ua[1]));
            const double b = sample(f, y->ua[0] + s * (y->ub[0] - y->ua[0]), y->ua[1] + s * (y->ub[1] - y->ua[1]));
            const double d = fmaxv > 0.0 ? fabs(a - b) / fmaxv : 0.0;
            sum += d;
            *max = fmax(*max, d);
            (*points)++;
        }
    }
    if (*points) *mean = sum / (double)*points;
    free(e);
    return 0;
}
