/* Alpha-tested occluders: a cut-out leaf texture casts its leaf-shaped shadow in every method. The scene
 * (util/alpha_leaves.c, into the test's temp dir): a ground plane and three leaf cards (one horizontal, two
 * tilted, one with its UVs repeating the texture twice), textured with a leaf-shaped alpha mask with an
 * off-centre hole, written as a glTF 2.0 file (alphaMode MASK, the texture's alpha channel) and as OBJ/MTL
 * (map_d, a grey mask, OBJ's bottom-up v). The oracle is a brute-force ray tracer of its own: its own
 * double-precision segment/triangle test over its own triangle list, its own barycentrics, its own bilinear
 * alpha lookup in the mask it generated. Every method (and ISA, traversal, pattern, Embree mode) must give the
 * oracle's visible mask sample for sample, except samples where the oracle's alpha is within 1e-3 of the cutoff
 * or its segment passes within 1e-6 (barycentric) of a triangle's edge at an opaque texel, which are counted,
 * printed and bounded. Also: the shadow has the leaf's shape (a point below the horizontal card sees the light
 * through exactly the card's transparent fraction; a point below the hole is lit, one below the leaf is not),
 * and camera rays pass through transparent texels to the ground (primary methods against the oracle). Whole
 * frames, the bake and the loading rules: test_alpha_frames.c. */
#include "alpha_leaves.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "visibility/alpha.h"
#include "accel/bvh.h"
#include "light/pattern.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


static void every_method(const char *format)
{
    setup s;
    al_setup_make(&s, format, 40);
    printf("%s: %d visible points\n", format, s.nq);
    static const ms_pattern pats[] = { MS_PATTERN_GRID, MS_PATTERN_STRATIFIED, MS_PATTERN_INTERLEAVED };
    static const char *const pat_names[] = { "grid", "stratified", "interleaved" };
    long total_differ = 0;
    for (int p = 0; p < 3; p++) {
        ms_render_ctx ctx = s.ctx;
        tu_ctx_set_pattern(&ctx, pats[p]);
        oracle_masks om;
        al_oracle_run(&s, &ctx, &om);
        printf(" %s, %s: %ld front samples, %ld occluded by the oracle; excluded: %ld with alpha within 1e-3 of the cutoff, "
               "%ld within 1e-6 of an edge\n", format, pat_names[p], om.front_n, om.occluded_n, om.amb_alpha, om.amb_geom);
        /* The scene is built so that cards occlude (a real test) and ties are rare. */
        assert_true(om.occluded_n > om.front_n / 50);
        assert_true(om.amb_alpha + om.amb_geom < om.front_n / 1000 + 10);
        const char *const *names = ms_method_names();
        for (int m = 0; names[m]; m++) {
            const ms_shadow_method *sm = ms_find_shadow_method(names[m]);
            if (sm->needs_grid && pats[p] != MS_PATTERN_GRID) continue;
            if (pats[p] == MS_PATTERN_INTERLEAVED && strcmp(names[m], "raytrace") && strcmp(names[m], "mft") &&
                strcmp(names[m], "embree"))
                continue;
            const int micro = !strcmp(names[m], "scanline") || !strcmp(names[m], "bounds") || !strcmp(names[m], "hierarchical");
            const int embree = !strcmp(names[m], "embree");
            for (int cap = embree ? MS_ISA_AUTO : MS_ISA_SCALAR; cap <= (embree ? MS_ISA_AUTO : MS_ISA_AVX512); cap++) {
                if (cap && (!tu_isa_allowed((ms_isa)cap) || cap > (int)ms_cpu_isa())) continue;
                for (int v = 0; v < (micro ? 2 : embree ? 3 : 1); v++) {
                    ms_render_ctx c = ctx;
                    c.isa_cap = (ms_isa)cap;
                    if (micro) c.traversal = v ? MS_TRAVERSAL_PIXEL : MS_TRAVERSAL_BLOCK;
                    static const ms_embree_mode modes[3] = { MS_EMBREE_PACKET16, MS_EMBREE_STREAM, MS_EMBREE_PACKET8 };
                    static const char *const mode_names[3] = { " packet16", " stream", " packet8" };
                    if (embree) c.embree_mode = modes[v];
                    char label[128];
                    snprintf(label, sizeof label, "%s %s %s%s", names[m], pat_names[p], cap ? ms_isa_name((ms_isa)cap) : "",
                             micro ? (v ? " pixel" : " block") : embree ? mode_names[v] : "");
                    total_differ += al_method_vs_oracle(&s, &c, names[m], &om, label);
                }
            }
        }
        al_oracle_free(&om);
    }
    assert_int_equal(total_differ, 0);
    al_setup_free(&s);
}

static void test_every_method_gltf(void **state) { (void)state; every_method("gltf"); }
static void test_every_method_obj(void **state) { (void)state; every_method("obj"); }

/* ---- the shadow's shape, through the points API ---- */

/* The fraction of the card's area where the bilinear alpha is >= 0.5, by a fine midpoint grid. */
static double opaque_fraction(void)
{
    const int n = 1024;
    long in = 0;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) in += al_oracle_alpha((x + 0.5) / n, (y + 0.5) / n) >= 0.5;
    return (double)in / ((double)n * n);
}

static void leaf_shape(const char *format)
{
    ms_scene sc;
    char dir[4096], err[512];
    al_load_scene(format, &sc, dir, sizeof dir);
    ms_accel *acc = NULL;
    assert_int_equal(ms_accel_build(&sc, 1, &acc, err, sizeof err), MS_OK);
    /* P below card A's centre: seen from P the 2 x 2 light at height 6 projects onto the card's plane at
     * height 3 as exactly the card (scale 3/6 about P), so V = the card's transparent fraction. */
    const double opaque = opaque_fraction();
    /* Below the hole (card uv (0.62, 0.42): world (0.12, 3, -0.08)) and below the leaf body (uv (0.3, 0.55):
     * (-0.2, 3, 0.05)) with a 0.04-wide light centred over the card: the segments cross the card's plane
     * within 0.01 of the points twice as far below... i.e. P = 2 X - light centre. */
    const float pos[9] = { 0, 0, 0, 0.24f, 0, -0.16f, -0.4f, 0, 0.1f };
    const float nrm[9] = { 0, 1, 0, 0, 1, 0, 0, 1, 0 };
    ms_points pts = { 3, pos, nrm, NULL, NULL };
    ms_light small = sc.light;
    small.corner = (ms_vec3){ -0.02f, 6, -0.02f };
    small.edge_s = (ms_vec3){ 0.04f, 0, 0 };
    small.edge_t = (ms_vec3){ 0, 0, 0.04f };
    const char *const *names = ms_method_names();
    for (int m = 0; names[m]; m++) {
        if (!strcmp(names[m], "hpc") || !strcmp(names[m], "hpc-scanline")) continue;   /* frames only */
        ms_points_options po = { 0 };
        po.method = names[m];
        po.samples = 1024;
        po.threads = 1;
        po.isa = tu_isa_cap();
        float v[3], v2[3];
        ms_status rc = ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err);
        if (rc) fprintf(stderr, "%s: %s\n", names[m], err);
        assert_int_equal(rc, MS_OK);
        rc = ms_visibility_points(acc, &small, &pts, &po, v2, NULL, NULL, NULL, err, sizeof err);
        assert_int_equal(rc, MS_OK);
        printf("%s %-13s below card A: V %.4f, the card's transparent fraction %.4f; small light: below the hole V %.3f, "
               "below the leaf V %.3f\n", format, names[m], v[0], 1.0 - opaque, v2[1], v2[2]);
        /* 1024 samples on the card: the edge of the leaf crosses about 2 * 32 * perimeter cells. */
        assert_true(fabs(v[0] - (1.0 - opaque)) < 0.02);
        assert_true(v2[1] == 1.0f);
        assert_true(v2[2] == 0.0f);
    }
    assert_true(opaque > 0.25 && opaque < 0.5);
    ms_accel_free(acc);
    ms_scene_free(&sc);
}

static void test_leaf_shape_gltf(void **state) { (void)state; leaf_shape("gltf"); }
static void test_leaf_shape_obj(void **state) { (void)state; leaf_shape("obj"); }

/* ---- primary rays: through transparent texels to what lies behind ---- */

static void primary(const char *format, const char *pname)
{
    const int size = 48;
    setup s;
    al_setup_make(&s, format, 8);
    const ms_primary_method *pm = ms_find_primary_method(pname);
    if (!pm) { al_setup_free(&s); return; }
    ms_render_ctx ctx = s.ctx;
    assert_int_equal(ms_camera_basis_init(&ctx.cam, &s.sc.camera, size, size), 0);
    char err[256];
    void *ps = NULL;
    assert_int_equal(pm->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit *hits = malloc((size_t)size * size * sizeof *hits);
    assert_non_null(hits);
    pm->trace(ps, &ctx, 0, 0, size, size, hits);
    pm->destroy(ps);
    long through = 0, differ = 0, amb = 0, on_cards = 0;
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            float of[3], df[3];
            assert_int_equal(ms_camera_ray(&ctx.cam, x, y, of, df), 0);
            const double o[3] = { of[0], of[1], of[2] }, d[3] = { df[0], df[1], df[2] };
            /* The oracle: the nearest triangle hit where opaque; ambiguous if a hit nearer than it is near the
             * cutoff or an edge. */
            int best = -1, ambiguous = 0, crossed = 0;
            double bt = INFINITY;
            for (int t = 0; t < al_n_tris; t++) {
                double tt, b1, b2;
                int ne;
                const int hit = al_oracle_hit(&al_tris[t], o, d, 0.0, INFINITY, &tt, &b1, &b2, &ne);
                const double a = al_tris[t].alpha ? al_card_alpha(&al_tris[t], b1, b2) : 1.0;
                if (ne && a >= 0.5 - 1e-3) ambiguous = 1;
                if (!hit) continue;
                if (al_tris[t].alpha && fabs(a - 0.5) < 1e-3) ambiguous = 1;
                if (a < 0.5) { crossed = 1; continue; }
                if (tt < bt) { bt = tt; best = t; }
            }
            const ms_hit *h = &hits[y * size + x];
            const int got = h->prim == UINT32_MAX ? -1 : s.oracle_tri[h->prim];
            if (ambiguous) { amb++; continue; }
            if (got != best) differ++;
            through += crossed && best >= 0 && !al_tris[best].alpha;
            on_cards += best >= 0 && al_tris[best].alpha;
        }
    printf("%s primary %s: %ld pixels see the ground through a transparent texel, %ld see a card; %ld differ from the "
           "oracle, %ld ambiguous\n", format, pname, through, on_cards, differ, amb);
    assert_true(through > 20);
    assert_true(on_cards > 20);
    assert_int_equal(differ, 0);
    assert_true(amb < 10);
    free(hits);
    al_setup_free(&s);
}

static void test_primary_gltf(void **state)
{
    (void)state;
    primary("gltf", "bvh");
    primary("gltf", "embree");
}
static void test_primary_obj(void **state)
{
    (void)state;
    primary("obj", "bvh");
    primary("obj", "embree");
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_method_gltf),
        cmocka_unit_test(test_every_method_obj),
        cmocka_unit_test(test_leaf_shape_gltf),
        cmocka_unit_test(test_leaf_shape_obj),
        cmocka_unit_test(test_primary_gltf),
        cmocka_unit_test(test_primary_obj),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
