/* Triangle setup shared by every micro-rasterization kernel (Woop 2010, sec. 3), and the internal
 * entry points of the kernel variants. Header-only (static inline) so that each ISA variant compiles
 * the setup with its own instruction set.
 *
 * Coordinates: the frame maps world X to light-index space m * (X - c): C at the origin, sample (i,j)
 * at (i, j, 1), z = segment parameter. An edge equation e covers the homogeneous point (x, y, 1) when
 * e . (x, y, 1) = e[0]*x + e[1]*y + e[2] >= 0; a sample is occluded when every active edge covers it. */
#ifndef MS_RASTER_INTERNAL_H
#define MS_RASTER_INTERNAL_H
#include <math.h>
#include <stdint.h>
#include "raster.h"
#include "core/perk.h"
#include "core/vec.h"

typedef struct ms_tri_setup {
    float e[5][3]; /* active edges: U, V, W always, then N and/or F when the triangle reaches a clip plane */
    int n;         /* number of active edges, 3..5 */
    int x0, x1;    /* conservative column range, inclusive, within [0, k-1] */
    int y0, y1;    /* conservative scanline range, inclusive, within [0, k-1] */
} ms_tri_setup;

/* Slack (in sample units) added to the projected bounding box: the box only prunes work, the edge
 * equations decide, so widening it keeps rounding in the projection from ever dropping a sample. */
#define MS_BOX_SLACK 1e-3f

/* Relative bound (16 ulps) on the rounding of a light-space depth z = m[2] . (P - C), in units of its
 * terms' magnitudes. At grazing light angles z is a small difference of large terms; depth decisions
 * (rejection, which clip edges) are taken on z widened by this bound, so that they err towards clipping:
 * an unneeded clip edge changes nothing, a missing one occludes samples behind the near plane. */
#define MS_Z_REL 1e-6f

static inline float ms_clampf(float x, float lo, float hi) { return ms_minf(ms_maxf(x, lo), hi); }

/* Float to int for values already clamped to a small range (never NaN, never out of int range). Exact:
 * truncation, then one step where it went the wrong way ((float)t is exact for |t| < 2^24). Not
 * ceilf/floorf: without SSE4.1 (portable files) they are library calls. */
static inline int ms_ceil_i(float x) { const int t = (int)x; return t + ((float)t < x); }
static inline int ms_floor_i(float x) { const int t = (int)x; return t - ((float)t > x); }

/* Triangle setup. Returns 0 when the triangle cannot occlude any sample (degenerate, culled, outside the
 * near/far range or outside the buffer), 1 otherwise with s filled in. */
static inline int ms_tri_setup_run(const ms_raster_frame *f, const float tri[9], ms_tri_setup *s)
{
    const int k = f->k;
    /* World vectors from C: a[i] = P_i - C, and the world edges w[i] = P[i+2] - P[i+1] (opposite vertex
     * i), exact for close vertices (Sterbenz), so they keep their full relative precision however far
     * the triangle is from C. v[i] = m a[i], the light-index coordinates, serve the depth range and the
     * projected box only. */
    float a[3][3], w[3][3], v[3][3];
    for (int i = 0; i < 3; i++) {
        const float *p = tri + 3 * i, *q = tri + 3 * ((i + 1) % 3), *r = tri + 3 * ((i + 2) % 3);
        for (int j = 0; j < 3; j++) { a[i][j] = p[j] - f->c[j]; w[i][j] = r[j] - q[j]; }
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) v[i][j] = f->m[j][0] * a[i][0] + f->m[j][1] * a[i][1] + f->m[j][2] * a[i][2];
    float zlo[3], zhi[3];
    for (int i = 0; i < 3; i++) {
        const float zerr = (fabsf(f->m[2][0]) * fabsf(a[i][0]) + fabsf(f->m[2][1]) * fabsf(a[i][1]) +
                            fabsf(f->m[2][2]) * fabsf(a[i][2])) * MS_Z_REL;
        zlo[i] = v[i][2] - zerr;
        zhi[i] = v[i][2] + zerr;
    }
    const float zmin = ms_minf(ms_minf(zlo[0], zlo[1]), zlo[2]);
    const float zmax = ms_maxf(ms_maxf(zhi[0], zhi[1]), zhi[2]);
    /* Every point of the triangle has z in [zmin, zmax]: nothing between near and far, nothing to do.
     * The negated form also rejects NaN coordinates. */
    if (!(zmax >= f->near && zmin <= f->far)) return 0;

    /* Edge equations U = V1 x V2, V = V2 x V0, W = V0 x V1 (sec. 3, eqs. 1-3), by the identity
     * (m A) x (m B) = det(m) M^T (A x B): the cross product of world vectors from C, carried to light
     * space by the rows of M^T (ds, dt, p0 - C), and the common factor det(m) dropped (the winding flip
     * below absorbs its sign). Departure: the paper crosses light-space vertices. When C sees the light
     * at a grazing angle m is ill-conditioned (entries of 1e3 and more), light-space vertices reach 1e4
     * and their cross products cancel to a relative error of 1e-3: whole rows of samples went wrong.
     * The world route makes each coefficient a plain dot product, and an edge's value at sample (i, j)
     * u . (S_ij - C) up to rounding, whatever the frame's condition.
     * The triangle (C, P_a, P_b) has three sides A, B and E = B - A, and A x B = A x E = B x E; the
     * rounding error of a cross product is eps times the product of its operands' lengths, so we take
     * the two shortest sides: A x B loses everything for a small triangle far from C (nearly parallel
     * A, B), and A x E for a vertex next to C. */
    float len2[3], elen2[3];
    for (int i = 0; i < 3; i++) {
        len2[i] = a[i][0] * a[i][0] + a[i][1] * a[i][1] + a[i][2] * a[i][2];
        elen2[i] = w[i][0] * w[i][0] + w[i][1] * w[i][1] + w[i][2] * w[i][2];
    }
    float (*e)[3] = s->e;
    for (int i = 0; i < 3; i++) {
        const int ia = (i + 1) % 3, ib = (i + 2) % 3;
        const int va_longest = len2[ia] >= len2[ib] && len2[ia] >= elen2[i];
        const int e_longest = !va_longest && elen2[i] >= len2[ib];
        const float *x = va_longest ? a[ib] : a[ia];
        const float *y = e_longest ? a[ib] : w[i];
        const float u[3] = { x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0] };
        for (int r = 0; r < 3; r++) e[i][r] = f->mt[r][0] * u[0] + f->mt[r][1] * u[1] + f->mt[r][2] * u[2];
    }
    /* U+V+W is M^T of the plane normal E1 x E2 = E2 x E0 = E0 x E1, from the two shortest edges (a
     * sliver's two long edges are nearly parallel). D = det(V0, V1, V2) = det(m) (P_i - C) . normal for
     * any i, with the same factor det(m) dropped: the vertex nearest C rounds least. */
    const int long_i = elen2[0] >= elen2[1] ? (elen2[0] >= elen2[2] ? 0 : 2) : (elen2[1] >= elen2[2] ? 1 : 2);
    const float *sa = w[(long_i + 1) % 3], *sb = w[(long_i + 2) % 3];
    const float nw[3] = { sa[1] * sb[2] - sa[2] * sb[1], sa[2] * sb[0] - sa[0] * sb[2], sa[0] * sb[1] - sa[1] * sb[0] };
    const int near_i = len2[0] <= len2[1] ? (len2[0] <= len2[2] ? 0 : 2) : (len2[1] <= len2[2] ? 1 : 2);
    float d = a[near_i][0] * nw[0] + a[near_i][1] * nw[1] + a[near_i][2] * nw[2];
    if (!(d != 0.0f)) return 0; /* the plane of the triangle contains C (or it has no area) */
    /* d is the world D = det(P0 - C, P1 - C, P2 - C): positive when the triangle faces away from C. */
    if (f->cull_backfaces && d > 0.0f) return 0;
    float sn[3];
    for (int r = 0; r < 3; r++) sn[r] = f->mt[r][0] * nw[0] + f->mt[r][1] * nw[1] + f->mt[r][2] * nw[2];
    if (d < 0.0f) {
        /* Two-sided: flip the winding rather than discard (the paper culls D <= 0). */
        for (int i = 0; i < 3; i++)
            for (int r = 0; r < 3; r++) e[i][r] = -e[i][r];
        d = -d;
        sn[0] = -sn[0]; sn[1] = -sn[1]; sn[2] = -sn[2];
    }
    int n = 3;
    /* Clip edges (eqs. 7-8): N = (0,0,D) - near (U+V+W), F = far (U+V+W) - (0,0,D). Each is needed only
     * when the triangle reaches its plane: the hit point is a convex combination of the vertices, so
     * zmin >= near already implies n >= 0 wherever u, v, w >= 0 (and likewise for far). */
    if (zmin < f->near) {
        e[n][0] = -f->near * sn[0]; e[n][1] = -f->near * sn[1]; e[n][2] = d - f->near * sn[2];
        n++;
    }
    if (zmax > f->far) {
        e[n][0] = f->far * sn[0]; e[n][1] = f->far * sn[1]; e[n][2] = f->far * sn[2] - d;
        n++;
    }
    s->n = n;

    /* Conservative sample range (sec. 4): the bounding box of the projected vertices when the triangle
     * lies in front of C; all of the buffer when it crosses the z = 0 plane (its projection is then
     * unbounded or wraps through infinity). */
    const float kmax = (float)(k - 1);
    if (zmin > 0.0f) {
        float xs[3], ys[3];
        for (int i = 0; i < 3; i++) {
            const float inv = 1.0f / v[i][2];
            xs[i] = v[i][0] * inv;
            ys[i] = v[i][1] * inv;
        }
        const float xlo = ms_minf(ms_minf(xs[0], xs[1]), xs[2]) - MS_BOX_SLACK;
        const float xhi = ms_maxf(ms_maxf(xs[0], xs[1]), xs[2]) + MS_BOX_SLACK;
        const float ylo = ms_minf(ms_minf(ys[0], ys[1]), ys[2]) - MS_BOX_SLACK;
        const float yhi = ms_maxf(ms_maxf(ys[0], ys[1]), ys[2]) + MS_BOX_SLACK;
        /* Clamp before converting: projections can be huge (z close to 0). */
        s->x0 = ms_ceil_i(ms_clampf(xlo, -1.0f, kmax + 1.0f));
        s->x1 = ms_floor_i(ms_clampf(xhi, -1.0f, kmax + 1.0f));
        s->y0 = ms_ceil_i(ms_clampf(ylo, -1.0f, kmax + 1.0f));
        s->y1 = ms_floor_i(ms_clampf(yhi, -1.0f, kmax + 1.0f));
        if (s->x0 < 0) s->x0 = 0;
        if (s->y0 < 0) s->y0 = 0;
        if (s->x1 > k - 1) s->x1 = k - 1;
        if (s->y1 > k - 1) s->y1 = k - 1;
        if (s->x0 > s->x1 || s->y0 > s->y1) return 0;
    } else {
        s->x0 = 0; s->x1 = k - 1;
        s->y0 = 0; s->y1 = k - 1;
    }
    return 1;
}

/* Per-sample edge test shared by Bounds and Hierarchical (same expression, same rounding). */
static inline float ms_edge_eval(const float e[3], float x, float y) { return e[0] * x + (e[1] * y + e[2]); }

/* Scanline setup (sec. 4, eq. 10): each edge with e_x != 0 becomes a bound on x, a*y + b, lower when
 * e_x > 0 and upper when e_x < 0. Edges parallel to the x axis bound y instead and go into [y0, y1]. */
typedef struct ms_scan_setup {
    float al[5], bl[5]; /* lower bounds: x >= al*y + bl */
    float au[5], bu[5]; /* upper bounds: x <= au*y + bu */
    int nl, nu;
    int y0, y1;
} ms_scan_setup;

/* An edge counts as parallel to x when e_x * k changes it by less than 2^-20 of its larger other
 * coefficient over the whole buffer: it then differs from the exact test only for samples within a
 * relative 1e-6 of the edge, a tie; and every slope kept stays below 2^20 k (finite, no overflow). */
#define MS_FLAT_EDGE (1.0f / 1048576.0f)

static inline int ms_scan_setup_run(const ms_raster_frame *f, const ms_tri_setup *t, ms_scan_setup *s)
{
    const int k = f->k;
    const float kf = (float)k;
    int nl = 0, nu = 0, y0 = t->y0, y1 = t->y1;
    for (int i = 0; i < t->n; i++) {
        const float ex = t->e[i][0], ey = t->e[i][1], ez = t->e[i][2];
        const float ax = fabsf(ex) * kf, ay = fabsf(ey) * kf, az = fabsf(ez);
        if (ax > MS_FLAT_EDGE * ms_maxf(ay, az)) {
            const float r = -1.0f / ex;
            if (ex > 0.0f) { s->al[nl] = ey * r; s->bl[nl] = ez * r; nl++; }
            else           { s->au[nu] = ey * r; s->bu[nu] = ez * r; nu++; }
        } else if (ay > MS_FLAT_EDGE * az) {
            /* The paper tilts such an edge slightly (a possible light leak); bounding y is exact. */
            const float yb = ms_clampf(-ez / ey, -1.0f, kf);
            if (ey > 0.0f) { const int c = ms_ceil_i(yb); if (c > y0) y0 = c; }
            else           { const int c = ms_floor_i(yb); if (c < y1) y1 = c; }
        } else if (ez < 0.0f) {
            return 0; /* constant and negative on the whole buffer */
        }
    }
    s->nl = nl; s->nu = nu;
    s->y0 = y0; s->y1 = y1;
    return y0 <= y1;
}

/* The SIMD setups' rare path for edges parallel to the scanlines: lane i of yv is the clamped y where
 * edge i crosses zero, a lower bound on y where bit i of up is set, an upper bound where bit i of dn is;
 * they narrow [*y0, *y1], then clamped to the buffer. */
static inline void ms_flat_y_bounds(const float yv[8], unsigned up, unsigned dn, int k, int *y0, int *y1)
{
    for (int i = 0; i < 5; i++) {
        if (up >> i & 1) { const int c = ms_ceil_i(yv[i]); if (c > *y0) *y0 = c; }
        if (dn >> i & 1) { const int c = ms_floor_i(yv[i]); if (c < *y1) *y1 = c; }
    }
    if (*y0 < 0) *y0 = 0;
    if (*y1 > k - 1) *y1 = k - 1;
}

/* Per-triangle data of the SIMD Scanline kernel's row loop (scanline_simd_impl.h): for each of the (up
 * to) five edges a lower and an upper bound a*y + b on x, neutral (0 resp. k-1) where the edge is not of
 * that kind, and the scanline range. The rows evaluate 3 edge lanes, or 5 when a clip edge is active. */
typedef struct ms_scan_vec {
    float al[8], bl[8], au[8], bu[8];
    int y0, y1;
} ms_scan_vec;

/* The same data for sixteen set-ups side by side (the block traversal's lanes: pixels, or (triangle, pixel)
 * pairs): edge e of lane l at al[e][l] etc.; edges 3 and 4 the near and far clip edges. */
#define MS_SCAN_LANES 16
typedef struct ms_scan_lanes {
    float al[5][MS_SCAN_LANES], bl[5][MS_SCAN_LANES], au[5][MS_SCAN_LANES], bu[5][MS_SCAN_LANES];
    int32_t y0[MS_SCAN_LANES], y1[MS_SCAN_LANES];
} ms_scan_lanes;

/* The SIMD Scanline kernel's row loop for lane `lane` of v over `edges` edge lanes (3: no clip edge; 5:
 * edges 3 and 4 are the near and far clip edges, the constant edge where one is not needed), for a caller
 * that computed the set-up itself with the kernel's operations (the block traversal: one triangle for
 * many pixels at once, block_raster_impl.h): the buffer is then the kernel's bit for bit. NULL when
 * `kernel` is not a SIMD Scanline instance for k (the portable kernels round their rows differently). */
typedef void (*ms_scan_rows_fn)(const ms_scan_lanes *v, int lane, void *buf);
ms_scan_rows_fn ms_raster_rows(ms_raster_fn kernel, int k, int edges);

/* The kernel instances (core/perk.h names): portable Scanline, Bounds, Hierarchical; SIMD Scanline for
 * AVX2 + FMA (8 scanlines per instruction) and AVX-512 (16), one source: scanline_simd_impl.h. */
#define MS_RASTER_PARAMS (const ms_raster_frame *f, const float tri[9], void *buf)
MS_PERK_DECLARE(void, ms_scanline, scalar, MS_RASTER_PARAMS);
MS_PERK_DECLARE(void, ms_bounds, scalar, MS_RASTER_PARAMS);
MS_PERK_DECLARE(void, ms_hier, scalar, MS_RASTER_PARAMS);
MS_PERK_DECLARE(void, ms_scanline, avx2, MS_RASTER_PARAMS);
MS_PERK_DECLARE(void, ms_scanline, avx512, MS_RASTER_PARAMS);
/* Bounds and Hierarchical compiled for AVX2 and AVX-512 (bounds_avx2.c, bounds_avx512.c): bit for bit the
 * scalar ones. */
MS_PERK_DECLARE(void, ms_bounds, avx2, MS_RASTER_PARAMS);
MS_PERK_DECLARE(void, ms_hier, avx2, MS_RASTER_PARAMS);
MS_PERK_DECLARE(void, ms_bounds, avx512, MS_RASTER_PARAMS);
MS_PERK_DECLARE(void, ms_hier, avx512, MS_RASTER_PARAMS);
MS_PERK_DECLARE(void, ms_clear_halfplane, scalar, (const float e[3], void *buf));
MS_PERK_DECLARE(void, ms_scanline_rows3, avx2, (const ms_scan_lanes *v, int lane, void *buf));
MS_PERK_DECLARE(void, ms_scanline_rows3, avx512, (const ms_scan_lanes *v, int lane, void *buf));
MS_PERK_DECLARE(void, ms_scanline_rows5, avx2, (const ms_scan_lanes *v, int lane, void *buf));
MS_PERK_DECLARE(void, ms_scanline_rows5, avx512, (const ms_scan_lanes *v, int lane, void *buf));

/* For the benchmark's cost fit: the scanlines the scalar Scanline kernel iterates for this triangle
 * (0 when setup rejects it). */
int ms_scanline_rows(const ms_raster_frame *f, const float tri[9]);

#endif
