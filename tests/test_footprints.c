/* Bilinear footprints (src/render/footprint.c) and the packer's pass that keeps them apart
 * (src/render/atlas_footprints.c), against oracles written here:
 *   - ms_footprint_triangle on random triangles equals the texels whose square of half-side `reach` meets the
 *     triangle, found by clipping the triangle to the square (Sutherland-Hodgman), not by separating axes;
 *   - ms_footprint_owners joins triangles that share a UV vertex and keeps apart charts whose footprints touch
 *     without sharing a texel;
 *   - ms_fp_separate, given charts and a region stacked on each other, moves them by whole texels until no
 *     two footprints share a texel (each chart's shape and fractional place kept), adds a page only when
 *     allowed, and reports a layout that cannot fit. */
#include "testutil.h"
#include "render/footprint.h"
#include "render/atlas_footprints.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The polygon p (n points) clipped to the half-plane s * (coordinate d) <= c. Returns the new count. */
static int clip(double p[][2], int n, int d, double s, double c)
{
    double q[16][2];
    int m = 0;
    for (int i = 0; i < n; i++) {
        const double *a = p[i], *b = p[(i + 1) % n];
        const double fa = s * a[d] - c, fb = s * b[d] - c;
        if (fa <= 0) { q[m][0] = a[0]; q[m][1] = a[1]; m++; }
        if ((fa < 0 && fb > 0) || (fa > 0 && fb < 0)) {
            const double t = fa / (fa - fb);
            q[m][0] = a[0] + t * (b[0] - a[0]);
            q[m][1] = a[1] + t * (b[1] - a[1]);
            m++;
        }
    }
    memcpy(p, q, (size_t)m * sizeof q[0]);
    return m;
}

/* 1 if the triangle u (texels) keeps a point inside the square of half-side r about (cx, cy). */
static int square_clip_meets(const float u[6], double cx, double cy, double r)
{
    double p[16][2];
    for (int k = 0; k < 3; k++) { p[k][0] = u[2 * k]; p[k][1] = u[2 * k + 1]; }
    int n = 3;
    n = clip(p, n, 0, 1.0, cx + r);
    n = clip(p, n, 0, -1.0, -(cx - r));
    n = clip(p, n, 1, 1.0, cy + r);
    n = clip(p, n, 1, -1.0, -(cy - r));
    return n > 0;
}

static double uniform(tu_rng *r) { return (double)(tu_rng_next(r) >> 11) * 0x1p-53; }

typedef struct grid { int w, h; unsigned char *on; long count; } grid;

static void mark(void *user, int x, int y)
{
    grid *g = user;
    assert_true(x >= 0 && y >= 0 && x < g->w && y < g->h);
    g->on[(size_t)y * g->w + x]++;
    g->count++;
}

static void test_triangle_footprint(void **st)
{
    (void)st;
    tu_rng rng = { 7 };
    grid g = { 24, 24, malloc(24 * 24), 0 };
    assert_non_null(g.on);
    long texels = 0;
    for (int it = 0; it < 400; it++) {
        float u[6];
        const double scale = it % 4 == 0 ? 0.6 : it % 4 == 1 ? 3.0 : 12.0;   /* slivers to a dozen texels */
        const double ox = 3 + 18 * uniform(&rng), oy = 3 + 18 * uniform(&rng);
        for (int k = 0; k < 3; k++) {
            u[2 * k] = (float)(ox + scale * (uniform(&rng) - 0.5));
            u[2 * k + 1] = (float)(oy + scale * (uniform(&rng) - 0.5));
        }
        memset(g.on, 0, 24 * 24);
        const double reach = it & 1 ? MS_FOOTPRINT_REACH_BAKE : MS_FOOTPRINT_REACH_PACK;
        ms_footprint_triangle(u, reach, g.w, g.h, mark, &g);
        for (int y = 0; y < g.h; y++)
            for (int x = 0; x < g.w; x++) {
                const int want = square_clip_meets(u, x + 0.5, y + 0.5, reach);
                assert_int_equal(g.on[(size_t)y * g.w + x], want);   /* each texel once */
                texels += want;
            }
    }
    printf("400 random triangles: %ld footprint texels, each as the clipping oracle says\n", texels);
    assert_true(texels > 4000);
    /* a triangle without area has none */
    const float flat[6] = { 5, 5, 8, 8, 11, 11 };
    g.count = 0;
    ms_footprint_triangle(flat, 1.0, g.w, g.h, mark, &g);
    assert_int_equal(g.count, 0);
    free(g.on);
}

/* UVs of a page of side 16 for three charts: A (two triangles sharing a vertex only), B touching A's footprint
 * without sharing a texel, C far away. */
static void test_owners(void **st)
{
    (void)st;
    const int S = 16;
    /* in texels; A: x 2.5..4.5 (its footprint: texels up to 4, texel 5's centre being 1 away), B from x 6 (its
     * footprint from texel 5): the two footprints touch */
    const float tex[4][6] = {
        { 2.5f, 2.5f, 4.5f, 2.5f, 2.5f, 4.5f },      /* A */
        { 2.5f, 4.5f, 4.5f, 6.5f, 2.5f, 6.5f },      /* A, sharing the vertex (2.5, 4.5) */
        { 6.0f, 2.5f, 8.0f, 2.5f, 6.0f, 4.5f },      /* B */
        { 12.5f, 12.5f, 14.5f, 12.5f, 12.5f, 14.5f } /* C */
    };
    float uv[24];
    for (int i = 0; i < 24; i++) uv[i] = tex[i / 6][i % 6] / (float)S;
    uint32_t *owner = malloc((size_t)S * S * sizeof *owner);
    assert_non_null(owner);
    assert_int_equal(ms_footprint_owners(uv, NULL, 4, S, 1, owner), 0);
    const uint32_t a = owner[3 * S + 3], a2 = owner[5 * S + 3], b = owner[3 * S + 7], c = owner[13 * S + 13];
    assert_int_equal(a, a2);
    assert_true(a != UINT32_MAX && b != UINT32_MAX && c != UINT32_MAX);
    assert_true(a != b && a != c && b != c);
    assert_int_equal(owner[3 * S + 4], a);
    assert_int_equal(owner[3 * S + 5], b);
    assert_int_equal(owner[10 * S + 10], UINT32_MAX);
    /* moved 0.75 texel closer, B's footprint takes texel 4, which A's holds: one owner */
    for (int k = 0; k < 6; k += 2) uv[12 + k] = (tex[2][k] - 0.75f) / (float)S;
    assert_int_equal(ms_footprint_owners(uv, NULL, 4, S, 1, owner), 0);
    assert_int_equal(owner[3 * S + 3], owner[3 * S + 7]);
    free(owner);
}

typedef struct fp_set { int size, pages; int *owner; long shared; } fp_set;
typedef struct fp_paint { fp_set *s; int unit, page; } fp_paint;

static void paint_unit(void *user, int x, int y)
{
    fp_paint *p = user;
    int *o = p->s->owner + ((size_t)p->page * p->s->size + y) * p->s->size + x;
    if (*o >= 0 && *o != p->unit) p->s->shared++;
    *o = p->unit;
}

/* Texels in two units' footprints (found here with the bake's reach), over l's pages. */
static long shared_texels(const ms_fp_layout *l)
{
    fp_set s = { l->size, l->pages, malloc((size_t)l->pages * l->size * l->size * sizeof(int)), 0 };
    assert_non_null(s.owner);
    for (size_t i = 0; i < (size_t)l->pages * l->size * l->size; i++) s.owner[i] = -1;
    for (size_t r = 0; r < l->nr; r++) {
        const float x0 = (float)l->rx[r], y0 = (float)l->ry[r], x1 = (float)(l->rx[r] + l->rw[r]), y1 = (float)(l->ry[r] + l->rh[r]);
        const float a[6] = { x0, y0, x1, y0, x1, y1 }, b[6] = { x0, y0, x1, y1, x0, y1 };
        fp_paint p = { &s, (int)r, l->rpage[r] };
        ms_footprint_triangle(a, MS_FOOTPRINT_REACH_BAKE, l->size, l->size, paint_unit, &p);
        ms_footprint_triangle(b, MS_FOOTPRINT_REACH_BAKE, l->size, l->size, paint_unit, &p);
    }
    for (size_t t = 0; t < l->nt; t++) {
        fp_paint p = { &s, (int)(l->nr + l->unit[t]), (int)l->tpage[t] };
        ms_footprint_triangle(l->uv + 6 * t, MS_FOOTPRINT_REACH_BAKE, l->size, l->size, paint_unit, &p);
    }
    free(s.owner);
    return s.shared;
}

static void test_separate(void **st)
{
    (void)st;
    /* a 6 x 4 region and three charts (a quad of two triangles, two single triangles) all stacked at the
     * page's corner, the charts at fractional places */
    const int S = 24;
    double rx[1] = { 1 }, ry[1] = { 1 }, rw[1] = { 6 }, rh[1] = { 4 };
    int rpage[1] = { 0 };
    const float uv0[4][6] = {
        { 1.3f, 1.2f, 5.3f, 1.2f, 5.3f, 4.7f }, { 1.3f, 1.2f, 5.3f, 4.7f, 1.3f, 4.7f },
        { 2.1f, 1.6f, 9.4f, 2.2f, 2.6f, 3.9f }, { 1.75f, 1.5f, 3.25f, 1.5f, 1.75f, 2.5f } };
    float uv[24];
    memcpy(uv, uv0, sizeof uv);
    uint32_t tpage[4] = { 0, 0, 0, 0 };
    const uint32_t unit[4] = { 0, 0, 1, 2 };
    ms_fp_layout l = { S, 1, 0, 1, rx, ry, rw, rh, rpage, 4, 3, uv, tpage, unit, 0 };
    assert_true(shared_texels(&l) > 0);
    assert_int_equal(ms_fp_separate(&l), 0);
    printf("separate: %zu of 4 units moved, %ld texels shared after\n", l.moved, shared_texels(&l));
    assert_int_equal(l.pages, 1);
    assert_int_equal(l.moved, 3);   /* the region stays; every chart met it */
    assert_int_equal(shared_texels(&l), 0);
    assert_true(rx[0] == 1 && ry[0] == 1);
    for (int t = 0; t < 4; t++)   /* every vertex of a chart moved by the same whole number of texels */
        for (int k = 0; k < 6; k++) {
            const float d = uv[6 * t + k] - uv0[t][k], d0 = uv[6 * t + (k & 1)] - uv0[t][k & 1];
            assert_true(d == floorf(d) && d == d0);
            assert_true(uv[6 * t + k] >= 0.0f && uv[6 * t + k] <= (float)S);
        }
    assert_true(uv[0] == uv[6] && uv[1] == uv[7]);   /* the quad's shared vertex still shared */
    /* on a page too small for all of them: not placed (one page), or a second page (allowed) */
    memcpy(uv, uv0, sizeof uv);
    rx[0] = ry[0] = 1;
    ms_fp_layout small = { 12, 1, 0, 1, rx, ry, rw, rh, rpage, 4, 3, uv, tpage, unit, 0 };
    assert_int_equal(ms_fp_separate(&small), 1);
    memcpy(uv, uv0, sizeof uv);
    memset(tpage, 0, sizeof tpage);
    rx[0] = ry[0] = 1;
    small.add_pages = 1;
    small.pages = 1;
    assert_int_equal(ms_fp_separate(&small), 0);
    printf("on a 12 x 12 page: %d pages, %zu moved\n", small.pages, small.moved);
    assert_true(small.pages >= 2);
    assert_int_equal(shared_texels(&small), 0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_triangle_footprint),
        cmocka_unit_test(test_owners),
        cmocka_unit_test(test_separate),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
