/* Packed charts kept from sharing footprint texels (atlas_footprints.c). xatlas packs each chart's bilinear
 * footprint as it estimates it (the texel squares about its raster tested against the chart's boundary
 * edges); with no padding between footprints that estimate let two charts read the same texel. This pass
 * takes the packed layout, finds every chart or region whose exact footprint (footprint.h) shares a texel
 * with one placed before it, and moves it by whole texels to the first place on the pages where it shares
 * none. */
#ifndef MS_ATLAS_FOOTPRINTS_H
#define MS_ATLAS_FOOTPRINTS_H
#include <stddef.h>
#include <stdint.h>

typedef struct ms_fp_layout {
    int size;                  /* page side, texels */
    int pages;                 /* in: the pages used; out: with those added (add_pages) */
    int add_pages;             /* 1: a chart with no room moves to a new page; 0: the layout does not fit */
    /* regions: rectangles (corner x, y and size w, h in texels, page), moved whole */
    size_t nr;
    double *rx, *ry;
    const double *rw, *rh;
    int *rpage;
    /* charts: triangles with UVs in texels of their page, unit[t] in [0, nu): a chart moved whole */
    size_t nt, nu;
    float *uv;
    uint32_t *tpage;
    const uint32_t *unit;
    size_t moved;              /* out: regions and charts moved */
} ms_fp_layout;

/* 0: no two footprints share a texel; 1: some chart found no room (add_pages 0); -1: out of memory. */
int ms_fp_separate(ms_fp_layout *l);

#endif
