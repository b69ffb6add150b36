/* Closed components of a triangle soup and the light-facing cull they allow (closed.h, docs/culling.md). */
#include "closed.h"
#include "holes.h"
#include "core/union_find.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Welding by open addressing (linear probing) and edge matching through the directed edges grouped by their
 * first vertex, O(n): at 270K triangles the two sorts they replace took 0.3 s, more than the frame's shadows
 * at 256x256, and an edge hash table twice that (48 MB of random accesses). */
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

/* Numbers the sets of the union-find `parent` over n triangles into label (0, 1, ... in order of their
 * smallest member), a set with any flagged triangle MS_OPEN_COMPONENT; returns the number of sets kept.
 * flag is overwritten (a set's flag gathers at its root). */
static size_t label_sets(uint32_t *parent, uint8_t *flag, size_t n, uint32_t *label)
{
    for (size_t t = 0; t < n; t++) {
        const uint32_t r = ms_uf_find(parent, (uint32_t)t);
        if (flag[t]) flag[r] = 1;
    }
    /* Roots are their set's smallest index (unite), so a root is numbered before its members. */
    size_t k = 0;
    for (size_t t = 0; t < n; t++) {
        const uint32_t r = ms_uf_find(parent, (uint32_t)t);
        if (flag[r]) label[t] = MS_OPEN_COMPONENT;
        else label[t] = r == t ? (uint32_t)k++ : label[r];
    }
    return k;
}

/* The boxes of the k labelled sets (label: per triangle, MS_OPEN_COMPONENT for none); returns the number of
 * labelled triangles. */
static size_t set_boxes(const float *tri, size_t n, const uint32_t *label, size_t k, float (*box)[6])
{
    for (size_t c = 0; c < k; c++)
        for (int a = 0; a < 3; a++) { box[c][a] = INFINITY; box[c][3 + a] = -INFINITY; }
    size_t m = 0;
    for (size_t t = 0; t < n; t++) {
        const uint32_t c = label[t];
        if (c == MS_OPEN_COMPONENT) continue;
        m++;
        for (int q = 0; q < 3; q++)
            for (int a = 0; a < 3; a++) {
                const float x = tri[9 * t + 3 * (size_t)q + (size_t)a];
                if (x < box[c][a]) box[c][a] = x;
                if (x > box[c][3 + a]) box[c][3 + a] = x;
            }
    }
    return m;
}

static uint32_t float_key(float f)
{
    f += 0.0f;   /* -0 and +0 are one position */
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

/* Appends to the rim the corner of triangle t where its edge a -> b starts (3 t + k). 0, or -1 when out of memory. */
static int rim_push(uint32_t **rim, size_t *n, size_t *cap, const uint32_t *id, uint32_t t, uint32_t a, uint32_t b)
{
    if (*n == *cap) {
        const size_t c = *cap ? 2 * *cap : 256;
        uint32_t *r = realloc(*rim, c * sizeof *r);
        if (!r) return -1;
        *rim = r;
        *cap = c;
    }
    uint32_t k = 0;
    while (id[3 * t + k] != a || id[3 * t + (k + 1) % 3] != b) k++;
    (*rim)[(*n)++] = 3 * t + k;
    return 0;
}

/* Appends directed edge i to the touching edges. 0, or -1 when out of memory. */
static int pinch_push(uint32_t **list, size_t *n, size_t *cap, uint32_t i)
{
    if (*n == *cap) {
        const size_t c = *cap ? 2 * *cap : 64;
        uint32_t *r = realloc(*list, c * sizeof *r);
        if (!r) return -1;
        *list = r;
        *cap = c;
    }
    (*list)[(*n)++] = i;
    return 0;
}

/* The first vertex of directed edge i of the CSR lists (start: nv + 1 offsets). */
static uint32_t edge_start(const uint32_t *start, uint32_t nv, uint32_t i)
{
    uint32_t lo = 0, hi = nv;   /* the a with start[a] <= i < start[a + 1] */
    while (hi - lo > 1) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (start[mid] <= i) lo = mid; else hi = mid;
    }
    return lo;
}

/* A touching edge (pinch: its directed edges, indices into the CSR lists start, dst, etri) closes a component only
 * where the component's own triangles walk it as often each way (the whole edge does: two consistently oriented
 * parts meet there, not a part and a flipped one); bad marks the others' triangles. */
static void touching_walks(const uint32_t *pinch, size_t n_pinch, const uint32_t *start, uint32_t nv,
                           const uint32_t *dst, const uint32_t *etri, uint32_t *parent, uint8_t *bad)
{
    for (size_t e = 0; e < n_pinch; e++) {
        const uint32_t i = pinch[e], t = etri[i], a = edge_start(start, nv, i), b = dst[i];
        const uint32_t r = ms_uf_find(parent, t);
        long walk = 0;
        for (uint32_t j = start[a]; j < start[a + 1]; j++) walk += dst[j] == b && ms_uf_find(parent, etri[j]) == r;
        for (uint32_t j = start[b]; j < start[b + 1]; j++) walk -= dst[j] == a && ms_uf_find(parent, etri[j]) == r;
        if (walk) bad[t] = 1;
    }
}

/* The closed components' boxes and orientations (out->component labelled, n_components set). 0, or -1 when out
 * of memory. */
static int component_boxes_and_sides(const float *tri, ms_closed *out)
{
    const size_t n = out->n_tris, nc = out->n_components;
    out->box = malloc(nc * sizeof *out->box);
    out->outward = malloc(nc);
    double *vol = calloc(nc, sizeof *vol);
    if (!out->box || !out->outward || !vol) { free(vol); return -1; }
    out->closed_tris = set_boxes(tri, n, out->component, nc, out->box);
    for (size_t t = 0; t < n; t++) {
        const uint32_t c = out->component[t];
        if (c == MS_OPEN_COMPONENT) continue;
        const float *p = tri + 9 * t, *ref = out->box[c];   /* any point will do: the box's low corner, near */
        double a[3], b[3], d[3];
        for (int k = 0; k < 3; k++) {
            a[k] = (double)p[k] - ref[k];
            b[k] = (double)p[3 + k] - ref[k];
            d[k] = (double)p[6 + k] - ref[k];
        }
        /* six times the signed volume of the tetrahedron (ref, a, b, c): summed over a closed surface,
         * positive when its winding points outwards */
        vol[c] += a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0]);
    }
    for (size_t c = 0; c < nc; c++) out->outward[c] = vol[c] >= 0.0 ? 1 : -1;
    free(vol);
    return 0;
}

int ms_closed_find(const float *tri, size_t n, ms_closed *out)
{
    memset(out, 0, sizeof *out);
    out->n_tris = n;
    if (n == 0) return 0;
    if (n > UINT32_MAX / 3) return -1;
    const size_t vm = table_size(3 * n);
    uint32_t *vslot = malloc(vm * sizeof *vslot);       /* corner index + 1 of a vertex's first corner, 0: empty */
    uint32_t *id = malloc(3 * n * sizeof *id);          /* welded vertex of each corner, numbered densely */
    uint32_t *pinch = NULL;                             /* directed edges of touching edges (index into dst) */
    size_t n_pinch = 0, pinch_cap = 0;
    uint32_t *rim = NULL;                               /* the edges used an odd number of times, once each: */
    size_t n_rim = 0, rim_cap = 0;                      /* the corner that starts them (3 t + k) */
    uint32_t *start = NULL, *dst = NULL, *etri = NULL;  /* directed edges by their first vertex (CSR) */
    uint32_t *parent = malloc(n * sizeof *parent);
    uint32_t *cparent = malloc(n * sizeof *cparent);    /* the mod-2 cycles: any shared edge unites */
    uint8_t *bad = calloc(n, 1);                        /* on a boundary, fin, flipped or degenerate edge */
    uint8_t *odd = calloc(n, 1);                        /* on an edge used an odd number of times */
    out->component = malloc(n * sizeof *out->component);
    out->cycle = malloc(n * sizeof *out->cycle);
    if (!vslot || !id || !parent || !cparent || !bad || !odd || !out->component || !out->cycle) goto oom;
    memset(vslot, 0, vm * sizeof *vslot);
    /* Weld: corners with bitwise-equal positions (-0 as +0) share a vertex. */
    uint32_t nv = 0;
    for (size_t c = 0; c < 3 * n; c++) {
        uint32_t key[3];
        for (int k = 0; k < 3; k++) key[k] = float_key(tri[3 * c + (size_t)k]);
        size_t h = (size_t)mix64(((uint64_t)key[0] << 32 | key[1]) ^ mix64(key[2])) & (vm - 1);
        for (;; h = (h + 1) & (vm - 1)) {
            if (!vslot[h]) { vslot[h] = (uint32_t)c + 1; id[c] = nv++; break; }
            const size_t o = vslot[h] - 1;
            int same = 1;
            for (int k = 0; k < 3 && same; k++) same = float_key(tri[3 * o + (size_t)k]) == key[k];
            if (same) { id[c] = id[o]; break; }
        }
    }
    free(vslot);
    vslot = NULL;
    /* The directed edges a -> b (a != b) grouped by a: finding an edge's twins is a look at b's few. */
    start = calloc((size_t)nv + 1, sizeof *start);
    dst = malloc(3 * n * sizeof *dst);
    etri = malloc(3 * n * sizeof *etri);
    if (!start || !dst || !etri) goto oom;
    for (size_t t = 0; t < n; t++) {
        parent[t] = cparent[t] = (uint32_t)t;
        for (int k = 0; k < 3; k++) {
            const uint32_t a = id[3 * t + (size_t)k], b = id[3 * t + (size_t)(k + 1) % 3];
            if (a == b) bad[t] = 1;   /* a repeated vertex: no solid has such a face */
            else start[a + 1]++;
        }
    }
    for (uint32_t v = 0; v < nv; v++) start[v + 1] += start[v];
    for (size_t t = 0; t < n; t++)
        for (int k = 0; k < 3; k++) {
            const uint32_t a = id[3 * t + (size_t)k], b = id[3 * t + (size_t)(k + 1) % 3];
            if (a == b) continue;
            const uint32_t at = start[a]++;   /* start[a] walks to start[a + 1]; shifted back below */
            dst[at] = b;
            etri[at] = (uint32_t)t;
        }
    for (uint32_t v = nv; v > 0; v--) start[v] = start[v - 1];
    start[0] = 0;
    for (uint32_t a = 0; a < nv; a++)
        for (uint32_t i = start[a]; i < start[a + 1]; i++) {
            const uint32_t b = dst[i], t = etri[i];
            /* the triangles walking a -> b (this one included) and b -> a */
            uint32_t same = 0, opp = 0, twin = 0, earlier = 0;
            for (uint32_t j = start[a]; j < start[a + 1]; j++)
                if (dst[j] == b) { same++; earlier += j < i; ms_uf_union(cparent, t, etri[j]); }
            for (uint32_t j = start[b]; j < start[b + 1]; j++)
                if (dst[j] == a) { opp++; twin = etri[j]; ms_uf_union(cparent, t, twin); }
            /* Exactly two triangles, walking the edge in opposite directions: neighbours on one consistently
             * oriented surface. As many each way but more than one (two solids, or two parts of one, touching
             * along the edge): no union through it, each component's own walks checked below. Anything else
             * (a boundary, a fin of three, two that walk it the same way) leaves their component open. */
            if (same == 1 && opp == 1) ms_uf_union(parent, t, twin);
            else if (same == opp) { if (pinch_push(&pinch, &n_pinch, &pinch_cap, i)) goto oom; }
            else bad[t] = 1;
            if ((same + opp) & 1) {
                odd[t] = 1;
                /* The rim edge once: at a's first a -> b, from the smaller end when both directions occur. */
                if (!earlier && (a < b || !opp) && rim_push(&rim, &n_rim, &rim_cap, id, t, a, b)) goto oom;
            }
        }
    touching_walks(pinch, n_pinch, start, nv, dst, etri, parent, bad);
    free(pinch);
    pinch = NULL;
    free(start);
    start = NULL;
    free(dst);
    dst = NULL;
    free(etri);
    etri = NULL;
    /* The holed sets (label_sets below only compresses cparent's paths). */
    if (ms_holes_cap(tri, n, id, rim, n_rim, cparent, out)) goto oom;
    free(rim);
    rim = NULL;
    free(id);
    id = NULL;
    const size_t nc = label_sets(parent, bad, n, out->component);   /* closed components */
    const size_t ncy = label_sets(cparent, odd, n, out->cycle);      /* mod-2 cycles */
    out->n_cycles = ncy;
    if (ncy) {
        out->cycle_box = malloc(ncy * sizeof *out->cycle_box);
        if (!out->cycle_box) goto oom;
        out->cycle_tris = set_boxes(tri, n, out->cycle, ncy, out->cycle_box);
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
    if (nc && component_boxes_and_sides(tri, out)) goto oom;
    return 0;
oom:
    free(pinch);
    free(vslot);
    free(id);
    free(rim);
    free(start);
    free(dst);
    free(etri);
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
    free(c->holed);
    free(c->holed_box);
    free(c->cap);
    free(c->cap_start);
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
