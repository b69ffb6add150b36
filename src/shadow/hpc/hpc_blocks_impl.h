/* Part of the per-ISA engine (hpc_impl.h, compiled once per ISA; included there after hpc_exact_impl.h): one
 * receiver against a job with the footprint test, group by group and block by block. */

/* The open bits of the 16 samples (i0 + l % gs, jb + l / gs) as lanes l, gs = 4 (4 rows) or 8 (2 rows); written
 * out row by row (a loop over the rows is vectorised into a gather, slower than these loads). */
static inline unsigned block_open(const uint64_t *open, int k, int i0, int jb, int gs)
{
    const int s0 = jb * k + i0, s1 = s0 + k;
    if (gs == 8)
        return (unsigned)(open[s0 >> 6] >> (s0 & 63) & 0xffu) | (unsigned)(open[s1 >> 6] >> (s1 & 63) & 0xffu) << 8;
    const int s2 = s1 + k, s3 = s2 + k;
    return (unsigned)(open[s0 >> 6] >> (s0 & 63) & 15u) | (unsigned)(open[s1 >> 6] >> (s1 & 63) & 15u) << 4 |
           (unsigned)(open[s2 >> 6] >> (s2 & 63) & 15u) << 8 | (unsigned)(open[s3 >> 6] >> (s3 & 63) & 15u) << 12;
}

/* A receiver's view of a job (one triangle, or two sharing an edge cast together: hpc_pair_batch): the triangles
 * that may block it (not its own), each with its footprint and its vertices relative to the receiver. */
typedef struct hpc_view {
    int nt;
    const tri_job *t[2];
    hpc_footprint fp[2];
    const uint64_t *ncand[2];   /* direct: per triangle, this receiver's samples the footprint may hold */
    const uint64_t *nsure[2];   /* direct: of those, the ones whose edge functions surely pass (footprint_sure_lanes) */
    uint64_t ngroups;           /* direct: groups holding them (a superset), over the triangles */
    int direct;                 /* 1: ncand and ngroups made by the leaf (cast_leaf_footprint), fp unused */
} hpc_view;

/* The lanes triangle t blocks of the 16-sample block at (i0, jb) of receiver q (live: the lanes to test), with
 * the 16-lane test or, switched off, one lane at a time; alpha-tested triangles only where opaque. sure: lanes
 * whose edge functions surely pass (footprint_sure_lanes): when they are all of live, they are blocked outright
 * where hpc_t_sure holds for this receiver (*tsure: -1 until first asked, then 0 or 1), else, when no row of the
 * block leaves its lanes to the own-axis form (a packet without a shared axis, kz < 0: ms_wt_segment, its own
 * shear and t), only the t range is tested (counter samples_sure). */
static unsigned block_hits(const shared *sh, chunk *c, const ms_shadow_query *q, const ms_grid *g, const int8_t *kz, int i0,
                           int jb, unsigned live, unsigned sure, int *tsure, const tri_job *t, const float V[3][3], float num)
{
    const int k = sh->k, gs = sh->gs;
    unsigned hit;
    int shared_axis = 1;
    const int all_sure = !(live & ~sure) && !hpc_sw(sh, MS_HPC_OFF_SURE | MS_HPC_OFF_SIMD_SAMPLES);
    if (all_sure && *tsure < 0) {   /* hpc_t_sure for this receiver, once a block could use it (-1: not yet known) */
        static const float zero3[3] = { 0.0f, 0.0f, 0.0f };
        *tsure = tsure_on(sh) && (hpc_sw(sh, MS_HPC_BREAK_TSURE) || hpc_t_sure(sh, q->p, zero3, t));
    }
    if (all_sure && !*tsure)
        for (int r = 0; r < LANES / gs; r++) shared_axis &= kz[((jb + r) * k + i0) / LANES] >= 0;
    if (all_sure && *tsure) {   /* hpc_t_sure: the t range passes too, on any axis */
        c->cnt[C_SAMPLES_SURE] += (uint64_t)__builtin_popcount(live);
        c->cnt[C_SAMPLES_TSURE] += (uint64_t)__builtin_popcount(live);
        hit = live;
    } else if (all_sure && shared_axis) {
        c->cnt[C_SAMPLES_SURE] += (uint64_t)__builtin_popcount(live);
        l16 d[3];
        block_dirs(q, g, i0, jb, gs, d);
        hit = t_range16(sh, t, d, l16_set1(num), live);
    } else if (hpc_sw(sh, MS_HPC_OFF_SIMD_SAMPLES)) {   /* one lane at a time, the scalar form */
        hit = 0;
        for (unsigned b = live; b; b &= b - 1) {
            const int l = __builtin_ctz(b), i = i0 + l % gs, j = jb + l / gs;
            float d[3];
            for (int a = 0; a < 3; a++) d[a] = (g->p0[a] + (float)i * g->ds[a] + (float)j * g->dt[a]) - q->p[a];
            hit |= (unsigned)hpc_sample_blocked(q->p, d, kz[(j * k + i) / LANES], t->v, t->N, V[0], V[1], V[2], num,
                                            sh->ctx->near, sh->ctx->far) << l;
        }
    } else {
        hit = group_block16(sh, q, g, kz, i0, jb, gs, live, t, V[0], V[1], V[2], num);
    }
    if (hit && ms_alpha_tested(sh->ctx->alpha, t->self))
        for (unsigned b = hit; b; b &= b - 1) {
            const int l = __builtin_ctz(b);
            if (!hpc_alpha_opaque(sh, t, q, g, i0 + l % gs, jb + l / gs)) hit &= ~(1u << l);
        }
    return hit;
}

/* cast_footprint's loop over the groups and blocks (below: its comment), written once and instantiated twice:
 * with the sure lanes (with_sure, a constant) for footprints over several groups, without for the others. A small
 * triangle's footprint rarely holds a whole block's live lanes, and there merely having the sure test in the
 * loop (its functions kept per block, its branch) cost more than it saved, taken or not. */
static inline __attribute__((always_inline)) void cast_blocks(const shared *sh, chunk *c, uint32_t r, const ms_grid *g,
                                                              const hpc_view *v, uint64_t todo, uint64_t gu,
                                                              float (*base)[4][64], const int with_sure)
{
    const ms_shadow_query *q = &sh->q[r];
    static const float off[2][2][LANES] = {
        { { 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3 }, { 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3 } },
        { { 0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7 }, { 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1 } } };
    const int k = sh->k, gs = sh->gs, rows = LANES / gs, wi = gs == 8, nt = v->nt;
    const uint64_t seg = (UINT64_C(1) << gs) - 1u;
    /* the sure lanes' slacks per triangle (negated under MS_HPC_BREAK_SURE, wrong on purpose) and whether
     * they prove anything (footprint_slack_ok) */
    l16 ssl[2][3];
    unsigned sok[2] = { 0u, 0u };
    for (int u = 0; u < nt && !v->direct && with_sure; u++) {
        for (int e = 0; e < 3; e++) ssl[u][e] = l16_set1(hpc_sw(sh, MS_HPC_BREAK_SURE) ? -v->fp[u].s[e] : v->fp[u].s[e]);
        sok[u] = v->fp[u].s[0] > 1e-30f && v->fp[u].s[1] > 1e-30f && v->fp[u].s[2] > 1e-30f ? 0xffffu : 0u;
    }
    l16 foff[2][4];
    for (int u = 0; u < nt && !v->direct; u++) footprint_offsets(&v->fp[u], l16_load(off[wi][0]), l16_load(off[wi][1]), foff[u]);
    int32_t s = sh->slot[r];
    const uint64_t *open = open_of(sh, c, r);
    float num[2] = { 0.0f, 0.0f }, V[2][3][3];   /* per triangle at its first exact test: offset, A, B, C */
    int tsure[2] = { -1, -1 };                    /* and hpc_t_sure for this receiver (-1: not yet known) */
    int have_num[2] = { 0, 0 };
    const int8_t *kz = NULL;
    const uint64_t gu0 = gu;
    for (uint64_t m = todo; m; m &= m - 1) {
        const int gk = __builtin_ctzll(m);
        const int i0 = (int)sh->group_i0[gk], j0 = (int)sh->group_j0[gk];
        unsigned any = 0;
        for (int jb = j0; jb < j0 + gs; jb += rows) {
            unsigned lanes[2] = { 0u, 0u }, sure[2] = { 0u, 0u };
            l16 E[2][4];
            if (v->direct) {
                for (int u = 0; u < nt; u++) lanes[u] = block_open(v->ncand[u], k, i0, jb, gs);
            } else {
                lanes[0] = footprint_lanes(&v->fp[0], foff[0], i0, jb, jb == j0 ? &base[0][0][0] : NULL, gk, E[0]);
                if (nt > 1) lanes[1] = footprint_lanes(&v->fp[1], foff[1], i0, jb, jb == j0 ? &base[1][0][0] : NULL, gk, E[1]);
            }
            if (!(lanes[0] | lanes[1])) continue;
            const unsigned ob = block_open(open, k, i0, jb, gs);
            if (!(ob & (lanes[0] | lanes[1]))) continue;
            if (!kz) {   /* the first exact test of this receiver and job */
                if (s < 0 && (s = slot_of(sh, c, r, g)) < 0) return;
                open = slot_mask(sh, c, s);
                kz = slot_kz(sh, c, s);
            }
            unsigned hit = 0;
            for (int u = 0; u < nt; u++) {
                const unsigned live = ob & lanes[u] & ~hit;   /* a sample the first blocks needs no second test */
                if (!live) continue;
                if (with_sure)
                    sure[u] = v->direct ? block_open(v->nsure[u], k, i0, jb, gs) : footprint_sure_lanes(E[u], ssl[u], sok[u]);
                if (!have_num[u]) {
                    num[u] = ms_wt_offset(q->p, v->t[u]->v, v->t[u]->N);
                    for (int i = 0; i < 3; i++)
                        for (int a = 0; a < 3; a++) V[u][i][a] = v->t[u]->v[3 * i + a] - q->p[a];
                    have_num[u] = 1;
                }
                c->cnt[C_SAMPLE_TESTS] += (uint64_t)__builtin_popcount(live);
                hit |= block_hits(sh, c, q, g, kz, i0, jb, live, sure[u], &tsure[u], v->t[u], V[u], num[u]);
            }
            if (!hit) continue;
            c->cnt[C_SAMPLES_BLOCKED] += (uint64_t)__builtin_popcount(hit);
            any |= hit;
            uint64_t *w = slot_mask(sh, c, s);
            for (int rr = 0; rr < rows; rr++) {
                const int s0 = (jb + rr) * k + i0;
                w[s0 >> 6] &= ~((uint64_t)(hit >> (rr * gs) & seg) << (s0 & 63));
            }
        }
        if (any && group_done(sh, open, gk)) gu |= UINT64_C(1) << gk;
    }
    if (gu != gu0) hpc_record_umbra(sh, c, r, s, gu);
}

/* Receiver r inside V_L against a job's triangles (v), with the footprint test in place of V_Gk (above): the
 * groups some triangle's footprint may touch, then in each block the lanes each footprint may hold, and the
 * exact test of each triangle only on those of its lanes that are still open. A sample is blocked when one of
 * the triangles blocks it, as raytrace's any-hit over both: the pair shares the traversal, the V_L test, the
 * per-pair set-up and the block loop, never the exact test (a convex quad's own edge functions would round
 * differently on the shared edge). The mask, the packets' shear axes and the plane offsets are made only
 * when some lane needs the exact test. */
static void cast_footprint(const shared *sh, chunk *c, uint32_t r, const ms_grid *g, const hpc_view *v)
{
    uint64_t gu = sh->gumbra[r];
    c->cnt[C_GROUP_POINT_TESTS] += (uint64_t)__builtin_popcountll(sh->all_groups & ~gu);
    c->cnt[C_PAIRS_FOOTPRINT] += (uint64_t)v->nt;
    /* The open groups a footprint may touch (a node's umbra groups are its points' too). */
    float base[2][4][64];   /* each function at each group's first sample (footprint_groups) */
    uint64_t todo;
    if (v->direct) todo = v->ngroups;
    else {
        todo = footprint_groups(sh, &v->fp[0], base[0]);
        if (v->nt > 1) todo |= footprint_groups(sh, &v->fp[1], base[1]);
    }
    todo &= ~gu;
    if (!todo) return;
    if (__builtin_popcountll(todo) >= SURE_MIN_GROUPS) cast_blocks(sh, c, r, g, v, todo, gu, base, 1);
    else cast_blocks(sh, c, r, g, v, todo, gu, base, 0);
}

/* One receiver against one triangle with the footprint test (receivers without their grid origins formed
 * up front, or in a leaf of more than 16 points). */
static void cast_point_footprint(const shared *sh, chunk *c, uint32_t r, const tri_job *t)
{
    const ms_shadow_query *q = &sh->q[r];
    ms_grid g;
    if (sh->p0) {
        memcpy(g.p0, sh->p0 + 4 * (size_t)r, sizeof g.p0);
        memcpy(g.ds, sh->grid_ds, sizeof g.ds);
        memcpy(g.dt, sh->grid_dt, sizeof g.dt);
        g.k = sh->k;
    } else {
        ms_grid_for_pixel(&sh->ctx->light, sh->k, q->px, q->py, sh->ctx->seed, &g);
    }
    hpc_view v;
    v.nt = 1;
    v.t[0] = t;
    v.direct = 0;
    float A[3], B[3], C[3];
    for (int a = 0; a < 3; a++) { A[a] = t->v[a] - q->p[a]; B[a] = t->v[3 + a] - q->p[a]; C[a] = t->v[6 + a] - q->p[a]; }
    hpc_footprint_setup(&v.fp[0], A, B, C, &g, q->p, sh->p0 ? sh->p0[4 * (size_t)r + 3] : hpc_footprint_rel(&g, q->p, sh->k));
    hpc_footprint_spans(&v.fp[0], (float)(sh->gs - 1));
    cast_footprint(sh, c, r, &g, &v);
}
