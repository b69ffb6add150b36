/* Packed charts kept from sharing footprint texels (atlas_footprints.h). Units (a region or a chart) are
 * drawn into an owner map of the pages in order, regions first; a unit whose footprint meets a texel owned
 * by another is set aside, and each one set aside is then placed at the first free place, pages in order and
 * rows top to bottom, at a whole-texel offset (its footprint's shape is then the same). */
#include "atlas_footprints.h"
#include "footprint.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct texels {
    int32_t *xy;   /* x, y pairs */
    size_t n, cap;
    int ok;
} texels;

static void add_texel(void *user, int x, int y)
{
    texels *t = user;
    if (t->n == t->cap) {
        const size_t cap = t->cap ? 2 * t->cap : 256;
        int32_t *p = realloc(t->xy, 2 * cap * sizeof *p);
        if (!p) { t->ok = 0; return; }
        t->xy = p;
        t->cap = cap;
    }
    t->xy[2 * t->n] = x;
    t->xy[2 * t->n + 1] = y;
    t->n++;
}

typedef struct sep {
    ms_fp_layout *l;
    size_t *first, *tris;   /* the chart units' triangles: tris[first[c] .. first[c + 1]) */
} sep;

static size_t n_units(const sep *s) { return s->l->nr + s->l->nu; }

static int unit_page(const sep *s, size_t u)
{
    const ms_fp_layout *l = s->l;
    if (u < l->nr) return l->rpage[u];
    const size_t c = u - l->nr;
    return s->first[c] < s->first[c + 1] ? (int)l->tpage[s->tris[s->first[c]]] : 0;
}

/* The footprint of unit u shifted by (dx, dy) texels, on a w x h grid, into out (emptied first). */
static int unit_texels(const sep *s, size_t u, double dx, double dy, int w, int h, texels *out)
{
    const ms_fp_layout *l = s->l;
    out->n = 0;
    out->ok = 1;
    if (u < l->nr) {
        const float x0 = (float)(l->rx[u] + dx), y0 = (float)(l->ry[u] + dy);
        const float x1 = (float)(l->rx[u] + l->rw[u] + dx), y1 = (float)(l->ry[u] + l->rh[u] + dy);
        const float a[6] = { x0, y0, x1, y0, x1, y1 }, b[6] = { x0, y0, x1, y1, x0, y1 };
        ms_footprint_triangle(a, MS_FOOTPRINT_REACH_PACK, w, h, add_texel, out);
        ms_footprint_triangle(b, MS_FOOTPRINT_REACH_PACK, w, h, add_texel, out);
    } else {
        const size_t c = u - l->nr;
        for (size_t i = s->first[c]; i < s->first[c + 1]; i++) {
            float q[6];
            for (int k = 0; k < 6; k++) q[k] = (float)(l->uv[6 * s->tris[i] + k] + ((k & 1) ? dy : dx));
            ms_footprint_triangle(q, MS_FOOTPRINT_REACH_PACK, w, h, add_texel, out);
        }
    }
    return out->ok ? 0 : -1;
}

/* The unit's box in texels (its UVs, or its rectangle). */
static void unit_box(const sep *s, size_t u, double lo[2], double hi[2])
{
    const ms_fp_layout *l = s->l;
    if (u < l->nr) {
        lo[0] = l->rx[u]; lo[1] = l->ry[u];
        hi[0] = l->rx[u] + l->rw[u]; hi[1] = l->ry[u] + l->rh[u];
        return;
    }
    lo[0] = lo[1] = INFINITY;
    hi[0] = hi[1] = -INFINITY;
    const size_t c = u - l->nr;
    for (size_t i = s->first[c]; i < s->first[c + 1]; i++)
        for (int k = 0; k < 6; k++) {
            const double v = l->uv[6 * s->tris[i] + k];
            lo[k & 1] = fmin(lo[k & 1], v);
            hi[k & 1] = fmax(hi[k & 1], v);
        }
}

static void move_unit(sep *s, size_t u, double dx, double dy, int page)
{
    ms_fp_layout *l = s->l;
    if (u < l->nr) {
        l->rx[u] += dx;
        l->ry[u] += dy;
        l->rpage[u] = page;
        return;
    }
    const size_t c = u - l->nr;
    for (size_t i = s->first[c]; i < s->first[c + 1]; i++) {
        float *q = l->uv + 6 * s->tris[i];
        for (int k = 0; k < 6; k++) q[k] = (float)(q[k] + ((k & 1) ? dy : dx));
        l->tpage[s->tris[i]] = (uint32_t)page;
    }
}

/* The first place (page, X, Y) where the texels t (relative, x in [0, mx], y in [0, my]) are all free. */
static int find_room(const uint32_t *owner, int pages, int size, const texels *t, int mx, int my, int *pg, int *X, int *Y)
{
    if (mx >= size || my >= size || !t->n) return 0;
    const int32_t fx = t->xy[0], fy = t->xy[1];
    for (int p = 0; p < pages; p++) {
        const uint32_t *o = owner + (size_t)p * size * size;
        for (int y = 0; y + my < size; y++)
            for (int x = 0; x + mx < size; x++) {
                if (o[(size_t)(y + fy) * size + x + fx] != UINT32_MAX) continue;
                size_t i = 1;
                while (i < t->n && o[(size_t)(y + t->xy[2 * i + 1]) * size + x + t->xy[2 * i]] == UINT32_MAX) i++;
                if (i == t->n) { *pg = p; *X = x; *Y = y; return 1; }
            }
    }
    return 0;
}

static void paint(uint32_t *o, int size, const texels *t, int X, int Y, uint32_t u)
{
    for (size_t i = 0; i < t->n; i++) o[(size_t)(t->xy[2 * i + 1] + Y) * size + t->xy[2 * i] + X] = u;
}

int ms_fp_separate(ms_fp_layout *l)
{
    const int size = l->size;
    const size_t page_texels = (size_t)size * size;
    sep s = { l, calloc(l->nu + 1, sizeof(size_t)), malloc((l->nt ? l->nt : 1) * sizeof(size_t)) };
    uint32_t *owner = malloc((size_t)(l->pages > 0 ? l->pages : 1) * page_texels * sizeof *owner);
    size_t *aside = malloc((n_units(&s) ? n_units(&s) : 1) * sizeof *aside), n_aside = 0;
    texels t = { NULL, 0, 0, 1 };
    int rc = -1, pages = l->pages > 0 ? l->pages : 1;
    l->moved = 0;
    if (!s.first || !s.tris || !owner || !aside) goto out;
    for (size_t i = 0; i < l->nt; i++) s.first[l->unit[i] + 1]++;
    for (size_t c = 0; c < l->nu; c++) s.first[c + 1] += s.first[c];
    {
        size_t *fill = malloc((l->nu ? l->nu : 1) * sizeof *fill);
        if (!fill) goto out;
        memcpy(fill, s.first, l->nu * sizeof *fill);
        for (size_t i = 0; i < l->nt; i++) s.tris[fill[l->unit[i]]++] = i;
        free(fill);
    }
    for (size_t i = 0; i < (size_t)pages * page_texels; i++) owner[i] = UINT32_MAX;
    for (size_t u = 0; u < n_units(&s); u++) {
        const int p = unit_page(&s, u);
        if (p < 0 || p >= pages) { aside[n_aside++] = u; continue; }
        if (unit_texels(&s, u, 0.0, 0.0, size, size, &t)) goto out;
        uint32_t *o = owner + (size_t)p * page_texels;
        size_t i = 0;
        while (i < t.n && (o[(size_t)t.xy[2 * i + 1] * size + t.xy[2 * i]] == UINT32_MAX ||
                           o[(size_t)t.xy[2 * i + 1] * size + t.xy[2 * i]] == (uint32_t)u)) i++;
        if (i < t.n) aside[n_aside++] = u;
        else paint(o, size, &t, 0, 0, (uint32_t)u);
    }
    for (size_t a = 0; a < n_aside; a++) {
        const size_t u = aside[a];
        double lo[2], hi[2];
        unit_box(&s, u, lo, hi);
        if (!(isfinite(lo[0]) && isfinite(lo[1]) && isfinite(hi[0]) && isfinite(hi[1]))) continue;
        /* its whole footprint with its box at (2, 2) + fraction: not clipped by the page it left */
        const double sx = 2.0 - floor(lo[0]), sy = 2.0 - floor(lo[1]);
        const int w = (int)ceil(hi[0] + sx) + 3, h = (int)ceil(hi[1] + sy) + 3;
        if (unit_texels(&s, u, sx, sy, w, h, &t)) goto out;
        int mx = 0, my = 0, mnx = w, mny = h;
        for (size_t i = 0; i < t.n; i++) {
            mx = t.xy[2 * i] > mx ? t.xy[2 * i] : mx;
            my = t.xy[2 * i + 1] > my ? t.xy[2 * i + 1] : my;
            mnx = t.xy[2 * i] < mnx ? t.xy[2 * i] : mnx;
            mny = t.xy[2 * i + 1] < mny ? t.xy[2 * i + 1] : mny;
        }
        for (size_t i = 0; i < t.n; i++) { t.xy[2 * i] -= mnx; t.xy[2 * i + 1] -= mny; }
        mx -= mnx;
        my -= mny;
        int pg = 0, X = 0, Y = 0;
        if (!find_room(owner, pages, size, &t, mx, my, &pg, &X, &Y)) {
            if (!l->add_pages || mx >= size || my >= size) { rc = 1; goto out; }
            uint32_t *grown = realloc(owner, (size_t)(pages + 1) * page_texels * sizeof *owner);
            if (!grown) goto out;
            owner = grown;
            for (size_t i = 0; i < page_texels; i++) owner[(size_t)pages * page_texels + i] = UINT32_MAX;
            pg = pages++;
        }
        paint(owner + (size_t)pg * page_texels, size, &t, X, Y, (uint32_t)u);
        move_unit(&s, u, sx - mnx + X, sy - mny + Y, pg);
        l->moved++;
    }
    l->pages = pages;
    rc = 0;
out:
    free(s.first);
    free(s.tris);
    free(owner);
    free(aside);
    free(t.xy);
    return rc;
}
