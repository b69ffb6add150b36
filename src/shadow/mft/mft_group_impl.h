/* Method mft in the interleaved mode (Benthin & Wald 2009, sec. 4.5): the tracer of a block's ray groups
 * (mft.h, ms_mft_rayblock), one source compiled per ISA (mft_scalar.c, mft_avx2.c, mft_avx512.c) with
 * lanes16.h for the file's target; defines ms_mft_groups_<isa>.
 *
 * A group is the up to 16 rays of one cell of the light, one from each pixel of a 4x4 block (mft.c): 16
 * receivers close together to 16 points in 1/16 of the light (256 samples; 1/64 at 1024). Sixteen groups
 * are sixteen SIMD lanes of the multi-frusta traversal (block_traverse_loop.h, with mftg_children carrying
 * each lane's rays down the walk), each bounded by the box of its live rays' origins and the box of their sample points
 * (ms_block_frusta_set_lane_box; the 16 lanes at once where a group starts from its cell's box), tested
 * 16 lanes at once where 4 or more lanes reach a node (MFTG_FRUSTUM_MIN); below the frusta each lane's
 * rays take raytrace's slab test, 16 in one register, at every child its frustum reaches (the child's
 * sides relative to the 16 receivers formed once for all lanes), and go on with the rays that enter; in
 * a leaf, per triangle:
 *   1. where 8 or more groups reach it, culling of them all at once: the triangle's box against each
 *      group's segments (the traversal's own interval test), and its plane against the boxes of origins
 *      and points (every segment wholly on one side, or meeting the plane only before the near end);
 *   2. the triangle relative to each of the 16 receivers and its plane offset (ms_wt_offset), once per
 *      triangle, one receiver per SIMD lane;
 *   3. per surviving group, its 16 rays in one SIMD operation: method raytrace's watertight test
 *      (raytrace_impl.h, packet_triangle) with each ray's own shear axis (its pixel's packet's) and
 *      shear, operation for operation, so every ray gets raytrace's answer; one bit per ray, a hit clears
 *      it (in the group and in its pixel's mask); a group with no live ray leaves the traversal.
 * A group's boxes are not recomputed after a leaf in which it lost rays (the paper's CR, frustum shrinking:
 * with the groups starting from their cell's box, the recomputation per group and leaf cost more than the
 * tighter boxes saved), a departure from the paper.
 *
 * Departures from the paper, and why:
 *  - the paper traces one frustum per pixel, its 16 rays (one interleaved set) spread over the whole light,
 *    so each frustum spans the whole light and culls little (measured: many times raytrace's ray tests,
 *    docs/notebook/2026-11-29-source-comment-figures.md). Grouping the same 256 rays of a block by cell
 *    instead gives 16 frusta each 1/4 of the light across, from a 4x4-pixel patch of receivers: the rays
 *    and the answers are the same;
 *  - a group has 16 apexes, so it has no corner rays: the paper's corner-ray culling (the triangle's edge
 *    planes through the apex) is replaced by the triangle-box and plane tests of step 1, which hold for a
 *    box of apexes; the paper's back-face culling is not used (shadows need both sides);
 *  - the per-ray box test at every node (the paper's "Ray-AABB" at the leaves only, which did not pay on
 *    Larrabee): a group's rays are a quarter of the light apart, wider than small triangles, so its
 *    frustum alone reached about 10x the leaves its rays enter;
 *  - the rays are formed once per block (not on demand from delta vectors): the exact agreement with
 *    raytrace needs its shear (one division per ray) and its shared packet axis.
 * Culling is conservative: each test carries a relative slack of 1e-5 of the magnitudes involved (about
 * 170 float ulps), far above the watertight test's own error (a few ulps of the vertices' distance). */
#include <math.h>
#include <string.h>
#include "mft.h"
#include "visibility/lanes16.h"
#include "core/perk.h"
#include "accel/ray_triangle.h"
#include "visibility/alpha.h"

#define MFTG_REL 1e-5f
/* The groups at a triangle from which it is culled for all at once: with one or two groups the cull costs
 * more than it saves; 8 measured a little faster than 4, and never culling slower (figures:
 * docs/notebook/2026-11-29-source-comment-figures.md). */
#define MFTG_TRI_CULL 8
/* The frusta's node test for 16 lanes at once only where MFTG_FRUSTUM_MIN or more lanes reach the parent;
 * with fewer, their per-ray tests alone are cheaper (measured against always and never). Where the frusta
 * were not tested, the children are ordered along the block's direction to the light; where they were, by
 * the frusta's majority vote on the entry distances. */
#define MFTG_FRUSTUM_MIN 4
#define MFTG_TINY 1e-30f   /* block_traverse.c's stand-in for a zero direction bound (1/TINY finite) */

typedef struct mftg_state {
    ms_block_frusta *fr;
    uint64_t *bt_cnt;
    const ms_mft_frame *f;
    ms_mft_rayblock *rb;
    const ms_bvh *b;
    ms_mft_group *grp[MS_BLOCK_LANES];   /* the group of each lane */
    /* Per lane: its origins' box and its points' box (centre and half extent), and a magnitude. */
    float oc[3][MS_BLOCK_LANES], oh[3][MS_BLOCK_LANES], pc[3][MS_BLOCK_LANES], ph[3][MS_BLOCK_LANES];
    float mag[MS_BLOCK_LANES];
    float dir[3];                        /* from the receivers' box to the light's centre: the children's order */
    float c[3][MS_BLOCK_LANES];          /* the receivers, one per lane (slot q) */
    float olo[3][MS_BLOCK_LANES], ohi[3][MS_BLOCK_LANES];   /* them shifted by raytrace's box margin */
} mftg_state;

/* Child box n against the 16 receivers (slot q in lane q), shared by every group at it: the box's sides
 * relative to each receiver shifted by raytrace's box margin (A: bmin - olo, B: bmax - ohi), the first
 * operations of raytrace's slab test (raytrace_impl.h, packet_enters), formed once per child instead of
 * once per group. */
static inline void mftg_box_sides(const mftg_state *s, const ms_bvh_node *n, l16 A[3], l16 B[3])
{
    for (int a = 0; a < 3; a++) {
        A[a] = l16_sub(l16_set1(n->bmin[a]), l16_load(s->olo[a]));
        B[a] = l16_sub(l16_set1(n->bmax[a]), l16_load(s->ohi[a]));
    }
}

/* Of the rays of group g (bits), those that enter the box whose sides are A, B (mftg_box_sides), given the
 * group's reciprocal directions inv: method raytrace's box test (raytrace_impl.h, packet_enters) per ray, its
 * widened box and Ize's factor, so it never drops a ray that raytrace's triangle test finds blocked by a
 * triangle in the box. */
static inline unsigned mftg_ray_box(const mftg_state *s, const l16 inv[3], const l16 A[3], const l16 B[3], unsigned bits)
{
    l16 t0 = l16_set1(s->f->near), t1 = l16_set1(s->f->far);
    for (int a = 0; a < 3; a++) {
        const l16 x = l16_mul(A[a], inv[a]), y = l16_mul(B[a], inv[a]);
        /* raytrace's compares: mn = x < y ? x : y, mx = x < y ? y : x (= y > x ? y : x, l16_max(y, x));
         * a NaN leaves t0, t1 as they were */
        t0 = l16_max(l16_min(x, y), t0);
        t1 = l16_min(l16_max(y, x), t1);
    }
    return l16_le(t0, l16_mul(t1, l16_set1(MS_WT_FAR_SCALE))) & bits;
}

/* Lane l's frustum from the box of its origins and the box of its points. */
static void mftg_lane_set(mftg_state *s, int l, const float clo[3], const float chi[3], const float plo[3], const float phi[3])
{
    float mag = 0.0f;
    for (int a = 0; a < 3; a++) {
        s->oc[a][l] = 0.5f * (clo[a] + chi[a]);
        s->oh[a][l] = 0.5f * (chi[a] - clo[a]);
        s->pc[a][l] = 0.5f * (plo[a] + phi[a]);
        s->ph[a][l] = 0.5f * (phi[a] - plo[a]);
        for (int e = 0; e < 4; e++) { const float x = fabsf(e == 0 ? clo[a] : e == 1 ? chi[a] : e == 2 ? plo[a] : phi[a]); mag = x > mag ? x : mag; }
    }
    s->mag[l] = mag;
    ms_block_frusta_set_lane_box(s->fr, l, clo, chi, plo, phi, MFTG_REL);
}

/* The lanes `full` of the 16 groups from g0 (rb->n a multiple of 16): their frusta from the box of the
 * present receivers (lo, hi) and their cells' boxes of points, 16 lanes at once with mftg_lane_set's and
 * ms_block_frusta_set_lane_box's operations (it was 6 scalar divisions per lane). */
static void mftg_lanes_set_cells(mftg_state *s, int g0, unsigned full, const float lo[3], const float hi[3])
{
    ms_block_frusta *fr = s->fr;
    const float *cb = s->rb->cell_box;
    const size_t nc = (size_t)s->rb->n;
    const l16 half = l16_set1(0.5f), zero = l16_set1(0.0f), one = l16_set1(1.0f), slack = l16_set1(MFTG_REL * 2.0f);
    const l16 tiny = l16_set1(MFTG_TINY), ntiny = l16_set1(-MFTG_TINY);
    l16 mag = zero;
    for (int a = 0; a < 3; a++) {
        const l16 clo = l16_set1(lo[a]), chi = l16_set1(hi[a]);
        const l16 plo = l16_load(cb + (size_t)a * nc + g0), phi = l16_load(cb + (size_t)(3 + a) * nc + g0);
        l16_store(s->oc[a], l16_mul(half, l16_add(clo, chi)));
        l16_store(s->oh[a], l16_mul(half, l16_sub(chi, clo)));
        l16_store(s->pc[a], l16_mul(half, l16_add(plo, phi)));
        l16_store(s->ph[a], l16_mul(half, l16_sub(phi, plo)));
        const l16 ma = l16_max(l16_max(l16_abs(clo), l16_abs(chi)), l16_max(l16_abs(plo), l16_abs(phi)));
        mag = l16_max(ma, mag);
        l16 dlo = l16_sub(l16_sub(plo, clo), l16_mul(slack, ma)), dhi = l16_add(l16_sub(phi, chi), l16_mul(slack, ma));
        dlo = l16_select(l16_le(dlo, zero) & ~l16_lt(dlo, zero), ntiny, dlo);   /* 0: -TINY */
        dhi = l16_select(l16_le(dhi, zero) & ~l16_lt(dhi, zero), tiny, dhi);
        l16_store(fr->c[a], clo);
        l16_store(fr->chi[a], chi);
        l16_store(fr->rlo[a], l16_div(one, dlo));
        l16_store(fr->rhi[a], l16_div(one, dhi));
        fr->pos_hi[a] = (fr->pos_hi[a] & ~full) | (l16_gt(dhi, zero) & full);
        fr->neg_lo[a] = (fr->neg_lo[a] & ~full) | (l16_lt(dlo, zero) & full);
    }
    l16_store(s->mag, mag);
    fr->live |= full;
}

/* Lane l's frustum from its group's live rays. */
static void mftg_lane_bounds(mftg_state *s, int l)
{
    const ms_mft_group *g = s->grp[l];
    const ms_mft_rayblock *rb = s->rb;
    float clo[3], chi[3], plo[3], phi[3];
    for (int a = 0; a < 3; a++) { clo[a] = plo[a] = INFINITY; chi[a] = phi[a] = -INFINITY; }
    for (unsigned m = g->live; m; m &= m - 1) {
        const int q = __builtin_ctz(m);
        for (int a = 0; a < 3; a++) {
            const float c = rb->c[a][q], p = g->p[a][q];
            clo[a] = c < clo[a] ? c : clo[a];
            chi[a] = c > chi[a] ? c : chi[a];
            plo[a] = p < plo[a] ? p : plo[a];
            phi[a] = p > phi[a] ? p : phi[a];
        }
    }
    mftg_lane_set(s, l, clo, chi, plo, phi);
}

static void mftg_leaf(mftg_state *s, const ms_bvh_node *n, unsigned mask, const uint16_t *enter);

/* Of the lanes ml (mr) whose frustum reaches child c[0] (c[1]), those with rays entering it (rl[l], rr[l]: the
 * rays; rays[l]: those that entered the parent). Both children in one pass over the lanes, which load their
 * group's directions once. */
static inline void mftg_child_rays(const mftg_state *s, const ms_bvh_node *c, unsigned *ml, unsigned *mr,
                                   const uint16_t *rays, uint16_t *rl, uint16_t *rr, uint64_t *ray_tests, uint64_t *culled)
{
    const unsigned m0 = *ml, m1 = *mr;
    if (!(m0 | m1)) return;
    l16 A0[3], B0[3], A1[3], B1[3];
    mftg_box_sides(s, &c[0], A0, B0);
    mftg_box_sides(s, &c[1], A1, B1);
    /* Both tests for every lane at either child, and no branch on their outcome: which lanes' rays enter
     * is data, and a branch on it mispredicts; a lane at one child only costs one unneeded test. */
    unsigned o0 = 0, o1 = 0;
    for (unsigned r = m0 | m1; r; r &= r - 1) {
        const int l = __builtin_ctz(r);
        const ms_mft_group *g = s->grp[l];
        const l16 inv[3] = { l16_load(g->inv[0]), l16_load(g->inv[1]), l16_load(g->inv[2]) };
        const unsigned bits = g->live & rays[l];
        const unsigned h0 = mftg_ray_box(s, inv, A0, B0, bits), h1 = mftg_ray_box(s, inv, A1, B1, bits);
        rl[l] = (uint16_t)h0;
        rr[l] = (uint16_t)h1;
        o0 |= (unsigned)(h0 != 0) << l;
        o1 |= (unsigned)(h1 != 0) << l;
    }
    o0 &= m0;
    o1 &= m1;
    *ray_tests += (uint64_t)(ms_bt_popcount16(m0) + ms_bt_popcount16(m1));
    *culled += (uint64_t)(ms_bt_popcount16(m0 & ~o0) + ms_bt_popcount16(m1 & ~o1));
    *ml = o0;
    *mr = o1;
}

/* The children of a node for the walk of block_traverse_loop.h, with each lane's rays: a child is visited for
 * the lanes whose frustum may reach it (all 16 at once) and, of those, whose rays enter it (one 16-ray box test
 * per lane, raytrace's). The frusta cull the upper levels for 16 groups at a time; the rays the lower ones,
 * where a group's frustum, however thin on the light, is wide against small triangles (measured: when only
 * the leaves tested the rays, about ten lane-leaf visits per leaf the rays enter). Departure from the paper
 * (frusta only). */
static inline void mftg_children(const mftg_state *s, const ms_bvh_node *c, unsigned mask, int order, unsigned *ml_out,
                                 unsigned *mr_out, int *right_first, const uint16_t *rays, uint16_t *rl, uint16_t *rr,
                                 uint64_t *tests, uint64_t *ray_tests, uint64_t *lanes_culled);

#define BT_STATE mftg_state
#define BT_FN mftg_traverse
#define BT_LEAF(s, n, mask) mftg_leaf(s, n, mask, rays)
#define BT_CHILDREN(s, c, mask, order, ml, mr, right_first) \
    mftg_children(s, c, mask, order, &(ml), &(mr), &(right_first), rays, rl, rr, &tests, &ray_tests, &lanes_culled)
#define BT_RAYS
#define BT_ROOT_RAYS(s, rays) \
    for (int l_ = 0; l_ < MS_BLOCK_LANES; l_++) (rays)[l_] = (uint16_t)((s)->grp[l_] ? (s)->grp[l_]->live : 0u)
#define BT_LOCALS uint64_t ray_tests = 0, lanes_culled = 0;
#define BT_DONE(s) (cnt[MS_MFT_RAY_BOX] += ray_tests, cnt[MS_MFT_LEAF_LANES_CULLED] += lanes_culled)
#include "shadow/microraster/block_traverse_loop.h"
#undef BT_STATE
#undef BT_FN
#undef BT_LEAF
#undef BT_CHILDREN
#undef BT_RAYS
#undef BT_ROOT_RAYS
#undef BT_LOCALS
#undef BT_DONE

static inline void mftg_children(const mftg_state *s, const ms_bvh_node *c, unsigned mask, int order, unsigned *ml_out,
                                 unsigned *mr_out, int *right_first, const uint16_t *rays, uint16_t *rl, uint16_t *rr,
                                 uint64_t *tests, uint64_t *ray_tests, uint64_t *lanes_culled)
{
    const ms_block_frusta *f = s->fr;
    l16 t0 = l16_set1(0.0f), t1 = t0;
    const int fr_test = ms_bt_popcount16(mask) >= MFTG_FRUSTUM_MIN;
    unsigned ml = mask, mr = mask;
    if (fr_test) {
        ml &= mftg_traverse_node(f, &c[0], &t0);
        mr &= mftg_traverse_node(f, &c[1], &t1);
        *tests += 2;
    }
    mftg_child_rays(s, c, &ml, &mr, rays, rl, rr, ray_tests, lanes_culled);
    *right_first = 0;
    if (ml && mr && order) {
        if (!fr_test) {
            float dot = 0.0f;
            for (int x = 0; x < 3; x++) dot += (c[1].bmin[x] + c[1].bmax[x] - c[0].bmin[x] - c[0].bmax[x]) * s->dir[x];
            *right_first = dot < 0.0f;
        } else {
            const unsigned both = ml & mr;
            *right_first = 2 * ms_bt_popcount16(l16_lt(t1, t0) & both) > ms_bt_popcount16(both);
        }
    }
    *ml_out = ml;
    *mr_out = mr;
}

/* The triangle's rays of group g (bits: its live slots, less those whose own triangle this is) that it
 * blocks: raytrace's packet_triangle per ray, the same operations in the same order, with the ray's own
 * shear axis. V[v][x]: the vertices relative to each slot's receiver (x: world axis); num: ms_wt_offset per
 * slot. */
static unsigned mftg_rays(const mftg_state *s, const ms_mft_group *g, unsigned bits, const float *tri, const float N[3],
                          const l16 V[3][3], l16 num, const float *numv)
{
    const ms_mft_frame *f = s->f;
    const unsigned alone = bits & g->alone;
    unsigned hit = 0;
    if (alone) {   /* slots whose packet shares no axis: each ray its own (ms_wt_segment, 16 lanes at once) */
        const l16 dir[3] = { l16_load(g->d[0]), l16_load(g->d[1]), l16_load(g->d[2]) };
        unsigned z;
        hit = ms_wt_rays16_own(V, dir, N, num, f->near, f->far, alone, &z);
        for (unsigned m = z; m; m &= m - 1) {   /* an edge function exactly 0: in double */
            const int q = __builtin_ctz(m);
            const float o[3] = { s->rb->c[0][q], s->rb->c[1][q], s->rb->c[2][q] }, d[3] = { g->d[0][q], g->d[1][q], g->d[2][q] };
            if (ms_wt_segment(o, d, tri, N, f->near, f->far)) hit |= 1u << q;
        }
    }
    bits &= ~alone;
    if (!bits) return hit;
    /* Per slot, the vertices permuted to its axes (kx, ky, kz cyclic): one permutation when every ray of
     * the group shares kz, else per-slot selects. */
    l16 A[3][3];   /* [vertex][x, y, z] */
    if (g->kz_all >= 0) {
        const int kz = g->kz_all, kx = kz + 1 == 3 ? 0 : kz + 1, ky = kx + 1 == 3 ? 0 : kx + 1;
        for (int v = 0; v < 3; v++) { A[v][0] = V[v][kx]; A[v][1] = V[v][ky]; A[v][2] = V[v][kz]; }
    } else {
        unsigned k0 = 0, k1 = 0;
        for (int q = 0; q < MS_BLOCK_LANES; q++) { k0 |= (unsigned)(g->kz[q] == 0) << q; k1 |= (unsigned)(g->kz[q] == 1) << q; }
        for (int v = 0; v < 3; v++) {
            A[v][0] = l16_select(k0, V[v][1], l16_select(k1, V[v][2], V[v][0]));
            A[v][1] = l16_select(k0, V[v][2], l16_select(k1, V[v][0], V[v][1]));
            A[v][2] = l16_select(k0, V[v][0], l16_select(k1, V[v][1], V[v][2]));
        }
    }
    const l16 dir[3] = { l16_load(g->d[0]), l16_load(g->d[1]), l16_load(g->d[2]) };
    unsigned z;
    hit |= ms_wt_rays16((const l16 (*)[3])A, l16_load(g->sx), l16_load(g->sy), dir, N, num, f->near, f->far, bits, &z);
    /* An edge function exactly 0: redone by the scalar test (in double), as raytrace does (rare). */
    for (unsigned m = z; m; m &= m - 1) {
        const int q = __builtin_ctz(m), kz = g->kz[q];
        float Vq[3][3];
        for (int vv = 0; vv < 3; vv++)
            for (int x = 0; x < 3; x++) Vq[vv][x] = tri[3 * vv + x] - s->rb->c[x][q];
        const float d[3] = { g->d[0][q], g->d[1][q], g->d[2][q] };
        if (ms_wt_segment_sheared(Vq[0], Vq[1], Vq[2], kz, g->sx[q], g->sy[q], d, N, numv[q], f->near, f->far))
            hit |= 1u << q;
    }
    return hit;
}

/* Leaf n for the lanes of mask, whose rays[l] entered its box. */
static void mftg_leaf(mftg_state *s, const ms_bvh_node *n, unsigned mask, const uint16_t *enter)
{
    ms_block_frusta *fr = s->fr;
    const ms_mft_frame *f = s->f;
    ms_mft_rayblock *rb = s->rb;
    uint64_t *cnt = s->bt_cnt;
    /* The slots whose own triangle is in this leaf. */
    uint32_t skip_tri[MS_BLOCK_LANES];
    unsigned skip_slot[MS_BLOCK_LANES];
    int nskip = 0;
    for (int q = 0; q < rb->nq; q++)
        if (rb->skip[q] - n->first < n->count) { skip_tri[nskip] = rb->skip[q]; skip_slot[nskip++] = 1u << q; }
    const l16 zero = l16_set1(0.0f), rel = l16_set1(MFTG_REL);
    l16 oc[3], oh[3], pc[3], ph[3], cq[3];
    for (int a = 0; a < 3; a++) {
        oc[a] = l16_load(s->oc[a]); oh[a] = l16_load(s->oh[a]);
        pc[a] = l16_load(s->pc[a]); ph[a] = l16_load(s->ph[a]);
        cq[a] = l16_load(s->c[a]);
    }
    const l16 lmag = l16_load(s->mag), near = l16_set1(f->near);
    uint64_t pairs = 0, c_box = 0, c_plane = 0, tested = 0, isec = 0, early = 0;
    for (uint32_t t = n->first; t < n->first + n->count; t++) {
        unsigned lanes = mask & fr->live;
        if (!lanes) break;
        pairs += (uint64_t)ms_bt_popcount16(lanes);
        const float *tri = s->b->tri + 9 * (size_t)t, *N = s->b->tri_n + 3 * (size_t)t;
        /* 1. The triangle's box against the groups' segments (the traversal's test), then its plane.
         * Worth its cost (one test for 16 groups) only with several groups at the triangle: measured,
         * with one or two it costs more than their 16-ray tests save. */
        if (ms_bt_popcount16(lanes) >= MFTG_TRI_CULL) {
            ms_bvh_node tb;
            float tmag = 0.0f;
            for (int a = 0; a < 3; a++) {
                const float x = tri[a], y = tri[3 + a], z = tri[6 + a];
                tb.bmin[a] = x < y ? (x < z ? x : z) : (y < z ? y : z);
                tb.bmax[a] = x > y ? (x > z ? x : z) : (y > z ? y : z);
                tmag = fmaxf(tmag, fmaxf(fabsf(tb.bmin[a]), fabsf(tb.bmax[a])));
            }
            l16 tlo;
            const unsigned in_box = mftg_traverse_node(fr, &tb, &tlo) & lanes;
            c_box += (uint64_t)ms_bt_popcount16(lanes & ~in_box);
            lanes = in_box;
            if (!lanes) continue;
            /* a = (C - v) . N over the origins' box, b = (P - v) . N over the points': the vertices' own
             * offsets span [wlo, whi] (N is rounded). A hit needs the segment to cross the plane at t =
             * a / (a - b) in [near, far]: not both ends on one side, and |a| >= near |a - b|. */
            const float nl1 = fabsf(N[0]) + fabsf(N[1]) + fabsf(N[2]);
            float wlo = INFINITY, whi = -INFINITY;
            for (int v = 0; v < 3; v++) {
                const float w = tri[3 * v] * N[0] + tri[3 * v + 1] * N[1] + tri[3 * v + 2] * N[2];
                wlo = w < wlo ? w : wlo;
                whi = w > whi ? w : whi;
            }
            const l16 an[3] = { l16_set1(fabsf(N[0])), l16_set1(fabsf(N[1])), l16_set1(fabsf(N[2])) };
            l16 o = zero, oe = zero, p = zero, pe = zero;
            for (int a = 0; a < 3; a++) {
                const l16 na = l16_set1(N[a]);
                o = l16_add(o, l16_mul(oc[a], na));
                oe = l16_add(oe, l16_mul(oh[a], an[a]));
                p = l16_add(p, l16_mul(pc[a], na));
                pe = l16_add(pe, l16_mul(ph[a], an[a]));
            }
            const l16 tol = l16_mul(l16_mul(l16_max(lmag, l16_set1(tmag)), l16_set1(nl1)), rel);
            const l16 wl = l16_set1(wlo), wh = l16_set1(whi);
            const l16 alo = l16_sub(l16_sub(o, oe), wh), ahi = l16_sub(l16_add(o, oe), wl);
            const l16 blo = l16_sub(l16_sub(p, pe), wh), bhi = l16_sub(l16_add(p, pe), wl);
            const l16 ntol = l16_sub(zero, tol);
            unsigned out = (l16_gt(alo, tol) & l16_gt(blo, tol)) | (l16_lt(ahi, ntol) & l16_lt(bhi, ntol));
            /* a - b = (C - P) . N over both boxes; near: max |a| < near min |a - b|. */
            const l16 dlo = l16_sub(l16_sub(o, oe), l16_add(p, pe)), dhi = l16_sub(l16_add(o, oe), l16_sub(p, pe));
            const unsigned dpos = l16_gt(dlo, zero), dneg = l16_lt(dhi, zero);
            const l16 dmin = l16_select(dpos, dlo, l16_sub(zero, dhi));
            const l16 amax = l16_max(l16_abs(alo), l16_abs(ahi));
            out |= (dpos | dneg) & l16_lt(l16_add(amax, tol), l16_mul(near, l16_sub(dmin, tol)));
            c_plane += (uint64_t)ms_bt_popcount16(lanes & out);
            lanes &= ~out;
            if (!lanes) continue;
        }
        unsigned skip = 0;
        for (int q = 0; q < nskip; q++)
            if (skip_tri[q] == t) skip |= skip_slot[q];
        /* 2. The triangle relative to each receiver (slot q in lane q) and ms_wt_offset, bit for bit. */
        l16 V[3][3];
        for (int v = 0; v < 3; v++)
            for (int x = 0; x < 3; x++) V[v][x] = l16_sub(l16_set1(tri[3 * v + x]), cq[x]);
        const l16 num = ms_wt_offset16((const l16 (*)[3])V, N);
        float numv[MS_BLOCK_LANES];
        l16_store(numv, num);
        /* 3. Each surviving group's rays, 16 in one operation. */
        for (; lanes; lanes &= lanes - 1) {
            const int l = __builtin_ctz(lanes);
            ms_mft_group *g = s->grp[l];
            const unsigned bits = g->live & enter[l] & ~skip;
            tested++;
            if (!bits) continue;
            isec++;
            unsigned hit = mftg_rays(s, g, bits, tri, N, V, num, numv);
            /* An alpha-tested triangle keeps only the rays where it is opaque (alpha.h: the segment from the
             * receiver to the sample point, as every method decides). */
            if (hit && f->alpha && f->alpha->flag[t])
                for (unsigned m = hit; m; m &= m - 1) {
                    const int q = __builtin_ctz(m);
                    const float o[3] = { rb->c[0][q], rb->c[1][q], rb->c[2][q] }, pt[3] = { g->p[0][q], g->p[1][q], g->p[2][q] };
                    if (!ms_alpha_segment_occludes(f->alpha, t, o, pt)) hit &= ~(1u << q);
                }
            if (!hit) continue;
            g->live &= ~hit;
            for (unsigned m = hit; m; m &= m - 1) {
                const int q = __builtin_ctz(m), i = g->sample[q];
                rb->mask[q][i >> 6] &= ~(UINT64_C(1) << (i & 63));
            }
            if (!g->live) { fr->live &= ~(1u << l); early++; }
        }
    }
    cnt[MS_MFT_PAIRS] += pairs;
    cnt[MS_MFT_CULLED_BOX] += c_box;
    cnt[MS_MFT_CULLED_PLANE] += c_plane;
    cnt[MS_MFT_PAIRS_TESTED] += tested;
    cnt[MS_MFT_ISEC16] += isec;
    cnt[MS_MFT_FRUSTA_EARLY_OUT] += early;
}

/* The rays of a block by set (rb->form_n, mft.c: mft_block_by_set), 16 slots at a time with raytrace's
 * operations: d = P - C, 1 / d, each slot packet's shear axis over its 16 samples in sample order
 * (ms_wt_packet_axis), sx = d[kx] * (1 / d[kz]); every lane one IEEE operation (lanes16.h), so the rays are
 * raytrace's floats. */
static void mftg_form(ms_mft_rayblock *rb)
{
    const int n = rb->form_n, ncell = rb->n;
    l16 C[3];
    for (int a = 0; a < 3; a++) C[a] = l16_load(rb->c[a]);
    const l16 one = l16_set1(1.0f);
    for (int c = 0; c < ncell; c++) {
        ms_mft_group *G = &rb->g[c];
        for (int a = 0; a < 3; a++) {
            const l16 P = l16_load(rb->cell_pts + ((size_t)c * 3 + a) * 16), d = l16_sub(P, C[a]);
            l16_store(G->p[a], P);
            l16_store(G->d[a], d);
            l16_store(G->inv[a], l16_div(one, d));
        }
        memcpy(G->sample, rb->sample_of + (size_t)c * 16, sizeof G->sample);
        G->live = 0;
    }
    /* Each group's live slots: a slot's bit where its sample in the group's cell is in its mask. */
    if (n == 16) {   /* a slot's samples are its mask's first 16 bits: only its set bits visited */
        unsigned lv[16] = { 0 }, all = 0xFFFFu;
        for (unsigned pm = rb->present; pm; pm &= pm - 1) all &= (unsigned)rb->mask[__builtin_ctz(pm)][0];
        /* every present slot's 16 samples in its mask (the usual case): every group has all present slots */
        for (unsigned pm = all == 0xFFFFu ? 0u : rb->present; pm; pm &= pm - 1) {
            const int q = __builtin_ctz(pm);
            const int *cell = rb->set_cell + (size_t)q * n;
            for (unsigned m = (unsigned)rb->mask[q][0] & 0xFFFFu; m; m &= m - 1) lv[cell[__builtin_ctz(m)]] |= 1u << q;
        }
        for (int c = 0; c < 16; c++) rb->g[c].live = all == 0xFFFFu ? rb->present : lv[c];
    } else
        for (int c = 0; c < ncell; c++) {
            ms_mft_group *G = &rb->g[c];
            for (unsigned pm = rb->present; pm; pm &= pm - 1) {
                const int q = __builtin_ctz(pm), j = G->sample[q];
                G->live |= (unsigned)(rb->mask[q][j >> 6] >> (j & 63) & 1u) << q;
            }
        }
    /* Each slot's packet axis (ms_wt_packet_axis over its 16-sample packets in sample order). n = 16: one
     * packet per slot, its samples the slot's lane of the 16 groups, so the 16 slots at once: the axis of
     * each slot's first sample, then the packet's test over the groups (an AND: order-free). */
    signed char kz[16][MS_SAMPLES_MAX / 16 / 16];
    const int pref = rb->shear_axis;
    if (n == 16) {
        unsigned k1 = 0, k2 = 0, ok = 0xFFFFu, okp = pref >= 0 ? 0xFFFFu : 0u;
        for (int q = 0; q < 16; q++) {
            const ms_mft_group *G = &rb->g[rb->set_cell[(size_t)q * n]];
            const float d0[3] = { G->d[0][q], G->d[1][q], G->d[2][q] };
            const int k = ms_wt_max_axis(d0);
            k1 |= (unsigned)(k == 1) << q;
            k2 |= (unsigned)(k == 2) << q;
        }
        const l16 two = l16_set1(2.0f), zero = l16_set1(0.0f);
        for (int c = 0; c < ncell; c++) {
            const ms_mft_group *G = &rb->g[c];
            const l16 ax = l16_abs(l16_load(G->d[0])), ay = l16_abs(l16_load(G->d[1])), az = l16_abs(l16_load(G->d[2]));
            const l16 m = l16_max(ax, l16_max(ay, az)), dk = l16_select(k1, ay, l16_select(k2, az, ax));
            ok &= l16_le(m, l16_mul(two, dk)) & l16_gt(m, zero);
            if (pref >= 0) okp &= l16_le(m, l16_mul(two, pref == 0 ? ax : pref == 1 ? ay : az)) & l16_gt(m, zero);
        }
        for (int q = 0; q < 16; q++)
            kz[q][0] = (signed char)(okp >> q & 1 ? pref : !(ok >> q & 1) ? -1 : k1 >> q & 1 ? 1 : k2 >> q & 1 ? 2 : 0);
    } else
        for (int q = 0; q < 16; q++) {
            if (!(rb->present >> q & 1)) continue;
            for (int ch = 0; ch < n / 16; ch++) {
                float dx[16], dy[16], dz[16];
                for (int l = 0; l < 16; l++) {
                    const ms_mft_group *G = &rb->g[rb->set_cell[(size_t)q * n + 16 * ch + l]];
                    dx[l] = G->d[0][q];
                    dy[l] = G->d[1][q];
                    dz[l] = G->d[2][q];
                }
                int k0;
                kz[q][ch] = (signed char)ms_wt_packet_axis(dx, dy, dz, 16, pref, &k0);
            }
        }
    /* n = 16 (256 samples): a slot's 16 samples are one packet, so every group has the slots' axes; they
     * are found once, and each group's common axis from its live slots by masks. */
    signed char kq[16];
    unsigned a1 = 0, a2 = 0, alone = 0;
    if (n == 16)
        for (int q = 0; q < 16; q++) {
            const int k = (rb->present >> q & 1) ? kz[q][0] : 0;
            kq[q] = (signed char)k;
            alone |= (unsigned)(k < 0) << q;
            a1 |= (unsigned)(k == 1) << q;
            a2 |= (unsigned)(k == 2) << q;
        }
    const unsigned a0 = 0xFFFFu & ~(alone | a1 | a2);
    for (int c = 0; c < ncell; c++) {
        ms_mft_group *G = &rb->g[c];
        unsigned k1 = 0, k2 = 0;
        if (n == 16) {
            memcpy(G->kz, kq, sizeof kq);
            G->alone = alone;
            k1 = a1;
            k2 = a2;
            const unsigned lv = G->live & ~alone;
            G->kz_all = !lv || (lv & a0) == lv ? 0 : (lv & a1) == lv ? 1 : (lv & a2) == lv ? 2 : -1;
        } else {
            int kall = -2;
            G->alone = 0;
            for (int q = 0; q < 16; q++) {
                const int k = (rb->present >> q & 1) ? kz[q][G->sample[q] >> 4] : 0;
                G->kz[q] = (signed char)k;
                G->alone |= (unsigned)(k < 0) << q;
                k1 |= (unsigned)(k == 1) << q;
                k2 |= (unsigned)(k == 2) << q;
                if ((G->live >> q & 1) && k >= 0) kall = kall == -2 || kall == k ? k : -1;
            }
            G->kz_all = kall < 0 ? (kall == -2 ? 0 : -1) : kall;
        }
        /* kz = 0: (kx, ky) = (1, 2); 1: (2, 0); 2: (0, 1); a slot without an axis (tested alone) takes 0's. */
        l16 d[3], inv[3];
        for (int a = 0; a < 3; a++) { d[a] = l16_load(G->d[a]); inv[a] = l16_load(G->inv[a]); }
        const l16 ikz = l16_select(k1, inv[1], l16_select(k2, inv[2], inv[0]));
        const l16 dkx = l16_select(k1, d[2], l16_select(k2, d[0], d[1]));
        const l16 dky = l16_select(k1, d[0], l16_select(k2, d[1], d[2]));
        l16_store(G->sx, l16_mul(dkx, ikz));
        l16_store(G->sy, l16_mul(dky, ikz));
    }
}

void MS_CAT(ms_mft_groups_, MS_ISA_SUFFIX)(const ms_mft_frame *f, ms_mft_rayblock *rb, const ms_bvh *b,
                                           const ms_bvh_shallow *sh, uint64_t *cnt)
{
    ms_block_frusta fr;
    mftg_state s;
    memset(&s, 0, sizeof s);
    s.fr = &fr;
    s.bt_cnt = cnt;
    s.f = f;
    s.rb = rb;
    s.b = b;
    if (rb->form_n) mftg_form(rb);
    for (int a = 0; a < 3; a++) memcpy(s.c[a], rb->c[a], sizeof s.c[a]);
    /* Each receiver shifted by raytrace's box margin (ms_wt_box_origins' operations, 16 receivers at once). */
    l16 om = l16_set1(0.0f);
    for (int a = 0; a < 3; a++) {
        const l16 o = l16_load(rb->c[a]);
        om = l16_max(l16_abs(l16_sub(l16_set1(b->nodes[0].bmin[a]), o)), om);
        om = l16_max(l16_abs(l16_sub(l16_set1(b->nodes[0].bmax[a]), o)), om);
        om = l16_max(l16_abs(o), om);
    }
    const l16 oe = l16_mul(om, l16_set1(MS_WT_BOX_REL));
    for (int a = 0; a < 3; a++) {
        l16_store(s.olo[a], l16_add(l16_load(rb->c[a]), oe));
        l16_store(s.ohi[a], l16_sub(l16_load(rb->c[a]), oe));
    }
    /* The box of the present receivers: with the cell's box of points, the starting frustum of every group
     * whose present slots are all live (most of them), without a pass over its rays. Departure from a
     * box of the live rays only (the paper's frustum of its rays): the cell's box holds the points of all
     * 16 sets, so it is at most the cell of the light, and a conservative bound of the group's points. */
    float blo[3] = { INFINITY, INFINITY, INFINITY }, bhi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (unsigned m = rb->present; m; m &= m - 1) {
        const int q = __builtin_ctz(m);
        for (int a = 0; a < 3; a++) {
            blo[a] = rb->c[a][q] < blo[a] ? rb->c[a][q] : blo[a];
            bhi[a] = rb->c[a][q] > bhi[a] ? rb->c[a][q] : bhi[a];
        }
    }
    for (int a = 0; a < 3; a++)
        s.dir[a] = (float)(f->lp[a] + 0.5 * f->ls[a] + 0.5 * f->lt[a]) - 0.5f * (blo[a] + bhi[a]);
    for (int g0 = 0; g0 < rb->n; g0 += MS_BLOCK_LANES) {
        ms_block_frusta_init(&fr, &sh->nodes[0], f->near, f->far);
        memset(s.grp, 0, sizeof s.grp);
        unsigned full = 0;
        for (int l = 0; l < MS_BLOCK_LANES && g0 + l < rb->n; l++) {
            s.grp[l] = &rb->g[g0 + l];
            if (!s.grp[l]->live) continue;
            if (rb->cell_box && s.grp[l]->live == rb->present) full |= 1u << l;
            cnt[MS_MFT_FRUSTA]++;
        }
        if (full) mftg_lanes_set_cells(&s, g0, full, blo, bhi);
        for (int l = 0; l < MS_BLOCK_LANES && g0 + l < rb->n; l++)
            if (s.grp[l]->live && !(full >> l & 1)) mftg_lane_bounds(&s, l);
        if (fr.live) mftg_traverse(&s, sh, f->flags & MS_MFT_ORDER);
    }
}
