/* What bakers expect of a lightmap (docs/baking.md, "Quality"), against independent answers:
 *   - no leaks at contacts: a closed box resting on a floor; texels whose centre lies under the box within
 *     their footprint of its side are moved out (their points end outside the box), and at floor points just
 *     outside the box the bilinear lookup of the bake matches ms_visibility_points irradiance computed there
 *     (without the fix, the contact's black bleeds out: measured and reported, and worse);
 *   - padding: with --padding 2, no texel of one chart (connected triangles in UV space, found here) lies
 *     within 2 texels of another chart's texel, so bilinear lookups (1 texel around a chart) never mix charts
 *     whatever fills the gap (the default, footprints touching, is tests/test_bake_padding.c's);
 *   - the seam error is measured (ms_lightmap.seam_*: smooth edges - the same shading normals on both sides,
 *     planes within 8 degrees without them - not creases) and agrees with the same measure taken here at
 *     the seam points from the lightmap's rgb (tests/test_bake_seams.c checks the stitching itself);
 *   - each pass reports once, in order (ms_bake_options.pass). */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIZE 128

/* A 4x4 floor (OBJ with vt: u = (x+2)/4, v = (z+2)/4 as set 0), a closed 1x1x1 box on it (no UVs), a light. */
static void write_scene(const char *dir, char *json, size_t n)
{
    char p[1024];
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "floor.obj"),
        "v -2 0 -2\nv -2 0 2\nv 2 0 2\nv 2 0 -2\nvt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "box.obj"),
        "v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5\nv -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n"
        "f 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n"), 0);
    assert_int_equal(tu_write_file(tu_path(json, n, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"floor.obj\"},{\"file\":\"box.obj\"}],"
        "\"camera\":{\"eye\":[0,5,5],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":32,\"height\":32},"
        "\"light\":{\"corner\":[0.5,3,-1.5],\"edge_s\":[1,0,0],\"edge_t\":[0,0,1],\"emission\":[1,1,1]}}"), 0);
}

static char g_passes[512];
static void note_pass(void *user, const char *pass, double s)
{
    (void)user;
    assert_true(s >= 0.0);
    snprintf(g_passes + strlen(g_passes), sizeof g_passes - strlen(g_passes), "%s;", pass);
}

static void bake(const ms_scene *sc, int no_fix, ms_lightmap *lm)
{
    ms_bake_options bo;
    tu_bake_options(&bo, SIZE, 0, 256);
    bo.no_leak_fix = no_fix;
    bo.pass = note_pass;
    char err[512] = "";
    assert_int_equal(ms_bake(sc, NULL, &bo, lm, err, sizeof err), MS_OK);
}

/* The floor's baked UV of world point (x, 0, z), from its triangles' baked UVs (barycentric in x, z). */
static int floor_uv(const ms_scene *sc, const ms_lightmap *lm, double x, double z, double uv[2], uint32_t *tri)
{
    for (size_t t = 0; t < sc->n_tris; t++) {
        if (sc->tri_mesh[t] != 0) continue;
        const float *p = sc->tri + 9 * t, *u = lm->uv + 6 * t;
        const double d = (p[3] - p[0]) * (p[8] - p[2]) - (p[5] - p[2]) * (p[6] - p[0]);
        const double w1 = ((x - p[0]) * (p[8] - p[2]) - (z - p[2]) * (p[6] - p[0])) / d;
        const double w2 = ((p[3] - p[0]) * (z - p[2]) - (p[5] - p[2]) * (x - p[0])) / d;
        if (w1 < 0 || w2 < 0 || w1 + w2 > 1) continue;
        uv[0] = (1 - w1 - w2) * u[0] + w1 * u[2] + w2 * u[4];
        uv[1] = (1 - w1 - w2) * u[1] + w1 * u[3] + w2 * u[5];
        *tri = (uint32_t)t;
        return 1;
    }
    return 0;
}

/* At floor points 0.3 texel outside each side of the box: baked (bilinear) against the oracle; mean and worst
 * |dE| / Emax. */
static void contact_error(const ms_scene *sc, const ms_lightmap *lm, double *mean, double *worst)
{
    char err[256];
    ms_accel *acc;
    assert_int_equal(ms_accel_build(sc, 0, &acc, err, sizeof err), MS_OK);
    double emax = 0.0;
    for (size_t i = 0; i < (size_t)SIZE * SIZE; i++) emax = fmax(emax, lm->frame.rgb[3 * i + 1]);
    double texel = 0.0;   /* the floor's texel size in world units */
    {
        const float *u = NULL;
        for (size_t t = 0; t < sc->n_tris && !u; t++) if (sc->tri_mesh[t] == 0) u = lm->uv + 6 * t;
        const double ua = fabs(((double)u[2] - u[0]) * ((double)u[5] - u[1]) - ((double)u[3] - u[1]) * ((double)u[4] - u[0])) * SIZE * SIZE;
        texel = sqrt(16.0 / ua);   /* a floor triangle has area 8; ua is twice its UV area */
    }
    const double off = 0.5 + 0.3 * texel;   /* 0.3 texel outside the box */
    double sum = 0.0;
    *worst = 0.0;
    int n = 0;
    for (int side = 0; side < 4; side++)
        for (int k = 0; k < 40; k++) {
            const double s = -0.45 + 0.9 * (k + 0.5) / 40.0;
            const double x = side == 0 ? -off : side == 1 ? off : s, z = side == 2 ? -off : side == 3 ? off : s;
            double uv[2] = { 0, 0 };
            uint32_t tri = 0;
            assert_true(floor_uv(sc, lm, x, z, uv, &tri));
            const double got = tu_lightmap_green(&lm->frame, 0, uv[0], uv[1]);
            const float p[3] = { (float)x, 0.0f, (float)z }, nrm[3] = { 0, 1, 0 };
            const double want = tu_point_irradiance(acc, sc, p, nrm, tri, uv, SIZE);
            sum += fabs(got - want) / emax;
            *worst = fmax(*worst, fabs(got - want) / emax);
            n++;
        }
    *mean = sum / n;
    ms_accel_free(acc);
}

static void test_contacts(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_quality");
    char json[1024], err[512] = "";
    write_scene(dir, json, sizeof json);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_lightmap fixed, raw;
    g_passes[0] = 0;
    bake(&sc, 0, &fixed);
    printf("passes: %s\n", g_passes);
    assert_string_equal(g_passes, "UVs;texels;leak test;acceleration structure;light 1/1;irradiance and dilation;seam stitching;seams;");
    g_passes[0] = 0;
    bake(&sc, 1, &raw);
    assert_string_equal(g_passes, "UVs;texels;acceleration structure;light 1/1;irradiance and dilation;seam stitching;seams;");
    assert_true(fixed.texels_moved > 0);
    assert_int_equal(raw.texels_moved, 0);
    /* every floor texel the fix moved: its point was under the box, now it is outside the box's footprint, on
     * the floor's plane (the lift of 1e-3 texel aside) */
    size_t moved = 0, were_dark = 0, deep = 0;
    double texel = 0.0;   /* the floor's texel in world units: a floor triangle has area 8, the determinant twice its UV area */
    for (size_t t = 0; t < sc.n_tris && texel == 0.0; t++)
        if (sc.tri_mesh[t] == 0) {
            const float *u = fixed.uv + 6 * t;
            texel = sqrt(16.0 / (fabs(((double)u[2] - u[0]) * ((double)u[5] - u[1]) - ((double)u[3] - u[1]) * ((double)u[4] - u[0])) * SIZE * SIZE));
        }
    for (size_t i = 0; i < (size_t)SIZE * SIZE; i++) {
        const uint32_t t = fixed.triangle[i];
        if (t == MS_NO_TRIANGLE || sc.tri_mesh[t] != 0) continue;
        const float *a = raw.position + 3 * i, *b = fixed.position + 3 * i;
        /* how far inside the box's footprint the texel's own point is (<= 0: outside) */
        const double inside = 0.5 - fmax(fabs(a[0]), fabs(a[2]));
        if (a[0] == b[0] && a[2] == b[2]) {   /* not moved: outside, or deeper inside than its footprint reaches */
            assert_true(inside <= 0.0 || inside >= 0.74 * texel);
            deep += inside > 0.0;
            continue;
        }
        assert_true(inside > 0.0 && inside < 0.76 * texel);
        assert_false(fabsf(b[0]) < 0.5f && fabsf(b[2]) < 0.5f);
        assert_true(fabsf(b[1]) < 1e-3f);
        were_dark += raw.frame.vis[i] == 0.0f;
        moved++;
    }
    double mf, wf, mr, wr;
    contact_error(&sc, &fixed, &mf, &wf);
    contact_error(&sc, &raw, &mr, &wr);
    printf("contacts: %zu floor texels moved out from under the box (%zu of them dark before; %zu deeper left alone); floor "
           "points 0.3 texel outside the box, bake vs oracle |dE|/Emax: with the fix mean %.4f worst %.4f, without mean %.4f "
           "worst %.4f\n", moved, were_dark, deep, mf, wf, mr, wr);
    printf("seams: with the fix %zu points mean %.4f max %.4f; without mean %.4f max %.4f\n", fixed.seam_points, fixed.seam_mean,
           fixed.seam_max, raw.seam_mean, raw.seam_max);
    assert_true(moved > 0 && were_dark > 0);
    assert_true(mf < 0.5 * mr && wf < wr);
    assert_true(mf < 0.02 && wf < 0.08);
    ms_lightmap_free(&fixed);
    ms_lightmap_free(&raw);
    ms_scene_free(&sc);
}

/* Charts: triangles joined by an edge whose two endpoints have the same baked UVs (union-find). */
static uint32_t find(uint32_t *par, uint32_t a)
{
    while (par[a] != a) a = par[a] = par[par[a]];
    return a;
}

#define MAX_PTS 200000

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Edge (i, i2) of triangle a is edge (j, j2) of triangle b, vertex i on vertex j: smooth when both have shading
 * normals there and they agree at both ends (cosine >= 0.9999), else when the planes (na, nb: unnormalised,
 * squared lengths la, lb) meet within 8 degrees facing the same way. */
static int smooth(const ms_scene *sc, size_t a, size_t b, int i, int i2, int j, int j2, const double *na, const double *nb,
                  double la, double lb)
{
    const int va[2] = { i, i2 }, vb[2] = { j, j2 };
    int have = sc->tri_normal != NULL, ok = 1;
    for (int e = 0; e < 2 && have; e++) {
        const float *p = sc->tri_normal + 9 * a + 3 * va[e], *q = sc->tri_normal + 9 * b + 3 * vb[e];
        const double lp = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
        const double lq = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2]);
        have = lp > 0 && lq > 0 && isfinite(lp) && isfinite(lq);
        if (have) ok &= ((double)p[0] * q[0] + (double)p[1] * q[1] + (double)p[2] * q[2]) / (lp * lq) >= 0.9999;
    }
    if (have) return ok;
    return (na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2]) / sqrt(la * lb) >= 0.99;
}

static void test_padding_and_seams(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_bake_options bo;
    tu_bake_options(&bo, 256, -1, 256);
    bo.padding = 2;
    char err[512] = "";
    ms_lightmap lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    const size_t n = sc.n_tris;
    uint32_t *par = malloc(n * sizeof *par);
    assert_non_null(par);
    for (size_t t = 0; t < n; t++) par[t] = (uint32_t)t;
    for (size_t a = 0; a < n; a++)
        for (size_t b = a + 1; b < n; b++) {
            int shared = 0;
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    shared += !memcmp(sc.tri + 9 * a + 3 * i, sc.tri + 9 * b + 3 * j, 12) &&
                              !memcmp(lm.uv + 6 * a + 2 * i, lm.uv + 6 * b + 2 * j, 8);
            if (shared >= 2) par[find(par, (uint32_t)a)] = find(par, (uint32_t)b);
        }
    long close = 0, pairs = 0;
    const int S = lm.frame.width;
    for (int y = 0; y < S; y++)
        for (int x = 0; x < S; x++) {
            const uint32_t t = lm.triangle[(size_t)y * S + x];
            if (t == MS_NO_TRIANGLE) continue;
            for (int dy = -2; dy <= 2; dy++)
                for (int dx = -2; dx <= 2; dx++) {
                    const int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= S || yy >= S) continue;
                    const uint32_t u = lm.triangle[(size_t)yy * S + xx];
                    if (u == MS_NO_TRIANGLE) continue;
                    pairs++;
                    close += find(par, t) != find(par, u);
                }
        }
    printf("padding: %ld texel pairs within 2 texels, %ld of them of two charts\n", pairs, close);
    assert_int_equal(close, 0);
    /* the seam measure taken here: every edge shared in space by exactly two baked triangles with different UVs */
    int *uses = calloc(n, sizeof *uses);   /* per (a, i): how many baked triangles have that edge */
    double *dv = malloc(MAX_PTS * sizeof *dv);
    assert_non_null(uses);
    assert_non_null(dv);
    double sum = 0.0, mx = 0.0, fmx = 0.0;
    long pts = 0;
    for (size_t i = 0; i < (size_t)S * S; i++)
        if (lm.frame.vis[i] >= 0.0f)
            for (int c = 0; c < 3; c++) fmx = fmax(fmx, lm.frame.rgb[3 * i + c]);
    for (size_t a = 0; a < n; a++) if (isfinite(lm.uv[6 * a])) for (int i = 0; i < 3; i++) {
        const int i2 = (i + 1) % 3;
        int cnt = 0;
        for (size_t b = 0; b < n; b++) {
            if (!isfinite(lm.uv[6 * b])) continue;
            for (int j = 0; j < 3; j++) {
                const float *pa = sc.tri + 9 * a, *pb = sc.tri + 9 * b;
                const int j2 = (j + 1) % 3;
                cnt += (!memcmp(pa + 3 * i, pb + 3 * j, 12) && !memcmp(pa + 3 * i2, pb + 3 * j2, 12)) ||
                       (!memcmp(pa + 3 * i, pb + 3 * j2, 12) && !memcmp(pa + 3 * i2, pb + 3 * j, 12));
            }
        }
        uses[a] |= (cnt == 2) << i;
    }
    for (size_t a = 0; a < n; a++)
        for (size_t b = a + 1; b < n; b++)
            for (int i = 0; i < 3; i++) {
                const int i2 = (i + 1) % 3;
                if (!(uses[a] >> i & 1) || !isfinite(lm.uv[6 * b])) continue;
                for (int j = 0; j < 3; j++) {
                    const int j2 = (j + 1) % 3;
                    const float *pa = sc.tri + 9 * a, *pb = sc.tri + 9 * b;
                    int same = !memcmp(pa + 3 * i, pb + 3 * j, 12) && !memcmp(pa + 3 * i2, pb + 3 * j2, 12);
                    int rev = !memcmp(pa + 3 * i, pb + 3 * j2, 12) && !memcmp(pa + 3 * i2, pb + 3 * j, 12);
                    if (!same && !rev) continue;
                    if (!memcmp(pa + 3 * i, pa + 3 * i2, 12)) continue;
                    double na[3], nb[3], la = 0, lb = 0;
                    for (int d = 0; d < 3; d++) {
                        const int d1 = (d + 1) % 3, d2 = (d + 2) % 3;
                        na[d] = (double)(pa[3 + d1] - pa[d1]) * (pa[6 + d2] - pa[d2]) - (double)(pa[3 + d2] - pa[d2]) * (pa[6 + d1] - pa[d1]);
                        nb[d] = (double)(pb[3 + d1] - pb[d1]) * (pb[6 + d2] - pb[d2]) - (double)(pb[3 + d2] - pb[d2]) * (pb[6 + d1] - pb[d1]);
                        la += na[d] * na[d];
                        lb += nb[d] * nb[d];
                    }
                    if (!(la > 0 && lb > 0)) continue;
                    if (!smooth(&sc, a, b, i, i2, same ? j : j2, same ? j2 : j, na, nb, la, lb)) continue;   /* a crease */
                    const float *ua0 = lm.uv + 6 * a + 2 * i, *ua1 = lm.uv + 6 * a + 2 * i2;
                    const float *ub0 = lm.uv + 6 * b + 2 * (same ? j : j2), *ub1 = lm.uv + 6 * b + 2 * (same ? j2 : j);
                    if (!memcmp(ua0, ub0, 8) && !memcmp(ua1, ub1, 8)) continue;
                    /* 2 points per texel of the longer side's UV length */
                    const double len = fmax(hypot((double)ua1[0] - ua0[0], (double)ua1[1] - ua0[1]),
                                            hypot((double)ub1[0] - ub0[0], (double)ub1[1] - ub0[1])) * S;
                    const int ns = len * 2 < 1 ? 1 : (int)ceil(len * 2);
                    for (int k = 0; k < ns; k++) {
                        /* both sides parametrised from the same endpoint (the smaller in byte order) */
                        const int flip = memcmp(pa + 3 * i, pa + 3 * i2, 12) > 0;
                        const double s = flip ? 1.0 - (k + 0.5) / ns : (k + 0.5) / ns;
                        double va = 0, vb = 0;
                        for (int side = 0; side < 2; side++) {
                            const float *u0 = side ? ub0 : ua0, *u1 = side ? ub1 : ua1;
                            const double u = u0[0] + s * (u1[0] - u0[0]), v = u0[1] + s * (u1[1] - u0[1]);
                            const double x = u * S - 0.5, y = v * S - 0.5;
                            const int x0 = (int)floor(x), y0 = (int)floor(y);
                            double acc = 0.0;
                            for (int q = 0; q < 4; q++) {
                                int xx = x0 + (q & 1), yy = y0 + (q >> 1);
                                xx = xx < 0 ? 0 : xx >= S ? S - 1 : xx;
                                yy = yy < 0 ? 0 : yy >= S ? S - 1 : yy;
                                const float *c = lm.frame.rgb + 3 * ((size_t)yy * S + xx);
                                acc += ((q & 1) ? x - x0 : 1 - (x - x0)) * ((q >> 1) ? y - y0 : 1 - (y - y0)) * fmax(c[0], fmax(c[1], c[2]));
                            }
                            if (side) vb = acc; else va = acc;
                        }
                        assert_true(pts < MAX_PTS);
                        dv[pts] = fabs(va - vb) / fmx;
                        sum += dv[pts];
                        mx = fmax(mx, dv[pts]);
                        pts++;
                    }
                }
            }
    assert_true(pts > 100);
    qsort(dv, (size_t)pts, sizeof *dv, cmp_double);
    const double p99 = dv[(size_t)(0.99 * (double)(pts - 1))];
    printf("seams: the bake's %zu points mean %.5f p99 %.5f max %.5f; measured here %ld points mean %.5f p99 %.5f max %.5f\n",
           lm.seam_points, lm.seam_mean, lm.seam_p99, lm.seam_max, pts, sum / (double)pts, p99, mx);
    assert_int_equal((long)lm.seam_points, pts);
    assert_true(fabs(lm.seam_mean - sum / (double)pts) < 1e-6 && fabs(lm.seam_max - mx) < 1e-6 && fabs(lm.seam_p99 - p99) < 1e-6);
    free(par);
    free(uses);
    free(dv);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_contacts),
        cmocka_unit_test(test_padding_and_seams),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
