/* Closed components (src/accel/closed.c) and the light-facing cull they allow (docs/culling.md).
 *
 * Topology against hand-built cases: a closed icosphere is one outward component, mirrored it is inward,
 * a hole, a fin, a flipped triangle or a repeated vertex open it; several solids are several components
 * with their boxes, also where two touch along an edge; pyramids meeting along an edge loop are not closed.
 * The cull against a brute-force oracle written here (double-precision segment-triangle test, no BVH, no
 * code of the library): for random solids, lights and receivers — outside the solids,
 * inside them, on them — every sample's occlusion by the kept triangles equals its occlusion by all
 * triangles. The cases that break the naive argument are shown to break it (the oracle finds leaks when
 * the guards are bypassed): a lamp inside a closed shade, and a room wound inwards with the sun outside.
 *
 * Interior boxes (src/accel/interior.c): every point sampled in every box lies inside its component by a
 * ray-parity count written here, and at least the clearance from each of its triangles (point-triangle
 * distance, double); an open mesh is no cycle (a holed one: test_holes.c). Frames of a dense sphere over a
 * ground: scanline with the boxes and the cull (its default), without either, per pixel, hierarchical,
 * raytrace with and without the cull, mft with and without the boxes (the driver's interior pass) give the
 * same V bit for bit, for a light apart from the sphere (boxes used) and one inside its box (none); the points
 * API with the boxes equals raytrace point for point. */
#include "testutil.h"
#include "accel/closed.h"
#include "accel/interior.h"
#include "test_mesh.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- topology ---- */

static void test_topology(void **st)
{
    (void)st;
    const double o[3] = { 0, 0, 0 };
    tm_mesh m = { 0 };
    tm_icosphere(&m, o, 1.0, 2, 0, 0.0, 1);
    ms_closed c;
    assert_int_equal(ms_closed_find(m.tri, m.n, &c), 0);
    assert_int_equal(c.n_components, 1);
    assert_int_equal(c.closed_tris, m.n);
    assert_int_equal(c.outward[0], 1);
    for (int a = 0; a < 3; a++) { assert_true(c.box[0][a] >= -1.0f && c.box[0][a] < -0.9f); assert_true(c.box[0][3 + a] <= 1.0f); }
    ms_closed_free(&c);

    tm_mesh f = { 0 };
    tm_icosphere(&f, o, 1.0, 2, 1, 0.0, 1);          /* wound inwards */
    assert_int_equal(ms_closed_find(f.tri, f.n, &c), 0);
    assert_int_equal(c.n_components, 1);
    assert_int_equal(c.outward[0], -1);
    ms_closed_free(&c);

    /* a hole: one triangle less */
    assert_int_equal(ms_closed_find(m.tri, m.n - 1, &c), 0);
    assert_int_equal(c.n_components, 0);
    assert_int_equal(c.closed_tris, 0);
    ms_closed_free(&c);

    /* a fin: one triangle twice (three triangles on each of its edges) */
    tm_mesh g = { 0 };
    tm_icosphere(&g, o, 1.0, 1, 0, 0.0, 1);
    double a[3], b[3], cc[3];
    for (int k = 0; k < 3; k++) { a[k] = g.tri[k]; b[k] = g.tri[3 + k]; cc[k] = g.tri[6 + k]; }
    tm_add_tri(&g, a, b, cc);
    assert_int_equal(ms_closed_find(g.tri, g.n, &c), 0);
    assert_int_equal(c.n_components, 0);
    ms_closed_free(&c);

    /* one triangle flipped: its edges are walked the same way twice */
    g.n--;
    float tmp[3];
    memcpy(tmp, g.tri + 3, sizeof tmp);
    memcpy(g.tri + 3, g.tri + 6, sizeof tmp);
    memcpy(g.tri + 6, tmp, sizeof tmp);
    assert_int_equal(ms_closed_find(g.tri, g.n, &c), 0);
    assert_int_equal(c.n_components, 0);
    ms_closed_free(&c);

    /* two boxes and an open quad: two closed components with their boxes; a degenerate triangle alone */
    tm_mesh h = { 0 };
    const double lo1[3] = { 0, 0, 0 }, hi1[3] = { 1, 2, 3 }, lo2[3] = { 5, 5, 5 }, hi2[3] = { 6, 6, 7 };
    tm_box(&h, lo1, hi1, 0);
    tm_box(&h, lo2, hi2, 1);
    const double q0[3] = { 10, 0, 0 }, q1[3] = { 11, 0, 0 }, q2[3] = { 11, 0, 1 }, q3[3] = { 10, 0, 1 };
    tm_add_tri(&h, q0, q1, q2);
    tm_add_tri(&h, q0, q2, q3);
    tm_add_tri(&h, q0, q0, q1);
    assert_int_equal(ms_closed_find(h.tri, h.n, &c), 0);
    assert_int_equal(c.n_components, 2);
    assert_int_equal(c.closed_tris, 24);
    assert_int_equal(c.outward[c.component[0]], 1);
    assert_int_equal(c.outward[c.component[12]], -1);
    for (int k = 24; k < 27; k++) assert_int_equal(c.component[k], MS_OPEN_COMPONENT);
    const float want[6] = { 5, 5, 5, 6, 6, 7 };
    for (int k = 0; k < 6; k++) assert_true(c.box[c.component[12]][k] == want[k]);
    ms_closed_free(&c);

    /* two boxes touching along an edge (walked twice each way): two closed components, one of them wound
     * inwards; no union through the edge, so each keeps its own orientation */
    tm_mesh e = { 0 };
    const double e1lo[3] = { 0, 0, 0 }, e1hi[3] = { 1, 1, 1 }, e2lo[3] = { 1, 1, 0 }, e2hi[3] = { 2, 2, 1 };
    tm_box(&e, e1lo, e1hi, 0);
    tm_box(&e, e2lo, e2hi, 1);
    assert_int_equal(ms_closed_find(e.tri, e.n, &c), 0);
    assert_int_equal(c.n_components, 2);
    assert_int_equal(c.closed_tris, 24);
    assert_int_equal(c.outward[c.component[0]], 1);
    assert_int_equal(c.outward[c.component[12]], -1);
    ms_closed_free(&c);

    /* two octahedra sharing their equator (each of its edges walked twice each way): an octahedron alone is
     * closed, but here every pyramid is a component of its own (nothing unites through the equator) whose own
     * triangles walk the equator one way only: none is closed, though the edges balance */
    tm_mesh q = { 0 };
    const double eq[4][3] = { { 1, 0, 0 }, { 0, 0, -1 }, { -1, 0, 0 }, { 0, 0, 1 } };
    for (int s2 = 1; s2 <= 2; s2++) {
        const double top[3] = { 0, s2, 0 }, bot[3] = { 0, -s2, 0 };
        for (int i = 0; i < 4; i++) {
            tm_add_tri(&q, top, eq[i], eq[(i + 1) % 4]);
            tm_add_tri(&q, bot, eq[(i + 1) % 4], eq[i]);
        }
    }
    assert_int_equal(ms_closed_find(q.tri, 8, &c), 0);
    assert_int_equal(c.n_components, 1);
    assert_int_equal(c.outward[0], 1);
    ms_closed_free(&c);
    assert_int_equal(ms_closed_find(q.tri, q.n, &c), 0);
    assert_int_equal(c.n_components, 0);
    ms_closed_free(&c);
    free(m.tri); free(f.tri); free(g.tri); free(h.tri); free(e.tri); free(q.tri);
}

/* ---- the cull against a brute-force oracle ---- */

static int occluded(const tm_mesh *m, const uint8_t *keep, const double p[3], const double l[3])
{
    for (size_t t = 0; t < m->n; t++)
        if ((!keep || keep[t]) && tm_seg_hits(m->tri + 9 * t, p, l)) return 1;
    return 0;
}

/* A rect light: corner + s es + t et. Its corners for the cull, its box, and sample (s, t). */
typedef struct rect { double c[3], es[3], et[3]; } rect;

static void light_hull(const rect *L, float pts[4][3], float box[6])
{
    for (int q = 0; q < 4; q++)
        for (int a = 0; a < 3; a++) pts[q][a] = (float)(L->c[a] + (q & 1) * L->es[a] + (q >> 1) * L->et[a]);
    for (int a = 0; a < 3; a++) {
        box[a] = box[3 + a] = pts[0][a];
        for (int q = 1; q < 4; q++) { if (pts[q][a] < box[a]) box[a] = pts[q][a]; if (pts[q][a] > box[3 + a]) box[3 + a] = pts[q][a]; }
    }
}

/* Receivers (random points in the box [lo, hi]), samples on an 8x8 grid of the light: how many segments
 * the kept triangles answer differently from all triangles; *blocked counts the occluded ones. */
static size_t differences(const tm_mesh *m, const uint8_t *keep, const rect *L, const double lo[3], const double hi[3],
                          int receivers, unsigned seed, size_t *blocked)
{
    size_t diff = 0;
    *blocked = 0;
    for (int r = 0; r < receivers; r++) {
        double p[3];
        for (int a = 0; a < 3; a++) p[a] = lo[a] + (hi[a] - lo[a]) * tm_urand(&seed);
        for (int i = 0; i < 8; i++)
            for (int j = 0; j < 8; j++) {
                double l[3];
                for (int a = 0; a < 3; a++) l[a] = L->c[a] + (i + 0.5) / 8.0 * L->es[a] + (j + 0.5) / 8.0 * L->et[a];
                const int all = occluded(m, NULL, p, l);
                *blocked += (size_t)all;
                diff += (size_t)(all != occluded(m, keep, p, l));
            }
    }
    return diff;
}

static double far_margin(const tm_mesh *m, const float lbox[6])
{
    /* the far range times the longest segment: the scene's and the light's boxes together */
    float b[6] = { lbox[0], lbox[1], lbox[2], lbox[3], lbox[4], lbox[5] };
    for (size_t i = 0; i < 3 * m->n; i++)
        for (int a = 0; a < 3; a++) { const float x = m->tri[3 * i + (size_t)a]; if (x < b[a]) b[a] = x; if (x > b[3 + a]) b[3 + a] = x; }
    const double dx = (double)b[3] - b[0], dy = (double)b[4] - b[1], dz = (double)b[5] - b[2];
    return 2.0 * (1.0 - TM_FAR) * sqrt(dx * dx + dy * dy + dz * dz);
}

static void test_cull_exact(void **st)
{
    (void)st;
    /* jittered icospheres (some wound inwards), boxes, and an open ground quad, under a light above */
    tm_mesh m = { 0 };
    unsigned seed = 7;
    for (int i = 0; i < 6; i++) {
        const double c[3] = { -4 + 8 * tm_urand(&seed), 0.8 + 2 * tm_urand(&seed), -4 + 8 * tm_urand(&seed) };
        tm_icosphere(&m, c, 0.5 + 0.7 * tm_urand(&seed), 2, i == 3, 0.15, 100u + (unsigned)i);
    }
    const double blo[3] = { 2, 0.2, -1 }, bhi[3] = { 3, 2.5, 1.5 };
    tm_box(&m, blo, bhi, 0);
    /* two boxes touching along an edge, one wound inwards */
    const double plo[3] = { -3, 0.5, 2 }, phi[3] = { -2, 1.5, 3 }, qlo[3] = { -2, 1.5, 2 }, qhi[3] = { -1, 2.5, 3 };
    tm_box(&m, plo, phi, 0);
    tm_box(&m, qlo, qhi, 1);
    const double g0[3] = { -8, 0, -8 }, g1[3] = { 8, 0, -8 }, g2[3] = { 8, 0, 8 }, g3[3] = { -8, 0, 8 };
    tm_add_tri(&m, g0, g2, g1);
    tm_add_tri(&m, g0, g3, g2);
    ms_closed c;
    assert_int_equal(ms_closed_find(m.tri, m.n, &c), 0);
    assert_int_equal(c.n_components, 9);
    assert_int_equal(c.closed_tris, m.n - 2);
    const rect lights[2] = { { { -1.5, 7, -1.5 }, { 3, 0, 0 }, { 0, 0.5, 3 } },     /* above, tilted */
                             { { 9, 1, -2 }, { 0, 3, 0 }, { 0, 0, 4 } } };          /* to the side */
    uint8_t *keep = malloc(m.n);
    for (int li = 0; li < 2; li++) {
        float pts[4][3], lbox[6];
        light_hull(&lights[li], pts, lbox);
        const size_t culled = ms_closed_cull(&c, m.tri, (const float (*)[3])pts, 4, lbox, far_margin(&m, lbox), keep);
        /* roughly the half of each solid that faces away from the light */
        printf("light %d: %zu of %zu triangles culled\n", li, culled, m.n);
        assert_true(culled > m.n / 4 && culled < 3 * m.n / 4);
        /* receivers everywhere in the scene's box: on the ground, in the air, inside the solids */
        const double lo[3] = { -6, 0, -6 }, hi[3] = { 6, 4, 6 };
        size_t blocked;
        const size_t diff = differences(&m, keep, &lights[li], lo, hi, 1500, 11u + (unsigned)li, &blocked);
        printf("light %d: %zu of %d segments occluded, %zu answered differently after the cull\n", li, blocked,
               1500 * 64, diff);
        assert_true(blocked > 10000);
        assert_int_equal(diff, 0);
    }
    free(keep);
    ms_closed_free(&c);
    free(m.tri);
}

/* The guards matter: what a cull without them would do, judged by the same oracle. */
static void test_cull_guards(void **st)
{
    (void)st;
    /* A lamp inside a closed shade: the light's box meets the shade's, so nothing of it is culled; culling
     * its triangles facing away from the light anyway (the naive rule) lets light out. */
    tm_mesh m = { 0 };
    const double o[3] = { 0, 3, 0 };
    tm_icosphere(&m, o, 1.0, 2, 0, 0.0, 3);
    const double g0[3] = { -8, 0, -8 }, g1[3] = { 8, 0, -8 }, g2[3] = { 8, 0, 8 }, g3[3] = { -8, 0, 8 };
    tm_add_tri(&m, g0, g2, g1);
    tm_add_tri(&m, g0, g3, g2);
    ms_closed c;
    assert_int_equal(ms_closed_find(m.tri, m.n, &c), 0);
    const rect lamp = { { -0.2, 2.9, -0.2 }, { 0.4, 0, 0 }, { 0, 0, 0.4 } };
    float pts[4][3], lbox[6];
    light_hull(&lamp, pts, lbox);
    uint8_t *keep = malloc(m.n);
    assert_int_equal(ms_closed_cull(&c, m.tri, (const float (*)[3])pts, 4, lbox, far_margin(&m, lbox), keep), 0);
    /* the naive rule: every closed triangle whose outward plane has the lamp behind it */
    const float huge[6] = { 1e30f, 1e30f, 1e30f, 2e30f, 2e30f, 2e30f };   /* a box "far away": no guard */
    const size_t naive = ms_closed_cull(&c, m.tri, (const float (*)[3])pts, 4, huge, 0.0, keep);
    assert_true(naive > 0);
    const double lo[3] = { -5, 0, -5 }, hi[3] = { 5, 0.01, 5 };
    size_t blocked;
    const size_t leaks = differences(&m, keep, &lamp, lo, hi, 300, 5, &blocked);
    printf("lamp in a shade: the naive cull drops %zu triangles and answers %zu of %zu occluded segments wrong\n",
           naive, leaks, blocked);
    assert_true(blocked > 0 && leaks == blocked);   /* every occluded segment leaks */
    ms_closed_free(&c);
    free(keep);
    free(m.tri);

    /* A room modelled as one box wound inwards (its faces seen from inside), the sun outside: the
     * orientation from the signed volume makes the room's inside the solid, so the walls between a receiver
     * inside and the sun are kept; taking the winding as outward (the naive rule) culls them. */
    tm_mesh r = { 0 };
    const double rlo[3] = { -3, 0, -3 }, rhi[3] = { 3, 3, 3 };
    tm_box(&r, rlo, rhi, 1);
    assert_int_equal(ms_closed_find(r.tri, r.n, &c), 0);
    assert_int_equal(c.outward[0], -1);
    const rect sun = { { 10, 20, -5 }, { 4, 0, 0 }, { 0, 0, 4 } };
    light_hull(&sun, pts, lbox);
    keep = malloc(r.n);
    const size_t culled = ms_closed_cull(&c, r.tri, (const float (*)[3])pts, 4, lbox, far_margin(&r, lbox), keep);
    const double ilo[3] = { -2.9, 0.1, -2.9 }, ihi[3] = { 2.9, 2.9, 2.9 };
    size_t diff = differences(&r, keep, &sun, ilo, ihi, 300, 9, &blocked);
    printf("inward room: %zu of %zu triangles culled, %zu of %zu occluded segments answered differently\n", culled,
           r.n, diff, blocked);
    assert_true(culled > 0);
    assert_int_equal(blocked, 300 * 64);
    assert_int_equal(diff, 0);
    c.outward[0] = 1;   /* the naive rule: the winding taken as outward */
    ms_closed_cull(&c, r.tri, (const float (*)[3])pts, 4, lbox, far_margin(&r, lbox), keep);
    diff = differences(&r, keep, &sun, ilo, ihi, 300, 9, &blocked);
    assert_true(diff > 0);
    ms_closed_free(&c);
    free(keep);
    free(r.tri);
}


/* ---- interior boxes ---- */

/* Crossings of the ray p + t d, t > 0, with the triangles (double Moller-Trumbore; d chosen irrational so
 * that edges and vertices are not met in these cases). */
static int ray_crossings(const tm_mesh *m, const double p[3], const double d[3])
{
    int n = 0;
    for (size_t i = 0; i < m->n; i++) {
        const float *t = m->tri + 9 * i;
        double e1[3], e2[3], s[3], h[3], q[3];
        for (int a = 0; a < 3; a++) { e1[a] = (double)t[3 + a] - t[a]; e2[a] = (double)t[6 + a] - t[a]; s[a] = p[a] - t[a]; }
        h[0] = d[1] * e2[2] - d[2] * e2[1]; h[1] = d[2] * e2[0] - d[0] * e2[2]; h[2] = d[0] * e2[1] - d[1] * e2[0];
        const double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
        if (det == 0.0) continue;
        const double u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) / det;
        if (u < 0.0 || u > 1.0) continue;
        q[0] = s[1] * e1[2] - s[2] * e1[1]; q[1] = s[2] * e1[0] - s[0] * e1[2]; q[2] = s[0] * e1[1] - s[1] * e1[0];
        const double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
        if (v < 0.0 || u + v > 1.0) continue;
        n += (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det > 0.0;
    }
    return n;
}

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Distance from p to triangle t (closest point by regions, Ericson's "Real-Time Collision Detection" 5.1.5). */
static double point_tri_dist(const double p[3], const float *t)
{
    double a[3], b[3], c[3], ab[3], ac[3], ap[3], x[3];
    for (int k = 0; k < 3; k++) {
        a[k] = t[k]; b[k] = t[3 + k]; c[k] = t[6 + k];
        ab[k] = b[k] - a[k]; ac[k] = c[k] - a[k]; ap[k] = p[k] - a[k];
    }
    const double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) { memcpy(x, a, sizeof x); goto done; }
    double bp[3], cp[3];
    for (int k = 0; k < 3; k++) { bp[k] = p[k] - b[k]; cp[k] = p[k] - c[k]; }
    const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) { memcpy(x, b, sizeof x); goto done; }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) { for (int k = 0; k < 3; k++) x[k] = a[k] + d1 / (d1 - d3) * ab[k]; goto done; }
    const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) { memcpy(x, c, sizeof x); goto done; }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) { for (int k = 0; k < 3; k++) x[k] = a[k] + d2 / (d2 - d6) * ac[k]; goto done; }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++) x[k] = b[k] + w * (c[k] - b[k]);
        goto done;
    }
    {
        const double den = 1.0 / (va + vb + vc), v = vb * den, w = vc * den;
        for (int k = 0; k < 3; k++) x[k] = a[k] + ab[k] * v + ac[k] * w;
    }
done:;
    double d[3];
    for (int k = 0; k < 3; k++) d[k] = p[k] - x[k];
    return sqrt(dot3(d, d));
}

/* Every box of in: corners, centre and random points inside their cycle (odd crossings along two
 * directions) and at least eps from each of its triangles. The cycle's triangles are those of m's first n
 * with that cycle number. Returns the boxes checked. */
static size_t check_boxes(const tm_mesh *m, size_t n, const ms_closed *c, const ms_interior *in, double eps)
{
    unsigned seed = 5;
    for (size_t b = 0; b < in->n_boxes; b++) {
        tm_mesh comp = { 0 };
        for (size_t t = 0; t < n; t++)
            if (c->cycle[t] == in->component[b]) {
                const float *f = m->tri + 9 * t;
                const double p0[3] = { f[0], f[1], f[2] }, p1[3] = { f[3], f[4], f[5] }, p2[3] = { f[6], f[7], f[8] };
                tm_add_tri(&comp, p0, p1, p2);
            }
        const float *bx = in->box[b];
        for (int a = 0; a < 3; a++) assert_true(bx[a] <= bx[3 + a]);
        for (int sidx = 0; sidx < 12; sidx++) {
            double p[3];
            for (int a = 0; a < 3; a++) {
                const double f = sidx < 8 ? (double)(sidx >> a & 1) : sidx == 8 ? 0.5 : tm_urand(&seed);
                p[a] = bx[a] + f * ((double)bx[3 + a] - bx[a]);
            }
            const double d1[3] = { 0.5773, 0.6181, 0.5331 }, d2[3] = { -0.3119, 0.8423, -0.4397 };
            assert_int_equal(ray_crossings(&comp, p, d1) % 2, 1);
            assert_int_equal(ray_crossings(&comp, p, d2) % 2, 1);
            double dmin = INFINITY;
            for (size_t t = 0; t < comp.n; t++) dmin = fmin(dmin, point_tri_dist(p, comp.tri + 9 * t));
            assert_true(dmin >= eps);
        }
        free(comp.tri);
    }
    return in->n_boxes;
}

static void test_interior_boxes(void **st)
{
    (void)st;
    const double eps = 2e-3;
    /* a jittered sphere; a hollow shell (an outer sphere and an inner one wound inwards: two components,
     * each with its own inside); a box */
    tm_mesh m = { 0 };
    const double c0[3] = { 0, 0, 0 }, c1[3] = { 3, 0.5, -1 };
    tm_icosphere(&m, c0, 1.0, 4, 0, 0.1, 3);
    tm_icosphere(&m, c1, 1.0, 3, 0, 0.0, 0);
    tm_icosphere(&m, c1, 0.6, 3, 1, 0.0, 0);
    const double lo[3] = { -2, -3, 1.5 }, hi[3] = { -1, -2.5, 3 };
    tm_box(&m, lo, hi, 0);
    ms_closed c;
    assert_int_equal(ms_closed_find(m.tri, m.n, &c), 0);
    assert_int_equal(c.n_components, 4);
    ms_interior in;
    assert_int_equal(ms_interior_find(m.tri, m.n, &c, 24, 0, eps, 2, &in), 0);
    assert_int_equal(c.n_cycles, 4);   /* every closed component is a cycle */
    int per[4] = { 0 };
    for (size_t b = 0; b < in.n_boxes; b++) per[in.component[b]]++;
    for (int k = 0; k < 4; k++) assert_true(per[k] > 0);
    assert_int_equal(check_boxes(&m, m.n, &c, &in, eps), in.n_boxes);
    /* min_tris leaves out the small ones */
    ms_interior_free(&in);
    assert_int_equal(ms_interior_find(m.tri, m.n, &c, 24, 2000, eps, 2, &in), 0);
    for (size_t b = 0; b < in.n_boxes; b++) assert_int_equal(c.cycle[0], in.component[b]);
    assert_true(in.n_boxes > 0);
    ms_interior_free(&in);
    ms_closed_free(&c);
    /* open: the sphere less one triangle is no cycle; capped, a holed set (its boxes: test_holes.c) */
    assert_int_equal(ms_closed_find(m.tri, 5119, &c), 0);
    assert_int_equal(ms_interior_find(m.tri, 5119, &c, 24, 0, eps, 2, &in), 0);
    assert_int_equal(c.n_cycles, 0);
    assert_int_equal(c.n_holed, 1);
    for (size_t b = 0; b < in.n_boxes; b++) assert_int_equal(in.component[b], 0);
    ms_interior_free(&in);
    ms_closed_free(&c);
    /* a flipped triangle: no closed component any more, still a cycle with an inside */
    float tmp[3];
    memcpy(tmp, m.tri + 3, sizeof tmp);
    memcpy(m.tri + 3, m.tri + 6, sizeof tmp);
    memcpy(m.tri + 6, tmp, sizeof tmp);
    assert_int_equal(ms_closed_find(m.tri, 5120, &c), 0);
    assert_int_equal(c.n_components, 0);
    assert_int_equal(c.n_cycles, 1);
    assert_int_equal(ms_interior_find(m.tri, 5120, &c, 24, 0, eps, 2, &in), 0);
    assert_true(in.n_boxes > 0);
    assert_int_equal(check_boxes(&m, 5120, &c, &in, eps), in.n_boxes);
    ms_interior_free(&in);
    ms_closed_free(&c);
    free(m.tri);
}

/* V of a frame by method with the options' switches (vis copied out, the stats kept). */
static float *frame_vis(const ms_scene *sc, const char *method, ms_traversal trav, int no_interior, ms_closed_cull_mode cull,
                        ms_stats *stats)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.traversal = trav;
    o.no_interior = no_interior;
    o.closed_cull = cull;
    o.threads = 2;
    return tu_render_vis(sc, &o, stats);
}

static void test_interior_frames(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    /* the ground of the Quad, and a dense sphere (5120 triangles) instead of its occluder */
    tm_mesh m = { 0 };
    tm_ground(&m);
    const double c[3] = { 0.3, 1.6, -0.2 };
    tm_icosphere(&m, c, 1.2, 4, 0, 0.08, 11);
    /* and a thin closed bar (12 triangles: no interior boxes) */
    const double blo[3] = { -2.5, 0.8, 1.3 }, bhi[3] = { 2.5, 0.9, 1.4 };
    tm_box(&m, blo, bhi, 0);
    free(sc.tri);
    sc.tri = m.tri;
    sc.n_tris = m.n;
    sc.camera.width = sc.camera.height = 64;
    sc.camera.eye = (ms_vec3){ 1, 5, 5 };   /* closer than the Quad's: the sphere and its shadow fill the frame */
    sc.camera.target = (ms_vec3){ 0, 0.5f, 0 };
    const int npix = 64 * 64;
    for (int light = 0; light < 2; light++) {
        if (light == 1) sc.light.corner = (ms_vec3){ 1.2f, 2.4f, 0.6f };   /* beside the sphere, within its box: no boxes */
        ms_stats s_int, s_rt;
        float *v_int = frame_vis(&sc, "scanline", MS_TRAVERSAL_BLOCK, 0, MS_CLOSED_CULL_DEFAULT, &s_int);
        float *v_no = frame_vis(&sc, "scanline", MS_TRAVERSAL_BLOCK, 1, MS_CLOSED_CULL_OFF, NULL);
        float *v_pix = frame_vis(&sc, "scanline", MS_TRAVERSAL_PIXEL, 0, MS_CLOSED_CULL_DEFAULT, NULL);
        float *v_hier = frame_vis(&sc, "hierarchical", MS_TRAVERSAL_BLOCK, 0, MS_CLOSED_CULL_OFF, NULL);
        float *v_rt = frame_vis(&sc, "raytrace", MS_TRAVERSAL_BLOCK, 0, MS_CLOSED_CULL_DEFAULT, &s_rt);
        ms_stats s_rtc, s_mft, s_mft_no;
        float *v_rtc = frame_vis(&sc, "raytrace", MS_TRAVERSAL_BLOCK, 0, MS_CLOSED_CULL_ON, &s_rtc);
        /* mft takes the boxes through the driver's interior pass (MS_OCC_INTERIOR_PASS), raytrace's V */
        float *v_mft = frame_vis(&sc, "mft", MS_TRAVERSAL_BLOCK, 0, MS_CLOSED_CULL_DEFAULT, &s_mft);
        float *v_mft_no = frame_vis(&sc, "mft", MS_TRAVERSAL_BLOCK, 1, MS_CLOSED_CULL_DEFAULT, &s_mft_no);
        /* the default: the micro-raster methods cull (the bar's bottom and a side, and the sphere's back, which
         * also has interior boxes), raytrace nothing; asked to, raytrace culls the same; for the light within the
         * sphere's box, only the bar */
        assert_int_equal(s_rt.occluders_culled, 0);
        assert_true(light == 0 ? s_rtc.occluders_culled > 1000 : s_rtc.occluders_culled > 0 && s_rtc.occluders_culled <= 12);
        assert_int_equal(s_int.occluders_culled, s_rtc.occluders_culled);
        if (light == 0) {
            assert_true(s_int.interior_boxes > 0);
            assert_true(tu_stat_counter(&s_int, "interior_rasterized") > 0);
            /* mft takes them as triangles, on the coarser grid (occluders.h, ms_interior_res) */
            assert_true(s_mft.interior_boxes > 0 && s_mft.interior_boxes <= s_int.interior_boxes);
            /* the pass ran: the blocks of the boxes' pass come before those of the triangles' */
            assert_true(tu_stat_counter(&s_mft, "blocks") > tu_stat_counter(&s_mft_no, "blocks"));
        } else {
            assert_int_equal(s_int.interior_boxes, 0);
            assert_int_equal(s_mft.interior_boxes, 0);
        }
        assert_int_equal(s_rt.interior_boxes, 0);   /* raytrace takes none: it is the reference here */
        int shadowed = 0;
        for (int i = 0; i < npix; i++) shadowed += v_rt[i] >= 0.0f && v_rt[i] < 1.0f;
        print_message("light %d: %d shadowed pixels\n", light, shadowed);
        assert_true(shadowed > npix / 10);
        assert_memory_equal(v_int, v_no, npix * sizeof *v_int);
        assert_memory_equal(v_int, v_pix, npix * sizeof *v_int);
        assert_memory_equal(v_int, v_hier, npix * sizeof *v_int);
        assert_memory_equal(v_int, v_rt, npix * sizeof *v_int);
        assert_memory_equal(v_int, v_rtc, npix * sizeof *v_int);
        assert_memory_equal(v_mft, v_rt, npix * sizeof *v_int);
        assert_memory_equal(v_mft_no, v_rt, npix * sizeof *v_int);
        free(v_int); free(v_no); free(v_pix); free(v_hier); free(v_rt); free(v_rtc); free(v_mft); free(v_mft_no);
    }
    ms_scene_free(&sc);
}

/* The points API (a bake's path) with the boxes: the same V as raytrace, point for point, on the ground
 * under the sphere and on the sphere itself. */
static void test_interior_points(void **st)
{
    (void)st;
    tm_mesh m = { 0 };
    tm_ground(&m);
    const double c[3] = { 0.3, 1.6, -0.2 };
    tm_icosphere(&m, c, 1.2, 4, 0, 0.08, 11);
    ms_scene sc;
    tu_make_quad(&sc);
    free(sc.tri);
    sc.tri = m.tri;
    sc.n_tris = m.n;
    ms_accel *acc;
    char err[256];
    assert_int_equal(ms_accel_build(&sc, 2, &acc, err, sizeof err), MS_OK);
    /* 2000 points: on the ground within 3 of the sphere's foot (triangle 0 or 1), and the sphere's
     * triangles' centroids (their own triangle) */
    const size_t n = 2000;
    float *pos = malloc(n * 3 * sizeof *pos), *nrm = malloc(n * 3 * sizeof *nrm);
    uint32_t *tri = malloc(n * sizeof *tri);
    unsigned seed = 77;
    for (size_t i = 0; i < n; i++) {
        if (i % 2) {
            const double x = -2.7 + 6.0 * tm_urand(&seed), z = -3.2 + 6.0 * tm_urand(&seed);
            pos[3 * i] = (float)x; pos[3 * i + 1] = 0.0f; pos[3 * i + 2] = (float)z;
            nrm[3 * i] = 0.0f; nrm[3 * i + 1] = 1.0f; nrm[3 * i + 2] = 0.0f;
            tri[i] = 0;   /* x, z on either ground triangle: both lie in the plane y = 0; 0 keeps its own out */
        } else {
            const uint32_t t = 2 + (uint32_t)(tm_urand(&seed) * 5120.0) % 5120;
            tm_centroid_normal(m.tri + 9 * (size_t)t, pos + 3 * i, nrm + 3 * i);
            tri[i] = t;
        }
    }
    const ms_points pts = { n, pos, nrm, tri, NULL };
    float *v_sl = malloc(n * sizeof *v_sl), *v_rt = malloc(n * sizeof *v_rt);
    ms_points_options o = { 0 };
    o.threads = 2;
    o.isa = tu_isa_cap();
    ms_stats s_sl;
    o.method = "scanline";
    assert_int_equal(ms_visibility_points(acc, &sc.light, &pts, &o, v_sl, NULL, NULL, &s_sl, err, sizeof err), MS_OK);
    o.method = "raytrace";
    assert_int_equal(ms_visibility_points(acc, &sc.light, &pts, &o, v_rt, NULL, NULL, NULL, err, sizeof err), MS_OK);
    assert_true(s_sl.interior_boxes > 0);
    int shadowed = 0;
    for (size_t i = 0; i < n; i++) shadowed += v_rt[i] >= 0.0f && v_rt[i] < 1.0f;
    assert_true(shadowed > 200);
    assert_memory_equal(v_sl, v_rt, n * sizeof *v_sl);
    free(v_sl); free(v_rt); free(pos); free(nrm); free(tri);
    ms_accel_free(acc);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_topology),
        cmocka_unit_test(test_cull_exact),
        cmocka_unit_test(test_cull_guards),
        cmocka_unit_test(test_interior_boxes),
        cmocka_unit_test(test_interior_frames),
        cmocka_unit_test(test_interior_points),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
