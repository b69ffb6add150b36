/* The shading of a finished frame (frame_shade.h): per pixel the lights' radiance from their S and S_spec
 * planes, and the frame's automatic exposure. */
#include "frame_shade.h"
#include "visibility/receiver.h"
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Textured lights: per light and pixel the weighted mean texel colour (ms_light_texture_mean) that scales
 * its unshadowed irradiance, 3 floats each (NULL entries for untextured lights); *out NULL when no light
 * is textured. 0, or -1 out of memory. */
static int texture_means(const ms_render_ctx *ctx0, const ms_light *lights, size_t nlights, const ms_hit *hits, int W,
                         int y0, size_t npix, int threads, float **out)
{
    *out = NULL;
    size_t textured = 0;
    for (size_t l = 0; l < nlights; l++) textured += lights[l].texture != NULL;
    if (!textured) return 0;
    float *t = malloc(nlights * npix * 3 * sizeof *t);
    if (!t) return -1;
    for (size_t l = 0; l < nlights; l++) {
        if (!lights[l].texture) continue;
        ms_render_ctx ctx = *ctx0;
        ctx.light = lights[l];
        float *tl = t + l * npix * 3;
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
        for (size_t i = 0; i < npix; i++) {
            if (hits[i].prim == UINT32_MAX) continue;
            ms_shadow_query q;
            ms_query_from_hit(&q, &hits[i], (uint32_t)(i % (size_t)W), (uint32_t)(i / (size_t)W + (size_t)y0));
            ms_light_texture_mean(&ctx, &q, tl + 3 * i);
        }
    }
    *out = t;
    return 0;
}

int ms_frame_shade(const ms_scene *scene, const ms_render_ctx *ctx, const ms_light *lights, size_t nlights,
                   const ms_hit *hits, const ms_surface *surf, int threads, int y0, ms_frame *out, float *lum_out)
{
    /* Shading (shade.h): per light the exact unshadowed irradiance times S, plus the LTC specular times
     * S_spec (ratio estimators: exact where the light is wholly visible or hidden, converging as k grows);
     * the lights' radiance adds up. */
    const int W = out->width;
    const size_t npix = (size_t)out->width * out->height;
    float *tex = NULL;   /* textured lights: the mean texel colour each pixel sees */
    if (texture_means(ctx, lights, nlights, hits, W, y0, npix, threads, &tex)) return -1;
    float *lum = lum_out ? lum_out : malloc(npix * sizeof(float));
    size_t nlum = 0;
    /* In parallel (a disk across the horizon costs a 256-gon per pixel): lum[i] per pixel, misses
     * dropped after. */
#pragma omp parallel for schedule(dynamic, 1024) num_threads(threads)
    for (size_t i = 0; i < npix; i++) {
        float *c = out->rgb + 3 * i;
        c[0] = c[1] = c[2] = 0.0f;
        if (lum) lum[i] = -INFINITY;
        if (hits[i].prim == UINT32_MAX) continue;
        ms_surface grey;
        if (!surf) {
            float viewer[3];   /* the eye, or up the pixel's own ray for an orthographic camera */
            ms_camera_viewer(&ctx->cam, hits[i].p, viewer);
            ms_surface_at(scene, NULL, &hits[i], viewer, MS_SHADING_STANDARD, &grey);   /* grey: the same in both */
        }
        float y = 0.0f;
        for (size_t l = 0; l < nlights; l++) {
            ms_light L = lights[l];
            if (tex && L.texture) {   /* the texels this pixel sees scale the emission */
                const float *t = tex + 3 * (l * npix + i);
                L.emission.x *= t[0];
                L.emission.y *= t[1];
                L.emission.z *= t[2];
            }
            float rgb[3], u;
            ms_shade(&L, hits[i].p, surf ? &surf[i] : &grey, out->shadow[l * npix + i], out->shadow_spec[l * npix + i],
                     rgb, &u);
            c[0] += rgb[0];
            c[1] += rgb[1];
            c[2] += rgb[2];
            y += u;
        }
        const float *em = surf ? surf[i].emissive : grey.emissive;   /* emission: once, not per light */
        if (em[0] != 0.0f || em[1] != 0.0f || em[2] != 0.0f) {
            for (int k = 0; k < 3; k++) c[k] += em[k];
            y += 0.2126f * em[0] + 0.7152f * em[1] + 0.0722f * em[2];
        }
        if (lum) lum[i] = y;
    }
    free(tex);
    if (lum_out) return 0;   /* a band's: the exposure is the caller's (frame_stream.c) */
    for (size_t i = 0; lum && i < npix; i++)
        if (hits[i].prim != UINT32_MAX) lum[nlum++] = lum[i];
    out->exposure = 1.0f;
    if (lum && nlum) {
        qsort(lum, nlum, sizeof *lum, cmp_float);
        float p99 = lum[(size_t)(0.99 * (double)(nlum - 1))];
        if (p99 > 0.0f) out->exposure = 1.0f / p99;
    }
    free(lum);
    return 0;
}
