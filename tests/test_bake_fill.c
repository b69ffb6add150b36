/* How full one lightmap page gets when two objects keep their own layouts (src/render/bake_uvs.c,
 * atlas_xpack.c), against answers made here. A 2 x 2 ground and a 1.2 x 1.2 plate, each with UV0 the
 * whole unit square (so their layouts overlap and each gets a region of its own), and a few quads without
 * UVs (xatlas charts, packed together with the regions):
 *   - one texel density: the regions' sides in texels (measured from the baked UVs) are in the ratio of
 *     the quads' world sides;
 *   - the packing is not what limits the scale: two squares of sides g and b share a square page only if
 *     g + b plus the space between and around them fits its side (otherwise their extents overlap in both
 *     directions), and the scale found brings g + b within 3% of that bound, though the page keeps empty
 *     texels beside the smaller square: at one density the two squares, not the packer, set the fill;
 *   - no texel centre lies in two objects' baked UV images (rasterized here, edges included), every triangle
 *     on the page, and the texel centres on triangles counted here are the reported page fill.
 * Island by island (MS_UV_PACK_ISLANDS, what the default does here), an object whose layout holds four small islands in the corners of its UV square: each
 * island moved as a whole (one scale for u and v, no rotation), one texel density for every island of both
 * objects, no texel centre in two islands, and the page far fuller than with one region per object.
 * Regions alone (no xatlas chart: the rectangle packer): the texels a bilinear lookup inside each region reads
 * (centres within one texel of its UV square) are never the other's; at the default padding (none) the two
 * sets may touch, with --padding 2 they leave at least 2 texels between them, which no lookup reads; at a texel
 * density that makes both larger than a page, each is shrunk to fit one page with that space around it. */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIZE 256
#define PAD 4

/* An OBJ of one horizontal quad x0..x1, z0..z1 at height y, with UV0 the unit square when uv is set. */
static void write_quad(const char *path, float x0, float x1, float z0, float z1, float y, int uv)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "v %g %g %g\nv %g %g %g\nv %g %g %g\nv %g %g %g\n", x0, y, z1, x1, y, z1, x1, y, z0, x0, y, z0);
    if (uv) fprintf(f, "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
    else fprintf(f, "f 1 2 3\nf 1 3 4\n");
    fclose(f);
}

static int centre_in(const float *u, double px, double py)
{
    double e[3];
    for (int k = 0; k < 3; k++) {
        const float *a = u + 2 * k, *b = u + 2 * ((k + 1) % 3);
        e[k] = ((double)b[0] - a[0]) * (py - a[1]) - ((double)b[1] - a[1]) * (px - a[0]);
    }
    return (e[0] >= 0 && e[1] >= 0 && e[2] >= 0) || (e[0] <= 0 && e[1] <= 0 && e[2] <= 0);
}

/* A bake of sc in UV set 0 on SIZE pages, islands packed one by one or not, at texel density T (0: one page),
 * with `padding` (0: the default). */
static void bake_uv0(const ms_scene *sc, int islands, float T, int padding, ms_lightmap *lm)
{
    char err[512] = "";
    ms_bake_options bo;
    memset(&bo, 0, sizeof bo);
    bo.size = SIZE;
    bo.padding = padding;
    bo.uv_set = 0;
    bo.uv_packing = islands ? MS_UV_PACK_ISLANDS : MS_UV_PACK_REGIONS;
    bo.texel_density = T;
    bo.points.samples = 256;
    bo.points.isa = tu_isa_cap();
    assert_int_equal(ms_bake(sc, NULL, &bo, lm, err, sizeof err), MS_OK);
}

/* The 2 x 2 ground and the 1.2 x 1.2 plate (UV0 the unit square each), with the two quads for xatlas when
 * `tiles`, written into a fresh folder `name` and loaded into sc. */
static void ground_and_plate(const char *name, int tiles, ms_scene *sc)
{
    const char *dir = tu_tmpdir(name);
    char path[512], text[1024];
    write_quad(tu_path(path, sizeof path, dir, "ground.obj"), -1.0f, 1.0f, -1.0f, 1.0f, 0.0f, 1);
    write_quad(tu_path(path, sizeof path, dir, "plate.obj"), 1.5f, 2.7f, -0.6f, 0.6f, 0.0f, 1);
    if (tiles) {
        write_quad(tu_path(path, sizeof path, dir, "tile0.obj"), -0.8f, -0.6f, -0.8f, -0.6f, 0.3f, 0);
        write_quad(tu_path(path, sizeof path, dir, "tile1.obj"), 0.4f, 0.7f, 0.2f, 0.35f, 0.3f, 0);
    }
    snprintf(text, sizeof text,
             "{\"meshes\":[{\"file\":\"ground.obj\"},{\"file\":\"plate.obj\"}%s],"
             "\"camera\":{\"eye\":[0.8,5,0.1],\"target\":[0.8,0,0],\"up\":[0,1,0],\"fov_y\":60,\"width\":32,\"height\":32},"
             "\"light\":{\"corner\":[-0.5,3,-0.5],\"edge_s\":[1,0,0],\"edge_t\":[0,0,1]}}",
             tiles ? ",{\"file\":\"tile0.obj\"},{\"file\":\"tile1.obj\"}" : "");
    tu_load_scene_text(dir, text, sc);
}

static void test_two_regions_bound(void **st)
{
    (void)st;
    ms_scene sc;
    ground_and_plate("bake_fill", 1, &sc);
    ms_lightmap lm;
    bake_uv0(&sc, 0, 0.0f, PAD, &lm);
    assert_int_equal(lm.pages, 1);
    assert_int_equal(lm.object_uv_set[0], 0);
    assert_int_equal(lm.object_uv_set[1], 0);
    /* each object's baked UV box, texels */
    double lo[4][2], hi[4][2];
    for (int m = 0; m < 4; m++)
        for (int d = 0; d < 2; d++) { lo[m][d] = INFINITY; hi[m][d] = -INFINITY; }
    for (size_t t = 0; t < sc.n_tris; t++) {
        const int m = (int)sc.tri_mesh[t];
        assert_int_equal(lm.page[t], 0);
        for (int k = 0; k < 6; k++) {
            const double v = lm.uv[6 * t + k] * SIZE;
            assert_true(v >= 0.0 && v <= SIZE);
            lo[m][k & 1] = fmin(lo[m][k & 1], v);
            hi[m][k & 1] = fmax(hi[m][k & 1], v);
        }
    }
    const double g = hi[0][0] - lo[0][0], b = hi[1][0] - lo[1][0];
    assert_true(fabs((hi[0][1] - lo[0][1]) / g - 1.0) < 1e-4);   /* squares stay squares */
    assert_true(fabs((hi[1][1] - lo[1][1]) / b - 1.0) < 1e-4);
    assert_true(fabs((g / b) / (2.0 / 1.2) - 1.0) < 1e-3);   /* one texel density */
    /* the bound: the page less the space between two regions (xatlas pads each by PAD / 2 texels beyond the
     * texels bilinear lookups read, one each side) and at least half a texel to each page edge */
    const double bound = SIZE - 1.0 - (PAD + 2.0);
    printf("ground %.1f + plate %.1f = %.1f texels, bound %.1f; page fill %.1f%%\n", g, b, g + b, bound, 100.0 * lm.page_fill[0]);
    assert_true(g + b > 0.97 * bound);
    assert_true(g + b <= bound + 2.0);   /* a region's edge may lie anywhere in its first and last texel */
    /* no texel centre in two objects */
    int twice = 0, on = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            const double px = (x + 0.5) / SIZE, py = (y + 0.5) / SIZE;
            int owner = -1, n = 0;   /* an object's triangles are consecutive */
            for (size_t t = 0; t < sc.n_tris; t++)
                if (centre_in(lm.uv + 6 * t, px, py) && (int)sc.tri_mesh[t] != owner) { owner = (int)sc.tri_mesh[t]; n++; }
            twice += n > 1;
            on += n > 0;
        }
    assert_int_equal(twice, 0);
    assert_true(fabs(on / (double)(SIZE * SIZE) - lm.page_fill[0]) < 0.01);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

/* Four 0.5 x 0.5 quads at height 0.3, each UV0 a 0.2 x 0.2 square in a corner of the unit square. */
static void write_parts(const char *path)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    static const float at[4][2] = { { -0.9f, -0.9f }, { 0.3f, -0.9f }, { -0.9f, 0.3f }, { 0.3f, 0.3f } };
    static const float uv[4][2] = { { 0.0f, 0.0f }, { 0.75f, 0.0f }, { 0.0f, 0.75f }, { 0.75f, 0.75f } };
    for (int q = 0; q < 4; q++) {
        const float x0 = at[q][0], z0 = at[q][1], x1 = x0 + 0.5f, z1 = z0 + 0.5f, u0 = uv[q][0], v0 = uv[q][1];
        fprintf(f, "v %g 0.3 %g\nv %g 0.3 %g\nv %g 0.3 %g\nv %g 0.3 %g\n", x0, z1, x1, z1, x1, z0, x0, z0);
        fprintf(f, "vt %g %g\nvt %g %g\nvt %g %g\nvt %g %g\n", u0, v0, u0 + 0.2f, v0, u0 + 0.2f, v0 + 0.2f, u0, v0 + 0.2f);
    }
    for (int q = 0; q < 4; q++) {
        const int b = 4 * q;
        fprintf(f, "f %d/%d %d/%d %d/%d\nf %d/%d %d/%d %d/%d\n", b + 1, b + 1, b + 2, b + 2, b + 3, b + 3, b + 1, b + 1, b + 3,
                b + 3, b + 4, b + 4);
    }
    fclose(f);
}

static char g_scaled[512];

static void keep_scaled(void *user, const char *msg)
{
    (void)user;
    if (strstr(msg, "scaled down")) snprintf(g_scaled, sizeof g_scaled, "%s", msg);
}

static double bake_fill(const ms_scene *sc, int islands, ms_lightmap *lm)
{
    bake_uv0(sc, islands, 0.0f, PAD, lm);
    assert_int_equal(lm->pages, 1);
    return lm->page_fill[0];
}

static void test_islands(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bake_fill_islands");
    char path[512];
    write_quad(tu_path(path, sizeof path, dir, "ground.obj"), -1.0f, 1.0f, -1.0f, 1.0f, 0.0f, 1);
    write_parts(tu_path(path, sizeof path, dir, "parts.obj"));
    ms_scene sc;
    tu_load_scene_text(dir,
        "{\"meshes\":[{\"file\":\"ground.obj\"},{\"file\":\"parts.obj\"}],"
        "\"camera\":{\"eye\":[0,5,0.1],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":60,\"width\":32,\"height\":32},"
        "\"light\":{\"corner\":[-0.5,3,-0.5],\"edge_s\":[1,0,0],\"edge_t\":[0,0,1]}}", &sc);
    assert_int_equal(sc.n_tris, 10);
    ms_lightmap whole, lm;
    const double f0 = bake_fill(&sc, 0, &whole), f1 = bake_fill(&sc, 1, &lm);
    /* islands: the ground's one (triangles 0, 1) and the parts' four (triangles 2 + 2q, 3 + 2q) */
    const double world_per_uv[2] = { 2.0, 2.5 };
    double density[5], off[5][2];
    for (size_t t = 0; t < sc.n_tris; t++) {
        const int m = (int)sc.tri_mesh[t], isl = (int)t / 2;
        assert_int_equal(lm.object_uv_set[m], 0);
        assert_true(lm.object_scale_offset[4 * m] == 0.0f);   /* no one scale-offset */
        const float *f = sc.tri_uv[0] + 6 * t, *b = lm.uv + 6 * t;
        /* the scale along u and along v from the triangle's edges: equal (no rotation, no stretch) */
        double au = 0.0, av = 0.0;
        for (int e = 1; e < 3; e++) {
            const double du = f[2 * e] - f[0], dv = f[2 * e + 1] - f[1];
            if (fabs(du) > 0.1) au = (b[2 * e] - b[0]) * SIZE / du;
            if (fabs(dv) > 0.1) av = (b[2 * e + 1] - b[1]) * SIZE / dv;
            if (fabs(du) > 0.1 && fabs(dv) > 0.1) {   /* a diagonal edge: the same scale on both axes */
                assert_true(fabs((b[2 * e] - b[0]) * SIZE / du - (b[2 * e + 1] - b[1]) * SIZE / dv) < 1e-3 * fabs(au));
            }
        }
        assert_true(au > 0.0 && fabs(au / av - 1.0) < 1e-4);
        const double o[2] = { b[0] * SIZE - au * f[0], b[1] * SIZE - av * f[1] };
        if (t % 2 == 0) {
            density[isl] = au / world_per_uv[m];   /* texels per world unit */
            off[isl][0] = o[0];
            off[isl][1] = o[1];
        } else {   /* the island's second triangle moved with the first */
            assert_true(fabs(au / world_per_uv[m] - density[isl]) < 1e-4 * density[isl]);
            assert_true(fabs(o[0] - off[isl][0]) < 1e-2 && fabs(o[1] - off[isl][1]) < 1e-2);
        }
    }
    for (int i = 1; i < 5; i++) assert_true(fabs(density[i] / density[0] - 1.0) < 1e-3);
    /* no texel centre in two islands; the centres on triangles are the page fill */
    int twice = 0, on = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            const double px = (x + 0.5) / SIZE, py = (y + 0.5) / SIZE;
            int owner = -1, n = 0;
            for (size_t t = 0; t < sc.n_tris; t++)
                if (centre_in(lm.uv + 6 * t, px, py) && (int)t / 2 != owner) { owner = (int)t / 2; n++; }
            twice += n > 1;
            on += n > 0;
        }
    printf("islands: %.1f texels per world unit, page fill %.1f%% (one region per object: %.1f%%)\n", density[0],
           100.0 * f1, 100.0 * f0);
    assert_int_equal(twice, 0);
    assert_true(fabs(on / (double)(SIZE * SIZE) - f1) < 0.01);
    assert_true(f1 > 0.6 && f1 > 2.0 * f0);
    ms_lightmap_free(&whole);
    ms_lightmap_free(&lm);
    /* a density at which the ground's island (2 x 2) is wider than a page: scaled down to fit, with a warning
     * that counts its triangles; the parts' islands keep the density */
    g_scaled[0] = 0;
    ms_set_warning_handler(keep_scaled, NULL);
    bake_uv0(&sc, 1, 200.0f, PAD, &lm);
    ms_set_warning_handler(NULL, NULL);
    printf("warning: %s\n", g_scaled);
    assert_non_null(strstr(g_scaled, "islands of 2 triangles"));
    const double side = fabs(lm.uv[6 * 2 + 2] - lm.uv[6 * 2]) * SIZE;   /* a part's first edge, 0.5 world units */
    assert_true(fabs(side - 100.0) < 0.5);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

/* The texel rows or columns [lo, hi] whose centres lie within one texel of the UV span [a, b] (texels). */
static void footprint(double a, double b, int *lo, int *hi)
{
    *lo = (int)floor(a - 1.5) + 1;   /* i + 0.5 > a - 1 */
    *hi = (int)ceil(b + 0.5) - 1;    /* i + 0.5 < b + 1 */
}

static void test_regions_apart(void **st)
{
    (void)st;
    ms_scene sc;
    ground_and_plate("bake_fill_apart", 0, &sc);
    ms_lightmap lm;
    for (int padding = 0; padding <= 2; padding += 2) {
        bake_uv0(&sc, 0, 0.0f, padding, &lm);
        assert_int_equal(lm.pages, 1);
        assert_int_equal(lm.charts, 0);   /* no xatlas: the regions' own packer */
        int fp[2][2][2];   /* [object][axis][lo, hi] */
        for (int m = 0; m < 2; m++) {
            double lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY };
            for (size_t t = 0; t < sc.n_tris; t++)
                if ((int)sc.tri_mesh[t] == m)
                    for (int k = 0; k < 6; k++) {
                        lo[k & 1] = fmin(lo[k & 1], lm.uv[6 * t + k] * SIZE);
                        hi[k & 1] = fmax(hi[k & 1], lm.uv[6 * t + k] * SIZE);
                    }
            for (int d = 0; d < 2; d++) footprint(lo[d], hi[d], &fp[m][d][0], &fp[m][d][1]);
        }
        int apart = -1;   /* texels between the two footprints along the axis that separates them */
        for (int d = 0; d < 2; d++) {
            const int gap = (fp[1][d][0] > fp[0][d][1] ? fp[1][d][0] - fp[0][d][1] : fp[0][d][0] - fp[1][d][1]) - 1;
            if (gap > apart) apart = gap;
        }
        printf("regions, padding %d: footprints x %d..%d and %d..%d, y %d..%d and %d..%d: %d texels apart; page fill %.1f%%\n",
               padding, fp[0][0][0], fp[0][0][1], fp[1][0][0], fp[1][0][1], fp[0][1][0], fp[0][1][1], fp[1][1][0], fp[1][1][1],
               apart, 100.0 * lm.page_fill[0]);
        assert_true(apart >= padding);   /* 0: the footprints may touch, never overlap */
        ms_lightmap_free(&lm);
    }
    /* at a density where both are larger than a page: each shrunk to fit one with that space around it */
    bake_uv0(&sc, 0, 300.0f, 0, &lm);
    assert_int_equal(lm.pages, 2);
    for (size_t t = 0; t < sc.n_tris; t++)
        for (int k = 0; k < 6; k++) assert_true(lm.uv[6 * t + k] * SIZE >= 2.0 && lm.uv[6 * t + k] * SIZE <= SIZE - 2.0);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_regions_bound),
        cmocka_unit_test(test_islands),
        cmocka_unit_test(test_regions_apart),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
