/* Light shapes (docs/design.md, "Light shapes"), each against an oracle of its own:
 *   - disk lights: every method's front and visible masks equal a brute-force test of every sample (in
 *     front of the receiver, on the disk by its distance from the centre in world space, occluded by a
 *     double-precision segment test against every triangle), and equal raytrace's bit for bit;
 *   - the unshadowed disk irradiance against numerical integration over the disk;
 *   - sphere lights: the outline disk against the exact tangent cone, the irradiance against numerical
 *     integration, every method against raytrace;
 *   - triangle lights: every method's masks against the brute force, frames against raytrace, the
 *     irradiance against numerical integration.
 * Lights in scene files and frames (many lights, units, bad input, outputs, textures): test_light_files.c. */
#include "testutil.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "light/pattern.h"
#include "visibility/disk_mask.h"
#include "core/cpu.h"
#include "accel/bvh.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- brute force ---- */

typedef enum { NO = 0, YES = 1, UNSURE = 2 } verdict;   /* tu_segment_hits' answers */

/* A disk (centre c, unit normal m, radius r), or a triangle (tri = 1: corner c, edges e1, e2). */
typedef struct disk_geom { double c[3], m[3], r; int tri; double e1[3], e2[3]; } disk_geom;

/* How far L lies off the shape: < 0 on it, > 0 off it. A disk: |L - c|^2 / r^2 - 1; a triangle: s + t - 1
 * for L = c + s e1 + t e2 (least squares in double: L lies on the plane up to float rounding). */
static double off_shape(const disk_geom *dg, const double L[3])
{
    double w[3];
    for (int c = 0; c < 3; c++) w[c] = L[c] - dg->c[c];
    if (!dg->tri) return (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) / (dg->r * dg->r) - 1.0;
    const double *a = dg->e1, *b = dg->e2;
    const double aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2], bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
    const double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const double wa = w[0] * a[0] + w[1] * a[1] + w[2] * a[2], wb = w[0] * b[0] + w[1] * b[1] + w[2] * b[2];
    const double det = aa * bb - ab * ab, s = (wa * bb - wb * ab) / det, t = (wb * aa - wa * ab) / det;
    return s + t - 1.0;
}

/* The expected bits of sample L for the receiver (p, n, prim): counted (front and on the disk) and visible. */
static void brute_sample(const ms_bvh *bvh, uint32_t prim, const float *pf, const float *nf, const float *Lf,
                         const disk_geom *dg, verdict *counted, verdict *visible)
{
    double p[3], L[3], d[3];
    for (int c = 0; c < 3; c++) { p[c] = pf[c]; L[c] = Lf[c]; d[c] = L[c] - p[c]; }
    const double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const double f = (d[0] * nf[0] + d[1] * nf[1] + d[2] * nf[2]) / dl;
    const double off = off_shape(dg, L);
    verdict cnt = f > 1e-5 && off < -1e-4 ? YES : (f < -1e-5 || off > 1e-4) ? NO : UNSURE;
    *counted = cnt;
    if (cnt == NO) { *visible = NO; return; }
    verdict occ = NO;
    for (uint32_t t = 0; t < bvh->n_tris && occ != YES; t++) {
        if (t == prim) continue;
        const verdict v = (verdict)tu_segment_hits(bvh->tri + 9 * (size_t)t, p, L, 1e-4, 1.0 - 1e-4);
        if (v == YES) occ = YES;
        else if (v == UNSURE) occ = UNSURE;
    }
    *visible = cnt == UNSURE || occ == UNSURE ? UNSURE : occ == YES ? NO : YES;
}

/* The Quad (ground, occluder) with a disk light. */
static void make_disk_scene(ms_scene *sc, ms_vec3 c, ms_vec3 m, float r, disk_geom *dg)
{
    tu_make_quad(sc);
    assert_int_equal(ms_light_disk(&sc->light, c, m, r), 0);
    const double ml = sqrt((double)m.x * m.x + (double)m.y * m.y + (double)m.z * m.z);
    *dg = (disk_geom){ .c = { c.x, c.y, c.z }, .m = { m.x / ml, m.y / ml, m.z / ml }, .r = r };
}

/* The Quad (ground, occluder) with a triangle light a, b, c. */
static void make_triangle_scene(ms_scene *sc, ms_vec3 a, ms_vec3 b, ms_vec3 c, disk_geom *dg)
{
    tu_make_quad(sc);
    assert_int_equal(ms_light_triangle(&sc->light, a, b, c), 0);
    *dg = (disk_geom){ .c = { a.x, a.y, a.z }, .tri = 1, .e1 = { (double)b.x - a.x, (double)b.y - a.y, (double)b.z - a.z },
                       .e2 = { (double)c.x - a.x, (double)c.y - a.y, (double)c.z - a.z } };
}

/* Every method's masks on a disk light: equal to the brute force where it is sure, equal to raytrace's
 * everywhere; and some samples of the bounding square really are masked off. */
static void check_disk_methods(ms_scene *sc, const disk_geom *dg, int size, int k, ms_pattern pat)
{
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc->tri, sc->n_tris, 1), 0);
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, sc, &bvh, size, size, k);
    tu_ctx_set_pattern(&ctx, pat);
    ctx.seed = 7;
    char err[256];
    int nq;
    ms_shadow_query *q = tu_frame_queries(&ctx, size, &nq);
    assert_true(nq > 0);
    const size_t mw = (size_t)ctx.mask_words;
    const int spp = ctx.samples;
    uint64_t *front = calloc((size_t)nq * mw, sizeof *front), *ref = calloc((size_t)nq * mw, sizeof *ref);
    uint64_t *vis = calloc((size_t)nq * mw, sizeof *vis);
    float *pts = malloc((size_t)spp * 3 * sizeof *pts);
    assert_true(front && ref && vis && pts);
    for (int i = 0; i < nq; i++)
        ms_front_mask(&ctx, &q[i], pat == MS_PATTERN_GRID ? NULL : (ms_pattern_points(pat, &ctx.light, k, q[i].px, q[i].py,
                                                                                       ctx.seed, pts), pts),
                      front + i * mw);
    /* The brute force, once: counted and visible verdicts per sample. */
    verdict *bc = malloc((size_t)nq * spp * sizeof *bc), *bv = malloc((size_t)nq * spp * sizeof *bv);
    assert_true(bc && bv);
    long sure = 0, total = 0, off_disk = 0, front_bad = 0;
    for (int i = 0; i < nq; i++) {
        ms_pattern_points(pat, &ctx.light, k, q[i].px, q[i].py, ctx.seed, pts);
        for (int s = 0; s < spp; s++) {
            verdict c, v;
            brute_sample(&bvh, q[i].prim, q[i].p, q[i].n, pts + 3 * s, dg, &c, &v);
            bc[(size_t)i * spp + s] = c;
            bv[(size_t)i * spp + s] = v;
            const double L[3] = { pts[3 * s], pts[3 * s + 1], pts[3 * s + 2] };
            off_disk += off_shape(dg, L) > 1e-4;
            if (c != UNSURE && (int)c != ms_mask_get(front + i * mw, s)) front_bad++;
        }
    }
    assert_int_equal(front_bad, 0);
    assert_true(off_disk > (long)nq * spp / 8);   /* the corners of the square (21%), half the parallelogram (50%) */
    /* raytrace first: its masks are the reference for the others */
    const char *const *names = ms_method_names();
    int have_ref = 0;
    for (int pass = 0; pass < 2; pass++)
        for (int mi = 0; names[mi]; mi++) {
            const int is_rt = !strcmp(names[mi], "raytrace");
            if ((pass == 0) != is_rt) continue;
            const ms_shadow_method *sm = ms_find_shadow_method(names[mi]);
            if (sm->needs_grid && pat != MS_PATTERN_GRID) continue;
            void *ss = NULL;
            uint64_t cnt[MS_MAX_COUNTERS] = { 0 };
            assert_int_equal(sm->create(&ctx, &ss, err, sizeof err), 0);
            memset(vis, 0, (size_t)nq * mw * sizeof *vis);
            assert_int_equal(sm->visibility(ss, &ctx, q, nq, front, vis, cnt), 0);
            sm->destroy(ss);
            long bad = 0, differ = 0;
            sure = total = 0;
            for (int i = 0; i < nq; i++)
                for (int s = 0; s < spp; s++) {
                    const verdict v = bv[(size_t)i * spp + s];
                    const int got = ms_mask_get(vis + i * mw, s);
                    total++;
                    if (v != UNSURE) { sure++; bad += got != (int)v; }
                    if (have_ref) differ += got != ms_mask_get(ref + i * mw, s);
                }
            if (bad || differ)
                fprintf(stderr, "%s, %s pattern, method %s: %ld samples differ from the brute force, %ld from raytrace\n",
                        dg->tri ? "triangle" : "disk", ms_pattern_name(pat), names[mi], bad, differ);
            assert_int_equal(bad, 0);
            assert_int_equal(differ, 0);
            if (is_rt) { memcpy(ref, vis, (size_t)nq * mw * sizeof *vis); have_ref = 1; }
        }
    assert_true(have_ref);
    assert_true(sure > total * 99 / 100);   /* the brute force decides nearly every sample */
    free(bc); free(bv); free(front); free(ref); free(vis); free(pts); free(q);
    ms_bvh_free(&bvh);
}

static void test_disk_every_method_grid(void **st)
{
    (void)st;
    ms_scene sc;
    disk_geom dg;
    /* Overhead, tilted: penumbrae of the occluder on the ground. */
    make_disk_scene(&sc, (ms_vec3){ 0.3f, 6, -0.2f }, (ms_vec3){ 0.2f, -1, 0.1f }, 1.4f, &dg);
    check_disk_methods(&sc, &dg, 24, 32, MS_PATTERN_GRID);
    ms_scene_free(&sc);
    /* Low and steep: the disk crosses the ground's plane (horizon and disk masks together), k = 16. */
    make_disk_scene(&sc, (ms_vec3){ 0, 0.6f, 4 }, (ms_vec3){ 0, -0.3f, -1 }, 1.5f, &dg);
    check_disk_methods(&sc, &dg, 24, 16, MS_PATTERN_GRID);
    ms_scene_free(&sc);
}

static void test_disk_ray_tracers_other_patterns(void **st)
{
    (void)st;
    ms_scene sc;
    disk_geom dg;
    make_disk_scene(&sc, (ms_vec3){ 0.3f, 6, -0.2f }, (ms_vec3){ 0.2f, -1, 0.1f }, 1.4f, &dg);
    check_disk_methods(&sc, &dg, 16, 16, MS_PATTERN_STRATIFIED);
    check_disk_methods(&sc, &dg, 16, 32, MS_PATTERN_INTERLEAVED);
    ms_scene_free(&sc);
}

/* Whole frames: every method's V and S on a disk light equal raytrace's exactly (same masks, same
 * resolution), and V is not the parallelogram's. */
static void test_disk_frames_equal(void **st)
{
    (void)st;
    ms_scene sc;
    disk_geom dg;
    make_disk_scene(&sc, (ms_vec3){ 0.3f, 6, -0.2f }, (ms_vec3){ 0.2f, -1, 0.1f }, 1.4f, &dg);
    ms_render_options o;
    tu_render_options_default(&o);
    o.width = o.height = 40;
    o.threads = 2;
    char err[256];
    ms_frame ref, f;
    tu_every_method_as_raytrace(&sc, &o, "disk frame", &ref, NULL, NULL);
    /* The same square as a parallelogram: more samples in front. */
    sc.light.shape = MS_LIGHT_RECT;
    o.method = "raytrace";
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
    long more = 0;
    for (int i = 0; i < 40 * 40; i++) more += f.front[i] > ref.front[i];
    assert_true(more > 40 * 40 / 2);
    ms_frame_free(&f);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

/* The vector-lane disk mask's instances (disk_mask.h) and whether this CPU runs each under the run's cap. */
static void (*const disk_mask_fn[3])(int k, float u, float v, uint64_t *mask) = {
    ms_grid_disk_mask_scalar, ms_grid_disk_mask_avx2, ms_grid_disk_mask_avx512
};
static int disk_mask_runs(int f)
{
    static const ms_isa isa[3] = { MS_ISA_SCALAR, MS_ISA_AVX2, MS_ISA_AVX512 };
    return isa[f] == MS_ISA_SCALAR || (ms_cpu_isa() >= isa[f] && tu_isa_allowed(isa[f]));
}

/* The grid's disk mask: the shape mask (sample by sample through the shape's row) equals the reference at
 * every k and many pixels and seeds, and so does every instance of the vector-lane mask that front masks use
 * (disk_mask.h) that this CPU runs (under MS_TEST_ISA); each instance also equals the grid's and the disk's
 * definitions written out here, for random shifts (u, v) and the extremes 0 and 1 - 2^-24. */
static void test_disk_mask_rows(void **st)
{
    (void)st;
    ms_light l;
    memset(&l, 0, sizeof l);
    assert_int_equal(ms_light_disk(&l, (ms_vec3){ 1, 2, 3 }, (ms_vec3){ 0.3f, -1, 0.2f }, 0.7f), 0);
    long kept = 0, total = 0;
    for (int k = 16; k <= 64; k *= 2)
        for (uint32_t px = 0; px < 64; px++)
            for (uint32_t seed = 0; seed < 8; seed++) {
                uint64_t a[64], b[64];
                memset(a, 0xFF, sizeof a);
                memset(b, 0xFF, sizeof b);
                ms_shape_mask_apply(MS_PATTERN_GRID, &l, k, px, 3 * px + 1, seed, a);
                ms_shape_mask_reference(MS_PATTERN_GRID, &l, k, px, 3 * px + 1, seed, b);
                for (int w = 0; w < k * k / 64; w++) assert_true(a[w] == b[w]);
                float u, v;
                ms_grid_shift(px, 3 * px + 1, seed, &u, &v);
                for (int f = 0; f < 3; f++) {
                    if (!disk_mask_runs(f)) continue;
                    uint64_t c[64];
                    memset(c, 0xFF, sizeof c);
                    disk_mask_fn[f](k, u, v, c);
                    for (int w = 0; w < k * k / 64; w++) assert_true(c[w] == b[w]);
                }
                kept += ms_mask_count(a, k * k / 64);
                total += k * k;
            }
    /* about pi/4 of the square */
    assert_true(fabs((double)kept / (double)total - M_PI / 4.0) < 0.01);
    tu_rng rng = { 7 };
    int ran = 0;
    for (int f = 0; f < 3; f++) {
        if (!disk_mask_runs(f)) continue;
        ran++;
        for (int k = 16; k <= 64; k *= 2)
            for (int trial = 0; trial < 200; trial++) {
                const float top = 1.0f - 1.0f / 16777216.0f;
                const float u = trial == 0 ? 0.0f : trial == 1 ? top : (float)(tu_rng_next(&rng) >> 40) * (1.0f / 16777216.0f);
                const float v = trial == 0 ? top : trial == 1 ? 0.0f : (float)(tu_rng_next(&rng) >> 40) * (1.0f / 16777216.0f);
                uint64_t a[64];
                memset(a, 0xFF, sizeof a);
                disk_mask_fn[f](k, u, v, a);
                const float ik = 1.0f / (float)k;
                for (int j = 0; j < k; j++)
                    for (int i = 0; i < k; i++) {
                        const float s = ((float)i + ((float)(k - 1 - j) + u) * ik) * ik;
                        const float t = ((float)j + ((float)i + v) * ik) * ik;
                        const float x = 2.0f * s - 1.0f, y = 2.0f * t - 1.0f;
                        const int n = j * k + i;
                        assert_int_equal((int)(a[n >> 6] >> (n & 63) & 1), x * x + y * y < 1.0f);
                    }
            }
    }
    printf("disk mask: %d vector-lane instance(s) equal the per-sample definition\n", ran);
    assert_true(ran >= 1);
}

/* ---- unshadowed irradiance ---- */

/* Numerical integration over the disk: polar midpoint rule, n x 2n cells, double precision,
 * max(cos theta_r, 0) (the horizon). */
static double disk_irradiance_numeric(const disk_geom *dg, const double p[3], const double n[3], int nr)
{
    double e1[3], e2[3];
    const double *m = dg->m;
    const double a[3] = { fabs(m[0]) < 0.9 ? 1.0 : 0.0, fabs(m[0]) < 0.9 ? 0.0 : 1.0, 0.0 };
    e1[0] = a[1] * m[2] - a[2] * m[1]; e1[1] = a[2] * m[0] - a[0] * m[2]; e1[2] = a[0] * m[1] - a[1] * m[0];
    const double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int c = 0; c < 3; c++) e1[c] /= l1;
    e2[0] = m[1] * e1[2] - m[2] * e1[1]; e2[1] = m[2] * e1[0] - m[0] * e1[2]; e2[2] = m[0] * e1[1] - m[1] * e1[0];
    double sum = 0.0;
    const int nphi = 2 * nr;
    for (int i = 0; i < nr; i++) {
        const double r = (i + 0.5) / nr * dg->r, dA = r * (dg->r / nr) * (2.0 * M_PI / nphi);
        for (int j = 0; j < nphi; j++) {
            const double ph = (j + 0.5) / nphi * 2.0 * M_PI, cs = cos(ph), sn = sin(ph);
            double d[3];
            for (int c = 0; c < 3; c++) d[c] = dg->c[c] + r * (cs * e1[c] + sn * e2[c]) - p[c];
            const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], dl = sqrt(d2);
            const double cr = (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / dl;
            const double cl = -(d[0] * m[0] + d[1] * m[1] + d[2] * m[2]) / dl;
            if (cr > 0.0 && cl > 0.0) sum += cr * cl / d2 * dA;
        }
    }
    return sum;
}

static void test_disk_irradiance(void **st)
{
    (void)st;
    tu_rng g = { 1234 };
    double worst_above = 0.0, worst_cross = 0.0;
    int above = 0, cross = 0;
    for (int trial = 0; trial < 400 && (above < 40 || cross < 40); trial++) {
        double v[12];
        for (int i = 0; i < 12; i++) v[i] = (double)(tu_rng_next(&g) >> 11) * (1.0 / 9007199254740992.0) * 2.0 - 1.0;
        ms_vec3 c = { (float)v[0], (float)v[1], (float)v[2] }, m = { (float)v[3], (float)v[4], (float)v[5] };
        const float r = 0.2f + 1.0f * (float)fabs(v[6]);
        ms_light l;
        memset(&l, 0, sizeof l);
        if (ms_light_disk(&l, c, m, r)) continue;
        disk_geom dg;
        const double ml = sqrt((double)m.x * m.x + (double)m.y * m.y + (double)m.z * m.z);
        dg = (disk_geom){ .c = { c.x, c.y, c.z }, .m = { m.x / ml, m.y / ml, m.z / ml }, .r = r };
        /* a point on the emitting side, 0.1 .. 2.1 from the plane, up to 2 to the side */
        const double h = 0.1 + 2.0 * fabs(v[7]);
        double p[3], n[3];
        for (int a = 0; a < 3; a++) p[a] = dg.c[a] + h * dg.m[a] + 2.0 * v[8 + a % 3] * (a == 1 ? 0.5 : 1.0);
        const double nl = sqrt(v[9] * v[9] + v[10] * v[10] + v[11] * v[11]);
        if (nl < 0.1) continue;
        for (int a = 0; a < 3; a++) n[a] = v[9 + a] / nl;
        /* the receiver facing the light at least partly */
        double toc[3] = { dg.c[0] - p[0], dg.c[1] - p[1], dg.c[2] - p[2] };
        if (toc[0] * n[0] + toc[1] * n[1] + toc[2] * n[2] < 0.0) for (int a = 0; a < 3; a++) n[a] = -n[a];
        const float pf[3] = { (float)p[0], (float)p[1], (float)p[2] }, nf[3] = { (float)n[0], (float)n[1], (float)n[2] };
        for (int a = 0; a < 3; a++) { p[a] = pf[a]; n[a] = nf[a]; }
        const double want = disk_irradiance_numeric(&dg, p, n, 800);
        const double got = ms_light_irradiance(&l, pf, nf);
        /* wholly above the horizon? */
        double nt[3], dn = n[0] * dg.m[0] + n[1] * dg.m[1] + n[2] * dg.m[2];
        for (int a = 0; a < 3; a++) nt[a] = n[a] - dn * dg.m[a];
        const double wholly = toc[0] * n[0] + toc[1] * n[1] + toc[2] * n[2] - r * sqrt(nt[0] * nt[0] + nt[1] * nt[1] + nt[2] * nt[2]);
        const double err = fabs(got - want) / fmax(want, 1e-3);
        if (wholly > 1e-3) { above++; worst_above = fmax(worst_above, err); }
        else if (wholly < -1e-3) { cross++; worst_cross = fmax(worst_cross, err); }
    }
    printf("disk irradiance vs numerical integration: %d points wholly above the horizon, worst relative error "
           "%.2e (closed form); %d across it, %.2e (256-gon)\n", above, worst_above, cross, worst_cross);
    assert_true(above >= 20 && cross >= 20);
    /* The midpoint rule at 800 x 1600 cells is good to about 1e-5 here; the float closed form adds ~1e-6. */
    assert_true(worst_above < 1e-4);
    assert_true(worst_cross < 1e-3);
}

/* ---- sphere lights ---- */

/* The outline disk against the exact tangent cone: every rim point lies on the sphere and its tangent
 * plane contains the ray from p, (rim - p) . (rim - c) = 0; the disk faces p. */
static void test_sphere_outline(void **st)
{
    (void)st;
    tu_rng g = { 99 };
    for (int trial = 0; trial < 200; trial++) {
        double v[7];
        for (int i = 0; i < 7; i++) v[i] = (double)(tu_rng_next(&g) >> 11) * (1.0 / 9007199254740992.0) * 2.0 - 1.0;
        ms_light sph;
        memset(&sph, 0, sizeof sph);
        const float R = 0.1f + (float)fabs(v[3]);
        assert_int_equal(ms_light_sphere(&sph, (ms_vec3){ (float)v[0], (float)v[1], (float)v[2] }, R), 0);
        /* a point 1.01 R .. 5 R from the centre */
        double dir[3] = { v[4], v[5], v[6] };
        const double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        if (dl < 0.1) continue;
        const double dist = R * (1.01 + 4.0 * fabs(v[4]));
        const float p[3] = { (float)(v[0] + dir[0] / dl * dist), (float)(v[1] + dir[1] / dl * dist), (float)(v[2] + dir[2] / dl * dist) };
        ms_light disk;
        assert_int_equal(ms_light_sphere_outline(&sph, p, &disk), 0);
        assert_int_equal(disk.shape, MS_LIGHT_DISK);
        const double c[3] = { sph.center.x, sph.center.y, sph.center.z };
        for (int k = 0; k < 16; k++) {
            /* rim point: the inscribed circle of the square at angle k */
            const double a = 2.0 * M_PI * k / 16, cs = 0.5 + 0.5 * cos(a), sn = 0.5 + 0.5 * sin(a);
            double rim[3], pr[3], cr[3];
            const double P0[3] = { disk.corner.x, disk.corner.y, disk.corner.z };
            const double S[3] = { disk.edge_s.x, disk.edge_s.y, disk.edge_s.z }, T[3] = { disk.edge_t.x, disk.edge_t.y, disk.edge_t.z };
            for (int q = 0; q < 3; q++) { rim[q] = P0[q] + cs * S[q] + sn * T[q]; pr[q] = rim[q] - p[q]; cr[q] = rim[q] - c[q]; }
            const double on = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
            const double tangent = (pr[0] * cr[0] + pr[1] * cr[1] + pr[2] * cr[2]) /
                                   (sqrt(pr[0] * pr[0] + pr[1] * pr[1] + pr[2] * pr[2]) * on);
            assert_true(fabs(on - R) <= 2e-5 * (R + dist));
            assert_true(fabs(tangent) <= 1e-4 * (dist / (dist - R * 0.999)));
        }
        /* faces p: cross(edge_s, edge_t) . (p - centre) > 0 */
        const double nx = (double)disk.edge_s.y * disk.edge_t.z - (double)disk.edge_s.z * disk.edge_t.y;
        const double ny = (double)disk.edge_s.z * disk.edge_t.x - (double)disk.edge_s.x * disk.edge_t.z;
        const double nz = (double)disk.edge_s.x * disk.edge_t.y - (double)disk.edge_s.y * disk.edge_t.x;
        assert_true(nx * (p[0] - c[0]) + ny * (p[1] - c[1]) + nz * (p[2] - c[2]) > 0.0);
    }
    /* inside: no outline */
    ms_light sph, disk;
    memset(&sph, 0, sizeof sph);
    ms_light_sphere(&sph, (ms_vec3){ 0, 0, 0 }, 1.0f);
    const float in[3] = { 0.5f, 0, 0 };
    assert_int_equal(ms_light_sphere_outline(&sph, in, &disk), MS_ERR_INVALID);
}

/* Sphere irradiance (Snyder's closed form) against numerical integration over the exact outline disk
 * (same solid angle, same radiance), above and across the horizon. */
static void test_sphere_irradiance(void **st)
{
    (void)st;
    tu_rng g = { 4321 };
    int above = 0, cross = 0;
    double worst = 0.0;
    for (int trial = 0; trial < 300 && (above < 30 || cross < 30); trial++) {
        double v[6];
        for (int i = 0; i < 6; i++) v[i] = (double)(tu_rng_next(&g) >> 11) * (1.0 / 9007199254740992.0) * 2.0 - 1.0;
        const float R = 0.3f + 0.5f * (float)fabs(v[0]);
        ms_light sph;
        memset(&sph, 0, sizeof sph);
        ms_light_sphere(&sph, (ms_vec3){ 0, 0, 0 }, R);
        const double d = R * (1.2 + 3.0 * fabs(v[1]));
        double dir[3] = { v[2], v[3], v[4] };
        const double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        if (dl < 0.1) continue;
        const float p[3] = { (float)(dir[0] / dl * d), (float)(dir[1] / dl * d), (float)(dir[2] / dl * d) };
        /* normal: at angle theta from the direction to the centre, up to 120 degrees */
        const double th = fabs(v[5]) * 2.0 * M_PI / 3.0;
        double a[3] = { -p[0], -p[1], -p[2] }, b[3];
        const double al = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        for (int q = 0; q < 3; q++) a[q] /= al;
        b[0] = a[1]; b[1] = -a[0]; b[2] = 0;   /* perpendicular to a (a is never along z only, by chance) */
        const double bl = sqrt(b[0] * b[0] + b[1] * b[1]);
        if (bl < 0.1) continue;
        for (int q = 0; q < 2; q++) b[q] /= bl;
        const float n[3] = { (float)(cos(th) * a[0] + sin(th) * b[0]), (float)(cos(th) * a[1] + sin(th) * b[1]),
                             (float)(cos(th) * a[2]) };
        /* the exact outline in double */
        const double pd[3] = { p[0], p[1], p[2] }, nd[3] = { n[0], n[1], n[2] };
        const double dd = sqrt(pd[0] * pd[0] + pd[1] * pd[1] + pd[2] * pd[2]), f = R * R / (dd * dd);
        disk_geom dg = { .c = { pd[0] * f, pd[1] * f, pd[2] * f }, .m = { pd[0] / dd, pd[1] / dd, pd[2] / dd },
                         .r = R * sqrt(dd * dd - R * R) / dd };
        const double want = disk_irradiance_numeric(&dg, pd, nd, 600);
        const double got = ms_light_irradiance(&sph, p, n);
        const double sin_s = R / dd;
        if (cos(th) > sin_s + 0.01) above++;
        else if (cos(th) < sin_s - 0.01 && cos(th) > -sin_s + 0.01) cross++;
        else continue;
        worst = fmax(worst, fabs(got - want) / fmax(want, 1e-3));
    }
    printf("sphere irradiance vs numerical integration: %d above the horizon, %d across, worst relative error %.2e\n",
           above, cross, worst);
    assert_true(above >= 20 && cross >= 20);
    assert_true(worst < 1e-4);
}

/* Every method on a sphere light equals raytrace pixel for pixel; raytrace's V equals the brute force on the
 * exact outline disk of each receiver, at every pixel the brute force decides whole. */
static void test_sphere_every_method(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    memset(&sc.light, 0, sizeof sc.light);
    assert_int_equal(ms_light_sphere(&sc.light, (ms_vec3){ 0.5f, 5.0f, 0.2f }, 0.9f), 0);
    sc.light.emission = (ms_vec3){ 1, 1, 1 };
    const int size = 24;
    ms_render_options o;
    tu_render_options_default(&o);
    o.width = o.height = size;
    o.threads = 2;
    char err[256];
    ms_frame ref;
    tu_every_method_as_raytrace(&sc, &o, "sphere frame", &ref, NULL, NULL);
    /* brute force at each pixel */
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc.tri, sc.n_tris, 1), 0);
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, &sc, &bvh, size, size, 32);
    const ms_primary_method *pm = ms_find_primary_method("bvh");
    void *ps = NULL;
    assert_int_equal(pm->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit hits[24 * 24];
    pm->trace(ps, &ctx, 0, 0, size, size, hits);
    pm->destroy(ps);
    float *pts = malloc(3 * 1024 * sizeof *pts);
    assert_non_null(pts);
    int decided = 0, partial = 0;
    const double c[3] = { sc.light.center.x, sc.light.center.y, sc.light.center.z }, R = sc.light.radius;
    for (int i = 0; i < size * size; i++) {
        if (hits[i].prim == UINT32_MAX) continue;
        ms_light disk;
        assert_int_equal(ms_light_sphere_outline(&sc.light, hits[i].p, &disk), 0);
        ms_pattern_points(MS_PATTERN_GRID, &disk, 32, (uint32_t)(i % size), (uint32_t)(i / size), 0, pts);
        const double p[3] = { hits[i].p[0], hits[i].p[1], hits[i].p[2] };
        const double w[3] = { p[0] - c[0], p[1] - c[1], p[2] - c[2] };
        const double d = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), f2 = R * R / (d * d);
        const disk_geom dg = { .c = { c[0] + w[0] * f2, c[1] + w[1] * f2, c[2] + w[2] * f2 },
                               .m = { w[0] / d, w[1] / d, w[2] / d }, .r = R * sqrt(d * d - R * R) / d };
        int nf = 0, nv = 0, unsure = 0;
        for (int s2 = 0; s2 < 1024; s2++) {
            verdict cnt, v;
            brute_sample(&bvh, hits[i].prim, hits[i].p, hits[i].n, pts + 3 * s2, &dg, &cnt, &v);
            if (cnt == UNSURE || v == UNSURE) { unsure = 1; break; }
            nf += cnt == YES;
            nv += v == YES;
        }
        if (unsure) continue;
        decided++;
        partial += nv > 0 && nv < nf;
        assert_int_equal(ref.front[i], nf);
        assert_true(ref.vis[i] == (nf ? (float)nv / (float)nf : 0.0f));
    }
    printf("sphere light: the brute force decided %d of %d pixels whole (%d in penumbra)\n", decided, size * size, partial);
    assert_true(decided > size * size / 2 && partial > 0);
    free(pts);
    ms_bvh_free(&bvh);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

/* ---- triangle lights ---- */

/* Every method's masks on a triangle light equal the brute force (on the triangle by its barycentric
 * s + t < 1 in world space) and raytrace's; the grid at two k and with the horizon crossing the light, and
 * the ray tracers' other patterns. */
static void test_triangle_every_method(void **st)
{
    (void)st;
    ms_scene sc;
    disk_geom dg;
    make_triangle_scene(&sc, (ms_vec3){ -1.2f, 6, -0.8f }, (ms_vec3){ 1.5f, 6.4f, -1.1f }, (ms_vec3){ 0.1f, 5.7f, 1.6f }, &dg);
    check_disk_methods(&sc, &dg, 24, 32, MS_PATTERN_GRID);
    check_disk_methods(&sc, &dg, 16, 16, MS_PATTERN_STRATIFIED);
    check_disk_methods(&sc, &dg, 16, 32, MS_PATTERN_INTERLEAVED);
    ms_scene_free(&sc);
    /* low and steep: the triangle crosses the ground's plane */
    make_triangle_scene(&sc, (ms_vec3){ -2, -0.8f, 4.5f }, (ms_vec3){ 2, -0.8f, 4.5f }, (ms_vec3){ 0, 2.5f, 3.5f }, &dg);
    check_disk_methods(&sc, &dg, 24, 16, MS_PATTERN_GRID);
    ms_scene_free(&sc);
}

/* Whole frames: every method's V, S and front on a triangle light equal raytrace's; half the
 * parallelogram's samples count. */
static void test_triangle_frames_equal(void **st)
{
    (void)st;
    ms_scene sc;
    disk_geom dg;
    make_triangle_scene(&sc, (ms_vec3){ -1.2f, 6, -0.8f }, (ms_vec3){ 1.5f, 6.4f, -1.1f }, (ms_vec3){ 0.1f, 5.7f, 1.6f }, &dg);
    ms_render_options o;
    tu_render_options_default(&o);
    o.width = o.height = 32;
    o.threads = 2;
    char err[256];
    ms_frame ref, f;
    tu_every_method_as_raytrace(&sc, &o, "triangle frame", &ref, NULL, NULL);
    sc.light.shape = MS_LIGHT_RECT;
    assert_int_equal(ms_render(&sc, &o, &f, err, sizeof err), 0);
    double tri_front = 0.0, rect_front = 0.0;
    for (int i = 0; i < 32 * 32; i++) { tri_front += ref.front[i]; rect_front += f.front[i]; }
    printf("triangle light: %.4f of the parallelogram's front samples count\n", tri_front / rect_front);
    assert_true(fabs(tri_front / rect_front - 0.5) < 0.02);
    ms_frame_free(&f);
    ms_frame_free(&ref);
    ms_scene_free(&sc);
}

/* The unshadowed irradiance against numerical integration over the triangle (n^2 sub-triangles, their
 * centroids, double precision, max(cos theta_r, 0)), above and across the receiver's horizon. */
static double triangle_irradiance_numeric(const double a[3], const double e1[3], const double e2[3], const double p[3],
                                          const double n[3], int nsub)
{
    double m[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
    const double ml = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]), dA = 0.5 * ml / ((double)nsub * nsub);
    for (int c = 0; c < 3; c++) m[c] /= ml;
    double sum = 0.0;
    for (int i = 0; i < nsub; i++)
        for (int j = 0; j < nsub - i; j++)
            for (int up = 0; up < 2; up++) {
                if (up && i + j + 1 >= nsub) continue;
                /* the sub-triangle's centroid in (s, t) */
                const double s = up ? (i + 2.0 / 3.0) / nsub : (i + 1.0 / 3.0) / nsub;
                const double t = up ? (j + 2.0 / 3.0) / nsub : (j + 1.0 / 3.0) / nsub;
                double d[3];
                for (int c = 0; c < 3; c++) d[c] = a[c] + s * e1[c] + t * e2[c] - p[c];
                const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], dl = sqrt(d2);
                const double cr = (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / dl;
                const double cl = -(d[0] * m[0] + d[1] * m[1] + d[2] * m[2]) / dl;
                if (cr > 0.0 && cl > 0.0) sum += cr * cl / d2 * dA;
            }
    return sum;
}

static void test_triangle_irradiance(void **st)
{
    (void)st;
    tu_rng g = { 4321 };
    double worst = 0.0;
    int tested = 0, crossing = 0;
    for (int trial = 0; trial < 200 && tested < 60; trial++) {
        double v[15];
        for (int i = 0; i < 15; i++) v[i] = (double)(tu_rng_next(&g) >> 11) * (1.0 / 9007199254740992.0) * 2.0 - 1.0;
        const ms_vec3 A = { (float)v[0], (float)v[1] + 2.0f, (float)v[2] }, B = { (float)v[3], (float)v[4] + 2.0f, (float)v[5] },
                      C = { (float)v[6], (float)v[7] + 2.0f, (float)v[8] };
        ms_light l;
        memset(&l, 0, sizeof l);
        if (ms_light_triangle(&l, A, B, C) || ms_light_area(&l) < 0.05f) continue;
        const float pf[3] = { (float)v[9], (float)v[10], (float)v[11] };
        double n[3] = { v[12], v[13], v[14] };
        const double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (nl < 0.1) continue;
        float nf[3];
        for (int c = 0; c < 3; c++) { nf[c] = (float)(n[c] / nl); n[c] = nf[c]; }
        const double a[3] = { A.x, A.y, A.z }, e1[3] = { (double)B.x - A.x, (double)B.y - A.y, (double)B.z - A.z },
                     e2[3] = { (double)C.x - A.x, (double)C.y - A.y, (double)C.z - A.z }, p[3] = { pf[0], pf[1], pf[2] };
        /* p on the emitting side, at least 0.3 from the triangle's plane (the numerical rule's accuracy) */
        const double m[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
        const double side = (p[0] - a[0]) * m[0] + (p[1] - a[1]) * m[1] + (p[2] - a[2]) * m[2];
        if (side < 0.3 * sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])) continue;   /* 0.3 from its plane */
        const double want = triangle_irradiance_numeric(a, e1, e2, p, n, 600);
        if (want < 1e-3) continue;
        const double got = ms_light_irradiance(&l, pf, nf);
        int below = 0, above = 0;
        for (int k = 0; k < 3; k++) {
            const double q[3] = { a[0] + (k == 1) * e1[0] + (k == 2) * e2[0] - p[0], a[1] + (k == 1) * e1[1] + (k == 2) * e2[1] - p[1],
                                  a[2] + (k == 1) * e1[2] + (k == 2) * e2[2] - p[2] };
            const double h = q[0] * n[0] + q[1] * n[1] + q[2] * n[2];
            below += h < 0.0;
            above += h > 0.0;
        }
        crossing += below && above;
        tested++;
        worst = fmax(worst, fabs(got - want) / want);
    }
    printf("triangle irradiance vs numerical integration: %d points (%d with the triangle across the horizon), worst "
           "relative error %.2e\n", tested, crossing, worst);
    assert_true(tested >= 40 && crossing >= 5);
    /* centroid rule at 360000 sub-triangles: ~1e-5; the float polygon formula ~1e-6 */
    assert_true(worst < 2e-4);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_disk_mask_rows),
        cmocka_unit_test(test_disk_every_method_grid),
        cmocka_unit_test(test_disk_ray_tracers_other_patterns),
        cmocka_unit_test(test_disk_frames_equal),
        cmocka_unit_test(test_disk_irradiance),
        cmocka_unit_test(test_sphere_outline),
        cmocka_unit_test(test_sphere_irradiance),
        cmocka_unit_test(test_sphere_every_method),
        cmocka_unit_test(test_triangle_every_method),
        cmocka_unit_test(test_triangle_frames_equal),
        cmocka_unit_test(test_triangle_irradiance),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
