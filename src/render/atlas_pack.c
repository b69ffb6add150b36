/* Packing of lightmap regions onto pages (atlas_pack.h). Each region keeps one scale and one offset (its
 * charts keep their shape and their relative placement, as the file laid them out), so the packing is of
 * rectangles, unrotated. MaxRects with the best-short-side-fit rule (Jylänki, "A Thousand Ways to Pack the
 * Bin", 2010): every page keeps the maximal free rectangles, a region goes where it leaves the least slack
 * on its shorter side, over every open page, largest first; shelves leave the width beside a tall region
 * empty (docs/notebook/2026-11-29-lightmap-charts.md). */
#include "atlas_pack.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct frect { double x, y, w, h; int page; } frect;

typedef struct freelist { frect *r; size_t n, cap; } freelist;

static int fl_push(freelist *f, frect r)
{
    if (f->n == f->cap) {
        const size_t cap = f->cap ? 2 * f->cap : 64;
        frect *g = realloc(f->r, cap * sizeof *g);
        if (!g) return -1;
        f->r = g;
        f->cap = cap;
    }
    f->r[f->n++] = r;
    return 0;
}

static int cmp_area(const void *a, const void *b)
{
    const ms_pack_rect *const *p = a, *const *q = b;
    const double x = fmax((*p)->w, (*p)->h) * 1e6 + (*p)->w * (*p)->h, y = fmax((*q)->w, (*q)->h) * 1e6 + (*q)->w * (*q)->h;
    if (x != y) return (x < y) - (x > y);
    return (*p > *q) - (*p < *q);   /* stable: the input order */
}

/* Splits the free rectangles that the placed u overlaps into the parts around it, then drops the free
 * rectangles that another contains. */
static int place(freelist *f, frect u)
{
    const size_t n = f->n;
    for (size_t i = 0; i < n; i++) {
        frect r = f->r[i];
        if (r.page != u.page || u.x >= r.x + r.w || u.x + u.w <= r.x || u.y >= r.y + r.h || u.y + u.h <= r.y) continue;
        f->r[i].w = -1.0;   /* removed below */
        const frect parts[4] = {
            { r.x, r.y, u.x - r.x, r.h, r.page }, { u.x + u.w, r.y, r.x + r.w - (u.x + u.w), r.h, r.page },
            { r.x, r.y, r.w, u.y - r.y, r.page }, { r.x, u.y + u.h, r.w, r.y + r.h - (u.y + u.h), r.page } };
        for (int k = 0; k < 4; k++)
            if (parts[k].w > 0.0 && parts[k].h > 0.0 && fl_push(f, parts[k])) return -1;
    }
    size_t m = 0;
    for (size_t i = 0; i < f->n; i++)
        if (f->r[i].w > 0.0) f->r[m++] = f->r[i];
    f->n = m;
    for (size_t i = 0; i < f->n; i++) {
        const frect *a = &f->r[i];
        if (a->w < 0.0) continue;
        for (size_t j = 0; j < f->n; j++) {
            const frect *b = &f->r[j];
            if (i == j || b->w < 0.0 || a->page != b->page) continue;
            if (a->x >= b->x && a->y >= b->y && a->x + a->w <= b->x + b->w && a->y + a->h <= b->y + b->h &&
                (a->x != b->x || a->y != b->y || a->w != b->w || a->h != b->h || i > j)) {
                f->r[i].w = -1.0;
                break;
            }
        }
    }
    m = 0;
    for (size_t i = 0; i < f->n; i++)
        if (f->r[i].w > 0.0) f->r[m++] = f->r[i];
    f->n = m;
    return 0;
}

int ms_pack_pages(ms_pack_rect *r, size_t n, double k, int size, int pad, int max_pages)
{
    ms_pack_rect **order = malloc((n ? n : 1) * sizeof *order);
    freelist f = { NULL, 0, 0 };
    int pages = 0, rc = -1;
    if (!order) goto out;
    for (size_t i = 0; i < n; i++) {
        order[i] = &r[i];
        r[i].w = k * r[i].w0;
        r[i].h = k * r[i].h0;
        if (r[i].w + 2 * pad > size || r[i].h + 2 * pad > size || !(r[i].w >= 0.0) || !(r[i].h >= 0.0)) goto out;
    }
    qsort(order, n, sizeof *order, cmp_area);
    /* a page's free space starts at (pad, pad); each region takes its texels plus pad to its right and below */
    for (size_t i = 0; i < n; i++) {
        ms_pack_rect *q = order[i];
        const double w = ceil(q->w) + pad, h = ceil(q->h) + pad;
        for (int attempt = 0; attempt < 2; attempt++) {
            double best = INFINITY, best_long = INFINITY;
            size_t at = SIZE_MAX;
            for (size_t j = 0; j < f.n; j++) {
                const frect *fr = &f.r[j];
                if (w > fr->w || h > fr->h) continue;
                const double ss = fmin(fr->w - w, fr->h - h), ls = fmax(fr->w - w, fr->h - h);
                if (ss < best || (ss == best && (ls < best_long || (ls == best_long && fr->page < f.r[at].page)))) {
                    best = ss;
                    best_long = ls;
                    at = j;
                }
            }
            if (at != SIZE_MAX) {
                const frect u = { f.r[at].x, f.r[at].y, w, h, f.r[at].page };
                q->x = u.x;
                q->y = u.y;
                q->page = u.page;
                if (place(&f, u)) goto out;
                break;
            }
            if (attempt || (max_pages > 0 && pages == max_pages)) goto out;
            const frect page = { pad, pad, size - pad, size - pad, pages++ };
            if (fl_push(&f, page)) goto out;
        }
    }
    rc = pages;
out:
    free(order);
    free(f.r);
    return rc;
}

int ms_pack_one_page(ms_pack_rect *r, size_t n, int size, int pad)
{
    double lo = 0.0, hi = 0.0;
    for (size_t i = 0; i < n; i++) hi = fmax(hi, fmax(r[i].w0, r[i].h0));
    if (!(hi > 0.0)) return ms_pack_pages(r, n, 1.0, size, pad, 1) == 1 || n == 0 ? 0 : -1;
    hi = size / hi;
    for (int it = 0; it < 50; it++) {
        const double mid = 0.5 * (lo + hi);
        if (ms_pack_pages(r, n, mid, size, pad, 1) >= 0) lo = mid;
        else hi = mid;
    }
    return lo > 0.0 && ms_pack_pages(r, n, lo, size, pad, 1) >= 0 ? 0 : -1;
}
