/* Part of the per-ISA engine (hpc_impl.h, compiled once per ISA; included there after hpc_leaf_impl.h): the
 * traversal of a chunk's hierarchy for one job (PROCESS-BLOCKER-OPTIMIZED, PROCESS-RECURSIVE) and the paper's
 * per-point form (group volumes V_Gk; hpc-scanline). */

/* INTERSECTS (hpc_volume_box) over all planes at once: per plane the scalar form's arithmetic. */
static int vol_box(const shared *sh, const hpc_volume *v, uint32_t act, const float lo[3], const float hi[3],
                   uint32_t *out, uint64_t *tests)
{
    if (hpc_sw(sh, MS_HPC_OFF_SIMD_PLANES)) return hpc_volume_box(v, act, lo, hi, out, tests);
    act &= v->n >= 32 ? UINT32_MAX : (UINT32_C(1) << v->n) - 1u;
    if (!act) { *out = 0; return 1; }
    l16 mx = l16_load(v->soa[3]), mn = mx;
    for (int a = 0; a < 3; a++) {
        const l16 n = l16_load(v->soa[a]), x = l16_mul(n, l16_set1(lo[a])), y = l16_mul(n, l16_set1(hi[a]));
        mx = l16_add(mx, l16_max(x, y));
        mn = l16_add(mn, l16_min(y, x));
    }
    *tests += (uint64_t)__builtin_popcount(act);
    if (l16_lt(mx, l16_set1(-v->eps)) & act) return 0;
    *out = act & ~l16_le(l16_set1(v->eps), mn);   /* wholly inside, with room for rounding */
    return 1;
}

/* POINT-IN-VOLUME (hpc_volume_point) over all planes at once. */
static int vol_point(const shared *sh, const hpc_volume *v, uint32_t act, const float p[3], uint64_t *tests)
{
    if (hpc_sw(sh, MS_HPC_OFF_SIMD_PLANES)) return hpc_volume_point(v, act, p, tests);
    act &= v->n >= 32 ? UINT32_MAX : (UINT32_C(1) << v->n) - 1u;
    if (!act) return 1;
    const l16 s = l16_add(l16_add(l16_add(l16_mul(l16_load(v->soa[0]), l16_set1(p[0])), l16_mul(l16_load(v->soa[1]), l16_set1(p[1]))),
                                  l16_mul(l16_load(v->soa[2]), l16_set1(p[2]))),
                          l16_load(v->soa[3]));
    *tests += (uint64_t)__builtin_popcount(act);
    return !(l16_lt(s, l16_set1(-v->eps)) & act);
}

/* One receiver of a leaf against the triangle (L56-L75). */
static void cast_point(const shared *sh, chunk *c, uint32_t r, const tri_job *t, uint32_t pl, const act_group *ag, int nag)
{
    const ms_shadow_query *q = &sh->q[r];
    if (sh->full[r] || q->prim == t->self) return;
    c->cnt[C_POINT_TESTS]++;
    if (!vol_point(sh, &t->vl, pl, q->p, &c->cnt[C_PLANE_TESTS])) return;
    c->cnt[C_PAIRS_IN_VL]++;
    if (sh->footprint) { cast_point_footprint(sh, c, r, t); return; }
    ms_grid g;   /* the point's samples, formed when first needed */
    int have_g = 0;
#define HPC_GRID() (have_g ? (void)0 : (ms_grid_for_pixel(&sh->ctx->light, sh->k, q->px, q->py, sh->ctx->seed, &g), (void)(have_g = 1)))
    int32_t s = sh->slot[r];
    if (s < 0) {
        HPC_GRID();
        if ((s = hpc_slot_get(sh, c)) < 0) { c->failed = 1; return; }
        sh->slot[r] = s;
        memcpy(slot_mask(sh, c, s), sh->front + (size_t)sh->orig[r] * sh->mw, (size_t)sh->mw * sizeof(uint64_t));
        slot_setup(sh, c, s, q, &g);
    }
    if (!c->gvol_built) hpc_group_volumes(sh, c, t);
    uint64_t *open = slot_mask(sh, c, s);
    const int8_t *kz = slot_kz(sh, c, s);
    float A[3], B[3], C[3];
    for (int a = 0; a < 3; a++) { A[a] = t->v[a] - q->p[a]; B[a] = t->v[3 + a] - q->p[a]; C[a] = t->v[6 + a] - q->p[a]; }
    const float num = ms_wt_offset(q->p, t->v, t->N);
    uint64_t gu = sh->gumbra[r];
    if (sh->scanline && slot_frame(sh, c, s)->k) {
        int any = 0;
        for (int i = 0; i < nag && !any; i++) {
            if (gu >> ag[i].k & 1u) continue;
            c->cnt[C_GROUP_POINT_TESTS]++;
            any = vol_point(sh, &c->gvol[ag[i].k], ag[i].planes, q->p, &c->cnt[C_PLANE_TESTS]);
        }
        if (any) {
            c->cnt[C_RASTER_CALLS]++;
            if (ms_alpha_tested(sh->ctx->alpha, t->self)) {   /* its opaque samples only (alpha.h) */
                const ms_alpha_pixel ap = { sh->ctx, q };
                ms_alpha_raster(&ap, slot_frame(sh, c, s), sh->raster, t->v, t->self, open);
            } else {
                sh->raster(slot_frame(sh, c, s), t->v, open);
            }
            for (int gk = 0; gk < sh->G; gk++)
                if (!(gu >> gk & 1u) && group_done(sh, open, gk)) gu |= UINT64_C(1) << gk;
        }
    } else {
        for (int i = 0; i < nag; i++) {
            const int gk = (int)ag[i].k;
            if (gu >> gk & 1u) continue;
            c->cnt[C_GROUP_POINT_TESTS]++;
            if (!vol_point(sh, &c->gvol[gk], ag[i].planes, q->p, &c->cnt[C_PLANE_TESTS])) continue;
            HPC_GRID();
            const int done = hpc_sw(sh, MS_HPC_OFF_SIMD_SAMPLES) ? hpc_cast_group(sh, c, open, kz, gk, q, &g, t, A, B, C, num)
                                                              : cast_group16(sh, c, open, kz, gk, q, &g, t, A, B, C, num);
            if (done) gu |= UINT64_C(1) << gk;
        }
    }
#undef HPC_GRID
    hpc_record_umbra(sh, c, r, s, gu);
}

/* PROCESS-RECURSIVE (L35-L81). */
static void cast_node(const shared *sh, chunk *c, uint32_t ni, const tri_job *t, uint32_t pl, const act_group *ag, int nag)
{
    hnode *N = &c->nodes[ni];
    c->cnt[C_NODE_VISITS]++;
    if (N->full) { c->cnt[C_UMBRA_NODE_SKIPS]++; return; }
    uint32_t pl2;
    if (!vol_box(sh, &t->vl, pl, N->lo, N->hi, &pl2, &c->cnt[C_PLANE_TESTS])) { c->cnt[C_NODES_OUTSIDE_VL]++; return; }
    const int sets = !hpc_sw(sh, MS_HPC_OFF_PLANE_SETS);
    if (!sets) pl2 = HPC_ALL_PLANES;
    act_group ag2[64];
    int n2 = 0;
    for (int i = 0; i < nag; i++) {
        if (N->gumbra >> ag[i].k & 1u) continue;
        if (c->gvol_built) {
            uint32_t p2;
            if (vol_box(sh, &c->gvol[ag[i].k], ag[i].planes, N->lo, N->hi, &p2, &c->cnt[C_PLANE_TESTS]))
                ag2[n2++] = (act_group){ ag[i].k, sets ? p2 : HPC_ALL_PLANES };
        } else ag2[n2++] = (act_group){ ag[i].k, HPC_ALL_PLANES };
    }
    if (!n2) return;
    if (!N->count) {
        const uint32_t l = N->first;
        cast_node(sh, c, l, t, pl2, ag2, n2);
        cast_node(sh, c, l + 1, t, pl2, ag2, n2);
        N->gumbra = c->nodes[l].gumbra & c->nodes[l + 1].gumbra;
        N->full = c->nodes[l].full & c->nodes[l + 1].full;
    } else {
        if (sh->footprint && sh->p0 && N->count <= LANES) cast_leaf_footprint(sh, c, N, t, pl2);
        else   /* a pair's second triangle: its vl is the pair's (hpc_prepare_batch); pairs only with the footprint */
            for (int u = 0; u < (t->pair > 0 ? 2 : 1); u++)
                for (uint32_t i = N->first; i < N->first + N->count; i++) cast_point(sh, c, c->idx[i], &t[u], pl2, ag2, n2);
        node_bits_from_points(sh, c, N);
    }
}

/* PROCESS-BLOCKER-OPTIMIZED (L29-L34). */
static void cast_triangle(const shared *sh, chunk *c, const tri_job *t)
{
    if (c->failed || !c->n_nodes) return;
    if (c->umbra_in_tree > 64 && 4 * c->umbra_in_tree > c->n) {
        c->cnt[C_REBUILDS]++;
        const double t0 = omp_get_wtime();
        const int bad = hpc_build_tree(sh, c);
        c->cnt[C_REBUILD_THREAD_US] += (uint64_t)((omp_get_wtime() - t0) * 1e6);
        if (bad) { c->failed = 1; return; }
        if (!c->n_nodes) return;
    }
    c->cnt[C_TRI_CHUNK_PASSES]++;
    c->gvol_built = 0;
    /* C off: before the traversal (not for a pair: the group volumes are one triangle's, and they would cull
     * nodes for the other; with the footprint test they serve only that node culling) */
    if (hpc_sw(sh, MS_HPC_OFF_LAZY) && t->pair <= 0) hpc_group_volumes(sh, c, t);
    act_group ag[64];
    for (int g = 0; g < sh->G; g++) ag[g] = (act_group){ (uint32_t)g, HPC_ALL_PLANES };
    cast_node(sh, c, 0, t, HPC_ALL_PLANES, ag, sh->G);
}
