/* The SIMD Scanline kernel's set-up for many (triangle, pixel) pairs at once, one pair per lane: the part of
 * the block traversal (block_raster_impl.h) that turns the pairs that passed the leaf tests into the
 * kernel's row data. Included by block_raster_impl.h once per ISA instance, after lanes16.h for the
 * includer's target. */
#ifndef MS_BLOCK_SETUP_H
#define MS_BLOCK_SETUP_H
#include "visibility/lanes16.h"
#include "raster/raster_internal.h"
#include "block_traverse.h"   /* MS_BLOCK_LANES */

_Static_assert(MS_SCAN_LANES == MS_BLOCK_LANES, "the set-up's lanes are the traversal's");
/* The lanes' Scanline set-ups of one triangle, the output of br_scan_setup: edges 0..2 the triangle's,
 * 3 and 4 the near and far clip edges (filled only for the lanes of `clip`). */
typedef struct br_setup {
    ms_scan_lanes v;     /* the row loop's data per lane */
    unsigned rows;       /* lanes with scanlines to clear */
    unsigned clip;       /* of those, the lanes whose row loop takes the five edges */
    unsigned kernel;     /* lanes left to the kernel: an edge parallel to the scanlines, a non-finite
                          * length (rare) */
} br_setup;

/* The triangle's own part of the set-up, per lane (the packed layout: one triangle per lane; the pixel
 * layout: one triangle in every lane): the world edges w[i] = P_{i+2} - P_{i+1}, their squared lengths
 * (the kernel's lanes 4..6) and the plane normal from the two shortest edges (the longest edge's
 * candidate, ties to the lower index), with the kernel's operations. */
typedef struct br_tri {
    l16 w[3][3], el[3], nw[3];
} br_tri;

static inline void br_tri_lanes(const l16 v[3][3], br_tri *t)
{
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) t->w[i][j] = l16_sub(v[(i + 2) % 3][j], v[(i + 1) % 3][j]);
        t->el[i] = l16_add(l16_add(l16_mul(t->w[i][0], t->w[i][0]), l16_mul(t->w[i][1], t->w[i][1])), l16_mul(t->w[i][2], t->w[i][2]));
    }
    const unsigned ge01 = l16_le(t->el[1], t->el[0]), ge02 = l16_le(t->el[2], t->el[0]), ge12 = l16_le(t->el[2], t->el[1]);
    const unsigned long0 = ge01 & ge02, long1 = ~ge01 & ge12;   /* else edge 2 */
    l16 sa[3], sb[3];
    for (int j = 0; j < 3; j++) {
        sa[j] = l16_select(long0, t->w[1][j], l16_select(long1, t->w[2][j], t->w[0][j]));
        sb[j] = l16_select(long0, t->w[2][j], l16_select(long1, t->w[0][j], t->w[1][j]));
    }
    t->nw[0] = l16_sub(l16_mul(sa[1], sb[2]), l16_mul(sa[2], sb[1]));
    t->nw[1] = l16_sub(l16_mul(sa[2], sb[0]), l16_mul(sa[0], sb[2]));
    t->nw[2] = l16_sub(l16_mul(sa[0], sb[1]), l16_mul(sa[1], sb[0]));
}

/* Issue #29 item 2, "set up each triangle once per block": the SIMD Scanline kernel's set-up
 * (scanline_simd_impl.h, ms_scan_vec_setup, clip-free instance) laid out with one pixel per lane instead
 * of one vertex or edge per lane, so that a triangle that several pixels of the block rasterize is set up
 * for all of them in one pass and each pixel runs only the kernel's row loop (ms_raster_rows). Every
 * value is computed with the kernel's operations in the kernel's order (lanes16.h: one IEEE operation
 * per lane, no FMA; the kernel's mul + add, its division y / z for the box where the leaf test above
 * multiplies by 1 / z), and every choice the kernel makes with a mask (shortest sides, nearest vertex,
 * longest edge, lower or upper bound) is the same comparison here, so each lane's ms_scan_vec is the
 * kernel's bit for bit and so is the buffer (test_block_traverse compares the masks with the per-pixel
 * traversal's, which calls the kernel). What the kernel does rarely stays with it: a lane whose triangle
 * reaches the near or far plane (clip edges), has an edge parallel to the scanlines, or has a non-finite
 * length goes to the kernel. The world edges and the plane normal do not depend on the pixel: they are
 * computed once, in scalar form with the same operations.
 * x, y, z: the vertices' light-index coordinates per lane, zmin / zmax their widened depth range (the
 * leaf test's, the kernel's operations); a[v][j] the world vectors P_v - C. */
static inline void br_scan_setup(unsigned lanes, const l16 a[3][3], const br_tri *tr, const l16 mt[3][3], l16 near_l,
                                 l16 far_l, const l16 x[3], const l16 y[3], const l16 z[3], l16 zmin, l16 zmax, int k,
                                 br_setup *o)
{
    const l16 zero = l16_set1(0.0f), kf = l16_set1((float)k);
    /* The lanes whose triangle reaches the near resp. far plane: the kernel's clip edges N and F. */
    const unsigned clip_n = lanes & l16_lt(zmin, near_l), clip_f = lanes & l16_gt(zmax, far_l);
    unsigned kernel = 0;
    const l16 (*w)[3] = tr->w, *el = tr->el, *nw = tr->nw;
    l16 len[3];
    for (int v = 0; v < 3; v++) {
        len[v] = l16_add(l16_add(l16_mul(a[v][0], a[v][0]), l16_mul(a[v][1], a[v][1])), l16_mul(a[v][2], a[v][2]));
        kernel |= lanes & ~l16_le(len[v], l16_set1(3.4e38f));   /* NaN or infinite: the kernel decides */
    }
    /* The edge equations: edge i from the two shortest sides of (C, P_{i+1}, P_{i+2}). */
    l16 ex[5], ey[5], ez[5];
    for (int i = 0; i < 3; i++) {
        const int ia = (i + 1) % 3, ib = (i + 2) % 3;
        const l16 wl = el[i];
        const unsigned va_longest = l16_le(len[ib], len[ia]) & l16_le(wl, len[ia]);
        const unsigned e_longest = ~va_longest & l16_le(len[ib], wl);
        l16 X[3], Y[3];
        for (int j = 0; j < 3; j++) {
            X[j] = l16_select(va_longest, a[ib][j], a[ia][j]);
            Y[j] = l16_select(e_longest, a[ib][j], w[i][j]);
        }
        const l16 ux = l16_sub(l16_mul(X[1], Y[2]), l16_mul(X[2], Y[1]));
        const l16 uy = l16_sub(l16_mul(X[2], Y[0]), l16_mul(X[0], Y[2]));
        const l16 uz = l16_sub(l16_mul(X[0], Y[1]), l16_mul(X[1], Y[0]));
        l16 e[3];
        for (int r = 0; r < 3; r++)
            e[r] = l16_add(l16_add(l16_mul(mt[r][0], ux), l16_mul(mt[r][1], uy)), l16_mul(mt[r][2], uz));
        ex[i] = e[0]; ey[i] = e[1]; ez[i] = e[2];
    }
    /* The plane normal from the two shortest edges (the longest edge's candidate, ties to the lower
     * index) and D from the vertex nearest C (ties to the lower index), as the kernel picks them. */
    const unsigned n0 = l16_le(len[0], len[1]) & l16_le(len[0], len[2]);
    const unsigned n1 = ~l16_le(len[0], len[1]) & l16_le(len[1], len[2]);
    l16 an[3];
    for (int j = 0; j < 3; j++) an[j] = l16_select(n0, a[0][j], l16_select(n1, a[1][j], a[2][j]));
    const l16 d = l16_add(l16_add(l16_mul(an[0], nw[0]), l16_mul(an[1], nw[1])), l16_mul(an[2], nw[2]));
    /* D = 0: the plane contains C, nothing to rasterize (nor for NaN). */
    unsigned live = lanes & ~kernel & (l16_lt(d, zero) | l16_gt(d, zero));
    const unsigned dneg = l16_lt(d, zero);
    const l16 flat = l16_set1(MS_FLAT_EDGE), minus1 = l16_set1(-1.0f);
    /* The clip edges (the kernel's lanes 3 and 4): N = -(near s_x, near s_y, near s_z - D) and
     * F = (far s_x, far s_y, far s_z - D) with s = M^T of the normal, unflipped like the kernel's; the
     * negation as a product by -1, exact and with the sign of zero the kernel's sign flip gives. Where a
     * lane needs only one, the other is the constant edge (0, 0, 1), which clips nothing. */
    const unsigned clip = live & (clip_n | clip_f);
    int n_edges = 3;
    if (clip) {
        l16 sn[3];
        for (int r = 0; r < 3; r++)
            sn[r] = l16_add(l16_add(l16_mul(mt[r][0], nw[0]), l16_mul(mt[r][1], nw[1])), l16_mul(mt[r][2], nw[2]));
        const l16 nearv = near_l, farv = far_l, onev = l16_set1(1.0f);
        ex[3] = l16_select(clip_n, l16_mul(l16_mul(nearv, sn[0]), minus1), zero);
        ey[3] = l16_select(clip_n, l16_mul(l16_mul(nearv, sn[1]), minus1), zero);
        ez[3] = l16_select(clip_n, l16_mul(l16_sub(l16_mul(nearv, sn[2]), d), minus1), onev);
        ex[4] = l16_select(clip_f, l16_mul(farv, sn[0]), zero);
        ey[4] = l16_select(clip_f, l16_mul(farv, sn[1]), zero);
        ez[4] = l16_select(clip_f, l16_sub(l16_mul(farv, sn[2]), d), onev);
        n_edges = 5;
    }
    for (int i = 0; i < n_edges && live; i++) {
        /* The lanes where edge i is the triangle's or a clip edge in use (the constant edge is never
         * flipped, never negative). */
        const unsigned used = i < 3 ? 0xFFFFu : i == 3 ? clip_n : clip_f;
        const l16 r = l16_div(minus1, ex[i]);
        const l16 ax = l16_mul(l16_abs(ex[i]), kf), ay = l16_mul(l16_abs(ey[i]), kf), az = l16_abs(ez[i]);
        const unsigned steep = l16_gt(ax, l16_mul(flat, l16_max(ay, az)));
        const unsigned flat_y = ~steep & l16_gt(ay, l16_mul(flat, az));
        kernel |= live & flat_y;
        /* Constant and negative over the buffer (after the two-sided flip by D's sign): nothing. */
        const unsigned neg = used & ((dneg & l16_gt(ez[i], zero)) | (~dneg & l16_lt(ez[i], zero)));
        live &= ~flat_y & ~(~steep & neg);
        const unsigned lower = steep & ((dneg & l16_lt(ex[i], zero)) | (~dneg & l16_gt(ex[i], zero)));
        const unsigned upper = steep & ~lower;
        const l16 av = l16_mul(ey[i], r), bv = l16_mul(ez[i], r);
        l16_store(o->v.al[i], l16_select(lower, av, zero));
        l16_store(o->v.bl[i], l16_select(lower, bv, zero));
        l16_store(o->v.au[i], l16_select(upper, av, zero));
        l16_store(o->v.bu[i], l16_select(upper, bv, l16_set1((float)k - 1.0f)));
    }
    /* Scanline range: the box of the projected vertices when in front of C (the kernel's division),
     * else the whole buffer. */
    const unsigned front = live & l16_gt(zmin, zero);
    l16 y0 = zero, y1 = l16_set1((float)k - 1.0f);
    if (front) {
        const l16 slack = l16_set1(MS_BOX_SLACK);
        l16 px[3], py[3];
        for (int v = 0; v < 3; v++) { px[v] = l16_div(x[v], z[v]); py[v] = l16_div(y[v], z[v]); }
        const l16 ylo = l16_min(l16_max(l16_sub(l16_min(l16_min(py[0], py[1]), py[2]), slack), minus1), kf);
        const l16 yhi = l16_min(l16_max(l16_add(l16_max(l16_max(py[0], py[1]), py[2]), slack), minus1), kf);
        const l16 xlo = l16_min(l16_max(l16_sub(l16_min(l16_min(px[0], px[1]), px[2]), slack), minus1), kf);
        const l16 xhi = l16_min(l16_max(l16_add(l16_max(l16_max(px[0], px[1]), px[2]), slack), minus1), kf);
        const l16 iy0 = l16_max(l16_ceil(ylo), zero), iy1 = l16_min(l16_floor(yhi), l16_set1((float)k - 1.0f));
        const l16 ix0 = l16_max(l16_ceil(xlo), zero), ix1 = l16_min(l16_floor(xhi), l16_set1((float)k - 1.0f));
        live &= ~(front & (l16_gt(iy0, iy1) | l16_gt(ix0, ix1)));
        y0 = l16_select(front, iy0, y0);
        y1 = l16_select(front, iy1, y1);
    }
    l16_store_int(o->v.y0, y0);
    l16_store_int(o->v.y1, y1);
    o->rows = live;
    o->clip = live & clip;
    o->kernel = kernel;
}

#endif
