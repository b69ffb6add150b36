/* Regions and xatlas charts packed together by xatlas's own packer (atlas_xpack.c). */
#ifndef MS_ATLAS_XPACK_H
#define MS_ATLAS_XPACK_H
#include <stddef.h>
#include <stdint.h>

typedef struct ms_xpack {
    /* in: regions (w x h texels, kept whole: an object's layout under one scale and offset) and charts
     * (triangles with UVs in texels; triangles sharing a UV vertex of the same key form one chart) */
    size_t nr;
    const double *rw, *rh;
    size_t nt;
    const float *tuv;
    const uint32_t *tkey;
    int size, pad;
    int grow;   /* 1: one atlas as large as it takes (no chart spills over), moved to (pad, pad): 1 page if it fits
                 * size x size, else 2 (not usable); 0: size x size pages, as many as it takes */
    /* out: each region's corner (texels) and page, each triangle's UVs (texels of its page) and page */
    double *rx, *ry;
    int *rpage;
    float *out_uv;
    uint32_t *tpage;
    double extent;   /* grow: the atlas's larger side, texels */
} ms_xpack;

/* Packs everything at scale s (every size and UV times s) onto size x size pages, no rotation, `pad` texels
 * apart (0: footprints touching, never sharing a texel: atlas_footprints.h). Returns the pages used, or -1 with a message (out of memory, a region larger than a page). xatlas
 * places charts on a fixed-size page by random probing (4096 tries), which on a nearly full page sends a
 * small chart to the next one; the growing atlas (grow) never does, so one page is fitted with it. */
int ms_xpack_run(ms_xpack *x, double s, char *err, size_t errlen);
#endif
