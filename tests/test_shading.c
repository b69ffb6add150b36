/* Surface shading (docs/shading.md) against independent oracles:
 *   - the unshadowed GGX specular of a parallelogram light by LTC (ms_ltc_ggx) against midpoint
 *     integration of the GGX BRDF (written here again, in double) times cos over the light;
 *   - the shadowed specular factor S_spec (ms_resolve_spec) against the brute-force ratio of the lobe's
 *     integral over the unoccluded light to that over the whole light, converging as k grows.
 * Materials, textures and normals in whole frames: test_shading_materials.c. */
#include "testutil.h"
#include "render/ltc.h"
#include "render/shade.h"
#include "visibility/receiver.h"
#include "light/pattern.h"
#include "camera/camera.h"
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- GGX in double, the oracle's own (height-correlated Smith, as the LTC fit) ---- */
static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double lambda_d(double alpha, double c)
{
    if (c >= 1.0) return 0.0;
    double t2 = (1.0 - c * c) / (c * c);
    return 0.5 * (-1.0 + sqrt(1.0 + alpha * alpha * t2));
}
/* f(v, l) * (n.l) for unit vectors. */
static double ggx_fcos(const double n[3], const double v[3], const double l[3], double alpha)
{
    double nv = dot3(n, v), nl = dot3(n, l);
    if (nv <= 0 || nl <= 0) return 0;
    double h[3] = { v[0] + l[0], v[1] + l[1], v[2] + l[2] }, hl = sqrt(dot3(h, h));
    double nh = dot3(n, h) / hl, a2 = alpha * alpha, d0 = nh * nh * (a2 - 1) + 1;
    double D = a2 / (M_PI * d0 * d0);
    return D / (1 + lambda_d(alpha, nv) + lambda_d(alpha, nl)) / (4 * nv);
}

typedef int (*occluder_fn)(const double p[3], const double l[3]);

/* Midpoint integral over the light of f cos * cos_l / r^2 (the specular lobe's share of the light per unit
 * radiance), over the points occ leaves visible (occ NULL: all). */
static double brute_spec(const ms_light *L, const double p[3], const double n[3], const double v[3], double alpha,
                         int N, occluder_fn occ)
{
    const double C[3] = { L->corner.x, L->corner.y, L->corner.z }, S[3] = { L->edge_s.x, L->edge_s.y, L->edge_s.z },
                 T[3] = { L->edge_t.x, L->edge_t.y, L->edge_t.z };
    double ln[3] = { S[1] * T[2] - S[2] * T[1], S[2] * T[0] - S[0] * T[2], S[0] * T[1] - S[1] * T[0] };
    double area = sqrt(dot3(ln, ln));
    for (int a = 0; a < 3; a++) ln[a] /= area;
    double sum = 0;
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            double s = (i + 0.5) / N, t = (j + 0.5) / N, q[3], d[3];
            if (L->shape == MS_LIGHT_DISK && (2 * s - 1) * (2 * s - 1) + (2 * t - 1) * (2 * t - 1) >= 1) continue;
            for (int a = 0; a < 3; a++) { q[a] = C[a] + s * S[a] + t * T[a]; d[a] = q[a] - p[a]; }
            double r2 = dot3(d, d), r = sqrt(r2), l[3] = { d[0] / r, d[1] / r, d[2] / r };
            double cl = -dot3(l, ln);
            if (cl <= 0 || dot3(d, n) <= 0) continue;
            if (occ && occ(p, q)) continue;
            sum += ggx_fcos(n, v, l, alpha) * cl / r2;
        }
    return sum * area / ((double)N * N);
}

/* The LTC's error as a share of the BRDF's directional albedo (the light that a white metal would reflect
 * from a light filling the hemisphere), measured below: worst 0.024 for views up to 60 degrees from the
 * normal, 0.088 at 80 degrees (the fit is poorest at grazing view). Bounds with margin: */
#define LTC_MAX_ERR 0.03
#define LTC_MAX_ERR_GRAZING 0.10

/* The directional albedo: f cos over the hemisphere, midpoint rule in (theta, phi). */
static double albedo(const double n[3], const double v[3], double alpha)
{
    (void)n;   /* n = (0, 1, 0): the hemisphere is parametrised around +y */
    const int NT = 400, NP = 800;
    double sum = 0;
    for (int i = 0; i < NT; i++) {
        double th = (i + 0.5) * (M_PI / 2) / NT, st = sin(th), ct = cos(th);
        for (int j = 0; j < NP; j++) {
            double ph = (j + 0.5) * 2 * M_PI / NP, l[3] = { st * cos(ph), ct, st * sin(ph) };
            sum += ggx_fcos(n, v, l, alpha) * st;
        }
    }
    return sum * (M_PI / 2 / NT) * (2 * M_PI / NP);
}


/* LTC against brute force over roughness, view angle and light placement. The LTC is a fit: its error is
 * what this measures and bounds (the bound is the worst seen here, with margin, reported below). */
static void test_ltc_against_brute_force(void **st)
{
    (void)st;
    const ms_light fixed[3] = {
        { .corner = { -1, 2, -1 }, .edge_s = { 2, 0, 0 }, .edge_t = { 0, 0, 2 }, .emission = { 1, 1, 1 } },      /* above, facing down */
        { .corner = { -3, 0.3f, -0.5f }, .edge_s = { 0, 1, 0 }, .edge_t = { 0, 0, 1 }, .emission = { 1, 1, 1 } }, /* low, near the horizon, facing +x */
        { .corner = { 0, 0, 0 }, .edge_s = { 0, 0, 0 }, .edge_t = { 0, 0, 0 }, .emission = { 1, 1, 1 } },        /* per view: on the mirror direction */
    };
    const double roughness[] = { 0.25, 0.4, 0.6, 0.8, 1.0 };
    const double view_deg[] = { 0, 30, 60, 80 };
    double worst[2] = { 0, 0 }, sum[2] = { 0, 0 };   /* |error| / albedo: views up to 60 degrees, and 80 */
    int n[2] = { 0, 0 };
    double alb[5][4];
    for (int ri = 0; ri < 5; ri++)
        for (int vi = 0; vi < 4; vi++) {
            double th = view_deg[vi] * M_PI / 180, v[3] = { sin(th), cos(th), 0.3 * sin(th) }, nn[3] = { 0, 1, 0 };
            tu_unit3(v);
            alb[ri][vi] = albedo(nn, v, roughness[ri] * roughness[ri]);
        }
    for (int li = 0; li < 3; li++)
        for (int ri = 0; ri < 5; ri++)
            for (int vi = 0; vi < 4; vi++)
                for (int side = -1; side <= 1; side += 2) {
                    ms_light L = fixed[li];
                    double p[3] = { 0, 0, 0 }, nn[3] = { 0, 1, 0 };
                    double th = view_deg[vi] * M_PI / 180;
                    double v[3] = { side * sin(th), cos(th), 0.3 * sin(th) };
                    tu_unit3(v);
                    if (li == 2) {
                        /* A 1 x 1 light 3 away on the mirror direction r = 2 (n.v) n - v, facing p. */
                        double r[3] = { -v[0], 2 * v[1] - v[1] * 0 - v[1], -v[2] };
                        r[1] = 2 * dot3(nn, v) - v[1];
                        tu_unit3(r);
                        double a[3] = { 0, 0, 1 }, e1[3], e2[3];
                        e1[0] = r[1] * a[2] - r[2] * a[1]; e1[1] = r[2] * a[0] - r[0] * a[2]; e1[2] = r[0] * a[1] - r[1] * a[0];
                        tu_unit3(e1);
                        e2[0] = r[1] * e1[2] - r[2] * e1[1]; e2[1] = r[2] * e1[0] - r[0] * e1[2]; e2[2] = r[0] * e1[1] - r[1] * e1[0];
                        /* emitting side cross(edge_s, edge_t) = cross(e2, e1) = -r: towards p */
                        L.corner = (ms_vec3){ (float)(3 * r[0] - 0.5 * (e1[0] + e2[0])), (float)(3 * r[1] - 0.5 * (e1[1] + e2[1])),
                                              (float)(3 * r[2] - 0.5 * (e1[2] + e2[2])) };
                        L.edge_s = (ms_vec3){ (float)e2[0], (float)e2[1], (float)e2[2] };
                        L.edge_t = (ms_vec3){ (float)e1[0], (float)e1[1], (float)e1[2] };
                    }
                    double a = roughness[ri] * roughness[ri];
                    double ref = brute_spec(&L, p, nn, v, a, 700, NULL);
                    const float pf[3] = { 0, 0, 0 }, nf[3] = { 0, 1, 0 }, vf[3] = { (float)v[0], (float)v[1], (float)v[2] };
                    double got = ms_ltc_ggx(&L, pf, nf, vf, (float)roughness[ri]);
                    const double e = fabs(got - ref) / alb[ri][vi];
                    const int g = view_deg[vi] > 60;
                    if (e > worst[g]) worst[g] = e;
                    sum[g] += e;
                    n[g]++;
                    if (getenv("MS_TEST_VERBOSE"))
                        printf("light %d r %.2f view %2.0f side %+d: ltc %.5f brute %.5f albedo %.4f |error|/albedo %.4f\n", li,
                               roughness[ri], view_deg[vi], side, got, ref, alb[ri][vi], e);
                }
    printf("LTC vs brute force, |error| / directional albedo: views 0-60 degrees (%d cases): worst %.4f, mean %.4f; "
           "view 80 degrees (%d cases): worst %.4f, mean %.4f\n", n[0], worst[0], sum[0] / n[0], n[1], worst[1], sum[1] / n[1]);
    assert_true(worst[0] < LTC_MAX_ERR);
    assert_true(worst[1] < LTC_MAX_ERR_GRAZING);
}

/* The same for disk lights (the ellipse inscribed in the parallelogram; ltc.c integrates the equal-area
 * 32-gon): the fit's error bound plus the polygon's, against brute force over the disk itself. */
static void test_ltc_disk_against_brute_force(void **st)
{
    (void)st;
    const ms_light fixed[2] = {
        { .corner = { -1, 2, -1 }, .edge_s = { 2, 0, 0 }, .edge_t = { 0, 0, 2 }, .emission = { 1, 1, 1 }, .shape = MS_LIGHT_DISK },
        { .corner = { -3, 0.3f, -0.5f }, .edge_s = { 0, 1, 0 }, .edge_t = { 0, 0, 1 }, .emission = { 1, 1, 1 }, .shape = MS_LIGHT_DISK },
    };
    const double roughness[] = { 0.25, 0.6, 1.0 };
    const double view_deg[] = { 0, 30, 60 };
    double worst = 0, sum = 0;
    int n = 0;
    for (int li = 0; li < 2; li++)
        for (int ri = 0; ri < 3; ri++)
            for (int vi = 0; vi < 3; vi++) {
                double p[3] = { 0, 0, 0 }, nn[3] = { 0, 1, 0 }, th = view_deg[vi] * M_PI / 180;
                double v[3] = { sin(th), cos(th), 0.3 * sin(th) };
                tu_unit3(v);
                const double a = roughness[ri] * roughness[ri];
                const double ref = brute_spec(&fixed[li], p, nn, v, a, 700, NULL);
                const float pf[3] = { 0, 0, 0 }, nf[3] = { 0, 1, 0 }, vf[3] = { (float)v[0], (float)v[1], (float)v[2] };
                const double e = fabs(ms_ltc_ggx(&fixed[li], pf, nf, vf, (float)roughness[ri]) - ref) / albedo(nn, v, a);
                if (e > worst) worst = e;
                sum += e;
                n++;
            }
    printf("LTC on disks vs brute force over the disk, |error| / directional albedo (%d cases): worst %.4f, mean %.4f\n",
           n, worst, sum / n);
    assert_true(worst < LTC_MAX_ERR);
}

/* The occluder of the convergence test: the half-plane y = 1, x < 0.1 (an edge across the light). */
static int half_plane(const double p[3], const double l[3])
{
    double u = (1.0 - p[1]) / (l[1] - p[1]);
    if (!(u > 0 && u < 1)) return 0;
    return p[0] + u * (l[0] - p[0]) < 0.1;
}

/* S_spec of one receiver from masks made here (front by ms_front_mask, visibility by half_plane on the
 * grid's sample points): the renderer's estimator on exact per-sample visibility. */
static float s_spec_at(const ms_light *L, int k, uint32_t px, const float p[3], const float n[3], const ms_surface *sf,
                       float *s_out)
{
    ms_render_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.light = *L;
    ctx.pattern = MS_PATTERN_GRID;
    ctx.k = k;
    ctx.samples = k * k;
    ctx.mask_words = k * k / 64;
    ctx.isa_cap = tu_isa_cap();
    ms_shadow_query q;
    memset(&q, 0, sizeof q);
    memcpy(q.p, p, sizeof q.p);
    memcpy(q.n, n, sizeof q.n);
    q.px = px;
    q.py = 7;
    q.prim = UINT32_MAX;
    uint64_t front[64], vis[64];
    ms_front_mask(&ctx, &q, NULL, front);
    ms_grid g;
    ms_grid_for_pixel(L, k, q.px, q.py, 0, &g);
    memset(vis, 0, sizeof vis);
    for (int s = 0; s < k * k; s++) {
        if (!ms_mask_get(front, s)) continue;
        double lp[3], pd[3] = { p[0], p[1], p[2] };
        for (int c = 0; c < 3; c++) lp[c] = g.p0[c] + (float)(s % k) * g.ds[c] + (float)(s / k) * g.dt[c];
        if (!half_plane(pd, lp)) vis[s >> 6] |= UINT64_C(1) << (s & 63);
    }
    float v;
    ms_resolve_vs(&ctx, &q, NULL, front, vis, &v, s_out);
    return ms_resolve_spec(&ctx, &q, NULL, front, vis, sf);
}

/* Shadowed specular: S_spec converges to the brute-force share of the lobe's light that is unoccluded, as
 * the samples grow; and it is not S (the lobe weights the light differently from the form factor). */
static void test_shadowed_specular_converges(void **st)
{
    (void)st;
    const ms_light L = { .corner = { -1, 2, -1 }, .edge_s = { 2, 0, 0 }, .edge_t = { 0, 0, 2 }, .emission = { 1, 1, 1 } };
    const double roughness[] = { 0.3, 0.6 };
    const double pts[3][3] = { { 0, 0, 0 }, { 0.3, 0, 0.2 }, { -0.2, 0, -0.4 } };
    const int ks[3] = { 16, 32, 64 };
    double mean_err[3] = { 0, 0, 0 }, worst64 = 0;
    int cases = 0;
    for (int ri = 0; ri < 2; ri++)
        for (int pi = 0; pi < 3; pi++) {
            const double p[3] = { pts[pi][0], pts[pi][1], pts[pi][2] }, n[3] = { 0, 1, 0 };
            double v[3] = { -0.5 - p[0], 1.0, 0.4 - p[2] };   /* the eye over the far side: the lobe leans towards +x */
            tu_unit3(v);
            const double a = roughness[ri] * roughness[ri];
            const double ref = brute_spec(&L, p, n, v, a, 1500, half_plane) / brute_spec(&L, p, n, v, a, 1500, NULL);
            ms_surface sf;
            memset(&sf, 0, sizeof sf);
            sf.n[1] = 1.0f;
            for (int c = 0; c < 3; c++) sf.v[c] = (float)v[c];
            sf.roughness = (float)roughness[ri];
            sf.specular = 1;
            const float pf[3] = { (float)p[0], (float)p[1], (float)p[2] }, nf[3] = { 0, 1, 0 };
            float s_ff = 0;
            for (int ki = 0; ki < 3; ki++) {
                double err = 0;
                for (uint32_t px = 0; px < 8; px++) {   /* 8 pixels: 8 rotations and shifts of the grid */
                    const float ss = s_spec_at(&L, ks[ki], px, pf, nf, &sf, &s_ff);
                    err += fabs(ss - ref) / 8;
                }
                mean_err[ki] += err;
                if (ki == 2 && err > worst64) worst64 = err;
            }
            /* The form-factor S of the same masks differs from the lobe's ratio: S_spec measures the lobe. */
            assert_true(fabs(s_ff - ref) > 0.02);
            cases++;
        }
    for (int ki = 0; ki < 3; ki++) mean_err[ki] /= cases;
    printf("S_spec vs brute force, mean |error| over %d receivers x 8 pixels: k=16 %.5f, k=32 %.5f, k=64 %.5f "
           "(worst receiver at k=64 %.5f)\n", cases, mean_err[0], mean_err[1], mean_err[2], worst64);
    assert_true(mean_err[1] < mean_err[0]);
    assert_true(mean_err[2] < mean_err[1]);
    assert_true(worst64 < 0.01);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ltc_against_brute_force),
        cmocka_unit_test(test_ltc_disk_against_brute_force),
        cmocka_unit_test(test_shadowed_specular_converges),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
