/* Part of the per-ISA engine (hpc_impl.h, compiled once per ISA; included there after hpc_engine.h): the footprint
 * test in the lanes (its set-up and proof: hpc_footprint.c). */

/* Which sign a hit needs, from the sum of the edge functions, E_sum = -((B - A) x (C - A)) . d (which side of
 * the triangle's plane the direction points to): a hit has all three of one sign (zeros aside), so where
 * E_sum stays above twice the sum of the slacks (its coefficients' and evaluation's rounding are far below
 * them) not all three can be <= 0 up to their slacks: all are >= 0, and any E_e < -s_e rules the samples
 * out; alike below. Elsewhere (the plane through the receiver parallel to the triangle crosses these
 * samples) only mixed signs beyond the slacks rule them out. lo, hi: bounds of E_0, E_1, E_2 and E_sum over
 * each lane's samples; s: each lane's slacks. Returns the lanes that may be hit. */
static inline unsigned footprint_keep_n(const l16 *lo, const l16 *hi, const l16 *s, int n)
{
    l16 ss = s[0];
    for (int e = 1; e < n; e++) ss = l16_add(ss, s[e]);
    const l16 s2 = l16_mul(l16_set1(2.0f), ss);
    const unsigned up = l16_gt(lo[n], s2), down = l16_lt(hi[n], l16_sub(l16_set1(0.0f), s2));
    unsigned pos = 0, neg = 0;
    for (int e = 0; e < n; e++) {
        pos |= l16_gt(lo[e], s[e]);                          /* E_e > s_e throughout */
        neg |= l16_lt(hi[e], l16_sub(l16_set1(0.0f), s[e]));   /* E_e < -s_e throughout */
    }
    return ~((pos & neg) | (up & neg) | (down & pos)) & 0xffffu;
}

/* A triangle's three functions and their sum (lo[3], hi[3]). */
static inline unsigned footprint_keep_lanes(const l16 lo[4], const l16 hi[4], const l16 s[3]) { return footprint_keep_n(lo, hi, s, 3); }

/* The same with one slack for every lane (a receiver's functions over 16 groups or samples). */
static inline unsigned footprint_keep(const l16 lo[4], const l16 hi[4], const float s[3])
{
    const l16 sl[3] = { l16_set1(s[0]), l16_set1(s[1]), l16_set1(s[2]) };
    return footprint_keep_lanes(lo, hi, sl);
}

/* The lanes whose samples the exact test's edge functions surely pass: all three E_e beyond their slacks with one
 * sign. The slack bounds |E_e - U_e d[kz]| by half of s_e (above: it covers the error sum twice), so there each
 * of the exact test's U, V, W is nonzero with the sign of E_e d[kz]: no zero edge (no double fall-back), no
 * mixed signs, det = U + V + W nonzero. Only the t range is then left to decide (block_hits). A slack below
 * the normal range proves nothing (its product may have underflowed): footprint_slack_ok gives the lanes whose
 * three slacks are normal, valid; the others are left to the exact test. */
static inline unsigned footprint_sure_lanes(const l16 E[3], const l16 s[3], unsigned valid)
{
    unsigned pos = valid, neg = valid;
    for (int e = 0; e < 3; e++) {
        pos &= l16_gt(E[e], s[e]);
        neg &= l16_lt(E[e], l16_sub(l16_set1(0.0f), s[e]));
    }
    return pos | neg;
}

static inline unsigned footprint_slack_ok(const l16 s[3])
{
    const l16 tiny = l16_set1(1e-30f);
    return l16_gt(s[0], tiny) & l16_gt(s[1], tiny) & l16_gt(s[2], tiny);
}

/* The groups (bit gk) whose samples the footprint may hold, bounding each edge function over the group's
 * gs x gs samples (16 groups per operation). base: each function at each group's first sample, [e][gk]. */
static uint64_t footprint_groups(const shared *sh, const hpc_footprint *f, float base[4][64])
{
    const float *dlo = f->dlo, *dhi = f->dhi;
    uint64_t cand = 0;
    for (int g0 = 0; g0 < sh->G; g0 += LANES) {
        const l16 gi = l16_load(sh->group_i0 + g0), gj = l16_load(sh->group_j0 + g0);
        l16 lo[4], hi[4];
        for (int e = 0; e < 4; e++) {
            const l16 b = l16_add(l16_add(l16_set1(f->e[e][0]), l16_mul(l16_set1(f->e[e][1]), gi)), l16_mul(l16_set1(f->e[e][2]), gj));
            l16_store(base[e] + g0, b);
            lo[e] = l16_add(b, l16_set1(dlo[e]));
            hi[e] = l16_add(b, l16_set1(dhi[e]));
        }
        cand |= (uint64_t)footprint_keep(lo, hi, f->s) << g0;
    }
    return cand & sh->all_groups;
}

/* The lanes of the 16-sample block at (i0, j0) the footprint may hold; off[e]: the block's offsets
 * e1 di + e2 dj per lane, made once per pair (footprint_offsets). gbase: the functions at the block's first
 * sample when it is a group's first (footprint_groups made them), else NULL. E: the functions per lane, for
 * the sure lanes (footprint_sure_lanes), which the caller asks only of blocks with lanes to test. */
static unsigned footprint_lanes(const hpc_footprint *f, const l16 off[4], int i0, int j0, const float *gbase, int gk,
                                l16 E[4])
{
    for (int e = 0; e < 4; e++)
        E[e] = l16_add(l16_set1(gbase ? gbase[64 * e + gk] : f->e[e][0] + f->e[e][1] * (float)i0 + f->e[e][2] * (float)j0), off[e]);
    return footprint_keep(E, E, f->s);
}

static void footprint_offsets(const hpc_footprint *f, l16 oi, l16 oj, l16 off[4])
{
    for (int e = 0; e < 4; e++) off[e] = l16_add(l16_mul(l16_set1(f->e[e][1]), oi), l16_mul(l16_set1(f->e[e][2]), oj));
}

/* hpc_footprint_spans per lane: e1, e2 of 16 receivers' function; the least and largest change to dlo, dhi. */
static inline void spans16(l16 e1, l16 e2, l16 span, l16 zero, float *dlo, float *dhi)
{
    const l16 di = l16_mul(e1, span), dj = l16_mul(e2, span);
    l16_store(dlo, l16_add(l16_min(di, zero), l16_min(dj, zero)));
    l16_store(dhi, l16_add(l16_max(di, zero), l16_max(dj, zero)));
}
