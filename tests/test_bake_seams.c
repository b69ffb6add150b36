/* Seam stitching (docs/baking.md, "Seams"; src/render/bake_stitch.c), against answers taken here:
 *   - a smooth cylinder lying along z under a rect light, a plate's penumbra across it, its UVs one strip (the
 *     file's, written here) cut along a meridian: the two sides of the cut, sampled bilinearly by this test's
 *     own sampler at 16 points per texel, agree within p99 0.05 and mean 0.005 of the largest irradiance once
 *     stitched (and S, the shadowmask's, likewise), and disagree clearly more without (--no-seam-stitch);
 *   - texels no bilinear lookup along the cut reads (found here from the cut's UVs) keep their baked bits;
 *   - stitched, the lightmap looked up bilinearly at random points of the cylinder (and at points within a texel
 *     of the cut) still equals ms_visibility_points irradiance there: mean <= 0.002, worst <= 0.05 of the
 *     largest irradiance (issue #47);
 *   - a hexagonal prism with one normal per face (hard edges) keeps its cut's discontinuity: nothing stitched,
 *     the lightmap as without stitching; the same prism with smooth normals is stitched. */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIZE 128
#define SAMPLES 256
#define PI 3.14159265358979323846
#define R 0.5
#define PHI0 (PI / 4)   /* the cut, 45 degrees from the top: the irradiance changes fast across it */

/* A cylinder of radius R about the axis (0, 1, z), z in [-1, 1], n segments starting at PHI0; UVs one strip
 * u in [0.05, 0.95], v in [0.05, 0.05 + 0.9 * 2 / circumference] (square texels), the last column's right edge
 * the cut (the same positions, other UVs). smooth: one radial normal per vertex; else one per face (hard). */
static void write_cylinder(const char *path, int n, int smooth)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    const double v1 = 0.05 + 0.9 * 2.0 / (2 * PI * R);
    for (int j = 0; j < n; j++) {
        const double phi = PHI0 + 2 * PI * j / n;
        for (int e = 0; e < 2; e++) fprintf(f, "v %.9g %.9g %d\n", R * cos(phi), 1.0 + R * sin(phi), e ? 1 : -1);
    }
    for (int j = 0; j <= n; j++)
        for (int e = 0; e < 2; e++) fprintf(f, "vt %.9g %.9g\n", 0.05 + 0.9 * j / n, e ? v1 : 0.05);
    for (int j = 0; j < n; j++) {
        const double phi = PHI0 + 2 * PI * (smooth ? j : j + 0.5) / n;
        fprintf(f, "vn %.9g %.9g 0\n", cos(phi), sin(phi));
    }
    for (int j = 0; j < n; j++) {
        const int jn = (j + 1) % n;
        /* 1-based: vertex (j, e) is 2j + e + 1, UV (column c, e) 2c + e + 1 */
        const int a = 2 * j + 1, b = 2 * jn + 1, c = 2 * jn + 2, d = 2 * j + 2;
        const int ta = 2 * j + 1, tb = 2 * (j + 1) + 1, tc = 2 * (j + 1) + 2, td = 2 * j + 2;
        const int na = j + 1, nb = smooth ? jn + 1 : j + 1;   /* per face: the column's own normal */
        fprintf(f, "f %d/%d/%d %d/%d/%d %d/%d/%d\n", a, ta, na, b, tb, nb, c, tc, nb);
        fprintf(f, "f %d/%d/%d %d/%d/%d %d/%d/%d\n", a, ta, na, c, tc, nb, d, td, na);
    }
    fclose(f);
}

static void write_scene(const char *dir, int n, int smooth, char *json, size_t len)
{
    char p[1024];
    write_cylinder(tu_path(p, sizeof p, dir, "cyl.obj"), n, smooth);
    /* a plate whose edge's penumbra runs along the cut */
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "plate.obj"),
        "v -2 2 -0.5\nv 0.3 2 -0.5\nv 0.3 2 0.5\nv -2 2 0.5\nf 1 2 3\nf 1 3 4\n"), 0);
    assert_int_equal(tu_write_file(tu_path(json, len, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"cyl.obj\"},{\"file\":\"plate.obj\",\"lightmap\":false}],"
        "\"camera\":{\"eye\":[0,4,4],\"target\":[0,1,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":32,\"height\":32},"
        "\"light\":{\"corner\":[-0.25,3.5,-0.25],\"edge_s\":[0.5,0,0],\"edge_t\":[0,0,0.5],\"emission\":[1,1,1]}}"), 0);
}

static void bake_budget(const ms_scene *sc, int size, int no_stitch, uint64_t max_memory, ms_lightmap *lm)
{
    ms_bake_options bo;
    memset(&bo, 0, sizeof bo);
    bo.points.max_memory = max_memory;
    bo.size = size;
    bo.uv_set = 0;
    bo.points.samples = SAMPLES;
    bo.points.isa = tu_isa_cap();
    bo.no_seam_stitch = no_stitch;
    char err[512] = "";
    assert_int_equal(ms_bake(sc, NULL, &bo, lm, err, sizeof err), MS_OK);
}

static void bake(const ms_scene *sc, int size, int no_stitch, ms_lightmap *lm) { bake_budget(sc, size, no_stitch, 0, lm); }

/* Plane (plane = -1: the irradiance's green channel; else light plane's S) bilinear at (u, v), clamped. */
static double lookup(const ms_frame *f, int plane, double u, double v)
{
    const int W = f->width, H = f->height;
    const double x = u * W - 0.5, y = v * H - 0.5;
    const double x0 = floor(x), y0 = floor(y), fx = x - x0, fy = y - y0;
    double s = 0.0;
    for (int q = 0; q < 4; q++) {
        int xx = (int)x0 + (q & 1), yy = (int)y0 + (q >> 1);
        xx = xx < 0 ? 0 : xx >= W ? W - 1 : xx;
        yy = yy < 0 ? 0 : yy >= H ? H - 1 : yy;
        const size_t i = (size_t)yy * W + xx;
        const double t = plane < 0 ? f->rgb[3 * i + 1] : f->shadow[(size_t)plane * W * H + i];
        s += ((q & 1) ? fx : 1 - fx) * ((q >> 1) ? fy : 1 - fy) * t;
    }
    return s;
}

/* The cut's UVs on its two sides, at its bottom (z = -1) and top (z = 1) vertex, from the baked UVs of the
 * triangles that touch it (side 0: the first column's, u near 0.05 in the file; side 1: the last's). */
static void cut_uvs(const ms_scene *sc, const ms_lightmap *lm, double uv[2][2][2])
{
    const float x = (float)(R * cos(PHI0)), y = (float)(1.0 + R * sin(PHI0));
    int found[2][2] = { { 0, 0 }, { 0, 0 } };
    double umid = 0.0;   /* the two sides' u lie on either side of the strip's middle */
    {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t t = 0; t < sc->n_tris; t++)
            if (sc->tri_mesh[t] == 0)
                for (int k = 0; k < 3; k++) { lo = fmin(lo, lm->uv[6 * t + 2 * k]); hi = fmax(hi, lm->uv[6 * t + 2 * k]); }
        umid = 0.5 * (lo + hi);
    }
    for (size_t t = 0; t < sc->n_tris; t++) {
        if (sc->tri_mesh[t] != 0) continue;
        for (int k = 0; k < 3; k++) {
            const float *p = sc->tri + 9 * t + 3 * k;
            if (p[0] != x || p[1] != y) continue;
            const int e = p[2] > 0, side = lm->uv[6 * t + 2 * k] > umid;
            uv[side][e][0] = lm->uv[6 * t + 2 * k];
            uv[side][e][1] = lm->uv[6 * t + 2 * k + 1];
            found[side][e] = 1;
        }
    }
    assert_true(found[0][0] && found[0][1] && found[1][0] && found[1][1]);
}

/* The cut's error: at 16 points per texel along it, |side 0 - side 1| of the plane relative to scale; mean and 99th
 * percentile. */
static void cut_error(const ms_lightmap *lm, const double uv[2][2][2], int plane, double scale, double *mean, double *p99)
{
    const int np = (int)ceil(16.0 * fabs(uv[0][1][1] - uv[0][0][1]) * lm->frame.width);
    double *d = malloc((size_t)np * sizeof *d), sum = 0.0;
    assert_non_null(d);
    for (int k = 0; k < np; k++) {
        const double t = (k + 0.5) / np;
        double v[2];
        for (int s = 0; s < 2; s++)
            v[s] = lookup(&lm->frame, plane, uv[s][0][0] + t * (uv[s][1][0] - uv[s][0][0]), uv[s][0][1] + t * (uv[s][1][1] - uv[s][0][1]));
        d[k] = fabs(v[0] - v[1]) / scale;
        sum += d[k];
    }
    for (int a = 1; a < np; a++)   /* insertion sort: a few thousand points */
        for (int b = a; b > 0 && d[b - 1] > d[b]; b--) { const double t = d[b]; d[b] = d[b - 1]; d[b - 1] = t; }
    *mean = sum / np;
    *p99 = d[(int)(0.99 * (np - 1))];
    free(d);
}

/* Texels a bilinear lookup anywhere on the cut reads (64 points per texel along each side). */
static uint8_t *cut_texels(const ms_lightmap *lm, const double uv[2][2][2])
{
    const int W = lm->frame.width;
    uint8_t *m = calloc((size_t)W * W, 1);
    assert_non_null(m);
    const int np = (int)ceil(64.0 * fabs(uv[0][1][1] - uv[0][0][1]) * W) + 1;
    for (int s = 0; s < 2; s++)
        for (int k = 0; k <= np; k++) {
            const double t = (double)k / np;
            const double x = (uv[s][0][0] + t * (uv[s][1][0] - uv[s][0][0])) * W - 0.5;
            const double y = (uv[s][0][1] + t * (uv[s][1][1] - uv[s][0][1])) * W - 0.5;
            for (int q = 0; q < 4; q++) {
                int xx = (int)floor(x) + (q & 1), yy = (int)floor(y) + (q >> 1);
                xx = xx < 0 ? 0 : xx >= W ? W - 1 : xx;
                yy = yy < 0 ? 0 : yy >= W ? W - 1 : yy;
                m[(size_t)yy * W + xx] = 1;
            }
        }
    return m;
}

static double largest(const ms_lightmap *lm)
{
    double e = 0.0;
    for (size_t i = 0; i < (size_t)lm->frame.width * lm->frame.height; i++)
        if (lm->triangle[i] != MS_NO_TRIANGLE) e = fmax(e, lm->frame.rgb[3 * i + 1]);
    return e;
}

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double uniform(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* The lightmaps against ms_visibility_points irradiance at random points of the cylinder's triangles, and at
 * points within a texel of the cut: mean and worst |dE| / Emax for each lightmap of lms. */
#define N_RANDOM 2000
#define N_CUT 500
static void oracle_error(const ms_scene *sc, const ms_lightmap *lms, int nlm, double *mean, double *worst, double *cut_mean)
{
    const size_t n = N_RANDOM + N_CUT;
    float *pos = malloc(n * 3 * sizeof *pos), *nor = malloc(n * 3 * sizeof *nor), *S = malloc(n * sizeof *S);
    uint32_t *tri = malloc(n * sizeof *tri), *key = malloc(n * 2 * sizeof *key);
    double *uv = malloc(n * 2 * sizeof *uv);
    assert_true(pos && nor && S && tri && key && uv);
    size_t cyl = 0;
    for (size_t t = 0; t < sc->n_tris; t++) cyl += sc->tri_mesh[t] == 0;
    const ms_lightmap *lm = &lms[0];   /* every lightmap of lms has the same UVs */
    const double texel = 2 * PI * R / (0.9 * SIZE);
    for (size_t i = 0; i < n; i++) {
        size_t t;
        double w1, w2;
        if (i < N_RANDOM) {
            t = (size_t)(uniform() * (double)cyl);
            w1 = uniform();
            w2 = uniform();
            if (w1 + w2 > 1) { w1 = 1 - w1; w2 = 1 - w2; }
        } else {
            /* near the cut: a triangle of the columns within a texel of it on either side (column j is triangles
             * 2j and 2j + 1, in the file's order) */
            const size_t cols = cyl / 2, k = (size_t)ceil(texel / (2 * PI * R / (double)cols));
            const size_t j = (size_t)(uniform() * (double)k);
            t = 2 * (uniform() < 0.5 ? j : cols - 1 - j) + (uniform() < 0.5);
            w1 = uniform();
            w2 = uniform();
            if (w1 + w2 > 1) { w1 = 1 - w1; w2 = 1 - w2; }
            const float *c = sc->tri + 9 * t;
            assert_true(hypot(c[0] - R * cos(PHI0), c[1] - 1.0 - R * sin(PHI0)) < 1.5 * texel);
        }
        const float *p = sc->tri + 9 * t, *u = lm->uv + 6 * t;
        const double w0 = 1 - w1 - w2;
        double e1[3], e2[3], nn[3];
        for (int d = 0; d < 3; d++) {
            pos[3 * i + d] = (float)(w0 * p[d] + w1 * p[3 + d] + w2 * p[6 + d]);
            e1[d] = (double)p[3 + d] - p[d];
            e2[d] = (double)p[6 + d] - p[d];
        }
        nn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        nn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        const double l = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
        for (int d = 0; d < 3; d++) nor[3 * i + d] = (float)(nn[d] / l);
        uv[2 * i] = w0 * u[0] + w1 * u[2] + w2 * u[4];
        uv[2 * i + 1] = w0 * u[1] + w1 * u[3] + w2 * u[5];
        tri[i] = (uint32_t)t;
        key[2 * i] = (uint32_t)floor(uv[2 * i] * SIZE);
        key[2 * i + 1] = (uint32_t)floor(uv[2 * i + 1] * SIZE);
    }
    char err[256];
    ms_accel *acc;
    assert_int_equal(ms_accel_build(sc, 0, &acc, err, sizeof err), MS_OK);
    ms_points pts = { n, pos, nor, tri, key };
    ms_points_options po;
    memset(&po, 0, sizeof po);
    po.samples = SAMPLES;
    po.isa = tu_isa_cap();
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, NULL, S, NULL, NULL, err, sizeof err), MS_OK);
    for (int k = 0; k < nlm; k++) {
        const double emax = largest(&lms[k]);
        double sum = 0.0, cut = 0.0;
        worst[k] = 0.0;
        for (size_t i = 0; i < n; i++) {
            const double want = ms_light_irradiance(&sc->light, pos + 3 * i, nor + 3 * i) * S[i] * sc->light.emission.y;
            const double d = fabs(lookup(&lms[k].frame, -1, uv[2 * i], uv[2 * i + 1]) - want) / emax;
            sum += d;
            cut += i >= N_RANDOM ? d : 0.0;
            worst[k] = fmax(worst[k], d);
        }
        mean[k] = sum / (double)n;
        cut_mean[k] = cut / N_CUT;
    }
    ms_accel_free(acc);
    free(pos); free(nor); free(S); free(tri); free(key); free(uv);
}

static void test_cylinder(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_seams_cyl");
    char json[1024], err[512] = "";
    write_scene(dir, 1024, 1, json, sizeof json);   /* 1024 segments: facets 0.35 degrees apart */
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), MS_OK);
    ms_lightmap lm[2];   /* stitched, not */
    bake(&sc, SIZE, 0, &lm[0]);
    bake(&sc, SIZE, 1, &lm[1]);
    double uv[2][2][2];
    cut_uvs(&sc, &lm[0], uv);
    const double emax = largest(&lm[0]);
    assert_true(emax > 0.0);
    double mean[2], p99[2], smean[2], sp99[2];
    for (int k = 0; k < 2; k++) {
        cut_error(&lm[k], uv, -1, emax, &mean[k], &p99[k]);
        cut_error(&lm[k], uv, 0, 1.0, &smean[k], &sp99[k]);
    }
    printf("cut, irradiance: stitched mean %.5f p99 %.5f, not stitched mean %.5f p99 %.5f of the largest (the bake's own "
           "measure: %.5f / %.5f and %.5f / %.5f over %zu points)\n", mean[0], p99[0], mean[1], p99[1], lm[0].seam_mean,
           lm[0].seam_p99, lm[1].seam_mean, lm[1].seam_p99, lm[0].seam_points);
    printf("cut, S (the shadowmask): stitched mean %.5f p99 %.5f, not stitched mean %.5f p99 %.5f\n", smean[0], sp99[0], smean[1],
           sp99[1]);
    assert_true(p99[0] <= 0.05 && mean[0] <= 0.005);
    assert_true(sp99[0] <= 0.05 && smean[0] <= 0.005);
    /* without stitching the cut shows: several times the error, and beyond the mean */
    assert_true(mean[1] > 4 * mean[0] && p99[1] > 4 * p99[0] && mean[1] > 0.005);
    assert_true(smean[1] > 4 * smean[0]);
    /* texels away from the cut: the same bits */
    uint8_t *near = cut_texels(&lm[0], uv);
    const size_t np = (size_t)SIZE * SIZE;
    size_t near_n = 0, near_changed = 0, far_changed = 0;
    for (size_t i = 0; i < np; i++) {
        const int same = !memcmp(lm[0].frame.rgb + 3 * i, lm[1].frame.rgb + 3 * i, 3 * sizeof(float)) &&
                         !memcmp(lm[0].frame.shadow + i, lm[1].frame.shadow + i, sizeof(float)) &&
                         !memcmp(lm[0].frame.vis + i, lm[1].frame.vis + i, sizeof(float));
        near_n += near[i];
        near_changed += near[i] && !same;
        far_changed += !near[i] && !same;
    }
    printf("texels: %zu read by lookups on the cut, %zu of them changed (the bake: %zu stitched in %.3f s); %zu others "
           "changed\n", near_n, near_changed, lm[0].stitched_texels, lm[0].stitch_s, far_changed);
    assert_int_equal(far_changed, 0);
    assert_true(near_changed > 0 && lm[0].stitched_texels == near_changed);
    assert_int_equal(lm[1].stitched_texels, 0);
    /* still exact */
    double omean[2], oworst[2], ocut[2];
    oracle_error(&sc, lm, 2, omean, oworst, ocut);
    printf("against ms_visibility_points at %d random points and %d within a texel of the cut: stitched mean %.5f worst %.5f "
           "(near the cut: mean %.5f), not stitched mean %.5f worst %.5f (near the cut: mean %.5f) of the largest irradiance\n",
           N_RANDOM, N_CUT, omean[0], oworst[0], ocut[0], omean[1], oworst[1], ocut[1]);
    assert_true(omean[0] <= 0.002 && oworst[0] <= 0.05);
    free(near);
    ms_lightmap_free(&lm[0]);
    ms_lightmap_free(&lm[1]);
    ms_scene_free(&sc);
}

static void test_hard_edges(void **st)
{
    (void)st;
    for (int smooth = 0; smooth < 2; smooth++) {
        const char *dir = tu_tmpdir(smooth ? "bake_seams_smooth_prism" : "bake_seams_hard_prism");
        char json[1024], err[512] = "";
        write_scene(dir, 6, smooth, json, sizeof json);
        ms_scene sc;
        assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), MS_OK);
        ms_lightmap a, b;
        bake(&sc, 64, 0, &a);
        bake(&sc, 64, 1, &b);
        const size_t np = (size_t)64 * 64;
        const int same = !memcmp(a.frame.rgb, b.frame.rgb, 3 * np * sizeof(float)) &&
                         !memcmp(a.frame.shadow, b.frame.shadow, np * sizeof(float));
        printf("hexagonal prism, %s normals: %zu seam points, %zu texels stitched; the lightmap %s without stitching\n",
               smooth ? "smooth" : "per-face", a.seam_points, a.stitched_texels, same ? "as" : "differs from");
        if (smooth) {
            assert_true(a.seam_points > 0 && a.stitched_texels > 0 && !same);
        } else {
            assert_true(a.seam_points == 0 && a.stitched_texels == 0 && same);
        }
        ms_lightmap_free(&a);
        ms_lightmap_free(&b);
        ms_scene_free(&sc);
    }
}

static char warned[1024];
static void catch_warning(void *user, const char *message)
{
    (void)user;
    snprintf(warned, sizeof warned, "%s", message);
}

/* The stitch's memory counts in the budget: with a budget that holds the bake but not the stitch beside it,
 * the bake runs, says that it skipped the stitch, and gives the unstitched lightmap bit for bit. */
static void test_stitch_over_budget(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_seams_budget");
    char json[1024], err[512] = "";
    write_scene(dir, 256, 1, json, sizeof json);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), MS_OK);
    ms_lightmap free_run, bare, tight;
    bake(&sc, 64, 0, &free_run);
    bake(&sc, 64, 1, &bare);
    assert_true(free_run.stitched_texels > 0);
    const uint64_t need = free_run.frame.stats.memory_need;
    assert_true(need > 0);
    warned[0] = 0;
    ms_set_warning_handler(catch_warning, NULL);
    bake_budget(&sc, 64, 0, need, &tight);
    ms_set_warning_handler(NULL, NULL);
    printf("warning: %s\n", warned);
    assert_non_null(strstr(warned, "seam stitching skipped"));
    assert_int_equal(tight.stitched_texels, 0);
    const size_t np = (size_t)64 * 64;
    assert_memory_equal(tight.frame.rgb, bare.frame.rgb, 3 * np * sizeof *bare.frame.rgb);
    assert_memory_equal(tight.frame.shadow, bare.frame.shadow, np * sizeof *bare.frame.shadow);
    ms_lightmap_free(&free_run);
    ms_lightmap_free(&bare);
    ms_lightmap_free(&tight);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cylinder),
        cmocka_unit_test(test_hard_edges),
        cmocka_unit_test(test_stitch_over_budget),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
