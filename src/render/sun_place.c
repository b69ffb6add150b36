/* Placing suns for a scene (sun_place.h). */
#include "sun_place.h"
#include "light/light_shape.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define BATCH 4096

static void grow(float box[6], const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            box[a] = fminf(box[a], v[3 * i + a]);
            box[3 + a] = fmaxf(box[3 + a], v[3 * i + a]);
        }
}

void ms_scene_tri_box(const ms_scene *s, const ms_bvh *bvh, float box[6])
{
    for (int a = 0; a < 3; a++) { box[a] = INFINITY; box[3 + a] = -INFINITY; }
    if (bvh && bvh->n_nodes) {
        for (int a = 0; a < 3; a++) { box[a] = bvh->nodes[0].bmin[a]; box[3 + a] = bvh->nodes[0].bmax[a]; }
    } else if (s->tri) {
        grow(box, s->tri, 3 * s->n_tris);
    } else if (s->procedural.type != MS_PROCEDURAL_NONE) {
        float *t = malloc(BATCH * 9 * sizeof *t);
        for (size_t first = 0; t && first < s->n_tris; first += BATCH) {
            const size_t n = s->n_tris - first < BATCH ? s->n_tris - first : BATCH;
            ms_procedural_triangles(s, first, n, t);
            grow(box, t, 3 * n);
        }
        free(t);   /* out of memory: the empty box, and the sun placed at a unit distance (ms_light_sun_place) */
    }
    for (int a = 0; a < 6; a++)
        if (!isfinite(box[a])) box[a] = 0.0f;   /* no triangles */
}

ms_light *ms_lights_placed(const ms_light *lights, size_t n, const ms_scene *s, const ms_bvh *bvh, int *oom)
{
    *oom = 0;
    size_t suns = 0;
    for (size_t l = 0; l < n; l++) suns += lights[l].shape == MS_LIGHT_SUN;
    if (!suns) return NULL;
    ms_light *out = malloc(n * sizeof *out);
    if (!out) { *oom = 1; return NULL; }
    memcpy(out, lights, n * sizeof *out);
    float box[6];
    ms_scene_tri_box(s, bvh, box);
    for (size_t l = 0; l < n; l++) ms_light_sun_place(&out[l], box);
    return out;
}
