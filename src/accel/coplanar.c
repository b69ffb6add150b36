/* Axis-aligned coplanar rectangles merged (coplanar.h). */
#include "coplanar.h"
#include <stdlib.h>
#include <string.h>

static uint32_t fbits(float f)
{
    f += 0.0f;   /* -0 and +0 are one coordinate */
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

/* A rectangle in the plane x_a = c: [u0, u1] x [v0, v1] over axes u = a+1, v = a+2 (mod 3). */
typedef struct rect {
    int a;
    float c, u0, u1, v0, v1;
    uint32_t tri;    /* an input triangle of it */
    uint32_t mc;     /* a half: the corner it leaves out (bit 0: u1, bit 1: v1); rectangles: unused */
} rect;

static int cmp_f(float x, float y) { return x < y ? -1 : x > y; }

/* Plane, then the rectangle's extent, then (halves) the left-out corner. */
static int cmp_half(const void *p, const void *q)
{
    const rect *x = p, *y = q;
    if (x->a != y->a) return x->a - y->a;
    int r;
    if ((r = cmp_f(x->c, y->c)) || (r = cmp_f(x->v0, y->v0)) || (r = cmp_f(x->v1, y->v1)) || (r = cmp_f(x->u0, y->u0)) ||
        (r = cmp_f(x->u1, y->u1)))
        return r;
    return (int)x->mc - (int)y->mc;
}

/* Runs along u: plane, v extent, then u0. */
static int cmp_rows(const void *p, const void *q)
{
    const rect *x = p, *y = q;
    if (x->a != y->a) return x->a - y->a;
    int r;
    if ((r = cmp_f(x->c, y->c)) || (r = cmp_f(x->v0, y->v0)) || (r = cmp_f(x->v1, y->v1))) return r;
    return cmp_f(x->u0, y->u0);
}

/* Runs along v: plane, u extent, then v0. */
static int cmp_cols(const void *p, const void *q)
{
    const rect *x = p, *y = q;
    if (x->a != y->a) return x->a - y->a;
    int r;
    if ((r = cmp_f(x->c, y->c)) || (r = cmp_f(x->u0, y->u0)) || (r = cmp_f(x->u1, y->u1))) return r;
    return cmp_f(x->v0, y->v0);
}

static int same_rect(const rect *x, const rect *y)
{
    return x->a == y->a && fbits(x->c) == fbits(y->c) && fbits(x->u0) == fbits(y->u0) && fbits(x->u1) == fbits(y->u1) &&
           fbits(x->v0) == fbits(y->v0) && fbits(x->v1) == fbits(y->v1);
}

/* Triangle t as half of an axis-aligned rectangle: 1 and h filled, else 0. */
static int as_half(const float *t, rect *h)
{
    int axis = -1;
    for (int a = 0; a < 3; a++)
        if (fbits(t[a]) == fbits(t[3 + a]) && fbits(t[a]) == fbits(t[6 + a])) {
            if (axis >= 0) return 0;   /* on a line: degenerate */
            axis = a;
        }
    if (axis < 0) return 0;
    const int au = (axis + 1) % 3, av = (axis + 2) % 3;
    float u[3], v[3];
    for (int k = 0; k < 3; k++) { u[k] = t[3 * k + au]; v[k] = t[3 * k + av]; }
    /* exactly two distinct values on each axis */
    float ulo = u[0], uhi = u[0], vlo = v[0], vhi = v[0];
    for (int k = 1; k < 3; k++) {
        if (u[k] < ulo) ulo = u[k];
        if (u[k] > uhi) uhi = u[k];
        if (v[k] < vlo) vlo = v[k];
        if (v[k] > vhi) vhi = v[k];
    }
    if (!(ulo < uhi && vlo < vhi)) return 0;
    unsigned seen = 0;
    for (int k = 0; k < 3; k++) {
        const int iu = fbits(u[k]) == fbits(uhi) ? 1 : fbits(u[k]) == fbits(ulo) ? 0 : -1;
        const int iv = fbits(v[k]) == fbits(vhi) ? 1 : fbits(v[k]) == fbits(vlo) ? 0 : -1;
        if (iu < 0 || iv < 0) return 0;
        seen |= 1u << (iu | iv << 1);
    }
    if (__builtin_popcount(seen) != 3) return 0;
    h->a = axis;
    h->c = t[axis] + 0.0f;
    h->u0 = ulo; h->u1 = uhi; h->v0 = vlo; h->v1 = vhi;
    h->mc = (uint32_t)__builtin_ctz(~seen & 0xFu);
    return 1;
}

/* Merges sorted runs of rects (by cmp) whose extents continue each other along u (along_u) or v, but not
 * along the world axis no_axis (-1: any); writes the merged ones back into r, map[i] = the merged index of
 * r's old i; returns their number and adds to *axes the world axes along which two or more were merged. */
static size_t merge_runs(rect *r, size_t n, int along_u, int no_axis, unsigned *axes, uint32_t *map, uint32_t *order)
{
    /* order: the original index of each sorted position (r is sorted together with it by the caller) */
    size_t m = 0;
    for (size_t i = 0; i < n;) {
        rect cur = r[i];
        map[order[i]] = (uint32_t)m;
        const int axis = (cur.a + (along_u ? 1 : 2)) % 3;
        size_t j = i + 1;
        for (; j < n && axis != no_axis; j++) {
            const rect *x = &r[j];
            const int same = x->a == cur.a && fbits(x->c) == fbits(cur.c) &&
                             (along_u ? fbits(x->v0) == fbits(cur.v0) && fbits(x->v1) == fbits(cur.v1) && fbits(x->u0) == fbits(cur.u1)
                                      : fbits(x->u0) == fbits(cur.u0) && fbits(x->u1) == fbits(cur.u1) && fbits(x->v0) == fbits(cur.v1));
            if (!same) break;
            if (along_u) cur.u1 = x->u1;
            else cur.v1 = x->v1;
            map[order[j]] = (uint32_t)m;
        }
        if (j > i + 1) *axes |= 1u << axis;
        r[m++] = cur;
        i = j;
    }
    return m;
}

/* Sorts r[0..n) by cmp carrying order along (both permuted alike). */
static int sort_with(rect *r, uint32_t *order, size_t n, int (*cmp)(const void *, const void *))
{
    typedef struct { rect r; uint32_t o; } pair;
    pair *p = malloc((n ? n : 1) * sizeof *p);
    if (!p) return -1;
    for (size_t i = 0; i < n; i++) { p[i].r = r[i]; p[i].o = order[i]; }
    qsort(p, n, sizeof *p, cmp);   /* rect is pair's first member: cmp reads it */
    for (size_t i = 0; i < n; i++) { r[i] = p[i].r; order[i] = p[i].o; }
    free(p);
    return 0;
}

static void emit(const rect *r, float *out)
{
    const int au = (r->a + 1) % 3, av = (r->a + 2) % 3;
    const float cu[4] = { r->u0, r->u1, r->u1, r->u0 }, cv[4] = { r->v0, r->v0, r->v1, r->v1 };
    static const int tv[2][3] = { { 0, 1, 2 }, { 0, 2, 3 } };
    for (int t = 0; t < 2; t++)
        for (int k = 0; k < 3; k++) {
            float *p = out + 9 * t + 3 * k;
            p[r->a] = r->c;
            p[au] = cu[tv[t][k]];
            p[av] = cv[tv[t][k]];
        }
}

int ms_coplanar_rect_pair(const float *a, const float *b, float corners[12])
{
    rect x, y;
    if (!as_half(a, &x) || !as_half(b, &y) || !same_rect(&x, &y) || (x.mc ^ y.mc) != 3u) return 0;
    float t[18];   /* emit's two triangles: corners 0 1 2 and 0 2 3, i.e. (u0 v0) (u1 v0) (u1 v1) (u0 v1) */
    emit(&x, t);
    static const int at[4] = { 0, 3, 6, 15 }, of_mc[4] = { 0, 1, 3, 2 };   /* a corner in t; mc's corner */
    const int m = of_mc[x.mc];   /* the corner a leaves out: the last */
    for (int i = 0; i < 4; i++) memcpy(corners + 3 * i, t + at[(m + 1 + i) % 4], 3 * sizeof *t);
    return 1;
}

int ms_coplanar_merge(const float *tri, size_t n, const uint8_t *eligible, int no_axis, float **out, size_t *n_out,
                      uint32_t **of_input, uint32_t **source, uint8_t **merged, unsigned *merged_axes)
{
    *merged_axes = 0;
    *out = NULL;
    *of_input = *source = NULL;
    *merged = NULL;
    *n_out = 0;
    rect *h = malloc((n ? n : 1) * sizeof *h);
    uint32_t *rect_of = malloc((n ? n : 1) * sizeof *rect_of);   /* per input triangle: its rectangle, or UINT32_MAX */
    uint32_t *order = malloc((n ? n : 1) * sizeof *order), *map = malloc((n ? n : 1) * sizeof *map);
    rect *r = malloc((n ? n : 1) * sizeof *r);
    uint32_t *r_tri = malloc((n ? n : 1) * 2 * sizeof *r_tri);   /* per rectangle: its two halves */
    int rc = -1;
    if (!h || !rect_of || !order || !map || !r || !r_tri) goto done;
    size_t nh = 0;
    for (size_t t = 0; t < n; t++) {
        rect_of[t] = UINT32_MAX;
        if ((!eligible || eligible[t]) && as_half(tri + 9 * t, &h[nh])) h[nh++].tri = (uint32_t)t;
    }
    qsort(h, nh, sizeof *h, cmp_half);
    /* Pair the halves of one rectangle (left-out corners mc and mc ^ 3): within a run of equal rectangles,
     * the sort puts corner 0 before 3 and 1 before 2; pair what matches, leave the rest. */
    size_t nr = 0;
    for (size_t i = 0; i < nh;) {
        size_t j = i + 1;
        while (j < nh && same_rect(&h[i], &h[j])) j++;
        uint32_t by_mc[4] = { UINT32_MAX, UINT32_MAX, UINT32_MAX, UINT32_MAX };
        for (size_t k = i; k < j; k++)
            if (by_mc[h[k].mc] == UINT32_MAX) by_mc[h[k].mc] = (uint32_t)k;
        for (uint32_t mc = 0; mc < 2; mc++) {
            const uint32_t x = by_mc[mc], y = by_mc[mc ^ 3u];
            if (x == UINT32_MAX || y == UINT32_MAX) continue;
            r[nr] = h[x];
            r_tri[2 * nr] = h[x].tri;
            r_tri[2 * nr + 1] = h[y].tri;
            nr++;
            break;   /* one rectangle per run: a second pair would cover it twice */
        }
        i = j;
    }
    /* Merge rows along u, then columns along v; final[i]: the merged rectangle of rectangle i. */
    uint32_t *final = malloc((nr ? nr : 1) * sizeof *final);
    if (!final) goto done;
    for (size_t i = 0; i < nr; i++) order[i] = (uint32_t)i;
    if (sort_with(r, order, nr, cmp_rows)) { free(final); goto done; }
    size_t m1 = merge_runs(r, nr, 1, no_axis, merged_axes, final, order);
    for (size_t i = 0; i < m1; i++) order[i] = (uint32_t)i;
    if (sort_with(r, order, m1, cmp_cols)) { free(final); goto done; }
    const size_t m2 = merge_runs(r, m1, 0, no_axis, merged_axes, map, order);
    for (size_t i = 0; i < nr; i++) final[i] = map[final[i]];
    /* A rectangle of one pair stays as its two triangles (its diagonal may not be the one emit draws):
     * only rectangles merged from two or more pairs change anything. pos: a merged rectangle's output. */
    uint32_t *pairs = calloc(m2 ? m2 : 1, sizeof *pairs), *pos = malloc((m2 ? m2 : 1) * sizeof *pos);
    if (!pairs || !pos) { free(pairs); free(pos); free(final); goto done; }
    for (size_t i = 0; i < nr; i++) pairs[final[i]]++;
    size_t nm = 0;
    for (size_t i = 0; i < m2; i++) pos[i] = pairs[i] > 1 ? (uint32_t)nm++ : UINT32_MAX;
    for (size_t i = 0; i < nr; i++)
        if (pairs[final[i]] > 1) rect_of[r_tri[2 * i]] = rect_of[r_tri[2 * i + 1]] = pos[final[i]];
    /* Output: the merged rectangles first (two triangles each), then every triangle left alone. */
    size_t left = 0;
    for (size_t t = 0; t < n; t++) left += rect_of[t] == UINT32_MAX;
    const size_t no = 2 * nm + left;
    *out = malloc((no ? no : 1) * 9 * sizeof **out);
    *of_input = malloc((n ? n : 1) * sizeof **of_input);
    *source = malloc((no ? no : 1) * sizeof **source);
    *merged = calloc(n ? n : 1, 1);
    if (!*out || !*of_input || !*source || !*merged) { free(pairs); free(pos); free(final); goto done; }
    for (size_t i = 0; i < m2; i++)
        if (pos[i] != UINT32_MAX) emit(&r[i], *out + 18 * (size_t)pos[i]);
    free(pairs);
    free(pos);
    size_t w = 2 * nm;
    for (size_t t = 0; t < n; t++) {
        if (rect_of[t] != UINT32_MAX) {
            const uint32_t o = 2 * rect_of[t];
            (*of_input)[t] = o;
            (*source)[o] = (*source)[o + 1] = (uint32_t)t;
            (*merged)[t] = 1;
            continue;
        }
        memcpy(*out + 9 * w, tri + 9 * t, 9 * sizeof **out);
        (*of_input)[t] = (uint32_t)w;
        (*source)[w++] = (uint32_t)t;
    }
    *n_out = no;
    free(final);
    rc = 0;
done:
    free(h);
    free(rect_of);
    free(order);
    free(map);
    free(r);
    free(r_tri);
    if (rc) {
        free(*out);
        free(*of_input);
        free(*source);
        free(*merged);
        *out = NULL;
        *of_input = *source = NULL;
        *merged = NULL;
    }
    return rc;
}
