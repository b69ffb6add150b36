/* The footprint test's set-up per receiver and triangle (hpc, in place of the paper's group volumes V_Gk): the
 * edge functions as affine functions of the sample's indices, and their slacks. Compiled once (hpc_engine.h);
 * its 16-lane tests are in hpc_footprint_impl.h. */
#include "hpc_engine.h"
#include <math.h>

/* ---- the footprint test (hpc, in place of the paper's group volumes V_Gk) ----
 *
 * Departure from the paper. For a receiver p and a triangle (vertices A, B, C relative to p, the floats the
 * exact test uses), the exact test's edge functions for the direction d are U = ((C x B) . d) / d[kz],
 * V = ((A x C) . d) / d[kz], W = ((B x A) . d) / d[kz] (the 2D cross product of two vertices sheared along d
 * is the triple product over d[kz]), and it reports a hit only when they do not have strictly mixed signs.
 * The sample directions d(i, j) = p0 + i ds + j dt - p of the receiver's grid are affine in (i, j), so each
 * E_e = (X_e . d) is an affine function e0 + i e1 + j e2 of the sample's indices: the triangle's footprint on
 * the light, in the grid's own coordinates, for this one receiver (V_Gk bounds it over the whole group
 * polygon and all pixels' grids, and costs 24 double-precision planes per group and triangle). A group or a
 * lane is rejected when over all its samples some E_e > s_e and some E_e' < -s_e'.
 *
 * The slack s_e bounds the exact test's rounding, so that no sample it calls blocked is ever rejected: with
 * the shear |sx|, |sy| <= 2 (the packet axis, ms_wt_packet_axis; 1 for a lane's own axis) the sheared
 * coordinates are off by at most 9.1 u |V|inf (u = 2^-24, V the vertex), U by at most 146 u |Y1|inf
 * |Y2|inf for the two vertices Y1, Y2 of its edge (the double fall-back at a zero edge only rounds less),
 * so E = U d[kz] by 146 u |Y1| |Y2| |d|inf; the float direction d is off the affine d(i, j) by at most
 * 5 u S per component (S = |p0| + k |ds| + k |dt| + |p|, all inf-norms), which moves E by at most
 * |X_e|_1 5 u S <= 30 u |Y1| |Y2| S; and this test's own float evaluation (the cross product, the three
 * dots, the affine sum) errs by at most 90 u |Y1| |Y2| dmax (dmax >= |d|inf of every sample). s_e =
 * u |Y1| |Y2| (512 dmax + 128 S) covers the sum twice. The t range and alpha only remove hits. */

/* dlo, dhi of a group of gs x gs samples (span = gs - 1) from the coefficients e1, e2 (footprint_groups);
 * cast_leaf_footprint forms the same per lane, 16 receivers at once. */
void hpc_footprint_spans(hpc_footprint *f, float span)
{
    for (int e = 0; e < 4; e++) {
        const float di = f->e[e][1] * span, dj = f->e[e][2] * span;
        f->dlo[e] = ms_minf(di, 0.0f) + ms_minf(dj, 0.0f);
        f->dhi[e] = ms_maxf(di, 0.0f) + ms_maxf(dj, 0.0f);
    }
}

/* The slack's factor for a receiver at p with grid g: u (512 dmax + 128 S), 1% up for its own rounding. */
float hpc_footprint_rel(const ms_grid *g, const float p[3], int k)
{
    float dmax = 0.0f, S = 0.0f;
    for (int a = 0; a < 3; a++) {
        const float ext = (float)(k - 1) * (fabsf(g->ds[a]) + fabsf(g->dt[a]));
        dmax = ms_maxf(dmax, fabsf(g->p0[a] - p[a]) + ext);           /* >= |d|inf of every sample */
        S = ms_maxf(S, fabsf(g->p0[a]) + ext + fabsf(p[a]));
    }
    return 5.9604645e-08f * (1.01f * (512.0f * dmax + 128.0f * S));
}

/* rel: hpc_footprint_rel of the receiver. */
void hpc_footprint_setup(hpc_footprint *f, const float A[3], const float B[3], const float C[3], const ms_grid *g,
                            const float p[3], float rel)
{
    const float *Y[3][2] = { { C, B }, { A, C }, { B, A } };
    const float w[3] = { g->p0[0] - p[0], g->p0[1] - p[1], g->p0[2] - p[2] };
    const float nA = inf_norm3(A), nB = inf_norm3(B), nC = inf_norm3(C);
    const float nrm[3][2] = { { nC, nB }, { nA, nC }, { nB, nA } };
    for (int e = 0; e < 3; e++) {
        float X[3];
        v3_cross(X, Y[e][0], Y[e][1]);
        f->e[e][0] = v3_dot(X, w);
        f->e[e][1] = v3_dot(X, g->ds);
        f->e[e][2] = v3_dot(X, g->dt);
        f->s[e] = rel * nrm[e][0] * nrm[e][1];
    }
    for (int c = 0; c < 3; c++) f->e[3][c] = f->e[0][c] + f->e[1][c] + f->e[2][c];
}
