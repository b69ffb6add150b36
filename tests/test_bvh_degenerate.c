/* Zero-area triangles never occlude: ms_intersect_triangle must not report a hit for a ray that passes
 * away from the segment a degenerate triangle spans. Scenes (sponza, sibenik) contain such triangles.
 * Oracle: the distance, in double precision, from the reported hit point to the segment. t >= 1e-4 as
 * for shadow segments (hits at t ~ 0 from rounding would be ignored there anyway). */
#include "testutil.h"
#include "accel/bvh.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static float rnd(tu_rng *r) { return (float)((tu_rng_next(r) >> 40) * (1.0 / 16777216.0)); }
static float rnd_in(tu_rng *r, float lo, float hi) { return lo + (hi - lo) * rnd(r); }

/* Zero-area triangles (a repeated vertex, or three collinear vertices) have no interior: whatever
 * ms_intersect_triangle reports for them, a reported hit point must lie on the segment they span
 * (within rounding). */
static void test_degenerate_triangles(void **st)
{
    (void)st;
    tu_rng g = { 10 };
    enum { N = 400 };
    float *soup = malloc(9 * N * sizeof(float));
    for (int m = 0; m < N; m++) {
        float a[3], b[3];
        for (int k = 0; k < 3; k++) { a[k] = rnd_in(&g, -5, 5); b[k] = a[k] + rnd_in(&g, -2, 2); }
        float w = m % 2 ? 0.5f : 1.0f;   /* collinear midpoint, or a repeated vertex */
        for (int k = 0; k < 3; k++) {
            soup[9 * m + k] = a[k];
            soup[9 * m + 3 + k] = b[k];
            soup[9 * m + 6 + k] = a[k] + w * (b[k] - a[k]);
        }
    }
    int spurious = 0, first = 1;
    long tests = 0;
    for (int it = 0; it < 4000; it++) {
        const float *tri = soup + 9 * (tu_rng_next(&g) % N);
        float o[3], d[3];
        float f = rnd(&g);
        for (int k = 0; k < 3; k++) { o[k] = rnd_in(&g, -10, 10); d[k] = tri[k] + f * (tri[3 + k] - tri[k]) - o[k]; }
        for (int m = 0; m < N; m++) {
            float t, u, v;
            tests++;
            if (!ms_intersect_triangle(soup + 9 * m, o, d, 1e-4f, INFINITY, &t, &u, &v)) continue;
            /* Distance from the hit point to the segment a-b, relative to the scene's size. */
            const float *A = soup + 9 * m, *B = soup + 9 * m + 3;
            double ab[3], ap[3], abab = 0, apab = 0;
            for (int k = 0; k < 3; k++) { ab[k] = (double)B[k] - A[k]; ap[k] = o[k] + (double)t * d[k] - A[k]; abab += ab[k] * ab[k]; apab += ap[k] * ab[k]; }
            double s = apab / abab, dist2 = 0;
            s = s < 0 ? 0 : s > 1 ? 1 : s;
            for (int k = 0; k < 3; k++) { double e = ap[k] - s * ab[k]; dist2 += e * e; }
            if (sqrt(dist2) > 1e-4) {
                spurious++;
                if (first) {
                    first = 0;
                    print_message("zero-area triangle %d (%g %g %g)-(%g %g %g) reported hit at t=%g, %g away from it\n", m,
                                  A[0], A[1], A[2], B[0], B[1], B[2], t, sqrt(dist2));
                }
            }
        }
    }
    if (spurious) print_message("%d of %ld ray/zero-area-triangle tests report a hit off the triangle\n", spurious, tests);
    free(soup);
    assert_int_equal(spurious, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_degenerate_triangles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
