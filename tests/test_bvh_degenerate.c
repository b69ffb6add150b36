/* Zero-area triangles under the watertight test (src/accel/ray_triangle.h). Our ray tests take every
 * triangle as it is (no sliver rejection: it would open a closed mesh wherever it has a sliver), so what
 * a zero-area triangle may do is bounded by the test itself:
 *  - a repeated vertex (two bitwise equal vertices) is never hit: its edge functions are exactly
 *    opposite or zero;
 *  - three collinear vertices are hit only by rays that pass through their segment, within rounding,
 *    and at a t between the vertices' along the ray's dominant axis (T / det is a convex combination
 *    of the vertices' depths; where on the segment is rounding noise, det being ~0).
 * Oracle, in double precision: the distance from the ray's line to the segment, and the vertices'
 * depths (x_kz - o_kz) / d_kz. Scenes (sponza, sibenik) contain such triangles. t >= 1e-4 as for
 * shadow segments. */
#include "testutil.h"
#include "accel/bvh.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static float rnd(tu_rng *r) { return (float)((tu_rng_next(r) >> 40) * (1.0 / 16777216.0)); }
static float rnd_in(tu_rng *r, float lo, float hi) { return lo + (hi - lo) * rnd(r); }

/* Distance from the point p to the line o + s d (all s), in double. */
static double point_line_distance(const double p[3], const float o[3], const float d[3])
{
    double w[3], dd = 0, wd = 0, ww = 0;
    for (int k = 0; k < 3; k++) { w[k] = p[k] - o[k]; dd += (double)d[k] * d[k]; wd += w[k] * d[k]; ww += w[k] * w[k]; }
    double d2 = ww - wd * wd / dd;
    return sqrt(d2 > 0 ? d2 : 0);
}

/* Distance between the line o + s d and the segment A-B: the squared distance is a convex quadratic
 * in the segment parameter f; its minimum, clamped to [0, 1]. */
static double line_segment_distance(const float o[3], const float d[3], const float *A, const float *B)
{
    double e[3], w[3], dd = 0, ee = 0, ed = 0, wd = 0, we = 0;
    for (int k = 0; k < 3; k++) {
        e[k] = (double)B[k] - A[k];
        w[k] = (double)A[k] - o[k];
        dd += (double)d[k] * d[k]; ee += e[k] * e[k]; ed += e[k] * d[k]; wd += w[k] * d[k]; we += w[k] * e[k];
    }
    /* |w + f e - s d|^2, s eliminated: minimise over f of |P(w + f e)|^2, P the projection off d. */
    double a = ee - ed * ed / dd, b = we - wd * ed / dd;
    double f = a > 0 ? -b / a : 0;
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    double p[3];
    for (int k = 0; k < 3; k++) p[k] = A[k] + f * e[k];
    return point_line_distance(p, o, d);
}

static void test_degenerate_triangles(void **st)
{
    (void)st;
    tu_rng g = { 10 };
    enum { N = 400 };
    float *soup = malloc(9 * N * sizeof(float));
    for (int m = 0; m < N; m++) {
        float a[3], b[3];
        for (int k = 0; k < 3; k++) { a[k] = rnd_in(&g, -5, 5); b[k] = a[k] + rnd_in(&g, -2, 2); }
        for (int k = 0; k < 3; k++) {
            soup[9 * m + k] = a[k];
            soup[9 * m + 3 + k] = b[k];
            /* collinear (a point between a and b, rounded), or b repeated bitwise */
            soup[9 * m + 6 + k] = m % 2 ? a[k] + 0.375f * (b[k] - a[k]) : b[k];
        }
    }
    int bad_repeated = 0, bad_far = 0, bad_depth = 0, collinear_hits = 0, first = 1;
    long tests = 0;
    for (int it = 0; it < 4000; it++) {
        const float *tri = soup + 9 * (tu_rng_next(&g) % N);
        float o[3], d[3];
        float f = rnd(&g);
        for (int k = 0; k < 3; k++) { o[k] = rnd_in(&g, -10, 10); d[k] = tri[k] + f * (tri[3 + k] - tri[k]) - o[k]; }
        int kz = fabsf(d[0]) >= fabsf(d[1]) ? (fabsf(d[0]) >= fabsf(d[2]) ? 0 : 2) : (fabsf(d[1]) >= fabsf(d[2]) ? 1 : 2);
        for (int m = 0; m < N; m++) {
            const float *A = soup + 9 * m, *B = A + 3, *C = A + 6;
            float t, u, v;
            tests++;
            if (!ms_intersect_triangle(A, o, d, 1e-4f, INFINITY, &t, &u, &v)) continue;
            if (m % 2 == 0) { bad_repeated++; continue; }
            collinear_hits++;
            double dist = line_segment_distance(o, d, A, B);
            double z[3], zlo, zhi, zt = (double)t;
            for (int c = 0; c < 3; c++) z[c] = ((double)A[3 * c + kz] - o[kz]) / d[kz];
            zlo = fmin(z[0], fmin(z[1], z[2]));
            zhi = fmax(z[0], fmax(z[1], z[2]));
            int far = dist > 1e-5, off = zt < zlo - 1e-5 * (1 + fabs(zlo)) || zt > zhi + 1e-5 * (1 + fabs(zhi));
            bad_far += far;
            bad_depth += off;
            if ((far || off) && first) {
                first = 0;
                print_message("collinear triangle %d (%g %g %g)-(%g %g %g)-(%g %g %g) hit at t=%g: ray %g from its segment, "
                              "vertex depths [%g, %g]\n", m, A[0], A[1], A[2], B[0], B[1], B[2], C[0], C[1], C[2], t, dist, zlo, zhi);
            }
        }
    }
    print_message("%ld ray/zero-area-triangle tests: %d hits on collinear triangles (rays through their segment), "
                  "%d hits on repeated-vertex triangles, %d hits away from the segment, %d outside the vertex depths\n",
                  tests, collinear_hits, bad_repeated, bad_far, bad_depth);
    free(soup);
    assert_int_equal(bad_repeated, 0);
    assert_int_equal(bad_far, 0);
    assert_int_equal(bad_depth, 0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_degenerate_triangles),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
