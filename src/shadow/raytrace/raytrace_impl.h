/* The packet tracer of method "raytrace" (raytrace.c), one source compiled per ISA: raytrace_packets.c
 * (portable), raytrace_packets_avx2.c, raytrace_packets_avx512.c. The lane loops are plain C over 16
 * lanes that the compiler vectorises for the file's instruction set; every lane's arithmetic is the same
 * IEEE operations in the same order (no FMA contraction, -ffp-contract=off), so every instance gives the
 * same masks. Included once per file; defines ms_raytrace_samples_<isa>. */
#include "shadow/method.h"
#include "raytrace.h"
#include "visibility/alpha.h"
#include "core/perk.h"
#include "light/pattern.h"
#include "light/light_frame.h"
#include "core/vec.h"
#include "accel/ray_triangle.h"
#include "visibility/lanes16.h"
#include "visibility/wt_rays16.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LANES 16


typedef struct packet {
    float o[3];
    float d[3][LANES], inv[3][LANES];
    float tmin, tmax;
    int live[LANES];        /* 1 while the ray is unoccluded */
    /* Watertight test (ray_triangle.h), set up by packet_shear: one shear axis kz for all lanes (the
     * origin is common, so each triangle is translated and permuted once per packet), per-lane
     * shear; kz < 0 when no axis suits every lane and lanes are tested one by one. */
    int kx, ky, kz;
    int pref;               /* the light's shear axis (ms_light_shear_axis) */
    float sx[LANES], sy[LANES];
    float o_lo[3], o_hi[3]; /* the origin shifted by the box margin (ms_wt_box_origins), set by trace_packet */
} packet;

/* The packet's shear: the axis its lanes share (ms_wt_packet_axis; kz = -1: the lanes are tested one by
 * one) and per lane Sx = d[kx] * (1/d[kz]) with the lane's 1/d of the slab test (the paper divides; any
 * shear that maps the ray onto the z axis serves). */
static void packet_shear(packet *pk)
{
    int kz;
    pk->kz = ms_wt_packet_axis(pk->d[0], pk->d[1], pk->d[2], LANES, pk->pref, &kz);
    pk->kx = kz + 1 == 3 ? 0 : kz + 1;
    pk->ky = pk->kx + 1 == 3 ? 0 : pk->kx + 1;
    for (int l = 0; l < LANES; l++) {
        pk->sx[l] = pk->d[pk->kx][l] * pk->inv[kz][l];
        pk->sy[l] = pk->d[pk->ky][l] * pk->inv[kz][l];
    }
}

static int any_live(const int *live)
{
    int a = 0;
    for (int l = 0; l < LANES; l++) a |= live[l];
    return a;
}

/* 1 if any live ray of the packet enters the node within [tmin, tmax]. The box is widened to match
 * the watertight triangle test (ms_wt_box_origins), once for all lanes since the origin is common. */
static int packet_enters(const packet *pk, const ms_bvh_node *n)
{
    float lo[3], hi[3];
    for (int a = 0; a < 3; a++) { lo[a] = n->bmin[a] - pk->o_lo[a]; hi[a] = n->bmax[a] - pk->o_hi[a]; }
    int hit = 0;
    for (int l = 0; l < LANES; l++) {
        float t0 = pk->tmin, t1 = pk->tmax;
        for (int a = 0; a < 3; a++) {
            float x = lo[a] * pk->inv[a][l], y = hi[a] * pk->inv[a][l];
            /* Plain compares (fminf/fmaxf are calls without -ffast-math); a NaN from 0*inf, the origin
             * on a slab plane of an axis-parallel ray, leaves t0/t1 unchanged. */
            float mn = x < y ? x : y, mx = x < y ? y : x;
            t0 = mn > t0 ? mn : t0;
            t1 = mx < t1 ? mx : t1;
        }
        /* Exit widened by Ize's bound as in ms_bvh_occluded. */
        hit |= (t0 <= t1 * MS_WT_FAR_SCALE) & pk->live[l];
    }
    return hit;
}

/* The watertight test (ray_triangle.h) against every live lane; clears the lanes the triangle blocks.
 * The vertices relative to the common origin are computed and permuted once, and so is the
 * origin's offset (v - o) . N from the triangle's plane (N = ms_wt_normal, kept by the BVH); the
 * lane loop is branch-free so that it vectorises. The t range is tested on that offset against tmin
 * and tmax scaled by d . N (sign adjusted), without a division: only the any-hit answer is needed
 * here. A lane with an edge function exactly 0 is left to a scalar pass that redoes it in double
 * (as ms_wt_evaluate does); it is rarely taken. */
static void packet_triangle(packet *pk, const float *tri, const float N[3])
{
    if (pk->kz < 0) {   /* each lane its own axis: ms_wt_segment, 16 lanes at once (ms_wt_rays16_own) */
        unsigned live = 0, zero;
        for (int l = 0; l < LANES; l++) live |= (unsigned)(pk->live[l] != 0) << l;
        if (!live) return;
        l16 A[3][3];
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) A[v][a] = l16_set1(tri[3 * v + a] - pk->o[a]);
        const l16 d[3] = { l16_load(pk->d[0]), l16_load(pk->d[1]), l16_load(pk->d[2]) };
        const unsigned hit = ms_wt_rays16_own(A, d, N, l16_set1(ms_wt_offset(pk->o, tri, N)), pk->tmin, pk->tmax, live, &zero);
        for (int l = 0; l < LANES; l++) {
            if ((zero >> l & 1u) == 0) {
                if (hit >> l & 1u) pk->live[l] = 0;
                continue;
            }
            const float dl[3] = { pk->d[0][l], pk->d[1][l], pk->d[2][l] };   /* an edge exactly 0: in double */
            pk->live[l] = !ms_wt_segment(pk->o, dl, tri, N, pk->tmin, pk->tmax);
        }
        return;
    }
    const int kx = pk->kx, ky = pk->ky, kz = pk->kz;
    float A[3], B[3], C[3];
    for (int a = 0; a < 3; a++) { A[a] = tri[a] - pk->o[a]; B[a] = tri[3 + a] - pk->o[a]; C[a] = tri[6 + a] - pk->o[a]; }
    const float Ax = A[kx], Ay = A[ky], Az = A[kz], Bx = B[kx], By = B[ky], Bz = B[kz];
    const float Cx = C[kx], Cy = C[ky], Cz = C[kz];
    const float num = ms_wt_offset(pk->o, tri, N);
    const float tmin = pk->tmin, tmax = pk->tmax;
    int zero = 0;
    for (int l = 0; l < LANES; l++) {
        const float sx = pk->sx[l], sy = pk->sy[l];
        const float ax = Ax - sx * Az, ay = Ay - sy * Az, bx = Bx - sx * Bz, by = By - sy * Bz;
        const float cx = Cx - sx * Cz, cy = Cy - sy * Cz;
        const float u = ms_wt_edge(cx, cy, bx, by), v = ms_wt_edge(ax, ay, cx, cy), w = ms_wt_edge(bx, by, ax, ay);
        const int z = (u == 0.0f) | (v == 0.0f) | (w == 0.0f);
        const int mixed = ((u < 0.0f) | (v < 0.0f) | (w < 0.0f)) & ((u > 0.0f) | (v > 0.0f) | (w > 0.0f));
        const float det = u + v + w;
        const float den = pk->d[0][l] * N[0] + pk->d[1][l] * N[1] + pk->d[2][l] * N[2];
        const float ns = den < 0.0f ? -num : num, aden = fabsf(den);
        const int hit = !z & !mixed & (det != 0.0f) & (aden > 0.0f) & (ns >= tmin * aden) & (ns <= tmax * aden);
        zero |= z & pk->live[l];
        pk->live[l] &= !hit;
    }
    if (zero)   /* the lanes with an edge function exactly 0, redone by the scalar test (in double) */
        for (int l = 0; l < LANES; l++) {
            const float sx = pk->sx[l], sy = pk->sy[l];
            const float ax = Ax - sx * Az, ay = Ay - sy * Az, bx = Bx - sx * Bz, by = By - sy * Bz;
            const float cx = Cx - sx * Cz, cy = Cy - sy * Cz;
            if (!pk->live[l] || (ms_wt_edge(cx, cy, bx, by) != 0.0f && ms_wt_edge(ax, ay, cx, cy) != 0.0f &&
                                 ms_wt_edge(bx, by, ax, ay) != 0.0f))
                continue;
            const float d[3] = { pk->d[0][l], pk->d[1][l], pk->d[2][l] };
            if (ms_wt_segment_sheared(A, B, C, kz, sx, sy, d, N, num, tmin, tmax)) pk->live[l] = 0;
        }
}

/* Any hit: an alpha-tested triangle (al non-NULL and flagged) first takes the lanes it meets geometrically, as
 * any triangle does; the lanes where it is transparent at the sample's segment (alpha.h: the one decision every
 * method shares) are then given back, and traversal goes on for them. pts: the packet's 16 sample points. */
static void trace_packet(const ms_bvh *b, packet *pk, uint32_t skip, const ms_alpha *al, const float *pts, uint64_t *cnt)
{
    uint32_t stack[MS_BVH_STACK];
    int sp = 0;
    stack[sp++] = 0;
    cnt[C_PACKETS]++;
    ms_wt_box_origins(b->nodes[0].bmin, b->nodes[0].bmax, pk->o, pk->o_lo, pk->o_hi);
    while (sp) {
        const ms_bvh_node *n = &b->nodes[stack[--sp]];
        cnt[C_NODE_VISITS]++;
        if (!packet_enters(pk, n)) continue;
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                if (i == skip) continue;
                cnt[C_TRI_TESTS]++;
                if (al && al->flag[i]) {
                    int before[LANES];
                    memcpy(before, pk->live, sizeof before);
                    packet_triangle(pk, b->tri + 9 * (size_t)i, b->tri_n + 3 * (size_t)i);
                    for (int l = 0; l < LANES; l++)
                        if (before[l] && !pk->live[l] && !ms_alpha_segment_occludes(al, i, pk->o, pts + 3 * l)) pk->live[l] = 1;
                    continue;
                }
                packet_triangle(pk, b->tri + 9 * (size_t)i, b->tri_n + 3 * (size_t)i);
            }
            if (!any_live(pk->live)) return;
        } else {
            stack[sp++] = n->first + 1;
            stack[sp++] = n->first;
        }
    }
}

int MS_CAT(ms_raytrace_samples_, MS_ISA_SUFFIX)(const ms_render_ctx *ctx, const ms_shadow_query *q, float *pts,
                                                const uint64_t *front, uint64_t *vis, uint64_t *cnt)
{
    const int ns = ctx->samples;
    ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q->px, q->py, ctx->seed, pts);
    memset(vis, 0, (size_t)ctx->mask_words * sizeof *vis);
    int visible = 0;
    const int pref = ms_light_shear_axis(&ctx->light);
    for (int base = 0; base < ns; base += LANES) {
        /* Samples behind the receiver's plane are not traced (LANES divides 64: one word holds them). */
        const uint64_t lanes = front[base >> 6] >> (base & 63) & ((UINT64_C(1) << LANES) - 1);
        if (!lanes) continue;
        packet pk;
        for (int a = 0; a < 3; a++) pk.o[a] = q->p[a];
        pk.tmin = ctx->near;
        pk.tmax = ctx->far;
        pk.pref = pref;
        for (int l = 0; l < LANES; l++) {
            for (int a = 0; a < 3; a++) {
                pk.d[a][l] = pts[3 * (base + l) + a] - pk.o[a];
                pk.inv[a][l] = 1.0f / pk.d[a][l];
            }
            pk.live[l] = (int)(lanes >> l & 1u);
        }
        packet_shear(&pk);
        trace_packet(ctx->bvh, &pk, q->prim, ctx->alpha, pts + 3 * base, cnt);
        uint64_t bits = 0;
        for (int l = 0; l < LANES; l++) bits |= (uint64_t)(pk.live[l] != 0) << l;
        vis[base >> 6] |= bits << (base & 63);
        visible += __builtin_popcountll(bits);
    }
    return visible;
}

