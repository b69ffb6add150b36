/* Pixel anti-aliasing's resolve (frame_aa.h). */
#include "frame_aa.h"
#include <stdlib.h>

int ms_frame_aa_resolve(ms_frame *f, int s, int front_scale)
{
    const int W = f->width / s, H = f->height / s, Ws = f->width;
    const size_t npix = (size_t)W * H, nsub = (size_t)f->width * f->height;
    const size_t nl = f->n_lights > 0 ? (size_t)f->n_lights : 1;
    float *rgb = malloc(npix * 3 * sizeof *rgb);
    float *vis = malloc(nl * npix * sizeof *vis), *shadow = malloc(nl * npix * sizeof *shadow);
    float *spec = malloc(nl * npix * sizeof *spec);
    uint16_t *front = malloc(nl * npix * sizeof *front);
    if (!rgb || !vis || !shadow || !spec || !front) {
        free(rgb); free(vis); free(shadow); free(spec); free(front);
        return -1;
    }
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
            for (int k = 0; k < 3; k++) rgb[3 * o + k] = (float)(c[k] * inv_k);
            for (size_t l = 0; l < nl; l++) {
                const float *v = f->vis + l * nsub, *sh = f->shadow + l * nsub, *sp = f->shadow_spec + l * nsub;
                const uint16_t *fr = f->front + l * nsub;
                double sv = 0.0, ss = 0.0, ssp = 0.0, sf = 0.0;
                int hits = 0;
                for (int j = 0; j < s; j++)
                    for (int i = 0; i < s; i++) {
                        const size_t q = (size_t)(y * s + j) * Ws + (size_t)(x * s + i);
                        if (v[q] < 0.0f) continue;   /* a miss: no V, S of its own */
                        sv += v[q];
                        ss += sh[q];
                        ssp += sp[q];
                        sf += fr[q];
                        hits++;
                    }
                const size_t d = l * npix + o;
                if (!hits) {
                    vis[d] = shadow[d] = spec[d] = -1.0f;
                    front[d] = 0;
                    continue;
                }
                vis[d] = (float)(sv / hits);
                shadow[d] = (float)(ss / hits);
                spec[d] = (float)(ssp / hits);
                const double fm = sf / hits * front_scale + 0.5;
                front[d] = (uint16_t)(fm < 65535.0 ? fm : 65535.0);
            }
        }
    free(f->rgb); free(f->vis); free(f->shadow); free(f->shadow_spec); free(f->front);
    f->rgb = rgb;
    f->vis = vis;
    f->shadow = shadow;
    f->shadow_spec = spec;
    f->front = front;
    f->width = W;
    f->height = H;
    return 0;
}
