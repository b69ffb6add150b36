/* Light sample patterns: every sample (i,j) (index j*k+i) lies in cell (i,j) of the light, on the
 * light's plane; the grid is an affine lattice whose k^2 samples take k^2 distinct values along each
 * light axis; both patterns are deterministic for (pixel, seed) and differ across pixels and seeds.
 * Oracle: each point solved back to (s,t) in the light's (non-orthogonal) frame in double precision. */
#include "testutil.h"
#include "light/pattern.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const ms_light L = { { 1, 5, -2 }, { 3, 0.5f, 0 }, { 0.8f, 0, 2 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };

/* Solves p - corner = s S + t T (least squares on the normal equations); returns the residual. */
static double to_st(const float *p, double *s, double *t)
{
    const double S[3] = { L.edge_s.x, L.edge_s.y, L.edge_s.z }, T[3] = { L.edge_t.x, L.edge_t.y, L.edge_t.z };
    double d[3] = { p[0] - (double)L.corner.x, p[1] - (double)L.corner.y, p[2] - (double)L.corner.z };
    double ss = 0, st = 0, tt = 0, ds = 0, dt = 0;
    for (int a = 0; a < 3; a++) { ss += S[a] * S[a]; st += S[a] * T[a]; tt += T[a] * T[a]; ds += d[a] * S[a]; dt += d[a] * T[a]; }
    double det = ss * tt - st * st;
    *s = (ds * tt - dt * st) / det;
    *t = (dt * ss - ds * st) / det;
    double r = 0;
    for (int a = 0; a < 3; a++) { double e = d[a] - *s * S[a] - *t * T[a]; r += e * e; }
    return sqrt(r);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void check_cells(ms_pattern pat, int k, uint32_t px, uint32_t py, uint32_t seed)
{
    float *xyz = malloc(3 * sizeof(float) * (size_t)(k * k));
    double *sv = malloc(sizeof(double) * (size_t)(k * k)), *tv = malloc(sizeof(double) * (size_t)(k * k));
    ms_pattern_points(pat, &L, k, px, py, seed, xyz);
    const double eps = 1e-5;   /* float rounding of the points, relative to the unit (s,t) square */
    for (int j = 0; j < k; j++)
        for (int i = 0; i < k; i++) {
            double s, t;
            double res = to_st(xyz + 3 * (j * k + i), &s, &t);
            assert_true(res < 1e-5);   /* on the light's plane */
            if (!(s >= (double)i / k - eps && s <= (double)(i + 1) / k + eps && t >= (double)j / k - eps && t <= (double)(j + 1) / k + eps))
                fail_msg("pattern %d k=%d pixel (%u,%u) seed %u: sample (%d,%d) at (s,t) = (%.7f, %.7f), outside its cell",
                         pat, k, px, py, seed, i, j, s, t);
            sv[j * k + i] = s;
            tv[j * k + i] = t;
        }
    if (pat == MS_PATTERN_GRID) {
        /* Rotated lattice: s takes k^2 distinct values about 1/k^2 apart, and so does t. */
        qsort(sv, (size_t)(k * k), sizeof *sv, cmp_double);
        qsort(tv, (size_t)(k * k), sizeof *tv, cmp_double);
        for (int n = 1; n < k * k; n++) {
            assert_true(sv[n] - sv[n - 1] > 0.5 / (k * k));
            assert_true(tv[n] - tv[n - 1] > 0.5 / (k * k));
        }
        /* Affine: sample(i,j) = p0 + i ds + j dt, as ms_grid_for_pixel reports. */
        ms_grid g;
        ms_grid_for_pixel(&L, k, px, py, seed, &g);
        assert_int_equal(g.k, k);
        for (int n = 0; n < k * k; n += 37) {
            int i = n % k, j = n / k;
            for (int a = 0; a < 3; a++)
                assert_true(fabsf(xyz[3 * n + a] - (g.p0[a] + (float)i * g.ds[a] + (float)j * g.dt[a])) < 1e-4f);
        }
    }
    free(xyz); free(sv); free(tv);
}

static void test_cells(void **st)
{
    (void)st;
    const int ks[3] = { 16, 32, 64 };
    for (int pat = 0; pat < 2; pat++)
        for (int ki = 0; ki < 3; ki++)
            for (uint32_t p = 0; p < 12; p++)
                check_cells((ms_pattern)pat, ks[ki], p * 97, p * 13 + 5, p % 3 == 0 ? 0 : 12345 + p);
    for (int k = 4; k <= 8; k *= 2)   /* stratified at 16 and 64 samples */
        for (uint32_t p = 0; p < 12; p++) check_cells(MS_PATTERN_STRATIFIED, k, p * 31, p + 2, p);
}

static void test_determinism_and_variation(void **st)
{
    (void)st;
    const int k = 16, n = 3 * k * k;
    float *a = malloc(sizeof(float) * n), *b = malloc(sizeof(float) * n);
    for (int pat = 0; pat < 2; pat++) {
        ms_pattern_points((ms_pattern)pat, &L, k, 10, 20, 7, a);
        ms_pattern_points((ms_pattern)pat, &L, k, 10, 20, 7, b);
        assert_memory_equal(a, b, sizeof(float) * n);
        ms_pattern_points((ms_pattern)pat, &L, k, 11, 20, 7, b);
        assert_memory_not_equal(a, b, sizeof(float) * n);
        ms_pattern_points((ms_pattern)pat, &L, k, 10, 21, 7, b);
        assert_memory_not_equal(a, b, sizeof(float) * n);
        ms_pattern_points((ms_pattern)pat, &L, k, 10, 20, 8, b);
        assert_memory_not_equal(a, b, sizeof(float) * n);
    }
    /* The stratified jitter of sample (0,0) over 4096 pixels averages to the middle of its cell. */
    double sum = 0;
    int cnt = 0;
    for (uint32_t y = 0; y < 64; y++)
        for (uint32_t x = 0; x < 64; x++) {
            ms_pattern_points(MS_PATTERN_STRATIFIED, &L, k, x, y, 3, a);
            double s, t;
            to_st(a, &s, &t);
            sum += s * k;   /* jitter of sample (0,0) within its cell, in [0,1) */
            cnt++;
        }
    assert_true(fabs(sum / cnt - 0.5) < 0.03);
    free(a); free(b);
}

static void test_samples_to_k(void **st)
{
    (void)st;
    assert_int_equal(ms_samples_to_k(256), 16);
    assert_int_equal(ms_samples_to_k(1024), 32);
    assert_int_equal(ms_samples_to_k(4096), 64);
    assert_int_equal(ms_samples_to_k(16), 4);    /* stratified only (ms_pattern_samples_per_pixel) */
    assert_int_equal(ms_samples_to_k(64), 8);
    assert_int_equal(ms_samples_to_k(0), 0);
    assert_int_equal(ms_samples_to_k(512), 0);
    assert_int_equal(ms_samples_to_k(-256), 0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cells),
        cmocka_unit_test(test_determinism_and_variation),
        cmocka_unit_test(test_samples_to_k),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
