/* The per-ISA part of the hierarchical penumbra casting engine (hpc_engine.h has the method and its departures
 * from the paper; docs/hpc.md, "Files", the map of its files).
 *
 * One source per ISA (CONTRIBUTING.md, "An ISA kernel"): this file, with the *_impl.h files it includes, is
 * compiled as hpc_scalar.c, hpc_avx2.c and hpc_avx512.c, each defining ms_hpc_cast_<isa>; hpc.c picks one under
 * the context's cap. What the ISA changes is the 16-lane code of lanes16.h (IEEE operations per lane, no FMA), so
 * every instance gives the same masks and counters (test_hpc checks it):
 *  - the hard-shadow test (L70) runs over 16 samples of a group at once (group_block16): a group of 4 x 4
 *    samples (k = 16, 32) is one call, one of 8 x 8 (k = 64) four calls of 2 rows. Each lane forms its
 *    sample, its direction and its shear exactly as the scalar form (and raytrace) does: the per-lane
 *    shear axis of its 16-sample packet (selected per lane; lanes whose packet has none are tested one by
 *    one, as raytrace does), sx = d[kx] * (1 / d[kz]), the same edge functions, the same double fall-back
 *    on a zero edge, the same plane-distance range. The paper tests the four planes of V_li with SSE,
 *    one sample at a time; here the SIMD width goes to the samples instead;
 *  - the box- and point-in-volume tests (INTERSECTS, POINT-IN-VOLUME) evaluate all the planes of a volume
 *    in one 16-lane operation (hpc_volume.h keeps them by component) and then keep the active ones: the
 *    scalar form's arithmetic per plane, without its early exit (the counter counts every active plane).
 * Measuring switches (ms_hpc_switches, hpc.h) turn off each optimisation of sec. 3.3 and each SIMD form. */

#include "hpc_engine.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "accel/ray_triangle.h"
#include "light/pattern.h"
#include "light/light_frame.h"
#include "core/vec.h"
#include "raster/raster.h"
#include "core/perk.h"
#include "visibility/lanes16.h"
#include "visibility/wt_rays16.h"
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "hpc_footprint_impl.h"
#include "hpc_slots_impl.h"
#include "hpc_exact_impl.h"
#include "hpc_blocks_impl.h"
#include "hpc_leaf_bound_impl.h"
#include "hpc_leaf_lanes_impl.h"
#include "hpc_leaf_impl.h"
#include "hpc_traverse_impl.h"

static void setup_light(shared *sh)
{
    const ms_light *L = &sh->ctx->light;
    sh->shear_axis = ms_light_shear_axis(L);
    const double P[3] = { L->corner.x, L->corner.y, L->corner.z };
    const double S[3] = { L->edge_s.x, L->edge_s.y, L->edge_s.z }, T[3] = { L->edge_t.x, L->edge_t.y, L->edge_t.z };
    const int k = sh->k, gpr = k / sh->gs;
    /* Widened by 1e-3 of a cell and by 16 ulps of the frame's coordinates (sh->scale, set by the caller):
     * the float samples round off their cells by ulps of their coordinates, which the polygons absorb so
     * that the culling margin need not magnify them. */
    const double ls = fmin(sqrt(S[0] * S[0] + S[1] * S[1] + S[2] * S[2]), sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2]));
    const double w = 1e-3 / k + (ls > 0.0 ? 16.0 * 1.1920929e-07 * sh->scale / ls : 0.0);
    const double corners[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
    for (int v = 0; v < 4; v++) {
        const double s = corners[v][0] * (1 + 2 * w) - w, t = corners[v][1] * (1 + 2 * w) - w;
        for (int a = 0; a < 3; a++) sh->light_poly[3 * v + a] = P[a] + s * S[a] + t * T[a];
    }
    for (int g = 0; g < sh->G; g++) {
        const double s0 = (double)(g % gpr * sh->gs) / k, t0 = (double)(g / gpr * sh->gs) / k, e = (double)sh->gs / k;
        for (int v = 0; v < 4; v++) {
            const double s = s0 - w + corners[v][0] * (e + 2 * w), t = t0 - w + corners[v][1] * (e + 2 * w);
            for (int a = 0; a < 3; a++) sh->group_poly[g][3 * v + a] = P[a] + s * S[a] + t * T[a];
        }
    }
    for (int a = 0; a < 3; a++) {
        sh->light_lo[a] = INFINITY;
        sh->light_hi[a] = -INFINITY;
        for (int v = 0; v < 4; v++) {
            sh->light_lo[a] = ms_minf(sh->light_lo[a], (float)sh->light_poly[3 * v + a]);
            sh->light_hi[a] = ms_maxf(sh->light_hi[a], (float)sh->light_poly[3 * v + a]);
        }
    }
}

int MS_CAT(ms_hpc_cast_, MS_ISA_SUFFIX)(const ms_render_ctx *ctx, int scanline, ms_raster_fn raster,
                                        const ms_shadow_query *q, size_t n, const uint64_t *front, uint64_t *vis,
                                        const hpc_source *src, uint64_t *counters)
{
    const int k = ctx->k, mw = ctx->mask_words;
    shared sh;
    memset(&sh, 0, sizeof sh);
    sh.ctx = ctx;
    sh.sw = ms_hpc_switches;
    sh.scanline = scanline;
    sh.raster = raster;
    sh.k = k;
    sh.mw = mw;
    sh.gs = k >= 64 ? 8 : 4;     /* 16, 64, 64 groups for k = 16, 32, 64 (a group-umbra word; 2x2 groups at
                                  * k = 16 tripled the box-plane tests and the time on a flowers scene) */
    sh.G = (k / sh.gs) * (k / sh.gs);
    for (int g = 0; g < sh.G; g++) {
        sh.group_i0[g] = (float)(g % (k / sh.gs) * sh.gs);
        sh.group_j0[g] = (float)(g / (k / sh.gs) * sh.gs);
    }
    for (int b = 0; b < 64; b++) { sh.bit_i[b] = (float)(b % k); sh.bit_j[b] = (float)(b / k); }
    sh.footprint = !scanline && !(sh.sw & MS_HPC_OFF_FOOTPRINT);
    sh.all_groups = sh.G == 64 ? UINT64_MAX : (UINT64_C(1) << sh.G) - 1u;
    sh.npk = k * k / LANES;
    sh.n = n;
    sh.q = q;
    sh.front = front;
    sh.frame_off = (size_t)mw * sizeof(uint64_t);
    sh.kz_off = sh.frame_off + (scanline ? sizeof(ms_raster_frame) : 0);
    sh.slot_bytes = (sh.kz_off + (size_t)sh.npk + 1 + 63) / 64 * 64;   /* + 1: the shared axis (slot_setup) */
    {
        ms_light_frame F;
        ms_light_frame_of(&ctx->light, &F);
        for (int a = 0; a < 3; a++) {   /* the light's four corners */
            const float c[4] = { F.corner[a], F.corner[a] + F.edge_s[a], F.corner[a] + F.edge_t[a],
                                 F.corner[a] + F.edge_s[a] + F.edge_t[a] };
            for (int v = 0; v < 4; v++) sh.scale = ms_maxf(sh.scale, 2.0f * fabsf(c[v]));
        }
    }
    const int threads = ctx->threads > 0 ? ctx->threads : 1;
    /* the receivers' box, and their largest coordinate in sh.scale (in parallel: the serial parts of a frame
     * count in its wall time; max and min are exact, so the order does not matter) */
    float lo0 = INFINITY, lo1 = INFINITY, lo2 = INFINITY, hi0 = -INFINITY, hi1 = -INFINITY, hi2 = -INFINITY, pmax = 0.0f;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(min : lo0, lo1, lo2) reduction(max : hi0, hi1, hi2, pmax)
    for (size_t i = 0; i < n; i++) {
        const float *p = q[i].p;
        lo0 = ms_minf(lo0, p[0]); lo1 = ms_minf(lo1, p[1]); lo2 = ms_minf(lo2, p[2]);
        hi0 = ms_maxf(hi0, p[0]); hi1 = ms_maxf(hi1, p[1]); hi2 = ms_maxf(hi2, p[2]);
        pmax = ms_maxf(pmax, ms_maxf(fabsf(p[0]), ms_maxf(fabsf(p[1]), fabsf(p[2]))));
    }
    sh.scale = ms_maxf(sh.scale, pmax);
    setup_light(&sh);
    const float rlo[3] = { lo0, lo1, lo2 }, rhi[3] = { hi0, hi1, hi2 };
    float reach2 = 0.0f;
    for (int a = 0; a < 3 && n; a++) {
        const float e = ms_maxf(fabsf(rhi[a] - sh.light_lo[a]), fabsf(sh.light_hi[a] - rlo[a]));
        reach2 += e * e;
    }
    sh.reach = sqrtf(reach2);

    int rc = -1, nchunks = 0;
    const int cap = 16 * threads;   /* chunks: see hpc_make_chunks */
    sh.gmask = calloc((size_t)sh.G * mw, sizeof *sh.gmask);
    sh.gumbra = malloc(n * sizeof *sh.gumbra);
    sh.full = malloc(n);
    sh.slot = malloc(n * sizeof *sh.slot);
    uint64_t *const gumbra0 = sh.gumbra, *gumbra2 = NULL;   /* by the caller's numbers, by hierarchy order */
    uint8_t *const full0 = sh.full, *full2 = NULL;
    int32_t *const slot0 = sh.slot, *slot2 = NULL;
    uint32_t *orig = NULL, nlive = 0;
    ms_shadow_query *q2 = NULL;
    uint32_t *idx = malloc(n * sizeof *idx);
    chunk *ch = calloc((size_t)cap, sizeof *ch);
    tri_job *jobs = malloc(BATCH * sizeof *jobs);
    float *tri = malloc(BATCH * 9 * sizeof *tri);
    uint32_t *ids = malloc(BATCH * sizeof *ids);
    int8_t *pairs = malloc(BATCH);
    if (!sh.gmask || !sh.gumbra || !sh.full || !sh.slot || !idx || !ch || !jobs || !tri || !ids || !pairs) goto done;
    for (int g = 0; g < sh.G; g++) {
        const int gpr = k / sh.gs, i0 = g % gpr * sh.gs, j0 = g / gpr * sh.gs;
        for (int j = j0; j < j0 + sh.gs; j++)
            for (int i = i0; i < i0 + sh.gs; i++) {
                const int s = j * k + i;
                sh.gmask[(size_t)g * mw + (s >> 6)] |= UINT64_C(1) << (s & 63);
            }
        sh.gw0[g] = (j0 * k + i0) >> 6;
        sh.gw1[g] = ((j0 + sh.gs - 1) * k + i0 + sh.gs - 1) >> 6;
    }
    /* Samples behind the horizon count as blocked from the start (umbra bits: nothing open). In parallel, the
     * live receivers gathered after (the serial parts of a frame count in its wall time). */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t r = 0; r < n; r++) {
        uint64_t gu = 0;
        const uint64_t *f = front + r * mw;
        for (int g = 0; g < sh.G; g++) {
            int open = 0;
            for (int w = sh.gw0[g]; w <= sh.gw1[g]; w++) open |= (f[w] & sh.gmask[(size_t)g * mw + w]) != 0;
            if (!open) gu |= UINT64_C(1) << g;
        }
        sh.gumbra[r] = gu;
        sh.full[r] = gu == sh.all_groups;
        sh.slot[r] = -1;
    }
    for (size_t r = 0; r < n; r++)
        if (!sh.full[r]) idx[nlive++] = (uint32_t)r;
    const uint32_t target = (uint32_t)((nlive + cap - 1) / cap) > 1024u ? (uint32_t)((nlive + cap - 1) / cap) : 1024u;
    nchunks = nlive ? hpc_make_chunks(&sh, idx, nlive, target, ch, cap, threads) : 0;
    if (nchunks < 0) goto done;
    int failed = 0;
    double t0 = omp_get_wtime();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(| : failed)
    for (int i = 0; i < nchunks; i++) failed |= hpc_build_tree(&sh, &ch[i]) != 0;
    counters[C_BUILD_US] += (uint64_t)((omp_get_wtime() - t0) * 1e6);
    if (failed) goto done;
    /* Renumbering in hierarchy order: the chunks' receivers one after another, each chunk's in its leaves'
     * order, with their queries, umbra bits, flags and slots, so that a leaf reads its points' data from a few
     * cache lines (the caller's order scatters them: the per-pair loads of umbra bits and masks took a
     * fifth of a cast on a GRIDS-like scene); the front masks stay the caller's (read once per receiver). */
    orig = malloc((nlive ? nlive : 1) * sizeof *orig);
    q2 = malloc((nlive ? nlive : 1) * sizeof *q2);
    gumbra2 = malloc((nlive ? nlive : 1) * sizeof *gumbra2);
    full2 = malloc(nlive ? nlive : 1);
    slot2 = malloc((nlive ? nlive : 1) * sizeof *slot2);
    if (!orig || !q2 || !gumbra2 || !full2 || !slot2) goto done;
    {
        uint32_t pos = 0;
        for (int i = 0; i < nchunks; i++) {
            ch[i].base = pos;
            ch[i].n0 = ch[i].n;
            pos += ch[i].n;
        }
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int i = 0; i < nchunks; i++)
        for (uint32_t j = 0, pos = ch[i].base; j < ch[i].n; j++, pos++) {
            const uint32_t o = ch[i].idx[j];
            orig[pos] = o;
            q2[pos] = q[o];
            gumbra2[pos] = sh.gumbra[o];
            full2[pos] = sh.full[o];
            slot2[pos] = -1;
            ch[i].idx[j] = pos;
        }
    sh.orig = orig;
    sh.q = q2;
    sh.gumbra = gumbra2;
    sh.full = full2;
    sh.slot = slot2;
    if (sh.footprint && nlive) {
        /* Each receiver's grid origin, formed once: the footprint test needs its grid for every triangle whose
         * V_L holds it. The steps are the light's (the same for every pixel, pattern.c); checked bit for bit,
         * and the grids formed per pair if they ever differ. */
        ms_grid g0;
        ms_grid_for_pixel(&ctx->light, k, sh.q[0].px, sh.q[0].py, ctx->seed, &g0);
        memcpy(sh.grid_ds, g0.ds, sizeof sh.grid_ds);
        memcpy(sh.grid_dt, g0.dt, sizeof sh.grid_dt);
        sh.p0 = malloc((size_t)nlive * 4 * sizeof *sh.p0);
        int same = sh.p0 != NULL;
        const size_t n_origins = sh.p0 ? nlive : 0;   /* the bound apart from the reduction's variable (TSan) */
#pragma omp parallel for schedule(static) num_threads(threads) reduction(& : same)
        for (size_t r = 0; r < n_origins; r++) {
            ms_grid g;
            ms_grid_for_pixel(&ctx->light, k, sh.q[r].px, sh.q[r].py, ctx->seed, &g);
            memcpy(sh.p0 + 4 * r, g.p0, sizeof g.p0);
            sh.p0[4 * r + 3] = hpc_footprint_rel(&g, sh.q[r].p, k);
            same &= !memcmp(g.ds, sh.grid_ds, sizeof g.ds) && !memcmp(g.dt, sh.grid_dt, sizeof g.dt);
        }
        if (!same) { free(sh.p0); sh.p0 = NULL; }
        else counters[C_SAMPLE_BYTES] += (uint64_t)nlive * 4u * sizeof *sh.p0;
        sh.pairs = sh.p0 && !(sh.sw & MS_HPC_OFF_PAIRS);
    }
    if (sh.sw & MS_HPC_OFF_ON_DEMAND) {   /* D off: every receiver's mask and sample data before any triangle */
        for (int i = 0; i < nchunks; i++)
            for (uint32_t j = 0; j < ch[i].n; j++) {
                const uint32_t r = ch[i].idx[j];
                const int32_t s = hpc_slot_get(&sh, &ch[i]);
                if (s < 0) goto done;
                ms_grid g;
                ms_grid_for_pixel(&ctx->light, k, sh.q[r].px, sh.q[r].py, ctx->seed, &g);
                sh.slot[r] = s;
                memcpy(slot_mask(&sh, &ch[i], s), front + (size_t)orig[r] * mw, (size_t)mw * sizeof(uint64_t));
                slot_setup(&sh, &ch[i], s, &sh.q[r], &g);
            }
    }
    t0 = omp_get_wtime();

    if (src->rewind && src->rewind(src->user)) goto done;
    for (;;) {
        const size_t got = src->next(src->user, tri, ids, BATCH);
        if (got == (size_t)-1) goto done;
        if (!got) break;
        if (sh.pairs) hpc_pair_batch(tri, ids, pairs, got);
        hpc_prepare_batch(&sh, jobs, tri, ids, sh.pairs ? pairs : NULL, got);
        counters[C_TRIANGLES] += got;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
        for (int i = 0; i < nchunks; i++)
            for (size_t t = 0; t < got; t++)
                if (jobs[t].pair >= 0) cast_triangle(&sh, &ch[i], &jobs[t]);
        for (int i = 0; i < nchunks; i++)
            if (ch[i].failed) goto done;
    }
    counters[C_CAST_US] += (uint64_t)((omp_get_wtime() - t0) * 1e6);
    /* The visible masks: front where no triangle came near, nothing in full umbra, else what is open. */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t r = 0; r < n; r++) {
        uint64_t *v = vis + r * mw;
        if (full0[r]) memset(v, 0, (size_t)mw * sizeof *v);
        else memcpy(v, front + r * mw, (size_t)mw * sizeof *v);
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int i = 0; i < nchunks; i++) {
        chunk *c = &ch[i];
        for (uint32_t r = c->base; r < c->base + c->n0; r++) {
            uint64_t *v = vis + (size_t)orig[r] * mw;
            if (sh.full[r]) memset(v, 0, (size_t)mw * sizeof *v);
            else if (sh.slot[r] >= 0) memcpy(v, slot_mask(&sh, c, sh.slot[r]), (size_t)mw * sizeof *v);
        }
    }
    rc = 0;
done:
    for (int i = 0; i < (nchunks > 0 ? nchunks : 0); i++) {
        for (int c = 0; c < C_COUNT; c++)
            if (c != C_TRIANGLES && c != C_MASKS_PEAK) counters[c] += ch[i].cnt[c];
        counters[C_MASKS_PEAK] += (uint64_t)ch[i].peak;
        /* The pool as allocated (it only grows): each slot's mask, and its per-point sample data (the
         * packets' shear axes, the Scanline frame). */
        counters[C_MASK_BYTES] += (uint64_t)ch[i].cap_slots * (uint64_t)mw * 8u;
        counters[C_SAMPLE_BYTES] += (uint64_t)ch[i].cap_slots * (uint64_t)(sh.slot_bytes - (size_t)mw * 8u);
        counters[C_HIERARCHY_BYTES] += ch[i].node_bytes_peak;
        free(ch[i].nodes);
        free(ch[i].pool);
        free(ch[i].free_list);
    }
    /* The hierarchy's per-point arrays: indices, umbra bits, full flags, slot numbers; the groups' masks. */
    counters[C_HIERARCHY_BYTES] += (uint64_t)n * (sizeof *idx + sizeof *sh.gumbra + 1u + sizeof *sh.slot) +
                                   (uint64_t)nlive * (sizeof *orig + sizeof *q2 + sizeof *gumbra2 + 1u + sizeof *slot2);
    counters[C_SAMPLE_BYTES] += (uint64_t)sh.G * (uint64_t)mw * 8u;
    free(ch);
    free(idx);
    free(jobs);
    free(tri);
    free(ids);
    free(pairs);
    free(sh.gmask);
    free(gumbra0);
    free(full0);
    free(slot0);
    free(orig);
    free(q2);
    free(gumbra2);
    free(full2);
    free(slot2);
    free(sh.p0);
    return rc;
}
