/* One frame: ms_render is the tile-by-tile frame (frame_job.c: BVH build, primary visibility, shadows per
 * light, each phase timed on its own and run over 16x16 pixel tiles by OpenMP, dynamic scheduling: shadow
 * cost varies wildly across a frame) with every tile in one call. */
#include "microshadow.h"
#include <string.h>

/* The whole frame in one go: every tile in one call of the tile-by-tile frame (frame_job.c). */
int ms_render(const ms_scene *scene, const ms_render_options *opt, ms_frame *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    ms_frame_job *job;
    const int crc = ms_frame_job_create(scene, opt, &job, err, errlen);
    if (crc) return crc == MS_ERR_BUDGET ? MS_ERR_BUDGET : -1;
    int rc = ms_frame_job_render(job, NULL, ms_frame_job_tiles(job, NULL, NULL), err, errlen);
    if (rc == 0) rc = ms_frame_job_finish(job, out, err, errlen) ? -1 : 0;
    else if (rc != MS_ERR_CANCELLED) rc = -1;
    ms_frame_job_free(job);
    return rc;
}
