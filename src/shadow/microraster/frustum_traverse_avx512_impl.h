/* Per k (core/perk_each.h): the AVX-512 node tests for the shared loop, with k a constant. */
INLINE void MS_KFN(ft_init)(trav_consts *t, const ms_raster_frame *f) { consts_init(t, f, MS_K); }
INLINE int MS_KFN(ft_root_out)(const trav_consts *t, const ms_bvh *b) { return root_out(t, b); }
INLINE int MS_KFN(ft_covers)(const trav_cov *cv, const void *buf) { return covers(buf, *cv, MS_K); }
INLINE int MS_KFN(ft_all_zero)(const void *buf) { return all_zero(buf, MS_K); }
INLINE void MS_KFN(ft_children)(const trav_consts *t, const ms_bvh *b, const ms_bvh_node *n, const void *buf,
                                int cull_occluded, int keep[2], trav_cov cv[2], float z[2], uint64_t *culled_frustum,
                                uint64_t *culled_occluded)
{
    children(t, b, n, buf, cull_occluded, keep, cv, z, culled_frustum, culled_occluded, MS_K);
}

#include "frustum_traverse_loop.h"
