/* Issue 33: scenes far from the origin. Each scene is generated at the origin, then written as OBJ and scene
 * JSON moved by (d, d/2, -d), d = 0, 1e4, 1e5, 1e6, every coordinate with full digits (%.17g of the double
 * sum), and loaded through ms_scene_load, which puts it into its local frame (src/scene/scene_frame.c):
 *
 *  - test_frame: the origin is 0 at d = 0 and exactly (d, d/2, -d) further out; the local triangles, camera and
 *    light are those of d = 0 within a float's rounding (the detail is kept: nothing rounded at 1e6's spacing);
 *  - test_methods_far: every method of ms_method_names() at every offset gives its own d = 0 frame (the tie
 *    tolerance of the method comparisons elsewhere: no pixel hit or missed differently, no pixel off by more
 *    than one sample, at most 1% of pixels off by one) and raytrace's frame at that offset alike, and its
 *    counters (node visits, triangle tests, ...) stay within 1.5x of d = 0;
 *  - test_points_far: ms_visibility_points takes world positions: points on the ground given at each offset
 *    (exactly representable there) get the V and S of d = 0;
 *  - test_leak_far, test_cracks_far: the light-leak and primary-crack scenes of test_watertight.c (smaller)
 *    at every offset: every method V == 0 inside the closed pillow, no pixel without a hit inside the
 *    closed icosphere;
 *  - test_localize: a scene built in world floats far out, put into its frame by ms_scene_localize. */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double offsets[] = { 0.0, 1e4, 1e5, 1e6 };
#define N_OFF (int)(sizeof offsets / sizeof offsets[0])

static double rnd(tu_rng *r) { return (double)(tu_rng_next(r) >> 11) * (1.0 / 9007199254740992.0); }
static float rndf(tu_rng *r, float lo, float hi) { return lo + (hi - lo) * (float)rnd(r); }

/* A scene at the origin: shared vertices (floats, as a modeller would have written them), triangles,
 * camera and one rect light. */
typedef struct gen {
    float *v;
    uint32_t *ix;
    size_t nv, nt, cap_v, cap_t;
    float eye[3], target[3], up[3], fov;
    float corner[3], es[3], et[3];
} gen;

static uint32_t vert(gen *g, float x, float y, float z)
{
    if (g->nv == g->cap_v) {
        g->cap_v = g->cap_v ? 2 * g->cap_v : 1024;
        g->v = realloc(g->v, g->cap_v * 3 * sizeof *g->v);
        assert_non_null(g->v);
    }
    g->v[3 * g->nv] = x; g->v[3 * g->nv + 1] = y; g->v[3 * g->nv + 2] = z;
    return (uint32_t)g->nv++;
}

static void tri(gen *g, uint32_t a, uint32_t b, uint32_t c)
{
    if (g->nt == g->cap_t) {
        g->cap_t = g->cap_t ? 2 * g->cap_t : 1024;
        g->ix = realloc(g->ix, g->cap_t * 3 * sizeof *g->ix);
        assert_non_null(g->ix);
    }
    g->ix[3 * g->nt] = a; g->ix[3 * g->nt + 1] = b; g->ix[3 * g->nt + 2] = c;
    g->nt++;
}

static void gen_free(gen *g) { free(g->v); free(g->ix); memset(g, 0, sizeof *g); }

/* A closed "pillow" (as test_watertight.c): two jittered n x n height-field sheets sharing their rim. */
static void pillow(gen *m, tu_rng *g, int n, float h, const float c[3], float ylo, float yhi)
{
    uint32_t *lo = malloc(sizeof(uint32_t) * (n + 1) * (n + 1)), *hi = malloc(sizeof(uint32_t) * (n + 1) * (n + 1));
    assert_non_null(lo);
    assert_non_null(hi);
    const float cell = 2.0f * h / (float)n;
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            const int rim = i == 0 || j == 0 || i == n || j == n;
            const float jx = rim ? 0.0f : rndf(g, -0.35f, 0.35f) * cell, jz = rim ? 0.0f : rndf(g, -0.35f, 0.35f) * cell;
            const float x = c[0] + (-h + cell * (float)i + jx), z = c[2] + (-h + cell * (float)j + jz);
            if (rim) {
                lo[j * (n + 1) + i] = hi[j * (n + 1) + i] = vert(m, x, c[1], z);
            } else {
                lo[j * (n + 1) + i] = vert(m, x, c[1] + ylo + rndf(g, -0.3f, 0.3f) * cell, z);
                const float jx2 = rndf(g, -0.35f, 0.35f) * cell, jz2 = rndf(g, -0.35f, 0.35f) * cell;
                hi[j * (n + 1) + i] = vert(m, x + jx2, c[1] + yhi + rndf(g, -0.3f, 0.3f) * cell, z + jz2);
            }
        }
    for (int s = 0; s < 2; s++) {
        const uint32_t *q = s ? hi : lo;
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                const uint32_t a = q[j * (n + 1) + i], b = q[j * (n + 1) + i + 1], cc = q[(j + 1) * (n + 1) + i + 1],
                               d = q[(j + 1) * (n + 1) + i];
                if (tu_rng_next(g) & 1) { tri(m, a, b, cc); tri(m, a, cc, d); }
                else { tri(m, a, b, d); tri(m, b, cc, d); }
            }
    }
    free(lo);
    free(hi);
}

static void ground(gen *m, float y, float h)
{
    const uint32_t a = vert(m, -h, y, -h), b = vert(m, h, y, -h), c = vert(m, h, y, h), d = vert(m, -h, y, h);
    tri(m, a, b, c);
    tri(m, a, c, d);
}

static void set3(float *o, float x, float y, float z) { o[0] = x; o[1] = y; o[2] = z; }

/* Soft shadows: a ground, a floating jittered pillow, a scatter of small leaves, a light above. */
static void soft_scene(gen *m)
{
    memset(m, 0, sizeof *m);
    tu_rng g = { 33 };
    ground(m, 0.0f, 3.0f);
    const float pc[3] = { 0.2f, 0.9f, -0.1f };
    pillow(m, &g, 20, 0.6f, pc, -0.15f, 0.15f);
    for (int i = 0; i < 300; i++) {
        const float x = rndf(&g, -1.5f, 1.5f), y = rndf(&g, 0.3f, 1.6f), z = rndf(&g, -1.5f, 1.5f), s = rndf(&g, 0.03f, 0.12f);
        const uint32_t a = vert(m, x, y, z), b = vert(m, x + s, y + rndf(&g, -s, s), z), c = vert(m, x, y + rndf(&g, -s, s), z + s);
        tri(m, a, b, c);
    }
    set3(m->eye, 1.9f, 2.6f, 3.1f);
    set3(m->target, 0.0f, 0.3f, 0.0f);
    set3(m->up, 0, 1, 0);
    m->fov = 50.0f;
    set3(m->corner, -0.6f, 2.4f, -0.5f);
    set3(m->es, 0.9f, 0.0f, 0.1f);
    set3(m->et, 0.0f, 0.05f, 0.8f);
}

/* The light inside a closed pillow over a ground, the camera under it looking down (test_watertight.c). */
static void leak_scene(gen *m)
{
    memset(m, 0, sizeof *m);
    tu_rng g = { 7 };
    const float pc[3] = { 0.0f, 2.0f, 0.0f };
    pillow(m, &g, 60, 1.5f, pc, -0.8f, 0.8f);
    ground(m, 0.0f, 3.0f);
    set3(m->eye, 0.05f, 1.0f, -0.03f);
    set3(m->target, 0, 0, 0);
    set3(m->up, 0, 0, 1);
    m->fov = 90.0f;
    set3(m->corner, -0.25f, 2.0f, -0.25f);
    set3(m->es, 0.5f, 0, 0);
    set3(m->et, 0, 0, 0.5f);
}

/* The camera inside a closed, jittered icosphere (test_watertight.c's primary cracks). */
static void crack_scene(gen *m)
{
    memset(m, 0, sizeof *m);
    tu_rng g = { 10 };
    double *p;
    int *t;
    size_t np, nt;
    tu_unit_icosphere(4, &p, &np, &t, &nt);
    const double edge = 4.0 / sqrt((double)nt);
    for (size_t i = 0; i < np; i++) {
        double q[3];
        for (int a = 0; a < 3; a++) q[a] = p[3 * i + a] + 0.3 * edge * (rnd(&g) * 2 - 1);
        vert(m, (float)q[0], (float)q[1], (float)q[2]);
    }
    for (size_t k = 0; k < nt; k++) tri(m, (uint32_t)t[3 * k], (uint32_t)t[3 * k + 1], (uint32_t)t[3 * k + 2]);
    free(p);
    free(t);
    set3(m->eye, 0.13f, -0.21f, 0.07f);
    set3(m->target, 1.0f, 0.3f, 0.2f);
    set3(m->up, 0, 1, 0);
    m->fov = 120.0f;
    set3(m->corner, -0.3f, 0.5f, -0.1f);
    set3(m->es, 0.2f, 0, 0);
    set3(m->et, 0, 0, 0.2f);
}

static void shifted(const double off[3], const float *p, double *o)
{
    for (int a = 0; a < 3; a++) o[a] = (double)p[a] + off[a];
}

/* Writes the scene moved by off as DIR/NAME.obj and DIR/NAME.json, every number with full digits; the
 * JSON's path into json. */
static void write_scene(const gen *m, const char *dir, const char *name, const double off[3], char *json, size_t n)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/%s.obj", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    for (size_t i = 0; i < m->nv; i++) {
        double p[3];
        shifted(off, m->v + 3 * i, p);
        /* Coordinates with more digits than a float holds (the same at every offset), so that the local
         * floats come from rounding, as a surveyed or CAD model's would, not from a float plus d, exactly. */
        tu_rng h = { 1000 + i };
        for (int a = 0; a < 3; a++) p[a] += 1e-8 * (2.0 * rnd(&h) - 1.0);
        fprintf(f, "v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
    }
    for (size_t i = 0; i < m->nt; i++) fprintf(f, "f %u %u %u\n", m->ix[3 * i] + 1, m->ix[3 * i + 1] + 1, m->ix[3 * i + 2] + 1);
    assert_int_equal(fclose(f), 0);
    double eye[3], target[3], corner[3];
    shifted(off, m->eye, eye);
    shifted(off, m->target, target);
    shifted(off, m->corner, corner);
    snprintf(json, n, "%s/%s.json", dir, name);
    f = fopen(json, "w");
    assert_non_null(f);
    fprintf(f, "{\"meshes\":[{\"file\":\"%s.obj\"}],\n"
               " \"camera\":{\"eye\":[%.17g,%.17g,%.17g],\"target\":[%.17g,%.17g,%.17g],\"up\":[%g,%g,%g],\"fov_y\":%g},\n"
               " \"light\":{\"corner\":[%.17g,%.17g,%.17g],\"edge_s\":[%.9g,%.9g,%.9g],\"edge_t\":[%.9g,%.9g,%.9g]}}\n",
            name, eye[0], eye[1], eye[2], target[0], target[1], target[2], (double)m->up[0], (double)m->up[1],
            (double)m->up[2], (double)m->fov, corner[0], corner[1], corner[2], (double)m->es[0], (double)m->es[1],
            (double)m->es[2], (double)m->et[0], (double)m->et[1], (double)m->et[2]);
    assert_int_equal(fclose(f), 0);
}

static void offset_vec(double d, double off[3]) { off[0] = d; off[1] = d / 2; off[2] = -d; }

/* The scene moved by offsets[o], loaded. */
static void load_at(const gen *m, const char *test, const char *name, int o, ms_scene *sc)
{
    char dir[4096], json[4200], sub[64], err[512] = "";
    snprintf(sub, sizeof sub, "%s_%d", name, o);
    snprintf(dir, sizeof dir, "%s", tu_tmpdir(test));
    double off[3];
    offset_vec(offsets[o], off);
    write_scene(m, dir, sub, off, json, sizeof json);
    if (ms_scene_load(json, sc, err, sizeof err)) fail_msg("%s: %s", json, err);
}

static void render(const ms_scene *sc, const char *method, int size, ms_frame *f)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.samples = 256;
    o.width = size;
    o.height = size;
    o.seed = 5;
    o.threads = 2;
    tu_render_ok(sc, &o, f);
}

static int method_size(const char *m) { return !strcmp(m, "raytrace") || !strncmp(m, "hpc", 3) ? 40 : 64; }

/* Within the tie tolerance of the method comparisons (test_cameras.c, test_hpc.c). */
static void assert_agree(const ms_frame *a, const ms_frame *b, const char *what)
{
    const tu_agreement g = tu_compare_frames(a, b);
    print_message("%s: %ld of %ld pixels differ, max |dV| %.2f samples, max |dS| %.2g\n", what, g.differ, g.pixels,
                  g.max_steps, g.max_ds);
    assert_int_equal(g.miss_mismatch, 0);
    assert_int_equal(g.beyond_one, 0);
    assert_int_equal(g.s_beyond, 0);
    assert_true((double)g.differ <= 0.01 * (double)g.pixels);
}

static void test_frame(void **st)
{
    (void)st;
    gen m;
    soft_scene(&m);
    ms_scene s0;
    load_at(&m, "test_far_origin_frame", "soft", 0, &s0);
    assert_true(s0.origin[0] == 0.0 && s0.origin[1] == 0.0 && s0.origin[2] == 0.0);
    for (int o = 1; o < N_OFF; o++) {
        ms_scene s;
        load_at(&m, "test_far_origin_frame", "soft", o, &s);
        double off[3];
        offset_vec(offsets[o], off);
        print_message("d = %g: origin (%.17g, %.17g, %.17g)\n", offsets[o], s.origin[0], s.origin[1], s.origin[2]);
        for (int a = 0; a < 3; a++) assert_true(s.origin[a] == off[a]);
        assert_int_equal(s.n_tris, s0.n_tris);
        /* The detail of d = 0: each coordinate within a float's rounding of it (2^-22 of the scene's size
         * of 3), not the 0.0625 spacing of floats at 1e6. */
        double worst = 0.0;
        for (size_t i = 0; i < 9 * s.n_tris; i++) worst = fmax(worst, fabs((double)s.tri[i] - (double)s0.tri[i]));
        const ms_vec3 *p[4] = { &s.camera.eye, &s.camera.target, &s.light.corner, &s.light.edge_s },
                      *q[4] = { &s0.camera.eye, &s0.camera.target, &s0.light.corner, &s0.light.edge_s };
        for (int k = 0; k < 4; k++)
            worst = fmax(worst, fmax(fabs((double)p[k]->x - q[k]->x), fmax(fabs((double)p[k]->y - q[k]->y), fabs((double)p[k]->z - q[k]->z))));
        print_message("d = %g: largest local coordinate change %.3g\n", offsets[o], worst);
        assert_true(worst <= 3.0 * 0x1p-22);
        ms_scene_free(&s);
    }
    ms_scene_free(&s0);
    gen_free(&m);
}

static void test_methods_far(void **st)
{
    (void)st;
    gen m;
    soft_scene(&m);
    int nm = 0;
    for (const char *const *n = ms_method_names(); *n; n++) nm++;
    ms_frame *f0 = calloc((size_t)nm, sizeof *f0);
    assert_non_null(f0);
    for (int o = 0; o < N_OFF; o++) {
        ms_scene sc;
        load_at(&m, "test_far_origin_methods", "soft", o, &sc);
        ms_frame rt40, rt64;
        render(&sc, "raytrace", 40, &rt40);
        render(&sc, "raytrace", 64, &rt64);
        int i = 0;
        for (const char *const *n = ms_method_names(); *n; n++, i++) {
            const int size = method_size(*n);
            ms_frame f;
            render(&sc, *n, size, &f);
            char what[128];
            snprintf(what, sizeof what, "d = %g, %s vs raytrace", offsets[o], *n);
            assert_agree(&f, size == 40 ? &rt40 : &rt64, what);
            if (o == 0) { f0[i] = f; continue; }
            snprintf(what, sizeof what, "d = %g, %s vs itself at d = 0", offsets[o], *n);
            assert_agree(&f, &f0[i], what);
            /* The traversal's work: far out the bounds are those of the origin (ray_triangle.h). */
            for (int c = 0; c < f.stats.n_counters; c++) {
                const char *cn = f.stats.counter_name[c];
                if (strlen(cn) > 3 && (!strcmp(cn + strlen(cn) - 3, "_us") || !strcmp(cn + strlen(cn) - 3, "_ns"))) continue;   /* times, not work */
                const double a = (double)f.stats.counter[c], b = (double)f0[i].stats.counter[c];
                if (a > 1.5 * b + 64.0)
                    fail_msg("d = %g, %s: counter %s %.0f, %.0f at d = 0 (> 1.5x)", offsets[o], *n, f.stats.counter_name[c], a, b);
            }
            ms_frame_free(&f);
        }
        ms_frame_free(&rt40);
        ms_frame_free(&rt64);
        ms_scene_free(&sc);
    }
    for (int i = 0; i < nm; i++) ms_frame_free(&f0[i]);
    free(f0);
    gen_free(&m);
}

static void test_points_far(void **st)
{
    (void)st;
    gen m;
    soft_scene(&m);
    enum { G = 24 };
    float v0[G * G], s0[G * G];
    for (int o = 0; o < N_OFF; o++) {
        ms_scene sc;
        load_at(&m, "test_far_origin_points", "soft", o, &sc);
        ms_accel *acc = NULL;
        char err[512] = "";
        assert_int_equal(ms_accel_build(&sc, 2, &acc, err, sizeof err), MS_OK);
        double org[3];
        ms_accel_origin(acc, org);
        for (int a = 0; a < 3; a++) assert_true(org[a] == sc.origin[a]);
        double off[3];
        offset_vec(offsets[o], off);
        /* On the ground (y = 0 at the origin), at multiples of 1/8: world floats exact at every offset. */
        float pos[3 * G * G], nor[3 * G * G];
        for (int j = 0; j < G; j++)
            for (int i = 0; i < G; i++) {
                const int k = j * G + i;
                pos[3 * k] = (float)(off[0] + (i - G / 2) * 0.125);
                pos[3 * k + 1] = (float)off[1];
                pos[3 * k + 2] = (float)(off[2] + (j - G / 2) * 0.125);
                nor[3 * k] = 0; nor[3 * k + 1] = 1; nor[3 * k + 2] = 0;
            }
        ms_points pts = { G * G, pos, nor, NULL, NULL };
        for (const char *const *n = ms_method_names(); *n; n++) {
            if (o == 0 && n == ms_method_names()) {   /* the reference first: raytrace at d = 0 */
                ms_points_options po;
                memset(&po, 0, sizeof po);
                po.method = "raytrace";
                po.samples = 256;
                po.threads = 2;
                po.isa = tu_isa_cap();
                if (ms_visibility_points(acc, NULL, &pts, &po, v0, s0, NULL, NULL, err, sizeof err)) fail_msg("%s", err);
            }
            ms_points_options po;
            memset(&po, 0, sizeof po);
            po.method = *n;
            po.samples = 256;
            po.threads = 2;
            po.isa = tu_isa_cap();
            float v[G * G], s[G * G];
            uint16_t fr[G * G];
            if (ms_visibility_points(acc, NULL, &pts, &po, v, s, fr, NULL, err, sizeof err)) fail_msg("%s: %s", *n, err);
            long differ = 0, beyond = 0, umbra = 0, lit = 0;
            for (int k = 0; k < G * G; k++) {
                const double steps = fabs((double)v[k] - v0[k]) * fr[k];
                differ += steps > 1e-3 || fabs((double)s[k] - s0[k]) > 8.0 * (steps + 1e-3) / (fr[k] ? fr[k] : 1);
                beyond += steps > 1.0 + 1e-3;
                umbra += v[k] < 0.5f;
                lit += v[k] > 0.9f;
            }
            print_message("points, d = %g, %s: %ld of %d points differ from raytrace at d = 0; %ld with V < 0.5, %ld with "
                          "V > 0.9\n", offsets[o], *n, differ, G * G, umbra, lit);
            assert_true(umbra > 0 && lit > 0);
            assert_int_equal(beyond, 0);
            assert_true(differ <= G * G / 100);
        }
        ms_accel_free(acc);
        ms_scene_free(&sc);
    }
    gen_free(&m);
}

static void test_leak_far(void **st)
{
    (void)st;
    gen m;
    leak_scene(&m);
    long leaked = 0;
    for (int o = 0; o < N_OFF; o++) {
        ms_scene sc;
        load_at(&m, "test_far_origin_leak", "leak", o, &sc);
        for (const char *const *n = ms_method_names(); *n; n++) {
            const int size = strcmp(*n, "embree") == 0 ? 64 : strcmp(*n, "raytrace") == 0 ? 48 : 32;
            ms_frame f;
            render(&sc, *n, size, &f);
            long k = 0, missed = 0;
            for (int i = 0; i < size * size; i++) {
                if (f.vis[i] < 0.0f) { missed++; continue; }
                k += lroundf(f.vis[i] * 256.0f);
            }
            print_message("leak, d = %g, %s: %ld visible samples, %ld misses\n", offsets[o], *n, k, missed);
            assert_int_equal(missed, 0);
            leaked += k;
            ms_frame_free(&f);
        }
        ms_scene_free(&sc);
    }
    assert_int_equal(leaked, 0);
    gen_free(&m);
}

static void test_cracks_far(void **st)
{
    (void)st;
    gen m;
    crack_scene(&m);
    long total = 0;
    for (int o = 0; o < N_OFF; o++) {
        ms_scene sc;
        load_at(&m, "test_far_origin_cracks", "cracks", o, &sc);
        for (const char *const *n = ms_method_names(); *n; n++) {
            const int size = strcmp(*n, "raytrace") == 0 ? 48 : 96;
            ms_frame f;
            render(&sc, *n, size, &f);
            long miss = 0;
            for (int i = 0; i < size * size; i++) miss += f.vis[i] < 0.0f;
            print_message("cracks, d = %g, %s %dx%d: %ld pixels with V = -1\n", offsets[o], *n, size, size, miss);
            total += miss;
            ms_frame_free(&f);
        }
        ms_scene_free(&sc);
    }
    assert_int_equal(total, 0);
    gen_free(&m);
}

/* A scene built in world floats (the leak scene at (1e5, 5e4, -1e5)): ms_scene_localize moves it into its
 * frame; still watertight in every method, and raytrace's traversal is that of a scene at home. */
static void test_localize(void **st)
{
    (void)st;
    gen m;
    leak_scene(&m);
    const double off[3] = { 1e5, 5e4, -1e5 };
    ms_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.n_tris = m.nt;
    sc.tri = malloc(m.nt * 9 * sizeof *sc.tri);
    assert_non_null(sc.tri);
    for (size_t t = 0; t < m.nt; t++)
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) sc.tri[9 * t + 3 * k + a] = (float)(m.v[3 * m.ix[3 * t + k] + a] + off[a]);
    sc.camera = (ms_camera){ { (float)(m.eye[0] + off[0]), (float)(m.eye[1] + off[1]), (float)(m.eye[2] + off[2]) },
                             { (float)(m.target[0] + off[0]), (float)(m.target[1] + off[1]), (float)(m.target[2] + off[2]) },
                             { 0, 0, 1 }, m.fov, 64, 64, MS_CAMERA_PINHOLE, 0, 0 };
    sc.light = (ms_light){ { (float)(m.corner[0] + off[0]), (float)(m.corner[1] + off[1]), (float)(m.corner[2] + off[2]) },
                           { m.es[0], m.es[1], m.es[2] }, { m.et[0], m.et[1], m.et[2] }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0,
                           { 0, 0, 0 }, 0 };
    sc.samples = 256;
    ms_frame before, after;
    render(&sc, "raytrace", 8, &before);   /* small: in world floats nothing is culled (slow under ASan) */
    assert_int_equal(ms_scene_localize(&sc), 0);
    print_message("localized: origin (%.17g, %.17g, %.17g), eye (%g, %g, %g)\n", sc.origin[0], sc.origin[1], sc.origin[2],
                  (double)sc.camera.eye.x, (double)sc.camera.eye.y, (double)sc.camera.eye.z);
    for (int a = 0; a < 3; a++) assert_true(sc.origin[a] == off[a]);
    const double o0[3] = { sc.origin[0], sc.origin[1], sc.origin[2] };
    assert_int_equal(ms_scene_localize(&sc), 0);   /* already in its frame: nothing moves */
    for (int a = 0; a < 3; a++) assert_true(sc.origin[a] == o0[a]);
    long leaked = 0;
    for (const char *const *n = ms_method_names(); *n; n++) {
        ms_frame f;
        render(&sc, *n, 48, &f);
        for (int i = 0; i < 48 * 48; i++) {
            assert_true(f.vis[i] >= 0.0f);
            leaked += lroundf(f.vis[i] * 256.0f);
        }
        ms_frame_free(&f);
    }
    render(&sc, "raytrace", 8, &after);
    print_message("raytrace %s: %.0f in world floats, %.0f localized\n", after.stats.counter_name[1],
                  (double)before.stats.counter[1], (double)after.stats.counter[1]);
    assert_true(4.0 * (double)after.stats.counter[1] < (double)before.stats.counter[1]);
    ms_frame_free(&after);
    assert_int_equal(leaked, 0);
    ms_frame_free(&before);
    ms_scene_free(&sc);
    gen_free(&m);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frame),
        cmocka_unit_test(test_methods_far),
        cmocka_unit_test(test_points_far),
        cmocka_unit_test(test_leak_far),
        cmocka_unit_test(test_cracks_far),
        cmocka_unit_test(test_localize),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
