/* Part of the per-ISA engine (hpc_impl.h, compiled once per ISA; included there after hpc_leaf_bound_impl.h): the
 * exact test of one sample for a leaf's 16 receivers at once. */

/* ---- the leaf's receivers in the lanes (hpc: the exact test of one sample for 16 receivers at once) ----
 *
 * Departure from the paper, whose leaf tests its points one by one (L56-L75). With the leaf footprint, every
 * sample it leaves is tested for the leaf's receivers in the lanes: lane l is receiver l's ray to its own sample
 * (i, j) (its own grid origin, its own packet's shear axis, its own vertices relative to it and plane offset),
 * each lane exactly what hpc_sample_blocked computes for it (exact16, the same operations as for a receiver's 16
 * samples), so the answers stay raytrace's bit for bit. What it removes is the per-receiver work: handing each
 * receiver its candidate samples, then its groups and blocks (cast_footprint), which on the merged bars cost
 * about 400 cycles per (receiver, triangle) for 4 samples tested. Per (leaf, triangle) the work is now one
 * 16-lane test per sample the leaf footprint leaves open, which as leaves shrink with resolution approaches the
 * receivers' own samples. MS_HPC_OFF_LEAF_LANES: the per-receiver form. */
typedef struct leaf_lanes {
    uint32_t rr[LANES];             /* each lane's receiver */
    unsigned act;                   /* the lanes in play */
    const uint64_t *open[LANES];    /* each lane's open samples: its mask, or its front mask before it has one */
    const int8_t *kz[LANES];        /* ready lanes: their packets' shear axes (slot_kz) */
    l16 p[3], p0[3];                /* each lane's receiver and grid origin */
    unsigned ready;                 /* lanes whose mask exists (and with it the packets' shear axes) */
    unsigned axis[3], mixed;        /* of those, the lanes whose every packet has shear axis 0, 1, 2; the others */
    l16w ow;                        /* the lanes' open samples in the current mask word (leaf_lanes_word) */
    unsigned have;                  /* bit u: triangle u's per-lane vertices and offset made */
    unsigned tsure;                 /* bit u: hpc_t_sure of triangle u over the leaf's box */
    float pc[3], h[3];              /* the leaf's box (cast_leaf_footprint's) */
    l16 V[2][3][3], num[2];         /* per triangle: its vertices relative to each lane's receiver, its offset */
    uint64_t touched[LANES];        /* per lane: the groups where it lost samples */
    unsigned has[2];                /* per triangle: the lanes it was tested for */
} leaf_lanes;

/* Files ready lane l under the axis all its packets share (slot_setup), or under mixed. */
static inline void leaf_lanes_axis(const shared *sh, const chunk *c, leaf_lanes *L, int l)
{
    L->kz[l] = slot_kz(sh, c, sh->slot[L->rr[l]]);
    const int z = L->kz[l][sh->npk];
    if (z >= 0) L->axis[z] |= 1u << l;
    else L->mixed |= 1u << l;
}

/* The lanes' open samples of mask word wd, before its samples are tested. */
static inline void leaf_lanes_word(leaf_lanes *L, int wd)
{
    uint64_t w[LANES] = { 0 };
    for (unsigned m = L->act; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        w[l] = L->open[l][wd];
    }
    L->ow = l16w_load(w);
}

/* Gives lanes need a mask (and the packets' shear axes: slot_of); the masks may move (the pool grows), so every
 * lane's open pointer is taken again. 0 when out of memory. */
static int leaf_lanes_ready(const shared *sh, chunk *c, leaf_lanes *L, unsigned need)
{
    for (unsigned m = need & ~L->ready; m; m &= m - 1) {
        const uint32_t r = L->rr[__builtin_ctz(m)];
        ms_grid g;
        memcpy(g.p0, sh->p0 + 4 * (size_t)r, sizeof g.p0);
        memcpy(g.ds, sh->grid_ds, sizeof g.ds);
        memcpy(g.dt, sh->grid_dt, sizeof g.dt);
        g.k = sh->k;
        if (slot_of(sh, c, r, &g) < 0) return 0;
    }
    for (unsigned m = need & ~L->ready; m; m &= m - 1) leaf_lanes_axis(sh, c, L, __builtin_ctz(m));
    L->ready |= need;
    for (unsigned m = L->act; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        L->open[l] = open_of(sh, c, L->rr[l]);
        if (L->ready >> l & 1u) L->kz[l] = slot_kz(sh, c, sh->slot[L->rr[l]]);
    }
    return 1;
}

/* Sample sidx (bit b of mask word wd) for the leaf's lanes: cand[x] the lanes whose footprint of triangle tu[x]
 * may hold it, sure[x] those whose edge functions surely pass (footprint_sure_lanes); the triangles in turn,
 * the second only on lanes the first left open (raytrace's any hit). The lanes it blocks lose the sample.
 * 0 when out of memory. */
static int leaf_lanes_sample(const shared *sh, chunk *c, const tri_job *t, leaf_lanes *L, const int tu[2], int nx,
                             int wd, int b, const unsigned cand[2], const unsigned sure[2])
{
    const unsigned open = l16w_bit(L->ow, b) & (cand[0] | cand[1]);
    if (!open) return 1;
    const int k = sh->k, sidx = 64 * wd + b, i = sidx % k, j = sidx / k, pk = sidx / LANES;
    l16 d[3];
    int have_d = 0;
    unsigned hit = 0;
    for (int x = 0; x < nx; x++) {
        const unsigned live = cand[x] & open & ~hit;
        if (!live) continue;
        const int u = tu[x];
        const tri_job *tr = &t[u];
        if ((live & ~L->ready) && !leaf_lanes_ready(sh, c, L, live)) return 0;
        if (!(L->have >> u & 1u)) {
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) L->V[u][v][a] = l16_sub(l16_set1(tr->v[3 * v + a]), L->p[a]);
            L->num[u] = ms_wt_offset16((const l16 (*)[3])L->V[u], tr->N);
            L->have |= 1u << u;
            if (tsure_on(sh) && (hpc_sw(sh, MS_HPC_BREAK_TSURE) || hpc_t_sure(sh, L->pc, L->h, tr))) L->tsure |= 1u << u;
        }
        L->has[u] |= live;
        c->cnt[C_SAMPLE_TESTS] += (uint64_t)__builtin_popcount(live);
        c->cnt[C_LEAF_LANE_TESTS] += (uint64_t)__builtin_popcount(live);
        if (!(live & ~sure[x]) && (L->tsure >> u & 1u)) {   /* blocked on every lane: no test (hpc_t_sure) */
            c->cnt[C_SAMPLES_SURE] += (uint64_t)__builtin_popcount(live);
            c->cnt[C_SAMPLES_TSURE] += (uint64_t)__builtin_popcount(live);
            hit |= live;
            continue;
        }
        if (!have_d) {
            for (int a = 0; a < 3; a++)
                d[a] = l16_sub(l16_add(l16_add(L->p0[a], l16_set1((float)i * sh->grid_ds[a])), l16_set1((float)j * sh->grid_dt[a])),
                               L->p[a]);
            have_d = 1;
        }
        unsigned m0 = L->axis[0] & live, m1 = L->axis[1] & live, mneg = 0;
        for (unsigned m = live & L->mixed; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            const int z = L->kz[l][pk];
            m0 |= (unsigned)(z == 0) << l;
            m1 |= (unsigned)(z == 1) << l;
            mneg |= (unsigned)(z < 0) << l;
        }
        if (!(live & ~sure[x]) && !mneg && !hpc_sw(sh, MS_HPC_OFF_SURE)) {
            c->cnt[C_SAMPLES_SURE] += (uint64_t)__builtin_popcount(live);
            hit |= t_range16(sh, tr, d, L->num[u], live);
        } else {
            hit |= exact16(sh, tr, L->p, L->V[u], d, L->num[u], m0, m1, mneg, -1, live);
        }
    }
    if (!hit) return 1;
    c->cnt[C_SAMPLES_BLOCKED] += (uint64_t)__builtin_popcount(hit);
    const int gk = (j / sh->gs) * (k / sh->gs) + i / sh->gs;
    L->ow = l16w_clear(L->ow, hit, b);
    for (unsigned m = hit; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        ((uint64_t *)L->open[l])[wd] &= ~(UINT64_C(1) << b);   /* a lane it blocks is ready: its own mask */
        L->touched[l] |= UINT64_C(1) << gk;
    }
    return 1;
}

/* After the leaf's samples: each lane's groups left without an open sample, its umbra bits (hpc_record_umbra). */
static void leaf_lanes_umbra(const shared *sh, chunk *c, const leaf_lanes *L)
{
    for (unsigned m = L->act; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        if (!L->touched[l]) continue;
        const uint32_t r = L->rr[l];
        const int32_t s = sh->slot[r];
        const uint64_t gu0 = sh->gumbra[r];
        uint64_t gu = gu0;
        for (uint64_t g = L->touched[l]; g; g &= g - 1)
            if (group_done(sh, slot_mask(sh, c, s), __builtin_ctzll(g))) gu |= g & -g;
        if (gu != gu0) hpc_record_umbra(sh, c, r, s, gu);
    }
}
