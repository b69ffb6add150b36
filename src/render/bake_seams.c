/* Chart seams (microshadow.h, ms_lightmap.seam_*): what a viewer sees across a chart seam is the lightmap
 * sampled at two different places for one point of the surface; their difference is the seam's line. Edges
 * are matched by their endpoints' exact positions (the loaders keep shared vertices bit-identical). */
#include "bake_seams.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Without shading normals, neighbours within 8 degrees of each other count as one smooth surface (a
 * tessellated sphere's do). With them, the two sides' normals must be the same NORMAL: within about 0.8
 * degrees, so that float noise in a file's duplicated seam vertices does not make a hard edge. */
#define SMOOTH_COS 0.99f
#define SAME_NORMAL_COS 0.9999f

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

static float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

typedef struct edge_rec {
    float a[3], b[3];   /* endpoints, a before b in byte order */
    uint32_t tri;
    uint8_t ka, kb;     /* their vertex indices in tri */
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

/* Triangle t's unit shading normal at vertex k, or 0 when its mesh has none there. */
static int shading_normal(const ms_scene *sc, uint32_t t, int k, float n[3])
{
    if (!sc->tri_normal) return 0;
    const float *v = sc->tri_normal + 9 * (size_t)t + 3 * k;
    const float l = sqrtf(dot3(v, v));
    if (!(l > 0.0f) || !isfinite(l)) return 0;
    for (int d = 0; d < 3; d++) n[d] = v[d] / l;
    return 1;
}

static int smooth_edge(const ms_scene *sc, const edge_rec *x, const edge_rec *y)
{
    float na[3], nb[3], sa[3], sb[3], ta[3], tb[3];
    if (!unit_normal(sc->tri + 9 * (size_t)x->tri, na) || !unit_normal(sc->tri + 9 * (size_t)y->tri, nb)) return 0;
    if (shading_normal(sc, x->tri, x->ka, sa) && shading_normal(sc, x->tri, x->kb, ta) && shading_normal(sc, y->tri, y->ka, sb) &&
        shading_normal(sc, y->tri, y->kb, tb))
        return dot3(sa, sb) >= SAME_NORMAL_COS && dot3(ta, tb) >= SAME_NORMAL_COS;
    return dot3(na, nb) >= SMOOTH_COS;
}

int ms_bake_seam_list(const ms_scene *sc, const float *uv, ms_seam **seams, size_t *count)
{
    *seams = NULL;
    *count = 0;
    const size_t n = sc->n_tris;
    edge_rec *e = malloc((n ? 3 * n : 1) * sizeof *e);
    if (!e) return -1;
    size_t m = 0;
    for (size_t t = 0; t < n; t++) {
        const float *u = uv + 6 * t;
        int ok = 1;
        for (int k = 0; k < 6 && ok; k++) ok = isfinite(u[k]);
        if (!ok) continue;
        for (int k = 0; k < 3; k++) {
            const int k2 = (k + 1) % 3;
            const float *p = sc->tri + 9 * t + 3 * k, *q = sc->tri + 9 * t + 3 * k2;
            const int swap = memcmp(p, q, 3 * sizeof(float)) > 0;
            edge_rec *r = &e[m++];
            memcpy(r->a, swap ? q : p, sizeof r->a);
            memcpy(r->b, swap ? p : q, sizeof r->b);
            r->ka = (uint8_t)(swap ? k2 : k);
            r->kb = (uint8_t)(swap ? k : k2);
            memcpy(r->ua, u + 2 * r->ka, sizeof r->ua);
            memcpy(r->ub, u + 2 * r->kb, sizeof r->ub);
            r->tri = (uint32_t)t;
        }
    }
    qsort(e, m, sizeof *e, cmp_edge);
    size_t cap = 0;
    int rc = 0;
    for (size_t i = 0, j; i < m && !rc; i = j) {
        /* the run of records of one edge: a seam only where exactly two triangles meet (manifold) */
        for (j = i + 1; j < m && !memcmp(e[j].a, e[i].a, sizeof e[i].a) && !memcmp(e[j].b, e[i].b, sizeof e[i].b); j++) {}
        if (j - i != 2) continue;
        const edge_rec *x = &e[i], *y = &e[i + 1];
        if (!memcmp(x->a, x->b, sizeof x->a)) continue;   /* a degenerate edge */
        if (!memcmp(x->ua, y->ua, sizeof x->ua) && !memcmp(x->ub, y->ub, sizeof x->ub)) continue;   /* one chart */
        if (!smooth_edge(sc, x, y)) continue;
        if (*count == cap) {
            cap = cap ? 2 * cap : 256;
            ms_seam *grown = realloc(*seams, cap * sizeof **seams);
            if (!grown) { rc = -1; break; }
            *seams = grown;
        }
        ms_seam *s = &(*seams)[(*count)++];
        memcpy(s->a0, x->ua, sizeof s->a0);
        memcpy(s->a1, x->ub, sizeof s->a1);
        memcpy(s->b0, y->ua, sizeof s->b0);
        memcpy(s->b1, y->ub, sizeof s->b1);
    }
    free(e);
    if (rc) { free(*seams); *seams = NULL; *count = 0; }
    return rc;
}

double ms_seam_len_texels(const ms_seam *s, int width, int height)
{
    const double la = hypot(((double)s->a1[0] - s->a0[0]) * width, ((double)s->a1[1] - s->a0[1]) * height);
    const double lb = hypot(((double)s->b1[0] - s->b0[0]) * width, ((double)s->b1[1] - s->b0[1]) * height);
    return fmax(la, lb);
}

int ms_seam_samples(double len_texels, int per_texel)
{
    const double k = ceil(len_texels * per_texel);
    return k < 1.0 ? 1 : k > 1e6 ? 1000000 : (int)k;
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

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int ms_bake_seams(const ms_frame *f, const ms_seam *seams, size_t n, ms_seam_error *out)
{
    memset(out, 0, sizeof *out);
    size_t total = 0;
    for (size_t i = 0; i < n; i++) total += (size_t)ms_seam_samples(ms_seam_len_texels(&seams[i], f->width, f->height), 2);
    if (!total) return 0;
    double *d = malloc(total * sizeof *d);
    if (!d) return -1;
    double fmaxv = 0.0;
    for (size_t i = 0; i < (size_t)f->width * f->height; i++)
        if (f->vis[i] >= 0.0f) fmaxv = fmax(fmaxv, fmax(f->rgb[3 * i], fmax(f->rgb[3 * i + 1], f->rgb[3 * i + 2])));
    size_t k = 0;
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        const ms_seam *s = &seams[i];
        const int ns = ms_seam_samples(ms_seam_len_texels(s, f->width, f->height), 2);
        for (int j = 0; j < ns; j++) {
            const double t = (j + 0.5) / ns;
            const double a = sample(f, s->a0[0] + t * (s->a1[0] - s->a0[0]), s->a0[1] + t * (s->a1[1] - s->a0[1]));
            const double b = sample(f, s->b0[0] + t * (s->b1[0] - s->b0[0]), s->b0[1] + t * (s->b1[1] - s->b0[1]));
            d[k] = fmaxv > 0.0 ? fabs(a - b) / fmaxv : 0.0;
            sum += d[k++];
        }
    }
    qsort(d, total, sizeof *d, cmp_double);
    out->points = total;
    out->mean = sum / (double)total;
    out->p99 = d[(size_t)(0.99 * (double)(total - 1))];
    out->max = d[total - 1];
    free(d);
    return 0;
}
