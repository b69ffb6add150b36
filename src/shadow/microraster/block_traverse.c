/* Set-up of the multi-frusta of a block (block_traverse.h): per lane, scalar, once per block or when a
 * lane's frustum shrinks. */
#include "block_traverse.h"
#include <math.h>
#include <string.h>
#include "core/vec.h"

/* Stand-in for a zero direction bound: 1/TINY stays finite (1e30), so no 0 * inf in the slab products. */
#define TINY 1e-30f

void ms_block_frusta_init(ms_block_frusta *f, const ms_bvh_node *root, float near, float far)
{
    memset(f, 0, sizeof *f);
    f->near = near;
    f->far = far;
    float ext = 0.0f;
    for (int a = 0; a < 3; a++) ext = ms_maxf(ext, ms_maxf(fabsf(root->bmin[a]), fabsf(root->bmax[a])));
    /* 2^-20 of the largest coordinate: 8 ulps of any coordinate or of C (a point of the scene), which
     * bounds the rounding of bmin - margin - C below the exact bmin - C. In the scene's frame (scene_frame.c)
     * the largest coordinate is at most 6 half-extents of the geometry: a fixed fraction of the scene at any
     * distance from the world's origin. */
    f->margin = ext * (1.0f / 1048576.0f) + 1e-30f;
}

void ms_block_frusta_set_lane(ms_block_frusta *f, int lane, const float c[3], const float d[4][3], float rel)
{
    const unsigned bit = 1u << lane;
    for (int a = 0; a < 3; a++) {
        float lo = d[0][a], hi = d[0][a], mag = fabsf(c[a]);
        for (int i = 1; i < 4; i++) { lo = ms_minf(lo, d[i][a]); hi = ms_maxf(hi, d[i][a]); }
        for (int i = 0; i < 4; i++) mag = ms_maxf(mag, fabsf(d[i][a]) + fabsf(c[a]));
        lo -= rel * mag;
        hi += rel * mag;
        if (lo == 0.0f) lo = -TINY;
        if (hi == 0.0f) hi = TINY;
        f->c[a][lane] = f->chi[a][lane] = c[a];
        f->rlo[a][lane] = 1.0f / lo;
        f->rhi[a][lane] = 1.0f / hi;
        f->pos_hi[a] = (f->pos_hi[a] & ~bit) | (hi > 0.0f ? bit : 0u);
        f->neg_lo[a] = (f->neg_lo[a] & ~bit) | (lo < 0.0f ? bit : 0u);
    }
    f->live |= bit;
}

void ms_block_frusta_set_lane_box(ms_block_frusta *f, int lane, const float clo[3], const float chi[3], const float plo[3],
                                  const float phi[3], float rel)
{
    const unsigned bit = 1u << lane;
    for (int a = 0; a < 3; a++) {
        const float mag = ms_maxf(ms_maxf(fabsf(clo[a]), fabsf(chi[a])), ms_maxf(fabsf(plo[a]), fabsf(phi[a])));
        /* dlo bounds the upper envelope's slope (from clo), dhi the lower's (from chi); 2 mag bounds |P - C|. */
        float lo = plo[a] - clo[a] - rel * 2.0f * mag, hi = phi[a] - chi[a] + rel * 2.0f * mag;
        if (lo == 0.0f) lo = -TINY;
        if (hi == 0.0f) hi = TINY;
        f->c[a][lane] = clo[a];
        f->chi[a][lane] = chi[a];
        f->rlo[a][lane] = 1.0f / lo;
        f->rhi[a][lane] = 1.0f / hi;
        f->pos_hi[a] = (f->pos_hi[a] & ~bit) | (hi > 0.0f ? bit : 0u);
        f->neg_lo[a] = (f->neg_lo[a] & ~bit) | (lo < 0.0f ? bit : 0u);
    }
    f->live |= bit;
}
