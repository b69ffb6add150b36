/* Penumbra volumes (src/shadow/hpc/hpc_volume.c, Laine & Aila 2005 sec. 3.2) against brute force: for random
 * light rectangles and triangles, every point that some segment from a point of the rectangle through the
 * triangle reaches (sampled densely, in double) lies inside the volume, with margin 0; and a box around
 * such a point is never culled. Also reports how tight the volume is: the share of sampled points inside
 * it that are shadowed from at least one of 64 light points. */
#include "testutil.h"
#include "shadow/hpc/hpc_volume.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

static double unitd(tu_rng *r) { return (double)(tu_rng_next(r) >> 11) * (1.0 / 9007199254740992.0); }

/* A light rectangle at y = 4 of random size (poly: its four corners) and a triangle between y = 0.5 and
 * 3.5 (tri: its three vertices). */
static void random_light_and_triangle(tu_rng *rng, double poly[12], float tri[9])
{
    const double lx = 0.2 + 2.0 * unitd(rng), lz = 0.2 + 2.0 * unitd(rng);
    const double corners[12] = { -lx, 4, -lz, lx, 4, -lz, lx, 4, lz, -lx, 4, lz };
    memcpy(poly, corners, sizeof corners);
    for (int v = 0; v < 3; v++) {
        tri[3 * v] = (float)(3.0 * unitd(rng) - 1.5);
        tri[3 * v + 1] = (float)(0.5 + 3.0 * unitd(rng));
        tri[3 * v + 2] = (float)(3.0 * unitd(rng) - 1.5);
    }
}

/* A random point x shadowed by triangle (v0, v1, v2) from the light of random_light_and_triangle (half sizes
 * lx, lz): light point l, triangle point t (barycentric), x = l + s (t - l), s >= 1. */
static void shadowed_point(tu_rng *rng, double lx, double lz, const float *v0, const float *v1, const float *v2, double x[3])
{
    double a = unitd(rng), b = unitd(rng);
    if (a + b > 1) { a = 1 - a; b = 1 - b; }
    const double l[3] = { -lx + 2 * lx * unitd(rng), 4, -lz + 2 * lz * unitd(rng) };
    const double s = 1.0 + 5.0 * unitd(rng);
    for (int c = 0; c < 3; c++) x[c] = l[c] + s * (v0[c] + a * (v1[c] - v0[c]) + b * (v2[c] - v0[c]) - l[c]);
}

static void test_contains_every_shadow(void **st)
{
    (void)st;
    tu_rng rng = { 0x5EED };
    long shadowed = 0, inside = 0, inside_and_shadowed = 0, planes = 0;
    for (int trial = 0; trial < 300; trial++) {
        double poly[12];
        float tri[9];
        random_light_and_triangle(&rng, poly, tri);
        const double lx = poly[3], lz = poly[8];   /* the light's half sizes */
        hpc_volume vol;
        planes += hpc_volume_build(&vol, poly, 4, tri, 0.0f);
        for (int k = 0; k < 200; k++) {
            double x[3];
            shadowed_point(&rng, lx, lz, tri, tri + 3, tri + 6, x);
            const float p[3] = { (float)x[0], (float)x[1], (float)x[2] };
            uint64_t tests = 0;
            /* margin: the float rounding of p and of the planes, far below the geometry */
            vol.eps = 1e-4f;
            if (!hpc_volume_point(&vol, HPC_ALL_PLANES, p, &tests))
                fail_msg("trial %d: shadowed point (%g %g %g) outside the volume", trial, x[0], x[1], x[2]);
            const float lo[3] = { p[0] - 0.01f, p[1] - 0.01f, p[2] - 0.01f }, hi[3] = { p[0] + 0.01f, p[1] + 0.01f, p[2] + 0.01f };
            uint32_t out;
            assert_true(hpc_volume_box(&vol, HPC_ALL_PLANES, lo, hi, &out, &tests));
            shadowed++;
        }
        /* tightness: random points below the light, inside the volume, shadowed from some light point? */
        for (int k = 0; k < 200; k++) {
            const float p[3] = { (float)(12 * unitd(&rng) - 6), (float)(-2 + 5.5 * unitd(&rng)), (float)(12 * unitd(&rng) - 6) };
            uint64_t tests = 0;
            vol.eps = 0.0f;
            if (!hpc_volume_point(&vol, HPC_ALL_PLANES, p, &tests)) continue;
            inside++;
            int any = 0;
            for (int i = 0; i < 8 && !any; i++)
                for (int j = 0; j < 8 && !any; j++) {
                    const double l[3] = { -lx + 2 * lx * (i + 0.5) / 8, 4, -lz + 2 * lz * (j + 0.5) / 8 };
                    /* segment l -> p against the triangle (Moller-Trumbore in double) */
                    double e1[3], e2[3], d[3], pv[3], sv[3], qv[3];
                    for (int c = 0; c < 3; c++) { e1[c] = tri[3 + c] - tri[c]; e2[c] = tri[6 + c] - tri[c]; d[c] = p[c] - l[c]; sv[c] = l[c] - tri[c]; }
                    pv[0] = d[1] * e2[2] - d[2] * e2[1]; pv[1] = d[2] * e2[0] - d[0] * e2[2]; pv[2] = d[0] * e2[1] - d[1] * e2[0];
                    const double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
                    if (fabs(det) < 1e-12) continue;
                    const double u = (sv[0] * pv[0] + sv[1] * pv[1] + sv[2] * pv[2]) / det;
                    qv[0] = sv[1] * e1[2] - sv[2] * e1[1]; qv[1] = sv[2] * e1[0] - sv[0] * e1[2]; qv[2] = sv[0] * e1[1] - sv[1] * e1[0];
                    const double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) / det;
                    const double tt = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
                    any = u >= 0 && v >= 0 && u + v <= 1 && tt > 0 && tt < 1;
                }
            inside_and_shadowed += any;
        }
    }
    printf("%ld shadowed points all inside; %.2f planes per volume; of %ld random points inside a volume, %.1f%% are "
           "shadowed from one of 64 light points\n", shadowed, (double)planes / 300.0, inside,
           100.0 * (double)inside_and_shadowed / (double)(inside ? inside : 1));
    assert_true(inside_and_shadowed * 2 > inside);   /* the volume is not the whole space */
}

/* Active plane sets: a box wholly inside loses its planes; a child box then needs no plane tests. */
static void test_active_planes(void **st)
{
    (void)st;
    const double poly[12] = { -1, 4, -1, 1, 4, -1, 1, 4, 1, -1, 4, 1 };
    const float tri[9] = { -1, 2, -1, 1, 2, -1, 0, 2, 1 };
    hpc_volume v;
    const int n = hpc_volume_build(&v, poly, 4, tri, 1e-5f);
    assert_true(n >= 4);
    assert_false(v.unbounded);
    uint64_t tests = 0;
    uint32_t out;
    /* a small box right under the triangle's centre, well inside the umbra region */
    const float lo[3] = { -0.05f, 1.0f, -0.35f }, hi[3] = { 0.05f, 1.1f, -0.25f };
    assert_true(hpc_volume_box(&v, HPC_ALL_PLANES, lo, hi, &out, &tests));
    assert_int_equal(out, 0);
    const uint64_t before = tests;
    assert_true(hpc_volume_point(&v, out, lo, &tests));
    assert_int_equal(tests, before);
    /* a box beside the light, above the triangle's plane: outside */
    const float lo2[3] = { 5, 3, 5 }, hi2[3] = { 6, 3.5f, 6 };
    assert_false(hpc_volume_box(&v, HPC_ALL_PLANES, lo2, hi2, &out, &tests));
    /* a triangle crossing the light: no separating plane, nothing culled */
    const float cross[9] = { -3, 3, 0, 3, 5, 0, 0, 4, 3 };
    hpc_volume_build(&v, poly, 4, cross, 1e-5f);
    assert_true(hpc_volume_box(&v, HPC_ALL_PLANES, lo2, hi2, &out, &tests));
}

/* A blocker of four points (hpc casts two triangles sharing an edge as one job, hpc_triangle.c hpc_pair_batch): for
 * random pairs, flat (a quad, convex or not) and folded along the shared edge, every point either triangle
 * shadows lies inside the volume of the four points, with margin 0 up to rounding; and the volume still
 * culls (a point beside the light is outside; the flat pair's volume keeps its cap). The points are given
 * in pair_batch's order: the first triangle's three, then the second's other vertex. */
static void test_pair_contains_both_shadows(void **st)
{
    (void)st;
    tu_rng rng = { 0xFA1D };
    long shadowed = 0, capped = 0, flat = 0;
    for (int trial = 0; trial < 400; trial++) {
        double poly[12];
        float pts[12];
        random_light_and_triangle(&rng, poly, pts);
        const double lx = poly[3], lz = poly[8];   /* the light's half sizes */
        /* the fourth point: across the edge (0, 2) from point 1, in the plane (even trials) or off it */
        const double m = 0.3 + 0.7 * unitd(&rng), w = 0.2 + unitd(&rng), fold = trial % 2 ? 0.8 * unitd(&rng) - 0.4 : 0.0;
        double nrm[3], e1[3], e2[3];
        for (int c = 0; c < 3; c++) { e1[c] = pts[3 + c] - pts[c]; e2[c] = pts[6 + c] - pts[c]; }
        nrm[0] = e1[1] * e2[2] - e1[2] * e2[1]; nrm[1] = e1[2] * e2[0] - e1[0] * e2[2]; nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
        const double nl = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        if (!(nl > 1e-3)) continue;
        for (int c = 0; c < 3; c++) {
            const double mid = pts[c] + m * e2[c];
            pts[9 + c] = (float)(mid - w * (pts[3 + c] - mid) + fold * nrm[c] / nl);
        }
        if (!(pts[10] > 0.3f && pts[10] < 3.7f)) continue;   /* below the light, as the triangles */
        hpc_volume vol;
        hpc_volume_build_points(&vol, poly, 4, pts, 4, 0.0f);
        assert_false(vol.unbounded);
        if (fold == 0.0) {   /* the cap comes last (the blocker's plane): when the first triangle has one */
            hpc_volume one;
            hpc_volume_build(&one, poly, 4, pts, 0.0f);
            const float *c = vol.pl[vol.n - 1], *c1 = one.pl[one.n - 1];
            const int cap1 = fabs(c1[0] * nrm[0] + c1[1] * nrm[1] + c1[2] * nrm[2]) > 0.999 * nl;
            flat += cap1;
            capped += cap1 && fabs(c[0] * nrm[0] + c[1] * nrm[1] + c[2] * nrm[2]) > 0.999 * nl;
        }
        static const int tri_of[2][3] = { { 0, 1, 2 }, { 0, 2, 3 } };
        for (int k = 0; k < 200; k++) {
            const int *tv = tri_of[k & 1];
            double x[3];
            shadowed_point(&rng, lx, lz, pts + 3 * tv[0], pts + 3 * tv[1], pts + 3 * tv[2], x);
            const float p[3] = { (float)x[0], (float)x[1], (float)x[2] };
            uint64_t tests = 0;
            vol.eps = 1e-4f;
            if (!hpc_volume_point(&vol, HPC_ALL_PLANES, p, &tests))
                fail_msg("trial %d: point (%g %g %g) shadowed by triangle %d outside the pair's volume", trial, x[0], x[1],
                         x[2], k & 1);
            shadowed++;
        }
        /* beside the light, above the blocker: culled */
        const float far[3] = { (float)(lx + 3.0), 4.5f, (float)(lz + 3.0) };
        uint64_t tests = 0;
        vol.eps = 1e-4f;
        assert_false(hpc_volume_point(&vol, HPC_ALL_PLANES, far, &tests));
    }
    printf("%ld points shadowed by either triangle of a pair all inside its volume; %ld of %ld flat pairs whose "
           "first triangle has a cap have one\n", shadowed, capped, flat);
    assert_true(shadowed > 40000);
    assert_true(flat > 50);
    assert_int_equal(capped, flat);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_contains_every_shadow),
        cmocka_unit_test(test_active_planes),
        cmocka_unit_test(test_pair_contains_both_shadows),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
