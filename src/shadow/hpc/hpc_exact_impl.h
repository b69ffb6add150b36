/* Part of the per-ISA engine (hpc_impl.h, compiled once per ISA; included there after hpc_slots_impl.h): the
 * hard-shadow test (L70) of 16 rays at once (the scalar form: hpc_exact.c). */

/* sel3(m0, m1, x0, x1, x2): per lane x0 where m0, x1 where m1, else x2 (a lane's component by its axis). */
static inline l16 sel3(unsigned m0, unsigned m1, l16 x0, l16 x1, l16 x2) { return l16_select(m0, x0, l16_select(m1, x1, x2)); }

/* The hard-shadow test (L70) of 16 rays in the lanes, each lane what hpc_sample_blocked computes for its ray, in the
 * same order: ray l from its receiver P[l] along d[l] (formed by the caller as hpc_sample_blocked forms it), sheared
 * along its packet's axis (one packet = 16 consecutive samples of a row of that receiver's grid, raytrace's):
 * axis 0 on lanes m0, 1 on m1, none on mneg (each its own, ms_wt_rays16_own: raytrace's ms_wt_segment), 2 on the
 * others; z0 >= 0: every lane's axis is z0 (no per-lane selection). V: the triangle's vertices relative to each
 * lane's receiver (world axes); num: each lane's plane offset (ms_wt_offset). Lanes with an edge function
 * exactly 0 go to the scalar form too (as raytrace's lanes do). Returns the lanes of live triangle t blocks.
 * Written once for both layouts: a receiver's 16 samples (group_block16) and a leaf's 16 receivers at one
 * sample (leaf_lanes_sample). */
static unsigned exact16(const shared *sh, const tri_job *t, const l16 P[3], const l16 V[3][3], const l16 d[3], l16 num,
                        unsigned m0, unsigned m1, unsigned mneg, int z0, unsigned live)
{
    /* kz = 0: kx = 1, ky = 2; kz = 1: kx = 2, ky = 0; kz = 2: kx = 0, ky = 1 */
    l16 dz, dx, dy, V3[3][3];
    if (z0 >= 0) {
        const int zx = z0 + 1 == 3 ? 0 : z0 + 1, zy = zx + 1 == 3 ? 0 : zx + 1;
        dz = d[z0]; dx = d[zx]; dy = d[zy];
        for (int v = 0; v < 3; v++) { V3[v][0] = V[v][zx]; V3[v][1] = V[v][zy]; V3[v][2] = V[v][z0]; }
    } else {
        dz = sel3(m0, m1, d[0], d[1], d[2]); dx = sel3(m0, m1, d[1], d[2], d[0]); dy = sel3(m0, m1, d[2], d[0], d[1]);
        for (int v = 0; v < 3; v++) {
            V3[v][0] = sel3(m0, m1, V[v][1], V[v][2], V[v][0]);
            V3[v][1] = sel3(m0, m1, V[v][2], V[v][0], V[v][1]);
            V3[v][2] = sel3(m0, m1, V[v][0], V[v][1], V[v][2]);
        }
    }
    const l16 inv = l16_div(l16_set1(1.0f), dz), sx = l16_mul(dx, inv), sy = l16_mul(dy, inv);
    const float *N = t->N, near = sh->ctx->near, far = sh->ctx->far;
    unsigned z, zown = 0;
    unsigned hit = ms_wt_rays16(V3, sx, sy, d, N, num, near, far, live & ~mneg, &z);
    if (live & mneg) hit |= ms_wt_rays16_own(V, d, N, num, near, far, live & mneg, &zown);
    const unsigned rest = z | zown;
    if (rest) {
        float dv[3][LANES], pv[3][LANES], vv[3][3][LANES], sxv[LANES], syv[LANES], nv[LANES];
        for (int a = 0; a < 3; a++) {
            l16_store(dv[a], d[a]);
            l16_store(pv[a], P[a]);
            for (int v = 0; v < 3; v++) l16_store(vv[v][a], V[v][a]);
        }
        l16_store(sxv, sx);
        l16_store(syv, sy);
        l16_store(nv, num);
        for (unsigned m = rest; m; m &= m - 1) {
            const int l = __builtin_ctz(m);
            const float dl[3] = { dv[0][l], dv[1][l], dv[2][l] }, pl[3] = { pv[0][l], pv[1][l], pv[2][l] };
            const float A[3] = { vv[0][0][l], vv[0][1][l], vv[0][2][l] }, B[3] = { vv[1][0][l], vv[1][1][l], vv[1][2][l] };
            const float C[3] = { vv[2][0][l], vv[2][1][l], vv[2][2][l] };
            const int kl = (mneg >> l & 1) ? -1 : (m0 >> l & 1) ? 0 : (m1 >> l & 1) ? 1 : 2;
            const int b = kl < 0 ? ms_wt_segment(pl, dl, t->v, N, near, far)
                                 : ms_wt_segment_sheared(A, B, C, kl, sxv[l], syv[l], dl, N, nv[l], near, far);
            hit |= (unsigned)b << l;
        }
    }
    return hit;
}

/* The lanes of live whose ray (d from its receiver, num its plane offset) meets triangle t's plane within [near,
 * far], by the exact test's own operations (ms_wt_rays16's tail: d . N, the signed offset num against near and far
 * times |d . N|): for lanes whose edge functions surely pass (footprint_sure_lanes) this is the whole of the exact
 * test's answer, bit for bit, without the shear and the edge functions. */
static unsigned t_range16(const shared *sh, const tri_job *t, const l16 d[3], l16 num, unsigned live)
{
    const float *N = t->N;
    const l16 zero = l16_set1(0.0f);
    const l16 den = l16_add(l16_add(l16_mul(d[0], l16_set1(N[0])), l16_mul(d[1], l16_set1(N[1]))), l16_mul(d[2], l16_set1(N[2])));
    const l16 ns = l16_select(l16_lt(den, zero), l16_sub(zero, num), num), aden = l16_abs(den);
    return live & l16_gt(aden, zero) & l16_le(l16_mul(l16_set1(sh->ctx->near), aden), ns) &
           l16_le(ns, l16_mul(l16_set1(sh->ctx->far), aden));
}

/* The directions of receiver q's 16 samples (i0 + l % w, j0 + l / w) of its grid g (w = 4 or 8 columns), formed
 * as hpc_sample_blocked forms them. */
static void block_dirs(const ms_shadow_query *q, const ms_grid *g, int i0, int j0, int w, l16 d[3])
{
    /* Lane l's column and row offsets in the block (small integers: exact in float). */
    static const float off[2][2][LANES] = {
        { { 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3 }, { 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3 } },
        { { 0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7 }, { 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1 } } };
    const int wi = w == 8;
    const l16 li = l16_add(l16_set1((float)i0), l16_load(off[wi][0])), lj = l16_add(l16_set1((float)j0), l16_load(off[wi][1]));
    for (int a = 0; a < 3; a++)
        d[a] = l16_sub(l16_add(l16_add(l16_set1(g->p0[a]), l16_mul(li, l16_set1(g->ds[a]))), l16_mul(lj, l16_set1(g->dt[a]))),
                       l16_set1(q->p[a]));
}

/* The hard-shadow test of 16 samples of receiver q at once (L70): lane l is sample (i0 + l % w, j0 + l / w) of
 * its grid g (w = 4 or 8 columns); live: the lanes to test; A, B, C: the vertices relative to q; num: q's plane
 * offset. Returns the lanes triangle t blocks (exact16). */
static unsigned group_block16(const shared *sh, const ms_shadow_query *q, const ms_grid *g, const int8_t *kz, int i0,
                              int j0, int w, unsigned live, const tri_job *t, const float A[3], const float B[3],
                              const float C[3], float num)
{
    const int k = sh->k, rows = LANES / w;
    /* A group lies within one 16-sample packet per row: the row's packet gives its lanes' shear axis. */
    unsigned m0 = 0, m1 = 0, mneg = 0;
    const unsigned rowbits = (1u << w) - 1u;
    int z0 = kz[(j0 * k + i0) / LANES], uniform = z0 >= 0;
    for (int r = 0; r < rows; r++) {
        const int z = kz[((j0 + r) * k + i0) / LANES];
        uniform &= z == z0;
        m0 |= (z == 0 ? rowbits : 0u) << (r * w);
        m1 |= (z == 1 ? rowbits : 0u) << (r * w);
        mneg |= (z < 0 ? rowbits : 0u) << (r * w);
    }
    l16 d[3];
    block_dirs(q, g, i0, j0, w, d);
    const l16 P[3] = { l16_set1(q->p[0]), l16_set1(q->p[1]), l16_set1(q->p[2]) };
    const l16 V[3][3] = { { l16_set1(A[0]), l16_set1(A[1]), l16_set1(A[2]) },
                          { l16_set1(B[0]), l16_set1(B[1]), l16_set1(B[2]) },
                          { l16_set1(C[0]), l16_set1(C[1]), l16_set1(C[2]) } };
    return exact16(sh, t, P, V, d, l16_set1(num), m0, m1, mneg, uniform ? z0 : -1, live);
}

/* hpc_cast_group with the 16-lane test: the group's open samples 16 at a time. */
static int cast_group16(const shared *sh, chunk *c, uint64_t *open, const int8_t *kz, int gk, const ms_shadow_query *q,
                        const ms_grid *g, const tri_job *t, const float A[3], const float B[3], const float C[3], float num)
{
    const int k = sh->k, gs = sh->gs, gpr = k / gs, rows = LANES / gs;
    const int i0 = (gk % gpr) * gs, j0 = (gk / gpr) * gs;
    const uint64_t seg = (UINT64_C(1) << gs) - 1u;
    const int alpha = ms_alpha_tested(sh->ctx->alpha, t->self);
    int left = 0;
    for (int jb = j0; jb < j0 + gs; jb += rows) {
        unsigned live = 0;
        for (int r = 0; r < rows; r++) {
            const int s0 = (jb + r) * k + i0;
            live |= (unsigned)(open[s0 >> 6] >> (s0 & 63) & seg) << (r * gs);
        }
        if (!live) continue;
        c->cnt[C_SAMPLE_TESTS] += (uint64_t)__builtin_popcount(live);
        unsigned hit = group_block16(sh, q, g, kz, i0, jb, gs, live, t, A, B, C, num);
        if (hit && alpha)
            for (unsigned m = hit; m; m &= m - 1) {
                const int l = __builtin_ctz(m);
                if (!hpc_alpha_opaque(sh, t, q, g, i0 + l % gs, jb + l / gs)) hit &= ~(1u << l);
            }
        c->cnt[C_SAMPLES_BLOCKED] += (uint64_t)__builtin_popcount(hit);
        for (int r = 0; r < rows; r++) {
            const int s0 = (jb + r) * k + i0;
            open[s0 >> 6] &= ~((uint64_t)(hit >> (r * gs) & seg) << (s0 & 63));
        }
    }
    for (int j = j0; j < j0 + gs && !left; j++) {
        const int s0 = j * k + i0;
        left |= (open[s0 >> 6] >> (s0 & 63) & seg) != 0;
    }
    return !left;
}
