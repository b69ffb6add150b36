/* ms_light_irradiance against (a) brute-force midpoint integration of cos_p * cos_l / r^2 over the
 * parallelogram, counting only light points above the receiver's horizon and on the emitting side,
 * and (b) the closed form for a point below the corner of a parallel rectangle. */
#include "testutil.h"
#include <math.h>
#include <stdio.h>

static double brute(const ms_light *l, const double p[3], const double n[3], int N)
{
    const double P[3] = { l->corner.x, l->corner.y, l->corner.z }, S[3] = { l->edge_s.x, l->edge_s.y, l->edge_s.z },
                 T[3] = { l->edge_t.x, l->edge_t.y, l->edge_t.z };
    double ln[3] = { S[1] * T[2] - S[2] * T[1], S[2] * T[0] - S[0] * T[2], S[0] * T[1] - S[1] * T[0] };
    double area = sqrt(ln[0] * ln[0] + ln[1] * ln[1] + ln[2] * ln[2]);
    for (int a = 0; a < 3; a++) ln[a] /= area;
    double sum = 0;
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            double s = (i + 0.5) / N, t = (j + 0.5) / N, d[3];
            for (int a = 0; a < 3; a++) d[a] = P[a] + s * S[a] + t * T[a] - p[a];
            double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], r = sqrt(r2);
            double cp = (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / r;
            double cl = -(d[0] * ln[0] + d[1] * ln[1] + d[2] * ln[2]) / r;
            if (cp > 0 && cl > 0) sum += cp * cl / r2;
        }
    return sum * area / ((double)N * N);
}

static float eval(const ms_light *l, const double p[3], const double n[3])
{
    double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const float pf[3] = { (float)p[0], (float)p[1], (float)p[2] }, nf[3] = { (float)(n[0] / nl), (float)(n[1] / nl), (float)(n[2] / nl) };
    return ms_light_irradiance(l, pf, nf);
}

static double g_worst;   /* worst relative error seen, reported */

static void check(const ms_light *l, double px, double py, double pz, double nx, double ny, double nz, double rel)
{
    double p[3] = { px, py, pz }, n[3] = { nx, ny, nz };
    double nl = sqrt(nx * nx + ny * ny + nz * nz);
    for (int a = 0; a < 3; a++) n[a] /= nl;
    double want = brute(l, p, n, 1000);
    float got = eval(l, p, n);
    if (!(want > 1e-3)) fail_msg("p=(%g %g %g): integration gives %g: not a useful case", px, py, pz, want);
    if (fabs(got - want) / want > g_worst) g_worst = fabs(got - want) / want;
    if (!(fabs(got - want) <= rel * want + 1e-6))
        fail_msg("p=(%g %g %g) n=(%g %g %g): ms_light_irradiance %.7g, integration %.7g", px, py, pz, nx, ny, nz, got, want);
}

static void test_against_integration(void **st)
{
    (void)st;
    /* The Quad light (emits down) and a tilted, non-rectangular one. */
    ms_light quad = { { -1, 6, -1 }, { 2, 0, 0 }, { 0, 0, 2 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    ms_light tilt = { { 0.5f, 3, -1 }, { 1.5f, -0.6f, 0.2f }, { 0.3f, 0.4f, 1.7f }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    check(&quad, 0, 0, 0, 0, 1, 0, 1e-4);
    check(&quad, 3, 0, -2, 0, 1, 0, 1e-4);
    check(&quad, 0.5, 4, 0.2, 0, 1, 0, 1e-4);
    check(&quad, 2, 1, 1, 0.3, 1, -0.2, 1e-4);
    check(&quad, -4, 2, 3, 1, 0.5, -1, 1e-4);
    /* Partly below the horizon: a wall (normal +x) at x = 0 under the light's middle sees half of it. */
    check(&quad, 0, 2, 0, 1, 0, 0, 1e-4);
    check(&quad, 0.3, 5, -0.2, 1, 0.4, 0.1, 1e-4);
    check(&quad, -0.5, 5.5, 0.5, 0.2, 0.3, 1, 1e-4);
    /* Which side of the tilted light emits: cross(edge_s, edge_t) has a negative y, so points below. */
    check(&tilt, 1, 0, 0, 0, 1, 0, 1e-4);
    check(&tilt, 2, 1, 1, 0.5, 1, -0.4, 1e-4);
    check(&tilt, 1.2, 2.5, 0, 1, 0.2, 0.3, 1e-4);
    check(&tilt, 0, -1, 2, -0.3, 1, -1, 1e-4);
    /* The straddling cases are really partial: less than with the horizon ignored. */
    double p[3] = { 0, 2, 0 }, up[3] = { 0, 1, 0 }, side[3] = { 1, 0, 0 };
    assert_true(eval(&quad, p, side) < 0.9 * eval(&quad, p, up));
    print_message("worst relative error against integration: %.2e\n", g_worst);
}

static void test_zero_cases(void **st)
{
    (void)st;
    ms_light quad = { { -1, 6, -1 }, { 2, 0, 0 }, { 0, 0, 2 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    double above[3] = { 0, 7, 0 }, below[3] = { 0, 0, 0 }, up[3] = { 0, 1, 0 }, down[3] = { 0, -1, 0 };
    assert_true(eval(&quad, above, up) == 0.0f);      /* behind the light (it emits downwards) */
    assert_true(eval(&quad, above, down) == 0.0f);
    assert_true(eval(&quad, below, down) == 0.0f);    /* entirely below the receiver's horizon */
    double far_side[3] = { 5, 6, 0 }, nx[3] = { 1, 0, 0 };
    assert_true(eval(&quad, far_side, nx) == 0.0f);   /* in the light's plane */
}

/* Point at distance c below a corner of an a x b rectangle parallel to the receiver:
 * E/L = pi F = 1/2 [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))], X = a/c, Y = b/c. */
static void test_closed_form(void **st)
{
    (void)st;
    const double cases[][3] = { { 2, 2, 6 }, { 1, 3, 0.5 }, { 5, 0.2, 2 }, { 1, 1, 1 } };
    for (int i = 0; i < 4; i++) {
        double a = cases[i][0], b = cases[i][1], c = cases[i][2], X = a / c, Y = b / c;
        double want = 0.5 * (X / sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) + Y / sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y)));
        ms_light l = { { 0, (float)c, 0 }, { (float)a, 0, 0 }, { 0, 0, (float)b }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
        double p[3] = { 0, 0, 0 }, n[3] = { 0, 1, 0 };
        float got = eval(&l, p, n);
        if (!(fabs(got - want) < 1e-5 * (1 + want))) fail_msg("rectangle %g x %g at %g: %.7g, closed form %.7g", a, b, c, got, want);
    }
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_form),
        cmocka_unit_test(test_zero_cases),
        cmocka_unit_test(test_against_integration),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
