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
 * Measuring switches (ms_hpc_switches, hpc.h; the tests' copy of the library only) turn off each optimisation of
 * sec. 3.3 and each SIMD form. */

#include "hpc_engine.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "accel/ray_triangle.h"
#include "light/pattern.h"
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

/* D off (a measuring switch): every receiver's mask and sample data before any triangle. 0, or -1 out of memory. */
static int preload_slots(hpc_frame *F)
{
    shared *sh = &F->sh;
    const ms_render_ctx *ctx = sh->ctx;
    for (int i = 0; i < F->nchunks; i++)
        for (uint32_t j = 0; j < F->ch[i].n; j++) {
            const uint32_t r = F->ch[i].idx[j];
            const int32_t s = hpc_slot_get(sh, &F->ch[i]);
            if (s < 0) return -1;
            ms_grid g;
            ms_grid_for_pixel(&ctx->light, sh->k, sh->q[r].px, sh->q[r].py, ctx->seed, &g);
            sh->slot[r] = s;
            memcpy(slot_mask(sh, &F->ch[i], s), sh->front + (size_t)sh->orig[r] * sh->mw, (size_t)sh->mw * sizeof(uint64_t));
            slot_setup(sh, &F->ch[i], s, &sh->q[r], &g);
        }
    return 0;
}

/* Every batch of the source's triangles read once, paired, made jobs (V_L, in parallel) and cast by every chunk,
 * chunks scheduled dynamically over the threads. 0, or -1 when the source fails or a chunk runs out of memory. */
static int cast_batches(hpc_frame *F, const hpc_source *src, uint64_t *counters)
{
    const shared *sh = &F->sh;
    const int nchunks = F->nchunks, threads = F->threads;
    chunk *ch = F->ch;
    tri_job *jobs = F->jobs;
    const double t0 = omp_get_wtime();
    if (src->rewind && src->rewind(src->user)) return -1;
    for (;;) {
        const size_t got = src->next(src->user, F->tri, F->ids, F->batch);
        if (got == (size_t)-1) return -1;
        if (!got) break;
        if (sh->pairs) hpc_pair_batch(F->tri, F->ids, F->pairs, got);
        hpc_prepare_batch(sh, jobs, F->tri, F->ids, sh->pairs ? F->pairs : NULL, got);
        counters[C_TRIANGLES] += got;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
        for (int i = 0; i < nchunks; i++)
            for (size_t t = 0; t < got; t++)
                if (jobs[t].pair >= 0) cast_triangle(sh, &ch[i], &jobs[t]);
        for (int i = 0; i < nchunks; i++)
            if (ch[i].failed) return -1;
    }
    counters[C_CAST_US] += (uint64_t)((omp_get_wtime() - t0) * 1e6);
    return 0;
}

int MS_CAT(ms_hpc_cast_, MS_ISA_SUFFIX)(const ms_render_ctx *ctx, int scanline, ms_raster_fn raster,
                                        const ms_shadow_query *q, size_t n, const uint64_t *front, uint64_t *vis,
                                        const hpc_source *src, uint64_t *counters)
{
    hpc_frame F;
    /* a batch holds every triangle of a small scene: the same single batch, without BATCH's buffers */
    const size_t batch = src->total && src->total < BATCH ? src->total : BATCH;
    int rc = hpc_frame_begin(&F, ctx, scanline, raster, q, n, front, batch, counters);
    if (!rc && hpc_sw(&F.sh, MS_HPC_OFF_ON_DEMAND)) rc = preload_slots(&F);
    if (!rc) rc = cast_batches(&F, src, counters);
    if (!rc) hpc_frame_vis(&F, vis);
    hpc_frame_end(&F, counters);
    return rc;
}
