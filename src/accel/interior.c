/* Interior boxes of closed surfaces (interior.h). */
#include "interior.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { CELL_FREE = 0, CELL_MARKED = 1, CELL_OUTSIDE = 2, CELL_SEEN = 3, CELL_INSIDE = 4, CELL_USED = 5 };

/* Groups of unmarked cells not reached from outside, tested by ray parity: at most this many per
 * component (largest first matters little: a statue has one big group and few pockets). */
#define MAX_GROUPS 64
#define MIN_GROUP_CELLS 8

/* A group's triangles: ids below n_scene are the scene's (tri), the others a holed set's caps (cap). */
typedef struct tri_src { const float *tri, *cap; size_t n_scene; } tri_src;

static const float *src_tri(const tri_src *s, uint32_t id)
{
    return id < s->n_scene ? s->tri + 9 * (size_t)id : s->cap + 9 * ((size_t)id - s->n_scene);
}

typedef struct grid {
    int nx, ny, nz;
    double o[3], h;
    uint8_t *cell;
} grid;

static size_t gidx(const grid *g, int x, int y, int z) { return ((size_t)z * (size_t)g->ny + (size_t)y) * (size_t)g->nx + (size_t)x; }

/* 0 when triangle t lies apart from the cube of centre c and half-side r by more than tol along one of the
 * separating axes of a triangle and a box (Akenine-Moller, "Fast 3D triangle-box overlap testing", 2001, in
 * double): the triangle's plane and the nine products of its edges with the cube's axes (the caller's cell
 * range already holds the cube's own three). 1 otherwise: a doubt marks the cell. */
static int tri_cube_overlap(const float *t, const double c[3], double r, double tol)
{
    double v[3][3], e[3][3];
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) v[i][a] = (double)t[3 * i + a] - c[a];
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) e[i][a] = v[(i + 1) % 3][a] - v[i][a];
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < 3; a++) {
            /* the axis unit_a x e_i */
            double ax[3] = { 0.0, 0.0, 0.0 };
            ax[(a + 1) % 3] = -e[i][(a + 2) % 3];
            ax[(a + 2) % 3] = e[i][(a + 1) % 3];
            double lo = INFINITY, hi = -INFINITY;
            for (int j = 0; j < 3; j++) {
                const double p = ax[0] * v[j][0] + ax[1] * v[j][1] + ax[2] * v[j][2];
                lo = fmin(lo, p);
                hi = fmax(hi, p);
            }
            const double len = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
            const double rad = r * (fabs(ax[0]) + fabs(ax[1]) + fabs(ax[2])) + tol * len;
            if (lo > rad || hi < -rad) return 0;
        }
    const double n[3] = { e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                          e[0][0] * e[1][1] - e[0][1] * e[1][0] };
    const double d = n[0] * v[0][0] + n[1] * v[0][1] + n[2] * v[0][2];
    const double rad = r * (fabs(n[0]) + fabs(n[1]) + fabs(n[2])) + tol * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return !(fabs(d) > rad);
}

/* The parity of the crossings of the ray p + t d (t > 0) with the cycle's triangles (Moller-Trumbore in
 * double): 1 odd, 0 even, -1 when the ray passes too close to an edge, a vertex or a plane to be sure (the
 * caller tries another direction). p is at least half a cell from every triangle, so t > 0 is clear. */
static int ray_parity(const tri_src *tri, const uint32_t *ids, size_t n, const double p[3], const double d[3], int threads)
{
    int odd = 0, unsure = 0;
#pragma omp parallel for reduction(^ : odd) reduction(| : unsure) schedule(static) num_threads(threads) if (n > 4096)
    for (size_t k = 0; k < n; k++) {
        const float *t = src_tri(tri, ids[k]);
        double e1[3], e2[3], s[3], h[3], q[3];
        for (int a = 0; a < 3; a++) { e1[a] = (double)t[3 + a] - t[a]; e2[a] = (double)t[6 + a] - t[a]; s[a] = p[a] - t[a]; }
        h[0] = d[1] * e2[2] - d[2] * e2[1]; h[1] = d[2] * e2[0] - d[0] * e2[2]; h[2] = d[0] * e2[1] - d[1] * e2[0];
        const double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
        const double scale = sqrt((e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]) * (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]));
        if (fabs(det) <= 1e-9 * scale) {
            /* parallel to the plane: a crossing is impossible unless the ray lies in it */
            const double n0 = e1[1] * e2[2] - e1[2] * e2[1], n1 = e1[2] * e2[0] - e1[0] * e2[2], n2 = e1[0] * e2[1] - e1[1] * e2[0];
            const double off = n0 * s[0] + n1 * s[1] + n2 * s[2];
            if (fabs(off) <= 1e-9 * sqrt(n0 * n0 + n1 * n1 + n2 * n2) * sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2])) unsure = 1;
            continue;
        }
        const double u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) / det;
        q[0] = s[1] * e1[2] - s[2] * e1[1]; q[1] = s[2] * e1[0] - s[0] * e1[2]; q[2] = s[0] * e1[1] - s[1] * e1[0];
        const double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
        const double w = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
        const double tol = 1e-7;
        if (w <= 0.0) continue;
        if (u < -tol || v < -tol || u + v > 1.0 + tol) continue;
        if (u <= tol || v <= tol || u + v >= 1.0 - tol) { unsure = 1; continue; }   /* near an edge or vertex */
        odd ^= 1;
    }
    return unsure ? -1 : odd;
}

/* Whether p is inside the cycle (odd crossings), by rays along fixed directions in turn until one is sure;
 * 0 when none is (the cells then stay out: always right). */
static int inside_cycle(const tri_src *tri, const uint32_t *ids, size_t n, const double p[3], int threads)
{
    static const double dirs[6][3] = { { 0.5773, 0.6181, 0.5331 }, { -0.3119, 0.8423, -0.4397 }, { 0.7071, -0.1234, 0.6963 },
                                       { -0.6513, -0.4455, 0.6142 }, { 0.1291, -0.9178, -0.3755 }, { -0.8236, 0.2468, -0.5107 } };
    for (int i = 0; i < 6; i++) {
        const int r = ray_parity(tri, ids, n, p, dirs[i], threads);
        if (r >= 0) return r;
    }
    return 0;
}

/* Flood fill from cell s over cells of value `from`, setting them to `to` (26-connected); stack: scratch
 * of the grid's size. Returns the cells filled. */
static size_t flood(grid *g, size_t s, uint8_t from, uint8_t to, size_t *stack)
{
    size_t top = 0, filled = 0;
    if (g->cell[s] != from) return 0;
    g->cell[s] = to;
    stack[top++] = s;
    const size_t sx = 1, sy = (size_t)g->nx, sz = (size_t)g->nx * (size_t)g->ny;
    while (top) {
        const size_t c = stack[--top];
        filled++;
        const int x = (int)(c % sy), y = (int)(c / sy % (size_t)g->ny), z = (int)(c / sz);
        for (int dz = -1; dz <= 1; dz++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    const int X = x + dx, Y = y + dy, Z = z + dz;
                    if (X < 0 || Y < 0 || Z < 0 || X >= g->nx || Y >= g->ny || Z >= g->nz) continue;
                    const size_t m = c + (size_t)((ptrdiff_t)dx * (ptrdiff_t)sx + (ptrdiff_t)dy * (ptrdiff_t)sy + (ptrdiff_t)dz * (ptrdiff_t)sz);
                    if (g->cell[m] == from) { g->cell[m] = to; stack[top++] = m; }
                }
    }
    return filled;
}

static int push_box(ms_interior *out, size_t *cap, const float b[6], uint32_t comp)
{
    if (out->n_boxes == *cap) {
        const size_t nc = *cap ? 2 * *cap : 64;
        float (*nb)[6] = realloc(out->box, nc * sizeof *nb);
        if (!nb) return -1;
        out->box = nb;
        uint32_t *ncmp = realloc(out->component, nc * sizeof *ncmp);
        if (!ncmp) return -1;
        out->component = ncmp;
        *cap = nc;
    }
    memcpy(out->box[out->n_boxes], b, sizeof out->box[0]);
    out->component[out->n_boxes++] = comp;
    return 0;
}

/* One cycle: its triangles ids[0..n), its box cbox. */
static int component_boxes(const tri_src *tri, const uint32_t *ids, size_t n, const float cbox[6], uint32_t comp,
                           int res, double eps, int threads, ms_interior *out, size_t *cap)
{
    double ext = 0.0;
    for (int a = 0; a < 3; a++) ext = fmax(ext, (double)cbox[3 + a] - cbox[a]);
    if (!(ext > 0.0) || res < 3) return 0;
    grid g;
    /* Cells no wider than four clearances would leave little or nothing unmarked: a coarser grid, by halves,
     * down to 16 cells (a far light's clearance is large beside a small cycle). */
    while (!(ext / res > 4.0 * eps) && res >= 32) res /= 2;
    g.h = ext / res;
    if (!(g.h > 4.0 * eps)) return 0;   /* still: nothing would be left */
    int dim[3];
    for (int a = 0; a < 3; a++) {
        dim[a] = (int)ceil(((double)cbox[3 + a] - cbox[a]) / g.h) + 3;   /* one border cell each side, one spare */
        g.o[a] = (double)cbox[a] - g.h;
    }
    g.nx = dim[0]; g.ny = dim[1]; g.nz = dim[2];
    const size_t nc = (size_t)g.nx * (size_t)g.ny * (size_t)g.nz;
    g.cell = calloc(nc, 1);
    size_t *stack = malloc(nc * sizeof *stack);
    if (!g.cell || !stack) { free(g.cell); free(stack); return -1; }
    /* Mark every cell whose closure comes within eps (L-infinity) of a triangle: the cells of the triangle's box
     * grown by eps that the triangle meets grown by eps (tri_cube_overlap; a cell whose box only the triangle's
     * box meets stays free, so the boxes come closer to a surface that runs across the grid). The small relative
     * slack covers the rounding of the cell coordinates. */
    const double slack = eps + 1e-9 * ext;
    for (size_t k = 0; k < n; k++) {
        const float *t = src_tri(tri, ids[k]);
        int lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            const double mn = fmin(fmin(t[a], t[3 + a]), t[6 + a]) - slack, mx = fmax(fmax(t[a], t[3 + a]), t[6 + a]) + slack;
            /* cell i spans [o + i h, o + (i + 1) h]: it meets [mn, mx] iff (mn - o)/h - 1 <= i <= (mx - o)/h;
             * a millionth of a cell more each side for the rounding of the divisions */
            lo[a] = (int)ceil((mn - g.o[a]) / g.h - 1.0 - 1e-6);
            hi[a] = (int)floor((mx - g.o[a]) / g.h + 1e-6);
            if (lo[a] < 0) lo[a] = 0;
            if (hi[a] > dim[a] - 1) hi[a] = dim[a] - 1;
        }
        for (int z = lo[2]; z <= hi[2]; z++)
            for (int y = lo[1]; y <= hi[1]; y++)
                for (int x = lo[0]; x <= hi[0]; x++) {
                    const size_t ci = gidx(&g, x, y, z);
                    if (g.cell[ci] == CELL_MARKED) continue;
                    const double cc[3] = { g.o[0] + (x + 0.5) * g.h, g.o[1] + (y + 0.5) * g.h, g.o[2] + (z + 0.5) * g.h };
                    if (tri_cube_overlap(t, cc, 0.5 * g.h + slack, 1e-9 * ext)) g.cell[ci] = CELL_MARKED;
                }
    }
    /* Outside: reached from the border (which no triangle reaches: the box is a cell inside it). */
    flood(&g, 0, CELL_FREE, CELL_OUTSIDE, stack);
    /* The other groups: inside or outside as a whole, by the parity of a ray from one cell's centre. */
    int groups = 0;
    for (size_t c = 0; c < nc && groups < MAX_GROUPS; c++) {
        if (g.cell[c] != CELL_FREE) continue;
        const int x = (int)(c % (size_t)g.nx), y = (int)(c / (size_t)g.nx % (size_t)g.ny), z = (int)(c / ((size_t)g.nx * (size_t)g.ny));
        /* A pocket of a few cells would give a box or two: not worth the ray's pass. */
        if (flood(&g, c, CELL_FREE, CELL_SEEN, stack) < MIN_GROUP_CELLS) continue;
        const double p[3] = { g.o[0] + (x + 0.5) * g.h, g.o[1] + (y + 0.5) * g.h, g.o[2] + (z + 0.5) * g.h };
        if (inside_cycle(tri, ids, n, p, threads)) flood(&g, c, CELL_SEEN, CELL_INSIDE, stack);
        groups++;
    }
    free(stack);
    /* Greedy boxes over the inside cells: along x, then whole rows along y, then whole slabs along z; at most
     * one per MS_INTERIOR_TRIS_PER_BOX triangles of the cycle, and one (a fragmented inside would otherwise give
     * up to a box per cell; the cells left are simply not boxed). */
    int rc = 0;
    const size_t limit = out->n_boxes + n / MS_INTERIOR_TRIS_PER_BOX + 1;
    for (int z = 0; z < g.nz && !rc && out->n_boxes < limit; z++)
        for (int y = 0; y < g.ny && !rc && out->n_boxes < limit; y++)
            for (int x = 0; x < g.nx && !rc && out->n_boxes < limit; x++) {
                if (g.cell[gidx(&g, x, y, z)] != CELL_INSIDE) continue;
                int x1 = x, y1 = y, z1 = z;
                while (x1 + 1 < g.nx && g.cell[gidx(&g, x1 + 1, y, z)] == CELL_INSIDE) x1++;
                for (int ok = 1; ok && y1 + 1 < g.ny;) {
                    for (int i = x; i <= x1 && ok; i++) ok = g.cell[gidx(&g, i, y1 + 1, z)] == CELL_INSIDE;
                    if (ok) y1++;
                }
                for (int ok = 1; ok && z1 + 1 < g.nz;) {
                    for (int j = y; j <= y1 && ok; j++)
                        for (int i = x; i <= x1 && ok; i++) ok = g.cell[gidx(&g, i, j, z1 + 1)] == CELL_INSIDE;
                    if (ok) z1++;
                }
                for (int k = z; k <= z1; k++)
                    for (int j = y; j <= y1; j++)
                        for (int i = x; i <= x1; i++) g.cell[gidx(&g, i, j, k)] = CELL_USED;
                /* Rounded inwards to float, so that the float box stays inside the cells. */
                const int c0[3] = { x, y, z }, c1[3] = { x1 + 1, y1 + 1, z1 + 1 };
                float b[6];
                for (int a = 0; a < 3; a++) {
                    const double lo = g.o[a] + c0[a] * g.h, hi = g.o[a] + c1[a] * g.h;
                    float fl = (float)lo, fh = (float)hi;
                    if ((double)fl < lo) fl = nextafterf(fl, INFINITY);
                    if ((double)fh > hi) fh = nextafterf(fh, -INFINITY);
                    b[a] = fl;
                    b[3 + a] = fh;
                }
                rc = push_box(out, cap, b, comp);
            }
    free(g.cell);
    return rc;
}

int ms_interior_find(const float *tri, size_t n, const ms_closed *c, int res, size_t min_tris, double eps,
                     int threads, ms_interior *out)
{
    memset(out, 0, sizeof *out);
    const size_t ng = ms_closed_groups(c), n_caps = c->n_holed ? c->cap_start[c->n_holed] : 0;
    if (!ng || c->n_tris != n) return 0;
    /* The triangles of each group (a cycle, or a holed set followed by its caps, ids from n on), contiguous. */
    size_t *start = calloc(ng + 1, sizeof *start), *fill = malloc(ng * sizeof *fill);
    size_t total = n_caps;
    for (size_t t = 0; start && t < n; t++) {
        const uint32_t g = ms_closed_group_of(c, t);
        if (g != MS_OPEN_COMPONENT) { start[g + 1]++; total++; }
    }
    uint32_t *ids = malloc((total ? total : 1) * sizeof *ids);
    if (!start || !fill || !ids) { free(start); free(fill); free(ids); return -1; }
    for (size_t h = 0; h < c->n_holed; h++) start[c->n_cycles + h + 1] += c->cap_start[h + 1] - c->cap_start[h];
    for (size_t g = 0; g < ng; g++) start[g + 1] += start[g];
    memcpy(fill, start, ng * sizeof *fill);
    for (size_t t = 0; t < n; t++) {
        const uint32_t g = ms_closed_group_of(c, t);
        if (g != MS_OPEN_COMPONENT) ids[fill[g]++] = (uint32_t)t;
    }
    for (size_t h = 0; h < c->n_holed; h++)
        for (size_t i = c->cap_start[h]; i < c->cap_start[h + 1]; i++) ids[fill[c->n_cycles + h]++] = (uint32_t)(n + i);
    free(fill);
    size_t cap = 0;
    int rc = 0;
    const tri_src src = { tri, c->cap, n };
    for (size_t g = 0; g < ng && !rc; g++) {
        const size_t m = start[g + 1] - start[g];
        const size_t real = g < c->n_cycles ? m : m - (c->cap_start[g - c->n_cycles + 1] - c->cap_start[g - c->n_cycles]);
        if (real < min_tris) continue;
        rc = component_boxes(&src, ids + start[g], m, ms_closed_group_box(c, g), (uint32_t)g, res, eps, threads, out, &cap);
    }
    free(start);
    free(ids);
    if (rc) ms_interior_free(out);
    return rc;
}

void ms_interior_free(ms_interior *in)
{
    free(in->box);
    free(in->component);
    memset(in, 0, sizeof *in);
}
