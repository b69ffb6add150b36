/* The interior boxes' pass of the block traversal as silhouettes (docs/culling.md, "Interior boxes"): seen from a
 * pixel, a box clears the samples inside its silhouette, the convex polygon bounded by its four or six silhouette
 * edges, in one pass of the Scanline row loop (raster_internal.h, ms_raster_rows with five edge lanes: a convex
 * polygon of six edges has at most five on either side), where its faces as triangles took two to six kernel calls.
 * Included by block_raster_impl.h per k and ISA, after br_state, br_leaf_ctx and br_covers.
 *
 * Exactness: what a box clears need not be any kernel's coverage of anything, only a subset of the samples whose
 * segments meet the box: those are occluded for every method (the claim of docs/culling.md), so the buffer after
 * the scene's triangles is the same whatever subset the boxes took. A sample inside every silhouette edge's plane
 * through C (on the box's side) lies on a ray from C through the box; with every corner of the box at a segment
 * parameter in [near, far] (z in light-index space is the parameter), the ray meets the box within the segment.
 * The rounding of the planes and of the row bounds (relative 1e-6 or so) may clear a sample whose segment passes
 * just outside the box, which the claim's clearance covers as it covers the kernels' own rounding. A box not
 * wholly in that range for a pixel, or seen nearly along one of its silhouette edges (a plane from a near-zero
 * cross product), is skipped for that pixel: skipping clears less, never wrong. */

#ifndef MS_BR_BOX_COMMON
#define MS_BR_BOX_COMMON
/* Smallest sine, squared, between the rays from C to a silhouette edge's two corners. */
#define BR_BOX_MIN_SIN2 1e-6f
#define BR_BOX_EDGES 12
#endif

/* Box b (min x, y, z, max x, y, z) for the pixels of `lanes`: the depth test (every corner in [near, far]), the
 * rectangle test (the corners' projected box against the visible rectangle) and the coverage test, as for a
 * triangle; then the silhouette edges of all the pixels that remain at once, one box edge at a time, and each
 * pixel's rows. Counted in L as a triangle is. */
static __attribute__((noinline)) void MS_KFN(br_box)(const br_state *s, br_leaf_ctx *L, const float b[6], unsigned lanes)
{
    const ms_block_input *in = s->in;
    const l16 one = l16_set1(1.0f), zero = l16_set1(0.0f);
    /* Light-index corners (corner bits: x = 1, y = 2, z = 4): the low corner's and the steps along each axis. */
    l16 p[8][3], d[3][3];
    {
        l16 a[3];
        for (int k = 0; k < 3; k++) a[k] = l16_sub(l16_set1(b[k]), L->c[k]);
        for (int r = 0; r < 3; r++) {
            p[0][r] = l16_add(l16_add(l16_mul(L->m[r][0], a[0]), l16_mul(L->m[r][1], a[1])), l16_mul(L->m[r][2], a[2]));
            for (int k = 0; k < 3; k++) d[k][r] = l16_mul(L->m[r][k], l16_set1(b[3 + k] - b[k]));
        }
    }
    for (int q = 1; q < 8; q++) {
        const int k = 31 - __builtin_clz((unsigned)q);   /* q's highest axis: q = (q without it) + that step */
        for (int r = 0; r < 3; r++) p[q][r] = l16_add(p[q & ~(1 << k)][r], d[k][r]);
    }
    l16 zmin = p[0][2], zmax = p[0][2], xlo = l16_set1(INFINITY), ylo = xlo, xhi = l16_set1(-INFINITY), yhi = xhi;
    for (int q = 0; q < 8; q++) {
        zmin = l16_min(zmin, p[q][2]);
        zmax = l16_max(zmax, p[q][2]);
        const l16 inv = l16_div(one, p[q][2]), xs = l16_mul(p[q][0], inv), ys = l16_mul(p[q][1], inv);
        xlo = l16_min(xlo, xs);
        xhi = l16_max(xhi, xs);
        ylo = l16_min(ylo, ys);
        yhi = l16_max(yhi, ys);
    }
    const unsigned depth_ok = lanes & l16_le(l16_set1(s->fr->near), zmin) & l16_le(zmax, l16_set1(s->fr->far));
    /* The samples the corners' projected box may hold, within the visible rectangle. */
    l16 bx0, bx1, by0, by1;
    MS_KFN(br_index_box)(xlo, xhi, ylo, yhi, L->rx0, L->rx1, L->ry0, L->ry1, &bx0, &bx1, &by0, &by1);
    const unsigned miss = l16_gt(bx0, bx1) | l16_gt(by0, by1);
    L->c_depth += (uint64_t)ms_bt_popcount16(lanes & ~depth_ok);
    L->c_rect += (uint64_t)ms_bt_popcount16(depth_ok & miss);
    unsigned go = depth_ok & ~miss;
    if (!go) return;
    int32_t ix0[MS_BLOCK_LANES], ix1[MS_BLOCK_LANES], iy0[MS_BLOCK_LANES], iy1[MS_BLOCK_LANES];
    l16_store_int(ix0, bx0); l16_store_int(ix1, bx1); l16_store_int(iy0, by0); l16_store_int(iy1, by1);
    for (unsigned m = go; m; m &= m - 1) {
        const int e = __builtin_ctz(m);
        if (!MS_KFN(br_covers)((const MS_WORD *)in->buf[e], ix0[e], ix1[e], iy0[e], iy1[e])) { L->c_cov++; go &= ~(1u << e); }
    }
    if (!go) return;
    /* The silhouette: the box edges between a face C is beyond and one it is not. Each bounds the samples by its
     * plane through C (normal n = corner x step, turned towards the box's centre): n . (x, y, 1) >= 0, a bound
     * on x per row (x >= or <= slope * y + offset by the sign of n_x). One parallel to the rows (n_x = 0: an edge
     * along a light axis) bounds the rows, at the lowest or highest corner, which the corners' box already does. */
    unsigned beyond_lo[3], beyond_hi[3];
    for (int a = 0; a < 3; a++) {
        beyond_lo[a] = l16_lt(L->c[a], l16_set1(b[a]));
        beyond_hi[a] = l16_gt(L->c[a], l16_set1(b[3 + a]));
    }
    l16 mid[3];
    for (int r = 0; r < 3; r++)
        mid[r] = l16_add(p[0][r], l16_mul(l16_set1(0.5f), l16_add(l16_add(d[0][r], d[1][r]), d[2][r])));
    float slope[BR_BOX_EDGES][MS_BLOCK_LANES], offset[BR_BOX_EDGES][MS_BLOCK_LANES];
    unsigned lower[BR_BOX_EDGES], upper[BR_BOX_EDGES], bad = 0;
    int ne = 0;
    const l16 tiny = l16_set1(BR_BOX_MIN_SIN2);
    for (int a = 0; a < 3; a++) {
        const int ab = (a + 1) % 3, ac = (a + 2) % 3;
        for (int q = 0; q < 4; q++) {
            const int sb = q & 1, sc = q >> 1;
            const unsigned sil = go & ((sb ? beyond_hi[ab] : beyond_lo[ab]) ^ (sc ? beyond_hi[ac] : beyond_lo[ac]));
            if (!sil) continue;
            const l16 *p0 = p[sb << ab | sc << ac], *p1 = p[sb << ab | sc << ac | 1 << a], *da = d[a];
            l16 n[3] = { l16_sub(l16_mul(p0[1], da[2]), l16_mul(p0[2], da[1])),
                         l16_sub(l16_mul(p0[2], da[0]), l16_mul(p0[0], da[2])),
                         l16_sub(l16_mul(p0[0], da[1]), l16_mul(p0[1], da[0])) };
            const l16 side = l16_add(l16_add(l16_mul(n[0], mid[0]), l16_mul(n[1], mid[1])), l16_mul(n[2], mid[2]));
            const unsigned flip = l16_lt(side, zero);
            for (int r = 0; r < 3; r++) n[r] = l16_select(flip, l16_sub(zero, n[r]), n[r]);
            const l16 nn = l16_add(l16_add(l16_mul(n[0], n[0]), l16_mul(n[1], n[1])), l16_mul(n[2], n[2]));
            const l16 l0 = l16_add(l16_add(l16_mul(p0[0], p0[0]), l16_mul(p0[1], p0[1])), l16_mul(p0[2], p0[2]));
            const l16 l1 = l16_add(l16_add(l16_mul(p1[0], p1[0]), l16_mul(p1[1], p1[1])), l16_mul(p1[2], p1[2]));
            bad |= sil & ~(l16_gt(nn, l16_mul(tiny, l16_mul(l0, l1))) & (flip | l16_gt(side, zero)));
            const l16 inv = l16_div(l16_set1(-1.0f), n[0]);
            l16_store(slope[ne], l16_mul(n[1], inv));
            l16_store(offset[ne], l16_mul(n[2], inv));
            lower[ne] = sil & l16_gt(n[0], zero);
            upper[ne++] = sil & l16_lt(n[0], zero);
        }
    }
    go &= ~bad;
    if (!go) return;
    /* Each pixel's edges into the row loop's five lower and five upper bounds (a convex polygon of six edges has
     * at most five on either side); the unused ones neutral. */
    ms_scan_lanes v;
    for (int i = 0; i < 5; i++) {
        l16_store(v.al[i], zero);
        l16_store(v.bl[i], zero);
        l16_store(v.au[i], zero);
        l16_store(v.bu[i], l16_set1((float)(MS_K - 1)));
    }
    int nl[MS_BLOCK_LANES] = { 0 }, nu[MS_BLOCK_LANES] = { 0 };
    for (int i = 0; i < ne; i++) {
        for (unsigned m = lower[i] & go; m; m &= m - 1) {
            const int e = __builtin_ctz(m);
            if (nl[e] == 5) { go &= ~(1u << e); continue; }
            v.al[nl[e]][e] = slope[i][e];
            v.bl[nl[e]++][e] = offset[i][e];
        }
        for (unsigned m = upper[i] & go; m; m &= m - 1) {
            const int e = __builtin_ctz(m);
            if (nu[e] == 5) { go &= ~(1u << e); continue; }
            v.au[nu[e]][e] = slope[i][e];
            v.bu[nu[e]++][e] = offset[i][e];
        }
    }
    for (unsigned m = go; m; m &= m - 1) {
        const int e = __builtin_ctz(m);
        if (iy0[e] > iy1[e]) continue;
        v.y0[e] = iy0[e];
        v.y1[e] = iy1[e];
        L->c_rast++;
        L->rasterized |= 1u << e;
        if (in->lane_rast) in->lane_rast[e]++;
        s->rows5(&v, e, in->buf[e]);
    }
}
