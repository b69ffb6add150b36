/* Rectangles (the objects' UV layouts) packed onto lightmap pages (atlas_pack.c). */
#ifndef MS_ATLAS_PACK_H
#define MS_ATLAS_PACK_H
#include <stddef.h>

typedef struct ms_pack_rect {
    double w0, h0;   /* size at scale 1 (texels when the scale is 1) */
    /* out: where it went, in texels of its page */
    double x, y, w, h;
    int page;
} ms_pack_rect;

/* Packs the rectangles at scale k (w = k w0, h = k h0, texels) onto pages of size x size, `pad` texels
 * between them and around them, at most max_pages pages (0: no limit): largest first, each where it fits
 * best on any open page (MaxRects, best short side), a new page when none has room. Returns the pages
 * used, or -1 when a rectangle is larger than a page or max_pages do not suffice. */
int ms_pack_pages(ms_pack_rect *r, size_t n, double k, int size, int pad, int max_pages);

/* The largest scale at which every rectangle fits one page (bisection), packed there; -1 when none does. */
int ms_pack_one_page(ms_pack_rect *r, size_t n, int size, int pad);

#endif
