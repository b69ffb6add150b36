/* The definition of V and S (microshadow.h, docs/design.md) against independent oracles:
 *   - receivers whose plane cuts the light: every method's V and S (grid; the ray tracers also on the
 *     interleaved pattern and on 16 stratified samples) equal a brute-force double-precision
 *     count and weighted sum over the same samples (front test, segment-triangle tests, weights);
 *   - two lifts: V and S do not depend on how far the hit point is lifted off its surface;
 *   - the underside of a ceiling under a light above it sees nothing of the light (V = S = 0);
 *   - the Quad shaded: E_unshadowed * S matches the analytic shadowed irradiance (polygon form factors of
 *     the light minus the occluder's projection onto it). */
#include "testutil.h"
#include "shadow/method.h"
#include "shadow/raytrace/raytrace.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "light/pattern.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- double-precision oracle ---- */

typedef struct oracle {
    int front, visible, ties;     /* counts over the pixel's samples; ties: within rounding of a decision */
    double wf, wv, wtie;          /* weight sums: front, visible, tied samples */
} oracle;

static void d_sub(double r[3], const double a[3], const double b[3]) { for (int i = 0; i < 3; i++) r[i] = a[i] - b[i]; }
static double d_dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void d_cross(double r[3], const double a[3], const double b[3])
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}

#define TIE 1e-6

/* Segment p + u (l - p), u in [near, far], against a triangle: 1 hit, 0 miss, -1 within TIE of an edge,
 * a vertex or the ends of the range. */
static int seg_tri(const double p[3], const double l[3], const float *t, double near, double far)
{
    double a[3], b[3], c[3], d[3];
    for (int i = 0; i < 3; i++) { a[i] = t[i]; b[i] = t[3 + i]; c[i] = t[6 + i]; }
    d_sub(d, l, p);
    double e1[3], e2[3], pv[3], s[3], qv[3];
    d_sub(e1, b, a);
    d_sub(e2, c, a);
    d_cross(pv, d, e2);
    double det = d_dot(e1, pv);
    if (det == 0.0) return 0;
    d_sub(s, p, a);
    double u = d_dot(s, pv) / det;
    d_cross(qv, s, e1);
    double v = d_dot(d, qv) / det, w = 1.0 - u - v, tt = d_dot(e2, qv) / det;
    double lo = fmin(fmin(u, v), w), tlo = fmin(tt - near, far - tt);
    if (lo > TIE && tlo > TIE) return 1;
    if (lo < -TIE || tlo < -TIE) return 0;
    return -1;
}

static oracle brute_force(const ms_render_ctx *ctx, const float *soup, size_t ntri, const float *skip_tri,
                          const ms_shadow_query *q)
{
    oracle o = { 0 };
    float *pts = malloc((size_t)ctx->samples * 3 * sizeof *pts);
    assert_non_null(pts);
    ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q->px, q->py, ctx->seed, pts);
    const ms_light *L = &ctx->light;
    double es[3] = { L->edge_s.x, L->edge_s.y, L->edge_s.z }, et[3] = { L->edge_t.x, L->edge_t.y, L->edge_t.z }, nl[3];
    d_cross(nl, es, et);
    double nll = sqrt(d_dot(nl, nl));
    for (int i = 0; i < 3; i++) nl[i] /= nll;
    double p[3] = { q->p[0], q->p[1], q->p[2] }, n[3] = { q->n[0], q->n[1], q->n[2] };
    for (int s = 0; s < ctx->samples; s++) {
        double l[3] = { pts[3 * s], pts[3 * s + 1], pts[3 * s + 2] }, d[3];
        d_sub(d, l, p);
        double r2 = d_dot(d, d), a = d_dot(d, n), b = -d_dot(d, nl);
        double w = fmax(a, 0.0) * fmax(b, 0.0) / (r2 * r2);
        if (fabs(a) <= TIE * sqrt(r2)) { o.ties++; o.wtie += w; continue; }
        if (a < 0.0) continue;
        int state = 1;   /* 1 visible, 0 occluded, -1 tie */
        for (size_t t = 0; t < ntri && state != 0; t++) {
            const float *tri = soup + 9 * t;
            if (skip_tri && !memcmp(tri, skip_tri, 9 * sizeof(float))) continue;
            int h = seg_tri(p, l, tri, ctx->near, ctx->far);
            if (h == 1) state = 0;
            else if (h == -1) state = -1;
        }
        if (state == -1) { o.ties++; o.wtie += w; continue; }
        o.front++;
        o.wf += w;
        if (state == 1) { o.visible++; o.wv += w; }
    }
    free(pts);
    return o;
}

/* ---- scenes ---- */

/* Every shadow method of the registry (ms_method_names: those compiled into this build), so that a new
 * method is tested without touching this file. */
#define methods (ms_method_names())

static size_t find_prim(const ms_bvh *bvh, const float *tri)
{
    for (size_t i = 0; i < bvh->n_tris; i++)
        if (!memcmp(bvh->tri + 9 * i, tri, 9 * sizeof(float))) return i;
    fail_msg("receiver triangle not found in the BVH");
    return 0;
}

/* A light (2 x 2 at y = 4, emitting down), receiver quads tilted so that their planes cut it (and one
 * wholly below its horizon, one facing away), and random occluding triangles in between. */
static size_t make_cut_scene(ms_scene *sc, tu_rng *rng)
{
    const float recv[][9] = {
        { -2, 0, -3, -2, 0, 3, 0.5f, 5, 0 },     /* y = 2 (x + 2): meets the light's plane at x = 0 */
        { -2, 0.5f, 0, 2, 0.5f, 0, 0, 3.5f, 0.3f }, /* nearly vertical, z ~ 0.1 (y - 0.5): cuts the light */
        { -3, 0.5f, -3, 3, 0.5f, -3, 0, 5, 3 },    /* tilted the other way, through the light */
        { -4, 5, -4, 4, 5, -4, 0, 5, 4 },         /* a ceiling above the light: all behind */
        { -4, 0.2f, -4, 0, 0.2f, 4, 4, 0.2f, -4 },/* a floor: all in front */
    };
    const size_t nr = sizeof recv / sizeof *recv, nocc = 40;
    memset(sc, 0, sizeof *sc);
    sc->n_tris = nr + nocc;
    sc->tri = malloc(sc->n_tris * 9 * sizeof(float));
    assert_non_null(sc->tri);
    memcpy(sc->tri, recv, sizeof recv);
    for (size_t t = 0; t < nocc; t++) {
        float c[3] = { (float)(tu_rng_next(rng) % 4000) / 1000.0f - 2.0f, 1.0f + (float)(tu_rng_next(rng) % 2500) / 1000.0f,
                       (float)(tu_rng_next(rng) % 4000) / 1000.0f - 2.0f };
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++)
                sc->tri[9 * (nr + t) + 3 * v + a] = c[a] + ((float)(tu_rng_next(rng) % 1000) / 1000.0f - 0.5f) * 0.8f;
    }
    sc->camera = (ms_camera){ { 0, 2, 12 }, { 0, 2, 0 }, { 0, 1, 0 }, 60.0f, 64, 64, MS_CAMERA_PINHOLE, 0, 0 };
    sc->light = (ms_light){ { -1, 4, -1 }, { 2, 0, 0 }, { 0, 0, 2 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    sc->samples = 1024;
    return nr;
}

/* Random points on the receivers, normals turned towards the camera, as primary hits would be. */
static int make_queries(const ms_scene *sc, const ms_bvh *bvh, size_t nr, int per, tu_rng *rng, ms_shadow_query *q,
                        const float **recv_tri)
{
    int n = 0;
    for (size_t r = 0; r < nr; r++) {
        const float *t = sc->tri + 9 * r;
        float e1[3], e2[3], nn[3];
        for (int a = 0; a < 3; a++) { e1[a] = t[3 + a] - t[a]; e2[a] = t[6 + a] - t[a]; }
        nn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        nn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        float len = sqrtf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
        for (int a = 0; a < 3; a++) nn[a] /= len;
        size_t prim = find_prim(bvh, t);
        for (int i = 0; i < per; i++) {
            float u = (float)(tu_rng_next(rng) % 1000) / 1000.0f, v = (float)(tu_rng_next(rng) % 1000) / 1000.0f;
            if (u + v > 1.0f) { u = 1.0f - u; v = 1.0f - v; }
            float to_cam = 0.0f;
            for (int a = 0; a < 3; a++) {
                q[n].p[a] = t[a] + u * e1[a] + v * e2[a];
                to_cam += (sc->camera.eye.x * (a == 0) + sc->camera.eye.y * (a == 1) + sc->camera.eye.z * (a == 2) - q[n].p[a]) * nn[a];
            }
            for (int a = 0; a < 3; a++) q[n].n[a] = to_cam >= 0.0f ? nn[a] : -nn[a];
            q[n].prim = (uint32_t)prim;
            q[n].px = (uint32_t)(tu_rng_next(rng) % 4096);
            q[n].py = (uint32_t)(tu_rng_next(rng) % 4096);
            recv_tri[n] = t;
            n++;
        }
    }
    return n;
}

static void test_plane_cuts_light(void **st)
{
    (void)st;
    tu_rng rng = { 17 };
    ms_scene sc;
    const size_t nr = make_cut_scene(&sc, &rng);
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 0), 0);
    enum { PER = 40 };
    ms_shadow_query q[5 * PER];
    const float *recv_tri[5 * PER];
    const int n = make_queries(&sc, &bvh, nr, PER, &rng, q, recv_tri);
    /* the grid at every k; the other patterns for the ray tracers: interleaved (N/16 per pixel) and
     * stratified at 16 samples (one mask word, partly used) */
    static const struct { ms_pattern pat; int k; } cfg[] = {
        { MS_PATTERN_GRID, 16 }, { MS_PATTERN_GRID, 32 }, { MS_PATTERN_GRID, 64 },
        { MS_PATTERN_INTERLEAVED, 16 }, { MS_PATTERN_INTERLEAVED, 64 }, { MS_PATTERN_STRATIFIED, 4 } };
    for (size_t c = 0; c < sizeof cfg / sizeof *cfg; c++) {
        const int k = cfg[c].k;
        ms_render_ctx ctx;
        tu_ctx_init(&ctx, &sc, &bvh, 64, 64, k);
        tu_ctx_set_pattern(&ctx, cfg[c].pat);
        oracle *o = malloc((size_t)n * sizeof *o);
        assert_non_null(o);
        int cut = 0, none = 0, tied = 0;
        for (int i = 0; i < n; i++) {
            o[i] = brute_force(&ctx, sc.tri, sc.n_tris, recv_tri[i], &q[i]);
            cut += o[i].front > 0 && o[i].front < ctx.samples - o[i].ties;
            none += o[i].front == 0 && o[i].ties == 0;
            tied += o[i].ties > 0;
        }
        printf("%s k=%d: %d points, %d with the light cut by their plane, %d with none in front, %d with tied samples\n",
               ms_pattern_name(cfg[c].pat), k, n, cut, none, tied);
        assert_true(cut >= n / 4);
        assert_true(none >= PER);
        assert_true(tied * 20 <= n);
        for (size_t m = 0; methods[m]; m++) {
            const ms_shadow_method *sm = ms_find_shadow_method(methods[m]);
            if (!sm) { printf("%s not compiled in\n", methods[m]); continue; }
            if (sm->needs_grid && cfg[c].pat != MS_PATTERN_GRID) continue;
            void *state = NULL;
            char err[256];
            assert_int_equal(sm->create(&ctx, &state, err, sizeof err), 0);
            float v[5 * PER], s[5 * PER];
            uint64_t cnt[MS_MAX_COUNTERS] = { 0 };
            assert_int_equal(tu_shadow_vs(sm, state, &ctx, q, n, v, s, cnt), 0);
            double max_ds = 0.0;
            for (int i = 0; i < n; i++) {
                if (o[i].ties) continue;   /* a sample within rounding of a decision: either answer is right */
                const double ve = o[i].front ? (double)o[i].visible / o[i].front : 0.0;
                const double se = o[i].wf > 0.0 ? o[i].wv / o[i].wf : ve;
                if (fabs(v[i] - ve) > 1e-6) fail_msg("%s k=%d point %d: V %.7f, brute force %d/%d", methods[m], k, i, v[i], o[i].visible, o[i].front);
                if (fabs(s[i] - se) > 2e-5) fail_msg("%s k=%d point %d: S %.7f, brute force %.7f (V %.4f)", methods[m], k, i, s[i], se, ve);
                max_ds = fmax(max_ds, fabs(s[i] - se));
            }
            printf("  %-12s V exact on every untied point, max |S - S_exact| %.2e\n", methods[m], max_ds);
            sm->destroy(state);
        }
        free(o);
    }
    ms_bvh_free(&bvh);
    ms_scene_free(&sc);
}

/* A closed, jittered, convex-and-concave bumpy sphere under a large light: many receivers see the light
 * partly behind their plane, and their neighbours bend both ways. V and S from P and from P lifted by
 * 1e-5 of the scene's size along n must agree but for samples within that distance of the horizon. */
static void bumpy_sphere(ms_scene *sc, int nu, int nv, tu_rng *rng)
{
    const size_t nvert = (size_t)nu * (nv - 1) + 2;
    float *vert = malloc(nvert * 3 * sizeof *vert);
    assert_non_null(vert);
    for (int j = 1; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            float th = (float)M_PI * ((float)j + 0.3f * ((float)(tu_rng_next(rng) % 1000) / 1000.0f - 0.5f)) / (float)nv;
            float ph = 2.0f * (float)M_PI * ((float)i + 0.3f * ((float)(tu_rng_next(rng) % 1000) / 1000.0f - 0.5f)) / (float)nu;
            float r = 1.0f + 0.08f * sinf(5.0f * ph) * sinf(4.0f * th) + 0.01f * ((float)(tu_rng_next(rng) % 1000) / 1000.0f);
            float *v = vert + 3 * ((size_t)(j - 1) * nu + i);
            v[0] = r * sinf(th) * cosf(ph);
            v[1] = 1.2f + r * cosf(th);
            v[2] = r * sinf(th) * sinf(ph);
        }
    float *top = vert + 3 * (nvert - 2), *bot = vert + 3 * (nvert - 1);
    top[0] = 0; top[1] = 2.2f; top[2] = 0;
    bot[0] = 0; bot[1] = 0.2f; bot[2] = 0;
    const size_t ntri = (size_t)nu * 2 * (nv - 1) + 2;
    memset(sc, 0, sizeof *sc);
    sc->tri = malloc(ntri * 9 * sizeof(float));
    assert_non_null(sc->tri);
    size_t t = 0;
#define V(i, j) (vert + 3 * ((size_t)((j) - 1) * nu + ((i) % nu)))
#define PUT(a, b, c) do { memcpy(sc->tri + 9 * t, a, 12); memcpy(sc->tri + 9 * t + 3, b, 12); memcpy(sc->tri + 9 * t + 6, c, 12); t++; } while (0)
    for (int i = 0; i < nu; i++) {
        PUT(top, V(i, 1), V(i + 1, 1));
        PUT(bot, V(i + 1, nv - 1), V(i, nv - 1));
        for (int j = 1; j < nv - 1; j++) {
            PUT(V(i, j), V(i, j + 1), V(i + 1, j + 1));
            PUT(V(i, j), V(i + 1, j + 1), V(i + 1, j));
        }
    }
#undef V
#undef PUT
    /* a ground plane */
    const float ground[2][9] = { { -6, 0, -6, -6, 0, 6, 6, 0, 6 }, { -6, 0, -6, 6, 0, 6, 6, 0, -6 } };
    memcpy(sc->tri + 9 * t, ground, sizeof ground);
    t += 2;
    sc->n_tris = t;
    free(vert);
    sc->camera = (ms_camera){ { 2.5f, 3.0f, 4.0f }, { 0, 1.0f, 0 }, { 0, 1, 0 }, 50.0f, 96, 96, MS_CAMERA_PINHOLE, 0, 0 };
    sc->light = (ms_light){ { -3, 3.0f, -1 }, { 6, 0, 0 }, { 0, 0.5f, 3 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    sc->samples = 1024;
}

static void test_two_lifts(void **st)
{
    (void)st;
    tu_rng rng = { 5 };
    ms_scene sc;
    bumpy_sphere(&sc, 48, 24, &rng);
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 0), 0);
    const int W = 64, H = 64;
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, &sc, &bvh, W, H, 32);
    /* hit points from the BVH primary, then the same points lifted */
    const ms_primary_method *pm = ms_find_primary_method("bvh");
    void *ps = NULL;
    char err[256];
    assert_int_equal(pm->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit *hits = malloc(sizeof *hits * W * H);
    ms_shadow_query *q0 = malloc(sizeof *q0 * W * H), *q1 = malloc(sizeof *q1 * W * H);
    assert_non_null(hits);
    assert_non_null(q0);
    assert_non_null(q1);
    pm->trace(ps, &ctx, 0, 0, W, H, hits);
    pm->destroy(ps);
    /* Lifts: 8 ulps of the coordinates (rounding's scale), and the old 1e-5 of the scene's size. */
    const float lifts[2] = { 8.0f * 2.4e-7f, 1e-5f * 12.0f };
    int n = 0, cut = 0;
    for (int i = 0; i < W * H; i++) {
        if (hits[i].prim == UINT32_MAX) continue;
        tu_query_from_hit(&q0[n], &hits[i], i % W, i / W);
        uint64_t fm[16];
        int nf = ms_front_mask(&ctx, &q0[n], NULL, fm);
        cut += nf > 0 && nf < ctx.samples;
        n++;
    }
    printf("two lifts: %d visible points, %d with the light cut by their plane\n", n, cut);
    assert_true(cut > n / 10);
    float *v0 = malloc(sizeof(float) * n), *v1 = malloc(sizeof(float) * n), *s0 = malloc(sizeof(float) * n),
          *s1 = malloc(sizeof(float) * n);
    for (size_t m = 0; methods[m]; m++)
    for (int li = 0; li < 2; li++) {
        /* Penumbra casting is left out here: it answers these points through a receiver hierarchy built per
         * call, the slowest part of this test under ASan, and test_hpc holds both of its variants to
         * raytrace's V and S sample for sample on every frame; raytrace, the definition, and the other
         * methods run. */
        if (strncmp(methods[m], "hpc", 3) == 0) continue;
        const float lift = lifts[li];
        for (int i = 0; i < n; i++) {
            q1[i] = q0[i];
            for (int a = 0; a < 3; a++) q1[i].p[a] = q0[i].p[a] + lift * q0[i].n[a];
        }
        const ms_shadow_method *sm = ms_find_shadow_method(methods[m]);
        if (!sm) continue;
        void *state = NULL;
        assert_int_equal(sm->create(&ctx, &state, err, sizeof err), 0);
        uint64_t cnt[MS_MAX_COUNTERS] = { 0 };
        assert_int_equal(tu_shadow_vs(sm, state, &ctx, q0, n, v0, s0, cnt), 0);
        assert_int_equal(tu_shadow_vs(sm, state, &ctx, q1, n, v1, s1, cnt), 0);
        int differ = 0;
        double worst_v = 0.0, worst_s = 0.0;
        for (int i = 0; i < n; i++) {
            double d = fabs((double)v0[i] - v1[i]);
            differ += d > 0.0;
            worst_v = fmax(worst_v, d);
            worst_s = fmax(worst_s, fabs((double)s0[i] - s1[i]));
        }
        printf("  %-12s lift %.1e: V differs at %d of %d points, max |dV| %.5f, max |dS| %.5f\n", methods[m],
               (double)lift, differ, n, worst_v, worst_s);
        /* Only samples whose segment passes within `lift` of the horizon or of a neighbouring triangle may
         * flip. At rounding's scale that is a tie now and then; at the old lift it is real geometry (segments
         * skimming a concave neighbour), a few samples at some points, where the old definition (samples
         * behind the plane drawn, blocked or not by the neighbours depending on the lift) moved V by up
         * to 0.7 on a scanned dragon. */
        if (li == 0) {
            assert_true(differ * 200 <= n);
            assert_true(worst_v <= 3.0 / 1024 + 1e-6);
        } else {
            assert_true(worst_v < 0.03);
        }
        assert_true(worst_s < 0.03);
        sm->destroy(state);
    }
    /* The old definition on the same points, for contrast: every sample drawn (front mask all ones), P
     * unlifted vs lifted by 1e-5 of the scene's size. This is what the test above guards against. */
    {
        for (int i = 0; i < n; i++) {
            q1[i] = q0[i];
            for (int a = 0; a < 3; a++) q1[i].p[a] = q0[i].p[a] + lifts[1] * q0[i].n[a];
        }
        uint64_t ones[16], va[16], vb[16], cnt[MS_MAX_COUNTERS] = { 0 };
        float pts[3 * 1024];
        memset(ones, 0xFF, sizeof ones);
        double worst = 0.0;
        int differ = 0;
        for (int i = 0; i < n; i++) {
            int a = ms_raytrace_visible_samples(&ctx, &q0[i], pts, ones, va, cnt);
            int b = ms_raytrace_visible_samples(&ctx, &q1[i], pts, ones, vb, cnt);
            differ += a != b;
            worst = fmax(worst, abs(a - b) / 1024.0);
        }
        printf("  old definition (all samples, lift 0 vs %.1e): V differs at %d of %d points, max |dV| %.3f\n",
               (double)lifts[1], differ, n, worst);
        assert_true(worst > 0.05);   /* the test above would have caught it */
    }
    free(v0); free(v1); free(s0); free(s1);
    free(hits); free(q0); free(q1);
    ms_bvh_free(&bvh);
    ms_scene_free(&sc);
}

/* Seen from below, a ceiling with the light above it: the light is behind every receiver's plane. */
static void test_ceiling_from_below(void **st)
{
    (void)st;
    ms_scene sc;
    memset(&sc, 0, sizeof sc);
    const float tri[2][9] = { { -5, 3, -5, 5, 3, 5, 5, 3, -5 }, { -5, 3, -5, -5, 3, 5, 5, 3, 5 } };
    sc.tri = malloc(sizeof tri);
    memcpy(sc.tri, tri, sizeof tri);
    sc.n_tris = 2;
    sc.camera = (ms_camera){ { 0, 0, 0 }, { 0, 3, 0.5f }, { 0, 0, 1 }, 60.0f, 32, 32, MS_CAMERA_PINHOLE, 0, 0 };
    sc.light = (ms_light){ { -1, 5, -1 }, { 2, 0, 0 }, { 0, 0, 2 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };   /* above, emitting down */
    sc.samples = 256;
    for (size_t m = 0; methods[m]; m++) {
        if (ms_method_available(methods[m]) != 1) continue;
        ms_render_options o;
        tu_render_options_default(&o);
        o.method = methods[m];
        ms_frame f;
        char err[256];
        assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
        int hit = 0;
        for (int i = 0; i < 32 * 32; i++) {
            if (f.vis[i] < 0.0f) continue;
            hit++;
            assert_int_equal(f.front[i], 0);
            assert_true(f.vis[i] == 0.0f && f.shadow[i] == 0.0f && f.rgb[3 * i] == 0.0f);
        }
        assert_true(hit == 32 * 32);
        ms_frame_free(&f);
    }
    ms_scene_free(&sc);
}

/* Irradiance (per unit radiance) at p with normal (0, 1, 0) from an axis-aligned rectangle in the plane
 * y = h above it: Lambert's polygon formula in double. */
static double rect_irradiance(double px, double pz, double h, double x0, double x1, double z0, double z1)
{
    if (!(x1 > x0 && z1 > z0)) return 0.0;
    const double c[4][3] = { { x0 - px, h, z0 - pz }, { x1 - px, h, z0 - pz }, { x1 - px, h, z1 - pz }, { x0 - px, h, z1 - pz } };
    double sum = 0.0;
    for (int i = 0; i < 4; i++) {
        const double *a = c[i], *b = c[(i + 1) % 4];
        double la = sqrt(d_dot(a, a)), lb = sqrt(d_dot(b, b)), g[3];
        d_cross(g, a, b);
        double gl = sqrt(d_dot(g, g));
        double theta = atan2(gl, d_dot(a, b));
        sum += theta * g[1] / gl;
        (void)la; (void)lb;
    }
    return 0.5 * fabs(sum);
}

static void test_quad_shaded(void **st)
{
    (void)st;
    /* The Quad of ../shared/scenes/quad: 20 x 20 ground at y = 0, 4 x 4 occluder at y = 2, 2 x 2 light at y = 6. */
    static const float tri[4][9] = {
        { -10, 0, -10, 10, 0, 10, 10, 0, -10 }, { -10, 0, -10, -10, 0, 10, 10, 0, 10 },
        { -2, 2, -2, 2, 2, 2, 2, 2, -2 }, { -2, 2, -2, -2, 2, 2, 2, 2, 2 } };
    ms_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.tri = malloc(sizeof tri);
    memcpy(sc.tri, tri, sizeof tri);
    sc.n_tris = 4;
    const int W = 128;
    sc.camera = (ms_camera){ { 0, 10, 12 }, { 0, 0, 0 }, { 0, 1, 0 }, 60.0f, W, W, MS_CAMERA_PINHOLE, 0, 0 };
    sc.light = (ms_light){ { -1, 6, -1 }, { 2, 0, 0 }, { 0, 0, 2 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    sc.samples = 1024;
    const char *const shaded_methods[] = { "scanline", "raytrace" };
    for (int m = 0; m < 2; m++) {
        ms_render_options o;
        tu_render_options_default(&o);
        o.method = shaded_methods[m];
        ms_frame f;
        char err[256];
        assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
        double eye[3] = { 0, 10, 12 }, fw[3] = { 0, -10, -12 }, len = sqrt(244.0);
        for (int a = 0; a < 3; a++) fw[a] /= len;
        double right[3] = { -fw[2], 0, fw[0] }, rl = sqrt(fw[2] * fw[2] + fw[0] * fw[0]);
        right[0] /= rl; right[2] /= rl;
        double up[3];
        d_cross(up, right, fw);
        double th = tan(30.0 * M_PI / 180.0), rel_s = 0.0, rel_v = 0.0;
        int n = 0, pen = 0;
        for (int y = 0; y < W; y++)
            for (int x = 0; x < W; x++) {
                double sx = (2.0 * (x + 0.5) / W - 1.0) * th, sy = (1.0 - 2.0 * (y + 0.5) / W) * th, d[3];
                for (int a = 0; a < 3; a++) d[a] = fw[a] + sx * right[a] + sy * up[a];
                double t2 = (2.0 - eye[1]) / d[1];
                if (fabs(eye[0] + t2 * d[0]) <= 2.01 && fabs(eye[2] + t2 * d[2]) <= 2.01) continue;   /* occluder */
                double t0 = -eye[1] / d[1], gx = eye[0] + t0 * d[0], gz = eye[2] + t0 * d[2];
                if (fabs(gx) > 9.9 || fabs(gz) > 9.9) continue;
                /* the occluder projected from the ground point onto the light's plane: scale 6/2 about it */
                double sc3 = 6.0 / 2.0;
                double ox0 = gx + sc3 * (-2.0 - gx), ox1 = gx + sc3 * (2.0 - gx);
                double oz0 = gz + sc3 * (-2.0 - gz), oz1 = gz + sc3 * (2.0 - gz);
                double e_light = rect_irradiance(gx, gz, 6.0, -1, 1, -1, 1);
                double e_hidden = rect_irradiance(gx, gz, 6.0, fmax(-1.0, ox0), fmin(1.0, ox1), fmax(-1.0, oz0), fmin(1.0, oz1));
                double e_exact = e_light - e_hidden;
                if (e_exact <= 1e-3 * e_light) continue;   /* umbra */
                const double albedo_pi = 0.8 / M_PI;
                double got_s = f.rgb[3 * (y * W + x)] / albedo_pi;
                double got_v = got_s / f.shadow[y * W + x] * f.vis[y * W + x];
                rel_s += fabs(got_s - e_exact) / e_exact;
                rel_v += fabs(got_v - e_exact) / e_exact;
                pen += e_hidden > 0.0;
                n++;
            }
        printf("quad shaded (%s): %d lit and penumbra pixels (%d penumbra): mean relative error of E*S %.4f%%, "
               "of E*V %.4f%%\n", shaded_methods[m], n, pen, 100.0 * rel_s / n, 100.0 * rel_v / n);
        assert_true(n > W * W / 3);
        assert_true(pen > 500);
        assert_true(rel_s / n < 0.005);
        ms_frame_free(&f);
    }
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plane_cuts_light),
        cmocka_unit_test(test_two_lifts),
        cmocka_unit_test(test_ceiling_from_below),
        cmocka_unit_test(test_quad_shaded),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
