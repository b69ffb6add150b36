/* The node tests of the scalar and AVX2 frustum traversals, instantiated per k through core/perk_each.h
 * (MS_K, MS_WORD) by frustum_traverse_scalar.c and frustum_traverse_avx2.c; the loop is
 * frustum_traverse_loop.h. The corners are computed with AVX2 only in the file that targets it
 * (MS_TARGET_AVX2), with the same roundings as the portable code.
 *
 * The traversal works in the pixel's light-index space (the kernel's frame: C at the origin, sample
 * (i,j) at (i,j,1)), where the frustum from C to the samples is 0 <= x <= (k-1)z, 0 <= y <= (k-1)z,
 * near <= z <= far. The paper culls BVH nodes against the frustum planes in world space; these are the
 * same planes, written where they are axis-aligned. A node's 8 corners are transformed once (a base
 * corner plus the three transformed box edges) and serve three tests:
 *   - frustum: all corners outside one of the half-spaces;
 *   - coverage: when the box lies in front of C its projection is the hull of its projected corners;
 *     if that holds no sample, or only samples already occluded (the rows it spans tested against the
 *     buffer), nothing below it can change V;
 *   - order: the nearer child (smaller z: the larger projection) is visited first, so that large
 *     occluders fill the buffer early and the coverage test and the umbra early-out fire sooner. */
#include <math.h>
#ifdef MS_TARGET_AVX2
#include <immintrin.h>
#endif


#ifndef MS_TRAV_COMMON
#define MS_TRAV_COMMON
typedef struct ms_node_view {
    float x0, x1, y0, y1;   /* projected bounds in sample units (valid when in_front) */
    float zmin;
    int outside;            /* culled by the frustum */
    int in_front;           /* every corner has z > 0 */
} ms_node_view;
/* The loop's per-pixel constants (the frame) and what a pushed node keeps (its view). */
typedef struct ms_ft_ctx { const ms_raster_frame *f; } ms_ft_ctx;
#define FT_CTX ms_ft_ctx
#define FT_SAVED ms_node_view
#endif

static inline void MS_KFN(view_node)(const ms_raster_frame *f, const ms_bvh_node *n, ms_node_view *v)
{
    float rel[3], e[3], base[3], col[3][3];
    for (int a = 0; a < 3; a++) { rel[a] = n->bmin[a] - f->c[a]; e[a] = n->bmax[a] - n->bmin[a]; }
    for (int r = 0; r < 3; r++) {
        base[r] = f->m[r][0] * rel[0] + f->m[r][1] * rel[1] + f->m[r][2] * rel[2];
        for (int a = 0; a < 3; a++) col[a][r] = f->m[r][a] * e[a];
    }
    const float hi = (float)(MS_K - 1) + MS_TRAV_SIDE_SLACK;
#ifdef MS_TARGET_AVX2
    /* The 8 corners in one register per coordinate. */
    const __m256 bx = _mm256_setr_ps(0, 1, 0, 1, 0, 1, 0, 1), by = _mm256_setr_ps(0, 0, 1, 1, 0, 0, 1, 1),
                 bz = _mm256_setr_ps(0, 0, 0, 0, 1, 1, 1, 1);
    __m256 c[3];
    for (int r = 0; r < 3; r++)
        c[r] = _mm256_fmadd_ps(bz, _mm256_set1_ps(col[2][r]),
                               _mm256_fmadd_ps(by, _mm256_set1_ps(col[1][r]),
                                               _mm256_fmadd_ps(bx, _mm256_set1_ps(col[0][r]), _mm256_set1_ps(base[r]))));
    const __m256 xs = c[0], ys = c[1], zs = c[2];
    const __m256 az = _mm256_mul_ps(_mm256_andnot_ps(_mm256_set1_ps(-0.0f), zs), _mm256_set1_ps(MS_TRAV_SIDE_SLACK));
    const __m256 naz = _mm256_sub_ps(_mm256_setzero_ps(), az);
    /* mul + add like the portable instance's hi * z + az (an FMA would round differently, and could
     * decide a corner on the boundary the other way); hi * z runs beside az, so it is no slower. */
    const __m256 top = _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(hi), zs), az);
    /* |= rather than one | chain: clang warns on | between comparisons (-Wbitwise-instead-of-logical),
     * and || would add branches. */
    int out = _mm256_movemask_ps(_mm256_cmp_ps(xs, naz, _CMP_LT_OQ)) == 0xFF;
    out |= _mm256_movemask_ps(_mm256_cmp_ps(xs, top, _CMP_GT_OQ)) == 0xFF;
    out |= _mm256_movemask_ps(_mm256_cmp_ps(ys, naz, _CMP_LT_OQ)) == 0xFF;
    out |= _mm256_movemask_ps(_mm256_cmp_ps(ys, top, _CMP_GT_OQ)) == 0xFF;
    out |= _mm256_movemask_ps(_mm256_cmp_ps(zs, _mm256_set1_ps(f->near), _CMP_LT_OQ)) == 0xFF;
    out |= _mm256_movemask_ps(_mm256_cmp_ps(zs, _mm256_set1_ps(f->far), _CMP_GT_OQ)) == 0xFF;
    v->outside = out;
    v->in_front = _mm256_movemask_ps(_mm256_cmp_ps(zs, _mm256_setzero_ps(), _CMP_GT_OQ)) == 0xFF;
    /* Horizontal min/max of 8 lanes, four at a time: [x0, y0, z0, -x1-...]. */
    __m256 iz = _mm256_div_ps(_mm256_set1_ps(1.0f), zs);
    __m256 px = _mm256_mul_ps(xs, iz), py = _mm256_mul_ps(ys, iz);
    __m128 lo_px = _mm_min_ps(_mm256_castps256_ps128(px), _mm256_extractf128_ps(px, 1));
    __m128 hi_px = _mm_max_ps(_mm256_castps256_ps128(px), _mm256_extractf128_ps(px, 1));
    __m128 lo_py = _mm_min_ps(_mm256_castps256_ps128(py), _mm256_extractf128_ps(py, 1));
    __m128 hi_py = _mm_max_ps(_mm256_castps256_ps128(py), _mm256_extractf128_ps(py, 1));
    __m128 lo_z = _mm_min_ps(_mm256_castps256_ps128(zs), _mm256_extractf128_ps(zs, 1));
    /* Transpose-free reduction: mins of (px, py, z) and negated maxes in one 4x4 min. */
    __m128 sx = _mm_unpacklo_ps(lo_px, lo_py), sy = _mm_unpackhi_ps(lo_px, lo_py);
    __m128 m01 = _mm_min_ps(sx, sy);                               /* px01 py01 px23 py23 pairs */
    __m128 mpx = _mm_min_ps(m01, _mm_movehl_ps(m01, m01));          /* lanes 0: px, 1: py */
    __m128 tx = _mm_unpacklo_ps(hi_px, hi_py), ty = _mm_unpackhi_ps(hi_px, hi_py);
    __m128 M01 = _mm_max_ps(tx, ty);
    __m128 Mpx = _mm_max_ps(M01, _mm_movehl_ps(M01, M01));
    __m128 zz = _mm_min_ps(lo_z, _mm_movehl_ps(lo_z, lo_z));
    zz = _mm_min_ss(zz, _mm_shuffle_ps(zz, zz, 1));
    v->zmin = _mm_cvtss_f32(zz);
    v->x0 = _mm_cvtss_f32(mpx);
    v->y0 = _mm_cvtss_f32(_mm_shuffle_ps(mpx, mpx, 1));
    v->x1 = _mm_cvtss_f32(Mpx);
    v->y1 = _mm_cvtss_f32(_mm_shuffle_ps(Mpx, Mpx, 1));
#else
    static const float bit[3][8] = { { 0, 1, 0, 1, 0, 1, 0, 1 }, { 0, 0, 1, 1, 0, 0, 1, 1 }, { 0, 0, 0, 0, 1, 1, 1, 1 } };
    float xs[8], ys[8], zs[8];
    for (int c = 0; c < 8; c++) {
        xs[c] = base[0] + bit[0][c] * col[0][0] + bit[1][c] * col[1][0] + bit[2][c] * col[2][0];
        ys[c] = base[1] + bit[0][c] * col[0][1] + bit[1][c] * col[1][1] + bit[2][c] * col[2][1];
        zs[c] = base[2] + bit[0][c] * col[0][2] + bit[1][c] * col[1][2] + bit[2][c] * col[2][2];
    }
    int out_xl = 1, out_xh = 1, out_yl = 1, out_yh = 1, out_near = 1, out_far = 1, front = 1;
    float zmin = zs[0], x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int c = 0; c < 8; c++) {
        float z = zs[c], az = fabsf(z) * MS_TRAV_SIDE_SLACK;
        out_xl &= xs[c] < -az;
        out_xh &= xs[c] > hi * z + az;
        out_yl &= ys[c] < -az;
        out_yh &= ys[c] > hi * z + az;
        out_near &= z < f->near;
        out_far &= z > f->far;
        front &= z > 0.0f;
        zmin = z < zmin ? z : zmin;
        float iz = 1.0f / z, px = xs[c] * iz, py = ys[c] * iz;
        x0 = px < x0 ? px : x0; x1 = px > x1 ? px : x1;
        y0 = py < y0 ? py : y0; y1 = py > y1 ? py : y1;
    }
    v->outside = out_xl | out_xh | out_yl | out_yh | out_near | out_far;
    v->in_front = front;
    v->zmin = zmin;
    v->x0 = x0; v->x1 = x1; v->y0 = y0; v->y1 = y1;
#endif
}

/* 1 if a still-visible sample may lie in the node's projected bounds (a small margin absorbs rounding
 * in the projection). */
static inline int MS_KFN(covers_live)(const ms_node_view *v, const MS_WORD *buf)
{
    if (!v->in_front) return 1;
    const float kmax = (float)(MS_K - 1);
    float fx0 = ceilf(v->x0 - MS_TRAV_SIDE_SLACK), fx1 = floorf(v->x1 + MS_TRAV_SIDE_SLACK);
    float fy0 = ceilf(v->y0 - MS_TRAV_SIDE_SLACK), fy1 = floorf(v->y1 + MS_TRAV_SIDE_SLACK);
    fx0 = fx0 < 0.0f ? 0.0f : fx0; fy0 = fy0 < 0.0f ? 0.0f : fy0;
    fx1 = fx1 > kmax ? kmax : fx1; fy1 = fy1 > kmax ? kmax : fy1;
    if (!(fx0 <= fx1 && fy0 <= fy1)) return 0;
    int i0 = (int)fx0, i1 = (int)fx1, j0 = (int)fy0, j1 = (int)fy1;
    /* Bits i0..i1 of a row, built without shifting by the word size. */
    const MS_WORD ones = (MS_WORD)~(MS_WORD)0;   /* cast after ~: uint16_t promotes to int */
    MS_WORD mask = (MS_WORD)((MS_WORD)(ones >> (MS_K - 1 - (i1 - i0))) << i0);
    MS_WORD any = 0;
    for (int j = j0; j <= j1; j++) any |= buf[j];
    if (!(any & mask)) return 0;
    for (int j = j0; j <= j1; j++)
        if (buf[j] & mask) return 1;
    return 0;
}

static inline int MS_KFN(all_zero)(const MS_WORD *buf)
{
    MS_WORD any = 0;
    for (int j = 0; j < MS_K; j++) any |= buf[j];
    return any == 0;
}

static inline void MS_KFN(ft_init)(ms_ft_ctx *t, const ms_raster_frame *f) { t->f = f; }

static inline int MS_KFN(ft_root_out)(const ms_ft_ctx *t, const ms_bvh *b)
{
    ms_node_view v;
    MS_KFN(view_node)(t->f, &b->nodes[0], &v);
    return v.outside;
}

static inline int MS_KFN(ft_covers)(const ms_node_view *v, const void *buf) { return MS_KFN(covers_live)(v, buf); }
static inline int MS_KFN(ft_all_zero)(const void *buf) { return MS_KFN(all_zero)(buf); }

static inline __attribute__((always_inline)) void MS_KFN(ft_children)(const ms_ft_ctx *t, const ms_bvh *b, const ms_bvh_node *n,
                                                                         const void *buf, int cull_occluded, int keep[2],
                                                                         ms_node_view v[2], float z[2], uint64_t *culled_frustum,
                                                                         uint64_t *culled_occluded)
{
    for (int h = 0; h < 2; h++) {
        MS_KFN(view_node)(t->f, &b->nodes[n->first + (uint32_t)h], &v[h]);
        keep[h] = !v[h].outside;
        *culled_frustum += (uint64_t)!keep[h];
        z[h] = v[h].zmin;
    }
    if (cull_occluded)
        for (int h = 0; h < 2; h++)
            if (keep[h] && !MS_KFN(covers_live)(&v[h], buf)) { keep[h] = 0; ++*culled_occluded; }
}

#include "frustum_traverse_loop.h"

