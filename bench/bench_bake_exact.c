/* How exact a bake is where an engine reads it: the lightmap looked up bilinearly (clamped to the point's
 * page) at random points of the baked triangles (uniform over their area), against the irradiance at those
 * points from ms_visibility_points (the same samples, the pattern of the texel the point lies in) times the
 * unshadowed irradiance with the shading normal, summed over the lights: green channel, relative to the
 * lightmap's largest texel on a triangle.
 *
 *   bench_bake_exact SCENE [--size N] [--samples K] [--padding P] [--uv S|xatlas] [--points N] [--seed S]
 *                    [--no-stitch 1]
 *
 * Prints mean, 99th and 99.9th percentiles, worst and how many points exceed 0.05 of the largest texel (and how many
 * of those lie where the irradiance varies by more than that within the cell of the four texels blended: a shadow
 * edge between texel centres or a feature smaller than a texel), and how
 * many lookups read a texel nothing filled. Textured lights are not supported (their bake weighs each texel by
 * the light texels its samples see). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "microshadow.h"
#include "render/shade.h"

static uint64_t next(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static double uniform(uint64_t *s) { return (double)(next(s) >> 11) * 0x1p-53; }

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Green at (u, v) of page p, bilinear, clamped to the page; *unfilled when a tap of weight > 0 has vis < 0,
 * *dilated when one lies off the triangles (filled by dilation); lo, hi: the least and greatest tap of weight > 0. */
static double lookup(const ms_lightmap *lm, int p, double u, double v, int *unfilled, int *dilated, double *lo, double *hi)
{
    const int S = lm->frame.width;
    const double x = u * S - 0.5, y = v * S - 0.5;
    const int x0 = (int)floor(x), y0 = (int)floor(y);
    const double fx = x - x0, fy = y - y0;
    double g = 0.0;
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int q = 0; q < 4; q++) {
        const int i = q & 1, j = q >> 1;
        const int xx = x0 + i < 0 ? 0 : x0 + i >= S ? S - 1 : x0 + i, yy = y0 + j < 0 ? 0 : y0 + j >= S ? S - 1 : y0 + j;
        const double w = (i ? fx : 1 - fx) * (j ? fy : 1 - fy);
        const size_t k = ((size_t)p * S + yy) * S + xx;
        if (w > 0.0 && lm->frame.vis[k] < 0.0f) *unfilled = 1;
        if (w > 0.0 && lm->triangle[k] == MS_NO_TRIANGLE) *dilated = 1;
        g += w * lm->frame.rgb[3 * k + 1];
        if (w > 0.0) {
            *lo = fmin(*lo, lm->frame.rgb[3 * k + 1]);
            *hi = fmax(*hi, lm->frame.rgb[3 * k + 1]);
        }
    }
    return g;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_bake_exact SCENE [--size N] [--samples K] [--padding P] [--uv S|xatlas] [--points N] [--seed S] [--no-stitch 1]\n");
        return 2;
    }
    int size = 1024, samples = 256, padding = 0, uv_set = 1, npts = 20000, no_stitch = 0;
    uint64_t seed = 1;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--size")) size = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--samples")) samples = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--padding")) padding = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--uv")) uv_set = strcmp(argv[i + 1], "xatlas") ? atoi(argv[i + 1]) : -1;
        else if (!strcmp(argv[i], "--points")) npts = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--seed")) seed = (uint64_t)atoll(argv[i + 1]);
        else if (!strcmp(argv[i], "--no-stitch")) no_stitch = atoi(argv[i + 1]);
        else { fprintf(stderr, "bench_bake_exact: unknown option %s\n", argv[i]); return 2; }
    }
    char err[1024] = "";
    ms_scene sc;
    if (ms_scene_load(argv[1], &sc, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 2; }
    size_t nl;
    const ms_light *lights = ms_scene_lights(&sc, &nl);
    for (size_t l = 0; l < nl; l++)
        if (lights[l].texture) { fprintf(stderr, "bench_bake_exact: %s has a textured light\n", argv[1]); return 2; }
    ms_accel *acc;
    if (ms_accel_build(&sc, 0, &acc, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 2; }
    ms_bake_options bo;
    memset(&bo, 0, sizeof bo);
    bo.size = size;
    bo.padding = padding;
    bo.uv_set = uv_set;
    bo.no_seam_stitch = no_stitch;
    bo.points.samples = samples;
    ms_lightmap lm;
    if (ms_bake(&sc, acc, &bo, &lm, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 2; }
    /* the points: triangles by world area, among the baked ones */
    double *cum = malloc(sc.n_tris * sizeof *cum), total = 0.0, emax = 0.0;
    float *pos = malloc((size_t)npts * 3 * sizeof *pos), *nrm = malloc((size_t)npts * 3 * sizeof *nrm);
    float *shade_n = malloc((size_t)npts * 3 * sizeof *shade_n), *S = malloc((size_t)npts * sizeof *S);
    double *uvp = malloc((size_t)npts * 2 * sizeof *uvp), *want = calloc((size_t)npts, sizeof *want), *d = malloc((size_t)npts * sizeof *d);
    uint32_t *tri = malloc((size_t)npts * sizeof *tri), *key = malloc((size_t)npts * 2 * sizeof *key);
    if (!cum || !pos || !nrm || !shade_n || !S || !uvp || !want || !d || !tri || !key) { fprintf(stderr, "out of memory\n"); return 2; }
    for (size_t t = 0; t < sc.n_tris; t++) {
        const float *v = sc.tri + 9 * t;
        const double e1[3] = { v[3] - v[0], v[4] - v[1], v[5] - v[2] }, e2[3] = { v[6] - v[0], v[7] - v[1], v[8] - v[2] };
        const double c[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
        const int baked = isfinite(lm.uv[6 * t]);
        total += baked ? 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) : 0.0;
        cum[t] = total;
    }
    for (size_t i = 0; i < (size_t)size * size * (size_t)lm.pages; i++)
        if (lm.triangle[i] != MS_NO_TRIANGLE) emax = fmax(emax, lm.frame.rgb[3 * i + 1]);
    for (int i = 0; i < npts; i++) {
        const double r = uniform(&seed) * total;
        size_t lo = 0, hi = sc.n_tris - 1;
        while (lo < hi) { const size_t m = (lo + hi) / 2; if (cum[m] < r) lo = m + 1; else hi = m; }
        const size_t t = lo;
        double a = uniform(&seed), b = uniform(&seed);
        if (a + b > 1.0) { a = 1.0 - a; b = 1.0 - b; }
        const float w[3] = { (float)(1.0 - a - b), (float)a, (float)b };
        const float *v = sc.tri + 9 * t;
        float ng[3];
        const float e1[3] = { v[3] - v[0], v[4] - v[1], v[5] - v[2] }, e2[3] = { v[6] - v[0], v[7] - v[1], v[8] - v[2] };
        ng[0] = e1[1] * e2[2] - e1[2] * e2[1];
        ng[1] = e1[2] * e2[0] - e1[0] * e2[2];
        ng[2] = e1[0] * e2[1] - e1[1] * e2[0];
        const float len = sqrtf(ng[0] * ng[0] + ng[1] * ng[1] + ng[2] * ng[2]);
        for (int k = 0; k < 3; k++) ng[k] /= len;
        float ns[3] = { ng[0], ng[1], ng[2] };
        if (ms_interpolated_normal(&sc, t, w, ns) && ns[0] * ng[0] + ns[1] * ng[1] + ns[2] * ng[2] < 0.0f)
            for (int k = 0; k < 3; k++) ns[k] = -ns[k];
        for (int k = 0; k < 3; k++) {
            const double p = w[0] * v[k] + w[1] * v[3 + k] + w[2] * v[6 + k];
            pos[3 * i + k] = (float)(p + sc.origin[k]);
            nrm[3 * i + k] = ng[k];
            shade_n[3 * i + k] = ns[k];
        }
        for (int k = 0; k < 2; k++)
            uvp[2 * i + k] = w[0] * lm.uv[6 * t + k] + w[1] * lm.uv[6 * t + 2 + k] + w[2] * lm.uv[6 * t + 4 + k];
        const uint32_t page = lm.page ? lm.page[t] : 0;
        key[2 * i] = (uint32_t)fmin(uvp[2 * i] * size, size - 1.0);
        key[2 * i + 1] = page * (uint32_t)size + (uint32_t)fmin(uvp[2 * i + 1] * size, size - 1.0);
        tri[i] = (uint32_t)t;
    }
    const ms_points pts = { (size_t)npts, pos, nrm, tri, key };
    ms_points_options po;
    memset(&po, 0, sizeof po);
    po.samples = samples;
    size_t nal;
    const ms_light *al = ms_accel_lights(acc, &nal);
    for (size_t l = 0; l < nal; l++) {
        if (ms_visibility_points(acc, &al[l], &pts, &po, NULL, S, NULL, NULL, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 2; }
        for (int i = 0; i < npts; i++) {
            float p[3];
            for (int k = 0; k < 3; k++) p[k] = (float)(pos[3 * i + k] - sc.origin[k]);
            want[i] += ms_light_irradiance(&lights[l], p, shade_n + 3 * i) * S[i] * lights[l].emission.y;
        }
    }
    /* the largest texel depends on where the layout's texel centres fall (a hot spot a texel misses halves it on
     * Sibenik); the points' own largest irradiance does not: both are given */
    double wmax = 0.0, sum_w = 0.0;
    for (int i = 0; i < npts; i++) wmax = fmax(wmax, want[i]);
    int unfilled = 0, dilated = 0, above_edge = 0;
    double sum = 0.0, sum_dilated = 0.0;
    for (int i = 0; i < npts; i++) {
        int u = 0, dl = 0;
        double lo, hi;
        const double g = lookup(&lm, lm.page ? (int)lm.page[tri[i]] : 0, uvp[2 * i], uvp[2 * i + 1], &u, &dl, &lo, &hi);
        unfilled += u;
        dilated += dl;
        d[i] = fabs(g - want[i]) / emax;
        /* Where the irradiance varies by more than 0.05 within the cell of the four texels the lookup blends (they
         * differ by more, or the point differs from all of them by more): a shadow edge between texel centres or a
         * feature smaller than a texel, which no bilinear ramp between exact texels follows. */
        const double vary = 0.05 * emax;
        if (d[i] > 0.05 && (hi - lo > vary || want[i] < lo - vary || want[i] > hi + vary)) above_edge++;
        sum += d[i];
        sum_dilated += dl ? d[i] : 0.0;
        sum_w += fabs(g - want[i]) / wmax;
    }
    qsort(d, (size_t)npts, sizeof *d, cmp_double);
    int above = 0;
    for (int i = 0; i < npts; i++) above += d[i] > 0.05;
    printf("%s: %dx%d, %d pages, padding %d%s, fill %.1f%%, %d points: |lookup - points API| / largest texel: mean %.5f, "
           "p99 %.5f, p99.9 %.5f, worst %.5f, %d above 0.05 (%d of them where the irradiance varies by more than 0.05 within the "
           "cell of the four texels blended) (mean %.5f of the points' largest); %d lookups read an unfilled "
           "texel; %d read a dilated one (their mean %.5f)\n",
           argv[1], size, size, lm.pages, padding, no_stitch ? ", not stitched" : "", 100.0 * lm.page_fill[0], npts, sum / npts,
           d[(size_t)(0.99 * (npts - 1))], d[(size_t)(0.999 * (npts - 1))], d[npts - 1], above, above_edge, sum_w / npts, unfilled, dilated,
           dilated ? sum_dilated / dilated : 0.0);
    ms_lightmap_free(&lm);
    ms_accel_free(acc);
    ms_scene_free(&sc);
    free(cum); free(pos); free(nrm); free(shade_n); free(S); free(uvp); free(want); free(d); free(tri); free(key);
    return 0;
}
