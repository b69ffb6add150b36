/* The traversal loop, written once for every instance (scalar, AVX2: frustum_traverse_impl.h; AVX-512:
 * frustum_traverse_avx512.c). Included per k (core/perk_each.h) after the including file has defined
 * FT_CTX (per-pixel constants), FT_SAVED (what a pushed node keeps for the recheck on pop) and, named by
 * MS_KFN, the operations:
 *   ft_init(FT_CTX *, frame)
 *   ft_root_out(const FT_CTX *, bvh) -> 1 when the root is outside the frustum
 *   ft_children(ctx, bvh, node, buf, cull_occluded, keep[2], saved[2], zmin[2], &culled_frustum,
 *               &culled_occluded): tests both children of an interior node (frustum, then coverage when
 *               cull_occluded), counting the culls
 *   ft_covers(const FT_SAVED *, buf) -> 1 when a still-visible sample may lie under the saved node
 *   ft_all_zero(buf)
 * Depth first, nearer child first when ordering; a pushed node is tested again on pop, because the
 * buffer has changed since it was pushed. */
void MS_KFN(ms_frustum_trace)(const ms_bvh *b, const ms_raster_frame *f, ms_raster_fn raster, uint32_t skip, void *buf,
                              uint64_t *cnt, int flags)
{
    const int cull_occluded = flags & MS_FT_CULL_OCCLUDED, order = flags & MS_FT_ORDER_CHILDREN;
    FT_CTX t;
    MS_KFN(ft_init)(&t, f);
    cnt[MS_FT_NODES_VISITED]++;
    if (MS_KFN(ft_root_out)(&t, b)) { cnt[MS_FT_NODES_CULLED_FRUSTUM]++; return; }
    uint32_t stack[MS_BVH_STACK];
    FT_SAVED saved[MS_BVH_STACK];
    int sp = 0;
    uint64_t visited = 0, culled_frustum = 0, culled_occluded = 0, triangles = 0;
    uint32_t ni = 0;
    for (;;) {
        const ms_bvh_node *n = &b->nodes[ni];
        if (n->count) {
            triangles += ms_ft_raster_leaf(b, n, f, raster, skip, buf);
            if (MS_KFN(ft_all_zero)(buf)) { cnt[MS_FT_EARLY_OUT]++; break; }
        } else {
            const uint32_t c0 = n->first;
            int keep[2];
            FT_SAVED sv[2];
            float z[2];
            MS_KFN(ft_children)(&t, b, n, buf, cull_occluded, keep, sv, z, &culled_frustum, &culled_occluded);
            visited += 2;
            if (keep[0] && keep[1]) {
                /* A branch, not a select: a mispredicted guess costs less than always waiting for z. */
                if (order && z[1] < z[0]) { saved[sp] = sv[0]; stack[sp++] = c0; ni = c0 + 1; }
                else { saved[sp] = sv[1]; stack[sp++] = c0 + 1; ni = c0; }
                continue;
            }
            if (keep[0]) { ni = c0; continue; }
            if (keep[1]) { ni = c0 + 1; continue; }
        }
        /* The buffer has changed since these nodes were pushed: some may be fully occluded by now. */
        for (;;) {
            if (sp == 0) goto done;
            --sp;
            if (!cull_occluded || MS_KFN(ft_covers)(&saved[sp], buf)) break;
            culled_occluded++;
        }
        ni = stack[sp];
    }
done:
    cnt[MS_FT_NODES_VISITED] += visited;
    cnt[MS_FT_NODES_CULLED_FRUSTUM] += culled_frustum;
    cnt[MS_FT_NODES_CULLED_OCCLUDED] += culled_occluded;
    cnt[MS_FT_TRIANGLES] += triangles;
}
