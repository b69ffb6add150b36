/* One frame: ms_render is the tile-by-tile frame (frame_job.c: BVH build, primary visibility, shadows per
 * light, each phase timed on its own and run over 16x16 pixel tiles by OpenMP, dynamic scheduling: shadow
 * cost varies wildly across a frame) with every tile in one call. */
#include "microshadow.h"
#include "core/abi.h"
#include "frame_shade.h"
#include <string.h>

/* The whole frame in one go: every tile in one call of the tile-by-tile frame (frame_job.c). */
ms_status ms_render_abi(const ms_abi *abi, const ms_scene *scene, const ms_render_options *opt, ms_frame *out, char *err,
                        size_t errlen)
{
    ms_status rc = ms_abi_check(abi, "ms_render", err, errlen);
    if (rc) return rc;
    ms_render_options own;
    opt = ms_abi_options(opt, MS_ABI_SIZE(abi, render_options), &own, sizeof own);
    memset(out, 0, sizeof *out);
    ms_frame_job *job;
    rc = ms_frame_job_create(scene, opt, &job, err, errlen);
    if (rc) return rc;
    rc = ms_frame_job_render(job, NULL, ms_frame_job_tiles(job, NULL, NULL), err, errlen);
    if (rc == MS_OK) rc = ms_frame_job_finish(job, out, err, errlen);
    ms_frame_job_free(job);
    return rc;
}

/* A frame job none of whose tiles is rendered: its finish traces the primary hits (and surfaces) itself and
 * shades them with S = 0, and the exposure (frame_shade.c) comes from the unshadowed radiance, which S does
 * not enter. raytrace: the method whose set-up is no more than the BVH the primary hits need anyway. */
ms_status ms_frame_auto_exposure(const ms_scene *scene, ms_shading shading, int threads, float *exposure, char *err,
                                 size_t errlen)
{
    ms_render_options o;
    memset(&o, 0, sizeof o);
    o.method = "raytrace";
    o.threads = threads;
    o.shading = shading;
    o.stream = MS_STREAM_OFF;
    ms_frame_job *job;
    ms_status rc = ms_frame_job_create(scene, &o, &job, err, errlen);
    if (rc) return rc;
    ms_frame f;
    rc = ms_frame_job_finish(job, &f, err, errlen);
    ms_frame_job_free(job);
    if (rc) return rc;
    *exposure = f.exposure;
    ms_frame_free(&f);
    return MS_OK;
}
