/* The points API (ms_accel_build, ms_visibility_points) against independent answers:
 *   - frames: the hit points of a frame, given as points with their pixel as pattern key and their
 *     triangle, get bit for bit the V, S and front count ms_render gives those pixels, for every method
 *     whose primary is the BVH's and both patterns (embree against raytrace on the same points, within
 *     its documented tie tolerance);
 *   - a brute-force double-precision count at random points in the air with random normals (no
 *     triangle), for every method;
 *   - the caller's order and the thread count do not change any result; concurrent calls on one accel
 *     give the sequential answers; a light passed per call equals the scene's light changed;
 *   - progress reaches 1 and cancellation stops the call; bad input gets MS_ERR_* and a message. */
#include "testutil.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "light/pattern.h"
#include "render/budget.h"
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Every shadow method of the registry (ms_method_names: those compiled into this build), so that a new
 * method is tested without touching this file. */
#define methods (ms_method_names())

/* Frame hits of the default scene at W x H by the BVH primary, as points with key and triangle. */
typedef struct frame_points {
    int W, H;
    size_t n;
    float *pos, *nor;
    uint32_t *tri, *key;
    int *pixel;          /* pixel index of point i */
} frame_points;

static void frame_points_make(frame_points *fp, const ms_scene *sc, int W, int H)
{
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc->tri, sc->n_tris, 0), 0);
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, sc, &bvh, W, H, 16);
    const ms_primary_method *pb = ms_find_primary_method("bvh");
    void *ps = NULL;
    char err[256];
    assert_int_equal(pb->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit *h = malloc(sizeof *h * W * H);
    assert_non_null(h);
    pb->trace(ps, &ctx, 0, 0, W, H, h);
    pb->destroy(ps);
    fp->W = W;
    fp->H = H;
    fp->pos = malloc(sizeof(float) * 3 * W * H);
    fp->nor = malloc(sizeof(float) * 3 * W * H);
    fp->tri = malloc(sizeof(uint32_t) * W * H);
    fp->key = malloc(sizeof(uint32_t) * 2 * W * H);
    fp->pixel = malloc(sizeof(int) * W * H);
    assert_true(fp->pos && fp->nor && fp->tri && fp->key && fp->pixel);
    fp->n = 0;
    for (int i = 0; i < W * H; i++) {
        if (h[i].prim == UINT32_MAX) continue;
        memcpy(fp->pos + 3 * fp->n, h[i].p, sizeof h[i].p);
        memcpy(fp->nor + 3 * fp->n, h[i].n, sizeof h[i].n);
        fp->tri[fp->n] = bvh.tri_source[h[i].prim];   /* the scene's numbering */
        fp->key[2 * fp->n] = (uint32_t)(i % W);
        fp->key[2 * fp->n + 1] = (uint32_t)(i / W);
        fp->pixel[fp->n] = i;
        fp->n++;
    }
    free(h);
    ms_bvh_free(&bvh);
}

static void frame_points_free(frame_points *fp)
{
    free(fp->pos);
    free(fp->nor);
    free(fp->tri);
    free(fp->key);
    free(fp->pixel);
}

static ms_points as_points(const frame_points *fp)
{
    ms_points p = { fp->n, fp->pos, fp->nor, fp->tri, fp->key };
    return p;
}

static void points_options(ms_points_options *o, const char *method, ms_pattern pattern, int samples)
{
    memset(o, 0, sizeof *o);
    o->method = method;
    o->pattern = pattern;
    o->samples = samples;
    o->isa = tu_isa_cap();
}

static void test_frame_agreement(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    const int W = 64, H = 48;
    frame_points fp;
    frame_points_make(&fp, &sc, W, H);
    assert_true(fp.n > (size_t)(W * H / 2));
    ms_accel *acc = NULL;
    char err[512] = "";
    assert_int_equal(ms_accel_build(&sc, 0, &acc, err, sizeof err), MS_OK);
    assert_int_equal(ms_accel_triangles(acc), sc.n_tris);
    ms_points pts = as_points(&fp);
    float *v = malloc(sizeof(float) * fp.n), *s = malloc(sizeof(float) * fp.n);
    uint16_t *f = malloc(sizeof(uint16_t) * fp.n);
    assert_true(v && s && f);
    for (int pat = 0; pat < 2; pat++)
        for (size_t m = 0; methods[m]; m++) {
            const ms_shadow_method *sm = ms_find_shadow_method(methods[m]);
            if (!sm || strcmp(sm->primary, "bvh") != 0) continue;
            if (pat == MS_PATTERN_STRATIFIED && sm->needs_grid) continue;
            ms_render_options ro;
            tu_render_options_default(&ro);
            ro.method = methods[m];
            ro.pattern = (ms_pattern)pat;
            ro.samples = 256;
            ro.width = W;
            ro.height = H;
            ro.seed = 7;
            ms_frame fr;
            assert_int_equal(ms_render(&sc, &ro, &fr, err, sizeof err), 0);
            ms_points_options po;
            points_options(&po, methods[m], (ms_pattern)pat, 256);
            po.seed = 7;
            ms_stats stats;
            assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, s, f, &stats, err, sizeof err), MS_OK);
            long differ = 0, visible = 0;
            for (int i = 0; i < W * H; i++) visible += fr.vis[i] >= 0.0f;
            for (size_t i = 0; i < fp.n; i++) {
                const int p = fp.pixel[i];
                differ += v[i] != fr.vis[p] || s[i] != fr.shadow[p] || f[i] != fr.front[p];
            }
            printf("%s %s: %zu points, %ld differ from the frame's pixels\n", methods[m],
                   pat ? "stratified" : "grid", fp.n, differ);
            assert_int_equal(visible, (long)fp.n);
            assert_int_equal(differ, 0);
            assert_string_equal(stats.method, methods[m]);
            assert_int_equal(stats.visible_pixels, fp.n);
            assert_int_equal(stats.shadow_rays, fr.stats.shadow_rays);
            /* The same occluders as the frame's: the closed-component cull where frames take it by default
             * (the methods that take the queries a batch at a time; the frame-level ones, hpc, go without). */
            if (!sm->visibility_all) assert_int_equal(stats.occluders_culled, fr.stats.occluders_culled);
            else assert_int_equal(stats.occluders_culled, 0);
            ms_frame_free(&fr);
        }
    free(v);
    free(s);
    free(f);
    ms_accel_free(acc);
    frame_points_free(&fp);
    ms_scene_free(&sc);
}

#ifdef MS_HAVE_EMBREE
/* embree on the same points as raytrace: at most one sample apart (a tie), and rarely (test_embree). */
static void test_embree_points(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    frame_points fp;
    frame_points_make(&fp, &sc, 64, 48);
    ms_accel *acc = NULL;
    char err[512] = "";
    assert_int_equal(ms_accel_build(&sc, 0, &acc, err, sizeof err), MS_OK);
    ms_points pts = as_points(&fp);
    float *va = malloc(sizeof(float) * fp.n), *vb = malloc(sizeof(float) * fp.n);
    assert_true(va && vb);
    /* with their triangles, and on no triangle (the Embree filter then has nothing to exclude) */
    for (int bare = 0; bare < 2; bare++) {
        if (bare) pts.triangle = NULL;
        ms_points_options po;
        points_options(&po, "raytrace", MS_PATTERN_GRID, 256);
        assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, va, NULL, NULL, NULL, err, sizeof err), MS_OK);
        po.method = "embree";
        assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, vb, NULL, NULL, NULL, err, sizeof err), MS_OK);
        long differ = 0, beyond = 0;
        for (size_t i = 0; i < fp.n; i++) {
            double steps = fabs((double)va[i] - (double)vb[i]) * 256.0;
            differ += steps > 0.0;
            beyond += steps > 1.0 + 1e-3;
        }
        printf("embree vs raytrace on %zu points%s: %ld differ, %ld beyond 1/N\n", fp.n,
               bare ? " (no triangles given)" : "", differ, beyond);
        assert_int_equal(beyond, 0);
        assert_true(differ * 1000 <= (long)fp.n);
    }
    free(va);
    free(vb);
    ms_accel_free(acc);
    frame_points_free(&fp);
    ms_scene_free(&sc);
}
#endif

/* ---- brute force in double precision ---- */

#define TIE 1e-6

static void d_sub(double r[3], const double a[3], const double b[3]) { for (int i = 0; i < 3; i++) r[i] = a[i] - b[i]; }
static double d_dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void d_cross(double r[3], const double a[3], const double b[3])
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}

/* Segment p + u (l - p), u in [near, far], against a triangle: 1 hit, 0 miss, -1 within TIE of a
 * decision (an edge, a vertex, the ends of the range). */
static int seg_tri(const double p[3], const double l[3], const float *t)
{
    double a[3], b[3], c[3], d[3], e1[3], e2[3], pv[3], s[3], qv[3];
    for (int i = 0; i < 3; i++) { a[i] = t[i]; b[i] = t[3 + i]; c[i] = t[6 + i]; }
    d_sub(d, l, p);
    d_sub(e1, b, a);
    d_sub(e2, c, a);
    d_cross(pv, d, e2);
    const double det = d_dot(e1, pv);
    if (det == 0.0) return 0;
    d_sub(s, p, a);
    const double u = d_dot(s, pv) / det;
    d_cross(qv, s, e1);
    const double v = d_dot(d, qv) / det, w = 1.0 - u - v, tt = d_dot(e2, qv) / det;
    const double lo = fmin(fmin(u, v), w), tlo = fmin(tt - 1e-4, 1.0 - 1e-4 - tt);
    if (lo > TIE && tlo > TIE) return 1;
    if (lo < -TIE || tlo < -TIE) return 0;
    return -1;
}

/* Front and visible counts of point (p, n) over pixel key's samples; ties: samples within rounding. */
static void brute(const ms_scene *sc, const float p_[3], const float n_[3], uint32_t kx, uint32_t ky, int k,
                  uint32_t seed, int *front, int *visible, int *ties)
{
    float *pts = malloc(sizeof(float) * 3 * k * k);
    assert_non_null(pts);
    ms_pattern_points(MS_PATTERN_GRID, &sc->light, k, kx, ky, seed, pts);
    const double p[3] = { p_[0], p_[1], p_[2] };
    double n[3] = { n_[0], n_[1], n_[2] };
    const double nl = sqrt(d_dot(n, n));
    for (int i = 0; i < 3; i++) n[i] /= nl;
    *front = *visible = *ties = 0;
    for (int s = 0; s < k * k; s++) {
        const double l[3] = { pts[3 * s], pts[3 * s + 1], pts[3 * s + 2] };
        double d[3];
        d_sub(d, l, p);
        const double a = d_dot(d, n);
        if (fabs(a) <= TIE * sqrt(d_dot(d, d))) { (*ties)++; continue; }
        if (a < 0.0) continue;
        int state = 1;
        for (size_t t = 0; t < sc->n_tris && state != 0; t++) {
            const int h = seg_tri(p, l, sc->tri + 9 * t);
            if (h == 1) state = 0;
            else if (h == -1) state = -1;
        }
        if (state == -1) { (*ties)++; continue; }
        (*front)++;
        *visible += state;
    }
    free(pts);
}

static void test_points_in_the_air(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    enum { N = 120 };
    float pos[3 * N], nor[3 * N];
    tu_rng rng = { 99 };
    /* the scene's box, from its triangles */
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (size_t i = 0; i < 3 * sc.n_tris; i++)
        for (int c = 0; c < 3; c++) {
            lo[c] = fminf(lo[c], sc.tri[3 * i + c]);
            hi[c] = fmaxf(hi[c], sc.tri[3 * i + c]);
        }
    for (int i = 0; i < N; i++)
        for (int c = 0; c < 3; c++) {
            const float u = (float)(tu_rng_next(&rng) % 100000) / 100000.0f;
            /* the lower third, among the occluders, where penumbrae are */
            pos[3 * i + c] = lo[c] + u * (hi[c] - lo[c]) * (c == 1 ? 0.33f : 1.0f);
            nor[3 * i + c] = (float)(tu_rng_next(&rng) % 2001) / 1000.0f - 1.0f;
        }
    for (int i = 0; i < N; i++) nor[3 * i + 1] += 0.5f;   /* mostly up, never zero */
    ms_accel *acc = NULL;
    char err[512] = "";
    assert_int_equal(ms_accel_build(&sc, 1, &acc, err, sizeof err), MS_OK);
    ms_points pts = { N, pos, nor, NULL, NULL };
    int of[N], ov[N], ot[N];
    long partial = 0;
    for (int i = 0; i < N; i++) {
        brute(&sc, pos + 3 * i, nor + 3 * i, (uint32_t)i, 0, 16, 3, &of[i], &ov[i], &ot[i]);
        partial += ov[i] > 0 && ov[i] < of[i];
    }
    printf("%d points in the air: %ld partly lit\n", N, partial);
    assert_true(partial >= 3);
    for (size_t m = 0; methods[m]; m++) {
        if (ms_method_available(methods[m]) != 1) continue;
        ms_points_options po;
        points_options(&po, methods[m], MS_PATTERN_GRID, 256);
        po.seed = 3;
        float v[N];
        uint16_t f[N];
        assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, f, NULL, err, sizeof err), MS_OK);
        long off = 0;
        for (int i = 0; i < N; i++) {
            const int vis = (int)lround((double)v[i] * f[i]);
            const int df = abs(f[i] - of[i]), dv = abs(vis - ov[i]);
            if (df > ot[i] || dv > ot[i]) {
                off++;
                printf("  %s point %d: front %d visible %d, brute force %d %d (ties %d)\n", methods[m], i, f[i], vis,
                       of[i], ov[i], ot[i]);
            }
        }
        assert_int_equal(off, 0);
    }
    ms_accel_free(acc);
    ms_scene_free(&sc);
}

/* Order, threads, concurrency, per-call light. */
static void test_invariance(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    frame_points fp;
    frame_points_make(&fp, &sc, 48, 32);
    const size_t n = fp.n;
    ms_accel *acc = NULL;
    char err[512] = "";
    assert_int_equal(ms_accel_build(&sc, 0, &acc, err, sizeof err), MS_OK);
    ms_points pts = as_points(&fp);
    float *v0 = malloc(sizeof(float) * n), *s0 = malloc(sizeof(float) * n);
    float *v1 = malloc(sizeof(float) * n), *s1 = malloc(sizeof(float) * n);
    assert_true(v0 && s0 && v1 && s1);
    ms_points_options po;
    points_options(&po, "scanline", MS_PATTERN_GRID, 256);
    po.threads = 1;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v0, s0, NULL, NULL, err, sizeof err), MS_OK);
    po.threads = 2;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v1, s1, NULL, NULL, err, sizeof err), MS_OK);
    assert_memory_equal(v0, v1, sizeof(float) * n);
    assert_memory_equal(s0, s1, sizeof(float) * n);

    /* reversed order: the same answer per point (keys and triangles travel with the points) */
    frame_points rv = fp;
    rv.pos = malloc(sizeof(float) * 3 * n);
    rv.nor = malloc(sizeof(float) * 3 * n);
    rv.tri = malloc(sizeof(uint32_t) * n);
    rv.key = malloc(sizeof(uint32_t) * 2 * n);
    assert_true(rv.pos && rv.nor && rv.tri && rv.key);
    for (size_t i = 0; i < n; i++) {
        const size_t j = n - 1 - i;
        memcpy(rv.pos + 3 * i, fp.pos + 3 * j, sizeof(float) * 3);
        memcpy(rv.nor + 3 * i, fp.nor + 3 * j, sizeof(float) * 3);
        rv.tri[i] = fp.tri[j];
        memcpy(rv.key + 2 * i, fp.key + 2 * j, sizeof(uint32_t) * 2);
    }
    ms_points rpts = as_points(&rv);
    assert_int_equal(ms_visibility_points(acc, NULL, &rpts, &po, v1, s1, NULL, NULL, err, sizeof err), MS_OK);
    for (size_t i = 0; i < n; i++) {
        assert_true(v1[i] == v0[n - 1 - i]);
        assert_true(s1[i] == s0[n - 1 - i]);
    }

    /* two calls at once on one new accel, one thread each: both want its culled occluder set, one builds it */
    float *va = malloc(sizeof(float) * n), *vb = malloc(sizeof(float) * n);
    assert_true(va && vb);
    int rc[2] = { -1, -1 };
    po.threads = 1;
    ms_accel *fresh = NULL;
    assert_int_equal(ms_accel_build(&sc, 0, &fresh, err, sizeof err), MS_OK);
#pragma omp parallel num_threads(2)
    {
        char e2[256];
        const int t = omp_get_thread_num();
        rc[t] = ms_visibility_points(fresh, NULL, &pts, &po, t ? vb : va, NULL, NULL, NULL, e2, sizeof e2);
    }
    ms_accel_free(fresh);
    assert_int_equal(rc[0], MS_OK);
    assert_int_equal(rc[1], MS_OK);
    assert_memory_equal(va, v0, sizeof(float) * n);
    assert_memory_equal(vb, v0, sizeof(float) * n);

    /* a light per call equals a scene with that light */
    ms_light moved = sc.light;
    moved.corner.x += 0.7f;
    moved.edge_s.x *= 0.5f;
    assert_int_equal(ms_visibility_points(acc, &moved, &pts, &po, va, NULL, NULL, NULL, err, sizeof err), MS_OK);
    ms_scene sc2 = sc;
    sc2.light = moved;
    ms_accel *acc2 = NULL;
    assert_int_equal(ms_accel_build(&sc2, 0, &acc2, err, sizeof err), MS_OK);
    assert_int_equal(ms_visibility_points(acc2, NULL, &pts, &po, vb, NULL, NULL, NULL, err, sizeof err), MS_OK);
    assert_memory_equal(va, vb, sizeof(float) * n);
    assert_memory_not_equal(va, v0, sizeof(float) * n);
    ms_accel_free(acc2);

    free(va);
    free(vb);
    free(rv.pos);
    free(rv.nor);
    free(rv.tri);
    free(rv.key);
    free(v0);
    free(s0);
    free(v1);
    free(s1);
    ms_accel_free(acc);
    frame_points_free(&fp);
    ms_scene_free(&sc);
}

typedef struct progress_log { int calls; double last; int cancel_at; int backwards; } progress_log;

static int on_progress(void *user, double f)
{
    progress_log *p = user;
    p->backwards |= f < p->last;
    p->last = f;
    return ++p->calls >= p->cancel_at;
}

/* The closed-component cull's occluder set is the accel's to keep, and optional: under a budget that holds the
 * call but not the set, the call goes without it and gives the same V, S and front; with room, the set is
 * built (the frame's count of culled triangles) and kept for the next call. */
static void test_cull_within_budget(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    frame_points fp;
    frame_points_make(&fp, &sc, 48, 48);
    ms_points pts = as_points(&fp);
    char err[512] = "";
    float *v[2], *s[2];
    uint16_t *f[2];
    uint64_t culled[2];
    for (int tight = 0; tight < 2; tight++) {
        ms_accel *acc = NULL;
        assert_int_equal(ms_accel_build(&sc, 1, &acc, err, sizeof err), MS_OK);
        ms_points_options po;
        points_options(&po, "scanline", MS_PATTERN_GRID, 256);
        po.threads = 1;
        const uint64_t call = ms_points_need(fp.n, sc.n_tris, 0, 4, 1, NULL);
        po.max_memory = tight ? call + ms_culled_sets_need(sc.n_tris, 0, 1) - 1 : 0;
        v[tight] = malloc(sizeof(float) * fp.n);
        s[tight] = malloc(sizeof(float) * fp.n);
        f[tight] = malloc(sizeof(uint16_t) * fp.n);
        assert_true(v[tight] && s[tight] && f[tight]);
        ms_stats stats;
        assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v[tight], s[tight], f[tight], &stats, err, sizeof err),
                         MS_OK);
        culled[tight] = stats.occluders_culled;
        if (!tight) {   /* kept: the second call finds it */
            assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v[0], s[0], f[0], &stats, err, sizeof err), MS_OK);
            assert_int_equal(stats.occluders_culled, culled[0]);
        }
        ms_accel_free(acc);
    }
    printf("cull: %llu triangles culled with room, %llu under the tight budget\n", (unsigned long long)culled[0],
           (unsigned long long)culled[1]);
    assert_true(culled[0] > 0);
    assert_int_equal(culled[1], 0);
    assert_memory_equal(v[0], v[1], sizeof(float) * fp.n);
    assert_memory_equal(s[0], s[1], sizeof(float) * fp.n);
    assert_memory_equal(f[0], f[1], sizeof(uint16_t) * fp.n);
    for (int i = 0; i < 2; i++) { free(v[i]); free(s[i]); free(f[i]); }
    frame_points_free(&fp);
    ms_scene_free(&sc);
}

/* A ball of 1280 triangles (closed: it gets interior boxes) over a ground, written as OBJ files and loaded. */
static void ball_scene(ms_scene *sc)
{
    const char *dir = tu_tmpdir("test_points_ball");
    char path[512];
    double *v;
    int *t;
    size_t nv, nt;
    tu_unit_icosphere(3, &v, &nv, &t, &nt);
    FILE *f = fopen(tu_path(path, sizeof path, dir, "ball.obj"), "w");
    assert_non_null(f);
    for (size_t i = 0; i < nv; i++) fprintf(f, "v %.9g %.9g %.9g\n", 0.6 * v[3 * i], 1.0 + 0.6 * v[3 * i + 1], 0.6 * v[3 * i + 2]);
    for (size_t i = 0; i < nt; i++) fprintf(f, "f %d %d %d\n", t[3 * i] + 1, t[3 * i + 1] + 1, t[3 * i + 2] + 1);
    fclose(f);
    free(v);
    free(t);
    assert_int_equal(tu_write_file(tu_path(path, sizeof path, dir, "ground.obj"),
                                   "v -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\nf 1 3 2\nf 1 4 3\n"), 0);
    tu_load_scene_text(dir,
                       "{\"meshes\":[{\"file\":\"ball.obj\"},{\"file\":\"ground.obj\"}],"
                       "\"camera\":{\"eye\":[2.5,3.5,2.5],\"target\":[0,0.6,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":48,\"height\":48},"
                       "\"light\":{\"corner\":[-1.2,3.2,-0.4],\"edge_s\":[0.8,0,0],\"edge_t\":[0,0,0.8]}}",
                       sc);
}

/* mft leaves the interior boxes to the driver (MS_OCC_INTERIOR_PASS): the points API runs them first as frames
 * do, with the frame's V, S and front on its hit points bit for bit, and as many traversals. */
static void test_interior_pass(void **st)
{
    (void)st;
    ms_scene sc;
    ball_scene(&sc);
    const int W = 48, H = 48;
    frame_points fp;
    frame_points_make(&fp, &sc, W, H);
    ms_accel *acc = NULL;
    char err[512] = "";
    assert_int_equal(ms_accel_build(&sc, 0, &acc, err, sizeof err), MS_OK);
    ms_points pts = as_points(&fp);
    float *v = malloc(sizeof(float) * fp.n), *s = malloc(sizeof(float) * fp.n);
    uint16_t *f = malloc(sizeof(uint16_t) * fp.n);
    assert_true(v && s && f);
    ms_render_options ro;
    tu_render_options_default(&ro);
    ro.method = "mft";
    ro.samples = 256;
    ro.width = W;
    ro.height = H;
    ms_frame fr;
    assert_int_equal(ms_render(&sc, &ro, &fr, err, sizeof err), MS_OK);
    ms_points_options po;
    points_options(&po, "mft", MS_PATTERN_GRID, 256);
    ms_stats stats;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, s, f, &stats, err, sizeof err), MS_OK);
    long differ = 0, shadowed = 0;
    for (size_t i = 0; i < fp.n; i++) {
        const int p = fp.pixel[i];
        differ += v[i] != fr.vis[p] || s[i] != fr.shadow[p] || f[i] != fr.front[p];
        shadowed += v[i] < 1.0f;
    }
    printf("mft on the ball: %zu points, %ld shadowed, %ld differ from the frame; interior boxes %llu (frame %llu)\n",
           fp.n, shadowed, differ, (unsigned long long)stats.interior_boxes, (unsigned long long)fr.stats.interior_boxes);
    /* The pass shows in the traversals: each block walks the boxes, then (unless they left it nothing) the
     * triangles, as in the frame, whose blocks differ only in how the receivers are grouped; without the pass
     * the points would walk about half as many. */
    const uint64_t blocks = tu_stat_counter(&stats, "blocks"), frame_blocks = tu_stat_counter(&fr.stats, "blocks");
    printf("block traversals: points %llu, frame %llu\n", (unsigned long long)blocks, (unsigned long long)frame_blocks);
    assert_true(blocks * 10 >= frame_blocks * 8);
    assert_true(shadowed > 100);
    assert_int_equal(differ, 0);
    /* The accel finds its boxes once for every method, on the silhouette grid; mft's frame on its own, coarser one
     * (occluders.h, ms_interior_res): more boxes here, the same V. */
    assert_true(fr.stats.interior_boxes > 0);
    assert_true(stats.interior_boxes >= fr.stats.interior_boxes);
    ms_frame_free(&fr);
    free(v);
    free(s);
    free(f);
    ms_accel_free(acc);
    frame_points_free(&fp);
    ms_scene_free(&sc);
}

static void test_progress_cancel(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    frame_points fp;
    frame_points_make(&fp, &sc, 64, 64);
    ms_accel *acc = NULL;
    char err[512] = "";
    assert_int_equal(ms_accel_build(&sc, 0, &acc, err, sizeof err), MS_OK);
    ms_points pts = as_points(&fp);
    float *v = malloc(sizeof(float) * fp.n);
    assert_non_null(v);
    ms_points_options po;
    points_options(&po, "scanline", MS_PATTERN_GRID, 256);
    progress_log log = { 0, 0.0, 1 << 30, 0 };
    po.progress = on_progress;
    po.progress_user = &log;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_OK);
    assert_int_equal(log.calls, (int)((fp.n + 255) / 256));
    assert_true(log.last == 1.0);
    assert_false(log.backwards);
    progress_log stop = { 0, 0.0, 1, 0 };
    po.progress_user = &stop;
    po.threads = 1;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_ERR_CANCELLED);
    assert_int_equal(stop.calls, 1);   /* one thread: nothing runs after the answer */
    assert_non_null(strstr(err, "cancelled"));
    free(v);
    ms_accel_free(acc);
    frame_points_free(&fp);
    ms_scene_free(&sc);
}

static void test_bad_input(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_accel *acc = NULL;
    char err[512] = "";
    assert_int_equal(ms_accel_build(NULL, 0, &acc, err, sizeof err), MS_ERR_INVALID);
    assert_null(acc);
    assert_int_equal(ms_accel_build(&sc, 0, &acc, err, sizeof err), MS_OK);
    float pos[6] = { 0, 1, 0, 0, 1, 0 }, nor[6] = { 0, 1, 0, 0, 1, 0 };
    uint32_t tri[2] = { 0, 0 };
    ms_points pts = { 2, pos, nor, tri, NULL };
    float v[2];
    ms_points_options po;
    points_options(&po, "scanline", MS_PATTERN_GRID, 256);
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_OK);
    pos[4] = NAN;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "point 1: position"));
    pos[4] = 1.0f;
    nor[3] = nor[4] = nor[5] = 0.0f;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "point 1: normal"));
    nor[4] = 1.0f;
    tri[1] = (uint32_t)sc.n_tris;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_ERR_INVALID);
    assert_non_null(strstr(err, "point 1: triangle"));
    tri[1] = MS_NO_TRIANGLE;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_OK);
    po.method = "nonesuch";
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_ERR_METHOD);
    assert_non_null(strstr(err, "unknown method 'nonesuch'"));
    po.method = "scanline";
    po.pattern = MS_PATTERN_STRATIFIED;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_ERR_INVALID);
    po.pattern = MS_PATTERN_GRID;
    po.samples = 100;
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_ERR_INVALID);
    po.samples = 256;
    ms_light bad = sc.light;
    bad.edge_t = bad.edge_s;   /* zero area */
    assert_int_equal(ms_visibility_points(acc, &bad, &pts, &po, v, NULL, NULL, NULL, err, sizeof err), MS_ERR_INVALID);
    /* no points: fine, nothing written */
    ms_points none = { 0, NULL, NULL, NULL, NULL };
    assert_int_equal(ms_visibility_points(acc, NULL, &none, &po, NULL, NULL, NULL, NULL, err, sizeof err), MS_OK);
    /* zeroed options: the defaults (scanline, 1024 samples) */
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, NULL, v, NULL, NULL, NULL, err, sizeof err), MS_OK);
    assert_string_equal(ms_status_name(MS_ERR_CANCELLED), "cancelled");
    ms_accel_free(acc);
    ms_accel_free(NULL);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frame_agreement),
#ifdef MS_HAVE_EMBREE
        cmocka_unit_test(test_embree_points),
#endif
        cmocka_unit_test(test_points_in_the_air),
        cmocka_unit_test(test_invariance),
        cmocka_unit_test(test_cull_within_budget),
        cmocka_unit_test(test_interior_pass),
        cmocka_unit_test(test_progress_cancel),
        cmocka_unit_test(test_bad_input),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
