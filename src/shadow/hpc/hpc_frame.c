/* The frame of a cast (ms_hpc_cast_<isa>, hpc_impl.h): the shared state, the light's polygons, the groups'
 * masks, the receivers' horizon, their chunks, hierarchies and renumbering, their grid origins; then the
 * visible masks and the counters. Compiled once (hpc_engine.h). */
#include "hpc_engine.h"
#include "light/light_frame.h"
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

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

/* The shared state's constants (the groups, the slots' layout, the frame's scale), the light's polygons and the
 * receivers' reach. */
static void frame_shared(hpc_frame *F, const ms_render_ctx *ctx, int scanline, ms_raster_fn raster,
                         const ms_shadow_query *q, size_t n, const uint64_t *front)
{
    shared *sh = &F->sh;
    const int k = ctx->k, mw = ctx->mask_words;
    sh->ctx = ctx;
#ifdef MS_TEST_HOOKS
    sh->sw = ms_hpc_switches;
#endif
    sh->scanline = scanline;
    sh->raster = raster;
    sh->k = k;
    sh->mw = mw;
    sh->gs = k >= 64 ? 8 : 4;     /* 16, 64, 64 groups for k = 16, 32, 64 (a group-umbra word; 2x2 groups at
                                   * k = 16 tripled the box-plane tests and the time on a flowers scene) */
    sh->G = (k / sh->gs) * (k / sh->gs);
    for (int g = 0; g < sh->G; g++) {
        sh->group_i0[g] = (float)(g % (k / sh->gs) * sh->gs);
        sh->group_j0[g] = (float)(g / (k / sh->gs) * sh->gs);
    }
    for (int b = 0; b < 64; b++) { sh->bit_i[b] = (float)(b % k); sh->bit_j[b] = (float)(b / k); }
    sh->footprint = !scanline && !hpc_sw(sh, MS_HPC_OFF_FOOTPRINT);
    sh->all_groups = sh->G == 64 ? UINT64_MAX : (UINT64_C(1) << sh->G) - 1u;
    sh->npk = k * k / LANES;
    sh->n = n;
    sh->q = q;
    sh->front = front;
    sh->frame_off = (size_t)mw * sizeof(uint64_t);
    sh->kz_off = sh->frame_off + (scanline ? sizeof(ms_raster_frame) : 0);
    sh->slot_bytes = (sh->kz_off + (size_t)sh->npk + 1 + 63) / 64 * 64;   /* + 1: the shared axis (slot_setup) */
    {
        ms_light_frame LF;
        ms_light_frame_of(&ctx->light, &LF);
        for (int a = 0; a < 3; a++) {   /* the light's four corners */
            const float c[4] = { LF.corner[a], LF.corner[a] + LF.edge_s[a], LF.corner[a] + LF.edge_t[a],
                                 LF.corner[a] + LF.edge_s[a] + LF.edge_t[a] };
            for (int v = 0; v < 4; v++) sh->scale = ms_maxf(sh->scale, 2.0f * fabsf(c[v]));
        }
    }
    const int threads = F->threads = ctx->threads > 0 ? ctx->threads : 1;
    /* the receivers' box, and their largest coordinate in sh->scale (in parallel: the serial parts of a frame
     * count in its wall time; max and min are exact, so the order does not matter) */
    float lo0 = INFINITY, lo1 = INFINITY, lo2 = INFINITY, hi0 = -INFINITY, hi1 = -INFINITY, hi2 = -INFINITY, pmax = 0.0f;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(min : lo0, lo1, lo2) reduction(max : hi0, hi1, hi2, pmax)
    for (size_t i = 0; i < n; i++) {
        const float *p = q[i].p;
        lo0 = ms_minf(lo0, p[0]); lo1 = ms_minf(lo1, p[1]); lo2 = ms_minf(lo2, p[2]);
        hi0 = ms_maxf(hi0, p[0]); hi1 = ms_maxf(hi1, p[1]); hi2 = ms_maxf(hi2, p[2]);
        pmax = ms_maxf(pmax, ms_maxf(fabsf(p[0]), ms_maxf(fabsf(p[1]), fabsf(p[2]))));
    }
    sh->scale = ms_maxf(sh->scale, pmax);
    setup_light(sh);
    const float rlo[3] = { lo0, lo1, lo2 }, rhi[3] = { hi0, hi1, hi2 };
    float reach2 = 0.0f;
    for (int a = 0; a < 3 && n; a++) {
        const float e = ms_maxf(fabsf(rhi[a] - sh->light_lo[a]), fabsf(sh->light_hi[a] - rlo[a]));
        reach2 += e * e;
    }
    sh->reach = sqrtf(reach2);
}

/* The per-receiver arrays, the chunks and a batch's buffers. 0, or -1 out of memory. */
static int frame_alloc(hpc_frame *F)
{
    shared *sh = &F->sh;
    const size_t n = sh->n;
    /* chunks (see hpc_make_chunks): never more than the receivers, each chunk holding one at least; a cast of
     * one point (a sphere's or sun's query) needs one, not 16 per thread (each with its volumes) */
    F->cap = n < (size_t)16 * F->threads ? (n ? (int)n : 1) : 16 * F->threads;
    sh->gmask = calloc((size_t)sh->G * sh->mw, sizeof *sh->gmask);
    sh->gumbra = F->gumbra0 = malloc(n * sizeof *sh->gumbra);
    sh->full = F->full0 = malloc(n);
    sh->slot = F->slot0 = malloc(n * sizeof *sh->slot);
    F->idx = malloc(n * sizeof *F->idx);
    F->ch = calloc((size_t)F->cap, sizeof *F->ch);
    F->jobs = malloc(F->batch * sizeof *F->jobs);
    F->tri = malloc(F->batch * 9 * sizeof *F->tri);
    F->ids = malloc(F->batch * sizeof *F->ids);
    F->pairs = malloc(F->batch);
    return sh->gmask && sh->gumbra && sh->full && sh->slot && F->idx && F->ch && F->jobs && F->tri && F->ids &&
                   F->pairs
               ? 0
               : -1;
}

/* The groups' masks; each receiver's umbra bits from its front mask, and the live receivers (not in full umbra)
 * in F->idx. */
static void frame_groups(hpc_frame *F)
{
    shared *sh = &F->sh;
    const int k = sh->k, mw = sh->mw, threads = F->threads;
    const size_t n = sh->n;
    const uint64_t *front = sh->front;
    for (int g = 0; g < sh->G; g++) {
        const int gpr = k / sh->gs, i0 = g % gpr * sh->gs, j0 = g / gpr * sh->gs;
        for (int j = j0; j < j0 + sh->gs; j++)
            for (int i = i0; i < i0 + sh->gs; i++) {
                const int s = j * k + i;
                sh->gmask[(size_t)g * mw + (s >> 6)] |= UINT64_C(1) << (s & 63);
            }
        sh->gw0[g] = (j0 * k + i0) >> 6;
        sh->gw1[g] = ((j0 + sh->gs - 1) * k + i0 + sh->gs - 1) >> 6;
    }
    /* Samples behind the horizon count as blocked from the start (umbra bits: nothing open). In parallel, the
     * live receivers gathered after (the serial parts of a frame count in its wall time). */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t r = 0; r < n; r++) {
        uint64_t gu = 0;
        const uint64_t *f = front + r * mw;
        for (int g = 0; g < sh->G; g++) {
            int open = 0;
            for (int w = sh->gw0[g]; w <= sh->gw1[g]; w++) open |= (f[w] & sh->gmask[(size_t)g * mw + w]) != 0;
            if (!open) gu |= UINT64_C(1) << g;
        }
        sh->gumbra[r] = gu;
        sh->full[r] = gu == sh->all_groups;
        sh->slot[r] = -1;
    }
    for (size_t r = 0; r < n; r++)
        if (!sh->full[r]) F->idx[F->nlive++] = (uint32_t)r;
}

/* The live receivers split into chunks, and each chunk's hierarchy (in parallel). 0, or -1 out of memory. */
static int frame_chunks(hpc_frame *F, uint64_t *counters)
{
    const shared *sh = &F->sh;
    const uint32_t nlive = F->nlive, cap = (uint32_t)F->cap;
    const int threads = F->threads;
    const uint32_t target = (uint32_t)((nlive + cap - 1) / cap) > 1024u ? (uint32_t)((nlive + cap - 1) / cap) : 1024u;
    F->nchunks = nlive ? hpc_make_chunks(sh, F->idx, nlive, target, F->ch, F->cap, threads) : 0;
    if (F->nchunks < 0) return -1;
    const int nchunks = F->nchunks;
    chunk *ch = F->ch;
    int failed = 0;
    const double t0 = omp_get_wtime();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(| : failed)
    for (int i = 0; i < nchunks; i++) failed |= hpc_build_tree(sh, &ch[i]) != 0;
    counters[C_BUILD_US] += (uint64_t)((omp_get_wtime() - t0) * 1e6);
    return failed ? -1 : 0;
}

/* Renumbering in hierarchy order: the chunks' receivers one after another, each chunk's in its leaves' order,
 * with their queries, umbra bits, flags and slots, so that a leaf reads its points' data from a few cache lines
 * (the caller's order scatters them: the per-pair loads of umbra bits and masks took a fifth of a cast on a
 * GRIDS-like scene); the front masks stay the caller's (read once per receiver). 0, or -1 out of memory. */
static int frame_renumber(hpc_frame *F)
{
    shared *sh = &F->sh;
    const uint32_t nlive = F->nlive;
    const int nchunks = F->nchunks, threads = F->threads;
    chunk *ch = F->ch;
    const ms_shadow_query *q = sh->q;
    uint32_t *orig = F->orig = malloc((nlive ? nlive : 1) * sizeof *orig);
    ms_shadow_query *q2 = F->q2 = malloc((nlive ? nlive : 1) * sizeof *q2);
    uint64_t *gumbra2 = F->gumbra2 = malloc((nlive ? nlive : 1) * sizeof *gumbra2);
    uint8_t *full2 = F->full2 = malloc(nlive ? nlive : 1);
    int32_t *slot2 = F->slot2 = malloc((nlive ? nlive : 1) * sizeof *slot2);
    if (!orig || !q2 || !gumbra2 || !full2 || !slot2) return -1;
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
            gumbra2[pos] = sh->gumbra[o];
            full2[pos] = sh->full[o];
            slot2[pos] = -1;
            ch[i].idx[j] = pos;
        }
    sh->orig = orig;
    sh->q = q2;
    sh->gumbra = gumbra2;
    sh->full = full2;
    sh->slot = slot2;
    return 0;
}

/* Each receiver's grid origin, formed once: the footprint test needs its grid for every triangle whose V_L
 * holds it. The steps are the light's (the same for every pixel, pattern.c); checked bit for bit, and the grids
 * formed per pair if they ever differ. */
static void frame_origins(hpc_frame *F, uint64_t *counters)
{
    shared *sh = &F->sh;
    const ms_render_ctx *ctx = sh->ctx;
    const uint32_t nlive = F->nlive;
    const int k = sh->k, threads = F->threads;
    if (!(sh->footprint && nlive)) return;
    ms_grid g0;
    ms_grid_for_pixel(&ctx->light, k, sh->q[0].px, sh->q[0].py, ctx->seed, &g0);
    memcpy(sh->grid_ds, g0.ds, sizeof sh->grid_ds);
    memcpy(sh->grid_dt, g0.dt, sizeof sh->grid_dt);
    sh->p0 = malloc((size_t)nlive * 4 * sizeof *sh->p0);
    int same = sh->p0 != NULL;
    const size_t n_origins = sh->p0 ? nlive : 0;   /* the bound apart from the reduction's variable (TSan) */
#pragma omp parallel for schedule(static) num_threads(threads) reduction(& : same)
    for (size_t r = 0; r < n_origins; r++) {
        ms_grid g;
        ms_grid_for_pixel(&ctx->light, k, sh->q[r].px, sh->q[r].py, ctx->seed, &g);
        memcpy(sh->p0 + 4 * r, g.p0, sizeof g.p0);
        sh->p0[4 * r + 3] = hpc_footprint_rel(&g, sh->q[r].p, k);
        same &= !memcmp(g.ds, sh->grid_ds, sizeof g.ds) && !memcmp(g.dt, sh->grid_dt, sizeof g.dt);
    }
    if (!same) { free(sh->p0); sh->p0 = NULL; }
    else counters[C_SAMPLE_BYTES] += (uint64_t)nlive * 4u * sizeof *sh->p0;
    sh->pairs = sh->p0 && !hpc_sw(sh, MS_HPC_OFF_PAIRS);
}

int hpc_frame_begin(hpc_frame *F, const ms_render_ctx *ctx, int scanline, ms_raster_fn raster,
                    const ms_shadow_query *q, size_t n, const uint64_t *front, size_t batch, uint64_t *counters)
{
    memset(F, 0, sizeof *F);
    F->batch = batch;
    frame_shared(F, ctx, scanline, raster, q, n, front);
    if (frame_alloc(F)) return -1;
    frame_groups(F);
    if (frame_chunks(F, counters) || frame_renumber(F)) return -1;
    frame_origins(F, counters);
    return 0;
}

/* The visible masks: front where no triangle came near, nothing in full umbra, else what is open. */
void hpc_frame_vis(const hpc_frame *F, uint64_t *vis)
{
    const shared *sh = &F->sh;
    const size_t n = sh->n;
    const int mw = sh->mw, threads = F->threads, nchunks = F->nchunks;
    const uint64_t *front = sh->front;
    const uint8_t *full0 = F->full0;
    const uint32_t *orig = F->orig;
    const chunk *ch = F->ch;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t r = 0; r < n; r++) {
        uint64_t *v = vis + r * mw;
        if (full0[r]) memset(v, 0, (size_t)mw * sizeof *v);
        else memcpy(v, front + r * mw, (size_t)mw * sizeof *v);
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int i = 0; i < nchunks; i++) {
        const chunk *c = &ch[i];
        for (uint32_t r = c->base; r < c->base + c->n0; r++) {
            uint64_t *v = vis + (size_t)orig[r] * mw;
            if (sh->full[r]) memset(v, 0, (size_t)mw * sizeof *v);
            else if (sh->slot[r] >= 0) memcpy(v, slot_mask(sh, c, sh->slot[r]), (size_t)mw * sizeof *v);
        }
    }
}

void hpc_frame_end(hpc_frame *F, uint64_t *counters)
{
    const shared *sh = &F->sh;
    const int mw = sh->mw;
    for (int i = 0; i < (F->nchunks > 0 ? F->nchunks : 0); i++) {
        const chunk *c = &F->ch[i];
        for (int x = 0; x < C_COUNT; x++)
            if (x != C_TRIANGLES && x != C_MASKS_PEAK) counters[x] += c->cnt[x];
        counters[C_MASKS_PEAK] += (uint64_t)c->peak;
        /* The pool as allocated (it only grows): each slot's mask, and its per-point sample data (the
         * packets' shear axes, the Scanline frame). */
        counters[C_MASK_BYTES] += (uint64_t)c->cap_slots * (uint64_t)mw * 8u;
        counters[C_SAMPLE_BYTES] += (uint64_t)c->cap_slots * (uint64_t)(sh->slot_bytes - (size_t)mw * 8u);
        counters[C_HIERARCHY_BYTES] += c->node_bytes_peak;
        free(c->nodes);
        free(c->pool);
        free(c->free_list);
    }
    /* The hierarchy's per-point arrays: indices, umbra bits, full flags, slot numbers; the groups' masks. */
    counters[C_HIERARCHY_BYTES] += (uint64_t)sh->n * (sizeof *F->idx + sizeof *sh->gumbra + 1u + sizeof *sh->slot) +
                                   (uint64_t)F->nlive * (sizeof *F->orig + sizeof *F->q2 + sizeof *F->gumbra2 + 1u +
                                                         sizeof *F->slot2);
    counters[C_SAMPLE_BYTES] += (uint64_t)sh->G * (uint64_t)mw * 8u;
    free(F->ch);
    free(F->idx);
    free(F->jobs);
    free(F->tri);
    free(F->ids);
    free(F->pairs);
    free(sh->gmask);
    free(F->gumbra0);
    free(F->full0);
    free(F->slot0);
    free(F->orig);
    free(F->q2);
    free(F->gumbra2);
    free(F->full2);
    free(F->slot2);
    free(sh->p0);
}
