/* A bake's UV layout and its pages (bake_pages.h). The pages of a lightmap are stacked in one frame, so that
 * the texels, the shadows (ms_bake_rows over any rows, the MPI driver included), dilation, the seams and
 * the writers see one image; the UVs are kept per page (what a file and an engine use) and converted to
 * the frame's rows where the bake rasterizes and stitches. */
#include "bake_pages.h"
#include "bake_uvs.h"
#include "uv_cache.h"
#include "scene/scene_internal.h"
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void ms_bake_pages_free(ms_lightmap *lm)
{
    free(lm->page);
    free(lm->page_fill);
    free(lm->object_uv_set);
    free(lm->object_scale_offset);
    lm->page = NULL;
    lm->page_fill = NULL;
    lm->object_uv_set = NULL;
    lm->object_scale_offset = NULL;
}

ms_status ms_bake_choose_uvs(const ms_scene *sc, const ms_bake_options *o, int size, int padding, ms_lightmap *lm, char *err,
                             size_t errlen)
{
    const size_t n = sc->n_tris, nobj = ms_bake_uv_objects(sc);
    if (!(o->texel_density >= 0.0f) || !isfinite(o->texel_density)) {
        snprintf(err, errlen, "texel density must be a finite number >= 0 (0: one page), not %g", o->texel_density);
        return MS_ERR_INVALID;
    }
    lm->uv = malloc((n ? n : 1) * 6 * sizeof(float));
    lm->page = malloc((n ? n : 1) * sizeof *lm->page);
    lm->object_uv_set = malloc((nobj ? nobj : 1) * sizeof *lm->object_uv_set);
    lm->object_scale_offset = malloc((nobj ? nobj : 1) * 4 * sizeof *lm->object_scale_offset);
    if (!lm->uv || !lm->page || !lm->object_uv_set || !lm->object_scale_offset) {
        snprintf(err, errlen, "out of memory for the UVs of %zu triangles", n);
        return MS_ERR_NO_MEMORY;
    }
    lm->n_objects = nobj;
    lm->n_tris = n;
    const double t0 = omp_get_wtime();
    ms_bake_uv_params p = { o->uv_set, size, padding, o->texel_density, o->uv_packing };
    ms_bake_uv_layout L = { lm->uv, lm->page, 1, lm->object_uv_set, lm->object_scale_offset };
    lm->uv_key = ms_uv_cache_key(sc, &p);
    if (o->uv_cache) {
        char why[256];
        const int got = ms_uv_cache_read(o->uv_cache, lm->uv_key, n, nobj, &L, why, sizeof why);
        if (got > 0) {
            lm->pages = L.pages;
            lm->uv_cached = 1;
            lm->unwrap_s = omp_get_wtime() - t0;
            return MS_OK;
        }
        if (got < 0) ms_warn("UV cache %s %s: not used, the UVs are made anew", o->uv_cache, why);
    }
    ms_bake_uv_report rep;
    if (ms_bake_uvs(sc, &p, &L, &rep, err, errlen)) return MS_ERR_INVALID;
    lm->pages = L.pages;
    lm->unwrapped_tris = rep.unwrapped;
    lm->charts = rep.charts;
    lm->unwrap_s = omp_get_wtime() - t0;
    return MS_OK;
}

float *ms_bake_frame_uv(const ms_lightmap *lm)
{
    if (lm->pages <= 1) return lm->uv;
    float *f = malloc((lm->n_tris ? lm->n_tris : 1) * 6 * sizeof *f);
    if (!f) return NULL;
    for (size_t t = 0; t < lm->n_tris; t++)
        for (int k = 0; k < 3; k++) {
            f[6 * t + 2 * k] = lm->uv[6 * t + 2 * k];
            f[6 * t + 2 * k + 1] = (float)(((double)lm->page[t] + lm->uv[6 * t + 2 * k + 1]) / lm->pages);
        }
    return f;
}

void ms_bake_page_fill(ms_lightmap *lm, const float *dist, int size)
{
    const int pages = lm->pages > 0 ? lm->pages : 1;
    free(lm->page_fill);
    lm->page_fill = calloc((size_t)pages, sizeof *lm->page_fill);
    if (!lm->page_fill) return;
    const size_t per = (size_t)size * size;
    for (int p = 0; p < pages; p++) {
        size_t on = 0;
        for (size_t i = 0; i < per; i++) on += dist[(size_t)p * per + i] == 0.0f;
        lm->page_fill[p] = (double)on / (double)per;
    }
}
