/* Shelf packing of lightmap regions onto pages (atlas_pack.h). Each region keeps one scale and one offset
 * (its charts keep their shape and their relative placement, as the file laid them out), so the packing
 * is of rectangles. First fit by decreasing height over the shelves of every open page: a short region
 * goes into the leftover width of an earlier shelf instead of opening a new one, which is what keeps the
 * pages filled when many small objects follow a few large ones. */
#include "atlas_pack.h"
#include <math.h>
#include <stdlib.h>

typedef struct shelf { double y, h, x; int page; } shelf;

static int cmp_height(const void *a, const void *b)
{
    const ms_pack_rect *const *p = a, *const *q = b;
    const double x = (*p)->h, y = (*q)->h;
    if (x != y) return (x < y) - (x > y);
    return (*p > *q) - (*p < *q);   /* stable: the input order */
}

int ms_pack_pages(ms_pack_rect *r, size_t n, double k, int size, int pad, int max_pages)
{
    ms_pack_rect **order = malloc((n ? n : 1) * sizeof *order);
    shelf *sh = malloc((n ? n : 1) * sizeof *sh);
    double *page_y = malloc((n ? n : 1) * sizeof *page_y);   /* the next free row of each page */
    int pages = 0, rc = -1;
    size_t ns = 0;
    if (!order || !sh || !page_y) goto out;
    for (size_t i = 0; i < n; i++) {
        order[i] = &r[i];
        r[i].w = r[i].fixed ? r[i].w0 : k * r[i].w0;
        r[i].h = r[i].fixed ? r[i].h0 : k * r[i].h0;
        if (r[i].w + 2 * pad > size || r[i].h + 2 * pad > size || !(r[i].w >= 0.0) || !(r[i].h >= 0.0)) goto out;
    }
    qsort(order, n, sizeof *order, cmp_height);
    for (size_t i = 0; i < n; i++) {
        ms_pack_rect *q = order[i];
        const double w = ceil(q->w), h = ceil(q->h);
        size_t s = 0;
        for (; s < ns; s++)
            if (h <= sh[s].h && sh[s].x + w + pad <= size) break;
        if (s == ns) {   /* a new shelf: on the first page with room below its last shelf, else a new page */
            int p = 0;
            for (; p < pages; p++)
                if (page_y[p] + h + pad <= size) break;
            if (p == pages) {
                if (max_pages > 0 && pages == max_pages) goto out;
                page_y[pages++] = pad;
            }
            sh[ns].y = page_y[p];
            sh[ns].h = h;
            sh[ns].x = pad;
            sh[ns].page = p;
            page_y[p] += h + pad;
            ns++;
        }
        q->x = sh[s].x;
        q->y = sh[s].y;
        q->page = sh[s].page;
        sh[s].x += w + pad;
    }
    rc = pages;
out:
    free(order);
    free(sh);
    free(page_y);
    return rc;
}

int ms_pack_one_page(ms_pack_rect *r, size_t n, int size, int pad)
{
    double lo = 0.0, hi = 0.0;
    for (size_t i = 0; i < n; i++)
        if (!r[i].fixed) hi = fmax(hi, fmax(r[i].w0, r[i].h0));
    if (!(hi > 0.0)) return ms_pack_pages(r, n, 1.0, size, pad, 1) == 1 || n == 0 ? 0 : -1;
    hi = size / hi;
    for (int it = 0; it < 50; it++) {
        const double mid = 0.5 * (lo + hi);
        if (ms_pack_pages(r, n, mid, size, pad, 1) >= 0) lo = mid;
        else hi = mid;
    }
    return lo > 0.0 && ms_pack_pages(r, n, lo, size, pad, 1) >= 0 ? 0 : -1;
}
