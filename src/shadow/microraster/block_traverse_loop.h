/* The multi-frusta traversal loop (block_traverse.h), written once and compiled into each user's
 * per-ISA instances (block_raster_impl.h, mft_impl.h, mft_group_impl.h) with lanes16.h for the includer's
 * target. The includer defines, before including:
 *   BT_STATE       its per-block state type, with members `ms_block_frusta *fr` and `uint64_t *bt_cnt`
 *                  (MS_BT_COUNTERS traversal counters);
 *   BT_LEAF(s, n, mask)  processes leaf n for the lanes of mask; it clears from s->fr->live the lanes
 *                  it finishes (every sample occluded);
 *   BT_FN          the name of the traversal function to define (and BT_FN##_node, the node test, and
 *                  BT_FN##_children, the default child test);
 * and, for a walk that tests more than the frusta at a node (mft's group tracer, whose rays go down with it):
 *   BT_CHILDREN(s, c, mask, order, ml, mr, right_first)  (optional) sets ml and mr, the lanes of mask that go
 *                  on into the children c[0] and c[1] (lvalues), and, where both are non-zero, right_first
 *                  (visit c[1] first); it counts its node tests in the loop's `tests`. Default: both children's
 *                  frustum tests, the nearer first by a majority of the lanes that reach both when order;
 *   BT_RAYS        (optional) a uint16_t per lane carried down the walk: the loop holds `rays` (the current
 *                  node's), `rl` and `rr` (BT_CHILDREN's for the children), stacks them with the nodes, and
 *                  sets the root's by BT_ROOT_RAYS(s, rays); BT_LEAF and BT_CHILDREN may read `rays`;
 *   BT_LOCALS, BT_DONE(s)  (optional) declarations the hooks use, and what to do with them at the end.
 * Depth first. A pushed node keeps its lane mask, which is narrowed on pop to the lanes still live. */
#include "block_traverse.h"
#include "visibility/lanes16.h"
#include <math.h>
#include <string.h>


/* The lanes whose frustum may reach node n, and their lower bound on the segment parameter. */
static inline unsigned MS_CAT(BT_FN, _node)(const ms_block_frusta *f, const ms_bvh_node *n, l16 *tlo_out)
{
    l16 tlo = l16_set1(f->near), thi = l16_set1(f->far);
    const l16 ninf = l16_set1(-INFINITY), pinf = l16_set1(INFINITY);
    for (int a = 0; a < 3; a++) {
        const l16 alo = l16_sub(l16_set1(n->bmin[a] - f->margin), l16_load(f->chi[a]));
        const l16 ahi = l16_sub(l16_set1(n->bmax[a] + f->margin), l16_load(f->c[a]));
        const l16 c1 = l16_mul(alo, l16_load(f->rhi[a]));   /* t dhi >= alo: lower if dhi > 0, else upper */
        const l16 c2 = l16_mul(ahi, l16_load(f->rlo[a]));   /* t dlo <= ahi: upper if dlo > 0, else lower */
        tlo = l16_max(tlo, l16_max(l16_select(f->pos_hi[a], c1, ninf), l16_select(f->neg_lo[a], c2, ninf)));
        thi = l16_min(thi, l16_min(l16_select(f->pos_hi[a], pinf, c1), l16_select(f->neg_lo[a], pinf, c2)));
    }
    *tlo_out = tlo;
    /* Relative slack 2^-16 for the rounding of the products; an upper bound of -inf (overflow of an
     * impossible constraint) gives NaN here and culls, as it should. t is the segment's parameter (0 at the
     * receiver, 1 at the sample): relative to it, the slack is position- and scale-free; the coordinates'
     * own rounding is the margin's (ms_block_frusta_init). */
    return l16_le(tlo, l16_add(thi, l16_mul(l16_abs(thi), l16_set1(1.0f / 65536.0f))));
}

/* The default child test: both children's frusta; where both survive, the nearer one first by a majority
 * of the lanes that reach both (the paper orders by its frusta's entry distances the same way). */
static inline void MS_CAT(BT_FN, _children)(const ms_block_frusta *f, const ms_bvh_node *c, unsigned mask, int order,
                                            unsigned *ml, unsigned *mr, int *right_first)
{
    l16 t0, t1;
    *ml = MS_CAT(BT_FN, _node)(f, &c[0], &t0) & mask;
    *mr = MS_CAT(BT_FN, _node)(f, &c[1], &t1) & mask;
    *right_first = 0;
    if (order && *ml && *mr) {
        const unsigned both = *ml & *mr;
        *right_first = 2 * ms_bt_popcount16(l16_lt(t1, t0) & both) > ms_bt_popcount16(both);
    }
}

#ifdef BT_RAYS
#define BT_CARRY_(dst, src) memcpy(dst, src, sizeof rays)
#else
#define BT_CARRY_(dst, src) ((void)0)
#endif

static void BT_FN(BT_STATE *s, const ms_bvh_shallow *sh, int order)
{
    ms_block_frusta *f = s->fr;
    uint64_t *cnt = s->bt_cnt;
    l16 t_root;
    cnt[MS_BT_BLOCKS]++;
    cnt[MS_BT_AABB_TESTS]++;
    unsigned mask = MS_CAT(BT_FN, _node)(f, &sh->nodes[0], &t_root) & f->live;
    if (!mask) return;
    uint32_t st_node[MS_BVH_STACK];
    unsigned st_mask[MS_BVH_STACK];
#ifdef BT_RAYS
    uint16_t st_rays[MS_BVH_STACK][MS_BLOCK_LANES];
    uint16_t rays[MS_BLOCK_LANES], rl[MS_BLOCK_LANES], rr[MS_BLOCK_LANES];
    BT_ROOT_RAYS(s, rays);
#endif
#ifdef BT_LOCALS
    BT_LOCALS
#endif
    int sp = 0;
    uint32_t ni = 0;
    uint64_t tests = 0;
    for (;;) {
        const ms_bvh_node *n = &sh->nodes[ni];
        if (n->count) {
            cnt[MS_BT_LEAVES]++;
            cnt[MS_BT_TRIS_ACCESSED] += n->count;
            BT_LEAF(s, n, mask);
            if (!f->live) { cnt[MS_BT_BLOCKS_EARLY_OUT]++; break; }
        } else {
            const uint32_t c0 = n->first;
            mask &= f->live;
            unsigned ml, mr;
            int right_first;
#ifdef BT_CHILDREN
            BT_CHILDREN(s, &sh->nodes[c0], mask, order, ml, mr, right_first);
#else
            MS_CAT(BT_FN, _children)(f, &sh->nodes[c0], mask, order, &ml, &mr, &right_first);
            tests += 2;
#endif
            if (ml && mr) {
                if (right_first) {
                    st_node[sp] = c0; st_mask[sp] = ml; BT_CARRY_(st_rays[sp], rl); sp++;
                    ni = c0 + 1; mask = mr; BT_CARRY_(rays, rr);
                } else {
                    st_node[sp] = c0 + 1; st_mask[sp] = mr; BT_CARRY_(st_rays[sp], rr); sp++;
                    ni = c0; mask = ml; BT_CARRY_(rays, rl);
                }
                continue;
            }
            if (ml) { ni = c0; mask = ml; BT_CARRY_(rays, rl); continue; }
            if (mr) { ni = c0 + 1; mask = mr; BT_CARRY_(rays, rr); continue; }
        }
        for (;;) {
            if (sp == 0) goto done;
            --sp;
            mask = st_mask[sp] & f->live;
            if (mask) break;
        }
        ni = st_node[sp];
        BT_CARRY_(rays, st_rays[sp]);
    }
done:
    cnt[MS_BT_AABB_TESTS] += tests;
#ifdef BT_DONE
    BT_DONE(s);
#endif
}
#undef BT_CARRY_
