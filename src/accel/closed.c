/* Closed components of a triangle soup and the light-facing cull they allow (closed.h, docs/culling.md). */
#include "closed.h"
#include <stdlib.h>
#include <string.h>

/* A vertex reference: its position's bits (so that sorting groups bitwise-equal positions) and where it is. */
typedef struct vref {
    uint32_t key[3];
    uint32_t at;        /* 3 * triangle + corner */
} vref;

static int cmp_vref(const void *a, const void *b)
{
    const vref *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->key[k] != y->key[k]) return x->key[k] < y->key[k] ? -1 : 1;
    return 0;
}

/* An edge of a triangle between welded vertices lo < hi; dir 0 when the triangle walks it lo -> hi. */
typedef struct edge {
    uint32_t lo, hi, tri, dir;
} edge;

static int cmp_edge(const void *a, const void *b)
{
    const edge *x = a, *y = b;
    if (x->lo != y->lo) return x->lo < y->lo ? -1 : 1;
    if (x->hi != y->hi) return x->hi < y->hi ? -1 : 1;
    return 0;
}

static uint32_t find_root(uint32_t *parent, uint32_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];   /* path halving */
        i = parent[i];
    }
    return i;
}

static void unite(uint32_t *parent, uint32_t a, uint32_t b)
{
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a != b) parent[a < b ? b : a] = a < b ? a : b;
}

static uint32_t float_key(float f)
{
    f += 0.0f;   /* -0 and +0 are one position */
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

int ms_closed_find(const float *tri, size_t n, ms_closed *out)
{
    memset(out, 0, sizeof *out);
    out->n_tris = n;
    if (n == 0) return 0;
    if (n > UINT32_MAX / 3) return -1;
    vref *v = malloc(3 * n * sizeof *v);
    uint32_t *id = malloc(3 * n * sizeof *id);          /* welded vertex of each corner */
    edge *e = malloc(3 * n * sizeof *e);
    uint32_t *parent = malloc(n * sizeof *parent);
    uint8_t *bad = calloc(n, 1);                        /* on a boundary, fin, flipped or degenerate edge */
    out->component = malloc(n * sizeof *out->component);
    if (!v || !id || !e || !parent || !bad || !out->component) goto oom;
    for (size_t c = 0; c < 3 * n; c++) {
        for (int k = 0; k < 3; k++) v[c].key[k] = float_key(tri[3 * c + (size_t)k]);
        v[c].at = (uint32_t)c;
    }
    qsort(v, 3 * n, sizeof *v, cmp_vref);
    uint32_t next = 0;
    for (size_t c = 0; c < 3 * n; c++) {
        if (c && cmp_vref(&v[c - 1], &v[c])) next++;
        id[v[c].at] = next;
    }
    free(v);
    v = NULL;
    size_t ne = 0;
    for (size_t t = 0; t < n; t++) {
        parent[t] = (uint32_t)t;
        for (int k = 0; k < 3; k++) {
            const uint32_t a = id[3 * t + (size_t)k], b = id[3 * t + (size_t)(k + 1) % 3];
            if (a == b) { bad[t] = 1; continue; }   /* a repeated vertex: no solid has such a face */
            e[ne++] = (edge){ a < b ? a : b, a < b ? b : a, (uint32_t)t, a < b ? 0u : 1u };
        }
    }
    qsort(e, ne, sizeof *e, cmp_edge);
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].lo == e[i].lo && e[j].hi == e[i].hi) j++;
        /* Exactly two triangles, walking the edge in opposite directions: they are neighbours on one
         * consistently oriented surface. Anything else (a boundary, a fin of three or more, two that walk
         * it the same way) leaves their component open. */
        if (j - i == 2 && e[i].dir != e[i + 1].dir) unite(parent, e[i].tri, e[i + 1].tri);
        else
            for (size_t k = i; k < j; k++) bad[e[k].tri] = 1;
        i = j;
    }
    free(e);
    e = NULL;
    free(id);
    id = NULL;
    /* A component is closed when none of its triangles is bad; roots are the smallest index. */
    for (size_t t = 0; t < n; t++) {
        const uint32_t r = find_root(parent, (uint32_t)t);
        if (bad[t]) bad[r] = 1;
    }
    /* Roots are their set's smallest index (unite), so a root is numbered before its members. */
    size_t nc = 0;
    for (size_t t = 0; t < n; t++) {
        const uint32_t r = find_root(parent, (uint32_t)t);
        if (bad[r]) out->component[t] = MS_OPEN_COMPONENT;
        else out->component[t] = r == t ? (uint32_t)nc++ : out->component[r];
    }
    free(parent);
    parent = NULL;
    free(bad);
    bad = NULL;
    out->n_components = nc;
    if (nc) {
        out->box = malloc(nc * sizeof *out->box);
        out->outward = malloc(nc);
        double *vol = calloc(nc, sizeof *vol), (*ref)[3] = malloc(nc * sizeof *ref);
        uint8_t *seen = calloc(nc, 1);
        if (!out->box || !out->outward || !vol || !ref || !seen) { free(vol); free(ref); free(seen); goto oom; }
        for (size_t t = 0; t < n; t++) {
            const uint32_t c = out->component[t];
            if (c == MS_OPEN_COMPONENT) continue;
            const float *p = tri + 9 * t;
            out->closed_tris++;
            if (!seen[c]) {
                seen[c] = 1;
                for (int k = 0; k < 3; k++) { out->box[c][k] = out->box[c][3 + k] = p[k]; ref[c][k] = p[k]; }
            }
            double a[3], b[3], d[3];
            for (int k = 0; k < 3; k++) {
                for (int q = 0; q < 3; q++) {
                    const float x = p[3 * q + k];
                    if (x < out->box[c][k]) out->box[c][k] = x;
                    if (x > out->box[c][3 + k]) out->box[c][3 + k] = x;
                }
                a[k] = (double)p[k] - ref[c][k];
                b[k] = (double)p[3 + k] - ref[c][k];
                d[k] = (double)p[6 + k] - ref[c][k];
            }
            /* six times the signed volume of the tetrahedron (ref, a, b, c): summed over a closed surface,
             * positive when its winding points outwards */
            vol[c] += a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0]);
        }
        for (size_t c = 0; c < nc; c++) out->outward[c] = vol[c] >= 0.0 ? 1 : -1;
        free(vol);
        free(ref);
        free(seen);
    }
    return 0;
oom:
    free(v);
    free(id);
    free(e);
    free(parent);
    free(bad);
    ms_closed_free(out);
    return -1;
}

void ms_closed_free(ms_closed *c)
{
    free(c->component);
    free(c->box);
    free(c->outward);
    memset(c, 0, sizeof *c);
}

size_t ms_closed_cull(const ms_closed *c, const float *tri, const float (*pts)[3], int n_pts, const float lbox[6],
                      double margin, uint8_t *keep)
{
    size_t culled = 0;
    uint8_t *apart = c->n_components ? malloc(c->n_components) : NULL;
    if (c->n_components && !apart) {   /* no memory for the flags: cull nothing, which is always right */
        memset(keep, 1, c->n_tris);
        return 0;
    }
    for (size_t k = 0; k < c->n_components; k++) {
        const float *b = c->box[k];
        int sep = 0;
        for (int a = 0; a < 3; a++)
            sep |= (double)lbox[a] > (double)b[3 + a] + margin || (double)lbox[3 + a] < (double)b[a] - margin;
        apart[k] = (uint8_t)sep;
    }
    for (size_t t = 0; t < c->n_tris; t++) {
        const uint32_t k = c->component[t];
        keep[t] = 1;
        if (k == MS_OPEN_COMPONENT || !apart[k]) continue;
        const float *p = tri + 9 * t;
        double u[3], w[3], nrm[3];
        for (int a = 0; a < 3; a++) { u[a] = (double)p[3 + a] - p[a]; w[a] = (double)p[6 + a] - p[a]; }
        nrm[0] = u[1] * w[2] - u[2] * w[1];
        nrm[1] = u[2] * w[0] - u[0] * w[2];
        nrm[2] = u[0] * w[1] - u[1] * w[0];
        const double s = c->outward[k];
        int behind = 1;
        for (int q = 0; q < n_pts && behind; q++) {
            double d[3], dot = 0.0, mag = 0.0;
            for (int a = 0; a < 3; a++) {
                d[a] = (double)pts[q][a] - p[a];
                dot += s * nrm[a] * d[a];
                mag += (nrm[a] < 0 ? -nrm[a] : nrm[a]) * (d[a] < 0 ? -d[a] : d[a]);
            }
            /* behind beyond any rounding of the plane (the terms' magnitudes times 1e-9, far above double's
             * error for these three products): a light point that may be on or in front keeps the triangle */
            behind = dot < -1e-9 * mag;
        }
        if (behind && nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2] > 0.0) { keep[t] = 0; culled++; }
    }
    free(apart);
    return culled;
}
