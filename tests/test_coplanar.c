/* Merged coplanar rectangles (src/accel/coplanar.c) for the micro-raster methods' occluders.
 *
 * The merge against an oracle written here: random points of each plane are covered by the merged
 * triangles exactly when they are covered by the input ones (point in triangle in double, points kept off
 * the edges), strips of segments become one rectangle, rectangles of one pair and triangles that are not
 * rectangle halves pass through unchanged. Frames of segmented bars over a tiled ground: scanline and hpc
 * (the tiled and the frame-level paths) with the merge, without it, and raytrace agree within the tie
 * tolerance of the other method tests (at most a sample on a few pixels; hpc without the merge bit for bit),
 * receivers on merged faces seen at grazing angles included (answered on the scene's own triangles,
 * counted; which of them need it, per sample, against the crossing worked out in the test). */
#include "testutil.h"
#include "accel/coplanar.h"
#include "accel/ray_triangle.h"
#include "accel/bvh.h"
#include "light/light_frame.h"
#include "visibility/receiver.h"
#include "render/exact_split.h"
#include "visibility/occluders.h"
#include "visibility/context.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct soup { float *t; size_t n, cap; } soup;

static void add(soup *s, const float a[3], const float b[3], const float c[3])
{
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 64;
        s->t = realloc(s->t, s->cap * 9 * sizeof(float));
        assert_non_null(s->t);
    }
    float *t = s->t + 9 * s->n++;
    memcpy(t, a, 3 * sizeof(float));
    memcpy(t + 3, b, 3 * sizeof(float));
    memcpy(t + 6, c, 3 * sizeof(float));
}

/* A box [lo, hi] whose faces along x are cut into `seg` strips (two triangles each); the end caps whole. */
static void bar(soup *s, const float lo[3], const float hi[3], int seg)
{
    for (int k = 0; k < seg; k++) {
        const float x0 = lo[0] + (hi[0] - lo[0]) * (float)k / (float)seg;
        const float x1 = k + 1 == seg ? hi[0] : lo[0] + (hi[0] - lo[0]) * (float)(k + 1) / (float)seg;
        const float y[4] = { lo[1], hi[1], hi[1], lo[1] }, z[4] = { lo[2], lo[2], hi[2], hi[2] };
        for (int f = 0; f < 4; f++) {
            const int g = (f + 1) % 4;
            const float a[3] = { x0, y[f], z[f] }, b[3] = { x1, y[f], z[f] }, c[3] = { x1, y[g], z[g] }, d[3] = { x0, y[g], z[g] };
            add(s, a, b, c);
            add(s, a, c, d);
        }
    }
    for (int e = 0; e < 2; e++) {
        const float x = e ? hi[0] : lo[0];
        const float a[3] = { x, lo[1], lo[2] }, b[3] = { x, hi[1], lo[2] }, c[3] = { x, hi[1], hi[2] }, d[3] = { x, lo[1], hi[2] };
        add(s, a, b, c);
        add(s, a, c, d);
    }
}

/* A ground y = 0 over [-w, w]^2 in n x n tiles (two triangles each, diagonals alternating). */
static void ground(soup *s, float w, int n)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            const float x0 = -w + 2 * w * (float)i / (float)n, x1 = -w + 2 * w * (float)(i + 1) / (float)n;
            const float z0 = -w + 2 * w * (float)j / (float)n, z1 = -w + 2 * w * (float)(j + 1) / (float)n;
            const float a[3] = { x0, 0, z0 }, b[3] = { x1, 0, z0 }, c[3] = { x1, 0, z1 }, d[3] = { x0, 0, z1 };
            if ((i + j) & 1) { add(s, a, b, c); add(s, a, c, d); }
            else { add(s, a, b, d); add(s, b, c, d); }
        }
}

static double urand(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (double)(*s >> 8) / 16777216.0;
}

/* Is (u, v) inside triangle t projected on the plane x_a = c (in double); *edge when within 1e-9 of a side. */
static int in_tri(const float *t, int a, double u, double v, int *edge)
{
    const int au = (a + 1) % 3, av = (a + 2) % 3;
    double s[3];
    for (int k = 0; k < 3; k++) {
        const float *p = t + 3 * k, *q = t + 3 * ((k + 1) % 3);
        s[k] = ((double)q[au] - p[au]) * (v - p[av]) - ((double)q[av] - p[av]) * (u - p[au]);
    }
    const double m = fmax(fabs(s[0]), fmax(fabs(s[1]), fabs(s[2])));
    for (int k = 0; k < 3; k++)
        if (fabs(s[k]) <= 1e-9 * (m + 1.0)) *edge = 1;
    return (s[0] >= 0 && s[1] >= 0 && s[2] >= 0) || (s[0] <= 0 && s[1] <= 0 && s[2] <= 0);
}

static int covered(const float *tri, size_t n, int a, float c, double u, double v, int *edge)
{
    int in = 0;
    for (size_t i = 0; i < n; i++) {
        const float *t = tri + 9 * i;
        if (t[a] != c || t[3 + a] != c || t[6 + a] != c) continue;
        in |= in_tri(t, a, u, v, edge);
    }
    return in;
}

static void test_merge(void **st)
{
    (void)st;
    soup s = { 0 };
    const float lo[3] = { -3, 1, -0.2f }, hi[3] = { 3, 1.1f, -0.1f };
    bar(&s, lo, hi, 32);                 /* 4 x 64 strip triangles + 4 cap triangles */
    ground(&s, 4, 6);                    /* 72 tile triangles: rows of rectangles */
    const float a[3] = { 0, 2, 0 }, b[3] = { 1, 2.5f, 0 }, c[3] = { 0, 2, 1 };
    add(&s, a, b, c);                    /* not axis-aligned: passes through */
    const size_t n = s.n;
    float *out;
    size_t no;
    uint32_t *of, *src;
    uint8_t *merged;
    unsigned axes;
    assert_int_equal(ms_coplanar_merge(s.t, n, NULL, -1, &out, &no, &of, &src, &merged, &axes), 0);
    /* the bar's four faces: one rectangle each (2 triangles); the caps are single pairs (unchanged); the
     * ground one rectangle; the tilted triangle */
    assert_int_equal(no, 4 * 2 + 4 + 2 + 1);
    for (size_t i = 0; i < 4 * 64; i++) assert_int_equal(merged[i], 1);
    for (size_t i = 256; i < 260; i++) assert_int_equal(merged[i], 0);
    assert_int_equal(merged[n - 1], 0);
    assert_memory_equal(out + 9 * of[n - 1], s.t + 9 * (n - 1), 9 * sizeof(float));
    for (size_t i = 256; i < 260; i++) assert_memory_equal(out + 9 * of[i], s.t + 9 * i, 9 * sizeof(float));
    for (size_t i = 0; i < n; i++) assert_true(of[i] < no);
    for (size_t o = 0; o < no; o++) assert_true(src[o] < n);
    /* the same points covered, plane by plane */
    unsigned seed = 3;
    struct { int a; float c; double u0, u1, v0, v1; } planes[] = {
        { 1, 1.0f, -0.3, 0.0, -3.5, 3.5 }, { 1, 1.1f, -0.3, 0.0, -3.5, 3.5 }, { 2, -0.2f, -3.5, 3.5, 0.9, 1.2 },
        { 2, -0.1f, -3.5, 3.5, 0.9, 1.2 }, { 0, -3.0f, 0.9, 1.2, -0.3, 0.0 }, { 1, 0.0f, -4.5, 4.5, -4.5, 4.5 } };
    int tested = 0, inside = 0;
    for (size_t p = 0; p < sizeof planes / sizeof *planes; p++)
        for (int k = 0; k < 4000; k++) {
            const double u = planes[p].u0 + (planes[p].u1 - planes[p].u0) * urand(&seed);
            const double v = planes[p].v0 + (planes[p].v1 - planes[p].v0) * urand(&seed);
            int edge = 0;
            const int want = covered(s.t, n, planes[p].a, planes[p].c, u, v, &edge);
            const int got = covered(out, no, planes[p].a, planes[p].c, u, v, &edge);
            if (edge) continue;
            tested++;
            inside += want;
            assert_int_equal(got, want);
        }
    assert_true(tested > 20000 && inside > 5000);
    free(out); free(of); free(src); free(merged);
    /* eligible: nothing merged where nothing may be */
    uint8_t *none = calloc(n, 1);
    assert_int_equal(ms_coplanar_merge(s.t, n, none, -1, &out, &no, &of, &src, &merged, &axes), 0);
    assert_int_equal(no, n);
    assert_memory_equal(out, s.t, n * 9 * sizeof(float));
    free(none); free(out); free(of); free(src); free(merged);
    free(s.t);
}

static float *vis_of(const ms_scene *sc, const char *method, int no_merge, ms_stats *stats)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.no_merge = no_merge;
    o.threads = 2;
    return tu_render_vis(sc, &o, stats);
}

/* Pixels where a and b differ, and the largest difference in samples (of 1024). */
static int differ(const float *a, const float *b, int np, double *max_samples)
{
    int d = 0;
    *max_samples = 0;
    for (int i = 0; i < np; i++)
        if (a[i] != b[i]) {
            d++;
            *max_samples = fmax(*max_samples, fabs((double)a[i] - b[i]) * 1024.0);
        }
    return d;
}

static void test_merged_frames(void **st)
{
    (void)st;
    soup s = { 0 };
    ground(&s, 4, 8);
    for (int i = 0; i < 6; i++) {
        const float lo[3] = { -3, 1.0f + 0.3f * (float)(i & 1), -1.6f + 0.55f * (float)i };
        const float hi[3] = { 3, lo[1] + 0.08f, lo[2] + 0.08f };
        bar(&s, lo, hi, 24);
    }
    ms_scene sc;
    tu_make_quad(&sc);
    free(sc.tri);
    sc.tri = s.t;
    sc.n_tris = s.n;
    sc.camera.width = sc.camera.height = 64;
    /* low over the bars: their side faces are receivers, some seen at grazing angles from the light */
    sc.camera.eye = (ms_vec3){ 3.5f, 2.2f, 4.5f };
    sc.camera.target = (ms_vec3){ 0, 0.8f, 0 };
    sc.light = (ms_light){ { -1.5f, 4, -1.5f }, { 3, 0, 0 }, { 0, 0, 3 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    const int np = 64 * 64;
    ms_stats sr;
    float *vr = vis_of(&sc, "raytrace", 0, &sr);
    assert_int_equal(sr.occluders_merged, 0);
    int shadowed = 0;
    for (int i = 0; i < np; i++) shadowed += vr[i] >= 0 && vr[i] < 1;
    assert_true(shadowed > np / 10);
    /* scanline through the micro-raster path's tiles, mft through them with the exact split, hpc through the
     * frame-level entry (shadow_frame.c) */
    static const char *const methods[] = { "scanline", "mft", "hpc" };
    for (int mi = 0; mi < 3; mi++) {
        ms_stats sm, sn;
        float *vm = vis_of(&sc, methods[mi], 0, &sm), *vn = vis_of(&sc, methods[mi], 1, &sn);
        assert_true(sm.occluders_merged > 0);
        assert_true(sm.receivers_on_merged > 0);
        assert_int_equal(sn.occluders_merged, 0);
        assert_int_equal(sn.receivers_on_merged, 0);
        double dm, dn;
        const int pm = differ(vm, vr, np, &dm), pn = differ(vn, vr, np, &dn);
        print_message("%s merged: %d pixels off raytrace (max %.1f samples); unmerged: %d (max %.1f); %llu receivers on "
                      "merged faces\n", methods[mi], pm, dm, pn, dn, (unsigned long long)sm.receivers_on_merged);
        /* the tie tolerance of the method tests: at most a sample, on under 1% of the pixels */
        assert_true(dm <= 1.0 && pm <= np / 100);
        assert_true(dn <= 1.0 && pn <= np / 100);
        /* mft's and hpc's per-sample test is raytrace's (docs/hpc.md): on the scene's own triangles bit for bit,
         * and on the merged ones too, each sample on a set exact for its shear axis (render/exact_split.c) */
        if (strcmp(methods[mi], "scanline")) {
            assert_int_equal(pn, 0);
            assert_int_equal(pm, 0);
        }
        free(vm);
        free(vn);
    }
    free(vr);
    ms_scene_free(&sc);
}

/* 1 when the segment o -> o + d meets one of the n triangles tri (9 floats each) under the watertight test with
 * shear axis kz (ms_wt_segment_sheared, the shear sx = d[kx] / d[kz] as the methods form it). */
static int meets(const float *tri, size_t n, const float o[3], const float d[3], int kz)
{
    const int kx = kz + 1 == 3 ? 0 : kz + 1, ky = kx + 1 == 3 ? 0 : kx + 1;
    const float inv = 1.0f / d[kz], sx = d[kx] * inv, sy = d[ky] * inv;
    for (size_t t = 0; t < n; t++) {
        const float *v = tri + 9 * t;
        float A[3], B[3], C[3], N[3];
        for (int a = 0; a < 3; a++) { A[a] = v[a] - o[a]; B[a] = v[3 + a] - o[a]; C[a] = v[6 + a] - o[a]; }
        ms_wt_normal(v, N);
        if (ms_wt_segment_sheared(A, B, C, kz, sx, sy, d, N, ms_wt_offset(o, v, N), 1e-4f, 1.0f)) return 1;
    }
    return 0;
}

/* The claim coplanar.h rests the exact split on: a strip of pieces along x in the plane y = c, merged into one
 * rectangle, is decided by the watertight test exactly as its pieces for every segment sheared along y (the
 * plane's axis) or z (the axis it was not merged along), and only along x may the merged side, a chord of the
 * pieces' rounded polyline, decide otherwise. Segments from random origins to points within ulps of the strip's
 * long sides (where the two could differ) and its cross seams, each tested with all three axes that keep the
 * shear bounded. */
static void test_merged_axes_exact(void **st)
{
    (void)st;
    soup s = { 0 };
    const float c = 1.37f, z0 = -0.213f, z1 = 0.171f;
    float x[18];
    for (int i = 0; i < 18; i++) x[i] = -2.9f + 0.3413f * (float)i + 0.0007f * (float)(i * i % 5);
    for (int i = 0; i < 17; i++) {
        const float a[3] = { x[i], c, z0 }, b[3] = { x[i + 1], c, z0 }, e[3] = { x[i + 1], c, z1 }, f[3] = { x[i], c, z1 };
        add(&s, a, b, e);
        add(&s, a, e, f);
    }
    float *out;
    size_t no;
    uint32_t *of, *src;
    uint8_t *merged;
    unsigned axes;
    assert_int_equal(ms_coplanar_merge(s.t, s.n, NULL, -1, &out, &no, &of, &src, &merged, &axes), 0);
    assert_int_equal(no, 2);
    assert_int_equal(axes, 1u);   /* merged along x only */
    unsigned rng = 7;
    long tested[3] = { 0 }, differ_axis[3] = { 0 };
    for (int r = 0; r < 400000; r++) {
        /* an origin below, off to a side, far enough in x that x may be the segment's largest axis */
        const float o[3] = { (float)(urand(&rng) * 16.0 - 8.0), c - 0.2f - (float)(urand(&rng) * 2.0),
                             (float)(urand(&rng) * 3.0 - 1.5) };
        /* a target on a long side, a hair off it, or on a cross seam */
        const int kind = (int)(urand(&rng) * 3.0);
        float tx = (float)(urand(&rng) * 5.6 - 2.8), tz = kind == 0 ? z0 : kind == 1 ? z1 : (float)(urand(&rng) * 0.38 - 0.21);
        if (kind == 2) tx = x[1 + (int)(urand(&rng) * 15.0)];
        else tz = nextafterf(tz, (urand(&rng) < 0.5 ? -1.0f : 1.0f) * 10.0f);
        const float e = (float)(urand(&rng) * 1e-6);
        const float tgt[3] = { tx + e, c, tz - e };
        float d[3];
        for (int a = 0; a < 3; a++) d[a] = 2.0f * (tgt[a] - o[a]);   /* the plane at half the segment */
        const float m = fmaxf(fabsf(d[0]), fmaxf(fabsf(d[1]), fabsf(d[2])));
        for (int kz = 0; kz < 3; kz++) {
            if (!(2.0f * fabsf(d[kz]) >= m)) continue;   /* the packet rule's bound on the shear */
            tested[kz]++;
            differ_axis[kz] += meets(s.t, s.n, o, d, kz) != meets(out, no, o, d, kz);
        }
    }
    print_message("segments decided otherwise by the merged strip: %ld of %ld sheared along x, %ld of %ld along y, "
                  "%ld of %ld along z\n", differ_axis[0], tested[0], differ_axis[1], tested[1], differ_axis[2], tested[2]);
    assert_true(tested[0] > 10000 && tested[1] > 10000 && tested[2] > 10000);
    assert_int_equal(differ_axis[1], 0);
    assert_int_equal(differ_axis[2], 0);
    assert_true(differ_axis[0] > 0);   /* the ties exist, and this test finds them */
    free(out); free(of); free(src); free(merged);
    free(s.t);
}

/* ms_receiver_axes, which proves most receivers' and packets' shear axes from the light's hull, against the rule
 * itself on every sample point (ms_pattern_points, ms_segment_axes): receivers all around a level and a tilted
 * light, near and far, on the grid and the stratified pattern, 256 and 1024 samples. */
static void test_receiver_axes(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 1), 0);
    static const ms_light lights[2] = {
        { { -1.5f, 4, -1.5f }, { 3, 0, 0 }, { 0, 0, 3 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 },
        { { -1.0f, 3, -0.5f }, { 2.2f, 1.3f, 0.4f }, { -0.3f, 0.9f, 2.1f }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 },
    };
    unsigned rng = 11;
    long receivers = 0, mixed = 0;
    for (int li = 0; li < 2; li++)
        for (int k = 16; k <= 32; k += 16)
            for (int pat = 0; pat < 2; pat++) {
                ms_render_ctx ctx;
                tu_ctx_init(&ctx, &sc, &bvh, 64, 64, k);
                if (pat) tu_ctx_set_pattern(&ctx, MS_PATTERN_STRATIFIED);
                ctx.light = lights[li];
                const int mw = ctx.mask_words, pref = ms_light_shear_axis(&ctx.light);
                float hull[8][3], box[6], *pts = malloc((size_t)ctx.samples * 3 * sizeof *pts);
                uint64_t fast[3 * 16], brute[3 * 16];
                assert_non_null(pts);
                const int n_hull = ms_light_hull(&ctx.light, hull, box);
                for (int r = 0; r < 3000; r++) {
                    ms_shadow_query q = { 0 };
                    const double reach = r % 3 == 0 ? 2.0 : r % 3 == 1 ? 8.0 : 30.0;
                    for (int a = 0; a < 3; a++) q.p[a] = (float)((urand(&rng) * 2.0 - 1.0) * reach);
                    q.px = (uint32_t)(urand(&rng) * 4096.0);
                    q.py = (uint32_t)(urand(&rng) * 4096.0);
                    ms_receiver_axes(&ctx, &q, (const float (*)[3])hull, n_hull, pref, pts, fast);
                    ms_pattern_points(ctx.pattern, &ctx.light, ctx.k, q.px, q.py, ctx.seed, pts);
                    memset(brute, 0, sizeof brute);
                    ms_segment_axes(q.p, pts, 0, ctx.samples, pref, mw, brute);
                    int used = 0;
                    for (int a = 0; a < 3; a++) {
                        uint64_t any = 0;
                        for (int w = 0; w < mw; w++) {
                            const uint64_t valid = ctx.samples - 64 * w >= 64 ? ~UINT64_C(0) : (UINT64_C(1) << (ctx.samples - 64 * w)) - 1;
                            assert_true((fast[a * mw + w] & valid) == brute[a * mw + w]);
                            any |= brute[a * mw + w];
                        }
                        used += any != 0;
                    }
                    receivers++;
                    mixed += used > 1;
                }
                free(pts);
            }
    print_message("ms_receiver_axes equals the rule on all %ld receivers, %ld of them with segments on more than one "
                  "axis\n", receivers, mixed);
    assert_true(mixed > receivers / 20);
    ms_bvh_free(&bvh);
    ms_scene_free(&sc);
}

/* ms_merged_receiver_ok_samples against the segment-plane crossing worked out here: a receiver a little behind
 * the face x = 1 (d = 1e-6) with samples in front, the crossing parameter d / (d + e) for a sample e in front of
 * the plane. A sample whose crossing lies at or beyond half the near range refuses the receiver, unless front
 * leaves it out; samples on the receiver's side never cross; a face off the axes is never merged. */
static void test_receiver_ok_samples(void **st)
{
    (void)st;
    const float tri[9] = { 1, 0, 0, 1, 1, 0, 1, 0, 1 };
    const float p[3] = { 1.0f - 1e-6f, 0.5f, 0.2f };
    const double d = 1.0 - (double)p[0];
    float pts[4 * 3] = { 3, 1, 1, 2, 0, 1, 0.5f, 2, 2, 0.25f, 0, 0 };   /* two far in front, two on p's side */
    uint64_t front = 15;
    assert_int_equal(ms_merged_receiver_ok_samples(tri, p, pts, &front, 4), 1);
    /* a sample in front so close to the plane that the segment meets it beyond half the near range */
    const double e_cross = d * (1.0 / (0.5 * (double)MS_SEGMENT_NEAR) - 1.0);   /* crossing at exactly near / 2 */
    pts[0] = (float)(1.0 + 0.5 * e_cross);
    assert_true(d / (d + ((double)pts[0] - 1.0)) > 0.5 * (double)MS_SEGMENT_NEAR);
    assert_int_equal(ms_merged_receiver_ok_samples(tri, p, pts, &front, 4), 0);
    front = 14;   /* that sample behind the receiver: it does not count */
    assert_int_equal(ms_merged_receiver_ok_samples(tri, p, pts, &front, 4), 1);
    front = 15;
    pts[0] = (float)(1.0 + 4.0 * e_cross);   /* far enough: the crossing below near / 4 */
    assert_true(d / (d + ((double)pts[0] - 1.0)) < 0.25 * (double)MS_SEGMENT_NEAR);
    assert_int_equal(ms_merged_receiver_ok_samples(tri, p, pts, &front, 4), 1);
    pts[3] = 1.0f;   /* a sample on the plane itself: the segment ends in it */
    assert_int_equal(ms_merged_receiver_ok_samples(tri, p, pts, &front, 4), 0);
    const float slanted[9] = { 1, 0, 0, 1.5f, 1, 0, 1, 0, 1 };
    assert_int_equal(ms_merged_receiver_ok_samples(slanted, p, pts, &front, 4), 1);
}

/* ms_coplanar_rect_pair (hpc's rectangle pairs): the halves of an axis-aligned rectangle, in any vertex order and
 * either diagonal, give its four corners in order around it, the first triangle's vertices being corners 0, 1, 2
 * and the second's 0, 2, 3 (checked as sets, bitwise); a pair that is not such a rectangle is refused. */
static int has_vertex(const float *t, const float *c)
{
    for (int k = 0; k < 3; k++)
        if (t[3 * k] == c[0] && t[3 * k + 1] == c[1] && t[3 * k + 2] == c[2]) return 1;
    return 0;
}

static void test_rect_pair(void **st)
{
    (void)st;
    /* the rectangle x = 0.5, y in [-1, 2], z in [0.25, 3], corners in order around it */
    const float R[4][3] = { { 0.5f, -1, 0.25f }, { 0.5f, 2, 0.25f }, { 0.5f, 2, 3 }, { 0.5f, -1, 3 } };
    for (int diag = 0; diag < 2; diag++)
        for (int rot = 0; rot < 3; rot++)
            for (int flip = 0; flip < 2; flip++) {
                /* halves along the diagonal R[diag] R[diag + 2]: (d, d+1, d+2) and (d, d+2, d+3), rotated and wound */
                const int ia[3] = { diag, diag + 1, diag + 2 }, ib[3] = { diag, diag + 2, (diag + 3) % 4 };
                float a[9], b[9], c[12];
                for (int k = 0; k < 3; k++) {
                    const int ka = flip ? 2 - (k + rot) % 3 : (k + rot) % 3, kb = (k + rot) % 3;
                    memcpy(a + 3 * k, R[ia[ka]], sizeof R[0]);
                    memcpy(b + 3 * k, R[ib[kb]], sizeof R[0]);
                }
                assert_int_equal(ms_coplanar_rect_pair(a, b, c), 1);
                for (int k = 0; k < 3; k++) {
                    assert_true(has_vertex(a, c + 3 * k));
                    assert_true(has_vertex(b, c + 3 * (k ? k + 1 : 0)));
                }
                assert_false(has_vertex(a, c + 9));
                /* in order around the rectangle: consecutive corners differ in one coordinate */
                for (int k = 0; k < 4; k++) {
                    int same = 0;
                    for (int x = 0; x < 3; x++) same += c[3 * k + x] == c[3 * ((k + 1) % 4) + x];
                    assert_int_equal(same, 2);
                }
            }
    /* refused: the same triangle twice, a half and a triangle off the plane, a non-rectangle quad */
    float a[9], b[9], c[12];
    for (int k = 0; k < 3; k++) { memcpy(a + 3 * k, R[k], sizeof R[0]); memcpy(b + 3 * k, R[k], sizeof R[0]); }
    assert_int_equal(ms_coplanar_rect_pair(a, b, c), 0);
    memcpy(b, R[0], sizeof R[0]);
    memcpy(b + 3, R[2], sizeof R[0]);
    memcpy(b + 6, R[3], sizeof R[0]);
    assert_int_equal(ms_coplanar_rect_pair(a, b, c), 1);
    b[6] = 0.5000001f;   /* off the plane by one ulp */
    assert_int_equal(ms_coplanar_rect_pair(a, b, c), 0);
    b[6] = 0.5f;
    b[8] = 2.9999998f;   /* not a rectangle by one ulp */
    assert_int_equal(ms_coplanar_rect_pair(a, b, c), 0);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_merge),
        cmocka_unit_test(test_merged_frames),
        cmocka_unit_test(test_merged_axes_exact),
        cmocka_unit_test(test_receiver_axes),
        cmocka_unit_test(test_receiver_ok_samples),
        cmocka_unit_test(test_rect_pair),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
