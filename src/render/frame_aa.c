/* Pixel anti-aliasing's resolve (frame_aa.h). */
#include "frame_aa.h"
#include <stdlib.h>

void ms_frame_aa_resolve_into(const ms_frame *f, int s, int front_scale, ms_frame *out)
{
    const int W = f->width / s, H = f->height / s, Ws = f->width;
    const size_t npix = (size_t)W * H, nsub = (size_t)f->width * f->height;
    const size_t nl = f->n_lights > 0 ? (size_t)f->n_lights : 1;
    const double inv_k = 1.0 / (double)(s * s);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const size_t o = (size_t)y * W + x;
            /* Summed in double: the mean of up to 16 floats, rounded once. */
            double c[3] = { 0.0, 0.0, 0.0 };
            for (int j = 0; j < s; j++)
                for (int i = 0; i < s; i++) {
                    const float *src = f->rgb + 3 * ((size_t)(y * s + j) * Ws + (size_t)(x * s + i));
                    for (int k = 0; k < 3; k++) c[k] += src[k];
                }
            for (int k = 0; k < 3; k++) out->rgb[3 * o + k] = (float)(c[k] * inv_k);
            for (size_t l = 0; l < nl; l++) {
                const float *v = f->vis + l * nsub, *sh = f->shadow + l * nsub;
                const float *sp = f->shadow_spec ? f->shadow_spec + l * nsub : NULL;
                const uint16_t *fr = f->front ? f->front + l * nsub : NULL;
                double sv = 0.0, ss = 0.0, ssp = 0.0, sf = 0.0;
                int hits = 0;
                for (int j = 0; j < s; j++)
                    for (int i = 0; i < s; i++) {
                        const size_t q = (size_t)(y * s + j) * Ws + (size_t)(x * s + i);
                        if (v[q] < 0.0f) continue;   /* a miss: no V, S of its own */
                        sv += v[q];
                        ss += sh[q];
                        if (sp) ssp += sp[q];
                        if (fr) sf += fr[q];
                        hits++;
                    }
                const size_t d = l * npix + o;
                if (!hits) {
                    out->vis[d] = out->shadow[d] = -1.0f;
                    if (sp) out->shadow_spec[d] = -1.0f;
                    if (fr) out->front[d] = 0;
                    continue;
                }
                out->vis[d] = (float)(sv / hits);
                out->shadow[d] = (float)(ss / hits);
                if (sp) out->shadow_spec[d] = (float)(ssp / hits);
                if (fr) {
                    const double fm = sf / hits * front_scale + 0.5;
                    out->front[d] = (uint16_t)(fm < 65535.0 ? fm : 65535.0);
                }
            }
        }
    out->width = W;
    out->height = H;
    out->n_lights = f->n_lights;
    out->exposure = f->exposure;
    out->stats = f->stats;
}

int ms_frame_aa_resolve(ms_frame *f, int s, int front_scale)
{
    const size_t npix = (size_t)(f->width / s) * (size_t)(f->height / s);
    const size_t nl = f->n_lights > 0 ? (size_t)f->n_lights : 1;
    ms_frame r = *f;
    r.rgb = malloc(npix * 3 * sizeof *r.rgb);
    r.vis = malloc(nl * npix * sizeof *r.vis);
    r.shadow = malloc(nl * npix * sizeof *r.shadow);
    r.shadow_spec = malloc(nl * npix * sizeof *r.shadow_spec);
    r.front = malloc(nl * npix * sizeof *r.front);
    if (!r.rgb || !r.vis || !r.shadow || !r.shadow_spec || !r.front) {
        free(r.rgb); free(r.vis); free(r.shadow); free(r.shadow_spec); free(r.front);
        return -1;
    }
    ms_frame_aa_resolve_into(f, s, front_scale, &r);
    free(f->rgb); free(f->vis); free(f->shadow); free(f->shadow_spec); free(f->front);
    *f = r;
    return 0;
}
