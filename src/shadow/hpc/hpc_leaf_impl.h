/* Part of the per-ISA engine (hpc_impl.h, compiled once per ISA; included there after hpc_leaf_lanes_impl.h): a
 * leaf's points against a job with the footprint test, 16 at a time. */

/* Whether the leaf footprint pays here, from this chunk's recent leaves cast with it (the counts halved as they
 * grow, so that they follow the triangles of the moment): only while it has left at most LEAF_FP_CANDS samples
 * per receiver to test in the lanes and, where its samples go to each receiver in turn (not lanes: the leaf lanes
 * off, or alpha), at most LEAF_FP_KEEP of the receivers to that per-receiver work; one leaf in LEAF_FP_PROBE uses
 * it regardless, to keep the counts current. Per chunk, so the same on every ISA and run. It pays on thin bars
 * (few receivers kept, two samples each) and costs where large triangles leave many samples per receiver or
 * small ones keep most receivers; with the leaf lanes a kept receiver costs no work of its own, so the keep
 * rule applies only without them. */
#define LEAF_FP_PROBE 64u
#define LEAF_FP_KEEP 0.75f
#define LEAF_FP_CANDS 6.0f
static inline int leaf_fp_pays(chunk *c, int lanes)
{
    if (c->lf_leaves++ % LEAF_FP_PROBE == 0) return 1;
    return (lanes || (float)c->lf_kept <= LEAF_FP_KEEP * (float)c->lf_in) && (float)c->lf_cands <= LEAF_FP_CANDS * (float)c->lf_in;
}

/* A leaf's shape u ruled out (counter cnt): the triangles it stands for (both for a rectangle pair, else
 * triangle u) leave the leaf, each counted when it had a receiver there. */
static inline void shape_off(chunk *c, int cnt, unsigned act, unsigned on[2], int u, int rect)
{
    for (int x = u; x <= (rect ? 1 : u); x++) {
        c->cnt[cnt] += (uint64_t)((act & on[x]) != 0);
        on[x] = 0;
    }
}

/* A leaf against a job in the lanes (cast_leaf_footprint's steps share it): lane l is the leaf's point l. */
typedef struct leaf_cast {
    int nt, ns, rect;                   /* the job's triangles; the shapes whose footprints are formed */
    int lanes_ok, leaf_fp, lanes;       /* the leaf's receivers in the lanes allowed; the leaf footprint; both */
    unsigned act, on[2], has[2];        /* on[u]: the lanes triangle u may block (not their own) */
    uint32_t rr[LANES];
    float P[3][LANES], W[3][LANES], R[LANES];
    l16 px, py, pz;
    uint64_t ncand[2][64];              /* with the leaf footprint: per shape, the samples it left */
    const uint64_t *lopen[LANES];       /* with the leaf footprint: each lane's open samples */
    fp_shape shape[2];
    leaf_box bx;                        /* with the leaf footprint: the receivers' box and their grid origins' */
    float fe[2][5][3][LANES], fs[2][5][LANES], fdl[2][4][LANES], fdh[2][4][LANES];
    uint64_t rc[2][LANES][64], rg[2][LANES];   /* per triangle and lane: the receiver's samples, their groups */
    uint64_t rsu[2][LANES][64];                /* of rc, the samples whose edge functions surely pass */
    leaf_lanes L;
} leaf_cast;

/* The leaf's points not in full umbra that a triangle of the job may block, in the lanes; of those, the ones
 * inside V_L (POINT-IN-VOLUME per lane, vol_point's arithmetic). Returns them (lc->act). */
static unsigned leaf_gather(const shared *sh, chunk *c, const hnode *N, const tri_job *t, uint32_t pl, leaf_cast *lc)
{
    const int nt = lc->nt;
    unsigned act = 0, on[2] = { 0, 0 };
    memset(lc->P, 0, sizeof lc->P);
    memset(lc->W, 0, sizeof lc->W);
    memset(lc->R, 0, sizeof lc->R);
    for (uint32_t i = 0; i < N->count; i++) {
        const uint32_t r = c->idx[N->first + i];
        lc->rr[i] = r;
        if (sh->full[r]) continue;
        for (int u = 0; u < nt; u++) on[u] |= (unsigned)(sh->q[r].prim != t[u].self) << i;
        if (!((on[0] | on[1]) >> i & 1u)) continue;
        act |= 1u << i;
        for (int a = 0; a < 3; a++) { lc->P[a][i] = sh->q[r].p[a]; lc->W[a][i] = sh->p0[4 * (size_t)r + a] - lc->P[a][i]; }
        lc->R[i] = sh->p0[4 * (size_t)r + 3];
    }
    lc->on[0] = on[0];
    lc->on[1] = on[1];
    if (!act) return 0;
    const int tested = __builtin_popcount(act);
    c->cnt[C_POINT_TESTS] += (uint64_t)tested;
    const l16 px = lc->px = l16_load(lc->P[0]), py = lc->py = l16_load(lc->P[1]), pz = lc->pz = l16_load(lc->P[2]);
    const hpc_volume *v = &t->vl;
    uint32_t planes = pl & (v->n >= 32 ? UINT32_MAX : (UINT32_C(1) << v->n) - 1u);
    c->cnt[C_PLANE_TESTS] += (uint64_t)tested * (uint64_t)__builtin_popcount(planes);
    const l16 neps = l16_set1(-v->eps);
    for (; planes && act; planes &= planes - 1) {
        const int i = __builtin_ctz(planes);
        const l16 d = l16_add(l16_add(l16_add(l16_mul(l16_set1(v->soa[0][i]), px), l16_mul(l16_set1(v->soa[1][i]), py)),
                                      l16_mul(l16_set1(v->soa[2][i]), pz)),
                              l16_set1(v->soa[3][i]));
        act &= ~l16_lt(d, neps);
    }
    if (!act) return 0;
    c->cnt[C_PAIRS_IN_VL] += (uint64_t)__builtin_popcount(act & on[0]) + (uint64_t)__builtin_popcount(act & on[1]);
    return act;
}

/* Whether the leaf footprint and the leaf's receivers in the lanes serve this leaf and job, and the shapes whose
 * footprints are formed. */
static void leaf_choose(const shared *sh, chunk *c, const tri_job *t, leaf_cast *lc)
{
    const int nt = lc->nt;
    const unsigned act = lc->act, *on = lc->on;
    /* pairs only: a lone triangle's set-up is shared by half as much work, and on a scanned mesh, whose
     * triangles are mostly alone, it cost more than it saved even with leaf_fp_pays */
    /* the leaf's receivers in the lanes (leaf_lanes, above): not for alpha-tested triangles (their opacity is
     * looked up per hit, hpc_alpha_opaque) nor with the 16-lane sample test off */
    int lanes_ok = !hpc_sw(sh, MS_HPC_OFF_LEAF_LANES | MS_HPC_OFF_SIMD_SAMPLES);
    for (int u = 0; u < nt && lanes_ok; u++) lanes_ok = !ms_alpha_tested(sh->ctx->alpha, t[u].self);
    const int leaf_fp = !hpc_sw(sh, MS_HPC_OFF_LEAF_FOOTPRINT) &&
                        (hpc_sw(sh, MS_HPC_ALL_LEAF_FOOTPRINT) ||
                         (nt == 2 && __builtin_popcount(act) >= LEAF_FP_MIN && leaf_fp_pays(c, lanes_ok)));
    /* The shapes whose footprints are formed: each triangle, or for a rectangle pair under the leaf footprint
     * its rectangle, standing for both ("rectangle pairs" above: one footprint for two triangles). */
    /* Not where a receiver lies on one of the two (its own is not cast against it): the other, coplanar with it,
     * rules out every sample by mixed signs, while the rectangle around the receiver rules out none (on a
     * ground plane that made the cast several times slower). */
    const int rect = leaf_fp && nt == 2 && t->rect && !hpc_sw(sh, MS_HPC_OFF_RECT) && (act & on[0] & on[1]) == act,
              ns = rect ? 1 : nt;
    for (int u = 0; u < ns; u++) lc->shape[u] = rect ? (fp_shape){ t->rc, 4 } : (fp_shape){ t[u].v, 3 };
    if (rect && hpc_sw(sh, MS_HPC_BREAK_RECT)) lc->shape[0].nv = 3;   /* wrong on purpose: the first triangle for both */
    lc->lanes_ok = lanes_ok;
    lc->leaf_fp = leaf_fp;
    lc->rect = rect;
    lc->ns = ns;
}

/* The leaf footprint over the receivers left (their box and their grid origins' box): each shape's candidate
 * samples in lc->ncand, the shapes that leave none ruled out. Returns the lanes left (lc->act). */
static unsigned leaf_bound(const shared *sh, chunk *c, leaf_cast *lc)
{
    const int ns = lc->ns, rect = lc->rect;
    unsigned act = lc->act, *on = lc->on;
    leaf_box *bx = &lc->bx;
    uint64_t ngroups[2] = { ~UINT64_C(0), ~UINT64_C(0) };
    for (int a = 0; a < 3; a++) {
        float plo = INFINITY, phi = -INFINITY, olo = INFINITY, ohi = -INFINITY;
        for (unsigned m = act; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            plo = ms_minf(plo, lc->P[a][l]);
            phi = ms_maxf(phi, lc->P[a][l]);
            const float p0 = sh->p0[4 * (size_t)lc->rr[l] + a];
            olo = ms_minf(olo, p0);
            ohi = ms_maxf(ohi, p0);
        }
        /* centres and half extents; the differences rounded up (a float difference is off by u of itself) */
        bx->pc[a] = 0.5f * (plo + phi);
        bx->h[a] = ms_maxf(phi - bx->pc[a], bx->pc[a] - plo) * 1.000001f;
        bx->p0c[a] = 0.5f * (olo + ohi);
        bx->J[a] = ms_maxf(ohi - bx->p0c[a], bx->p0c[a] - olo) * 1.000001f;
        if (hpc_sw(sh, MS_HPC_BREAK_LEAF_BOUND)) bx->J[a] = 0.0f;   /* wrong on purpose (test_hpc) */
    }
    leaf_fn fn[2];
    leaf_setup(sh, bx, lc->shape, ns, fn);
    c->cnt[C_RECT_PAIRS] += (uint64_t)rect;
    for (int u = 0; u < ns; u++) {   /* a rectangle: shape 0 stands for both triangles (on[0] covers act) */
        if (!(act & on[u])) {   /* no receiver for it: no samples (read by the rule's counts below) */
            memset(lc->ncand[u], 0, (size_t)sh->mw * sizeof lc->ncand[u][0]);
            continue;
        }
        ngroups[u] = leaf_footprint(sh, bx, &fn[u], lc->ncand[u]);
        if (!ngroups[u]) shape_off(c, C_LEAF_CULLS, act, on, u, rect);
    }
    act &= on[0] | on[1];
    if (!act) return lc->act = 0;
    /* A sample blocked already for every receiver of the leaf needs no test for any (the paper's L21, for a
     * whole leaf): the candidates masked by the union of the receivers' open samples, and below each
     * receiver's by its own: a third fewer pairs reach per-receiver work on thin bars. */
    uint64_t any_open[64] = { 0 };
    for (unsigned m = act; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        lc->lopen[l] = open_of(sh, c, lc->rr[l]);
        for (int wd = 0; wd < sh->mw; wd++) any_open[wd] |= lc->lopen[l][wd];
    }
    for (int u = 0; u < ns; u++) {
        if (!(act & on[u])) continue;
        uint64_t left = 0;
        for (int wd = 0; wd < sh->mw; wd++) left |= lc->ncand[u][wd] &= any_open[wd];
        if (!left) shape_off(c, C_LEAF_CULLS_BLOCKED, act, on, u, rect);
    }
    act &= on[0] | on[1];
    return lc->act = act;
}

/* hpc_footprint_setup per lane, per triangle; for a rectangle pair its five distinct functions (rect_fns), each
 * triangle's footprint taken from them below */
static void leaf_functions(const shared *sh, leaf_cast *lc)
{
    const int ns = lc->ns, rect = lc->rect, leaf_fp = lc->leaf_fp;
    const l16 px = lc->px, py = lc->py, pz = lc->pz;
    const l16 w[3] = { l16_load(lc->W[0]), l16_load(lc->W[1]), l16_load(lc->W[2]) }, rel = l16_load(lc->R);
    float (*fe)[5][3][LANES] = lc->fe, (*fs)[5][LANES] = lc->fs, (*fdl)[4][LANES] = lc->fdl, (*fdh)[4][LANES] = lc->fdh;
    const l16 span = l16_set1((float)(sh->gs - 1)), zero = l16_set1(0.0f);
    for (int u = 0; u < ns; u++) {
        const int nv = rect ? 4 : 3, nfn = rect ? 5 : 3, (*pair)[2] = rect ? rect_fns : fp_edges[0];
        l16 Y[4][3], nY[4];
        for (int vtx = 0; vtx < nv; vtx++) {
            const l16 pc[3] = { px, py, pz };
            for (int a = 0; a < 3; a++) Y[vtx][a] = l16_sub(l16_set1(lc->shape[u].v[3 * vtx + a]), pc[a]);
            nY[vtx] = l16_max(l16_abs(Y[vtx][0]), l16_max(l16_abs(Y[vtx][1]), l16_abs(Y[vtx][2])));
        }
        l16 esum[3] = { l16_set1(0.0f), l16_set1(0.0f), l16_set1(0.0f) };   /* 0 + x = x */
        for (int e = 0; e < nfn; e++) {
            const l16 *y1 = Y[pair[e][0]], *y2 = Y[pair[e][1]];
            const l16 X[3] = { l16_sub(l16_mul(y1[1], y2[2]), l16_mul(y1[2], y2[1])), l16_sub(l16_mul(y1[2], y2[0]), l16_mul(y1[0], y2[2])),
                               l16_sub(l16_mul(y1[0], y2[1]), l16_mul(y1[1], y2[0])) };
            const l16 c0 = l16_add(l16_add(l16_mul(X[0], w[0]), l16_mul(X[1], w[1])), l16_mul(X[2], w[2]));
            const l16 c1 = l16_add(l16_add(l16_mul(X[0], l16_set1(sh->grid_ds[0])), l16_mul(X[1], l16_set1(sh->grid_ds[1]))),
                                   l16_mul(X[2], l16_set1(sh->grid_ds[2])));
            const l16 c2 = l16_add(l16_add(l16_mul(X[0], l16_set1(sh->grid_dt[0])), l16_mul(X[1], l16_set1(sh->grid_dt[1]))),
                                   l16_mul(X[2], l16_set1(sh->grid_dt[2])));
            l16_store(fe[u][e][0], c0);
            l16_store(fe[u][e][1], c1);
            l16_store(fe[u][e][2], c2);
            if (!leaf_fp) spans16(c1, c2, span, zero, fdl[u][e], fdh[u][e]);
            l16_store(fs[u][e], l16_mul(l16_mul(rel, nY[pair[e][0]]), nY[pair[e][1]]));
            if (rect) continue;
            esum[0] = l16_add(esum[0], c0);
            esum[1] = l16_add(esum[1], c1);
            esum[2] = l16_add(esum[2], c2);
        }
        if (rect) continue;
        for (int a = 0; a < 3; a++) l16_store(fe[u][3][a], esum[a]);
        if (!leaf_fp) spans16(esum[1], esum[2], span, zero, fdl[u][3], fdh[u][3]);
    }
}

/* The leaf's receivers in the lanes (leaf_lanes): their receivers, open samples, masks ready, grid origins. */
static void leaf_lanes_begin(const shared *sh, chunk *c, leaf_cast *lc)
{
    leaf_lanes *L = &lc->L;
    const unsigned act = lc->act;
    L->act = act;
    L->ready = L->have = L->mixed = L->tsure = 0;
    memcpy(L->pc, lc->bx.pc, sizeof L->pc);
    memcpy(L->h, lc->bx.h, sizeof L->h);
    L->axis[0] = L->axis[1] = L->axis[2] = 0;
    L->has[0] = L->has[1] = 0;
    float p0[3][LANES] = { { 0 } };
    for (unsigned m = act; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        L->rr[l] = lc->rr[l];
        L->open[l] = lc->lopen[l];
        L->touched[l] = 0;
        L->ready |= (unsigned)(sh->slot[lc->rr[l]] >= 0) << l;
        for (int a = 0; a < 3; a++) p0[a][l] = sh->p0[4 * (size_t)lc->rr[l] + a];
    }
    for (unsigned m = L->ready; m; m &= m - 1) leaf_lanes_axis(sh, c, L, __builtin_ctz(m));
    for (int a = 0; a < 3; a++) { L->p[a] = l16_load(lc->P[a]); L->p0[a] = l16_load(p0[a]); }
}

/* With the leaf footprint: each sample it left of shape u, tested for the leaf's receivers in the lanes
 * (footprint_keep per receiver, the footprint_lanes arithmetic with the sample's own indices), giving each
 * receiver its samples: the work per leaf follows the samples left, which fall as the leaves shrink with
 * resolution. A rectangle pair's samples (its rectangle's, for both triangles) are looped over once, and each
 * triangle's own footprint is tested on them from the five functions, so that each triangle's exact tests run on
 * its own candidates only (the rectangle's would double them). 0 when out of memory. */
static int leaf_shape_samples(const shared *sh, chunk *c, const tri_job *t, leaf_cast *lc, int u)
{
    const int mw = sh->mw, rect = lc->rect, lanes = lc->lanes;
    const unsigned act = lc->act, *on = lc->on;
    const uint64_t *const *lopen = lc->lopen;
    const l16 zero = l16_set1(0.0f);
    const unsigned lanes_u[2] = { act & (rect ? on[0] : on[u]), rect ? act & on[1] : 0u };
    const unsigned lanes_on = lanes_u[0] | lanes_u[1];
    if (!lanes_on) return 1;
    const int tu[2] = { u, u + 1 };   /* the triangles of the shape: u, or both of a rectangle pair */
    for (int x = 0; x < 1 + rect && !lanes; x++)
        for (unsigned m = lanes_u[x]; m; m &= m - 1) {
            memset(lc->rc[u + x][__builtin_ctz(m)], 0, (size_t)mw * sizeof(uint64_t));
            memset(lc->rsu[u + x][__builtin_ctz(m)], 0, (size_t)mw * sizeof(uint64_t));
            lc->rg[u + x][__builtin_ctz(m)] = 0;
        }
    const int nfn = rect ? 5 : 4;   /* with the triangle's sum */
    l16 c0[5], c1[5], c2[5], sl[2][3];
    for (int e = 0; e < nfn; e++) { c0[e] = l16_load(lc->fe[u][e][0]); c1[e] = l16_load(lc->fe[u][e][1]); c2[e] = l16_load(lc->fe[u][e][2]); }
    unsigned slok[2] = { 0u, 0u };
    l16 slsure[2][3];   /* the sure lanes' slacks: sl, or -sl (MS_HPC_BREAK_SURE, wrong on purpose) */
    for (int x = 0; x < 1 + rect; x++) {
        for (int e = 0; e < 3; e++) {
            sl[x][e] = l16_load(lc->fs[u][rect ? rect_tri[x][e] : e]);
            slsure[x][e] = hpc_sw(sh, MS_HPC_BREAK_SURE) ? l16_sub(zero, sl[x][e]) : sl[x][e];
        }
        slok[x] = footprint_slack_ok(sl[x]);
    }
    for (int wd = 0; wd < mw; wd++) {
        if (lanes && lc->ncand[u][wd]) leaf_lanes_word(&lc->L, wd);
        for (uint64_t bits = lc->ncand[u][wd]; bits; bits &= bits - 1) {
            const int bit = __builtin_ctzll(bits), sidx = 64 * wd + bit;
            /* k = 16, 32 or 64 (sh->gs), so a word holds whole rows */
            const l16 fi = l16_set1(sh->bit_i[bit]), fj = l16_set1((float)(64 / sh->k * wd) + sh->bit_j[bit]);
            l16 E[5];
            for (int e = 0; e < nfn; e++) E[e] = l16_add(l16_add(c0[e], l16_mul(c1[e], fi)), l16_mul(c2[e], fj));
            unsigned hitl[2], surel[2];
            if (rect) {   /* rectangle pairs, above: each triangle's functions and their sum */
                const l16 nd = l16_sub(zero, E[4]);
                const l16 T0[4] = { E[0], E[1], E[4], l16_add(l16_add(E[0], E[1]), E[4]) };
                const l16 T1[4] = { E[2], E[3], nd, l16_add(l16_add(E[2], E[3]), nd) };
                hitl[0] = footprint_keep_lanes(T0, T0, sl[0]) & lanes_u[0];
                hitl[1] = footprint_keep_lanes(T1, T1, sl[1]) & lanes_u[1];
                surel[0] = footprint_sure_lanes(T0, slsure[0], slok[0]);
                surel[1] = footprint_sure_lanes(T1, slsure[1], slok[1]);
            } else {
                hitl[0] = footprint_keep_lanes(E, E, sl[0]) & lanes_u[0];
                hitl[1] = 0;
                surel[0] = footprint_sure_lanes(E, slsure[0], slok[0]);
                surel[1] = 0;
            }
            if (!(hitl[0] | hitl[1])) continue;
            if (lanes) {
                if (!leaf_lanes_sample(sh, c, t, &lc->L, tu, 1 + rect, wd, bit, hitl, surel)) return 0;
                continue;
            }
            const int gk = (sidx / sh->k / sh->gs) * (sh->k / sh->gs) + (sidx % sh->k) / sh->gs;
            for (int x = 0; x < 2; x++)
                for (unsigned h2 = hitl[x]; h2; h2 &= h2 - 1) {
                    const int l = __builtin_ctz(h2);
                    if (!(lopen[l][wd] >> bit & 1u)) continue;   /* blocked already for this receiver */
                    lc->rc[u + x][l][wd] |= UINT64_C(1) << bit;
                    lc->rsu[u + x][l][wd] |= (uint64_t)(surel[x] >> l & 1u) << bit;
                    lc->rg[u + x][l] |= UINT64_C(1) << gk;
                    lc->has[u + x] |= 1u << l;
                }
        }
    }
    return 1;
}

/* After the samples: the lanes' umbra bits, the leaf footprint rule's counts (leaf_fp_pays). */
static void leaf_counts(const shared *sh, chunk *c, leaf_cast *lc)
{
    if (lc->lanes) {
        lc->has[0] = lc->L.has[0];
        lc->has[1] = lc->L.has[1];
        c->cnt[C_PAIRS_FOOTPRINT] += (uint64_t)(__builtin_popcount(lc->has[0]) + __builtin_popcount(lc->has[1]));
        leaf_lanes_umbra(sh, c, &lc->L);
    }
    if (lc->leaf_fp) {
        c->lf_in += (uint32_t)__builtin_popcount(lc->act);
        c->lf_kept += (uint32_t)__builtin_popcount(lc->act & (lc->has[0] | lc->has[1]));
        for (int u = 0; u < lc->ns; u++)
            for (int wd = 0; wd < sh->mw; wd++) c->lf_cands += (uint32_t)__builtin_popcountll(lc->ncand[u][wd]);
        if (c->lf_in > 4096u) { c->lf_in >>= 1; c->lf_kept >>= 1; c->lf_cands >>= 1; }   /* the recent leaves count */
    }
}

/* Not in the lanes: each receiver with its own view of the job (its candidate samples from the leaf footprint,
 * or its footprints from the lanes' set-up) to cast_footprint. */
static void leaf_receivers(const shared *sh, chunk *c, const tri_job *t, const leaf_cast *lc)
{
    const int leaf_fp = lc->leaf_fp, nt = lc->nt;
    for (unsigned m = leaf_fp ? lc->act & (lc->has[0] | lc->has[1]) : lc->act; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        const uint32_t r = lc->rr[l];
        hpc_view view;
        view.nt = 0;
        view.direct = leaf_fp;
        view.ngroups = 0;
        for (int u = 0; u < nt; u++) {
            if (!((leaf_fp ? lc->has[u] : lc->on[u]) >> l & 1u)) continue;
            const int x = view.nt++;
            view.t[x] = &t[u];
            if (leaf_fp) {
                view.ncand[x] = lc->rc[u][l];
                view.nsure[x] = lc->rsu[u][l];
                view.ngroups |= lc->rg[u][l];
                continue;
            }
            for (int e = 0; e < 4; e++)
                for (int a = 0; a < 3; a++) view.fp[x].e[e][a] = lc->fe[u][e][a][l];
            for (int e = 0; e < 3; e++) view.fp[x].s[e] = lc->fs[u][e][l];
            for (int e = 0; e < 4; e++) { view.fp[x].dlo[e] = lc->fdl[u][e][l]; view.fp[x].dhi[e] = lc->fdh[u][e][l]; }
        }
        ms_grid g;
        memcpy(g.p0, sh->p0 + 4 * (size_t)r, sizeof g.p0);
        memcpy(g.ds, sh->grid_ds, sizeof g.ds);
        memcpy(g.dt, sh->grid_dt, sizeof g.dt);
        g.k = sh->k;
        cast_footprint(sh, c, r, &g, &view);
    }
}

/* The points of a leaf inside V_L against a job (a triangle, or a pair: hpc_pair_batch) with the footprint test,
 * 16 receivers per operation (departure: the paper handles a leaf's points one by one): the point-in-V_L test
 * (POINT-IN-VOLUME, the same arithmetic as vol_point per lane) and hpc_footprint_setup (the same arithmetic per
 * lane, per triangle), then each point's groups and samples (cast_footprint), or with the leaf footprint the
 * samples it leaves, for the leaf's receivers in the lanes. */
_Static_assert(LEAF_POINTS_FOOTPRINT <= LANES, "a leaf's points fit the lanes");
static void cast_leaf_footprint(const shared *sh, chunk *c, const hnode *N, const tri_job *t, uint32_t pl)
{
    leaf_cast lc;
    lc.nt = t->pair > 0 ? 2 : 1;
    for (int l = 0; l < LANES; l++) lc.lopen[l] = NULL;
    if (!(lc.act = leaf_gather(sh, c, N, t, pl, &lc))) return;
    leaf_choose(sh, c, t, &lc);
    if (lc.leaf_fp && !leaf_bound(sh, c, &lc)) return;
    leaf_functions(sh, &lc);
    lc.has[0] = lc.has[1] = 0u;
    lc.lanes = lc.leaf_fp && lc.lanes_ok;
    if (lc.lanes) leaf_lanes_begin(sh, c, &lc);
    if (lc.leaf_fp)
        for (int u = 0; u < lc.ns; u++)
            if (!leaf_shape_samples(sh, c, t, &lc, u)) return;
    leaf_counts(sh, c, &lc);
    if (!lc.lanes) leaf_receivers(sh, c, t, &lc);
}
