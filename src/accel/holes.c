/* Holed surfaces capped for the interior boxes (holes.h, docs/culling.md "Holes"). */
#include "holes.h"
#include "core/union_find.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The holed sets' rim edges: their welded end vertices and a corner at each end (for its position), their set. */
typedef struct rim_edge { uint32_t v[2], corner[2], set; } rim_edge;
/* An end of a rim edge, sorted by vertex: a vertex's edges are a run. */
typedef struct rim_end { uint32_t v, edge; } rim_end;

static int end_cmp(const void *a, const void *b)
{
    const rim_end *x = a, *y = b;
    return x->v != y->v ? (x->v > y->v) - (x->v < y->v) : (x->edge > y->edge) - (x->edge < y->edge);
}

static void grow_box(float b[6], const float *p)
{
    for (int a = 0; a < 3; a++) {
        if (p[a] < b[a]) b[a] = p[a];
        if (p[a] > b[3 + a]) b[3 + a] = p[a];
    }
}

/* The first end of vertex v in ends[0..n) (sorted), or n. */
static size_t first_end(const rim_end *ends, size_t n, uint32_t v)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        const size_t mid = (lo + hi) / 2;
        if (ends[mid].v < v) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* The closed walks of set h's rim edges (e[first..m) holds them, those of a set contiguous), each capped by a fan
 * from its centroid into out->cap from slot *nc on. The walk from a vertex takes any unused edge of the set at
 * each vertex it reaches; with an even number of the set's rim edges at every vertex it can only stop where it
 * started (-2 if it does not: the caller then caps nothing). */
static int cap_walks(const float *tri, const rim_edge *e, size_t m, const rim_end *ends, uint8_t *used, size_t first,
                     uint32_t h, size_t *nc, size_t *cap_cap, ms_closed *out)
{
    uint32_t *walk = NULL;   /* the corners of the walk's vertices */
    size_t walk_cap = 0;
    for (size_t e0 = first; e0 < m && e[e0].set == h; e0++) {
        if (used[e0]) continue;
        size_t len = 0, cur = e0;
        int end = 0;   /* the walk leaves edge cur from its end `end` */
        const uint32_t v0 = e[e0].v[0];
        for (;;) {
            if (len == walk_cap) {
                walk_cap = walk_cap ? 2 * walk_cap : 64;
                uint32_t *w = realloc(walk, walk_cap * sizeof *walk);
                if (!w) { free(walk); return -1; }
                walk = w;
            }
            walk[len++] = e[cur].corner[end];
            used[cur] = 1;
            const uint32_t v = e[cur].v[1 - end];
            if (v == v0) break;
            size_t next = m;
            for (size_t i = first_end(ends, 2 * m, v); i < 2 * m && ends[i].v == v && next == m; i++)
                if (!used[ends[i].edge] && e[ends[i].edge].set == h) next = ends[i].edge;
            if (next == m) { free(walk); return -2; }
            end = e[next].v[0] == v ? 0 : 1;
            cur = next;
        }
        double c[3] = { 0.0, 0.0, 0.0 };
        for (size_t i = 0; i < len; i++)
            for (int a = 0; a < 3; a++) c[a] += (double)tri[3 * (size_t)walk[i] + (size_t)a];
        float cf[3];
        for (int a = 0; a < 3; a++) cf[a] = (float)(c[a] / (double)len);
        if (*nc + len > *cap_cap) {
            size_t mm = *cap_cap ? 2 * *cap_cap : 256;
            while (mm < *nc + len) mm *= 2;
            float *p = realloc(out->cap, mm * 9 * sizeof *p);
            if (!p) { free(walk); return -1; }
            out->cap = p;
            *cap_cap = mm;
        }
        for (size_t i = 0; i < len; i++) {
            float *t = out->cap + 9 * (*nc)++;
            memcpy(t, cf, sizeof cf);
            memcpy(t + 3, tri + 3 * (size_t)walk[i], 3 * sizeof(float));
            memcpy(t + 6, tri + 3 * (size_t)walk[(i + 1) % len], 3 * sizeof(float));
        }
        grow_box(out->holed_box[h], cf);
    }
    free(walk);
    return 0;
}

static void holes_free(ms_closed *out)
{
    free(out->holed);
    free(out->holed_box);
    free(out->cap);
    free(out->cap_start);
    out->holed = NULL;
    out->holed_box = NULL;
    out->cap = NULL;
    out->cap_start = NULL;
    out->n_holed = 0;
}

int ms_holes_cap(const float *tri, size_t n, const uint32_t *id, const uint32_t *rim, size_t n_rim, uint32_t *parent,
                 ms_closed *out)
{
    out->n_holed = 0;
    if (!n_rim) return 0;
    uint32_t *size = calloc(n, sizeof *size), *rims = calloc(n, sizeof *rims), *set_of_root = malloc(n * sizeof *set_of_root);
    rim_edge *e = NULL;
    rim_end *ends = NULL;
    uint8_t *used = NULL;
    int rc = -1;
    if (!size || !rims || !set_of_root) goto done;
    for (size_t t = 0; t < n; t++) size[ms_uf_find(parent, (uint32_t)t)]++;
    for (size_t i = 0; i < n_rim; i++) rims[ms_uf_find(parent, rim[i] / 3)]++;
    /* Sets numbered in the order of their roots, the smallest members: the same numbering whatever the threads. */
    size_t nh = 0, m = 0;
    for (size_t t = 0; t < n; t++) {
        set_of_root[t] = UINT32_MAX;
        if (parent[t] == t && rims[t] && size[t] >= MS_HOLED_MIN_TRIS && (size_t)rims[t] * MS_HOLED_TRIS_PER_RIM_EDGE <= size[t]) {
            set_of_root[t] = (uint32_t)nh++;
            m += rims[t];
        }
    }
    rc = 0;
    if (!nh) goto done;
    rc = -1;
    out->holed = malloc(n * sizeof *out->holed);
    out->holed_box = malloc(nh * sizeof *out->holed_box);
    out->cap_start = malloc((nh + 1) * sizeof *out->cap_start);
    e = malloc(m * sizeof *e);
    ends = malloc(2 * m * sizeof *ends);
    used = calloc(m, 1);
    if (!out->holed || !out->holed_box || !out->cap_start || !e || !ends || !used) goto done;
    for (size_t h = 0; h < nh; h++)
        for (int a = 0; a < 3; a++) { out->holed_box[h][a] = INFINITY; out->holed_box[h][3 + a] = -INFINITY; }
    for (size_t t = 0; t < n; t++) {
        const uint32_t h = set_of_root[ms_uf_find(parent, (uint32_t)t)];
        out->holed[t] = h == UINT32_MAX ? MS_OPEN_COMPONENT : h;
        if (h != UINT32_MAX)
            for (int q = 0; q < 3; q++) grow_box(out->holed_box[h], tri + 9 * t + 3 * (size_t)q);
    }
    /* The holed sets' rim edges, set by set (a counting sort), and their ends by vertex. */
    size_t *at = calloc(nh + 1, sizeof *at);
    if (!at) goto done;
    for (size_t i = 0; i < n_rim; i++) {
        const uint32_t h = out->holed[rim[i] / 3];
        if (h != MS_OPEN_COMPONENT) at[h + 1]++;
    }
    for (size_t h = 0; h < nh; h++) at[h + 1] += at[h];
    for (size_t i = 0; i < n_rim; i++) {
        const uint32_t t = rim[i] / 3, k = rim[i] % 3, h = out->holed[t];
        if (h == MS_OPEN_COMPONENT) continue;
        rim_edge *r = &e[at[h]++];
        r->corner[0] = 3 * t + k;
        r->corner[1] = 3 * t + (k + 1) % 3;
        r->v[0] = id[r->corner[0]];
        r->v[1] = id[r->corner[1]];
        r->set = h;
    }
    free(at);
    for (size_t i = 0; i < m; i++) {
        ends[2 * i].v = e[i].v[0];
        ends[2 * i + 1].v = e[i].v[1];
        ends[2 * i].edge = ends[2 * i + 1].edge = (uint32_t)i;
    }
    qsort(ends, 2 * m, sizeof *ends, end_cmp);
    size_t nc = 0, cap_cap = 0, first = 0;
    for (uint32_t h = 0; h < nh; h++) {
        out->cap_start[h] = nc;
        const int w = cap_walks(tri, e, m, ends, used, first, h, &nc, &cap_cap, out);
        if (w == -2) { holes_free(out); rc = 0; goto done; }   /* no caps rather than a surface that is no cycle */
        if (w) goto done;
        while (first < m && e[first].set == h) first++;
    }
    out->cap_start[nh] = nc;
    out->n_holed = nh;
    rc = 0;
done:
    free(size);
    free(rims);
    free(set_of_root);
    free(e);
    free(ends);
    free(used);
    if (rc) holes_free(out);
    return rc;
}

/* Box corners and light points against the cap along axis d: 1 when they lie on opposite sides beyond tol (the
 * tolerance scaled to the axis's length). */
static int separates(const double d[3], const double (*h)[3], int nh, const double (*t)[3], double tol)
{
    const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0.0)) return 0;
    double hlo = INFINITY, hhi = -INFINITY, tlo = INFINITY, thi = -INFINITY;
    for (int i = 0; i < nh; i++) {   /* comparisons, not fmin and fmax: those are calls here */
        const double p = d[0] * h[i][0] + d[1] * h[i][1] + d[2] * h[i][2];
        hlo = p < hlo ? p : hlo;
        hhi = p > hhi ? p : hhi;
    }
    for (int i = 0; i < 3; i++) {
        const double p = d[0] * t[i][0] + d[1] * t[i][1] + d[2] * t[i][2];
        tlo = p < tlo ? p : tlo;
        thi = p > thi ? p : thi;
    }
    return hhi + tol * len < tlo || thi + tol * len < hlo;
}

static void cross3(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* 1 when one of the axes u x dirs[i] separates. */
static int crossed_separates(const double u[3], const double (*dirs)[3], int n, const double (*h)[3], int nh,
                             const double (*t)[3], double tol)
{
    for (int i = 0; i < n; i++) {
        double d[3];
        cross3(u, dirs[i], d);
        if (separates(d, h, nh, t, tol)) return 1;
    }
    return 0;
}

/* The separating-axis test of the hull of the box's corners and the light's points against the cap. Candidate
 * axes, cheapest and likeliest first: the cap's normal, the box's axes, the light's edge directions crossed, the
 * cap's edges crossed with the box's axes, the light's edges and the bridges (a light point less a box corner),
 * and the hull's own faces spanned by a bridge and a box axis or a light edge. A superset of these would make the
 * test exact for convex bodies; any axis that separates proves the segments miss the cap. */
int ms_cap_hidden(const float b[6], const float (*pts)[3], int n_pts, const float cap[9], double tol)
{
    enum { MAXP = 8 };
    if (n_pts > MAXP) return 0;
    double h[8 + MAXP][3], t[3][3], te[3][3], le[MAXP][3], br[8 * MAXP][3];
    int nh = 0;
    for (int c = 0; c < 8; c++, nh++)
        for (int a = 0; a < 3; a++) h[nh][a] = (double)b[(c >> a & 1) ? 3 + a : a];
    for (int q = 0; q < n_pts; q++, nh++)
        for (int a = 0; a < 3; a++) h[nh][a] = (double)pts[q][a];
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) t[i][a] = (double)cap[3 * i + a];
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) te[i][a] = t[(i + 1) % 3][a] - t[i][a];
    double d[3];
    cross3(te[0], te[1], d);
    if (separates(d, h, nh, t, tol)) return 1;
    for (int a = 0; a < 3; a++) {
        const double ax[3] = { a == 0, a == 1, a == 2 };
        if (separates(ax, h, nh, t, tol)) return 1;
    }
    const int nl = n_pts - 1;
    for (int q = 0; q < nl; q++)
        for (int a = 0; a < 3; a++) le[q][a] = (double)pts[q + 1][a] - pts[0][a];
    for (int q = 0; q + 1 < nl; q++) {
        cross3(le[q], le[q + 1], d);
        if (separates(d, h, nh, t, tol)) return 1;
    }
    int nb = 0;
    for (int q = 0; q < n_pts; q++)
        for (int c = 0; c < 8; c++, nb++)
            for (int a = 0; a < 3; a++) br[nb][a] = h[8 + q][a] - h[c][a];
    static const double axes[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
    for (int i = 0; i < 3; i++)
        if (crossed_separates(te[i], axes, 3, h, nh, t, tol) || crossed_separates(te[i], (const double (*)[3])le, nl, h, nh, t, tol))
            return 1;
    for (int k = 0; k < nb; k++)
        if (crossed_separates(br[k], (const double (*)[3])te, 3, h, nh, t, tol) || crossed_separates(br[k], axes, 3, h, nh, t, tol) ||
            crossed_separates(br[k], (const double (*)[3])le, nl, h, nh, t, tol))
            return 1;
    return 0;
}
