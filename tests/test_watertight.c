/* Issue 9, item 3: visibility is watertight. No ray slips between two triangles that share an edge,
 * in any method.
 *
 *  - test_triangle_oracle: the watertight ray/triangle test (src/accel/ray_triangle.h) against a
 *    double-precision plane-and-barycentrics oracle, on random rays not within a margin of an edge.
 *  - test_grazing_t: rays grazing long triangles from just beside their plane: t accurate to the
 *    plane distance's rounding, so the near threshold is decided right (the receiver-at-a-crease case).
 *  - test_fan_vertex_and_edges: rays aimed exactly at the centre vertex and at float points on the
 *    shared edges of jittered, closed triangle fans hit at least one triangle of the fan, every time;
 *    per triangle (ms_intersect_triangle) and through the BVH (closest and any hit: the boxes must be
 *    conservative enough for the triangle test). The old two-sided Moller-Trumbore (kept below as the
 *    counter-example, not as an oracle) misses some: measured 833 of 60000 fan rays (1.4%) on this
 *    test's fans (827 through the old BVH), 0 for the watertight test.
 *  - test_flat_grid_vertices: rays through the shared vertices of a flat jittered grid, whose BVH
 *    boxes are all flat with the vertices on their faces, through BVH closest and any hit.
 *  - test_light_leak: a closed, finely and irregularly tessellated occluder (a jittered "pillow"
 *    of two height-field sheets sharing their rim, shared vertices) around the light; a ground plane
 *    below it, seen from a camera under the occluder. Every shadow method of ms_method_names() must
 *    report V == 0 exactly at every pixel; 7.8e6 sample tests. The scene is put far from the origin
 *    as well, where rounding is coarse relative to the triangles. The old code leaked 11 samples here
 *    (raytrace 4 + 1, Embree's default mode 4 + 2; the micro-rasterizers none).
 *  - test_primary_cracks: the camera inside a closed, jittered 20480-triangle icosphere: every primary
 *    method (our BVH's and Embree's) hits every pixel, at several resolutions, directly through the
 *    primary interface and end to end through ms_render (V != -1 everywhere). The old code missed 5
 *    pixels, all at 1024x1024 (BVH 3 + 1, Embree's default mode 1).
 *  - test_kernels_shared_edges: the micro-rasterization kernels (every kernel, k and ISA variant) on
 *    a jittered mesh covering the light's frustum whose vertices lie on sample rays, so that samples
 *    fall on shared edges: no sample stays visible. (Samples on shared vertices are counted, not
 *    asserted: the kernels are not watertight there, see the test.)
 *
 * "Old code": this file built against commit 6956bd6 (Moller-Trumbore with sliver rejection, the
 * previous box test, Embree's default mode); each test prints its counts. The old code also fails
 * test_grazing_t (433 hits on the wrong side of near) and test_flat_grid_vertices (7.7% missed).
 * `test_watertight --only <test name>` runs one test (tu_run_tests). */
#include "testutil.h"
#include "accel/bvh.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "raster/raster.h"
#include "accel/ray_triangle.h"
#include "visibility/lanes16.h"
#include "visibility/wt_rays16.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double rnd(tu_rng *r) { return (double)(tu_rng_next(r) >> 11) * (1.0 / 9007199254740992.0); }   /* [0,1) */
static float rndf(tu_rng *r, float lo, float hi) { return lo + (hi - lo) * (float)rnd(r); }

/* The previous ray test (two-sided Moller-Trumbore), for counting what it missed; not an oracle. */
static int mt_intersect(const float tri[9], const float o[3], const float d[3], float tmin, float tmax)
{
    float e1[3], e2[3], p[3], s[3], q[3];
    for (int a = 0; a < 3; a++) { e1[a] = tri[3 + a] - tri[a]; e2[a] = tri[6 + a] - tri[a]; s[a] = o[a] - tri[a]; }
    p[0] = d[1] * e2[2] - d[2] * e2[1]; p[1] = d[2] * e2[0] - d[0] * e2[2]; p[2] = d[0] * e2[1] - d[1] * e2[0];
    float det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (det == 0.0f) return 0;
    float inv = 1.0f / det;
    float u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) * inv;
    if (!(u >= 0.0f && u <= 1.0f)) return 0;
    q[0] = s[1] * e1[2] - s[2] * e1[1]; q[1] = s[2] * e1[0] - s[0] * e1[2]; q[2] = s[0] * e1[1] - s[1] * e1[0];
    float v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
    if (!(v >= 0.0f && u + v <= 1.0f)) return 0;
    float t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
    return t >= tmin && t <= tmax;
}

/* ---- a: the triangle test ---- */

static void test_triangle_oracle(void **st)
{
    (void)st;
    tu_rng g = { 91 };
    int hits = 0, misses = 0;
    for (int it = 0; it < 40000; it++) {
        float tri[9], o[3], d[3];
        float scale = it % 3 == 0 ? 1e-3f : it % 3 == 1 ? 1.0f : 300.0f;    /* rounding at every scale */
        float off = it % 5 == 0 ? 1000.0f : 0.0f;
        for (int k = 0; k < 9; k++) tri[k] = off + scale * rndf(&g, -2, 2);
        for (int a = 0; a < 3; a++) o[a] = off + scale * rndf(&g, -4, 4);
        /* aim at a point of the plane with barycentrics in [-0.4, 1.4]; a quarter pointing away */
        double b1 = rnd(&g) * 1.8 - 0.4, b2 = (rnd(&g) * 1.8 - 0.4) * (1 - b1);
        for (int a = 0; a < 3; a++)
            d[a] = (float)(tri[a] + b1 * ((double)tri[3 + a] - tri[a]) + b2 * ((double)tri[6 + a] - tri[a]) - o[a]);
        if (it % 4 == 0) for (int a = 0; a < 3; a++) d[a] = -d[a];
        /* oracle: plane intersection and signed sub-areas, in double */
        double e1[3], e2[3], n[3];
        for (int a = 0; a < 3; a++) { e1[a] = (double)tri[3 + a] - tri[a]; e2[a] = (double)tri[6 + a] - tri[a]; }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1]; n[1] = e1[2] * e2[0] - e1[0] * e2[2]; n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2], dn = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
        double dl = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
        if (nn < 1e-4 * scale * scale * scale * scale || fabs(dn) < 0.05 * sqrt(nn) * dl) continue;
        double t = (n[0] * (tri[0] - (double)o[0]) + n[1] * (tri[1] - (double)o[1]) + n[2] * (tri[2] - (double)o[2])) / dn;
        double p[3], w[3];
        for (int a = 0; a < 3; a++) p[a] = o[a] + t * d[a];
        for (int k = 0; k < 3; k++) {
            const float *A = tri + 3 * ((k + 1) % 3), *B = tri + 3 * ((k + 2) % 3);
            double ab[3], ap[3];
            for (int a = 0; a < 3; a++) { ab[a] = (double)B[a] - A[a]; ap[a] = p[a] - A[a]; }
            w[k] = ((ab[1] * ap[2] - ab[2] * ap[1]) * n[0] + (ab[2] * ap[0] - ab[0] * ap[2]) * n[1] +
                    (ab[0] * ap[1] - ab[1] * ap[0]) * n[2]) / nn;
        }
        /* away from ties: 1e-3 in barycentrics (1e-2 far from the origin, where the inputs round) */
        double margin = off > 0 ? 1e-2 : 1e-3;
        if (fabs(w[0]) < margin || fabs(w[1]) < margin || fabs(w[2]) < margin || fabs(t) < 1e-3) continue;
        int want = w[0] > 0 && w[1] > 0 && w[2] > 0 && t > 0;
        float ft, fu, fv;
        int got = ms_intersect_triangle(tri, o, d, 0.0f, INFINITY, &ft, &fu, &fv);
        if (got != want) print_message("it %d: watertight %d, oracle %d (w %g %g %g, t %g)\n", it, got, want, w[0], w[1], w[2], t);
        assert_int_equal(got, want);
        if (got) {
            assert_true(fabs(ft - t) <= 1e-4 * (1 + fabs(t)) * (off > 0 ? 10 : 1));
            assert_true(fabs(fu - w[1]) < margin * 0.1 && fabs(fv - w[2]) < margin * 0.1);
            /* [tmin, tmax] is inclusive of the reported t and excludes anything past it */
            assert_true(ms_intersect_triangle(tri, o, d, ft, ft, &ft, &fu, &fv));
            assert_false(ms_intersect_triangle(tri, o, d, 0.0f, nextafterf(ft, 0.0f), &ft, &fu, &fv));
            hits++;
        } else {
            misses++;
        }
    }
    print_message("watertight triangle test vs double oracle: %d hits, %d misses\n", hits, misses);
    assert_true(hits > 2000 && misses > 2000);
}

/* The 16-lane forms of the segment test (visibility/wt_rays16.h, here in lanes16.h's portable C: the ISA forms are
 * the same IEEE operations, compared with it through the methods' ISA instances in test_hpc and test_mft):
 * ms_wt_rays16_own, each ray with its own shear axis, against the scalar ms_wt_segment bit for bit, and
 * ms_wt_offset16 against ms_wt_offset. The rays go every way (each axis the largest, either sign, so the winding
 * swap ms_wt_rays16_own leaves out happens), half of them aimed at the triangle's vertices, at float points of its
 * edges or along its edges' lines (ties, exact zeros: the double fall-back the caller redoes), the rest near it;
 * origins on the triangle's plane, near it, far; segments ending short of the plane (t beyond far) or starting
 * past it. */
#define LANES 16
static void test_rays16_lanes(void **st)
{
    (void)st;
    tu_rng g = { 97 };
    const float near = 1e-4f, far = 1.0f - 1e-4f;
    long hits = 0, tested = 0, zeros = 0, swapped = 0, axes[3] = { 0, 0, 0 };
    for (int it = 0; it < 4000; it++) {
        float tri[9], N[3];
        const float scale = it % 3 == 0 ? 1e-2f : it % 3 == 1 ? 1.0f : 100.0f, off = it % 7 == 0 ? 500.0f : 0.0f;
        for (int k = 0; k < 9; k++) tri[k] = off + scale * rndf(&g, -1, 1);
        if (it % 5 == 0) tri[1] = tri[4] = tri[7];   /* an axis-aligned plane: exact zeros along its lines */
        ms_wt_normal(tri, N);
        float O[3][LANES], D[3][LANES];
        l16 V[3][3];
        float vv[3][3][LANES];
        for (int l = 0; l < LANES; l++) {
            float o[3], target[3];
            const int kind = (int)(tu_rng_next(&g) % 6);
            const int e = (int)(tu_rng_next(&g) % 3), e2 = (e + 1) % 3;
            const float s = rndf(&g, -0.5f, 1.5f);
            for (int a = 0; a < 3; a++) {
                const float A = tri[3 * e + a], B = tri[3 * e2 + a];
                target[a] = kind == 0 ? A                                   /* a vertex */
                          : kind == 1 ? A + 0.5f * (B - A)                   /* a float point of an edge */
                          : kind == 2 ? A + s * (B - A)                      /* on the edge's line */
                          : off + scale * rndf(&g, -1.2f, 1.2f);             /* near the triangle */
                o[a] = off + scale * rndf(&g, -3, 3);
            }
            if (l % 4 == 0) for (int a = 0; a < 3; a++) o[a] = tri[a] + 0.25f * (tri[3 + a] - tri[a]) + 0.25f * (tri[6 + a] - tri[a]);
            const float reach = l % 3 == 0 ? 0.5f : l % 3 == 1 ? 2.0f : 1.0f;   /* short of the plane, past it, at it */
            for (int a = 0; a < 3; a++) { O[a][l] = o[a]; D[a][l] = reach * (target[a] - o[a]); }
            if (l % 5 == 1) for (int a = 0; a < 3; a++) D[a][l] = -D[a][l];
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) vv[v][a][l] = tri[3 * v + a] - o[a];
        }
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) V[v][a] = l16_load(vv[v][a]);
        const l16 d[3] = { l16_load(D[0]), l16_load(D[1]), l16_load(D[2]) };
        const l16 num = ms_wt_offset16((const l16 (*)[3])V, N);
        float numv[LANES];
        l16_store(numv, num);
        unsigned zero;
        const unsigned hit = ms_wt_rays16_own((const l16 (*)[3])V, d, N, num, near, far, 0xffffu, &zero);
        for (int l = 0; l < LANES; l++) {
            const float o[3] = { O[0][l], O[1][l], O[2][l] }, dl[3] = { D[0][l], D[1][l], D[2][l] };
            const float num1 = ms_wt_offset(o, tri, N);
            assert_memory_equal(&numv[l], &num1, sizeof num1);
            const int want = ms_wt_segment(o, dl, tri, N, near, far);
            const int kz = ms_wt_max_axis(dl);
            axes[kz]++;
            swapped += dl[kz] < 0.0f;
            tested++;
            if (zero >> l & 1u) { zeros++; continue; }   /* the caller's: ms_wt_segment itself */
            if ((int)(hit >> l & 1u) != want)
                print_message("it %d lane %d: lanes %u, scalar %d\n", it, l, hit >> l & 1u, want);
            assert_int_equal((int)(hit >> l & 1u), want);
            hits += want;
        }
    }
    print_message("ms_wt_rays16_own = ms_wt_segment on %ld rays (%ld hits; %ld with an edge exactly 0, left to the caller; "
                  "largest axis x %ld, y %ld, z %ld; %ld with d[kz] < 0)\n", tested - zeros, hits, zeros, axes[0], axes[1],
                  axes[2], swapped);
    assert_true(hits > 2000 && tested - zeros - hits > 5000);
    assert_true(zeros > 100 && swapped > 10000 && axes[0] > 10000 && axes[1] > 10000 && axes[2] > 10000);
}

/* Rays grazing long triangles from just beside their plane (a receiver next to a crease): t must be
 * accurate to the rounding of the plane distance, not of the vertices' distance, or a neighbour that
 * the segment crosses behind its origin (t < 0) is reported in front, at t > near: false occlusion.
 * Measured on these rays (units: ulps of the origin's distance to the nearest vertex over the grazing
 * angle, the inputs' own uncertainty): the paper's t = T / det, 368 units, 32 of 7738 hits on the
 * wrong side of near = 1e-4 (in Dabrovic Sponza: t = +1.9e-4 for -5.2e-4, false self-shadowing at a
 * crease); the old Moller-Trumbore, 964 units, 433 wrong; the plane distance with N from the two long
 * edges, as many wrong; now (N from the two shortest edges, nearest vertex): 1.94 units, 0 wrong. */
static void test_grazing_t(void **st)
{
    (void)st;
    tu_rng g = { 94 };
    int checked = 0, wrong = 0;
    double worst = 0, worst_units = 0;
    for (int it = 0; it < 20000; it++) {
        /* a triangle 10 long and 0.02 wide around a random frame, near or far from the origin */
        float off = it % 2 ? 0.0f : 200.0f;
        double c[3] = { off + rnd(&g) * 4 - 2, rnd(&g) * 4 - 2, rnd(&g) * 4 - 2 }, e[3], f[3], n[3];
        for (int a = 0; a < 3; a++) e[a] = rnd(&g) * 2 - 1;
        double el = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        for (int a = 0; a < 3; a++) e[a] /= el;
        do {
            for (int a = 0; a < 3; a++) f[a] = rnd(&g) * 2 - 1;
            double fe = f[0] * e[0] + f[1] * e[1] + f[2] * e[2];
            for (int a = 0; a < 3; a++) f[a] -= fe * e[a];
        } while (f[0] * f[0] + f[1] * f[1] + f[2] * f[2] < 0.01);
        double fl = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        for (int a = 0; a < 3; a++) f[a] /= fl;
        n[0] = e[1] * f[2] - e[2] * f[1]; n[1] = e[2] * f[0] - e[0] * f[2]; n[2] = e[0] * f[1] - e[1] * f[0];
        float tri[9], o[3], d[3];
        for (int a = 0; a < 3; a++) {
            tri[a] = (float)(c[a] - 5 * e[a]);
            tri[3 + a] = (float)(c[a] + 5 * e[a]);
            tri[6 + a] = (float)(c[a] + 5 * e[a] + 0.02 * f[a]);
        }
        /* origin 1e-5..1e-4 off the plane, near the long edge; direction along the triangle or across
         * it (half the rays: across its width, a little along it), tilted by 0.002..0.01 towards or
         * away from the plane */
        double h = (1e-5 + 9e-5 * rnd(&g)) * (it & 2 ? 1 : -1), s0 = rnd(&g) * 6 - 3, tilt = (0.002 + 0.008 * rnd(&g)) * (it & 4 ? 1 : -1);
        double L = 2 + 3 * rnd(&g), along = it & 16 ? 0.6 * (rnd(&g) - 0.5) : (it & 8 ? 1 : -1), across = it & 16 ? (it & 8 ? 1 : -1) : 0;
        for (int a = 0; a < 3; a++) {
            o[a] = (float)(c[a] + s0 * e[a] + 0.01 * f[a] + h * n[a]);
            d[a] = (float)(L * (e[a] * along + f[a] * across + tilt * n[a]));
        }
        /* double oracle on the float inputs */
        double E1[3], E2[3], N[3], num = 0, den = 0;
        for (int a = 0; a < 3; a++) { E1[a] = (double)tri[3 + a] - tri[a]; E2[a] = (double)tri[6 + a] - tri[a]; }
        N[0] = E1[1] * E2[2] - E1[2] * E2[1]; N[1] = E1[2] * E2[0] - E1[0] * E2[2]; N[2] = E1[0] * E2[1] - E1[1] * E2[0];
        for (int a = 0; a < 3; a++) { num += ((double)tri[a] - o[a]) * N[a]; den += (double)d[a] * N[a]; }
        double t = num / den;
        float ft, fu, fv;
        if (!ms_intersect_triangle(tri, o, d, -INFINITY, INFINITY, &ft, &fu, &fv)) continue;
        checked++;
        /* bound: 8 ulps of the origin's distance to the nearest vertex, over the angle, plus 4 ulps of t */
        double nl = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]), dmin = INFINITY;
        for (int v = 0; v < 3; v++) {
            double q = 0;
            for (int a = 0; a < 3; a++) q += ((double)tri[3 * v + a] - o[a]) * ((double)tri[3 * v + a] - o[a]);
            dmin = fmin(dmin, sqrt(q));
        }
        double unit = 0x1p-24 * (dmin * nl / fabs(den) + fabs(t));
        double err = fabs(ft - t);
        if (err > worst) worst = err;
        if (err / unit > worst_units) worst_units = err / unit;
        /* the occlusion decision at near = 1e-4 must follow the true t when it is not a tie */
        if (fabs(t - 1e-4) > 2e-5 && (ft >= 1e-4f) != (t >= 1e-4)) wrong++;
    }
    print_message("grazing rays: %d hits checked, largest |t - t_double| %.3g (%.2f ulps of distance / angle), %d wrong sides "
                  "of near = 1e-4\n", checked, worst, worst_units, wrong);
    assert_true(checked > 5000);
    assert_true(worst_units < 8);
    assert_int_equal(wrong, 0);
}

/* A closed fan: centre c, rim p[0..n-1] (jittered, not planar), triangles (c, p[i], p[i+1 mod n]).
 * Rim and centre are around `base`, of radius r. A height field over x, z with slopes below 30
 * degrees, so that rays steeper than 45 degrees cross it once, through no silhouette edge (where a
 * ray could legitimately graze past both triangles). */
static void make_fan(tu_rng *g, const float base[3], float r, int n, float *tri)
{
    float c[3] = { base[0] + rndf(g, -0.1f, 0.1f) * r, base[1] + rndf(g, -0.05f, 0.05f) * r, base[2] + rndf(g, -0.1f, 0.1f) * r };
    float rim[64][3];
    double phase = rnd(g) * 6.283185307179586;
    for (int i = 0; i < n; i++) {
        double a = phase + 6.283185307179586 * (i + 0.6 * (rnd(g) - 0.5)) / n;   /* steps below 180 degrees */
        float rr = r * rndf(g, 0.5f, 1.5f);
        rim[i][0] = base[0] + rr * (float)cos(a);
        rim[i][1] = base[1] + r * (0.08f * (float)sin(2 * a + phase) + rndf(g, -0.002f, 0.002f));
        rim[i][2] = base[2] + rr * (float)sin(a);
    }
    for (int i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            tri[9 * i + a] = c[a];
            tri[9 * i + 3 + a] = rim[i][a];
            tri[9 * i + 6 + a] = rim[(i + 1) % n][a];
        }
}

static void test_fan_vertex_and_edges(void **st)
{
    (void)st;
    tu_rng g = { 92 };
    enum { FANS = 200, RAYS = 300, MAXN = 24 };
    float *soup = malloc(sizeof(float) * 9 * MAXN * FANS);
    int fan_n[FANS];
    size_t nt = 0;
    for (int f = 0; f < FANS; f++) {
        /* fans of 3 to 24 triangles, of many sizes, near and far from the world origin */
        float scale = f % 3 == 0 ? 0.01f : f % 3 == 1 ? 1.0f : 20.0f;
        float off = f % 4 == 0 ? 500.0f : 0.0f;
        float base[3] = { off + 60.0f * scale * rndf(&g, -1, 1), off + 60.0f * scale * rndf(&g, -1, 1), 60.0f * scale * rndf(&g, -1, 1) };
        fan_n[f] = 4 + (int)(tu_rng_next(&g) % (MAXN - 3));
        make_fan(&g, base, scale, fan_n[f], soup + 9 * nt);
        nt += (size_t)fan_n[f];
    }
    ms_bvh b;
    assert_int_equal(ms_bvh_build(&b, soup, nt, 0), 0);
    long rays = 0, wt_miss = 0, mt_miss = 0, bvh_closest_miss = 0, bvh_any_miss = 0, shadow_miss = 0;
    size_t first = 0;
    for (int f = 0; f < FANS; first += (size_t)fan_n[f], f++) {
        const float *fan = soup + 9 * first;
        const int n = fan_n[f];
        float span = 0.0f;
        for (int a = 0; a < 3; a++) span = fmaxf(span, fabsf(fan[3 + a] - fan[a]));
        for (int k = 0; k < RAYS; k++) {
            /* the target: the centre vertex, a rim vertex, or a float point on a shared edge */
            float target[3];
            int i = (int)(tu_rng_next(&g) % (uint64_t)n), kind = k % 3;
            float s = 0.9f * (float)rnd(&g);   /* not next to the rim: the rounded target must stay inside the fan */
            for (int a = 0; a < 3; a++) {
                const float *c = fan + 9 * i, *p = fan + 9 * i + 3;
                target[a] = kind == 0 ? c[a] : kind == 1 ? c[a] + s * (p[a] - c[a]) : c[a] + 0.5f * s * (p[a] - c[a]);
            }
            /* from above or below the fan, steeply enough not to graze it */
            float o[3] = { target[0] + span * rndf(&g, -1, 1), target[1] + span * (k & 8 ? 1.0f : -1.0f) * rndf(&g, 1.5f, 4),
                           target[2] + span * rndf(&g, -1, 1) };
            float d[3] = { target[0] - o[0], target[1] - o[1], target[2] - o[2] };
            /* a ray past the target (infinite) and a segment reaching well beyond it */
            int wt = 0, mt = 0;
            for (int j = 0; j < n; j++) {
                float t, u, v;
                wt |= ms_intersect_triangle(fan + 9 * j, o, d, 0.0f, INFINITY, &t, &u, &v);
                mt |= mt_intersect(fan + 9 * j, o, d, 0.0f, INFINITY);
            }
            ms_ray r = { { o[0], o[1], o[2] }, { d[0], d[1], d[2] }, 0.0f, INFINITY };
            ms_ray_hit h;
            int closest = ms_bvh_closest(&b, &r, &h), any = ms_bvh_occluded(&b, &r, UINT32_MAX);
            ms_ray seg = { { o[0], o[1], o[2] }, { 2 * d[0], 2 * d[1], 2 * d[2] }, 1e-4f, 1.0f - 1e-4f };
            int shadow = ms_bvh_occluded(&b, &seg, UINT32_MAX);
            rays++;
            wt_miss += !wt;
            mt_miss += !mt;
            bvh_closest_miss += !closest;
            bvh_any_miss += !any;
            shadow_miss += !shadow;
            if ((!wt || !closest || !any || !shadow) && wt_miss + bvh_closest_miss + bvh_any_miss + shadow_miss <= 4)
                print_message("fan %d (%d triangles), %s: o=(%.9g %.9g %.9g) d=(%.9g %.9g %.9g): triangles %d, closest %d, any %d, segment %d\n",
                              f, n, kind == 0 ? "centre" : kind == 1 ? "shared edge" : "shared edge (inner half)",
                              o[0], o[1], o[2], d[0], d[1], d[2], wt, closest, any, shadow);
        }
    }
    print_message("%ld rays at shared vertices and edges of %d closed fans: watertight misses %ld (BVH closest %ld, any %ld, "
                  "segments %ld); the old Moller-Trumbore misses %ld\n", rays, FANS, wt_miss, bvh_closest_miss, bvh_any_miss,
                  shadow_miss, mt_miss);
    assert_int_equal(wt_miss, 0);
    assert_int_equal(bvh_closest_miss, 0);
    assert_int_equal(bvh_any_miss, 0);
    assert_int_equal(shadow_miss, 0);
    ms_bvh_free(&b);
    free(soup);
}

/* Rays through the shared vertices of a flat, jittered grid (all vertices at one y, so every BVH box
 * is flat and the vertices lie on box faces): closest and any hit through the BVH must find the
 * grid every time, near the origin and 100 units away from it. The old code (Moller-Trumbore and the
 * previous box test) missed 7715 of the 100000 rays at the origin here (7.7%; 156022 of 2e6 with
 * the loop scaled up, and 92218 of 2e6 at offset 100). */
static void test_flat_grid_vertices(void **st)
{
    (void)st;
    for (int pass = 0; pass < 2; pass++) {
        tu_rng g = { 93 + (uint64_t)pass };
        const int n = 200;
        const float off = pass ? 100.0f : 0.0f;
        float *v = malloc(sizeof(float) * 3 * (n + 1) * (n + 1)), *soup = malloc(sizeof(float) * 18 * n * n);
        assert_non_null(v);
        assert_non_null(soup);
        for (int j = 0; j <= n; j++)
            for (int i = 0; i <= n; i++) {
                float *p = v + 3 * (j * (n + 1) + i);
                int rim = i == 0 || j == 0 || i == n || j == n;
                p[0] = off + ((float)i + (rim ? 0.0f : rndf(&g, -0.2f, 0.2f))) * 0.01f;
                p[1] = off + 0.3f;
                p[2] = off + ((float)j + (rim ? 0.0f : rndf(&g, -0.2f, 0.2f))) * 0.01f;
            }
        size_t m = 0;
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
                int t[2][3] = { { a, b, c }, { a, c, d } };
                if (tu_rng_next(&g) & 1) { t[0][2] = d; t[1][0] = b; t[1][1] = c; t[1][2] = d; }
                for (int k = 0; k < 2; k++, m++)
                    for (int q = 0; q < 3; q++) memcpy(soup + 9 * m + 3 * q, v + 3 * t[k][q], 3 * sizeof(float));
            }
        ms_bvh b;
        assert_int_equal(ms_bvh_build(&b, soup, m, 0), 0);
        long rays = 0, miss_closest = 0, miss_any = 0;
        for (int it = 0; it < 100000; it++) {
            int i = 1 + (int)(tu_rng_next(&g) % (uint64_t)(n - 1)), j = 1 + (int)(tu_rng_next(&g) % (uint64_t)(n - 1));
            const float *p = v + 3 * (j * (n + 1) + i);
            float o[3] = { p[0] + rndf(&g, -0.025f, 0.025f), p[1] + rndf(&g, 0.02f, 0.5f), p[2] + rndf(&g, -0.025f, 0.025f) };
            if (it & 1) o[1] = p[1] - (o[1] - p[1]);   /* from below as well */
            ms_ray r = { { o[0], o[1], o[2] }, { p[0] - o[0], p[1] - o[1], p[2] - o[2] }, 0.0f, INFINITY };
            ms_ray_hit h;
            rays++;
            miss_closest += !ms_bvh_closest(&b, &r, &h);
            miss_any += !ms_bvh_occluded(&b, &r, UINT32_MAX);
        }
        print_message("flat jittered grid at offset %g (%zu triangles): %ld rays through shared vertices, closest misses %ld, "
                      "any misses %ld\n", off, m, rays, miss_closest, miss_any);
        assert_int_equal(miss_closest, 0);
        assert_int_equal(miss_any, 0);
        ms_bvh_free(&b);
        free(v);
        free(soup);
    }
}

/* ---- scenes built here ---- */

typedef struct mesh {
    float *v;        /* 3 per vertex */
    uint32_t *ix;    /* 3 per triangle */
    size_t nv, nt, cv, ct;
} mesh;

static uint32_t mesh_vertex(mesh *m, float x, float y, float z)
{
    if (m->nv == m->cv) { m->cv = m->cv ? 2 * m->cv : 1024; m->v = realloc(m->v, sizeof(float) * 3 * m->cv); assert_non_null(m->v); }
    m->v[3 * m->nv] = x; m->v[3 * m->nv + 1] = y; m->v[3 * m->nv + 2] = z;
    return (uint32_t)m->nv++;
}

static void mesh_tri(mesh *m, uint32_t a, uint32_t b, uint32_t c)
{
    if (m->nt == m->ct) { m->ct = m->ct ? 2 * m->ct : 1024; m->ix = realloc(m->ix, sizeof(uint32_t) * 3 * m->ct); assert_non_null(m->ix); }
    m->ix[3 * m->nt] = a; m->ix[3 * m->nt + 1] = b; m->ix[3 * m->nt + 2] = c;
    m->nt++;
}

/* Appends the mesh as a soup (indexed -> 9 floats per triangle: shared vertices stay bitwise equal). */
static void soup_append(float **soup, size_t *n, const mesh *m)
{
    *soup = realloc(*soup, sizeof(float) * 9 * (*n + m->nt));
    assert_non_null(*soup);
    for (size_t t = 0; t < m->nt; t++)
        for (int c = 0; c < 3; c++) memcpy(*soup + 9 * (*n + t) + 3 * c, m->v + 3 * m->ix[3 * t + c], 3 * sizeof(float));
    *n += m->nt;
}

static void mesh_free(mesh *m) { free(m->v); free(m->ix); memset(m, 0, sizeof *m); }

/* A closed "pillow" around the light: two jittered height-field sheets over an n x n grid of the
 * square [-h, h]^2 (in x, z), the lower one around y = y0 + ylo, the upper one around y0 + yhi, sharing
 * their rim at y0; interior vertices jittered in all three coordinates, each cell split along a
 * random diagonal. A closed 2-manifold: every edge is shared by exactly two triangles. */
static void make_pillow(mesh *m, tu_rng *g, int n, float h, const float c[3], float ylo, float yhi)
{
    uint32_t *lo = malloc(sizeof(uint32_t) * (n + 1) * (n + 1)), *hi = malloc(sizeof(uint32_t) * (n + 1) * (n + 1));
    assert_non_null(lo);
    assert_non_null(hi);
    const float cell = 2.0f * h / (float)n;
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            int rim = i == 0 || j == 0 || i == n || j == n;
            float jx = rim ? 0.0f : rndf(g, -0.35f, 0.35f) * cell, jz = rim ? 0.0f : rndf(g, -0.35f, 0.35f) * cell;
            float x = c[0] + (-h + cell * (float)i + jx), z = c[2] + (-h + cell * (float)j + jz);
            if (rim) {
                lo[j * (n + 1) + i] = hi[j * (n + 1) + i] = mesh_vertex(m, x, c[1], z);
            } else {
                lo[j * (n + 1) + i] = mesh_vertex(m, x, c[1] + ylo + rndf(g, -0.3f, 0.3f) * cell, z);
                float jx2 = rndf(g, -0.35f, 0.35f) * cell, jz2 = rndf(g, -0.35f, 0.35f) * cell;
                hi[j * (n + 1) + i] = mesh_vertex(m, x + jx2, c[1] + yhi + rndf(g, -0.3f, 0.3f) * cell, z + jz2);
            }
        }
    for (int s = 0; s < 2; s++) {
        const uint32_t *q = s ? hi : lo;
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                uint32_t a = q[j * (n + 1) + i], b = q[j * (n + 1) + i + 1], cc = q[(j + 1) * (n + 1) + i + 1],
                         d = q[(j + 1) * (n + 1) + i];
                if (tu_rng_next(g) & 1) { mesh_tri(m, a, b, cc); mesh_tri(m, a, cc, d); }
                else { mesh_tri(m, a, b, d); mesh_tri(m, b, cc, d); }
            }
    }
    free(lo);
    free(hi);
}

static void render_ok(const ms_scene *sc, const char *method, int samples, int w, int h, ms_frame *f)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.samples = samples;
    o.width = w;
    o.height = h;
    o.seed = 3;
    tu_render_ok(sc, &o, f);
}

/* The light-leak scene around centre c: ground y = c.y + 0 (a 2-triangle square), light 0.5 x 0.5
 * facing down at c.y + 2 inside a closed pillow (rim at c.y + 2, sheets at about c.y + 1.2 and
 * c.y + 2.8, n x n cells over [-1.5, 1.5]^2), camera under it looking down at the ground. */
static void leak_scene(ms_scene *sc, const float c[3], int n, uint64_t seed)
{
    memset(sc, 0, sizeof *sc);
    tu_rng g = { seed };
    mesh m = { 0 };
    const float pc[3] = { c[0], c[1] + 2.0f, c[2] };
    make_pillow(&m, &g, n, 1.5f, pc, -0.8f, 0.8f);
    uint32_t g0 = mesh_vertex(&m, c[0] - 3, c[1], c[2] - 3), g1 = mesh_vertex(&m, c[0] + 3, c[1], c[2] - 3);
    uint32_t g2 = mesh_vertex(&m, c[0] + 3, c[1], c[2] + 3), g3 = mesh_vertex(&m, c[0] - 3, c[1], c[2] + 3);
    mesh_tri(&m, g0, g1, g2);
    mesh_tri(&m, g0, g2, g3);
    soup_append(&sc->tri, &sc->n_tris, &m);
    mesh_free(&m);
    sc->camera = (ms_camera){ { c[0] + 0.05f, c[1] + 1.0f, c[2] - 0.03f }, { c[0], c[1], c[2] }, { 0, 0, 1 }, 90.0f, 64, 64, MS_CAMERA_PINHOLE, 0, 0 };
    sc->light = (ms_light){ { c[0] - 0.25f, c[1] + 2.0f, c[2] - 0.25f }, { 0.5f, 0, 0 }, { 0, 0, 0.5f }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    sc->samples = 256;
}

static void check_no_leak(const ms_scene *sc, const char *what, int samples, long *leaked_total, double *tests)
{
    for (const char *const *name = ms_method_names(); *name; name++) {
        /* Embree at 80x80; raytrace (slow under ASan) at 48x48; the micro-rasterizers, which
         * rasterize about a thousand of the occluder's triangles per pixel here, at 40x40; penumbra casting
         * (the slowest under ASan far from the origin) at 32x32. */
        const int size = strcmp(*name, "embree") == 0 ? 80 : strcmp(*name, "raytrace") == 0 ? 48
                         : strncmp(*name, "hpc", 3) == 0 ? 32 : 40;
        ms_frame f;
        render_ok(sc, *name, samples, size, size, &f);
        long leaked = 0, missed = 0, pixels_leaking = 0;
        for (int i = 0; i < size * size; i++) {
            if (f.vis[i] < 0.0f) { missed++; continue; }
            long k = lroundf(f.vis[i] * (float)samples);
            leaked += k;
            pixels_leaking += k > 0;
        }
        print_message("%s, %s, %dx%d, %d samples: %ld visible samples (%ld pixels) of %.3g tested, %ld primary misses "
                      "(BVH build %.2fs, set-up %.2fs, shadows %.2fs)\n", what, *name, size, size, samples, leaked, pixels_leaking,
                      (double)f.stats.shadow_rays, missed, f.stats.build_s, f.stats.setup_s, f.stats.shadow_s);
        assert_int_equal(missed, 0);
        assert_int_equal(f.stats.visible_pixels, (uint64_t)size * size);
        *leaked_total += leaked;
        *tests += (double)f.stats.shadow_rays;
        ms_frame_free(&f);
    }
}

static void test_light_leak(void **st)
{
    (void)st;
    long leaked = 0;
    double tests = 0;
    ms_scene sc;
    const float at_origin[3] = { 0, 0, 0 }, far_away[3] = { 700.0f, 300.0f, -500.0f };
    leak_scene(&sc, at_origin, 220, 1);           /* 2 x 220^2 = 96800 occluder triangles */
    check_no_leak(&sc, "pillow at the origin", 256, &leaked, &tests);
    ms_scene_free(&sc);
    leak_scene(&sc, far_away, 220, 2);
    check_no_leak(&sc, "pillow at (700, 300, -500)", 256, &leaked, &tests);
    ms_scene_free(&sc);
    print_message("light leak: %ld visible samples in %.3g sample tests\n", leaked, tests);
    assert_true(tests > 5e6);   /* 7.8e6 */
    assert_int_equal(leaked, 0);
}

/* ---- c: primary cracks ---- */

/* An icosphere of 20 * 4^levels triangles, radius r around c, every vertex jittered radially and
 * tangentially by up to `jitter` of the edge length; shared vertices (midpoints looked up per edge). */
static void make_icosphere(mesh *m, tu_rng *g, int levels, const float c[3], float r, float jitter)
{
    double *p;
    int *tri;
    size_t np, nt;
    tu_unit_icosphere(levels, &p, &np, &tri, &nt);
    const double edge = 4.0 / sqrt((double)nt);   /* about the edge length on the unit sphere */
    for (size_t i = 0; i < np; i++) {
        double q[3];
        for (int a = 0; a < 3; a++) q[a] = p[3 * i + a] + jitter * edge * (rnd(g) * 2 - 1);
        mesh_vertex(m, c[0] + (float)(r * q[0]), c[1] + (float)(r * q[1]), c[2] + (float)(r * q[2]));
    }
    for (size_t k = 0; k < nt; k++) mesh_tri(m, (uint32_t)tri[3 * k], (uint32_t)tri[3 * k + 1], (uint32_t)tri[3 * k + 2]);
    free(p);
    free(tri);
}

static void sphere_scene(ms_scene *sc, const float c[3], uint64_t seed)
{
    memset(sc, 0, sizeof *sc);
    tu_rng g = { seed };
    mesh m = { 0 };
    make_icosphere(&m, &g, 5, c, 1.0f, 0.3f);       /* 20480 triangles */
    soup_append(&sc->tri, &sc->n_tris, &m);
    mesh_free(&m);
    /* camera off the centre, looking at a wall with a wide field of view */
    sc->camera = (ms_camera){ { c[0] + 0.13f, c[1] - 0.21f, c[2] + 0.07f }, { c[0] + 1.0f, c[1] + 0.3f, c[2] + 0.2f }, { 0, 1, 0 }, 120.0f, 64, 64, MS_CAMERA_PINHOLE, 0, 0 };
    sc->light = (ms_light){ { c[0] - 0.3f, c[1] + 0.5f, c[2] - 0.1f }, { 0.2f, 0, 0 }, { 0, 0, 0.2f }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    sc->samples = 256;
}

/* Misses of one primary method at W x H, through the primary interface (no shadows). */
static long primary_misses(const ms_scene *sc, const char *primary, int W, int H)
{
    ms_render_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    assert_int_equal(ms_camera_basis_init(&ctx.cam, &sc->camera, W, H), 0);
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc->tri, sc->n_tris, 0), 0);
    ctx.scene = sc;
    ctx.bvh = &bvh;
    ctx.light = sc->light;
    ctx.pattern = MS_PATTERN_GRID;
    ctx.k = 16;
    ctx.samples = 256;
    ctx.near = 1e-4f;
    ctx.far = 1.0f - 1e-4f;
    ctx.threads = 2;
    const ms_primary_method *pm = ms_find_primary_method(primary);
    assert_non_null(pm);
    void *state = NULL;
    char err[512] = "";
    assert_int_equal(pm->create(&ctx, &state, err, sizeof err), 0);
    long miss = 0;
    enum { T = 32 };
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : miss) num_threads(2)
    for (int ty = 0; ty < (H + T - 1) / T; ty++) {
        ms_hit *row = malloc(sizeof *row * T * T);
        for (int x0 = 0; x0 < W; x0 += T) {
            int y0 = ty * T, x1 = x0 + T < W ? x0 + T : W, y1 = y0 + T < H ? y0 + T : H;
            pm->trace(state, &ctx, x0, y0, x1, y1, row);
            for (int i = 0; i < (x1 - x0) * (y1 - y0); i++) miss += row[i].prim == UINT32_MAX;
        }
        free(row);
    }
    pm->destroy(state);
    ms_bvh_free(&bvh);
    return miss;
}

static void test_primary_cracks(void **st)
{
    (void)st;
    static const char *const primaries[] = { "bvh",
#ifdef MS_HAVE_EMBREE
                                             "embree",
#endif
    };
    const float centres[2][3] = { { 0, 0, 0 }, { 300.0f, -200.0f, 500.0f } };
    long total = 0;
    for (int s = 0; s < 2; s++) {
        ms_scene sc;
        sphere_scene(&sc, centres[s], 10 + (uint64_t)s);
        static const int sizes[] = { 64, 257, 512, 1024 };
        for (size_t p = 0; p < sizeof primaries / sizeof *primaries; p++)
            for (int z = 0; z < 4; z++) {
                long miss = primary_misses(&sc, primaries[p], sizes[z], sizes[z]);
                print_message("sphere at (%g %g %g), %u triangles, primary %s, %dx%d: %ld pixels miss\n", centres[s][0],
                              centres[s][1], centres[s][2], (unsigned)sc.n_tris, primaries[p], sizes[z], sizes[z], miss);
                total += miss;
            }
        /* End to end: every method's frame has V != -1 everywhere (its primary hit every pixel). */
        for (const char *const *name = ms_method_names(); *name; name++) {
            ms_frame f;
            int size = strcmp(*name, "raytrace") == 0 ? 48 : 96;   /* raytrace shadows are slow under ASan */
            render_ok(&sc, *name, 256, size, size, &f);
            long miss = 0;
            for (int i = 0; i < size * size; i++) miss += f.vis[i] < 0.0f;
            print_message("sphere at (%g %g %g), ms_render %s %dx%d: %ld pixels with V = -1\n", centres[s][0], centres[s][1],
                          centres[s][2], *name, size, size, miss);
            total += miss;
            ms_frame_free(&f);
        }
        ms_scene_free(&sc);
    }
    assert_int_equal(total, 0);
}

/* ---- d: the micro-rasterization kernels on shared edges ---- */

/* A jittered sheet between C and the light, covering the whole frustum C -> light (so closed as far
 * as any sample can tell), whose vertices lie on sample rays (up to the rounding of their world
 * coordinates): vertex (i, j) is C + z_ij (S(x_i, y_j) - C), S(x, y) = p0 + x ds + y dt the light's
 * sample lattice, z_ij jittered in depth, each cell split along a random diagonal.
 *   on_vertices = 0: x_i = i*step + 1/2, y_j = j*step: samples lie on the shared edges along x (a
 *                    straight line in projection) and on no vertex or other edge;
 *   on_vertices = 1: x_i = i*step, y_j = j*step: samples also on shared vertices.
 * Returns the samples left visible, summed over every kernel and ISA variant; *runs counts them. */
static long kernels_on_mesh(tu_rng *g, int frame, int on_vertices, long *runs)
{
    static const ms_isa isas[] = { MS_ISA_SCALAR, MS_ISA_AVX2, MS_ISA_AVX512 };
    const int k = frame % 3 == 0 ? 16 : frame % 3 == 1 ? 32 : 64;
    const float off = frame % 2 ? 400.0f : 0.0f;
    ms_light L = { { off - 0.5f + rndf(g, -0.1f, 0.1f), 2.0f, -0.5f }, { 1.0f, rndf(g, -0.1f, 0.1f), 0 },
                   { 0, rndf(g, -0.1f, 0.1f), 1.0f }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    ms_grid grid;
    ms_grid_for_pixel(&L, k, (uint32_t)frame, 7, 11, &grid);
    const float c[3] = { off + rndf(g, -0.3f, 0.3f), rndf(g, -0.2f, 0.2f), rndf(g, -0.3f, 0.3f) };
    ms_raster_frame fr;
    assert_int_equal(ms_raster_frame_init(&fr, c, &grid, 1e-4f, 1.0f - 1e-4f, 0), 0);
    const int step = 1 + (int)(tu_rng_next(g) % 3);
    const int lo = -2, hi = (k - 1) / step + 3, n = hi - lo + 1;
    mesh m = { 0 };
    uint32_t *vid = malloc(sizeof(uint32_t) * (size_t)n * n);
    assert_non_null(vid);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double si = (double)((lo + i) * step) + (on_vertices ? 0.0 : 0.5), sj = (double)((lo + j) * step);
            double z = 0.3 + 0.3 * rnd(g);
            float p[3];
            for (int a = 0; a < 3; a++)
                p[a] = (float)(c[a] + z * (grid.p0[a] + si * grid.ds[a] + sj * grid.dt[a] - c[a]));
            vid[j * n + i] = mesh_vertex(&m, p[0], p[1], p[2]);
        }
    for (int j = 0; j + 1 < n; j++)
        for (int i = 0; i + 1 < n; i++) {
            uint32_t a = vid[j * n + i], b = vid[j * n + i + 1], cc = vid[(j + 1) * n + i + 1], d = vid[(j + 1) * n + i];
            if (tu_rng_next(g) & 1) { mesh_tri(&m, a, b, cc); mesh_tri(&m, a, cc, d); }
            else { mesh_tri(&m, a, b, d); mesh_tri(&m, b, cc, d); }
        }
    free(vid);
    float *soup = NULL;
    size_t nt = 0;
    soup_append(&soup, &nt, &m);
    mesh_free(&m);
    long visible = 0;
    for (int kid = 0; kid < MS_KERNEL_COUNT; kid++)
        for (int is = 0; is < 3; is++) {
            if (!tu_isa_allowed(isas[is])) continue;
            ms_raster_fn fn = ms_raster_kernel_isa((ms_kernel_id)kid, k, isas[is]);
            if (!fn) continue;
            uint64_t buf[64];
            ms_buffer_fill_visible(buf, k);
            for (size_t t = 0; t < nt; t++) fn(&fr, soup + 9 * t, buf);
            int vis = ms_buffer_visible_count(buf, k);
            if (vis && !on_vertices)
                print_message("frame %d (k %d, step %d, offset %g): %s/%s leaves %d samples on shared edges visible\n", frame, k,
                              step, off, ms_kernel_name((ms_kernel_id)kid), ms_isa_name(isas[is]), vis);
            visible += vis;
            (*runs)++;
        }
    free(soup);
    return visible;
}

/* Samples on shared edges: every kernel covers them (each edge function of a shared edge is the exact
 * negation of its neighbour's, and a sample on it counts as covered by either). Samples on shared
 * vertices are counted and printed, not asserted: the kernels' edge functions are world-space cross
 * products dotted with the frame, not exact predicates, so around a vertex shared by six triangles the
 * rounding can favour the next triangle at every spoke and leave the sample to none (measured: 468
 * samples over these 24 frames and all variants, the same before and after the watertight change). */
static void test_kernels_shared_edges(void **st)
{
    (void)st;
    tu_rng g = { 95 };
    long runs = 0, on_edges = 0, vruns = 0, on_vertices = 0;
    for (int frame = 0; frame < 24; frame++) {
        on_edges += kernels_on_mesh(&g, frame, 0, &runs);
        on_vertices += kernels_on_mesh(&g, frame, 1, &vruns);
    }
    print_message("kernels, meshes with samples on shared edges: %ld kernel runs, %ld samples left visible; with samples on "
                  "shared vertices too: %ld runs, %ld samples left visible (not asserted)\n", runs, on_edges, vruns, on_vertices);
    assert_true(runs >= 24 * 3);
    assert_int_equal(on_edges, 0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_triangle_oracle),
        cmocka_unit_test(test_grazing_t),
        cmocka_unit_test(test_rays16_lanes),
        cmocka_unit_test(test_fan_vertex_and_edges),
        cmocka_unit_test(test_flat_grid_vertices),
        cmocka_unit_test(test_kernels_shared_edges),
        cmocka_unit_test(test_light_leak),
        cmocka_unit_test(test_primary_cracks),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
