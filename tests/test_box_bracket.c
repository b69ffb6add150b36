/* The block traversal's bracket of the Scanline kernel's projected box (src/shadow/microraster/box_bracket.h)
 * against the kernel's own arithmetic: for every lane the bracket calls sure, the sample range from the
 * projections x (1/z) must be the one from the kernel's division x / z (fl(x / z), minus or plus the slack,
 * clamped to [-1, k], rounded up or down, clamped to [0, k - 1]), bit for bit. Random triangles, and
 * adversarial ones whose projections land within a few ulps of a rounding boundary (an integer plus or
 * minus the slack), where x (1/z) and x / z do round to different ranges: there the bracket must say
 * "doubt" (counted, and the test asserts it happened, so that a bracket too narrow to cover the
 * difference between the two roundings fails here). */
#include <math.h>
#include <stdio.h>
#include "testutil.h"
#include "shadow/microraster/box_bracket.h"
#include "raster/raster_internal.h"   /* MS_BOX_SLACK */

/* The kernel's range of three projected values (raster_internal.h / block_raster_impl.h br_scan_setup). */
static void kernel_range(const float p[3], int k, float *i0, float *i1)
{
    const float slack = MS_BOX_SLACK, kf = (float)k;
    const float mn = fminf(fminf(p[0], p[1]), p[2]), mx = fmaxf(fmaxf(p[0], p[1]), p[2]);
    const float lo = fminf(fmaxf(mn - slack, -1.0f), kf), hi = fminf(fmaxf(mx + slack, -1.0f), kf);
    *i0 = fmaxf(ceilf(lo), 0.0f);
    *i1 = fminf(floorf(hi), kf - 1.0f);
}

static double unit(tu_rng *r) { return (double)(tu_rng_next(r) >> 11) * (1.0 / 9007199254740992.0); }

typedef struct tally { long sure, doubt, wrong_mult; } tally;

/* 16 lanes of three vertices (c, z): the bracket from fl(c fl(1/z)) against the kernel's fl(c / z). */
static void check_lanes(const float c[3][16], const float z[3][16], int k, tally *t)
{
    volatile float vz;   /* keeps the oracle's divisions and products separate roundings */
    l16 q[3];
    float qa[3][16], pa[3][16];
    for (int v = 0; v < 3; v++) {
        for (int l = 0; l < 16; l++) {
            vz = z[v][l];
            const float inv = 1.0f / vz;
            qa[v][l] = c[v][l] * inv;
            pa[v][l] = c[v][l] / vz;
        }
        q[v] = l16_load(qa[v]);
    }
    l16 i0, i1;
    const unsigned sure = br_box_bracket(q, l16_set1(MS_BOX_SLACK), l16_set1(-1.0f), l16_set1((float)k),
                                         l16_set1((float)k - 1.0f), &i0, &i1);
    float g0[16], g1[16];
    l16_store(g0, i0);
    l16_store(g1, i1);
    for (int l = 0; l < 16; l++) {
        const float p[3] = { pa[0][l], pa[1][l], pa[2][l] }, qq[3] = { qa[0][l], qa[1][l], qa[2][l] };
        float k0, k1, m0, m1;
        kernel_range(p, k, &k0, &k1);
        kernel_range(qq, k, &m0, &m1);
        if (!(sure >> l & 1)) { t->doubt++; continue; }
        t->sure++;
        t->wrong_mult += m0 != k0 || m1 != k1;   /* where x (1/z) alone would have been wrong */
        if (g0[l] != k0 || g1[l] != k1)
            fail_msg("k=%d lane %d: bracket %g..%g, kernel %g..%g (p %a %a %a, q %a %a %a)", k, l, g0[l], g1[l], k0, k1,
                     p[0], p[1], p[2], qq[0], qq[1], qq[2]);
    }
}

static void run(int k, int adversarial, long batches, tally *t)
{
    tu_rng r = { 29u + (uint64_t)k * 7u + (uint64_t)adversarial };
    float c[3][16], z[3][16];
    for (long b = 0; b < batches; b++) {
        for (int v = 0; v < 3; v++)
            for (int l = 0; l < 16; l++) {
                /* z over several decades (the near-light triangles have z close to 1, the others less). */
                const float zz = (float)(pow(10.0, -3.0 + 4.0 * unit(&r)));
                float target;
                if (adversarial) {
                    /* A boundary of the rounding: an integer, minus (lower bound) or plus (upper) the slack,
                     * moved by a few ulps. */
                    const int n = (int)(unit(&r) * (k + 2)) - 1;
                    const float edge = (float)n + ((tu_rng_next(&r) & 1) ? MS_BOX_SLACK : -MS_BOX_SLACK);
                    const int ulps = (int)(unit(&r) * 9.0) - 4;
                    target = edge;
                    for (int u = 0; u < (ulps < 0 ? -ulps : ulps); u++) target = nextafterf(target, ulps < 0 ? -INFINITY : INFINITY);
                } else {
                    target = (float)(-0.5 * k + 2.0 * k * unit(&r));
                }
                z[v][l] = zz;
                c[v][l] = target * zz;
            }
        check_lanes(c, z, k, t);
    }
}

static void test_random(void **state)
{
    (void)state;
    for (int k = 16; k <= 64; k *= 2) {
        tally t = { 0, 0, 0 };
        run(k, 0, 20000, &t);
        printf("random k=%d: %ld lanes sure (equal to the division), %ld in doubt\n", k, t.sure, t.doubt);
        assert_true(t.sure > 0);
        /* Doubt is rare away from the boundaries: the division's cost is then seldom paid. */
        assert_true(t.doubt * 100 < t.sure);
    }
}

static void test_adversarial(void **state)
{
    (void)state;
    for (int k = 16; k <= 64; k *= 2) {
        tally t = { 0, 0, 0 };
        run(k, 1, 20000, &t);
        printf("adversarial k=%d: %ld lanes sure (equal to the division), %ld in doubt\n", k, t.sure, t.doubt);
        assert_true(t.sure > 0);
        /* The boundaries are reached: some lanes are left to the division. */
        assert_true(t.doubt > 0);
    }
}

/* The bracket's reason to exist: x (1/z) and x / z do round to different ranges near a boundary. Found
 * among the adversarial lanes (the bracket must have left every such lane in doubt, which check_lanes
 * verified lane by lane; here only that such lanes exist, so that the test above is not vacuous). */
static void test_multiplication_alone_differs(void **state)
{
    (void)state;
    tu_rng r = { 4242u };
    long differ = 0;
    for (long i = 0; i < 2000000 && !differ; i++) {
        const float zz = (float)(pow(10.0, -3.0 + 4.0 * unit(&r)));
        const float target = nextafterf(7.0f + MS_BOX_SLACK, (tu_rng_next(&r) & 1) ? INFINITY : -INFINITY);
        const float c = target * zz;
        volatile float vz = zz;
        const float inv = 1.0f / vz;
        const float q = c * inv, p = c / vz;
        differ += ceilf(q - MS_BOX_SLACK) != ceilf(p - MS_BOX_SLACK);
    }
    printf("x (1/z) and x / z round to different sample indices: %s\n", differ ? "found" : "not found");
    assert_true(differ > 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random),
        cmocka_unit_test(test_adversarial),
        cmocka_unit_test(test_multiplication_alone_differs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
