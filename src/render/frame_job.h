/* A frame tile by tile (ms_frame_job, microshadow.h): the set-up, the tiled primary and shadow phases and
 * the frame-global finish that ms_render runs in one go, split so that a driver can render any tiles in
 * any number of calls (the CLI's MPI mode hands tiles out to processes) and still get ms_render's image bit
 * for bit. Why that holds: a pixel's hit point, surface, samples and V/S/S_spec for every light depend only
 * on the pixel, the seed and the scene (the block methods group 4x4 pixel blocks, which never straddle a
 * 16x16 tile; a sphere light is answered one query at a time); what depends on the whole frame (the
 * interleaved pattern's filter, which reads neighbours across tiles, the exposure's 99th percentile, the
 * shading's hit points) runs in finish over the whole frame. Frame-level methods (visibility_all) get the
 * receivers of one call at once, which is exact only for methods whose answer does not depend on the other
 * receivers (method.h, split_exact); the others only render whole frames. Each light has its own method
 * state for the job's life (set-ups such as hpc's light hierarchy and the frusta are per light), so that
 * any call can render any tile for every light. */

#ifndef MS_FRAME_JOB_H
#define MS_FRAME_JOB_H
#include "microshadow.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/occluders.h"
#include "visibility/alpha.h"
#include "shade.h"
#include "exact_split.h"
#include <stdint.h>

#define TILE MS_TILE_SIZE

/* The job: what ms_frame_job_create sets up (frame_job_create.c), the calls render (frame_job.c, the shadow
 * phase in frame_job_shadow.c) and finish or hand out in bands (frame_job_finish.c). */

struct ms_frame_job {
    ms_scene soup;                /* a procedural scene materialised for a method that does not stream */
    int own_soup;
    const ms_scene *scene;
    const ms_shadow_method *sm;
    const ms_primary_method *pm;
    ms_render_ctx ctx;            /* ctx.light: light 0; each light's pass uses a copy with its light */
    const ms_light *lights;
    size_t nlights;
    ms_light *placed_lights;      /* the lights with their suns placed for the scene (sun_place.h); NULL: none */
    ms_bvh bvh;
    struct ms_alpha *alpha;       /* alpha-tested triangles (NULL: none), ctx.alpha */
    void *pstate;
    void **sstate;                /* per light */
    void **own_sstate;            /* per light whose occluders merge coplanar faces: the method over the scene's
                                   * own triangles, for the receivers on merged faces (merged_last) */
    void **axis_sstate;           /* per light and axis (3 per light), for a method with MS_OCC_MERGE_EXACT: the
                                   * method over the light's set exact for that axis (occluders.h, for_axis) */
    void **interior_sstate;       /* per light with interior boxes, for a method with MS_OCC_INTERIOR_PASS: the
                                   * method over the boxes' triangles, run before the scene's */
    ms_occluders *occ;            /* per light: its occluders (sm->occluders, occluder_what), else NULL */
    ms_render_options opt;
    int W, H, tx, ty, ntiles, samples, spp, threads, rendered_any, streamed;
    /* The rows the planes (hits, surf, the frame's) hold: y_base .. y_base + rows_held; the whole frame, or
     * a band of band_rows at most when the outputs are streamed (frame_stream.c). */
    int y_base, rows_held, band_rows;
    /* Streamed: rows 0 .. rendered_to are rendered, 0 .. emitted_to handed out. With the interleaved filter
     * (band_filter) a band is handed out once two rows of the next are rendered: the planes then hold a window
     * of 2 band_rows + 2 rows from y_base, and the filtered band goes to band_vis, band_shadow, band_spec. */
    int rendered_to, emitted_to, band_filter;
    float *band_vis, *band_shadow, *band_spec;
    int aa_s, aa_split;           /* anti-aliasing: W, H are s times the output's; frame_aa.c resolves them */
    ms_hit *hits;
    ms_surface *surf;             /* per pixel, only for scenes with materials or normals (shade.h) */
    uint8_t *traced;              /* per tile: primary hits (and surfaces) are in hits (and surf) */
    ms_frame frame;
    double t_start;
    long done, total;             /* progress: tiles over the primary phase and every light's shadow phase */
    long reported;                /* the largest `done` handed to the progress callback */
    int cancelled;                /* the callback asked to stop: the remaining tiles are skipped */
};

static inline void tile_rect(const ms_frame_job *j, int t, int *x0, int *y0, int *x1, int *y1)
{
    *x0 = (t % j->tx) * TILE;
    *y0 = (t / j->tx) * TILE;
    *x1 = *x0 + TILE < j->W ? *x0 + TILE : j->W;
    *y1 = *y0 + TILE < j->H ? *y0 + TILE : j->H;
}

/* CPU seconds of all the process's threads (frame_job.c). */
double fj_process_cpu_s(void);
/* One tile done (the progress callback); 1 once the callback cancelled the frame (frame_job.c). */
void fj_progress_tick(ms_frame_job *j);
int fj_cancelled(ms_frame_job *j);
/* Primary hits, and surfaces, of tiles[0..n) (tiles == NULL: 0..n-1) (frame_job.c). */
void fj_trace_tiles(ms_frame_job *j, const int *tiles, int n, int tick);
void fj_surface_tiles(ms_frame_job *j, const int *tiles, int n);

/* Light l's contexts (frame_job_light.c). */
void fj_light_ctx(const ms_frame_job *j, size_t l, ms_render_ctx *c);
void fj_light_own_ctx(const ms_frame_job *j, size_t l, ms_render_ctx *c);
void fj_light_axis_ctx(const ms_frame_job *j, size_t l, int a, ms_render_ctx *c);
void fj_light_split(const ms_frame_job *j, size_t l, ms_exact_split *sp);
void fj_light_interior_ctx(const ms_frame_job *j, size_t l, ms_render_ctx *c);

/* Sums of the shadow passes of one call. */
typedef struct pass_sums {
    uint64_t counters[MS_MAX_COUNTERS];
    uint64_t visible, penumbra, segments, on_merged;
    double resolve_thread_s;
} pass_sums;

/* The shadow phase of light l over tiles[0..n) (tiles == NULL: 0..n-1; whole: the frame's first and only
 * call): front masks, the method's visible masks, V, S and S_spec into light l's planes, over 16x16 tiles
 * (or the method's frame-level entry). Adds to p. 0, or -1 out of memory or when the method fails
 * (frame_job_shadow.c). */
int fj_shadow_pass(ms_frame_job *j, size_t l, const int *tiles, int n, int whole, pass_sums *p);

#endif
