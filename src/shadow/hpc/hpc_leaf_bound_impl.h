/* Part of the per-ISA engine (hpc_impl.h, compiled once per ISA; included there after hpc_blocks_impl.h): the leaf
 * footprint, a bound of the footprint test over a whole leaf, and rectangle pairs. */

/* ---- the leaf footprint (hpc: the footprint test bounded over a whole leaf) ----
 *
 * Departure from the paper (whose group volumes V_Gk cull whole light groups at a node): the footprint test's
 * edge functions bounded over every receiver of a leaf at once, per light sample. The leaf's receivers lie in
 * a box (centre pc, half extents h) and their grid origins in a box (centre p0c, half extents J); all share
 * the grid's steps ds, dt. For receiver p = pc + q and origin p0 = p0c + j, with Y1, Y2 an edge's vertices
 * relative to pc and x' = w + i ds + j dt (w = p0c - pc) the sample relative to pc, the edge function
 * E = det(Y1 - q, Y2 - q, x' + j - q) is affine in q and in the sample, so, exactly in reals,
 *     E = X . x' + X . j + g(i, j) . q - q . (D x j),   X = Y1 x Y2, D = Y2 - Y1, g = -(X + D x x'),
 * and |E - X . x'| <= sum_c h_c |g_c(i, j)| + sum_c |X_c| J_c + sum_c h_c (|D_c+1| J_c+2 + |D_c+2| J_c+1).
 * g is affine in (i, j), so over a group of gs x gs samples |g_c| <= |g_c(centre)| + (gs-1)/2 (|g_1c| + |g_2c|)
 * (g_1, g_2 its steps): one bound U per function and group. The sum of the three functions (the side of the
 * triangle's plane) is Xs . (x' + j - q), Xs = the sum of the X: its bound is sum_c |Xs_c| (J_c + h_c).
 * footprint_keep then rules a sample out for every receiver of the leaf when E_c - U and E_c + U (E_c = X . x')
 * are beyond the slacks. The slack is the footprint test's for a receiver anywhere in the box with an origin
 * anywhere in its box (|Y - p|inf <= |Y1|inf + |h|inf, dmax and S over both boxes), taken twice: it covers the
 * exact test's rounding as the per-receiver footprint's does, the exact test's vertices being v - p rounded
 * (u of them: at most 12 u |Y1| |Y2| dmax in E, where the bound above is for v - p exact), and this bound's own
 * evaluation (E_c is the footprint's arithmetic at pc; U is a sum of non-negative terms, rounded up by 1e-3 of
 * itself, plus 20 u of the magnitudes of g's terms, which may cancel). So no sample
 * the exact test blocks for any receiver of the leaf is ever ruled out. What it buys: a leaf whose triangle
 * covers no sample of any receiver (a thin bar whose shadow passes between the sample rows of the leaf's
 * receivers) is dropped with one test instead of one footprint per receiver, and the candidate samples of
 * the others bound each receiver's groups and lanes. */
typedef struct leaf_box { float pc[3], h[3], p0c[3], J[3]; } leaf_box;

/* The bound's terms per edge function of a shape (leaf_setup: a triangle, or a rectangle pair's rectangle) and
 * the sum's (at [nf]). */
typedef struct leaf_fn {
    int nf;                   /* edge functions: 3 (a triangle) or 4 (a rectangle) */
    float e[5][3], s[4];      /* E_c's coefficients (as hpc_footprint's), the slacks */
    float gst[4][3][3];       /* per function: g at the grid's origin, per column, per row */
    float ufix[5], uspan[4];  /* per function: U's terms that do not depend on the group */
} leaf_fn;

/* ---- rectangle pairs (hpc: one leaf footprint for a pair that is an axis-aligned rectangle) ----
 *
 * A pair (hpc_pair_batch) whose triangles are the two halves of one axis-aligned rectangle (ms_coplanar_rect_pair,
 * the test coplanar.c merges by: every vertex on one plane, the corners a rectangle, all bitwise) covers exactly
 * that rectangle. Its corners P0..P3 in order around it, the first triangle T0 = (P0, P1, P2), the second
 * T1 = (P0, P2, P3). Relative to a receiver p, as reals (the corners' floats minus p exactly) and for a
 * direction d, the sides' functions are F_i = (P_i+1 x P_i) . d (the footprint's orientation) and the
 * diagonal's D = (P0 x P2) . d: T0's three functions are F0, F1, D and T1's F2, F3, -D (each up to one sign for
 * all three: its own winding). The corners are a parallelogram, P3 = P0 + P2 - P1 exactly in the reals, so
 * P3 x P2 = P0 x P2 + P2 x P1 and P0 x P3 = P0 x P2 + P1 x P0, i.e. exactly
 *     F2 = F1 + D,   F3 = F0 + D.
 * The footprint test's argument (above) makes a sample T0's exact test blocks have T0's three real functions
 * all >= -e or all <= e, e the exact test's error (146 u |Y1| |Y2| dmax, 30 u |Y1| |Y2| S for the direction,
 * and 12 u |Y1| |Y2| dmax for its vertices v - p rounded, as the leaf footprint's comment: at most
 * u M^2 (158 dmax + 30 S), M the largest |P_i - p|inf). Then F2 = F1 + D and F3 = F0 + D are >= -2e (alike
 * <= 2e), and for T1 F0 = F3 - D, F1 = F2 - D likewise: all four sides have no strictly mixed signs beyond 2e,
 * which is the convexity of the rectangle made exact. Each side evaluated (the footprint's arithmetic, off by
 * at most u M^2 102 dmax with the vertices' rounding) is then beyond -s_R for every block by either triangle
 * when s_R >= 2e + 102 u M^2 dmax = u M^2 (418 dmax + 60 S); s_R = RECT_SLACK rel M^2 = 2.02 u M^2
 * (512 dmax + 128 S) covers that twice. The sum of the four is twice either triangle's sum (2 (F0 + F1 + D));
 * a block with all of T0's or T1's functions <= e makes it at most 6e (the evaluated one below 8 s_R), so where
 * it exceeds 2 x the four slacks (8 s_R) the block has the >= signs, and any side below -s_R rules the sample
 * out; alike below: footprint_keep's logic with four functions (footprint_keep_n).
 * Each side is an edge function of two corners, so the leaf footprint's bound over a box of receivers and grid
 * origins applies to it unchanged, and the sum's, Xs . (x' + j - q), Xs = the sum of the P_i+1 x P_i (which
 * does not depend on q around a closed polygon), has the triangle's bound |Xs| . (J + h); the slack is s_R for
 * any receiver in the box (M from the corners' distances to the box centre plus its half extent), taken twice,
 * as the triangle's. So one leaf footprint serves the pair (leaf_setup of 4 functions instead of 6, one
 * leaf_footprint instead of two, no sample either triangle blocks for any receiver of the leaf ruled out).
 * Its candidates are then looped over once for the leaf's receivers, where the four sides and D are evaluated
 * per lane and each triangle's own footprint test (F0, F1, D and F2, F3, -D: its own functions exactly, as a
 * cross product's operands swapped and a negation are exact; their sums from the values, whose rounding is far
 * below the slacks) picks its samples, so that each triangle's exact tests stay on its own candidates (the
 * rectangle's for both doubled the exact tests). MS_HPC_OFF_RECT: every pair as two triangles. */

/* A footprint's shape: a triangle (3 vertices, its own edge functions) or a rectangle pair's rectangle (4
 * corners in order around it; "rectangle pairs" below). fp_edges: each function's two vertices, Y1 x Y2, the
 * same orientation for both (C x B, A x C, B x A as hpc_footprint_setup; P1 x P0, ..., P0 x P3 around the
 * rectangle). */
typedef struct fp_shape { const float *v; int nv; } fp_shape;
static const int fp_edges[2][4][2] = { { { 2, 1 }, { 0, 2 }, { 1, 0 }, { 0, 0 } }, { { 1, 0 }, { 2, 1 }, { 3, 2 }, { 0, 3 } } };

/* The slack's factor of a rectangle's functions (above): s_R = RECT_SLACK rel M^2, M the largest |corner - p|inf. */
#define RECT_SLACK 2.0f

/* A rectangle pair's functions per receiver: its four sides and the diagonal P0 x P2 (the first triangle's
 * third function; the second's is its negation, exactly); rect_tri: each triangle's three of them (above). */
static const int rect_fns[5][2] = { { 1, 0 }, { 2, 1 }, { 3, 2 }, { 0, 3 }, { 0, 2 } };
static const int rect_tri[2][3] = { { 0, 1, 4 }, { 2, 3, 4 } };

/* leaf_fn of the ns shapes shp for box b: the functions of all shapes in the lanes (up to 6), each lane the
 * arithmetic the comments above give (IEEE per lane, as everywhere in lanes16.h). */
static void leaf_setup(const shared *sh, const leaf_box *b, const fp_shape *shp, int ns, leaf_fn *out)
{
    const int k = sh->k, gs = sh->gs;
    const float *ds = sh->grid_ds, *dt = sh->grid_dt;
    float w[3], hmax = 0.0f, dmax = 0.0f, S = 0.0f;
    for (int a = 0; a < 3; a++) {
        w[a] = b->p0c[a] - b->pc[a];
        hmax = ms_maxf(hmax, b->h[a]);
        const float ext = (float)(k - 1) * (fabsf(ds[a]) + fabsf(dt[a]));
        dmax = ms_maxf(dmax, fabsf(w[a]) + b->J[a] + b->h[a] + ext);
        S = ms_maxf(S, fabsf(b->p0c[a]) + b->J[a] + ext + fabsf(b->pc[a]) + b->h[a]);
    }
    const float rel = 2.0f * 5.9604645e-08f * (1.01f * (512.0f * dmax + 128.0f * S));
    float y1[3][LANES] = { { 0 } }, y2[3][LANES] = { { 0 } }, n12[LANES] = { 0 };
    int lane0[2];
    for (int u = 0, l = 0; u < ns; u++) {
        const int nv = shp[u].nv, (*pair)[2] = fp_edges[nv == 4];
        float Y[4][3], nY[4], M = 0.0f;
        for (int v = 0; v < nv; v++) {
            for (int a = 0; a < 3; a++) Y[v][a] = shp[u].v[3 * v + a] - b->pc[a];
            nY[v] = inf_norm3(Y[v]) + hmax;
            M = ms_maxf(M, nY[v]);
        }
        lane0[u] = l;
        for (int f = 0; f < nv; f++, l++) {
            for (int a = 0; a < 3; a++) { y1[a][l] = Y[pair[f][0]][a]; y2[a][l] = Y[pair[f][1]][a]; }
            n12[l] = nv == 4 ? RECT_SLACK * M * M : nY[pair[f][0]] * nY[pair[f][1]];
        }
    }
    l16 Y1[3], Y2[3], X[3], D[3], Dw[3], Dds[3], Ddt[3];
    for (int a = 0; a < 3; a++) { Y1[a] = l16_load(y1[a]); Y2[a] = l16_load(y2[a]); D[a] = l16_sub(Y2[a], Y1[a]); }
    const l16 W[3] = { l16_set1(w[0]), l16_set1(w[1]), l16_set1(w[2]) };
    const l16 DS[3] = { l16_set1(ds[0]), l16_set1(ds[1]), l16_set1(ds[2]) }, DT[3] = { l16_set1(dt[0]), l16_set1(dt[1]), l16_set1(dt[2]) };
#define HPC_CROSS16(r, x, y)                                                                   \
    (r[0] = l16_sub(l16_mul(x[1], y[2]), l16_mul(x[2], y[1])),                                 \
     r[1] = l16_sub(l16_mul(x[2], y[0]), l16_mul(x[0], y[2])),                                 \
     r[2] = l16_sub(l16_mul(x[0], y[1]), l16_mul(x[1], y[0])))
#define HPC_DOT16(x, y) l16_add(l16_add(l16_mul(x[0], y[0]), l16_mul(x[1], y[1])), l16_mul(x[2], y[2]))
    HPC_CROSS16(X, Y1, Y2);
    HPC_CROSS16(Dw, D, W);
    HPC_CROSS16(Dds, D, DS);
    HPC_CROSS16(Ddt, D, DT);
    float E0[LANES], E1[LANES], E2[LANES], SL[LANES], G[3][3][LANES], UF[LANES], US[LANES], XA[3][LANES];
    l16_store(E0, HPC_DOT16(X, W));
    l16_store(E1, HPC_DOT16(X, DS));
    l16_store(E2, HPC_DOT16(X, DT));
#undef HPC_CROSS16
#undef HPC_DOT16
    l16_store(SL, l16_mul(l16_set1(rel), l16_load(n12)));
    const l16 zero = l16_set1(0.0f);
    l16 jx = zero, kx = zero, sp = zero, mag = l16_add(l16_add(l16_abs(X[0]), l16_abs(X[1])), l16_abs(X[2]));
    const l16 nD = l16_add(l16_add(l16_abs(D[0]), l16_abs(D[1])), l16_abs(D[2]));
    for (int a = 0; a < 3; a++) {
        const int a1 = (a + 1) % 3, a2 = (a + 2) % 3;
        l16_store(G[0][a], l16_sub(zero, l16_add(X[a], Dw[a])));
        l16_store(G[1][a], l16_sub(zero, Dds[a]));
        l16_store(G[2][a], l16_sub(zero, Ddt[a]));
        l16_store(XA[a], X[a]);
        const l16 h = l16_set1(b->h[a]);
        jx = l16_add(jx, l16_mul(l16_abs(X[a]), l16_set1(b->J[a])));
        kx = l16_add(kx, l16_mul(h, l16_add(l16_mul(l16_abs(D[a1]), l16_set1(b->J[a2])), l16_mul(l16_abs(D[a2]), l16_set1(b->J[a1])))));
        sp = l16_add(sp, l16_mul(h, l16_add(l16_abs(Dds[a]), l16_abs(Ddt[a]))));
        /* the rounding of g's terms (X + D x w may cancel) and of their affine sums: 20 u of the magnitudes */
        mag = l16_add(mag, l16_mul(l16_mul(l16_set1(2.0f), nD), l16_set1(fabsf(w[a]) + (float)k * (fabsf(ds[a]) + fabsf(dt[a])))));
    }
    l16_store(UF, l16_add(l16_add(jx, kx), l16_mul(l16_set1(1.2e-6f * (b->h[0] + b->h[1] + b->h[2])), mag)));
    l16_store(US, l16_mul(l16_set1(0.5f * (float)(gs - 1)), sp));
    for (int u = 0; u < ns; u++) {
        leaf_fn *o = &out[u];
        const int nf = shp[u].nv;
        o->nf = nf;
        float Xs[3] = { 0.0f, 0.0f, 0.0f };
        for (int f = 0; f < nf; f++) {
            const int l = lane0[u] + f;
            o->e[f][0] = E0[l];
            o->e[f][1] = E1[l];
            o->e[f][2] = E2[l];
            o->s[f] = SL[l];
            for (int q = 0; q < 3; q++)
                for (int a = 0; a < 3; a++) o->gst[f][q][a] = G[q][a][l];
            o->ufix[f] = UF[l];
            o->uspan[f] = US[l];
            for (int a = 0; a < 3; a++) Xs[a] += XA[a][l];
        }
        for (int c = 0; c < 3; c++) {
            o->e[nf][c] = o->e[0][c] + o->e[1][c] + o->e[2][c];
            if (nf == 4) o->e[nf][c] += o->e[3][c];
        }
        o->ufix[nf] = 0.0f;
        for (int a = 0; a < 3; a++) o->ufix[nf] += fabsf(Xs[a]) * (b->J[a] + b->h[a]);
        o->ufix[nf] *= 1.001f;
    }
}

/* The samples (bits as a mask's) a triangle (its leaf_fn) may block for some receiver of box b, in cand (mw
 * words); its groups are returned (0: the triangle blocks no sample of any of them). */
static uint64_t leaf_footprint(const shared *sh, const leaf_box *b, const leaf_fn *fn, uint64_t *cand)
{
    const int k = sh->k, gs = sh->gs, rows = LANES / gs;
    const float (*e)[3] = fn->e, *ufix = fn->ufix, *uspan = fn->uspan;
    const int nf = fn->nf;
    const l16 s[4] = { l16_set1(fn->s[0]), l16_set1(fn->s[1]), l16_set1(fn->s[2]), l16_set1(nf == 4 ? fn->s[3] : 0.0f) };
    /* the groups: each function at each group's first sample, its change over the group, +- U */
    float base[5][64], U[4][64];
    uint64_t groups = 0;
    const float half = 0.5f * (float)(gs - 1), span = (float)(gs - 1);
    for (int g0 = 0; g0 < sh->G; g0 += LANES) {
        const l16 gi = l16_load(sh->group_i0 + g0), gj = l16_load(sh->group_j0 + g0);
        const l16 ci = l16_add(gi, l16_set1(half)), cj = l16_add(gj, l16_set1(half));
        l16 lo[5], hi[5];
        for (int f = 0; f <= nf; f++) {
            const l16 bs = l16_add(l16_add(l16_set1(e[f][0]), l16_mul(l16_set1(e[f][1]), gi)), l16_mul(l16_set1(e[f][2]), gj));
            l16_store(base[f] + g0, bs);
            l16 u = l16_set1(ufix[f]);
            if (f < nf) {
                l16 acc = l16_set1(ufix[f] + uspan[f]);
                for (int a = 0; a < 3; a++) {
                    const l16 ga = l16_add(l16_add(l16_set1(fn->gst[f][0][a]), l16_mul(l16_set1(fn->gst[f][1][a]), ci)),
                                           l16_mul(l16_set1(fn->gst[f][2][a]), cj));
                    acc = l16_add(acc, l16_mul(l16_abs(ga), l16_set1(b->h[a])));
                }
                u = l16_mul(acc, l16_set1(1.001f));
                l16_store(U[f] + g0, u);
            }
            const float di = e[f][1] * span, dj = e[f][2] * span;
            lo[f] = l16_sub(l16_add(bs, l16_set1(ms_minf(di, 0.0f) + ms_minf(dj, 0.0f))), u);
            hi[f] = l16_add(l16_add(bs, l16_set1(ms_maxf(di, 0.0f) + ms_maxf(dj, 0.0f))), u);
        }
        groups |= (uint64_t)footprint_keep_n(lo, hi, s, nf) << g0;
    }
    groups &= sh->all_groups;
    memset(cand, 0, (size_t)sh->mw * sizeof *cand);
    if (!groups) return 0;
    static const float off[2][2][LANES] = {
        { { 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3 }, { 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3 } },
        { { 0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7 }, { 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1 } } };
    const int wi = gs == 8;
    const l16 oi = l16_load(off[wi][0]), oj = l16_load(off[wi][1]);
    l16 foff[5];
    for (int f = 0; f <= nf; f++) foff[f] = l16_add(l16_mul(l16_set1(e[f][1]), oi), l16_mul(l16_set1(e[f][2]), oj));
    const uint64_t seg = (UINT64_C(1) << gs) - 1u;
    uint64_t out = 0;
    for (uint64_t m = groups; m; m &= m - 1) {
        const int gk = __builtin_ctzll(m);
        const int i0 = (int)sh->group_i0[gk], j0 = (int)sh->group_j0[gk];
        for (int jb = j0; jb < j0 + gs; jb += rows) {
            l16 lo[5], hi[5];
            for (int f = 0; f <= nf; f++) {
                const float b0 = jb == j0 ? base[f][gk] : e[f][0] + e[f][1] * (float)i0 + e[f][2] * (float)jb;
                const l16 E = l16_add(l16_set1(b0), foff[f]), u = l16_set1(f < nf ? U[f][gk] : ufix[nf]);
                lo[f] = l16_sub(E, u);
                hi[f] = l16_add(E, u);
            }
            const unsigned keep = footprint_keep_n(lo, hi, s, nf);
            if (!keep) continue;
            out |= UINT64_C(1) << gk;
            for (int rr = 0; rr < rows; rr++) {
                const int s0 = (jb + rr) * k + i0;
                cand[s0 >> 6] |= (uint64_t)(keep >> (rr * gs) & seg) << (s0 & 63);
            }
        }
    }
    return out;
}
