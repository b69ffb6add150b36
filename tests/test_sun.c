/* The sun (shape "sun", src/light/light_sun.c; docs/design.md, "The sun"), each check against an oracle of
 * its own:
 *   - every method's V, S and front equal raytrace's on a scene with a closed, finely meshed box (the
 *     closed-mesh cull, the interior boxes and the merge of the ground's coplanar rectangles all at work for
 *     the sun), and raytrace's equal a brute force in double: a sample counts when it lies in front of the
 *     receiver and its direction within the sun's cone, and is occluded when a triangle meets the ray from P
 *     towards it at any distance beyond the near range (no far limit at all);
 *   - bakes (the points API, given the sun unplaced): every method's V, S and front equal raytrace's, and
 *     raytrace's the brute force; points far outside the scene: their segments still reach it;
 *   - blocks (the micro-rasterization methods take a sun's or a sphere's queries 4x4 at a time): roofs at
 *     different heights within each block under a wide sun and a large sphere, every method equal to raytrace
 *     (which is called one query at a time);
 *   - the closed-mesh cull at its limit: a box's face nearly parallel to the sun, kept (every method equals
 *     raytrace, which culls nothing);
 *   - the penumbra: a pole's shadow edge at distance d from the pole is d tan(0.53 deg) wide (within a pixel
 *     of an orthographic view from above);
 *   - irradiance: pi L sin^2 alpha cos theta above the horizon, numerical integration over the cone across it;
 *   - glTF KHR_lights_punctual directional: a sun towards the node's +Z, radiance E / (pi sin^2 alpha) from E
 *     lux, extras.angular_diameter_deg, and every method's frame equal to raytrace's;
 *   - the scene file: "shape": "sun" with "direction" and the default 0.53, "lumens" as lux, bad keys refused. */
#include "testutil.h"
#include "primary/primary.h"
#include "light/pattern.h"
#include "light/light_shape.h"
#include "accel/bvh.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef enum { NO = 0, YES = 1, UNSURE = 2 } verdict;   /* tu_segment_hits' answers */

/* ---- the scene: a ground of 4 x 4 squares, a closed box of 7 x 7 squares per face, a tilted triangle ---- */

static size_t put_quad(float *t, size_t n, const float a[3], const float b[3], const float c[3], const float d[3])
{
    memcpy(t + 9 * n, a, 12); memcpy(t + 9 * n + 3, b, 12); memcpy(t + 9 * n + 6, c, 12);
    memcpy(t + 9 * n + 9, a, 12); memcpy(t + 9 * n + 12, c, 12); memcpy(t + 9 * n + 15, d, 12);
    return n + 2;
}

/* A closed box lo..hi of b x b squares per face: every lattice point computed once per axis, so that the
 * faces share their edges' vertices exactly; counter-clockwise seen from outside. */
static size_t put_box(float *t, size_t n, const float lo[3], const float hi[3], int b_n)
{
    float g[3][16];
    for (int a = 0; a < 3; a++)
        for (int i = 0; i <= b_n; i++) g[a][i] = lo[a] + (hi[a] - lo[a]) * (float)i / (float)b_n;
    for (int a = 0; a < 3; a++)
        for (int side = 0; side < 2; side++) {
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            for (int i = 0; i < b_n; i++)
                for (int j = 0; j < b_n; j++) {
                    float v[4][3];
                    const int di[4] = { 0, 1, 1, 0 }, dj[4] = { 0, 0, 1, 1 };
                    for (int k = 0; k < 4; k++) {
                        v[k][a] = side ? hi[a] : lo[a];
                        v[k][b] = g[b][i + di[k]];
                        v[k][c] = g[c][j + dj[k]];
                    }
                    /* (e_b, e_c) turns towards +a */
                    n = side ? put_quad(t, n, v[0], v[1], v[2], v[3]) : put_quad(t, n, v[0], v[3], v[2], v[1]);
                }
        }
    return n;
}

/* A ground of 4 x 4 squares (merged), a closed box of 7 x 7 squares per face (interior boxes), a closed box of
 * 12 triangles (too few for interior boxes: culled on the side away from the sun), a tilted triangle. */
static void make_sun_scene(ms_scene *sc, float deg)
{
    enum { G = 4, B = 7 };
    const size_t cap = 2 * G * G + 12 * B * B + 12 + 1;
    memset(sc, 0, sizeof *sc);
    sc->tri = malloc(cap * 9 * sizeof *sc->tri);
    assert_non_null(sc->tri);
    size_t n = 0;
    for (int i = 0; i < G; i++)
        for (int j = 0; j < G; j++) {   /* facing up */
            const float x0 = -8.0f + 4.0f * i, x1 = x0 + 4.0f, z0 = -8.0f + 4.0f * j, z1 = z0 + 4.0f;
            n = put_quad(sc->tri, n, (float[]){ x0, 0, z0 }, (float[]){ x0, 0, z1 }, (float[]){ x1, 0, z1 }, (float[]){ x1, 0, z0 });
        }
    /* its grid cells wider than 4 times the interior clearance (accel/interior.c) */
    n = put_box(sc->tri, n, (const float[]){ -2, 0.5f, -2.5f }, (const float[]){ 2, 4.5f, 1.5f }, B);
    n = put_box(sc->tri, n, (const float[]){ -5, 0.2f, 2 }, (const float[]){ -3.5f, 1.7f, 3.5f }, 1);
    const float tri[9] = { 3.0f, 1.2f, 2.0f, 5.0f, 1.6f, 2.5f, 3.6f, 2.0f, 4.2f };
    memcpy(sc->tri + 9 * n, tri, sizeof tri);
    sc->n_tris = n + 1;
    sc->camera = (ms_camera){ { 7, 10, 12 }, { 0.5f, 1, 0.5f }, { 0, 1, 0 }, 60.0f, 32, 32, MS_CAMERA_PINHOLE, 0, 0 };
    assert_int_equal(ms_light_sun(&sc->light, (ms_vec3){ -0.45f, 0.8f, -0.35f }, deg), 0);
    sc->light.emission = (ms_vec3){ 1, 1, 1 };
    sc->samples = 256;
}

/* The box of the scene's triangles, computed here. */
static void tri_box(const ms_scene *sc, float box[6])
{
    for (int a = 0; a < 3; a++) { box[a] = INFINITY; box[3 + a] = -INFINITY; }
    for (size_t i = 0; i < 3 * sc->n_tris; i++)
        for (int a = 0; a < 3; a++) {
            box[a] = fminf(box[a], sc->tri[3 * i + a]);
            box[3 + a] = fmaxf(box[3 + a], sc->tri[3 * i + a]);
        }
}

/* The light-dependent optimisations are at work for the sun, not turned off (tu_method_check). */
static void sun_optimisations_at_work(const char *method, const ms_frame *f, const ms_frame *ref, void *deg)
{
    (void)ref;
    if (strcmp(method, "scanline")) return;
    printf("sun %.2f deg, scanline: %llu triangles culled, %llu interior boxes, %llu triangles merged\n",
           (double)*(const float *)deg, (unsigned long long)f->stats.occluders_culled,
           (unsigned long long)f->stats.interior_boxes, (unsigned long long)f->stats.occluders_merged);
    assert_true(f->stats.occluders_culled > 0);
    assert_true(f->stats.interior_boxes > 0);
    assert_true(f->stats.occluders_merged > 0);
}

static void check_every_method(float deg)
{
    ms_scene sc;
    make_sun_scene(&sc, deg);
    const int size = 32;
    ms_render_options o;
    tu_render_options_default(&o);
    o.width = o.height = size;
    o.threads = 2;
    char err[256];
    ms_frame ref;
    tu_every_method_as_raytrace(&sc, &o, "sun frame", &ref, sun_optimisations_at_work, &deg);
    /* the brute force at each pixel, on the sun placed as the frame places it */
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 1), 0);
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, &sc, &bvh, size, size, 16);
    const ms_primary_method *pm = ms_find_primary_method("bvh");
    void *ps = NULL;
    assert_int_equal(pm->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit hits[32 * 32];
    pm->trace(ps, &ctx, 0, 0, size, size, hits);
    pm->destroy(ps);
    ms_light sun = sc.light;
    float box[6];
    tri_box(&sc, box);
    ms_light_sun_place(&sun, box);
    const double ta = tan(0.5 * deg * M_PI / 180.0);
    const double u[3] = { sun.center.x, sun.center.y, sun.center.z };
    float pts[3 * 256];
    int decided = 0, partial = 0, lit = 0, hit = 0;
    for (int i = 0; i < size * size; i++) {
        if (hits[i].prim == UINT32_MAX) continue;
        hit++;
        ms_light disk;
        assert_int_equal(ms_light_shape_of(MS_LIGHT_SUN)->outline(&sun, hits[i].p, &disk), 0);
        ms_pattern_points(MS_PATTERN_GRID, &disk, 16, (uint32_t)(i % size), (uint32_t)(i / size), 0, pts);
        const double p[3] = { hits[i].p[0], hits[i].p[1], hits[i].p[2] }, *nn = NULL;
        const double nr[3] = { hits[i].n[0], hits[i].n[1], hits[i].n[2] };
        nn = nr;
        int nf = 0, nv = 0, unsure = 0;
        double sw = 0.0, swv = 0.0;
        for (int s = 0; s < 256 && !unsure; s++) {
            const double L[3] = { pts[3 * s], pts[3 * s + 1], pts[3 * s + 2] };
            const double d[3] = { L[0] - p[0], L[1] - p[1], L[2] - p[2] };
            const double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            const double cr = (d[0] * nn[0] + d[1] * nn[1] + d[2] * nn[2]) / r;
            const double along = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
            const double side2 = r * r - along * along;
            /* the direction's tangent against the cone's: on the sun when below */
            const double off = side2 / (along * along * ta * ta) - 1.0;
            if (fabs(cr) < 1e-5 || fabs(off) < 1e-4) { unsure = 1; break; }
            if (!(cr > 0.0 && off < 0.0)) continue;
            nf++;
            verdict occ = NO;
            for (uint32_t t = 0; t < bvh.n_tris && occ != YES; t++) {
                if (t == hits[i].prim) continue;
                const verdict v = (verdict)tu_segment_hits(bvh.tri + 9 * (size_t)t, p, L, 1e-4, INFINITY);   /* a ray: no far end */
                if (v != NO) occ = v;
            }
            if (occ == UNSURE) { unsure = 1; break; }
            const double w = cr * (along / r) / (r * r);   /* cos theta_l: the disk faces -u */
            sw += w;
            if (occ == NO) { nv++; swv += w; }
        }
        if (unsure) continue;
        decided++;
        partial += nv > 0 && nv < nf;
        lit += nv > 0;
        assert_int_equal(ref.front[i], nf);
        assert_true(ref.vis[i] == (nf ? (float)nv / (float)nf : 0.0f));
        if (nf) assert_true(fabs(ref.shadow[i] - swv / sw) < 1e-5);
    }
    printf("sun %.2f deg: the brute force decided %d of %d pixels on the scene (%d lit, %d in penumbra)\n", (double)deg,
           decided, hit, lit, partial);
    assert_true(decided > hit * 9 / 10 && lit > hit / 2);
    if (deg > 1.0f) assert_true(partial > 0);
    ms_bvh_free(&bvh);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

static void test_every_method_wide(void **st) { (void)st; check_every_method(8.0f); }
static void test_every_method_sun(void **st) { (void)st; check_every_method(0.53f); }

/* ---- bakes (the points API): the sun given unplaced, placed for the accel's scene ---- */

/* The Quad (ground, a square occluder at height 2) under a sun of 6 degrees: every method's baked V, S and front
 * equal raytrace's texel for texel, and raytrace's V and front the brute force (no far limit) where it decides. */
static void test_bake(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    assert_int_equal(ms_light_sun(&sc.light, (ms_vec3){ 0.3f, 1.0f, 0.2f }, 6.0f), 0);
    sc.light.emission = (ms_vec3){ 1, 1, 1 };
    const int size = 56;   /* more than 10 penumbra texels in the layout of docs/baking.md, "Charts" */
    const size_t nt = (size_t)size * size;
    char err[512];
    ms_bake_options bo;
    memset(&bo, 0, sizeof bo);
    bo.size = size;
    bo.uv_set = -1;
    bo.points.samples = 256;
    bo.points.threads = 2;
    bo.points.isa = tu_isa_cap();
    bo.points.method = "raytrace";
    ms_lightmap ref, lm;
    assert_int_equal(ms_bake(&sc, NULL, &bo, &ref, err, sizeof err), MS_OK);
    const char *const *names = ms_method_names();
    for (int mi = 0; names[mi]; mi++) {
        bo.points.method = names[mi];
        assert_int_equal(ms_bake(&sc, NULL, &bo, &lm, err, sizeof err), MS_OK);
        long differ = 0;
        for (size_t i = 0; i < nt; i++)
            differ += lm.frame.vis[i] != ref.frame.vis[i] || lm.frame.shadow[i] != ref.frame.shadow[i] ||
                      lm.frame.front[i] != ref.frame.front[i];
        if (differ) fprintf(stderr, "sun bake, method %s: %ld texels differ from raytrace\n", names[mi], differ);
        assert_int_equal(differ, 0);
        ms_lightmap_free(&lm);
    }
    ms_light sun = sc.light;
    float box[6];
    tri_box(&sc, box);
    ms_light_sun_place(&sun, box);
    const double ta = tan(3.0 * M_PI / 180.0), u[3] = { sun.center.x, sun.center.y, sun.center.z };
    float pts[3 * 256];
    long decided = 0, partial = 0, bad = 0, texels = 0;
    for (size_t i = 0; i < nt; i++) {
        if (ref.triangle[i] == MS_NO_TRIANGLE) continue;
        texels++;
        const float *pf = ref.position + 3 * i, *n = ref.normal + 3 * i;
        const double p[3] = { pf[0], pf[1], pf[2] };
        ms_light disk;
        assert_int_equal(ms_light_shape_of(MS_LIGHT_SUN)->outline(&sun, pf, &disk), 0);
        ms_pattern_points(MS_PATTERN_GRID, &disk, 16, (uint32_t)(i % size), (uint32_t)(i / size), 0, pts);
        int nf = 0, nv = 0, unsure = 0;
        for (int s = 0; s < 256 && !unsure; s++) {
            const double L[3] = { pts[3 * s], pts[3 * s + 1], pts[3 * s + 2] };
            const double d[3] = { L[0] - p[0], L[1] - p[1], L[2] - p[2] };
            const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], along = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
            const double off = (r2 - along * along) / (along * along * ta * ta) - 1.0;
            const double side = (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / sqrt(r2);
            if (fabs(off) < 1e-4 || fabs(side) < 1e-5) { unsure = 1; break; }
            if (off > 0.0 || side < 0.0) continue;
            nf++;
            verdict occ = NO;
            for (size_t t = 0; t < sc.n_tris && occ != YES; t++) {
                if (t == ref.triangle[i]) continue;
                const verdict v = (verdict)tu_segment_hits(sc.tri + 9 * t, p, L, 1e-4, INFINITY);
                if (v != NO) occ = v;
            }
            if (occ == UNSURE) unsure = 1;
            nv += occ == NO;
        }
        if (unsure) continue;
        decided++;
        partial += nv > 0 && nv < nf;
        bad += ref.frame.vis[i] != (nf ? (float)nv / (float)nf : 0.0f) || ref.frame.front[i] != nf;
    }
    printf("sun bake: the brute force decided %ld of %ld texels (%ld in penumbra); %ld differ from raytrace\n", decided,
           texels, partial, bad);
    assert_int_equal(bad, 0);
    assert_true(decided > texels * 8 / 10 && partial > 10);
    ms_lightmap_free(&ref);
    ms_scene_free(&sc);
}

/* Points outside the scene's ball (the points API only): their segments grow so that they still leave the
 * scene. Under the Quad's ground at 200 below (its sun ray meets the ground 4 off centre): V = 0 by every
 * method, where a segment of the scene's length D = 57 would end in the air below the ground and see the sun;
 * 200 above: V = 1; and every method equals raytrace at points around the scene. */
static void test_points_outside(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    assert_int_equal(ms_light_sun(&sc.light, (ms_vec3){ 0.02f, 1.0f, 0.01f }, 2.0f), 0);
    sc.light.emission = (ms_vec3){ 1, 1, 1 };
    ms_accel *acc = NULL;
    char err[512];
    assert_int_equal(ms_accel_build(&sc, 2, &acc, err, sizeof err), MS_OK);
    enum { N = 6 };
    const float pos[N][3] = { { 0, -200, 0 }, { 0, 200, 0 }, { 0.5f, 1, 0.3f }, { -30, 3, 40 }, { 1, -5, 1 }, { 12, 0.5f, -3 } };
    const float nrm[N][3] = { { 0, 1, 0 }, { 0, 1, 0 }, { 0, 1, 0 }, { 0.2f, 1, 0 }, { 0, 1, 0 }, { -1, 1, 0 } };
    const ms_points q = { .n = N, .position = &pos[0][0], .normal = &nrm[0][0] };
    float rv[N], rs[N], v[N], s[N];
    uint16_t rf[N], f[N];
    ms_points_options o;
    memset(&o, 0, sizeof o);
    o.samples = 256;
    o.threads = 1;
    o.isa = tu_isa_cap();
    o.method = "raytrace";
    assert_int_equal(ms_visibility_points(acc, NULL, &q, &o, rv, rs, rf, NULL, err, sizeof err), MS_OK);
    printf("sun, points: V under the ground %g, far above %g, under the occluder %g, beside the scene %g\n", (double)rv[0],
           (double)rv[1], (double)rv[2], (double)rv[3]);
    assert_true(rv[0] == 0.0f && rf[0] > 0);
    assert_true(rv[1] == 1.0f && rf[1] > 0);
    assert_true(rv[2] == 0.0f);
    const char *const *names = ms_method_names();
    for (int mi = 0; names[mi]; mi++) {
        o.method = names[mi];
        assert_int_equal(ms_visibility_points(acc, NULL, &q, &o, v, s, f, NULL, err, sizeof err), MS_OK);
        for (int i = 0; i < N; i++) {
            if (v[i] != rv[i] || s[i] != rs[i] || f[i] != rf[i])
                fprintf(stderr, "sun points, method %s, point %d: V %g S %g front %d, raytrace %g %g %d\n", names[mi], i,
                        (double)v[i], (double)s[i], f[i], (double)rv[i], (double)rs[i], rf[i]);
            assert_true(v[i] == rv[i] && s[i] == rs[i] && f[i] == rf[i]);
        }
    }
    ms_accel_free(acc);
    ms_scene_free(&sc);
}

/* The closed-mesh cull with the sun's hull at its limit: a box (12 triangles) over a ground, its +x face at
 * x = 1.2 nearly parallel to the sun (the sun 0.5 degrees off the vertical towards +x, its disk 0.265 degrees
 * in radius: every direction of the cone is in front of that face, by 0.235 degrees at least). Points on the
 * ground under the box's edge see the sun through the bottom face (facing away: culled) and out through that
 * side face, which must be kept: every method's V, S and front equal raytrace's (which culls nothing), with
 * samples in penumbra. A hull of the square at distance D alone (seen from the origin, not from every receiver)
 * culls that face and fails here. */
static void grazing_cull_at_work(const char *method, const ms_frame *f, const ms_frame *ref, void *user)
{
    (void)ref;
    (void)user;
    if (strcmp(method, "scanline")) return;
    printf("sun grazing a box's face: scanline culled %llu triangles\n", (unsigned long long)f->stats.occluders_culled);
    assert_true(f->stats.occluders_culled > 0);
}

static void test_cull_grazing(void **st)
{
    (void)st;
    ms_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.tri = malloc((2 + 12) * 9 * sizeof *sc.tri);
    assert_non_null(sc.tri);
    static const float ground[2][9] = { { -10, 0, -10, -10, 0, 10, 10, 0, 10 }, { -10, 0, -10, 10, 0, 10, 10, 0, -10 } };
    memcpy(sc.tri, ground, sizeof ground);
    sc.n_tris = put_box(sc.tri, 2, (const float[]){ 0.2f, 1, -0.5f }, (const float[]){ 1.2f, 2, 0.5f }, 1);
    const double b = 0.5 * M_PI / 180.0;
    assert_int_equal(ms_light_sun(&sc.light, (ms_vec3){ (float)sin(b), (float)cos(b), 0 }, 0.53f), 0);
    sc.light.emission = (ms_vec3){ 1, 1, 1 };
    /* an orthographic view under the box, of the ground about x = 1.187: 64 x 16 pixels of 0.000625 */
    sc.camera = (ms_camera){ { 1.19f, 0.5f, 3 }, { 1.19f, 0, 0 }, { 0, 1, 0 }, 0, 64, 16, MS_CAMERA_ORTHOGRAPHIC, 0, 0.01f };
    sc.samples = 1024;
    ms_render_options o;
    tu_render_options_default(&o);
    o.threads = 2;
    ms_frame ref;
    tu_every_method_as_raytrace(&sc, &o, "sun grazing", &ref, grazing_cull_at_work, NULL);
    int partial = 0, dark = 0;
    for (int i = 0; i < 64 * 16; i++) { partial += ref.vis[i] > 0.0f && ref.vis[i] < 1.0f; dark += ref.vis[i] == 0.0f; }
    printf("sun grazing a box's face: %d of %d pixels in penumbra, %d in umbra\n", partial, 64 * 16, dark);
    assert_true(partial > 16 && dark > 16);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

/* ---- blocks of receivers at different heights: each lane its own outline ---- */

/* The micro-rasterization methods take an outlined light's queries a 4x4 block at a time, each pixel on its
 * own outline (microraster.c, ms_ctx_for_query). A view from above of a "city" of flat roofs 0.5 wide at
 * heights from 0.2 to 3.2 (neighbouring pixels of a block up to 3 apart) under a bar at height 5 and a wide
 * sun (60 degrees) or a large sphere near by: a pixel traced with a neighbour's outline would be answered
 * on samples shifted by the heights' difference (for the sun a direction off by about 3 / D of a cone of
 * half-angle 30 degrees), which the bar's wide penumbra shows. Every method's V, S and front equal raytrace's
 * (answered one query at a time), and scanline's blocks hold several pixels each. */
static void blocks_kept(const char *method, const ms_frame *f, const ms_frame *ref, void *user)
{
    (void)user;
    if (strcmp(method, "scanline")) return;
    uint64_t blocks = 0, hit = 0;
    for (int c = 0; c < f->stats.n_counters; c++)
        if (!strcmp(f->stats.counter_name[c], "blocks")) blocks = f->stats.counter[c];
    for (int i = 0; i < ref->width * ref->height; i++) hit += ref->vis[i] >= 0.0f;
    printf("scanline traversed %llu blocks for %llu pixels on geometry\n", (unsigned long long)blocks, (unsigned long long)hit);
    assert_true(blocks > 0 && blocks < hit / 4);   /* the blocks kept: not one per pixel */
}

static void test_block_lanes(void **st)
{
    (void)st;
    enum { C = 12 };   /* C x C roofs */
    ms_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.tri = malloc((2 + 2 * C * C + 12) * 9 * sizeof *sc.tri);
    assert_non_null(sc.tri);
    size_t n = put_quad(sc.tri, 0, (float[]){ -8, 0, -8 }, (float[]){ -8, 0, 8 }, (float[]){ 8, 0, 8 }, (float[]){ 8, 0, -8 });
    for (int i = 0; i < C; i++)
        for (int j = 0; j < C; j++) {
            const float x0 = -3.0f + 0.5f * (float)i, z0 = -3.0f + 0.5f * (float)j, x1 = x0 + 0.5f, z1 = z0 + 0.5f;
            const float h = 0.2f + 0.75f * (float)((7 * i + 3 * j) % 5);
            n = put_quad(sc.tri, n, (float[]){ x0, h, z0 }, (float[]){ x0, h, z1 }, (float[]){ x1, h, z1 }, (float[]){ x1, h, z0 });
        }
    sc.n_tris = put_box(sc.tri, n, (const float[]){ -4, 5, -0.4f }, (const float[]){ 4, 5.3f, 0.4f }, 1);
    /* 32 x 32 pixels of 0.1875 over the roofs: about 2.7 pixels to a roof, so every block spans several */
    sc.camera = (ms_camera){ { 0, 20, 0 }, { 0, 0, 0 }, { 0, 0, -1 }, 0, 32, 32, MS_CAMERA_ORTHOGRAPHIC, 0, 6.0f };
    sc.samples = 256;
    for (int light = 0; light < 2; light++) {
        if (light == 0) assert_int_equal(ms_light_sun(&sc.light, (ms_vec3){ 0.3f, 0.8f, 0.5f }, 60.0f), 0);
        else assert_int_equal(ms_light_sphere(&sc.light, (ms_vec3){ 1.5f, 9.0f, 2.5f }, 3.0f), 0);
        sc.light.emission = (ms_vec3){ 1, 1, 1 };
        ms_render_options o;
        tu_render_options_default(&o);
        o.threads = 2;
        ms_frame ref;
        tu_every_method_as_raytrace(&sc, &o, light ? "sphere over roofs" : "sun over roofs", &ref, blocks_kept, NULL);
        int partial = 0, hit = 0;
        for (int i = 0; i < 32 * 32; i++) {
            hit += ref.vis[i] >= 0.0f;
            partial += ref.vis[i] > 0.0f && ref.vis[i] < 1.0f;
        }
        printf("%s over roofs: %d of %d pixels in penumbra\n", light ? "sphere" : "sun 60 deg", partial, hit);
        assert_true(partial > hit / 8);
        ms_frame_free(&ref);
    }
    ms_scene_free(&sc);
}

/* ---- the penumbra of a pole ---- */

/* A 1 x 80 x 1 pole on a ground of 400 x 400, the sun at 45 degrees towards -x: the shadow runs along +x and
 * its edge z = 0.5 is lit through the pole's vertical edge at distance d = (x - 0.5) sqrt(2). An orthographic
 * view from above of 64 x 64 pixels of 0.02 centred on the edge at x: the pixels of the middle rows with
 * 0 < V < 1 span the penumbra, d 2 tan(alpha) = d tan(0.53 deg) to first order. */
static void test_penumbra_width(void **st)
{
    (void)st;
    static const float ground[2][9] = { { -200, 0, -200, -200, 0, 200, 200, 0, 200 }, { -200, 0, -200, 200, 0, 200, 200, 0, -200 } };
    ms_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.tri = malloc((2 + 12) * 9 * sizeof *sc.tri);
    assert_non_null(sc.tri);
    memcpy(sc.tri, ground, sizeof ground);
    size_t n = 2;
    const float lo[3] = { -0.5f, 0, -0.5f }, hi[3] = { 0.5f, 80, 0.5f };
    for (int a = 0; a < 3; a++)
        for (int side = 0; side < 2; side++) {
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            float v[4][3];
            const int db[4] = { 0, 1, 1, 0 }, dc[4] = { 0, 0, 1, 1 };
            for (int k = 0; k < 4; k++) {
                v[k][a] = side ? hi[a] : lo[a];
                v[k][b] = db[k] ? hi[b] : lo[b];
                v[k][c] = dc[k] ? hi[c] : lo[c];
            }
            n = side ? put_quad(sc.tri, n, v[0], v[1], v[2], v[3]) : put_quad(sc.tri, n, v[0], v[3], v[2], v[1]);
        }
    sc.n_tris = n;
    assert_int_equal(ms_light_sun(&sc.light, (ms_vec3){ -1, 1, 0 }, 0.53f), 0);
    sc.light.emission = (ms_vec3){ 1, 1, 1 };
    sc.samples = 4096;
    const double px = 0.02, alpha = 0.5 * 0.53 * M_PI / 180.0;
    const double xs[3] = { 10.5, 25.5, 40.5 };
    for (int k = 0; k < 3; k++) {
        sc.camera = (ms_camera){ { (float)xs[k], 50, 0.5f }, { (float)xs[k], 0, 0.5f }, { 1, 0, 0 }, 0, 64, 64,
                                 MS_CAMERA_ORTHOGRAPHIC, 0, (float)(64 * px) };
        ms_render_options o;
        tu_render_options_default(&o);
        o.threads = 2;
        o.method = "scanline";
        ms_frame f;
        tu_render_ok(&sc, &o, &f);
        const double d = (xs[k] - 0.5) * sqrt(2.0), want = d * tan(0.53 * M_PI / 180.0) / px;
        const double exact = d * 2.0 * tan(alpha) / px;
        for (int y = 31; y <= 32; y++) {
            int count = 0, umbra = 0, full = 0;
            for (int x = 0; x < 64; x++) {
                const float v = f.vis[y * 64 + x];
                assert_true(v >= 0.0f);
                count += v > 0.0f && v < 1.0f;
                umbra += v == 0.0f;
                full += v == 1.0f;
            }
            printf("pole shadow edge at d = %.2f: %d penumbra pixels, d tan(0.53 deg) = %.2f pixels (2 d tan(alpha) = %.2f); "
                   "%d umbra, %d lit\n", d, count, want, exact, umbra, full);
            assert_true(fabs(count - want) <= 1.0);
            assert_true(umbra > 0 && full > 0);
        }
        ms_frame_free(&f);
    }
    ms_scene_free(&sc);
}

/* ---- irradiance ---- */

/* Numerical integration of max(cos, 0) over the cone of half-angle alpha about u, in polar coordinates about
 * u (midpoint rule, nr x nphi cells). */
static double cone_numeric(const double u[3], double alpha, const double nrm[3], int nr, int nphi)
{
    double e1[3], e2[3];
    const double a[3] = { fabs(u[0]) < 0.9 ? 1.0 : 0.0, fabs(u[0]) < 0.9 ? 0.0 : 1.0, 0.0 };
    e1[0] = a[1] * u[2] - a[2] * u[1]; e1[1] = a[2] * u[0] - a[0] * u[2]; e1[2] = a[0] * u[1] - a[1] * u[0];
    const double l = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int c = 0; c < 3; c++) e1[c] /= l;
    e2[0] = u[1] * e1[2] - u[2] * e1[1]; e2[1] = u[2] * e1[0] - u[0] * e1[2]; e2[2] = u[0] * e1[1] - u[1] * e1[0];
    double sum = 0.0;
    for (int i = 0; i < nr; i++) {
        const double th = alpha * (i + 0.5) / nr, dth = alpha / nr;
        for (int j = 0; j < nphi; j++) {
            const double ph = 2.0 * M_PI * (j + 0.5) / nphi;
            double w[3];
            for (int c = 0; c < 3; c++) w[c] = cos(th) * u[c] + sin(th) * (cos(ph) * e1[c] + sin(ph) * e2[c]);
            const double cn = w[0] * nrm[0] + w[1] * nrm[1] + w[2] * nrm[2];
            if (cn > 0.0) sum += cn * sin(th) * dth * (2.0 * M_PI / nphi);
        }
    }
    return sum;
}

static void test_sun_irradiance(void **st)
{
    (void)st;
    const float degs[2] = { 0.53f, 20.0f };
    int across = 0;
    double worst = 0.0;
    for (int di = 0; di < 2; di++) {
        ms_light l;
        memset(&l, 0, sizeof l);
        const ms_vec3 dir = { 0.3f, 0.9f, -0.2f };
        assert_int_equal(ms_light_sun(&l, dir, degs[di]), 0);
        const double len = sqrt(0.09 + 0.81 + 0.04), u[3] = { 0.3 / len, 0.9 / len, -0.2 / len };
        const double alpha = 0.5 * degs[di] * M_PI / 180.0, s2 = sin(alpha) * sin(alpha);
        for (int k = 0; k <= 40; k++) {
            /* normals sweeping from facing the sun to facing away, through the horizon */
            const double th = M_PI * k / 40.0;
            double e[3] = { -u[1], u[0], 0.0 };
            const double el = sqrt(e[0] * e[0] + e[1] * e[1]);
            e[0] /= el; e[1] /= el;
            const double nd[3] = { cos(th) * u[0] + sin(th) * e[0], cos(th) * u[1] + sin(th) * e[1], cos(th) * u[2] };
            const float n[3] = { (float)nd[0], (float)nd[1], (float)nd[2] }, p[3] = { 3, -1, 7 };
            const double got = ms_light_irradiance(&l, p, n);
            const double ct = cos(th);
            double want;
            if (ct * ct > s2) want = ct > 0.0 ? M_PI * s2 * ct : 0.0;   /* wholly above or below the horizon */
            else { want = cone_numeric(u, alpha, nd, 400, 800); across++; }
            const double err = fabs(got - want) / (M_PI * s2);
            worst = fmax(worst, err);
            if (err > 2e-4) fprintf(stderr, "sun %.2f deg, theta %.3f: %.9g, want %.9g\n", (double)degs[di], th, got, want);
            assert_true(err <= 2e-4);
        }
        /* the same at every point */
        const float n[3] = { (float)u[0], (float)u[1], (float)u[2] }, p1[3] = { 0, 0, 0 }, p2[3] = { -5e3f, 40, 1e4f };
        assert_true(ms_light_irradiance(&l, p1, n) == ms_light_irradiance(&l, p2, n));
    }
    printf("sun irradiance: worst relative error %.2e of pi L sin^2 alpha (%d normals across the horizon)\n", worst, across);
    assert_true(across >= 2);
}

/* ---- glTF directional, and the scene file ---- */

static void test_gltf_directional(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("sun_gltf");
    /* a ground 8 x 8 (two triangles) and a square occluder 1 x 1 at height 1 */
    static const float tri[4][9] = { { -4, 0, -4, -4, 0, 4, 4, 0, 4 }, { -4, 0, -4, 4, 0, 4, 4, 0, -4 },
                                     { -0.5f, 1, -0.5f, -0.5f, 1, 0.5f, 0.5f, 1, 0.5f }, { -0.5f, 1, -0.5f, 0.5f, 1, 0.5f, 0.5f, 1, -0.5f } };
    char path[4096];
    FILE *f = fopen(tu_path(path, sizeof path, dir, "d.bin"), "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(tri, sizeof tri, 1, f), 1);
    fclose(f);
    /* The light's node turned by the quaternion q = (x, y, z, w) = (-0.3, 0.2, 0.1, w) normalised: its -Z
     * is where the light travels, +Z towards the sun. */
    const double qx0 = -0.3, qy0 = 0.2, qz0 = 0.1, qw0 = 0.9273618495495703;
    const double qn = sqrt(qx0 * qx0 + qy0 * qy0 + qz0 * qz0 + qw0 * qw0);
    const double x = qx0 / qn, y = qy0 / qn, z = qz0 / qn, w = qw0 / qn;
    /* the rotation matrix's third column: R e_z */
    const double zc[3] = { 2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y) };
    char js[4096];
    snprintf(js, sizeof js,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
             "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"directional\",\"color\":[1,0.8,0.5],"
             "\"intensity\":1000,\"extras\":{\"angular_diameter_deg\":3}}]}},"
             "\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
             "\"nodes\":[{\"mesh\":0},{\"rotation\":[%.17g,%.17g,%.17g,%.17g],\"translation\":[5,5,5],"
             "\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
             "\"buffers\":[{\"uri\":\"d.bin\",\"byteLength\":%zu}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":12,\"type\":\"VEC3\","
             "\"min\":[-4,0,-4],\"max\":[4,1,4]}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}",
             x, y, z, w, sizeof tri, sizeof tri);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "d.gltf"), js), 0);
    const char *scene = "{ \"meshes\": [ { \"file\": \"d.gltf\" } ],\n"
                        " \"camera\": { \"eye\": [0, 6, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 60,"
                        " \"width\": 24, \"height\": 24 }, \"render\": { \"samples\": 256 } }\n";
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "d.json"), scene), 0);
    ms_scene sc;
    char err[512];
    if (ms_scene_load(path, &sc, err, sizeof err)) fail_msg("%s", err);
    size_t nl;
    const ms_light *L = ms_scene_lights(&sc, &nl);
    assert_int_equal((int)nl, 1);
    assert_int_equal(L[0].shape, MS_LIGHT_SUN);
    assert_true(fabs(L[0].center.x - zc[0]) < 1e-6 && fabs(L[0].center.y - zc[1]) < 1e-6 && fabs(L[0].center.z - zc[2]) < 1e-6);
    /* lux to radiance: E = pi L sin^2 alpha, alpha = 1.5 degrees */
    const double sa = sin(1.5 * M_PI / 180.0), k = 1000.0 / (M_PI * sa * sa);
    assert_true(fabs(L[0].emission.x / k - 1.0) < 1e-5 && fabs(L[0].emission.y / (0.8 * k) - 1.0) < 1e-5 &&
                fabs(L[0].emission.z / (0.5 * k) - 1.0) < 1e-5);
    /* the illuminance at normal incidence comes back as 1000 lux */
    const float nrm[3] = { L[0].center.x, L[0].center.y, L[0].center.z }, p[3] = { 0, 0, 0 };
    assert_true(fabs(ms_light_irradiance(&L[0], p, nrm) * L[0].emission.x - 1000.0) < 0.05);
    ms_render_options o;
    tu_render_options_default(&o);
    o.threads = 2;
    ms_frame ref;
    tu_every_method_as_raytrace(&sc, &o, "glTF sun", &ref, NULL, NULL);
    long shadowed = 0, lit = 0;
    for (int i = 0; i < 24 * 24; i++) { shadowed += ref.vis[i] == 0.0f; lit += ref.vis[i] == 1.0f; }
    assert_true(shadowed > 0 && lit > 0);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

static void test_scene_file(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("sun_json");
    char path[4096], text[2048];
    const char *head = "{ \"camera\": { \"eye\": [0, 6, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 60, "
                       "\"width\": 16, \"height\": 16 }, \"procedural\": { \"type\": \"flowers\", \"triangles\": 2000, "
                       "\"seed\": 1 }, ";
    snprintf(text, sizeof text, "%s\"light\": { \"shape\": \"sun\", \"direction\": [0, 2, 0], \"lumens\": 100000 } }", head);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "a.json"), text), 0);
    ms_scene sc;
    char err[512];
    if (ms_scene_load(path, &sc, err, sizeof err)) fail_msg("%s", err);
    assert_int_equal(sc.light.shape, MS_LIGHT_SUN);
    assert_true(sc.light.center.x == 0.0f && sc.light.center.y == 1.0f && sc.light.center.z == 0.0f);
    /* the default 0.53 degrees; "lumens" is the illuminance at normal incidence */
    const double sa = sin(0.265 * M_PI / 180.0);
    assert_true(fabs(sc.light.emission.x / (100000.0 / (M_PI * sa * sa)) - 1.0) < 1e-5);
    /* a streamed procedural scene (hpc) places the sun as the materialised one does: the same frame */
    ms_render_options o;
    tu_render_options_default(&o);
    o.threads = 2;
    ms_frame a, b;
    o.method = "hpc";
    tu_render_ok(&sc, &o, &a);
    o.method = "raytrace";
    tu_render_ok(&sc, &o, &b);
    long differ = 0, shadowed = 0;
    for (int i = 0; i < 16 * 16; i++) { differ += a.vis[i] != b.vis[i] || a.shadow[i] != b.shadow[i]; shadowed += b.vis[i] < 1.0f && b.vis[i] >= 0.0f; }
    printf("procedural scene under the sun: %ld of 256 pixels shadowed, %ld differ\n", shadowed, differ);
    assert_int_equal(differ, 0);
    ms_frame_free(&a);
    ms_frame_free(&b);
    ms_scene_free(&sc);
    static const struct { const char *light, *needle; } bad[] = {
        { "{ \"shape\": \"sun\" }", "light.direction is missing" },
        { "{ \"shape\": \"sun\", \"direction\": [0, 0, 0] }", "direction must not be zero" },
        { "{ \"shape\": \"sun\", \"direction\": [0, 1, 0], \"angular_diameter_deg\": 0 }", "angular_diameter_deg must be in (0, 90]" },
        { "{ \"shape\": \"sun\", \"direction\": [0, 1, 0], \"angular_diameter_deg\": 120 }", "angular_diameter_deg must be in (0, 90]" },
        { "{ \"shape\": \"sun\", \"direction\": [0, 1, 0], \"texture\": \"t.png\" }", "texture" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(text, sizeof text, "%s\"light\": %s }", head, bad[i].light);
        assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "b.json"), text), 0);
        assert_int_not_equal(ms_scene_load(path, &sc, err, sizeof err), 0);
        if (!strstr(err, bad[i].needle)) fail_msg("got \"%s\", want \"%s\"", err, bad[i].needle);
        assert_non_null(strstr(err, "b.json"));
    }
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_method_wide),
        cmocka_unit_test(test_every_method_sun),
        cmocka_unit_test(test_bake),
        cmocka_unit_test(test_points_outside),
        cmocka_unit_test(test_cull_grazing),
        cmocka_unit_test(test_block_lanes),
        cmocka_unit_test(test_penumbra_width),
        cmocka_unit_test(test_sun_irradiance),
        cmocka_unit_test(test_gltf_directional),
        cmocka_unit_test(test_scene_file),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
