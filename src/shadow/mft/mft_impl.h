/* Method mft's block tracer (Benthin & Wald 2009, sec. 4-5 and Appendix A), one source compiled per ISA
 * (mft_scalar.c, mft_avx2.c, mft_avx512.c) with lanes16.h for the file's target; defines
 * ms_mft_block_<isa>. The 16 shadow frusta of a 4x4 pixel block (one per lane: apex C, the corner rays of
 * the rectangle of its live samples) traverse the shallow BVH together (block_traverse_loop.h: interval
 * arithmetic node culling of all 16 at once, nearer child first, early termination); in a leaf:
 *   0. the leaf's box against each frustum's four side planes, the receiver's horizon and the band of
 *      the segment parameter (16 lanes at once): a frustum that cannot reach the box skips the leaf;
 *   1. per triangle, culling of all 16 frusta at once: the receiver's horizon (every vertex behind its
 *      plane by more than 1e-5 of its distance), the triangle's plane (the segment parameter where the
 *      rays cross it, bounded over the frustum by the corner rays, outside [near, far]), the footprint:
 *      the triangle clipped to c >= near/4 and projected from C onto the light, in cells of the light's
 *      k x k strata (both shared patterns keep sample (i, j) in cell (i, j)), whose box cuts the
 *      frustum's live rectangle to the rows and columns of samples it can cover (an empty cut culls the
 *      pair), and, where there is no footprint or the cut still spans more than MFT_CORNER_AREA cells,
 *      the paper's corner-ray culling (all four corner rays outside one of the triangle's three edge
 *      planes through C);
 *   2. for each surviving frustum, its live rays in those rows and columns, 16 per SIMD operation (a
 *      packet: 16 consecutive samples of a row), found row by row from the live mask, only packets
 *      that still hold a live ray there; one bit per ray: a hit clears it; a frustum with no live ray
 *      leaves the block (early termination) and the block stops when none is left;
 *   3. after a leaf in which some ray of a frustum terminated, its corner rays are recomputed from the
 *      rectangle of its still-live samples (the paper's CR); with MS_MFT_FS its traversal bounds too
 *      (the paper's FS).
 *
 * The ray/triangle test is method raytrace's (raytrace_impl.h, packet_triangle) operation for
 * operation: the watertight test (ray_triangle.h) with the shear axis of the 16-sample packet, the edge
 * functions in float and in double where one is exactly 0, the plane distance against [near, far]
 * scaled by d . N; the rays are the same floats (mft.c). So each ray gets raytrace's answer, and the
 * culling above only has to be conservative: each of its tests carries a relative slack (1e-5, about 170
 * float ulps) far above the rounding of its own arithmetic and of the watertight test's decisions.
 *
 * Departures from the paper, and why:
 *  - rays are not generated from delta vectors at every test but formed once per pixel and 16-sample
 *    packet, when the packet is first tested (mft.c, ms_mft_rays), and kept for the block: the exact
 *    agreement with raytrace needs its shear (one division per ray), which generating rays at every
 *    test would repeat; 16 pixels x N x 8 floats (with the reciprocals of mft_ray_box; 512 KB at N = 1024) stay in the L2 cache;
 *  - the paper tests a frustum's 16 rays (its interleaved set) in one operation; with N up to 4096 rays
 *    per frustum, we test N/16 packets, only those the triangle's footprint reaches (16 rays need no
 *    footprint);
 *  - the paper culls back faces; shadows need both sides (two-sided test), so its back-face test is
 *    replaced by the plane-range test, which also drops the receiver's coplanar neighbours (t ~ 0);
 *  - the corner-ray culling is applied after the footprint's cut and only where the cut is absent or
 *    large: after the cut it culls few pairs that the cut does not, for a measurable share of the
 *    tracer's time;
 *  - the leaf culling (step 0) and the horizon test are ours; the paper's leaf culling (per-packet
 *    ray-AABB tests, Table 2) did not pay on Larrabee; this one tests the 16 frusta at once and removes
 *    more than half of the triangle-frustum pairs on the big-light Sponza;
 *  - a finer footprint (the triangle's span per row, from its edge functions along the light) cut the
 *    16-ray tests by a quarter but cost more in scalar set-up than it saved (measured, not kept);
 *  - on the grid pattern the footprint's box is taken against the samples' own positions in their cells
 *    (MFT_GRID_EPS: columns per row of a cut up to MFT_GRID_ROWS rows, 16 lanes at once, dropping pairs
 *    with no sample in the box), not only against whole cells;
 *  - the interleaved pattern is traced by mft_group_impl.h (rays regrouped by cell of the light); there
 *    each group's rays take raytrace's box test per node (the paper's "Ray-AABB"). On the grid the same
 *    test (once per leaf and packet) cut the 16-ray tests but not the time: not kept
 *    (docs/notebook/2026-11-22-mft-choices-and-first-results.md). */
#include <math.h>
#include <string.h>
#include "mft.h"
#include "visibility/lanes16.h"
#include "visibility/wt_rays16.h"
#include "core/perk.h"
#include "accel/ray_triangle.h"
#include "light/pattern.h"
#include "visibility/alpha.h"

#define MFT_REL 1e-5f
#define MFT_MAX_SKIP MS_BLOCK_LANES
/* Cells of a footprint-cut rectangle above which the corner rays are still tried (measured against 64 and
 * "never"). */
#define MFT_CORNER_AREA 256.0f

typedef struct mft_state {
    ms_block_frusta *fr;
    uint64_t *bt_cnt;
    const ms_mft_frame *f;
    ms_mft_block *blk;
    const ms_bvh *b;
    float cd[4][3][MS_BLOCK_LANES];   /* corner ray directions */
    float cl[4][MS_BLOCK_LANES];      /* their L1 norms */
    float hn[3][MS_BLOCK_LANES];      /* receiver normals */
    int rect[MS_BLOCK_LANES][4];      /* live cells: columns r[0]..r[1], rows r[2]..r[3] */
    float rectf[4][MS_BLOCK_LANES];   /* the same as floats, by bound (the leaf's vector cut) */
    uint64_t livech[MS_BLOCK_LANES][4]; /* packets (16 samples) with a live ray, one bit each */
    float m[3][3][MS_BLOCK_LANES];    /* cell projections (ms_mft_lane.m) */
    float ml1[3][MS_BLOCK_LANES];
    float fslack[MS_BLOCK_LANES];
    unsigned has_m;                   /* lanes with a cell projection */
    float sp[4][3][MS_BLOCK_LANES];   /* the frusta's side planes through C (normals facing in) */
    float olo[3][MS_BLOCK_LANES], ohi[3][MS_BLOCK_LANES];   /* C shifted by the box margin (ms_wt_box_origins) */
    float goa[MS_BLOCK_LANES], gv[MS_BLOCK_LANES];  /* the grid pattern's (k - 1 + u) / k and v per lane */
    int grid_rows;                    /* the grid pattern, k >= 16: the footprint against the samples (MFT_GRID_EPS) */
} mft_state;

/* Row j (k bits) of a sample mask. */
static inline uint64_t mft_row(const uint64_t *m, int k, int j)
{
    if (k == 64) return m[j];
    const int bit = j * k;
    return m[bit >> 6] >> (bit & 63) & ((UINT64_C(1) << k) - 1);
}

/* The rectangle of the live samples; 0 if none. For k >= 16 a 64-bit word holds 64 / k whole rows:
 * the columns from the OR of the words folded to one row, the rows from the first and last live words. */
static int mft_live_rect(const uint64_t *m, int k, int r[4])
{
    if (k >= 16) {
        const int nw = k * k / 64, rpw = 64 / k;
        int w0 = -1, w1 = -1;
        uint64_t acc = 0;
        for (int w = 0; w < nw; w++)
            if (m[w]) { if (w0 < 0) w0 = w; w1 = w; acc |= m[w]; }
        if (w0 < 0) return 0;
        for (int sh = 32; sh >= k; sh >>= 1) acc |= acc >> sh;
        const uint64_t row = k == 64 ? acc : acc & ((UINT64_C(1) << k) - 1);
        r[0] = __builtin_ctzll(row);
        r[1] = 63 - __builtin_clzll(row);
        r[2] = w0 * rpw + __builtin_ctzll(m[w0]) / k;
        r[3] = w1 * rpw + (63 - __builtin_clzll(m[w1])) / k;
        return 1;
    }
    uint64_t any = 0;
    int j0 = -1, j1 = -1;
    for (int j = 0; j < k; j++) {
        const uint64_t row = mft_row(m, k, j);
        if (row) { if (j0 < 0) j0 = j; j1 = j; any |= row; }
    }
    if (!any) return 0;
    r[0] = __builtin_ctzll(any);
    r[1] = 63 - __builtin_clzll(any);
    r[2] = j0;
    r[3] = j1;
    return 1;
}

/* Lane l's corner rays from its rectangle, and its traversal frustum when `traversal` is set. */
static void mft_lane_frustum(mft_state *s, int l, int traversal)
{
    const ms_mft_lane *L = &s->blk->lane[l];
    float d[4][3];
    ms_mft_corners(s->f, L->c, s->rect[l], d);
    for (int q = 0; q < 4; q++) s->rectf[q][l] = (float)s->rect[l][q];
    for (int c = 0; c < 4; c++) {
        for (int a = 0; a < 3; a++) s->cd[c][a][l] = d[c][a];
        s->cl[c][l] = fabsf(d[c][0]) + fabsf(d[c][1]) + fabsf(d[c][2]);
    }
    /* Side planes through C and consecutive corners (around the rectangle: 0, 1, 3, 2), in double,
     * each facing the opposite corner. */
    static const int ring[5] = { 0, 1, 3, 2, 0 };
    for (int q = 0; q < 4; q++) {
        const float *x = d[ring[q]], *y = d[ring[q + 1]], *o = d[ring[q + 2 > 4 ? 1 : q + 2]];
        double nn[3] = { (double)x[1] * y[2] - (double)x[2] * y[1], (double)x[2] * y[0] - (double)x[0] * y[2],
                         (double)x[0] * y[1] - (double)x[1] * y[0] };
        const double side = nn[0] * o[0] + nn[1] * o[1] + nn[2] * o[2];
        for (int a = 0; a < 3; a++) s->sp[q][a][l] = (float)(side < 0.0 ? -nn[a] : nn[a]);
    }
    if (traversal) ms_block_frusta_set_lane(s->fr, l, L->c, d, 1e-5f);
}

/* The lanes of mask whose frustum may reach leaf n's box: the box wholly outside one of the frustum's
 * four side planes, or behind the receiver's plane, or wholly at c < near/2 or beyond the light's plane
 * (c > 1), reaches none of its rays (what the micro-raster kernels' block traversal does per pixel at a
 * leaf; the paper's leaf culling by ray-packet AABB tests did not pay off on Larrabee, this one tests
 * 16 frusta at once). Over the box, a plane's largest value is n . (centre - C) + |n| . half-extent;
 * the slack is 1e-5 of the magnitudes. */
static unsigned mft_leaf_lanes(const mft_state *s, const ms_bvh_node *n, unsigned mask)
{
    l16 r[3], h[3];
    float hs = 0.0f;
    for (int a = 0; a < 3; a++) {
        const float hh = 0.5f * (n->bmax[a] - n->bmin[a]);
        r[a] = l16_sub(l16_set1(0.5f * (n->bmin[a] + n->bmax[a])), l16_load(s->fr->c[a]));
        h[a] = l16_set1(hh);
        hs += hh;
    }
    const l16 zero = l16_set1(0.0f), rel = l16_set1(MFT_REL);
    const l16 mag = l16_add(l16_add(l16_add(l16_abs(r[0]), l16_abs(r[1])), l16_abs(r[2])), l16_set1(hs));
    unsigned out = 0;
#define MFT_PLANE_MAX(nv, mx, nl1)                                                                              \
    do {                                                                                                       \
        const l16 a0 = l16_abs(nv[0]), a1 = l16_abs(nv[1]), a2 = l16_abs(nv[2]);                               \
        mx = l16_add(l16_add(l16_add(l16_mul(nv[0], r[0]), l16_mul(nv[1], r[1])), l16_mul(nv[2], r[2])),        \
                     l16_add(l16_add(l16_mul(a0, h[0]), l16_mul(a1, h[1])), l16_mul(a2, h[2])));                \
        nl1 = l16_add(l16_add(a0, a1), a2);                                                                    \
    } while (0)
    for (int q = 0; q < 5; q++) {
        l16 nv[3], mx, nl1;
        for (int a = 0; a < 3; a++) nv[a] = l16_load(q < 4 ? s->sp[q][a] : s->hn[a]);
        MFT_PLANE_MAX(nv, mx, nl1);
        out |= l16_lt(l16_add(mx, l16_mul(l16_mul(nl1, mag), rel)), zero);
    }
    if (s->has_m) {
        /* c over the box: [-(max of -c), max of c]. */
        l16 nv[3], mx, nl1, mn;
        for (int a = 0; a < 3; a++) nv[a] = l16_load(s->m[2][a]);
        MFT_PLANE_MAX(nv, mx, nl1);
        const l16 tol = l16_mul(l16_mul(nl1, mag), rel);
        for (int a = 0; a < 3; a++) nv[a] = l16_sub(zero, nv[a]);
        MFT_PLANE_MAX(nv, mn, nl1);
        out |= s->has_m & (l16_lt(l16_add(mx, tol), l16_set1(0.5f * s->f->near)) |
                           l16_gt(l16_sub(l16_sub(zero, mn), tol), l16_set1(1.0f)));
    }
#undef MFT_PLANE_MAX
    return mask & ~out;
}


/* The rays of 16-sample packet ch of lane L (bits: the live ones) that triangle tri hits: raytrace's
 * packet_triangle (raytrace_impl.h), the same operations in the same order. V: the vertices relative to
 * C; num: (v - C) . N from the vertex nearest C (ms_wt_offset). */
static unsigned mft_packet(const ms_mft_lane *L, int ch, unsigned bits, const float *tri, const float N[3],
                           const float V[3][3], float num, float near, float far)
{
    const int kz = L->kz[ch], base = ch * 16;
    unsigned hit = 0;
    if (kz < 0) {   /* each ray its own axis: ms_wt_segment, 16 lanes at once */
        const l16 Vs[3][3] = { { l16_set1(V[0][0]), l16_set1(V[0][1]), l16_set1(V[0][2]) },
                               { l16_set1(V[1][0]), l16_set1(V[1][1]), l16_set1(V[1][2]) },
                               { l16_set1(V[2][0]), l16_set1(V[2][1]), l16_set1(V[2][2]) } };
        const l16 dir[3] = { l16_load(L->d[0] + base), l16_load(L->d[1] + base), l16_load(L->d[2] + base) };
        unsigned z;
        hit = ms_wt_rays16_own(Vs, dir, N, l16_set1(num), near, far, bits, &z);
        for (unsigned m = z; m; m &= m - 1) {   /* an edge function exactly 0: in double */
            const int l = __builtin_ctz(m);
            const float d[3] = { L->d[0][base + l], L->d[1][base + l], L->d[2][base + l] };
            if (ms_wt_segment(L->c, d, tri, N, near, far)) hit |= 1u << l;
        }
        return hit;
    }
    const int kx = kz + 1 == 3 ? 0 : kz + 1, ky = kx + 1 == 3 ? 0 : kx + 1;
    const l16 sx = l16_load(L->sx + base), sy = l16_load(L->sy + base);
    const l16 Az = l16_set1(V[0][kz]), Bz = l16_set1(V[1][kz]), Cz = l16_set1(V[2][kz]);
    const l16 A[3][3] = { { l16_set1(V[0][kx]), l16_set1(V[0][ky]), Az }, { l16_set1(V[1][kx]), l16_set1(V[1][ky]), Bz },
                          { l16_set1(V[2][kx]), l16_set1(V[2][ky]), Cz } };
    const l16 dir[3] = { l16_load(L->d[0] + base), l16_load(L->d[1] + base), l16_load(L->d[2] + base) };
    unsigned z;
    hit = ms_wt_rays16(A, sx, sy, dir, N, l16_set1(num), near, far, bits, &z);
    /* An edge function exactly 0: redone by the scalar test (in double), as raytrace does (rare). */
    for (unsigned m = z; m; m &= m - 1) {
        const int l = __builtin_ctz(m), i = base + l;
        const float d[3] = { L->d[0][i], L->d[1][i], L->d[2][i] };
        if (ms_wt_segment_sheared(V[0], V[1], V[2], kz, L->sx[i], L->sy[i], d, N, num, near, far)) hit |= 1u << l;
    }
    return hit;
}

/* The cells of the light that triangle (a: its vertices relative to C, la: their L1 norms) can cover,
 * for the lanes of `lanes`: the triangle clipped to c >= near/4 (the segment parameter of a point is its
 * c, and a hit needs t >= near) and projected from C onto the light's plane, in cells: box[0..1] the
 * columns' range, box[2..3] the rows', widened by the lane's slack and, per projected point, by the
 * rounding of its float coordinates (a bound of 8.4 ulps of |m_r|_1 |X|_1 per coordinate, amplified by
 * the division by c). Returns the lanes with a box; *empty: the lanes where no part of the triangle has
 * c >= near/4 (it blocks none of their rays). A lane whose c is too uncertain near C (its bound above
 * near/8) gets no box. */
static unsigned mft_footprint16(const mft_state *s, const l16 a[3][3], const l16 la[3], unsigned lanes, unsigned *empty,
                                float box[4][MS_BLOCK_LANES])
{
    l16 m[3][3], ml[3];
    for (int r = 0; r < 3; r++) {
        ml[r] = l16_mul(l16_load(s->ml1[r]), l16_set1(1e-6f));
        for (int x = 0; x < 3; x++) m[r][x] = l16_load(s->m[r][x]);
    }
    const float near = s->f->near;
    const l16 cmin = l16_set1(0.25f * near), ecmax = l16_set1(0.125f * near);
    const l16 one = l16_set1(1.0f), two = l16_set1(2.0f), tiny = l16_set1(1e-6f);
    l16 p[3][3], e[3][3];   /* [vertex][a, b, c] */
    unsigned in[3], valid = lanes;
    for (int v = 0; v < 3; v++) {
        for (int r = 0; r < 3; r++) {
            p[v][r] = l16_add(l16_add(l16_mul(m[r][0], a[v][0]), l16_mul(m[r][1], a[v][1])), l16_mul(m[r][2], a[v][2]));
            e[v][r] = l16_mul(ml[r], la[v]);
        }
        valid &= l16_le(e[v][2], ecmax);
        in[v] = l16_le(cmin, p[v][2]);
    }
    l16 lo[2] = { l16_set1(INFINITY), l16_set1(INFINITY) }, hi[2] = { l16_set1(-INFINITY), l16_set1(-INFINITY) };
#define MFT_PROJECT(q, eq, msk)                                                                            \
    do {                                                                                                   \
        const l16 inv = l16_div(one, q[2]);                                                                \
        for (int r = 0; r < 2; r++) {                                                                      \
            const l16 x = l16_mul(q[r], inv), ax = l16_abs(x);                                             \
            const l16 sl = l16_add(l16_mul(l16_mul(l16_add(eq[r], l16_mul(ax, eq[2])), inv), two), l16_mul(ax, tiny)); \
            lo[r] = l16_select(msk, l16_min(lo[r], l16_sub(x, sl)), lo[r]);                               \
            hi[r] = l16_select(msk, l16_max(hi[r], l16_add(x, sl)), hi[r]);                               \
        }                                                                                                  \
    } while (0)
    for (int v = 0; v < 3; v++) MFT_PROJECT(p[v], e[v], in[v] & valid);
    for (int v = 0; v < 3; v++) {
        const int w = v == 2 ? 0 : v + 1;
        const unsigned cross = (in[v] ^ in[w]) & valid;
        if (!cross) continue;
        /* The edge's point at c = near/4 (a point of the edge for the rounded parameter: its own c is
         * used to project it). */
        const l16 t = l16_div(l16_sub(cmin, p[v][2]), l16_sub(p[w][2], p[v][2]));
        l16 q[3], eq[3];
        for (int r = 0; r < 3; r++) {
            q[r] = l16_add(p[v][r], l16_mul(t, l16_sub(p[w][r], p[v][r])));
            eq[r] = l16_add(e[v][r], e[w][r]);
        }
        MFT_PROJECT(q, eq, cross);
    }
#undef MFT_PROJECT
    *empty = valid & ~(in[0] | in[1] | in[2]);
    valid &= ~*empty;
    const l16 fs = l16_load(s->fslack), lim0 = l16_set1(-1.0f), lim1 = l16_set1((float)s->f->k);
    for (int r = 0; r < 2; r++) {
        l16_store(box[2 * r], l16_min(l16_max(l16_sub(lo[r], fs), lim0), lim1));
        l16_store(box[2 * r + 1], l16_min(l16_max(l16_add(hi[r], fs), lim0), lim1));
    }
    return valid;
}

#ifndef MFT_ALPHA_FILTER
#define MFT_ALPHA_FILTER
/* The bits of hit (rays of packet ch of lane L that alpha-tested triangle t meets) where t is opaque. */
static unsigned mft_alpha_filter(const ms_mft_frame *f, const ms_mft_lane *L, int ch, uint32_t t, unsigned hit)
{
    float pts[3 * 16];
    ms_pattern_points_range(f->pattern, &f->light, f->k, L->px, L->py, f->seed, ch * 16, 16, pts);
    for (unsigned m = hit; m; m &= m - 1) {
        const int b = __builtin_ctz(m);
        if (!ms_alpha_segment_occludes(f->alpha, t, L->c, pts + 3 * b)) hit &= ~(1u << b);
    }
    return hit;
}
#endif

/* One (frustum, triangle) pair on its way through the packets it may hit. */
typedef struct mft_pair {
    mft_state *s;
    ms_mft_lane *L;
    int l;
    uint32_t t;
    const float *tri, *N;
    float num;
    int have_v, isec, cleared, done;
    float V[3][3];                    /* the vertices relative to C, formed at the first test */
} mft_pair;

/* Tests the live rays `bits` of packet ch against the pair's triangle and clears those it blocks; sets
 * done when the lane has no live ray left. */
static inline void mft_pair_packet(mft_pair *pr, int ch, unsigned bits)
{
    mft_state *s = pr->s;
    ms_mft_lane *L = pr->L;
    const ms_mft_frame *f = s->f;
    if (!pr->have_v) {
        for (int v = 0; v < 3; v++)
            for (int x = 0; x < 3; x++) pr->V[v][x] = pr->tri[3 * v + x] - L->c[x];
        pr->have_v = 1;
    }
    if (!(L->ready[ch >> 6] >> (ch & 63) & 1)) ms_mft_rays(f, L, ch);
    pr->isec++;
    unsigned hit = mft_packet(L, ch, bits, pr->tri, pr->N, (const float(*)[3])pr->V, pr->num, f->near, f->far);
    /* Any hit: an alpha-tested triangle keeps only the rays where it is opaque (alpha.h, the decision
     * every method shares: the segment from C to the pattern's sample point). */
    if (hit && f->alpha && f->alpha->flag[pr->t]) hit = mft_alpha_filter(f, L, ch, pr->t, hit);
    if (!hit) return;
    const int sh = (ch & 3) * 16;
    const unsigned all = (unsigned)(L->mask[ch >> 2] >> sh) & 0xFFFFu;
    L->mask[ch >> 2] &= ~((uint64_t)hit << sh);
    pr->cleared = 1;
    if (all & ~hit) return;
    uint64_t *lc = s->livech[pr->l];
    lc[ch >> 6] &= ~(UINT64_C(1) << (ch & 63));
    pr->done = !(lc[0] | lc[1] | lc[2] | lc[3]);
}

/* The grid pattern (pattern.c, ms_grid_for_pixel) puts sample (i, j) of a pixel with shift (u, v) at cell
 * coordinates (i + (k - 1 - j + u) / k, j + (i + v) / k), not anywhere in cell (i, j): so in row j the
 * samples inside the footprint's box [a0, a1] x [b0, b1] are the columns i with i + (k - 1 - j + u) / k in
 * [a0, a1] and (i + v) / k in [b0 - j, b1 - j], an interval of columns:
 *   ceil(a0 - (k - 1 + u) / k + j / k) .. floor(a1 - (k - 1 + u) / k + j / k), and
 *   ceil(k b0 - v) - k j .. floor(k b1 - v) - k j (k j an integer: exact).
 * The box bounds the exact positions of the samples whose rays can hit (the bound the cut to cells relies
 * on already, mft_footprint16); EPS (a thousandth of a cell, far above the float rounding of these few
 * operations on values below k^2) keeps the interval conservative. A departure from the paper (which has
 * no footprint): the cut to cells alone leaves about (w + 1)(h + 1) cells for a box of w x h cells, most of
 * them without a sample in the box for a small triangle under a big light; this leaves about w h. Done for
 * cuts of at most MFT_GRID_ROWS rows, 16 lanes at once (taller cuts: the per-row work cost more than it
 * saved; docs/notebook/2026-11-26-mft-grid-setup-and-footprint.md). */
#define MFT_GRID_EPS 1e-3f
#define MFT_GRID_ROWS 2
/* Per lane, the columns of the cut's first MFT_GRID_ROWS rows that hold a sample in the footprint's box:
 * first and last, by row. */
typedef struct mft_grid_box {
    int32_t rows[2 * MFT_GRID_ROWS][MS_BLOCK_LANES];
} mft_grid_box;

/* The plane: num = (v - C) . N from the vertex nearest C (ms_wt_offset, bit for bit; a: the vertices relative to
 * the 16 origins C, lv their squared lengths); the segments' d . N over the frustum lies between the corner rays'
 * (cd, of lengths cl: the samples are convex combinations of the corners), widened; a hit needs num / (d . N) in
 * [near, far]. The lanes whose segments cannot meet the plane there; num and |num| into *num_out, *an_out. */
static inline unsigned mft_plane_out(const ms_mft_frame *f, const l16 a[3][3], const l16 lv[3], const float *N, float nl1,
                                     const l16 cd[4][3], const l16 cl[4], l16 *num_out, l16 *an_out)
{
    const l16 zero = l16_set1(0.0f), near = l16_set1(f->near), far = l16_set1(f->far);
    const l16 one_lo = l16_set1(1.0f - MFT_REL), one_hi = l16_set1(1.0f + MFT_REL);
    const l16 inf = l16_set1(INFINITY), ninf = l16_set1(-INFINITY);
    const unsigned p0 = l16_le(lv[0], lv[1]) & l16_le(lv[0], lv[2]);
    const unsigned p1 = ~l16_le(lv[0], lv[1]) & l16_le(lv[1], lv[2]);
    l16 vn[3];
    for (int x = 0; x < 3; x++) vn[x] = l16_select(p0, a[0][x], l16_select(p1, a[1][x], a[2][x]));
    const l16 num = l16_add(l16_add(l16_mul(vn[0], l16_set1(N[0])), l16_mul(vn[1], l16_set1(N[1]))), l16_mul(vn[2], l16_set1(N[2])));
    l16 dlo = inf, dhi = ninf, clmax = zero;
    for (int q = 0; q < 4; q++) {
        const l16 den = l16_add(l16_add(l16_mul(cd[q][0], l16_set1(N[0])), l16_mul(cd[q][1], l16_set1(N[1]))),
                                l16_mul(cd[q][2], l16_set1(N[2])));
        dlo = l16_min(dlo, den);
        dhi = l16_max(dhi, den);
        clmax = l16_max(clmax, cl[q]);
    }
    const l16 dtol = l16_mul(clmax, l16_set1(nl1 * MFT_REL));
    dlo = l16_sub(dlo, dtol);
    dhi = l16_add(dhi, dtol);
    const unsigned pos = l16_gt(num, zero);
    const l16 an = l16_abs(num);
    *num_out = num;
    *an_out = an;
    const l16 slo = l16_select(pos, dlo, l16_sub(zero, dhi)), shi = l16_select(pos, dhi, l16_sub(zero, dlo));
    const unsigned plane_out = l16_le(an, zero) | l16_le(shi, zero) | l16_lt(l16_mul(far, shi), l16_mul(an, one_lo)) |
                               l16_gt(l16_mul(near, slo), l16_mul(an, one_hi));
    return plane_out;
}

/* Corner rays against the edge planes through C (a: the vertices relative to the 16 origins, la their L1 lengths;
 * cd, cl: the corner rays and their lengths): a ray hits (t > 0) only inside the cone of the vertices, where every
 * edge function (a_i x a_j) . d has the sign of det = (a0 x a1) . a2. Trusted only where |det| clears its own
 * rounding. The lanes of corner_lanes whose four corner rays all miss. */
static inline unsigned mft_corner_out(const l16 a[3][3], const l16 la[3], const l16 cd[4][3], const l16 cl[4],
                                      unsigned corner_lanes)
{
    const l16 zero = l16_set1(0.0f), rel = l16_set1(MFT_REL);
    l16 e[3][3];
    for (int q = 0; q < 3; q++) {
        const l16 *x = a[q], *y = a[q == 2 ? 0 : q + 1];
        e[q][0] = l16_sub(l16_mul(x[1], y[2]), l16_mul(x[2], y[1]));
        e[q][1] = l16_sub(l16_mul(x[2], y[0]), l16_mul(x[0], y[2]));
        e[q][2] = l16_sub(l16_mul(x[0], y[1]), l16_mul(x[1], y[0]));
    }
    const l16 det = l16_add(l16_add(l16_mul(e[0][0], a[2][0]), l16_mul(e[0][1], a[2][1])), l16_mul(e[0][2], a[2][2]));
    const unsigned det_ok = l16_gt(l16_abs(det), l16_mul(l16_mul(l16_mul(la[0], la[1]), la[2]), rel));
    const unsigned det_pos = l16_gt(det, zero);
    unsigned corner_out = 0;
    for (int q = 0; q < 3; q++) {
        const l16 lq = l16_mul(l16_mul(la[q], la[q == 2 ? 0 : q + 1]), rel);
        unsigned all = 0xFFFF;
        for (int c4 = 0; c4 < 4; c4++) {
            const l16 ev = l16_add(l16_add(l16_mul(e[q][0], cd[c4][0]), l16_mul(e[q][1], cd[c4][1])),
                                   l16_mul(e[q][2], cd[c4][2]));
            const l16 tol = l16_mul(lq, cl[c4]);
            all &= (det_pos & l16_lt(l16_add(ev, tol), zero)) | (~det_pos & l16_gt(l16_sub(ev, tol), zero));
        }
        corner_out |= all;
    }
    return corner_out & det_ok & corner_lanes;
}

/* The pair's live rays in cells [x0, x1] x [y0, y1] of its lane l, one 16-ray test per packet that holds any; fine:
 * each row narrowed to the grid's columns in the footprint's box (gbox). */
static inline void mft_pair_cells(mft_pair *pr, const ms_mft_lane *L, int l, int k, int x0, int x1, int y0, int y1, int fine,
                                  const mft_grid_box *gbox)
{
    const int cpr = k / 16;
    if (k >= 16) {
        /* Row by row, the live rays of columns x0..x1, one test per 16-sample packet that holds any. */
        const uint64_t cols = ((UINT64_C(2) << x1) - 1) & ~((UINT64_C(1) << x0) - 1);
                for (int y = y0; y <= y1 && !pr->done; y++) {
            uint64_t row = mft_row(L->mask, k, y) & cols;
            if (row && fine) {
                const int q = y - y0, i0 = gbox->rows[2 * q][l], i1 = gbox->rows[2 * q + 1][l];
                row = i0 > i1 ? 0 : row & ((UINT64_C(2) << i1) - 1) & ~((UINT64_C(1) << i0) - 1);
            }
            while (row) {
                const int p = __builtin_ctzll(row) >> 4;
                const unsigned bits = (unsigned)(row >> 16 * p) & 0xFFFFu;
                row &= ~(UINT64_C(0xFFFF) << 16 * p);
                mft_pair_packet(pr, y * cpr + p, bits);
            }
        }
    } else {
        /* k = 4, 8 (stratified 16, 64): a packet is 16 / k whole rows. (An earlier loop took k / 16 =
         * 0 packets per row and tested no ray at all: mft answered the front mask; the known bug of
         * test_visibility.) */
        const int rpp = 16 / k;
        const unsigned rowcols = ((1u << (x1 - x0 + 1)) - 1u) << x0;
        for (int ch = y0 / rpp; ch <= y1 / rpp; ch++) {
            unsigned cols = 0;
            for (int r = 0; r < rpp; r++)
                if (ch * rpp + r >= y0 && ch * rpp + r <= y1) cols |= rowcols << (r * k);
            const unsigned bits = (unsigned)(L->mask[ch >> 2] >> (ch & 3) * 16) & cols;
            if (bits) mft_pair_packet(pr, ch, bits);
        }
    }
}

/* The grid's samples in the footprint's box (above MFT_GRID_EPS): the columns of each of the first MFT_GRID_ROWS rows
 * of the cuts r into gbox, for the 16 lanes at once. The lanes whose cut holds no sample. */
static inline unsigned mft_grid_cut(const mft_state *s, int k, float box[4][MS_BLOCK_LANES], const l16 r[4],
                                    mft_grid_box *gbox)
{
    const l16 kf = l16_set1((float)k), keps = l16_set1((float)k * MFT_GRID_EPS), eps = l16_set1(MFT_GRID_EPS);
    const l16 oa = l16_load(s->goa), v = l16_load(s->gv);
    const l16 ga0 = l16_sub(l16_sub(l16_load(box[0]), oa), eps), ga1 = l16_add(l16_sub(l16_load(box[1]), oa), eps);
    const l16 gb0 = l16_ceil(l16_sub(l16_sub(l16_mul(kf, l16_load(box[2])), keps), v));
    const l16 gb1 = l16_floor(l16_add(l16_sub(l16_mul(kf, l16_load(box[3])), v), keps));
    const l16 invk = l16_set1(1.0f / (float)k);
    unsigned none = 0xFFFF;
    for (int q = 0; q < MFT_GRID_ROWS; q++) {
        const l16 j = l16_add(r[2], l16_set1((float)q)), jk = l16_mul(j, invk), kj = l16_mul(j, kf);
        const l16 ia = l16_max(l16_max(l16_ceil(l16_add(ga0, jk)), l16_sub(gb0, kj)), r[0]);
        const l16 ib = l16_min(l16_min(l16_floor(l16_add(ga1, jk)), l16_sub(gb1, kj)), r[1]);
        l16_store_int(gbox->rows[2 * q], ia);
        l16_store_int(gbox->rows[2 * q + 1], ib);
        none &= l16_gt(ia, ib) | (q ? l16_gt(j, r[3]) : 0u);
    }
    return none;
}

static void mft_leaf(mft_state *s, const ms_bvh_node *n, unsigned mask)
{
    ms_block_frusta *fr = s->fr;
    const ms_mft_frame *f = s->f;
    ms_mft_block *blk = s->blk;
    uint64_t *cnt = s->bt_cnt;
    const int k = f->k;
    /* The pixels whose own triangle is in this leaf. */
    uint32_t skip_tri[MFT_MAX_SKIP];
    unsigned skip_lane[MFT_MAX_SKIP];
    int nskip = 0;
    for (unsigned m = mask; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        if (blk->lane[l].skip - n->first < n->count) { skip_tri[nskip] = blk->lane[l].skip; skip_lane[nskip++] = 1u << l; }
    }
    const unsigned before = mask & fr->live;
    mask = mft_leaf_lanes(s, n, before);
    cnt[MS_MFT_LEAF_LANES_CULLED] += (uint64_t)ms_bt_popcount16(before & ~mask);
    if (!mask) return;
    l16 c[3], hn[3], cd[4][3], cl[4];
    for (int a = 0; a < 3; a++) { c[a] = l16_load(fr->c[a]); hn[a] = l16_load(s->hn[a]); }
    for (int q = 0; q < 4; q++) {
        cl[q] = l16_load(s->cl[q]);
        for (int a = 0; a < 3; a++) cd[q][a] = l16_load(s->cd[q][a]);
    }
    const l16 zero = l16_set1(0.0f), rel = l16_set1(MFT_REL);
    unsigned terminated = 0;
    uint64_t pairs = 0, c_hor = 0, c_plane = 0, c_corner = 0, c_foot = 0, tested = 0, isec = 0, early = 0;
    for (uint32_t t = n->first; t < n->first + n->count; t++) {
        unsigned lanes = mask & fr->live;
        if (!lanes) break;
        for (int q = 0; q < nskip; q++)
            if (skip_tri[q] == t) lanes &= ~skip_lane[q];
        if (!lanes) continue;
        pairs += (uint64_t)ms_bt_popcount16(lanes);
        const float *tri = s->b->tri + 9 * (size_t)t, *N = s->b->tri_n + 3 * (size_t)t;
        l16 a[3][3], la[3], lv[3];
        unsigned behind = 0xFFFF;
        for (int v = 0; v < 3; v++) {
            for (int x = 0; x < 3; x++) a[v][x] = l16_sub(l16_set1(tri[3 * v + x]), c[x]);
            la[v] = l16_add(l16_add(l16_abs(a[v][0]), l16_abs(a[v][1])), l16_abs(a[v][2]));
            lv[v] = l16_add(l16_add(l16_mul(a[v][0], a[v][0]), l16_mul(a[v][1], a[v][1])), l16_mul(a[v][2], a[v][2]));
            const l16 h = l16_add(l16_add(l16_mul(hn[0], a[v][0]), l16_mul(hn[1], a[v][1])), l16_mul(hn[2], a[v][2]));
            behind &= l16_lt(h, l16_sub(zero, l16_mul(la[v], rel)));
        }
        const float nl1 = fabsf(N[0]) + fabsf(N[1]) + fabsf(N[2]);
        l16 num, an;
        const unsigned plane_out = mft_plane_out(f, a, lv, N, nl1, cd, cl, &num, &an);
        unsigned pass = lanes & ~behind;
        c_hor += (uint64_t)ms_bt_popcount16(lanes & behind);
        c_plane += (uint64_t)ms_bt_popcount16(pass & plane_out);
        pass &= ~plane_out;
        if (!pass) continue;
        /* Each surviving lane's rectangle of cells: its live rectangle, cut to the triangle's footprint,
         * for the 16 lanes at once (floor and clamp in vector form, the box being within [-1, k]); an empty
         * cut drops the pair before any scalar work. */
        l16 r[4];
        for (int q = 0; q < 4; q++) r[q] = l16_load(s->rectf[q]);
        unsigned foot = 0, grid_rows = 0;
        mft_grid_box gbox;
        /* No footprint for a triangle whose plane passes within 1e-4 of its size from C (|num| is C's
         * distance from the plane times |N|): some rays graze it, and the watertight test decides its
         * edges in the plane across the ray, where such a triangle is a sliver, with an error that grows
         * as the rays flatten, beyond the footprint's slack. Found on Sponza's big light at 1024^2: a
         * sliver 3e-5 off the receiver's plane, which raytrace finds hit by a ray passing 2.5e-4 outside
         * it (exact rational arithmetic); mft must give raytrace's answer, so it tests such triangles
         * over the whole live rectangle. (|det| as the corner rays use it would also catch it, but it is
         * small for every small, far triangle; the threshold 1e-4 of the size costs a modest share of extra
         * 16-ray tests there, where 1e-2 cost many more.) */
        const l16 lamax = l16_max(la[0], l16_max(la[1], la[2]));
        const unsigned grazing = l16_le(an, l16_mul(lamax, l16_set1(nl1 * 1e-4f)));
        const unsigned foot_lanes = pass & s->has_m & ~grazing;
        if (foot_lanes) {
            float box[4][MS_BLOCK_LANES];
            unsigned empty = 0;
            foot = mft_footprint16(s, a, la, foot_lanes, &empty, box);
            for (int q = 0; q < 4; q += 2) {
                const l16 lo = l16_floor(l16_load(box[q])), hi = l16_floor(l16_load(box[q + 1]));
                r[q] = l16_select(foot, l16_max(lo, r[q]), r[q]);
                r[q + 1] = l16_select(foot, l16_min(hi, r[q + 1]), r[q + 1]);
            }
            unsigned out = empty | (foot & (l16_gt(r[0], r[1]) | l16_gt(r[2], r[3])));
            const unsigned short_cut = foot & ~out & l16_le(r[3], l16_add(r[2], l16_set1((float)(MFT_GRID_ROWS - 1))));
            if (s->grid_rows && short_cut) {   /* a short cut with no sample of the grid drops the pair */
                grid_rows = short_cut;
                out |= grid_rows & mft_grid_cut(s, k, box, r, &gbox);
            }
            c_foot += (uint64_t)ms_bt_popcount16(pass & out);
            pass &= ~out;
        }
        /* Corner rays (mft_corner_out) for the lanes without a footprint, or whose cut still spans more than
         * MFT_CORNER_AREA cells (with a small cut, the cut above culls nearly every pair this test would:
         * measured). */
        const l16 one_f = l16_set1(1.0f);
        const l16 area = l16_mul(l16_add(l16_sub(r[1], r[0]), one_f), l16_add(l16_sub(r[3], r[2]), one_f));
        const unsigned corner_lanes = pass & (~foot | l16_gt(area, l16_set1(MFT_CORNER_AREA)));
        if (corner_lanes) {
            const unsigned corner_out = mft_corner_out(a, la, cd, cl, corner_lanes);
            c_corner += (uint64_t)ms_bt_popcount16(pass & corner_out);
            pass &= ~corner_out;
        }
        if (!pass) continue;
        float numv[MS_BLOCK_LANES];
        l16_store(numv, num);
        int32_t rc[4][MS_BLOCK_LANES];
        for (int q = 0; q < 4; q++) l16_store_int(rc[q], r[q]);
        tested += (uint64_t)ms_bt_popcount16(pass);
        for (; pass; pass &= pass - 1) {
            const int l = __builtin_ctz(pass);
            ms_mft_lane *L = &blk->lane[l];
            const int x0 = rc[0][l], x1 = rc[1][l], y0 = rc[2][l], y1 = rc[3][l];
            mft_pair pr = { .s = s, .L = L, .l = l, .t = t, .tri = tri, .N = N, .num = numv[l] };
            mft_pair_cells(&pr, L, l, k, x0, x1, y0, y1, grid_rows >> l & 1, &gbox);
            isec += (uint64_t)pr.isec;
            if (!pr.cleared) continue;
            terminated |= 1u << l;
            if (pr.done) { fr->live &= ~(1u << l); early++; }
        }
    }
    cnt[MS_MFT_PAIRS] += pairs;
    cnt[MS_MFT_CULLED_HORIZON] += c_hor;
    cnt[MS_MFT_CULLED_PLANE] += c_plane;
    cnt[MS_MFT_CULLED_CORNER] += c_corner;
    cnt[MS_MFT_CULLED_FOOTPRINT] += c_foot;
    cnt[MS_MFT_PAIRS_TESTED] += tested;
    cnt[MS_MFT_ISEC16] += isec;
    cnt[MS_MFT_FRUSTA_EARLY_OUT] += early;
    /* CR (and FS): the corner rays of the frusta that lost rays here, from their live rectangle. */
    for (unsigned m = terminated & fr->live; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        int r[4];
        mft_live_rect(blk->lane[l].mask, k, r);
        if (memcmp(r, s->rect[l], sizeof r) == 0) continue;
        memcpy(s->rect[l], r, sizeof r);
        cnt[MS_MFT_RECT_SHRINKS]++;
        mft_lane_frustum(s, l, f->flags & MS_MFT_FS);
    }
}

#define BT_STATE mft_state
#define BT_LEAF(s, n, mask) mft_leaf(s, n, mask)
#define BT_FN mft_traverse
#include "shadow/microraster/block_traverse_loop.h"
#undef BT_STATE
#undef BT_LEAF
#undef BT_FN

void MS_CAT(ms_mft_block_, MS_ISA_SUFFIX)(const ms_mft_frame *f, ms_mft_block *blk, const ms_bvh *b,
                                          const ms_bvh_shallow *sh, uint64_t *cnt)
{
    ms_block_frusta fr;
    mft_state s;
    memset(&s, 0, sizeof s);
    ms_block_frusta_init(&fr, &sh->nodes[0], f->near, f->far);
    s.fr = &fr;
    s.bt_cnt = cnt;
    s.f = f;
    s.blk = blk;
    s.b = b;
    s.grid_rows = f->pattern == MS_PATTERN_GRID && f->k >= 16;
    for (int l = 0; l < blk->n; l++) {
        ms_mft_lane *L = &blk->lane[l];
        for (int a = 0; a < 3; a++) s.hn[a][l] = L->n[a];
        if (s.grid_rows) {
            float u;
            ms_grid_shift(L->px, L->py, f->seed, &u, &s.gv[l]);
            s.goa[l] = ((float)(f->k - 1) + u) / (float)f->k;
        }
        float olo[3], ohi[3];
        ms_wt_box_origins(b->nodes[0].bmin, b->nodes[0].bmax, L->c, olo, ohi);
        for (int a = 0; a < 3; a++) { s.olo[a][l] = olo[a]; s.ohi[a][l] = ohi[a]; }
        if (L->has_m) {
            s.has_m |= 1u << l;
            s.fslack[l] = L->foot_slack;
            for (int r = 0; r < 3; r++) {
                s.ml1[r][l] = L->m_l1[r];
                for (int a = 0; a < 3; a++) s.m[r][a][l] = L->m[r][a];
            }
        }
        if (!mft_live_rect(L->mask, f->k, s.rect[l])) continue;   /* the caller hands over non-empty masks */
        for (int ch = 0; ch < f->samples / 16; ch++)
            if (L->mask[ch >> 2] >> (ch & 3) * 16 & 0xFFFFu) s.livech[l][ch >> 6] |= UINT64_C(1) << (ch & 63);
        mft_lane_frustum(&s, l, 1);
        cnt[MS_MFT_FRUSTA]++;
    }
    mft_traverse(&s, sh, f->flags & MS_MFT_ORDER);
}
