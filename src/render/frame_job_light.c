/* Each light's contexts for a frame job (frame_job.h): over its occluders, over the scene's own triangles, over
 * its sets exact per axis, over its interior boxes; its split of the samples among its exact sets. */

#include "frame_job.h"
#include <string.h>

/* Light l's context: the frame's, with its light and, when the method takes them, its occluders. */
void fj_light_ctx(const ms_frame_job *j, size_t l, ms_render_ctx *c)
{
    *c = j->ctx;
    c->light = j->lights[l];
    if (j->occ) ms_occluders_ctx(&j->occ[l], c);
}

/* Light l's context over the scene's own triangles (its interior boxes kept: they are exact for any
 * receiver), for the receivers on merged faces. */
void fj_light_own_ctx(const ms_frame_job *j, size_t l, ms_render_ctx *c)
{
    fj_light_ctx(j, l, c);
    c->bvh = &j->bvh;
    c->alpha = j->alpha;
    c->prim_map = NULL;
    c->prim_merged = NULL;
}

/* Light l's context over its set exact for segments sheared along axis a (occluders.h, for_axis). */
void fj_light_axis_ctx(const ms_frame_job *j, size_t l, int a, ms_render_ctx *c)
{
    const ms_occluders *s = j->occ[l].for_axis[a];
    fj_light_ctx(j, l, c);
    c->bvh = &s->bvh;
    c->alpha = s->alpha;
    c->prim_map = s->prim_map;
    c->prim_merged = NULL;
}

/* Light l's split of the samples among its exact sets (exact_split.h): the axes its merge is not exact for,
 * each with the state over its set exact for it, or over the scene's own triangles. axes 0: no split (a
 * method that need not equal raytrace, or nothing merged). */
void fj_light_split(const ms_frame_job *j, size_t l, ms_exact_split *sp)
{
    memset(sp, 0, sizeof *sp);
    if (!(j->sm->occluders & MS_OCC_MERGE_EXACT) || !j->occ || !j->occ[l].active) return;
    sp->axes = j->occ[l].merged_axes;
    for (int a = 0; a < 3; a++) {
        if (!(sp->axes >> a & 1u)) continue;
        ms_render_ctx c;
        if (j->occ[l].for_axis[a]) fj_light_axis_ctx(j, l, a, &c);
        else fj_light_own_ctx(j, l, &c);
        sp->state[a] = j->occ[l].for_axis[a] ? j->axis_sstate[3 * l + (size_t)a] : j->own_sstate[l];
        sp->bvh[a] = c.bvh;
        sp->alpha[a] = c.alpha;
        sp->prim_map[a] = c.prim_map;
    }
}

/* Light l's context over its interior boxes alone, for a method that takes them as occluders of its own
 * (MS_OCC_INTERIOR_PASS): no receiver lies on them, none is alpha-tested. */
void fj_light_interior_ctx(const ms_frame_job *j, size_t l, ms_render_ctx *c)
{
    ms_render_ctx lc;
    fj_light_ctx(j, l, &lc);
    ms_ctx_interior_pass(&lc, c);
}
