/* The hard-shadow test (L70) one sample at a time: the scalar form of the exact test (the 16-lane form is
 * hpc_exact_impl.h), and an alpha-tested triangle's opacity. Compiled once (hpc_engine.h). */
#include "hpc_engine.h"
#include "accel/ray_triangle.h"
#include "visibility/alpha.h"

/* The reference tracer's lane test for one sample (ray_triangle.h, as raytrace's packets): 1 if the
 * triangle blocks the segment from the receiver o to o + d at a parameter in [near, far]. A, B, C: the
 * vertices minus o; num: ms_wt_offset(o, tri, N). */
int hpc_sample_blocked(const float o[3], const float d[3], int kz, const float *tri, const float N[3],
                          const float A[3], const float B[3], const float C[3], float num, float tmin, float tmax)
{
    if (kz < 0) return ms_wt_segment(o, d, tri, N, tmin, tmax);
    const int kx = kz + 1 == 3 ? 0 : kz + 1, ky = kx + 1 == 3 ? 0 : kx + 1;
    const float inv = 1.0f / d[kz];
    return ms_wt_segment_sheared(A, B, C, kz, d[kx] * inv, d[ky] * inv, d, N, num, tmin, tmax);
}

/* Alpha-tested triangle t (alpha.h) at sample (i, j) of q's grid: 1 where it occludes. The sample point is the
 * pattern's float, formed as ms_pattern_points_range forms it. */
int hpc_alpha_opaque(const shared *sh, const tri_job *t, const ms_shadow_query *q, const ms_grid *g, int i, int j)
{
    float L[3];
    for (int a = 0; a < 3; a++) L[a] = g->p0[a] + (float)i * g->ds[a] + (float)j * g->dt[a];
    return ms_alpha_segment_occludes(sh->ctx->alpha, t->self, q->p, L);
}

/* Tests the open samples of group gk of receiver r (L68-L71); returns 1 when none is left open. An
 * alpha-tested triangle blocks a sample only where it is opaque (any hit, alpha.h). */
int hpc_cast_group(const shared *sh, chunk *c, uint64_t *open, const int8_t *kz, int gk, const ms_shadow_query *q,
                      const ms_grid *g, const tri_job *t, const float A[3], const float B[3], const float C[3], float num)
{
    const int k = sh->k, gs = sh->gs, gpr = k / gs;
    const int i0 = (gk % gpr) * gs, j0 = (gk / gpr) * gs;
    const uint64_t seg = (UINT64_C(1) << gs) - 1u;   /* gs <= 8 */
    const int alpha = ms_alpha_tested(sh->ctx->alpha, t->self);
    int left = 0;
    for (int j = j0; j < j0 + gs; j++) {
        const int s0 = j * k + i0, w = s0 >> 6, b = s0 & 63;
        uint64_t bits = open[w] >> b & seg;
        while (bits) {
            const int di = __builtin_ctzll(bits);
            bits &= bits - 1u;
            const int i = i0 + di, s = s0 + di;
            float d[3];
            for (int a = 0; a < 3; a++) d[a] = (g->p0[a] + (float)i * g->ds[a] + (float)j * g->dt[a]) - q->p[a];
            c->cnt[C_SAMPLE_TESTS]++;
            if (hpc_sample_blocked(q->p, d, kz[s / LANES], t->v, t->N, A, B, C, num, sh->ctx->near, sh->ctx->far) &&
                !(alpha && !hpc_alpha_opaque(sh, t, q, g, i, j))) {
                open[w] &= ~(UINT64_C(1) << (b + di));
                c->cnt[C_SAMPLES_BLOCKED]++;
            }
        }
        left |= (open[w] >> b & seg) != 0;
    }
    return !left;
}
