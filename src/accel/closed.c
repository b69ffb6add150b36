/* Closed components of a triangle soup and the light-facing cull they allow (closed.h, docs/culling.md). */
#include "closed.h"
#include <stdlib.h>
#include <string.h>

/* Welding and edge matching by open addressing (linear probing), O(n): at 270K triangles the two sorts they
 * replace took 0.3 s, more than the frame's shadows at 256x256. */
static uint64_t mix64(uint64_t x)
{
    x ^= x >> 33; x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33; x *= 0xc4ceb9fe1a85ec53ULL;
    return x ^ (x >> 33);
}

static size_t table_size(size_t n)
{
    size_t m = 16;
    while (m < 2 * n) m <<= 1;
    return m;
}

/* An edge between welded vertices lo < hi: the triangles that walk it (the first two), how many, and the
 * direction of each (0: lo -> hi). */
typedef struct edge_slot {
    uint32_t lo, hi;    /* hi == 0 and lo == 0: empty (lo < hi always holds for a real edge) */
    uint32_t tri[2];
    uint32_t count;
    uint8_t dir[2];
} edge_slot;

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
    const size_t vm = table_size(3 * n), em = table_size(3 * n);
    uint32_t *vslot = malloc(vm * sizeof *vslot);       /* corner index + 1 of a vertex's first corner, 0: empty */
    uint32_t *id = malloc(3 * n * sizeof *id);          /* welded vertex of each corner */
    edge_slot *e = calloc(em, sizeof *e);
    uint32_t *parent = malloc(n * sizeof *parent);
    uint32_t *cparent = malloc(n * sizeof *cparent);    /* the mod-2 cycles: any shared edge unites */
    uint8_t *bad = calloc(n, 1);                        /* on a boundary, fin, flipped or degenerate edge */
    uint8_t *odd = calloc(n, 1);                        /* on an edge used an odd number of times */
    out->component = malloc(n * sizeof *out->component);
    out->cycle = malloc(n * sizeof *out->cycle);
    if (!vslot || !id || !e || !parent || !cparent || !bad || !odd || !out->component || !out->cycle) goto oom;
    memset(vslot, 0, vm * sizeof *vslot);
    /* Weld: corners with bitwise-equal positions (-0 as +0) share a vertex, numbered by first corner. */
    for (size_t c = 0; c < 3 * n; c++) {
        uint32_t key[3];
        for (int k = 0; k < 3; k++) key[k] = float_key(tri[3 * c + (size_t)k]);
        size_t h = (size_t)mix64(((uint64_t)key[0] << 32 | key[1]) ^ mix64(key[2])) & (vm - 1);
        for (;; h = (h + 1) & (vm - 1)) {
            if (!vslot[h]) { vslot[h] = (uint32_t)c + 1; id[c] = (uint32_t)c; break; }
            const size_t o = vslot[h] - 1;
            int same = 1;
            for (int k = 0; k < 3 && same; k++) same = float_key(tri[3 * o + (size_t)k]) == key[k];
            if (same) { id[c] = id[o]; break; }
        }
    }
    free(vslot);
    vslot = NULL;
    for (size_t t = 0; t < n; t++) {
        parent[t] = cparent[t] = (uint32_t)t;
        for (int k = 0; k < 3; k++) {
            const uint32_t a = id[3 * t + (size_t)k], b = id[3 * t + (size_t)(k + 1) % 3];
            if (a == b) { bad[t] = 1; continue; }   /* a repeated vertex: no solid has such a face */
            const uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
            size_t h = (size_t)mix64((uint64_t)lo << 32 | hi) & (em - 1);
            while (e[h].count && (e[h].lo != lo || e[h].hi != hi)) h = (h + 1) & (em - 1);
            edge_slot *s = &e[h];
            if (s->count) unite(cparent, (uint32_t)t, s->tri[0]);
            if (s->count < 2) {
                s->lo = lo; s->hi = hi;
                s->tri[s->count] = (uint32_t)t;
                s->dir[s->count] = a < b ? 0 : 1;
            } else {
                bad[t] = 1;   /* a fin of three or more: all of them open */
                bad[s->tri[0]] = bad[s->tri[1]] = 1;
            }
            s->count++;
        }
    }
    for (size_t i = 0; i < em; i++) {
        const edge_slot *s = &e[i];
        /* Exactly two triangles, walking the edge in opposite directions: they are neighbours on one
         * consistently oriented surface. Anything else (a boundary, a fin of three or more, two that walk
         * it the same way) leaves their component open. */
        if (s->count == 2 && s->dir[0] != s->dir[1]) unite(parent, s->tri[0], s->tri[1]);
        else if (s->count == 1) bad[s->tri[0]] = 1;
        else if (s->count >= 2) bad[s->tri[0]] = bad[s->tri[1]] = 1;
        if (s->count & 1) odd[s->tri[0]] = 1;
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
    /* The mod-2 cycles the same way: open when any of their edges is used an odd number of times. */
    for (size_t t = 0; t < n; t++) {
        const uint32_t r = find_root(cparent, (uint32_t)t);
        if (odd[t]) odd[r] = 1;
    }
    size_t ncy = 0;
    for (size_t t = 0; t < n; t++) {
        const uint32_t r = find_root(cparent, (uint32_t)t);
        if (odd[r]) out->cycle[t] = MS_OPEN_COMPONENT;
        else out->cycle[t] = r == t ? (uint32_t)ncy++ : out->cycle[r];
    }
    out->n_cycles = ncy;
    if (ncy) {
        out->cycle_box = malloc(ncy * sizeof *out->cycle_box);
        uint8_t *seen = calloc(ncy, 1);
        if (!out->cycle_box || !seen) { free(seen); goto oom; }
        for (size_t t = 0; t < n; t++) {
            const uint32_t c = out->cycle[t];
            if (c == MS_OPEN_COMPONENT) continue;
            const float *p = tri + 9 * t;
            out->cycle_tris++;
            if (!seen[c]) {
                seen[c] = 1;
                for (int k = 0; k < 3; k++) out->cycle_box[c][k] = out->cycle_box[c][3 + k] = p[k];
            }
            for (int q = 0; q < 3; q++)
                for (int k = 0; k < 3; k++) {
                    const float x = p[3 * q + k];
                    if (x < out->cycle_box[c][k]) out->cycle_box[c][k] = x;
                    if (x > out->cycle_box[c][3 + k]) out->cycle_box[c][3 + k] = x;
                }
        }
        free(seen);
    }
    free(parent);
    parent = NULL;
    free(cparent);
    cparent = NULL;
    free(bad);
    bad = NULL;
    free(odd);
    odd = NULL;
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
    free(vslot);
    free(id);
    free(e);
    free(parent);
    free(cparent);
    free(bad);
    free(odd);
    ms_closed_free(out);
    return -1;
}

void ms_closed_free(ms_closed *c)
{
    free(c->component);
    free(c->box);
    free(c->outward);
    free(c->cycle);
    free(c->cycle_box);
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
