/* A UV set as one object's lightmap layout (uv_validity.h). A layout whose triangles overlap would bake two
 * surfaces into the same texels (tiling texture UVs, mirrored halves sharing one island). A few overlapping
 * triangles (a mirrored rivet on its twin's island) are charted apart and the rest of the layout kept; past
 * 2% of the object's area the layout is dropped whole, as cutting islands apart adds seams (and at some
 * point the charts are xatlas's anyway). The overlap test bins the triangles' UV boxes into a uniform grid
 * over the layout (about one triangle per cell) and tests the pairs that share a cell with the separating
 * axis theorem; triangles that only touch (a shared edge or vertex, or closer than the tolerance) are
 * apart. */
#include "uv_validity.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static double world_area(const float *t)
{
    const double e1[3] = { t[3] - t[0], t[4] - t[1], t[5] - t[2] }, e2[3] = { t[6] - t[0], t[7] - t[1], t[8] - t[2] };
    const double c[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
    return 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

/* Depth of the overlap of two triangles' interiors (the smallest over the six edge normals of the projected
 * intervals' overlap); <= 0 when a separating axis exists. */
static double overlap_depth(const float *a, const float *b)
{
    double depth = INFINITY;
    for (int tri = 0; tri < 2; tri++) {
        const float *t = tri ? b : a;
        for (int k = 0; k < 3; k++) {
            const double ex = (double)t[2 * ((k + 1) % 3)] - t[2 * k], ey = (double)t[2 * ((k + 1) % 3) + 1] - t[2 * k + 1];
            const double len = hypot(ex, ey);
            if (!(len > 0.0)) continue;
            const double nx = -ey / len, ny = ex / len;
            double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY };
            for (int s = 0; s < 2; s++) {
                const float *q = s ? b : a;
                for (int v = 0; v < 3; v++) {
                    const double d = nx * q[2 * v] + ny * q[2 * v + 1];
                    lo[s] = fmin(lo[s], d);
                    hi[s] = fmax(hi[s], d);
                }
            }
            depth = fmin(depth, fmin(hi[0], hi[1]) - fmax(lo[0], lo[1]));
            if (depth <= 0.0) return depth;
        }
    }
    return depth;
}

int ms_uv_layout_valid(const float *pos, const float *set, const uint32_t *tris, size_t n, uint8_t *bad, ms_uv_validity *out)
{
    memset(out, 0, sizeof *out);
    double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY };
    for (size_t i = 0; i < n; i++) {
        const float *u = set + 6 * (size_t)tris[i];
        int ok = 1;
        for (int k = 0; k < 6; k++) ok &= isfinite(u[k]) != 0;
        if (!ok) { out->missing++; continue; }
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 2; d++) { lo[d] = fmin(lo[d], u[2 * k + d]); hi[d] = fmax(hi[d], u[2 * k + d]); }
    }
    if (out->missing || !n) return 0;
    const double ext = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    if (!(ext > 0.0)) { out->degenerate = n; return 0; }
    const double min_area = 1e-12 * (hi[0] - lo[0]) * (hi[1] - lo[1]), eps = 1e-5 * ext;
    uint8_t *deg = calloc(n, 1);
    double *wa = malloc(n * sizeof *wa);
    if (!deg || !wa) { free(deg); free(wa); return -1; }
    for (size_t i = 0; i < n; i++) {
        const float *u = set + 6 * (size_t)tris[i];
        const double a = 0.5 * fabs(((double)u[2] - u[0]) * ((double)u[5] - u[1]) - ((double)u[3] - u[1]) * ((double)u[4] - u[0]));
        wa[i] = world_area(pos + 9 * (size_t)tris[i]);
        out->world_area += wa[i];
        if (a <= min_area) { deg[i] = 1; out->degenerate++; out->degenerate_world_area += wa[i]; }
    }
    /* the grid: about one triangle per cell, at most 1024 cells a side */
    const int g = (int)fmin(1024.0, fmax(1.0, ceil(sqrt((double)n))));
    const double sx = g / fmax(hi[0] - lo[0], 1e-30), sy = g / fmax(hi[1] - lo[1], 1e-30);
    size_t *start = calloc((size_t)g * g + 1, sizeof *start), total = 0;
    int rc = -1;
    uint32_t *list = NULL;
    if (!start) goto out;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i < n; i++) {
            if (deg[i]) continue;
            const float *u = set + 6 * (size_t)tris[i];
            const double ulo = fmin(fmin(u[0], u[2]), u[4]), uhi = fmax(fmax(u[0], u[2]), u[4]);
            const double vlo = fmin(fmin(u[1], u[3]), u[5]), vhi = fmax(fmax(u[1], u[3]), u[5]);
            const int x0 = (int)fmax(0.0, floor((ulo - lo[0]) * sx)), x1 = (int)fmin(g - 1.0, floor((uhi - lo[0]) * sx));
            const int y0 = (int)fmax(0.0, floor((vlo - lo[1]) * sy)), y1 = (int)fmin(g - 1.0, floor((vhi - lo[1]) * sy));
            for (int y = y0; y <= y1; y++)
                for (int x = x0; x <= x1; x++) {
                    const size_t c = (size_t)y * g + x;
                    if (pass == 0) start[c + 1]++;
                    else list[start[c]++] = (uint32_t)i;
                }
        }
        if (pass == 0) {
            for (size_t c = 0; c < (size_t)g * g; c++) start[c + 1] += start[c];
            total = start[(size_t)g * g];
            list = malloc((total ? total : 1) * sizeof *list);
            if (!list) goto out;
        } else   /* the fill advanced every start to its cell's end: shift back */
            for (size_t c = (size_t)g * g; c > 0; c--) start[c] = start[c - 1];
        if (pass == 1) start[0] = 0;
    }
    uint8_t *hit = deg;   /* reused: 2 marks an overlapping triangle */
    const double allowed = 0.02 * out->world_area;
    for (size_t c = 0; c < (size_t)g * g && out->overlapping_world_area + out->degenerate_world_area <= allowed; c++)
        for (size_t p = start[c]; p < start[c + 1]; p++)
            for (size_t q = p + 1; q < start[c + 1]; q++) {
                const uint32_t i = list[p], j = list[q];
                if (hit[i] == 2 && hit[j] == 2) continue;
                if (overlap_depth(set + 6 * (size_t)tris[i], set + 6 * (size_t)tris[j]) > eps) {
                    if (hit[i] != 2) { hit[i] = 2; out->overlapping++; out->overlapping_world_area += wa[i]; }
                    if (hit[j] != 2) { hit[j] = 2; out->overlapping++; out->overlapping_world_area += wa[j]; }
                }
            }
    rc = out->overlapping_world_area + out->degenerate_world_area <= allowed;
    if (bad)
        for (size_t i = 0; i < n; i++) bad[i] = hit[i] != 0;
out:
    free(wa);
    free(start);
    free(list);
    free(deg);
    return rc;
}
