/* Charts never mix their light in a bilinear lookup, against answers made here. A grid of small triangles
 * without UVs, each its own xatlas chart, every other one facing away from the light (black): the bake packs
 * lit and black charts side by side (right triangles, whose long edges leave footprint texels next to another
 * chart's texels), and
 *   - no texel lies in two charts' footprints (the texels whose centres lie within one texel of a chart's UV
 *     triangles, found here): what a lookup inside one chart reads is never another's. At the default padding
 *     (none) footprints may touch; xatlas's own footprint test is approximate and the packer moves the charts it
 *     let share texels (src/render/atlas_footprints.c);
 *   - with --padding 2 no texel of one footprint neighbours another's either (what an engine that mipmaps the
 *     lightmap needs);
 *   - the lightmap looked up bilinearly at points just inside every edge of every lit triangle equals the
 *     irradiance ms_visibility_points gives there: a footprint texel filled from a black neighbour (the dilation
 *     fills each footprint from its own chart) would darken the lookup (with xatlas's footprints taken as they
 *     are and a dilation blind to charts, 378 texels lay in two footprints here and the worst lookup was 0.40
 *     of the largest irradiance off). */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIZE 128
#define GRID 8
#define NT (2 * GRID * GRID)

/* Triangle t is lit (faces the light) or black (faces away), a checkerboard. */
static int lit(int t) { return !((t + t / (2 * GRID)) & 1); }

/* Each cell of a GRID x GRID grid holds two right triangles apart (no shared vertex, so each is a chart of
 * its own), whose long edges face each other at 45 degrees in UV as in space: footprints along a diagonal
 * hold texels whose 8-neighbours are the other chart's. */
static void write_grid(const char *path)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    for (int t = 0; t < NT; t++) {
        const int q = t / 2;
        const float x0 = -1.2f + 0.3f * (float)(q % GRID), z0 = -1.2f + 0.3f * (float)(q / GRID), x1 = x0 + 0.2f, z1 = z0 + 0.2f;
        float c[3][3];
        if (t & 1) { const float v[3][3] = { { x0, 0, z1 }, { x1, 0, z1 }, { x1, 0, z0 } }; memcpy(c, v, sizeof v); }
        else { const float v[3][3] = { { x0 - 0.02f, 0, z1 + 0.02f }, { x1 - 0.02f, 0, z0 + 0.02f }, { x0 - 0.02f, 0, z0 + 0.02f } }; memcpy(c, v, sizeof v); }
        for (int k = 0; k < 3; k++) {
            const int kk = lit(t) ? k : 2 - k;   /* counter-clockwise from +y when lit */
            fprintf(f, "v %.9g %.9g %.9g\n", c[kk][0], c[kk][1], c[kk][2]);
        }
    }
    for (int t = 0; t < NT; t++) fprintf(f, "f %d %d %d\n", 3 * t + 1, 3 * t + 2, 3 * t + 3);
    fclose(f);
}

/* 1 if the open square of side 2 about (px, py) meets UV triangle u (texels): the boxes overlap and no edge
 * separates them (a texel whose square only touches the triangle gets no weight in a lookup there). */
static int square_meets(const double u[3][2], double px, double py)
{
    double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY };
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 2; d++) { lo[d] = fmin(lo[d], u[k][d]); hi[d] = fmax(hi[d], u[k][d]); }
    if (px + 1 <= lo[0] || px - 1 >= hi[0] || py + 1 <= lo[1] || py - 1 >= hi[1]) return 0;   /* touching reads nothing */
    const double area = (u[1][0] - u[0][0]) * (u[2][1] - u[0][1]) - (u[1][1] - u[0][1]) * (u[2][0] - u[0][0]);
    for (int k = 0; k < 3; k++) {
        const double *a = u[k], *b = u[(k + 1) % 3];
        const double ex = b[0] - a[0], ey = b[1] - a[1];
        const double e = (area < 0 ? -1.0 : 1.0) * (ex * (py - a[1]) - ey * (px - a[0]));
        if (e + fabs(ex) + fabs(ey) <= 0) return 0;   /* the square's corner furthest inside is not inside */
    }
    return 1;
}

static void tight_charts(int padding)
{
    const char *dir = tu_tmpdir("bake_padding");
    char path[512], err[512] = "";
    write_grid(tu_path(path, sizeof path, dir, "grid.obj"));
    ms_scene sc;
    tu_load_scene_text(dir,
        "{\"meshes\":[{\"file\":\"grid.obj\"}],"
        "\"camera\":{\"eye\":[0,5,0.1],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":60,\"width\":32,\"height\":32},"
        "\"light\":{\"corner\":[-1,2,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2]}}", &sc);
    ms_bake_options bo;
    tu_bake_options(&bo, SIZE, -1, 256);   /* xatlas for all */
    bo.padding = padding;
    ms_lightmap lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
    assert_int_equal(lm.pages, 1);
    /* footprints: the triangle (chart) whose footprint holds each texel, -2 for two */
    int *owner = malloc((size_t)SIZE * SIZE * sizeof *owner);
    assert_non_null(owner);
    for (size_t i = 0; i < (size_t)SIZE * SIZE; i++) owner[i] = -1;
    long shared = 0;
    for (size_t t = 0; t < sc.n_tris; t++) {
        double u[3][2];
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 2; d++) u[k][d] = lm.uv[6 * t + 2 * k + d] * SIZE;
        const int q = (int)t;
        for (int y = 0; y < SIZE; y++)
            for (int x = 0; x < SIZE; x++) {
                if (!square_meets(u, x + 0.5, y + 0.5)) continue;
                int *o = owner + (size_t)y * SIZE + x;
                if (*o >= 0 && *o != q) { shared++; *o = -2; }
                else if (*o == -1) *o = q;
            }
    }
    long touching = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x + 1 < SIZE; x++)
            for (int dy = 0; dy <= 1 && y + dy < SIZE; dy++) {
                const int a = owner[(size_t)y * SIZE + x], b = owner[(size_t)(y + dy) * SIZE + x + 1];
                touching += a >= 0 && b >= 0 && a != b;
            }
    /* the lookups just inside every edge of every lit triangle, against the oracle */
    ms_accel *acc;
    assert_int_equal(ms_accel_build(&sc, 0, &acc, err, sizeof err), MS_OK);
    double emax = 0.0;
    for (size_t i = 0; i < (size_t)SIZE * SIZE; i++)
        if (lm.triangle[i] != MS_NO_TRIANGLE) emax = fmax(emax, lm.frame.rgb[3 * i + 1]);
    double worst = 0.0, sum = 0.0;
    int n = 0;
    for (int q = 0; q < NT; q++) {
        if (!lit(q)) continue;
        {
            const size_t t = (size_t)q;
            for (int e = 0; e < 3; e++)
                for (int j = 1; j < 8; j++) {
                    /* a point on edge e of triangle t, moved 1% of the way towards the opposite vertex */
                    double w[3] = { 0, 0, 0 };
                    w[e] = j / 8.0;
                    w[(e + 1) % 3] = 1.0 - j / 8.0;
                    for (int c = 0; c < 3; c++) w[c] = 0.99 * w[c] + (c == (e + 2) % 3 ? 0.01 : 0.0);
                    float p[3];
                    double uv[2];
                    tu_tri_point(&sc, lm.uv, t, w, p, uv);
                    const float nrm[3] = { 0, 1, 0 };
                    const double want = tu_point_irradiance(acc, &sc, p, nrm, (uint32_t)t, uv, SIZE);
                    const double d = fabs(tu_lightmap_green(&lm.frame, 0, uv[0], uv[1]) - want) / emax;
                    worst = fmax(worst, d);
                    sum += d;
                    n++;
                }
        }
    }
    printf("tight charts, padding %d: %ld texels in two footprints, %ld neighbouring texels of two footprints; %d lookups at lit "
           "triangles' edges against ms_visibility_points: mean %.4f, worst %.4f of the largest irradiance\n",
           padding, shared, touching, n, sum / n, worst);
    assert_int_equal(shared, 0);
    if (padding) assert_int_equal(touching, 0);
    else assert_true(touching > 0);   /* the default packs them touching: the case the dilation must get right */
    assert_true(worst <= 0.02);
    ms_accel_free(acc);
    free(owner);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

static void test_tight_charts_do_not_mix(void **st)
{
    (void)st;
    tight_charts(0);
}

static void test_tight_charts_padded(void **st)
{
    (void)st;
    tight_charts(2);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tight_charts_do_not_mix),
        cmocka_unit_test(test_tight_charts_padded),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
